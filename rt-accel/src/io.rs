//! Mesh readers (feature `io`): Wavefront OBJ (through `tobj`), PLY with
//! per-vertex scalar properties (through `ply-rs-bw`, the maintained fork
//! of `ply-rs`) and VTK polydata, legacy `.vtk` and XML `.vtp` (through
//! `vtkio`).
//!
//! Each reader returns a [`MeshData`]: positions, triangles (polygons are
//! split into fans, triangle strips into their triangles), normals where
//! the file has one per vertex, and every per-vertex scalar the file
//! carries, by name. [`MeshData::into_mesh`] then picks the scalar to
//! colour by and validates the lot as a [`TriangleMesh`]. Every malformed,
//! truncated or inconsistent file is an `Err` naming the problem; nothing
//! is read past what the file declares.
//!
//! Where the scalars come from:
//! - **PLY**: every scalar property of the `vertex` element other than
//!   `x y z nx ny nz`, under its own name (`red`, `confidence`, `pressure`…).
//! - **VTK**: every point-data array (attributes and field data) with one
//!   value per point; arrays of several components give their magnitude
//!   (a velocity's speed), under the array's name. Cell data is not read.
//! - **OBJ**: the format has no scalars; tools that colour-map OBJ write the
//!   scalar as a 1-D texture coordinate, so `vt` coordinates are offered as
//!   scalars `u` and `v`.
//!
//! ```
//! use rt_accel::io::parse_ply;
//!
//! let ply = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
//! property float z\nproperty float pressure\nelement face 1\n\
//! property list uchar int vertex_indices\nend_header\n\
//! 0 0 0 1.5\n1 0 0 2.5\n0 1 0 3.5\n3 0 1 2\n";
//! let data = parse_ply(ply).unwrap();
//! assert_eq!(data.scalar_names().collect::<Vec<_>>(), ["pressure"]);
//! let mesh = data.into_mesh(Some("pressure")).unwrap();
//! assert_eq!(mesh.scalars(), Some(&[1.5, 2.5, 3.5][..]));
//! ```

use alloc::{
    format,
    string::{String, ToString},
    vec::Vec,
};
use core::fmt;
use std::{fs, path::Path};

use glam::Vec3;

use crate::{BuildError, TriangleMesh};

/// Why a file could not be read as a mesh.
#[derive(Clone, Debug, PartialEq)]
pub enum ReadError {
    /// The operating system could not read a file.
    Io {
        /// The file.
        path: String,
        /// The system's message.
        message: String,
    },
    /// The file is not valid in its format.
    Malformed(String),
    /// A valid file using something this reader does not read.
    Unsupported(String),
    /// More vertices than 32-bit indices can address.
    TooLarge,
    /// [`MeshData::into_mesh`] was asked for a scalar the file lacks.
    NoSuchScalar {
        /// The name asked for.
        name: String,
        /// The names the file has.
        available: Vec<String>,
    },
    /// The geometry is invalid (a NaN vertex, an index out of range, a
    /// zero normal), with the offending vertex or triangle.
    Mesh(BuildError),
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, message } => write!(f, "{path}: {message}"),
            Self::Malformed(m) => write!(f, "malformed mesh file: {m}"),
            Self::Unsupported(m) => write!(f, "unsupported: {m}"),
            Self::TooLarge => f.write_str("more vertices than 32-bit indices address"),
            Self::NoSuchScalar { name, available } => {
                write!(f, "no scalar `{name}`; the file has {available:?}")
            }
            Self::Mesh(e) => write!(f, "{e}"),
        }
    }
}

impl core::error::Error for ReadError {}

impl From<BuildError> for ReadError {
    fn from(e: BuildError) -> Self {
        Self::Mesh(e)
    }
}

/// A mesh as read from a file, before a scalar is chosen.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshData {
    /// Vertex positions (not yet checked for NaN; [`Self::into_mesh`] does).
    pub positions: Vec<Vec3>,
    /// Triangles (not yet checked against the vertex count).
    pub indices: Vec<[u32; 3]>,
    /// One normal per vertex, when the file has them for every vertex.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex scalars by name, one value per vertex each, in file order.
    pub scalars: Vec<(String, Vec<f32>)>,
}

impl MeshData {
    /// The names of the scalars, in file order.
    pub fn scalar_names(&self) -> impl Iterator<Item = &str> {
        self.scalars.iter().map(|(n, _)| n.as_str())
    }

