//! PNG output.

use std::{
    fmt,
    fs::File,
    io::BufWriter,
    path::{Path, PathBuf},
};

use rt_core::{Frame, FrameError, Pixel};

/// Why a PNG could not be written.
#[derive(Debug)]
pub enum WriteError {
    /// The file or its folder could not be created.
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
    /// The encoder failed (I/O while writing included).
    Encode {
        /// The file.
        path: PathBuf,
        /// The encoder's error.
        source: png::EncodingError,
    },
    /// The image could not be made (too large).
    Frame(FrameError),
}

impl fmt::Display for WriteError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Encode { path, source } => write!(f, "{}: {source}", path.display()),
            Self::Frame(e) => write!(f, "image: {e}"),
        }
    }
}

impl std::error::Error for WriteError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            Self::Encode { source, .. } => Some(source),
            Self::Frame(e) => Some(e),
        }
    }
}

/// For tools that report errors as text.
impl From<WriteError> for String {
    fn from(e: WriteError) -> Self {
        e.to_string()
    }
}

/// Creates `path`'s folder if it has one.
fn create_parent(path: &Path) -> Result<(), WriteError> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir)
            .map_err(|source| WriteError::Io { path: dir.to_path_buf(), source }),
        None => Ok(()),
    }
}

/// Writes a frame as an 8-bit sRGB RGBA PNG (straight alpha); creates
/// the folder.
///
/// # Errors
/// [`WriteError`] naming the file or folder.
pub fn write_png(frame: &Frame, path: &Path) -> Result<(), WriteError> {
    create_parent(path)?;
    let encode = |source| WriteError::Encode { path: path.to_path_buf(), source };
    let f = File::create(path).map_err(|source| WriteError::Io { path: path.into(), source })?;
    let mut enc = png::Encoder::new(BufWriter::new(f), frame.width(), frame.height());
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut w = enc.write_header().map_err(encode)?;
    w.write_image_data(&frame.to_srgba8()).map_err(encode)
}

/// Writes a film's image, normalised to the background and multiplied by
/// `scale` (0.5 puts an undisturbed background at mid grey), as an 8-bit
/// sRGB PNG; creates the folder.
///
/// # Errors
/// [`WriteError`] naming the file or folder.
pub fn write_film(film: &rt_photo::Film, scale: f32, path: &Path) -> Result<(), WriteError> {
    let size = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let mut frame =
        Frame::new(size(film.width()), size(film.height())).map_err(WriteError::Frame)?;
    for (p, c) in frame.pixels_mut().iter_mut().zip(film.normalized()) {
        *p = Pixel { color: [c[0] * scale, c[1] * scale, c[2] * scale, 1.0], depth: 0.0 };
    }
    write_png(&frame, path)
}
