//! `rt focusing`: focusing schlieren of a volume file: a lens-and-grid
//! system (a grid of bright bands behind the flow, its negative as the
//! cutoff) focused on a plane in the flow, which it shows sharply while
//! what lies before and behind it blurs away.

use std::path::PathBuf;

use rt_photo::{
    FocusingImages, FocusingOptions, FocusingRigOptions, FocusingSetup, Medium, Sensor,
};

use crate::{
    image,
    optics::{self, Axis, Interpolation, MeshOptions, Samples},
    output::Outputs,
    parse,
};

/// `rt focusing FILE`: options.
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
    /// Light travels along this axis, from the source grid through the
    /// flow to the lens (the image axes are those of `rt schlieren`).
    #[arg(long, value_enum, default_value_t = Axis::Z)]
    pub axis: Axis,
    /// Image width in pixels (height follows the volume's aspect).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=i64::from(rt_photo::MAX_CAMERA_EDGE)))]
    pub size: u32,
    /// Schlieren lens focal length in metres [default: a quarter of
    /// --distance, so f/2 at the default aperture].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub focal_length: Option<f64>,
    /// Schlieren lens aperture diameter in metres [default: f/2, an eighth
    /// of --distance]: larger
    /// focuses more sharply (depth of sharp focus ≈ 2·w·Z/D for a feature
    /// of width w at distance Z).
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub aperture: Option<f64>,
    /// Pitch of a pixel in the schlieren lens's image plane (relayed to a
    /// camera), metres [default: the volume's width and 5 % fill the
    /// image].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub pixel: Option<f64>,
    /// Distance from the lens to the volume's centre in metres [default:
    /// twice the volume's width across the image].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub distance: Option<f64>,
    /// The plane in focus: its distance from the volume's centre toward
    /// the lens, metres (negative: beyond the centre).
    #[arg(long, default_value_t = 0.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub focus: f64,
    /// Distance from the lens to the source grid in metres [default:
    /// twice the focus distance].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub source_distance: Option<f64>,
    /// Source grid pitch on its plane, metres [default: from a survey of
    /// the flow, so that the strongest 1 % of deflections across the bands
    /// use 80 % of the linear range (finer saturates them, then repeats),
    /// kept to 25–100 periods across the aperture's view of the source
    /// plane, so the undisturbed image is flat].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub pitch: Option<f64>,
    /// Bright fraction of each period of the source grid, in (0, 1).
    #[arg(long, default_value_t = 0.5, value_parser = parse::finite, allow_hyphen_values = true)]
    pub duty: f64,
    /// Band orientation, degrees: 0 = bands along the image's vertical,
    /// sensitive to horizontal deflection.
    #[arg(long, default_value_t = 0.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub angle: f64,
    /// The cutoff grid's shift across the bands, in pitches: the
    /// sensitivity (0: dark field; up to min(duty, 1 − duty)).
    #[arg(long, default_value_t = 0.25, value_parser = parse::finite, allow_hyphen_values = true)]
    pub offset: f64,
    /// Number of bands, centred on the axis [default: unbounded]. Each
    /// point of the image sees the source plane through the lens, so a
    /// few bands light only the part of the image that sees them.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub bands: Option<u32>,
    /// k: k² aperture samples per pixel (stripes along the bands).
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=i64::from(rt_photo::MAX_APERTURE_SAMPLES)))]
    pub samples_per_axis: u32,
    /// Sensor: electrons at the undisturbed background.
    #[arg(long, default_value_t = 5000.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub exposure: f64,
    /// Sensor full well, electrons.
    #[arg(long, default_value_t = 10000.0, value_parser = parse::positive, allow_hyphen_values = true)]
    pub full_well: f64,
    /// Sensor bit depth (8: an 8-bit PNG; more: 16-bit).
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub bits: u32,
    /// Photon shot noise (Poisson).
    #[arg(long)]
    pub shot_noise: bool,
    /// Read noise, electrons rms.
    #[arg(long, default_value_t = 0.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub read_noise: f64,
    /// Seed of the samples and the noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output: the image as the sensor records it (PNG; the undisturbed
    /// background at `--exposure`), and beside it `<stem>.raw` + `.json`
    /// (float32 I/I₀ per pixel: 1 = undisturbed, and where no band lights
    /// the pixel even without the flow).
    #[arg(long, default_value = "out/focusing.png")]
    pub out: PathBuf,
}

