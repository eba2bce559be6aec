//! Images read from PNGs (feature `png`): a BOS background as linear
//! luminance (what a printed or displayed pattern sends the camera), and
//! a schlieren filter painted by the user as linear RGB transmission.

use alloc::{
    string::{String, ToString},
    vec,
    vec::Vec,
};
use core::fmt;
use std::{fs::File, io::BufReader, path::Path};

use super::BackgroundChoice;
use crate::FilterImage;

/// The most pixels a PNG read here may hold (4096 × 4096).
const MAX_PIXELS: u64 = 1 << 24;

/// Why a background or filter image could not be read; each names the
/// file.
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
    /// pixels (or, for a filter, not square).
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
        let (width, height, rgb, grey) = read_linear(path)?;
        let luminance = |&[r, g, b]: &[f64; 3]| {
            if grey { r } else { 0.2126 * r + 0.7152 * g + 0.0722 * b }
        };
        let samples = rgb.iter().map(luminance).collect();
        Ok(Self::Image { width, height, samples, pixel })
    }
}

impl FilterImage {
    /// Reads a square PNG (decoded as [`BackgroundChoice::read_png`] does,
    /// but kept in colour) as a filter spanning `±half_range` radians of
    /// deflection on both axes: the image's columns left to right are
    /// `εu` rising, its rows top to bottom `εv` falling (as the image of
    /// the focal plane is seen), and each pixel's linear RGB is what it
    /// transmits. The whole square transmits ([`FilterImage::round`] off).
    ///
    /// # Errors
    /// An unreadable or malformed file, one over 4096² pixels or not
    /// square; a `half_range` that is not positive and finite.
    pub fn read_png(path: &Path, half_range: f64) -> Result<Self, PngError> {
        let (w, h, rgb, _) = read_linear(path)?;
        Self::square(path, w, h, &rgb, half_range)
    }

    /// [`FilterImage::read_png`] of a PNG's bytes (a filter painted on a
    /// page); errors name it "the painted filter".
    ///
    /// # Errors
    /// As [`FilterImage::read_png`].
    pub fn from_png(png: &[u8], half_range: f64) -> Result<Self, PngError> {
        let path = Path::new("the painted filter");
        let (w, h, rgb, _) = decode_linear(png, path)?;
        Self::square(path, w, h, &rgb, half_range)
    }

    fn square(
        path: &Path,
        w: usize,
        h: usize,
        rgb: &[[f64; 3]],
        half_range: f64,
    ) -> Result<Self, PngError> {
        let err = |what: String| PngError::Malformed { path: path.into(), what };
        if !(half_range.is_finite() && half_range > 0.0) {
            return Err(err(alloc::format!("half range {half_range} rad is not positive")));
        }
        if w != h {
            return Err(err(alloc::format!("a filter image must be square, not {w}×{h}")));
        }
        let mut filter = Self::opaque(w, half_range);
        for (row, line) in rgb.chunks_exact(w.max(1)).enumerate() {
            let j = w - 1 - row;
            for (i, p) in line.iter().enumerate() {
                filter.rgb[i + w * j] = p.map(|c| c as f32);
            }
        }
        Ok(filter)
    }
}

/// A PNG's pixels as linear RGB in `[0, 1]`, rows top first (grey
/// repeated in the three channels, and `true` for a grey file; alpha
/// ignored): decoded from sRGB unless the file says it is linear (gAMA 1.0
/// and no sRGB chunk).
fn read_linear(path: &Path) -> Result<Linear, PngError> {
    let file = File::open(path).map_err(|source| PngError::Io { path: path.into(), source })?;
    decode_linear(BufReader::new(file), path)
}

/// A PNG's pixels: width, height, linear RGB rows top first, grey.
type Linear = (usize, usize, Vec<[f64; 3]>, bool);

/// [`read_linear`] from any reader; errors name `path`.
fn decode_linear<R: std::io::Read>(source: R, path: &Path) -> Result<Linear, PngError> {
    let err = |what: String| PngError::Malformed { path: path.into(), what };
    let mut decoder = png::Decoder::new(source);
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
    let mut pixels = Vec::with_capacity(wu * hu);
    for row in buf[..frame.buffer_size()].chunks_exact(frame.line_size).take(hu) {
        for x in 0..wu {
            let at = |c: usize| {
                let i = x * channels + c;
                decode(if wide {
                    f64::from(u16::from_be_bytes([row[2 * i], row[2 * i + 1]])) / 65535.0
                } else {
                    f64::from(row[i]) / 255.0
                })
            };
            pixels.push(if channels < 3 { [at(0); 3] } else { [at(0), at(1), at(2)] });
        }
    }
    if pixels.len() != wu * hu {
        return Err(err("the image data is short".into()));
    }
    Ok((wu, hu, pixels, channels < 3))
}

/// The sRGB decoding (IEC 61966-2-1) of `c ∈ [0, 1]`.
fn srgb_to_linear(c: f64) -> f64 {
    if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}
