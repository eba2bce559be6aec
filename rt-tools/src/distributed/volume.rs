//! Volumes across ranks: the grid is split into bricks, one per rank; each
//! rank reads only its brick (with the ghost layers a step can reach)
//! from the file, and photons are handed from brick to brick as they
//! cross. Rank 0 lands them on the film in the bench's own order, so the
//! image equals one process tracing the whole grid, bit for bit.
//!
//! 1. **Emission.** Every rank runs the bench once with a tracer that only
//!    records what it is asked: the photons' `(origin, direction)`. A
//!    photon's identity is those six `f64`s (its pixel and stratum are a
//!    function of them). `rt_volume::trace_begin` carries each straight to
//!    the volume; the rank owning its entry point keeps it (rank 0 also
//!    keeps the ones that miss).
//! 2. **Tracing.** Each round, a rank advances up to [`BATCH`] photons
//!    through its brick (`rt_volume::trace_leg`, on all cores): a photon
//!    that steps into another rank's brick is handed over with its whole
//!    integration state (position, `T = n dx/ds`, optical path, arc
//!    length, step, stats, the last evaluation), which is all the
//!    integrator carries (the bench draws no random numbers in flight);
//!    one that leaves the volume becomes a result for rank 0. Rounds run
//!    on `rt_composite::exchange::rounds` until no rank holds a photon.
//! 3. **Film.** Rank 0 runs the bench again with a tracer that looks each
//!    photon's result up by its identity: the landing, the cutoff and the
//!    splatting happen in the bench's fixed order, exactly as in one
//!    process.
//!
//! Each leg computes what the whole grid's trace computes (the brick
//! interpolates with global indices, a step started in the owned box stays
//! within the loaded reach), so the result is `rt_volume::trace`'s, bit
//! for bit. A step that reaches past the loaded samples is an `Err`, never
//! a wrong image: the brick answers NaN there.
//!
//! Memory per rank: its brick, the photons it owns at entry, and per
//! round at most [`BATCH`] photons and [`BATCH`] results in messages; rank
//! 0 also holds one result per photon for the ordered reduction.

use std::{
    path::{Path, PathBuf},
    sync::Mutex,
    time::Instant,
};

use anyhow::{Context, anyhow, bail};
use rayon::prelude::*;
use rt_composite::{
    Communicator,
    exchange::{ExchangeStats, all_gather, rounds},
};
use rt_photo::{Axis, Cutoff, Film, Filter, Mode, Reconstruction, SchlierenBench, Weighting};
use rt_volume::{
    Begin, BrickField, Bricks, Exit, Grid, GridField, GridInfo, Interp, Leg, PathState, Samples,
    TraceParams, TraceResult, TraceStats, glam::DVec3, io, step_reach, trace, trace_begin,
    trace_leg,
};

/// Photons a rank advances per round, and most results it sends rank 0
/// per round, by default: this bounds its message buffers (see
/// [`VolumeJob::largest_message`]).
pub const BATCH: usize = 1 << 14;

/// The most photons one distributed run traces (each rank lists their
/// 48-byte identities once while it finds its own).
pub const MAX_PHOTONS: u64 = 1 << 25;

/// Bytes of a photon handed over: its identity (6 words) and its
/// [`PathState`].
pub const PHOTON_BYTES: usize = 8 * (6 + PathState::WORDS);

/// Bytes of a finished photon's result sent to rank 0: its identity and
/// 15 words of [`TraceResult`].
pub const RESULT_BYTES: usize = 8 * (6 + TraceResult::WORDS);

/// What a volume render records.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VolumeOptics {
    /// Knife-edge schlieren, edge along the image's v axis (deflections
    /// along u are seen); the edge's range is chosen from the photons'
    /// deflections (0.5 ± 0.45 at their 99th percentile), as `rt
    /// schlieren` chooses it.
    Knife,
    /// Interferometry against the undisturbed index.
    Interferometry {
        /// Wavelength in metres.
        lambda: f64,
        /// Carrier fringe spacing in metres (`None`: infinite fringe).
        fringes: Option<f64>,
    },
}

