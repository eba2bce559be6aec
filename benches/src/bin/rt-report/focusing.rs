//! Focusing schlieren: the signal of a thin bump against its distance
//! from the focus plane, the depth of focus it shows, and the geometric
//! prediction (the set-up of `rt-photo/tests/focusing.rs`, test 3).
//!
//! f = 0.1 m at f/2 (D = 5 cm) focused at Z_F = 1 m, pixels of 0.5 mm on
//! the focus plane; a source grid of 4 mm bands (duty ½) at Z_S = 2 m,
//! cutoff shifted by a quarter band (o = 1 mm). The bump: `n = 1 +
//! δ·exp(−ρ²/2σ²)·exp(−(z − z₀)²/2σ_z²)`, δ = 2e-3, σ = 4 mm, σ_z = 1 mm.
//! The signal: the largest |I/I₀ − 1| on a row through it, and divided by
//! the lever `(Z_S − z₀)/(Z_S − Z_F)` (a bump nearer the lens moves its
//! rays' source points further).
//!
//! Geometric prediction: the rays of focus point X cross the plane z₀ in
//! the disc centred `X·z₀/Z_F` of diameter `D·|z₀ − Z_F|/Z_F`, so a pixel's
//! `I/I₀ − 1` is the disc's mean of `ε·(Z_S − z₀)/o`. The simplest
//! estimate of the depth of sharp focus — the range where that disc is
//! narrower than the bump's signal (w = 2σ between its extremes) — is
//! `2·w·Z_F/D`.

use std::{fmt::Write as _, path::Path};

use glam::DVec3;
use rt_benches::plot::{Plot, Series, loglog};
use rt_photo::{
    FocusingSchlieren, SourceGrid, ThinLens, TraceParams,
    rt_volume::{Bounds, FnField},
};

use crate::{Section, timing::time};

const DELTA: f64 = 2e-3;
const SIGMA: f64 = 4e-3;
const SIGMA_Z: f64 = 1e-3;
const Z_F: f64 = 1.0;
const Z_S: f64 = 2.0;
const OFFSET: f64 = 1e-3;

/// ε across x of the thin bump at `(x, y)`.
fn eps(x: f64, y: f64) -> f64 {
    -(std::f64::consts::TAU).sqrt() * DELTA * SIGMA_Z / SIGMA
        * (x / SIGMA)
        * (-(x * x + y * y) / (2.0 * SIGMA * SIGMA)).exp()
}

fn thin_bump(z0: f64) -> FnField<impl Fn(DVec3) -> (f64, DVec3)> {
    let r = 6.0 * SIGMA;
    FnField {
        f: move |p: DVec3| {
            let dz = p.z - z0;
            let g = (-(p.x * p.x + p.y * p.y) / (2.0 * SIGMA * SIGMA)
                - dz * dz / (2.0 * SIGMA_Z * SIGMA_Z))
                .exp();
            let grad = -DELTA
                * g
                * DVec3::new(
                    p.x / (SIGMA * SIGMA),
                    p.y / (SIGMA * SIGMA),
                    dz / (SIGMA_Z * SIGMA_Z),
                );
            (1.0 + DELTA * g, grad)
        },
        bounds: Bounds::new(
            DVec3::new(-r, -r, z0 - 6.0 * SIGMA_Z),
            DVec3::new(r, r, z0 + 6.0 * SIGMA_Z),
        ),
        ambient: 1.0,
    }
}

