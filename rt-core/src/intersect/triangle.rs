//! Watertight ray–triangle intersection (Woop, Benthin, Wald 2013,
//! "Watertight Ray/Triangle Intersection", JCGT 2(1)).
//!
//! The ray is sheared so it runs along `+z` from the origin; each edge
//! function `U, V, W` is then a 2-D cross product of sheared vertices. An
//! edge shared by two triangles yields the same edge value, negated, in both,
//! so a ray through the edge or a shared vertex hits at least one of them:
//! no gaps. Edge values of exactly zero are recomputed in f64, as the paper
//! prescribes, so the sign decision there is exact.

use glam::{Vec2, Vec3};

use crate::{Aabb, Hit, PrimKind, Ray, aabb::widen_far, math::gamma};

/// Per-ray constants of the watertight test: the dominant axis `kz`, the
/// two others `kx`, `ky` (swapped to keep winding), and the shear.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WatertightRay {
    /// Axis indices `[kx, ky, kz]`.
    pub axes: [usize; 3],
    /// Shear `(Sx, Sy, Sz) = (d_kx/d_kz, d_ky/d_kz, 1/d_kz)`.
    pub shear: Vec3,
}

impl WatertightRay {
    /// Precomputes the shear for `ray` (whose direction must be non-zero
    /// and finite; see [`Ray::is_valid`]).
    #[inline]
    #[must_use]
    pub fn new(ray: &Ray) -> Self {
        // `[kx, ky]` by `2·kz + (d_kz < 0)`: the next two axes in cyclic
        // order, swapped for a negative `d_kz` to keep the winding.
        const XY: [[usize; 2]; 6] = [[1, 2], [2, 1], [2, 0], [0, 2], [0, 1], [1, 0]];
        // Indexed as an array (`Vec3`'s indexing is a match: branches).
        let d = ray.direction.to_array();
        let [x, y, z] = ray.direction.abs().to_array();
        // The largest |d| (the first on ties), chosen by arithmetic: a
        // branch on it mispredicts for rays of random direction (a third
        // of a missed incoherent ray's cost).
        let kz = usize::from(!((x >= y) & (x >= z))) * (2 - usize::from(y >= z));
        let [kx, ky] = XY[2 * kz + usize::from(d[kz] < 0.0)];
        let sz = 1.0 / d[kz];
        Self { axes: [kx, ky, kz], shear: Vec3::new(d[kx] * sz, d[ky] * sz, sz) }
    }
}

/// Distance and barycentrics of a triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter.
    pub t: f32,
    /// Barycentric weight of `v1`.
    pub b1: f32,
    /// Barycentric weight of `v2`.
    pub b2: f32,
}

/// The watertight test's sheared vertices and edge functions: the part
/// of the test that decides whether the ray passes through the triangle.
struct Edges {
    /// Scaled barycentric coordinates (2-D edge functions), decided in
    /// f64 where one is zero in f32.
    u: f32,
    v: f32,
    w: f32,
    /// The vertices' sheared distances along the ray, `S_z·(vᵢ − o)_kz`.
    z: [f32; 3],
    /// The vertices relative to the origin, and sheared (`x, y` of each),
    /// for [`Edges::t_error`].
    rel: [Vec3; 3],
    sheared: [f32; 6],
}

