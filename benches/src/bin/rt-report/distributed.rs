//! Rays and photons across in-process ranks (threads and channels), each
//! result checked bit for bit against one process:
//!
//! - `surface`: the terrain cut into slabs, one per rank, rendered with
//!   hard shadows and ambient occlusion whose rays are answered by every
//!   rank whose region they cross (`rt distributed --shadows --ao N`);
//! - `volume`: the built-in blast wave split into bricks, one per rank,
//!   each loaded from the raw file with its ghost layers only; knife-edge
//!   schlieren photons are handed from brick to brick
//!   (`rt distributed --volume`).
//!
//! All ranks share this machine's cores, so `seconds(1) / seconds(n)` is
//! what distribution costs on the same hardware (1.0: nothing), not a
//! speed-up; the traffic columns are what a cluster would carry.

use std::{fmt::Write as _, path::Path, time::Duration};

use rt_benches::plot::{Plot, Series, loglog};
use rt_composite::{Schedule, ThreadComm};
use rt_core::Frame;
use rt_tools::distributed::{surface, volume};

use crate::{
    Section,
    timing::{Samples, time},
};

/// One row of the table.
struct Row {
    kind: &'static str,
    ranks: usize,
    samples: Samples,
    items: u64,
    bytes: u64,
    messages: u64,
    identical: bool,
    /// Largest brick any rank held, in samples (volumes).
    largest_brick: usize,
    /// Longest message any rank sent, in bytes.
    largest_message: u64,
}

impl Row {
    fn new(kind: &'static str, ranks: usize) -> Self {
        Self {
            kind,
            ranks,
            samples: Samples::default(),
            items: 0,
            bytes: 0,
            messages: 0,
            identical: true,
            largest_brick: 0,
            largest_message: 0,
        }
    }
}

fn same(a: &Frame, b: &Frame) -> bool {
    a.pixels().iter().zip(b.pixels()).all(|(p, q)| {
        p.depth.to_bits() == q.depth.to_bits()
            && p.color.iter().zip(&q.color).all(|(x, y)| x.to_bits() == y.to_bits())
    })
}

/// Runs `f` on `n` thread ranks; results in rank order.
fn on_ranks<T: Send, E: std::fmt::Display + Send>(
    n: usize,
    f: impl Fn(&ThreadComm) -> Result<T, E> + Sync,
) -> Result<Vec<T>, String> {
    let comms = ThreadComm::group(n, Duration::from_secs(300));
    std::thread::scope(|s| {
        let f = &f;
        let hs: Vec<_> = comms.into_iter().map(|c| s.spawn(move || f(&c))).collect();
        hs.into_iter()
            .map(|h| {
                h.join().map_err(|_| "a rank panicked".to_string())?.map_err(|e| format!("{e:#}"))
            })
            .collect()
    })
}

fn surface_rows(quick: bool, ranks: &[usize], reps: usize) -> Result<Vec<Row>, String> {
    let job = surface::SurfaceJob {
        size: if quick { (320, 240) } else { (1024, 768) },
        grid: if quick { 129 } else { 513 },
        shadows: true,
        ao: if quick { 2 } else { 8 },
        ao_distance: None,
        seed: 1,
        schedule: Schedule::BinarySwap,
    };
    let whole = surface::single(&job).map_err(|e| format!("{e:#}"))?;
    let mut rows = Vec::new();
    for &n in ranks {
        let mut row = Row::new("surface", n);
        for _ in 0..reps {
            let (secs, out) = time(|| on_ranks(n, |c| surface::rank(c, &job)));
            let out = out?;
            row.samples.0.push(secs);
            row.items = out.iter().map(|(_, r)| r.occlusion.sent).sum();
            row.bytes = out.iter().map(|(_, r)| r.occlusion.exchange.bytes_sent).sum();
            row.messages = out.iter().map(|(_, r)| r.occlusion.exchange.messages).sum();
            row.largest_message =
                out.iter().map(|(_, r)| r.occlusion.exchange.largest_message).max().unwrap_or(0);
            let image = out.iter().find_map(|(f, _)| f.as_ref()).ok_or("no image")?;
            row.identical &= same(image, &whole);
        }
        rows.push(row);
    }
    Ok(rows)
}

