//! Four triangles tested at once with the watertight algorithm.
//!
//! The lanes compute exactly what the scalar
//! [`rt_core::intersect::intersect_triangle_t`] computes, operation for
//! operation, so the BVH and a brute-force loop agree to the bit. Lanes whose
//! edge function is exactly zero (ray through an edge or vertex) are handed
//! to the scalar test, which decides them in f64 as Woop et al. prescribe.
//! Unused lanes hold NaN vertices, which never hit; lanes of triangles
//! that became degenerate in a refit hold three copies of one point, whose
//! edge functions are exactly zero, so they never hit either.

use glam::Vec3;
use rt_core::{
    Aabb, Hit, PrimKind, Ray,
    intersect::{
        TriangleHit, WatertightRay, intersect_triangle_t, triangle_barycentrics, triangle_hit,
    },
};

#[cfg(target_arch = "x86_64")]
use crate::simd::F32x8;
use crate::{
    RayCtx,
    prim::{BestHit, Primitive, Sealed},
    simd::{F32x4, Lanes},
};

/// Up to four triangles in structure-of-arrays form: `v[k][axis][lane]` is
/// coordinate `axis` of vertex `k` of triangle `lane`. 160 bytes.
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C, align(16))]
pub struct TriPacket {
    /// Vertex coordinates, `[vertex][axis][lane]`.
    pub v: [[[f32; 4]; 3]; 3],
    /// Triangle index per lane; `u32::MAX` for an unused lane.
    pub prims: [u32; 4],
}

impl TriPacket {
    /// A packet with every lane unused.
    pub const EMPTY: Self = Self { v: [[[f32::NAN; 4]; 3]; 3], prims: [u32::MAX; 4] };

    /// Vertex `k` of `lane`.
    #[inline]
    #[must_use]
    pub fn vertex(&self, lane: usize, k: usize) -> Vec3 {
        Vec3::new(self.v[k][0][lane], self.v[k][1][lane], self.v[k][2][lane])
    }

    /// Sets `lane` to triangle `prim` with the given vertices.
    #[inline]
    pub fn set_lane(&mut self, lane: usize, prim: u32, verts: [Vec3; 3]) {
        for (k, p) in verts.iter().enumerate() {
            for a in 0..3 {
                self.v[k][a][lane] = p[a];
            }
        }
        self.prims[lane] = prim;
    }

    /// Number of used lanes (they are filled from lane 0).
    #[must_use]
    pub fn len(&self) -> usize {
        self.prims.iter().take_while(|&&p| p != u32::MAX).count()
    }

    /// Whether no lane is used.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.prims[0] == u32::MAX
    }

    /// The scalar test's final check ([`rt_core::internal::triangle_admits_hit`]) for a lane
    /// the SIMD test accepted; lanes failing it are redone by the scalar
    /// test, which may settle their `t` onto the box.
    #[inline(always)]
    fn admits(&self, lane: usize, ctx: &RayCtx, t: f32) -> bool {
        let (a, b, c) = (self.vertex(lane, 0), self.vertex(lane, 1), self.vertex(lane, 2));
        ctx.admits_hit(a.min(b).min(c), a.max(b).max(c), t)
    }

    #[inline]
    fn scalar(&self, lane: usize, ray: &Ray, pre: &RayCtx) -> Option<TriangleHit> {
        let (a, b, c) = (self.vertex(lane, 0), self.vertex(lane, 1), self.vertex(lane, 2));
        intersect_triangle_t(ray, &pre.wt, a, b, c)
    }
}

/// Where the triangle test's lanes come from: one packet (four lanes) or
/// two side by side (eight, for the AVX kernels).
trait Verts {
    type L: Lanes;
    /// Coordinate `axis` of vertex `k`, per lane.
    ///
    /// # Safety
    /// As [`Lanes`]: the lane type's methods may run here.
    unsafe fn coord(&self, k: usize, axis: usize) -> Self::L;
}

impl Verts for TriPacket {
    type L = F32x4;
    #[inline(always)]
    unsafe fn coord(&self, k: usize, axis: usize) -> F32x4 {
        F32x4::from_array(self.v[k][axis])
    }
}

#[cfg(target_arch = "x86_64")]
impl Verts for [TriPacket; 2] {
    type L = F32x8;
    #[inline(always)]
    unsafe fn coord(&self, k: usize, axis: usize) -> F32x8 {
        F32x8::from_halves(self[0].v[k][axis], self[1].v[k][axis])
    }
}

