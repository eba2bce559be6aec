//! Distributed tracing through bricks of a grid: each leg of a ray runs on
//! one rank's [`BrickField`] only, and the final result equals, bit for
//! bit, the trace through the whole grid.

mod support;

use glam::DVec3;
use rt_volume::{
    Begin, BrickError, BrickField, Bricks, Exit, Grid, GridField, GridInfo, IndexField, Interp,
    Leg, Method, PathState, TraceError, TraceParams, TraceResult, step_reach, trace, trace_begin,
    trace_leg,
};
use support::Rng;

const DIMS: [usize; 3] = [33, 29, 31];
const AMBIENT: f64 = 1.000_293;

/// A graded-index fibre along z (rays along it oscillate across the
/// planes near its axis: re-entries) and an off-centre bump, sampled on
/// a 33×29×31 grid with a different spacing per axis, centred on 0.
fn grid() -> Grid {
    let spacing = DVec3::new(0.031, 0.035, 0.0325);
    let origin = -0.5 * (DVec3::new(32.0, 28.0, 30.0) * spacing);
    let c = DVec3::new(0.2, -0.15, 0.1);
    let mut data = Vec::new();
    for k in 0..DIMS[2] {
        for j in 0..DIMS[1] {
            for i in 0..DIMS[0] {
                let p = origin + DVec3::new(i as f64, j as f64, k as f64) * spacing;
                let fibre = 0.5 * (-(p.x * p.x + p.y * p.y) / (2.0 * 0.15 * 0.15)).exp();
                let bump = 0.15 * (-(p - c).length_squared() / (2.0 * 0.1 * 0.1)).exp();
                data.push((1.1 + fibre + bump) as f32);
            }
        }
    }
    Grid::new(DIMS, origin, spacing, data).unwrap()
}

fn params(method: Method, cell: f64) -> TraceParams {
    match method {
        Method::Adaptive => {
            TraceParams { tolerance: 1e-8, max_step: 0.5 * cell, ..TraceParams::accurate() }
        }
        m => TraceParams { max_step: cell, ..TraceParams::fixed(m, 0.5 * cell) },
    }
}

/// About 200 rays: along the fibre, from all around, from inside, through
/// the partition's inner brick corners diagonally, along its planes, and
/// some that miss.
fn rays(bricks: &Bricks, rng: &mut Rng) -> Vec<(DVec3, DVec3)> {
    let b = bricks.info().bounds();
    let (lo, hi) = (b.min, b.max);
    let mut r = Vec::new();
    for _ in 0..50 {
        let o = DVec3::new(rng.range(-0.25, 0.25), rng.range(-0.25, 0.25), lo.z - 0.3);
        r.push((o, DVec3::new(rng.range(-0.1, 0.1), rng.range(-0.1, 0.1), 1.0)));
    }
    for _ in 0..50 {
        let a = rng.range(0.0, core::f64::consts::TAU);
        let z = rng.range(-1.0, 1.0);
        let s = (1.0 - z * z).sqrt();
        let o = 1.5 * DVec3::new(s * a.cos(), s * a.sin(), z);
        let target =
            DVec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z));
        r.push((o, target - o));
    }
    for _ in 0..20 {
        let o = DVec3::new(rng.range(lo.x, hi.x), rng.range(lo.y, hi.y), rng.range(lo.z, hi.z));
        let d = DVec3::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
        r.push((o, d));
    }
    // Misses: beside the box, and away from it.
    for i in 0..10 {
        let t = f64::from(i);
        r.push((DVec3::new(hi.x + 0.1 + 0.01 * t, 0.0, lo.z - 1.0), DVec3::Z));
        r.push((DVec3::new(0.0, 0.1 * t - 0.5, hi.z + 0.5), DVec3::new(0.1, 0.0, 1.0)));
    }
    // Diagonally through the inner corners where bricks meet (and the
    // centre, for one brick).
    let mut corners = vec![0.5 * (lo + hi)];
    for rank in 0..bricks.count() {
        let m = bricks.owned(rank).max;
        if m.cmplt(hi).all() {
            corners.push(m);
        }
    }
    corners.truncate(6);
    for c in &corners {
        for d in [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, 1.0, 1.0),
            DVec3::new(1.0, -1.0, 1.0),
            DVec3::new(1.0, 1.0, -1.0),
            DVec3::new(1.0, 1.0, 0.0),
        ] {
            r.push((*c - 1.5 * d, d));
        }
    }
    // Along the brick planes (and the fibre's axis plane), nearly parallel
    // to them: the fibre bends these rays back and forth across.
    let mut planes = vec![0.0];
    for rank in 0..bricks.count() {
        let x = bricks.owned(rank).max.x;
        if x < hi.x {
            planes.push(x);
        }
    }
    while r.len() < 200 {
        let x = planes[r.len() % planes.len()] + rng.range(-0.02, 0.02);
        let o = DVec3::new(x, rng.range(-0.3, 0.3), lo.z - 0.2);
        r.push((o, DVec3::new(rng.range(-0.03, 0.03), rng.range(-0.2, 0.2), 1.0)));
    }
    r
}

