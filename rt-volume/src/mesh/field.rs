//! Building an [`UnstructuredField`]: the split into tetrahedra, the checks,
//! face adjacency and the boundary's BVH.

use alloc::vec::Vec;

use glam::{DVec3, Vec3};
use rt_accel::{BuildParams, Bvh, TriPacket, build_triangles};

use super::{Cell, MeshError};
use crate::Bounds;

/// No neighbour: the face is on the mesh's boundary.
pub(crate) const NONE: u32 = u32::MAX;

/// The points of face `i` of a tetrahedron: the three other than `i`.
pub(crate) const FACE: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];

/// A refractive-index field on an unstructured mesh: `n` given at the
/// points and linear inside each tetrahedron, so `∇n` is constant per
/// tetrahedron and continuous `n` crosses every face. Cells other than
/// tetrahedra are split (see [`Cell`]); rays are traced through it cell by
/// cell in closed form ([`UnstructuredField::trace`]).
///
/// Outside the mesh (beyond its boundary faces, including holes and the
/// gaps of a non-convex mesh) the index is [`UnstructuredField::ambient`].
#[derive(Clone, Debug)]
pub struct UnstructuredField {
    pub(crate) points: Vec<DVec3>,
    /// `n` at each point.
    pub(crate) index: Vec<f64>,
    /// Point indices of each tetrahedron, ordered so its volume is positive.
    pub(crate) tets: Vec<[u32; 4]>,
    /// The input cell each tetrahedron comes from.
    pub(crate) cell_of: Vec<u32>,
    /// The tetrahedron across face `i` (opposite point `i`), or [`NONE`].
    pub(crate) neighbors: Vec<[u32; 4]>,
    /// `∇n` of each tetrahedron.
    pub(crate) gradients: Vec<DVec3>,
    /// Bit `i` set: face `i`'s canonical normal (see [`face_normal`])
    /// points into the tetrahedron, so its outward normal is the negative.
    pub(crate) flips: Vec<u8>,
    /// Boundary faces as `4·tet + face`, in the BVH's primitive order.
    pub(crate) boundary: Vec<u32>,
    /// The boundary triangles, in `f32` coordinates relative to `shift`.
    pub(crate) bvh: Bvh<TriPacket>,
    pub(crate) shift: DVec3,
    pub(crate) bounds: Bounds,
    pub(crate) ambient: f64,
    /// Smallest and largest `n` at the points.
    pub(crate) range: (f64, f64),
    /// Per tetrahedron, a bound on the parameter `t` a ray can spend in it:
    /// a catenary inside a convex cell is shorter than the perimeter of
    /// the plane section it lies in (< π·diameter), and moves at
    /// `ds/dt = n ≥` the cell's smallest `n`; `4·diameter/n_min`, rounded up.
    pub(crate) reach: Vec<f32>,
}

/// The face's normal `(p_b − p_a) × (p_c − p_a)` for its points sorted by
/// index (`a < b < c`), and `p_a`. Both tetrahedra sharing a face compute it
/// with the same operations on the same numbers, so their plane tests are
/// exact negatives of each other: a point is never inside both or neither
/// by round-off.
#[inline]
pub(crate) fn face_normal(points: &[DVec3], mut ids: [u32; 3]) -> (DVec3, DVec3) {
    ids.sort_unstable();
    let [a, b, c] = ids.map(|i| points[i as usize]);
    ((b - a).cross(c - a), a)
}

/// Six times the signed volume of `(p0, p1, p2, p3)`.
fn volume6(p: [DVec3; 4]) -> f64 {
    (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))
}

/// Relative size below which a tetrahedron's volume counts as zero: `6V`
/// against the cube of its longest edge (a regular tetrahedron has 0.118).
const FLAT: f64 = 1e-12;

