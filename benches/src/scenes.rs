//! Deterministic scenes and ray sets.

use glam::Vec3;
use rt_core::{Camera, Projection, Ray, glam::Vec2, sampling};
use rt_photo::{Cutoff, Mode, Reconstruction, SchlierenBench, Weighting};
use rt_volume::{Cell, Grid, GridField, Interp, TraceParams, glam::DVec3};

/// An indexed triangle mesh.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
}

impl Mesh {
    /// Bounds `(min, max)` of the vertices.
    #[must_use]
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let init = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        self.positions.iter().fold(init, |(lo, hi), p| (lo.min(*p), hi.max(*p)))
    }
}

/// A noisy height field over `[-1, 1]²` with `n × n` vertices
/// (`2 (n − 1)²` triangles): the demo's terrain ([`rt_tools::scenes::terrain`]).
#[must_use]
pub fn terrain(n: u32) -> Mesh {
    let t = rt_tools::scenes::terrain(n);
    Mesh { positions: t.positions().to_vec(), indices: t.indices().to_vec() }
}

/// The unit icosphere subdivided `level` times (`20 · 4^level` triangles).
#[must_use]
pub fn icosphere(level: u32) -> Mesh {
    let m = rt_accel::TriangleMesh::icosphere(level);
    Mesh { positions: m.positions().to_vec(), indices: m.indices().to_vec() }
}

/// `width × height` primary rays (pixel centres) of a perspective camera
/// at `eye` looking at `target`.
#[must_use]
pub fn primary_rays(eye: Vec3, target: Vec3, width: u32, height: u32) -> Vec<Ray> {
    let p = Projection::Perspective { fov_y: 50f32.to_radians() };
    let cam = Camera::look_at(eye, target, Vec3::Y, p, width, height).expect("valid camera");
    let mut rays = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            rays.push(cam.generate_ray(x, y, Vec2::splat(0.5), Vec2::ZERO));
        }
    }
    rays
}

/// `count` incoherent rays: origins uniform in the box `(lo, hi)`,
/// directions uniform on the sphere, from `seed`.
#[must_use]
pub fn incoherent_rays(lo: Vec3, hi: Vec3, count: usize, seed: u64) -> Vec<Ray> {
    let mut rng = sampling::rng_from_seed(seed);
    (0..count)
        .map(|_| {
            let u = Vec3::new(
                sampling::uniform(&mut rng),
                sampling::uniform(&mut rng),
                sampling::uniform(&mut rng),
            );
            let o = lo + (hi - lo) * u;
            let z = 1.0 - 2.0 * sampling::uniform(&mut rng);
            let phi = std::f32::consts::TAU * sampling::uniform(&mut rng);
            let r = (1.0 - z * z).max(0.0).sqrt();
            Ray::new(o, Vec3::new(r * phi.cos(), r * phi.sin(), z))
        })
        .collect()
}

/// Samples per axis of the report's bump fields.
pub const BUMP_GRID: usize = 128;

/// Ambient 1 plus Gaussian bumps `(centre, amplitude, σ)` on the unit cube.
pub fn bump_grid(bumps: &[(DVec3, f64, f64)]) -> GridField {
    let h = 1.0 / BUMP_GRID as f64;
    let origin = DVec3::splat(0.5 * h);
    let mut data = Vec::with_capacity(BUMP_GRID.pow(3));
    for k in 0..BUMP_GRID {
        for j in 0..BUMP_GRID {
            for i in 0..BUMP_GRID {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h;
                let v: f64 = 1.0
                    + bumps
                        .iter()
                        .map(|(c, a, s)| a * (-(p - *c).length_squared() / (2.0 * s * s)).exp())
                        .sum::<f64>();
                data.push(v as f32);
            }
        }
    }
    GridField::new(
        Grid::new([BUMP_GRID; 3], origin, DVec3::splat(h), data).expect("grid"),
        Interp::Trilinear,
        1.0,
    )
    .expect("field")
}

