//! Sort-last compositing on in-process ranks (threads and channels):
//! direct send, binary swap and radix-k (k = 4) on 2–16 ranks, 1024² and
//! 4096² images, 5 %, 50 % and 100 % of the pixels drawn; each result
//! checked bit for bit against the serial fold; plus the single-thread
//! z-compositing rate of two dense images against `memcpy` of the same
//! bytes.

use std::{fmt::Write as _, hint::black_box, path::Path, time::Duration};

use rt_composite::{Fragment, Operator, Schedule, ThreadComm, composite, serial_fold};
use rt_core::Pixel;

use crate::{
    Section,
    timing::{Samples, time},
};

/// A rank's image: the data cover `active` of the screen (blocks of 64
/// pixels chosen by a hash shared by all ranks: renders are coherent and
/// the ranks draw parts of one object), and every rank draws all of it at
/// its own depths (overlapping layers, the most blending work).
fn image(rank: usize, len: usize, active: f64) -> Vec<Pixel> {
    let covered = |block: u64| {
        let mut x = block.wrapping_add(1).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        x ^= x >> 31;
        x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
        x ^= x >> 29;
        ((x >> 11) as f64 / (1u64 << 53) as f64) < active
    };
    (0..len)
        .map(|i| {
            if covered((i / 64) as u64) {
                let h = (i as u64).wrapping_mul(2654435761) ^ (rank as u64 * 0x85eb_ca6b);
                let d = (h % 1000) as f32 / 100.0 + rank as f32 * 0.01;
                Pixel { color: [0.2, 0.4, 0.6, 1.0], depth: d }
            } else {
                Pixel::BACKGROUND
            }
        })
        .collect()
}

fn bits_equal(a: &[Pixel], b: &[Pixel]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            p.depth.to_bits() == q.depth.to_bits()
                && p.color.iter().zip(&q.color).all(|(x, y)| x.to_bits() == y.to_bits())
        })
}

