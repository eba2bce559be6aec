//! Unstructured meshes written as VTK XML (`.vtu`, ASCII): what `rt demo`
//! hands its user to try `rt schlieren FILE.vtu` on, readable by ParaView
//! and by `rt_volume::io::read_unstructured`.

use std::{fmt::Write as _, path::Path};

use anyhow::{Context, bail};
use rt_photo::Cell;
use rt_volume::glam::DVec3;

/// Writes `points`, `cells` and one scalar per point (`name`, `values`) to
/// `path`. Numbers are written in Rust's shortest round-trip form, so a
/// reader gets back the same `f64`s.
///
/// # Errors
/// A value count that does not match the points; an unwritable file.
pub fn write_vtu(
    path: &Path,
    points: &[DVec3],
    cells: &[Cell],
    name: &str,
    values: &[f64],
) -> anyhow::Result<()> {
    if values.len() != points.len() {
        bail!("{} values for {} points", values.len(), points.len());
    }
    if name.contains(['"', '<', '>', '&']) {
        bail!("array name {name:?} has XML markup characters");
    }
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0"?>"#);
    let _ =
        writeln!(s, r#"<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">"#);
    let _ = writeln!(s, "<UnstructuredGrid>");
    let _ =
        writeln!(s, r#"<Piece NumberOfPoints="{}" NumberOfCells="{}">"#, points.len(), cells.len());
    let _ = writeln!(s, r#"<PointData Scalars="{name}">"#);
    let _ = writeln!(s, r#"<DataArray type="Float64" Name="{name}" format="ascii">"#);
    for v in values {
        let _ = writeln!(s, "{v:?}");
    }
    let _ = writeln!(s, "</DataArray>\n</PointData>\n<Points>");
    let _ = writeln!(s, r#"<DataArray type="Float64" NumberOfComponents="3" format="ascii">"#);
    for p in points {
        let _ = writeln!(s, "{:?} {:?} {:?}", p.x, p.y, p.z);
    }
    let _ = writeln!(s, "</DataArray>\n</Points>\n<Cells>");
    let _ = writeln!(s, r#"<DataArray type="Int64" Name="connectivity" format="ascii">"#);
    for c in cells {
        let ids: Vec<String> = c.points().iter().map(u32::to_string).collect();
        let _ = writeln!(s, "{}", ids.join(" "));
    }
    let _ = writeln!(s, "</DataArray>");
    let _ = writeln!(s, r#"<DataArray type="Int64" Name="offsets" format="ascii">"#);
    let mut offset = 0usize;
    for c in cells {
        offset += c.points().len();
        let _ = writeln!(s, "{offset}");
    }
    let _ = writeln!(s, "</DataArray>");
    let _ = writeln!(s, r#"<DataArray type="UInt8" Name="types" format="ascii">"#);
    for c in cells {
        let _ = writeln!(s, "{}", c.vtk_type());
    }
    let _ = writeln!(s, "</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>");
    std::fs::write(path, s).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Written and read back: the same points, cells and values, bit for
    /// bit; a mismatched value count and a markup name are errors.
    #[test]
    fn round_trip_through_the_reader() {
        let points: Vec<DVec3> = (0..8)
            .map(|i| {
                DVec3::new(f64::from(i & 1), f64::from((i >> 1) & 1), f64::from(i >> 2)) * 0.1
                    + 1e-17
            })
            .chain([DVec3::new(0.05, 0.05, 0.3), DVec3::new(1.0 / 3.0, 0.0, 0.2)])
            .collect();
        let cells = [
            Cell::Hexahedron([0, 1, 3, 2, 4, 5, 7, 6]),
            Cell::Pyramid([4, 5, 7, 6, 8]),
            Cell::Tetra([1, 3, 5, 9]),
        ];
        let values: Vec<f64> = (0..10).map(|i| 1.0 + f64::from(i) / 7.0).collect();
        let path = std::env::temp_dir().join(format!("rt-vtu-{}.vtu", std::process::id()));
        write_vtu(&path, &points, &cells, "density", &values).unwrap();
        let back = rt_volume::io::read_unstructured(&path, Some("density")).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(back.points, points);
        assert_eq!(back.cells, cells);
        assert_eq!(back.values, values);
        assert!(write_vtu(&path, &points, &cells, "density", &values[1..]).is_err());
        assert!(write_vtu(&path, &points, &cells, "a\"b", &values).is_err());
    }
}
