//! Closest-hit and occlusion traversal of a borrowed BVH: no std, no
//! allocation, a fixed stack. The queries and their step loops
//! ([`query`]), the node tests ([`node_test`]) and child order
//! ([`order`]); a ray's precomputed constants ([`ray_ctx`]); eight-ray
//! packets ([`packet`]) and streams of rays sorted into coherent groups
//! ([`stream`]); the SIMD lanes ([`simd`]) and the instruction set picked
//! at run time ([`isa`]).

pub(crate) mod isa;
mod node_test;
mod order;
pub(crate) mod packet;
mod query;
pub(crate) mod ray_ctx;
pub(crate) mod simd;
pub(crate) mod stream;

#[cfg(all(test, target_arch = "x86_64"))]
pub(crate) use node_test::box_lanes_fused;
pub(crate) use node_test::box_test;
#[cfg(target_arch = "x86_64")]
pub(crate) use node_test::{box_lanes_avx, fused_lanes, fused_rows};
pub(crate) use order::Walk;
#[cfg(target_arch = "x86_64")]
pub(crate) use order::compress_table;
pub(crate) use query::fits_fused;
pub use query::{BvhRef, MAX_DEPTH, STACK_SIZE, TraversalStack, TraversalStats};

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use core::mem::MaybeUninit;

    use super::order::push_sorted;
    use crate::node::{ChildRef, Node, WIDTH};
    use crate::{Isa, ray_ctx::tests::Bits};

    /// The branch-free sorted push: every mask of three or more children,
    /// distances drawn with ties (equal, and within the 8 ulps its keys
    /// ignore) and zeros; each child but the nearest pushed once, with its
    /// own distance, by descending key.
    #[test]
    fn sorted_push_pushes_every_child_but_the_nearest_farthest_first() {
        if !Isa::Avx2.is_available() {
            return;
        }
        let mut g = Bits(0x51ed_270b_2a3f_6c49);
        let mut node = Node::EMPTY;
        for slot in 0..WIDTH {
            node.children[slot] = ChildRef::inner(slot as u32 + 1);
        }
        for mask in (0u32..1 << WIDTH).filter(|m| m.count_ones() >= 3) {
            for _ in 0..64 {
                let base = g.unit() * 4.0;
                let tnear: [f32; WIDTH] = core::array::from_fn(|_| match g.next() % 4 {
                    0 => 0.0,
                    1 => base,
                    2 => f32::from_bits(base.to_bits() + (g.next() % 8) as u32),
                    _ => g.unit() * 4.0,
                });
                let mut refs = [MaybeUninit::<ChildRef>::uninit(); WIDTH];
                let mut ts = [MaybeUninit::<f32>::uninit(); WIDTH];
                // SAFETY: the CPU has AVX2 (checked above); both outputs
                // hold `WIDTH` entries; the distances are non-negative.
                let near =
                    unsafe { push_sorted(refs.as_mut_ptr(), ts.as_mut_ptr(), &node, mask, &tnear) };
                let k = mask.count_ones() as usize;
                // SAFETY: all `WIDTH` entries are written.
                let (refs, ts) =
                    unsafe { (refs.map(|r| r.assume_init()), ts.map(|t| t.assume_init())) };
                let slot = |r: ChildRef| r.index() - 1;
                // A child's key: its distance's bits above the low three,
                // then its slot.
                let key = |s: usize| tnear[s].to_bits() & !7 | s as u32;
                // The nearest is the child entered with the least key.
                let least = (0..WIDTH).filter(|&i| mask >> i & 1 == 1).min_by_key(|&i| key(i));
                assert_eq!(Some(slot(near)), least, "{mask:#b} {tnear:?}");
                // The others once each, with their own distances, by
                // descending key.
                let mut seen = 1u32 << slot(near);
                for e in 0..k - 1 {
                    let s = slot(refs[e]);
                    assert!(mask >> s & 1 == 1 && seen >> s & 1 == 0, "{mask:#b} {refs:?}");
                    seen |= 1 << s;
                    assert_eq!(ts[e].to_bits(), tnear[s].to_bits());
                    let next = if e + 1 < k - 1 { slot(refs[e + 1]) } else { slot(near) };
                    assert!(key(s) > key(next), "{mask:#b} {tnear:?} {refs:?}");
                }
                assert_eq!(seen, mask);
            }
        }
    }
}
