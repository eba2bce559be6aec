//! Integrating the ray equation `d/ds (n dx/ds) = ∇n`.
//!
//! With the parameter `dt = ds/n` and `T = n dx/ds` the equation becomes
//! the first-order system `dx/dt = T`, `dT/dt = n∇n = ½∇(n²)`, with the
//! invariant `|T| = n`; the optical path obeys `d(OPL)/dt = n²`. The system
//! is Hamiltonian (`H = ½|T|² − ½n²(x)`, separable), which the symplectic
//! leapfrog scheme exploits. Step sizes are in `t`, which equals arc length
//! where `n = 1`; the arc length itself is integrated along (`ds/dt = n`).
//!
//! A trace ends on an event: the ray leaves the bounds, or its arc length
//! inside them reaches [`TraceParams::max_length`]. The step that would
//! pass the event is replaced by one of the same scheme shortened to land
//! on it (regula falsi on the step length), so every scheme keeps its
//! order up to the exit. Stage points of that step (and of any step near a
//! face) may fall just outside the box; they see the field's first-order
//! continuation from the nearest point of the box, never the ambient index
//! the ray meets only after leaving (see `Eval::n`).

mod eval;
mod params;
mod path_state;
mod run;
mod schemes;
mod walk;

pub use params::{Exit, Method, TraceError, TraceParams, TraceResult, TraceStats};
pub use path_state::PathState;
#[cfg(test)]
pub(crate) use schemes::A;
pub use walk::{Begin, Leg, trace, trace_begin, trace_leg, trace_visiting};
pub(crate) use walk::{Offer, Skip, check_params, trace_impl};

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::{Bounds, LinearIndex};

    /// Found by the `integrators` fuzz target: a direction of length
    /// 3e-241 squared to 0 in `normalize`, and the trace returned NaN with
    /// `Exit::Left`. Tiny and huge directions now trace as their unit
    /// vector does.
    #[test]
    fn fuzz_regression_tiny_and_huge_directions() {
        let f = LinearIndex {
            n0: 1.0,
            gradient: DVec3::new(0.0, 0.1, 0.0),
            bounds: Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
        };
        let p = TraceParams::accurate();
        let unit = trace(&f, DVec3::new(-2.0, 0.0, 0.0), DVec3::X, &p).unwrap();
        for s in [-2.999393638964874e-241, 1e-300, 1e300, f64::MAX] {
            let r = trace(&f, DVec3::new(-2.0, 0.0, 0.0), DVec3::X * s.abs(), &p).unwrap();
            assert_eq!(r, unit, "direction scaled by {s:e}");
        }
        // A negative step cap (also from the fuzzer) traced backwards out
        // of the box; it is an error now, as is NaN.
        for max_step in [-0.1875, 0.0, f64::NAN] {
            let q = TraceParams { max_step, ..TraceParams::fixed(Method::Symplectic, 3.875) };
            assert_eq!(trace(&f, DVec3::ZERO, DVec3::X, &q), Err(TraceError::InvalidParams));
        }
        // n ≈ 3.4e38 with a gradient: one Euler step leaves far from
        // straight and the exit search cannot resolve it; the exit point
        // must still be on the box (it was 1e21 away).
        let huge = LinearIndex {
            n0: 3.4028234663852886e38,
            gradient: DVec3::new(0.0, -1.625, -1.625),
            bounds: Bounds::new(DVec3::new(-2.3125, -1.5, -4.0), DVec3::ZERO),
        };
        let r = trace(
            &huge,
            DVec3::new(-1.125, -1.625, -1.625),
            DVec3::new(-3.9375, 3.4028234663852886e38, 3.4028234663852886e38),
            &TraceParams::fixed(Method::Euler, 0.01),
        )
        .unwrap();
        assert_eq!(r.exit, Exit::Left);
        assert!(huge.bounds.contains(r.position), "{r:?}");
        // An ambient index of 4e281 around a field of n ≈ 1. The entry
        // point rounds to just outside the box (x = 1.9375 − 9e-16), where
        // the trace used to take the ambient index for the field's:
        // `T = 4e281·d` inside, and the path overflowed (an error, rather
        // than an infinite result). The field's continuation now gives its
        // own index there: a finite trace, `|T| = n` throughout, the
        // optical path dominated by the ambient stretch (4e281 · 5.9).
        let grid = crate::Grid::new(
            [2, 2, 2],
            DVec3::splat(3.875),
            DVec3::splat(3.875),
            alloc::vec![0.999, 0.999, 0.999, 0.999, 0.999, 1.0, 1.008, 1.0],
        )
        .unwrap();
        let field =
            crate::GridField::new(grid, crate::Interp::CatmullRom, 4.147_771_230_004_15e281)
                .unwrap();
        let q = TraceParams {
            tolerance: 1.1920928955078125e-7,
            max_step: 3.875,
            max_steps: 5020,
            max_length: 3.875,
            ..TraceParams::fixed(Method::Symplectic, 1.1920928955078125e-7)
        };
        let r =
            trace(&field, DVec3::new(-2.125, 3.4375, 3.4375), DVec3::new(3.4375, -1.125, 3.5), &q)
                .unwrap();
        assert!(r.position.is_finite() && r.optical_path.is_finite(), "{r:?}");
        assert!(r.stats.invariant_drift < 1e-12, "{r:?}");
        assert!((r.optical_path / 4.147_771_230_004_15e281 - 5.948).abs() < 1e-3, "{r:?}");
        // The fuzzer's own case: a ray beside the box along a tiny -z.
        let f = LinearIndex {
            n0: 1.5,
            gradient: DVec3::splat(-1.625),
            bounds: Bounds::new(DVec3::new(-2.3125, -1.625, -4.0), DVec3::ZERO),
        };
        let r = trace(
            &f,
            DVec3::new(-3.5, 0.0, 0.0),
            DVec3::new(0.0, 0.0, -2.999393638964874e-241),
            &p,
        )
        .unwrap();
        assert_eq!(r.exit, Exit::Missed);
        assert!(r.position.is_finite() && r.direction.is_finite());
    }
}
