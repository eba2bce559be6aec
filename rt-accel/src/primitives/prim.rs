//! What a BVH leaf can hold: the [`Primitive`] trait and its sphere and
//! capsule items (triangles come in packets of four, see
//! [`crate::TriPacket`]).

use rt_core::{
    Aabb, Hit, PrimKind, Ray,
    intersect::{
        Capsule, Sphere, intersect_capsule, intersect_capsule_t, intersect_sphere,
        intersect_sphere_t,
    },
};

use crate::RayCtx;

/// The closest hit found so far during a traversal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BestHit {
    /// Ray parameter (initially the ray's `t_max`).
    pub t: f32,
    /// Primitive index of the hit (`u32::MAX` before any).
    pub prim: u32,
    /// Leaf item holding it.
    pub item: u32,
    /// Lane within the item (packets hold several primitives).
    pub lane: u32,
}

impl BestHit {
    /// No hit yet, searching up to `t_max`.
    #[inline]
    #[must_use]
    pub const fn new(t_max: f32) -> Self {
        Self { t: t_max, prim: u32::MAX, item: u32::MAX, lane: 0 }
    }

    /// Offers a hit; it wins if closer, or equally close with a lower
    /// primitive index (so the answer does not depend on visiting order).
    #[inline]
    pub fn offer(&mut self, t: f32, prim: u32, item: u32, lane: u32) {
        if t < self.t || (t == self.t && prim < self.prim) {
            *self = Self { t, prim, item, lane };
        }
    }

    /// Whether any hit was recorded.
    #[inline]
    #[must_use]
    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }
}

mod sealed {
    /// Seals [`super::Primitive`], and holds what only the kernels call.
    pub trait Sealed: Sized {
        /// The items as triangle packets, if they are: the AVX kernels
        /// test those two at a time.
        #[inline(always)]
        fn as_tri_packets(items: &[Self]) -> Option<&[crate::TriPacket]> {
            let _ = items;
            None
        }
    }
}
pub(crate) use sealed::Sealed;

/// Offers the hits of a leaf's `items` (leaf positions `first..`) to
/// `best`. A plain loop, always inlined (see [`any_leaf`]). `AVX`:
/// triangle packets are tested two at a time, in eight lanes.
#[inline(always)]
pub(crate) fn closest_leaf<P: Primitive, const AVX: bool>(
    items: &[P],
    first: usize,
    ctx: &RayCtx,
    best: &mut BestHit,
) {
    #[cfg(target_arch = "x86_64")]
    if AVX && let Some(tris) = P::as_tri_packets(items) {
        // SAFETY: `AVX` is instantiated only inside the kernels compiled
        // with AVX, entered only where `Isa::is_available` found it.
        return unsafe { crate::tri_packet::closest_x8(tris, first, ctx, best) };
    }
    for (k, item) in items.iter().enumerate() {
        item.closest((first + k) as u32, ctx, best);
    }
}

/// Whether `ctx`'s ray hits any of a leaf's `items` before `t_max`. A
/// plain loop, always inlined, so the leaf tests compile with the calling
/// kernel's instruction set: `items.iter().any(…)` was left out of line,
/// a generic function built for the baseline target (SSE2 code called
/// from the AVX kernels). `AVX` (only inside the kernels compiled with
/// AVX, as `traverse::box_test`): triangle packets are tested two at a
/// time, in eight lanes, with the same answer.
#[inline(always)]
pub(crate) fn any_leaf<P: Primitive, const AVX: bool>(
    items: &[P],
    ctx: &RayCtx,
    t_max: f32,
) -> bool {
    #[cfg(target_arch = "x86_64")]
    if AVX && let Some(tris) = P::as_tri_packets(items) {
        // SAFETY: `AVX` is instantiated only inside the kernels compiled
        // with AVX, entered only where `Isa::is_available` found it.
        return unsafe { crate::tri_packet::any_x8(tris, ctx, t_max) };
    }
    for item in items {
        if item.any(ctx, t_max) {
            return true;
        }
    }
    false
}

/// A leaf item: one or more primitives tested together. Implemented by
/// [`crate::TriPacket`], [`SphereItem`] and [`CapsuleItem`]; sealed.
pub trait Primitive: bytemuck::Pod + Sealed {
    /// The kind reported in hits.
    const KIND: PrimKind;
    /// Tag stored in serialized BVHs.
    const TAG: u32;

    /// Offers every hit of this item with `t ∈ [t_min, best.t]` to `best`.
    fn closest(&self, item: u32, ray: &RayCtx, best: &mut BestHit);
    /// Whether any primitive of the item is hit with `t ∈ [t_min, t_max]`.
    fn any(&self, ray: &RayCtx, t_max: f32) -> bool;
    /// The full hit record for `lane`, whose hit at parameter `t` was found
    /// by [`Primitive::closest`] for `ray`: the same `t`, and the rest as
    /// the primitive's scalar test computes it.
    fn hit(&self, lane: u32, ray: &Ray, t: f32) -> Option<Hit>;
    /// The box around the item's primitives.
    fn bounds(&self) -> Aabb;
    /// Whether the item's data are well formed, with primitive ids below
    /// `prim_count` (checked when loading bytes).
    fn is_well_formed(&self, prim_count: u32) -> bool;
}