impl Edges {
    #[inline]
    fn new(ray: &Ray, pre: &WatertightRay, v0: Vec3, v1: Vec3, v2: Vec3) -> Self {
        let [kx, ky, kz] = pre.axes;
        let s = pre.shear;
        // Vertices relative to the origin, sheared so the ray runs along +z.
        let a = v0 - ray.origin;
        let b = v1 - ray.origin;
        let c = v2 - ray.origin;
        let (ax, ay) = (a[kx] - s.x * a[kz], a[ky] - s.y * a[kz]);
        let (bx, by) = (b[kx] - s.x * b[kz], b[ky] - s.y * b[kz]);
        let (cx, cy) = (c[kx] - s.x * c[kz], c[ky] - s.y * c[kz]);
        // Scaled barycentric coordinates: 2-D edge functions.
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            // On an edge in f32: decide the sign exactly in f64.
            let f =
                |p: f32, q: f32, r: f32, t: f32| (p as f64 * q as f64 - r as f64 * t as f64) as f32;
            u = f(cx, by, cy, bx);
            v = f(ax, cy, ay, cx);
            w = f(bx, ay, by, ax);
        }
        let z = [s.z * a[kz], s.z * b[kz], s.z * c[kz]];
        Self { u, v, w, z, rel: [a, b, c], sheared: [ax, ay, bx, by, cx, cy] }
    }

    /// A bound on the error of the hit distance `t = (u·z₀ + v·z₁ + w·z₂) /
    /// det` for `inv = 1 / det`. Each sheared coordinate, `p_kx − S_x·p_kz`
    /// of `p = v − o`, is off by at most γ(5) of its terms' sizes (five
    /// roundings): far from the origin, an absolute error that the
    /// triangle's own size does not bound. An edge function, a difference
    /// of two products of them, is then off by `δ_e = 2·(γ(2)·m² + 2·δ·m)`
    /// (`m` the largest sheared coordinate). `t` is the vertices' distances
    /// averaged with the edge functions as weights, so errors `δ_e` move it
    /// by at most `3·δ_e·(z_max − z_min) / |det|`; the distances' own
    /// rounding (γ(3) of the largest) and the sum's (γ(3) of its terms,
    /// eightfold) add to that. A sliver seen from afar has weights of
    /// relative error far above ε: its `t` can round tens of ulps short of
    /// the plane it lies in.
    #[cold]
    fn t_error(&self, pre: &WatertightRay, inv: f32) -> f32 {
        let ([kx, ky, kz], s) = (pre.axes, pre.shear);
        let size =
            |p: Vec3| (p[kx].abs() + (s.x * p[kz]).abs()).max(p[ky].abs() + (s.y * p[kz]).abs());
        let [a, b, c] = self.rel;
        let delta = gamma(5) * size(a).max(size(b)).max(size(c));
        let m = self.sheared.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        let e_err = 2.0 * (gamma(2) * m * m + 2.0 * delta * m);
        let [za, zb, zc] = self.z;
        let (lo, hi) = (za.min(zb).min(zc), za.max(zb).max(zc));
        let terms = (self.u * za).abs() + (self.v * zb).abs() + (self.w * zc).abs();
        let inv = inv.abs();
        3.0 * e_err * (hi - lo) * inv
            + gamma(3) * lo.abs().max(hi.abs())
            + 8.0 * gamma(3) * terms * inv
    }

    /// `det = u + v + w` if the ray passes through the triangle (the edge
    /// functions do not differ in sign) and it is neither 0 nor overflowed
    /// (vertices near `f32::MAX`, which would make `t` a meaningless ±0:
    /// no hit, as in the packet test).
    #[inline]
    fn det(&self) -> Option<f32> {
        let (u, v, w) = (self.u, self.v, self.w);
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        (det != 0.0 && det.is_finite()).then_some(det)
    }
}

/// The watertight test with precomputed `pre`; `None` on a miss, for
/// degenerate triangles (`det = 0`), outside `[ray.t_min, ray.t_max]`, and
/// for hits outside the triangle's box by rounding
/// ([`triangle_admits_hit`]). Both faces are hit (no culling).
#[inline]
#[must_use]
pub fn intersect_triangle_t(
    ray: &Ray,
    pre: &WatertightRay,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
) -> Option<TriangleHit> {
    let e = Edges::new(ray, pre, v0, v1, v2);
    let det = e.det()?;
    let (u, v, w, [za, zb, zc]) = (e.u, e.v, e.w, e.z);
    // Scaled hit distance, then the true one.
    let tt = u * za + v * zb + w * zc;
    let inv = 1.0 / det;
    let t = tt * inv;
    // A `t` that overflowed to `+∞` (vertices near `f32::MAX`) is no hit,
    // even for a ray with `t_max = ∞`.
    if !(t >= ray.t_min && t <= ray.t_max && t < f32::INFINITY) {
        return None;
    }
    // `t` interpolates the vertices' distances with the barycentrics: for
    // a triangle large next to `t` it cancels, and for a sliver far from
    // the origin its weights are inexact: it can round below the near
    // plane of the triangle's (flat) box. Within a bound on that error,
    // it is moved onto the plane instead of rejected.
    let t = settle_triangle_t(ray, t, || e.t_error(pre, inv), v0, v1, v2)?;
    Some(TriangleHit { t, b1: v * inv, b2: w * inv })
}

