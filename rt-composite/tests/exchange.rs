//! Rounds of exchange and occlusion across ranks: the distributed answer
//! equals the whole scene's for every rank count and batch size; failures
//! are an `Err` on every rank within the timeout.

use core::time::Duration;
use std::time::Instant;

use rt_composite::{
    CommError, Communicator, OcclusionStats, ThreadComm,
    exchange::{ExchangeError, all_gather, rounds},
    resolve_occlusion,
};
use rt_core::{
    Aabb, Ray,
    glam::Vec3,
    intersect::intersect_triangle,
    sampling::{rng_for, uniform},
};

/// Runs `f(comm)` on `n` thread ranks; results in rank order.
fn on_ranks<T: Send>(n: usize, timeout: Duration, f: impl Fn(ThreadComm) -> T + Sync) -> Vec<T> {
    let comms = ThreadComm::group(n, timeout);
    std::thread::scope(|s| {
        let handles: Vec<_> = comms.into_iter().map(|c| s.spawn(|| f(c))).collect();
        handles.into_iter().map(|h| h.join().expect("rank panicked")).collect()
    })
}

/// A field of small random triangles in the unit cube.
fn triangles(n: usize, seed: u64) -> Vec<[Vec3; 3]> {
    let mut rng = rng_for(seed, 0);
    let mut p = || Vec3::new(uniform(&mut rng), uniform(&mut rng), uniform(&mut rng));
    (0..n)
        .map(|_| {
            let c = p();
            [c, c + 0.2 * (p() - 0.5), c + 0.2 * (p() - 0.5)]
        })
        .collect()
}

/// Rays from points in the cube in random directions, short and long.
fn rays(n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = rng_for(seed, 1);
    let mut u = || uniform(&mut rng);
    (0..n)
        .map(|i| {
            let o = Vec3::new(u(), u(), u());
            let d = Vec3::new(u() - 0.5, u() - 0.5, u() - 0.5);
            let t_max = if i % 3 == 0 { f32::INFINITY } else { 0.05 + u() };
            Ray::with_range(o, d, 0.0, t_max)
        })
        .collect()
}

fn occluded_by(tris: &[[Vec3; 3]], ray: &Ray) -> bool {
    tris.iter().any(|t| intersect_triangle(ray, t[0], t[1], t[2]).is_some())
}

/// Triangles by centroid into `n` slabs along x (rank r: slab r).
fn split(tris: &[[Vec3; 3]], n: usize) -> Vec<Vec<[Vec3; 3]>> {
    let mut out = vec![Vec::new(); n];
    for t in tris {
        let cx = (t[0].x + t[1].x + t[2].x) / 3.0;
        out[((cx * n as f32) as usize).min(n - 1)].push(*t);
    }
    out
}

fn bounds(tris: &[[Vec3; 3]]) -> Aabb {
    tris.iter().flatten().fold(Aabb::EMPTY, |b, &p| b.grow(p))
}

#[test]
fn distributed_occlusion_equals_the_whole_scene() {
    let tris = triangles(1500, 7);
    let all_rays = rays(1200, 9);
    let expected: Vec<bool> = all_rays.iter().map(|r| occluded_by(&tris, r)).collect();
    let blocked = expected.iter().filter(|&&b| b).count();
    assert!(blocked > 200 && blocked < 1000, "a test needs both answers: {blocked}");
    for n in [1usize, 2, 3, 4, 7, 16] {
        let parts = split(&tris, n);
        let regions: Vec<Aabb> = parts.iter().map(|p| bounds(p)).collect();
        for batch in [1usize, 17, 1 << 20] {
            let out = on_ranks(n, Duration::from_secs(20), |c| {
                let me = c.rank();
                // Rank r asks about every n-th ray, starting at r.
                let mine: Vec<Ray> = all_rays.iter().skip(me).step_by(n).copied().collect();
                let own = &parts[me];
                resolve_occlusion(&c, &regions, &mine, batch, |rs, out| {
                    for (r, o) in rs.iter().zip(out.iter_mut()) {
                        *o = occluded_by(own, r);
                    }
                })
            });
            let mut sent = 0;
            for (me, r) in out.into_iter().enumerate() {
                let (bits, stats): (Vec<bool>, OcclusionStats) =
                    r.unwrap_or_else(|e| panic!("{n} ranks, batch {batch}, rank {me}: {e}"));
                let want: Vec<bool> = expected.iter().skip(me).step_by(n).copied().collect();
                assert_eq!(bits, want, "{n} ranks, batch {batch}, rank {me}");
                assert!(stats.blocked_locally <= stats.rays);
                sent += stats.sent;
            }
            // With several ranks, rays really travel.
            assert_eq!(sent > 0, n > 1, "{n} ranks");
        }
    }
}

