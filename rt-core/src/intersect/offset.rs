//! Spawning secondary rays without self-intersection.
//!
//! The hit point carries a per-axis error bound `δ`. Offsetting the origin
//! along the normal by `d = |n|·δ` moves it outside the box of points the
//! true surface point could be, on the side the new ray leaves from; the
//! result is then rounded away from the surface by one ulp per axis
//! (pbrt-v4, §6.8.6 "Robust Spawned Ray Origins").

use glam::Vec3;

use crate::Ray;

/// The next representable f32 above `x` (`+∞` stays, `−0.0` → smallest
/// positive subnormal).
#[inline]
#[must_use]
pub fn next_float_up(x: f32) -> f32 {
    if x.is_infinite() && x > 0.0 || x.is_nan() {
        return x;
    }
    let x = if x == -0.0 { 0.0 } else { x };
    let bits = x.to_bits();
    f32::from_bits(if x >= 0.0 { bits + 1 } else { bits - 1 })
}

/// The next representable f32 below `x`.
#[inline]
#[must_use]
pub fn next_float_down(x: f32) -> f32 {
    -next_float_up(-x)
}

/// The origin for a ray leaving a surface at `p` (error bound `p_error`,
/// geometric normal `n`) in direction `w`: offset to `w`'s side of the
/// surface by the error bound projected on the normal, then rounded away.
#[must_use]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let side = if w.dot(n) < 0.0 { -n } else { n };
    let mut po = p + d * side;
    // Rounded away along the normal even where the bound is 0 (a hit on
    // an axis-aligned plane is exact): the origin must leave the surface.
    // The step must also survive the slab distance `(plane − o)·(1/w)`
    // that every hit is re-checked with (`triangle_admits_hit`): one ulp
    // off a plane through 0 is a subnormal, which that product rounds to
    // −0 once `|w| > 1`, so the plane was hit at `t = −0`. At least
    // `4·MIN_POSITIVE·|w|` away, the product is a normal number.
    for i in 0..3 {
        let step = 4.0 * f32::MIN_POSITIVE * w[i].abs();
        if side[i] > 0.0 {
            po[i] = next_float_up(po[i]).max(p[i] + step);
        } else if side[i] < 0.0 {
            po[i] = next_float_down(po[i]).min(p[i] - step);
        }
    }
    po
}

/// A ray leaving the surface point `p` in direction `w` over `[0, ∞)`.
#[must_use]
pub fn spawn_ray(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Ray {
    Ray::new(offset_ray_origin(p, p_error, n, w), w)
}

/// A shadow ray from the surface point `p` toward `target`, stopping just
/// short of it (`t ∈ [0, 1 − 2⁻¹⁰]` with direction `target − origin`).
#[must_use]
pub fn spawn_ray_to(p: Vec3, p_error: Vec3, n: Vec3, target: Vec3) -> Ray {
    let o = offset_ray_origin(p, p_error, n, target - p);
    Ray::with_range(o, target - o, 0.0, 1.0 - 1.0 / 1024.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::intersect::{Sphere, intersect_sphere, intersect_triangle};

    #[test]
    fn next_float_steps_one_ulp() {
        assert!(next_float_up(1.0) > 1.0 && next_float_up(1.0) - 1.0 == f32::EPSILON);
        assert!(next_float_down(1.0) < 1.0);
        assert!(next_float_up(-0.0) > 0.0);
        assert_eq!(next_float_up(f32::INFINITY), f32::INFINITY);
    }

    #[test]
    fn reflected_ray_leaves_far_sphere_without_self_hit() {
        // Far from the origin, rounding in the hit point is large.
        let s = Sphere::new(Vec3::new(1.0e4, 2.0e4, -3.0e4), 7.0);
        for i in 0..200 {
            let a = i as f32 * 0.0137;
            let target = s.center + Vec3::new(a.cos(), a.sin(), 0.3).normalize() * 6.0;
            let r = Ray::new(Vec3::ZERO, target);
            let h = intersect_sphere(&r, &s, 0).expect("aimed at the sphere");
            let out = spawn_ray(h.position, h.position_error, h.normal, h.normal);
            assert!(intersect_sphere(&out, &s, 0).is_none(), "self-hit at {i}");
        }
    }

    #[test]
    fn shadow_ray_from_triangle_does_not_self_hit() {
        let (v0, v1, v2) = (
            Vec3::new(1.0e3, 0.0, 7.0),
            Vec3::new(1.0e3 + 5.0, 0.1, 7.0),
            Vec3::new(1.0e3, 3.0, 7.3),
        );
        for i in 0..100 {
            let o = Vec3::new(1.0e3 + 0.01 * i as f32, 0.7, 20.0);
            let r = Ray::new(o, Vec3::new(0.003, 0.001, -1.0));
            let Some(h) = intersect_triangle(&r, v0, v1, v2) else {
                continue;
            };
            let light = Vec3::new(900.0, -50.0, 100.0);
            let s = spawn_ray_to(h.position, h.position_error, h.normal, light);
            assert!(intersect_triangle(&s, v0, v1, v2).is_none());
        }
    }

    #[test]
    fn shadow_rays_leave_an_exact_plane_through_zero() {
        // A floor `y = 0` whose hits are exact in y (error bound 0): one
        // ulp up from 0 is a subnormal, which vanished from the slab
        // distance `(0 − o.y) / d.y` when `d.y > 1` and let the floor
        // shadow itself at `t = −0` (found by the renderer's shadow test).
        let floor =
            [Vec3::new(-50.0, 0.0, -50.0), Vec3::new(-50.0, 0.0, 50.0), Vec3::new(50.0, 0.0, 50.0)];
        let lamp = Vec3::new(-1.0, 2.5, 1.5);
        let mut tried = 0;
        for i in 0..64 {
            for j in 0..64 {
                let above = Vec3::new(-4.0 + 0.125 * i as f32, 5.0, -4.0 + 0.125 * j as f32);
                let r = Ray::new(above, Vec3::NEG_Y);
                let Some(h) = intersect_triangle(&r, floor[0], floor[1], floor[2]) else {
                    continue;
                };
                assert_eq!(h.position_error.y, 0.0);
                for target in [lamp, lamp * 40.0, h.position + Vec3::new(-3.0, 1e-3, 0.5)] {
                    let s = spawn_ray_to(h.position, h.position_error, h.normal, target);
                    assert!(
                        intersect_triangle(&s, floor[0], floor[1], floor[2]).is_none(),
                        "{s:?}"
                    );
                    let d = spawn_ray(h.position, h.position_error, h.normal, target - h.position);
                    assert!(
                        intersect_triangle(&d, floor[0], floor[1], floor[2]).is_none(),
                        "{d:?}"
                    );
                }
                tried += 1;
            }
        }
        assert!(tried > 1000);
    }
}
