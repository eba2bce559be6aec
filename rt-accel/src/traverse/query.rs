//! The queries on a borrowed BVH and their kernels: closest hit and
//! occlusion, one ray or four in flight, dispatched on the CPU's ISA; the
//! step loops that walk the tree with a fixed stack.

use core::mem::MaybeUninit;

use rt_core::{Aabb, Hit, Ray, SceneQuery, internal::widen_far};

use crate::{
    Isa, RayCtx, UnsupportedIsa,
    node::{ChildRef, Node, WIDTH},
    prim::{BestHit, Primitive, any_leaf, closest_leaf},
    ray_ctx::Fused,
    simd::{prefetch_bytes, prefetch_line},
};

use super::node_test::*;
use super::order::*;

/// Deepest tree accepted by builders and loaders (root = depth 1).
pub const MAX_DEPTH: usize = 64;
/// Traversal stack entries: each level pushes at most `WIDTH − 1` siblings.
pub const STACK_SIZE: usize = (WIDTH - 1) * MAX_DEPTH + 1;

/// A BVH borrowed from memory: nodes, leaf items and the number of
/// primitives their ids refer to. Built by [`crate::Bvh::as_ref`] or
/// [`BvhRef::from_bytes`], which check every invariant the traversal relies
/// on, so traversal never reads out of bounds and always terminates.
/// Queries run on the widest kernel the CPU has ([`Isa::detect`]);
/// [`BvhRef::with_isa`] picks another, with the same answers.
#[derive(Debug)]
pub struct BvhRef<'a, P: Primitive> {
    pub(crate) nodes: &'a [Node],
    pub(crate) items: &'a [P],
    pub(crate) prim_count: u32,
    /// Always one [`Isa::is_available`] approved: the dispatch relies on it.
    pub(crate) isa: Isa,
    /// Whether every box lies within the fused node test's range
    /// ([`fits_fused`]): the AVX kernels use it for the rays it covers.
    pub(crate) fused: bool,
}

/// Whether every node's boxes lie within the range the fused node test
/// covers (`±2¹²⁶`, see `crate::ray_ctx::Fused`).
pub(crate) fn fits_fused(nodes: &[Node]) -> bool {
    nodes.iter().all(|n| n.within(crate::ray_ctx::FUSED_RANGE))
}

impl<P: Primitive> Clone for BvhRef<'_, P> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<P: Primitive> Copy for BvhRef<'_, P> {}

/// A traversal stack (~3.6 KiB). Its entries start uninitialized, so a
/// fresh one costs nothing (the plain query methods make one per call);
/// [`BvhRef::closest_hit_with`] and friends take one the caller keeps.
#[derive(Clone, Debug)]
pub struct TraversalStack {
    /// Entries `0..sp` of a running traversal are written; the others are
    /// never read.
    refs: [MaybeUninit<ChildRef>; STACK_SIZE],
    ts: [MaybeUninit<f32>; STACK_SIZE],
}

impl TraversalStack {
    /// An empty stack.
    #[must_use]
    pub const fn new() -> Self {
        Self { refs: [MaybeUninit::uninit(); STACK_SIZE], ts: [MaybeUninit::uninit(); STACK_SIZE] }
    }
}

impl Default for TraversalStack {
    fn default() -> Self {
        Self::new()
    }
}

/// Traversal statistics for one ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TraversalStats {
    /// Inner nodes whose boxes were tested.
    pub nodes: u32,
    /// Leaf items tested.
    pub items: u32,
}

impl<'a, P: Primitive> BvhRef<'a, P> {
    /// The traversal kernel queries run on.
    #[must_use]
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// The same BVH queried with kernel `isa` (to compare kernels, or to
    /// pin one); every kernel returns the same hits, bit for bit.
    ///
    /// # Errors
    /// [`UnsupportedIsa`] if this CPU or target cannot run it.
    pub fn with_isa(self, isa: Isa) -> Result<Self, UnsupportedIsa> {
        if isa.is_available() { Ok(Self { isa, ..self }) } else { Err(UnsupportedIsa(isa)) }
    }

