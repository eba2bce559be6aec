//! OBJ from any bytes: an `Err` or a mesh with indices in range and one
//! value per vertex in every array.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(m) = rt_surface::io::parse_obj(data) {
        rt_fuzz::check_mesh(m);
    }
});
