//! Criterion: closest-hit and occlusion traversal of primary, incoherent
//! and missed rays (the primary rays turned around, so they miss the
//! root box: what a query costs beyond its nodes, the ray's setup).
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]
// criterion_group! generates undocumented items.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use rt_accel::{BuildParams, build_triangles};
use rt_benches::scenes;
use rt_core::Ray;

fn traversal(c: &mut Criterion) {
    let mesh = scenes::terrain(257);
    let bvh = build_triangles(&mesh.positions, &mesh.indices, &BuildParams::medium()).unwrap();
    let (lo, hi) = mesh.bounds();
    let primary = scenes::primary_rays(Vec3::new(0.0, 1.1, 2.0), Vec3::ZERO, 128, 128);
    let missed: Vec<Ray> = primary.iter().map(|r| Ray::new(r.origin, -r.direction)).collect();
    assert!(missed.iter().all(|r| bvh.closest_t(r).is_none()), "a turned-around ray hits");
    let sets = [
        ("primary", primary),
        ("incoherent", scenes::incoherent_rays(lo, hi, 1 << 14, 1)),
        ("missed", missed),
    ];
    let mut g = c.benchmark_group("traversal_terrain257");
    for (name, rays) in &sets {
        g.throughput(Throughput::Elements(rays.len() as u64));
        g.bench_function(format!("closest_{name}"), |b| {
            b.iter(|| rays.iter().filter(|r| bvh.closest_t(black_box(r)).is_some()).count())
        });
        g.bench_function(format!("occluded_{name}"), |b| {
            b.iter(|| rays.iter().filter(|r| bvh.occluded(black_box(r))).count())
        });
    }
    g.finish();
}

criterion_group!(benches, traversal);
criterion_main!(benches);
