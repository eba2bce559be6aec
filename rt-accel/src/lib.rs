//! # rt-accel
//!
//! An 8-wide bounding volume hierarchy for the `rt` crates. Trees are built
//! by a binned SAH builder of our own (the default) or with
//! [obvhs](https://crates.io/crates/obvhs)'s PLOC presets (feature
//! `obvhs`), then converted to a layout of our own: plain `bytemuck::Pod`
//! nodes holding eight child boxes in structure-of-arrays form, tested four
//! per SSE pass, and leaves of triangle packets tested four at a time with
//! the watertight algorithm. The layout can be written to bytes, loaded
//! elsewhere (checked: malformed bytes are an `Err`) and traversed with no
//! std and no allocation.
//!
//! Queries: [`BvhRef::closest_hit`] (ties in `t` go to the lower primitive
//! index, so the answer does not depend on traversal order) and
//! [`BvhRef::occluded`] (stops at the first hit). Both implement
//! [`rt_core::SceneQuery`]. Moving geometry is handled by refitting
//! ([`Bvh::refit_triangles`]) without a rebuild.
//!
//! ## Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | std float functions; implies `alloc` |
//! | `alloc` | via `std` | owned [`Bvh`], [`Scene`], [`Instances`], [`TriangleMesh`], [`AlignedBytes`], copying loader, refit |
//! | `obvhs` | yes | building ([`build_triangles`], [`build_spheres`], [`build_capsules`]); needs std |
//! | `libm` | no | float functions from `libm` for `no_std` |
//!
//! ## Example
//! ```
//! use rt_accel::{BuildParams, build_triangles};
//! use rt_core::{Ray, glam::Vec3};
//!
//! let positions = [Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
//! let bvh = build_triangles(&positions, &[[0, 1, 2]], &BuildParams::medium()).unwrap();
//! let hit = bvh.closest_hit(&Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::NEG_Z)).unwrap();
//! assert_eq!((hit.t, hit.prim), (3.0, 0));
//! // Round trip through bytes: copied into a new BVH, or viewed in place
//! // (zero-copy needs aligned bytes, which `to_aligned_bytes` gives).
//! let bytes = bvh.to_bytes();
//! let loaded = rt_accel::Bvh::<rt_accel::TriPacket>::from_bytes(&bytes).unwrap();
//! assert_eq!(loaded, bvh);
//! let aligned = bvh.to_aligned_bytes();
//! let view = rt_accel::BvhRef::<rt_accel::TriPacket>::from_bytes(&aligned).unwrap();
//! assert_eq!(view.closest_hit(&Ray::new(Vec3::new(0.0, 0.0, 3.0), Vec3::NEG_Z)), Some(hit));
//! ```
#![no_std]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod construct;
mod error;
mod layout;
mod primitives;
mod traverse;

// The folders group the concepts; the modules keep their crate-level
// paths (`crate::node`, `crate::sah`, …).
#[cfg(feature = "obvhs")]
use construct::{build, sah};
#[cfg(feature = "alloc")]
use layout::{aligned, bvh, check, pages};
use layout::{bytes, node};
#[cfg(feature = "alloc")]
use primitives::{instance, mesh, scene};
use primitives::{prim, tri_packet};
use traverse::{isa, packet, ray_ctx, simd, stream};

#[cfg(feature = "alloc")]
pub use aligned::{AlignedBytes, BYTES_ALIGN};
#[cfg(feature = "obvhs")]
pub use build::{BuildParams, BuildQuality, build_capsules, build_spheres, build_triangles};
#[cfg(feature = "alloc")]
pub use bvh::Bvh;
pub use bytes::{Header, MAGIC, VERSION, validate};
pub use error::{BuildError, LoadError};
#[cfg(feature = "alloc")]
pub use instance::{InstanceError, Instances, Object};
pub use isa::{Isa, UnsupportedIsa};
#[cfg(feature = "alloc")]
pub use mesh::TriangleMesh;
pub use node::{ChildRef, GROUPS, MAX_ITEMS, MAX_LEAF_ITEMS, MAX_NODES, NODE_BYTES, Node, WIDTH};
pub use packet::PACKET;
pub use prim::{BestHit, CapsuleItem, Primitive, SphereItem};
pub use ray_ctx::RayCtx;
#[cfg(feature = "alloc")]
pub use scene::Scene;
pub use stream::{GROUP, STREAM};
pub use traverse::{BvhRef, MAX_DEPTH, STACK_SIZE, TraversalStack, TraversalStats};
pub use tri_packet::TriPacket;

/// The crate README's example, compiled and run as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
