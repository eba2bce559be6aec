//! rt against the watertight suite: no ray that must hit a closed mesh
//! misses it, on any kernel the CPU has, at any scale from 1e-8 to 1e8.

use rt_accel::{BuildParams, Isa, build_triangles};
use rt_benches::watertight::{Case, misses, needles, sliver_cube, suite};

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
