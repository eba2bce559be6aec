//! Two-level hierarchies against the same geometry flattened into one BVH.

extern crate alloc;

use alloc::sync::Arc;

use rt_accel::{BuildParams, InstanceError, Instances, Scene, TriangleMesh, build_triangles};
use rt_core::{
    Ray, SceneQuery,
    glam::{Mat4, Quat, Vec3},
    sampling, spawn_ray,
};

fn mesh() -> TriangleMesh {
    TriangleMesh::icosphere(3)
}

fn transforms() -> Vec<Mat4> {
    (0..12)
        .map(|i| {
            let f = i as f32;
            Mat4::from_scale_rotation_translation(
                Vec3::new(0.5 + 0.1 * f, 0.7, 0.4 + 0.05 * f),
                Quat::from_axis_angle(Vec3::new(1.0, f, 0.5).normalize(), 0.4 * f),
                Vec3::new((f * 1.7).sin() * 4.0, (f * 0.9).cos() * 3.0, f * 0.6 - 3.0),
            )
        })
        .collect()
}

fn scene_of(positions: &[Vec3], indices: &[[u32; 3]]) -> Scene {
    Scene {
        triangles: build_triangles(positions, indices, &BuildParams::medium()).unwrap(),
        ..Scene::default()
    }
}

fn rays(n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = sampling::rng_from_seed(seed);
    (0..n)
        .map(|_| {
            let u = |r: &mut _| sampling::uniform(r) * 2.0 - 1.0;
            let o = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)) * 8.0;
            let target = Vec3::new(u(&mut rng), u(&mut rng), u(&mut rng)) * 4.0;
            Ray::new(o, target - o)
        })
        .collect()
}

/// Twelve scaled, rotated, translated copies of a sphere mesh, as
/// instances and flattened into one BVH: every ray hits the same
/// primitive of the same copy at the same distance (to transform
/// rounding), and occlusion agrees.
#[test]
fn instances_answer_as_the_flattened_scene() {
    let m = mesh();
    let object = Arc::new(scene_of(m.positions(), m.indices()));
    let ts = transforms();
    let placements: Vec<(u32, Mat4)> = ts.iter().map(|t| (0, *t)).collect();
    let inst = Instances::new(vec![Arc::clone(&object)], &placements).unwrap();
    // Flattened: copy k's triangles are prims k·n .. (k + 1)·n.
    let n = m.indices().len() as u32;
    let nv = m.positions().len() as u32;
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    for (k, t) in ts.iter().enumerate() {
        pos.extend(m.positions().iter().map(|&p| t.transform_point3(p)));
        idx.extend(m.indices().iter().map(|tri| tri.map(|i| i + k as u32 * nv)));
    }
    let flat = scene_of(&pos, &idx);
    let mut hits = 0;
    for r in rays(4000, 7) {
        let a = inst.closest_hit_instance(&r);
        let b = flat.closest_hit(&r);
        match (a, b) {
            (None, None) => {}
            (Some((i, ha)), Some(hb)) => {
                hits += 1;
                assert_eq!(i * n + ha.prim, hb.prim, "{r:?}");
                assert!((ha.t - hb.t).abs() <= 1e-4 * hb.t, "{} vs {}", ha.t, hb.t);
                assert!((ha.position - hb.position).length() < 1e-3);
                assert!(ha.normal.dot(hb.normal) > 0.999);
            }
            // Grazing rays may go either way under the transform's
            // rounding; they must be rare.
            (a, b) => {
                assert!(a.is_none() || b.is_none());
            }
        }
        assert_eq!(inst.occluded(&r), flat.occluded(&r), "{r:?}");
    }
    assert!(hits > 1000, "{hits} hits: the test needs coverage");
}

/// A ray spawned from an instance hit with its error bound leaves the
/// surface: on a copy scaled by 1000 and moved far from the origin, rays
/// leaving outward never hit the sphere they start on.
#[test]
fn spawned_rays_do_not_self_intersect_far_from_the_origin() {
    let m = mesh();
    let object = scene_of(m.positions(), m.indices());
    let t = Mat4::from_scale_rotation_translation(
        Vec3::splat(1000.0),
        Quat::from_rotation_y(0.3),
        Vec3::new(1.0e5, -3.0e4, 2.0e4),
    );
    let inst = Instances::new(vec![&object], &[(0, t)]).unwrap();
    let centre = t.transform_point3(Vec3::ZERO);
    let mut rng = sampling::rng_from_seed(3);
    let mut tested = 0;
    for _ in 0..2000 {
        let d = Vec3::new(
            sampling::uniform(&mut rng) - 0.5,
            sampling::uniform(&mut rng) - 0.5,
            sampling::uniform(&mut rng) - 0.5,
        );
        let o = centre + d.normalize() * 5000.0;
        let Some(h) = inst.closest_hit(&Ray::new(o, centre - o)) else { continue };
        let n = if h.normal.dot(o - h.position) > 0.0 { h.normal } else { -h.normal };
        // Outward, within 60° of the normal.
        let w = (n + 0.5 * d.normalize().cross(n)).normalize();
        assert!(!inst.occluded(&spawn_ray(h.position, h.position_error, n, w)));
        tested += 1;
    }
    assert!(tested > 1500);
}

/// Two identical instances in the same place: the lower index wins.
#[test]
fn ties_go_to_the_lower_instance() {
    let m = mesh();
    let object = scene_of(m.positions(), m.indices());
    let t = Mat4::from_translation(Vec3::new(0.0, 0.0, -5.0));
    let inst = Instances::new(vec![&object, &object], &[(1, t), (0, t), (1, t)]).unwrap();
    let (i, _) = inst.closest_hit_instance(&Ray::new(Vec3::ZERO, Vec3::NEG_Z)).unwrap();
    assert_eq!(i, 0);
}

/// Bad placements are errors naming the instance; no instances, or an
/// invalid ray, miss.
#[test]
fn bad_placements_are_errors() {
    let m = mesh();
    let object = scene_of(m.positions(), m.indices());
    let ok = Mat4::IDENTITY;
    let e = |p: &[(u32, Mat4)]| Instances::new(vec![&object], p).err();
    assert_eq!(e(&[(0, ok), (1, ok)]), Some(InstanceError::NoSuchObject { instance: 1 }));
    assert_eq!(e(&[(0, Mat4::ZERO)]), Some(InstanceError::BadTransform { instance: 0 }));
    let nan = Mat4::from_translation(Vec3::new(f32::NAN, 0.0, 0.0));
    assert_eq!(e(&[(0, ok), (0, nan)]), Some(InstanceError::BadTransform { instance: 1 }));
    let flat = Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0));
    assert_eq!(e(&[(0, flat)]), Some(InstanceError::BadTransform { instance: 0 }));
    let none = Instances::new(vec![&object], &[]).unwrap();
    assert!(none.is_empty() && none.bounds().is_empty());
    assert_eq!(none.closest_hit(&Ray::new(Vec3::Z, Vec3::NEG_Z)), None);
    let one = Instances::new(vec![&object], &[(0, ok)]).unwrap();
    assert_eq!(one.closest_hit(&Ray::new(Vec3::NAN, Vec3::NEG_Z)), None);
    assert!(!one.occluded(&Ray::new(Vec3::Z * 3.0, Vec3::ZERO)));
    assert!(one.occluded(&Ray::new(Vec3::Z * 3.0, Vec3::NEG_Z)));
}
