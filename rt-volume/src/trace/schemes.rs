//! One step of each scheme (Euler, RK4, leapfrog; Dormand–Prince 5(4)
//! with error control) and the step shortened to land on an event.

use glam::DVec3;

use super::eval::{Eval, State};
use super::{Exit, Method, TraceError, TraceParams, TraceStats};
use crate::{IndexField, math::powf};

/// One step of size `h` (for `Adaptive`: one uncontrolled Dormand–Prince
/// step).
pub(super) fn fixed_step<F: IndexField>(
    m: Method,
    ev: &mut Eval<'_, F>,
    y: &State,
    h: f64,
) -> Result<State, TraceError> {
    Ok(match m {
        Method::Euler => {
            let k = ev.deriv(y)?;
            y.axpy(h, &k)
        }
        // One Dormand–Prince step without control (the landing step).
        Method::Adaptive => dopri(ev, y, h)?.0,
        Method::Rk4 => {
            let k1 = ev.deriv(y)?;
            let k2 = ev.deriv(&y.axpy(0.5 * h, &k1))?;
            let k3 = ev.deriv(&y.axpy(0.5 * h, &k2))?;
            let k4 = ev.deriv(&y.axpy(h, &k3))?;
            State {
                x: y.x + h / 6.0 * (k1.x + 2.0 * k2.x + 2.0 * k3.x + k4.x),
                t: y.t + h / 6.0 * (k1.t + 2.0 * k2.t + 2.0 * k3.t + k4.t),
                opl: y.opl + h / 6.0 * (k1.opl + 2.0 * k2.opl + 2.0 * k3.opl + k4.opl),
                s: y.s + h / 6.0 * (k1.s + 2.0 * k2.s + 2.0 * k3.s + k4.s),
            }
        }
        Method::Symplectic => {
            // Kick–drift–kick. Optical path and arc length along the
            // chord the drift actually moved, `n` by the trapezoid rule:
            // leapfrog keeps `|T|² − n²` bounded, not zero, so a ray
            // leaves a refracting region with `|T|` off `n` by O(h²) and,
            // in the uniform region after it, `∫ n² dt` would drift from
            // `n × (distance moved)` in proportion to that distance (a
            // 2.5 % phase error through a Gaussian bump at two-cell
            // steps, docs/oracles.md §5); the chord never does.
            let (n_a, g_a) = ev.n(y.x)?;
            let t_half = y.t + 0.5 * h * n_a * g_a;
            let x = y.x + h * t_half;
            let (n_b, g_b) = ev.n(x)?;
            let len = (x - y.x).length();
            State {
                x,
                t: t_half + 0.5 * h * n_b * g_b,
                opl: y.opl + 0.5 * (n_a + n_b) * len,
                s: y.s + len,
            }
        }
    })
}

// Dormand–Prince 5(4) tableau (Dormand & Prince 1980).
pub(crate) const A: [[f64; 6]; 6] = [
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
/// 5th-order weights (= last row of `A`, FSAL).
const B5: [f64; 7] =
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0];
/// 4th-order weights.
const B4: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];

/// One Dormand–Prince step of size `h`: the 5th-order result and the
/// max-norm of its difference from the 4th-order one (position and `T`).
pub(super) fn dopri<F: IndexField>(
    ev: &mut Eval<'_, F>,
    y: &State,
    h: f64,
) -> Result<(State, f64), TraceError> {
    let mut k = [*y; 7];
    k[0] = ev.deriv(y)?;
    for s in 1..7 {
        let mut yi = *y;
        for (j, a) in A[s - 1].iter().enumerate().take(s) {
            yi = yi.axpy(h * a, &k[j]);
        }
        k[s] = ev.deriv(&yi)?;
    }
    let (mut y5, mut y4) = (*y, *y);
    for s in 0..7 {
        y5 = y5.axpy(h * B5[s], &k[s]);
        y4 = y4.axpy(h * B4[s], &k[s]);
    }
    let err = (y5.x - y4.x).abs().max_element().max((y5.t - y4.t).abs().max_element());
    Ok((y5, err))
}