/// What to render.
#[derive(Clone, Debug, PartialEq)]
pub struct VolumeJob {
    /// A raw + JSON volume or an NRRD volume with raw encoding (read a
    /// brick at a time).
    pub file: PathBuf,
    /// What the samples are.
    pub samples: Samples,
    /// The interpolant.
    pub interp: Interp,
    /// What is recorded.
    pub optics: VolumeOptics,
    /// Film width in pixels (the height follows the volume's aspect).
    pub size: u32,
    /// `strata × strata` photons per pixel.
    pub strata: u32,
    /// Seed of the photons' placement.
    pub seed: u64,
    /// Most photons a rank advances, and most results it sends rank 0,
    /// per round ([`BATCH`] by default).
    pub batch: usize,
}

impl VolumeJob {
    /// The built-in blast wave (64³ densities), written into `dir` as
    /// raw and JSON files so that ranks can read bricks of it; knife-edge
    /// schlieren along z with the Catmull–Rom interpolant.
    ///
    /// # Errors
    /// `dir` cannot be written.
    pub fn builtin(dir: &Path, size: u32, strata: u32) -> anyhow::Result<Self> {
        let file = crate::builtin::write_blast_wave(dir)?;
        Ok(Self {
            file,
            samples: Samples::AIR,
            interp: Interp::CatmullRom,
            optics: VolumeOptics::Knife,
            size,
            strata,
            seed: 1,
            batch: BATCH,
        })
    }

    /// The longest message a rank can send: one round's hand-offs to one
    /// peer and, to rank 0, one round's results, with their counts and
    /// the two-byte header. Whatever the photon count.
    #[must_use]
    pub fn largest_message(&self) -> usize {
        let batch = self.batch.max(1);
        2 + 8 + batch * PHOTON_BYTES + 8 + batch * RESULT_BYTES
    }

    /// The samples `lo..hi` of the file, as index.
    fn read_box(&self, lo: [usize; 3], hi: [usize; 3]) -> anyhow::Result<Grid> {
        let grid = io::read_grid_box(&self.file, lo, hi)?;
        // Non-physical samples are the user's to judge here (the ranks
        // read bricks, not the whole volume's range).
        let grid = self.samples.grid_to_index(grid, true);
        grid.with_context(|| self.file.display().to_string())
    }

    /// The whole grid's header, and the index outside the volume (its
    /// first sample's, as `rt schlieren` takes it).
    fn header(&self) -> anyhow::Result<(GridInfo, f64)> {
        let ext = self.file.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("json" | "raw" | "nrrd" | "nhdr")) {
            bail!(
                "{}: a distributed volume is read a brick at a time, from raw + JSON (.json) or NRRD with raw encoding (.nrrd, .nhdr)",
                self.file.display()
            );
        }
        let info = io::read_grid_info(&self.file)?;
        let first = self.read_box([0; 3], [1; 3])?;
        let ambient = f64::from(first.data()[0]);
        Ok((info, ambient))
    }

    /// Step as `TraceParams::for_grid` takes it: leapfrog at one cell.
    fn params(info: &GridInfo) -> TraceParams {
        let cell = info.spacing.min_element();
        TraceParams { max_step: cell, ..TraceParams::fixed(rt_volume::Method::Symplectic, cell) }
    }

    /// The bench through the volume along z, in the mode's optics (the
    /// knife edge's range comes later, from the photons).
    fn bench(&self, info: &GridInfo, ambient: f64, h: f64) -> SchlierenBench {
        let mode = match self.optics {
            VolumeOptics::Knife => {
                Mode::Schlieren(Cutoff::KnifeEdge { angle: 0.0, offset: 0.0, f: 1.0, h })
            }
            VolumeOptics::Interferometry { lambda, fringes } => {
                Mode::Interferometry { lambda, n_ref: ambient, fringe_spacing: fringes }
            }
        };
        let bench = SchlierenBench::through(info.bounds(), Axis::Z, mode, 0.0, Self::params(info));
        SchlierenBench {
            strata: self.strata,
            weighting: Weighting::Weight,
            reconstruction: Reconstruction::Sheet,
            ..bench
        }
    }

    /// The film, refusing more photons than [`MAX_PHOTONS`] (every rank
    /// lists their identities once).
    fn film(&self, bench: &SchlierenBench) -> anyhow::Result<Film> {
        let height = (f64::from(self.size) * bench.height / bench.width).round().max(1.0) as usize;
        let side = |n: usize| (n as u64).saturating_mul(u64::from(self.strata)).saturating_add(2);
        let photons = side(self.size as usize).saturating_mul(side(height));
        if photons > MAX_PHOTONS {
            bail!(
                "{photons} photons is more than a distributed run traces ({MAX_PHOTONS}); lower --size or --strata"
            );
        }
        Ok(Film::new(self.size as usize, height, Filter::Tent)?)
    }
}

