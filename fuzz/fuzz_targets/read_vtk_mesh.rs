//! VTK polydata, legacy and XML, from any bytes: an `Err` or a mesh with
//! indices in range and one value per vertex in every array.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let parsed = if data.first() == Some(&b'<') {
        rt_surface::io::parse_vtk_xml(data)
    } else {
        rt_surface::io::parse_vtk_legacy(data)
    };
    if let Ok(m) = parsed {
        rt_fuzz::check_mesh(m);
    }
});
