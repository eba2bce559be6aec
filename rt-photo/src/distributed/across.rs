//! Any instrument's rays traced across ranks. An instrument that renders
//! through a tracer `(origin, direction) → result` (the schlieren bench,
//! its survey, BOS, focusing schlieren) is run once on every rank with a
//! tracer that only records the rays it asks for; the rays are traced
//! through the bricks in rounds; rank 0 then runs it again with a tracer
//! that looks each ray's result up. Whatever the instrument, the rays it
//! asks for cannot depend on the answers (none of them draws a random
//! number from a result), so the two runs ask for the same rays.

use alloc::{format, vec, vec::Vec};
use core::sync::atomic::{AtomicU64, Ordering};
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
    BrickSource, DistributedError, MAX_PHOTONS, VolumeJob, VolumeRank, Watch,
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
    watch: Watch<'a>,
    /// What this rank has done.
    pub(crate) report: VolumeRank,
}

impl<'a, C: Communicator> Across<'a, C> {
    /// Reads this rank's brick of `source` (as `job` takes its samples);
    /// its traces are watched by `watch`.
    pub(crate) fn new(
        comm: &'a C,
        job: &VolumeJob,
        source: &dyn BrickSource,
        watch: Watch<'a>,
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
        let batch = job.batch.max(1);
        Ok(Self { comm, batch, info, ambient, params, bricks, field, watch, report })
    }

    /// Traces the rays `emit` asks of its tracer (it is run on every rank
    /// with a tracer that records them and answers a straight ray):
    /// rank 0 gets every result, the others `None`; rank 0 tells the
    /// watch its progress if `counted`.
    pub(crate) fn trace(
        &mut self,
        emit: impl FnOnce(&Tracer<'_>) -> Result<(), DistributedError>,
        counted: bool,
    ) -> Result<Option<Traced<'a>>, DistributedError> {
        let t = Instant::now();
        let me = self.comm.rank();
        let ranks = self.comm.size();
        let (bounds, ambient, params) = (self.info.bounds(), self.ambient, self.params);
        let watch = self.watch;
        let bricks = &self.bricks;
        // This rank's photons, found as the instrument lists them: those
        // entering its brick (rank 0: also those missing the volume,
        // whose result needs no field).
        let mine = |k: Key| -> Result<Option<Entry>, TraceError> {
            let (o, d) = unkey(&k);
            Ok(match trace_begin(bounds, ambient, o, d, &params)? {
                Begin::Missed(r) if me == 0 => Some(Entry::Done(k, r)),
                Begin::Inside(s) if bricks.owner(s.position()) == me => Some(Entry::Queued(k, s)),
                Begin::Missed(_) | Begin::Inside(_) => None,
            })
        };
        let (entries, total) = match emissions(emit, watch, mine) {
            // The first round fails and so tells the peers.
            Err(_) if watch.stopped() => (Vec::new(), 0),
            listed => listed?,
        };
        let tell = |done: usize| {
            if counted && me == 0 {
                (watch.progress)(done as u64, total);
            }
        };
        let mut queue: Vec<(Key, PathState)> = Vec::new();
        let mut done: Vec<(Key, TraceResult)> = Vec::new();
        for e in entries {
            match e {
                Entry::Queued(k, s) => queue.push((k, s)),
                Entry::Done(k, r) => done.push((k, r)),
            }
        }
        let report = &mut self.report;
        report.entered += queue.len() as u64;
        let (field, batch) = (&self.field, self.batch);
        let mut results: Vec<(Key, TraceResult)> = Vec::new();
        let owns = |x: DVec3| bricks.owner(x) == me;
        let step = |_: u32, inbox: &[Batch], outbox: &mut [Vec<u8>]| {
            if watch.stopped() {
                return Err(DistributedError::Stopped);
            }
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
                .map(|(k, s)| {
                    let leg = if watch.stopped() {
                        Err(TraceError::Stopped)
                    } else {
                        trace_leg(field, s, &params, owns)
                    };
                    (k, leg)
                })
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
                    Err(TraceError::Stopped) => return Err(DistributedError::Stopped),
                    Err(e) => return Err(e.into()),
                }
            }
            let send_now = done.len().min(batch);
            let finished: Vec<(Key, TraceResult)> = done.split_off(done.len() - send_now);
            if me == 0 {
                results.extend(finished.iter().copied());
                tell(results.len());
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
        tell(results.len());
        let sum = &mut self.report.exchange;
        sum.rounds += stats.rounds;
        sum.messages += stats.messages;
        sum.bytes_sent += stats.bytes_sent;
        sum.largest_message = sum.largest_message.max(stats.largest_message);
        self.report.seconds[1] += t.elapsed().as_secs_f64();
        Ok((me == 0).then(|| Traced::new(results, watch)))
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

/// Every ray's result, on rank 0; looked up until the watch says to
/// stop.
pub(crate) struct Traced<'a> {
    results: Vec<(Key, TraceResult)>,
    watch: Watch<'a>,
}

impl<'a> Traced<'a> {
    fn new(mut results: Vec<(Key, TraceResult)>, watch: Watch<'a>) -> Self {
        results.sort_unstable_by_key(|(k, _)| *k);
        // A ray asked for twice was traced twice, alike.
        results.dedup_by_key(|(k, _)| *k);
        Self { results, watch }
    }

