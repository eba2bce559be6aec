//! The schlieren bench set up from the data: every cutoff, shadowgraph
//! and interferometry, with automatic exposure.

use alloc::{format, string::String};
use core::fmt;

use rt_volume::Medium;

use super::error::{finite, positive, within};
use crate::{
    Axis, BenchError, Cutoff, Film, Filter, FilterImage, Mode, Reconstruction, SchlierenBench,
    SetupError, Survey,
    units::{index, si, sig3},
};

/// The longest image side a set-up accepts, in pixels.
pub const MAX_EDGE: u32 = 16384;
/// The most photons one render traces.
pub const MAX_PHOTONS: u64 = 1 << 36;
/// The most photons per pixel a set-up accepts.
pub const MAX_PHOTONS_PER_PIXEL: u32 = 65536;

/// The optical set-up of a [`SchlierenOptions`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CutoffKind {
    /// Knife edge across the `angle` direction (classic schlieren).
    #[default]
    Knife,
    /// Graded filter: transmission ramps linearly with the deflection.
    Graded,
    /// Pinhole in the focal plane: passes only weakly deflected light.
    Pinhole,
    /// Opaque disc in the focal plane: passes only deflected light.
    DarkField,
    /// Hue-wheel colour filter: hue = direction of deflection, saturation
    /// = its size (rainbow schlieren).
    Color,
    /// No cutoff: a shadowgraph (with a film distance) or plain
    /// transmission.
    None,
    /// Interferometry: phase from the optical path, with optional finite
    /// fringes.
    Interferometry,
}

/// What a schlieren image is to be; `None` means "choose it from the
/// medium" (see each field).
#[derive(Clone, Debug, PartialEq)]
pub struct SchlierenOptions {
    /// The optical set-up.
    pub cutoff: CutoffKind,
    /// Direction the knife edge or graded filter is sensitive to, degrees
    /// from the image's horizontal axis.
    pub angle: f64,
    /// Focal length of the schlieren head, metres.
    pub f: f64,
    /// Source image height (knife edge) or ramp width (graded filter),
    /// metres; chosen: the 99th percentile of the deflection maps to 0.45
    /// of the range.
    pub h: Option<f64>,
    /// Stop radius (pinhole, dark field), metres; chosen: a quarter of the
    /// 99th-percentile deflection times `f`.
    pub radius: Option<f64>,
    /// Colour filter's rim deflection, radians; chosen: the rim clears
    /// 99.5 % of the disturbed pixels of a survey at the image's width.
    pub half_range: Option<f64>,
    /// Interferometry wavelength, metres.
    pub wavelength: f64,
    /// Interferometry fringe spacing on the film, metres (`None`:
    /// infinite fringe).
    pub fringes: Option<f64>,
    /// Film distance behind the volume, metres; chosen: for a shadowgraph
    /// the strongest contrast about 0.5, else 0.
    pub film_distance: Option<f64>,
    /// Beam direction.
    pub axis: Axis,
    /// Image width in pixels (the height keeps the volume's aspect).
    pub size: u32,
    /// Photons per pixel (rounded up to whole passes: [`lattice`]).
    pub photons: u32,
    /// How photons become the image.
    pub reconstruction: Reconstruction,
}

impl Default for SchlierenOptions {
    fn default() -> Self {
        Self {
            cutoff: CutoffKind::Knife,
            angle: 0.0,
            f: 1.0,
            h: None,
            radius: None,
            half_range: None,
            wavelength: 10.6e-6,
            fringes: None,
            film_distance: None,
            axis: Axis::Z,
            size: 512,
            photons: 16,
            reconstruction: Reconstruction::Sheet,
        }
    }
}

impl SchlierenOptions {
    /// `Err` naming the first option out of range.
    fn validate(&self) -> Result<(), SetupError> {
        finite("angle", self.angle)?;
        positive("f", self.f)?;
        for (name, v) in [("h", self.h), ("radius", self.radius), ("half_range", self.half_range)] {
            v.map(|v| positive(name, v)).transpose()?;
        }
        positive("wavelength", self.wavelength)?;
        self.fringes.map(|v| positive("fringe_spacing", v)).transpose()?;
        self.film_distance.map(|v| finite("film_distance", v)).transpose()?;
        within("size", self.size, 1, MAX_EDGE)?;
        within("photons", self.photons, 1, MAX_PHOTONS_PER_PIXEL)?;
        Ok(())
    }
}

