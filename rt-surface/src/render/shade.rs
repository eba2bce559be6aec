//! One pixel's light: the camera ray, translucent layers composited front
//! to back, Blinn–Phong from each light with hard shadows, ambient
//! occlusion and mirror bounces. Each pixel draws from its own random
//! stream, so the image does not depend on which thread renders it.

use alloc::vec::Vec;

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

/// Per-pixel state: its random stream, its counts, and the tile's terms
/// waiting on occlusion answers.
struct PixelWork {
    rng: Rng,
    counts: RayCounts,
    /// The pixel being walked (its index in the tile).
    pixel: u32,
    pending: Pending,
}

/// Light that reaches a pixel only through unoccluded rays: shadow and AO
/// rays are not traced where shading asks about them but gathered for the
/// whole tile, answered by one
/// [`SceneQuery::occluded_batch`](rt_core::SceneQuery::occluded_batch)
/// per kind (rt-accel walks groups of them through the tree together,
/// faster the more alike a group's rays are: shadow rays toward one light
/// share their direction, AO rays are short), and their terms added
/// afterwards. This works because a pixel's colour is linear in each
/// answer, and nothing else depends on one: a pixel's shadow rays and AO
/// directions come from its hits and its own random stream, whether or not
/// an earlier one was blocked.
struct Pending {
    /// The rays of each kind ([`SHADOW`], [`AO`]), term after term.
    rays: [Vec<Ray>; 2],
    /// The terms, in the order of their rays.
    terms: Vec<Term>,
}

/// [`Pending::rays`] of shadow rays.
const SHADOW: usize = 0;
/// [`Pending::rays`] of AO rays.
const AO: usize = 1;

/// Light that counts in proportion to the open rays among `total`, of
/// which `traced` wait in `Pending::rays[kind]` (the others are open).
struct Term {
    pixel: u32,
    rgb: Vec3,
    traced: u32,
    total: u32,
    kind: usize,
}