pub(crate) fn run(dir: &Path, quick: bool) -> Result<Section, String> {
    let mut csv = String::from(
        "algorithm,ranks,width,height,active_fraction,seconds,bytes_sent,identical_to_serial\n",
    );
    let mut md = String::from(
        "| algorithm | ranks | size | active | seconds (best of 3) | spread | MB sent | vs dense | identical |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    let mut verdicts = Vec::new();
    let mut all_identical = true;
    let mut worst_ratio: f64 = 0.0;
    let sizes: &[(u32, &[usize])] = if quick {
        &[(256, &[2, 3, 4, 5, 8, 16])]
    } else {
        &[(1024, &[2, 3, 4, 5, 8, 16]), (4096, &[2, 4])]
    };
    for &(side, rank_counts) in sizes {
        let len = (side * side) as usize;
        for &n in rank_counts {
            let mut dense_bytes = std::collections::HashMap::new();
            for active in [1.0, 0.5, 0.05] {
                let images: Vec<Vec<Pixel>> = (0..n).map(|r| image(r, len, active)).collect();
                let refs: Vec<&[Pixel]> = images.iter().map(Vec::as_slice).collect();
                let expected = serial_fold(&refs, &Operator::Depth).map_err(|e| e.to_string())?;
                drop(refs);
                for (name, schedule) in [
                    ("direct-send", Schedule::DirectSend),
                    ("binary-swap", Schedule::BinarySwap),
                    ("radix-k", Schedule::RadixK(4)),
                ] {
                    // Best of 3; every run's image is checked.
                    let mut samples = Samples::default();
                    let (mut sent, mut identical) = (0, true);
                    for _ in 0..3 {
                        let comms = ThreadComm::group(n, Duration::from_secs(120));
                        let (secs, outcomes) = time(|| {
                            std::thread::scope(|s| {
                                let hs: Vec<_> = comms
                                    .into_iter()
                                    .zip(&images)
                                    .map(|(c, img)| {
                                        s.spawn(move || {
                                            composite(
                                                &c,
                                                img,
                                                side,
                                                side,
                                                schedule,
                                                &Operator::Depth,
                                            )
                                        })
                                    })
                                    .collect();
                                hs.into_iter().map(|h| h.join()).collect::<Vec<_>>()
                            })
                        });
                        samples.0.push(secs);
                        sent = 0;
                        let mut got = false;
                        for o in outcomes {
                            let (img, stats) = o
                                .map_err(|_| "a rank panicked".to_string())?
                                .map_err(|e| e.to_string())?;
                            sent += stats.bytes_sent;
                            if let Some(img) = img {
                                got = bits_equal(&img, &expected);
                            }
                        }
                        identical &= got;
                    }
                    let secs = samples.best();
                    all_identical &= identical;
                    if active == 1.0 {
                        dense_bytes.insert(name, sent);
                    }
                    let vs_dense = sent as f64 / dense_bytes[name] as f64;
                    if active < 1.0 {
                        worst_ratio = worst_ratio.max(vs_dense / active);
                    }
                    writeln!(csv, "{name},{n},{side},{side},{active},{secs:.4},{sent},{identical}")
                        .unwrap();
                    writeln!(
                        md,
                        "| {name} | {n} | {side}² | {active} | {secs:.3} | +{:.0}% | {:.1} | {vs_dense:.3} | {identical} |",
                        samples.spread(),
                        sent as f64 / 1e6
                    )
                    .unwrap();
                }
            }
        }
    }

    // Two dense images on one thread: z-compositing against memcpy of the
    // same bytes (both images read, one written), best of 5.
    let side = if quick { 1024 } else { 4096 };
    let len = side * side;
    let (a, b) = (image(0, len, 1.0), image(1, len, 1.0));
    let mut out = vec![Pixel::BACKGROUND; len];
    let (mut zs, mut ms) = (Samples::default(), Samples::default());
    let bytes_a: &[u8] = bytemuck::cast_slice(&a);
    let mut copy = vec![0u8; 2 * bytes_a.len()];
    for _ in 0..5 {
        zs.0.push(
            time(|| {
                for ((o, p), q) in out.iter_mut().zip(&a).zip(&b) {
                    *o = p.z(*q);
                }
                black_box(&out);
            })
            .0,
        );
        ms.0.push(
            time(|| {
                copy[..bytes_a.len()].copy_from_slice(bytes_a);
                copy[bytes_a.len()..].copy_from_slice(bytemuck::cast_slice(&b));
                black_box(&copy);
            })
            .0,
        );
    }
    let bytes = 2 * len * 20;
    for (name, s) in [("z-serial", &zs), ("memcpy", &ms)] {
        writeln!(csv, "{name},1,{side},{side},1,{:.5},{bytes},true", s.best()).unwrap();
        writeln!(
            md,
            "| {name} | 1 | {side}² | 1 | {:.4} (best of 5) | +{:.0}% | {:.1} | — | — |",
            s.best(),
            s.spread(),
            bytes as f64 / 1e6
        )
        .unwrap();
    }
    let rate = ms.best() / zs.best();
    verdicts.push(format!(
        "z-compositing two dense {side}² images on one thread: {:.2} GB/s against memcpy's {:.2} GB/s = {rate:.2}× (target ≥ 0.5×: {})",
        bytes as f64 / zs.best() / 1e9,
        bytes as f64 / ms.best() / 1e9,
        if rate >= 0.5 { "met" } else { "NOT met" }
    ));
    verdicts.push(format!("identical to the serial fold on every row: {all_identical}"));
    verdicts.push(format!(
        "sparse bytes sent ≤ {worst_ratio:.2} × active fraction × dense bytes (target ≤ 1.2)"
    ));
    std::fs::write(dir.join("composite.csv"), &csv).map_err(|e| e.to_string())?;
    writeln!(md, "\nwrote {}", dir.join("composite.csv").display()).unwrap();
    Ok(Section {
        title:
            "composite (in-process ranks on threads; seconds are wall time on this machine's cores)"
                .into(),
        body: md,
        verdicts,
        plots: vec![],
    })
}
