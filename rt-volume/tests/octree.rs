//! Octree skipping never changes the answer by more than its bound.

use glam::DVec3;
use proptest::prelude::*;
use rt_volume::{
    BeamMask, BeamWindow, Grid, GridField, Interp, Method, TraceError, TraceParams, build_octree,
    trace, trace_beam, trace_skipping,
};

/// A 40³ field on the unit cube: ambient 1 plus compact Gaussian blobs.
fn blobs(spec: &[(f64, f64, f64, f64, f64)]) -> GridField {
    blobs_with(spec, Interp::Trilinear)
}

/// [`blobs`] with either interpolant.
fn blobs_with(spec: &[(f64, f64, f64, f64, f64)], interp: Interp) -> GridField {
    field_40(interp, |p| {
        let mut v = 1.0;
        for &(x, y, z, amp, s) in spec {
            v += amp * (-(p - DVec3::new(x, y, z)).length_squared() / (2.0 * s * s)).exp();
        }
        v
    })
}

/// `value(p)` sampled at the cell centres of a 40³ grid on the unit cube.
fn field_40(interp: Interp, value: impl Fn(DVec3) -> f64) -> GridField {
    let n = 40;
    let h = 1.0 / n as f64;
    let origin = DVec3::splat(0.5 * h);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                data.push(value(origin + DVec3::new(i as f64, j as f64, k as f64) * h) as f32);
            }
        }
    }
    GridField::new(Grid::new([n; 3], origin, DVec3::splat(h), data).unwrap(), interp, 1.0).unwrap()
}

fn blob() -> impl Strategy<Value = (f64, f64, f64, f64, f64)> {
    (0.2..0.8f64, 0.2..0.8f64, 0.2..0.8f64, 1e-4..3e-3f64, 0.03..0.08f64)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, rng_seed: proptest::test_runner::RngSeed::Fixed(11), failure_persistence: None, ..ProptestConfig::default() })]

    /// On random blob fields, trilinear or Catmull–Rom, the exit direction
    /// with skipping differs from uniform stepping by no more than the
    /// reported skip bound (plus the integrator's own error, ~1e-9 here);
    /// and skipping saves work.
    #[test]
    fn skipping_stays_within_its_bound(
        spec in prop::collection::vec(blob(), 1..4),
        rays in prop::collection::vec((0.05..0.95f64, 0.05..0.95f64, -0.2..0.2f64, -0.2..0.2f64), 6),
        tol_exp in 4.0..7.0f64,
        cubic in any::<bool>(),
    ) {
        let f = blobs_with(&spec, if cubic { Interp::CatmullRom } else { Interp::Trilinear });
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
    // Catmull–Rom's gradient bound is 2.34× looser and reaches a cell
    // further, so less is skipped (2.5× fewer evaluations here, not 3×+).
    for (interp, saving) in [(Interp::Trilinear, 3), (Interp::CatmullRom, 2)] {
        let spec = [(0.3, 0.3, 0.5, 2e-3, 0.04), (0.7, 0.6, 0.4, 1e-3, 0.03)];
        let f = blobs_with(&spec, interp);
        let tree = build_octree(&f).unwrap();
        let p = TraceParams::fixed(Method::Rk4, 0.005);
        let (mut eu, mut es) = (0, 0);
        for i in 0..20 {
            let o = DVec3::new(0.05 + 0.045 * f64::from(i), 0.5, -0.5);
            eu += trace(&f, o, DVec3::Z, &p).unwrap().stats.field_evals;
            es += trace_skipping(&f, &tree, o, DVec3::Z, &p, 1e-5).unwrap().stats.field_evals;
        }
        assert!(es * saving < eu, "{interp:?}: skipping {es} vs uniform {eu}");
    }
}

