//! Every rt-gl test program and the real Debian programs it is tried on,
//! each run three ways under `xvfb-run` with Mesa's software GL: with
//! rt-gl loaded but idle (`RT_GL_MODE=off`: the program's own frame
//! rate through the interposer), traced (`gl` mode) and traced
//! asynchronously (`RT_GL_ASYNC=1`); and once more with every frame
//! dumped, rasterized and traced, to compare them: the share of pixels
//! where both agree on covered or background (worst and median frame)
//! and the mean colour difference where both cover.

use std::{
    ffi::OsString,
    fmt::Write as _,
    path::{Path, PathBuf},
};

use super::gl::{read_png, run_x, tool};

/// One program and how to run it.
struct Program {
    /// Its name in the table.
    name: String,
    /// What it exercises.
    what: &'static str,
    /// The command for the timed runs (runs until stopped).
    timed: Vec<OsString>,
    /// The command for the dumped run (stops by itself or is stopped).
    dumped: Vec<OsString>,
}

/// The measurements of one program.
struct Row {
    frames: usize,
    coverage: (f64, f64),
    colour: (f64, f64),
    fps: [Option<f64>; 3],
}

/// `(coverage agreement, mean colour difference)` of two frames, the
/// background taken from the raster's first pixel.
fn agreement(raster: &Path, traced: &Path) -> Result<(f64, f64), String> {
    let (w, h, a) = read_png(raster)?;
    let (w2, h2, b) = read_png(traced)?;
    if (w, h) != (w2, h2) || a.len() < 4 {
        return Err(format!("{} and {} differ in size", raster.display(), traced.display()));
    }
    let bg = [a[0], a[1], a[2]];
    let covered = |p: &[u8]| (0..3).any(|k| p[k].abs_diff(bg[k]) > 2);
    let (mut agree, mut both, mut diff) = (0usize, 0usize, 0.0f64);
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let (ca, cb) = (covered(pa), covered(pb));
        agree += usize::from(ca == cb);
        if ca && cb {
            both += 1;
            diff += (0..3).map(|k| f64::from(pa[k].abs_diff(pb[k]))).sum::<f64>() / 3.0;
        }
    }
    let n = (w as usize * h as usize).max(1);
    Ok((agree as f64 / n as f64, if both == 0 { 0.0 } else { diff / both as f64 }))
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Swaps per second of a run of `secs` seconds (`RT_GL_STATS` lines).
fn fps(out: &str, secs: f64) -> Option<f64> {
    let swaps = out
        .lines()
        .filter(|l| {
            l.strip_prefix("rt-gl: frame ")
                .and_then(|r| r.split_once(": "))
                .is_some_and(|(n, _)| n.chars().all(|c| c.is_ascii_digit()))
        })
        .count();
    (swaps > 0).then(|| swaps as f64 / secs)
}

fn os(v: &[&str]) -> Vec<OsString> {
    v.iter().map(OsString::from).collect()
}

/// `timeout -s INT secs` before `cmd`.
fn stopped(secs: &str, cmd: &[OsString]) -> Vec<OsString> {
    let mut v = os(&["timeout", "-s", "INT", secs]);
    v.extend(cmd.iter().cloned());
    v
}

/// Compiles `tests/gl-programs/NAME.c` with `libs`.
fn compile(dir: &Path, name: &str, libs: &[&str]) -> Result<PathBuf, String> {
    let src =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../rt-gl/tests/gl-programs/{name}.c"));
    let exe = dir.join(format!("gl-{name}"));
    let status = std::process::Command::new(tool("cc")?)
        .arg("-O2")
        .arg("-o")
        .arg(&exe)
        .arg(&src)
        .args(libs)
        .status()
        .map_err(|e| format!("running cc: {e}"))?;
    if status.success() { Ok(exe) } else { Err(format!("cc failed on {}", src.display())) }
}

