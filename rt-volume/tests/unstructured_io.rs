//! VTK unstructured-grid readers (feature `io`): one small mesh of every
//! linear volume cell (and a triangle to skip) written in every format by
//! hand, read back exactly; malformed files are `Err`s, never panics.
#![cfg(feature = "io")]

use std::path::{Path, PathBuf};

use glam::DVec3;
use rt_volume::{
    Cell,
    io::{
        ReadError, ReadErrorKind, UnstructuredData, is_unstructured, read_grid, read_unstructured,
    },
};

/// A mesh as a file spells it: points, `(VTK type, point ids)` per cell,
/// a scalar `p` per point (a 3-vector `vec` per point comes before it: the
/// coordinates) and a scalar `c` per cell.
#[derive(Clone)]
struct Mesh {
    points: Vec<[f64; 3]>,
    cells: Vec<(u8, Vec<i64>)>,
    p: Vec<f64>,
    c: Vec<f32>,
}

/// A hexahedron, a wedge, a pyramid, a tetrahedron, a voxel (beside the
/// hexahedron) and a triangle; point 16 is in no cell.
fn mesh() -> Mesh {
    let points = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
        [2.0, 0.0, 0.0],
        [2.0, 1.0, 0.0],
        [2.0, 0.0, 1.0],
        [2.0, 1.0, 1.0],
        [0.5, 0.5, 2.0],
        [0.0, 2.0, 0.0],
        [0.0, 2.0, 1.0],
        [-1.0, 0.0, 0.0],
        [3.0, 3.0, 3.0],
    ];
    let cells = vec![
        (12, vec![0, 1, 2, 3, 4, 5, 6, 7]),
        (13, vec![3, 2, 13, 7, 6, 14]),
        (14, vec![4, 5, 6, 7, 12]),
        (10, vec![0, 3, 4, 15]),
        // Voxel order: x fastest, then y, then z.
        (11, vec![1, 8, 2, 9, 5, 10, 6, 11]),
        (5, vec![0, 1, 2]),
    ];
    let p = points.iter().map(|q| q[0] + 10.0 * q[1] + 100.0 * q[2] + 0.25).collect();
    Mesh { points, cells, p, c: vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0] }
}

/// The cells `mesh()` must read as, in VTK order (the voxel reordered).
fn expected_cells() -> Vec<Cell> {
    vec![
        Cell::Hexahedron([0, 1, 2, 3, 4, 5, 6, 7]),
        Cell::Wedge([3, 2, 13, 7, 6, 14]),
        Cell::Pyramid([4, 5, 6, 7, 12]),
        Cell::Tetra([0, 3, 4, 15]),
        Cell::Hexahedron([1, 8, 9, 2, 5, 10, 11, 6]),
    ]
}

// ---- Writers -------------------------------------------------------------

fn join<T: ToString>(v: impl IntoIterator<Item = T>) -> String {
    v.into_iter().map(|x| x.to_string()).collect::<Vec<_>>().join(" ")
}

fn vec_data(m: &Mesh) -> Vec<f32> {
    m.points.iter().flat_map(|q| q.map(|x| x as f32)).collect()
}

fn legacy_ascii(m: &Mesh) -> Vec<u8> {
    let size: usize = m.cells.iter().map(|(_, ids)| ids.len() + 1).sum();
    let cells: Vec<String> =
        m.cells.iter().map(|(_, ids)| format!("{} {}", ids.len(), join(ids))).collect();
    format!(
        "# vtk DataFile Version 3.0\nrt test mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n\
         POINTS {np} double\n{pts}\nCELLS {nc} {size}\n{cells}\nCELL_TYPES {nc}\n{types}\n\
         POINT_DATA {np}\nVECTORS vec float\n{vec}\nSCALARS p double 1\nLOOKUP_TABLE default\n{p}\n\
         CELL_DATA {nc}\nSCALARS c float 1\nLOOKUP_TABLE default\n{c}\n",
        np = m.points.len(),
        pts = join(m.points.iter().flatten()),
        nc = m.cells.len(),
        cells = cells.join("\n"),
        types = join(m.cells.iter().map(|(t, _)| t)),
        vec = join(vec_data(m)),
        p = join(&m.p),
        c = join(&m.c),
    )
    .into_bytes()
}