/// The tolerance is a budget for the whole ray, not for each node: on a
/// dense field (blobs everywhere, every node a little rough) a ray that
/// crosses many smooth nodes stops skipping once their bounds add up to
/// the tolerance, so its exit direction stays within the tolerance of
/// uniform stepping. (A per-node tolerance of 1e-3 let these rays spend
/// 1.2e-3.)
#[test]
fn the_tolerance_bounds_the_whole_ray_on_a_dense_field() {
    let mut spec = Vec::new();
    for k in 0..4 {
        for j in 0..4 {
            for i in 0..4 {
                let c = |v: usize| 0.125 + 0.25 * v as f64;
                let amp = 2e-4 * (1.0 + ((i + 2 * j + 3 * k) % 5) as f64);
                spec.push((c(i), c(j), c(k), amp, 0.07));
            }
        }
    }
    let f = blobs(&spec);
    let tree = build_octree(&f).unwrap();
    let p = TraceParams { tolerance: 1e-12, max_step: 1.0 / 40.0, ..TraceParams::accurate() };
    for tol in [1e-3, 1e-4, 1e-5] {
        let (mut used, mut skipped) = (0.0f64, 0);
        for i in 0..12 {
            for j in 0..12 {
                let o = DVec3::new(0.04 + 0.08 * f64::from(i), 0.04 + 0.08 * f64::from(j), -0.5);
                let d = DVec3::new(0.1, -0.05, 1.0);
                let uniform = trace(&f, o, d, &p).unwrap();
                let r = trace_skipping(&f, &tree, o, d, &p, tol).unwrap();
                let diff = (r.direction - uniform.direction).length();
                assert!(
                    r.stats.skip_bound <= tol * (1.0 + 1e-9),
                    "{tol}: {:e}",
                    r.stats.skip_bound
                );
                assert!(diff <= tol, "{tol} at {o}: deflection differs by {diff:e}");
                used = used.max(r.stats.skip_bound / tol);
                skipped = skipped.max(r.stats.skipped);
            }
        }
        // At the loosest tolerance the budget is really spent, over
        // several nodes (finer ones skip nothing on this field).
        if tol == 1e-3 {
            assert!(used > 0.5 && skipped >= 2, "spent {used} of the budget, {skipped} skips");
        }
    }
}

/// A beam mask's clear cells are exactly safe: every ray through one is
/// answered as the skip chain answers it (straight, no integration step),
/// for an axis-aligned and an oblique beam; most of a sparse field's beam
/// is clear, the rays through the blobs are not.
#[test]
fn beam_mask_clear_rays_are_what_skipping_gives() {
    let f = blobs(&[(0.3, 0.3, 0.5, 2e-3, 0.04), (0.7, 0.6, 0.4, 1e-3, 0.03)]);
    let tree = build_octree(&f).unwrap();
    let p = TraceParams::for_grid(&f);
    for (direction, u) in
        [(DVec3::Z, DVec3::X), (DVec3::new(0.3, -0.2, 1.0), DVec3::new(1.0, 0.5, 0.0))]
    {
        for tol in [1e-6, 1e-4] {
            let window = BeamWindow {
                center: DVec3::new(0.5, 0.5, 0.5) - direction.normalize(),
                direction,
                u,
                size: [1.3, 1.3],
                cells: [48, 40],
            };
            let mask = BeamMask::build(&f, &tree, &window, tol).unwrap();
            let (uu, vv) = {
                let d = direction.normalize();
                let uu = (u - d * d.dot(u)).normalize();
                (uu, d.cross(uu))
            };
            let (mut clear, mut blocked) = (0, 0);
            for j in 0..97 {
                for i in 0..101 {
                    let a = (i as f64 / 100.0 - 0.5) * 1.3;
                    let b = (j as f64 / 96.0 - 0.5) * 1.3;
                    let o = window.center + a * uu + b * vv;
                    let want = trace_skipping(&f, &tree, o, direction, &p, tol).unwrap();
                    let got = trace_beam(&f, &tree, &mask, o, direction, &p).unwrap();
                    if mask.clear_at(o).is_none() {
                        assert_eq!(got, want, "{o}");
                        blocked += usize::from(want.stats.steps > want.stats.skipped);
                        continue;
                    }
                    clear += 1;
                    assert_eq!(want.stats.steps, want.stats.skipped, "clear ray integrated: {o}");
                    assert_eq!(got.exit, want.exit);
                    assert!((got.position - want.position).length() < 1e-9, "{o}");
                    assert!((got.direction - want.direction).length() < 1e-12, "{o}");
                    assert!((got.optical_path - want.optical_path).abs() < 1e-9, "{o}");
                    assert!(
                        got.stats.skip_bound >= want.stats.skip_bound * (1.0 - 1e-6),
                        "{o} {} {}",
                        got.stats.skip_bound,
                        want.stats.skip_bound
                    );
                }
            }
            let total = 97 * 101;
            assert!(clear * 2 > total, "{tol}: only {clear} of {total} clear");
            assert!(blocked > 50, "{tol}: {blocked} rays met a rough brick");
            assert!(mask.clear_fraction() > 0.3 && mask.clear_fraction() < 1.0);
        }
    }
}

