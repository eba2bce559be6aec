//! BVH answers equal brute force; bytes round-trip; refit equals rebuild.

mod support;

use proptest::prelude::*;
use rt_accel::{
    BuildParams, BuildQuality, Bvh, Isa, TriPacket, build_capsules, build_spheres, build_triangles,
};
use rt_core::{
    Ray, SceneQuery,
    glam::Vec3,
    intersect::{Capsule, Sphere, intersect_triangle},
};
use support::*;

fn vec3(r: f32) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Random triangle soup: small triangles scattered in a box, some sharing
/// vertices.
fn soup() -> impl Strategy<Value = (Vec<Vec3>, Vec<[u32; 3]>)> {
    (prop::collection::vec((vec3(10.0), vec3(1.5), vec3(1.5)), 1..120)).prop_map(|tris| {
        let mut pos = Vec::new();
        let mut idx = Vec::new();
        for (i, (c, a, b)) in tris.into_iter().enumerate() {
            let base = pos.len() as u32;
            pos.extend([c, c + a, c + b]);
            // Every third triangle reuses the previous triangle's edge.
            if i % 3 == 2 && base >= 3 {
                idx.push([base - 2, base - 1, base]);
            } else {
                idx.push([base, base + 1, base + 2]);
            }
        }
        (pos, idx)
    })
}

fn ray() -> impl Strategy<Value = Ray> {
    // Negative `t_min` too: the single-ray kernels test such rays with the
    // full far-plane comparison, the others with a shorter one.
    (vec3(14.0), vec3(1.0), -2.0f32..2.0, prop::bool::ANY).prop_filter_map(
        "zero dir",
        |(o, d, tmin, inf)| {
            if d.length_squared() < 1e-6 {
                return None;
            }
            let t_max = if inf { f32::INFINITY } else { 12.0 };
            Some(Ray::with_range(o, d, tmin, t_max))
        },
    )
}

