//! Building (feature `obvhs`): a binary BVH, from our binned SAH builder
//! (`construct/sah.rs`, the default) or obvhs's PLOC + reinsertion + leaf collapse
//! presets, then the 8-wide layout of least SAH cost over it (Ylitie et
//! al. 2017's dynamic programming).
//!
//! obvhs stays at this edge: inputs and outputs are rt types.

use alloc::vec::Vec;
use core::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::{
    BvhBuildParams,
    bvh2::{
        Bvh2,
        builder::{build_bvh2, build_bvh2_from_tris},
    },
};
use rt_core::{
    Aabb,
    intersect::{Capsule, Sphere, is_degenerate_triangle},
};

use crate::{
    BuildError, Bvh, CapsuleItem, MAX_DEPTH, SphereItem, TriPacket,
    check::triangle_vertices,
    node::{ChildRef, MAX_ITEMS, MAX_LEAF_ITEMS, MAX_NODES, Node, WIDTH},
    prim::{Primitive, ShapeItem},
    sah,
};

/// Build presets: obvhs's PLOC presets, from fastest build to best
/// traversal, and rt-accel's own binned SAH builder, which gives the best
/// trees of all on the report's scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum BuildQuality {
    /// PLOC with the smallest search radius, no reinsertion.
    Fastest,
    /// Minimal search radius with a little reinsertion.
    VeryFast,
    /// Low search radius, some reinsertion.
    Fast,
    /// Medium search radius and reinsertion (obvhs: "around Embree's build
    /// time with faster traversal").
    Medium,
    /// High search radius, more reinsertion, spatial pre-splits for triangles.
    Slow,
    /// Full reinsertion and pre-splits.
    VerySlow,
    /// rt-accel's own top-down binned SAH builder (Wald 2007), not
    /// obvhs's: the best trees of all presets on the report's scenes, in
    /// about `Medium`'s build time. [`BuildParams::medium`] uses it.
    BinnedSah,
}

impl BuildQuality {
    /// Every preset, fastest first.
    pub const ALL: [Self; 7] = [
        Self::Fastest,
        Self::VeryFast,
        Self::Fast,
        Self::Medium,
        Self::BinnedSah,
        Self::Slow,
        Self::VerySlow,
    ];

    /// The preset's name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Fastest => "fastest",
            Self::VeryFast => "very_fast",
            Self::Fast => "fast",
            Self::Medium => "medium",
            Self::Slow => "slow",
            Self::VerySlow => "very_slow",
            Self::BinnedSah => "binned_sah",
        }
    }

    fn obvhs(self) -> BvhBuildParams {
        match self {
            Self::Fastest => BvhBuildParams::fastest_build(),
            Self::VeryFast => BvhBuildParams::very_fast_build(),
            Self::Fast => BvhBuildParams::fast_build(),
            Self::Medium => BvhBuildParams::medium_build(),
            Self::Slow => BvhBuildParams::slow_build(),
            Self::VerySlow => BvhBuildParams::very_slow_build(),
            // Only its leaf size is read.
            Self::BinnedSah => BvhBuildParams::medium_build(),
        }
    }
}

/// Build settings: a quality preset and the largest leaf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildParams {
    /// The binary builder and its preset.
    pub quality: BuildQuality,
    /// Most primitives per leaf, `1..=16` (clamped). Triangles are tested
    /// four at a time; leaves of several packets make the tree shallower,
    /// which pays for incoherent rays at no cost to primary ones.
    /// [`BuildParams::medium`] allows 12 (three packets), which its node
    /// weight needs (`TRI_NODE_COST` in `build.rs`); 16 gains nothing more.
    pub max_leaf_size: u32,
}

impl BuildParams {
    /// Quick builds for geometry that changes every frame.
    #[must_use]
    pub const fn fast() -> Self {
        Self { quality: BuildQuality::Fast, max_leaf_size: 8 }
    }

