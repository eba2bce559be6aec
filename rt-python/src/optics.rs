//! The optical bench: schlieren (every cutoff), shadowgraph,
//! interferometry and colour schlieren of a volume, set up as `rt
//! schlieren` sets it up (the same defaults, the same automatic exposure,
//! the same photons), so both give the same image for the same options;
//! background-oriented and focusing schlieren set up by `rt bos`'s and `rt
//! focusing`'s own option parsers, for the same reason.

use std::path::PathBuf;

use clap::ValueEnum;
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2,
    ndarray::{Array2, Array3},
};
use pyo3::prelude::*;
use rt_cli::{
    optics::{Axis, Interpolation, MeshOptions, Quantity, Samples, Source},
    schlieren::{Args, CutoffKind, Estimator, prepare},
};
use rt_photo::{Airy, Bench, ImageBackground, Mode, Reconstruction, Sensor};
use rt_volume::GLADSTONE_DALE_AIR;

use crate::{value_error, volume::PyVolume};

/// Longest image side, as `rt schlieren --size` allows.
const MAX_EDGE: u32 = 16384;

/// The value of enum `E` named `s` (as the command line spells it).
fn parse<E: ValueEnum>(what: &str, s: &str) -> PyResult<E> {
    E::from_str(s, false).map_err(|_| {
        let known: Vec<String> = E::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_string()))
            .collect();
        value_error(format!("{what}: unknown `{s}` (known: {})", known.join(", ")))
    })
}

/// A `ValueError` carrying the first line of what clap says about bad
/// command-line arguments.
fn command_line_error(e: clap::Error) -> PyErr {
    value_error(e.to_string().lines().next().unwrap_or_default().trim_start_matches("error: "))
}

/// `Err` unless `v` is finite and `> 0`.
fn positive(name: &str, v: f64) -> PyResult<f64> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(value_error(format!("{name} must be finite and > 0 (got {v})")))
    }
}

/// The film as `(image [h, w, 3] relative to an undisturbed beam with
/// nothing cut, in the f64 the film accumulates in, mean deflection [h, w, 2] in radians (NaN where no photon
/// landed), the mean interferometric phase [h, w] in radians (NaN where
/// no photon landed; 0 outside interferometry), the image of an
/// undisturbed beam through the optics (RGB), a line saying which optics
/// were chosen)`.
type Optics<'py> = (
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f32>>,
    Bound<'py, PyArray2<f64>>,
    [f32; 3],
    String,
);