/// Where `values` (by increasing `|dz|`) first fall below `level`,
/// linearly interpolated; `None` if they never do.
fn crossing(points: &[(f64, f64)], level: f64) -> Option<f64> {
    points.windows(2).find(|w| w[0].1 >= level && w[1].1 < level).map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        x0 + (x1 - x0) * (y0 - level) / (y0 - y1)
    })
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let width = 41;
    let cam = ThinLens {
        position: DVec3::ZERO,
        direction: DVec3::Z,
        up: DVec3::Y,
        focal_length: 0.1,
        f_number: 2.0,
        focus_distance: Z_F,
        pixel_pitch: 0.5e-3 / 9.0,
        width,
        height: 1,
    };
    let fs = FocusingSchlieren {
        camera: cam,
        source_distance: Z_S,
        grid: SourceGrid { pitch: 4e-3, duty: 0.5, angle: 0.0, bands: None },
        cutoff_offset: 0.25,
        aperture_samples: if quick { 16 } else { 32 },
        params: TraceParams::accurate(),
    };
    let xs: Vec<f64> = (0..width).map(|i| cam.focus_point(i as f64 + 0.5, 0.5).x).collect();
    let radius = 0.5 * cam.aperture();
    let predicted = |dz: f64| {
        let z = Z_F + dz;
        let r = radius * (dz / Z_F).abs();
        let m = 64;
        xs.iter()
            .map(|&x| {
                let (mut sum, mut count) = (0.0, 0u32);
                for a in 0..m {
                    for b in 0..m {
                        let u = (2.0 * (f64::from(a) + 0.5) / f64::from(m) - 1.0) * r;
                        let v = (2.0 * (f64::from(b) + 0.5) / f64::from(m) - 1.0) * r;
                        if u * u + v * v <= r * r {
                            sum += eps(x * z / Z_F + u, v);
                            count += 1;
                        }
                    }
                }
                (sum / f64::from(count) * (Z_S - z) / OFFSET).abs()
            })
            .fold(0.0f64, f64::max)
    };
    let steps: Vec<f64> = if quick {
        vec![0.0, 0.05, 0.1, 0.2, 0.3, 0.5]
    } else {
        vec![0.0, 0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.4, 0.5, 0.7]
    };
    let mut csv = String::from("dz,signal,normalized,predicted,seconds\n");
    let mut md = String::from(
        "| Δz (m, + away from the lens) | signal max\\|I/I₀ − 1\\| | ÷ lever | geometric prediction ÷ lever | seconds |\n|---|---|---|---|---|\n",
    );
    let (mut near, mut far, mut pred, mut pred_far) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut in_focus = 0.0;
    for &step in &steps {
        for side in [-1.0, 1.0] {
            if step == 0.0 && side > 0.0 {
                continue;
            }
            let dz = side * step;
            let field = thin_bump(Z_F + dz);
            let (secs, out) = time(|| fs.render(&field, 7));
            let rel = out.map_err(|e| e.to_string())?.relative();
            let signal = rel.iter().map(|v| (v - 1.0).abs()).fold(0.0f64, f64::max);
            let lever = (Z_S - Z_F) / (Z_S - Z_F - dz);
            let p = predicted(dz);
            writeln!(csv, "{dz},{signal:.5},{:.5},{:.5},{secs:.3}", signal * lever, p * lever)
                .unwrap();
            writeln!(
                md,
                "| {dz:+.2} | {signal:.4} | {:.4} | {:.4} | {secs:.2} |",
                signal * lever,
                p * lever
            )
            .unwrap();
            if step == 0.0 {
                in_focus = signal;
            }
            let x = step.max(3e-3);
            if side < 0.0 || step == 0.0 {
                near.push((x, signal * lever));
                pred.push((x, p * lever));
            }
            if side > 0.0 || step == 0.0 {
                far.push((x, signal * lever));
                pred_far.push((x, p * lever));
            }
        }
    }
    std::fs::write(dir.join("focusing.csv"), &csv).map_err(|e| e.to_string())?;
    let half = 0.5 * in_focus;
    let (h_near, h_far, h_pred) =
        (crossing(&near, half), crossing(&far, half), crossing(&pred, half));
    let rule = 2.0 * (2.0 * SIGMA) * Z_F / cam.aperture();
    let fmt = |v: Option<f64>| v.map_or("beyond the range".into(), |v| format!("{v:.3} m"));
    writeln!(
        md,
        "\nDepth of focus (the signal ÷ lever falls to half of its in-focus {in_focus:.3}): measured at {} toward the lens and {} away from it; the geometric prediction (disc mean) at {}; full depth of sharp focus by the simple rule 2·w·Z_F/D = {rule:.3} m (±{:.3} m), w = 2σ.\n\nwrote {}",
        fmt(h_near),
        fmt(h_far),
        fmt(h_pred),
        rule / 2.0,
        dir.join("focusing.csv").display()
    )
    .unwrap();
    let plot = Plot {
        pareto: false,
        title:
            "Focusing schlieren: signal of a thin bump against its distance from the focus plane"
                .into(),
        x_label: "|Δz| from the focus plane (m; 0 drawn at 3 mm)".into(),
        y_label: "max |I/I₀ − 1| ÷ lever".into(),
        series: vec![
            Series { name: "bump toward the lens".into(), points: near },
            Series { name: "bump away from the lens".into(), points: far },
            Series { name: "geometric prediction, toward".into(), points: pred.clone() },
            Series { name: "geometric prediction, away".into(), points: pred_far },
        ],
    };
    loglog(&plot, 900, 600, &dir.join("focusing.png")).map_err(|e| e.to_string())?;
    let within = h_near.zip(h_pred).map(|(m, p)| (m / p - 1.0).abs());
    Ok(Section {
        title: "focusing (thin bump moved along the axis: signal, depth of focus)".into(),
        body: md,
        verdicts: vec![format!(
            "measured half-signal distance {} vs the geometric prediction {} ({}); the simple rule's half depth {:.3} m",
            fmt(h_near),
            fmt(h_pred),
            within.map_or("not comparable".into(), |w| format!("{:.0} % apart", 100.0 * w)),
            rule / 2.0
        )],
        plots: vec![(
            "focusing.png".into(),
            "max |I/I₀ − 1| divided by the lever (y) against |Δz| (x), log–log, both sides and the geometric prediction".into(),
        )],
    })
}
