//! Why a file could not be read as a mesh.

use alloc::{
    boxed::Box,
    string::{String, ToString},
    vec::Vec,
};
use core::{error::Error, fmt};
use std::path::{Path, PathBuf};

use crate::MeshError;

/// Why a file could not be read as a mesh: what went wrong
/// ([`ReadErrorKind`]) and, for the readers given a path, in which file.
/// `rt-volume`'s grid readers return an error of the same shape.
#[derive(Debug)]
pub struct ReadError {
    path: Option<PathBuf>,
    kind: ReadErrorKind,
}

/// What went wrong reading a mesh.
#[derive(Debug)]
#[non_exhaustive]
pub enum ReadErrorKind {
    /// The operating system could not read the file.
    Io(std::io::Error),
    /// The file's extension names no format these readers know.
    UnknownFormat,
    /// The bytes are not valid in the file's format.
    Malformed {
        /// What is wrong (format and place).
        message: String,
        /// The parser's own error, where it gave one.
        source: Option<Box<dyn Error + Send + Sync>>,
    },
    /// A valid file using something this reader does not read.
    Unsupported(String),
    /// More vertices than 32-bit indices can address.
    TooLarge,
    /// [`MeshData::into_mesh`](super::MeshData::into_mesh) was asked for a
    /// scalar the file lacks.
    NoSuchScalar {
        /// The name asked for.
        name: String,
        /// The names the file has.
        available: Vec<String>,
    },
    /// The geometry is invalid (a NaN vertex, an index out of range, a
    /// zero normal), with the offending vertex or triangle.
    Mesh(MeshError),
}

impl ReadError {
    /// The file, for errors of the readers given a path.
    #[must_use]
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// What went wrong.
    #[must_use]
    pub fn kind(&self) -> &ReadErrorKind {
        &self.kind
    }

    /// What went wrong, by value.
    #[must_use]
    pub fn into_kind(self) -> ReadErrorKind {
        self.kind
    }

    /// The error in `path`, unless it already names a file.
    pub(super) fn in_file(mut self, path: &Path) -> Self {
        self.path.get_or_insert_with(|| path.to_path_buf());
        self
    }
}

impl From<ReadErrorKind> for ReadError {
    fn from(kind: ReadErrorKind) -> Self {
        Self { path: None, kind }
    }
}

impl From<MeshError> for ReadError {
    fn from(e: MeshError) -> Self {
        ReadErrorKind::Mesh(e).into()
    }
}

impl From<rt_accel::BuildError> for ReadError {
    fn from(e: rt_accel::BuildError) -> Self {
        MeshError::Geometry(e).into()
    }
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(path) = &self.path {
            write!(f, "{}: ", path.display())?;
        }
        write!(f, "{}", self.kind)
    }
}

impl fmt::Display for ReadErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io(e) => write!(f, "{e}"),
            Self::UnknownFormat => {
                f.write_str("unknown mesh format (expected .obj, .ply, .vtk or .vtp)")
            }
            Self::Malformed { message, source: Some(e) } => {
                // One line: parsers' messages may go on with dumps of their
                // state, which `source()` still gives in full.
                let text = e.to_string();
                let first = text.lines().next().unwrap_or_default();
                write!(f, "malformed mesh file: {message}: {first}")
            }
            Self::Malformed { message, source: None } => {
                write!(f, "malformed mesh file: {message}")
            }
            Self::Unsupported(m) => write!(f, "unsupported: {m}"),
            Self::TooLarge => f.write_str("more vertices than 32-bit indices address"),
            Self::NoSuchScalar { name, available } => {
                write!(f, "no scalar `{name}`; the file has {available:?}")
            }
            Self::Mesh(e) => write!(f, "invalid mesh: {e}"),
        }
    }
}

impl Error for ReadError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        match &self.kind {
            ReadErrorKind::Io(e) => Some(e),
            ReadErrorKind::Malformed { source: Some(e), .. } => Some(&**e),
            ReadErrorKind::Mesh(e) => Some(e),
            _ => None,
        }
    }
}

/// A malformed-file error with no parser error behind it.
pub(super) fn malformed(message: impl Into<String>) -> ReadError {
    ReadErrorKind::Malformed { message: message.into(), source: None }.into()
}

/// A malformed-file error wrapping the parser's own.
pub(super) fn parse_error(
    message: impl Into<String>,
    e: impl Into<Box<dyn Error + Send + Sync>>,
) -> ReadError {
    ReadErrorKind::Malformed { message: message.into(), source: Some(e.into()) }.into()
}

/// A valid file using something the reader does not read.
pub(super) fn unsupported(message: impl Into<String>) -> ReadError {
    ReadErrorKind::Unsupported(message.into()).into()
}
