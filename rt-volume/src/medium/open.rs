//! One reader for every supported volume and mesh file, as a medium.

use std::path::Path;

use alloc::{boxed::Box, string::String};

use super::{Medium, MediumError, MeshTrace, Samples};
use crate::{
    Interp,
    io::{is_unstructured, read_grid, read_unstructured},
};

/// How [`Medium::open`] reads a file.
#[derive(Clone, Debug, PartialEq)]
pub struct MediumOptions {
    /// What the values are (default: air's density).
    pub samples: Samples,
    /// Accept densities ≤ 0 (or indices below 1) instead of refusing them.
    pub allow_nonphysical: bool,
    /// A grid's interpolation (default Catmull–Rom: C¹, so a shadowgraph,
    /// which images the gradient's derivative, does not print the cells).
    pub interp: Interp,
    /// How a mesh is traced.
    pub mesh: MeshTrace,
    /// A mesh's point- or cell-data array (`None`: its first scalar point
    /// array, else its first scalar cell array).
    pub array: Option<String>,
}

impl Default for MediumOptions {
    fn default() -> Self {
        Self {
            samples: Samples::AIR,
            allow_nonphysical: false,
            interp: Interp::CatmullRom,
            mesh: MeshTrace::Smooth,
            array: None,
        }
    }
}

impl Medium {
    /// Reads `path` as a medium: an unstructured mesh (`.vtu`, legacy
    /// `.vtk` unstructured grids) or a grid (NRRD, raw + JSON, VTK image
    /// data), its values read as `options` say.
    ///
    /// # Errors
    /// [`MediumError::Read`] for a file that cannot be read (naming it and
    /// the problem); [`MediumError::InFile`] for data that make no medium.
    pub fn open(path: &Path, options: &MediumOptions) -> Result<Self, MediumError> {
        let o = options;
        let medium = if is_unstructured(path) {
            let data = read_unstructured(path, o.array.as_deref()).map_err(MediumError::Read)?;
            Self::from_mesh(
                data.points,
                &data.cells,
                data.values,
                o.samples,
                o.allow_nonphysical,
                &data.array,
                o.mesh,
            )
        } else {
            let grid = read_grid(path).map_err(MediumError::Read)?;
            Self::from_grid(grid, o.samples, o.allow_nonphysical, o.interp)
        };
        medium.map_err(|e| MediumError::InFile { path: path.into(), source: Box::new(e) })
    }
}
