//! The schlieren report's dense row: what a user meets on real data that
//! is disturbed everywhere ([`dense_flow`]), rendered as `rt schlieren`
//! renders it (the library's set-up with its defaults, the medium's own
//! settings), on one thread so the rate is photons per CPU-second. The
//! error is the image's against a reference traced by RK4 at a quarter
//! cell without skipping, from the same photons (same seed and lattice),
//! so it measures the tracing alone.

use std::{fmt::Write as _, path::Path};

use rt_benches::scenes::{DENSE_GRID, dense_flow};
use rt_photo::{Film, Medium, Samples as Gas, SchlierenOptions, SchlierenSetup};
use rt_volume::{Interp, Method, TraceParams, trace};

use crate::{
    schlieren::rmse,
    timing::{Samples, time},
};

/// One interpolant's row.
pub(crate) struct DenseRow {
    /// `rt-trilinear`, `rt-catmull-rom`, or `gpu-trilinear`.
    pub(crate) interp: &'static str,
    /// Where it ran: `one CPU thread`, or the adapter's name.
    pub(crate) on: String,
    pub(crate) photons: u64,
    pub(crate) seconds: f64,
    pub(crate) spread: f64,
    pub(crate) rmse: f64,
    pub(crate) steps_per_photon: f64,
    pub(crate) evals_per_photon: f64,
}

/// The dense rows (trilinear, Catmull–Rom) at `size` pixels and `photons`
/// per pixel; the field is also written to `dir` as raw + JSON, so
/// `rt schlieren dir/dense_flow_128.json` shows the same image.
pub(crate) fn rows(dir: &Path, size: u32, photons: u32) -> Result<Vec<DenseRow>, String> {
    let grid = dense_flow(DENSE_GRID, 1);
    write_field(dir, &grid)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().map_err(|e| e.to_string())?;
    let mut out = Vec::new();
    for (name, interp) in
        [("rt-trilinear", Interp::Trilinear), ("rt-catmull-rom", Interp::CatmullRom)]
    {
        let medium =
            Medium::from_grid(grid.clone(), Gas::AIR, false, interp).map_err(|e| e.to_string())?;
        let options = SchlierenOptions { size, photons, ..SchlierenOptions::default() };
        let setup = SchlierenSetup::choose(&medium, &options).map_err(|e| e.to_string())?;
        let mut samples = Samples::default();
        let mut film = None;
        for _ in 0..3 {
            let (t, r) = time(|| pool.install(|| setup.render(&medium, 7, &mut |_, _| {})));
            film = Some(r.map_err(|e| e.to_string())?);
            samples.0.push(t);
        }
        let film = film.ok_or("no run")?;
        // The reference: the same bench and photons, every photon
        // integrated by RK4 at a quarter cell (no octree, no beam mask).
        let Medium::Grid(g) = &medium else { return Err("not a grid".into()) };
        let h = g.field().grid().spacing().min_element();
        let fine = TraceParams::fixed(Method::Rk4, 0.25 * h);
        let (strata, passes) = rt_photo::lattice(photons);
        let bench = rt_photo::SchlierenBench { strata, params: fine, ..setup.bench.clone() };
        let mut reference = Film::new(setup.size.0, setup.size.1, rt_photo::Filter::Tent)
            .map_err(|e| e.to_string())?;
        for pass in 0..passes {
            bench
                .render_with(&|o, d| trace(g.field(), o, d, &fine), &mut reference, pass, 7)
                .map_err(|e| e.to_string())?;
        }
        let (steps, evals) = per_photon(&medium, &setup);
        if interp == Interp::Trilinear {
            // The same render with its photons traced on the GPU, where
            // there is one (`rt schlieren --device gpu`).
            match rt_gpu::Gpu::new() {
                Ok(gpu) => {
                    let mut samples = Samples::default();
                    let mut gpu_film = None;
                    for _ in 0..3 {
                        let (t, r) = time(|| {
                            rt_gpu::render_schlieren(
                                &gpu,
                                &setup,
                                &medium,
                                7,
                                &mut |_, _| {},
                                &|| false,
                            )
                        });
                        gpu_film = Some(r.map_err(|e| e.to_string())?);
                        samples.0.push(t);
                    }
                    let gpu_film = gpu_film.ok_or("no run")?;
                    let soft = if gpu.is_software() { ", a software driver" } else { "" };
                    out.push(DenseRow {
                        interp: "gpu-trilinear",
                        on: format!("{}{soft}", gpu.name()),
                        photons: gpu_film.emitted,
                        seconds: samples.best(),
                        spread: samples.spread(),
                        rmse: rmse(&gpu_film, &reference),
                        steps_per_photon: f64::NAN,
                        evals_per_photon: f64::NAN,
                    });
                }
                Err(e) => eprintln!("rt-report: no GPU row: {e}"),
            }
        }
        out.push(DenseRow {
            interp: name,
            on: "one CPU thread".into(),
            photons: film.emitted,
            seconds: samples.best(),
            spread: samples.spread(),
            rmse: rmse(&film, &reference),
            steps_per_photon: steps,
            evals_per_photon: evals,
        });
    }
    Ok(out)
}

