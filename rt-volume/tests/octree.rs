//! Octree skipping never changes the answer by more than its bound.

use glam::DVec3;
use proptest::prelude::*;
use rt_volume::{
    Grid, GridField, Interp, Method, TraceParams, build_octree, trace, trace_skipping,
};

/// A 40³ field on the unit cube: ambient 1 plus compact Gaussian blobs.
fn blobs(spec: &[(f64, f64, f64, f64, f64)]) -> GridField {
    let n = 40;
    let h = 1.0 / n as f64;
    let origin = DVec3::splat(0.5 * h);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h;
                let mut v = 1.0;
                for &(x, y, z, amp, s) in spec {
                    v += amp * (-(p - DVec3::new(x, y, z)).length_squared() / (2.0 * s * s)).exp();
                }
                data.push(v as f32);
            }
        }
    }
    GridField::new(
        Grid::new([n; 3], origin, DVec3::splat(h), data).unwrap(),
        Interp::Trilinear,
        1.0,
    )
    .unwrap()
}

fn blob() -> impl Strategy<Value = (f64, f64, f64, f64, f64)> {
    (0.2..0.8f64, 0.2..0.8f64, 0.2..0.8f64, 1e-4..3e-3f64, 0.03..0.08f64)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, rng_seed: proptest::test_runner::RngSeed::Fixed(11), failure_persistence: None, ..ProptestConfig::default() })]

    /// On random blob fields, the exit direction with skipping differs from
    /// uniform stepping by no more than the reported skip bound (plus the
    /// integrator's own error, ~1e-9 here); and skipping saves work.
    #[test]
    fn skipping_stays_within_its_bound(
        spec in prop::collection::vec(blob(), 1..4),
        rays in prop::collection::vec((0.05..0.95f64, 0.05..0.95f64, -0.2..0.2f64, -0.2..0.2f64), 6),
        tol_exp in 4.0..7.0f64,
    ) {
        let f = blobs(&spec);
        let tree = build_octree(&f).unwrap();
        let tol = 10f64.powf(-tol_exp);
        // Tight adaptive integration (steps ≤ a cell) on both sides, so the
        // comparison sees the skipping, not the integrator's own error at
        // the trilinear field's gradient kinks.
        let p = TraceParams { tolerance: 1e-12, max_step: 1.0 / 40.0, ..TraceParams::accurate() };
        for (x, y, dx, dy) in rays {
            let o = DVec3::new(x, y, -0.5);
            let d = DVec3::new(dx, dy, 1.0);
            let uniform = trace(&f, o, d, &p).unwrap();
            let skipping = trace_skipping(&f, &tree, o, d, &p, tol).unwrap();
            let diff = (skipping.direction - uniform.direction).length();
            prop_assert!(
                diff <= skipping.stats.skip_bound + 1e-8,
                "deflection differs by {diff:e}, bound {:e}", skipping.stats.skip_bound
            );
        }
    }
}

/// A sparse field (blobs filling a few % of the volume) is mostly skipped:
/// far fewer evaluations than uniform stepping.
#[test]
fn sparse_fields_are_mostly_skipped() {
    let f = blobs(&[(0.3, 0.3, 0.5, 2e-3, 0.04), (0.7, 0.6, 0.4, 1e-3, 0.03)]);
    let tree = build_octree(&f).unwrap();
    let p = TraceParams::fixed(Method::Rk4, 0.005);
    let (mut eu, mut es) = (0, 0);
    for i in 0..20 {
        let o = DVec3::new(0.05 + 0.045 * f64::from(i), 0.5, -0.5);
        eu += trace(&f, o, DVec3::Z, &p).unwrap().stats.field_evals;
        es += trace_skipping(&f, &tree, o, DVec3::Z, &p, 1e-5).unwrap().stats.field_evals;
    }
    assert!(es * 3 < eu, "skipping {es} vs uniform {eu}");
}