    /// The nodes (root first; empty for an empty BVH).
    #[must_use]
    pub fn nodes(&self) -> &'a [Node] {
        self.nodes
    }

    /// The leaf items in leaf order.
    #[must_use]
    pub fn items(&self) -> &'a [P] {
        self.items
    }

    /// Number of primitives the items refer to.
    #[must_use]
    pub fn prim_count(&self) -> u32 {
        self.prim_count
    }

    /// The box around everything (empty for an empty BVH).
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, Node::bounds)
    }

    /// The closest hit in `[ray.t_min, ray.t_max]`; ties in `t` go to the
    /// lower primitive index. Invalid rays ([`Ray::is_valid`]) miss.
    #[must_use]
    pub fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit_with(ray, &mut TraversalStack::new())
    }

    /// [`BvhRef::closest_hit`] with a caller-owned stack.
    #[must_use]
    pub fn closest_hit_with(&self, ray: &Ray, stack: &mut TraversalStack) -> Option<Hit> {
        self.record(self.closest_t_with(ray, stack)?, ray)
    }

    /// The full hit record of a traversal's best hit.
    pub(crate) fn record(&self, best: BestHit, ray: &Ray) -> Option<Hit> {
        self.items[best.item as usize].hit(best.lane, ray, best.t)
    }

    /// Like [`BvhRef::closest_hit`], counting the work done into `stats`.
    /// Runs the portable kernel, which visits the same nodes and items as
    /// every other (their box masks and orders are identical), so the
    /// fast kernels need not count.
    pub fn closest_hit_stats(&self, ray: &Ray, stats: &mut TraversalStats) -> Option<Hit> {
        let best = self.closest_kernel::<false>(ray, stats, &mut TraversalStack::new())?;
        best.is_hit().then(|| self.record(best, ray))?
    }

    /// The closest hit's `t`, primitive and leaf position, without the full
    /// hit record (the cheapest closest-hit query).
    #[must_use]
    pub fn closest_t(&self, ray: &Ray) -> Option<BestHit> {
        self.closest_t_with(ray, &mut TraversalStack::new())
    }

    /// [`BvhRef::closest_t`] with a caller-owned stack.
    #[must_use]
    pub fn closest_t_with(&self, ray: &Ray, stack: &mut TraversalStack) -> Option<BestHit> {
        if self.nodes.is_empty() {
            return None;
        }
        let best = self.closest_best(ray, stack)?;
        best.is_hit().then_some(best)
    }

    /// Whether anything is hit in `[ray.t_min, ray.t_max]`; stops at the
    /// first hit found. Invalid rays are not occluded.
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_with(ray, &mut TraversalStack::new())
    }

    /// [`BvhRef::occluded`] with a caller-owned stack.
    #[must_use]
    pub fn occluded_with(&self, ray: &Ray, stack: &mut TraversalStack) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        match self.isa {
            // SAFETY: `self.isa` passed `Isa::is_available` (the field's
            // invariant): the CPU has the features these kernels enable.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.occluded_avx512(ray, stack) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Isa::Avx2 => unsafe { self.occluded_avx2(ray, stack) },
            _ => self.occluded_portable(ray, stack),
        }
    }

    /// The 4-wide kernel, out of line (see `closest_portable`).
    #[inline(never)]
    fn occluded_portable(&self, ray: &Ray, stack: &mut TraversalStack) -> bool {
        self.occluded_kernel::<false>(ray, stack)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma")]
    fn occluded_avx2(&self, ray: &Ray, stack: &mut TraversalStack) -> bool {
        self.occluded_kernel::<true>(ray, stack)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,avx512f,avx512vl")]
    fn occluded_avx512(&self, ray: &Ray, stack: &mut TraversalStack) -> bool {
        self.occluded_kernel::<true>(ray, stack)
    }

    /// The occlusion kernel: any hit ends it. `AVX`: test a node's boxes
    /// in one 8-wide pass (only inside the AVX kernels above). Rays with
    /// `t_min ≥ 0` take the shorter box test (see [`box_test`]). The ray's
    /// constants are made here, inside the kernel, so they stay in
    /// registers: made by a separate call, they were stored and read back
    /// at once with loads wider than the stores, which the CPU cannot
    /// forward (a tenth of a missed ray's time). The tree must not be
    /// empty: the root is read unchecked (`occluded_with` checks).
    #[inline(always)]
    fn occluded_kernel<const AVX: bool>(&self, ray: &Ray, stack: &mut TraversalStack) -> bool {
        let Some((ctx, fz)) = self.ray_constants::<AVX>(ray) else {
            return false;
        };
        let (ctx, fz) = (&ctx, &fz);
        let root = ChildRef::inner(0);
        // Two instantiations per kernel: rays the fused test does not
        // cover take the general test on the AVX kernels (a third, the
        // robust short test, made the kernels slower).
        if AVX && fz.on {
            self.occluded_from::<AVX, true, true>(ctx, fz, root, stack)
        } else if !AVX && ctx.ray.t_min >= 0.0 {
            self.occluded_from::<AVX, true, false>(ctx, fz, root, stack)
        } else {
            self.occluded_from::<AVX, false, false>(ctx, fz, root, stack)
        }
    }

    /// The ray's constants for kernel `AVX`: with the fused node test's
    /// on the AVX kernels (on where it covers the ray and this BVH), off
    /// on the 4-wide ones; `None` for an invalid ray.
    #[inline(always)]
    pub(crate) fn ray_constants<const AVX: bool>(&self, ray: &Ray) -> Option<(RayCtx, Fused)> {
        #[cfg(target_arch = "x86_64")]
        if AVX {
            // SAFETY: `AVX` kernels run only inside the functions compiled
            // with AVX, called only where the CPU has it (as `box_test`).
            return unsafe { RayCtx::new_fused_avx(ray, self.fused) };
        }
        RayCtx::new(ray).map(|c| (c, Fused::OFF))
    }

    /// [`Self::occluded_kernel`] over the subtree `start` only.
    #[inline(always)]
    pub(crate) fn occluded_from<const AVX: bool, const NONNEG: bool, const FUSED: bool>(
        &self,
        ctx: &RayCtx,
        fz: &Fused,
        start: ChildRef,
        stack: &mut TraversalStack,
    ) -> bool {
        let t_max = ctx.ray.t_max;
        let stack = &mut stack.refs;
        let mut sp = 0;
        let mut cur = start;
        loop {
            if cur.is_leaf() {
                let (first, count) = cur.leaf_range();
                if any_leaf::<P, AVX>(self.leaf(first, count), ctx, t_max) {
                    return true;
                }
            } else {
                let node = self.node(cur);
                // Widened as in `closest_step`: a box entered at a rounded
                // distance just past `t_max` may hold a hit at exactly
                // `t_max` (found by the `bvh` fuzz target with
                // `t_min = t_max`).
                let (mask, _) = box_test::<AVX, NONNEG, FUSED>(node, ctx, fz, widen_far(t_max));
                // Empty slots are never entered (see `closest_step`). The
                // hit children are pushed in slot order and the last one
                // is visited next, taken from the node rather than
                // reloaded from the store just made.
                if mask != 0 {
                    push_children::<AVX>(stack, sp, node, mask);
                    sp += mask.count_ones() as usize - 1;
                    cur = node.children[31 - mask.leading_zeros() as usize];
                    continue;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: entries below the pushes' count were written above.
            cur = unsafe { stack[sp].assume_init() };
        }
    }

    /// Inner node `c`, found by its byte offset (no multiply on the
    /// traversal's chain, see `layout/node.rs`).
    #[inline(always)]
    pub(crate) fn node(&self, c: ChildRef) -> &'a Node {
        debug_assert!(
            c.byte_offset().is_multiple_of(crate::NODE_BYTES as usize)
                && c.index() < self.nodes.len()
        );
        // SAFETY: traversals only follow references stored in the tree
        // (or the root of a non-empty tree), and every `BvhRef` was made
        // by `Bvh::as_ref` or `BvhRef::from_bytes`, which prove that each
        // inner reference is the offset of an existing node, a multiple of
        // its size (`validate`).
        unsafe { &*self.nodes.as_ptr().byte_add(c.byte_offset()) }
    }

    /// The items `first..first + count` of a leaf reference.
    #[inline(always)]
    pub(crate) fn leaf(&self, first: usize, count: usize) -> &'a [P] {
        debug_assert!(first + count <= self.items.len());
        // SAFETY: as in `node`: `validate` proves every leaf reference's
        // range lies within the items.
        unsafe { self.items.get_unchecked(first..first + count) }
    }

    #[inline(always)]
    fn prefetch(&self, c: ChildRef) {
        if c.is_leaf() {
            let (first, count) = c.leaf_range();
            if let Some(it) = self.items.get(first) {
                // The first two items: a leaf's usual size.
                prefetch_bytes(it, count.min(2) * core::mem::size_of::<P>());
            }
        } else {
            // A reference from the tree (see `node`).
            prefetch_bytes(self.node(c), core::mem::size_of::<Node>());
        }
    }

    /// Starts fetching the subtrees a node just stacked (`stacked`,
    /// farthest first): the one visited after the nearest, to overlap its
    /// memory latency, and of the others only the leaves.
    /// Prefetching every stacked child (four lines per node) cost more
    /// than it saved; the leaves are worth it, since their triangles are
    /// a ray's largest misses.
    #[inline(always)]
    fn prefetch_stacked(&self, stacked: &[ChildRef]) {
        if let Some((&next, others)) = stacked.split_last() {
            self.prefetch(next);
            for &r in others {
                if r.is_leaf() {
                    self.prefetch(r);
                }
            }
        }
    }

    /// The closest-hit traversal on this BVH's kernel; `None` for an
    /// invalid ray. Its statistics are a local nobody reads, so they
    /// compile away: counted through a pointer, they cost a store per node.
    #[inline]
    fn closest_best(&self, ray: &Ray, stack: &mut TraversalStack) -> Option<BestHit> {
        match self.isa {
            // SAFETY: `self.isa` passed `Isa::is_available` (the field's
            // invariant): the CPU has the features these kernels enable.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.closest_avx512(ray, stack) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Isa::Avx2 => unsafe { self.closest_avx2(ray, stack) },
            _ => self.closest_portable(ray, stack),
        }
    }

    /// The 4-wide kernel, out of line as the AVX ones are: inlined into
    /// the dispatch, its stack frame (the registers it saves, 840 bytes)
    /// was set up on every query, whichever kernel ran.
    #[inline(never)]
    fn closest_portable(&self, ray: &Ray, stack: &mut TraversalStack) -> Option<BestHit> {
        self.closest_kernel::<false>(ray, &mut TraversalStats::default(), stack)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma")]
    fn closest_avx2(&self, ray: &Ray, stack: &mut TraversalStack) -> Option<BestHit> {
        self.closest_kernel::<true>(ray, &mut TraversalStats::default(), stack)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,avx512f,avx512vl")]
    fn closest_avx512(&self, ray: &Ray, stack: &mut TraversalStack) -> Option<BestHit> {
        self.closest_kernel::<true>(ray, &mut TraversalStats::default(), stack)
    }

    /// The traversal kernel: front-to-back by entry distance, culling
    /// stacked subtrees that start beyond the best hit. `AVX`: test a
    /// node's boxes in one 8-wide pass (only inside the AVX kernels above).
    /// Rays with `t_min ≥ 0` take the shorter box test (see [`box_test`]).
    /// The ray's constants are made here, as in [`Self::occluded_kernel`].
    #[inline(always)]
    fn closest_kernel<const AVX: bool>(
        &self,
        ray: &Ray,
        stats: &mut TraversalStats,
        stack: &mut TraversalStack,
    ) -> Option<BestHit> {
        let (ctx, fz) = &self.ray_constants::<AVX>(ray)?;
        let best = BestHit::new(ctx.ray.t_max);
        if self.nodes.is_empty() {
            return Some(best);
        }
        let root = ChildRef::inner(0);
        // As in `occluded_kernel`: two instantiations per kernel.
        Some(if AVX && fz.on {
            self.closest_from::<AVX, true, true>(ctx, fz, root, best, stats, stack)
        } else if !AVX && ctx.ray.t_min >= 0.0 {
            self.closest_from::<AVX, true, false>(ctx, fz, root, best, stats, stack)
        } else {
            self.closest_from::<AVX, false, false>(ctx, fz, root, best, stats, stack)
        })
    }

    /// [`Self::closest_kernel`] over the subtree `start` only, improving
    /// on `best` (the packets hand a subtree to it once a single ray is
    /// left in it).
    #[inline(always)]
    pub(crate) fn closest_from<const AVX: bool, const NONNEG: bool, const FUSED: bool>(
        &self,
        ctx: &RayCtx,
        fz: &Fused,
        start: ChildRef,
        best: BestHit,
        stats: &mut TraversalStats,
        stack: &mut TraversalStack,
    ) -> BestHit {
        let mut walk = Walk { cur: start, sp: 0, best };
        while self.closest_step::<AVX, NONNEG, FUSED>(ctx, fz, &mut walk, stats, stack) {}
        walk.best
    }

    /// One step of a closest-hit traversal: visits `walk.cur` (a node or
    /// a leaf) and moves on to the next subtree to visit, front to back by
    /// entry distance, skipping stacked subtrees that start beyond the
    /// best hit. False when nothing is left to visit.
    #[inline(always)]
    pub(crate) fn closest_step<const AVX: bool, const NONNEG: bool, const FUSED: bool>(
        &self,
        ctx: &RayCtx,
        fz: &Fused,
        walk: &mut Walk,
        stats: &mut TraversalStats,
        stack: &mut TraversalStack,
    ) -> bool {
        let TraversalStack { refs: stack_ref, ts: stack_t } = stack;
        let Walk { cur, sp, best } = walk;
        if cur.is_leaf() {
            let (first, count) = cur.leaf_range();
            stats.items += count as u32;
            closest_leaf::<_, AVX>(self.leaf(first, count), first, ctx, best);
        } else {
            stats.nodes += 1;
            let node = self.node(*cur);
            // The line of the child references, which the traversal reads
            // only once the boxes are tested, fetched beside the boxes (a
            // 224-byte node's last line may hold none of them, and would
            // be missed only then). The occlusion kernel loads the
            // references with the boxes and needs no such prefetch.
            prefetch_line(&node.children);
            // A box entered at (rounded) distance just past the best hit
            // may still hold an exact tie; widen the bound as the far
            // planes are widened.
            let bound = widen_far(best.t);
            let (mask, tnear) = box_test::<AVX, NONNEG, FUSED>(node, ctx, fz, bound);
            // Empty slots hold the empty box, which no ray enters
            // (`validate` rejects blobs where they do not): `mask` names
            // real children only. One or two children (most nodes) take
            // a short path; more are sorted.
            if mask != 0 {
                let i = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    *cur = node.children[i];
                    // Fetched here, as Embree fetches the child it visits
                    // (likely why it helps: the next step branches on
                    // what the child is, which mispredicts for rays of
                    // random direction, and its loads would wait for the
                    // recovery). It pays on incoherent rays and costs
                    // coherent ones next to nothing.
                    self.prefetch(*cur);
                    return true;
                }
                let j = rest.trailing_zeros() as usize;
                if rest & (rest - 1) == 0 {
                    let (ci, cj) = (node.children[i], node.children[j]);
                    let (near, far, t_far) =
                        if tnear[j] < tnear[i] { (cj, ci, tnear[i]) } else { (ci, cj, tnear[j]) };
                    self.prefetch(near);
                    self.prefetch(far);
                    push(stack_ref, stack_t, sp, far, t_far);
                    *cur = near;
                    return true;
                }
                // Three or more on the fused kernels: sorted without a
                // branch (`push_sorted`). The insertion sort below
                // mispredicts for rays of random direction; a sorting
                // network does not, and coherent rays lose nothing.
                #[cfg(target_arch = "x86_64")]
                if AVX && FUSED && *sp + WIDTH <= STACK_SIZE {
                    let k = mask.count_ones() as usize;
                    // SAFETY: `AVX` kernels run only where the CPU has
                    // AVX2 (see `box_test`); the `WIDTH` entries from `sp`
                    // lie in the stack (checked above; the bound of
                    // `push_children` says it always holds); the fused
                    // test's entry distances have their sign bit clear
                    // (`box_lanes_fused`: a maximum with `t_min ≥ +0`).
                    let near = unsafe {
                        push_sorted(
                            stack_ref.as_mut_ptr().add(*sp),
                            stack_t.as_mut_ptr().add(*sp),
                            node,
                            mask,
                            &tnear,
                        )
                    };
                    // SAFETY: entries `sp..sp + k − 1` were just written.
                    let pushed = unsafe {
                        core::slice::from_raw_parts(
                            stack_ref.as_ptr().add(*sp).cast::<ChildRef>(),
                            k - 1,
                        )
                    };
                    // The child visited next (as with one or two hit),
                    // then the stacked ones.
                    self.prefetch(near);
                    self.prefetch_stacked(pushed);
                    *sp += k - 1;
                    *cur = near;
                    return true;
                }
                // Gather the hit children with their entry distances.
                let mut refs = [ChildRef::EMPTY; WIDTH];
                let mut ts = [0.0f32; WIDTH];
                let mut k = 0;
                let mut m = mask;
                while m != 0 {
                    let i = m.trailing_zeros() as usize;
                    m &= m - 1;
                    refs[k] = node.children[i];
                    ts[k] = tnear[i];
                    k += 1;
                }
                // Sort descending by entry distance (at most 8: insertion
                // sort), push all but the nearest, descend into it.
                for a in 1..k {
                    let (r, t) = (refs[a], ts[a]);
                    let mut b = a;
                    while b > 0 && ts[b - 1] < t {
                        refs[b] = refs[b - 1];
                        ts[b] = ts[b - 1];
                        b -= 1;
                    }
                    refs[b] = r;
                    ts[b] = t;
                }
                self.prefetch_stacked(&refs[..k - 1]);
                for a in 0..k - 1 {
                    push(stack_ref, stack_t, sp, refs[a], ts[a]);
                }
                *cur = refs[k - 1];
                return true;
            }
        }
        // Pop the next subtree that can still hold a closer hit.
        while *sp > 0 {
            *sp -= 1;
            debug_assert!(*sp < STACK_SIZE);
            // SAFETY: entries below the pushes' count were written by
            // `push` (both arrays), which kept the count within the stack.
            let (t, r) = unsafe {
                (
                    stack_t.get_unchecked(*sp).assume_init(),
                    stack_ref.get_unchecked(*sp).assume_init(),
                )
            };
            if t <= widen_far(best.t) {
                *cur = r;
                return true;
            }
        }
        false
    }
}

impl<P: Primitive> SceneQuery for BvhRef<'_, P> {
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        BvhRef::closest_hit(self, ray)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        BvhRef::occluded(self, ray)
    }

    /// Through [`BvhRef::occluded_stream`]: the same answers.
    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        let n = rays.len().min(out.len());
        self.occluded_stream(&rays[..n], |i, o| out[i] = o);
    }

    /// Through [`BvhRef::closest_t_stream`] (coherent runs of rays walk
    /// the tree as groups on the AVX kernels): the same hits.
    fn closest_hit_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        let n = rays.len().min(out.len());
        self.closest_t_stream(&rays[..n], |i, b| out[i] = b.and_then(|b| self.record(b, &rays[i])));
    }

    /// On the AVX kernels ray by ray, where single rays take the fused
    /// node test and the packets do not: measured faster there (`rt-report
    /// render`'s frames and the traversal report's primary rows); through
    /// [`BvhRef::closest_t_packet`] on the 4-wide kernels. The same hits
    /// either way.
    fn closest_hit_packet(&self, rays: &[Ray; crate::PACKET]) -> [Option<Hit>; crate::PACKET] {
        if matches!(self.isa, Isa::Avx2 | Isa::Avx512) {
            let mut stack = TraversalStack::new();
            return core::array::from_fn(|i| self.closest_hit_with(&rays[i], &mut stack));
        }
        let best = self.closest_t_packet(rays);
        // The same primitive's record whichever stored copy was found.
        core::array::from_fn(|i| best[i].and_then(|b| self.record(b, &rays[i])))
    }
}
