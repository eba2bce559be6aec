//! `rt schlieren`: synthetic schlieren, shadowgraph, interferogram or
//! colour schlieren of a volume file, with automatic exposure.

use std::path::PathBuf;

use anyhow::{Context, bail};
use clap::ValueEnum;
use rt_core::Frame;
use rt_photo::{Bench, Cutoff, Film, FilterImage, Mode, Reconstruction};
use rt_volume::{
    glam::DVec3,
    io::{is_unstructured, read_grid},
};

use crate::{
    figure::{self, Figure, Legend},
    image,
    optics::{Axis, Interpolation, MeshOptions, Samples, Source, Survey, Volume},
    parse,
};

/// The optical set-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CutoffKind {
    /// Knife edge across the `--angle` direction (classic schlieren).
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

/// `rt schlieren FILE`: options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The volume: NRRD (.nrrd/.nhdr), raw + JSON sidecar (.json/.raw),
    /// VTK image data (.vtk/.vti), or an unstructured mesh (.vtu, or a
    /// legacy .vtk UNSTRUCTURED_GRID: tetrahedra, pyramids, wedges,
    /// hexahedra), traced as `--mesh` says.
    pub file: PathBuf,
    /// What the samples are.
    #[command(flatten)]
    pub samples: Samples,
    /// Accept densities ≤ 0 (or indices below 1) instead of refusing them.
    #[arg(long)]
    pub allow_nonphysical: bool,
    /// The optical set-up.
    #[arg(long, value_enum, default_value_t = CutoffKind::Knife)]
    pub cutoff: CutoffKind,
    /// Direction the knife edge or graded filter is sensitive to, in
    /// degrees from the image's horizontal axis.
    #[arg(long, default_value_t = 0.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub angle: f64,
    /// Focal length of the schlieren head, in metres.
    #[arg(long, default_value_t = 1.0, value_parser = parse::positive, allow_hyphen_values = true)]
    pub f: f64,
    /// Source image height (knife edge) or ramp width (graded filter) in
    /// metres [default: automatic, the 99th percentile of the deflection
    /// maps to 0.45 of the range].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub h: Option<f64>,
    /// Stop radius in the focal plane (pinhole, dark field), in metres
    /// [default: automatic, a quarter of the 99th-percentile deflection
    /// times f].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub radius: Option<f64>,
    /// Colour filter half range: the deflection at the wheel's rim, in
    /// radians [default: automatic, the 99th-percentile deflection].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub half_range: Option<f64>,
    /// Interferometry wavelength in metres (CO₂ laser: 10.6e-6).
    #[arg(long, default_value_t = 10.6e-6, value_parser = parse::positive, allow_hyphen_values = true)]
    pub lambda: f64,
    /// Interferometry fringe spacing on the film in metres [default:
    /// infinite fringe].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub fringes: Option<f64>,
    /// Film distance behind the volume, in metres [default: automatic for
    /// a shadowgraph (--cutoff none), the strongest contrast about 0.5; 0
    /// otherwise].
    #[arg(long, value_parser = parse::finite, allow_hyphen_values = true)]
    pub film_distance: Option<f64>,
    /// Beam direction.
    #[arg(long, value_enum, default_value_t = Axis::Z)]
    pub axis: Axis,
    /// Image width in pixels (height follows the volume's aspect).
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=i64::from(parse::MAX_EDGE)))]
    pub size: u32,
    /// Photons per pixel. Each pass traces a k×k lattice of photons per
    /// pixel (k = 2 up to 63 photons, 4 from 64, 8 from 256: at least four
    /// passes), shifted from pass to pass; each lattice cell carries its
    /// light onto the film where its corners land, by exact area, so an
    /// undisturbed beam has no grain at all and more photons sharpen the
    /// image rather than average noise. Rounded up to whole passes.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub photons: u32,
    /// How photons become the image: `sheet` (each pass's lattice of
    /// photons carried onto the film by exact area: no grain) or `photons`
    /// (each photon splatted alone with a tent filter: grainy, the classic
    /// Monte Carlo estimate, for comparison).
    #[arg(long, value_enum, default_value_t = Estimator::Sheet)]
    pub estimator: Estimator,
    /// Interpolation between samples (grids).
    #[arg(long, value_enum, default_value_t = Interpolation::Linear)]
    pub interp: Interpolation,
    /// How an unstructured mesh is read and traced.
    #[command(flatten)]
    pub mesh: MeshOptions,
    /// Seed of every random choice: the same seed gives the same image.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// PNG to write (8-bit sRGB, the undisturbed background mid grey, or
    /// white for the colour filter).
    #[arg(long, default_value = "out/schlieren.png")]
    pub out: PathBuf,
    /// Also write `<stem>-figure.png` beside it: the image with axes in
    /// metres, tick values, a scale bar, the optics in its title and, for
    /// the colour filter, the deflection wheel [default: on].
    #[arg(long, overrides_with = "no_figure")]
    pub figure: bool,
    /// Skip the figure.
    #[arg(long, overrides_with = "figure")]
    pub no_figure: bool,
    /// Also write `<stem>-16bit.png`: linear 16-bit samples, 32768 × the
    /// intensity relative to an undisturbed beam with nothing cut (a knife
    /// edge's background reads 16384, a shadowgraph's 32768); grey, RGB
    /// for the colour filter.
    #[arg(long)]
    pub raw16: bool,
}