/// What a distributed trace did.
#[derive(Default)]
struct Tally {
    rays: usize,
    legs_3: usize,
    reentered: usize,
    diagonal_hops: usize,
    missed: usize,
}

/// The legs of one ray, each on the rank owning its start, with only that
/// rank's brick; the state goes through its words between legs.
fn trace_distributed(
    bricks: &Bricks,
    fields: &[BrickField],
    o: DVec3,
    d: DVec3,
    p: &TraceParams,
    tally: &mut Tally,
) -> Result<TraceResult, TraceError> {
    let f0 = &fields[0];
    let mut state = match trace_begin(f0.bounds(), f0.ambient(), o, d, p)? {
        Begin::Missed(r) => {
            tally.missed += 1;
            return Ok(r);
        }
        Begin::Inside(s) => s,
    };
    let mut path = Vec::new();
    loop {
        let rank = bricks.owner(state.position());
        assert_ne!(path.last(), Some(&rank), "handed to itself");
        path.push(rank);
        assert!(path.len() < 10_000, "ping-pong");
        let wire = PathState::from_words(&state.to_words()).unwrap();
        assert_eq!(wire, state);
        match trace_leg(&fields[rank], wire, p, |x| bricks.owner(x) == rank)? {
            Leg::Finished(r) => {
                tally.rays += 1;
                tally.legs_3 += usize::from(path.len() >= 3);
                let again = path.iter().enumerate().any(|(i, r)| path[i + 1..].contains(r));
                tally.reentered += usize::from(again);
                let [px, py, _] = bricks.parts();
                let coords = |r: usize| [r % px, (r / px) % py, r / (px * py)];
                tally.diagonal_hops += path
                    .windows(2)
                    .filter(|w| {
                        let (a, b) = (coords(w[0]), coords(w[1]));
                        (0..3).filter(|&i| a[i] != b[i]).count() >= 2
                    })
                    .count();
                return Ok(r);
            }
            Leg::Left(s) => state = s,
        }
    }
}

fn assert_bit_identical(got: &TraceResult, want: &TraceResult, what: &str) {
    assert_eq!(got, want, "{what}");
    let bits = |r: &TraceResult| {
        (
            r.position.to_array().map(f64::to_bits),
            r.direction.to_array().map(f64::to_bits),
            r.optical_path.to_bits(),
        )
    };
    assert_eq!(bits(got), bits(want), "{what}");
}

