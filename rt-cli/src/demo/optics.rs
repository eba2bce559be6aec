//! Synthetic schlieren, shadowgraph, interferometry and colour schlieren
//! of the built-in blast wave, each exactly as `rt schlieren` renders a
//! user's file (fast path, automatic exposure).

use std::path::Path;

use anyhow::Context;
use rt_volume::io;

use crate::{
    bos, focusing,
    optics::{Interpolation, Volume},
    schlieren,
};

const RAW: &[u8] = include_bytes!("../../data/blast_sedov_64.raw");
const JSON: &str = include_str!("../../data/blast_sedov_64.json");

/// The built-in blast wave's density, as index by Gladstone–Dale, with the
/// C¹ Catmull–Rom interpolant (on the fast path: the octree bounds it).
///
/// # Errors
/// None in practice (the data are built in and valid).
pub fn blast_wave() -> anyhow::Result<Volume> {
    blast_wave_with(Interpolation::Cubic)
}

/// [`blast_wave`] with the interpolant `interp`.
///
/// # Errors
/// None in practice (the data are built in and valid).
pub fn blast_wave_with(interp: Interpolation) -> anyhow::Result<Volume> {
    let header: serde_json::Value = serde_json::from_str(JSON).context("built-in JSON header")?;
    let grid = io::parse_raw_json(&header, RAW).context("built-in blast wave")?;
    Volume::density(grid, interp)
}

/// Renders the four optical pictures into `out`.
pub(crate) fn render_all(out: &Path) -> anyhow::Result<()> {
    let volume = blast_wave()?;
    let jobs: [(&str, &[&str]); 4] = [
        ("schlieren-knife.png", &["--cutoff", "knife"]),
        ("shadowgraph.png", &["--cutoff", "none"]),
        // A CO₂ laser (10.6 µm): the blast's optical path excess of ~1e-4 m
        // spans a few dozen fringes instead of hundreds below the pixel
        // size at visible wavelengths.
        ("interferogram.png", &["--cutoff", "interferometry", "--fringes", "0.04"]),
        ("schlieren-color.png", &["--cutoff", "color"]),
    ];
    for (name, args) in jobs {
        let path = out.join(name);
        let mut a = schlieren::Args::from_args(Path::new("built-in"), args.iter().copied())?;
        a.out = path;
        schlieren::render(&volume, &a).with_context(|| name.to_string())?;
    }
    // Background-oriented schlieren: the pair and the true displacement,
    // exactly as `rt bos` renders a user's file.
    let mut a = bos::Args::from_args(Path::new("built-in"), ["--size", "384"])?;
    a.out = out.join("bos.png");
    bos::render(&volume, &a).context("bos.png")?;
    // Focusing schlieren focused on the blast's mid-plane, exactly as
    // `rt focusing` renders a user's file: the shock's cross-section
    // there sharp, the shell before and behind it blurred.
    let mut a = focusing::Args::from_args(Path::new("built-in"), ["--size", "384"])?;
    a.out = out.join("focusing.png");
    focusing::render(&volume, &a).context("focusing.png")?;
    Ok(())
}
