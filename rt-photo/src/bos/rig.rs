//! A laboratory BOS rig chosen for a flow, where the user has not said
//! otherwise: the camera of a lab set-up (`camera/lab.rs`), and the
//! background behind the flow. Sensitivity is set by the background
//! distance `Z_D`: paraxially the background's image moves by
//! `Δ = M·Z_D·ε / pitch` pixels, `M = f/(Z_A + Z_D − f)`, so `Z_D` is
//! chosen for the flow's strongest deflections (the 99th percentile of a
//! survey) to move the image a few pixels: the range window
//! cross-correlation follows well, where the dots are not yet smeared.

use core::fmt;

use super::BosError;
use crate::camera::lab::{FOCAL_LENGTHS, LAB_DISTANCE, SENSOR_PITCH, SENSOR_PIXELS, lab_camera};

/// What the user fixed of a BOS rig (`None`: chosen by [`BosRig::choose`]).
/// Lengths in metres.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BosRigOptions {
    /// Focal length of the camera lens, `f`.
    pub focal_length: Option<f64>,
    /// Pitch of an image pixel on the sensor.
    pub pixel_pitch: Option<f64>,
    /// Lens to the flow's centre, `Z_A`.
    pub camera_distance: Option<f64>,
    /// Flow's centre to the background, `Z_D`.
    pub background_distance: Option<f64>,
}

/// A BOS rig: camera, lens and distances (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BosRig {
    /// Image pixels across.
    pub pixels: usize,
    /// Pitch of an image pixel on the sensor.
    pub pixel_pitch: f64,
    /// Focal length `f`.
    pub focal_length: f64,
    /// Lens to the flow's centre, `Z_A`.
    pub camera_distance: f64,
    /// Flow's centre to the background, `Z_D`.
    pub background_distance: f64,
    /// The 99th percentile of the flow's deflection the rig was chosen for
    /// (radians; 0 if unknown or none).
    pub deflection: f64,
    /// `Z_D` was wanted larger or smaller than a rig allows (the
    /// displacement then misses [`BosRig::TARGET_DISPLACEMENT`]).
    pub limited: bool,
}

impl BosRig {
    /// Pixels across the sensor a default rig has.
    pub const SENSOR_PIXELS: usize = SENSOR_PIXELS;
    /// Their pitch, metres.
    pub const SENSOR_PITCH: f64 = SENSOR_PITCH;
    /// The focal lengths a default rig picks from (metres): the usual
    /// prime lenses, 24 mm to 400 mm.
    pub const FOCAL_LENGTHS: [f64; 9] = FOCAL_LENGTHS;
    /// The camera distance a default lens is picked for (metres).
    pub const LAB_DISTANCE: f64 = LAB_DISTANCE;
    /// The displacement (pixels) the default `Z_D` gives the 99th
    /// percentile of the flow's deflection.
    pub const TARGET_DISPLACEMENT: f64 = 4.0;

    /// The rig for a flow `width` across the image and `depth` along the
    /// light, imaged on `pixels` pixels across, whose deflections reach
    /// `deflection` (radians, the 99th percentile; 0 if none), with what
    /// `fixed` fixes:
    /// - pitch: the default sensor's width over `pixels`;
    /// - lens: of [`BosRig::FOCAL_LENGTHS`], the one that fills the view
    ///   with the flow nearest [`BosRig::LAB_DISTANCE`] (or, with the
    ///   camera distance fixed, the focal length that fills it there);
    /// - camera distance: the flow (and a 5 % margin) fills the view;
    /// - background distance: the 99th-percentile deflection moves the
    ///   image by [`BosRig::TARGET_DISPLACEMENT`] pixels, kept between
    ///   just behind the flow (0.6 `depth`) and twice the camera distance
    ///   (the camera distance without a deflection).
    ///
    /// # Errors
    /// [`BosError::Setup`] for a size or a fixed value that is not finite
    /// and > 0, or no pixels.
    pub fn choose(
        fixed: &BosRigOptions,
        width: f64,
        depth: f64,
        pixels: usize,
        deflection: f64,
    ) -> Result<Self, BosError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !pos(width) || !pos(depth) || pixels == 0 {
            return Err(BosError::Setup("the flow's size and the image width must be > 0"));
        }
        let fixed_ok = [
            fixed.focal_length,
            fixed.pixel_pitch,
            fixed.camera_distance,
            fixed.background_distance,
        ]
        .iter()
        .flatten()
        .all(|&v| pos(v));
        if !fixed_ok {
            return Err(BosError::Setup("lengths of the rig must be finite and > 0"));
        }
        let deflection = if deflection.is_finite() { deflection.abs() } else { 0.0 };
        let (pitch, focal_length, camera_distance) =
            lab_camera(width, pixels, fixed.pixel_pitch, fixed.focal_length, fixed.camera_distance);
        let (background_distance, limited) = match fixed.background_distance {
            Some(z_d) => (z_d, false),
            // No flow to size it for: the background as far behind as the
            // camera is in front.
            None if deflection == 0.0 => (camera_distance, false),
            None => {
                let (lo, hi) = ((0.6 * depth).min(camera_distance), 2.0 * camera_distance);
                // Δ(Z_D) = f·Z_D·ε / ((Z_A + Z_D − f)·pitch) rises toward
                // f·ε/pitch: solve Δ = target where it can be reached.
                let c = Self::TARGET_DISPLACEMENT * pitch / (focal_length * deflection);
                let want = if c < 1.0 {
                    c * (camera_distance - focal_length) / (1.0 - c)
                } else {
                    f64::INFINITY
                };
                (want.clamp(lo, hi), !(lo..=hi).contains(&want))
            }
        };
        Ok(Self {
            pixels,
            pixel_pitch: pitch,
            focal_length,
            camera_distance,
            background_distance,
            deflection,
            limited,
        })
    }

    /// `M = f/(Z_B − f)`, the background's magnification onto the sensor
    /// (`Z_B = Z_A + Z_D`).
    #[must_use]
    pub fn magnification(&self) -> f64 {
        let z_b = self.camera_distance + self.background_distance;
        self.focal_length / (z_b - self.focal_length)
    }

    /// The paraxial displacement, in pixels, of a deflection `eps`
    /// (radians): `M·Z_D·ε / pitch`.
    #[must_use]
    pub fn displacement(&self, eps: f64) -> f64 {
        self.magnification() * self.background_distance * eps / self.pixel_pitch
    }
}

