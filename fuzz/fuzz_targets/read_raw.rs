//! A raw volume's JSON header and payload from any bytes (split at the
//! first NUL): an `Err` or a grid whose samples fill its dimensions.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (header, payload) = (&data[..split], data.get(split + 1..).unwrap_or_default());
    let Ok(v) = serde_json::from_slice::<serde_json::Value>(header) else { return };
    if let Ok(g) = rt_volume::io::parse_raw_json(&v, payload) {
        rt_fuzz::check_grid(&g);
    }
});
