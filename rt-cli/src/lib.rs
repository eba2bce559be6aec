//! # rt-cli
//!
//! The `rt` command-line tool of the rt crates (install with
//! `cargo install --path rt-cli`):
//!
//! - `rt demo [DIR]`: the main job — a ray-traced surface scene and
//!   synthetic schlieren, shadowgraph, interferometry and colour schlieren
//!   of a built-in CFD blast wave, as PNGs;
//! - `rt schlieren FILE`: the optical bench on your own volume (NRRD, raw +
//!   JSON, VTK image data), on the fast path (octree skipping and beam
//!   masks) by default;
//! - `rt bos FILE`: background-oriented schlieren of your volume: the
//!   reference and flow images of a dotted background through a thin-lens
//!   camera and sensor, and the true displacement;
//! - `rt focusing FILE`: focusing schlieren of your volume: a
//!   lens-and-grid system focused on a plane in the flow;
//! - `rt view MESH`: a ray-traced picture of a mesh (OBJ, PLY, VTK)
//!   coloured by one of its scalars;
//! - `rt serve FILE`: the schlieren bench in the browser: move the knife,
//!   paint a filter in the focal plane, watch the image refine;
//! - `rt info FILE`: what a volume or mesh holds;
//! - `rt distributed`: rendering across ranks (threads, or MPI processes
//!   with feature `mpi`), checked bit for bit: a terrain with shadows and
//!   AO answered across ranks, or a volume's photons handed between
//!   bricks.
//!
//! Errors are one line (`rt: error: …`) with a non-zero exit; `--help` on
//! every subcommand gives each option with its unit and default.
//!
//! The library half holds the commands (each a clap `Args` struct and a
//! `run` function), so they can be driven and tested without a process.
//! They map their options onto the libraries' set-ups (`rt_photo`'s
//! `SchlierenSetup`, `BosSetup`, `FocusingSetup` over an
//! `rt_volume::Medium`) and write what comes back through `rt-tools`.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

pub mod bos;
pub mod demo;
pub mod distributed;
pub mod focusing;
pub mod info;
pub mod optics;
mod parse;
mod progress;
pub mod schlieren;
pub mod serve;
pub mod view;

// What the commands write files with, shared with the report.
use rt_tools::{figure, image, output};

use clap::{Parser, Subcommand};

/// Ray tracing for scientific visualization: synthetic schlieren of CFD
/// volumes, ray-traced meshes, sort-last compositing.
#[derive(Debug, Parser)]
#[command(name = "rt", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Render the built-in scenes (surface, schlieren, shadowgraph,
    /// interferogram, colour schlieren) into a folder.
    Demo(demo::Args),
    /// Synthetic schlieren, shadowgraph or interferogram of a volume file.
    Schlieren(schlieren::Args),
    /// Background-oriented schlieren of a volume file: the reference and
    /// flow images of a dotted background and the true displacement.
    Bos(bos::Args),
    /// Focusing schlieren of a volume file: a lens-and-grid system focused
    /// on a plane in the flow.
    Focusing(focusing::Args),
    /// Ray-trace a mesh file coloured by one of its scalars.
    View(view::Args),
    /// Describe a volume or mesh file: size, geometry, value ranges.
    Info(info::Args),
    /// Render data split across ranks, checked against one process bit
    /// for bit: a terrain (shadow and AO rays answered by every rank) or
    /// a volume (photons handed between bricks).
    Distributed(distributed::Args),
    /// The schlieren bench in the browser: a local page where you move
    /// the knife, paint a filter in the focal plane and watch the image
    /// refine pass by pass.
    Serve(serve::Args),
}

/// Runs one command.
///
/// # Errors
/// Whatever the command met, with the context of what it was doing.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Demo(a) => demo::run(&a),
        Command::Schlieren(a) => schlieren::run(&a),
        Command::Bos(a) => bos::run(&a),
        Command::Focusing(a) => focusing::run(&a),
        Command::View(a) => view::run(&a),
        Command::Info(a) => info::run(&a),
        Command::Distributed(a) => distributed::run(&a),
        Command::Serve(a) => serve::run(&a),
    }
}

/// An error and its causes on one line: each cause's first line, skipping
/// a cause whose text the line already holds (errors that print their
/// source's message and also return it from `source()`).
#[must_use]
pub fn one_line(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        let first = text.lines().next().unwrap_or_default().trim();
        if first.is_empty() || out.contains(first) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(first);
    }
    out
}
