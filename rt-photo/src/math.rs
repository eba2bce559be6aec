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
}

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("rt-photo needs float functions: enable feature `std` (default) or `libm`.");

#[cfg(any(feature = "std", feature = "libm"))]
pub(crate) use imp::*;
