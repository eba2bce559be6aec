//! The user's schlieren job as `rt schlieren` runs it (the built-in blast
//! wave, default optics chosen by the tool, its fast path): image noise
//! against photons per pixel, and the tool's photons/s against the rate
//! the `schlieren` area measures for rt on its sparse field, in this run.
//!
//! Noise is measured as a user would: two renders that differ only in the
//! seed, `rms(a − b)/√2` over the disturbed pixels (where a reference image
//! differs from the undisturbed background by more than 0.02) and over the
//! whole image, for the sheet estimator the tool uses and for splatted
//! photons beside it; the error against an unbiased reference (photons
//! counted in the pixel they land in, 1024 per pixel) shows what noise does
//! not: bias, here the sheet's blur of the image's jumps over a lattice
//! cell, and the tent filter's over two pixels.

use std::{fmt::Write as _, path::Path};

use rt_benches::{
    plot::{Plot, Series, loglog},
    scenes::{knife_bench, sparse_bumps},
};
use rt_photo::{
    Film, Filter, Reconstruction, SchlierenBench, SchlierenOptions, SchlierenSetup, TraceParams,
    lattice,
};
use rt_photo::{GridMedium, Medium};
use rt_tools::builtin::blast_wave;

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

/// rms of `a − reference` over the disturbed pixels.
fn error(a: &Film, reference: &[[f64; 3]], disturbed: &[bool]) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for ((p, q), &d) in a.normalized_f64().iter().zip(reference).zip(disturbed) {
        if d {
            s += (p[0] - q[0]).powi(2);
            n += 1;
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// One measured row: estimator, photons per pixel, seconds, noise in the
/// disturbed pixels, error against the reference, photons/s.
struct Row {
    sheet: bool,
    n: u32,
    noise: f64,
    rate: f64,
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    // The tool's defaults: knife edge, 512 px, 16 photons per pixel, its
    // default interpolant, the sheet estimator.
    let defaults = SchlierenOptions::default();
    let volume = blast_wave().map_err(|e| e.to_string())?;
    let setup = SchlierenSetup::choose(&volume, &defaults).map_err(|e| e.to_string())?;
    let (bench, chosen) = (&setup.bench, setup.to_string());
    let background = f64::from(setup.background()[0]);
    let size = if quick { 128 } else { defaults.size as usize };
    let counts: &[u32] = if quick { &[4, 16, 64] } else { &[4, 16, 64, 256] };
    // The reference: photons splatted with the box filter (each counted in
    // the pixel it lands in: no blur, no bias), 1024 per pixel, averaged
    // over two seeds; its own noise is reported.
    let reference_n = 1024;
    let box_render = |seed: u64| -> Result<Film, String> {
        let height = ((size as f64) * bench.height / bench.width).round().max(1.0) as usize;
        let mut film = Film::new(size, height, Filter::Box).map_err(|e| e.to_string())?;
        let (strata, passes) = lattice(reference_n);
        let b = SchlierenBench { strata, reconstruction: Reconstruction::Photons, ..bench.clone() };
        for pass in 0..passes {
            b.render_medium(&volume, &mut film, pass, seed).map_err(|e| e.to_string())?;
        }
        Ok(film)
    };
    let (r1, r2) = (box_render(97)?, box_render(98)?);
    let reference: Vec<[f64; 3]> = r1
        .normalized_f64()
        .iter()
        .zip(r2.normalized_f64())
        .map(|(p, q)| [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])])
        .collect();
    let disturbed: Vec<bool> = reference.iter().map(|p| (p[0] - background).abs() > 0.02).collect();
    let share = disturbed.iter().filter(|&&d| d).count() as f64 / disturbed.len() as f64;
    // The mean of two seeds has the noise of one over √2.
    let reference_noise = noise(&r1, &r2, &disturbed).0 / std::f64::consts::SQRT_2;

    let mut csv = String::from(
        "estimator,photons_per_pixel,photons,seconds,noise_disturbed,noise_all,error_vs_reference\n",
    );
    let mut md = format!(
        "Knife edge as `rt schlieren` chooses it ({chosen}), the built-in blast wave ({} interpolation, octree skipping and beam masks, leapfrog at two cells), {size}² pixels; {:.0} % of them disturbed (differing from the background {background} by more than 0.02 in the reference). \
         Two estimators, each with the tool's lattice (k × k photons per pixel per pass, k = 2 below 64 photons per pixel, 4 from 64, 8 from 256; the passes shifted along the R2 sequence): **sheet** (`rt schlieren`'s: the photons of a pass form a lattice whose cells carry their light onto the film where their corners land, exact area, Abel, Hahn & Kaehler 2012) and **photons** (each photon splatted alone with the tent filter). \
         Noise is `rms(a − b)/√2` of two seeds, as a fraction of the background; error is the rms difference, over the disturbed pixels and in image units, from the reference: photons counted in the pixel they land in (box filter, unbiased), {reference_n} per pixel, the mean of two seeds (its own noise: {reference_noise:.1e}).\n\n\
         | estimator | photons/pixel | photons | seconds | M photons/s | noise (disturbed) / background | noise (all) / background | error vs reference |\n|---|---|---|---|---|---|---|---|\n",
        "Catmull–Rom",
        100.0 * share
    );
    let mut rows = Vec::new();
    let height = ((size as f64) * bench.height / bench.width).round().max(1.0) as usize;
    for sheet in [true, false] {
        let b = SchlierenBench {
            reconstruction: if sheet { Reconstruction::Sheet } else { Reconstruction::Photons },
            ..bench.clone()
        };
        let name = if sheet { "sheet" } else { "photons" };
        for &n in counts {
            let run = SchlierenSetup {
                bench: b.clone(),
                size: (size, height),
                options: SchlierenOptions { photons: n, ..setup.options.clone() },
                ..setup.clone()
            };
            let render = |seed: u64| -> Result<(Film, f64), String> {
                let t = std::time::Instant::now();
                let film = run.render(&volume, seed, &mut |_, _| {}).map_err(|e| e.to_string())?;
                Ok((film, t.elapsed().as_secs_f64()))
            };
            let (a, secs) = render(1)?;
            let (c, _) = render(2)?;
            let (nd, na) = noise(&a, &c, &disturbed);
            let (nd, na) = (nd / background, na / background);
            let err = error(&a, &reference, &disturbed);
            let photons = a.emitted;
            writeln!(csv, "{name},{n},{photons},{secs:.4},{nd:e},{na:e},{err:e}").unwrap();
            writeln!(
                md,
                "| {name} | {n} | {photons} | {secs:.2} | {:.2} | {nd:.2e} | {na:.2e} | {err:.2e} |",
                photons as f64 / secs / 1e6,
            )
            .unwrap();
            rows.push(Row { sheet, n, noise: nd, rate: photons as f64 / secs });
        }
    }
    std::fs::write(dir.join("noise.csv"), &csv).map_err(|e| e.to_string())?;
    let png = dir.join("noise.png");
    let series = |sheet: bool| -> Vec<(f64, f64)> {
        rows.iter().filter(|r| r.sheet == sheet).map(|r| (f64::from(r.n), r.noise)).collect()
    };
    let photons = series(false);
    let root_n: Vec<(f64, f64)> = photons
        .first()
        .map(|&(n0, e0)| photons.iter().map(|&(n, _)| (n, e0 * (n0 / n).sqrt())).collect())
        .unwrap_or_default();
    loglog(
        &Plot {
            pareto: true,
            title: "Schlieren image noise against photons per pixel (blast wave, two seeds)".into(),
            x_label: "photons per pixel".into(),
            y_label: "rms noise in disturbed pixels / background".into(),
            series: vec![
                Series { name: "sheet (rt schlieren)".into(), points: series(true) },
                Series { name: "photons splatted (tent filter)".into(), points: photons },
                Series { name: "1/√N through the first photons point".into(), points: root_n },
            ],
        },
        800,
        560,
        &png,
    )?;

    let mut verdicts = Vec::new();
    let cli = |n: u32| rows.iter().find(|r| r.sheet && r.n == n);
    if let Some(r) = cli(defaults.photons) {
        let limit = 1.0 / 255.0;
        verdicts.push(format!(
            "noise at the default {} photons per pixel{}: {:.2e} of the background in the disturbed pixels (target ≤ 1/255 = {limit:.2e}) → {}",
            defaults.photons,
            if quick { format!(" ({size}² pixels, quick run)") } else { String::new() },
            r.noise,
            if r.noise <= limit { "met" } else { "NOT met" }
        ));
    }
    for sheet in [true, false] {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.sheet == sheet).collect();
        if let (Some(first), Some(last)) = (mine.first(), mine.last()) {
            let slope =
                (last.noise / first.noise).ln() / (f64::from(last.n) / f64::from(first.n)).ln();
            verdicts.push(format!(
                "{} noise falls as N^{slope:.2} from {} to {} photons per pixel (independent photons: N^-0.50) → {}",
                if sheet { "sheet" } else { "splatted photons'" },
                first.n,
                last.n,
                if slope < -0.5 { "faster than 1/√N, met" } else { "NOT faster than 1/√N" }
            ));
        }
    }
    // The schlieren area's `rt` setting on its sparse field, in this run:
    // one photon per pixel of a 128² film, best of 3.
    let f = sparse_bumps();
    let b = knife_bench(TraceParams::for_grid(&f), 1);
    let medium = Medium::Grid(GridMedium::from_field(f, b.params).map_err(|e| e.to_string())?);
    let mut samples = Samples::default();
    let mut emitted = 0;
    for _ in 0..3 {
        let mut film = Film::new(128, 128, Filter::Box).map_err(|e| e.to_string())?;
        let (t, r) = time(|| b.render_medium(&medium, &mut film, 0, 7));
        r.map_err(|e| e.to_string())?;
        samples.0.push(t);
        emitted = film.emitted;
    }
    let report_rate = emitted as f64 / samples.best();
    if let Some(&Row { rate, .. }) = cli(defaults.photons) {
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
            "rms noise of two seeds in the disturbed pixels against photons per pixel, sheet and splatted photons, with the 1/√N line of independent photons".into(),
        )],
    })
}
