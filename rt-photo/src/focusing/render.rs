//! Focusing schlieren (lens-and-grid; Weinstein, "Large-field high-
//! brightness focusing schlieren system", AIAA J. 31(7), 1993): an
//! extended source of bright bands behind the flow, a schlieren lens that
//! images the flow's focus plane on the film and the source grid on a
//! cutoff grid — the source grid's negative, shifted by a fraction of a
//! band — in front of the film.
//!
//! Each film point gathers light from every bright band, through the whole
//! lens aperture; the rays of one point cross the flow along paths that
//! meet only at the focus plane, so a disturbance there moves all of their
//! source images alike (a sharp signal), while one far from it moves the
//! few rays that cross it (blurred away).
//!
//! ## The backward model
//! The camera ([`ThinLens`], focused on the plane in the flow) traces each
//! pixel's rays backward from stratified aperture points toward the
//! pixel's point on the focus plane, through the field, then straight on to
//! the source plane at `Z_S`. A ray lands at `s₁` (across the bands); its
//! undisturbed line, continued straight, at `s₀`. The cutoff grid lies
//! where the lens images the source plane, so a ray crosses it at the
//! image of `s₀` (a thin lens maps every object-side line onto one
//! image-side line, point by conjugate point): the ray carries light
//! `B(s₁) · C(s₀)`, `B` the source's brightness (1 on a band, 0 between)
//! and `C(s) = 1 − B(s − o)` the cutoff's transmission, `o` its shift in
//! the source plane. A pixel's value is the mean over its rays: the
//! fraction of an unobstructed, uniformly bright source's light that
//! reaches it.
//!
//! Undisturbed, a grid of pitch `p` and duty cycle `d` passes `o/p` of the
//! light (for `o ≤ min(d, 1 − d)·p`). A thin disturbance in the focus plane,
//! at distance `z` from the lens, deflecting every ray of a pixel by `ε`
//! (across the bands) moves every `s₁` by `δ = ε·(Z_S − z)`, so
//! `I/I₀ = 1 + δ/o`: the knife edge of a conventional schlieren system of
//! focal length `Z_S − z` whose source image of height `2o` is half cut
//! (`1 + 2 f ε / h`, docs/oracles.md §5).
//!
//! The depth of sharp focus (geometric): the rays of a focus point fill a
//! cone of the aperture's diameter `D` at the lens, so at a distance `Δz`
//! from the focus plane they cross the flow over a disc of diameter
//! `D·|Δz|/z`; a disturbance of width `w` stays sharp while that disc is
//! smaller than it, `|Δz| < w·z/D`: depth of sharp focus `2·w·z/D`.

use alloc::vec::Vec;
use core::fmt;

use glam::DVec3;
use rt_core::sampling::{rng_for, uniform_f64};
use rt_volume::{IndexField, TraceError, TraceParams, TraceResult, trace};

use crate::camera::{Basis, ThinLens};
use crate::math::{atan2, cos, floor, sin, sqrt};

/// The source grid: bright bands of width `duty · pitch`, `pitch` apart,
/// on the source plane. `angle` turns the bands: at 0 they run along the
/// camera's up axis (bands across the image's x, sensitive to horizontal
/// deflection); at 90° along its right axis. Band `k` is centred at
/// `s = (k + c)·pitch`, `s` the coordinate across the bands (`c = 0` for
/// an odd number of bands, ½ for an even one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SourceGrid {
    /// Distance between band centres, scene units (metres), on the source
    /// plane.
    pub pitch: f64,
    /// Bright fraction of a period, in (0, 1).
    pub duty: f64,
    /// Band orientation, radians (see the type's docs).
    pub angle: f64,
    /// How many bands, centred on the optical axis; `None`: unbounded.
    /// `Some(1)` with a narrow band is the light source of a conventional
    /// knife-edge system.
    pub bands: Option<u32>,
}

