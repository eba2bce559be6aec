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
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../rt-tools/data/blast_sedov_64.nhdr")
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
    for sub in ["demo", "schlieren", "bos", "focusing", "view", "info", "distributed", "serve"] {
        assert!(stdout(&o).contains(sub), "{sub}");
    }
    for sub in ["demo", "schlieren", "view", "info", "distributed", "serve"] {
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
    // Distributed: a volume that cannot be read a brick at a time, and
    // jobs too large to hold are one-line errors, not a crash.
    fails_with(
        &rt(&["distributed", "--volume", ply.to_str().unwrap()]),
        &["nan.ply", "a brick at a time"],
    );
    fails_with(
        &rt(&["distributed", "--volume", "--size", "16384x16384", "--ranks", "2"]),
        &["photons is more than a distributed run traces"],
    );
    fails_with(
        &rt(&["distributed", "--size", "16384x16384", "--ao", "4096"]),
        &["shadow and AO rays is more than"],
    );
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
    // Units and three significant digits, never 0.015625 or 0.9999999999999999.
    assert!(text.contains("spacing 15.6 mm × 15.6 mm × 15.6 mm"), "{text}");
    assert!(text.contains("values 0.0187 … 2.85 (mean 1.00)"), "{text}");
    assert!(text.contains("index 1.00000417 … 1.000644"), "{text}");
    assert!(text.contains("99th percentile 1.54 mrad"), "{text}");
}

