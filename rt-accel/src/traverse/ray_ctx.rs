//! Per-ray constants shared by the box tests and the leaf tests.

use rt_core::{
    Ray,
    internal::{FAR_INV_SCALE, SLAB_FAR_SCALE, SLAB_FAR_SCALE_NEG, widen_far},
    intersect::WatertightRay,
};

use crate::{node::GROUPS, simd::F32x4};

/// One row of a node's bounds: one plane of every child.
type Row = [[f32; 4]; GROUPS];
/// A node's bounds (`Node::bounds`).
type Rows = [Row; 6];
/// Bytes per row (32).
const ROW: u8 = size_of::<Row>() as u8;

/// Everything a traversal precomputes once per ray: the reciprocal
/// direction, the near/far plane selection by direction sign, and the
/// watertight triangle shear. Scalars only (100 bytes): kernels broadcast
/// them into SIMD lanes where they use them, which costs one load each,
/// while splatting them here made the context five times larger and its
/// construction a third of a missed ray's cost.
#[derive(Clone, Copy, Debug)]
pub struct RayCtx {
    /// The ray, with `t_min = +0` where it was `−0` (the same range: the
    /// fused node test compares bits, and wants a clear sign bit).
    pub(crate) ray: Ray,
    /// Reciprocal direction per axis (`±∞` for `±0`).
    pub(crate) inv1: glam::Vec3A,
    /// The far planes' reciprocal: `inv1 · FAR_INV_SCALE` for rays with
    /// `t_min ≥ 0` ([`rt_core::internal::FAR_INV_SCALE`]), else `inv1`.
    pub(crate) inv_far: glam::Vec3A,
    /// The factors that widen the smallest far distance upward and
    /// downward (`max` of the two products, [`widen_far`]): the Ize
    /// scales for rays with `t_min < 0`, `1` for the others (whose far
    /// distances are widened by `inv_far` already). Box tests that do not
    /// know a ray's kind use them; those that know skip them (`NONNEG`).
    pub(crate) far_up: f32,
    /// See `far_up`.
    pub(crate) far_down: f32,
    /// Byte offsets in `Node::bounds` of the rows holding the near plane
    /// per axis (entries 0–2: row `2·axis + sign bit`, 32 bytes a row)
    /// and the far plane per axis (entries 4–6); entries 3 and 7 are 0.
    /// Offsets, not rows, so a node test adds them to the node's address
    /// without a shift (six fewer instructions a node); eight bytes, so
    /// the setup copies them in one load and one store.
    pub(crate) rows: [u8; 8],
    /// Watertight shear constants for triangles.
    pub(crate) wt: WatertightRay,
    /// Origin permuted to `[kx, ky, kz]`.
    pub(crate) wt_org: glam::Vec3,
}

