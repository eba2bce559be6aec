//! Pixels and the two compositing operators.

use alloc::vec::Vec;

use rt_core::Pixel;

/// A pixel that can be composited: premultiplied RGBA plus depth, with a
/// fixed little-endian wire form.
///
/// Both operators have [`Fragment::BACKGROUND`] (transparent black at depth
/// `+∞`, bit for bit) as an exact identity: it is never sent, never
/// blended, and the result of blending with it is the other operand
/// unchanged, bit for bit.
pub trait Fragment: Copy + PartialEq + core::fmt::Debug + Send + Sync + 'static {
    /// The identity: transparent black at `+∞`, all other bits zero.
    const BACKGROUND: Self;
    /// Bytes on the wire.
    const SIZE: usize;
    /// Whether this is [`Self::BACKGROUND`] bit for bit (a pixel with
    /// `-0.0` colour or a NaN is active).
    fn is_background(&self) -> bool;
    /// Depth for z-compositing; NaN counts as `+∞`.
    fn depth(&self) -> f32;
    /// The nearer of `self` and `back`; on equal depth `self` wins, so with
    /// `self` from the lower rank ties go to the lower rank.
    #[must_use]
    fn z(self, back: Self) -> Self {
        if back.is_background() {
            self
        } else if self.is_background() || back.depth() < self.depth() {
            back
        } else {
            self
        }
    }
    /// `self` over `back` (premultiplied colour); the depth is the nearer
    /// of the two (see [`over`]).
    #[must_use]
    fn over(self, back: Self) -> Self;
    /// Writes [`Self::SIZE`] bytes.
    fn write(&self, out: &mut [u8]);
    /// Reads [`Self::SIZE`] bytes.
    fn read(bytes: &[u8]) -> Self;
    /// Appends the wire form of every pixel of `pixels` to `out` (as
    /// [`Self::write`] each, in one pass).
    fn write_all(pixels: &[Self], out: &mut Vec<u8>) {
        let at = out.len();
        out.resize(at + Self::SIZE * pixels.len(), 0);
        for (chunk, p) in out[at..].chunks_exact_mut(Self::SIZE).zip(pixels) {
            p.write(chunk);
        }
    }
    /// The pixels of `bytes` (whole [`Self::SIZE`] chunks; a partial one at
    /// the end is left out), as [`Self::read`] each.
    #[must_use]
    fn read_all(bytes: &[u8]) -> Vec<Self> {
        bytes.chunks_exact(Self::SIZE).map(Self::read).collect()
    }
}

/// Whole-slice copies where the wire form is the memory layout (the
/// fields in order, little-endian, no padding).
#[cfg(target_endian = "little")]
fn write_pod<T: bytemuck::Pod>(pixels: &[T], out: &mut Vec<u8>) {
    out.extend_from_slice(bytemuck::cast_slice(pixels));
}

#[cfg(target_endian = "little")]
fn read_pod<T: bytemuck::Pod>(bytes: &[u8]) -> Vec<T> {
    let whole = bytes.len() - bytes.len() % core::mem::size_of::<T>();
    bytemuck::pod_collect_to_vec(&bytes[..whole])
}

fn depth_key(d: f32) -> f32 {
    if d.is_nan() { f32::INFINITY } else { d }
}

/// Premultiplied `over` of `f32` pixels: `front + (1 − α_front) · back`
/// per channel; the depth is the nearer of the two (NaN counting as `+∞`,
/// ties to the front). The background on either side is an exact
/// identity.
#[must_use]
pub fn over(front: Pixel, back: Pixel) -> Pixel {
    front.over(back)
}

/// Z-compositing of `f32` pixels: the nearer fragment, ties to `front`
/// (the lower rank); the background on either side is an exact identity.
#[must_use]
pub fn z_composite(front: Pixel, back: Pixel) -> Pixel {
    front.z(back)
}

impl Fragment for Pixel {
    const BACKGROUND: Self = Pixel::BACKGROUND;
    const SIZE: usize = 20;

    fn is_background(&self) -> bool {
        // Bitwise, without early exits: compositing loops stay branch-free.
        let c = self.color.map(f32::to_bits);
        ((self.depth.to_bits() ^ f32::INFINITY.to_bits()) | c[0] | c[1] | c[2] | c[3]) == 0
    }

    fn depth(&self) -> f32 {
        depth_key(self.depth)
    }

