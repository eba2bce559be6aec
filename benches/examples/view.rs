//! Renders a user's mesh file (OBJ, PLY or VTK polydata) to PNG with the
//! rt surface renderer on all cores.
//!
//! ```text
//! cargo run --release -p rt-benches --example view -- FILE [options]
//!
//!   --out PATH           PNG to write (default: FILE with extension .png)
//!   --scalar NAME        colour by this per-vertex scalar (see --list)
//!   --colormap NAME      viridis (default), cool-to-warm or grayscale
//!   --range LO,HI        scalar range of the map (default: the data's)
//!   --color R,G,B        solid linear colour without a scalar (default 0.8,0.8,0.8)
//!   --ao N               ambient-occlusion rays per pixel per pass (default 0)
//!   --ao-distance D      their reach (default: 0.2 × the mesh's radius)
//!   --shadows            hard shadows from the key light
//!   --size WxH           image size (default 1024x768)
//!   --passes N           progressive passes (default 4)
//!   --azimuth DEG        camera around the vertical axis (default 30)
//!   --elevation DEG      camera above the horizon (default 20)
//!   --distance F         camera distance in mesh radii (default: fit the view)
//!   --fov DEG            vertical field of view (default 35)
//!   --eye X,Y,Z          camera position (overrides azimuth/elevation/distance)
//!   --target X,Y,Z       point looked at (default: the mesh's centre)
//!   --up X,Y,Z           up direction (default 0,1,0)
//!   --orthographic       parallel projection framing the mesh
//!   --seed N             sample stream (same seed, same image)
//!   --list               print the file's scalars and exit
//! ```
//!
//! The main job writes a mesh to try it on:
//! `cargo run --release -p rt-benches --bin rt-demo -- out`, then
//! `cargo run --release -p rt-benches --example view -- out/terrain.ply --scalar height --ao 8 --shadows`.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

use std::{path::PathBuf, process::ExitCode, time::Instant};

use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use rt_benches::image::write_png;
use rt_core::{Camera, ColorMap, Projection};
use rt_surface::{Light, Paint, Renderer, Settings, SurfaceScene, io::read_mesh};

const USAGE: &str = "usage: view FILE [--out PATH] [--scalar NAME] [--colormap viridis|cool-to-warm|grayscale] \
[--range LO,HI] [--color R,G,B] [--ao N] [--ao-distance D] [--shadows] [--size WxH] [--passes N] \
[--azimuth DEG] [--elevation DEG] [--distance F] [--fov DEG] [--eye X,Y,Z] [--target X,Y,Z] \
[--up X,Y,Z] [--orthographic] [--seed N] [--list]";

struct Options {
    file: PathBuf,
    out: Option<PathBuf>,
    scalar: Option<String>,
    colormap: String,
    range: Option<(f32, f32)>,
    color: [f32; 3],
    ao: u32,
    ao_distance: Option<f32>,
    shadows: bool,
    size: (u32, u32),
    passes: u32,
    azimuth: f32,
    elevation: f32,
    distance: Option<f32>,
    fov: f32,
    eye: Option<Vec3>,
    target: Option<Vec3>,
    up: Vec3,
    orthographic: bool,
    seed: u64,
    list: bool,
}

fn numbers<const N: usize>(s: &str, sep: char, what: &str) -> Result<[f32; N], String> {
    let v: Vec<f32> = s
        .split(sep)
        .map(|t| t.trim().parse::<f32>().map_err(|_| format!("{what}: bad number `{t}`")))
        .collect::<Result<_, _>>()?;
    let arr: [f32; N] = v.try_into().map_err(|_| format!("{what} needs {N} values: `{s}`"))?;
    if arr.iter().all(|x| x.is_finite()) { Ok(arr) } else { Err(format!("{what}: not finite")) }
}

fn parse_args(args: impl Iterator<Item = String>) -> Result<Options, String> {
    let mut o = Options {
        file: PathBuf::new(),
        out: None,
        scalar: None,
        colormap: "viridis".into(),
        range: None,
        color: [0.8; 3],
        ao: 0,
        ao_distance: None,
        shadows: false,
        size: (1024, 768),
        passes: 4,
        azimuth: 30.0,
        elevation: 20.0,
        distance: None,
        fov: 35.0,
        eye: None,
        target: None,
        up: Vec3::Y,
        orthographic: false,
        seed: 0,
        list: false,
    };
    let mut file = None;
    let mut args = args.peekable();
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{a} needs a value"));
        let uint = |s: String| s.parse::<u32>().map_err(|_| format!("{a}: bad count `{s}`"));
        let float = |s: String| -> Result<f32, String> { Ok(numbers::<1>(&s, ',', &a)?[0]) };
        match a.as_str() {
            "--out" => o.out = Some(PathBuf::from(value()?)),
            "--scalar" => o.scalar = Some(value()?),
            "--colormap" => o.colormap = value()?,
            "--range" => {
                let [lo, hi] = numbers(&value()?, ',', "--range")?;
                o.range = Some((lo, hi));
            }
            "--color" => o.color = numbers(&value()?, ',', "--color")?,
            "--ao" => o.ao = uint(value()?)?,
            "--ao-distance" => o.ao_distance = Some(float(value()?)?),
            "--shadows" => o.shadows = true,
            "--size" => {
                let v = value()?;
                let (w, h) = v.split_once(['x', 'X']).ok_or("--size wants WxH")?;
                o.size = (uint(w.to_string())?, uint(h.to_string())?);
            }
            "--passes" => o.passes = uint(value()?)?.max(1),
            "--azimuth" => o.azimuth = float(value()?)?,
            "--elevation" => o.elevation = float(value()?)?,
            "--distance" => o.distance = Some(float(value()?)?),
            "--fov" => o.fov = float(value()?)?,
            "--eye" => o.eye = Some(Vec3::from(numbers(&value()?, ',', "--eye")?)),
            "--target" => o.target = Some(Vec3::from(numbers(&value()?, ',', "--target")?)),
            "--up" => o.up = Vec3::from(numbers(&value()?, ',', "--up")?),
            "--orthographic" => o.orthographic = true,
            "--seed" => o.seed = value()?.parse().map_err(|_| "--seed: bad number".to_string())?,
            "--list" => o.list = true,
            "-h" | "--help" => return Err(USAGE.into()),
            s if s.starts_with("--") => return Err(format!("unknown option {s}\n{USAGE}")),
            _ if file.is_none() => file = Some(PathBuf::from(&a)),
            _ => return Err(format!("one file only (got `{a}` too)\n{USAGE}")),
        }
    }
    o.file = file.ok_or(USAGE)?;
    Ok(o)
}