/// The constants of the fused node test (one multiply-add per plane, see
/// `box_lanes_fused`): per axis, the near distance to a plane at `b` is
/// `fma(b, inv_near, off_near)` and the far distance `fma(b, inv_far,
/// off_far)`. The robust test spends a subtraction and a multiply there
/// (twice the latency on the node chain); Embree's fast mode spends one
/// multiply-add too, without the margins below, so it can miss boxes the
/// robust test enters.
///
/// # Why it admits every box the robust test admits
/// Let `u = 2⁻²⁴`, `inv = fl(1/d)` and `inv_f = fl(inv·(1 + 8u))` (the
/// robust test's reciprocals, `RayCtx::inv1` and `RayCtx::inv_far`). The
/// robust test computes `n = fl(fl(b − o)·inv)` for a near plane and `f =
/// fl(fl(b' − o)·inv_f)` for a far plane. The fused test computes `n* =
/// fl(X)`, `X = b·inv_near + off_near`, and `f* = fl(Y)`, `Y = b'·inv_far
/// + off_far` (exact products and sums, one rounding). Rounding is
/// monotone, so bounds on the exact `X` and `Y` carry over:
/// - `inv_near = fl(inv·(1 − 8u))`, so `0 < inv_near/inv < 1 − 6u`.
///   With `p = fl(o·inv_near)`, `off_near = fl(−fl(p + 8u·|p|) − 2⁻¹¹⁹)`
///   (the floor `2⁻¹¹⁹`, a subtraction of a positive number, can only
///   lower it). In the normal range `|p − o·inv_near| ≤ u·|o·inv_near|`,
///   which the `7u·|p|` left after rounding covers; below it the floor
///   does. So `off_near ≤ −o·inv_near` and `X ≤ (b − o)·inv_near`. Where `(b − o)·inv > 0`,
///   `X < (b − o)·inv·(1 − 6u) < fl(b − o)·inv` (a subtraction rounds by
///   at most `u` relative, and is exact among subnormals): `n* ≤ n`.
///   Elsewhere `X ≤ 0`, so `n* ≤ 0 ≤ t_min`. Either way `max(n*, t_min) ≤
///   max(n, t_min)`.
/// - `inv_far = fl(inv_f·(1 + 8u))`, so `inv_far/inv_f > 1 + 6u`. With `q
///   = fl(o·inv_far)`, `off_far = fl(fl(8u·|q| − q) + 2⁻¹¹⁹)`, which the
///   floor can only raise: as above, `off_far ≥ −o·inv_far + 2⁻¹⁴⁸` (the
///   floor covers it where `q` is subnormal or 0),
///   so `Y ≥ (b' − o)·inv_far + 2⁻¹⁴⁸`. Where `(b' − o)·inv_f > 0`, `Y >
///   (b' − o)·inv_f·(1 + 6u) > fl(b' − o)·inv_f`: `f* ≥ f`. Elsewhere `f ≤
///   0`. If `f < 0`, the robust test rejects the box (its entry is at
///   least `t_min ≥ 0`). If `f = ±0`, then `|fl(b' − o)·inv_f| ≤ 2⁻¹⁵⁰`,
///   so `|(b' − o)·inv_far| < 2⁻¹⁴⁹` and `Y > 0`: `f* ≥ 0 = f`.
///
/// So where the robust test admits a box (`max(n's, t_min) ≤ min(f's,
/// t_max)`), the fused one does too, entering no later, and a BVH searched
/// with it still finds every hit the primitives' own check
/// ([`rt_core::Aabb::admits_hit`]) accepts: exactly a brute-force loop's
/// hits. It admits a little more: boxes a ray misses by a few ulps of its
/// origin's coordinates (or, for geometry below `2⁻¹⁰⁰`, by the floors).
/// The floors keep the offsets out of the subnormal range (an offset
/// cancels to a subnormal only where `fl(p + 8u·|p|)` or `fl(8u·|q| − q)`
/// lies within `2⁻¹²⁶` of `∓2⁻¹¹⁹`, an origin coordinate of about `2⁻¹¹⁹`
/// ray lengths): a subnormal operand costs an Intel core's multiply-add a
/// microcode assist (every primary ray from an eye at `x = 0` would pay
/// it without floors). One addition each, where replacing the small offsets
/// by the floor took a compare and a select.
///
/// The bounds need every value above to be finite and the reciprocals
/// normal, and `b − o` not to overflow: the ray has `t_min ≥ 0`, `|o| ≤
/// 2¹²⁶`, `2⁻¹²⁵ ≤ |inv| ≤ 2¹²⁶` per axis and finite offsets (else
/// `Fused::on` is false), and the BVH's boxes lie within `±2¹²⁶`
/// (empty slots' infinite bounds give `±∞` distances, never NaN, and are
/// never entered). Rays along an axis (`d = ±0`, `inv = ±∞`) take the
/// robust test. The test
/// `fused_node_test_admits_every_box_the_robust_test_admits` checks all of
/// this over every scale.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Fused {
    /// Whether the test covers the ray and its BVH (else the robust test
    /// runs, and the other fields are not used).
    pub(crate) on: bool,
    pub(crate) inv_near: glam::Vec3A,
    pub(crate) off_near: glam::Vec3A,
    pub(crate) inv_far: glam::Vec3A,
    pub(crate) off_far: glam::Vec3A,
}

/// The largest coordinate (of a ray origin or a box) the fused node test
/// covers: `2¹²⁶`.
pub(crate) const FUSED_RANGE: f32 = (1u128 << 126) as f32;

/// `[kx, ky, kz, 3]` by `2·kz + (d_kz < 0)` (`WatertightRay::new`'s
/// axes: the next two in cyclic order, swapped for a negative `d_kz`), as
/// a lane permutation; two unused entries pad it to eight.
#[cfg(target_arch = "x86_64")]
static PERM: [[i32; 4]; 8] = [
    [1, 2, 0, 3],
    [2, 1, 0, 3],
    [2, 0, 1, 3],
    [0, 2, 1, 3],
    [0, 1, 2, 3],
    [1, 0, 2, 3],
    [0, 1, 2, 3],
    [0, 1, 2, 3],
];

