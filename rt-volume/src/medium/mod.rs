//! The media a ray can be traced through, as one closed set: a gridded
//! field with its octree ([`GridMedium`]), an unstructured mesh traced
//! exactly cell by cell, or the same mesh with recovered gradients
//! (feature `mesh`). Each carries its own trace settings, so an instrument
//! takes a [`Medium`] and asks it for bounds, ambient index and paths.
//!
//! [`Samples`] turns what a file holds (density by Gladstone–Dale, or the
//! index itself) into index, with the physical checks; [`Medium::open`]
//! (feature `io`) reads any supported volume or mesh file as a medium.

#[cfg(feature = "io")]
mod open;
mod samples;

use alloc::string::String;
use core::fmt;

use glam::DVec3;

use crate::{
    Bounds, Grid, GridError, GridField, IndexField, Interp, Octree, OctreeError, TraceError,
    TraceParams, TraceResult, build_octree, trace, trace_skipping,
};
#[cfg(feature = "mesh")]
use crate::{MeshError, SmoothField, UnstructuredField};

#[cfg(feature = "io")]
pub use open::MediumOptions;
pub use samples::Samples;

/// How an unstructured mesh is traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeshTrace {
    /// Exactly through the data's piecewise-linear interpolant, cell by
    /// cell in closed form: a ray's deflection is first order in the cell
    /// size, so coarse cells show as facets.
    Exact,
    /// Gradients recovered at the points and interpolated, integrated by
    /// RK4 at half an edge: second order per ray, no facets, and a given
    /// error sooner than [`MeshTrace::Exact`] (`rt-report unstructured`).
    #[default]
    Smooth,
}

/// A gridded index field with the octree that bounds its interpolant (the
/// fast path: straight steps where the field is smooth) and its trace
/// settings.
#[derive(Clone, Debug)]
pub struct GridMedium {
    field: GridField,
    tree: Octree,
    params: TraceParams,
}

impl GridMedium {
    /// `grid` (index samples) interpolated as `interp`; the index outside
    /// is that of its first sample (a corner: undisturbed gas, usually).
    /// Traced by leapfrog at two cells, which reaches the image error of
    /// one-cell steps in less time (`rt-report schlieren`, `rt-2voxel`).
    ///
    /// # Errors
    /// [`MediumError::Grid`] for a bad ambient index,
    /// [`MediumError::Octree`] for a grid under 2 samples a side.
    pub fn new(grid: Grid, interp: Interp) -> Result<Self, MediumError> {
        let ambient = grid.data().first().map_or(1.0, |&n| f64::from(n));
        let field = GridField::new(grid, interp, ambient)?;
        let tree = build_octree(&field)?;
        let base = TraceParams::for_grid(&field);
        let params = TraceParams { step: 2.0 * base.step, max_step: 2.0 * base.max_step, ..base };
        Ok(Self { field, tree, params })
    }

    /// `field` as it is (its own ambient index), traced with `params`.
    ///
    /// # Errors
    /// [`MediumError::Octree`] for a grid under 2 samples a side.
    pub fn from_field(field: GridField, params: TraceParams) -> Result<Self, MediumError> {
        let tree = build_octree(&field)?;
        Ok(Self { field, tree, params })
    }

    /// The field.
    #[must_use]
    pub fn field(&self) -> &GridField {
        &self.field
    }

    /// Its octree.
    #[must_use]
    pub fn tree(&self) -> &Octree {
        &self.tree
    }
}

/// A refractive medium a ray can be traced through.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub enum Medium {
    /// A gridded field on the octree's fast path.
    Grid(GridMedium),
    /// An unstructured mesh traced exactly, cell by cell.
    #[cfg(feature = "mesh")]
    ExactMesh(UnstructuredField),
    /// An unstructured mesh with recovered gradients, integrated.
    #[cfg(feature = "mesh")]
    SmoothMesh {
        /// The mesh and its gradients.
        field: SmoothField,
        /// Its trace settings ([`SmoothField::params`] unless replaced).
        params: TraceParams,
    },
}

