//! Wavefront OBJ, through `tobj`.

use alloc::{string::ToString, vec::Vec};

use super::{
    MeshData, ReadError,
    error::{malformed, parse_error},
    mesh_data::{check_vertex_count, vec3s},
};

/// Parses a Wavefront OBJ file: every object and group becomes one mesh,
/// polygons are split into fans, points and lines are left out, materials
/// are not read. Vertex normals are kept when every vertex has one;
/// texture coordinates become scalars `u` and `v` when every vertex has
/// one.
///
/// # Errors
/// [`ReadErrorKind::Malformed`](super::ReadErrorKind::Malformed) wrapping `tobj`'s error, or for an index that
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
        .map_err(|_| malformed("OBJ: the parser failed on a bad index"))?
        .map_err(|e| parse_error("OBJ", e))?;
    let mut out = MeshData::default();
    for model in models {
        let m = model.mesh;
        let positions =
            vec3s(&m.positions).ok_or_else(|| malformed("OBJ: positions not in triples"))?;
        let n = positions.len();
        check_vertex_count(n)?;
        if !m.indices.len().is_multiple_of(3) {
            return Err(malformed("OBJ: face indices not in triples"));
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
