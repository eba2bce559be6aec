//! Laboratory rigs chosen for a flow: what an experimentalist would set up
//! to photograph it with BOS ([`BosRig`]) or focusing schlieren
//! ([`FocusingRig`]), where the user has not said otherwise.
//!
//! Both have a real camera: a sensor of a fixed physical size (here 2048
//! pixels of 5.5 µm, 11.3 mm across; a smaller image is that sensor
//! binned, so its pixels are larger and the field of view stays), a lens
//! from the usual range of focal lengths, about 1.5 m from the flow.
//!
//! BOS: the background behind the flow. Sensitivity is set by the
//! background distance
//! `Z_D`: paraxially the background's image moves by
//! `Δ = M·Z_D·ε / pitch` pixels, `M = f/(Z_A + Z_D − f)`, so `Z_D` is
//! chosen for the flow's strongest deflections (the 99th percentile of a
//! survey) to move the image a few pixels: the range window
//! cross-correlation follows well, where the dots are not yet smeared.
//!
//! Focusing schlieren (Weinstein 1993) images the flow with a schlieren
//! lens of large aperture, whose image is relayed to a camera: the lens's
//! f-number, not a camera sensor's size, is what is physical there. The
//! default: the lens twice the flow's width from it, focal length a
//! quarter of that distance at f/2 (`D = Z/8`, as a large-field system's
//! lens); the image plane's pixels sized so the flow fills the image; the
//! source grid as far behind the focus plane as the lens is in front; its
//! pitch chosen for the flow (the 99th-percentile deflection across the
//! bands uses 80 % of the cutoff's linear range) but kept to 25–100
//! periods across the aperture's view of the source plane. With fewer, a
//! pixel's disc of view holds a share of the bands that changes with its
//! position, and the undisturbed image ripples (over `N` periods by up to
//! about `3.6·J₁(πN)/(πN)` of the mean for a quarter-pitch cutoff: 0.6 %
//! at N = 25).

use core::fmt;

use crate::bos::BosError;
use crate::focusing::FocusingError;

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

/// Pixels across the default sensor, and their pitch (metres).
const SENSOR_PIXELS: usize = 2048;
const SENSOR_PITCH: f64 = 5.5e-6;
/// The usual prime lenses (metres).
const FOCAL_LENGTHS: [f64; 9] = [0.024, 0.035, 0.05, 0.085, 0.105, 0.135, 0.2, 0.3, 0.4];
/// The camera distance a default lens is picked for (metres).
const LAB_DISTANCE: f64 = 1.5;
/// The field of view spans the flow's width and this margin.
const MARGIN: f64 = 1.05;

/// The camera for a flow `width` across on `pixels` pixels: `(pixel
/// pitch, focal length, distance to the flow)`, each as fixed or chosen:
/// the default sensor binned to `pixels`; the usual lens that fills the
/// view with the flow nearest [`LAB_DISTANCE`] (with the distance fixed,
/// the focal length that fills it there); the distance that fills the
/// view (thin lens, `Z = f·(1 + 1/M)`).
fn lab_camera(
    width: f64,
    pixels: usize,
    pitch: Option<f64>,
    focal_length: Option<f64>,
    distance: Option<f64>,
) -> (f64, f64, f64) {
    let pitch = pitch.unwrap_or(SENSOR_PITCH * SENSOR_PIXELS as f64 / pixels as f64);
    // The object-to-sensor ratio that fills the view: Z = f·(1 + ratio).
    let ratio = MARGIN * width / (pitch * pixels as f64);
    let f = match (focal_length, distance) {
        (Some(f), _) => f,
        (None, Some(z)) => z / (1.0 + ratio),
        (None, None) => {
            let miss = |f: f64| (f * (1.0 + ratio) / LAB_DISTANCE).ln().abs();
            FOCAL_LENGTHS.into_iter().min_by(|a, b| miss(*a).total_cmp(&miss(*b))).unwrap_or(0.1)
        }
    };
    (pitch, f, distance.unwrap_or(f * (1.0 + ratio)))
}

