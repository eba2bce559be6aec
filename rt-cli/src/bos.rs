//! `rt bos`: background-oriented schlieren of a volume file: the
//! reference and flow images of a background (random dots, a dot grid or
//! a PNG image) seen through the flow by a thin-lens camera and recorded
//! by its sensor (diffraction blur optional), and the ground-truth
//! displacement.

use std::path::{Path, PathBuf};

use anyhow::Context;
use rt_photo::{
    BosOptions, BosRig, BosRigOptions, BosSetup, FilterImage, Medium, Sensor, SetupError, units::si,
};

use crate::{
    figure::{Figure, Image, Legend, significant},
    image,
    optics::{self, Axis, Interpolation, MeshOptions, Samples},
    output::Outputs,
    parse,
};

/// `rt bos FILE`: options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The volume: NRRD, raw + JSON sidecar, VTK image data, or an
    /// unstructured mesh (.vtu, legacy .vtk UNSTRUCTURED_GRID).
    pub file: PathBuf,
    /// How an unstructured mesh is read and traced.
    #[command(flatten)]
    pub mesh: MeshOptions,
    /// What the samples are.
    #[command(flatten)]
    pub samples: Samples,
    /// Interpolation between samples (`cubic`: Catmull–Rom, a smooth
    /// gradient; `rt-report bos`: 0.004 px from the paraxial relation on a
    /// bump of 10 cells' σ, where `linear` is 0.09 px off).
    #[arg(long, value_enum, default_value_t = Interpolation::Cubic)]
    pub interp: Interpolation,
    /// Light travels along this axis, from the background through the flow
    /// to the camera (the image axes are those of `rt schlieren`).
    #[arg(long, value_enum, default_value_t = Axis::Z)]
    pub axis: Axis,
    /// Image width in pixels (height follows the volume's aspect).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=i64::from(rt_photo::MAX_CAMERA_EDGE)))]
    pub size: u32,
    /// Lens focal length in metres [default: of the usual lenses (24 mm to
    /// 400 mm), the one that fills the image with the volume about 1.5 m
    /// away].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub focal_length: Option<f64>,
    /// f-number N (aperture diameter f/N): larger blurs the flow less.
    #[arg(long, default_value_t = 16.0, value_parser = parse::positive, allow_hyphen_values = true)]
    pub f_number: f64,
    /// Pitch of an image pixel on the sensor, metres [default: a 2048 ×
    /// 5.5e-6 m sensor (11.3 mm) binned to --size pixels].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub pixel: Option<f64>,
    /// Distance from the lens to the volume's centre (Z_A) in metres
    /// [default: the volume's cross-section fills the image width].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub distance: Option<f64>,
    /// Distance from the volume's centre to the background (Z_D) in
    /// metres [default: chosen from a survey of the flow's deflections so
    /// that their 99th percentile moves the image 4 px, between 0.6× the
    /// volume's depth and 2 Z_A].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub background_distance: Option<f64>,
    /// The background: `random` dots, a `grid` of dots (both sized by
    /// --dot and --spacing), or the path of a PNG image (grey or colour,
    /// read as linear luminance: 0 black, 1 white).
    #[arg(long, default_value = "random", value_parser = background)]
    pub background: BackgroundChoice,
    /// A background image's pixel as imaged, in sensor pixels [default:
    /// the image spans the sensor's width].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub background_pixel: Option<f64>,
    /// Dot diameter on the image, pixels (full width at half maximum).
    #[arg(long, default_value_t = 3.0, value_parser = parse::positive, allow_hyphen_values = true)]
    pub dot: f64,
    /// Distance between dots on the image, pixels.
    #[arg(long, default_value_t = 4.0, value_parser = parse::positive, allow_hyphen_values = true)]
    pub spacing: f64,
    /// k: k × k stratified aperture samples per pixel.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=i64::from(rt_photo::MAX_APERTURE_SAMPLES)))]
    pub samples_per_axis: u32,
    /// Sensor: electrons at the brightest dot's centre (about 1 in the
    /// background's units).
    #[arg(long, default_value_t = 8000.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub exposure: f64,
    /// Sensor full well, electrons.
    #[arg(long, default_value_t = 10000.0, value_parser = parse::positive, allow_hyphen_values = true)]
    pub full_well: f64,
    /// Sensor bit depth (8: 8-bit PNGs; more: 16-bit PNGs).
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub bits: u32,
    /// Photon shot noise (Poisson).
    #[arg(long)]
    pub shot_noise: bool,
    /// Read noise, electrons rms.
    #[arg(long, default_value_t = 0.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub read_noise: f64,
    /// Diffraction blur: the sensor records the images blurred by the
    /// lens's Airy pattern (first dark ring 2.44 λ N(1 + M) across, N(1 +
    /// M) the working f-number).
    #[arg(long)]
    pub airy: bool,
    /// Wavelength in metres (of --airy's diffraction).
    #[arg(long, default_value = "532e-9", value_parser = parse::positive, allow_hyphen_values = true)]
    pub wavelength: f64,
    /// Seed of the dots, the samples and the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output stem: writes `<stem>-reference.png`, `<stem>-flow.png`,
    /// `<stem>-displacement.png` (hue: direction, saturation: size, with
    /// its colour wheel) and `<stem>-displacement.json` + `.raw` (float32
    /// Δx, Δy per pixel, in pixels, x right and y down). The displacement
    /// is the ground truth in the convention of PIV/BOS software: the
    /// apparent motion of the background pattern from the reference image
    /// to the flow image.
    #[arg(long, default_value = "out/bos.png")]
    pub out: PathBuf,
}

