//! Why a mesh could not be built.

use core::fmt;

/// Why an [`super::UnstructuredField`] could not be built. Every variant
/// names the first offending point or cell (indices into the caller's
/// lists).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MeshError {
    /// No cells.
    Empty,
    /// More points, cells or tetrahedra than `u32` indices address.
    TooLarge,
    /// One value per point is needed.
    ValueCount {
        /// Points in the mesh.
        points: usize,
        /// Values given.
        values: usize,
    },
    /// A point coordinate is NaN or infinite.
    NonFinitePoint {
        /// Index of the point.
        point: usize,
    },
    /// A point's value is NaN or infinite, or maps to an index that is not
    /// finite and positive.
    BadValue {
        /// Index of the point.
        point: usize,
    },
    /// A cell refers to a point that does not exist.
    IndexOutOfRange {
        /// Index of the cell.
        cell: usize,
        /// The missing point index.
        index: u32,
    },
    /// A cell uses the same point twice.
    RepeatedPoint {
        /// Index of the cell.
        cell: usize,
    },
    /// A cell (or one tetrahedron of its split) has no volume: its points
    /// are coplanar to round-off.
    Degenerate {
        /// Index of the cell.
        cell: usize,
    },
    /// A cell is folded (the tetrahedra of its split face opposite ways)
    /// or overlaps the cell across one of its faces (both lie on the same
    /// side of the face they share): it is inverted.
    Inverted {
        /// Index of the cell.
        cell: usize,
    },
    /// A face is shared by more than two cells.
    NonManifold {
        /// Index of a cell with that face.
        cell: usize,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Empty => write!(f, "the mesh has no cells"),
            Self::TooLarge => write!(f, "the mesh has more than 2^32 - 2 points or tetrahedra"),
            Self::ValueCount { points, values } => {
                write!(f, "{values} values given for {points} points (one per point needed)")
            }
            Self::NonFinitePoint { point } => write!(f, "point {point} is not finite"),
            Self::BadValue { point } => {
                write!(f, "the value at point {point} is not finite, or maps to no positive index")
            }
            Self::IndexOutOfRange { cell, index } => {
                write!(f, "cell {cell} refers to missing point {index}")
            }
            Self::RepeatedPoint { cell } => write!(f, "cell {cell} uses a point twice"),
            Self::Degenerate { cell } => write!(f, "cell {cell} has no volume"),
            Self::Inverted { cell } => write!(f, "cell {cell} is inverted or overlaps a neighbour"),
            Self::NonManifold { cell } => {
                write!(f, "cell {cell} has a face shared by more than two cells")
            }
        }
    }
}

impl core::error::Error for MeshError {}
