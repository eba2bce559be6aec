//! Focusing schlieren: the conventional knife edge it reduces to
//! (docs/oracles.md §5), a brute-force forward simulation it must agree with, and
//! its depth of focus.

use glam::DVec3;
use rt_core::sampling::{rng_for, uniform_f64};
use rt_photo::{FocusingError, FocusingSchlieren, SourceGrid, ThinLens, TraceParams};
use rt_photo::{GridMedium, Medium};
use rt_volume::{Bounds, Constant, FnField, GaussianBump, IndexField, trace};

/// f = 0.1 m at f/2 (D = 5 cm) focused at Z_F = 1 m (M = 1/9), pixels of
/// 0.5 mm on the focus plane; looking along +z from the origin, up = +y
/// (so the image's right is −x).
fn camera(width: usize, height: usize) -> ThinLens {
    ThinLens {
        position: DVec3::ZERO,
        direction: DVec3::Z,
        up: DVec3::Y,
        focal_length: 0.1,
        f_number: 2.0,
        focus_distance: 1.0,
        pixel_pitch: 0.5e-3 / 9.0,
        width,
        height,
    }
}

/// The source grid 1 m behind the focus plane (Z_S = 2 m).
fn set_up(cam: ThinLens, grid: SourceGrid, offset: f64, k: u32) -> FocusingSchlieren {
    FocusingSchlieren {
        camera: cam,
        source_distance: 2.0,
        grid,
        cutoff_offset: offset,
        aperture_samples: k,
        params: TraceParams::accurate(),
    }
}

/// docs/oracles.md §5: the deflection of a ray through a Gaussian bump at impact
/// parameter `x` (signed, along x), toward the centre.
fn eps(delta: f64, sigma: f64, x: f64) -> f64 {
    -(core::f64::consts::TAU).sqrt()
        * delta
        * (x / sigma)
        * (-(x * x) / (2.0 * sigma * sigma)).exp()
}

/// (1) One band, 12.5 mm wide (a quarter of the aperture), half covered by
/// the cutoff (o = 6.25 mm): the conventional knife-edge system of focal
/// length `Z_S − Z_F` = 1 m and source image `h = 2o`. A bump in the focus
/// plane (δ = 1e-3, σ = 5 mm) gives `I/I₀ = 1 + ε·(Z_S − Z_F)/o` at every
/// pixel of a row through it, within the aperture sampling's noise. (The
/// row spans |x| ≤ 4 mm: a pixel at x sees the band through a strip of
/// the lens centred 2x off its axis, and further out the disc's chord
/// changes across the strip, so the light no longer varies as a knife
/// edge's — a real effect of a single-band system, not noise.)
#[test]
fn one_band_is_the_conventional_knife_edge() {
    let (delta, sigma) = (1e-3, 5e-3);
    let field = GaussianBump::new(DVec3::new(0.0, 0.0, 1.0), delta, sigma, 6.0);
    let cam = camera(17, 1);
    let band = 12.5e-3;
    // Duty ½ of a 25 mm pitch: one band 12.5 mm wide.
    let grid = SourceGrid { pitch: 2.0 * band, duty: 0.5, angle: 0.0, bands: Some(1) };
    let fs = set_up(cam, grid, 0.25, 48);
    let out = fs.render(&field, 3).unwrap();
    let rel = out.relative();
    let o = 0.25 * 2.0 * band;
    let mut peak: f64 = 0.0;
    for (i, got) in rel.iter().enumerate() {
        let x = cam.focus_point(i as f64 + 0.5, 0.5).x;
        // Across the bands is the image's right, −x: s moves by −ε_x·1 m.
        let want = 1.0 - eps(delta, sigma, x) * 1.0 / o;
        assert!((got - want).abs() < 0.02, "pixel {i} (x = {x}): {got} vs {want}");
        peak = peak.max((want - 1.0).abs());
        // Undisturbed, the transmitted strip is o = 6.25 mm wide on the
        // lens's 50 mm disc, near its middle: ~0.16 of its light.
        assert!(out.reference[i] > 0.14 && out.reference[i] < 0.17, "{}", out.reference[i]);
    }
    assert!(peak > 0.2, "the signal is there: {peak}");
}

