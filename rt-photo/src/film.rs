//! The film: photons splatted with a normalised reconstruction filter.

use alloc::vec::Vec;

/// The reconstruction filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    /// Each photon lands in the one pixel it hits. With pixel-aligned
    /// stratified emission an undisturbed field gives exactly the background.
    Box,
    /// Bilinear tent of one pixel radius; weights sum to 1 per photon.
    Tent,
    /// A wider tent, `radius` pixels (≥ 1), weights normalised per photon:
    /// for few photons per pixel (see [`Filter::adaptive`]).
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
        let r = if photons_per_pixel > 0.0 { (4.0 / photons_per_pixel).sqrt() } else { 4.0 };
        if r <= 1.0 { Self::Tent } else { Self::WideTent { radius: r.min(16.0) } }
    }
}

/// Accumulated photon weight per pixel (RGB), the mean deflection per pixel
/// (the picking pass), and photon bookkeeping.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    width: usize,
    height: usize,
    filter: Filter,
    rgb: Vec<[f64; 3]>,
    eps: Vec<[f64; 3]>,
    /// Photons emitted so far.
    pub emitted: u64,
    /// Photons that landed outside the film (counted, not splatted).
    pub lost: u64,
    /// Photons emitted per pixel of an undisturbed image (the background).
    pub per_pixel: f64,
}

impl Film {
    /// An empty film of `width × height` pixels.
    ///
    /// # Errors
    /// A message for zero or too large sizes.
    pub fn new(width: usize, height: usize, filter: Filter) -> Result<Self, &'static str> {
        let n = width
            .checked_mul(height)
            .filter(|&n| n > 0 && n <= 1 << 28)
            .ok_or("film size is zero or too large")?;
        Ok(Self {
            width,
            height,
            filter,
            rgb: alloc::vec![[0.0; 3]; n],
            eps: alloc::vec![[0.0; 3]; n],
            emitted: 0,
            lost: 0,
            per_pixel: 0.0,
        })
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
        let (wd, ht) = (self.width as f64, self.height as f64);
        if !(x >= 0.0 && y >= 0.0 && x < wd && y < ht) {
            self.lost += 1;
            return;
        }
        let mut add = |i: usize, j: usize, k: f64| {
            let p = i + self.width * j;
            for (acc, wc) in self.rgb[p].iter_mut().zip(w) {
                *acc += k * f64::from(wc);
            }
            self.eps[p][0] += k * eps.0;
            self.eps[p][1] += k * eps.1;
            self.eps[p][2] += k;
        };
        match self.filter {
            Filter::Box => add(x as usize, y as usize, 1.0),
            Filter::WideTent { radius } => {
                // Separable tent over the pixel centres within `radius`;
                // normalised over the pixels on the film.
                let r = radius.max(1.0);
                let (i0, i1) =
                    (((x - r - 0.5).ceil()).max(0.0), ((x + r - 0.5).floor()).min(wd - 1.0));
                let (j0, j1) =
                    (((y - r - 0.5).ceil()).max(0.0), ((y + r - 0.5).floor()).min(ht - 1.0));
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
                let (i0, j0) = (u.floor(), v.floor());
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

    /// Total deposited weight (RGB).
    #[must_use]
    pub fn total(&self) -> [f64; 3] {
        self.rgb.iter().fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]])
    }

    /// The image normalised to the background: 1 where nothing deflects
    /// and nothing is cut, per channel, row-major.
    #[must_use]
    pub fn normalized(&self) -> Vec<[f32; 3]> {
        let k = if self.per_pixel > 0.0 { 1.0 / self.per_pixel } else { 0.0 };
        self.rgb.iter().map(|p| [(p[0] * k) as f32, (p[1] * k) as f32, (p[2] * k) as f32]).collect()
    }

    /// Mean deflection `(εu, εv)` of the photons that landed in each pixel
    /// (the picking pass: where to paint a filter); `None` for empty pixels.
    #[must_use]
    pub fn mean_deflection(&self) -> Vec<Option<(f64, f64)>> {
        self.eps.iter().map(|e| (e[2] > 0.0).then(|| (e[0] / e[2], e[1] / e[2]))).collect()
    }
}