/// A bench set up for a medium: the bench (its mode and film distance
/// chosen where the options left them out), the film's size and the
/// photons; `Display` is the line saying what was chosen.
#[derive(Clone, Debug)]
pub struct SchlierenSetup {
    /// The bench, with the chosen optics.
    pub bench: SchlierenBench,
    /// Film width and height in pixels.
    pub size: (usize, usize),
    /// The options it was set up from (photons per pixel among them).
    pub options: SchlierenOptions,
    /// A warning about the set-up (fringes that alias), if any.
    pub warning: Option<String>,
}

impl SchlierenSetup {
    /// Sets up `o` for `medium`: surveys the deflections (a 96-pixel film,
    /// and for a colour filter with its rim unset, one at the image's
    /// width up to 512) and chooses what `o` leaves out.
    ///
    /// # Errors
    /// An option out of range, too many photons, a failing survey.
    pub fn choose(medium: &Medium, o: &SchlierenOptions) -> Result<Self, SetupError> {
        o.validate()?;
        let params = medium.params();
        let probe = SchlierenBench::through(
            medium.bounds(),
            o.axis,
            Mode::Schlieren(Cutoff::None),
            0.0,
            params,
        );
        let (w, h) = o.axis.image_size(medium.bounds(), o.size as usize);
        let photons = w as u64 * h as u64 * traced_per_pixel(o.photons);
        if photons > MAX_PHOTONS {
            return Err(SetupError::TooManyPhotons { photons, max: MAX_PHOTONS });
        }
        let survey = Survey::of(medium, &probe, Survey::WIDTH)?;
        // A colour filter's rim must clear the peaks a coarse survey
        // smooths away: survey it at the image's resolution (a fraction of
        // the render's photons).
        let fine = if o.cutoff == CutoffKind::Color && o.half_range.is_none() {
            Some(Survey::of(medium, &probe, w.min(512))?)
        } else {
            None
        };
        let (mode, film_distance) = exposure(o, &survey, fine.as_ref(), medium.ambient());
        let mut warning = None;
        if let Mode::Interferometry { lambda, fringe_spacing, .. } = mode {
            // Phase step per pixel: the deflection is the phase gradient over k.
            let pixel = probe.width / f64::from(o.size);
            let tau = core::f64::consts::TAU;
            let step = tau / lambda * survey.magnitude(0.99) * pixel
                + fringe_spacing.map_or(0.0, |s| tau * pixel / s);
            if step > core::f64::consts::PI {
                warning =
                    Some(format!("fringes alias: up to {step:.1} rad of phase per pixel (> π)"));
            }
        }
        let bench = SchlierenBench {
            reconstruction: o.reconstruction,
            ..SchlierenBench::through(medium.bounds(), o.axis, mode, film_distance, params)
        };
        Ok(Self { bench, size: (w, h), options: o.clone(), warning })
    }

    /// The set-up with `filter` in its focal plane instead of its cutoff
    /// (a filter the user painted: `FilterImage::read_png`, feature
    /// `png`); the title and line say "colour filter".
    ///
    /// # Errors
    /// [`BenchError::Cutoff`] for a filter that is empty, of the wrong
    /// size or not finite.
    pub fn with_filter(mut self, filter: FilterImage) -> Result<Self, SetupError> {
        let cutoff = Cutoff::Color(filter);
        cutoff.validate().map_err(BenchError::Cutoff)?;
        self.bench.mode = Mode::Schlieren(cutoff);
        self.options.cutoff = CutoffKind::Color;
        Ok(self)
    }

    /// The colour filter's rim this set-up chose or was given (radians), or
    /// the deflection range its cutoff spans (`None`: no cutoff,
    /// interferometry): the scale of the focal plane a painted filter
    /// covers.
    #[must_use]
    pub fn focal_range(&self) -> Option<f64> {
        match &self.bench.mode {
            Mode::Schlieren(Cutoff::Color(f)) => Some(f.half_range),
            Mode::Schlieren(c) => c.range(),
            Mode::Interferometry { .. } => None,
        }
    }

