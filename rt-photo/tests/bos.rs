//! Background-oriented schlieren against docs/oracles.md §7 and the thin-lens
//! formulas.

use glam::DVec3;
use rt_photo::{Background, Bos, DotBackground, DotGrid, ImageBackground, ThinLens, TraceParams};
use rt_photo::{GridMedium, Medium};
use rt_volume::{Bounds, Constant, GaussianBump};

/// docs/oracles.md §7's camera: f = 0.1 m focused on the background at Z_B = 2.1 m
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

fn dots(cam: &ThinLens) -> DotBackground {
    DotBackground::for_camera(cam, 3.0, 4.0, 9)
}

fn bos(cam: ThinLens, k: u32) -> Bos {
    Bos {
        camera: cam,
        background_distance: 2.1,
        background: dots(&cam).into(),
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
        // Looking along +z with y up, the image's x (right) is −x; the
        // rays land shifted by M·Z_D·ε on the image, and the pattern
        // appears shifted the other way. The bump is a converging lens: it
        // magnifies the background, so the pattern moves outward.
        let want = m * 1.0 * eps / 5e-6;
        let outward = if i < w / 2 { -1.0 } else { 1.0 };
        assert!(want * outward >= 0.0 || want.abs() < 1e-12, "pixel {i}: {want}");
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
    let d = dots(&good.camera);
    let g = DotGrid::for_camera(&good.camera, 2.0, 5.0);
    for bad in [
        Bos { camera: ThinLens { focus_distance: 0.05, ..good.camera }, ..good.clone() },
        Bos { camera: ThinLens { f_number: f64::NAN, ..good.camera }, ..good.clone() },
        Bos { camera: ThinLens { up: DVec3::Z, ..good.camera }, ..good.clone() },
        Bos { camera: ThinLens { width: 0, ..good.camera }, ..good.clone() },
        Bos { background_distance: -1.0, ..good.clone() },
        Bos { aperture_samples: 0, ..good.clone() },
        Bos { background: DotBackground { spacing: 0.0, ..d }.into(), ..good.clone() },
        Bos { background: DotBackground { dot_diameter: f64::NAN, ..d }.into(), ..good.clone() },
        Bos { background: DotGrid { spacing: -1.0, ..g }.into(), ..good.clone() },
        Bos { background: DotGrid { dot_diameter: f64::INFINITY, ..g }.into(), ..good.clone() },
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

/// A flow-free field (n = 1 in a box across the view).
fn no_flow() -> Constant {
    Constant { n: 1.0, bounds: Bounds::new(DVec3::new(-0.1, -0.1, 1.0), DVec3::new(0.1, 0.1, 1.2)) }
}

/// A dot grid 6 pixels apart as imaged: the reference image repeats every
/// 6 pixels across and down (to the sampling noise of 100 rays a pixel),
/// and not at half that; the background itself is periodic with its
/// spacing, with a dot (value ≈ 1) on each lattice point.
#[test]
fn dot_grid_is_periodic_with_the_imaged_spacing() {
    let cam = camera(8.0, 48, 36);
    let grid = DotGrid::for_camera(&cam, 2.5, 6.0);
    assert!((grid.spacing - 6.0 * 5e-6 / 0.05).abs() < 1e-15);
    let s = grid.spacing;
    for (u, v) in [(0.0, 0.0), (0.31 * s, -0.77 * s), (-4.5 * s, 2.25 * s)] {
        assert!((grid.value(u + s, v) - grid.value(u, v)).abs() < 1e-12);
        assert!((grid.value(u, v - 3.0 * s) - grid.value(u, v)).abs() < 1e-12);
    }
    assert!((grid.value(2.0 * s, -s) - 1.0).abs() < 1e-3);
    assert!(grid.value(0.5 * s, 0.5 * s) < 0.01);

    let b = Bos { background: grid.into(), ..bos(cam, 10) };
    let out = b.render(&no_flow(), 3).unwrap();
    assert!(out.flow.iter().zip(&out.reference).all(|(a, b)| (a - b).abs() < 1e-9));
    let (w, h) = (48, 36);
    let at = |i: usize, j: usize| out.reference[j * w + i];
    let mut worst: f64 = 0.0;
    let mut half: f64 = 0.0;
    for j in 0..h {
        for i in 0..w {
            if i + 6 < w {
                worst = worst.max((at(i + 6, j) - at(i, j)).abs());
                half = half.max((at(i + 3, j) - at(i, j)).abs());
            }
            if j + 6 < h {
                worst = worst.max((at(i, j + 6) - at(i, j)).abs());
            }
        }
    }
    let (lo, hi) =
        out.reference.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &v| (l.min(v), h.max(v)));
    println!(
        "dot grid: range {lo:.3}..{hi:.3}, period-6 mismatch {worst:.4}, half-period {half:.3}"
    );
    assert!(lo < 0.05 && hi > 0.5, "{lo}..{hi}");
    assert!(worst < 0.02, "not periodic with 6 px: {worst}");
    assert!(half > 0.3, "{half}");
}

/// A deterministic pseudo-random image in [0, 1).
fn noise_image(w: usize, h: usize) -> Vec<f64> {
    (0..w * h)
        .map(|p| {
            let x = (p as u64 + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
            ((x >> 11) ^ (x >> 37)) as f64 / (1u64 << 53) as f64 % 1.0
        })
        .collect()
}

/// The camera focused on an image background whose pixels image onto
/// the sensor's one for one, looking through no flow: the flow image is
/// the reference, and each pixel is the image's bilinear interpolant
/// averaged over the pixel, which is the image filtered by
/// `[1 6 1]/8 ⊗ [1 6 1]/8` (edges repeated), to the sampling noise of 64
/// rays a pixel; a smooth image comes back as it was.
#[test]
fn image_background_is_reproduced_through_a_uniform_field() {
    let (w, h) = (32usize, 24usize);
    let cam = camera(8.0, w, h);
    let img = noise_image(w, h);
    let background = ImageBackground::for_camera(&cam, w, h, img.clone(), 1.0).unwrap();
    assert!((background.pixel_size() - 1e-4).abs() < 1e-18);
    let b = Bos { background: background.into(), ..bos(cam, 8) };
    let out = b.render(&no_flow(), 4).unwrap();
    assert!(out.flow.iter().zip(&out.reference).all(|(a, b)| (a - b).abs() < 1e-9));
    assert!(out.displacement.iter().all(|d| d[0].abs() < 1e-9 && d[1].abs() < 1e-9));
    let px = |i: isize, j: isize| {
        img[(j.clamp(0, h as isize - 1) as usize) * w + i.clamp(0, w as isize - 1) as usize]
    };
    let tap = [1.0 / 8.0, 6.0 / 8.0, 1.0 / 8.0];
    let (mut worst, mut raw): (f64, f64) = (0.0, 0.0);
    for j in 0..h as isize {
        for i in 0..w as isize {
            let mut want = 0.0;
            for (b, ty) in tap.iter().enumerate() {
                for (a, tx) in tap.iter().enumerate() {
                    want += tx * ty * px(i + a as isize - 1, j + b as isize - 1);
                }
            }
            let got = out.reference[j as usize * w + i as usize];
            worst = worst.max((got - want).abs());
            raw = raw.max((got - px(i, j)).abs());
        }
    }
    println!("image background: max |got − filtered| {worst:.4} (vs unfiltered {raw:.3})");
    assert!(worst < 0.015, "{worst}");
    assert!(raw > 0.1, "the filter is real: {raw}");

    // A smooth image (a slow sinusoid) comes back nearly as it was.
    let smooth: Vec<f64> = (0..w * h)
        .map(|p| {
            let (i, j) = ((p % w) as f64, (p / w) as f64);
            0.5 + 0.4
                * (core::f64::consts::TAU * i / 32.0).sin()
                * (core::f64::consts::TAU * j / 24.0).cos()
        })
        .collect();
    let background = ImageBackground::for_camera(&cam, w, h, smooth.clone(), 1.0).unwrap();
    let out = Bos { background: background.into(), ..bos(cam, 4) }.render(&no_flow(), 4).unwrap();
    let worst = out.reference.iter().zip(&smooth).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(worst < 0.02, "{worst}");
}

/// Values of an image background: samples at pixel centres, bilinear
/// between, the mean outside.
#[test]
fn image_background_values() {
    // 3 × 2 pixels of 0.5 m, centred: x from −0.75 to 0.75, y 0.5 to −0.5.
    let img = ImageBackground::new(3, 2, vec![0.0, 0.2, 0.4, 1.0, 0.6, 0.8], 0.5).unwrap();
    assert_eq!((img.width(), img.height(), img.samples().len()), (3, 2, 6));
    assert!((img.outside() - 0.5).abs() < 1e-15);
    let b = Background::from(img.clone());
    assert_eq!(b.value(-0.5, 0.25), 0.0); // pixel (0, 0)'s centre
    assert_eq!(b.value(0.5, -0.25), 0.8); // pixel (2, 1)'s centre
    assert!((b.value(-0.25, 0.25) - 0.1).abs() < 1e-15);
    assert!((b.value(0.0, 0.0) - 0.4).abs() < 1e-15); // (0.2 + 0.6)/2
    assert_eq!(b.value(-0.7, 0.45), 0.0); // the edge's half pixel repeats it
    assert_eq!(b.value(-0.8, 0.0), 0.5); // outside: the mean
    assert_eq!(b.value(0.0, 0.51), 0.5);
    assert_eq!(b.value(f64::NAN, 0.0), 0.5);
    assert_eq!(b.value(f64::INFINITY, 0.0), 0.5);
}

#[test]
fn bad_background_images_are_errors() {
    use rt_photo::BosError;
    let size = |e| matches!(e, Err(BosError::ImageSize { .. }));
    assert!(size(ImageBackground::new(0, 4, vec![], 1.0)));
    assert!(size(ImageBackground::new(2, 2, vec![0.5; 3], 1.0)));
    assert!(size(ImageBackground::new(usize::MAX, 2, vec![0.5; 2], 1.0)));
    assert!(matches!(
        ImageBackground::new(2, 1, vec![0.5, f64::NAN], 1.0),
        Err(BosError::ImageSample { index: 1, .. })
    ));
    assert!(matches!(
        ImageBackground::new(1, 2, vec![-0.1, 0.5], 1.0),
        Err(BosError::ImageSample { index: 0, value }) if value == -0.1
    ));
    assert!(matches!(
        ImageBackground::new(1, 1, vec![f64::INFINITY], 1.0),
        Err(BosError::ImageSample { .. })
    ));
    for p in [0.0, -1.0, f64::NAN, f64::INFINITY, 1e308] {
        let e = ImageBackground::new(10, 1, vec![0.5; 10], p).unwrap_err();
        assert!(matches!(e, BosError::Setup(_)), "{p}: {e}");
        assert!(!e.to_string().is_empty());
    }
    let e = ImageBackground::new(2, 2, vec![0.5; 3], 1.0).unwrap_err();
    assert!(e.to_string().contains("2×2") && e.to_string().contains('3'), "{e}");
}

/// rt's default for grids: octree skipping within a per-ray budget of a
/// tenth of a pixel of displacement ([`Bos::resolvable_deflection`])
/// gives the ground truth of plain tracing to 0.1 px, and the same images
/// at any thread count.
#[test]
fn grid_render_with_octree_matches_plain_tracing() {
    use rt_volume::{Grid, GridField, Interp};
    let (n, h, z_a) = (64, 1e-3, 1.1);
    let half = 0.5 * h * (n - 1) as f64;
    let origin = DVec3::new(-half, -half, z_a - half);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h
                    - DVec3::new(0.0, 0.0, z_a);
                data.push((1.0 + 1e-3 * (-p.length_squared() / (2.0 * 1e-4)).exp()) as f32);
            }
        }
    }
    let g = Grid::new([n; 3], origin, DVec3::splat(h), data).unwrap();
    let field = GridField::new(g, Interp::CatmullRom, 1.0).unwrap();
    // 50 µm pixels: the 48 × 40 image spans ±12 mm of the bump (σ = 1 cm,
    // δ = 1e-3: 1.5 px at the peak).
    let cam = ThinLens { pixel_pitch: 5e-5, ..camera(16.0, 48, 40) };
    let b = Bos { params: TraceParams::for_grid(&field), ..bos(cam, 2) };
    // 0.1 px of 50 µm at M = 0.05 over Z_D = 1 m: 1e-4 rad.
    assert!((b.resolvable_deflection(z_a) - 1e-4).abs() < 1e-15);
    let plain = b.render(&field, 3).unwrap();
    let medium = Medium::Grid(GridMedium::from_field(field.clone(), b.params).unwrap());
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| b.render_medium(&medium, 3).unwrap())
    };
    let fast = render(1);
    assert_eq!(fast, render(3));
    let worst = plain
        .displacement
        .iter()
        .zip(&fast.displacement)
        .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
        .fold(0.0f64, f64::max);
    assert!(worst <= 0.1, "octree vs plain: {worst} px");
    let peak = plain.displacement.iter().map(|d| d[0].hypot(d[1])).fold(0.0f64, f64::max);
    assert!(peak > 1.2, "the bump moves the background: {peak} px");
}
