//! Mesh readers: each format read from hand-written files whose contents
//! are known exactly, and every kind of bad file an `Err`.

use glam::Vec3;
use rt_accel::BuildError;
use rt_surface::{
    Mesh, MeshError,
    io::{
        MeshData, ReadError, ReadErrorKind, parse_obj, parse_ply, parse_vtk_legacy, parse_vtk_xml,
        read_mesh, write_ply,
    },
};

/// A unit square in z = 0 split into two triangles along (0,0)–(1,1), the
/// scalar equal to x + 2y, normals +z: what every fixture below describes.
fn square_positions() -> Vec<Vec3> {
    vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y]
}

const QUAD: [[u32; 3]; 2] = [[0, 1, 2], [0, 2, 3]];

#[test]
fn obj_polygons_become_fans_with_normals_and_texture_scalars() {
    let obj = b"# a square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
                vt 0 0.5\nvt 1 0.5\nvt 3 0.5\nvt 2 0.5\nvn 0 0 1\n\
                f 1/1/1 2/2/1 3/3/1 4/4/1\n";
    let data = parse_obj(obj).unwrap();
    assert_eq!(data.positions, square_positions());
    assert_eq!(data.indices, QUAD);
    assert_eq!(data.normals.as_deref(), Some(&[Vec3::Z; 4][..]));
    assert_eq!(data.scalar_names().collect::<Vec<_>>(), ["u", "v"]);
    let mesh = data.into_mesh(Some("u")).unwrap();
    assert_eq!(mesh.scalars(), Some(&[0.0, 1.0, 3.0, 2.0][..]));
    assert!(mesh.normals().is_some());
}

#[test]
fn obj_objects_are_merged_with_shifted_indices() {
    let obj = b"o a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\
                o b\nv 5 0 0\nv 6 0 0\nv 5 1 0\nf 4 5 6\nl 4 5\np 6\n";
    let data = parse_obj(obj).unwrap();
    assert_eq!(data.positions.len(), 6);
    assert_eq!(data.indices, [[0, 1, 2], [3, 4, 5]]);
    assert_eq!(data.positions[3], Vec3::new(5.0, 0.0, 0.0));
    assert!(data.normals.is_none());
    assert!(data.scalars.is_empty());
}

fn ply_header(format: &str, extra: &str) -> String {
    format!(
        "ply\nformat {format} 1.0\ncomment made by hand\nelement vertex 4\n\
         property float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\n\
         property double pressure\nproperty uchar flag\n{extra}\
         element face 1\nproperty list uchar int vertex_indices\nend_header\n"
    )
}

#[test]
fn ply_ascii_and_binary_read_the_same_mesh() {
    let mut ascii = ply_header("ascii", "");
    for p in square_positions() {
        ascii += &format!("{} {} {} 0 0 1 {} 7\n", p.x, p.y, p.z, p.x + 2.0 * p.y);
    }
    ascii += "4 0 1 2 3\n";
    let from_ascii = parse_ply(ascii.as_bytes()).unwrap();

    for big in [false, true] {
        let fmt = if big { "binary_big_endian" } else { "binary_little_endian" };
        let mut bin = ply_header(fmt, "").into_bytes();
        let f = |v: f32| if big { v.to_be_bytes() } else { v.to_le_bytes() };
        for p in square_positions() {
            for v in [p.x, p.y, p.z, 0.0, 0.0, 1.0] {
                bin.extend(f(v));
            }
            let s = f64::from(p.x + 2.0 * p.y);
            bin.extend(if big { s.to_be_bytes() } else { s.to_le_bytes() });
            bin.push(7);
        }
        bin.push(4);
        for i in 0i32..4 {
            bin.extend(if big { i.to_be_bytes() } else { i.to_le_bytes() });
        }
        assert_eq!(parse_ply(&bin).unwrap(), from_ascii, "{fmt}");
    }

    assert_eq!(from_ascii.positions, square_positions());
    assert_eq!(from_ascii.indices, QUAD);
    assert_eq!(from_ascii.normals.as_deref(), Some(&[Vec3::Z; 4][..]));
    assert_eq!(from_ascii.scalar_names().collect::<Vec<_>>(), ["pressure", "flag"]);
    let mesh = from_ascii.into_mesh(Some("pressure")).unwrap();
    assert_eq!(mesh.scalars(), Some(&[0.0, 1.0, 3.0, 2.0][..]));
}

