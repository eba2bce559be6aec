//! Streams: many independent rays traced in one loop, a few at a time.
//!
//! A single ray's traversal is one long chain of dependent steps: load a
//! node, test its boxes, pick a child, load that child. Each step waits for
//! the one before, so most of a core's execution units sit idle (measured:
//! ~45 cycles per node on the terrain, whether the nodes are in L1 or not).
//! A stream keeps [`STREAM`] rays in flight and advances each by one step
//! in turn, so the chains of different rays overlap in the core's
//! out-of-order window; a ray that finishes hands its lane to the next ray
//! of the stream. Every ray runs exactly its single-ray traversal (the same
//! steps, the same arithmetic), so its answer equals the single-ray query
//! bit for bit; only the order in which answers are reported differs.

use rt_core::Ray;

use crate::{
    Isa, RayCtx,
    node::ChildRef,
    prim::{BestHit, Primitive},
    traverse::{BvhRef, Step, TraversalStack, TraversalStats, Walk},
};

/// Rays a stream keeps in flight.
pub const STREAM: usize = 4;

/// A ray in flight: its constants, where its traversal stands, and its
/// index in the stream.
struct Lane {
    ctx: RayCtx,
    walk: Walk,
    index: usize,
}

/// The next valid ray of `rays` from `*next` on, as a lane at the root;
/// invalid rays on the way are answered `miss(i)`.
#[inline(always)]
fn next_lane(rays: &[Ray], next: &mut usize, mut miss: impl FnMut(usize)) -> Option<Lane> {
    while let Some(ray) = rays.get(*next) {
        let index = *next;
        *next += 1;
        match RayCtx::new(ray) {
            Some(ctx) => {
                let walk = Walk { cur: ChildRef::inner(0), sp: 0, best: BestHit::new(ray.t_max) };
                return Some(Lane { ctx, walk, index });
            }
            None => miss(index),
        }
    }
    None
}

impl<P: Primitive> BvhRef<'_, P> {
    /// The closest hit of every ray of `rays`, as
    /// [`BvhRef::closest_t`] finds it (bit for bit), reported as
    /// `out(index, hit)` once per ray, in the order rays finish. Faster
    /// than one query per ray when rays are many: [`STREAM`] traversals
    /// overlap in the core.
    pub fn closest_t_stream(&self, rays: &[Ray], mut out: impl FnMut(usize, Option<BestHit>)) {
        if self.nodes.is_empty() {
            (0..rays.len()).for_each(|i| out(i, None));
            return;
        }
        match self.isa {
            // SAFETY: `self.isa` passed `Isa::is_available` (the field's
            // invariant): the CPU has the features these kernels enable.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.closest_stream_avx512(rays, &mut out) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Isa::Avx2 => unsafe { self.closest_stream_avx2(rays, &mut out) },
            _ => self.closest_stream::<false>(rays, &mut out),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    fn closest_stream_avx2(&self, rays: &[Ray], out: &mut dyn FnMut(usize, Option<BestHit>)) {
        self.closest_stream::<true>(rays, out);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,avx512f,avx512vl")]
    fn closest_stream_avx512(&self, rays: &[Ray], out: &mut dyn FnMut(usize, Option<BestHit>)) {
        self.closest_stream::<true>(rays, out);
    }

    /// The stream kernel of [`BvhRef::closest_t_stream`] (non-empty BVH).
    #[inline(always)]
    fn closest_stream<const AVX: bool>(
        &self,
        rays: &[Ray],
        out: &mut dyn FnMut(usize, Option<BestHit>),
    ) {
        let mut stacks = [const { TraversalStack::new() }; STREAM];
        let mut stats = TraversalStats::default();
        let mut next = 0;
        let mut lanes: [Option<Lane>; STREAM] =
            core::array::from_fn(|_| next_lane(rays, &mut next, |i| out(i, None)));
        loop {
            let mut live = false;
            for (lane, stack) in lanes.iter_mut().zip(&mut stacks) {
                let Some(l) = lane else { continue };
                live = true;
                if !self.closest_step::<AVX>(&l.ctx, &mut l.walk, &mut stats, stack) {
                    let best = l.walk.best;
                    out(l.index, best.is_hit().then_some(best));
                    *lane = next_lane(rays, &mut next, |i| out(i, None));
                }
            }
            if !live {
                return;
            }
        }
    }

    /// Whether each ray of `rays` is occluded, as [`BvhRef::occluded`]
    /// answers, reported as `out(index, occluded)` once per ray, in the
    /// order rays finish; [`STREAM`] traversals overlap in the core.
    pub fn occluded_stream(&self, rays: &[Ray], mut out: impl FnMut(usize, bool)) {
        if self.nodes.is_empty() {
            (0..rays.len()).for_each(|i| out(i, false));
            return;
        }
        match self.isa {
            // SAFETY: as in `closest_t_stream`.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.occluded_stream_avx512(rays, &mut out) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Isa::Avx2 => unsafe { self.occluded_stream_avx2(rays, &mut out) },
            _ => self.occluded_stream_kernel::<false>(rays, &mut out),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2")]
    fn occluded_stream_avx2(&self, rays: &[Ray], out: &mut dyn FnMut(usize, bool)) {
        self.occluded_stream_kernel::<true>(rays, out);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,avx512f,avx512vl")]
    fn occluded_stream_avx512(&self, rays: &[Ray], out: &mut dyn FnMut(usize, bool)) {
        self.occluded_stream_kernel::<true>(rays, out);
    }

    /// The stream kernel of [`BvhRef::occluded_stream`] (non-empty BVH).
    #[inline(always)]
    fn occluded_stream_kernel<const AVX: bool>(
        &self,
        rays: &[Ray],
        out: &mut dyn FnMut(usize, bool),
    ) {
        let mut stacks = [const { TraversalStack::new() }; STREAM];
        let mut next = 0;
        let mut lanes: [Option<Lane>; STREAM] =
            core::array::from_fn(|_| next_lane(rays, &mut next, |i| out(i, false)));
        loop {
            let mut live = false;
            for (lane, stack) in lanes.iter_mut().zip(&mut stacks) {
                let Some(l) = lane else { continue };
                live = true;
                let answer = match self.occluded_step::<AVX>(&l.ctx, &mut l.walk, stack) {
                    Step::Go => continue,
                    Step::Hit => true,
                    Step::Done => false,
                };
                out(l.index, answer);
                *lane = next_lane(rays, &mut next, |i| out(i, false));
            }
            if !live {
                return;
            }
        }
    }
}