impl UnstructuredField {
    /// A field from points, cells and the index `n` at each point.
    /// `ambient` is the index outside the mesh.
    ///
    /// A tetrahedron's points may come in either orientation; a split cell
    /// must not fold (all its tetrahedra the same orientation).
    ///
    /// # Errors
    /// [`MeshError`] naming the first offending point or cell: no cells,
    /// NaN/∞ points, values that are not finite and positive (or `ambient`
    /// not so: `BadValue` with point `usize::MAX`), indices out of range,
    /// a point used twice by a cell, zero-volume, folded or overlapping
    /// cells, a face shared by more than two cells, sizes past `u32`.
    pub fn new(
        points: Vec<DVec3>,
        cells: &[Cell],
        index: Vec<f64>,
        ambient: f64,
    ) -> Result<Self, MeshError> {
        if cells.is_empty() {
            return Err(MeshError::Empty);
        }
        if points.len() >= NONE as usize || cells.len() >= NONE as usize {
            return Err(MeshError::TooLarge);
        }
        if index.len() != points.len() {
            return Err(MeshError::ValueCount { points: points.len(), values: index.len() });
        }
        if !(ambient.is_finite() && ambient > 0.0) {
            return Err(MeshError::BadValue { point: usize::MAX });
        }
        if let Some(point) = points.iter().position(|p| !p.is_finite()) {
            return Err(MeshError::NonFinitePoint { point });
        }
        if let Some(point) = index.iter().position(|n| !(n.is_finite() && *n > 0.0)) {
            return Err(MeshError::BadValue { point });
        }
        let (tets, cell_of) = split_cells(&points, cells)?;
        let (neighbors, flips, boundary) = adjacency(&points, &tets, &cell_of)?;
        let gradients = tets
            .iter()
            .map(|t| gradient(t.map(|i| points[i as usize]), t.map(|i| index[i as usize])))
            .collect();
        let bounds = points.iter().fold(
            Bounds::new(DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |b, p| Bounds::new(b.min.min(*p), b.max.max(*p)),
        );
        let shift = 0.5 * (bounds.min + bounds.max);
        let bvh = boundary_bvh(&points, &tets, &boundary, shift)?;
        let range =
            index.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &n| (lo.min(n), hi.max(n)));
        let reach = tets
            .iter()
            .map(|t| {
                let p = t.map(|i| points[i as usize]);
                let n_min = t.iter().map(|&i| index[i as usize]).fold(f64::INFINITY, f64::min);
                let r = (4.0 * longest_edge(p) / n_min) as f32;
                // Rounded up (and never 0 or NaN: the cell has volume).
                if r.is_finite() { f32::from_bits(r.to_bits() + 1) } else { f32::MAX }
            })
            .collect();
        Ok(Self {
            points,
            index,
            tets,
            cell_of,
            neighbors,
            gradients,
            flips,
            boundary,
            bvh,
            shift,
            bounds,
            ambient,
            range,
            reach,
        })
    }

    /// [`UnstructuredField::new`] from a scalar per point (density, say)
    /// mapped to the index by `map` (e.g. Gladstone–Dale:
    /// `|rho| rt_volume::gladstone_dale(rho, rt_volume::GLADSTONE_DALE_AIR)`).
    ///
    /// # Errors
    /// As [`UnstructuredField::new`]; a value that maps to no finite
    /// positive index is `BadValue`.
    pub fn from_values(
        points: Vec<DVec3>,
        cells: &[Cell],
        values: &[f64],
        map: impl Fn(f64) -> f64,
        ambient: f64,
    ) -> Result<Self, MeshError> {
        let index = values.iter().map(|&v| map(v)).collect();
        Self::new(points, cells, index, ambient)
    }

    /// The points.
    #[must_use]
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// `n` at each point.
    #[must_use]
    pub fn index(&self) -> &[f64] {
        &self.index
    }

    /// The tetrahedra, as point indices (positive orientation).
    #[must_use]
    pub fn tetrahedra(&self) -> &[[u32; 4]] {
        &self.tets
    }

    /// How many input cells the mesh was built from.
    #[must_use]
    pub fn cell_count(&self) -> usize {
        self.cell_of.last().map_or(0, |&c| c as usize + 1)
    }

    /// The input cell each tetrahedron comes from.
    #[must_use]
    pub fn cell_of(&self, tet: usize) -> Option<usize> {
        self.cell_of.get(tet).map(|&c| c as usize)
    }

    /// How many faces lie on the boundary (holes and outer surface).
    #[must_use]
    pub fn boundary_faces(&self) -> usize {
        self.boundary.len()
    }

    /// The box around every point.
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        self.bounds
    }

    /// The index outside the mesh.
    #[must_use]
    pub fn ambient(&self) -> f64 {
        self.ambient
    }

    /// The smallest and largest `n` at the points.
    #[must_use]
    pub fn index_range(&self) -> (f64, f64) {
        self.range
    }

    /// The index and its gradient inside tetrahedron `tet` at `x` (its
    /// linear function, also continued outside it).
    #[inline]
    pub(crate) fn linear(&self, tet: usize, x: DVec3) -> (f64, DVec3) {
        let v0 = self.tets[tet][0] as usize;
        let g = self.gradients[tet];
        (self.index[v0] + g.dot(x - self.points[v0]), g)
    }

    /// The outward plane of face `i` of `tet`: `(normal, point)`, not unit.
    #[inline]
    pub(crate) fn plane(&self, tet: usize, i: usize) -> (DVec3, DVec3) {
        let t = self.tets[tet];
        let (nrm, a) = face_normal(&self.points, FACE[i].map(|k| t[k]));
        (if self.flips[tet] >> i & 1 == 1 { -nrm } else { nrm }, a)
    }
}

