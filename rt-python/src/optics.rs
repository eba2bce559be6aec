//! The instruments: schlieren (every cutoff), shadowgraph,
//! interferometry and colour schlieren, background-oriented and focusing
//! schlieren of a volume, set up by the library's own set-ups
//! (`rt_photo::SchlierenSetup`, `BosSetup`, `FocusingSetup`) as `rt
//! schlieren`, `rt bos` and `rt focusing` set them up: the same defaults,
//! the same automatic choices, the same image for the same options. The
//! options are checked once, there.

use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2,
    ndarray::{Array2, Array3},
};
use pyo3::prelude::*;
use rt_photo::{
    Airy, Axis, BackgroundChoice, BosOptions, BosRigOptions, BosSetup, CutoffKind, FocusingOptions,
    FocusingRigOptions, FocusingSetup, Reconstruction, SchlierenOptions, SchlierenSetup, Sensor,
};

use crate::{value_error, volume::PyVolume};

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

/// The film as `(image [h, w, 3] relative to an undisturbed beam with
/// nothing cut, in the f64 the film accumulates in, mean deflection [h, w, 2] in radians (NaN where no photon
/// landed), the mean interferometric phase [h, w] in radians (NaN where
/// no photon landed; 0 outside interferometry), the image of an
/// undisturbed beam through the optics (RGB), a line saying which optics
/// were chosen, a warning about the set-up (aliasing fringes) or None)`.
type Optics<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f32>>,
    Bound<'py, PyArray2<f64>>,
    [f32; 3],
    String,
    Option<String>,
);

/// Renders `volume` on the bench the arguments describe.
#[pyfunction]
#[pyo3(name = "_optics")]
#[pyo3(signature = (volume, cutoff_name, angle, f, h, radius, half_range, wavelength, fringe_spacing, film_distance, axis_name, size, photons, seed, estimator_name))]
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
) -> PyResult<Optics<'py>> {
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
    let v = &volume.inner;
    let (film, setup) = py
        .detach(|| -> Result<_, rt_photo::SetupError> {
            let setup = SchlierenSetup::choose(v, &options)?;
            let film = setup.render(v, seed, &mut |_, _| {})?;
            Ok((film, setup))
        })
        .map_err(value_error)?;
    let (w, h) = (film.width(), film.height());
    let rgb: Vec<f64> = film.normalized_f64().into_iter().flatten().collect();
    let eps: Vec<f32> = film
        .mean_deflection()
        .into_iter()
        .flat_map(|e| e.map_or([f32::NAN; 2], |(u, v)| [u as f32, v as f32]))
        .collect();
    let phase: Vec<f64> = film.mean_phase().into_iter().map(|p| p.unwrap_or(f64::NAN)).collect();
    let image = Array3::from_shape_vec((h, w, 3), rgb).map_err(value_error)?;
    let deflection = Array3::from_shape_vec((h, w, 2), eps).map_err(value_error)?;
    let phase = Array2::from_shape_vec((h, w), phase).map_err(value_error)?;
    Ok((
        image.into_pyarray(py),
        deflection.into_pyarray(py),
        phase.into_pyarray(py),
        setup.background(),
        setup.to_string(),
        setup.warning,
    ))
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
/// right, y down), a line describing the set-up)`.
type BosOut<'py> =
    (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray3<f64>>, String);

/// Background-oriented schlieren of `volume` ([`BosSetup`]); the
/// background is `"random"`, `"grid"`, the path of a PNG image, or
/// `image` (grey, row 0 at the top), each of its pixels `image_pixel`
/// sensor pixels as imaged (default: it spans the width).
#[pyfunction]
#[pyo3(name = "_bos")]
#[pyo3(signature = (volume, axis_name, size, focal_length, f_number, pixel, distance, background_distance, dot, spacing, samples, seed, background, image=None, image_pixel=None))]
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
) -> PyResult<BosOut<'py>> {
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
    let options = BosOptions {
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
    };
    let v = &volume.inner;
    let (setup, images) = py
        .detach(|| -> Result<_, rt_photo::SetupError> {
            let setup = BosSetup::choose(v, &options)?;
            let images = setup.render(v, seed)?;
            Ok((setup, images))
        })
        .map_err(value_error)?;
    let (bos, rig) = (&setup.bos, &setup.rig);
    let (w, h) = (images.width, images.height);
    let c = bos.camera;
    let said = format!(
        "f/{} (working f/{:.2}), {rig}; {w}×{h} pixels",
        c.f_number,
        c.f_number * (1.0 + c.magnification()),
    );
    let disp: Vec<f64> = images.displacement.iter().flatten().copied().collect();
    Ok((
        Array2::from_shape_vec((h, w), images.reference).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((h, w), images.flow).map_err(value_error)?.into_pyarray(py),
        Array3::from_shape_vec((h, w, 2), disp).map_err(value_error)?.into_pyarray(py),
        said,
    ))
}

/// `(reference [h, w], flow [h, w], I/I₀ [h, w], a line describing the
/// set-up)`.
type FocusingOut<'py> =
    (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>, String);

/// Focusing schlieren of `volume` ([`FocusingSetup`]).
#[pyfunction]
#[pyo3(name = "_focusing")]
#[pyo3(signature = (volume, axis_name, size, focal_length, aperture, pixel, distance, focus, source_distance, pitch, duty, angle, offset, bands, samples, seed))]
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
) -> PyResult<FocusingOut<'py>> {
    let options = FocusingOptions {
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
    };
    let v = &volume.inner;
    let (setup, images) = py
        .detach(|| -> Result<_, rt_photo::SetupError> {
            let setup = FocusingSetup::choose(v, &options)?;
            let images = setup.render(v, seed)?;
            Ok((setup, images))
        })
        .map_err(value_error)?;
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
    Ok((
        Array2::from_shape_vec((h, w), images.reference).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((h, w), images.flow).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((h, w), relative).map_err(value_error)?.into_pyarray(py),
        said,
    ))
}
