//! VTK unstructured grids (legacy `UNSTRUCTURED_GRID`, XML
//! `UnstructuredGrid`), through `vtkio`: points, linear volume cells and
//! one scalar per point.

use alloc::{
    format,
    string::{String, ToString},
    vec,
    vec::Vec,
};
use std::{fs::File, io::Read, path::Path};

use glam::DVec3;
use vtkio::model::{
    Attribute, CellType, DataSet, IOBuffer, Piece, UnstructuredGridPiece, VertexNumbers,
};

use super::{
    ReadError, ReadErrorKind,
    error::{malformed, parse_error, unsupported},
    legacy_scan::check_legacy_sizes,
    xml_scan::prepare_xml,
};
use crate::Cell;

/// What an unstructured-grid file holds: points, volume cells, and one
/// scalar per point.
#[derive(Clone, Debug, PartialEq)]
pub struct UnstructuredData {
    /// The points, in the file's order (several pieces one after another).
    pub points: Vec<DVec3>,
    /// The volume cells, in the file's order, by indices into
    /// [`points`](Self::points) in VTK's point order (a `VTK_VOXEL` becomes
    /// a [`Cell::Hexahedron`] with its points reordered).
    pub cells: Vec<Cell>,
    /// One value per point (of the chosen array).
    pub values: Vec<f64>,
    /// The array's name.
    pub array: String,
    /// Whether the array was cell data, averaged to points (each point: the
    /// plain mean of the volume cells that use it; a point no volume cell
    /// uses gets `0.0`, which nothing reads).
    pub from_cells: bool,
    /// Lower-dimensional cells (vertices, lines, triangles, quads, polygons)
    /// that were skipped: they hold no volume.
    pub skipped_cells: usize,
}

/// Reads a VTK unstructured grid: legacy `.vtk` (`DATASET
/// UNSTRUCTURED_GRID`, ASCII or big-endian BINARY) or XML `.vtu` (ASCII,
/// inline base64 or appended raw/base64 data, uncompressed; several pieces
/// are joined), with the `vtkio` crate.
///
/// Cells kept: `VTK_TETRA` (10), `VTK_VOXEL` (11, as a hexahedron),
/// `VTK_HEXAHEDRON` (12), `VTK_WEDGE` (13), `VTK_PYRAMID` (14). Cells of
/// dimension 0–2 (types 1–9) are skipped and counted in
/// [`UnstructuredData::skipped_cells`].
///
/// The values: with `array` `Some(name)`, the point-data array of that
/// name, else the cell-data array of that name; with `None`, the first
/// scalar point-data array, else the first scalar cell-data array. Cell
/// data is averaged to the points (see [`UnstructuredData::from_cells`]).
/// Any numeric type is read, as `f64`.
///
/// # Errors
/// [`ReadError`] naming the problem and the file:
/// - [`ReadErrorKind::UnknownFormat`]: an extension other than `.vtk`/`.vtu`;
/// - [`ReadErrorKind::Io`]: the file cannot be read;
/// - [`ReadErrorKind::Unsupported`]: another data set type, compressed XML
///   payloads, pieces in other files (`.pvtu`), other cell types (quadratic,
///   polyhedra, …: the type and the cell are named), multi-component or
///   bit arrays;
/// - [`ReadErrorKind::Malformed`]: a file `vtkio` cannot parse (truncated,
///   garbage, empty), or one declaring more values than its bytes hold, a
///   cell with the wrong number of points for its type or a point index out
///   of range, NaN or infinite coordinates or values (the index is named),
///   no volume cells, or no such array (the message lists the arrays there
///   are).
pub fn read_unstructured(path: &Path, array: Option<&str>) -> Result<UnstructuredData, ReadError> {
    unstructured(path, array).map_err(|e| e.in_file(path))
}

/// Whether `path` looks like an unstructured grid, cheaply: a `.vtu`
/// extension, or a `.vtk` file whose legacy header (in its first
/// kilobyte) says `DATASET UNSTRUCTURED_GRID`. A file that cannot be read
/// is not one.
#[must_use]
pub fn is_unstructured(path: &Path) -> bool {
    match extension(path).as_deref() {
        Some("vtu") => true,
        Some("vtk") => {
            let mut head = Vec::new();
            let read = File::open(path).and_then(|f| f.take(1024).read_to_end(&mut head));
            read.is_ok() && legacy_dataset(&head).is_some_and(|d| d == "UNSTRUCTURED_GRID")
        }
        _ => false,
    }
}

