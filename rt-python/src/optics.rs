//! The instruments: schlieren (every cutoff), shadowgraph,
//! interferometry and colour schlieren, background-oriented and focusing
//! schlieren of a volume, set up by the library's own set-ups
//! (`rt_photo::SchlierenSetup`, `BosSetup`, `FocusingSetup`) as `rt
//! schlieren`, `rt bos` and `rt focusing` set them up: the same defaults,
//! the same automatic choices, the same image for the same options. The
//! options are checked once, there. The schlieren bench's photons are
//! traced on the device `device` names (`rt_gpu::choose`, as `rt
//! schlieren --device`).

use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2,
    ndarray::{Array2, Array3, ArrayD},
};
use pyo3::{
    exceptions::{PyKeyboardInterrupt, PyMemoryError, PyRuntimeError, PyValueError},
    prelude::*,
    types::PyDict,
};
use rt_photo::{
    Airy, Axis, BackgroundChoice, BosOptions, BosRigOptions, BosSetup, Cutoff, CutoffKind,
    FocusingOptions, FocusingRigOptions, FocusingSetup, Mode, Reconstruction, SchlierenOptions,
    SchlierenSetup, Sensor,
};

use crate::{value_error, volume::PyVolume, watch::watched};

/// The axis named `s`.
fn axis(s: &str) -> PyResult<Axis> {
    match s {
        "x" => Ok(Axis::X),
        "y" => Ok(Axis::Y),
        "z" => Ok(Axis::Z),
        _ => Err(value_error(format!("axis: unknown `{s}` (known: x, y, z)"))),
    }
}

/// The cutoff named `s`, as `rt schlieren --cutoff` spells it.
fn cutoff(s: &str) -> PyResult<CutoffKind> {
    Ok(match s {
        "knife" => CutoffKind::Knife,
        "graded" => CutoffKind::Graded,
        "pinhole" => CutoffKind::Pinhole,
        "dark-field" => CutoffKind::DarkField,
        "color" => CutoffKind::Color,
        "none" => CutoffKind::None,
        "interferometry" => CutoffKind::Interferometry,
        _ => {
            return Err(value_error(format!(
                "cutoff: unknown `{s}` (known: knife, graded, pinhole, dark-field, color, none, interferometry)"
            )));
        }
    })
}

/// The estimator named `s`.
fn estimator(s: &str) -> PyResult<Reconstruction> {
    match s {
        "sheet" => Ok(Reconstruction::Sheet),
        "photons" => Ok(Reconstruction::Photons),
        _ => Err(value_error(format!("estimator: unknown `{s}` (known: sheet, photons)"))),
    }
}

/// `(image [h, w] or [h, w, 3] (RGB when `rgb`) relative to the
/// undisturbed background (where that is not black), of the dtype asked
/// for; the mean deflection [h, w, 2] in radians, NaN where no photon
/// landed (when asked for); the mean interferometric phase [h, w] in
/// radians, NaN where no photon landed, 0 outside interferometry (when
/// asked for); the optics chosen, by the keyword names of
/// `rtvis.schlieren`; a line saying which; a warning about the set-up
/// (aliasing fringes) or None)`.
type Optics<'py> = (
    Bound<'py, PyAny>,
    Option<Bound<'py, PyArray3<f32>>>,
    Option<Bound<'py, PyArray2<f64>>>,
    Bound<'py, PyDict>,
    String,
    Option<String>,
);

/// A vector of `n` items from `items`, or `MemoryError` if it does not
/// fit: outputs are as large as the film, and a machine that just held
/// the film may not hold them too.
pub(crate) fn filled<T>(n: usize, items: impl Iterator<Item = T>) -> PyResult<Vec<T>> {
    let mut v = Vec::new();
    v.try_reserve_exact(n).map_err(|_| {
        PyMemoryError::new_err(format!(
            "rtvis: an output of {} bytes does not fit in memory",
            n.saturating_mul(core::mem::size_of::<T>())
        ))
    })?;
    v.extend(items.take(n));
    Ok(v)
}

/// A set-up error as Python sees it: a film too large for memory is a
/// `MemoryError`, anything else a `ValueError`.
pub(crate) fn setup_error(e: rt_photo::SetupError) -> PyErr {
    match e {
        rt_photo::SetupError::Film(rt_photo::FilmError::OutOfMemory { bytes }) => {
            PyMemoryError::new_err(format!(
                "rtvis: the film's {bytes} bytes do not fit in memory (a smaller size fits)"
            ))
        }
        e => value_error(e),
    }
}

