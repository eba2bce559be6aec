//! Stress cases for compositing: all-equal depths, depths one ulp apart at
//! every magnitude from 1e-8 to 1e8, ±∞ and NaN depths, NaN colours,
//! extreme alphas. Every schedule must give exactly the documented answer
//! (not merely the serial fold's), on every rank count.

mod support;

use rt_composite::{Fragment, Operator, Schedule};
use rt_core::Pixel;
use support::bits;

const SCHEDULES: [Schedule; 4] =
    [Schedule::DirectSend, Schedule::BinarySwap, Schedule::RadixK(3), Schedule::RadixK(4)];

/// Rank 0's composited image for `images` (one per rank), `w × h`.
fn run(images: &[Vec<Pixel>], w: u32, h: u32, s: Schedule, m: &Operator) -> Vec<Pixel> {
    let out = support::run(images, (w, h), s, m);
    let mut first = None;
    for (r, o) in out.into_iter().enumerate() {
        let (img, _) = o.unwrap_or_else(|e| panic!("rank {r} {s:?}: {e}"));
        if r == 0 {
            first = img;
        }
    }
    first.expect("rank 0 has the image")
}

/// Every rank draws every pixel at exactly the same depth, in its own
/// colour: ties go to the lower rank, so the result is rank 0's image.
#[test]
fn all_equal_depths_give_rank_zero_everywhere() {
    for n in [2usize, 3, 5, 8, 13] {
        let (w, h) = (9u32, 7u32);
        let images: Vec<Vec<Pixel>> = (0..n)
            .map(|r| {
                (0..w * h)
                    .map(|i| Pixel {
                        color: [r as f32 / n as f32, 0.5, 0.25, 1.0],
                        depth: (i % 3) as f32,
                    })
                    .collect()
            })
            .collect();
        for s in SCHEDULES {
            assert_eq!(
                bits(&run(&images, w, h, s, &Operator::Depth)),
                bits(&images[0]),
                "{n} {s:?}"
            );
        }
    }
}

/// Depths one ulp apart at every magnitude 1e-8 … 1e8 (positive and
/// negative): each pixel goes to the rank holding the smallest depth,
/// exactly, whichever rank that is.
#[test]
fn depths_one_ulp_apart_at_every_magnitude() {
    let n = 6usize;
    let mags: Vec<f32> = (-8..=8).map(|k| 10f32.powi(k)).flat_map(|m| [m, -m]).collect();
    let len = mags.len();
    // Rank r at pixel i: the magnitude moved up by ((r + i) % n) ulps, so
    // the winner rotates with i.
    let up = |x: f32, k: usize| (0..k).fold(x, |v, _| v.next_up());
    let images: Vec<Vec<Pixel>> = (0..n)
        .map(|r| {
            (0..len)
                .map(|i| Pixel {
                    color: [r as f32, 0.0, 0.0, 1.0],
                    depth: up(mags[i], (r + i) % n),
                })
                .collect()
        })
        .collect();
    for s in SCHEDULES {
        let out = run(&images, len as u32, 1, s, &Operator::Depth);
        for (i, p) in out.iter().enumerate() {
            let winner = (0..n).find(|r| (r + i) % n == 0).expect("some rank has 0 ulps");
            assert_eq!(p.color[0], winner as f32, "{s:?} pixel {i} ({:e})", mags[i]);
            assert_eq!(p.depth, mags[i]);
        }
    }
}

/// −∞ beats everything, +∞ with colour beats only the background, NaN
/// depth counts as +∞ (ties to the lower rank), and a NaN colour is
/// carried through untouched.
#[test]
fn infinite_and_nan_depths_and_nan_colours() {
    let c = |r: f32| [r, f32::NAN, 0.5, 1.0];
    // Per pixel: the depth of each of 4 ranks, and the winner.
    let cases: [([f32; 4], usize); 6] = [
        ([1.0, f32::NEG_INFINITY, 0.0, -1e30], 1),
        ([f32::INFINITY, f32::NAN, 5.0, f32::INFINITY], 2),
        ([f32::NAN, f32::INFINITY, f32::NAN, f32::NAN], 0),
        ([f32::NAN, f32::NAN, f32::NAN, -0.0], 3),
        ([0.0, -0.0, 0.0, -0.0], 0),
        ([f32::MAX, f32::MIN_POSITIVE, 1e-45, f32::MIN_POSITIVE], 2),
    ];
    let images: Vec<Vec<Pixel>> = (0..4)
        .map(|r| cases.iter().map(|(d, _)| Pixel { color: c(r as f32), depth: d[r] }).collect())
        .collect();
    for s in SCHEDULES {
        let out = run(&images, cases.len() as u32, 1, s, &Operator::Depth);
        for (i, (p, (d, winner))) in out.iter().zip(&cases).enumerate() {
            assert_eq!(p.color[0], *winner as f32, "{s:?} case {i}");
            assert_eq!(p.depth.to_bits(), d[*winner].to_bits(), "{s:?} case {i}");
            assert!(p.color[1].is_nan(), "the NaN colour was not carried");
        }
    }
}

/// Ordered `over` of 16 layers with alphas from subnormal to 1: for valid
/// premultiplied input (colour ≤ alpha ≤ 1) every channel stays in
/// `[0, 1]`, alpha never decreases as layers are added, an opaque front
/// layer hides everything behind it exactly.
#[test]
fn over_with_extreme_alphas_stays_in_range() {
    let alphas = [1e-45f32, 1e-38, 1e-8, 1e-3, 0.5, 0.999_999, 1.0, 0.0];
    let n = 16usize;
    let images: Vec<Vec<Pixel>> = (0..n)
        .map(|r| {
            (0..alphas.len())
                .map(|i| {
                    let a = alphas[(i + r) % alphas.len()];
                    Pixel { color: [a, a * 0.5, 0.0, a], depth: r as f32 }
                })
                .collect()
        })
        .collect();
    let order: Vec<usize> = (0..n).collect();
    let out = run(&images, alphas.len() as u32, 1, Schedule::DirectSend, &Operator::Over { order });
    for (i, p) in out.iter().enumerate() {
        assert!(p.color.iter().all(|v| (0.0..=1.0).contains(v)), "pixel {i}: {p:?}");
        let front = images[0][i];
        assert!(p.color[3] >= front.color[3], "pixel {i}: alpha fell");
        if front.color[3] == 1.0 {
            assert_eq!(p.color, front.color, "pixel {i}: the opaque front layer was not kept");
        }
    }
    // The background is exact identity even next to subnormal alphas.
    let tiny = Pixel { color: [1e-45, 0.0, 0.0, 1e-45], depth: 3.0 };
    assert_eq!(tiny.over(Pixel::BACKGROUND), tiny);
    assert_eq!(Pixel::BACKGROUND.over(tiny), tiny);
}
