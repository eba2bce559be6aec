//! The smooth option: `∇n` recovered at the points and interpolated, for an
//! integrator.
//!
//! The exact tracer ([`UnstructuredField::trace`]) follows the data's
//! piecewise-linear interpolant, whose gradient is constant per cell and
//! only first-order accurate: a single ray's deflection converges at first
//! order in the cell size, and a knife edge shows the cells' facets where
//! they are coarse. [`SmoothField`] instead recovers a gradient at every
//! point by a least-squares quadratic through its neighbours (second-order
//! accurate for smooth data, one-sided ones at the boundary too) and
//! interpolates it linearly inside each tetrahedron, as `n` is: `∇n` is
//! then continuous and second-order accurate, and the deflection of a ray
//! integrated through it ([`SmoothField::trace`], or [`crate::trace`],
//! e.g. with [`SmoothField::params`]) converges at second order. (`∇n` is then not
//! exactly the gradient of the interpolated `n`; the two differ at second
//! order, which the invariant drift `| |T| − n |` reports.) Points are
//! located through a uniform grid of buckets over the mesh.
//!
//! Both live on the mesh's split into tetrahedra (see [`super::Cell`]),
//! which has no preferred direction, and the gradients are fitted at the
//! input points only, through the input points sharing a cell with each
//! (a structured mesh's 3 × 3 × 3 block): a centre point the split adds
//! takes the mean of its corners' gradients, as its value is the mean of
//! theirs (its value is no sample, so fitting through it would spoil the
//! fits' second order).

use alloc::vec::Vec;

use glam::DVec3;

use super::{UnstructuredField, field::NONE};
use crate::{Bounds, IndexField, Method, TraceError, TraceParams, TraceResult};

/// An [`UnstructuredField`] with gradients recovered at its points, an
/// [`IndexField`] for [`crate::trace`]: `n` and `∇n` both interpolated
/// linearly in each tetrahedron. Outside every tetrahedron (beyond the
/// mesh, in holes) `n` is the mesh's ambient index and `∇n = 0`.
#[derive(Clone, Debug)]
pub struct SmoothField {
    mesh: UnstructuredField,
    gradients: Vec<DVec3>,
    /// Boxed: kept small, as `Medium` holds the field inline.
    packed: alloc::boxed::Box<Packed>,
    locator: Locator,
    spacing: f64,
}

/// What locating a point and evaluating there read, packed for the
/// cache: every point's position, index and recovered gradient in one
/// line ([`Node`]), the points numbered in the order the tetrahedra first
/// use them, so the points of neighbouring tetrahedra lie together
/// whatever the input's numbering (a shuffled one made every point a
/// miss: three per tetrahedron walked, eight more per evaluation).
#[derive(Clone, Debug)]
struct Packed {
    nodes: Vec<Node>,
    /// Each tetrahedron's points, in `nodes` (the mesh's numbering of the
    /// tetrahedra).
    tets: Vec<[u32; 4]>,
}

/// A point of [`Packed`]: one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Node {
    p: DVec3,
    n: f64,
    g: DVec3,
}

impl Packed {
    fn new(mesh: &UnstructuredField, gradients: &[DVec3]) -> Self {
        let mut renumbered = alloc::vec![u32::MAX; mesh.points.len()];
        let mut nodes = Vec::with_capacity(mesh.points.len());
        let tets = mesh
            .tets
            .iter()
            .map(|t| {
                t.map(|i| {
                    let i = i as usize;
                    if renumbered[i] == u32::MAX {
                        renumbered[i] = nodes.len() as u32;
                        nodes.push(Node { p: mesh.points[i], n: mesh.index[i], g: gradients[i] });
                    }
                    renumbered[i]
                })
            })
            .collect();
        Self { nodes, tets }
    }

    /// The barycentric coordinates of `x` in `tet`.
    #[inline]
    fn barycentric(&self, tet: usize, x: DVec3) -> [f64; 4] {
        let [p0, p1, p2, p3] = self.tets[tet].map(|i| self.nodes[i as usize].p);
        let (e1, e2, e3, r) = (p1 - p0, p2 - p0, p3 - p0, x - p0);
        let c23 = e2.cross(e3);
        let det = e1.dot(c23);
        let l1 = r.dot(c23) / det;
        let l2 = e1.dot(r.cross(e3)) / det;
        let l3 = e1.dot(e2.cross(r)) / det;
        [1.0 - l1 - l2 - l3, l1, l2, l3]
    }

    /// `(n, ∇n)` from tetrahedron `tet`'s barycentric coordinates `l`.
    #[inline]
    fn values(&self, tet: usize, l: [f64; 4]) -> (f64, DVec3) {
        let mut n = 0.0;
        let mut g = DVec3::ZERO;
        for (k, &i) in self.tets[tet].iter().enumerate() {
            let node = &self.nodes[i as usize];
            n += l[k] * node.n;
            g += l[k] * node.g;
        }
        (n, g)
    }
}

