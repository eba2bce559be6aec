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
    let run = |out: &Path| {
        let o = rt(&[
            "schlieren",
            vol.to_str().unwrap(),
            "--size",
            "48",
            "--photons",
            "4",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        stdout(&o)
    };
    let (a, b) = (dir.join("a.png"), dir.join("b.png"));
    let said = run(&a);
    run(&b);
    assert!(said.contains("knife edge at 0 deg, f = 1 m, h = "), "{said}");
    assert!(said.contains("48×48"), "{said}");
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    std::fs::remove_dir_all(&dir).unwrap();
}
