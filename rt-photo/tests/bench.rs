//! The optical bench against exact answers (docs/oracles.md §5), conservation and
//! determinism.

mod support;

use glam::DVec3;
use rt_core::frame::linear_to_srgb;
use rt_photo::{
    BenchError, Cutoff, CutoffError, CutoffParam, Film, FilmError, Filter, Mode, Photon,
    Reconstruction, SchlierenBench, Weighting,
};
use rt_photo::{GridMedium, Medium};
use rt_volume::{Bounds, Constant, GaussianBump, TraceParams};
use support::{bench, knife};

const SQRT_2PI: f64 = 2.506_628_274_631_000_5;

/// Pixel centre `(x, y)` in scene units.
fn centre(film: &Film, i: usize, j: usize) -> (f64, f64) {
    let x = (i as f64 + 0.5) / film.width() as f64 * 6.0 - 3.0;
    let y = 3.0 - (j as f64 + 0.5) / film.height() as f64 * 6.0;
    (x, y)
}

fn rmse(film: &Film, want: impl Fn(f64, f64) -> f64) -> f64 {
    let img = film.normalized();
    let mut s = 0.0;
    for j in 0..film.height() {
        for i in 0..film.width() {
            let (x, y) = centre(film, i, j);
            let d = f64::from(img[i + film.width() * j][0]) - want(x, y);
            s += d * d;
        }
    }
    (s / img.len() as f64).sqrt()
}

/// An undisturbed field gives exactly the background: 1 uncut, 0.5 with a
/// half-cut knife edge, in every pixel; nothing is lost.
#[test]
fn undisturbed_field_gives_exact_background() {
    let f = Constant { n: 1.0, bounds: Bounds::new(DVec3::splat(-5.0), DVec3::splat(5.0)) };
    for (mode, want) in [(Mode::Schlieren(Cutoff::None), 1.0f32), (knife(1000.0), 0.5)] {
        let mut film = Film::new(32, 24, Filter::Box).unwrap();
        bench(mode, 3).render(&f, &mut film, 0, 7).unwrap();
        assert!(film.normalized().iter().all(|p| p[0] == want), "background not exactly {want}");
        assert_eq!(film.lost, 0);
    }
}

/// With no cutoff and L = 0 the total film weight equals the photons
/// emitted; with L > 0 every photon is either on the film or counted lost.
#[test]
fn photon_weight_is_conserved() {
    // A low-index bump: a diverging lens that pushes edge photons outward.
    let f = GaussianBump::new(DVec3::ZERO, -5e-3, 1.0, 5.0);
    for (l, filter) in [(0.0, Filter::Box), (0.0, Filter::Tent), (200.0, Filter::Tent)] {
        let mut film = Film::new(40, 40, filter).unwrap();
        let mut b = bench(Mode::Schlieren(Cutoff::None), 2);
        b.film_distance = l;
        b.render(&f, &mut film, 0, 1).unwrap();
        let on_film = film.total()[0];
        assert!(
            (on_film + film.lost as f64 - film.emitted as f64).abs() < 1e-6 * film.emitted as f64,
            "L = {l}: {on_film} on film + {} lost vs {} emitted",
            film.lost,
            film.emitted
        );
        if l > 0.0 {
            assert!(film.lost > 100, "a strong lens at L = {l} must push photons off the film");
        }
    }
}

/// docs/oracles.md §5: knife-edge schlieren of a weak Gaussian bump against the
/// analytic intensity `clamp(0.5 + (f/h) ε_x)`, with 128²·64 ≈ 1M photons:
/// RMSE ≤ 1 % of the (half-cut) background. (Photons land at their exit
/// points, displaced inside the bump.)
#[test]
fn knife_edge_matches_the_analytic_gaussian() {
    let (delta, sigma, fh) = (1e-4, 1.0, 1500.0);
    let f = GaussianBump::new(DVec3::ZERO, delta, sigma, 5.0);
    // The tent filter smooths the count noise of photons displaced across
    // pixel borders inside the bump (box filter: rmse 0.0075, tent: 0.0037).
    let mut film = Film::new(128, 128, Filter::Tent).unwrap();
    bench(knife(fh), 8).render(&f, &mut film, 0, 3).unwrap();
    assert!(film.emitted >= 1_000_000);
    let want = |x: f64, y: f64| {
        let g = (-(x * x + y * y) / (2.0 * sigma * sigma)).exp();
        let eps_x = -SQRT_2PI * delta * (x / sigma) * g;
        (0.5 + fh * eps_x).clamp(0.0, 1.0)
    };
    let e = rmse(&film, want);
    assert!(e <= 0.01 * 0.5, "rmse {e}");
    // The signal is really there: a wrong sign or scale would fail.
    assert!(rmse(&film, |_, _| 0.5) > 0.05);
    assert!(rmse(&film, |x, y| 1.0 - want(x, y)) > 0.05);
}

