//! Occlusion across ranks: shadow and ambient-occlusion rays against
//! geometry that is split between ranks by space.
//!
//! Each rank owns the primitives inside its *region* (an [`Aabb`]; regions
//! may touch but their primitives are disjoint) and every rank knows every
//! region. A ray is occluded by the whole scene iff some rank's primitives
//! occlude it, so the answer is the OR over the ranks whose regions the
//! ray's segment `[t_min, t_max]` crosses, and the first rank that blocks
//! it settles it:
//!
//! 1. The owner of the ray tests it against its own primitives first (no
//!    message).
//! 2. If it is still open, the ray is sent to the other ranks whose regions
//!    it crosses, **one at a time, in the order it enters them** (entry `t`,
//!    ties to the lower rank): near blockers are the likely ones, and a
//!    blocked ray is never sent further.
//! 3. A rank answers the queries it received in a round with one bit per
//!    ray, in the next round's message to the asker.
//!
//! Everything travels in [`rounds`](crate::exchange::rounds): per round and
//! peer one message with the answers owed to it and the new queries for
//! it. The answer for each ray is the same whatever the rank count, the
//! regions or the order of the queries, as long as each rank's `test`
//! answers exactly for its own primitives (a watertight BVH does), so a
//! distributed render equals the single-process one bit for bit.
//!
//! A ray travels as eight little-endian `f32`s: origin, direction,
//! `t_min`, `t_max` (32 bytes); an answer costs one bit.

use alloc::{vec, vec::Vec};
use core::fmt;

use rt_core::{Aabb, Ray, glam::Vec3};

use crate::{
    Communicator,
    exchange::{Batch, ExchangeError, ExchangeStats, Reader, rounds},
};

/// Bytes of one ray in a query.
pub const RAY_BYTES: usize = 32;

/// What resolving occlusion cost one rank.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OcclusionStats {
    /// This rank's own rays.
    pub rays: u64,
    /// Of those, blocked by this rank's own primitives (never sent).
    pub blocked_locally: u64,
    /// Of those, blocked by another rank's primitives (what rank-local
    /// occlusion would have missed).
    pub blocked_elsewhere: u64,
    /// Queries this rank sent (a ray sent to two ranks counts twice).
    pub sent: u64,
    /// Queries this rank answered for others.
    pub answered: u64,
    /// The rounds' messages and bytes.
    pub exchange: ExchangeStats,
}

/// Why occlusion could not be resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OcclusionError {
    /// `regions` does not hold one box per rank.
    Regions {
        /// Boxes given.
        given: usize,
        /// Ranks in the communicator.
        ranks: usize,
    },
    /// Rank `from` sent a batch that does not parse (wrong length, answers
    /// for queries never sent, a non-finite ray).
    BadBatch {
        /// The sender.
        from: usize,
    },
}

impl fmt::Display for OcclusionError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Regions { given, ranks } => {
                write!(f, "{given} regions given for {ranks} ranks (one per rank needed)")
            }
            Self::BadBatch { from } => {
                write!(f, "rank {from} sent an occlusion batch that does not parse")
            }
        }
    }
}

impl core::error::Error for OcclusionError {}

/// Appends `ray` as eight little-endian `f32`s.
fn put_ray(out: &mut Vec<u8>, r: &Ray) {
    for v in [
        r.origin.x,
        r.origin.y,
        r.origin.z,
        r.direction.x,
        r.direction.y,
        r.direction.z,
        r.t_min,
        r.t_max,
    ] {
        out.extend(v.to_bits().to_le_bytes());
    }
}

/// A ray read back exactly; `None` if it is not a valid ray.
fn get_ray(r: &mut Reader<'_>) -> Option<Ray> {
    let mut v = [0f32; 8];
    for x in &mut v {
        *x = r.f32()?;
    }
    let ray = Ray::with_range(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]), v[6], v[7]);
    ray.is_valid().then_some(ray)
}