/// How photons become the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Estimator {
    /// The lattice of each pass as a sheet, by exact area.
    Sheet,
    /// Photons splatted one by one with a tent filter.
    Photons,
}

/// The most photons one run may trace.
const MAX_PHOTONS: u64 = 1 << 36;

/// The cutoff or mode for `args`, its parameters chosen from `survey` where
/// the user left them out; returns a line saying what was chosen.
fn optics(a: &Args, survey: &Survey, n_ref: f64) -> (Mode, f64, String) {
    let angle = a.angle.to_radians();
    // Knife edge and graded filter: 0.5 ± 0.45 at the 99th percentile.
    let eps_perp = survey.along(angle, 0.99).max(1e-12);
    let eps = survey.magnitude(0.99).max(1e-12);
    let f = a.f;
    let film = a.film_distance.unwrap_or(0.0);
    match a.cutoff {
        CutoffKind::Knife => {
            let h = a.h.unwrap_or(f * eps_perp / 0.45);
            let mode = Mode::Schlieren(Cutoff::KnifeEdge { angle, offset: 0.0, f, h });
            (mode, film, format!("knife edge at {} deg, f = {f} m, h = {h:.4e} m", a.angle))
        }
        CutoffKind::Graded => {
            let width = a.h.unwrap_or(f * eps_perp / 0.45);
            let mode = Mode::Schlieren(Cutoff::Graded { angle, f, width });
            (mode, film, format!("graded filter at {} deg, f = {f} m, h = {width:.4e} m", a.angle))
        }
        CutoffKind::Pinhole | CutoffKind::DarkField => {
            let radius = a.radius.unwrap_or(0.25 * f * eps);
            let dark_field = a.cutoff == CutoffKind::DarkField;
            let mode = Mode::Schlieren(Cutoff::Pinhole { f, radius, dark_field });
            let what = if dark_field { "dark-field stop" } else { "pinhole" };
            (mode, film, format!("{what}, f = {f} m, radius = {radius:.4e} m"))
        }
        CutoffKind::Color => {
            let half = a.half_range.unwrap_or(eps);
            let mode = Mode::Schlieren(Cutoff::Color(FilterImage::hue_wheel(256, half)));
            (mode, film, format!("colour filter, half range = {half:.4e} rad"))
        }
        CutoffKind::None => {
            let div = survey.divergence(0.99);
            let l = a.film_distance.unwrap_or(if div > 0.0 { 0.5 / div } else { 0.0 });
            (Mode::Schlieren(Cutoff::None), l, format!("no cutoff, film distance = {l:.4} m"))
        }
        CutoffKind::Interferometry => {
            let mode = Mode::Interferometry { lambda: a.lambda, n_ref, fringe_spacing: a.fringes };
            let fringes =
                a.fringes.map_or("infinite fringe".to_string(), |s| format!("fringes {s} m"));
            (mode, film, format!("interferometry, λ = {} m, n_ref = {n_ref}, {fringes}", a.lambda))
        }
    }
}

/// Runs `rt schlieren`.
///
/// # Errors
/// An unreadable or unsuitable volume, bad optics, too many photons, an
/// unwritable output.
pub fn run(a: &Args) -> anyhow::Result<()> {
    if is_unstructured(&a.file) {
        return render(&a.mesh.load(&a.file, a.samples, a.allow_nonphysical)?, a);
    }
    let grid = read_grid(&a.file)?;
    let volume = Volume::new(grid, a.samples.quantity, a.samples.k, a.allow_nonphysical, a.interp)
        .with_context(|| a.file.display().to_string())?;
    render(&volume, a)
}

/// The bench `a` describes for `volume`, its optics chosen from a survey
/// of the deflections where `a` leaves them out, and a line saying what
/// was chosen (every user-facing render goes through here: the CLI, the
/// demo, the report's noise measurement).
///
/// # Errors
/// Too many photons for one run; a failing survey.
pub fn prepare(volume: &impl Source, a: &Args) -> anyhow::Result<(Bench, String)> {
    let probe = volume.bench(a.axis, Mode::Schlieren(Cutoff::None), 0.0);
    let height = ((f64::from(a.size)) * probe.height / probe.width).round().max(1.0);
    let photons = u64::from(a.size) * height as u64 * crate::optics::traced_per_pixel(a.photons);
    if photons > MAX_PHOTONS {
        bail!(
            "{photons} photons is more than one run traces ({MAX_PHOTONS}); lower --size or --photons"
        );
    }
    let survey = volume.survey(&probe)?;
    let n_ref = volume.n_ref();
    let (mode, film_distance, chosen) = optics(a, &survey, n_ref);
    if let Mode::Interferometry { lambda, fringe_spacing, .. } = mode {
        // Phase step per pixel: the deflection is the phase gradient over k.
        let pixel = probe.width / f64::from(a.size);
        let tau = std::f64::consts::TAU;
        let step = tau / lambda * survey.magnitude(0.99) * pixel
            + fringe_spacing.map_or(0.0, |s| tau * pixel / s);
        if step > std::f64::consts::PI {
            eprintln!(
                "rt: warning: fringes alias: up to {step:.1} rad of phase per pixel (> π); raise --size or --lambda"
            );
        }
    }
    Ok((volume.bench(a.axis, mode, film_distance), chosen))
}

