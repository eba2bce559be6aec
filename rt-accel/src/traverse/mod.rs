//! Closest-hit and occlusion traversal of a borrowed BVH: no std, no
//! allocation, a fixed stack.

use core::mem::MaybeUninit;

use rt_core::{Aabb, Hit, Ray, SceneQuery, internal::widen_far};

use crate::{
    Isa, RayCtx, UnsupportedIsa,
    node::{ChildRef, GROUPS, Node, WIDTH},
    prim::{BestHit, Primitive, any_leaf, closest_leaf},
    ray_ctx::Fused,
    simd::{prefetch_bytes, prefetch_line},
};

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
    /// traversal's chain, see `node.rs`).
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

/// Pushes `(r, t)` onto a closest-hit traversal's stack of height `sp`,
/// unchecked: the stack is never full there. Every entry on it is a child
/// of an inner node on the path from the root to the subtree being
/// visited, at most `WIDTH − 1` per node (the visited child is not
/// pushed), and that path holds at most [`MAX_DEPTH`] inner nodes
/// (builders and `validate` reject deeper trees; `BvhRef`'s invariant). So
/// the height stays at most `(WIDTH − 1) · MAX_DEPTH < STACK_SIZE`.
#[inline(always)]
fn push(
    refs: &mut [MaybeUninit<ChildRef>; STACK_SIZE],
    ts: &mut [MaybeUninit<f32>; STACK_SIZE],
    sp: &mut usize,
    r: ChildRef,
    t: f32,
) {
    debug_assert!(*sp < STACK_SIZE);
    // SAFETY: `sp < STACK_SIZE`, by the bound above.
    unsafe {
        refs.get_unchecked_mut(*sp).write(r);
        ts.get_unchecked_mut(*sp).write(t);
    }
    *sp += 1;
}

/// Where a closest-hit traversal stands between two steps: the subtree to
/// visit next, the stack height and the best hit so far.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Walk {
    pub(crate) cur: ChildRef,
    pub(crate) sp: usize,
    pub(crate) best: BestHit,
}

/// Writes the children of `node` named by `mask` (not 0) to
/// `stack[sp..]` in slot order. The entry for the last may be written or
/// not (the caller visits it next); with `AVX` entries up to
/// `sp + WIDTH` are (garbage past the children).
#[inline(always)]
fn push_children<const AVX: bool>(
    stack: &mut [MaybeUninit<ChildRef>; STACK_SIZE],
    sp: usize,
    node: &Node,
    mask: u32,
) {
    // Each level leaves at most `WIDTH − 1` entries and `validate` bounds
    // the depth by `MAX_DEPTH`, so a node is reached with `sp ≤ (WIDTH −
    // 1)·(MAX_DEPTH − 1)` and the second test always holds.
    #[cfg(target_arch = "x86_64")]
    if AVX && sp + WIDTH <= STACK_SIZE {
        // SAFETY: `AVX` kernels run only where the CPU has AVX2 (see
        // `box_test`); the `WIDTH` entries from `sp` lie in the stack.
        unsafe { push_hit_children(stack.as_mut_ptr().add(sp), node, mask) };
        return;
    }
    let (mut m, mut k) = (mask, sp);
    while m != 0 {
        let i = m.trailing_zeros() as usize;
        m &= m - 1;
        stack[k].write(node.children[i]);
        k += 1;
    }
}

/// For each 8-bit child mask, the slots of its set bits in order, padded
/// with slot 0: the permutation that packs a node's hit children together.
#[cfg(target_arch = "x86_64")]
static COMPRESS: [[u32; WIDTH]; 1 << WIDTH] = compress_table(false);

/// The packing permutations for every 8-bit mask: the slots of its set
/// bits in ascending order (`descending`: from the highest down), padded
/// with slot 0.
#[cfg(target_arch = "x86_64")]
pub(crate) const fn compress_table(descending: bool) -> [[u32; WIDTH]; 1 << WIDTH] {
    let mut t = [[0u32; WIDTH]; 1 << WIDTH];
    let mut m = 0;
    while m < 1 << WIDTH {
        let (mut k, mut j) = (0, 0);
        while j < WIDTH {
            let i = if descending { WIDTH - 1 - j } else { j };
            if m & (1 << i) != 0 {
                t[m][k] = i as u32;
                k += 1;
            }
            j += 1;
        }
        m += 1;
    }
    t
}

