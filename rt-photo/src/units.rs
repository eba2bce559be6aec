//! Numbers as a paper prints them: SI prefixes and three significant
//! digits (`10.6 µm`, `2.90 mm`, `169 k photons/s`), refractive indices to
//! the digit that shows their departure from 1 (`1.000637`). The lines
//! the set-ups print ([`crate::SchlierenSetup`]'s `Display`) and the
//! tools' summaries and figure titles go through here, never `{}` of a
//! raw `f64` (`0.0000106 m`, `1.0006369352340698`).

use alloc::{format, string::String};

use crate::math::{floor, log10, powi, round};

/// `x` with three significant digits, plainly (`0.00291` → `0.00291`,
/// `0.9999999999999999` → `1.00`; whole numbers up to 99 999 in full);
/// scientific
/// (`1.23e-7`) outside 1e-3 … 1e5; NaN and infinities as Rust prints them.
#[must_use]
pub fn sig3(x: f64) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    // Rounded to three digits first: 0.99999 is 1.00, not 1.000.
    let e = exponent_of(x);
    let x = round(x / powi(10.0, e - 2)) * powi(10.0, e - 2);
    let e = exponent_of(x);
    if (-3..5).contains(&e) {
        let decimals = (2 - e).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        let m = x / powi(10.0, e);
        format!("{m:.2}e{e}")
    }
}

/// `x` in `unit` with an SI prefix and three significant digits:
/// `si(10.6e-6, "m")` → `10.6 µm`, `si(0.00290, "m")` → `2.90 mm`,
/// `si(169_134.0, "photons/s")` → `169 k photons/s`. Prefixes from pico
/// to giga; beyond them, scientific notation.
#[must_use]
pub fn si(x: f64, unit: &str) -> String {
    if !x.is_finite() || x == 0.0 {
        return format!("{x} {unit}");
    }
    const PREFIXES: [(i32, &str); 8] =
        [(-12, "p"), (-9, "n"), (-6, "µ"), (-3, "m"), (0, ""), (3, "k"), (6, "M"), (9, "G")];
    // Round to three digits first, so 999.96e-6 becomes 1.00 m, not 1000 µm.
    let e = exponent_of(x);
    let rounded = round(x / powi(10.0, e - 2)) * powi(10.0, e - 2);
    let e = exponent_of(rounded);
    let Some(&(p, prefix)) = PREFIXES.iter().rev().find(|(p, _)| *p <= e) else {
        return format!("{} {unit}", sig3(x));
    };
    if e >= 12 {
        return format!("{} {unit}", sig3(x));
    }
    // A prefix joins a symbol (`mm`, `mrad`) but stands apart from a word
    // (`169 k photons/s`).
    let value = sig3(rounded / powi(10.0, p));
    if unit.len() > 3 && !prefix.is_empty() {
        format!("{value} {prefix} {unit}")
    } else if unit.is_empty() && prefix.is_empty() {
        value
    } else {
        format!("{value} {prefix}{unit}")
    }
}

/// A refractive index (or any number near 1) to the decimal that shows
/// its departure from 1 to three significant digits: `1.0006369…` →
/// `1.000637`, water's `1.33` → `1.330`, exactly 1 → `1`.
#[must_use]
pub fn index(n: f64) -> String {
    let d = (n - 1.0).abs();
    if !n.is_finite() || d == 0.0 {
        return format!("{n}");
    }
    let decimals = (2 - exponent_of(d)).clamp(2, 12) as usize;
    format!("{n:.decimals$}")
}

/// The decimal exponent of `x`'s leading digit (`0.0029` → `-3`).
fn exponent_of(x: f64) -> i32 {
    // A hair above, so exact powers of ten land on their own exponent.
    floor(log10(x.abs()) + 1e-12) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_issue_s_examples_read_as_a_paper_prints_them() {
        assert_eq!(si(10.6e-6, "m"), "10.6 µm");
        assert_eq!(si(0.0000106, "m"), "10.6 µm");
        assert_eq!(si(2.9037e-3, "m"), "2.90 mm");
        assert_eq!(si(169_134.56, "photons/s"), "169 k photons/s");
        assert_eq!(si(2.4486e-3, "rad"), "2.45 mrad");
        assert_eq!(si(1.0, "m"), "1.00 m");
        assert_eq!(si(5.2258, "m"), "5.23 m");
        assert_eq!(si(999.96e-6, "m"), "1.00 mm");
        assert_eq!(si(-3.2e-9, "s"), "-3.20 ns");
        assert_eq!(si(4.2e15, "J"), "4.20e15 J");
        assert_eq!(index(1.000_636_935_234_069_8), "1.000637");
        assert_eq!(index(1.33), "1.330");
        assert_eq!(index(1.0), "1");
        assert_eq!(sig3(0.999_999_999_999_999_9), "1.00");
        assert_eq!(sig3(0.015625), "0.0156");
        assert_eq!(sig3(-0.4921875), "-0.492");
        assert_eq!(sig3(1.2345e-7), "1.23e-7");
        assert_eq!(sig3(f64::NAN), "NaN");
    }
}
