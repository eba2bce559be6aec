//! VTK polydata, legacy `.vtk` and XML `.vtp`, through `vtkio`.

use alloc::{format, string::String, vec::Vec};

use super::{
    MeshData, ReadError, ReadErrorKind,
    error::{malformed, parse_error, unsupported},
    mesh_data::{check_vertex_count, fan, strip, vec3s},
};

/// Parses legacy VTK polydata (`.vtk`, ASCII or big-endian binary).
///
/// # Errors
/// [`ReadErrorKind::Malformed`] for files `vtkio` rejects or whose cells are
/// inconsistent, [`ReadErrorKind::Unsupported`] for other data set types.
pub fn parse_vtk_legacy(bytes: &[u8]) -> Result<MeshData, ReadError> {
    let vtk = vtkio::Vtk::parse_legacy_be(bytes).map_err(|e| parse_error("VTK", e))?;
    polydata(vtk)
}

/// Parses XML VTK polydata (`.vtp`) with inline or appended, uncompressed
/// data.
///
/// # Errors
/// As [`parse_vtk_legacy`]; compressed payloads are
/// [`ReadErrorKind::Malformed`] (`vtkio` is built without its compressors).
pub fn parse_vtk_xml(bytes: &[u8]) -> Result<MeshData, ReadError> {
    let vtk = vtkio::Vtk::parse_xml(bytes).map_err(|e| parse_error("VTK XML", e))?;
    polydata(vtk)
}

fn polydata(vtk: vtkio::Vtk) -> Result<MeshData, ReadError> {
    use vtkio::model::DataSet;
    let DataSet::PolyData { pieces, .. } = vtk.data else {
        return Err(unsupported("VTK data set other than polydata"));
    };
    let mut out = MeshData::default();
    for (k, piece) in pieces.into_iter().enumerate() {
        // Pieces in other files are not followed: a reader of user data
        // should not open paths named inside it.
        let vtkio::model::Piece::Inline(piece) = piece else {
            return Err(unsupported(format!("VTK piece {k} refers to another file")));
        };
        out.append(polydata_piece(*piece)?)?;
    }
    Ok(out)
}

fn polydata_piece(piece: vtkio::model::PolyDataPiece) -> Result<MeshData, ReadError> {
    use vtkio::model::{Attribute, ElementType};
    let malformed = |m: &str| malformed(format!("VTK: {m}"));
    let flat: Vec<f32> =
        piece.points.cast_into().ok_or_else(|| malformed("point coordinates of an odd type"))?;
    let positions = vec3s(&flat).ok_or_else(|| malformed("point coordinates not in triples"))?;
    let n = positions.len();
    check_vertex_count(n)?;
    let mut indices = Vec::new();
    if let Some(polys) = piece.polys {
        cells(polys, |c| {
            if c.len() < 3 {
                return Err(malformed(&format!("a polygon of {} points", c.len())));
            }
            fan(c, &mut indices);
            Ok(())
        })?;
    }
    if let Some(strips) = piece.strips {
        cells(strips, |c| {
            strip(c, &mut indices);
            Ok(())
        })?;
    }
    let mut normals = None;
    let mut scalars = Vec::new();
    let mut take =
        |name: String, elem: Option<&ElementType>, comps: usize, data: vtkio::IOBuffer| {
            let Some(values) = data.cast_into::<f32>() else { return };
            if comps == 0 || values.len() != comps * n {
                return;
            }
            if matches!(elem, Some(ElementType::Normals)) && comps == 3 {
                normals = vec3s(&values);
            } else if comps == 1 {
                scalars.push((name, values));
            } else {
                let magnitude =
                    values.chunks_exact(comps).map(|c| c.iter().map(|x| x * x).sum::<f32>().sqrt());
                scalars.push((name, magnitude.collect()));
            }
        };
    for attribute in piece.data.point {
        match attribute {
            Attribute::DataArray(a) => {
                let comps = a.elem.num_comp() as usize;
                take(a.name, Some(&a.elem), comps, a.data);
            }
            Attribute::Field { data_array, .. } => {
                for a in data_array {
                    take(a.name, None, a.elem as usize, a.data);
                }
            }
        }
    }
    Ok(MeshData { positions, indices, normals, scalars })
}

/// Calls `f` with each cell's point indices, checking the cell layout.
fn cells(
    numbers: vtkio::model::VertexNumbers,
    mut f: impl FnMut(&[u32]) -> Result<(), ReadError>,
) -> Result<(), ReadError> {
    use vtkio::model::VertexNumbers;
    let bad = || malformed("VTK: cell list runs past its data");
    let mut cell = Vec::new();
    match numbers {
        VertexNumbers::Legacy { num_cells, vertices } => {
            let mut at = 0usize;
            for _ in 0..num_cells {
                let len = *vertices.get(at).ok_or_else(bad)? as usize;
                let ids = vertices.get(at + 1..).and_then(|v| v.get(..len)).ok_or_else(bad)?;
                f(ids)?;
                at += 1 + len;
            }
        }
        VertexNumbers::XML { connectivity, offsets } => {
            let mut start = 0usize;
            for &end in &offsets {
                let end = usize::try_from(end).map_err(|_| bad())?;
                let ids = connectivity.get(start..end).ok_or_else(bad)?;
                cell.clear();
                for &i in ids {
                    cell.push(
                        u32::try_from(i).map_err(|_| ReadError::from(ReadErrorKind::TooLarge))?,
                    );
                }
                f(&cell)?;
                start = end;
            }
        }
    }
    Ok(())
}
