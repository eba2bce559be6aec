//! The closed-form oracles of `docs/oracles.md` §1–§5, and the invariants.

use glam::DVec3;
use rt_volume::{
    Bounds, Constant, Exit, GaussianBump, GrinRod, IndexField, LinearIndex, LinearSquared,
    Luneburg, Method, TraceParams, trace,
};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// The high-order settings the oracles are checked with.
fn high_order() -> [TraceParams; 2] {
    [
        TraceParams { tolerance: 1e-12, ..TraceParams::accurate() },
        TraceParams::fixed(Method::Rk4, 1e-3),
    ]
}

fn catenary_field() -> LinearIndex {
    LinearIndex {
        n0: 1.0,
        gradient: DVec3::new(0.0, 0.2, 0.0),
        bounds: Bounds::new(DVec3::new(0.0, -1.0, -1.0), DVec3::new(2.0, 1.0, 1.0)),
    }
}

/// §1: `y(x) = (n₀/g)(cosh(g x/n₀) − 1)`; slope `sinh(g x/n₀)`; optical path
/// `∫ n ds = n₀ (x/2 + (n₀/4g) sinh(2 g x/n₀))`.
#[test]
fn catenary_in_a_linear_index() {
    let f = catenary_field();
    let (n0, g, x) = (1.0f64, 0.2f64, 2.0f64);
    let y = n0 / g * ((g * x / n0).cosh() - 1.0);
    assert!((y - 0.40536186).abs() < 1e-8, "oracle value {y}");
    let slope = (g * x / n0).sinh();
    let opl = n0 * (x / 2.0 + n0 / (4.0 * g) * (2.0 * g * x / n0).sinh());
    for p in high_order() {
        let r = trace(&f, DVec3::ZERO, DVec3::X, &p).unwrap();
        assert_eq!(r.exit, Exit::Left);
        assert_eq!(r.position.x, 2.0);
        assert!(rel(r.position.y, y) < 1e-7, "{:?}: y {} vs {y}", p.method, r.position.y);
        assert!(rel(r.direction.y / r.direction.x, slope) < 1e-7, "{:?}: slope", p.method);
        assert!(rel(r.optical_path, opl) < 1e-7, "{:?}: opl {} vs {opl}", p.method, r.optical_path);
        assert!(r.position.z.abs() < 1e-15);
    }
}

/// Euler, the original tool's scheme: error ≈ 2.1e-2 at step 0.1, and it
/// halves with each halving of the step (first order).
#[test]
fn euler_error_shrinks_linearly() {
    let f = catenary_field();
    let y = 0.405_361_86;
    let err = |h: f64| {
        let r = trace(&f, DVec3::ZERO, DVec3::X, &TraceParams::fixed(Method::Euler, h)).unwrap();
        (r.position.y - y).abs()
    };
    let e = [err(0.1), err(0.05), err(0.025), err(0.0125)];
    assert!((e[0] - 2.1e-2).abs() < 0.3e-2, "Euler at 0.1: {}", e[0]);
    for w in e.windows(2) {
        let ratio = w[0] / w[1];
        assert!((ratio - 2.0).abs() < 0.25, "ratio {ratio} ({e:?})");
    }
}

/// §2: `n² = n₀² + a y`, horizontal launch: `y = a x² / (4 n₀²)`; RK4 is
/// exact up to round-off (the solution is a polynomial of degree 2 in t).
#[test]
fn parabola_in_linear_n_squared() {
    let (n0, a) = (1.5f64, 0.3f64);
    let f = LinearSquared {
        n0,
        a: DVec3::new(0.0, a, 0.0),
        bounds: Bounds::new(DVec3::new(0.0, -1.0, -1.0), DVec3::new(3.0, 2.0, 1.0)),
    };
    let y = a * 9.0 / (4.0 * n0 * n0);
    let r = trace(&f, DVec3::ZERO, DVec3::X, &TraceParams::fixed(Method::Rk4, 0.1)).unwrap();
    assert_eq!(r.position.x, 3.0);
    assert!((r.position.y - y).abs() < 1e-13, "{} vs {y}", r.position.y);
    let r = trace(&f, DVec3::ZERO, DVec3::X, &TraceParams::accurate()).unwrap();
    assert!(rel(r.position.y, y) < 1e-7);
}

/// §3: GRIN rod `n² = n₀²(1 − α² r²)`, meridional ray parallel to the axis
/// at `r₀`: `r(z) = r₀ cos(n₀ α z / β)`, `β = n₀ √(1 − α² r₀²)`.
#[test]
fn grin_rod_meridional_ray() {
    let (n0, alpha, r0, len) = (1.5f64, 0.5f64, 0.3f64, 4.0f64);
    let f = GrinRod {
        n0,
        alpha,
        bounds: Bounds::new(DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, 1.0, len)),
    };
    let beta = n0 * (1.0 - alpha * alpha * r0 * r0).sqrt();
    let w = n0 * alpha / beta;
    let (x, slope) = (r0 * (w * len).cos(), -r0 * w * (w * len).sin());
    for p in high_order() {
        let r = trace(&f, DVec3::new(r0, 0.0, 0.0), DVec3::Z, &p).unwrap();
        assert_eq!(r.position.z, len);
        assert!(rel(r.position.x, x) < 1e-7, "{:?}: {} vs {x}", p.method, r.position.x);
        assert!(rel(r.direction.x / r.direction.z, slope) < 1e-7, "{:?}", p.method);
        assert!(r.position.y.abs() < 1e-14, "stays meridional");
    }
}

