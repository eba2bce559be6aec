//! The optical bench: a collimated beam through a field onto a film.

use alloc::vec::Vec;
use core::fmt;

use glam::DVec3;
use rt_core::ColorMap;
use rt_core::sampling::{rng_for, uniform};
use rt_volume::{
    BeamMask, BeamWindow, GridField, IndexField, TraceError, TraceParams, TraceResult, trace,
    trace_beam, trace_visiting,
};

use super::cutoff::Prepared;
use super::{Cutoff, CutoffError, Film, Photon};
use crate::math;

/// What the film records.
#[derive(Clone, Debug, PartialEq)]
pub enum Mode {
    /// Schlieren or shadowgraph: the cutoff's transmission.
    Schlieren(Cutoff),
    /// Interferometry: `I = (1 + cos(φ + 2π x/Λ))/2` with
    /// `φ = (2π/λ)·∫ (n − n_ref) ds`.
    Interferometry {
        /// Wavelength (length units of the scene).
        lambda: f64,
        /// Reference index.
        n_ref: f64,
        /// Fringe spacing `Λ` on the film (`None`: infinite fringe).
        fringe_spacing: Option<f64>,
    },
}

/// How photons are weighted by the cutoff.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Weighting {
    /// Each photon deposits its transmission.
    Weight,
    /// Russian roulette: each photon passes with probability equal to its
    /// (grey) transmission and deposits 1, or is absorbed; same expectation.
    Roulette,
}

/// How the photons of a pass become an image.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Reconstruction {
    /// Each photon lands alone and is spread by the film's
    /// [`Filter`](crate::Filter). The photons of a pixel are stratified, each pass
    /// continuing a low-discrepancy sequence, so noise falls faster than
    /// `1/√N`; but a pixel still counts photons whose landing points jitter
    /// across its edges, and that count is noisy.
    #[default]
    Photons,
    /// The photons of a pass form a lattice over the beam, `strata` points
    /// per pixel along each axis, the whole lattice shifted per pass along
    /// the R2 sequence from an offset drawn from the seed. Each lattice
    /// cell carries its light onto the part of the film its corners' landing
    /// points enclose (two triangles), shared among the pixels it overlaps
    /// by exact area: the sheet estimator of Abel, Hahn & Kaehler (2012).
    /// An undisturbed beam gives exactly the background, and where light
    /// bends the error is that of approximating the optical map by flat
    /// triangles, `O(1/strata²)` for a smooth field, not noise. The film's
    /// filter is not used; weighting must be [`Weighting::Weight`].
    Sheet,
}

/// Why a render could not run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BenchError {
    /// The beam's `center`, `direction` or `u` has a NaN or infinite
    /// component.
    BeamNotFinite,
    /// `direction` and `u` are not unit vectors at right angles (to 1e-9).
    NotOrthonormal,
    /// The beam's `width` or `height` is not finite and positive.
    BeamSize {
        /// The beam's width.
        width: f64,
        /// The beam's height.
        height: f64,
    },
    /// `film_distance` is NaN or infinite.
    FilmDistance(f64),
    /// `strata` is outside `1..=64`.
    Strata(u32),
    /// The schlieren cutoff is invalid ([`Cutoff::validate`]).
    Cutoff(CutoffError),
    /// The interferometer's wavelength is not finite and positive.
    Wavelength(f64),
    /// The interferometer's reference index is not finite and positive.
    ReferenceIndex(f64),
    /// The interferometer's fringe spacing is not finite and positive.
    FringeSpacing(f64),
    /// [`Reconstruction::Sheet`] with [`Weighting::Roulette`]: a sheet
    /// carries each cell's mean transmission, never a random 0 or 1.
    SheetRoulette,
    /// Tracing a photon failed (or building the beam mask of
    /// [`SchlierenBench::render_medium`] on a grid).
    Trace(TraceError),
}

