//! `rt-report`: run time against error, per area, as tables and CSV files
//! under `target/rt-report/`.
//!
//! ```text
//! cargo run --release -p rt-benches --bin rt-report -- traversal [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- watertight [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- grin [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- octree [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- schlieren [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- noise [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- bos [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- focusing [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- render [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- composite [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- unstructured [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- distributed [--quick]
//! cargo run --release -p rt-benches --bin rt-report -- gl [--quick]         # needs xvfb-run, cc, glxgears
//! cargo run --release -p rt-benches --bin rt-report -- python [--quick]     # needs RT_PYTHON with rtvis, trimesh, embreex
//! cargo run --release -p rt-benches --bin rt-report -- all [--quick]   # + index.md
//! ```
// A std-only tool crate: the no_std import lints guard the libraries.
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

mod bos;
mod composite;
mod distributed;
#[cfg(feature = "embree3")]
mod embree3;
#[cfg(feature = "embree4")]
mod embree4;
#[cfg(any(feature = "embree3", feature = "embree4"))]
mod filter;
mod focusing;
mod gl;
mod gl_programs;
mod grin;
mod noise;
mod octree;
mod python;
mod render;
mod schlieren;
mod schlieren_dense;
mod timing;
#[cfg(feature = "tinybvh")]
mod tinybvh;
mod traversal;
mod unstructured;
mod watertight;

use std::{io::Write as _, path::PathBuf, process::ExitCode};

/// Where reports go: `$CARGO_TARGET_DIR/rt-report` or `target/rt-report` at
/// the workspace root.
fn out_dir() -> PathBuf {
    // The workspace root is this package's parent folder (named as such,
    // not as `benches/..`, in the paths the report prints).
    let here = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = here.parent().unwrap_or(here);
    let target =
        std::env::var_os("CARGO_TARGET_DIR").map_or_else(|| root.join("target"), PathBuf::from);
    target.join("rt-report")
}

/// One area's part of the report.
pub(crate) struct Section {
    /// Heading (without `##`).
    pub(crate) title: String,
    /// Tables and notes, markdown.
    pub(crate) body: String,
    /// One line each, against the area's targets.
    pub(crate) verdicts: Vec<String>,
    /// `(file name in the report folder, caption)`.
    pub(crate) plots: Vec<(String, String)>,
}

/// CPU model and core count, from `/proc/cpuinfo` and the OS.
fn machine() -> String {
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    format!("{model}, {cores} cores available, {} {}", std::env::consts::OS, std::env::consts::ARCH)
}

/// `index.md`: the machine, then per area its verdicts, plots and tables.
fn index(sections: &[(&str, Section)], quick: bool, seconds: f64) -> String {
    use std::fmt::Write as _;
    let mut out = String::from("# rt report: run time against error\n\n");
    writeln!(
        out,
        "Machine: {}. Mode: {}. Took {seconds:.0} s. Command: `cargo run --release -p rt-benches --bin rt-report -- all{}`.\n",
        machine(),
        if quick { "quick (smaller problems, fewer repetitions)" } else { "full" },
        if quick { " --quick" } else { "" }
    )
    .unwrap();
    out.push_str("How to read it: each area has one line per target (met / NOT met), its plot — error (y) against run time (x) on log–log axes, the Pareto front ringed (no other point is both faster and more accurate) — and its table. Timings are best of N runs with the spread (slowest over fastest); ratios between implementations come from the same run. CSV files beside this page hold every number.\n\n## Verdicts\n\n");
    for (area, s) in sections {
        for v in &s.verdicts {
            writeln!(out, "- **{area}**: {v}").unwrap();
        }
    }
    for (_, s) in sections {
        writeln!(out, "\n## {}\n", s.title).unwrap();
        for v in &s.verdicts {
            writeln!(out, "- {v}").unwrap();
        }
        for (file, caption) in &s.plots {
            writeln!(out, "\n![{caption}]({file})\n\n*{file}*: {caption}.").unwrap();
        }
        writeln!(out, "\n{}", s.body).unwrap();
    }
    out
}

const USAGE: &str = "usage: rt-report [AREA ...] [--quick]

Writes tables, CSV files and plots under target/rt-report/.
AREA: traversal, watertight, grin, octree, schlieren, noise, bos, focusing, render,
composite, unstructured, distributed (none or
`all`: every one of these, plus target/rt-report/index.md), gl (rt-gl
against Mesa; needs xvfb-run, cc and glxgears) or python (rtvis.RayMesh
against embreex; needs RT_PYTHON with rtvis, trimesh and embreex); these
two are not part of `all`.
--quick: smaller problems, fewer repetitions (checks the pipeline, not the
targets).

