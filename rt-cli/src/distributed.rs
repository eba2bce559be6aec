//! `rt distributed`: rendering data split across ranks, checked against
//! one process rendering all of it, bit for bit.
//!
//! ```text
//! # ranks as threads of one process (no MPI needed)
//! rt distributed --ranks 4 --shadows --ao 4
//! # ranks as MPI processes (Debian: libopenmpi-dev openmpi-bin libclang-dev)
//! cargo build --release -p rt-cli --features mpi
//! mpirun -np 4 target/release/rt distributed --shadows --ao 4 --schedule radix-3
//! # knife-edge schlieren of a volume, photons handed between bricks
//! rt distributed --ranks 8 --volume blast.json
//! ```
//!
//! **Surfaces** (the default): the terrain is cut into slabs of triangles
//! by centroid along its longest axis; each rank builds a BVH over its
//! slab only, shades the pixels its slab covers with shadow and AO rays
//! answered by every rank whose region they cross (see `rt_tools::distributed::surface`), and
//! the frames are z-composited.
//!
//! **Volumes** (`--volume [FILE]`): the grid is split into bricks, one per
//! rank; each rank reads only its brick and its ghost layers from the
//! file, and photons are handed from brick to brick (see `rt_tools::distributed::volume`);
//! rank 0 lands them on the film in the bench's fixed order.
//!
//! The image is written by rank 0, which also renders the whole mesh in
//! one process and compares: the program exits non-zero if one bit of
//! depth or colour differs.

use std::{
    path::{Path, PathBuf},
    time::Instant,
};

use anyhow::{anyhow, bail};
use clap::ValueEnum;
use rt_composite::{Communicator, Schedule};
use rt_core::{Frame, Pixel};
use rt_photo::Film;

use rt_tools::{
    distributed::{surface, volume},
    image::{film_frame, write_png},
    output::Outputs,
};

use crate::{
    optics::{Interpolation, Samples},
    parse,
};

/// A compositing schedule: `direct-send`, `binary-swap` or `radix-K`.
fn schedule(s: &str) -> Result<Schedule, String> {
    match s {
        "direct-send" => Ok(Schedule::DirectSend),
        "binary-swap" => Ok(Schedule::BinarySwap),
        _ => match s.strip_prefix("radix-").map(str::parse::<usize>) {
            Some(Ok(k)) if k >= 2 => Ok(Schedule::RadixK(k)),
            _ => Err(format!("`{s}`: direct-send, binary-swap or radix-K with K ≥ 2")),
        },
    }
}

/// Seconds, more than 0 and at most a week.
fn timeout(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 604_800.0 => Ok(v),
        _ => Err(format!("`{s}`: seconds, more than 0 and at most 604800 (a week)")),
    }
}

/// `rt distributed`: options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Ranks, as threads of this process (ignored under MPI, where
    /// `mpirun -np N` sets them).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub ranks: u32,
    /// Image size in pixels, WxH.
    #[arg(long, value_parser = parse::size, default_value = "640x480")]
    pub size: (u32, u32),
    /// The terrain has N×N vertices (2 (N−1)² triangles).
    #[arg(long, default_value_t = 257, value_parser = clap::value_parser!(u32).range(2..=4096))]
    pub grid: u32,
    /// Hard shadows from the sun, tested against every rank's triangles.
    #[arg(long)]
    pub shadows: bool,
    /// Ambient-occlusion rays per visible hit (0: off), tested against
    /// every rank's triangles.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=4096))]
    pub ao: u32,
    /// Longest AO ray, in scene units [default: 5 % of the scene's
    /// diagonal].
    #[arg(long, value_parser = parse::positive)]
    pub ao_distance: Option<f64>,
    /// Seed of the AO directions.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Seconds a rank waits for another before giving up (a rank that
    /// stops answering is then an error on every rank, never a hang).
    #[arg(long, default_value_t = 60.0, value_parser = timeout)]
    pub timeout: f64,
    /// Compositing schedule: direct-send, binary-swap or radix-K (K ≥ 2).
    #[arg(long, value_parser = schedule, default_value = "binary-swap")]
    pub schedule: Schedule,
    /// Render a volume instead of the terrain: knife-edge schlieren (or
    /// `--record interferometry`) with photons handed between bricks. FILE
    /// is a raw + JSON volume or an NRRD volume with raw encoding; without
    /// FILE, the built-in blast wave.
    #[arg(long, value_name = "FILE", num_args = 0..=1, default_missing_value = "built-in")]
    pub volume: Option<PathBuf>,
    /// Volume: what the film records.
    #[arg(long, value_enum, default_value_t = Record::Knife)]
    pub record: Record,
    /// Volume: photons per pixel are STRATA² (the film is WIDTH of
    /// `--size` wide, its height from the volume's aspect).
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub strata: u32,
    /// Volume: interpolation between samples.
    #[arg(long, value_enum, default_value_t = Interpolation::Cubic)]
    pub interp: Interpolation,
    /// Volume, interferometry: wavelength in metres.
    #[arg(long, default_value = "10.6e-6", value_parser = parse::positive)]
    pub lambda: f64,
    /// Volume, interferometry: carrier fringe spacing in metres (0:
    /// infinite fringe).
    #[arg(long, default_value_t = 0.04, value_parser = parse::non_negative)]
    pub fringes: f64,
    /// Volume: what the samples are.
    #[command(flatten)]
    pub samples: Samples,
    /// PNG rank 0 writes [default: out/distributed.png, with --volume
    /// out/distributed-volume.png].
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// What a distributed volume render records.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Record {
    /// Knife-edge schlieren.
    Knife,
    /// Interferometry.
    Interferometry,
}