/// What one rank did, and what it cost.
#[derive(Clone, Debug, Default)]
pub struct VolumeRank {
    /// Samples of this rank's brick (ghost layers included).
    pub brick_samples: usize,
    /// Samples of the whole grid.
    pub grid_samples: usize,
    /// Photons that entered the volume in this rank's brick.
    pub entered: u64,
    /// Legs traced here (a photon crossing three bricks has three legs).
    pub legs: u64,
    /// Photons this rank handed to another.
    pub handed_off: u64,
    /// The rounds' messages and bytes (hand-offs and results).
    pub exchange: ExchangeStats,
    /// Seconds: reading the brick, tracing (rounds), the film (rank 0).
    pub seconds: [f64; 3],
}

/// A photon's identity: its origin and direction, bit for bit.
type Key = [u64; 6];

fn key(o: DVec3, d: DVec3) -> Key {
    [o.x, o.y, o.z, d.x, d.y, d.z].map(f64::to_bits)
}

/// The photons the bench emits for `film`, each once, by key.
fn emissions(bench: &SchlierenBench, film: &Film, seed: u64) -> anyhow::Result<Vec<Key>> {
    let seen = Mutex::new(Vec::new());
    let mut scratch = Film::new(film.width(), film.height(), Filter::Tent)?;
    bench.render_with(
        &|o, d| {
            seen.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(key(o, d));
            Ok(straight(o, d))
        },
        &mut scratch,
        0,
        seed,
    )?;
    let mut keys = seen.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner);
    keys.sort_unstable();
    keys.dedup();
    Ok(keys)
}

fn straight(o: DVec3, d: DVec3) -> TraceResult {
    TraceResult {
        position: o,
        direction: d,
        optical_path: 0.0,
        exit: Exit::Missed,
        stats: TraceStats::default(),
    }
}

fn unkey(k: &Key) -> (DVec3, DVec3) {
    let v = k.map(f64::from_bits);
    (DVec3::new(v[0], v[1], v[2]), DVec3::new(v[3], v[4], v[5]))
}

/// The knife edge's range from the photons' deflections along u: 0.5 ±
/// 0.45 at their 99th percentile (f = 1 m).
fn knife_range(bench: &SchlierenBench, results: &[TraceResult]) -> f64 {
    let mut along: Vec<f64> = results.iter().map(|r| r.direction.dot(bench.u).abs()).collect();
    along.sort_unstable_by(f64::total_cmp);
    let q = along.get((0.99 * (along.len().saturating_sub(1)) as f64) as usize).copied();
    q.unwrap_or(0.0).max(1e-12) / 0.45
}