/// Writes the children of `node` named by `mask` to `out[0..popcount]`
/// in slot order, with one 8-lane permute and store and no branch (the
/// loop over set bits mispredicted its exit at every node). All `WIDTH`
/// entries of `out` are written; those past the count are garbage.
///
/// # Safety
/// The CPU must have AVX2, and `out` must be valid for `WIDTH` writes.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn push_hit_children(out: *mut MaybeUninit<ChildRef>, node: &Node, mask: u32) {
    use core::arch::x86_64::{
        __m256i, _mm256_loadu_si256, _mm256_permutevar8x32_epi32, _mm256_storeu_si256,
    };
    debug_assert!(mask < 1 << WIDTH);
    // SAFETY: the caller guarantees AVX2 and `out`; `node.children` is
    // `WIDTH` u32s (32 bytes, read unaligned); `mask & 0xff` indexes the
    // table.
    unsafe {
        let kids = _mm256_loadu_si256(node.children.as_ptr().cast::<__m256i>());
        let perm = COMPRESS.get_unchecked((mask & 0xff) as usize);
        let perm = _mm256_loadu_si256(perm.as_ptr().cast::<__m256i>());
        _mm256_storeu_si256(out.cast::<__m256i>(), _mm256_permutevar8x32_epi32(kids, perm));
    }
}

/// Writes the children of `node` named by `mask` (three or more) to
/// `refs[0..k − 1]` and their entry distances `tnear` to `ts[0..k − 1]`,
/// farthest first, and returns the nearest, which is not pushed: what the
/// closest-hit step's insertion sort does, without its branches (which
/// mispredict for rays of random direction). The lanes' keys are the
/// distances' bits (every fused entry distance is `+0` or positive, so they
/// order as the floats) with the slot in the low three bits, which breaks
/// ties and lets the sorted keys name their slots; the lanes missed sort
/// last as `i32::MIN`. Batcher's odd–even merge sort (19 comparators in
/// six layers), and the nearest found by a minimum over the lanes beside
/// it, so the next node's address does not wait for the sort. All `WIDTH`
/// entries of both outputs are written; those past `k − 1` are garbage.
/// Keys ignore the low three bits of the distances, so two children
/// within 8 ulps may be visited in either order: the traversal's result
/// does not depend on the order, and the distances pushed are exact.
///
/// # Safety
/// The CPU must have AVX2; `refs` and `ts` must be valid for `WIDTH`
/// writes; every entry distance named by `mask` must have its sign bit
/// clear (the fused test's).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn push_sorted(
    refs: *mut MaybeUninit<ChildRef>,
    ts: *mut MaybeUninit<f32>,
    node: &Node,
    mask: u32,
    tnear: &[f32; WIDTH],
) -> ChildRef {
    use core::arch::x86_64::*;
    /// One layer of comparators `(i, j)`, `i < j`: lane `i` takes the
    /// larger key and `j` the smaller; `w` is the keys permuted so each
    /// lane sees its partner, `MAX` has the bits of the lanes `i`.
    #[inline(always)]
    unsafe fn layer<const MAX: i32>(v: __m256i, w: __m256i) -> __m256i {
        // SAFETY: the caller guarantees AVX2.
        unsafe { _mm256_blend_epi32::<MAX>(_mm256_min_epi32(v, w), _mm256_max_epi32(v, w)) }
    }
    // SAFETY: the caller guarantees AVX2 and the outputs; `tnear` and
    // `node.children` are `WIDTH` 32-bit values (32 bytes, read unaligned).
    unsafe {
        let t = _mm256_loadu_si256(tnear.as_ptr().cast::<__m256i>());
        let slot = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let bit = _mm256_sllv_epi32(_mm256_set1_epi32(1), slot);
        let hit = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bit), bit);
        let key = _mm256_or_si256(_mm256_and_si256(t, _mm256_set1_epi32(!7)), slot);
        // The nearest: the smallest key of the lanes entered.
        let m = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MAX), key, hit);
        let m = _mm256_min_epi32(m, _mm256_permute2x128_si256::<1>(m, m));
        let m = _mm256_min_epi32(m, _mm256_shuffle_epi32::<0b01_00_11_10>(m));
        let m = _mm256_min_epi32(m, _mm256_shuffle_epi32::<0b10_11_00_01>(m));
        let nearest = (_mm256_cvtsi256_si32(m) & 7) as usize;
        // The keys in descending order.
        let v = _mm256_blendv_epi8(_mm256_set1_epi32(i32::MIN), key, hit);
        // (0,1) (2,3) (4,5) (6,7)
        let v = layer::<0b0101_0101>(v, _mm256_shuffle_epi32::<0b10_11_00_01>(v));
        // (0,2) (1,3) (4,6) (5,7)
        let v = layer::<0b0011_0011>(v, _mm256_shuffle_epi32::<0b01_00_11_10>(v));
        // (1,2) (5,6)
        let v = layer::<0b0010_0010>(v, _mm256_shuffle_epi32::<0b11_01_10_00>(v));
        // (0,4) (1,5) (2,6) (3,7)
        let v = layer::<0b0000_1111>(v, _mm256_permute2x128_si256::<1>(v, v));
        // (2,4) (3,5)
        let v = layer::<0b0000_1100>(v, _mm256_permute4x64_epi64::<0b11_01_10_00>(v));
        // (1,2) (3,4) (5,6)
        let w = _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 1, 4, 3, 6, 5, 7));
        let v = layer::<0b0010_1010>(v, w);
        let order = _mm256_and_si256(v, _mm256_set1_epi32(7));
        let kids = _mm256_loadu_si256(node.children.as_ptr().cast::<__m256i>());
        _mm256_storeu_si256(refs.cast::<__m256i>(), _mm256_permutevar8x32_epi32(kids, order));
        _mm256_storeu_si256(ts.cast::<__m256i>(), _mm256_permutevar8x32_epi32(t, order));
        *node.children.get_unchecked(nearest)
    }
}

