//! Knife-edge schlieren of a sparse 128³ gridded field: the original
//! scheme (explicit Euler, one-voxel step, trilinear, no octree) against
//! rt's default for grids (`SchlierenBench::render_medium` on a grid: leapfrog with octree
//! skipping at the bench's tolerance), at one and two voxels per step;
//! image RMSE against a converged reference, over photon counts.

use std::{fmt::Write as _, path::Path};

use rt_benches::{
    plot::{Plot, Series, loglog},
    scenes::{knife_bench, sparse_bumps},
};
use rt_photo::{Film, Filter};
use rt_photo::{GridMedium, Medium};
use rt_volume::{Method, TraceParams, build_octree, trace, trace_skipping};

use crate::{
    Section,
    timing::{Samples, time},
};

const FILM: usize = 128;

/// Image rmse of `a` against `b`, normalized to the background.
pub(crate) fn rmse(a: &Film, b: &Film) -> f64 {
    let (x, y) = (a.normalized(), b.normalized());
    let s: f64 = x.iter().zip(&y).map(|(p, q)| f64::from(p[0] - q[0]).powi(2)).sum();
    (s / x.len() as f64).sqrt()
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let f = sparse_bumps();
    let tree = build_octree(&f).map_err(|e| e.to_string())?;
    let h = f.grid().spacing().x;
    // Converged reference: RK4 at a quarter voxel, 256 photons per pixel,
    // skipping only while the ray's deflection bound stays below 1e-9.
    let mut reference = Film::new(FILM, FILM, Filter::Box).map_err(|e| e.to_string())?;
    let rb = knife_bench(TraceParams::fixed(Method::Rk4, 0.25 * h), 16);
    rb.render_with(
        &|o, d| trace_skipping(&f, &tree, o, d, &rb.params, 1e-9),
        &mut reference,
        0,
        99,
    )
    .map_err(|e| e.to_string())?;
    let strata: &[u32] = if quick { &[1, 2] } else { &[1, 2, 4, 8] };
    let mut csv = String::from("case,method,photons,seconds,rmse\n");
    let mut rows: Vec<(String, u64, f64, f64, f64)> = Vec::new();
    let rt = TraceParams::for_grid(&f);
    let runs = [
        ("original", TraceParams::fixed(Method::Euler, h)),
        ("rt", rt),
        ("rt-2voxel", TraceParams { step: 2.0 * h, max_step: 2.0 * h, ..rt }),
    ];
    for &k in strata {
        for (name, params) in runs {
            // Best of 3 (the film of the last run is kept; all are equal).
            let b = knife_bench(params, k);
            let medium =
                Medium::Grid(GridMedium::from_field(f.clone(), params).map_err(|e| e.to_string())?);
            let mut samples = Samples::default();
            let mut film = Film::new(FILM, FILM, Filter::Box).map_err(|e| e.to_string())?;
            for _ in 0..3 {
                film = Film::new(FILM, FILM, Filter::Box).map_err(|e| e.to_string())?;
                let (t, r) = if name == "original" {
                    time(|| b.render_with(&|o, d| trace(&f, o, d, &b.params), &mut film, 0, 7))
                } else {
                    time(|| b.render_medium(&medium, &mut film, 0, 7))
                };
                r.map_err(|e| e.to_string())?;
                samples.0.push(t);
            }
            let secs = samples.best();
            let e = rmse(&film, &reference);
            writeln!(csv, "sparse128,{name},{},{secs:.4},{e:e}", film.emitted).unwrap();
            rows.push((name.to_string(), film.emitted, secs, e, samples.spread()));
        }
    }
    let series: Vec<Series> = [
        ("original", "original: Euler, 1-voxel steps"),
        ("rt", "rt: leapfrog + octree, 1 voxel"),
        ("rt-2voxel", "rt-2voxel: leapfrog + octree, 2 voxels"),
    ]
    .iter()
    .map(|&(m, name)| Series {
        name: name.into(),
        points: rows.iter().filter(|r| r.0 == m).map(|r| (r.2, r.3)).collect(),
    })
    .collect();
    let png = dir.join("schlieren.png");
    let plot = Plot {
        pareto: true,
        title: format!(
            "Schlieren, {FILM}² film: error against time over {} … {} photons per pixel",
            strata[0].pow(2),
            strata[strata.len() - 1].pow(2)
        ),
        x_label: "seconds per film (best of 3)".into(),
        y_label: "rmse against the converged film (normalized)".into(),
        series,
    };
    loglog(&plot, 800, 560, &png)?;
    let mut md = String::from(
        "| method | photons | seconds (best of 3) | spread | photons/s | rmse |\n|---|---|---|---|---|---|\n",
    );
    for r in &rows {
        writeln!(
            md,
            "| {} | {} | {:.3} | +{:.0}% | {:.0} | {:.2e} |",
            r.0,
            r.1,
            r.2,
            r.4,
            r.1 as f64 / r.2,
            r.3
        )
        .unwrap();
    }
    // Speed at equal error: the time each rt configuration needs to reach
    // the original's rmse, interpolated log–log along its own sweep (its
    // cheapest run if that is already as good; none if it never gets there).
    let mut verdicts = Vec::new();
    for o in rows.iter().filter(|r| r.0 == "original") {
        let mut each = Vec::new();
        let mut best = 0.0f64;
        for name in ["rt", "rt-2voxel"] {
            let mut pts: Vec<_> = rows.iter().filter(|r| r.0 == name).collect();
            pts.sort_by(|a, b| a.2.total_cmp(&b.2));
            let t = if pts.first().is_some_and(|p| p.3 <= o.3) {
                pts.first().map(|p| p.2)
            } else {
                pts.windows(2).find(|w| w[0].3 > o.3 && w[1].3 <= o.3).map(|w| {
                    let s = (o.3 / w[0].3).ln() / (w[1].3 / w[0].3).ln();
                    (w[0].2.ln() + s * (w[1].2 / w[0].2).ln()).exp()
                })
            };
            match t {
                Some(t) => {
                    each.push(format!("{name} in {t:.4} s ({:.1}×)", o.2 / t));
                    best = best.max(o.2 / t);
                }
                None => each.push(format!("{name} never")),
            }
        }
        verdicts.push(format!(
            "original with {} photons (rmse {:.2e}, {:.3} s) — that rmse reached by {} (target ≥ 20×: {})",
            o.1,
            o.3,
            o.2,
            each.join(", "),
            if best >= 20.0 { "met" } else { "NOT met" }
        ));
    }
    // The dense row: what users meet on real data.
    let (size, photons) = if quick { (64, 4) } else { (256, 16) };
    let dense = crate::schlieren_dense::rows(dir, size, photons)?;
    let (dense_md, dense_verdicts) = crate::schlieren_dense::table(&dense, size, photons);
    md.push_str(&dense_md);
    verdicts.extend(dense_verdicts);
    for r in &dense {
        writeln!(csv, "dense128,{},{},{:.4},{:e}", r.interp, r.photons, r.seconds, r.rmse).unwrap();
    }
    std::fs::write(dir.join("schlieren.csv"), &csv).map_err(|e| e.to_string())?;
    writeln!(md, "\nwrote {}", dir.join("schlieren.csv").display()).unwrap();
    Ok(Section {
        title: format!(
            "schlieren (knife edge, sparse 128³ field, {FILM}² film, reference RK4 h/4 with 4M photons)"
        ),
        body: md,
        verdicts,
        plots: vec![(
            "schlieren.png".into(),
            "rmse against the reference (y) against seconds (x), one line per method over photons per pixel; rings: Pareto front".into(),
        )],
    })
}