/// One process tracing the whole grid: the reference the distributed
/// image must equal. The film is `SchlierenBench::render`'s own.
///
/// # Errors
/// An unreadable volume, a failing trace.
pub fn single(job: &VolumeJob) -> anyhow::Result<Film> {
    let (info, ambient) = job.header()?;
    let whole = job.read_box([0; 3], info.dims)?;
    let field = GridField::new(whole, job.interp, ambient)?;
    let bench = job.bench(&info, ambient, 1.0);
    let mut film = job.film(&bench)?;
    let bench = if job.optics == VolumeOptics::Knife {
        let keys = emissions(&bench, &film, job.seed)?;
        let results = keys
            .par_iter()
            .map(|k| {
                let (o, d) = unkey(k);
                trace(&field, o, d, &bench.params)
            })
            .collect::<Result<Vec<_>, _>>()?;
        job.bench(&info, ambient, knife_range(&bench, &results))
    } else {
        bench
    };
    bench.render(&field, &mut film, 0, job.seed)?;
    Ok(film)
}

/// Whether two films hold the same image, bit for bit.
#[must_use]
pub fn same(a: &Film, b: &Film) -> bool {
    let bits =
        |f: &Film| -> Vec<u32> { f.normalized().iter().flatten().map(|v| v.to_bits()).collect() };
    a.width() == b.width() && a.height() == b.height() && bits(a) == bits(b)
}

fn put_f64s(out: &mut Vec<u8>, v: &[f64]) {
    for x in v {
        out.extend(x.to_bits().to_le_bytes());
    }
}

/// A photon's identity and its result (`TraceResult`'s own words).
fn put_result(out: &mut Vec<u8>, k: &Key, r: &TraceResult) {
    for w in k {
        out.extend(w.to_le_bytes());
    }
    put_f64s(out, &r.to_words());
}

/// Little-endian words off a batch.
struct Words<'a>(&'a [u8]);

impl Words<'_> {
    fn u64(&mut self) -> Option<u64> {
        let (head, rest) = self.0.split_first_chunk::<8>()?;
        self.0 = rest;
        Some(u64::from_le_bytes(*head))
    }
    fn f64(&mut self) -> Option<f64> {
        self.u64().map(f64::from_bits)
    }
    fn key(&mut self) -> Option<Key> {
        let mut k = [0; 6];
        for w in &mut k {
            *w = self.u64()?;
        }
        Some(k)
    }
}

fn get_result(w: &mut Words<'_>) -> Option<(Key, TraceResult)> {
    let k = w.key()?;
    let mut v = [0f64; TraceResult::WORDS];
    for x in &mut v {
        *x = w.f64()?;
    }
    Some((k, TraceResult::from_words(&v).ok()?))
}

/// Reads this rank's brick with enough ghost layers for every step: first
/// with a reach for `n ≤ 2` and a gentle gradient, then, once every
/// rank's largest index and gradient are known, again if that was short.
fn load_brick<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
    bricks: &Bricks,
    ambient: f64,
    params: &TraceParams,
) -> anyhow::Result<BrickField> {
    let me = comm.rank();
    let mut reach = step_reach(params, 2.0, 1.0)?;
    loop {
        let (lo, hi) = bricks.samples_needed(me, reach, job.interp)?;
        let samples = job.read_box(lo, hi)?;
        let b = samples.index_bounds(job.interp);
        let mine: Vec<u8> = [b.n_max, b.grad_max].iter().flat_map(|v| v.to_le_bytes()).collect();
        let (all, _) = all_gather(comm, &mine).map_err(|e| anyhow!("rank {me}: {e}"))?;
        let (mut n_all, mut g_all) = (ambient, 0f64);
        for (r, b) in all.iter().enumerate() {
            let v: Vec<f64> = b
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
                .collect();
            let [n, g] = v[..] else { bail!("rank {r} sent a malformed extreme") };
            n_all = n_all.max(n);
            g_all = g_all.max(g);
        }
        let needed = step_reach(params, n_all, g_all)?;
        if needed <= reach {
            return Ok(BrickField::new(bricks.info(), lo, samples, job.interp, ambient)?);
        }
        // Every rank sees the same extremes, so all read again together.
        reach = needed;
    }
}

