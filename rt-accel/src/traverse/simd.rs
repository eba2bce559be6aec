//! Four f32 lanes: SSE on x86-64 (always present there), plain arrays
//! elsewhere. Both implementations give bit-identical results, including the
//! NaN rule that matters for the slab test: `max(a, b)` and `min(a, b)`
//! return `b` when either is NaN (the SSE `maxps`/`minps` definition).

// The intrinsics below carry `#[target_feature(enable = "sse")]`, so calling
// them is `unsafe` even though SSE is part of every x86-64 CPU: each call's
// SAFETY note says just that.
#[cfg(target_arch = "x86_64")]
mod imp {
    use core::arch::x86_64::*;

    /// Four f32 lanes.
    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub(crate) struct F32x4(__m128);

    impl F32x4 {
        #[inline(always)]
        pub(crate) fn splat(x: f32) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_set1_ps(x) })
        }
        #[inline(always)]
        pub(crate) fn from_array(a: [f32; 4]) -> Self {
            Self(bytemuck::cast(a))
        }
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 4] {
            bytemuck::cast(self.0)
        }
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_add_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_sub_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn mul(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_mul_ps(self.0, o.0) })
        }
        #[inline(always)]
        pub(crate) fn div(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_div_ps(self.0, o.0) })
        }
        /// `self` if `self > o`, else `o` (so NaN in either gives `o`).
        #[inline(always)]
        pub(crate) fn max(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_max_ps(self.0, o.0) })
        }
        /// `self` if `self < o`, else `o` (so NaN in either gives `o`).
        #[inline(always)]
        pub(crate) fn min(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_min_ps(self.0, o.0) })
        }
        /// Bit `i` set where lane `i` has `self <= o` (false for NaN).
        #[inline(always)]
        pub(crate) fn le_mask(self, o: Self) -> u32 {
            // SAFETY: SSE is in the x86-64 baseline.
            (unsafe { _mm_movemask_ps(_mm_cmple_ps(self.0, o.0)) }) as u32
        }
        /// Bit `i` set where lane `i` has `self < o`.
        #[inline(always)]
        pub(crate) fn lt_mask(self, o: Self) -> u32 {
            // SAFETY: SSE is in the x86-64 baseline.
            (unsafe { _mm_movemask_ps(_mm_cmplt_ps(self.0, o.0)) }) as u32
        }
        /// Bit `i` set where lane `i` has `self == o`.
        #[inline(always)]
        pub(crate) fn eq_mask(self, o: Self) -> u32 {
            // SAFETY: SSE is in the x86-64 baseline.
            (unsafe { _mm_movemask_ps(_mm_cmpeq_ps(self.0, o.0)) }) as u32
        }
        /// The lanes' bits or-ed.
        #[inline(always)]
        pub(crate) fn or_bits(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_or_ps(self.0, o.0) })
        }
        /// The lanes' bits and-ed.
        #[inline(always)]
        pub(crate) fn and_bits(self, o: Self) -> Self {
            // SAFETY: SSE is in the x86-64 baseline.
            Self(unsafe { _mm_and_ps(self.0, o.0) })
        }
        /// Bit `i` set where lane `i`'s sign bit is (`−0` and NaNs too).
        #[inline(always)]
        pub(crate) fn sign_mask(self) -> u32 {
            // SAFETY: SSE is in the x86-64 baseline.
            (unsafe { _mm_movemask_ps(self.0) }) as u32
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod imp {
    /// Four f32 lanes.
    #[derive(Clone, Copy, Debug)]
    #[repr(C, align(16))]
    pub(crate) struct F32x4([f32; 4]);

    impl F32x4 {
        #[inline(always)]
        pub(crate) fn splat(x: f32) -> Self {
            Self([x; 4])
        }
        #[inline(always)]
        pub(crate) fn from_array(a: [f32; 4]) -> Self {
            Self(a)
        }
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 4] {
            self.0
        }
        #[inline(always)]
        fn zip(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
            Self(core::array::from_fn(|i| f(self.0[i], o.0[i])))
        }
        #[inline(always)]
        fn mask(self, o: Self, f: impl Fn(f32, f32) -> bool) -> u32 {
            (0..4).fold(0, |m, i| m | (u32::from(f(self.0[i], o.0[i])) << i))
        }
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            self.zip(o, |a, b| a + b)
        }
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            self.zip(o, |a, b| a - b)
        }
        #[inline(always)]
        pub(crate) fn mul(self, o: Self) -> Self {
            self.zip(o, |a, b| a * b)
        }
        #[inline(always)]
        pub(crate) fn div(self, o: Self) -> Self {
            self.zip(o, |a, b| a / b)
        }
        #[inline(always)]
        pub(crate) fn max(self, o: Self) -> Self {
            self.zip(o, |a, b| if a > b { a } else { b })
        }
        #[inline(always)]
        pub(crate) fn min(self, o: Self) -> Self {
            self.zip(o, |a, b| if a < b { a } else { b })
        }
        #[inline(always)]
        pub(crate) fn le_mask(self, o: Self) -> u32 {
            self.mask(o, |a, b| a <= b)
        }
        #[inline(always)]
        pub(crate) fn lt_mask(self, o: Self) -> u32 {
            self.mask(o, |a, b| a < b)
        }
        #[inline(always)]
        pub(crate) fn eq_mask(self, o: Self) -> u32 {
            self.mask(o, |a, b| a == b)
        }
        #[inline(always)]
        pub(crate) fn or_bits(self, o: Self) -> Self {
            self.zip(o, |a, b| f32::from_bits(a.to_bits() | b.to_bits()))
        }
        #[inline(always)]
        pub(crate) fn and_bits(self, o: Self) -> Self {
            self.zip(o, |a, b| f32::from_bits(a.to_bits() & b.to_bits()))
        }
        #[inline(always)]
        pub(crate) fn sign_mask(self) -> u32 {
            self.mask(self, |a, _| a.is_sign_negative())
        }
    }
}