/// The node test of kernel `AVX` (see [`box_test_avx`]) or the 4-wide one.
///
/// The test is the primitives' own box check's arithmetic
/// ([`rt_core::Aabb::admits_hit`]), lane for lane, which is why a BVH
/// finds exactly a brute-force loop's hits. Rays with `t_min ≥ 0` compute
/// their far distances with the reciprocal scaled by
/// [`rt_core::internal::FAR_INV_SCALE`]; other rays widen the smallest far
/// distance by its sign ([`rt_core::internal::widen_far`]), through the
/// ray's `far_up` and `far_down` (both 1 for the first kind, so the
/// general form is right for every ray).
///
/// `NONNEG`: the caller knows the ray has `t_min ≥ 0` (the kernels pick
/// it per ray), and the mask is one compare, `t0 ≤ min(t1x, t1y, t1z,
/// t_max)`, instead of two multiplies, three compares and two logical
/// operations.
///
/// `FUSED` (AVX kernels only; `fz.on` must hold): the fused test
/// ([`box_lanes_fused`]), one multiply-add per plane, admitting every box
/// the robust test admits (and a sliver more), so the hits are the same.
/// The single-ray kernels pick it per ray, at entry: chosen per node
/// instead, a branch on `fz.on` sits on every node step.
#[inline(always)]
pub(crate) fn box_test<const AVX: bool, const NONNEG: bool, const FUSED: bool>(
    node: &Node,
    ctx: &RayCtx,
    fz: &Fused,
    t_max: f32,
) -> (u32, [f32; WIDTH]) {
    #[cfg(target_arch = "x86_64")]
    if AVX {
        // SAFETY: `AVX` kernels are instantiated only inside the functions
        // compiled with AVX enabled (`closest_avx2`, …), which are called
        // only when `Isa::is_available` found the CPU has it.
        return unsafe { box_test_avx::<NONNEG, FUSED>(node, ctx, fz, t_max) };
    }
    let _ = fz;
    box_test_x4::<NONNEG>(node, ctx, t_max)
}

