//! Background-oriented schlieren set up from the data: a laboratory rig
//! chosen for the flow's deflections, a thin-lens camera and a
//! background.

use rt_volume::{Bounds, Medium, TraceParams};

use super::error::{positive, within};
use crate::{
    Axis, Background, BackgroundChoice, Bos, BosImages, BosRig, BosRigOptions, DotBackground,
    DotGrid, ImageBackground, SchlierenBench, SetupError, Survey, ThinLens,
};

/// What a BOS recording is to be; `None` means "choose it from the
/// medium" (by [`BosRig::choose`]).
#[derive(Clone, Debug, PartialEq)]
pub struct BosOptions {
    /// The camera looks along this axis (from its + side).
    pub axis: Axis,
    /// Image width in pixels (the height keeps the volume's aspect).
    pub size: u32,
    /// The rig's lens, sensor pixel and distances (metres).
    pub rig: BosRigOptions,
    /// The lens's f-number.
    pub f_number: f64,
    /// The background.
    pub background: BackgroundChoice,
    /// Dot diameter and spacing in image pixels (random dots, dot grid).
    pub dot: f64,
    /// See [`BosOptions::dot`].
    pub spacing: f64,
    /// Aperture samples per axis (rays per pixel: its square).
    pub samples_per_axis: u32,
    /// Seed of the random dots.
    pub seed: u64,
}

impl Default for BosOptions {
    fn default() -> Self {
        Self {
            axis: Axis::Z,
            size: 512,
            rig: BosRigOptions::default(),
            f_number: 16.0,
            background: BackgroundChoice::Random,
            dot: 3.0,
            spacing: 4.0,
            samples_per_axis: 2,
            seed: 1,
        }
    }
}

/// A BOS recording set up for a medium: what renders it and the rig
/// chosen (`Display`: its line).
#[derive(Clone, Debug)]
pub struct BosSetup {
    /// Camera, background and sampling.
    pub bos: Bos,
    /// The rig: lens, distances, sensor, expected displacement.
    pub rig: BosRig,
}

impl BosSetup {
    /// Sets up `o` for `medium`; the survey runs only when the background
    /// distance is left to choose (it is what needs the deflections).
    ///
    /// # Errors
    /// An option out of range, a camera inside its focal length of the
    /// volume, a bad background, a failing survey.
    pub fn choose(medium: &Medium, o: &BosOptions) -> Result<Self, SetupError> {
        let params = medium.params();
        Self::choose_with(medium.bounds(), params, o, |probe| {
            Survey::of(medium, probe, Survey::WIDTH)
        })
    }

    /// [`BosSetup::choose`] for a medium filling `bounds`, traced with
    /// `params`, whose survey (asked only when the background distance is left to
    /// choose) `survey` takes with the bench it is given (across ranks,
    /// say: [`Survey::of_with`] with their tracer).
    ///
    /// # Errors
    /// As [`BosSetup::choose`]; the survey's own.
    pub fn choose_with<E: From<SetupError>>(
        bounds: Bounds,
        params: TraceParams,
        o: &BosOptions,
        survey: impl FnOnce(&SchlierenBench) -> Result<Survey, E>,
    ) -> Result<Self, E> {
        within("size", o.size, 1, super::MAX_CAMERA_EDGE)?;
        within("samples", o.samples_per_axis, 1, super::MAX_APERTURE_SAMPLES)?;
        positive("f_number", o.f_number)?;
        positive("dot", o.dot)?;
        positive("spacing", o.spacing)?;
        let r = &o.rig;
        for (name, v) in [
            ("focal_length", r.focal_length),
            ("pixel", r.pixel_pitch),
            ("distance", r.camera_distance),
            ("background_distance", r.background_distance),
        ] {
            v.map(|v| positive(name, v)).transpose()?;
        }
        if let BackgroundChoice::Image { pixel: Some(px), .. } = &o.background {
            positive("background_pixel", *px)?;
        }
        let b = bounds;
        let (axis, u) = o.axis.frame();
        let v = axis.cross(u);
        let ext = b.max - b.min;
        let (w, h) = o.axis.image_size(b, o.size as usize);
        let deflection = if o.rig.background_distance.is_none() {
            survey(&Survey::bench_through(b, o.axis, params))?.magnitude(0.99)
        } else {
            0.0
        };
        let rig = BosRig::choose(&o.rig, ext.dot(u), ext.dot(axis), w, deflection)
            .map_err(SetupError::from)?;
        let (f, z_a, z_d) = (rig.focal_length, rig.camera_distance, rig.background_distance);
        if z_a <= f {
            return Err(SetupError::TooClose { distance: z_a, focal_length: f }.into());
        }
        let camera = ThinLens {
            position: 0.5 * (b.min + b.max) + z_a * axis,
            direction: -axis,
            up: v,
            focal_length: f,
            f_number: o.f_number,
            focus_distance: z_a + z_d,
            pixel_pitch: rig.pixel_pitch,
            width: w,
            height: h,
        };
        let background: Background = match &o.background {
            BackgroundChoice::Random => {
                DotBackground::for_camera(&camera, o.dot, o.spacing, o.seed).into()
            }
            BackgroundChoice::Grid => DotGrid::for_camera(&camera, o.dot, o.spacing).into(),
            BackgroundChoice::Image { width, height, samples, pixel } => {
                let px = pixel.unwrap_or(w as f64 / *width as f64);
                ImageBackground::for_camera(&camera, *width, *height, samples.clone(), px)
                    .map_err(SetupError::from)?
                    .into()
            }
        };
        let bos = Bos {
            camera,
            background_distance: z_a + z_d,
            background,
            aperture_samples: o.samples_per_axis,
            params,
        };
        bos.validate().map_err(SetupError::from)?;
        Ok(Self { bos, rig })
    }

    /// The reference and flow images and the true displacement through
    /// `medium` (see [`Bos::render_medium`]).
    ///
    /// # Errors
    /// A failing trace.
    pub fn render(&self, medium: &Medium, seed: u64) -> Result<BosImages, SetupError> {
        self.render_until(medium, seed, &|| false)
    }

    /// [`BosSetup::render`] that asks `stop` before each ray (from the
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
    ) -> Result<BosImages, SetupError> {
        self.bos
            .render_medium_until(medium, seed, stop)
            .map_err(|e| SetupError::stopped_or(stop, e))
    }
}

impl core::fmt::Display for BosSetup {
    /// `f/16, f = 24 mm, Z_A = 2.261 m, …`: the lens and the rig.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "f/{}, {}", self.bos.camera.f_number, self.rig)
    }
}
