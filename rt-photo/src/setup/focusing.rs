//! Focusing schlieren set up from the data: a laboratory lens-and-grid
//! rig, its grid pitch chosen for the flow's deflections.

use rt_volume::{Bounds, Medium, TraceParams};

use super::error::{finite, invalid, positive, within};
use crate::{
    Axis, FocusingImages, FocusingRig, FocusingRigOptions, FocusingSchlieren, SchlierenBench,
    SetupError, SourceGrid, Survey, ThinLens,
};

/// What a focusing-schlieren image is to be; `None` means "choose it from
/// the medium" (by [`FocusingRig::choose`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FocusingOptions {
    /// The lens looks along this axis (from its + side).
    pub axis: Axis,
    /// Image width in pixels (the height keeps the volume's aspect).
    pub size: u32,
    /// The rig's lens, pixel, distances and grid pitch (metres).
    pub rig: FocusingRigOptions,
    /// The plane in focus: metres beyond the volume's centre, along the
    /// view.
    pub focus: f64,
    /// The source grid's bright fraction of each period.
    pub duty: f64,
    /// The bands' direction, degrees (0: the bands run along the image's
    /// v axis, so the system sees deflections along u).
    pub angle: f64,
    /// The cutoff grid's shift, in periods (0.25: a quarter band, the
    /// linear range's middle).
    pub offset: f64,
    /// Bands across the source grid (`None`: as many as fill it).
    pub bands: Option<u32>,
    /// Aperture samples per axis (rays per pixel: its square).
    pub samples_per_axis: u32,
}

impl Default for FocusingOptions {
    fn default() -> Self {
        Self {
            axis: Axis::Z,
            size: 512,
            rig: FocusingRigOptions::default(),
            focus: 0.0,
            duty: 0.5,
            angle: 0.0,
            offset: 0.25,
            bands: None,
            samples_per_axis: 6,
        }
    }
}

/// A focusing-schlieren system set up for a medium (`Display`: the rig's
/// line).
#[derive(Clone, Debug)]
pub struct FocusingSetup {
    /// Lens, grids and sampling.
    pub system: FocusingSchlieren,
    /// The rig chosen.
    pub rig: FocusingRig,
}

impl FocusingSetup {
    /// Sets up `o` for `medium`; the survey runs only when the grid's
    /// pitch is left to choose.
    ///
    /// # Errors
    /// An option out of range, a bad rig, a failing survey.
    pub fn choose(medium: &Medium, o: &FocusingOptions) -> Result<Self, SetupError> {
        let params = medium.params();
        Self::choose_with(medium.bounds(), params, o, |probe| {
            Survey::of(medium, probe, Survey::WIDTH)
        })
    }

    /// [`FocusingSetup::choose`] for a medium filling `bounds`, traced with
    /// `params`, whose survey (asked only when the grid's pitch is left to
    /// choose) `survey` takes with the bench it is given (across ranks,
    /// say: [`Survey::of_with`] with their tracer).
    ///
    /// # Errors
    /// As [`FocusingSetup::choose`]; the survey's own.
    pub fn choose_with<E: From<SetupError>>(
        bounds: Bounds,
        params: TraceParams,
        o: &FocusingOptions,
        survey: impl FnOnce(&SchlierenBench) -> Result<Survey, E>,
    ) -> Result<Self, E> {
        within("size", o.size, 1, super::MAX_CAMERA_EDGE)?;
        within("samples", o.samples_per_axis, 1, super::MAX_APERTURE_SAMPLES)?;
        finite("focus", o.focus)?;
        finite("angle", o.angle)?;
        if !(o.duty > 0.0 && o.duty < 1.0) {
            return Err(invalid("duty", "in (0, 1)", o.duty).into());
        }
        if !(o.offset >= 0.0 && o.offset < 1.0) {
            return Err(invalid("offset", "in [0, 1) pitches", o.offset).into());
        }
        if let Some(n) = o.bands {
            within("bands", n, 1, u32::MAX)?;
        }
        let r = &o.rig;
        for (name, v) in [
            ("focal_length", r.focal_length),
            ("aperture", r.aperture),
            ("pixel", r.pixel_pitch),
            ("distance", r.camera_distance),
            ("source_distance", r.source_distance),
            ("pitch", r.grid_pitch),
        ] {
            v.map(|v| positive(name, v)).transpose()?;
        }
        let b = bounds;
        let (axis, u) = o.axis.frame();
        let v = axis.cross(u);
        let ext = b.max - b.min;
        let (w, h) = o.axis.image_size(b, o.size as usize);
        let angle = o.angle.to_radians();
        let deflection = if o.rig.grid_pitch.is_none() {
            survey(&Survey::bench_through(b, o.axis, params))?.along(angle, 0.99)
        } else {
            0.0
        };
        let rig = FocusingRig::choose(&o.rig, ext.dot(u), w, o.focus, o.offset, deflection)
            .map_err(SetupError::from)?;
        let camera = ThinLens {
            position: 0.5 * (b.min + b.max) + rig.camera_distance * axis,
            direction: -axis,
            up: v,
            focal_length: rig.focal_length,
            f_number: rig.focal_length / rig.aperture,
            focus_distance: rig.focus_distance,
            pixel_pitch: rig.pixel_pitch,
            width: w,
            height: h,
        };
        let system = FocusingSchlieren {
            camera,
            source_distance: rig.source_distance,
            grid: SourceGrid { pitch: rig.grid_pitch, duty: o.duty, angle, bands: o.bands },
            cutoff_offset: o.offset,
            aperture_samples: o.samples_per_axis,
            params,
        };
        system.validate().map_err(SetupError::from)?;
        Ok(Self { system, rig })
    }

    /// The reference and flow images through `medium` (see
    /// [`FocusingSchlieren::render_medium`]).
    ///
    /// # Errors
    /// A failing trace.
    pub fn render(&self, medium: &Medium, seed: u64) -> Result<FocusingImages, SetupError> {
        self.render_until(medium, seed, &|| false)
    }

    /// [`FocusingSetup::render`] that asks `stop` before each ray (from the
    /// worker threads): once it says yes, the render ends within a ray's
    /// time with [`SetupError::Stopped`].
    ///
    /// # Errors
    /// A failing trace or [`SetupError::Stopped`].
    pub fn render_until(
        &self,
        medium: &Medium,
        seed: u64,
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<FocusingImages, SetupError> {
        self.system
            .render_medium_until(medium, seed, stop)
            .map_err(|e| SetupError::stopped_or(stop, e))
    }
}

impl core::fmt::Display for FocusingSetup {
    /// The rig and the cutoff's shift.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{}; cutoff offset {} pitch", self.rig, self.system.cutoff_offset)
    }
}