/// Infinite-fringe interferometry: `I = (1 + cos φ)/2`,
/// `φ = (2π/λ)·√(2π) σ δ g(r)`; not `sin φ`.
#[test]
fn interferogram_phase_matches_the_analytic_gaussian() {
    let (delta, sigma) = (1e-4, 1.0);
    let lambda = 2.0 * SQRT_2PI * sigma * delta / 1.5; // φ(0) = 1.5 · 2π / 2 = 1.5π
    let f = GaussianBump::new(DVec3::ZERO, delta, sigma, 5.0);
    let mode = Mode::Interferometry { lambda, n_ref: 1.0, fringe_spacing: None };
    let mut film = Film::new(64, 64, Filter::Box).unwrap();
    bench(mode, 8).render(&f, &mut film, 0, 5).unwrap();
    let want = |x: f64, y: f64| {
        let phi = core::f64::consts::TAU / lambda
            * SQRT_2PI
            * sigma
            * delta
            * (-(x * x + y * y) / 2.0).exp();
        0.5 * (1.0 + phi.cos())
    };
    assert!(rmse(&film, want) < 0.02, "rmse {}", rmse(&film, want));
    assert!(rmse(&film, |x, y| 0.5 * (1.0 + (want(x, y) * 2.0 - 1.0).acos().sin())) > 0.1);
    // The mean phase per pixel, unwrapped, is the oracle's φ itself: the
    // pixel's average of a smooth φ over its area (second order in the
    // pixel size, 0.16 σ here: ≤ 0.5 % of φ(0)) and first order in δ.
    let phi0 = core::f64::consts::TAU / lambda * SQRT_2PI * sigma * delta;
    let phase = film.mean_phase();
    let mut worst: f64 = 0.0;
    for j in 0..film.height() {
        for i in 0..film.width() {
            let (x, y) = centre(&film, i, j);
            let got = phase[i + film.width() * j].expect("every pixel gets photons");
            worst = worst.max((got - phi0 * (-(x * x + y * y) / 2.0).exp()).abs());
        }
    }
    assert!(worst < 5e-3 * phi0, "phase error {worst:e} rad of φ(0) = {phi0}");
}

/// Outside interferometry the phase is not recorded: 0.
#[test]
fn schlieren_films_record_no_phase() {
    let f = GaussianBump::new(DVec3::ZERO, 1e-4, 1.0, 5.0);
    let mut film = Film::new(8, 8, Filter::Box).unwrap();
    bench(knife(1500.0), 2).render(&f, &mut film, 0, 1).unwrap();
    assert!(film.mean_phase().iter().all(|p| *p == Some(0.0)));
}

/// Russian roulette has the weighted image's expectation.
#[test]
fn roulette_has_the_same_expectation() {
    let f = GaussianBump::new(DVec3::ZERO, 1e-4, 1.0, 5.0);
    let mut w = Film::new(16, 16, Filter::Box).unwrap();
    let mut r = Film::new(16, 16, Filter::Box).unwrap();
    let mut b = bench(knife(1500.0), 8);
    b.render(&f, &mut w, 0, 9).unwrap();
    b.weighting = Weighting::Roulette;
    b.render(&f, &mut r, 0, 9).unwrap();
    let (tw, tr) = (w.total()[0], r.total()[0]);
    assert!((tw - tr).abs() < 4.0 * (tw * 0.25).sqrt(), "{tw} vs {tr}");
}

/// The same seed gives the same image bit for bit with 1 or 2 threads, and
/// progressive passes refine instead of restarting.
#[test]
fn deterministic_across_thread_counts_and_progressive() {
    let f = GaussianBump::new(DVec3::ZERO, 2e-3, 1.0, 5.0);
    let b = SchlierenBench { film_distance: 50.0, ..bench(knife(300.0), 2) };
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut film = Film::new(48, 40, Filter::Tent).unwrap();
            b.render(&f, &mut film, 0, 11).unwrap();
            b.render(&f, &mut film, 1, 11).unwrap();
            film
        })
    };
    let (one, two) = (render(1), render(2));
    assert_eq!(one, two);
    assert_eq!(one.per_pixel, 8.0);
}

