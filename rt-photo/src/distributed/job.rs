//! What a distributed volume render is, and one process rendering it
//! whole (the reference every rank count must equal).

use alloc::vec::Vec;
use std::path::PathBuf;

use glam::DVec3;
use rayon::prelude::*;
use rt_composite::exchange::ExchangeStats;
use rt_volume::{
    Grid, GridField, GridInfo, Interp, MediumError, Samples, TraceParams, TraceResult, io, trace,
};

use super::{
    BATCH, DistributedError, MAX_PHOTONS, Watch,
    across::{Tracer, emissions},
    wire::{PHOTON_BYTES, RESULT_BYTES, unkey},
};
use crate::{Axis, Cutoff, Film, Filter, Mode, Reconstruction, SchlierenBench, Weighting};

/// What a volume render records.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VolumeOptics {
    /// Knife-edge schlieren, edge along the image's v axis (deflections
    /// along u are seen); the edge's range is chosen from the photons'
    /// deflections (0.5 ± 0.45 at their 99th percentile).
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
    /// Knife-edge schlieren of `file`'s densities (air) along z with the
    /// Catmull–Rom interpolant, [`BATCH`] photons a round, seed 1.
    #[must_use]
    pub fn knife_edge(file: PathBuf, size: u32, strata: u32) -> Self {
        Self {
            file,
            samples: Samples::AIR,
            interp: Interp::CatmullRom,
            optics: VolumeOptics::Knife,
            size,
            strata,
            seed: 1,
            batch: BATCH,
        }
    }

    /// The longest message a rank can send: one round's hand-offs to one
    /// peer and, to rank 0, one round's results, with their counts and
    /// the two-byte header. Whatever the photon count.
    #[must_use]
    pub fn largest_message(&self) -> usize {
        let batch = self.batch.max(1);
        2 + 8 + batch * PHOTON_BYTES + 8 + batch * RESULT_BYTES
    }

    /// The samples `lo..hi` of `source`, as index.
    pub(crate) fn read_box(
        &self,
        source: &dyn BrickSource,
        lo: [usize; 3],
        hi: [usize; 3],
    ) -> Result<Grid, DistributedError> {
        self.to_index(source.read(lo, hi)?)
    }

    /// Samples as index. Non-physical samples are the user's to judge
    /// here (the ranks read bricks, not the whole volume's range).
    fn to_index(&self, grid: Grid) -> Result<Grid, DistributedError> {
        self.samples.grid_to_index(grid, true).map_err(|e| {
            let path = self.file.clone();
            DistributedError::Samples(MediumError::InFile {
                path,
                source: alloc::boxed::Box::new(e),
            })
        })
    }

    /// The whole grid's header, and the index outside the volume (its
    /// first sample's, as a medium takes it).
    pub(crate) fn header(
        &self,
        source: &dyn BrickSource,
    ) -> Result<(GridInfo, f64), DistributedError> {
        let info = source.info()?;
        let first = Grid::new([1; 3], info.origin, info.spacing, alloc::vec![source.first()?])?;
        let ambient = f64::from(self.to_index(first)?.data()[0]);
        Ok((info, ambient))
    }
}

/// Where a rank's samples come from: the job's file, read a box at a time
/// (a [`VolumeJob`] is one), or the piece of the grid the caller holds (a
/// [`Piece`]: what a ParaView rank is handed).
pub trait BrickSource: Sync {
    /// The whole grid's header.
    ///
    /// # Errors
    /// An unreadable or unsupported file.
    fn info(&self) -> Result<GridInfo, DistributedError>;

    /// The raw samples `lo..hi` (sample indices, `hi` exclusive) as a
    /// grid whose origin is sample `lo`'s centre.
    ///
    /// # Errors
    /// Samples the source does not hold or cannot read.
    fn read(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Grid, DistributedError>;

    /// Sample `(0, 0, 0)`, raw: the medium around the volume.
    ///
    /// # Errors
    /// As [`BrickSource::read`].
    fn first(&self) -> Result<f32, DistributedError> {
        Ok(self.read([0; 3], [1; 3])?.data()[0])
    }
}

impl BrickSource for VolumeJob {
    fn info(&self) -> Result<GridInfo, DistributedError> {
        let ext = self.file.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("json" | "raw" | "nrrd" | "nhdr")) {
            return Err(DistributedError::Format(self.file.clone()));
        }
        Ok(io::read_grid_info(&self.file)?)
    }