/// The optics `setup` chose, keyed by `rtvis.schlieren`'s keywords.
fn chosen<'py>(py: Python<'py>, setup: &SchlierenSetup) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let o = &setup.options;
    match &setup.bench.mode {
        Mode::Schlieren(c) => match c {
            Cutoff::KnifeEdge { h, .. } => d.set_item("h", h)?,
            Cutoff::Graded { width, .. } => d.set_item("h", width)?,
            Cutoff::Pinhole { radius, .. } => d.set_item("radius", radius)?,
            Cutoff::Color(filter) => d.set_item("half_range", filter.half_range)?,
            _ => {}
        },
        Mode::Interferometry { lambda, fringe_spacing, .. } => {
            d.set_item("wavelength", lambda)?;
            d.set_item("fringe_spacing", fringe_spacing)?;
        }
    }
    d.set_item("angle", o.angle)?;
    d.set_item("f", o.f)?;
    d.set_item("film_distance", setup.bench.film_distance)?;
    d.set_item("size", o.size)?;
    d.set_item("photons", o.photons)?;
    Ok(d)
}

/// Renders `volume` on the bench the arguments describe; `output` is
/// `(rgb, float64, relative, deflection, phase)`: what to return
/// (`relative`: divided by the background's level).
#[pyfunction]
#[pyo3(name = "_optics")]
#[pyo3(signature = (volume, cutoff_name, angle, f, h, radius, half_range, wavelength, fringe_spacing, film_distance, axis_name, size, photons, seed, estimator_name, output, progress=None, device_name="cpu"))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn optics<'py>(
    py: Python<'py>,
    volume: &PyVolume,
    cutoff_name: &str,
    angle: f64,
    f: f64,
    h: Option<f64>,
    radius: Option<f64>,
    half_range: Option<f64>,
    wavelength: f64,
    fringe_spacing: Option<f64>,
    film_distance: Option<f64>,
    axis_name: &str,
    size: u32,
    photons: u32,
    seed: u64,
    estimator_name: &str,
    output: (bool, bool, bool, bool, bool),
    progress: Option<Py<PyAny>>,
    device_name: &str,
) -> PyResult<Optics<'py>> {
    let device = match device_name {
        "cpu" => rt_gpu::Device::Cpu,
        "gpu" => rt_gpu::Device::Gpu,
        "auto" => rt_gpu::Device::Auto,
        other => {
            return Err(PyValueError::new_err(format!(
                "device: expected \"cpu\", \"gpu\" or \"auto\", got {other:?}"
            )));
        }
    };
    let options = SchlierenOptions {
        cutoff: cutoff(cutoff_name)?,
        angle,
        f,
        h,
        radius,
        half_range,
        wavelength,
        fringes: fringe_spacing,
        film_distance,
        axis: axis(axis_name)?,
        size,
        photons,
        reconstruction: estimator(estimator_name)?,
    };
    let (rgb, wide, relative, want_deflection, want_phase) = output;
    let v = &volume.inner;
    let (film, setup, on) = watched(py, progress, |w| -> Result<_, Failed> {
        let setup = SchlierenSetup::choose(v, &options).map_err(Failed::Setup)?;
        let chosen = rt_gpu::choose(device, v).map_err(Failed::Gpu)?;
        let film = match &chosen {
            rt_gpu::Chosen::Gpu(gpu) => {
                let (progress, stop) = (&mut |d, t| w.progress(d, t), &|| w.stopped());
                rt_gpu::render_schlieren(gpu, &setup, v, seed, progress, stop)
                    .map_err(Failed::Gpu)?
            }
            rt_gpu::Chosen::Cpu(_) => setup
                .render_until(v, seed, &mut |d, t| w.progress(d, t), &|| w.stopped())
                .map_err(Failed::Setup)?,
        };
        Ok((film, setup, chosen.describe()))
    })?
    .map_err(|e| match e {
        Failed::Setup(e) => setup_error(e),
        Failed::Gpu(e) => gpu_error(e),
    })?;
    let (w, h) = (film.width(), film.height());
    let n = w * h;
    // Relative to the background, channel by channel, where it is not
    // black (a dark field's is).
    let b = setup.background().map(f64::from);
    let scale = |p: [f64; 3], c: usize| if relative && b[c] > 0.0 { p[c] / b[c] } else { p[c] };
    let channels = if rgb { 3 } else { 1 };
    let pixels =
        || film.normalized_iter().flat_map(move |p| (0..channels).map(move |c| scale(p, c)));
    let shape = [h, w, channels];
    let image: Bound<'py, PyAny> = if wide {
        let a = ArrayD::from_shape_vec(
            &shape[..if rgb { 3 } else { 2 }],
            filled(n * channels, pixels())?,
        );
        a.map_err(value_error)?.into_pyarray(py).into_any()
    } else {
        let a = ArrayD::from_shape_vec(
            &shape[..if rgb { 3 } else { 2 }],
            filled(n * channels, pixels().map(|x| x as f32))?,
        );
        a.map_err(value_error)?.into_pyarray(py).into_any()
    };
    let deflection = if want_deflection {
        let eps = film
            .deflection_iter()
            .flat_map(|e| e.map_or([f32::NAN; 2], |(u, v)| [u as f32, v as f32]));
        let a = Array3::from_shape_vec((h, w, 2), filled(2 * n, eps)?).map_err(value_error)?;
        Some(a.into_pyarray(py))
    } else {
        None
    };
    let phase = if want_phase {
        let phi = film.phase_iter().map(|p| p.unwrap_or(f64::NAN));
        Some(Array2::from_shape_vec((h, w), filled(n, phi)?).map_err(value_error)?.into_pyarray(py))
    } else {
        None
    };
    drop(film);
    let said = match device {
        rt_gpu::Device::Cpu => setup.to_string(),
        _ => format!("{setup}; traced on {on}"),
    };
    Ok((image, deflection, phase, chosen(py, &setup)?, said, setup.warning))
}

