//! Criterion: BVH build time per preset (obvhs's up to medium, and the
//! binned SAH builder).
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]
// criterion_group! generates undocumented items.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use rt_accel::{BuildParams, BuildQuality, build_triangles};
use rt_benches::scenes;

fn build(c: &mut Criterion) {
    let mesh = scenes::icosphere(5);
    let mut g = c.benchmark_group("build_icosphere5");
    g.sample_size(10);
    for q in &BuildQuality::ALL[..5] {
        let p = BuildParams { quality: *q, ..BuildParams::medium() };
        g.bench_function(q.name(), |b| {
            b.iter(|| build_triangles(&mesh.positions, &mesh.indices, &p).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, build);
criterion_main!(benches);
