//! Diffraction blur: the Airy pattern of a lens's circular aperture, on
//! the sensor's pixels (docs/physics.md §11).
//!
//! At wavelength `λ` a lens whose light converges on the sensor at
//! f-number `N` images a point as the Airy pattern
//! `I(r) = I₀ [2 J₁(x)/x]²`, `x = π r/(λN)` (Born & Wolf §8.5.2): a disc
//! whose first dark ring has diameter `2.44 λN` (the first zero of `J₁`,
//! `x = 3.8317`), ringed by fainter rings. The light within radius `r` is
//! `E = 1 − J₀²(x) − J₁²(x)` (Rayleigh): 83.8 % inside the first dark
//! ring.
//!
//! [`Airy::kernel`] samples the pattern centred on a pixel's centre: each
//! tap is the light falling on one pixel, `∫∫ I dA` over the pixel's
//! square, computed in polar form `∫ I(r) φ(r) 2πr dr` (`φ`: the fraction
//! of the circle of radius `r` inside the square) by 3-point
//! Gauss–Legendre on steps of at most `λN/8` and a sixteenth of a pixel,
//! split where the circle passes the square's corners. The kernel extends
//! to the 21st dark ring (radius ≈ 21.25 λN): the light beyond, under
//! 0.96 % (`J₀² + J₁² ≈ 2/(πx)`), is dropped and the taps rescaled to sum
//! to 1 (so a uniform image stays uniform; the fraction kept is
//! [`AiryKernel::captured`]). [`Airy::blur`] convolves an image with it,
//! edges clamped (the pixels beyond an edge repeat it).
//!
//! `J₀` and `J₁`: the polynomial approximations of Abramowitz & Stegun
//! 9.4.1, 9.4.3 (`J₀`) and 9.4.4, 9.4.6 (`J₁`), absolute error below 1e-7.

use alloc::vec;
use alloc::vec::Vec;

use super::sensor_error::{SensorError, check_image};
use crate::math::{atan2, ceil, cos, sqrt};

/// The first zero of `J₁`: the first dark ring at `x = 3.8317…`.
const J1_ZERO_1: f64 = 3.831_705_970_207_512;

/// The kernel's radius in units of `λN`: the 21st dark ring of the Airy
/// pattern (`x = 66.75`, `r = x λN/π`), beyond which 0.95 % of the light
/// falls.
const KERNEL_RADIUS: f64 = 21.25;

/// The largest kernel radius, in pixels (a kernel of 1025² taps).
const MAX_RADIUS: usize = 512;

/// Diffraction by a lens's circular aperture: an Airy pattern on the
/// sensor (first dark ring of diameter `2.44 λN`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Airy {
    /// Wavelength `λ`, metres.
    pub wavelength: f64,
    /// f-number `N` of the cone of light converging on the sensor. For a
    /// lens focused at a finite distance that is the working f-number
    /// `N·(1 + M)` of a lens set to `N` at magnification `M`
    /// ([`ThinLens::airy`](crate::ThinLens::airy) gives it).
    pub f_number: f64,
    /// Sensor pixel pitch, metres.
    pub pixel_pitch: f64,
}

/// An [`Airy`] pattern sampled on the pixels: `(2·radius + 1)²` taps,
/// row-major, centred on the middle one; symmetric, non-negative, summing
/// to 1.
#[derive(Clone, Debug, PartialEq)]
pub struct AiryKernel {
    /// Taps on each side of the centre.
    pub radius: usize,
    /// The taps, `(2·radius + 1)²`, row-major.
    pub weights: Vec<f64>,
    /// The fraction of the pattern's light that falls on the kernel's
    /// pixels (before the taps were rescaled to sum to 1): above 0.99.
    pub captured: f64,
}

