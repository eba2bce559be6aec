//! A frame's passes put together as GL's depth buffer puts its draws
//! together: in the order drawn, a pass's pixel replacing what is there
//! when the pass's depth test is off or its depth is not greater than
//! the depth buffer's, which a depth clear between passes resets.
//!
//! Traced 3-D passes give colours and depths; 2-D overlays give only
//! where they cover and how deep (traced without shading), their colour
//! being GL's own raster, kept in the window: the composite marks those
//! pixels with alpha 0 and is drawn over the program's back buffer with
//! the alpha test, so GL's overlay shows through exactly as it drew it.
//! A pass that could not be traced keeps its whole viewport as GL drew
//! it. Where no pass covers a pixel inside a traced pass's viewport, the
//! composite shows the clear colour of that pass's frame; outside every
//! traced viewport, GL's pixel stays. A traced pass seen only through
//! blended surfaces goes over what the passes before it show there, as
//! GL blends a later draw over the framebuffer.

use glam::Vec4;

use crate::render::{Image, to_rgba8};

/// What one pass contributes.
#[derive(Clone, Debug)]
pub enum Content {
    /// Ray traced: RGBA and window depth per pixel of the viewport
    /// (`f32::INFINITY`: nothing hit), rows bottom to top.
    Traced {
        /// The traced colours.
        image: Image,
        /// The window depths.
        depth: Vec<f32>,
    },
    /// A 2-D overlay, shown from GL's raster where it covers: window
    /// depth per pixel of the viewport (`f32::INFINITY`: not covered).
    Raster {
        /// The window depths.
        depth: Vec<f32>,
    },
    /// Not traced (an error): the whole viewport shows GL's raster.
    Untraced,
}

/// One pass, placed in the window.
#[derive(Clone, Debug)]
pub struct Layer {
    /// Window rectangle `[x, y, width, height]` the content covers.
    pub viewport: [i32; 4],
    /// The pass's depth test was on.
    pub depth_test: bool,
    /// The depth buffer was cleared before the pass.
    pub depth_cleared: bool,
    /// Clear colour behind a traced pass.
    pub background: Vec4,
    /// The pixels.
    pub content: Content,
}

/// A 2-D overlay's coverage `depth` (over viewport `v`) at `(x, y)`, or
/// where it does not cover that pixel, the nearest of its eight
/// neighbours': one ray per pixel centre misses some pixels GL's
/// rasterizer covers (thin lines, points, edges), and a pixel GL drew
/// must show what GL drew.
fn near(depth: &[f32], v: [i32; 4], x: i32, y: i32) -> f32 {
    let own = (y - v[1]) as usize * v[2] as usize + (x - v[0]) as usize;
    let mut z = depth.get(own).copied().unwrap_or(f32::INFINITY);
    if z.is_finite() {
        return z;
    }
    for dy in -1..=1 {
        for dx in -1..=1 {
            let (px, py) = (x + dx - v[0], y + dy - v[1]);
            if px >= 0 && py >= 0 && px < v[2] && py < v[3] {
                let i = py as usize * v[2] as usize + px as usize;
                z = z.min(depth.get(i).copied().unwrap_or(f32::INFINITY));
            }
        }
    }
    z
}

/// Whether the composite has any pixel GL's raster must show (alpha 0).
#[must_use]
pub fn keeps_raster(image: &Image) -> bool {
    image.rgba.chunks_exact(4).any(|p| p[3] == 0)
}

/// Whether compositing `layers` may need GL's raster as a colour: a
/// traced pass with blended surfaces, after a pass kept as GL drew it.
#[must_use]
pub fn needs_raster(layers: &[Layer]) -> bool {
    let mut kept = false;
    for l in layers {
        match &l.content {
            Content::Traced { image, depth } => {
                let translucent =
                    image.rgba.chunks_exact(4).zip(depth).any(|(p, z)| z.is_finite() && p[3] < 255);
                if kept && translucent {
                    return true;
                }
            }
            Content::Raster { .. } | Content::Untraced => kept = true,
        }
    }
    false
}

