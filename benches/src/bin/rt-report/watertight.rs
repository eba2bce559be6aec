//! The watertight suite (`rt_benches::watertight`) against every anchor
//! built in: how many rays that must hit a closed mesh each one misses
//! (closest-hit queries; rt also with its any-hit query), and, from each
//! anchor's every-hit query, the cracks and double counts at the point
//! each ray is aimed at. obvhs
//! and tinybvh test triangles with Möller–Trumbore, Embree 3 by default
//! with its fast test and in its robust mode with a watertight one.

use std::{fmt::Write as _, path::Path};

use glam::Vec3A;
use obvhs::{
    BvhBuildParams,
    bvh2::builder::build_bvh2_from_tris,
    cwbvh::builder::build_cwbvh_from_tris,
    ray::{Ray as ORay, RayHit},
    triangle::Triangle,
};
use rt_accel::{BuildParams, build_triangles};
use rt_benches::watertight::{AtAims, Case, at_aims, misses, suite};
use rt_core::Ray;
use rt_surface::cast::RayCaster;

use crate::{Section, timing::time};

/// `misses` of `case` with `hits`, and the best of five runs' seconds.
fn timed(case: &Case, mut hits: impl FnMut(&Ray) -> bool) -> (usize, f64) {
    let (mut n, mut best) = (0, f64::INFINITY);
    for _ in 0..5 {
        let (secs, m) = time(|| misses(case, &mut hits));
        (n, best) = (m, best.min(secs));
    }
    (n, best)
}