/// Legacy BINARY: big-endian, as VTK writes it.
fn legacy_binary(m: &Mesh) -> Vec<u8> {
    let mut f =
        b"# vtk DataFile Version 3.0\nrt test mesh\nBINARY\nDATASET UNSTRUCTURED_GRID\n".to_vec();
    f.extend(format!("POINTS {} double\n", m.points.len()).bytes());
    f.extend(m.points.iter().flatten().flat_map(|x| x.to_be_bytes()));
    let size: usize = m.cells.iter().map(|(_, ids)| ids.len() + 1).sum();
    f.extend(format!("\nCELLS {} {size}\n", m.cells.len()).bytes());
    for (_, ids) in &m.cells {
        f.extend((ids.len() as i32).to_be_bytes());
        f.extend(ids.iter().flat_map(|&i| (i as i32).to_be_bytes()));
    }
    f.extend(format!("\nCELL_TYPES {}\n", m.cells.len()).bytes());
    f.extend(m.cells.iter().flat_map(|(t, _)| i32::from(*t).to_be_bytes()));
    f.extend(format!("\nPOINT_DATA {}\nVECTORS vec float\n", m.points.len()).bytes());
    f.extend(vec_data(m).iter().flat_map(|x| x.to_be_bytes()));
    f.extend(b"\nSCALARS p double 1\nLOOKUP_TABLE default\n");
    f.extend(m.p.iter().flat_map(|x| x.to_be_bytes()));
    f.extend(
        format!("\nCELL_DATA {}\nSCALARS c float 1\nLOOKUP_TABLE default\n", m.cells.len()).bytes(),
    );
    f.extend(m.c.iter().flat_map(|x| x.to_be_bytes()));
    f.push(b'\n');
    f
}

/// How a `.vtu` file stores its arrays.
#[derive(Clone, Copy, Debug)]
enum Xml {
    Ascii,
    /// Inline base64 with `UInt64` block headers (`header_type` given).
    Base64,
    /// Inline base64 with `UInt32` block headers and no `header_type`
    /// attribute (VTK's default, as older files have it).
    Base64NoHeaderType,
    /// Raw bytes in an `AppendedData` element, `UInt32` headers.
    AppendedRaw,
    /// Base64 in an `AppendedData` element (each block's header and data
    /// encoded as one, as VTK writes them), big-endian, `UInt64` headers.
    AppendedBase64,
}

const XML_FORMATS: [Xml; 5] =
    [Xml::Ascii, Xml::Base64, Xml::Base64NoHeaderType, Xml::AppendedRaw, Xml::AppendedBase64];

/// One XML data array: VTK type name, name, components, text (for ASCII)
/// and bytes (in the file's byte order).
struct Array {
    ty: &'static str,
    name: &'static str,
    comps: usize,
    text: String,
    bytes: Vec<u8>,
}

fn array<T: ToString + Copy>(
    ty: &'static str,
    name: &'static str,
    comps: usize,
    v: &[T],
    to_bytes: impl Fn(T) -> Vec<u8>,
) -> Array {
    Array {
        ty,
        name,
        comps,
        text: join(v.iter().copied()),
        bytes: v.iter().flat_map(|&x| to_bytes(x)).collect(),
    }
}

