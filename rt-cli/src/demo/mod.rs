//! `rt demo`: the main job — renders the built-in scenes into a folder.
//!
//! ```text
//! rt demo [DIR]          (default: out/)
//! ```
//!
//! Writes, 8-bit sRGB PNGs:
//! - `surface.png`: a ray-traced scientific surface scene rendered with
//!   `rt_surface::Renderer`: a terrain mesh coloured by its height through
//!   viridis (the scalar is interpolated across each triangle, then
//!   mapped; angle-weighted smooth vertex normals), slightly mirroring
//!   sphere glyphs coloured with the cool-to-warm map, and a glossy
//!   streamline tube, under ambient light with ambient occlusion (8 rays)
//!   and a directional light with hard shadows; 4 progressive passes, on
//!   white (as `rt view` draws by default).
//! - `terrain.ply`: the terrain mesh with its `height` scalar, to try the
//!   `rt view` on (`--scalar height`).
//! - From the built-in blast wave (`rt-tools/data/`, a real PyClaw Euler
//!   solution, density → index by Gladstone–Dale), photons traced through
//!   the volume along z: `schlieren-knife.png` (vertical knife edge,
//!   background mid-grey), `shadowgraph.png` (film 2 m behind, background
//!   mid-grey), `interferogram.png` (10.6 µm CO₂ laser, finite fringes) and
//!   `schlieren-color.png` (hue-wheel colour filter: hue = direction of
//!   deflection, saturation = its size), each with its `-figure.png`
//!   (axes in metres, scale bar, the optics in the title, the colour
//!   filter's legend) as `rt schlieren` writes it; and
//!   background-oriented schlieren as `rt bos` writes it:
//!   `bos-reference.png`, `bos-flow.png` (a random-dot background without
//!   and with the flow) and `bos-displacement.png` (+ `.json`/`.raw`: the
//!   true displacement in pixels); and focusing schlieren as `rt
//!   focusing` writes it: `focusing.png` (a lens-and-grid system focused
//!   on the blast's mid-plane, + `.json`/`.raw`: I/I₀ per pixel); and the
//!   blast wave as an unstructured mesh (2 × 2 × 2 block means, 32³
//!   points, 31³ hexahedra): `blast.vtu`, and `schlieren-mesh.png` (+ `-figure.png`)
//!   rendered from it as `rt schlieren blast.vtu --mesh smooth` does.
mod optics;

use std::{path::PathBuf, time::Instant};

use anyhow::Context;
use rt_core::{Camera, ColorMap, Projection, glam::Vec3, intersect::Sphere};
use rt_surface::{
    Glyphs, Light, Material, Mesh, Paint, Renderer, Settings, SurfaceScene, Tube, io::write_ply,
};

use rt_tools::{
    image::{over_background, write_png},
    output::{Outputs, make_folder},
    scenes,
};

/// `rt demo [DIR]`: options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Folder to write the pictures into (created if missing).
    #[arg(default_value = "out")]
    pub dir: PathBuf,
}

const WIDTH: u32 = 960;
const HEIGHT: u32 = 640;
/// Progressive passes (jittered anti-aliasing, fresh AO directions).
const PASSES: u32 = 4;

/// The terrain coloured by its height.
fn terrain() -> anyhow::Result<Mesh> {
    let terrain = scenes::terrain(257);
    let heights: Vec<f32> = terrain.positions().iter().map(|p| p.y).collect();
    Ok(Mesh::from(terrain).with_scalars(heights)?)
}