/// A thin bump: `n = 1 + δ·exp(−ρ²/2σ²)·exp(−(z − z₀)²/2σ_z²)`, ρ the
/// distance from the z axis.
fn thin_bump(
    delta: f64,
    sigma: f64,
    sigma_z: f64,
    z0: f64,
) -> FnField<impl Fn(DVec3) -> (f64, DVec3)> {
    let r = 6.0 * sigma;
    FnField {
        f: move |p: DVec3| {
            let dz = p.z - z0;
            let g = (-(p.x * p.x + p.y * p.y) / (2.0 * sigma * sigma)
                - dz * dz / (2.0 * sigma_z * sigma_z))
                .exp();
            let n = 1.0 + delta * g;
            let grad = -delta
                * g
                * DVec3::new(
                    p.x / (sigma * sigma),
                    p.y / (sigma * sigma),
                    dz / (sigma_z * sigma_z),
                );
            (n, grad)
        },
        bounds: Bounds::new(
            DVec3::new(-r, -r, z0 - 6.0 * sigma_z),
            DVec3::new(r, r, z0 + 6.0 * sigma_z),
        ),
        ambient: 1.0,
    }
}

/// The thin bump's deflection across x at `(x, y)`, docs/oracles.md §5 for a
/// bump of thickness σ_z: `−√(2π)·δ·(σ_z/σ)·(x/σ)·exp(−ρ²/2σ²)`.
fn thin_eps(delta: f64, sigma: f64, sigma_z: f64, x: f64, y: f64) -> f64 {
    -(core::f64::consts::TAU).sqrt() * delta * sigma_z / sigma
        * (x / sigma)
        * (-(x * x + y * y) / (2.0 * sigma * sigma)).exp()
}

/// (3) A thin bump (σ = 4 mm across, 1 mm along the axis) moved along the
/// axis. Geometric optics predicts the signal: the rays of the focus point
/// X cross the plane at depth z in the disc centred `X·z/Z_F` of diameter
/// `D·|z − Z_F|/Z_F`, so a pixel's `I/I₀ − 1` is the mean over that disc of
/// `ε·(Z_S − z)/o`. The rendered signal (the largest |I/I₀ − 1| on a row
/// through the bump) follows that prediction at every distance, peaks
/// with the bump in the focus plane, and falls off on both sides.
#[test]
fn a_bump_off_the_focus_plane_blurs_away() {
    let (delta, sigma, sigma_z) = (2e-3, 4e-3, 1e-3);
    let cam = camera(41, 1);
    let grid = SourceGrid { pitch: 4e-3, duty: 0.5, angle: 0.0, bands: None };
    let fs = set_up(cam, grid, 0.25, 32);
    let (o, z_f, z_s, radius) = (0.25 * 4e-3, 1.0, 2.0, 0.5 * cam.aperture());
    let xs: Vec<f64> = (0..41).map(|i| cam.focus_point(f64::from(i) + 0.5, 0.5).x).collect();
    let signal = |dz: f64| {
        let field = thin_bump(delta, sigma, sigma_z, z_f + dz);
        let rel = fs.render(&field, 7).unwrap().relative();
        rel.iter().map(|v| (v - 1.0).abs()).fold(0.0f64, f64::max)
    };
    let predicted = |dz: f64| {
        let z = z_f + dz;
        let r = radius * (dz / z_f).abs();
        let m = 48;
        xs.iter()
            .map(|&x| {
                let (mut sum, mut count) = (0.0, 0);
                for a in 0..m {
                    for b in 0..m {
                        let u = (2.0 * (f64::from(a) + 0.5) / f64::from(m) - 1.0) * r;
                        let v = (2.0 * (f64::from(b) + 0.5) / f64::from(m) - 1.0) * r;
                        if u * u + v * v <= r * r {
                            sum += thin_eps(delta, sigma, sigma_z, x * z / z_f + u, v);
                            count += 1;
                        }
                    }
                }
                (sum / f64::from(count) * (z_s - z) / o).abs()
            })
            .fold(0.0f64, f64::max)
    };
    let in_focus = signal(0.0);
    // In focus: ε's extreme, √(2π)·δ·(σ_z/σ)·e^(−½) at ρ = σ, times the
    // lever Z_S − Z_F over o.
    let want = thin_eps(delta, sigma, sigma_z, -sigma, 0.0) * (z_s - z_f) / o;
    assert!((in_focus / want - 1.0).abs() < 0.03, "in focus: {in_focus} vs {want}");
    // Divided by the lever (Z_S − z)/(Z_S − Z_F) — a bump nearer the lens
    // moves its rays' source points further — the signal peaks in the
    // focus plane and falls off monotonically on both sides, to under half
    // of it 0.3 m away (the measured depth of focus: `rt-report focusing`).
    let mut last = [in_focus; 2];
    for dz in [0.02, 0.05, 0.1, 0.2, 0.3] {
        for (k, side) in [-1.0, 1.0].into_iter().enumerate() {
            let (got, want) = (signal(side * dz), predicted(side * dz));
            assert!(
                (got - want).abs() < 0.02 + 0.05 * want,
                "Δz = {}: signal {got} vs geometric {want}",
                side * dz
            );
            let lever = (z_s - z_f) / (z_s - z_f - side * dz);
            let norm = got * lever;
            assert!(norm < last[k] + 0.015, "Δz = {}: {norm} after {}", side * dz, last[k]);
            last[k] = norm;
        }
    }
    assert!(last.iter().all(|s| *s < 0.5 * in_focus), "{last:?} of {in_focus}");
}