    /// The result of the ray from `o` along `d` ([`TraceError::InvalidRay`]
    /// if it was never asked for: see [`missing`]).
    pub(crate) fn get(&self, o: DVec3, d: DVec3) -> Result<TraceResult, TraceError> {
        if self.watch.stopped() {
            return Err(TraceError::Stopped);
        }
        let k = key(o, d);
        let found = self.results.binary_search_by_key(&k, |(k, _)| *k);
        Ok(self.results[found.map_err(|_| TraceError::InvalidRay)?].1)
    }

    /// Every result, in the rays' order.
    pub(crate) fn results(&self) -> impl Iterator<Item = &TraceResult> {
        self.results.iter().map(|(_, r)| r)
    }
}

/// A lookup's error as what it is: a missing result, or a stop.
pub(crate) fn missing(e: TraceError) -> DistributedError {
    match e {
        TraceError::InvalidRay => DistributedError::MissingResult,
        TraceError::Stopped => DistributedError::Stopped,
        e => e.into(),
    }
}

/// A ray this rank starts with: to trace, or (rank 0) already done.
enum Entry {
    Queued(Key, PathState),
    Done(Key, TraceResult),
}

/// What `keep` keeps of the rays `emit` asks for (by key, on the
/// instrument's threads, each thread into its own list), and how many it
/// asked for; refused past [`MAX_PHOTONS`] (the instrument is stopped at
/// the first ray beyond), or once `watch` says to stop. A ray asked for
/// twice is kept twice (its two results are the same).
pub(crate) fn emissions<T: Send>(
    emit: impl FnOnce(&Tracer<'_>) -> Result<(), DistributedError>,
    watch: Watch<'_>,
    keep: impl Fn(Key) -> Result<Option<T>, TraceError> + Sync,
) -> Result<(Vec<T>, u64), DistributedError> {
    let lists: Vec<Mutex<Vec<T>>> =
        (0..=rayon::current_num_threads()).map(|_| Mutex::new(Vec::new())).collect();
    let asked = AtomicU64::new(0);
    let emitted = emit(&|o, d| {
        if watch.stopped() {
            return Err(TraceError::Stopped);
        }
        if asked.fetch_add(1, Ordering::Relaxed) >= MAX_PHOTONS {
            // Ends the instrument's run: too many, reported below.
            return Err(TraceError::InvalidRay);
        }
        if let Some(t) = keep(key(o, d))? {
            // Uncontended: a list per worker thread (0: any other thread).
            let i = rayon::current_thread_index().map_or(0, |i| i + 1) % lists.len();
            lists[i].lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(t);
        }
        Ok(straight(o, d))
    });
    let asked = asked.into_inner();
    if asked > MAX_PHOTONS {
        return Err(DistributedError::TooManyPhotons { photons: asked, max: MAX_PHOTONS });
    }
    emitted?;
    let mut kept = Vec::new();
    for list in lists {
        kept.append(&mut list.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner));
    }
    Ok((kept, asked))
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
