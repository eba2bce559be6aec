//! The bench behind the page: one worker thread renders the newest
//! settings pass after pass and publishes each refined image; a change
//! stops the render within a photon's time and the newest state wins
//! (nothing queues); a painted filter is applied to the picking pass's
//! recorded deflections without tracing again; with no page asking for
//! frames (a closed tab) the work stops until one asks again.

use std::{
    path::PathBuf,
    sync::{Arc, Condvar, Mutex, MutexGuard},
    time::{Duration, Instant},
};

use rt_core::{Frame, Pixel};
use rt_photo::{
    Cutoff, Film, FilterImage, Medium, Mode, SchlierenOptions, SchlierenSetup, SetupError,
};

use super::settings::{self, FileOptions, Settings};
use crate::{image, optics};

/// Pixels per side of the focal plane painted on (the page's canvas).
pub(crate) const PAINT_SIZE: usize = 256;

/// Photons in a first pass above which a preview is shown before it
/// (about 30 ms on two cores).
const PREVIEW_PHOTONS: u64 = 32_768;

/// The photons one pass of `photons` per pixel traces per pixel.
fn traced_per_pass(photons: u32) -> u64 {
    let (k, _) = rt_photo::lattice(photons);
    u64::from(k * k)
}

/// No frame asked for this long: the page is gone, the work stops.
pub(crate) const IDLE: Duration = Duration::from_secs(3);

/// What the page is shown: the newest image and what it is.
#[derive(Clone, Debug, Default)]
pub(crate) struct Shown {
    /// Grows with every image published.
    pub(crate) serial: u64,
    /// The settings' generation the image is of.
    pub(crate) generation: u64,
    /// Passes done and planned.
    pub(crate) pass: u64,
    pub(crate) passes: u64,
    /// Photons traced so far, and seconds since the settings changed.
    pub(crate) photons: u64,
    pub(crate) seconds: f64,
    /// The image (PNG), and its size.
    pub(crate) png: Arc<Vec<u8>>,
    pub(crate) width: usize,
    pub(crate) height: usize,
    /// A refusal of the settings (shown on the page), if any.
    pub(crate) message: Option<String>,
    /// The optics chosen (the set-up's line), the device, the command.
    pub(crate) optics: String,
    pub(crate) device: String,
    pub(crate) command: String,
    /// Painting: the focal plane's half range (radians) and the picking
    /// pass's film (each pixel's light and mean deflection).
    pub(crate) half_range: Option<f64>,
    pub(crate) picking: Option<Arc<Film>>,
}

/// What the page asked for last.
#[derive(Default)]
struct Job {
    generation: u64,
    settings: Option<Settings>,
    filter: Option<(u64, Arc<FilterImage>)>,
    /// The painted filter as the page sent it (PNG).
    filter_png: Option<Vec<u8>>,
    /// When a page last asked for a frame.
    seen: Option<Instant>,
}

/// The state shared by the worker and the requests.
pub(crate) struct Engine {
    pub(crate) file: PathBuf,
    pub(crate) file_options: FileOptions,
    pub(crate) device: crate::optics::DeviceArg,
    /// Where "save figure" writes (the painted filter among it).
    pub(crate) out: PathBuf,
    job: Mutex<Job>,
    job_changed: Condvar,
    shown: Mutex<Shown>,
    shown_changed: Condvar,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panicking request must not take the server down: the data are
    // plain values, whole at every unlock.
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

impl Engine {
    pub(crate) fn new(
        file: PathBuf,
        file_options: FileOptions,
        device: crate::optics::DeviceArg,
        out: PathBuf,
    ) -> Arc<Self> {
        Arc::new(Self {
            file,
            file_options,
            device,
            out,
            job: Mutex::default(),
            job_changed: Condvar::new(),
            shown: Mutex::default(),
            shown_changed: Condvar::new(),
        })
    }

    /// The page's new settings; the render of the old ones stops.
    pub(crate) fn set(&self, s: Settings) -> u64 {
        let mut job = lock(&self.job);
        job.generation += 1;
        job.settings = Some(s);
        job.seen = Some(Instant::now());
        self.job_changed.notify_all();
        job.generation
    }

    /// A painted filter (applied to the picking pass without tracing).
    pub(crate) fn paint(&self, f: FilterImage, png: Vec<u8>) {
        let mut job = lock(&self.job);
        let n = job.filter.as_ref().map_or(1, |(n, _)| n + 1);
        job.filter = Some((n, Arc::new(f)));
        job.filter_png = Some(png);
        self.job_changed.notify_all();
    }

    /// The painted filter as the page sent it (PNG), if it sent one.
    pub(crate) fn filter_png(&self) -> Option<Vec<u8>> {
        lock(&self.job).filter_png.clone()
    }

    /// The page is gone (it said so on closing).
    pub(crate) fn leave(&self) {
        lock(&self.job).seen = None;
    }