/// Why a render on either device failed.
enum Failed {
    Setup(rt_photo::SetupError),
    Gpu(rt_gpu::GpuError),
}

/// A GPU error as Python's: a medium or device the GPU cannot take is a
/// `ValueError` (or `RuntimeError` where there is no adapter), a device
/// failure a `RuntimeError`.
fn gpu_error(e: rt_gpu::GpuError) -> PyErr {
    use rt_gpu::GpuError as E;
    match e {
        E::Unsupported(_) | E::BadSettings | E::NonFinite { .. } | E::ZeroDirection { .. } => {
            PyValueError::new_err(format!("rtvis: {e}"))
        }
        E::Stopped => PyKeyboardInterrupt::new_err("stopped"),
        e => PyRuntimeError::new_err(format!("rtvis: {e}")),
    }
}

/// Records an intensity image (1 = background) as a camera sensor would
/// (`rt_photo::Sensor`): counts of `bits` bits; `airy` = `(wavelength,
/// f-number, pixel pitch)` blurs it by diffraction first.
#[pyfunction]
#[pyo3(name = "_record")]
#[pyo3(signature = (image, exposure, full_well, bits, shot_noise, read_noise, seed, airy=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn record<'py>(
    py: Python<'py>,
    image: PyReadonlyArray2<'py, f64>,
    exposure: f64,
    full_well: f64,
    bits: u32,
    shot_noise: bool,
    read_noise: f64,
    seed: u64,
    airy: Option<(f64, f64, f64)>,
) -> PyResult<Bound<'py, PyArray2<u16>>> {
    let airy = airy.map(|(wavelength, f_number, pitch)| Airy::new(wavelength, f_number, pitch));
    let sensor = Sensor { exposure, full_well, bits, shot_noise, read_noise, airy };
    let view = image.as_array();
    let (h, w) = view.dim();
    let data: Vec<f64> = view.iter().copied().collect();
    let counts = py.detach(|| sensor.record(&data, w, h, seed)).map_err(value_error)?;
    Ok(Array2::from_shape_vec((h, w), counts).map_err(value_error)?.into_pyarray(py))
}

/// `(reference [h, w], flow [h, w], displacement [h, w, 2] in pixels (x
/// right, y down), a line describing the set-up, the rig chosen by
/// `rtvis.bos`'s keywords)`.
pub(crate) type BosOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    String,
    Bound<'py, PyDict>,
);

