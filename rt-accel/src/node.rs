//! The 4-wide node layout and child references.
//!
//! A node holds the boxes of its four children in structure-of-arrays form
//! (one `[f32; 4]` per axis bound) so one SSE pass tests all four, and
//! four child references. A reference is either an inner node index, a leaf
//! (first item and item count), or empty. Children are always stored after
//! their parent, so every path through the tree is strictly increasing in
//! node index; loaders check this, which rules out cycles.

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

/// A reference to a child of a node.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(transparent)]
pub struct ChildRef(pub u32);

impl ChildRef {
    /// An unused child slot.
    pub const EMPTY: Self = Self(u32::MAX);

    /// A reference to inner node `index` (`index < 2³¹`).
    #[inline]
    #[must_use]
    pub const fn inner(index: u32) -> Self {
        Self(index & !LEAF_BIT)
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

/// A BVH node: four child boxes (SoA) and four child references.
/// 112 bytes, 16-byte aligned.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct Node {
    /// `[min_x, max_x, min_y, max_y, min_z, max_z]`, each over the 4 children.
    /// Empty slots hold the empty box (`+∞`, `−∞`).
    pub bounds: [[f32; 4]; 6],
    /// The children.
    pub children: [ChildRef; 4],
}

impl Node {
    /// A node with four empty slots.
    pub const EMPTY: Self = Self {
        bounds: [
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
            [f32::INFINITY; 4],
            [f32::NEG_INFINITY; 4],
        ],
        children: [ChildRef::EMPTY; 4],
    };

    /// The box of child slot `i`.
    #[inline]
    #[must_use]
    pub fn child_bounds(&self, i: usize) -> Aabb {
        let b = &self.bounds;
        Aabb::new(Vec3::new(b[0][i], b[2][i], b[4][i]), Vec3::new(b[1][i], b[3][i], b[5][i]))
    }

    /// Sets the box of child slot `i`.
    #[inline]
    pub fn set_child_bounds(&mut self, i: usize, a: Aabb) {
        let b = &mut self.bounds;
        (b[0][i], b[2][i], b[4][i]) = (a.min.x, a.min.y, a.min.z);
        (b[1][i], b[3][i], b[5][i]) = (a.max.x, a.max.y, a.max.z);
    }

    /// The union of the child boxes.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        (0..4).fold(Aabb::EMPTY, |acc, i| {
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
        assert!(!n.is_leaf() && n.index() == 77);
        assert!(ChildRef::EMPTY.is_leaf() && ChildRef::EMPTY.is_empty());
        assert_eq!(core::mem::size_of::<Node>(), 112);
    }
}