impl Medium {
    /// `grid`'s samples read as `samples` say, mapped to index and
    /// interpolated as `interp` (see [`GridMedium::new`]).
    ///
    /// # Errors
    /// Non-physical samples unless `allow_nonphysical`, a bad constant
    /// (see [`Samples::grid_to_index`]); as [`GridMedium::new`].
    pub fn from_grid(
        grid: Grid,
        samples: Samples,
        allow_nonphysical: bool,
        interp: Interp,
    ) -> Result<Self, MediumError> {
        let grid = samples.grid_to_index(grid, allow_nonphysical)?;
        Ok(Self::Grid(GridMedium::new(grid, interp)?))
    }

    /// A mesh of `points` and `cells` with one value per point read as
    /// `samples` say (`array` names them in errors), traced as `how`; the
    /// index outside is that of its first point.
    ///
    /// # Errors
    /// Non-physical values unless `allow_nonphysical`, a bad constant; a
    /// bad mesh ([`MediumError::Mesh`]).
    #[cfg(feature = "mesh")]
    pub fn from_mesh(
        points: alloc::vec::Vec<DVec3>,
        cells: &[crate::Cell],
        values: alloc::vec::Vec<f64>,
        samples: Samples,
        allow_nonphysical: bool,
        array: &str,
        how: MeshTrace,
    ) -> Result<Self, MediumError> {
        let index = samples.values_to_index(values, allow_nonphysical, array)?;
        let ambient = index.first().copied().unwrap_or(1.0);
        let field = UnstructuredField::new(points, cells, index, ambient)?;
        Ok(match how {
            MeshTrace::Exact => Self::ExactMesh(field),
            MeshTrace::Smooth => {
                let field = SmoothField::new(field);
                let params = field.params();
                Self::SmoothMesh { field, params }
            }
        })
    }

    /// The box the field fills.
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        match self {
            Self::Grid(g) => g.field.bounds(),
            #[cfg(feature = "mesh")]
            Self::ExactMesh(m) => m.bounds(),
            #[cfg(feature = "mesh")]
            Self::SmoothMesh { field, .. } => field.mesh().bounds(),
        }
    }

    /// The undisturbed index outside (interferometry's reference).
    #[must_use]
    pub fn ambient(&self) -> f64 {
        match self {
            Self::Grid(g) => g.field.ambient(),
            #[cfg(feature = "mesh")]
            Self::ExactMesh(m) => m.ambient(),
            #[cfg(feature = "mesh")]
            Self::SmoothMesh { field, .. } => field.mesh().ambient(),
        }
    }

    /// The trace settings instruments use on this medium (unused by an
    /// exact mesh, traced in closed form).
    #[must_use]
    pub fn params(&self) -> TraceParams {
        match self {
            Self::Grid(g) => g.params,
            #[cfg(feature = "mesh")]
            Self::ExactMesh(_) => TraceParams::accurate(),
            #[cfg(feature = "mesh")]
            Self::SmoothMesh { params, .. } => *params,
        }
    }

    /// Replaces the trace settings (a grid's, or a smooth mesh's; an exact
    /// mesh has none to replace).
    pub fn set_params(&mut self, params: TraceParams) {
        match self {
            Self::Grid(g) => g.params = params,
            #[cfg(feature = "mesh")]
            Self::ExactMesh(_) => {}
            #[cfg(feature = "mesh")]
            Self::SmoothMesh { params: p, .. } => *p = params,
        }
    }

    /// The unstructured mesh, if this is one.
    #[cfg(feature = "mesh")]
    #[must_use]
    pub fn mesh(&self) -> Option<&UnstructuredField> {
        match self {
            Self::Grid(_) => None,
            Self::ExactMesh(m) => Some(m),
            Self::SmoothMesh { field, .. } => Some(field.mesh()),
        }
    }

    /// One ray's path from `origin` along `direction` with the medium's
    /// settings. On a grid, `skip` is the deflection (radians) that
    /// straight steps across smooth octree nodes may change along the
    /// whole ray (see [`trace_skipping`]; `None`: every step integrated);
    /// meshes ignore it. The result's stats count the steps.
    ///
    /// # Errors
    /// As [`trace`]: a bad ray, settings or tolerance.
    pub fn trace(
        &self,
        origin: DVec3,
        direction: DVec3,
        skip: Option<f64>,
    ) -> Result<TraceResult, TraceError> {
        match self {
            Self::Grid(g) => match skip {
                Some(tol) => trace_skipping(&g.field, &g.tree, origin, direction, &g.params, tol),
                None => trace(&g.field, origin, direction, &g.params),
            },
            #[cfg(feature = "mesh")]
            Self::ExactMesh(m) => m.trace(origin, direction),
            #[cfg(feature = "mesh")]
            Self::SmoothMesh { field, params } => field.trace(origin, direction, params),
        }
    }
}

