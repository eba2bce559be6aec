//! Background-oriented schlieren (BOS; Raffel, Exp. Fluids 56:60, 2015):
//! a camera focused on a dotted background looks through the flow; the
//! flow bends the rays, so the background's image moves by
//! `Δ = M·Z_D·ε` (paraxially, docs/oracles.md §7), `M = f/(Z_B − f)`, `Z_D` from
//! the flow's mid-plane to the background.
//!
//! The camera is a thin lens ([`ThinLens`]): each pixel's rays are traced
//! *backward* from stratified points of the aperture toward the pixel's
//! point on the focus plane, through the field (any [`IndexField`], any
//! integrator), then straight on to the background plane, where the
//! [`Background`] (random dots, a dot grid or an image) is looked up.
//! [`Bos::render`] returns the reference
//! image (no flow: the rays go straight), the flow image and the ground
//! truth users check their BOS processing against: per pixel, the
//! apparent motion of the background pattern from the reference to the
//! flow image (as PIV software reports it), in pixels.

use alloc::vec::Vec;
use core::fmt;

use glam::DVec3;
use rt_core::sampling::{rng_for, uniform_f64};
use rt_volume::{IndexField, TraceError, TraceParams, TraceResult, trace};

use super::Background;
use crate::camera::{Basis, CameraError, ThinLens};
use crate::rows::rows;

/// A BOS set-up: `camera` focused on the background at `background_distance`
/// (`Z_B`, normally its focus distance), `aperture_samples²` stratified
/// rays per pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Bos {
    /// The camera.
    pub camera: ThinLens,
    /// Distance from the lens to the background plane (perpendicular to
    /// the optical axis).
    pub background_distance: f64,
    /// The background.
    pub background: Background,
    /// `k`: `k × k` stratified aperture (and pixel) samples per pixel.
    pub aperture_samples: u32,
    /// The integrator through the field.
    pub params: TraceParams,
}

/// A BOS pair and its ground truth, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct BosImages {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// The background seen without the flow.
    pub reference: Vec<f64>,
    /// The background seen through the flow.
    pub flow: Vec<f64>,
    /// Per pixel, `(Δx, Δy)` in pixels (x right, y down), in the
    /// convention of PIV and BOS software: the apparent motion of the
    /// background pattern from the reference image to the flow image, what
    /// cross-correlating reference → flow measures. It is the opposite of
    /// the shift of where the pixel's rays land: the undisturbed
    /// aperture-averaged landing point on the background minus the
    /// disturbed one, imaged by `M`.
    pub displacement: Vec<[f64; 2]>,
}

/// Why a BOS render failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BosError {
    /// A camera setting is out of range (which, in words).
    Camera(&'static str),
    /// The background distance is not finite and > 0, or the dots are not
    /// finite and > 0, or a background image's pixel size is not, or
    /// `aperture_samples` is not 1 to 64 (which, in words).
    Setup(&'static str),
    /// A background image has no pixels, or not `width × height` samples.
    ImageSize {
        /// Pixels per row.
        width: usize,
        /// Rows.
        height: usize,
        /// Samples given.
        samples: usize,
    },
    /// A background image's sample is NaN, infinite or negative.
    ImageSample {
        /// Its index (row-major).
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A ray could not be traced through the field.
    Trace(TraceError),
}

impl fmt::Display for BosError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Camera(w) => write!(f, "BOS camera: {w}"),
            Self::Setup(w) => write!(f, "BOS set-up: {w}"),
            Self::ImageSize { width, height, samples } => write!(
                f,
                "BOS background image: {width}×{height} pixels with {samples} samples (must be width × height, not 0)"
            ),
            Self::ImageSample { index, value } => {
                write!(f, "BOS background image: sample {index} is {value}, must be finite and ≥ 0")
            }
            Self::Trace(e) => write!(f, "BOS trace: {e}"),
        }
    }
}

impl From<CameraError> for BosError {
    fn from(e: CameraError) -> Self {
        Self::Camera(e.0)
    }
}

impl core::error::Error for BosError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Trace(e) => Some(e),
            _ => None,
        }
    }
}

impl Bos {
    /// Checks the set-up.
    ///
    /// # Errors
    /// [`BosError::Camera`] or [`BosError::Setup`].
    pub fn validate(&self) -> Result<(), BosError> {
        self.camera.validate()?;
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !pos(self.background_distance) {
            return Err(BosError::Setup("the background distance must be finite and > 0"));
        }
        self.background.validate()?;
        if !(1..=64).contains(&self.aperture_samples) {
            return Err(BosError::Setup("aperture samples must be 1 to 64 per axis"));
        }
        Ok(())
    }

