//! A background image read from a PNG (feature `png`), as linear
//! luminance: what a printed or displayed pattern sends the camera.

use alloc::{
    string::{String, ToString},
    vec,
    vec::Vec,
};
use core::fmt;
use std::{fs::File, io::BufReader, path::Path};

use super::BackgroundChoice;

/// The most pixels [`BackgroundChoice::read_png`] reads (4096 × 4096).
const MAX_PIXELS: u64 = 1 << 24;

/// Why a background image could not be read; each names the file.
#[derive(Debug)]
pub enum PngError {
    /// The file could not be opened or read.
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// The file is not a PNG we read: malformed, truncated, over 4096²
    /// pixels.
    Malformed {
        /// The file.
        path: std::path::PathBuf,
        /// What is wrong with it.
        what: String,
    },
}

impl fmt::Display for PngError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Malformed { path, what } => write!(f, "{}: {what}", path.display()),
        }
    }
}

impl core::error::Error for PngError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            Self::Malformed { .. } => None,
        }
    }
}

impl BackgroundChoice {
    /// Reads a PNG (grey or colour, 1–16 bits, palette included; alpha
    /// ignored) as a background image of linear luminance: samples decoded
    /// from sRGB, unless the file says it is linear (gAMA 1.0 and no sRGB
    /// chunk, as `rt` writes its counts), then `Y = 0.2126 R + 0.7152 G +
    /// 0.0722 B` (Rec. 709) for colour. Each image pixel covers `pixel`
    /// sensor pixels as imaged (`None`: the image spans the sensor).
    ///
    /// # Errors
    /// An unreadable or malformed file, or one over 4096² pixels.
    pub fn read_png(path: &Path, pixel: Option<f64>) -> Result<Self, PngError> {
        let err = |what: String| PngError::Malformed { path: path.into(), what };
        let file = File::open(path).map_err(|source| PngError::Io { path: path.into(), source })?;
        let mut decoder = png::Decoder::new(BufReader::new(file));
        decoder.set_transformations(png::Transformations::EXPAND);
        let mut reader = decoder.read_info().map_err(|e| err(e.to_string()))?;
        let info = reader.info();
        let (w, h) = (info.width, info.height);
        if u64::from(w) * u64::from(h) > MAX_PIXELS {
            return Err(err(alloc::format!("{w}×{h} pixels, at most {MAX_PIXELS} read")));
        }
        let linear = info.srgb.is_none()
            && info.source_gamma.is_some_and(|g| (g.into_value() - 1.0).abs() < 0.01);
        let mut buf = vec![0; reader.output_buffer_size()];
        let frame = reader.next_frame(&mut buf).map_err(|e| err(e.to_string()))?;
        let channels = match frame.color_type {
            png::ColorType::Grayscale => 1,
            png::ColorType::GrayscaleAlpha => 2,
            png::ColorType::Rgb => 3,
            png::ColorType::Rgba => 4,
            png::ColorType::Indexed => return Err(err("palette not expanded".into())),
        };
        let wide = frame.bit_depth == png::BitDepth::Sixteen;
        let decode = |c: f64| if linear { c } else { srgb_to_linear(c) };
        let (wu, hu) = (w as usize, h as usize);
        let mut samples = Vec::with_capacity(wu * hu);
        for row in buf[..frame.buffer_size()].chunks_exact(frame.line_size).take(hu) {
            for x in 0..wu {
                let at = |c: usize| {
                    let i = x * channels + c;
                    if wide {
                        f64::from(u16::from_be_bytes([row[2 * i], row[2 * i + 1]])) / 65535.0
                    } else {
                        f64::from(row[i]) / 255.0
                    }
                };
                samples.push(if channels < 3 {
                    decode(at(0))
                } else {
                    0.2126 * decode(at(0)) + 0.7152 * decode(at(1)) + 0.0722 * decode(at(2))
                });
            }
        }
        if samples.len() != wu * hu {
            return Err(err("the image data is short".into()));
        }
        Ok(Self::Image { width: wu, height: hu, samples, pixel })
    }
}

/// The sRGB decoding (IEC 61966-2-1) of `c ∈ [0, 1]`.
fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}
