//! Top-down binned SAH building (Wald 2007, "On fast construction of
//! SAH-based bounding volume hierarchies", IEEE Symposium on Interactive
//! Ray Tracing): the binary tree that [`crate::build`]'s 8-wide collapse
//! starts from, for [`crate::BuildQuality::BinnedSah`].
//!
//! A node's primitives are sorted by box centroid into [`BINS`] equal bins
//! along each axis, and the node is split between the two bins that give
//! the least surface area heuristic,
//!
//! ```text
//! cost(split) = ⌈n_left / k⌉ · A(left) + ⌈n_right / k⌉ · A(right),
//! ```
//!
//! with `A` the surface area of the side's box, `n` its primitive count
//! and `k` the primitives a leaf item holds (4 for triangle packets, as
//! Embree counts its Triangle4 blocks; 1 for spheres and capsules): the
//! leaf items the side would need (the node's own area is the same for
//! every split, so it drops out). Counting items, not triangles, favours
//! splits into full packets: fewer packets and nodes for a ray to test.
//! Nodes of at most `leaf` primitives become leaves; the collapse then
//! merges subtrees into the final leaves by the same heuristic.
//!
//! **Invariants.** Every primitive is in exactly one leaf; no leaf holds
//! more than `leaf` primitives; no leaf is deeper than `max_depth` (a
//! node whose depth plus `⌈log₂ n⌉` reaches it is split at its median
//! instead, which halves `n` and so keeps the sum from growing: without
//! that, centroids spread over many orders of magnitude put all but one
//! primitive in the first bin at every level). Areas and costs are f64
//! from the f32 corners, so boxes whose extent overflows f32 still compare.
//!
//! **Threads.** The two sides of a split are independent, so near the
//! root the left side is built on a thread of its own (scoped threads,
//! down to sides of 16 384 primitives, as many as the process may use):
//! the same tree on any number of threads, node for node.

use alloc::{vec, vec::Vec};

use glam::Vec3A;
use obvhs::{
    aabb::Aabb as OAabb,
    bvh2::{Bvh2, node::Bvh2Node},
};

/// Bins per axis. Fewer bins gave costlier trees on the report's scenes,
/// more bins none cheaper.
const BINS: usize = 32;

/// Half the surface area of `b`, in f64 (so finite for any finite box;
/// the 8-wide collapse weighs its choices by the same measure).
pub(crate) fn half_area(b: &OAabb) -> f64 {
    let e = b.max.as_dvec3() - b.min.as_dvec3();
    e.x * e.y + e.y * e.z + e.z * e.x
}

/// The centroid of `b`, halved before the sum so that it cannot overflow.
fn centroid(b: &OAabb) -> Vec3A {
    b.min * 0.5 + b.max * 0.5
}

/// One bin: the box and number of its primitives.
#[derive(Clone, Copy)]
struct Bin {
    bounds: OAabb,
    count: u32,
}

impl Bin {
    const EMPTY: Self = Self { bounds: OAabb::INVALID, count: 0 };
}

/// The binning of one node: centroid `c` falls into bin
/// `⌊(c − lo) · scale⌋` per axis, clamped into `0..BINS` (a NaN or
/// negative product to 0, an infinite one to the last bin; an axis
/// without extent has `scale` 0, so all in bin 0).
#[derive(Clone, Copy)]
struct Binning {
    lo: Vec3A,
    scale: Vec3A,
}

impl Binning {
    fn new(centroids: &OAabb) -> Self {
        let ext = centroids.max - centroids.min;
        // Just under `BINS`, so the largest centroid lands in the last bin.
        let s = Vec3A::splat(BINS as f32 * 0.999_99) / ext;
        let scale = Vec3A::select(ext.cmpgt(Vec3A::ZERO) & s.is_finite_mask(), s, Vec3A::ZERO);
        Self { lo: centroids.min, scale }
    }