impl fmt::Display for BenchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BeamNotFinite => write!(f, "beam centre, direction or u is not finite"),
            Self::NotOrthonormal => {
                write!(f, "beam direction and u must be orthonormal (unit length, at right angles)")
            }
            Self::BeamSize { width, height } => write!(
                f,
                "beam width and height must be finite and positive (got {width} × {height})"
            ),
            Self::FilmDistance(l) => write!(f, "film distance must be finite (got {l})"),
            Self::Strata(k) => {
                write!(f, "strata must be in 1..=64 (photons per pixel = strata²), got {k}")
            }
            Self::Cutoff(e) => write!(f, "bad cutoff: {e}"),
            Self::Wavelength(l) => write!(f, "wavelength must be finite and positive (got {l})"),
            Self::ReferenceIndex(n) => {
                write!(f, "reference index must be finite and positive (got {n})")
            }
            Self::FringeSpacing(s) => {
                write!(f, "fringe spacing must be finite and positive (got {s})")
            }
            Self::SheetRoulette => {
                write!(
                    f,
                    "sheet reconstruction weights photons (Russian roulette is for splatting)"
                )
            }
            Self::Trace(e) => write!(f, "trace: {e}"),
        }
    }
}

impl core::error::Error for BenchError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Cutoff(e) => Some(e),
            Self::Trace(e) => Some(e),
            _ => None,
        }
    }
}

impl From<CutoffError> for BenchError {
    fn from(e: CutoffError) -> Self {
        Self::Cutoff(e)
    }
}

impl From<TraceError> for BenchError {
    fn from(e: TraceError) -> Self {
        Self::Trace(e)
    }
}

/// A collimated beam, the optics behind the test section, and the film.
#[derive(Clone, Debug, PartialEq)]
pub struct SchlierenBench {
    /// Centre of the beam's emission plane (upstream of the field).
    pub center: DVec3,
    /// Beam direction (unit).
    pub direction: DVec3,
    /// Film/image axis u (unit, ⟂ direction); v = direction × u.
    pub u: DVec3,
    /// Beam (and film) width along u.
    pub width: f64,
    /// Beam height along v.
    pub height: f64,
    /// Distance along the beam from `center` to the plane the optics
    /// image: the object's mid-plane, as a real schlieren or shadowgraph
    /// set-up focuses on it.
    pub image_plane: f64,
    /// Distance from the image plane to the film along the beam
    /// (shadowgraph; 0 images the mid-plane, negative values a plane
    /// upstream of it). Each photon lands where its exit ray crosses that
    /// plane.
    pub film_distance: f64,
    /// What is recorded.
    pub mode: Mode,
    /// Cutoff weighting.
    pub weighting: Weighting,
    /// How a pass's photons become the image.
    pub reconstruction: Reconstruction,
    /// Photons per pixel per pass: `k × k`, placed by a low-discrepancy
    /// sequence that each pass continues.
    pub strata: u32,
    /// Integrator settings.
    pub params: TraceParams,
}

/// A tracer of many rays at once: `(origin, direction)` pairs in, their
/// traces out in the same order ([`SchlierenBench::render_batched`]).
pub type BatchTracer<'a> =
    dyn FnMut(&[(DVec3, DVec3)]) -> Result<Vec<TraceResult>, TraceError> + 'a;

/// Photons a sheet pass holds at once (56 bytes each: 117 MB); a larger
/// lattice is traced and shared out in bands of rows.
const SHEET_BAND_PHOTONS: usize = 1 << 21;

/// Rows `0..n` of photons traced by `row` (in parallel with feature
/// `parallel`), in order; the first error if any row fails.
fn rows(
    n: usize,
    row: impl Fn(usize) -> Result<Vec<Photon>, BenchError> + Sync,
) -> Result<Vec<Vec<Photon>>, BenchError> {
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        (0..n).into_par_iter().map(&row).collect()
    }
    #[cfg(not(feature = "parallel"))]
    (0..n).map(row).collect()
}

