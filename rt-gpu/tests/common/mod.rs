//! What the GPU tests share: the adapter (or why there is none) and the
//! Gaussian bump on a grid.

use rt_gpu::Gpu;
use rt_volume::{Grid, glam::DVec3};

/// The first adapter; without one, `None` (the test says so and passes),
/// unless `RT_GPU_REQUIRE` is set (CI's setting): then it fails.
pub(crate) fn gpu() -> Option<Gpu> {
    match Gpu::new() {
        Ok(g) => Some(g),
        Err(e) if std::env::var_os("RT_GPU_REQUIRE").is_none() => {
            eprintln!("no GPU test run: {e}");
            None
        }
        Err(e) => panic!("RT_GPU_REQUIRE is set: {e}"),
    }
}

/// The bump `1 + δ·exp(−|x|²/2σ²)` (σ = 1) sampled at the centres of `n³`
/// cells over `[−4, 4]³`.
pub(crate) fn bump_grid(n: usize, delta: f64) -> Grid {
    let h = 8.0 / n as f64;
    let origin = DVec3::splat(-4.0 + 0.5 * h);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = origin + h * DVec3::new(i as f64, j as f64, k as f64);
                data.push((1.0 + delta * (-p.length_squared() / 2.0).exp()) as f32);
            }
        }
    }
    Grid::new([n; 3], origin, DVec3::splat(h), data).unwrap()
}