impl Args {
    fn out(&self) -> PathBuf {
        self.out.clone().unwrap_or_else(|| {
            PathBuf::from(if self.volume.is_some() {
                "out/distributed-volume.png"
            } else {
                "out/distributed.png"
            })
        })
    }

    /// The volume job, its built-in data written under `scratch` when no
    /// file is given.
    fn volume_job(&self, file: &Path, scratch: &Path) -> anyhow::Result<volume::VolumeJob> {
        let file = if file == Path::new("built-in") {
            volume::builtin_file(scratch)?
        } else {
            file.to_path_buf()
        };
        Ok(volume::VolumeJob {
            file,
            samples: self.samples.into(),
            interp: self.interp.into(),
            optics: match self.record {
                Record::Knife => volume::VolumeOptics::Knife,
                Record::Interferometry => volume::VolumeOptics::Interferometry {
                    lambda: self.lambda,
                    fringes: (self.fringes > 0.0).then_some(self.fringes),
                },
            },
            size: self.size.0,
            strata: self.strata,
            seed: self.seed,
            batch: volume::BATCH,
        })
    }

    fn surface_job(&self) -> surface::SurfaceJob {
        surface::SurfaceJob {
            size: self.size,
            grid: self.grid,
            shadows: self.shadows,
            ao: self.ao,
            ao_distance: self.ao_distance.map(|d| d as f32),
            seed: self.seed,
            schedule: self.schedule,
        }
    }
}

/// Where rank `rank` writes the built-in volume (removed by `run`).
fn scratch(rank: usize) -> PathBuf {
    std::env::temp_dir().join(format!("rt-distributed-{}-{rank}", std::process::id()))
}

/// What rank 0 has at the end.
enum Image {
    Surface(Frame),
    Volume(Film, volume::VolumeJob),
}

/// What one rank does; rank 0 returns the image.
fn rank_main<C: Communicator>(comm: &C, o: &Args) -> anyhow::Result<Option<Image>> {
    let (rank, ranks) = (comm.rank(), comm.size());
    let t = Instant::now();
    if let Some(file) = &o.volume {
        let job = o.volume_job(file, &scratch(rank))?;
        let (film, r) = volume::rank(comm, &job)?;
        println!(
            "rank {rank}/{ranks}: brick of {} samples ({:.1} % of the grid's {}), {} photons entered here, \
             {} legs traced, {} handed to other ranks, {} rounds, {} bytes in {} messages; {:.3} s",
            r.brick_samples,
            100.0 * r.brick_samples as f64 / r.grid_samples as f64,
            r.grid_samples,
            r.entered,
            r.legs,
            r.handed_off,
            r.exchange.rounds,
            r.exchange.bytes_sent,
            r.exchange.messages,
            t.elapsed().as_secs_f64(),
        );
        return Ok(film.map(|f| Image::Volume(f, job)));
    }
    let (image, r) = surface::rank(comm, &o.surface_job())?;
    let occ = &r.occlusion;
    println!(
        "rank {rank}/{ranks}: {} triangles, {} pixels covered; {} occlusion rays ({} blocked here, {} by other ranks), \
         {} sent to other ranks, {} answered for them, {} rounds, {} bytes in {} messages; \
         composite {} bytes in {} messages; {:.3} s",
        r.triangles,
        r.covered,
        occ.rays,
        occ.blocked_locally,
        occ.blocked_elsewhere,
        occ.sent,
        occ.answered,
        occ.exchange.rounds,
        occ.exchange.bytes_sent,
        occ.exchange.messages,
        r.composite.bytes_sent,
        r.composite.messages,
        t.elapsed().as_secs_f64(),
    );
    Ok(image.map(Image::Surface))
}

