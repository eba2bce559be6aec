//! `rt info`: what a volume or mesh file holds.

use std::path::{Path, PathBuf};

use anyhow::Context;
use rt_photo::Cell;
use rt_photo::{Cutoff, Mode};
use rt_surface::io::{MeshData, read_mesh};
use rt_volume::{
    Grid,
    io::{is_unstructured, read_grid, read_unstructured},
};

use crate::optics::{Axis, Interpolation, MeshTrace, MeshVolume, Samples, Source, Survey, Volume};

/// `rt info FILE`: options.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A volume (.nrrd, .nhdr, .json, .raw, .vtk, .vti), an unstructured
    /// volume mesh (.vtu, .vtk) or a surface mesh (.obj, .ply, .vtk, .vtp).
    pub file: PathBuf,
    /// What the samples are.
    #[command(flatten)]
    pub samples: Samples,
    /// For volumes: the beam direction of the deflection survey.
    #[arg(long, value_enum, default_value_t = Axis::Z)]
    pub axis: Axis,
    /// For unstructured meshes: the point- or cell-data array to read
    /// (default: the first scalar point array, else the first scalar cell
    /// array, averaged to the points).
    #[arg(long)]
    pub array: Option<String>,
}

/// Runs `rt info`.
///
/// # Errors
/// A file that is neither a readable volume nor a readable mesh.
pub fn run(a: &Args) -> anyhow::Result<()> {
    let ext = a.file.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if is_unstructured(&a.file) {
        print!("{}", unstructured(a)?);
        return Ok(());
    }
    let text = match ext.as_deref() {
        Some("obj" | "ply" | "vtp") => mesh(&a.file, &read_mesh(&a.file)?),
        // Legacy VTK holds either: try image data, then polydata.
        Some("vtk") => match read_grid(&a.file) {
            Ok(g) => volume(a, &g)?,
            Err(grid_error) => match read_mesh(&a.file) {
                Ok(m) => mesh(&a.file, &m),
                Err(_) => return Err(grid_error.into()),
            },
        },
        _ => volume(a, &read_grid(&a.file)?)?,
    };
    print!("{text}");
    Ok(())
}

/// `lo … hi` of the finite values, with the count of others.
fn range(values: impl Iterator<Item = f64>) -> String {
    let (mut lo, mut hi, mut sum, mut n, mut bad) = (f64::MAX, f64::MIN, 0.0, 0usize, 0usize);
    for v in values {
        if v.is_finite() {
            (lo, hi, sum, n) = (lo.min(v), hi.max(v), sum + v, n + 1);
        } else {
            bad += 1;
        }
    }
    if n == 0 {
        return format!("no finite values ({bad} others)");
    }
    let mean = sum / n as f64;
    let others = if bad > 0 { format!(", {bad} not finite") } else { String::new() };
    format!("{lo} … {hi} (mean {mean:.6}{others})")
}

fn volume(a: &Args, g: &Grid) -> anyhow::Result<String> {
    let [nx, ny, nz] = g.dims();
    let (o, s, b) = (g.origin(), g.spacing(), g.bounds());
    let mut text = format!(
        "{}: volume of {nx}×{ny}×{nz} samples, cell-centred\n\
         spacing {} × {} × {}, first sample at ({}, {}, {})\n\
         bounds ({}, {}, {}) … ({}, {}, {})\n\
         values {}\n",
        a.file.display(),
        s.x,
        s.y,
        s.z,
        o.x,
        o.y,
        o.z,
        b.min.x,
        b.min.y,
        b.min.z,
        b.max.x,
        b.max.y,
        b.max.z,
        range(g.data().iter().map(|&v| f64::from(v))),
    );
    let v = Volume::new(g.clone(), a.samples.quantity, a.samples.k, true, Interpolation::Linear)
        .context("preparing the deflection survey")?;
    text += &format!("index {}\n", range(v.field.grid().data().iter().map(|&n| f64::from(n))));
    let bench = v.bench(a.axis, Mode::Schlieren(Cutoff::None), 0.0);
    text += &survey_line(a, &v.survey(&bench)?);
    Ok(text)
}

/// An unstructured grid: its cells by kind, the tetrahedra they split
/// into, the boundary, the array, and the deflection survey.
fn unstructured(a: &Args) -> anyhow::Result<String> {
    let data = read_unstructured(&a.file, a.array.as_deref())?;
    let mut kinds = [0usize; 4];
    for c in &data.cells {
        kinds[match c {
            Cell::Tetra(_) => 0,
            Cell::Pyramid(_) => 1,
            Cell::Wedge(_) => 2,
            Cell::Hexahedron(_) => 3,
        }] += 1;
    }
    let coord = |k: usize| range(data.points.iter().map(move |p| p[k]));
    let mut text = format!(
        "{}: unstructured mesh of {} points, {} cells ({} tetrahedra, {} pyramids, {} wedges, {} hexahedra; {} lower-dimensional cells skipped)\n\
         x {}\ny {}\nz {}\n\
         array {} ({} data{}): {}\n",
        a.file.display(),
        data.points.len(),
        data.cells.len(),
        kinds[0],
        kinds[1],
        kinds[2],
        kinds[3],
        data.skipped_cells,
        coord(0),
        coord(1),
        coord(2),
        data.array,
        if data.from_cells { "cell" } else { "point" },
        if data.from_cells { ", averaged to the points" } else { "" },
        range(data.values.iter().copied()),
    );
    let v = MeshVolume::new(data, a.samples.quantity, a.samples.k, true, MeshTrace::Exact)
        .context("preparing the deflection survey")?;
    let m = v.mesh();
    text += &format!(
        "split into {} tetrahedra, {} boundary faces\nindex {}\n",
        m.tetrahedra().len(),
        m.boundary_faces(),
        range(m.index().iter().copied()),
    );
    let bench = v.bench(a.axis, Mode::Schlieren(Cutoff::None), 0.0);
    text += &survey_line(a, &v.survey(&bench)?);
    Ok(text)
}

/// The survey's line of `rt info`.
fn survey_line(a: &Args, survey: &Survey) -> String {
    format!(
        "deflection along {} (one photon per pixel of a {}-wide survey): |ε| median {:.3e}, 99th percentile {:.3e}, max {:.3e} rad\n",
        format!("{:?}", a.axis).to_lowercase(),
        survey.width,
        survey.magnitude(0.5),
        survey.magnitude(0.99),
        survey.magnitude(1.0),
    )
}

fn mesh(path: &Path, m: &MeshData) -> String {
    let coord = |k: usize| range(m.positions.iter().map(move |p| f64::from(p[k])));
    let mut text = format!(
        "{}: mesh of {} vertices, {} triangles\nx {}\ny {}\nz {}\nnormals: {}\n",
        path.display(),
        m.positions.len(),
        m.indices.len(),
        coord(0),
        coord(1),
        coord(2),
        if m.normals.is_some() { "one per vertex" } else { "none" },
    );
    if m.scalars.is_empty() {
        text += "scalars: none\n";
    }
    for (name, values) in &m.scalars {
        text += &format!("scalar {name}: {}\n", range(values.iter().map(|&v| f64::from(v))));
    }
    text
}