/// The `n`-th point of the R2 sequence (Roberts 2018) in `[0, 1)²`,
/// shifted by `shift` modulo 1.
#[inline]
fn r2(n: u64, shift: (f64, f64)) -> (f64, f64) {
    // 1/φ₂ and 1/φ₂², φ₂ the plastic number (the real root of x³ = x + 1).
    const A1: f64 = 0.754_877_666_246_692_8;
    const A2: f64 = 0.569_840_290_998_053_3;
    // n·α mod 1 in two steps, exact enough for n < 2⁵³.
    let frac = |x: f64| x - math::floor(x);
    let n = n as f64;
    (frac(shift.0 + frac(n * A1)), frac(shift.1 + frac(n * A2)))
}

impl SchlierenBench {
    fn v(&self) -> DVec3 {
        self.direction.cross(self.u)
    }

    /// Checks the parameters. (A [`Film`] is never empty: `Film::new`
    /// refuses zero sizes.)
    fn validate(&self) -> Result<(), BenchError> {
        let finite3 = |v: DVec3| v.is_finite();
        if !(finite3(self.center) && finite3(self.direction) && finite3(self.u)) {
            return Err(BenchError::BeamNotFinite);
        }
        if (self.direction.length() - 1.0).abs() > 1e-9
            || (self.u.length() - 1.0).abs() > 1e-9
            || self.u.dot(self.direction).abs() > 1e-9
        {
            return Err(BenchError::NotOrthonormal);
        }
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !(positive(self.width) && positive(self.height)) {
            return Err(BenchError::BeamSize { width: self.width, height: self.height });
        }
        if !(self.film_distance.is_finite() && self.image_plane.is_finite()) {
            return Err(BenchError::FilmDistance(self.film_distance + self.image_plane));
        }
        if !(1..=64).contains(&self.strata) {
            return Err(BenchError::Strata(self.strata));
        }
        if self.reconstruction == Reconstruction::Sheet && self.weighting == Weighting::Roulette {
            return Err(BenchError::SheetRoulette);
        }
        match &self.mode {
            Mode::Schlieren(c) => c.validate().map_err(BenchError::Cutoff),
            Mode::Interferometry { lambda, n_ref, fringe_spacing } => {
                if !positive(*lambda) {
                    Err(BenchError::Wavelength(*lambda))
                } else if !positive(*n_ref) {
                    Err(BenchError::ReferenceIndex(*n_ref))
                } else if let Some(s) = fringe_spacing.filter(|&s| !positive(s)) {
                    Err(BenchError::FringeSpacing(s))
                } else {
                    Ok(())
                }
            }
        }
    }