/// The barycentrics `(b1, b2)` that [`intersect_triangle_t`] reports for
/// a hit, without its distance: `None` where the ray does not pass
/// through the triangle. For a hit whose distance is known already (a
/// BVH's traversal found it), this makes the same record for less: it
/// skips the distance, its range test and its settling on the box.
#[inline]
#[must_use]
pub fn triangle_barycentrics(
    ray: &Ray,
    pre: &WatertightRay,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
) -> Option<(f32, f32)> {
    let e = Edges::new(ray, pre, v0, v1, v2);
    let inv = 1.0 / e.det()?;
    Some((e.v * inv, e.w * inv))
}

/// The hit distance a triangle test reports for a computed `t` whose
/// rounding error is at most `slack()`: `t` itself where the triangle's
/// box admits it ([`triangle_admits_hit`]), else the box's near distance
/// if that lies within `t + slack()` (and `ray.t_max`), else `None`. So the
/// reported `t` is always one the box admits, which keeps a BVH's answer
/// equal to a brute-force loop's. The bound is asked for only when `t`
/// lies short of the box.
#[inline]
#[must_use]
pub fn settle_triangle_t(
    ray: &Ray,
    t: f32,
    slack: impl FnOnce() -> f32,
    v0: Vec3,
    v1: Vec3,
    v2: Vec3,
) -> Option<f32> {
    let bx = Aabb::new(v0.min(v1).min(v2), v0.max(v1).max(v2));
    // The box test up to `t` finds the same near distance as one up to
    // `t + slack` wherever that is at most `t`.
    if bx
        .intersect_ray(&Ray { t_max: widen_far(t), ..*ray })
        .is_some_and(|(near, _)| near <= widen_far(t))
    {
        return Some(t);
    }
    let (near, _) = bx.intersect_ray(&Ray { t_max: widen_far(t + slack()), ..*ray })?;
    // An unbounded slack (a determinant near zero) may reach a box whose
    // near side is at infinity: that is no hit.
    if near <= widen_far(t) {
        Some(t)
    } else {
        (near <= ray.t_max && near < f32::INFINITY).then_some(near)
    }
}

/// Whether a triangle hit at `t` lies inside the triangle's box as the
/// robust slab test sees it ([`Aabb::admits_hit`]); rejects hits placed
/// outside it by rounding (grazing rays, hits at `t ≈ t_min`).
#[inline]
#[must_use]
pub fn triangle_admits_hit(ray: &Ray, t: f32, v0: Vec3, v1: Vec3, v2: Vec3) -> bool {
    Aabb::new(v0.min(v1).min(v2), v0.max(v1).max(v2)).admits_hit(ray, t)
}

/// Whether the triangle has zero area: its edge cross product, evaluated in
/// f64 (where products of f32 differences are nearly exact), is zero, or a
/// vertex is not finite. Such triangles are never hit by
/// [`intersect_triangle`] and are left out of acceleration structures.
#[must_use]
pub fn is_degenerate_triangle(v0: Vec3, v1: Vec3, v2: Vec3) -> bool {
    if !(v0.is_finite() && v1.is_finite() && v2.is_finite()) {
        return true;
    }
    let e1 = [0, 1, 2].map(|i| f64::from(v1[i]) - f64::from(v0[i]));
    let e2 = [0, 1, 2].map(|i| f64::from(v2[i]) - f64::from(v0[i]));
    e1[1] * e2[2] - e1[2] * e2[1] == 0.0
        && e1[2] * e2[0] - e1[0] * e2[2] == 0.0
        && e1[0] * e2[1] - e1[1] * e2[0] == 0.0
}

/// Convenience form of [`intersect_triangle_t`] that builds the per-ray
/// constants itself and returns a full [`Hit`] (with `prim` 0). Degenerate
/// triangles ([`is_degenerate_triangle`]) are never hit.
#[must_use]
pub fn intersect_triangle(ray: &Ray, v0: Vec3, v1: Vec3, v2: Vec3) -> Option<Hit> {
    if !ray.is_valid() || is_degenerate_triangle(v0, v1, v2) {
        return None;
    }
    let pre = WatertightRay::new(ray);
    intersect_triangle_t(ray, &pre, v0, v1, v2).map(|h| triangle_hit(h, 0, v0, v1, v2))
}

