//! Wavefront OBJ, through `tobj`.

use alloc::{format, string::ToString, vec::Vec};

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
/// [`ReadErrorKind::Malformed`](super::ReadErrorKind::Malformed) wrapping
/// `tobj`'s error, with the line it is about where it can be found, or for
/// an index that makes `tobj` itself fail.
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
        .map_err(|e| match error_line(bytes, &e) {
            Some(line) => parse_error(format!("OBJ line {line}"), e),
            None => parse_error("OBJ", e),
        })?;
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

/// The first line (1-based) that `tobj`'s error `e` can be about: tobj
/// reports the kind of error but not where.
fn error_line(bytes: &[u8], e: &tobj::LoadError) -> Option<usize> {
    use tobj::LoadError as E;
    let text = core::str::from_utf8(bytes).ok()?;
    let floats = |rest: &[&str]| rest.iter().all(|t| t.parse::<f32>().is_ok());
    let count =
        |tag: &str| text.lines().filter(|l| l.split_whitespace().next() == Some(tag)).count();
    let (nv, nt, nn) = (count("v"), count("vt"), count("vn"));
    // Index `k` (1-based, negative from the end) of a list of `len` items.
    let index_ok = |t: &str, len: usize| match t.parse::<i64>() {
        Ok(k) if k > 0 => usize::try_from(k).is_ok_and(|k| k <= len),
        Ok(k) if k < 0 => usize::try_from(-k).is_ok_and(|k| k <= len),
        _ => false,
    };
    let bad = |tag: &str, words: &[&str]| -> bool {
        let rest = &words[1..];
        match (e, tag) {
            (E::PositionParseError | E::ColorParseError, "v") => {
                !(matches!(rest.len(), 3 | 4 | 6 | 7) && floats(rest))
            }
            (E::ScalingByZeroError, "v") => rest.get(3).is_some_and(|w| w.parse() == Ok(0.0f32)),
            (E::NormalParseError, "vn") => !(rest.len() == 3 && floats(rest)),
            (E::TexcoordParseError, "vt") => !((1..=3).contains(&rest.len()) && floats(rest)),
            (E::InvalidPolygon, "f") => rest.len() < 3,
            (E::FaceParseError, "f") => rest.iter().any(|r| {
                r.split('/')
                    .enumerate()
                    .any(|(i, t)| !(t.is_empty() && i > 0) && t.parse::<i64>().is_err())
            }),
            (
                E::FaceVertexOutOfBounds | E::FaceTexCoordOutOfBounds | E::FaceNormalOutOfBounds,
                "f",
            ) => {
                let slot = match e {
                    E::FaceVertexOutOfBounds => 0,
                    E::FaceTexCoordOutOfBounds => 1,
                    _ => 2,
                };
                let len = [nv, nt, nn][slot];
                rest.iter().any(|r| {
                    r.split('/').nth(slot).is_some_and(|t| !t.is_empty() && !index_ok(t, len))
                })
            }
            _ => false,
        }
    };
    text.lines().enumerate().find_map(|(i, line)| {
        let words: Vec<&str> = line.split('#').next()?.split_whitespace().collect();
        let tag = *words.first()?;
        bad(tag, &words).then_some(i + 1)
    })
}
