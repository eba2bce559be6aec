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
    // Selects rather than branches (secondary rays leave surfaces facing
    // every way, so branches on the sign mispredict): `x + 0` turns −0
    // into +0 and keeps every other value; `+∞` and NaN are kept.
    let x0 = x + 0.0;
    let bits = x0.to_bits();
    let stepped =
        f32::from_bits(if x0 >= 0.0 { bits.wrapping_add(1) } else { bits.wrapping_sub(1) });
    if x.is_nan() || x == f32::INFINITY { x } else { stepped }
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
#[inline]
#[must_use]
pub fn offset_ray_origin(p: Vec3, p_error: Vec3, n: Vec3, w: Vec3) -> Vec3 {
    let d = n.abs().dot(p_error);
    let side = if w.dot(n) < 0.0 { -n } else { n };
    let po = p + d * side;
    // Rounded away along the normal even where the bound is 0 (a hit on
    // an axis-aligned plane is exact): the origin must leave the surface.
    // The step must also survive the slab distance `(plane − o)·(1/w)`
    // that every hit is re-checked with (`triangle_admits_hit`): one ulp
    // off a plane through 0 is a subnormal, which that product rounds to
    // −0 once `|w| > 1`, so the plane was hit at `t = −0`. At least
    // `4·MIN_POSITIVE·|w|` away, the product is a normal number.
    // Both roundings are computed and one is selected, without branches,
    // and inlined: this runs for every secondary ray. The step is at least
    // `4·MIN_POSITIVE`, never subnormal: `4·MIN_POSITIVE·|w|` is subnormal
    // for `|w| < 1/4`, and an Intel core takes a microcode assist (~100
    // cycles) for every subnormal result, on every secondary ray.
    let axis = |po: f32, p: f32, side: f32, w: f32| {
        let step = (4.0 * f32::MIN_POSITIVE) * w.abs().max(1.0);
        let up = next_float_up(po).max(p + step);
        let down = next_float_down(po).min(p - step);
        if side > 0.0 {
            up
        } else if side < 0.0 {
            down
        } else {
            po
        }
    };
    Vec3::new(
        axis(po.x, p.x, side.x, w.x),
        axis(po.y, p.y, side.y, w.y),
        axis(po.z, p.z, side.z, w.z),
    )
}

/// A ray leaving the surface point `p` in direction `w` over `[0, ∞)`.
#[inline]
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
    fn next_float_up_matches_the_step_by_step_definition() {
        // The definition, branch by branch: +∞ and NaN stay, −0 is 0,
        // then one ulp toward +∞.
        let reference = |x: f32| {
            if x.is_nan() || x == f32::INFINITY {
                return x.to_bits();
            }
            let x = if x == 0.0 { 0.0 } else { x };
            if x >= 0.0 { x.to_bits() + 1 } else { x.to_bits() - 1 }
        };
        let specials = [0x8000_0000, 0, 1, 0x8000_0001, 0x7f80_0000, 0xff80_0000, 0x7fc0_0000];
        let sampled = (0..=u32::MAX).step_by(4099);
        for bits in specials.into_iter().chain(sampled) {
            let x = f32::from_bits(bits);
            assert_eq!(next_float_up(x).to_bits(), reference(x), "{bits:#x}");
            assert_eq!(next_float_down(x).to_bits(), (-f32::from_bits(reference(-x))).to_bits());
        }
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
    fn origins_off_an_exact_plane_are_normal_numbers() {
        // A hit exactly on `y = 0` leaving at a grazing angle (`|w.y|`
        // down to 2⁻²⁰): the origin's y steps off the plane to a normal
        // number, never a subnormal (which would cost a microcode assist
        // in every slab test the ray makes, and in the step itself).
        for k in 0..=20 {
            let wy = (0.5f32).powi(k);
            for (n, w) in
                [(Vec3::Y, Vec3::new(1.0, wy, 0.0)), (Vec3::NEG_Y, Vec3::new(1.0, -wy, 0.0))]
            {
                let o = offset_ray_origin(Vec3::new(3.0, 0.0, -2.0), Vec3::ZERO, n, w);
                assert!(o.y.is_normal() && o.y.signum() == w.y.signum(), "{k}: {o:?}");
                assert!(o.y.abs() <= 8.0 * f32::MIN_POSITIVE, "{k}: {o:?}");
            }
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