    /// Traces the photon emitted at film coordinates `(px, py)` (pixels,
    /// continuous) of a `w × h` film, and lands it on the film plane.
    #[allow(clippy::too_many_arguments)]
    fn photon(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<(TraceResult, [f32; 3]), TraceError> + Sync),
        cutoff: Option<&Prepared<'_>>,
        (w, h): (usize, usize),
        px: f64,
        py: f64,
        rng: &mut rt_core::sampling::Rng,
    ) -> Result<Photon, BenchError> {
        let v = self.v();
        let a = (px / w as f64 - 0.5) * self.width;
        let b = (0.5 - py / h as f64) * self.height;
        let o = self.center + a * self.u + b * v;
        let (r, colour) = tracer(o, self.direction).map_err(BenchError::Trace)?;
        let e = r.direction;
        let (eu, ev) = (e.dot(self.u), e.dot(v));
        // The exit ray carried (forward or back) to the film plane.
        let along = e.dot(self.direction).max(1e-12);
        let film_plane = self.image_plane + self.film_distance;
        let to_film = film_plane - (r.position - self.center).dot(self.direction);
        let p = r.position + (to_film / along) * e;
        let fa = (p - self.center).dot(self.u);
        let fb = (p - self.center).dot(v);
        let fx = (fa / self.width + 0.5) * w as f64;
        let fy = (0.5 - fb / self.height) * h as f64;
        let mut phase = 0.0;
        let weight = match &self.mode {
            Mode::Schlieren(_) => {
                let t = cutoff.map_or([1.0; 3], |p| p.transmit(eu, ev));
                match self.weighting {
                    Weighting::Weight => t,
                    Weighting::Roulette => {
                        let g = (t[0] + t[1] + t[2]) / 3.0;
                        if uniform(rng) < g { [1.0; 3] } else { [0.0; 3] }
                    }
                }
            }
            Mode::Interferometry { lambda, n_ref, fringe_spacing } => {
                let straight = (r.position - o).dot(self.direction);
                let phi = core::f64::consts::TAU / lambda * (r.optical_path - n_ref * straight);
                phase = phi;
                let carrier = fringe_spacing.map_or(0.0, |s| core::f64::consts::TAU * fa / s);
                [(0.5 * (1.0 + math::cos(phi + carrier))) as f32; 3]
            }
        };
        let weight = [weight[0] * colour[0], weight[1] * colour[1], weight[2] * colour[2]];
        Ok(Photon::new(fx, fy, weight, (eu, ev)).with_phase(phase))
    }

    /// The cutoff, prepared, for schlieren.
    fn cutoff(&self) -> Option<Prepared<'_>> {
        match &self.mode {
            Mode::Schlieren(c) => Some(c.prepare()),
            Mode::Interferometry { .. } => None,
        }
    }

    /// Traces the photons of film row `row` for pass `pass`.
    fn row(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<(TraceResult, [f32; 3]), TraceError> + Sync),
        film: &Film,
        row: usize,
        pass: u64,
        seed: u64,
    ) -> Result<Vec<Photon>, BenchError> {
        let (w, h) = (film.width(), film.height());
        let k = self.strata as usize;
        let mut rng = rng_for(seed ^ pass.wrapping_mul(0x9e37_79b9_7f4a_7c15), row as u64);
        // Each pixel is split into `k × k` strata, one photon in each per
        // pass; within a stratum, the passes place their photons along a
        // low-discrepancy R2 sequence (Roberts 2018: `nα mod 1`, α from the
        // plastic number) shifted by a random offset per stratum
        // (Cranley–Patterson). Pass 0 is plain jittered stratification; the
        // later passes fill the gaps it left, so noise falls faster than
        // `1/√passes`. The offsets do not depend on the pass.
        let mut offsets = rng_for(seed ^ 0x6a09_e667_f3bc_c909, row as u64);
        let mut out = Vec::with_capacity(w * k * k);
        let cutoff = self.cutoff();
        for i in 0..w {
            for s in 0..k * k {
                let shift = (f64::from(uniform(&mut offsets)), f64::from(uniform(&mut offsets)));
                let (rx, ry) = r2(pass, shift);
                let (jx, jy) = (((s % k) as f64 + rx) / k as f64, ((s / k) as f64 + ry) / k as f64);
                let (px, py) = (i as f64 + jx, row as f64 + jy);
                out.push(self.photon(tracer, cutoff.as_ref(), (w, h), px, py, &mut rng)?);
            }
        }
        Ok(out)
    }

    /// Adds one pass of `strata²` photons per pixel to `film` (progressive:
    /// call again with the next `pass` to refine). Photons of each row use
    /// their own random stream from `(seed, pass, row)`, and are splatted in
    /// row order, so the image is bit-identical at any thread count.
    ///
    /// # Errors
    /// [`BenchError`] for bad parameters or a failing trace; the film is
    /// unchanged then.
    pub fn render<F: IndexField + Sync>(
        &self,
        field: &F,
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        self.render_with(&|o, d| trace(field, o, d, &self.params), film, pass, seed)
    }

    /// The per-ray tolerance for octree skipping (see
    /// [`rt_volume::trace_skipping`]: the deflection skipping may change
    /// along a whole photon's path) that this bench cannot see: the
    /// smallest deflection it resolves, taken as 1/1000 of what changes
    /// the cutoff's transmission fully ([`Cutoff::range`]; for a knife
    /// edge `h/(f·1000)`: a thousand grey levels). Without a cutoff the
    /// film position resolves it: 1/1000 of a pixel after the film
    /// distance `L` (any skip is invisible at `L = 0`; capped at 1e-3
    /// rad). Interferometry resolves optical path: 1/1000 of a wavelength
    /// over the field's extent.
    #[must_use]
    pub fn skip_tolerance(&self, field: &GridField, film: &Film) -> f64 {
        let resolvable = match &self.mode {
            Mode::Schlieren(c) => c.range().unwrap_or_else(|| {
                let pixel = (self.width / film.width().max(1) as f64)
                    .min(self.height / film.height().max(1) as f64);
                pixel / self.film_distance.abs()
            }),
            Mode::Interferometry { lambda, .. } => {
                let b = field.bounds();
                lambda / (b.max - b.min).length()
            }
        } / 1000.0;
        resolvable.min(1e-3)
    }

    /// [`SchlierenBench::render`] for a gridded field on the fast path
    /// ([`SchlierenBench::render_medium`] of a grid): the grid's octree lets photons
    /// cross the field's smooth regions in straight steps, with the
    /// tolerance the bench cannot resolve ([`SchlierenBench::skip_tolerance`]);
    /// photons whose line meets no node too rough for it (a [`BeamMask`]
    /// with one cell per film pixel) go straight without walking the tree.
    /// The grid's octree bounds its own interpolant (a
    /// [`rt_volume::GridMedium`] builds them together).
    pub(crate) fn render_grid_with(
        &self,
        grid: &rt_volume::GridMedium,
        params: &TraceParams,
        film: &mut Film,
        pass: u64,
        seed: u64,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<(), BenchError> {
        self.validate()?;
        let (field, tree) = (grid.field(), grid.tree());
        let window = BeamWindow {
            center: self.center,
            direction: self.direction,
            u: self.u,
            size: [self.width, self.height],
            cells: [film.width(), film.height()],
        };
        let mask = BeamMask::build(field, tree, &window, self.skip_tolerance(field, film))
            .map_err(BenchError::Trace)?;
        let trace = crate::medium::until(stop, |o, d| trace_beam(field, tree, &mask, o, d, params));
        self.render_with(&trace, film, pass, seed)
    }

    /// [`SchlierenBench::render`] with any tracer `(origin, direction) → result`,
    /// e.g. octree skipping over a gridded field:
    /// `|o, d| rt_volume::trace_skipping(&grid, &tree, o, d, &params, tol)`.
    ///
    /// # Errors
    /// As [`SchlierenBench::render`].
    pub fn render_with(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync),
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        self.render_colored_with(&|o, d| tracer(o, d).map(|r| (r, [1.0; 3])), film, pass, seed)
    }

    /// [`SchlierenBench::render_with`] with the pass's photons traced all at
    /// once by `batch` (a GPU, say): it is handed every `(origin,
    /// direction)` the pass emits, in no set order, and returns their
    /// traces in the same order. The photons are then cut, carried to the
    /// film and splatted exactly as `render_with` does with a tracer giving
    /// those traces, so the image is the one it would make. (The pass is
    /// walked twice on the host: once to list its photons, once to splat
    /// them.)
    ///
    /// # Errors
    /// As [`SchlierenBench::render`]; [`BenchError::Trace`] with `batch`'s
    /// error, or [`TraceError::InvalidRay`] where it returns fewer traces
    /// than photons. The film is unchanged then.
    #[cfg(feature = "std")]
    pub fn render_batched(
        &self,
        batch: &mut BatchTracer<'_>,
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        use std::{collections::HashMap, sync::Mutex};
        let key = |o: DVec3, d: DVec3| [o.x, o.y, o.z, d.x, d.y, d.z].map(f64::to_bits);
        // The pass's photons: asked of a tracer that lists them and goes
        // straight, on a scratch film.
        let asked = Mutex::new(Vec::new());
        let list = |o: DVec3, d: DVec3| {
            asked.lock().map_err(|_| TraceError::InvalidRay)?.push((o, d));
            Ok((
                TraceResult {
                    position: o,
                    direction: d,
                    optical_path: 0.0,
                    exit: rt_volume::Exit::Missed,
                    stats: Default::default(),
                },
                [1.0; 3],
            ))
        };
        self.render_colored_with(&list, &mut film.clone(), pass, seed)?;
        let mut asked =
            asked.into_inner().map_err(|_| BenchError::Trace(TraceError::InvalidRay))?;
        asked.sort_unstable_by_key(|&(o, d)| key(o, d));
        asked.dedup_by_key(|&mut (o, d)| key(o, d));
        let traced = batch(&asked).map_err(BenchError::Trace)?;
        if traced.len() != asked.len() {
            return Err(BenchError::Trace(TraceError::InvalidRay));
        }
        let found: HashMap<_, _> =
            asked.iter().zip(traced).map(|(&(o, d), r)| (key(o, d), r)).collect();
        let look_up = |o: DVec3, d: DVec3| {
            found.get(&key(o, d)).map(|&r| (r, [1.0; 3])).ok_or(TraceError::InvalidRay)
        };
        self.render_colored_with(&look_up, film, pass, seed)
    }

    /// Multifield: each photon also carries the colour `map(s̄)` of a
    /// second, scalar field, `s̄` its mean over the steps of the photon's
    /// bent path inside the volume, multiplied into its cutoff weight.
    /// Photons that miss the volume carry white.
    ///
    /// # Errors
    /// As [`SchlierenBench::render`].
    pub fn render_colored<F: IndexField + Sync>(
        &self,
        field: &F,
        scalar: &(impl Fn(DVec3) -> f64 + Sync),
        map: &ColorMap<'_>,
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        let tracer = |o: DVec3, d: DVec3| {
            mean_colour(scalar, map, |visit| trace_visiting(field, o, d, &self.params, visit))
        };
        self.render_colored_with(&tracer, film, pass, seed)
    }

    pub(crate) fn render_colored_with(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<(TraceResult, [f32; 3]), TraceError> + Sync),
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        self.validate()?;
        if self.reconstruction == Reconstruction::Sheet {
            return self.sheet(tracer, film, pass, seed);
        }
        let traced = rows(film.height(), |r| self.row(tracer, film, r, pass, seed))?;
        film.emitted += traced.iter().map(|r| r.len() as u64).sum::<u64>();
        film.splat_all(traced.iter().flatten());
        film.per_pixel += f64::from(self.strata * self.strata);
        Ok(())
    }

    /// One pass of [`Reconstruction::Sheet`]: the lattice traced row by row
    /// (in parallel), then each cell's two triangles shared out over the
    /// film. The lattice has `strata` points per pixel and one more on each
    /// side, so its cells cover the beam whatever the pass's shift; a cell
    /// straddling the beam's edge carries only the light of its part inside.
    fn sheet(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<(TraceResult, [f32; 3]), TraceError> + Sync),
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        self.sheet_in_bands(tracer, film, pass, seed, SHEET_BAND_PHOTONS)
    }

    /// [`SchlierenBench::sheet`] holding about `band_photons` photons at once.
    fn sheet_in_bands(
        &self,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<(TraceResult, [f32; 3]), TraceError> + Sync),
        film: &mut Film,
        pass: u64,
        seed: u64,
        band_photons: usize,
    ) -> Result<(), BenchError> {
        let (w, h) = (film.width(), film.height());
        let k = self.strata as usize;
        let kf = k as f64;
        let (nx, ny) = (w * k + 2, h * k + 2);
        let mut base = rng_for(seed ^ 0x6a09_e667_f3bc_c909, u64::MAX);
        let shift = (f64::from(uniform(&mut base)), f64::from(uniform(&mut base)));
        let (sx, sy) = r2(pass, shift);
        // Lattice point `(a, b)` at film coordinates `((a − 1 + sx)/k, …)`.
        let at = |a: usize, s: f64| (a as f64 - 1.0 + s) / kf;
        let cutoff = self.cutoff();
        let trace_row = |b: usize| -> Result<Vec<Photon>, BenchError> {
            // Weighting is `Weight` (validated): the generator is unused.
            let mut rng = rng_for(seed, b as u64);
            (0..nx)
                .map(|a| {
                    self.photon(tracer, cutoff.as_ref(), (w, h), at(a, sx), at(b, sy), &mut rng)
                })
                .collect()
        };
        // Light per unit emission area: a full cell (1/k² pixel²) carries
        // one photon's worth, so the background is k² per pixel per pass.
        let density = kf * kf;
        // The lattice in bands of rows, each band's cells shared out before
        // the next is traced (with the row they share): memory stays at a
        // band's photons, not a film's worth; cells reach each pixel in
        // the same order, so the image is the same, bit for bit.
        let band = (band_photons / nx).max(2);
        let mut carried: Option<Vec<Photon>> = None;
        let mut b0 = 0;
        while b0 < ny {
            let b1 = (b0 + band).min(ny);
            let traced = rows(b1 - b0, |i| trace_row(b0 + i))?;
            film.emitted += ((b1 - b0) * nx) as u64;
            // Lost: photons emitted inside the beam that landed off the
            // film (the lattice's outer ring starts outside it).
            film.lost += traced
                .iter()
                .zip(b0..)
                .flat_map(|(row, b)| row.iter().enumerate().map(move |(a, p)| (a, b, p)))
                .filter(|&(a, b, p)| {
                    let (x, y) = (at(a, sx), at(b, sy));
                    let emitted = x >= 0.0 && y >= 0.0 && x < w as f64 && y < h as f64;
                    emitted && !(p.x >= 0.0 && p.y >= 0.0 && p.x < w as f64 && p.y < h as f64)
                })
                .count() as u64;
            // Row `first` of the lattice is local row 0.
            let first = if carried.is_some() { b0 - 1 } else { b0 };
            let mut lattice: Vec<Vec<Photon>> = carried.take().into_iter().chain(traced).collect();
            film.deposit_sheet(&lattice, |a, b| (at(a, sx), at(first + b, sy)), density);
            carried = lattice.pop();
            b0 = b1;
        }
        film.per_pixel += density;
        Ok(())
    }
}

