//! Reading a box of a raw payload: one seek and one read per row of the
//! box, never the rest of the file (raw + JSON and raw NRRD share it).

use alloc::{format, vec::Vec};
use std::{
    fs::File,
    io::{Read, Seek, SeekFrom},
    path::Path,
};

use glam::DVec3;

use super::{
    ReadError, ReadErrorKind,
    decode::{SampleType, decode},
    error::malformed,
};
use crate::Grid;

/// Where the samples of a volume are, and what they are.
pub(super) struct Payload<'a> {
    /// The file holding them.
    pub(super) path: &'a Path,
    /// Where in it they start (after an attached header).
    pub(super) offset: u64,
    /// Samples per axis of the whole volume.
    pub(super) dims: [usize; 3],
    pub(super) ty: SampleType,
    pub(super) little: bool,
    /// Centre of sample `(0, 0, 0)`, and the cell size.
    pub(super) origin: DVec3,
    pub(super) spacing: DVec3,
}

/// The samples `lo ≤ (i, j, k) < hi` of `p`, as a grid whose origin is
/// sample `lo`'s centre. The payload must run from its offset to the end
/// of the file and hold exactly the volume's samples (checked by its
/// length, not by reading it).
pub(super) fn read_box(p: &Payload<'_>, lo: [usize; 3], hi: [usize; 3]) -> Result<Grid, ReadError> {
    if (0..3).any(|a| lo[a] >= hi[a] || hi[a] > p.dims[a]) {
        return Err(malformed(format!(
            "box {lo:?}..{hi:?} is empty or outside the volume's dims {:?}",
            p.dims
        )));
    }
    let box_dims = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let count = box_dims[0]
        .checked_mul(box_dims[1])
        .and_then(|x| x.checked_mul(box_dims[2]))
        .filter(|&x| x <= Grid::MAX_SAMPLES)
        .ok_or(ReadError::from(ReadErrorKind::TooLarge))?;
    let size = p.ty.size();
    let total = p.dims[0]
        .checked_mul(p.dims[1])
        .and_then(|x| x.checked_mul(p.dims[2]))
        .and_then(|x| x.checked_mul(size))
        .ok_or(ReadError::from(ReadErrorKind::TooLarge))?;
    let io = |e| ReadError::from(ReadErrorKind::Io(e)).in_file(p.path);
    let mut f = File::open(p.path).map_err(io)?;
    let len = f.metadata().map_err(io)?.len().saturating_sub(p.offset);
    if len != total as u64 {
        return Err(ReadError::from(ReadErrorKind::Truncated {
            expected: total,
            found: usize::try_from(len).unwrap_or(usize::MAX),
        })
        .in_file(p.path));
    }
    let row = box_dims[0] * size;
    let mut bytes = alloc::vec![0u8; count * size];
    let mut at = 0;
    for k in lo[2]..hi[2] {
        for j in lo[1]..hi[1] {
            let first = (lo[0] + p.dims[0] * (j + p.dims[1] * k)) * size;
            f.seek(SeekFrom::Start(p.offset + first as u64)).map_err(io)?;
            f.read_exact(&mut bytes[at..at + row]).map_err(io)?;
            at += row;
        }
    }
    let data = decode(&bytes, p.ty, p.little, count)?;
    let origin = p.origin + p.spacing * DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64);
    Ok(Grid::new(box_dims, origin, p.spacing, data)?)
}

/// The bytes of `path` up to and including the first empty line (`\n\n`)
/// and their length, reading no further than the next 64 KiB block; at
/// most 1 MiB.
pub(super) fn read_header(path: &Path) -> Result<(Vec<u8>, usize), ReadError> {
    const LIMIT: usize = 1 << 20;
    let io = |e| ReadError::from(ReadErrorKind::Io(e)).in_file(path);
    let mut f = File::open(path).map_err(io)?;
    let mut bytes = Vec::new();
    let mut block = alloc::vec![0u8; 1 << 16];
    loop {
        let from = bytes.len().saturating_sub(1);
        let got = f.read(&mut block).map_err(io)?;
        bytes.extend_from_slice(&block[..got]);
        if let Some(end) = bytes[from..].windows(2).position(|w| w == b"\n\n") {
            return Ok((bytes, from + end));
        }
        if got == 0 || bytes.len() > LIMIT {
            return Err(malformed("no blank line ends the header").in_file(path));
        }
    }
}