pub(crate) use imp::F32x4;

/// Eight f32 lanes on AVX, for the AVX2 and AVX-512 kernels ([`crate::Isa`]):
/// a node's eight child boxes in one pass. The methods are `unsafe`: they
/// may run only where the CPU has AVX, i.e. inside the kernels compiled
/// with it (`#[target_feature]`), which are entered only after run-time
/// detection; they are always inlined there, so the intrinsics compile to
/// AVX instructions in place. Same NaN rule as [`F32x4`].
#[cfg(target_arch = "x86_64")]
mod avx {
    use core::arch::x86_64::*;

    #[derive(Clone, Copy, Debug)]
    #[repr(transparent)]
    pub(crate) struct F32x8(__m256);

    // SAFETY (every method): the caller guarantees the CPU has AVX.
    impl F32x8 {
        #[inline(always)]
        pub(crate) fn from_groups(g: [[f32; 4]; 2]) -> Self {
            Self(bytemuck::cast(g))
        }
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f32; 8] {
            bytemuck::cast(self.0)
        }
        #[inline(always)]
        pub(crate) fn from_array(a: [f32; 8]) -> Self {
            Self(bytemuck::cast(a))
        }
        /// `b` in the lanes where `mask`'s sign bit is set, else `self`.
        #[inline(always)]
        pub(crate) unsafe fn blend(self, b: Self, mask: Self) -> Self {
            Self(unsafe { _mm256_blendv_ps(self.0, b.0, mask.0) })
        }
        /// `lo` in lanes 0–3, `hi` in lanes 4–7.
        #[inline(always)]
        pub(crate) fn from_halves(lo: [f32; 4], hi: [f32; 4]) -> Self {
            Self(bytemuck::cast([lo, hi]))
        }
        /// `self` if `self > o`, else `o` (NaN in either gives `o`).
        #[inline(always)]
        pub(crate) unsafe fn max(self, o: Self) -> Self {
            Self(unsafe { _mm256_max_ps(self.0, o.0) })
        }
        /// `self` if `self < o`, else `o` (NaN in either gives `o`).
        #[inline(always)]
        pub(crate) unsafe fn min(self, o: Self) -> Self {
            Self(unsafe { _mm256_min_ps(self.0, o.0) })
        }
        /// All ones in the lanes where `self <= o` (none for NaN), else 0.
        #[inline(always)]
        pub(crate) unsafe fn le(self, o: Self) -> Self {
            Self(unsafe { _mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0) })
        }
        /// `self·a + b` with one rounding (the CPU must also have FMA).
        #[inline(always)]
        pub(crate) unsafe fn mul_add(self, a: Self, b: Self) -> Self {
            Self(unsafe { _mm256_fmadd_ps(self.0, a.0, b.0) })
        }
        /// Bitwise or.
        #[inline(always)]
        pub(crate) unsafe fn or(self, o: Self) -> Self {
            Self(unsafe { _mm256_or_ps(self.0, o.0) })
        }
        /// Bitwise and.
        #[inline(always)]
        pub(crate) unsafe fn and(self, o: Self) -> Self {
            Self(unsafe { _mm256_and_ps(self.0, o.0) })
        }
        /// Bitwise exclusive or.
        #[inline(always)]
        pub(crate) unsafe fn xor(self, o: Self) -> Self {
            Self(unsafe { _mm256_xor_ps(self.0, o.0) })
        }
        /// Every lane holding the bits of `bits` (not a float value: for
        /// [`F32x8::and`] / [`F32x8::or`] and [`F32x8::to_bits`]).
        #[inline(always)]
        pub(crate) unsafe fn splat_bits(bits: u32) -> Self {
            Self(unsafe { _mm256_castsi256_ps(_mm256_set1_epi32(bits as i32)) })
        }
        /// The lanes' bits.
        #[inline(always)]
        pub(crate) fn to_bits(self) -> [u32; 8] {
            bytemuck::cast(self.0)
        }
        /// The lanes' bits compared as signed 32-bit integers (AVX2): the
        /// larger of each pair. For floats with the sign bit clear (`+0`
        /// to `+∞`, no NaN) that is the larger float; every float with the
        /// sign bit set (`−0`, negatives) is below all of those. One cycle
        /// where the float maximum takes four.
        #[inline(always)]
        pub(crate) unsafe fn max_bits(self, o: Self) -> Self {
            Self(unsafe {
                _mm256_castsi256_ps(_mm256_max_epi32(
                    _mm256_castps_si256(self.0),
                    _mm256_castps_si256(o.0),
                ))
            })
        }
        /// [`F32x8::max_bits`]'s minimum.
        #[inline(always)]
        pub(crate) unsafe fn min_bits(self, o: Self) -> Self {
            Self(unsafe {
                _mm256_castsi256_ps(_mm256_min_epi32(
                    _mm256_castps_si256(self.0),
                    _mm256_castps_si256(o.0),
                ))
            })
        }
        /// All ones in the lanes where `self`'s bits are greater than
        /// `o`'s as signed 32-bit integers (AVX2), else 0.
        #[inline(always)]
        pub(crate) unsafe fn gt_bits(self, o: Self) -> Self {
            Self(unsafe {
                _mm256_castsi256_ps(_mm256_cmpgt_epi32(
                    _mm256_castps_si256(self.0),
                    _mm256_castps_si256(o.0),
                ))
            })
        }
        /// Bit `i` set where lane `i`'s sign bit is.
        #[inline(always)]
        pub(crate) unsafe fn sign_mask(self) -> u32 {
            (unsafe { _mm256_movemask_ps(self.0) }) as u32
        }
    }

    // The arithmetic shared with `F32x4` (SAFETY, every method: as above).
    impl super::Lanes for F32x8 {
        type Array = [f32; 8];
        const ALL: u32 = 0xff;
        #[inline(always)]
        unsafe fn splat(x: f32) -> Self {
            Self(unsafe { _mm256_set1_ps(x) })
        }
        #[inline(always)]
        unsafe fn add(self, o: Self) -> Self {
            Self(unsafe { _mm256_add_ps(self.0, o.0) })
        }
        #[inline(always)]
        unsafe fn sub(self, o: Self) -> Self {
            Self(unsafe { _mm256_sub_ps(self.0, o.0) })
        }
        #[inline(always)]
        unsafe fn mul(self, o: Self) -> Self {
            Self(unsafe { _mm256_mul_ps(self.0, o.0) })
        }
        #[inline(always)]
        unsafe fn div(self, o: Self) -> Self {
            Self(unsafe { _mm256_div_ps(self.0, o.0) })
        }
        #[inline(always)]
        unsafe fn le_mask(self, o: Self) -> u32 {
            (unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, o.0)) }) as u32
        }
        #[inline(always)]
        unsafe fn lt_mask(self, o: Self) -> u32 {
            (unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(self.0, o.0)) }) as u32
        }
        #[inline(always)]
        unsafe fn eq_mask(self, o: Self) -> u32 {
            (unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(self.0, o.0)) }) as u32
        }
        #[inline(always)]
        unsafe fn or_bits(self, o: Self) -> Self {
            unsafe { F32x8::or(self, o) }
        }
        #[inline(always)]
        unsafe fn and_bits(self, o: Self) -> Self {
            unsafe { F32x8::and(self, o) }
        }
        #[inline(always)]
        unsafe fn sign_mask(self) -> u32 {
            unsafe { F32x8::sign_mask(self) }
        }
        #[inline(always)]
        fn to_lanes(self) -> [f32; 8] {
            self.to_array()
        }
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::F32x8;

