//! Numerical stability: at coordinate scales and ray lengths from 1e-8 to
//! 1e8 BVH answers equal brute force to the bit and closed meshes let no
//! ray through; invalid rays (NaN, ±∞, zero direction, empty or NaN range)
//! miss everything; zero-area triangles are never hit; grazing and
//! axis-aligned rays with ±0.0 direction components agree with brute force.

mod support;

use proptest::prelude::*;
use rt_accel::{
    Bvh, Primitive, Scene, TraversalStats, build_capsules, build_spheres, build_triangles,
};
use rt_core::{
    Ray, SceneQuery,
    glam::Vec3,
    intersect::{Capsule, Sphere, is_degenerate_triangle},
};
use support::*;

/// The decimal exponents swept: scales `10^k` from 1e-8 to 1e8.
const EXPONENTS: core::ops::RangeInclusive<i32> = -8..=8;

/// Offsets of a shape from the origin, in units of its scale: at the
/// origin, beside it, and far away compared with its size.
const OFFSETS: [f32; 4] = [0.0, 1.0, -30.0, 1000.0];

/// The direction in which shapes are offset (no zero component).
const OFFSET_DIR: Vec3 = Vec3::new(1.0, -0.625, 0.375);

/// `10^k` correctly rounded to f32.
fn pow10(k: i32) -> f32 {
    10f64.powi(k) as f32
}

/// The `i`-th ray length of a log-uniform sweep over 1e-8 … 1e8.
fn length(i: usize) -> f32 {
    pow10((i % 17) as i32 - 8)
}

