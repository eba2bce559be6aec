//! Cells of an unstructured mesh and their split into tetrahedra.
//!
//! The split adds points: a centre on every quadrilateral face, shared by
//! the two cells across it (found by the face's sorted point numbers), and
//! a centre in every hexahedron and wedge. Each cell is then the cone from
//! its centre over its faces, every quadrilateral cut into the four
//! triangles from its centre to its edges: a hexahedron gives 24
//! tetrahedra (4 per face), a wedge 14 (3 quadrilaterals, 2 triangles), a
//! pyramid 4 (its base's triangles joined to the apex; the triangular faces
//! need no centre), a tetrahedron itself. A centre's position and value are
//! the means of its corners' (the bilinear and trilinear interpolants'
//! values there on a parallelogram face and a parallelepiped cell): the
//! face- and body-centred subdivision, which Carr, Möller and Snoeyink
//! ("Simplicial subdivisions and sampling artifacts", IEEE Visualization
//! 2001) compare with the 5- and 6-tetrahedra splits.
//!
//! Nothing in the split depends on how the points are numbered, so the
//! piecewise-linear interpolant on it has no preferred direction: a cell's
//! tetrahedra follow its own symmetries (a cube's all 48). (Cutting each
//! quadrilateral along the diagonal through its lowest-numbered point, as
//! the 6-tetrahedra split this one replaced did, gives the interpolant a
//! direction that moves with the numbering: a spherical blast on a
//! structured mesh came out lopsided in a knife-edge image.) Neighbours
//! still meet face to face: two cells sharing a quadrilateral share its
//! centre and so its four triangles, and triangles are not cut. Means are
//! exact for linear data, so a field linear in space stays exactly linear.
//!
//! What each way of tracing a mesh follows: the exact tracer
//! ([`super::UnstructuredField::trace`]) the piecewise-linear interpolant
//! on these tetrahedra; the smooth field ([`super::SmoothField`]) `n` and
//! the gradients it recovers at the input points interpolated linearly on
//! the same tetrahedra, a centre's gradient the mean of its corners'.

/// A cell by the indices of its points, in VTK's order (the same order
/// VTK's `VTK_TETRA`, `VTK_PYRAMID`, `VTK_WEDGE` and `VTK_HEXAHEDRON` use).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Cell {
    /// Four points.
    Tetra([u32; 4]),
    /// A quadrilateral base `0 1 2 3` and the apex `4`.
    Pyramid([u32; 5]),
    /// Triangles `0 1 2` and `3 4 5`, with edges `0–3`, `1–4`, `2–5`.
    Wedge([u32; 6]),
    /// Quadrilaterals `0 1 2 3` and `4 5 6 7`, with edges `0–4`, `1–5`,
    /// `2–6`, `3–7`.
    Hexahedron([u32; 8]),
}

/// Faces of each kind as local point indices (triangles have a repeated
/// last index `u8::MAX`).
const TETRA_FACES: [[u8; 4]; 4] = [[1, 2, 3, X], [0, 3, 2, X], [0, 1, 3, X], [0, 2, 1, X]];
const PYRAMID_FACES: [[u8; 4]; 5] =
    [[0, 3, 2, 1], [0, 1, 4, X], [1, 2, 4, X], [2, 3, 4, X], [3, 0, 4, X]];
const WEDGE_FACES: [[u8; 4]; 5] =
    [[0, 2, 1, X], [3, 4, 5, X], [0, 1, 4, 3], [1, 2, 5, 4], [2, 0, 3, 5]];
