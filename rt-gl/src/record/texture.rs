//! 2-D textures as the fixed-function pipeline applies them (OpenGL 2.1
//! §3.8): level 0 of each texture object, unpacked to RGBA8 as
//! `glTexImage2D` reads it, sampled with its wrap and filter modes, and
//! combined with the fragment's colour by the texture environment
//! (table 3.22/3.23: `GL_MODULATE`, `GL_REPLACE`, `GL_DECAL`, `GL_BLEND`,
//! `GL_ADD`).
//!
//! Approximated: only level 0 is kept, so a minified texture is sampled
//! with the magnification filter rather than from the mipmap GL would
//! pick (a ray has no pixel footprint); `glTexGen`'s normal and
//! reflection maps, 1-D, 3-D and cube-map textures are not traced (a
//! pass drawn with them is kept as GL drew it). Object-linear,
//! eye-linear and sphere-map coordinates are generated per vertex, as GL
//! does (`Recorder::generated_texcoord`).

use glam::{Vec2, Vec4};

use crate::gl;

/// Largest texture side kept (GL's `GL_MAX_TEXTURE_SIZE` on common
/// hardware); bigger images are not recorded.
pub const MAX_TEXTURE_SIZE: u32 = 16384;

/// The base internal format: which of the texel's channels exist, and so
/// how the environment combines them (GL 2.1 table 3.15).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BaseFormat {
    /// `GL_ALPHA`.
    Alpha,
    /// `GL_LUMINANCE`.
    Luminance,
    /// `GL_LUMINANCE_ALPHA`.
    LuminanceAlpha,
    /// `GL_INTENSITY`.
    Intensity,
    /// `GL_RGB`.
    Rgb,
    /// `GL_RGBA`.
    Rgba,
}

impl BaseFormat {
    /// The base format of an internal format (sized or not).
    #[must_use]
    pub fn of(internal: u32) -> Self {
        match internal {
            0x1906 | 0x803B..=0x803E => Self::Alpha,
            1 | 0x1909 | 0x803F..=0x8042 => Self::Luminance,
            2 | 0x190A | 0x8043..=0x8048 => Self::LuminanceAlpha,
            0x8049..=0x804D => Self::Intensity,
            3 | 0x1907 | 0x2A10 | 0x804F..=0x8054 | 0x8C40 | 0x8C41 => Self::Rgb,
            _ => Self::Rgba,
        }
    }
}

/// How `glPixelStore` says client pixel rectangles are laid out
/// (`GL_UNPACK_*`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelStore {
    /// `GL_UNPACK_ALIGNMENT` (1, 2, 4 or 8).
    pub alignment: usize,
    /// `GL_UNPACK_ROW_LENGTH` (0: the image's width).
    pub row_length: usize,
    /// `GL_UNPACK_SKIP_ROWS`.
    pub skip_rows: usize,
    /// `GL_UNPACK_SKIP_PIXELS`.
    pub skip_pixels: usize,
}

impl Default for PixelStore {
    fn default() -> Self {
        Self { alignment: 4, row_length: 0, skip_rows: 0, skip_pixels: 0 }
    }
}

/// Components per pixel of a client `format`, and bytes per component of
/// `ty`; `None` for what is not read (packed and compressed types).
#[must_use]
pub fn pixel_layout(format: u32, ty: u32) -> Option<(usize, usize)> {
    let components = match format {
        // RED, GREEN, BLUE, ALPHA, LUMINANCE, INTENSITY.
        0x1903..=0x1906 | 0x1909 | 0x8049 => 1,
        0x190A => 2,
        gl::RGB | 0x80E0 => 3,
        gl::RGBA | 0x80E1 => 4,
        _ => return None,
    };
    let bytes = match ty {
        gl::UNSIGNED_BYTE | gl::BYTE => 1,
        gl::UNSIGNED_SHORT | gl::SHORT => 2,
        gl::FLOAT | gl::UNSIGNED_INT | gl::INT => 4,
        _ => return None,
    };
    Some((components, bytes))
}

impl PixelStore {
    /// Bytes from the pointer a `width × height` image of `format` and
    /// `ty` spans, or `None` if it cannot be read.
    #[must_use]
    pub fn image_bytes(&self, width: usize, height: usize, format: u32, ty: u32) -> Option<usize> {
        let (components, size) = pixel_layout(format, ty)?;
        if width == 0 || height == 0 {
            return Some(0);
        }
        let pixel = components * size;
        let row = self.row_stride(width, pixel)?;
        let last = (self.skip_rows + height - 1).checked_mul(row)?;
        last.checked_add((self.skip_pixels + width).checked_mul(pixel)?)
    }

