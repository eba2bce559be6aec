//! Rays aimed exactly at shared vertices and edges of closed meshes never
//! slip between triangles.

mod support;

use rt_accel::build_triangles;
use rt_core::{Ray, glam::Vec3};
use support::*;

/// Rays that truly cross the surface exactly at a vertex or an edge point
/// of a closed convex mesh must hit it. Targets: every vertex and several
/// points on every edge. Rays: from outside, aimed at the target from
/// directions that enter the mesh (toward its centre, jittered), and from
/// inside points through the target.
fn assert_closed(pos: &[Vec3], idx: &[[u32; 3]], center: Vec3) {
    let built = build_triangles(pos, idx, &params()).unwrap();
    for isa in rt_accel::Isa::available() {
        let bvh = built.as_ref().with_isa(isa).unwrap();
        assert_closed_on(&bvh, pos, idx, center);
    }
}

fn assert_closed_on(
    bvh: &rt_accel::BvhRef<'_, rt_accel::TriPacket>,
    pos: &[Vec3],
    idx: &[[u32; 3]],
    center: Vec3,
) {
    let mut targets: Vec<Vec3> = pos.to_vec();
    for t in idx {
        for k in 0..3 {
            let (a, b) = (pos[t[k] as usize], pos[t[(k + 1) % 3] as usize]);
            for s in [0.5f32, 0.25, 1.0 / 3.0, 0.125] {
                targets.push(a + (b - a) * s);
            }
        }
    }
    let jitters = [Vec3::ZERO, Vec3::new(0.13, -0.07, 0.05), Vec3::new(-0.02, 0.11, -0.09)];
    let insides = [center, center + Vec3::new(0.031, -0.017, 0.023)];
    let mut rays = 0;
    for &p in &targets {
        for (i, j) in jitters.iter().enumerate() {
            let eye = p + (p - center) * (1.5 + i as f32) + *j;
            let r = Ray::new(eye, p - eye);
            assert!(bvh.closest_hit(&r).is_some(), "outside ray {eye} → {p} slipped through");
            assert!(bvh.occluded(&r));
            rays += 1;
        }
        for &o in &insides {
            let r = Ray::new(o, p - o);
            assert!(bvh.closest_hit(&r).is_some(), "inside ray {o} → {p} slipped through");
            rays += 1;
        }
    }
    assert!(rays > 100);
}

#[test]
fn icosphere_vertices_and_edges_are_watertight() {
    let (pos, idx) = icosphere(3);
    assert_closed(&pos, &idx, Vec3::ZERO);
}

#[test]
fn cube_vertices_and_edges_are_watertight() {
    let (pos, idx) = cube();
    assert_closed(&pos, &idx, Vec3::splat(0.5));
    // Translated far from the origin, where rounding is coarse.
    let far: Vec<Vec3> = pos.iter().map(|p| *p * 3.0 + Vec3::new(1.0e4, -2.0e4, 3.0e3)).collect();
    assert_closed(&far, &idx, Vec3::splat(1.5) + Vec3::new(1.0e4, -2.0e4, 3.0e3));
}

#[test]
fn axis_aligned_rays_through_cube_edges_with_signed_zero() {
    let (pos, idx) = cube();
    let bvh = build_triangles(&pos, &idx, &params()).unwrap();
    // Along -x through the face diagonal's midpoint and an edge, with ±0.0 components.
    for d in [Vec3::new(-1.0, 0.0, 0.0), Vec3::new(-1.0, -0.0, -0.0), Vec3::new(-1.0, 0.0, -0.0)] {
        for o in [Vec3::new(3.0, 0.5, 0.5), Vec3::new(3.0, 0.25, 0.75), Vec3::new(3.0, 0.5, 1.0)] {
            let h = bvh.closest_hit(&Ray::new(o, d)).expect("hit");
            assert_eq!(h.t, 2.0);
        }
    }
}
