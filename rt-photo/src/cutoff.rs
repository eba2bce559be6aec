//! Optical cutoffs acting on a photon's deflection `ε` (radians, in the
//! image plane): what fraction of it reaches the film, per colour channel.

use alloc::vec::Vec;

/// A 2-D RGB filter image indexed by deflection (rainbow schlieren, or a
/// filter painted by the user).
#[derive(Clone, Debug, PartialEq)]
pub struct FilterImage {
    /// Pixels per side (`size × size`).
    pub size: usize,
    /// Linear RGB transmission per pixel, row-major, row 0 at `−half_range`
    /// of the second deflection axis.
    pub rgb: Vec<[f32; 3]>,
    /// The deflection (radians) at the image's edges: pixel centres span
    /// `[−half_range, half_range]` on both axes.
    pub half_range: f64,
}

impl FilterImage {
    /// An all-black (opaque) filter to paint on.
    #[must_use]
    pub fn opaque(size: usize, half_range: f64) -> Self {
        Self { size, rgb: alloc::vec![[0.0; 3]; size * size], half_range }
    }

    /// A hue wheel: colour by direction of `ε`, brightness by magnitude
    /// (rainbow schlieren). `half_range` sets full saturation.
    #[must_use]
    pub fn hue_wheel(size: usize, half_range: f64) -> Self {
        let mut f = Self::opaque(size, half_range);
        for j in 0..size {
            for i in 0..size {
                let (u, v) = (f.coord(i), f.coord(j));
                let r = (u * u + v * v).sqrt() / half_range;
                let a = v.atan2(u);
                let c = |shift: f64| (0.5 + 0.5 * (a - shift).cos()) as f32;
                let k = r.min(1.0) as f32;
                f.rgb[i + size * j] =
                    [(1.0 - k) + k * c(0.0), (1.0 - k) + k * c(2.094), (1.0 - k) + k * c(4.189)];
            }
        }
        f
    }

    fn coord(&self, i: usize) -> f64 {
        (2.0 * (i as f64 + 0.5) / self.size as f64 - 1.0) * self.half_range
    }

    /// Paints a disc brush of `radius` (radians) and colour at deflection
    /// `(eu, ev)` (the picking pass tells where features deflect to).
    pub fn paint(&mut self, eu: f64, ev: f64, radius: f64, rgb: [f32; 3]) {
        for j in 0..self.size {
            for i in 0..self.size {
                let (du, dv) = (self.coord(i) - eu, self.coord(j) - ev);
                if du * du + dv * dv <= radius * radius {
                    self.rgb[i + self.size * j] = rgb;
                }
            }
        }
    }

    /// Transmission at deflection `(eu, ev)` (nearest pixel; outside the
    /// image: opaque).
    #[must_use]
    pub fn at(&self, eu: f64, ev: f64) -> [f32; 3] {
        let to = |e: f64| ((e / self.half_range + 1.0) * 0.5 * self.size as f64).floor();
        let (i, j) = (to(eu), to(ev));
        if i >= 0.0 && j >= 0.0 && (i as usize) < self.size && (j as usize) < self.size {
            self.rgb[i as usize + self.size * j as usize]
        } else {
            [0.0; 3]
        }
    }
}

/// The cutoff in the schlieren head's focal plane.
#[derive(Clone, Debug, PartialEq)]
pub enum Cutoff {
    /// No cutoff: every photon passes (shadowgraph, or plain transmission).
    None,
    /// A knife edge cutting the source image of height `h` in a head of
    /// focal length `f` (same length unit): transmitted fraction
    /// `clamp(0.5 + (f/h)·ε⊥ + offset, 0, 1)`, `ε⊥` the deflection along
    /// `angle` (radians from the image's u axis; the edge lies across it).
    KnifeEdge {
        /// Direction in the image plane the edge is sensitive to.
        angle: f64,
        /// Shift of the edge, in units of the source image (0 = half cut).
        offset: f64,
        /// Focal length of the schlieren head.
        f: f64,
        /// Height of the source image.
        h: f64,
    },
    /// A graded filter: transmission ramps linearly over its `width` for a
    /// point source, `clamp(0.5 + f·ε⊥ / width, 0, 1)`.
    Graded {
        /// Direction of the ramp.
        angle: f64,
        /// Focal length.
        f: f64,
        /// Width of the ramp in the focal plane.
        width: f64,
    },
    /// A circular stop of `radius` in the focal plane: bright field passes
    /// `f·|ε| ≤ radius`, dark field (an opaque disc) passes the rest.
    Pinhole {
        /// Focal length.
        f: f64,
        /// Radius of the hole (or disc).
        radius: f64,
        /// Dark field: an opaque disc instead of a hole.
        dark_field: bool,
    },
    /// A colour filter image indexed by `ε` (rainbow schlieren).
    Color(FilterImage),
}

