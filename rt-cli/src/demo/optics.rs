//! Synthetic schlieren, shadowgraph, interferometry and colour schlieren
//! of the built-in blast wave, each exactly as `rt schlieren` renders a
//! user's file (fast path, automatic exposure).

use std::path::Path;

use anyhow::Context;
use rt_volume::io;

use rt_photo::{Cell, Medium, MeshTrace, Samples};
use rt_volume::{Interp, glam::DVec3};

use crate::{bos, focusing, schlieren, vtu};

const RAW: &[u8] = include_bytes!("../../data/blast_sedov_64.raw");
const JSON: &str = include_str!("../../data/blast_sedov_64.json");

/// The built-in blast wave's density, as index by Gladstone–Dale, with the
/// C¹ Catmull–Rom interpolant (on the fast path: the octree bounds it).
///
/// # Errors
/// None in practice (the data are built in and valid).
pub fn blast_wave() -> anyhow::Result<Medium> {
    blast_wave_with(Interp::CatmullRom)
}

/// [`blast_wave`] with the interpolant `interp`.
///
/// # Errors
/// None in practice (the data are built in and valid).
pub fn blast_wave_with(interp: Interp) -> anyhow::Result<Medium> {
    let header: serde_json::Value = serde_json::from_str(JSON).context("built-in JSON header")?;
    let grid = io::parse_raw_json(&header, RAW).context("built-in blast wave")?;
    Ok(Medium::from_grid(grid, Samples::AIR, false, interp)?)
}

/// Writes the built-in blast wave into `dir` as raw + JSON (for tools
/// that read a file a brick at a time); returns the JSON's path.
///
/// # Errors
/// `dir` cannot be created or written.
pub fn write_blast_wave(dir: &Path) -> anyhow::Result<std::path::PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| dir.display().to_string())?;
    let json = dir.join("blast_sedov_64.json");
    std::fs::write(&json, JSON).with_context(|| json.display().to_string())?;
    let raw = dir.join("blast_sedov_64.raw");
    std::fs::write(&raw, RAW).with_context(|| raw.display().to_string())?;
    Ok(json)
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
    // The blast wave as an unstructured mesh: written as `blast.vtu` (for
    // the user to try `rt schlieren out/blast.vtu` and ParaView on), read
    // back, and rendered exactly as `rt schlieren` renders a user's mesh.
    let vtu = out.join("blast.vtu");
    let (points, cells, density) = blast_mesh()?;
    vtu::write_vtu(&vtu, &points, &cells, "density", &density)?;
    let options = rt_volume::MediumOptions { mesh: MeshTrace::Smooth, ..Default::default() };
    let mesh = Medium::open(&vtu, &options)?;
    let args = ["--cutoff", "knife", "--size", "256", "--photons", "4", "--mesh", "smooth"];
    let mut a = schlieren::Args::from_args(&vtu, args)?;
    a.out = out.join("schlieren-mesh.png");
    schlieren::render(&mesh, &a).context("schlieren-mesh.png")?;
    Ok(())
}

/// The built-in blast wave's density coarsened 2 × 2 × 2 — each point the
/// mean of a block of 8 samples, at the block's centre — as the points and
/// hexahedra of an unstructured mesh (32³ points, 31³ hexahedra). The
/// blocks' centres lie symmetrically about the blast's centre, as the
/// samples do (every second sample would not: it sits a quarter of a
/// mesh cell off, and a knife edge shows it as a lopsided shock).
fn blast_mesh() -> anyhow::Result<(Vec<DVec3>, Vec<Cell>, Vec<f64>)> {
    let header: serde_json::Value = serde_json::from_str(JSON).context("built-in JSON header")?;
    let grid = io::parse_raw_json(&header, RAW).context("built-in blast wave")?;
    let [nx, ny, nz] = grid.dims().map(|d| d / 2);
    let (o, h) = (grid.origin(), grid.spacing());
    let [gx, gy, _] = grid.dims();
    let mut points = Vec::with_capacity(nx * ny * nz);
    let mut density = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let (a, b, c) = (2 * i, 2 * j, 2 * k);
                points.push(o + h * DVec3::new(a as f64 + 0.5, b as f64 + 0.5, c as f64 + 0.5));
                let mut sum = 0.0;
                for (da, db, dc) in (0..8).map(|q| (q & 1, (q >> 1) & 1, q >> 2)) {
                    sum += f64::from(grid.data()[a + da + gx * (b + db + gy * (c + dc))]);
                }
                density.push(sum / 8.0);
            }
        }
    }
    let cells = Cell::lattice_hexahedra([nx, ny, nz]);
    Ok((points, cells, density))
}
