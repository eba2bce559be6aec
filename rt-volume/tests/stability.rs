//! Numerical stability: steep gradients, grazing entries, long paths,
//! extreme steps, bad fields and bad input.

use glam::DVec3;
use rt_volume::{
    Bounds, Exit, FnField, GrinRod, IndexField, LinearIndex, Method, TraceError, TraceParams, trace,
};

fn unit_box() -> Bounds {
    Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0))
}

/// A near-discontinuity (a tanh step 1e-4 wide, index jump 1e-2): with
/// `max_step` below the layer's width the adaptive integrator sees the
/// layer and shrinks its step through it, stays finite and keeps
/// `|T| = n` to its tolerance; the result obeys Snell's law across the step
/// (`n sin θ` conserved along the interface).
#[test]
fn steep_gradient_is_resolved() {
    let w = 1e-4;
    let f = FnField {
        f: move |x: DVec3| {
            let th = (x.x / w).tanh();
            (1.0 + 0.005 * (1.0 + th), DVec3::new(0.005 * (1.0 - th * th) / w, 0.0, 0.0))
        },
        bounds: unit_box(),
        ambient: 1.0,
    };
    let d = DVec3::new(1.0, 0.6, 0.0).normalize();
    // Steps no longer than twice the layer's width, so stages land in it.
    let p = TraceParams { max_step: 2.0 * w, ..TraceParams::accurate() };
    let r = trace(&f, DVec3::new(-1.0, -0.5, 0.0), d, &p).unwrap();
    assert_eq!(r.exit, Exit::Left);
    assert!(r.position.is_finite() && r.direction.is_finite());
    assert!(r.stats.rejected > 0, "the step must have been cut at the interface");
    assert!(r.stats.invariant_drift < 1e-8, "drift {}", r.stats.invariant_drift);
    // T_y is conserved (n depends on x only): n₁ sin θ₁ = n₂ sin θ₂.
    let (n1, n2) = (f.eval(DVec3::new(-1.0, 0.0, 0.0)).0, f.eval(r.position).0);
    assert!((n2 * r.direction.y - n1 * d.y).abs() < 1e-9);
}

/// A ray lying in a face plane of the bounds, and one touching an edge, are
/// traced without panicking and leave with finite results.
#[test]
fn grazing_entries() {
    let f = LinearIndex { n0: 1.0, gradient: DVec3::new(0.0, 0.1, 0.0), bounds: unit_box() };
    for (o, d) in [
        (DVec3::new(-2.0, 1.0, 0.0), DVec3::X),
        (DVec3::new(-2.0, -1.0, -1.0), DVec3::X),
        (DVec3::new(-2.0, 1.0, 1.0), DVec3::new(1.0, -0.0, 0.0)),
        (DVec3::new(0.0, 0.0, -2.0), DVec3::new(1e-300, 0.0, 1.0)),
    ] {
        let r = trace(&f, o, d, &TraceParams::accurate()).unwrap();
        assert!(r.position.is_finite() && r.direction.is_finite(), "{o:?} {d:?}");
        assert!(matches!(r.exit, Exit::Left | Exit::Missed));
    }
}

/// A very long path (about 160 oscillations in a GRIN rod): the symplectic
/// scheme keeps `| |T| − n |` bounded, and RK4 at the same cost drifts more.
#[test]
fn long_paths_keep_the_invariant_bounded() {
    let f = GrinRod {
        n0: 1.5,
        alpha: 1.0,
        bounds: Bounds::new(DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, 1.0, 1000.0)),
    };
    let leap = trace(
        &f,
        DVec3::new(0.5, 0.0, 0.0),
        DVec3::Z,
        &TraceParams::fixed(Method::Symplectic, 0.05),
    )
    .unwrap();
    let rk4 = trace(&f, DVec3::new(0.5, 0.0, 0.0), DVec3::Z, &TraceParams::fixed(Method::Rk4, 0.2))
        .unwrap();
    assert_eq!(leap.exit, Exit::Left);
    assert_eq!(leap.position.z, 1000.0);
    assert!(leap.stats.invariant_drift < 2e-3, "leapfrog drift {}", leap.stats.invariant_drift);
    assert!(leap.position.x.abs() <= 0.5 + 1e-3, "amplitude grew: {}", leap.position.x);
    assert!(rk4.stats.field_evals.abs_diff(leap.stats.field_evals) < leap.stats.field_evals / 2);
}

/// Tiny steps stop at `max_steps` (no endless loop); huge steps still land
/// exactly on the exit face.
#[test]
fn extreme_steps() {
    let f = LinearIndex { n0: 1.0, gradient: DVec3::new(0.0, 0.2, 0.0), bounds: unit_box() };
    let tiny = TraceParams { max_steps: 1000, ..TraceParams::fixed(Method::Rk4, 1e-12) };
    let r = trace(&f, DVec3::new(-1.0, 0.0, 0.0), DVec3::X, &tiny).unwrap();
    assert_eq!(r.exit, Exit::MaxSteps);
    assert!(r.position.is_finite());
    let short = TraceParams { max_length: 0.5, ..TraceParams::fixed(Method::Rk4, 0.01) };
    assert_eq!(
        trace(&f, DVec3::new(-1.0, 0.0, 0.0), DVec3::X, &short).unwrap().exit,
        Exit::MaxLength
    );
    for m in Method::ALL {
        let huge = TraceParams::fixed(m, 1e6);
        let r = trace(&f, DVec3::new(-1.0, 0.0, 0.0), DVec3::X, &huge).unwrap();
        assert_eq!(r.exit, Exit::Left, "{m:?}");
        assert!(f.bounds().contains(r.position), "{m:?}: {:?}", r.position);
        assert!(r.position.is_finite());
    }
}

