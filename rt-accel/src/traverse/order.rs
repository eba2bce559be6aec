//! Which children are visited next: the stack pushes, nearest child
//! first, sorted without a branch on the AVX kernels.

use core::mem::MaybeUninit;

use crate::{
    node::{ChildRef, Node, WIDTH},
    prim::BestHit,
};

use super::query::STACK_SIZE;

/// Pushes `(r, t)` onto a closest-hit traversal's stack of height `sp`,
/// unchecked: the stack is never full there. Every entry on it is a child
/// of an inner node on the path from the root to the subtree being
/// visited, at most `WIDTH − 1` per node (the visited child is not
/// pushed), and that path holds at most [`MAX_DEPTH`] inner nodes
/// (builders and `validate` reject deeper trees; `BvhRef`'s invariant). So
/// the height stays at most `(WIDTH − 1) · MAX_DEPTH < STACK_SIZE`.
#[inline(always)]
pub(super) fn push(
    refs: &mut [MaybeUninit<ChildRef>; STACK_SIZE],
    ts: &mut [MaybeUninit<f32>; STACK_SIZE],
    sp: &mut usize,
    r: ChildRef,
    t: f32,
) {
    debug_assert!(*sp < STACK_SIZE);
    // SAFETY: `sp < STACK_SIZE`, by the bound above.
    unsafe {
        refs.get_unchecked_mut(*sp).write(r);
        ts.get_unchecked_mut(*sp).write(t);
    }
    *sp += 1;
}

/// Where a closest-hit traversal stands between two steps: the subtree to
/// visit next, the stack height and the best hit so far.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Walk {
    pub(crate) cur: ChildRef,
    pub(crate) sp: usize,
    pub(crate) best: BestHit,
}

/// Writes the children of `node` named by `mask` (not 0) to
/// `stack[sp..]` in slot order. The entry for the last may be written or
/// not (the caller visits it next); with `AVX` entries up to
/// `sp + WIDTH` are (garbage past the children).
#[inline(always)]
pub(super) fn push_children<const AVX: bool>(
    stack: &mut [MaybeUninit<ChildRef>; STACK_SIZE],
    sp: usize,
    node: &Node,
    mask: u32,
) {
    // Each level leaves at most `WIDTH − 1` entries and `validate` bounds
    // the depth by `MAX_DEPTH`, so a node is reached with `sp ≤ (WIDTH −
    // 1)·(MAX_DEPTH − 1)` and the second test always holds.
    #[cfg(target_arch = "x86_64")]
    if AVX && sp + WIDTH <= STACK_SIZE {
        // SAFETY: `AVX` kernels run only where the CPU has AVX2 (see
        // `box_test`); the `WIDTH` entries from `sp` lie in the stack.
        unsafe { push_hit_children(stack.as_mut_ptr().add(sp), node, mask) };
        return;
    }
    let (mut m, mut k) = (mask, sp);
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        stack[k].write(node.children[i]);
        k += 1;
    }
}

/// For each 8-bit child mask, the slots of its set bits in order, padded
/// with slot 0: the permutation that packs a node's hit children together.
#[cfg(target_arch = "x86_64")]
static COMPRESS: [[u32; WIDTH]; 1 << WIDTH] = compress_table(false);

/// The packing permutations for every 8-bit mask: the slots of its set
/// bits in ascending order (`descending`: from the highest down), padded
/// with slot 0.
#[cfg(target_arch = "x86_64")]
pub(crate) const fn compress_table(descending: bool) -> [[u32; WIDTH]; 1 << WIDTH] {
    let mut t = [[0u32; WIDTH]; 1 << WIDTH];
    let mut m = 0;
    while m < 1 << WIDTH {
        let (mut k, mut j) = (0, 0);
        while j < WIDTH {
            let i = if descending { WIDTH - 1 - j } else { j };
            if m & (1 << i) != 0 {
                t[m][k] = i as u32;
                k += 1;
            }
            j += 1;
        }
        m += 1;
    }
    t
}

/// Writes the children of `node` named by `mask` to `out[0..popcount]`
/// in slot order, with one 8-lane permute and store and no branch (the
/// loop over set bits mispredicted its exit at every node). All `WIDTH`
/// entries of `out` are written; those past the count are garbage.
///
/// # Safety
/// The CPU must have AVX2, and `out` must be valid for `WIDTH` writes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn push_hit_children(out: *mut MaybeUninit<ChildRef>, node: &Node, mask: u32) {
    use core::arch::x86_64::{
        __m256i, _mm256_loadu_si256, _mm256_permutevar8x32_epi32, _mm256_storeu_si256,
    };
    debug_assert!(mask < 1 << WIDTH);
    // SAFETY: the caller guarantees AVX2 and `out`; `node.children` is
    // `WIDTH` u32s (32 bytes, read unaligned); `mask & 0xff` indexes the
    // table.
    unsafe {
        let kids = _mm256_loadu_si256(node.children.as_ptr().cast::<__m256i>());
        let perm = COMPRESS.get_unchecked((mask & 0xff) as usize);
        let perm = _mm256_loadu_si256(perm.as_ptr().cast::<__m256i>());
        _mm256_storeu_si256(out.cast::<__m256i>(), _mm256_permutevar8x32_epi32(kids, perm));
    }
}

