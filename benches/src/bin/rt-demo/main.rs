//! The main job: renders the built-in scenes and writes PNGs.
//!
//! ```text
//! cargo run --release -p rt-benches --bin rt-demo -- [OUT_DIR]   (default: out/)
//! ```
//!
//! Writes, 8-bit sRGB PNGs:
//! - `surface.png`: a ray-traced scientific surface scene: a terrain mesh
//!   coloured by its height through viridis (the scalar is interpolated
//!   across each triangle, then mapped), sphere glyphs coloured with the
//!   cool-to-warm map, and a streamline tube of capsules, under a
//!   directional light with hard shadows.
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
use rt_accel::{BuildParams, Scene, TriangleMesh, build_capsules, build_spheres};
use rt_benches::{image::write_png, scenes};
use rt_core::{
    Camera, ColorMap, Frame, Hit, PrimKind, Projection, Ray, SceneQuery,
    glam::Vec2,
    intersect::{Capsule, Sphere},
    spawn_ray,
};

const WIDTH: u32 = 960;
const HEIGHT: u32 = 640;

struct World {
    scene: Scene,
    mesh: TriangleMesh,
    spheres: Vec<Sphere>,
    height_map: ColorMap<'static>,
    glyph_map: ColorMap<'static>,
    light_dir: Vec3,
}

fn build_world() -> Result<World, String> {
    let terrain = scenes::terrain(257);
    let heights: Vec<f32> = terrain.positions.iter().map(|p| p.y).collect();
    let (lo, hi) = heights.iter().fold((f32::MAX, f32::MIN), |(a, b), &h| (a.min(h), b.max(h)));
    let mesh = TriangleMesh::new(terrain.positions, terrain.indices, Some(heights))
        .map_err(|e| e.to_string())?;
    let params = BuildParams::medium();
    let triangles = mesh.build_bvh(&params).map_err(|e| e.to_string())?;
    // A ring of glyphs above the terrain, sized and coloured by a scalar.
    let spheres: Vec<Sphere> = (0..24)
        .map(|i| {
            let a = i as f32 / 24.0 * std::f32::consts::TAU;
            let r = 0.03 + 0.03 * (0.5 + 0.5 * (3.0 * a).sin());
            Sphere::new(Vec3::new(0.7 * a.cos(), 0.45 + 0.1 * (2.0 * a).sin(), 0.7 * a.sin()), r)
        })
        .collect();
    // A helical streamline as a tube of capsules.
    let helix: Vec<Vec3> = (0..=240)
        .map(|i| {
            let s = i as f32 / 240.0;
            let a = s * 4.0 * std::f32::consts::TAU;
            Vec3::new(0.25 * a.cos(), 0.1 + 0.6 * s, 0.25 * a.sin())
        })
        .collect();
    let tubes: Vec<Capsule> = helix.windows(2).map(|w| Capsule::new(w[0], w[1], 0.015)).collect();
    let scene = Scene {
        triangles,
        spheres: build_spheres(&spheres, &params).map_err(|e| e.to_string())?,
        capsules: build_capsules(&tubes, &params).map_err(|e| e.to_string())?,
    };
    Ok(World {
        scene,
        mesh,
        spheres,
        height_map: ColorMap::viridis().with_range(lo, hi).map_err(|e| e.to_string())?,
        glyph_map: ColorMap::cool_to_warm().with_range(0.03, 0.06).map_err(|e| e.to_string())?,
        light_dir: Vec3::new(-0.5, 1.0, 0.35).normalize(),
    })
}

/// Linear RGB of a hit surface before lighting.
fn albedo(w: &World, h: &Hit) -> [f32; 3] {
    let c = match h.kind {
        PrimKind::Triangle => w.height_map.map(w.mesh.interpolate_scalar(h).unwrap_or(f32::NAN)),
        PrimKind::Sphere => w.glyph_map.map(w.spheres[h.prim as usize].radius),
        PrimKind::Capsule => [0.9, 0.9, 0.92, 1.0],
    };
    [c[0], c[1], c[2]]
}

/// Lambert under one directional light with a hard shadow, plus ambient.
fn shade(w: &World, ray: &Ray) -> ([f32; 4], f32) {
    let Some(h) = w.scene.closest_hit(ray) else { return ([0.0; 4], f32::INFINITY) };
    // Face the normal toward the viewer.
    let n = if h.normal.dot(ray.direction) > 0.0 { -h.normal } else { h.normal };
    let cos = n.dot(w.light_dir).max(0.0);
    let lit = if cos > 0.0 {
        let shadow = spawn_ray(h.position, h.position_error, n, w.light_dir);
        if w.scene.occluded(&shadow) { 0.0 } else { cos }
    } else {
        0.0
    };
    let a = albedo(w, &h);
    let k = 0.25 + 0.75 * lit;
    ([a[0] * k, a[1] * k, a[2] * k, 1.0], h.t)
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
    let t0 = Instant::now();
    let world = build_world()?;
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
    let mut frame = Frame::new(WIDTH, HEIGHT).map_err(|e| e.to_string())?;
    // Rows split over the machine's threads; each pixel depends only on its
    // own ray, so the image is identical at any thread count.
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let rows_per = (HEIGHT as usize).div_ceil(threads);
    let t1 = Instant::now();
    std::thread::scope(|s| {
        for (chunk, pixels) in frame.pixels_mut().chunks_mut(rows_per * WIDTH as usize).enumerate()
        {
            let (world, cam) = (&world, &cam);
            s.spawn(move || {
                for (i, px) in pixels.iter_mut().enumerate() {
                    let idx = chunk * rows_per * WIDTH as usize + i;
                    let (x, y) = ((idx % WIDTH as usize) as u32, (idx / WIDTH as usize) as u32);
                    let ray = cam.generate_ray(x, y, Vec2::splat(0.5), Vec2::ZERO);
                    let (color, depth) = shade(world, &ray);
                    px.color = color;
                    px.depth = depth;
                }
            });
        }
    });
    let rendered = t1.elapsed();
    let path = out.join("surface.png");
    write_png(&frame, &path)?;
    println!(
        "wrote {} ({WIDTH}×{HEIGHT}, {} triangles + {} spheres + {} tubes; build {:.0} ms, render {:.0} ms on {threads} threads)",
        path.display(),
        world.mesh.indices().len(),
        world.spheres.len(),
        world.scene.capsules.prim_count(),
        built.as_secs_f64() * 1e3,
        rendered.as_secs_f64() * 1e3,
    );
    schlieren::render_all(out)
}
