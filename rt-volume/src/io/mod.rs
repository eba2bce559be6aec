//! File readers (feature `io`). Gridded data ([`read_grid`]): raw samples
//! with a JSON header (the project's sidecar format), NRRD (the original
//! tool's format) and VTK image data (through `vtkio`). Unstructured grids
//! ([`read_unstructured`], told apart by [`is_unstructured`]): VTK legacy
//! `UNSTRUCTURED_GRID` and XML `.vtu`, as points, linear volume cells
//! ([`Cell`](crate::Cell)) and one scalar per point.
//! Every malformed, truncated or oversized input is an `Err` naming the
//! problem; samples that are NaN or infinite are rejected.

mod base64;
mod decode;
mod error;
mod legacy_scan;
mod nrrd;
mod raw_json;
mod unstructured;
mod vtk;
mod xml_scan;

use alloc::vec::Vec;
use std::{fs, path::Path};

pub use error::{ReadError, ReadErrorKind};
pub use nrrd::{parse_nrrd, read_nrrd};
pub use raw_json::{parse_raw_json, read_raw_json, read_raw_json_box};
pub use unstructured::{UnstructuredData, is_unstructured, read_unstructured};
pub use vtk::read_vtk;

use crate::Grid;

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
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("nrrd" | "nhdr") => read_nrrd(path),
        Some("json") => read_raw_json(path),
        Some("raw") => read_raw_json(&path.with_extension("json")),
        Some("vtk" | "vti") => read_vtk(path),
        _ => Err(ReadError::from(ReadErrorKind::UnknownFormat).in_file(path)),
    }
}
