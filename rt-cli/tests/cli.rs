//! The `rt` binary as a user runs it: help, real files, bad files and bad
//! options — a one-line error and a non-zero exit, never a panic.

use std::{
    path::{Path, PathBuf},
    process::{Command, Output},
};

fn rt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rt")).args(args).output().expect("run rt")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// A fresh folder for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rt-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The built-in blast wave (a detached NRRD header beside its payload).
fn blast_wave() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("data/blast_sedov_64.nhdr")
}

/// Asserts a failed run with a one-line `rt: error:` message holding each
/// of `wants`.
fn fails_with(o: &Output, wants: &[&str]) {
    assert_eq!(o.status.code(), Some(1), "{}", stderr(o));
    let e = stderr(o);
    assert!(e.starts_with("rt: error: "), "{e}");
    assert_eq!(e.trim_end().lines().count(), 1, "one line: {e}");
    for w in wants {
        assert!(e.contains(w), "`{w}` not in {e}");
    }
    assert!(!e.contains("panicked"), "{e}");
}

/// A small density volume as raw + JSON: a Gaussian bump of density on
/// 1.2 kg/m³ (or its negative with `negate`).
fn bump_volume(dir: &Path, negate: bool) -> PathBuf {
    let n = 24usize;
    let mut raw = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let r2 = [i, j, k].iter().map(|&c| (c as f32 - 11.5).powi(2)).sum::<f32>();
                let rho = 1.2 + 3.0 * (-r2 / 18.0).exp();
                raw.extend((if negate { -rho } else { rho }).to_le_bytes());
            }
        }
    }
    std::fs::write(dir.join("bump.raw"), raw).unwrap();
    let json = format!(
        r#"{{"dims": [{n}, {n}, {n}], "dtype": "float32", "spacing": [0.01, 0.01, 0.01],
            "origin": [0, 0, 0], "file": "bump.raw"}}"#
    );
    let path = dir.join("bump.json");
    std::fs::write(&path, json).unwrap();
    path
}

#[test]
fn help_lists_every_subcommand_and_every_option_with_its_default() {
    let o = rt(&["--help"]);
    assert!(o.status.success());
    for sub in ["demo", "schlieren", "view", "info", "distributed"] {
        assert!(stdout(&o).contains(sub), "{sub}");
    }
    for sub in ["demo", "schlieren", "view", "info", "distributed"] {
        let o = rt(&[sub, "--help"]);
        assert!(o.status.success(), "{sub} --help: {}", stderr(&o));
    }
    let help = stdout(&rt(&["schlieren", "--help"]));
    for want in ["[default: 16]", "[default: knife]", "metres", "dark-field", "--allow-nonphysical"]
    {
        assert!(help.contains(want), "`{want}` not in schlieren --help");
    }
}

