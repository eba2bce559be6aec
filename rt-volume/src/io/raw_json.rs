//! Raw samples described by a JSON header (the project's sidecar format).

use alloc::{format, vec::Vec};
use std::path::Path;

use glam::DVec3;

use super::{
    ReadError, ReadErrorKind,
    decode::{SampleType, decode},
    error::{malformed, parse_error, unsupported},
    read,
};
use crate::Grid;

/// Reads raw samples described by a JSON header such as the project's
/// sidecar: `dims` `[nx, ny, nz]`, `dtype` (`float32`, `float64`, `uint8`,
/// `int16`, `uint16`), `endian` (`little` default), `spacing`, `origin`
/// (centre of sample 0), and `file` (the payload, relative to the JSON).
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn read_raw_json(json_path: &Path) -> Result<Grid, ReadError> {
    let text = read(json_path)?;
    let header = || -> Result<(serde_json::Value, Vec<u8>), ReadError> {
        let v: serde_json::Value =
            serde_json::from_slice(&text).map_err(|e| parse_error("JSON", e))?;
        let file = v["file"].as_str().ok_or_else(|| malformed("no `file`"))?;
        let dir = json_path.parent().unwrap_or(Path::new("."));
        let payload = read(&dir.join(file))?;
        Ok((v, payload))
    };
    header().and_then(|(v, payload)| parse_raw_json(&v, &payload)).map_err(|e| e.in_file(json_path))
}

/// [`read_raw_json`] from a parsed header and the payload bytes.
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn parse_raw_json(v: &serde_json::Value, payload: &[u8]) -> Result<Grid, ReadError> {
    let triple = |key: &str| -> Result<[f64; 3], ReadError> {
        let a = v[key].as_array().ok_or_else(|| malformed(format!("no `{key}` array")))?;
        let x: Vec<f64> = a.iter().filter_map(serde_json::Value::as_f64).collect();
        match x[..] {
            [a, b, c] if a.is_finite() && b.is_finite() && c.is_finite() => Ok([a, b, c]),
            _ => Err(malformed(format!("`{key}` needs 3 finite numbers"))),
        }
    };
    let dims = {
        let a = v["dims"].as_array().ok_or_else(|| malformed("no `dims` array"))?;
        let d: Vec<usize> =
            a.iter().filter_map(|x| x.as_u64()).filter_map(|x| usize::try_from(x).ok()).collect();
        match d[..] {
            [x, y, z] if a.len() == 3 => [x, y, z],
            _ => return Err(malformed("`dims` needs 3 non-negative integers")),
        }
    };
    let ty = match v["dtype"].as_str().unwrap_or("float32") {
        "float32" | "f32" => SampleType::F32,
        "float64" | "f64" => SampleType::F64,
        "uint8" | "u8" => SampleType::U8,
        "int16" | "i16" => SampleType::I16,
        "uint16" | "u16" => SampleType::U16,
        other => return Err(unsupported(format!("dtype `{other}`"))),
    };
    let little = v["endian"].as_str().unwrap_or("little") == "little";
    let spacing = DVec3::from(triple("spacing")?);
    let origin = DVec3::from(triple("origin")?);
    let count = dims[0]
        .checked_mul(dims[1])
        .and_then(|x| x.checked_mul(dims[2]))
        .filter(|&x| x <= Grid::MAX_SAMPLES)
        .ok_or(ReadError::from(ReadErrorKind::TooLarge))?;
    let data = decode(payload, ty, little, count)?;
    Ok(Grid::new(dims, origin, spacing, data)?)
}