    /// The default: the best traversal for a moderate build time
    /// ([`BuildQuality::BinnedSah`]).
    #[must_use]
    pub const fn medium() -> Self {
        Self { quality: BuildQuality::BinnedSah, max_leaf_size: 12 }
    }

    /// obvhs's slow preset (more reinsertion, spatial pre-splits): a
    /// slower build whose trees traced slower than
    /// [`BuildParams::medium`]'s on the report's scenes; there for
    /// comparison, and for meshes of long thin triangles, where pre-splits
    /// can pay.
    #[must_use]
    pub const fn slow() -> Self {
        Self { quality: BuildQuality::Slow, max_leaf_size: 8 }
    }

    fn obvhs(&self) -> BvhBuildParams {
        let mut p = self.quality.obvhs();
        p.max_prims_per_leaf = self.max_leaf_size.clamp(1, MAX_LEAF_ITEMS);
        p
    }
}

impl Default for BuildParams {
    fn default() -> Self {
        Self::medium()
    }
}

fn a3(v: Vec3) -> Vec3A {
    Vec3A::from(v)
}

/// Builds a BVH over an indexed triangle mesh. Degenerate (zero-area)
/// triangles are left out: they can never be hit.
///
/// # Errors
/// [`BuildError::NonFiniteVertex`] naming the first NaN/∞ vertex that a
/// triangle uses, [`BuildError::IndexOutOfRange`], or a size limit.
pub fn build_triangles(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    params: &BuildParams,
) -> Result<Bvh<TriPacket>, BuildError> {
    let prim_count = u32::try_from(indices.len()).map_err(|_| BuildError::TooManyPrimitives)?;
    let verts = triangle_vertices(positions, indices)?;
    let mut tris = Vec::with_capacity(indices.len());
    let mut ids = Vec::with_capacity(indices.len());
    for (i, v) in verts.enumerate() {
        let v = v?;
        if !is_degenerate_triangle(v[0], v[1], v[2]) {
            tris.push(obvhs::triangle::Triangle { v0: a3(v[0]), v1: a3(v[1]), v2: a3(v[2]) });
            ids.push(i as u32);
        }
    }
    let p = params.obvhs();
    let max_leaf = p.max_prims_per_leaf;
    let bvh2 = if tris.is_empty() {
        None
    } else {
        Some(match params.quality {
            BuildQuality::BinnedSah => {
                let boxes: Vec<_> = tris.iter().map(obvhs::triangle::Triangle::aabb).collect();
                sah::build_bvh2(&boxes, sah_leaf(max_leaf), 4, MAX_DEPTH, build_threads())
            }
            _ => build_bvh2_from_tris(&tris, p, &mut Duration::default()),
        })
    };
    let (nodes, items) = convert(
        bvh2.as_ref(),
        max_leaf,
        |n| n.div_ceil(4),
        TRI_NODE_COST,
        |prims, items: &mut Vec<TriPacket>| {
            for chunk in prims.chunks(4) {
                let mut packet = TriPacket::EMPTY;
                for (lane, &k) in chunk.iter().enumerate() {
                    let t = &tris[k as usize];
                    packet.set_lane(lane, ids[k as usize], [t.v0.into(), t.v1.into(), t.v2.into()]);
                }
                items.push(packet);
            }
        },
    )?;
    let mut bvh = Bvh::from_arrays(&nodes, &items, prim_count);
    // The boxes from the items themselves: with spatial pre-splits (the
    // slow presets) obvhs's leaf boxes are clipped parts of a triangle's
    // box, and a hit on the triangle's box boundary could fall outside
    // them by rounding — a false miss that brute force does not have
    // (found by the `bvh` fuzz target). Every box now contains its
    // triangles' whole boxes, exactly.
    bvh.refit_with(|_| Ok(()))?;
    Ok(bvh)
}