/// The programs: every test program mode, then the Debian ones found.
fn programs(dir: &Path, secs: &str) -> Result<Vec<Program>, String> {
    let private = compile(dir, "private_gl", &["-lX11", "-ldl", "-lm"])?;
    let egl = compile(dir, "egl_gl", &["-lEGL", "-lGL", "-lX11", "-lm"])?;
    let scenes = compile(dir, "scenes", &["-lGL", "-lX11", "-lm"])?;
    let mut v = Vec::new();
    let modes: [(&str, &str); 16] = [
        ("", "libGL opened privately, glXGetProcAddressARB"),
        ("noviewport", "no glViewport"),
        ("cw", "glFrontFace(GL_CW), two-sided lighting"),
        ("lightsoff", "lights off before the swap"),
        ("arrays", "glInterleavedArrays, glRectf"),
        ("shadow", "projective planar shadow (left out), stencil"),
        ("overlay", "3-D glOrtho pass, pixel overlays, NDC background"),
        ("viewports", "two viewports, scissored clears"),
        ("depthclear", "pass after glClear(GL_DEPTH_BUFFER_BIT)"),
        ("fog", "fog: linear, exp, exp2"),
        ("blend", "alpha blending, culling, GL_NORMALIZE"),
        ("wireframe", "glPolygonMode(GL_LINE)"),
        ("texture", "2-D textures, environments, alpha test"),
        ("texgen", "glTexGen sphere map, object linear"),
        ("bitmap", "glBitmap text, glDrawPixels"),
        ("still", "a still ball (asynchronous accumulation)"),
    ];
    for (mode, what) in modes {
        let name =
            if mode.is_empty() { "private_gl".to_owned() } else { format!("private_gl {mode}") };
        let run = |frames: &str| {
            let mut c = vec![private.clone().into_os_string(), frames.into()];
            if !mode.is_empty() {
                c.push(mode.into());
            }
            c
        };
        v.push(Program { name, what, timed: run("100000000"), dumped: run("8") });
    }
    v.push(Program {
        name: "egl_gl".into(),
        what: "EGL context, eglSwapBuffers",
        timed: vec![egl.clone().into_os_string(), "100000000".into()],
        dumped: vec![egl.into_os_string(), "8".into()],
    });
    v.push(Program {
        name: "scenes".into(),
        what: "every recorded path, one scene a frame",
        timed: vec![scenes.clone().into_os_string(), "100000000".into()],
        dumped: vec![scenes.clone().into_os_string(), "10".into()],
    });
    v.push(Program {
        name: "scenes wave".into(),
        what: "a buffer rewritten every frame (refits)",
        timed: vec![scenes.clone().into_os_string(), "wave".into(), "100000000".into()],
        dumped: vec![scenes.into_os_string(), "wave".into(), "8".into()],
    });
    // Debian's programs, where installed.
    let debian: [(&str, &str, &str); 7] = [
        ("glxgears", "/usr/bin/glxgears", "mesa-utils: display lists"),
        (
            "xscreensaver molecule",
            "/usr/libexec/xscreensaver/molecule",
            "xscreensaver-gl: molecules, textured labels, shells",
        ),
        ("xscreensaver gears", "/usr/libexec/xscreensaver/gears", "xscreensaver-gl: gears"),
        (
            "xscreensaver pipes",
            "/usr/libexec/xscreensaver/pipes",
            "xscreensaver-gl: pipes, a list a frame",
        ),
        (
            "xscreensaver sierpinski3d",
            "/usr/libexec/xscreensaver/sierpinski3d",
            "xscreensaver-gl: fractal",
        ),
        (
            "xscreensaver superquadrics",
            "/usr/libexec/xscreensaver/superquadrics",
            "xscreensaver-gl: morphing surfaces",
        ),
        (
            "xscreensaver polyhedra",
            "/usr/libexec/xscreensaver/polyhedra",
            "xscreensaver-gl: polyhedra, textured titles",
        ),
    ];
    for (name, path, what) in debian {
        if Path::new(path).exists() {
            let cmd = os(&[path]);
            v.push(Program {
                name: name.into(),
                what,
                timed: cmd.clone(),
                dumped: stopped(secs, &cmd),
            });
        }
    }
    Ok(v)
}

