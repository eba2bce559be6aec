//! Axis-aligned boxes and the conservative slab test.

use glam::{Vec3, Vec3A};

use crate::{Ray, math::gamma};

/// An axis-aligned box `[min, max]`, closed on both ends.
///
/// [`Aabb::EMPTY`] (min `+∞`, max `−∞`) contains nothing and is the identity
/// of [`Aabb::union`].
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

/// `1 + 2γ(3)`: scaling a positive far slab distance by this makes the slab
/// test conservative under f32 rounding (Ize 2013, "Robust BVH Ray
/// Traversal"); see [`widen_far`] for the signed form.
pub const SLAB_FAR_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// `1 − 2γ(3)`: the scale that widens a *negative* far distance.
pub const SLAB_FAR_SCALE_NEG: f32 = 1.0 - 2.0 * gamma(3);

/// `1 + 8u` (`u = 2⁻²⁴`, exact in f32): for rays with `t_min ≥ 0`, the
/// far slab distances are computed with the reciprocal direction scaled by
/// this instead of being widened one by one (as Embree's robust kernels
/// do). A BVH traversal can then test a node with one compare and no
/// multiply per box (`rt-accel`).
///
/// Why it is conservative: the far distance `fl(fl(b − o) · fl(fl(1/d) ·
/// S))` has four roundings, so for an exact distance `T₁ ≥ 0` it is at
/// least `T₁·S·(1 − u)⁴`; the near distance, with three, is at most
/// `T₀·(1 + u)³` for `T₀ ≥ 0`. A box the ray enters (`T₀ ≤ T₁`) passes
/// whenever `S·(1 − u)⁴ ≥ (1 + u)³`, which `1 + 8u` meets (`1 + 4u −
/// O(u²)` against `1 + 3u + O(u²)`; the bound, as Ize's, is for distances
/// in the normal range). A negative `T₁` is computed negative (rounding keeps
/// signs), below any `t₀ ≥ t_min ≥ 0`, so the sign-dependent widening of
/// [`widen_far`] is not needed. It must stay the same number wherever the
/// slab test is computed: a BVH finds exactly a brute-force loop's hits
/// because its node test and the primitives' box check
/// ([`Aabb::admits_hit`]) do the same arithmetic.
pub const FAR_INV_SCALE: f32 = 1.0 + 8.0 * (f32::EPSILON * 0.5);

/// A far slab distance moved outward by its rounding bound, whatever its
/// sign: `max(t·(1 + 2γ(3)), t·(1 − 2γ(3)))`.
#[inline]
#[must_use]
pub fn widen_far(t: f32) -> f32 {
    let (a, b) = (t * SLAB_FAR_SCALE, t * SLAB_FAR_SCALE_NEG);
    if a > b { a } else { b }
}

impl Aabb {
    /// The empty box.
    pub const EMPTY: Self = Self { min: Vec3::INFINITY, max: Vec3::NEG_INFINITY };

    /// A box from its corners (not reordered).
    #[inline]
    #[must_use]
    pub const fn new(min: Vec3, max: Vec3) -> Self {
        Self { min, max }
    }

    /// The smallest box holding every point (empty for no points).
    #[must_use]
    pub fn from_points(points: &[Vec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.grow(p))
    }

    /// The box grown to hold `p`.
    #[inline]
    #[must_use]
    pub fn grow(self, p: Vec3) -> Self {
        Self { min: min3(self.min, p), max: max3(self.max, p) }
    }