/// A field that returns NaN (or a non-positive index) is an error naming
/// the point; bad rays and parameters are errors, not panics.
#[test]
fn bad_fields_rays_and_params_are_errors() {
    let nan = FnField {
        f: |x: DVec3| if x.x > 0.0 { (f64::NAN, DVec3::ZERO) } else { (1.0, DVec3::ZERO) },
        bounds: unit_box(),
        ambient: 1.0,
    };
    match trace(&nan, DVec3::new(-2.0, 0.0, 0.0), DVec3::X, &TraceParams::accurate()) {
        Err(TraceError::BadField { at }) => assert!(at.x > 0.0),
        other => panic!("expected BadField, got {other:?}"),
    }
    let neg = FnField { f: |_| (-1.0, DVec3::ZERO), bounds: unit_box(), ambient: 1.0 };
    assert!(matches!(
        trace(&neg, DVec3::ZERO, DVec3::X, &TraceParams::accurate()),
        Err(TraceError::BadField { .. })
    ));
    let f = LinearIndex { n0: 1.0, gradient: DVec3::ZERO, bounds: unit_box() };
    let p = TraceParams::accurate();
    assert_eq!(trace(&f, DVec3::NAN, DVec3::X, &p), Err(TraceError::InvalidRay));
    assert_eq!(trace(&f, DVec3::ZERO, DVec3::ZERO, &p), Err(TraceError::InvalidRay));
    assert_eq!(trace(&f, DVec3::ZERO, DVec3::INFINITY, &p), Err(TraceError::InvalidRay));
    for bad in [
        TraceParams { step: 0.0, ..p },
        TraceParams { step: f64::NAN, ..p },
        TraceParams { tolerance: -1.0, ..p },
        TraceParams { max_steps: 0, ..p },
        TraceParams { max_length: f64::INFINITY, ..p },
    ] {
        assert_eq!(trace(&f, DVec3::ZERO, DVec3::X, &bad), Err(TraceError::InvalidParams));
    }
}

/// docs/oracles.md §1 at every scale: the catenary in `n = 1 + (0.2/s)·y` over a
/// box scaled by `s = 10^k`, k in -8..=8, launched along +x (direction
/// also scaled, by 1/s), with the step and path limit scaled with the box.
/// The path has the same shape at every scale, so the exit height over `s`
/// must match the oracle to 1e-7, the slope and the optical path over `s`
/// too, and `| |T| − n |` stays at rounding: fixed-step RK4 at every
/// scale, the adaptive scheme (absolute tolerance) from 1e-8 to 1e6.
#[test]
fn catenary_is_scale_free_from_1e_minus_8_to_1e8() {
    let (g, x) = (0.2f64, 2.0f64);
    let y = (g * x).cosh() / g - 1.0 / g;
    let slope = (g * x).sinh();
    let opl = x / 2.0 + (2.0 * g * x).sinh() / (4.0 * g);
    for k in -8..=8 {
        let s = 10f64.powi(k);
        let f = LinearIndex {
            n0: 1.0,
            gradient: DVec3::new(0.0, g / s, 0.0),
            bounds: Bounds::new(DVec3::new(0.0, -s, -s), DVec3::new(2.0 * s, s, s)),
        };
        // Adaptive's tolerance is absolute, in position and in T alike
        // (documented): above s = 1e6 a 1e-10 bound is below f64 round-off
        // of the position, and scaling it with s loosens T. So the
        // adaptive scheme is held to 1e-8 … 1e6, fixed-step RK4 (whose
        // steps scale with the box) to the whole range.
        let methods: &[Method] =
            if s <= 1e6 { &[Method::Adaptive, Method::Rk4] } else { &[Method::Rk4] };
        for &method in methods {
            let p = match method {
                Method::Adaptive => TraceParams { step: 1e-2 * s, ..TraceParams::accurate() },
                _ => TraceParams::fixed(method, 1e-3 * s),
            };
            let p = TraceParams { max_length: 10.0 * s, ..p };
            let r = trace(&f, DVec3::ZERO, DVec3::X / s, &p).unwrap();
            assert_eq!(r.exit, Exit::Left, "s = {s:e} {method:?}");
            let rel = |a: f64, b: f64| ((a - b) / b).abs();
            assert!(rel(r.position.x / s, x) < 1e-12, "s = {s:e}: x {}", r.position.x);
            assert!(
                rel(r.position.y / s, y) < 1e-7,
                "s = {s:e} {method:?}: y/s {}",
                r.position.y / s
            );
            assert!(rel(r.direction.y / r.direction.x, slope) < 1e-7, "s = {s:e}: slope");
            assert!(rel(r.optical_path / s, opl) < 1e-7, "s = {s:e}: optical path");
            assert!(r.stats.invariant_drift < 1e-9, "s = {s:e}: drift {}", r.stats.invariant_drift);
        }
    }
}