/// Bad parameters are errors, and the film is left untouched.
#[test]
fn bad_parameters_are_errors() {
    let f = GaussianBump::new(DVec3::ZERO, 1e-4, 1.0, 5.0);
    let mut film = Film::new(8, 8, Filter::Box).unwrap();
    let before = film.clone();
    type IsExpected = fn(BenchError) -> bool;
    let cases: [(SchlierenBench, IsExpected); 6] = [
        (
            bench(
                Mode::Schlieren(Cutoff::KnifeEdge { angle: f64::NAN, offset: 0.0, f: 1.0, h: 1.0 }),
                2,
            ),
            |e| {
                matches!(
                    e,
                    BenchError::Cutoff(CutoffError::NotFinite { param: CutoffParam::Angle, .. })
                )
            },
        ),
        (bench(Mode::Interferometry { lambda: 0.0, n_ref: 1.0, fringe_spacing: None }, 2), |e| {
            e == BenchError::Wavelength(0.0)
        }),
        (
            bench(Mode::Interferometry { lambda: -1.0, n_ref: 1.0, fringe_spacing: Some(1.0) }, 2),
            |e| e == BenchError::Wavelength(-1.0),
        ),
        (bench(Mode::Schlieren(Cutoff::Color(rt_photo::FilterImage::opaque(0, 1.0))), 2), |e| {
            e == BenchError::Cutoff(CutoffError::EmptyImage)
        }),
        (bench(Mode::Schlieren(Cutoff::None), 0), |e| e == BenchError::Strata(0)),
        (
            SchlierenBench {
                direction: DVec3::new(0.0, 0.0, 2.0),
                ..bench(Mode::Schlieren(Cutoff::None), 2)
            },
            |e| e == BenchError::NotOrthonormal,
        ),
    ];
    for (b, expected) in cases {
        let e = b.render(&f, &mut film, 0, 1).unwrap_err();
        assert!(expected(e), "{e:?}");
        assert_eq!(film, before);
    }
    // The wrapped cause is the error's source.
    let e = BenchError::from(CutoffError::EmptyImage);
    let source = core::error::Error::source(&e).map(ToString::to_string);
    assert_eq!(source, Some(CutoffError::EmptyImage.to_string()));
    assert_eq!(Film::new(0, 8, Filter::Box), Err(FilmError::ZeroSize { width: 0, height: 8 }));
}

/// Linearised shadowgraph of a weak bump at small `L`:
/// `I/I₀ ≈ 1 + L·A·g(r)·(2 − r²/σ²)`, `A = √(2π)·δ/σ` (docs/oracles.md §5); 1M
/// photons on 32² pixels keep the count noise below the 5 % signal.
#[test]
fn shadowgraph_matches_the_linearised_gaussian() {
    let (delta, sigma, l) = (1e-4, 1.0, 100.0);
    let f = GaussianBump::new(DVec3::ZERO, delta, sigma, 5.0);
    let mut film = Film::new(32, 32, Filter::Tent).unwrap();
    let b = SchlierenBench { film_distance: l, ..bench(Mode::Schlieren(Cutoff::None), 32) };
    b.render(&f, &mut film, 0, 17).unwrap();
    assert!(film.emitted >= 1_000_000);
    let a = SQRT_2PI * delta / sigma;
    let want = |x: f64, y: f64| {
        let r2 = (x * x + y * y) / (sigma * sigma);
        1.0 + l * a * (-r2 / 2.0).exp() * (2.0 - r2)
    };
    // Pixels within 2.5 of the centre (the film's edge loses photons).
    let img = film.normalized();
    let (mut s, mut flat, mut n) = (0.0, 0.0, 0.0);
    for j in 0..32 {
        for i in 0..32 {
            let (x, y) = centre(&film, i, j);
            if x * x + y * y < 2.5 * 2.5 {
                let v = f64::from(img[i + 32 * j][0]);
                s += (v - want(x, y)).powi(2);
                flat += (v - 1.0).powi(2);
                n += 1.0;
            }
        }
    }
    let (e, f0) = ((s / n).sqrt(), (flat / n).sqrt());
    assert!(e < 0.006, "rmse {e}");
    assert!(f0 > 2.0 * e, "the 5 % signal must stand out: flat rmse {f0}");
}

