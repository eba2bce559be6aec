//! Operators, sparse images and every schedule against the serial fold,
//! bit for bit; collective errors without hangs.

mod support;

use core::time::Duration;

use proptest::prelude::*;
use rt_composite::{
    CommError, Communicator, CompositeError, DecodeError, Fragment, Operator, Pixel8, Schedule,
    SparseImage, ThreadComm, composite, serial_fold,
};
use rt_core::Pixel;
use support::{bits, image, run, run_on};

fn fold<F: Fragment>(images: &[Vec<F>], m: &Operator) -> Vec<F> {
    let refs: Vec<&[F]> = images.iter().map(Vec::as_slice).collect();
    serial_fold(&refs, m).unwrap()
}

#[test]
fn background_is_an_exact_identity_of_both_operators() {
    for p in image(3, 200, 1.0).into_iter().chain([Pixel { color: [-0.0; 4], depth: 1.0 }]) {
        let bg = Pixel::BACKGROUND;
        assert_eq!(bits(&[p.z(bg), bg.z(p), p.over(bg), bg.over(p)]), bits(&[p; 4]));
        let q = Pixel8::from_pixel(p);
        let b8 = Pixel8::BACKGROUND;
        assert_eq!([q.z(b8), b8.z(q), q.over(b8), b8.over(q)], [q; 4]);
    }
}

#[test]
fn z_fold_is_the_nearest_fragment_with_ties_to_the_lower_rank() {
    // Against a direct argmin over (depth, rank), NaN depth as +∞.
    let images: Vec<Vec<Pixel>> = (0..7).map(|r| image(r, 500, 0.6)).collect();
    let folded = fold(&images, &Operator::Depth);
    for (i, got) in folded.iter().enumerate() {
        let key = |p: &Pixel| if p.depth.is_nan() { f32::INFINITY } else { p.depth };
        let best = images
            .iter()
            .map(|img| img[i])
            .filter(|p| !p.is_background())
            .enumerate()
            .min_by(|(ra, a), (rb, b)| key(a).partial_cmp(&key(b)).unwrap().then(ra.cmp(rb)))
            .map_or(Pixel::BACKGROUND, |(_, p)| p);
        assert_eq!(bits(&[*got]), bits(&[best]), "pixel {i}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn z_is_associative_and_commutative_over_rank_pairs(seed in any::<u64>()) {
        let v = image(seed, 3, 0.9);
        let (a, b, c) = (v[0], v[1], v[2]);
        // Ranks 0 < 1 < 2: any bracketing of the ordered sequence agrees.
        prop_assert_eq!(bits(&[a.z(b).z(c)]), bits(&[a.z(b.z(c))]));
        // Commutative on (pixel, rank): the operand of lower rank goes first.
        let zr = |(p, r): (Pixel, u32), (q, s): (Pixel, u32)| if r < s { p.z(q) } else { q.z(p) };
        prop_assert_eq!(bits(&[zr((a, 0), (b, 1))]), bits(&[zr((b, 1), (a, 0))]));
    }

    #[test]
    fn over_is_associative_up_to_rounding(seed in any::<u64>()) {
        let v: Vec<Pixel> = image(seed, 3, 1.0)
            .into_iter()
            .map(|p| Pixel { color: p.color.map(|c| if c.is_nan() { 0.5 } else { c.abs() }), depth: 1.0 })
            .collect();
        let (a, b, c) = (v[0], v[1], v[2]);
        let (l, r) = (a.over(b).over(c), a.over(b.over(c)));
        for k in 0..4 {
            prop_assert!((l.color[k] - r.color[k]).abs() <= 1e-6, "{l:?} {r:?}");
        }
        // 8-bit over stays within two steps of the f32 result.
        let q = |p: Pixel| Pixel8::from_pixel(p);
        let eight = q(a).over(q(b)).over(q(c)).to_pixel();
        for k in 0..4 {
            prop_assert!((eight.color[k] - l.color[k].min(1.0)).abs() <= 3.0 / 255.0);
        }
    }

    #[test]
    fn sparse_images_match_their_dense_form(seed in any::<u64>(), len in 0usize..300, active in 0.0f64..1.0) {
        let a = image(seed, len, active);
        let b = image(seed ^ 0xabc, len, active);
        let sa = SparseImage::encode(5, &a);
        prop_assert_eq!(sa.active_count(), a.iter().filter(|p| !p.is_background()).count());
        let mut dense = vec![Pixel { color: [9.0; 4], depth: 9.0 }; len + 5];
        sa.write_into(&mut dense);
        prop_assert_eq!(bits(&dense[5..]), bits(&a));
        let (lo, hi) = (5 + len / 3, 5 + len * 2 / 3);
        // Compared as bytes: NaN colours are not equal to themselves.
        prop_assert_eq!(
            sa.slice(lo..hi).to_bytes(),
            SparseImage::encode(lo, &a[lo - 5..hi - 5]).to_bytes()
        );
        let z = sa.combine(&SparseImage::encode(5, &b), Fragment::z).unwrap();
        let dz: Vec<Pixel> = a.iter().zip(&b).map(|(p, q)| p.z(*q)).collect();
        prop_assert_eq!(z.to_bytes(), SparseImage::encode(5, &dz).to_bytes());
        prop_assert!(sa.combine(&SparseImage::encode(4, &b), Fragment::z).is_none());
        let round = SparseImage::<Pixel>::from_bytes(&z.to_bytes()).unwrap();
        prop_assert_eq!(bits(&{ let mut d = vec![Pixel::BACKGROUND; len + 5]; round.write_into(&mut d); d }),
            bits(&{ let mut d = vec![Pixel::BACKGROUND; len + 5]; z.write_into(&mut d); d }));
    }

    #[test]
    fn decoding_any_bytes_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
        let _ = SparseImage::<Pixel>::from_bytes(&bytes);
        let _ = SparseImage::<Pixel8>::from_bytes(&bytes);
    }
}

