//! The 8-wide node layout and child references.
//!
//! A node holds the boxes of its eight children in structure-of-arrays form
//! (`[f32; 4]` per axis bound and group of four children, so one SSE pass
//! tests four boxes) and eight child references. A reference is either an
//! inner node's byte offset in the node array (its index times
//! [`NODE_BYTES`]), a leaf (first item and item count), or empty. Nodes
//! are stored breadth first, so children always follow their parent;
//! loaders check this exactly, which rules out cycles and sharing.
//!
//! Why byte offsets: a traversal step loads a child reference, finds the
//! node's address and loads its boxes, one after the other. From an index
//! the address takes a multiply by 224 (3 cycles on the chain); from an
//! offset, an addition the load's addressing does. It caps a tree at
//! [`MAX_NODES`] nodes, about 190 M triangles.
//!
//! Why eight: incoherent rays on million-triangle scenes are bound by the
//! chain of dependent node fetches from root to leaf, which halving the
//! depth of a 4-wide tree shortens, at no cost to primary rays.

use glam::Vec3;
use rt_core::Aabb;

/// Bit set on leaf references.
const LEAF_BIT: u32 = 1 << 31;
/// Bits of a leaf reference holding `count − 1`.
const COUNT_SHIFT: u32 = 27;
/// Largest number of items in one leaf.
pub const MAX_LEAF_ITEMS: u32 = 16;
/// Largest first-item index a leaf can hold (`2²⁷ − 2`; `2²⁷ − 1` with
/// count 16 is the empty reference).
pub const MAX_ITEMS: u32 = (1 << COUNT_SHIFT) - 1;

/// Bytes per node: the stride of inner references.
pub const NODE_BYTES: u32 = core::mem::size_of::<Node>() as u32;
/// Largest number of nodes one tree can hold: inner references are byte
/// offsets below `2³¹`.
pub const MAX_NODES: u32 = LEAF_BIT / NODE_BYTES;

/// A reference to a child of a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(transparent)]
pub struct ChildRef(pub u32);

impl ChildRef {
    /// An unused child slot.
    pub const EMPTY: Self = Self(u32::MAX);

    /// A reference to inner node `index`, stored as its byte offset
    /// `index · NODE_BYTES`. `index` must be below [`MAX_NODES`]; a larger
    /// one makes a reference that names some other node (loaders reject
    /// trees whose references are out of order).
    #[inline]
    #[must_use]
    pub const fn inner(index: u32) -> Self {
        Self(index.wrapping_mul(NODE_BYTES) & !LEAF_BIT)
    }

    /// A leaf of `count ∈ [1, 16]` items starting at `first < MAX_ITEMS`.
    #[inline]
    #[must_use]
    pub const fn leaf(first: u32, count: u32) -> Self {
        Self(LEAF_BIT | ((count - 1) << COUNT_SHIFT) | first)
    }

    /// Whether this is the empty slot.
    #[inline]
    #[must_use]
    pub const fn is_empty(self) -> bool {
        self.0 == u32::MAX
    }

    /// Whether this is a leaf (or empty).
    #[inline]
    #[must_use]
    pub const fn is_leaf(self) -> bool {
        self.0 & LEAF_BIT != 0
    }

    /// Inner node index (meaningful for inner references).
    #[inline]
    #[must_use]
    pub const fn index(self) -> usize {
        (self.0 / NODE_BYTES) as usize
    }

    /// Byte offset of an inner node in the node array (meaningful for
    /// inner references; a multiple of [`NODE_BYTES`] in every checked
    /// tree).
    #[inline(always)]
    #[must_use]
    pub const fn byte_offset(self) -> usize {
        self.0 as usize
    }

    /// `(first item, item count)` of a leaf reference.
    #[inline]
    #[must_use]
    pub const fn leaf_range(self) -> (usize, usize) {
        let first = self.0 & ((1 << COUNT_SHIFT) - 1);
        let count = ((self.0 >> COUNT_SHIFT) & 0xf) + 1;
        (first as usize, count as usize)
    }
}

/// Children per node.
pub const WIDTH: usize = 8;
/// Groups of four children, tested by one SSE pass each.
pub const GROUPS: usize = WIDTH / 4;

/// A BVH node: [`WIDTH`] child boxes in structure-of-arrays form and their
/// references.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct Node {
    /// `[min_x, max_x, min_y, max_y, min_z, max_z]`, each over the children
    /// in groups of four: `bounds[row][group][lane]` is child `4·group + lane`.
    /// Empty slots hold the empty box (`+∞`, `−∞`).
    pub bounds: [[[f32; 4]; GROUPS]; 6],
    /// The children.
    pub children: [ChildRef; WIDTH],
}

impl Node {
    /// A node with every slot empty.
    pub const EMPTY: Self = Self {
        bounds: [
            [[f32::INFINITY; 4]; GROUPS],
            [[f32::NEG_INFINITY; 4]; GROUPS],
            [[f32::INFINITY; 4]; GROUPS],
            [[f32::NEG_INFINITY; 4]; GROUPS],
            [[f32::INFINITY; 4]; GROUPS],
            [[f32::NEG_INFINITY; 4]; GROUPS],
        ],
        children: [ChildRef::EMPTY; WIDTH],
    };

    /// The box of child slot `i`.
    #[inline]
    #[must_use]
    pub fn child_bounds(&self, i: usize) -> Aabb {
        let (g, l) = (i / 4, i % 4);
        let b = |row: usize| self.bounds[row][g][l];
        Aabb::new(Vec3::new(b(0), b(2), b(4)), Vec3::new(b(1), b(3), b(5)))
    }

    /// Sets the box of child slot `i`.
    #[inline]
    pub fn set_child_bounds(&mut self, i: usize, a: Aabb) {
        let (g, l) = (i / 4, i % 4);
        let vals = [a.min.x, a.max.x, a.min.y, a.max.y, a.min.z, a.max.z];
        for (row, v) in vals.into_iter().enumerate() {
            self.bounds[row][g][l] = v;
        }
    }

    /// Whether every non-empty child box lies within `±range` (false for a
    /// NaN or infinite bound).
    #[must_use]
    pub(crate) fn within(&self, range: f32) -> bool {
        (0..WIDTH).all(|i| {
            let b = self.child_bounds(i);
            self.children[i].is_empty()
                || (b.min.abs().cmple(Vec3::splat(range)) & b.max.abs().cmple(Vec3::splat(range)))
                    .all()
        })
    }

    /// The union of the child boxes.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        (0..WIDTH).fold(Aabb::EMPTY, |acc, i| {
            if self.children[i].is_empty() { acc } else { acc.union(self.child_bounds(i)) }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn child_refs_round_trip() {
        let l = ChildRef::leaf(MAX_ITEMS - 1, MAX_LEAF_ITEMS);
        assert!(l.is_leaf() && !l.is_empty());
        assert_eq!(l.leaf_range(), ((MAX_ITEMS - 1) as usize, 16));
        assert_eq!(ChildRef::leaf(5, 1).leaf_range(), (5, 1));
        let n = ChildRef::inner(77);
        assert!(!n.is_leaf() && n.index() == 77 && n.byte_offset() == 77 * 224);
        let last = ChildRef::inner(MAX_NODES - 1);
        assert!(!last.is_leaf() && !last.is_empty() && last.index() == (MAX_NODES - 1) as usize);
        assert!(ChildRef::EMPTY.is_leaf() && ChildRef::EMPTY.is_empty());
        assert_eq!(core::mem::size_of::<Node>(), 28 * WIDTH);
    }
}