/// Background-oriented schlieren of `volume` ([`BosSetup`]); the
/// background is `"random"`, `"grid"`, the path of a PNG image, or
/// `image` (grey, row 0 at the top), each of its pixels `image_pixel`
/// sensor pixels as imaged (default: it spans the width).
#[pyfunction]
#[pyo3(name = "_bos")]
#[pyo3(signature = (volume, axis_name, size, focal_length, f_number, pixel, distance, background_distance, dot, spacing, samples, seed, background, image=None, image_pixel=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn bos<'py>(
    py: Python<'py>,
    volume: &PyVolume,
    axis_name: &str,
    size: u32,
    focal_length: Option<f64>,
    f_number: f64,
    pixel: Option<f64>,
    distance: Option<f64>,
    background_distance: Option<f64>,
    dot: f64,
    spacing: f64,
    samples: u32,
    seed: u64,
    background: &str,
    image: Option<PyReadonlyArray2<'py, f64>>,
    image_pixel: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<BosOut<'py>> {
    let options = bos_options(
        axis_name,
        size,
        focal_length,
        f_number,
        pixel,
        distance,
        background_distance,
        dot,
        spacing,
        samples,
        seed,
        background,
        image,
        image_pixel,
    )?;
    let v = &volume.inner;
    let (setup, images) = watched(py, progress, |w| -> Result<_, rt_photo::SetupError> {
        let setup = BosSetup::choose(v, &options)?;
        let c = &setup.bos.camera;
        let rays = (c.width * c.height) as u64 * u64::from(setup.bos.aperture_samples).pow(2);
        let images = w.counting(rays, |stop| setup.render_until(v, seed, stop))?;
        Ok((setup, images))
    })?
    .map_err(setup_error)?;
    bos_out(py, &setup, images)
}

/// The options `rtvis.bos`'s keywords give.
#[allow(clippy::too_many_arguments)]
pub(crate) fn bos_options(
    axis_name: &str,
    size: u32,
    focal_length: Option<f64>,
    f_number: f64,
    pixel: Option<f64>,
    distance: Option<f64>,
    background_distance: Option<f64>,
    dot: f64,
    spacing: f64,
    samples: u32,
    seed: u64,
    background: &str,
    image: Option<PyReadonlyArray2<'_, f64>>,
    image_pixel: Option<f64>,
) -> PyResult<BosOptions> {
    let background = match (image, background) {
        (Some(i), _) => {
            let view = i.as_array();
            let (h, w) = view.dim();
            let samples = view.iter().copied().collect();
            BackgroundChoice::Image { width: w, height: h, samples, pixel: image_pixel }
        }
        (None, "random") => BackgroundChoice::Random,
        (None, "grid") => BackgroundChoice::Grid,
        (None, path) => BackgroundChoice::read_png(std::path::Path::new(path), image_pixel)
            .map_err(|e| match e {
                rt_photo::PngError::Io { .. } => {
                    pyo3::exceptions::PyOSError::new_err(e.to_string())
                }
                rt_photo::PngError::Malformed { .. } => value_error(e),
            })?,
    };
    Ok(BosOptions {
        axis: axis(axis_name)?,
        size,
        rig: BosRigOptions {
            focal_length,
            pixel_pitch: pixel,
            camera_distance: distance,
            background_distance,
        },
        f_number,
        background,
        dot,
        spacing,
        samples_per_axis: samples,
        seed,
    })
}

/// What `rtvis.bos` returns of `setup`'s `images`.
pub(crate) fn bos_out<'py>(
    py: Python<'py>,
    setup: &BosSetup,
    images: rt_photo::BosImages,
) -> PyResult<BosOut<'py>> {
    let (bos, rig) = (&setup.bos, &setup.rig);
    let (w, h) = (images.width, images.height);
    let c = bos.camera;
    let said = format!(
        "f/{} (working f/{:.2}), {rig}; {w}×{h} pixels",
        c.f_number,
        c.f_number * (1.0 + c.magnification()),
    );
    let disp: Vec<f64> = images.displacement.iter().flatten().copied().collect();
    let chosen = PyDict::new(py);
    chosen.set_item("focal_length", rig.focal_length)?;
    chosen.set_item("pixel", rig.pixel_pitch)?;
    chosen.set_item("distance", rig.camera_distance)?;
    chosen.set_item("background_distance", rig.background_distance)?;
    Ok((
        Array2::from_shape_vec((h, w), images.reference).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((h, w), images.flow).map_err(value_error)?.into_pyarray(py),
        Array3::from_shape_vec((h, w, 2), disp).map_err(value_error)?.into_pyarray(py),
        said,
        chosen,
    ))
}

/// `(reference [h, w], flow [h, w], I/I₀ [h, w], a line describing the
/// set-up, the rig chosen by `rtvis.focusing`'s keywords)`.
pub(crate) type FocusingOut<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    String,
    Bound<'py, PyDict>,
);

