//! Packets: eight rays traced through the tree together.
//!
//! Rays that share most of their path — the camera rays of a small tile,
//! the shadow rays of neighbouring pixels toward one light — visit nearly
//! the same nodes. A packet visits each node once for all of them: one
//! fetch, one gather and sort of the children, one stack entry, with the
//! box test done for every ray still interested (each ray's own lanes, SIMD
//! across the rays); leaves are tested ray by ray with the single-ray
//! triangle test. This is the classic coherent-packet traversal (Wald,
//! Slusallek, Benthin & Wagner 2001, "Interactive rendering with coherent
//! ray tracing"), here on the 8-wide tree.
//!
//! Every ray's answer equals its single-ray query, bit for bit: each lane
//! of the box test does the single-ray test's arithmetic in the same order
//! (the NaN rule included), a ray enters a child only if its own test
//! passes, a subtree is skipped for a ray only where its single-ray
//! traversal would skip it too, and the closest hit does not depend on the
//! order hits are found (ties go to the lower primitive index). A packet
//! may visit a node for one ray that another ray did not need; that costs
//! time, never a different answer.

use core::mem::MaybeUninit;

use rt_core::{Ray, internal::widen_far};

use crate::{
    Isa, RayCtx,
    node::{ChildRef, GROUPS, Node, WIDTH},
    prim::{BestHit, Primitive, any_leaf, closest_leaf},
    ray_ctx::Fused,
    traverse::{BvhRef, STACK_SIZE, TraversalStack, TraversalStats},
};

/// Rays in a packet.
pub const PACKET: usize = 8;

/// A subtree that at most this many of a packet's rays still want is left
/// to the single-ray kernel, ray by ray: it tests a node's eight boxes for
/// one ray in one pass, where the packet would spend a pass per box.
const SPLIT: u32 = 3;

/// A packet's per-ray constants in structure-of-arrays form, for the box
/// test across rays; lanes of invalid rays hold zeros and are never active.
struct Lanes {
    ctx: [Option<RayCtx>; PACKET],
    org: [[f32; PACKET]; 3],
    inv: [[f32; PACKET]; 3],
    /// The far planes' reciprocals ([`RayCtx`]'s).
    inv_far: [[f32; PACKET]; 3],
    /// The far-distance widening factors ([`RayCtx`]'s `far_up`,
    /// `far_down`).
    far_up: [f32; PACKET],
    far_down: [f32; PACKET],
    /// Whether every valid ray has `t_min ≥ 0`: the box tests then skip
    /// the widening factors (all 1), as the single-ray test does.
    nonneg: bool,
    /// The direction's sign per axis and ray as a lane mask: −0.0 (sign
    /// bit set) where the direction's sign bit is set, else 0.0.
    neg_mask: [[f32; PACKET]; 3],
    t_min: [f32; PACKET],
    /// Rays that are valid ([`Ray::is_valid`]), one bit each.
    valid: u32,
}

impl Lanes {
    /// Always inlined into the kernels, which build their lanes
    /// themselves (see `closest_t_packet`); a plain loop, since
    /// `each_ref().map(…)` was left out of line.
    #[inline(always)]
    fn new(rays: &[Ray; PACKET]) -> Self {
        let mut ctx = [None; PACKET];
        for (c, r) in ctx.iter_mut().zip(rays) {
            *c = RayCtx::new(r);
        }
        let mut l = Self {
            ctx,
            org: [[0.0; PACKET]; 3],
            inv: [[0.0; PACKET]; 3],
            inv_far: [[0.0; PACKET]; 3],
            far_up: [1.0; PACKET],
            far_down: [1.0; PACKET],
            nonneg: true,
            neg_mask: [[0.0; PACKET]; 3],
            t_min: [0.0; PACKET],
            valid: 0,
        };
        for (r, c) in l.ctx.iter().enumerate() {
            if let Some(c) = c {
                l.valid |= 1 << r;
                for a in 0..3 {
                    l.org[a][r] = c.ray.origin[a];
                    l.inv[a][r] = c.inv1[a];
                    l.inv_far[a][r] = c.inv_far[a];
                    let neg = c.ray.direction[a].is_sign_negative();
                    l.neg_mask[a][r] = if neg { -0.0 } else { 0.0 };
                }
                l.t_min[r] = c.ray.t_min;
                (l.far_up[r], l.far_down[r]) = (c.far_up, c.far_down);
                l.nonneg &= c.ray.t_min >= 0.0;
            }
        }
        l
    }
}

