//! # rt-photo
//!
//! The optical bench of computational schlieren photography: a collimated
//! beam of photons is traced along curved paths through a refractive-index
//! field (`rt-volume`); each photon's deflection `ε` meets a cutoff (knife
//! edge, graded filter, pinhole / dark field, colour filter) or, for
//! interferometry, its optical path sets a phase; it lands on a film at its
//! exit point carried a distance `L` further (shadowgraph).
//!
//! Images are normalised to the background (1 = undisturbed, uncut) and
//! deterministic: the same seed gives the same image, bit for bit, at any
//! thread count (feature `parallel`).
//!
//! ## Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | float functions (required for now) |
//! | `parallel` | no | rows rendered with rayon |
#![no_std]

extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

#[cfg(not(feature = "std"))]
compile_error!("rt-photo needs feature `std` for its float functions.");

mod bench;
mod cutoff;
mod film;

pub use bench::{Bench, BenchError, Mode, Weighting};
pub use cutoff::{Cutoff, FilterImage};
pub use film::{Film, Filter, Photon};