/// The full hit record for a triangle hit: position from barycentrics with
/// its error bound `γ(7)·Σ|bᵢ·vᵢ|` (pbrt-v4, §6.8.6), and the unit geometric
/// normal `(v1 − v0) × (v2 − v0)`.
#[must_use]
pub fn triangle_hit(h: TriangleHit, prim: u32, v0: Vec3, v1: Vec3, v2: Vec3) -> Hit {
    let b0 = 1.0 - h.b1 - h.b2;
    let position = b0 * v0 + h.b1 * v1 + h.b2 * v2;
    let abs_sum = (b0 * v0).abs() + (h.b1 * v1).abs() + (h.b2 * v2).abs();
    let normal = (v1 - v0).cross(v2 - v0).normalize_or_zero();
    Hit {
        t: h.t,
        prim,
        kind: PrimKind::Triangle,
        uv: Vec2::new(h.b1, h.b2),
        normal,
        position,
        position_error: gamma(7) * abs_sum,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shear_axes_are_the_dominant_axis_and_the_winding_pair() {
        // The definition, with branches: `kz` the largest |d| (the first
        // on ties), `kx`, `ky` the next two in cyclic order, swapped where
        // `d_kz < 0`.
        let reference = |d: Vec3| {
            let a = d.abs();
            let kz = if a.x >= a.y && a.x >= a.z {
                0
            } else if a.y >= a.z {
                1
            } else {
                2
            };
            let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
            let (kx, ky) = if d[kz] < 0.0 { (ky, kx) } else { (kx, ky) };
            (kx, ky, kz)
        };
        // Every sign pattern, every order of magnitudes, and ties.
        let mags = [0.0f32, 0.25, 0.5, 0.5, 1.0, 3.0];
        for &x in &mags {
            for &y in &mags {
                for &z in &mags {
                    for s in 0..8 {
                        let sign = |b: i32| if s & b == 0 { 1.0 } else { -1.0 };
                        let d = Vec3::new(sign(1) * x, sign(2) * y, sign(4) * z);
                        if d == Vec3::ZERO {
                            continue;
                        }
                        let w = WatertightRay::new(&Ray::new(Vec3::ZERO, d));
                        let (kx, ky, kz) = reference(d);
                        assert_eq!(w.axes, [kx, ky, kz], "{d}");
                        let sz = 1.0 / d[kz];
                        assert_eq!(w.shear.to_array(), [d[kx] * sz, d[ky] * sz, sz], "{d}");
                    }
                }
            }
        }
    }

    #[test]
    fn large_flat_triangles_seen_from_close_by_are_hit() {
        // A wall x = 0 of two 2·s triangles; rays from 0.25 in front of it.
        // Their t (barycentric interpolation of ±s distances) rounds below
        // the flat box's near plane; the test must settle, not miss.
        for s in [50.0f32, 1e3] {
            let v = [
                Vec3::new(0.0, 0.0, -s),
                Vec3::new(0.0, s, -s),
                Vec3::new(0.0, s, s),
                Vec3::new(0.0, 0.0, s),
            ];
            let mut missed = 0;
            for i in 0..2000 {
                let a = i as f32 * 0.618_034 * core::f32::consts::TAU;
                let up = 0.05 + 0.9 * ((i as f32 * 0.754_877) % 1.0);
                // x is not the dominant axis: t comes from y or z.
                let d = Vec3::new(-0.35, 0.3 + up, 0.9 * a.sin().signum()).normalize();
                let r = Ray::new(Vec3::new(0.25, 0.0, a.cos()), d);
                let h = intersect_triangle(&r, v[0], v[1], v[2])
                    .or_else(|| intersect_triangle(&r, v[0], v[2], v[3]));
                match h {
                    Some(h) => assert!((h.t - 0.25 / -d.x).abs() < 1e-3 * h.t, "{s}: {}", h.t),
                    None => missed += 1,
                }
            }
            assert_eq!(missed, 0, "{s}");
        }
    }

    /// Found by the `intersect` fuzz target: a ray grazing a triangle in
    /// its plane, one vertex at `f32::MAX`, with `t_max = ∞`: the settling
    /// slack was unbounded and the box's near side at infinity, so the hit
    /// came back at `t = ∞`.
    #[test]
    fn fuzz_regression_no_hit_at_infinity() {
        let ray = Ray::new(Vec3::new(-1e-45, 0.0, 0.0), Vec3::new(0.0, 1.0, -1e-45));
        let (a, b, c) =
            (Vec3::new(1.0, 1.192_092_9e-7, 0.0), Vec3::ZERO, Vec3::new(0.0, f32::MAX, 0.0));
        if let Some(h) = intersect_triangle(&ray, a, b, c) {
            assert!(h.t.is_finite(), "hit at t = {}", h.t);
        }
    }

    #[test]
    fn slivers_seen_from_afar_are_hit_on_their_shared_diagonal() {
        // A strip of slivers in the plane y = s (each 1000 times longer
        // than wide), rays from 10·s away aimed at the diagonals two of them
        // share. Far from the origin the sheared coordinates round by more
        // than a sliver's width allows: t rounds tens of ulps short of the
        // (flat) box's plane, and the test must settle, not miss.
        for s in [1e-8f32, 1e-4, 1.0, 1e4, 1e8] {
            let x = |i: i32| (-1.0 + 2e-3 * i as f32) * s;
            let mut missed = 0;
            for i in 0..1000 {
                // The slivers (x_i, x_i+1) × (−s, s) split on a diagonal.
                let (a, b) = (Vec3::new(x(i), s, -s), Vec3::new(x(i + 1), s, s));
                let (c, d) = (Vec3::new(x(i + 1), s, -s), Vec3::new(x(i), s, s));
                let aim = (a + b) * 0.5;
                for k in 0..4 {
                    // Often along z, the slivers' length: t then comes from
                    // their vertices' z, which differ by 2·s.
                    let f = (4 * i + k) as f32 * 0.618_034;
                    let (g, h) = (f % 1.0, (f * 1.618) % 1.0);
                    let dir = Vec3::new(g - 0.5, -0.3 - 0.7 * h, 2.0 * g - 1.0).normalize();
                    let r = Ray::new(aim - dir * (10.0 * s), dir);
                    let h =
                        intersect_triangle(&r, a, c, b).or_else(|| intersect_triangle(&r, a, b, d));
                    missed += usize::from(h.is_none());
                }
            }
            assert_eq!(missed, 0, "scale {s}");
        }
    }

    const V0: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    const V1: Vec3 = Vec3::new(1.0, 0.0, 0.0);
    const V2: Vec3 = Vec3::new(0.0, 1.0, 0.0);

    #[test]
    fn hits_interior_with_barycentrics() {
        let r = Ray::new(Vec3::new(0.25, 0.5, 2.0), Vec3::NEG_Z);
        let h = intersect_triangle(&r, V0, V1, V2).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        assert!((h.uv.x - 0.25).abs() < 1e-6 && (h.uv.y - 0.5).abs() < 1e-6);
        assert!((h.normal - Vec3::Z).length() < 1e-6);
        assert!((h.position - Vec3::new(0.25, 0.5, 0.0)).length() < 1e-6);
    }

    #[test]
    fn back_face_hit_and_outside_miss() {
        let r = Ray::new(Vec3::new(0.25, 0.25, -1.0), Vec3::Z);
        assert!(intersect_triangle(&r, V0, V1, V2).is_some());
        let r = Ray::new(Vec3::new(0.75, 0.75, 1.0), Vec3::NEG_Z);
        assert!(intersect_triangle(&r, V0, V1, V2).is_none());
    }

    #[test]
    fn shared_edge_is_hit_by_one_side() {
        // Two triangles sharing the diagonal of the unit square.
        let q = Vec3::new(1.0, 1.0, 0.0);
        let r = Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::NEG_Z);
        let a = intersect_triangle(&r, V0, V1, q);
        let b = intersect_triangle(&r, V0, q, V2);
        assert!(a.is_some() || b.is_some());
    }

    #[test]
    fn degenerate_triangles_never_hit() {
        let r = Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::new(-0.1, -0.1, -1.0));
        let p = Vec3::new(0.45, 0.45, 0.0);
        assert!(intersect_triangle(&r, p, p, p).is_none());
        let (q1, q2) = (Vec3::new(1.0, 1.0, 0.0), Vec3::new(2.0, 2.0, 0.0));
        assert!(is_degenerate_triangle(V0, q1, q2));
        assert!(intersect_triangle(&r, V0, q1, q2).is_none());
        assert!(!is_degenerate_triangle(V0, V1, V2));
    }

    #[test]
    fn range_is_respected() {
        let r = Ray::with_range(Vec3::new(0.25, 0.25, 2.0), Vec3::NEG_Z, 0.0, 1.5);
        assert!(intersect_triangle(&r, V0, V1, V2).is_none());
        let r = Ray::with_range(Vec3::new(0.25, 0.25, 2.0), Vec3::NEG_Z, 2.5, 9.0);
        assert!(intersect_triangle(&r, V0, V1, V2).is_none());
    }
}