#[test]
fn vtk_legacy_polydata_polygons_strips_and_point_data() {
    let vtk = b"# vtk DataFile Version 3.0\nsquare\nASCII\nDATASET POLYDATA\n\
        POINTS 6 float\n0 0 0  1 0 0  1 1 0  0 1 0  2 0 0  2 1 0\n\
        POLYGONS 1 5\n4 0 1 2 3\n\
        TRIANGLE_STRIPS 1 5\n4 1 4 2 5\n\
        POINT_DATA 6\nSCALARS pressure float 1\nLOOKUP_TABLE default\n0 1 3 2 2 4\n\
        VECTORS velocity float\n3 4 0  0 0 0  1 0 0  0 1 0  0 0 2  6 8 0\n\
        NORMALS normals float\n0 0 1  0 0 1  0 0 1  0 0 1  0 0 1  0 0 1\n";
    let data = parse_vtk_legacy(vtk).unwrap();
    assert_eq!(data.positions.len(), 6);
    // The fan, then the strip with every other triangle turned to keep
    // the winding: (1,4,2), (4,2,5) → (2,4,5).
    assert_eq!(data.indices, [[0, 1, 2], [0, 2, 3], [1, 4, 2], [2, 4, 5]]);
    for t in &data.indices {
        let [a, b, c] = t.map(|i| data.positions[i as usize]);
        assert!((b - a).cross(c - a).z > 0.0, "{t:?} is wound clockwise");
    }
    assert_eq!(data.normals.as_deref(), Some(&[Vec3::Z; 6][..]));
    assert_eq!(data.scalar_names().collect::<Vec<_>>(), ["pressure", "velocity"]);
    let speed = data.clone().into_mesh(Some("velocity")).unwrap();
    assert_eq!(speed.scalars(), Some(&[5.0, 0.0, 1.0, 1.0, 2.0, 10.0][..]));
    let p = data.into_mesh(Some("pressure")).unwrap();
    assert_eq!(p.scalars(), Some(&[0.0, 1.0, 3.0, 2.0, 2.0, 4.0][..]));
}

#[test]
fn vtk_xml_polydata() {
    let vtp = br#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="4" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="1">
      <PointData Scalars="pressure">
        <DataArray type="Float32" Name="pressure" format="ascii">0 1 3 2</DataArray>
      </PointData>
      <Points>
        <DataArray type="Float32" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 1 1 0 0 1 0</DataArray>
      </Points>
      <Polys>
        <DataArray type="Int32" Name="connectivity" format="ascii">0 1 2 3</DataArray>
        <DataArray type="Int32" Name="offsets" format="ascii">4</DataArray>
      </Polys>
    </Piece>
  </PolyData>
</VTKFile>
"#;
    let data = parse_vtk_xml(vtp).unwrap();
    assert_eq!(data.positions, square_positions());
    assert_eq!(data.indices, QUAD);
    let mesh = data.into_mesh(Some("pressure")).unwrap();
    assert_eq!(mesh.scalars(), Some(&[0.0, 1.0, 3.0, 2.0][..]));
}

