//! PNG output, and PNG input of a grey image (a BOS background).

use std::{
    fmt,
    fs::File,
    io::BufWriter,
    path::{Path, PathBuf},
};

use anyhow::{Context, bail};

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

/// The companion of a PNG: `<path's stem>-<suffix>.png` in its folder
/// (`out/a.png`, `figure` → `out/a-figure.png`).
#[must_use]
pub fn beside(path: &Path, suffix: &str) -> PathBuf {
    let stem = path.file_stem().map_or("image".into(), |s| s.to_string_lossy());
    path.with_file_name(format!("{stem}-{suffix}.png"))
}

/// Creates `path`'s folder if it has one.
fn create_parent(path: &Path) -> Result<(), WriteError> {
    match path.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(dir) => std::fs::create_dir_all(dir)
            .map_err(|source| WriteError::Io { path: dir.to_path_buf(), source }),
        None => Ok(()),
    }
}

/// Encodes `data` (rows top first; 16-bit samples big-endian, as PNG
/// wants) as a PNG of `color` and `depth`; `srgb` marks it sRGB, else
/// linear (gAMA 1.0); `text` adds one `tEXt` comment. Creates the folder.
fn encode(
    path: &Path,
    size: (u32, u32),
    format: (png::ColorType, png::BitDepth),
    srgb: bool,
    text: Option<&str>,
    data: &[u8],
) -> Result<(), WriteError> {
    create_parent(path)?;
    let f = File::create(path).map_err(|source| WriteError::Io { path: path.into(), source })?;
    encode_to(BufWriter::new(f), size, format, srgb, text, data)
        .map_err(|source| WriteError::Encode { path: path.to_path_buf(), source })
}

/// [`encode`] into any writer.
fn encode_to<W: std::io::Write>(
    out: W,
    (width, height): (u32, u32),
    (color, depth): (png::ColorType, png::BitDepth),
    srgb: bool,
    text: Option<&str>,
    data: &[u8],
) -> Result<(), png::EncodingError> {
    let mut enc = png::Encoder::new(out, width, height);
    enc.set_color(color);
    enc.set_depth(depth);
    if srgb {
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    } else {
        enc.set_source_gamma(png::ScaledFloat::new(1.0));
    }
    if let Some(text) = text {
        enc.add_text_chunk("Comment".to_string(), text.to_string())?;
    }
    let mut w = enc.write_header()?;
    w.write_image_data(data)?;
    w.finish()
}

/// A frame as the bytes of the PNG [`write_png`] writes (to serve it).
///
/// # Errors
/// The encoder's error (none in practice for a frame's size).
pub fn png_bytes(frame: &Frame) -> Result<Vec<u8>, png::EncodingError> {
    let mut out = Vec::new();
    let format = (png::ColorType::Rgba, png::BitDepth::Eight);
    encode_to(&mut out, (frame.width(), frame.height()), format, true, None, &frame.to_srgba8())?;
    Ok(out)
}

/// Writes a frame as an 8-bit sRGB RGBA PNG (straight alpha); creates
/// the folder.
///
/// # Errors
/// [`WriteError`] naming the file or folder.
pub fn write_png(frame: &Frame, path: &Path) -> Result<(), WriteError> {
    let format = (png::ColorType::Rgba, png::BitDepth::Eight);
    encode(path, (frame.width(), frame.height()), format, true, None, &frame.to_srgba8())
}

/// Writes 8-bit sRGB RGB pixels (rows top first) as a PNG; creates the
/// folder.
///
/// # Errors
/// [`WriteError`] naming the file or folder.
///
/// # Panics
/// If `rgb` does not hold `3 × width × height` bytes.
pub fn write_rgb8(rgb: &[u8], width: u32, height: u32, path: &Path) -> Result<(), WriteError> {
    assert_eq!(rgb.len() as u64, 3 * u64::from(width) * u64::from(height), "RGB buffer size");
    let format = (png::ColorType::Rgb, png::BitDepth::Eight);
    encode(path, (width, height), format, true, None, rgb)
}

/// Writes sensor counts (rows top first) of `bits` bits as a grey PNG:
/// 8-bit for `bits ≤ 8`, else 16-bit with the counts in the high bits
/// (scaled by `2^(16 − bits)`), linear (gAMA 1.0), as a camera writes raw
/// frames; creates the folder.
///
/// # Errors
/// [`WriteError`] naming the file or folder.
///
/// # Panics
/// If `counts` does not hold `width × height` samples.
pub fn write_counts(
    counts: &[u16],
    bits: u32,
    width: u32,
    height: u32,
    path: &Path,
) -> Result<(), WriteError> {
    assert_eq!(counts.len() as u64, u64::from(width) * u64::from(height), "counts buffer size");
    let text = format!("rt: sensor counts of {bits} bits");
    if bits <= 8 {
        let data: Vec<u8> = counts.iter().map(|&c| c.min(255) as u8).collect();
        let format = (png::ColorType::Grayscale, png::BitDepth::Eight);
        encode(path, (width, height), format, false, Some(&text), &data)
    } else {
        let shift = 16 - bits.min(16);
        let data: Vec<u8> = counts.iter().flat_map(|&c| (c << shift).to_be_bytes()).collect();
        let format = (png::ColorType::Grayscale, png::BitDepth::Sixteen);
        encode(path, (width, height), format, false, Some(&text), &data)
    }
}

