//! `rt-report`: run time against error, per area, as tables and CSV files
//! under `target/rt-report/`.
//!
//! ```text
//! cargo run --release -p rt-benches --bin rt-report -- traversal [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- grin [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- octree [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- schlieren [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- render [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- composite [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- all [--quick]
//! ```
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

mod composite;
#[cfg(feature = "embree3")]
mod embree3;
mod grin;
mod octree;
mod render;
mod schlieren;
mod timing;
#[cfg(feature = "tinybvh")]
mod tinybvh;
mod traversal;

use std::{path::PathBuf, process::ExitCode};

/// Where reports go: `$CARGO_TARGET_DIR/rt-report` or `target/rt-report` at
/// the workspace root.
fn out_dir() -> PathBuf {
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..").join("target"));
    target.join("rt-report")
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let areas: Vec<&str> =
        args.iter().filter(|a| !a.starts_with("--")).map(String::as_str).collect();
    let areas = if areas.is_empty() || areas == ["all"] {
        vec!["traversal", "grin", "octree", "schlieren", "render", "composite"]
    } else {
        areas
    };
    let dir = out_dir();
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    for area in areas {
        let result = match area {
            "traversal" => traversal::run(&dir, quick),
            "grin" => grin::run(&dir, quick),
            "octree" => octree::run(&dir, quick),
            "schlieren" => schlieren::run(&dir, quick),
            "render" => render::run(&dir, quick),
            "composite" => composite::run(&dir, quick),
            other => Err(format!(
                "unknown area `{other}` (known: traversal, grin, octree, schlieren, render, composite, all)"
            )),
        };
        if let Err(e) = result {
            eprintln!("rt-report {area}: {e}");
            return ExitCode::FAILURE;
        }
    }
    ExitCode::SUCCESS
}
