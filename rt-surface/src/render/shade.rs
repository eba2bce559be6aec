//! One pixel's light: the camera ray, translucent layers composited front
//! to back, Blinn–Phong from each light with hard shadows, ambient
//! occlusion and mirror bounces. Each pixel draws from its own random
//! stream, so the image does not depend on which thread renders it.

use alloc::vec::{self, Vec};

use glam::{Vec2, Vec3};
use rt_core::{
    Aabb, Camera, Hit, Ray,
    camera::cosine_hemisphere,
    intersect::{spawn_ray, spawn_ray_to},
    sampling::{Rng, rng_for, uniform2},
};

use super::{Light, Material, RayCounts, Settings, ShadeScene, Surface, TILE};
use crate::math::{powf, sqrt};

pub(super) struct TileResult {
    pub(super) x0: u32,
    pub(super) y0: u32,
    pub(super) w: u32,
    pub(super) pixels: Vec<([f32; 4], f32)>,
    pub(super) counts: RayCounts,
}

/// What one pass shares between tiles.
pub(super) struct Ctx<'a, S> {
    pub(super) scene: &'a S,
    pub(super) camera: &'a Camera,
    pub(super) settings: &'a Settings,
    pub(super) bounds: Aabb,
}

/// Per-pixel state: its random stream, its counts and how its rays are
/// answered.
struct PixelWork {
    rng: Rng,
    counts: RayCounts,
    trace: Trace,
}

/// How a tile's rays are answered. A tile that asks occlusion queries is
/// walked twice: the first walk traces its closest hits and gathers its
/// shadow and AO rays (answering "open"), one
/// [`SceneQuery::occluded_batch`](rt_core::SceneQuery::occluded_batch)
/// answers them all (rt-accel walks them through the tree together), and
/// the second walk replays the hits and the answers in order. The queries
/// never depend on the answers: a pixel's shadow rays and AO directions
/// come from its hits and its own random stream, whether or not an earlier
/// one was blocked, and no hit is traced after an occlusion query that
/// depends on it. So the second walk asks exactly what the first gathered,
/// and the frame equals the ray-by-ray one bit for bit.
enum Trace {
    /// The first walk: closest hits as traced, occlusion rays to answer.
    Gather { hits: Vec<Option<Hit>>, rays: Vec<Ray> },
    /// The second walk: the first walk's hits and the answers, in order.
    Replay { hits: vec::IntoIter<Option<Hit>>, answers: vec::IntoIter<bool> },
}

/// A ray no scene is hit by (NaN origin: [`Ray::is_valid`] fails).
const NO_RAY: Ray = Ray { origin: Vec3::NAN, direction: Vec3::Z, t_min: 0.0, t_max: 0.0 };