fn vtu(m: &Mesh, how: Xml) -> Vec<u8> {
    let mut offsets = Vec::new();
    let mut end = 0i64;
    for (_, ids) in &m.cells {
        end += ids.len() as i64;
        offsets.push(end);
    }
    let conn: Vec<i64> = m.cells.iter().flat_map(|(_, ids)| ids.iter().copied()).collect();
    let types: Vec<u8> = m.cells.iter().map(|(t, _)| *t).collect();
    let pts: Vec<f64> = m.points.iter().flatten().copied().collect();
    let be = matches!(how, Xml::AppendedBase64);
    macro_rules! bytes {
        () => {
            |x| if be { x.to_be_bytes().to_vec() } else { x.to_le_bytes().to_vec() }
        };
    }
    let sections: [(&str, Vec<Array>); 4] = [
        (
            "PointData Scalars=\"p\"",
            vec![
                array("Float32", "vec", 3, &vec_data(m), bytes!()),
                array("Float64", "p", 1, &m.p, bytes!()),
            ],
        ),
        ("CellData", vec![array("Float32", "c", 1, &m.c, bytes!())]),
        ("Points", vec![array("Float64", "", 3, &pts, bytes!())]),
        (
            "Cells",
            vec![
                array("Int64", "connectivity", 1, &conn, bytes!()),
                array("Int64", "offsets", 1, &offsets, bytes!()),
                array("UInt8", "types", 1, &types, |x| vec![x]),
            ],
        ),
    ];
    let header_type = match how {
        Xml::Base64 | Xml::AppendedBase64 => " header_type=\"UInt64\"",
        Xml::Base64NoHeaderType => "",
        Xml::Ascii | Xml::AppendedRaw => " header_type=\"UInt32\"",
    };
    let order = if be { "BigEndian" } else { "LittleEndian" };
    let mut s = format!(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
         byte_order=\"{order}\"{header_type}>\n<UnstructuredGrid>\n\
         <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
        m.points.len(),
        m.cells.len()
    );
    let mut appended = Vec::new();
    for (section, arrays) in &sections {
        s += &format!("<{section}>\n");
        for a in arrays {
            let name =
                if a.name.is_empty() { String::new() } else { format!(" Name=\"{}\"", a.name) };
            let head =
                format!("<DataArray type=\"{}\"{name} NumberOfComponents=\"{}\"", a.ty, a.comps);
            s += &match how {
                Xml::Ascii => format!("{head} format=\"ascii\">\n{}\n</DataArray>\n", a.text),
                Xml::Base64 => {
                    let mut block = (a.bytes.len() as u64).to_le_bytes().to_vec();
                    block.extend(&a.bytes);
                    format!("{head} format=\"binary\">\n{}\n</DataArray>\n", base64(&block))
                }
                Xml::Base64NoHeaderType => {
                    let mut block = (a.bytes.len() as u32).to_le_bytes().to_vec();
                    block.extend(&a.bytes);
                    format!("{head} format=\"binary\">\n{}\n</DataArray>\n", base64(&block))
                }
                Xml::AppendedRaw => {
                    let offset = appended.len();
                    appended.extend((a.bytes.len() as u32).to_le_bytes());
                    appended.extend(&a.bytes);
                    format!("{head} format=\"appended\" offset=\"{offset}\"/>\n")
                }
                Xml::AppendedBase64 => {
                    let offset = appended.len();
                    let mut block = (a.bytes.len() as u64).to_be_bytes().to_vec();
                    block.extend(&a.bytes);
                    appended.extend(base64(&block).bytes());
                    format!("{head} format=\"appended\" offset=\"{offset}\">\n</DataArray>\n")
                }
            };
        }
        let close = section.split(' ').next().unwrap();
        s += &format!("</{close}>\n");
    }
    s += "</Piece>\n</UnstructuredGrid>\n";
    let mut f = s.into_bytes();
    if let Xml::AppendedRaw | Xml::AppendedBase64 = how {
        let encoding = if be { "base64" } else { "raw" };
        f.extend(format!("<AppendedData encoding=\"{encoding}\">\n_").bytes());
        f.extend(&appended);
        f.extend(b"\n</AppendedData>\n");
    }
    f.extend(b"</VTKFile>\n");
    f
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in bytes.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            let ch = if k <= c.len() { A[(n >> (18 - 6 * k) & 63) as usize] } else { b'=' };
            s.push(char::from(ch));
        }
    }
    s
}

// ---- Helpers -------------------------------------------------------------

