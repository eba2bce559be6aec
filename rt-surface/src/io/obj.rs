//! Wavefront OBJ, through `tobj`.

use alloc::{
    format,
    string::{String, ToString},
    vec::Vec,
};

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
/// a face index outside its list (0, past the end of the file's list, or
/// counting back past the first item read), with its line.
pub fn parse_obj(bytes: &[u8]) -> Result<MeshData, ReadError> {
    let options = tobj::LoadOptions {
        single_index: true,
        triangulate: true,
        ignore_points: true,
        ignore_lines: true,
    };
    // tobj 4.0.5 multiplies face indices unchecked (`f 1/-9` with fewer
    // texture coordinates overflows): every index is checked here first,
    // so tobj only sees indices into its lists. Its panics, should it have
    // others, are still caught and reported as a malformed file (under
    // `panic = "abort"` they would abort).
    check_face_indices(bytes)?;
    let load =
        || tobj::load_obj_buf(&mut &bytes[..], &options, |_| Err(tobj::LoadError::OpenFileFailed));
    let (models, _materials) = std::panic::catch_unwind(load)
        .map_err(|_| malformed("OBJ: the parser failed"))?
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
            _ => false,
        }
    };
    text.lines().enumerate().find_map(|(i, line)| {
        let words: Vec<&str> = line.split('#').next()?.split_whitespace().collect();
        let tag = *words.first()?;
        bad(tag, &words).then_some(i + 1)
    })
}

/// The lists a face vertex `v/vt/vn` indexes, in its slot order.
const LISTS: [(&str, &str); 3] = [("v", "vertex"), ("vt", "texture coordinate"), ("vn", "normal")];

/// Checks every face index of `bytes` the way the OBJ format defines
/// them: `k > 0` is the k-th item of its list in the file, `k < 0` counts
/// back from the last item read before the face, `0` is no item. Texture
/// coordinate and normal indices are not checked in a file without that
/// list (tobj leaves them out). Lines are read as tobj reads them, up to
/// the first that is not UTF-8 (where tobj stops with its own error);
/// indices that are not integers are left to tobj's error too.
fn check_face_indices(bytes: &[u8]) -> Result<(), ReadError> {
    let lines = || bytes.split(|&b| b == b'\n').map_while(|l| core::str::from_utf8(l).ok());
    let slot = |tag: &str| LISTS.iter().position(|&(t, _)| t == tag);
    let mut total = [0usize; 3];
    for line in lines() {
        if let Some(s) = line.split_whitespace().next().and_then(slot) {
            total[s] += 1;
        }
    }
    let mut read = [0usize; 3];
    for (number, line) in lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("f") => {}
            tag => {
                if let Some(s) = tag.and_then(slot) {
                    read[s] += 1;
                }
                continue;
            }
        }
        for vertex in words {
            for (s, t) in vertex.split('/').enumerate().take(3) {
                let what = LISTS[s].1;
                let bad = |why: String| malformed(format!("OBJ line {}: {why}", number + 1));
                if t.is_empty() {
                    if s == 0 {
                        return Err(bad(format!("face vertex {vertex:?} has no vertex index")));
                    }
                    continue;
                }
                let Ok(k) = t.parse::<i64>() else { continue };
                if s > 0 && total[s] == 0 {
                    continue;
                }
                let ok = match k {
                    0 => return Err(bad(format!("{what} index 0 (OBJ counts from 1)"))),
                    1.. => k.unsigned_abs() <= total[s] as u64,
                    _ => k.unsigned_abs() <= read[s] as u64,
                };
                if !ok {
                    let (n, place) = if k > 0 {
                        (total[s], "in the file")
                    } else {
                        (read[s], "before this line")
                    };
                    return Err(bad(format!("{what} index {k}, with {n} {place}")));
                }
            }
        }
    }
    Ok(())
}
