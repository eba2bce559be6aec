//! Optical cutoffs acting on a photon's deflection `ε` (radians, in the
//! image plane): what fraction of it reaches the film, per colour channel.

use alloc::vec::Vec;
use core::fmt;

use crate::math;

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
    /// The filter is a disc of radius `half_range` (a hue wheel): light
    /// deflected beyond it is blocked in every direction alike, not only
    /// past the square table's edges (which a round flow would show as
    /// four dark spots on the axes). `false`: the whole square transmits.
    pub round: bool,
}

impl FilterImage {
    /// An all-black (opaque) filter to paint on.
    #[must_use]
    pub fn opaque(size: usize, half_range: f64) -> Self {
        Self { size, rgb: alloc::vec![[0.0; 3]; size * size], half_range, round: false }
    }

    /// A clear filter (every photon passes inside `±half_range`): the
    /// picking pass of a filter to be painted, whose film records the
    /// deflections at this filter's resolution ([`Cutoff::range`]: the
    /// octree skips only what a pixel of it would not show).
    #[must_use]
    pub fn clear(size: usize, half_range: f64) -> Self {
        Self { rgb: alloc::vec![[1.0; 3]; size * size], ..Self::opaque(size, half_range) }
    }

    /// A hue wheel: colour by direction of `ε`, brightness by magnitude
    /// (rainbow schlieren). `half_range` sets full saturation, at the
    /// rim of the disc that transmits ([`FilterImage::round`]).
    #[must_use]
    pub fn hue_wheel(size: usize, half_range: f64) -> Self {
        let mut f = Self::opaque(size, half_range);
        for j in 0..size {
            for i in 0..size {
                let (u, v) = (f.coord(i), f.coord(j));
                let r = math::sqrt(u * u + v * v) / half_range;
                let a = math::atan2(v, u);
                let c = |shift: f64| (0.5 + 0.5 * math::cos(a - shift)) as f32;
                let k = r.min(1.0) as f32;
                f.rgb[i + size * j] =
                    [(1.0 - k) + k * c(0.0), (1.0 - k) + k * c(2.094), (1.0 - k) + k * c(4.189)];
            }
        }
        f.round = true;
        f
    }

    /// `cutoff` sampled at the pixel centres of a `size × size` filter over
    /// `±half_range` radians: a knife edge, graded filter or stop as a
    /// filter to paint on (a painted filter's presets), the same light
    /// transmitted to within a pixel of deflection.
    #[must_use]
    pub fn of_cutoff(cutoff: &Cutoff, size: usize, half_range: f64) -> Self {
        let mut f = Self::opaque(size, half_range);
        let prepared = cutoff.prepare();
        for j in 0..size {
            for i in 0..size {
                f.rgb[i + size * j] = prepared.transmit(f.coord(i), f.coord(j));
            }
        }
        f.round = matches!(cutoff, Cutoff::Color(c) if c.round);
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
    /// image, or a round filter's disc: opaque).
    #[must_use]
    pub fn at(&self, eu: f64, ev: f64) -> [f32; 3] {
        let to = |e: f64| math::floor((e / self.half_range + 1.0) * 0.5 * self.size as f64);
        let (i, j) = (to(eu), to(ev));
        let inside = !self.round || eu * eu + ev * ev <= self.half_range * self.half_range;
        if inside && i >= 0.0 && j >= 0.0 && (i as usize) < self.size && (j as usize) < self.size {
            self.rgb[i as usize + self.size * j as usize]
        } else {
            [0.0; 3]
        }
    }
}

/// A parameter of a [`Cutoff`], as a [`CutoffError`] names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CutoffParam {
    /// `angle`: the direction a knife edge or graded filter is sensitive
    /// to.
    Angle,
    /// `offset`: the shift of a knife edge.
    Offset,
    /// `f`: the focal length of the schlieren head.
    FocalLength,
    /// `h`: the height of the source image (knife edge).
    SourceHeight,
    /// `width`: the width of a graded filter's ramp.
    Width,
    /// `radius`: the radius of a pinhole or dark-field stop.
    Radius,
    /// `half_range`: the deflection at a colour filter image's edges.
    HalfRange,
}