#[test]
fn beam_mask_rejects_bad_windows_and_other_fields() {
    let f = blobs(&[(0.5, 0.5, 0.5, 1e-3, 0.05)]);
    let tree = build_octree(&f).unwrap();
    let w = BeamWindow {
        center: DVec3::new(0.5, 0.5, -1.0),
        direction: DVec3::Z,
        u: DVec3::X,
        size: [1.0, 1.0],
        cells: [8, 8],
    };
    let bad = |w: BeamWindow, tol: f64| BeamMask::build(&f, &tree, &w, tol).is_err();
    assert!(!bad(w, 1e-5));
    assert!(bad(w, 0.0) && bad(w, f64::NAN));
    assert!(bad(BeamWindow { u: DVec3::Z, ..w }, 1e-5));
    assert!(bad(BeamWindow { direction: DVec3::ZERO, ..w }, 1e-5));
    assert!(bad(BeamWindow { size: [1.0, f64::INFINITY], ..w }, 1e-5));
    assert!(bad(BeamWindow { cells: [0, 8], ..w }, 1e-5));
    assert!(bad(BeamWindow { cells: [usize::MAX, 2], ..w }, 1e-5));
    // A tree built for another interpolant is refused, not trusted.
    let cubic = GridField::new(f.grid().clone(), Interp::CatmullRom, 1.0).unwrap();
    assert_eq!(BeamMask::build(&cubic, &tree, &w, 1e-5).err(), Some(TraceError::InvalidParams));
    assert_eq!(
        trace_skipping(&cubic, &tree, w.center, DVec3::Z, &TraceParams::for_grid(&f), 1e-5).err(),
        Some(TraceError::InvalidParams)
    );
    // A mask of another field is refused, not trusted.
    let mask = BeamMask::build(&f, &tree, &w, 1e-5).unwrap();
    let g = Grid::new([9; 3], DVec3::ZERO, DVec3::splat(0.1), vec![1.0; 729]).unwrap();
    let other = GridField::new(g, Interp::Trilinear, 1.0).unwrap();
    let p = TraceParams::for_grid(&f);
    assert_eq!(
        trace_beam(&other, &tree, &mask, w.center, DVec3::Z, &p),
        Err(TraceError::InvalidParams)
    );
    // NaN rays and bad parameters are the skipping tracer's errors.
    let nan = DVec3::new(f64::NAN, 0.5, -1.0);
    assert_eq!(trace_beam(&f, &tree, &mask, nan, DVec3::Z, &p), Err(TraceError::InvalidRay));
    let zero = TraceParams { step: 0.0, ..p };
    let o = DVec3::new(0.05, 0.05, -1.0);
    assert!(mask.clear_at(o).is_some());
    assert_eq!(trace_beam(&f, &tree, &mask, o, DVec3::Z, &zero), Err(TraceError::InvalidParams));
}

