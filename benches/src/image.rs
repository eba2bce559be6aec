//! PNG output.

use std::{
    fmt,
    fs::File,
    io::BufWriter,
    path::{Path, PathBuf},
};

use rt_core::Frame;

/// Why a PNG could not be written: the file and the encoder's (or the
/// system's) error.
#[derive(Debug)]
pub struct WriteError {
    /// The file.
    pub path: PathBuf,
    /// What went wrong (I/O errors arrive as `png::EncodingError::IoError`).
    pub source: png::EncodingError,
}

impl fmt::Display for WriteError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path.display(), self.source)
    }
}

impl std::error::Error for WriteError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.source)
    }
}

/// For the tools' one-line messages.
impl From<WriteError> for String {
    fn from(e: WriteError) -> Self {
        e.to_string()
    }
}

/// Writes a frame as an 8-bit sRGB RGBA PNG (straight alpha).
///
/// # Errors
/// [`WriteError`] naming the file.
pub fn write_png(frame: &Frame, path: &Path) -> Result<(), WriteError> {
    let err = |source| WriteError { path: path.to_path_buf(), source };
    let f = File::create(path).map_err(|e| err(e.into()))?;
    let mut enc = png::Encoder::new(BufWriter::new(f), frame.width(), frame.height());
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut w = enc.write_header().map_err(err)?;
    w.write_image_data(&frame.to_srgba8()).map_err(err)
}