unstructured writes unstructured.csv (case,method,cells,seconds,
max_deflection_error: the Gaussian bump on N = 8..64 cells per side, 64x64
rays, one thread, error = |exit direction - exact| / peak deflection),
unstructured_detail.csv (case,method,cells,build_seconds,seconds,rays,
rays_per_s,max_deflection_error,mean_deflection_error,max_pixel_error,
stalled: + mean over the rays, the largest error of 8x8-ray pixel means
and the rays that did not leave the far side) and
unstructured_throughput.csv (method,case,cells,build_seconds,rays,threads,
seconds,photons_per_s,cells_crossed,cells_per_s: a 256x256 beam through
the N = 64 mesh, 6.29M tetrahedra, one thread and all cores;
cells_crossed = sum of TraceStats::steps, the tetrahedra crossed).

schlieren writes schlieren.csv (case,method,photons,seconds,rmse: the
sparse 128^3 field's sweep, and the dense 128^3 flow rendered as
`rt schlieren` renders it, one thread, rmse against RK4 at h/4 from the
same photons) and the dense flow itself, dense_flow_128.json + .raw.

distributed writes distributed.csv (kind,ranks,seconds,items_sent,
bytes_sent,messages,identical_to_single: surfaces with shadows and AO and
the blast wave's knife-edge schlieren on 1, 2, 4, 8, 16 in-process ranks;
items are occlusion rays or photons sent between ranks).";

fn main() -> ExitCode {
    // SAFETY: the first thing the program does: no other thread runs yet.
    unsafe { rt_gpu::quiet_without_session() };
    let t0 = std::time::Instant::now();
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.iter().any(|a| a == "--help" || a == "-h") {
        // Not `println!`, which panics when the reader has gone
        // (`rt-report --help | head`).
        let _ = writeln!(std::io::stdout(), "{USAGE}");
        return ExitCode::SUCCESS;
    }
    if let Some(bad) = args.iter().find(|a| a.starts_with('-') && *a != "--quick") {
        eprintln!("rt-report: unknown option `{bad}` (known: --quick, --help)\n\n{USAGE}");
        return ExitCode::from(2);
    }
    let quick = args.iter().any(|a| a == "--quick");
    let areas: Vec<&str> =
        args.iter().filter(|a| !a.starts_with("--")).map(String::as_str).collect();
    let all = areas.is_empty() || areas == ["all"];
    let areas = if all {
        vec![
            "traversal",
            "watertight",
            "grin",
            "octree",
            "schlieren",
            "noise",
            "bos",
            "focusing",
            "render",
            "composite",
            "unstructured",
            "distributed",
        ]
    } else {
        areas
    };
    let dir = out_dir();
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    let mut sections = Vec::new();
    for area in areas {
        let result = match area {
            "traversal" => traversal::run(&dir, quick),
            "watertight" => watertight::run(&dir, quick),
            "grin" => grin::run(&dir, quick),
            "octree" => octree::run(&dir, quick),
            "schlieren" => schlieren::run(&dir, quick),
            "noise" => noise::run(&dir, quick),
            "bos" => bos::run(&dir, quick),
            "focusing" => focusing::run(&dir, quick),
            "render" => render::run(&dir, quick),
            "composite" => composite::run(&dir, quick),
            "unstructured" => unstructured::run(&dir, quick),
            "distributed" => distributed::run(&dir, quick),
            "gl" => gl::run(&dir, quick),
            "python" => python::run(&dir, quick),
            other => Err(format!(
                "unknown area `{other}` (known: traversal, watertight, grin, octree, schlieren, noise, bos, focusing, render, composite, unstructured, distributed, gl, python, all)"
            )),
        };
        match result {
            Ok(s) => {
                let mut text = format!("## {}\n\n{}\n", s.title, s.body);
                for v in &s.verdicts {
                    text += &format!("- {v}\n");
                }
                for (file, caption) in &s.plots {
                    text += &format!("- plot {}: {caption}\n", dir.join(file).display());
                }
                // Written, not `println!`ed: a reader that has gone
                // (`rt-report traversal | head`) must not panic the
                // report, which still writes its files.
                let _ = writeln!(std::io::stdout(), "{text}");
                sections.push((area, s));
            }
            Err(e) => {
                eprintln!("rt-report {area}: {e}");
                return ExitCode::FAILURE;
            }
        }
    }
    if all {
        let path = dir.join("index.md");
        if let Err(e) = std::fs::write(&path, index(&sections, quick, t0.elapsed().as_secs_f64())) {
            eprintln!("cannot write {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        let _ = writeln!(std::io::stdout(), "wrote {}", path.display());
    }
    ExitCode::SUCCESS
}
