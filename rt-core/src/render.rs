//! Surface rendering for scientific visualization: Blinn–Phong shading
//! under ambient, directional and point lights with hard shadows, ambient
//! occlusion, mirror reflections and transparency composited in depth
//! order, over any [`ShadeScene`].
//!
//! Each pixel's samples use their own random stream from `(seed, pass,
//! pixel)`, so a frame is the same bit for bit at any thread count
//! (feature `parallel`: tiles on rayon). Work a scene does not need is not
//! done, and [`RayCounts`] proves it: no shadow rays without lights that
//! cast them, no AO rays with AO off (or without an ambient light for it
//! to darken), no reflection rays without a mirror material, no
//! transparency rays through opaque surfaces, and a ray that misses the
//! scene's bounds is not traversed ([`RayCounts::culled`]).

use alloc::vec::Vec;
use core::{
    fmt,
    sync::atomic::{AtomicUsize, Ordering},
};

use glam::{Vec2, Vec3};

use crate::{
    Aabb, Camera, Frame, FrameError, Hit, Ray, SceneQuery,
    camera::cosine_hemisphere,
    intersect::{spawn_ray, spawn_ray_to},
    math::{powf, sqrt},
    sampling::{Rng, rng_for, uniform2},
};

/// How a surface reflects light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Lambertian weight of the albedo (0–1).
    pub diffuse: f32,
    /// Blinn–Phong specular weight (0–1), white highlights.
    pub specular: f32,
    /// Blinn–Phong exponent (> 0).
    pub shininess: f32,
    /// Opacity (0–1): below 1 the surface is composited `over` what lies
    /// behind it.
    pub opacity: f32,
    /// Mirror reflectance (0–1): that fraction of the colour comes from the
    /// reflected ray.
    pub mirror: f32,
}

impl Material {
    /// Opaque and purely diffuse.
    pub const MATTE: Self =
        Self { diffuse: 1.0, specular: 0.0, shininess: 32.0, opacity: 1.0, mirror: 0.0 };
    /// Opaque, diffuse with a highlight.
    pub const GLOSSY: Self =
        Self { diffuse: 0.8, specular: 0.3, shininess: 48.0, opacity: 1.0, mirror: 0.0 };

    /// Checks every weight is in `[0, 1]` and the exponent positive.
    ///
    /// # Errors
    /// The name of the first bad parameter.
    pub fn validate(&self) -> Result<(), &'static str> {
        let unit = |v: f32| (0.0..=1.0).contains(&v);
        if !unit(self.diffuse) {
            Err("material diffuse must be in [0, 1]")
        } else if !unit(self.specular) {
            Err("material specular must be in [0, 1]")
        } else if !(self.shininess.is_finite() && self.shininess > 0.0) {
            Err("material shininess must be finite and > 0")
        } else if !unit(self.opacity) {
            Err("material opacity must be in [0, 1]")
        } else if !unit(self.mirror) {
            Err("material mirror must be in [0, 1]")
        } else {
            Ok(())
        }
    }
}

impl Default for Material {
    fn default() -> Self {
        Self::MATTE
    }
}

/// What the renderer needs to know about a hit surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Linear RGB before lighting (e.g. a colour-mapped scalar).
    pub albedo: [f32; 3],
    /// Unit shading normal (interpolated or geometric); either side.
    pub normal: Vec3,
    /// How it reflects.
    pub material: Material,
}

/// A scene the renderer can shade: hits, occlusion, the surface at a hit
/// and the bounds of everything in it.
pub trait ShadeScene: SceneQuery {
    /// The surface at `hit` (one this scene returned).
    fn surface(&self, hit: &Hit) -> Surface;
    /// A box containing every primitive (empty for an empty scene).
    fn bounds(&self) -> Aabb;
}

/// A light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Light from every direction: `albedo · color`, darkened by ambient
    /// occlusion when it is on.
    Ambient {
        /// Linear RGB.
        color: [f32; 3],
    },
    /// A light at infinity.
    Directional {
        /// Direction *toward* the light (any length).
        direction: Vec3,
        /// Irradiance on a surface facing it, linear RGB.
        color: [f32; 3],
    },
    /// A point light; irradiance falls off as `1/d²`.
    Point {
        /// Where it is.
        position: Vec3,
        /// Irradiance at unit distance, linear RGB.
        color: [f32; 3],
    },
}