    /// Renders the image through `medium` (whole passes of a lattice of
    /// photons per pixel, [`lattice`]); `progress(done, total)` after each
    /// pass, in photons.
    ///
    /// # Errors
    /// A failing trace.
    pub fn render(
        &self,
        medium: &Medium,
        seed: u64,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<Film, SetupError> {
        self.render_until(medium, seed, progress, &|| false)
    }

    /// [`SchlierenSetup::render`] that asks `stop` before each photon (from
    /// the worker threads): once it says yes, the render ends within a
    /// photon's time with [`SetupError::Stopped`].
    ///
    /// # Errors
    /// A failing trace, [`SetupError::Stopped`], or a film that does not
    /// fit in memory.
    pub fn render_until(
        &self,
        medium: &Medium,
        seed: u64,
        progress: &mut dyn FnMut(u64, u64),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<Film, SetupError> {
        self.render_passes(progress, &mut |bench, film, pass| {
            bench
                .render_medium_until(medium, film, pass, seed, stop)
                .map_err(|e| SetupError::stopped_or(stop, e))
        })
    }

    /// The render's film, each pass added by `pass(bench, film, index)`
    /// (the bench with the pass's lattice; e.g. traced on a GPU with the
    /// same optics): what [`SchlierenSetup::render_until`] does with the
    /// CPU's tracers. `progress(done, total)` after each pass, in photons.
    ///
    /// # Errors
    /// A film that does not fit in memory; the first error of `pass`.
    pub fn render_passes(
        &self,
        progress: &mut dyn FnMut(u64, u64),
        pass: &mut dyn FnMut(&SchlierenBench, &mut Film, u64) -> Result<(), SetupError>,
    ) -> Result<Film, SetupError> {
        let (w, h) = self.size;
        let mut film = Film::new(w, h, Filter::Tent)?;
        let (strata, passes) = lattice(self.options.photons);
        let bench = SchlierenBench { strata, ..self.bench.clone() };
        let per_pass = (w * h) as u64 * u64::from(strata * strata);
        for p in 0..passes {
            pass(&bench, &mut film, p)?;
            progress(per_pass * (p + 1), per_pass * passes);
        }
        Ok(film)
    }

    /// What the image shows, for a title: "Knife-edge schlieren",
    /// "Shadowgraph", …
    #[must_use]
    pub fn title(&self) -> &'static str {
        match self.options.cutoff {
            CutoffKind::Knife => "Knife-edge schlieren",
            CutoffKind::Graded => "Graded-filter schlieren",
            CutoffKind::Pinhole => "Pinhole (bright-field) schlieren",
            CutoffKind::DarkField => "Dark-field schlieren",
            CutoffKind::Color => "Colour schlieren",
            CutoffKind::None if self.bench.film_distance != 0.0 => "Shadowgraph",
            CutoffKind::None => "Transmission (no cutoff)",
            CutoffKind::Interferometry => "Interferogram",
        }
    }

    /// The image of an undisturbed beam through the optics (RGB, relative
    /// to a beam with nothing cut): a knife edge's half, a colour filter's
    /// white, an infinite fringe's bright.
    #[must_use]
    pub fn background(&self) -> [f32; 3] {
        match &self.bench.mode {
            Mode::Schlieren(c) => c.transmit(0.0, 0.0),
            Mode::Interferometry { .. } => [1.0; 3],
        }
    }
}

impl fmt::Display for SchlierenSetup {
    /// The optics chosen: `knife edge at 0°, f = 1.00 m, h = 2.90 mm`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let angle = sig3(self.options.angle);
        match &self.bench.mode {
            Mode::Schlieren(Cutoff::KnifeEdge { f: fl, h, .. }) => {
                write!(f, "knife edge at {angle}°, f = {}, h = {}", si(*fl, "m"), si(*h, "m"))
            }
            Mode::Schlieren(Cutoff::Graded { f: fl, width, .. }) => write!(
                f,
                "graded filter at {angle}°, f = {}, width = {}",
                si(*fl, "m"),
                si(*width, "m")
            ),
            Mode::Schlieren(Cutoff::Pinhole { f: fl, radius, dark_field }) => {
                let what = if *dark_field { "dark-field stop" } else { "pinhole" };
                write!(f, "{what}, f = {}, radius = {}", si(*fl, "m"), si(*radius, "m"))
            }
            Mode::Schlieren(Cutoff::Color(filter)) => {
                write!(f, "colour filter, rim at |ε| = {}", si(filter.half_range, "rad"))
            }
            Mode::Schlieren(_) => {
                write!(f, "no cutoff, film distance = {}", si(self.bench.film_distance, "m"))
            }
            Mode::Interferometry { lambda, n_ref, fringe_spacing } => {
                let fringes = fringe_spacing
                    .map_or("infinite fringe".into(), |s| format!("fringes {} apart", si(s, "m")));
                write!(
                    f,
                    "interferometry, λ = {}, n_ref = {}, {fringes}",
                    si(*lambda, "m"),
                    index(*n_ref)
                )
            }
        }
    }
}