/// Composites `frame` (premultiplied) over an opaque vertical gradient
/// of linear RGB, `top` in the first row to `bottom` in the last (equal
/// for a plain colour): `c + (1 − α)·background`, alpha 1 everywhere.
/// Depth is left as it is.
pub fn over_background(frame: &mut Frame, top: [f32; 3], bottom: [f32; 3]) {
    let (w, h) = (frame.width() as usize, frame.height() as usize);
    for (y, row) in frame.pixels_mut().chunks_mut(w.max(1)).enumerate() {
        let t = if h > 1 { y as f32 / (h - 1) as f32 } else { 0.0 };
        let bg: [f32; 3] = core::array::from_fn(|k| top[k] + t * (bottom[k] - top[k]));
        for p in row {
            let clear = 1.0 - p.color[3].clamp(0.0, 1.0);
            for (c, b) in p.color.iter_mut().zip(bg) {
                *c += clear * b;
            }
            p.color[3] = 1.0;
        }
    }
}

/// A film's image as an opaque frame: normalised to the background and
/// multiplied by `scale` (0.5 puts an undisturbed, uncut background at
/// mid grey).
///
/// # Errors
/// [`WriteError::Frame`] for an image too large for a frame.
pub fn film_frame(film: &rt_photo::Film, scale: f32) -> Result<Frame, WriteError> {
    let size = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let mut frame =
        Frame::new(size(film.width()), size(film.height())).map_err(WriteError::Frame)?;
    for (p, c) in frame.pixels_mut().iter_mut().zip(film.normalized()) {
        *p = Pixel { color: [c[0] * scale, c[1] * scale, c[2] * scale, 1.0], depth: 0.0 };
    }
    Ok(frame)
}

/// Writes a film's image, normalised to the background and multiplied by
/// `scale` (0.5 puts an undisturbed background at mid grey), as an 8-bit
/// sRGB PNG; creates the folder.
///
/// # Errors
/// [`WriteError`] naming the file or folder.
pub fn write_film(film: &rt_photo::Film, scale: f32, path: &Path) -> Result<(), WriteError> {
    write_png(&film_frame(film, scale)?, path)
}

/// The 16-bit value of the light an undisturbed beam gives with nothing
/// cut: `--raw16` images store `RAW16_UNIT × I / I₀` (linear, clamped to
/// 65535), so values up to twice the uncut background are kept.
pub const RAW16_UNIT: f64 = 32768.0;

/// Writes a film's image as a linear 16-bit PNG for measurements: each
/// sample is `RAW16_UNIT × I/I₀` rounded and clamped to `0..=65535`, `I/I₀`
/// the intensity relative to an undisturbed beam with nothing cut
/// ([`rt_photo::Film::normalized_f64`]; 1 → 32768). So a knife edge's
/// undisturbed background (half the source cut) reads 16384, a
/// shadowgraph's 32768, its caustics up to 2× before they clip. Grey
/// (one channel, the mean of three) unless `color` (RGB, for the colour
/// filter). Marked linear (gAMA 1.0), with the scale in a `tEXt`
/// comment. Creates the folder.
///
/// # Errors
/// [`WriteError`] naming the file or folder, or an image too large.
pub fn write_film16(film: &rt_photo::Film, color: bool, path: &Path) -> Result<(), WriteError> {
    let size = |n: usize| u32::try_from(n).map_err(|_| WriteError::Frame(FrameError::TooLarge));
    let (w, h) = (size(film.width())?, size(film.height())?);
    let to16 = |x: f64| -> [u8; 2] {
        let v = if x > 0.0 { (x * RAW16_UNIT).round().min(65535.0) } else { 0.0 };
        (v as u16).to_be_bytes()
    };
    let pixels = film.normalized_f64();
    let mut data = Vec::with_capacity(pixels.len() * if color { 6 } else { 2 });
    for c in pixels {
        if color {
            data.extend(c.iter().flat_map(|&x| to16(x)));
        } else {
            data.extend(to16((c[0] + c[1] + c[2]) / 3.0));
        }
    }
    let kind = if color { png::ColorType::Rgb } else { png::ColorType::Grayscale };
    let text = format!(
        "rt: linear intensity; value / {RAW16_UNIT} = I/I0, I0 the undisturbed beam with nothing cut"
    );
    encode(path, (w, h), (kind, png::BitDepth::Sixteen), false, Some(&text), &data)
}

/// Writes `data` (`components` values per pixel, `width × height` pixels,
/// rows top first) as raw little-endian float32 with a JSON sidecar
/// beside it (`rt`'s raw + JSON format), both staged in `outs` (which
/// must hold `raw` and its `.json`): `description` says what the values
/// are.
///
/// # Errors
/// An unwritable path, or `data` not `components × width × height` long.
pub fn write_raw_f32(
    outs: &crate::output::Outputs,
    raw: &Path,
    data: &[f64],
    components: usize,
    width: usize,
    height: usize,
    description: &str,
) -> anyhow::Result<()> {
    if data.len() != components * width * height {
        bail!("{}: {} values for {width}×{height}×{components}", raw.display(), data.len());
    }
    let bytes: Vec<u8> = data.iter().flat_map(|&x| (x as f32).to_le_bytes()).collect();
    std::fs::write(outs.staging(raw), bytes).with_context(|| raw.display().to_string())?;
    let json = serde_json::json!({
        "dims": [width, height],
        "components": components,
        "dtype": "float32",
        "endian": "little",
        "file": raw.file_name().map(|f| f.to_string_lossy().into_owned()),
        "description": description,
    });
    let path = raw.with_extension("json");
    std::fs::write(outs.staging(&path), serde_json::to_string_pretty(&json)?)
        .with_context(|| path.display().to_string())?;
    Ok(())
}