/// `n` unit vectors spread over the sphere (a Fibonacci lattice).
fn directions(n: usize) -> Vec<Vec3> {
    let golden = core::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - (i as f32 + 0.5) / n as f32 * 2.0;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

/// Number of triangles stored in a BVH's packets.
fn stored_triangles(bvh: &TriBvh) -> usize {
    bvh.items().iter().map(|p| p.len()).sum()
}

/// Asserts that every query of a triangle BVH, on every kernel the CPU
/// runs, answers `r` exactly as brute force does, and returns the
/// brute-force answer.
fn check_triangles(bvh: &TriBvh, pos: &[Vec3], idx: &[[u32; 3]], r: &Ray) -> Option<(f32, u32)> {
    check_items(bvh, r, |r| brute_triangles(pos, idx, r))
}

/// Like [`check_triangles`] for spheres or capsules, with `brute` the
/// reference.
fn check_items<P: Primitive>(
    bvh: &Bvh<P>,
    r: &Ray,
    brute: impl Fn(&Ray) -> Option<(f32, u32)>,
) -> Option<(f32, u32)> {
    let want = brute(r);
    assert_eq!(bvh_t(bvh, r), want, "closest_t, {r:?}");
    for isa in rt_accel::Isa::available() {
        let v = bvh.as_ref().with_isa(isa).unwrap();
        assert_eq!(v.closest_t(r).map(|b| (b.t, b.prim)), want, "closest_t, {isa}, {r:?}");
        assert_eq!(v.closest_hit(r).map(|h| (h.t, h.prim)), want, "closest_hit, {isa}, {r:?}");
        assert_eq!(v.occluded(r), want.is_some(), "occluded, {isa}, {r:?}");
    }
    want
}

/// A closed mesh scaled by `10^k` for every k in -8..=8 and offset by up to
/// 1000 times its size: rays from outside toward points inside it, and
/// rays from those points outward, all hit (no false miss through the
/// closed surface), at ray lengths swept over 1e-8 … 1e8, and every BVH
/// answer equals brute force exactly.
#[test]
fn closed_meshes_have_no_false_misses_at_any_scale() {
    let dirs = directions(12);
    let meshes = [(icosphere(2), Vec3::ZERO, 0.5), (cube(), Vec3::splat(0.5), 0.3)];
    let mut rays = 0;
    for ((pos0, idx), center0, inner) in &meshes {
        for k in EXPONENTS {
            let s = pow10(k);
            for (o, f) in OFFSETS.iter().enumerate() {
                let off = OFFSET_DIR * (f * s);
                let pos: Vec<Vec3> = pos0.iter().map(|p| *p * s + off).collect();
                let center = *center0 * s + off;
                let bvh = build_triangles(&pos, idx, &params()).unwrap();
                // No triangle collapsed in rounding: the mesh is still closed.
                assert_eq!(stored_triangles(&bvh), idx.len(), "k = {k}, offset {f}");
                for (i, d) in dirs.iter().enumerate() {
                    let len = length(i + o * 5 + (k + 8) as usize);
                    let target = center + dirs[(i * 7 + 3) % dirs.len()] * (inner * s);
                    let eye = center + *d * (4.0 * s);
                    let r = Ray::new(eye, (target - eye).normalize() * len);
                    let (t, _) = check_triangles(&bvh, &pos, idx, &r).unwrap_or_else(|| {
                        panic!("outside ray missed, k = {k}, offset {f}: {r:?}")
                    });
                    assert!(t > 0.0 && t.is_finite());
                    let r = Ray::new(target, *d * len);
                    check_triangles(&bvh, &pos, idx, &r)
                        .unwrap_or_else(|| panic!("inside ray missed, k = {k}, offset {f}: {r:?}"));
                    rays += 2;
                }
            }
        }
    }
    assert_eq!(rays, 2 * 17 * 4 * 12 * 2);
}

/// A 3×3×3 grid of spheres and one of capsules, scaled by `10^k` for every
/// k in -8..=8 and offset by up to 1000 times the scale: a ray aimed at
/// each sphere's centre or capsule's axis midpoint from outside the grid
/// hits, at ray lengths swept over 1e-8 … 1e8, and the BVH answers equal
/// brute force exactly.
#[test]
fn spheres_and_capsules_are_hit_at_any_scale() {
    let dirs = directions(27);
    for k in EXPONENTS {
        let s = pow10(k);
        for (o, f) in OFFSETS.iter().enumerate() {
            let off = OFFSET_DIR * (f * s);
            let mut spheres = Vec::new();
            let mut capsules = Vec::new();
            for i in 0..27 {
                let cell = Vec3::new((i % 3) as f32, (i / 3 % 3) as f32, (i / 9) as f32);
                let p = cell * (2.5 * s) + off;
                let radius = (0.25 + 0.125 * (i % 6) as f32) * s;
                spheres.push(Sphere::new(p, radius));
                let axis = Vec3::new(1.0, 0.5, -0.75) * s;
                capsules.push(Capsule::new(p, p + axis, radius * 0.5));
            }
            let sb = build_spheres(&spheres, &params()).unwrap();
            let cb = build_capsules(&capsules, &params()).unwrap();
            let grid_center = Vec3::splat(2.5 * s) + off;
            for i in 0..27 {
                let len = length(i + o + (k + 8) as usize);
                let target = spheres[i].center;
                let eye = grid_center + dirs[i] * (20.0 * s);
                let r = Ray::new(eye, (target - eye).normalize() * len);
                check_items(&sb, &r, |r| brute_spheres(&spheres, r))
                    .unwrap_or_else(|| panic!("sphere missed, k = {k}, offset {f}: {r:?}"));
                let c = &capsules[i];
                let target = (c.p0 + c.p1) * 0.5;
                let r = Ray::new(eye, (target - eye).normalize() * len);
                check_items(&cb, &r, |r| brute_capsules(&capsules, r))
                    .unwrap_or_else(|| panic!("capsule missed, k = {k}, offset {f}: {r:?}"));
            }
        }
    }
}

fn vec3(r: f32) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// A point, direction and `[t_min, t_max]` in shape units.
fn unit_ray() -> impl Strategy<Value = (Vec3, Vec3, f32, bool)> {
    (vec3(4.0), vec3(1.0), 0.0f32..1.0, prop::bool::ANY)
        .prop_filter("zero direction", |(_, d, _, _)| d.length_squared() > 1e-4)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        rng_seed: proptest::test_runner::RngSeed::Fixed(20_240_611),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Random rays against triangles, spheres and capsules at a random scale
    /// `10^k`, offset `10^k·f`, with directions of random length `10^j`
    /// (k, j in -8..=8): every BVH answer equals brute force exactly.
    #[test]
    fn random_rays_at_random_scales_match_brute_force(
        k in -8i32..=8,
        j in -8i32..=8,
        f in prop::sample::select(OFFSETS.to_vec()),
        spheres in prop::collection::vec((vec3(3.0), 0.05f32..1.0), 1..24),
        capsules in prop::collection::vec((vec3(3.0), vec3(1.0), 0.05f32..0.5), 1..24),
        rays in prop::collection::vec(unit_ray(), 24),
    ) {
        let (s, len) = (pow10(k), pow10(j));
        let off = OFFSET_DIR * (f * s);
        let place = |p: Vec3| p * s + off;
        let (ico, idx) = icosphere(1);
        let pos: Vec<Vec3> = ico.iter().map(|&p| place(p)).collect();
        let spheres: Vec<Sphere> = spheres.iter().map(|&(c, r)| Sphere::new(place(c), r * s)).collect();
        let capsules: Vec<Capsule> = capsules
            .iter()
            .map(|&(a, d, r)| Capsule::new(place(a), place(a + d), r * s))
            .collect();
        let tb = build_triangles(&pos, &idx, &params()).unwrap();
        let sb = build_spheres(&spheres, &params()).unwrap();
        let cb = build_capsules(&capsules, &params()).unwrap();
        for &(o, d, t_min, inf) in &rays {
            // t is measured in units of |direction|: scale the range with it.
            let t_max = if inf { f32::INFINITY } else { 8.0 * s / len };
            let r = Ray::with_range(place(o), d.normalize() * len, t_min * s / len, t_max);
            check_triangles(&tb, &pos, &idx, &r);
            check_items(&sb, &r, |r| brute_spheres(&spheres, r));
            check_items(&cb, &r, |r| brute_capsules(&capsules, r));
        }
    }
}

/// Rays that [`Ray::is_valid`] rejects, made from `base` by spoiling one
/// thing at a time: NaN or ±∞ in the origin or direction, zero directions
/// (either sign of zero), `t_min > t_max`, NaN or infinite `t_min`, NaN
/// `t_max`.
fn invalid_rays(base: Ray) -> Vec<Ray> {
    let mut out = Vec::new();
    for a in 0..3 {
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            let mut r = base;
            r.origin[a] = bad;
            out.push(r);
            let mut r = base;
            r.direction[a] = bad;
            out.push(r);
        }
    }
    for d in [Vec3::ZERO, Vec3::splat(-0.0), Vec3::new(0.0, -0.0, 0.0)] {
        out.push(Ray { direction: d, ..base });
        out.push(Ray { origin: Vec3::NAN, direction: d, ..base });
    }
    for (t_min, t_max) in [
        (5.0, 4.0),
        (1.0, 0.0),
        (0.0, -f32::MIN_POSITIVE),
        (f32::MAX, 1.0),
        (0.0, f32::NEG_INFINITY),
        (0.0, f32::NAN),
        (f32::NAN, 10.0),
        (f32::NAN, f32::NAN),
        (f32::NAN, f32::INFINITY),
        (f32::INFINITY, f32::INFINITY),
        (f32::NEG_INFINITY, 10.0),
        (f32::NEG_INFINITY, f32::INFINITY),
    ] {
        out.push(Ray { t_min, t_max, ..base });
    }
    out
}