impl crate::TriangleMesh {
    /// Builds a BVH over the mesh ([`build_triangles`]); hits carry the
    /// triangle index and the barycentrics of the hit point (for
    /// interpolating per-vertex data).
    ///
    /// # Errors
    /// As [`build_triangles`] (a validated mesh only fails on size limits).
    pub fn build_bvh(&self, params: &BuildParams) -> Result<Bvh<TriPacket>, BuildError> {
        build_triangles(self.positions(), self.indices(), params)
    }
}

/// Builds a BVH over spheres.
///
/// # Errors
/// [`BuildError::InvalidPrimitive`] for the first sphere with a non-finite
/// value or a non-positive radius, or a size limit.
pub fn build_spheres(
    spheres: &[Sphere],
    params: &BuildParams,
) -> Result<Bvh<SphereItem>, BuildError> {
    build_shapes(spheres, params)
}

/// Builds a BVH over capsules (tubes with round caps).
///
/// # Errors
/// [`BuildError::InvalidPrimitive`] for the first capsule with a
/// non-finite value or a non-positive radius, or a size limit.
pub fn build_capsules(
    capsules: &[Capsule],
    params: &BuildParams,
) -> Result<Bvh<CapsuleItem>, BuildError> {
    build_shapes(capsules, params)
}

fn build_shapes<P: ShapeItem>(
    shapes: &[P::Shape],
    params: &BuildParams,
) -> Result<Bvh<P>, BuildError> {
    if let Some(index) = shapes.iter().position(|s| !P::shape_is_valid(s)) {
        return Err(BuildError::InvalidPrimitive { index });
    }
    let items = shapes.iter().enumerate().map(|(i, &s)| P::wrap(s, i as u32)).collect();
    build_items(items, params)
}

/// One item per primitive: build over the items' boxes, then reorder the
/// items into leaf order.
fn build_items<P: Primitive>(prims: Vec<P>, params: &BuildParams) -> Result<Bvh<P>, BuildError> {
    let prim_count = u32::try_from(prims.len()).map_err(|_| BuildError::TooManyPrimitives)?;
    let boxes: Vec<obvhs::aabb::Aabb> = prims
        .iter()
        .map(|p| {
            let b = p.bounds();
            obvhs::aabb::Aabb::new(a3(b.min), a3(b.max))
        })
        .collect();
    let p = params.obvhs();
    let max_leaf = p.max_prims_per_leaf;
    let bvh2 = match params.quality {
        _ if boxes.is_empty() => None,
        BuildQuality::BinnedSah => {
            Some(sah::build_bvh2(&boxes, sah_leaf(max_leaf), 1, MAX_DEPTH, build_threads()))
        }
        _ => Some(build_bvh2(&boxes, p, &mut Duration::default())),
    };
    let (nodes, items) = convert(
        bvh2.as_ref(),
        max_leaf,
        |n| n,
        SHAPE_NODE_COST,
        |ids, items: &mut Vec<P>| {
            items.extend(ids.iter().map(|&i| prims[i as usize]));
        },
    )?;
    Ok(Bvh::from_arrays(&nodes, &items, prim_count))
}

/// The binned SAH builder's leaf size: four primitives (one triangle
/// packet) or `max_leaf` if smaller. The collapse merges leaves up to
/// `max_leaf`; binary leaves of eight left it nothing to choose (costlier
/// trees).
fn sah_leaf(max_leaf: u32) -> usize {
    max_leaf.min(4) as usize
}

/// Threads for the binned SAH builder: the cores the process may use.
fn build_threads() -> usize {
    std::thread::available_parallelism().map_or(1, core::num::NonZero::get)
}

fn to_aabb(b: &obvhs::aabb::Aabb) -> Aabb {
    Aabb::new(b.min.into(), b.max.into())
}