/// Renderer settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// The lights (none: only emission-free black, so add at least one).
    pub lights: Vec<Light>,
    /// Hard shadows from directional and point lights.
    pub shadows: bool,
    /// Ambient-occlusion rays per hit (0: off), cosine-weighted about the
    /// normal; occlusion counts only within `ao_distance`.
    pub ao_samples: u32,
    /// Longest AO ray.
    pub ao_distance: f32,
    /// Most mirror bounces; a mirror beyond them shows its local shading.
    pub max_bounces: u32,
    /// Most translucent layers a ray passes through.
    pub max_layers: u32,
    /// Linear RGB that reflected rays see where they miss everything.
    pub environment: [f32; 3],
    /// Seed of every random choice (pixel jitter, AO directions).
    pub seed: u64,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            lights: alloc::vec![
                Light::Ambient { color: [0.25; 3] },
                Light::Directional { direction: Vec3::new(-0.5, 1.0, 0.35), color: [0.8; 3] },
            ],
            shadows: true,
            ao_samples: 0,
            ao_distance: 1.0,
            max_bounces: 2,
            max_layers: 16,
            environment: [0.0; 3],
            seed: 0,
        }
    }
}

impl Settings {
    /// Most AO samples per hit.
    pub const MAX_AO_SAMPLES: u32 = 4096;
    /// Most mirror bounces.
    pub const MAX_BOUNCES: u32 = 64;
    /// Most translucent layers.
    pub const MAX_LAYERS: u32 = 1024;

    fn validate(&self) -> Result<(), RenderError> {
        let bad = |s| Err(RenderError::BadSettings(s));
        let rgb = |c: &[f32; 3]| c.iter().all(|v| v.is_finite() && *v >= 0.0);
        for l in &self.lights {
            let ok = match l {
                Light::Ambient { color } => rgb(color),
                Light::Directional { direction, color } => {
                    rgb(color) && direction.is_finite() && *direction != Vec3::ZERO
                }
                Light::Point { position, color } => rgb(color) && position.is_finite(),
            };
            if !ok {
                return bad("light: colour must be finite and ≥ 0, position/direction finite");
            }
        }
        if self.ao_samples > Self::MAX_AO_SAMPLES {
            return bad("ao_samples above Settings::MAX_AO_SAMPLES");
        }
        if self.ao_samples > 0 && !(self.ao_distance.is_finite() && self.ao_distance > 0.0) {
            return bad("ao_distance must be finite and > 0");
        }
        if self.max_bounces > Self::MAX_BOUNCES {
            return bad("max_bounces above Settings::MAX_BOUNCES");
        }
        if self.max_layers > Self::MAX_LAYERS {
            return bad("max_layers above Settings::MAX_LAYERS");
        }
        if !rgb(&self.environment) {
            return bad("environment colour must be finite and ≥ 0");
        }
        Ok(())
    }
}

/// Rays cast, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera rays.
    pub primary: u64,
    /// Shadow rays toward lights.
    pub shadow: u64,
    /// Ambient-occlusion rays.
    pub ao: u64,
    /// Mirror reflection rays.
    pub reflection: u64,
    /// Rays continued through translucent surfaces.
    pub transparency: u64,
    /// Rays of any kind that missed the scene's bounds and so were never
    /// traversed.
    pub culled: u64,
}

impl RayCounts {
    /// Every ray cast (culled rays are among the kinds).
    #[must_use]
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.ao + self.reflection + self.transparency
    }

    fn add(&mut self, o: &Self) {
        self.primary += o.primary;
        self.shadow += o.shadow;
        self.ao += o.ao;
        self.reflection += o.reflection;
        self.transparency += o.transparency;
        self.culled += o.culled;
    }
}

