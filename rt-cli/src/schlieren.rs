//! `rt schlieren`: synthetic schlieren, shadowgraph, interferogram or
//! colour schlieren of a volume file, with automatic exposure.

use std::{path::PathBuf, time::Instant};

use anyhow::Context;
use clap::ValueEnum;
use rt_core::Frame;
use rt_photo::{
    Cutoff, CutoffKind as Kind, Film, FilterImage, Medium, Mode, Reconstruction, SchlierenOptions,
    SchlierenSetup, traced_per_pixel, units::si,
};
use rt_volume::glam::DVec3;

use crate::{
    figure::{self, Figure, Legend},
    image,
    optics::{self, Axis, DeviceArg, Interpolation, MeshOptions, Samples},
    output::Outputs,
    parse, progress,
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
    /// A colour filter painted in a PNG, in place of the hue wheel (with
    /// `--cutoff color`): square, its sRGB colours what it transmits,
    /// spanning ±--half-range of deflection (automatic as for the wheel)
    /// with εu rising left to right and εv bottom to top. `rt serve` saves
    /// the filter painted on its page this way.
    #[arg(long)]
    pub filter: Option<PathBuf>,
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
    #[arg(long, default_value_t = 512, value_parser = clap::value_parser!(u32).range(1..=i64::from(rt_photo::MAX_EDGE)))]
    pub size: u32,
    /// Photons per pixel. Each pass traces a k×k lattice of photons per
    /// pixel (k = 2 up to 63 photons, 4 from 64, 8 from 256: at least four
    /// passes), shifted from pass to pass; each lattice cell carries its
    /// light onto the film where its corners land, by exact area, so an
    /// undisturbed beam has no grain at all and more photons sharpen the
    /// image rather than average noise. Rounded up to whole passes.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=i64::from(rt_photo::MAX_PHOTONS_PER_PIXEL)))]
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
    /// Where the photons are traced: `cpu` (the default: the same image on
    /// every machine), `gpu` (grids with `--interp linear`; an error where
    /// there is no GPU), `auto` (the GPU where it can, else the CPU; the
    /// choice is printed).
    #[arg(long, value_enum, default_value_t = DeviceArg::Cpu)]
    pub device: DeviceArg,
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

impl Args {
    /// The library's options for these arguments.
    #[must_use]
    pub fn options(&self) -> SchlierenOptions {
        SchlierenOptions {
            cutoff: match self.cutoff {
                CutoffKind::Knife => Kind::Knife,
                CutoffKind::Graded => Kind::Graded,
                CutoffKind::Pinhole => Kind::Pinhole,
                CutoffKind::DarkField => Kind::DarkField,
                CutoffKind::Color => Kind::Color,
                CutoffKind::None => Kind::None,
                CutoffKind::Interferometry => Kind::Interferometry,
            },
            angle: self.angle,
            f: self.f,
            h: self.h,
            radius: self.radius,
            half_range: self.half_range,
            wavelength: self.lambda,
            fringes: self.fringes,
            film_distance: self.film_distance,
            axis: self.axis.into(),
            size: self.size,
            photons: self.photons,
            reconstruction: match self.estimator {
                Estimator::Sheet => Reconstruction::Sheet,
                Estimator::Photons => Reconstruction::Photons,
            },
        }
    }
}

/// Runs `rt schlieren`.
///
/// # Errors
/// An unreadable or unsuitable volume, bad optics, too many photons, an
/// unwritable output.
pub fn run(a: &Args) -> anyhow::Result<()> {
    render(&optics::open(&a.file, a.samples, a.allow_nonphysical, a.interp, &a.mesh)?, a)
}

/// Renders `medium` as `a` says (its file and sample options aside) and
/// writes the PNG; prints one summary line.
///
/// # Errors
/// Bad optics, too many photons, an unwritable output.
pub fn render(medium: &Medium, a: &Args) -> anyhow::Result<()> {
    let mut targets = vec![a.out.clone()];
    if a.raw16 {
        targets.push(image::beside(&a.out, "16bit"));
    }
    if !a.no_figure {
        targets.push(image::beside(&a.out, "figure"));
    }
    // Before any work: an impossible --out fails now, not after the render.
    let outs = Outputs::check(&targets)?;
    if a.filter.is_some() && a.cutoff != CutoffKind::Color {
        anyhow::bail!("--filter is a colour filter: add --cutoff color");
    }
    let mut setup = SchlierenSetup::choose(medium, &a.options()).map_err(optics::hint)?;
    if let Some(path) = &a.filter {
        let range = setup.focal_range().unwrap_or(1e-3);
        setup = setup.with_filter(FilterImage::read_png(path, range)?).map_err(optics::hint)?;
    }
    if let Some(w) = &setup.warning {
        eprintln!("rt: warning: {w}; raise --size or --lambda");
    }
    let (w, h) = setup.size;
    let bar = progress::bar((w * h) as u64 * traced_per_pixel(a.photons), "photons");
    let chosen = rt_gpu::choose(a.device.into(), medium)?;
    if a.device != DeviceArg::Cpu {
        bar.suspend(|| eprintln!("rt: tracing on {}", chosen.describe()));
    }
    let t = Instant::now();
    let film = match &chosen {
        rt_gpu::Chosen::Gpu(gpu) => {
            let progress = &mut |done, _| bar.set_position(done);
            rt_gpu::render_schlieren(gpu, &setup, medium, a.seed, progress, &|| false)?
        }
        rt_gpu::Chosen::Cpu(_) => {
            setup.render(medium, a.seed, &mut |done, _| bar.set_position(done))?
        }
    };
    let seconds = t.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let bench = &setup.bench;
    let scale = if matches!(bench.mode, Mode::Schlieren(Cutoff::None)) { 0.5 } else { 1.0 };
    let frame = image::film_frame(&film, scale)?;
    image::write_png(&frame, &outs.staging(&a.out))?;
    if a.raw16 {
        let color = matches!(bench.mode, Mode::Schlieren(Cutoff::Color(_)));
        image::write_film16(&film, color, &outs.staging(&image::beside(&a.out, "16bit")))?;
    }
    if !a.no_figure {
        let path = image::beside(&a.out, "figure");
        figure(medium, a, &setup, &frame)
            .write(&outs.staging(&path))
            .with_context(|| path.display().to_string())?;
    }
    outs.commit()?;
    println!("{}", summary(&targets, &film, seconds, &setup.to_string()));
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
fn figure(medium: &Medium, a: &Args, setup: &SchlierenSetup, frame: &Frame) -> Figure {
    let bench = &setup.bench;
    let b = medium.bounds();
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
    let mode = setup.title();
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
        subtitle: format!("{setup}; {} photons per pixel", traced_per_pixel(a.photons)),
        axes: Some(axes),
        legend,
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