impl SourceGrid {
    /// The coordinate across the bands of the source-plane point `(u, v)`
    /// (camera right and up).
    fn across(&self, u: f64, v: f64) -> f64 {
        u * cos(self.angle) + v * sin(self.angle)
    }

    /// `s` (across the bands) in period units: band `k` is bright on
    /// `y ∈ [k + (1 − d)/2, k + (1 + d)/2)`, `d` the duty cycle.
    fn y(&self, s: f64) -> f64 {
        let c = match self.bands {
            Some(n) if n % 2 == 0 => 0.5,
            _ => 0.0,
        };
        s / self.pitch - c + 0.5
    }

    /// The periods `[lo, hi)` (in `y`) that hold bands: all, or `n` of
    /// them centred on the axis.
    fn period_range(&self) -> (f64, f64) {
        match self.bands {
            None => (f64::NEG_INFINITY, f64::INFINITY),
            Some(n) => {
                let lo = -f64::from(n / 2);
                (lo, lo + f64::from(n))
            }
        }
    }

    /// Whether `s` (across the bands) lies on a bright band.
    #[cfg(test)]
    fn bright(&self, s: f64) -> bool {
        let y = self.y(s);
        let (lo, hi) = self.period_range();
        let f = y - floor(y);
        y >= lo && y < hi && f >= 0.5 * (1.0 - self.duty) && f < 0.5 * (1.0 + self.duty)
    }

    /// `∫ B(s) ds` over `[s0, s1]`: the bright length there.
    fn bright_length(&self, s0: f64, s1: f64) -> f64 {
        let (lo, hi) = self.period_range();
        let (y0, y1) = (self.y(s0).max(lo), self.y(s1).min(hi));
        if y1 <= y0 {
            return 0.0;
        }
        // Cumulative bright length in periods, from y = 0.
        let (a, d) = (0.5 * (1.0 - self.duty), self.duty);
        let cumulative = |y: f64| {
            let k = floor(y);
            k * d + (y - k - a).clamp(0.0, d)
        };
        (cumulative(y1) - cumulative(y0)) * self.pitch
    }

    /// Calls `f` with each bright interval of the grid moved by `offset`
    /// (`B(s − offset) = 1`) within `[s0, s1]`, in order; `false` (and no
    /// call) if that spans more than [`SourceGrid::MAX_LISTED`] periods.
    fn bands_in(&self, s0: f64, s1: f64, offset: f64, mut f: impl FnMut(f64, f64)) -> bool {
        let (y0, y1) = (self.y(s0 - offset), self.y(s1 - offset));
        if !(y0.is_finite() && y1.is_finite()) || y1 - y0 > Self::MAX_LISTED {
            return false;
        }
        let (lo, hi) = self.period_range();
        let (a, b) = (0.5 * (1.0 - self.duty), 0.5 * (1.0 + self.duty));
        // s of y = 0 (the inverse of `y`).
        let origin = s0 - offset - y0 * self.pitch;
        let mut k = floor(y0).max(lo);
        while k <= y1 && k < hi {
            let x0 = (origin + (k + a) * self.pitch + offset).max(s0);
            let x1 = (origin + (k + b) * self.pitch + offset).min(s1);
            if x1 > x0 {
                f(x0, x1);
            }
            k += 1.0;
        }
        true
    }

    /// Most periods [`SourceGrid::bands_in`] lists; beyond, callers use
    /// the closed-form lengths.
    const MAX_LISTED: f64 = 64.0;

