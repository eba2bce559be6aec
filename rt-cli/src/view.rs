//! `rt view`: a user's mesh file (OBJ, PLY or VTK polydata) ray-traced to
//! PNG on all cores, coloured by one of its scalars.

use std::{path::PathBuf, time::Instant};

use anyhow::{Context, bail};
use clap::ValueEnum;
use rt_core::{Camera, ColorMap, Projection, glam::Vec3};
use rt_surface::{Light, Paint, Renderer, Settings, SurfaceScene, io::read_mesh};

use crate::{image::write_png, parse, progress};

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
}

/// Runs `rt view`.
///
/// # Errors
/// An unreadable mesh, an unknown scalar, a mesh with no triangles, a bad
/// camera, an unwritable output.
pub fn run(o: &Args) -> anyhow::Result<()> {
    let t0 = Instant::now();
    let data = read_mesh(&o.file)?;
    let mesh = data.into_mesh(o.scalar.as_deref()).with_context(|| o.file.display().to_string())?;
    if mesh.indices().is_empty() {
        bail!("{}: no triangles to render", o.file.display());
    }
    let paint = match mesh.scalars() {
        Some(s) => {
            let map = match o.colormap {
                ColorMapName::Viridis => ColorMap::viridis(),
                ColorMapName::CoolToWarm => ColorMap::cool_to_warm(),
                ColorMapName::Grayscale => ColorMap::grayscale(),
            };
            let (lo, hi) = o.range.or_else(|| finite_range(s)).unwrap_or((0.0, 1.0));
            let hi = if hi > lo { hi } else { lo + 1.0 };
            Paint::Mapped(map.with_range(lo, hi)?)
        }
        None => Paint::Solid(o.color),
    };
    // The view framing the mesh's bounding sphere.
    let (lo, hi) =
        mesh.positions().iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(f32::MIN_POSITIVE);
    let triangles = mesh.indices().len();
    let world = SurfaceScene::from_mesh(mesh, paint)?;
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

    let frame = renderer.frame()?;
    let out = o.out.clone().unwrap_or_else(|| o.file.with_extension("png"));
    write_png(&frame, &out)?;
    let c = renderer.counts();
    let seconds = rendered.as_secs_f64();
    println!(
        "wrote {} ({w}×{h}, {triangles} triangles, {} passes; read + build {:.2} s, render {seconds:.2} s, {:.1} Mrays/s: {} primary, {} shadow, {} AO)",
        out.display(),
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