/// `x` if `x > y`, else `y`: SSE's `maxps` (NaN in either gives `y`).
#[inline(always)]
fn max(x: f32, y: f32) -> f32 {
    if x > y { x } else { y }
}

/// `x` if `x < y`, else `y`: SSE's `minps`.
#[inline(always)]
fn min(x: f32, y: f32) -> f32 {
    if x < y { x } else { y }
}

/// The rays of a packet that enter child `c` of `node` within their own
/// `t_max` (one bit each), and their entry distances: per ray, exactly the
/// single-ray box test's arithmetic.
#[inline(always)]
fn child_test(node: &Node, c: usize, l: &Lanes, t_max: &[f32; PACKET]) -> (u32, [f32; PACKET]) {
    let (g, k) = (c / 4, c % 4);
    let b = &node.bounds;
    let mut t0 = [0.0f32; PACKET];
    let mut t1 = [0.0f32; PACKET];
    for r in 0..PACKET {
        let slab = |a: usize| {
            let (lo, hi) = (b[2 * a][g][k], b[2 * a + 1][g][k]);
            let neg = l.neg_mask[a][r].is_sign_negative();
            let (near, far) = if neg { (hi, lo) } else { (lo, hi) };
            ((near - l.org[a][r]) * l.inv[a][r], (far - l.org[a][r]) * l.inv_far[a][r])
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        t0[r] = max(nx, max(ny, max(nz, l.t_min[r])));
        t1[r] = if l.nonneg {
            min(fx, min(fy, min(fz, t_max[r])))
        } else {
            let f = min(fx, min(fy, min(fz, f32::INFINITY)));
            min(max(f * l.far_up[r], f * l.far_down[r]), t_max[r])
        };
    }
    let mut mask = 0;
    for r in 0..PACKET {
        mask |= u32::from(t0[r] <= t1[r]) << r;
    }
    (mask, t0)
}

/// [`child_test`] with the eight rays in the lanes of one AVX register:
/// the same arithmetic per lane.
///
/// # Safety
/// The CPU must have AVX (inlined into the AVX kernels only).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn child_test_avx(
    node: &Node,
    c: usize,
    l: &Lanes,
    t_max: &[f32; PACKET],
) -> (u32, [f32; PACKET]) {
    use crate::simd::{F32x8, Lanes as _};
    let (g, k) = (c / 4, c % 4);
    let b = &node.bounds;
    #[inline(always)]
    unsafe fn slab(lo: f32, hi: f32, l: &Lanes, a: usize) -> (F32x8, F32x8) {
        // SAFETY: the caller guarantees AVX.
        unsafe {
            let (lo, hi) = (F32x8::splat(lo), F32x8::splat(hi));
            let neg = F32x8::from_array(l.neg_mask[a]);
            let (near, far) = (lo.blend(hi, neg), hi.blend(lo, neg));
            let (o, inv) = (F32x8::from_array(l.org[a]), F32x8::from_array(l.inv[a]));
            let inv_far = F32x8::from_array(l.inv_far[a]);
            (near.sub(o).mul(inv), far.sub(o).mul(inv_far))
        }
    }
    // SAFETY: the caller guarantees AVX.
    unsafe {
        let (nx, fx) = slab(b[0][g][k], b[1][g][k], l, 0);
        let (ny, fy) = slab(b[2][g][k], b[3][g][k], l, 1);
        let (nz, fz) = slab(b[4][g][k], b[5][g][k], l, 2);
        let t0 = nx.max(ny.max(nz.max(F32x8::from_array(l.t_min))));
        if l.nonneg {
            let t1 = fx.min(fy.min(fz.min(F32x8::from_array(*t_max))));
            return (t0.le_mask(t1), t0.to_array());
        }
        let t1 = fx.min(fy.min(fz.min(F32x8::splat(f32::INFINITY))));
        let t1 = t1
            .mul(F32x8::from_array(l.far_up))
            .max(t1.mul(F32x8::from_array(l.far_down)))
            .min(F32x8::from_array(*t_max));
        (t0.le_mask(t1), t0.to_array())
    }
}