fn volume_rows(quick: bool, ranks: &[usize], reps: usize) -> Result<Vec<Row>, String> {
    let dir = std::env::temp_dir().join(format!("rt-report-distributed-{}", std::process::id()));
    let job = volume::builtin(&dir, if quick { 128 } else { 512 }, if quick { 1 } else { 2 })
        .map_err(|e| format!("{e:#}"))?;
    let whole = volume::single(&job).map_err(|e| format!("{e:#}"))?;
    let mut rows = Vec::new();
    for &n in ranks {
        let mut row = Row::new("volume", n);
        for _ in 0..reps {
            let (secs, out) = time(|| on_ranks(n, |c| volume::rank(c, &job)));
            let out = out?;
            row.samples.0.push(secs);
            row.items = out.iter().map(|(_, r)| r.handed_off).sum();
            row.bytes = out.iter().map(|(_, r)| r.exchange.bytes_sent).sum();
            row.messages = out.iter().map(|(_, r)| r.exchange.messages).sum();
            row.largest_message =
                out.iter().map(|(_, r)| r.exchange.largest_message).max().unwrap_or(0);
            row.largest_brick = out.iter().map(|(_, r)| r.brick_samples).max().unwrap_or(0);
            let image = out.iter().find_map(|(f, _)| f.as_ref()).ok_or("no image")?;
            row.identical &= volume::same(image, &whole);
        }
        rows.push(row);
    }
    std::fs::remove_dir_all(&dir).ok();
    Ok(rows)
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let ranks: &[usize] = &[1, 2, 4, 8, 16];
    let reps = if quick { 1 } else { 3 };
    let mut rows = surface_rows(quick, ranks, reps)?;
    rows.extend(volume_rows(quick, ranks, reps)?);
    let mut csv =
        String::from("kind,ranks,seconds,items_sent,bytes_sent,messages,identical_to_single\n");
    let mut md = String::from(
        "| kind | ranks | seconds (best) | spread | vs 1 rank | items sent | MB sent | messages | longest message (KB) | largest brick (samples) | identical |\n|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut series = Vec::new();
    let mut verdicts = Vec::new();
    for kind in ["surface", "volume"] {
        let of_kind: Vec<&Row> = rows.iter().filter(|r| r.kind == kind).collect();
        let one = of_kind.first().map_or(f64::NAN, |r| r.samples.best());
        for r in &of_kind {
            let secs = r.samples.best();
            writeln!(
                csv,
                "{},{},{secs:.4},{},{},{},{}",
                r.kind, r.ranks, r.items, r.bytes, r.messages, r.identical
            )
            .unwrap();
            let brick = if r.kind == "volume" { r.largest_brick.to_string() } else { "—".into() };
            writeln!(
                md,
                "| {} | {} | {secs:.3} | +{:.0}% | {:.2} | {} | {:.2} | {} | {:.1} | {brick} | {} |",
                r.kind,
                r.ranks,
                r.samples.spread(),
                one / secs,
                r.items,
                r.bytes as f64 / 1e6,
                r.messages,
                r.largest_message as f64 / 1e3,
                r.identical
            )
            .unwrap();
        }
        series.push(Series {
            name: format!("{kind}: bytes sent"),
            points: of_kind.iter().map(|r| (r.ranks as f64, r.bytes as f64)).collect(),
        });
        let all = of_kind.iter().all(|r| r.identical);
        verdicts.push(format!(
            "{kind}: identical to the single-process image on {} of {} rank counts ({})",
            of_kind.iter().filter(|r| r.identical).count(),
            of_kind.len(),
            if all { "met" } else { "NOT met" }
        ));
    }
    std::fs::write(dir.join("distributed.csv"), &csv).map_err(|e| e.to_string())?;
    writeln!(md, "\nwrote {}", dir.join("distributed.csv").display()).unwrap();
    let plot = Plot {
        pareto: false,
        title: "bytes sent between ranks (rays and photons)".into(),
        x_label: "ranks".into(),
        y_label: "bytes sent, all ranks".into(),
        series,
    };
    loglog(&plot, 800, 560, &dir.join("distributed.png")).map_err(|e| e.to_string())?;
    Ok(Section {
        title: "distributed (rays and photons across in-process ranks; all ranks share this machine's cores)".into(),
        body: md,
        verdicts,
        plots: vec![(
            "distributed.png".into(),
            "bytes sent between ranks (y) against the rank count (x), surfaces (occlusion queries and answers) and volumes (photons handed between bricks)".into(),
        )],
    })
}
