//! Streams: many independent rays traced in one call.
//!
//! A single ray's traversal is one long chain of dependent steps: load a
//! node, test its boxes, pick a child, load that child. Each step waits for
//! the one before, so most of a core's execution units sit idle. Closest
//! hits keep [`STREAM`] rays in flight and advance each by one step in
//! turn, so the chains of different rays overlap in the core's
//! out-of-order window; a ray that finishes hands its lane to the next ray
//! of the stream. On the AVX kernels, runs of [`GROUP`] rays of one
//! direction octant (camera rays along a row, rays toward one light) walk
//! the tree together instead, as occlusion groups do, the nearest subtree
//! first. Occlusion walks the tree with groups of [`GROUP`] rays
//! (as Embree's ray streams do): a node is fetched once for every ray of
//! the group that reaches it, each ray testing it with the single-ray box
//! test, and a subtree is pushed with the rays that entered it.
//!
//! Either way every ray enters exactly the subtrees its single-ray
//! traversal would enter, with the same arithmetic, so its answer equals
//! the single-ray query bit for bit; only the order in which answers are
//! reported differs.

use rt_core::{Ray, internal::widen_far};

use crate::{
    Isa, RayCtx,
    node::{ChildRef, Node, WIDTH},
    prim::{BestHit, Primitive, any_leaf},
    ray_ctx::Fused,
    traverse::{BvhRef, STACK_SIZE, TraversalStack, TraversalStats, Walk, box_test},
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
    /// overlap in the core, and on the AVX kernels each run of [`GROUP`]
    /// consecutive rays of one direction octant walks the tree as a group
    /// (`rt-report traversal`'s primary rows, 1024² camera rays in rows:
    /// 1.5–1.6× the single-ray rate, 1.8–1.95× Embree 3's coherent
    /// stream).
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
    #[target_feature(enable = "avx,avx2,fma")]
    fn closest_stream_avx2(&self, rays: &[Ray], out: &mut dyn FnMut(usize, Option<BestHit>)) {
        self.closest_stream_mixed(rays, out);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,avx512f,avx512vl")]
    fn closest_stream_avx512(&self, rays: &[Ray], out: &mut dyn FnMut(usize, Option<BestHit>)) {
        self.closest_stream_mixed(rays, out);
    }

    /// The AVX stream kernel of [`BvhRef::closest_t_stream`]: runs of
    /// [`GROUP`] rays of one direction octant (camera rays of a row, rays
    /// toward one direction) walk the tree as a group
    /// (`closest_group`) where the fused test covers them all; the rest
    /// take the interleaved single-ray kernel.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn closest_stream_mixed(&self, rays: &[Ray], out: &mut dyn FnMut(usize, Option<BestHit>)) {
        let Some(mut g) = Group::new() else { return };
        let mut best = [BestHit::new(0.0); GROUP];
        // Start of the rays not yet answered, left to the single-ray kernel.
        let mut left = 0;
        let mut start = 0;
        while start + GROUP <= rays.len() {
            let chunk = &rays[start..start + GROUP];
            let octant = chunk[0].direction.is_negative_bitmask();
            if chunk.iter().any(|r| r.direction.is_negative_bitmask() != octant) {
                start += GROUP;
                continue;
            }
            let mut fused = true;
            for (r, ray) in chunk.iter().enumerate() {
                // SAFETY: this kernel runs only where the CPU has AVX2.
                match self.ray_constants::<true>(ray) {
                    Some((ctx, fz)) => {
                        fused &= fz.on;
                        (g.ctxs[r], g.fzs[r], best[r]) = (ctx, fz, BestHit::new(ray.t_max));
                    }
                    None => fused = false,
                }
            }
            if !fused {
                start += GROUP;
                continue;
            }
            if left < start {
                self.closest_stream::<true>(&rays[left..start], &mut |i, h| out(left + i, h));
            }
            // SAFETY: as above; every ray is covered by the fused test, and
            // has the rows of the first: `RayCtx` picks them by the signs
            // of the direction, which the octant compared above.
            unsafe { self.closest_group(&g.ctxs, &g.fzs, &mut best, &mut g.stack) };
            for (r, b) in best.iter().enumerate() {
                out(start + r, b.is_hit().then_some(*b));
            }
            start += GROUP;
            left = start;
        }
        if left < rays.len() {
            self.closest_stream::<true>(&rays[left..], &mut |i, h| out(left + i, h));
        }
    }

    /// The closest hit of every ray of a group (`best[r]` for `ctxs[r]`,
    /// each starting at its ray's `t_max`), the group walking the tree
    /// together: a node is fetched once for every ray that reaches it,
    /// each ray tests its boxes with the single-ray fused test up to its
    /// best hit so far, and a subtree is pushed with the rays that entered
    /// it, nearest first by the entry distance of the group's first ray
    /// there. A ray enters every box that can hold a hit closer than its
    /// best so far, as its single-ray traversal does, and a hit wins over
    /// another as there (closer, or as close with a lower primitive
    /// index), so each ray finds its single-ray answer, bit for bit.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA; every ray of `ctxs` must have the
    /// fused test on in `fzs` and the rows of `ctxs[0]`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    unsafe fn closest_group(
        &self,
        ctxs: &[RayCtx; GROUP],
        fzs: &[Fused; GROUP],
        best: &mut [BestHit; GROUP],
        stack: &mut GroupStack,
    ) {
        let mut sp = 0;
        let (mut cur, mut rays) = (ChildRef::inner(0), u32::MAX);
        loop {
            if cur.is_leaf() {
                let (first, count) = cur.leaf_range();
                let items = self.leaf(first, count);
                let mut m = rays;
                while m != 0 {
                    let r = m.trailing_zeros() as usize;
                    m &= m - 1;
                    crate::prim::closest_leaf::<_, true>(items, first, &ctxs[r], &mut best[r]);
                }
            } else {
                let node = self.node(cur);
                // SAFETY: the caller's guarantees.
                let (child, t0) = unsafe { group_box_closest(node, ctxs, fzs, best, rays) };
                sp = push_nearest_last(&mut stack.0, sp, node, &child, &t0);
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            Entry { node: cur, rays } = stack.0[sp];
        }
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
                if !self.closest_step::<AVX, false, false>(
                    &l.ctx,
                    &Fused::OFF,
                    &mut l.walk,
                    &mut stats,
                    stack,
                ) {
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
    /// answers, reported as `out(index, occluded)` once per ray (in
    /// groups); groups of [`GROUP`] rays walk the tree together.
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
    #[target_feature(enable = "avx,avx2,fma")]
    fn occluded_stream_avx2(&self, rays: &[Ray], out: &mut dyn FnMut(usize, bool)) {
        self.occluded_stream_kernel::<true>(rays, out);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,avx512f,avx512vl")]
    fn occluded_stream_avx512(&self, rays: &[Ray], out: &mut dyn FnMut(usize, bool)) {
        self.occluded_stream_kernel::<true>(rays, out);
    }

    /// The stream kernel of [`BvhRef::occluded_stream`] (non-empty BVH):
    /// groups of up to [`GROUP`] consecutive rays.
    #[inline(always)]
    fn occluded_stream_kernel<const AVX: bool>(
        &self,
        rays: &[Ray],
        out: &mut dyn FnMut(usize, bool),
    ) {
        let Some(mut group) = Group::new() else { return };
        for (c, chunk) in rays.chunks(GROUP).enumerate() {
            self.occluded_rays::<AVX>(chunk, c * GROUP, &mut group, out);
        }
    }

    /// Answers the rays of `chunk` (at most [`GROUP`], `chunk[k]` being
    /// ray `first + k` of the stream): the invalid rays miss, the others
    /// walk the tree as one group with the fastest box test that holds for
    /// all of them.
    #[inline(always)]
    fn occluded_rays<const AVX: bool>(
        &self,
        chunk: &[Ray],
        first: usize,
        g: &mut Group,
        out: &mut dyn FnMut(usize, bool),
    ) {
        let mut n = 0;
        // Whether every ray has `t_min ≥ 0` (shadow and AO rays do): then
        // the shorter box test applies to each (`box_test`); whether the
        // fused test covers every ray (only on the AVX kernels, see
        // `ray_constants`).
        let (mut nonneg, mut fused) = (true, true);
        for (i, ray) in (first..).zip(chunk) {
            let Some((ctx, fz)) = self.ray_constants::<AVX>(ray) else {
                out(i, false);
                continue;
            };
            nonneg &= ctx.ray.t_min >= 0.0;
            fused &= fz.on;
            (g.ctxs[n], g.fzs[n], g.index[n]) = (ctx, fz, i);
            n += 1;
        }
        if n == 0 {
            return;
        }
        let (ctxs, fzs, stack) = (&g.ctxs[..n], &g.fzs[..n], &mut g.stack);
        // Where the rays share their octant, hence their plane rows
        // (shadow rays toward one light), `group_box_avx` loads them once.
        let hit = if fused && ctxs.iter().all(|c| c.rows == ctxs[0].rows) {
            self.occluded_group::<AVX, true, true, true>(ctxs, fzs, stack)
        } else if fused {
            self.occluded_group::<AVX, true, true, false>(ctxs, fzs, stack)
        } else if nonneg {
            self.occluded_group::<AVX, true, false, false>(ctxs, fzs, stack)
        } else {
            self.occluded_group::<AVX, false, false, false>(ctxs, fzs, stack)
        };
        (0..n).for_each(|r| out(g.index[r], hit >> r & 1 != 0));
    }

    /// Whether each ray of the group is occluded (bit `r` for `ctxs[r]`),
    /// the group walking the tree together: each node is fetched once for
    /// every ray that reaches it, and each ray tests its boxes and leaves
    /// with the single-ray tests, so it enters exactly the subtrees its
    /// own traversal would enter (until it is found occluded) and gets the
    /// same answer. A subtree is pushed with the rays that entered it; a
    /// ray found occluded drops out of every pending subtree.
    #[inline(always)]
    fn occluded_group<
        const AVX: bool,
        const NONNEG: bool,
        const FUSED: bool,
        const SHARED: bool,
    >(
        &self,
        ctxs: &[RayCtx],
        fzs: &[Fused],
        stack: &mut GroupStack,
    ) -> u32 {
        let all = if ctxs.len() >= 32 { u32::MAX } else { (1u32 << ctxs.len()) - 1 };
        let mut occluded = 0u32;
        let mut sp = 0;
        let (mut cur, mut rays) = (ChildRef::inner(0), all);
        loop {
            let active = rays & !occluded;
            if active != 0 {
                if cur.is_leaf() {
                    let (first, count) = cur.leaf_range();
                    occluded |= leaf_group::<P, AVX>(self.leaf(first, count), ctxs, active);
                    if occluded == all {
                        return occluded;
                    }
                } else {
                    let node = self.node(cur);
                    // The rays entering each child.
                    let child =
                        group_box_test::<AVX, NONNEG, FUSED, SHARED>(node, ctxs, fzs, active);
                    sp = push_group::<AVX>(&mut stack.0, sp, node, &child);
                }
            }
            if sp == 0 {
                return occluded;
            }
            sp -= 1;
            Entry { node: cur, rays } = stack.0[sp];
        }
    }
}

/// Which of the rays in `active` (bits of `ctxs`) hit an item of `items`
/// (a leaf), each as the single-ray occlusion test answers. On the AVX
/// kernels a leaf of one triangle packet (most leaves) is tested for two
/// rays at a time, one in each half of the eight lanes
/// (`tri_packet::any_pair`).
#[inline(always)]
fn leaf_group<P: Primitive, const AVX: bool>(items: &[P], ctxs: &[RayCtx], active: u32) -> u32 {
    let mut hit = 0;
    let mut m = active;
    #[cfg(target_arch = "x86_64")]
    if AVX && let Some([tri]) = P::as_tri_packets(items) {
        while m & (m.wrapping_sub(1)) != 0 {
            let a = m.trailing_zeros() as usize;
            m &= m - 1;
            let b = m.trailing_zeros() as usize;
            m &= m - 1;
            let (ca, cb) = (&ctxs[a], &ctxs[b]);
            // SAFETY: `AVX` kernels run only where the CPU has AVX (see
            // `box_test`).
            let [ha, hb] = unsafe {
                crate::tri_packet::any_pair(tri, [(ca, ca.ray.t_max), (cb, cb.ray.t_max)])
            };
            hit |= u32::from(ha) << a | u32::from(hb) << b;
        }
    }
    while m != 0 {
        let r = m.trailing_zeros() as usize;
        m &= m - 1;
        let ctx = &ctxs[r];
        if any_leaf::<P, AVX>(items, ctx, ctx.ray.t_max) {
            hit |= 1 << r;
        }
    }
    hit
}

/// Which of the rays in `active` (bits of `ctxs`) enter each child of
/// `node`, each ray tested with the single-ray occlusion test: the
/// fused one where it covers every ray (`FUSED`), with the plane rows
/// loaded once for the group where all rays have the same octant
/// (`SHARED`, see `group_box_avx`), else the robust one, short where every
/// ray has `t_min ≥ 0` (`NONNEG`, see `box_test`).
/// The AVX kernels gather the rays' bits with two vector operations per
/// ray; the 4-wide one bit by bit. Branch-free: which children a ray
/// enters is unpredictable.
#[inline(always)]
fn group_box_test<const AVX: bool, const NONNEG: bool, const FUSED: bool, const SHARED: bool>(
    node: &Node,
    ctxs: &[RayCtx],
    fzs: &[Fused],
    active: u32,
) -> [u32; WIDTH] {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` kernels run only where the CPU has AVX2 and FMA
        // (see `box_test`); the caller sets `FUSED` only where every `fzs`
        // is on, and `SHARED` only where every ray has the rows of
        // `ctxs[0]`.
        return unsafe { group_box_avx::<NONNEG, FUSED, SHARED>(node, ctxs, fzs, active) };
    }
    let _ = fzs;
    let mut child = [0u32; WIDTH];
    let mut m = active;
    while m != 0 {
        let r = m.trailing_zeros() as usize;
        m &= m - 1;
        let ctx = &ctxs[r];
        // Widened as in the single-ray occlusion test.
        let (hit, _) =
            box_test::<AVX, NONNEG, false>(node, ctx, &Fused::OFF, widen_far(ctx.ray.t_max));
        for (i, c) in child.iter_mut().enumerate() {
            *c |= (hit >> i & 1) << r;
        }
    }
    child
}

/// [`group_box_test`] on the AVX kernels: each ray's entered lanes ORed
/// into the children's masks as vectors. With `FUSED` each ray takes the
/// fused test, as the single-ray occlusion kernel does (the same subtrees,
/// so the same answers), and with `SHARED` too the six plane rows are
/// loaded once for the group: its rays share their direction signs, so
/// they test the same rows, and each ray's test is then six multiply-adds
/// on registers and the compares.
///
/// # Safety
/// The CPU must have AVX2 and FMA; with `FUSED`, every ray of `ctxs` must
/// have the fused test on in `fzs`, and with `SHARED` the rows
/// (`RayCtx::rows`) of `ctxs[0]`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn group_box_avx<const NONNEG: bool, const FUSED: bool, const SHARED: bool>(
    node: &Node,
    ctxs: &[RayCtx],
    fzs: &[Fused],
    active: u32,
) -> [u32; WIDTH] {
    use crate::{
        simd::F32x8,
        traverse::{box_lanes_avx, fused_lanes, fused_rows},
    };
    // SAFETY: the caller guarantees AVX2, FMA and the fused test's
    // constants; `ctxs` is not empty (the group has a ray).
    unsafe {
        let shared = fused_rows(&node.bounds, &ctxs[0]);
        let mut acc = F32x8::splat_bits(0);
        let mut m = active;
        while m != 0 {
            let r = m.trailing_zeros() as usize;
            m &= m - 1;
            let ctx = &ctxs[r];
            // Widened as in the single-ray occlusion test.
            let t_max = widen_far(ctx.ray.t_max);
            let (entered, _) = if FUSED {
                let rows = if SHARED { shared } else { fused_rows(&node.bounds, ctx) };
                fused_lanes(&rows, ctx, &fzs[r], t_max)
            } else {
                box_lanes_avx::<NONNEG, false>(node, ctx, &Fused::OFF, t_max)
            };
            acc = acc.or(entered.and(F32x8::splat_bits(1 << r)));
        }
        acc.to_bits()
    }
}

/// Which of the rays in `rays` (bits of `ctxs`) enter each child of
/// `node` with the single-ray closest-hit test (fused, up to the ray's
/// best hit so far), and the entry distances of the first of them.
///
/// # Safety
/// As [`BvhRef::closest_group`]; `rays` is not empty.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn group_box_closest(
    node: &Node,
    ctxs: &[RayCtx; GROUP],
    fzs: &[Fused; GROUP],
    best: &[BestHit; GROUP],
    rays: u32,
) -> ([u32; WIDTH], [f32; WIDTH]) {
    use crate::{
        simd::F32x8,
        traverse::{fused_lanes, fused_rows},
    };
    // SAFETY: the caller's guarantees.
    unsafe {
        let rows = fused_rows(&node.bounds, &ctxs[0]);
        let r0 = rays.trailing_zeros() as usize;
        let (entered, t0) = fused_lanes(&rows, &ctxs[r0], &fzs[r0], widen_far(best[r0].t));
        let mut acc = entered.and(F32x8::splat_bits(1 << r0));
        let mut m = rays & (rays - 1);
        while m != 0 {
            let r = m.trailing_zeros() as usize;
            m &= m - 1;
            let (entered, _) = fused_lanes(&rows, &ctxs[r], &fzs[r], widen_far(best[r].t));
            acc = acc.or(entered.and(F32x8::splat_bits(1 << r)));
        }
        (acc.to_bits(), t0.to_array())
    }
}

/// Pushes an entry for every child of `node` that some ray entered
/// (`child[i] != 0`), farthest first by `t` (so the nearest is visited
/// next); returns the new stack height.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn push_nearest_last(
    stack: &mut [Entry; STACK_SIZE],
    sp: usize,
    node: &Node,
    child: &[u32; WIDTH],
    t: &[f32; WIDTH],
) -> usize {
    let mut order = [0usize; WIDTH];
    let mut k = 0;
    for i in 0..WIDTH {
        if child[i] != 0 {
            // Insertion by descending distance (coherent rays: predictable).
            let mut b = k;
            while b > 0 && t[order[b - 1]] < t[i] {
                order[b] = order[b - 1];
                b -= 1;
            }
            order[b] = i;
            k += 1;
        }
    }
    let mut sp = sp;
    for &i in &order[..k] {
        stack[sp] = Entry { node: node.children[i], rays: child[i] };
        sp += 1;
    }
    sp
}

/// Rays an occlusion stream walks the tree with together (bits of a `u32`).
pub const GROUP: usize = 32;

/// A group's rays (their constants and indices in the stream) and its
/// stack, made once a stream and reused by every group.
struct Group {
    ctxs: [RayCtx; GROUP],
    fzs: [Fused; GROUP],
    index: [usize; GROUP],
    stack: GroupStack,
}

impl Group {
    fn new() -> Option<Self> {
        // Filler for the unused end of the arrays (never read).
        let filler = RayCtx::new(&Ray::new(glam::Vec3::ZERO, glam::Vec3::X))?;
        Some(Self {
            ctxs: [filler; GROUP],
            fzs: [Fused::OFF; GROUP],
            index: [0; GROUP],
            stack: GroupStack::new(),
        })
    }
}

/// The pending subtrees of a group and the rays that entered each. Each
/// level leaves at most `WIDTH − 1` siblings pending and pushes at most
/// `WIDTH`, so `STACK_SIZE` entries hold a tree of `MAX_DEPTH` levels.
struct GroupStack([Entry; STACK_SIZE]);

impl GroupStack {
    fn new() -> Self {
        Self([Entry { node: ChildRef::EMPTY, rays: 0 }; STACK_SIZE])
    }
}

/// A pending subtree of a group and the rays that entered it (a `repr(C)`
/// pair, which [`push_entered`] writes as two 32-bit lanes).
#[derive(Clone, Copy)]
#[repr(C)]
struct Entry {
    node: ChildRef,
    rays: u32,
}

/// Pushes an entry for every child of `node` that some ray entered
/// (`child[i] != 0`), highest slot first (so the lowest is visited
/// first); returns the new stack height.
#[inline(always)]
fn push_group<const AVX: bool>(
    stack: &mut [Entry; STACK_SIZE],
    sp: usize,
    node: &Node,
    child: &[u32; WIDTH],
) -> usize {
    // Each level leaves at most `WIDTH − 1` entries and the depth is at
    // most `MAX_DEPTH` (`validate`), so a node is reached with
    // `sp ≤ (WIDTH − 1)·(MAX_DEPTH − 1)` and the test always holds.
    #[cfg(target_arch = "x86_64")]
    if AVX && sp + WIDTH <= STACK_SIZE {
        // SAFETY: `AVX` kernels run only where the CPU has AVX2; the
        // `WIDTH` entries from `sp` lie in the stack.
        return sp + unsafe { push_entered(stack.as_mut_ptr().add(sp), node, child) };
    }
    let mut sp = sp;
    for i in (0..WIDTH).rev() {
        if child[i] != 0 {
            stack[sp] = Entry { node: node.children[i], rays: child[i] };
            sp += 1;
        }
    }
    sp
}

/// For each 8-bit child mask, the slots of its set bits from the highest
/// down, padded with slot 0.
#[cfg(target_arch = "x86_64")]
static COMPRESS_DOWN: [[u32; WIDTH]; 1 << WIDTH] = crate::traverse::compress_table(true);

/// Writes an entry for every child of `node` that some ray entered
/// (`child[i] != 0`), highest slot first as the scalar loop does, with two
/// permutes, two unpacks and two stores and no branch (which children the
/// group enters is unpredictable); returns their number. All `WIDTH`
/// entries of `out` are written; those past the number are garbage.
///
/// # Safety
/// The CPU must have AVX2, and `out` must be valid for `WIDTH` writes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn push_entered(out: *mut Entry, node: &Node, child: &[u32; WIDTH]) -> usize {
    use core::arch::x86_64::{
        __m256i, _mm256_castsi256_ps, _mm256_cmpeq_epi32, _mm256_loadu_si256, _mm256_movemask_ps,
        _mm256_permute2x128_si256, _mm256_permutevar8x32_epi32, _mm256_setzero_si256,
        _mm256_storeu_si256, _mm256_unpackhi_epi32, _mm256_unpacklo_epi32,
    };
    // SAFETY: the caller guarantees AVX2 and `out`; `child` and
    // `node.children` are `WIDTH` u32s (32 bytes, read unaligned); the
    // mask has 8 bits, so it indexes the table.
    unsafe {
        let rays = _mm256_loadu_si256(child.as_ptr().cast::<__m256i>());
        let none = _mm256_cmpeq_epi32(rays, _mm256_setzero_si256());
        let mask = !(_mm256_movemask_ps(_mm256_castsi256_ps(none)) as u32) & 0xff;
        let perm = COMPRESS_DOWN.get_unchecked(mask as usize);
        let perm = _mm256_loadu_si256(perm.as_ptr().cast::<__m256i>());
        let kids = _mm256_loadu_si256(node.children.as_ptr().cast::<__m256i>());
        let (kids, rays) =
            (_mm256_permutevar8x32_epi32(kids, perm), _mm256_permutevar8x32_epi32(rays, perm));
        // Pairs 0, 1 | 4, 5 and 2, 3 | 6, 7, then in order.
        let (lo, hi) = (_mm256_unpacklo_epi32(kids, rays), _mm256_unpackhi_epi32(kids, rays));
        _mm256_storeu_si256(out.cast::<__m256i>(), _mm256_permute2x128_si256::<0x20>(lo, hi));
        _mm256_storeu_si256(
            out.add(4).cast::<__m256i>(),
            _mm256_permute2x128_si256::<0x31>(lo, hi),
        );
        mask.count_ones() as usize
    }
}