    /// The smallest box holding both.
    #[inline]
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        Self { min: min3(self.min, other.min), max: max3(self.max, other.max) }
    }

    /// Whether the box holds no point (`min > max` on some axis, or NaN).
    #[inline]
    #[must_use]
    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    /// Whether `p` is inside or on the boundary.
    #[inline]
    #[must_use]
    pub fn contains(&self, p: Vec3) -> bool {
        self.min.cmple(p).all() && p.cmple(self.max).all()
    }

    /// Centre point.
    #[inline]
    #[must_use]
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// `max − min`.
    #[inline]
    #[must_use]
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    /// Half the surface area (the SAH cost weight); 0 for an empty box.
    #[inline]
    #[must_use]
    pub fn half_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// Whether a hit at parameter `t` is consistent with this box, the box of
    /// the primitive hit: the robust slab test admits the ray within
    /// `[ray.t_min, widen_far(t)]`. Intersection tests apply this to their
    /// hits, so a hit never lies outside its primitive's box by rounding;
    /// then a BVH, whose boxes contain the primitives' boxes and whose
    /// culling uses the same test, finds exactly the hits a brute-force loop
    /// finds.
    #[inline]
    #[must_use]
    pub fn admits_hit(&self, ray: &Ray, t: f32) -> bool {
        self.intersect_ray(&Ray { t_max: widen_far(t), ..*ray }).is_some()
    }

    /// The parameter interval `[t0, t1]` where `ray` is inside the box,
    /// clipped to the ray's `[t_min, t_max]`, or `None`.
    ///
    /// The slab test of Kay and Kajiya made robust as Ize (2013) shows: the
    /// far distance is scaled by [`SLAB_FAR_SCALE`] so rounding never causes
    /// a false miss (for negative distances too, see [`widen_far`]); for
    /// rays with `t_min ≥ 0` the reciprocal of the far planes is scaled by
    /// [`FAR_INV_SCALE`] instead. Direction components of `±0.0` give reciprocals of `±∞`;
    /// the slab near/far planes are chosen by the sign *bit*, so `−0.0` is
    /// handled like any negative direction. A ray lying exactly in a slab's
    /// plane gives `0·∞ = NaN` for that plane; the comparisons below are
    /// written so a NaN distance never narrows the interval (the box is
    /// closed, so such a ray touches it).
    #[inline]
    #[must_use]
    pub fn intersect_ray(&self, ray: &Ray) -> Option<(f32, f32)> {
        if !ray.is_valid() {
            return None;
        }
        // Three lanes at once and no branch on the direction's signs
        // (secondary rays leave surfaces every way, so branches on them
        // mispredict): the same operations, lane by lane, as one axis at a
        // time, so the same answer bit for bit.
        let (o, d) = (Vec3A::from(ray.origin), Vec3A::from(ray.direction));
        let inv = d.recip();
        let nonneg = ray.t_min >= 0.0;
        let inv_far = if nonneg { inv * FAR_INV_SCALE } else { inv };
        // The sign *bit* picks the planes: −0.0 counts as negative.
        let neg = Vec3A::ONE.copysign(d).cmplt(Vec3A::ZERO);
        let (min, max) = (Vec3A::from(self.min), Vec3A::from(self.max));
        let near = (Vec3A::select(neg, max, min) - o) * inv;
        let far = (Vec3A::select(neg, min, max) - o) * inv_far;
        // `x > t0` is false for NaN, so NaN leaves the bound alone.
        let (mut t0, mut t1) = (ray.t_min, ray.t_max);
        for a in 0..3 {
            let f = if nonneg { far[a] } else { widen_far(far[a]) };
            if near[a] > t0 {
                t0 = near[a];
            }
            if f < t1 {
                t1 = f;
            }
        }
        (t0 <= t1).then_some((t0, t1))
    }
}

/// Component-wise minimum that never depends on NaN propagation rules: a
/// NaN in `b` leaves `a`'s component.
#[inline]
fn min3(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(
        if b.x < a.x { b.x } else { a.x },
        if b.y < a.y { b.y } else { a.y },
        if b.z < a.z { b.z } else { a.z },
    )
}