impl fmt::Display for BosRig {
    /// One line: lens, distances, sensor and the expected displacement.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mm = |m: f64| m * 1e3;
        write!(
            f,
            "f = {:.0} mm, Z_A = {:.3} m, Z_D = {:.3} m, M = {:.4}; {} px of {:.2} µm ({:.1} mm sensor)",
            mm(self.focal_length),
            self.camera_distance,
            self.background_distance,
            self.magnification(),
            self.pixels,
            self.pixel_pitch * 1e6,
            mm(self.pixel_pitch * self.pixels as f64),
        )?;
        if self.deflection > 0.0 {
            write!(
                f,
                "; ε₉₉ = {:.3} mrad → Δ₉₉ ≈ {:.2} px",
                self.deflection * 1e3,
                self.displacement(self.deflection)
            )?;
            if self.limited {
                f.write_str(" (Z_D at its limit)")?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_rig_is_a_lab_rig_with_a_few_pixels_of_displacement() {
        // A 10 cm flow, deflections to 1 mrad, a 512-px image.
        let rig = BosRig::choose(&BosRigOptions::default(), 0.1, 0.1, 512, 1e-3).unwrap();
        assert!((rig.pixel_pitch * 512.0 - 2048.0 * 5.5e-6).abs() < 1e-12);
        assert!(BosRig::FOCAL_LENGTHS.contains(&rig.focal_length));
        assert!((0.5..4.0).contains(&rig.camera_distance), "{rig}");
        // The view spans the flow at its centre (thin lens, Z_A = f(1 + w/S)).
        let view = rig.pixel_pitch * 512.0 * (rig.camera_distance / rig.focal_length - 1.0);
        assert!((view / 0.105 - 1.0).abs() < 1e-9, "{view}");
        assert!((rig.displacement(1e-3) - BosRig::TARGET_DISPLACEMENT).abs() < 1e-9, "{rig}");
        assert!(!rig.limited);
    }

    #[test]
    fn weak_and_strong_flows_meet_the_limits_of_the_background_distance() {
        let weak = BosRig::choose(&BosRigOptions::default(), 0.1, 0.1, 512, 1e-9).unwrap();
        assert!(weak.limited && weak.background_distance == 2.0 * weak.camera_distance);
        let none = BosRig::choose(&BosRigOptions::default(), 0.1, 0.1, 512, 0.0).unwrap();
        assert_eq!(none.background_distance, none.camera_distance);
        let strong = BosRig::choose(&BosRigOptions::default(), 0.1, 0.1, 512, 1.0).unwrap();
        assert!(strong.limited && (strong.background_distance - 0.06).abs() < 1e-12);
    }

    #[test]
    fn fixed_values_are_kept_and_bad_ones_refused() {
        let fixed = BosRigOptions {
            focal_length: Some(0.05),
            pixel_pitch: Some(5e-6),
            camera_distance: Some(2.0),
            background_distance: Some(0.5),
        };
        let rig = BosRig::choose(&fixed, 0.1, 0.1, 512, 1e-3).unwrap();
        assert_eq!(
            (rig.focal_length, rig.pixel_pitch, rig.camera_distance, rig.background_distance),
            (0.05, 5e-6, 2.0, 0.5)
        );
        let only_distance =
            BosRigOptions { camera_distance: Some(3.0), ..BosRigOptions::default() };
        let rig = BosRig::choose(&only_distance, 0.1, 0.1, 512, 1e-3).unwrap();
        let view = rig.pixel_pitch * 512.0 * (3.0 / rig.focal_length - 1.0);
        assert!((view / 0.105 - 1.0).abs() < 1e-9);
        let bad = BosRigOptions { focal_length: Some(f64::NAN), ..BosRigOptions::default() };
        assert!(BosRig::choose(&bad, 0.1, 0.1, 512, 1e-3).is_err());
        assert!(BosRig::choose(&BosRigOptions::default(), 0.0, 0.1, 512, 1e-3).is_err());
        assert!(BosRig::choose(&BosRigOptions::default(), 0.1, 0.1, 0, 1e-3).is_err());
    }
}
