//! What a BOS camera looks at ([`Background`]): random dots
//! ([`DotBackground`]), a regular grid of dots ([`DotGrid`]) or the
//! user's image ([`ImageBackground`]), as brightness (about 0–1) at
//! `(u, v)` on the background plane: along the camera's right and up
//! axes, from the optical axis, in scene units. Their `for_camera`
//! constructors size them in pixels as imaged by a camera focused on the
//! background ([`ThinLens::pixel_in_focus`]).

use alloc::vec::Vec;

use rt_core::sampling::{rng_for, uniform_f64};

use super::BosError;
use crate::camera::ThinLens;
use crate::math::{exp, floor};

/// The background behind the flow.
#[derive(Clone, Debug, PartialEq)]
pub enum Background {
    /// Dots at random positions.
    RandomDots(DotBackground),
    /// Dots on a square lattice.
    DotGrid(DotGrid),
    /// A grayscale image.
    Image(ImageBackground),
}

impl Background {
    /// The brightness at `(u, v)` on the background plane.
    #[inline]
    #[must_use]
    pub fn value(&self, u: f64, v: f64) -> f64 {
        match self {
            Self::RandomDots(d) => d.value(u, v),
            Self::DotGrid(g) => g.value(u, v),
            Self::Image(i) => i.value(u, v),
        }
    }

    /// Checks the dots' sizes (an [`ImageBackground`] is checked when
    /// made).
    ///
    /// # Errors
    /// [`BosError::Setup`] for a dot spacing or diameter that is not
    /// finite and > 0.
    pub fn validate(&self) -> Result<(), BosError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let (spacing, diameter) = match self {
            Self::RandomDots(d) => (d.spacing, d.dot_diameter),
            Self::DotGrid(g) => (g.spacing, g.dot_diameter),
            Self::Image(_) => return Ok(()),
        };
        if !pos(spacing) || !pos(diameter) {
            return Err(BosError::Setup("dot spacing and diameter must be finite and > 0"));
        }
        Ok(())
    }
}

impl From<DotBackground> for Background {
    fn from(d: DotBackground) -> Self {
        Self::RandomDots(d)
    }
}

impl From<DotGrid> for Background {
    fn from(g: DotGrid) -> Self {
        Self::DotGrid(g)
    }
}

impl From<ImageBackground> for Background {
    fn from(i: ImageBackground) -> Self {
        Self::Image(i)
    }
}

/// `exp(−4 ln 2 · r²/d²)`'s factor for dots of FWHM `d`.
fn gaussian_factor(d: f64) -> f64 {
    4.0 * core::f64::consts::LN_2 / (d * d)
}

/// A background of random dots: one dot per cell of a square lattice of
/// `spacing`, at a position drawn from `(seed, cell)`, each a Gaussian of
/// full width at half maximum `dot_diameter`; the value is the sum of the
/// dots (bright dots on black, ≤ about 1), on the background plane's `(u,
/// v)` coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DotBackground {
    /// Distance between dots (lattice cell), scene units.
    pub spacing: f64,
    /// Dot diameter (full width at half maximum), scene units.
    pub dot_diameter: f64,
    /// Seed of the dot positions.
    pub seed: u64,
}

impl DotBackground {
    /// Dots of `dot_px` pixels as imaged, `spacing_px` pixels apart, for
    /// `camera` focused on the background.
    #[must_use]
    pub fn for_camera(camera: &ThinLens, dot_px: f64, spacing_px: f64, seed: u64) -> Self {
        let px = camera.pixel_in_focus();
        Self { spacing: spacing_px * px, dot_diameter: dot_px * px, seed }
    }

    /// The background at `(u, v)`.
    #[must_use]
    pub fn value(&self, u: f64, v: f64) -> f64 {
        let (ci, cj) = (floor(u / self.spacing), floor(v / self.spacing));
        // Gaussian of FWHM d: exp(−4 ln 2 · r²/d²).
        let k = 4.0 * core::f64::consts::LN_2 / (self.dot_diameter * self.dot_diameter);
        let mut sum = 0.0;
        for dj in -1..=1 {
            for di in -1..=1 {
                let (i, j) = (ci + f64::from(di), cj + f64::from(dj));
                let cell = (i as i64 as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15)
                    ^ (j as i64 as u64).wrapping_mul(0xc2b2_ae3d_27d4_eb4f);
                let mut rng = rng_for(self.seed, cell);
                let x = (i + uniform_f64(&mut rng)) * self.spacing;
                let y = (j + uniform_f64(&mut rng)) * self.spacing;
                let r2 = (u - x) * (u - x) + (v - y) * (v - y);
                sum += crate::math::exp(-k * r2);
            }
        }
        sum
    }
}

/// A regular grid of dots: one on each point `(i·spacing, j·spacing)` of
/// a square lattice (one on the optical axis), each a Gaussian of full
/// width at half maximum `dot_diameter`; the value is the sum of the
/// nine nearest dots (bright dots on black, about 1 at a dot's centre for
/// dots up to half the spacing; those left out, 1.5 spacings or more
/// away, add under 0.2 % for dots as wide as the spacing).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DotGrid {
    /// Distance between neighbouring dots, scene units.
    pub spacing: f64,
    /// Dot diameter (full width at half maximum), scene units.
    pub dot_diameter: f64,
}

impl DotGrid {
    /// Dots of `dot_px` pixels as imaged, `spacing_px` pixels apart, for
    /// `camera` focused on the background.
    #[must_use]
    pub fn for_camera(camera: &ThinLens, dot_px: f64, spacing_px: f64) -> Self {
        let px = camera.pixel_in_focus();
        Self { spacing: spacing_px * px, dot_diameter: dot_px * px }
    }

