//! The byte format of a built BVH and its validation.
//!
//! Layout: a 64-byte [`Header`], then the nodes, then the leaf items, all
//! in native byte order (the header records it). Loading checks the header
//! and every invariant traversal relies on (see [`validate`]), so a
//! malformed blob is an `Err`, never a panic or an out-of-bounds read.

use rt_core::Aabb;

use crate::{
    LoadError, MAX_DEPTH,
    node::{NODE_BYTES, Node},
    prim::Primitive,
    traverse::BvhRef,
};

/// Magic bytes opening every serialized BVH.
pub const MAGIC: [u8; 8] = *b"rtBVH4\0\0";
/// Format version written by this crate. Version 2 stores inner child
/// references as byte offsets (version 1: node indices).
pub const VERSION: u32 = 2;
const ENDIAN: u32 = 0x0102_0304;

/// The header of a serialized BVH.
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Header {
    /// [`MAGIC`].
    pub magic: [u8; 8],
    /// [`VERSION`].
    pub version: u32,
    /// `0x01020304` in the writer's byte order.
    pub endian: u32,
    /// Primitive kind tag ([`Primitive::TAG`]).
    pub tag: u32,
    /// Number of nodes.
    pub node_count: u32,
    /// Number of leaf items.
    pub item_count: u32,
    /// Number of primitives the items refer to.
    pub prim_count: u32,
    /// Reserved, zero.
    pub reserved: [u32; 8],
}

impl Header {
    #[cfg(feature = "alloc")]
    pub(crate) fn new<P: Primitive>(nodes: usize, items: usize, prims: u32) -> Self {
        Self {
            magic: MAGIC,
            version: VERSION,
            endian: ENDIAN,
            tag: P::TAG,
            node_count: nodes as u32,
            item_count: items as u32,
            prim_count: prims,
            reserved: [0; 8],
        }
    }
}

/// Reads and checks the header; returns it with the byte ranges of the
/// node and item arrays.
pub(crate) fn parse<P: Primitive>(
    bytes: &[u8],
) -> Result<(Header, core::ops::Range<usize>, core::ops::Range<usize>), LoadError> {
    let hsize = size_of::<Header>();
    let head = bytes.get(..hsize).ok_or(LoadError::BadLength)?;
    let h: Header = bytemuck::pod_read_unaligned(head);
    if h.magic != MAGIC {
        return Err(LoadError::BadMagic);
    }
    if h.endian != ENDIAN {
        return Err(LoadError::WrongEndianness);
    }
    if h.version != VERSION {
        return Err(LoadError::UnsupportedVersion(h.version));
    }
    if h.tag != P::TAG {
        return Err(LoadError::WrongKind { expected: P::TAG, found: h.tag });
    }
    let nodes_len =
        (h.node_count as usize).checked_mul(size_of::<Node>()).ok_or(LoadError::BadLength)?;
    let items_len =
        (h.item_count as usize).checked_mul(size_of::<P>()).ok_or(LoadError::BadLength)?;
    let total = hsize
        .checked_add(nodes_len)
        .and_then(|n| n.checked_add(items_len))
        .ok_or(LoadError::BadLength)?;
    if bytes.len() != total {
        return Err(LoadError::BadLength);
    }
    Ok((h, hsize..hsize + nodes_len, hsize + nodes_len..total))
}

impl<'a, P: Primitive> BvhRef<'a, P> {
    /// Borrows a serialized BVH without copying. The bytes must start on a
    /// 16-byte boundary (`align_of::<Node>()`): [`crate::AlignedBytes`]
    /// (from [`crate::Bvh::to_aligned_bytes`], or a copy of bytes read
    /// elsewhere) always does; a `Vec<u8>` need not. Use
    /// [`crate::Bvh::from_bytes`] to load from any buffer by copying.
    ///
    /// # Errors
    /// [`LoadError`] naming the first problem found.
    pub fn from_bytes(bytes: &'a [u8]) -> Result<Self, LoadError> {
        let (h, nr, ir) = parse::<P>(bytes)?;
        let nodes: &[Node] =
            bytemuck::try_cast_slice(&bytes[nr]).map_err(|_| LoadError::Misaligned)?;
        let items: &[P] =
            bytemuck::try_cast_slice(&bytes[ir]).map_err(|_| LoadError::Misaligned)?;
        validate(nodes, items, h.prim_count)?;
        let fused = crate::traverse::fits_fused(nodes);
        Ok(Self { nodes, items, prim_count: h.prim_count, isa: crate::Isa::detect(), fused })
    }

    /// Wraps arrays after checking them with [`validate`].
    ///
    /// # Errors
    /// [`LoadError`] naming the first problem found.
    pub fn from_parts(
        nodes: &'a [Node],
        items: &'a [P],
        prim_count: u32,
    ) -> Result<Self, LoadError> {
        validate(nodes, items, prim_count)?;
        let fused = crate::traverse::fits_fused(nodes);
        Ok(Self { nodes, items, prim_count, isa: crate::Isa::detect(), fused })
    }
}

/// Checks what traversal relies on: nodes are in breadth-first order, so
/// the inner children met scanning nodes `0, 1, 2, …` (slots in order) are
/// exactly nodes `1, 2, 3, …`, each once: that makes the nodes a tree with
/// every child after its parent. Empty slots hold the empty box, which no
/// ray enters. Leaf ranges lie inside the item array;
/// depth ≤ [`MAX_DEPTH`]; every item is well formed. Linear time, constant
/// memory, no allocation.
///
/// # Errors
/// [`LoadError`] naming the first problem found.
pub fn validate<P: Primitive>(
    nodes: &[Node],
    items: &[P],
    prim_count: u32,
) -> Result<(), LoadError> {
    if let Some(item) = items.iter().position(|it| !it.is_well_formed(prim_count)) {
        return Err(LoadError::BadItem { item });
    }
    if nodes.is_empty() {
        return if items.is_empty() { Ok(()) } else { Err(LoadError::NotATree) };
    }
    // `next`: the index the next inner child reference must have. Nodes in
    // `[level_start, level_end)` form one level of the tree.
    let mut next = 1;
    let (mut depth, mut level_end) = (1, 1);
    for (i, node) in nodes.iter().enumerate() {
        if i >= next {
            // Nothing refers to node i.
            return Err(LoadError::NotATree);
        }
        if i == level_end {
            depth += 1;
            level_end = next;
        }
        if depth > MAX_DEPTH {
            return Err(LoadError::TooDeep);
        }
        for (slot, c) in node.children.into_iter().enumerate() {
            if c.is_empty() {
                if node.child_bounds(slot) != Aabb::EMPTY {
                    return Err(LoadError::OpenEmptySlot { node: i });
                }
                continue;
            }
            if c.is_leaf() {
                let (first, count) = c.leaf_range();
                if first + count > items.len() {
                    return Err(LoadError::LeafOutOfRange { node: i });
                }
            } else {
                let ci = c.index();
                // An offset between two nodes would floor to a valid index.
                if !c.byte_offset().is_multiple_of(NODE_BYTES as usize)
                    || ci <= i
                    || ci >= nodes.len()
                {
                    return Err(LoadError::BadChild { node: i });
                }
                if ci != next {
                    return Err(LoadError::NotATree);
                }
                next += 1;
            }
        }
    }
    if next != nodes.len() {
        return Err(LoadError::NotATree);
    }
    Ok(())
}