    fn read(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Grid, DistributedError> {
        Ok(io::read_grid_box(&self.file, lo, hi)?)
    }
}

/// The box of a grid one rank holds, raw samples x fastest: enough for a
/// run when it covers the rank's brick and ghost layers
/// ([`first_brick_box`](super::first_brick_box)).
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// The whole grid's header.
    pub info: GridInfo,
    /// The piece's first sample, in the whole grid's indices.
    pub lo: [usize; 3],
    /// Samples per axis of the piece.
    pub dims: [usize; 3],
    /// The piece's samples, x fastest.
    pub samples: Vec<f32>,
    /// The whole grid's sample `(0, 0, 0)` (the ambient medium), which
    /// this piece need not hold.
    pub first: f32,
}

impl BrickSource for Piece {
    fn info(&self) -> Result<GridInfo, DistributedError> {
        Ok(self.info)
    }

    fn read(&self, lo: [usize; 3], hi: [usize; 3]) -> Result<Grid, DistributedError> {
        let inside = (0..3)
            .all(|a| self.lo[a] <= lo[a] && lo[a] < hi[a] && hi[a] <= self.lo[a] + self.dims[a]);
        let count = self.dims.iter().product::<usize>();
        if !inside || self.samples.len() != count {
            return Err(DistributedError::Piece { lo, hi, held: (self.lo, self.dims) });
        }
        let d = [0, 1, 2].map(|a| hi[a] - lo[a]);
        let mut out = Vec::with_capacity(d.iter().product());
        for k in lo[2]..hi[2] {
            for j in lo[1]..hi[1] {
                let row = (k - self.lo[2]) * self.dims[1] + (j - self.lo[1]);
                let start = row * self.dims[0] + (lo[0] - self.lo[0]);
                out.extend_from_slice(&self.samples[start..start + d[0]]);
            }
        }
        let origin = self.info.origin
            + DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64) * self.info.spacing;
        Ok(Grid::new(d, origin, self.info.spacing, out)?)
    }

    fn first(&self) -> Result<f32, DistributedError> {
        Ok(self.first)
    }
}

impl VolumeJob {
    /// Step as `TraceParams::for_grid` takes it: leapfrog at one cell.
    pub(crate) fn params(info: &GridInfo) -> TraceParams {
        let cell = info.spacing.min_element();
        TraceParams { max_step: cell, ..TraceParams::fixed(rt_volume::Method::Symplectic, cell) }
    }

    /// The bench through the volume along z, in the mode's optics (the
    /// knife edge's range comes later, from the photons).
    pub(crate) fn bench(&self, info: &GridInfo, ambient: f64, h: f64) -> SchlierenBench {
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
    pub(crate) fn film(&self, bench: &SchlierenBench) -> Result<Film, DistributedError> {
        let height = (f64::from(self.size) * bench.height / bench.width).round().max(1.0) as usize;
        let side = |n: usize| (n as u64).saturating_mul(u64::from(self.strata)).saturating_add(2);
        let photons = side(self.size as usize).saturating_mul(side(height));
        if photons > MAX_PHOTONS {
            return Err(DistributedError::TooManyPhotons { photons, max: MAX_PHOTONS });
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

/// The knife edge's range from the photons' deflections along u: 0.5 ±
/// 0.45 at their 99th percentile (f = 1 m).
pub(crate) fn knife_range(bench: &SchlierenBench, results: &[TraceResult]) -> f64 {
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
pub fn single(job: &VolumeJob) -> Result<Film, DistributedError> {
    single_from(job, job)
}

/// [`single`] of the samples `source` holds (the whole grid).
///
/// # Errors
/// As [`single`].
pub fn single_from(job: &VolumeJob, source: &dyn BrickSource) -> Result<Film, DistributedError> {
    let (info, ambient) = job.header(source)?;
    let whole = job.read_box(source, [0; 3], info.dims)?;
    let field = GridField::new(whole, job.interp, ambient)?;
    let bench = job.bench(&info, ambient, 1.0);
    let mut film = job.film(&bench)?;
    let bench = if job.optics == VolumeOptics::Knife {
        let emit = |t: &Tracer<'_>| {
            let mut scratch = Film::new(film.width(), film.height(), Filter::Tent)?;
            Ok(bench.render_with(&t, &mut scratch, 0, job.seed)?)
        };
        let (mut keys, _) = emissions(emit, Watch::NONE, |k| Ok(Some(k)))?;
        // As rank 0 holds them: each ray once.
        keys.sort_unstable();
        keys.dedup();
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