/// docs/oracles.md §6: as the bump weakens, the traced deflection converges to the
/// line-of-sight integral of the gradient along the unbent ray (for the
/// Gaussian, `−√(2π)·δ·(x/σ)·g(r)`), the relative difference falling
/// linearly with δ.
#[test]
fn straight_line_limit() {
    let rel = |delta: f64| {
        let f = GaussianBump::new(DVec3::ZERO, delta, 1.0, 6.0);
        let p = TraceParams { tolerance: 1e-13, ..TraceParams::accurate() };
        [0.5f64, 1.0, 1.5]
            .iter()
            .map(|&x| {
                let r = rt_volume::trace(&f, DVec3::new(x, 0.0, -7.0), DVec3::Z, &p).unwrap();
                let traced = r.direction.x / r.direction.z;
                let linear = -SQRT_2PI * delta * x * (-x * x / 2.0).exp();
                ((traced - linear) / linear).abs()
            })
            .fold(0.0f64, f64::max)
    };
    let d = [rel(1e-2), rel(1e-3), rel(1e-4)];
    for w in d.windows(2) {
        let ratio = w[0] / w[1];
        assert!((7.0..14.0).contains(&ratio), "not linear in δ: {d:?}");
    }
}

/// Multifield: photons carry the colour of a second field averaged along
/// their path; with a scalar equal to x, each image column shows the
/// colour map at that x, times the cutoff's weight (here none: 1).
#[test]
fn photons_carry_the_colour_of_a_second_field() {
    let f = Constant { n: 1.0, bounds: Bounds::new(DVec3::splat(-3.0), DVec3::splat(3.0)) };
    let map = rt_core::ColorMap::viridis().with_range(-3.0, 3.0).unwrap();
    let mut film = Film::new(24, 8, Filter::Box).unwrap();
    let b = bench(Mode::Schlieren(Cutoff::None), 2);
    b.render_colored(&f, &|x: DVec3| x.x, &map, &mut film, 0, 4).unwrap();
    let img = film.normalized();
    for j in 0..8 {
        for i in 0..24 {
            let (x, _) = centre(&film, i, j);
            let want = map.map(x as f32);
            let got = img[i + 24 * j];
            for c in 0..3 {
                // Jitter spreads each pixel's photons over 0.25 in x;
                // compared as shown (sRGB), where the map is even.
                let (g, w) = (linear_to_srgb(got[c]), linear_to_srgb(want[c]));
                assert!((g - w).abs() < 0.03, "pixel {i},{j}: {got:?} vs {want:?}");
            }
        }
    }
    assert_eq!(film.lost, 0);
}

/// With one photon per pixel and Russian roulette (each photon deposits 0
/// or 1), the adaptive wide tent cuts the image noise against a
/// 16-photon weighted reference, while keeping every photon's weight.
#[test]
fn adaptive_radius_reduces_noise_at_few_photons() {
    let f = GaussianBump::new(DVec3::ZERO, 1e-4, 1.0, 5.0);
    let b1 = SchlierenBench { weighting: Weighting::Roulette, ..bench(knife(1500.0), 1) };
    let mut reference = Film::new(64, 64, Filter::Tent).unwrap();
    bench(knife(1500.0), 4).render(&f, &mut reference, 0, 1).unwrap();
    let diff = |a: &Film| {
        let (x, y) = (a.normalized(), reference.normalized());
        (x.iter().zip(&y).map(|(p, q)| f64::from(p[0] - q[0]).powi(2)).sum::<f64>()
            / x.len() as f64)
            .sqrt()
    };
    let mut sharp = Film::new(64, 64, Filter::Box).unwrap();
    b1.render(&f, &mut sharp, 0, 2).unwrap();
    let wide_filter = Filter::adaptive(1.0);
    assert!(matches!(wide_filter, Filter::WideTent { radius } if radius == 2.0));
    let mut wide = Film::new(64, 64, wide_filter).unwrap();
    b1.render(&f, &mut wide, 0, 2).unwrap();
    assert!(diff(&wide) < 0.7 * diff(&sharp), "wide {} vs box {}", diff(&wide), diff(&sharp));
    assert!((wide.total()[0] - sharp.total()[0]).abs() < 1e-6 * sharp.total()[0]);
    assert_eq!(Filter::adaptive(16.0), Filter::Tent);
}

