//! Curved-ray integrators: endpoint error against run time, per case and
//! integrator, over a sweep of steps (fixed-step methods) or tolerances
//! (adaptive). Error is measured against the closed-form oracles of
//! `docs/oracles.md` (`gaussian`, which has no closed form beyond first order:
//! against RK4 at step 2e-4).

use std::{fmt::Write as _, path::Path};

use glam::DVec3;
use rt_benches::plot::{Plot, Series, loglog};
use rt_volume::{
    Bounds, GaussianBump, GrinRod, IndexField, LinearIndex, Luneburg, Method, TraceParams, trace,
};

use crate::{
    Section,
    timing::{Samples, time},
};

/// A ray launched into a case, with the exact exit point.
struct Probe {
    origin: DVec3,
    direction: DVec3,
    exit: DVec3,
}

fn linear() -> (LinearIndex, Vec<Probe>) {
    let f = LinearIndex {
        n0: 1.0,
        gradient: DVec3::new(0.0, 0.2, 0.0),
        bounds: Bounds::new(DVec3::new(0.0, -1.0, -1.0), DVec3::new(2.0, 1.0, 1.0)),
    };
    // Catenary through y0: n0' = n0 + g y0, y = y0 + (n0'/g)(cosh(g x/n0') − 1).
    let probes = (0..8)
        .map(|i| {
            let y0 = -0.5 + i as f64 / 7.0;
            let n = 1.0 + 0.2 * y0;
            let y = y0 + n / 0.2 * ((0.2 * 2.0 / n).cosh() - 1.0);
            Probe {
                origin: DVec3::new(0.0, y0, 0.0),
                direction: DVec3::X,
                exit: DVec3::new(2.0, y, 0.0),
            }
        })
        .collect();
    (f, probes)
}

fn grin_rod() -> (GrinRod, Vec<Probe>) {
    let (n0, alpha, len) = (1.5, 0.5, 4.0);
    let f = GrinRod {
        n0,
        alpha,
        bounds: Bounds::new(DVec3::new(-1.0, -1.0, 0.0), DVec3::new(1.0, 1.0, len)),
    };
    let probes = (1..=8)
        .map(|i| {
            let r0 = 0.07 * f64::from(i);
            let beta = n0 * (1.0f64 - alpha * alpha * r0 * r0).sqrt();
            let x = r0 * (n0 * alpha / beta * len).cos();
            Probe {
                origin: DVec3::new(r0, 0.0, 0.0),
                direction: DVec3::Z,
                exit: DVec3::new(x, 0.0, len),
            }
        })
        .collect();
    (f, probes)
}

fn luneburg() -> (Luneburg, Vec<Probe>) {
    let r = 1.0;
    let f = Luneburg { center: DVec3::ZERO, radius: r };
    let probes = (0..8)
        .map(|i| {
            let a = f64::from(i) * 0.785;
            let rho = 0.1 + 0.1 * f64::from(i);
            Probe {
                origin: DVec3::new(rho * a.cos(), rho * a.sin(), -r),
                direction: DVec3::Z,
                exit: DVec3::new(0.0, 0.0, r),
            }
        })
        .collect();
    (f, probes)
}

fn gaussian() -> (GaussianBump, Vec<Probe>) {
    let f = GaussianBump::new(DVec3::ZERO, 0.05, 1.0, 5.0);
    // An independent reference: RK4 at a tiny step (error ~1e-15), not the
    // adaptive method the sweep measures.
    let reference = TraceParams::fixed(Method::Rk4, 2e-4);
    let probes = (0..8)
        .map(|i| {
            let o = DVec3::new(0.25 * f64::from(i + 1), 0.1, -5.0);
            let exit = trace(&f, o, DVec3::Z, &reference).expect("reference").position;
            Probe { origin: o, direction: DVec3::Z, exit }
        })
        .collect();
    (f, probes)
}

/// One row: (tolerance-or-step, steps, evals, seconds, max error, max drift).
/// `(knob, steps/ray, evals/ray, seconds/ray (best of 3), error, drift,
/// spread %)`.
type Row = (f64, u64, u64, f64, f64, f64, f64);

/// Runs one parameter setting over a case's probes.
type Case<'a> = &'a dyn Fn(&TraceParams) -> Row;

fn sweep<F: IndexField>(field: &F, probes: &[Probe], p: &TraceParams) -> Row {
    let run = || {
        let (mut steps, mut evals, mut err, mut drift) = (0u64, 0u64, 0.0f64, 0.0f64);
        for pr in probes {
            let r = trace(field, pr.origin, pr.direction, p).expect("valid trace");
            steps += u64::from(r.stats.steps);
            evals += u64::from(r.stats.field_evals);
            err = err.max((r.position - pr.exit).length());
            drift = drift.max(r.stats.invariant_drift);
        }
        (steps, evals, err, drift)
    };
    // Best of 3 for the time, with the spread.
    let mut samples = Samples::default();
    let mut out = (0, 0, 0.0, 0.0);
    for _ in 0..3 {
        let (s, o) = time(run);
        samples.0.push(s);
        out = o;
    }
    let best = samples.best();
    let n = probes.len() as u64;
    let knob = if p.method == Method::Adaptive { p.tolerance } else { p.step };
    (knob, out.0 / n, out.1 / n, best / n as f64, out.2, out.3, samples.spread())
}

