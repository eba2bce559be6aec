//! Which instruction set the traversal kernels use, chosen at run time.
//!
//! One binary built with default flags carries every kernel its target
//! can run: on x86-64 an SSE kernel (the baseline), an AVX2 kernel (the
//! eight child boxes of a node in one 256-bit pass) and an AVX-512 kernel
//! (the same code compiled with AVX-512F/VL, whose compares write mask
//! registers directly). With `std` the widest kernel the CPU has is picked
//! once by `is_x86_feature_detected!`; without `std` by the target features
//! the build enables. Every kernel does the same arithmetic lane for lane,
//! so all of them return the same hits, bit for bit (tested on every
//! kernel the CPU runs).

use core::fmt;

/// An instruction set a traversal kernel is built for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    /// Four lanes with plain arrays: targets other than x86-64.
    Portable,
    /// SSE (x86-64's baseline): a node's boxes in two 4-wide passes.
    Sse,
    /// AVX2 + FMA: a node's eight boxes in one 8-wide pass, one fused
    /// multiply-add per plane for rays the fused test covers.
    Avx2,
    /// AVX-512F + VL: the AVX2 kernel with EVEX encodings and compares
    /// into mask registers.
    Avx512,
}

impl Isa {
    /// Every kernel, narrowest first.
    pub const ALL: [Self; 4] = [Self::Portable, Self::Sse, Self::Avx2, Self::Avx512];

    /// The widest kernel this CPU runs (with `std`: detected at run time
    /// and cached by the standard library; without: from the target
    /// features of the build).
    #[must_use]
    pub fn detect() -> Self {
        // Every BVH query asks: remember the answer (0: not asked yet).
        static DETECTED: core::sync::atomic::AtomicU8 = core::sync::atomic::AtomicU8::new(0);
        let known = DETECTED.load(core::sync::atomic::Ordering::Relaxed);
        if let Some(&isa) = known.checked_sub(1).and_then(|i| Self::ALL.get(usize::from(i))) {
            return isa;
        }
        let isa =
            Self::ALL.into_iter().rev().find(|isa| isa.is_available()).unwrap_or(Self::Portable);
        let index = Self::ALL.iter().position(|&a| a == isa).unwrap_or(0) as u8;
        DETECTED.store(index + 1, core::sync::atomic::Ordering::Relaxed);
        isa
    }

    /// Whether this CPU (and this build's target) runs the kernel.
    #[must_use]
    pub fn is_available(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            #[cfg(feature = "std")]
            macro_rules! has {
                ($($f:tt),+) => { $(std::is_x86_feature_detected!($f))&&+ };
            }
            #[cfg(not(feature = "std"))]
            macro_rules! has {
                ($($f:tt),+) => { $(cfg!(target_feature = $f))&&+ };
            }
            match self {
                Self::Portable => false,
                Self::Sse => true,
                Self::Avx2 => has!("avx", "avx2", "fma"),
                Self::Avx512 => has!("avx", "avx2", "fma", "avx512f", "avx512vl"),
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            self == Self::Portable
        }
    }

    /// The kernels this CPU runs, narrowest first.
    pub fn available() -> impl Iterator<Item = Self> {
        Self::ALL.into_iter().filter(|isa| isa.is_available())
    }

    /// Lower-case name: `portable`, `sse`, `avx2`, `avx512`.
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Self::Portable => "portable",
            Self::Sse => "sse",
            Self::Avx2 => "avx2",
            Self::Avx512 => "avx512",
        }
    }

    /// The kernel named `name` (as [`Isa::name`] writes it), if any.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|isa| isa.name() == name)
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A kernel was asked for that this CPU or target cannot run
/// ([`crate::BvhRef::with_isa`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnsupportedIsa(pub Isa);

impl fmt::Display for UnsupportedIsa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "this CPU or target cannot run the {} traversal kernel", self.0)
    }
}

impl core::error::Error for UnsupportedIsa {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_detect_picks_the_widest() {
        for isa in Isa::ALL {
            assert_eq!(Isa::from_name(isa.name()), Some(isa));
        }
        assert_eq!(Isa::from_name("neon"), None);
        let widest = Isa::available().last().unwrap();
        assert_eq!(Isa::detect(), widest);
        #[cfg(target_arch = "x86_64")]
        assert!(Isa::Sse.is_available() && !Isa::Portable.is_available());
    }
}