fn quality() -> impl Strategy<Value = BuildParams> {
    (0usize..6, 1u32..=16)
        .prop_map(|(q, leaf)| BuildParams { quality: BuildQuality::ALL[q], max_leaf_size: leaf })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, rng_seed: proptest::test_runner::RngSeed::Fixed(7), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn triangles_match_brute_force((pos, idx) in soup(), rays in prop::collection::vec(ray(), 64), p in quality()) {
        let bvh = build_triangles(&pos, &idx, &p).unwrap();
        // On every kernel this CPU runs (Isa::detect's among them).
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            for r in &rays {
                let want = brute_triangles(&pos, &idx, r);
                prop_assert_eq!(view.closest_t(r).map(|b| (b.t, b.prim)), want, "{}", isa);
                prop_assert_eq!(view.occluded(r), want.is_some(), "{}", isa);
                if let Some(h) = view.closest_hit(r) {
                    prop_assert_eq!((h.t, h.prim), want.unwrap());
                    // The whole record, as the scalar test makes it for
                    // that triangle alone: same barycentrics, normal,
                    // position and error bound, bit for bit.
                    let [a, b, c] = idx[h.prim as usize].map(|k| pos[k as usize]);
                    let mut s = intersect_triangle(r, a, b, c).unwrap();
                    s.prim = h.prim;
                    prop_assert_eq!(h, s, "{}", isa);
                }
            }
        }
    }

    /// The same at every scale, from geometry below `2⁻¹⁰⁰` through trees
    /// past the AVX kernels' fused node test's range (`2¹²⁶`), which then
    /// take the robust test; with rays from the triangles' vertices (on
    /// the boxes' planes) and rays along an axis among them.
    #[test]
    fn triangles_match_brute_force_at_every_scale(
        (pos, idx) in soup(),
        rays in prop::collection::vec(ray(), 48),
        exp in prop::sample::select(vec![-110i32, -60, -20, 0, 40, 100, 118, 122, 124]),
    ) {
        let s = 2f32.powi(exp);
        let pos: Vec<Vec3> = pos.iter().map(|&p| p * s).collect();
        let mut rays: Vec<Ray> = rays
            .iter()
            .map(|r| Ray::with_range(r.origin * s, r.direction, r.t_min.max(0.0) * s, r.t_max * s))
            .collect();
        for (i, v) in pos.iter().enumerate().take(16) {
            let d = if i % 2 == 0 { Vec3::new(0.0, -1.0, 0.0) } else { Vec3::new(0.3, -1.0, 0.2) };
            rays.push(Ray::new(*v, d));
            rays.push(Ray::new(*v + Vec3::Y * s, d));
        }
        let bvh = build_triangles(&pos, &idx, &BuildParams::medium()).unwrap();
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            for r in &rays {
                let want = brute_triangles(&pos, &idx, r);
                prop_assert_eq!(view.closest_t(r).map(|b| (b.t, b.prim)), want, "{} {:?}", isa, r);
                prop_assert_eq!(view.occluded(r), want.is_some(), "{} {:?}", isa, r);
            }
        }
    }

    /// Packets of eight rays (some invalid, some sharing an origin) answer
    /// exactly as the single-ray queries, on every kernel.
    #[test]
    fn packets_answer_as_single_rays(
        (pos, idx) in soup(),
        rays in prop::collection::vec(ray(), 8 * 6),
        invalid in prop::collection::vec(0usize..8, 0..3),
        p in quality(),
    ) {
        let bvh = build_triangles(&pos, &idx, &p).unwrap();
        let mut rays = rays;
        for (k, chunk) in rays.chunks_mut(8).enumerate() {
            if k % 2 == 1 {
                // A shared origin: camera-like.
                let o = chunk[0].origin;
                for r in chunk.iter_mut() {
                    r.origin = o;
                }
            }
            for &i in &invalid {
                chunk[i].origin.x = f32::NAN;
            }
        }
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            for chunk in rays.chunks(8) {
                let packet: &[Ray; 8] = chunk.try_into().unwrap();
                let closest = view.closest_t_packet(packet);
                let occluded = view.occluded_packet(packet);
                // The renderer's entry point (single rays on the AVX
                // kernels, packets on the others): whole hit records.
                let records = SceneQuery::closest_hit_packet(&view, packet);
                for (i, r) in packet.iter().enumerate() {
                    prop_assert_eq!(records[i], view.closest_hit(r), "{} ray {}", isa, i);
                    // `t` and primitive; `item`/`lane` may name another
                    // reference to the same triangle (builds may split).
                    let th = |b: Option<rt_accel::BestHit>| b.map(|b| (b.t.to_bits(), b.prim));
                    prop_assert_eq!(th(closest[i]), th(view.closest_t(r)), "{} ray {}", isa, i);
                    prop_assert_eq!(occluded[i], view.occluded(r), "{} ray {}", isa, i);
                }
            }
        }
    }

    /// Streams (rays some invalid, more rays than lanes, any count) report
    /// every ray exactly once, with the single-ray query's answer, on every
    /// kernel.
    #[test]
    fn streams_answer_as_single_rays(
        (pos, idx) in soup(),
        rays in prop::collection::vec(ray(), 0..40),
        invalid in prop::collection::vec(0usize..40, 0..6),
        p in quality(),
    ) {
        let bvh = build_triangles(&pos, &idx, &p).unwrap();
        let mut rays = rays;
        for &i in &invalid {
            if let Some(r) = rays.get_mut(i) {
                r.direction = Vec3::ZERO;
            }
        }
        let th = |b: Option<rt_accel::BestHit>| b.map(|b| (b.t.to_bits(), b.prim));
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            let mut closest = vec![None; rays.len()];
            let mut seen = vec![0u32; rays.len()];
            view.closest_t_stream(&rays, |i, h| {
                closest[i] = th(h);
                seen[i] += 1;
            });
            let mut occluded = vec![None; rays.len()];
            view.occluded_stream(&rays, |i, o| {
                occluded[i] = Some(o);
                seen[i] += 1;
            });
            prop_assert!(seen.iter().all(|&n| n == 2), "{}: {:?}", isa, seen);
            for (i, r) in rays.iter().enumerate() {
                prop_assert_eq!(closest[i], th(view.closest_t(r)), "{} ray {}", isa, i);
                prop_assert_eq!(occluded[i], Some(view.occluded(r)), "{} ray {}", isa, i);
            }
        }
    }

    /// Streams of shadow-like rays (one direction, origins spread,
    /// `t_min ≥ 0`: occlusion groups whose rays share an octant take the
    /// fused node test with the plane rows loaded once, and closest-hit
    /// runs of 32 such rays walk the tree as a group), some with a
    /// component's sign flipped (groups of mixed octants), some with
    /// `t_min < 0`, some from past the fused test's range, some invalid:
    /// every answer is brute force's, on every kernel.
    #[test]
    fn coherent_streams_answer_as_brute_force(
        (pos, idx) in soup(),
        d in vec3(1.0).prop_filter("zero dir", |d| d.length_squared() > 1e-4),
        rays in prop::collection::vec((vec3(14.0), 0.0f32..3.0, 0.5f32..30.0, 0u32..200), 1..150),
        p in quality(),
    ) {
        let bvh = build_triangles(&pos, &idx, &p).unwrap();
        let rays: Vec<Ray> = rays
            .into_iter()
            .map(|(o, t_min, t_max, kind)| {
                let (mut o, mut d, mut t_min) = (o, d, t_min);
                match kind {
                    0 => d.x = -d.x,
                    1 => d.z = -d.z,
                    2 => t_min = -t_min,
                    3 => o *= 1e38,
                    4 => d = Vec3::ZERO,
                    _ => {}
                }
                Ray::with_range(o, d, t_min, t_min + t_max)
            })
            .collect();
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            let (mut got, mut seen) = (vec![None; rays.len()], vec![0u32; rays.len()]);
            view.occluded_stream(&rays, |i, o| {
                got[i] = Some(o);
                seen[i] += 1;
            });
            prop_assert!(seen.iter().all(|&n| n == 1), "{}: {:?}", isa, seen);
            let mut closest = vec![None; rays.len()];
            view.closest_t_stream(&rays, |i, h| {
                closest[i] = h.map(|b| (b.t, b.prim));
                seen[i] += 1;
            });
            prop_assert!(seen.iter().all(|&n| n == 2), "{}: {:?}", isa, seen);
            for (i, r) in rays.iter().enumerate() {
                let want = if r.is_valid() { brute_triangles(&pos, &idx, r) } else { None };
                prop_assert_eq!(got[i], Some(want.is_some()), "{} ray {}: {:?}", isa, i, r);
                prop_assert_eq!(closest[i], want, "{} ray {}: {:?}", isa, i, r);
            }
        }
    }

    #[test]
    fn spheres_match_brute_force(
        s in prop::collection::vec((vec3(10.0), 0.05f32..2.0).prop_map(|(c, r)| Sphere::new(c, r)), 1..100),
        rays in prop::collection::vec(ray(), 64),
        p in quality(),
    ) {
        let bvh = build_spheres(&s, &p).unwrap();
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            for r in &rays {
                let want = brute_spheres(&s, r);
                prop_assert_eq!(view.closest_t(r).map(|b| (b.t, b.prim)), want, "{}", isa);
                prop_assert_eq!(view.occluded(r), want.is_some(), "{}", isa);
            }
        }
    }

    #[test]
    fn capsules_match_brute_force(
        c in prop::collection::vec((vec3(10.0), vec3(2.0), 0.05f32..1.0).prop_map(|(a, d, r)| Capsule::new(a, a + d, r)), 1..100),
        rays in prop::collection::vec(ray(), 64),
        p in quality(),
    ) {
        let bvh = build_capsules(&c, &p).unwrap();
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            for r in &rays {
                let want = brute_capsules(&c, r);
                prop_assert_eq!(view.closest_t(r).map(|b| (b.t, b.prim)), want, "{}", isa);
                prop_assert_eq!(view.occluded(r), want.is_some(), "{}", isa);
            }
        }
    }

    #[test]
    fn bytes_round_trip_answers_identically((pos, idx) in soup(), rays in prop::collection::vec(ray(), 32)) {
        let bvh = build_triangles(&pos, &idx, &params()).unwrap();
        let bytes = bvh.to_bytes();
        let copied = Bvh::<TriPacket>::from_bytes(&bytes).unwrap();
        prop_assert_eq!(&copied, &bvh);
        // Zero-copy view over an aligned copy of the bytes.
        let aligned = bvh.to_aligned_bytes();
        prop_assert_eq!(&*aligned, &bytes[..]);
        let view = rt_accel::BvhRef::<TriPacket>::from_bytes(&aligned).unwrap();
        for r in &rays {
            prop_assert_eq!(copied.closest_hit(r), bvh.closest_hit(r));
            prop_assert_eq!(view.closest_hit(r), bvh.closest_hit(r));
            prop_assert_eq!(view.occluded(r), bvh.occluded(r));
        }
    }

    #[test]
    fn refit_answers_like_a_fresh_build(
        (pos, idx) in soup(),
        shift in prop::collection::vec(vec3(3.0), 1..8),
        rays in prop::collection::vec(ray(), 48),
    ) {
        let mut bvh = build_triangles(&pos, &idx, &params()).unwrap();
        // Move every vertex (a deformation, not a rigid motion).
        let moved: Vec<Vec3> = pos.iter().enumerate().map(|(i, p)| *p + shift[i % shift.len()] * (1.0 + (i % 5) as f32 * 0.1)).collect();
        bvh.refit_triangles(&moved, &idx).unwrap();
        for r in &rays {
            // Triangles that became degenerate stay in a refit tree but are
            // never hit by brute force either (det = 0), so answers agree.
            prop_assert_eq!(bvh_t(&bvh, r), brute_triangles(&moved, &idx, r));
            prop_assert_eq!(bvh.occluded(r), brute_triangles(&moved, &idx, r).is_some());
        }
        // And the refit tree is still well formed.
        prop_assert!(Bvh::<TriPacket>::from_bytes(&bvh.to_bytes()).is_ok());
    }
}

