//! The user's schlieren job as `rt schlieren` runs it (the built-in blast
//! wave, default optics chosen by the tool, its fast path): image noise
//! against photons per pixel, and the tool's photons/s against the rate
//! the `schlieren` area measures for rt on its sparse field, in this run.
//!
//! Noise is measured as a user would: two renders that differ only in the
//! seed, `rms(a − b)/√2` over the disturbed pixels (where the converged
//! image differs from the undisturbed background by more than 0.02) and
//! over the whole image.

use std::{fmt::Write as _, path::Path};

use rt_benches::{
    plot::{Plot, Series, loglog},
    scenes::{knife_bench, sparse_bumps},
};
use rt_cli::{demo::blast_wave_with, schlieren};
use rt_photo::{Film, Filter, TraceParams, build_octree};

use crate::{
    Section,
    timing::{Samples, time},
};

/// `(noise over the disturbed pixels, over all pixels)` of two renders.
fn noise(a: &Film, b: &Film, disturbed: &[bool]) -> (f64, f64) {
    let (x, y) = (a.normalized_f64(), b.normalized_f64());
    let (mut sd, mut nd, mut sa) = (0.0, 0usize, 0.0);
    for ((p, q), &d) in x.iter().zip(&y).zip(disturbed) {
        let e = (p[0] - q[0]).powi(2);
        sa += e;
        if d {
            sd += e;
            nd += 1;
        }
    }
    let rms = |s: f64, n: usize| (s / n.max(1) as f64).sqrt() / std::f64::consts::SQRT_2;
    (rms(sd, nd), rms(sa, x.len()))
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    // The tool's defaults: knife edge, 512 px, 16 photons per pixel, its
    // default interpolant.
    let defaults = schlieren::Args::from_args(Path::new("built-in"), ["--cutoff", "knife"])
        .map_err(|e| e.to_string())?;
    let volume = blast_wave_with(defaults.interp).map_err(|e| e.to_string())?;
    let (bench, chosen) = schlieren::prepare(&volume, &defaults).map_err(|e| e.to_string())?;
    let size = if quick { 128 } else { defaults.size as usize };
    let counts: &[u32] = if quick { &[4, 16, 64] } else { &[4, 16, 64, 256] };
    let reference_n = *counts.last().unwrap_or(&16);
    // The disturbed pixels, from the best-converged image.
    let (converged, _) = volume.render(&bench, size, reference_n, 99).map_err(|e| e.to_string())?;
    let background = 0.5;
    let disturbed: Vec<bool> =
        converged.normalized_f64().iter().map(|p| (p[0] - background).abs() > 0.02).collect();
    let share = disturbed.iter().filter(|&&d| d).count() as f64 / disturbed.len() as f64;

    let mut csv = String::from("photons_per_pixel,photons,seconds,noise_disturbed,noise_all\n");
    let mut md = format!(
        "Knife edge as `rt schlieren` chooses it ({chosen}), the built-in blast wave ({:?} interpolation, octree skipping and beam masks, leapfrog at two cells), {size}² pixels; {:.0} % of them disturbed.\n\n\
         | photons/pixel | photons | seconds | M photons/s | noise (disturbed) | × √N | noise (all) |\n|---|---|---|---|---|---|---|\n",
        defaults.interp,
        100.0 * share
    );
    let mut rows = Vec::new();
    for &n in counts {
        let (a, secs) = volume.render(&bench, size, n, 1).map_err(|e| e.to_string())?;
        let (b, _) = volume.render(&bench, size, n, 2).map_err(|e| e.to_string())?;
        let (nd, na) = noise(&a, &b, &disturbed);
        let photons = a.emitted;
        writeln!(csv, "{n},{photons},{secs:.4},{nd:e},{na:e}").unwrap();
        writeln!(
            md,
            "| {n} | {photons} | {secs:.2} | {:.2} | {nd:.2e} | {:.3} | {na:.2e} |",
            photons as f64 / secs / 1e6,
            nd * f64::from(n).sqrt()
        )
        .unwrap();
        rows.push((n, secs, nd, photons as f64 / secs));
    }
    std::fs::write(dir.join("noise.csv"), &csv).map_err(|e| e.to_string())?;
    let png = dir.join("noise.png");
    loglog(
        &Plot {
            title: "Schlieren image noise against photons per pixel (blast wave, two seeds)".into(),
            x_label: "photons per pixel".into(),
            y_label: "rms noise in disturbed pixels (fraction of background)".into(),
            series: vec![
                Series {
                    name: "rt schlieren (stratified, R2 across passes)".into(),
                    points: rows.iter().map(|r| (f64::from(r.0), r.2)).collect(),
                },
                Series {
                    name: "1/√N through the first point".into(),
                    points: rows
                        .first()
                        .map(|f| {
                            rows.iter()
                                .map(|r| {
                                    (f64::from(r.0), f.2 * (f64::from(f.0) / f64::from(r.0)).sqrt())
                                })
                                .collect()
                        })
                        .unwrap_or_default(),
                },
            ],
        },
        800,
        560,
        &png,
    )?;

    let mut verdicts = Vec::new();
    if let Some(&(_, _, nd, _)) = rows.iter().find(|r| r.0 == defaults.photons) {
        let limit = 1.0 / 255.0;
        verdicts.push(format!(
            "noise at the default {} photons per pixel{}: {nd:.2e} of the background in the disturbed pixels (target ≤ 1/255 = {limit:.2e}) → {}",
            defaults.photons,
            if quick { format!(" ({size}² pixels, quick run)") } else { String::new() },
            if nd <= limit { "met" } else { "NOT met" }
        ));
    }
    if let (Some(first), Some(last)) = (rows.first(), rows.last()) {
        let slope = (last.2 / first.2).ln() / (f64::from(last.0) / f64::from(first.0)).ln();
        verdicts.push(format!(
            "noise falls as N^{slope:.2} from {} to {} photons per pixel (independent photons: N^-0.50) → {}",
            first.0,
            last.0,
            if slope < -0.5 { "faster than 1/√N, met" } else { "NOT faster than 1/√N" }
        ));
    }
    // The schlieren area's `rt` setting on its sparse field, in this run:
    // one photon per pixel of a 128² film, best of 3.
    let f = sparse_bumps();
    let tree = build_octree(&f).map_err(|e| e.to_string())?;
    let b = knife_bench(TraceParams::for_grid(&f), 1);
    let mut samples = Samples::default();
    let mut emitted = 0;
    for _ in 0..3 {
        let mut film = Film::new(128, 128, Filter::Box).map_err(|e| e.to_string())?;
        let (t, r) = time(|| b.render_grid(&f, &tree, &mut film, 0, 7));
        r.map_err(|e| e.to_string())?;
        samples.0.push(t);
        emitted = film.emitted;
    }
    let report_rate = emitted as f64 / samples.best();
    if let Some(&(_, _, _, rate)) = rows.iter().find(|r| r.0 == defaults.photons) {
        let ratio = rate / report_rate;
        verdicts.push(format!(
            "`rt schlieren` on the blast wave at its defaults traces {:.2} M photons/s, {ratio:.2}× the {:.2} M photons/s of the schlieren area's `rt` (sparse 128³ field) in this run (target ≥ 0.5×) → {}",
            rate / 1e6,
            report_rate / 1e6,
            if ratio >= 0.5 { "met" } else { "NOT met" }
        ));
    }
    writeln!(md, "\nwrote {}", dir.join("noise.csv").display()).unwrap();
    Ok(Section {
        title: "The user's schlieren job: noise against photons, and speed".into(),
        body: md,
        verdicts,
        plots: vec![(
            "noise.png".into(),
            "rms noise of two seeds in the disturbed pixels against photons per pixel, with the 1/√N line of independent photons".into(),
        )],
    })
}