    fn bin(&self, c: Vec3A, axis: usize) -> usize {
        (((c[axis] - self.lo[axis]) * self.scale[axis]) as usize).min(BINS - 1)
    }
}

/// The split of least cost for the primitives `ids`: `(axis, first bin
/// of the right side)`, or `None` where every axis has all centroids in
/// one bin (or the costs are not comparable).
fn best_split(
    ids: &[u32],
    boxes: &[OAabb],
    cents: &[Vec3A],
    binning: &Binning,
    block: u32,
) -> Option<(usize, usize)> {
    let items = |n: u32| f64::from(n.div_ceil(block));
    let mut bins = [[Bin::EMPTY; BINS]; 3];
    for &i in ids {
        let (b, c) = (&boxes[i as usize], cents[i as usize]);
        for (axis, row) in bins.iter_mut().enumerate() {
            let bin = &mut row[binning.bin(c, axis)];
            bin.bounds = bin.bounds.union(b);
            bin.count += 1;
        }
    }
    let mut best: Option<(f64, usize, usize)> = None;
    for (axis, row) in bins.iter().enumerate() {
        // `right[k]`: the cost of bins `k..` as one side.
        let mut right = [0.0f64; BINS];
        let (mut b, mut n) = (OAabb::INVALID, 0u32);
        for k in (1..BINS).rev() {
            b = b.union(&row[k].bounds);
            n += row[k].count;
            right[k] = if n == 0 { f64::NAN } else { half_area(&b) * items(n) };
        }
        let (mut b, mut n) = (OAabb::INVALID, 0u32);
        for k in 1..BINS {
            b = b.union(&row[k - 1].bounds);
            n += row[k - 1].count;
            // Both sides must hold a primitive (NaN `right` otherwise).
            let cost = half_area(&b) * items(n) + right[k];
            if n > 0 && best.is_none_or(|(c, ..)| cost < c) && !cost.is_nan() {
                best = Some((cost, axis, k));
            }
        }
    }
    best.map(|(_, axis, k)| (axis, k))
}

/// `⌈log₂ n⌉`.
fn ceil_log2(n: usize) -> usize {
    n.next_power_of_two().trailing_zeros() as usize
}

/// What the builder reads: the primitives' boxes and centroids and the
/// settings of [`build_bvh2`].
struct Input<'a> {
    boxes: &'a [OAabb],
    cents: &'a [Vec3A],
    leaf: usize,
    block: u32,
    max_depth: usize,
}

