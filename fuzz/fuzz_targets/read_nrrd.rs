//! NRRD from any bytes (attached data only: no file is opened): an `Err`
//! or a grid whose samples fill its dimensions.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(g) = rt_volume::io::parse_nrrd(data, None) {
        rt_fuzz::check_grid(&g);
    }
});