    /// `∫ B(s)·B(s + shift) ds` over `[s0, s1]`: the length lit by the
    /// grid and by the grid moved by `−shift`.
    fn overlap_length(&self, s0: f64, s1: f64, shift: f64) -> f64 {
        let (lo, hi) = self.period_range();
        let e = shift / self.pitch;
        // Both factors hold bands only where `y` and `y + e` lie in the
        // band periods; there they equal the unbounded grid's.
        let y0 = self.y(s0).max(lo).max(lo - e);
        let y1 = self.y(s1).min(hi).min(hi - e);
        if y1.is_nan() || y0.is_nan() || y1 <= y0 {
            return 0.0;
        }
        let (a, b) = (0.5 * (1.0 - self.duty), 0.5 * (1.0 + self.duty));
        let e = e - floor(e);
        let meet = |p: f64, q: f64, r: f64, t: f64| (q.min(t) - p.max(r)).max(0.0);
        // In one period u ∈ [0, 1): B(u) on [a, b); B(u + e) on
        // [a − e, b − e) and [a − e + 1, b − e + 1).
        let within =
            |f: f64| meet(a, b.min(f), a - e, b - e) + meet(a, b.min(f), a - e + 1.0, b - e + 1.0);
        let per_period = within(1.0);
        let cumulative = |y: f64| {
            let k = floor(y);
            k * per_period + within(y - k)
        };
        (cumulative(y1) - cumulative(y0)) * self.pitch
    }
}

/// A focusing-schlieren set-up (see the module docs): `camera` focused on
/// the plane of the flow to image, the source grid at `source_distance`
/// from the lens (behind the flow), the cutoff grid its negative shifted by
/// `cutoff_offset` pitches, `aperture_samples²` rays per pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FocusingSchlieren {
    /// The camera: its lens is the schlieren lens, its focus distance the
    /// plane in the flow imaged sharply.
    pub camera: ThinLens,
    /// Distance from the lens to the source grid, beyond the focus plane.
    pub source_distance: f64,
    /// The source grid.
    pub grid: SourceGrid,
    /// The cutoff grid's shift across the bands, in pitches (`o/p`): the
    /// sensitivity. In `(0, min(duty, 1 − duty)]` the undisturbed image
    /// passes `o/p` of the light; 0 is dark field.
    pub cutoff_offset: f64,
    /// `k`: `k` stratified points per pixel, each seeing the aperture
    /// through `k` stripes along the bands (`k²` traced rays per pixel).
    pub aperture_samples: u32,
    /// The integrator through the field.
    pub params: TraceParams,
}

/// A focusing-schlieren image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct FocusingImages {
    /// Pixels per row.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// Without the flow: the fraction of the light each pixel receives.
    pub reference: Vec<f64>,
    /// Through the flow.
    pub flow: Vec<f64>,
}

impl FocusingImages {
    /// `flow / reference` per pixel (1 = undisturbed), where the reference
    /// receives light (> 1e-12), else 1: the same rays in both, so the
    /// sampling's own noise cancels where nothing moved.
    #[must_use]
    pub fn relative(&self) -> Vec<f64> {
        self.flow
            .iter()
            .zip(&self.reference)
            .map(|(f, r)| if *r > 1e-12 { f / r } else { 1.0 })
            .collect()
    }
}

/// Why a focusing-schlieren render failed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FocusingError {
    /// A camera setting is out of range (which, in words).
    Camera(&'static str),
    /// The source distance, grid, offset or sample count is out of range
    /// (which, in words).
    Setup(&'static str),
    /// A ray could not be traced through the field.
    Trace(TraceError),
}

impl fmt::Display for FocusingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Camera(w) => write!(f, "focusing schlieren camera: {w}"),
            Self::Setup(w) => write!(f, "focusing schlieren set-up: {w}"),
            Self::Trace(e) => write!(f, "focusing schlieren trace: {e}"),
        }
    }
}

impl core::error::Error for FocusingError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Trace(e) => Some(e),
            _ => None,
        }
    }
}

