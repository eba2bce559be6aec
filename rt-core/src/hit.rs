//! Hit records and the scene query seam.

use glam::{Vec2, Vec3};

use crate::Ray;

/// Which kind of primitive a [`Hit`] refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum PrimKind {
    /// A triangle; `uv` holds barycentrics `(b1, b2)` of vertices 1 and 2.
    Triangle = 0,
    /// A sphere; `uv` holds (azimuth `φ ∈ [0, 2π)`, polar `θ ∈ [0, π]`) in radians.
    Sphere = 1,
    /// A capsule (tube with round caps); `uv` holds (axial position `s ∈ [0, 1]`
    /// of the closest axis point, azimuth in radians).
    Capsule = 2,
}

/// A ray–primitive intersection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit; the depth every frame stores.
    pub t: f32,
    /// Index of the primitive within its kind's input list.
    pub prim: u32,
    /// The kind of primitive hit.
    pub kind: PrimKind,
    /// Local surface coordinates; meaning per [`PrimKind`].
    pub uv: Vec2,
    /// Unit geometric normal; for triangles `(v1 − v0) × (v2 − v0)`
    /// normalised (counter-clockwise front faces), not flipped toward the ray.
    pub normal: Vec3,
    /// Hit point, computed from the surface (barycentrics, re-projection onto
    /// the sphere) rather than `ray.at(t)`, which is less accurate.
    pub position: Vec3,
    /// Per-axis bound on the absolute rounding error of `position`, for
    /// [`crate::offset_ray_origin`].
    pub position_error: Vec3,
}

/// What shading code asks of a scene: closest hit and occlusion.
///
/// `rt-core` knows no acceleration structure; `rt-accel` implements this for
/// its BVH, and a brute-force loop implements it in tests.
pub trait SceneQuery {
    /// The closest hit with `t` in `[ray.t_min, ray.t_max]`, or `None`.
    fn closest_hit(&self, ray: &Ray) -> Option<Hit>;
    /// Whether anything is hit with `t` in `[ray.t_min, ray.t_max]`; may stop
    /// at the first hit found.
    fn occluded(&self, ray: &Ray) -> bool;
    /// [`SceneQuery::closest_hit`] of eight rays at once, `out[i]` equal to
    /// `closest_hit(&rays[i])`. Scenes that trace coherent rays together
    /// (rt-accel's packets) override it; the default asks ray by ray.
    fn closest_hit_packet(&self, rays: &[Ray; 8]) -> [Option<Hit>; 8] {
        core::array::from_fn(|i| self.closest_hit(&rays[i]))
    }
    /// [`SceneQuery::closest_hit`] of many rays: `out[i] =
    /// closest_hit(&rays[i])` for every `i` below the shorter of the two
    /// lengths. Scenes that walk coherent rays through the tree together
    /// (rt-accel's closest-hit streams) override it; the default asks ray
    /// by ray. Renderers hand over a tile's camera rays at once.
    fn closest_hit_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        for (ray, o) in rays.iter().zip(out) {
            *o = self.closest_hit(ray);
        }
    }
    /// [`SceneQuery::occluded`] of many rays: `out[i] = occluded(&rays[i])`
    /// for every `i` below the shorter of the two lengths. Scenes that walk
    /// rays through the tree together (rt-accel's occlusion streams)
    /// override it; the default asks ray by ray. Shading code whose later
    /// work does not depend on the answers (shadow and AO rays) gathers
    /// its rays and asks once.
    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        for (ray, o) in rays.iter().zip(out) {
            *o = self.occluded(ray);
        }
    }
}