/// Focusing schlieren of `volume` ([`FocusingSetup`]).
#[pyfunction]
#[pyo3(name = "_focusing")]
#[pyo3(signature = (volume, axis_name, size, focal_length, aperture, pixel, distance, focus, source_distance, pitch, duty, angle, offset, bands, samples, seed, progress=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn focusing<'py>(
    py: Python<'py>,
    volume: &PyVolume,
    axis_name: &str,
    size: u32,
    focal_length: Option<f64>,
    aperture: Option<f64>,
    pixel: Option<f64>,
    distance: Option<f64>,
    focus: f64,
    source_distance: Option<f64>,
    pitch: Option<f64>,
    duty: f64,
    angle: f64,
    offset: f64,
    bands: Option<u32>,
    samples: u32,
    seed: u64,
    progress: Option<Py<PyAny>>,
) -> PyResult<FocusingOut<'py>> {
    let options = focusing_options(
        axis_name,
        size,
        focal_length,
        aperture,
        pixel,
        distance,
        focus,
        source_distance,
        pitch,
        duty,
        angle,
        offset,
        bands,
        samples,
    )?;
    let v = &volume.inner;
    let (setup, images) = watched(py, progress, |w| -> Result<_, rt_photo::SetupError> {
        let setup = FocusingSetup::choose(v, &options)?;
        let c = &setup.system.camera;
        let rays = (c.width * c.height) as u64 * u64::from(setup.system.aperture_samples).pow(2);
        let images = w.counting(rays, |stop| setup.render_until(v, seed, stop))?;
        Ok((setup, images))
    })?
    .map_err(setup_error)?;
    focusing_out(py, &setup, images, angle)
}

/// The options `rtvis.focusing`'s keywords give.
#[allow(clippy::too_many_arguments)]
pub(crate) fn focusing_options(
    axis_name: &str,
    size: u32,
    focal_length: Option<f64>,
    aperture: Option<f64>,
    pixel: Option<f64>,
    distance: Option<f64>,
    focus: f64,
    source_distance: Option<f64>,
    pitch: Option<f64>,
    duty: f64,
    angle: f64,
    offset: f64,
    bands: Option<u32>,
    samples: u32,
) -> PyResult<FocusingOptions> {
    Ok(FocusingOptions {
        axis: axis(axis_name)?,
        size,
        rig: FocusingRigOptions {
            focal_length,
            aperture,
            pixel_pitch: pixel,
            camera_distance: distance,
            source_distance,
            grid_pitch: pitch,
        },
        focus,
        duty,
        angle,
        offset,
        bands,
        samples_per_axis: samples,
    })
}

/// What `rtvis.focusing` returns of `setup`'s `images` (`angle`: the
/// bands' angle as the user gave it, degrees).
pub(crate) fn focusing_out<'py>(
    py: Python<'py>,
    setup: &FocusingSetup,
    images: rt_photo::FocusingImages,
    angle: f64,
) -> PyResult<FocusingOut<'py>> {
    let fs = &setup.system;
    let (w, h) = (images.width, images.height);
    let c = fs.camera;
    let z_f = c.focus_distance;
    // Shortest round-trip decimals: the pitch said here, passed back as
    // `pitch`, gives the same image.
    let said = format!(
        "f = {:e} m, aperture {:e} m (f/{:.4}), focus {:e} m from the lens, source grid at {:e} m, pitch {:e} m ({:.1} periods across the aperture's view), duty {}, angle {}°, cutoff offset {} pitch, {}×{} pixels of {:e} m",
        c.focal_length,
        c.aperture(),
        c.f_number,
        z_f,
        fs.source_distance,
        fs.grid.pitch,
        c.aperture() * (fs.source_distance - z_f) / z_f / fs.grid.pitch,
        fs.grid.duty,
        angle,
        fs.cutoff_offset,
        w,
        h,
        c.pixel_pitch
    );
    let relative = images.relative();
    let chosen = PyDict::new(py);
    chosen.set_item("focal_length", c.focal_length)?;
    chosen.set_item("aperture", c.aperture())?;
    chosen.set_item("pixel", c.pixel_pitch)?;
    chosen.set_item("distance", setup.rig.camera_distance)?;
    chosen.set_item("source_distance", fs.source_distance)?;
    chosen.set_item("pitch", fs.grid.pitch)?;
    Ok((
        Array2::from_shape_vec((h, w), images.reference).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((h, w), images.flow).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((h, w), relative).map_err(value_error)?.into_pyarray(py),
        said,
        chosen,
    ))
}
