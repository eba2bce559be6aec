//! Octree build over grids from any numbers, and marching through it with
//! the skipping tracer: `Err` for bad input, otherwise finite results
//! leaving through the bounds; in a uniform grid the skipping tracer goes
//! straight (the exact answer).
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_fuzz::{check_trace, f64_any, grid, trace_params};
use rt_volume::{Exit, GridField, IndexField, Interp, build_octree, glam::DVec3, trace_skipping};

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let Ok(Some(g)) = grid(&mut u) else { return };
    let uniform = g.data().iter().all(|&v| v == g.data()[0]);
    let Ok(field) = GridField::new(g, Interp::Trilinear, 1.0) else { return };
    let Ok(tree) = build_octree(&field) else { return };
    let v = |u: &mut arbitrary::Unstructured<'_>| -> arbitrary::Result<DVec3> {
        Ok(DVec3::new(f64_any(u)?, f64_any(u)?, f64_any(u)?))
    };
    let (Ok(o), Ok(d), Ok(params), Ok(tol)) =
        (v(&mut u), v(&mut u), trace_params(&mut u), f64_any(&mut u))
    else {
        return;
    };
    let Ok(r) = trace_skipping(&field, &tree, o, d, &params, tol) else { return };
    check_trace(&r, &field.bounds(), o, "skipping");
    if uniform && r.exit == Exit::Left && d.is_finite() && d.length() > 0.0 {
        // Straight through: the exit direction is the launch direction.
        let unit = |v: DVec3| (v / v.abs().max_element()).normalize();
        let (a, b) = (unit(d), unit(r.direction));
        assert!((a - b).length() <= 1e-9, "bent in a uniform grid: {d:?} → {:?}", r.direction);
    }
});
