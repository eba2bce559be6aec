//! Readers for gridded data (feature `io`): raw samples with a JSON header
//! (the project's sidecar format), NRRD (the original tool's format) and
//! VTK image data (through `vtkio`).
//! Every malformed, truncated or oversized input is an `Err` naming the
//! problem; samples that are NaN or infinite are rejected.

use alloc::{
    format,
    string::{String, ToString},
    vec::Vec,
};
use core::fmt;
use std::{
    fs,
    path::{Path, PathBuf},
};

use glam::DVec3;

use crate::{Grid, GridError};

/// Why a file could not be read as a grid.
#[derive(Clone, Debug, PartialEq)]
pub enum ReadError {
    /// The operating system could not read a file.
    Io {
        /// The file.
        path: PathBuf,
        /// The system's message.
        message: String,
    },
    /// The header is not what the format requires.
    Malformed(String),
    /// A valid file using a feature this reader does not support.
    Unsupported(String),
    /// The payload length does not match the header.
    Truncated {
        /// Bytes the header calls for.
        expected: usize,
        /// Bytes present.
        found: usize,
    },
    /// The samples do not form a valid grid (NaN, sizes, geometry).
    Grid(GridError),
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, message } => write!(f, "{}: {message}", path.display()),
            Self::Malformed(m) => write!(f, "malformed header: {m}"),
            Self::Unsupported(m) => write!(f, "unsupported: {m}"),
            Self::Truncated { expected, found } => {
                write!(f, "payload has {found} bytes, header calls for {expected}")
            }
            Self::Grid(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for ReadError {}

impl From<GridError> for ReadError {
    fn from(e: GridError) -> Self {
        Self::Grid(e)
    }
}

fn read(path: &Path) -> Result<Vec<u8>, ReadError> {
    fs::read(path).map_err(|e| ReadError::Io { path: path.to_path_buf(), message: e.to_string() })
}

/// Sample types the readers decode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum SampleType {
    F32,
    F64,
    U8,
    I16,
    U16,
}

impl SampleType {
    fn size(self) -> usize {
        match self {
            Self::F32 => 4,
            Self::F64 => 8,
            Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
        }
    }
}

/// Decodes `payload` into `f32` samples.
fn decode(
    payload: &[u8],
    ty: SampleType,
    little: bool,
    count: usize,
) -> Result<Vec<f32>, ReadError> {
    let expected = count.checked_mul(ty.size()).ok_or(ReadError::Grid(GridError::TooLarge))?;
    if payload.len() != expected {
        return Err(ReadError::Truncated { expected, found: payload.len() });
    }
    let mut out = Vec::new();
    out.try_reserve_exact(count).map_err(|_| ReadError::Grid(GridError::TooLarge))?;
    for c in payload.chunks_exact(ty.size()) {
        let v = match ty {
            SampleType::F32 => {
                let b = [c[0], c[1], c[2], c[3]];
                if little { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) }
            }
            SampleType::F64 => {
                let b: [u8; 8] = c.try_into().map_err(|_| ReadError::Malformed("sample".into()))?;
                (if little { f64::from_le_bytes(b) } else { f64::from_be_bytes(b) }) as f32
            }
            SampleType::U8 => f32::from(c[0]),
            SampleType::I16 => {
                let b = [c[0], c[1]];
                f32::from(if little { i16::from_le_bytes(b) } else { i16::from_be_bytes(b) })
            }
            SampleType::U16 => {
                let b = [c[0], c[1]];
                f32::from(if little { u16::from_le_bytes(b) } else { u16::from_be_bytes(b) })
            }
        };
        out.push(v);
    }
    Ok(out)
}

fn three_f64(s: &str, what: &str) -> Result<DVec3, ReadError> {
    let v: Vec<f64> = s
        .split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')')
        .filter(|t| !t.is_empty())
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| ReadError::Malformed(format!("{what}: `{s}`")))?;
    match v[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(ReadError::Malformed(format!("{what} needs 3 values: `{s}`"))),
    }
}