fn main() -> ExitCode {
    match parse_args(std::env::args().skip(1)).and_then(|o| run(&o)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("view: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(o: &Options) -> Result<(), String> {
    let t0 = Instant::now();
    let data = read_mesh(&o.file).map_err(|e| e.to_string())?;
    if o.list {
        println!(
            "{}: {} vertices, {} triangles",
            o.file.display(),
            data.positions.len(),
            data.indices.len()
        );
        println!("normals: {}", if data.normals.is_some() { "per vertex" } else { "none" });
        for (name, values) in &data.scalars {
            let (lo, hi) = finite_range(values).unwrap_or((f32::NAN, f32::NAN));
            println!("scalar {name}: {lo} … {hi}");
        }
        return Ok(());
    }
    let mesh =
        data.into_mesh(o.scalar.as_deref()).map_err(|e| format!("{}: {e}", o.file.display()))?;
    if mesh.indices().is_empty() {
        return Err(format!("{}: no triangles to render", o.file.display()));
    }
    let paint = match mesh.scalars() {
        Some(s) => {
            let map = match o.colormap.as_str() {
                "viridis" => ColorMap::viridis(),
                "cool-to-warm" | "coolwarm" => ColorMap::cool_to_warm(),
                "grayscale" | "gray" => ColorMap::grayscale(),
                other => return Err(format!("unknown colour map `{other}`")),
            };
            let (lo, hi) = o.range.or_else(|| finite_range(s)).unwrap_or((0.0, 1.0));
            let hi = if hi > lo { hi } else { lo + 1.0 };
            Paint::Mapped(map.with_range(lo, hi).map_err(|e| e.to_string())?)
        }
        None => Paint::Solid(o.color),
    };
    // The view framing the mesh's bounding sphere.
    let (lo, hi) =
        mesh.positions().iter().fold((Vec3::MAX, Vec3::MIN), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let center = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(f32::MIN_POSITIVE);
    let triangles = mesh.indices().len();
    let world = SurfaceScene::from_mesh(mesh, paint).map_err(|e| e.to_string())?;
    let built = t0.elapsed();

    let (w, h) = o.size;
    let aspect = w as f32 / h.max(1) as f32;
    let fov = o.fov.to_radians();
    let target = o.target.unwrap_or(center);
    let (az, el) = (o.azimuth.to_radians(), o.elevation.to_radians());
    let dir = Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
    // Fit the sphere in the narrower of the two fields of view.
    let half = (fov * 0.5).tan().min((fov * 0.5).tan() * aspect).atan();
    let fit = radius / half.sin();
    let eye = o.eye.unwrap_or(target + dir * o.distance.map_or(fit, |d| d * radius));
    let projection = if o.orthographic {
        Projection::Orthographic { height: 2.0 * radius * (1.0f32).max(1.0 / aspect) }
    } else {
        Projection::Perspective { fov_y: fov }
    };
    let cam = Camera::look_at(eye, target, o.up, projection, w, h).map_err(|e| e.to_string())?;
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
        ao_distance: o.ao_distance.unwrap_or(0.2 * radius),
        seed: o.seed,
        ..Settings::default()
    };
    let mut renderer = Renderer::new(cam, settings).map_err(|e| e.to_string())?;

    let tiles = renderer.tiles_per_pass();
    let bar = ProgressBar::new((tiles * o.passes as usize) as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {percent:>3}% {elapsed_precise} eta {eta}")
            .map_err(|e| e.to_string())?
            .progress_chars("=> "),
    );
    let t1 = Instant::now();
    for pass in 0..o.passes {
        bar.set_message(format!("pass {}/{}", pass + 1, o.passes));
        renderer.render_pass_with_progress(&world, |_, _| bar.inc(1));
    }
    bar.finish_and_clear();
    let rendered = t1.elapsed();

    let frame = renderer.frame().map_err(|e| e.to_string())?;
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
