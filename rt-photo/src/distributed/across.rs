//! Any instrument's rays traced across ranks. An instrument that renders
//! through a tracer `(origin, direction) → result` (the schlieren bench,
//! its survey, BOS, focusing schlieren) is run once on every rank with a
//! tracer that only records the rays it asks for; the rays are traced
//! through the bricks in rounds; rank 0 then runs it again with a tracer
//! that looks each ray's result up. Whatever the instrument, the rays it
//! asks for cannot depend on the answers (none of them draws a random
//! number from a result), so the two runs ask for the same rays.

use alloc::{format, vec, vec::Vec};
use std::{sync::Mutex, time::Instant};

use glam::DVec3;
use rayon::prelude::*;
use rt_composite::{
    Communicator,
    exchange::{Batch, ExchangeError, all_gather, rounds},
};
use rt_volume::{
    Begin, BrickField, Bricks, Exit, GridInfo, Leg, PathState, TraceError, TraceParams,
    TraceResult, TraceStats, step_reach, trace_begin, trace_leg,
};

use super::{
    BrickSource, DistributedError, MAX_PHOTONS, VolumeJob, VolumeRank,
    wire::{Key, Words, key, put_count, put_photon, put_result, unkey},
};

/// A tracer as instruments take it.
pub(crate) type Tracer<'a> = dyn Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync + 'a;

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

/// One rank's part: its brick of the grid, and the ranks to trade
/// photons with.
pub(crate) struct Across<'a, C: Communicator> {
    comm: &'a C,
    batch: usize,
    pub(crate) info: GridInfo,
    /// The index outside the volume.
    pub(crate) ambient: f64,
    pub(crate) params: TraceParams,
    bricks: Bricks,
    field: BrickField,
    /// What this rank has done.
    pub(crate) report: VolumeRank,
}

impl<'a, C: Communicator> Across<'a, C> {
    /// Reads this rank's brick of `source` (as `job` takes its samples).
    pub(crate) fn new(
        comm: &'a C,
        job: &VolumeJob,
        source: &dyn BrickSource,
    ) -> Result<Self, DistributedError> {
        let t = Instant::now();
        let (info, ambient) = job.header(source)?;
        let bricks = Bricks::for_ranks(info, comm.size())?;
        let params = VolumeJob::params(&info);
        let field = load_brick(comm, job, source, &bricks, ambient, &params)?;
        let mut report = VolumeRank {
            brick_samples: field.stored_samples(),
            grid_samples: info.dims.iter().product(),
            ..VolumeRank::default()
        };
        report.seconds[0] = t.elapsed().as_secs_f64();
        Ok(Self { comm, batch: job.batch.max(1), info, ambient, params, bricks, field, report })
    }