/// `RayCtx::rows` by the direction's sign bits (bit `a` set: axis `a`
/// negative): the near plane's row is `2·a + 1` for a negative direction,
/// `2·a` otherwise, and the far plane's the other one.
static ROWS: [[u8; 8]; 8] = {
    let mut t = [[0; 8]; 8];
    let mut m = 0;
    while m < 8 {
        let mut a = 0;
        while a < 3 {
            let neg = (m >> a & 1) as u8;
            t[m][a] = ROW * (2 * a as u8 + neg);
            t[m][4 + a] = ROW * (2 * a as u8 + 1 - neg);
            a += 1;
        }
        m += 1;
    }
    t
};

impl Fused {
    /// For kernels that do not use the test: packets, streams and the
    /// 4-wide kernels.
    pub(crate) const OFF: Self = Self {
        on: false,
        inv_near: glam::Vec3A::ZERO,
        off_near: glam::Vec3A::ZERO,
        inv_far: glam::Vec3A::ZERO,
        off_far: glam::Vec3A::ZERO,
    };

    /// The constants for a ray with origin `o`, reciprocal `inv` and far
    /// reciprocal `inv_f`; on if `enable` (the ray has `t_min ≥ 0` and its
    /// BVH lies in the test's range) and the ray is in the ranges the
    /// bounds above need. Branch-free.
    #[inline(always)]
    fn from_parts(o: glam::Vec3A, inv: glam::Vec3A, inv_f: glam::Vec3A, enable: bool) -> Self {
        use glam::Vec3A;
        const EIGHT_U: f32 = 8.0 * (f32::EPSILON * 0.5);
        // 2⁻¹¹⁹: the offsets' floor, moved outward by it.
        const FLOOR: f32 = 1.0 / (1u128 << 119) as f32;
        let inv_near = inv * (1.0 - EIGHT_U);
        let inv_far = inv_f * (1.0 + EIGHT_U);
        let (p, q) = (o * inv_near, o * inv_far);
        let off_near = -(p + p.abs() * EIGHT_U) - FLOOR;
        let off_far = (q.abs() * EIGHT_U - q) + FLOOR;
        let a = inv.abs();
        let ok = o.abs().cmple(Vec3A::splat(FUSED_RANGE))
            & a.cmpge(Vec3A::splat(2.0 * f32::MIN_POSITIVE))
            & a.cmple(Vec3A::splat(FUSED_RANGE))
            & off_near.is_finite_mask()
            & off_far.is_finite_mask();
        Self { on: enable & ok.all(), inv_near, off_near, inv_far, off_far }
    }
}

impl RayCtx {
    /// The constants for `ray`, or `None` if the ray is not valid
    /// ([`Ray::is_valid`]): such rays miss everything. Always inlined, so
    /// the single-ray kernels keep the constants in registers.
    #[inline(always)]
    #[must_use]
    pub fn new(ray: &Ray) -> Option<Self> {
        Self::build::<false>(ray, false).map(|(ctx, _)| ctx)
    }

    /// [`RayCtx::new`] with the fused node test's constants too, on where
    /// the test covers the ray and `tree_in_range` (the BVH's boxes lie in
    /// its range, [`crate::traverse::fits_fused`]). The kernels that use
    /// them (the single-ray AVX ones) build them with
    /// [`RayCtx::new_fused_avx`]; this portable form is what the tests
    /// check that one and the fused test against. Kept beside the
    /// context, not in it: packets and streams store a context per ray,
    /// and a larger one slowed them.
    #[cfg(test)]
    #[must_use]
    pub(crate) fn new_fused(ray: &Ray, tree_in_range: bool) -> Option<(Self, Fused)> {
        Self::build::<true>(ray, tree_in_range)
    }

