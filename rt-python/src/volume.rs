//! Volumes: a numpy array or a file, mapped to refractive index, with the
//! octree the optical bench skips uniform regions by.

use std::path::PathBuf;

use numpy::PyReadonlyArray3;
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::{exceptions::PyOSError, prelude::*};
use rt_volume::{
    Cell, Grid, GridField, Interp, Medium, MediumError, MeshTrace, Samples,
    glam::DVec3,
    io::{ReadErrorKind, UnstructuredData, read_grid, read_unstructured},
};

use crate::value_error;

/// A volume ready for the optical bench: a grid (the index field and its
/// octree) or an unstructured mesh.
#[pyclass(name = "_Volume", module = "rtvis._rtvis", frozen)]
pub(crate) struct PyVolume {
    pub(crate) inner: Medium,
}

impl PyVolume {
    /// The gridded field, or a `ValueError` for a mesh.
    fn grid(&self) -> PyResult<&GridField> {
        match &self.inner {
            Medium::Grid(g) => Ok(g.field()),
            _ => Err(value_error("an unstructured mesh has no grid")),
        }
    }
}

/// What `quantity` (with constant `k`) names.
pub(crate) fn samples(quantity: &str, k: f64) -> PyResult<Samples> {
    match quantity {
        "density" => Ok(Samples::Density { gladstone_dale: k }),
        "index" => Ok(Samples::Index),
        other => Err(value_error(format!("quantity: unknown `{other}` (known: density, index)"))),
    }
}

/// The interpolant `interpolation` names.
pub(crate) fn interp(interpolation: &str) -> PyResult<Interp> {
    match interpolation {
        "linear" => Ok(Interp::Trilinear),
        "cubic" => Ok(Interp::CatmullRom),
        other => {
            Err(value_error(format!("interpolation: unknown `{other}` (known: linear, cubic)")))
        }
    }
}

/// A `ValueError` for samples that make no medium, with the keywords that
/// fix a non-physical one.
fn medium_error(e: MediumError) -> PyErr {
    match e {
        MediumError::NonPhysical { .. } => {
            value_error(format!("{e}; check quantity=, or pass allow_nonphysical=True"))
        }
        e => value_error(e),
    }
}

/// The medium of `grid`'s samples, built with the GIL released.
fn build(
    py: Python<'_>,
    grid: Grid,
    quantity: &str,
    k: f64,
    interpolation: &str,
    allow_nonphysical: bool,
) -> PyResult<PyVolume> {
    let (s, i) = (samples(quantity, k)?, interp(interpolation)?);
    let inner =
        py.detach(|| Medium::from_grid(grid, s, allow_nonphysical, i)).map_err(medium_error)?;
    Ok(PyVolume { inner })
}

#[pymethods]
impl PyVolume {
    #[new]
    #[pyo3(signature = (values, spacing, origin, quantity, k, interpolation, allow_nonphysical))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        values: PyReadonlyArray3<'_, f32>,
        spacing: [f64; 3],
        origin: [f64; 3],
        quantity: &str,
        k: f64,
        interpolation: &str,
        allow_nonphysical: bool,
    ) -> PyResult<Self> {
        let view = values.as_array();
        let (nz, ny, nx) = view.dim();
        // Logical (C) order whatever the strides: x fastest, as Grid wants.
        let data: Vec<f32> = view.iter().copied().collect();
        let grid = Grid::new([nx, ny, nz], DVec3::from(origin), DVec3::from(spacing), data)
            .map_err(|e| value_error(format!("values: {e}")))?;
        build(py, grid, quantity, k, interpolation, allow_nonphysical)
    }

    /// Samples per axis, `(nz, ny, nx)` as the array's shape.
    #[getter]
    fn shape(&self) -> PyResult<(usize, usize, usize)> {
        let [nx, ny, nz] = self.grid()?.grid().dims();
        Ok((nz, ny, nx))
    }

    /// Sample spacing `(dx, dy, dz)`.
    #[getter]
    fn spacing(&self) -> PyResult<[f64; 3]> {
        Ok(self.grid()?.grid().spacing().to_array())
    }

    /// Centre of sample `[0, 0, 0]`, `(x, y, z)`.
    #[getter]
    fn origin(&self) -> PyResult<[f64; 3]> {
        Ok(self.grid()?.grid().origin().to_array())
    }

    /// `((xmin, ymin, zmin), (xmax, ymax, zmax))`: the box the samples
    /// cover.
    #[getter]
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let b = self.inner.bounds();
        (b.min.to_array(), b.max.to_array())
    }

    /// For a mesh: `(points, cells, tetrahedra, boundary faces)`.
    #[getter]
    fn mesh_counts(&self) -> PyResult<(usize, usize, usize, usize)> {
        match self.inner.mesh() {
            Some(f) => {
                Ok((f.points().len(), f.cell_count(), f.tetrahedra().len(), f.boundary_faces()))
            }
            None => Err(value_error("a grid is not an unstructured mesh")),
        }
    }

    /// A mesh from points `(n, 3)`, the cells of each kind (`(m, 4)`
    /// tetrahedra, `(m, 5)` pyramids, `(m, 6)` wedges, `(m, 8)`
    /// hexahedra, VTK point order) and one value per point.
    #[staticmethod]
    #[pyo3(signature = (points, tetra, pyramid, wedge, hexahedron, values, quantity, k, trace, allow_nonphysical))]
    #[allow(clippy::too_many_arguments)]
    fn mesh(
        py: Python<'_>,
        points: PyReadonlyArray2<'_, f64>,
        tetra: PyReadonlyArray2<'_, i64>,
        pyramid: PyReadonlyArray2<'_, i64>,
        wedge: PyReadonlyArray2<'_, i64>,
        hexahedron: PyReadonlyArray2<'_, i64>,
        values: PyReadonlyArray1<'_, f64>,
        quantity: &str,
        k: f64,
        trace: &str,
        allow_nonphysical: bool,
    ) -> PyResult<Self> {
        let p = points.as_array();
        if p.ncols() != 3 {
            return Err(value_error(format!("points: expected shape (n, 3), got {:?}", p.dim())));
        }
        let points: Vec<DVec3> =
            p.rows().into_iter().map(|r| DVec3::new(r[0], r[1], r[2])).collect();
        let mut cells = Vec::new();
        for (name, arr, width) in [
            ("tetra", &tetra, 4),
            ("pyramid", &pyramid, 5),
            ("wedge", &wedge, 6),
            ("hexahedron", &hexahedron, 8),
        ] {
            let a = arr.as_array();
            if a.nrows() > 0 && a.ncols() != width {
                return Err(value_error(format!(
                    "{name}: expected shape (m, {width}), got {:?}",
                    a.dim()
                )));
            }
            for (row, r) in a.rows().into_iter().enumerate() {
                let mut ids = [0u32; 8];
                for (slot, &v) in ids.iter_mut().zip(r.iter()) {
                    *slot = u32::try_from(v).map_err(|_| {
                        value_error(format!("{name}[{row}]: point index {v} out of range"))
                    })?;
                }
                cells.push(match width {
                    4 => Cell::Tetra([ids[0], ids[1], ids[2], ids[3]]),
                    5 => Cell::Pyramid([ids[0], ids[1], ids[2], ids[3], ids[4]]),
                    6 => Cell::Wedge([ids[0], ids[1], ids[2], ids[3], ids[4], ids[5]]),
                    _ => Cell::Hexahedron(ids),
                });
            }
        }
        let data = UnstructuredData {
            points,
            cells,
            values: values.as_array().to_vec(),
            array: "values".into(),
            from_cells: false,
            skipped_cells: 0,
        };
        build_mesh(py, data, quantity, k, trace, allow_nonphysical)
    }

    /// The refractive index samples, `[z, y, x]`.
    fn index<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
        let (nz, ny, nx) = self.shape()?;
        let data = self.grid()?.grid().data().to_vec();
        let a = numpy::ndarray::Array3::from_shape_vec((nz, ny, nx), data).map_err(value_error)?;
        Ok(numpy::IntoPyArray::into_pyarray(a, py))
    }
}