/// Why the renderer refused.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RenderError {
    /// A setting is out of range (named).
    BadSettings(&'static str),
    /// The frame could not be made.
    Frame(FrameError),
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadSettings(s) => write!(f, "bad render settings: {s}"),
            Self::Frame(e) => write!(f, "frame: {e}"),
        }
    }
}

impl core::error::Error for RenderError {}

/// Pixels per tile edge (the unit of parallel work).
pub const TILE: u32 = 16;

/// A progressive renderer: each [`Renderer::render_pass`] adds one sample
/// per pixel (pass 0 at the pixel centres, later passes jittered) and
/// new AO directions; [`Renderer::frame`] is the running mean.
#[derive(Clone, Debug)]
pub struct Renderer {
    camera: Camera,
    settings: Settings,
    /// Per pixel: premultiplied RGBA summed over passes.
    sums: Vec<[f32; 4]>,
    /// Per pixel: depth of the pixel-centre ray (pass 0).
    depth: Vec<f32>,
    passes: u32,
    counts: RayCounts,
}

impl Renderer {
    /// A renderer for `camera`'s image.
    ///
    /// # Errors
    /// [`RenderError::BadSettings`] for out-of-range settings (see
    /// [`Material::validate`] for materials, checked by scenes), and
    /// [`RenderError::Frame`] for an image too large.
    pub fn new(camera: Camera, settings: Settings) -> Result<Self, RenderError> {
        settings.validate()?;
        let n = u64::from(camera.width) * u64::from(camera.height);
        if n > Frame::MAX_PIXELS {
            return Err(RenderError::Frame(FrameError::TooLarge));
        }
        let n = n as usize;
        let mut sums = Vec::new();
        let mut depth = Vec::new();
        let oom = |_| RenderError::Frame(FrameError::OutOfMemory);
        sums.try_reserve_exact(n).map_err(oom)?;
        depth.try_reserve_exact(n).map_err(oom)?;
        sums.resize(n, [0.0; 4]);
        depth.resize(n, f32::INFINITY);
        let mut settings = settings;
        for l in &mut settings.lights {
            if let Light::Directional { direction, .. } = l {
                *direction = direction.normalize();
            }
        }
        Ok(Self { camera, settings, sums, depth, passes: 0, counts: RayCounts::default() })
    }

    /// Passes accumulated so far.
    #[must_use]
    pub fn passes(&self) -> u32 {
        self.passes
    }

    /// Rays cast over all passes.
    #[must_use]
    pub fn counts(&self) -> RayCounts {
        self.counts
    }

    /// The settings (directional lights normalised).
    #[must_use]
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Starts over (same camera and settings).
    pub fn reset(&mut self) {
        self.sums.fill([0.0; 4]);
        self.depth.fill(f32::INFINITY);
        self.passes = 0;
        self.counts = RayCounts::default();
    }

    /// Renders one more pass of `scene`; returns the rays it cast.
    pub fn render_pass<S: ShadeScene + Sync>(&mut self, scene: &S) -> RayCounts {
        self.render_pass_with_progress(scene, |_, _| {})
    }

    /// Tiles (16 × 16 pixels, clipped at the edges) in one pass.
    #[must_use]
    pub fn tiles_per_pass(&self) -> usize {
        self.camera.width.div_ceil(TILE) as usize * self.camera.height.div_ceil(TILE) as usize
    }

