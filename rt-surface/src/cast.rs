//! Rays cast at a triangle mesh in batches: the queries a mesh-processing
//! user asks of a ray tracer (trimesh's `ray` module, PyVista's
//! `ray_trace`), over rt's watertight traversal. A [`RayCaster`] is built
//! once per mesh (or loaded from its bytes) and answers, for a batch of
//! rays, the first hit of each, whether each hits anything, or every
//! surface crossing along each.
//!
//! A ray with a NaN or infinite coordinate, or a zero direction, hits
//! nothing (it does not fail the batch). With feature `parallel` a batch
//! is split over rayon's threads; each ray's answer is computed alone, so
//! the answers are the same at any thread count.

use alloc::vec::Vec;

use rt_accel::{BuildError, BuildParams, Bvh, LoadError, TriPacket, build_triangles};
use rt_core::{Hit, Ray, glam::Vec3};

/// A triangle mesh ready for rays: its BVH (the triangles are inside it,
/// so the caster needs nothing else, and its bytes are the whole of it).
#[derive(Debug)]
pub struct RayCaster {
    bvh: Bvh<TriPacket>,
}

/// Rays a batch hands each thread at once.
#[cfg(feature = "parallel")]
const CHUNK: usize = 256;

impl RayCaster {
    /// The caster of the mesh with vertices `positions` and triangles
    /// `triangles` (indices into `positions`; zero-area triangles are left
    /// out, since no ray can hit them).
    ///
    /// # Errors
    /// A NaN or infinite vertex that a triangle uses, an index out of
    /// range, more triangles than a BVH addresses.
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<Self, BuildError> {
        Ok(Self { bvh: build_triangles(positions, triangles, &BuildParams::medium())? })
    }

    /// The caster saved by [`RayCaster::to_bytes`].
    ///
    /// # Errors
    /// Bytes that are not a triangle BVH of this version, or that fail its
    /// checks.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, LoadError> {
        Ok(Self { bvh: Bvh::from_bytes(bytes)? })
    }

    /// The caster as bytes (its BVH and triangles), to load with
    /// [`RayCaster::from_bytes`].
    #[must_use]
    pub fn to_bytes(&self) -> Vec<u8> {
        self.bvh.to_bytes()
    }

    /// Triangles of the mesh it was built from (zero-area ones included).
    #[must_use]
    pub fn triangle_count(&self) -> u32 {
        self.bvh.prim_count()
    }

    /// The first hit of each ray within its `[t_min, t_max]` (`prim` is
    /// the triangle's index, `uv` its barycentric coordinates of vertices
    /// 1 and 2).
    #[must_use]
    pub fn first(&self, rays: &[Ray]) -> Vec<Option<Hit>> {
        let view = self.bvh.as_ref();
        map(rays, |r| view.closest_hit(r))
    }

    /// The distance and triangle of each ray's first hit, without the
    /// rest of [`RayCaster::first`]'s record (cheaper: no point, normal
    /// or barycentrics).
    #[must_use]
    pub fn nearest(&self, rays: &[Ray]) -> Vec<Option<(f32, u32)>> {
        let view = self.bvh.as_ref();
        map(rays, |r| view.closest_t(r).map(|h| (h.t, h.prim)))
    }

    /// Whether each ray hits anything within its `[t_min, t_max]`.
    #[must_use]
    pub fn any(&self, rays: &[Ray]) -> Vec<bool> {
        let view = self.bvh.as_ref();
        map(rays, |r| view.occluded(r))
    }

    /// Every surface crossing along each ray, nearest first, at most
    /// `most` a ray: `(ray index, hit)`, in the rays' order. A ray that
    /// crosses at a shared edge or vertex crosses once there (the hit is
    /// the nearest of the triangles that meet there; the others, whose
    /// points agree with it within rounding, are skipped), so a ray
    /// through a closed mesh crosses it an even number of times. Two
    /// surfaces closer than 16 ulps of the coordinates count once.
    #[must_use]
    pub fn all(&self, rays: &[Ray], most: usize) -> Vec<(u32, Hit)> {
        let view = self.bvh.as_ref();
        let per_ray = map(rays, |r| {
            let mut hits: Vec<Hit> = Vec::new();
            let mut ray = *r;
            // Each step moves past one hit; a crossing met again (its
            // other triangles) is skipped, so this bounds the steps too.
            for _ in 0..most.saturating_mul(8).saturating_add(64) {
                if hits.len() >= most {
                    break;
                }
                let Some(h) = view.closest_hit(&ray) else { break };
                if !hits.last().is_some_and(|last| same_crossing(last, &h)) {
                    hits.push(h);
                }
                // Past this hit: the next representable parameter.
                ray.t_min = h.t.next_up();
                if ray.t_min > ray.t_max {
                    break;
                }
            }
            hits
        });
        let mut out = Vec::new();
        for (i, hits) in per_ray.into_iter().enumerate() {
            out.extend(hits.into_iter().map(|h| (i as u32, h)));
        }
        out
    }
}

/// Whether `b` is the crossing `a` already is: another triangle at a
/// shared edge or vertex, whose point differs by rounding only. Their
/// barycentrics round apart too, so the bound is the points' own error
/// bounds (four times over) and 16 ulps of the larger coordinate: two
/// surfaces closer than that count as one crossing.
fn same_crossing(a: &Hit, b: &Hit) -> bool {
    let gap = (a.position - b.position).abs();
    let scale = a.position.abs().max_element().max(b.position.abs().max_element());
    let bound =
        (a.position_error + b.position_error) * 4.0 + Vec3::splat(scale * 16.0 * f32::EPSILON);
    gap.cmple(bound).all()
}

/// `f` of every ray, in order (over rayon's threads with `parallel`).
fn map<T: Send>(rays: &[Ray], f: impl Fn(&Ray) -> T + Sync) -> Vec<T> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        rays.par_chunks(CHUNK).flat_map_iter(|c| c.iter().map(&f)).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        rays.iter().map(f).collect()
    }
}
