//! The film: photons splatted with a normalised reconstruction filter.

use alloc::vec::Vec;
use core::fmt;

use super::{cutoff::FilterImage, sheet};
use crate::math;

/// The reconstruction filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// Each photon lands in the one pixel it hits. With pixel-aligned
    /// stratified emission an undisturbed field gives exactly the background.
    Box,
    /// Bilinear tent of one pixel radius; weights sum to 1 per photon.
    Tent,
    /// A wider tent, `radius` pixels (finite, ≥ 1), weights normalised
    /// per photon: for few photons per pixel (see [`Filter::adaptive`]).
    WideTent {
        /// Radius in pixels.
        radius: f64,
    },
}

impl Filter {
    /// The adaptive-radius choice for `photons_per_pixel`: a tent whose
    /// footprint (≈ radius² pixels) gathers about 4 photons, never narrower
    /// than one pixel.
    #[must_use]
    pub fn adaptive(photons_per_pixel: f64) -> Self {
        let r = if photons_per_pixel > 0.0 { math::sqrt(4.0 / photons_per_pixel) } else { 4.0 };
        if r <= 1.0 { Self::Tent } else { Self::WideTent { radius: r.min(16.0) } }
    }
}

/// A photon landed on the film, as [`Film::splat_all`] takes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Photon {
    /// Film coordinate in pixels, continuous, growing to the right: pixel
    /// `(i, j)` spans `[i, i+1) × [j, j+1)`.
    pub x: f64,
    /// Film coordinate in pixels, continuous, growing downward (row 0 is
    /// the top of the image).
    pub y: f64,
    /// Weight per linear RGB channel: the cutoff's transmission (times
    /// the colour a multifield render carries); 1 is one undisturbed,
    /// uncut photon.
    pub weight: [f32; 3],
    /// Deflection `(εu, εv)` in radians along the image axes u (to the
    /// right) and v (up, against `y`): the photon's unit exit direction
    /// projected on them, i.e. the sines of the deflection angles, equal to
    /// the angles for small deflections. Averaged per pixel by
    /// [`Film::mean_deflection`].
    pub deflection: (f64, f64),
    /// Interferometry: the photon's phase `φ = (2π/λ)·∫(n − n_ref) ds`
    /// in radians, unwrapped (0 in the other modes). Averaged per pixel by
    /// [`Film::mean_phase`].
    pub phase: f64,
}

impl Photon {
    /// A photon at `(x, y)` (pixels) with RGB `weight` and `deflection`
    /// `(εu, εv)` (radians).
    #[inline]
    #[must_use]
    pub const fn new(x: f64, y: f64, weight: [f32; 3], deflection: (f64, f64)) -> Self {
        Self { x, y, weight, deflection, phase: 0.0 }
    }

    /// The photon with its interferometric `phase` (radians).
    #[inline]
    #[must_use]
    pub const fn with_phase(self, phase: f64) -> Self {
        Self { phase, ..self }
    }
}

/// Why a film could not be made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FilmError {
    /// The width or the height is zero.
    ZeroSize {
        /// Requested width in pixels.
        width: usize,
        /// Requested height in pixels.
        height: usize,
    },
    /// More than [`Film::MAX_PIXELS`] pixels (or `width × height`
    /// overflows).
    TooLarge {
        /// Requested width in pixels.
        width: usize,
        /// Requested height in pixels.
        height: usize,
    },
    /// A [`Filter::WideTent`] radius that is NaN, infinite or below one
    /// pixel.
    BadFilterRadius(f64),
    /// The accumulators did not fit in memory (the allocator refused).
    OutOfMemory {
        /// Bytes asked for.
        bytes: usize,
    },
}

impl fmt::Display for FilmError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ZeroSize { width, height } => {
                write!(f, "a {width}×{height} film has no pixels")
            }
            Self::TooLarge { width, height } => write!(
                f,
                "a {width}×{height} film exceeds the limit of {} pixels",
                Film::MAX_PIXELS
            ),
            Self::BadFilterRadius(r) => {
                write!(f, "wide tent filter radius {r} must be finite and at least 1 pixel")
            }
            Self::OutOfMemory { bytes } => {
                write!(f, "a film of {bytes} bytes does not fit in memory")
            }
        }
    }
}

