//! What one rank does: read its brick, trace the photons that enter it,
//! hand the others on in rounds; rank 0 lands every result on the film.

use alloc::{format, vec, vec::Vec};
use std::time::Instant;

use glam::DVec3;
use rayon::prelude::*;
use rt_composite::{
    Communicator,
    exchange::{Batch, ExchangeError, all_gather, rounds},
};
use rt_volume::{
    Begin, BrickField, Bricks, GridInfo, Leg, PathState, TraceError, TraceParams, TraceResult,
    step_reach, trace_begin, trace_leg,
};

use super::{
    BrickSource, DistributedError, VolumeJob, VolumeOptics, VolumeRank,
    job::{emissions, knife_range},
    wire::{Key, Words, key, put_count, put_photon, put_result, unkey},
};
use crate::Film;

/// `e` as this rank's error: a step's own, or the exchange's.
fn exchange_error<E: Into<DistributedError> + core::fmt::Display>(
    me: usize,
    e: ExchangeError<E>,
) -> DistributedError {
    match e {
        ExchangeError::Step(e) => e.into(),
        e => DistributedError::Exchange { rank: me, message: format!("{e}") },
    }
}

/// Reads this rank's brick with enough ghost layers for every step: first
/// with a reach for `n ≤ 2` and a gentle gradient, then, once every
/// rank's largest index and gradient are known, again if that was short.
fn load_brick<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
    source: &dyn BrickSource,
    bricks: &Bricks,
    ambient: f64,
    params: &TraceParams,
) -> Result<BrickField, DistributedError> {
    let me = comm.rank();
    let mut reach = step_reach(params, FIRST_N, FIRST_GRADIENT)?;
    loop {
        let (lo, hi) = bricks.samples_needed(me, reach, job.interp)?;
        let samples = job.read_box(source, lo, hi)?;
        let b = samples.index_bounds(job.interp);
        let mine: Vec<u8> = [b.n_max, b.grad_max].iter().flat_map(|v| v.to_le_bytes()).collect();
        let (all, _) = all_gather(comm, &mine).map_err(|e| exchange_error(me, e))?;
        let (mut n_all, mut g_all) = (ambient, 0f64);
        for (r, b) in all.iter().enumerate() {
            let mut w = Words(b);
            let (Some(n), Some(g), true) = (w.u64(), w.u64(), b.len() == 16) else {
                return Err(DistributedError::Malformed { from: r });
            };
            n_all = n_all.max(f64::from_bits(n));
            g_all = g_all.max(f64::from_bits(g));
        }
        let needed = step_reach(params, n_all, g_all)?;
        if needed <= reach {
            return Ok(BrickField::new(bricks.info(), lo, samples, job.interp, ambient)?);
        }
        // Every rank sees the same extremes, so all read again together.
        reach = needed;
    }
}

/// The first read's bound on the index and its gradient (air-like media;
/// a run reads again, with ghost layers to match, when any rank's samples
/// exceed them).
const FIRST_N: f64 = 2.0;
const FIRST_GRADIENT: f64 = 1.0;

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
    rank_from(comm, job, job)
}