/// A sphere with its primitive index, as stored in leaves.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct SphereItem {
    /// The sphere.
    pub sphere: Sphere,
    /// Index in the input list.
    pub prim: u32,
    /// Padding to 32 bytes; always 0.
    pub pad: [u32; 3],
}

/// A capsule with its primitive index, as stored in leaves.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct CapsuleItem {
    /// The capsule.
    pub capsule: Capsule,
    /// Index in the input list.
    pub prim: u32,
    /// Padding to 48 bytes; always 0.
    pub pad: [u32; 3],
}

impl Sealed for SphereItem {}
impl Sealed for CapsuleItem {}

impl Primitive for SphereItem {
    const KIND: PrimKind = PrimKind::Sphere;
    const TAG: u32 = 2;

    #[inline]
    fn closest(&self, item: u32, ray: &RayCtx, best: &mut BestHit) {
        let r = Ray::with_range(ray.ray.origin, ray.ray.direction, ray.ray.t_min, best.t);
        if let Some(t) = intersect_sphere_t(&r, &self.sphere) {
            best.offer(t, self.prim, item, 0);
        }
    }

    #[inline]
    fn any(&self, ray: &RayCtx, t_max: f32) -> bool {
        let r = Ray::with_range(ray.ray.origin, ray.ray.direction, ray.ray.t_min, t_max);
        intersect_sphere_t(&r, &self.sphere).is_some()
    }

    fn hit(&self, _lane: u32, ray: &Ray, t: f32) -> Option<Hit> {
        let r = Ray { t_max: t, ..*ray };
        intersect_sphere(&r, &self.sphere, self.prim)
    }

    fn bounds(&self) -> Aabb {
        self.sphere.bounds()
    }

    fn is_well_formed(&self, prim_count: u32) -> bool {
        self.sphere.is_valid() && self.prim < prim_count
    }
}

impl Primitive for CapsuleItem {
    const KIND: PrimKind = PrimKind::Capsule;
    const TAG: u32 = 3;

    #[inline]
    fn closest(&self, item: u32, ray: &RayCtx, best: &mut BestHit) {
        let r = Ray::with_range(ray.ray.origin, ray.ray.direction, ray.ray.t_min, best.t);
        if let Some(t) = intersect_capsule_t(&r, &self.capsule) {
            best.offer(t, self.prim, item, 0);
        }
    }

    #[inline]
    fn any(&self, ray: &RayCtx, t_max: f32) -> bool {
        let r = Ray::with_range(ray.ray.origin, ray.ray.direction, ray.ray.t_min, t_max);
        intersect_capsule_t(&r, &self.capsule).is_some()
    }

    fn hit(&self, _lane: u32, ray: &Ray, t: f32) -> Option<Hit> {
        let r = Ray { t_max: t, ..*ray };
        intersect_capsule(&r, &self.capsule, self.prim)
    }

    fn bounds(&self) -> Aabb {
        self.capsule.bounds()
    }

    fn is_well_formed(&self, prim_count: u32) -> bool {
        self.capsule.is_valid() && self.prim < prim_count
    }
}

/// Items that wrap one shape (sphere, capsule) with its primitive index:
/// lets building and refitting share one code path.
#[cfg(feature = "alloc")]
pub(crate) trait ShapeItem: Primitive {
    /// The wrapped shape.
    type Shape: Copy;
    /// The item for shape `prim`.
    #[cfg_attr(not(feature = "obvhs"), allow(dead_code, reason = "used by the builder"))]
    fn wrap(shape: Self::Shape, prim: u32) -> Self;
    /// Replaces the shape (refit).
    fn set_shape(&mut self, shape: Self::Shape);
    /// The primitive index.
    fn prim(&self) -> u32;
    /// Whether the shape is finite with a positive radius.
    fn shape_is_valid(shape: &Self::Shape) -> bool;
}

#[cfg(feature = "alloc")]
impl ShapeItem for SphereItem {
    type Shape = Sphere;
    fn wrap(sphere: Sphere, prim: u32) -> Self {
        Self { sphere, prim, pad: [0; 3] }
    }
    fn set_shape(&mut self, shape: Sphere) {
        self.sphere = shape;
    }
    fn prim(&self) -> u32 {
        self.prim
    }
    fn shape_is_valid(shape: &Sphere) -> bool {
        shape.is_valid()
    }
}

#[cfg(feature = "alloc")]
impl ShapeItem for CapsuleItem {
    type Shape = Capsule;
    fn wrap(capsule: Capsule, prim: u32) -> Self {
        Self { capsule, prim, pad: [0; 3] }
    }
    fn set_shape(&mut self, shape: Capsule) {
        self.capsule = shape;
    }
    fn prim(&self) -> u32 {
        self.prim
    }
    fn shape_is_valid(shape: &Capsule) -> bool {
        shape.is_valid()
    }
}
