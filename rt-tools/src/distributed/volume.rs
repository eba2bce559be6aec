//! Volumes across ranks: the protocol is the library's
//! (`rt_photo::distributed`, re-exported here); this adds the built-in
//! blast wave as a job.

use std::path::{Path, PathBuf};

pub use rt_photo::distributed::*;

/// Knife-edge schlieren of the built-in blast wave (64³ densities),
/// written into `dir` as raw and JSON files so that ranks can read
/// bricks of it.
///
/// # Errors
/// `dir` cannot be written.
pub fn builtin(dir: &Path, size: u32, strata: u32) -> anyhow::Result<VolumeJob> {
    Ok(VolumeJob::knife_edge(builtin_file(dir)?, size, strata))
}

/// The file the CLI renders when given none: the built-in blast wave,
/// written as raw + JSON into `dir`.
///
/// # Errors
/// `dir` cannot be written.
pub fn builtin_file(dir: &Path) -> anyhow::Result<PathBuf> {
    crate::builtin::write_blast_wave(dir)
}