    /// Renders the pair and the ground-truth displacement through `field`;
    /// seeded sample positions (the same seed, the same images, at any
    /// thread count with feature `parallel`).
    ///
    /// # Errors
    /// A bad set-up, or a failing trace.
    pub fn render<F: IndexField + Sync>(
        &self,
        field: &F,
        seed: u64,
    ) -> Result<BosImages, BosError> {
        self.render_with(&|o, d| trace(field, o, d, &self.params), seed)
    }

    /// The deflection (radians) that moves the background's image by a
    /// tenth of a pixel for a flow whose mid-plane lies `z_a` from the
    /// lens: `0.1·pitch / (M·Z_D)`, `Z_D = Z_B − Z_A` (capped at 1e-3).
    #[must_use]
    pub fn resolvable_deflection(&self, z_a: f64) -> f64 {
        let cam = &self.camera;
        let z_d = self.background_distance - z_a;
        let tol = 0.1 * cam.pixel_pitch / (cam.magnification() * z_d);
        if tol.is_finite() && tol > 0.0 { tol.min(1e-3) } else { 1e-3 }
    }

    /// [`Bos::render`] with any tracer `(origin, direction) → result`.
    ///
    /// # Errors
    /// As [`Bos::render`].
    pub fn render_with(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync),
        seed: u64,
    ) -> Result<BosImages, BosError> {
        self.validate()?;
        let (w, h) = (self.camera.width, self.camera.height);
        let rows = rows(h, |j| self.row(tracer, j, seed));
        let mut out = BosImages {
            width: w,
            height: h,
            reference: Vec::with_capacity(w * h),
            flow: Vec::with_capacity(w * h),
            displacement: Vec::with_capacity(w * h),
        };
        for r in rows {
            for p in r? {
                out.reference.push(p.reference);
                out.flow.push(p.flow);
                out.displacement.push(p.displacement);
            }
        }
        Ok(out)
    }

    /// Where the ray from `origin` along `d` meets the background plane,
    /// as `(u, v)` on it (the camera's right and up axes).
    fn on_background(&self, f: &Basis, origin: DVec3, d: DVec3) -> (f64, f64) {
        let plane = self.camera.position + self.background_distance * f.axis;
        let t = (plane - origin).dot(f.axis) / d.dot(f.axis);
        let p = origin + t * d - plane;
        (p.dot(f.right), p.dot(f.up))
    }

    fn row(
        &self,
        tracer: &impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError>,
        j: usize,
        seed: u64,
    ) -> Result<Vec<Pixel>, BosError> {
        let cam = &self.camera;
        let f = cam.basis();
        let k = self.aperture_samples;
        let n = f64::from(k * k);
        let to_px = cam.magnification() / cam.pixel_pitch;
        let mut out = Vec::with_capacity(cam.width);
        for i in 0..cam.width {
            let mut rng = rng_for(seed, (j * cam.width + i) as u64);
            let mut px = Pixel { reference: 0.0, flow: 0.0, displacement: [0.0; 2] };
            for s in 0..k * k {
                // Stratified lens and pixel positions, jittered.
                let (a, b) = (f64::from(s % k), f64::from(s / k));
                let lens = (
                    (a + uniform_f64(&mut rng)) / f64::from(k),
                    (b + uniform_f64(&mut rng)) / f64::from(k),
                );
                let sub = (
                    (b + uniform_f64(&mut rng)) / f64::from(k),
                    (a + uniform_f64(&mut rng)) / f64::from(k),
                );
                let (o, d) = cam.ray(i as f64 + sub.0, j as f64 + sub.1, lens);
                let (u0, v0) = self.on_background(&f, o, d);
                let r = tracer(o, d).map_err(BosError::Trace)?;
                let (u1, v1) = self.on_background(&f, r.position, r.direction);
                px.reference += self.background.value(u0, v0);
                px.flow += self.background.value(u1, v1);
                // The pattern moves the other way from where the ray
                // lands: flow(p) = reference(p + landing shift), so a
                // feature at q in the reference shows at q − shift.
                px.displacement[0] -= (u1 - u0) * to_px;
                px.displacement[1] += (v1 - v0) * to_px;
            }
            px.reference /= n;
            px.flow /= n;
            px.displacement = px.displacement.map(|x| x / n);
            out.push(px);
        }
        Ok(out)
    }
}

/// One pixel's results.
#[derive(Clone, Copy, Debug)]
struct Pixel {
    reference: f64,
    flow: f64,
    displacement: [f64; 2],
}
