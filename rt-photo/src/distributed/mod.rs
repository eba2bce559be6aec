//! Photons across ranks (feature `distributed`): the grid is split into
//! bricks, one per rank; each rank reads only its brick (with the ghost
//! layers a step can reach) from the file, and photons are handed from brick to brick as they
//! cross. Rank 0 lands them on the film in the bench's own order, so the
//! image equals one process tracing the whole grid, bit for bit.
//!
//! The instrument is any that renders through a tracer: the schlieren
//! bench ([`rank`]), background-oriented and focusing schlieren
//! ([`bos_rank`], [`focusing_rank`], whose rig is chosen from a survey
//! traced the same way).
//!
//! 1. **Emission.** Every rank runs the instrument once with a tracer that
//!    only records what it is asked: the rays' `(origin, direction)`. A
//!    ray's identity is those six `f64`s (its pixel and stratum are a
//!    function of them). `rt_volume::trace_begin` carries each straight to
//!    the volume; the rank owning its entry point keeps it (rank 0 also
//!    keeps the ones that miss).
//! 2. **Tracing.** Each round, a rank advances up to [`BATCH`] photons
//!    through its brick (`rt_volume::trace_leg`, on all cores): a photon
//!    that steps into another rank's brick is handed over with its whole
//!    integration state (position, `T = n dx/ds`, optical path, arc
//!    length, step, stats, the last evaluation), which is all the
//!    integrator carries (the bench draws no random numbers in flight);
//!    one that leaves the volume becomes a result for rank 0. Rounds run
//!    on `rt_composite::exchange::rounds` until no rank holds a photon.
//! 3. **Film.** Rank 0 runs the instrument again with a tracer that looks
//!    each ray's result up by its identity: the landing, the cutoff and
//!    the splatting happen in the instrument's fixed order, exactly as in
//!    one process.
//!
//! Each leg computes what the whole grid's trace computes (the brick
//! interpolates with global indices, a step started in the owned box stays
//! within the loaded reach), so the result is `rt_volume::trace`'s, bit
//! for bit. A step that reaches past the loaded samples is an `Err`, never
//! a wrong image: the brick answers NaN there.
//!
//! Memory per rank: its brick, the photons it owns at entry, and per
//! round at most [`BATCH`] photons and [`BATCH`] results in messages; rank
//! 0 also holds one result per photon for the ordered reduction.
//!
//! [`rank`] runs on any `rt_composite::Communicator` (threads in one
//! process, or MPI processes); [`single`] is one process tracing the whole
//! grid, the image every rank count must equal; the messages' format is
//! in `wire.rs`, beside `rt_volume::PathState`'s and `TraceResult`'s
//! words.

mod across;
mod camera;
mod error;
mod job;
mod rank;
mod watch;
mod wire;

pub use camera::{CameraRank, bos_rank, bos_single, focusing_rank, focusing_single};
pub use error::DistributedError;
pub use job::{BrickSource, Piece, VolumeJob, VolumeOptics, VolumeRank, same, single, single_from};
pub use rank::{first_brick_box, rank, rank_from};
pub use watch::Watch;
pub use wire::{PHOTON_BYTES, RESULT_BYTES};

/// Photons a rank advances per round, and most results it sends rank 0
/// per round, by default: this bounds its message buffers (see
/// [`VolumeJob::largest_message`]).
pub const BATCH: usize = 1 << 14;

/// The most photons one distributed run traces (each rank lists their
/// 48-byte identities once while it finds its own).
pub const MAX_PHOTONS: u64 = 1 << 25;