/// An impossible `--out` is refused before the work (a folder, a path
/// through a file), with one line naming it and nothing written; a missing
/// folder is made and said.
#[test]
fn outputs_are_checked_before_the_work() {
    let dir = scratch("outputs");
    let vol = bump_volume(&dir, false);
    std::fs::write(dir.join("a-file"), b"").unwrap();
    for (sub, extra) in [("schlieren", vec!["--size", "8"]), ("bos", vec!["--size", "8"])] {
        for (out, why) in
            [(dir.join("a-file/x.png"), "is not a folder"), (dir.clone(), "is a folder")]
        {
            let mut args = vec![sub, vol.to_str().unwrap(), "--out", out.to_str().unwrap()];
            args.extend_from_slice(&extra);
            fails_with(&rt(&args), &[why]);
        }
    }
    let out = dir.join("made/here/s.png");
    let o = rt(&[
        "schlieren",
        vol.to_str().unwrap(),
        "--size",
        "8",
        "--no-figure",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("created folder"), "{}", stderr(&o));
    let names: Vec<_> =
        std::fs::read_dir(out.parent().unwrap()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names, vec![std::ffi::OsString::from("s.png")], "no staging file left");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `rt info` counts NaN and infinite samples instead of refusing the file
/// (which `rt schlieren` refuses, naming the first).
#[test]
fn info_counts_blanked_samples() {
    let dir = scratch("info-nan");
    let n = 8usize;
    let mut data = vec![1.2f32; n * n * n];
    data[5] = f32::NAN;
    data[77] = f32::INFINITY;
    let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join("v.raw"), bytes).unwrap();
    std::fs::write(
        dir.join("v.json"),
        r#"{"file": "v.raw", "dims": [8, 8, 8], "dtype": "float32", "spacing": [0.001, 0.001, 0.001], "origin": [0, 0, 0]}"#,
    )
    .unwrap();
    let json = dir.join("v.json");
    let o = rt(&["info", json.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("values 1.20 … 1.20 (mean 1.20, 2 NaN or infinite)"), "{text}");
    assert!(text.contains("2 samples are NaN or infinite"), "{text}");
    let out = dir.join("x.png");
    fails_with(
        &rt(&["schlieren", json.to_str().unwrap(), "--out", out.to_str().unwrap()]),
        &["sample 5 is not finite"],
    );
    std::fs::remove_dir_all(&dir).unwrap();
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
    assert!(said.contains("knife edge at 0°, f = 1.00 m, h = "), "{said}");
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
         property float z\nproperty float flat\nproperty float temp\nproperty float coarse\n\
         element face 2\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0 2.5 300 300\n1 0 0 2.5 300.00003 300.002\n1 1 0 2.5 300 300\n\
         0 1 0 2.5 300.00003 300.002\n\
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
    // A range of a few dozen float32 steps (300 to 300.002): drawn, with a
    // warning and the figure's title saying so.
    let out = dir.join("coarse.png");
    let args = ["--scalar", "coarse", "--size", "64x48", "--figure", "--out"];
    let o = rt(&[&["view", ply.to_str().unwrap()][..], &args, &[out.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("float32 steps: its colours come in as many bands"),
        "{}",
        stderr(&o)
    );
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
    assert!(said.contains("40×40") && said.contains("99th percentile"), "{said}");
    // The rig chosen is printed with units.
    assert!(said.contains(" mm, Z_A = ") && said.contains(" µm (11.3 mm sensor)"), "{said}");
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
    assert!(said.contains(&format!("max {max:.3} px)")), "{said} vs {max}");
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
        "--focal-length",
        "0.1",
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

/// A 12-bit sensor PNG's counts (stored in the high bits of 16).
fn counts12(path: &Path) -> Vec<f64> {
    let (info, buf) = decode(path);
    assert_eq!(
        (info.color_type, info.bit_depth),
        (png::ColorType::Grayscale, png::BitDepth::Sixteen)
    );
    buf.chunks(2).map(|c| f64::from(u16::from_be_bytes([c[0], c[1]]) >> 4)).collect()
}

/// The sRGB decoding of an 8-bit sample.
fn srgb_to_linear(c: u8) -> f64 {
    let c = f64::from(c) / 255.0;
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// `rt bos --background grid|FILE.png` and `--airy`: the grid's reference
/// repeats every --spacing pixels; a 40 × 40 grey PNG spans the 40-pixel
/// sensor one pixel for one and comes back (sRGB-decoded, as counts at
/// 8000 e⁻ of a 10 000 e⁻ well) through no flow, while the flow image
/// moves it; diffraction lowers the grid's contrast, keeps its mean; the
/// truth does not depend on the background; bad images are one-line
/// errors.
#[test]
fn bos_backgrounds_grid_image_and_airy() {
    let dir = scratch("bos-backgrounds");
    let vol = bump_volume(&dir, false);
    let run = |stem: &str, extra: &[&str]| {
        let out = dir.join(format!("{stem}.png"));
        let mut args = vec![
            "bos",
            vol.to_str().unwrap(),
            "--size",
            "40",
            "--samples-per-axis",
            "6",
            // A 100 mm lens (the default for this small volume is
            // shorter) and, unless asked otherwise, a 40-pixel crop of a
            // 5 µm sensor: the default bins a whole sensor into 40
            // pixels, each 282 µm, which the bump moves by 0.1 pixel.
            "--focal-length",
            "0.1",
            "--out",
            out.to_str().unwrap(),
        ];
        if !extra.contains(&"--pixel") {
            args.extend_from_slice(&["--pixel", "5e-6"]);
        }
        args.extend_from_slice(extra);
        let o = rt(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        for f in ["reference.png", "flow.png", "displacement.png", "displacement.raw"] {
            assert!(dir.join(format!("{stem}-{f}")).is_file(), "{stem}-{f}");
        }
        stdout(&o)
    };
    let read = |f: &str| std::fs::read(dir.join(f)).unwrap();
    run("random", &[]);
    let said = run("grid", &["--background", "grid", "--spacing", "5", "--dot", "2"]);
    assert!(said.contains("background a dot grid"), "{said}");
    let grid = counts12(&dir.join("grid-reference.png"));
    assert_eq!(grid.len(), 40 * 40);
    let shift = |v: &[f64], dx: usize, dy: usize| {
        let mut sum = 0.0;
        for y in 0..40 - dy {
            for x in 0..40 - dx {
                sum += (v[(y + dy) * 40 + x + dx] - v[y * 40 + x]).abs();
            }
        }
        sum / ((40 - dx) * (40 - dy)) as f64
    };
    let (period, half) = (shift(&grid, 5, 0) + shift(&grid, 0, 5), shift(&grid, 2, 0));
    assert!(period < 0.1 * half, "grid period mismatch {period} vs {half}");
    assert_ne!(read("grid-reference.png"), read("random-reference.png"));
    assert_eq!(read("grid-displacement.raw"), read("random-displacement.raw"));

    // Diffraction (λN(1 + M) ≈ 1.1 px): the dots spread, the light stays.
    let said = run(
        "airy",
        &[
            "--background",
            "grid",
            "--spacing",
            "5",
            "--dot",
            "2",
            "--airy",
            "--f-number",
            "8",
            "--pixel",
            "4e-6",
        ],
    );
    assert!(said.contains("Airy disc"), "{said}");
    let sharp = run(
        "sharp",
        &[
            "--background",
            "grid",
            "--spacing",
            "5",
            "--dot",
            "2",
            "--f-number",
            "8",
            "--pixel",
            "4e-6",
        ],
    );
    assert!(!sharp.contains("Airy"), "{sharp}");
    let (a, s) =
        (counts12(&dir.join("airy-reference.png")), counts12(&dir.join("sharp-reference.png")));
    let stats = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        (m, (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt())
    };
    let ((ma, sa), (ms, ss)) = (stats(&a), stats(&s));
    // (The light the rings carry past an edge is replaced by the clamped
    // edge's: on 40 pixels the mean moves by under 3 %.)
    assert!((ma / ms - 1.0).abs() < 0.03, "mean {ma} vs {ms}");
    assert!(sa < 0.7 * ss, "contrast {sa} vs {ss}");
    assert_eq!(read("airy-displacement.raw"), read("sharp-displacement.raw"));

    // An image background: vertical stripes 16 pixels apart, 8-bit sRGB.
    let img = dir.join("stripes.png");
    let bytes: Vec<u8> = (0..40 * 40)
        .map(|p| {
            let x = (p % 40) as f64 + 0.5;
            (128.0 + 100.0 * (core::f64::consts::TAU * x / 16.0).sin()).round() as u8
        })
        .collect();
    {
        let f = std::fs::File::create(&img).unwrap();
        let mut enc = png::Encoder::new(std::io::BufWriter::new(f), 40, 40);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        enc.write_header().unwrap().write_image_data(&bytes).unwrap();
    }
    let said = run("image", &["--background", img.to_str().unwrap()]);
    assert!(said.contains("stripes.png"), "{said}");
    let got = counts12(&dir.join("image-reference.png"));
    let worst = got
        .iter()
        .zip(&bytes)
        .map(|(&c, &b)| (c / 4095.0 * 10_000.0 / 8000.0 - srgb_to_linear(b)).abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.03, "image background comes back to {worst}");
    let flow = counts12(&dir.join("image-flow.png"));
    let moved = flow.iter().zip(&got).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(moved > 100.0, "the bump moves the stripes: {moved} counts");
    assert_eq!(read("image-displacement.raw"), read("random-displacement.raw"));
    // An RGB image is read as its luminance: grey RGB gives the same.
    let rgb = dir.join("stripes-rgb.png");
    {
        let f = std::fs::File::create(&rgb).unwrap();
        let mut enc = png::Encoder::new(std::io::BufWriter::new(f), 40, 40);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let data: Vec<u8> = bytes.iter().flat_map(|&b| [b, b, b]).collect();
        enc.write_header().unwrap().write_image_data(&data).unwrap();
    }
    run("rgb", &["--background", rgb.to_str().unwrap()]);
    let grey = counts12(&dir.join("rgb-reference.png"));
    assert!(grey.iter().zip(&got).all(|(a, b)| (a - b).abs() <= 1.0), "RGB grey ≠ grey");

    // Bad images.
    std::fs::write(dir.join("junk.png"), b"not a png").unwrap();
    let bad = |path: &Path| {
        rt(&[
            "bos",
            vol.to_str().unwrap(),
            "--size",
            "8",
            "--background",
            path.to_str().unwrap(),
            "--out",
            dir.join("x.png").to_str().unwrap(),
        ])
    };
    fails_with(&bad(&dir.join("junk.png")), &["junk.png"]);
    fails_with(&bad(&dir.join("missing.png")), &["missing.png"]);
    let o = rt(&["bos", vol.to_str().unwrap(), "--background", ""]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let o = rt(&["bos", vol.to_str().unwrap(), "--wavelength", "-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let help = stdout(&rt(&["bos", "--help"]));
    for opt in ["--background", "--background-pixel", "--airy", "--wavelength"] {
        assert!(help.contains(opt), "{opt}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `rt focusing`: the sensor image and I/I₀ beside it; the bump shows
/// (brighter on one side, darker on the other, as a knife edge across the
/// bands sees it) on an undisturbed background of 1; the same seed, the
/// same files; turning the bands turns the signal; moving the focus far
/// from the bump blurs it away; bad input is a one-line error.
#[test]
fn focusing_writes_an_image_that_focuses() {
    let dir = scratch("focusing");
    let vol = bump_volume(&dir, false);
    let run = |stem: &str, extra: &[&str]| {
        let out = dir.join(format!("{stem}.png"));
        let mut args = vec![
            "focusing",
            vol.to_str().unwrap(),
            "--size",
            "32",
            "--samples-per-axis",
            "4",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = rt(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(dir.join(format!("{stem}.json")).is_file());
        let raw = std::fs::read(dir.join(format!("{stem}.raw"))).unwrap();
        assert_eq!(raw.len(), 32 * 32 * 4);
        let rel: Vec<f64> =
            raw.chunks(4).map(|c| f64::from(f32::from_le_bytes(c.try_into().unwrap()))).collect();
        (stdout(&o), rel)
    };
    let (said, a) = run("a", &[]);
    assert!(said.contains("32×32") && said.contains("periods across the view"), "{said}");
    // Corners: undisturbed. Left and right of the centre: the signal.
    assert!(
        (a[0] - 1.0).abs() < 1e-6 && (a[32 * 32 - 1] - 1.0).abs() < 1e-6,
        "{} {}",
        a[0],
        a[1023]
    );
    let (l, r) = (a[16 * 32 + 10] - 1.0, a[16 * 32 + 21] - 1.0);
    assert!(l.abs() > 0.05 && r.abs() > 0.05 && l * r < 0.0, "left {l}, right {r}");
    // Above and below the centre the bands (vertical) see nothing.
    let (u, d) = (a[10 * 32 + 16] - 1.0, a[21 * 32 + 16] - 1.0);
    assert!(u.abs() < 0.3 * l.abs() && d.abs() < 0.3 * l.abs(), "up {u}, down {d}");
    let (_, b) = run("b", &[]);
    assert_eq!(a, b);
    assert_eq!(
        std::fs::read(dir.join("a.png")).unwrap(),
        std::fs::read(dir.join("b.png")).unwrap()
    );
    // Bands turned 90°: the signal moves above and below.
    let (_, t) = run("t", &["--angle", "90"]);
    let (u, d) = (t[10 * 32 + 16] - 1.0, t[21 * 32 + 16] - 1.0);
    assert!(u.abs() > 0.05 && d.abs() > 0.05 && u * d < 0.0, "turned: up {u}, down {d}");
    // Focused 20 cm toward the lens, far from the 24 cm bump: blurred.
    let mm: f64 = said.split("pitch ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    let pitch = format!("{}", mm * 1e-3);
    let (_, far) = run("far", &["--focus", "0.2", "--pitch", &pitch]);
    let peak = |v: &[f64]| v.iter().map(|x| (x - 1.0).abs()).fold(0.0, f64::max);
    assert!(peak(&far) < 0.6 * peak(&a), "focused away {} vs {}", peak(&far), peak(&a));
    // Bad input.
    fails_with(&rt(&["focusing", dir.join("missing.nrrd").to_str().unwrap()]), &["missing.nrrd"]);
    let o = rt(&[
        "focusing",
        vol.to_str().unwrap(),
        "--duty",
        "1.5",
        "--out",
        dir.join("x.png").to_str().unwrap(),
    ]);
    fails_with(&o, &["duty"]);
    let o = rt(&[
        "focusing",
        vol.to_str().unwrap(),
        "--source-distance",
        "0.1",
        "--out",
        dir.join("x.png").to_str().unwrap(),
    ]);
    fails_with(&o, &["source grid"]);
    let o = rt(&["focusing", vol.to_str().unwrap(), "--aperture", "-1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let help = rt(&["focusing", "--help"]);
    assert!(help.status.success() && stdout(&help).contains("--source-distance"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// matplotlib's 256 viridis entries (sRGB), the data file rt-core's
/// table test reads.
fn published_viridis() -> Vec<[f64; 3]> {
    include_str!("../../rt-core/tests/data/viridis.csv")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with('r'))
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// The figure's colour bar against the published table: `rt view
/// --figure` of a ramp through viridis over a given range; the bar's
/// pixel rows run from the range's top to its bottom, each the published
/// colour at its value within one 8-bit step (a map encoded twice showed
/// the middle as (100, 198, 196), published (33, 145, 140)).
#[test]
fn the_figure_colour_bar_is_the_published_viridis() {
    let dir = scratch("colour-bar");
    let ply = dir.join("ramp.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nproperty float s\nelement face 2\n\
         property list uchar int vertex_indices\nend_header\n\
         0 0 0 0\n1 0 0 1\n1 1 0 1\n0 1 0 0\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    let out = dir.join("ramp.png");
    let o = rt(&[
        "view",
        ply.to_str().unwrap(),
        "--scalar",
        "s",
        "--colormap",
        "viridis",
        "--range",
        "0,1",
        "--size",
        "64x48",
        "--figure",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let (info, px) = decode(&dir.join("ramp-figure.png"));
    let (w, h) = (info.width as usize, info.height as usize);
    let at = |x: usize, y: usize| {
        let p = 3 * (y * w + x);
        [px[p], px[p + 1], px[p + 2]].map(i32::from)
    };
    let near = |c: [i32; 3], want: [i32; 3]| (0..3).all(|k| (c[k] - want[k]).abs() <= 2);
    // The bar: in the legend (the right part), the column with the longest
    // run of rows starting at viridis' top colour.
    let (top, bottom) = ([253, 231, 37], [68, 1, 84]);
    let mut best = (0, 0, 0);
    for x in w / 2..w {
        for y0 in 0..h {
            if !near(at(x, y0), top) || (y0 > 0 && near(at(x, y0 - 1), top)) {
                continue;
            }
            let mut y1 = y0;
            while y1 + 1 < h && !near(at(x, y1 + 1), [255, 255, 255]) && at(x, y1 + 1) != [90; 3] {
                y1 += 1;
            }
            if near(at(x, y1), bottom) && y1 - y0 > best.2 - best.1 {
                best = (x, y0, y1);
            }
        }
    }
    let (x, y0, y1) = best;
    assert!(y1 - y0 > 100, "no colour bar found ({best:?})");
    let table = published_viridis();
    // The bar's frame covers one row above and below the colours found.
    let (first, rows) = (y0 - 1, (y1 - y0 + 3) as f64);
    let mut worst = 0;
    for y in y0..=y1 {
        // Row y shows the value at its centre, 1 at the top, 0 at the bottom.
        let s = 1.0 - ((y - first) as f64 + 0.5) / rows;
        let f = s * 255.0;
        let (i, t) = ((f.floor() as usize).min(254), f - f.floor().min(254.0));
        let want = [0, 1, 2]
            .map(|k| ((table[i][k] + t * (table[i + 1][k] - table[i][k])) * 255.0).round() as i32);
        let got = at(x, y);
        worst = worst.max((0..3).map(|k| (got[k] - want[k]).abs()).max().unwrap());
    }
    assert!(worst <= 1, "colour bar off the published table by {worst}/255");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `--device`: the GPU's image of the blast wave is the CPU's to a grey
/// level or two; `gpu` where it cannot trace is a one-line error, `auto`
/// says what it chose. Without an adapter (and without `RT_GPU_REQUIRE`,
/// which CI sets), only the CPU's side is checked.
#[test]
fn schlieren_on_the_gpu_makes_the_cpus_image() {
    let dir = scratch("device");
    let wave = blast_wave();
    let wave = wave.to_str().unwrap();
    let (cpu, gpu) = (dir.join("cpu.png"), dir.join("gpu.png"));
    let common = ["--size", "96", "--photons", "4", "--interp", "linear", "--no-figure"];
    let o = rt(&[&["schlieren", wave, "--out", cpu.to_str().unwrap()][..], &common[..]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let o = rt(&[
        &["schlieren", wave, "--device", "gpu", "--out", gpu.to_str().unwrap()][..],
        &common[..],
    ]
    .concat());
    // No adapter (none matches the name asked for): `gpu` is a one-line
    // error, `auto` runs on the CPU and says why.
    let without = |device: &str| {
        Command::new(env!("CARGO_BIN_EXE_rt"))
            .env("RT_GPU_ADAPTER", "no adapter has this name")
            .args(
                [
                    &["schlieren", wave, "--device", device, "--out", gpu.to_str().unwrap()][..],
                    &common[..],
                ]
                .concat(),
            )
            .output()
            .unwrap()
    };
    fails_with(&without("gpu"), &["no GPU adapter found"]);
    let o2 = without("auto");
    assert!(o2.status.success(), "{}", stderr(&o2));
    assert!(stderr(&o2).contains("rt: tracing on cpu (no GPU adapter found"), "{}", stderr(&o2));
    if !o.status.success() && std::env::var_os("RT_GPU_REQUIRE").is_none() {
        fails_with(&o, &["no GPU adapter"]);
        return;
    }
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("rt: tracing on gpu ("), "{}", stderr(&o));
    let ((_, a), (_, b)) = (decode(&cpu), decode(&gpu));
    assert_eq!(a.len(), b.len());
    let worst = a.iter().zip(&b).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
    let mean =
        a.iter().zip(&b).map(|(x, y)| f64::from(x.abs_diff(*y))).sum::<f64>() / a.len() as f64;
    // The CPU skips the octree's smooth nodes within what the bench
    // resolves; the GPU steps through them (measured: 2 % of the values
    // one or two levels apart, 0.02 levels on average).
    assert!(worst <= 2, "grey levels apart: up to {worst}");
    assert!(mean < 0.1, "grey levels apart: {mean:.3} on average");
    // The default interpolant is cubic: `gpu` refuses it, `auto` falls back.
    fails_with(
        &rt(&[
            "schlieren",
            wave,
            "--device",
            "gpu",
            "--size",
            "32",
            "--no-figure",
            "--out",
            gpu.to_str().unwrap(),
        ]),
        &["trilinear", "--interp linear"],
    );
    let o = rt(&[
        "schlieren",
        wave,
        "--device",
        "auto",
        "--size",
        "32",
        "--no-figure",
        "--out",
        gpu.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("rt: tracing on cpu (the GPU traces the trilinear"),
        "{}",
        stderr(&o)
    );
}

/// Writes an 8-bit RGB PNG of `w × h` pixels from `f(x, y)`.
fn write_rgb_png(path: &Path, w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) {
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            data.extend(f(x, y));
        }
    }
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut enc = png::Encoder::new(file, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.write_header().unwrap().write_image_data(&data).unwrap();
}

/// A painted filter (what `rt serve` saves): a white right half is a
/// hard knife edge across u, so the image has the light and dark sides
/// the automatic knife edge has (correlated with its image; the same
/// filter mirrored, anti-correlated); bad filters are one-line errors.
#[test]
fn schlieren_takes_a_painted_filter() {
    let dir = scratch("filter");
    let file = blast_wave();
    let file = file.to_str().unwrap();
    let common = ["--size", "48", "--photons", "4", "--no-figure"];
    let knife = dir.join("knife.png");
    let o = rt(&[&["schlieren", file][..], &common, &["--out", knife.to_str().unwrap()]].concat());
    assert!(o.status.success(), "{}", stderr(&o));
    let grey = |p: &Path| -> Vec<f64> {
        let (info, px) = decode(p);
        let n = info.color_type.samples();
        px.chunks(n).map(|c| f64::from(c[0])).collect()
    };
    let b = grey(&knife);
    let correlation = |a: &[f64]| {
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let (ma, mb) = (mean(a), mean(&b));
        let cov: f64 = a.iter().zip(&b).map(|(x, y)| (x - ma) * (y - mb)).sum();
        let var = |v: &[f64], m: f64| v.iter().map(|x| (x - m).powi(2)).sum::<f64>();
        cov / (var(a, ma) * var(&b, mb)).sqrt()
    };
    let half = dir.join("half.png");
    for (right, sign) in [(true, 1.0), (false, -1.0)] {
        write_rgb_png(&half, 64, 64, |x, _| if (x >= 32) == right { [255; 3] } else { [0; 3] });
        let painted = dir.join("painted.png");
        let o = rt(&[
            &["schlieren", file, "--cutoff", "color", "--filter", half.to_str().unwrap()][..],
            &common,
            &["--out", painted.to_str().unwrap()],
        ]
        .concat());
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(stdout(&o).contains("colour filter"), "{}", stdout(&o));
        // Measured: 0.62 and −0.47 (a hard edge against the knife's ramp;
        // the undeflected light falls in the right half).
        let r = correlation(&grey(&painted));
        assert!(sign * r > 0.4, "white {}: correlation {r:.3}", ["left", "right"][right as usize]);
    }

    let wide = dir.join("wide.png");
    write_rgb_png(&wide, 8, 4, |_, _| [255; 3]);
    let out = dir.join("x.png");
    let out = out.to_str().unwrap();
    fails_with(
        &rt(&["schlieren", file, "--filter", half.to_str().unwrap(), "--out", out]),
        &["--cutoff color"],
    );
    fails_with(
        &rt(&[
            "schlieren",
            file,
            "--cutoff",
            "color",
            "--filter",
            wide.to_str().unwrap(),
            "--out",
            out,
        ]),
        &["wide.png", "square"],
    );
    let missing = dir.join("missing.png");
    fails_with(
        &rt(&[
            "schlieren",
            file,
            "--cutoff",
            "color",
            "--filter",
            missing.to_str().unwrap(),
            "--out",
            out,
        ]),
        &["missing.png"],
    );
}