/// The mode and film distance for `o`, each parameter chosen from
/// `survey` (a colour rim from `fine`, if given) where `o` leaves it out.
fn exposure(
    o: &SchlierenOptions,
    survey: &Survey,
    fine: Option<&Survey>,
    n_ref: f64,
) -> (Mode, f64) {
    let angle = o.angle.to_radians();
    // Knife edge and graded filter: 0.5 ± 0.45 at the 99th percentile.
    let eps_perp = survey.along(angle, 0.99).max(1e-12);
    let eps = survey.magnitude(0.99).max(1e-12);
    let f = o.f;
    let film = o.film_distance.unwrap_or(0.0);
    let mode = match o.cutoff {
        CutoffKind::Knife => {
            let h = o.h.unwrap_or(f * eps_perp / 0.45);
            Cutoff::KnifeEdge { angle, offset: 0.0, f, h }
        }
        CutoffKind::Graded => {
            Cutoff::Graded { angle, f, width: o.h.unwrap_or(f * eps_perp / 0.45) }
        }
        CutoffKind::Pinhole | CutoffKind::DarkField => Cutoff::Pinhole {
            f,
            radius: o.radius.unwrap_or(0.25 * f * eps),
            dark_field: o.cutoff == CutoffKind::DarkField,
        },
        CutoffKind::Color => {
            let chosen = || fine.unwrap_or(survey).disturbed_magnitude(0.995).max(1e-12);
            Cutoff::Color(FilterImage::hue_wheel(256, o.half_range.unwrap_or_else(chosen)))
        }
        CutoffKind::None => {
            let div = survey.divergence(0.99);
            let l = o.film_distance.unwrap_or(if div > 0.0 { 0.5 / div } else { 0.0 });
            return (Mode::Schlieren(Cutoff::None), l);
        }
        CutoffKind::Interferometry => {
            let mode =
                Mode::Interferometry { lambda: o.wavelength, n_ref, fringe_spacing: o.fringes };
            return (mode, film);
        }
    };
    (Mode::Schlieren(mode), film)
}

/// The lattice that traces `photons` photons per pixel: `(k, passes)`, a
/// `k × k` lattice per pixel in each pass. The sheet spreads each cell's
/// light over the cell's image, which blurs a jump in the image (trilinear
/// data's gradient jumps at cell faces) over `1/k` of a pixel; so `k`
/// grows with the photons — the largest power of two with at least 4
/// passes of `k²` (2 from 4 photons per pixel: 16 → 2, 64 → 4, 256 → 8)
/// — and the passes, shifted along R2, fill in between. `photons` rounds
/// up to whole passes.
#[must_use]
pub fn lattice(photons: u32) -> (u32, u64) {
    let mut k = 1u32;
    while 4 * (2 * k) * (2 * k) <= photons.max(16) && k < 64 {
        k *= 2;
    }
    let k = if photons < 4 { 1 } else { k };
    (k, u64::from(photons.div_ceil(k * k)))
}

/// The photons per pixel [`lattice`] traces for `photons`: whole passes.
#[must_use]
pub fn traced_per_pixel(photons: u32) -> u64 {
    let (k, passes) = lattice(photons);
    passes * u64::from(k * k)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lattice_refines_with_the_photons() {
        assert_eq!(lattice(1), (1, 1));
        assert_eq!(lattice(3), (1, 3));
        assert_eq!(lattice(4), (2, 1));
        assert_eq!(lattice(16), (2, 4));
        assert_eq!(lattice(17), (2, 5));
        assert_eq!(lattice(63), (2, 16));
        assert_eq!(lattice(64), (4, 4));
        assert_eq!(lattice(256), (8, 4));
        assert_eq!(lattice(65536), (64, 16));
    }
}