/// A BVH miss for `r` through every query, the borrowed view included.
fn assert_misses<P: Primitive>(bvh: &Bvh<P>, r: &Ray) {
    assert_eq!(bvh.closest_hit(r), None, "{r:?}");
    assert_eq!(bvh.closest_t(r), None, "{r:?}");
    assert!(!bvh.occluded(r), "{r:?}");
    let view = bvh.as_ref();
    assert_eq!(view.closest_hit(r), None, "{r:?}");
    assert!(!view.occluded(r), "{r:?}");
    let mut stats = TraversalStats::default();
    assert_eq!(view.closest_hit_stats(r, &mut stats), None, "{r:?}");
    assert_eq!(SceneQuery::closest_hit(bvh, r), None, "{r:?}");
    assert!(!SceneQuery::occluded(bvh, r), "{r:?}");
}

/// Rays with NaN or ±∞ in origin or direction, zero directions, `t_min >
/// t_max` or a NaN bound miss everything (no hit, not occluded, no panic)
/// in triangle, sphere and capsule BVHs and in a [`Scene`], although the
/// valid ray they were made from hits every one of them.
#[test]
fn invalid_rays_miss_everything() {
    let (pos, idx) = cube();
    let scene = Scene {
        triangles: build_triangles(&pos, &idx, &params()).unwrap(),
        spheres: build_spheres(&[Sphere::new(Vec3::new(0.5, 0.5, -2.0), 0.5)], &params()).unwrap(),
        capsules: build_capsules(
            &[Capsule::new(Vec3::new(0.5, 0.5, -4.0), Vec3::new(0.5, 0.5, -5.0), 0.25)],
            &params(),
        )
        .unwrap(),
    };
    let base = Ray::with_range(Vec3::new(0.5, 0.5, 5.0), Vec3::new(0.01, -0.02, -1.0), 0.0, 100.0);
    assert!(scene.triangles.closest_hit(&base).is_some());
    assert!(scene.spheres.closest_hit(&base).is_some());
    assert!(scene.capsules.closest_hit(&base).is_some());
    assert!(scene.closest_hit(&base).is_some() && scene.occluded(&base));
    let rays = invalid_rays(base);
    assert!(rays.len() > 30);
    for r in &rays {
        assert!(!r.is_valid(), "{r:?}");
        assert_misses(&scene.triangles, r);
        assert_misses(&scene.spheres, r);
        assert_misses(&scene.capsules, r);
        assert_eq!(scene.closest_hit(r), None, "{r:?}");
        assert!(!scene.occluded(r), "{r:?}");
        assert_eq!(brute_triangles(&pos, &idx, r), None);
    }
}

