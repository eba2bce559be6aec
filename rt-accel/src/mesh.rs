//! Triangle meshes with optional per-vertex scalars.

use alloc::vec::Vec;

use glam::Vec3;
use rt_core::{Hit, PrimKind};

use crate::BuildError;

/// An indexed triangle mesh, validated on construction.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriangleMesh {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    scalars: Option<Vec<f32>>,
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
        Ok(Self { positions, indices, scalars })
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
