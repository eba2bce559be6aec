//! A quick look at the deflections a medium causes, from which the
//! set-ups choose what the user left unset.

use alloc::vec::Vec;

use glam::DVec3;
use rt_volume::{Bounds, Medium, TraceError, TraceParams, TraceResult};

use crate::{Axis, Cutoff, Film, Filter, Mode, SchlierenBench, SetupError, math};

/// Mean deflection per pixel of a coarse, uncut image of a medium.
#[derive(Clone, Debug)]
pub struct Survey {
    /// `(εu, εv)` per pixel, radians (`None`: no photon landed).
    pub eps: Vec<Option<(f64, f64)>>,
    /// Pixels per row.
    pub width: usize,
    /// Pixel size `(du, dv)` in the scene's length unit.
    pub pixel: (f64, f64),
}

impl Survey {
    /// Pixels across the survey every set-up takes: coarse and cheap
    /// (one photon a pixel), fine enough for quantiles.
    pub const WIDTH: usize = 96;

    /// The deflections `bench` would see through `medium`: one photon per
    /// pixel of a film `width` pixels wide, no cutoff, film in the image
    /// plane, every step traced (no skipping: such a bench cannot see
    /// deflections, so its skipping tolerance would hide a weak flow's).
    /// Finer shows the peaks a coarse film's pixel means smooth away.
    ///
    /// # Errors
    /// A failing trace.
    pub fn of(medium: &Medium, bench: &SchlierenBench, width: usize) -> Result<Self, SetupError> {
        Self::of_with(bench, width, &|o, d| medium.trace(o, d, None))
    }

    /// [`Survey::of`] with any tracer `(origin, direction) → result` (the
    /// photons of a grid spread over ranks, say).
    ///
    /// # Errors
    /// A failing trace.
    pub fn of_with(
        bench: &SchlierenBench,
        width: usize,
        tracer: &(impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync),
    ) -> Result<Self, SetupError> {
        let width = width.max(1);
        let height = math::round(width as f64 * bench.height / bench.width).clamp(1.0, 4096.0);
        let mut film = Film::new(width, height as usize, Filter::Box)?;
        Self::probe(bench).render_with(tracer, &mut film, 0, 0x5eed)?;
        Ok(Self {
            eps: film.mean_deflection(),
            width,
            pixel: (bench.width / width as f64, bench.height / height),
        })
    }

    /// `bench` as the survey runs it: no cutoff, film in the image plane.
    fn probe(bench: &SchlierenBench) -> SchlierenBench {
        SchlierenBench { mode: Mode::Schlieren(Cutoff::None), film_distance: 0.0, ..bench.clone() }
    }

    /// The bench [`Survey::through`] looks along `axis` with, through
    /// `bounds` with trace settings `params`.
    #[must_use]
    pub fn bench_through(bounds: Bounds, axis: Axis, params: TraceParams) -> SchlierenBench {
        SchlierenBench::through(bounds, axis, Mode::Schlieren(Cutoff::None), 0.0, params)
    }

    /// The deflections seen looking through the whole of `medium` along
    /// `axis` (the bench of [`SchlierenBench::through`]), on a film `width`
    /// pixels wide.
    ///
    /// # Errors
    /// A failing trace.
    pub fn through(medium: &Medium, axis: Axis, width: usize) -> Result<Self, SetupError> {
        Self::of(medium, &Self::bench_through(medium.bounds(), axis, medium.params()), width)
    }

    /// The `q`-quantile of `|ε|`.
    #[must_use]
    pub fn magnitude(&self, q: f64) -> f64 {
        quantile(self.eps.iter().flatten().map(|&(a, b)| math::hypot(a, b)).collect(), q)
    }

    /// The `q`-quantile of `|ε|` over the disturbed pixels (those
    /// deflected by more than a thousandth of the largest deflection):
    /// undisturbed pixels do not dilute it, however much of the image they
    /// fill.
    #[must_use]
    pub fn disturbed_magnitude(&self, q: f64) -> f64 {
        let all: Vec<f64> = self.eps.iter().flatten().map(|&(a, b)| math::hypot(a, b)).collect();
        let floor = 1e-3 * all.iter().copied().filter(|m| m.is_finite()).fold(0.0, f64::max);
        quantile(all.into_iter().filter(|&m| m > floor).collect(), q)
    }

    /// The `q`-quantile of `|ε⊥|`, the deflection along `angle` (radians
    /// from the image's u axis), as a knife edge there sees it.
    #[must_use]
    pub fn along(&self, angle: f64, q: f64) -> f64 {
        let (s, c) = (math::sin(angle), math::cos(angle));
        quantile(self.eps.iter().flatten().map(|&(a, b)| (a * c + b * s).abs()).collect(), q)
    }

    /// The `q`-quantile of `|∇⊥·ε|` (per length unit): what a film at
    /// distance `L` sees as the relative contrast `L·∇⊥·ε` (shadowgraph).
    #[must_use]
    pub fn divergence(&self, q: f64) -> f64 {
        let w = self.width;
        let at = |i: usize, j: usize| self.eps.get(i + w * j).copied().flatten();
        let rows = self.eps.len() / w.max(1);
        let mut div = Vec::new();
        for j in 1..rows.saturating_sub(1) {
            for i in 1..w.saturating_sub(1) {
                if let (Some(l), Some(r), Some(up), Some(down)) =
                    (at(i - 1, j), at(i + 1, j), at(i, j - 1), at(i, j + 1))
                {
                    // Rows grow downward, v upward.
                    let du = (r.0 - l.0) / (2.0 * self.pixel.0);
                    let dv = (up.1 - down.1) / (2.0 * self.pixel.1);
                    div.push((du + dv).abs());
                }
            }
        }
        quantile(div, q)
    }
}

/// The `q`-quantile (0–1) of `values` (0 for none).
fn quantile(mut values: Vec<f64>, q: f64) -> f64 {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let i = math::round((values.len() - 1) as f64 * q.clamp(0.0, 1.0)) as usize;
    values[i]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_ignore_non_finite_values() {
        assert_eq!(quantile(alloc::vec![], 0.5), 0.0);
        assert_eq!(quantile(alloc::vec![3.0, f64::NAN, 1.0, 2.0], 0.5), 2.0);
        assert_eq!(quantile((1..=100).map(f64::from).collect(), 0.99), 99.0);
    }

    /// The disturbed quantile ignores the undisturbed pixels: a flow in a
    /// small corner of the image has the same rim as one filling it,
    /// where the plain quantile would sink toward 0.
    #[test]
    fn the_disturbed_quantile_is_not_diluted_by_still_air() {
        let flow: Vec<Option<(f64, f64)>> = (1..=100).map(|i| Some((f64::from(i), 0.0))).collect();
        let mut sparse = alloc::vec![Some((0.0, 0.0)); 9900];
        sparse.extend(flow.iter().copied());
        let survey = |eps| Survey { eps, width: 100, pixel: (1.0, 1.0) };
        let (full, corner) = (survey(flow), survey(sparse));
        assert_eq!(full.disturbed_magnitude(0.99), corner.disturbed_magnitude(0.99));
        assert_eq!(corner.disturbed_magnitude(0.99), 99.0);
        assert_eq!(corner.magnitude(0.99), 0.0);
    }
}
