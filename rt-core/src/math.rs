//! Float functions from std or `libm`: the one place the crate chooses.

#[cfg(feature = "std")]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f32) -> f32 {
        x.sqrt()
    }
    #[inline]
    pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
        x.sin_cos()
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
    pub(crate) fn sin_cos(x: f32) -> (f32, f32) {
        libm::sincosf(x)
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

/// `γ(n) = n·u / (1 − n·u)` with `u = 2⁻²⁴`, the bound on the relative error of
/// `n` chained f32 operations (Higham; pbrt-v4 `Gamma`).
#[inline]
#[must_use]
pub const fn gamma(n: i32) -> f32 {
    let nu = n as f32 * (f32::EPSILON * 0.5);
    nu / (1.0 - nu)
}
