//! Triangle meshes with optional per-vertex scalars.

use alloc::{collections::BTreeMap, vec::Vec};

use glam::Vec3;
use rt_core::{Hit, PrimKind};

use crate::BuildError;

/// An indexed triangle mesh, validated on construction.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    scalars: Option<Vec<f32>>,
    normals: Option<Vec<Vec3>>,
}

impl TriangleMesh {
    /// A mesh from vertex positions, triangles (counter-clockwise front
    /// faces) and optional per-vertex scalars.
    ///
    /// # Errors
    /// [`BuildError::NonFiniteVertex`] for the first NaN/∞ vertex,
    /// [`BuildError::IndexOutOfRange`], or
    /// [`BuildError::ScalarCountMismatch`]. Scalars may be NaN (they map to
    /// the colour map's NaN colour).
    pub fn new(
        positions: Vec<Vec3>,
        indices: Vec<[u32; 3]>,
        scalars: Option<Vec<f32>>,
    ) -> Result<Self, BuildError> {
        if let Some(vertex) = positions.iter().position(|p| !p.is_finite()) {
            return Err(BuildError::NonFiniteVertex { vertex });
        }
        for (triangle, t) in indices.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= positions.len()) {
                return Err(BuildError::IndexOutOfRange { triangle, index });
            }
        }
        if let Some(s) = &scalars
            && s.len() != positions.len()
        {
            return Err(BuildError::ScalarCountMismatch {
                vertices: positions.len(),
                scalars: s.len(),
            });
        }
        Ok(Self { positions, indices, scalars, normals: None })
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
        let t = (1.0 + 5.0f32.sqrt()) / 2.0;
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
        Self { positions, indices, scalars: None, normals: None }
    }

    /// The mesh with per-vertex shading normals (any non-zero length).
    ///
    /// # Errors
    /// [`BuildError::NormalCountMismatch`] unless there is one per vertex,
    /// [`BuildError::BadNormal`] for the first NaN/∞ or zero normal.
    pub fn with_normals(mut self, normals: Vec<Vec3>) -> Result<Self, BuildError> {
        if normals.len() != self.positions.len() {
            return Err(BuildError::NormalCountMismatch {
                vertices: self.positions.len(),
                normals: normals.len(),
            });
        }
        if let Some(vertex) = normals.iter().position(|n| !n.is_finite() || *n == Vec3::ZERO) {
            return Err(BuildError::BadNormal { vertex });
        }
        self.normals = Some(normals);
        Ok(self)
    }

    /// Per-vertex normals, if any.
    #[must_use]
    pub fn normals(&self) -> Option<&[Vec3]> {
        self.normals.as_deref()
    }

    /// The shading normal at a triangle hit: the vertex normals
    /// interpolated with the hit's barycentrics and normalised, or the
    /// geometric normal without normals (or where they cancel).
    #[must_use]
    pub fn shading_normal(&self, hit: &Hit) -> Vec3 {
        let interpolated = self.normals.as_ref().and_then(|n| {
            let [i0, i1, i2] = *self.indices.get(hit.prim as usize)?;
            let (b1, b2) = (hit.uv.x, hit.uv.y);
            let v = (1.0 - b1 - b2) * n[i0 as usize] + b1 * n[i1 as usize] + b2 * n[i2 as usize];
            v.try_normalize()
        });
        interpolated.unwrap_or(hit.normal)
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

    /// Per-vertex scalars, if any.
    #[must_use]
    pub fn scalars(&self) -> Option<&[f32]> {
        self.scalars.as_deref()
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

    /// The scalar at a triangle hit, interpolated with the hit's
    /// barycentrics (interpolate the scalar, then colour-map it). `None`
    /// without scalars or for a hit on another kind or triangle index.
    #[must_use]
    pub fn interpolate_scalar(&self, hit: &Hit) -> Option<f32> {
        if hit.kind != PrimKind::Triangle {
            return None;
        }
        let s = self.scalars.as_ref()?;
        let [i0, i1, i2] = *self.indices.get(hit.prim as usize)?;
        let (b1, b2) = (hit.uv.x, hit.uv.y);
        let b0 = 1.0 - b1 - b2;
        Some(b0 * s[i0 as usize] + b1 * s[i1 as usize] + b2 * s[i2 as usize])
    }
}