impl core::error::Error for FilmError {}

/// Accumulated photon weight per pixel (RGB), the mean deflection and
/// phase per pixel (the picking pass), and photon bookkeeping.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: usize,
    height: usize,
    filter: Filter,
    rgb: Vec<[f64; 3]>,
    /// Per pixel: Σ k·εu, Σ k·εv, Σ k, Σ k·φ.
    eps: Vec<[f64; 4]>,
    /// Photons emitted so far.
    pub emitted: u64,
    /// Photons that landed outside the film (counted, not splatted; for a
    /// sheet, those of its lattice emitted inside the beam).
    pub lost: u64,
    /// Photons emitted per pixel of an undisturbed image (the background).
    pub per_pixel: f64,
}

impl Film {
    /// The most pixels a film may have: 2²⁸ (its accumulators take 56
    /// bytes a pixel, 14 GiB at the limit).
    pub const MAX_PIXELS: usize = 1 << 28;

    /// An empty film of `width × height` pixels.
    ///
    /// # Errors
    /// [`FilmError::ZeroSize`] if `width` or `height` is 0,
    /// [`FilmError::TooLarge`] beyond [`Film::MAX_PIXELS`],
    /// [`FilmError::BadFilterRadius`] for a [`Filter::WideTent`] radius
    /// that is not finite and ≥ 1.
    pub fn new(width: usize, height: usize, filter: Filter) -> Result<Self, FilmError> {
        if width == 0 || height == 0 {
            return Err(FilmError::ZeroSize { width, height });
        }
        let n = width
            .checked_mul(height)
            .filter(|&n| n <= Self::MAX_PIXELS)
            .ok_or(FilmError::TooLarge { width, height })?;
        if let Filter::WideTent { radius } = filter
            && !(radius.is_finite() && radius >= 1.0)
        {
            return Err(FilmError::BadFilterRadius(radius));
        }
        // Fallible: a film too large for the machine is an `Err`, not an
        // abort of the program that embeds it.
        let bytes = n * (size_of::<[f64; 3]>() + size_of::<[f64; 4]>());
        let (mut rgb, mut eps) = (Vec::new(), Vec::new());
        rgb.try_reserve_exact(n).map_err(|_| FilmError::OutOfMemory { bytes })?;
        eps.try_reserve_exact(n).map_err(|_| FilmError::OutOfMemory { bytes })?;
        rgb.resize(n, [0.0; 3]);
        eps.resize(n, [0.0; 4]);
        Ok(Self { width, height, filter, rgb, eps, emitted: 0, lost: 0, per_pixel: 0.0 })
    }

    /// Width in pixels.
    #[must_use]
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    #[must_use]
    pub fn height(&self) -> usize {
        self.height
    }

    /// Deposits weight `w` (RGB) of a photon at continuous pixel
    /// coordinates `(x, y)` (pixel `(i, j)` spans `[i, i+1) × [j, j+1)`),
    /// with its deflection for the picking pass.
    pub fn splat(&mut self, x: f64, y: f64, w: [f32; 3], eps: (f64, f64)) {
        self.splat_photon(&Photon::new(x, y, w, eps));
    }

    /// [`Film::splat`] of a whole photon (its phase too).
    pub fn splat_photon(&mut self, p: &Photon) {
        let &Photon { x, y, weight: w, deflection: eps, phase } = p;
        if !self.on_film(x, y) {
            self.lost += 1;
            return;
        }
        let width = self.width;
        let (rgb, eps_acc) = (&mut self.rgb, &mut self.eps);
        footprint(self.filter, self.width, self.height, x, y, |i, j, k| {
            let p = i + width * j;
            deposit(&mut rgb[p], &mut eps_acc[p], k, w.map(f64::from), eps, phase);
        });
    }