    /// The constants of `RayCtx::new_fused` (the portable form, which the
    /// tests keep), computed with SSE/AVX instructions: the same
    /// values, bit for bit (the test `avx_setup_equals_the_portable_one`
    /// checks every field), in a third fewer instructions. The portable
    /// form checked the ray field by field with a branch each, found the
    /// dominant axis's lanes through memory and bounds-checked its
    /// tables: 285 instructions before the first node in the AVX-512
    /// kernel (a third of a primary ray's), against 190 now.
    ///
    /// # Safety
    /// The CPU must have AVX. Always inlined, into the kernels compiled
    /// with it.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) unsafe fn new_fused_avx(ray: &Ray, tree_in_range: bool) -> Option<(Self, Fused)> {
        use core::arch::x86_64::{
            __m256, _CMP_LT_OQ, _CMP_NEQ_UQ, _mm_and_ps, _mm_blend_ps, _mm_castsi128_ps,
            _mm_div_ps, _mm_loadu_ps, _mm_loadu_si128, _mm_movemask_ps, _mm_mul_ps, _mm_permute_ps,
            _mm_permutevar_ps, _mm_set1_epi32, _mm_set1_ps, _mm256_add_ps, _mm256_and_ps,
            _mm256_blend_ps, _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_loadu_ps,
            _mm256_movemask_ps, _mm256_set1_epi32, _mm256_set1_ps, _mm256_setzero_ps,
        };
        const { assert!(size_of::<Ray>() == 32 && align_of::<Ray>() == 4) };
        // SAFETY: the caller guarantees AVX. `Ray` is `repr(C)`, eight
        // `f32`s (origin, direction, t_min, t_max; size checked above):
        // the loads read inside it. The permutation table is indexed below
        // its length.
        unsafe {
            let p = core::ptr::from_ref(ray).cast::<f32>();
            // [ox oy oz dx | dy dz t_min t_max]
            let all = _mm256_loadu_ps(p);
            let abs = _mm256_and_ps(all, _mm256_castsi256_ps(_mm256_set1_epi32(0x7fff_ffff)));
            let finite =
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(abs, _mm256_set1_ps(f32::INFINITY)));
            let nonzero =
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_NEQ_UQ>(all, _mm256_setzero_ps()));
            // `Ray::is_valid`: origin, direction and t_min finite (lanes
            // 0–6), the direction not zero (lanes 3–5; NaN is not finite),
            // t_min ≤ t_max.
            if !((finite & 0x7f == 0x7f) & (nonzero & 0x38 != 0) & (ray.t_min <= ray.t_max)) {
                return None;
            }
            let o = _mm_loadu_ps(p); // [ox oy oz dx]
            let d = _mm_loadu_ps(p.add(3)); // [dx dy dz t_min]
            let neg = _mm_movemask_ps(d) as usize & 7;
            let [x, y, z, _] =
                glam::Vec4::from(_mm_and_ps(d, _mm_castsi128_ps(_mm_set1_epi32(0x7fff_ffff))))
                    .to_array();
            // The dominant axis as `WatertightRay::new` picks it (the first
            // on ties); its sign is never zero on a valid ray.
            let kz = usize::from(!((x >= y) & (x >= z))) * (2 - usize::from(y >= z));
            let perm = &PERM[(2 * kz + (neg >> kz & 1)) & 7];
            let ctrl = _mm_loadu_si128(perm.as_ptr().cast());
            let dp = _mm_permutevar_ps(d, ctrl); // [d_kx d_ky d_kz _]
            // sz = 1 / d_kz; shear = (d_kx·sz, d_ky·sz, sz)
            let sz = _mm_div_ps(_mm_set1_ps(1.0), _mm_permute_ps::<0b10_10_10_10>(dp));
            let shear = _mm_blend_ps::<0b0100>(_mm_mul_ps(dp, sz), sz);
            let wt = WatertightRay {
                axes: [perm[0] as usize, perm[1] as usize, perm[2] as usize],
                shear: glam::Vec3A::from(shear).into(),
            };
            let wt_org = glam::Vec3A::from(_mm_permutevar_ps(o, ctrl)).into();
            let inv = glam::Vec3A::from(_mm_div_ps(_mm_set1_ps(1.0), d));
            // The ray whole, with `t_min + 0` (lane 6): one store, where
            // field by field it took eight moves.
            let fixed =
                _mm256_blend_ps::<0b0100_0000>(all, _mm256_add_ps(all, _mm256_setzero_ps()));
            // SAFETY: `Ray` is eight `f32`s (checked above), any bits are
            // a valid `f32`.
            let fixed = core::mem::transmute::<__m256, Ray>(fixed);
            let ctx = Self::assemble(fixed, inv, ROWS[neg], wt, wt_org);
            let enable = ray.t_min >= 0.0 && tree_in_range;
            let fused = Fused::from_parts(glam::Vec3A::from(o), inv, ctx.inv_far, enable);
            Some((ctx, fused))
        }
    }

    /// The context of a valid `ray` (its `t_min` made `+0` where it was
    /// `−0`, see the field) from what its constructors compute: the
    /// reciprocal direction, the near and far row offsets and the
    /// watertight constants.
    #[inline(always)]
    fn assemble(
        ray: Ray,
        inv: glam::Vec3A,
        rows: [u8; 8],
        wt: WatertightRay,
        wt_org: glam::Vec3,
    ) -> Self {
        let nonneg = ray.t_min >= 0.0;
        Self {
            ray,
            inv1: inv,
            inv_far: if nonneg { inv * FAR_INV_SCALE } else { inv },
            far_up: if nonneg { 1.0 } else { SLAB_FAR_SCALE },
            far_down: if nonneg { 1.0 } else { SLAB_FAR_SCALE_NEG },
            rows,
            wt,
            wt_org,
        }
    }

    #[inline(always)]
    fn build<const FUSED: bool>(ray: &Ray, tree_in_range: bool) -> Option<(Self, Fused)> {
        if !ray.is_valid() {
            return None;
        }
        let o = ray.origin;
        let d = ray.direction;
        let rows = ROWS[d.is_negative_bitmask() as usize & 7];
        let wt = WatertightRay::new(ray);
        let [kx, ky, kz] = wt.axes;
        let inv = glam::Vec3A::from(d).recip();
        // Indexed as an array: `Vec3`'s own indexing is a match, which
        // compiled to branches on the axes, mispredicted for rays of
        // random direction.
        let wt_org = {
            let o = o.to_array();
            glam::Vec3::new(o[kx], o[ky], o[kz])
        };
        // `+ 0.0` makes a `−0` start `+0` (see the field).
        let ctx = Self::assemble(Ray { t_min: ray.t_min + 0.0, ..*ray }, inv, rows, wt, wt_org);
        let fused = if FUSED {
            Fused::from_parts(o.into(), inv, ctx.inv_far, ray.t_min >= 0.0 && tree_in_range)
        } else {
            Fused::OFF
        };
        Some((ctx, fused))
    }

    /// The origin per axis, splatted.
    #[inline(always)]
    pub(crate) fn org4(&self, a: usize) -> F32x4 {
        F32x4::splat(self.ray.origin[a])
    }

    /// The reciprocal direction per axis, splatted.
    #[inline(always)]
    pub(crate) fn inv4(&self, a: usize) -> F32x4 {
        F32x4::splat(self.inv1[a])
    }

    /// The far planes' reciprocal per axis (see [`FAR_INV_SCALE`]), splatted.
    #[inline(always)]
    pub(crate) fn inv_far4(&self, a: usize) -> F32x4 {
        F32x4::splat(self.inv_far[a])
    }

    /// [`rt_core::Aabb::admits_hit`] for the box `lo..hi` and this ray,
    /// with the same arithmetic (so the same answer, bit for bit) but
    /// without recomputing the reciprocal direction or checking the ray.
    #[inline(always)]
    #[must_use]
    pub(crate) fn admits_hit(&self, lo: glam::Vec3, hi: glam::Vec3, t: f32) -> bool {
        let (o, d) = (self.ray.origin.to_array(), self.ray.direction.to_array());
        let (lo, hi) = (lo.to_array(), hi.to_array());
        let nonneg = self.ray.t_min >= 0.0;
        let mut t0 = self.ray.t_min;
        let mut t1 = widen_far(t);
        for a in 0..3 {
            // `(hi, lo)` where the direction's sign bit is set, else `(lo,
            // hi)`, picked by bits: compiled as a branch, the pick
            // mispredicted about once per incoherent ray (its sign is
            // random from ray to ray).
            let swap = (lo[a].to_bits() ^ hi[a].to_bits()) & ((d[a].to_bits() as i32 >> 31) as u32);
            let (near, far) =
                (f32::from_bits(lo[a].to_bits() ^ swap), f32::from_bits(hi[a].to_bits() ^ swap));
            let near = (near - o[a]) * self.inv1[a];
            let far = (far - o[a]) * self.inv_far[a];
            let far = if nonneg { far } else { widen_far(far) };
            // `x > t0` is false for NaN, so NaN leaves the bound alone.
            if near > t0 {
                t0 = near;
            }
            if far < t1 {
                t1 = far;
            }
        }
        t0 <= t1
    }

    /// The near and far plane rows of `bounds` (a node's) for axis `a`.
    #[inline(always)]
    pub(crate) fn planes<'b>(&self, bounds: &'b Rows, a: usize) -> (&'b Row, &'b Row) {
        let (near, far) = (usize::from(self.rows[a]), usize::from(self.rows[4 + a]));
        debug_assert!(near % size_of::<Row>() == 0 && near < size_of::<Rows>());
        debug_assert!(far % size_of::<Row>() == 0 && far < size_of::<Rows>());
        // SAFETY: the constructors set entries 0–2 and 4–6 of `rows`
        // from `ROWS`, whose entries there are `ROW·(2·axis)` or
        // `ROW·(2·axis + 1)` with `axis < 3`: the offset of one of the six
        // rows.
        unsafe {
            let rows = core::ptr::from_ref(bounds);
            (&*rows.byte_add(near).cast::<Row>(), &*rows.byte_add(far).cast::<Row>())
        }
    }

    /// The ray these constants were made for.
    #[inline]
    #[must_use]
    pub fn ray(&self) -> &Ray {
        &self.ray
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use glam::Vec3;
    use rt_core::{Aabb, Ray};

    use super::{Fused, RayCtx};
    use crate::{
        Isa,
        node::{Node, WIDTH},
        traverse::box_test,
    };

    /// The fused test of one box, in scalars (`f32::mul_add` rounds once,
    /// as the kernel's multiply-add does): `(admitted, entry distance)`.
    fn fused_scalar(ctx: &RayCtx, fz: &Fused, b: &Aabb, t_max: f32) -> (bool, f32) {
        // `+ 0.0` makes `−0` `+0`, as the kernel does (`RayCtx` for
        // `t_min`, an integer maximum with 0 for `t_max`).
        let (mut t0, mut t1) = (ctx.ray.t_min + 0.0, t_max + 0.0);
        let mut far_sign = false;
        for a in 0..3 {
            let neg = ctx.ray.direction[a].is_sign_negative();
            let (n, f) = if neg { (b.max[a], b.min[a]) } else { (b.min[a], b.max[a]) };
            t0 = t0.max(n.mul_add(fz.inv_near[a], fz.off_near[a]));
            let f = f.mul_add(fz.inv_far[a], fz.off_far[a]);
            far_sign |= f.is_sign_negative();
            t1 = t1.min(f);
        }
        // The lanes compare bits as integers: a far distance with the sign
        // bit set, `−0` included, rejects the box.
        (t0 <= t1 && !far_sign, t0)
    }

    /// Random bits: xorshift64.
    pub(crate) struct Bits(pub(crate) u64);
    impl Bits {
        pub(crate) fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        pub(crate) fn unit(&mut self) -> f32 {
            (self.next() >> 40) as f32 / (1u64 << 24) as f32
        }
        /// A float of any sign and any exponent from `2⁻¹⁴⁹` (subnormal)
        /// to `2^max_exp`, or zero.
        fn any(&mut self, max_exp: i32) -> f32 {
            let r = self.next();
            if r.is_multiple_of(16) {
                return 0.0;
            }
            let e = (r >> 8) as i32 % (149 + max_exp) - 149;
            let m = 1.0 + (r >> 40) as f32 / (1u64 << 24) as f32;
            let v = m * 2f32.powi(e.max(-126)) * if e < -126 { 2f32.powi(e + 126) } else { 1.0 };
            if r & 1 == 0 { v } else { -v }
        }
    }

    /// Every field of a context and its fused constants, as bits (an
    /// array: the crate's tests also build without `alloc`).
    fn ctx_bits(c: &(RayCtx, Fused)) -> [u32; 46] {
        let (ctx, f) = c;
        let v3 = |v: glam::Vec3A| v.to_array().map(f32::to_bits);
        let scalars = [ctx.ray.t_min, ctx.ray.t_max, ctx.far_up, ctx.far_down].map(f32::to_bits);
        let bytes = ctx.rows.map(u32::from);
        let mut fields = v3(ctx.ray.origin.into())
            .into_iter()
            .chain(v3(ctx.ray.direction.into()))
            .chain(scalars)
            .chain(v3(ctx.inv1))
            .chain(v3(ctx.inv_far))
            .chain(bytes)
            .chain(ctx.wt.axes.map(|a| a as u32))
            .chain(v3(ctx.wt.shear.into()))
            .chain(v3(ctx.wt_org.into()))
            .chain([u32::from(f.on)])
            .chain([f.inv_near, f.off_near, f.inv_far, f.off_far].into_iter().flat_map(v3));
        let out = [0; 46].map(|_: u32| fields.next().expect("fewer than 46 fields"));
        assert!(fields.next().is_none(), "more than 46 fields");
        out
    }

    /// The AVX kernels' ray setup equals the portable one, field for field
    /// and bit for bit, and refuses the same rays: rays of every scale,
    /// directions along axes and diagonals (ties for the dominant axis),
    /// signed zeros, subnormals, infinities and NaN in every field.
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn avx_setup_equals_the_portable_one() {
        if !Isa::Avx2.is_available() {
            return;
        }
        let mut g = Bits(0x2545_f491_4f6c_dd1d);
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            f32::MIN_POSITIVE,
            -1e-45,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        let (mut valid, mut on) = (0, 0);
        for i in 0..200_000u32 {
            let mut f = [0.0f32; 8];
            for k in 0..8 {
                let r = g.next();
                f[k] = match r % 8 {
                    0 => special[(r >> 8) as usize % special.len()],
                    // Ties: repeat an earlier value, or its negation.
                    1 if k > 0 => f[(r >> 8) as usize % k] * if r & 256 == 0 { 1.0 } else { -1.0 },
                    2 => g.unit() - 0.5,
                    _ => g.any(if k < 3 { 126 } else { 120 }),
                };
            }
            if i % 3 == 0 {
                // Mostly valid ranges.
                (f[6], f[7]) = (f[6].abs() * 1e-3, if i % 2 == 0 { f32::INFINITY } else { 1e3 });
            }
            let ray = Ray::with_range(
                Vec3::new(f[0], f[1], f[2]),
                Vec3::new(f[3], f[4], f[5]),
                f[6],
                f[7],
            );
            for in_range in [false, true] {
                let portable = RayCtx::new_fused(&ray, in_range);
                // SAFETY: the CPU has AVX (checked above).
                let avx = unsafe { RayCtx::new_fused_avx(&ray, in_range) };
                assert_eq!(portable.is_some(), avx.is_some(), "{ray:?}");
                assert_eq!(portable.is_some(), ray.is_valid(), "{ray:?}");
                if let (Some(p), Some(a)) = (portable, avx) {
                    assert_eq!(ctx_bits(&p), ctx_bits(&a), "{ray:?}");
                    valid += 1;
                    on += usize::from(p.1.on);
                }
            }
        }
        assert!(valid > 100_000 && on > 5_000, "{valid} {on}");
    }

    /// The leaves' box check equals rt-core's `Aabb::admits_hit` on
    /// every ray and box: directions of both signs on every axis (signed
    /// zeros included), `t_min` below and above 0, boxes of any magnitude
    /// (`Bits::any`), hits on and just off the box's planes.
    #[test]
    fn leaf_box_check_equals_rt_cores() {
        let mut g = Bits(0x2545_f491_4f6c_dd1d);
        let (mut admitted, mut refused) = (0, 0);
        for i in 0..60_000u32 {
            let any3 = |g: &mut Bits, e| Vec3::new(g.any(e), g.any(e), g.any(e));
            let (p, q) = if i.is_multiple_of(2) {
                (any3(&mut g, 100), any3(&mut g, 100))
            } else {
                let v = |g: &mut Bits| Vec3::new(g.unit(), g.unit(), g.unit());
                (v(&mut g), v(&mut g))
            };
            let b = Aabb::new(p.min(q), p.max(q));
            let o = if i % 3 == 0 { any3(&mut g, 100) } else { b.min.lerp(b.max, g.unit()) };
            let mut d = any3(&mut g, 60);
            if i % 5 == 0 {
                d[(g.next() % 3) as usize] = if g.next() & 1 == 0 { 0.0 } else { -0.0 };
            }
            let t_min = match g.next() % 4 {
                0 => -g.unit(),
                1 => -0.0,
                _ => 0.0,
            };
            let ray = Ray::with_range(o, d, t_min, f32::INFINITY);
            let Some(ctx) = RayCtx::new(&ray) else { continue };
            // A distance to one of the box's planes, moved by a few ulps
            // either way, or any distance.
            let a = (g.next() % 3) as usize;
            let plane = if g.next() & 1 == 0 { b.min[a] } else { b.max[a] };
            let t = match g.next() % 3 {
                0 => g.any(100).abs(),
                _ => {
                    let t = (plane - o[a]) / d[a];
                    let ulps = (g.next() % 9) as i32 - 4;
                    f32::from_bits(t.to_bits().wrapping_add_signed(ulps))
                }
            };
            if !t.is_finite() {
                continue;
            }
            let want = b.admits_hit(&ray, t);
            assert_eq!(ctx.admits_hit(b.min, b.max, t), want, "{b:?} {ray:?} t = {t}");
            if want { admitted += 1 } else { refused += 1 }
        }
        assert!(admitted > 10_000 && refused > 10_000, "{admitted} admitted, {refused} refused");
    }

    /// The fused node test admits every box the robust test admits, at
    /// an entry distance no later, over rays and boxes of every scale
    /// (subnormal through `2¹²⁶`), grazing rays through box edges and
    /// corners, and origins on box planes; and the AVX kernel's lanes
    /// equal the scalar model, bit for bit.
    #[test]
    fn fused_node_test_admits_every_box_the_robust_test_admits() {
        let mut g = Bits(0x9e37_79b9_7f4a_7c15);
        let avx = Isa::Avx2.is_available();
        let (mut covered, mut robust_in, mut only_fused, mut grazing) = (0, 0, 0, 0);
        let mut robust_normal = 0;
        for i in 0..40_000u32 {
            // A scale for this round's geometry: 2⁻¹⁴⁰ (subnormal
            // coordinates and distances) … 2¹²⁰.
            let e = (g.next() % 261) as i32 - 140;
            let scale = 2f32.powi(e.max(-126)) * 2f32.powi((e + 126).min(0));
            let v = |g: &mut Bits| Vec3::new(g.unit(), g.unit(), g.unit()) - 0.5;
            let mut boxes = [Aabb::EMPTY; WIDTH];
            let (o, d);
            if i.is_multiple_of(4) {
                // Bit patterns: any magnitude in every coordinate.
                for b in &mut boxes {
                    let (p, q) = (
                        Vec3::new(g.any(126), g.any(126), g.any(126)),
                        Vec3::new(g.any(126), g.any(126), g.any(126)),
                    );
                    *b = Aabb::new(p.min(q), p.max(q));
                }
                o = Vec3::new(g.any(126), g.any(126), g.any(126));
                d = Vec3::new(g.any(120), g.any(120), g.any(120));
            } else {
                for b in &mut boxes {
                    let lo = v(&mut g) * scale;
                    *b = Aabb::new(lo, lo + (v(&mut g) + 0.5) * scale);
                }
                // Toward a point on an edge or corner of box 0, or from a
                // point on one of its planes.
                let b = boxes[0];
                let mut p = b.min.lerp(b.max, g.unit());
                for a in 0..3 {
                    if !g.next().is_multiple_of(3) {
                        p[a] = if g.next() & 1 == 0 { b.min[a] } else { b.max[a] };
                    }
                }
                if i % 4 == 1 {
                    o = p;
                    d = v(&mut g);
                } else {
                    o = p + v(&mut g) * scale * 4.0;
                    d = (p - o) * (1.0 + 0.25 * v(&mut g).x);
                }
            }
            let mut node = Node::EMPTY;
            for (slot, b) in boxes.iter().enumerate() {
                node.set_child_bounds(slot, *b);
                node.children[slot] = crate::node::ChildRef::leaf(0, 1);
            }
            // Zeros of both signs at either end (the lanes compare bits).
            let t_min = match g.next() % 8 {
                0 => -0.0,
                1 => 0.0,
                _ => g.unit() * scale,
            };
            let t_max = match g.next() % 16 {
                0 => -0.0,
                1 => 0.0,
                2..=8 => f32::INFINITY,
                _ => g.unit() * 4.0,
            };
            let ray = Ray::with_range(o, d, t_min, t_max);
            let Some((ctx, fz)) = RayCtx::new_fused(&ray, node.within(super::FUSED_RANGE)) else {
                continue;
            };
            if !fz.on {
                continue;
            }
            covered += 1;
            let (robust, robust_t0) =
                box_test::<false, true, false>(&node, &ctx, &Fused::OFF, t_max);
            let mut fused = 0;
            for (slot, b) in boxes.iter().enumerate() {
                let (admit, t0) = fused_scalar(&ctx, &fz, b, t_max);
                fused |= u32::from(admit) << slot;
                if robust >> slot & 1 != 0 {
                    robust_in += 1;
                    assert!(admit, "{b:?} {:?}: robust admits, fused does not", ctx.ray);
                    assert!(t0 <= robust_t0[slot], "{b:?} {:?}: enters later", ctx.ray);
                    let exit = (0..3).map(|a| {
                        let neg = d[a].is_sign_negative();
                        let f = if neg { b.min[a] } else { b.max[a] };
                        (f - o[a]) * ctx.inv_far[a]
                    });
                    grazing +=
                        usize::from(exit.fold(f32::INFINITY, f32::min) - t0 <= t0.abs() * 1e-6);
                }
            }
            // Below 2⁻¹⁰⁰ the offsets' floor (2⁻¹¹⁹) admits nearly every
            // box: correct, and loose only for geometry at that scale.
            if scale > 2f32.powi(-100) || i.is_multiple_of(4) {
                only_fused += (fused & !robust).count_ones();
                robust_normal += robust.count_ones();
            }
            #[cfg(target_arch = "x86_64")]
            if avx {
                // SAFETY: the CPU has AVX2 and FMA (checked above); the ray
                // and the node are covered.
                let (lanes, _) =
                    unsafe { crate::traverse::box_lanes_fused(&node.bounds, &ctx, &fz, t_max) };
                // SAFETY: as above.
                assert_eq!(unsafe { lanes.sign_mask() }, fused, "{:?}", ctx.ray);
            }
        }
        // Enough rays covered, entering, grazing; and the fused test admits
        // only a sliver more than the robust one.
        assert!(
            covered > 20_000 && robust_in > 20_000 && grazing > 1_000,
            "{covered} {robust_in} {grazing}"
        );
        assert!(only_fused * 50 < robust_normal, "{only_fused} of {robust_normal}");
    }
}
