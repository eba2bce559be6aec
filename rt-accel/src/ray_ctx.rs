//! Per-ray constants shared by the box tests and the leaf tests.

use rt_core::{
    Ray,
    internal::{SLAB_FAR_SCALE, SLAB_FAR_SCALE_NEG, widen_far},
    intersect::WatertightRay,
};

use crate::simd::F32x4;

/// Everything a traversal precomputes once per ray: splatted origin and
/// reciprocal direction, the near/far plane selection by direction sign, and
/// the watertight triangle shear.
#[derive(Clone, Copy, Debug)]
pub struct RayCtx {
    pub(crate) ray: Ray,
    /// Origin per axis, splatted.
    pub(crate) org: [F32x4; 3],
    /// Reciprocal direction per axis (`±∞` for `±0`).
    pub(crate) inv1: glam::Vec3,
    /// Reciprocal direction per axis, splatted.
    pub(crate) inv: [F32x4; 3],
    /// Row of `Node::bounds` holding the near plane per axis (by sign bit).
    pub(crate) near: [usize; 3],
    /// Row holding the far plane per axis.
    pub(crate) far: [usize; 3],
    /// `1 ± 2γ(3)`: far distances are widened outward by rounding bounds.
    pub(crate) far_up: F32x4,
    pub(crate) far_down: F32x4,
    pub(crate) t_min: F32x4,
    /// Watertight shear constants for triangles.
    pub(crate) wt: WatertightRay,
    /// Origin permuted to `[kx, ky, kz]`, splatted.
    pub(crate) wt_org: [F32x4; 3],
    /// `(Sx, Sy, Sz)` splatted.
    pub(crate) wt_shear: [F32x4; 3],
}

impl RayCtx {
    /// The constants for `ray`, or `None` if the ray is not valid
    /// ([`Ray::is_valid`]): such rays miss everything.
    #[inline]
    #[must_use]
    pub fn new(ray: &Ray) -> Option<Self> {
        if !ray.is_valid() {
            return None;
        }
        let o = ray.origin;
        let d = ray.direction;
        let inv = d.recip();
        let sel = |a: usize| {
            let neg = usize::from(d[a].is_sign_negative());
            (2 * a + neg, 2 * a + 1 - neg)
        };
        let (nx, fx) = sel(0);
        let (ny, fy) = sel(1);
        let (nz, fz) = sel(2);
        let wt = WatertightRay::new(ray);
        let [kx, ky, kz] = wt.axes;
        Some(Self {
            ray: *ray,
            inv1: inv,
            org: [F32x4::splat(o.x), F32x4::splat(o.y), F32x4::splat(o.z)],
            inv: [F32x4::splat(inv.x), F32x4::splat(inv.y), F32x4::splat(inv.z)],
            near: [nx, ny, nz],
            far: [fx, fy, fz],
            far_up: F32x4::splat(SLAB_FAR_SCALE),
            far_down: F32x4::splat(SLAB_FAR_SCALE_NEG),
            t_min: F32x4::splat(ray.t_min),
            wt,
            wt_org: [F32x4::splat(o[kx]), F32x4::splat(o[ky]), F32x4::splat(o[kz])],
            wt_shear: [
                F32x4::splat(wt.shear.x),
                F32x4::splat(wt.shear.y),
                F32x4::splat(wt.shear.z),
            ],
        })
    }

    /// [`rt_core::Aabb::admits_hit`] for the box `lo..hi` and this ray,
    /// with the same arithmetic (so the same answer, bit for bit) but
    /// without recomputing the reciprocal direction or checking the ray.
    #[inline(always)]
    #[must_use]
    pub(crate) fn admits_hit(&self, lo: glam::Vec3, hi: glam::Vec3, t: f32) -> bool {
        let (o, d) = (self.ray.origin, self.ray.direction);
        let mut t0 = self.ray.t_min;
        let mut t1 = widen_far(t);
        for a in 0..3 {
            let (near, far) = if d[a].is_sign_negative() { (hi[a], lo[a]) } else { (lo[a], hi[a]) };
            let near = (near - o[a]) * self.inv1[a];
            let far = widen_far((far - o[a]) * self.inv1[a]);
            // `x > t0` is false for NaN, so NaN leaves the bound alone.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        t0 <= t1
    }

    /// The near and far plane rows of `bounds` (a node's) for axis `a`.
    #[inline(always)]
    pub(crate) fn planes<'b, T>(&self, bounds: &'b [T; 6], a: usize) -> (&'b T, &'b T) {
        debug_assert!(self.near[a] < 6 && self.far[a] < 6);
        // SAFETY: `RayCtx::new`, the only constructor, sets every `near`
        // and `far` entry to `2·axis` or `2·axis + 1` with `axis < 3`.
        unsafe { (bounds.get_unchecked(self.near[a]), bounds.get_unchecked(self.far[a])) }
    }

    /// The ray these constants were made for.
    #[inline]
    #[must_use]
    pub fn ray(&self) -> &Ray {
        &self.ray
    }
}
