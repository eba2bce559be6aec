//! Distributed rendering equals one process, bit for bit: surfaces with
//! shadows and ambient occlusion answered across ranks, on 1, 2, 3, 4, 7
//! and 16 ranks (threads). `.ci/run` runs the 4-process MPI case.

use core::time::Duration;

use rt_cli::distributed::surface::{self, SurfaceJob};
use rt_composite::{Schedule, ThreadComm};
use rt_core::{Frame, Pixel};

fn bits(f: &Frame) -> Vec<([u32; 4], u32)> {
    f.pixels().iter().map(|p: &Pixel| (p.color.map(f32::to_bits), p.depth.to_bits())).collect()
}

/// Rank 0's image and every rank's report.
fn surfaces(job: &SurfaceJob, ranks: usize) -> (Frame, Vec<surface::SurfaceRank>) {
    let comms = ThreadComm::group(ranks, Duration::from_secs(60));
    let out: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> =
            comms.into_iter().map(|c| s.spawn(move || surface::rank(&c, job))).collect();
        handles.into_iter().map(|h| h.join().expect("rank panicked")).collect()
    });
    let mut image = None;
    let mut reports = Vec::new();
    for (r, o) in out.into_iter().enumerate() {
        let (img, rep) = o.unwrap_or_else(|e| panic!("{ranks} ranks, rank {r}: {e:#}"));
        assert_eq!(img.is_some(), r == 0);
        image = image.or(img);
        reports.push(rep);
    }
    (image.expect("rank 0's image"), reports)
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
