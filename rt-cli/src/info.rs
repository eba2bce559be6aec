//! `rt info`: what a volume or mesh file holds.

use std::path::{Path, PathBuf};

use anyhow::Context;
use rt_photo::{
    Cell, Medium, MeshTrace, Survey,
    units::{index, si, sig3},
};
use rt_surface::io::{MeshData, read_mesh};
use rt_volume::{
    GridSamples, Interp,
    glam::DVec3,
    io::{is_unstructured, read_grid_samples, read_unstructured},
};

use crate::optics::{Axis, Samples};

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
        Some("vtk") => match read_grid_samples(&a.file) {
            Ok(g) => volume(a, g)?,
            Err(grid_error) => match read_mesh(&a.file) {
                Ok(m) => mesh(&a.file, &m),
                Err(_) => return Err(grid_error.into()),
            },
        },
        _ => volume(a, read_grid_samples(&a.file)?)?,
    };
    print!("{text}");
    Ok(())
}

/// `lo … hi` of the finite values (three significant digits, or as an
/// index with `near_one`), their mean, and how many are not finite.
fn range(values: impl Iterator<Item = f64>, near_one: bool) -> String {
    let (mut lo, mut hi, mut sum, mut n, mut bad) = (f64::MAX, f64::MIN, 0.0, 0usize, 0usize);
    for v in values {
        if v.is_finite() {
            (lo, hi, sum, n) = (lo.min(v), hi.max(v), sum + v, n + 1);
        } else {
            bad += 1;
        }
    }
    if n == 0 {
        return format!("no finite values ({bad} NaN or infinite)");
    }
    let mean = sum / n as f64;
    let show = |x: f64| if near_one { index(x) } else { sig3(x) };
    let others = if bad > 0 { format!(", {bad} NaN or infinite") } else { String::new() };
    format!("{} … {} (mean {}{others})", show(lo), show(hi), show(mean))
}

/// A point or vector in metres, three significant digits a component.
fn metres(v: DVec3) -> String {
    format!("({}, {}, {}) m", sig3(v.x), sig3(v.y), sig3(v.z))
}

fn volume(a: &Args, samples: GridSamples) -> anyhow::Result<String> {
    let [nx, ny, nz] = samples.dims;
    let blanks = samples.non_finite();
    let mut text = format!(
        "{}: volume of {nx}×{ny}×{nz} samples, cell-centred\n\
         spacing {} × {} × {}, first sample at {}\n\
         values {}\n",
        a.file.display(),
        si(samples.spacing.x, "m"),
        si(samples.spacing.y, "m"),
        si(samples.spacing.z, "m"),
        metres(samples.origin),
        range(samples.data.iter().map(|&v| f64::from(v)), false),
    );
    // Blanked samples count above; the survey sees them as the median of
    // the others (a uniform medium there).
    let fill = median(&samples.data);
    let (g, _) = samples.into_grid_filling(fill)?;
    let b = g.bounds();
    text += &format!("bounds {} … {}\n", metres(b.min), metres(b.max));
    if blanks > 0 {
        text += &format!(
            "{blanks} samples are NaN or infinite: the index and the survey below take them as the median value, {}\n",
            sig3(f64::from(fill))
        );
    }
    let v = Medium::from_grid(g, a.samples.into(), true, Interp::Trilinear)
        .context("preparing the deflection survey")?;
    if let Medium::Grid(g) = &v {
        let index = g.field().grid().data().iter().map(|&n| f64::from(n));
        text += &format!("index {}\n", range(index, true));
    }
    text += &survey_line(a, &v)?;
    Ok(text)
}

/// The median of the finite values (1 if there are none).
fn median(data: &[f32]) -> f32 {
    let mut finite: Vec<f32> = data.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return 1.0;
    }
    let mid = finite.len() / 2;
    *finite.select_nth_unstable_by(mid, f32::total_cmp).1
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
    let coord = |k: usize| range(data.points.iter().map(move |p| p[k]), false);
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
        range(data.values.iter().copied(), false),
    );
    let (points, values) = (data.points, data.values);
    let v = Medium::from_mesh(
        points,
        &data.cells,
        values,
        a.samples.into(),
        true,
        &data.array,
        MeshTrace::Exact,
    )
    .context("preparing the deflection survey")?;
    let m = v.mesh().context("a mesh read as a grid")?;
    text += &format!(
        "split into {} tetrahedra, {} boundary faces\nindex {}\n",
        m.tetrahedra().len(),
        m.boundary_faces(),
        range(m.index().iter().copied(), true),
    );
    text += &survey_line(a, &v)?;
    Ok(text)
}

/// The survey's line of `rt info`.
fn survey_line(a: &Args, medium: &Medium) -> anyhow::Result<String> {
    let survey = Survey::through(medium, a.axis.into(), Survey::WIDTH)?;
    let rad = |x: f64| if x == 0.0 { "0 rad".to_string() } else { si(x, "rad") };
    Ok(format!(
        "deflection along {} (one photon per pixel of a {}-wide survey): |ε| median {}, 99th percentile {}, max {}\n",
        format!("{:?}", a.axis).to_lowercase(),
        survey.width,
        rad(survey.magnitude(0.5)),
        rad(survey.magnitude(0.99)),
        rad(survey.magnitude(1.0)),
    ))
}

fn mesh(path: &Path, m: &MeshData) -> String {
    let coord = |k: usize| range(m.positions.iter().map(move |p| f64::from(p[k])), false);
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
        text += &format!("scalar {name}: {}\n", range(values.iter().map(|&v| f64::from(v)), false));
    }
    text
}