/// What the user fixed of a focusing-schlieren rig (`None`: chosen by
/// [`FocusingRig::choose`]). Lengths in metres.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FocusingRigOptions {
    /// Focal length of the schlieren lens, `f`.
    pub focal_length: Option<f64>,
    /// Its aperture diameter `D`.
    pub aperture: Option<f64>,
    /// Pitch of an image pixel on the sensor.
    pub pixel_pitch: Option<f64>,
    /// Lens to the flow's centre, `Z`.
    pub camera_distance: Option<f64>,
    /// Lens to the source grid, `Z_S`.
    pub source_distance: Option<f64>,
    /// The source grid's pitch on its plane.
    pub grid_pitch: Option<f64>,
}

/// A focusing-schlieren rig (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FocusingRig {
    /// Image pixels across.
    pub pixels: usize,
    /// Pitch of an image pixel on the sensor.
    pub pixel_pitch: f64,
    /// Focal length `f` of the schlieren lens.
    pub focal_length: f64,
    /// Its aperture diameter `D`.
    pub aperture: f64,
    /// Lens to the flow's centre, `Z`.
    pub camera_distance: f64,
    /// Lens to the plane in focus, `Z_F`.
    pub focus_distance: f64,
    /// Lens to the source grid, `Z_S`.
    pub source_distance: f64,
    /// The source grid's pitch on its plane.
    pub grid_pitch: f64,
    /// The pitch the flow's deflections asked for lay outside the
    /// 25–100 periods across the view (strong deflections then saturate,
    /// or weak ones show less contrast).
    pub limited: bool,
}

impl FocusingRig {
    /// The f-number a default rig opens its lens to.
    pub const F_NUMBER: f64 = 2.0;
    /// Fewest and most periods of the source grid across the aperture's
    /// view of the source plane a default grid has.
    pub const PERIODS: (f64, f64) = (25.0, 100.0);

    /// The rig for a flow `width` across the image, imaged on `pixels`
    /// pixels, focused `focus` toward the lens from its centre, with a
    /// cutoff shifted `offset` pitches, whose deflection across the bands
    /// reaches `deflection` (radians, the 99th percentile; 0 if none); what
    /// is not fixed: the lens `2·width` from the flow's centre, its focal
    /// length a quarter of that, at f/2; the image plane's pixels such that
    /// the flow's width and 5 % fill the image; the source grid at twice
    /// the focus distance, its pitch such that the deflection moves the
    /// source's image by 80 % of the offset (`ε·(Z_S − Z_F) = 0.8·o`), kept
    /// to [`FocusingRig::PERIODS`] periods across the aperture's view
    /// `D·(Z_S − Z_F)/Z_F`.
    ///
    /// # Errors
    /// [`FocusingError::Setup`] for a size or fixed value that is not
    /// finite and > 0, no pixels, or the focus plane not beyond the focal
    /// length and before the source.
    pub fn choose(
        fixed: &FocusingRigOptions,
        width: f64,
        pixels: usize,
        focus: f64,
        offset: f64,
        deflection: f64,
    ) -> Result<Self, FocusingError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !pos(width) || pixels == 0 || !focus.is_finite() {
            return Err(FocusingError::Setup("the flow's size and the image width must be > 0"));
        }
        let given = [
            fixed.focal_length,
            fixed.aperture,
            fixed.pixel_pitch,
            fixed.camera_distance,
            fixed.source_distance,
            fixed.grid_pitch,
        ];
        if !given.iter().flatten().all(|&v| pos(v)) {
            return Err(FocusingError::Setup("lengths of the rig must be finite and > 0"));
        }
        let z = fixed.camera_distance.unwrap_or(2.0 * width);
        let f = match (fixed.focal_length, fixed.aperture) {
            (Some(f), _) => f,
            (None, Some(d)) => (Self::F_NUMBER * d).min(0.5 * z),
            (None, None) => 0.25 * z,
        };
        let z_f = z - focus;
        if z_f <= f {
            return Err(FocusingError::Setup(
                "the focus plane must be farther from the lens than its focal length",
            ));
        }
        let z_s = fixed.source_distance.unwrap_or(2.0 * z_f);
        if z_s <= z_f {
            return Err(FocusingError::Setup("the source grid must lie beyond the focus plane"));
        }
        let aperture = fixed.aperture.unwrap_or(f / Self::F_NUMBER);
        // The focus plane's magnification M = f/(Z_F − f) at the centre.
        let pitch = fixed.pixel_pitch.unwrap_or(MARGIN * width * f / (z - f) / pixels as f64);
        let view = aperture * (z_s - z_f) / z_f;
        let (grid_pitch, limited) = match fixed.grid_pitch {
            Some(p) => (p, false),
            None => {
                let (few, many) = Self::PERIODS;
                let eps = if deflection.is_finite() { deflection.abs() } else { 0.0 };
                let want = if eps > 0.0 && offset > 0.0 {
                    eps * (z_s - z_f) / (0.8 * offset)
                } else {
                    view / few
                };
                let (fine, coarse) = (view / many, view / few);
                (want.clamp(fine, coarse), !(fine..=coarse).contains(&want))
            }
        };
        Ok(Self {
            pixels,
            pixel_pitch: pitch,
            focal_length: f,
            aperture,
            camera_distance: z,
            focus_distance: z_f,
            source_distance: z_s,
            grid_pitch,
            limited,
        })
    }

    /// Periods of the source grid across the aperture's view of the source
    /// plane, `D·(Z_S − Z_F)/(Z_F·p)`.
    #[must_use]
    pub fn periods_in_view(&self) -> f64 {
        self.aperture * (self.source_distance - self.focus_distance)
            / self.focus_distance
            / self.grid_pitch
    }
}

