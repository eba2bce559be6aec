//! The demo's built-in scenes.

use rt_accel::TriangleMesh;
use rt_core::{glam::Vec3, sampling};

/// Smooth value noise in `[-1, 1]` from an integer-lattice hash.
fn value_noise(x: f32, y: f32, seed: u64) -> f32 {
    let h = |i: i64, j: i64| {
        let k = sampling::mix64(seed ^ (i as u64).wrapping_mul(0x9e37_79b9) ^ (j as u64) << 32);
        (k >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
    };
    let (i, j) = (x.floor() as i64, y.floor() as i64);
    let (fx, fy) = (x - x.floor(), y - y.floor());
    let s = |t: f32| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (s(fx), s(fy));
    let a = h(i, j) + sx * (h(i + 1, j) - h(i, j));
    let b = h(i, j + 1) + sx * (h(i + 1, j + 1) - h(i, j + 1));
    a + sy * (b - a)
}

/// A noisy height field over `[-1, 1]²` with `n × n` vertices
/// (`2 (n − 1)²` triangles): fractal value noise, five octaves.
#[must_use]
///
/// # Panics
/// If `n < 2` or `n > 4096` (a programming error: the demo's sizes are
/// constants).
pub fn terrain(n: u32) -> TriangleMesh {
    assert!((2..=4096).contains(&n), "terrain of {n}² vertices");
    let mut positions = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let x = 2.0 * i as f32 / (n - 1) as f32 - 1.0;
            let y = 2.0 * j as f32 / (n - 1) as f32 - 1.0;
            let mut h = 0.0;
            let mut amp = 0.25;
            let mut freq = 2.0;
            for o in 0..5 {
                h += amp * value_noise(x * freq, y * freq, 17 + o);
                amp *= 0.5;
                freq *= 2.0;
            }
            positions.push(Vec3::new(x, h, y));
        }
    }
    let mut indices = Vec::with_capacity((2 * (n - 1) * (n - 1)) as usize);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            let (b, c, d) = (a + 1, a + n, a + n + 1);
            indices.push([a, c, b]);
            indices.push([b, c, d]);
        }
    }
    TriangleMesh::new(positions, indices).expect("finite heights and in-range indices")
}
