//! VTK image data (legacy or XML, by the first byte) from any bytes,
//! through the path-based reader on a scratch file: an `Err` or a grid
//! whose samples fill its dimensions.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let ext = if data.first() == Some(&b'<') { "vti" } else { "vtk" };
    let path = std::env::temp_dir().join(format!("rt-fuzz-{}.{ext}", std::process::id()));
    if std::fs::write(&path, data).is_err() {
        return;
    }
    if let Ok(g) = rt_volume::io::read_vtk(&path) {
        rt_fuzz::check_grid(&g);
    }
});
