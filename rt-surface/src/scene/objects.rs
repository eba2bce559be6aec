//! What a scene holds besides meshes, and how each object gets its colour.

use alloc::vec::Vec;
use core::fmt;

use glam::Vec3;
use rt_core::{ColorMap, intersect::Sphere};

use crate::Material;

/// How a surface gets its colour.
#[derive(Clone, Debug, PartialEq)]
pub enum Paint<'m> {
    /// One linear RGB colour.
    Solid([f32; 3]),
    /// The object's scalar (interpolated across the primitive first)
    /// through a colour map; objects without scalars get its NaN colour.
    Mapped(ColorMap<'m>),
}

impl Paint<'_> {
    pub(super) fn color(&self, scalar: Option<f32>) -> [f32; 3] {
        match self {
            Self::Solid(c) => *c,
            Self::Mapped(m) => {
                let c = m.map(scalar.unwrap_or(f32::NAN));
                [c[0], c[1], c[2]]
            }
        }
    }
}

/// Sphere glyphs (points, atoms), with an optional scalar each.
#[derive(Clone, Debug, PartialEq)]
pub struct Glyphs<'m> {
    /// The spheres.
    pub spheres: Vec<Sphere>,
    /// One scalar per sphere, for [`Paint::Mapped`].
    pub scalars: Option<Vec<f32>>,
    /// Colour.
    pub paint: Paint<'m>,
    /// Material.
    pub material: Material,
}

/// A tube along a polyline (a streamline), with optional scalars at the
/// points, interpolated along each segment.
#[derive(Clone, Debug, PartialEq)]
pub struct Tube<'m> {
    /// The polyline (at least 2 points).
    pub points: Vec<Vec3>,
    /// Tube radius.
    pub radius: f32,
    /// One scalar per point, for [`Paint::Mapped`].
    pub scalars: Option<Vec<f32>>,
    /// Colour.
    pub paint: Paint<'m>,
    /// Material.
    pub material: Material,
}

/// The kinds of object in a [`SurfaceScene`](super::SurfaceScene), for naming one in an error.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObjectKind {
    /// A triangle mesh.
    Mesh,
    /// A set of sphere glyphs.
    Glyphs,
    /// A tube.
    Tube,
}

impl fmt::Display for ObjectKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Mesh => "mesh",
            Self::Glyphs => "glyphs",
            Self::Tube => "tube",
        })
    }
}