    /// The newest image once it is newer than `after` (or after `wait`);
    /// counts as the page being there.
    pub(crate) fn frame(&self, after: u64, wait: Duration) -> Shown {
        {
            let mut job = lock(&self.job);
            job.seen = Some(Instant::now());
            self.job_changed.notify_all();
        }
        let shown = lock(&self.shown);
        let (shown, _) = self
            .shown_changed
            .wait_timeout_while(shown, wait, |s| s.serial <= after)
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        shown.clone()
    }

    /// The image shown now.
    pub(crate) fn shown(&self) -> Shown {
        lock(&self.shown).clone()
    }

    fn publish(&self, mut s: Shown) {
        let mut shown = lock(&self.shown);
        s.serial = shown.serial + 1;
        *shown = s;
        self.shown_changed.notify_all();
    }

    fn generation(&self) -> u64 {
        lock(&self.job).generation
    }

    fn idle(&self) -> bool {
        lock(&self.job).seen.is_none_or(|t| t.elapsed() > IDLE)
    }

    /// The worker: renders the newest settings until told to stop.
    pub(crate) fn run(self: &Arc<Self>) {
        let mut media: Vec<(optics::Interpolation, Arc<Medium>)> = Vec::new();
        let mut done: Option<u64> = None; // generation rendered to the end
        let mut painted = 0u64; // filter applied last
        loop {
            let (generation, settings, filter) = {
                let job = lock(&self.job);
                let wanted = |j: &Job| {
                    let fresh = j.settings.is_some() && done != Some(j.generation);
                    let here = j.seen.is_some_and(|t| t.elapsed() <= IDLE);
                    let repaint = j.filter.as_ref().is_some_and(|(n, _)| *n != painted);
                    here && (fresh || repaint)
                };
                let (job, _) = self
                    .job_changed
                    .wait_timeout_while(job, Duration::from_millis(500), |j| !wanted(j))
                    .unwrap_or_else(std::sync::PoisonError::into_inner);
                if !wanted(&job) {
                    continue;
                }
                (job.generation, job.settings.clone(), job.filter.clone())
            };
            let Some(settings) = settings else { continue };
            if let Some((n, f)) = &filter {
                painted = *n;
                // Only the filter changed, and its picking pass is done:
                // apply it to the recorded deflections.
                if done == Some(generation) && settings.paint {
                    let mut s = self.shown();
                    if let Some(film) = s.picking.clone()
                        && let Ok(png) = painted_png(&film, f)
                    {
                        s.png = Arc::new(png);
                        self.publish(s);
                    }
                    continue;
                }
            }
            let medium = match medium_for(&mut media, self, settings.interp()) {
                Ok(m) => m,
                Err(e) => {
                    self.refuse(generation, &settings, e);
                    done = Some(generation);
                    continue;
                }
            };
            match self.render(generation, &settings, &medium) {
                Ok(()) => done = Some(generation),
                Err(Some(e)) => {
                    self.refuse(generation, &settings, e);
                    done = Some(generation);
                }
                // Stopped: a newer state, or the page went away.
                Err(None) => {}
            }
        }
    }

    /// Shows `message` in place of an image for `settings`.
    fn refuse(&self, generation: u64, settings: &Settings, message: String) {
        let old = self.shown();
        self.publish(Shown {
            generation,
            pass: 0,
            passes: 0,
            message: Some(message),
            command: settings::command_line(&self.file, &self.file_options, &settings.traced()),
            ..old
        });
    }