fn build_world(mesh: Mesh) -> anyhow::Result<SurfaceScene<'static>> {
    let heights = mesh.scalars().unwrap_or_default();
    let (lo, hi) = heights.iter().fold((f32::MAX, f32::MIN), |(a, b), &h| (a.min(h), b.max(h)));
    // A ring of glyphs above the terrain, sized and coloured by a scalar.
    let spheres: Vec<Sphere> = (0..24)
        .map(|i| {
            let a = i as f32 / 24.0 * std::f32::consts::TAU;
            let r = 0.03 + 0.03 * (0.5 + 0.5 * (3.0 * a).sin());
            Sphere::new(Vec3::new(0.7 * a.cos(), 0.45 + 0.1 * (2.0 * a).sin(), 0.7 * a.sin()), r)
        })
        .collect();
    let radii = spheres.iter().map(|s| s.radius).collect();
    // A helical streamline as a tube, coloured by its height.
    let helix: Vec<Vec3> = (0..=240)
        .map(|i| {
            let s = i as f32 / 240.0;
            let a = s * 4.0 * std::f32::consts::TAU;
            Vec3::new(0.25 * a.cos(), 0.1 + 0.6 * s, 0.25 * a.sin())
        })
        .collect();
    let tube = Tube {
        points: helix,
        radius: 0.015,
        scalars: None,
        paint: Paint::Solid([0.9, 0.9, 0.92]),
        material: Material::GLOSSY,
    };
    let glyphs = Glyphs {
        spheres,
        scalars: Some(radii),
        paint: Paint::Mapped(ColorMap::cool_to_warm().with_range(0.03, 0.06)?),
        material: Material { mirror: 0.25, ..Material::GLOSSY },
    };
    let height = Paint::Mapped(ColorMap::viridis().with_range(lo, hi)?);
    Ok(SurfaceScene::builder()
        .mesh(mesh, height, Material::MATTE)
        .glyphs(glyphs)
        .tube(tube)
        .build()?)
}

/// Runs `rt demo`.
///
/// # Errors
/// An unwritable folder or file.
pub fn run(a: &Args) -> anyhow::Result<()> {
    let out = a.dir.as_path();
    // The folder made (and said) and checked before any work.
    make_folder(out)?;
    let outs = Outputs::check(&[out.join("surface.png")])?;
    let mesh = terrain()?;
    // The terrain as a file, to try `rt view` on.
    let ply = out.join("terrain.ply");
    let file = std::fs::File::create(&ply).with_context(|| ply.display().to_string())?;
    write_ply(&mesh, "height", std::io::BufWriter::new(file))
        .with_context(|| ply.display().to_string())?;
    let t0 = Instant::now();
    // Smooth shading for the render; the file keeps plain geometry (`rt
    // view` computes the same normals).
    let world = build_world(mesh.with_smooth_normals())?;
    let built = t0.elapsed();
    let proj = Projection::Perspective { fov_y: 40f32.to_radians() };
    let cam = Camera::look_at(
        Vec3::new(1.5, 1.3, 2.1),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::Y,
        proj,
        WIDTH,
        HEIGHT,
    )?;
    let settings = Settings {
        lights: vec![
            Light::Ambient { color: [0.35; 3] },
            Light::Directional { direction: Vec3::new(-0.5, 1.0, 0.35), color: [0.75; 3] },
        ],
        shadows: true,
        ao_samples: 8,
        ao_distance: 0.25,
        ..Settings::default()
    };
    let mut renderer = Renderer::new(cam, settings)?;
    let t1 = Instant::now();
    // Tiles on all cores (rayon); the frame is identical at any thread count.
    for _ in 0..PASSES {
        renderer.render_pass(&world);
    }
    let rendered = t1.elapsed();
    let mut frame = renderer.frame()?;
    over_background(&mut frame, [1.0; 3], [1.0; 3]);
    let c = renderer.counts();
    let path = out.join("surface.png");
    write_png(&frame, &outs.staging(&path))?;
    outs.commit()?;
    println!(
        "wrote {} ({WIDTH}×{HEIGHT}, {} triangles + glyphs + tube; {PASSES} passes, AO 8; build {:.0} ms, render {:.0} ms; rays: {} primary, {} shadow, {} AO, {} reflection)",
        path.display(),
        world.triangle_count(),
        built.as_secs_f64() * 1e3,
        rendered.as_secs_f64() * 1e3,
        c.primary,
        c.shadow,
        c.ao,
        c.reflection,
    );
    optics::render_all(out)
}
