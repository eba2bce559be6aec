//! The main job: renders the built-in scenes and writes PNGs.
//!
//! ```text
//! cargo run --release -p rt-benches --bin rt-demo -- [OUT_DIR]   (default: out/)
//! ```
//!
//! Writes, 8-bit sRGB PNGs:
//! - `surface.png`: a ray-traced scientific surface scene rendered with
//!   `rt_surface::Renderer`: a terrain mesh coloured by its height through
//!   viridis (the scalar is interpolated across each triangle, then
//!   mapped), slightly mirroring sphere glyphs coloured with the
//!   cool-to-warm map, and a glossy streamline tube, under ambient light
//!   with ambient occlusion (8 rays) and a directional light with hard
//!   shadows; 4 progressive passes.
//! - `terrain.ply`: the terrain mesh with its `height` scalar, to try the
//!   `view` example on (`--scalar height`).
//! - From the built-in blast wave (`benches/data/`, a real PyClaw Euler
//!   solution, density → index by Gladstone–Dale), photons traced through
//!   the volume along z: `schlieren-knife.png` (vertical knife edge,
//!   background mid-grey), `shadowgraph.png` (film 2 m behind, background
//!   mid-grey), `interferogram.png` (10.6 µm CO₂ laser, finite fringes) and
//!   `schlieren-color.png` (hue-wheel colour filter: hue = direction of
//!   deflection, saturation = its size).
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

mod schlieren;

use std::{path::PathBuf, process::ExitCode, time::Instant};

use glam::Vec3;
use rt_benches::{image::write_png, scenes};
use rt_core::{Camera, ColorMap, Projection, intersect::Sphere};
use rt_surface::{
    Glyphs, Light, Material, Mesh, Paint, Renderer, Settings, SurfaceScene, Tube, io::write_ply,
};

const WIDTH: u32 = 960;
const HEIGHT: u32 = 640;
/// Progressive passes (jittered anti-aliasing, fresh AO directions).
const PASSES: u32 = 4;

/// The terrain coloured by its height.
fn terrain() -> Result<Mesh, String> {
    let terrain = scenes::terrain(257);
    let heights: Vec<f32> = terrain.positions.iter().map(|p| p.y).collect();
    Mesh::new(terrain.positions, terrain.indices, Some(heights)).map_err(|e| e.to_string())
}

fn build_world(mesh: Mesh) -> Result<SurfaceScene<'static>, String> {
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
        paint: Paint::Mapped(
            ColorMap::cool_to_warm().with_range(0.03, 0.06).map_err(|e| e.to_string())?,
        ),
        material: Material { mirror: 0.25, ..Material::GLOSSY },
    };
    let height = Paint::Mapped(ColorMap::viridis().with_range(lo, hi).map_err(|e| e.to_string())?);
    SurfaceScene::builder()
        .mesh(mesh, height, Material::MATTE)
        .glyphs(glyphs)
        .tube(tube)
        .build()
        .map_err(|e| e.to_string())
}

fn main() -> ExitCode {
    let out = std::env::args().nth(1).map_or_else(|| PathBuf::from("out"), PathBuf::from);
    match run(&out) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("rt-demo: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(out: &std::path::Path) -> Result<(), String> {
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mesh = terrain()?;
    // The terrain as a file, to try the `view` example on.
    let ply = out.join("terrain.ply");
    let file = std::fs::File::create(&ply).map_err(|e| format!("{}: {e}", ply.display()))?;
    write_ply(&mesh, "height", std::io::BufWriter::new(file))
        .map_err(|e| format!("{}: {e}", ply.display()))?;
    let t0 = Instant::now();
    let world = build_world(mesh)?;
    let built = t0.elapsed();
    let proj = Projection::Perspective { fov_y: 40f32.to_radians() };
    let cam = Camera::look_at(
        Vec3::new(1.5, 1.3, 2.1),
        Vec3::new(0.0, 0.1, 0.0),
        Vec3::Y,
        proj,
        WIDTH,
        HEIGHT,
    )
    .map_err(|e| e.to_string())?;
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
    let mut renderer = Renderer::new(cam, settings).map_err(|e| e.to_string())?;
    let t1 = Instant::now();
    // Tiles on all cores (rayon); the frame is identical at any thread count.
    for _ in 0..PASSES {
        renderer.render_pass(&world);
    }
    let rendered = t1.elapsed();
    let frame = renderer.frame().map_err(|e| e.to_string())?;
    let c = renderer.counts();
    let path = out.join("surface.png");
    write_png(&frame, &path)?;
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
    schlieren::render_all(out)
}