/// A fresh directory for one test's files, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(test: &str) -> Self {
        let dir =
            std::env::temp_dir().join(format!("rt-volume-ugrid-{test}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }

    fn write(&self, name: &str, bytes: &[u8]) -> PathBuf {
        let path = self.0.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

/// Every format of `m`: a file name and its bytes.
fn every_format(m: &Mesh) -> Vec<(String, Vec<u8>)> {
    let mut v = vec![
        ("ascii.vtk".to_string(), legacy_ascii(m)),
        ("binary.vtk".to_string(), legacy_binary(m)),
    ];
    for how in XML_FORMATS {
        v.push((format!("{how:?}.vtu").to_lowercase(), vtu(m, how)));
    }
    v
}

fn kind<T: core::fmt::Debug>(r: Result<T, ReadError>) -> ReadErrorKind {
    r.unwrap_err().into_kind()
}

/// The error's message, checked to be `Malformed`.
fn malformed<T: core::fmt::Debug>(r: Result<T, ReadError>) -> String {
    let e = r.unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Malformed { .. }), "{e:?}");
    e.to_string()
}

/// The point values: the plain mean of the volume cells' values around
/// each point (0 where none), by brute force.
fn averaged(m: &Mesh) -> Vec<f64> {
    (0..m.points.len() as i64)
        .map(|p| {
            let around: Vec<f64> = m
                .cells
                .iter()
                .zip(&m.c)
                .filter(|((t, ids), _)| *t >= 10 && ids.contains(&p))
                .map(|(_, &c)| f64::from(c))
                .collect();
            if around.is_empty() { 0.0 } else { around.iter().sum::<f64>() / around.len() as f64 }
        })
        .collect()
}

// ---- Tests ---------------------------------------------------------------

/// Every format reads as the same points, cells (VTK order, the voxel
/// reordered into a hexahedron), values and skipped triangle.
#[test]
fn every_format_reads_the_mesh_exactly() {
    let dir = TempDir::new("formats");
    let m = mesh();
    let points: Vec<DVec3> = m.points.iter().map(|&q| DVec3::from(q)).collect();
    for (name, bytes) in every_format(&m) {
        let path = dir.write(&name, &bytes);
        assert!(is_unstructured(&path), "{name}");
        let d = read_unstructured(&path, None).unwrap_or_else(|e| panic!("{name}: {e}"));
        let want = UnstructuredData {
            points: points.clone(),
            cells: expected_cells(),
            values: m.p.clone(),
            array: "p".into(),
            from_cells: false,
            skipped_cells: 1,
        };
        assert_eq!(d, want, "{name}");
        // The same file's cell data, averaged to the points.
        let d = read_unstructured(&path, Some("c")).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(d.from_cells && d.array == "c", "{name}");
        assert_eq!(d.values, averaged(&m), "{name}");
    }
}

/// Files written by `vtkio` itself (legacy big-endian binary, XML inline
/// base64) read the same.
#[test]
fn files_written_by_vtkio_read_the_same() {
    use vtkio::model::{
        Attribute, Attributes, CellType, Cells, DataSet, UnstructuredGridPiece, Version,
        VertexNumbers, Vtk,
    };
    let dir = TempDir::new("vtkio");
    let m = mesh();
    let mut vertices = Vec::new();
    for (_, ids) in &m.cells {
        vertices.push(ids.len() as u32);
        vertices.extend(ids.iter().map(|&i| i as u32));
    }
    let types = m.cells.iter().map(|(t, _)| num_cell_type(*t)).collect::<Vec<CellType>>();
    let vtk = Vtk {
        version: Version::new((4, 1)),
        title: "rt test mesh".into(),
        byte_order: vtkio::model::ByteOrder::BigEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: m.points.iter().flatten().copied().collect::<Vec<f64>>().into(),
            cells: Cells {
                cell_verts: VertexNumbers::Legacy { num_cells: m.cells.len() as u32, vertices },
                types,
            },
            data: Attributes {
                point: vec![Attribute::scalars("p", 1).with_data(m.p.clone())],
                cell: vec![Attribute::scalars("c", 1).with_data(m.c.clone())],
            },
        }),
    };
    for name in ["vtkio.vtk", "vtkio.vtu"] {
        let path = dir.0.join(name);
        vtk.clone().export(&path).unwrap();
        let d = read_unstructured(&path, None).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(d.cells, expected_cells(), "{name}");
        assert_eq!(d.values, m.p, "{name}");
        assert_eq!(d.points[12], DVec3::new(0.5, 0.5, 2.0), "{name}");
        assert_eq!(d.skipped_cells, 1, "{name}");
        let d = read_unstructured(&path, Some("c")).unwrap();
        assert_eq!(d.values, averaged(&m), "{name}");
    }
}