#[test]
fn a_flat_triangle_behind_the_origin_is_hit_with_negative_t_min() {
    // A triangle in the plane z = 0 and rays leaving it toward +z with
    // `t_min < 0`: the hit is at t = −1, where the flat box's entry and
    // exit distances are equal and negative. Only the far distance widened
    // toward zero admits the box (the kernels for `t_min ≥ 0` skip that
    // comparison, which must never be used for these rays).
    let pos = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
    let bvh = build_triangles(&pos, &[[0, 1, 2]], &params()).unwrap();
    let rays: Vec<Ray> = (0..8)
        .map(|i| Ray::with_range(Vec3::new(0.05 * i as f32, 0.1, 1.0), Vec3::Z, -2.0, 5.0))
        .collect();
    for isa in Isa::available() {
        let view = bvh.as_ref().with_isa(isa).unwrap();
        for r in &rays {
            let h = view.closest_hit(r).unwrap_or_else(|| panic!("{isa:?}: {r:?} missed"));
            assert_eq!(h.t, -1.0);
            assert!(view.occluded(r), "{isa:?}");
        }
        let packet = view.closest_t_packet(&rays.clone().try_into().unwrap());
        assert!(packet.iter().all(|b| b.is_some_and(|b| b.t == -1.0)), "{isa:?}");
        let mut n = 0;
        view.occluded_stream(&rays, |_, o| n += usize::from(o));
        assert_eq!(n, rays.len(), "{isa:?}");
        // One stream group mixing rays with `t_min = 0` (the triangle is
        // behind them: no hit) and a few with `t_min < 0`: the group must
        // take the full test for all (it takes the short one only when
        // every ray has `t_min ≥ 0`).
        let mixed: Vec<Ray> = (0..40)
            .map(|i| {
                let t_min = if i % 7 == 6 { -2.0 } else { 0.0 };
                Ray::with_range(Vec3::new(0.01 * i as f32, 0.1, 1.0), Vec3::Z, t_min, 5.0)
            })
            .collect();
        let mut got = vec![None; mixed.len()];
        view.occluded_stream(&mixed, |i, o| got[i] = Some(o));
        for (r, g) in mixed.iter().zip(&got) {
            assert_eq!(*g, Some(r.t_min < 0.0), "{isa:?}: {r:?}");
        }
    }
    // With `t_min = 0` the triangle is behind the ray: no hit.
    let r = Ray::with_range(Vec3::new(0.0, 0.1, 1.0), Vec3::Z, 0.0, 5.0);
    assert!(bvh.closest_hit(&r).is_none() && !bvh.occluded(&r));
}

