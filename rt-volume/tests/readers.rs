//! File readers (feature `io`): the project's real CFD data, and every kind
//! of malformed input as an `Err`.
#![cfg(feature = "io")]

use std::path::{Path, PathBuf};

use glam::DVec3;
use rt_volume::io::{ReadError, ReadErrorKind, parse_nrrd, read_grid};

/// The repository's copy of the project's real CFD data (the main job
/// embeds it): raw payload, JSON sidecar and a detached NRRD header.
fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../rt-cli/data").join(name)
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
