//! Schlieren, BOS and focusing schlieren of a grid whose pieces are held
//! by different ranks (as ParaView hands a rank its extent): rt-photo's brick protocol
//! (`rt_photo::distributed`) over the caller's mpi4py communicator,
//! photons handed from brick to brick; rank 0 gets the image, bit for bit
//! the image of one process tracing the whole grid.

use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2, PyReadonlyArray3, ndarray::Array2};
use pyo3::prelude::*;
use rt_photo::{
    distributed::{
        DistributedError, Piece, VolumeJob, VolumeOptics, Watch, bos_rank, first_brick_box,
        focusing_rank, rank_from,
    },
    glam::DVec3,
    rt_volume::GridInfo,
};

use crate::{
    composite::PyComm,
    optics::{BosOut, FocusingOut, bos_options, bos_out, focusing_options, focusing_out},
    value_error,
    volume::{interp, samples},
    watch::watched,
};

/// The whole grid's header from Python's `(nx, ny, nz)`, spacing, origin.
fn grid_info(dims: [usize; 3], spacing: [f64; 3], origin: [f64; 3]) -> GridInfo {
    GridInfo { dims, origin: DVec3::from(origin), spacing: DVec3::from(spacing) }
}

/// `(lo, hi)`, the samples (x, y, z indices, `hi` exclusive) rank `rank`
/// of `ranks` must hold: its brick and ghost layers.
#[pyfunction]
#[pyo3(name = "_brick_box")]
pub(crate) fn brick_box(
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    interpolation: &str,
    ranks: usize,
    rank: usize,
) -> PyResult<([usize; 3], [usize; 3])> {
    first_brick_box(grid_info(dims, spacing, origin), interp(interpolation)?, ranks, rank)
        .map_err(value_error)
}

/// This rank's piece as rt-photo holds it: `piece` is `[z, y, x]` raw
/// samples from sample `lo` (x, y, z) of the whole `dims` grid; `first`
/// is the whole grid's sample (0, 0, 0).
struct Held {
    piece: Piece,
    job: VolumeJob,
}

impl Held {
    #[allow(clippy::too_many_arguments)]
    fn new(
        piece: &PyReadonlyArray3<'_, f32>,
        lo: [usize; 3],
        dims: [usize; 3],
        spacing: [f64; 3],
        origin: [f64; 3],
        first: f32,
        quantity: &str,
        k: f64,
        interpolation: &str,
    ) -> PyResult<Self> {
        let view = piece.as_array();
        let (nz, ny, nx) = view.dim();
        let piece = Piece {
            info: grid_info(dims, spacing, origin),
            lo,
            dims: [nx, ny, nz],
            samples: view.iter().copied().collect(),
            first,
        };
        let job = VolumeJob {
            file: "a piece held in memory".into(),
            samples: samples(quantity, k)?,
            interp: interp(interpolation)?,
            optics: VolumeOptics::Knife,
            size: 1,
            strata: 1,
            seed: 1,
            batch: rt_photo::distributed::BATCH,
        };
        Ok(Self { piece, job })
    }
}

/// `run` on `comm`'s ranks, watched from this thread with the GIL
/// released (`progress(done, total)` on rank 0; Ctrl-C or the callback's
/// exception stops every rank); a failure as a `ValueError` naming the
/// rank (and a peer's cause, if one is known).
fn across<T: Send>(
    py: Python<'_>,
    comm: Py<PyAny>,
    progress: Option<Py<PyAny>>,
    run: impl FnOnce(&PyComm, Watch<'_>) -> Result<T, DistributedError> + Send,
) -> PyResult<T> {
    let c = PyComm::new(py, comm)?;
    let rank = c.rank_number();
    let out = watched(py, progress, |w| {
        let (stop, progress) = (|| w.stopped(), |d, t| w.progress(d, t));
        run(&c, Watch::new(&stop, &progress))
    })?;
    out.map_err(|e| {
        let why = c.cause().map_or(String::new(), |c| format!(" ({c})"));
        // An exchange's error names this rank already.
        let who = format!("rank {rank}: ");
        let e = e.to_string();
        let said = if e.starts_with(&who) { e } else { who + &e };
        value_error(format!("{said}{why}"))
    })
}

/// This rank's part of a schlieren image (knife edge along the image's
/// vertical, or interferometry) of a grid split over `comm`'s ranks
/// (the piece as [`Held`] takes it). Rank 0 gets the image relative to
/// the undisturbed background `[h, w]`, the others `None`.
#[pyfunction]
#[pyo3(name = "_schlieren_piece")]
#[pyo3(signature = (piece, lo, dims, spacing, origin, first, quantity, k, interpolation, optics, wavelength, fringe_spacing, size, strata, seed, comm, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn schlieren_piece<'py>(
    py: Python<'py>,
    piece: PyReadonlyArray3<'py, f32>,
    lo: [usize; 3],
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    first: f32,
    quantity: &str,
    k: f64,
    interpolation: &str,
    optics: &str,
    wavelength: f64,
    fringe_spacing: Option<f64>,
    size: u32,
    strata: u32,
    seed: u64,
    comm: Py<PyAny>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
    let optics = match optics {
        "knife" => VolumeOptics::Knife,
        "interferometry" => {
            VolumeOptics::Interferometry { lambda: wavelength, fringes: fringe_spacing }
        }
        other => {
            return Err(value_error(format!(
                "optics: unknown `{other}` (known across ranks: knife, interferometry)"
            )));
        }
    };
    let held = Held::new(&piece, lo, dims, spacing, origin, first, quantity, k, interpolation)?;
    let job = VolumeJob { optics, size, strata, seed, ..held.job };
    let (film, _) = across(py, comm, progress, |c, w| rank_from(c, &job, &held.piece, w))?;
    let Some(film) = film else { return Ok(None) };
    // Relative to the undisturbed background: a knife edge passes half.
    let background = if matches!(job.optics, VolumeOptics::Knife) { 0.5 } else { 1.0 };
    let (w, h) = (film.width(), film.height());
    let image: Vec<f64> = film.normalized_iter().map(|p| p[0] / background).collect();
    Ok(Some(Array2::from_shape_vec((h, w), image).map_err(value_error)?.into_pyarray(py)))
}

