//! Building with obvhs (feature `obvhs`): PLOC + reinsertion + leaf
//! collapse into a binary BVH, then conversion to the 8-wide layout.
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
    node::{ChildRef, MAX_ITEMS, MAX_LEAF_ITEMS, Node, WIDTH},
    prim::{Primitive, ShapeItem},
};

/// obvhs's build presets, from fastest build to best traversal.
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
}

impl BuildQuality {
    /// Every preset, fastest first.
    pub const ALL: [Self; 6] =
        [Self::Fastest, Self::VeryFast, Self::Fast, Self::Medium, Self::Slow, Self::VerySlow];

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
        }
    }
}

/// Build settings: a quality preset and the largest leaf.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BuildParams {
    /// obvhs preset.
    pub quality: BuildQuality,
    /// Most primitives per leaf, `1..=16` (clamped). Triangles are tested
    /// four at a time; leaves of up to 8 (two packets) make the tree
    /// shallower, which pays for incoherent rays (`rt-report traversal`:
    /// leaf 4 → 8 took incoherent rays from 0.92–0.95× to 1.0–1.05× of
    /// obvhs's CWBVH, primary rays unchanged).
    pub max_leaf_size: u32,
}

impl BuildParams {
    /// Quick builds for geometry that changes every frame.
    #[must_use]
    pub const fn fast() -> Self {
        Self { quality: BuildQuality::Fast, max_leaf_size: 8 }
    }

    /// The default: good traversal for a moderate build time.
    #[must_use]
    pub const fn medium() -> Self {
        Self { quality: BuildQuality::Medium, max_leaf_size: 8 }
    }

    /// Best traversal, slow build.
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
    let bvh2 = if tris.is_empty() {
        None
    } else {
        Some(build_bvh2_from_tris(&tris, p, &mut Duration::default()))
    };
    let (nodes, items) = convert(bvh2.as_ref(), |prims, items: &mut Vec<TriPacket>| {
        for chunk in prims.chunks(4) {
            let mut packet = TriPacket::EMPTY;
            for (lane, &k) in chunk.iter().enumerate() {
                let t = &tris[k as usize];
                packet.set_lane(lane, ids[k as usize], [t.v0.into(), t.v1.into(), t.v2.into()]);
            }
            items.push(packet);
        }
    })?;
    let mut bvh = Bvh { nodes, items, prim_count };
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
    let bvh2 = if boxes.is_empty() {
        None
    } else {
        Some(build_bvh2(&boxes, params.obvhs(), &mut Duration::default()))
    };
    let (nodes, items) = convert(bvh2.as_ref(), |ids, items: &mut Vec<P>| {
        items.extend(ids.iter().map(|&i| prims[i as usize]));
    })?;
    Ok(Bvh { nodes, items, prim_count })
}

fn to_aabb(b: &obvhs::aabb::Aabb) -> Aabb {
    Aabb::new(b.min.into(), b.max.into())
}

/// Collapses a binary BVH into the 8-wide layout: each wide node takes its
/// binary node's two children and repeatedly opens the inner child of
/// largest surface area until it has [`WIDTH`]. Nodes are emitted breadth
/// first (the order [`crate::validate`] checks), so children always follow
/// their parent.
fn convert<P: Primitive>(
    bvh2: Option<&Bvh2>,
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
    nodes.push(Node::EMPTY);
    // `work[i]` = (binary node, depth) of wide node `i`; processing in index
    // order while appending children gives breadth-first order.
    let mut work = alloc::vec![(0usize, 1usize)];
    let mut dst = 0;
    while let Some(&(src, depth)) = work.get(dst) {
        if depth > MAX_DEPTH {
            return Err(BuildError::TooDeep);
        }
        let n = &b2.nodes[src];
        let mut kids: Vec<usize> = if n.is_leaf() {
            alloc::vec![src]
        } else {
            alloc::vec![n.first_index as usize, n.first_index as usize + 1]
        };
        while kids.len() < WIDTH {
            let open = kids
                .iter()
                .enumerate()
                .filter(|(_, k)| !b2.nodes[**k].is_leaf())
                .max_by(|a, b| {
                    let (ha, hb) =
                        (b2.nodes[*a.1].aabb().half_area(), b2.nodes[*b.1].aabb().half_area());
                    ha.total_cmp(&hb)
                })
                .map(|(i, _)| i);
            let Some(i) = open else { break };
            let k = kids.swap_remove(i);
            let first = b2.nodes[k].first_index as usize;
            kids.push(first);
            kids.push(first + 1);
        }
        let mut node = Node::EMPTY;
        for (slot, &k) in kids.iter().enumerate() {
            let kn = &b2.nodes[k];
            node.set_child_bounds(slot, to_aabb(kn.aabb()));
            node.children[slot] = if kn.is_leaf() {
                let start = kn.first_index as usize;
                let prims = &b2.primitive_indices[start..start + kn.prim_count as usize];
                let first = items.len();
                emit_leaf(prims, &mut items);
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
