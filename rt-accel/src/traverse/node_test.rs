//! Ray against a node's eight child boxes: the robust slab test (four
//! lanes at a time, or eight with AVX) and the fused one-multiply-add test
//! the single-ray kernels pick where it holds.

use crate::{
    RayCtx,
    node::{GROUPS, Node, WIDTH},
    ray_ctx::Fused,
};

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
pub(super) fn box_test_x4<const NONNEG: bool>(
    node: &Node,
    ctx: &RayCtx,
    t_max: f32,
) -> (u32, [f32; WIDTH]) {
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
pub(super) unsafe fn box_test_avx<const NONNEG: bool, const FUSED: bool>(
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
