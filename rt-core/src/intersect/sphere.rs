//! Numerically stable ray–sphere intersection.
//!
//! With `f = o − c`, the roots of `a t² + 2b t + c' = 0` (`a = d·d`,
//! `b = f·d`, `c' = f·f − r²`) are taken in the form of Press et al.
//! (`q = −(b + sign(b)·√Δ)`, `t₀ = q/a`, `t₁ = c'/q`) so no root suffers
//! cancellation, and the discriminant is `a·(r² − |f − (b/a) d|²)` as in
//! Haines et al., "Precision Improvements for Ray/Sphere Intersection"
//! (Ray Tracing Gems, ch. 7), which stays accurate for far or tiny spheres.

use glam::{Vec2, Vec3};

use crate::{
    Aabb, Hit, PrimKind, Ray,
    math::{acos, atan2, gamma, sqrt},
};

/// A sphere.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius, finite and `> 0` for a valid sphere.
    pub radius: f32,
}

impl Sphere {
    /// A sphere from centre and radius.
    #[inline]
    #[must_use]
    pub const fn new(center: Vec3, radius: f32) -> Self {
        Self { center, radius }
    }

    /// The bounding box `centre ± radius`.
    #[inline]
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        let r = Vec3::splat(self.radius);
        Aabb::new(self.center - r, self.center + r)
    }

    /// Whether centre and radius are finite and the radius positive.
    #[inline]
    #[must_use]
    pub fn is_valid(&self) -> bool {
        self.center.is_finite() && self.radius.is_finite() && self.radius > 0.0
    }
}

/// Both roots of `a t² + 2 b t + c = 0` in ascending order, computed without
/// cancellation, or `None` when they are complex (or `a = 0`). `disc_over_a`
/// is `b² / a − c`, passed in so callers can use a more accurate form.
#[inline]
#[must_use]
pub fn solve_quadratic(a: f32, b: f32, c: f32, disc_over_a: f32) -> Option<(f32, f32)> {
    if disc_over_a.is_nan() || disc_over_a < 0.0 || a == 0.0 {
        return None;
    }
    let root = sqrt(a * disc_over_a);
    let q = if b < 0.0 { -b + root } else { -b - root };
    if q == 0.0 {
        let t = -b / a;
        return Some((t, t));
    }
    let (t0, t1) = (q / a, c / q);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// The smallest ray parameter in `[ray.t_min, ray.t_max]` where the ray meets
/// the sphere's surface (entering or leaving), or `None`.
#[inline]
#[must_use]
pub fn intersect_sphere_t(ray: &Ray, sphere: &Sphere) -> Option<f32> {
    let (t0, t1) = sphere_roots(ray.origin - sphere.center, ray.direction, sphere.radius)?;
    let b = sphere.bounds();
    first_in_range(ray, t0, t1, |t| b.admits_hit(ray, t))
}

/// Ascending roots of `|f + t·d| = r` (`f` = origin − centre), stable form.
#[inline]
pub(crate) fn sphere_roots(f: Vec3, d: Vec3, r: f32) -> Option<(f32, f32)> {
    let a = d.length_squared();
    let b = f.dot(d);
    let c = f.length_squared() - r * r;
    let v = f - (b / a) * d;
    solve_quadratic(a, b, c, r * r - v.length_squared())
}

/// The closest of two ascending roots inside the ray's interval that the
/// primitive's box admits ([`Aabb::admits_hit`]).
#[inline]
pub(crate) fn first_in_range(
    ray: &Ray,
    t0: f32,
    t1: f32,
    admits: impl Fn(f32) -> bool,
) -> Option<f32> {
    // `t < ∞`: roots overflow for radii near `f32::MAX`; no hit there.
    [t0, t1]
        .into_iter()
        .find(|&t| t >= ray.t_min && t <= ray.t_max && t < f32::INFINITY && admits(t))
}

/// Full hit record for a sphere: the hit point is re-projected onto the
/// surface (`c + r·(p − c)/|p − c|`), with error bound `γ(5)·|p|` (pbrt-v4
/// §6.8.5). `uv` = (azimuth φ, polar θ) about `+z`.
#[must_use]
pub fn intersect_sphere(ray: &Ray, sphere: &Sphere, prim: u32) -> Option<Hit> {
    if !ray.is_valid() || !sphere.is_valid() {
        return None;
    }
    let t = intersect_sphere_t(ray, sphere)?;
    let local = ray.at(t) - sphere.center;
    let normal = local.normalize_or_zero();
    let local = normal * sphere.radius;
    let position = sphere.center + local;
    let mut phi = atan2(local.y, local.x);
    if phi < 0.0 {
        phi += core::f32::consts::TAU;
    }
    let theta = acos(normal.z.clamp(-1.0, 1.0));
    Some(Hit {
        t,
        prim,
        kind: PrimKind::Sphere,
        uv: Vec2::new(phi, theta),
        normal,
        position,
        position_error: gamma(5) * (sphere.center.abs() + local.abs()),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_sphere_front_and_inside() {
        let s = Sphere::new(Vec3::ZERO, 1.0);
        let r = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
        let h = intersect_sphere(&r, &s, 7).unwrap();
        assert_eq!(h.t, 4.0);
        assert_eq!(h.prim, 7);
        assert!((h.normal - Vec3::Z).length() < 1e-6);
        let inside = Ray::new(Vec3::ZERO, Vec3::X);
        assert_eq!(intersect_sphere_t(&inside, &s), Some(1.0));
    }

    #[test]
    fn far_tiny_sphere_is_accurate() {
        // The naive discriminant b² − a·c loses every digit here.
        let s = Sphere::new(Vec3::new(0.0, 0.0, -1.0e6), 1.0e-2);
        let r = Ray::new(Vec3::ZERO, Vec3::NEG_Z);
        let t = intersect_sphere_t(&r, &s).unwrap();
        assert!((t as f64 - (1.0e6 - 1.0e-2)).abs() < 0.07, "t = {t}");
        let off = Ray::new(Vec3::new(0.011, 0.0, 0.0), Vec3::NEG_Z);
        assert!(intersect_sphere_t(&off, &s).is_none());
    }

    #[test]
    fn misses_and_range() {
        let s = Sphere::new(Vec3::ZERO, 1.0);
        let r = Ray::new(Vec3::new(0.0, 2.0, 5.0), Vec3::NEG_Z);
        assert!(intersect_sphere_t(&r, &s).is_none());
        let r = Ray::with_range(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z, 0.0, 3.9);
        assert!(intersect_sphere_t(&r, &s).is_none());
        let r = Ray::with_range(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z, 4.5, 9.0);
        assert_eq!(intersect_sphere_t(&r, &s), Some(6.0));
    }
}