impl Airy {
    /// The pattern of light `wavelength` through f-number `f_number` on
    /// pixels of pitch `pixel_pitch` (metres).
    #[inline]
    #[must_use]
    pub const fn new(wavelength: f64, f_number: f64, pixel_pitch: f64) -> Self {
        Self { wavelength, f_number, pixel_pitch }
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`SensorError::Wavelength`], [`SensorError::FNumber`] or
    /// [`SensorError::PixelPitch`] for a value that is not finite and > 0;
    /// [`SensorError::AiryTooWide`] when the kernel would pass 512 pixels
    /// in radius (`λN` above about 24 pixels).
    pub fn validate(&self) -> Result<(), SensorError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !pos(self.wavelength) {
            return Err(SensorError::Wavelength(self.wavelength));
        }
        if !pos(self.f_number) {
            return Err(SensorError::FNumber(self.f_number));
        }
        if !pos(self.pixel_pitch) {
            return Err(SensorError::PixelPitch(self.pixel_pitch));
        }
        let s = self.scale();
        if !(s.is_finite() && KERNEL_RADIUS * s <= MAX_RADIUS as f64) {
            return Err(SensorError::AiryTooWide(s));
        }
        Ok(())
    }

    /// `λN` in pixels: the pattern's length scale.
    #[inline]
    #[must_use]
    pub fn scale(&self) -> f64 {
        self.wavelength * self.f_number / self.pixel_pitch
    }

    /// The radius of the first dark ring, `1.22 λN`, in pixels (half the
    /// `2.44 λN` diameter).
    #[inline]
    #[must_use]
    pub fn first_dark_ring(&self) -> f64 {
        J1_ZERO_1 / core::f64::consts::PI * self.scale()
    }

    /// The intensity at `r` pixels from the centre relative to the peak:
    /// `[2 J₁(x)/x]²`, `x = π r/(λN)` (1 at the centre).
    #[inline]
    #[must_use]
    pub fn intensity(&self, r: f64) -> f64 {
        airy_intensity(core::f64::consts::PI * r / self.scale())
    }

    /// The fraction of the light within `r` pixels of the centre:
    /// `1 − J₀²(x) − J₁²(x)`, `x = π r/(λN)` (0.838 at the first dark
    /// ring, → 1 far out).
    #[inline]
    #[must_use]
    pub fn encircled_energy(&self, r: f64) -> f64 {
        let x = core::f64::consts::PI * r / self.scale();
        1.0 - j0(x) * j0(x) - j1(x) * j1(x)
    }

    /// The pattern sampled on the pixels (see the module docs): a kernel
    /// of radius `⌈21.25 λN⌉` pixels.
    ///
    /// # Errors
    /// A bad setting (see [`Airy::validate`]).
    pub fn kernel(&self) -> Result<AiryKernel, SensorError> {
        self.validate()?;
        let s = self.scale();
        let radius = (ceil(KERNEL_RADIUS * s) as usize).clamp(1, MAX_RADIUS);
        let n = 2 * radius + 1;
        // Steps of the radial integral: the rings (width ≈ λN) and the
        // pixel's outline both resolved.
        let step = (s / 8.0).min(1.0 / 16.0);
        // dE = I(x)·2πr dr · π/(4 (λN)²): the pattern's light sums to 1.
        let norm = core::f64::consts::PI / (4.0 * s * s);
        let mut weights = vec![0.0; n * n];
        // One octant (0 ≤ j ≤ i), mirrored: the kernel is exactly
        // symmetric.
        for i in 0..=radius {
            for j in 0..=i {
                let w = norm * pixel_light(i as f64, j as f64, s, step);
                for (a, b) in [(i, j), (j, i)] {
                    for (x, y) in [
                        (radius + a, radius + b),
                        (radius - a, radius + b),
                        (radius + a, radius - b),
                        (radius - a, radius - b),
                    ] {
                        weights[y * n + x] = w;
                    }
                }
            }
        }
        let captured: f64 = weights.iter().sum();
        for w in &mut weights {
            *w /= captured;
        }
        Ok(AiryKernel { radius, weights, captured })
    }

    /// `image` (`width × height` intensities, row-major) convolved with
    /// the [`Airy::kernel`], edges clamped; deterministic (each pixel's sum
    /// in a fixed order, at any thread count with feature `parallel`).
    /// Costs `width × height × (2·radius + 1)²` multiplications.
    ///
    /// # Errors
    /// A bad setting, an image of the wrong size, or a sample that is not
    /// a finite intensity ≥ 0.
    pub fn blur(
        &self,
        image: &[f64],
        width: usize,
        height: usize,
    ) -> Result<Vec<f64>, SensorError> {
        check_image(image, width, height)?;
        Ok(self.kernel()?.convolve(image, width, height))
    }
}

