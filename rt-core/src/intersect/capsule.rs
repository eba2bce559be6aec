//! Ray–capsule intersection: tubes with round caps for streamlines and
//! line glyphs.
//!
//! A capsule is the set of points within `r` of the segment `p0 p1`: a
//! finite cylinder plus a sphere at each end. The candidates are the two
//! roots of the infinite cylinder (kept where the closest axis point lies
//! inside the segment) and the roots of each end sphere (kept beyond its
//! end); the smallest in range wins, so rays starting inside also find the
//! exit. Every quadratic is solved in the stable form of
//! [`super::solve_quadratic`].

use glam::{Vec2, Vec3};

use super::sphere::sphere_roots;
use crate::{
    Aabb, Hit, PrimKind, Ray,
    math::{atan2, gamma, sqrt},
};

/// A capsule: segment `p0 → p1` swept by a sphere of `radius`.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Capsule {
    /// Start of the axis.
    pub p0: Vec3,
    /// Radius, finite and `> 0` for a valid capsule.
    pub radius: f32,
    /// End of the axis (may equal `p0`: a sphere).
    pub p1: Vec3,
    /// Padding that keeps the layout `Pod`; always 0.
    pub pad: f32,
}

impl Capsule {
    /// A capsule from its axis end points and radius.
    #[inline]
    #[must_use]
    pub const fn new(p0: Vec3, p1: Vec3, radius: f32) -> Self {
        Self { p0, radius, p1, pad: 0.0 }
    }

    /// Whether the end points are finite and the radius finite and positive.
    #[inline]
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.p0.is_finite() && self.p1.is_finite() && self.radius.is_finite() && self.radius > 0.0
    }

    /// The bounding box: the union of the end spheres' boxes.
    #[inline]
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius);
        Aabb::new(self.p0 - r, self.p0 + r).union(Aabb::new(self.p1 - r, self.p1 + r))
    }

    /// Axial parameter `s ∈ [0, 1]` of the axis point closest to `p`.
    #[inline]
    #[must_use]
    pub fn axial(&self, p: Vec3) -> f32 {
        let ba = self.p1 - self.p0;
        let l2 = ba.length_squared();
        if l2 > 0.0 { ((p - self.p0).dot(ba) / l2).clamp(0.0, 1.0) } else { 0.0 }
    }
}

/// The smallest ray parameter in `[ray.t_min, ray.t_max]` where the ray meets
/// the capsule's surface, or `None`.
#[must_use]
pub fn intersect_capsule_t(ray: &Ray, cap: &Capsule) -> Option<f32> {
    let ba = cap.p1 - cap.p0;
    let oa = ray.origin - cap.p0;
    let d = ray.direction;
    let baba = ba.length_squared();
    let mut best: Option<f32> = None;
    let bounds = cap.bounds();
    let mut keep = |t: f32| {
        // `t < ∞`: roots overflow for radii near `f32::MAX`; no hit there.
        if t >= ray.t_min
            && t <= ray.t_max
            && t < f32::INFINITY
            && best.is_none_or(|b| t < b)
            && bounds.admits_hit(ray, t)
        {
            best = Some(t);
        }
    };
    if baba > 0.0 {
        // Infinite cylinder about the axis: the sphere equation with the
        // axial parts of origin and direction projected out.
        let axis = ba / sqrt(baba);
        let dp = d - d.dot(axis) * axis;
        let op = oa - oa.dot(axis) * axis;
        if let Some((t0, t1)) = sphere_roots(op, dp, cap.radius) {
            for t in [t0, t1] {
                let y = (oa + t * d).dot(ba);
                if y >= 0.0 && y <= baba {
                    keep(t);
                }
            }
        }
    }
    // End spheres, each kept only beyond its end of the segment.
    for (center, beyond_p1) in [(cap.p0, false), (cap.p1, true)] {
        if let Some((t0, t1)) = sphere_roots(ray.origin - center, d, cap.radius) {
            for t in [t0, t1] {
                let y = (oa + t * d).dot(ba);
                if (beyond_p1 && y >= baba) || (!beyond_p1 && y <= 0.0) {
                    keep(t);
                }
            }
        }
    }
    best
}