    /// The background at `(u, v)`.
    #[must_use]
    pub fn value(&self, u: f64, v: f64) -> f64 {
        let (ci, cj) = (floor(u / self.spacing + 0.5), floor(v / self.spacing + 0.5));
        let k = gaussian_factor(self.dot_diameter);
        let mut sum = 0.0;
        for dj in -1..=1 {
            for di in -1..=1 {
                let x = u - (ci + f64::from(di)) * self.spacing;
                let y = v - (cj + f64::from(dj)) * self.spacing;
                sum += exp(-k * (x * x + y * y));
            }
        }
        sum
    }
}

/// A grayscale image on the background plane, centred on the optical
/// axis, upright (row 0 at the top, toward the camera's up), each pixel a
/// square of side `pixel_size`; bilinear between pixel centres (the
/// outermost half pixel repeats the edge); outside it, the image's mean
/// (a uniform grey, so its border is no edge for a BOS processor to
/// track). Samples are brightness, 0 black, 1 the white of a dot's
/// centre.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageBackground {
    width: usize,
    height: usize,
    samples: Vec<f64>,
    pixel_size: f64,
    outside: f64,
}

impl ImageBackground {
    /// The image of `width × height` `samples` (row-major, row 0 at the
    /// top), each pixel `pixel_size` wide on the background plane.
    ///
    /// # Errors
    /// [`BosError::ImageSize`] when there are no pixels or not `width ×
    /// height` samples; [`BosError::ImageSample`] for a sample that is not
    /// finite and ≥ 0; [`BosError::Setup`] when `pixel_size` is not finite
    /// and > 0 (or the image's extent overflows).
    pub fn new(
        width: usize,
        height: usize,
        samples: Vec<f64>,
        pixel_size: f64,
    ) -> Result<Self, BosError> {
        let n = width.checked_mul(height).unwrap_or(0);
        if n == 0 || samples.len() != n {
            return Err(BosError::ImageSize { width, height, samples: samples.len() });
        }
        if let Some(index) = samples.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
            return Err(BosError::ImageSample { index, value: samples[index] });
        }
        let extent = pixel_size * width.max(height) as f64;
        if !(pixel_size.is_finite() && pixel_size > 0.0 && extent.is_finite()) {
            return Err(BosError::Setup(
                "the background image's pixel size must be finite and > 0",
            ));
        }
        let outside = samples.iter().sum::<f64>() / n as f64;
        Ok(Self { width, height, samples, pixel_size, outside })
    }

    /// [`ImageBackground::new`] with pixels of `pixel_px` sensor pixels
    /// as imaged by `camera` focused on the background.
    ///
    /// # Errors
    /// As [`ImageBackground::new`].
    pub fn for_camera(
        camera: &ThinLens,
        width: usize,
        height: usize,
        samples: Vec<f64>,
        pixel_px: f64,
    ) -> Result<Self, BosError> {
        Self::new(width, height, samples, pixel_px * camera.pixel_in_focus())
    }

    /// Pixels per row.
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Rows.
    #[must_use]
    pub fn height(&self) -> usize {
        self.height
    }

    /// The samples, row-major, row 0 at the top.
    #[must_use]
    pub fn samples(&self) -> &[f64] {
        &self.samples
    }

    /// The side of a pixel on the background plane, scene units.
    #[must_use]
    pub fn pixel_size(&self) -> f64 {
        self.pixel_size
    }

    /// The value outside the image: the mean of its samples.
    #[must_use]
    pub fn outside(&self) -> f64 {
        self.outside
    }

    /// The background at `(u, v)`.
    #[must_use]
    pub fn value(&self, u: f64, v: f64) -> f64 {
        let (w, h) = (self.width as f64, self.height as f64);
        // Image coordinates: pixel (i, j) spans [i, i+1) × [j, j+1).
        let x = u / self.pixel_size + 0.5 * w;
        let y = 0.5 * h - v / self.pixel_size;
        if !(x >= 0.0 && x <= w && y >= 0.0 && y <= h) {
            return self.outside; // NaN lands here too
        }
        // Bilinear between pixel centres, edge pixels repeated.
        let (fx, fy) = (x - 0.5, y - 0.5);
        let (x0, y0) = (floor(fx), floor(fy));
        let (tx, ty) = (fx - x0, fy - y0);
        let col = |i: f64| (i.max(0.0) as usize).min(self.width - 1);
        let row = |j: f64| (j.max(0.0) as usize).min(self.height - 1);
        let at = |i: f64, j: f64| self.samples[row(j) * self.width + col(i)];
        let top = at(x0, y0) + tx * (at(x0 + 1.0, y0) - at(x0, y0));
        let bottom = at(x0, y0 + 1.0) + tx * (at(x0 + 1.0, y0 + 1.0) - at(x0, y0 + 1.0));
        top + ty * (bottom - top)
    }
}

/// The background behind the flow.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum BackgroundChoice {
    /// Random dots (seeded by [`crate::BosOptions::seed`]).
    #[default]
    Random,
    /// A regular grid of dots.
    Grid,
    /// A grey image, row 0 at the top.
    Image {
        /// Pixels across.
        width: usize,
        /// Pixels down.
        height: usize,
        /// Grey levels, row by row.
        samples: Vec<f64>,
        /// Sensor pixels one image pixel covers as imaged (`None`: the
        /// image spans the sensor's width).
        pixel: Option<f64>,
    },
}
