//! # rt-volume
//!
//! Refractive-index fields and integrators for curved rays, the core of
//! computational schlieren, shadowgraph and interferometry: light bends
//! toward higher index along `d/ds (n dx/ds) = ∇n`.
//!
//! - [`IndexField`]: `n(x)` and `∇n(x)` in one call, constant outside its
//!   [`Bounds`]. Analytic fields for every closed-form case in the
//!   project's oracles ([`LinearIndex`], [`LinearSquared`], [`GrinRod`],
//!   [`Luneburg`], [`GaussianBump`]), [`FnField`] for a closure giving `n`
//!   and `∇n`, [`FnIndex`] for one giving `n` alone (central differences).
//! - [`trace`]: straight to the bounds, integrated inside them with
//!   [`Method::Euler`] (baseline), [`Method::Rk4`], [`Method::Adaptive`]
//!   (Dormand–Prince 5(4)) or [`Method::Symplectic`] (leapfrog), landed
//!   exactly on the surface where the ray leaves, or stopped exactly at an
//!   arc length inside the bounds ([`TraceParams::max_length`]); the last
//!   step is shortened onto the event and sees the field's own values, so
//!   every scheme keeps its order to the end. Reports the end point,
//!   direction, optical path and [`TraceStats`].
//! - Distributed tracing through a grid too large for one node: a
//!   [`Bricks`] partition gives each rank a [`BrickField`] (its box of
//!   samples plus the ghost layers [`step_reach`] sizes, interpolated in
//!   the global grid's coordinates); [`trace_begin`] and one
//!   [`trace_leg`] per brick visited, the [`PathState`] handed between
//!   ranks as f64 words, give bit for bit [`trace`]'s result (it runs the
//!   same code).
//!
//! All arithmetic is f64: the oracles are met to 1e-7 relative.
//!
//! ## Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | std float functions; implies `alloc` |
//! | `alloc` | via `std` | gridded fields ([`Grid`], [`GridField`]) and [`skip`]ping ([`Octree`], [`trace_skipping`], [`BeamMask`]) |
//! | `libm` | no | float functions from `libm` for `no_std` |
//! | `mesh` | no | unstructured meshes (`UnstructuredField`, traced exactly cell by cell; `SmoothField`, gradients recovered for an integrator); needs std |
//! | `io` | no | readers (module `io`): raw + JSON header, NRRD, VTK image data, VTK unstructured grids (implies `mesh`) |
//!
//! ## Example
//! ```
//! use rt_volume::{Bounds, LinearIndex, TraceParams, trace};
//! use glam::DVec3;
//!
//! // n = 1 + 0.2 y: a ray launched along +x bends up into a catenary.
//! let field = LinearIndex {
//!     n0: 1.0,
//!     gradient: DVec3::new(0.0, 0.2, 0.0),
//!     bounds: Bounds::new(DVec3::new(0.0, -1.0, -1.0), DVec3::new(2.0, 1.0, 1.0)),
//! };
//! let r = trace(&field, DVec3::ZERO, DVec3::X, &TraceParams::accurate()).unwrap();
//! assert!((r.position.y - 0.40536186).abs() < 1e-7);
//! ```
#![no_std]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod analytic;
#[cfg(feature = "alloc")]
mod brick;
mod field;
#[cfg(feature = "alloc")]
mod grid;
#[cfg(feature = "io")]
pub mod io;
mod math;
#[cfg(feature = "alloc")]
mod medium;
#[cfg(feature = "mesh")]
pub mod mesh;
#[cfg(feature = "alloc")]
mod partition;
mod reach;
mod refractivity;
#[cfg(feature = "alloc")]
pub mod skip;
#[cfg(feature = "alloc")]
mod stencil;
mod trace;

pub use analytic::{
    Constant, FnField, FnIndex, GaussianBump, GrinRod, LinearIndex, LinearSquared, Luneburg,
};
#[cfg(feature = "alloc")]
pub use brick::{BrickError, BrickField, GridInfo, IndexBounds};
pub use field::{Bounds, IndexField};
#[cfg(feature = "alloc")]
pub use grid::{Grid, GridError, GridField, GridSamples, Interp};
#[cfg(feature = "io")]
pub use medium::MediumOptions;
#[cfg(feature = "alloc")]
pub use medium::{GridMedium, Medium, MediumError, MeshTrace, Samples};
#[cfg(feature = "mesh")]
pub use mesh::{Cell, MeshError, SmoothField, UnstructuredField};
#[cfg(feature = "alloc")]
pub use partition::Bricks;
pub use reach::step_reach;
pub use refractivity::{GLADSTONE_DALE_AIR, Sum, air_index_edlen, gladstone_dale};
#[cfg(feature = "alloc")]
pub use skip::{
    BRICK, BeamMask, BeamWindow, MAX_BEAM_CELLS, OctNode, Octree, OctreeError, SmoothNode,
    build_octree, trace_beam, trace_skipping,
};
pub use trace::{
    Begin, Exit, Leg, Method, PathState, TraceError, TraceParams, TraceResult, TraceStats, trace,
    trace_begin, trace_leg, trace_visiting,
};

pub use glam;

/// The crate README's example, compiled and run as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