/// What one run of [`lanes`] tests: the triangles in its lanes and the
/// ray each lane tests them against (one ray in all lanes, or, for the
/// occlusion streams, two rays against one packet, a ray a half).
trait Test {
    type L: Lanes;
    /// Per lane, the coordinate of vertex `k` along shear axis `i` (axis
    /// `WatertightRay::axes[i]`) of the lane's ray.
    ///
    /// # Safety
    /// As [`Lanes`].
    unsafe fn coord(&self, k: usize, i: usize) -> Self::L;
    /// Per lane, `f` of the lane's ray and its `t_max`.
    ///
    /// # Safety
    /// As [`Lanes`].
    unsafe fn per_ray(&self, f: impl Fn(&RayCtx, f32) -> f32) -> Self::L;
}

/// Triangles `V` against one ray, up to `t_max`.
struct Single<'a, V> {
    tris: &'a V,
    ctx: &'a RayCtx,
    t_max: f32,
}

impl<V: Verts> Test for Single<'_, V> {
    type L = V::L;
    #[inline(always)]
    unsafe fn coord(&self, k: usize, i: usize) -> V::L {
        // SAFETY: the caller's guarantee.
        unsafe { self.tris.coord(k, self.ctx.wt.axes[i]) }
    }
    #[inline(always)]
    unsafe fn per_ray(&self, f: impl Fn(&RayCtx, f32) -> f32) -> V::L {
        // SAFETY: the caller's guarantee.
        unsafe { <V::L as Lanes>::splat(f(self.ctx, self.t_max)) }
    }
}

/// One packet against two rays (each with its `t_max`): lanes 0–3 the
/// first ray's, 4–7 the second's.
#[cfg(target_arch = "x86_64")]
struct Pair<'a> {
    tri: &'a TriPacket,
    rays: [(&'a RayCtx, f32); 2],
}

#[cfg(target_arch = "x86_64")]
impl Test for Pair<'_> {
    type L = F32x8;
    #[inline(always)]
    unsafe fn coord(&self, k: usize, i: usize) -> F32x8 {
        let [(a, _), (b, _)] = self.rays;
        F32x8::from_halves(self.tri.v[k][a.wt.axes[i]], self.tri.v[k][b.wt.axes[i]])
    }
    #[inline(always)]
    unsafe fn per_ray(&self, f: impl Fn(&RayCtx, f32) -> f32) -> F32x8 {
        let [(a, ta), (b, tb)] = self.rays;
        F32x8::from_halves([f(a, ta); 4], [f(b, tb); 4])
    }
}

/// Lane masks: `(candidates, zero_lanes)` and the lanes' `t`. A candidate
/// passed the sign test, has `det ≠ 0` and `t ∈ [t_min, t_max]`; zero
/// lanes must be redone by the scalar test. Lane `l` of two packets is
/// lane `l % 4` of packet `l / 4`, computed with the same operations; of
/// a [`Pair`], lane `l % 4` of its packet against ray `l / 4`. Each lane
/// computes what the four-lane test of its own ray computes.
///
/// # Safety
/// As [`Lanes`]: `T::L`'s methods may run here.
#[inline(always)]
unsafe fn lanes<T: Test, const EARLY: bool>(test: &T) -> (u32, u32, <T::L as Lanes>::Array) {
    // Vertex `k` relative to the origin, sheared (a function, not a
    // closure: closures are not always inlined, and one left out of line
    // is compiled without the kernel's instruction set).
    #[inline(always)]
    unsafe fn vert<T: Test>(test: &T, k: usize) -> (T::L, T::L, T::L) {
        // SAFETY: the caller's guarantee.
        unsafe {
            let x = test.coord(k, 0).sub(test.per_ray(|c, _| c.wt_org.x));
            let y = test.coord(k, 1).sub(test.per_ray(|c, _| c.wt_org.y));
            let z = test.coord(k, 2).sub(test.per_ray(|c, _| c.wt_org.z));
            let (sx, sy) = (test.per_ray(|c, _| c.wt.shear.x), test.per_ray(|c, _| c.wt.shear.y));
            (x.sub(sx.mul(z)), y.sub(sy.mul(z)), z)
        }
    }
    // SAFETY: the caller's guarantee.
    unsafe {
        let splat = <T::L as Lanes>::splat;
        let sz = test.per_ray(|c, _| c.wt.shear.z);
        let (ax, ay, az) = vert(test, 0);
        let (bx, by, bz) = vert(test, 1);
        let (cx, cy, cz) = vert(test, 2);
        let u = cx.mul(by).sub(cy.mul(bx));
        let v = ax.mul(cy).sub(ay.mul(cx));
        let w = bx.mul(ay).sub(by.mul(ax));
        let zero = splat(0.0);
        let on_edge = u.eq_mask(zero) | v.eq_mask(zero) | w.eq_mask(zero);
        // A lane the ray passes through has edge functions of one sign:
        // read off the sign bits, all three set or none. That is the
        // scalar test's `u < 0 || …` and `u > 0 || …` wherever those
        // decide: lanes with a zero function are the scalar test's
        // (`on_edge`), and a NaN one makes `det` NaN, rejected below.
        let any_neg = u.or_bits(v).or_bits(w).sign_mask();
        let all_neg = u.and_bits(v).and_bits(w).sign_mask();
        let one_sign = all_neg | !any_neg;
        let all = <T::L as Lanes>::ALL;
        if EARLY && (one_sign | on_edge) & all == 0 {
            return (0, 0, zero.to_lanes());
        }
        let det = u.add(v).add(w);
        let tt = u.mul(sz.mul(az)).add(v.mul(sz.mul(bz))).add(w.mul(sz.mul(cz)));
        let t = tt.mul(splat(1.0).div(det));
        let inf = splat(f32::INFINITY);
        // `t < ∞` as the scalar test: an overflowed `t` is no hit.
        let (t_min, t_max) = (test.per_ray(|c, _| c.ray.t_min), test.per_ray(|_, t| t));
        let in_range = t_min.le_mask(t) & t.le_mask(t_max) & t.lt_mask(inf);
        // As the scalar test: an overflowed `det` is no hit.
        let finite = det.lt_mask(inf) & splat(f32::NEG_INFINITY).lt_mask(det);
        let ok = one_sign & !det.eq_mask(zero) & finite & in_range & !on_edge & all;
        (ok, on_edge & all, t.to_lanes())
    }
}

