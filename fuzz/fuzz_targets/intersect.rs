//! Ray against triangle, sphere, capsule and box: hits are finite and in
//! range, degenerate triangles, invalid primitives and invalid rays never
//! hit, box intervals are ordered numbers.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_core::{
    Aabb,
    intersect::{
        Capsule, Sphere, intersect_capsule, intersect_sphere, intersect_triangle,
        is_degenerate_triangle,
    },
};
use rt_fuzz::{check_t, f32_any, ray, triangle};

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let (Ok(r), Ok([a, b, c]), Ok(radius)) = (ray(&mut u), triangle(&mut u), f32_any(&mut u))
    else {
        return;
    };
    if let Some(h) = intersect_triangle(&r, a, b, c) {
        check_t(&r, h.t, "triangle");
        assert!(r.is_valid(), "an invalid ray hit: {r:?}");
        assert!(!is_degenerate_triangle(a, b, c), "a degenerate triangle was hit");
    }
    let sphere = Sphere { center: a, radius };
    if let Some(h) = intersect_sphere(&r, &sphere, 0) {
        check_t(&r, h.t, "sphere");
        assert!(sphere.is_valid() && r.is_valid(), "{sphere:?} {r:?}");
    }
    let capsule = Capsule { p0: a, radius, p1: b, pad: 0.0 };
    if let Some(h) = intersect_capsule(&r, &capsule, 0) {
        check_t(&r, h.t, &format!("capsule {capsule:?}"));
        assert!(capsule.is_valid() && r.is_valid(), "{capsule:?} {r:?}");
    }
    let boxed = Aabb::new(a.min(b), a.max(b));
    if let Some((t0, t1)) = boxed.intersect_ray(&r) {
        assert!(t0 <= t1, "box interval {t0} {t1} for {r:?}");
    }
});