/// Tests the ray against a node's boxes (Ize 2013's robust slab test, see
/// [`rt_core::Aabb::intersect_ray`]), four per 4-wide pass. Returns the
/// mask of boxes entered within `[t_min, t_max]` and the entry distances.
#[inline(always)]
fn box_test_x4<const NONNEG: bool>(node: &Node, ctx: &RayCtx, t_max: f32) -> (u32, [f32; WIDTH]) {
    use crate::simd::F32x4;
    let b = &node.bounds;
    let t_max = F32x4::splat(t_max);
    let mut mask = 0;
    let mut tnear = [0.0f32; WIDTH];
    for g in 0..GROUPS {
        let slab = |a: usize| {
            let (near, far) = ctx.planes(b, a);
            let o = ctx.org4(a);
            let near = F32x4::from_array(near[g]).sub(o).mul(ctx.inv4(a));
            let far = F32x4::from_array(far[g]).sub(o).mul(ctx.inv_far4(a));
            (near, far)
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        // `x.max(acc)` keeps `acc` when `x` is NaN (a ray in a slab plane).
        let t0 = nx.max(ny.max(nz.max(F32x4::splat(ctx.ray.t_min))));
        let m = if NONNEG {
            // The far distances are widened already (`FAR_INV_SCALE`).
            t0.le_mask(fx.min(fy.min(fz.min(t_max))))
        } else {
            let t1 = fx.min(fy.min(fz.min(F32x4::splat(f32::INFINITY))));
            // Widen outward whatever the sign (rt_core::internal::widen_far;
            // by 1 where `inv_far` widened already): `t0 ≤ min(max(t1·up,
            // t1·down), t_max)` as three compares (no value is NaN), as the
            // AVX kernels do.
            let (up, down) = (t1.mul(F32x4::splat(ctx.far_up)), t1.mul(F32x4::splat(ctx.far_down)));
            (t0.le_mask(up) | t0.le_mask(down)) & t0.le_mask(t_max)
        };
        mask |= m << (4 * g);
        tnear[4 * g..4 * g + 4].copy_from_slice(&t0.to_array());
    }
    (mask, tnear)
}

/// [`box_test_x4`] in one AVX pass over all eight children: identical
/// arithmetic, lane for lane.
///
/// # Safety
/// The CPU must have AVX (AVX2 and FMA for `FUSED`). Always inlined, into
/// the kernels compiled with them.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn box_test_avx<const NONNEG: bool, const FUSED: bool>(
    node: &Node,
    ctx: &RayCtx,
    fz: &Fused,
    t_max: f32,
) -> (u32, [f32; WIDTH]) {
    // SAFETY: the caller guarantees AVX.
    unsafe {
        let (entered, t0) = box_lanes_avx::<NONNEG, FUSED>(node, ctx, fz, t_max);
        (entered.sign_mask(), t0.to_array())
    }
}

/// The fused node test: per plane one multiply-add with the ray's
/// [`crate::ray_ctx::Fused`] constants, where the robust test takes a
/// subtraction and a multiply on the dependent chain. It admits every box
/// the robust test admits (the proof is at `Fused`), so the hits are the
/// same, bit for bit.
///
/// The maxima, minima and the final compare take the distances' bits as
/// signed integers (one cycle each on the chain where the float
/// instructions take four; Embree's AVX2 kernels do the same). No
/// distance is NaN, and the range's ends are made `+0` where they are
/// `−0`, so:
/// - the entry `t0`, a maximum with `t_min` (sign bit clear), is the float
///   maximum: integers order floats with a clear sign bit as floats, and
///   put every float with the sign bit set below them;
/// - if no far distance has its sign bit set, the exit `t1` is the float
///   minimum and `t0 > t1` compares as floats; if one has (`−0`
///   included), `t1` is negative as an integer and the box is missed.
///
/// That differs from the float test only in boxes it misses with an exit
/// at `−0`, which the robust test misses too: where that test admits a
/// box, every fused far distance is the rounding of a positive number
/// (`Fused`'s proof), so its sign bit is clear.
///
/// # Safety
/// The CPU must have AVX2 and FMA; `f` must be on (the test covers the ray
/// and the BVH).
/// Always inlined, into the kernels compiled with them.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn box_lanes_fused(
    b: &[[[f32; 4]; 2]; 6],
    ctx: &RayCtx,
    f: &Fused,
    t_max: f32,
) -> (crate::simd::F32x8, crate::simd::F32x8) {
    // SAFETY: the caller guarantees AVX, AVX2 and FMA, and `f`.
    unsafe { fused_lanes(&fused_rows(b, ctx), ctx, f, t_max) }
}

