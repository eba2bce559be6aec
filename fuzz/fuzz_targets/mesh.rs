//! Unstructured meshes from any numbers: construction is an `Err` or a
//! field, and tracing through a field is an `Err` (bad ray) or a finite
//! result that leaves on the bounds (or stops at the step cap) — never a
//! panic or a hang. The boundary is found in f32 (rt-accel's BVH, relative
//! to the mesh's centre), so a ray grazing it within f32 rounding of the
//! mesh's size may be taken in: "on the bounds" allows that much.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_fuzz::f64_any;
use rt_volume::{Cell, Exit, UnstructuredField, glam::DVec3};

fuzz_target!(|data: &[u8]| {
    let mut u = arbitrary::Unstructured::new(data);
    let _ = run(&mut u);
});

fn run(u: &mut arbitrary::Unstructured<'_>) -> arbitrary::Result<()> {
    let v = |u: &mut arbitrary::Unstructured<'_>| -> arbitrary::Result<DVec3> {
        Ok(DVec3::new(f64_any(u)?, f64_any(u)?, f64_any(u)?))
    };
    let n_points = u.int_in_range(0usize..=12)?;
    let mut points = Vec::with_capacity(n_points);
    let mut index = Vec::with_capacity(n_points);
    for _ in 0..n_points {
        points.push(v(u)?);
        index.push(if u.arbitrary()? { 1.0 + f64_any(u)? * 1e-3 } else { f64_any(u)? });
    }
    let id = |u: &mut arbitrary::Unstructured<'_>| -> arbitrary::Result<u32> {
        Ok(u32::from(u.int_in_range(0u8..=13)?))
    };
    let n_cells = u.int_in_range(0usize..=6)?;
    let mut cells = Vec::with_capacity(n_cells);
    for _ in 0..n_cells {
        cells.push(match u.int_in_range(0u8..=3)? {
            0 => Cell::Tetra([id(u)?, id(u)?, id(u)?, id(u)?]),
            1 => Cell::Pyramid([id(u)?, id(u)?, id(u)?, id(u)?, id(u)?]),
            2 => Cell::Wedge([id(u)?, id(u)?, id(u)?, id(u)?, id(u)?, id(u)?]),
            _ => Cell::Hexahedron([id(u)?, id(u)?, id(u)?, id(u)?, id(u)?, id(u)?, id(u)?, id(u)?]),
        });
    }
    let ambient = if u.arbitrary()? { 1.0 } else { f64_any(u)? };
    let Ok(field) = UnstructuredField::new(points, &cells, index, ambient) else { return Ok(()) };
    for _ in 0..4 {
        let (o, d) = (v(u)?, v(u)?);
        let Ok(r) = field.trace(o, d) else { continue };
        assert!(r.position.is_finite() && r.direction.is_finite(), "{r:?}");
        assert!(r.optical_path.is_finite(), "{r:?}");
        if r.exit == Exit::Left {
            let b = field.bounds();
            let slack = 1e-6 * (b.max - b.min).abs().max_element() + 1e-300;
            assert!(
                (b.min - slack).cmple(r.position).all() && r.position.cmple(b.max + slack).all(),
                "left outside the bounds {b:?}: {r:?}"
            );
        }
    }
    Ok(())
}