/// Writes the children of `node` named by `mask` (three or more) to
/// `refs[0..k − 1]` and their entry distances `tnear` to `ts[0..k − 1]`,
/// farthest first, and returns the nearest, which is not pushed: what the
/// closest-hit step's insertion sort does, without its branches (which
/// mispredict for rays of random direction). The lanes' keys are the
/// distances' bits (every fused entry distance is `+0` or positive, so they
/// order as the floats) with the slot in the low three bits, which breaks
/// ties and lets the sorted keys name their slots; the lanes missed sort
/// last as `i32::MIN`. Batcher's odd–even merge sort (19 comparators in
/// six layers), and the nearest found by a minimum over the lanes beside
/// it, so the next node's address does not wait for the sort. All `WIDTH`
/// entries of both outputs are written; those past `k − 1` are garbage.
/// Keys ignore the low three bits of the distances, so two children
/// within 8 ulps may be visited in either order: the traversal's result
/// does not depend on the order, and the distances pushed are exact.
///
/// # Safety
/// The CPU must have AVX2; `refs` and `ts` must be valid for `WIDTH`
/// writes; every entry distance named by `mask` must have its sign bit
/// clear (the fused test's).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(super) unsafe fn push_sorted(
    refs: *mut MaybeUninit<ChildRef>,
    ts: *mut MaybeUninit<f32>,
    node: &Node,
    mask: u32,
    tnear: &[f32; WIDTH],
) -> ChildRef {
    use core::arch::x86_64::*;
    /// One layer of comparators `(i, j)`, `i < j`: lane `i` takes the
    /// larger key and `j` the smaller; `w` is the keys permuted so each
    /// lane sees its partner, `MAX` has the bits of the lanes `i`.
    #[inline(always)]
    unsafe fn layer<const MAX: i32>(v: __m256i, w: __m256i) -> __m256i {
        // SAFETY: the caller guarantees AVX2.
        unsafe { _mm256_blend_epi32::<MAX>(_mm256_min_epi32(v, w), _mm256_max_epi32(v, w)) }
    }
    // SAFETY: the caller guarantees AVX2 and the outputs; `tnear` and
    // `node.children` are `WIDTH` 32-bit values (32 bytes, read unaligned).
    unsafe {
        let t = _mm256_loadu_si256(tnear.as_ptr().cast::<__m256i>());
        let slot = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let bit = _mm256_sllv_epi32(_mm256_set1_epi32(1), slot);
        let hit = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bit), bit);
        let key = _mm256_or_si256(_mm256_and_si256(t, _mm256_set1_epi32(!7)), slot);
        // The nearest: the smallest key of the lanes entered.
        let m = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MAX), key, hit);
        let m = _mm256_min_epi32(m, _mm256_permute2x128_si256::<1>(m, m));
        let m = _mm256_min_epi32(m, _mm256_shuffle_epi32::<0b01_00_11_10>(m));
        let m = _mm256_min_epi32(m, _mm256_shuffle_epi32::<0b10_11_00_01>(m));
        let nearest = (_mm256_cvtsi256_si32(m) & 7) as usize;
        // The keys in descending order.
        let v = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MIN), key, hit);
        // (0,1) (2,3) (4,5) (6,7)
        let v = layer::<0b0101_0101>(v, _mm256_shuffle_epi32::<0b10_11_00_01>(v));
        // (0,2) (1,3) (4,6) (5,7)
        let v = layer::<0b0011_0011>(v, _mm256_shuffle_epi32::<0b01_00_11_10>(v));
        // (1,2) (5,6)
        let v = layer::<0b0010_0010>(v, _mm256_shuffle_epi32::<0b11_01_10_00>(v));
        // (0,4) (1,5) (2,6) (3,7)
        let v = layer::<0b0000_1111>(v, _mm256_permute2x128_si256::<1>(v, v));
        // (2,4) (3,5)
        let v = layer::<0b0000_1100>(v, _mm256_permute4x64_epi64::<0b11_01_10_00>(v));
        // (1,2) (3,4) (5,6)
        let w = _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 1, 4, 3, 6, 5, 7));
        let v = layer::<0b0010_1010>(v, w);
        let order = _mm256_and_si256(v, _mm256_set1_epi32(7));
        let kids = _mm256_loadu_si256(node.children.as_ptr().cast::<__m256i>());
        _mm256_storeu_si256(refs.cast::<__m256i>(), _mm256_permutevar8x32_epi32(kids, order));
        _mm256_storeu_si256(ts.cast::<__m256i>(), _mm256_permutevar8x32_epi32(t, order));
        *node.children.get_unchecked(nearest)
    }
}
