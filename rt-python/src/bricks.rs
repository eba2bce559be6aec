//! Schlieren of a grid whose pieces are held by different ranks (as
//! ParaView hands a rank its extent): rt-photo's brick protocol
//! (`rt_photo::distributed`) over the caller's mpi4py communicator,
//! photons handed from brick to brick; rank 0 gets the image, bit for bit
//! the image of one process tracing the whole grid.

use numpy::{IntoPyArray, PyArray2, PyReadonlyArray3, ndarray::Array2};
use pyo3::prelude::*;
use rt_photo::{
    distributed::{Piece, VolumeJob, VolumeOptics, first_brick_box, rank_from},
    glam::DVec3,
    rt_volume::GridInfo,
};

use crate::{
    composite::PyComm,
    value_error,
    volume::{interp, samples},
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

/// This rank's part of a schlieren image (knife edge along the image's
/// vertical, or interferometry) of a grid split over `comm`'s ranks:
/// `piece` is `[z, y, x]` raw samples from sample `lo` (x, y, z) of the
/// whole `dims` grid; `first` is the whole grid's sample (0, 0, 0). Rank
/// 0 gets the image relative to the undisturbed background `[h, w]`,
/// the others `None`.
#[pyfunction]
#[pyo3(name = "_schlieren_piece")]
#[pyo3(signature = (piece, lo, dims, spacing, origin, first, quantity, k, interpolation, optics, wavelength, fringe_spacing, size, strata, seed, comm))]
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
        optics,
        size,
        strata,
        seed,
        batch: rt_photo::distributed::BATCH,
    };
    let c = PyComm::new(py, comm)?;
    let rank = c.rank_number();
    let result = py.detach(|| rank_from(&c, &job, &piece));
    let film = match result {
        Ok((film, _)) => film,
        Err(e) => {
            let why = c.cause().map_or(String::new(), |c| format!(" ({c})"));
            return Err(value_error(format!("rank {rank}: {e}{why}")));
        }
    };
    let Some(film) = film else { return Ok(None) };
    // Relative to the undisturbed background: a knife edge passes half.
    let background = if matches!(job.optics, VolumeOptics::Knife) { 0.5 } else { 1.0 };
    let (w, h) = (film.width(), film.height());
    let image: Vec<f64> = film.normalized_iter().map(|p| p[0] / background).collect();
    Ok(Some(Array2::from_shape_vec((h, w), image).map_err(value_error)?.into_pyarray(py)))
}
