//! rt-gl against the real GL it stands in front of: the C test program
//! drawing a static-VBO grid of N triangles, frame times with Mesa's
//! software GL alone and with rt-gl (`gl` mode, all cores) traced over
//! it; glxgears' frame rate both ways; a side-by-side of glxgears as
//! Mesa rasterizes it and as rt-gl traces it with shadows and ambient
//! occlusion. GLuRay's claim, checked on this machine: ray tracing's
//! frame time grows with log(triangles) once the BVH is built, so it
//! overtakes software rasterization as meshes grow.
//!
//! Needs `xvfb-run`, `cc`, libGL/libX11 headers and `glxgears`
//! (Debian: `xvfb xauth mesa-utils libgl-dev libx11-dev`).

use std::{
    fmt::Write as _,
    path::{Path, PathBuf},
    process::Command,
};

use rt_benches::plot::{Plot, Series, loglog};

use crate::Section;

const XVFB: [&str; 3] = ["-a", "-s", "-screen 0 1024x768x24"];

pub(crate) fn tool(name: &str) -> Result<PathBuf, String> {
    let out = Command::new("sh")
        .args(["-c", &format!("command -v {name}")])
        .output()
        .map_err(|e| e.to_string())?;
    if out.status.success() {
        Ok(PathBuf::from(String::from_utf8_lossy(&out.stdout).trim()))
    } else {
        Err(format!(
            "`{name}` not found (Debian: apt-get install xvfb xauth mesa-utils libgl-dev libx11-dev)"
        ))
    }
}

/// Builds the interposer (release) and returns its path.
fn interposer(dir: &Path) -> Result<PathBuf, String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let status = Command::new(cargo)
        .args(["build", "--release", "-p", "rt-gl"])
        .status()
        .map_err(|e| format!("running cargo: {e}"))?;
    if !status.success() {
        return Err("cargo build --release -p rt-gl failed".into());
    }
    // The report folder is `<target>/rt-report`.
    let lib = dir.join("..").join("release").join("librt_gl.so");
    if lib.exists() { Ok(lib) } else { Err(format!("{} not found after the build", lib.display())) }
}

/// Compiles the C test program into `dir`.
fn scenes_program(dir: &Path) -> Result<PathBuf, String> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rt-gl/tests/gl-programs/scenes.c");
    let exe = dir.join("gl-scenes");
    let status = Command::new(tool("cc")?)
        .arg("-O2")
        .arg("-o")
        .arg(&exe)
        .arg(&src)
        .args(["-lGL", "-lX11", "-lm"])
        .status()
        .map_err(|e| format!("running cc: {e}"))?;
    if status.success() { Ok(exe) } else { Err(format!("cc failed on {}", src.display())) }
}

/// Runs `args` under xvfb-run, with rt-gl preloaded when `lib` is given.
pub(crate) fn run_x(
    args: &[&std::ffi::OsStr],
    lib: Option<&Path>,
    env: &[(&str, &str)],
) -> Result<String, String> {
    let mut cmd = Command::new(tool("xvfb-run")?);
    cmd.args(XVFB).args(args);
    if let Some(l) = lib {
        cmd.env("LD_PRELOAD", l);
    }
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().map_err(|e| e.to_string())?;
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    // `timeout` ends glxgears with 124; anything else non-zero failed.
    if !out.status.success() && out.status.code() != Some(124) {
        return Err(format!("{args:?} failed ({}): {stderr}", out.status));
    }
    Ok(stdout + &stderr)
}

/// `(first frame, median of the others)` from the program's output.
fn frame_times(out: &str) -> Result<(f64, f64), String> {
    let t: Vec<f64> = out
        .lines()
        .filter_map(|l| l.strip_prefix("frame "))
        .filter_map(|l| l.split_whitespace().nth(1)?.parse().ok())
        .collect();
    let (first, rest) = t.split_first().ok_or("no frame times in the program's output")?;
    let mut rest = rest.to_vec();
    rest.sort_by(f64::total_cmp);
    let median = rest.get(rest.len() / 2).copied().ok_or("one frame only")?;
    Ok((*first, median))
}

/// glxgears' last "N frames in T seconds = F FPS" line.
fn fps(out: &str) -> Option<f64> {
    out.lines().rev().find_map(|l| {
        let (_, tail) = l.split_once(" = ")?;
        tail.split_whitespace().next()?.parse().ok()
    })
}