impl FocusingSchlieren {
    /// Checks the set-up.
    ///
    /// # Errors
    /// [`FocusingError::Camera`] or [`FocusingError::Setup`], naming the
    /// first bad setting.
    pub fn validate(&self) -> Result<(), FocusingError> {
        self.camera.validate().map_err(|e| FocusingError::Camera(e.0))?;
        let g = &self.grid;
        let why = if !(self.source_distance.is_finite()
            && self.source_distance > self.camera.focus_distance)
        {
            Some("the source grid must be finite and beyond the focus plane")
        } else if !(g.pitch.is_finite() && g.pitch > 0.0) {
            Some("the grid pitch must be finite and > 0")
        } else if !(g.duty > 0.0 && g.duty < 1.0) {
            Some("the duty cycle must be in (0, 1)")
        } else if !g.angle.is_finite() {
            Some("the band angle must be finite")
        } else if g.bands == Some(0) {
            Some("a grid of bands needs at least one")
        } else if !(self.cutoff_offset >= 0.0 && self.cutoff_offset < 1.0) {
            Some("the cutoff offset must be in [0, 1) pitches")
        } else if !(1..=64).contains(&self.aperture_samples) {
            Some("aperture samples must be 1 to 64 per axis")
        } else {
            None
        };
        why.map_or(Ok(()), |w| Err(FocusingError::Setup(w)))
    }

    /// The light through the cutoff from the source-plane interval
    /// `[s0, s1]` (across the bands) whose rays the flow moves by `shift`
    /// there: `∫ B(s + shift)·C(s) ds` with `C(s) = 1 − B(s − o)`.
    fn transmitted(&self, s0: f64, s1: f64, shift: f64) -> f64 {
        let o = self.cutoff_offset * self.grid.pitch;
        let lit = self.grid.bright_length(s0 + shift, s1 + shift);
        // ∫ B(s + shift)·B(s − o) ds = ∫ B(t)·B(t + shift + o) dt, t = s − o.
        (lit - self.grid.overlap_length(s0 - o, s1 - o, shift + o)).max(0.0)
    }

    /// The light through the cutoff from the aperture strip `a ∈ [p0, p1]`
    /// (across the bands, in aperture radii), whose undisturbed lines meet
    /// the source plane at `s = line + a·slope` and which the flow moves
    /// by `shift` there: `∫ chord(a)·B(s + shift)·C(s) da`, `chord(a) =
    /// 2√(1 − a²)` the disc's extent along the bands. The lit stretches of
    /// `B(s + shift)·C(s)` are listed and each weighted by its exact area
    /// of the disc: a strip's chord changes across it, most near the rim,
    /// and weighting every stretch by the strip's mean chord made the
    /// undisturbed image ripple with the bands' position (±3 %).
    fn strip_light(&self, (p0, p1): (f64, f64), line: f64, slope: f64, shift: f64) -> f64 {
        let (e0, e1) = (line + p0 * slope, line + p1 * slope);
        let (lo, hi) = (e0.min(e1), e0.max(e1));
        let o = self.cutoff_offset * self.grid.pitch;
        let mut area = 0.0;
        let mut lit = |x0: f64, x1: f64| {
            let (a0, a1) = ((x0 - line) / slope, (x1 - line) / slope);
            let (a0, a1) = (a0.min(a1).max(p0), a0.max(a1).min(p1));
            if a1 > a0 {
                area += disc_area_below(a1) - disc_area_below(a0);
            }
        };
        let listed = self.grid.bands_in(lo, hi, -shift, |x0, x1| {
            // C(s) = 1 − B(s − o): the source's stretch less the cutoff's
            // bands over it.
            let mut at = x0;
            self.grid.bands_in(x0, x1, o, |c0, c1| {
                if c0 > at {
                    lit(at, c0);
                }
                at = at.max(c1);
            });
            if x1 > at {
                lit(at, x1);
            }
        });
        if listed {
            area
        } else {
            // Bands far finer than the strip: the chord's change averages
            // out over them.
            (disc_area_below(p1) - disc_area_below(p0)) / (hi - lo)
                * self.transmitted(lo, hi, shift)
        }
    }

