//! The progressive renderer: passes of one sample per pixel, tiles on
//! rayon (feature `parallel`), the running mean as a [`Frame`].

use alloc::vec::Vec;
use core::{
    fmt,
    sync::atomic::{AtomicUsize, Ordering},
};

use rt_core::{Camera, Frame, FrameError};

use super::{
    Light, SettingsError, ShadeScene,
    settings::Settings,
    shade::{Ctx, TileResult},
};

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

    pub(super) fn add(&mut self, o: &Self) {
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
    Settings(SettingsError),
    /// The frame could not be made (too large, or out of memory).
    Frame(FrameError),
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Settings(e) => write!(f, "bad render settings: {e}"),
            Self::Frame(e) => write!(f, "frame: {e}"),
        }
    }
}

impl core::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Settings(e) => Some(e),
            Self::Frame(e) => Some(e),
        }
    }
}

impl From<SettingsError> for RenderError {
    fn from(e: SettingsError) -> Self {
        Self::Settings(e)
    }
}

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
    /// [`RenderError::Settings`] for out-of-range settings (see
    /// [`Material::validate`](super::Material::validate) for materials, checked by scenes), and
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
        // A stop that never says yes never stops the pass.
        self.render_pass_until(scene, progress, &|| false).unwrap_or_default()
    }

    /// [`Self::render_pass_with_progress`] that asks `stop` before each
    /// tile: once it says yes the pass ends early and is dropped (`None`),
    /// leaving the passes accumulated so far as they were.
    pub fn render_pass_until<S, P>(
        &mut self,
        scene: &S,
        progress: P,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Option<RayCounts>
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
            if stop() {
                return None;
            }
            let tile = ctx.tile(x0, y0, pass);
            progress(finished.fetch_add(1, Ordering::Relaxed) + 1, tiles.len());
            Some(tile)
        };
        #[cfg(feature = "parallel")]
        let done: Vec<TileResult> = {
            use rayon::prelude::*;
            tiles.par_iter().map(work).collect::<Option<_>>()?
        };
        #[cfg(not(feature = "parallel"))]
        let done: Vec<TileResult> = tiles.iter().map(work).collect::<Option<_>>()?;
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
        Some(counts)
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
