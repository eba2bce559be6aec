//! `rt view`: a user's mesh file (OBJ, PLY or VTK polydata) ray-traced to
//! PNG on all cores, coloured by one of its scalars.

use std::{path::PathBuf, time::Instant};

use anyhow::{Context, bail};
use clap::ValueEnum;
use rt_core::{Camera, ColorMap, Projection, glam::Vec3};
use rt_surface::{
    Light, Material, Mesh, MeshError, Paint, Renderer, Settings, SurfaceScene, io::read_mesh,
};

use crate::{
    figure::{Figure, Image, Legend, significant},
    image::{beside, over_background, write_png},
    output::Outputs,
    parse, progress,
};

/// The colour maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColorMapName {
    /// Perceptually uniform, dark blue to yellow.
    Viridis,
    /// Diverging, blue through white to red (Moreland).
    CoolToWarm,
    /// Black to white.
    Grayscale,
}

/// What the render is drawn on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Background {
    /// White: the page a paper is printed on, so the object sits on it
    /// with no visible frame, prints without ink and crops cleanly.
    White,
    /// Black (slides, dark pages).
    Black,
    /// A gentle vertical gradient, pale blue-grey at the top to white.
    Gradient,
    /// None: alpha 0 where nothing was hit (to composite elsewhere).
    Transparent,
}

impl Background {
    /// Linear RGB at the top and bottom rows, or `None` for transparent.
    #[must_use]
    pub fn colors(self) -> Option<([f32; 3], [f32; 3])> {
        match self {
            Self::White => Some(([1.0; 3], [1.0; 3])),
            Self::Black => Some(([0.0; 3], [0.0; 3])),
            Self::Gradient => Some(([0.62, 0.68, 0.76], [1.0; 3])),
            Self::Transparent => None,
        }
    }
}

/// The ground plane's colour (linear RGB): a neutral mid grey.
const GROUND: [f32; 3] = [0.5; 3];

/// `rt view MESH`: options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The mesh: OBJ, PLY (with per-vertex scalars) or VTK polydata
    /// (.vtk, .vtp).
    pub file: PathBuf,
    /// PNG to write [default: the mesh's path with extension .png].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Colour by this per-vertex scalar (`rt info FILE` lists them).
    #[arg(long)]
    pub scalar: Option<String>,
    /// Colour map for the scalar.
    #[arg(long, value_enum, default_value_t = ColorMapName::Viridis)]
    pub colormap: ColorMapName,
    /// Scalar range of the map, LO,HI [default: the data's].
    #[arg(long, value_parser = parse::range, allow_hyphen_values = true)]
    pub range: Option<(f32, f32)>,
    /// Linear RGB (each 0–1) without a scalar.
    #[arg(long, value_parser = parse::rgb, default_value = "0.8,0.8,0.8")]
    pub color: [f32; 3],
    /// Ambient-occlusion rays per pixel per pass (0: off).
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u32).range(0..=4096))]
    pub ao: u32,
    /// Reach of the AO rays, in the mesh's units [default: 0.2 × its
    /// bounding radius].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub ao_distance: Option<f64>,
    /// Hard shadows from the key light.
    #[arg(long)]
    pub shadows: bool,
    /// Image size in pixels, WxH.
    #[arg(long, value_parser = parse::size, default_value = "1024x768")]
    pub size: (u32, u32),
    /// Progressive passes (one jittered sample per pixel each).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub passes: u32,
    /// Camera around the vertical axis, in degrees.
    #[arg(long, default_value_t = 30.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub azimuth: f64,
    /// Camera above the horizon, in degrees.
    #[arg(long, default_value_t = 20.0, value_parser = parse::finite, allow_hyphen_values = true)]
    pub elevation: f64,
    /// Camera distance in bounding radii [default: fit the view].
    #[arg(long, value_parser = parse::positive, allow_hyphen_values = true)]
    pub distance: Option<f64>,
    /// Vertical field of view, in degrees (0–180 exclusive).
    #[arg(long, default_value_t = 35.0, value_parser = parse::positive, allow_hyphen_values = true)]
    pub fov: f64,
    /// Camera position X,Y,Z (overrides azimuth, elevation, distance).
    #[arg(long, value_parser = parse::vec3, allow_hyphen_values = true)]
    pub eye: Option<Vec3>,
    /// Point looked at, X,Y,Z [default: the mesh's centre].
    #[arg(long, value_parser = parse::vec3, allow_hyphen_values = true)]
    pub target: Option<Vec3>,
    /// Up direction, X,Y,Z.
    #[arg(long, value_parser = parse::vec3, default_value = "0,1,0", allow_hyphen_values = true)]
    pub up: Vec3,
    /// Parallel projection framing the mesh.
    #[arg(long)]
    pub orthographic: bool,
    /// Seed of the sample streams (the same seed gives the same image).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// What the mesh is drawn on (transparent: alpha 0 where nothing was
    /// hit).
    #[arg(long, value_enum, default_value_t = Background::White)]
    pub background: Background,
    /// Show the facets: ignore the file's normals and compute no smooth
    /// ones [default: the file's normals, else angle-weighted vertex
    /// normals].
    #[arg(long)]
    pub flat: bool,
    /// A grey ground plane just below the mesh's lowest point along --up,
    /// 6 bounding radii wide, that takes its shadow and AO (with --shadows,
    /// --ao).
    #[arg(long)]
    pub ground: bool,
    /// Also write `<stem>-figure.png`: the render with a colour bar
    /// labelled with the scalar's name and range.
    #[arg(long)]
    pub figure: bool,
}