/// A packet traversal's stack: subtrees with the rays that still want them
/// and the nearest of their entry distances. Entries `0..sp` are written;
/// the others start uninitialized (a fresh stack costs nothing) and are
/// never read.
struct Stack {
    refs: [MaybeUninit<ChildRef>; STACK_SIZE],
    rays: [MaybeUninit<u8>; STACK_SIZE],
    ts: [MaybeUninit<f32>; STACK_SIZE],
    sp: usize,
}

impl Stack {
    #[inline(always)]
    fn new() -> Self {
        // Built field by field in place: `Self { refs: [uninit; N], …,
        // sp: 0 }` compiled to a 4 KB memset of zeros on every packet.
        let mut s = MaybeUninit::<Self>::uninit();
        // SAFETY: `sp` is written; every other field is an array of
        // `MaybeUninit`, for which uninitialized memory is a valid value.
        unsafe {
            core::ptr::addr_of_mut!((*s.as_mut_ptr()).sp).write(0);
            s.assume_init()
        }
    }

    #[inline(always)]
    fn push(&mut self, c: ChildRef, rays: u32, t: f32) {
        self.refs[self.sp].write(c);
        self.rays[self.sp].write(rays as u8);
        self.ts[self.sp].write(t);
        self.sp += 1;
    }

    /// Pops the top entry `(ref, rays, t)`; `None` when empty.
    #[inline(always)]
    fn pop(&mut self) -> Option<(ChildRef, u32, f32)> {
        self.sp = self.sp.checked_sub(1)?;
        let i = self.sp;
        // SAFETY: `push` wrote all three arrays at every index below the
        // count it keeps.
        Some(unsafe {
            (
                self.refs[i].assume_init(),
                u32::from(self.rays[i].assume_init()),
                self.ts[i].assume_init(),
            )
        })
    }
}

