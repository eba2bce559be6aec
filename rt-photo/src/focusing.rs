//! Focusing schlieren (lens-and-grid; Weinstein, "Large-field high-
//! brightness focusing schlieren system", AIAA J. 31(7), 1993): an
//! extended source of bright bands behind the flow, a schlieren lens that
//! images the flow's focus plane on the film and the source grid on a
//! cutoff grid — the source grid's negative, shifted by a fraction of a
//! band — in front of the film.
//!
//! Each film point gathers light from every bright band, through the whole
//! lens aperture; the rays of one point cross the flow along paths that
//! meet only at the focus plane, so a disturbance there moves all of their
//! source images alike (a sharp signal), while one far from it moves the
//! few rays that cross it (blurred away).
//!
//! ## The backward model
//! The camera ([`ThinLens`], focused on the plane in the flow) traces each
//! pixel's rays backward from stratified aperture points toward the
//! pixel's point on the focus plane, through the field, then straight on to
//! the source plane at `Z_S`. A ray lands at `s₁` (across the bands); its
//! undisturbed line, continued straight, at `s₀`. The cutoff grid lies
//! where the lens images the source plane, so a ray crosses it at the
//! image of `s₀` (a thin lens maps every object-side line onto one
//! image-side line, point by conjugate point): the ray carries light
//! `B(s₁) · C(s₀)`, `B` the source's brightness (1 on a band, 0 between)
//! and `C(s) = 1 − B(s − o)` the cutoff's transmission, `o` its shift in
//! the source plane. A pixel's value is the mean over its rays: the
//! fraction of an unobstructed, uniformly bright source's light that
//! reaches it.
//!
//! Undisturbed, a grid of pitch `p` and duty cycle `d` passes `o/p` of the
//! light (for `o ≤ min(d, 1 − d)·p`). A thin disturbance in the focus plane,
//! at distance `z` from the lens, deflecting every ray of a pixel by `ε`
//! (across the bands) moves every `s₁` by `δ = ε·(Z_S − z)`, so
//! `I/I₀ = 1 + δ/o`: the knife edge of a conventional schlieren system of
//! focal length `Z_S − z` whose source image of height `2o` is half cut
//! (`1 + 2 f ε / h`, ORACLES §5).
//!
//! The depth of sharp focus (geometric): the rays of a focus point fill a
//! cone of the aperture's diameter `D` at the lens, so at a distance `Δz`
//! from the focus plane they cross the flow over a disc of diameter
//! `D·|Δz|/z`; a disturbance of width `w` stays sharp while that disc is
//! smaller than it, `|Δz| < w·z/D`: depth of sharp focus `2·w·z/D`.

use alloc::vec::Vec;
use core::fmt;

use glam::DVec3;
use rt_core::sampling::{rng_for, uniform_f64};
use rt_volume::{GridField, IndexField, Octree, TraceError, TraceParams, TraceResult, trace};

use crate::bos::{Frame, ThinLens};
use crate::math::{cos, floor, sin, sqrt};

/// The source grid: bright bands of width `duty · pitch`, `pitch` apart,
/// on the source plane. `angle` turns the bands: at 0 they run along the
/// camera's up axis (bands across the image's x, sensitive to horizontal
/// deflection); at 90° along its right axis. Band `k` is centred at
/// `s = (k + c)·pitch`, `s` the coordinate across the bands (`c = 0` for
/// an odd number of bands, ½ for an even one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SourceGrid {
    /// Distance between band centres, scene units (metres), on the source
    /// plane.
    pub pitch: f64,
    /// Bright fraction of a period, in (0, 1).
    pub duty: f64,
    /// Band orientation, radians (see the type's docs).
    pub angle: f64,
    /// How many bands, centred on the optical axis; `None`: unbounded.
    /// `Some(1)` with a narrow band is the light source of a conventional
    /// knife-edge system.
    pub bands: Option<u32>,
}