#[test]
fn empty_inputs_build_empty_bvhs_that_miss() {
    let r = Ray::new(Vec3::ZERO, Vec3::X);
    let t = build_triangles(&[], &[], &params()).unwrap();
    assert!(t.closest_hit(&r).is_none() && !t.occluded(&r));
    let s = build_spheres(&[], &params()).unwrap();
    assert!(s.closest_hit(&r).is_none());
    let bytes = t.to_bytes();
    assert_eq!(Bvh::<TriPacket>::from_bytes(&bytes).unwrap(), t);
}

#[test]
fn bad_input_is_an_error_naming_it() {
    use rt_accel::BuildError;
    let pos = [Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y];
    assert_eq!(
        build_triangles(&pos, &[[0, 1, 3], [0, 2, 3]], &params()),
        Err(BuildError::NonFiniteVertex { vertex: 2 })
    );
    assert_eq!(
        build_triangles(&pos, &[[0, 1, 3], [0, 1, 9]], &params()),
        Err(BuildError::IndexOutOfRange { triangle: 1, index: 9 })
    );
    let s = [Sphere::new(Vec3::ZERO, 1.0), Sphere::new(Vec3::ZERO, -1.0)];
    assert_eq!(build_spheres(&s, &params()), Err(BuildError::InvalidPrimitive { index: 1 }));
    let c = [Capsule::new(Vec3::ZERO, Vec3::splat(f32::INFINITY), 1.0)];
    assert_eq!(build_capsules(&c, &params()), Err(BuildError::InvalidPrimitive { index: 0 }));
    let mut bvh = build_triangles(&pos, &[[0, 1, 3]], &params()).unwrap();
    let before = bvh.clone();
    assert_eq!(
        bvh.refit_triangles(&pos, &[[0, 2, 3]]),
        Err(BuildError::NonFiniteVertex { vertex: 2 })
    );
    assert_eq!(bvh, before, "a failed refit changes nothing");
}