impl AiryKernel {
    /// `image` (checked: `width × height > 0` samples) convolved with the
    /// kernel, edges clamped.
    pub(crate) fn convolve(&self, image: &[f64], width: usize, height: usize) -> Vec<f64> {
        debug_assert!(width * height == image.len() && !image.is_empty());
        let (r, n) = (self.radius, 2 * self.radius + 1);
        // Each row padded by r on both sides with its edge value.
        let pw = width + 2 * r;
        let mut padded = Vec::with_capacity(pw * height);
        for row in image.chunks_exact(width) {
            padded.extend(core::iter::repeat_n(row[0], r));
            padded.extend_from_slice(row);
            padded.extend(core::iter::repeat_n(row[width - 1], r));
        }
        // Out(x, y) = Σ K[dy][dx] · In(x + dx − r, y + dy − r), clamped
        // (the kernel is symmetric: correlation is convolution).
        let row = |y: usize| {
            let mut out = vec![0.0; width];
            for dy in 0..n {
                let sy = (y + dy).saturating_sub(r).min(height - 1);
                let src = &padded[sy * pw..(sy + 1) * pw];
                let k = &self.weights[dy * n..(dy + 1) * n];
                for (x, o) in out.iter_mut().enumerate() {
                    *o += dot(k, &src[x..x + n]);
                }
            }
            out
        };
        #[cfg(feature = "parallel")]
        let rows: Vec<Vec<f64>> = {
            use rayon::prelude::*;
            (0..height).into_par_iter().map(row).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let rows: Vec<Vec<f64>> = (0..height).map(row).collect();
        rows.concat()
    }
}

/// `Σ aᵢ bᵢ` in four interleaved partial sums (a fixed order).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// `[2 J₁(x)/x]²` (1 at `x = 0`).
fn airy_intensity(x: f64) -> f64 {
    let x = x.abs();
    let a = if x <= 3.0 { 2.0 * j1_over_x_small(x) } else { 2.0 * j1(x) / x };
    a * a
}

/// `∫ [2 J₁(x)/x]² φ(r) 2πr dr` over the pixel `(i, j)` (`i ≥ j ≥ 0`, its
/// square `[i − ½, i + ½] × [j − ½, j + ½]` in pixels), `x = πr/s`.
fn pixel_light(i: f64, j: f64, s: f64, step: f64) -> f64 {
    let (x0, x1, y0, y1) = (i - 0.5, i + 0.5, j - 0.5, j + 0.5);
    let center = i == 0.0;
    let r_min = if center { 0.0 } else { sqrt(x0 * x0 + if j == 0.0 { 0.0 } else { y0 * y0 }) };
    // Breakpoints: where φ has kinks (the circle through a corner, or
    // leaving the inscribed circle of the centre pixel).
    let mut cuts = [r_min, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let mut k = 1;
    let mut push = |r: f64| {
        if r > r_min {
            cuts[k] = r;
            k += 1;
        }
    };
    if center {
        push(0.5);
        push(sqrt(0.5));
    } else {
        for (x, y) in [(x0, y0), (x0, y1), (x1, y0), (x1, y1)] {
            push(sqrt(x * x + y * y));
        }
        if j == 0.0 {
            // Tangent to the far edge.
            push(x1);
        }
    }
    let cuts = &mut cuts[..k];
    cuts.sort_unstable_by(f64::total_cmp);
    let phi = |r: f64| if center { centre_fraction(r) } else { arc_fraction(r, x0, x1, y0, y1) };
    let f = |r: f64| {
        airy_intensity(core::f64::consts::PI * r / s) * phi(r) * core::f64::consts::TAU * r
    };
    // 3-point Gauss–Legendre on each step.
    const G: f64 = 0.774_596_669_241_483_4; // √(3/5)
    let mut total = 0.0;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        let m = ceil((b - a) / step).max(1.0);
        let h = (b - a) / m;
        for q in 0..m as usize {
            let c = a + (q as f64 + 0.5) * h;
            let d = 0.5 * h * G;
            total += 0.5 * h * (5.0 * f(c - d) + 8.0 * f(c) + 5.0 * f(c + d)) / 9.0;
        }
    }
    total
}

/// The fraction of the circle of radius `r` about the origin inside the
/// centre pixel `[−½, ½]²`: 1 inside its inscribed circle, then less the
/// four arcs beyond its edges, `1 − (4/π) acos(1/(2r))`, 0 past its
/// corners.
fn centre_fraction(r: f64) -> f64 {
    if r <= 0.5 {
        1.0
    } else {
        (1.0 - 4.0 / core::f64::consts::PI * acos((0.5 / r).min(1.0))).max(0.0)
    }
}

/// The fraction of the circle of radius `r` about the origin inside the
/// rectangle `[x0, x1] × [y0, y1]`, `x0 > 0` (right of the origin: the
/// arc is where `|θ| < π/2`).
fn arc_fraction(r: f64, x0: f64, x1: f64, y0: f64, y1: f64) -> f64 {
    // θ within [a, b] keeps y = r sin θ in [y0, y1]; |θ| within [c, d]
    // keeps x = r cos θ in [x0, x1].
    let a = asin((y0 / r).clamp(-1.0, 1.0));
    let b = asin((y1 / r).clamp(-1.0, 1.0));
    let c = acos((x1 / r).min(1.0));
    let d = acos((x0 / r).min(1.0));
    let overlap = |lo: f64, hi: f64| (b.min(hi) - a.max(lo)).max(0.0);
    (overlap(c, d) + overlap(-d, -c)) / core::f64::consts::TAU
}

/// `asin t`, `|t| ≤ 1`.
fn asin(t: f64) -> f64 {
    atan2(t, sqrt((1.0 - t * t).max(0.0)))
}

/// `acos t`, `|t| ≤ 1`.
fn acos(t: f64) -> f64 {
    atan2(sqrt((1.0 - t * t).max(0.0)), t)
}

/// `J₁(x)/x` for `|x| ≤ 3` (A&S 9.4.4, error < 1.3e-8).
fn j1_over_x_small(x: f64) -> f64 {
    let t = (x / 3.0) * (x / 3.0);
    0.5 + t
        * (-0.562_499_85
            + t * (0.210_935_73
                + t * (-0.039_542_89
                    + t * (0.004_433_19 + t * (-0.000_317_61 + t * 0.000_011_09)))))
}

/// The Bessel function `J₀(x)` (A&S 9.4.1 for `|x| ≤ 3`, error < 5e-8;
/// 9.4.3 beyond, < 1.6e-8 in the modulus, 7e-8 in the phase).
pub(crate) fn j0(x: f64) -> f64 {
    let x = x.abs();
    if x <= 3.0 {
        let t = (x / 3.0) * (x / 3.0);
        1.0 + t
            * (-2.249_999_7
                + t * (1.265_620_8
                    + t * (-0.316_386_6
                        + t * (0.044_447_9 + t * (-0.003_944_4 + t * 0.000_210_0)))))
    } else {
        let u = 3.0 / x;
        let f0 = 0.797_884_56
            + u * (-0.000_000_77
                + u * (-0.005_527_40
                    + u * (-0.000_095_12
                        + u * (0.001_372_37 + u * (-0.000_728_05 + u * 0.000_144_76)))));
        // (A&S's 0.78539816 is π/4.)
        let th0 = x - core::f64::consts::FRAC_PI_4
            + u * (-0.041_663_97
                + u * (-0.000_039_54
                    + u * (0.002_625_73
                        + u * (-0.000_541_25 + u * (-0.000_293_33 + u * 0.000_135_58)))));
        f0 * cos(th0) / sqrt(x)
    }
}

/// The Bessel function `J₁(x)` (A&S 9.4.4 for `|x| ≤ 3`, error < 1.3e-8;
/// 9.4.6 beyond, < 4e-8 in the modulus, 9e-8 in the phase).
pub(crate) fn j1(x: f64) -> f64 {
    let sign = if x < 0.0 { -1.0 } else { 1.0 };
    let x = x.abs();
    let v = if x <= 3.0 {
        x * j1_over_x_small(x)
    } else {
        let u = 3.0 / x;
        let f1 = 0.797_884_56
            + u * (0.000_001_56
                + u * (0.016_596_67
                    + u * (0.000_171_05
                        + u * (-0.002_495_11 + u * (0.001_136_53 + u * -0.000_200_33)))));
        let th1 = x - 2.356_194_49
            + u * (0.124_996_12
                + u * (0.000_056_50
                    + u * (-0.006_378_79
                        + u * (0.000_743_48 + u * (0.000_798_24 + u * -0.000_291_66)))));
        f1 * cos(th1) / sqrt(x)
    };
    sign * v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::sin;

    /// `J_n(x) = (1/2π) ∫₀^{2π} cos(nτ − x sin τ) dτ` by the trapezoid
    /// rule, exact to rounding for a periodic integrand sampled finely.
    fn bessel_reference(n: f64, x: f64) -> f64 {
        let m = 2000;
        (0..m)
            .map(|k| {
                let t = core::f64::consts::TAU * f64::from(k) / f64::from(m);
                cos(n * t - x * sin(t))
            })
            .sum::<f64>()
            / f64::from(m)
    }

    #[test]
    fn bessel_functions_match_their_integrals() {
        let mut worst: f64 = 0.0;
        for k in 0..=1600 {
            let x = f64::from(k) * 0.0625; // 0 … 100, through x = 3
            worst = worst.max((j0(x) - bessel_reference(0.0, x)).abs());
            worst = worst.max((j1(x) - bessel_reference(1.0, x)).abs());
        }
        assert!(worst < 1e-7, "{worst}");
        // Known zeros.
        assert!(j0(2.404_825_557_695_773).abs() < 1e-7);
        for z in [J1_ZERO_1, 7.015_586_669_815_619, 10.173_468_135_062_722] {
            assert!(j1(z).abs() < 1e-7, "J1({z}) = {}", j1(z));
        }
        assert_eq!(j1(-2.0), -j1(2.0));
    }

    /// `dE/dr = I(r)·2πr·π/(4 (λN)²)`: the encircled energy is the
    /// integral of the intensity; 83.8 % at the first dark ring.
    #[test]
    fn encircled_energy_integrates_the_intensity() {
        let a = Airy::new(500e-9, 8.0, 1e-6); // λN = 4 px
        let s = a.scale();
        assert!((s - 4.0).abs() < 1e-12);
        let h = 1e-4;
        for r in [0.3, 1.0, 4.87, 7.5, 20.0] {
            let de = (a.encircled_energy(r + h) - a.encircled_energy(r - h)) / (2.0 * h);
            let want =
                a.intensity(r) * core::f64::consts::TAU * r * core::f64::consts::PI / (4.0 * s * s);
            assert!((de - want).abs() < 1e-5, "r {r}: {de} vs {want}");
        }
        let ring = a.first_dark_ring();
        assert!((ring / (1.22 * s) - 1.0).abs() < 1e-3);
        assert!(a.intensity(ring) < 1e-12);
        assert!((a.encircled_energy(ring) - 0.8378).abs() < 1e-4, "{}", a.encircled_energy(ring));
        assert_eq!(a.intensity(0.0), 1.0);
    }

    /// The fraction of a circle inside a square: 1/4 for a circle through
    /// a corner-centred square's symmetric arc, against brute force.
    #[test]
    fn arc_fraction_is_the_arc_inside() {
        for (r, x0, y0) in [(1.3, 0.5, -0.5), (2.0, 1.5, 0.5), (1.9, 1.5, 1.5), (0.7, 0.5, -0.5)] {
            let (x1, y1) = (x0 + 1.0, y0 + 1.0);
            let m = 200_000;
            let inside = (0..m)
                .filter(|&k| {
                    let t = core::f64::consts::TAU * (f64::from(k) + 0.5) / f64::from(m);
                    let (x, y) = (r * cos(t), r * sin(t));
                    x >= x0 && x <= x1 && y >= y0 && y <= y1
                })
                .count() as f64
                / f64::from(m);
            let got = arc_fraction(r, x0, x1, y0, y1);
            assert!((got - inside).abs() < 1e-4, "r {r} at ({x0}, {y0}): {got} vs {inside}");
        }
        assert_eq!(centre_fraction(0.4), 1.0);
        assert!(centre_fraction(0.7072).abs() < 1e-12);
    }
}
