//! Criterion: what each skip of docs/physics.md §5 saves, one thread. Each group
//! times the same frame or trace with the work present and skipped:
//! - `shadows`, `ao`, `reflection`: a 128² frame of a 32k-triangle terrain
//!   with mirroring glyphs, with and without shadow rays, AO rays (4) and
//!   reflective material;
//! - `cull`: a camera looking away from the scene, the renderer (every
//!   primary ray stopped by the scene-bounds test) against the same rays
//!   sent through the BVH;
//! - `moving_mesh`: vertices moved, the BVH refitted against rebuilt;
//! - `volume`: 128² photons through the sparse 128³ bump field, marched
//!   everywhere (`trace`), skipping uniform octree nodes
//!   (`trace_skipping`), and with the beam mask (`render_medium` on a grid).
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]
// criterion_group! generates undocumented items.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{
    BenchmarkGroup, Criterion, criterion_group, criterion_main, measurement::WallTime,
};
use glam::{Vec2, Vec3};
use rayon::ThreadPool;
use rt_accel::{BuildParams, TriangleMesh};
use rt_benches::scenes::{self, knife_bench, sparse_bumps};
use rt_core::{Camera, Projection, SceneQuery, intersect::Sphere};
use rt_photo::{Film, Filter};
use rt_photo::{GridMedium, Medium};
use rt_surface::{Glyphs, Light, Material, Paint, Renderer, Settings, SurfaceScene};
use rt_volume::{TraceParams, build_octree, trace, trace_skipping};

const SIZE: u32 = 128;

fn world(mirror: f32) -> SurfaceScene<'static> {
    let t = scenes::terrain(129);
    let mesh = TriangleMesh::new(t.positions, t.indices).expect("terrain");
    let spheres = (0..12)
        .map(|i| {
            let a = i as f32 / 12.0 * std::f32::consts::TAU;
            Sphere::new(Vec3::new(0.6 * a.cos(), 0.45, 0.6 * a.sin()), 0.06)
        })
        .collect();
    let glyphs = Glyphs {
        spheres,
        scalars: None,
        paint: Paint::Solid([0.8, 0.3, 0.2]),
        material: Material { mirror, ..Material::GLOSSY },
    };
    SurfaceScene::build(
        vec![(mesh.into(), Paint::Solid([0.7; 3]), Material::MATTE)],
        vec![glyphs],
        vec![],
        &BuildParams::medium(),
    )
    .expect("scene")
}

fn camera(target: Vec3) -> Camera {
    let proj = Projection::Perspective { fov_y: 40f32.to_radians() };
    Camera::look_at(Vec3::new(1.5, 1.3, 2.1), target, Vec3::Y, proj, SIZE, SIZE).expect("camera")
}

fn settings(shadows: bool, ao_samples: u32) -> Settings {
    Settings {
        lights: vec![
            Light::Ambient { color: [0.35; 3] },
            Light::Directional { direction: Vec3::new(-0.5, 1.0, 0.35), color: [0.75; 3] },
        ],
        shadows,
        ao_samples,
        ao_distance: 0.25,
        ..Settings::default()
    }
}

/// A frame timed with the renderer's tiles on `pool` (one thread).
fn frame(
    g: &mut BenchmarkGroup<'_, WallTime>,
    pool: &ThreadPool,
    name: &str,
    s: &SurfaceScene<'_>,
    cam: Camera,
    st: &Settings,
) {
    g.bench_function(name, |b| {
        b.iter(|| {
            let mut r = Renderer::new(cam, st.clone()).expect("renderer");
            pool.install(|| r.render_pass(s))
        });
    });
}

fn skips(c: &mut Criterion) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    {
        let matte = world(0.0);
        let mirror = world(0.3);
        let view = camera(Vec3::new(0.0, 0.1, 0.0));
        let mut g = c.benchmark_group("skip_shadows");
        frame(&mut g, &pool, "cast", &matte, view, &settings(true, 0));
        frame(&mut g, &pool, "skipped", &matte, view, &settings(false, 0));
        g.finish();
        let mut g = c.benchmark_group("skip_ao");
        frame(&mut g, &pool, "ao4", &matte, view, &settings(false, 4));
        frame(&mut g, &pool, "skipped", &matte, view, &settings(false, 0));
        g.finish();
        let mut g = c.benchmark_group("skip_reflection");
        frame(&mut g, &pool, "mirror", &mirror, view, &settings(false, 0));
        frame(&mut g, &pool, "skipped", &matte, view, &settings(false, 0));
        g.finish();

        // Looking straight up, away from everything.
        let away = camera(Vec3::new(1.5, 5.0, 2.11));
        let mut g = c.benchmark_group("skip_cull");
        frame(&mut g, &pool, "renderer_culled", &matte, away, &settings(true, 4));
        let rays: Vec<_> = (0..SIZE * SIZE)
            .map(|i| away.generate_ray(i % SIZE, i / SIZE, Vec2::splat(0.5), Vec2::ZERO))
            .collect();
        g.bench_function("bvh_traversed", |b| {
            b.iter(|| rays.iter().filter(|r| matte.closest_hit(black_box(r)).is_some()).count());
        });
        g.finish();
    }

    let t = scenes::terrain(257);
    let moved: Vec<Vec3> = t.positions.iter().map(|p| *p + Vec3::new(0.0, 0.01, 0.0)).collect();
    let mesh = TriangleMesh::new(t.positions.clone(), t.indices.clone()).expect("terrain");
    let mut s = SurfaceScene::build(
        vec![(mesh.clone().into(), Paint::Solid([0.7; 3]), Material::MATTE)],
        vec![],
        vec![],
        &BuildParams::medium(),
    )
    .expect("scene");
    let mut g = c.benchmark_group("skip_moving_mesh_131k");
    g.sample_size(20);
    g.bench_function("refit", |b| b.iter(|| s.set_mesh_positions(0, &moved).expect("refit")));
    g.bench_function("rebuild", |b| {
        b.iter(|| s.replace_mesh(0, mesh.clone().into()).expect("rebuild"))
    });
    g.finish();

    let f = sparse_bumps();
    let tree = build_octree(&f).expect("octree");
    let bench = knife_bench(TraceParams::for_grid(&f), 1);
    let mut g = c.benchmark_group("skip_volume_sparse128");
    g.sample_size(10);
    {
        let film = || Film::new(128, 128, Filter::Box).expect("film");
        g.bench_function("march_everywhere", |b| {
            b.iter(|| {
                pool.install(|| {
                    bench.render_with(&|o, d| trace(&f, o, d, &bench.params), &mut film(), 0, 7)
                })
            })
        });
        g.bench_function("octree_skipping", |b| {
            let tol = bench.skip_tolerance(&f, &film());
            b.iter(|| {
                pool.install(|| {
                    bench.render_with(
                        &|o, d| trace_skipping(&f, &tree, o, d, &bench.params, tol),
                        &mut film(),
                        0,
                        7,
                    )
                })
            })
        });
        let medium = Medium::Grid(GridMedium::from_field(f.clone(), bench.params).expect("octree"));
        g.bench_function("beam_mask", |b| {
            b.iter(|| pool.install(|| bench.render_medium(&medium, &mut film(), 0, 7)))
        });
    }
    g.finish();
}

criterion_group!(benches, skips);
criterion_main!(benches);