    /// As the trait's, as a bitwise select (depths of real images are
    /// unpredictable, and a branch per pixel costs more than the select).
    fn z(self, back: Self) -> Self {
        let take_back =
            !back.is_background() & (self.is_background() | (back.depth() < self.depth()));
        let m = 0u32.wrapping_sub(u32::from(take_back));
        let pick = |a: f32, b: f32| f32::from_bits((b.to_bits() & m) | (a.to_bits() & !m));
        Self {
            color: [
                pick(self.color[0], back.color[0]),
                pick(self.color[1], back.color[1]),
                pick(self.color[2], back.color[2]),
                pick(self.color[3], back.color[3]),
            ],
            depth: pick(self.depth, back.depth),
        }
    }

    fn over(self, back: Self) -> Self {
        if back.is_background() {
            return self;
        }
        if self.is_background() {
            return back;
        }
        let t = 1.0 - self.color[3];
        let mut color = [0.0; 4];
        for (c, (f, b)) in color.iter_mut().zip(self.color.iter().zip(back.color)) {
            *c = f + t * b;
        }
        let depth = if back.depth() < self.depth() { back.depth } else { self.depth };
        Self { color, depth }
    }

    fn write(&self, out: &mut [u8]) {
        for (chunk, v) in out.chunks_exact_mut(4).zip(self.color.iter().chain([&self.depth])) {
            chunk.copy_from_slice(&v.to_le_bytes());
        }
    }

    fn read(bytes: &[u8]) -> Self {
        let f = |i: usize| {
            f32::from_le_bytes([bytes[4 * i], bytes[4 * i + 1], bytes[4 * i + 2], bytes[4 * i + 3]])
        };
        Self { color: [f(0), f(1), f(2), f(3)], depth: f(4) }
    }

    // `repr(C)` `[f32; 4]` then `f32`: the wire form on little-endian.
    #[cfg(target_endian = "little")]
    fn write_all(pixels: &[Self], out: &mut Vec<u8>) {
        write_pod(pixels, out);
    }

    #[cfg(target_endian = "little")]
    fn read_all(bytes: &[u8]) -> Vec<Self> {
        read_pod(bytes)
    }
}

/// A pixel with 8-bit premultiplied RGBA (a quarter of the colour
/// bandwidth) and `f32` depth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Pixel8 {
    /// Premultiplied `[r, g, b, a]`, 255 = 1.
    pub color: [u8; 4],
    /// Depth bits (`f32::to_bits`); `+∞` for background.
    pub depth_bits: u32,
}

impl Pixel8 {
    /// Rounds an `f32` pixel's colour (clamped to `[0, 1]`, NaN → 0) to 8 bits.
    #[must_use]
    pub fn from_pixel(p: Pixel) -> Self {
        let q = |v: f32| if v.is_nan() { 0 } else { (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8 };
        Self { color: p.color.map(q), depth_bits: p.depth.to_bits() }
    }

    /// The `f32` pixel.
    #[must_use]
    pub fn to_pixel(self) -> Pixel {
        Pixel {
            color: self.color.map(|c| f32::from(c) / 255.0),
            depth: f32::from_bits(self.depth_bits),
        }
    }
}

impl Fragment for Pixel8 {
    const BACKGROUND: Self = Self { color: [0; 4], depth_bits: 0x7f80_0000 };
    const SIZE: usize = 8;

    fn is_background(&self) -> bool {
        *self == Self::BACKGROUND
    }

    fn depth(&self) -> f32 {
        depth_key(f32::from_bits(self.depth_bits))
    }

    /// Integer `over`: `front + round((255 − α_front) · back / 255)`,
    /// saturating.
    fn over(self, back: Self) -> Self {
        if back.is_background() {
            return self;
        }
        if self.is_background() {
            return back;
        }
        let t = 255 - u32::from(self.color[3]);
        let mut color = [0u8; 4];
        for (c, (f, b)) in color.iter_mut().zip(self.color.iter().zip(back.color)) {
            let v = u32::from(*f) + (t * u32::from(b) + 127) / 255;
            *c = v.min(255) as u8;
        }
        let depth_bits =
            if back.depth() < self.depth() { back.depth_bits } else { self.depth_bits };
        Self { color, depth_bits }
    }

    fn write(&self, out: &mut [u8]) {
        out[..4].copy_from_slice(&self.color);
        out[4..8].copy_from_slice(&self.depth_bits.to_le_bytes());
    }

    fn read(bytes: &[u8]) -> Self {
        Self {
            color: [bytes[0], bytes[1], bytes[2], bytes[3]],
            depth_bits: u32::from_le_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]),
        }
    }

    // `repr(C)` `[u8; 4]` then `u32`: the wire form on little-endian.
    #[cfg(target_endian = "little")]
    fn write_all(pixels: &[Self], out: &mut Vec<u8>) {
        write_pod(pixels, out);
    }

    #[cfg(target_endian = "little")]
    fn read_all(bytes: &[u8]) -> Vec<Self> {
        read_pod(bytes)
    }
}