/// Whether each of `rays` is occluded by the scene spread over the ranks
/// of `comm`, on every rank at once: rank `r` owns the primitives inside
/// `regions[r]` and `test(rays, out)` sets `out[i]` to whether *its own*
/// primitives occlude `rays[i]` (`out` comes in all `false`; a batch may
/// be tested in parallel). At most `batch` new queries leave a rank per
/// round, which bounds its message buffers.
///
/// Every rank must call this with the same `regions`; each passes its own
/// rays (any number, possibly none).
///
/// # Errors
/// [`ExchangeError`] on every rank when any rank fails, a peer stops
/// answering (the communicator's timeout), or a batch is malformed.
pub fn resolve_occlusion<C: Communicator + ?Sized>(
    comm: &C,
    regions: &[Aabb],
    rays: &[Ray],
    batch: usize,
    mut test: impl FnMut(&[Ray], &mut [bool]),
) -> Result<(Vec<bool>, OcclusionStats), ExchangeError<OcclusionError>> {
    let (me, size) = (comm.rank(), comm.size());
    if regions.len() != size {
        return Err(ExchangeError::Step(OcclusionError::Regions {
            given: regions.len(),
            ranks: size,
        }));
    }
    let batch = batch.max(1);
    let mut stats = OcclusionStats { rays: rays.len() as u64, ..OcclusionStats::default() };
    // Each ray's route: the other ranks it crosses, in crossing order.
    let mut route: Vec<u32> = Vec::new();
    let mut route_at: Vec<u32> = Vec::with_capacity(rays.len() + 1);
    let mut crossed: Vec<(f32, u32)> = Vec::new();
    let mut local: Vec<bool> = Vec::with_capacity(rays.len());
    for ray in rays {
        route_at.push(route.len() as u32);
        crossed.clear();
        let mut mine = false;
        for (r, region) in regions.iter().enumerate() {
            if let Some((t0, _)) = region.intersect_ray(ray) {
                if r == me {
                    mine = true;
                } else {
                    crossed.push((t0, r as u32));
                }
            }
        }
        crossed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        route.extend(crossed.iter().map(|c| c.1));
        local.push(mine);
    }
    route_at.push(route.len() as u32);
    // Step 1: this rank's own primitives, all rays in one call.
    let mut occluded = vec![false; rays.len()];
    let to_test: Vec<usize> = (0..rays.len()).filter(|&i| local[i]).collect();
    if !to_test.is_empty() {
        let subset: Vec<Ray> = to_test.iter().map(|&i| rays[i]).collect();
        let mut bits = vec![false; subset.len()];
        test(&subset, &mut bits);
        for (&i, &b) in to_test.iter().zip(&bits) {
            occluded[i] = b;
        }
    }
    stats.blocked_locally = occluded.iter().filter(|&&b| b).count() as u64;
    // Per ray: the index of the next hop on its route.
    let mut hop: Vec<u32> = vec![0; rays.len()];
    // Open rays not yet sent anywhere, and those awaiting each peer.
    let mut ready: Vec<usize> = (0..rays.len()).filter(|&i| !occluded[i]).rev().collect();
    // Queries sent to each peer in the last two rounds, by round parity:
    // those sent in round `r` are answered in the peer's message of round
    // `r + 1`, which this rank reads in round `r + 2`.
    let mut waiting: Vec<[Vec<usize>; 2]> = vec![[Vec::new(), Vec::new()]; size];
    let mut open = ready.len();
    // Queries received this round (answered in this round's messages),
    // and how many came from each peer.
    let mut received: Vec<Ray> = Vec::new();
    let mut counts: Vec<usize> = vec![0; size];
    let step = |round: u32, inbox: &[Batch], outbox: &mut [Vec<u8>]| {
        let parity = (round % 2) as usize;
        // Answers to our queries, then queries from the others.
        received.clear();
        for (from, b) in inbox.iter().enumerate() {
            counts[from] = 0;
            let bad = || OcclusionError::BadBatch { from };
            if b.bytes.is_empty() {
                if waiting[from][parity].is_empty() {
                    continue;
                }
                return Err(bad());
            }
            let mut r = Reader::new(&b.bytes);
            let answers = r.u32().ok_or_else(bad)? as usize;
            if answers != waiting[from][parity].len() {
                return Err(bad());
            }
            let bits = r.take(answers.div_ceil(8)).ok_or_else(bad)?;
            for (k, i) in waiting[from][parity].drain(..).enumerate() {
                if bits[k / 8] >> (k % 8) & 1 == 1 {
                    occluded[i] = true;
                    stats.blocked_elsewhere += 1;
                    open -= 1;
                } else {
                    hop[i] += 1;
                    ready.push(i);
                }
            }
            let queries = r.u32().ok_or_else(bad)? as usize;
            if queries.checked_mul(RAY_BYTES) != Some(b.bytes.len() - 4 - answers.div_ceil(8) - 4) {
                return Err(bad());
            }
            for _ in 0..queries {
                received.push(get_ray(&mut r).ok_or_else(bad)?);
            }
            if !r.is_empty() {
                return Err(bad());
            }
            counts[from] = queries;
        }
        let mut answers = vec![false; received.len()];
        if !received.is_empty() {
            test(&received, &mut answers);
            stats.answered += received.len() as u64;
        }
        // New queries: each open ray to the next rank on its route, or
        // settled as open when the route is done.
        let mut new: Vec<Vec<usize>> = vec![Vec::new(); size];
        let mut sent = 0;
        while sent < batch {
            let Some(i) = ready.pop() else { break };
            let at = (route_at[i] + hop[i]) as usize;
            if at >= route_at[i + 1] as usize {
                open -= 1;
                continue;
            }
            new[route[at] as usize].push(i);
            sent += 1;
        }
        stats.sent += sent as u64;
        let mut at = 0;
        for (peer, out) in outbox.iter_mut().enumerate() {
            let answers = &answers[at..at + counts[peer]];
            at += counts[peer];
            if answers.is_empty() && new[peer].is_empty() {
                continue;
            }
            out.extend((answers.len() as u32).to_le_bytes());
            let mut bytes = vec![0u8; answers.len().div_ceil(8)];
            for (k, &b) in answers.iter().enumerate() {
                bytes[k / 8] |= u8::from(b) << (k % 8);
            }
            out.extend(bytes);
            out.extend((new[peer].len() as u32).to_le_bytes());
            for &i in &new[peer] {
                put_ray(out, &rays[i]);
            }
            waiting[peer][parity] = core::mem::take(&mut new[peer]);
        }
        Ok(open > 0)
    };
    // Every hop is two rounds (query, answer); a ray crosses at most
    // `size − 1` other regions, and `batch` limits how many start a round.
    let max_rounds =
        u32::try_from(2 * size + 2 + rays.len().div_ceil(batch) * 2 * size).unwrap_or(u32::MAX);
    stats.exchange = rounds(comm, max_rounds.max(64), step)?;
    Ok((occluded, stats))
}