/// Runs one program every way and measures it.
fn measure(p: &Program, dir: &Path, lib: &Path, secs: &str) -> Result<Row, String> {
    let t: f64 = secs.parse().map_err(|_| "seconds")?;
    let mut fps_of = [None; 3];
    let ways: [&[(&str, &str)]; 3] = [
        &[("RT_GL_MODE", "off"), ("RT_GL_STATS", "1")],
        &[("RT_GL_MODE", "gl"), ("RT_GL_STATS", "1")],
        &[("RT_GL_MODE", "gl"), ("RT_GL_STATS", "1"), ("RT_GL_ASYNC", "1")],
    ];
    let timed = stopped(secs, &p.timed);
    let args: Vec<&std::ffi::OsStr> = timed.iter().map(OsString::as_os_str).collect();
    for (k, env) in ways.iter().enumerate() {
        fps_of[k] = fps(&run_x(&args, Some(lib), env)?, t);
    }
    let dumps = dir.join("gl-programs-frames");
    let _ = std::fs::remove_dir_all(&dumps);
    std::fs::create_dir_all(&dumps).map_err(|e| e.to_string())?;
    let d = dumps.to_string_lossy().into_owned();
    let args: Vec<&std::ffi::OsStr> = p.dumped.iter().map(OsString::as_os_str).collect();
    run_x(&args, Some(lib), &[("RT_GL_DUMP", &d), ("RT_GL_DUMP_RASTER", "1")])?;
    let (mut cov, mut col) = (Vec::new(), Vec::new());
    // Frames with nothing drawn have no dumps: every raster there is.
    let mut rasters: Vec<PathBuf> = std::fs::read_dir(&dumps)
        .map_err(|e| e.to_string())?
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("raster-")))
        .collect();
    rasters.sort();
    for raster in rasters {
        let name =
            raster.file_name().unwrap_or_default().to_string_lossy().replace("raster-", "rt-");
        let traced = dumps.join(name);
        // A frame left as rasterized (an error the program provokes) or
        // written half when the program was stopped is not compared.
        if let (true, Ok((a, c))) = (traced.exists(), agreement(&raster, &traced)) {
            cov.push(a);
            col.push(c);
        }
    }
    let _ = std::fs::remove_dir_all(&dumps);
    let frames = cov.len();
    let worst_cov = cov.iter().copied().fold(f64::NAN, f64::min);
    let worst_col = col.iter().copied().fold(f64::NAN, f64::max);
    Ok(Row {
        frames,
        coverage: (worst_cov, median(&mut cov)),
        colour: (median(&mut col), worst_col),
        fps: fps_of,
    })
}

/// What [`table`] found.
pub(crate) struct Summary {
    /// The markdown table.
    pub(crate) md: String,
    /// Debian programs run.
    pub(crate) real: usize,
    /// Programs run, and those at ≥ 99 % coverage agreement in every
    /// frame with a mean colour difference ≤ 10/255 in every frame.
    pub(crate) total: usize,
    pub(crate) on_target: usize,
}

/// The table (markdown) and its CSV, written as `gl-programs.csv`.
pub(crate) fn table(dir: &Path, lib: &Path, quick: bool) -> Result<Summary, String> {
    let secs = if quick { "3" } else { "6" };
    let mut md = String::from(
        "| program | exercises | frames compared | coverage worst / median | colour difference median / worst (/255) | fps off | fps traced | fps traced async | traced / off |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut csv = String::from(
        "program,frames,coverage_worst,coverage_median,colour_median,colour_worst,fps_off,fps_traced,fps_async\n",
    );
    let list = programs(dir, secs)?;
    let (mut real, mut on_target) = (0, 0);
    for p in &list {
        eprintln!("gl: {}", p.name);
        let r = measure(p, dir, lib, secs)?;
        real += usize::from(
            !p.name.starts_with("private_gl")
                && !p.name.starts_with("scenes")
                && p.name != "egl_gl",
        );
        on_target += usize::from(r.frames > 0 && r.coverage.0 >= 0.99 && r.colour.1 <= 10.0);
        let f = |x: Option<f64>| x.map_or("—".to_owned(), |v| format!("{v:.1}"));
        let ratio = match r.fps {
            [Some(off), Some(traced), _] => format!("{:.3}", traced / off),
            _ => "—".into(),
        };
        writeln!(
            md,
            "| {} | {} | {} | {:.2} % / {:.2} % | {:.2} / {:.2} | {} | {} | {} | {ratio} |",
            p.name,
            p.what,
            r.frames,
            100.0 * r.coverage.0,
            100.0 * r.coverage.1,
            r.colour.0,
            r.colour.1,
            f(r.fps[0]),
            f(r.fps[1]),
            f(r.fps[2]),
        )
        .unwrap();
        let c = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:.3}"));
        writeln!(
            csv,
            "{},{},{:.6},{:.6},{:.4},{:.4},{},{},{}",
            p.name,
            r.frames,
            r.coverage.0,
            r.coverage.1,
            r.colour.0,
            r.colour.1,
            c(r.fps[0]),
            c(r.fps[1]),
            c(r.fps[2])
        )
        .unwrap();
    }
    std::fs::write(dir.join("gl-programs.csv"), csv).map_err(|e| e.to_string())?;
    Ok(Summary { md, real, total: list.len(), on_target })
}
