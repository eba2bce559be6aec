//! `rt distributed`: rendering data split across ranks, checked against
//! one process rendering all of it, bit for bit.
//!
//! ```text
//! # ranks as threads of one process (no MPI needed)
//! rt distributed --ranks 4 --shadows --ao 4
//! # ranks as MPI processes (Debian: libopenmpi-dev openmpi-bin libclang-dev)
//! cargo build --release -p rt-cli --features mpi
//! mpirun -np 4 target/release/rt distributed --shadows --ao 4 --schedule radix-3
//! ```
//!
//! **Surfaces** (the default): the terrain is cut into slabs of triangles
//! by centroid along its longest axis; each rank builds a BVH over its
//! slab only, shades the pixels its slab covers with shadow and AO rays
//! answered by every rank whose region they cross (see [`surface`]), and
//! the frames are z-composited.
//!
//! The image is written by rank 0, which also renders the whole mesh in
//! one process and compares: the program exits non-zero if one bit of
//! depth or colour differs.

pub mod surface;

use std::{path::PathBuf, time::Instant};

use anyhow::{anyhow, bail};
use rt_composite::{Communicator, Schedule};
use rt_core::{Frame, Pixel};

use crate::{image::write_png, parse};

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

/// A positive, finite length.
fn positive(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("`{s}`: must be a finite number > 0")),
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
    #[arg(long, value_parser = positive)]
    pub ao_distance: Option<f32>,
    /// Seed of the AO directions.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Compositing schedule: direct-send, binary-swap or radix-K (K ≥ 2).
    #[arg(long, value_parser = schedule, default_value = "binary-swap")]
    pub schedule: Schedule,
    /// PNG rank 0 writes.
    #[arg(long, default_value = "out/distributed.png")]
    pub out: PathBuf,
}

impl Args {
    fn surface_job(&self) -> surface::SurfaceJob {
        surface::SurfaceJob {
            size: self.size,
            grid: self.grid,
            shadows: self.shadows,
            ao: self.ao,
            ao_distance: self.ao_distance,
            seed: self.seed,
            schedule: self.schedule,
        }
    }
}

/// What one rank does; rank 0 returns the image.
fn rank_main<C: Communicator>(comm: &C, o: &Args) -> anyhow::Result<Option<Frame>> {
    let (rank, ranks) = (comm.rank(), comm.size());
    let t = Instant::now();
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
    Ok(image)
}

/// Rank 0's check against the whole data rendered in one process.
fn check(composited: &Frame, o: &Args) -> anyhow::Result<()> {
    write_png(composited, &o.out)?;
    let whole = surface::single(&o.surface_job())?;
    let bits = |p: &Pixel| (p.color.map(f32::to_bits), p.depth.to_bits());
    let differ =
        composited.pixels().iter().zip(whole.pixels()).filter(|(a, b)| bits(a) != bits(b)).count();
    let covered = whole.pixels().iter().filter(|p| p.depth.is_finite()).count();
    println!(
        "wrote {}: {}×{}, {covered} pixels covered; differs from the single-process render in {differ} pixels (depth and colour compared bit for bit)",
        o.out.display(),
        o.size.0,
        o.size.1
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
    let comm = MpiComm::new(&world, std::time::Duration::from_secs(60));
    let result = rank_main(&comm, o).and_then(|f| f.map_or(Ok(()), |f| check(&f, o)));
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
    let comms = ThreadComm::group(o.ranks as usize, std::time::Duration::from_secs(60));
    let results: Vec<anyhow::Result<Option<Frame>>> = std::thread::scope(|s| {
        let handles: Vec<_> =
            comms.into_iter().map(|c| s.spawn(move || rank_main(&c, o))).collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err(anyhow!("a rank panicked"))))
            .collect()
    });
    let mut image = None;
    for r in results {
        if let Some(f) = r? {
            image = Some(f);
        }
    }
    check(&image.ok_or_else(|| anyhow!("no rank returned the image"))?, o)
}