    /// The triangle mesh, coloured by the scalar `scalar` if given.
    ///
    /// # Errors
    /// [`ReadError::NoSuchScalar`], or [`ReadError::Mesh`] for a NaN/∞
    /// vertex, an index out of range or a zero/NaN normal (each naming the
    /// vertex or triangle).
    pub fn into_mesh(self, scalar: Option<&str>) -> Result<TriangleMesh, ReadError> {
        let chosen = match scalar {
            None => None,
            Some(name) => {
                let available: Vec<String> = self.scalar_names().map(ToString::to_string).collect();
                let found = self.scalars.into_iter().find(|(n, _)| n == name);
                Some(found.ok_or(ReadError::NoSuchScalar { name: name.to_string(), available })?.1)
            }
        };
        let mesh = TriangleMesh::new(self.positions, self.indices, chosen)?;
        Ok(match self.normals {
            Some(n) => mesh.with_normals(n)?,
            None => mesh,
        })
    }

    /// Appends `other` (indices shifted past this mesh's vertices). Scalars
    /// and normals are kept only where both have them.
    fn append(&mut self, other: Self) -> Result<(), ReadError> {
        // Check each part's indices against its own vertices: once shifted,
        // an index past the end would land on the next part's vertices.
        for (k, t) in other.indices.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= other.positions.len()) {
                let triangle = self.indices.len() + k;
                return Err(ReadError::Mesh(BuildError::IndexOutOfRange { triangle, index }));
            }
        }
        let offset = u32::try_from(self.positions.len()).map_err(|_| ReadError::TooLarge)?;
        if self.positions.is_empty() && self.indices.is_empty() {
            *self = other;
            return Ok(());
        }
        check_vertex_count(self.positions.len() + other.positions.len())?;
        self.positions.extend(other.positions);
        self.indices.extend(other.indices.into_iter().map(|t| t.map(|i| i + offset)));
        self.normals = match (self.normals.take(), other.normals) {
            (Some(mut a), Some(b)) => {
                a.extend(b);
                Some(a)
            }
            _ => None,
        };
        let mut theirs = other.scalars;
        self.scalars.retain_mut(|(name, values)| {
            match theirs.iter_mut().find(|(n, _)| n == name) {
                Some((_, v)) => {
                    values.append(v);
                    true
                }
                None => false,
            }
        });
        theirs.clear();
        Ok(())
    }
}

fn check_vertex_count(n: usize) -> Result<(), ReadError> {
    u32::try_from(n).map(|_| ()).map_err(|_| ReadError::TooLarge)
}

/// Converts polygon or strip vertex lists into triangles.
fn fan(cell: &[u32], out: &mut Vec<[u32; 3]>) {
    for w in cell.windows(2).skip(1) {
        out.push([cell[0], w[0], w[1]]);
    }
}

fn strip(cell: &[u32], out: &mut Vec<[u32; 3]>) {
    for (k, w) in cell.windows(3).enumerate() {
        // Every other triangle of a strip is reversed to keep one winding.
        out.push(if k % 2 == 0 { [w[0], w[1], w[2]] } else { [w[1], w[0], w[2]] });
    }
}

fn io_error(path: &Path, e: &std::io::Error) -> ReadError {
    ReadError::Io { path: path.display().to_string(), message: e.to_string() }
}

fn read(path: &Path) -> Result<Vec<u8>, ReadError> {
    fs::read(path).map_err(|e| io_error(path, &e))
}

/// Reads a mesh by extension: `.obj`, `.ply`, `.vtk` (legacy) or `.vtp`
/// (XML polydata).
///
/// # Errors
/// [`ReadError`] naming the problem; an unknown extension is
/// [`ReadError::Unsupported`].
pub fn read_mesh(path: &Path) -> Result<MeshData, ReadError> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("obj") => parse_obj(&read(path)?),
        Some("ply") => parse_ply(&read(path)?),
        Some("vtk") => parse_vtk_legacy(&read(path)?),
        Some("vtp") => parse_vtk_xml(&read(path)?),
        other => Err(ReadError::Unsupported(format!(
            "file extension {other:?} (expected obj, ply, vtk or vtp)"
        ))),
    }
}

// ---------------------------------------------------------------- OBJ ----

