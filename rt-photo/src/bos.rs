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
use rt_volume::{GridField, IndexField, Octree, TraceError, TraceParams, TraceResult, trace};

use crate::airy::Airy;
use crate::background::Background;
use crate::math::{cos, sin};

/// A thin-lens camera: lens centre `position`, optical axis `direction`,
/// focused at `focus_distance` (object side) with focal length
/// `focal_length` and f-number `f_number` (aperture diameter `D = f/N`); a
/// sensor of `width × height` pixels of pitch `pixel_pitch` in the image
/// plane. The image is stored upright (row 0 at the top, `up` upward).
/// Lengths in the scene's unit (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// Centre of the lens.
    pub position: DVec3,
    /// Optical axis, toward the scene (any length).
    pub direction: DVec3,
    /// Upward in the image (any vector not along `direction`).
    pub up: DVec3,
    /// Focal length `f`.
    pub focal_length: f64,
    /// f-number `N`.
    pub f_number: f64,
    /// Distance from the lens to the plane in focus, `> f`.
    pub focus_distance: f64,
    /// Sensor pixel pitch.
    pub pixel_pitch: f64,
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

/// The camera's orthonormal frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    pub(crate) axis: DVec3,
    pub(crate) right: DVec3,
    pub(crate) up: DVec3,
}

impl ThinLens {
    /// The magnification of the focus plane onto the sensor,
    /// `M = f/(Z_F − f)`.
    #[must_use]
    pub fn magnification(&self) -> f64 {
        self.focal_length / (self.focus_distance - self.focal_length)
    }

    /// Aperture diameter `D = f/N`.
    #[must_use]
    pub fn aperture(&self) -> f64 {
        self.focal_length / self.f_number
    }

    /// The size of a sensor pixel imaged on the focus plane,
    /// `pitch/M` (scene units).
    #[must_use]
    pub fn pixel_in_focus(&self) -> f64 {
        self.pixel_pitch / self.magnification()
    }

    /// The lens's diffraction at `wavelength` (metres) on this sensor:
    /// the light converges on the sensor at the working f-number
    /// `N·(1 + M)` (the image lies `f·(1 + M)` behind the lens), so the
    /// Airy disc's first dark ring has diameter `2.44 λ N (1 + M)`.
    #[must_use]
    pub fn airy(&self, wavelength: f64) -> Airy {
        Airy::new(wavelength, self.f_number * (1.0 + self.magnification()), self.pixel_pitch)
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`BosError::Camera`] naming the first bad one.
    pub fn validate(&self) -> Result<(), BosError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let why =
            if !(self.position.is_finite() && self.direction.is_finite() && self.up.is_finite()) {
                Some("position, direction and up must be finite")
            } else if self.direction.length_squared() == 0.0
                || self.direction.normalize().cross(self.up).length_squared() < 1e-12
            {
                Some("direction must be non-zero and up not along it")
            } else if !pos(self.focal_length) || !pos(self.f_number) || !pos(self.pixel_pitch) {
                Some("focal length, f-number and pixel pitch must be finite and > 0")
            } else if !(self.focus_distance.is_finite() && self.focus_distance > self.focal_length)
            {
                Some("the focus distance must be finite and beyond the focal length")
            } else if self.width == 0
                || self.height == 0
                || self.width.checked_mul(self.height).is_none_or(|n| n > 1 << 26)
            {
                Some("the sensor must have 1 to 2^26 pixels")
            } else {
                None
            };
        why.map_or(Ok(()), |w| Err(BosError::Camera(w)))
    }

    pub(crate) fn frame(&self) -> Frame {
        let axis = self.direction.normalize();
        let right = axis.cross(self.up).normalize();
        Frame { axis, right, up: right.cross(axis) }
    }

    /// The point of the focus plane that pixel coordinates `(px, py)`
    /// (continuous: pixel `(i, j)` spans `[i, i+1) × [j, j+1)`, rows
    /// downward) see in focus.
    #[must_use]
    pub fn focus_point(&self, px: f64, py: f64) -> DVec3 {
        self.focus_point_in(&self.frame(), px, py)
    }

    /// [`ThinLens::focus_point`] in the camera's frame `f`, computed once
    /// by the caller.
    fn focus_point_in(&self, f: &Frame, px: f64, py: f64) -> DVec3 {
        let scale = self.pixel_pitch / self.magnification();
        self.position
            + self.focus_distance * f.axis
            + (px - 0.5 * self.width as f64) * scale * f.right
            + (0.5 * self.height as f64 - py) * scale * f.up
    }

    /// The ray from the lens point at `lens ∈ [0, 1)²` (mapped onto the
    /// aperture disc) through pixel coordinates `(px, py)`: origin on the
    /// lens, unit direction toward [`ThinLens::focus_point`].
    #[must_use]
    pub fn ray(&self, px: f64, py: f64, lens: (f64, f64)) -> (DVec3, DVec3) {
        self.ray_from(px, py, concentric_disk(lens))
    }

    /// [`ThinLens::ray`] from the lens point `(dx, dy)` of the unit disc
    /// (along the camera's right and up, in aperture radii).
    #[must_use]
    pub fn ray_from(&self, px: f64, py: f64, (dx, dy): (f64, f64)) -> (DVec3, DVec3) {
        let f = self.frame();
        let r = 0.5 * self.aperture();
        let origin = self.position + r * (dx * f.right + dy * f.up);
        (origin, (self.focus_point_in(&f, px, py) - origin).normalize())
    }
}

