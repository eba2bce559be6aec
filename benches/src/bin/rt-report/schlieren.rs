//! Knife-edge schlieren of a sparse 128³ gridded field: the original
//! scheme (explicit Euler, one-voxel step, trilinear, no octree) against
//! rt's default for grids (RK4 at one voxel with octree skipping), image
//! RMSE against a converged reference, over photon counts.

use std::{fmt::Write as _, path::Path};

use glam::DVec3;
use rt_benches::plot::{PALETTE, Series, loglog};
use rt_photo::{Bench, Cutoff, Film, Filter, Mode, Weighting};
use rt_volume::{Method, TraceParams, build_octree, trace, trace_skipping};

use crate::{octree::sparse, timing::time};

const FILM: usize = 128;

fn bench(method: Method, step: f64, strata: u32) -> Bench {
    Bench {
        center: DVec3::new(0.5, 0.5, -0.1),
        direction: DVec3::Z,
        u: DVec3::X,
        width: 1.0,
        height: 1.0,
        film_distance: 0.0,
        mode: Mode::Schlieren(Cutoff::KnifeEdge { angle: 0.0, offset: 0.0, f: 1.0, h: 4e-3 }),
        weighting: Weighting::Weight,
        strata,
        params: TraceParams::fixed(method, step),
    }
}

fn rmse(a: &Film, b: &Film) -> f64 {
    let (x, y) = (a.normalized(), b.normalized());
    let s: f64 = x.iter().zip(&y).map(|(p, q)| f64::from(p[0] - q[0]).powi(2)).sum();
    (s / x.len() as f64).sqrt()
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<(), String> {
    let f = sparse();
    let tree = build_octree(&f).map_err(|e| e.to_string())?;
    let h = f.grid().spacing().x;
    let tol = 1e-6;
    // Converged reference: RK4 at a quarter voxel, 64 photons per pixel.
    let mut reference = Film::new(FILM, FILM, Filter::Box).map_err(str::to_string)?;
    let rb = bench(Method::Rk4, 0.25 * h, 8);
    rb.render(&f, &mut reference, 0, 99).map_err(|e| e.to_string())?;
    let strata: &[u32] = if quick { &[1, 2] } else { &[1, 2, 4] };
    let mut csv = String::from("case,method,photons,seconds,rmse\n");
    let mut rows: Vec<(&str, u64, f64, f64)> = Vec::new();
    for &k in strata {
        for (name, step) in [("original", h), ("rt", h)] {
            let mut film = Film::new(FILM, FILM, Filter::Box).map_err(str::to_string)?;
            let (secs, r) = if name == "original" {
                let b = bench(Method::Euler, step, k);
                time(|| b.render_with(&|o, d| trace(&f, o, d, &b.params), &mut film, 0, 7))
            } else {
                let b = bench(Method::Rk4, step, k);
                time(|| {
                    b.render_with(
                        &|o, d| trace_skipping(&f, &tree, o, d, &b.params, tol),
                        &mut film,
                        0,
                        7,
                    )
                })
            };
            r.map_err(|e| e.to_string())?;
            let e = rmse(&film, &reference);
            writeln!(csv, "sparse128,{name},{},{secs:.4},{e:e}", film.emitted).unwrap();
            rows.push((name, film.emitted, secs, e));
        }
    }
    std::fs::write(dir.join("schlieren.csv"), &csv).map_err(|e| e.to_string())?;
    let series: Vec<Series> = ["original", "rt"]
        .iter()
        .enumerate()
        .map(|(i, m)| Series {
            points: rows.iter().filter(|r| r.0 == *m).map(|r| (r.2, r.3)).collect(),
            color: PALETTE[i].0,
        })
        .collect();
    let png = dir.join("schlieren.png");
    loglog(&series, 640, 480, &png)?;
    let mut md =
        String::from("| method | photons | seconds | photons/s | rmse |\n|---|---|---|---|---|\n");
    for r in &rows {
        writeln!(md, "| {} | {} | {:.3} | {:.0} | {:.2e} |", r.0, r.1, r.2, r.1 as f64 / r.2, r.3)
            .unwrap();
    }
    // Speed at equal or better error: for each original run, the fastest rt
    // run whose rmse is at most 2 % above it (both are noise-limited).
    let mut verdicts = Vec::new();
    for o in rows.iter().filter(|r| r.0 == "original") {
        let as_good = rows.iter().filter(|r| r.0 == "rt" && r.3 <= o.3 * 1.02);
        if let Some(rt) = as_good.min_by(|a, b| a.2.total_cmp(&b.2)) {
            verdicts.push(format!(
                "original with {} photons (rmse {:.2e}, {:.3} s) vs rt's fastest run as good (rmse {:.2e}, {:.3} s): {:.1}× faster (target ≥ 20×: {})",
                o.1,
                o.3,
                o.2,
                rt.3,
                rt.2,
                o.2 / rt.2,
                if o.2 / rt.2 >= 20.0 { "met" } else { "NOT met" }
            ));
        }
    }
    let best = verdicts.iter().map(String::as_str).collect::<Vec<_>>().join("\n- ");
    println!(
        "## schlieren (knife edge, sparse 128³ field, {FILM}² film, reference RK4 h/4 with 1M photons)\n\n{md}\n- {best}\n\nPlot `{}`: rmse (y) against seconds (x), log–log; original red, rt blue.\nwrote {}",
        png.display(),
        dir.join("schlieren.csv").display()
    );
    Ok(())
}
