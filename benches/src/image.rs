//! PNG output.

use std::{fs::File, io::BufWriter, path::Path};

use rt_core::Frame;

/// Writes a frame as an 8-bit sRGB RGBA PNG (straight alpha).
///
/// # Errors
/// I/O or encoding errors, as text naming the file.
pub fn write_png(frame: &Frame, path: &Path) -> Result<(), String> {
    let f = File::create(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut enc = png::Encoder::new(BufWriter::new(f), frame.width(), frame.height());
    enc.set_color(png::ColorType::Rgba);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let mut w = enc.write_header().map_err(|e| format!("{}: {e}", path.display()))?;
    w.write_image_data(&frame.to_srgba8()).map_err(|e| format!("{}: {e}", path.display()))
}
