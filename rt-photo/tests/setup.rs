//! The instruments set up from the data (`SchlierenSetup`, `BosSetup`,
//! `FocusingSetup` over a `Medium`): what they choose, that one `render`
//! over a medium is the per-field render it replaces, and that bad
//! options are refused by name.

use rt_photo::{
    Axis, BosOptions, BosSetup, Cutoff, CutoffKind, Film, Filter, FilterImage, FocusingOptions,
    FocusingSetup, Medium, Mode, SchlierenBench, SchlierenOptions, SchlierenSetup, SetupError,
    Survey,
    glam::DVec3,
    rt_volume::{GLADSTONE_DALE_AIR, Grid, Interp, Samples},
};

/// A Gaussian density bump `1.2 + amp·exp(−r²/2σ²)` on an `n³` grid of
/// spacing `h` centred at the origin.
fn bump(n: usize, h: f64, sigma: f64, amp: f64) -> Grid {
    let c = 0.5 * (n as f64 - 1.0) * h;
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = DVec3::new(i as f64, j as f64, k as f64) * h - c;
                data.push((1.2 + amp * (-p.length_squared() / (2.0 * sigma * sigma)).exp()) as f32);
            }
        }
    }
    Grid::new([n; 3], DVec3::splat(-0.5 * n as f64 * h), DVec3::splat(h), data).unwrap()
}

fn medium(interp: Interp) -> Medium {
    Medium::from_grid(bump(40, 1.5e-3, 8e-3, 0.3), Samples::AIR, false, interp).unwrap()
}

/// A weak flow (peak deflection ~1e-4 rad, below the skipping tolerance
/// of a bench without cutoff) is measured, not skipped: the survey's
/// largest deflection is the bump's analytic `K·A·√(2π)·e^(−1/2)` (see
/// docs/oracles.md) within the coarse survey's sampling. Skipped, it would
/// read 0 and the automatic exposure would saturate the knife edge.
#[test]
fn the_survey_measures_weak_flows() {
    let (sigma, amp) = (8e-3, 0.3);
    let m =
        Medium::from_grid(bump(48, 1.5e-3, sigma, amp), Samples::AIR, false, Interp::CatmullRom)
            .unwrap();
    let survey = Survey::through(&m, Axis::Z, Survey::WIDTH).unwrap();
    let exact = GLADSTONE_DALE_AIR * amp * core::f64::consts::TAU.sqrt() * (-0.5f64).exp();
    let got = survey.magnitude(1.0);
    assert!((got / exact - 1.0).abs() < 0.1, "survey max |ε| {got:e}, analytic {exact:e}");
}

/// The automatic knife edge maps the 99th percentile of the deflection
/// across it to 0.45 of its range: the image stays within 0.5 ± 0.45 but
/// for about 1 % of the pixels, and uses that range (a knife edge chosen
/// from |ε| instead of ε⊥, or off by a factor, fails one of the two).
#[test]
fn the_automatic_knife_edge_spends_its_range_on_the_flow() {
    let m = medium(Interp::CatmullRom);
    let o = SchlierenOptions { size: 64, photons: 4, ..SchlierenOptions::default() };
    let setup = SchlierenSetup::choose(&m, &o).unwrap();
    assert!(setup.to_string().starts_with("knife edge at 0°, f = 1.00 m, h = "), "{setup}");
    let film = setup.render(&m, 1, &mut |_, _| {}).unwrap();
    let image: Vec<f64> = film.normalized_f64().iter().map(|p| p[0]).collect();
    let outside = image.iter().filter(|v| (**v - 0.5).abs() > 0.45 + 1e-9).count();
    let deviation = image.iter().map(|v| (v - 0.5).abs()).fold(0.0, f64::max);
    assert!(outside as f64 <= 0.02 * image.len() as f64, "{outside} of {} saturated", image.len());
    assert!(deviation > 0.3, "largest |I − 0.5| only {deviation}");
}