impl SmoothField {
    /// Recovers the gradients of `mesh` and builds its point locator.
    #[must_use]
    pub fn new(mesh: UnstructuredField) -> Self {
        let gradients = recover(&mesh);
        let packed = alloc::boxed::Box::new(Packed::new(&mesh, &gradients));
        let locator = Locator::build(&mesh);
        let spacing = median_edge(&mesh);
        Self { mesh, gradients, packed, locator, spacing }
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &UnstructuredField {
        &self.mesh
    }

    /// The recovered `∇n` at each point (of [`UnstructuredField::points`]:
    /// the input's).
    #[must_use]
    pub fn gradients(&self) -> &[DVec3] {
        &self.gradients[..self.mesh.inputs]
    }

    /// Classic RK4 with steps of half the median edge length of the input
    /// cells (a structured mesh's spacing): second order
    /// in the cell size overall (the field's derivatives jump at faces,
    /// which caps RK4's order there), like the recovered gradients.
    #[must_use]
    pub fn params(&self) -> TraceParams {
        let h = 0.5 * self.spacing;
        TraceParams { max_step: h, ..TraceParams::fixed(Method::Rk4, h) }
    }

    /// The tetrahedron holding `x` and its barycentric coordinates.
    #[must_use]
    pub fn locate(&self, x: DVec3) -> Option<(usize, [f64; 4])> {
        self.locator.locate(&self.mesh, &self.packed, x)
    }

    /// [`crate::trace`] through this field, faster: each evaluation starts
    /// from the tetrahedron of the ray's previous one and walks toward `x`
    /// across the faces it lies beyond (a step or two, where a lookup in
    /// the buckets tests several), falling back to the buckets. The memory
    /// is the ray's own, so the result does not depend on which thread
    /// traces it; it may differ from [`crate::trace`]'s in the last bits
    /// where a point lies on a face (either cell's values, equal to
    /// round-off).
    ///
    /// # Errors
    /// As [`crate::trace`].
    pub fn trace(
        &self,
        origin: DVec3,
        direction: DVec3,
        params: &TraceParams,
    ) -> Result<TraceResult, TraceError> {
        let walker = Walker { field: self, last: core::cell::Cell::new(None) };
        crate::trace(&walker, origin, direction, params)
    }

    /// [`SmoothField::locate`], walking from `start` first.
    fn locate_from(&self, x: DVec3, start: usize) -> Option<(usize, [f64; 4])> {
        let mut tet = start;
        for _ in 0..8 {
            let l = self.packed.barycentric(tet, x);
            let (i, worst) = (0..4)
                .map(|k| (k, l[k]))
                .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
            if worst >= 0.0 {
                return Some((tet, l));
            }
            // Beyond the face opposite point `i`: into the cell there.
            match self.mesh.neighbors[tet][i] {
                NONE => break,
                next => tet = next as usize,
            }
        }
        self.locate(x)
    }
}

/// A [`SmoothField`] remembering the tetrahedron of its last evaluation
/// (one ray's).
struct Walker<'a> {
    field: &'a SmoothField,
    last: core::cell::Cell<Option<usize>>,
}

impl IndexField for Walker<'_> {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let found = match self.last.get() {
            Some(t) => self.field.locate_from(x, t),
            None => self.field.locate(x),
        };
        let Some((tet, l)) = found else {
            return (self.field.mesh.ambient, DVec3::ZERO);
        };
        self.last.set(Some(tet));
        self.field.packed.values(tet, l)
    }
    fn bounds(&self) -> Bounds {
        self.field.mesh.bounds
    }
    fn ambient(&self) -> f64 {
        self.field.mesh.ambient
    }
}

impl IndexField for SmoothField {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let Some((tet, l)) = self.locate(x) else {
            return (self.mesh.ambient, DVec3::ZERO);
        };
        self.packed.values(tet, l)
    }
    fn bounds(&self) -> Bounds {
        self.mesh.bounds
    }
    fn ambient(&self) -> f64 {
        self.mesh.ambient
    }
}