/// Whether the range `lo..=hi` of a scalar is below float resolution:
/// equal ends, or a span of at most 4 ulps of the larger magnitude
/// (stretching a colour map over it would paint round-off as noise).
fn is_constant(lo: f32, hi: f32) -> bool {
    hi - lo <= 4.0 * f32::EPSILON * lo.abs().max(hi.abs())
}

/// How many float32 steps `[lo, hi]` spans, where that is few enough (under
/// 256) for the colour map's bands to show; `None` for a finer range.
fn float_steps(lo: f32, hi: f32) -> Option<u32> {
    let step = f32::EPSILON * lo.abs().max(hi.abs());
    let steps = f64::from(hi - lo) / f64::from(step);
    (step > 0.0 && steps < 256.0).then(|| steps.round() as u32)
}

/// A square of `6 × radius` side facing `up` (unit), centred under
/// `center`, its height along `up` just below `lowest`: two triangles,
/// counter-clockwise seen from above.
fn ground_plane(center: Vec3, radius: f32, up: Vec3, lowest: f32) -> Result<Mesh, MeshError> {
    let e1 = up.any_orthonormal_vector();
    let e2 = up.cross(e1);
    let c = center + up * (lowest - 0.01 * radius - center.dot(up));
    let a = 3.0 * radius;
    let corners = [-e1 - e2, e1 - e2, e1 + e2, -e1 + e2].map(|d| c + a * d).to_vec();
    Mesh::new(corners, vec![[0, 1, 2], [0, 2, 3]], None)
}