/// (2) The backward method against brute force: source points drawn on
/// the source plane and lens points on the aperture, traced forward through
/// the field to the lens; each ray refracted by the thin lens to the film,
/// crossing the cutoff grid (the source grid's image, in image space) on
/// the way. A bump 3 cm off the focus plane (its out-of-focus blur is in
/// play), a grid of 5 mm bands; the relative image of a row agrees within
/// the forward simulation's noise.
#[test]
fn backward_equals_a_forward_simulation() {
    let (delta, sigma) = (1e-3, 5e-3);
    let z_b = 1.03;
    let field = GaussianBump::new(DVec3::new(0.0, 0.0, z_b), delta, sigma, 6.0);
    let (w, h) = (16, 1);
    let cam = camera(w, h);
    let grid = SourceGrid { pitch: 5e-3, duty: 0.5, angle: 0.0, bands: None };
    let offset = 0.25;
    let fs = set_up(cam, grid, offset, 32);
    let backward = fs.render(&field, 1).unwrap().relative();

    // Forward. Thin lens f at z = 0; object planes Z_F (focus) and Z_S
    // (source) image at v = fZ/(Z − f), magnification −v/Z.
    let (f, z_f, z_s) = (0.1, 1.0, 2.0);
    let (v_f, v_s) = (f * z_f / (z_f - f), f * z_s / (z_s - f));
    let radius = 0.5 * cam.aperture();
    let pixel = 0.5e-3; // on the focus plane
    // The film: pixel (i, j) spans x ∈ (−(i+1−w/2), −(i−w/2))·pixel on the
    // focus plane (right = −x), y ∈ ((h/2 − j − 1), (h/2 − j))·pixel.
    let bright = |s: f64| {
        let x = s / 5e-3;
        (x - x.round()).abs() < 0.25
    };
    // The cutoff grid in image space at z = −v_s: the source grid's image
    // (inverted, scaled by v_s/Z_S), negative, shifted by the offset
    // across the bands (here along −x in the source plane ⇒ +x·m there).
    let m_s = v_s / z_s;
    let cutoff = |c: DVec3| {
        // Back to source-plane coordinates across the bands (s = −x).
        let sx = -c.x / m_s;
        let s = -sx;
        if bright(s - offset * 5e-3) { 0.0 } else { 1.0 }
    };
    let run = |with_flow: bool, n: u32| -> Vec<f64> {
        let mut film = vec![0.0; w * h];
        let mut rng = rng_for(99, 0);
        // Source points that reach the image through the aperture, with a
        // margin: S = L + (P − L)·Z_S/Z_F for P on the film's footprint.
        // (The flow moves a ray's focus-plane point by ≤ 0.05 mm here.)
        let (half_w, half_h) = (0.5 * w as f64 * pixel + 2e-4, 0.5 * h as f64 * pixel + 2e-4);
        for _ in 0..n {
            // A lens point, uniform on the disc (rejection).
            let l = loop {
                let p = DVec3::new(
                    (2.0 * uniform_f64(&mut rng) - 1.0) * radius,
                    (2.0 * uniform_f64(&mut rng) - 1.0) * radius,
                    0.0,
                );
                if p.length() <= radius {
                    break p;
                }
            };
            let p = DVec3::new(
                (2.0 * uniform_f64(&mut rng) - 1.0) * half_w,
                (2.0 * uniform_f64(&mut rng) - 1.0) * half_h,
                z_f,
            );
            let s = l + (p - l) * (z_s / z_f);
            // The band coordinate across is −x.
            if !bright(-s.x) {
                continue;
            }
            let d = (l - s).normalize();
            let (pos, dir) = if with_flow {
                let r = trace(&field, s, d, &TraceParams::accurate()).unwrap();
                (r.position, r.direction)
            } else {
                (s, d)
            };
            // Where the final line meets the lens.
            let lp = pos + dir * (-pos.z / dir.z);
            if lp.truncate().length() > radius {
                continue;
            }
            // The object-side line's point on the focus plane, and its image.
            let q = pos + dir * ((z_f - pos.z) / dir.z);
            let q_img = DVec3::new(-q.x * v_f / z_f, -q.y * v_f / z_f, -v_f);
            // The image-side ray from the lens point to the image point
            // crosses the cutoff plane z = −v_s.
            let c = lp + (q_img - lp) * (v_s / v_f);
            let t = cutoff(c);
            if t == 0.0 {
                continue;
            }
            // The film pixel (from the image point; upright storage).
            let (px, py) = (-q.x / pixel + 0.5 * w as f64, 0.5 * h as f64 - q.y / pixel);
            if px >= 0.0 && py >= 0.0 && px < w as f64 && py < h as f64 {
                film[py as usize * w + px as usize] += t;
            }
        }
        film
    };
    let n = 400_000;
    let (flow, reference) = (run(true, n), run(false, n));
    for i in 0..w {
        let fwd = flow[i] / reference[i];
        // Poisson noise of the two counts.
        let noise = fwd * (1.0 / flow[i] + 1.0 / reference[i]).sqrt();
        assert!(reference[i] > 2000.0, "{}", reference[i]);
        assert!(
            (backward[i] - fwd).abs() < 4.0 * noise + 0.01,
            "pixel {i}: backward {} vs forward {fwd} ± {noise}",
            backward[i]
        );
    }
    let contrast = backward.iter().map(|v| (v - 1.0).abs()).fold(0.0f64, f64::max);
    assert!(contrast > 0.1, "the bump shows: {contrast}");
}