impl CutoffParam {
    /// The field's name in [`Cutoff`] or [`FilterImage`].
    #[must_use]
    pub const fn field(self) -> &'static str {
        match self {
            Self::Angle => "angle",
            Self::Offset => "offset",
            Self::FocalLength => "f",
            Self::SourceHeight => "h",
            Self::Width => "width",
            Self::Radius => "radius",
            Self::HalfRange => "half_range",
        }
    }
}

impl fmt::Display for CutoffParam {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let what = match self {
            Self::Angle => "angle",
            Self::Offset => "offset",
            Self::FocalLength => "focal length",
            Self::SourceHeight => "source image height",
            Self::Width => "ramp width",
            Self::Radius => "stop radius",
            Self::HalfRange => "filter image half range",
        };
        write!(f, "{what} `{}`", self.field())
    }
}

/// Why [`Cutoff::validate`] refused a cutoff.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CutoffError {
    /// An angle or offset is NaN or infinite.
    NotFinite {
        /// Which one.
        param: CutoffParam,
        /// Its value.
        value: f64,
    },
    /// A length (focal length, source height, ramp width, stop radius) or
    /// a colour filter's half range is not finite and positive.
    NotPositive {
        /// Which one.
        param: CutoffParam,
        /// Its value.
        value: f64,
    },
    /// The colour filter image has no pixels (`size` is 0).
    EmptyImage,
    /// The colour filter image's `rgb` does not hold `size²` pixels.
    ImageSize {
        /// Its `size`.
        size: usize,
        /// The length of its `rgb`.
        len: usize,
    },
    /// The colour filter image holds a NaN or infinite transmission.
    NonFiniteImage {
        /// Index of the first such pixel in `rgb`.
        pixel: usize,
    },
}

impl fmt::Display for CutoffError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotFinite { param, value } => {
                write!(f, "cutoff {param} must be finite (got {value})")
            }
            Self::NotPositive { param, value } => {
                write!(f, "cutoff {param} must be finite and positive (got {value})")
            }
            Self::EmptyImage => write!(f, "colour filter image has no pixels (size 0)"),
            Self::ImageSize { size, len } => {
                write!(f, "colour filter image of size {size} needs {size}² pixels, has {len}")
            }
            Self::NonFiniteImage { pixel } => {
                write!(f, "colour filter image pixel {pixel} is not finite")
            }
        }
    }
}

