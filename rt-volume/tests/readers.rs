//! File readers (feature `io`): the project's real CFD data, and every kind
//! of malformed input as an `Err`.
#![cfg(feature = "io")]

use std::path::{Path, PathBuf};

use glam::DVec3;
use rt_volume::io::{ReadError, ReadErrorKind, parse_nrrd, read_grid};

/// The repository's copy of the project's real CFD data (the main job
/// embeds it): raw payload, JSON sidecar and a detached NRRD header.
fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../rt-tools/data").join(name)
}

/// The blast wave through every form: detached NRRD header, the same header
/// with the payload attached (as the original `.nrrd` file has it), and the
/// raw payload with its JSON sidecar: same geometry and samples, the
/// statistics its provenance records (min, max, mean).
#[test]
fn blast_wave_reads_identically_from_nrrd_and_raw_json() {
    let a = read_grid(&data("blast_sedov_64.nhdr")).expect("detached nrrd");
    let b = read_grid(&data("blast_sedov_64.json")).expect("raw + json");
    assert_eq!(a, b);
    let header = std::fs::read_to_string(data("blast_sedov_64.nhdr")).unwrap();
    let header: String =
        header.lines().filter(|l| !l.starts_with("data file")).map(|l| format!("{l}\n")).collect();
    let mut attached = header.into_bytes();
    attached.extend(std::fs::read(data("blast_sedov_64.raw")).unwrap());
    assert_eq!(parse_nrrd(&attached, None).expect("attached nrrd"), a);
    assert_eq!(a.dims(), [64, 64, 64]);
    assert_eq!(a.spacing(), DVec3::splat(0.015625));
    assert_eq!(a.origin(), DVec3::splat(-0.4921875));
    let b = a.bounds();
    assert_eq!((b.min, b.max), (DVec3::splat(-0.5), DVec3::splat(0.5)));
    let d = a.data();
    let (min, max) = d.iter().fold((f32::MAX, f32::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)));
    let mean = d.iter().map(|&v| f64::from(v)).sum::<f64>() / d.len() as f64;
    assert!((min - 0.018_673_161).abs() < 1e-8 && (max - 2.849_521_6).abs() < 1e-6);
    assert!((mean - 1.0).abs() < 1e-6, "mass conserved: mean {mean}");
}

/// What went wrong, for a result that must be an error.
fn kind<T: core::fmt::Debug>(r: Result<T, ReadError>) -> ReadErrorKind {
    r.unwrap_err().into_kind()
}

fn header(body: &str) -> Vec<u8> {
    let mut v = format!("NRRD0004\n{body}\n\n").into_bytes();
    v.extend([0u8; 8 * 4]);
    v
}

/// Malformed NRRD headers and payloads are errors naming the problem.
#[test]
fn malformed_nrrd_is_an_error() {
    let ok = "type: float\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nendian: little";
    assert!(parse_nrrd(&header(ok), None).is_ok());
    for bytes in [&b"P6 not nrrd"[..], b"NRRD0004\ntype: float"] {
        let e = parse_nrrd(bytes, None).unwrap_err();
        assert!(matches!(e.kind(), ReadErrorKind::Malformed { .. }), "{e}");
    }
    for (body, want) in [
        ("type: float\ndimension: 2\nsizes: 2 2\nencoding: raw", "dimension"),
        ("type: complex\ndimension: 3\nsizes: 2 2 2\nencoding: raw", "type"),
        ("type: float\ndimension: 3\nsizes: 2 2 2\nencoding: gzip", "encoding"),
        ("type: float\ndimension: 3\nsizes: 2 x 2\nencoding: raw", "sizes"),
        ("dimension: 3\nsizes: 2 2 2\nencoding: raw", "type"),
        ("type: float\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspacings: 1 nan", "spacings"),
        ("type: float\ndimension: 3\nencoding: raw", "sizes"),
    ] {
        let e = parse_nrrd(&header(body), None).unwrap_err();
        assert!(e.to_string().contains(want), "{body:?}: {e}");
    }
    // Truncated payload, and counts that overflow.
    let mut short = header(ok);
    short.truncate(short.len() - 3);
    assert!(matches!(
        kind(parse_nrrd(&short, None)),
        ReadErrorKind::Truncated { expected: 32, found: 29 }
    ));
    let huge =
        header("type: float\ndimension: 3\nsizes: 4294967296 4294967296 4294967296\nencoding: raw");
    assert!(matches!(kind(parse_nrrd(&huge, None)), ReadErrorKind::TooLarge));
    // NaN samples.
    let mut nan = header(ok);
    let n = nan.len();
    nan[n - 4..].copy_from_slice(&f32::NAN.to_le_bytes());
    assert!(matches!(
        kind(parse_nrrd(&nan, None)),
        ReadErrorKind::Grid(rt_volume::GridError::NonFinite { index: 7 })
    ));
    // Zero spacing.
    let zero = header("type: float\ndimension: 3\nsizes: 2 2 2\nencoding: raw\nspacings: 1 0 1");
    assert!(matches!(
        kind(parse_nrrd(&zero, None)),
        ReadErrorKind::Grid(rt_volume::GridError::BadGeometry)
    ));
}