/// Renders `volume` on the bench the arguments describe.
#[pyfunction]
#[pyo3(name = "_optics")]
#[pyo3(signature = (volume, cutoff, angle, f, h, radius, half_range, wavelength, fringe_spacing, film_distance, axis, size, photons, seed, estimator))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn optics<'py>(
    py: Python<'py>,
    volume: &PyVolume,
    cutoff: &str,
    angle: f64,
    f: f64,
    h: Option<f64>,
    radius: Option<f64>,
    half_range: Option<f64>,
    wavelength: f64,
    fringe_spacing: Option<f64>,
    film_distance: Option<f64>,
    axis: &str,
    size: u32,
    photons: u32,
    seed: u64,
    estimator: &str,
) -> PyResult<Optics<'py>> {
    if !angle.is_finite() {
        return Err(value_error(format!("angle must be finite (got {angle})")));
    }
    if let Some(d) = film_distance.filter(|d| !d.is_finite()) {
        return Err(value_error(format!("film_distance must be finite (got {d})")));
    }
    if !(1..=MAX_EDGE).contains(&size) {
        return Err(value_error(format!("size must be 1 to {MAX_EDGE} pixels (got {size})")));
    }
    if !(1..=65536).contains(&photons) {
        return Err(value_error(format!("photons must be 1 to 65536 per pixel (got {photons})")));
    }
    let args = Args {
        file: PathBuf::new(),
        samples: Samples { quantity: Quantity::Density, k: GLADSTONE_DALE_AIR },
        allow_nonphysical: false,
        cutoff: parse::<CutoffKind>("cutoff", cutoff)?,
        angle,
        f: positive("f", f)?,
        h: h.map(|v| positive("h", v)).transpose()?,
        radius: radius.map(|v| positive("radius", v)).transpose()?,
        half_range: half_range.map(|v| positive("half_range", v)).transpose()?,
        lambda: positive("wavelength", wavelength)?,
        fringes: fringe_spacing.map(|v| positive("fringe_spacing", v)).transpose()?,
        film_distance,
        axis: parse::<Axis>("axis", axis)?,
        size,
        photons,
        estimator: parse::<Estimator>("estimator", estimator)?,
        interp: Interpolation::Linear,
        mesh: MeshOptions::default(),
        seed,
        out: PathBuf::new(),
        figure: false,
        no_figure: true,
        raw16: false,
    };
    let v = &volume.inner;
    let (film, background, chosen) = py
        .detach(|| -> anyhow::Result<_> {
            let (bench, chosen) = prepare(v, &args)?;
            let bench = match args.estimator {
                Estimator::Sheet => bench,
                Estimator::Photons => Bench { reconstruction: Reconstruction::Photons, ..bench },
            };
            let background = match &bench.mode {
                Mode::Schlieren(c) => c.transmit(0.0, 0.0),
                // Infinite fringe: the undisturbed beam is bright.
                Mode::Interferometry { .. } => [1.0; 3],
            };
            let (film, _) = v.render(&bench, size as usize, photons, seed)?;
            Ok((film, background, chosen))
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
        background,
        chosen,
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

/// Background-oriented schlieren of `volume`, set up by `rt bos`'s own
/// options (`args`: its command-line arguments after the file); `image`
/// (grey, row 0 at the top) replaces the background, each of its pixels
/// `image_pixel` sensor pixels as imaged (default: it spans the width).
#[pyfunction]
#[pyo3(name = "_bos")]
#[pyo3(signature = (volume, args, image=None, image_pixel=None))]
pub(crate) fn bos<'py>(
    py: Python<'py>,
    volume: &PyVolume,
    args: Vec<String>,
    image: Option<PyReadonlyArray2<'py, f64>>,
    image_pixel: Option<f64>,
) -> PyResult<BosOut<'py>> {
    let a = rt_cli::bos::Args::from_args(std::path::Path::new("volume"), args)
        .map_err(command_line_error)?;
    let v = &volume.inner;
    let image = image.map(|i| {
        let view = i.as_array();
        let (h, w) = view.dim();
        (w, h, view.iter().copied().collect::<Vec<f64>>())
    });
    let (bos, rig, images) = py
        .detach(|| -> anyhow::Result<_> {
            let (mut bos, rig) = rt_cli::bos::prepare(v, &a)?;
            if let Some((w, h, samples)) = image {
                let px = image_pixel.unwrap_or(bos.camera.width as f64 / w as f64);
                bos.background =
                    ImageBackground::for_camera(&bos.camera, w, h, samples, px)?.into();
            }
            let images = v.bos(&bos, a.seed)?;
            Ok((bos, rig, images))
        })
        .map_err(value_error)?;
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

/// Focusing schlieren of `volume`, set up by `rt focusing`'s own options
/// (`args`: its command-line arguments after the file), so every default
/// and every automatic choice (the grid's pitch from a survey of the flow)
/// is the command line's.
#[pyfunction]
#[pyo3(name = "_focusing")]
#[pyo3(signature = (volume, args))]
pub(crate) fn focusing<'py>(
    py: Python<'py>,
    volume: &PyVolume,
    args: Vec<String>,
) -> PyResult<FocusingOut<'py>> {
    let a = rt_cli::focusing::Args::from_args(std::path::Path::new("volume"), args)
        .map_err(command_line_error)?;
    let v = &volume.inner;
    let (fs, images) = py
        .detach(|| -> anyhow::Result<_> {
            let (fs, _) = rt_cli::focusing::prepare(v, &a)?;
            let images = v.focusing(&fs, a.seed)?;
            Ok((fs, images))
        })
        .map_err(value_error)?;
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
        a.angle,
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