/// Reads a volume file (NRRD, raw + JSON sidecar, VTK image data).
#[pyfunction]
#[pyo3(name = "_read_volume")]
#[pyo3(signature = (path, quantity, k, interpolation, allow_nonphysical))]
pub(crate) fn read_volume(
    py: Python<'_>,
    path: PathBuf,
    quantity: &str,
    k: f64,
    interpolation: &str,
    allow_nonphysical: bool,
) -> PyResult<PyVolume> {
    samples(quantity, k)?;
    interp(interpolation)?;
    let grid = py.detach(|| read_grid(&path)).map_err(|e| {
        // The error names the file.
        let msg = e.to_string();
        match e.kind() {
            ReadErrorKind::Io(_) => PyOSError::new_err(msg),
            _ => value_error(msg),
        }
    })?;
    build(py, grid, quantity, k, interpolation, allow_nonphysical)
}

/// The mesh of `data`, built with the GIL released.
fn build_mesh(
    py: Python<'_>,
    data: UnstructuredData,
    quantity: &str,
    k: f64,
    trace: &str,
    allow_nonphysical: bool,
) -> PyResult<PyVolume> {
    let s = samples(quantity, k)?;
    let how = match trace {
        "exact" => MeshTrace::Exact,
        "smooth" => MeshTrace::Smooth,
        other => {
            return Err(value_error(format!("trace: unknown `{other}` (known: exact, smooth)")));
        }
    };
    if data.values.len() != data.points.len() {
        return Err(value_error(format!(
            "values: {} for {} points (one per point needed)",
            data.values.len(),
            data.points.len()
        )));
    }
    let inner = py
        .detach(|| {
            let (points, values) = (data.points, data.values);
            Medium::from_mesh(points, &data.cells, values, s, allow_nonphysical, &data.array, how)
        })
        .map_err(medium_error)?;
    Ok(PyVolume { inner })
}

/// Reads an unstructured mesh file (VTK `.vtu`, legacy `.vtk`).
#[pyfunction]
#[pyo3(name = "_read_mesh")]
#[pyo3(signature = (path, array, quantity, k, trace, allow_nonphysical))]
pub(crate) fn read_mesh(
    py: Python<'_>,
    path: PathBuf,
    array: Option<String>,
    quantity: &str,
    k: f64,
    trace: &str,
    allow_nonphysical: bool,
) -> PyResult<PyVolume> {
    let data = py.detach(|| read_unstructured(&path, array.as_deref())).map_err(|e| {
        let msg = e.to_string();
        match e.kind() {
            ReadErrorKind::Io(_) => PyOSError::new_err(msg),
            _ => value_error(msg),
        }
    })?;
    build_mesh(py, data, quantity, k, trace, allow_nonphysical)
}
