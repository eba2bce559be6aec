//! Octree skipping against uniform stepping on a sparse and a dense
//! 128³ field: field evaluations, time, and the deflection error the
//! skipping introduces (against the same integrator without skipping).

use std::{fmt::Write as _, path::Path};

use glam::DVec3;
use rt_benches::scenes::{BUMP_GRID, dense_bumps, sparse_bumps};
use rt_volume::{Method, TraceParams, TraceResult, build_octree, trace, trace_skipping};

use rt_benches::plot::{Plot, Series, loglog};

use crate::{
    Section,
    timing::{Samples, time},
};

/// A 32 × 32 beam of parallel rays along z through the unit cube.
fn beam() -> Vec<(DVec3, DVec3)> {
    (0..32 * 32)
        .map(|i| {
            let (x, y) = ((i % 32) as f64 + 0.5, (i / 32) as f64 + 0.5);
            (DVec3::new(x / 32.0, y / 32.0, -0.1), DVec3::Z)
        })
        .collect()
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let params = TraceParams::fixed(Method::Rk4, 0.5 / BUMP_GRID as f64);
    let rays = beam();
    let rays = if quick { &rays[..256] } else { &rays[..] };
    let mut csv = String::from("field,method,field_evals,seconds,max_deflection_error,tolerance\n");
    let mut md = String::from(
        "| field | method | tolerance | field evals | seconds | max deflection error | ≤ tolerance | evals vs uniform |\n|---|---|---|---|---|---|---|---|\n",
    );
    let mut verdict = String::new();
    // The tolerance is a per-ray budget: the error stays within it on
    // every field, dense ones included.
    let mut over = Vec::new();
    let mut series = Vec::new();
    for (name, f) in [("sparse", sparse_bumps()), ("dense", dense_bumps())] {
        let tree = build_octree(&f).map_err(|e| e.to_string())?;
        // Best of 3, with the spread (slowest / fastest − 1).
        let go = |skip: Option<f64>| -> Result<(Samples, Vec<TraceResult>), String> {
            let mut samples = Samples::default();
            let mut last = Vec::new();
            for _ in 0..3 {
                let (secs, out) = time(|| {
                    rays.iter()
                        .map(|(o, d)| match skip {
                            None => trace(&f, *o, *d, &params),
                            Some(tol) => trace_skipping(&f, &tree, *o, *d, &params, tol),
                        })
                        .collect::<Result<Vec<_>, _>>()
                });
                samples.0.push(secs);
                last = out.map_err(|e| e.to_string())?;
            }
            Ok((samples, last))
        };
        let (us, uniform) = go(None)?;
        let useconds = us.best();
        let uevals: u64 = uniform.iter().map(|r| u64::from(r.stats.field_evals)).sum();
        writeln!(csv, "{name},uniform,{uevals},{useconds:.4},0,0").unwrap();
        writeln!(
            md,
            "| {name} | uniform | — | {uevals} | {useconds:.3} (+{:.0}%) | 0 | — | 1 |",
            us.spread()
        )
        .unwrap();
        let mut points = Vec::new();
        for tol in [1e-3, 1e-4, 1e-5, 1e-6, 1e-7] {
            let (samples, out) = go(Some(tol))?;
            let secs = samples.best();
            let evals: u64 = out.iter().map(|r| u64::from(r.stats.field_evals)).sum();
            let err = out
                .iter()
                .zip(&uniform)
                .map(|(a, b)| (a.direction - b.direction).length())
                .fold(0.0f64, f64::max);
            writeln!(csv, "{name},octree,{evals},{secs:.4},{err:e},{tol:e}").unwrap();
            let ratio = evals as f64 / uevals as f64;
            writeln!(
                md,
                "| {name} | octree | {tol:.0e} | {evals} | {secs:.3} (+{:.0}%) | {err:.2e} | {} | {ratio:.3} |",
                samples.spread(),
                if err <= tol { "yes" } else { "no" }
            )
            .unwrap();
            points.push((secs, err.max(1e-17)));
            if err > tol {
                over.push(format!("{name} at {tol:.0e}: {err:.1e}"));
            }
            if name == "sparse" && err <= tol && ratio <= 0.2 && verdict.is_empty() {
                verdict = format!(
                    "sparse: octree at tolerance {tol:.0e} uses {ratio:.3}× the field evaluations of uniform stepping with max deflection error {err:.1e} ≤ tolerance → met (target ≤ 1/5)"
                );
            }
        }
        series.push(Series { name: format!("{name} field, octree skipping"), points });
    }
    if verdict.is_empty() {
        verdict = "sparse: no tolerance reached ≤ 1/5 of uniform's evaluations within tolerance → NOT met".into();
    }
    let within = if over.is_empty() {
        "every field, every tolerance: max deflection error ≤ tolerance (a per-ray budget) → met"
            .to_string()
    } else {
        format!("max deflection error over the tolerance: {} → NOT met", over.join(", "))
    };
    std::fs::write(dir.join("octree.csv"), &csv).map_err(|e| e.to_string())?;
    let plot = Plot {
        pareto: true,
        title: "Octree skipping: error against time over tolerances 1e-3 … 1e-7".into(),
        x_label: format!("seconds for {} rays (best of 3)", rays.len()),
        y_label: "max deflection error |Δ direction| (1e-17 = exact)".into(),
        series,
    };
    loglog(&plot, 800, 560, &dir.join("octree.png"))?;
    writeln!(md, "\nwrote {}", dir.join("octree.csv").display()).unwrap();
    Ok(Section {
        title: format!(
            "octree (RK4, step = half a cell, {} rays of a parallel beam, 128³ grid, best of 3)",
            rays.len()
        ),
        body: md,
        verdicts: vec![verdict, within],
        plots: vec![(
            "octree.png".into(),
            "max deflection error (y; 1e-17 stands for exactly 0) against seconds (x) of the skipping tracer over tolerances 1e-3 … 1e-7, one line per field; rings: Pareto front".into(),
        )],
    })
}