/// [`rank`] with this rank's samples from `source` (each rank its own:
/// a [`super::Piece`] covering [`first_brick_box`]).
///
/// # Errors
/// As [`rank`]; a piece that lacks samples a step reaches.
pub fn rank_from<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
    source: &dyn BrickSource,
) -> Result<(Option<Film>, VolumeRank), DistributedError> {
    let (me, ranks) = (comm.rank(), comm.size());
    let mut report = VolumeRank::default();
    let t = Instant::now();
    let (info, ambient) = job.header(source)?;
    let bricks = Bricks::for_ranks(info, ranks)?;
    let params = VolumeJob::params(&info);
    let field = load_brick(comm, job, source, &bricks, ambient, &params)?;
    report.brick_samples = field.stored_samples();
    report.grid_samples = info.dims.iter().product();
    report.seconds[0] = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let bounds = info.bounds();
    let bench = job.bench(&info, ambient, 1.0);
    let film = job.film(&bench)?;
    // This rank's photons: those entering its brick (rank 0: also those
    // missing the volume, whose result needs no field).
    let mut queue: Vec<(Key, PathState)> = Vec::new();
    let mut done: Vec<(Key, TraceResult)> = Vec::new();
    for k in emissions(&bench, &film, job.seed)? {
        let (o, d) = unkey(&k);
        match trace_begin(bounds, ambient, o, d, &params)? {
            Begin::Missed(r) if me == 0 => done.push((k, r)),
            Begin::Missed(_) => {}
            Begin::Inside(s) if bricks.owner(s.position()) == me => queue.push((k, s)),
            Begin::Inside(_) => {}
        }
    }
    report.entered = queue.len() as u64;
    let mut results: Vec<(Key, TraceResult)> = Vec::new();
    let owns = |x: DVec3| bricks.owner(x) == me;
    let step = |_: u32, inbox: &[Batch], outbox: &mut [Vec<u8>]| {
        for b in inbox {
            if b.bytes.is_empty() {
                continue;
            }
            let bad = DistributedError::Malformed { from: b.from };
            let mut w = Words(&b.bytes);
            let photons = w.u64().ok_or(DistributedError::Malformed { from: b.from })?;
            for _ in 0..photons {
                queue.push(w.photon().ok_or(DistributedError::Malformed { from: b.from })?);
            }
            let finished = w.u64().ok_or(DistributedError::Malformed { from: b.from })?;
            if finished > 0 && me != 0 {
                return Err(bad);
            }
            for _ in 0..finished {
                results.push(w.result().ok_or(DistributedError::Malformed { from: b.from })?);
            }
            if !w.0.is_empty() {
                return Err(bad);
            }
        }
        let take = queue.len().min(job.batch.max(1));
        let batch: Vec<(Key, PathState)> = queue.split_off(queue.len() - take);
        let legs: Vec<(Key, Result<Leg, TraceError>)> =
            batch.into_par_iter().map(|(k, s)| (k, trace_leg(&field, s, &params, owns))).collect();
        report.legs += legs.len() as u64;
        let mut handed: Vec<Vec<(Key, PathState)>> = vec![Vec::new(); ranks];
        for (k, leg) in legs {
            match leg {
                Ok(Leg::Finished(r)) => done.push((k, r)),
                Ok(Leg::Left(s)) => handed[bricks.owner(s.position())].push((k, s)),
                Err(TraceError::BadField { at }) if !field.covers(at) => {
                    return Err(DistributedError::BeyondBrick { rank: me, at });
                }
                Err(e) => return Err(e.into()),
            }
        }
        let send_now = done.len().min(job.batch.max(1));
        let finished: Vec<(Key, TraceResult)> = done.split_off(done.len() - send_now);
        if me == 0 {
            results.extend(finished.iter().copied());
        }
        for (peer, out) in outbox.iter_mut().enumerate() {
            let to_zero = peer == 0 && me != 0 && !finished.is_empty();
            if handed[peer].is_empty() && !to_zero {
                continue;
            }
            report.handed_off += handed[peer].len() as u64;
            put_count(out, handed[peer].len());
            for (k, s) in &handed[peer] {
                put_photon(out, k, s);
            }
            let sent: &[(Key, TraceResult)] = if to_zero { &finished } else { &[] };
            put_count(out, sent.len());
            for (k, r) in sent {
                put_result(out, k, r);
            }
        }
        Ok(!queue.is_empty() || !done.is_empty())
    };
    report.exchange = rounds(comm, 1_000_000, step).map_err(|e| exchange_error(me, e))?;
    report.seconds[1] = t.elapsed().as_secs_f64();
    if me != 0 {
        return Ok((None, report));
    }
    let t = Instant::now();
    results.sort_unstable_by_key(|(k, _)| *k);
    let bench = if job.optics == VolumeOptics::Knife {
        let traced: Vec<TraceResult> = results.iter().map(|(_, r)| *r).collect();
        job.bench(&info, ambient, knife_range(&bench, &traced))
    } else {
        bench
    };
    let mut film = job.film(&bench)?;
    let lookup = |o: DVec3, d: DVec3| {
        let k = key(o, d);
        results
            .binary_search_by_key(&k, |(k, _)| *k)
            .map(|i| results[i].1)
            .map_err(|_| TraceError::InvalidRay)
    };
    bench.render_with(&lookup, &mut film, 0, job.seed).map_err(|e| match e {
        crate::BenchError::Trace(TraceError::InvalidRay) => DistributedError::MissingResult,
        e => e.into(),
    })?;
    report.seconds[2] = t.elapsed().as_secs_f64();
    Ok((Some(film), report))
}
