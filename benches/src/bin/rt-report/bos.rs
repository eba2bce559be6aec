//! Background-oriented schlieren: the ground-truth displacement against
//! the paraxial relation `Δ = M·Z_D·ε` (docs/oracles.md §7) and against a
//! converged render, over aperture samples, integrators and octree
//! skipping, with the run time of each.
//!
//! The flow is docs/oracles.md §7's Gaussian bump (δ = 1e-4, σ = 1 cm at
//! Z_A = 1.1 m; the camera, f = 0.1 m, focused on the background at
//! Z_B = 2.1 m, M = 0.05, 5 µm pixels), analytic or sampled on a 96³ grid
//! of 1 mm (±4.75σ). Case `paraxial`: an f/400 camera (the rays of a pixel
//! cross the bump within 0.1 mm), each pixel against the relation at its
//! impact point. Case `f8`: an f/8 camera (the flow blurred over ~50
//! pixels), against the analytic field traced with the adaptive integrator
//! at tolerance 1e-10 through 8 × 8 aperture samples.

use std::{fmt::Write as _, path::Path};

use glam::DVec3;
use rt_benches::plot::{Plot, Series, loglog};
use rt_photo::{
    Background, Bos, BosImages, DotBackground, GridField, ThinLens, TraceParams,
    rt_volume::{GaussianBump, Grid, Interp, Method},
};
use rt_photo::{GridMedium, Medium};

use crate::{
    Section,
    timing::{Samples, time},
};

const DELTA: f64 = 1e-4;
const SIGMA: f64 = 0.01;
const Z_A: f64 = 1.1;
const Z_B: f64 = 2.1;
const PITCH: f64 = 5e-6;

fn camera(f_number: f64, side: usize) -> ThinLens {
    ThinLens {
        position: DVec3::ZERO,
        direction: DVec3::Z,
        up: DVec3::Y,
        focal_length: 0.1,
        f_number,
        focus_distance: Z_B,
        pixel_pitch: PITCH,
        width: side,
        height: side,
    }
}

/// The bump sampled on a 96³ grid of 1 mm around its centre.
fn gridded(interp: Interp) -> Result<GridField, String> {
    let (n, h) = (96usize, 1e-3);
    let half = 0.5 * h * (n - 1) as f64;
    let origin = DVec3::new(-half, -half, Z_A - half);
    let mut data = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h
                    - DVec3::new(0.0, 0.0, Z_A);
                let g = (-p.length_squared() / (2.0 * SIGMA * SIGMA)).exp();
                data.push((1.0 + DELTA * g) as f32);
            }
        }
    }
    let grid = Grid::new([n; 3], origin, DVec3::splat(h), data).map_err(|e| e.to_string())?;
    GridField::new(grid, interp, 1.0).map_err(|e| e.to_string())
}

/// docs/oracles.md §7 at every pixel: the displacement (pixels, x right, y down)
/// of the background seen through the chief ray's impact point.
fn paraxial(cam: &ThinLens) -> Vec<[f64; 2]> {
    let m = cam.magnification();
    let mut out = Vec::with_capacity(cam.width * cam.height);
    for j in 0..cam.height {
        for i in 0..cam.width {
            let p = cam.focus_point(i as f64 + 0.5, j as f64 + 0.5) * (Z_A / Z_B);
            let (x, y) = (p.x, p.y);
            let g = (-(x * x + y * y) / (2.0 * SIGMA * SIGMA)).exp();
            let e = -(std::f64::consts::TAU).sqrt() * DELTA * g / SIGMA;
            // The landing point moves by Z_D·ε; the image's right is −x,
            // its y runs down (−y).
            out.push([-m * (Z_B - Z_A) * e * x / PITCH, -m * (Z_B - Z_A) * e * y / PITCH]);
        }
    }
    out
}

