//! The watertight suite (`rt_benches::watertight`) against every anchor
//! built in: how many rays that must hit a closed mesh each one misses.
//! Closest-hit queries throughout; rt also with its any-hit query. obvhs
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
use rt_benches::watertight::{misses, suite};
use rt_core::Ray;

use crate::Section;

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
    let mut rays = 0;
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
            misses(case, |r| view.closest_t(r).is_some()),
            misses(case, |r| view.occluded(r)),
            misses(case, |r| {
                let mut hit = RayHit::none();
                cw.ray_traverse(to_o(r), &mut hit, |ray, id| cw_tris[id].intersect(ray))
            }),
            misses(case, |r| {
                let mut hit = RayHit::none();
                b2.ray_traverse(to_o(r), &mut hit, |ray, id| b2_tris[id].intersect(ray))
            }),
        ];
        #[cfg(feature = "embree3")]
        for robust in [false, true] {
            let scene = crate::embree3::EmbreeScene::new(&m.positions, &m.indices, robust);
            let mut ctx = crate::embree3::context();
            row.push(misses(case, |r| scene.closest(&mut ctx, r).is_some()));
        }
        #[cfg(feature = "embree4")]
        for robust in [false, true] {
            let scene = crate::embree4::Embree4Scene::new(&m.positions, &m.indices, robust)?;
            row.push(misses(case, |r| scene.closest(r).is_some()));
        }
        #[cfg(feature = "tinybvh")]
        {
            let tiny = crate::tinybvh::TinyScene::new(&m.positions, &m.indices)?;
            row.push(misses(case, |r| tiny.closest(r).is_some()));
        }
        let cells: Vec<String> = row.iter().map(usize::to_string).collect();
        let _ = writeln!(md, "| {} | {} | {} |", case.name, case.rays.len(), cells.join(" | "));
        let _ = writeln!(csv, "{},{},{}", case.name, case.rays.len(), cells.join(","));
        for (t, n) in totals.iter_mut().zip(&row) {
            *t += n;
        }
        rays += case.rays.len();
    }
    let cells: Vec<String> = totals.iter().map(usize::to_string).collect();
    let _ = writeln!(md, "| **all** | {rays} | {} |", cells.join(" | "));
    std::fs::write(dir.join("watertight.csv"), csv).map_err(|e| e.to_string())?;
    let verdicts = names
        .iter()
        .zip(&totals)
        .map(|(name, &n)| {
            let share = 100.0 * n as f64 / rays.max(1) as f64;
            let mark = if name.starts_with("rt") && n > 0 { " **(target: 0)**" } else { "" };
            format!("{name}: {n} misses of {rays} rays that must hit ({share:.3} %){mark}")
        })
        .collect();
    #[cfg(feature = "embree4")]
    let md = format!("Embree 4: {} (`RT_EMBREE4`).\n\n{md}", crate::embree4::version()?);
    let body = format!(
        "Rays that must hit a closed mesh (each aimed exactly at a vertex or a shared edge, its line through the solid; `rt_benches::watertight`), counted as misses when a query reports no hit. rt's kernels are all checked by `cargo test -p rt-benches --test watertight`. tinybvh rejects a triangle whose determinant is below an absolute 10⁻⁶ (its source), so small meshes are missed whole; double hits (two triangles reporting one crossing) are not counted, since closest-hit queries do not show them.\n\n{md}"
    );
    Ok(Section { title: "watertight suite (misses)".into(), body, verdicts, plots: vec![] })
}
