//! Raw samples described by a JSON header (the project's sidecar format).

use alloc::{format, vec::Vec};
use std::path::Path;

use glam::DVec3;

use super::{
    ReadError, ReadErrorKind,
    decode::{SampleType, decode},
    error::{malformed, parse_error, unsupported},
    read,
    sub_box::{Payload, read_box},
};
use crate::{Grid, GridInfo, GridSamples};

/// Reads raw samples described by a JSON header such as the project's
/// sidecar: `dims` `[nx, ny, nz]`, `dtype` (`float32`, `float64`, `uint8`,
/// `int16`, `uint16`), `endian` (`little` default), `spacing`, `origin`
/// (centre of sample 0), and `file` (the payload, relative to the JSON).
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn read_raw_json(json_path: &Path) -> Result<Grid, ReadError> {
    read_raw_json_samples(json_path)?.into_grid().map_err(|e| ReadError::from(e).in_file(json_path))
}

/// [`read_raw_json`]'s samples before the grid's checks (NaN kept).
///
/// # Errors
/// [`ReadError`] naming the problem.
pub(super) fn read_raw_json_samples(json_path: &Path) -> Result<GridSamples, ReadError> {
    let text = read(json_path)?;
    let header = || -> Result<(serde_json::Value, Vec<u8>), ReadError> {
        let v: serde_json::Value =
            serde_json::from_slice(&text).map_err(|e| parse_error("JSON", e))?;
        let file = v["file"].as_str().ok_or_else(|| malformed("no `file`"))?;
        // Too many samples is an error before the payload is read.
        let [x, y, z] = header(&v)?.dims;
        x.checked_mul(y)
            .and_then(|n| n.checked_mul(z))
            .filter(|&n| n <= Grid::MAX_SAMPLES)
            .ok_or(ReadError::from(ReadErrorKind::TooLarge))?;
        let dir = json_path.parent().unwrap_or(Path::new("."));
        let payload = read(&dir.join(file))?;
        Ok((v, payload))
    };
    header()
        .and_then(|(v, payload)| parse_raw_json_samples(&v, &payload))
        .map_err(|e| e.in_file(json_path))
}

/// What a raw + JSON header says.
struct Header {
    dims: [usize; 3],
    ty: SampleType,
    little: bool,
    spacing: DVec3,
    origin: DVec3,
}

fn header(v: &serde_json::Value) -> Result<Header, ReadError> {
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
    Ok(Header {
        dims,
        ty,
        little,
        spacing: DVec3::from(triple("spacing")?),
        origin: DVec3::from(triple("origin")?),
    })
}

/// [`read_raw_json`] from a parsed header and the payload bytes.
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn parse_raw_json(v: &serde_json::Value, payload: &[u8]) -> Result<Grid, ReadError> {
    Ok(parse_raw_json_samples(v, payload)?.into_grid()?)
}

/// [`parse_raw_json`]'s samples before the grid's checks (NaN kept).
fn parse_raw_json_samples(v: &serde_json::Value, payload: &[u8]) -> Result<GridSamples, ReadError> {
    let h = header(v)?;
    let dims = h.dims;
    let count = dims[0]
        .checked_mul(dims[1])
        .and_then(|x| x.checked_mul(dims[2]))
        .filter(|&x| x <= Grid::MAX_SAMPLES)
        .ok_or(ReadError::from(ReadErrorKind::TooLarge))?;
    let data = decode(payload, h.ty, h.little, count)?;
    Ok(GridSamples { dims, origin: h.origin, spacing: h.spacing, data })
}

/// The samples `lo ≤ (i, j, k) < hi` of a raw + JSON volume, read without
/// reading the rest of its payload: one seek and one read per row of the
/// box (a brick of a volume larger than memory, with its ghost layers).
/// The grid keeps the volume's spacing; its origin is sample `lo`'s centre.
/// The payload must hold exactly the header's samples (checked by its
/// length, not by reading it); the whole volume may exceed
/// [`Grid::MAX_SAMPLES`], the box may not.
///
/// # Errors
/// [`ReadError`] naming the problem: an empty box or one past the
/// volume's `dims` is [`ReadErrorKind::Malformed`]; a payload of the wrong
/// length [`ReadErrorKind::Truncated`].
pub fn read_raw_json_box(
    json_path: &Path,
    lo: [usize; 3],
    hi: [usize; 3],
) -> Result<Grid, ReadError> {
    let text = read(json_path)?;
    let load = || -> Result<Grid, ReadError> {
        let v: serde_json::Value =
            serde_json::from_slice(&text).map_err(|e| parse_error("JSON", e))?;
        let h = header(&v)?;
        let file = v["file"].as_str().ok_or_else(|| malformed("no `file`"))?;
        let path = json_path.parent().unwrap_or(Path::new(".")).join(file);
        let payload = Payload {
            path: &path,
            offset: 0,
            dims: h.dims,
            ty: h.ty,
            little: h.little,
            origin: h.origin,
            spacing: h.spacing,
        };
        read_box(&payload, lo, hi)
    };
    load().map_err(|e| e.in_file(json_path))
}

/// The header of a raw + JSON volume (dims, origin, spacing), without
/// reading its payload.
///
/// # Errors
/// [`ReadError`] naming the problem; a header [`GridInfo::new`] refuses
/// is [`ReadErrorKind::Grid`].
pub fn read_raw_json_info(json_path: &Path) -> Result<GridInfo, ReadError> {
    let text = read(json_path)?;
    let load = || -> Result<GridInfo, ReadError> {
        let v: serde_json::Value =
            serde_json::from_slice(&text).map_err(|e| parse_error("JSON", e))?;
        let h = header(&v)?;
        Ok(GridInfo::new(h.dims, h.origin, h.spacing)?)
    };
    load().map_err(|e| e.in_file(json_path))
}