/// Parses a Wavefront OBJ file: every object and group becomes one mesh,
/// polygons are split into fans, points and lines are left out, materials
/// are not read. Vertex normals are kept when every vertex has one;
/// texture coordinates become scalars `u` and `v` when every vertex has
/// one.
///
/// # Errors
/// [`ReadError::Malformed`] with `tobj`'s reason, or for an index that
/// makes `tobj` itself fail.
pub fn parse_obj(bytes: &[u8]) -> Result<MeshData, ReadError> {
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj 4.0.5 indexes texture coordinates and normals with unchecked
    // arithmetic (`f 1/-2` far past the list overflows, found by the
    // `read_obj` fuzz target): its panic is caught and reported as a
    // malformed file. (Under `panic = "abort"` it would still abort.)
    let load =
        || tobj::load_obj_buf(&mut &bytes[..], &options, |_| Err(tobj::LoadError::OpenFileFailed));
    let (models, _materials) = std::panic::catch_unwind(load)
        .map_err(|_| ReadError::Malformed("OBJ: the parser failed on a bad index".into()))?
        .map_err(|e| ReadError::Malformed(format!("OBJ: {e}")))?;
    let mut out = MeshData::default();
    for model in models {
        let m = model.mesh;
        let positions = vec3s(&m.positions)
            .ok_or_else(|| ReadError::Malformed("OBJ: positions not in triples".into()))?;
        let n = positions.len();
        check_vertex_count(n)?;
        if !m.indices.len().is_multiple_of(3) {
            return Err(ReadError::Malformed("OBJ: face indices not in triples".into()));
        }
        let indices = m.indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let normals = vec3s(&m.normals).filter(|v| v.len() == n && n > 0);
        let mut scalars = Vec::new();
        if m.texcoords.len() == 2 * n && n > 0 {
            scalars.push(("u".to_string(), m.texcoords.iter().step_by(2).copied().collect()));
            scalars
                .push(("v".to_string(), m.texcoords.iter().skip(1).step_by(2).copied().collect()));
        }
        out.append(MeshData { positions, indices, normals, scalars })?;
    }
    Ok(out)
}

fn vec3s(flat: &[f32]) -> Option<Vec<Vec3>> {
    flat.len().is_multiple_of(3).then(|| flat.chunks_exact(3).map(Vec3::from_slice).collect())
}

// ---------------------------------------------------------------- PLY ----

/// Parses a PLY file (ASCII, binary little- or big-endian): the `vertex`
/// element's `x y z`, optional `nx ny nz`, every other scalar property as a
/// scalar, and the `face` element's `vertex_indices` (or `vertex_index`)
/// lists, split into fans. Other elements are ignored.
///
/// # Errors
/// [`ReadError::Malformed`] for a file `ply-rs-bw` rejects, no `vertex`
/// element or coordinates, a face list of fewer than 3 vertices or a
/// negative index.
pub fn parse_ply(bytes: &[u8]) -> Result<MeshData, ReadError> {
    use ply_rs_bw::{
        parser::Parser,
        ply::{DefaultElement, PropertyType},
    };
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut &bytes[..])
        .map_err(|e| ReadError::Malformed(format!("PLY: {e}")))?;
    let malformed = |m: &str| ReadError::Malformed(format!("PLY: {m}"));
    let vertex_def =
        ply.header.elements.get("vertex").ok_or_else(|| malformed("no `vertex` element"))?;
    let vertices = ply.payload.get("vertex").map_or(&[][..], Vec::as_slice);
    check_vertex_count(vertices.len())?;
    let scalar_names: Vec<&String> = vertex_def
        .properties
        .values()
        .filter(|p| matches!(p.data_type, PropertyType::Scalar(_)))
        .map(|p| &p.name)
        .collect();
    let has = |name: &str| scalar_names.iter().any(|n| *n == name);
    if !(has("x") && has("y") && has("z")) {
        return Err(malformed("the `vertex` element lacks scalar x, y or z"));
    }
    let get = |v: &DefaultElement, name: &str| v.get(name).and_then(ply_scalar);
    let mut positions = Vec::with_capacity(vertices.len());
    for (i, v) in vertices.iter().enumerate() {
        let c = |a| get(v, a).ok_or_else(|| malformed(&format!("vertex {i} lacks `{a}`")));
        positions.push(Vec3::new(c("x")?, c("y")?, c("z")?));
    }
    let normals = if has("nx") && has("ny") && has("nz") {
        let n: Option<Vec<Vec3>> = vertices
            .iter()
            .map(|v| Some(Vec3::new(get(v, "nx")?, get(v, "ny")?, get(v, "nz")?)))
            .collect();
        Some(n.ok_or_else(|| malformed("a vertex lacks a normal component"))?)
    } else {
        None
    };
    let mut scalars = Vec::new();
    for name in scalar_names {
        if ["x", "y", "z", "nx", "ny", "nz"].contains(&name.as_str()) {
            continue;
        }
        let values: Option<Vec<f32>> = vertices.iter().map(|v| get(v, name)).collect();
        let values = values.ok_or_else(|| malformed(&format!("a vertex lacks `{name}`")))?;
        scalars.push((name.clone(), values));
    }
    let mut indices = Vec::new();
    let mut cell = Vec::new();
    for (f, face) in ply.payload.get("face").map_or(&[][..], Vec::as_slice).iter().enumerate() {
        let list = face
            .get("vertex_indices")
            .or_else(|| face.get("vertex_index"))
            .ok_or_else(|| malformed(&format!("face {f} has no vertex_indices list")))?;
        cell.clear();
        ply_indices(list, &mut cell).ok_or_else(|| {
            malformed(&format!("face {f}: indices must be a list of integers ≥ 0"))
        })?;
        if cell.len() < 3 {
            return Err(malformed(&format!("face {f} has {} vertices", cell.len())));
        }
        fan(&cell, &mut indices);
    }
    Ok(MeshData { positions, indices, normals, scalars })
}