    /// Traces the rays `emit` asks of its tracer (it is run on every rank
    /// with a tracer that records them and answers a straight ray):
    /// rank 0 gets every result; the others `None`.
    pub(crate) fn trace(
        &mut self,
        emit: impl FnOnce(&Tracer<'_>) -> Result<(), DistributedError>,
    ) -> Result<Option<Traced>, DistributedError> {
        let t = Instant::now();
        let me = self.comm.rank();
        let ranks = self.comm.size();
        let (bounds, ambient, params) = (self.info.bounds(), self.ambient, self.params);
        // This rank's photons: those entering its brick (rank 0: also
        // those missing the volume, whose result needs no field).
        let mut queue: Vec<(Key, PathState)> = Vec::new();
        let mut done: Vec<(Key, TraceResult)> = Vec::new();
        for k in emissions(emit)? {
            let (o, d) = unkey(&k);
            match trace_begin(bounds, ambient, o, d, &params)? {
                Begin::Missed(r) if me == 0 => done.push((k, r)),
                Begin::Missed(_) => {}
                Begin::Inside(s) if self.bricks.owner(s.position()) == me => queue.push((k, s)),
                Begin::Inside(_) => {}
            }
        }
        let report = &mut self.report;
        report.entered += queue.len() as u64;
        let (bricks, field, batch) = (&self.bricks, &self.field, self.batch);
        let mut results: Vec<(Key, TraceResult)> = Vec::new();
        let owns = |x: DVec3| bricks.owner(x) == me;
        let step = |_: u32, inbox: &[Batch], outbox: &mut [Vec<u8>]| {
            for b in inbox {
                if b.bytes.is_empty() {
                    continue;
                }
                let bad = || DistributedError::Malformed { from: b.from };
                let mut w = Words(&b.bytes);
                let photons = w.u64().ok_or_else(bad)?;
                for _ in 0..photons {
                    queue.push(w.photon().ok_or_else(bad)?);
                }
                let finished = w.u64().ok_or_else(bad)?;
                if finished > 0 && me != 0 {
                    return Err(bad());
                }
                for _ in 0..finished {
                    results.push(w.result().ok_or_else(bad)?);
                }
                if !w.0.is_empty() {
                    return Err(bad());
                }
            }
            let take = queue.len().min(batch);
            let legs: Vec<(Key, Result<Leg, TraceError>)> = queue
                .split_off(queue.len() - take)
                .into_par_iter()
                .map(|(k, s)| (k, trace_leg(field, s, &params, owns)))
                .collect();
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
            let send_now = done.len().min(batch);
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
        let stats = rounds(self.comm, 1_000_000, step).map_err(|e| exchange_error(me, e))?;
        let sum = &mut self.report.exchange;
        sum.rounds += stats.rounds;
        sum.messages += stats.messages;
        sum.bytes_sent += stats.bytes_sent;
        sum.largest_message = sum.largest_message.max(stats.largest_message);
        self.report.seconds[1] += t.elapsed().as_secs_f64();
        Ok((me == 0).then(|| Traced::new(results)))
    }

    /// Rank 0's `bytes` on every rank (the others' are not sent).
    pub(crate) fn share(&self, bytes: &[u8]) -> Result<Vec<u8>, DistributedError> {
        let me = self.comm.rank();
        let mine = if me == 0 { bytes } else { &[] };
        let (mut all, _) = all_gather(self.comm, mine).map_err(|e| exchange_error(me, e))?;
        if all.is_empty() {
            return Err(DistributedError::Malformed { from: 0 });
        }
        Ok(all.swap_remove(0))
    }
}

/// Every ray's result, on rank 0.
pub(crate) struct Traced(Vec<(Key, TraceResult)>);

impl Traced {
    fn new(mut results: Vec<(Key, TraceResult)>) -> Self {
        results.sort_unstable_by_key(|(k, _)| *k);
        Self(results)
    }

    /// The result of the ray from `o` along `d` ([`TraceError::InvalidRay`]
    /// if it was never asked for: see [`missing`]).
    pub(crate) fn get(&self, o: DVec3, d: DVec3) -> Result<TraceResult, TraceError> {
        let k = key(o, d);
        let i = self.0.binary_search_by_key(&k, |(k, _)| *k).map_err(|_| TraceError::InvalidRay)?;
        Ok(self.0[i].1)
    }

    /// Every result, in the rays' order.
    pub(crate) fn results(&self) -> impl Iterator<Item = &TraceResult> {
        self.0.iter().map(|(_, r)| r)
    }
}

/// A lookup's [`TraceError::InvalidRay`] as the missing result it is.
pub(crate) fn missing(e: TraceError) -> DistributedError {
    match e {
        TraceError::InvalidRay => DistributedError::MissingResult,
        e => e.into(),
    }
}

/// The rays `emit` asks for, each once, by key; refused past
/// [`MAX_PHOTONS`] (every rank lists them; the instrument is stopped at
/// the first ray beyond).
pub(crate) fn emissions(
    emit: impl FnOnce(&Tracer<'_>) -> Result<(), DistributedError>,
) -> Result<Vec<Key>, DistributedError> {
    let seen = Mutex::new(Vec::new());
    let emitted = emit(&|o, d| {
        let mut seen = seen.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        if seen.len() as u64 > MAX_PHOTONS {
            // Ends the instrument's run: too many, reported below.
            return Err(TraceError::InvalidRay);
        }
        seen.push(key(o, d));
        Ok(straight(o, d))
    });
    let mut keys = seen.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner);
    if keys.len() as u64 > MAX_PHOTONS {
        let photons = keys.len() as u64;
        return Err(DistributedError::TooManyPhotons { photons, max: MAX_PHOTONS });
    }
    emitted?;
    keys.sort_unstable();
    keys.dedup();
    Ok(keys)
}

/// A photon that went straight, nothing done.
fn straight(o: DVec3, d: DVec3) -> TraceResult {
    TraceResult {
        position: o,
        direction: d,
        optical_path: 0.0,
        exit: Exit::Missed,
        stats: TraceStats::default(),
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
pub(crate) const FIRST_N: f64 = 2.0;
pub(crate) const FIRST_GRADIENT: f64 = 1.0;