/// The six plane rows of `b` that [`box_lanes_fused`] tests for a ray with
/// `ctx`'s direction signs, as lanes: the near and far rows of x, y, z.
/// Rays of one direction octant test the same rows, so an occlusion
/// stream group of such rays loads them once a node.
///
/// # Safety
/// The CPU must have AVX. Always inlined.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn fused_rows(b: &[[[f32; 4]; 2]; 6], ctx: &RayCtx) -> [crate::simd::F32x8; 6] {
    use crate::simd::F32x8;
    let (nx, fx) = ctx.planes(b, 0);
    let (ny, fy) = ctx.planes(b, 1);
    let (nz, fz) = ctx.planes(b, 2);
    [nx, fx, ny, fy, nz, fz].map(|r| F32x8::from_groups(*r))
}

/// [`box_lanes_fused`] on rows loaded already ([`fused_rows`], for a ray
/// of `ctx`'s octant).
///
/// # Safety
/// As [`box_lanes_fused`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn fused_lanes(
    rows: &[crate::simd::F32x8; 6],
    ctx: &RayCtx,
    f: &Fused,
    t_max: f32,
) -> (crate::simd::F32x8, crate::simd::F32x8) {
    use crate::simd::{F32x8, Lanes as _};
    debug_assert!(f.on);
    // A function, not a closure (see `box_lanes_avx`).
    #[inline(always)]
    unsafe fn slab(rows: &[F32x8; 6], f: &Fused, a: usize) -> (F32x8, F32x8) {
        // SAFETY: the caller guarantees AVX and FMA.
        unsafe {
            let near =
                rows[2 * a].mul_add(F32x8::splat(f.inv_near[a]), F32x8::splat(f.off_near[a]));
            let far =
                rows[2 * a + 1].mul_add(F32x8::splat(f.inv_far[a]), F32x8::splat(f.off_far[a]));
            (near, far)
        }
    }
    // SAFETY: the caller guarantees AVX, AVX2 and FMA.
    unsafe {
        let (nx, fx) = slab(rows, f, 0);
        let (ny, fy) = slab(rows, f, 1);
        let (nz, fz) = slab(rows, f, 2);
        // The range's ends with their sign bits clear: `t_max` with `−0`
        // made `+0` here, `t_min` by `RayCtx`.
        let t_min = F32x8::splat(ctx.ray.t_min);
        let t_max = F32x8::splat(t_max).max_bits(F32x8::splat(0.0));
        let t0 = nx.max_bits(ny).max_bits(nz.max_bits(t_min));
        let t1 = fx.min_bits(fy).min_bits(fz.min_bits(t_max));
        let missed = t0.gt_bits(t1);
        (missed.xor(F32x8::splat_bits(u32::MAX)), t0)
    }
}