/// A 40³ field disturbed everywhere: a sum of plane waves.
fn waves(interp: Interp) -> GridField {
    field_40(interp, |p| {
        1.0 + 1e-3 * (17.0 * p.x + 5.0 * p.z).sin()
            + 7e-4 * (11.0 * p.y - 13.0 * p.z + 0.3).cos()
            + 5e-4 * (23.0 * p.x + 19.0 * p.y).sin()
    })
}

/// Where no node is smooth enough to cross, skipping must not change a
/// ray at all: the octree's trace equals the plain trace bit for bit,
/// evaluations and steps included, with either interpolant and any
/// fixed-step or adaptive scheme (the dense path asks the octree once,
/// then integrates the whole ray).
#[test]
fn a_dense_field_is_traced_exactly_as_without_the_octree() {
    for interp in [Interp::Trilinear, Interp::CatmullRom] {
        let f = waves(interp);
        let tree = build_octree(&f).unwrap();
        for params in [
            TraceParams { max_step: 0.05, ..TraceParams::fixed(Method::Symplectic, 0.05) },
            TraceParams::fixed(Method::Rk4, 0.025),
            TraceParams { max_step: 0.025, ..TraceParams::accurate() },
        ] {
            for i in 0..20 {
                let t = f64::from(i);
                let o = DVec3::new(0.1 + 0.04 * t, 0.9 - 0.035 * t, -0.3);
                let d = DVec3::new(0.1 * (0.7 * t).sin(), 0.1 * (1.3 * t).cos(), 1.0);
                let plain = trace(&f, o, d, &params).unwrap();
                let skipping = trace_skipping(&f, &tree, o, d, &params, 1e-9).unwrap();
                assert_eq!(skipping, plain, "{interp:?} {:?} ray {i}", params.method);
                assert_eq!(skipping.stats.skipped, 0);
            }
        }
    }
}

/// [`Octree::rough_run`] against a fine walk along the same line: every
/// brick before the distance it returns is rough, the one at it smooth
/// (or the line has left the cells when it says `+∞`).
#[test]
fn a_rough_run_ends_where_a_fine_walk_meets_a_smooth_brick() {
    let f = blobs(&[(0.3, 0.4, 0.5, 2e-3, 0.05), (0.7, 0.6, 0.4, 1e-3, 0.04)]);
    let tree = build_octree(&f).unwrap();
    let cells = 39.0;
    let tol = 2e-6;
    let mut finite = 0;
    for i in 0..200 {
        let t = f64::from(i);
        let p = [
            (0.37 * t).fract() * cells,
            (0.61 * t + 0.2).fract() * cells,
            (0.13 * t + 0.7).fract() * cells,
        ];
        let dir = DVec3::new((1.7 * t).sin(), (2.3 * t).cos(), (0.9 * t).sin() - 0.2).normalize();
        let ds = (dir * 40.0).to_array();
        let run = tree.rough_run(p, ds, tol);
        let at = |s: f64| [0, 1, 2].map(|a| p[a] + s * ds[a]);
        let smooth = |q: [f64; 3]| tree.smooth_node(q, tol).is_some();
        if tree.brick_of(p).is_some_and(|_| smooth(p)) {
            assert_eq!(run, 0.0, "smooth at the start, ray {i}");
            continue;
        }
        // Walk in steps of 1e-3 of a cell, staying off brick faces by
        // checking just before and just after the answer.
        let step = 1e-3 / 40.0;
        let end = if run.is_finite() { run - step } else { 10.0 };
        let mut s = 0.0;
        while s < end {
            let q = at(s);
            if tree.brick_of(q).is_none() {
                break;
            }
            assert!(!smooth(q), "ray {i}: smooth at {s} before the run's end {run}");
            s += step;
        }
        if run.is_finite() {
            finite += 1;
            assert!(smooth(at(run + step)), "ray {i}: rough just after the run's end {run}");
        } else {
            assert!(tree.brick_of(at(s)).is_none() || s >= end, "ray {i}: never left the cells");
        }
    }
    assert!(finite > 10, "the field must have runs that end: {finite}");
}
