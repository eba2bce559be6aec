//! VTK unstructured grids (legacy or XML, by the first byte) from any
//! bytes, through the path-based reader on a scratch file: an `Err`, or
//! data whose cells index its points and whose values match them — and
//! building a mesh from those data is an `Err` or a field that traces.
#![no_main]

use libfuzzer_sys::fuzz_target;
use rt_volume::{UnstructuredField, glam::DVec3};

fuzz_target!(|data: &[u8]| {
    let ext = if data.first() == Some(&b'<') { "vtu" } else { "vtk" };
    let path = std::env::temp_dir().join(format!("rt-fuzz-mesh-{}.{ext}", std::process::id()));
    if std::fs::write(&path, data).is_err() {
        return;
    }
    let Ok(d) = rt_volume::io::read_unstructured(&path, None) else { return };
    assert_eq!(d.values.len(), d.points.len());
    for c in &d.cells {
        assert!(c.points().iter().all(|&i| (i as usize) < d.points.len()), "{c:?}");
    }
    assert!(d.points.iter().all(|p| p.is_finite()) && d.values.iter().all(|v| v.is_finite()));
    let index = d.values.iter().map(|v| 1.0 + 1e-4 * v.clamp(-1e3, 1e3)).collect();
    let Ok(field) = UnstructuredField::new(d.points, &d.cells, index, 1.0) else { return };
    let b = field.bounds();
    let o = 0.5 * (b.min + b.max) - DVec3::Z * (b.max.z - b.min.z + 1.0);
    let r = field.trace(o, DVec3::Z);
    assert!(r.map_or(true, |r| r.position.is_finite() && r.optical_path.is_finite()));
});
