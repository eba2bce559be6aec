//! What every reader returns: geometry and every scalar, before a scalar
//! is chosen.

use alloc::{
    string::{String, ToString},
    vec::Vec,
};

use glam::Vec3;
use rt_accel::BuildError;

use super::{ReadError, ReadErrorKind};
use crate::Mesh;

/// A mesh as read from a file, before a scalar is chosen.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions (not yet checked for NaN; [`Self::into_mesh`] does).
    pub positions: Vec<Vec3>,
    /// Triangles (not yet checked against the vertex count).
    pub indices: Vec<[u32; 3]>,
    /// One normal per vertex, when the file has them for every vertex.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex scalars by name, one value per vertex each, in file order.
    pub scalars: Vec<(String, Vec<f32>)>,
}

impl MeshData {
    /// The names of the scalars, in file order.
    pub fn scalar_names(&self) -> impl Iterator<Item = &str> {
        self.scalars.iter().map(|(n, _)| n.as_str())
    }

    /// The triangle mesh, coloured by the scalar `scalar` if given.
    ///
    /// # Errors
    /// [`ReadErrorKind::NoSuchScalar`], or [`ReadErrorKind::Mesh`] for a NaN/∞
    /// vertex, an index out of range or a zero/NaN normal (each naming the
    /// vertex or triangle).
    pub fn into_mesh(self, scalar: Option<&str>) -> Result<Mesh, ReadError> {
        let chosen = match scalar {
            None => None,
            Some(name) => {
                let available: Vec<String> = self.scalar_names().map(ToString::to_string).collect();
                let found = self.scalars.into_iter().find(|(n, _)| n == name);
                Some(
                    found
                        .ok_or(ReadError::from(ReadErrorKind::NoSuchScalar {
                            name: name.to_string(),
                            available,
                        }))?
                        .1,
                )
            }
        };
        let mesh = Mesh::new(self.positions, self.indices, chosen)?;
        Ok(match self.normals {
            Some(n) => mesh.with_normals(n)?,
            None => mesh,
        })
    }

    /// Appends `other` (indices shifted past this mesh's vertices). Scalars
    /// and normals are kept only where both have them.
    pub(super) fn append(&mut self, other: Self) -> Result<(), ReadError> {
        // Check each part's indices against its own vertices: once shifted,
        // an index past the end would land on the next part's vertices.
        for (k, t) in other.indices.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= other.positions.len()) {
                let triangle = self.indices.len() + k;
                return Err(BuildError::IndexOutOfRange { triangle, index }.into());
            }
        }
        let offset = u32::try_from(self.positions.len())
            .map_err(|_| ReadError::from(ReadErrorKind::TooLarge))?;
        if self.positions.is_empty() && self.indices.is_empty() {
            *self = other;
            return Ok(());
        }
        check_vertex_count(self.positions.len() + other.positions.len())?;
        self.positions.extend(other.positions);
        self.indices.extend(other.indices.into_iter().map(|t| t.map(|i| i + offset)));
        self.normals = match (self.normals.take(), other.normals) {
            (Some(mut a), Some(b)) => {
                a.extend(b);
                Some(a)
            }
            _ => None,
        };
        let mut theirs = other.scalars;
        self.scalars.retain_mut(|(name, values)| {
            match theirs.iter_mut().find(|(n, _)| n == name) {
                Some((_, v)) => {
                    values.append(v);
                    true
                }
                None => false,
            }
        });
        theirs.clear();
        Ok(())
    }
}

pub(super) fn check_vertex_count(n: usize) -> Result<(), ReadError> {
    u32::try_from(n).map(|_| ()).map_err(|_| ReadError::from(ReadErrorKind::TooLarge))
}

/// Converts polygon or strip vertex lists into triangles.
pub(super) fn fan(cell: &[u32], out: &mut Vec<[u32; 3]>) {
    for w in cell.windows(2).skip(1) {
        out.push([cell[0], w[0], w[1]]);
    }
}

pub(super) fn strip(cell: &[u32], out: &mut Vec<[u32; 3]>) {
    for (k, w) in cell.windows(3).enumerate() {
        // Every other triangle of a strip is reversed to keep one winding.
        out.push(if k % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] });
    }
}

/// Groups of three floats as vectors; `None` unless the length is a
/// multiple of 3.
pub(super) fn vec3s(flat: &[f32]) -> Option<Vec<Vec3>> {
    flat.len().is_multiple_of(3).then(|| flat.chunks_exact(3).map(Vec3::from_slice).collect())
}
