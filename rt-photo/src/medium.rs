//! Every instrument over any [`Medium`]: a grid on its octree's fast path
//! (skipping within the tolerance each instrument cannot resolve), an
//! exact or a smooth mesh; traced with the medium's own settings
//! ([`Medium::params`]), not the instrument's.

use glam::DVec3;
use rt_volume::{Medium, TraceError, TraceResult};

use crate::{
    BenchError, Bos, BosError, BosImages, Film, FocusingError, FocusingImages, FocusingSchlieren,
    SchlierenBench,
};

impl SchlierenBench {
    /// Adds one pass to `film` through `medium` (see [`SchlierenBench::render`]):
    /// a grid on its octree's fast path — photons cross the field's smooth
    /// regions in straight steps within the tolerance the bench cannot
    /// resolve ([`SchlierenBench::skip_tolerance`]), and photons whose line meets no
    /// node too rough for it go straight without walking the tree; a mesh
    /// traced exactly or with its recovered gradients.
    ///
    /// # Errors
    /// As [`SchlierenBench::render`].
    pub fn render_medium(
        &self,
        medium: &Medium,
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        self.render_medium_until(medium, film, pass, seed, &|| false)
    }

    /// [`SchlierenBench::render_medium`] that asks `stop` before each
    /// photon and, once it says yes, fails with
    /// [`TraceError::Stopped`] (an interrupt within a photon's time).
    ///
    /// # Errors
    /// As [`SchlierenBench::render`].
    pub fn render_medium_until(
        &self,
        medium: &Medium,
        film: &mut Film,
        pass: u64,
        seed: u64,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<(), BenchError> {
        match medium {
            Medium::Grid(g) => self.render_grid_with(g, &medium.params(), film, pass, seed, stop),
            _ => self.render_with(&until(stop, |o, d| medium.trace(o, d, None)), film, pass, seed),
        }
    }
}

impl Bos {
    /// The images through `medium` (see [`Bos::render`]); a grid with
    /// octree skipping within a per-ray budget of
    /// [`Bos::resolvable_deflection`] at the field's centre (the ground
    /// truth moves by at most a tenth of a pixel).
    ///
    /// # Errors
    /// As [`Bos::render`].
    pub fn render_medium(&self, medium: &Medium, seed: u64) -> Result<BosImages, BosError> {
        self.render_medium_until(medium, seed, &|| false)
    }

    /// [`Bos::render_medium`] that asks `stop` before each ray and, once it
    /// says yes, fails with [`TraceError::Stopped`].
    ///
    /// # Errors
    /// As [`Bos::render`].
    pub fn render_medium_until(
        &self,
        medium: &Medium,
        seed: u64,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<BosImages, BosError> {
        let tol = matches!(medium, Medium::Grid(_)).then(|| {
            let b = medium.bounds();
            let axis = self.camera.direction.normalize();
            let z_a = (0.5 * (b.min + b.max) - self.camera.position).dot(axis);
            self.resolvable_deflection(z_a)
        });
        self.render_with(&until(stop, |o, d| medium.trace(o, d, tol)), seed)
    }
}

impl FocusingSchlieren {
    /// The images through `medium` (see [`FocusingSchlieren::render`]); a
    /// grid with octree skipping within a per-ray budget of
    /// [`FocusingSchlieren::resolvable_deflection`].
    ///
    /// # Errors
    /// As [`FocusingSchlieren::render`].
    pub fn render_medium(
        &self,
        medium: &Medium,
        seed: u64,
    ) -> Result<FocusingImages, FocusingError> {
        self.render_medium_until(medium, seed, &|| false)
    }

    /// [`FocusingSchlieren::render_medium`] that asks `stop` before each
    /// ray and, once it says yes, fails with [`TraceError::Stopped`].
    ///
    /// # Errors
    /// As [`FocusingSchlieren::render`].
    pub fn render_medium_until(
        &self,
        medium: &Medium,
        seed: u64,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<FocusingImages, FocusingError> {
        let skip = matches!(medium, Medium::Grid(_)).then(|| self.resolvable_deflection());
        self.render_with(&until(stop, |o, d| medium.trace(o, d, skip)), seed)
    }
}

/// `trace`, unless `stop` says to stop: then [`TraceError::Stopped`].
pub(crate) fn until<'a>(
    stop: &'a (dyn Fn() -> bool + Sync),
    trace: impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync + 'a,
) -> impl Fn(DVec3, DVec3) -> Result<TraceResult, TraceError> + Sync + 'a {
    move |o, d| if stop() { Err(TraceError::Stopped) } else { trace(o, d) }
}
