//! Meshes: scalars and normals interpolated at BVH hits, and every bad
//! array an `Err` naming it.

use rt_surface::{
    Mesh, MeshError,
    rt_accel::{BuildError, BuildParams, TriangleMesh},
    rt_core::{Ray, glam::Vec3},
};

/// A scalar that is linear in space, sampled at the vertices, interpolates
/// at every hit to its exact value at the hit point (barycentrics are right
/// and belong to the reported triangle).
#[test]
fn mesh_scalars_interpolate_at_hits() {
    let sphere = TriangleMesh::icosphere(2);
    let f = |p: Vec3| 2.0 * p.x - 0.5 * p.y + 3.0 * p.z + 1.0;
    let scalars = sphere.positions().iter().map(|p| f(*p)).collect();
    let mesh = Mesh::from(sphere.clone()).with_scalars(scalars).unwrap();
    let bvh = mesh.geometry().build_bvh(&BuildParams::medium()).unwrap();
    let mut hits = 0;
    for i in 0..200 {
        let a = i as f32 * 0.618;
        let o = Vec3::new(3.0 * a.cos(), 1.3 * (0.7 * a).sin(), 3.0 * a.sin());
        let h = bvh.closest_hit(&Ray::new(o, -o + Vec3::new(0.1, -0.2, 0.05))).expect("hit");
        let s = mesh.interpolate_scalar(&h).unwrap();
        assert!((s - f(h.position)).abs() < 1e-4, "{s} vs {}", f(h.position));
        hits += 1;
    }
    assert_eq!(hits, 200);
    let pos = sphere.positions().to_vec();
    assert_eq!(
        Mesh::new(pos, vec![[0, 1, 2]], Some(vec![0.0])),
        Err(MeshError::ScalarCountMismatch { vertices: 162, scalars: 1 })
    );
}

/// The unit sphere's vertex normals are its positions: the interpolated
/// shading normal at a hit is within the chord's sag of the true normal,
/// and without normals the geometric one is returned.
#[test]
fn shading_normals_interpolate_and_default_to_geometric() {
    let sphere = TriangleMesh::icosphere(3);
    let normals = sphere.positions().to_vec();
    let smooth = Mesh::from(sphere.clone()).with_normals(normals).unwrap();
    let flat = Mesh::from(sphere.clone());
    let bvh = sphere.build_bvh(&BuildParams::medium()).unwrap();
    for i in 0..100 {
        let a = i as f32 * 0.37;
        let o = 3.0 * Vec3::new(a.cos(), (1.3 * a).sin(), a.sin());
        let h = bvh.closest_hit(&Ray::new(o, -o)).expect("hit");
        let n = smooth.shading_normal(&h);
        assert!((n.length() - 1.0).abs() < 1e-5);
        assert!(n.dot(h.position.normalize()) > 0.999, "{n} at {}", h.position);
        assert_eq!(flat.shading_normal(&h), h.normal);
    }
}

/// Bad geometry, scalars and normals are errors naming what is wrong.
#[test]
fn bad_arrays_are_named() {
    let tri = || vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    let mut nan = tri();
    nan[1].y = f32::NAN;
    assert_eq!(
        Mesh::new(nan, vec![[0, 1, 2]], None),
        Err(MeshError::Geometry(BuildError::NonFiniteVertex { vertex: 1 }))
    );
    assert_eq!(
        Mesh::new(tri(), vec![[0, 1, 3]], None),
        Err(MeshError::Geometry(BuildError::IndexOutOfRange { triangle: 0, index: 3 }))
    );
    let mesh = Mesh::new(tri(), vec![[0, 1, 2]], None).unwrap();
    assert_eq!(
        mesh.clone().with_normals(vec![Vec3::Z]),
        Err(MeshError::NormalCountMismatch { vertices: 3, normals: 1 })
    );
    assert_eq!(
        mesh.clone().with_normals(vec![Vec3::Z, Vec3::ZERO, Vec3::Z]),
        Err(MeshError::BadNormal { vertex: 1 })
    );
    assert_eq!(
        mesh.with_normals(vec![Vec3::Z, Vec3::Z, Vec3::INFINITY]),
        Err(MeshError::BadNormal { vertex: 2 })
    );
    let e = MeshError::Geometry(BuildError::NonFiniteVertex { vertex: 1 });
    let source = core::error::Error::source(&e).expect("wraps the build error");
    assert_eq!(source.to_string(), "vertex 1 is not finite");
}