/// The children of `node` some ray of `rays` enters: `(count, refs, ray
/// masks, nearest entry distances)`, sorted by entry distance, farthest
/// first.
#[inline(always)]
fn hit_children<const AVX: bool>(
    node: &Node,
    l: &Lanes,
    rays: u32,
    bound: &[f32; PACKET],
) -> (usize, [ChildRef; WIDTH], [u32; WIDTH], [f32; WIDTH]) {
    const { assert!(GROUPS * 4 == WIDTH) };
    let mut refs = [ChildRef::EMPTY; WIDTH];
    let mut masks = [0u32; WIDTH];
    let mut ts = [0.0f32; WIDTH];
    let mut k = 0;
    for c in 0..WIDTH {
        let child = node.children[c];
        if child.is_empty() {
            continue;
        }
        #[cfg(target_arch = "x86_64")]
        let (m, t0) = if AVX {
            // SAFETY: `AVX` kernels are instantiated only inside functions
            // compiled with AVX, entered after `Isa::is_available`.
            unsafe { child_test_avx(node, c, l, bound) }
        } else {
            child_test(node, c, l, bound)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let (m, t0) = child_test(node, c, l, bound);
        let m = m & rays;
        if m == 0 {
            continue;
        }
        let mut t = f32::INFINITY;
        let mut bits = m;
        while bits != 0 {
            let r = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            t = t.min(t0[r]);
        }
        // Insertion, farthest first.
        let mut j = k;
        while j > 0 && ts[j - 1] < t {
            refs[j] = refs[j - 1];
            masks[j] = masks[j - 1];
            ts[j] = ts[j - 1];
            j -= 1;
        }
        refs[j] = child;
        masks[j] = m;
        ts[j] = t;
        k += 1;
    }
    (k, refs, masks, ts)
}

impl<P: Primitive> BvhRef<'_, P> {
    /// The closest hits of eight rays traced as a packet: `out[i]` has the
    /// `t` and primitive of [`BvhRef::closest_t`]`(&rays[i])`, bit for bit
    /// (its `item` and `lane` may name another reference to the same
    /// primitive, where a build stored it twice). Fastest when the
    /// rays are coherent (a 4 × 2 or 8 × 1 tile of camera rays, shadow rays
    /// of neighbouring pixels); pad a short packet with invalid rays
    /// (e.g. a NaN origin), which miss. No allocation.
    #[must_use]
    pub fn closest_t_packet(&self, rays: &[Ray; PACKET]) -> [Option<BestHit>; PACKET] {
        // The kernels build the rays' constants themselves: built here and
        // read back there at once, they would go through memory.
        let best = match self.isa {
            // SAFETY: `self.isa` passed `Isa::is_available`: the CPU has the
            // features these kernels enable.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.closest_packet_avx512(rays) },
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.closest_packet_avx2(rays) },
            _ => self.closest_packet_kernel::<false>(rays),
        };
        core::array::from_fn(|r| best[r].is_hit().then_some(best[r]))
    }

    /// Whether each of eight rays, traced as a packet, hits anything:
    /// `out[i]` equals [`BvhRef::occluded`]`(&rays[i])`. A ray stops at the
    /// first hit found; the packet when every ray has. No allocation.
    #[must_use]
    pub fn occluded_packet(&self, rays: &[Ray; PACKET]) -> [bool; PACKET] {
        let hit = match self.isa {
            // SAFETY: as in `closest_t_packet`.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => unsafe { self.occluded_packet_avx512(rays) },
            // SAFETY: as in `closest_t_packet`.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => unsafe { self.occluded_packet_avx2(rays) },
            _ => self.occluded_packet_kernel::<false>(rays),
        };
        core::array::from_fn(|r| hit & (1 << r) != 0)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma")]
    fn closest_packet_avx2(&self, rays: &[Ray; PACKET]) -> [BestHit; PACKET] {
        self.closest_packet_kernel::<true>(rays)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,avx512f,avx512vl")]
    fn closest_packet_avx512(&self, rays: &[Ray; PACKET]) -> [BestHit; PACKET] {
        self.closest_packet_kernel::<true>(rays)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma")]
    fn occluded_packet_avx2(&self, rays: &[Ray; PACKET]) -> u32 {
        self.occluded_packet_kernel::<true>(rays)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx,avx2,fma,avx512f,avx512vl")]
    fn occluded_packet_avx512(&self, rays: &[Ray; PACKET]) -> u32 {
        self.occluded_packet_kernel::<true>(rays)
    }

    /// Front to back by the nearest entry distance of the rays that want a
    /// subtree; a popped subtree keeps only the rays whose best hit may
    /// still lie beyond that distance.
    #[inline(always)]
    fn closest_packet_kernel<const AVX: bool>(&self, rays: &[Ray; PACKET]) -> [BestHit; PACKET] {
        let l = &Lanes::new(rays);
        let mut best: [BestHit; PACKET] = core::array::from_fn(|r| {
            BestHit::new(l.ctx[r].as_ref().map_or(f32::NEG_INFINITY, |c| c.ray.t_max))
        });
        if self.nodes.is_empty() || l.valid == 0 {
            return best;
        }
        let mut stack = Stack::new();
        let mut single = TraversalStack::new();
        let (mut cur, mut rays) = (ChildRef::inner(0), l.valid);
        'walk: loop {
            if !cur.is_leaf() && rays.count_ones() <= SPLIT {
                // Few rays left in this subtree: the single-ray kernel tests
                // a node's eight boxes for one ray in one pass.
                let mut bits = rays;
                while bits != 0 {
                    let r = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if let Some(ctx) = &l.ctx[r] {
                        let mut stats = TraversalStats::default();
                        best[r] = self.closest_from::<AVX, false, false>(
                            ctx,
                            &Fused::OFF,
                            cur,
                            best[r],
                            &mut stats,
                            &mut single,
                        );
                    }
                }
            } else if cur.is_leaf() {
                let (first, count) = cur.leaf_range();
                let mut bits = rays;
                while bits != 0 {
                    let r = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if let Some(ctx) = &l.ctx[r] {
                        closest_leaf::<_, AVX>(self.leaf(first, count), first, ctx, &mut best[r]);
                    }
                }
            } else {
                let node = self.node(cur);
                let bound: [f32; PACKET] = core::array::from_fn(|r| widen_far(best[r].t));
                let (k, refs, masks, ts) = hit_children::<AVX>(node, l, rays, &bound);
                if k > 0 {
                    for a in 0..k - 1 {
                        stack.push(refs[a], masks[a], ts[a]);
                    }
                    cur = refs[k - 1];
                    rays = masks[k - 1];
                    continue 'walk;
                }
            }
            // Pop the next subtree some ray may still find a closer hit in.
            loop {
                let Some((r_top, mut bits, t)) = stack.pop() else {
                    break 'walk;
                };
                let mut keep = 0;
                while bits != 0 {
                    let r = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if t <= widen_far(best[r].t) {
                        keep |= 1 << r;
                    }
                }
                if keep != 0 {
                    cur = r_top;
                    rays = keep;
                    continue 'walk;
                }
            }
        }
        best
    }

    /// Any hit ends a ray; the packet ends when every ray has.
    #[inline(always)]
    fn occluded_packet_kernel<const AVX: bool>(&self, rays: &[Ray; PACKET]) -> u32 {
        let l = &Lanes::new(rays);
        let mut done = 0u32;
        if self.nodes.is_empty() || l.valid == 0 {
            return done;
        }
        // Widened as in the single-ray occlusion test.
        let bound: [f32; PACKET] =
            core::array::from_fn(|r| l.ctx[r].as_ref().map_or(0.0, |c| widen_far(c.ray.t_max)));
        let mut stack = Stack::new();
        let mut single = TraversalStack::new();
        let (mut cur, mut rays) = (ChildRef::inner(0), l.valid);
        loop {
            if !cur.is_leaf() && rays.count_ones() <= SPLIT {
                // Few rays left in this subtree: the single-ray kernel.
                let mut bits = rays;
                while bits != 0 {
                    let r = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if let Some(ctx) = &l.ctx[r]
                        && self.occluded_from::<AVX, false, false>(
                            ctx,
                            &Fused::OFF,
                            cur,
                            &mut single,
                        )
                    {
                        done |= 1 << r;
                    }
                }
                if done == l.valid {
                    return done;
                }
            } else if cur.is_leaf() {
                let (first, count) = cur.leaf_range();
                let mut bits = rays;
                while bits != 0 {
                    let r = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    if let Some(ctx) = &l.ctx[r] {
                        let t_max = ctx.ray.t_max;
                        if any_leaf::<P, AVX>(self.leaf(first, count), ctx, t_max) {
                            done |= 1 << r;
                        }
                    }
                }
                if done == l.valid {
                    return done;
                }
            } else {
                let node = self.node(cur);
                let (k, refs, masks, ts) = hit_children::<AVX>(node, l, rays, &bound);
                for a in 0..k {
                    stack.push(refs[a], masks[a], ts[a]);
                }
            }
            loop {
                let Some((r_top, bits, _)) = stack.pop() else {
                    return done;
                };
                let keep = bits & !done;
                if keep != 0 {
                    cur = r_top;
                    rays = keep;
                    break;
                }
            }
        }
    }
}