/// Runs `rt bos`.
///
/// # Errors
/// An unreadable or unsuitable volume, a bad set-up, an unwritable output.
pub fn run(a: &Args) -> anyhow::Result<()> {
    render(&optics::open(&a.file, a.samples, false, a.interp, &a.mesh)?, a)
}

/// Renders `volume` as `a` says (its file and sample options aside),
/// writes the images and prints one summary line.
///
/// # Errors
/// A bad set-up or an unwritable output.
pub fn render(medium: &Medium, a: &Args) -> anyhow::Result<()> {
    let t = std::time::Instant::now();
    Outputs::refuse_folder(&a.out)?;
    let paths = [
        image::beside(&a.out, "reference"),
        image::beside(&a.out, "flow"),
        image::beside(&a.out, "displacement"),
    ];
    let raw = a.out.with_file_name(format!(
        "{}-displacement.raw",
        a.out.file_stem().map_or("bos".into(), |s| s.to_string_lossy())
    ));
    // Before any work: an impossible --out fails now, not after the render.
    let mut targets = paths.to_vec();
    targets.extend([raw.clone(), raw.with_extension("json")]);
    let outs = Outputs::check(&targets)?;
    let setup = prepare(medium, a)?;
    let (bos, rig) = (&setup.bos, &setup.rig);
    let camera = bos.camera;
    let (w, h) = (camera.width, camera.height);
    let images = setup.render(medium, a.seed)?;
    let sensor = Sensor {
        exposure: a.exposure,
        full_well: a.full_well,
        bits: a.bits,
        shot_noise: a.shot_noise,
        read_noise: a.read_noise,
        airy: a.airy.then(|| camera.airy(a.wavelength)),
    };
    let (w32, h32) = (w as u32, h as u32);
    let reference = sensor.record(&images.reference, w, h, a.seed)?;
    let flow = sensor.record(&images.flow, w, h, a.seed.wrapping_add(1))?;
    image::write_counts(&reference, a.bits, w32, h32, &outs.staging(&paths[0]))?;
    image::write_counts(&flow, a.bits, w32, h32, &outs.staging(&paths[1]))?;
    let mut sorted: Vec<f64> = images.displacement.iter().map(|d| d[0].hypot(d[1])).collect();
    sorted.sort_by(f64::total_cmp);
    let max = sorted.last().copied().unwrap_or(0.0);
    let p99 = sorted[((sorted.len() - 1) as f64 * 0.99) as usize];
    let figure = outs.staging(&paths[2]);
    displacement_figure(&images.displacement, (w32, h32), p99, max, (rig, a.f_number), &figure)
        .with_context(|| paths[2].display().to_string())?;
    let flat: Vec<f64> = images.displacement.iter().flatten().copied().collect();
    image::write_raw_f32(
        &outs,
        &raw,
        &flat,
        2,
        w,
        h,
        "BOS ground-truth displacement (dx, dy) per pixel, in pixels, x right and y down, rows top first: the apparent motion of the background pattern from the reference image to the flow image (the convention of PIV/BOS software)",
    )?;
    outs.commit()?;
    let background = match &a.background {
        BackgroundChoice::Random => "random dots".to_string(),
        BackgroundChoice::Grid => "a dot grid".to_string(),
        BackgroundChoice::Image(p) => p.display().to_string(),
    };
    let airy = sensor.airy.map_or(String::new(), |d| {
        format!("; Airy disc {:.2} px across", 2.0 * d.first_dark_ring())
    });
    println!(
        "wrote {}, {}, {}, {} ({w}×{h}, {} rays in {:.2} s; f/{}, {rig}; background {background}{airy}; displacement 99th percentile {p99:.3} px, max {max:.3} px)",
        paths[0].display(),
        paths[1].display(),
        paths[2].display(),
        raw.with_extension("json").display(),
        w * h * (a.samples_per_axis * a.samples_per_axis) as usize,
        t.elapsed().as_secs_f64(),
        a.f_number,
    );
    Ok(())
}