/// A shadowgraph's film is placed where the strongest contrast is about
/// 0.5; a colour filter's rim clears the deflections; interferometry
/// takes the medium's ambient index as its reference.
#[test]
fn each_cutoff_chooses_from_the_data() {
    let m = medium(Interp::Trilinear);
    let choose = |cutoff| {
        let o = SchlierenOptions { cutoff, size: 48, photons: 4, ..SchlierenOptions::default() };
        SchlierenSetup::choose(&m, &o).unwrap()
    };
    let shadow = choose(CutoffKind::None);
    assert!(shadow.bench.film_distance > 0.0 && shadow.title() == "Shadowgraph");
    let colour = choose(CutoffKind::Color);
    let Mode::Schlieren(Cutoff::Color(filter)) = &colour.bench.mode else { panic!("colour") };
    let largest = Survey::through(&m, Axis::Z, 48).unwrap().magnitude(1.0);
    assert!(filter.half_range > 0.5 * largest && filter.half_range <= largest);
    let Mode::Interferometry { n_ref, .. } = choose(CutoffKind::Interferometry).bench.mode else {
        panic!("interferometry")
    };
    assert_eq!(n_ref, m.ambient());
}

/// A round flow seen through the automatic colour filter is cut the same
/// in every direction: the rim clears all but the strongest deflections,
/// and those go dark all round the ring, on the diagonals as on the axes.
/// (A square filter, blocking only past its edges, would darken four
/// spots on the axes, which a round flow cannot make.)
#[test]
fn a_round_flow_is_cut_alike_in_every_direction() {
    let m = medium(Interp::CatmullRom);
    let o = SchlierenOptions {
        cutoff: CutoffKind::Color,
        size: 96,
        photons: 4,
        ..SchlierenOptions::default()
    };
    let setup = SchlierenSetup::choose(&m, &o).unwrap();
    let film = setup.render(&m, 1, &mut |_, _| {}).unwrap();
    let (w, pixels) = (film.width(), film.normalized_f64());
    let (mut axes, mut diagonals) = (0, 0);
    for (i, p) in pixels.iter().enumerate() {
        if p[0] + p[1] + p[2] < 0.5 {
            let (x, y) =
                ((i % w) as f64 + 0.5 - 0.5 * w as f64, (i / w) as f64 + 0.5 - 0.5 * w as f64);
            let a = y.atan2(x).rem_euclid(core::f64::consts::FRAC_PI_2).to_degrees();
            if (a - 45.0).abs() < 22.5 { diagonals += 1 } else { axes += 1 }
        }
    }
    assert!(axes + diagonals > 8, "no pixel cut: {axes} + {diagonals}");
    assert!(
        diagonals * 2 > axes && axes * 2 > diagonals,
        "{axes} near the axes, {diagonals} near the diagonals"
    );
}

/// A render over a medium traces with the medium's settings, not the
/// instrument's: a bench carrying other settings gives the same image,
/// and the medium's settings, replaced, change it.
#[test]
fn a_medium_carries_its_trace_settings() {
    let mut m = medium(Interp::CatmullRom);
    let o = SchlierenOptions { size: 40, photons: 4, ..SchlierenOptions::default() };
    let setup = SchlierenSetup::choose(&m, &o).unwrap();
    let bench = SchlierenBench { strata: 2, ..setup.bench.clone() };
    let other = SchlierenBench { params: rt_photo::TraceParams::accurate(), ..bench.clone() };
    let film = || Film::new(40, 40, Filter::Tent).unwrap();
    let (mut a, mut b, mut c) = (film(), film(), film());
    bench.render_medium(&m, &mut a, 0, 7).unwrap();
    other.render_medium(&m, &mut b, 0, 7).unwrap();
    assert_eq!(a.normalized_f64(), b.normalized_f64());
    let coarse = m.params();
    m.set_params(rt_photo::TraceParams {
        step: 4.0 * coarse.step,
        max_step: 4.0 * coarse.max_step,
        ..coarse
    });
    bench.render_medium(&m, &mut c, 0, 7).unwrap();
    assert_ne!(a.normalized_f64(), c.normalized_f64());
}

/// BOS and focusing set-ups render, and say what they chose.
#[test]
fn bos_and_focusing_set_up_from_the_flow() {
    let m = medium(Interp::CatmullRom);
    let bos = BosSetup::choose(&m, &BosOptions { size: 24, ..BosOptions::default() }).unwrap();
    assert!(bos.to_string().starts_with("f/16, f = "), "{bos}");
    let images = bos.render(&m, 1).unwrap();
    assert_eq!((images.width, images.height), (24, 24));
    assert!(images.displacement.iter().any(|d| d[0].hypot(d[1]) > 1e-3));
    let o = FocusingOptions { size: 16, samples_per_axis: 2, ..FocusingOptions::default() };
    let f = FocusingSetup::choose(&m, &o).unwrap();
    assert!(f.to_string().contains("cutoff offset 0.25 pitch"), "{f}");
    assert_eq!(f.render(&m, 1).unwrap().relative().len(), 16 * 16);
}