/// Runs `rt view`.
///
/// # Errors
/// An unreadable mesh, an unknown scalar, a mesh with no triangles, a bad
/// camera, an unwritable output.
pub fn run(o: &Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let out = o.out.clone().unwrap_or_else(|| o.file.with_extension("png"));
    let mut targets = vec![out.clone()];
    if o.figure {
        targets.push(beside(&out, "figure"));
    }
    // Before any work: an impossible --out fails now, not after the render.
    let outs = Outputs::check(&targets)?;
    let mut data = read_mesh(&o.file)?;
    if o.flat {
        data.normals = None;
    }
    let mut mesh =
        data.into_mesh(o.scalar.as_deref()).with_context(|| o.file.display().to_string())?;
    if mesh.indices().is_empty() {
        bail!("{}: no triangles to render", o.file.display());
    }
    if !o.flat && mesh.normals().is_none() {
        mesh = mesh.with_smooth_normals();
    }
    let name = o.scalar.as_deref().unwrap_or("scalar");
    // The map and whether the scalar is constant (drawn in one colour).
    let mapped = match mesh.scalars() {
        Some(s) => {
            let map = match o.colormap {
                ColorMapName::Viridis => ColorMap::viridis(),
                ColorMapName::CoolToWarm => ColorMap::cool_to_warm(),
                ColorMapName::Grayscale => ColorMap::grayscale(),
            };
            let (lo, hi, constant) = match (o.range, finite_range(s)) {
                (Some((lo, hi)), _) => (lo, hi, false),
                (None, Some((lo, hi))) if is_constant(lo, hi) => {
                    let what = if lo == hi {
                        format!("every value is {lo}")
                    } else {
                        format!("{lo} to {hi}, within float round-off")
                    };
                    eprintln!(
                        "rt: warning: scalar {name} is constant ({what}); drawn in one colour"
                    );
                    // An empty range maps every value to the map's middle.
                    let mid = lo + 0.5 * (hi - lo);
                    (mid, mid, true)
                }
                (None, Some((lo, hi))) => {
                    if let Some(steps) = float_steps(lo, hi) {
                        eprintln!(
                            "rt: warning: scalar {name} spans {lo} to {hi}, only {steps} float32 steps: its colours come in as many bands"
                        );
                    }
                    (lo, hi, false)
                }
                // No finite value: every vertex gets the NaN colour.
                (None, None) => (0.0, 1.0, false),
            };
            Some((map.with_range(lo, hi)?, constant))
        }
        None => None,
    };
    let paint = mapped.map_or(Paint::Solid(o.color), |(map, _)| Paint::Mapped(map));
    // The view framing the mesh's bounding sphere.
    let (lo, hi) =
        mesh.positions().iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(f32::MIN_POSITIVE);
    let triangles = mesh.indices().len();
    let up = o.up.normalize_or(Vec3::Y);
    let ground = if o.ground {
        let lowest = mesh.positions().iter().map(|p| p.dot(up)).fold(f32::INFINITY, f32::min);
        Some(ground_plane(center, radius, up, lowest).context("the ground plane")?)
    } else {
        None
    };
    let mut scene = SurfaceScene::builder().mesh(mesh, paint, Material::MATTE);
    if let Some(g) = ground {
        scene = scene.mesh(g, Paint::Solid(GROUND), Material::MATTE);
    }
    let world = scene.build()?;
    let built = t0.elapsed();

    let (w, h) = o.size;
    let aspect = w as f32 / h.max(1) as f32;
    if o.fov >= 180.0 {
        bail!("--fov {}: the field of view must be below 180 degrees", o.fov);
    }
    let fov = (o.fov as f32).to_radians();
    let target = o.target.unwrap_or(center);
    let (az, el) = ((o.azimuth as f32).to_radians(), (o.elevation as f32).to_radians());
    let dir = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    // Fit the sphere in the narrower of the two fields of view.
    let half = (fov * 0.5).tan().min((fov * 0.5).tan() * aspect).atan();
    let fit = radius / half.sin();
    let eye = o.eye.unwrap_or(target + dir * o.distance.map_or(fit, |d| d as f32 * radius));
    let projection = if o.orthographic {
        Projection::Orthographic { height: 2.0 * radius * (1.0f32).max(1.0 / aspect) }
    } else {
        Projection::Perspective { fov_y: fov }
    };
    let cam = Camera::look_at(eye, target, o.up, projection, w, h).context("camera")?;
    // A key light from over the viewer's left shoulder, plus ambient.
    let left = dir.cross(o.up).normalize_or_zero();
    let key = (dir + left * 0.6 + o.up.normalize_or_zero() * 0.8).normalize_or(dir);
    let settings = Settings {
        lights: vec![
            Light::Ambient { color: [0.35; 3] },
            Light::Directional { direction: key, color: [0.75; 3] },
        ],
        shadows: o.shadows,
        ao_samples: o.ao,
        ao_distance: o.ao_distance.map_or(0.2 * radius, |d| d as f32),
        seed: o.seed,
        ..Settings::default()
    };
    let mut renderer = Renderer::new(cam, settings)?;

    let tiles = renderer.tiles_per_pass();
    let bar = progress::bar((tiles * o.passes as usize) as u64, "tiles");
    let t1 = Instant::now();
    for pass in 0..o.passes {
        bar.set_message(format!("pass {}/{}", pass + 1, o.passes));
        renderer.render_pass_with_progress(&world, |_, _| bar.inc(1));
    }
    bar.finish_and_clear();
    let rendered = t1.elapsed();

    let mut frame = renderer.frame()?;
    if let Some((top, bottom)) = o.background.colors() {
        over_background(&mut frame, top, bottom);
    }
    write_png(&frame, &outs.staging(&out))?;
    let mut written = out.display().to_string();
    if o.figure {
        let path = beside(&out, "figure");
        let file = o
            .file
            .file_name()
            .map_or(o.file.display().to_string(), |f| f.to_string_lossy().into_owned());
        let (legend, subtitle) = match mapped {
            Some((map, constant)) => {
                let (lo, hi) = map.range();
                let (lo, hi) = (significant(lo.into()), significant(hi.into()));
                let steps = float_steps(map.range().0, map.range().1);
                let range = match (constant, steps) {
                    (true, _) => format!("constant, {lo}"),
                    (false, Some(n)) => format!("{lo} to {hi}, only {n} float steps"),
                    (false, None) => format!("{lo} to {hi}"),
                };
                let legend = Legend::ColorBar { map, name: name.to_string(), constant };
                let cmap = o.colormap.to_possible_value().map(|v| v.get_name().to_string());
                let cmap = cmap.unwrap_or_default();
                (legend, format!("coloured by {name} ({range}) through {cmap}"))
            }
            None => (Legend::None, String::new()),
        };
        let figure = Figure {
            image: Image::from_frame(&frame),
            title: format!("{file}: {triangles} triangles"),
            subtitle,
            axes: None,
            legend,
        };
        figure.write(&outs.staging(&path)).with_context(|| path.display().to_string())?;
        written = format!("{written}, {}", path.display());
    }
    outs.commit()?;
    let c = renderer.counts();
    let seconds = rendered.as_secs_f64();
    println!(
        "wrote {written} ({w}×{h}, {triangles} triangles, {} passes; read + build {:.2} s, render {seconds:.2} s, {:.1} Mrays/s: {} primary, {} shadow, {} AO)",
        o.passes,
        built.as_secs_f64(),
        c.total() as f64 / seconds / 1e6,
        c.primary,
        c.shadow,
        c.ao,
    );
    Ok(())
}

fn finite_range(values: &[f32]) -> Option<(f32, f32)> {
    let (lo, hi) = values
        .iter()
        .filter(|v| v.is_finite())
        .fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    (lo <= hi).then_some((lo, hi))
}
