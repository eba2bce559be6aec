//! `RayCaster` against a brute-force Möller–Trumbore test in f64 over
//! every triangle (random rays, which meet edges with probability zero),
//! crossings of a closed mesh (even from outside, odd from inside), bad
//! rays and its bytes.

use rt_core::{Ray, glam::Vec3};
use rt_surface::RayCaster;

fn mesh() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let m = rt_surface::rt_accel::TriangleMesh::icosphere(3);
    (m.positions().to_vec(), m.indices().to_vec())
}

/// A deterministic number in `[-1, 1)`.
fn random(state: &mut u64) -> f32 {
    *state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
    ((*state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
}

fn rays(n: usize, seed: u64) -> Vec<Ray> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            // Outside the sphere, 3 from its centre.
            let o = Vec3::new(random(&mut s), random(&mut s), random(&mut s)).normalize() * 3.0;
            // Inside the sphere: |target| ≤ 0.5√3.
            let target = Vec3::new(random(&mut s), random(&mut s), random(&mut s)) * 0.5;
            Ray::new(o, (target - o).normalize())
        })
        .collect()
}

/// `(t, triangle)` of the nearest hit, Möller–Trumbore in f64.
fn brute(p: &[Vec3], tris: &[[u32; 3]], r: &Ray) -> Option<(f64, u32)> {
    let d = r.direction.as_dvec3();
    let o = r.origin.as_dvec3();
    let mut best: Option<(f64, u32)> = None;
    for (i, t) in tris.iter().enumerate() {
        let [a, b, c] = t.map(|k| p[k as usize].as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let q = d.cross(e2);
        let det = e1.dot(q);
        if det.abs() < 1e-15 {
            continue;
        }
        let s = o - a;
        let u = s.dot(q) / det;
        let w = s.cross(e1);
        let v = d.dot(w) / det;
        let dist = e2.dot(w) / det;
        if u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist >= 0.0 && best.is_none_or(|b| dist < b.0) {
            best = Some((dist, i as u32));
        }
    }
    best
}

#[test]
fn first_hits_are_the_brute_force_nearest_triangle() {
    let (p, tris) = mesh();
    let caster = RayCaster::new(&p, &tris).unwrap();
    let rays = rays(2000, 7);
    let hits = caster.first(&rays);
    let mut hit = 0;
    for (r, h) in rays.iter().zip(&hits) {
        let want = brute(&p, &tris, r);
        assert_eq!(h.map(|h| h.prim), want.map(|w| w.1), "{r:?}");
        if let (Some(h), Some(w)) = (h, want) {
            assert!((f64::from(h.t) - w.0).abs() < 1e-5, "t {} against {}", h.t, w.0);
            hit += 1;
        }
    }
    assert!(hit > 1000, "only {hit} hits");
    let nearest = caster.nearest(&rays);
    assert!(nearest.iter().zip(&hits).all(|(n, h)| *n == h.map(|h| (h.t, h.prim))));
    let any = caster.any(&rays);
    assert!(any.iter().zip(&hits).all(|(a, h)| *a == h.is_some()));
}

#[test]
fn every_ray_crosses_a_closed_mesh_an_even_number_of_times_from_outside() {
    let (p, tris) = mesh();
    let caster = RayCaster::new(&p, &tris).unwrap();
    let outside = rays(3000, 11);
    let all = caster.all(&outside, 16);
    let mut count = vec![0usize; outside.len()];
    for (i, h) in &all {
        count[*i as usize] += 1;
        assert!(h.t >= 0.0);
    }
    // Each ray aims at a point inside the sphere: two crossings.
    let odd: Vec<_> = count.iter().enumerate().filter(|(_, c)| **c != 2).collect();
    assert!(odd.is_empty(), "rays not crossing twice: {odd:?}");
    // Nearest first, in the rays' order.
    assert!(all.windows(2).all(|w| w[0].0 < w[1].0 || (w[0].0 == w[1].0 && w[0].1.t < w[1].1.t)));
    // From the centre: one crossing each.
    let inside: Vec<Ray> = outside.iter().map(|r| Ray::new(Vec3::ZERO, r.direction)).collect();
    assert_eq!(caster.all(&inside, 16).len(), inside.len());
    assert_eq!(caster.all(&outside, 1).len(), outside.len());
}

#[test]
fn bad_rays_hit_nothing_and_the_rest_of_the_batch_is_answered() {
    let (p, tris) = mesh();
    let caster = RayCaster::new(&p, &tris).unwrap();
    let good = Ray::new(Vec3::new(0.0, 0.0, 3.0), -Vec3::Z);
    let batch = [
        Ray::new(Vec3::NAN, -Vec3::Z),
        Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO),
        Ray::new(Vec3::new(0.0, 0.0, f32::INFINITY), -Vec3::Z),
        Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::new(0.0, f32::NAN, -1.0)),
        good,
    ];
    let first = caster.first(&batch);
    assert!(first[..4].iter().all(Option::is_none) && first[4].is_some());
    assert_eq!(caster.any(&batch), [false, false, false, false, true]);
    assert!(caster.all(&batch, 8).iter().all(|(i, _)| *i == 4));
}

#[test]
fn a_caster_saved_as_bytes_answers_alike_and_bad_bytes_are_refused() {
    let (p, tris) = mesh();
    let caster = RayCaster::new(&p, &tris).unwrap();
    let bytes = caster.to_bytes();
    let loaded = RayCaster::from_bytes(&bytes).unwrap();
    let rays = rays(500, 3);
    let bits = |c: &RayCaster| -> Vec<Option<(u32, u32)>> {
        c.first(&rays).iter().map(|h| h.map(|h| (h.prim, h.t.to_bits()))).collect()
    };
    assert_eq!(bits(&caster), bits(&loaded));
    assert_eq!(loaded.triangle_count() as usize, tris.len());
    assert!(RayCaster::from_bytes(&bytes[..bytes.len() / 2]).is_err());
    assert!(RayCaster::from_bytes(b"not a bvh").is_err());
    // Bad meshes: an index out of range, a NaN vertex.
    assert!(RayCaster::new(&p, &[[0, 1, p.len() as u32]]).is_err());
    let mut nan = p.clone();
    nan[0] = Vec3::NAN;
    assert!(RayCaster::new(&nan, &tris).is_err());
}

#[test]
fn rays_through_shared_edges_and_vertices_cross_once_there() {
    // Aimed at the centre through each vertex and each edge's midpoint:
    // in and out, each often at another shared edge or vertex, where two
    // or more triangles report distances a rounding apart.
    let (p, tris) = mesh();
    let caster = RayCaster::new(&p, &tris).unwrap();
    let mut targets = p.clone();
    for t in &tris {
        for k in 0..3 {
            targets.push((p[t[k] as usize] + p[t[(k + 1) % 3] as usize]) * 0.5);
        }
    }
    let rays: Vec<Ray> = targets.iter().map(|&v| Ray::new(v * 3.0, -v)).collect();
    assert!(caster.any(&rays).iter().all(|&a| a));
    let mut count = vec![0usize; rays.len()];
    for (i, _) in caster.all(&rays, 16) {
        count[i as usize] += 1;
    }
    let odd: Vec<_> = count.iter().enumerate().filter(|(_, c)| **c != 2).collect();
    assert!(odd.is_empty(), "{} of {} rays not crossing twice: {odd:?}", odd.len(), rays.len());
}