/// Bad options are refused by name, before any work.
#[test]
fn bad_options_are_refused_by_name() {
    let m = medium(Interp::Trilinear);
    let bad = |o: SchlierenOptions| SchlierenSetup::choose(&m, &o).unwrap_err().to_string();
    let d = SchlierenOptions::default;
    assert_eq!(bad(SchlierenOptions { angle: f64::NAN, ..d() }), "angle must be finite (got NaN)");
    assert_eq!(bad(SchlierenOptions { h: Some(-1.0), ..d() }), "h must be finite and > 0 (got -1)");
    assert_eq!(bad(SchlierenOptions { size: 0, ..d() }), "size must be 1 to 16384 (got 0)");
    let many = SchlierenOptions { size: 16384, photons: 65536, ..d() };
    assert!(matches!(SchlierenSetup::choose(&m, &many), Err(SetupError::TooManyPhotons { .. })));
    let close = BosOptions {
        rig: rt_photo::BosRigOptions {
            camera_distance: Some(0.01),
            focal_length: Some(0.05),
            ..Default::default()
        },
        ..BosOptions::default()
    };
    assert!(matches!(BosSetup::choose(&m, &close), Err(SetupError::TooClose { .. })));
    let pitch = FocusingOptions {
        rig: rt_photo::FocusingRigOptions { grid_pitch: Some(f64::INFINITY), ..Default::default() },
        ..FocusingOptions::default()
    };
    let e = FocusingSetup::choose(&m, &pitch).unwrap_err().to_string();
    assert_eq!(e, "pitch must be finite and > 0 (got inf)");
}

/// `render_until` stops when told, on every instrument, with
/// `SetupError::Stopped` (not a trace error), after tracing part of the
/// image only; and a `stop` that never says yes changes nothing: the same
/// film, bit for bit, as `render`.
#[test]
fn renders_stop_when_told_and_only_then() {
    use core::sync::atomic::{AtomicU64, Ordering};
    let m = medium(Interp::CatmullRom);
    // Says yes from its `after`-th question on, counting the questions.
    let stop_after = |after: u64| {
        let asked = AtomicU64::new(0);
        move || asked.fetch_add(1, Ordering::Relaxed) >= after
    };
    let o = SchlierenOptions { size: 48, photons: 4, ..SchlierenOptions::default() };
    let setup = SchlierenSetup::choose(&m, &o).unwrap();
    let mut passes = 0;
    let got = setup.render_until(&m, 1, &mut |_, _| passes += 1, &stop_after(1000));
    assert!(matches!(got, Err(SetupError::Stopped)), "{got:?}");
    assert_eq!(passes, 0, "stopped inside the first pass");
    let never = setup.render_until(&m, 1, &mut |_, _| {}, &|| false).unwrap();
    assert_eq!(never, setup.render(&m, 1, &mut |_, _| {}).unwrap());

    let bos = BosSetup::choose(&m, &BosOptions { size: 48, ..BosOptions::default() }).unwrap();
    let got = bos.render_until(&m, 1, &stop_after(100));
    assert!(matches!(got, Err(SetupError::Stopped)), "BOS: {:?}", got.map(|_| ()));
    let foc =
        FocusingSetup::choose(&m, &FocusingOptions { size: 48, ..FocusingOptions::default() })
            .unwrap();
    let got = foc.render_until(&m, 1, &stop_after(100));
    assert!(matches!(got, Err(SetupError::Stopped)), "focusing: {:?}", got.map(|_| ()));
    // Asked once a ray: width × height × k² (progress counts on it).
    let asked = AtomicU64::new(0);
    let count = || asked.fetch_add(1, Ordering::Relaxed) == u64::MAX;
    let c = foc.system.camera;
    foc.render_until(&m, 1, &count).unwrap();
    let k = u64::from(foc.system.aperture_samples);
    assert_eq!(asked.swap(0, Ordering::Relaxed), (c.width * c.height) as u64 * k * k);
    let c = bos.bos.camera;
    bos.render_until(&m, 1, &count).unwrap();
    let k = u64::from(bos.bos.aperture_samples);
    assert_eq!(asked.into_inner(), (c.width * c.height) as u64 * k * k);
}

