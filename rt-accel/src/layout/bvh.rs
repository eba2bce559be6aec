//! The owned BVH: node and item arrays, with byte export and import.

use alloc::vec::Vec;

use rt_core::{Aabb, Hit, Ray, SceneQuery};

use crate::{
    BuildError, LoadError,
    bytes::{Header, parse, validate},
    node::{ChildRef, Node, WIDTH},
    pages::large_copy,
    prim::{BestHit, Primitive},
    traverse::BvhRef,
};

/// A BVH that owns its arrays. Queries go through [`Bvh::as_ref`] (or the
/// delegating methods here); the layout is plain `Pod` data. Equality is
/// bitwise (unused packet lanes hold NaN).
#[derive(Clone, Debug)]
pub struct Bvh<P: Primitive> {
    pub(crate) nodes: Vec<Node>,
    pub(crate) items: Vec<P>,
    pub(crate) prim_count: u32,
    /// Whether every box lies within the fused node test's range
    /// ([`crate::traverse::fits_fused`]); kept up to date by every change
    /// of the nodes.
    pub(crate) fused: bool,
}

impl<P: Primitive> Bvh<P> {
    /// A BVH over nothing: every query misses.
    #[must_use]
    pub fn empty() -> Self {
        Self { nodes: Vec::new(), items: Vec::new(), prim_count: 0, fused: true }
    }

    /// A BVH of copies of `nodes` and `items` in memory advised for large
    /// pages (see `pages.rs`: fewer TLB misses for incoherent rays).
    pub(crate) fn from_arrays(nodes: &[Node], items: &[P], prim_count: u32) -> Self {
        let fused = crate::traverse::fits_fused(nodes);
        Self { nodes: large_copy(nodes), items: large_copy(items), prim_count, fused }
    }

    /// The borrowed view used for traversal.
    #[inline]
    #[must_use]
    pub fn as_ref(&self) -> BvhRef<'_, P> {
        BvhRef {
            nodes: &self.nodes,
            items: &self.items,
            prim_count: self.prim_count,
            isa: crate::Isa::detect(),
            fused: self.fused,
        }
    }

    /// See [`BvhRef::closest_hit`].
    #[inline]
    #[must_use]
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.as_ref().closest_hit(ray)
    }

    /// See [`BvhRef::closest_t`].
    #[inline]
    #[must_use]
    pub fn closest_t(&self, ray: &Ray) -> Option<BestHit> {
        self.as_ref().closest_t(ray)
    }

    /// See [`BvhRef::occluded`].
    #[inline]
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.as_ref().occluded(ray)
    }

    /// The box around everything.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.as_ref().bounds()
    }

    /// Number of nodes.
    #[must_use]
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// The leaf items.
    #[must_use]
    pub fn items(&self) -> &[P] {
        &self.items
    }

    /// Number of primitives the items refer to.
    #[must_use]
    pub fn prim_count(&self) -> u32 {
        self.prim_count
    }

    /// Tree depth (root = 1; 0 when empty).
    #[must_use]
    pub fn depth(&self) -> usize {
        let mut depth = alloc::vec![0usize; self.nodes.len()];
        let mut max = 0;
        for i in 0..self.nodes.len() {
            let d = if i == 0 { 1 } else { depth[i] };
            max = max.max(d);
            for c in self.nodes[i].children {
                if !c.is_leaf() {
                    depth[c.index()] = d + 1;
                }
            }
        }
        max
    }

    /// The serialized form: header, nodes, items (native byte order), in
    /// a plain `Vec` (1-byte alignment promised: load it with
    /// [`Bvh::from_bytes`], which copies, or use
    /// [`Bvh::to_aligned_bytes`] to view it in place with
    /// [`BvhRef::from_bytes`](crate::BvhRef::from_bytes)).
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        let h = Header::new::<P>(self.nodes.len(), self.items.len(), self.prim_count);
        let mut out = Vec::with_capacity(
            size_of::<Header>()
                + self.nodes.len() * size_of::<Node>()
                + self.items.len() * size_of::<P>(),
        );
        out.extend_from_slice(bytemuck::bytes_of(&h));
        out.extend_from_slice(bytemuck::cast_slice(&self.nodes));
        out.extend_from_slice(bytemuck::cast_slice(&self.items));
        out
    }

    /// [`Bvh::to_bytes`] in [`AlignedBytes`](crate::AlignedBytes): ready for
    /// zero-copy viewing with [`BvhRef::from_bytes`](crate::BvhRef::from_bytes).
    #[must_use]
    pub fn to_aligned_bytes(&self) -> crate::AlignedBytes {
        crate::AlignedBytes::copy_from(&self.to_bytes())
    }

    /// Loads a serialized BVH from any byte buffer (copying into aligned
    /// storage) after full validation.
    ///
    /// # Errors
    /// [`LoadError`] naming the first problem found.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, LoadError> {
        let (h, nr, ir) = parse::<P>(bytes)?;
        let nodes: Vec<Node> = bytemuck::pod_collect_to_vec(&bytes[nr]);
        let items: Vec<P> = bytemuck::pod_collect_to_vec(&bytes[ir]);
        validate(&nodes, &items, h.prim_count)?;
        Ok(Self::from_arrays(&nodes, &items, h.prim_count))
    }

    /// Recomputes every box bottom-up after `update` has rewritten the leaf
    /// items in place (same primitives, moved). No rebuild: the topology is
    /// kept, so quality degrades as primitives move far.
    ///
    /// # Errors
    /// Whatever `update` returns; the BVH is unchanged only if `update`
    /// fails before writing.
    pub fn refit_with(
        &mut self,
        update: impl FnOnce(&mut [P]) -> Result<(), BuildError>,
    ) -> Result<(), BuildError> {
        update(&mut self.items)?;
        // Children come after parents, so a reverse sweep sees children first.
        for i in (0..self.nodes.len()).rev() {
            for slot in 0..WIDTH {
                let c = self.nodes[i].children[slot];
                let b = if c.is_empty() {
                    Aabb::EMPTY
                } else if c.is_leaf() {
                    leaf_bounds(&self.items, c)
                } else {
                    self.nodes[c.index()].bounds()
                };
                self.nodes[i].set_child_bounds(slot, b);
            }
        }
        self.fused = crate::traverse::fits_fused(&self.nodes);
        Ok(())
    }
}

impl<P: Primitive> PartialEq for Bvh<P> {
    fn eq(&self, other: &Self) -> bool {
        self.prim_count == other.prim_count
            && bytemuck::cast_slice::<Node, u8>(&self.nodes)
                == bytemuck::cast_slice::<Node, u8>(&other.nodes)
            && bytemuck::cast_slice::<P, u8>(&self.items)
                == bytemuck::cast_slice::<P, u8>(&other.items)
    }
}

fn leaf_bounds<P: Primitive>(items: &[P], c: ChildRef) -> Aabb {
    let (first, count) = c.leaf_range();
    items[first..first + count].iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds()))
}

impl<P: Primitive> SceneQuery for Bvh<P> {
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.as_ref().closest_hit(ray)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.as_ref().occluded(ray)
    }

    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        self.as_ref().occluded_batch(rays, out);
    }

    fn closest_hit_packet(&self, rays: &[Ray; crate::PACKET]) -> [Option<Hit>; crate::PACKET] {
        self.as_ref().closest_hit_packet(rays)
    }

    fn closest_hit_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.as_ref().closest_hit_batch(rays, out);
    }
}
