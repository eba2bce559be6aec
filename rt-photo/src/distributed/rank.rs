//! What one rank does for a schlieren or interferometry image: trace
//! the photons that enter its brick, hand the others on; rank 0 lands
//! every result on the film.

use rt_composite::Communicator;
use rt_volume::{Bricks, GridInfo, step_reach};

use super::{
    BrickSource, DistributedError, VolumeJob, VolumeOptics, VolumeRank, Watch,
    across::{Across, FIRST_GRADIENT, FIRST_N, missing},
    job::knife_range,
};
use crate::{BenchError, Film, Filter};
use std::time::Instant;

/// The samples `rank` of `ranks` reads first (its brick and the ghost
/// layers a step reaches in a medium within the first bounds), as
/// `(lo, hi)` sample indices: the box a caller handing each rank its own
/// [`super::Piece`] gives it (larger is fine).
///
/// # Errors
/// A bad grid header, a grid that does not split for `ranks`.
pub fn first_brick_box(
    info: GridInfo,
    interp: rt_volume::Interp,
    ranks: usize,
    rank: usize,
) -> Result<([usize; 3], [usize; 3]), DistributedError> {
    let bricks = Bricks::for_ranks(info, ranks)?;
    let reach = step_reach(&VolumeJob::params(&info), FIRST_N, FIRST_GRADIENT)?;
    Ok(bricks.samples_needed(rank, reach, interp)?)
}

/// What one rank does: trace its photons, hand the others on; rank 0
/// returns the film, bit for bit the film of [`super::single`].
///
/// # Errors
/// Any rank's failure (every rank learns of it within the timeout).
pub fn rank<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
) -> Result<(Option<Film>, VolumeRank), DistributedError> {
    rank_from(comm, job, job, Watch::NONE)
}

/// [`rank`] with this rank's samples from `source` (each rank its own:
/// a [`super::Piece`] covering [`first_brick_box`]), watched by `watch`
/// (progress in photons).
///
/// # Errors
/// As [`rank`]; a piece that lacks samples a step reaches;
/// [`DistributedError::Stopped`] once `watch` says to stop.
pub fn rank_from<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
    source: &dyn BrickSource,
    watch: Watch<'_>,
) -> Result<(Option<Film>, VolumeRank), DistributedError> {
    let mut across = Across::new(comm, job, source, watch)?;
    let (info, ambient) = (across.info, across.ambient);
    let bench = job.bench(&info, ambient, 1.0);
    let film = job.film(&bench)?;
    let traced = across.trace(
        |t| {
            let mut scratch = Film::new(film.width(), film.height(), Filter::Tent)?;
            Ok(bench.render_with(&t, &mut scratch, 0, job.seed)?)
        },
        true,
    )?;
    let Some(traced) = traced else {
        return Ok((None, across.report));
    };
    let t = Instant::now();
    let bench = if job.optics == VolumeOptics::Knife {
        let results: alloc::vec::Vec<_> = traced.results().copied().collect();
        job.bench(&info, ambient, knife_range(&bench, &results))
    } else {
        bench
    };
    let mut film = job.film(&bench)?;
    bench.render_with(&|o, d| traced.get(o, d), &mut film, 0, job.seed).map_err(|e| match e {
        BenchError::Trace(e) => missing(e),
        e => e.into(),
    })?;
    across.report.seconds[2] = t.elapsed().as_secs_f64();
    Ok((Some(film), across.report))
}