/// §4: every ray of a beam along `+z` entering a Luneburg lens reaches the
/// far pole `R·ẑ`, leaves along `−p₀/R`, and the optical path from the
/// tangent plane `z = −R` to the focus is `R(1 + π/2)`.
#[test]
fn luneburg_lens_focuses_a_parallel_beam() {
    let big_r = 2.0;
    let f = Luneburg { center: DVec3::ZERO, radius: big_r };
    let p = TraceParams { tolerance: 1e-13, ..TraceParams::accurate() };
    for (x, y) in [(0.3, 0.0), (1.0, 0.7), (-1.2, 0.4), (0.0, -1.9)] {
        let p0 = DVec3::new(x, y, -(big_r * big_r - x * x - y * y).sqrt());
        let r = trace(&f, DVec3::new(x, y, -big_r), DVec3::Z, &p).unwrap();
        assert!(
            (r.position - DVec3::new(0.0, 0.0, big_r)).length() < 1e-7 * big_r,
            "{:?}",
            r.position
        );
        let d = -p0 / big_r;
        assert!((r.direction - d).length() < 1e-7, "{:?} vs {d:?}", r.direction);
        let opl = big_r * (1.0 + core::f64::consts::FRAC_PI_2);
        assert!(rel(r.optical_path, opl) < 1e-7, "opl {} vs {opl}", r.optical_path);
        assert!(r.stats.invariant_drift < 1e-9);
    }
}

/// §5: a weak Gaussian bump deflects by `ε(r) = −√(2π)·δ·(r/σ)·g(r)·r̂`
/// and delays the phase by `√(2π) σ δ g(r)` of optical path (first order in
/// δ: relative agreement ~δ).
#[test]
fn gaussian_bump_deflection_and_phase() {
    let (delta, sigma) = (1e-4, 1.0);
    let f = GaussianBump::new(DVec3::ZERO, delta, sigma, 8.0);
    let r = trace(&f, DVec3::new(1.0, 0.0, -10.0), DVec3::Z, &TraceParams::accurate()).unwrap();
    let eps_x = r.direction.x / r.direction.z;
    assert!(rel(eps_x, -1.520347e-4) < 1e-3, "ε_x = {eps_x}");
    assert!(r.direction.y.abs() < 1e-18);
    // Optical path excess over the straight geometric length.
    let geometric = (r.position - DVec3::new(1.0, 0.0, -10.0)).length();
    let excess = r.optical_path - geometric;
    let g = (-0.5f64).exp();
    let want = (2.0 * core::f64::consts::PI).sqrt() * sigma * delta * g;
    assert!(rel(excess, want) < 1e-3, "phase path {excess} vs {want}");
}

/// `T_z` is conserved where `n` does not depend on z.
#[test]
fn t_z_is_conserved_in_z_invariant_fields() {
    let f = catenary_field();
    let d = DVec3::new(1.0, 0.1, 0.4).normalize();
    let r = trace(&f, DVec3::ZERO, d, &TraceParams::accurate()).unwrap();
    let (n_exit, _) = f.eval(r.position);
    let (n_entry, _) = f.eval(DVec3::ZERO);
    assert!((n_exit * r.direction.z - n_entry * d.z).abs() < 1e-10);
}

/// `x × T` is conserved in spherically symmetric fields, and the ray stays
/// in the plane through the centre.
#[test]
fn angular_momentum_is_conserved_in_spherical_fields() {
    let f = GaussianBump::new(DVec3::ZERO, 0.05, 1.0, 5.0);
    let o = DVec3::new(0.4, -0.7, -5.0);
    let d = DVec3::new(0.1, 0.2, 1.0).normalize();
    let p = TraceParams { tolerance: 1e-13, ..TraceParams::accurate() };
    let r = trace(&f, o, d, &p).unwrap();
    let l0 = o.cross(f.eval(o).0 * d);
    let (n, _) = f.eval(r.position);
    let l1 = r.position.cross(n * r.direction);
    assert!((l1 - l0).length() < 1e-10, "{l0:?} → {l1:?}");
    assert!(r.position.dot(l0).abs() < 1e-9, "left the plane");
    assert!(r.direction.dot(DVec3::Z) < 0.9999, "the bump did bend the ray");
}

/// A uniform field gives exactly straight rays for every method.
#[test]
fn uniform_fields_give_straight_rays() {
    let f = Constant { n: 1.33, bounds: Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0)) };
    let d = DVec3::new(0.3, -0.2, 1.0).normalize();
    let o = DVec3::new(0.1, 0.2, -3.0);
    for m in Method::ALL {
        let r = trace(&f, o, d, &TraceParams::fixed(m, 0.01)).unwrap();
        // T = n·d is never changed: the direction is bit-identical to the
        // launch direction as the integrator stores it.
        assert_eq!(r.direction, (1.33 * d).normalize(), "{m:?} bent the ray");
        let off = (r.position - o) - (r.position - o).dot(d) * d;
        assert!(off.length() < 1e-14, "{m:?}: {off:?}");
        // It leaves through the face x = 1 (x grows 0.3 per unit of z).
        assert_eq!(r.position.x, 1.0);
        assert!(rel(r.optical_path, 1.33 * (r.position - o).length()) < 1e-12);
    }
}

/// Rays that miss the bounds are returned unchanged; rays starting inside
/// are integrated from their origin.
#[test]
fn misses_and_starts_inside() {
    let f = catenary_field();
    let r = trace(&f, DVec3::new(0.0, 5.0, 0.0), DVec3::X, &TraceParams::accurate()).unwrap();
    assert_eq!(r.exit, Exit::Missed);
    assert_eq!(r.stats.field_evals, 0);
    let inside = trace(&f, DVec3::new(1.0, 0.0, 0.0), DVec3::X, &TraceParams::accurate()).unwrap();
    assert_eq!(inside.exit, Exit::Left);
    assert_eq!(inside.position.x, 2.0);
    assert!(inside.position.y > 0.0 && inside.position.y < 0.40536186);
}
