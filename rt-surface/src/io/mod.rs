//! Mesh readers (feature `io`): Wavefront OBJ (through `tobj`), PLY with
//! per-vertex scalar properties (through `ply-rs-bw`, the maintained fork
//! of `ply-rs`) and VTK polydata, legacy `.vtk` and XML `.vtp` (through
//! `vtkio`).
//!
//! Each reader returns a [`MeshData`]: positions, triangles (polygons are
//! split into fans, triangle strips into their triangles), normals where
//! the file has one per vertex, and every per-vertex scalar the file
//! carries, by name. [`MeshData::into_mesh`] then picks the scalar to
//! colour by and validates the lot as a [`Mesh`](crate::Mesh). Every malformed,
//! truncated or inconsistent file is an `Err` naming the problem; nothing
//! is read past what the file declares.
//!
//! Where the scalars come from:
//! - **PLY**: every scalar property of the `vertex` element other than
//!   `x y z nx ny nz`, under its own name (`red`, `confidence`, `pressure`…).
//! - **VTK**: every point-data array (attributes and field data) with one
//!   value per point; arrays of several components give their magnitude
//!   (a velocity's speed), under the array's name. Cell data is not read.
//! - **OBJ**: the format has no scalars; tools that colour-map OBJ write the
//!   scalar as a 1-D texture coordinate, so `vt` coordinates are offered as
//!   scalars `u` and `v`.
//!
//! ```
//! use rt_surface::io::parse_ply;
//!
//! let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
//! property float z\nproperty float pressure\nelement face 1\n\
//! property list uchar int vertex_indices\nend_header\n\
//! 0 0 0 1.5\n1 0 0 2.5\n0 1 0 3.5\n3 0 1 2\n";
//! let data = parse_ply(ply).unwrap();
//! assert_eq!(data.scalar_names().collect::<Vec<_>>(), ["pressure"]);
//! let mesh = data.into_mesh(Some("pressure")).unwrap();
//! assert_eq!(mesh.scalars(), Some(&[1.5, 2.5, 3.5][..]));
//! ```

mod error;
mod mesh_data;
mod obj;
mod ply;
mod vtk;

use alloc::vec::Vec;
use std::{fs, path::Path};

pub use error::{ReadError, ReadErrorKind};
pub use mesh_data::MeshData;
pub use obj::parse_obj;
pub use ply::{parse_ply, write_ply};
pub use vtk::{parse_vtk_legacy, parse_vtk_xml};

fn read(path: &Path) -> Result<Vec<u8>, ReadError> {
    fs::read(path).map_err(|e| ReadError::from(ReadErrorKind::Io(e)))
}

/// Reads a mesh by extension: `.obj`, `.ply`, `.vtk` (legacy) or `.vtp`
/// (XML polydata).
///
/// # Errors
/// [`ReadError`] naming the problem; an unknown extension is
/// [`ReadErrorKind::UnknownFormat`]. Every error names the file
/// ([`ReadError::path`]).
pub fn read_mesh(path: &Path) -> Result<MeshData, ReadError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    let parse = match ext.as_deref() {
        Some("obj") => parse_obj,
        Some("ply") => parse_ply,
        Some("vtk") => parse_vtk_legacy,
        Some("vtp") => parse_vtk_xml,
        _ => return Err(ReadError::from(ReadErrorKind::UnknownFormat).in_file(path)),
    };
    read(path).and_then(|bytes| parse(&bytes)).map_err(|e| e.in_file(path))
}