fn num_cell_type(t: u8) -> vtkio::model::CellType {
    use vtkio::model::CellType::*;
    match t {
        5 => Triangle,
        10 => Tetra,
        11 => Voxel,
        12 => Hexahedron,
        13 => Wedge,
        14 => Pyramid,
        24 => QuadraticTetra,
        _ => unreachable!(),
    }
}

/// Raw appended bytes that look like markup (`<`, `</`) are data: the
/// payload is never read as XML.
#[test]
fn appended_raw_bytes_may_look_like_markup() {
    let dir = TempDir::new("markup");
    let mut m = mesh();
    m.p[0] = f64::from_bits(0x3FF0_0000_0000_003C);
    m.p[1] = f64::from_bits(0x3FF0_0000_3C2F_3C2F);
    m.p[2] = f64::from_bits(0x3FF0_003E_3C21_2D2D);
    let bytes = vtu(&m, Xml::AppendedRaw);
    assert!(bytes.windows(2).filter(|w| w == b"</").count() > 6, "markup-like payload");
    let d = read_unstructured(&dir.write("lt.vtu", &bytes), None).unwrap();
    assert_eq!(d.values, m.p);
    assert_eq!(d.cells, expected_cells());
}

/// Cell data averaged to points: a point shared by cells gets their mean,
/// a point in one cell its value, a point in none 0; with no scalar point
/// data the first scalar cell array is taken.
#[test]
fn cell_data_is_averaged_to_points() {
    let dir = TempDir::new("average");
    let m = mesh();
    let path = dir.write("m.vtu", &vtu(&m, Xml::Ascii));
    let d = read_unstructured(&path, Some("c")).unwrap();
    assert_eq!(d.values[0], 2.5, "hexahedron 1 and tetrahedron 4");
    assert_eq!(d.values[1], 3.0, "hexahedron 1 and voxel 5 (the triangle is no volume)");
    assert_eq!(d.values[6], 2.75, "hexahedron, wedge, pyramid, voxel");
    assert_eq!(d.values[12], 3.0, "the pyramid's apex");
    assert_eq!(d.values[15], 4.0, "the tetrahedron's own point");
    assert_eq!(d.values[16], 0.0, "in no cell");
    // Only cell data: chosen with no name.
    let only_cells = legacy_ascii(&m);
    let text = String::from_utf8(only_cells).unwrap();
    let cut = text.find("POINT_DATA").unwrap()..text.find("CELL_DATA").unwrap();
    let path = dir.write("cells.vtk", text.replace(&text[cut], "").as_bytes());
    let d = read_unstructured(&path, None).unwrap();
    assert!(d.from_cells && d.array == "c");
    assert_eq!(d.values, averaged(&m));
}

/// Choosing arrays: point data before cell data of the same name; a
/// vector array named is refused; a missing name lists what there is.
#[test]
fn arrays_are_chosen_by_name() {
    let dir = TempDir::new("choice");
    let m = mesh();
    let text = String::from_utf8(legacy_ascii(&m)).unwrap();
    // Rename the cell array `p` too: the point array wins.
    let path = dir.write("both.vtk", text.replace("SCALARS c float", "SCALARS p float").as_bytes());
    let d = read_unstructured(&path, Some("p")).unwrap();
    assert!(!d.from_cells);
    assert_eq!(d.values, m.p);
    let path = dir.write("m.vtk", text.as_bytes());
    let e = read_unstructured(&path, Some("vec")).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Unsupported(_)), "{e:?}");
    assert!(e.to_string().contains("3 components"), "{e}");
    let msg = malformed(read_unstructured(&path, Some("rho")));
    for name in ["`rho`", "`p`", "`vec`", "`c`"] {
        assert!(msg.contains(name), "{name} in {msg}");
    }
    // No scalar at all: only the vector array.
    let cut = text.find("SCALARS p").unwrap()..text.len();
    let path = dir.write("vec.vtk", text.replace(&text[cut], "").as_bytes());
    let msg = malformed(read_unstructured(&path, None));
    assert!(msg.contains("no scalar") && msg.contains("`vec`"), "{msg}");
}

