//! Shared pieces of the benchmarks, the report and the demo: deterministic
//! test scenes, ray sets and the report's plots.
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

pub mod plot;
pub mod scenes;
pub mod watertight;
