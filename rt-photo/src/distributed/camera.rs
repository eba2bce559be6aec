//! Background-oriented and focusing schlieren across ranks: the camera's
//! rays, and those of the survey that chooses the rig, traced through
//! the bricks like the schlieren bench's photons. Every rank takes the
//! same survey (rank 0's, shared), so every rank chooses the same rig and
//! asks for the same rays; rank 0 renders the images from their results.
//! They equal [`bos_single`] and [`focusing_single`], one process tracing
//! the whole grid, bit for bit.
//!
//! Of a [`VolumeJob`], these read the samples' meaning, the interpolant
//! and the batch; the camera's size, sampling and seed are the options'.

use alloc::vec::Vec;
use std::time::Instant;

use rt_composite::Communicator;
use rt_volume::{Bounds, GridField, TraceParams, trace};

use super::{
    BrickSource, DistributedError, MAX_PHOTONS, VolumeJob, VolumeRank, Watch,
    across::{Across, Tracer, missing},
    wire::Words,
};
use crate::{
    BenchError, BosError, BosImages, BosOptions, BosSetup, FocusingError, FocusingImages,
    FocusingOptions, FocusingSetup, SchlierenBench, SetupError, Survey,
};

/// What a rank returns: rank 0 the set-up chosen and its images.
pub type CameraRank<S, I> = (Option<(S, I)>, VolumeRank);

/// BOS of the grid `source` holds (this rank's part of it) with the rig
/// [`BosSetup::choose`] would choose, every ray traced across the ranks,
/// watched by `watch` (progress in camera rays).
///
/// # Errors
/// A bad option, any rank's failure; [`DistributedError::Stopped`] once
/// `watch` says to stop.
pub fn bos_rank<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
    source: &dyn BrickSource,
    options: &BosOptions,
    seed: u64,
    watch: Watch<'_>,
) -> Result<CameraRank<BosSetup, BosImages>, DistributedError> {
    on_ranks(comm, job, source, watch, bos_choose(options), bos_render(seed))
}

/// [`bos_rank`] in one process holding the whole grid.
///
/// # Errors
/// As [`bos_rank`].
pub fn bos_single(
    job: &VolumeJob,
    source: &dyn BrickSource,
    options: &BosOptions,
    seed: u64,
) -> Result<(BosSetup, BosImages), DistributedError> {
    whole(job, source, bos_choose(options), bos_render(seed))
}

/// Focusing schlieren of the grid `source` holds (this rank's part of
/// it) with the rig [`FocusingSetup::choose`] would choose, every ray
/// traced across the ranks, watched by `watch` (progress in camera rays).
///
/// # Errors
/// As [`bos_rank`].
pub fn focusing_rank<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
    source: &dyn BrickSource,
    options: &FocusingOptions,
    seed: u64,
    watch: Watch<'_>,
) -> Result<CameraRank<FocusingSetup, FocusingImages>, DistributedError> {
    on_ranks(comm, job, source, watch, focusing_choose(options), focusing_render(seed))
}

/// [`focusing_rank`] in one process holding the whole grid.
///
/// # Errors
/// As [`focusing_rank`].
pub fn focusing_single(
    job: &VolumeJob,
    source: &dyn BrickSource,
    options: &FocusingOptions,
    seed: u64,
) -> Result<(FocusingSetup, FocusingImages), DistributedError> {
    whole(job, source, focusing_choose(options), focusing_render(seed))
}

/// A survey as the set-ups ask for one.
type SurveyFn<'a> = dyn FnMut(&SchlierenBench) -> Result<Survey, DistributedError> + 'a;