/// Valid rays at the edges of f32 (origin or direction near `f32::MAX`,
/// subnormal directions, `t_max = f32::MAX`) do not panic and agree with
/// brute force, for triangles, spheres and capsules.
#[test]
fn extreme_finite_rays_agree_with_brute_force() {
    let (pos, idx) = cube();
    let tb = build_triangles(&pos, &idx, &params()).unwrap();
    let spheres = [Sphere::new(Vec3::splat(0.5), 0.75), Sphere::new(Vec3::splat(3.0e18), 1.0e17)];
    let sb = build_spheres(&spheres, &params()).unwrap();
    let capsules = [Capsule::new(Vec3::ZERO, Vec3::ONE, 0.25)];
    let cb = build_capsules(&capsules, &params()).unwrap();
    let big = f32::MAX;
    let tiny = f32::from_bits(1); // the smallest subnormal
    let rays = [
        Ray::new(Vec3::new(-big, 0.5, 0.5), Vec3::X),
        Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(0.0, 0.0, -big)),
        Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(big, big, -big)),
        Ray::new(Vec3::splat(-big), Vec3::ONE),
        Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(0.0, 0.0, -tiny)),
        Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(tiny, -tiny, -1.0)),
        Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(0.0, 0.0, -1.0e-30)),
        Ray::with_range(Vec3::new(0.5, 0.5, 5.0), Vec3::NEG_Z, 0.0, big),
        Ray::with_range(Vec3::new(0.5, 0.5, 5.0), Vec3::NEG_Z, big, big),
        Ray::new(Vec3::splat(2.0e18), Vec3::ONE),
        Ray::new(Vec3::splat(2.0e38), Vec3::ONE),
        Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(1.0e-38, 1.0e-38, -1.0e-38)),
    ];
    for r in &rays {
        assert!(r.is_valid());
        check_triangles(&tb, &pos, &idx, r);
        check_items(&sb, r, |r| brute_spheres(&spheres, r));
        check_items(&cb, r, |r| brute_capsules(&capsules, r));
    }
    // A ray with a direction of 1e-30 still finds the cube at t = 4e30.
    let r = Ray::new(Vec3::new(0.5, 0.5, 5.0), Vec3::new(0.0, 0.0, -1.0e-30));
    assert_eq!(bvh_t(&tb, &r).map(|(t, _)| t), Some(4.0e30));
}

/// Zero-area triangles of every kind, at scale `s`, plus two ordinary
/// ones, as separate vertex triples. Triangles 0..=5 are degenerate: all
/// three vertices equal; two equal; exactly collinear in the plane z = 0;
/// exactly collinear along the diagonal (0,0,0), (1,1,1), (2,2,2); along
/// the z axis; collinear with a repeated vertex. Triangle 6 is ordinary and
/// covers every degenerate point in the plane z = 0; triangle 7 is a large
/// backstop at z = −10·s.
fn degenerate_set(s: f32) -> Vec<[Vec3; 3]> {
    let v = |x: f32, y: f32, z: f32| Vec3::new(x, y, z) * s;
    vec![
        [v(0.5, 0.25, 0.0), v(0.5, 0.25, 0.0), v(0.5, 0.25, 0.0)],
        [v(0.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, -1.0, 0.0)],
        [v(-1.0, -1.0, 0.0), v(0.0, 0.0, 0.0), v(1.0, 1.0, 0.0)],
        [v(0.0, 0.0, 0.0), v(1.0, 1.0, 1.0), v(2.0, 2.0, 2.0)],
        [v(0.0, 0.0, 0.0), v(0.0, 0.0, 1.0), v(0.0, 0.0, 3.0)],
        [v(1.0, 1.0, 1.0), v(2.0, 2.0, 2.0), v(1.0, 1.0, 1.0)],
        [v(-4.0, -4.0, 0.0), v(4.0, -4.0, 0.0), v(0.0, 4.0, 0.0)],
        [v(-40.0, -40.0, -10.0), v(40.0, -40.0, -10.0), v(0.0, 40.0, -10.0)],
    ]
}

const DEGENERATE: usize = 6;

