//! The thin-lens camera of BOS and focusing schlieren: a lens of focal
//! length `f` and f-number `N` focused at a distance, a sensor of pixels,
//! and each pixel's rays from stratified points of the aperture toward its
//! point on the focus plane.

use core::fmt;

use glam::DVec3;

use crate::math::{cos, sin};

use super::Airy;

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

/// The camera's orthonormal basis: its axis, right and up.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Basis {
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
    /// [`CameraError`] naming the first bad one.
    pub fn validate(&self) -> Result<(), CameraError> {
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
        why.map_or(Ok(()), |w| Err(CameraError(w)))
    }

    pub(crate) fn basis(&self) -> Basis {
        let axis = self.direction.normalize();
        let right = axis.cross(self.up).normalize();
        Basis { axis, right, up: right.cross(axis) }
    }

    /// The point of the focus plane that pixel coordinates `(px, py)`
    /// (continuous: pixel `(i, j)` spans `[i, i+1) × [j, j+1)`, rows
    /// downward) see in focus.
    #[must_use]
    pub fn focus_point(&self, px: f64, py: f64) -> DVec3 {
        self.focus_point_in(&self.basis(), px, py)
    }

    /// [`ThinLens::focus_point`] in the camera's frame `f`, computed once
    /// by the caller.
    fn focus_point_in(&self, f: &Basis, px: f64, py: f64) -> DVec3 {
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
        let f = self.basis();
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

/// A camera setting out of range (which, in words).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CameraError(pub &'static str);

impl fmt::Display for CameraError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "camera: {}", self.0)
    }
}

impl core::error::Error for CameraError {}

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