/// An undisturbed field changes nothing; rendering is deterministic.
#[test]
fn uniform_field_changes_nothing_and_renders_repeat() {
    let field = Constant {
        n: 1.0,
        bounds: Bounds::new(DVec3::new(-0.1, -0.1, 0.9), DVec3::new(0.1, 0.1, 1.1)),
    };
    let grid = SourceGrid { pitch: 3e-3, duty: 0.5, angle: 0.3, bands: None };
    let fs = set_up(camera(12, 8), grid, 0.2, 4);
    let out = fs.render(&field, 5).unwrap();
    // (The same rays, up to rounding in where they meet the source.)
    assert!(out.flow.iter().zip(&out.reference).all(|(a, b)| (a - b).abs() < 1e-12));
    assert!(out.relative().iter().all(|v| (v - 1.0).abs() < 1e-11));
    // o/p = 0.2 of the light passes, undisturbed (17 periods across the
    // view: a ripple well under 1 %).
    assert!(out.reference.iter().all(|v| (v - 0.2).abs() < 0.005), "{:?}", out.reference);
    assert_eq!(fs.render(&field, 5).unwrap(), out);
    assert_ne!(fs.render(&field, 6).unwrap().reference, out.reference);
}

/// Without a flow the image is flat where the aperture sees many bands,
/// wherever they fall on the pixels. A pixel's light is the part of its
/// aperture's disc on the source plane (5 cm across here) that the bands
/// and the cutoff leave lit; over `N` periods that part ripples with the
/// disc's position by up to about `2·sinc(o/p)·2J₁(πN)/(πN)` of the mean
/// (6 % at N = 4, 0.45 % at N = 24): physics, not grain, so a coarse grid
/// must show it and a default grid puts tens of periods across the view.
/// (Weighting each aperture strip by its mean chord, as before, blurred
/// the disc's rim and misplaced the ripple.)
#[test]
fn the_undisturbed_image_is_flat_over_many_bands() {
    let field = Constant {
        n: 1.0,
        bounds: Bounds::new(DVec3::new(-0.1, -0.1, 0.9), DVec3::new(0.1, 0.1, 1.1)),
    };
    let ripple = |pitch: f64, duty: f64, angle: f64, offset: f64, k: u32| {
        let grid = SourceGrid { pitch, duty, angle, bands: None };
        let out = set_up(camera(80, 2), grid, offset, k).render(&field, 2).unwrap();
        let dev: Vec<f64> = out.reference.iter().map(|v| v / offset - 1.0).collect();
        let rms = (dev.iter().map(|d| d * d).sum::<f64>() / dev.len() as f64).sqrt();
        (rms, dev.iter().fold(0.0f64, |m, d| m.max(d.abs())))
    };
    // Two periods across the view: a pixel's disc holds a varying share.
    let (rms, _) = ripple(25e-3, 0.5, 0.0, 0.25, 6);
    assert!(rms > 0.05, "two periods across the aperture: rms {rms}");
    for (pitch, duty, angle, offset, k) in [
        (2.1e-3, 0.5, 0.0, 0.25, 1),
        (2.1e-3, 0.5, 0.0, 0.25, 6),
        (1.3e-3, 0.3, 0.7, 0.1, 3),
        (1.0e-3, 0.5, core::f64::consts::FRAC_PI_2, 0.25, 6),
        (0.53e-3, 0.6, 0.2, 0.3, 2),
    ] {
        let (rms, max) = ripple(pitch, duty, angle, offset, k);
        assert!(
            rms < 5e-3 && max < 8e-3,
            "pitch {pitch} duty {duty} k {k}: rms {rms:e}, max {max:e}"
        );
    }
}

