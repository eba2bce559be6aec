//! Checking a [`Geometry`] before it is traced: every index names
//! something that exists and every per-vertex and per-triangle array has
//! its length, so that building and shading index without bounds
//! failures.
//!
//! The recorder only makes geometry that passes; a `Geometry` put
//! together by hand (its fields are public) may not, and building or
//! tracing it then answers [`GeometryError`] rather than panicking.

use core::fmt;

use rt_accel::BuildError;

use super::Geometry;

/// One primitive of a [`Geometry`], by its index in the field that
/// holds it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Primitive {
    /// `triangles[i]` (with `triangle_info[i]`).
    Triangle(usize),
    /// `spheres[i]`.
    Sphere(usize),
    /// `tubes[i]`.
    Tube(usize),
}

impl fmt::Display for Primitive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Triangle(i) => write!(f, "triangle {i}"),
            Self::Sphere(i) => write!(f, "sphere {i}"),
            Self::Tube(i) => write!(f, "tube {i}"),
        }
    }
}

/// Why a [`Geometry`] cannot be traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GeometryError {
    /// `normals` or `colors` does not hold exactly one entry per position.
    VertexAttributeCount {
        /// `positions.len()`.
        positions: usize,
        /// `normals.len()`.
        normals: usize,
        /// `colors.len()`.
        colors: usize,
    },
    /// `texcoords` is neither empty nor one entry per position.
    TexcoordCount {
        /// `positions.len()`.
        positions: usize,
        /// `texcoords.len()`.
        texcoords: usize,
    },
    /// `triangle_info` does not hold exactly one entry per triangle.
    TriangleInfoCount {
        /// `triangles.len()`.
        triangles: usize,
        /// `triangle_info.len()`.
        triangle_info: usize,
    },
    /// A primitive names a vertex past the end of `positions` (a
    /// triangle's corner or provoking vertex, a sphere's centre, a tube's
    /// end).
    VertexOutOfRange {
        /// The primitive.
        primitive: Primitive,
        /// The vertex index it names.
        index: u32,
    },
    /// A primitive names a shading past the end of `shadings`.
    ShadingOutOfRange {
        /// The primitive.
        primitive: Primitive,
        /// The shading index it names.
        index: u32,
    },
    /// The well-formed geometry's BVHs could not be built: a vertex or a
    /// radius that is not finite (or a radius not positive), or a size
    /// limit. Never [`BuildError::IndexOutOfRange`]:
    /// [`GeometryError::VertexOutOfRange`] is found first.
    Build(BuildError),
}

impl fmt::Display for GeometryError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::VertexAttributeCount { positions, normals, colors } => write!(
                f,
                "{positions} positions but {normals} normals and {colors} colours (one per position)"
            ),
            Self::TexcoordCount { positions, texcoords } => write!(
                f,
                "{positions} positions but {texcoords} texture coordinates (none, or one per position)"
            ),
            Self::TriangleInfoCount { triangles, triangle_info } => write!(
                f,
                "{triangles} triangles but {triangle_info} triangle_info entries (one per triangle)"
            ),
            Self::VertexOutOfRange { primitive, index } => {
                write!(f, "{primitive} refers to missing vertex {index}")
            }
            Self::ShadingOutOfRange { primitive, index } => {
                write!(f, "{primitive} refers to missing shading {index}")
            }
            Self::Build(e) => write!(f, "building the BVH: {e}"),
        }
    }
}

impl core::error::Error for GeometryError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Build(e) => Some(e),
            _ => None,
        }
    }
}

impl From<BuildError> for GeometryError {
    fn from(e: BuildError) -> Self {
        Self::Build(e)
    }
}

impl Geometry {
    /// Checks that the geometry can be built and shaded: one normal and
    /// one colour per position, one `triangle_info` entry per triangle,
    /// and every vertex and shading index in range. [`Geometry::build`]
    /// (and so every trace of the geometry) checks first; values (NaN,
    /// radii) are the build's to judge.
    ///
    /// # Errors
    /// The first problem found: [`GeometryError::VertexAttributeCount`],
    /// [`GeometryError::TexcoordCount`], [`GeometryError::TriangleInfoCount`],
    /// [`GeometryError::VertexOutOfRange`] or
    /// [`GeometryError::ShadingOutOfRange`].
    pub fn check(&self) -> Result<(), GeometryError> {
        let n = self.positions.len();
        if self.normals.len() != n || self.colors.len() != n {
            return Err(GeometryError::VertexAttributeCount {
                positions: n,
                normals: self.normals.len(),
                colors: self.colors.len(),
            });
        }
        if !self.texcoords.is_empty() && self.texcoords.len() != n {
            return Err(GeometryError::TexcoordCount {
                positions: n,
                texcoords: self.texcoords.len(),
            });
        }
        if self.triangle_info.len() != self.triangles.len() {
            return Err(GeometryError::TriangleInfoCount {
                triangles: self.triangles.len(),
                triangle_info: self.triangle_info.len(),
            });
        }
        let vertex = |primitive, index: u32| {
            if (index as usize) < n {
                Ok(())
            } else {
                Err(GeometryError::VertexOutOfRange { primitive, index })
            }
        };
        let shading = |primitive, index: u32| {
            if (index as usize) < self.shadings.len() {
                Ok(())
            } else {
                Err(GeometryError::ShadingOutOfRange { primitive, index })
            }
        };
        for (i, (corners, &(s, provoking))) in
            self.triangles.iter().zip(&self.triangle_info).enumerate()
        {
            let p = Primitive::Triangle(i);
            for &v in corners {
                vertex(p, v)?;
            }
            vertex(p, provoking)?;
            shading(p, s)?;
        }
        for (i, &(v, _, s)) in self.spheres.iter().enumerate() {
            let p = Primitive::Sphere(i);
            vertex(p, v)?;
            shading(p, s)?;
        }
        for (i, &(ends, _, s)) in self.tubes.iter().enumerate() {
            let p = Primitive::Tube(i);
            for v in ends {
                vertex(p, v)?;
            }
            shading(p, s)?;
        }
        Ok(())
    }
}
