//! Errors of building and loading.

use core::fmt;

/// Why a BVH could not be built or refitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuildError {
    /// A vertex coordinate is NaN or infinite.
    NonFiniteVertex {
        /// Index of the vertex.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
    },
    /// A sphere or capsule has a non-finite coordinate or a radius that is
    /// not finite and positive.
    InvalidPrimitive {
        /// Index of the primitive.
        index: usize,
    },
    /// Refit data do not match the BVH (different primitive count).
    RefitMismatch,
    /// More primitives than the node layout can address (2²⁷ leaf items,
    /// [`crate::MAX_NODES`] nodes).
    TooManyPrimitives,
    /// The builder produced a tree deeper than [`crate::MAX_DEPTH`].
    TooDeep,
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NonFiniteVertex { vertex } => write!(f, "vertex {vertex} is not finite"),
            Self::IndexOutOfRange { triangle, index } => {
                write!(f, "triangle {triangle} refers to missing vertex {index}")
            }
            Self::InvalidPrimitive { index } => {
                write!(f, "primitive {index} is not finite or has a non-positive radius")
            }
            Self::RefitMismatch => write!(f, "refit data do not match the BVH's primitives"),
            Self::TooManyPrimitives => write!(f, "too many primitives for one BVH"),
            Self::TooDeep => write!(f, "BVH deeper than MAX_DEPTH"),
        }
    }
}

impl core::error::Error for BuildError {}

/// Why bytes could not be loaded as a BVH.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadError {
    /// Shorter than the header, or the length does not match the header.
    BadLength,
    /// Not an rt BVH (magic bytes differ).
    BadMagic,
    /// A format version this build does not read.
    UnsupportedVersion(u32),
    /// Written on a machine of the other byte order.
    WrongEndianness,
    /// A BVH of another primitive kind.
    WrongKind {
        /// Tag expected by the caller's type.
        expected: u32,
        /// Tag in the bytes.
        found: u32,
    },
    /// Zero-copy loading needs 16-byte aligned bytes; copy with
    /// `Bvh::from_bytes` instead.
    Misaligned,
    /// A child reference points at or before its parent, past the end, or
    /// between two nodes (an offset not a multiple of the node size).
    BadChild {
        /// The node holding the reference.
        node: usize,
    },
    /// A leaf's item range exceeds the item array.
    LeafOutOfRange {
        /// The node holding the leaf.
        node: usize,
    },
    /// An empty child slot whose box is not the empty box: traversal
    /// relies on no ray ever entering an empty slot.
    OpenEmptySlot {
        /// The node holding the slot.
        node: usize,
    },
    /// Nodes reachable twice or not at all: not a tree.
    NotATree,
    /// Deeper than [`crate::MAX_DEPTH`].
    TooDeep,
    /// A leaf item has non-finite data or a primitive id out of range.
    BadItem {
        /// Index of the item.
        item: usize,
    },
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadLength => write!(f, "byte length does not match the BVH header"),
            Self::BadMagic => write!(f, "not an rt BVH (bad magic)"),
            Self::UnsupportedVersion(v) => write!(f, "unsupported BVH format version {v}"),
            Self::WrongEndianness => write!(f, "BVH written with the other byte order"),
            Self::WrongKind { expected, found } => {
                write!(f, "BVH holds primitive kind {found}, expected {expected}")
            }
            Self::Misaligned => write!(f, "bytes not 16-byte aligned for zero-copy loading"),
            Self::BadChild { node } => write!(f, "node {node} has an invalid child reference"),
            Self::LeafOutOfRange { node } => write!(f, "node {node} has a leaf past the items"),
            Self::OpenEmptySlot { node } => {
                write!(f, "node {node} has an empty child slot with a non-empty box")
            }
            Self::NotATree => write!(f, "nodes do not form a tree"),
            Self::TooDeep => write!(f, "BVH deeper than MAX_DEPTH"),
            Self::BadItem { item } => write!(f, "leaf item {item} is malformed"),
        }
    }
}

impl core::error::Error for LoadError {}
