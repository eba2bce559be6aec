//! Seeded random numbers and sample sequences.
//!
//! The generator is PCG32 (`rand_pcg`, O'Neill 2014): small state, good
//! statistics, and independent *streams*, which is what makes images
//! deterministic at any thread count: each pixel (or photon batch) gets its
//! own stream derived from the seed, so no work item depends on which thread
//! ran it or in what order.

use glam::Vec2;
use rand_core::{Rng as _, SeedableRng as _};

/// The crate's random number generator.
pub type Rng = rand_pcg::Pcg32;

/// A generator for work item `index` of a computation seeded by `seed`:
/// independent streams, identical for the same `(seed, index)` on every run.
#[must_use]
pub fn rng_for(seed: u64, index: u64) -> Rng {
    rand_pcg::Pcg32::new(mix64(seed ^ 0x9e37_79b9_7f4a_7c15), index)
}

/// A generator from a 64-bit seed alone.
#[must_use]
pub fn rng_from_seed(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// A uniform `f32` in `[0, 1)` with 24 random bits.
#[inline]
pub fn uniform(rng: &mut Rng) -> f32 {
    (rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// A uniform `f64` in `[0, 1)` with 53 random bits.
#[inline]
pub fn uniform_f64(rng: &mut Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A uniform point in `[0, 1)²`.
#[inline]
pub fn uniform2(rng: &mut Rng) -> Vec2 {
    let x = uniform(rng);
    Vec2::new(x, uniform(rng))
}

/// SplitMix64's finaliser: a bijective 64-bit mixer (Steele et al. 2014).
#[inline]
#[must_use]
pub const fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Sample `index` of an `nx × ny` jittered stratification of `[0, 1)²`:
/// one uniform point in each cell, cells in row-major order. Indices past
/// `nx·ny` wrap.
///
/// # Panics
/// If `nx` or `ny` is zero (a programming error).
pub fn stratified2(index: u32, nx: u32, ny: u32, rng: &mut Rng) -> Vec2 {
    assert!(nx > 0 && ny > 0, "stratified2 needs a non-empty grid");
    let i = index % (nx * ny);
    let cell = Vec2::new((i % nx) as f32, (i / nx) as f32);
    let p = (cell + uniform2(rng)) / Vec2::new(nx as f32, ny as f32);
    // Rounding can land exactly on 1; keep the half-open interval.
    p.min(Vec2::splat(ONE_MINUS_EPS))
}

/// The largest f32 below 1.
pub const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// Van der Corput radical inverse of `i` in base 2 (bit reversal), in `[0, 1)`.
#[inline]
#[must_use]
pub fn radical_inverse2(i: u32) -> f32 {
    (i.reverse_bits() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// Radical inverse of `i` in base 3, in `[0, 1)`.
#[must_use]
pub fn radical_inverse3(mut i: u32) -> f32 {
    let mut f = 1.0f64 / 3.0;
    let mut r = 0.0f64;
    while i > 0 {
        r += f64::from(i % 3) * f;
        i /= 3;
        f /= 3.0;
    }
    (r as f32).min(ONE_MINUS_EPS)
}

/// Point `i` of the 2-D Halton sequence (bases 2 and 3) shifted by
/// `rotation` modulo 1 (Cranley–Patterson), so each pixel gets a
/// decorrelated copy of the same low-discrepancy set.
#[must_use]
pub fn halton2(i: u32, rotation: Vec2) -> Vec2 {
    let p = Vec2::new(radical_inverse2(i), radical_inverse3(i)) + rotation;
    wrap01(p)
}

/// Point `i` of Roberts' R2 sequence (the generalised golden ratio), shifted
/// by `rotation` modulo 1: low discrepancy for any number of points, not
/// just powers of the bases.
#[must_use]
pub fn r2(i: u32, rotation: Vec2) -> Vec2 {
    // 1/φ₂ and 1/φ₂², φ₂ the plastic number, in 0.32 fixed point so the
    // sequence stays exact for every index.
    const A1: u32 = 3_242_174_889; // 0.754877666... · 2³²
    const A2: u32 = 2_447_445_414; // 0.569840290... · 2³²
    let x = A1.wrapping_mul(i).wrapping_add(0x8000_0000);
    let y = A2.wrapping_mul(i).wrapping_add(0x8000_0000);
    let p = Vec2::new((x >> 8) as f32, (y >> 8) as f32) * (1.0 / (1u32 << 24) as f32);
    wrap01(p + rotation)
}

fn wrap01(p: Vec2) -> Vec2 {
    let f = |x: f32| {
        let y = x - crate::math::floor(x);
        if y < 1.0 { y } else { 0.0 }
    };
    Vec2::new(f(p.x), f(p.y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_seed_same_stream_different_index_different_stream() {
        let mut r1 = rng_for(42, 7);
        let mut r2_ = rng_for(42, 7);
        let mut r3 = rng_for(42, 8);
        let s1: [u32; 8] = core::array::from_fn(|_| r1.next_u32());
        let s2: [u32; 8] = core::array::from_fn(|_| r2_.next_u32());
        let s3: [u32; 8] = core::array::from_fn(|_| r3.next_u32());
        assert_eq!(s1, s2);
        assert_ne!(s1, s3);
    }

    #[test]
    fn uniform_is_half_open_and_mean_half() {
        let mut r = rng_from_seed(1);
        let mut sum = 0.0f64;
        for _ in 0..100_000 {
            let u = uniform(&mut r);
            assert!((0.0..1.0).contains(&u));
            sum += f64::from(u);
        }
        assert!((sum / 100_000.0 - 0.5).abs() < 0.005);
    }

    #[test]
    fn stratified_puts_one_point_per_cell() {
        let mut r = rng_from_seed(3);
        let mut seen = [false; 12];
        for i in 0..12 {
            let p = stratified2(i, 4, 3, &mut r);
            let c = (p.x * 4.0) as usize + 4 * (p.y * 3.0) as usize;
            assert!(!seen[c]);
            seen[c] = true;
        }
    }

    #[test]
    fn low_discrepancy_sequences_fill_boxes_evenly() {
        // Star discrepancy proxy: counts in a 4×4 grid of 256 points differ
        // from 16 by at most a few, far less than uniform random would.
        for seq in [halton2 as fn(u32, Vec2) -> Vec2, r2] {
            let mut counts = [0i32; 16];
            for i in 0..256 {
                let p = seq(i, Vec2::ZERO);
                assert!((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y));
                counts[(p.x * 4.0) as usize + 4 * (p.y * 4.0) as usize] += 1;
            }
            assert!(counts.iter().all(|&c| (c - 16).abs() <= 3), "{counts:?}");
        }
        assert_eq!(radical_inverse2(1), 0.5);
        assert!((radical_inverse3(1) - 1.0 / 3.0).abs() < 1e-7);
        assert!((radical_inverse3(5) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-7);
    }
}
