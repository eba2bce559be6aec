//! Numerical stress for the optics: photons at absurd positions on the
//! film and exactly on its edges, deflections from 1e-8 to 1e8 (and NaN)
//! through every cutoff, bump strengths over six decades, and a bump far
//! narrower than the beam's sampling. Each test asserts conservation,
//! range or linearity — the property that matters — not just "no panic".

mod support;

use glam::DVec3;
use rt_photo::{Cutoff, Film, Filter, Mode, SchlierenBench};
use rt_volume::GaussianBump;

fn filters() -> [Filter; 4] {
    [Filter::Box, Filter::Tent, Filter::WideTent { radius: 2.5 }, Filter::adaptive(0.1)]
}

/// Photons at NaN, ±∞, huge, subnormal and exactly-on-the-edge positions:
/// each either lands (its whole weight deposited: every filter's shares
/// sum to 1, clipped footprints included) or is counted lost — never a
/// NaN pixel, never weight created or destroyed.
#[test]
fn film_accounts_for_every_photon() {
    let (w, h) = (16usize, 9usize);
    let (wf, hf) = (w as f64, h as f64);
    let xs = [
        f64::NAN,
        f64::INFINITY,
        f64::NEG_INFINITY,
        -1e300,
        1e300,
        -f64::MIN_POSITIVE,
        -0.0,
        0.0,
        5e-324,
        0.5,
        wf.next_down(),
        wf,
        wf.next_up(),
        1e-8,
        7.25,
    ];
    for filter in filters() {
        let mut film = Film::new(w, h, filter).unwrap();
        let (mut landed, mut lost) = (0u64, 0u64);
        for &x in &xs {
            for &y in &[f64::NAN, -0.0, 0.0, 4.5, hf.next_down(), hf, 1e300] {
                film.splat(x, y, [1.0, 0.5, 0.25], (1e-3, -1e-3));
                if x >= 0.0 && y >= 0.0 && x < wf && y < hf {
                    landed += 1;
                } else {
                    lost += 1;
                }
            }
        }
        assert_eq!(film.lost, lost, "{filter:?}");
        let total = film.total();
        assert!((total[0] - landed as f64).abs() < 1e-9 * landed as f64, "{filter:?}: {total:?}");
        assert!((total[1] - 0.5 * landed as f64).abs() < 1e-9 * landed as f64, "{filter:?}");
        assert!(film.normalized().iter().flatten().all(|v| v.is_finite()), "{filter:?}");
        assert!(
            film.mean_deflection().iter().flatten().all(|(a, b)| a.is_finite() && b.is_finite())
        );
    }
}

/// Found by the `film` fuzz target (the target's own reference sum was at
/// fault): weights of ±4.59e27 splatted at one point cancel exactly in
/// the film's pixels, leaving the small weights landed between them
/// intact where the footprints do not overlap (box and tent), while a
/// plain running sum of the weights loses them. (Where footprints overlap,
/// a pixel holds ±4.59e27 plus the small share, which f64 rounds away:
/// the film, like any sum, is exact to `ε·Σ|w|`, as the target now
/// checks.)
#[test]
fn fuzz_regression_cancelling_huge_weights_keep_the_small_ones() {
    let huge = f32::from_bits(0x6d6d_6d6d); // 4.59e27, from the fuzz input
    for filter in [Filter::Box, Filter::Tent] {
        let mut film = Film::new(27, 40, filter).unwrap();
        film.splat(2.8125, 0.0, [-huge; 3], (-1.375, 1.375));
        film.splat(0.25, 3.875, [2.8125; 3], (2.8125, -2.8125));
        film.splat(2.8125, 0.0, [huge; 3], (-1.375, 1.375));
        film.splat(0.25, 3.875, [3.875; 3], (2.6875, -2.6875));
        assert_eq!(film.total(), [6.6875; 3], "{filter:?}");
        let naive = [-huge, 2.8125, huge, 3.875].iter().map(|&w| f64::from(w)).sum::<f64>();
        assert_eq!(naive, 3.875, "the reference sum the fuzz target used loses 2.8125");
    }
}