#[test]
fn bad_files_are_one_line_errors() {
    let dir = scratch("bad-files");
    fails_with(
        &rt(&["schlieren", "/nonexistent/x.nrrd"]),
        &["/nonexistent/x.nrrd", "No such file"],
    );
    let obj = dir.join("mesh.obj");
    std::fs::write(&obj, "v 0 0 0\n").unwrap();
    fails_with(&rt(&["schlieren", obj.to_str().unwrap()]), &["unknown grid format"]);
    let ply = dir.join("nan.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
         property float z\nend_header\n0 0 nan\n1 0 0\n0 1 0\n",
    )
    .unwrap();
    fails_with(&rt(&["view", ply.to_str().unwrap()]), &["nan.ply", "malformed mesh file"]);
    fails_with(&rt(&["info", ply.to_str().unwrap()]), &["nan.ply"]);
    let negative = bump_volume(&dir, true);
    fails_with(
        &rt(&["schlieren", negative.to_str().unwrap()]),
        &["density ≤ 0", "--allow-nonphysical"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_options_are_usage_errors_naming_the_valid_ones() {
    let file = blast_wave();
    let f = file.to_str().unwrap();
    for (args, want) in [
        (vec!["schlieren", f, "--photons", "1e30"], "photons"),
        (vec!["schlieren", f, "--photons", "0"], "photons"),
        (vec!["schlieren", f, "--cutoff", "laser"], "knife"),
        (vec!["schlieren", f, "--estimator", "kde"], "sheet"),
        (vec!["schlieren", f, "--f", "-1"], "must be > 0"),
        (vec!["view", "x.ply", "--size", "0x0"], "1 to 16384"),
        (vec!["view", "x.ply", "--colormap", "jet"], "viridis"),
        (vec!["distributed", "--schedule", "radix-1"], "radix-K"),
    ] {
        let o = rt(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn info_describes_the_blast_wave() {
    let o = rt(&["info", blast_wave().to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("volume of 64×64×64 samples"), "{text}");
    assert!(text.contains("spacing 0.015625 × 0.015625 × 0.015625"), "{text}");
    assert!(text.contains("deflection along z"), "{text}");
}

/// A small volume renders; the same seed gives the same bytes, and the
/// automatic exposure is printed so the run can be repeated exactly.
#[test]
fn schlieren_renders_deterministically_with_its_exposure_printed() {
    let dir = scratch("schlieren");
    let vol = bump_volume(&dir, false);
    let run = |out: &Path, estimator: &str| {
        let o = rt(&[
            "schlieren",
            vol.to_str().unwrap(),
            "--size",
            "48",
            "--photons",
            "4",
            "--estimator",
            estimator,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let (a, b, c) = (dir.join("a.png"), dir.join("b.png"), dir.join("c.png"));
    let said = run(&a, "sheet");
    run(&b, "sheet");
    assert!(said.contains("knife edge at 0 deg, f = 1 m, h = "), "{said}");
    assert!(said.contains("48×48"), "{said}");
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    // The classic estimator is there for comparison, and differs.
    run(&c, "photons");
    assert_ne!(std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A PNG's header and pixels (as stored: no expansion or stripping).
fn decode(path: &Path) -> (png::OutputInfo, Vec<u8>) {
    let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut reader = png::Decoder::new(std::io::BufReader::new(file)).read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    buf.truncate(info.buffer_size());
    (info, buf)
}

/// A unit square facing +z with two per-vertex scalars: `flat` exactly
/// 2.5 everywhere, `temp` 300 and the next float up (one ulp apart).
fn constant_scalar_ply(dir: &Path) -> PathBuf {
    let path = dir.join("square.ply");
    std::fs::write(
        &path,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nproperty float flat\nproperty float temp\nelement face 2\n\
         property list uchar int vertex_indices\nend_header\n\
         0 0 0 2.5 300\n1 0 0 2.5 300.00003\n1 1 0 2.5 300\n0 1 0 2.5 300.00003\n\
         3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    path
}

/// A scalar without range (exactly constant, or within round-off) is
/// drawn in one colour with a warning, not stretched over its round-off:
/// every fully covered pixel of the flat, evenly lit square is the same.
#[test]
fn view_warns_about_a_constant_scalar_and_paints_it_in_one_colour() {
    let dir = scratch("constant-scalar");
    let ply = constant_scalar_ply(&dir);
    for scalar in ["flat", "temp"] {
        let out = dir.join(format!("{scalar}.png"));
        let o = rt(&[
            "view",
            ply.to_str().unwrap(),
            "--scalar",
            scalar,
            "--size",
            "64x48",
            "--background",
            "transparent",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(e.contains(&format!("rt: warning: scalar {scalar} is constant (")), "{e}");
        assert!(e.contains("drawn in one colour"), "{e}");
        let (info, px) = decode(&out);
        assert_eq!(info.color_type, png::ColorType::Rgba);
        let inside: Vec<&[u8]> = px.chunks_exact(4).filter(|p| p[3] == 255).collect();
        assert!(inside.len() > 100, "the square covers the view: {}", inside.len());
        assert!(inside.iter().all(|p| *p == inside[0]), "{scalar}: more than one colour");
    }
    // A range given by the user is taken as it is: no warning.
    let out = dir.join("ranged.png");
    let args = ["--scalar", "flat", "--range", "0,5", "--size", "32x24", "--out"];
    let o = rt(&[&["view", ply.to_str().unwrap()][..], &args, &[out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Renders are opaque by default (composited on white); `--background
/// transparent` keeps alpha 0 where nothing was hit.
#[test]
fn view_background_is_opaque_unless_transparent_is_asked_for() {
    let dir = scratch("background");
    let ply = constant_scalar_ply(&dir);
    let render = |name: &str, extra: &[&str]| {
        let out = dir.join(name);
        let mut args = vec!["view", ply.to_str().unwrap(), "--size", "48x32"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = rt(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        decode(&out).1
    };
    let opaque = render("default.png", &[]);
    assert!(opaque.chunks_exact(4).all(|p| p[3] == 255));
    assert_eq!(&opaque[..4], &[255; 4], "white in the corner");
    for background in ["black", "gradient"] {
        let px = render(&format!("{background}.png"), &["--background", background]);
        assert!(px.chunks_exact(4).all(|p| p[3] == 255), "{background}");
    }
    let clear = render("clear.png", &["--background", "transparent"]);
    assert_eq!(&clear[..4], &[0; 4], "nothing hit in the corner");
    assert!(clear.chunks_exact(4).any(|p| p[3] == 255));
    // Facets, a ground plane and a figure are accepted too.
    let o = rt(&[
        "view",
        ply.to_str().unwrap(),
        "--flat",
        "--ground",
        "--shadows",
        "--figure",
        "--size",
        "48x32",
        "--out",
        dir.join("more.png").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(dir.join("more-figure.png").is_file());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `rt schlieren` writes the image, its figure beside it (unless
/// `--no-figure`) and, with `--raw16`, a linear 16-bit PNG of the same
/// size: grey, or RGB for the colour filter.
#[test]
fn schlieren_writes_a_figure_and_a_16_bit_image_on_request() {
    let dir = scratch("figure");
    let vol = bump_volume(&dir, false);
    let run = |out: &Path, extra: &[&str]| {
        let mut args = vec!["schlieren", vol.to_str().unwrap(), "--size", "40", "--photons", "4"];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--out", out.to_str().unwrap()]);
        let o = rt(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let said = run(&dir.join("knife.png"), &["--raw16"]);
    let figure = dir.join("knife-figure.png");
    assert!(said.contains(figure.to_str().unwrap()), "{said}");
    let (image, _) = decode(&dir.join("knife.png"));
    assert_eq!((image.width, image.height), (40, 40));
    let (info, _) = decode(&figure);
    assert!(info.width >= 520 && info.height >= 520, "{}×{}", info.width, info.height);
    let (raw, px) = decode(&dir.join("knife-16bit.png"));
    assert_eq!(raw.bit_depth, png::BitDepth::Sixteen);
    assert_eq!(raw.color_type, png::ColorType::Grayscale);
    assert_eq!((raw.width, raw.height), (40, 40));
    // Near the corner the beam is undisturbed: a knife edge passes half
    // the source there, 16384 (the mean of 4 × 4 pixels, one in from the
    // edges).
    let at = |x: usize, y: usize| {
        f64::from(u16::from_be_bytes([px[2 * (x + 40 * y)], px[2 * (x + 40 * y) + 1]]))
    };
    let corner =
        (1..5).flat_map(|y| (1..5).map(move |x| (x, y))).map(|(x, y)| at(x, y)).sum::<f64>() / 16.0;
    assert!((15000.0..17800.0).contains(&corner), "{corner}");

    run(&dir.join("color.png"), &["--cutoff", "color", "--raw16", "--no-figure"]);
    assert!(dir.join("color.png").is_file());
    assert!(!dir.join("color-figure.png").exists(), "--no-figure writes no figure");
    let (raw, _) = decode(&dir.join("color-16bit.png"));
    assert_eq!((raw.bit_depth, raw.color_type), (png::BitDepth::Sixteen, png::ColorType::Rgb));
    // The last of --figure / --no-figure wins.
    run(&dir.join("again.png"), &["--no-figure", "--figure"]);
    assert!(dir.join("again-figure.png").is_file());
    assert!(!dir.join("again-16bit.png").exists(), "no --raw16, no 16-bit image");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `rt bos`: a small volume gives the pair, the displacement image and
/// its raw + JSON, deterministically; the displacement read back from the
/// raw file is what the printed summary says; noise options change the
/// flow image but not the truth; bad files and options are one-line
/// errors.
#[test]
fn bos_writes_a_pair_and_its_true_displacement() {
    let dir = scratch("bos");
    let vol = bump_volume(&dir, false);
    let run = |stem: &str, extra: &[&str]| {
        let out = dir.join(format!("{stem}.png"));
        let mut args =
            vec!["bos", vol.to_str().unwrap(), "--size", "40", "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = rt(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let said = run("a", &[]);
    run("b", &[]);
    for f in [
        "a-reference.png",
        "a-flow.png",
        "a-displacement.png",
        "a-displacement.json",
        "a-displacement.raw",
    ] {
        assert!(dir.join(f).exists(), "{f}: {said}");
    }
    assert!(said.contains("40×40") && said.contains("displacement max"), "{said}");
    for f in ["flow.png", "displacement.raw"] {
        assert_eq!(
            std::fs::read(dir.join(format!("a-{f}"))).unwrap(),
            std::fs::read(dir.join(format!("b-{f}"))).unwrap()
        );
    }
    let raw = std::fs::read(dir.join("a-displacement.raw")).unwrap();
    assert_eq!(raw.len(), 40 * 40 * 2 * 4);
    let max = raw
        .chunks(8)
        .map(|c| {
            let x = f32::from_le_bytes(c[..4].try_into().unwrap());
            let y = f32::from_le_bytes(c[4..].try_into().unwrap());
            f64::from(x).hypot(f64::from(y))
        })
        .fold(0.0, f64::max);
    assert!(max > 0.05, "the bump moves the background: max {max} px");
    assert!(said.contains(&format!("displacement max {max:.3} px")), "{said} vs {max}");
    // Noise changes the recorded image, not the truth.
    run("n", &["--shot-noise", "--read-noise", "5"]);
    assert_ne!(
        std::fs::read(dir.join("a-flow.png")).unwrap(),
        std::fs::read(dir.join("n-flow.png")).unwrap()
    );
    assert_eq!(
        std::fs::read(dir.join("a-displacement.raw")).unwrap(),
        std::fs::read(dir.join("n-displacement.raw")).unwrap()
    );
    // Bad input.
    fails_with(&rt(&["bos", dir.join("missing.nrrd").to_str().unwrap()]), &["missing.nrrd"]);
    let o = rt(&["bos", vol.to_str().unwrap(), "--f-number", "-2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = rt(&[
        "bos",
        vol.to_str().unwrap(),
        "--distance",
        "0.05",
        "--out",
        dir.join("x.png").to_str().unwrap(),
    ]);
    fails_with(&o, &["farther from the lens"]);
    let help = rt(&["bos", "--help"]);
    assert!(help.status.success() && stdout(&help).contains("--background-distance"));
    std::fs::remove_dir_all(&dir).unwrap();
}
