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
//! splits into full packets: 3.45 → 3.89 triangles a packet on the
//! terrain, 9–13 % fewer nodes, single-ray rows +2–7 % (two interleaved
//! runs; the first had terrain primary rays −3 %, the second +2.5 %). Nodes of at most `leaf` primitives become leaves; the collapse
//! then merges subtrees into the final leaves by the same heuristic.
//!
//! **Invariants.** Every primitive is in exactly one leaf; no leaf holds
//! more than `leaf` primitives; no leaf is deeper than [`MAX_DEPTH`] (a
//! node whose depth plus `⌈log₂ n⌉` reaches it is split at its median
//! instead, which halves `n` and so keeps the sum from growing: without
//! that, centroids spread over many orders of magnitude put all but one
//! primitive in the first bin at every level). Areas and costs are f64
//! from the f32 corners, so boxes whose extent overflows f32 still compare.

use alloc::{vec, vec::Vec};

use glam::Vec3A;
use obvhs::{
    aabb::Aabb as OAabb,
    bvh2::{Bvh2, node::Bvh2Node},
};

/// Bins per axis. 16 bins gave trees 0.2–0.4 % costlier than 32 on the
/// report's scenes, 64 and 128 none cheaper.
const BINS: usize = 32;

/// Half the surface area of `b`, in f64.
fn half_area(b: &OAabb) -> f64 {
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

/// The binary tree over `boxes` (finite boxes, not empty), leaves of at
/// most `leaf ≥ 1` primitives no deeper than `max_depth ≥ ⌈log₂
/// boxes.len()⌉` (the builder passes [`crate::MAX_DEPTH`]), splits costed
/// in leaf items of `block ≥ 1` primitives: see the module documentation.
pub(crate) fn build_bvh2(boxes: &[OAabb], leaf: usize, block: u32, max_depth: usize) -> Bvh2 {
    debug_assert!(!boxes.is_empty() && leaf >= 1 && block >= 1);
    debug_assert!(ceil_log2(boxes.len()) <= max_depth);
    let cents: Vec<Vec3A> = boxes.iter().map(centroid).collect();
    let mut ids: Vec<u32> = (0..boxes.len() as u32).collect();
    let mut nodes = vec![Bvh2Node::default()];
    // (node, first, end, depth) still to fill, depth-first.
    let mut todo = vec![(0usize, 0usize, boxes.len(), 0usize)];
    while let Some((slot, first, end, depth)) = todo.pop() {
        let part = &mut ids[first..end];
        let (mut bounds, mut cb) = (OAabb::INVALID, OAabb::INVALID);
        for &i in part.iter() {
            bounds = bounds.union(&boxes[i as usize]);
            cb.extend(cents[i as usize]);
        }
        let n = part.len();
        if n <= leaf {
            nodes[slot] = Bvh2Node::new(bounds, n as u32, first as u32);
            continue;
        }
        let binning = Binning::new(&cb);
        let split = if depth + ceil_log2(n) < max_depth {
            best_split(part, boxes, &cents, &binning, block)
        } else {
            None
        };
        let mid = match split {
            Some((axis, k)) => {
                // Stable enough for determinism: a plain in-place
                // partition, the same on every run.
                let mut l = 0;
                for j in 0..n {
                    if binning.bin(cents[part[j] as usize], axis) < k {
                        part.swap(j, l);
                        l += 1;
                    }
                }
                l
            }
            None => {
                // The median along the widest centroid extent.
                let axis = (cb.max - cb.min).max_position();
                let key = |i: &u32| cents[*i as usize][axis];
                part.select_nth_unstable_by(n / 2, |a, b| key(a).total_cmp(&key(b)));
                n / 2
            }
        };
        let kids = nodes.len();
        nodes.extend([Bvh2Node::default(); 2]);
        nodes[slot] = Bvh2Node::new(bounds, 0, kids as u32);
        todo.push((kids + 1, first + mid, end, depth + 1));
        todo.push((kids, first, first + mid, depth + 1));
    }
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
        let b2 = build_bvh2(&boxes, 4, 1, MAX_DEPTH);
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
        let b2 = build_bvh2(&boxes, 4, 1, MAX_DEPTH);
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
            let b2 = build_bvh2(&boxes, 4, block, MAX_DEPTH);
            let root = b2.nodes[0].first_index as usize;
            let sizes = [root, root + 1].map(|k| prims_under(&b2, k));
            assert!(sizes.contains(&left), "block {block}: {sizes:?}");
        }
    }

    /// Identical boxes have no split: medians, down to the leaf size.
    #[test]
    fn identical_boxes_are_halved() {
        let boxes = vec![unit(3.0); 1000];
        let ls = check_partition(&build_bvh2(&boxes, 3, 1, MAX_DEPTH), 1000, 3);
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
        let ls = leaves(&build_bvh2(&boxes, 1, 1, 12));
        assert!(ls.iter().all(|(d, _)| *d <= 12), "{:?}", ls.iter().map(|l| l.0).max());
        check_partition(&build_bvh2(&boxes, 1, 1, MAX_DEPTH), 100, 1);
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
        check_partition(&build_bvh2(&boxes, 2, 4, MAX_DEPTH), 64, 2);
    }
}
