//! VTK image data (legacy `STRUCTURED_POINTS`, XML `ImageData`), through
//! `vtkio`.

use alloc::vec::Vec;
use std::path::Path;

use glam::DVec3;

use super::{
    ReadError, ReadErrorKind,
    error::{malformed, parse_error, unsupported},
    legacy_scan::check_legacy_sizes,
    xml_scan::prepare_xml,
};
use crate::{Grid, GridSamples};

/// Reads VTK image data (legacy `STRUCTURED_POINTS` or XML `ImageData`,
/// `.vtk`/`.vti`) with the `vtkio` crate: the first point-data array
/// (first component) becomes the samples, point `(0,0,0)` at `origin`
/// (taken as sample centres, the crates' cell-centred convention).
///
/// # Errors
/// [`ReadError`] naming the problem: unreadable or malformed files, other
/// data set types, compressed XML payloads, no point data.
pub fn read_vtk(path: &Path) -> Result<Grid, ReadError> {
    read_vtk_samples(path)?.into_grid().map_err(|e| ReadError::from(e).in_file(path))
}

/// [`read_vtk`]'s samples before the grid's checks (NaN kept).
///
/// # Errors
/// As [`read_vtk`].
pub(super) fn read_vtk_samples(path: &Path) -> Result<GridSamples, ReadError> {
    vtk_grid(path).map_err(|e| e.in_file(path))
}

fn vtk_grid(path: &Path) -> Result<GridSamples, ReadError> {
    use vtkio::model::{Attribute, DataSet, Extent};
    let to_read_error = |e| match e {
        vtkio::Error::IO(io) => ReadError::from(ReadErrorKind::Io(io)),
        other => parse_error("VTK", other),
    };
    let vtk = if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("vtk")) {
        // Checked first: `vtkio` reserves memory for the counts declared.
        let bytes = super::read(path)?;
        check_legacy_sizes(&bytes)?;
        vtkio::Vtk::parse_legacy_be(bytes.as_slice()).map_err(to_read_error)?
    } else {
        let bytes = prepare_xml(super::read(path)?)?;
        vtkio::Vtk::parse_xml(bytes.as_slice()).map_err(to_read_error)?
    };
    let DataSet::ImageData { extent, origin, spacing, pieces, .. } = vtk.data else {
        if matches!(vtk.data, DataSet::UnstructuredGrid { .. }) {
            return Err(unsupported("VTK unstructured grid: read it with `read_unstructured`"));
        }
        return Err(unsupported("VTK data set other than image data / structured points"));
    };
    let dims = match extent {
        Extent::Dims(d) => d.map(|v| v as usize),
        Extent::Ranges(r) => {
            let len = |x: &core::ops::RangeInclusive<i32>| {
                usize::try_from(i64::from(*x.end()) - i64::from(*x.start()) + 1).unwrap_or(0)
            };
            [len(&r[0]), len(&r[1]), len(&r[2])]
        }
    };
    let piece = pieces
        .into_iter()
        .next()
        .ok_or_else(|| malformed("VTK image data without pieces"))?
        .into_loaded_piece_data(path.parent())
        .map_err(|e| parse_error("VTK piece", e))?;
    let (data, components) = piece
        .data
        .point
        .into_iter()
        .find_map(|a| match a {
            Attribute::DataArray(d) => Some((d.data, d.elem.num_comp() as usize)),
            Attribute::Field { data_array, .. } => {
                data_array.into_iter().next().map(|f| (f.data, f.elem as usize))
            }
        })
        .ok_or_else(|| malformed("VTK image data without point data"))?;
    let values: Vec<f32> = data.cast_into::<f32>().ok_or_else(|| unsupported("VTK sample type"))?;
    let values =
        if components > 1 { values.iter().step_by(components).copied().collect() } else { values };
    let f = |a: [f32; 3]| DVec3::new(f64::from(a[0]), f64::from(a[1]), f64::from(a[2]));
    Ok(GridSamples { dims, origin: f(origin), spacing: f(spacing), data: values })
}