impl<S: ShadeScene> Ctx<'_, S> {
    pub(super) fn tile(&self, x0: u32, y0: u32, pass: u32) -> TileResult {
        let (w, h) = (self.camera.width, self.camera.height);
        let (tw, th) = (TILE.min(w - x0), TILE.min(h - y0));
        let stream_seed = self.settings.seed ^ u64::from(pass).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        let mut counts = RayCounts::default();
        // Camera rays eight pixels of a row at a time, traced as a packet
        // (`SceneQuery::closest_hit_packet`: the same hits as one by one);
        // each pixel keeps its own random stream for the rest of its path.
        let mut starts: Vec<(Ray, Option<Hit>, Rng)> = Vec::with_capacity((tw * th) as usize);
        for y in y0..y0 + th {
            let mut x = x0;
            while x < x0 + tw {
                let n = (x0 + tw - x).min(8) as usize;
                let mut rays = [NO_RAY; 8];
                let mut streams: [Option<Rng>; 8] = [const { None }; 8];
                for (k, (ray, stream)) in rays.iter_mut().zip(&mut streams).take(n).enumerate() {
                    let px = x + k as u32;
                    let rng = stream
                        .insert(rng_for(stream_seed, u64::from(y) * u64::from(w) + u64::from(px)));
                    let jitter = if pass == 0 { Vec2::splat(0.5) } else { uniform2(rng) };
                    *ray = self.camera.generate_ray(px, y, jitter, uniform2(rng));
                }
                // Rays that miss the scene's box are not traced (`closest`).
                let culled: [bool; 8] = core::array::from_fn(|k| {
                    k < n && self.bounds.intersect_ray(&rays[k]).is_none()
                });
                let traced: [Ray; 8] =
                    core::array::from_fn(|k| if culled[k] { NO_RAY } else { rays[k] });
                let first = self.scene.closest_hit_packet(&traced);
                for (k, stream) in streams.into_iter().take(n).enumerate() {
                    counts.primary += 1;
                    counts.culled += u64::from(culled[k]);
                    if let Some(rng) = stream {
                        starts.push((rays[k], first[k], rng));
                    }
                }
                x += n as u32;
            }
        }
        let trace = Trace::Gather { hits: Vec::new(), rays: Vec::new() };
        let mut pw = PixelWork { rng: rng_for(stream_seed, 0), counts, trace };
        let mut pixels = self.walk(&starts, &mut pw);
        if let Trace::Gather { hits, rays } = pw.trace
            && !rays.is_empty()
        {
            let mut answers = alloc::vec![false; rays.len()];
            self.scene.occluded_batch(&rays, &mut answers);
            let trace = Trace::Replay { hits: hits.into_iter(), answers: answers.into_iter() };
            // Counted in the first walk already.
            let mut replay = PixelWork { rng: pw.rng, counts: RayCounts::default(), trace };
            pixels = self.walk(&starts, &mut replay);
        }
        TileResult { x0, y0, w: tw, pixels, counts: pw.counts }
    }

    /// Each pixel's colour, alpha and depth from its camera ray, first hit
    /// and random stream.
    fn walk(&self, starts: &[(Ray, Option<Hit>, Rng)], pw: &mut PixelWork) -> Vec<([f32; 4], f32)> {
        starts
            .iter()
            .map(|(ray, first, rng)| {
                pw.rng = rng.clone();
                let (rgb, a, depth) = self.path_from(*ray, *first, 0, pw);
                ([rgb.x, rgb.y, rgb.z, a], depth)
            })
            .collect()
    }

    /// The closest hit, not traversing rays that miss the scene's box.
    fn closest(&self, ray: &Ray, pw: &mut PixelWork) -> Option<Hit> {
        let hits = match &mut pw.trace {
            Trace::Replay { hits, .. } => {
                let hit = hits.next();
                debug_assert!(hit.is_some(), "the replay asks what the first walk traced");
                return hit.flatten();
            }
            Trace::Gather { hits, .. } => hits,
        };
        let hit = if self.bounds.intersect_ray(ray).is_none() {
            pw.counts.culled += 1;
            None
        } else {
            self.scene.closest_hit(ray)
        };
        hits.push(hit);
        hit
    }

    /// Whether `ray` is blocked: "no" while gathering (the ray is kept for
    /// the batch), the batch's answer when replaying. Rays that miss the
    /// scene's box are neither gathered nor traced, in both walks.
    fn occluded(&self, ray: &Ray, pw: &mut PixelWork) -> bool {
        if self.bounds.intersect_ray(ray).is_none() {
            pw.counts.culled += 1;
            return false;
        }
        match &mut pw.trace {
            Trace::Replay { answers, .. } => {
                let answer = answers.next();
                debug_assert!(answer.is_some(), "the replay asks what the first walk gathered");
                answer.unwrap_or(false)
            }
            Trace::Gather { rays, .. } => {
                rays.push(*ray);
                false
            }
        }
    }

    /// Premultiplied colour, alpha and depth seen along `ray`: translucent
    /// layers composited front to back.
    fn path(&self, ray: Ray, bounce: u32, pw: &mut PixelWork) -> (Vec3, f32, f32) {
        let first = self.closest(&ray, pw);
        self.path_from(ray, first, bounce, pw)
    }

    /// [`Self::path`] with the closest hit of `ray` already found.
    fn path_from(
        &self,
        mut ray: Ray,
        first: Option<Hit>,
        bounce: u32,
        pw: &mut PixelWork,
    ) -> (Vec3, f32, f32) {
        let (mut rgb, mut alpha, mut depth) = (Vec3::ZERO, 0.0f32, f32::INFINITY);
        // Distance along the first ray to the current ray's origin.
        let mut travelled = 0.0;
        let mut layers = 0;
        let mut found = first;
        while let Some(hit) = found {
            let s = self.scene.surface(&hit);
            let opacity = s.material.opacity;
            if opacity > 0.0 {
                if depth.is_infinite() {
                    depth = travelled + hit.t;
                }
                let c = self.shade(&ray, &hit, &s, bounce, pw);
                rgb += (1.0 - alpha) * opacity * c;
                alpha += (1.0 - alpha) * opacity;
            }
            if alpha >= 1.0 || layers >= self.settings.max_layers {
                break;
            }
            // On through the surface, same direction.
            layers += 1;
            pw.counts.transparency += 1;
            let next = spawn_ray(hit.position, hit.position_error, hit.normal, ray.direction);
            travelled += (next.origin - ray.origin).length();
            ray = next;
            found = self.closest(&ray, pw);
        }
        (rgb, alpha, depth)
    }

    /// Linear RGB leaving the surface toward the viewer.
    fn shade(&self, ray: &Ray, hit: &Hit, s: &Surface, bounce: u32, pw: &mut PixelWork) -> Vec3 {
        let d = ray.direction.normalize();
        // Both normals face the viewer.
        let ng = if hit.normal.dot(d) > 0.0 { -hit.normal } else { hit.normal };
        let n = if s.normal.dot(ng) < 0.0 { -s.normal } else { s.normal };
        let (p, err) = (hit.position, hit.position_error);
        let albedo = Vec3::from_array(s.albedo);
        let m = &s.material;
        let mut ao = None;
        let mut c = Vec3::ZERO;
        for light in &self.settings.lights {
            match *light {
                Light::Ambient { color } => {
                    let k = *ao.get_or_insert_with(|| self.ambient_occlusion(p, err, ng, pw));
                    c += k * albedo * Vec3::from_array(color);
                }
                Light::Directional { direction: l, color } => {
                    let lit = self.settings.shadows.then(|| spawn_ray(p, err, ng, l));
                    c += self.direct(n, d, l, 1.0, lit, albedo, m, color, pw);
                }
                Light::Point { position, color } => {
                    let to = position - p;
                    let d2 = to.length_squared();
                    if d2 > 0.0 {
                        let lit = self.settings.shadows.then(|| spawn_ray_to(p, err, ng, position));
                        c += self.direct(n, d, to / sqrt(d2), 1.0 / d2, lit, albedo, m, color, pw);
                    }
                }
            }
        }
        if m.mirror > 0.0 && bounce < self.settings.max_bounces {
            pw.counts.reflection += 1;
            let r = d - 2.0 * d.dot(n) * n;
            let (rgb, a, _) = self.path(spawn_ray(p, err, ng, r), bounce + 1, pw);
            let seen = rgb + (1.0 - a) * Vec3::from_array(self.settings.environment);
            c = (1.0 - m.mirror) * c + m.mirror * seen;
        }
        c
    }

    /// Blinn–Phong from one light in direction `l` (unit) scaled by
    /// `falloff`; `shadow` is the ray to test when shadows are on.
    #[allow(clippy::too_many_arguments)]
    fn direct(
        &self,
        n: Vec3,
        d: Vec3,
        l: Vec3,
        falloff: f32,
        shadow: Option<Ray>,
        albedo: Vec3,
        m: &Material,
        color: [f32; 3],
        pw: &mut PixelWork,
    ) -> Vec3 {
        let cos = n.dot(l);
        if cos <= 0.0 {
            return Vec3::ZERO;
        }
        if let Some(r) = shadow {
            pw.counts.shadow += 1;
            if self.occluded(&r, pw) {
                return Vec3::ZERO;
            }
        }
        let half = (l - d).normalize_or_zero();
        let spec = if m.specular > 0.0 {
            m.specular * powf(n.dot(half).max(0.0), m.shininess)
        } else {
            0.0
        };
        falloff * Vec3::from_array(color) * (m.diffuse * cos * albedo + Vec3::splat(spec))
    }

    /// The unoccluded fraction of `ao_samples` cosine-weighted rays about
    /// `ng` (1 with AO off).
    fn ambient_occlusion(&self, p: Vec3, err: Vec3, ng: Vec3, pw: &mut PixelWork) -> f32 {
        let n = self.settings.ao_samples;
        if n == 0 {
            return 1.0;
        }
        let (t, b) = ng.any_orthonormal_pair();
        let mut open = 0;
        for _ in 0..n {
            let l = cosine_hemisphere(uniform2(&mut pw.rng));
            let w = l.x * t + l.y * b + l.z * ng;
            let mut r = spawn_ray(p, err, ng, w);
            r.t_max = self.settings.ao_distance;
            pw.counts.ao += 1;
            if !self.occluded(&r, pw) {
                open += 1;
            }
        }
        open as f32 / n as f32
    }
}
