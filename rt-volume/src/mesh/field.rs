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
/// tetrahedra are split, with points added at the centres of
/// quadrilateral faces and of hexahedra and wedges (see [`Cell`]); rays
/// are traced through it cell by cell in closed form
/// ([`UnstructuredField::trace`]).
///
/// Outside the mesh (beyond its boundary faces, including holes and the
/// gaps of a non-convex mesh) the index is [`UnstructuredField::ambient`].
#[derive(Clone, Debug)]
pub struct UnstructuredField {
    /// The input points, then the centre points the split adds.
    pub(crate) points: Vec<DVec3>,
    /// `n` at each point.
    pub(crate) index: Vec<f64>,
    /// How many of `points` are the input's.
    pub(crate) inputs: usize,
    /// The corners each added point is the centre of.
    pub(crate) centres: Centres,
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

/// The corners of the points the split adds, point `inputs + i` the mean
/// of `corners[start[i]..start[i + 1]]` (a quadrilateral's 4, a wedge's 6,
/// a hexahedron's 8), each list sorted.
#[derive(Clone, Debug, Default)]
pub(crate) struct Centres {
    pub(crate) start: Vec<u32>,
    pub(crate) corners: Vec<u32>,
}

impl Centres {
    /// The corners of added point `i` (counted from the first added).
    pub(crate) fn of(&self, i: usize) -> &[u32] {
        &self.corners[self.start[i] as usize..self.start[i + 1] as usize]
    }
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
    /// must not fold (all its tetrahedra the same orientation). The split
    /// adds points (see [`Cell`]), with the means of their corners' values;
    /// [`UnstructuredField::points`] and [`UnstructuredField::index`] stay
    /// the input's.
    ///
    /// # Errors
    /// [`MeshError`] naming the first offending point or cell: no cells,
    /// NaN/∞ points, values that are not finite and positive (or `ambient`
    /// not so: `BadValue` with point `usize::MAX`), indices out of range,
    /// a point used twice by a cell, zero-volume, folded or overlapping
    /// cells, a face shared by more than two cells, sizes past `u32`.
    pub fn new(
        mut points: Vec<DVec3>,
        cells: &[Cell],
        mut index: Vec<f64>,
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
        let inputs = points.len();
        let range =
            index.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &n| (lo.min(n), hi.max(n)));
        let (tets, cell_of, centres) = split_cells(&mut points, &mut index, cells)?;
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
            inputs,
            centres,
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

    /// The points, as given.
    #[must_use]
    pub fn points(&self) -> &[DVec3] {
        &self.points[..self.inputs]
    }

    /// `n` at each point, as given.
    #[must_use]
    pub fn index(&self) -> &[f64] {
        &self.index[..self.inputs]
    }

    /// The points the tetrahedra are made of: the input points
    /// ([`UnstructuredField::points`]), then the centre points the split
    /// adds (see [`Cell`]).
    #[must_use]
    pub fn split_points(&self) -> &[DVec3] {
        &self.points
    }

    /// The tetrahedra, as indices into [`UnstructuredField::split_points`]
    /// (positive orientation).
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

/// The split's tetrahedra and the cell each comes from, and its points.
type Split = (Vec<[u32; 4]>, Vec<u32>, Centres);

/// Splits every cell, checks it, and orients its tetrahedra positively;
/// the points it adds (and their values) are appended to `points` and
/// `index`.
fn split_cells(
    points: &mut Vec<DVec3>,
    index: &mut Vec<f64>,
    cells: &[Cell],
) -> Result<Split, MeshError> {
    // The cells before the first with a bad point index are split (their
    // errors come first); that cell's error comes after.
    let mut bad_index = None;
    for (c, cell) in cells.iter().enumerate() {
        let ids = cell.points();
        if let Some(&index) = ids.iter().find(|&&i| i as usize >= points.len()) {
            bad_index = Some((c, MeshError::IndexOutOfRange { cell: c, index }));
            break;
        }
        if ids.iter().enumerate().any(|(k, i)| ids[..k].contains(i)) {
            bad_index = Some((c, MeshError::RepeatedPoint { cell: c }));
            break;
        }
    }
    let cells = &cells[..bad_index.map_or(cells.len(), |(c, _)| c)];
    let total: usize = cells.iter().map(Cell::tet_count).sum();
    if total >= NONE as usize {
        return Err(MeshError::TooLarge);
    }
    // One centre per quadrilateral face, found by its sorted points: the
    // two cells across a face share it.
    let mut quads: Vec<([u32; 4], u32)> = cells
        .iter()
        .flat_map(Cell::quads)
        .enumerate()
        .map(|(k, mut q)| {
            q.sort_unstable();
            (q, k as u32)
        })
        .collect();
    quads.sort_unstable();
    let faces = quads.chunk_by(|a, b| a.0 == b.0).count();
    let middles = cells.iter().filter(|c| c.has_centre()).count();
    if points.len() + faces + middles >= NONE as usize {
        return Err(MeshError::TooLarge);
    }
    points.reserve(faces + middles);
    index.reserve(faces + middles);
    let mut centres = Centres {
        start: Vec::with_capacity(faces + middles + 1),
        corners: Vec::with_capacity(4 * faces + 8 * middles),
    };
    centres.start.push(0);
    let mut quad_centre = alloc::vec![0u32; quads.len()];
    for group in quads.chunk_by(|a, b| a.0 == b.0) {
        let id = add_centre(points, index, &mut centres, &group[0].0);
        for &(_, k) in group {
            quad_centre[k as usize] = id;
        }
    }
    let mut tets = Vec::with_capacity(total);
    let mut cell_of = Vec::with_capacity(total);
    let mut first_quad = 0;
    for (c, cell) in cells.iter().enumerate() {
        let centre = if cell.has_centre() {
            let mut ids = [0u32; 8];
            let ids = &mut ids[..cell.points().len()];
            ids.copy_from_slice(cell.points());
            ids.sort_unstable();
            add_centre(points, index, &mut centres, ids)
        } else {
            NONE
        };
        let quads = &quad_centre[first_quad..];
        first_quad += cell.quads().count();
        let start = tets.len();
        let mut sign = 0.0f64;
        let mut bad = None;
        cell.split(
            centre,
            |k| quads[k],
            |t| {
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
            },
        );
        if let Some(e) = bad {
            return Err(e);
        }
        cell_of.resize(tets.len(), c as u32);
        debug_assert_eq!(tets.len() - start, cell.tet_count());
    }
    if let Some((_, e)) = bad_index {
        return Err(e);
    }
    Ok((tets, cell_of, centres))
}

/// Appends the mean of the points `ids` (sorted: the sums do not depend
/// on the order a cell lists them in) and of their values; its index.
/// Each term is divided before it is added, so finite points and values
/// have a finite mean however large.
fn add_centre(
    points: &mut Vec<DVec3>,
    index: &mut Vec<f64>,
    centres: &mut Centres,
    ids: &[u32],
) -> u32 {
    let count = ids.len() as f64;
    let (mut p, mut n) = (DVec3::ZERO, 0.0);
    for &i in ids {
        p += points[i as usize] / count;
        n += index[i as usize] / count;
    }
    points.push(p);
    index.push(n);
    centres.corners.extend_from_slice(ids);
    centres.start.push(centres.corners.len() as u32);
    (points.len() - 1) as u32
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