/// Four compact bumps (σ = 0.02): their gradients fill well under 10 % of
/// the volume.
pub fn sparse_bumps() -> GridField {
    bump_grid(&[
        (DVec3::new(0.3, 0.3, 0.3), 3e-3, 0.02),
        (DVec3::new(0.7, 0.35, 0.6), 2e-3, 0.02),
        (DVec3::new(0.4, 0.7, 0.5), 3e-3, 0.02),
        (DVec3::new(0.65, 0.7, 0.25), 1e-3, 0.02),
    ])
}

/// Forty broad bumps (σ = 0.08) that overlap everywhere.
pub fn dense_bumps() -> GridField {
    let bumps: Vec<_> = (0..40)
        .map(|i| {
            let t = f64::from(i);
            let c = DVec3::new(
                (t * 0.618).fract(),
                (t * 0.382 + 0.1).fract(),
                (t * 0.7548 + 0.3).fract(),
            );
            (c, 1e-3, 0.08)
        })
        .collect();
    bump_grid(&bumps)
}

/// The schlieren report's bench: a knife edge (f/h = 250) on a beam along
/// z over the unit square, `strata²` photons per pixel.
#[must_use]
pub fn knife_bench(params: TraceParams, strata: u32) -> SchlierenBench {
    SchlierenBench {
        center: DVec3::new(0.5, 0.5, -0.1),
        direction: DVec3::Z,
        u: DVec3::X,
        width: 1.0,
        height: 1.0,
        image_plane: 0.6,
        film_distance: 0.0,
        mode: Mode::Schlieren(Cutoff::KnifeEdge { angle: 0.0, offset: 0.0, f: 1.0, h: 4e-3 }),
        weighting: Weighting::Weight,
        reconstruction: Reconstruction::Photons,
        strata,
        params,
    }
}

/// The box `[lo, hi]` cut into `n³` hexahedra (VTK order) on a regular
/// lattice of `(n + 1)³` points, the point numbering shuffled with `seed`
/// (Fisher–Yates, SplitMix64), as scattered as in a real mesh's file (the
/// split into tetrahedra does not depend on the numbering).
///
/// # Panics
/// If `n` is zero or the points overflow `u32`.
#[must_use]
pub fn box_hex_mesh(lo: DVec3, hi: DVec3, n: usize, seed: u64) -> (Vec<DVec3>, Vec<Cell>) {
    assert!(n > 0, "a box mesh needs at least one cell per side");
    let side = n + 1;
    let count = side.pow(3);
    assert!(u32::try_from(count).is_ok(), "{count} points overflow u32");
    let h = (hi - lo) / n as f64;
    let lattice = |i: usize, j: usize, k: usize| i + side * (j + side * k);
    // SplitMix64 (Steele, Lea & Flood 2014): small, seeded, good enough
    // for a permutation.
    let mut state = seed;
    let mut next = move || {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    // `perm[lattice index]` = the point's number in the file.
    let mut perm: Vec<u32> = (0..count as u32).collect();
    for i in (1..count).rev() {
        perm.swap(i, (next() % (i as u64 + 1)) as usize);
    }
    let mut points = vec![DVec3::ZERO; count];
    for k in 0..side {
        for j in 0..side {
            for i in 0..side {
                points[perm[lattice(i, j, k)] as usize] =
                    lo + h * DVec3::new(i as f64, j as f64, k as f64);
            }
        }
    }
    let mut cells = Vec::with_capacity(n.pow(3));
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                cells.push(Cell::Hexahedron(
                    [
                        (i, j, k),
                        (i + 1, j, k),
                        (i + 1, j + 1, k),
                        (i, j + 1, k),
                        (i, j, k + 1),
                        (i + 1, j, k + 1),
                        (i + 1, j + 1, k + 1),
                        (i, j + 1, k + 1),
                    ]
                    .map(|(a, b, c)| perm[lattice(a, b, c)]),
                ));
            }
        }
    }
    (points, cells)
}