impl SourceGrid {
    /// The coordinate across the bands of the source-plane point `(u, v)`
    /// (camera right and up).
    fn across(&self, u: f64, v: f64) -> f64 {
        u * cos(self.angle) + v * sin(self.angle)
    }

    /// Whether `s` (across the bands) lies on a bright band.
    fn bright(&self, s: f64) -> bool {
        let c = match self.bands {
            Some(n) if n % 2 == 0 => 0.5,
            _ => 0.0,
        };
        let x = s / self.pitch - c;
        let k = floor(x + 0.5);
        if let Some(n) = self.bands {
            // Bands k = −(n−1)/2 … (n−1)/2 (shifted by c for even n).
            let half = (f64::from(n) - 1.0) / 2.0;
            if (k + c).abs() > half + 1e-9 {
                return false;
            }
        }
        (x - k).abs() < 0.5 * self.duty
    }
}

/// A focusing-schlieren set-up (see the module docs): `camera` focused on
/// the plane of the flow to image, the source grid at `source_distance`
/// from the lens (behind the flow), the cutoff grid its negative shifted by
/// `cutoff_offset` pitches, `aperture_samples²` stratified rays per pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FocusingSchlieren {
    /// The camera: its lens is the schlieren lens, its focus distance the
    /// plane in the flow imaged sharply.
    pub camera: ThinLens,
    /// Distance from the lens to the source grid, beyond the focus plane.
    pub source_distance: f64,
    /// The source grid.
    pub grid: SourceGrid,
    /// The cutoff grid's shift across the bands, in pitches (`o/p`): the
    /// sensitivity. In `(0, min(duty, 1 − duty)]` the undisturbed image
    /// passes `o/p` of the light; 0 is dark field.
    pub cutoff_offset: f64,
    /// `k`: `k × k` stratified aperture (and pixel) samples per pixel.
    pub aperture_samples: u32,
    /// The integrator through the field.
    pub params: TraceParams,
}

/// A focusing-schlieren image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct FocusingImages {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Without the flow: the fraction of the light each pixel receives.
    pub reference: Vec<f64>,
    /// Through the flow.
    pub flow: Vec<f64>,
}

impl FocusingImages {
    /// `flow / reference` per pixel (1 = undisturbed), where the reference
    /// receives light (> 1e-12), else 1: the same rays in both, so the
    /// sampling's own noise cancels where nothing moved.
    #[must_use]
    pub fn relative(&self) -> Vec<f64> {
        self.flow
            .iter()
            .zip(&self.reference)
            .map(|(f, r)| if *r > 1e-12 { f / r } else { 1.0 })
            .collect()
    }
}

/// Why a focusing-schlieren render failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FocusingError {
    /// A camera setting is out of range (which, in words).
    Camera(&'static str),
    /// The source distance, grid, offset or sample count is out of range
    /// (which, in words).
    Setup(&'static str),
    /// A ray could not be traced through the field.
    Trace(TraceError),
}

impl fmt::Display for FocusingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Camera(w) => write!(f, "focusing schlieren camera: {w}"),
            Self::Setup(w) => write!(f, "focusing schlieren set-up: {w}"),
            Self::Trace(e) => write!(f, "focusing schlieren trace: {e}"),
        }
    }
}

impl core::error::Error for FocusingError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Trace(e) => Some(e),
            _ => None,
        }
    }
}