/// This rank's part of `rtvis.bos` of a grid split over `comm`'s ranks
/// (the piece as [`Held`] takes it; then `_bos`'s arguments after the
/// volume): the rig's
/// survey and every ray traced across the ranks. Rank 0 gets `_bos`'s
/// tuple, the others `None`.
#[pyfunction]
#[pyo3(name = "_bos_piece")]
#[pyo3(signature = (piece, lo, dims, spacing, origin, first, quantity, k, interpolation, axis_name, size, focal_length, f_number, pixel, distance, background_distance, dot, spacing_dots, samples, seed, background, image, image_pixel, comm, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn bos_piece<'py>(
    py: Python<'py>,
    piece: PyReadonlyArray3<'py, f32>,
    lo: [usize; 3],
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    first: f32,
    quantity: &str,
    k: f64,
    interpolation: &str,
    axis_name: &str,
    size: u32,
    focal_length: Option<f64>,
    f_number: f64,
    pixel: Option<f64>,
    distance: Option<f64>,
    background_distance: Option<f64>,
    dot: f64,
    spacing_dots: f64,
    samples: u32,
    seed: u64,
    background: &str,
    image: Option<PyReadonlyArray2<'py, f64>>,
    image_pixel: Option<f64>,
    comm: Py<PyAny>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Option<BosOut<'py>>> {
    let options = bos_options(
        axis_name,
        size,
        focal_length,
        f_number,
        pixel,
        distance,
        background_distance,
        dot,
        spacing_dots,
        samples,
        seed,
        background,
        image,
        image_pixel,
    )?;
    let held = Held::new(&piece, lo, dims, spacing, origin, first, quantity, k, interpolation)?;
    let (out, _) =
        across(py, comm, progress, |c, w| bos_rank(c, &held.job, &held.piece, &options, seed, w))?;
    out.map(|(setup, images)| bos_out(py, &setup, images)).transpose()
}

/// This rank's part of `rtvis.focusing` of a grid split over `comm`'s
/// ranks (the piece as [`Held`] takes it; then `_focusing`'s arguments after
/// the volume): the
/// rig's survey and every ray traced across the ranks. Rank 0 gets
/// `_focusing`'s tuple, the others `None`.
#[pyfunction]
#[pyo3(name = "_focusing_piece")]
#[pyo3(signature = (piece, lo, dims, spacing, origin, first, quantity, k, interpolation, axis_name, size, focal_length, aperture, pixel, distance, focus, source_distance, pitch, duty, angle, offset, bands, samples, seed, comm, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn focusing_piece<'py>(
    py: Python<'py>,
    piece: PyReadonlyArray3<'py, f32>,
    lo: [usize; 3],
    dims: [usize; 3],
    spacing: [f64; 3],
    origin: [f64; 3],
    first: f32,
    quantity: &str,
    k: f64,
    interpolation: &str,
    axis_name: &str,
    size: u32,
    focal_length: Option<f64>,
    aperture: Option<f64>,
    pixel: Option<f64>,
    distance: Option<f64>,
    focus: f64,
    source_distance: Option<f64>,
    pitch: Option<f64>,
    duty: f64,
    angle: f64,
    offset: f64,
    bands: Option<u32>,
    samples: u32,
    seed: u64,
    comm: Py<PyAny>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Option<FocusingOut<'py>>> {
    let options = focusing_options(
        axis_name,
        size,
        focal_length,
        aperture,
        pixel,
        distance,
        focus,
        source_distance,
        pitch,
        duty,
        angle,
        offset,
        bands,
        samples,
    )?;
    let held = Held::new(&piece, lo, dims, spacing, origin, first, quantity, k, interpolation)?;
    let (out, _) = across(py, comm, progress, |c, w| {
        focusing_rank(c, &held.job, &held.piece, &options, seed, w)
    })?;
    out.map(|(setup, images)| focusing_out(py, &setup, images, angle)).transpose()
}