    /// The smallest deflection (radians) the set-up resolves: the one
    /// that changes a pixel's relative intensity by 1/1000 (`δ/o`, with
    /// `δ = ε·(Z_S − Z_F)` from the focus plane). Octree skipping spends
    /// it as each ray's budget ([`FocusingSchlieren::render_medium`] of a grid).
    #[must_use]
    pub fn resolvable_deflection(&self) -> f64 {
        let lever = (self.source_distance - self.camera.focus_distance).max(f64::MIN_POSITIVE);
        let o = self.cutoff_offset.max(0.01) * self.grid.pitch;
        (o / lever / 1000.0).min(1e-3)
    }

    /// Renders the reference and flow images through `field` (any
    /// [`IndexField`], any integrator); seeded sample positions (the same
    /// seed, the same images, at any thread count with feature
    /// `parallel`).
    ///
    /// # Errors
    /// A bad set-up, or a failing trace.
    pub fn render<F: IndexField + Sync>(
        &self,
        field: &F,
        seed: u64,
    ) -> Result<FocusingImages, FocusingError> {
        self.render_with(&|o, d| trace(field, o, d, &self.params), seed)
    }

    /// [`FocusingSchlieren::render`] with any tracer `(origin, direction)
    /// → result`.
    ///
    /// # Errors
    /// As [`FocusingSchlieren::render`].
    pub fn render_with(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync),
        seed: u64,
    ) -> Result<FocusingImages, FocusingError> {
        self.validate()?;
        let (w, h) = (self.camera.width, self.camera.height);
        let frame = self.camera.basis();
        let rows = crate::rows::rows(h, |j| self.row(tracer, &frame, j, seed));
        let mut out = FocusingImages {
            width: w,
            height: h,
            reference: Vec::with_capacity(w * h),
            flow: Vec::with_capacity(w * h),
        };
        for r in rows {
            for [reference, flow] in r? {
                out.reference.push(reference);
                out.flow.push(flow);
            }
        }
        Ok(out)
    }

    /// Where the line from `origin` along `d` meets the source plane,
    /// across the bands.
    fn on_source(&self, f: &Basis, origin: DVec3, d: DVec3) -> f64 {
        let plane = self.camera.position + self.source_distance * f.axis;
        let t = (plane - origin).dot(f.axis) / d.dot(f.axis);
        let p = origin + t * d - plane;
        self.grid.across(p.dot(f.right), p.dot(f.up))
    }

    /// One row's `[reference, flow]` pixels.
    ///
    /// Each pixel is sampled at `k` stratified points (a jittered Latin
    /// square of `k × k` cells), and from each the aperture is cut in `k`
    /// stripes along the bands, one traced ray per stripe from a jittered
    /// point of it. The light a ray carries depends on where it crosses
    /// the bands, so it is integrated exactly across them: the aperture,
    /// in 32 strips, maps onto intervals `[s₀⁻, s₀⁺]` of the source plane
    /// (the undisturbed lines of the point), which the flow moves by a
    /// shift interpolated between the traced rays' `s₁ − s₀`; a strip
    /// carries the disc's area over the stretches where `B(s + shift)·C(s)`
    /// is lit ([`FocusingSchlieren::strip_light`]). Without the flow, or
    /// with a disturbance in the
    /// focus plane (every ray of a point moved alike), this is exact
    /// whatever the bands' pitch; elsewhere it holds while the shift is
    /// close to linear between neighbouring rays. No grain from bands
    /// finer than the samples.
    fn row(
        &self,
        tracer: &impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError>,
        f: &Basis,
        j: usize,
        seed: u64,
    ) -> Result<Vec<[f64; 2]>, FocusingError> {
        let cam = &self.camera;
        let k = self.aperture_samples;
        let kf = f64::from(k);
        let scramble = coprime_near(k, 0.618_033_988_75 * kf);
        let (across, along) = (
            (cos(self.grid.angle), sin(self.grid.angle)),
            (-sin(self.grid.angle), cos(self.grid.angle)),
        );
        // ds₀/da: the undisturbed line through lens point a (aperture
        // radii, across) and a fixed focus point meets the source plane
        // at s₀ = a·R·(1 − Z_S/Z_F) + const.
        let slope = 0.5 * cam.aperture() * (1.0 - self.source_distance / cam.focus_distance);
        let width = 2.0 / kf;
        let parts = 32u32.div_ceil(k);
        let piece = width / f64::from(parts);
        let mut out = Vec::with_capacity(cam.width);
        let mut rays: Vec<(f64, f64)> = Vec::with_capacity(k as usize);
        for i in 0..cam.width {
            let mut rng = rng_for(seed, (j * cam.width + i) as u64);
            let (mut reference, mut flow) = (0.0, 0.0);
            for q in 0..k {
                let row = (u64::from(q) * u64::from(scramble) % u64::from(k)) as u32;
                let px = i as f64 + (f64::from(q) + uniform_f64(&mut rng)) / kf;
                let py = j as f64 + (f64::from(row) + uniform_f64(&mut rng)) / kf;
                // One ray per stripe, from a jittered point of it: where
                // it crosses the stripe (`a`, across) and how far the flow
                // moves its source point.
                rays.clear();
                let mut line = 0.0;
                for t in 0..k {
                    let a = (f64::from(t) + uniform_f64(&mut rng)) * width - 1.0;
                    let b = (2.0 * uniform_f64(&mut rng) - 1.0) * sqrt((1.0 - a * a).max(0.0));
                    let lens = (a * across.0 + b * along.0, a * across.1 + b * along.1);
                    let (o, d) = cam.ray_from(px, py, lens);
                    let s0 = self.on_source(f, o, d);
                    // The undisturbed lines of this point: s₀ = line + a·slope.
                    line = s0 - a * slope;
                    let r = tracer(o, d).map_err(FocusingError::Trace)?;
                    rays.push((a, self.on_source(f, r.position, r.direction) - s0));
                }
                // The pieces of the aperture, each with its interval on the
                // source plane, its area, and the shift interpolated
                // between the rays around it (constant beyond the outer
                // ones): a shift that changes across the aperture is
                // followed piece by piece, not held over a stripe.
                let mut next = 0;
                for m in 0..k * parts {
                    let (p0, p1) = (f64::from(m) * piece - 1.0, f64::from(m + 1) * piece - 1.0);
                    let mid = 0.5 * (p0 + p1);
                    while next < rays.len() && rays[next].0 < mid {
                        next += 1;
                    }
                    let shift = match (next.checked_sub(1).map(|i| rays[i]), rays.get(next)) {
                        (Some((a0, d0)), Some(&(a1, d1))) => {
                            d0 + (d1 - d0) * (mid - a0) / (a1 - a0)
                        }
                        (Some((_, d)), None) | (None, Some(&(_, d))) => d,
                        (None, None) => 0.0,
                    };
                    reference += self.strip_light((p0, p1), line, slope, 0.0);
                    flow += self.strip_light((p0, p1), line, slope, shift);
                }
            }
            // Each of the k points saw the whole aperture, area π.
            let total = kf * core::f64::consts::PI;
            out.push([reference / total, flow / total]);
        }
        Ok(out)
    }
}