/// Every cutoff, for deflections swept log-uniformly over 1e-8 … 1e8 in
/// both signs and both image axes (and NaN, ±∞): transmission stays in
/// `[0, 1]`; a knife edge and a graded filter never darken as the
/// deflection grows across them and pass exactly half at zero (half cut);
/// a NaN deflection is blocked.
#[test]
fn cutoffs_over_twenty_decades_of_deflection() {
    let knife = Cutoff::KnifeEdge { angle: 0.3, offset: 0.0, f: 1.0, h: 1e-3 };
    let graded = Cutoff::Graded { angle: -1.1, f: 2.0, width: 1e-4 };
    let pin = Cutoff::Pinhole { f: 1.0, radius: 1e-6, dark_field: true };
    let mut eps: Vec<f64> = (-8..=8).flat_map(|k| [10f64.powi(k), -(10f64.powi(k))]).collect();
    eps.extend([0.0, -0.0, f64::INFINITY, f64::NEG_INFINITY, f64::MIN_POSITIVE]);
    eps.sort_by(f64::total_cmp);
    for c in [&knife, &graded, &pin, &Cutoff::None] {
        for &a in &eps {
            for &b in &eps {
                let t = c.transmit(a, b);
                assert!(t.iter().all(|v| (0.0..=1.0).contains(v)), "{c:?} ({a}, {b}) → {t:?}");
            }
        }
        if !matches!(c, Cutoff::None) {
            assert_eq!(c.transmit(f64::NAN, 0.0), [0.0; 3], "{c:?}: NaN deflection not blocked");
        }
    }
    for (c, angle) in [(&knife, 0.3f64), (&graded, -1.1)] {
        assert_eq!(c.transmit(0.0, 0.0), [0.5; 3]);
        let (cs, sn) = (angle.cos(), angle.sin());
        let along: Vec<f32> = eps.iter().map(|&e| c.transmit(e * cs, e * sn)[0]).collect();
        assert!(along.windows(2).all(|w| w[1] >= w[0]), "{c:?} not monotone: {along:?}");
        assert_eq!((along[0], along[along.len() - 1]), (0.0, 1.0), "{c:?} not saturating");
    }
}

/// A beam along +z through `[-3, 3]²` with a knife edge, one photon per
/// pixel.
fn knife_bench(f_over_h: f64) -> SchlierenBench {
    support::bench(support::knife(f_over_h), 1)
}

/// The knife-edge signal of a Gaussian bump for strength `delta` and
/// sensitivity f/h: the image minus its half-cut background, summed over
/// the left half of the film. (A sum, because photons displaced across a
/// pixel border move weight between pixels but not across the middle,
/// where the deflection vanishes.)
fn signal(delta: f64, f_over_h: f64) -> (f64, Film) {
    let f = GaussianBump::new(DVec3::ZERO, delta, 1.0, 5.0);
    let mut film = Film::new(24, 24, Filter::Box).unwrap();
    knife_bench(f_over_h).render(&f, &mut film, 0, 3).unwrap();
    let img = film.normalized();
    let s = (0..24 * 24).filter(|i| i % 24 < 12).map(|i| f64::from(img[i][0]) - 0.5).sum();
    (s, film)
}

/// Bump strengths δ from 1e-8 to 1e-2 (sensitivity raised as δ falls, so
/// the signal stays in the knife's linear range): the signal is linear in
/// δ·(f/h) — each decade of δ at fixed f/h gives 10× the signal within
/// 2 % (up to δ = 1e-2; beyond, the deflection itself is no longer
/// linear in δ) — and at a δ far too strong for the knife the image saturates to
/// exactly 0 and 1 with no NaN.
#[test]
fn knife_signal_is_linear_over_six_decades_and_saturates_cleanly() {
    let mut per_unit = Vec::new();
    for k in 3..=8 {
        let delta = 10f64.powi(-k);
        let f_over_h = 0.05 / delta / 20.0; // signal ≈ 0.05·√(2π)·g/σ·… ≪ 0.5
        let (lo, _) = signal(delta, f_over_h);
        let (hi, _) = signal(10.0 * delta, f_over_h);
        let ratio = hi / lo;
        assert!((ratio - 10.0).abs() < 0.2, "δ = {delta:e}: signal ratio {ratio}");
        per_unit.push(lo / (delta * f_over_h));
    }
    // The same signal per unit of δ·f/h at every decade.
    let (min, max) = per_unit.iter().fold((f64::MAX, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(max / min < 1.02, "signal per δ·f/h drifts: {per_unit:?}");
    let (_, film) = signal(0.5, 1e4);
    let img = film.normalized();
    assert!(img.iter().flatten().all(|v| v.is_finite()));
    let (lo, hi) = img.iter().fold((f32::MAX, 0.0f32), |(a, b), p| (a.min(p[0]), b.max(p[0])));
    assert_eq!((lo, hi > 0.99), (0.0, true), "a saturated knife image is cut to 0 and passes ≈ 1");
}

/// A bump 100× narrower than the beam's photon spacing, and one with a
/// very steep index (δ = 0.3 over σ = 1e-3): every photon still lands or
/// is lost (weight conserved), nothing is NaN.
#[test]
fn needle_bumps_conserve_weight() {
    for (delta, sigma) in [(1e-3, 1e-3), (0.3, 1e-3), (-0.3, 1e-2)] {
        let f = GaussianBump::new(DVec3::new(0.01, -0.02, 0.0), delta, sigma, 5.0);
        let mut film = Film::new(20, 20, Filter::Tent).unwrap();
        let mut b = knife_bench(1.0);
        b.mode = Mode::Schlieren(Cutoff::None);
        b.film_distance = 3.0;
        b.strata = 2;
        b.render(&f, &mut film, 0, 5).unwrap();
        let on = film.total()[0];
        assert!(
            (on + film.lost as f64 - film.emitted as f64).abs() < 1e-9 * film.emitted as f64,
            "δ {delta} σ {sigma}: {on} + {} lost ≠ {}",
            film.lost,
            film.emitted
        );
        assert!(film.normalized().iter().flatten().all(|v| v.is_finite()));
    }
}
