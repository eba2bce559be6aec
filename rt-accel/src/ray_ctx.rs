//! Per-ray constants shared by the box tests and the leaf tests.

use rt_core::{
    Ray,
    internal::{FAR_INV_SCALE, SLAB_FAR_SCALE, SLAB_FAR_SCALE_NEG, widen_far},
    intersect::WatertightRay,
};

use crate::simd::F32x4;

/// Everything a traversal precomputes once per ray: the reciprocal
/// direction, the near/far plane selection by direction sign, and the
/// watertight triangle shear. Scalars only (100 bytes): kernels broadcast
/// them into SIMD lanes where they use them, which costs one load each,
/// while splatting them here made the context five times larger and its
/// construction a third of a missed ray's cost.
#[derive(Clone, Copy, Debug)]
pub struct RayCtx {
    pub(crate) ray: Ray,
    /// Reciprocal direction per axis (`±∞` for `±0`).
    pub(crate) inv1: glam::Vec3,
    /// The far planes' reciprocal: `inv1 · FAR_INV_SCALE` for rays with
    /// `t_min ≥ 0` ([`rt_core::internal::FAR_INV_SCALE`]), else `inv1`.
    pub(crate) inv_far: glam::Vec3,
    /// The factors that widen the smallest far distance upward and
    /// downward (`max` of the two products, [`widen_far`]): the Ize
    /// scales for rays with `t_min < 0`, `1` for the others (whose far
    /// distances are widened by `inv_far` already). Box tests that do not
    /// know a ray's kind use them; those that know skip them (`NONNEG`).
    pub(crate) far_up: f32,
    /// See `far_up`.
    pub(crate) far_down: f32,
    /// Row of `Node::bounds` holding the near plane per axis (by sign bit).
    pub(crate) near: [u8; 3],
    /// Row holding the far plane per axis.
    pub(crate) far: [u8; 3],
    /// Watertight shear constants for triangles.
    pub(crate) wt: WatertightRay,
    /// Origin permuted to `[kx, ky, kz]`.
    pub(crate) wt_org: glam::Vec3,
}

impl RayCtx {
    /// The constants for `ray`, or `None` if the ray is not valid
    /// ([`Ray::is_valid`]): such rays miss everything. Always inlined, so
    /// the single-ray kernels keep the constants in registers.
    #[inline(always)]
    #[must_use]
    pub fn new(ray: &Ray) -> Option<Self> {
        if !ray.is_valid() {
            return None;
        }
        let o = ray.origin;
        let d = ray.direction;
        let sel = |a: u8| {
            let neg = u8::from(d[usize::from(a)].is_sign_negative());
            (2 * a + neg, 2 * a + 1 - neg)
        };
        let (nx, fx) = sel(0);
        let (ny, fy) = sel(1);
        let (nz, fz) = sel(2);
        let wt = WatertightRay::new(ray);
        let nonneg = ray.t_min >= 0.0;
        let [kx, ky, kz] = wt.axes;
        Some(Self {
            ray: *ray,
            inv1: d.recip(),
            inv_far: if nonneg { d.recip() * FAR_INV_SCALE } else { d.recip() },
            far_up: if nonneg { 1.0 } else { SLAB_FAR_SCALE },
            far_down: if nonneg { 1.0 } else { SLAB_FAR_SCALE_NEG },
            near: [nx, ny, nz],
            far: [fx, fy, fz],
            wt,
            wt_org: glam::Vec3::new(o[kx], o[ky], o[kz]),
        })
    }

    /// The origin per axis, splatted.
    #[inline(always)]
    pub(crate) fn org4(&self, a: usize) -> F32x4 {
        F32x4::splat(self.ray.origin[a])
    }

    /// The reciprocal direction per axis, splatted.
    #[inline(always)]
    pub(crate) fn inv4(&self, a: usize) -> F32x4 {
        F32x4::splat(self.inv1[a])
    }

    /// The far planes' reciprocal per axis (see [`FAR_INV_SCALE`]), splatted.
    #[inline(always)]
    pub(crate) fn inv_far4(&self, a: usize) -> F32x4 {
        F32x4::splat(self.inv_far[a])
    }

    /// [`rt_core::Aabb::admits_hit`] for the box `lo..hi` and this ray,
    /// with the same arithmetic (so the same answer, bit for bit) but
    /// without recomputing the reciprocal direction or checking the ray.
    #[inline(always)]
    #[must_use]
    pub(crate) fn admits_hit(&self, lo: glam::Vec3, hi: glam::Vec3, t: f32) -> bool {
        let (o, d) = (self.ray.origin, self.ray.direction);
        let nonneg = self.ray.t_min >= 0.0;
        let mut t0 = self.ray.t_min;
        let mut t1 = widen_far(t);
        for a in 0..3 {
            let (near, far) = if d[a].is_sign_negative() { (hi[a], lo[a]) } else { (lo[a], hi[a]) };
            let near = (near - o[a]) * self.inv1[a];
            let far = (far - o[a]) * self.inv_far[a];
            let far = if nonneg { far } else { widen_far(far) };
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
        let (near, far) = (usize::from(self.near[a]), usize::from(self.far[a]));
        debug_assert!(near < 6 && far < 6);
        // SAFETY: `RayCtx::new`, the only constructor, sets every `near`
        // and `far` entry to `2·axis` or `2·axis + 1` with `axis < 3`.
        unsafe { (bounds.get_unchecked(near), bounds.get_unchecked(far)) }
    }

    /// The ray these constants were made for.
    #[inline]
    #[must_use]
    pub fn ray(&self) -> &Ray {
        &self.ray
    }
}