fn params(method: Method, quick: bool) -> Vec<TraceParams> {
    let fine = if quick { 6 } else { 12 };
    match method {
        // 1e-3 … 1e-14: tighter than that is below f64 resolution.
        Method::Adaptive => (0..fine.min(12))
            .map(|k| TraceParams { tolerance: 10f64.powi(-3 - k), ..TraceParams::accurate() })
            .collect(),
        Method::Euler => {
            (0..fine + 2).map(|k| TraceParams::fixed(method, 0.2 / 2f64.powi(k))).collect()
        }
        _ => (0..fine).map(|k| TraceParams::fixed(method, 0.4 / 2f64.powi(k))).collect(),
    }
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let mut csv = String::from(
        "case,integrator,tolerance,steps,field_evals,seconds,endpoint_error,invariant_drift\n",
    );
    let mut md = String::new();
    let mut verdicts = Vec::new();
    let mut plots = Vec::new();
    let (lf, lp) = linear();
    let (gf, gp) = grin_rod();
    let (uf, up) = luneburg();
    let (bf, bp) = gaussian();
    let cases: [(&str, Case<'_>); 4] = [
        ("linear", &|p| sweep(&lf, &lp, p)),
        ("grin-rod", &|p| sweep(&gf, &gp, p)),
        ("luneburg", &|p| sweep(&uf, &up, p)),
        ("gaussian", &|p| sweep(&bf, &bp, p)),
    ];
    for (case, f) in cases {
        let mut series = Vec::new();
        let mut rows_by_method = Vec::new();
        for m in Method::ALL {
            let rows: Vec<Row> = params(m, quick).iter().map(f).collect();
            for r in &rows {
                writeln!(
                    csv,
                    "{case},{},{:e},{},{},{:e},{:e},{:e}",
                    m.name(),
                    r.0,
                    r.1,
                    r.2,
                    r.3,
                    r.4,
                    r.5
                )
                .unwrap();
            }
            series.push(Series {
                name: m.name().into(),
                points: rows.iter().map(|r| (r.3, r.4)).collect(),
            });
            rows_by_method.push((m, rows));
        }
        let png = dir.join(format!("grin-{case}.png"));
        let plot = Plot {
            pareto: true,
            title: format!(
                "GRIN integrators, {case} field: error against time (step / tolerance sweep)"
            ),
            x_label: "seconds per ray (best of 3)".into(),
            y_label: "max endpoint error (scene units)".into(),
            series,
        };
        loglog(&plot, 800, 560, &png)?;
        plots.push((
            format!("grin-{case}.png"),
            format!("{case}: endpoint error (y) against seconds per ray (x), one line per integrator over its step sizes or tolerances; rings: Pareto front"),
        ));
        // Headline: cheapest run of each method reaching 1e-4, and the best error.
        writeln!(md, "\n### {case}\n\n| integrator | evals/ray for error ≤ 1e-4 | µs/ray there (best of 3, spread) | best error | drift there |\n|---|---|---|---|---|").unwrap();
        let mut need = Vec::new();
        for (m, rows) in &rows_by_method {
            let cheapest = rows.iter().filter(|r| r.4 <= 1e-4).min_by_key(|r| r.2);
            let best = rows.iter().min_by(|a, b| a.4.total_cmp(&b.4)).expect("rows");
            writeln!(
                md,
                "| {} | {} | {} | {:.2e} | {:.1e} |",
                m.name(),
                cheapest.map_or("—".into(), |r| r.2.to_string()),
                cheapest.map_or("—".into(), |r| format!("{:.2} (+{:.0}%)", r.3 * 1e6, r.6)),
                best.4,
                best.5
            )
            .unwrap();
            need.push((*m, cheapest.map(|r| r.2), best.4));
        }
        if case == "linear" {
            let euler = need[0].1;
            let other = need[1..].iter().filter_map(|n| n.1).min();
            let ok = matches!((euler, other), (Some(e), Some(o)) if o * 100 <= e);
            verdicts.push(format!(
                "linear: best non-Euler run reaching 1e-4 uses {} field evaluations per ray, Euler {} → {} (target ≤ 1/100)",
                other.map_or("—".into(), |v| v.to_string()),
                euler.map_or("— (never reached)".into(), |v| v.to_string()),
                if ok { "met" } else { "NOT met" }
            ));
        }
        if case == "luneburg" {
            let best = need.iter().map(|n| n.2).fold(f64::INFINITY, f64::min);
            verdicts.push(format!(
                "luneburg: best endpoint error {best:.2e} → {} (target ≤ 1e-8)",
                if best <= 1e-8 { "met" } else { "NOT met" }
            ));
        }
        writeln!(md, "\nPlot `{}`: error (y) against seconds per ray (x), log–log, one line per integrator (named in the legend); ringed points form the Pareto front.", png.display()).unwrap();
    }
    std::fs::write(dir.join("grin.csv"), &csv).map_err(|e| e.to_string())?;
    writeln!(md, "\nwrote {}", dir.join("grin.csv").display()).unwrap();
    Ok(Section {
        title: "grin (curved rays: endpoint error against run time)".into(),
        body: md,
        verdicts,
        plots,
    })
}