/// A Gaussian bump sampled on a 64³ grid over `[-3, 3]³`, trilinear.
fn gridded_bump() -> rt_volume::GridField {
    use rt_volume::{Grid, GridField, Interp};
    let n = 64;
    let h = 6.0 / n as f64;
    let origin = DVec3::splat(-3.0 + 0.5 * h);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h;
                data.push((1.0 + 1e-3 * (-p.length_squared() / (2.0 * 0.5 * 0.5)).exp()) as f32);
            }
        }
    }
    let g = Grid::new([n; 3], origin, DVec3::splat(h), data).unwrap();
    GridField::new(g, Interp::Trilinear, 1.0).unwrap()
}

/// rt's default for grids (octree skipping at the bench's tolerance)
/// renders what plain tracing renders, within what the optics resolve,
/// and stays bit-identical across thread counts.
#[test]
fn grid_render_with_octree_matches_plain_tracing() {
    let f = gridded_bump();
    let b = SchlierenBench { params: TraceParams::for_grid(&f), ..bench(knife(300.0), 2) };
    let mut film = Film::new(64, 64, Filter::Box).unwrap();
    assert_eq!(b.skip_tolerance(&f, &film), (1.0 / 300.0) / 1000.0);
    let mut plain = film.clone();
    b.render(&f, &mut plain, 0, 5).unwrap();
    let medium = Medium::Grid(GridMedium::from_field(f.clone(), b.params).unwrap());
    let render = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut film = Film::new(64, 64, Filter::Box).unwrap();
            b.render_medium(&medium, &mut film, 0, 5).unwrap();
            film
        })
    };
    film = render(1);
    assert_eq!(film, render(3));
    let (a, p) = (film.normalized(), plain.normalized());
    let worst = a.iter().zip(&p).map(|(x, y)| (x[0] - y[0]).abs()).fold(0.0f32, f32::max);
    // Skipping may change a photon's deflection by the resolvable one
    // (1/1000 of the knife's range) over its whole path, so a pixel's
    // transmission by at most 1/1000 (f32 rounding aside).
    assert!(worst < 1.1e-3, "octree image differs from plain tracing by {worst}");
    let signal = p.iter().map(|x| (x[0] - 0.5).abs()).fold(0.0f32, f32::max);
    assert!(signal > 0.2, "the bump shows: {signal}");
}

/// The tolerance follows the optics: the cutoff's range, the film's pixel
/// after `L`, or the wavelength.
#[test]
fn skip_tolerance_follows_the_optics() {
    let f = gridded_bump();
    let film = Film::new(60, 30, Filter::Box).unwrap();
    let shadow = SchlierenBench { film_distance: 100.0, ..bench(Mode::Schlieren(Cutoff::None), 1) };
    // Pixel 0.1 (6/60), seen 100 further: 1e-3 rad; 1/1000 of it.
    assert!((shadow.skip_tolerance(&f, &film) - 1e-6).abs() < 1e-18);
    // At L = 0 without a cutoff nothing is resolved: the cap.
    let plain = bench(Mode::Schlieren(Cutoff::None), 1);
    assert_eq!(plain.skip_tolerance(&f, &film), 1e-3);
    let interf = bench(Mode::Interferometry { lambda: 5e-4, n_ref: 1.0, fringe_spacing: None }, 1);
    let want = 5e-4 / (6.0 * 3f64.sqrt()) / 1000.0;
    assert!((interf.skip_tolerance(&f, &film) - want).abs() < 1e-15 * want.max(1e-300) + 1e-20);
}

/// Splatting in parallel bands deposits exactly what serial splatting
/// does, for every filter, with photons on and off the film.
#[test]
fn parallel_splat_equals_serial_splat() {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let photons: Vec<Photon> = (0..20_000)
        .map(|_| {
            let (x, y) = (next() * 44.0 - 2.0, next() * 34.0 - 2.0);
            let w = [next() as f32, next() as f32, 1.0];
            Photon::new(x, y, w, (next() - 0.5, next() - 0.5))
        })
        .collect();
    for filter in [Filter::Box, Filter::Tent, Filter::WideTent { radius: 2.5 }] {
        let mut serial = Film::new(40, 30, filter).unwrap();
        for p in &photons {
            serial.splat(p.x, p.y, p.weight, p.deflection);
        }
        for threads in [1, 2, 7] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut banded = Film::new(40, 30, filter).unwrap();
            pool.install(|| banded.splat_all(photons.iter()));
            assert_eq!(serial, banded, "{filter:?} with {threads} threads");
        }
        assert!(serial.lost > 0 && serial.lost < 20_000);
    }
}

