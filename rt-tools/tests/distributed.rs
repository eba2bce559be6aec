//! Distributed rendering equals one process, bit for bit: surfaces with
//! shadows and ambient occlusion answered across ranks, on 1, 2, 3, 4, 7
//! and 16 ranks (threads). `.ci/run` runs the 4-process MPI case.

use core::time::Duration;

use rt_composite::{Communicator as _, Schedule, ThreadComm};
use rt_core::{Frame, Pixel};
use rt_tools::distributed::{
    surface::{self, SurfaceJob},
    volume,
};

fn bits(f: &Frame) -> Vec<([u32; 4], u32)> {
    f.pixels().iter().map(|p: &Pixel| (p.color.map(f32::to_bits), p.depth.to_bits())).collect()
}

/// Runs `f` on `ranks` thread ranks: rank 0's result and every rank's
/// report (only rank 0 may have a result).
fn on_ranks<T: Send, R: Send>(
    ranks: usize,
    f: impl Fn(&ThreadComm) -> anyhow::Result<(Option<T>, R)> + Sync,
) -> (T, Vec<R>) {
    let mut first = None;
    let mut reports = Vec::new();
    for (r, o) in outcomes(ranks, f).into_iter().enumerate() {
        let (img, rep) = o.unwrap_or_else(|e| panic!("{ranks} ranks, rank {r}: {e}"));
        assert_eq!(img.is_some(), r == 0);
        first = first.or(img);
        reports.push(rep);
    }
    (first.expect("rank 0's result"), reports)
}

/// Each rank's outcome of `f` on `ranks` thread ranks, its error as text.
fn outcomes<T: Send, E: core::fmt::Display + Send>(
    ranks: usize,
    f: impl Fn(&ThreadComm) -> Result<T, E> + Sync,
) -> Vec<Result<T, String>> {
    let comms = ThreadComm::group(ranks, Duration::from_secs(60));
    let f = &f;
    std::thread::scope(|s| {
        let handles: Vec<_> = comms.into_iter().map(|c| s.spawn(move || f(&c))).collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("rank panicked").map_err(|e| format!("{e:#}")))
            .collect()
    })
}

fn surfaces(job: &SurfaceJob, ranks: usize) -> (Frame, Vec<surface::SurfaceRank>) {
    on_ranks(ranks, |c| surface::rank(c, job))
}

#[test]
fn surfaces_with_shadows_and_ao_equal_one_process_bit_for_bit() {
    let job = SurfaceJob {
        size: (96, 72),
        grid: 65,
        shadows: true,
        ao: 4,
        ao_distance: Some(0.4),
        seed: 3,
        schedule: Schedule::BinarySwap,
    };
    let whole = surface::single(&job).unwrap();
    // The lighting is global: without shadows and AO the image differs.
    let local = surface::single(&SurfaceJob { shadows: false, ao: 0, ..job.clone() }).unwrap();
    let changed = bits(&whole).iter().zip(bits(&local)).filter(|(a, b)| **a != *b).count();
    assert!(changed > 1000, "shadows and AO change only {changed} pixels");
    for ranks in [1usize, 2, 3, 4, 7, 16] {
        let (image, reports) = surfaces(&job, ranks);
        let differ = bits(&image).iter().zip(bits(&whole)).filter(|(a, b)| **a != *b).count();
        assert_eq!(differ, 0, "{ranks} ranks: {differ} pixels differ");
        let sent: u64 = reports.iter().map(|r| r.occlusion.sent).sum();
        let answered: u64 = reports.iter().map(|r| r.occlusion.answered).sum();
        // Every query sent is answered once, and with several ranks some
        // rays really are answered by another rank.
        assert_eq!(sent, answered, "{ranks} ranks");
        assert_eq!(sent > 0, ranks > 1, "{ranks} ranks");
        // Rays blocked only by another rank's triangles: rank-local
        // occlusion would have left them open, and the image would differ.
        let elsewhere: u64 = reports.iter().map(|r| r.occlusion.blocked_elsewhere).sum();
        assert_eq!(elsewhere > 100, ranks > 1, "{ranks} ranks: {elsewhere} blocked elsewhere");
        let triangles: usize = reports.iter().map(|r| r.triangles).sum();
        assert_eq!(triangles, 2 * 64 * 64, "{ranks} ranks own every triangle once");
    }
}

fn volumes(job: &volume::VolumeJob, ranks: usize) -> (rt_photo::Film, Vec<volume::VolumeRank>) {
    on_ranks(ranks, |c| Ok(volume::rank(c, job)?))
}

