//! Helpers shared by the integration tests and the MPI self-test example
//! (which includes this file with `#[path]`): a seeded image generator,
//! bitwise pixel comparison, and `composite` run on a group of threads.
#![allow(dead_code, reason = "each test binary and the example use only part of it")]

use core::time::Duration;

use rt_composite::{
    Communicator, CompositeError, Fragment, Operator, Schedule, Stats, ThreadComm, composite,
};
use rt_core::Pixel;

/// What `composite` returns on one rank.
pub(crate) type Outcome<F> = Result<(Option<Vec<F>>, Stats), CompositeError>;

/// A deterministic image: about `active` of the pixels drawn, depths from
/// a small set so that ties between ranks are common, now and then a
/// NaN colour, a `-0.0` colour or depth, an infinite or NaN depth.
pub(crate) fn image(seed: u64, len: usize, active: f64) -> Vec<Pixel> {
    let mut x = seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    (0..len)
        .map(|_| {
            let r = next();
            if (r % 1000) as f64 >= active * 1000.0 {
                return Pixel::BACKGROUND;
            }
            let a = ((r >> 10) % 5) as f32 / 4.0;
            let c = |k: u64| a * ((r >> (20 + 4 * k)) % 16) as f32 / 15.0;
            let depth = match (r >> 40) % 23 {
                0 => f32::INFINITY,
                1 => f32::NAN,
                2 => -0.0,
                d => (d % 4) as f32,
            };
            let mut color = [c(0), c(1), c(2), a];
            if (r >> 50) % 31 == 0 {
                color[1] = f32::NAN;
            }
            if (r >> 55) % 29 == 0 {
                color = [-0.0; 4];
            }
            Pixel { color, depth }
        })
        .collect()
}

/// The pixels' bits, so that NaNs compare equal and `-0.0` differs from
/// `0.0`.
pub(crate) fn bits(p: &[Pixel]) -> Vec<[u32; 5]> {
    p.iter()
        .map(|p| [p.color[0], p.color[1], p.color[2], p.color[3], p.depth].map(f32::to_bits))
        .collect()
}

/// Runs `composite` on `comms.len()` threads, rank `r` with `images[r]`.
pub(crate) fn run_on<C, F>(
    comms: Vec<C>,
    images: &[Vec<F>],
    size: (u32, u32),
    s: Schedule,
    m: &Operator,
) -> Vec<Outcome<F>>
where
    C: Communicator + Send,
    F: Fragment,
{
    std::thread::scope(|scope| {
        let handles: Vec<_> = comms
            .into_iter()
            .zip(images)
            .map(|(c, img)| scope.spawn(move || composite(&c, img, size.0, size.1, s, m)))
            .collect();
        handles.into_iter().map(|h| h.join().expect("no panic")).collect()
    })
}

/// [`run_on`] a [`ThreadComm`] group with a 20 s timeout.
pub(crate) fn run<F: Fragment>(
    images: &[Vec<F>],
    size: (u32, u32),
    s: Schedule,
    m: &Operator,
) -> Vec<Outcome<F>> {
    run_on(ThreadComm::group(images.len(), Duration::from_secs(20)), images, size, s, m)
}