/// `is_unstructured` by extension and legacy header.
#[test]
fn is_unstructured_reads_the_header() {
    let dir = TempDir::new("detect");
    let m = mesh();
    assert!(is_unstructured(Path::new("/nonexistent/a.vtu")));
    assert!(is_unstructured(Path::new("/nonexistent/a.VTU")));
    assert!(!is_unstructured(Path::new("/nonexistent/a.vtk")));
    assert!(!is_unstructured(Path::new("/nonexistent/a.vti")));
    assert!(is_unstructured(&dir.write("u.vtk", &legacy_binary(&m))));
    let sp = b"# vtk DataFile Version 3.0\nDATASET UNSTRUCTURED_GRID in the title\nASCII\n\
               DATASET STRUCTURED_POINTS\nDIMENSIONS 2 2 2\nORIGIN 0 0 0\nSPACING 1 1 1\n\
               POINT_DATA 8\nSCALARS n float 1\nLOOKUP_TABLE default\n1 1 1 1 1 1 1 1\n";
    let sp = dir.write("sp.vtk", sp);
    assert!(!is_unstructured(&sp));
    assert!(read_grid(&sp).is_ok());
    // The grid reader points an unstructured grid here.
    let e = read_grid(&dir.write("u2.vtk", &legacy_ascii(&m))).unwrap_err();
    assert!(e.to_string().contains("read_unstructured"), "{e}");
    // And this reader refuses other data sets.
    assert!(matches!(kind(read_unstructured(&sp, None)), ReadErrorKind::Unsupported(_)));
}

/// Cell types that are not linear volume cells, bad connectivity and
/// non-finite numbers: errors naming the cell or the value, in every
/// format.
#[test]
fn bad_cells_and_values_are_errors() {
    let dir = TempDir::new("bad");
    let check = |m: Mesh, what: &str, want: &[&str], unsupported: bool| {
        for (name, bytes) in every_format(&m) {
            let path = dir.write(&name, &bytes);
            let e = read_unstructured(&path, None).unwrap_err();
            let msg = e.to_string();
            if unsupported {
                assert!(matches!(e.kind(), ReadErrorKind::Unsupported(_)), "{what}, {name}: {e:?}");
            } else {
                assert!(
                    matches!(e.kind(), ReadErrorKind::Malformed { .. }),
                    "{what}, {name}: {e:?}"
                );
            }
            for w in want {
                assert!(msg.contains(w), "{what}, {name}: `{w}` in {msg}");
            }
            assert_eq!(e.path(), Some(path.as_path()));
        }
    };
    // A quadratic tetrahedron (10 points).
    let mut m = mesh();
    m.cells[3] = (24, vec![0, 3, 4, 15, 1, 2, 5, 6, 7, 8]);
    check(m, "quadratic", &["cell type 24", "cell 3"], true);
    let mut m = mesh();
    m.cells[2].1[4] = 17;
    check(m, "index past the end", &["cell 2", "index 17"], false);
    let mut m = mesh();
    m.cells[1].1.pop();
    check(m, "wedge of 5 points", &["cell 1", "5 points"], false);
    // Non-finite numbers (legacy ASCII `NaN`, `inf` are no numbers to
    // vtkio: parse errors there).
    let mut nan = mesh();
    nan.p[7] = f64::NAN;
    let mut inf = mesh();
    inf.points[9][1] = f64::INFINITY;
    for (m, want) in [(nan, "value 7"), (inf, "point 9")] {
        for (name, bytes) in every_format(&m) {
            let msg = malformed(read_unstructured(&dir.write(&name, &bytes), None));
            assert!(name == "ascii.vtk" || msg.contains(want), "{name}: `{want}` in {msg}");
        }
    }
    // Only the triangle: no volume.
    let mut m = mesh();
    m.cells.truncate(0);
    m.cells.push((5, vec![0, 1, 2]));
    m.c.truncate(1);
    check(m, "no volume cells", &["without volume cells", "1 lower-dimensional"], false);
}

