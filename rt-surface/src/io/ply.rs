//! PLY, through `ply-rs-bw` (the maintained fork of `ply-rs`): reading
//! with every per-vertex scalar, and writing.

use alloc::{format, string::String, vec::Vec};
use std::io::Write;

use glam::Vec3;

use super::{
    MeshData, ReadError,
    error::{malformed, parse_error},
    mesh_data::{check_vertex_count, fan},
};
use crate::Mesh;

/// Parses a PLY file (ASCII, binary little- or big-endian): the `vertex`
/// element's `x y z`, optional `nx ny nz`, every other scalar property as a
/// scalar, and the `face` element's `vertex_indices` (or `vertex_index`)
/// lists, split into fans. Other elements are ignored.
///
/// # Errors
/// [`ReadErrorKind::Malformed`](super::ReadErrorKind::Malformed) for a file `ply-rs-bw` rejects, no `vertex`
/// element or coordinates, a face list of fewer than 3 vertices or a
/// negative index.
pub fn parse_ply(bytes: &[u8]) -> Result<MeshData, ReadError> {
    use ply_rs_bw::{
        parser::Parser,
        ply::{DefaultElement, PropertyType},
    };
    let ply = Parser::<DefaultElement>::new()
        .read_ply(&mut &bytes[..])
        .map_err(|e| parse_error("PLY", e))?;
    let malformed = |m: &str| malformed(format!("PLY: {m}"));
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

/// Writes `mesh` as binary little-endian PLY: `x y z`, its scalars (if any)
/// as the vertex property `scalar_name`, its normals (if any) as
/// `nx ny nz`, and triangles as `vertex_indices` lists; [`parse_ply`] reads
/// it back unchanged.
///
/// # Errors
/// The writer's I/O error; [`std::io::ErrorKind::InvalidInput`] for a
/// scalar name that is empty, holds whitespace or collides with
/// `x y z nx ny nz`.
pub fn write_ply(mesh: &Mesh, scalar_name: &str, mut out: impl Write) -> std::io::Result<()> {
    let scalars = mesh.scalars();
    let reserved = ["x", "y", "z", "nx", "ny", "nz"];
    if scalars.is_some()
        && (scalar_name.is_empty()
            || scalar_name.contains(char::is_whitespace)
            || reserved.contains(&scalar_name))
    {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("PLY property name `{scalar_name}`"),
        ));
    }
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by rt-surface\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.positions().len()
    );
    if mesh.normals().is_some() {
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    if scalars.is_some() {
        header += &format!("property float {scalar_name}\n");
    }
    header += &format!(
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.indices().len()
    );
    let mut bytes = Vec::with_capacity(header.len() + 24 * mesh.positions().len());
    bytes.extend_from_slice(header.as_bytes());
    for (i, p) in mesh.positions().iter().enumerate() {
        let normal = mesh.normals().map(|n| n[i].to_array());
        let values = p.to_array().into_iter().chain(normal.into_iter().flatten());
        for v in values.chain(scalars.map(|s| s[i])) {
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    for t in mesh.indices() {
        bytes.push(3);
        for i in t {
            bytes.extend_from_slice(&i.to_le_bytes());
        }
    }
    out.write_all(&bytes)?;
    out.flush()
}
