//! Frames: premultiplied RGBA `f32` colour plus depth per pixel.

use alloc::vec::Vec;
use core::fmt;

pub use crate::srgb::{linear_to_srgb, srgb_to_linear};

/// One pixel: premultiplied linear RGBA and depth (the ray parameter `t` of
/// the visible surface; `+∞` for background).
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Pixel {
    /// Premultiplied `[r, g, b, a]`.
    pub color: [f32; 4],
    /// Depth `t`; `+∞` where nothing was hit.
    pub depth: f32,
}

impl Pixel {
    /// Transparent black at infinite depth: the identity of compositing.
    pub const BACKGROUND: Self = Self { color: [0.0; 4], depth: f32::INFINITY };
}

/// Why a frame could not be made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    /// Width or height is zero.
    Empty,
    /// `width × height` overflows or exceeds [`Frame::MAX_PIXELS`].
    TooLarge,
    /// The allocator could not provide the pixels.
    OutOfMemory,
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Empty => "frame width and height must be non-zero",
            Self::TooLarge => "frame size overflows or exceeds Frame::MAX_PIXELS",
            Self::OutOfMemory => "not enough memory for the frame",
        })
    }
}

impl core::error::Error for FrameError {}

/// A `width × height` image of [`Pixel`]s in row-major order, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    width: u32,
    height: u32,
    pixels: Vec<Pixel>,
}

impl Frame {
    /// The largest pixel count accepted (2²⁸, 5 GiB of pixels).
    pub const MAX_PIXELS: u64 = 1 << 28;

    /// A frame filled with [`Pixel::BACKGROUND`].
    ///
    /// # Errors
    /// [`FrameError`] for a zero or too large size, or when allocation fails.
    pub fn new(width: u32, height: u32) -> Result<Self, FrameError> {
        if width == 0 || height == 0 {
            return Err(FrameError::Empty);
        }
        let n = u64::from(width) * u64::from(height);
        if n > Self::MAX_PIXELS {
            return Err(FrameError::TooLarge);
        }
        let n = usize::try_from(n).map_err(|_| FrameError::TooLarge)?;
        let mut pixels = Vec::new();
        pixels.try_reserve_exact(n).map_err(|_| FrameError::OutOfMemory)?;
        pixels.resize(n, Pixel::BACKGROUND);
        Ok(Self { width, height, pixels })
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All pixels, row-major.
    #[must_use]
    pub fn pixels(&self) -> &[Pixel] {
        &self.pixels
    }

    /// All pixels, mutable.
    pub fn pixels_mut(&mut self) -> &mut [Pixel] {
        &mut self.pixels
    }

    /// The pixel at `(x, y)`, or `None` outside the frame.
    #[must_use]
    pub fn get(&self, x: u32, y: u32) -> Option<&Pixel> {
        (x < self.width && y < self.height)
            .then(|| &self.pixels[y as usize * self.width as usize + x as usize])
    }

    /// The pixel at `(x, y)` mutably, or `None` outside the frame.
    pub fn get_mut(&mut self, x: u32, y: u32) -> Option<&mut Pixel> {
        let w = self.width as usize;
        (x < self.width && y < self.height).then(|| &mut self.pixels[y as usize * w + x as usize])
    }

    /// The pixels as bytes (for sending or writing).
    #[must_use]
    pub fn as_bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.pixels)
    }

    /// 8-bit sRGB RGBA with straight alpha: colour is un-premultiplied,
    /// encoded with the sRGB transfer curve and rounded.
    #[must_use]
    pub fn to_srgba8(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(self.pixels.len() * 4);
        for p in &self.pixels {
            let a = p.color[3];
            let inv = if a > 0.0 { 1.0 / a } else { 0.0 };
            for c in &p.color[..3] {
                out.push(to_u8(linear_to_srgb(c * inv)));
            }
            out.push(to_u8(a));
        }
        out
    }
}

fn to_u8(x: f32) -> u8 {
    let x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    (x * 255.0 + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_validated() {
        assert_eq!(Frame::new(0, 5), Err(FrameError::Empty));
        assert_eq!(Frame::new(u32::MAX, u32::MAX), Err(FrameError::TooLarge));
        let f = Frame::new(3, 2).unwrap();
        assert_eq!(f.pixels().len(), 6);
        assert!(f.get(3, 0).is_none() && f.get(2, 1).is_some());
        assert!(f.pixels().iter().all(|p| *p == Pixel::BACKGROUND));
        assert_eq!(f.as_bytes().len(), 6 * 20);
    }

    #[test]
    fn srgb_export_unpremultiplies() {
        let mut f = Frame::new(1, 1).unwrap();
        *f.get_mut(0, 0).unwrap() = Pixel { color: [0.5, 0.0, 0.25, 0.5], depth: 1.0 };
        assert_eq!(f.to_srgba8(), alloc::vec![255, 0, 188, 128]);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
    }
}
