//! Surfaces across ranks: each rank owns a slab of the terrain's
//! triangles, renders the pixels its own geometry covers, and resolves
//! their shadow and ambient-occlusion rays against every rank's geometry
//! (`rt_composite::resolve_occlusion`); the frames are then z-composited.
//!
//! Shading with global occlusion is done in two renders of the rank's
//! pixels (`rt_surface::RecordOcclusion`, then `AnsweredOcclusion`): the
//! first records the occlusion rays, the ranks answer them together, the
//! second shades with the answers. A pixel's rays and random numbers do
//! not depend on the answers, and each answer is the whole mesh's (the OR
//! of watertight per-rank answers), so the composite equals one process
//! rendering the whole mesh, bit for bit, depth and colour.
//!
//! A rank shades every pixel its geometry covers, also those another
//! rank's nearer geometry hides; this overdraw is the price of not
//! compositing depth before shading (which would need a second
//! composite). The terrain, seen from above, has little of it.

use std::time::Instant;

use anyhow::{Context, anyhow, bail};
use rayon::prelude::*;
use rt_composite::{
    Communicator, OcclusionStats, Operator, Schedule, Stats, composite, exchange::all_gather,
    resolve_occlusion,
};
use rt_core::{Aabb, Camera, ColorMap, Frame, Projection, SceneQuery, glam::Vec3};
use rt_surface::{
    AnsweredOcclusion, Light, Mesh, Paint, RecordOcclusion, Renderer, Settings, SurfaceScene,
};

use crate::scenes;

/// What to render: the built-in terrain, its lighting and the image.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceJob {
    /// Image size in pixels.
    pub size: (u32, u32),
    /// The terrain has `grid × grid` vertices.
    pub grid: u32,
    /// Hard shadows from the directional light.
    pub shadows: bool,
    /// Ambient-occlusion rays per visible hit (0: off).
    pub ao: u32,
    /// Longest AO ray; `None`: 5 % of the scene's diagonal.
    pub ao_distance: Option<f32>,
    /// Seed of the AO directions.
    pub seed: u64,
    /// Compositing schedule.
    pub schedule: Schedule,
}

/// What one rank did, and what it cost.
#[derive(Clone, Debug, Default)]
pub struct SurfaceRank {
    /// Triangles this rank owns.
    pub triangles: usize,
    /// Pixels its geometry covers.
    pub covered: usize,
    /// Seconds: first render (recording), occlusion exchange, second
    /// render, composite.
    pub seconds: [f64; 4],
    /// Occlusion queries and their messages.
    pub occlusion: OcclusionStats,
    /// The composite's messages.
    pub composite: Stats,
}

/// Queries per peer per round (32 bytes each: at most 2 MiB a message).
const BATCH: usize = 1 << 16;

/// The most occlusion rays one run may record (32 bytes each, held twice
/// while they are sorted and answered).
pub const MAX_OCCLUSION_RAYS: u64 = 1 << 26;

impl SurfaceJob {
    /// Refuses a job whose occlusion rays would not fit in memory.
    ///
    /// # Errors
    /// More than [`MAX_OCCLUSION_RAYS`] rays.
    pub fn check(&self) -> anyhow::Result<()> {
        let pixels = u64::from(self.size.0) * u64::from(self.size.1);
        let rays = pixels * (u64::from(self.ao) + u64::from(self.shadows));
        if rays > MAX_OCCLUSION_RAYS {
            bail!(
                "{rays} shadow and AO rays is more than a distributed run records ({MAX_OCCLUSION_RAYS}); lower --size or --ao"
            );
        }
        Ok(())
    }
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

fn scene(mesh: Mesh, range: (f32, f32)) -> anyhow::Result<SurfaceScene<'static>> {
    let paint = Paint::Mapped(ColorMap::viridis().with_range(range.0, range.1)?);
    Ok(SurfaceScene::from_mesh(mesh, paint)?)
}

/// The camera and settings every rank (and the single process) uses.
fn setup(job: &SurfaceJob, whole: Aabb) -> anyhow::Result<(Camera, Settings)> {
    let cam = Camera::look_at(
        Vec3::new(1.5, 1.3, 2.1),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 40f32.to_radians() },
        job.size.0,
        job.size.1,
    )?;
    let ao_distance = job.ao_distance.unwrap_or_else(|| 0.05 * whole.extent().length());
    let settings = Settings {
        lights: vec![
            Light::Ambient { color: [0.35; 3] },
            Light::Directional { direction: Vec3::new(-0.9, 0.5, 0.35), color: [0.75; 3] },
        ],
        shadows: job.shadows,
        ao_samples: job.ao,
        ao_distance,
        seed: job.seed,
        ..Settings::default()
    };
    Ok((cam, settings))
}