impl FocusingSchlieren {
    /// Checks the set-up.
    ///
    /// # Errors
    /// [`FocusingError::Camera`] or [`FocusingError::Setup`], naming the
    /// first bad setting.
    pub fn validate(&self) -> Result<(), FocusingError> {
        self.camera.validate().map_err(|e| match e {
            crate::BosError::Camera(w) => FocusingError::Camera(w),
            _ => FocusingError::Camera("invalid"),
        })?;
        let g = &self.grid;
        let why = if !(self.source_distance.is_finite()
            && self.source_distance > self.camera.focus_distance)
        {
            Some("the source grid must be finite and beyond the focus plane")
        } else if !(g.pitch.is_finite() && g.pitch > 0.0) {
            Some("the grid pitch must be finite and > 0")
        } else if !(g.duty > 0.0 && g.duty < 1.0) {
            Some("the duty cycle must be in (0, 1)")
        } else if !g.angle.is_finite() {
            Some("the band angle must be finite")
        } else if g.bands == Some(0) {
            Some("a grid of bands needs at least one")
        } else if !(self.cutoff_offset >= 0.0 && self.cutoff_offset < 1.0) {
            Some("the cutoff offset must be in [0, 1) pitches")
        } else if !(1..=64).contains(&self.aperture_samples) {
            Some("aperture samples must be 1 to 64 per axis")
        } else {
            None
        };
        why.map_or(Ok(()), |w| Err(FocusingError::Setup(w)))
    }

    /// The cutoff's transmission at `s` (across the bands, source-plane
    /// units): the negative of the source grid, shifted by the offset.
    fn cutoff(&self, s: f64) -> f64 {
        if self.grid.bright(s - self.cutoff_offset * self.grid.pitch) { 0.0 } else { 1.0 }
    }

    /// The smallest deflection (radians) the set-up resolves: the one
    /// that changes a pixel's relative intensity by 1/1000 (`δ/o`, with
    /// `δ = ε·(Z_S − Z_F)` from the focus plane). Octree skipping spends
    /// it as each ray's budget ([`FocusingSchlieren::render_grid`]).
    #[must_use]
    pub fn resolvable_deflection(&self) -> f64 {
        let lever = (self.source_distance - self.camera.focus_distance).max(f64::MIN_POSITIVE);
        let o = self.cutoff_offset.max(0.01) * self.grid.pitch;
        (o / lever / 1000.0).min(1e-3)
    }

    /// Renders the reference and flow images through `field` (any
    /// [`IndexField`], any integrator); seeded sample positions (the same
    /// seed, the same images, at any thread count with feature
    /// `parallel`).
    ///
    /// # Errors
    /// A bad set-up, or a failing trace.
    pub fn render<F: IndexField + Sync>(
        &self,
        field: &F,
        seed: u64,
    ) -> Result<FocusingImages, FocusingError> {
        self.render_with(&|o, d| trace(field, o, d, &self.params), seed)
    }

    /// [`FocusingSchlieren::render`] for a gridded field, rt's default:
    /// octree skipping (`tree` from [`rt_volume::build_octree`]) within a
    /// per-ray budget of [`FocusingSchlieren::resolvable_deflection`].
    /// With a tree built for another interpolant, traced without skipping.
    ///
    /// # Errors
    /// As [`FocusingSchlieren::render`].
    pub fn render_grid(
        &self,
        field: &GridField,
        tree: &Octree,
        seed: u64,
    ) -> Result<FocusingImages, FocusingError> {
        if field.interp() != tree.interp() {
            return self.render(field, seed);
        }
        let tol = self.resolvable_deflection();
        self.render_with(
            &|o, d| rt_volume::trace_skipping(field, tree, o, d, &self.params, tol),
            seed,
        )
    }