/// Shirley–Chiu concentric map of `[0, 1)²` onto the unit disc.
fn concentric_disk((u, v): (f64, f64)) -> (f64, f64) {
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let q = core::f64::consts::FRAC_PI_4;
    let (r, theta) = if a.abs() > b.abs() { (a, q * (b / a)) } else { (b, 2.0 * q - q * (a / b)) };
    (r * cos(theta), r * sin(theta))
}

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

    /// [`Bos::render`] for a gridded field, rt's default: octree skipping
    /// (`tree` from [`rt_volume::build_octree`]) within a per-ray budget of
    /// [`Bos::resolvable_deflection`] at the field's centre — the ground
    /// truth moves by at most a tenth of a pixel. With a tree built for
    /// another interpolant, traced without skipping.
    ///
    /// # Errors
    /// As [`Bos::render`].
    pub fn render_grid(
        &self,
        field: &GridField,
        tree: &Octree,
        seed: u64,
    ) -> Result<BosImages, BosError> {
        if field.interp() != tree.interp() {
            return self.render(field, seed);
        }
        let b = field.bounds();
        let axis = self.camera.direction.normalize();
        let z_a = (0.5 * (b.min + b.max) - self.camera.position).dot(axis);
        let tol = self.resolvable_deflection(z_a);
        self.render_with(
            &|o, d| rt_volume::trace_skipping(field, tree, o, d, &self.params, tol),
            seed,
        )
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
    fn on_background(&self, f: &Frame, origin: DVec3, d: DVec3) -> (f64, f64) {
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
        let f = cam.frame();
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

/// `row(j)` for rows `0..h`, in order: in parallel with feature
/// `parallel` (each row its own work, so the result does not depend on the
/// thread count).
pub(crate) fn rows<P: Send, E: Send>(
    h: usize,
    row: impl Fn(usize) -> Result<Vec<P>, E> + Sync + Send,
) -> Vec<Result<Vec<P>, E>> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..h).into_par_iter().map(row).collect()
    }
    #[cfg(not(feature = "parallel"))]
    {
        (0..h).map(row).collect()
    }
}

/// One pixel's results.
#[derive(Clone, Copy, Debug)]
struct Pixel {
    reference: f64,
    flow: f64,
    displacement: [f64; 2],
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::sqrt;

    #[test]
    fn concentric_disk_stays_in_the_disc_and_covers_it() {
        let mut max: f64 = 0.0;
        for i in 0..=20 {
            for j in 0..=20 {
                let (x, y) = concentric_disk((f64::from(i) / 20.0, f64::from(j) / 20.0));
                max = max.max(sqrt(x * x + y * y));
            }
        }
        assert!((max - 1.0).abs() < 1e-12, "{max}");
    }
}