/// Spheres and capsules moved (and resized) by a refit answer like brute
/// force over the moved shapes; bad refit data change nothing.
#[test]
fn sphere_and_capsule_refit_match_brute_force() {
    let spheres: Vec<Sphere> = (0..60)
        .map(|i| Sphere::new(Vec3::new((i % 7) as f32, (i / 7) as f32, (i % 3) as f32), 0.3))
        .collect();
    let capsules: Vec<Capsule> =
        spheres.iter().map(|s| Capsule::new(s.center, s.center + Vec3::Z, 0.2)).collect();
    let mut sb = build_spheres(&spheres, &params()).unwrap();
    let mut cb = build_capsules(&capsules, &params()).unwrap();
    let moved_s: Vec<Sphere> = spheres
        .iter()
        .enumerate()
        .map(|(i, s)| {
            Sphere::new(s.center * 1.7 + Vec3::new(0.0, (i % 4) as f32, 2.0), 0.2 + 0.01 * i as f32)
        })
        .collect();
    let moved_c: Vec<Capsule> = moved_s
        .iter()
        .map(|s| Capsule::new(s.center, s.center - 2.0 * Vec3::X, s.radius))
        .collect();
    sb.refit_spheres(&moved_s).unwrap();
    cb.refit_capsules(&moved_c).unwrap();
    let mut hits = 0;
    for i in 0..400 {
        let a = i as f32 * 0.37;
        let r = Ray::new(
            Vec3::new(5.0 + 9.0 * a.cos(), 6.0 + 9.0 * a.sin(), 12.0),
            Vec3::new(-a.cos(), -a.sin(), -1.5),
        );
        let want = brute_spheres(&moved_s, &r);
        assert_eq!(bvh_t(&sb, &r), want);
        assert_eq!(bvh_t(&cb, &r), brute_capsules(&moved_c, &r));
        hits += usize::from(want.is_some());
    }
    assert!(hits > 40, "only {hits} hits");
    let before = sb.clone();
    assert!(sb.refit_spheres(&moved_s[..5]).is_err());
    let mut bad = moved_s.clone();
    bad[3].radius = f32::NAN;
    assert_eq!(sb.refit_spheres(&bad), Err(rt_accel::BuildError::InvalidPrimitive { index: 3 }));
    assert_eq!(sb, before);
}

