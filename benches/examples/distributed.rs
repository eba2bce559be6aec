//! Sort-last distributed rendering: each rank renders its share of a mesh,
//! `rt_composite` merges the frames by depth, rank 0 writes the PNG and
//! checks it, pixel for pixel, against one process rendering the whole
//! mesh.
//!
//! ```text
//! # ranks as threads of one process (no MPI needed)
//! cargo run --release -p rt-benches --example distributed -- [options]
//! # ranks as MPI processes (Debian: libopenmpi-dev openmpi-bin libclang-dev)
//! cargo build --release -p rt-benches --features mpi --example distributed
//! mpirun -np 4 target/release/examples/distributed [options]
//!
//!   --ranks N          ranks as threads (default 4; ignored under MPI)
//!   --size WxH         image size (default 640x480)
//!   --grid N           terrain of N×N vertices (default 257)
//!   --schedule S       direct-send, binary-swap (default) or radix-K
//!   --out PATH         PNG to write (default target/distributed.png)
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
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

use std::{path::PathBuf, process::ExitCode, time::Instant};

use glam::Vec3;

use rt_benches::{image::write_png, scenes};
use rt_composite::{Communicator, Mode, Schedule, composite};
use rt_core::{Camera, ColorMap, Frame, Pixel, Projection};
use rt_surface::{Light, Mesh, Paint, Renderer, Settings, SurfaceScene};

const USAGE: &str = "usage: distributed [--ranks N] [--size WxH] [--grid N] \
[--schedule direct-send|binary-swap|radix-K] [--out PATH]";

struct Options {
    ranks: usize,
    size: (u32, u32),
    grid: u32,
    schedule: Schedule,
    out: PathBuf,
}

fn parse_args(args: impl Iterator<Item = String>) -> Result<Options, String> {
    let mut o = Options {
        ranks: 4,
        size: (640, 480),
        grid: 257,
        schedule: Schedule::BinarySwap,
        out: PathBuf::from("target/distributed.png"),
    };
    let mut args = args;
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--ranks" => {
                o.ranks = value()?.parse().map_err(|_| "--ranks: not a count")?;
                if !(1..=256).contains(&o.ranks) {
                    return Err("--ranks: 1 to 256".into());
                }
            }
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once('x').ok_or("--size: WxH")?;
                o.size = (
                    w.parse().map_err(|_| "--size: bad width")?,
                    h.parse().map_err(|_| "--size: bad height")?,
                );
            }
            "--grid" => {
                o.grid = value()?.parse().map_err(|_| "--grid: not a count")?;
                if !(2..=4097).contains(&o.grid) {
                    return Err("--grid: 2 to 4097".into());
                }
            }
            "--schedule" => {
                let v = value()?;
                o.schedule = match v.as_str() {
                    "direct-send" => Schedule::DirectSend,
                    "binary-swap" => Schedule::BinarySwap,
                    s => match s.strip_prefix("radix-").map(str::parse) {
                        Some(Ok(k)) => Schedule::RadixK(k),
                        _ => return Err(format!("--schedule: unknown `{v}`")),
                    },
                };
            }
            "--out" => o.out = PathBuf::from(value()?),
            "-h" | "--help" => return Err(USAGE.into()),
            other => return Err(format!("unknown option `{other}`\n{USAGE}")),
        }
    }
    Ok(o)
}

/// The whole terrain, coloured by height, and the colour map's range.
fn terrain(grid: u32) -> Result<(Mesh, (f32, f32)), String> {
    let t = scenes::terrain(grid);
    let heights: Vec<f32> = t.positions.iter().map(|p| p.y).collect();
    let range = heights.iter().fold((f32::MAX, f32::MIN), |(a, b), &h| (a.min(h), b.max(h)));
    let mesh = Mesh::new(t.positions, t.indices, Some(heights)).map_err(|e| e.to_string())?;
    Ok((mesh, range))
}

/// Slab `rank` of `ranks`: the triangles whose centroids fall in that
/// share of the order along the mesh's longest axis, with only the
/// vertices they use (values copied, so shading is unchanged).
fn share(mesh: &Mesh, rank: usize, ranks: usize) -> Result<Mesh, String> {
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
    Mesh::new(positions, indices, Some(scalars)).map_err(|e| e.to_string())
}