impl fmt::Display for FocusingRig {
    /// One line: lens, distances, grid and sensor.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "schlieren lens f = {:.0} mm at f/{:.1} (D = {:.1} mm), Z = {:.3} m, focus {:.3} m, source grid at {:.3} m, pitch {:.3} mm ({:.0} periods across the view{}); image plane {} px of {:.3} mm",
            self.focal_length * 1e3,
            self.focal_length / self.aperture,
            self.aperture * 1e3,
            self.camera_distance,
            self.focus_distance,
            self.source_distance,
            self.grid_pitch * 1e3,
            self.periods_in_view(),
            if self.limited { ", at its limit" } else { "" },
            self.pixels,
            self.pixel_pitch * 1e3,
        )
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
    fn the_default_focusing_rig_opens_the_lens_and_puts_tens_of_bands_in_view() {
        let o = FocusingRigOptions::default();
        let rig = FocusingRig::choose(&o, 0.2, 512, 0.0, 0.25, 1e-4).unwrap();
        assert!(rig.focal_length / rig.aperture >= 2.0 - 1e-12, "{rig}");
        assert!((rig.source_distance - 2.0 * rig.focus_distance).abs() < 1e-12);
        let n = rig.periods_in_view();
        assert!((25.0 - 1e-9..=100.0 + 1e-9).contains(&n), "{rig}");
        // Weak flows ask for a fine grid, held at 100 periods; strong ones
        // a coarse grid, held at 25 (their strongest deflections saturate).
        let weak = FocusingRig::choose(&o, 0.2, 512, 0.0, 0.25, 1e-9).unwrap();
        assert!(weak.limited && (weak.periods_in_view() - 100.0).abs() < 1e-9);
        let strong = FocusingRig::choose(&o, 0.2, 512, 0.0, 0.25, 1.0).unwrap();
        assert!(strong.limited && (strong.periods_in_view() - 25.0).abs() < 1e-9);
        // The flow and 5 % fill the image: M·1.05·width = pixels·pitch.
        let m = rig.focal_length / (rig.focus_distance - rig.focal_length);
        assert!((m * 1.05 * 0.2 / (512.0 * rig.pixel_pitch) - 1.0).abs() < 1e-12);
        // Between the limits the pitch is the flow's: ε·(Z_S − Z_F) = 0.8·o.
        let eps = 0.8 * 0.25 * rig.aperture / rig.focus_distance / 50.0
            * (rig.focus_distance / (rig.source_distance - rig.focus_distance));
        let mid = FocusingRig::choose(&o, 0.2, 512, 0.0, 0.25, eps).unwrap();
        let lever = mid.source_distance - mid.focus_distance;
        assert!(!mid.limited && (eps * lever / (0.8 * 0.25 * mid.grid_pitch) - 1.0).abs() < 1e-9);
        assert!(FocusingRig::choose(&o, 0.2, 512, 10.0, 0.25, 1e-4).is_err());
        let bad = FocusingRigOptions { aperture: Some(-1.0), ..o };
        assert!(FocusingRig::choose(&bad, 0.2, 512, 0.0, 0.25, 1e-4).is_err());
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