/// Flattens triangles into positions and indices.
fn soup(tris: &[[Vec3; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let pos = tris.iter().flatten().copied().collect();
    let idx = (0..tris.len() as u32).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    (pos, idx)
}

/// Rays aimed exactly at every vertex and edge midpoint of the degenerate
/// triangles, from above, obliquely, along the diagonal line itself and
/// with ±0.0 components: none hits a degenerate triangle, each hits an
/// ordinary one; where the degenerate point lies in the ordinary
/// triangle's plane, the hit is that triangle (though the degenerate ones
/// have lower indices and would win a tie), and every answer equals brute
/// force.
fn assert_degenerate_never_hit(bvh: &TriBvh, tris: &[[Vec3; 3]], s: f32) {
    let (pos, idx) = soup(tris);
    let dirs = [
        Vec3::NEG_Z,
        Vec3::new(-0.0, 0.0, -1.0),
        Vec3::new(0.0, -0.0, -1.0),
        Vec3::new(0.3, -0.2, -1.0),
        Vec3::new(-1.0, -1.0, -1.0),
        Vec3::new(-0.5, -0.0, -1.0),
    ];
    let mut rays = 0;
    for tri in &tris[..DEGENERATE] {
        let mut targets = tri.to_vec();
        targets.extend((0..3).map(|e| (tri[e] + tri[(e + 1) % 3]) * 0.5));
        for p in targets {
            for d in dirs {
                let r = Ray::new(p - d * (10.0 * s), d);
                let (t, prim) = check_triangles(bvh, &pos, &idx, &r)
                    .unwrap_or_else(|| panic!("backstop missed: {r:?}"));
                assert!(prim as usize >= DEGENERATE, "degenerate triangle {prim} hit by {r:?}");
                if p.z == 0.0 {
                    assert_eq!(prim, 6, "{r:?}");
                    assert!((t / (10.0 * s) - 1.0).abs() < 1e-5, "t = {t}");
                }
                rays += 1;
            }
        }
    }
    assert_eq!(rays, DEGENERATE * 6 * dirs.len());
}

/// Degenerate (zero-area) triangles, at scales 1e-8 … 1e8, are left out at
/// build time and never hit, even by rays aimed exactly at their points,
/// while the ordinary triangles in the same mesh are hit.
#[test]
fn degenerate_triangles_are_never_hit() {
    for k in EXPONENTS {
        let s = pow10(k);
        let tris = degenerate_set(s);
        for t in &tris[..DEGENERATE] {
            assert!(is_degenerate_triangle(t[0], t[1], t[2]), "{t:?}");
        }
        let (pos, idx) = soup(&tris);
        let bvh = build_triangles(&pos, &idx, &params()).unwrap();
        assert_eq!(stored_triangles(&bvh), 2);
        assert_eq!(bvh.prim_count(), tris.len() as u32);
        assert_degenerate_never_hit(&bvh, &tris, s);
    }
}

/// Triangles that become degenerate through a refit stay in the tree as
/// packet lanes; traversal must still never report them (at scales 1e-8 …
/// 1e8), and the ordinary triangles must still be hit. `det` of an exactly
/// collinear triangle rounds to non-zero after the shear, so refit must not
/// leave such a triangle as it is. Smallest case: refit one triangle to
/// (0,0,0), (1,1,1), (2,2,2); the ray from (−2, 3, 11) along (0.3, −0.2, −1)
/// passes through (1, 1, 1).
#[test]
fn triangles_made_degenerate_by_refit_are_never_hit() {
    for k in EXPONENTS {
        let s = pow10(k);
        let tris = degenerate_set(s);
        // The same triangles with two vertices moved off the line: all ordinary.
        let moved: Vec<[Vec3; 3]> = tris
            .iter()
            .enumerate()
            .map(|(i, t)| {
                if i < DEGENERATE {
                    [t[0], t[1] + Vec3::new(1.0, 0.0, 0.0) * s, t[2] + Vec3::new(0.0, 1.0, 0.5) * s]
                } else {
                    *t
                }
            })
            .collect();
        for t in &moved {
            assert!(!is_degenerate_triangle(t[0], t[1], t[2]), "{t:?}");
        }
        let (pos0, idx) = soup(&moved);
        let mut bvh = build_triangles(&pos0, &idx, &params()).unwrap();
        assert_eq!(stored_triangles(&bvh), tris.len());
        let (pos, _) = soup(&tris);
        bvh.refit_triangles(&pos, &idx).unwrap();
        assert_eq!(stored_triangles(&bvh), tris.len(), "refit keeps every lane");
        assert_degenerate_never_hit(&bvh, &tris, s);
    }
}

/// A 2×2×2 block of unit cubes in `[0, 2]³`: coincident coplanar faces
/// between neighbours and flat, axis-aligned leaf boxes.
fn cube_block() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (cp, ci) = cube();
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    for c in 0..8 {
        let shift = Vec3::new((c & 1) as f32, ((c >> 1) & 1) as f32, ((c >> 2) & 1) as f32);
        let base = pos.len() as u32;
        pos.extend(cp.iter().map(|p| *p + shift));
        idx.extend(ci.iter().map(|t| t.map(|i| i + base)));
    }
    (pos, idx)
}

/// Coordinates on and between the block's planes.
const GRID: [f32; 9] = [-1.0, 0.0, 0.25, 0.5, 1.0, 1.5, 1.75, 2.0, 3.0];
/// Direction components: ±0.0, axis units, and grazing slopes.
const DIR: [f32; 8] = [-1.0, -0.5, -0.0, 0.0, 0.5, 1.0, 1.0e-7, -1.0e-7];

fn grid_ray() -> impl Strategy<Value = Ray> {
    let c = || prop::sample::select(GRID.to_vec());
    let d = || prop::sample::select(DIR.to_vec());
    ((c(), c(), c()), (d(), d(), d()), prop::sample::select(vec![-3.0f32, -0.5, 0.0, 0.5, 1.0]))
        .prop_filter_map("zero direction", |((ox, oy, oz), (dx, dy, dz), t_min)| {
            let d = Vec3::new(dx, dy, dz);
            (d != Vec3::ZERO)
                .then(|| Ray::with_range(Vec3::new(ox, oy, oz), d, t_min, f32::INFINITY))
        })
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x57AB),
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Axis-aligned and grazing rays (components of ±0.0 and ±1e-7) from
    /// points on and between the planes of a block of cubes, so rays run
    /// inside face planes, along edges and through vertices, with ranges
    /// starting behind, at and ahead of the origin: BVH answers equal brute
    /// force exactly.
    #[test]
    fn axis_aligned_and_grazing_rays_match_brute_force(rays in prop::collection::vec(grid_ray(), 48)) {
        let (pos, idx) = cube_block();
        let bvh = build_triangles(&pos, &idx, &params()).unwrap();
        for r in &rays {
            check_triangles(&bvh, &pos, &idx, r);
        }
    }
}