/// Rank 0's check against the whole data rendered in one process.
fn check(image: &Image, o: &Args, outs: Outputs) -> anyhow::Result<()> {
    let out = o.out();
    let (differ, covered, size) = match image {
        Image::Surface(composited) => {
            write_png(composited, &outs.staging(&out))?;
            let whole = surface::single(&o.surface_job())?;
            let bits = |p: &Pixel| (p.color.map(f32::to_bits), p.depth.to_bits());
            let differ = composited
                .pixels()
                .iter()
                .zip(whole.pixels())
                .filter(|(a, b)| bits(a) != bits(b))
                .count();
            let covered = whole.pixels().iter().filter(|p| p.depth.is_finite()).count();
            (differ, covered, (composited.width(), composited.height()))
        }
        Image::Volume(film, job) => {
            write_png(&film_frame(film, 1.0)?, &outs.staging(&out))?;
            let whole = volume::single(job)?;
            let differ = if volume::same(film, &whole) {
                0
            } else {
                let (a, b) = (film.normalized(), whole.normalized());
                a.iter()
                    .zip(&b)
                    .filter(|(p, q)| p.map(f32::to_bits) != q.map(f32::to_bits))
                    .count()
                    .max(1)
            };
            let size = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
            (differ, film.width() * film.height(), (size(film.width()), size(film.height())))
        }
    };
    outs.commit()?;
    println!(
        "wrote {}: {}×{}, {covered} pixels covered; differs from the single-process render in {differ} pixels (compared bit for bit)",
        out.display(),
        size.0,
        size.1
    );
    if covered == 0 {
        bail!("nothing in view");
    }
    if differ > 0 {
        bail!("{differ} pixels differ from the single-process render");
    }
    Ok(())
}

/// Runs `rt distributed` on MPI processes.
///
/// # Errors
/// A failing rank (every rank learns of it), or a composite that differs
/// from the single-process render.
#[cfg(feature = "mpi")]
pub fn run(o: &Args) -> anyhow::Result<()> {
    use rt_composite::{MpiComm, mpi::traits::Communicator as _};
    let universe =
        rt_composite::mpi::initialize().ok_or_else(|| anyhow!("MPI was already initialised"))?;
    let world = universe.world();
    let comm = MpiComm::new(&world, std::time::Duration::from_secs_f64(o.timeout));
    // Rank 0 writes: its --out is checked before the work, and every rank
    // learns the answer first, so none starts work rank 0 will not join.
    let outs = if comm.rank() == 0 { Some(Outputs::check(&[o.out()])) } else { None };
    let mut writable = u8::from(outs.as_ref().is_none_or(Result::is_ok));
    rt_composite::mpi::traits::Root::broadcast_into(&world.process_at_rank(0), &mut writable);
    let result = match outs {
        Some(Err(e)) => Err(e),
        _ if writable == 0 => Err(anyhow!("rank 0 cannot write {}", o.out().display())),
        Some(Ok(outs)) => {
            rank_main(&comm, o).and_then(|f| f.map_or(Ok(()), |f| check(&f, o, outs)))
        }
        None => rank_main(&comm, o).map(drop),
    };
    std::fs::remove_dir_all(scratch(comm.rank())).ok();
    // Every rank learns whether rank 0's check passed.
    let mut ok = u8::from(result.is_ok());
    rt_composite::mpi::traits::Root::broadcast_into(&world.process_at_rank(0), &mut ok);
    match result {
        Err(e) => Err(e),
        Ok(()) if ok == 0 => Err(anyhow!("rank 0 failed")),
        Ok(()) => Ok(()),
    }
}

/// Runs `rt distributed` on threads.
///
/// # Errors
/// A failing rank, or a composite that differs from the single-process
/// render.
#[cfg(not(feature = "mpi"))]
pub fn run(o: &Args) -> anyhow::Result<()> {
    use rt_composite::ThreadComm;
    // Before any work: an impossible --out fails now, not after the render.
    let outs = Outputs::check(&[o.out()])?;
    let comms = ThreadComm::group(o.ranks as usize, std::time::Duration::from_secs_f64(o.timeout));
    let results: Vec<anyhow::Result<Option<Image>>> = std::thread::scope(|s| {
        let handles: Vec<_> =
            comms.into_iter().map(|c| s.spawn(move || rank_main(&c, o))).collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err(anyhow!("a rank panicked"))))
            .collect()
    });
    let checked = results.into_iter().collect::<anyhow::Result<Vec<_>>>().and_then(|images| {
        let image = images.into_iter().flatten().next();
        check(&image.ok_or_else(|| anyhow!("no rank returned the image"))?, o, outs)
    });
    for rank in 0..o.ranks as usize {
        std::fs::remove_dir_all(scratch(rank)).ok();
    }
    checked
}