/// The bit-identity test: every method, both interpolants, 1–16
/// bricks, ~200 rays each.
#[test]
fn legs_through_bricks_equal_the_whole_grid_trace_bit_for_bit() {
    let g = grid();
    let info = g.info();
    let cell = info.spacing.min_element();
    let total = g.data().len();
    let mut all = Tally::default();
    let mut exits = [0usize; 4];
    for interp in [Interp::Trilinear, Interp::CatmullRom] {
        let whole = GridField::new(g.clone(), interp, AMBIENT).unwrap();
        let bounds = g.index_bounds(interp);
        for method in Method::ALL {
            let p = params(method, cell);
            let reach = step_reach(&p, bounds.n_max, bounds.grad_max).unwrap();
            for ranks in [1, 2, 3, 4, 7, 8, 16] {
                let bricks = Bricks::for_ranks(info, ranks).unwrap();
                assert_eq!(bricks.count(), ranks);
                let fields: Vec<BrickField> = (0..ranks)
                    .map(|r| {
                        let (lo, hi) = bricks.samples_needed(r, reach, interp).unwrap();
                        BrickField::from_grid(&g, lo, hi, interp, AMBIENT).unwrap()
                    })
                    .collect();
                if ranks > 1 {
                    for f in &fields {
                        assert!(
                            f.stored_samples() < total,
                            "{ranks} ranks: a brick holds the whole grid"
                        );
                    }
                }
                // The bricks' own bounds, combined, hold where the
                // grid's do (tighter: each brick's per-axis maxima).
                let c =
                    fields.iter().map(BrickField::index_bounds).reduce(|a, b| a.max(b)).unwrap();
                assert!(c.n_max <= bounds.n_max && c.grad_max <= bounds.grad_max, "{c:?}");
                assert!(c.grad_max > 0.9 * bounds.grad_max, "{c:?}");
                if interp == Interp::Trilinear {
                    assert_eq!(c.n_max, bounds.n_max);
                }
                let mut tally = Tally::default();
                let mut rng = Rng(ranks as u64 * 7919 + method as u64);
                for (o, d) in rays(&bricks, &mut rng) {
                    let want = trace(&whole, o, d, &p).unwrap();
                    let got = trace_distributed(&bricks, &fields, o, d, &p, &mut tally)
                        .unwrap_or_else(|e| {
                            panic!("{interp:?} {method:?} {ranks} ranks, ray {o} {d}: {e}")
                        });
                    let what = format!("{interp:?} {method:?} {ranks} ranks, ray {o} {d}");
                    assert_bit_identical(&got, &want, &what);
                    exits[want.exit as usize] += 1;
                }
                if ranks >= 4 {
                    assert!(tally.legs_3 > 0, "{interp:?} {method:?} {ranks}: no ray had 3 legs");
                }
                if ranks == 8 {
                    assert!(tally.diagonal_hops > 0, "{interp:?} {method:?}: no corner crossed");
                }
                all.rays += tally.rays;
                all.legs_3 += tally.legs_3;
                all.reentered += tally.reentered;
                all.diagonal_hops += tally.diagonal_hops;
                all.missed += tally.missed;
            }
        }
    }
    assert!(all.reentered > 100, "re-entries: {}", all.reentered);
    assert!(all.legs_3 > 1000, "rays with ≥ 3 legs: {}", all.legs_3);
    assert!(all.missed > 0 && all.rays > 1000);
    assert!(exits[Exit::Missed as usize] > 0 && exits[Exit::Left as usize] > 1000, "{exits:?}");
}

/// The other two ends of a trace, on bricks: the arc-length limit and the
/// step limit.
#[test]
fn max_length_and_max_steps_end_the_same_on_bricks() {
    let g = grid();
    let info = g.info();
    let cell = info.spacing.min_element();
    let mut tally = Tally::default();
    for interp in [Interp::Trilinear, Interp::CatmullRom] {
        let whole = GridField::new(g.clone(), interp, AMBIENT).unwrap();
        let bounds = g.index_bounds(interp);
        for (method, p) in [
            (Method::Rk4, TraceParams { max_length: 0.5, ..params(Method::Rk4, cell) }),
            (Method::Adaptive, TraceParams { max_steps: 25, ..params(Method::Adaptive, cell) }),
            (Method::Symplectic, TraceParams { max_steps: 30, ..params(Method::Symplectic, cell) }),
        ] {
            let reach = step_reach(&p, bounds.n_max, bounds.grad_max).unwrap();
            let bricks = Bricks::new(info, [2, 2, 2]).unwrap();
            let fields: Vec<BrickField> = (0..8)
                .map(|r| {
                    let (lo, hi) = bricks.samples_needed(r, reach, interp).unwrap();
                    BrickField::from_grid(&g, lo, hi, interp, AMBIENT).unwrap()
                })
                .collect();
            let mut rng = Rng(17);
            let mut ended = 0;
            for (o, d) in rays(&bricks, &mut rng) {
                let want = trace(&whole, o, d, &p).unwrap();
                let got = trace_distributed(&bricks, &fields, o, d, &p, &mut tally).unwrap();
                assert_bit_identical(&got, &want, &format!("{method:?} {o} {d}"));
                ended += usize::from(matches!(want.exit, Exit::MaxLength | Exit::MaxSteps));
            }
            assert!(ended > 20, "{method:?}: {ended} rays ended on a limit");
        }
    }
}

