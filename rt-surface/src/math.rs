//! Float functions from std or `libm`: the one place the crate chooses.

#[cfg(feature = "std")]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f32) -> f32 {
        x.sqrt()
    }
    #[inline]
    pub(crate) fn powf(x: f32, y: f32) -> f32 {
        x.powf(y)
    }
}

#[cfg(all(not(feature = "std"), feature = "libm"))]
mod imp {
    #[inline]
    pub(crate) fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    #[inline]
    pub(crate) fn powf(x: f32, y: f32) -> f32 {
        libm::powf(x, y)
    }
}

#[cfg(not(any(feature = "std", feature = "libm")))]
compile_error!("rt-surface needs float functions: enable feature `std` (default) or `libm`.");

#[cfg(any(feature = "std", feature = "libm"))]
pub(crate) use imp::*;