    fn row_stride(&self, width: usize, pixel: usize) -> Option<usize> {
        let length = if self.row_length > 0 { self.row_length } else { width };
        let bytes = length.checked_mul(pixel)?;
        let a = self.alignment.max(1);
        // GL pads rows to the alignment only for components smaller than it.
        Some(if pixel.is_multiple_of(a) { bytes } else { bytes.div_ceil(a) * a })
    }
}

/// One texture object's level 0 and parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// RGBA texels, bottom row first (as GL stores them); channels the
    /// base format lacks are as GL expands them.
    pub texels: Vec<[u8; 4]>,
    /// The base internal format.
    pub format: BaseFormat,
    /// `GL_TEXTURE_WRAP_S`, `GL_TEXTURE_WRAP_T`.
    pub wrap: [u32; 2],
    /// Linear (not nearest) filtering when magnified, when minified.
    pub linear: [bool; 2],
    /// The texels are known: every image given was read (not one from a
    /// pixel buffer object, or of a format or type not read here).
    pub readable: bool,
}

impl Default for Texture {
    fn default() -> Self {
        Self {
            width: 0,
            height: 0,
            texels: Vec::new(),
            format: BaseFormat::Rgba,
            wrap: [gl::REPEAT; 2],
            // GL's initial filters: GL_LINEAR, GL_NEAREST_MIPMAP_LINEAR.
            linear: [true, false],
            readable: true,
        }
    }
}

impl Texture {
    /// Whether the texture has an image (GL disables texturing with an
    /// incomplete texture).
    #[must_use]
    pub fn is_complete(&self) -> bool {
        self.width > 0 && self.height > 0
    }

    /// Reads a client image of `format`/`ty` (`data` spans
    /// [`PixelStore::image_bytes`]) into `width × height` RGBA texels at
    /// `(x, y)` of `self` (the whole image when it is new).
    ///
    /// Returns `false` (nothing changed) for what cannot be read.
    #[allow(clippy::too_many_arguments)]
    pub fn store(
        &mut self,
        [x, y]: [usize; 2],
        [width, height]: [usize; 2],
        format: u32,
        ty: u32,
        data: &[u8],
        unpack: &PixelStore,
    ) -> bool {
        let Some((components, size)) = pixel_layout(format, ty) else { return false };
        let pixel = components * size;
        let Some(row) = unpack.row_stride(width, pixel) else { return false };
        if unpack.image_bytes(width, height, format, ty).is_none_or(|n| n > data.len())
            || x + width > self.width as usize
            || y + height > self.height as usize
        {
            return false;
        }
        let channel = |bytes: &[u8]| -> f32 {
            match (ty, bytes) {
                (gl::UNSIGNED_BYTE, [b]) => f32::from(*b) / 255.0,
                (gl::BYTE, [b]) => (f32::from(*b as i8) / 127.0).max(-1.0),
                (gl::UNSIGNED_SHORT, [a, b]) => f32::from(u16::from_ne_bytes([*a, *b])) / 65535.0,
                (gl::SHORT, [a, b]) => {
                    (f32::from(i16::from_ne_bytes([*a, *b])) / 32767.0).max(-1.0)
                }
                (gl::FLOAT, [a, b, c, d]) => f32::from_ne_bytes([*a, *b, *c, *d]),
                (gl::UNSIGNED_INT, [a, b, c, d]) => {
                    u32::from_ne_bytes([*a, *b, *c, *d]) as f32 / u32::MAX as f32
                }
                (gl::INT, [a, b, c, d]) => {
                    i32::from_ne_bytes([*a, *b, *c, *d]) as f32 / i32::MAX as f32
                }
                _ => 0.0,
            }
        };
        for j in 0..height {
            let start = (unpack.skip_rows + j) * row + unpack.skip_pixels * pixel;
            for i in 0..width {
                let p = &data[start + i * pixel..start + (i + 1) * pixel];
                let c: Vec<f32> = p.chunks_exact(size).map(channel).collect();
                let rgba = match (format, c.as_slice()) {
                    (0x1903, [r]) => [*r, 0.0, 0.0, 1.0],
                    (0x1904, [g]) => [0.0, *g, 0.0, 1.0],
                    (0x1905, [b]) => [0.0, 0.0, *b, 1.0],
                    (0x1906, [a]) => [0.0, 0.0, 0.0, *a],
                    (0x1909, [l]) => [*l, *l, *l, 1.0],
                    (0x8049, [i]) => [*i; 4],
                    (0x190A, [l, a]) => [*l, *l, *l, *a],
                    (gl::RGB, [r, g, b]) => [*r, *g, *b, 1.0],
                    (0x80E0, [b, g, r]) => [*r, *g, *b, 1.0],
                    (gl::RGBA, [r, g, b, a]) => [*r, *g, *b, *a],
                    (0x80E1, [b, g, r, a]) => [*r, *g, *b, *a],
                    _ => return false,
                };
                let texel = self.format_texel(rgba);
                self.texels[(y + j) * self.width as usize + x + i] = texel;
            }
        }
        true
    }