/// Mean integration steps and field evaluations of the photons of one
/// film row across the middle of the image (the medium's own tracer and
/// skipping).
fn per_photon(medium: &Medium, setup: &SchlierenSetup) -> (f64, f64) {
    let b = &setup.bench;
    let v = b.direction.cross(b.u);
    let tol = match medium {
        Medium::Grid(g) => {
            let film = Film::new(setup.size.0, setup.size.1, rt_photo::Filter::Tent);
            film.ok().map(|f| b.skip_tolerance(g.field(), &f))
        }
        _ => None,
    };
    let n = 256;
    let (mut steps, mut evals) = (0u64, 0u64);
    for i in 0..n {
        let a = (i as f64 + 0.5) / n as f64 - 0.5;
        let o = b.center + a * b.width * b.u + 0.01 * b.height * v;
        if let Ok(r) = medium.trace(o, b.direction, tol) {
            steps += u64::from(r.stats.steps - r.stats.skipped);
            evals += u64::from(r.stats.field_evals);
        }
    }
    (steps as f64 / n as f64, evals as f64 / n as f64)
}

/// The field as `rt` reads it: raw little-endian f32 and a JSON header.
fn write_field(dir: &Path, grid: &rt_volume::Grid) -> Result<(), String> {
    let name = format!("dense_flow_{DENSE_GRID}");
    let raw: Vec<u8> = grid.data().iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join(format!("{name}.raw")), raw).map_err(|e| e.to_string())?;
    let header = serde_json::json!({
        "name": name,
        "file": format!("{name}.raw"),
        "dims": grid.dims(),
        "dtype": "float32",
        "endian": "little",
        "spacing": grid.spacing().to_array(),
        "origin": grid.origin().to_array(),
        "units": "kg/m^3",
        "length_units": "m",
        "quantity": "density",
        "generated_by": "rt-report schlieren (rt_benches::scenes::dense_flow, seed 1)",
    });
    let text = serde_json::to_string_pretty(&header).map_err(|e| e.to_string())?;
    std::fs::write(dir.join(format!("{name}.json")), text).map_err(|e| e.to_string())
}

/// The rows as a table, and the verdict on Catmull–Rom's cost.
pub(crate) fn table(rows: &[DenseRow], size: u32, photons: u32) -> (String, Vec<String>) {
    let mut md = format!(
        "\n**Dense field** ({DENSE_GRID}³ [`dense_flow`]: disturbed everywhere), as `rt schlieren` \
         renders it ({size} px, {photons} photons per pixel, the set-up's defaults), one thread; \
         rmse against RK4 at h/4 with the same photons. The GPU row (where there is an adapter: \
         `rt schlieren --device gpu`, rt-gpu) runs the same set-up with its photons traced on the \
         device in f32, no octree; on a software driver (Mesa's lavapipe, on these same cores) \
         its rate is only a check that it runs:\n\n\
         | tracer | on | photons | seconds (best of 3) | spread | photons per second | steps per photon | evaluations per photon | rmse |\n\
         |---|---|---|---|---|---|---|---|---|\n"
    );
    let count = |x: f64| if x.is_nan() { "–".to_string() } else { format!("{x:.1}") };
    for r in rows {
        writeln!(
            md,
            "| {} | {} | {} | {:.3} | +{:.0}% | {:.0} | {} | {} | {:.2e} |",
            r.interp,
            r.on,
            r.photons,
            r.seconds,
            r.spread,
            r.photons as f64 / r.seconds,
            count(r.steps_per_photon),
            count(r.evals_per_photon),
            r.rmse
        )
        .unwrap();
    }
    let mut verdicts = Vec::new();
    let rt = |name: &str| rows.iter().find(|r| r.interp == name);
    if let (Some(lin), Some(cubic)) = (rt("rt-trilinear"), rt("rt-catmull-rom")) {
        let ratio = cubic.seconds / lin.seconds;
        verdicts.push(format!(
            "dense {DENSE_GRID}³: Catmull–Rom costs {ratio:.2}× trilinear (target ≤ 1.3×: {})",
            if ratio <= 1.3 { "met" } else { "NOT met" }
        ));
    }
    (md, verdicts)
}
