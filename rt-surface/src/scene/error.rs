//! Why a scene could not be built or changed.

use core::fmt;

use rt_accel::BuildError;

use super::ObjectKind;
use crate::MaterialError;

/// Why a [`SurfaceScene`](super::SurfaceScene) could not be built or changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneError {
    /// Building or refitting a BVH failed (names the vertex or primitive,
    /// counted within the object).
    Build {
        /// Which kind of object.
        kind: ObjectKind,
        /// Its index among objects of that kind.
        object: usize,
        /// What was wrong.
        error: BuildError,
    },
    /// A material parameter out of range.
    Material {
        /// Which kind of object.
        kind: ObjectKind,
        /// Its index among objects of that kind.
        object: usize,
        /// The parameter.
        error: MaterialError,
    },
    /// Glyph or tube scalars whose count does not match, a tube of fewer
    /// than 2 points.
    Shape {
        /// Which kind of object.
        kind: ObjectKind,
        /// Its index among objects of that kind.
        object: usize,
    },
    /// No mesh with that index.
    NoSuchMesh(usize),
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Build { kind, object, error } => write!(f, "{kind} {object}: {error}"),
            Self::Material { kind, object, error } => write!(f, "{kind} {object}: {error}"),
            Self::Shape { kind, object } => {
                write!(f, "{kind} {object}: scalar count does not match, or too few points")
            }
            Self::NoSuchMesh(i) => write!(f, "no mesh {i}"),
        }
    }
}

impl core::error::Error for SceneError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Build { error, .. } => Some(error),
            Self::Material { error, .. } => Some(error),
            Self::Shape { .. } | Self::NoSuchMesh(_) => None,
        }
    }
}
