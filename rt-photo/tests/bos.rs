//! Background-oriented schlieren against ORACLES §7 and the thin-lens
//! formulas.

use glam::DVec3;
use rt_photo::{Bos, DotBackground, ThinLens, TraceParams};
use rt_volume::{Bounds, Constant, GaussianBump};

/// ORACLES §7's camera: f = 0.1 m focused on the background at Z_B = 2.1 m
/// (M = 0.05), 5 µm pixels, looking along +z from the origin.
fn camera(f_number: f64, width: usize, height: usize) -> ThinLens {
    ThinLens {
        position: DVec3::ZERO,
        direction: DVec3::Z,
        up: DVec3::Y,
        focal_length: 0.1,
        f_number,
        focus_distance: 2.1,
        pixel_pitch: 5e-6,
        width,
        height,
    }
}

fn bos(cam: ThinLens, k: u32) -> Bos {
    Bos {
        camera: cam,
        background_distance: 2.1,
        background: DotBackground::for_camera(&cam, 3.0, 4.0, 9),
        aperture_samples: k,
        params: TraceParams::accurate(),
    }
}

/// §7: a Gaussian bump (δ = 1e-4, σ = 1 cm) at Z_A = 1.1 m (Z_D = 1 m):
/// the background seen through impact point r moves by
/// `M·Z_D·|ε(r)|`, 1.5203 pixels at r = σ. With a small aperture (f/400:
/// the rays of a pixel cross the bump within 0.12 mm) the ground truth at
/// every pixel of a row through the bump is the paraxial relation at that
/// pixel's impact point, to 1 % of the peak.
#[test]
fn displacement_is_the_paraxial_relation() {
    let (delta, sigma, z_a) = (1e-4, 0.01, 1.1);
    let field = GaussianBump::new(DVec3::new(0.0, 0.0, z_a), delta, sigma, 5.0);
    let (w, h) = (420, 1);
    let cam = camera(400.0, w, h);
    let out = bos(cam, 2).render(&field, 1).unwrap();
    let m = cam.magnification();
    assert!((m - 0.05).abs() < 1e-15);
    let peak = m * 1.0 * 1.520_347e-4 / 5e-6;
    assert!((peak - 1.5203).abs() < 1e-4);
    let mut best: f64 = 0.0;
    for i in 0..w {
        // The pixel centre's chief ray meets the bump's mid-plane at
        // x = x_focus · Z_A / Z_B.
        let x = cam.focus_point(i as f64 + 0.5, 0.5).x * z_a / 2.1;
        let eps = -(core::f64::consts::TAU).sqrt()
            * delta
            * (x / sigma)
            * (-(x * x) / (2.0 * sigma * sigma)).exp();
        // Looking along +z with y up, the image's x (right) is −x.
        let want = -m * 1.0 * eps / 5e-6;
        let got = out.displacement[i];
        assert!((got[0] - want).abs() < 0.01 * peak, "pixel {i}: Δx {} vs {want}", got[0]);
        // (Sub-pixel jitter samples ε_y about the axis: ≤ 1 % of the peak.)
        assert!(got[1].abs() < 0.01 * peak, "pixel {i}: Δy {}", got[1]);
        best = best.max(got[0].abs());
    }
    assert!((best / peak - 1.0).abs() < 0.01, "peak {best} vs {peak}");
    // The flow image differs from the reference where the dots moved.
    assert!(out.flow.iter().zip(&out.reference).any(|(a, b)| (a - b).abs() > 0.05));
}

/// A uniform field moves nothing: zero displacement, and the flow image
/// is the reference.
#[test]
fn uniform_field_moves_nothing() {
    let field = Constant {
        n: 1.0,
        bounds: Bounds::new(DVec3::new(-0.1, -0.1, 1.0), DVec3::new(0.1, 0.1, 1.2)),
    };
    let out = bos(camera(8.0, 24, 16), 3).render(&field, 2).unwrap();
    assert!(out.displacement.iter().all(|d| d[0].abs() < 1e-9 && d[1].abs() < 1e-9));
    assert!(out.flow.iter().zip(&out.reference).all(|(a, b)| (a - b).abs() < 1e-9));
    // The background is really there (dots and gaps).
    let (lo, hi) =
        out.reference.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
    assert!(lo < 0.2 && hi > 0.6, "background range {lo}..{hi}");
}

/// The thin lens: a pixel's rays all meet at its focus point, and cross
/// the plane at Z_A in a disc that images onto the sensor with diameter
/// `D·M·Z_D/Z_A` (§7: 113.6 pixels at f/8) — the out-of-focus blur of
/// the flow, growing with the aperture.
#[test]
fn out_of_focus_blur_is_the_thin_lens_disc() {
    let (z_a, z_b) = (1.1, 2.1);
    for n_f in [2.0, 4.0, 8.0, 16.0] {
        let cam = camera(n_f, 64, 64);
        let target = cam.focus_point(40.25, 20.75);
        let mut pts = Vec::new();
        // Lens samples over the closed square, so the disc's rim is in.
        for a in 0..=48 {
            for b in 0..=48 {
                let (o, d) = cam.ray(40.25, 20.75, (f64::from(a) / 48.0, f64::from(b) / 48.0));
                // Through the focus point.
                let t = (target - o).dot(d);
                assert!((o + t * d - target).length() < 1e-12);
                pts.push(o + (z_a - o.z) / d.z * d);
            }
        }
        let diameter = pts
            .iter()
            .map(|p| pts.iter().map(|q| (*p - *q).length()).fold(0.0, f64::max))
            .fold(0.0, f64::max);
        // Object-side footprint D·Z_D/Z_B, imaged from Z_A with s_B/Z_A.
        let s_b = 0.1 * z_b / (z_b - 0.1);
        let on_sensor = diameter * s_b / z_a / 5e-6;
        let want = cam.aperture() * cam.magnification() * (z_b - z_a) / z_a / 5e-6;
        assert!((on_sensor / want - 1.0).abs() < 0.01, "f/{n_f}: {on_sensor} px vs {want}");
        if n_f == 8.0 {
            assert!((want - 113.6).abs() < 0.1, "{want}");
        }
    }
}

#[test]
fn bad_set_ups_are_errors() {
    let f = Constant { n: 1.0, bounds: Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0)) };
    let good = bos(camera(8.0, 4, 4), 1);
    assert!(good.render(&f, 0).is_ok());
    for bad in [
        Bos { camera: ThinLens { focus_distance: 0.05, ..good.camera }, ..good },
        Bos { camera: ThinLens { f_number: f64::NAN, ..good.camera }, ..good },
        Bos { camera: ThinLens { up: DVec3::Z, ..good.camera }, ..good },
        Bos { camera: ThinLens { width: 0, ..good.camera }, ..good },
        Bos { background_distance: -1.0, ..good },
        Bos { aperture_samples: 0, ..good },
        Bos { background: DotBackground { spacing: 0.0, ..good.background }, ..good },
    ] {
        let e = bad.render(&f, 0).unwrap_err();
        assert!(!e.to_string().is_empty());
    }
}

/// The same seed gives the same pair and ground truth, bit for bit, on 1
/// and 3 threads.
#[test]
fn deterministic_across_thread_counts() {
    let field = GaussianBump::new(DVec3::new(0.0, 0.0, 1.1), 1e-3, 0.002, 5.0);
    let b = bos(camera(8.0, 32, 24), 2);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| b.render(&field, 5).unwrap())
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert_ne!(one, b.render(&field, 6).unwrap());
}
