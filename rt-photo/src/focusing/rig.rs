//! A laboratory focusing-schlieren rig chosen for a flow (Weinstein
//! 1993), where the user has not said otherwise. A schlieren lens of large
//! aperture images the flow and is relayed to a camera: the lens's
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

use super::FocusingError;
use crate::camera::lab::MARGIN;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