/// The displacement as a figure: hue = direction, saturation = size up to
/// the 99th percentile `p99` (beyond it, full colour), and its wheel.
fn displacement_figure(
    field: &[[f64; 2]],
    (w, h): (u32, u32),
    p99: f64,
    max: f64,
    (rig, f_number): (&BosRig, f64),
    path: &Path,
) -> anyhow::Result<()> {
    // A field with (almost) nothing moving: scale to the maximum, so the
    // wheel still has a size.
    let (rim, note) = if p99 > 1e-3 * max && p99 > 0.0 {
        (p99, "99th percentile")
    } else {
        (max.max(1e-6), "maximum")
    };
    let wheel = FilterImage::hue_wheel(256, rim);
    let rgb: Vec<u8> = field
        .iter()
        .flat_map(|d| {
            // Clamped to the rim, so the largest 1 % keep their hue. The
            // wheel's up is the image's −y.
            let k = (rim / d[0].hypot(d[1])).min(1.0);
            let c = wheel.at(k * d[0] * 0.999_999, -k * d[1] * 0.999_999);
            c.map(|x| (rt_core::frame::linear_to_srgb(x.clamp(0.0, 1.0)) * 255.0).round() as u8)
        })
        .collect();
    let fig = Figure {
        image: Image::from_rgb8(w, h, rgb),
        title: "BOS displacement, reference → flow (ground truth)".into(),
        subtitle: format!(
            "f = {} at f/{}, Z_A = {}, Z_D = {}, pixels of {}; |Δ| up to {} px",
            si(rig.focal_length, "m"),
            f_number,
            si(rig.camera_distance, "m"),
            si(rig.background_distance, "m"),
            si(rig.pixel_pitch, "m"),
            significant(max)
        ),
        axes: None,
        legend: Legend::DisplacementWheel { filter: wheel, rim_note: note.into() },
    };
    Ok(fig.write(path)?)
}

/// The library's set-up for `a` ([`BosSetup::choose`]: the rig, camera
/// and background chosen from the medium where `a` leaves them out), the
/// background image read from its PNG.
///
/// # Errors
/// An unreadable background image, or what [`BosSetup::choose`] refuses.
pub fn prepare(medium: &Medium, a: &Args) -> anyhow::Result<BosSetup> {
    let background = match &a.background {
        BackgroundChoice::Random => rt_photo::BackgroundChoice::Random,
        BackgroundChoice::Grid => rt_photo::BackgroundChoice::Grid,
        BackgroundChoice::Image(path) => {
            rt_photo::BackgroundChoice::read_png(path, a.background_pixel)?
        }
    };
    let options = BosOptions {
        axis: a.axis.into(),
        size: a.size,
        rig: BosRigOptions {
            focal_length: a.focal_length,
            pixel_pitch: a.pixel,
            camera_distance: a.distance,
            background_distance: a.background_distance,
        },
        f_number: a.f_number,
        background,
        dot: a.dot,
        spacing: a.spacing,
        samples_per_axis: a.samples_per_axis,
        seed: a.seed,
    };
    BosSetup::choose(medium, &options).map_err(|e| match &a.background {
        BackgroundChoice::Image(path) if matches!(e, SetupError::Bos(_)) => {
            anyhow::Error::new(e).context(path.display().to_string())
        }
        _ => e.into(),
    })
}

/// What `--background` names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BackgroundChoice {
    /// `random`: random dots.
    Random,
    /// `grid`: a regular grid of dots.
    Grid,
    /// A PNG image's path.
    Image(PathBuf),
}

/// `random`, `grid`, or a path.
fn background(s: &str) -> Result<BackgroundChoice, String> {
    Ok(match s {
        "random" => BackgroundChoice::Random,
        "grid" => BackgroundChoice::Grid,
        "" => return Err("`random`, `grid` or the path of a PNG image".into()),
        path => BackgroundChoice::Image(PathBuf::from(path)),
    })
}