impl Input<'_> {
    /// The box of the primitives `part`, and where to split them (`None`:
    /// a leaf): `part` is reordered so that `part[..mid]` is the left side.
    fn split(&self, part: &mut [u32], depth: usize) -> (OAabb, Option<usize>) {
        let (mut bounds, mut cb) = (OAabb::INVALID, OAabb::INVALID);
        for &i in part.iter() {
            bounds = bounds.union(&self.boxes[i as usize]);
            cb.extend(self.cents[i as usize]);
        }
        let n = part.len();
        if n <= self.leaf {
            return (bounds, None);
        }
        let binning = Binning::new(&cb);
        let split = if depth + ceil_log2(n) < self.max_depth {
            best_split(part, self.boxes, self.cents, &binning, self.block)
        } else {
            None
        };
        let mid = match split {
            Some((axis, k)) => {
                // A plain in-place partition: the same on every run.
                let mut l = 0;
                for j in 0..n {
                    if binning.bin(self.cents[part[j] as usize], axis) < k {
                        part.swap(j, l);
                        l += 1;
                    }
                }
                l
            }
            None => {
                // The median along the widest centroid extent.
                let axis = (cb.max - cb.min).max_position();
                let key = |i: &u32| self.cents[*i as usize][axis];
                part.select_nth_unstable_by(n / 2, |a, b| key(a).total_cmp(&key(b)));
                n / 2
            }
        };
        (bounds, Some(mid))
    }

    /// The subtree over `part` (`ids[base..base + part.len()]`) at `depth`,
    /// its root at index 0, built on this thread.
    fn subtree(&self, part: &mut [u32], base: usize, depth: usize) -> Vec<Bvh2Node> {
        let mut nodes = vec![Bvh2Node::default()];
        // (node, first, end, depth) still to fill, depth-first.
        let mut todo = vec![(0usize, 0usize, part.len(), depth)];
        while let Some((slot, first, end, depth)) = todo.pop() {
            let (bounds, mid) = self.split(&mut part[first..end], depth);
            let Some(mid) = mid else {
                nodes[slot] = Bvh2Node::new(bounds, (end - first) as u32, (base + first) as u32);
                continue;
            };
            let kids = nodes.len();
            nodes.extend([Bvh2Node::default(); 2]);
            nodes[slot] = Bvh2Node::new(bounds, 0, kids as u32);
            todo.push((kids + 1, first + mid, end, depth + 1));
            todo.push((kids, first, first + mid, depth + 1));
        }
        nodes
    }

    /// [`Self::subtree`], the left side of each split on a thread of its
    /// own while `threads > 1` and the side is large: the same tree as on
    /// one thread (each side's splits depend on its primitives only, and
    /// the sides are joined in a fixed order).
    fn subtree_par(
        &self,
        part: &mut [u32],
        base: usize,
        depth: usize,
        threads: usize,
    ) -> Vec<Bvh2Node> {
        /// Below this many primitives a side is not worth a thread.
        const MIN_PARALLEL: usize = 1 << 14;
        if threads < 2 || part.len() < 2 * MIN_PARALLEL {
            return self.subtree(part, base, depth);
        }
        let (bounds, mid) = self.split(part, depth);
        let Some(mid) = mid else {
            return vec![Bvh2Node::new(bounds, part.len() as u32, base as u32)];
        };
        let (l, r) = part.split_at_mut(mid);
        let half = threads / 2;
        let (left, right) = std::thread::scope(|s| {
            let spawned = std::thread::Builder::new()
                .spawn_scoped(s, || self.subtree_par(l, base, depth + 1, half));
            let right = self.subtree_par(r, base + mid, depth + 1, threads - half);
            let left =
                spawned.ok().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
            (left, right)
        });
        // No thread to be had: this one builds the left side too.
        let left = left.unwrap_or_else(|| self.subtree_par(l, base, depth + 1, 1));
        // The root, the two sides' roots, then the rest of each side in
        // order. Node `j > 0` of a side goes to `rest + j − 1`; children
        // are never a side's node 0, so each pair stays adjacent.
        let nl = left.len();
        let (left_rest, right_rest) = (3, 2 + nl);
        let relocate = |n: &Bvh2Node, rest: usize| {
            let mut n = *n;
            if !n.is_leaf() {
                n.first_index = (rest + n.first_index as usize - 1) as u32;
            }
            n
        };
        let mut nodes = Vec::with_capacity(1 + nl + right.len());
        nodes.push(Bvh2Node::new(bounds, 0, 1));
        nodes.push(relocate(&left[0], left_rest));
        nodes.push(relocate(&right[0], right_rest));
        nodes.extend(left[1..].iter().map(|n| relocate(n, left_rest)));
        nodes.extend(right[1..].iter().map(|n| relocate(n, right_rest)));
        nodes
    }
}

