//! Indexed triangle meshes: plain, validated geometry for building and
//! refitting triangle BVHs.

use alloc::{collections::BTreeMap, vec::Vec};

use glam::Vec3;

use crate::BuildError;

/// An indexed triangle mesh, validated on construction.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
}

impl TriangleMesh {
    /// A mesh from vertex positions and triangles (counter-clockwise front
    /// faces).
    ///
    /// # Errors
    /// [`BuildError::NonFiniteVertex`] for the first NaN/∞ vertex, or
    /// [`BuildError::IndexOutOfRange`] for the first triangle naming a
    /// vertex that does not exist.
    pub fn new(positions: Vec<Vec3>, indices: Vec<[u32; 3]>) -> Result<Self, BuildError> {
        if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
            return Err(BuildError::NonFiniteVertex { vertex });
        }
        for (triangle, t) in indices.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(BuildError::IndexOutOfRange { triangle, index });
            }
        }
        Ok(Self { positions, indices })
    }

    /// The unit sphere as an icosahedron subdivided `level` times
    /// (`20 · 4^level` triangles, shared vertices, counter-clockwise seen
    /// from outside): a closed mesh for glyphs and tests.
    ///
    /// # Panics
    /// If `level > 10` (over 20M triangles; a programming error).
    #[must_use]
    pub fn icosphere(level: u32) -> Self {
        assert!(level <= 10, "icosphere level {level} is too fine");
        // The golden ratio (1 + √5) / 2, rounded to f32 as the computed
        // value is (no float functions needed without std).
        let t = 1.618_034_f32;
        let base = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ];
        let mut positions: Vec<Vec3> =
            base.iter().map(|&(x, y, z)| Vec3::new(x, y, z).normalize()).collect();
        let mut indices: Vec<[u32; 3]> = alloc::vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..level {
            // Each edge's midpoint is made once and shared by both triangles.
            let mut mid = BTreeMap::new();
            let mut midpoint = |a: u32, b: u32, pos: &mut Vec<Vec3>| {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    pos.push(((pos[a as usize] + pos[b as usize]) * 0.5).normalize());
                    pos.len() as u32 - 1
                })
            };
            let mut next = Vec::with_capacity(indices.len() * 4);
            for [a, b, c] in indices {
                let ab = midpoint(a, b, &mut positions);
                let bc = midpoint(b, c, &mut positions);
                let ca = midpoint(c, a, &mut positions);
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            indices = next;
        }
        Self { positions, indices }
    }

    /// Vertex positions.
    #[must_use]
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Triangles as vertex index triples.
    #[must_use]
    pub fn indices(&self) -> &[[u32; 3]] {
        &self.indices
    }

    /// Replaces the positions (same count) for animation; follow with
    /// [`crate::Bvh::refit_triangles`].
    ///
    /// # Errors
    /// [`BuildError::RefitMismatch`] for a different vertex count,
    /// [`BuildError::NonFiniteVertex`]; the mesh is unchanged on error.
    pub fn set_positions(&mut self, positions: &[Vec3]) -> Result<(), BuildError> {
        if positions.len() != self.positions.len() {
            return Err(BuildError::RefitMismatch);
        }
        if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
            return Err(BuildError::NonFiniteVertex { vertex });
        }
        self.positions.copy_from_slice(positions);
        Ok(())
    }
}