/// Missing files and bad JSON headers are errors too.
#[test]
fn missing_files_and_bad_json_are_errors() {
    let missing = Path::new("/nonexistent/x.nrrd");
    let e = read_grid(missing).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Io(io) if io.kind() == std::io::ErrorKind::NotFound));
    assert_eq!(e.path(), Some(missing));
    assert!(e.to_string().starts_with("/nonexistent/x.nrrd: "), "{e}");
    assert!(core::error::Error::source(&e).is_some(), "the I/O error is the source");
    let e = read_grid(Path::new("x.vtu")).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::UnknownFormat));
    assert!(e.to_string().starts_with("x.vtu: unknown grid format"), "{e}");
    // A detached NRRD header whose payload file is missing names that file.
    let dir = std::env::temp_dir().join(format!("rt-volume-detached-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let nhdr = dir.join("h.nhdr");
    std::fs::write(
        &nhdr,
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: gone.raw\n\n",
    )
    .unwrap();
    let e = read_grid(&nhdr).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Io(_)), "{e:?}");
    assert_eq!(e.path(), Some(dir.join("gone.raw").as_path()));
    // A bad header names the header file.
    std::fs::write(&nhdr, "NRRD0004\ntype: float\n").unwrap();
    let e = read_grid(&nhdr).unwrap_err();
    assert_eq!(e.path(), Some(nhdr.as_path()));
    assert!(e.to_string().starts_with(&format!("{}: malformed header", nhdr.display())), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
    let v: serde_json::Value =
        serde_json::json!({"dims": [2, 2], "spacing": [1, 1, 1], "origin": [0, 0, 0]});
    assert!(rt_volume::io::parse_raw_json(&v, &[0; 32]).is_err());
    let v: serde_json::Value =
        serde_json::json!({"dims": [2, 2, 2], "spacing": [1, 1, 1], "origin": [0, 0, 0]});
    assert!(rt_volume::io::parse_raw_json(&v, &[0; 32]).is_ok());
    assert!(matches!(
        kind(rt_volume::io::parse_raw_json(&v, &[0; 31])),
        ReadErrorKind::Truncated { .. }
    ));
    let v: serde_json::Value = serde_json::json!({"dims": [2, 2, 2], "dtype": "complex64", "spacing": [1, 1, 1], "origin": [0, 0, 0]});
    assert!(matches!(
        kind(rt_volume::io::parse_raw_json(&v, &[0; 32])),
        ReadErrorKind::Unsupported(_)
    ));
}