#[test]
fn read_mesh_goes_by_extension_and_names_io_errors() {
    let dir = std::env::temp_dir().join(format!("rt-surface-io-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let obj = dir.join("t.OBJ");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert_eq!(read_mesh(&obj).unwrap().indices, [[0, 1, 2]]);
    let missing = dir.join("none.ply");
    let e = read_mesh(&missing).unwrap_err();
    let ReadErrorKind::Io(source) = e.kind() else { panic!("{e:?}") };
    assert_eq!(source.kind(), std::io::ErrorKind::NotFound);
    assert_eq!(e.path(), Some(missing.as_path()));
    // The system's error is the source, the path leads the message.
    assert!(core::error::Error::source(&e).is_some());
    assert!(e.to_string().starts_with(&format!("{}: ", missing.display())), "{e}");
    // A parse error in a named file names it too.
    let bad = dir.join("bad.ply");
    std::fs::write(&bad, "plx\n").unwrap();
    let e = read_mesh(&bad).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Malformed { .. }), "{e:?}");
    assert!(e.to_string().starts_with(&format!("{}: malformed", bad.display())), "{e}");
    let e = read_mesh(&dir.join("t.stl")).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::UnknownFormat), "{e:?}");
    assert!(e.to_string().starts_with(&format!("{}: ", dir.join("t.stl").display())));
    assert!(e.to_string().contains(".obj, .ply, .vtk or .vtp"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The mesh error inside a reader's error.
fn mesh_error<T: core::fmt::Debug>(r: Result<T, ReadError>) -> MeshError {
    match r.map_err(ReadError::into_kind) {
        Err(ReadErrorKind::Mesh(e)) => e,
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_geometry_names_the_vertex_or_triangle() {
    let nan = parse_obj(b"v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    assert!(matches!(
        mesh_error(nan.into_mesh(None)),
        MeshError::Geometry(BuildError::NonFiniteVertex { vertex: 1 })
    ));

    let mut ply = ply_header("ascii", "");
    ply += "0 0 0 0 0 1 0 0\n1 0 0 0 0 1 0 0\n0 1 0 0 0 1 0 0\n0 0 1 0 0 0 0 0\n3 0 1 2\n";
    // Vertex 3's normal is zero.
    let data = parse_ply(ply.as_bytes()).unwrap();
    assert_eq!(mesh_error(data.into_mesh(None)), MeshError::BadNormal { vertex: 3 });

    let far = ply.replace("3 0 1 2\n", "3 0 1 9\n");
    let data = parse_ply(far.as_bytes()).unwrap();
    assert_eq!(
        mesh_error(data.into_mesh(None)),
        MeshError::Geometry(BuildError::IndexOutOfRange { triangle: 0, index: 9 })
    );

    // An index past its own object must not land on the next object's
    // vertices once the objects are merged.
    let vtk = b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\n\
        POINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n3 0 1 3\n";
    assert_eq!(
        mesh_error(parse_vtk_legacy(vtk)),
        MeshError::Geometry(BuildError::IndexOutOfRange { triangle: 0, index: 3 })
    );
}

#[test]
fn missing_scalar_lists_the_available_ones() {
    let data =
        parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n").unwrap();
    match data.into_mesh(Some("temperature")).map_err(ReadError::into_kind) {
        Err(ReadErrorKind::NoSuchScalar { name, available }) => {
            assert_eq!(name, "temperature");
            assert_eq!(available, ["u", "v"]);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn malformed_files_are_errors() {
    let mut ply = ply_header("ascii", "");
    ply += "0 0 0 0 0 1 0 0\n1 0 0 0 0 1 0 0\n0 1 0 0 0 1 0 0\n0 0 1 0 0 1 0 0\n3 0 1 2\n";
    let truncated_binary = {
        let mut b = ply_header("binary_little_endian", "").into_bytes();
        b.extend([0u8; 40]);
        b
    };
    let cases: Vec<(&str, Result<_, ReadError>)> = vec![
        ("obj face index 0", parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n")),
        ("obj face past the end", parse_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")),
        ("obj bad number", parse_obj(b"v 0 zero 0\n")),
        ("not a ply", parse_ply(b"plx\nformat ascii 1.0\nend_header\n")),
        ("ply without end_header", parse_ply(b"ply\nformat ascii 1.0\nelement vertex 1\n")),
        ("ply truncated ascii", parse_ply(ply.replace("3 0 1 2\n", "").as_bytes())),
        ("ply truncated binary", parse_ply(&truncated_binary)),
        ("ply two-vertex face", parse_ply(ply.replace("3 0 1 2\n", "2 0 1\n").as_bytes())),
        ("ply negative index", parse_ply(ply.replace("3 0 1 2\n", "3 0 -1 2\n").as_bytes())),
        (
            "ply without z",
            parse_ply(b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n"),
        ),
        ("ply huge count", parse_ply(b"ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n\0\0")),
        ("vtk garbage", parse_vtk_legacy(b"# vtk DataFile Version 3.0\n\xff\xfe")),
        (
            "vtk image data",
            parse_vtk_legacy(b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 1 1 1\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 1\nSCALARS s float 1\nLOOKUP_TABLE default\n0\n"),
        ),
        (
            "vtk polygon runs past its data",
            parse_vtk_legacy(b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 4\n9 0 1 2\n"),
        ),
        (
            "vtk two-point polygon",
            parse_vtk_legacy(b"# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 3 float\n0 0 0 1 0 0 0 1 0\nPOLYGONS 1 3\n2 0 1\n"),
        ),
        ("vtp garbage", parse_vtk_xml(b"<VTKFile type=\"PolyData\"><PolyData><Piece")),
    ];
    let accepted: Vec<_> = cases.iter().filter(|(_, r)| r.is_ok()).collect();
    assert!(accepted.is_empty(), "accepted: {accepted:?}");
    for (what, result) in cases {
        // Every error explains itself.
        assert!(!result.unwrap_err().to_string().is_empty(), "{what}");
    }
    // An empty file is a valid, empty mesh.
    assert_eq!(parse_obj(b"").unwrap(), MeshData::default());
}

/// Found by the `read_obj` fuzz target: `tobj` overflows computing a
/// texture-coordinate index (`f 1/-2` past the list) and panics; the
/// reader answers `Err` instead.
#[test]
fn fuzz_regression_obj_bad_texcoord_index_is_an_error() {
    let parts: [&[u8]; 10] = [
        b"\nf\x0c 2 2  \n\nv\x0b\r5\r00\x0b0\n-\nv\x03\x0b\no\r\x19\n\x0b282  ?",
        b"\nf\x0c 2 2 2  \n\nv\x0b\r5\r00\x0b0\n-\nv\x03\x0b\no\r\x19\n\x0b282  ",
        b"?\nf\x0c 2 2 2  \n\nv\x0b\r5\r00\x0b0\n-\nv\x03\x0b\ng\r\x19\n\x0b    ",
        b"  \nf\x0b 1 2 2/  1/-2 \n-\nv\x03\x0b\no$\r\x19\n\x0b282  ?\nf\x0c 2 2",
        b" 2  \n35\n35\n\nvt\r50\x0b\x0b00\x0b\x0b0f\x0b0350\x0b3\nf\x0b3\nl35\n",
        b"\n335\n\nvt\r50\x0b\x0b00\x0b\x0b0\nf35f\x0b//\nv\x0b\r0\x0b\x0b0\x0b8",
        b"\nv\x03\x0b\ng\r\x19\n\x0b      \nf\x0b 1 2 2/  1/-2 \n-\nv\x03\x0b\no",
        b"\r\x19\n\x0b282  ?\nf\x0c 2 2\x00\x00\x00\x00\x00\x00\x00\x8035\n\nvt",
        b"\r50\x0b\x0b00\x0b\x0b0f\x0b0350\x0b3\nf\x0b3\nl35\n\n335\n\nvt\r50",
        b"\x0b\x0b00\x0b\x0b0\nf35f\x0b//\nv\x0b\r0\x0b\x0b0\x0b828",
    ];
    let bytes = parts.concat();
    assert_eq!(bytes.len(), 375);
    assert!(matches!(parse_obj(&bytes).unwrap_err().kind(), ReadErrorKind::Malformed { .. }));
}

/// Found by the `read_obj` fuzz target in CI: a texture-coordinate index
/// far before the list (`f 1/-0025` with one `vt` read; the same case is
/// in the next test) overflowed inside `tobj`; under the fuzzer's
/// abort-on-panic hook, catching the panic did not help. Face indices are
/// now checked before `tobj` sees them.
#[test]
fn fuzz_regression_obj_texcoord_index_before_the_list_is_checked_first() {
    let parts: [&[u8]; 12] = [
        b"\nv\x7f\0gv\x7f\0g\nvn\x0b9\t99\t9\n=~L \nvt\x0b19\t9  \t9",
        b"99\x0b\nv\x7f\0gv\x0b\x0bg gg\x049\t99\nv\x0b\t9\t99\t9\n v\x0b9\t",
        b"9\t9\nv\x0b\t9\t9\t9\nv\x0b\t9\t9\t9\n9\t999\t9\t\t99\t \n",
        b"v\x0b\t9\t99\t9\n\0\0\0\0\0\0\0\x08v\x0b9\t9\t9\nf\x0b\t9\t9\t9\nv",
        b"\x0b\t9\t9\t9\t\t99\t \nv\x0b\t9\r9\t9\nvK9\t999\t9\t\t99",
        b"\t \nv\x0b\t9\t99\t9\nv\x0b9\t9\t9\nf\x0b\t9\t9\t9\n\x7f\nf\0g\t",
        b"\ng\0g\t\ng\0\0\n\0\ng\x1a\0\nf\x0b\x0b/-05\nv\x0b9\t9\t9\t9\n=\x0b",
        b"9ccYcccccccccccccc\x0b\t9\nv\x0b9\t9\t9\t9\n=\nv=",
        b"v \t\t99\0\t\n99\x0b\t9\nv\x0b9\t9\t9\t9\n=\r9\n=9\t9\0\t\n",
        b"99\x0b\t9\nv\x0b9\t9\t9\t9\n\t9\nv\x0b9\t9\t9\t9\n=\r9\nf\x0b1",
        b"/-0025 05\x0b\x0b/-05\x0b\x0b/-0025 05\x0b\x0b/-05\nf\x0b1",
        b"/-005 65 65\x0b1/-005 65 65",
    ];
    let bytes = parts.concat();
    assert_eq!(bytes.len(), 420);
    let e = parse_obj(&bytes).unwrap_err();
    // Its first bad index is an earlier one-vertex face without a vertex
    // index (tobj skips one-vertex faces, so it never failed there).
    assert!(e.to_string().contains("OBJ line 27: face vertex \"/-05\""), "{e}");
}

/// Face indices are checked as OBJ defines them: from 1, negative counts
/// back from the items read so far, forward references are allowed, and
/// texture coordinate or normal indices in a file without that list are
/// ignored (as tobj does).
#[test]
fn obj_face_indices_follow_the_format() {
    let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    for ok in [
        format!("{tri}f -3 -2 -1\n"),
        format!("f 1 2 3\n{tri}"),
        format!("{tri}f 1/7 2/7 3/7\n"),
        format!("{tri}f 1//9 2//9 3//9\n"),
        format!("{tri}vt 0 0\nf 1/-1 2/1 3/-1\n"),
    ] {
        assert_eq!(parse_obj(ok.as_bytes()).unwrap().indices, [[0, 1, 2]], "{ok}");
    }
    for (bad, message) in [
        (format!("{tri}f -4 -2 -1\n"), "line 4: vertex index -4, with 3 before this line"),
        (format!("f -1 2 3\n{tri}"), "line 1: vertex index -1, with 0 before this line"),
        (format!("{tri}f 1 2 4\n"), "line 4: vertex index 4, with 3 in the file"),
        (format!("{tri}vt 0 0\nf 1/2 2/1 3/1\n"), "line 5: texture coordinate index 2, with 1"),
        (format!("{tri}vt 0 0\nf 1/-25 2/1 3/1\n"), "texture coordinate index -25, with 1"),
        (format!("{tri}vn 0 0 1\nf 1//-2 2//1 3//1\n"), "line 5: normal index -2, with 1"),
        (format!("{tri}vn 0 0 1\nf 1//0 2//1 3//1\n"), "line 5: normal index 0"),
        (format!("{tri}vt 0 0\nf 1/-9223372036854775808 2 3\n"), "index -9223372036854775808"),
        (format!("{tri}vn 0 0 1\nf 1//9223372036854775807 2 3\n"), "index 9223372036854775807"),
        (format!("{tri}f /1 2 3\n"), "line 4: face vertex \"/1\" has no vertex index"),
    ] {
        let e = parse_obj(bad.as_bytes()).unwrap_err();
        assert!(e.to_string().contains(message), "{bad}: {e}");
        assert_eq!(e.to_string().lines().count(), 1);
    }
}

/// Parse errors wrap the parser's own error as their source, and print
/// its first line on one line of their own.
#[test]
fn parser_errors_are_the_source() {
    for e in [
        parse_obj(b"v 0 zero 0\n").unwrap_err(),
        parse_ply(b"plx\nformat ascii 1.0\nend_header\n").unwrap_err(),
        parse_vtk_legacy(b"# vtk DataFile Version 3.0\n\xff\xfe").unwrap_err(),
    ] {
        assert!(matches!(e.kind(), ReadErrorKind::Malformed { source: Some(_), .. }), "{e:?}");
        let inner = core::error::Error::source(&e).expect("source");
        let inner = inner.to_string();
        let first = inner.lines().next().unwrap();
        assert!(e.to_string().ends_with(first), "{e} / {inner}");
        assert_eq!(e.to_string().lines().count(), 1, "{e}");
    }
}

/// What `write_ply` writes, `parse_ply` reads back exactly: positions,
/// normals, the scalar under its name, triangles.
#[test]
fn ply_round_trip() {
    let positions = vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1e-7)];
    let normals = vec![Vec3::Z, Vec3::Z, Vec3::new(0.0, 0.6, 0.8), Vec3::Z];
    let mesh = Mesh::new(positions, QUAD.to_vec(), Some(vec![0.5, -1.0, f32::MAX, 3.25]))
        .unwrap()
        .with_normals(normals)
        .unwrap();
    let mut bytes = Vec::new();
    write_ply(&mesh, "pressure", &mut bytes).unwrap();
    let data = parse_ply(&bytes).unwrap();
    assert_eq!(data.scalar_names().collect::<Vec<_>>(), ["pressure"]);
    assert_eq!(data.into_mesh(Some("pressure")).unwrap(), mesh);
    // Without scalars or normals too.
    let plain = Mesh::new(mesh.positions().to_vec(), QUAD.to_vec(), None).unwrap();
    bytes.clear();
    write_ply(&plain, "unused name", &mut bytes).unwrap();
    assert_eq!(parse_ply(&bytes).unwrap().into_mesh(None).unwrap(), plain);
    // A name that would break the header is refused.
    for bad in ["", "two words", "x", "nz"] {
        let e = write_ply(&mesh, bad, &mut Vec::new()).unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidInput, "{bad:?}");
    }
}

/// OBJ errors say which line (tobj's own errors do not).
#[test]
fn obj_errors_name_the_line() {
    for (obj, line) in [
        (&b"v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n"[..], 2),
        (b"# a comment\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0\nf 1 2 3\n", 5),
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 x\n", 5),
        (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n", 5),
    ] {
        let e = parse_obj(obj).unwrap_err();
        assert!(e.to_string().contains(&format!("OBJ line {line}: ")), "{e}");
        assert_eq!(e.to_string().lines().count(), 1);
    }
}
