//! Skipping what a ray does not need to integrate through a gridded
//! field: a min/max octree of the index and its gradient bound
//! ([`Octree`]), a march that crosses its smooth nodes in one straight
//! step each ([`trace_skipping`]), and beam masks that send the rays of a
//! collimated beam meeting no rough brick straight through ([`BeamMask`]).
//!
//! The deflection a skip may miss is bounded per ray and reported
//! ([`crate::TraceStats::skip_bound`]); the octree bounds the field's own
//! interpolant (trilinear or Catmull–Rom), and skipping refuses a tree
//! built for another.

mod beam;
mod march;
mod octree;

pub use beam::{BeamMask, BeamWindow, MAX_BEAM_CELLS, trace_beam};
pub use march::{build_octree, trace_skipping};
pub use octree::{BRICK, OctNode, Octree, OctreeError, SmoothNode};