/// Rays lying exactly in a face plane of a sphere's or capsule's box, with
/// ±0.0 direction components, touch the primitive tangentially: the box
/// test must not cull them (a NaN slab distance must not narrow the
/// interval), so the BVH hits wherever brute force does, and the exactly
/// tangent sphere rays do hit.
#[test]
fn rays_in_box_face_planes_match_brute_force() {
    let spheres: Vec<Sphere> = (0..8)
        .map(|i| {
            Sphere::new(
                Vec3::new(4.0 * i as f32, (i % 3) as f32, -2.0 * (i % 2) as f32),
                0.5 + (i % 4) as f32 * 0.25,
            )
        })
        .collect();
    let capsules: Vec<Capsule> = spheres
        .iter()
        .map(|s| Capsule::new(s.center, s.center + Vec3::new(0.0, 0.0, 2.0), s.radius))
        .collect();
    let sb = build_spheres(&spheres, &params()).unwrap();
    let cb = build_capsules(&capsules, &params()).unwrap();
    let zeros = [0.0, -0.0];
    let mut tangent_hits = 0;
    for (i, sp) in spheres.iter().enumerate() {
        let (c, r) = (sp.center, sp.radius);
        for zx in zeros {
            for zy in zeros {
                // In the plane x = c.x + r, going −z; in the plane y = c.y − r, going +x.
                let rays = [
                    Ray::new(Vec3::new(c.x + r, c.y, c.z + 10.0), Vec3::new(zx, zy, -1.0)),
                    Ray::new(Vec3::new(c.x - 1.5, c.y - r, c.z), Vec3::new(1.0, zx, zy)),
                    Ray::new(Vec3::new(c.x + r, c.y + r, c.z + 10.0), Vec3::new(zx, zy, -1.0)),
                ];
                for (j, ray) in rays.iter().enumerate() {
                    let hit = check_items(&sb, ray, |r| brute_spheres(&spheres, r));
                    if j < 2 {
                        // Exactly tangent (r, c are dyadic): one touching point.
                        let (_, prim) =
                            hit.unwrap_or_else(|| panic!("tangent ray missed sphere {i}: {ray:?}"));
                        assert_eq!(prim as usize, i);
                        tangent_hits += 1;
                    }
                    check_items(&cb, ray, |r| brute_capsules(&capsules, r));
                }
            }
        }
    }
    assert_eq!(tangent_hits, spheres.len() * 4 * 2);
}

