//! BVH build and traversal against brute force: up to 48 triangles from
//! any floats (NaN vertices are a build error), 8 rays each; the closest
//! hit, its triangle and the occlusion answer equal the brute-force ones
//! exactly (ties to the lower index), for every build quality.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_accel::{BuildParams, build_triangles};
use rt_core::{
    Ray,
    intersect::{WatertightRay, intersect_triangle_t, is_degenerate_triangle},
};
use rt_fuzz::{ray, triangle};

fn brute(pos: &[rt_core::glam::Vec3], idx: &[[u32; 3]], r: &Ray) -> Option<(f32, u32)> {
    if !r.is_valid() {
        return None;
    }
    let pre = WatertightRay::new(r);
    let mut best: Option<(f32, u32)> = None;
    for (i, t) in idx.iter().enumerate() {
        let [a, b, c] = t.map(|k| pos[k as usize]);
        if is_degenerate_triangle(a, b, c) {
            continue;
        }
        if let Some(h) = intersect_triangle_t(r, &pre, a, b, c)
            && best.is_none_or(|(bt, _)| h.t < bt)
        {
            best = Some((h.t, i as u32));
        }
    }
    best
}

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let Ok(n) = u.int_in_range(0usize..=48) else { return };
    let mut pos = Vec::new();
    let mut idx = Vec::new();
    for i in 0..n {
        let Ok(t) = triangle(&mut u) else { return };
        // Now and then share a vertex with the previous triangle.
        let share = i > 0 && u.ratio(1u8, 4).unwrap_or(false);
        let base = pos.len() as u32;
        pos.extend(t);
        idx.push(if share { [base - 1, base + 1, base + 2] } else { [base, base + 1, base + 2] });
    }
    let quality = match u.int_in_range(0u8..=2).unwrap_or(0) {
        0 => BuildParams::fast(),
        1 => BuildParams::medium(),
        _ => BuildParams::slow(),
    };
    let bvh = match build_triangles(&pos, &idx, &quality) {
        Ok(b) => b,
        Err(_) => {
            assert!(pos.iter().any(|p| !p.is_finite()), "finite triangles refused");
            return;
        }
    };
    for _ in 0..8 {
        let Ok(r) = ray(&mut u) else { return };
        let want = brute(&pos, &idx, &r);
        assert_eq!(bvh.closest_t(&r).map(|b| (b.t, b.prim)), want, "{r:?} {pos:?} {idx:?}");
        assert_eq!(bvh.closest_hit(&r).map(|h| (h.t, h.prim)), want, "{r:?}");
        assert_eq!(bvh.occluded(&r), want.is_some(), "{r:?} {pos:?} {idx:?}");
    }
});