/// Every kernel the CPU runs is offered, the widest by default; asking for
/// one it cannot run is an error naming it, not a crash later.
#[test]
fn kernels_are_chosen_at_run_time_and_refused_when_missing() {
    let (pos, idx) = icosphere(2);
    let bvh = build_triangles(&pos, &idx, &params()).unwrap();
    assert_eq!(bvh.as_ref().isa(), Isa::detect());
    for isa in Isa::ALL {
        match bvh.as_ref().with_isa(isa) {
            Ok(view) => assert!(isa.is_available() && view.isa() == isa),
            Err(e) => assert!(!isa.is_available() && e.0 == isa),
        }
    }
    #[cfg(target_arch = "x86_64")]
    assert!(bvh.as_ref().with_isa(Isa::Portable).is_err());
    let e = rt_accel::UnsupportedIsa(Isa::Avx512).to_string();
    assert!(e.contains("avx512 traversal kernel"), "{e}");
}

/// Camera rays of 8 × 1 tiles over a closed mesh: packets equal single
/// rays on every kernel (hits at shared edges included), and an empty BVH
/// or an all-invalid packet misses.
#[test]
fn camera_packets_answer_as_single_rays() {
    let (pos, idx) = icosphere(4);
    let bvh = build_triangles(&pos, &idx, &params()).unwrap();
    let eye = Vec3::new(0.3, 0.4, 3.0);
    let rays: Vec<Ray> = (0..64 * 64)
        .map(|i| {
            let (x, y) = ((i % 64) as f32 / 63.0 - 0.5, (i / 64) as f32 / 63.0 - 0.5);
            Ray::new(eye, Vec3::new(x, y, -1.6))
        })
        .collect();
    let mut hits = 0;
    for isa in Isa::available() {
        let view = bvh.as_ref().with_isa(isa).unwrap();
        for chunk in rays.chunks(8) {
            let packet: &[Ray; 8] = chunk.try_into().unwrap();
            let (c, o) = (view.closest_t_packet(packet), view.occluded_packet(packet));
            for (i, r) in packet.iter().enumerate() {
                let th = |b: Option<rt_accel::BestHit>| b.map(|b| (b.t.to_bits(), b.prim));
                assert_eq!(th(c[i]), th(view.closest_t(r)), "{isa}");
                assert_eq!(o[i], view.occluded(r), "{isa}");
                hits += usize::from(o[i]);
            }
        }
    }
    assert!(hits > 1000, "the sphere must fill part of the view: {hits}");
    // Streams over the same rays, on every kernel; an empty BVH's stream
    // misses every ray once.
    for isa in Isa::available() {
        let view = bvh.as_ref().with_isa(isa).unwrap();
        let th = |b: Option<rt_accel::BestHit>| b.map(|b| (b.t.to_bits(), b.prim));
        let mut n = 0;
        view.closest_t_stream(&rays, |i, h| {
            assert_eq!(th(h), th(view.closest_t(&rays[i])), "{isa}");
            n += 1;
        });
        view.occluded_stream(&rays, |i, o| {
            assert_eq!(o, view.occluded(&rays[i]), "{isa}");
            n += 1;
        });
        assert_eq!(n, 2 * rays.len());
    }
    let nan = Ray::new(Vec3::NAN, Vec3::Z);
    assert_eq!(bvh.as_ref().closest_t_packet(&[nan; 8]), [None; 8]);
    let empty = build_triangles(&[], &[], &params()).unwrap();
    assert_eq!(empty.as_ref().occluded_packet(&rays[..8].try_into().unwrap()), [false; 8]);
    let mut misses = 0;
    empty.as_ref().closest_t_stream(&rays, |_, h| misses += usize::from(h.is_none()));
    empty.as_ref().occluded_stream(&rays, |_, o| misses += usize::from(!o));
    assert_eq!(misses, 2 * rays.len());
}