#[test]
fn truncated_and_padded_encodings_are_errors() {
    let s = SparseImage::encode(0, &image(1, 100, 0.5));
    let b = s.to_bytes();
    for cut in [0, 3, 19, 20, 27, b.len() - 1] {
        assert_eq!(
            SparseImage::<Pixel>::from_bytes(&b[..cut]).unwrap_err(),
            DecodeError::Truncated,
            "cut {cut}"
        );
    }
    let mut long = b.clone();
    long.push(0);
    assert_eq!(SparseImage::<Pixel>::from_bytes(&long).unwrap_err(), DecodeError::TrailingBytes);
    let mut lie = b;
    lie[8] ^= 1; // the span's length no longer matches the runs
    assert_eq!(SparseImage::<Pixel>::from_bytes(&lie).unwrap_err(), DecodeError::Inconsistent);
}

/// Every schedule, every rank count 1–16, sizes not divisible by the rank
/// count and 1×1: rank 0's image equals the serial fold bit for bit.
#[test]
fn every_schedule_equals_the_serial_fold() {
    let schedules = [
        Schedule::DirectSend,
        Schedule::BinarySwap,
        Schedule::RadixK(2),
        Schedule::RadixK(3),
        Schedule::RadixK(4),
        Schedule::RadixK(16),
    ];
    for n in 1..=16usize {
        for (w, h) in [(1u32, 1u32), (7, 3), (13, 11)] {
            let active = [0.05, 0.5, 1.0][n % 3];
            let images: Vec<Vec<Pixel>> =
                (0..n).map(|r| image((n * 100 + r) as u64, (w * h) as usize, active)).collect();
            let expected = bits(&fold(&images, &Operator::Depth));
            for s in schedules {
                let out = run(&images, (w, h), s, &Operator::Depth);
                for (r, o) in out.into_iter().enumerate() {
                    let (img, _) = o.unwrap_or_else(|e| panic!("{n} ranks {w}×{h} {s:?}: {e}"));
                    match img {
                        Some(img) => {
                            assert_eq!(r, 0);
                            assert_eq!(bits(&img), expected, "{n} ranks {w}×{h} {s:?}");
                        }
                        None => assert_ne!(r, 0),
                    }
                }
            }
        }
    }
}