/// The trace `trace` runs, with the colour `map(s̄)` of the mean `s̄` of
/// `scalar` at the points it visits (white where it visits none).
pub(crate) fn mean_colour(
    scalar: &impl Fn(DVec3) -> f64,
    map: &ColorMap<'_>,
    trace: impl FnOnce(&mut dyn FnMut(DVec3)) -> Result<TraceResult, TraceError>,
) -> Result<(TraceResult, [f32; 3]), TraceError> {
    let (mut sum, mut n) = (0.0, 0u32);
    let r = trace(&mut |x| {
        sum += scalar(x);
        n += 1;
    })?;
    let c = if n > 0 { map.map((sum / f64::from(n)) as f32) } else { [1.0; 4] };
    Ok((r, [c[0], c[1], c[2]]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Filter, Weighting};
    use rt_volume::GaussianBump;

    /// A 6 × 4 beam along +z into a bump at the origin, imaging its
    /// mid-plane, 2 × 2 photons a pixel per pass.
    fn bump_bench(
        mode: Mode,
        film_distance: f64,
        reconstruction: Reconstruction,
    ) -> SchlierenBench {
        SchlierenBench {
            center: DVec3::new(0.0, 0.0, -6.0),
            direction: DVec3::Z,
            u: DVec3::X,
            width: 6.0,
            height: 4.0,
            image_plane: 6.0,
            film_distance,
            mode,
            weighting: Weighting::Weight,
            reconstruction,
            strata: 2,
            params: TraceParams::accurate(),
        }
    }

    /// The sheet traced and shared out in bands of a few rows is the
    /// sheet of one band, bit for bit (cells reach each pixel in the same
    /// order), photon counts included; a knife edge and a shadowgraph
    /// (cells folded over each other) alike.
    #[test]
    fn a_sheet_in_bands_is_the_whole_sheet() {
        let f = GaussianBump::new(DVec3::ZERO, 2e-3, 1.0, 5.0);
        let knife = Cutoff::KnifeEdge { angle: 0.3, offset: 0.0, f: 1.0, h: 1e-3 };
        for (mode, film_distance) in
            [(Mode::Schlieren(knife), 0.0), (Mode::Schlieren(Cutoff::None), 900.0)]
        {
            let bench = bump_bench(mode, film_distance, Reconstruction::Sheet);
            let tracer = |o, d| trace(&f, o, d, &bench.params).map(|r| (r, [1.0; 3]));
            let render = |band| {
                let mut film = Film::new(30, 20, Filter::Tent).unwrap();
                for pass in 0..2 {
                    bench.sheet_in_bands(&tracer, &mut film, pass, 9, band).unwrap();
                }
                film
            };
            let whole = render(usize::MAX);
            for band in [62 * 2, 62 * 5, 62 * 7 + 3] {
                assert_eq!(render(band), whole, "bands of {} rows", band / 62);
            }
        }
    }

    /// Photons traced in one batch make the image the per-photon tracer
    /// makes, bit for bit: splatted photons (box and tent) and the sheet,
    /// a knife edge and interferometry, over two passes; a batch that
    /// returns too few traces is an error and leaves the film as it was.
    #[test]
    fn a_batch_of_traces_makes_the_image_of_one_at_a_time() {
        let f = GaussianBump::new(DVec3::ZERO, 2e-3, 1.0, 5.0);
        let knife = Cutoff::KnifeEdge { angle: 0.3, offset: 0.0, f: 1.0, h: 1e-3 };
        let fringes = Mode::Interferometry { lambda: 5e-4, n_ref: 1.0, fringe_spacing: None };
        for (mode, reconstruction, filter) in [
            (Mode::Schlieren(knife.clone()), Reconstruction::Photons, Filter::Box),
            (Mode::Schlieren(knife.clone()), Reconstruction::Photons, Filter::Tent),
            (Mode::Schlieren(knife), Reconstruction::Sheet, Filter::Tent),
            (fringes, Reconstruction::Photons, Filter::Tent),
        ] {
            let bench = bump_bench(mode, 0.0, reconstruction);
            let (mut one, mut all) =
                (Film::new(24, 16, filter).unwrap(), Film::new(24, 16, filter).unwrap());
            let mut batch = |rays: &[(DVec3, DVec3)]| {
                rays.iter().map(|&(o, d)| trace(&f, o, d, &bench.params)).collect()
            };
            for pass in 0..2 {
                bench.render(&f, &mut one, pass, 5).unwrap();
                bench.render_batched(&mut batch, &mut all, pass, 5).unwrap();
            }
            assert_eq!(all, one, "{reconstruction:?}, {filter:?}");
            let before = all.clone();
            let mut short = |rays: &[(DVec3, DVec3)]| {
                Ok(alloc::vec![trace(&f, rays[0].0, rays[0].1, &bench.params)?])
            };
            assert!(bench.render_batched(&mut short, &mut all, 2, 5).is_err());
            assert_eq!(all, before);
        }
    }
}
