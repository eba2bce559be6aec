//! What is wrong with a sensor's settings or the image given to it, and
//! the image check the sensor and the lens's diffraction share.

use core::fmt;

/// What is wrong with a [`Sensor`](super::Sensor) or the image given to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SensorError {
    /// `exposure` is not finite and ≥ 0.
    Exposure(f64),
    /// `full_well` is not finite and > 0.
    FullWell(f64),
    /// `bits` is not in 1–16.
    Bits(u32),
    /// `read_noise` is not finite and ≥ 0.
    ReadNoise(f64),
    /// The image's length is not `width × height` (or that is 0).
    ImageSize {
        /// `width × height`.
        expected: usize,
        /// Samples given.
        found: usize,
    },
    /// A sample is NaN, infinite or negative (an intensity is ≥ 0).
    Sample {
        /// Its index.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The [`Airy`](super::Airy) wavelength is not finite and > 0.
    Wavelength(f64),
    /// The [`Airy`](super::Airy) f-number is not finite and > 0.
    FNumber(f64),
    /// The [`Airy`](super::Airy) pixel pitch is not finite and > 0.
    PixelPitch(f64),
    /// The [`Airy`](super::Airy) pattern is too wide for the pixels: `λN` (given, in
    /// pixels) above 24, whose kernel would pass 512 pixels in radius.
    AiryTooWide(f64),
}

impl fmt::Display for SensorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Exposure(v) => write!(f, "exposure must be finite and ≥ 0 electrons (got {v})"),
            Self::FullWell(v) => write!(f, "full well must be finite and > 0 electrons (got {v})"),
            Self::Bits(b) => write!(f, "bits must be 1 to 16 (got {b})"),
            Self::ReadNoise(v) => {
                write!(f, "read noise must be finite and ≥ 0 electrons (got {v})")
            }
            Self::ImageSize { expected, found } => {
                write!(
                    f,
                    "image has {found} samples, width × height is {expected} (and must not be 0)"
                )
            }
            Self::Sample { index, value } => {
                write!(f, "intensity {index} is {value}: must be finite and ≥ 0")
            }
            Self::Wavelength(v) => {
                write!(f, "diffraction: wavelength must be finite and > 0 metres (got {v})")
            }
            Self::FNumber(v) => write!(f, "diffraction: f-number must be finite and > 0 (got {v})"),
            Self::PixelPitch(v) => {
                write!(f, "diffraction: pixel pitch must be finite and > 0 metres (got {v})")
            }
            Self::AiryTooWide(v) => write!(
                f,
                "diffraction: λN is {v} pixels, at most about 24 (an Airy kernel of at most 512 pixels in radius)"
            ),
        }
    }
}

impl core::error::Error for SensorError {}

/// Checks that `image` has `width × height > 0` samples, each a finite
/// intensity ≥ 0.
pub(crate) fn check_image(image: &[f64], width: usize, height: usize) -> Result<(), SensorError> {
    let expected = width.checked_mul(height).unwrap_or(0);
    if expected == 0 || image.len() != expected {
        return Err(SensorError::ImageSize { expected, found: image.len() });
    }
    if let Some(index) = image.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(SensorError::Sample { index, value: image[index] });
    }
    Ok(())
}