/// Whether any lane [`lanes`] found for `packets` is a hit before `t_max`
/// (candidates that fail the scalar test's final box check, and the
/// zero lanes, are settled by the scalar test).
#[inline(always)]
fn any_lane(
    packets: &[TriPacket],
    (mut ok, mut edge, t): (u32, u32, impl core::ops::Index<usize, Output = f32>),
    ctx: &RayCtx,
    t_max: f32,
) -> bool {
    while ok != 0 {
        let l = ok.trailing_zeros() as usize;
        ok &= ok - 1;
        if packets[l / 4].admits(l % 4, ctx, t[l]) {
            return true;
        }
        edge |= 1 << l;
    }
    if edge == 0 {
        // Most leaves: no ray copy (made before the loop, it was made at
        // every leaf, 45 instructions a shadow ray).
        return false;
    }
    let r = Ray { t_max, ..ctx.ray };
    while edge != 0 {
        let l = edge.trailing_zeros() as usize;
        edge &= edge - 1;
        if packets[l / 4].scalar(l % 4, &r, ctx).is_some() {
            return true;
        }
    }
    false
}

/// Offers to `best` the hits among the lanes [`lanes`] found for
/// `packets` (leaf items `item..`): candidates that pass the scalar
/// test's final box check, then the zero lanes and the rest, settled by
/// the scalar test up to the best hit so far.
#[inline(always)]
fn offer_lanes(
    packets: &[TriPacket],
    item: u32,
    (mut ok, mut edge, t): (u32, u32, impl core::ops::Index<usize, Output = f32>),
    ctx: &RayCtx,
    best: &mut BestHit,
) {
    while ok != 0 {
        let l = ok.trailing_zeros() as usize;
        ok &= ok - 1;
        let (p, lane) = (&packets[l / 4], l % 4);
        if p.admits(lane, ctx, t[l]) {
            best.offer(t[l], p.prims[lane], item + (l / 4) as u32, lane as u32);
        } else {
            // Rounded below its box: the scalar test settles it.
            edge |= 1 << l;
        }
    }
    if edge != 0 {
        let r = Ray { t_max: best.t, ..ctx.ray };
        while edge != 0 {
            let l = edge.trailing_zeros() as usize;
            edge &= edge - 1;
            let (p, lane) = (&packets[l / 4], l % 4);
            if let Some(h) = p.scalar(lane, &r, ctx) {
                best.offer(h.t, p.prims[lane], item + (l / 4) as u32, lane as u32);
            }
        }
    }
}

/// [`Primitive::closest`] over a leaf's packets (leaf items `first..`),
/// two at a time in eight lanes: the same best hit as one packet after
/// the other, since [`BestHit::offer`] does not depend on the order.
///
/// # Safety
/// The CPU must have AVX. Always inlined, into the kernels compiled with it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn closest_x8(
    packets: &[TriPacket],
    first: usize,
    ctx: &RayCtx,
    best: &mut BestHit,
) {
    let (pairs, rest) = packets.as_chunks::<2>();
    for (k, pair) in pairs.iter().enumerate() {
        // SAFETY: the caller guarantees AVX.
        let found = unsafe { lanes::<_, true>(&Single { tris: pair, ctx, t_max: best.t }) };
        offer_lanes(pair, (first + 2 * k) as u32, found, ctx, best);
    }
    if let [last] = rest {
        last.closest((first + packets.len() - 1) as u32, ctx, best);
    }
}