/// RGBA rows of a PNG.
pub(crate) fn read_png(path: &Path) -> Result<(u32, u32, Vec<u8>), String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut dec = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let mut buf = vec![0; dec.output_buffer_size()];
    let info = dec.next_frame(&mut buf).map_err(|e| format!("{}: {e}", path.display()))?;
    buf.truncate(info.buffer_size());
    Ok((info.width, info.height, buf))
}

/// `a` and `b` side by side (RGBA in, RGB out).
fn side_by_side(a: &Path, b: &Path, out: &Path) -> Result<(), String> {
    let (w, h, pa) = read_png(a)?;
    let (w2, h2, pb) = read_png(b)?;
    if (w, h) != (w2, h2) {
        return Err("the two frames differ in size".into());
    }
    let mut rgb = Vec::with_capacity(6 * (w * h) as usize);
    for y in 0..h as usize {
        for img in [&pa, &pb] {
            let row = &img[4 * y * w as usize..4 * (y + 1) * w as usize];
            rgb.extend(row.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]));
        }
    }
    rt_tools::image::write_rgb8(&rgb, 2 * w, h, out).map_err(|e| e.to_string())
}

fn counters(dir: &Path) -> Option<std::collections::HashMap<String, u64>> {
    let text = std::fs::read_to_string(dir.join("counters.txt")).ok()?;
    Some(
        text.split_whitespace()
            .filter_map(|kv| kv.split_once('='))
            .filter_map(|(k, v)| Some((k.to_owned(), v.parse().ok()?)))
            .collect(),
    )
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let lib = interposer(dir)?;
    let exe = scenes_program(dir)?;
    let gears = tool("glxgears")?;
    let sizes: &[u32] =
        if quick { &[10_000, 100_000] } else { &[10_000, 100_000, 1_000_000, 4_000_000] };
    let frames = if quick { "4" } else { "6" };
    let mut csv = String::from("program,triangles,implementation,first_frame_s,frame_s\n");
    let mut md = String::from(
        "| program | triangles | implementation | first frame (s) | frame (s, median after the first) | rt-gl / mesa |\n|---|---|---|---|---|---|\n",
    );
    let (mut mesa_pts, mut rt_pts) = (Vec::new(), Vec::new());
    let mut crossing = None;
    for &n in sizes {
        let ns = n.to_string();
        let args = [exe.as_os_str(), "mesh".as_ref(), ns.as_ref(), frames.as_ref()];
        eprintln!("gl: {n} triangles, Mesa");
        let (m_first, m_frame) = frame_times(&run_x(&args, None, &[])?)?;
        eprintln!("gl: {n} triangles, rt-gl");
        let (r_first, r_frame) = frame_times(&run_x(&args, Some(&lib), &[("RT_GL_MODE", "gl")])?)?;
        for (imp, first, frame) in [("mesa", m_first, m_frame), ("rt-gl", r_first, r_frame)] {
            writeln!(csv, "scenes-mesh,{n},{imp},{first:.6},{frame:.6}").unwrap();
        }
        writeln!(md, "| scenes mesh | {n} | mesa | {m_first:.4} | {m_frame:.4} | |").unwrap();
        writeln!(
            md,
            "| scenes mesh | {n} | rt-gl | {r_first:.4} | {r_frame:.4} | {:.2}× |",
            r_frame / m_frame
        )
        .unwrap();
        mesa_pts.push((f64::from(n), m_frame));
        rt_pts.push((f64::from(n), r_frame));
        if crossing.is_none() && r_frame < m_frame {
            crossing = Some(n);
        }
    }
    // glxgears both ways (its own FPS line, printed every 5 s).
    let secs = if quick { "6" } else { "11" };
    let gears_args =
        ["timeout".as_ref(), "-s".as_ref(), "INT".as_ref(), secs.as_ref(), gears.as_os_str()];
    eprintln!("gl: glxgears, Mesa");
    let mesa_fps = fps(&run_x(&gears_args, None, &[])?).ok_or("no FPS line from glxgears")?;
    eprintln!("gl: glxgears, rt-gl");
    let count_dir = dir.join("gl-glxgears-counters");
    let _ = std::fs::remove_dir_all(&count_dir);
    let cd = count_dir.to_string_lossy().into_owned();
    let rt_fps = fps(&run_x(&gears_args, Some(&lib), &[("RT_GL_DUMP", &cd)])?)
        .ok_or("no FPS line from glxgears under rt-gl")?;
    // Only the counters are kept from that run: the PNGs cost time.
    let gear_tris = counters(&count_dir).and_then(|c| c.get("triangles").copied()).unwrap_or(0);
    let _ = std::fs::remove_dir_all(&count_dir);
    for (imp, f) in [("mesa", mesa_fps), ("rt-gl", rt_fps)] {
        writeln!(csv, "glxgears,{gear_tris},{imp},,{:.6}", 1.0 / f).unwrap();
    }
    writeln!(
        md,
        "| glxgears | {gear_tris} | mesa | | {:.4} ({mesa_fps:.0} FPS) | |",
        1.0 / mesa_fps
    )
    .unwrap();
    writeln!(
        md,
        "| glxgears | {gear_tris} | rt-gl | | {:.4} ({rt_fps:.0} FPS) | {:.2}× |",
        1.0 / rt_fps,
        mesa_fps / rt_fps
    )
    .unwrap();
    std::fs::write(dir.join("gl.csv"), &csv).map_err(|e| e.to_string())?;

    // glxgears rasterized beside ray traced with shadows and AO.
    let shots = dir.join("gl-glxgears-frames");
    let _ = std::fs::remove_dir_all(&shots);
    let sd = shots.to_string_lossy().into_owned();
    let shot_args =
        ["timeout".as_ref(), "-s".as_ref(), "INT".as_ref(), "4".as_ref(), gears.as_os_str()];
    run_x(
        &shot_args,
        Some(&lib),
        &[
            ("RT_GL_MODE", "rt"),
            ("RT_GL_AO", "16"),
            ("RT_GL_DUMP", &sd),
            ("RT_GL_DUMP_RASTER", "1"),
        ],
    )?;
    let side = "gl-glxgears.png";
    side_by_side(&shots.join("raster-0005.png"), &shots.join("rt-0005.png"), &dir.join(side))?;
    let _ = std::fs::remove_dir_all(&shots);

    let summary = crate::gl_programs::table(dir, &lib, quick)?;
    let (programs, real) = (&summary.md, summary.real);

    let plot = Plot {
        title: "Frame time against triangles: Mesa (software GL) vs rt-gl".into(),
        x_label: "triangles".into(),
        y_label: "seconds per frame (after the first)".into(),
        series: vec![
            Series { name: "mesa".into(), points: mesa_pts },
            Series { name: "rt-gl (gl mode)".into(), points: rt_pts },
        ],
        pareto: false,
    };
    let plot_file = "gl.png";
    loglog(&plot, 900, 600, &dir.join(plot_file)).map_err(|e| e.to_string())?;
    let verdict = match crossing {
        Some(n) => format!(
            "rt-gl's frame is faster than Mesa's from {n} triangles on (after its first frame, which builds the BVH)"
        ),
        None => format!(
            "rt-gl's frame is not faster than Mesa's up to {} triangles on this machine",
            sizes.last().copied().unwrap_or(0)
        ),
    };
    let body = format!(
        "The C test program (`rt-gl/tests/gl-programs/scenes.c mesh N`) draws a lit grid of N triangles from a static VBO with an element buffer into a 512² window under `xvfb-run`; Mesa's software GL alone, then with rt-gl preloaded (`gl` mode, all cores: the frame is ray traced and written over Mesa's). Frame time = from the frame's first call to `glFinish` after the swap. glxgears: its own FPS line, 300² window.\n\n{md}\nSide by side: `{side}` (left: Mesa's raster; right: rt-gl, `RT_GL_MODE=rt`, 16 AO rays, shadows).\n\n### Every test program and the Debian programs found\n\nEach program run under `xvfb-run` (Mesa llvmpipe, 1024×768 screen): three timed runs of the same length with rt-gl loaded — `RT_GL_MODE=off` (calls forwarded, nothing recorded: the program's own frame rate through the interposer), traced (`gl` mode, all cores), traced asynchronously (`RT_GL_ASYNC=1`) — counting swaps; then a run with every frame dumped as Mesa rasterized it and as rt-gl shows it: coverage agreement (object vs the background of the raster's corner pixel) per frame, worst and median, and the mean colour difference where both cover. {real} real programs from Debian (mesa-utils, xscreensaver-gl) were found and run. CSV: `gl-programs.csv`.\n\n{programs}"
    );
    Ok(Section {
        title: "rt-gl: ray tracing an unmodified OpenGL program".into(),
        body,
        verdicts: vec![
            verdict,
            format!(
                "{} of {} programs ({} from Debian) at ≥ 99 % coverage agreement and ≤ 10/255 mean colour difference in every frame compared",
                summary.on_target, summary.total, summary.real
            ),
        ],
        plots: vec![
            (plot_file.into(), "frame time against triangles, log–log".into()),
            (
                side.into(),
                "glxgears: Mesa's raster (left), rt-gl with shadows and AO (right)".into(),
            ),
        ],
    })
}
