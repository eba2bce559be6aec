//! Numerical stress for the ray–primitive tests: geometry and rays scaled
//! log-uniformly from 1e-8 to 1e8, rays through shared vertices and
//! edges of a closed mesh, axis-aligned and grazing rays with ±0.0
//! components, spheres far away next to their size, self-intersection of
//! spawned rays, and invalid rays. Each test asserts the property that
//! matters, against an exact answer.

use rt_core::{
    Aabb, Ray,
    glam::Vec3,
    intersect::{
        Capsule, Sphere, intersect_capsule, intersect_sphere, intersect_triangle, spawn_ray,
    },
};

/// A vector in f64, exactly.
fn d3(v: Vec3) -> [f64; 3] {
    [f64::from(v.x), f64::from(v.y), f64::from(v.z)]
}

fn len64(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// 10^k for k in -8..=8.
fn scales() -> impl Iterator<Item = f32> {
    (-8..=8).map(|k| 10f32.powi(k))
}

/// The closed octahedron `|x| + |y| + |z| = s` around `c`: 6 vertices, 8
/// faces sharing every edge and vertex.
fn octahedron(c: Vec3, s: f32) -> Vec<[Vec3; 3]> {
    let mut faces = Vec::new();
    for sx in [-1.0f32, 1.0] {
        for sy in [-1.0f32, 1.0] {
            for sz in [-1.0f32, 1.0] {
                faces.push([
                    c + Vec3::new(sx * s, 0.0, 0.0),
                    c + Vec3::new(0.0, sy * s, 0.0),
                    c + Vec3::new(0.0, 0.0, sz * s),
                ]);
            }
        }
    }
    faces
}

/// The nearest hit over all faces.
fn nearest(faces: &[[Vec3; 3]], r: &Ray) -> Option<f32> {
    faces
        .iter()
        .filter_map(|f| intersect_triangle(r, f[0], f[1], f[2]))
        .map(|h| h.t)
        .reduce(f32::min)
}

/// Directions from the centre through every vertex, every edge midpoint
/// and every face centre (exactly the shared features), then 26 others.
fn feature_directions() -> Vec<Vec3> {
    let mut d = Vec::new();
    for a in 0..3 {
        for s in [-1.0f32, 1.0] {
            let mut v = Vec3::ZERO;
            v[a] = s;
            d.push(v); // vertex
        }
    }
    for a in 0..3 {
        for b in a + 1..3 {
            for sa in [-1.0f32, 1.0] {
                for sb in [-1.0f32, 1.0] {
                    let mut v = Vec3::ZERO;
                    v[a] = sa;
                    v[b] = sb;
                    d.push(v); // edge midpoint
                }
            }
        }
    }
    for sx in [-1.0f32, 1.0] {
        for sy in [-1.0f32, 1.0] {
            for sz in [-1.0f32, 1.0] {
                d.push(Vec3::new(sx, sy, sz)); // face centre
            }
        }
    }
    for i in 0..26 {
        let f = i as f32 * 0.731;
        d.push(Vec3::new(f.sin(), (1.7 * f).cos(), (2.3 * f + 0.4).sin()));
    }
    d
}

/// The exact distance from the centre to the surface `|x|₁ = s` along `d`.
fn exact_distance(d: Vec3, s: f32) -> f64 {
    let d = d3(d);
    f64::from(s) * len64(d) / (d[0].abs() + d[1].abs() + d[2].abs())
}

/// From the centre of a closed octahedron, rays through its shared
/// vertices, shared edges and face centres (and elsewhere) all hit — no
/// ray leaks through a crack — at every scale from 1e-8 to 1e8 and offset
/// 1000 sizes from the origin; the distance is right to 16 ulps of the
/// coordinates.
#[test]
fn closed_mesh_has_no_false_miss_through_shared_edges_and_vertices() {
    let dirs = feature_directions();
    for s in scales() {
        for c in [Vec3::ZERO, Vec3::new(1000.0 * s, -700.0 * s, 300.0 * s)] {
            let faces = octahedron(c, s);
            for &d in &dirs {
                for len in [1.0, 1e-8, 1e8] {
                    let r = Ray::new(c, d * len);
                    let t = nearest(&faces, &r)
                        .unwrap_or_else(|| panic!("leaked: scale {s:e} centre {c} dir {d}"));
                    let got = f64::from(t) * len64(d3(d * len));
                    // f32 holds the vertices to ε·(|c| + s): the error is
                    // bounded by a few of those ulps, whatever the scale.
                    let ulp = f64::from(f32::EPSILON) * f64::from(c.abs().max_element() + s);
                    let err = (got - exact_distance(d, s)).abs() / ulp;
                    assert!(err < 16.0, "scale {s:e} dir {d}: distance {got:e}, {err:.1} ulps");
                }
            }
        }
    }
}

/// From outside, rays aimed exactly at a shared vertex or edge midpoint
/// hit the surface there (entering, never passing between the faces).
#[test]
fn rays_aimed_at_shared_features_from_outside_hit_them() {
    for s in scales() {
        let faces = octahedron(Vec3::ZERO, s);
        for d in feature_directions().into_iter().take(18) {
            let target = d * (s / (d.x.abs() + d.y.abs() + d.z.abs()));
            let from = target + d * (3.0 * s);
            let r = Ray::new(from, -d);
            let t = nearest(&faces, &r).unwrap_or_else(|| panic!("missed {target} at {s:e}"));
            let hit = r.at(t);
            assert!((hit - target).length() <= 1e-5 * s, "scale {s:e}: hit {hit}, aimed {target}");
        }
    }
}

/// The exact slab interval in f64, with a closed box: `None` on a miss.
fn exact_slab(b: &Aabb, r: &Ray) -> Option<(f64, f64)> {
    let (o, d) = (d3(r.origin), d3(r.direction));
    let (lo, hi) = (d3(b.min), d3(b.max));
    let (mut t0, mut t1) = (f64::from(r.t_min), f64::from(r.t_max));
    for a in 0..3 {
        if d[a] == 0.0 {
            if o[a] < lo[a] || o[a] > hi[a] {
                return None;
            }
            continue;
        }
        let (p, q) = ((lo[a] - o[a]) / d[a], (hi[a] - o[a]) / d[a]);
        t0 = t0.max(p.min(q));
        t1 = t1.min(p.max(q));
    }
    (t0 <= t1).then_some((t0, t1))
}

/// Axis-aligned rays with +0.0 and −0.0 components, rays lying exactly in
/// a face plane and grazing an edge, at every scale: the robust slab test
/// agrees with the exact interval — it hits whenever the exact ray touches
/// the closed box (no false miss), misses whenever the exact ray clears it
/// by more than rounding, and never answers NaN.
#[test]
fn slab_test_with_signed_zeros_and_face_planes() {
    for s in scales() {
        let b = Aabb::new(Vec3::splat(-s), Vec3::splat(s));
        let coords = [-2.0 * s, -s, -0.5 * s, 0.0, 0.5 * s, s, 2.0 * s];
        let zeros = [0.0f32, -0.0];
        for &y in &coords {
            for &z in &coords {
                for zy in zeros {
                    for zz in zeros {
                        for dx in [1.0f32, -1.0] {
                            let r = Ray::new(Vec3::new(-3.0 * s * dx, y, z), Vec3::new(dx, zy, zz));
                            let got = b.intersect_ray(&r);
                            let want = exact_slab(&b, &r);
                            assert_eq!(got.is_some(), want.is_some(), "{r:?}");
                            if let (Some((t0, t1)), Some((w0, w1))) = (got, want) {
                                assert!(!t0.is_nan() && !t1.is_nan());
                                assert!(f64::from(t0) <= w0 * (1.0 + 1e-6) + 1e-30, "{r:?}");
                                assert!(f64::from(t1) >= w1 * (1.0 - 1e-6), "{r:?}");
                            }
                        }
                    }
                }
            }
        }
        // Grazing: along an edge of the box, and a hair outside it.
        let edge = Ray::new(Vec3::new(-3.0 * s, s, s), Vec3::X);
        assert!(b.intersect_ray(&edge).is_some(), "edge graze at {s:e}");
        let outside = Ray::new(Vec3::new(-3.0 * s, s * (1.0 + 1e-5), s), Vec3::X);
        assert!(b.intersect_ray(&outside).is_none(), "outside graze at {s:e}");
    }
}

/// A sphere of radius `r` at distance up to 1e7·r: the stable root keeps
/// the near distance `D − r` to 1e-6 relative, at every scale, where the
/// textbook `b² − 4ac` in f32 loses every digit.
#[test]
fn far_small_spheres_keep_their_distance() {
    for s in scales() {
        for far in [1e1f32, 1e3, 1e5, 1e7] {
            let (r, d) = (s, far * s);
            let dir = Vec3::new(0.6, 0.0, 0.8);
            let origin = Vec3::new(-0.3 * s, 0.7 * s, 0.1 * s);
            let sphere = Sphere::new(origin + d * dir, r);
            let hit = intersect_sphere(&Ray::new(origin, dir), &sphere, 0)
                .unwrap_or_else(|| panic!("missed at distance {far:e} scale {s:e}"));
            let c = d3(sphere.center);
            let o = d3(origin);
            let exact = len64([c[0] - o[0], c[1] - o[1], c[2] - o[2]]) - f64::from(r);
            let err = (f64::from(hit.t) - exact).abs() / exact;
            assert!(
                err < 1e-6,
                "distance {far:e} scale {s:e}: t {} exact {exact} ({err:e})",
                hit.t
            );
        }
    }
}

/// A ray spawned from a hit on a triangle — onward through it, or back
/// off it — never hits that triangle again, at every scale and far from
/// the origin; the offset is a few ulps of the hit's coordinates.
#[test]
fn spawned_rays_do_not_hit_their_own_surface() {
    for s in scales() {
        for c in [Vec3::ZERO, Vec3::splat(1234.5 * s)] {
            let tri = [
                c + Vec3::new(-s, -s, 0.1 * s),
                c + Vec3::new(s, -0.5 * s, -0.2 * s),
                c + Vec3::new(0.0, s, 0.05 * s),
            ];
            for k in 0..16 {
                let f = k as f32 * 0.37;
                let target = c + Vec3::new(0.3 * f.sin() * s, 0.3 * f.cos() * s, 0.0);
                let from = target + Vec3::new(0.2 * f.cos(), 0.3, 1.0) * (2.0 * s);
                let r = Ray::new(from, target - from);
                let Some(h) = intersect_triangle(&r, tri[0], tri[1], tri[2]) else {
                    panic!("missed the triangle at {s:e}");
                };
                let through = r.direction.normalize();
                let back = -through;
                for w in [through, back, through.reflect(h.normal.normalize())] {
                    let sr = spawn_ray(h.position, h.position_error, h.normal, w);
                    // The offset is a few ulps of the hit's coordinates.
                    let ulp = f32::EPSILON * h.position.abs().max_element().max(s);
                    let off = (sr.origin - h.position).length() / ulp;
                    assert!(off <= 64.0, "offset {off} ulps at {s:e}");
                    assert!(
                        intersect_triangle(&sr, tri[0], tri[1], tri[2]).is_none(),
                        "self-hit at scale {s:e}, centre {c}"
                    );
                }
            }
        }
    }
}

/// Rays that are not rays — NaN or infinite origin or direction, a zero
/// direction (either sign), an empty or NaN range — miss every primitive.
#[test]
fn invalid_rays_miss_everything() {
    let tri = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    let sphere = Sphere::new(Vec3::ZERO, 1.0);
    let capsule = Capsule::new(Vec3::ZERO, Vec3::Z, 0.5);
    let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let o = Vec3::new(0.1, 0.1, -5.0);
    let bad = [
        Ray::new(Vec3::NAN, Vec3::Z),
        Ray::new(Vec3::new(0.0, f32::INFINITY, -5.0), Vec3::Z),
        Ray::new(o, Vec3::new(0.0, 0.0, f32::NAN)),
        Ray::new(o, Vec3::new(0.0, 0.0, f32::INFINITY)),
        Ray::new(o, Vec3::ZERO),
        Ray::new(o, Vec3::splat(-0.0)),
        Ray::with_range(o, Vec3::Z, 10.0, 1.0),
        Ray::with_range(o, Vec3::Z, f32::NAN, 10.0),
        Ray::with_range(o, Vec3::Z, 0.0, f32::NAN),
    ];
    for r in bad {
        assert!(intersect_triangle(&r, tri[0], tri[1], tri[2]).is_none(), "{r:?}");
        assert!(intersect_sphere(&r, &sphere, 0).is_none(), "{r:?}");
        assert!(intersect_capsule(&r, &capsule, 0).is_none(), "{r:?}");
        assert!(b.intersect_ray(&r).is_none(), "{r:?}");
    }
    // The same ray, valid, hits all four.
    let good = Ray::new(o, Vec3::Z);
    assert!(intersect_triangle(&good, tri[0], tri[1], tri[2]).is_some());
    assert!(intersect_sphere(&good, &sphere, 0).is_some());
    assert!(intersect_capsule(&good, &capsule, 0).is_some());
    assert!(b.intersect_ray(&good).is_some());
}
