//! f64 float functions from std or `libm`.

#[cfg(feature = "std")]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f64) -> f64 {
        x.sqrt()
    }
    #[inline]
    pub(crate) fn exp(x: f64) -> f64 {
        x.exp()
    }
    #[inline]
    pub(crate) fn powf(x: f64, y: f64) -> f64 {
        x.powf(y)
    }
}

#[cfg(all(not(feature = "std"), feature = "libm"))]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f64) -> f64 {
        libm::sqrt(x)
    }
    #[inline]
    pub(crate) fn exp(x: f64) -> f64 {
        libm::exp(x)
    }
    #[inline]
    pub(crate) fn powf(x: f64, y: f64) -> f64 {
        libm::pow(x, y)
    }
}

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("rt-volume needs float functions: enable feature `std` (default) or `libm`.");

#[cfg(any(feature = "std", feature = "libm"))]
pub(crate) use imp::*;