/// One sample at each pixel centre of `mesh`, lit locally.
fn render(mesh: Mesh, range: (f32, f32), size: (u32, u32)) -> Result<Frame, String> {
    let paint =
        Paint::Mapped(ColorMap::viridis().with_range(range.0, range.1).map_err(|e| e.to_string())?);
    let world = SurfaceScene::from_mesh(mesh, paint).map_err(|e| e.to_string())?;
    let cam = Camera::look_at(
        Vec3::new(1.5, 1.3, 2.1),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 40f32.to_radians() },
        size.0,
        size.1,
    )
    .map_err(|e| e.to_string())?;
    let settings = Settings {
        lights: vec![
            Light::Ambient { color: [0.35; 3] },
            Light::Directional { direction: Vec3::new(-0.5, 1.0, 0.35), color: [0.75; 3] },
        ],
        shadows: false,
        ao_samples: 0,
        ..Settings::default()
    };
    let mut renderer = Renderer::new(cam, settings).map_err(|e| e.to_string())?;
    renderer.render_pass(&world);
    renderer.frame().map_err(|e| e.to_string())
}

/// What one rank does: render its share, composite; rank 0 gets the image.
fn rank_main<C: Communicator>(comm: &C, o: &Options) -> Result<Option<Frame>, String> {
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
            .map_err(|e| format!("rank {rank}: {e}"))?;
    println!(
        "rank {rank}/{ranks}: {triangles} triangles, {active} pixels covered, render {rendered:.3} s, \
         composite {:.3} s, sent {} bytes in {} messages",
        t1.elapsed().as_secs_f64(),
        stats.bytes_sent,
        stats.messages,
    );
    let Some(pixels) = image else { return Ok(None) };
    let mut out = Frame::new(o.size.0, o.size.1).map_err(|e| e.to_string())?;
    out.pixels_mut().copy_from_slice(&pixels);
    Ok(Some(out))
}

/// Rank 0's check against the whole mesh rendered in one process.
fn check(composited: &Frame, o: &Options) -> Result<(), String> {
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
        return Err("nothing in view".into());
    }
    if differ == 0 { Ok(()) } else { Err(format!("{differ} pixels differ")) }
}

#[cfg(feature = "mpi")]
fn run(o: &Options) -> Result<(), String> {
    use rt_composite::{MpiComm, mpi::traits::Communicator as _};
    let universe = rt_composite::mpi::initialize().ok_or("MPI was already initialised")?;
    let world = universe.world();
    let comm = MpiComm::new(&world, std::time::Duration::from_secs(60));
    let result = rank_main(&comm, o).and_then(|f| f.map_or(Ok(()), |f| check(&f, o)));
    // Every rank learns whether rank 0's check passed.
    let mut ok = u8::from(result.is_ok());
    rt_composite::mpi::traits::Root::broadcast_into(&world.process_at_rank(0), &mut ok);
    match result {
        Err(e) => Err(e),
        Ok(()) if ok == 0 => Err("rank 0 failed".into()),
        Ok(()) => Ok(()),
    }
}

#[cfg(not(feature = "mpi"))]
fn run(o: &Options) -> Result<(), String> {
    use rt_composite::ThreadComm;
    let comms = ThreadComm::group(o.ranks, std::time::Duration::from_secs(60));
    let results: Vec<Result<Option<Frame>, String>> = std::thread::scope(|s| {
        let handles: Vec<_> =
            comms.into_iter().map(|c| s.spawn(move || rank_main(&c, o))).collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| Err("a rank panicked".into())))
            .collect()
    });
    let mut image = None;
    for r in results {
        if let Some(f) = r? {
            image = Some(f);
        }
    }
    check(&image.ok_or("no rank returned the image")?, o)
}

fn main() -> ExitCode {
    let result = parse_args(std::env::args().skip(1)).and_then(|o| run(&o));
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("distributed: {e}");
            ExitCode::FAILURE
        }
    }
}