#[test]
fn regions_must_be_one_per_rank() {
    let out = on_ranks(2, Duration::from_secs(5), |c| {
        resolve_occlusion(&c, &[Aabb::EMPTY], &[], 8, |_, _| {})
    });
    for r in out {
        assert!(matches!(
            r,
            Err(ExchangeError::Step(rt_composite::OcclusionError::Regions { given: 1, ranks: 2 }))
        ));
    }
}

#[test]
fn all_gather_gives_every_rank_every_payload() {
    for n in [1usize, 2, 5] {
        let out = on_ranks(n, Duration::from_secs(5), |c| {
            let mine = if c.rank() == 1 { Vec::new() } else { vec![c.rank() as u8; c.rank() + 1] };
            all_gather(&c, &mine).map(|(all, _)| all)
        });
        for r in out {
            let all = r.unwrap();
            assert_eq!(all.len(), n);
            for (k, b) in all.iter().enumerate() {
                let want = if k == 1 { Vec::new() } else { vec![k as u8; k + 1] };
                assert_eq!(b, &want, "{n} ranks, payload of rank {k}");
            }
        }
    }
}

/// A rank that stops answering after its first round: every other rank
/// returns an `Err` within about one timeout, and none hangs.
#[test]
fn a_silent_rank_is_an_error_everywhere_within_the_timeout() {
    let timeout = Duration::from_millis(400);
    let t0 = Instant::now();
    let out = on_ranks(4, timeout, |c| {
        if c.rank() == 2 {
            // Round 0 only, then silence (the communicator stays alive, so
            // peers see no disconnect: only the timeout can tell them).
            let r: Result<_, ExchangeError<&str>> = rounds(&c, 1, |_, _, _| Ok(true));
            std::thread::sleep(Duration::from_secs(3));
            return r.map(|_| ()).map_err(|e| format!("{e}"));
        }
        rounds(&c, 1000, |_, _, out| {
            out.iter_mut().for_each(|o| o.push(1));
            Ok::<_, &str>(true)
        })
        .map(|_| ())
        .map_err(|e| format!("{e}"))
    });
    let elapsed = t0.elapsed();
    for (r, res) in out.iter().enumerate() {
        assert!(res.is_err(), "rank {r} must fail: {res:?}");
    }
    // Ranks 0, 1, 3 fail on the timeout, on a peer's abort, or on a peer
    // that already failed and hung up (under load one rank's timeout can
    // fire well before another's); rank 2 sleeps 3 s after its own
    // failure, so the others' failures are timed by their own error
    // messages, not by the join.
    assert!(elapsed < Duration::from_secs(6), "{elapsed:?}");
    for r in [0, 1, 3] {
        let e = out[r].as_ref().unwrap_err();
        assert!(
            e.contains("timed out") || e.contains("failed") || e.contains("is gone"),
            "rank {r}: {e}"
        );
    }
}

/// Ranks that fail on their own: their peers learn it in the same round.
#[test]
fn a_failing_step_is_an_error_on_every_rank() {
    let t0 = Instant::now();
    let out = on_ranks(5, Duration::from_secs(30), |c| {
        let me = c.rank();
        rounds(&c, 1000, |round, _, out| {
            if me == 3 && round == 4 {
                return Err("rank 3 broke");
            }
            out[(me + 1) % out.len()].push(round as u8);
            Ok(true)
        })
    });
    // Far less than the 30 s timeout: the abort is a message.
    assert!(t0.elapsed() < Duration::from_secs(5));
    for (r, res) in out.into_iter().enumerate() {
        match res {
            Err(ExchangeError::Step("rank 3 broke")) => assert_eq!(r, 3),
            // The abort, or a peer that already returned after it.
            Err(
                ExchangeError::PeerFailed { from }
                | ExchangeError::Comm(CommError::Disconnected(from)),
            ) => {
                assert_ne!(r, 3, "from {from}");
            }
            other => panic!("rank {r}: {other:?}"),
        }
    }
}

/// Work that never settles stops at `max_rounds` on every rank.
#[test]
fn work_that_never_settles_is_too_many_rounds() {
    let out = on_ranks(3, Duration::from_secs(10), |c| rounds(&c, 50, |_, _, _| Ok::<_, ()>(true)));
    for r in out {
        assert!(
            matches!(r, Err(ExchangeError::TooManyRounds(50) | ExchangeError::PeerFailed { .. })),
            "{r:?}"
        );
    }
}

/// A peer that sends garbage instead of a header.
#[test]
fn a_malformed_message_is_an_error() {
    let out = on_ranks(2, Duration::from_secs(5), |c| {
        if c.rank() == 1 {
            c.send(0, rt_composite::exchange::EXCHANGE_TAG, vec![7, 7, 7]).unwrap();
            // Alive until rank 0 has sent its round (then it reads ours).
            std::thread::sleep(Duration::from_millis(300));
            return Ok(());
        }
        rounds(&c, 10, |_, _, _| Ok::<_, ()>(false)).map(|_| ())
    });
    assert_eq!(out[0], Err(ExchangeError::Malformed { from: 1 }));
}