/// Renders `volume` as `a` says (its file and sample options aside) and
/// writes the PNG; prints one summary line.
///
/// # Errors
/// Bad optics, too many photons, an unwritable output.
pub fn render(volume: &impl Source, a: &Args) -> anyhow::Result<()> {
    let (bench, chosen) = prepare(volume, a)?;
    let bench = match a.estimator {
        Estimator::Sheet => bench,
        Estimator::Photons => Bench { reconstruction: Reconstruction::Photons, ..bench },
    };
    let (film, seconds) = volume.render(&bench, a.size as usize, a.photons, a.seed)?;
    let scale = if matches!(bench.mode, Mode::Schlieren(Cutoff::None)) { 0.5 } else { 1.0 };
    let frame = image::film_frame(&film, scale)?;
    image::write_png(&frame, &a.out)?;
    let mut written = vec![a.out.clone()];
    if a.raw16 {
        let path = image::beside(&a.out, "16bit");
        let color = matches!(bench.mode, Mode::Schlieren(Cutoff::Color(_)));
        image::write_film16(&film, color, &path)?;
        written.push(path);
    }
    if !a.no_figure {
        let path = image::beside(&a.out, "figure");
        figure(volume, a, &bench, &frame, &chosen).write(&path)?;
        written.push(path);
    }
    println!("{}", summary(&written, &film, seconds, &chosen));
    Ok(())
}

/// The name of the coordinate axis `d` (a unit axis) runs along.
fn axis_name(d: DVec3) -> &'static str {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        "x"
    } else if a.y >= a.z {
        "y"
    } else {
        "z"
    }
}

/// The figure of `frame`: axes from the volume's bounds along the image
/// axes u and v, the mode and optics in the title, the colour filter's
/// wheel as its legend.
fn figure(volume: &impl Source, a: &Args, bench: &Bench, frame: &Frame, chosen: &str) -> Figure {
    let b = volume.bounds();
    let v = bench.direction.cross(bench.u);
    // The image spans the box's cross-section: u left to right, v bottom
    // to top (the box's coordinates along each, whatever the axis's sign).
    let span = |d: DVec3| {
        let (p, q) = (b.min.dot(d), b.max.dot(d));
        p.min(q)..p.max(q)
    };
    let axes = (
        figure::Axis { name: axis_name(bench.u).into(), range: span(bench.u) },
        figure::Axis { name: axis_name(v).into(), range: span(v) },
    );
    let mode = match a.cutoff {
        CutoffKind::Knife => "Knife-edge schlieren",
        CutoffKind::Graded => "Graded-filter schlieren",
        CutoffKind::Pinhole => "Pinhole (bright-field) schlieren",
        CutoffKind::DarkField => "Dark-field schlieren",
        CutoffKind::Color => "Colour schlieren",
        CutoffKind::None if bench.film_distance != 0.0 => "Shadowgraph",
        CutoffKind::None => "Transmission (no cutoff)",
        CutoffKind::Interferometry => "Interferogram",
    };
    let file = a
        .file
        .file_name()
        .map_or(a.file.display().to_string(), |f| f.to_string_lossy().into_owned());
    let legend = match &bench.mode {
        Mode::Schlieren(Cutoff::Color(filter)) => Legend::Wheel(filter.clone()),
        _ => Legend::None,
    };
    let along = if bench.direction.element_sum() < 0.0 { "−" } else { "+" };
    Figure {
        image: figure::Image::from_frame(frame),
        title: format!("{mode}: {file}, beam along {along}{}", axis_name(bench.direction)),
        subtitle: format!(
            "{chosen}; {} photons per pixel",
            crate::optics::traced_per_pixel(a.photons)
        ),
        axes: Some(axes),
        legend,
    }
}

impl Args {
    /// The options `rt schlieren FILE ARGS…` would parse to, defaults
    /// included.
    ///
    /// # Errors
    /// What clap reports for bad arguments.
    pub fn from_args<I, T>(file: &std::path::Path, args: I) -> Result<Self, clap::Error>
    where
        I: IntoIterator<Item = T>,
        T: Into<std::ffi::OsString> + Clone,
    {
        crate::parse::subcommand("schlieren", file, args)
    }
}

/// One line: what was written, how many photons in how long, the optics.
pub(crate) fn summary(written: &[PathBuf], film: &Film, seconds: f64, chosen: &str) -> String {
    let files: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
    format!(
        "wrote {} ({}×{}, {} photons in {seconds:.2} s, {:.2} M photons/s; {chosen})",
        files.join(", "),
        film.width(),
        film.height(),
        film.emitted,
        film.emitted as f64 / seconds.max(1e-9) / 1e6,
    )
}