fn bos_choose(
    o: &BosOptions,
) -> impl FnOnce(Bounds, TraceParams, &mut SurveyFn<'_>) -> Result<BosSetup, DistributedError> + '_
{
    move |b, p, survey| BosSetup::choose_with(b, p, o, survey)
}

fn bos_render(seed: u64) -> impl Fn(&BosSetup, &Tracer<'_>) -> Result<BosImages, DistributedError> {
    move |s, t| {
        let c = &s.bos.camera;
        at_most((c.width * c.height) as u64, s.bos.aperture_samples)?;
        s.bos.render_with(&t, seed).map_err(|e| match e {
            BosError::Trace(e) => missing(e),
            e => SetupError::Bos(e).into(),
        })
    }
}

fn focusing_choose(
    o: &FocusingOptions,
) -> impl FnOnce(Bounds, TraceParams, &mut SurveyFn<'_>) -> Result<FocusingSetup, DistributedError> + '_
{
    move |b, p, survey| FocusingSetup::choose_with(b, p, o, survey)
}

fn focusing_render(
    seed: u64,
) -> impl Fn(&FocusingSetup, &Tracer<'_>) -> Result<FocusingImages, DistributedError> {
    move |s, t| {
        let c = &s.system.camera;
        at_most((c.width * c.height) as u64, s.system.aperture_samples)?;
        s.system.render_with(&t, seed).map_err(|e| match e {
            FocusingError::Trace(e) => missing(e),
            e => SetupError::Focusing(e).into(),
        })
    }
}

/// `Ok` if `pixels` with `k²` rays each are at most [`MAX_PHOTONS`].
fn at_most(pixels: u64, k: u32) -> Result<(), DistributedError> {
    let photons = pixels.saturating_mul(u64::from(k).pow(2));
    if photons > MAX_PHOTONS {
        return Err(DistributedError::TooManyPhotons { photons, max: MAX_PHOTONS });
    }
    Ok(())
}

/// The set-up `choose` makes (its survey across the ranks) and, on rank
/// 0, the images `render` makes of it.
fn on_ranks<C: Communicator, S, I>(
    comm: &C,
    job: &VolumeJob,
    source: &dyn BrickSource,
    watch: Watch<'_>,
    choose: impl FnOnce(Bounds, TraceParams, &mut SurveyFn<'_>) -> Result<S, DistributedError>,
    render: impl Fn(&S, &Tracer<'_>) -> Result<I, DistributedError>,
) -> Result<CameraRank<S, I>, DistributedError> {
    let mut across = Across::new(comm, job, source, watch)?;
    let (bounds, params) = (across.info.bounds(), across.params);
    let setup = choose(bounds, params, &mut |probe| survey_across(&mut across, probe))?;
    let Some(traced) = across.trace(|t| render(&setup, t).map(drop), true)? else {
        return Ok((None, across.report));
    };
    let t = Instant::now();
    let images = render(&setup, &|o, d| traced.get(o, d))?;
    across.report.seconds[2] = t.elapsed().as_secs_f64();
    Ok((Some((setup, images)), across.report))
}

/// The survey through `probe`, its photons traced across the ranks;
/// rank 0's, on every rank.
fn survey_across<C: Communicator>(
    across: &mut Across<'_, C>,
    probe: &SchlierenBench,
) -> Result<Survey, DistributedError> {
    let width = Survey::WIDTH;
    let traced = across.trace(|t| Ok(Survey::of_with(probe, width, &t).map(drop)?), false)?;
    let mut bytes = Vec::new();
    if let Some(traced) = traced {
        let survey =
            Survey::of_with(probe, width, &|o, d| traced.get(o, d)).map_err(|e| match e {
                SetupError::SchlierenBench(BenchError::Trace(e)) => missing(e),
                e => e.into(),
            })?;
        for e in &survey.eps {
            let (flag, (a, b)) = e.map_or((0u64, (0.0, 0.0)), |e| (1, e));
            for w in [flag, a.to_bits(), b.to_bits()] {
                bytes.extend(w.to_le_bytes());
            }
        }
        for w in [survey.pixel.0.to_bits(), survey.pixel.1.to_bits()] {
            bytes.extend(w.to_le_bytes());
        }
    }
    let shared = across.share(&bytes)?;
    let bad = DistributedError::Malformed { from: 0 };
    if shared.len() < 16 || (shared.len() - 16) % 24 != 0 {
        return Err(bad);
    }
    let mut w = Words(&shared);
    let mut eps = Vec::with_capacity((shared.len() - 16) / 24);
    for _ in 0..(shared.len() - 16) / 24 {
        let (Some(flag), Some(a), Some(b)) = (w.u64(), w.u64(), w.u64()) else {
            return Err(bad);
        };
        eps.push((flag == 1).then(|| (f64::from_bits(a), f64::from_bits(b))));
    }
    let (Some(du), Some(dv)) = (w.u64(), w.u64()) else {
        return Err(bad);
    };
    Ok(Survey { eps, width, pixel: (f64::from_bits(du), f64::from_bits(dv)) })
}

/// [`on_ranks`] in one process holding the whole grid.
fn whole<S, I>(
    job: &VolumeJob,
    source: &dyn BrickSource,
    choose: impl FnOnce(Bounds, TraceParams, &mut SurveyFn<'_>) -> Result<S, DistributedError>,
    render: impl Fn(&S, &Tracer<'_>) -> Result<I, DistributedError>,
) -> Result<(S, I), DistributedError> {
    let (info, ambient) = job.header(source)?;
    let field = GridField::new(job.read_box(source, [0; 3], info.dims)?, job.interp, ambient)?;
    let params = VolumeJob::params(&info);
    let tracer = |o, d| trace(&field, o, d, &params);
    let setup = choose(info.bounds(), params, &mut |probe| {
        Ok(Survey::of_with(probe, Survey::WIDTH, &tracer)?)
    })?;
    let images = render(&setup, &tracer)?;
    Ok((setup, images))
}
