//! File readers (feature `io`). Gridded data ([`read_grid`]): raw samples
//! with a JSON header (the project's sidecar format), NRRD (the original
//! tool's format) and VTK image data (through `vtkio`). Unstructured grids
//! ([`read_unstructured`], told apart by [`is_unstructured`]): VTK legacy
//! `UNSTRUCTURED_GRID` and XML `.vtu`, as points, linear volume cells
//! ([`Cell`](crate::Cell)) and one scalar per point.
//! Every malformed, truncated or oversized input is an `Err` naming the
//! problem; samples that are NaN or infinite are rejected, unless read
//! with [`read_grid_samples`], which keeps them to be counted or filled.
//!
//! For bricks of volumes larger than memory: [`read_grid_info`] reads a
//! raw + JSON or NRRD header alone, [`read_grid_box`] a box of samples,
//! one seek and read per row, never the rest (raw payloads only).

mod base64;
mod decode;
mod error;
mod legacy_scan;
mod nrrd;
mod raw_json;
mod sub_box;
mod unstructured;
mod vtk;
mod xml_scan;

use alloc::vec::Vec;
use std::{fs, path::Path};

pub use error::{ReadError, ReadErrorKind};
pub use nrrd::{parse_nrrd, read_nrrd, read_nrrd_box, read_nrrd_info};
pub use raw_json::{parse_raw_json, read_raw_json, read_raw_json_box, read_raw_json_info};
pub use unstructured::{UnstructuredData, is_unstructured, read_unstructured};
pub use vtk::read_vtk;

use crate::{Grid, GridInfo, GridSamples};

/// The bytes of `path`; an error names it.
fn read(path: &Path) -> Result<Vec<u8>, ReadError> {
    fs::read(path).map_err(|e| ReadError::from(ReadErrorKind::Io(e)).in_file(path))
}

/// Reads a grid by extension: `.nrrd`/`.nhdr` as NRRD, `.json` as a raw
/// header (a `.raw` file is read through the `.json` beside it),
/// `.vtk`/`.vti` as VTK image data. Unstructured grids (`.vtu`, and
/// `.vtk` files [`is_unstructured`] picks out) are read with
/// [`read_unstructured`].
///
/// # Errors
/// [`ReadError`] naming the problem and the file; an unknown extension is
/// [`ReadErrorKind::UnknownFormat`].
pub fn read_grid(path: &Path) -> Result<Grid, ReadError> {
    match extension(path).as_deref() {
        Some("nrrd" | "nhdr") => read_nrrd(path),
        Some("json") => read_raw_json(path),
        Some("raw") => read_raw_json(&path.with_extension("json")),
        Some("vtk" | "vti") => read_vtk(path),
        _ => Err(ReadError::from(ReadErrorKind::UnknownFormat).in_file(path)),
    }
}

/// [`read_grid`]'s samples before the grid's checks: NaN and infinite
/// samples kept, for a caller that counts them (`rt info`) or fills them
/// ([`GridSamples::into_grid_filling`]).
///
/// # Errors
/// As [`read_grid`], less the non-finite samples.
pub fn read_grid_samples(path: &Path) -> Result<GridSamples, ReadError> {
    match extension(path).as_deref() {
        Some("nrrd" | "nhdr") => nrrd::read_nrrd_samples(path),
        Some("json") => raw_json::read_raw_json_samples(path),
        Some("raw") => raw_json::read_raw_json_samples(&path.with_extension("json")),
        Some("vtk" | "vti") => vtk::read_vtk_samples(path),
        _ => Err(ReadError::from(ReadErrorKind::UnknownFormat).in_file(path)),
    }
}

/// Reads the header of a grid file by extension, without its payload:
/// `.nrrd`/`.nhdr` ([`read_nrrd_info`]), `.json` or `.raw`
/// ([`read_raw_json_info`]). Every rank of a distributed trace reads it
/// to partition the grid, then only its brick ([`read_grid_box`]).
///
/// # Errors
/// [`ReadError`] naming the problem and the file; VTK files are
/// [`ReadErrorKind::Unsupported`] (their payload is not read by rows),
/// other extensions [`ReadErrorKind::UnknownFormat`].
pub fn read_grid_info(path: &Path) -> Result<GridInfo, ReadError> {
    match extension(path).as_deref() {
        Some("nrrd" | "nhdr") => read_nrrd_info(path),
        Some("json") => read_raw_json_info(path),
        Some("raw") => read_raw_json_info(&path.with_extension("json")),
        Some("vtk" | "vti") => {
            Err(error::unsupported("reading a VTK grid's header alone (use raw + JSON or NRRD)")
                .in_file(path))
        }
        _ => Err(ReadError::from(ReadErrorKind::UnknownFormat).in_file(path)),
    }
}

/// Reads the samples `lo ≤ (i, j, k) < hi` of a grid file by extension,
/// without the rest: `.nrrd`/`.nhdr` ([`read_nrrd_box`], raw encoding),
/// `.json` or `.raw` ([`read_raw_json_box`]).
///
/// # Errors
/// As [`read_grid_info`], and as the box readers.
pub fn read_grid_box(path: &Path, lo: [usize; 3], hi: [usize; 3]) -> Result<Grid, ReadError> {
    match extension(path).as_deref() {
        Some("nrrd" | "nhdr") => read_nrrd_box(path, lo, hi),
        Some("json") => read_raw_json_box(path, lo, hi),
        Some("raw") => read_raw_json_box(&path.with_extension("json"), lo, hi),
        Some("vtk" | "vti") => {
            Err(error::unsupported("reading a box of a VTK grid (use raw + JSON or NRRD)")
                .in_file(path))
        }
        _ => Err(ReadError::from(ReadErrorKind::UnknownFormat).in_file(path)),
    }
}

/// A path's extension, lower case.
fn extension(path: &Path) -> Option<alloc::string::String> {
    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}
