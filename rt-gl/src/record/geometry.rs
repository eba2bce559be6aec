//! Recorded geometry in one space (positions, normals, colours, triangles,
//! spheres and tubes, with their shadings), and its BVHs.

use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use rt_accel::{BuildError, BuildParams, Scene, build_capsules, build_spheres, build_triangles};
use rt_core::intersect::{Capsule, Sphere};

use super::{GeometryError, Shading, normal_matrix};

/// Recorded geometry in one space, with what shading needs.
///
/// The fields are public, and nothing stops a hand-made geometry from
/// breaking the rules below; [`Geometry::check`] tells, and building or
/// tracing such a geometry is a [`GeometryError`], never a panic.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Geometry {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals (unnormalised, as transformed), one per position.
    pub normals: Vec<Vec3>,
    /// Vertex colours, one per position.
    pub colors: Vec<Vec4>,
    /// Texture coordinates: none, or one per position.
    pub texcoords: Vec<Vec2>,
    /// Triangles (vertex indices, counter-clockwise as drawn).
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle (one entry each): its shading (index into
    /// `shadings`) and provoking vertex (for flat shading).
    pub triangle_info: Vec<(u32, u32)>,
    /// Points drawn as spheres: vertex, radius, shading.
    pub spheres: Vec<(u32, f32, u32)>,
    /// Line segments drawn as tubes: vertices, radius, shading.
    pub tubes: Vec<([u32; 2], f32, u32)>,
    /// The shadings used.
    pub shadings: Vec<Shading>,
}

impl Geometry {
    /// Whether nothing was drawn.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty() && self.spheres.is_empty() && self.tubes.is_empty()
    }

    /// Appends `other` transformed by `m` (positions) and `m`'s normal
    /// matrix (normals).
    ///
    /// # Errors
    /// What [`Geometry::check`] finds in `self` or in `other`; nothing is
    /// appended then (an index out of range, offset, could name a vertex
    /// of the other geometry and pass unnoticed).
    pub fn append_transformed(&mut self, other: &Self, m: &Mat4) -> Result<(), GeometryError> {
        self.check()?;
        other.check()?;
        self.append_checked(other, m);
        Ok(())
    }

    /// [`Geometry::append_transformed`] of two geometries that have
    /// passed [`Geometry::check`].
    pub(super) fn append_checked(&mut self, other: &Self, m: &Mat4) {
        // Saturating: past 2³² vertices an index cannot be offset (nor
        // made), and must not wrap onto a vertex that exists.
        let base = u32::try_from(self.positions.len()).unwrap_or(u32::MAX);
        let sbase = u32::try_from(self.shadings.len()).unwrap_or(u32::MAX);
        let v = |i: u32| i.saturating_add(base);
        let s = |i: u32| i.saturating_add(sbase);
        let nm = normal_matrix(m);
        // Radii scale with the transform's mean scale.
        let scale = Mat3::from_mat4(*m).determinant().abs().cbrt();
        self.positions.extend(other.positions.iter().map(|&p| m.transform_point3(p)));
        self.normals.extend(other.normals.iter().map(|&n| nm * n));
        self.colors.extend_from_slice(&other.colors);
        if !self.texcoords.is_empty() || !other.texcoords.is_empty() {
            // Either side without texture coordinates has zeros.
            self.texcoords.resize(base as usize, Vec2::ZERO);
            self.texcoords.extend_from_slice(&other.texcoords);
            self.texcoords.resize(self.positions.len(), Vec2::ZERO);
        }
        self.triangles.extend(other.triangles.iter().map(|t| t.map(v)));
        self.triangle_info.extend(other.triangle_info.iter().map(|&(k, p)| (s(k), v(p))));
        self.spheres.extend(other.spheres.iter().map(|&(i, r, k)| (v(i), r * scale, s(k))));
        self.tubes.extend(other.tubes.iter().map(|&(e, r, k)| (e.map(v), r * scale, s(k))));
        self.shadings.extend_from_slice(&other.shadings);
    }

    /// BVHs over the triangles, spheres and tubes, once the geometry has
    /// passed [`Geometry::check`].
    ///
    /// # Errors
    /// What [`Geometry::check`] finds, or [`GeometryError::Build`] if a
    /// primitive is not finite (or a radius not positive).
    pub fn build(&self) -> Result<Scene, GeometryError> {
        self.check()?;
        Ok(self.build_checked()?)
    }

    /// [`Geometry::build`] for a geometry that has passed
    /// [`Geometry::check`].
    pub(super) fn build_checked(&self) -> Result<Scene, BuildError> {
        let params = BuildParams::fast();
        Ok(Scene {
            triangles: build_triangles(&self.positions, &self.triangles, &params)?,
            spheres: build_spheres(&self.sphere_shapes(), &params)?,
            capsules: build_capsules(&self.tube_shapes(), &params)?,
        })
    }

    /// The points as spheres, in the order of [`Self::spheres`].
    ///
    /// # Panics
    /// On a geometry that has not passed [`Geometry::check`].
    pub(super) fn sphere_shapes(&self) -> Vec<Sphere> {
        self.spheres.iter().map(|&(v, r, _)| Sphere::new(self.positions[v as usize], r)).collect()
    }

    /// The line segments as capsules, in the order of [`Self::tubes`].
    ///
    /// # Panics
    /// On a geometry that has not passed [`Geometry::check`].
    pub(super) fn tube_shapes(&self) -> Vec<Capsule> {
        self.tubes
            .iter()
            .map(|&([a, b], r, _)| {
                Capsule::new(self.positions[a as usize], self.positions[b as usize], r)
            })
            .collect()
    }

    pub(super) fn shading_index(&mut self, s: Shading) -> u32 {
        if self.shadings.last() != Some(&s) {
            self.shadings.push(s);
        }
        self.shadings.len() as u32 - 1
    }
}
