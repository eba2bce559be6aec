//! The film from any size, filter and photons: only empty films and wide
//! tents of a NaN, infinite or sub-pixel radius are refused; off-film and
//! non-finite positions are counted as lost, never splatted; with finite
//! weights and deflections every pixel stays finite and the deposited
//! total equals the weight of the photons that landed (each filter's
//! shares sum to 1).
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_fuzz::{f32_any, f64_any};
use rt_photo::{Film, FilmError, Filter};

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let (Ok(w), Ok(h), Ok(kind), Ok(radius)) = (
        u.int_in_range(0usize..=40),
        u.int_in_range(0usize..=40),
        u.int_in_range(0u8..=3),
        f64_any(&mut u),
    ) else {
        return;
    };
    let filter = match kind {
        0 => Filter::Box,
        1 => Filter::Tent,
        2 => Filter::WideTent { radius },
        _ => Filter::adaptive(radius),
    };
    let mut film = match Film::new(w, h, filter) {
        Ok(film) => film,
        Err(FilmError::ZeroSize { .. }) => {
            assert!(w == 0 || h == 0, "a {w}×{h} film refused as empty");
            return;
        }
        Err(FilmError::BadFilterRadius(r)) => {
            // `Filter::adaptive` always gives a valid radius.
            assert!(kind == 2 && !(r.is_finite() && r >= 1.0), "radius {r} refused");
            return;
        }
        Err(e) => panic!("a {w}×{h} film refused: {e}"),
    };
    // The sum of what landed, and of its magnitudes: the reference sum
    // rounds too, by up to ε·Σ|w| (weights of ±4.6e27 around small ones
    // lose the small ones in it; found by this target), so the comparison
    // is scaled by Σ|w|, not by the sum.
    let (mut landed, mut landed_abs, mut finite) = (0.0f64, 0.0f64, true);
    let mut expected_lost = 0;
    for _ in 0..32 {
        let (Ok(x), Ok(y), Ok(weight), Ok(e)) =
            (f64_any(&mut u), f64_any(&mut u), f32_any(&mut u), f64_any(&mut u))
        else {
            break;
        };
        let on = x >= 0.0 && y >= 0.0 && x < w as f64 && y < h as f64;
        if on {
            landed += f64::from(weight);
            landed_abs += f64::from(weight).abs();
        } else {
            expected_lost += 1;
        }
        finite &= weight.is_finite() && e.is_finite() && weight.abs() < 1e30;
        film.splat(x, y, [weight; 3], (e, -e));
    }
    assert_eq!(film.lost, expected_lost, "off-film photons miscounted");
    if finite {
        let total = film.total()[0];
        assert!(total.is_finite(), "total {total}");
        let scale = 1.0 + landed_abs;
        assert!(
            (total - landed).abs() <= 1e-9 * scale * 32.0,
            "deposited {total}, landed {landed}"
        );
        assert!(film.normalized().iter().flatten().all(|v| v.is_finite()));
    }
});
