//! f64 float functions from std or `libm`: exactly those rt-photo calls.

#[cfg(feature = "std")]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f64) -> f64 {
        x.sqrt()
    }
    #[inline]
    pub(crate) fn floor(x: f64) -> f64 {
        x.floor()
    }
    #[inline]
    pub(crate) fn ceil(x: f64) -> f64 {
        x.ceil()
    }
    #[inline]
    pub(crate) fn sin(x: f64) -> f64 {
        x.sin()
    }
    #[inline]
    pub(crate) fn cos(x: f64) -> f64 {
        x.cos()
    }
    #[inline]
    pub(crate) fn atan2(y: f64, x: f64) -> f64 {
        y.atan2(x)
    }
    #[inline]
    pub(crate) fn ln(x: f64) -> f64 {
        x.ln()
    }
    #[inline]
    pub(crate) fn exp(x: f64) -> f64 {
        x.exp()
    }
    #[inline]
    pub(crate) fn log10(x: f64) -> f64 {
        x.log10()
    }
    #[inline]
    pub(crate) fn round(x: f64) -> f64 {
        x.round()
    }
    #[inline]
    pub(crate) fn powi(x: f64, n: i32) -> f64 {
        x.powi(n)
    }
    #[inline]
    pub(crate) fn hypot(x: f64, y: f64) -> f64 {
        x.hypot(y)
    }
}

#[cfg(all(not(feature = "std"), feature = "libm"))]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f64) -> f64 {
        libm::sqrt(x)
    }
    #[inline]
    pub(crate) fn floor(x: f64) -> f64 {
        libm::floor(x)
    }
    #[inline]
    pub(crate) fn ceil(x: f64) -> f64 {
        libm::ceil(x)
    }
    #[inline]
    pub(crate) fn sin(x: f64) -> f64 {
        libm::sin(x)
    }
    #[inline]
    pub(crate) fn cos(x: f64) -> f64 {
        libm::cos(x)
    }
    #[inline]
    pub(crate) fn atan2(y: f64, x: f64) -> f64 {
        libm::atan2(y, x)
    }
    #[inline]
    pub(crate) fn ln(x: f64) -> f64 {
        libm::log(x)
    }
    #[inline]
    pub(crate) fn exp(x: f64) -> f64 {
        libm::exp(x)
    }
    #[inline]
    pub(crate) fn log10(x: f64) -> f64 {
        libm::log10(x)
    }
    #[inline]
    pub(crate) fn round(x: f64) -> f64 {
        libm::round(x)
    }
    #[inline]
    pub(crate) fn powi(x: f64, n: i32) -> f64 {
        libm::pow(x, f64::from(n))
    }
    #[inline]
    pub(crate) fn hypot(x: f64, y: f64) -> f64 {
        libm::hypot(x, y)
    }
}

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("rt-photo needs float functions: enable feature `std` (default) or `libm`.");

#[cfg(any(feature = "std", feature = "libm"))]
pub(crate) use imp::*;
