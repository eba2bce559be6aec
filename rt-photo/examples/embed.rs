//! The path a renderer engineer takes: rt as a cargo dependency, no
//! command line. Reads a volume file, sets up three instruments from the
//! data (each option left unset is chosen from a survey of the flow) and
//! writes raw float32 arrays a visualization tool can load.
//!
//! ```text
//! cargo run -p rt-photo --example embed -- VOLUME OUT_DIR
//! ```
//!
//! `VOLUME`: NRRD, raw + JSON, VTK image data or an unstructured mesh
//! (`.vtu`), holding density in kg/m³. Writes into `OUT_DIR`:
//! `knife.f32` (intensity relative to an undisturbed beam with nothing
//! cut), `bos-reference.f32`, `bos-flow.f32`, `bos-displacement.f32`
//! (two values a pixel, in pixels, PIV's convention), `focusing.f32`
//! (I/I₀); each row-major, rows top first, and prints their sizes and the
//! set-ups chosen.

use core::error::Error;
use std::{fs, path::PathBuf};

use rt_photo::{
    BosOptions, BosSetup, FocusingOptions, FocusingSetup, Medium, SchlierenOptions, SchlierenSetup,
    rt_volume::MediumOptions,
};

/// `values` as little-endian float32 into `dir/name`.
fn write(
    dir: &std::path::Path,
    name: &str,
    values: impl Iterator<Item = f64>,
) -> std::io::Result<()> {
    let bytes: Vec<u8> = values.flat_map(|v| (v as f32).to_le_bytes()).collect();
    fs::write(dir.join(name), bytes)
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args_os().skip(1).map(PathBuf::from);
    let (Some(file), Some(out)) = (args.next(), args.next()) else {
        return Err("usage: embed VOLUME OUT_DIR".into());
    };
    fs::create_dir_all(&out)?;
    // Density of air by Gladstone–Dale, Catmull–Rom between samples, a
    // mesh with recovered gradients: the defaults.
    let medium = Medium::open(&file, &MediumOptions::default())?;
    let b = medium.bounds();
    println!("{}: {:?} … {:?}, ambient index {}", file.display(), b.min, b.max, medium.ambient());

    // Knife-edge schlieren, its source image height chosen so that the
    // 99th percentile of the deflection spans 0.45 of the edge's range.
    let knife = SchlierenOptions { size: 256, photons: 4, ..SchlierenOptions::default() };
    let setup = SchlierenSetup::choose(&medium, &knife)?;
    let film = setup.render(&medium, 1, &mut |done, total| {
        if done == total {
            println!("knife edge: {total} photons traced");
        }
    })?;
    let (w, h) = setup.size;
    write(&out, "knife.f32", film.normalized_f64().into_iter().map(|p| p[0]))?;
    println!("knife.f32: {w}×{h}; {setup}");

    // A BOS pair through a laboratory rig chosen for the flow, and the
    // true displacement.
    let bos = BosSetup::choose(&medium, &BosOptions { size: 128, ..BosOptions::default() })?;
    let images = bos.render(&medium, 1)?;
    write(&out, "bos-reference.f32", images.reference.iter().copied())?;
    write(&out, "bos-flow.f32", images.flow.iter().copied())?;
    write(&out, "bos-displacement.f32", images.displacement.iter().flatten().copied())?;
    let largest = images.displacement.iter().map(|d| d[0].hypot(d[1])).fold(0.0, f64::max);
    println!(
        "bos-*.f32: {}×{}, displacement up to {largest:.3} px; {bos}",
        images.width, images.height
    );

    // Focusing schlieren focused on the volume's mid-plane.
    let options = FocusingOptions { size: 128, samples_per_axis: 3, ..FocusingOptions::default() };
    let focusing = FocusingSetup::choose(&medium, &options)?;
    let images = focusing.render(&medium, 1)?;
    write(&out, "focusing.f32", images.relative().into_iter())?;
    println!("focusing.f32: {}×{}; {focusing}", images.width, images.height);
    Ok(())
}