/// [`box_test_avx`] as lanes: all ones in the lanes of the boxes entered,
/// and the entry distances.
///
/// # Safety
/// The CPU must have AVX (AVX2 and FMA for `FUSED`). Always inlined, into
/// the kernels compiled with them.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn box_lanes_avx<const NONNEG: bool, const FUSED: bool>(
    node: &Node,
    ctx: &RayCtx,
    fz: &Fused,
    t_max: f32,
) -> (crate::simd::F32x8, crate::simd::F32x8) {
    use crate::simd::{F32x8, Lanes as _};
    const { assert!(GROUPS == 2) };
    let b = &node.bounds;
    // Near and far distances to the planes of axis `a` (a function, not a
    // closure: closures are not always inlined, and an out-of-line call
    // would pass the 256-bit lanes through memory).
    #[inline(always)]
    unsafe fn slab(b: &[[[f32; 4]; 2]; 6], ctx: &RayCtx, a: usize) -> (F32x8, F32x8) {
        // SAFETY: the caller guarantees AVX.
        unsafe {
            let (o, inv) = (F32x8::splat(ctx.ray.origin[a]), F32x8::splat(ctx.inv1[a]));
            let inv_far = F32x8::splat(ctx.inv_far[a]);
            let (near, far) = ctx.planes(b, a);
            let near = F32x8::from_groups(*near).sub(o).mul(inv);
            let far = F32x8::from_groups(*far).sub(o).mul(inv_far);
            (near, far)
        }
    }
    // SAFETY: the caller guarantees AVX.
    unsafe {
        if FUSED {
            return box_lanes_fused(b, ctx, fz, t_max);
        }
        let (nx, fx) = slab(b, ctx, 0);
        let (ny, fy) = slab(b, ctx, 1);
        let (nz, fz) = slab(b, ctx, 2);
        let t0 = nx.max(ny.max(nz.max(F32x8::splat(ctx.ray.t_min))));
        if NONNEG {
            // The far distances are widened already (`FAR_INV_SCALE`).
            return (t0.le(fx.min(fy.min(fz.min(F32x8::splat(t_max))))), t0);
        }
        let t1 = fx.min(fy.min(fz.min(F32x8::splat(f32::INFINITY))));
        // `t0 ≤ min(max(t1·up, t1·down), t_max)` as three compares side by
        // side (none of the values is NaN: the same mask, a shorter chain).
        let up = t1.mul(F32x8::splat(ctx.far_up));
        let down = t1.mul(F32x8::splat(ctx.far_down));
        let entered = t0.le(up).or(t0.le(down)).and(t0.le(F32x8::splat(t_max)));
        (entered, t0)
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

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use core::mem::MaybeUninit;

    use super::{ChildRef, Node, WIDTH, push_sorted};
    use crate::{Isa, ray_ctx::tests::Bits};

    /// The branch-free sorted push: every mask of three or more children,
    /// distances drawn with ties (equal, and within the 8 ulps its keys
    /// ignore) and zeros; each child but the nearest pushed once, with its
    /// own distance, by descending key.
    #[test]
    fn sorted_push_pushes_every_child_but_the_nearest_farthest_first() {
        if !Isa::Avx2.is_available() {
            return;
        }
        let mut g = Bits(0x51ed_270b_2a3f_6c49);
        let mut node = Node::EMPTY;
        for slot in 0..WIDTH {
            node.children[slot] = ChildRef::inner(slot as u32 + 1);
        }
        for mask in (0u32..1 << WIDTH).filter(|m| m.count_ones() >= 3) {
            for _ in 0..64 {
                let base = g.unit() * 4.0;
                let tnear: [f32; WIDTH] = core::array::from_fn(|_| match g.next() % 4 {
                    0 => 0.0,
                    1 => base,
                    2 => f32::from_bits(base.to_bits() + (g.next() % 8) as u32),
                    _ => g.unit() * 4.0,
                });
                let mut refs = [MaybeUninit::<ChildRef>::uninit(); WIDTH];
                let mut ts = [MaybeUninit::<f32>::uninit(); WIDTH];
                // SAFETY: the CPU has AVX2 (checked above); both outputs
                // hold `WIDTH` entries; the distances are non-negative.
                let near =
                    unsafe { push_sorted(refs.as_mut_ptr(), ts.as_mut_ptr(), &node, mask, &tnear) };
                let k = mask.count_ones() as usize;
                // SAFETY: all `WIDTH` entries are written.
                let (refs, ts) =
                    unsafe { (refs.map(|r| r.assume_init()), ts.map(|t| t.assume_init())) };
                let slot = |r: ChildRef| r.index() - 1;
                // A child's key: its distance's bits above the low three,
                // then its slot.
                let key = |s: usize| tnear[s].to_bits() & !7 | s as u32;
                // The nearest is the child entered with the least key.
                let least = (0..WIDTH).filter(|&i| mask >> i & 1 == 1).min_by_key(|&i| key(i));
                assert_eq!(Some(slot(near)), least, "{mask:#b} {tnear:?}");
                // The others once each, with their own distances, by
                // descending key.
                let mut seen = 1u32 << slot(near);
                for e in 0..k - 1 {
                    let s = slot(refs[e]);
                    assert!(mask >> s & 1 == 1 && seen >> s & 1 == 0, "{mask:#b} {refs:?}");
                    seen |= 1 << s;
                    assert_eq!(ts[e].to_bits(), tnear[s].to_bits());
                    let next = if e + 1 < k - 1 { slot(refs[e + 1]) } else { slot(near) };
                    assert!(key(s) > key(next), "{mask:#b} {tnear:?} {refs:?}");
                }
                assert_eq!(seen, mask);
            }
        }
    }
}