/// A ray whose `[t_min, t_max]` range lies (partly) behind its origin is
/// valid ([`Ray::is_valid`] needs only a finite `t_min ≤ t_max`), so the
/// BVH finds hits at negative `t` as brute force does, flat boxes (an
/// axis-aligned triangle) included: the far slab distance must be widened
/// toward +∞ whatever its sign.
#[test]
fn hits_behind_the_origin_match_brute_force() {
    let pos = [Vec3::new(1.0, -1.0, -1.0), Vec3::new(1.0, 2.0, -1.0), Vec3::new(1.0, -1.0, 2.0)];
    let idx = [[0, 1, 2]];
    let bvh = build_triangles(&pos, &idx, &params()).unwrap();
    let r = Ray::with_range(Vec3::new(3.0, 0.0, 0.0), Vec3::X, -10.0, 10.0);
    assert_eq!(brute_triangles(&pos, &idx, &r), Some((-2.0, 0)));
    check_triangles(&bvh, &pos, &idx, &r);
}

/// Rays that start within rounding distance of a face plane, or graze a
/// face at a slope of 1e-30, still get the brute-force answer, tie rule
/// included. Without the triangle test's box check (`triangle_admits_hit`)
/// the watertight test accepts hits a rounding error outside the triangle's
/// box or before `t_min` (`t = −0.0` for a face 1e-30 behind the origin),
/// which the BVH's box culling rejects.
#[test]
fn rays_within_rounding_of_a_face_match_brute_force() {
    let (pos, idx) = cube();
    let bvh = build_triangles(&pos, &idx, &params()).unwrap();
    let rays = [
        // 1e-30 below the face z = 0, leaving it: brute force hits at t = −0.0.
        Ray::new(Vec3::new(0.5, 0.5, -1.0e-30), Vec3::new(-0.5, -1.0, -1.0)),
        // Grazing the face z = 0, crossing its plane 1e-30 outside its edge y = 0.
        Ray::with_range(
            Vec3::new(0.5, 0.0, -1.0e-30),
            Vec3::new(1.0e-7, -1.0e-30, 1.0e-30),
            0.5,
            f32::INFINITY,
        ),
    ];
    for r in &rays {
        check_triangles(&bvh, &pos, &idx, r);
    }
    let (pos, idx) = cube_block();
    let bvh = build_triangles(&pos, &idx, &params()).unwrap();
    // In the plane z = 1, reaching the edge y = 1 at t = 1: triangles 7 and 54 both hit at t = 1.
    let r = Ray::new(Vec3::new(0.5, 1.0000001, 1.0), Vec3::new(1.0e-7, -1.0e-7, -0.0));
    check_triangles(&bvh, &pos, &idx, &r);
}

/// Found by the `bvh` fuzz target: vertices near `f32::MAX` make the
/// packet test's `t` overflow to `+∞`, which `occluded` took for a hit
/// while `closest_hit` (and brute force) found none. A `t` of `+∞` is no
/// hit anywhere now.
#[test]
fn fuzz_regression_overflowing_t_is_no_hit() {
    let tiny = f32::MIN_POSITIVE;
    let pos = vec![
        Vec3::new(0.0, tiny, tiny),
        Vec3::new(tiny, tiny, 0.0),
        Vec3::new(-3.9375, 0.0, f32::MAX),
        Vec3::new(-1.125, -1.125, -1.125),
        Vec3::new(-1.125, -1.125, 1.375),
        Vec3::new(3.875, tiny, tiny),
    ];
    let idx = vec![[0, 1, 2], [2, 4, 5]];
    let ray = Ray::new(Vec3::new(1.4375, tiny, 1.3125), Vec3::new(1.3125, 1.3125, -3.6875));
    for params in [
        rt_accel::BuildParams::fast(),
        rt_accel::BuildParams::medium(),
        rt_accel::BuildParams::slow(),
    ] {
        let bvh = build_triangles(&pos, &idx, &params).unwrap();
        assert_eq!(check_triangles(&bvh, &pos, &idx, &ray), None);
    }
}

/// Found by the `bvh` fuzz target: with the slow presets' spatial
/// pre-splits, a leaf held a clipped part of a triangle's box, and a hit
/// on that box's boundary (at the ray origin, `t = -0.0`) fell outside it:
/// the BVH missed what brute force hit. Boxes are refitted to the whole
/// triangles now.
#[test]
fn fuzz_regression_pre_split_boxes_hold_whole_triangles() {
    let t = f32::MIN_POSITIVE;
    let pos = vec![
        Vec3::new(-1.125, 0.0, -1.125),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.192_092_9e-7, 0.0, 0.0),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, t, t),
        Vec3::new(t, -4.0, 1e30),
        Vec3::new(2.875, 2.25, 2.875),
        Vec3::new(-0.75, t, t),
        Vec3::new(t, 3.59e-43, 0.0),
        Vec3::new(-448_843.8, t, t),
        Vec3::new(t, t, -4.0),
        Vec3::new(0.0, 0.0, 0.0),
    ];
    let idx = vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [8, 10, 11]];
    let ray = Ray {
        origin: Vec3::splat(t),
        direction: Vec3::new(100_000.0, 0.0, 7.2027e-41),
        t_min: 0.0,
        t_max: f32::INFINITY,
    };
    for quality in rt_accel::BuildQuality::ALL {
        let params = rt_accel::BuildParams { quality, ..rt_accel::BuildParams::medium() };
        let bvh = build_triangles(&pos, &idx, &params).unwrap();
        assert_eq!(check_triangles(&bvh, &pos, &idx, &ray), Some((-0.0, 1)), "{quality:?}");
    }
}