/// The area of the unit disc left of `a` (`∫ 2√(1 − t²) dt` from −1).
fn disc_area_below(a: f64) -> f64 {
    let a = a.clamp(-1.0, 1.0);
    let c = sqrt((1.0 - a * a).max(0.0));
    a * c + atan2(a, c) + core::f64::consts::FRAC_PI_2
}

/// The integer nearest `target` (in `[1, n)`) that is coprime to `n`: `s ↦
/// s·m mod n` is then a permutation of `0..n`.
fn coprime_near(n: u32, target: f64) -> u32 {
    let gcd = |mut a: u32, mut b: u32| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    let mut m = (target as u32).clamp(1, n.max(2) - 1);
    while gcd(m, n) != 1 {
        m += 1;
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form lengths against a fine Riemann sum of the bands,
    /// for unbounded and finite grids, odd and even band counts, shifts
    /// of any size and intervals across many periods or inside one.
    #[test]
    fn band_integrals_are_the_sums_of_the_bands() {
        let riemann = |f: &dyn Fn(f64) -> f64, s0: f64, s1: f64| {
            let m = 200_000;
            let h = (s1 - s0) / f64::from(m);
            (0..m).map(|i| f(s0 + (f64::from(i) + 0.5) * h)).sum::<f64>() * h
        };
        let b = |g: &SourceGrid, s: f64| if g.bright(s) { 1.0 } else { 0.0 };
        for bands in [None, Some(1), Some(2), Some(5)] {
            for duty in [0.2, 0.5, 0.8] {
                let g = SourceGrid { pitch: 0.7, duty, angle: 0.0, bands };
                for (s0, s1) in [(-3.1, 2.9), (0.05, 0.31), (-0.4, -0.1), (1.2, 9.0)] {
                    let want = riemann(&|s| b(&g, s), s0, s1);
                    let got = g.bright_length(s0, s1);
                    assert!(
                        (got - want).abs() < 1e-4,
                        "{bands:?} {duty} [{s0}, {s1}]: {got} vs {want}"
                    );
                    for shift in [0.0, 0.13, -0.52, 0.7, 2.35] {
                        let want = riemann(&|s| b(&g, s) * b(&g, s + shift), s0, s1);
                        let got = g.overlap_length(s0, s1, shift);
                        assert!(
                            (got - want).abs() < 1e-4,
                            "{bands:?} {duty} [{s0}, {s1}] shift {shift}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }

    /// A strip of the aperture carries `∫ 2√(1 − a²)·B(s + shift)·C(s) da`
    /// exactly (against a fine Riemann sum), for strips at the disc's
    /// centre and at its rim, where the chord changes fastest: weighting
    /// the strip by its mean chord was off by up to a few percent of the
    /// strip's light there.
    #[test]
    fn a_strip_carries_its_exact_share_of_the_disc() {
        let cam = ThinLens {
            position: DVec3::ZERO,
            direction: DVec3::Z,
            up: DVec3::Y,
            focal_length: 0.1,
            f_number: 2.0,
            focus_distance: 1.0,
            pixel_pitch: 1e-5,
            width: 1,
            height: 1,
        };
        for (bands, duty, offset) in [(None, 0.5, 0.25), (Some(3), 0.3, 0.1), (None, 0.7, 0.2)] {
            let fs = FocusingSchlieren {
                camera: cam,
                source_distance: 2.0,
                grid: SourceGrid { pitch: 3e-3, duty, angle: 0.0, bands },
                cutoff_offset: offset,
                aperture_samples: 1,
                params: TraceParams::accurate(),
            };
            let lit = |s: f64, shift: f64| {
                let b = |x: f64| if fs.grid.bright(x) { 1.0 } else { 0.0 };
                b(s + shift) * (1.0 - b(s - offset * fs.grid.pitch))
            };
            for (p0, p1) in [(-1.0, -0.9375), (-0.03, 0.05), (0.94, 1.0), (-1.0, 1.0)] {
                for (line, slope, shift) in [(0.0011, -0.025, 0.0), (-0.0007, 0.025, 4.1e-4)] {
                    let m = 400_000;
                    let h = (p1 - p0) / f64::from(m);
                    let want: f64 = (0..m)
                        .map(|i| {
                            let a = p0 + (f64::from(i) + 0.5) * h;
                            2.0 * sqrt((1.0 - a * a).max(0.0)) * lit(line + a * slope, shift)
                        })
                        .sum::<f64>()
                        * h;
                    let got = fs.strip_light((p0, p1), line, slope, shift);
                    assert!(
                        (got - want).abs() < 2e-5 * (p1 - p0).max(0.1),
                        "{bands:?} [{p0}, {p1}] line {line} shift {shift}: {got} vs {want}"
                    );
                }
            }
        }
    }
}