impl<S: ShadeScene> Ctx<'_, S> {
    pub(super) fn tile(&self, x0: u32, y0: u32, pass: u32) -> TileResult {
        let (w, h) = (self.camera.width, self.camera.height);
        let (tw, th) = (TILE.min(w - x0), TILE.min(h - y0));
        let area = (tw * th) as usize;
        let mut pixels = Vec::with_capacity(area);
        let stream_seed = self.settings.seed ^ u64::from(pass).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        // Room for the rays of one opaque layer a pixel: growing from
        // nothing, the batches were copied about ten times a tile.
        let shadowed = if self.settings.shadows {
            self.settings.lights.iter().filter(|l| !matches!(l, Light::Ambient { .. })).count()
        } else {
            0
        };
        let ao = self.settings.ao_samples as usize;
        let pending = Pending {
            rays: [Vec::with_capacity(area * shadowed), Vec::with_capacity(area * ao)],
            terms: Vec::with_capacity(area * (shadowed + usize::from(ao > 0))),
        };
        let mut pw = PixelWork {
            rng: rng_for(stream_seed, 0),
            counts: RayCounts::default(),
            pixel: 0,
            pending,
        };
        // The tile's camera rays at once, through
        // `SceneQuery::closest_hit_batch` (a BVH walks runs of coherent
        // rays through the tree together: the same hits as one by one);
        // each pixel keeps its own random stream for the rest of its path.
        let mut rays = Vec::with_capacity(area);
        let mut streams = Vec::with_capacity(area);
        for y in y0..y0 + th {
            for x in x0..x0 + tw {
                let mut rng = rng_for(stream_seed, u64::from(y) * u64::from(w) + u64::from(x));
                let jitter = if pass == 0 { Vec2::splat(0.5) } else { uniform2(&mut rng) };
                rays.push(self.camera.generate_ray(x, y, jitter, uniform2(&mut rng)));
                streams.push(rng);
            }
        }
        // Rays that miss the scene's box are not traced (`closest`).
        let culled: Vec<bool> =
            rays.iter().map(|r| self.bounds.intersect_ray(r).is_none()).collect();
        let traced: Vec<Ray> =
            rays.iter().zip(&culled).filter(|&(_, &c)| !c).map(|(r, _)| *r).collect();
        let mut hits = alloc::vec![None; traced.len()];
        self.scene.closest_hit_batch(&traced, &mut hits);
        let mut hits = hits.into_iter();
        for ((ray, rng), culled) in rays.into_iter().zip(streams).zip(culled) {
            let first = if culled { None } else { hits.next().flatten() };
            pw.rng = rng;
            pw.pixel = pixels.len() as u32;
            pw.counts.primary += 1;
            pw.counts.culled += u64::from(culled);
            let (rgb, a, depth) = self.path_from(ray, first, 0, 1.0, &mut pw);
            pixels.push(([rgb.x, rgb.y, rgb.z, a], depth));
        }
        let Pending { rays, terms } = pw.pending;
        if !terms.is_empty() {
            let mut answers = rays.map(|rays| {
                let mut occluded = alloc::vec![false; rays.len()];
                self.scene.occluded_batch(&rays, &mut occluded);
                occluded.into_iter()
            });
            for Term { pixel, rgb, traced, total, kind } in terms {
                let blocked = answers[kind].by_ref().take(traced as usize).filter(|&o| o).count();
                let open = total - blocked as u32;
                if open > 0 {
                    let add = rgb * (open as f32 / total as f32);
                    let p = &mut pixels[pixel as usize].0;
                    for (c, a) in p.iter_mut().zip(add.to_array()) {
                        *c += a;
                    }
                }
            }
        }
        TileResult { x0, y0, w: tw, pixels, counts: pw.counts }
    }

    /// The closest hit, not traversing rays that miss the scene's box.
    fn closest(&self, ray: &Ray, pw: &mut PixelWork) -> Option<Hit> {
        if self.bounds.intersect_ray(ray).is_none() {
            pw.counts.culled += 1;
            return None;
        }
        self.scene.closest_hit(ray)
    }

    /// Keeps `ray` for the tile's batch of its `kind` unless it misses the
    /// scene's box (then it is open without being traced).
    fn gather(&self, ray: Ray, kind: usize, pw: &mut PixelWork) {
        if self.bounds.intersect_ray(&ray).is_some() {
            pw.pending.rays[kind].push(ray);
        } else {
            pw.counts.culled += 1;
        }
    }

    /// Leaves the light `rgb` of one term (weighted for its pixel) for the
    /// tile's batch, to count in proportion to the open rays among the
    /// `total` of `kind` just gathered, of which those from `first` on
    /// were kept. Returns whether anything was left (if not, the term is
    /// all open).
    fn term(&self, first: usize, total: u32, rgb: Vec3, kind: usize, pw: &mut PixelWork) -> bool {
        let traced = (pw.pending.rays[kind].len() - first) as u32;
        if traced > 0 {
            pw.pending.terms.push(Term { pixel: pw.pixel, rgb, traced, total, kind });
        }
        traced > 0
    }

    /// Premultiplied colour, alpha and depth seen along `ray`, `weight`
    /// being its share of the pixel: translucent layers composited front to
    /// back. Light behind shadow and AO rays is left for the tile's batch.
    fn path(&self, ray: Ray, bounce: u32, weight: f32, pw: &mut PixelWork) -> (Vec3, f32, f32) {
        let first = self.closest(&ray, pw);
        self.path_from(ray, first, bounce, weight, pw)
    }

    /// [`Self::path`] with the closest hit of `ray` already found.
    fn path_from(
        &self,
        mut ray: Ray,
        first: Option<Hit>,
        bounce: u32,
        weight: f32,
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
                let share = (1.0 - alpha) * opacity;
                let c = self.shade(&ray, &hit, &s, bounce, weight * share, pw);
                rgb += share * c;
                alpha += share;
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

    /// Linear RGB leaving the surface toward the viewer, `weight` being
    /// its share of the pixel.
    fn shade(
        &self,
        ray: &Ray,
        hit: &Hit,
        s: &Surface,
        bounce: u32,
        weight: f32,
        pw: &mut PixelWork,
    ) -> Vec3 {
        let d = ray.direction.normalize();
        // Both normals face the viewer.
        let ng = if hit.normal.dot(d) > 0.0 { -hit.normal } else { hit.normal };
        let n = if s.normal.dot(ng) < 0.0 { -s.normal } else { s.normal };
        let (p, err) = (hit.position, hit.position_error);
        let albedo = Vec3::from_array(s.albedo);
        let m = &s.material;
        let mirror = m.mirror > 0.0 && bounce < self.settings.max_bounces;
        // The share of this surface's own light (the rest is the mirror's).
        let own = if mirror { weight * (1.0 - m.mirror) } else { weight };
        let mut ambient = None;
        let mut c = Vec3::ZERO;
        for light in &self.settings.lights {
            match *light {
                Light::Ambient { color } => {
                    *ambient.get_or_insert(Vec3::ZERO) += Vec3::from_array(color);
                }
                Light::Directional { direction: l, color } => {
                    let lit = self.settings.shadows.then(|| spawn_ray(p, err, ng, l));
                    c += self.direct(n, d, l, 1.0, lit, albedo, m, color, own, pw);
                }
                Light::Point { position, color } => {
                    let to = position - p;
                    let d2 = to.length_squared();
                    if d2 > 0.0 {
                        let lit = self.settings.shadows.then(|| spawn_ray_to(p, err, ng, position));
                        c += self.direct(
                            n,
                            d,
                            to / sqrt(d2),
                            1.0 / d2,
                            lit,
                            albedo,
                            m,
                            color,
                            own,
                            pw,
                        );
                    }
                }
            }
        }
        if let Some(color) = ambient {
            // Before the mirror's path, which draws from the same stream.
            c += self.ambient_occlusion(p, err, ng, own * albedo * color, pw) * albedo * color;
        }
        if mirror {
            pw.counts.reflection += 1;
            let r = d - 2.0 * d.dot(n) * n;
            let (rgb, a, _) =
                self.path(spawn_ray(p, err, ng, r), bounce + 1, weight * m.mirror, pw);
            let seen = rgb + (1.0 - a) * Vec3::from_array(self.settings.environment);
            c = (1.0 - m.mirror) * c + m.mirror * seen;
        }
        c
    }

    /// Blinn–Phong from one light in direction `l` (unit) scaled by
    /// `falloff`; `shadow` is the ray to test when shadows are on, in which
    /// case the light is left for the tile's batch (weighted by `weight`)
    /// and zero is returned.
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
        weight: f32,
        pw: &mut PixelWork,
    ) -> Vec3 {
        let cos = n.dot(l);
        if cos <= 0.0 {
            return Vec3::ZERO;
        }
        let half = (l - d).normalize_or_zero();
        let spec = if m.specular > 0.0 {
            m.specular * powf(n.dot(half).max(0.0), m.shininess)
        } else {
            0.0
        };
        let lit =
            falloff * Vec3::from_array(color) * (m.diffuse * cos * albedo + Vec3::splat(spec));
        if let Some(r) = shadow {
            pw.counts.shadow += 1;
            let first = pw.pending.rays[SHADOW].len();
            self.gather(r, SHADOW, pw);
            if self.term(first, 1, weight * lit, SHADOW, pw) {
                return Vec3::ZERO;
            }
        }
        lit
    }

    /// The fraction of `ao_samples` cosine-weighted rays about `ng` known
    /// open now: 1 with AO off or every ray outside the scene's box, else
    /// 0, the light `rgb` (weighted for the pixel) being left for the
    /// tile's batch to scale by the open fraction.
    fn ambient_occlusion(
        &self,
        p: Vec3,
        err: Vec3,
        ng: Vec3,
        rgb: Vec3,
        pw: &mut PixelWork,
    ) -> f32 {
        let n = self.settings.ao_samples;
        if n == 0 {
            return 1.0;
        }
        let (t, b) = ng.any_orthonormal_pair();
        pw.counts.ao += u64::from(n);
        let first = pw.pending.rays[AO].len();
        for _ in 0..n {
            let l = cosine_hemisphere(uniform2(&mut pw.rng));
            let mut r = spawn_ray(p, err, ng, l.x * t + l.y * b + l.z * ng);
            r.t_max = self.settings.ao_distance;
            self.gather(r, AO, pw);
        }
        if self.term(first, n, rgb, AO, pw) { 0.0 } else { 1.0 }
    }
}