/// Repainting without tracing again: the knife edge the set-up chose,
/// painted as a filter ([`FilterImage::of_cutoff`]) and applied to the
/// deflections a picking pass recorded (a clear filter in the focal
/// plane; [`Film::through_filter`]), gives the knife-edge image traced
/// photon by photon, to the filter's pixel of deflection and the spread
/// of deflections inside a pixel. A filter read with its axes swapped or
/// flipped, applied to the light instead of the deflection, or a picking
/// pass that skips what the filter resolves (no cutoff: the bump's
/// deflections read 0) is off by tenths.
#[test]
fn a_painted_knife_over_recorded_deflections_is_the_traced_knife() {
    let m = medium(Interp::CatmullRom);
    for angle in [0.0, 90.0, 225.0] {
        let o = SchlierenOptions { size: 64, photons: 16, angle, ..SchlierenOptions::default() };
        let knife = SchlierenSetup::choose(&m, &o).unwrap();
        let traced = knife.render(&m, 1, &mut |_, _| {}).unwrap().normalized();
        let Mode::Schlieren(cutoff) = &knife.bench.mode else { unreachable!() };
        let half = 4.0 * knife.focal_range().unwrap();
        let colour = SchlierenOptions { cutoff: CutoffKind::Color, half_range: Some(half), ..o };
        let picking = SchlierenSetup::choose(&m, &colour).unwrap();
        let picking = picking.with_filter(FilterImage::clear(512, half)).unwrap();
        let film = picking.render(&m, 1, &mut |_, _| {}).unwrap();
        let painted = film.through_filter(&FilterImage::of_cutoff(cutoff, 512, half));
        let diff: Vec<f64> =
            traced.iter().zip(&painted).map(|(a, b)| f64::from((a[0] - b[0]).abs())).collect();
        let rms = (diff.iter().map(|d| d * d).sum::<f64>() / diff.len() as f64).sqrt();
        let max = diff.iter().copied().fold(0.0, f64::max);
        let contrast = traced.iter().map(|p| (p[0] - 0.5).abs()).fold(0.0, f32::max);
        assert!(contrast > 0.3, "angle {angle}: the knife shows little ({contrast})");
        // The filter's pixel is 1/64 of the knife's ramp: steps of 1/128
        // (measured: rms 5.3e-3, max 7.8e-3 to 1.1e-2).
        assert!(rms < 8e-3 && max < 2e-2, "angle {angle}: rms {rms:.4}, max {max:.4}");
    }
}

/// A filter painted in a PNG is read with `εu` along its columns and `εv`
/// up its rows, and a set-up takes it in its focal plane.
#[cfg(feature = "png")]
#[test]
fn a_filter_png_is_read_the_way_the_focal_plane_is_seen() {
    let dir = std::env::temp_dir().join(format!("rt-photo-filter-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("filter.png");
    // 4 × 4: the top-right pixel white (εu > 0, εv > 0), the rest black.
    let mut rgb = vec![0u8; 4 * 4 * 3];
    rgb[3 * 3..3 * 4].copy_from_slice(&[255, 255, 255]);
    let file = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    let mut enc = png::Encoder::new(file, 4, 4);
    enc.set_color(png::ColorType::Rgb);
    enc.write_header().unwrap().write_image_data(&rgb).unwrap();
    let filter = FilterImage::read_png(&path, 1e-3).unwrap();
    assert_eq!(filter.at(0.9e-3, 0.9e-3), [1.0; 3]);
    for (eu, ev) in [(-0.9e-3, 0.9e-3), (0.9e-3, -0.9e-3), (-0.9e-3, -0.9e-3)] {
        assert_eq!(filter.at(eu, ev), [0.0; 3], "({eu}, {ev})");
    }
    assert!(FilterImage::read_png(&path, f64::NAN).is_err());
    assert!(FilterImage::read_png(&dir.join("absent.png"), 1e-3).is_err());
    let m = medium(Interp::Trilinear);
    let o = SchlierenOptions { size: 32, photons: 4, ..SchlierenOptions::default() };
    let setup = SchlierenSetup::choose(&m, &o).unwrap().with_filter(filter).unwrap();
    assert_eq!(setup.title(), "Colour schlieren");
    let empty = FilterImage { rgb: vec![], ..FilterImage::opaque(4, 1e-3) };
    assert!(SchlierenSetup::choose(&m, &o).unwrap().with_filter(empty).is_err());
    std::fs::remove_dir_all(&dir).ok();
}