#[test]
fn ordered_over_and_eight_bit_pixels_equal_the_serial_fold() {
    for n in [1usize, 2, 5, 8, 13] {
        let (w, h) = (9u32, 5u32);
        let images: Vec<Vec<Pixel>> = (0..n).map(|r| image(r as u64 + 77, 45, 0.7)).collect();
        // Visibility order: a rotation and reversal of the ranks.
        let order: Vec<usize> = (0..n).map(|i| (n - 1 - i + 2) % n).collect();
        let m = Operator::Over { order };
        let out = run(&images, (w, h), Schedule::DirectSend, &m);
        assert_eq!(bits(&out[0].as_ref().unwrap().0.clone().unwrap()), bits(&fold(&images, &m)));

        let eight: Vec<Vec<Pixel8>> =
            images.iter().map(|i| i.iter().map(|p| Pixel8::from_pixel(*p)).collect()).collect();
        for s in [Schedule::BinarySwap, Schedule::RadixK(3)] {
            let out = run(&eight, (w, h), s, &Operator::Depth);
            assert_eq!(
                out[0].as_ref().unwrap().0.as_deref(),
                Some(&fold(&eight, &Operator::Depth)[..])
            );
        }
    }
}

/// `-0.0` colour at `+∞` over `+0.0` colour at NaN depth is `+0.0` at
/// `+∞`: the background, made from two active pixels. The result must be
/// stored as background (the gather's decoder rejects a stored one) and
/// still equal the serial fold, on both the in-place (same runs) and the
/// general path.
#[test]
fn an_over_that_makes_the_background_is_encoded_as_background() {
    let a = Pixel { color: [-0.0; 4], depth: f32::INFINITY };
    let b = Pixel { color: [0.0; 4], depth: f32::NAN };
    assert!(!a.is_background() && !b.is_background() && a.over(b).is_background());
    let c = Pixel { color: [0.5; 4], depth: 1.0 };
    for images in [
        vec![vec![a, a, c, a], vec![b, b, c, b]], // same runs: in place
        vec![vec![a, a, c, a], vec![b, Pixel::BACKGROUND, c, b]],
    ] {
        let sparse: Vec<SparseImage<Pixel>> =
            images.iter().map(|i| SparseImage::encode(0, i)).collect();
        let combined = sparse[0].combine(&sparse[1], Pixel::over).unwrap();
        assert!(SparseImage::<Pixel>::from_bytes(&combined.to_bytes()).is_ok());
        let mode = Operator::Over { order: vec![0, 1] };
        let expected = bits(&fold(&images, &mode));
        for (r, o) in run(&images, (2, 2), Schedule::DirectSend, &mode).into_iter().enumerate() {
            let (img, _) = o.unwrap_or_else(|e| panic!("rank {r}: {e}"));
            if let Some(img) = img {
                assert_eq!(bits(&img), expected);
                assert!(img[0].is_background());
            }
        }
    }
}

#[test]
fn background_is_never_sent() {
    // Eight ranks of 64×64 with nothing drawn: messages carry headers only.
    let images = vec![vec![Pixel::BACKGROUND; 64 * 64]; 8];
    for s in [Schedule::DirectSend, Schedule::BinarySwap, Schedule::RadixK(4)] {
        let sent: usize = run(&images, (64, 64), s, &Operator::Depth)
            .into_iter()
            .map(|o| o.unwrap().1.bytes_sent)
            .sum();
        assert!(sent < 8 * 20 * 64, "{s:?}: {sent} bytes");
    }
}

/// Wraps a communicator and cuts the end off every message it sends.
struct Truncating(ThreadComm);

impl Communicator for Truncating {
    fn rank(&self) -> usize {
        self.0.rank()
    }
    fn size(&self) -> usize {
        self.0.size()
    }
    fn send(&self, to: usize, tag: u32, mut data: Vec<u8>) -> Result<(), CommError> {
        data.truncate(data.len().saturating_sub(3));
        self.0.send(to, tag, data)
    }
    fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError> {
        self.0.recv(from, tag)
    }
}