impl Cutoff {
    /// Checks the parameters.
    ///
    /// # Errors
    /// A message naming the bad parameter.
    pub fn validate(&self) -> Result<(), &'static str> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        match self {
            Self::None => Ok(()),
            Self::KnifeEdge { angle, offset, f, h } => {
                if !(angle.is_finite() && offset.is_finite()) {
                    Err("knife edge angle/offset not finite")
                } else if !(pos(*f) && pos(*h)) {
                    Err("knife edge f and h must be finite and positive")
                } else {
                    Ok(())
                }
            }
            Self::Graded { angle, f, width } => {
                if angle.is_finite() && pos(*f) && pos(*width) {
                    Ok(())
                } else {
                    Err("graded filter parameters")
                }
            }
            Self::Pinhole { f, radius, .. } => {
                if pos(*f) && pos(*radius) {
                    Ok(())
                } else {
                    Err("pinhole f and radius must be positive")
                }
            }
            Self::Color(img) => {
                if img.size == 0 || img.rgb.len() != img.size * img.size || !pos(img.half_range) {
                    Err("colour filter image is empty or malformed")
                } else if img.rgb.iter().flatten().any(|v| !v.is_finite()) {
                    Err("colour filter image has non-finite values")
                } else {
                    Ok(())
                }
            }
        }
    }

    /// The deflection (radians) over which the transmission changes fully:
    /// `h/f` for a knife edge, `width/f` for a graded filter, `radius/f`
    /// for a pinhole, one filter pixel (`2·half_range/size`) for a colour
    /// filter; `None` without a cutoff.
    #[must_use]
    pub fn range(&self) -> Option<f64> {
        match self {
            Self::None => None,
            Self::KnifeEdge { f, h, .. } => Some(h / f),
            Self::Graded { f, width, .. } => Some(width / f),
            Self::Pinhole { f, radius, .. } => Some(radius / f),
            Self::Color(img) => Some(2.0 * img.half_range / img.size.max(1) as f64),
        }
    }

    /// Transmission per channel for deflection `(eu, ev)`, in `[0, 1]`; a
    /// NaN deflection is blocked (0) by every cutoff but [`Cutoff::None`].
    #[must_use]
    pub fn transmit(&self, eu: f64, ev: f64) -> [f32; 3] {
        self.prepare().transmit(eu, ev)
    }

    /// The cutoff with its edge direction's sine and cosine computed once,
    /// for transmitting many photons.
    pub(crate) fn prepare(&self) -> Prepared<'_> {
        let angle = match self {
            Self::KnifeEdge { angle, .. } | Self::Graded { angle, .. } => *angle,
            _ => 0.0,
        };
        Prepared { cutoff: self, cos: angle.cos(), sin: angle.sin() }
    }
}

/// A [`Cutoff`] with its edge direction precomputed.
pub(crate) struct Prepared<'a> {
    cutoff: &'a Cutoff,
    cos: f64,
    sin: f64,
}

impl Prepared<'_> {
    /// As [`Cutoff::transmit`].
    pub(crate) fn transmit(&self, eu: f64, ev: f64) -> [f32; 3] {
        let along = eu * self.cos + ev * self.sin;
        // A NaN deflection (or `0·∞` from one) is blocked, never a NaN.
        let gray = |t: f64| {
            let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) as f32 };
            [t; 3]
        };
        match self.cutoff {
            Cutoff::None => [1.0; 3],
            Cutoff::KnifeEdge { offset, f, h, .. } => gray(0.5 + f / h * along + offset),
            Cutoff::Graded { f, width, .. } => gray(0.5 + f * along / width),
            Cutoff::Pinhole { f, radius, dark_field } => {
                let r = f * (eu * eu + ev * ev).sqrt();
                let inside = r <= *radius;
                // NaN is neither inside nor outside: blocked either way.
                gray(if r.is_nan() || inside == *dark_field { 0.0 } else { 1.0 })
            }
            Cutoff::Color(img) => img.at(eu, ev),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Found by the `cutoff` fuzz target: a NaN deflection came out of the
    /// knife edge as a NaN transmission.
    #[test]
    fn fuzz_regression_nan_deflection_is_blocked() {
        let k = Cutoff::KnifeEdge { angle: -0.6875, offset: 0.375, f: 0.3125, h: 0.375 };
        assert_eq!(k.transmit(f64::NAN, 0.375), [0.0; 3]);
        let g = Cutoff::Graded { angle: 0.0, f: 1.0, width: 1.0 };
        assert_eq!(g.transmit(f64::INFINITY, f64::NAN), [0.0; 3]);
        for dark_field in [false, true] {
            let p = Cutoff::Pinhole { f: 1.0, radius: 1.0, dark_field };
            assert_eq!(p.transmit(f64::NAN, 0.0), [0.0; 3]);
        }
    }

    #[test]
    fn knife_edge_is_the_documented_ramp() {
        let k = Cutoff::KnifeEdge { angle: 0.0, offset: 0.0, f: 1.0, h: 1e-3 };
        assert_eq!(k.transmit(0.0, 0.0), [0.5; 3]);
        assert_eq!(k.transmit(2.5e-4, 1.0), [0.75; 3]);
        assert_eq!(k.transmit(-1.0, 0.0), [0.0; 3]);
        let rotated =
            Cutoff::KnifeEdge { angle: core::f64::consts::FRAC_PI_2, offset: 0.0, f: 1.0, h: 1e-3 };
        assert_eq!(rotated.transmit(0.0, 2.5e-4)[0], 0.75);
        let p = Cutoff::Pinhole { f: 1.0, radius: 1e-3, dark_field: true };
        assert_eq!((p.transmit(0.0, 0.0)[0], p.transmit(2e-3, 0.0)[0]), (0.0, 1.0));
        assert!(
            Cutoff::KnifeEdge { angle: f64::NAN, offset: 0.0, f: 1.0, h: 1.0 }.validate().is_err()
        );
        assert!(
            Cutoff::Color(FilterImage { size: 0, rgb: alloc::vec![], half_range: 1.0 })
                .validate()
                .is_err()
        );
    }

    #[test]
    fn painted_filter_answers_at_the_brush() {
        let mut f = FilterImage::opaque(64, 1e-3);
        f.paint(3e-4, -2e-4, 1e-4, [1.0, 0.0, 0.0]);
        assert_eq!(f.at(3e-4, -2e-4), [1.0, 0.0, 0.0]);
        assert_eq!(f.at(-3e-4, 2e-4), [0.0; 3]);
        assert_eq!(f.at(5e-3, 0.0), [0.0; 3]);
    }
}
