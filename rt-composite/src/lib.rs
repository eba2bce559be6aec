//! # rt-composite
//!
//! Sort-last compositing for the `rt` crates: when each rank (process or
//! thread) renders a share of the data, their frames — premultiplied RGBA
//! plus depth, as [`rt_core::Frame`] holds them — are merged into one
//! image, by depth or in a visibility order with `over`. This is what
//! IceT does for ParaView and VisIt.
//!
//! - Operators ([`Fragment`]: [`rt_core::Pixel`] in `f32`, [`Pixel8`] with
//!   8-bit colour): z-compositing keeps the nearer fragment, ties to the
//!   lower rank, so it is associative and commutative over (pixel, rank)
//!   pairs; `over` is associative up to rounding. The background
//!   (transparent black at `+∞`) is an exact identity of both.
//! - Sparse images ([`SparseImage`]): active-pixel run-length encoding;
//!   compositing walks the runs, so background pixels are never blended
//!   or sent.
//! - Schedules ([`composite`]): direct send, binary swap (with folding for
//!   rank counts that are not powers of two) and radix-k, over any
//!   [`Communicator`] — [`ThreadComm`] in process (feature `std`) — then a
//!   gather to rank 0. The result equals [`serial_fold`] bit for bit, for
//!   any rank count and image size; a failure on one rank is an `Err` on
//!   every rank.
//! - Rays across ranks ([`resolve_occlusion`]): shadow and
//!   ambient-occlusion rays against geometry split between ranks by
//!   space, each ray sent to the ranks whose regions it crosses, in
//!   crossing order, until one blocks it; answers are bits. Its transport,
//!   [`exchange::rounds`], moves batches of any work (occlusion queries,
//!   photons handed between bricks) in rounds of all-to-all messages and
//!   detects termination from flags the messages carry, without a barrier
//!   per item; a rank that fails or stops answering is an `Err` on every
//!   rank within the timeout.
//!
//! ```
//! use core::time::Duration;
//! use rt_composite::{Operator, Schedule, ThreadComm, composite, serial_fold};
//! use rt_core::Pixel;
//!
//! // Three ranks, each drew one pixel of a 4×1 image at its own depth.
//! let images: Vec<Vec<Pixel>> = (0..3)
//!     .map(|r| {
//!         let mut img = vec![Pixel::BACKGROUND; 4];
//!         img[r] = Pixel { color: [1.0; 4], depth: r as f32 };
//!         img[3] = Pixel { color: [0.5; 4], depth: 10.0 - r as f32 };
//!         img
//!     })
//!     .collect();
//! let comms = ThreadComm::group(3, Duration::from_secs(5));
//! let results: Vec<_> = std::thread::scope(|s| {
//!     let handles: Vec<_> = comms
//!         .into_iter()
//!         .zip(&images)
//!         .map(|(c, img)| s.spawn(move || composite(&c, img, 4, 1, Schedule::BinarySwap, &Operator::Depth)))
//!         .collect();
//!     handles.into_iter().map(|h| h.join().unwrap().unwrap()).collect()
//! });
//! let refs: Vec<&[Pixel]> = images.iter().map(Vec::as_slice).collect();
//! let expected = serial_fold(&refs, &Operator::Depth).unwrap();
//! assert_eq!(results[0].0.as_deref(), Some(&expected[..]));
//! assert_eq!(expected[3].depth, 8.0); // the nearest of 10, 9, 8
//! ```
#![no_std]

extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod comm;
pub mod exchange;
mod fragment;
mod occlusion;
mod schedule;
mod sparse;

#[cfg(feature = "mpi")]
pub use comm::MpiComm;
#[cfg(feature = "std")]
pub use comm::ThreadComm;
pub use comm::{CommError, Communicator};
pub use fragment::{Fragment, Pixel8, over, z_composite};
/// The `mpi` crate (rsmpi) this crate's [`MpiComm`] is built on, so that
/// callers initialise MPI with the same version.
#[cfg(feature = "mpi")]
pub use mpi;
pub use occlusion::{OcclusionError, OcclusionStats, RAY_BYTES, resolve_occlusion};
pub use schedule::{
    CompositeError, MessageProblem, Operator, Schedule, Stats, composite, serial_fold,
};
pub use sparse::{DecodeError, SparseImage};

/// The crate README's example, compiled and run as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
