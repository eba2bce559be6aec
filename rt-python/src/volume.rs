//! Volumes: a numpy array or a file, mapped to refractive index, with the
//! octree the optical bench skips uniform regions by.

use std::path::PathBuf;

use numpy::PyReadonlyArray3;
use pyo3::{exceptions::PyOSError, prelude::*};
use rt_cli::optics::{Interpolation, Quantity, Volume};
use rt_volume::{
    Grid,
    glam::DVec3,
    io::{ReadErrorKind, read_grid},
};

use crate::value_error;

/// A volume ready for the optical bench (the index field and its octree).
#[pyclass(name = "_Volume", module = "rtvis._rtvis", frozen)]
pub(crate) struct PyVolume {
    pub(crate) inner: Volume,
}

/// `quantity` and `interpolation` by name.
fn options(quantity: &str, interpolation: &str) -> PyResult<(Quantity, Interpolation)> {
    let q = match quantity {
        "density" => Quantity::Density,
        "index" => Quantity::Index,
        other => {
            return Err(value_error(format!(
                "quantity: unknown `{other}` (known: density, index)"
            )));
        }
    };
    let i = match interpolation {
        "linear" => Interpolation::Linear,
        "cubic" => Interpolation::Cubic,
        other => {
            return Err(value_error(format!(
                "interpolation: unknown `{other}` (known: linear, cubic)"
            )));
        }
    };
    Ok((q, i))
}

/// The volume of `grid`, built with the GIL released.
fn build(
    py: Python<'_>,
    grid: Grid,
    quantity: &str,
    k: f64,
    interpolation: &str,
    allow_nonphysical: bool,
) -> PyResult<PyVolume> {
    let (q, i) = options(quantity, interpolation)?;
    let inner = py.detach(|| Volume::new(grid, q, k, allow_nonphysical, i)).map_err(value_error)?;
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
    fn shape(&self) -> (usize, usize, usize) {
        let [nx, ny, nz] = self.inner.field.grid().dims();
        (nz, ny, nx)
    }

    /// Sample spacing `(dx, dy, dz)`.
    #[getter]
    fn spacing(&self) -> [f64; 3] {
        self.inner.field.grid().spacing().to_array()
    }

    /// Centre of sample `[0, 0, 0]`, `(x, y, z)`.
    #[getter]
    fn origin(&self) -> [f64; 3] {
        self.inner.field.grid().origin().to_array()
    }

    /// `((xmin, ymin, zmin), (xmax, ymax, zmax))`: the box the samples
    /// cover.
    #[getter]
    fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let b = self.inner.field.grid().bounds();
        (b.min.to_array(), b.max.to_array())
    }

    /// The refractive index samples, `[z, y, x]`.
    fn index<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, numpy::PyArray3<f32>>> {
        let (nz, ny, nx) = self.shape();
        let data = self.inner.field.grid().data().to_vec();
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
    options(quantity, interpolation)?;
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
