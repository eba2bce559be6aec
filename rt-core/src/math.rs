//! Float functions from std or `libm`: the one place the crate chooses.

#[cfg(feature = "std")]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f32) -> f32 {
        x.sqrt()
    }
    #[inline]
    pub(crate) fn tan(x: f32) -> f32 {
        x.tan()
    }
    #[inline]
    #[cfg_attr(not(feature = "alloc"), allow(dead_code, reason = "used by `Frame` only"))]
    pub(crate) fn powf(x: f32, y: f32) -> f32 {
        x.powf(y)
    }
    #[inline]
    pub(crate) fn floor(x: f32) -> f32 {
        x.floor()
    }
    #[inline]
    pub(crate) fn atan2(y: f32, x: f32) -> f32 {
        y.atan2(x)
    }
    #[inline]
    pub(crate) fn acos(x: f32) -> f32 {
        x.acos()
    }
}

#[cfg(all(not(feature = "std"), feature = "libm"))]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    #[inline]
    pub(crate) fn tan(x: f32) -> f32 {
        libm::tanf(x)
    }
    #[inline]
    #[cfg_attr(not(feature = "alloc"), allow(dead_code, reason = "used by `Frame` only"))]
    pub(crate) fn powf(x: f32, y: f32) -> f32 {
        libm::powf(x, y)
    }
    #[inline]
    pub(crate) fn floor(x: f32) -> f32 {
        libm::floorf(x)
    }
    #[inline]
    pub(crate) fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
    #[inline]
    pub(crate) fn acos(x: f32) -> f32 {
        libm::acosf(x)
    }
}

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("rt-core needs float functions: enable feature `std` (default) or `libm`.");

#[cfg(any(feature = "std", feature = "libm"))]
pub(crate) use imp::*;

/// `(sin x, cos x)` for `|x| ≤ π/4`, by their Taylor series through
/// `x⁹` and `x¹⁰` (the first terms left out are below `2·10⁻⁹` there), in
/// Horner form: plain f32 arithmetic, so the same bits on every platform
/// and with `std` or `libm` alike (the platform's `sinf`, which AO
/// directions used before, differs between C libraries in the last bit,
/// and so did the images). Within 1 ulp of the true values
/// (`sin_cos_quarter_is_within_one_ulp`).
#[inline]
#[must_use]
pub(crate) fn sin_cos_quarter(x: f32) -> (f32, f32) {
    // 1/k! for k = 2 … 10.
    const F: [f32; 9] = [
        1.0 / 2.0,
        1.0 / 6.0,
        1.0 / 24.0,
        1.0 / 120.0,
        1.0 / 720.0,
        1.0 / 5040.0,
        1.0 / 40320.0,
        1.0 / 362_880.0,
        1.0 / 3_628_800.0,
    ];
    let x2 = x * x;
    let s = x + x * x2 * (-F[1] + x2 * (F[3] + x2 * (-F[5] + x2 * F[7])));
    let c = 1.0 + x2 * (-F[0] + x2 * (F[2] + x2 * (-F[4] + x2 * (F[6] - x2 * F[8]))));
    (s, c)
}

/// `γ(n) = n·u / (1 − n·u)` with `u = 2⁻²⁴`, the bound on the relative error of
/// `n` chained f32 operations (Higham; pbrt-v4 `Gamma`).
#[inline]
#[must_use]
pub const fn gamma(n: i32) -> f32 {
    let nu = n as f32 * (f32::EPSILON * 0.5);
    nu / (1.0 - nu)
}

#[cfg(all(test, feature = "std"))]
mod tests {
    use super::sin_cos_quarter;

    /// Distance in ulps between `x` and the f32 nearest `exact`.
    fn ulps(x: f32, exact: f64) -> u32 {
        let e = exact as f32;
        // Same sign across the whole range tested (or both zero).
        (x.to_bits() as i64 - e.to_bits() as i64).unsigned_abs() as u32
    }

    #[test]
    fn sin_cos_quarter_is_within_one_ulp() {
        let q = core::f32::consts::FRAC_PI_4;
        let mut worst = (0, 0);
        // Every 2⁻²⁰ of the range, both ends and zero.
        let n = 1 << 20;
        for i in -n..=n {
            let x = q * (i as f32 / n as f32);
            let (s, c) = sin_cos_quarter(x);
            let (es, ec) = f64::from(x).sin_cos();
            worst = (worst.0.max(ulps(s, es)), worst.1.max(ulps(c, ec)));
            assert!(s.abs() <= 1.0 && c <= 1.0 && c > 0.7, "{x}: {s} {c}");
        }
        assert!(worst.0 <= 1 && worst.1 <= 1, "worst ulps (sin, cos) {worst:?}");
        // Odd and even, exactly.
        for x in [0.1f32, 0.5, q] {
            let ((s, c), (sn, cn)) = (sin_cos_quarter(x), sin_cos_quarter(-x));
            assert!(s == -sn && c == cn);
        }
    }
}
