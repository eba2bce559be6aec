//! NRRD (the original tool's format): attached or detached raw data.

use alloc::{
    format,
    string::{String, ToString},
    vec::Vec,
};
use std::path::{Path, PathBuf};

use glam::DVec3;

use super::{
    ReadError, ReadErrorKind,
    decode::{SampleType, decode, three_f64, three_usize},
    error::{malformed, unsupported},
    read,
    sub_box::{Payload, read_box, read_header},
};
use crate::{Grid, GridInfo, GridSamples};

/// Reads a NRRD file (`NRRD0001`–`NRRD0005`, 3-D, raw encoding, attached or
/// detached data). Geometry: `spacings` (or `space directions` that are
/// axis-aligned), origin from `space origin`, an `origin:=` key/value, or
/// `axis mins` with cell centring; default origin 0, spacing 1.
///
/// Too many samples is an error before the payload is read (the header
/// is read first, on its own).
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn read_nrrd(path: &Path) -> Result<Grid, ReadError> {
    read_nrrd_samples(path)?.into_grid().map_err(|e| ReadError::from(e).in_file(path))
}

/// [`read_nrrd`]'s samples before the grid's checks (NaN kept).
///
/// # Errors
/// [`ReadError`] naming the problem.
pub(super) fn read_nrrd_samples(path: &Path) -> Result<GridSamples, ReadError> {
    let (h, _) = read_header_of(path)?;
    sample_count(h.dims).map_err(|e| e.in_file(path))?;
    let bytes = read(path)?;
    parse_nrrd_samples(&bytes, path.parent()).map_err(|e| e.in_file(path))
}

/// `nx·ny·nz`, at most [`Grid::MAX_SAMPLES`].
fn sample_count(dims: [usize; 3]) -> Result<usize, ReadError> {
    dims[0]
        .checked_mul(dims[1])
        .and_then(|v| v.checked_mul(dims[2]))
        .filter(|&v| v <= Grid::MAX_SAMPLES)
        .ok_or(ReadError::from(ReadErrorKind::TooLarge))
}

/// [`read_nrrd`] from bytes; `dir` resolves detached data files.
///
/// # Errors
/// [`ReadError`] naming the problem.
pub fn parse_nrrd(bytes: &[u8], dir: Option<&Path>) -> Result<Grid, ReadError> {
    Ok(parse_nrrd_samples(bytes, dir)?.into_grid()?)
}

/// [`parse_nrrd`]'s samples before the grid's checks (NaN kept).
fn parse_nrrd_samples(bytes: &[u8], dir: Option<&Path>) -> Result<GridSamples, ReadError> {
    if !bytes.starts_with(b"NRRD000") {
        return Err(malformed("not a NRRD file (magic)"));
    }
    // The header ends at the first empty line.
    let end = bytes
        .windows(2)
        .position(|w| w == b"\n\n")
        .ok_or_else(|| malformed("no blank line ends the header"))?;
    let h = parse_header(&bytes[..end])?;
    let payload = &bytes[end + 2..];
    let dims = h.dims;
    let count = sample_count(dims)?;
    let detached;
    let payload = match &h.data_file {
        Some(f) => {
            let p = dir.map_or_else(|| PathBuf::from(f), |d| d.join(f));
            detached = read(&p)?;
            &detached[..]
        }
        None => payload,
    };
    let data = decode(payload, h.ty, h.little, count)?;
    Ok(GridSamples { dims, origin: h.origin, spacing: h.spacing, data })
}

/// What a NRRD header says.
struct Header {
    ty: SampleType,
    dims: [usize; 3],
    little: bool,
    spacing: DVec3,
    origin: DVec3,
    /// The detached data file, as written.
    data_file: Option<String>,
}

