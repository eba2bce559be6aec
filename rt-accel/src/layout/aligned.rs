//! Byte buffers aligned for zero-copy loading.

use alloc::vec::Vec;
use core::{fmt, ops::Deref};

/// Alignment of [`AlignedBytes`]: a cache line, which covers the node and
/// item types (`align_of::<Node>()` is 16).
pub const BYTES_ALIGN: usize = 64;

#[derive(Clone, Copy, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(64))]
struct Line([u8; BYTES_ALIGN]);

/// Bytes whose first byte sits on a [`BYTES_ALIGN`]-byte boundary, as
/// [`BvhRef::from_bytes`](crate::BvhRef::from_bytes) needs to view a
/// serialized BVH without copying it. Dereferences to `[u8]`.
///
/// A plain `Vec<u8>` promises only 1-byte alignment: viewing one may work
/// on one allocator and be [`LoadError::Misaligned`](crate::LoadError::Misaligned)
/// on another. Write with [`Bvh::to_aligned_bytes`](crate::Bvh::to_aligned_bytes),
/// or copy bytes read from elsewhere with [`AlignedBytes::copy_from`].
///
/// ```
/// use rt_accel::{AlignedBytes, BuildParams, BvhRef, TriPacket, build_triangles};
/// use rt_core::{Ray, glam::Vec3};
///
/// let positions = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::Y];
/// let bvh = build_triangles(&positions, &[[0, 1, 2]], &BuildParams::medium()).unwrap();
/// let stored: Vec<u8> = bvh.to_bytes(); // e.g. written to a file and read back
/// let bytes = AlignedBytes::copy_from(&stored);
/// let view = BvhRef::<TriPacket>::from_bytes(&bytes).unwrap(); // no copy of the tree
/// assert_eq!(view.closest_hit(&Ray::new(Vec3::Z, Vec3::NEG_Z)).unwrap().t, 1.0);
/// ```
#[derive(Clone, Default, PartialEq, Eq)]
pub struct AlignedBytes {
    lines: Vec<Line>,
    len: usize,
}

impl AlignedBytes {
    /// An aligned copy of `bytes`.
    #[must_use]
    pub fn copy_from(bytes: &[u8]) -> Self {
        // In memory advised for large pages, as an owned `Bvh`'s arrays.
        let mut lines = crate::pages::large_zeroed(bytes.len().div_ceil(BYTES_ALIGN));
        bytemuck::cast_slice_mut::<Line, u8>(&mut lines)[..bytes.len()].copy_from_slice(bytes);
        Self { lines, len: bytes.len() }
    }

    /// The bytes.
    #[must_use]
    pub fn as_bytes(&self) -> &[u8] {
        &bytemuck::cast_slice(&self.lines)[..self.len]
    }
}

impl Deref for AlignedBytes {
    type Target = [u8];

    fn deref(&self) -> &[u8] {
        self.as_bytes()
    }
}

impl AsRef<[u8]> for AlignedBytes {
    fn as_ref(&self) -> &[u8] {
        self.as_bytes()
    }
}

impl fmt::Debug for AlignedBytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("AlignedBytes").field("len", &self.len).finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copies_are_aligned_and_exact() {
        for n in [0, 1, 63, 64, 65, 1000] {
            let src: Vec<u8> = (0..n).map(|i| (i * 7 + 3) as u8).collect();
            let a = AlignedBytes::copy_from(&src);
            assert_eq!(&*a, &src[..]);
            assert_eq!(a.as_ptr() as usize % BYTES_ALIGN, 0, "{n} bytes");
        }
    }
}