    /// [`FocusingSchlieren::render`] with any tracer `(origin, direction)
    /// → result`.
    ///
    /// # Errors
    /// As [`FocusingSchlieren::render`].
    pub fn render_with(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync),
        seed: u64,
    ) -> Result<FocusingImages, FocusingError> {
        self.validate()?;
        let (w, h) = (self.camera.width, self.camera.height);
        let frame = self.camera.frame();
        let row = |j: usize| self.row(tracer, &frame, j, seed);
        #[cfg(feature = "parallel")]
        let rows: Vec<Result<Vec<[f64; 2]>, FocusingError>> = {
            use rayon::prelude::*;
            (0..h).into_par_iter().map(row).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let rows: Vec<Result<Vec<[f64; 2]>, FocusingError>> = (0..h).map(row).collect();
        let mut out = FocusingImages {
            width: w,
            height: h,
            reference: Vec::with_capacity(w * h),
            flow: Vec::with_capacity(w * h),
        };
        for r in rows {
            for [reference, flow] in r? {
                out.reference.push(reference);
                out.flow.push(flow);
            }
        }
        Ok(out)
    }

    /// Where the line from `origin` along `d` meets the source plane,
    /// across the bands.
    fn on_source(&self, f: &Frame, origin: DVec3, d: DVec3) -> f64 {
        let plane = self.camera.position + self.source_distance * f.axis;
        let t = (plane - origin).dot(f.axis) / d.dot(f.axis);
        let p = origin + t * d - plane;
        self.grid.across(p.dot(f.right), p.dot(f.up))
    }

    /// One row's `[reference, flow]` pixels.
    ///
    /// The aperture is sampled in `k²` stripes along the bands (jittered
    /// across them; uniform along, weighted by the stripe's chord): the
    /// light a ray carries depends on where it crosses the bands, so the
    /// bands' edges are resolved to `1/k²` of the aperture — far better
    /// than a `k × k` lattice of points, whose cells are wider than a
    /// fine grid's bands. Pixel positions are stratified `k × k` in an
    /// order decorrelated from the stripes.
    fn row(
        &self,
        tracer: &impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError>,
        f: &Frame,
        j: usize,
        seed: u64,
    ) -> Result<Vec<[f64; 2]>, FocusingError> {
        let cam = &self.camera;
        let k = self.aperture_samples;
        let n = k * k;
        let scramble = coprime_near(n, 0.618_033_988_75 * f64::from(n));
        let (across, along) = (
            (cos(self.grid.angle), sin(self.grid.angle)),
            (-sin(self.grid.angle), cos(self.grid.angle)),
        );
        let mut out = Vec::with_capacity(cam.width);
        for i in 0..cam.width {
            let mut rng = rng_for(seed, (j * cam.width + i) as u64);
            let (mut reference, mut flow, mut total) = (0.0, 0.0, 0.0);
            for s in 0..n {
                let a = 2.0 * (f64::from(s) + uniform_f64(&mut rng)) / f64::from(n) - 1.0;
                let chord = sqrt((1.0 - a * a).max(0.0));
                let b = (2.0 * uniform_f64(&mut rng) - 1.0) * chord;
                let lens = (a * across.0 + b * along.0, a * across.1 + b * along.1);
                let p = (u64::from(s) * u64::from(scramble) % u64::from(n)) as u32;
                let sub = (
                    (f64::from(p % k) + uniform_f64(&mut rng)) / f64::from(k),
                    (f64::from(p / k) + uniform_f64(&mut rng)) / f64::from(k),
                );
                total += chord;
                let (o, d) = cam.ray_from(i as f64 + sub.0, j as f64 + sub.1, lens);
                let s0 = self.on_source(f, o, d);
                let cut = self.cutoff(s0);
                if cut == 0.0 {
                    // Blocked whatever the flow does to it: no trace.
                    continue;
                }
                if self.grid.bright(s0) {
                    reference += cut * chord;
                }
                let r = tracer(o, d).map_err(FocusingError::Trace)?;
                if self.grid.bright(self.on_source(f, r.position, r.direction)) {
                    flow += cut * chord;
                }
            }
            out.push([reference / total, flow / total]);
        }
        Ok(out)
    }
}

/// The integer nearest `target` (in `[1, n)`) that is coprime to `n`: `s ↦
/// s·m mod n` is then a permutation of `0..n`.
fn coprime_near(n: u32, target: f64) -> u32 {
    let gcd = |mut a: u32, mut b: u32| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let mut m = (target as u32).clamp(1, n.max(2) - 1);
    while gcd(m, n) != 1 {
        m += 1;
    }
    m
}