/// The binary tree over `boxes` (finite boxes, not empty), leaves of at
/// most `leaf ≥ 1` primitives no deeper than `max_depth ≥ ⌈log₂
/// boxes.len()⌉` (the builder passes [`crate::MAX_DEPTH`]), splits costed
/// in leaf items of `block ≥ 1` primitives: see the module documentation.
/// Built on up to `threads` threads; the tree is the same for any number.
pub(crate) fn build_bvh2(
    boxes: &[OAabb],
    leaf: usize,
    block: u32,
    max_depth: usize,
    threads: usize,
) -> Bvh2 {
    debug_assert!(!boxes.is_empty() && leaf >= 1 && block >= 1);
    debug_assert!(ceil_log2(boxes.len()) <= max_depth);
    let cents: Vec<Vec3A> = boxes.iter().map(centroid).collect();
    let input = Input { boxes, cents: &cents, leaf, block, max_depth };
    let mut ids: Vec<u32> = (0..boxes.len() as u32).collect();
    let nodes = input.subtree_par(&mut ids, 0, 0, threads);
    Bvh2 { nodes, primitive_indices: ids, ..Bvh2::default() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::MAX_DEPTH;

    fn unit(x: f32) -> OAabb {
        OAabb::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x + 1.0, 1.0, 1.0))
    }

    /// Leaves in tree order: `(depth, primitives)`.
    fn leaves(b2: &Bvh2) -> Vec<(usize, Vec<u32>)> {
        let mut out = Vec::new();
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, d)) = stack.pop() {
            let node = &b2.nodes[i];
            if node.is_leaf() {
                let f = node.first_index as usize;
                out.push((d, b2.primitive_indices[f..f + node.prim_count as usize].to_vec()));
            } else {
                // Every inner box holds both children's.
                let (l, r) = (
                    &b2.nodes[node.first_index as usize],
                    &b2.nodes[node.first_index as usize + 1],
                );
                assert_eq!(node.aabb().union(l.aabb()).union(r.aabb()), *node.aabb());
                stack.extend([
                    (node.first_index as usize + 1, d + 1),
                    (node.first_index as usize, d + 1),
                ]);
            }
        }
        out
    }

    /// The number of primitives under node `i`.
    fn prims_under(b2: &Bvh2, i: usize) -> u32 {
        let node = &b2.nodes[i];
        if node.is_leaf() {
            node.prim_count
        } else {
            let f = node.first_index as usize;
            prims_under(b2, f) + prims_under(b2, f + 1)
        }
    }

    fn check_partition(b2: &Bvh2, n: usize, leaf: usize) -> Vec<(usize, Vec<u32>)> {
        let ls = leaves(b2);
        let mut all: Vec<u32> = ls.iter().flat_map(|(_, p)| p.iter().copied()).collect();
        all.sort_unstable();
        assert_eq!(all, (0..n as u32).collect::<Vec<_>>(), "every primitive once");
        assert!(ls.iter().all(|(d, p)| !p.is_empty() && p.len() <= leaf && *d <= MAX_DEPTH));
        ls
    }

    /// Two clusters far apart: the root splits between them, not inside one.
    #[test]
    fn splits_between_clusters() {
        let boxes: Vec<OAabb> = (0..4)
            .map(|i| unit(i as f32))
            .chain((0..12).map(|i| unit(1000.0 + i as f32)))
            .collect();
        let b2 = build_bvh2(&boxes, 4, 1, MAX_DEPTH, 1);
        check_partition(&b2, 16, 4);
        let root = &b2.nodes[0];
        let left = &b2.nodes[root.first_index as usize];
        let right = &b2.nodes[root.first_index as usize + 1];
        let (lo, hi) =
            if left.aabb().min.x < right.aabb().min.x { (left, right) } else { (right, left) };
        assert_eq!((lo.aabb().max.x, hi.aabb().min.x), (4.0, 1000.0));
    }

    /// The split is where the SAH puts it: one box far off to the side
    /// of fifteen packed ones is split off alone (a median split would cut
    /// the packed ones in half).
    #[test]
    fn takes_the_split_of_least_cost() {
        let boxes: Vec<OAabb> =
            (0..15).map(|i| unit(i as f32 * 0.01)).chain([unit(500.0)]).collect();
        let b2 = build_bvh2(&boxes, 4, 1, MAX_DEPTH, 1);
        let root = b2.nodes[0].first_index as usize;
        let sizes = [root, root + 1].map(|k| prims_under(&b2, k));
        assert_eq!(sizes.iter().min(), Some(&1), "{sizes:?}");
    }

    /// Splits are costed in leaf items: five touching boxes, a gap of 2,
    /// then three. Counting primitives, the gap is worth keeping (5 | 3);
    /// counting packets of four, two full packets are cheaper (4 | 4).
    #[test]
    fn splits_are_costed_in_leaf_items() {
        let boxes: Vec<OAabb> =
            (0..5).map(|i| unit(i as f32)).chain((0..3).map(|i| unit(7.0 + i as f32))).collect();
        for (block, left) in [(1, 5), (4, 4)] {
            let b2 = build_bvh2(&boxes, 4, block, MAX_DEPTH, 1);
            let root = b2.nodes[0].first_index as usize;
            let sizes = [root, root + 1].map(|k| prims_under(&b2, k));
            assert!(sizes.contains(&left), "block {block}: {sizes:?}");
        }
    }

    /// Identical boxes have no split: medians, down to the leaf size.
    #[test]
    fn identical_boxes_are_halved() {
        let boxes = vec![unit(3.0); 1000];
        let ls = check_partition(&build_bvh2(&boxes, 3, 1, MAX_DEPTH, 1), 1000, 3);
        assert!(ls.iter().all(|(d, _)| *d <= ceil_log2(1000)));
    }

    /// Centroids an octave apart: binning splits off the top five
    /// octaves per level, so the depth bound (here 12) takes over.
    #[test]
    fn exponential_spacing_stays_within_the_depth_limit() {
        let boxes: Vec<OAabb> = (0..100)
            .map(|i| {
                let x = 2f32.powi(i);
                OAabb::new(Vec3A::new(x, 0.0, 0.0), Vec3A::new(x * 1.5, 1.0, 1.0))
            })
            .collect();
        let ls = leaves(&build_bvh2(&boxes, 1, 1, 12, 1));
        assert!(ls.iter().all(|(d, _)| *d <= 12), "{:?}", ls.iter().map(|l| l.0).max());
        check_partition(&build_bvh2(&boxes, 1, 1, MAX_DEPTH, 1), 100, 1);
    }

    /// The tree is the same on any number of threads (and the parallel
    /// merge keeps every child pair adjacent and every index in range).
    #[test]
    fn same_tree_on_any_number_of_threads() {
        let mut bits = crate::ray_ctx::tests::Bits(0x2545_f491_4f6c_dd1d);
        let mut r = || bits.unit();
        let boxes: Vec<OAabb> = (0..70_000)
            .map(|_| {
                let p = Vec3A::new(r(), r(), r()) * 100.0;
                OAabb::new(p, p + Vec3A::new(r(), r(), r()))
            })
            .collect();
        let one = build_bvh2(&boxes, 4, 4, MAX_DEPTH, 1);
        check_partition(&one, boxes.len(), 4);
        let key = |b: &Bvh2| {
            b.nodes.iter().map(|n| (*n.aabb(), n.prim_count, n.first_index)).collect::<Vec<_>>()
        };
        for threads in [2, 3, 8] {
            let many = build_bvh2(&boxes, 4, 4, MAX_DEPTH, threads);
            assert!(key(&many) == key(&one), "{threads} threads");
            assert_eq!(many.primitive_indices, one.primitive_indices);
        }
    }

    /// Boxes near the f32 limits: no overflow to a NaN cost or bin.
    #[test]
    fn huge_boxes_build() {
        let m = f32::MAX;
        let boxes: Vec<OAabb> = (0..64)
            .map(|i| {
                let s = if i % 2 == 0 { -m } else { m * 0.5 };
                OAabb::new(Vec3A::new(s, -m, i as f32), Vec3A::new(m, m, i as f32 + 1.0))
            })
            .collect();
        check_partition(&build_bvh2(&boxes, 2, 4, MAX_DEPTH, 1), 64, 2);
    }
}