/// A brick's values are the whole grid's, bit for bit, wherever it holds
/// the stencil, and NaN elsewhere; `covers` tells which.
#[test]
fn a_brick_interpolates_exactly_as_the_whole_grid() {
    let g = grid();
    let b = g.bounds();
    let mut rng = Rng(5);
    for interp in [Interp::Trilinear, Interp::CatmullRom] {
        let whole = GridField::new(g.clone(), interp, AMBIENT).unwrap();
        for (lo, hi) in [
            ([0, 0, 0], [33, 29, 31]),
            ([0, 3, 5], [9, 29, 14]),
            ([20, 0, 20], [33, 7, 31]),
            ([4, 4, 4], [8, 9, 10]),
        ] {
            let brick = BrickField::from_grid(&g, lo, hi, interp, AMBIENT).unwrap();
            assert_eq!(brick.sample_box(), (lo, hi));
            assert_eq!(brick.bounds(), b);
            let (mut inside, mut outside) = (0, 0);
            // The box's own cells, with a cell around them.
            let cell = |i: usize, a: usize| g.origin()[a] + (i as f64 - 1.5) * g.spacing()[a];
            let (near_lo, near_hi) = (
                DVec3::from([0, 1, 2].map(|a| cell(lo[a], a))),
                DVec3::from([0, 1, 2].map(|a| cell(hi[a] + 2, a))),
            );
            for n in 0..4000 {
                // Over the bounds and a little beyond, and near the box.
                let (a, z) =
                    if n % 2 == 0 { (b.min - 0.05, b.max + 0.05) } else { (near_lo, near_hi) };
                let x = DVec3::new(rng.range(a.x, z.x), rng.range(a.y, z.y), rng.range(a.z, z.z));
                let (n, grad) = brick.eval(x);
                if brick.covers(x) {
                    inside += 1;
                    let (wn, wg) = whole.eval(x);
                    assert_eq!(n.to_bits(), wn.to_bits(), "{interp:?} {lo:?}..{hi:?} at {x}");
                    assert_eq!(grad.to_array().map(f64::to_bits), wg.to_array().map(f64::to_bits));
                } else {
                    outside += 1;
                    assert!(n.is_nan() && grad.is_nan(), "{x}");
                }
            }
            assert!(inside > 20, "{lo:?}..{hi:?}");
            if hi != DIMS {
                assert!(outside > 20);
            } else {
                assert_eq!(outside, 0);
            }
        }
    }
}

/// Exactly the cells a box of samples can interpolate: trilinear needs
/// the two samples around a point per axis, Catmull–Rom four (the ghost
/// rule's two at a face).
#[test]
fn covers_is_the_stencil() {
    let g = grid();
    let info = g.info();
    let at = |u: [f64; 3]| info.origin + DVec3::from(u) * info.spacing;
    let tri = BrickField::from_grid(&g, [4, 4, 4], [8, 8, 8], Interp::Trilinear, 1.0).unwrap();
    assert!(tri.covers(at([4.01, 4.01, 4.01])));
    assert!(tri.covers(at([6.99, 6.99, 6.99])));
    assert!(!tri.covers(at([7.01, 5.0, 5.0])), "needs sample 8");
    assert!(!tri.covers(at([3.99, 5.0, 5.0])), "needs sample 3");
    let cr = BrickField::from_grid(&g, [4, 4, 4], [9, 9, 9], Interp::CatmullRom, 1.0).unwrap();
    assert!(cr.covers(at([5.01, 5.01, 5.01])));
    assert!(cr.covers(at([6.99, 6.5, 6.01])));
    assert!(!cr.covers(at([4.99, 5.5, 5.5])), "needs sample 3");
    assert!(!cr.covers(at([7.01, 5.5, 5.5])), "needs sample 9");
    // At the grid's faces the ghost sample −1 is 2s₀ − s₁: samples 0..3
    // cover the first cells and the outer half cell.
    let face = BrickField::from_grid(&g, [0, 0, 0], [3, 3, 3], Interp::CatmullRom, 1.0).unwrap();
    assert!(face.covers(at([-0.5, -0.5, -0.5])));
    assert!(face.covers(at([0.99, 0.5, 0.01])));
    assert!(!face.covers(at([1.01, 0.5, 0.5])));
    let top = [30, 26, 28];
    let face = BrickField::from_grid(&g, top, DIMS, Interp::CatmullRom, 1.0).unwrap();
    assert!(face.covers(at([32.5, 28.5, 30.5])));
    assert!(face.covers(at([31.01, 27.01, 29.01])));
    assert!(!face.covers(at([30.99, 28.0, 30.0])));
}

