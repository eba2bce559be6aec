//! Synthetic schlieren, shadowgraph, interferometry, colour, BOS and
//! focusing schlieren of the built-in blast wave, each exactly as `rt
//! schlieren`, `rt bos` and `rt focusing` render a user's file.

use std::path::Path;

use anyhow::Context;
use rt_photo::{Medium, MeshTrace};
use rt_tools::{
    builtin::{blast_mesh, blast_wave},
    vtu,
};

use crate::{bos, focusing, parse::subcommand, schlieren};

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
        let mut a: schlieren::Args = subcommand("schlieren", Path::new("built-in"), args.iter())?;
        a.out = path;
        schlieren::render(&volume, &a).with_context(|| name.to_string())?;
    }
    // Background-oriented schlieren: the pair and the true displacement,
    // exactly as `rt bos` renders a user's file.
    let mut a: bos::Args = subcommand("bos", Path::new("built-in"), ["--size", "384"])?;
    a.out = out.join("bos.png");
    bos::render(&volume, &a).context("bos.png")?;
    // Focusing schlieren focused on the blast's mid-plane, exactly as
    // `rt focusing` renders a user's file: the shock's cross-section
    // there sharp, the shell before and behind it blurred.
    let mut a: focusing::Args = subcommand("focusing", Path::new("built-in"), ["--size", "384"])?;
    a.out = out.join("focusing.png");
    focusing::render(&volume, &a).context("focusing.png")?;
    // The blast wave as an unstructured mesh: written as `blast.vtu` (for
    // the user to try `rt schlieren out/blast.vtu` and ParaView on), read
    // back, and rendered exactly as `rt schlieren` renders a user's mesh.
    let vtu = out.join("blast.vtu");
    let (points, cells, density) = blast_mesh()?;
    vtu::write_vtu(&vtu, &points, &cells, "density", &density)?;
    let options = rt_volume::MediumOptions { mesh: MeshTrace::Smooth, ..Default::default() };
    let mesh = Medium::open(&vtu, &options)?;
    let args = ["--cutoff", "knife", "--size", "256", "--photons", "4", "--mesh", "smooth"];
    let mut a: schlieren::Args = subcommand("schlieren", &vtu, args)?;
    a.out = out.join("schlieren-mesh.png");
    schlieren::render(&mesh, &a).context("schlieren-mesh.png")?;
    Ok(())
}
