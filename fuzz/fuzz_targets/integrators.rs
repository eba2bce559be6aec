//! Every integrator on grids (trilinear and Catmull–Rom) and analytic
//! fields built from any numbers, with any ray and parameters: an `Err`
//! for bad input, otherwise finite results that leave through the bounds.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_fuzz::{check_trace, f64_any, grid, trace_params};
use rt_volume::{Bounds, GridField, IndexField, Interp, LinearIndex, glam::DVec3, trace};

fn dvec3(u: &mut arbitrary::Unstructured<'_>) -> arbitrary::Result<DVec3> {
    Ok(DVec3::new(f64_any(u)?, f64_any(u)?, f64_any(u)?))
}

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let Ok(which) = u.int_in_range(0u8..=2) else { return };
    let (Ok(origin), Ok(direction), Ok(params)) =
        (dvec3(&mut u), dvec3(&mut u), trace_params(&mut u))
    else {
        return;
    };
    match which {
        0 | 1 => {
            let Ok(Some(g)) = grid(&mut u) else { return };
            let interp = if which == 0 { Interp::Trilinear } else { Interp::CatmullRom };
            let Ok(ambient) = f64_any(&mut u) else { return };
            let Ok(field) = GridField::new(g, interp, ambient) else { return };
            if let Ok(r) = trace(&field, origin, direction, &params) {
                check_trace(&r, &field.bounds(), origin, "grid");
            }
        }
        _ => {
            let (Ok(n0), Ok(gradient), Ok(lo), Ok(hi)) =
                (f64_any(&mut u), dvec3(&mut u), dvec3(&mut u), dvec3(&mut u))
            else {
                return;
            };
            // A box of zero volume (a point, a plane) is left out: the
            // trace answers it, but "on the bounds" within rounding of
            // coordinates far larger than the box means little.
            if !lo.cmplt(hi).all() {
                return;
            }
            let f = LinearIndex { n0, gradient, bounds: Bounds { min: lo, max: hi } };
            if let Ok(r) = trace(&f, origin, direction, &params) {
                check_trace(&r, &f.bounds(), origin, "linear index");
            }
        }
    }
});
