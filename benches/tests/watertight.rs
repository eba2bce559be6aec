//! rt against the watertight suite: no ray that must hit a closed mesh
//! misses it, on any kernel the CPU has, at any scale from 1e-8 to 1e8;
//! and rt's all-hits query counts each crossing once, so the parity of
//! crossings tells inside from outside.

use rt_accel::{BuildParams, Isa, build_triangles};
use rt_benches::watertight::{Case, at_aims, misses, needles, sliver_cube, suite};
use rt_core::intersect::intersect_triangle;
use rt_surface::cast::RayCaster;

fn closed(m: &rt_benches::scenes::Mesh) -> bool {
    // Every edge is shared by exactly two triangles, once each way.
    let mut edges = std::collections::HashMap::new();
    for t in &m.indices {
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    edges.iter().all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
}

#[test]
fn the_suite_meshes_are_closed_and_its_rays_many() {
    assert!(closed(&sliver_cube(10)) && closed(&needles(16, 1e-3)));
    let cases = suite(200);
    assert_eq!(cases.len(), 20);
    assert!(cases.iter().all(|c: &Case| c.rays.len() > 300), "a case with few rays");
}

#[test]
fn rt_misses_no_ray_of_the_watertight_suite() {
    for case in suite(200) {
        let bvh = build_triangles(&case.mesh.positions, &case.mesh.indices, &BuildParams::medium())
            .unwrap();
        for isa in Isa::available() {
            let view = bvh.as_ref().with_isa(isa).unwrap();
            let missed = misses(&case, |r| view.closest_t(r).is_some());
            assert_eq!(missed, 0, "{}: {isa} missed {missed} of {}", case.name, case.rays.len());
            let missed = misses(&case, |r| view.occluded(r));
            assert_eq!(missed, 0, "{}: {isa} (any hit) missed {missed}", case.name);
        }
    }
}

#[test]
fn rt_reports_each_crossing_once_and_two_through_a_convex_solid() {
    for case in suite(200) {
        let caster = RayCaster::new(&case.mesh.positions, &case.mesh.indices).unwrap();
        let all = |r: &rt_core::Ray| caster.all(core::slice::from_ref(r), 64);
        let at = at_aims(&case, |r| all(r).iter().map(|(_, h)| (h.t, h.prim)).collect());
        assert!(at.rays > 300, "{}: {at:?}", case.name);
        assert_eq!((at.missed, at.doubled), (0, 0), "{}: {at:?}", case.name);
        if case.name.starts_with("height field") {
            continue;
        }
        // A line through a convex solid, from outside, crosses it twice.
        for (r, aim) in case.rays.iter().zip(&case.aims) {
            if r.origin != aim.point {
                let n = all(r).len();
                assert_eq!(n, 2, "{}: {n} crossings along {r:?}", case.name);
            }
        }
    }
}

#[test]
fn the_count_sees_an_edge_that_both_its_triangles_report() {
    // rt's triangle test alone, over every triangle: watertight, so both
    // triangles at a shared edge report the crossing, and the count must
    // see it (rt's all-hits query above merges them).
    let mut doubled = 0;
    for case in suite(20).into_iter().filter(|c| c.name.ends_with("×1e0")) {
        let m = &case.mesh;
        let at = at_aims(&case, |r| {
            let tri = |t: &[u32; 3]| t.map(|i| m.positions[i as usize]);
            (0u32..)
                .zip(&m.indices)
                .filter_map(|(i, t)| {
                    let [a, b, c] = tri(t);
                    intersect_triangle(r, a, b, c).map(|h| (h.t, i))
                })
                .collect()
        });
        assert_eq!(at.missed, 0, "{}: {at:?}", case.name);
        doubled += at.doubled;
    }
    assert!(doubled > 50, "only {doubled} rays double counted by the bare triangle test");
}