/// Component-wise maximum; a NaN in `b` leaves `a`'s component.
#[inline]
fn max3(a: Vec3, b: Vec3) -> Vec3 {
    Vec3::new(
        if b.x > a.x { b.x } else { a.x },
        if b.y > a.y { b.y } else { a.y },
        if b.z > a.z { b.z } else { a.z },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_parallel_rays_with_signed_zero() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        // Inside the y/z slabs, direction along -x with +0 and -0 components.
        for d in [Vec3::new(-1.0, 0.0, -0.0), Vec3::new(-1.0, -0.0, 0.0)] {
            let r = Ray::new(Vec3::new(2.0, 0.5, 0.5), d);
            let (t0, t1) = b.intersect_ray(&r).expect("hit");
            // `t1` is widened outward by a few ulps by design.
            assert!((t0 - 1.0).abs() < 1e-6 && (t1 - 2.0).abs() < 2e-6);
        }
        // Outside the y slab: must miss for both signs of zero.
        for d in [Vec3::new(-1.0, 0.0, 0.0), Vec3::new(-1.0, -0.0, 0.0)] {
            let r = Ray::new(Vec3::new(2.0, 1.5, 0.5), d);
            assert!(b.intersect_ray(&r).is_none());
        }
    }

    #[test]
    fn ray_in_face_plane_touches_closed_box() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        // Origin on the plane y = 1, moving parallel to it: 0·∞ = NaN case.
        for d in [Vec3::new(-1.0, 0.0, 0.0), Vec3::new(-1.0, -0.0, 0.0)] {
            let r = Ray::new(Vec3::new(2.0, 1.0, 0.5), d);
            assert!(b.intersect_ray(&r).is_some());
        }
    }

    #[test]
    fn far_scale_prevents_false_miss_on_flat_box() {
        // A flat box hit at a grazing distance: t0 == t1 exactly in reals.
        let b = Aabb::new(Vec3::new(0.1, -1.0, -1.0), Vec3::new(0.1, 1.0, 1.0));
        let r = Ray::new(Vec3::new(-0.3, 0.0, 0.0), Vec3::new(0.7, 0.1, 0.0));
        assert!(b.intersect_ray(&r).is_some());
    }

    #[test]
    fn flat_box_behind_the_origin_is_found_with_negative_t_min() {
        // The box lies at negative t; the far distance is negative and must
        // be widened toward +∞ (a plain scale by 1 + 2γ would shrink it).
        let b = Aabb::new(Vec3::new(-0.3, -1.0, -1.0), Vec3::new(-0.3, 1.0, 1.0));
        let r = Ray::with_range(Vec3::new(0.1, 0.0, 0.0), Vec3::new(0.7, 0.1, 0.0), -10.0, 10.0);
        assert!(b.intersect_ray(&r).is_some());
        assert_eq!(widen_far(-2.0), -2.0 * SLAB_FAR_SCALE_NEG);
        assert_eq!(widen_far(2.0), 2.0 * SLAB_FAR_SCALE);
    }

    #[test]
    fn invalid_rays_miss() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::ONE);
        let nan = Ray::new(Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X);
        let zero = Ray::new(Vec3::ZERO, Vec3::ZERO);
        let inf = Ray::new(Vec3::ZERO, Vec3::new(f32::INFINITY, 0.0, 0.0));
        assert!(b.intersect_ray(&nan).is_none());
        assert!(b.intersect_ray(&zero).is_none());
        assert!(b.intersect_ray(&inf).is_none());
    }

    /// Rays aimed at points on a box's edges, from all around it, enter
    /// the box within rounding of their exit: wherever the exact slab test
    /// (in f64, from the same f32 inputs) says they enter, the robust f32
    /// test must too, for `t_min ≥ 0` (widened through the reciprocal,
    /// [`FAR_INV_SCALE`]) and for `t_min < 0` (widened by sign). Without
    /// widening (a scale of 1) it fails; the worst case of the bound needs
    /// every rounding against it, which random rays seldom meet, so
    /// scales down to `1 + 2u` pass it too.
    #[test]
    fn grazing_rays_that_enter_in_exact_arithmetic_are_never_missed() {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut unit = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let (mut grazing, mut entered) = (0, 0);
        for _ in 0..200_000 {
            let scale = 10f32.powi((unit() * 8.0) as i32 - 4);
            let lo = Vec3::new(unit(), unit(), unit()) * scale;
            let b = Aabb::new(lo, lo + Vec3::new(unit(), unit(), unit()) * scale + 1e-3 * scale);
            // A point on one of the box's twelve edges.
            let (a, k) = ((unit() * 3.0) as usize % 3, (unit() * 4.0) as usize % 4);
            let mut p = b.min.lerp(b.max, unit());
            p[(a + 1) % 3] = if k & 1 == 0 { b.min[(a + 1) % 3] } else { b.max[(a + 1) % 3] };
            p[(a + 2) % 3] = if k & 2 == 0 { b.min[(a + 2) % 3] } else { b.max[(a + 2) % 3] };
            let o = b.center() + (Vec3::new(unit(), unit(), unit()) - 0.5) * 8.0 * scale;
            let d = p - o;
            for t_min in [0.0, -0.5] {
                let r = Ray::with_range(o, d, t_min, f32::INFINITY);
                // The exact interval, in f64 (differences of f32 values are
                // exact there; one division rounds, far below f32's ulp).
                let (mut t0, mut t1) = (f64::from(t_min), f64::INFINITY);
                for ax in 0..3 {
                    let (o, d) = (f64::from(o[ax]), f64::from(d[ax]));
                    let (l, h) = (f64::from(b.min[ax]), f64::from(b.max[ax]));
                    if d == 0.0 {
                        if o < l || o > h {
                            t0 = f64::INFINITY;
                        }
                        continue;
                    }
                    let (n, f) = ((l - o) / d, (h - o) / d);
                    t0 = t0.max(n.min(f));
                    t1 = t1.min(n.max(f));
                }
                if t0 <= t1 {
                    grazing += usize::from(t1 - t0 < 1e-6 * t1.abs().max(1e-30));
                    entered += 1;
                    assert!(b.intersect_ray(&r).is_some(), "{b:?} {r:?}: exact [{t0}, {t1}]");
                }
            }
        }
        // Most rays enter and a good share graze (exit within 1e-6 of entry).
        assert!(entered > 100_000 && grazing > 10_000, "{entered} {grazing}");
    }

    #[test]
    fn union_and_empty() {
        let a = Aabb::EMPTY.grow(Vec3::ONE).grow(-Vec3::ONE);
        assert_eq!(a, Aabb::new(-Vec3::ONE, Vec3::ONE));
        assert!(Aabb::EMPTY.is_empty());
        assert_eq!(Aabb::EMPTY.union(a), a);
        assert_eq!(a.grow(Vec3::NAN), a);
    }
}