/// Found by the `bvh` fuzz target: a ray with `t_min = t_max = 0.75`
/// hitting a plane at exactly 0.75. `closest_hit` widened its box bound
/// and found it; `occluded` culled the box (entered at a rounded 0.75 + ε)
/// and said no. Both widen the bound now.
#[test]
fn fuzz_regression_occluded_at_exactly_t_max() {
    let pos = vec![
        Vec3::new(-3.1875, 10000.0, -2.8125),
        Vec3::new(-2.8125, -2.8125, -2.8125),
        Vec3::new(10000.0, 2.6875, -2.8125),
        Vec3::new(-2.8125, 0.5, -2.8125),
        Vec3::new(2.6875, -2.8125, -2.8125),
        Vec3::new(-2.8125, 2.6875, 2.4375),
        Vec3::new(1.0, -2.5625, 2.75),
        Vec3::new(-0.0, 0.0, -2.8125),
        Vec3::new(-1.1875, 3.875, 3.875),
        Vec3::new(2.875, -2.8125, -2.8125),
        Vec3::new(-2.8125, 3.875, 3.875),
        Vec3::new(3.875, 3.875, 3.875),
        Vec3::new(1e-8, 0.0, 0.0),
        Vec3::new(3.875, -1e-8, 3.875),
        Vec3::new(1.0, 3.875, 3.875),
    ];
    let idx = vec![[0, 1, 2], [2, 4, 5], [6, 7, 8], [9, 10, 11], [12, 13, 14]];
    let ray = Ray {
        origin: Vec3::new(3.875, -0.0, 0.0),
        direction: Vec3::new(0.0, 1.192_092_9e-7, -3.75),
        t_min: 0.75,
        t_max: 0.75,
    };
    for quality in rt_accel::BuildQuality::ALL {
        let params = rt_accel::BuildParams { quality, ..rt_accel::BuildParams::medium() };
        let bvh = build_triangles(&pos, &idx, &params).unwrap();
        assert_eq!(check_triangles(&bvh, &pos, &idx, &ray), Some((0.75, 0)), "{quality:?}");
    }
}

/// A flat grid of small squares far from the origin (`|o| ≈ 4·10⁴`), with
/// rays from about one unit away aimed at its vertices and edge points:
/// there `|o/d|` is 10⁴ times the hit distance, so a box test that rounds
/// `o·(1/d)` on its own (`fma(b, 1/d, −o·(1/d))`, one instruction per
/// plane) without a margin for it leaves boxes the exact test enters
/// (tried: it fails here). Every kernel must answer as brute force does,
/// and no ray may slip through the grid.
#[test]
fn grid_far_from_the_origin_hit_near_its_vertices() {
    let n = 12;
    let base = Vec3::new(1.1e4, -2.3e4, 3.7e4);
    let mut pos = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            pos.push(base + Vec3::new(i as f32 * 0.37, j as f32 * 0.41, 0.0));
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    let mut idx = Vec::new();
    for j in 0..n {
        for i in 0..n {
            idx.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            idx.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    let bvh = build_triangles(&pos, &idx, &rt_accel::BuildParams { max_leaf_size: 1, ..params() })
        .unwrap();
    let mut rays = 0;
    for j in 1..n {
        for i in 1..n {
            let v = pos[at(i, j) as usize];
            let w = pos[at(i + 1, j) as usize];
            for target in [v, (v + w) * 0.5, v + (w - v) * 0.3] {
                for (k, off) in [
                    Vec3::new(0.31, 0.17, 0.9),
                    Vec3::new(-0.23, 0.29, -1.3),
                    Vec3::new(0.07, -0.61, 0.45),
                    Vec3::new(-1.9, -0.8, 2.1),
                ]
                .into_iter()
                .enumerate()
                {
                    let eye = target + off;
                    let r = Ray::new(eye, target - eye);
                    let got = check_triangles(&bvh, &pos, &idx, &r);
                    assert!(got.is_some(), "ray {k} from {eye} → {target} slipped through");
                    rays += 1;
                }
            }
        }
    }
    assert!(rays > 1000);
}