/// The lane arithmetic the triangle test is written in, four lanes
/// ([`F32x4`]) or eight ([`F32x8`]): one generic test, the same IEEE
/// operations per lane at either width.
///
/// The methods are `unsafe` because [`F32x8`]'s need AVX: call them only
/// where the lane type's own methods may run (for [`F32x4`], anywhere).
pub(crate) trait Lanes: Copy {
    /// The lanes as an array.
    type Array: core::ops::Index<usize, Output = f32>;
    /// The mask with a bit for every lane.
    const ALL: u32;
    unsafe fn splat(x: f32) -> Self;
    unsafe fn add(self, o: Self) -> Self;
    unsafe fn sub(self, o: Self) -> Self;
    unsafe fn mul(self, o: Self) -> Self;
    unsafe fn div(self, o: Self) -> Self;
    unsafe fn le_mask(self, o: Self) -> u32;
    unsafe fn lt_mask(self, o: Self) -> u32;
    unsafe fn eq_mask(self, o: Self) -> u32;
    /// Bitwise or, and bitwise and, of the lanes.
    unsafe fn or_bits(self, o: Self) -> Self;
    /// See `or_bits`.
    unsafe fn and_bits(self, o: Self) -> Self;
    /// Bit `i` set where lane `i`'s sign bit is.
    unsafe fn sign_mask(self) -> u32;
    fn to_lanes(self) -> Self::Array;
}