    /// Renders `settings` pass after pass, publishing each; `Err(None)`
    /// when stopped.
    fn render(
        &self,
        generation: u64,
        settings: &Settings,
        medium: &Medium,
    ) -> Result<(), Option<String>> {
        let t = Instant::now();
        let argv = settings.traced();
        let a = settings::args(&self.file, &self.file_options, &argv).map_err(Some)?;
        let options = a.options();
        let mut setup =
            SchlierenSetup::choose(medium, &options).map_err(|e| Some(e.to_string()))?;
        // Painting: the colour filter's rim (automatic, or the page's) is
        // the focal plane painted on, to four digits as the command line
        // prints it; the picking pass traces through a clear filter of it.
        let half_range = match settings.paint {
            true => setup.focal_range().and_then(|h| format!("{h:.3e}").parse::<f64>().ok()),
            false => None,
        };
        if let Some(h) = half_range {
            setup = setup
                .with_filter(FilterImage::clear(PAINT_SIZE, h))
                .map_err(|e| Some(e.to_string()))?;
        }
        let chosen = rt_gpu::choose(self.device.into(), medium).map_err(|e| Some(e.to_string()))?;
        let device = chosen.describe();
        let stop = || self.generation() != generation || self.idle();
        let mut command = match half_range {
            Some(h) => settings.figure(&self.out.join("filter.png"), h),
            None => argv.clone(),
        };
        // The same image from the command line needs the same device.
        if matches!(chosen, rt_gpu::Chosen::Gpu(_)) {
            command.extend(["--device".into(), "gpu".into()]);
        }
        let base = Shown {
            generation,
            optics: setup.to_string(),
            device: device.clone(),
            command: settings::command_line(&self.file, &self.file_options, &command),
            half_range,
            ..Shown::default()
        };
        let scale =
            if matches!(setup.bench.mode, Mode::Schlieren(Cutoff::None)) { 0.5 } else { 1.0 };
        let tracer = match &chosen {
            rt_gpu::Chosen::Gpu(gpu) => match medium {
                Medium::Grid(g) => {
                    Some(rt_gpu::GridTracer::new(gpu, g.field()).map_err(|e| Some(e.to_string()))?)
                }
                _ => None,
            },
            rt_gpu::Chosen::Cpu(_) => None,
        };
        let seed = a.seed;
        let publish = |film: &Film, pass: u64, passes: u64| -> Result<(), SetupError> {
            // The newest filter: painting goes on while the pass traces.
            let filter = lock(&self.job).filter.clone().map(|(_, f)| f);
            let (png, picking) = match (&filter, settings.paint) {
                (Some(f), true) => (painted_png(film, f), Some(Arc::new(film.clone()))),
                (None, true) => (plain_png(film, 1.0), Some(Arc::new(film.clone()))),
                _ => (plain_png(film, scale), None),
            };
            let png = png.map_err(|_| SetupError::Stopped)?;
            self.publish(Shown {
                pass,
                passes,
                photons: film.emitted,
                seconds: t.elapsed().as_secs_f64(),
                png: Arc::new(png),
                width: film.width(),
                height: film.height(),
                picking,
                ..base.clone()
            });
            Ok(())
        };
        let (_, passes) = rt_photo::lattice(options.photons);
        let trace = |bench: &rt_photo::SchlierenBench, film: &mut Film, p: u64| {
            if stop() {
                return Err(SetupError::Stopped);
            }
            match &tracer {
                Some(tracer) => tracer.schlieren_pass(bench, film, p, seed).map_err(|e| match e {
                    rt_gpu::GpuError::Bench(b) => SetupError::SchlierenBench(b),
                    _ => SetupError::Stopped,
                }),
                None => bench
                    .render_medium_until(medium, film, p, seed, &stop)
                    .map_err(|e| if stop() { SetupError::Stopped } else { e.into() }),
            }
        };
        // A first pass of a large image takes long: show a preview (a
        // quarter of the size, one 2 × 2 lattice, the same optics) first,
        // so a change is seen within a frame or two.
        let (w, h) = setup.size;
        let per_pass = (w * h) as u64 * traced_per_pass(options.photons);
        if per_pass > PREVIEW_PHOTONS {
            let size = ((w / 4).max(16), (h / 4).max(16));
            let o = SchlierenOptions { size: size.0 as u32, photons: 4, ..options.clone() };
            let preview = SchlierenSetup { size, options: o, ..setup.clone() };
            let film = preview.render_passes(&mut |_, _| {}, &mut |b, f, p| trace(b, f, p));
            match film {
                Ok(film) => publish(&film, 0, passes).map_err(|_| None)?,
                Err(SetupError::Stopped) if stop() => return Err(None),
                Err(e) => return Err(Some(e.to_string())),
            }
        }
        let result = setup.render_passes(&mut |_, _| {}, &mut |bench, film, p| {
            trace(bench, film, p)?;
            publish(film, p + 1, passes)
        });
        match result {
            Ok(_) => Ok(()),
            Err(SetupError::Stopped) if stop() => Err(None),
            Err(e) => Err(Some(e.to_string())),
        }
    }
}

/// The medium for `interp`, opened once.
fn medium_for(
    media: &mut Vec<(optics::Interpolation, Arc<Medium>)>,
    engine: &Engine,
    interp: optics::Interpolation,
) -> Result<Arc<Medium>, String> {
    if let Some((_, m)) = media.iter().find(|(i, _)| *i == interp) {
        return Ok(m.clone());
    }
    let fo = &engine.file_options;
    let m = optics::open(&engine.file, fo.samples, fo.allow_nonphysical, interp, &fo.mesh)
        .map_err(|e| crate::one_line(&e))?;
    let m = Arc::new(m);
    media.push((interp, m.clone()));
    Ok(m)
}

/// The film's image as `rt schlieren` writes it (PNG bytes).
fn plain_png(film: &Film, scale: f32) -> Result<Vec<u8>, String> {
    let frame = image::film_frame(film, scale).map_err(|e| e.to_string())?;
    image::png_bytes(&frame).map_err(|e| e.to_string())
}

/// The picking pass's film through a painted filter (PNG bytes).
pub(crate) fn painted_png(film: &Film, filter: &FilterImage) -> Result<Vec<u8>, String> {
    let size = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
    let mut frame =
        Frame::new(size(film.width()), size(film.height())).map_err(|e| e.to_string())?;
    for (p, c) in frame.pixels_mut().iter_mut().zip(film.through_filter(filter)) {
        *p = Pixel { color: [c[0], c[1], c[2], 1.0], depth: 0.0 };
    }
    image::png_bytes(&frame).map_err(|e| e.to_string())
}