fn three_usize(s: &str, what: &str) -> Result<[usize; 3], ReadError> {
    let v: Vec<usize> = s
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| ReadError::Malformed(format!("{what}: `{s}`")))?;
    match v[..] {
        [x, y, z] => Ok([x, y, z]),
        _ => Err(ReadError::Malformed(format!("{what} needs 3 values: `{s}`"))),
    }
}

/// Reads a NRRD file (`NRRD0001`–`NRRD0005`, 3-D, raw encoding, attached or
/// detached data). Geometry: `spacings` (or `space directions` that are
/// axis-aligned), origin from `space origin`, an `origin:=` key/value, or
/// `axis mins` with cell centring; default origin 0, spacing 1.
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn read_nrrd(path: &Path) -> Result<Grid, ReadError> {
    let bytes = read(path)?;
    parse_nrrd(&bytes, path.parent())
}

/// [`read_nrrd`] from bytes; `dir` resolves detached data files.
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn parse_nrrd(bytes: &[u8], dir: Option<&Path>) -> Result<Grid, ReadError> {
    if !bytes.starts_with(b"NRRD000") {
        return Err(ReadError::Malformed("not a NRRD file (magic)".into()));
    }
    // The header ends at the first empty line.
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .ok_or_else(|| ReadError::Malformed("no blank line ends the header".into()))?;
    let header = core::str::from_utf8(&bytes[..end])
        .map_err(|_| ReadError::Malformed("header is not UTF-8".into()))?;
    let payload = &bytes[end + 2..];
    let (mut ty, mut dims, mut little, mut raw) = (None, None, true, false);
    let (mut spacing, mut origin, mut mins, mut cell, mut data_file) =
        (DVec3::ONE, None, None, false, None);
    for line in header.lines().skip(1) {
        if line.starts_with('#') || line.trim().is_empty() {
            continue;
        }
        if let Some((k, v)) = line.split_once(":=") {
            if k.trim() == "origin" {
                origin = Some(three_f64(v, "origin")?);
            }
            continue;
        }
        let Some((k, v)) = line.split_once(':') else {
            return Err(ReadError::Malformed(format!("line without a field: `{line}`")));
        };
        let v = v.trim();
        match k.trim() {
            "type" => {
                ty = Some(match v {
                    "float" => SampleType::F32,
                    "double" => SampleType::F64,
                    "uchar" | "unsigned char" | "uint8" | "uint8_t" => SampleType::U8,
                    "short" | "int16" | "int16_t" | "signed short" => SampleType::I16,
                    "ushort" | "unsigned short" | "uint16" | "uint16_t" => SampleType::U16,
                    other => return Err(ReadError::Unsupported(format!("type `{other}`"))),
                })
            }
            "dimension" if v != "3" => {
                return Err(ReadError::Unsupported(format!("dimension {v} (only 3)")));
            }
            "sizes" => dims = Some(three_usize(v, "sizes")?),
            "spacings" => spacing = three_f64(v, "spacings")?,
            "space directions" => {
                let rows: Vec<DVec3> = v
                    .split(')')
                    .filter(|t| t.contains('('))
                    .map(|t| three_f64(t, "space directions"))
                    .collect::<Result<_, _>>()?;
                if rows.len() != 3 {
                    return Err(ReadError::Malformed("space directions needs 3 vectors".into()));
                }
                for (a, r) in rows.iter().enumerate() {
                    let off: f64 = (0..3).filter(|&b| b != a).map(|b| r[b].abs()).sum();
                    if off != 0.0 {
                        return Err(ReadError::Unsupported(
                            "non-axis-aligned space directions".into(),
                        ));
                    }
                    spacing[a] = r[a];
                }
            }
            "space origin" => origin = Some(three_f64(v, "space origin")?),
            "axis mins" => mins = Some(three_f64(v, "axis mins")?),
            "centers" | "centerings" => cell = v.split_whitespace().all(|c| c == "cell"),
            "endian" => little = v == "little",
            "encoding" => {
                raw = v == "raw";
                if !raw {
                    return Err(ReadError::Unsupported(format!("encoding `{v}` (only raw)")));
                }
            }
            "data file" | "datafile" => data_file = Some(v.to_string()),
            _ => {}
        }
    }
    let ty = ty.ok_or_else(|| ReadError::Malformed("no `type`".into()))?;
    let dims = dims.ok_or_else(|| ReadError::Malformed("no `sizes`".into()))?;
    if !raw {
        return Err(ReadError::Malformed("no `encoding`".into()));
    }
    let origin = origin.unwrap_or_else(|| match mins {
        Some(m) if cell => m + 0.5 * spacing,
        Some(m) => m,
        None => DVec3::ZERO,
    });
    let count = dims[0]
        .checked_mul(dims[1])
        .and_then(|v| v.checked_mul(dims[2]))
        .filter(|&v| v <= Grid::MAX_SAMPLES)
        .ok_or(ReadError::Grid(GridError::TooLarge))?;
    let detached;
    let payload = match data_file {
        Some(f) => {
            let p = dir.map_or_else(|| PathBuf::from(&f), |d| d.join(&f));
            detached = read(&p)?;
            &detached[..]
        }
        None => payload,
    };
    let data = decode(payload, ty, little, count)?;
    Ok(Grid::new(dims, origin, spacing, data)?)
}