/// The header's fields (the bytes before the blank line).
fn parse_header(bytes: &[u8]) -> Result<Header, ReadError> {
    let header = core::str::from_utf8(bytes).map_err(|_| malformed("header is not UTF-8"))?;
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
            return Err(malformed(format!("line without a field: `{line}`")));
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
                    other => return Err(unsupported(format!("type `{other}`"))),
                })
            }
            "dimension" if v != "3" => {
                return Err(unsupported(format!("dimension {v} (only 3)")));
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
                    return Err(malformed("space directions needs 3 vectors"));
                }
                for (a, r) in rows.iter().enumerate() {
                    let off: f64 = (0..3).filter(|&b| b != a).map(|b| r[b].abs()).sum();
                    if off != 0.0 {
                        return Err(unsupported("non-axis-aligned space directions"));
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
                    // Compressed payloads would have to be inflated whole
                    // (and bricks streamed out of them): not read.
                    return Err(unsupported(format!(
                        "encoding `{v}` (only raw; reading a sub-box needs raw too)"
                    )));
                }
            }
            "data file" | "datafile" => data_file = Some(v.to_string()),
            _ => {}
        }
    }
    let ty = ty.ok_or_else(|| malformed("no `type`"))?;
    let dims = dims.ok_or_else(|| malformed("no `sizes`"))?;
    if !raw {
        return Err(malformed("no `encoding`"));
    }
    let origin = origin.unwrap_or_else(|| match mins {
        Some(m) if cell => m + 0.5 * spacing,
        Some(m) => m,
        None => DVec3::ZERO,
    });
    Ok(Header { ty, dims, little, spacing, origin, data_file })
}

/// The header of a NRRD file, read without reading the payload (only the
/// file's first block).
fn read_header_of(path: &Path) -> Result<(Header, usize), ReadError> {
    let (bytes, end) = read_header(path)?;
    if !bytes.starts_with(b"NRRD000") {
        return Err(malformed("not a NRRD file (magic)").in_file(path));
    }
    let h = parse_header(&bytes[..end]).map_err(|e| e.in_file(path))?;
    Ok((h, end + 2))
}

/// The samples `lo ≤ (i, j, k) < hi` of a NRRD volume with raw encoding
/// (attached or detached data), read without reading the rest of it: the
/// header's block, then one seek and one read per row of the box. The
/// grid keeps the volume's spacing; its origin is sample `lo`'s centre.
/// The payload must hold exactly the header's samples (checked by its
/// length, not by reading it); the whole volume may exceed
/// [`Grid::MAX_SAMPLES`], the box may not.
///
/// # Errors
/// [`ReadError`] naming the problem: an empty box or one past the
/// volume's `sizes` is [`ReadErrorKind::Malformed`]; a payload of the
/// wrong length [`ReadErrorKind::Truncated`]; a compressed encoding
/// [`ReadErrorKind::Unsupported`] (sub-boxes are read from raw payloads).
pub fn read_nrrd_box(path: &Path, lo: [usize; 3], hi: [usize; 3]) -> Result<Grid, ReadError> {
    let (h, payload_at) = read_header_of(path)?;
    let detached = h.data_file.as_ref().map(|f| path.parent().unwrap_or(Path::new(".")).join(f));
    let payload = Payload {
        path: detached.as_deref().unwrap_or(path),
        offset: if detached.is_some() { 0 } else { payload_at as u64 },
        dims: h.dims,
        ty: h.ty,
        little: h.little,
        origin: h.origin,
        spacing: h.spacing,
    };
    read_box(&payload, lo, hi).map_err(|e| e.in_file(path))
}

/// The header of a NRRD volume (dims, origin, spacing), without reading
/// its payload.
///
/// # Errors
/// [`ReadError`] naming the problem; a header [`GridInfo::new`] refuses
/// is [`ReadErrorKind::Grid`].
pub fn read_nrrd_info(path: &Path) -> Result<GridInfo, ReadError> {
    let (h, _) = read_header_of(path)?;
    GridInfo::new(h.dims, h.origin, h.spacing).map_err(|e| ReadError::from(e).in_file(path))
}