/// Every anchor's misses per case, and the table.
pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let cases = suite(if quick { 200 } else { 2000 });
    let mut names: Vec<&str> = vec!["rt", "rt any-hit", "obvhs-cwbvh", "obvhs-bvh2"];
    if cfg!(feature = "embree3") {
        names.extend(["embree3", "embree3-robust"]);
    }
    if cfg!(feature = "embree4") {
        names.extend(["embree4", "embree4-robust"]);
    }
    if cfg!(feature = "tinybvh") {
        names.push("tinybvh");
    }
    let mut md = format!("| mesh and scale | rays | {} |\n|---|---|", names.join(" | "));
    md += &"---|".repeat(names.len());
    md.push('\n');
    let mut csv = format!("case,rays,{}\n", names.join(","));
    let mut totals = vec![0usize; names.len()];
    let mut seconds = vec![0.0f64; names.len()];
    let mut rays = 0;
    // The all-hits queries: every anchor but tinybvh, which has none.
    let mut all_names: Vec<&str> = vec!["rt", "obvhs-cwbvh", "obvhs-bvh2"];
    if cfg!(feature = "embree3") {
        all_names.extend(["embree3", "embree3-robust"]);
    }
    if cfg!(feature = "embree4") {
        all_names.extend(["embree4", "embree4-robust"]);
    }
    let mut all_md = format!("| mesh and scale | rays | {} |\n|---|---|", all_names.join(" | "));
    all_md += &"---|".repeat(all_names.len());
    all_md.push('\n');
    let mut all_csv = String::from("case,anchor,rays,missed,doubled\n");
    let mut all_totals = vec![AtAims::default(); all_names.len()];
    for case in &cases {
        let m = &case.mesh;
        let bvh = build_triangles(&m.positions, &m.indices, &BuildParams::medium())
            .map_err(|e| e.to_string())?;
        let view = bvh.as_ref();
        let tris: Vec<Triangle> = m
            .indices
            .iter()
            .map(|t| {
                let v = t.map(|i| Vec3A::from(m.positions[i as usize]));
                Triangle { v0: v[0], v1: v[1], v2: v[2] }
            })
            .collect();
        let params = BvhBuildParams::medium_build();
        let mut took = std::time::Duration::default();
        let cw = build_cwbvh_from_tris(&tris, params, &mut took);
        let cw_tris: Vec<Triangle> =
            cw.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
        let b2 = build_bvh2_from_tris(&tris, params, &mut took);
        let b2_tris: Vec<Triangle> =
            b2.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
        let to_o = |r: &Ray| ORay::new(r.origin.into(), r.direction.into(), r.t_min, r.t_max);
        // The anchors built in add their columns below.
        #[cfg_attr(
            not(any(feature = "embree3", feature = "embree4", feature = "tinybvh")),
            allow(unused_mut)
        )]
        let mut row = vec![
            timed(case, |r| view.closest_t(r).is_some()),
            timed(case, |r| view.occluded(r)),
            timed(case, |r| {
                let mut hit = RayHit::none();
                cw.ray_traverse(to_o(r), &mut hit, |ray, id| cw_tris[id].intersect(ray))
            }),
            timed(case, |r| {
                let mut hit = RayHit::none();
                b2.ray_traverse(to_o(r), &mut hit, |ray, id| b2_tris[id].intersect(ray))
            }),
        ];
        #[cfg(feature = "embree3")]
        for robust in [false, true] {
            let scene = crate::embree3::EmbreeScene::new(&m.positions, &m.indices, robust);
            let mut ctx = crate::embree3::context();
            row.push(timed(case, |r| scene.closest(&mut ctx, r).is_some()));
        }
        #[cfg(feature = "embree4")]
        for robust in [false, true] {
            let scene = crate::embree4::Embree4Scene::new(&m.positions, &m.indices, robust)?;
            row.push(timed(case, |r| scene.closest(r).is_some()));
        }
        #[cfg(feature = "tinybvh")]
        {
            let tiny = crate::tinybvh::TinyScene::new(&m.positions, &m.indices)?;
            row.push(timed(case, |r| tiny.closest(r).is_some()));
        }
        // Every hit along each ray, as `(t, triangle)`: rt's all-hits
        // query; obvhs's traversal with a callback that records each hit
        // and lets the ray go on; Embree's with a filter that does.
        let caster = RayCaster::new(&m.positions, &m.indices).map_err(|e| e.to_string())?;
        let obvhs_all = |r: &Ray, cwbvh: bool| {
            let mut hits = Vec::new();
            let mut hit = RayHit::none();
            let mut record = |ray: &ORay, id: usize, tris: &[Triangle], prims: &[u32]| {
                let t = tris[id].intersect(ray);
                if t < f32::INFINITY {
                    hits.push((t, prims[id]));
                }
                f32::INFINITY
            };
            if cwbvh {
                cw.ray_traverse(to_o(r), &mut hit, |ray, id| {
                    record(ray, id, &cw_tris, &cw.primitive_indices)
                });
            } else {
                b2.ray_traverse(to_o(r), &mut hit, |ray, id| {
                    record(ray, id, &b2_tris, &b2.primitive_indices)
                });
            }
            hits
        };
        #[cfg_attr(not(any(feature = "embree3", feature = "embree4")), allow(unused_mut))]
        let mut all_row = vec![
            at_aims(case, |r| {
                caster
                    .all(core::slice::from_ref(r), 64)
                    .iter()
                    .map(|(_, h)| (h.t, h.prim))
                    .collect()
            }),
            at_aims(case, |r| obvhs_all(r, true)),
            at_aims(case, |r| obvhs_all(r, false)),
        ];
        #[cfg(feature = "embree3")]
        for robust in [false, true] {
            let scene = crate::embree3::EmbreeScene::recording(&m.positions, &m.indices, robust);
            let mut ctx = crate::embree3::context();
            all_row.push(at_aims(case, |r| scene.all_hits(&mut ctx, r)));
        }
        #[cfg(feature = "embree4")]
        for robust in [false, true] {
            let scene = crate::embree4::Embree4Scene::recording(&m.positions, &m.indices, robust)?;
            all_row.push(at_aims(case, |r| scene.all_hits(r)));
        }
        let cells: Vec<String> =
            all_row.iter().map(|a| format!("{} / {}", a.missed, a.doubled)).collect();
        let _ = writeln!(all_md, "| {} | {} | {} |", case.name, all_row[0].rays, cells.join(" | "));
        for ((name, a), total) in all_names.iter().zip(&all_row).zip(&mut all_totals) {
            let _ = writeln!(all_csv, "{},{name},{},{},{}", case.name, a.rays, a.missed, a.doubled);
            *total += *a;
        }
        let cells: Vec<String> = row.iter().map(|(n, _)| n.to_string()).collect();
        let _ = writeln!(md, "| {} | {} | {} |", case.name, case.rays.len(), cells.join(" | "));
        let _ = writeln!(csv, "{},{},{}", case.name, case.rays.len(), cells.join(","));
        for ((t, secs), (n, took)) in totals.iter_mut().zip(&mut seconds).zip(&row) {
            *t += n;
            *secs += took;
        }
        rays += case.rays.len();
    }
    let cells: Vec<String> = totals.iter().map(usize::to_string).collect();
    let _ = writeln!(md, "| **all** | {rays} | {} |", cells.join(" | "));
    let cells: Vec<String> =
        all_totals.iter().map(|a| format!("{} / {}", a.missed, a.doubled)).collect();
    let _ = writeln!(all_md, "| **all** | {} | {} |", all_totals[0].rays, cells.join(" | "));
    std::fs::write(dir.join("watertight.csv"), csv).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("watertight_all_hits.csv"), all_csv).map_err(|e| e.to_string())?;
    let mut verdicts: Vec<String> = names
        .iter()
        .zip(&totals)
        .map(|(name, &n)| {
            let share = 100.0 * n as f64 / rays.max(1) as f64;
            let mark = if name.starts_with("rt") && n > 0 { " **(target: 0)**" } else { "" };
            format!("{name}: {n} misses of {rays} rays that must hit ({share:.3} %){mark}")
        })
        .collect();
    verdicts.extend(all_names.iter().zip(&all_totals).map(|(name, a)| {
        let mark = if *name == "rt" && (a.missed, a.doubled) != (0, 0) {
            " **(target: 0 and 0)**"
        } else {
            ""
        };
        format!(
            "{name}, all hits: {} cracks and {} double counts at the aimed point of {} rays{mark}",
            a.missed, a.doubled, a.rays
        )
    }));
    // The closest-hit queries' speed on the suite's own rays (one thread,
    // best of five per case), against Embree 4's default where built in.
    let anchor = ["embree4", "embree3"].iter().find_map(|a| names.iter().position(|n| n == a));
    let against = anchor.map_or("–", |a| names[a]);
    let mut speed = format!("| query | M rays/s | × {against} |\n|---|---|---|\n");
    for (name, secs) in names.iter().zip(&seconds) {
        let ratio = anchor.map_or(String::from("–"), |a| format!("{:.2}", seconds[a] / secs));
        let _ = writeln!(speed, "| {name} | {:.2} | {ratio} |", rays as f64 / secs / 1e6);
    }
    if let Some(a) = anchor {
        let ratio = seconds[a] / seconds[0];
        let met = if ratio >= 1.0 { "met" } else { "NOT met" };
        verdicts.push(format!(
            "rt's closest hits on the suite's rays at {ratio:.2}× {}'s speed (target ≥ 1.0×): {met}",
            names[a]
        ));
    }
    let md = format!(
        "{md}\nThe same queries' speed on the suite's {rays} rays (one thread; each case's best of five runs, summed; the last column is each one's speed over the anchor's closest hits):\n\n{speed}"
    );
    #[cfg(feature = "embree4")]
    let md = format!("Embree 4: {} (`RT_EMBREE4`).\n\n{md}", crate::embree4::version()?);
    let body = format!(
        "Rays that must hit a closed mesh (each aimed exactly at a vertex or a shared edge, its line through the solid; `rt_benches::watertight`), counted as misses when a query reports no hit. rt's kernels are all checked by `cargo test -p rt-benches --test watertight`. tinybvh rejects a triangle whose determinant is below an absolute 10⁻⁶ (its source), so small meshes are missed whole.\n\n{md}\n\
         **Every hit along each ray** (what an inside/outside test by counting crossings, or trimesh's `intersects_location`, relies on): per anchor, `cracks / double counts` at the point each ray is aimed at, over the rays aimed from outside (`rt_benches::watertight::at_aims`). A crack: no hit there (the closest-hit count above misses it when the ray goes on to hit the back face); a double count: two or more triangles reporting the one crossing there. rt: its all-hits query (`rt_surface::cast::RayCaster::all`, which merges the triangles that meet at one crossing); obvhs: its traversal with a callback that records each Möller–Trumbore hit and lets the ray go on; Embree: `rtcIntersect1` with an intersection filter that records and rejects every hit (`filter.rs`). tinybvh has no all-hits query. `watertight_all_hits.csv` has the counts.\n\n{all_md}"
    );
    Ok(Section { title: "watertight suite (misses)".into(), body, verdicts, plots: vec![] })
}