/// Tetrahedra by the buckets of a uniform grid their boxes overlap.
#[derive(Clone, Debug)]
struct Locator {
    lo: DVec3,
    scale: DVec3,
    dims: [usize; 3],
    /// Bucket `b`'s tetrahedra: `items[start[b]..start[b + 1]]`.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Locator {
    fn build(mesh: &UnstructuredField) -> Self {
        let b = mesh.bounds;
        let ext = (b.max - b.min).max(DVec3::splat(f64::MIN_POSITIVE));
        // About two tetrahedra per bucket, buckets near cubes.
        let target = (mesh.tets.len() as f64 / 2.0).max(1.0);
        let side = (ext.x * ext.y * ext.z / target).cbrt().max(ext.max_element() / 1024.0);
        let dims = [0, 1, 2].map(|a| ((ext[a] / side).ceil() as usize).clamp(1, 1024));
        let scale = DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) / ext;
        let mut loc = Self { lo: b.min, scale, dims, start: Vec::new(), items: Vec::new() };
        let ranges: Vec<[[usize; 3]; 2]> = (0..mesh.tets.len())
            .map(|t| {
                let p = mesh.tets[t].map(|i| mesh.points[i as usize]);
                let lo = p[0].min(p[1]).min(p[2]).min(p[3]);
                let hi = p[0].max(p[1]).max(p[2]).max(p[3]);
                [loc.cell(lo), loc.cell(hi)]
            })
            .collect();
        let total = dims[0] * dims[1] * dims[2];
        let mut count = alloc::vec![0u32; total + 1];
        let each = |r: &[[usize; 3]; 2], f: &mut dyn FnMut(usize)| {
            for k in r[0][2]..=r[1][2] {
                for j in r[0][1]..=r[1][1] {
                    for i in r[0][0]..=r[1][0] {
                        f(i + dims[0] * (j + dims[1] * k));
                    }
                }
            }
        };
        for r in &ranges {
            each(r, &mut |c| count[c + 1] += 1);
        }
        for c in 0..total {
            count[c + 1] += count[c];
        }
        let mut fill = count.clone();
        let mut items = alloc::vec![0u32; count[total] as usize];
        for (t, r) in ranges.iter().enumerate() {
            each(r, &mut |c| {
                items[fill[c] as usize] = t as u32;
                fill[c] += 1;
            });
        }
        loc.start = count;
        loc.items = items;
        loc
    }

    /// The bucket holding `x`, clamped into the grid.
    fn cell(&self, x: DVec3) -> [usize; 3] {
        let u = (x - self.lo) * self.scale;
        [0, 1, 2].map(|a| {
            let v = u[a].floor();
            if v > 0.0 { (v as usize).min(self.dims[a] - 1) } else { 0 }
        })
    }

    fn locate(
        &self,
        mesh: &UnstructuredField,
        packed: &Packed,
        x: DVec3,
    ) -> Option<(usize, [f64; 4])> {
        if !mesh.bounds.contains(x) {
            return None;
        }
        let [i, j, k] = self.cell(x);
        let c = i + self.dims[0] * (j + self.dims[1] * k);
        let mut best: Option<(f64, usize, [f64; 4])> = None;
        for &t in &self.items[self.start[c] as usize..self.start[c + 1] as usize] {
            let l = packed.barycentric(t as usize, x);
            let worst = l[0].min(l[1]).min(l[2]).min(l[3]);
            if worst >= 0.0 {
                return Some((t as usize, l));
            }
            if best.is_none_or(|(w, _, _)| worst > w) {
                best = Some((worst, t as usize, l));
            }
        }
        // On a face to round-off: the nearest candidate.
        best.filter(|&(w, _, _)| w > -1e-9).map(|(_, t, l)| (t, l))
    }
}

/// The median edge length of the input cells: per tetrahedron, its first
/// edge between two input points (every tetrahedron of the split has one:
/// of a hexahedron or wedge, the cell's edge it is built on).
fn median_edge(mesh: &UnstructuredField) -> f64 {
    let inputs = mesh.inputs as u32;
    let mut e: Vec<f64> = mesh
        .tets
        .iter()
        .filter_map(|t| {
            let mut own = t.iter().filter(|&&p| p < inputs);
            let (a, b) = (*own.next()?, *own.next()?);
            Some((mesh.points[a as usize] - mesh.points[b as usize]).length())
        })
        .collect();
    if e.is_empty() {
        return 0.0;
    }
    let mid = e.len() / 2;
    e.select_nth_unstable_by(mid, f64::total_cmp);
    e[mid]
}