/// The word after `DATASET` in a legacy header, upper case; the version
/// and title lines (the first two) are not read.
fn legacy_dataset(head: &[u8]) -> Option<String> {
    head.split(|&b| b == b'\n').skip(2).find_map(|line| {
        let mut words = line.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty());
        if !words.next()?.eq_ignore_ascii_case(b"DATASET") {
            return None;
        }
        Some(String::from_utf8_lossy(words.next()?).to_ascii_uppercase())
    })
}

fn extension(path: &Path) -> Option<String> {
    path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase)
}

fn unstructured(path: &Path, array: Option<&str>) -> Result<UnstructuredData, ReadError> {
    let ext = extension(path);
    let legacy = match ext.as_deref() {
        Some("vtk") => true,
        Some("vtu") => false,
        _ => return Err(ReadErrorKind::UnknownFormat.into()),
    };
    // The file's bytes are let go once parsed.
    let vtk = {
        let bytes = super::read(path)?;
        if legacy {
            check_legacy_sizes(&bytes)?;
            vtkio::Vtk::parse_legacy_be(bytes.as_slice()).map_err(|e| vtk_error(e, "legacy VTK"))?
        } else {
            let bytes = prepare_xml(bytes)?;
            vtkio::Vtk::parse_xml(bytes.as_slice()).map_err(|e| vtk_error(e, "XML VTK"))?
        }
    };
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else {
        return Err(unsupported("VTK data set other than an unstructured grid"));
    };
    let pieces = pieces
        .into_iter()
        .map(|p| match p {
            Piece::Inline(p) => Ok(*p),
            _ => Err(unsupported("VTK pieces stored in other files (parallel .pvtu)")),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let first = pieces.first().ok_or_else(|| malformed("VTK unstructured grid without pieces"))?;
    let (name, from_cells) = choose_array(first, array)?;
    let mut out = UnstructuredData {
        points: Vec::new(),
        cells: Vec::new(),
        values: Vec::new(),
        array: name,
        from_cells,
        skipped_cells: 0,
    };
    let mut cells_before = 0;
    for piece in pieces {
        cells_before += append_piece(&mut out, piece, cells_before)?;
    }
    if out.cells.is_empty() {
        return Err(malformed(format!(
            "VTK unstructured grid without volume cells ({} lower-dimensional cells skipped)",
            out.skipped_cells
        )));
    }
    Ok(out)
}

/// A `vtkio` error as a [`ReadError`]; `format` names the parser.
fn vtk_error(e: vtkio::Error, format: &str) -> ReadError {
    use vtkio::xml::{Error as XmlError, ValidationError};
    match e {
        vtkio::Error::IO(io) => ReadErrorKind::Io(io).into(),
        // `vtkio`'s word for a legacy file that stops mid-way.
        vtkio::Error::Unknown => malformed(format!("{format}: the file ends early")),
        vtkio::Error::XML(XmlError::Validation(ValidationError::MissingCompressionLibrary(c))) => {
            unsupported(format!("compressed XML VTK payloads ({c:?})"))
        }
        other => parse_error(format, other),
    }
}

/// A data array of a piece: its name, components and values.
struct Array<'a> {
    name: &'a str,
    components: usize,
    data: &'a IOBuffer,
}

/// The per-element arrays of `attributes` (a legacy lookup table is not
/// one; the arrays of a legacy `FIELD` are).
fn arrays(attributes: &[Attribute]) -> Vec<Array<'_>> {
    use vtkio::model::ElementType;
    let mut out = Vec::new();
    for a in attributes {
        match a {
            Attribute::DataArray(d) if d.elem != ElementType::LookupTable => out.push(Array {
                name: &d.name,
                components: d.elem.num_comp() as usize,
                data: &d.data,
            }),
            Attribute::DataArray(_) => {}
            Attribute::Field { data_array, .. } => {
                out.extend(data_array.iter().map(|f| Array {
                    name: &f.name,
                    components: f.elem as usize,
                    data: &f.data,
                }));
            }
        }
    }
    out
}

