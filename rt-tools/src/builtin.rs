//! The built-in blast wave: the density of a real 3-D PyClaw Euler
//! solution, 64³ (`data/`, embedded), as a medium, as the points and
//! cells of a mesh, or written out as raw + JSON files.

use std::path::Path;

use anyhow::Context;
use rt_volume::io;

use rt_photo::{Cell, Medium, Samples};
use rt_volume::{Interp, glam::DVec3};

const RAW: &[u8] = include_bytes!("../data/blast_sedov_64.raw");
const JSON: &str = include_str!("../data/blast_sedov_64.json");

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

/// The built-in blast wave's density coarsened 2 × 2 × 2 — each point the
/// mean of a block of 8 samples, at the block's centre — as the points and
/// hexahedra of an unstructured mesh (32³ points, 31³ hexahedra). The
/// blocks' centres lie symmetrically about the blast's centre, as the
/// samples do (every second sample would not: it sits a quarter of a
/// mesh cell off, and a knife edge shows it as a lopsided shock).
pub fn blast_mesh() -> anyhow::Result<(Vec<DVec3>, Vec<Cell>, Vec<f64>)> {
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
