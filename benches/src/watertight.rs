//! A watertight suite: closed meshes and rays that must hit them, each
//! aimed exactly at a vertex or a shared edge. Whatever the tracer, a ray
//! of this suite that reports no hit is a miss (a crack between two
//! triangles that share an edge, or a vertex that belongs to none).
//!
//! Why each ray must hit: every ray passes through a point `T` of the
//! surface (a vertex, or the midpoint of an edge) and, on its line, a
//! point inside the solid (for the convex meshes, a point within 0.98 of
//! the inradius of the centroid; for the height field, any point below
//! it), so the line crosses the closed surface; its origin lies outside
//! (or on the surface, looking inwards), so the crossing is at `t ≥ 0`.
//! The meshes: an icosphere; a cube whose four faces around the x axis
//! are strips of slivers (each 1000 times longer than wide); a bipyramid
//! of needles (512 triangles meeting at each apex, 10⁴ times longer than
//! wide); a height field (aimed at from above). The rays: from random
//! directions, along the axes, shallow (lines within 2 % of the
//! inradius of the surface), and from the surface inwards; at scales from
//! 10⁻⁸ to 10⁸.

use glam::Vec3;
use rt_core::Ray;

use crate::scenes::{Mesh, icosphere, terrain};

/// One mesh of the suite and its rays, every one of which must hit.
#[derive(Clone, Debug)]
pub struct Case {
    /// The mesh and the scale it is at (`"icosphere ×1e-8"`).
    pub name: String,
    /// The closed mesh.
    pub mesh: Mesh,
    /// Rays that must hit it.
    pub rays: Vec<Ray>,
}

/// The scales every mesh is tried at.
pub const SCALES: [f32; 5] = [1e-8, 1e-4, 1.0, 1e4, 1e8];

/// The suite: each mesh at each of [`SCALES`], with `targets` vertices
/// and edge midpoints aimed at per mesh.
#[must_use]
pub fn suite(targets: usize) -> Vec<Case> {
    let meshes = [
        ("icosphere", icosphere(3), true),
        ("sliver cube", sliver_cube(1000), true),
        ("needle bipyramid", needles(256, 1e-4), true),
        ("height field", terrain(48), false),
    ];
    let mut cases = Vec::new();
    for (name, mesh, convex) in meshes {
        let rays = if convex { convex_rays(&mesh, targets) } else { field_rays(&mesh, targets) };
        for s in SCALES {
            let scaled = Mesh {
                positions: mesh.positions.iter().map(|p| *p * s).collect(),
                indices: mesh.indices.clone(),
            };
            let rays = rays
                .iter()
                .map(|r| Ray { origin: r.origin * s, ..*r })
                .filter(|r| r.origin.is_finite())
                .collect();
            cases.push(Case { name: format!("{name} ×{s:e}"), mesh: scaled, rays });
        }
    }
    cases
}

/// The cube `[-1, 1]³` whose four faces around the x axis are strips of
/// `2n` slivers between its x edges (each split into `n` equal parts,
/// shared by both faces that meet there); the two x faces are two
/// triangles each. Closed, outward-facing.
#[must_use]
pub fn sliver_cube(n: u32) -> Mesh {
    let mut m = Mesh::default();
    // The four x edges, in order around the axis: (y, z).
    let around = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let edge = |m: &mut Mesh, (y, z): (f32, f32)| -> u32 {
        let first = m.positions.len() as u32;
        for i in 0..=n {
            let x = -1.0 + 2.0 * i as f32 / n as f32;
            m.positions.push(Vec3::new(x, y, z));
        }
        first
    };
    let starts: Vec<u32> = around.iter().map(|&e| edge(&mut m, e)).collect();
    for k in 0..4 {
        let (a, b) = (starts[k], starts[(k + 1) % 4]);
        for i in 0..n {
            m.indices.push([a + i, a + i + 1, b + i + 1]);
            m.indices.push([a + i, b + i + 1, b + i]);
        }
    }
    // The x = ±1 faces: the edges' first and last vertices.
    let ends = |j: u32| -> Vec<u32> { starts.iter().map(|s| s + j).collect() };
    let (lo, hi) = (ends(0), ends(n));
    m.indices.push([lo[0], lo[2], lo[1]]);
    m.indices.push([lo[0], lo[3], lo[2]]);
    m.indices.push([hi[0], hi[1], hi[2]]);
    m.indices.push([hi[0], hi[2], hi[3]]);
    orient_outwards(&mut m);
    m
}