/// What one rank does: trace its photons, hand the others on; rank 0
/// returns the film.
///
/// # Errors
/// Any rank's failure (every rank learns of it within the timeout).
pub fn rank<C: Communicator>(
    comm: &C,
    job: &VolumeJob,
) -> anyhow::Result<(Option<Film>, VolumeRank)> {
    let (me, ranks) = (comm.rank(), comm.size());
    let mut report = VolumeRank::default();
    let t = Instant::now();
    let (info, ambient) = job.header()?;
    let bricks = Bricks::for_ranks(info, ranks)?;
    let params = VolumeJob::params(&info);
    let field = load_brick(comm, job, &bricks, ambient, &params)?;
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
    let step = |_: u32, inbox: &[rt_composite::exchange::Batch], outbox: &mut [Vec<u8>]| {
        for b in inbox {
            let bad = || format!("rank {} sent a malformed batch", b.from);
            let mut w = Words(&b.bytes);
            if b.bytes.is_empty() {
                continue;
            }
            let photons = w.u64().ok_or_else(bad)?;
            for _ in 0..photons {
                let k = w.key().ok_or_else(bad)?;
                let mut words = [0f64; PathState::WORDS];
                for x in &mut words {
                    *x = w.f64().ok_or_else(bad)?;
                }
                queue.push((
                    k,
                    PathState::from_words(&words).map_err(|e| format!("{}: {e}", bad()))?,
                ));
            }
            let finished = w.u64().ok_or_else(bad)?;
            if finished > 0 && me != 0 {
                return Err(bad());
            }
            for _ in 0..finished {
                results.push(get_result(&mut w).ok_or_else(bad)?);
            }
            if !w.0.is_empty() {
                return Err(bad());
            }
        }
        let take = queue.len().min(job.batch.max(1));
        let batch: Vec<(Key, PathState)> = queue.split_off(queue.len() - take);
        let legs: Vec<(Key, Result<Leg, rt_volume::TraceError>)> =
            batch.into_par_iter().map(|(k, s)| (k, trace_leg(&field, s, &params, owns))).collect();
        report.legs += legs.len() as u64;
        let mut handed: Vec<Vec<(Key, PathState)>> = vec![Vec::new(); ranks];
        for (k, leg) in legs {
            match leg {
                Ok(Leg::Finished(r)) => done.push((k, r)),
                Ok(Leg::Left(s)) => handed[bricks.owner(s.position())].push((k, s)),
                Err(rt_volume::TraceError::BadField { at }) if !field.covers(at) => {
                    return Err(format!(
                        "rank {me}: a step reached {at} beyond this rank's brick and its ghost layers"
                    ));
                }
                Err(e) => return Err(format!("rank {me}: {e}")),
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
            out.extend((handed[peer].len() as u64).to_le_bytes());
            for (k, s) in &handed[peer] {
                for w in k {
                    out.extend(w.to_le_bytes());
                }
                put_f64s(out, &s.to_words());
            }
            if to_zero {
                out.extend((finished.len() as u64).to_le_bytes());
                for (k, r) in &finished {
                    put_result(out, k, r);
                }
            } else {
                out.extend(0u64.to_le_bytes());
            }
        }
        Ok(!queue.is_empty() || !done.is_empty())
    };
    report.exchange = rounds(comm, 1_000_000, step).map_err(|e| anyhow!("rank {me}: {e}"))?;
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
            .map_err(|_| rt_volume::TraceError::InvalidRay)
    };
    bench
        .render_with(&lookup, &mut film, 0, job.seed)
        .context("rank 0: a photon's result is missing")?;
    report.seconds[2] = t.elapsed().as_secs_f64();
    Ok((Some(film), report))
}

/// The file the CLI renders when given none: the built-in blast wave,
/// written as raw + JSON into `dir`.
///
/// # Errors
/// `dir` cannot be written.
pub fn builtin_file(dir: &Path) -> anyhow::Result<PathBuf> {
    crate::builtin::write_blast_wave(dir)
}
