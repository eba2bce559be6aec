//! Cells of an unstructured mesh and their split into tetrahedra.
//!
//! Every cell is split by *pulling* its lowest-numbered point `v`: each face
//! not containing `v` is cut into triangles, a quadrilateral along the
//! diagonal through its own lowest-numbered point, and each triangle is
//! joined to `v`. For a convex cell this is a triangulation of the cell
//! (the cone of a convex polytope from one of its vertices), and a face's
//! cut depends only on the face's own point numbers, so two cells sharing a
//! quadrilateral cut it along the same diagonal: the tetrahedra of
//! neighbours meet face to face, without gaps. No point is added, so a
//! field linear in space stays exactly linear. Counts: a tetrahedron 1, a
//! pyramid 2, a wedge 3, a hexahedron 6.
//!
//! A rule that cuts every quadrilateral along the diagonal through its
//! lowest point is the one of Dompierre, Labbé, Vallet and Camarero
//! ("How to subdivide pyramids, prisms and hexahedra into tetrahedra",
//! 8th International Meshing Roundtable, 1999); pulling the cell's lowest
//! point is what makes every hexahedron splittable with it and no Steiner
//! point.

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

    /// How many tetrahedra the split gives.
    #[must_use]
    pub fn tet_count(&self) -> usize {
        match self {
            Self::Tetra(_) => 1,
            Self::Pyramid(_) => 2,
            Self::Wedge(_) => 3,
            Self::Hexahedron(_) => 6,
        }
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
    /// (orientation not fixed: the caller orders them by volume).
    pub(crate) fn split(&self, mut emit: impl FnMut([u32; 4])) {
        let p = self.points();
        if let Self::Tetra(t) = self {
            emit(*t);
            return;
        }
        // The pulled point: the lowest global index.
        let v = *p.iter().min().expect("cells have points");
        for face in self.faces() {
            let ids: [u32; 4] = [
                p[usize::from(face[0])],
                p[usize::from(face[1])],
                p[usize::from(face[2])],
                if face[3] == X { u32::MAX } else { p[usize::from(face[3])] },
            ];
            let quad = face[3] != X;
            let len = if quad { 4 } else { 3 };
            if ids[..len].contains(&v) {
                continue;
            }
            if quad {
                // Cut along the diagonal through the face's lowest point.
                let k = (0..4).min_by_key(|&i| ids[i]).expect("four points");
                let a = ids[k];
                let (b, c, d) = (ids[(k + 1) % 4], ids[(k + 2) % 4], ids[(k + 3) % 4]);
                emit([v, a, b, c]);
                emit([v, a, c, d]);
            } else {
                emit([v, ids[0], ids[1], ids[2]]);
            }
        }
    }
}