    fn on_film(&self, x: f64, y: f64) -> bool {
        x >= 0.0 && y >= 0.0 && x < self.width as f64 && y < self.height as f64
    }

    /// Splats photons in order: the same image, bit for bit, as calling
    /// [`Film::splat_photon`] on each in turn. With feature
    /// `parallel` the film's rows are split into bands filled in parallel,
    /// each band taking, in order, the photons whose footprint reaches it,
    /// so every pixel still sums its contributions in the serial order.
    pub fn splat_all<'a>(
        &mut self,
        photons: impl Iterator<Item = &'a Photon> + Clone + Send + Sync,
    ) {
        #[cfg(feature = "parallel")]
        {
            let (width, height, filter) = (self.width, self.height, self.filter);
            let lost = photons.clone().filter(|p| !self.on_film(p.x, p.y)).count();
            // Rows a photon's footprint may reach beyond its own.
            let reach = match filter {
                Filter::Box => 0.0,
                Filter::Tent => 1.0,
                Filter::WideTent { radius } => radius.max(1.0) + 1.0,
            };
            self.bands(|lo, rgb, eps_acc| {
                let hi = lo + rgb.len() / width;
                for &Photon { x, y, weight: w, deflection: e, phase } in photons.clone() {
                    let on = x >= 0.0 && y >= 0.0 && x < width as f64 && y < height as f64;
                    if !on || y + reach < lo as f64 || y - reach >= hi as f64 {
                        continue;
                    }
                    footprint(filter, width, height, x, y, |i, j, k| {
                        if (lo..hi).contains(&j) {
                            let p = i + width * (j - lo);
                            deposit(&mut rgb[p], &mut eps_acc[p], k, w.map(f64::from), e, phase);
                        }
                    });
                }
            });
            self.lost += lost as u64;
        }
        #[cfg(not(feature = "parallel"))]
        for p in photons {
            self.splat_photon(p);
        }
    }

    /// Shares out the cells of a traced lattice ([`crate::Reconstruction::Sheet`]):
    /// `lattice` holds rows of landed photons, all rows equally long, the
    /// photon `(a, b)` emitted at film coordinates `emission(a, b)`; cell
    /// `(a, b)` has corners `(a, b)`, `(a+1, b)`, `(a+1, b+1)`, `(a, b+1)`
    /// (numbered 0–3) and carries `density` photons per unit of its
    /// emission area (pixels²) inside the beam (the film's rectangle).
    /// Where a cell inside the beam lands as a convex quadrilateral its
    /// light, with its corners' mean weight and deflection, is spread
    /// uniformly over it; a cell folded or twisted by the optics is shared
    /// out as its triangles `[0, 1, 2]` and `[0, 2, 3]`, each over its own
    /// image; a cell straddling the beam's edge as the parts of its
    /// triangles inside the beam, carried by each triangle's affine map.
    /// With feature `parallel` the film is split into bands of rows filled
    /// in parallel, each taking the cells in the serial order: the same
    /// image, bit for bit.
    pub(crate) fn deposit_sheet(
        &mut self,
        lattice: &[Vec<Photon>],
        emission: impl Fn(usize, usize) -> (f64, f64) + Sync,
        density: f64,
    ) {
        let (width, height) = (self.width, self.height);
        let (wd, ht) = (width as f64, height as f64);
        // The rows of the film each row of cells may reach.
        let reach: Vec<(f64, f64)> = lattice
            .windows(2)
            .map(|r| {
                r.iter()
                    .flatten()
                    .map(|p| p.y)
                    .filter(|y| y.is_finite())
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| (lo.min(y), hi.max(y)))
            })
            .collect();
        const CORNER: [(usize, usize); 4] = [(0, 0), (1, 0), (1, 1), (0, 1)];
        let band = |lo: usize, rgb: &mut [[f64; 3]], eps: &mut [[f64; 4]]| {
            let hi = lo + rgb.len() / width;
            for (b, rows) in lattice.windows(2).enumerate() {
                let (y0, y1) = reach[b];
                if !(y1 >= lo as f64 && y0 < hi as f64) {
                    continue;
                }
                for a in 0..rows[0].len().saturating_sub(1) {
                    let c = [&rows[0][a], &rows[0][a + 1], &rows[1][a + 1], &rows[1][a]];
                    // Spreads `e` photons with the mean weight and
                    // deflection of `corners` uniformly over `image`.
                    let mut spread = |corners: &[usize], image: &[(f64, f64)], e: f64| {
                        let m = 1.0 / corners.len() as f64;
                        let (mut w, mut d, mut phi) = ([0.0; 3], (0.0, 0.0), 0.0);
                        for &i in corners {
                            let p = c[i];
                            for (wc, pc) in w.iter_mut().zip(p.weight) {
                                *wc += m * f64::from(pc);
                            }
                            d = (d.0 + m * p.deflection.0, d.1 + m * p.deflection.1);
                            phi += m * p.phase;
                        }
                        sheet::cover(image, width, height, (lo, hi), |i, j, k| {
                            let p = i + width * (j - lo);
                            deposit(&mut rgb[p], &mut eps[p], k * e, w, d, phi);
                        });
                    };
                    let landed = [0, 1, 2, 3].map(|i| (c[i].x, c[i].y));
                    let from = CORNER.map(|(da, db)| emission(a + da, b + db));
                    let inside =
                        from[0].0 >= 0.0 && from[0].1 >= 0.0 && from[2].0 <= wd && from[2].1 <= ht;
                    if !inside {
                        for tri in [[0, 1, 2], [0, 2, 3]] {
                            let (f, t) = (tri.map(|i| from[i]), tri.map(|i| landed[i]));
                            if let Some((image, area)) = sheet::clip_and_map(f, t, wd, ht) {
                                spread(&tri, image.vertices(), density * area);
                            }
                        }
                    } else if sheet::convex(landed) {
                        // One convex quadrilateral: one polygon to share out.
                        spread(&[0, 1, 2, 3], &landed, 1.0);
                    } else {
                        for tri in [[0, 1, 2], [0, 2, 3]] {
                            spread(&tri, &tri.map(|i| landed[i]), 0.5);
                        }
                    }
                }
            }
        };
        self.bands(band);
    }

    /// Calls `fill(first_row, rgb, eps)` on bands of whole rows covering
    /// the film: one band per thread, in parallel, with feature `parallel`;
    /// the whole film at once without. A pixel's sums then depend only on
    /// the order `fill` visits its contributions, never on the banding.
    fn bands(&mut self, fill: impl Fn(usize, &mut [[f64; 3]], &mut [[f64; 4]]) + Sync) {
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            let (width, height) = (self.width, self.height);
            let rows = height.div_ceil(rayon::current_num_threads().clamp(1, height));
            self.rgb
                .par_chunks_mut(rows * width)
                .zip(self.eps.par_chunks_mut(rows * width))
                .enumerate()
                .for_each(|(b, (rgb, eps))| fill(b * rows, rgb, eps));
        }
        #[cfg(not(feature = "parallel"))]
        fill(0, &mut self.rgb, &mut self.eps);
    }

    /// Total deposited weight (RGB).
    #[must_use]
    pub fn total(&self) -> [f64; 3] {
        self.rgb.iter().fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]])
    }

    /// The image normalised to the background: 1 where nothing deflects
    /// and nothing is cut, per channel, row-major; all 0 before any photon
    /// was emitted. Rounded to `f32` (a relative step of 6e-8): see
    /// [`Film::normalized_f64`] to measure smaller differences.
    #[must_use]
    pub fn normalized(&self) -> Vec<[f32; 3]> {
        self.normalized_iter().map(|p| p.map(|c| c as f32)).collect()
    }

    /// [`Film::normalized`] in the `f64` the film accumulates in, for
    /// measurements of differences too small for `f32`: between two
    /// renders, or between pixels of a weak signal (a relative 1e-9 is
    /// lost in `f32`, kept here).
    #[must_use]
    pub fn normalized_f64(&self) -> Vec<[f64; 3]> {
        self.normalized_iter().collect()
    }

    /// [`Film::normalized_f64`] pixel by pixel, without the vector (an
    /// image as large as the film need not be held twice).
    pub fn normalized_iter(&self) -> impl Iterator<Item = [f64; 3]> + '_ {
        let k = if self.per_pixel > 0.0 { 1.0 / self.per_pixel } else { 0.0 };
        self.rgb.iter().map(move |p| [p[0] * k, p[1] * k, p[2] * k])
    }

    /// Mean deflection `(εu, εv)` of the photons that landed in each pixel
    /// (the picking pass: where to paint a filter); `None` for empty pixels.
    #[must_use]
    pub fn mean_deflection(&self) -> Vec<Option<(f64, f64)>> {
        self.deflection_iter().collect()
    }

    /// [`Film::mean_deflection`] pixel by pixel.
    pub fn deflection_iter(&self) -> impl Iterator<Item = Option<(f64, f64)>> + '_ {
        self.eps.iter().map(|e| (e[2] > 0.0).then(|| (e[0] / e[2], e[1] / e[2])))
    }

    /// The image `filter` gives from the deflections this film recorded
    /// (the picking pass: a render through [`FilterImage::clear`]), without
    /// tracing again:
    /// each pixel's light ([`Film::normalized_iter`]'s first channel) times
    /// what `filter` transmits at its photons' mean deflection; empty
    /// pixels dark. Exact where a pixel's photons share one deflection;
    /// where they spread (a shock inside the pixel) it is the filter at
    /// their mean, not the mean of the filter.
    #[must_use]
    pub fn through_filter(&self, filter: &FilterImage) -> Vec<[f32; 3]> {
        self.normalized_iter()
            .zip(self.deflection_iter())
            .map(|(light, eps)| match eps {
                Some((eu, ev)) => filter.at(eu, ev).map(|t| t * light[0] as f32),
                None => [0.0; 3],
            })
            .collect()
    }

    /// Mean interferometric phase (radians, unwrapped: see
    /// [`Photon::phase`]) of the photons that landed in each pixel; `None`
    /// for empty pixels; 0 where the bench is not an interferometer.
    #[must_use]
    pub fn mean_phase(&self) -> Vec<Option<f64>> {
        self.phase_iter().collect()
    }

    /// [`Film::mean_phase`] pixel by pixel.
    pub fn phase_iter(&self) -> impl Iterator<Item = Option<f64>> + '_ {
        self.eps.iter().map(|e| (e[2] > 0.0).then(|| e[3] / e[2]))
    }
}