#[test]
fn bad_set_ups_are_errors() {
    let f = Constant { n: 1.0, bounds: Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0)) };
    let grid = SourceGrid { pitch: 3e-3, duty: 0.5, angle: 0.0, bands: None };
    let good = set_up(camera(4, 4), grid, 0.25, 1);
    assert!(good.render(&f, 0).is_ok());
    let setup = |fs: FocusingSchlieren| fs.render(&f, 0).unwrap_err();
    for bad in [
        FocusingSchlieren { source_distance: 0.5, ..good },
        FocusingSchlieren { source_distance: f64::NAN, ..good },
        FocusingSchlieren { grid: SourceGrid { pitch: 0.0, ..grid }, ..good },
        FocusingSchlieren { grid: SourceGrid { duty: 1.0, ..grid }, ..good },
        FocusingSchlieren { grid: SourceGrid { angle: f64::INFINITY, ..grid }, ..good },
        FocusingSchlieren { grid: SourceGrid { bands: Some(0), ..grid }, ..good },
        FocusingSchlieren { cutoff_offset: -0.1, ..good },
        FocusingSchlieren { cutoff_offset: 1.0, ..good },
        FocusingSchlieren { aperture_samples: 65, ..good },
    ] {
        let e = setup(bad);
        assert!(matches!(e, FocusingError::Setup(_)), "{e}");
        assert!(e.to_string().starts_with("focusing schlieren set-up: "), "{e}");
    }
    let cam = FocusingSchlieren { camera: ThinLens { f_number: -2.0, ..good.camera }, ..good };
    assert!(matches!(setup(cam), FocusingError::Camera(_)));
    // A field whose index is not finite: a trace error, not a panic.
    let nan = FnField {
        f: |_: DVec3| (f64::NAN, DVec3::ZERO),
        bounds: Bounds::new(DVec3::splat(-1.0), DVec3::splat(2.0)),
        ambient: 1.0,
    };
    assert!(nan.bounds().contains(DVec3::new(0.0, 0.0, 1.0)));
    assert!(matches!(good.render(&nan, 0), Err(FocusingError::Trace(_))));
}

/// rt's default for grids, octree skipping within the resolvable
/// deflection per ray, renders what plain tracing renders (the same
/// rays: a ray's source point moves by at most 1/1000 of the cutoff's
/// shift, so few change band) and repeats bit for bit at any thread count.
#[test]
fn grid_render_with_octree_matches_plain_tracing() {
    use rt_volume::{Grid, GridField, Interp};
    let (n, h) = (48, 0.5e-3);
    let origin = DVec3::new(-0.5 * h * (n - 1) as f64, -0.5 * h * (n - 1) as f64, 0.988);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h - DVec3::Z;
                data.push((1.0 + 1e-3 * (-p.length_squared() / (2.0 * 4e-3 * 4e-3)).exp()) as f32);
            }
        }
    }
    let g = Grid::new([n; 3], origin, DVec3::splat(h), data).unwrap();
    let field = GridField::new(g, Interp::Trilinear, 1.0).unwrap();
    let grid = SourceGrid { pitch: 4e-3, duty: 0.5, angle: 0.5, bands: None };
    let fs = FocusingSchlieren {
        params: TraceParams::for_grid(&field),
        ..set_up(camera(40, 30), grid, 0.25, 8)
    };
    let plain = fs.render(&field, 4).unwrap().relative();
    let medium = Medium::Grid(GridMedium::from_field(field.clone(), fs.params).unwrap());
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| fs.render_medium(&medium, 4).unwrap())
    };
    let skipping = render(1);
    assert_eq!(skipping, render(3));
    let skipping = skipping.relative();
    let diffs: Vec<f64> = plain.iter().zip(&skipping).map(|(a, b)| (a - b).abs()).collect();
    let worst = diffs.iter().fold(0.0f64, |m, d| m.max(*d));
    let mean = diffs.iter().sum::<f64>() / diffs.len() as f64;
    assert!(worst < 0.02 && mean < 1e-3, "octree vs plain: worst {worst}, mean {mean}");
    let signal = plain.iter().map(|v| (v - 1.0).abs()).fold(0.0f64, f64::max);
    assert!(signal > 0.3, "the bump shows: {signal}");
}