impl core::error::Error for CutoffError {}

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
    /// Checks the parameters: angles and offsets finite, lengths finite
    /// and positive, a colour filter image of `size²` finite pixels.
    ///
    /// # Errors
    /// The first bad parameter, in the order the variant's fields are
    /// declared, as a [`CutoffError`].
    pub fn validate(&self) -> Result<(), CutoffError> {
        use CutoffParam as P;
        let finite = |param, value: f64| {
            if value.is_finite() { Ok(()) } else { Err(CutoffError::NotFinite { param, value }) }
        };
        let positive = |param, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(CutoffError::NotPositive { param, value })
            }
        };
        match self {
            Self::None => Ok(()),
            Self::KnifeEdge { angle, offset, f, h } => {
                finite(P::Angle, *angle)?;
                finite(P::Offset, *offset)?;
                positive(P::FocalLength, *f)?;
                positive(P::SourceHeight, *h)
            }
            Self::Graded { angle, f, width } => {
                finite(P::Angle, *angle)?;
                positive(P::FocalLength, *f)?;
                positive(P::Width, *width)
            }
            Self::Pinhole { f, radius, .. } => {
                positive(P::FocalLength, *f)?;
                positive(P::Radius, *radius)
            }
            Self::Color(img) => {
                if img.size == 0 {
                    return Err(CutoffError::EmptyImage);
                }
                if img.size.checked_mul(img.size) != Some(img.rgb.len()) {
                    return Err(CutoffError::ImageSize { size: img.size, len: img.rgb.len() });
                }
                positive(P::HalfRange, img.half_range)?;
                match img.rgb.iter().position(|p| !p.iter().all(|v| v.is_finite())) {
                    Some(pixel) => Err(CutoffError::NonFiniteImage { pixel }),
                    None => Ok(()),
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
        Prepared { cutoff: self, cos: math::cos(angle), sin: math::sin(angle) }
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
                let r = f * math::sqrt(eu * eu + ev * ev);
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
        assert!(matches!(
            Cutoff::KnifeEdge { angle: f64::NAN, offset: 0.0, f: 1.0, h: 1.0 }.validate(),
            Err(CutoffError::NotFinite { param: CutoffParam::Angle, value }) if value.is_nan()
        ));
        assert_eq!(
            Cutoff::Color(FilterImage::opaque(0, 1.0)).validate(),
            Err(CutoffError::EmptyImage)
        );
    }

    /// Each bad parameter is named, first bad one first.
    #[test]
    fn validate_names_the_bad_parameter() {
        use CutoffParam as P;
        let not_pos = |param, value| Err(CutoffError::NotPositive { param, value });
        let knife = |angle, offset, f, h| Cutoff::KnifeEdge { angle, offset, f, h };
        assert_eq!(knife(0.0, 0.0, 1.0, 1.0).validate(), Ok(()));
        assert_eq!(
            knife(0.0, f64::INFINITY, -1.0, 1.0).validate(),
            Err(CutoffError::NotFinite { param: P::Offset, value: f64::INFINITY })
        );
        assert_eq!(knife(0.0, 0.0, 1.0, 0.0).validate(), not_pos(P::SourceHeight, 0.0));
        let graded = Cutoff::Graded { angle: 0.0, f: f64::INFINITY, width: 1.0 };
        assert_eq!(graded.validate(), not_pos(P::FocalLength, f64::INFINITY));
        let graded = Cutoff::Graded { angle: 0.0, f: 1.0, width: -1.0 };
        assert_eq!(graded.validate(), not_pos(P::Width, -1.0));
        let pin = Cutoff::Pinhole { f: 1.0, radius: 0.0, dark_field: false };
        assert_eq!(pin.validate(), not_pos(P::Radius, 0.0));
        let img = |size, n, half_range| {
            Cutoff::Color(FilterImage {
                rgb: alloc::vec![[0.5; 3]; n],
                ..FilterImage::opaque(size, half_range)
            })
        };
        assert_eq!(img(2, 3, 1.0).validate(), Err(CutoffError::ImageSize { size: 2, len: 3 }));
        assert_eq!(img(2, 4, 0.0).validate(), not_pos(P::HalfRange, 0.0));
        assert_eq!(img(2, 4, 1.0).validate(), Ok(()));
        let mut bad = FilterImage::opaque(2, 1.0);
        bad.rgb[3][1] = f32::NAN;
        assert_eq!(Cutoff::Color(bad).validate(), Err(CutoffError::NonFiniteImage { pixel: 3 }));
        // Messages name the parameter for command-line users.
        let shown = alloc::format!("{}", knife(0.0, 0.0, -2.0, 1.0).validate().unwrap_err());
        assert_eq!(shown, "cutoff focal length `f` must be finite and positive (got -2)");
    }

    #[test]
    fn painted_filter_answers_at_the_brush() {
        let mut f = FilterImage::opaque(64, 1e-3);
        f.paint(3e-4, -2e-4, 1e-4, [1.0, 0.0, 0.0]);
        assert_eq!(f.at(3e-4, -2e-4), [1.0, 0.0, 0.0]);
        assert_eq!(f.at(-3e-4, 2e-4), [0.0; 3]);
        assert_eq!(f.at(5e-3, 0.0), [0.0; 3]);
    }

    /// A hue wheel is round: just inside its rim it transmits the
    /// saturated hue (`Σ rgb ≈ 1.5`), just outside nothing, on the axes
    /// as on the diagonals (its table is square: past the rim on a
    /// diagonal the table would still transmit).
    #[test]
    fn a_hue_wheel_is_round() {
        let h = 1e-3;
        let f = FilterImage::hue_wheel(256, h);
        for a in [0.0f64, 0.5, 1.0, 1.5, 2.5, 3.5] {
            let (s, c) = (a * core::f64::consts::FRAC_PI_4).sin_cos();
            let sum: f32 = f.at(0.99 * h * c, 0.99 * h * s).iter().sum();
            assert!((sum - 1.5).abs() < 0.05, "a = {a}: Σ {sum}");
            assert_eq!(f.at(1.01 * h * c, 1.01 * h * s), [0.0; 3], "a = {a}");
        }
        // A painted slide transmits its whole square.
        let mut slide = FilterImage::opaque(4, h);
        slide.rgb = alloc::vec![[1.0; 3]; 16];
        assert_eq!(slide.at(0.9 * h, 0.9 * h), [1.0; 3]);
    }
}
