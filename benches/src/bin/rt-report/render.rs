//! The surface renderer on a ≥ 1M-triangle terrain at 1024²: AO 0/4/16,
//! one thread and all cores; rays by kind from the renderer's counters.

use std::{fmt::Write as _, path::Path};

use glam::Vec3;
use rt_accel::{BuildParams, Paint, SurfaceScene, TriangleMesh};
use rt_benches::scenes;
use rt_core::{Camera, ColorMap, Light, Material, Projection, Renderer, Settings};

use crate::timing::time;

pub(crate) fn run(dir: &Path, quick: bool) -> Result<(), String> {
    // 725² vertices: 1 048 352 triangles (the quick run: 257², 131 072).
    let (n, size) = if quick { (257, 512) } else { (725, 1024) };
    let t = scenes::terrain(n);
    let heights: Vec<f32> = t.positions.iter().map(|p| p.y).collect();
    let (lo, hi) = heights.iter().fold((f32::MAX, f32::MIN), |(a, b), &h| (a.min(h), b.max(h)));
    let mesh =
        TriangleMesh::new(t.positions, t.indices, Some(heights)).map_err(|e| e.to_string())?;
    let map = ColorMap::viridis().with_range(lo, hi).map_err(|e| e.to_string())?;
    let scene = SurfaceScene::build(
        vec![(mesh, Paint::Mapped(map), Material::MATTE)],
        vec![],
        vec![],
        &BuildParams::medium(),
    )
    .map_err(|e| e.to_string())?;
    let cam = Camera::look_at(
        Vec3::new(1.6, 1.4, 2.2),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::Y,
        Projection::Perspective { fov_y: 40f32.to_radians() },
        size,
        size,
    )
    .map_err(|e| e.to_string())?;
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut csv = String::from(
        "scene,threads,width,height,ao_samples,seconds,primary_rays,shadow_rays,ao_rays,reflection_rays\n",
    );
    let mut md = String::from(
        "| threads | AO | seconds | primary | shadow | AO rays | Mrays/s |\n|---|---|---|---|---|---|---|\n",
    );
    let mut single = std::collections::HashMap::new();
    let mut verdicts = Vec::new();
    for ao in [0u32, 4, 16] {
        for threads in [1, cores] {
            let settings = Settings {
                lights: vec![
                    Light::Ambient { color: [0.35; 3] },
                    Light::Directional { direction: Vec3::new(-0.5, 1.0, 0.35), color: [0.75; 3] },
                ],
                shadows: true,
                ao_samples: ao,
                ao_distance: 0.2,
                ..Settings::default()
            };
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| e.to_string())?;
            // Best of 3 single passes.
            let mut best = f64::INFINITY;
            let mut counts = None;
            for _ in 0..if quick { 1 } else { 3 } {
                let mut r = Renderer::new(cam, settings.clone()).map_err(|e| e.to_string())?;
                let (s, c) = time(|| pool.install(|| r.render_pass(&scene)));
                best = best.min(s);
                counts = Some(c);
            }
            let c = counts.ok_or("no run")?;
            writeln!(
                csv,
                "terrain{},{threads},{size},{size},{ao},{best:.4},{},{},{},{}",
                scene.triangle_count(),
                c.primary,
                c.shadow,
                c.ao,
                c.reflection
            )
            .unwrap();
            writeln!(
                md,
                "| {threads} | {ao} | {best:.3} | {} | {} | {} | {:.2} |",
                c.primary,
                c.shadow,
                c.ao,
                c.total() as f64 / best / 1e6
            )
            .unwrap();
            if threads == 1 {
                single.insert(ao, best);
            } else if let Some(s1) = single.get(&ao) {
                verdicts.push(format!(
                    "AO {ao}: parallel efficiency on {threads} cores {:.2} (target ≥ 0.9)",
                    s1 / best / threads as f64
                ));
            }
        }
    }
    std::fs::write(dir.join("render.csv"), &csv).map_err(|e| e.to_string())?;
    println!(
        "## render ({} triangles, {size}², one pass, directional light with shadows + ambient)\n\n{md}\n- {}\nwrote {}",
        scene.triangle_count(),
        verdicts.join("\n- "),
        dir.join("render.csv").display()
    );
    Ok(())
}
