//! Runs of leapfrog steps with nothing to decide between them: no skip
//! to ask for, no face or arc-length limit within the next step, the
//! space owned. The dense part of a dense field is all such steps; the
//! general loop ([`leg`](super::walk)) hands them here.

use glam::DVec3;

use super::eval::{Eval, State};
use super::{TraceError, TraceStats};
use crate::IndexField;

/// Where a run stops: the step from a state whose arc length reaches
/// `until_s` (the skip oracle is asked there) or that `owns` refuses, or
/// the step that would make the steps reach `max_steps`, leave the
/// bounds or reach `limit` (arc length), is left to the general loop.
pub(super) struct RunLimits<'o, O: Fn(DVec3) -> bool> {
    pub(super) h: f64,
    pub(super) limit: f64,
    pub(super) until_s: f64,
    pub(super) max_steps: u32,
    pub(super) owns: &'o O,
}

/// Leapfrog steps from `y` within `lim` (see [`RunLimits`]): bit for bit
/// the steps, statistics and evaluations of the general loop taking them
/// one at a time (the same kick–drift–kick as the scheme's step, the same
/// accept test, the same cache of the last evaluation), without its
/// per-step dispatch: the evaluation at a step's start is the one its
/// predecessor ended with, and the two checks that end a run come before
/// the step's evaluation, so a run that stops has evaluated nothing the
/// general loop will not reuse. Returns the steps taken.
///
/// # Errors
/// [`TraceError::BadField`] where the field is not a valid index, as the
/// general loop.
pub(super) fn leapfrog_run<F: IndexField, O: Fn(DVec3) -> bool>(
    ev: &mut Eval<'_, F>,
    y: &mut State,
    stats: &mut TraceStats,
    lim: &RunLimits<'_, O>,
    visit: &mut impl FnMut(DVec3),
) -> Result<u32, TraceError> {
    let h = lim.h;
    let mut taken = 0;
    while y.s < lim.until_s && stats.steps + stats.rejected < lim.max_steps && (lim.owns)(y.x) {
        // An accepted state lies in the bounds: the field's own values.
        let (n_a, g_a) = ev.n_inside(y.x)?;
        let t_half = y.t + 0.5 * h * n_a * g_a;
        let x = y.x + h * t_half;
        let len = (x - y.x).length();
        if !(ev.bounds.contains(x) && y.s + len < lim.limit) {
            break;
        }
        let (n_b, g_b) = ev.n_inside(x)?;
        *y = State {
            x,
            t: t_half + 0.5 * h * n_b * g_b,
            opl: y.opl + 0.5 * (n_a + n_b) * len,
            s: y.s + len,
        };
        visit(y.x);
        stats.steps += 1;
        stats.invariant_drift = stats.invariant_drift.max((y.t.length() - n_b).abs());
        stats.field_evals = ev.evals;
        taken += 1;
    }
    Ok(taken)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::Method;
    use crate::trace::schemes::fixed_step;
    use crate::{Grid, GridField, Interp};

    fn waves(interp: Interp) -> GridField {
        let n = 24;
        let h = 1.0 / n as f64;
        let data = (0..n * n * n)
            .map(|i| {
                let (x, y, z) =
                    ((i % n) as f64 * h, ((i / n) % n) as f64 * h, (i / n / n) as f64 * h);
                (1.0 + 1e-3 * (13.0 * x + 4.0 * z).sin() + 6e-4 * (9.0 * y - 7.0 * z).cos()) as f32
            })
            .collect();
        let g = Grid::new([n; 3], DVec3::splat(0.5 * h), DVec3::splat(h), data).unwrap();
        GridField::new(g, interp, 1.0).unwrap()
    }

    /// A run is the scheme's own step taken one at a time — states,
    /// evaluations and the invariant's drift bit for bit — and stops at
    /// the step that would leave the bounds, at the arc-length limit and
    /// at the step count, without evaluating there.
    #[test]
    fn a_run_is_the_schemes_steps_one_by_one() {
        for interp in [Interp::Trilinear, Interp::CatmullRom] {
            let f = waves(interp);
            let bounds = f.bounds();
            let start = State {
                x: DVec3::new(0.3, 0.6, bounds.min.z),
                t: DVec3::new(0.05, -0.02, 1.0).normalize(),
                opl: 0.0,
                s: 0.0,
            };
            let h = 0.03;
            for (limit, max_steps) in [(f64::INFINITY, u32::MAX), (0.5, u32::MAX), (9.0, 7)] {
                let new_eval = || Eval { field: &f, bounds, ambient: 1.0, evals: 0, last: None };
                let (mut ev, mut y, mut stats) = (new_eval(), start, TraceStats::default());
                let lim =
                    RunLimits { h, limit, until_s: f64::INFINITY, max_steps, owns: &|_| true };
                let taken = leapfrog_run(&mut ev, &mut y, &mut stats, &lim, &mut |_| {}).unwrap();
                // The same steps through the scheme's step function.
                let (mut ev2, mut y2, mut drift) = (new_eval(), start, 0.0f64);
                let mut count = 0;
                while count < max_steps {
                    let next = fixed_step(Method::Symplectic, &mut ev2, &y2, h).unwrap();
                    if !(bounds.contains(next.x) && next.s < limit) {
                        break;
                    }
                    y2 = next;
                    let (n, _) = ev2.n(y2.x).unwrap();
                    drift = drift.max((y2.t.length() - n).abs());
                    count += 1;
                }
                assert!(taken > 5, "{interp:?}: {taken} steps");
                assert_eq!((taken, y), (count, y2), "{interp:?} limit {limit}");
                assert_eq!(stats.invariant_drift.to_bits(), drift.to_bits());
                // The scheme's last trial step evaluated where the run did
                // not: one evaluation more, no other difference.
                let extra = u32::from(count < max_steps);
                assert_eq!((stats.steps, stats.field_evals + extra), (count, ev2.evals));
            }
        }
    }
}
