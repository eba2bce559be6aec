//! Shared pieces of the benchmarks, the report and the demo: deterministic
//! test scenes, ray sets and PNG output.

pub mod image;
pub mod scenes;