/// Why samples could not become a medium.
#[derive(Debug)]
#[non_exhaustive]
pub enum MediumError {
    /// A density ≤ 0 or an index below 1, refused unless non-physical
    /// values are allowed (often: density read as index or the reverse).
    NonPhysical {
        /// What was found: `"a density ≤ 0 kg/m³"` or `"an index below 1"`.
        what: &'static str,
        /// The lowest value.
        lowest: f64,
        /// The mesh array it came from (`None`: a grid's samples, f32).
        array: Option<String>,
    },
    /// The Gladstone–Dale constant is not finite and positive.
    GladstoneDale(f64),
    /// The index samples make no grid (a NaN after mapping, a bad ambient).
    Grid(GridError),
    /// The grid is too small for its octree.
    Octree(OctreeError),
    /// The mesh is malformed.
    #[cfg(feature = "mesh")]
    Mesh(MeshError),
    /// The file could not be read (the error names it).
    #[cfg(feature = "io")]
    Read(crate::io::ReadError),
    /// The file was read, but its data make no medium.
    #[cfg(feature = "io")]
    InFile {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong with its data.
        source: alloc::boxed::Box<MediumError>,
    },
}

impl fmt::Display for MediumError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            // A grid's samples are f32: printed as such, shortest.
            Self::NonPhysical { what, lowest, array: None } => {
                write!(f, "the volume holds {what} (lowest sample {})", *lowest as f32)
            }
            Self::NonPhysical { what, lowest, array: Some(a) } => {
                write!(f, "the mesh holds {what} (lowest value {lowest} in array {a:?})")
            }
            Self::GladstoneDale(k) => {
                write!(f, "the Gladstone–Dale constant must be finite and > 0 (got {k})")
            }
            Self::Grid(e) => e.fmt(f),
            Self::Octree(e) => write!(f, "building the octree: {e}"),
            #[cfg(feature = "mesh")]
            Self::Mesh(e) => e.fmt(f),
            #[cfg(feature = "io")]
            Self::Read(e) => e.fmt(f),
            #[cfg(feature = "io")]
            Self::InFile { path, source } => write!(f, "{}: {source}", path.display()),
        }
    }
}

impl core::error::Error for MediumError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Grid(e) => Some(e),
            Self::Octree(e) => Some(e),
            #[cfg(feature = "mesh")]
            Self::Mesh(e) => Some(e),
            #[cfg(feature = "io")]
            Self::Read(e) => Some(e),
            _ => None,
        }
    }
}

impl From<GridError> for MediumError {
    fn from(e: GridError) -> Self {
        Self::Grid(e)
    }
}

impl From<OctreeError> for MediumError {
    fn from(e: OctreeError) -> Self {
        Self::Octree(e)
    }
}

#[cfg(feature = "mesh")]
impl From<MeshError> for MediumError {
    fn from(e: MeshError) -> Self {
        Self::Mesh(e)
    }
}
