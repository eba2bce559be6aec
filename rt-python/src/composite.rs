//! Sort-last compositing of premultiplied RGBA + depth images: in one
//! process (a list of images), or across the ranks of an MPI communicator
//! from `mpi4py`, through rt-composite's schedules.

use std::sync::Mutex;

use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3,
    ndarray::{Array2, Array3},
};
use pyo3::{exceptions::PyTimeoutError, prelude::*, types::PyBytes};
use rt_composite::{CommError, Communicator, Operator, Schedule, serial_fold};
use rt_core::Pixel;

use crate::value_error;

/// `(rgba [h, w, 4], depth [h, w])`.
type Image<'py> = (Bound<'py, PyArray3<f32>>, Bound<'py, PyArray2<f32>>);

/// One image's pixels from its RGBA and depth arrays, checked: shapes
/// `[h, w, 4]` and `[h, w]`, colours finite, depths not NaN.
fn pixels(
    i: usize,
    rgba: &PyReadonlyArray3<'_, f32>,
    depth: &PyReadonlyArray2<'_, f32>,
) -> PyResult<(usize, usize, Vec<Pixel>)> {
    let (c, d) = (rgba.as_array(), depth.as_array());
    let (h, w, k) = c.dim();
    if k != 4 || d.dim() != (h, w) {
        return Err(value_error(format!(
            "image {i}: rgba must be (h, w, 4) and depth (h, w); got {:?} and {:?}",
            c.shape(),
            d.shape()
        )));
    }
    if h == 0 || w == 0 {
        return Err(value_error(format!("image {i} is empty ({w}×{h})")));
    }
    let mut out = Vec::with_capacity(h * w);
    for ((y, x), &z) in d.indexed_iter() {
        let color = [c[[y, x, 0]], c[[y, x, 1]], c[[y, x, 2]], c[[y, x, 3]]];
        if z.is_nan() || !color.iter().all(|v| v.is_finite()) {
            return Err(value_error(format!(
                "image {i}: pixel (row {y}, column {x}) has a NaN depth or a non-finite colour"
            )));
        }
        out.push(Pixel { color, depth: z });
    }
    Ok((w, h, out))
}

/// The arrays of `pixels` (`w × h`).
fn arrays<'py>(py: Python<'py>, w: usize, h: usize, pixels: &[Pixel]) -> PyResult<Image<'py>> {
    let rgba: Vec<f32> = pixels.iter().flat_map(|p| p.color).collect();
    let depth: Vec<f32> = pixels.iter().map(|p| p.depth).collect();
    Ok((
        Array3::from_shape_vec((h, w, 4), rgba).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((h, w), depth).map_err(value_error)?.into_pyarray(py),
    ))
}

/// Depth-composites the images: per pixel the nearest fragment, ties to
/// the earlier image.
#[pyfunction]
#[pyo3(name = "_composite")]
pub(crate) fn composite<'py>(
    py: Python<'py>,
    rgba: Vec<PyReadonlyArray3<'py, f32>>,
    depth: Vec<PyReadonlyArray2<'py, f32>>,
) -> PyResult<Image<'py>> {
    if rgba.is_empty() || rgba.len() != depth.len() {
        return Err(value_error(format!(
            "expected as many depth images as colour images, at least one (got {} and {})",
            rgba.len(),
            depth.len()
        )));
    }
    let mut images = Vec::with_capacity(rgba.len());
    let mut size = None;
    for (i, (c, d)) in rgba.iter().zip(&depth).enumerate() {
        let (w, h, px) = pixels(i, c, d)?;
        if *size.get_or_insert((w, h)) != (w, h) {
            return Err(value_error(format!(
                "image {i} is {w}×{h}, image 0 is {}×{}",
                size.map_or(0, |s| s.0),
                size.map_or(0, |s| s.1)
            )));
        }
        images.push(px);
    }
    let (w, h) = size.unwrap_or((0, 0));
    let refs: Vec<&[Pixel]> = images.iter().map(Vec::as_slice).collect();
    let out = py.detach(|| serial_fold(&refs, &Operator::Depth)).map_err(value_error)?;
    arrays(py, w, h, &out)
}

/// A communicator whose messages go through a Python object with methods
/// `rank()`, `size()`, `send(to, tag, data: bytes)` and `recv(source,
/// tag) -> bytes` (rtvis wraps an `mpi4py` communicator so): the
/// compositing schedule runs in Rust, the transport is the caller's MPI.
pub(crate) struct PyComm {
    obj: Py<PyAny>,
    rank: usize,
    size: usize,
    /// The first Python exception a call raised, for the error message.
    error: Mutex<Option<String>>,
}

