//! Every cutoff from any parameters: `validate` refuses the bad ones; a
//! valid cutoff transmits between 0 and 1 per channel for any deflection,
//! NaN and infinite ones included, and a knife edge or graded filter does
//! not decrease as the deflection grows across it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_fuzz::f64_any;
use rt_photo::{Cutoff, FilterImage};

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let mut x = || f64_any(&mut u);
    let (Ok(a), Ok(b), Ok(c), Ok(d), Ok(eu), Ok(ev), Ok(step)) =
        (x(), x(), x(), x(), x(), x(), x())
    else {
        return;
    };
    let Ok(kind) = u.int_in_range(0u8..=5) else { return };
    let cutoff = match kind {
        0 => Cutoff::None,
        1 => Cutoff::KnifeEdge { angle: a, offset: b, f: c, h: d },
        2 => Cutoff::Graded { angle: a, f: c, width: d },
        3 => Cutoff::Pinhole { f: c, radius: d, dark_field: b > 0.0 },
        4 => Cutoff::Color(FilterImage::hue_wheel(1 + (a.abs() as usize % 64), d)),
        _ => Cutoff::Color(FilterImage::opaque(1 + (a.abs() as usize % 64), d)),
    };
    if cutoff.validate().is_err() {
        return;
    }
    let t = cutoff.transmit(eu, ev);
    assert!(t.iter().all(|v| (0.0..=1.0).contains(v)), "{cutoff:?} ({eu}, {ev}) → {t:?}");
    if let Cutoff::KnifeEdge { angle, .. } | Cutoff::Graded { angle, .. } = cutoff
        && step.is_finite()
        && step > 0.0
        && eu.is_finite()
    {
        // Along the sensitive direction, more deflection never darkens.
        let (c, s) = (angle.cos(), angle.sin());
        let (e0, e1) = ((eu * c, eu * s), ((eu + step) * c, (eu + step) * s));
        let (t0, t1) = (cutoff.transmit(e0.0, e0.1)[0], cutoff.transmit(e1.0, e1.1)[0]);
        assert!(t1 >= t0 - 1e-6, "{cutoff:?}: {t0} at {eu}, {t1} at {}", eu + step);
    }
});