/// Full hit record for a capsule: the hit point is re-projected onto the
/// surface around its closest axis point, with a `γ(6)`-scaled error bound.
/// `uv` = (axial `s ∈ [0, 1]`, azimuth in radians about the axis).
#[must_use]
pub fn intersect_capsule(ray: &Ray, cap: &Capsule, prim: u32) -> Option<Hit> {
    if !ray.is_valid() || !cap.is_valid() {
        return None;
    }
    let t = intersect_capsule_t(ray, cap)?;
    let p = ray.at(t);
    let s = cap.axial(p);
    let center = cap.p0 + s * (cap.p1 - cap.p0);
    let normal = (p - center).normalize_or_zero();
    let local = normal * cap.radius;
    let axis = (cap.p1 - cap.p0).normalize_or(Vec3::Z);
    let (e1, e2) = axis.any_orthonormal_pair();
    let mut phi = atan2(local.dot(e2), local.dot(e1));
    if phi < 0.0 {
        phi += core::f32::consts::TAU;
    }
    Some(Hit {
        t,
        prim,
        kind: PrimKind::Capsule,
        uv: Vec2::new(s, phi),
        normal,
        position: center + local,
        position_error: gamma(6) * (cap.p0.abs() + cap.p1.abs() + local.abs()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by the `intersect` fuzz target: a radius of `f32::MAX` made a
    /// root overflow, and the capsule reported a hit at `t = ∞`.
    #[test]
    fn fuzz_regression_no_hit_at_infinity() {
        let cap = Capsule {
            p0: Vec3::new(0.0, -1.0, 3.875),
            radius: f32::MAX,
            p1: Vec3::new(3.875, -3.75, 0.0),
            pad: 0.0,
        };
        let ray = Ray::new(Vec3::new(1.9375, 1.9375, 1.3125), Vec3::new(1.9375, -2.875, -3.75));
        assert!(intersect_capsule_t(&ray, &cap).is_none_or(|t| t.is_finite()));
        let s = crate::intersect::Sphere { center: cap.p0, radius: f32::MAX };
        assert!(crate::intersect::intersect_sphere_t(&ray, &s).is_none_or(|t| t.is_finite()));
    }

    fn cap() -> Capsule {
        Capsule::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), 0.5)
    }

    #[test]
    fn body_cap_and_inside() {
        let c = cap();
        let body = Ray::new(Vec3::new(3.0, 0.0, 1.0), Vec3::NEG_X);
        assert!((intersect_capsule_t(&body, &c).unwrap() - 2.5).abs() < 1e-6);
        let top = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
        assert!((intersect_capsule_t(&top, &c).unwrap() - 2.5).abs() < 1e-6);
        let bottom = Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::Z);
        assert!((intersect_capsule_t(&bottom, &c).unwrap() - 4.5).abs() < 1e-6);
        let inside = Ray::new(Vec3::new(0.0, 0.0, 1.0), Vec3::X);
        assert!((intersect_capsule_t(&inside, &c).unwrap() - 0.5).abs() < 1e-6);
        let h = intersect_capsule(&body, &c, 3).unwrap();
        assert!((h.normal - Vec3::X).length() < 1e-6);
        assert!((h.uv.x - 0.5).abs() < 1e-6);
    }

    #[test]
    fn misses() {
        let c = cap();
        // Passes beside the body.
        let r = Ray::new(Vec3::new(3.0, 0.6, 1.0), Vec3::NEG_X);
        assert!(intersect_capsule_t(&r, &c).is_none());
        // Passes above the top cap, parallel to the axis offset.
        let r = Ray::new(Vec3::new(0.0, 0.0, 2.6), Vec3::X);
        assert!(intersect_capsule_t(&r, &c).is_none());
        // Ray parallel to the axis, outside the radius.
        let r = Ray::new(Vec3::new(0.7, 0.0, 5.0), Vec3::NEG_Z);
        assert!(intersect_capsule_t(&r, &c).is_none());
    }

    #[test]
    fn zero_length_axis_is_a_sphere() {
        let c = Capsule::new(Vec3::ONE, Vec3::ONE, 1.0);
        let r = Ray::new(Vec3::new(1.0, 1.0, 4.0), Vec3::NEG_Z);
        assert!((intersect_capsule_t(&r, &c).unwrap() - 2.0).abs() < 1e-6);
    }
}