fn rmse(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let s: f64 = a.iter().zip(b).map(|(p, q)| (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sum();
    (s / a.len().max(1) as f64).sqrt()
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let side = if quick { 24 } else { 64 };
    let reps = if quick { 1 } else { 3 };
    let analytic = GaussianBump::new(DVec3::new(0.0, 0.0, Z_A), DELTA, SIGMA, 5.0);
    let linear = gridded(Interp::Trilinear)?;
    let cubic = gridded(Interp::CatmullRom)?;
    let for_grid = TraceParams::for_grid(&linear);
    // The command line's integrator: leapfrog, steps of two cells.
    let leapfrog =
        TraceParams { step: 2.0 * for_grid.step, max_step: 2.0 * for_grid.max_step, ..for_grid };
    let rk4 = TraceParams::fixed(Method::Rk4, for_grid.step);
    // The grids as media on their octrees' fast path, with each integrator.
    let medium = |field: &GridField, params| -> Result<Medium, String> {
        let grid = GridMedium::from_field(field.clone(), params).map_err(|e| e.to_string())?;
        Ok(Medium::Grid(grid))
    };
    let (leap_l, rk4_l, rk4_c) =
        (medium(&linear, leapfrog)?, medium(&linear, rk4)?, medium(&cubic, rk4)?);
    let samples: &[u32] = if quick { &[1, 2] } else { &[1, 2, 4] };
    let mut csv = String::from("case,method,samples,seconds,displacement_rmse_px\n");
    let mut md = String::from(
        "| case | method | samples/pixel | seconds | displacement rms error (px) |\n|---|---|---|---|---|\n",
    );
    let mut series: Vec<Series> = Vec::new();
    let mut verdicts = Vec::new();
    for (case, f_number) in [("paraxial", 400.0), ("f8", 8.0)] {
        let cam = camera(f_number, side);
        let bos = |k: u32, params: TraceParams| Bos {
            camera: cam,
            background_distance: Z_B,
            background: Background::RandomDots(DotBackground::for_camera(&cam, 3.0, 4.0, 9)),
            aperture_samples: k,
            params,
        };
        let truth = if case == "paraxial" {
            paraxial(&cam)
        } else {
            bos(8, TraceParams::accurate())
                .render(&analytic, 1)
                .map_err(|e| e.to_string())?
                .displacement
        };
        type Run<'a> = Box<dyn Fn(&Bos) -> Result<BosImages, rt_photo::BosError> + 'a>;
        let methods: Vec<(&str, TraceParams, Run<'_>)> = vec![
            (
                "analytic-adaptive",
                TraceParams::accurate(),
                Box::new(|b: &Bos| b.render(&analytic, 2)),
            ),
            ("grid-leapfrog-2cell", leapfrog, Box::new(|b: &Bos| b.render(&linear, 2))),
            (
                "grid-leapfrog-2cell-octree",
                leapfrog,
                Box::new(|b: &Bos| b.render_medium(&leap_l, 2)),
            ),
            ("grid-rk4-1cell", rk4, Box::new(|b: &Bos| b.render(&linear, 2))),
            ("grid-rk4-1cell-octree", rk4, Box::new(|b: &Bos| b.render_medium(&rk4_l, 2))),
            ("cubic-grid-rk4-1cell-octree", rk4, Box::new(|b: &Bos| b.render_medium(&rk4_c, 2))),
        ];
        for (name, params, run) in &methods {
            let mut points = Vec::new();
            for &k in samples {
                let b = bos(k, *params);
                let mut t = Samples::default();
                let mut last = None;
                for _ in 0..reps {
                    let (secs, out) = time(|| run(&b));
                    t.0.push(secs);
                    last = Some(out.map_err(|e| e.to_string())?);
                }
                let out = last.ok_or("no run")?;
                let err = rmse(&out.displacement, &truth);
                let secs = t.best();
                writeln!(csv, "{case},{name},{},{secs:.4},{err:.5e}", k * k).unwrap();
                writeln!(
                    md,
                    "| {case} | {name} | {} | {secs:.3} (+{:.0}%) | {err:.4} |",
                    k * k,
                    t.spread()
                )
                .unwrap();
                points.push((secs, err.max(1e-9)));
            }
            series.push(Series { name: format!("{case}: {name}"), points });
        }
        // The octree's own effect: skipping against the same integrator.
        let b = bos(samples[samples.len() - 1], leapfrog);
        let plain = b.render(&linear, 2).map_err(|e| e.to_string())?;
        let fast = b.render_medium(&leap_l, 2).map_err(|e| e.to_string())?;
        let moved = plain
            .displacement
            .iter()
            .zip(&fast.displacement)
            .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
            .fold(0.0f64, f64::max);
        verdicts.push(format!(
            "{case}: octree skipping moves the ground truth by at most {moved:.4} px (budget 0.1 px) → {}",
            if moved <= 0.1 { "met" } else { "NOT met" }
        ));
    }
    std::fs::write(dir.join("bos.csv"), &csv).map_err(|e| e.to_string())?;
    let plot = Plot {
        pareto: false,
        title: "BOS ground truth: error against time".into(),
        x_label: format!("seconds for a {side}² image (best of {reps})"),
        y_label: "displacement rms error (pixels)".into(),
        series,
    };
    loglog(&plot, 900, 600, &dir.join("bos.png")).map_err(|e| e.to_string())?;
    writeln!(md, "\nwrote {}", dir.join("bos.csv").display()).unwrap();
    openpiv_closure(dir, &mut md, &mut verdicts);
    Ok(Section {
        title: format!(
            "bos (docs/oracles.md §7 bump, {side}² pixels, analytic or on a 96³ grid; paraxial: f/400 against Δ = M·Z_D·ε; f8: against the analytic field at 64 samples, adaptive 1e-10)"
        ),
        body: md,
        verdicts,
        plots: vec![(
            "bos.png".into(),
            "displacement rms error (y, pixels) against seconds (x), one line per case and method over 1, 4, 16 aperture samples per pixel".into(),
        )],
    })
}

/// The closure against OpenPIV (`rt-python/examples/bos_openpiv.py`): a
/// BOS pair of a Gaussian density bump from `rtvis.bos` and `rt bos`, with
/// and without sensor noise, cross-correlated by OpenPIV, against rt's
/// truth averaged over each window. Run with the Python `$RT_PYTHON`
/// names, or CI's virtualenv (`target/venv-rtvis`) when it has rtvis and
/// openpiv; otherwise the section says it was not run.
fn openpiv_closure(dir: &Path, md: &mut String, verdicts: &mut Vec<String>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let python = std::env::var_os("RT_PYTHON")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| root.join("target/venv-rtvis/bin/python"));
    let script = root.join("rt-python/examples/bos_openpiv.py");
    let json = dir.join("bos-openpiv.json");
    let mut cmd = std::process::Command::new(&python);
    cmd.arg(&script).arg("--json").arg(&json);
    let rt = root.join("target/release/rt");
    if rt.exists() {
        cmd.arg("--rt").arg(&rt);
    }
    match cmd.output() {
        Ok(out) if out.status.success() => {
            let table = String::from_utf8_lossy(&out.stdout);
            writeln!(md, "\nOpenPIV (window 32 px, overlap 16) against rt's truth averaged over each window:\n\n{table}").unwrap();
            let rows = std::fs::read_to_string(&json).unwrap_or_default();
            // The thresholds: same sign and shape, sub-pixel agreement.
            let met = rows.contains("correlation")
                && table.lines().filter(|l| l.starts_with("| rt")).all(|l| {
                    let cells: Vec<&str> = l.split('|').map(str::trim).collect();
                    let corr: f64 = cells.get(3).and_then(|c| c.parse().ok()).unwrap_or(-1.0);
                    let rms: f64 = cells.get(4).and_then(|c| c.parse().ok()).unwrap_or(9.0);
                    corr >= 0.98 && rms <= 0.1
                });
            verdicts.push(format!(
                "OpenPIV closure: correlation ≥ 0.98 and rms ≤ 0.1 px in every case → {}",
                if met { "met" } else { "NOT met" }
            ));
        }
        Ok(out) => {
            let why = String::from_utf8_lossy(&out.stderr);
            let last = why.lines().last().unwrap_or("no message");
            writeln!(md, "\nOpenPIV closure: failed ({}: {last})", python.display()).unwrap();
            verdicts.push("OpenPIV closure → NOT met (the script failed)".into());
        }
        Err(_) => {
            writeln!(
                md,
                "\nOpenPIV closure: not run (no {}; set RT_PYTHON to a Python with rtvis and openpiv)",
                python.display()
            )
            .unwrap();
        }
    }
}
