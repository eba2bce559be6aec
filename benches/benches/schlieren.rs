//! Criterion: one knife-edge schlieren pass (128² photons, 128² film) of
//! the sparse 128³ bump field on one thread: the original scheme against
//! rt's default for grids, per photon.
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]
// criterion_group! generates undocumented items.
#![allow(missing_docs)]

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use rt_benches::scenes::{knife_bench, sparse_bumps};
use rt_photo::{Film, Filter};
use rt_photo::{GridMedium, Medium};
use rt_volume::{Method, TraceParams, trace};

fn schlieren(c: &mut Criterion) {
    let f = sparse_bumps();
    let h = f.grid().spacing().x;
    let rt = TraceParams::for_grid(&f);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("pool");
    let mut g = c.benchmark_group("schlieren_sparse128_1thread");
    g.sample_size(10).throughput(Throughput::Elements(128 * 128));
    for (name, params) in [
        ("original", TraceParams::fixed(Method::Euler, h)),
        ("rt", rt),
        ("rt-2voxel", TraceParams { step: 2.0 * h, max_step: 2.0 * h, ..rt }),
    ] {
        let b = knife_bench(params, 1);
        let medium = Medium::Grid(GridMedium::from_field(f.clone(), params).expect("octree"));
        g.bench_function(name, |bn| {
            bn.iter(|| {
                let mut film = Film::new(128, 128, Filter::Box).expect("film");
                pool.install(|| {
                    if name == "original" {
                        b.render_with(&|o, d| trace(&f, o, d, &b.params), &mut film, 0, 7)
                    } else {
                        b.render_medium(&medium, &mut film, 0, 7)
                    }
                })
                .expect("render");
                film
            });
        });
    }
    g.finish();
}

criterion_group!(benches, schlieren);
criterion_main!(benches);
