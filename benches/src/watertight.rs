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
//!
//! The same rays also count double hits ([`at_aims`]): where a line
//! crosses the surface once, at the shared edge or vertex it is aimed at,
//! an all-hits query that reports two triangles there counts the crossing
//! twice, and an inside/outside test by the parity of crossings fails.

use std::collections::HashMap;

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
    /// Where each ray crosses the surface at the point it is aimed at.
    pub aims: Vec<Aim>,
}

/// The point of the surface a ray of the suite is aimed at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aim {
    /// The point (for a ray from the surface, its origin).
    pub point: Vec3,
    /// How far along the ray from the point a hit still is the crossing
    /// there: a twentieth of the inradius (of a cell, for the height
    /// field) over the cosine to the most grazing face that meets there,
    /// at most a quarter of the chord through a convex mesh. So it is far
    /// above the rounding of `t` (which grows as the ray grazes: for a ray
    /// along a needle, a thousandfold) and below the distance to the next
    /// crossing.
    pub window: f32,
}

/// The scales every mesh is tried at.
pub const SCALES: [f32; 5] = [1e-8, 1e-4, 1.0, 1e4, 1e8];

/// Vertices along each side of the height field.
const FIELD: u32 = 48;

/// The suite: each mesh at each of [`SCALES`], with `targets` vertices
/// and edge midpoints aimed at per mesh.
#[must_use]
pub fn suite(targets: usize) -> Vec<Case> {
    let meshes = [
        ("icosphere", icosphere(3), true),
        ("sliver cube", sliver_cube(1000), true),
        ("needle bipyramid", needles(256, 1e-4), true),
        ("height field", terrain(FIELD), false),
    ];
    let mut cases = Vec::new();
    for (name, mesh, convex) in meshes {
        let (aimed, near) = if convex {
            (convex_rays(&mesh, targets), 0.05 * inradius(&mesh))
        } else {
            // The height field's cells are 2 / (n − 1) wide.
            (field_rays(&mesh, targets), 0.05 * 2.0 / (FIELD - 1) as f32)
        };
        let faces = faces_at(&mesh);
        let window = |r: &Ray, t: Vec3| {
            let d = r.direction.normalize();
            let cos = faces[&t.to_array().map(f32::to_bits)]
                .iter()
                .map(|n| n.dot(d).abs())
                .fold(1.0, f32::min);
            let window = near / cos.max(1e-6);
            // A quarter of the chord, where the faces there graze more
            // than the line does (a ray along a needle, at its apex).
            if convex { window.min(0.25 * chord(&mesh, r) as f32) } else { window }
        };
        let aimed: Vec<(Ray, Aim)> =
            aimed.iter().map(|&(r, t)| (r, Aim { point: t, window: window(&r, t) })).collect();
        for s in SCALES {
            let scaled = Mesh {
                positions: mesh.positions.iter().map(|p| *p * s).collect(),
                indices: mesh.indices.clone(),
            };
            let (rays, aims) = aimed
                .iter()
                .map(|(r, aim)| {
                    let aim = Aim { point: aim.point * s, window: aim.window * s };
                    (Ray { origin: r.origin * s, ..*r }, aim)
                })
                .filter(|(r, _)| r.origin.is_finite())
                .unzip();
            cases.push(Case { name: format!("{name} ×{s:e}"), mesh: scaled, rays, aims });
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

/// The unit normals of the triangles that meet at each vertex and edge
/// midpoint of `m` (keyed by the point's bits).
fn faces_at(m: &Mesh) -> HashMap<[u32; 3], Vec<Vec3>> {
    let mut faces: HashMap<[u32; 3], Vec<Vec3>> = HashMap::new();
    for t in &m.indices {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let n = (b - a).cross(c - a).normalize();
        for p in [a, b, c, (a + b) * 0.5, (b + c) * 0.5, (c + a) * 0.5] {
            faces.entry(p.to_array().map(f32::to_bits)).or_default().push(n);
        }
    }
    faces
}

/// The length of the chord of the convex, outward-facing mesh `m` on the
/// line of `r` (in units of its direction's length): between the last
/// face plane it enters and the first it leaves, in f64.
fn chord(m: &Mesh, r: &Ray) -> f64 {
    let (o, d) = (r.origin.as_dvec3(), r.direction.as_dvec3());
    let (mut enter, mut leave) = (f64::NEG_INFINITY, f64::INFINITY);
    for t in &m.indices {
        let [a, b, c] = t.map(|i| m.positions[i as usize].as_dvec3());
        let n = (b - a).cross(c - a);
        let (along, to) = (n.dot(d), n.dot(a - o));
        if along < 0.0 {
            enter = enter.max(to / along);
        } else if along > 0.0 {
            leave = leave.min(to / along);
        }
    }
    leave - enter
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

/// The inradius of a convex mesh about its centroid: the distance to the
/// nearest face plane.
fn inradius(m: &Mesh) -> f32 {
    let c = centroid(m);
    m.indices
        .iter()
        .map(|t| {
            let [a, b, d] = t.map(|i| m.positions[i as usize]);
            (b - a).cross(d - a).normalize().dot(a - c).abs()
        })
        .fold(f32::INFINITY, f32::min)
}

/// Rays through the targets of a convex mesh and a point inside it, each
/// with its target.
fn convex_rays(m: &Mesh, count: usize) -> Vec<(Ray, Vec3)> {
    let c = centroid(m);
    let inradius = inradius(m);
    let (lo, hi) = m.bounds();
    let far = 3.0 * (hi - lo).length();
    let mut random = Random(0x5eed);
    let mut rays = Vec::new();
    // Outside, on the line through `t` along `d`: the ray aimed at `t`.
    let aimed = |t: Vec3, d: Vec3| (Ray::new(t - d * far, d), t);
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
        rays.push((Ray::new(t, (p - t).normalize()), t));
    }
    rays
}

/// Rays from above through the targets of a height field over
/// `[-1, 1]²` (those within 0.95 of its centre on both axes), each with
/// its target: straight down, and tilted where a tilt crosses the
/// surface there once.
fn field_rays(m: &Mesh, count: usize) -> Vec<(Ray, Vec3)> {
    let faces = faces_at(m);
    let mut random = Random(0xf1e1d);
    let mut rays = Vec::new();
    for t in targets(m, count * 2) {
        if t.x.abs() > 0.95 || t.z.abs() > 0.95 {
            continue;
        }
        // A tilted line crosses the surface once at `t` only if it passes
        // every face there from the same side, at an angle: else it may
        // touch the surface there, and cross it twice or not at all.
        let at = &faces[&t.to_array().map(f32::to_bits)];
        let once = |d: Vec3| {
            let cos: Vec<f32> = at.iter().map(|n| n.dot(d)).collect();
            cos.iter().all(|c| *c > 0.2) || cos.iter().all(|c| *c < -0.2)
        };
        let tilted = (0..16)
            .map(|_| Vec3::new(random.next() - 0.5, -1.0, random.next() - 0.5).normalize())
            .find(|d| once(*d));
        for d in core::iter::once(-Vec3::Y).chain(tilted) {
            rays.push((Ray::new(t - d * 4.0, d), t));
        }
    }
    rays
}

/// How many of `case`'s rays `hits` says miss.
pub fn misses(case: &Case, mut hits: impl FnMut(&Ray) -> bool) -> usize {
    case.rays.iter().filter(|r| !hits(r)).count()
}

/// What an all-hits query reported where the suite's rays cross the
/// surface at the point they are aimed at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AtAims {
    /// Rays counted: those aimed at their point from outside (a ray from
    /// the surface is left out: whether a hit at `t = 0` counts is a
    /// convention, not a crack).
    pub rays: usize,
    /// Rays with no hit at their point (a crack).
    pub missed: usize,
    /// Rays with hits on two or more triangles at their point, where the
    /// line crosses the surface once (a double count: an inside/outside
    /// test by counting crossings gets it wrong).
    pub doubled: usize,
}

impl core::ops::AddAssign for AtAims {
    fn add_assign(&mut self, o: Self) {
        self.rays += o.rays;
        self.missed += o.missed;
        self.doubled += o.doubled;
    }
}

/// Counts, over `case`'s rays aimed from outside, the crossings that
/// `all_hits` (every hit along a ray as `(t, triangle)`, in any order)
/// reports at the aimed point: the hits within its [`Aim::window`], one a
/// triangle (a triangle reported twice, as a BVH with split references
/// may, is one).
pub fn at_aims(case: &Case, mut all_hits: impl FnMut(&Ray) -> Vec<(f32, u32)>) -> AtAims {
    let mut out = AtAims::default();
    for (r, aim) in case.rays.iter().zip(&case.aims) {
        let d = r.direction.as_dvec3();
        let t_aim = (aim.point.as_dvec3() - r.origin.as_dvec3()).dot(d) / d.length_squared();
        let window = f64::from(aim.window) / d.length();
        if t_aim <= window {
            continue;
        }
        let mut there: Vec<u32> = all_hits(r)
            .into_iter()
            .filter(|&(t, _)| (f64::from(t) - t_aim).abs() <= window)
            .map(|(_, prim)| prim)
            .collect();
        there.sort_unstable();
        there.dedup();
        out.rays += 1;
        out.missed += usize::from(there.is_empty());
        out.doubled += usize::from(there.len() > 1);
    }
    out
}