#[allow(clippy::cast_possible_truncation, reason = "samples are stored as f32")]
fn ply_scalar(p: &ply_rs_bw::ply::Property) -> Option<f32> {
    use ply_rs_bw::ply::Property as P;
    Some(match *p {
        P::Char(v) => f32::from(v),
        P::UChar(v) => f32::from(v),
        P::Short(v) => f32::from(v),
        P::UShort(v) => f32::from(v),
        P::Int(v) => v as f32,
        P::UInt(v) => v as f32,
        P::Float(v) => v,
        P::Double(v) => v as f32,
        _ => return None,
    })
}

fn ply_indices(p: &ply_rs_bw::ply::Property, out: &mut Vec<u32>) -> Option<()> {
    use ply_rs_bw::ply::Property as P;
    fn push<T: Copy>(v: &[T], out: &mut Vec<u32>, f: impl Fn(T) -> Option<u32>) -> Option<()> {
        for &x in v {
            out.push(f(x)?);
        }
        Some(())
    }
    match p {
        P::ListChar(v) => push(v, out, |x| u32::try_from(x).ok()),
        P::ListUChar(v) => push(v, out, |x| Some(u32::from(x))),
        P::ListShort(v) => push(v, out, |x| u32::try_from(x).ok()),
        P::ListUShort(v) => push(v, out, |x| Some(u32::from(x))),
        P::ListInt(v) => push(v, out, |x| u32::try_from(x).ok()),
        P::ListUInt(v) => push(v, out, Some),
        _ => None,
    }
}

// ---------------------------------------------------------------- VTK ----

/// Parses legacy VTK polydata (`.vtk`, ASCII or big-endian binary).
///
/// # Errors
/// [`ReadError::Malformed`] for files `vtkio` rejects or whose cells are
/// inconsistent, [`ReadError::Unsupported`] for other data set types.
pub fn parse_vtk_legacy(bytes: &[u8]) -> Result<MeshData, ReadError> {
    let vtk = vtkio::Vtk::parse_legacy_be(bytes)
        .map_err(|e| ReadError::Malformed(format!("VTK: {e}")))?;
    polydata(vtk)
}

/// Parses XML VTK polydata (`.vtp`) with inline or appended, uncompressed
/// data.
///
/// # Errors
/// As [`parse_vtk_legacy`]; compressed payloads are
/// [`ReadError::Malformed`] (`vtkio` is built without its compressors).
pub fn parse_vtk_xml(bytes: &[u8]) -> Result<MeshData, ReadError> {
    let vtk =
        vtkio::Vtk::parse_xml(bytes).map_err(|e| ReadError::Malformed(format!("VTK XML: {e}")))?;
    polydata(vtk)
}

fn polydata(vtk: vtkio::Vtk) -> Result<MeshData, ReadError> {
    use vtkio::model::DataSet;
    let DataSet::PolyData { pieces, .. } = vtk.data else {
        return Err(ReadError::Unsupported("VTK data set other than polydata".into()));
    };
    let mut out = MeshData::default();
    for (k, piece) in pieces.into_iter().enumerate() {
        // Pieces in other files are not followed: a reader of user data
        // should not open paths named inside it.
        let vtkio::model::Piece::Inline(piece) = piece else {
            return Err(ReadError::Unsupported(format!("VTK piece {k} refers to another file")));
        };
        out.append(polydata_piece(*piece)?)?;
    }
    Ok(out)
}

fn polydata_piece(piece: vtkio::model::PolyDataPiece) -> Result<MeshData, ReadError> {
    use vtkio::model::{Attribute, ElementType};
    let malformed = |m: &str| ReadError::Malformed(format!("VTK: {m}"));
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
    let bad = || ReadError::Malformed("VTK: cell list runs past its data".into());
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
                    cell.push(u32::try_from(i).map_err(|_| ReadError::TooLarge)?);
                }
                f(&cell)?;
                start = end;
            }
        }
    }
    Ok(())
}
