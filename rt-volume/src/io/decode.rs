//! Sample decoding and header number parsing shared by the readers.

use alloc::{format, vec::Vec};

use glam::DVec3;

use super::{ReadError, ReadErrorKind, error::malformed};

/// Sample types the readers decode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SampleType {
    F32,
    F64,
    U8,
    I16,
    U16,
}

impl SampleType {
    pub(super) fn size(self) -> usize {
        match self {
            Self::F32 => 4,
            Self::F64 => 8,
            Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
        }
    }
}

/// Decodes `payload` into `f32` samples.
pub(super) fn decode(
    payload: &[u8],
    ty: SampleType,
    little: bool,
    count: usize,
) -> Result<Vec<f32>, ReadError> {
    let expected = count.checked_mul(ty.size()).ok_or(ReadError::from(ReadErrorKind::TooLarge))?;
    if payload.len() != expected {
        return Err(ReadErrorKind::Truncated { expected, found: payload.len() }.into());
    }
    let mut out = Vec::new();
    out.try_reserve_exact(count).map_err(|_| ReadError::from(ReadErrorKind::TooLarge))?;
    for c in payload.chunks_exact(ty.size()) {
        let v = match ty {
            SampleType::F32 => {
                let b = [c[0], c[1], c[2], c[3]];
                if little { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) }
            }
            SampleType::F64 => {
                let b: [u8; 8] = c.try_into().map_err(|_| malformed("sample"))?;
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

pub(super) fn three_f64(s: &str, what: &str) -> Result<DVec3, ReadError> {
    let v: Vec<f64> = s
        .split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')')
        .filter(|t| !t.is_empty())
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| malformed(format!("{what}: `{s}`")))?;
    match v[..] {
        [x, y, z] => Ok(DVec3::new(x, y, z)),
        _ => Err(malformed(format!("{what} needs 3 values: `{s}`"))),
    }
}

pub(super) fn three_usize(s: &str, what: &str) -> Result<[usize; 3], ReadError> {
    let v: Vec<usize> = s
        .split_whitespace()
        .map(str::parse)
        .collect::<Result<_, _>>()
        .map_err(|_| malformed(format!("{what}: `{s}`")))?;
    match v[..] {
        [x, y, z] => Ok([x, y, z]),
        _ => Err(malformed(format!("{what} needs 3 values: `{s}`"))),
    }
}