/// A brick loaded without enough ghost layers stops the trace with
/// `BadField` at a point it does not cover, never with a wrong answer.
#[test]
fn a_brick_short_of_its_reach_is_an_error_not_a_wrong_answer() {
    let g = grid();
    let info = g.info();
    let cell = info.spacing.min_element();
    for interp in [Interp::Trilinear, Interp::CatmullRom] {
        let bricks = Bricks::new(info, [2, 1, 1]).unwrap();
        for p in [
            params(Method::Rk4, cell),
            TraceParams {
                max_step: 4.0 * cell,
                ..TraceParams::fixed(Method::Symplectic, 4.0 * cell)
            },
        ] {
            for (name, boxes) in [
                ("owned samples only", [bricks.samples_owned(0), bricks.samples_owned(1)]),
                ("zero reach", [0, 1].map(|r| bricks.samples_needed(r, 0.0, interp).unwrap())),
            ] {
                if name == "zero reach" && p.step < cell {
                    // Half-cell steps stay within the stencil's slack.
                    continue;
                }
                let fields = boxes
                    .map(|(lo, hi)| BrickField::from_grid(&g, lo, hi, interp, AMBIENT).unwrap());
                let o = DVec3::new(-0.6, 0.05, 0.02);
                let state = match trace_begin(info.bounds(), AMBIENT, o, DVec3::X, &p).unwrap() {
                    Begin::Inside(s) => s,
                    Begin::Missed(_) => panic!("aimed at the box"),
                };
                let mut state = state;
                let err = loop {
                    let r = bricks.owner(state.position());
                    match trace_leg(&fields[r], state, &p, |x| bricks.owner(x) == r) {
                        Ok(Leg::Left(s)) => state = s,
                        Ok(Leg::Finished(res)) => panic!("{interp:?} {name}: finished {res:?}"),
                        Err(e) => break (r, e),
                    }
                };
                let (r, TraceError::BadField { at }) = err else {
                    panic!("{interp:?} {name}: {err:?}");
                };
                assert!(!fields[r].covers(at), "{interp:?} {name}: {at}");
            }
        }
    }
}