/// Reads raw samples described by a JSON header such as the project's
/// sidecar: `dims` `[nx, ny, nz]`, `dtype` (`float32`, `float64`, `uint8`,
/// `int16`, `uint16`), `endian` (`little` default), `spacing`, `origin`
/// (centre of sample 0), and `file` (the payload, relative to the JSON).
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn read_raw_json(json_path: &Path) -> Result<Grid, ReadError> {
    let text = read(json_path)?;
    let v: serde_json::Value =
        serde_json::from_slice(&text).map_err(|e| ReadError::Malformed(format!("JSON: {e}")))?;
    let file = v["file"].as_str().ok_or_else(|| ReadError::Malformed("no `file`".into()))?;
    let dir = json_path.parent().unwrap_or(Path::new("."));
    let payload = read(&dir.join(file))?;
    parse_raw_json(&v, &payload)
}

/// [`read_raw_json`] from a parsed header and the payload bytes.
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn parse_raw_json(v: &serde_json::Value, payload: &[u8]) -> Result<Grid, ReadError> {
    let triple = |key: &str| -> Result<[f64; 3], ReadError> {
        let a =
            v[key].as_array().ok_or_else(|| ReadError::Malformed(format!("no `{key}` array")))?;
        let x: Vec<f64> = a.iter().filter_map(serde_json::Value::as_f64).collect();
        match x[..] {
            [a, b, c] if a.is_finite() && b.is_finite() && c.is_finite() => Ok([a, b, c]),
            _ => Err(ReadError::Malformed(format!("`{key}` needs 3 finite numbers"))),
        }
    };
    let dims = {
        let a =
            v["dims"].as_array().ok_or_else(|| ReadError::Malformed("no `dims` array".into()))?;
        let d: Vec<usize> =
            a.iter().filter_map(|x| x.as_u64()).filter_map(|x| usize::try_from(x).ok()).collect();
        match d[..] {
            [x, y, z] if a.len() == 3 => [x, y, z],
            _ => return Err(ReadError::Malformed("`dims` needs 3 non-negative integers".into())),
        }
    };
    let ty = match v["dtype"].as_str().unwrap_or("float32") {
        "float32" | "f32" => SampleType::F32,
        "float64" | "f64" => SampleType::F64,
        "uint8" | "u8" => SampleType::U8,
        "int16" | "i16" => SampleType::I16,
        "uint16" | "u16" => SampleType::U16,
        other => return Err(ReadError::Unsupported(format!("dtype `{other}`"))),
    };
    let little = v["endian"].as_str().unwrap_or("little") == "little";
    let spacing = DVec3::from(triple("spacing")?);
    let origin = DVec3::from(triple("origin")?);
    let count = dims[0]
        .checked_mul(dims[1])
        .and_then(|x| x.checked_mul(dims[2]))
        .filter(|&x| x <= Grid::MAX_SAMPLES)
        .ok_or(ReadError::Grid(GridError::TooLarge))?;
    let data = decode(payload, ty, little, count)?;
    Ok(Grid::new(dims, origin, spacing, data)?)
}