    /// A client RGBA colour as a texel of the base format (GL's
    /// conversion: luminance from red, intensity from red).
    fn format_texel(&self, [r, g, b, a]: [f32; 4]) -> [u8; 4] {
        let c = match self.format {
            BaseFormat::Alpha => [0.0, 0.0, 0.0, a],
            BaseFormat::Luminance => [r, r, r, 1.0],
            BaseFormat::LuminanceAlpha => [r, r, r, a],
            BaseFormat::Intensity => [r; 4],
            BaseFormat::Rgb => [r, g, b, 1.0],
            BaseFormat::Rgba => [r, g, b, a],
        };
        c.map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8)
    }

    /// The filtered texel at texture coordinates `uv` (`[0, 1]` spans
    /// the image; outside, as the wrap modes say).
    #[must_use]
    pub fn sample(&self, uv: Vec2) -> Vec4 {
        if !self.is_complete() || !uv.is_finite() {
            return Vec4::ONE;
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let texel = |i: i64, j: i64| {
            let i = wrap(i, w, self.wrap[0]);
            let j = wrap(j, h, self.wrap[1]);
            let t = self.texels[(j * w + i) as usize];
            Vec4::from_array(t.map(|c| f32::from(c) / 255.0))
        };
        let (x, y) = (uv.x * w as f32, uv.y * h as f32);
        // Magnified or minified is a footprint question a ray has no
        // answer to; a texel per pixel or more is the common case.
        if !self.linear[0] {
            return texel(x.floor() as i64, y.floor() as i64);
        }
        let (x, y) = (x - 0.5, y - 0.5);
        let (i, j) = (x.floor(), y.floor());
        let (fx, fy) = (x - i, y - j);
        let (i, j) = (i as i64, j as i64);
        let bottom = texel(i, j).lerp(texel(i + 1, j), fx);
        let top = texel(i, j + 1).lerp(texel(i + 1, j + 1), fx);
        bottom.lerp(top, fy)
    }
}

/// Texel index `i` of a side of `n` texels under wrap mode `mode`.
fn wrap(i: i64, n: i64, mode: u32) -> i64 {
    match mode {
        gl::REPEAT => i.rem_euclid(n),
        0x8370 => {
            // GL_MIRRORED_REPEAT.
            let k = i.rem_euclid(2 * n);
            if k < n { k } else { 2 * n - 1 - k }
        }
        // GL_CLAMP, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_BORDER: the edge texel
        // (the border colour of GL_CLAMP's outer half is not kept).
        _ => i.clamp(0, n - 1),
    }
}

/// The texture environment of unit 0 (`glTexEnv`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TexEnv {
    /// `GL_TEXTURE_ENV_MODE`.
    pub mode: u32,
    /// `GL_TEXTURE_ENV_COLOR`.
    pub color: Vec4,
}

impl Default for TexEnv {
    fn default() -> Self {
        Self { mode: gl::MODULATE, color: Vec4::ZERO }
    }
}

impl TexEnv {
    /// The fragment colour `cf` combined with texel `t` of a texture of
    /// base format `format` (GL 2.1 tables 3.22 and 3.23).
    #[must_use]
    pub fn apply(&self, cf: Vec4, t: Vec4, format: BaseFormat) -> Vec4 {
        use BaseFormat as F;
        let (ct, at) = (t.truncate(), t.w);
        let (c, a) = (cf.truncate(), cf.w);
        let cc = self.color.truncate();
        let (rgb, alpha) = match self.mode {
            gl::REPLACE => match format {
                F::Alpha => (c, at),
                F::Luminance | F::Rgb => (ct, a),
                _ => (ct, at),
            },
            gl::DECAL => match format {
                F::Rgb => (ct, a),
                F::Rgba => (c * (1.0 - at) + ct * at, a),
                _ => (c, a),
            },
            gl::BLEND_ENV => match format {
                F::Alpha => (c, a * at),
                F::Intensity => (c * (1.0 - ct) + cc * ct, a * (1.0 - at) + self.color.w * at),
                F::Luminance | F::Rgb => (c * (1.0 - ct) + cc * ct, a),
                _ => (c * (1.0 - ct) + cc * ct, a * at),
            },
            gl::ADD => match format {
                F::Alpha => (c, a * at),
                F::Intensity => (c + ct, a + at),
                F::Luminance | F::Rgb => (c + ct, a),
                _ => (c + ct, a * at),
            },
            // GL_MODULATE.
            _ => match format {
                F::Alpha => (c, a * at),
                F::Luminance | F::Rgb => (c * ct, a),
                _ => (c * ct, a * at),
            },
        };
        rgb.min(glam::Vec3::ONE).extend(alpha.clamp(0.0, 1.0))
    }
}