/// What a pixel shows so far.
#[derive(Clone, Copy)]
enum Shown {
    Nothing,
    /// GL's own pixel.
    Raster,
    /// A traced colour, `[0, 255]` per channel.
    Color([f32; 3]),
}

/// The composite over the window rectangle `window` (`[x, y, width,
/// height]`): opaque where a traced pass or its background shows, alpha 0
/// where GL's raster is to stay. A traced pass's pixel that is not
/// opaque (blended surfaces only) goes over what the earlier passes
/// show there: over GL's pixel, `raster` (the window's pixels over
/// `window`, read back; without it, over the pass's background).
#[must_use]
pub fn composite(window: [i32; 4], layers: &[Layer], raster: Option<&Image>) -> Image {
    let [wx, wy, ww, wh] = window.map(|v| v.max(0));
    let mut rgba = vec![0u8; 4 * ww as usize * wh as usize];
    let inside =
        |v: [i32; 4], x: i32, y: i32| x >= v[0] && y >= v[1] && x - v[0] < v[2] && y - v[1] < v[3];
    let rgb = |c: Vec4| {
        let c = to_rgba8(c);
        [c[0], c[1], c[2]].map(f32::from)
    };
    for (row, y) in rgba.chunks_exact_mut(4 * ww.max(1) as usize).zip(wy..) {
        for (px, x) in row.chunks_exact_mut(4).zip(wx..) {
            let mut depth = 1.0f32;
            let mut shown = Shown::Nothing;
            let mut background = None;
            // GL's pixel here, as a colour.
            let gl_pixel = |fallback: [f32; 3]| {
                let i = 4 * ((y - wy) as usize * ww as usize + (x - wx) as usize);
                raster
                    .and_then(|r| r.rgba.get(i..i + 3))
                    .map_or(fallback, |p| [p[0], p[1], p[2]].map(f32::from))
            };
            for l in layers {
                if l.depth_cleared {
                    depth = 1.0;
                }
                let v = l.viewport;
                if !inside(v, x, y) {
                    continue;
                }
                let i = (y - v[1]) as usize * v[2] as usize + (x - v[0]) as usize;
                let z = match &l.content {
                    Content::Traced { depth, .. } => {
                        background = Some(l.background);
                        depth.get(i).copied().unwrap_or(f32::INFINITY)
                    }
                    Content::Raster { depth } => near(depth, v, x, y),
                    Content::Untraced => {
                        shown = Shown::Raster;
                        continue;
                    }
                };
                if !z.is_finite() || (l.depth_test && z > depth) {
                    continue;
                }
                if l.depth_test {
                    depth = z;
                }
                shown = match &l.content {
                    Content::Traced { image, .. } => {
                        let p = image.rgba.get(4 * i..4 * i + 4).unwrap_or(&[0, 0, 0, 255]);
                        let a = f32::from(p[3]) / 255.0;
                        let below = match shown {
                            _ if p[3] == 255 => [0.0; 3],
                            Shown::Color(c) => c,
                            Shown::Raster => gl_pixel(rgb(l.background)),
                            Shown::Nothing => rgb(l.background),
                        };
                        Shown::Color([0, 1, 2].map(|k| f32::from(p[k]) + (1.0 - a) * below[k]))
                    }
                    _ => Shown::Raster,
                };
            }
            let c = match shown {
                Shown::Color(c) => Some(c.map(|v| v.round().clamp(0.0, 255.0) as u8)),
                Shown::Raster => None,
                Shown::Nothing => background.map(|b| {
                    let c = to_rgba8(b);
                    [c[0], c[1], c[2]]
                }),
            };
            px.copy_from_slice(&c.map_or([0; 4], |c| [c[0], c[1], c[2], 255]));
        }
    }
    Image { width: ww as u32, height: wh as u32, rgba }
}
