//! Why a file could not be read as a grid.

use alloc::{
    boxed::Box,
    string::{String, ToString},
};
use core::{error::Error, fmt};
use std::path::{Path, PathBuf};

use crate::GridError;

/// Why a file could not be read as a grid: what went wrong
/// ([`ReadErrorKind`]) and, for the readers given a path, in which file
/// (the header's, or a payload file it names). `rt-surface`'s mesh
/// readers return an error of the same shape.
#[derive(Debug)]
pub struct ReadError {
    path: Option<PathBuf>,
    kind: ReadErrorKind,
}

/// What went wrong reading a grid.
#[derive(Debug)]
#[non_exhaustive]
pub enum ReadErrorKind {
    /// The operating system could not read the file.
    Io(std::io::Error),
    /// The file's extension names no format these readers know.
    UnknownFormat,
    /// The header is not valid in the file's format.
    Malformed {
        /// What is wrong (format and field).
        message: String,
        /// The parser's own error, where it gave one.
        source: Option<Box<dyn Error + Send + Sync>>,
    },
    /// A valid file using something this reader does not read.
    Unsupported(String),
    /// The header declares more samples than [`crate::Grid::MAX_SAMPLES`]
    /// (or than the address space holds).
    TooLarge,
    /// The payload length does not match the header.
    Truncated {
        /// Bytes the header calls for.
        expected: usize,
        /// Bytes present.
        found: usize,
    },
    /// The samples do not form a valid grid (NaN, sizes, geometry).
    Grid(GridError),
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

impl From<GridError> for ReadError {
    fn from(e: GridError) -> Self {
        ReadErrorKind::Grid(e).into()
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
            Self::UnknownFormat => f.write_str(
                "unknown grid format (expected .nrrd, .nhdr, .json with .raw, .vtk or .vti; \
                 unstructured grids .vtk or .vtu)",
            ),
            Self::Malformed { message, source: Some(e) } => {
                // One line: parsers' messages may go on with dumps of their
                // state, which `source()` still gives in full.
                let text = e.to_string();
                let first = text.lines().next().unwrap_or_default();
                write!(f, "malformed header: {message}: {first}")
            }
            Self::Malformed { message, source: None } => write!(f, "malformed header: {message}"),
            Self::Unsupported(m) => write!(f, "unsupported: {m}"),
            Self::TooLarge => {
                write!(f, "more samples than a grid holds ({})", crate::Grid::MAX_SAMPLES)
            }
            Self::Truncated { expected, found } => {
                write!(f, "payload has {found} bytes, header calls for {expected}")
            }
            Self::Grid(e) => write!(f, "invalid grid: {e}"),
        }
    }
}

impl Error for ReadError {
    fn source(&self) -> Option<&(dyn Error + 'static)> {
        match &self.kind {
            ReadErrorKind::Io(e) => Some(e),
            ReadErrorKind::Malformed { source: Some(e), .. } => Some(&**e),
            ReadErrorKind::Grid(e) => Some(e),
            _ => None,
        }
    }
}

/// A malformed-header error with no parser error behind it.
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
