//! Shared helpers: deterministic geometry and brute-force references.
#![allow(dead_code, unreachable_pub)]

use rt_accel::{BestHit, BuildParams, Bvh, CapsuleItem, SphereItem, TriPacket};
use rt_core::{
    Ray,
    glam::Vec3,
    intersect::{
        Capsule, Sphere, WatertightRay, intersect_capsule_t, intersect_sphere_t,
        intersect_triangle_t, is_degenerate_triangle,
    },
};

/// The first smallest `t` over all items: `(t, index)`.
fn brute<T>(items: &[T], ray: &Ray, f: impl Fn(&T) -> Option<f32>) -> Option<(f32, u32)> {
    if !ray.is_valid() {
        return None;
    }
    items.iter().enumerate().filter_map(|(i, it)| f(it).map(|t| (t, i as u32))).fold(
        None,
        |best, (t, i)| match best {
            Some((bt, _)) if bt <= t => best,
            _ => Some((t, i)),
        },
    )
}

/// Brute-force closest hit over triangles: `(t, prim)`, ties to the lower index.
pub fn brute_triangles(pos: &[Vec3], idx: &[[u32; 3]], ray: &Ray) -> Option<(f32, u32)> {
    let pre = ray.is_valid().then(|| WatertightRay::new(ray))?;
    brute(idx, ray, |t| {
        let [a, b, c] = t.map(|k| pos[k as usize]);
        if is_degenerate_triangle(a, b, c) {
            return None;
        }
        intersect_triangle_t(ray, &pre, a, b, c).map(|h| h.t)
    })
}

/// Brute-force closest hit over spheres.
pub fn brute_spheres(s: &[Sphere], ray: &Ray) -> Option<(f32, u32)> {
    brute(s, ray, |sp| intersect_sphere_t(ray, sp))
}

/// Brute-force closest hit over capsules.
pub fn brute_capsules(c: &[Capsule], ray: &Ray) -> Option<(f32, u32)> {
    brute(c, ray, |cp| intersect_capsule_t(ray, cp))
}

/// `(t, prim)` of a BVH closest-hit query.
pub fn bvh_t<P: rt_accel::Primitive>(bvh: &Bvh<P>, ray: &Ray) -> Option<(f32, u32)> {
    bvh.closest_t(ray).map(|b: BestHit| (b.t, b.prim))
}

/// An icosphere subdivided `level` times (closed, shared vertices).
pub fn icosphere(level: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let m = rt_accel::TriangleMesh::icosphere(level);
    (m.positions().to_vec(), m.indices().to_vec())
}

/// A unit cube `[0, 1]³` of 12 triangles, outward counter-clockwise faces.
pub fn cube() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let pos = (0..8)
        .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
        .collect();
    let idx = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    (pos, idx)
}

pub fn params() -> BuildParams {
    BuildParams::medium()
}

pub type TriBvh = Bvh<TriPacket>;
pub type SphereBvh = Bvh<SphereItem>;
pub type CapsuleBvh = Bvh<CapsuleItem>;
