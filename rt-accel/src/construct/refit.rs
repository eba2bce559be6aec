//! Refitting after primitives move: same tree, new boxes.

use glam::Vec3;
use rt_core::intersect::{Capsule, Sphere, is_degenerate_triangle};

use crate::{
    BuildError, Bvh, CapsuleItem, SphereItem, TriPacket, check::triangle_vertices, prim::ShapeItem,
};

impl Bvh<TriPacket> {
    /// Moves every triangle to its new vertices (`indices` must be the list
    /// the BVH was built from, `positions` the moved vertices) and refits
    /// the boxes. Triangles left out at build time as degenerate stay out
    /// until a rebuild; triangles that become degenerate are never hit
    /// (their lane collapses to a point) until a refit gives them area.
    ///
    /// # Errors
    /// [`BuildError::RefitMismatch`] if `indices` has a different length,
    /// else as [`crate::build_triangles`]; on error nothing is changed.
    pub fn refit_triangles(
        &mut self,
        positions: &[Vec3],
        indices: &[[u32; 3]],
    ) -> Result<(), BuildError> {
        if indices.len() != self.prim_count as usize {
            return Err(BuildError::RefitMismatch);
        }
        // Check everything before writing anything.
        for v in triangle_vertices(positions, indices)? {
            v?;
        }
        self.refit_with(|items| {
            for packet in items {
                for lane in 0..packet.len() {
                    let idx = indices[packet.prims[lane] as usize];
                    let mut verts = idx.map(|i| positions[i as usize]);
                    if is_degenerate_triangle(verts[0], verts[1], verts[2]) {
                        // A point triangle: edge functions exactly 0, never hit.
                        verts = [verts[0]; 3];
                    }
                    packet.set_lane(lane, packet.prims[lane], verts);
                }
            }
            Ok(())
        })
    }
}

impl Bvh<SphereItem> {
    /// Moves (and resizes) every sphere and refits the boxes.
    ///
    /// # Errors
    /// [`BuildError::RefitMismatch`] for a different count,
    /// [`BuildError::InvalidPrimitive`] for a bad sphere; nothing changes.
    pub fn refit_spheres(&mut self, spheres: &[Sphere]) -> Result<(), BuildError> {
        refit_shapes(self, spheres)
    }
}

impl Bvh<CapsuleItem> {
    /// Moves every capsule and refits the boxes.
    ///
    /// # Errors
    /// [`BuildError::RefitMismatch`] for a different count,
    /// [`BuildError::InvalidPrimitive`] for a bad capsule; nothing changes.
    pub fn refit_capsules(&mut self, capsules: &[Capsule]) -> Result<(), BuildError> {
        refit_shapes(self, capsules)
    }
}

/// Checks the new shapes, then moves every item and refits the boxes.
fn refit_shapes<P: ShapeItem>(bvh: &mut Bvh<P>, shapes: &[P::Shape]) -> Result<(), BuildError> {
    if shapes.len() != bvh.prim_count as usize {
        return Err(BuildError::RefitMismatch);
    }
    if let Some(index) = shapes.iter().position(|s| !P::shape_is_valid(s)) {
        return Err(BuildError::InvalidPrimitive { index });
    }
    bvh.refit_with(|items| {
        for it in items {
            it.set_shape(shapes[it.prim() as usize]);
        }
        Ok(())
    })
}