/// docs/oracles.md §5 at `σ = 1 cm` (a bump in metres, as in §7's BOS vector): the
/// deflection is an angle, `ε = −√(2π)·δ·(r/σ)·g(r)`, whatever the bump's
/// scale (an earlier statement of it carried a spurious `1/σ`, 100× here),
/// the shadowgraph's contrast scales as `A = √(2π)·δ/σ` and the phase as
/// `σ·δ`. Knife edge, shadowgraph and interferometry, with the sheet.
#[test]
fn oracles_hold_for_a_bump_of_one_centimetre() {
    let (delta, sigma) = (1e-4, 0.01);
    let f = GaussianBump::new(DVec3::ZERO, delta, sigma, 5.0);
    let scaled = |mode: Mode, film_distance: f64| SchlierenBench {
        center: DVec3::new(0.0, 0.0, -6.0 * sigma),
        width: 6.0 * sigma,
        height: 6.0 * sigma,
        image_plane: 6.0 * sigma,
        film_distance,
        reconstruction: Reconstruction::Sheet,
        ..bench(mode, 4)
    };
    // Worst |image − want| over pixels within 2.5σ of the axis.
    let worst = |film: &Film, value: &dyn Fn(usize) -> f64, want: &dyn Fn(f64, f64) -> f64| {
        let mut w: f64 = 0.0;
        for j in 0..film.height() {
            for i in 0..film.width() {
                let (x, y) = centre(film, i, j);
                if x * x + y * y < 2.5 * 2.5 {
                    w = w.max((value(i + film.width() * j) - want(x * sigma, y * sigma)).abs());
                }
            }
        }
        w
    };
    let g = |x: f64, y: f64| (-(x * x + y * y) / (2.0 * sigma * sigma)).exp();

    let fh = 1500.0;
    let mut film = Film::new(48, 48, Filter::Tent).unwrap();
    scaled(knife(fh), 0.0).render(&f, &mut film, 0, 3).unwrap();
    let img = film.normalized_f64();
    let knife_want =
        |x: f64, y: f64| (0.5 - fh * SQRT_2PI * delta * (x / sigma) * g(x, y)).clamp(0.0, 1.0);
    let e = worst(&film, &|p| img[p][0], &knife_want);
    assert!(e < 5e-3, "knife edge: worst {e}");
    assert!(worst(&film, &|p| img[p][0], &|_, _| 0.5) > 0.1, "the signal is there");

    let l = 1.0;
    let mut film = Film::new(48, 48, Filter::Tent).unwrap();
    scaled(Mode::Schlieren(Cutoff::None), l).render(&f, &mut film, 0, 5).unwrap();
    let img = film.normalized_f64();
    let a = SQRT_2PI * delta / sigma;
    let shadow_want = |x: f64, y: f64| {
        let r2 = (x * x + y * y) / (sigma * sigma);
        1.0 + l * a * g(x, y) * (2.0 - r2)
    };
    let e = worst(&film, &|p| img[p][0], &shadow_want);
    assert!(e < 5e-3, "shadowgraph: worst {e}");
    assert!(worst(&film, &|p| img[p][0], &|_, _| 1.0) > 0.04, "the 5 % signal is there");

    let lambda = 2.0 * SQRT_2PI * sigma * delta / 1.5; // φ(0) = 1.5π
    let mode = Mode::Interferometry { lambda, n_ref: 1.0, fringe_spacing: None };
    let mut film = Film::new(48, 48, Filter::Tent).unwrap();
    scaled(mode, 0.0).render(&f, &mut film, 0, 7).unwrap();
    let phase = film.mean_phase();
    let phi0 = core::f64::consts::TAU / lambda * SQRT_2PI * sigma * delta;
    let e = worst(&film, &|p| phase[p].unwrap_or(f64::NAN), &|x, y| phi0 * g(x, y));
    assert!(e < 5e-3 * phi0, "phase: worst {e} rad of {phi0}");
}
