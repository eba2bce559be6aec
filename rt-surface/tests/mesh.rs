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

/// On a closed icosphere (vertices on the unit sphere) the angle-weighted
/// normals approach the sphere's own normals as the triangles shrink:
/// within 1e-3 from level 6 (81,920 triangles). Angle weighting is exact
/// only where a vertex's neighbourhood is symmetric (level 1 here); on
/// the irregular rings of finer levels its error falls with the edge
/// length (0.0104 at level 2, halving per level), as measured against an
/// `f64` reference of the same weights.
#[test]
fn smooth_normals_of_an_icosphere_are_the_sphere_normals() {
    let mut errors = Vec::new();
    for level in 1..=6 {
        let sphere = TriangleMesh::icosphere(level);
        let mesh = Mesh::from(sphere.clone()).with_smooth_normals();
        let normals = mesh.normals().expect("normals");
        assert_eq!(normals.len(), sphere.positions().len());
        let mut worst = 0.0f32;
        for (n, p) in normals.iter().zip(sphere.positions()) {
            assert!((n.length() - 1.0).abs() < 1e-6, "{n}");
            worst = worst.max((*n - p.normalize()).length());
        }
        errors.push(worst);
    }
    assert!(errors[0] < 1e-6, "{errors:?}");
    assert!((errors[1] - 0.0104).abs() < 1e-4, "{errors:?}");
    for pair in errors[1..].windows(2) {
        assert!(pair[1] < 0.55 * pair[0], "first-order convergence: {errors:?}");
    }
    assert!(errors[5] < 1e-3, "{errors:?}");
}

/// A flat quad, however it is split, gets exactly its plane's normal at
/// every vertex; a tilted one gets its plane's normal to rounding.
#[test]
fn smooth_normals_of_a_flat_quad_are_the_plane_normal() {
    let quad = vec![
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(3.0, 0.0, 2.0),
        Vec3::new(3.0, 1.0, 2.0),
        Vec3::new(0.0, 1.0, 2.0),
        Vec3::new(1.0, 0.3, 2.0),
    ];
    // Two triangles, then a fan around an inner vertex.
    for indices in [vec![[0, 1, 2], [0, 2, 3]], vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]] {
        let mesh = Mesh::new(quad.clone(), indices, None).unwrap().with_smooth_normals();
        let normals = mesh.normals().unwrap();
        // The split quad leaves vertex 4 unused: it gets +Z, no hit sees it.
        assert!(normals.iter().all(|&n| n == Vec3::Z), "{normals:?}");
    }
    let tilt = |p: Vec3| Vec3::new(p.x, p.y * 0.6, p.y * 0.8);
    let mesh = Mesh::new(quad.iter().map(|&p| tilt(p)).collect(), vec![[0, 1, 2], [0, 2, 3]], None)
        .unwrap()
        .with_smooth_normals();
    let plane = Vec3::new(0.0, -0.8, 0.6);
    for n in &mesh.normals().unwrap()[..4] {
        assert!((*n - plane).length() < 1e-6, "{n}");
    }
}

/// Angle weighting: a cube's corner normal is the corner's diagonal
/// whichever way its faces are split into triangles (a plain or area
/// average would lean toward the face split in two).
#[test]
fn smooth_normals_do_not_depend_on_the_triangulation() {
    let p = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    // Three faces of the unit cube meeting at the corner (1, 1, 1).
    let positions = vec![
        p(1., 1., 1.),
        p(0., 1., 1.),
        p(0., 0., 1.),
        p(1., 0., 1.),
        p(1., 0., 0.),
        p(1., 1., 0.),
        p(0., 1., 0.),
    ];
    let indices = vec![
        // z = 1: split along the diagonal from the corner (two triangles there).
        [0, 1, 2],
        [0, 2, 3],
        // x = 1: split along the other diagonal (one triangle at the corner).
        [0, 3, 5],
        [3, 4, 5],
        // y = 1: split through the corner too.
        [0, 5, 6],
        [0, 6, 1],
    ];
    let mesh = Mesh::new(positions, indices, None).unwrap().with_smooth_normals();
    let n = mesh.normals().unwrap()[0];
    assert!((n - Vec3::ONE.normalize()).length() < 1e-5, "{n}");
}

/// Degenerate triangles contribute nothing; a vertex on degenerate
/// triangles only keeps the mesh's former normal (or +Z); two faces back
/// to back give the first face's normal; existing normals are replaced.
#[test]
fn smooth_normals_skip_degenerate_triangles() {
    let positions = vec![
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        // A sliver of zero area (collinear), and a repeated vertex.
        Vec3::new(2.0, 0.0, 0.0),
        Vec3::new(4.0, 0.0, 0.0),
    ];
    let indices = vec![[0, 1, 2], [1, 3, 4], [0, 0, 2]];
    let mesh = Mesh::new(positions.clone(), indices.clone(), None).unwrap();
    let smooth = mesh.clone().with_smooth_normals();
    let normals = smooth.normals().unwrap();
    assert_eq!(&normals[..3], &[Vec3::Z; 3]);
    assert_eq!(&normals[3..], &[Vec3::Z; 2]);
    let tilted = Vec3::new(0.0, 1.0, 1.0);
    let with = mesh.with_normals(vec![tilted; 5]).unwrap().with_smooth_normals();
    let normals = with.normals().unwrap();
    assert_eq!(&normals[..3], &[Vec3::Z; 3], "recomputed");
    assert_eq!(&normals[3..], &[tilted; 2], "kept where nothing valid touches");
    // The same triangle both ways: the sums cancel.
    let sheet = Mesh::new(positions, vec![[0, 1, 2], [0, 2, 1]], None).unwrap();
    assert_eq!(&sheet.with_smooth_normals().normals().unwrap()[..3], &[Vec3::Z; 3]);
}