/// Negative point indices: the legacy binary's `-1` and XML's `Int64 -1`.
#[test]
fn negative_indices_are_errors() {
    let dir = TempDir::new("negative");
    let mut m = mesh();
    m.cells[0].1[0] = -1;
    for (name, bytes) in every_format(&m) {
        let path = dir.write(&name, &bytes);
        let e = read_unstructured(&path, None).unwrap_err();
        assert!(matches!(e.kind(), ReadErrorKind::Malformed { .. }), "{name}: {e:?}");
    }
    let path = dir.write("neg.vtk", &legacy_binary(&m));
    assert!(malformed(read_unstructured(&path, None)).contains("cell 0"));
}

/// Truncated files, garbage, empty files, absurd sizes, compressed XML and
/// unknown extensions: errors, and no cut of any file panics.
#[test]
fn broken_files_are_errors_never_panics() {
    let dir = TempDir::new("broken");
    let m = mesh();
    for (name, bytes) in every_format(&m) {
        let path = dir.write(&name, &bytes[..bytes.len() / 2]);
        malformed(read_unstructured(&path, None));
        // Cuts all along: an `Err`, or a shorter valid file read
        // consistently.
        for len in (0..bytes.len()).step_by(3) {
            let path = dir.write(&name, &bytes[..len]);
            if let Ok(d) = read_unstructured(&path, None) {
                assert_eq!(d.values.len(), d.points.len(), "{name} cut at {len}");
            }
        }
        // Garbage and emptiness.
        let garbage: Vec<u8> =
            (0..500u32).map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8).collect();
        malformed(read_unstructured(&dir.write(&name, &garbage), None));
        malformed(read_unstructured(&dir.write(&name, b""), None));
    }
    // A legacy header declaring billions of values is refused before any
    // memory is reserved for them.
    let text = String::from_utf8(legacy_ascii(&m)).unwrap();
    for (prefix, decl) in [
        ("POINTS", "POINTS 4000000000 double"),
        ("CELLS", "CELLS 6 4000000000"),
        ("CELL_TYPES", "CELL_TYPES 4000000000"),
        ("POINT_DATA", "POINT_DATA 4000000000"),
        ("SCALARS p", "SCALARS p double 4000000000"),
        ("VECTORS", "FIELD f 1\nvec 3 4000000000 float"),
    ] {
        let lines: Vec<&str> =
            text.lines().map(|l| if l.starts_with(prefix) { decl } else { l }).collect();
        let path = dir.write("huge.vtk", lines.join("\n").as_bytes());
        let msg = malformed(read_unstructured(&path, None));
        assert!(msg.contains("4000000000") && msg.contains("bytes hold"), "{msg}");
        // The grid reader checks the same way.
        assert!(read_grid(&path).is_err());
    }
    // Compressed XML: unsupported (as the grid reader has it).
    let text = String::from_utf8(vtu(&m, Xml::Base64)).unwrap();
    let z = text.replace("header_type=", "compressor=\"vtkZLibDataCompressor\" header_type=");
    let e = read_unstructured(&dir.write("z.vtu", z.as_bytes()), None).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Unsupported(_)), "{e:?}");
    assert!(e.to_string().contains("compressed"), "{e}");
    // Files that are not there, or not these formats.
    let e = read_unstructured(Path::new("/nonexistent/u.vtu"), None).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Io(_)), "{e:?}");
    let e = read_unstructured(&dir.write("u.vti", &vtu(&m, Xml::Ascii)), None).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::UnknownFormat), "{e:?}");
}
