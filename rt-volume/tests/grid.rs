//! Gridded fields against the analytic field they sample.

use glam::DVec3;
use rt_volume::{GaussianBump, Grid, GridField, IndexField, Interp, TraceParams, trace};

/// The bump sampled at cell centres of an `n³` grid over its bounds.
fn sampled(f: &GaussianBump, n: usize, interp: Interp) -> GridField {
    let b = f.bounds();
    let h = (b.max - b.min) / n as f64;
    let origin = b.min + 0.5 * h;
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                data.push(f.eval(origin + DVec3::new(i as f64, j as f64, k as f64) * h).0 as f32);
            }
        }
    }
    GridField::new(Grid::new([n; 3], origin, h, data).unwrap(), interp, 1.0).unwrap()
}

/// Deflection through a gridded bump converges to the analytic one as the
/// grid is refined (halving the spacing: trilinear error / ≥ 2, Catmull–Rom
/// / ≥ 3), and the C¹ Catmull–Rom interpolant is the more accurate.
#[test]
fn gridded_deflection_converges_to_analytic() {
    let f = GaussianBump::new(DVec3::ZERO, 1e-2, 1.0, 4.0);
    let o = DVec3::new(0.8, 0.3, -4.0);
    let p = TraceParams { max_step: 0.05, ..TraceParams::accurate() };
    let exact = trace(&f, o, DVec3::Z, &p).unwrap().direction;
    let err = |n: usize, interp: Interp| {
        let g = sampled(&f, n, interp);
        let p = TraceParams { max_step: g.grid().spacing().x, ..p };
        (trace(&g, o, DVec3::Z, &p).unwrap().direction - exact).length()
    };
    // Trilinear's gradient is first-order accurate, Catmull–Rom's higher.
    for (interp, gain) in [(Interp::Trilinear, 2.0), (Interp::CatmullRom, 3.0)] {
        let (coarse, fine) = (err(24, interp), err(48, interp));
        assert!(fine < coarse / gain, "{interp:?}: {coarse} → {fine}");
    }
    assert!(err(48, Interp::CatmullRom) < err(48, Interp::Trilinear));
    assert!(err(48, Interp::CatmullRom) < 5e-5, "{}", err(48, Interp::CatmullRom));
}