/// Samples per axis of [`dense_flow`] in the report.
pub const DENSE_GRID: usize = 128;

/// A density field (kg/m³) disturbed everywhere, like a real shock–bubble
/// or turbulent flow and unlike the sparse bumps: `n³` cell-centred
/// samples over a 1 m cube, air (1.2 kg/m³) carrying 48 Fourier modes of
/// random direction and phase, wavelengths log-uniform over 1/32 … 1/4
/// of the box, amplitude `∝ |k|^(−5/6)` (a Kolmogorov-like spectrum) at
/// 5 % rms, all compressed ×1.8 inside a spherical shock of radius 0.3
/// whose front is a `tanh` ramp of 1.5 cells. Octree skipping finds
/// almost nothing to skip in it. Deterministic for a `seed`.
///
/// # Panics
/// If `n < 8` (the shock's front would not be resolved).
#[must_use]
pub fn dense_flow(n: usize, seed: u64) -> Grid {
    assert!(n >= 8, "a dense flow needs at least 8 samples a side");
    let h = 1.0 / n as f64;
    let origin = DVec3::splat(0.5 * h);
    let mut rng = sampling::rng_for(seed, 0x00de_05e0);
    let modes: Vec<(DVec3, f64, f64)> = (0..48)
        .map(|_| {
            let lambda = (1.0 / 32.0) * 8f64.powf(sampling::uniform_f64(&mut rng));
            let z = 2.0 * sampling::uniform_f64(&mut rng) - 1.0;
            let phi = core::f64::consts::TAU * sampling::uniform_f64(&mut rng);
            let r = (1.0 - z * z).sqrt();
            let k = core::f64::consts::TAU / lambda * DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let phase = core::f64::consts::TAU * sampling::uniform_f64(&mut rng);
            (k, k.length().powf(-5.0 / 6.0), phase)
        })
        .collect();
    // Cosines of random phases each have mean square ½: scale to 5 % rms.
    let power: f64 = modes.iter().map(|m| 0.5 * m.1 * m.1).sum();
    let scale = 0.05 / power.sqrt();
    // e^{i(k·x + φ)} = e^{iφ} e^{i kx x} e^{i ky y} e^{i kz z}: per-axis
    // tables of (cos, sin), so a sample costs 48 complex products, not
    // 48 cosines.
    let table = |axis: usize| -> Vec<Vec<(f64, f64)>> {
        (0..n)
            .map(|i| {
                let x = origin[axis] + i as f64 * h;
                modes.iter().map(|m| ((m.0[axis] * x).cos(), (m.0[axis] * x).sin())).collect()
            })
            .collect()
    };
    let (tx, ty, tz) = (table(0), table(1), table(2));
    let mul = |a: (f64, f64), b: (f64, f64)| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let width = 1.5 * h;
    let mut data = Vec::with_capacity(n * n * n);
    for (k, zk) in tz.iter().enumerate() {
        for (j, yj) in ty.iter().enumerate() {
            let yz: Vec<(f64, f64)> = (0..modes.len())
                .map(|m| mul(mul((modes[m].2.cos(), modes[m].2.sin()), yj[m]), zk[m]))
                .collect();
            for (i, row) in tx.iter().enumerate() {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h;
                let wave: f64 =
                    (0..modes.len()).map(|m| modes[m].1 * mul(yz[m], row[m]).0).sum::<f64>();
                let r = (p - DVec3::splat(0.5)).length();
                let shock = 1.0 + 0.8 * 0.5 * (1.0 - ((r - 0.3) / width).tanh());
                data.push((1.2 * shock * (1.0 + scale * wave)) as f32);
            }
        }
    }
    Grid::new([n; 3], origin, DVec3::splat(h), data).expect("a dense flow is a valid grid")
}