/// The partition: every point has one owner whose box holds it; counts
/// factorised near-cubically; a prime count cuts the longest axis.
#[test]
fn bricks_partition_space_and_samples() {
    let info = grid().info();
    let b = info.bounds();
    for ranks in 1..=64 {
        let Ok(bricks) = Bricks::for_ranks(info, ranks) else {
            // Only a prime larger than every axis's samples does not fit.
            assert!([37, 41, 43, 47, 53, 59, 61].contains(&ranks), "{ranks}");
            continue;
        };
        let p = bricks.parts();
        assert_eq!(p[0] * p[1] * p[2], ranks);
        let mut samples = 0;
        for r in 0..ranks {
            let (lo, hi) = bricks.samples_owned(r);
            samples += (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
        }
        assert_eq!(samples, 33 * 29 * 31, "{ranks}");
    }
    assert_eq!(Bricks::for_ranks(info, 7).unwrap().parts(), [7, 1, 1]);
    assert_eq!(Bricks::for_ranks(info, 8).unwrap().parts(), [2, 2, 2]);
    let tall = GridInfo::new([10, 10, 40], DVec3::ZERO, DVec3::ONE).unwrap();
    assert_eq!(Bricks::for_ranks(tall, 7).unwrap().parts(), [1, 1, 7]);
    assert_eq!(Bricks::for_ranks(tall, 41).unwrap_err(), BrickError::Partition);
    assert!(Bricks::for_ranks(tall, 1024).is_ok());
    assert_eq!(Bricks::for_ranks(tall, 0).unwrap_err(), BrickError::Partition);
    assert_eq!(Bricks::new(tall, [11, 1, 1]).unwrap_err(), BrickError::Partition);
    assert_eq!(Bricks::new(tall, [0, 1, 1]).unwrap_err(), BrickError::Partition);
    let bricks = Bricks::new(info, [3, 2, 4]).unwrap();
    assert_eq!(bricks.owner(DVec3::splat(-100.0)), 0);
    assert_eq!(bricks.owner(DVec3::splat(100.0)), 23);
    assert_eq!(bricks.owner(b.max), 23, "the last brick is closed");
    assert_eq!(bricks.owner(b.min), 0);
    // The samples needed within `reach` cover every point that near.
    let reach = 0.07;
    let g = grid();
    let fields: Vec<BrickField> = (0..bricks.count())
        .map(|r| {
            let (lo, hi) = bricks.samples_needed(r, reach, Interp::CatmullRom).unwrap();
            BrickField::from_grid(&g, lo, hi, Interp::CatmullRom, 1.0).unwrap()
        })
        .collect();
    let mut rng = Rng(3);
    for _ in 0..5000 {
        let x = DVec3::new(
            rng.range(b.min.x, b.max.x),
            rng.range(b.min.y, b.max.y),
            rng.range(b.min.z, b.max.z),
        );
        let r = bricks.owner(x);
        assert!(bricks.owned(r).contains(x));
        let y = x + DVec3::new(
            rng.range(-reach, reach),
            rng.range(-reach, reach),
            rng.range(-reach, reach),
        );
        let y = y.clamp(b.min, b.max);
        assert!(fields[r].covers(y), "{x} → {y}");
    }
    assert_eq!(bricks.samples_needed(0, f64::NAN, Interp::Trilinear), Err(BrickError::Reach));
    assert_eq!(bricks.samples_needed(0, -1.0, Interp::Trilinear), Err(BrickError::Reach));
    assert_eq!(bricks.samples_needed(0, f64::INFINITY, Interp::Trilinear), Ok(([0; 3], DIMS)));
}

/// Boxes and headers that do not fit are errors.
#[test]
fn bad_bricks_are_errors() {
    let g = grid();
    let t = Interp::Trilinear;
    assert!(matches!(
        BrickField::from_grid(&g, [0; 3], [34, 2, 2], t, 1.0),
        Err(BrickError::SampleBox { .. })
    ));
    assert!(matches!(
        BrickField::from_grid(&g, [3; 3], [3, 5, 5], t, 1.0),
        Err(BrickError::SampleBox { .. })
    ));
    assert!(BrickField::from_grid(&g, [0; 3], [2; 3], t, 0.0).is_err());
    let small = Grid::new([2, 2, 2], DVec3::ZERO, DVec3::ONE, vec![1.0; 8]).unwrap();
    assert!(matches!(
        BrickField::new(g.info(), [32, 0, 0], small.clone(), t, 1.0),
        Err(BrickError::SampleBox { .. })
    ));
    assert!(BrickField::new(g.info(), [31, 27, 29], small, t, 1.0).is_ok());
    let neg = Grid::new(
        [2, 2, 2],
        DVec3::ZERO,
        DVec3::ONE,
        vec![1.0, 1.0, -1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
    )
    .unwrap();
    assert!(BrickField::new(g.info(), [0; 3], neg, t, 1.0).is_err());
    assert!(GridInfo::new([0, 1, 1], DVec3::ZERO, DVec3::ONE).is_err());
    assert!(GridInfo::new([1, 1, 1], DVec3::ZERO, DVec3::new(1.0, 0.0, 1.0)).is_err());
    assert!(GridInfo::new([usize::MAX, 2, 1], DVec3::ZERO, DVec3::ONE).is_err());
    assert!(
        GridInfo::new([1 << 20, 1 << 20, 1 << 10], DVec3::ZERO, DVec3::ONE).is_ok(),
        "larger than a Grid"
    );
}

/// A path state crosses the wire exactly; words no state writes are
/// refused.
#[test]
fn path_state_round_trips_through_words_and_refuses_garbage() {
    let g = grid();
    let cell = g.spacing().min_element();
    let field = GridField::new(g.clone(), Interp::CatmullRom, AMBIENT).unwrap();
    let p = params(Method::Adaptive, cell);
    let Begin::Inside(start) =
        trace_begin(field.bounds(), AMBIENT, DVec3::new(0.1, 0.0, -1.0), DVec3::Z, &p).unwrap()
    else {
        panic!("aimed at the box");
    };
    assert_eq!(PathState::from_words(&start.to_words()), Ok(start));
    // Midway: entered, with stats and a cached evaluation.
    let Leg::Left(mid) = trace_leg(&field, start, &p, |x| x.z < 0.0).unwrap() else {
        panic!("the ray crosses z = 0");
    };
    assert!(mid.position().z >= 0.0 && mid.stats().steps > 5);
    let w = mid.to_words();
    assert_eq!(PathState::from_words(&w), Ok(mid));
    assert_eq!(
        PathState::from_words(&w).unwrap().to_words().map(f64::to_bits),
        w.map(f64::to_bits)
    );
    // Resuming from the words finishes as the whole trace does.
    let Leg::Finished(end) =
        trace_leg(&field, PathState::from_words(&w).unwrap(), &p, |_| true).unwrap()
    else {
        panic!("owns everything");
    };
    assert_eq!(end, trace(&field, DVec3::new(0.1, 0.0, -1.0), DVec3::Z, &p).unwrap());
    // Garbage: each word spoiled in turn.
    let spoil = |i: usize, v: f64| {
        let mut b = w;
        b[i] = v;
        PathState::from_words(&b)
    };
    for (i, v) in [
        (0, f64::NAN),
        (1, f64::INFINITY),
        (4, f64::NAN),
        (6, f64::NEG_INFINITY),
        (7, f64::NAN),
        (8, 0.0),
        (8, -1.0),
        (9, f64::NAN),
        (10, -1.0),
        (11, -1.0),
        (11, 2.5),
        (12, 5e9),
        (13, f64::NAN),
        (14, -1e-3),
        (15, f64::NAN),
        (16, 0.5),
        (17, -1.0),
        (18, 0.5),
        (22, 0.0),
        (20, f64::NAN),
        (26, 2.0),
        (26, 0.0),
    ] {
        assert_eq!(spoil(i, v), Err(TraceError::InvalidState), "word {i} = {v}");
    }
    let mut zero_t = w;
    zero_t[3..6].copy_from_slice(&[0.0; 3]);
    assert_eq!(PathState::from_words(&zero_t), Err(TraceError::InvalidState));
    // No cached evaluation: its words must be zeros.
    let mut none = w;
    none[18] = 0.0;
    assert_eq!(PathState::from_words(&none), Err(TraceError::InvalidState));
    none[19..26].copy_from_slice(&[0.0; 7]);
    assert!(PathState::from_words(&none).is_ok());
    assert_eq!(PathState::from_words(&[0.0; PathState::WORDS]), Err(TraceError::InvalidState));
}

/// A finished ray's result crosses the wire exactly, every exit kind;
/// words no result writes are refused.
#[test]
fn trace_results_round_trip_through_words_and_refuse_garbage() {
    let g = grid();
    let cell = g.spacing().min_element();
    let field = GridField::new(g, Interp::CatmullRom, AMBIENT).unwrap();
    let mut results = Vec::new();
    for (origin, max_steps) in [
        (DVec3::new(0.1, 0.0, -1.0), 100_000),
        (DVec3::new(5.0, 5.0, -1.0), 100_000),
        (DVec3::new(0.1, 0.0, -1.0), 3),
    ] {
        let p = TraceParams { max_steps, ..params(Method::Adaptive, cell) };
        results.push(trace(&field, origin, DVec3::Z, &p).unwrap());
    }
    let exits: Vec<Exit> = results.iter().map(|r| r.exit).collect();
    assert_eq!(exits, [Exit::Left, Exit::Missed, Exit::MaxSteps]);
    for r in &results {
        let w = r.to_words();
        let back = TraceResult::from_words(&w).unwrap();
        assert_eq!(back.to_words().map(f64::to_bits), w.map(f64::to_bits));
        assert_eq!(back, *r);
    }
    let w = results[0].to_words();
    for (i, v) in [(7, 4.0), (7, 0.5), (7, -1.0), (8, -1.0), (9, 2.5), (10, 5e9), (13, f64::NAN)] {
        let mut b = w;
        b[i] = v;
        assert_eq!(TraceResult::from_words(&b), Err(TraceError::InvalidState), "word {i} = {v}");
    }
}