/// An accepted adaptive step: `(state, step used, local error)`; adapts `h`
/// (never above `max_step`).
pub(super) fn adaptive_step<F: IndexField>(
    ev: &mut Eval<'_, F>,
    y: &State,
    h: &mut f64,
    max_step: f64,
    params: &TraceParams,
    stats: &mut TraceStats,
) -> Result<(State, f64, f64), TraceError> {
    loop {
        let (next, err) = dopri(ev, y, *h)?;
        // Standard controller: safety 0.9, growth in [0.2, 5].
        let factor = if err > 0.0 { 0.9 * powf(params.tolerance / err, 0.2) } else { 5.0 };
        let factor = factor.clamp(0.2, 5.0);
        if err <= params.tolerance {
            let used = *h;
            *h = (*h * factor).min(max_step);
            return Ok((next, used, err));
        }
        stats.rejected += 1;
        let tried = *h;
        *h *= factor;
        if stats.rejected + stats.steps >= params.max_steps || *h < 1e-300 {
            // Give up controlling: accept (the caller stops on max_steps).
            return Ok((next, tried, err));
        }
    }
}

/// Finds the step `h* ∈ (0, h]` from `y` (inside the bounds, arc length
/// below `limit`) to the first event on the step to `past`: the bounds'
/// surface, or the arc length `limit`. The Illinois variant of regula
/// falsi on the larger of the signed distance outside the box (per unit
/// of box size) and the arc length past `limit` (per unit of `limit`),
/// with the scheme's own step of each trial length, so the last step is
/// as accurate as the others. Returns the state there, snapped onto the
/// face it left through, and which event it was.
pub(super) fn land<F: IndexField>(
    m: Method,
    ev: &mut Eval<'_, F>,
    y: &State,
    past: &State,
    h: f64,
    limit: f64,
    stats: &mut TraceStats,
) -> Result<(State, Exit), TraceError> {
    let b = ev.bounds;
    // Signed distance outside the box, per unit of box size: ≤ 0 inside,
    // > 0 outside; its zero on the step is where the ray leaves.
    let size = (b.max - b.min).max(DVec3::splat(f64::MIN_POSITIVE));
    let outside_by = |s: &State| -> (f64, usize, f64) {
        let mut worst = (f64::NEG_INFINITY, 0, 0.0);
        for a in 0..3 {
            for (over, plane) in [
                ((s.x[a] - b.max[a]) / size[a], b.max[a]),
                ((b.min[a] - s.x[a]) / size[a], b.min[a]),
            ] {
                if over > worst.0 {
                    worst = (over, a, plane);
                }
            }
        }
        worst
    };
    // Arc length past the limit, per unit of the limit.
    let beyond = |s: &State| (s.s - limit) / limit;
    let g = |s: &State| {
        let (over, _, _) = outside_by(s);
        let late = beyond(s);
        if late > over { late } else { over }
    };
    let (mut lo, mut g_lo) = (0.0, g(y));
    let (mut hi, mut g_hi) = (h, g(past));
    let mut landed = *past;
    let mut side = 0i8;
    let tol = 1e-14;
    for _ in 0..60 {
        let hm = if g_hi != g_lo { hi - g_hi * (hi - lo) / (g_hi - g_lo) } else { 0.5 * (lo + hi) };
        let hm = if hm > lo && hm < hi { hm } else { 0.5 * (lo + hi) };
        let s = fixed_step(m, ev, y, hm)?;
        let gm = g(&s);
        landed = s;
        if gm.abs() <= tol || hi - lo <= 1e-15 * h {
            break;
        }
        if gm > 0.0 {
            hi = hm;
            g_hi = gm;
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        } else {
            lo = hm;
            g_lo = gm;
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        }
    }
    stats.steps += 1;
    let (over, axis, plane) = outside_by(&landed);
    if beyond(&landed) > over {
        // The arc-length limit came first: the ray is inside the box (the
        // clamp only guards against rounding).
        landed.x = landed.x.clamp(b.min, b.max);
        return Ok((landed, Exit::MaxLength));
    }
    // Snap the exit coordinate onto the face it is on (within `tol`).
    landed.x[axis] = plane;
    // Where the search could not resolve the crossing (a field so extreme
    // that one step is far from straight: found by fuzzing with n ≈ 1e38),
    // the other coordinates may still lie outside: the exit is on the box.
    landed.x = landed.x.clamp(b.min, b.max);
    Ok((landed, Exit::Left))
}