/// Adds a photon's share `k` of weight `w`, deflection `eps` and `phase`
/// to a pixel.
#[inline]
fn deposit(
    rgb: &mut [f64; 3],
    acc: &mut [f64; 4],
    k: f64,
    w: [f64; 3],
    eps: (f64, f64),
    phase: f64,
) {
    for (a, wc) in rgb.iter_mut().zip(w) {
        *a += k * wc;
    }
    acc[0] += k * eps.0;
    acc[1] += k * eps.1;
    acc[2] += k;
    acc[3] += k * phase;
}

/// Calls `add(i, j, k)` for every pixel of the filter's footprint around
/// the on-film point `(x, y)`, shares `k` summing to 1.
fn footprint(
    filter: Filter,
    width: usize,
    height: usize,
    x: f64,
    y: f64,
    mut add: impl FnMut(usize, usize, f64),
) {
    let (wd, ht) = (width as f64, height as f64);
    match filter {
        Filter::Box => add(x as usize, y as usize, 1.0),
        Filter::WideTent { radius } => {
            // Separable tent over the pixel centres within `radius`;
            // normalised over the pixels on the film.
            let r = radius.max(1.0);
            let (i0, i1) =
                (math::ceil(x - r - 0.5).max(0.0), math::floor(x + r - 0.5).min(wd - 1.0));
            let (j0, j1) =
                (math::ceil(y - r - 0.5).max(0.0), math::floor(y + r - 0.5).min(ht - 1.0));
            let tent = |d: f64| (1.0 - d.abs() / r).max(0.0);
            let mut total = 0.0;
            let mut j = j0;
            while j <= j1 {
                let mut i = i0;
                while i <= i1 {
                    total += tent(i + 0.5 - x) * tent(j + 0.5 - y);
                    i += 1.0;
                }
                j += 1.0;
            }
            if total > 0.0 {
                let mut j = j0;
                while j <= j1 {
                    let mut i = i0;
                    while i <= i1 {
                        let k = tent(i + 0.5 - x) * tent(j + 0.5 - y) / total;
                        if k > 0.0 {
                            add(i as usize, j as usize, k);
                        }
                        i += 1.0;
                    }
                    j += 1.0;
                }
            } else {
                add(x as usize, y as usize, 1.0);
            }
        }
        Filter::Tent => {
            // Bilinear weights to the four nearest pixel centres; weights
            // falling off the film are renormalised onto the rest, so
            // every photon deposits exactly 1.
            let (u, v) = (x - 0.5, y - 0.5);
            let (i0, j0) = (math::floor(u), math::floor(v));
            let (fx, fy) = (u - i0, v - j0);
            let mut cells = [(0usize, 0usize, 0.0f64); 4];
            let mut total = 0.0;
            let mut n = 0;
            for (di, wi) in [(0.0, 1.0 - fx), (1.0, fx)] {
                for (dj, wj) in [(0.0, 1.0 - fy), (1.0, fy)] {
                    let (i, j) = (i0 + di, j0 + dj);
                    if i >= 0.0 && j >= 0.0 && i < wd && j < ht && wi * wj > 0.0 {
                        cells[n] = (i as usize, j as usize, wi * wj);
                        total += wi * wj;
                        n += 1;
                    }
                }
            }
            for &(i, j, k) in &cells[..n] {
                add(i, j, k / total);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two pixels 1e-9 apart (relative): `f32` rounds them to the same
    /// value, `f64` keeps the difference.
    #[test]
    fn normalized_f64_keeps_what_f32_loses() {
        let mut film = Film::new(2, 1, Filter::Box).unwrap();
        film.splat(0.5, 0.5, [1.0; 3], (0.0, 0.0));
        film.splat(1.5, 0.5, [1.0; 3], (0.0, 0.0));
        film.splat(1.5, 0.5, [1e-9; 3], (0.0, 0.0));
        film.per_pixel = 1.0;
        let (narrow, wide) = (film.normalized(), film.normalized_f64());
        assert_eq!(narrow[0], narrow[1], "f32 cannot tell them apart");
        let d = wide[1][0] - wide[0][0];
        assert!((d - 1e-9).abs() < 1e-15, "f64 keeps the difference: {d:e}");
        for (a, b) in narrow.iter().flatten().zip(wide.iter().flatten()) {
            assert_eq!(*a, *b as f32, "normalized is normalized_f64 rounded");
        }
    }

    #[test]
    fn bad_sizes_and_radii_are_typed_errors() {
        let e = |w, h, f| Film::new(w, h, f).unwrap_err();
        assert_eq!(e(0, 8, Filter::Box), FilmError::ZeroSize { width: 0, height: 8 });
        assert_eq!(e(8, 0, Filter::Tent), FilmError::ZeroSize { width: 8, height: 0 });
        let huge = FilmError::TooLarge { width: 1 << 20, height: 1 << 20 };
        assert_eq!(e(1 << 20, 1 << 20, Filter::Box), huge);
        let over = FilmError::TooLarge { width: usize::MAX, height: 2 };
        assert_eq!(e(usize::MAX, 2, Filter::Box), over);
        for r in [f64::NAN, f64::INFINITY, 0.5, -2.0] {
            let got = e(4, 4, Filter::WideTent { radius: r });
            assert!(matches!(got, FilmError::BadFilterRadius(x) if x.to_bits() == r.to_bits()));
        }
        assert!(Film::new(4, 4, Filter::WideTent { radius: 1.0 }).is_ok());
    }
}
