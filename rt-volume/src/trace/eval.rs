//! The integrated state and the field as the integrators see it.

use glam::DVec3;

use super::TraceError;
use crate::IndexField;

/// The integrated state: position, `T = n dx/ds`, optical path, arc
/// length since entering the bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct State {
    pub(super) x: DVec3,
    pub(super) t: DVec3,
    pub(super) opl: f64,
    pub(super) s: f64,
}

impl State {
    pub(super) fn axpy(self, h: f64, d: &State) -> State {
        State {
            x: self.x + h * d.x,
            t: self.t + h * d.t,
            opl: self.opl + h * d.opl,
            s: self.s + h * d.s,
        }
    }
}

/// Field access that never evaluates outside the bounds and counts calls.
pub(super) struct Eval<'a, F: IndexField> {
    pub(super) field: &'a F,
    pub(super) bounds: crate::Bounds,
    pub(super) ambient: f64,
    pub(super) evals: u32,
    /// The last evaluation: steps that end where the next begins (FSAL,
    /// leapfrog) reuse it instead of calling the field again.
    pub(super) last: Option<(DVec3, f64, DVec3)>,
}

impl<F: IndexField> Eval<'_, F> {
    /// `(n, ∇n)` at `x`: inside the bounds, the field's own values.
    ///
    /// Outside them, at stage points of a step that crosses a face (the
    /// trace never integrates beyond one), the field's first-order
    /// continuation from the nearest point `c` of the box:
    /// `(n(c) + ∇n(c)·(x − c), ∇n(c))`, exact for linear fields and off by
    /// `O(|x − c|²)` for smooth ones. The ambient index there (what the ray
    /// meets after leaving) put a jump inside the last step, and every
    /// scheme lost its order at a slanted exit through a face where
    /// `∇n ≠ 0` (RK4's exit direction erred at first order in the step).
    /// Where the continuation is no valid index (far outside, after a huge
    /// trial step), the nearest point's own values are used.
    pub(super) fn n(&mut self, x: DVec3) -> Result<(f64, DVec3), TraceError> {
        if self.bounds.contains(x) {
            return self.n_inside(x);
        }
        if x.is_nan() {
            // An overflowed state: the caller reports it.
            return Ok((self.ambient, DVec3::ZERO));
        }
        let c = nearest_in(&self.bounds, x);
        let (n, g) = self.n_inside(c)?;
        let continued = n + g.dot(x - c);
        Ok((if continued.is_finite() && continued > 0.0 { continued } else { n }, g))
    }

    /// `(n, ∇n)` from the field at a point of the bounds.
    pub(super) fn n_inside(&mut self, x: DVec3) -> Result<(f64, DVec3), TraceError> {
        if let Some((lx, n, g)) = self.last
            && lx == x
        {
            return Ok((n, g));
        }
        self.evals += 1;
        let (n, g) = self.field.eval(x);
        if !(n.is_finite() && n > 0.0 && g.is_finite()) {
            return Err(TraceError::BadField { at: x });
        }
        self.last = Some((x, n, g));
        Ok((n, g))
    }

    /// `dy/dt = (T, n∇n, n², n)`.
    pub(super) fn deriv(&mut self, y: &State) -> Result<State, TraceError> {
        let (n, g) = self.n(y.x)?;
        Ok(State { x: y.t, t: n * g, opl: n * n, s: n })
    }
}

/// The point of `b` nearest to `x` (explicit comparisons: nothing relies on
/// how `min`/`max` treat NaN).
pub(super) fn nearest_in(b: &crate::Bounds, x: DVec3) -> DVec3 {
    let c = |a: usize| {
        if x[a] < b.min[a] {
            b.min[a]
        } else if x[a] > b.max[a] {
            b.max[a]
        } else {
            x[a]
        }
    };
    DVec3::new(c(0), c(1), c(2))
}
