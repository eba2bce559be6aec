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
    output::Outputs,
    parse,
    units::{index, si, sig3},
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
    /// radians; light deflected beyond the rim is cut and shows black
    /// [default: automatic, the rim clears 99.5 % of the disturbed pixels
    /// (surveyed at the image's resolution)].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub half_range: Option<f64>,
    /// Interferometry wavelength in metres (CO₂ laser: 10.6e-6).
    #[arg(long, default_value = "10.6e-6", value_parser = parse::positive, allow_hyphen_values = true)]
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
    /// Interpolation between samples (grids): `cubic` (Catmull–Rom, C¹)
    /// by default, as `linear`'s gradient jumps at every cell face and a
    /// shadowgraph, which images its derivative, prints the grid as lines;
    /// `linear` is about twice as fast.
    #[arg(long, value_enum, default_value_t = Interpolation::Cubic)]
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
fn optics(a: &Args, survey: &Survey, fine: Option<&Survey>, n_ref: f64) -> (Mode, f64, String) {
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
            let what =
                format!("knife edge at {}°, f = {}, h = {}", sig3(a.angle), si(f, "m"), si(h, "m"));
            (mode, film, what)
        }
        CutoffKind::Graded => {
            let width = a.h.unwrap_or(f * eps_perp / 0.45);
            let mode = Mode::Schlieren(Cutoff::Graded { angle, f, width });
            let what = format!(
                "graded filter at {}°, f = {}, width = {}",
                sig3(a.angle),
                si(f, "m"),
                si(width, "m")
            );
            (mode, film, what)
        }
        CutoffKind::Pinhole | CutoffKind::DarkField => {
            let radius = a.radius.unwrap_or(0.25 * f * eps);
            let dark_field = a.cutoff == CutoffKind::DarkField;
            let mode = Mode::Schlieren(Cutoff::Pinhole { f, radius, dark_field });
            let what = if dark_field { "dark-field stop" } else { "pinhole" };
            (mode, film, format!("{what}, f = {}, radius = {}", si(f, "m"), si(radius, "m")))
        }
        CutoffKind::Color => {
            // The rim clears 99.5 % of the disturbed pixels of a survey at
            // the image's resolution: what lies beyond it is cut (black).
            let chosen = || fine.unwrap_or(survey).disturbed_magnitude(0.995).max(1e-12);
            let half = a.half_range.unwrap_or_else(chosen);
            let mode = Mode::Schlieren(Cutoff::Color(FilterImage::hue_wheel(256, half)));
            (mode, film, format!("colour filter, rim at |ε| = {}", si(half, "rad")))
        }
        CutoffKind::None => {
            let div = survey.divergence(0.99);
            let l = a.film_distance.unwrap_or(if div > 0.0 { 0.5 / div } else { 0.0 });
            (Mode::Schlieren(Cutoff::None), l, format!("no cutoff, film distance = {}", si(l, "m")))
        }
        CutoffKind::Interferometry => {
            let mode = Mode::Interferometry { lambda: a.lambda, n_ref, fringe_spacing: a.fringes };
            let fringes = a
                .fringes
                .map_or("infinite fringe".to_string(), |s| format!("fringes {} apart", si(s, "m")));
            let what = format!(
                "interferometry, λ = {}, n_ref = {}, {fringes}",
                si(a.lambda, "m"),
                index(n_ref)
            );
            (mode, film, what)
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
    // A colour filter's rim must clear the peaks a coarse survey smooths
    // away: survey it at the image's resolution (up to 512 pixels across,
    // one photon each: a fraction of the render's photons).
    let fine = if a.cutoff == CutoffKind::Color && a.half_range.is_none() {
        Some(volume.survey_at(&probe, (a.size as usize).min(512))?)
    } else {
        None
    };
    let (mode, film_distance, chosen) = optics(a, &survey, fine.as_ref(), n_ref);
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
    let mut targets = vec![a.out.clone()];
    if a.raw16 {
        targets.push(image::beside(&a.out, "16bit"));
    }
    if !a.no_figure {
        targets.push(image::beside(&a.out, "figure"));
    }
    // Before any work: an impossible --out fails now, not after the render.
    let outs = Outputs::check(&targets)?;
    let (bench, chosen) = prepare(volume, a)?;
    let bench = match a.estimator {
        Estimator::Sheet => bench,
        Estimator::Photons => Bench { reconstruction: Reconstruction::Photons, ..bench },
    };
    let (film, seconds) = volume.render(&bench, a.size as usize, a.photons, a.seed)?;
    let scale = if matches!(bench.mode, Mode::Schlieren(Cutoff::None)) { 0.5 } else { 1.0 };
    let frame = image::film_frame(&film, scale)?;
    image::write_png(&frame, &outs.staging(&a.out))?;
    if a.raw16 {
        let color = matches!(bench.mode, Mode::Schlieren(Cutoff::Color(_)));
        image::write_film16(&film, color, &outs.staging(&image::beside(&a.out, "16bit")))?;
    }
    if !a.no_figure {
        let path = image::beside(&a.out, "figure");
        figure(volume, a, &bench, &frame, &chosen)
            .write(&outs.staging(&path))
            .with_context(|| path.display().to_string())?;
    }
    outs.commit()?;
    println!("{}", summary(&targets, &film, seconds, &chosen));
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
        "wrote {} ({}×{}, {} photons in {}, {}; {chosen})",
        files.join(", "),
        film.width(),
        film.height(),
        film.emitted,
        si(seconds, "s"),
        si(film.emitted as f64 / seconds.max(1e-9), "photons/s"),
    )
}