/// Each input point's neighbours: the input points sharing a cell with it
/// (sorted, without itself). A cell's tetrahedra are consecutive, and
/// together hold all its points.
fn neighbours(mesh: &UnstructuredField) -> (Vec<u32>, Vec<u32>) {
    let n = mesh.inputs;
    let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(12 * mesh.tets.len());
    let mut corners: Vec<u32> = Vec::with_capacity(32);
    let mut t = 0;
    while t < mesh.tets.len() {
        let cell = mesh.cell_of[t];
        corners.clear();
        while t < mesh.tets.len() && mesh.cell_of[t] == cell {
            corners.extend(mesh.tets[t].iter().filter(|&&p| (p as usize) < n));
            t += 1;
        }
        corners.sort_unstable();
        corners.dedup();
        for &a in &corners {
            for &b in &corners {
                if a != b {
                    pairs.push((a, b));
                }
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let mut start = alloc::vec![0u32; n + 1];
    for &(a, _) in &pairs {
        start[a as usize + 1] += 1;
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    (start, pairs.into_iter().map(|(_, b)| b).collect())
}

/// Gradients at the input points: a least-squares quadratic through the
/// 1-ring (2-ring where the 1-ring is too small or flat), its gradient at
/// the point; a linear fit, then the mean of the cells' gradients, where
/// even that is singular. Then the added points': their corners' mean.
fn recover(mesh: &UnstructuredField) -> Vec<DVec3> {
    let (start, adj) = neighbours(mesh);
    let ring = |p: usize| &adj[start[p] as usize..start[p + 1] as usize];
    let mut cell_mean = alloc::vec![(DVec3::ZERO, 0u32); mesh.inputs];
    for (t, tet) in mesh.tets.iter().enumerate() {
        for &p in tet.iter().filter(|&&p| (p as usize) < mesh.inputs) {
            cell_mean[p as usize].0 += mesh.gradients[t];
            cell_mean[p as usize].1 += 1;
        }
    }
    let mut two = Vec::new();
    let mut gradients: Vec<DVec3> = (0..mesh.inputs)
        .map(|p| {
            let one = ring(p);
            if let Some(g) = fit(mesh, p, one, true) {
                return g;
            }
            two.clear();
            for &q in one {
                two.extend_from_slice(ring(q as usize));
            }
            two.sort_unstable();
            two.dedup();
            two.retain(|&q| q as usize != p);
            fit(mesh, p, &two, true).or_else(|| fit(mesh, p, one, false)).unwrap_or_else(|| {
                let (s, c) = cell_mean[p];
                if c > 0 { s / f64::from(c) } else { DVec3::ZERO }
            })
        })
        .collect();
    gradients.reserve(mesh.points.len() - mesh.inputs);
    for i in 0..mesh.points.len() - mesh.inputs {
        let corners = mesh.centres.of(i);
        let sum = corners.iter().map(|&p| gradients[p as usize]).sum::<DVec3>();
        gradients.push(sum / corners.len() as f64);
    }
    gradients
}

/// The gradient at point `p` of a least-squares fit through `others`:
/// quadratic (9 unknowns, at least 12 points) or linear.
fn fit(mesh: &UnstructuredField, p: usize, others: &[u32], quadratic: bool) -> Option<DVec3> {
    let need = if quadratic { 12 } else { 3 };
    if others.len() < need {
        return None;
    }
    let x0 = mesh.points[p];
    let n0 = mesh.index[p];
    let h = others.iter().map(|&q| (mesh.points[q as usize] - x0).length()).fold(0.0, f64::max);
    if h <= 0.0 || h.is_nan() {
        return None;
    }
    let mut a = [[0.0f64; 9]; 9];
    let mut rhs = [0.0f64; 9];
    let m = if quadratic { 9 } else { 3 };
    for &q in others {
        let d = (mesh.points[q as usize] - x0) / h;
        let row = [d.x, d.y, d.z, d.x * d.x, d.y * d.y, d.z * d.z, d.x * d.y, d.x * d.z, d.y * d.z];
        let v = mesh.index[q as usize] - n0;
        for r in 0..m {
            rhs[r] += row[r] * v;
            for c in 0..m {
                a[r][c] += row[r] * row[c];
            }
        }
    }
    let s = solve(&mut a, &mut rhs, m)?;
    Some(DVec3::new(s[0], s[1], s[2]) / h)
}

/// Solves the symmetric system `a[..m][..m]·x = b` by Gaussian elimination
/// with partial pivoting; `None` if a pivot falls below 1e-10 of the
/// largest diagonal (a ring too flat to fit).
fn solve(a: &mut [[f64; 9]; 9], b: &mut [f64; 9], m: usize) -> Option<[f64; 9]> {
    let scale = (0..m).map(|i| a[i][i]).fold(0.0, f64::max);
    if scale <= 0.0 || scale.is_nan() {
        return None;
    }
    for col in 0..m {
        let piv = (col..m).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[piv][col].abs() <= 1e-10 * scale || a[piv][col].is_nan() {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        let pivot = a[col];
        for r in col + 1..m {
            let f = a[r][col] / pivot[col];
            for (x, p) in a[r][col..m].iter_mut().zip(&pivot[col..m]) {
                *x -= f * p;
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0f64; 9];
    for r in (0..m).rev() {
        let mut s = b[r];
        for c in r + 1..m {
            s -= a[r][c] * x[c];
        }
        x[r] = s / a[r][r];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}