/// The array to read (its name, and whether it is cell data), chosen in
/// the first piece.
fn choose_array(
    piece: &UnstructuredGridPiece,
    name: Option<&str>,
) -> Result<(String, bool), ReadError> {
    let point = arrays(&piece.data.point);
    let cell = arrays(&piece.data.cell);
    let found = match name {
        Some(name) => {
            let hit = |arrays: &[Array<'_>]| arrays.iter().position(|a| a.name == name);
            hit(&point).map(|i| (&point[i], false)).or_else(|| hit(&cell).map(|i| (&cell[i], true)))
        }
        None => {
            let scalar = |arrays: &[Array<'_>]| arrays.iter().position(|a| a.components == 1);
            scalar(&point)
                .map(|i| (&point[i], false))
                .or_else(|| scalar(&cell).map(|i| (&cell[i], true)))
        }
    };
    let Some((a, from_cells)) = found else {
        let what = match name {
            Some(name) => format!("no point or cell data array named `{name}`"),
            None => "no scalar (1-component) point or cell data array".to_string(),
        };
        return Err(malformed(format!("{what}; the file has {}", list(&point, &cell))));
    };
    if a.components != 1 {
        return Err(unsupported(format!(
            "array `{}` has {} components: only scalar (1-component) arrays are read",
            a.name, a.components
        )));
    }
    Ok((a.name.to_string(), from_cells))
}

/// The arrays there are, for an error message.
fn list(point: &[Array<'_>], cell: &[Array<'_>]) -> String {
    let names = |arrays: &[Array<'_>]| {
        let v: Vec<String> =
            arrays.iter().map(|a| format!("`{}` ({} components)", a.name, a.components)).collect();
        if v.is_empty() { "none".to_string() } else { v.join(", ") }
    };
    format!("point data: {}; cell data: {}", names(point), names(cell))
}

/// Appends one piece to `out` (its points, cells and values); returns its
/// number of cells, skipped ones included. `cells_before`: the cells of the
/// pieces before, for error messages.
fn append_piece(
    out: &mut UnstructuredData,
    piece: UnstructuredGridPiece,
    cells_before: usize,
) -> Result<usize, ReadError> {
    let base = out.points.len();
    // Points, checked finite.
    let coords: Vec<f64> =
        piece.points.cast_into().ok_or_else(|| unsupported("VTK point coordinates of type bit"))?;
    if !coords.len().is_multiple_of(3) {
        return Err(malformed(format!(
            "VTK points: {} coordinates, not a multiple of 3",
            coords.len()
        )));
    }
    let n = coords.len() / 3;
    if base + n > u32::MAX as usize {
        return Err(malformed(format!("{} points: more than u32 indices address", base + n)));
    }
    for (i, c) in coords.chunks_exact(3).enumerate() {
        let p = DVec3::new(c[0], c[1], c[2]);
        if !p.is_finite() {
            return Err(malformed(format!("VTK point {} is not finite: {p}", base + i)));
        }
        out.points.push(p);
    }
    // Cells: the volume ones converted, with their index in the piece.
    let types = &piece.cells.types;
    let ranges = cell_ranges(&piece.cells.cell_verts, types.len())?;
    let ids = |j: usize| -> u64 {
        match &piece.cells.cell_verts {
            VertexNumbers::Legacy { vertices, .. } => u64::from(vertices[j]),
            VertexNumbers::XML { connectivity, .. } => connectivity[j],
        }
    };
    let mut kept = Vec::new();
    for (i, (&ty, range)) in types.iter().zip(ranges).enumerate() {
        let cell = cells_before + i;
        let code = ty as u8;
        if matches!(code, 1..=9) {
            out.skipped_cells += 1;
            continue;
        }
        let wanted = match ty {
            CellType::Tetra => 4,
            CellType::Pyramid => 5,
            CellType::Wedge => 6,
            CellType::Hexahedron | CellType::Voxel => 8,
            other => {
                return Err(unsupported(format!(
                    "VTK cell type {code} ({other:?}) of cell {cell}: only tetrahedra (10), \
                     voxels (11), hexahedra (12), wedges (13) and pyramids (14) are read"
                )));
            }
        };
        if range.len() != wanted {
            return Err(malformed(format!(
                "VTK cell {cell} ({ty:?}) has {} points, not {wanted}",
                range.len()
            )));
        }
        let mut p = [0u32; 8];
        for (k, j) in range.enumerate() {
            let id = ids(j);
            p[k] = usize::try_from(id)
                .ok()
                .filter(|&id| id < n)
                .and_then(|id| u32::try_from(base + id).ok())
                .ok_or_else(|| {
                    malformed(format!(
                        "VTK cell {cell}: point index {id} out of range ({n} points)"
                    ))
                })?;
        }
        let c = match ty {
            CellType::Tetra => Cell::Tetra([p[0], p[1], p[2], p[3]]),
            CellType::Pyramid => Cell::Pyramid([p[0], p[1], p[2], p[3], p[4]]),
            CellType::Wedge => Cell::Wedge([p[0], p[1], p[2], p[3], p[4], p[5]]),
            // A voxel's points run x fastest, then y, then z: swap 2–3, 6–7.
            CellType::Voxel => Cell::Hexahedron([p[0], p[1], p[3], p[2], p[4], p[5], p[7], p[6]]),
            _ => Cell::Hexahedron(p),
        };
        out.cells.push(c);
        kept.push(i);
    }
    // Values.
    let (attributes, len) =
        if out.from_cells { (&piece.data.cell, types.len()) } else { (&piece.data.point, n) };
    let values = array_values(
        attributes,
        &out.array,
        len,
        if out.from_cells { cells_before } else { base },
    )?;
    if out.from_cells {
        let cells = &out.cells[out.cells.len() - kept.len()..];
        out.values.extend(cells_to_points(cells, &kept, &values, base, n));
    } else {
        out.values.extend(values);
    }
    Ok(types.len())
}

/// The range of point ids of each of `count` cells, checked against the
/// lists' lengths.
fn cell_ranges(
    verts: &VertexNumbers,
    count: usize,
) -> Result<Vec<core::ops::Range<usize>>, ReadError> {
    let mut ranges = Vec::new();
    match verts {
        VertexNumbers::Legacy { num_cells, vertices } => {
            if *num_cells as usize != count {
                return Err(malformed(format!(
                    "legacy VTK: CELLS gives {num_cells} cells, CELL_TYPES {count}"
                )));
            }
            // Each cell: its point count, then the points.
            let mut at = 0usize;
            for i in 0..count {
                let n = vertices.get(at).map(|&n| n as usize);
                let end = n.and_then(|n| (at + 1).checked_add(n)).filter(|&e| e <= vertices.len());
                let Some(end) = end else {
                    return Err(malformed(format!(
                        "legacy VTK: the CELLS list ends inside cell {i}"
                    )));
                };
                ranges.push(at + 1..end);
                at = end;
            }
            if at != vertices.len() {
                return Err(malformed(format!(
                    "legacy VTK: the CELLS size is {}, the cells use {at}",
                    vertices.len()
                )));
            }
        }
        VertexNumbers::XML { connectivity, offsets } => {
            if offsets.len() != count {
                return Err(malformed(format!(
                    "XML VTK: {} cell offsets, {count} cell types",
                    offsets.len()
                )));
            }
            let mut start = 0usize;
            for (i, &end) in offsets.iter().enumerate() {
                let end = usize::try_from(end)
                    .ok()
                    .filter(|&e| e >= start && e <= connectivity.len())
                    .ok_or_else(|| {
                        malformed(format!(
                            "XML VTK: offset {end} of cell {i} out of order or past the \
                             connectivity ({} ids)",
                            connectivity.len()
                        ))
                    })?;
                ranges.push(start..end);
                start = end;
            }
        }
    }
    Ok(ranges)
}

/// The values of the 1-component array `name` among `attributes`, which
/// must hold `len` of them, all finite; `first` is the index of the first
/// value in the whole file, for error messages.
fn array_values(
    attributes: &[Attribute],
    name: &str,
    len: usize,
    first: usize,
) -> Result<Vec<f64>, ReadError> {
    let arrays = arrays(attributes);
    let a = arrays
        .iter()
        .find(|a| a.name == name)
        .ok_or_else(|| malformed(format!("array `{name}` missing from a later piece")))?;
    if a.components != 1 {
        return Err(unsupported(format!(
            "array `{name}` has {} components in a later piece",
            a.components
        )));
    }
    let values: Vec<f64> = a
        .data
        .clone()
        .cast_into()
        .ok_or_else(|| unsupported(format!("array `{name}` of type bit")))?;
    if values.len() != len {
        return Err(malformed(format!("array `{name}` has {} values, not {len}", values.len())));
    }
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(malformed(format!(
            "array `{name}`: value {} is not finite ({})",
            first + i,
            values[i]
        )));
    }
    Ok(values)
}

/// Cell values averaged to the `n` points from `base` on: each point the
/// plain mean of the cells using it (`0.0` where none does). `cells[k]`
/// has the value `values[kept[k]]`.
fn cells_to_points(
    cells: &[Cell],
    kept: &[usize],
    values: &[f64],
    base: usize,
    n: usize,
) -> Vec<f64> {
    let mut sum = vec![0.0; n];
    let mut count = vec![0u32; n];
    for (c, &i) in cells.iter().zip(kept) {
        let p = c.points();
        for (k, &id) in p.iter().enumerate() {
            // A point listed twice in one cell (a collapsed cell) counts once.
            if p[..k].contains(&id) {
                continue;
            }
            let j = id as usize - base;
            sum[j] += values[i];
            count[j] += 1;
        }
    }
    sum.iter().zip(&count).map(|(&s, &c)| if c == 0 { 0.0 } else { s / f64::from(c) }).collect()
}