/// The collapse's surface area heuristic weighs every test by the surface
/// area of the box that leads to it (the chance a ray gets there). This is
/// the cost of testing one leaf item (four triangles, a sphere, a
/// capsule); a wide node's test is weighed against it.
const ITEM_COST: f64 = 1.0;
/// The cost of one wide node's test above triangle packets: three packets.
/// A node is one more fetch on the chain from root to leaf, where a
/// leaf's packets lie side by side and are fetched together; on
/// million-triangle scenes that chain sets the time. At this weight a
/// node costs more than a leaf of up to three packets over the same box,
/// so a subtree of at most `max_leaf_size` triangles becomes a leaf (or
/// is spread over its parent's free slots), never a small node of its
/// own: far fewer nodes than at a weight of 1, so a shorter chain of
/// fetches for every ray. Heavier weights (4–8) slowed coherent rays on
/// the icosphere, lighter ones (2, 2.5) gained less elsewhere.
const TRI_NODE_COST: f64 = 3.0;
/// The cost of one wide node's test above spheres and capsules (items of
/// one primitive each): the weight triangles had before, not measured
/// again for shapes.
const SHAPE_NODE_COST: f64 = 1.0;

/// How a binary subtree is laid out among `s` child slots of a wide node.
#[derive(Clone, Copy, Debug)]
enum Choice {
    /// One slot: a leaf holding every primitive of the subtree.
    Leaf,
    /// One slot: a wide node of its own.
    Node,
    /// The two binary children, over `left` and `right` slots.
    Split { left: u8, right: u8 },
}

/// The cheapest layout of every binary subtree over 1 to [`WIDTH`] slots
/// (Ylitie, Karras and Laine 2017, "Efficient incoherent ray traversal
/// on GPUs through compressed wide BVHs", §4.1: dynamic programming over
/// the binary tree, bottom up).
struct Plan {
    /// `choice[n][s − 1]`: the layout of subtree `n` over at most `s` slots.
    choice: Vec<[Choice; WIDTH]>,
    /// `wide[n]`: the children of the wide node made of inner node `n`,
    /// its two binary children over all [`WIDTH`] slots.
    wide: Vec<Choice>,
}

impl Plan {
    /// `items(p)`: leaf items that `p` primitives take; a leaf holds at
    /// most `max_leaf` primitives.
    fn new(b2: &Bvh2, max_leaf: u32, items: impl Fn(u32) -> u32, node_cost: f64) -> Self {
        let n = b2.nodes.len();
        // In f64, from the boxes' f32 corners: every area and sum is
        // finite (a box's extent may overflow f32), so every inner node
        // finds a split.
        let mut cost = alloc::vec![[f64::INFINITY; WIDTH]; n];
        let mut choice = alloc::vec![[Choice::Leaf; WIDTH]; n];
        let mut wide = alloc::vec![Choice::Leaf; n];
        let mut prims = alloc::vec![0u32; n];
        // Post order with an explicit stack (`true`: children done).
        let mut stack = alloc::vec![(0usize, false)];
        while let Some((i, done)) = stack.pop() {
            let node = &b2.nodes[i];
            let area = sah::half_area(node.aabb());
            let leaf_cost = |p: u32| area * ITEM_COST * f64::from(items(p));
            if node.is_leaf() {
                prims[i] = node.prim_count;
                cost[i] = [leaf_cost(node.prim_count); WIDTH];
                continue;
            }
            let (l, r) = (node.first_index as usize, node.first_index as usize + 1);
            if !done {
                stack.extend([(i, true), (l, false), (r, false)]);
                continue;
            }
            prims[i] = prims[l].saturating_add(prims[r]);
            // `split[s − 1]`: both children over exactly `s ≥ 2` slots.
            let mut split = [(f64::INFINITY, Choice::Leaf); WIDTH];
            for s in 2..=WIDTH {
                for left in 1..s {
                    let c = cost[l][left - 1] + cost[r][s - left - 1];
                    if c < split[s - 1].0 {
                        let (left, right) = (left as u8, (s - left) as u8);
                        split[s - 1] = (c, Choice::Split { left, right });
                    }
                }
            }
            let leaf = if prims[i] <= max_leaf { leaf_cost(prims[i]) } else { f64::INFINITY };
            let inner = area * node_cost + split[WIDTH - 1].0;
            wide[i] = split[WIDTH - 1].1;
            (cost[i][0], choice[i][0]) =
                if leaf <= inner { (leaf, Choice::Leaf) } else { (inner, Choice::Node) };
            for s in 1..WIDTH {
                (cost[i][s], choice[i][s]) = if split[s].0 < cost[i][s - 1] {
                    split[s]
                } else {
                    (cost[i][s - 1], choice[i][s - 1])
                };
            }
        }
        Self { choice, wide }
    }