/// [`Primitive::any`] over a leaf's packets, two at a time in eight
/// lanes: the same answer as one packet after the other.
///
/// # Safety
/// The CPU must have AVX. Always inlined, into the kernels compiled with it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn any_x8(packets: &[TriPacket], ctx: &RayCtx, t_max: f32) -> bool {
    let (pairs, rest) = packets.as_chunks::<2>();
    for pair in pairs {
        // SAFETY: the caller guarantees AVX.
        let test = Single { tris: pair, ctx, t_max };
        if any_lane(pair, unsafe { lanes::<_, false>(&test) }, ctx, t_max) {
            return true;
        }
    }
    // A plain `if let`: a closure (`is_some_and`) may be left out of line.
    if let [last] = rest { last.any(ctx, t_max) } else { false }
}

/// Whether each of two rays (with its `t_max`) hits a triangle of
/// `packet`: [`Primitive::any`] for both in one eight-lane pass, the same
/// answers. Occlusion streams test a leaf of one packet (most leaves)
/// this way for two rays of a group at a time.
///
/// # Safety
/// The CPU must have AVX. Always inlined, into the kernels compiled with it.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) unsafe fn any_pair(packet: &TriPacket, rays: [(&RayCtx, f32); 2]) -> [bool; 2] {
    // SAFETY: the caller guarantees AVX.
    let (ok, edge, t) = unsafe { lanes::<_, false>(&Pair { tri: packet, rays }) };
    let one = core::slice::from_ref(packet);
    let [(a, ta), (b, tb)] = rays;
    let low = [t[0], t[1], t[2], t[3]];
    let high = [t[4], t[5], t[6], t[7]];
    [
        any_lane(one, (ok & 0xf, edge & 0xf, low), a, ta),
        any_lane(one, (ok >> 4, edge >> 4, high), b, tb),
    ]
}

impl Sealed for TriPacket {
    #[inline(always)]
    fn as_tri_packets(items: &[Self]) -> Option<&[TriPacket]> {
        Some(items)
    }
}

impl Primitive for TriPacket {
    const KIND: PrimKind = PrimKind::Triangle;
    const TAG: u32 = 1;

    // Always inlined: into each traversal kernel, compiled with its
    // instruction set.
    #[inline(always)]
    fn closest(&self, item: u32, ctx: &RayCtx, best: &mut BestHit) {
        // SAFETY: four lanes run anywhere.
        let found = unsafe { lanes::<_, true>(&Single { tris: self, ctx, t_max: best.t }) };
        offer_lanes(core::slice::from_ref(self), item, found, ctx, best);
    }

    #[inline(always)]
    fn any(&self, ctx: &RayCtx, t_max: f32) -> bool {
        // SAFETY: four lanes run anywhere.
        let found = unsafe { lanes::<_, false>(&Single { tris: self, ctx, t_max }) };
        any_lane(core::slice::from_ref(self), found, ctx, t_max)
    }

    fn hit(&self, lane: u32, ray: &Ray, t: f32) -> Option<Hit> {
        // The traversal settled `t` already: only the barycentrics are
        // left to find, as the scalar test finds them (the whole scalar
        // test again, with its box check, would repeat the traversal's
        // work for every hit).
        let l = lane as usize;
        if !(ray.is_valid() && t >= ray.t_min && t <= ray.t_max) {
            return None;
        }
        let (a, b, c) = (self.vertex(l, 0), self.vertex(l, 1), self.vertex(l, 2));
        let (b1, b2) = triangle_barycentrics(ray, &WatertightRay::new(ray), a, b, c)?;
        Some(triangle_hit(TriangleHit { t, b1, b2 }, self.prims[l], a, b, c))
    }

    fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for lane in 0..self.len() {
            for k in 0..3 {
                b = b.grow(self.vertex(lane, k));
            }
        }
        b
    }

    fn is_well_formed(&self, prim_count: u32) -> bool {
        let n = self.len();
        (0..4).all(|lane| {
            if lane < n {
                self.prims[lane] < prim_count && (0..3).all(|k| self.vertex(lane, k).is_finite())
            } else {
                // Unused lanes are tested too: they must hold NaN.
                self.prims[lane] == u32::MAX
                    && self.v.iter().all(|vk| vk.iter().all(|axis| axis[lane].is_nan()))
            }
        })
    }
}