/// Splits every cell, checks it, and orients its tetrahedra positively.
fn split_cells(points: &[DVec3], cells: &[Cell]) -> Result<(Vec<[u32; 4]>, Vec<u32>), MeshError> {
    let total: usize = cells.iter().map(Cell::tet_count).sum();
    if total >= NONE as usize {
        return Err(MeshError::TooLarge);
    }
    let mut tets = Vec::with_capacity(total);
    let mut cell_of = Vec::with_capacity(total);
    for (c, cell) in cells.iter().enumerate() {
        let ids = cell.points();
        if let Some(&index) = ids.iter().find(|&&i| i as usize >= points.len()) {
            return Err(MeshError::IndexOutOfRange { cell: c, index });
        }
        if ids.iter().enumerate().any(|(k, i)| ids[..k].contains(i)) {
            return Err(MeshError::RepeatedPoint { cell: c });
        }
        let start = tets.len();
        let mut sign = 0.0f64;
        let mut bad = None;
        cell.split(|t| {
            let p = t.map(|i| points[i as usize]);
            let v = volume6(p);
            let edge = longest_edge(p);
            if v.abs() <= FLAT * edge * edge * edge || v.is_nan() {
                bad.get_or_insert(MeshError::Degenerate { cell: c });
            } else if sign * v < 0.0 {
                bad.get_or_insert(MeshError::Inverted { cell: c });
            }
            sign = v;
            tets.push(if v < 0.0 { [t[0], t[1], t[3], t[2]] } else { t });
        });
        if let Some(e) = bad {
            return Err(e);
        }
        cell_of.resize(tets.len(), c as u32);
        debug_assert_eq!(tets.len() - start, cell.tet_count());
    }
    Ok((tets, cell_of))
}

fn longest_edge(p: [DVec3; 4]) -> f64 {
    let mut m = 0.0f64;
    for i in 0..4 {
        for j in i + 1..4 {
            m = m.max((p[i] - p[j]).length());
        }
    }
    m
}

type Adjacency = (Vec<[u32; 4]>, Vec<u8>, Vec<u32>);

/// Matches faces by their sorted point triples: each interior face joins
/// two tetrahedra, which must lie on opposite sides of it.
fn adjacency(points: &[DVec3], tets: &[[u32; 4]], cell_of: &[u32]) -> Result<Adjacency, MeshError> {
    let mut neighbors = alloc::vec![[NONE; 4]; tets.len()];
    let mut flips = alloc::vec![0u8; tets.len()];
    // Which side of its canonical plane each tetrahedron's own point lies.
    for (t, tet) in tets.iter().enumerate() {
        for (i, face) in FACE.iter().enumerate() {
            let (nrm, a) = face_normal(points, face.map(|k| tet[k]));
            let side = nrm.dot(points[tet[i] as usize] - a);
            if side == 0.0 {
                return Err(MeshError::Degenerate { cell: cell_of[t] as usize });
            }
            if side > 0.0 {
                flips[t] |= 1 << i;
            }
        }
    }
    let mut faces: Vec<([u32; 3], u32)> = Vec::with_capacity(4 * tets.len());
    for (t, tet) in tets.iter().enumerate() {
        for (i, face) in FACE.iter().enumerate() {
            let mut key = face.map(|k| tet[k]);
            key.sort_unstable();
            faces.push((key, 4 * t as u32 + i as u32));
        }
    }
    faces.sort_unstable();
    let mut boundary = Vec::new();
    let mut k = 0;
    while k < faces.len() {
        let mut e = k + 1;
        while e < faces.len() && faces[e].0 == faces[k].0 {
            e += 1;
        }
        let (a, b) = (faces[k].1, faces.get(k + 1).map_or(0, |f| f.1));
        match e - k {
            1 => boundary.push(a),
            2 => {
                let (ta, fa, tb, fb) = ((a / 4) as usize, a % 4, (b / 4) as usize, b % 4);
                // Opposite sides: exactly one of the two has the flip bit.
                if (flips[ta] >> fa & 1) == (flips[tb] >> fb & 1) {
                    return Err(MeshError::Inverted { cell: cell_of[tb] as usize });
                }
                neighbors[ta][fa as usize] = tb as u32;
                neighbors[tb][fb as usize] = ta as u32;
            }
            _ => return Err(MeshError::NonManifold { cell: cell_of[(a / 4) as usize] as usize }),
        }
        k = e;
    }
    Ok((neighbors, flips, boundary))
}

/// `∇n` of the linear function through the four values.
fn gradient(p: [DVec3; 4], n: [f64; 4]) -> DVec3 {
    let (e1, e2, e3) = (p[1] - p[0], p[2] - p[0], p[3] - p[0]);
    let (d1, d2, d3) = (n[1] - n[0], n[2] - n[0], n[3] - n[0]);
    let v = e1.dot(e2.cross(e3));
    (d1 * e2.cross(e3) + d2 * e3.cross(e1) + d3 * e1.cross(e2)) / v
}

/// The BVH over boundary faces, in `f32` relative to `shift` (the bounds'
/// centre) so the precision is the mesh's own, wherever it sits.
fn boundary_bvh(
    points: &[DVec3],
    tets: &[[u32; 4]],
    boundary: &[u32],
    shift: DVec3,
) -> Result<Bvh<TriPacket>, MeshError> {
    let positions: Vec<Vec3> = points.iter().map(|p| (*p - shift).as_vec3()).collect();
    let tris: Vec<[u32; 3]> = boundary
        .iter()
        .map(|&f| {
            let tet = tets[(f / 4) as usize];
            FACE[(f % 4) as usize].map(|k| tet[k])
        })
        .collect();
    if tris.is_empty() {
        return Ok(Bvh::empty());
    }
    build_triangles(&positions, &tris, &BuildParams::medium()).map_err(|_| MeshError::TooLarge)
}