/// One sample at each pixel centre of the whole terrain in one process:
/// the reference the distributed image must equal.
///
/// # Errors
/// Bad settings (e.g. a non-positive AO distance).
pub fn single(job: &SurfaceJob) -> anyhow::Result<Frame> {
    job.check()?;
    let (mesh, range) = terrain(job.grid)?;
    let world = scene(mesh, range)?;
    let (cam, settings) = setup(job, rt_surface::ShadeScene::bounds(&world))?;
    let mut renderer = Renderer::new(cam, settings)?;
    renderer.render_pass(&world);
    Ok(renderer.frame()?)
}

fn encode_box(b: &Aabb) -> Vec<u8> {
    [b.min.to_array(), b.max.to_array()].concat().iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn decode_box(bytes: &[u8]) -> Option<Aabb> {
    let v: Vec<f32> =
        bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    (v.len() == 6).then(|| Aabb::new(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5])))
}

/// What one rank does: render its slab with global shadows and AO,
/// composite; rank 0 gets the image.
///
/// # Errors
/// Any rank's failure (every rank learns of it), or bad settings.
pub fn rank<C: Communicator>(
    comm: &C,
    job: &SurfaceJob,
) -> anyhow::Result<(Option<Frame>, SurfaceRank)> {
    let (me, ranks) = (comm.rank(), comm.size());
    job.check()?;
    let mut report = SurfaceRank::default();
    let (mesh, range) = terrain(job.grid)?;
    let mine = share(&mesh, me, ranks)?;
    drop(mesh);
    report.triangles = mine.indices().len();
    let world = scene(mine, range)?;
    // Every rank's region; the renderer culls against their union.
    let (all, _) = all_gather(comm, &encode_box(&rt_surface::ShadeScene::bounds(&world)))
        .map_err(|e| anyhow!("rank {me}: exchanging regions: {e}"))?;
    let regions: Vec<Aabb> = all
        .iter()
        .enumerate()
        .map(|(r, b)| decode_box(b).ok_or_else(|| anyhow!("rank {r} sent a malformed region")))
        .collect::<anyhow::Result<_>>()?;
    let whole = regions.iter().fold(Aabb::EMPTY, |u, b| u.union(*b));
    let (cam, settings) = setup(job, whole)?;
    let global = settings.shadows || settings.ao_samples > 0;
    let t = Instant::now();
    let frame = if global {
        let record = RecordOcclusion::new(&world, whole);
        Renderer::new(cam, settings.clone())?.render_pass(&record);
        let rays = record.into_queries();
        report.seconds[0] = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (occluded, stats) = resolve_occlusion(comm, &regions, &rays, BATCH, |rays, out| {
            rays.par_iter().zip(out.par_iter_mut()).for_each(|(r, o)| *o = world.occluded(r));
        })
        .map_err(|e| anyhow!("rank {me}: occlusion across ranks: {e}"))?;
        report.occlusion = stats;
        report.seconds[1] = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let answered = AnsweredOcclusion::new(&world, whole, &rays, occluded)?;
        let mut renderer = Renderer::new(cam, settings)?;
        renderer.render_pass(&answered);
        if answered.unknown() > 0 {
            bail!("rank {me}: {} occlusion rays were not recorded", answered.unknown());
        }
        report.seconds[2] = t.elapsed().as_secs_f64();
        renderer.frame()?
    } else {
        let mut renderer = Renderer::new(cam, settings)?;
        renderer.render_pass(&world);
        report.seconds[2] = t.elapsed().as_secs_f64();
        renderer.frame()?
    };
    report.covered = frame.pixels().iter().filter(|p| p.depth.is_finite()).count();
    let t = Instant::now();
    let (image, stats) =
        composite(comm, frame.pixels(), job.size.0, job.size.1, job.schedule, &Operator::Depth)
            .with_context(|| format!("rank {me}"))?;
    report.seconds[3] = t.elapsed().as_secs_f64();
    report.composite = stats;
    let Some(pixels) = image else { return Ok((None, report)) };
    let mut out = Frame::new(job.size.0, job.size.1)?;
    out.pixels_mut().copy_from_slice(&pixels);
    Ok((Some(out), report))
}