const HEX_FACES: [[u8; 4]; 6] =
    [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
const X: u8 = u8::MAX;

impl Cell {
    /// The cell's point indices.
    #[must_use]
    pub fn points(&self) -> &[u32] {
        match self {
            Self::Tetra(p) => p,
            Self::Pyramid(p) => p,
            Self::Wedge(p) => p,
            Self::Hexahedron(p) => p,
        }
    }

    /// The hexahedra of a structured lattice of `dims` points a side,
    /// numbered x fastest (`i + nx·(j + ny·k)`, as grids store their
    /// samples): a structured grid's points made into an unstructured mesh.
    /// Empty if any side has fewer than two points.
    #[must_use]
    pub fn lattice_hexahedra(dims: [usize; 3]) -> alloc::vec::Vec<Self> {
        let [nx, ny, nz] = dims;
        let id = |i: usize, j: usize, k: usize| (i + nx * (j + ny * k)) as u32;
        let mut cells = alloc::vec::Vec::new();
        for k in 0..nz.saturating_sub(1) {
            for j in 0..ny.saturating_sub(1) {
                for i in 0..nx.saturating_sub(1) {
                    cells.push(Self::Hexahedron([
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1),
                    ]));
                }
            }
        }
        cells
    }

    /// VTK's cell type number (10, 14, 13, 12).
    #[must_use]
    pub fn vtk_type(&self) -> u8 {
        match self {
            Self::Tetra(_) => 10,
            Self::Pyramid(_) => 14,
            Self::Wedge(_) => 13,
            Self::Hexahedron(_) => 12,
        }
    }

    /// How many tetrahedra the split gives: 1, 4, 14 and 24 (see the
    /// module docs of `mesh::cell`, or `docs/physics.md` §6).
    #[must_use]
    pub fn tet_count(&self) -> usize {
        match self {
            Self::Tetra(_) => 1,
            Self::Pyramid(_) => 4,
            Self::Wedge(_) => 14,
            Self::Hexahedron(_) => 24,
        }
    }

    /// Whether the split adds a point at the cell's centre (hexahedra and
    /// wedges).
    pub(crate) fn has_centre(&self) -> bool {
        matches!(self, Self::Wedge(_) | Self::Hexahedron(_))
    }

    /// The cell's quadrilateral faces, as point indices in order around
    /// each (the order [`Cell::split`] numbers them in).
    pub(crate) fn quads(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        let p = self.points();
        self.faces().iter().filter(|f| f[3] != X).map(move |f| f.map(|k| p[usize::from(k)]))
    }

    fn faces(&self) -> &'static [[u8; 4]] {
        match self {
            Self::Tetra(_) => &TETRA_FACES,
            Self::Pyramid(_) => &PYRAMID_FACES,
            Self::Wedge(_) => &WEDGE_FACES,
            Self::Hexahedron(_) => &HEX_FACES,
        }
    }

    /// Calls `emit` with the point indices of each tetrahedron of the split
    /// (orientation not fixed: the caller orders them by volume). `centre`
    /// is the point at the cell's centre (used by hexahedra and wedges),
    /// `quad_centre(k)` the one at the centre of its `k`-th quadrilateral
    /// face (in [`Cell::quads`]'s order).
    pub(crate) fn split(
        &self,
        centre: u32,
        quad_centre: impl Fn(usize) -> u32,
        mut emit: impl FnMut([u32; 4]),
    ) {
        let p = self.points();
        match self {
            Self::Tetra(t) => emit(*t),
            Self::Pyramid(q) => {
                // The base's four triangles, each joined to the apex.
                let f = quad_centre(0);
                let base = PYRAMID_FACES[0].map(|k| p[usize::from(k)]);
                for e in 0..4 {
                    emit([f, base[e], base[(e + 1) % 4], q[4]]);
                }
            }
            Self::Wedge(_) | Self::Hexahedron(_) => {
                let mut k = 0;
                for face in self.faces() {
                    if face[3] == X {
                        emit([
                            centre,
                            p[usize::from(face[0])],
                            p[usize::from(face[1])],
                            p[usize::from(face[2])],
                        ]);
                        continue;
                    }
                    let ids = face.map(|i| p[usize::from(i)]);
                    let f = quad_centre(k);
                    k += 1;
                    for e in 0..4 {
                        emit([centre, f, ids[e], ids[(e + 1) % 4]]);
                    }
                }
            }
        }
    }
}