/// Legacy VTK structured points: geometry and samples as written; other data
/// sets and garbage are errors.
#[test]
fn vtk_structured_points() {
    let dir = std::env::temp_dir().join(format!("rt-volume-vtk-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("sp.vtk");
    let values: Vec<String> = (0..24).map(|i| format!("{}", 1.0 + 0.01 * f64::from(i))).collect();
    std::fs::write(
        &good,
        format!(
            "# vtk DataFile Version 3.0\nrt test\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 3 2\nORIGIN 0.5 -1 2\nSPACING 0.25 0.5 1\nPOINT_DATA 24\nSCALARS n float 1\nLOOKUP_TABLE default\n{}\n",
            values.join(" ")
        ),
    )
    .unwrap();
    let g = read_grid(&good).expect("structured points");
    assert_eq!(g.dims(), [4, 3, 2]);
    assert_eq!(g.origin(), DVec3::new(0.5, -1.0, 2.0));
    assert_eq!(g.spacing(), DVec3::new(0.25, 0.5, 1.0));
    assert_eq!(g.data()[23], 1.23);
    let bad = dir.join("bad.vtk");
    std::fs::write(
        &bad,
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 3\n",
    )
    .unwrap();
    assert!(matches!(kind(read_grid(&bad)), ReadErrorKind::Malformed { .. }));
    let poly = dir.join("poly.vtk");
    std::fs::write(
        &poly,
        "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 1 float\n0 0 0\n",
    )
    .unwrap();
    assert!(matches!(kind(read_grid(&poly)), ReadErrorKind::Unsupported(_)));
    let nan = dir.join("nan.vtk");
    let mut v = values.clone();
    v[5] = "nan".into();
    std::fs::write(
        &nan,
        format!(
            "# vtk DataFile Version 3.0\nrt test\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 4 3 2\nORIGIN 0 0 0\nSPACING 1 1 1\nPOINT_DATA 24\nSCALARS n float 1\nLOOKUP_TABLE default\n{}\n",
            v.join(" ")
        ),
    )
    .unwrap();
    assert!(read_grid(&nan).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

/// A brick of the blast wave read on its own (`read_raw_json_box`): the
/// same samples, bit for bit, as the same box of the whole grid, at the
/// same positions; empty or out-of-range boxes and a payload of the wrong
/// length are errors.
#[test]
fn a_box_of_a_raw_volume_is_that_box_of_the_whole() {
    let whole = read_grid(&data("blast_sedov_64.json")).unwrap();
    let (lo, hi) = ([3, 17, 40], [35, 20, 64]);
    let part = rt_volume::io::read_raw_json_box(&data("blast_sedov_64.json"), lo, hi).unwrap();
    assert_eq!(part.dims(), [32, 3, 24]);
    assert_eq!(part.spacing(), whole.spacing());
    assert_eq!(part.origin(), whole.origin() + whole.spacing() * DVec3::new(3.0, 17.0, 40.0));
    let [nx, ny, _] = whole.dims();
    for k in 0..24 {
        for j in 0..3 {
            for i in 0..32 {
                let w = whole.data()[(i + 3) + nx * ((j + 17) + ny * (k + 40))];
                assert_eq!(part.data()[i + 32 * (j + 3 * k)].to_bits(), w.to_bits());
            }
        }
    }
    let json = data("blast_sedov_64.json");
    for (lo, hi) in [([0, 0, 0], [0, 4, 4]), ([0, 0, 60], [4, 4, 65]), ([5, 0, 0], [4, 4, 4])] {
        assert!(matches!(
            kind(rt_volume::io::read_raw_json_box(&json, lo, hi)),
            ReadErrorKind::Malformed { .. }
        ));
    }
    // A payload one sample short.
    let dir = std::env::temp_dir().join(format!("rt-volume-box-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let raw = std::fs::read(data("blast_sedov_64.raw")).unwrap();
    std::fs::write(dir.join("blast_sedov_64.raw"), &raw[..raw.len() - 4]).unwrap();
    std::fs::copy(&json, dir.join("b.json")).unwrap();
    let e = rt_volume::io::read_raw_json_box(&dir.join("b.json"), [0; 3], [2; 3]).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Truncated { .. }), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A brick of a volume larger than a `Grid` may hold (2³⁶ samples, a
/// sparse 256 GiB payload the file system never writes): read in a moment,
/// because only the brick's rows are read.
#[test]
fn a_box_of_a_volume_too_large_to_load_reads_only_its_rows() {
    let dir = std::env::temp_dir().join(format!("rt-volume-huge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let n = 4096usize;
    let payload = dir.join("huge.raw");
    let f = std::fs::File::create(&payload).unwrap();
    if f.set_len((n * n * n * 4) as u64).is_err() {
        // No sparse file this large here: nothing to show.
        std::fs::remove_dir_all(&dir).unwrap();
        return;
    }
    // One sample set, at (100, 200, 300).
    let at = ((100 + n * (200 + n * 300)) * 4) as u64;
    std::io::Seek::seek(&mut &f, std::io::SeekFrom::Start(at)).unwrap();
    std::io::Write::write_all(&mut &f, &2.5f32.to_le_bytes()).unwrap();
    drop(f);
    let json = dir.join("huge.json");
    std::fs::write(
        &json,
        r#"{"dims": [4096, 4096, 4096], "dtype": "float32", "spacing": [1, 1, 1], "origin": [0, 0, 0], "file": "huge.raw"}"#,
    )
    .unwrap();
    assert!(matches!(kind(read_grid(&json)), ReadErrorKind::TooLarge));
    let brick = rt_volume::io::read_raw_json_box(&json, [96, 196, 296], [104, 204, 304]).unwrap();
    assert_eq!(brick.dims(), [8; 3]);
    assert_eq!(brick.data()[4 + 8 * (4 + 8 * 4)], 2.5);
    assert_eq!(brick.data().iter().filter(|&&v| v != 0.0).count(), 1);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The box `lo..hi` of a whole grid, as the box readers return it.
fn cut(whole: &rt_volume::Grid, lo: [usize; 3], hi: [usize; 3]) -> rt_volume::Grid {
    let [nx, ny, _] = whole.dims();
    let mut data = Vec::new();
    for k in lo[2]..hi[2] {
        for j in lo[1]..hi[1] {
            let row = nx * (j + ny * k);
            data.extend_from_slice(&whole.data()[row + lo[0]..row + hi[0]]);
        }
    }
    let origin =
        whole.origin() + whole.spacing() * DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64);
    let dims = [0, 1, 2].map(|a| hi[a] - lo[a]);
    rt_volume::Grid::new(dims, origin, whole.spacing(), data).unwrap()
}

fn bit_equal(a: &rt_volume::Grid, b: &rt_volume::Grid) {
    assert_eq!((a.dims(), a.origin(), a.spacing()), (b.dims(), b.origin(), b.spacing()));
    let bits = |g: &rt_volume::Grid| g.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(a), bits(b));
}

/// A scratch directory, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("rt-volume-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

/// A box of a NRRD volume (raw encoding; detached and attached data;
/// both byte orders; float, double and 16-bit samples) is that box of the
/// whole file's grid, bit for bit; its header alone gives the grid's
/// geometry; the dispatching readers pick NRRD and raw + JSON by
/// extension.
#[test]
fn a_box_of_a_nrrd_volume_is_that_box_of_the_whole() {
    use rt_volume::io::{read_grid_box, read_grid_info, read_nrrd_box};
    let dir = Scratch::new("nrrd-box");
    let dims = [7usize, 5, 6];
    let count = dims.iter().product::<usize>();
    let values: Vec<f64> =
        (0..count).map(|i| 1.0 + (i as f64 * 0.37).sin().abs() * 300.0).collect();
    let boxes = [
        ([0, 0, 0], [7, 5, 6]),
        ([2, 1, 3], [5, 4, 6]),
        ([6, 4, 5], [7, 5, 6]),
        ([0, 2, 0], [7, 3, 2]),
    ];
    for (ty, size) in [("float", 4), ("double", 8), ("ushort", 2)] {
        for endian in ["little", "big"] {
            let mut payload = Vec::new();
            for &v in &values {
                let bytes: Vec<u8> = match (ty, endian) {
                    ("float", "little") => (v as f32).to_le_bytes().to_vec(),
                    ("float", _) => (v as f32).to_be_bytes().to_vec(),
                    ("double", "little") => v.to_le_bytes().to_vec(),
                    ("double", _) => v.to_be_bytes().to_vec(),
                    (_, "little") => (v as u16).to_le_bytes().to_vec(),
                    _ => (v as u16).to_be_bytes().to_vec(),
                };
                payload.extend(bytes);
            }
            assert_eq!(payload.len(), count * size);
            let fields = format!(
                "NRRD0004\ntype: {ty}\ndimension: 3\nsizes: 7 5 6\nspacings: 0.5 0.25 2\n\
                 space origin: (1, -2, 0.5)\nendian: {endian}\nencoding: raw\n"
            );
            let name = format!("{ty}-{endian}");
            let raw = dir.0.join(format!("{name}.raw"));
            std::fs::write(&raw, &payload).unwrap();
            let nhdr = dir.0.join(format!("{name}.nhdr"));
            std::fs::write(&nhdr, format!("{fields}data file: {name}.raw\n\n")).unwrap();
            let nrrd = dir.0.join(format!("{name}.nrrd"));
            let mut attached = format!("{fields}\n").into_bytes();
            attached.extend(&payload);
            std::fs::write(&nrrd, attached).unwrap();
            for path in [&nhdr, &nrrd] {
                let whole = read_grid(path).unwrap();
                assert_eq!(whole.dims(), dims);
                assert_eq!(whole.origin(), DVec3::new(1.0, -2.0, 0.5));
                assert_eq!(read_grid_info(path).unwrap(), whole.info());
                for (lo, hi) in boxes {
                    let part = read_nrrd_box(path, lo, hi).unwrap();
                    bit_equal(&part, &cut(&whole, lo, hi));
                    bit_equal(&read_grid_box(path, lo, hi).unwrap(), &part);
                }
            }
        }
    }
    // The project's data: its detached header, and raw + JSON.
    let whole = read_grid(&data("blast_sedov_64.nhdr")).unwrap();
    let (lo, hi) = ([3, 17, 40], [35, 20, 64]);
    bit_equal(&read_nrrd_box(&data("blast_sedov_64.nhdr"), lo, hi).unwrap(), &cut(&whole, lo, hi));
    for name in ["blast_sedov_64.nhdr", "blast_sedov_64.json", "blast_sedov_64.raw"] {
        assert_eq!(read_grid_info(&data(name)).unwrap(), whole.info(), "{name}");
        bit_equal(&read_grid_box(&data(name), lo, hi).unwrap(), &cut(&whole, lo, hi));
    }
}

/// Boxes that do not fit, payloads of the wrong length, compressed
/// encodings, missing files and formats without a header of their own are
/// errors naming the problem.
#[test]
fn bad_nrrd_boxes_and_headers_are_errors() {
    use rt_volume::io::{read_grid_box, read_grid_info, read_nrrd_box, read_nrrd_info};
    let dir = Scratch::new("nrrd-bad");
    let fields = "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n";
    let payload = vec![0x3f_u8; 2 * 3 * 4 * 4];
    let write = |name: &str, bytes: &[u8]| {
        let p = dir.0.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    };
    let attached = |extra: &[u8]| {
        let mut v = format!("{fields}\n").into_bytes();
        v.extend(extra);
        v
    };
    let ok = write("ok.nrrd", &attached(&payload));
    assert!(read_nrrd_box(&ok, [0; 3], [2, 3, 4]).is_ok());
    for (lo, hi) in [
        ([0, 0, 0], [0, 3, 4]),
        ([0, 0, 0], [2, 3, 5]),
        ([1, 0, 0], [1, 1, 1]),
        ([3, 0, 0], [2, 3, 4]),
    ] {
        let e = read_nrrd_box(&ok, lo, hi).unwrap_err();
        assert!(matches!(e.kind(), ReadErrorKind::Malformed { .. }), "{lo:?}..{hi:?}: {e}");
    }
    // One byte short, one too many: attached and detached.
    let short = write("short.nrrd", &attached(&payload[1..]));
    let long = write("long.nrrd", &attached(&[&payload[..], &[0]].concat()));
    write("short.raw", &payload[1..]);
    let detached = write("short.nhdr", format!("{fields}data file: short.raw\n\n").as_bytes());
    for p in [&short, &long, &detached] {
        let e = read_nrrd_box(p, [0; 3], [1; 3]).unwrap_err();
        assert!(matches!(e.kind(), ReadErrorKind::Truncated { expected: 96, .. }), "{e}");
    }
    // Compressed: refused, saying why.
    let gz = write("gz.nrrd", &attached(&payload).replace_encoding());
    let e = read_nrrd_box(&gz, [0; 3], [1; 3]).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Unsupported(m) if m.contains("raw")), "{e}");
    // A detached file that is not there; a header without its blank line;
    // not NRRD at all.
    let gone = write("gone.nhdr", format!("{fields}data file: nowhere.raw\n\n").as_bytes());
    assert!(matches!(
        read_nrrd_box(&gone, [0; 3], [1; 3]).unwrap_err().kind(),
        ReadErrorKind::Io(_)
    ));
    assert!(read_nrrd_info(&gone).is_ok(), "the header alone reads no payload");
    let open = write("open.nrrd", fields.as_bytes());
    assert!(matches!(read_nrrd_info(&open).unwrap_err().kind(), ReadErrorKind::Malformed { .. }));
    let not = write("not.nrrd", b"P6\n\n");
    assert!(matches!(read_nrrd_info(&not).unwrap_err().kind(), ReadErrorKind::Malformed { .. }));
    let zero =
        write("zero.nhdr", b"NRRD0004\ntype: float\ndimension: 3\nsizes: 2 0 2\nencoding: raw\n\n");
    assert!(matches!(read_nrrd_info(&zero).unwrap_err().kind(), ReadErrorKind::Grid(_)));
    // Formats and extensions without a header reader.
    let vti = write("x.vti", b"<VTKFile/>");
    assert!(matches!(read_grid_info(&vti).unwrap_err().kind(), ReadErrorKind::Unsupported(_)));
    assert!(matches!(
        read_grid_box(&vti, [0; 3], [1; 3]).unwrap_err().kind(),
        ReadErrorKind::Unsupported(_)
    ));
    let txt = write("x.txt", b"");
    assert!(matches!(read_grid_info(&txt).unwrap_err().kind(), ReadErrorKind::UnknownFormat));
    let e = read_grid_info(Path::new("/nonexistent/x.json")).unwrap_err();
    assert!(matches!(e.kind(), ReadErrorKind::Io(_)) && e.path().is_some(), "{e}");
}

/// `encoding: raw` → `encoding: gzip` in a header's bytes.
trait ReplaceEncoding {
    fn replace_encoding(self) -> Vec<u8>;
}

impl ReplaceEncoding for Vec<u8> {
    fn replace_encoding(self) -> Vec<u8> {
        let at = self.windows(13).position(|w| w == b"encoding: raw").unwrap();
        [&self[..at], b"encoding: gzip", &self[at + 13..]].concat()
    }
}

/// A brick of an attached NRRD volume of 2³⁶ samples (a sparse 256 GiB
/// file): its header and rows only are read.
#[test]
fn a_box_of_a_huge_attached_nrrd_reads_only_its_rows() {
    let dir = Scratch::new("nrrd-huge");
    let n = 4096usize;
    let header = b"NRRD0005\ntype: float\ndimension: 3\nsizes: 4096 4096 4096\nendian: little\nencoding: raw\n\n";
    let path = dir.0.join("huge.nrrd");
    let f = std::fs::File::create(&path).unwrap();
    if f.set_len((header.len() + n * n * n * 4) as u64).is_err() {
        // No sparse file this large here: nothing to show.
        return;
    }
    std::io::Write::write_all(&mut &f, header).unwrap();
    let at = (header.len() + (100 + n * (200 + n * 300)) * 4) as u64;
    std::io::Seek::seek(&mut &f, std::io::SeekFrom::Start(at)).unwrap();
    std::io::Write::write_all(&mut &f, &2.5f32.to_le_bytes()).unwrap();
    drop(f);
    let info = rt_volume::io::read_grid_info(&path).unwrap();
    assert_eq!(info.dims, [4096; 3]);
    assert!(matches!(kind(read_grid(&path)), ReadErrorKind::TooLarge));
    let brick = rt_volume::io::read_nrrd_box(&path, [96, 196, 296], [104, 204, 304]).unwrap();
    assert_eq!(brick.dims(), [8; 3]);
    assert_eq!(brick.data()[4 + 8 * (4 + 8 * 4)], 2.5);
    assert_eq!(brick.data().iter().filter(|&&v| v != 0.0).count(), 1);
}