impl PyComm {
    /// The communicator `obj` (an rtvis wrapper of an mpi4py one).
    pub(crate) fn new(py: Python<'_>, obj: Py<PyAny>) -> PyResult<Self> {
        let rank: usize = obj.call_method0(py, "rank")?.extract(py)?;
        let size: usize = obj.call_method0(py, "size")?.extract(py)?;
        Ok(Self { obj, rank, size, error: Mutex::new(None) })
    }

    /// This rank's number.
    pub(crate) fn rank_number(&self) -> usize {
        self.rank
    }

    /// The first Python exception a call raised, if any.
    pub(crate) fn cause(&self) -> Option<String> {
        self.error.lock().ok().and_then(|g| g.clone())
    }

    /// Remembers `e` (the first one) and maps it to a [`CommError`].
    fn fail(&self, py: Python<'_>, e: &PyErr, timeout: CommError) -> CommError {
        if let Ok(mut first) = self.error.lock() {
            first.get_or_insert_with(|| e.to_string());
        }
        if e.is_instance_of::<PyTimeoutError>(py) {
            timeout
        } else {
            CommError::Transport { code: -1 }
        }
    }
}

impl Communicator for PyComm {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.size
    }

    fn send(&self, to: usize, tag: u32, data: Vec<u8>) -> Result<(), CommError> {
        if to >= self.size {
            return Err(CommError::NoSuchRank(to));
        }
        Python::attach(|py| {
            let bytes = PyBytes::new(py, &data);
            self.obj
                .call_method1(py, "send", (to, tag, bytes))
                .map(|_| ())
                .map_err(|e| self.fail(py, &e, CommError::Disconnected(to)))
        })
    }

    fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError> {
        if from >= self.size {
            return Err(CommError::NoSuchRank(from));
        }
        Python::attach(|py| {
            let timeout = CommError::Timeout { from, tag };
            let got = self
                .obj
                .call_method1(py, "recv", (from, tag))
                .map_err(|e| self.fail(py, &e, timeout))?;
            let bytes = got.bind(py).cast::<PyBytes>().map_err(|e| {
                let e: PyErr = e.into();
                self.fail(py, &e, CommError::Transport { code: -1 })
            })?;
            Ok(bytes.as_bytes().to_vec())
        })
    }
}

/// Depth-composites this rank's image with every other rank's of `comm`
/// (see [`PyComm`]): rank 0 gets the image, the others `None`.
#[pyfunction]
#[pyo3(name = "_composite_comm")]
#[pyo3(signature = (rgba, depth, comm, schedule, radix))]
pub(crate) fn composite_comm<'py>(
    py: Python<'py>,
    rgba: PyReadonlyArray3<'py, f32>,
    depth: PyReadonlyArray2<'py, f32>,
    comm: Py<PyAny>,
    schedule: &str,
    radix: usize,
) -> PyResult<Option<Image<'py>>> {
    let schedule = match schedule {
        "direct-send" => Schedule::DirectSend,
        "binary-swap" => Schedule::BinarySwap,
        "radix-k" => Schedule::RadixK(radix),
        other => {
            return Err(value_error(format!(
                "schedule: unknown `{other}` (known: binary-swap, radix-k, direct-send)"
            )));
        }
    };
    let (w, h, px) = pixels(0, &rgba, &depth)?;
    let rank: usize = comm.call_method0(py, "rank")?.extract(py)?;
    let size: usize = comm.call_method0(py, "size")?.extract(py)?;
    let c = PyComm { obj: comm, rank, size, error: Mutex::new(None) };
    let (w32, h32) = (w as u32, h as u32);
    let result =
        py.detach(|| rt_composite::composite(&c, &px, w32, h32, schedule, &Operator::Depth));
    match result {
        Ok((Some(out), _)) => Ok(Some(arrays(py, w, h, &out)?)),
        Ok((None, _)) => Ok(None),
        Err(e) => {
            let cause = c.error.lock().ok().and_then(|g| g.clone());
            Err(value_error(match cause {
                Some(c) => format!("compositing failed on rank {rank}: {e} ({c})"),
                None => format!("compositing failed on rank {rank}: {e}"),
            }))
        }
    }
}