/// Knife-edge schlieren and interferometry of the blast wave, photons
/// handed between bricks that each rank read alone from the file: the film
/// equals one process tracing the whole grid, bit for bit, and no rank
/// held the whole grid.
#[test]
fn volumes_equal_one_process_bit_for_bit_and_no_rank_holds_the_grid() {
    let dir =
        std::env::temp_dir().join(format!("rt-tools-test-distributed-{}", std::process::id()));
    let knife = volume::builtin(&dir, 40, 1).unwrap();
    let fringes = volume::VolumeJob {
        optics: volume::VolumeOptics::Interferometry { lambda: 10.6e-6, fringes: Some(0.04) },
        interp: rt_volume::Interp::Trilinear,
        ..knife.clone()
    };
    for job in [&knife, &fringes] {
        let whole = volume::single(job).unwrap();
        for ranks in [1usize, 2, 3, 4, 7, 16] {
            let (film, reports) = volumes(job, ranks);
            assert!(
                volume::same(&film, &whole),
                "{ranks} ranks, {:?}: the films differ",
                job.optics
            );
            let entered: u64 = reports.iter().map(|r| r.entered).sum();
            let handed: u64 = reports.iter().map(|r| r.handed_off).sum();
            let legs: u64 = reports.iter().map(|r| r.legs).sum();
            // Every leg but a photon's last ends in a hand-off.
            assert_eq!(legs, entered + handed, "{ranks} ranks");
            for r in &reports {
                if ranks > 1 {
                    assert!(
                        r.brick_samples < r.grid_samples,
                        "{ranks} ranks: a rank held the grid"
                    );
                } else {
                    assert_eq!(r.brick_samples, r.grid_samples);
                }
            }
            // Bricks split the beam's axis from 2 ranks up (for 2: 2×1×1 along
            // the longest axis, a cube's first: x; so from 3 check travel).
            if ranks >= 4 {
                assert!(handed > 0, "{ranks} ranks: no photon crossed a brick");
            }
        }
    }
    // Bounded buffers: with 50 photons a round, no message exceeds what 50
    // hand-offs and 50 results take, though over a thousand photons cross
    // (in more rounds); the film is still the same.
    let small = volume::VolumeJob { batch: 50, ..knife.clone() };
    let whole = volume::single(&small).unwrap();
    let (film, reports) = volumes(&small, 4);
    assert!(volume::same(&film, &whole));
    let handed: u64 = reports.iter().map(|r| r.handed_off).sum();
    assert!(handed > 1000, "{handed}");
    for r in &reports {
        let longest = r.exchange.largest_message as usize;
        assert!(longest <= small.largest_message(), "{longest} > {}", small.largest_message());
        assert!(r.exchange.rounds > 8, "{} rounds", r.exchange.rounds);
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// A rank whose messages stop arriving after its first `after` (it keeps
/// running, so only the timeout can tell its peers).
struct GoesSilent {
    inner: ThreadComm,
    after: usize,
    sent: core::cell::Cell<usize>,
}

impl rt_composite::Communicator for GoesSilent {
    fn rank(&self) -> usize {
        self.inner.rank()
    }
    fn size(&self) -> usize {
        self.inner.size()
    }
    fn send(&self, to: usize, tag: u32, data: Vec<u8>) -> Result<(), rt_composite::CommError> {
        self.sent.set(self.sent.get() + 1);
        if self.sent.get() > self.after {
            return Ok(());
        }
        self.inner.send(to, tag, data)
    }
    fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, rt_composite::CommError> {
        self.inner.recv(from, tag)
    }
}

/// Rank 2 of 4 stops answering in the middle of the work: its first nine
/// messages arrive (the two rounds that share the regions or the field's
/// extremes, then the first round of occlusion queries or photons), the
/// rest never do. Every rank returns an `Err` within about the timeout,
/// and none hangs.
#[test]
fn a_rank_that_stops_answering_is_an_error_on_every_rank() {
    let dir = std::env::temp_dir().join(format!("rt-tools-test-silent-{}", std::process::id()));
    let vjob = volume::builtin(&dir, 32, 1).unwrap();
    let sjob = SurfaceJob {
        size: (64, 48),
        grid: 33,
        shadows: true,
        ao: 2,
        ao_distance: None,
        seed: 1,
        schedule: Schedule::BinarySwap,
    };
    let timeout = Duration::from_millis(500);
    for kind in ["surface", "volume"] {
        let comms = ThreadComm::group(4, timeout);
        let t0 = std::time::Instant::now();
        let failed: Vec<(bool, Duration)> = std::thread::scope(|s| {
            let handles: Vec<_> = comms
                .into_iter()
                .map(|c| {
                    let after = if c.rank() == 2 { 9 } else { usize::MAX };
                    let c = GoesSilent { inner: c, after, sent: core::cell::Cell::new(0) };
                    let (sjob, vjob) = (&sjob, &vjob);
                    s.spawn(move || {
                        let err = if kind == "surface" {
                            surface::rank(&c, sjob).is_err()
                        } else {
                            volume::rank(&c, vjob).is_err()
                        };
                        (err, t0.elapsed())
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().expect("rank panicked")).collect()
        });
        for (r, (err, at)) in failed.iter().enumerate() {
            assert!(err, "{kind}: rank {r} did not fail");
            assert!(*at < Duration::from_secs(10), "{kind}: rank {r} took {at:?}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Samples `lo..hi` of the whole `grid` as the piece a rank holds.
fn cut(
    grid: &rt_volume::Grid,
    info: rt_volume::GridInfo,
    lo: [usize; 3],
    hi: [usize; 3],
) -> volume::Piece {
    let dims = [0, 1, 2].map(|a| hi[a] - lo[a]);
    let mut samples = Vec::new();
    for k in lo[2]..hi[2] {
        for j in lo[1]..hi[1] {
            let row = (k * info.dims[1] + j) * info.dims[0];
            samples.extend_from_slice(&grid.data()[row + lo[0]..row + hi[0]]);
        }
    }
    volume::Piece { info, lo, dims, samples, first: grid.data()[0] }
}

/// Each rank handed only its piece of the grid, as ParaView hands a rank
/// its extent (here cut from the file in memory, each the box
/// `first_brick_box` names): the same film as one process, bit for bit;
/// a piece short of its ghost layers is refused by name, not traced wrong.
#[test]
fn pieces_held_in_memory_equal_one_process_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("rt-tools-test-pieces-{}", std::process::id()));
    let job = volume::builtin(&dir, 32, 1).unwrap();
    let info = rt_volume::io::read_grid_info(&job.file).unwrap();
    let grid = rt_volume::io::read_grid_box(&job.file, [0; 3], info.dims).unwrap();
    let whole = volume::single(&job).unwrap();
    let piece = |lo, hi| cut(&grid, info, lo, hi);
    for ranks in [1usize, 2, 3, 4] {
        let (film, reports) = on_ranks(ranks, |c| {
            let (lo, hi) = volume::first_brick_box(info, job.interp, ranks, c.rank())?;
            Ok(volume::rank_from(c, &job, &piece(lo, hi), volume::Watch::NONE)?)
        });
        assert!(volume::same(&film, &whole), "{ranks} ranks: the films differ");
        if ranks > 1 {
            assert!(reports.iter().all(|r| r.brick_samples < r.grid_samples));
        }
    }
    // Pieces one layer short on every side: refused.
    let comms = ThreadComm::group(2, Duration::from_secs(20));
    let errors: Vec<String> = std::thread::scope(|s| {
        let handles: Vec<_> = comms
            .into_iter()
            .map(|c| {
                let (job, piece) = (&job, &piece);
                s.spawn(move || {
                    let (lo, hi) = volume::first_brick_box(info, job.interp, 2, c.rank()).unwrap();
                    let lo = lo.map(|v| v + 1);
                    let hi = hi.map(|v| v - 1);
                    volume::rank_from(&c, job, &piece(lo, hi), volume::Watch::NONE)
                        .err()
                        .map(|e| e.to_string())
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap().unwrap_or_default()).collect()
    });
    assert!(errors.iter().any(|e| e.contains("too few ghost layers")), "{errors:?}");
}

/// A watched run: rank 0 alone is told its progress, rising to every
/// photon; a rank told to stop (while it traces, or while it lists its
/// photons) fails with `Stopped` and every peer learns of it from the
/// exchange, none from the 60 s timeout.
#[test]
fn a_watched_run_tells_its_progress_and_stops_on_every_rank() {
    use core::sync::atomic::{AtomicU64, Ordering};
    use std::sync::Mutex;
    let dir = std::env::temp_dir().join(format!("rt-tools-test-watch-{}", std::process::id()));
    let job = volume::builtin(&dir, 32, 1).unwrap();
    let told: Vec<Mutex<Vec<(u64, u64)>>> = (0..3).map(|_| Mutex::new(Vec::new())).collect();
    let never = || false;
    let out = outcomes(3, |c| {
        let log = &told[c.rank()];
        let progress = |d, t| log.lock().unwrap().push((d, t));
        volume::rank_from(c, &job, &job, volume::Watch::new(&never, &progress))
    });
    let film = out[0].as_ref().unwrap().0.as_ref().unwrap();
    assert!(volume::same(film, &volume::single(&job).unwrap()));
    let seen = told[0].lock().unwrap().clone();
    let total = seen[0].1;
    // One photon per stratum: 32² pixels and the film's margin, 1² strata.
    assert_eq!(total, 34 * 34, "{seen:?}");
    assert!(seen.windows(2).all(|w| w[0].0 <= w[1].0 && w[1].1 == total), "{seen:?}");
    assert_eq!(seen.last(), Some(&(total, total)));
    assert!(seen.len() > 2 && seen[0].0 < total, "{seen:?}");
    assert!(told[1].lock().unwrap().is_empty() && told[2].lock().unwrap().is_empty());

    for (who, after) in [(1usize, 50u64), (0, 0)] {
        let asked = AtomicU64::new(0);
        let stop = || asked.fetch_add(1, Ordering::Relaxed) >= after;
        let out = outcomes(3, |c| {
            let watch = if c.rank() == who {
                volume::Watch::new(&stop, &|_, _| {})
            } else {
                volume::Watch::NONE
            };
            volume::rank_from(c, &job, &job, watch)
        });
        for (r, o) in out.iter().enumerate() {
            let e = o.as_ref().err().unwrap_or_else(|| panic!("rank {r} was not stopped"));
            // A peer hears the abort, or finds a rank that ended because
            // of it gone (threads drop their channels); never a timeout.
            let heard = (0..3).filter(|&p| p != r).any(|p| {
                e.contains(&format!("rank {p} failed")) || e.contains(&format!("rank {p} is gone"))
            });
            let ok = if r == who { e.contains("the run was stopped") } else { heard };
            assert!(ok, "stopping rank {who}: rank {r} says {e}");
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// BOS and focusing schlieren of the blast wave, each rank holding only
/// its piece: the rig chosen from a survey traced across the ranks, and
/// every camera ray handed between bricks, give the images of one process
/// tracing the whole grid, bit for bit, on 1 to 4 ranks.
#[test]
fn bos_and_focusing_across_ranks_equal_one_process_bit_for_bit() {
    let dir = std::env::temp_dir().join(format!("rt-tools-test-cameras-{}", std::process::id()));
    let job = volume::builtin(&dir, 32, 1).unwrap();
    let info = rt_volume::io::read_grid_info(&job.file).unwrap();
    let grid = rt_volume::io::read_grid_box(&job.file, [0; 3], info.dims).unwrap();
    let piece = |ranks: usize, rank: usize| -> anyhow::Result<volume::Piece> {
        let (lo, hi) = volume::first_brick_box(info, job.interp, ranks, rank)?;
        Ok(cut(&grid, info, lo, hi))
    };
    let f64_bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let bos = rt_photo::BosOptions { size: 40, samples_per_axis: 1, ..Default::default() };
    let (setup, whole) = volume::bos_single(&job, &job, &bos, 5).unwrap();
    // The survey saw the blast: the background sits where its deflection
    // moves the dots, and they move.
    assert!(setup.rig.deflection > 0.0, "{}", setup.rig);
    let moved = whole.displacement.iter().map(|d| d[0].hypot(d[1])).fold(0.0, f64::max);
    assert!(moved > 0.1, "largest displacement {moved} px, rig {}", setup.rig);
    let focusing =
        rt_photo::FocusingOptions { size: 40, samples_per_axis: 2, ..Default::default() };
    let (fsetup, fwhole) = volume::focusing_single(&job, &job, &focusing, 5).unwrap();
    assert_ne!(f64_bits(&fwhole.flow), f64_bits(&fwhole.reference));
    for ranks in [1usize, 2, 3, 4] {
        let ((s, images), reports) = on_ranks(ranks, |c| {
            Ok(volume::bos_rank(c, &job, &piece(ranks, c.rank())?, &bos, 5, volume::Watch::NONE)?)
        });
        assert_eq!(s.rig, setup.rig, "{ranks} ranks: another rig");
        assert_eq!(f64_bits(&images.flow), f64_bits(&whole.flow), "{ranks} ranks: BOS flow");
        let d = |i: &rt_photo::BosImages| {
            i.displacement.iter().flatten().map(|x| x.to_bits()).collect::<Vec<_>>()
        };
        assert_eq!(d(&images), d(&whole), "{ranks} ranks: displacement");
        if ranks == 4 {
            assert!(reports.iter().map(|r| r.handed_off).sum::<u64>() > 100);
            assert!(reports.iter().all(|r| r.brick_samples < r.grid_samples));
        }
        let ((s, images), _) = on_ranks(ranks, |c| {
            Ok(volume::focusing_rank(
                c,
                &job,
                &piece(ranks, c.rank())?,
                &focusing,
                5,
                volume::Watch::NONE,
            )?)
        });
        assert_eq!(s.rig, fsetup.rig, "{ranks} ranks: another focusing rig");
        assert_eq!(f64_bits(&images.flow), f64_bits(&fwhole.flow), "{ranks} ranks: focusing");
        assert_eq!(f64_bits(&images.reference), f64_bits(&fwhole.reference));
    }
    std::fs::remove_dir_all(&dir).ok();
}