/// [`F32x4`]'s own (safe) methods.
impl Lanes for F32x4 {
    type Array = [f32; 4];
    const ALL: u32 = 0xf;
    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        F32x4::splat(x)
    }
    #[inline(always)]
    unsafe fn add(self, o: Self) -> Self {
        F32x4::add(self, o)
    }
    #[inline(always)]
    unsafe fn sub(self, o: Self) -> Self {
        F32x4::sub(self, o)
    }
    #[inline(always)]
    unsafe fn mul(self, o: Self) -> Self {
        F32x4::mul(self, o)
    }
    #[inline(always)]
    unsafe fn div(self, o: Self) -> Self {
        F32x4::div(self, o)
    }
    #[inline(always)]
    unsafe fn le_mask(self, o: Self) -> u32 {
        F32x4::le_mask(self, o)
    }
    #[inline(always)]
    unsafe fn lt_mask(self, o: Self) -> u32 {
        F32x4::lt_mask(self, o)
    }
    #[inline(always)]
    unsafe fn eq_mask(self, o: Self) -> u32 {
        F32x4::eq_mask(self, o)
    }
    #[inline(always)]
    unsafe fn or_bits(self, o: Self) -> Self {
        F32x4::or_bits(self, o)
    }
    #[inline(always)]
    unsafe fn and_bits(self, o: Self) -> Self {
        F32x4::and_bits(self, o)
    }
    #[inline(always)]
    unsafe fn sign_mask(self) -> u32 {
        F32x4::sign_mask(self)
    }
    #[inline(always)]
    fn to_lanes(self) -> [f32; 4] {
        self.to_array()
    }
}

