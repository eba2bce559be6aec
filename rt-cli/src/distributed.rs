//! Sort-last distributed rendering: each rank renders its share of a mesh,
//! `rt_composite` merges the frames by depth, rank 0 writes the PNG and
//! checks it, pixel for pixel, against one process rendering the whole
//! mesh.
//!
//! ```text
//! # ranks as threads of one process (no MPI needed)
//! rt distributed --ranks 4 --schedule binary-swap
//! # ranks as MPI processes (Debian: libopenmpi-dev openmpi-bin libclang-dev)
//! cargo build --release -p rt-cli --features mpi
//! mpirun -np 4 target/release/rt distributed --schedule radix-3
//! ```
//!
//! The mesh is cut into `N` slabs of triangles by centroid along its
//! longest axis; each rank builds a BVH over its slab only. Shading is
//! local (ambient + a directional light, no shadow or occlusion rays,
//! which would need the other ranks' geometry) and one sample at each
//! pixel centre, so every pixel is the nearest hit of the same ray over
//! the same triangles with the same arithmetic: the composite must equal
//! the whole-mesh render bit for bit, depth and colour. The program exits
//! non-zero if one bit differs.

use std::{path::PathBuf, time::Instant};

use anyhow::{Context, anyhow, bail};
use rt_composite::{Communicator, Mode, Schedule, composite};
use rt_core::{Camera, ColorMap, Frame, Pixel, Projection, glam::Vec3};
use rt_surface::{Light, Mesh, Paint, Renderer, Settings, SurfaceScene};

use crate::{image::write_png, parse, scenes};

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
    /// Compositing schedule: direct-send, binary-swap or radix-K (K ≥ 2).
    #[arg(long, value_parser = schedule, default_value = "binary-swap")]
    pub schedule: Schedule,
    /// PNG rank 0 writes.
    #[arg(long, default_value = "out/distributed.png")]
    pub out: PathBuf,
}

/// The whole terrain, coloured by height, and the colour map's range.
fn terrain(grid: u32) -> anyhow::Result<(Mesh, (f32, f32))> {
    let t = scenes::terrain(grid);
    let heights: Vec<f32> = t.positions().iter().map(|p| p.y).collect();
    let range = heights.iter().fold((f32::MAX, f32::MIN), |(a, b), &h| (a.min(h), b.max(h)));
    let mesh = Mesh::from(t).with_scalars(heights)?;
    Ok((mesh, range))
}

/// Slab `rank` of `ranks`: the triangles whose centroids fall in that
/// share of the order along the mesh's longest axis, with only the
/// vertices they use (values copied, so shading is unchanged).
fn share(mesh: &Mesh, rank: usize, ranks: usize) -> anyhow::Result<Mesh> {
    let (p, idx) = (mesh.positions(), mesh.indices());
    let (lo, hi) = p.iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let axis = (hi - lo).max_position();
    let centroid = |t: &[u32; 3]| t.iter().map(|&i| p[i as usize][axis]).sum::<f32>();
    let mut order: Vec<usize> = (0..idx.len()).collect();
    order.sort_by(|&a, &b| centroid(&idx[a]).total_cmp(&centroid(&idx[b])).then(a.cmp(&b)));
    let slab = &order[idx.len() * rank / ranks..idx.len() * (rank + 1) / ranks];
    let mut remap = vec![u32::MAX; p.len()];
    let (mut positions, mut scalars, mut indices) = (Vec::new(), Vec::new(), Vec::new());
    let all_scalars = mesh.scalars().unwrap_or_default();
    for &t in slab {
        indices.push(idx[t].map(|v| {
            let v = v as usize;
            if remap[v] == u32::MAX {
                remap[v] = positions.len() as u32;
                positions.push(p[v]);
                scalars.push(all_scalars.get(v).copied().unwrap_or(0.0));
            }
            remap[v]
        }));
    }
    Ok(Mesh::new(positions, indices, Some(scalars))?)
}

/// One sample at each pixel centre of `mesh`, lit locally.
fn render(mesh: Mesh, range: (f32, f32), size: (u32, u32)) -> anyhow::Result<Frame> {
    let paint = Paint::Mapped(ColorMap::viridis().with_range(range.0, range.1)?);
    let world = SurfaceScene::from_mesh(mesh, paint)?;
    let cam = Camera::look_at(
        Vec3::new(1.5, 1.3, 2.1),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 40f32.to_radians() },
        size.0,
        size.1,
    )?;
    let settings = Settings {
        lights: vec![
            Light::Ambient { color: [0.35; 3] },
            Light::Directional { direction: Vec3::new(-0.5, 1.0, 0.35), color: [0.75; 3] },
        ],
        shadows: false,
        ao_samples: 0,
        ..Settings::default()
    };
    let mut renderer = Renderer::new(cam, settings)?;
    renderer.render_pass(&world);
    Ok(renderer.frame()?)
}

/// What one rank does: render its share, composite; rank 0 gets the image.
fn rank_main<C: Communicator>(comm: &C, o: &Args) -> anyhow::Result<Option<Frame>> {
    let (rank, ranks) = (comm.rank(), comm.size());
    let (mesh, range) = terrain(o.grid)?;
    let mine = share(&mesh, rank, ranks)?;
    let triangles = mine.indices().len();
    let t0 = Instant::now();
    let frame = render(mine, range, o.size)?;
    let rendered = t0.elapsed().as_secs_f64();
    let active =
        frame.pixels().iter().filter(|p| !rt_composite::Fragment::is_background(*p)).count();
    let t1 = Instant::now();
    let (image, stats) =
        composite(comm, frame.pixels(), o.size.0, o.size.1, o.schedule, &Mode::Depth)
            .with_context(|| format!("rank {rank}"))?;
    println!(
        "rank {rank}/{ranks}: {triangles} triangles, {active} pixels covered, render {rendered:.3} s, \
         composite {:.3} s, sent {} bytes in {} messages",
        t1.elapsed().as_secs_f64(),
        stats.bytes_sent,
        stats.messages,
    );
    let Some(pixels) = image else { return Ok(None) };
    let mut out = Frame::new(o.size.0, o.size.1)?;
    out.pixels_mut().copy_from_slice(&pixels);
    Ok(Some(out))
}

/// Rank 0's check against the whole mesh rendered in one process.
fn check(composited: &Frame, o: &Args) -> anyhow::Result<()> {
    write_png(composited, &o.out)?;
    let (mesh, range) = terrain(o.grid)?;
    let whole = render(mesh, range, o.size)?;
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
