//! NRRD from any bytes (attached data only: no file is opened): an `Err`
//! or a grid whose samples fill its dimensions. The first byte picks a
//! start: the input as is, after the magic line, or after a whole valid
//! header (so that mutations reach the fields and the payload).
#![no_main]

use libfuzzer_sys::fuzz_target;

const MAGIC: &[u8] = b"NRRD0004\n";
const HEADER: &[u8] =
    b"NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nspacings: 1 1 1\nencoding: raw\nendian: little\n\n";

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else { return };
    let input = match first % 3 {
        0 => rest.to_vec(),
        1 => [MAGIC, rest].concat(),
        _ => [HEADER, rest].concat(),
    };
    if let Ok(g) = rt_volume::io::parse_nrrd(&input, None) {
        rt_fuzz::check_grid(&g);
    }
});