/// Runs `rt focusing`.
///
/// # Errors
/// An unreadable or unsuitable volume, a bad set-up, an unwritable output.
pub fn run(a: &Args) -> anyhow::Result<()> {
    render(&optics::open(&a.file, a.samples, false, a.interp, &a.mesh)?, a).map(drop)
}

/// Renders `volume` as `a` says (its file and sample options aside),
/// writes the image and prints one summary line.
///
/// # Errors
/// A bad set-up or an unwritable output.
pub fn render(medium: &Medium, a: &Args) -> anyhow::Result<FocusingImages> {
    let t = std::time::Instant::now();
    let raw = a.out.with_extension("raw");
    // Before any work: an impossible --out fails now, not after the render.
    let outs = Outputs::check(&[a.out.clone(), raw.clone(), raw.with_extension("json")])?;
    let setup = prepare(medium, a)?;
    let cam = setup.system.camera;
    let (w, h) = (cam.width, cam.height);
    let images = setup.render(medium, a.seed)?;
    let relative = images.relative();
    // The sensor records the light, scaled so that the undisturbed
    // background (the mean over the pixels the source lights) collects
    // `--exposure` electrons: pixels the bands cannot reach stay dark.
    let lit: Vec<f64> = images.reference.iter().copied().filter(|r| *r > 1e-12).collect();
    let background = if lit.is_empty() { 1.0 } else { lit.iter().sum::<f64>() / lit.len() as f64 };
    let light: Vec<f64> = images.flow.iter().map(|f| f / background).collect();
    let sensor = Sensor {
        exposure: a.exposure,
        full_well: a.full_well,
        bits: a.bits,
        shot_noise: a.shot_noise,
        read_noise: a.read_noise,
        airy: None,
    };
    let counts = sensor.record(&light, w, h, a.seed)?;
    image::write_counts(&counts, a.bits, w as u32, h as u32, &outs.staging(&a.out))?;
    image::write_raw_f32(
        &outs,
        &raw,
        &relative,
        1,
        w,
        h,
        "focusing schlieren: I/I0 per pixel (1 = undisturbed, and where the source lights nothing), rows top first",
    )?;
    outs.commit()?;
    let mut sorted: Vec<f64> = relative.iter().map(|v| (v - 1.0).abs()).collect();
    sorted.sort_by(f64::total_cmp);
    let p99 = sorted[((sorted.len() - 1) as f64 * 0.99) as usize];
    println!(
        "wrote {}, {} ({w}×{h}, {} rays in {:.2} s; {setup}; |I/I₀ − 1| 99th percentile {p99:.3})",
        a.out.display(),
        raw.with_extension("json").display(),
        w * h * (a.samples_per_axis * a.samples_per_axis) as usize,
        t.elapsed().as_secs_f64(),
    );
    Ok(images)
}

/// The library's set-up for `a` ([`FocusingSetup::choose`]: the rig and
/// grid chosen from the medium where `a` leaves them out).
///
/// # Errors
/// What [`FocusingSetup::choose`] refuses.
pub fn prepare(medium: &Medium, a: &Args) -> anyhow::Result<FocusingSetup> {
    let options = FocusingOptions {
        axis: a.axis.into(),
        size: a.size,
        rig: FocusingRigOptions {
            focal_length: a.focal_length,
            aperture: a.aperture,
            pixel_pitch: a.pixel,
            camera_distance: a.distance,
            source_distance: a.source_distance,
            grid_pitch: a.pitch,
        },
        focus: a.focus,
        duty: a.duty,
        angle: a.angle,
        offset: a.offset,
        bands: a.bands,
        samples_per_axis: a.samples_per_axis,
    };
    Ok(FocusingSetup::choose(medium, &options)?)
}