/// Hints the CPU to start loading the cache line that holds `r`'s first
/// byte.
#[inline(always)]
pub(crate) fn prefetch_line<T>(r: &T) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: SSE is in the x86-64 baseline; a prefetch never faults.
        unsafe { _mm_prefetch::<{ _MM_HINT_T0 }>((r as *const T).cast::<i8>()) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = r;
}

/// Hints the CPU to start loading the cache lines of `bytes` bytes from
/// `r` on (every line they touch, whatever `r`'s alignment).
#[inline(always)]
pub(crate) fn prefetch_bytes<T>(r: &T, bytes: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        let p = (r as *const T).cast::<i8>();
        let mut off = 0;
        while off < bytes {
            // SAFETY: SSE is in the x86-64 baseline; a prefetch never
            // faults, whatever the address (`wrapping_add` keeps the
            // pointer arithmetic defined even past the object).
            unsafe { _mm_prefetch::<{ _MM_HINT_T0 }>(p.wrapping_add(off)) };
            off += 64;
        }
        // The last byte's line, when `r` is not line-aligned.
        // SAFETY: as above.
        unsafe { _mm_prefetch::<{ _MM_HINT_T0 }>(p.wrapping_add(bytes.max(1) - 1)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (r, bytes);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_rule_and_masks() {
        let a = F32x4::from_array([1.0, f32::NAN, 3.0, -0.0]);
        let b = F32x4::from_array([2.0, 5.0, f32::NAN, 0.0]);
        let mx = a.max(b).to_array();
        assert_eq!(mx[0], 2.0);
        assert_eq!(mx[1], 5.0);
        assert!(mx[2].is_nan());
        assert_eq!(a.min(b).to_array()[1], 5.0);
        assert_eq!(a.le_mask(b), 0b1001);
        assert_eq!(a.lt_mask(b), 0b0001);
        assert_eq!(a.eq_mask(b), 0b1000);
        let s = a.add(b).mul(F32x4::splat(2.0)).sub(b).div(F32x4::splat(1.0)).to_array();
        assert_eq!(s[0], 4.0);
        // Sign bits: `−0` has one, `+0` and the (positive) NaN do not.
        let c = F32x4::from_array([-1.0, 2.0, -0.0, 0.0]);
        let d = F32x4::from_array([-3.0, -4.0, 5.0, -0.0]);
        assert_eq!(a.sign_mask(), 0b1000);
        assert_eq!(c.or_bits(d).sign_mask(), 0b1111);
        assert_eq!(c.and_bits(d).sign_mask(), 0b0001);
        assert_eq!(c.and_bits(F32x4::splat(f32::from_bits(0x7fff_ffff))).to_array()[0], 1.0);
    }
}