    /// Appends the slots of subtree `n` laid out over at most `s` slots:
    /// `(binary node, is leaf)`.
    fn slots(&self, b2: &Bvh2, n: usize, s: usize, out: &mut Vec<(usize, bool)>) {
        self.place(b2, n, self.choice[n][s - 1], out);
    }

    /// Appends the slots of subtree `n` laid out as `c`.
    fn place(&self, b2: &Bvh2, n: usize, c: Choice, out: &mut Vec<(usize, bool)>) {
        match c {
            Choice::Leaf => out.push((n, true)),
            Choice::Node => out.push((n, false)),
            Choice::Split { left, right } => {
                let l = b2.nodes[n].first_index as usize;
                self.slots(b2, l, usize::from(left), out);
                self.slots(b2, l + 1, usize::from(right), out);
            }
        }
    }

    /// The children of the wide node made of binary node `n` (one leaf
    /// for a binary leaf at the root).
    fn children(&self, b2: &Bvh2, n: usize, out: &mut Vec<(usize, bool)>) {
        out.clear();
        let c = if b2.nodes[n].is_leaf() { Choice::Leaf } else { self.wide[n] };
        self.place(b2, n, c, out);
    }

    /// The primitives of subtree `n`, each once (with spatial splits a
    /// primitive may sit in several of its binary leaves).
    fn gather(b2: &Bvh2, n: usize, out: &mut Vec<u32>) {
        out.clear();
        let mut stack = alloc::vec![n];
        while let Some(i) = stack.pop() {
            let node = &b2.nodes[i];
            if node.is_leaf() {
                let start = node.first_index as usize;
                out.extend_from_slice(
                    &b2.primitive_indices[start..start + node.prim_count as usize],
                );
            } else {
                stack.extend([node.first_index as usize + 1, node.first_index as usize]);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// Collapses a binary BVH into the 8-wide layout chosen by [`Plan`]: the
/// layout of least SAH cost, which merges small subtrees into leaves and
/// fills wide nodes where the binary tree allows. `items(p)` is the
/// number of leaf items `p` primitives take; `emit_leaf` appends them.
/// Nodes are emitted breadth first (the order [`crate::validate`]
/// checks), so children always follow their parent.
fn convert<P: Primitive>(
    bvh2: Option<&Bvh2>,
    max_leaf: u32,
    items_of: impl Fn(u32) -> u32,
    node_cost: f64,
    mut emit_leaf: impl FnMut(&[u32], &mut Vec<P>),
) -> Result<(Vec<Node>, Vec<P>), BuildError> {
    let mut nodes = Vec::new();
    let mut items = Vec::new();
    let Some(b2) = bvh2 else {
        return Ok((nodes, items));
    };
    if b2.nodes.is_empty() {
        return Ok((nodes, items));
    }
    let plan = Plan::new(b2, max_leaf, items_of, node_cost);
    nodes.push(Node::EMPTY);
    // `work[i]` = (binary node, depth) of wide node `i`; processing in index
    // order while appending children gives breadth-first order.
    let mut work = alloc::vec![(0usize, 1usize)];
    let mut dst = 0;
    let (mut kids, mut prims) = (Vec::new(), Vec::new());
    while let Some(&(src, depth)) = work.get(dst) {
        if depth > MAX_DEPTH {
            return Err(BuildError::TooDeep);
        }
        plan.children(b2, src, &mut kids);
        let mut node = Node::EMPTY;
        for (slot, &(k, is_leaf)) in kids.iter().enumerate() {
            node.set_child_bounds(slot, to_aabb(b2.nodes[k].aabb()));
            node.children[slot] = if is_leaf {
                // At most the primitives `Plan` counted, so within the
                // leaf size.
                Plan::gather(b2, k, &mut prims);
                let first = items.len();
                emit_leaf(&prims, &mut items);
                let count = items.len() - first;
                if items.len() > MAX_ITEMS as usize {
                    return Err(BuildError::TooManyPrimitives);
                }
                if count == 0 || count > MAX_LEAF_ITEMS as usize {
                    return Err(BuildError::TooManyPrimitives);
                }
                ChildRef::leaf(first as u32, count as u32)
            } else {
                let idx = nodes.len();
                if idx >= MAX_NODES as usize {
                    return Err(BuildError::TooManyPrimitives);
                }
                nodes.push(Node::EMPTY);
                work.push((k, depth + 1));
                ChildRef::inner(idx as u32)
            };
        }
        nodes[dst] = node;
        dst += 1;
    }
    Ok((nodes, items))
}

#[cfg(test)]
mod tests {
    use obvhs::{aabb::Aabb as OAabb, bvh2::node::Bvh2Node};

    use super::*;

    /// A balanced binary tree over leaves of one primitive each, primitive
    /// `i` with box `boxes[i]`; `dup` adds the last but one primitive to the
    /// last leaf too (as spatial splits do).
    fn balanced(boxes: &[OAabb], dup: bool) -> Bvh2 {
        fn node(b2: &mut Bvh2, boxes: &[OAabb], first: u32, slot: usize) {
            if boxes.len() == 1 {
                b2.nodes[slot] = Bvh2Node::new(boxes[0], 1, first);
                return;
            }
            let kids = b2.nodes.len();
            b2.nodes.extend([Bvh2Node::default(); 2]);
            let mid = boxes.len() / 2;
            node(b2, &boxes[..mid], first, kids);
            node(b2, &boxes[mid..], first + mid as u32, kids + 1);
            let aabb = b2.nodes[kids].aabb().union(b2.nodes[kids + 1].aabb());
            b2.nodes[slot] = Bvh2Node::new(aabb, 0, kids as u32);
        }
        let mut b2 = Bvh2 { nodes: alloc::vec![Bvh2Node::default()], ..Bvh2::default() };
        b2.primitive_indices = (0..boxes.len() as u32).collect();
        node(&mut b2, boxes, 0, 0);
        if dup {
            let last = b2.nodes.iter().rposition(Bvh2Node::is_leaf).unwrap();
            let n = boxes.len() as u32;
            b2.primitive_indices.extend([n - 1, n - 2]);
            b2.nodes[last] = Bvh2Node::new(*b2.nodes[last].aabb(), 2, n);
        }
        b2
    }

    fn unit_box(x: f32, y: f32) -> OAabb {
        OAabb::new(Vec3A::new(x, y, 0.0), Vec3A::new(x + 1.0, y + 1.0, 1.0))
    }

    /// Collapses `b2` into triangle packets; the primitives of each leaf.
    fn collapse(b2: &Bvh2, max_leaf: u32) -> (Vec<Node>, Vec<Vec<u32>>) {
        collapse_weighed(b2, max_leaf, TRI_NODE_COST)
    }

    /// [`collapse`] with a node weighed as `node_cost` packets.
    fn collapse_weighed(b2: &Bvh2, max_leaf: u32, node_cost: f64) -> (Vec<Node>, Vec<Vec<u32>>) {
        let (nodes, items) = convert(
            Some(b2),
            max_leaf,
            |n| n.div_ceil(4),
            node_cost,
            |prims, items| {
                for chunk in prims.chunks(4) {
                    let mut p = TriPacket::EMPTY;
                    for (lane, &k) in chunk.iter().enumerate() {
                        p.set_lane(lane, k, [Vec3::ZERO; 3]);
                    }
                    items.push(p);
                }
            },
        )
        .unwrap();
        let leaves = nodes
            .iter()
            .flat_map(|n| n.children)
            .filter(|c| c.is_leaf() && !c.is_empty())
            .map(|c| {
                let (first, count) = c.leaf_range();
                items[first..first + count]
                    .iter()
                    .flat_map(|p| p.prims)
                    .filter(|&k| k != u32::MAX)
                    .collect()
            })
            .collect();
        (nodes, leaves)
    }

    fn fill(n: &Node) -> usize {
        n.children.iter().filter(|c| !c.is_empty()).count()
    }

    #[test]
    fn sixty_four_far_apart_leaves_make_nine_full_nodes() {
        // Far apart, a node weighed as one packet: merging any two into a
        // leaf costs more than a slot.
        let boxes: Vec<_> = (0..64).map(|i| unit_box(100.0 * i as f32, 0.0)).collect();
        let (nodes, leaves) = collapse_weighed(&balanced(&boxes, false), 8, 1.0);
        assert_eq!(nodes.len(), 9);
        assert!(nodes.iter().all(|n| fill(n) == WIDTH));
        let mut prims: Vec<u32> = leaves.concat();
        prims.sort_unstable();
        assert_eq!(prims, (0..64).collect::<Vec<_>>());
    }

    #[test]
    fn a_node_weighed_as_three_packets_gives_way_to_leaves_of_two() {
        // The same boxes with the triangles' weight: a leaf of two packets
        // costs less than a node over the same box, however far apart its
        // primitives, so the root holds eight leaves of eight.
        let boxes: Vec<_> = (0..64).map(|i| unit_box(100.0 * i as f32, 0.0)).collect();
        let (nodes, leaves) = collapse(&balanced(&boxes, false), 8);
        assert_eq!((nodes.len(), fill(&nodes[0])), (1, WIDTH));
        assert!(leaves.iter().all(|l| l.len() == 8), "{leaves:?}");
        // Leaves of one packet at most: sixteen or more leaves do not fit
        // one node's slots, so wide nodes come back below the root.
        let (nodes, leaves) = collapse(&balanced(&boxes, false), 4);
        assert_eq!(nodes.len(), 3);
        assert!(leaves.len() >= 16 && leaves.iter().all(|l| l.len() <= 4), "{leaves:?}");
        assert_eq!(leaves.concat().len(), 64);
    }

    #[test]
    fn overlapping_leaves_merge_into_packets_up_to_the_leaf_size() {
        // Sixteen copies of one box: a leaf of four costs one packet test
        // over the same area as one of a single primitive.
        let boxes = [unit_box(0.0, 0.0); 16];
        let (nodes, leaves) = collapse(&balanced(&boxes, false), 4);
        assert_eq!(nodes.len(), 1);
        assert_eq!(fill(&nodes[0]), 4);
        assert!(leaves.iter().all(|l| l.len() == 4), "{leaves:?}");
        // With leaves of one, the same tree needs two levels.
        let (nodes, leaves) = collapse(&balanced(&boxes, false), 1);
        assert_eq!((nodes.len(), leaves.len()), (3, 16));
    }

    #[test]
    fn a_primitive_in_two_merged_leaves_is_tested_once() {
        // Leaves [0], [1] and [2, 1]: the root's second child, three
        // primitives with 1 counted twice, is one packet and one leaf.
        let boxes = [unit_box(0.0, 0.0); 3];
        let (_, leaves) = collapse(&balanced(&boxes, true), 8);
        assert_eq!(leaves, [alloc::vec![0], alloc::vec![1, 2]]);
    }
}