enum Either {
    Plain(ThreadComm),
    Cut(Truncating),
}

impl Communicator for Either {
    fn rank(&self) -> usize {
        match self {
            Self::Plain(c) => c.rank(),
            Self::Cut(c) => c.rank(),
        }
    }
    fn size(&self) -> usize {
        match self {
            Self::Plain(c) => c.size(),
            Self::Cut(c) => c.size(),
        }
    }
    fn send(&self, to: usize, tag: u32, data: Vec<u8>) -> Result<(), CommError> {
        match self {
            Self::Plain(c) => c.send(to, tag, data),
            Self::Cut(c) => c.send(to, tag, data),
        }
    }
    fn recv(&self, from: usize, tag: u32) -> Result<Vec<u8>, CommError> {
        match self {
            Self::Plain(c) => c.recv(from, tag),
            Self::Cut(c) => c.recv(from, tag),
        }
    }
}

#[test]
fn a_failure_anywhere_is_an_err_everywhere_without_hanging() {
    let t = Duration::from_secs(10);
    for s in [Schedule::DirectSend, Schedule::BinarySwap, Schedule::RadixK(3)] {
        for n in [2usize, 5, 8] {
            let images: Vec<Vec<Pixel>> = (0..n).map(|r| image(r as u64, 35, 0.8)).collect();
            // One rank's image is of another size.
            let mut wrong = images.clone();
            wrong[n - 1] = image(1, 36, 0.8);
            let sizes_ok = run(&wrong, (7, 5), s, &Operator::Depth);
            assert!(sizes_ok.iter().all(Result::is_err), "{s:?} {n}: {sizes_ok:?}");
            // One rank says 6×6 where the others say 7×5 (same pixel count
            // as its own image).
            let comms = ThreadComm::group(n, t);
            let out: Vec<_> = std::thread::scope(|scope| {
                let hs: Vec<_> = comms
                    .into_iter()
                    .zip(&images)
                    .enumerate()
                    .map(|(r, (c, img))| {
                        scope.spawn(move || {
                            let size = if r == 1 { (5, 7) } else { (7, 5) };
                            composite(&c, img, size.0, size.1, s, &Operator::Depth)
                        })
                    })
                    .collect();
                hs.into_iter().map(|h| h.join().expect("no panic")).collect()
            });
            assert!(out.iter().all(Result::is_err), "{s:?} {n}: {out:?}");
            // One rank truncates everything it sends.
            let comms: Vec<Either> =
                ThreadComm::group(n, t)
                    .into_iter()
                    .map(|c| {
                        if c.rank() == n / 2 {
                            Either::Cut(Truncating(c))
                        } else {
                            Either::Plain(c)
                        }
                    })
                    .collect();
            let out = run_on(comms, &images, (7, 5), s, &Operator::Depth);
            assert!(out.iter().all(Result::is_err), "{s:?} {n}: {out:?}");
        }
    }
    // A rank that never shows up: the others time out with an Err.
    let mut comms = ThreadComm::group(4, Duration::from_millis(300));
    drop(comms.pop());
    let images: Vec<Vec<Pixel>> = (0..3).map(|r| image(r, 16, 0.5)).collect();
    let out = run_on(comms, &images, (4, 4), Schedule::BinarySwap, &Operator::Depth);
    assert!(out.iter().all(Result::is_err), "{out:?}");
    // Bad arguments are errors on every rank too.
    let images: Vec<Vec<Pixel>> = (0..4).map(|r| image(r, 16, 0.5)).collect();
    let over = Operator::Over { order: vec![3, 2, 1, 0] };
    for (s, m, e) in [
        (Schedule::BinarySwap, over.clone(), CompositeError::OverNeedsDirectSend),
        (
            Schedule::DirectSend,
            Operator::Over { order: vec![0, 0, 1, 2] },
            CompositeError::BadOrder,
        ),
        (Schedule::RadixK(1), Operator::Depth, CompositeError::BadRadix(1)),
    ] {
        for o in run(&images, (4, 4), s, &m) {
            assert_eq!(o.unwrap_err(), e);
        }
    }
}