/// Reads VTK image data (legacy `STRUCTURED_POINTS` or XML `ImageData`,
/// `.vtk`/`.vti`) with the `vtkio` crate: the first point-data array
/// (first component) becomes the samples, point `(0,0,0)` at `origin`
/// (taken as sample centres, the crates' cell-centred convention).
///
/// # Errors
/// [`ReadError`] naming the problem: unreadable or malformed files, other
/// data set types, compressed XML payloads, no point data.
pub fn read_vtk(path: &Path) -> Result<Grid, ReadError> {
    use vtkio::model::{Attribute, DataSet, Extent};
    let vtk = vtkio::Vtk::import(path).map_err(|e| match e {
        vtkio::Error::IO(io) => ReadError::Io { path: path.to_path_buf(), message: io.to_string() },
        other => ReadError::Malformed(format!("VTK: {other}")),
    })?;
    let DataSet::ImageData { extent, origin, spacing, pieces, .. } = vtk.data else {
        return Err(ReadError::Unsupported(
            "VTK data set other than image data / structured points".into(),
        ));
    };
    let dims = match extent {
        Extent::Dims(d) => d.map(|v| v as usize),
        Extent::Ranges(r) => {
            let len = |x: &core::ops::RangeInclusive<i32>| {
                usize::try_from(i64::from(*x.end()) - i64::from(*x.start()) + 1).unwrap_or(0)
            };
            [len(&r[0]), len(&r[1]), len(&r[2])]
        }
    };
    let piece = pieces
        .into_iter()
        .next()
        .ok_or_else(|| ReadError::Malformed("VTK image data without pieces".into()))?
        .into_loaded_piece_data(path.parent())
        .map_err(|e| ReadError::Malformed(format!("VTK piece: {e}")))?;
    let (data, components) = piece
        .data
        .point
        .into_iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) => Some((d.data, d.elem.num_comp() as usize)),
            Attribute::Field { data_array, .. } => {
                data_array.into_iter().next().map(|f| (f.data, f.elem as usize))
            }
        })
        .ok_or_else(|| ReadError::Malformed("VTK image data without point data".into()))?;
    let values: Vec<f32> =
        data.cast_into::<f32>().ok_or_else(|| ReadError::Unsupported("VTK sample type".into()))?;
    let values =
        if components > 1 { values.iter().step_by(components).copied().collect() } else { values };
    let f = |a: [f32; 3]| DVec3::new(f64::from(a[0]), f64::from(a[1]), f64::from(a[2]));
    Ok(Grid::new(dims, f(origin), f(spacing), values)?)
}

/// Reads a grid by extension: `.nrrd`/`.nhdr` as NRRD, `.json` as a raw
/// header (a `.raw` file is read through the `.json` beside it),
/// `.vtk`/`.vti` as VTK image data.
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn read_grid(path: &Path) -> Result<Grid, ReadError> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("nrrd" | "nhdr") => read_nrrd(path),
        Some("json") => read_raw_json(path),
        Some("raw") => read_raw_json(&path.with_extension("json")),
        Some("vtk" | "vti") => read_vtk(path),
        other => Err(ReadError::Unsupported(format!("file extension {other:?}"))),
    }
}