/// A bipyramid of needles: `n` vertices on a circle of radius `r` in the
/// y = 0 plane, joined to apexes at y = ±1: `2n` triangles, each about
/// `n / (2π r)` times longer than wide. Closed, outward-facing.
#[must_use]
pub fn needles(n: u32, r: f32) -> Mesh {
    let mut m = Mesh::default();
    for i in 0..n {
        let a = core::f32::consts::TAU * i as f32 / n as f32;
        m.positions.push(Vec3::new(r * a.cos(), 0.0, r * a.sin()));
    }
    m.positions.push(Vec3::Y);
    m.positions.push(-Vec3::Y);
    for i in 0..n {
        let j = (i + 1) % n;
        m.indices.push([i, n, j]);
        m.indices.push([i, j, n + 1]);
    }
    orient_outwards(&mut m);
    m
}

/// Turns each triangle of a convex mesh around its centroid to face out.
fn orient_outwards(m: &mut Mesh) {
    let c = centroid(m);
    for t in &mut m.indices {
        let [a, b, d] = t.map(|i| m.positions[i as usize]);
        if (b - a).cross(d - a).dot(a - c) < 0.0 {
            t.swap(1, 2);
        }
    }
}

fn centroid(m: &Mesh) -> Vec3 {
    let (lo, hi) = m.bounds();
    (lo + hi) * 0.5
}

/// Vertices and edge midpoints of `m`, `count` of them spread evenly.
fn targets(m: &Mesh, count: usize) -> Vec<Vec3> {
    let mut all: Vec<Vec3> = m.positions.clone();
    for t in &m.indices {
        for k in 0..3 {
            let (a, b) = (m.positions[t[k] as usize], m.positions[t[(k + 1) % 3] as usize]);
            all.push((a + b) * 0.5);
        }
    }
    let step = (all.len() / count.max(1)).max(1);
    all.into_iter().step_by(step).take(count).collect()
}

/// A deterministic generator of numbers in `[0, 1)` (SplitMix64).
struct Random(u64);

impl Random {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }

    /// A point of the unit ball.
    fn ball(&mut self) -> Vec3 {
        loop {
            let p = Vec3::new(self.next(), self.next(), self.next()) * 2.0 - Vec3::ONE;
            if p.length_squared() <= 1.0 {
                return p;
            }
        }
    }
}

/// Rays through the targets of a convex mesh and a point inside it.
fn convex_rays(m: &Mesh, count: usize) -> Vec<Ray> {
    let c = centroid(m);
    // The inradius about the centroid: the nearest face plane.
    let inradius = m
        .indices
        .iter()
        .map(|t| {
            let [a, b, d] = t.map(|i| m.positions[i as usize]);
            (b - a).cross(d - a).normalize().dot(a - c).abs()
        })
        .fold(f32::INFINITY, f32::min);
    let (lo, hi) = m.bounds();
    let far = 3.0 * (hi - lo).length();
    let mut random = Random(0x5eed);
    let mut rays = Vec::new();
    // Outside, on the line through `t` along `d`: the ray aimed at `t`.
    let aimed = |t: Vec3, d: Vec3| Ray::new(t - d * far, d);
    for t in targets(m, count) {
        for _ in 0..2 {
            let p = c + random.ball() * (0.5 * inradius);
            rays.push(aimed(t, (p - t).normalize()));
        }
        // Along the axes whose line passes within the inradius.
        for axis in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            let off = (c - t) - axis * (c - t).dot(axis);
            if (c - t).dot(axis) > 0.0 && off.length() < 0.9 * inradius {
                rays.push(aimed(t, axis));
            }
        }
        // Shallow: a line within 2 % of the inradius of the surface.
        let out = (t - c).normalize();
        let side = out.any_orthonormal_vector();
        let p = c + side * (0.98 * inradius);
        rays.push(aimed(t, (p - t).normalize()));
        // From the surface, inwards.
        let p = c + random.ball() * (0.5 * inradius);
        rays.push(Ray::new(t, (p - t).normalize()));
    }
    rays
}

/// Rays from above through the targets of a height field over
/// `[-1, 1]²` (those within 0.95 of its centre on both axes).
fn field_rays(m: &Mesh, count: usize) -> Vec<Ray> {
    let mut random = Random(0xf1e1d);
    let mut rays = Vec::new();
    for t in targets(m, count * 2) {
        if t.x.abs() > 0.95 || t.z.abs() > 0.95 {
            continue;
        }
        let tilted = Vec3::new(random.next() - 0.5, -1.0, random.next() - 0.5).normalize();
        for d in [-Vec3::Y, tilted] {
            rays.push(Ray::new(t - d * 4.0, d));
        }
    }
    rays
}

/// How many of `case`'s rays `hits` says miss.
pub fn misses(case: &Case, mut hits: impl FnMut(&Ray) -> bool) -> usize {
    case.rays.iter().filter(|r| !hits(r)).count()
}