    /// [`Self::render_pass`], calling `progress(done, total)` after each
    /// tile (from the worker threads, in completion order) for progress
    /// bars. The image does not depend on it.
    pub fn render_pass_with_progress<S, P>(&mut self, scene: &S, progress: P) -> RayCounts
    where
        S: ShadeScene + Sync,
        P: Fn(usize, usize) + Sync,
    {
        let (w, h) = (self.camera.width, self.camera.height);
        let tiles: Vec<(u32, u32)> = (0..h.div_ceil(TILE))
            .flat_map(|ty| (0..w.div_ceil(TILE)).map(move |tx| (tx * TILE, ty * TILE)))
            .collect();
        let ctx =
            Ctx { scene, camera: &self.camera, settings: &self.settings, bounds: scene.bounds() };
        let pass = self.passes;
        let finished = AtomicUsize::new(0);
        let work = |&(x0, y0): &(u32, u32)| {
            let tile = ctx.tile(x0, y0, pass);
            progress(finished.fetch_add(1, Ordering::Relaxed) + 1, tiles.len());
            tile
        };
        #[cfg(feature = "parallel")]
        let done: Vec<TileResult> = {
            use rayon::prelude::*;
            tiles.par_iter().map(work).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let done: Vec<TileResult> = tiles.iter().map(work).collect();
        let mut counts = RayCounts::default();
        for t in &done {
            counts.add(&t.counts);
            for (i, (c, d)) in t.pixels.iter().enumerate() {
                let (x, y) = (t.x0 + i as u32 % t.w, t.y0 + i as u32 / t.w);
                let p = (y * w + x) as usize;
                for (sum, v) in self.sums[p].iter_mut().zip(c) {
                    *sum += v;
                }
                if pass == 0 {
                    self.depth[p] = *d;
                }
            }
        }
        self.passes += 1;
        self.counts.add(&counts);
        counts
    }

    /// The mean of the passes so far as a frame (background where no pass
    /// has run).
    ///
    /// # Errors
    /// [`FrameError::OutOfMemory`] when the frame cannot be allocated.
    pub fn frame(&self) -> Result<Frame, FrameError> {
        let mut f = Frame::new(self.camera.width, self.camera.height)?;
        if self.passes > 0 {
            let inv = 1.0 / self.passes as f32;
            for ((px, s), d) in f.pixels_mut().iter_mut().zip(&self.sums).zip(&self.depth) {
                px.color = s.map(|v| v * inv);
                px.depth = *d;
            }
        }
        Ok(f)
    }
}

struct TileResult {
    x0: u32,
    y0: u32,
    w: u32,
    pixels: Vec<([f32; 4], f32)>,
    counts: RayCounts,
}

/// What one pass shares between tiles.
struct Ctx<'a, S> {
    scene: &'a S,
    camera: &'a Camera,
    settings: &'a Settings,
    bounds: Aabb,
}

/// Per-pixel state: its random stream and its counts.
struct PixelWork {
    rng: Rng,
    counts: RayCounts,
}

impl<S: ShadeScene> Ctx<'_, S> {
    fn tile(&self, x0: u32, y0: u32, pass: u32) -> TileResult {
        let (w, h) = (self.camera.width, self.camera.height);
        let (tw, th) = (TILE.min(w - x0), TILE.min(h - y0));
        let mut pixels = Vec::with_capacity((tw * th) as usize);
        let stream_seed = self.settings.seed ^ u64::from(pass).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        let mut pw = PixelWork { rng: rng_for(stream_seed, 0), counts: RayCounts::default() };
        for y in y0..y0 + th {
            for x in x0..x0 + tw {
                pw.rng = rng_for(stream_seed, u64::from(y) * u64::from(w) + u64::from(x));
                let jitter = if pass == 0 { Vec2::splat(0.5) } else { uniform2(&mut pw.rng) };
                let ray = self.camera.generate_ray(x, y, jitter, uniform2(&mut pw.rng));
                pw.counts.primary += 1;
                let (rgb, a, depth) = self.path(ray, 0, &mut pw);
                pixels.push(([rgb.x, rgb.y, rgb.z, a], depth));
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

    fn occluded(&self, ray: &Ray, pw: &mut PixelWork) -> bool {
        if self.bounds.intersect_ray(ray).is_none() {
            pw.counts.culled += 1;
            return false;
        }
        self.scene.occluded(ray)
    }

    /// Premultiplied colour, alpha and depth seen along `ray`: translucent
    /// layers composited front to back.
    fn path(&self, mut ray: Ray, bounce: u32, pw: &mut PixelWork) -> (Vec3, f32, f32) {
        let (mut rgb, mut alpha, mut depth) = (Vec3::ZERO, 0.0f32, f32::INFINITY);
        // Distance along the first ray to the current ray's origin.
        let mut travelled = 0.0;
        let mut layers = 0;
        while let Some(hit) = self.closest(&ray, pw) {
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
