//! Tracing a ray through an unstructured field, one tetrahedron at a time,
//! in closed form.
//!
//! Inside a tetrahedron `n(x) = n₀ + G·(x − x₀)` with `G` constant. In the
//! parameter `dt = ds/n` the ray equation `dx/dt = T`, `dT/dt = n∇n` gives
//! `d²n/dt² = G·dT/dt = |G|² n`, so with `g = |G|`, `k = G·T₀`:
//!
//! ```text
//! n(t) = n₀ cosh(gt) + k sinh(gt)/g
//! T(t) = T₀ + G·(n₀ S(t) + k C(t))
//! x(t) = x₀ + T₀ t + G·(n₀ C(t) + k D(t))
//! OPL(t) = ∫₀ᵗ n² dτ = n₀² t (1 + sinhc(2gt))/2 + n₀ k t² sinhc(gt)² + 2 k² t³ sm(2gt)
//! ```
//!
//! with `S = sinh(gt)/g`, `C = (cosh(gt) − 1)/g²`, `D = (sinh(gt) − gt)/g³`,
//! `sinhc(u) = sinh(u)/u` and `sm(u) = (sinh(u) − u)/u³`, all evaluated from
//! series near `u = 0` so that `g → 0` (a uniform cell: a straight line) is
//! exact too. This is the catenary of docs/oracles.md §1 in the plane of `T₀` and
//! `G`, with no step and no truncation error.
//!
//! **Leaving the cell.** A face plane's signed distance along the path,
//! `f(t) = N·(x(t) − a)`, has `f''(t) = (N·G)·n(t)`, and `n(t) > 0` for every
//! `t` (`n(t) = A e^{gt} + B e^{−gt}` with `A, B ≥ 0` since `|k| ≤ g n₀`):
//! each `f` is convex, concave or linear on the whole line. So the first
//! `t > 0` where it turns positive is bracketed by a few evaluations and
//! solved by safeguarded Newton to round-off. The face with the smallest
//! such `t` is where the ray leaves; the ray goes on in the tetrahedron
//! across it from the same point with the same `T` (rescaled so `|T| = n`
//! of the new cell's function there, which is the same to round-off: `n`
//! is continuous).
//!
//! **Watertight.** Two tetrahedra sharing a face evaluate its plane with
//! the same operations on the same numbers (see `face_normal`), so a point
//! and direction that leave one enter the other: a ray through a shared
//! vertex, edge or face never falls through a gap. A point already outside
//! a face by round-off and moving out leaves through it at once (`t = 0`).
//! Every step moves the ray forward or crosses a face; the number of steps
//! is capped at twice the tetrahedron count plus 64 (a straight line meets
//! a convex cell once, a catenary at most twice), past which the trace
//! stops with [`Exit::MaxSteps`] instead of looping.
//!
//! **Entry and gaps.** The ray goes straight (index `ambient`) to the first
//! boundary face the BVH finds in front of it, and, after leaving the
//! mesh, straight on to the next boundary face it enters, if any (a hole or
//! the gap of a non-convex mesh). An origin inside the mesh is located by
//! walking straight back from the first boundary face ahead.

use glam::DVec3;
use rt_core::Ray;

use super::field::{NONE, UnstructuredField};
use crate::{Exit, TraceError, TraceResult, TraceStats};

/// `1/k!` for `k = 0..=15`.
const INV_FACT: [f64; 16] = {
    let mut t = [1.0f64; 16];
    let mut k = 1;
    while k < 16 {
        t[k] = t[k - 1] / k as f64;
        k += 1;
    }
    t
};

/// `sinh(u)/u`, `(cosh(u) − 1)/u²`, `(sinh(u) − u)/u³`.
#[inline]
fn hyper(u: f64) -> (f64, f64, f64) {
    let v = u * u;
    if v < 1e-6 {
        // |u| < 1e-3 (nearly every cell of a weak flow): three terms, the
        // next below 1e-21 relative.
        return (
            1.0 + v * (INV_FACT[3] + v * INV_FACT[5]),
            INV_FACT[2] + v * (INV_FACT[4] + v * INV_FACT[6]),
            INV_FACT[3] + v * (INV_FACT[5] + v * INV_FACT[7]),
        );
    }
    if v < 0.25 {
        // Taylor series in v = u², exact to f64 for |u| < 0.5 (the next
        // terms are below 1e-17 relative): Σ vᵏ/(2k+1)!, Σ vᵏ/(2k+2)!,
        // Σ vᵏ/(2k+3)!.
        let series = |first: usize| {
            let mut acc = 0.0;
            for k in (0..7).rev() {
                acc = acc * v + INV_FACT[first + 2 * k];
            }
            acc
        };
        (series(1), series(2), series(3))
    } else {
        let sh = u.sinh();
        let half = (0.5 * u).sinh();
        (sh / u, 2.0 * half * half / v, (sh - u) / (v * u))
    }
}

/// The closed-form path in one cell from `(x₀, T₀)`.
#[derive(Clone, Copy, Debug)]
struct Arc {
    x0: DVec3,
    t0: DVec3,
    n0: f64,
    grad: DVec3,
    g: f64,
    /// `G·T₀`.
    k: f64,
}

impl Arc {
    /// `(n₀ C(t) + k D(t))`: the path's offset along `G`.
    #[inline]
    fn offset(&self, t: f64) -> f64 {
        let (_, c, m) = hyper(self.g * t);
        t * t * (self.n0 * c + self.k * t * m)
    }

    /// `(n₀ S(t) + k C(t))`: the change of `T` along `G`.
    #[inline]
    fn turn(&self, t: f64) -> f64 {
        let (s, c, _) = hyper(self.g * t);
        t * (self.n0 * s + self.k * t * c)
    }

    /// Position, `T`, and the optical path from the start.
    fn at(&self, t: f64) -> (DVec3, DVec3, f64) {
        let (s, c, m) = hyper(self.g * t);
        let (s2, _, m2) = hyper(2.0 * self.g * t);
        let x = self.x0 + self.t0 * t + self.grad * (t * t * (self.n0 * c + self.k * t * m));
        let tt = self.t0 + self.grad * (t * (self.n0 * s + self.k * t * c));
        let (n0, k) = (self.n0, self.k);
        let opl =
            n0 * n0 * t * 0.5 * (1.0 + s2) + n0 * k * t * t * s * s + 2.0 * k * k * t * t * t * m2;
        (x, tt, opl)
    }
}

/// One face's signed distance along an arc: `f(t) = s₀ + b t + p·offset(t)`.
#[derive(Clone, Copy)]
struct Face {
    s0: f64,
    b: f64,
    p: f64,
}

impl Face {
    #[inline]
    fn f(&self, arc: &Arc, t: f64) -> f64 {
        self.s0 + self.b * t + if self.p == 0.0 { 0.0 } else { self.p * arc.offset(t) }
    }

    #[inline]
    fn df(&self, arc: &Arc, t: f64) -> f64 {
        self.b + if self.p == 0.0 { 0.0 } else { self.p * arc.turn(t) }
    }

    /// The first `t ≥ 0` at which the path crosses this face outward, if
    /// any before `cap`.
    fn exit(&self, arc: &Arc, guess: f64, cap: f64) -> Option<f64> {
        let Face { s0, b, p } = *self;
        if p == 0.0 {
            // A straight line relative to the plane.
            return if b > 0.0 { Some(if s0 >= 0.0 { 0.0 } else { -s0 / b }) } else { None };
        }
        if s0 >= 0.0 && b >= 0.0 && (b > 0.0 || p > 0.0) {
            // Outside (or on it) and not coming in: leaving now.
            return Some(0.0);
        }
        let mut lo = 0.0;
        if p < 0.0 && b <= 0.0 {
            // Concave and not rising: never crosses outward.
            return None;
        }
        // Still inside at `cap`, and (concave) still rising there: a convex
        // f that crossed outward would stay out, a concave one rising at
        // `cap` rose all along, so nothing crosses before `cap`. (Most
        // faces end here once the first exit is known: one evaluation.)
        if cap.is_finite() && self.f(arc, cap) <= 0.0 && (p > 0.0 || self.df(arc, cap) >= 0.0) {
            return None;
        }
        if s0 >= 0.0 {
            // Convex, on or just outside the plane and moving in: the
            // crossing is after the minimum (where f' = 0).
            let tmin = self.root(arc, 0.0, guess.max(f64::MIN_POSITIVE), cap, true)?;
            if self.f(arc, tmin) >= 0.0 {
                return None;
            }
            lo = tmin;
        }
        self.root(arc, lo, guess.max(lo), cap, false)
    }

    /// The root in `t > lo` of `f` (or of `f'` when `derivative`), which is
    /// negative at `lo` and, on the bracket found, crosses zero once.
    /// Doubles `hi` from `start` until the sign changes (or `cap` passes).
    fn root(&self, arc: &Arc, lo: f64, start: f64, cap: f64, derivative: bool) -> Option<f64> {
        let eval = |t: f64| if derivative { self.df(arc, t) } else { self.f(arc, t) };
        let slope = |t: f64| if derivative { self.p * arc.n_at(t) } else { self.df(arc, t) };
        let mut lo = lo;
        let mut hi = if start > lo { start } else { lo + cap * 1e-3 };
        // The values at the bracket's ends, where known.
        let mut v_lo = f64::NEG_INFINITY;
        let v_hi = loop {
            let v = eval(hi);
            if v > 0.0 {
                break v;
            }
            if !derivative && self.p < 0.0 && self.df(arc, hi) <= 0.0 {
                // Concave, past its maximum without crossing.
                return None;
            }
            if hi >= cap || !v.is_finite() {
                return None;
            }
            (lo, v_lo) = (hi, v);
            hi = (2.0 * hi).min(cap);
        };
        // Safeguarded Newton in [lo, hi] with f(lo) ≤ 0 < f(hi), from the
        // end nearer the root (the straight-line guess is usually within
        // round-off of it in a weak field).
        let (mut t, mut v) = if -v_lo < v_hi { (lo, v_lo) } else { (hi, v_hi) };
        for _ in 0..100 {
            if v > 0.0 {
                hi = t;
            } else {
                lo = t;
            }
            if v == 0.0 {
                return Some(t);
            }
            let step = v / slope(t);
            if step.abs() <= 16.0 * f64::EPSILON * t.abs() {
                // Converged: the step is round-off (and may well fall
                // outside the bracket by an ulp).
                break;
            }
            let mut next = t - step;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            t = next;
            if hi - lo <= 16.0 * f64::EPSILON * hi {
                break;
            }
            v = eval(t);
        }
        // Converged to round-off (from either side: a point a rounding
        // error inside the face is left through it by the next cell's
        // exact negative of the same test).
        Some(t)
    }
}

impl Arc {
    /// `n(t)` along the arc.
    #[inline]
    fn n_at(&self, t: f64) -> f64 {
        let (s, c, _) = hyper(self.g * t);
        self.n0 * (1.0 + self.g * self.g * t * t * c) + self.k * t * s
    }
}

/// Where a cell step ends.
struct Step {
    t: f64,
    face: usize,
}

impl UnstructuredField {
    /// Traces a ray from `origin` along `direction` (any non-zero length):
    /// straight through the ambient index to the mesh, along the exact
    /// curved path cell by cell inside it, straight across any gap to
    /// where it enters again, and stopped on the boundary face where it
    /// finally leaves. The result has the same meaning as
    /// [`crate::trace`]'s: the optical path counts the straight stretches
    /// outside at `ambient`; [`TraceStats::steps`] counts the tetrahedra
    /// crossed and [`TraceStats::invariant_drift`] the largest `| |T| − n |`
    /// at a face before `T` is rescaled.
    ///
    /// # Errors
    /// [`TraceError::InvalidRay`] for a non-finite origin or direction or a
    /// zero direction; [`TraceError::BadField`] if the path overflows.
    pub fn trace(&self, origin: DVec3, direction: DVec3) -> Result<TraceResult, TraceError> {
        self.trace_visiting(origin, direction, |_| {})
    }

    /// [`UnstructuredField::trace`], calling `visit(x)` where the ray
    /// leaves each tetrahedron (for sampling a second field along the bent
    /// path).
    ///
    /// # Errors
    /// As [`UnstructuredField::trace`].
    pub fn trace_visiting(
        &self,
        origin: DVec3,
        direction: DVec3,
        mut visit: impl FnMut(DVec3),
    ) -> Result<TraceResult, TraceError> {
        if !(origin.is_finite() && direction.is_finite()) || direction == DVec3::ZERO {
            return Err(TraceError::InvalidRay);
        }
        let d = unit(direction);
        let mut stats = TraceStats::default();
        let limit = 2 * self.tets.len() as u64 + 64;
        let mut count = 0u64;
        // Where the ray is, outside the mesh, and what it has gathered.
        let (mut x, mut dir, mut opl) = (origin, d, 0.0);
        let mut entered = false;
        let mut start = match self.first_boundary(origin, d, None, false) {
            Some((face, t)) if self.outward(face).dot(d) > 0.0 => {
                // The first boundary face ahead is one the ray leaves by: the
                // origin is inside the mesh.
                self.locate_back(origin, d, face, t).map(|tet| (tet, origin, 0.0))
            }
            Some((face, t)) => Some(((face / 4) as usize, origin + t * d, t)),
            None => None,
        };
        let exit = loop {
            let Some((tet0, x0, gap)) = start else {
                break if entered { Exit::Left } else { Exit::Missed };
            };
            entered = true;
            opl += self.ambient * gap;
            let (n0, _) = self.linear(tet0, x0);
            if !(n0.is_finite() && n0 > 0.0) {
                return Err(TraceError::BadField { at: x0 });
            }
            let mut tet = tet0;
            // The last step's cells when it was of no length: a zero step
            // straight back through the same face is a ray held on it.
            let mut back: Option<(usize, usize)> = None;
            let tiny = 1e-9 * (self.bounds.max - self.bounds.min).max_element() / self.range.1;
            let mut cur = x0;
            let mut tt = n0 * dir;
            // Inside the mesh: cell by cell.
            let left = loop {
                count += 1;
                if count > limit {
                    break None;
                }
                stats.steps += 1;
                let (n, grad) = self.linear(tet, cur);
                let drift = (tt.length() - n).abs();
                stats.invariant_drift = stats.invariant_drift.max(drift);
                if !(n.is_finite() && n > 0.0) {
                    return Err(TraceError::BadField { at: cur });
                }
                tt = unit(tt) * n;
                let mut arc =
                    Arc { x0: cur, t0: tt, n0: n, grad, g: grad.length(), k: grad.dot(tt) };
                let mut step = self.leave(tet, &arc, None);
                let next = self.neighbors[tet][step.face];
                if step.t <= tiny && back == Some((next as usize, tet)) {
                    // Both cells bend the ray into the face between them (a
                    // ridge of n along it): the ray slides along the face,
                    // with the gradient's part across it taken out (the
                    // sliding solution of a piecewise-smooth system), to
                    // the face's edge.
                    let (nrm, _) = self.plane(tet, step.face);
                    let across = nrm.dot(grad) / nrm.length_squared();
                    let along = grad - across * nrm;
                    let t_in = tt - nrm.dot(tt) / nrm.length_squared() * nrm;
                    let t_in = unit(t_in) * n;
                    arc = Arc {
                        x0: cur,
                        t0: t_in,
                        n0: n,
                        grad: along,
                        g: along.length(),
                        k: along.dot(t_in),
                    };
                    step = self.leave(tet, &arc, Some(step.face));
                }
                back = (step.t <= tiny).then_some((tet, self.neighbors[tet][step.face] as usize));
                let (x1, t1, dopl) = arc.at(step.t);
                if !(x1.is_finite() && t1.is_finite() && dopl.is_finite())
                    || t1 == DVec3::ZERO
                    || !self.near_cell(tet, x1)
                {
                    // Overflow, or an index so steep across the cell (n
                    // from ~0 to huge) that the exit could not be resolved
                    // in f64: the exit point is not on the cell.
                    return Err(TraceError::BadField { at: cur });
                }
                opl += dopl;
                cur = x1;
                tt = t1;
                visit(cur);
                let next = self.neighbors[tet][step.face];
                if next == NONE {
                    break Some(4 * tet as u32 + step.face as u32);
                }
                tet = next as usize;
            };
            x = cur;
            dir = unit(tt);
            let Some(face) = left else {
                break Exit::MaxSteps;
            };
            // Straight on across a gap to where the ray enters again.
            start = self
                .first_boundary(x, dir, Some(face), true)
                .map(|(f, t)| ((f / 4) as usize, x + t * dir, t));
        };
        if exit == Exit::Missed {
            return Ok(TraceResult {
                position: origin,
                direction: d,
                optical_path: 0.0,
                exit,
                stats,
            });
        }
        if !opl.is_finite() {
            // Every term is finite and positive, so the sum only overflows
            // (a huge index over a long path, e.g. the ambient one).
            return Err(TraceError::BadField { at: x });
        }
        Ok(TraceResult { position: x, direction: dir, optical_path: opl, exit, stats })
    }

    /// The face where the arc leaves `tet` first.
    fn leave(&self, tet: usize, arc: &Arc, exclude: Option<usize>) -> Step {
        // A bound on the time to leave (see `UnstructuredField::reach`).
        let cap = f64::from(self.reach[tet]);
        let mut faces = [Face { s0: 0.0, b: 0.0, p: 0.0 }; 4];
        let mut guess = f64::INFINITY;
        for (i, face) in faces.iter_mut().enumerate() {
            let (nrm, a) = self.plane(tet, i);
            *face = Face { s0: nrm.dot(arc.x0 - a), b: nrm.dot(arc.t0), p: nrm.dot(arc.grad) };
            if face.b > 0.0 {
                guess = guess.min((-face.s0 / face.b).max(0.0));
            }
        }
        let guess = if guess.is_finite() && guess > 0.0 { guess } else { 0.25 * cap };
        let mut best = Step { t: f64::INFINITY, face: 0 };
        // Faces in the order the straight line meets them: the first is
        // nearly always where the arc leaves, and the others are then only
        // searched up to its time.
        let mut order = [0usize, 1, 2, 3];
        let straight = |f: &Face| if f.b > 0.0 { -f.s0 / f.b } else { f64::INFINITY };
        order.sort_by(|&a, &b| straight(&faces[a]).total_cmp(&straight(&faces[b])));
        for i in order {
            if Some(i) == exclude {
                continue;
            }
            let limit = cap.min(best.t);
            if let Some(t) = faces[i].exit(arc, guess.min(limit), limit)
                && t < best.t
            {
                best = Step { t, face: i };
            }
        }
        if best.t.is_infinite() {
            // No face crossed (round-off at a vertex): leave at once through
            // the face the ray heads most out of.
            let out = |i: usize| faces[i].b / self.plane(tet, i).0.length();
            let i = (0..4).max_by(|&a, &b| out(a).total_cmp(&out(b))).unwrap_or(0);
            best = Step { t: 0.0, face: i };
        }
        best
    }

    /// Whether `x` is within the box of `tet`'s points, grown by a millionth
    /// of its size (the exit point of a step lies on one of its faces, to
    /// round-off).
    fn near_cell(&self, tet: usize, x: DVec3) -> bool {
        let p = self.tets[tet].map(|i| self.points[i as usize]);
        let lo = p[0].min(p[1]).min(p[2]).min(p[3]);
        let hi = p[0].max(p[1]).max(p[2]).max(p[3]);
        let slack = 1e-6 * (hi - lo).max_element() + 1e-12 * lo.abs().max(hi.abs()).max_element();
        (lo - slack).cmple(x).all() && x.cmple(hi + slack).all()
    }

    /// The outward normal of boundary face `4·tet + i`.
    fn outward(&self, face: u32) -> DVec3 {
        self.plane((face / 4) as usize, (face % 4) as usize).0
    }

    /// The nearest boundary face the straight ray `o + t·d` (`t > 0`) meets,
    /// other than `skip` (and only faces it enters by, if `entering`), with
    /// `t` refined in f64 on the face's plane.
    fn first_boundary(
        &self,
        o: DVec3,
        d: DVec3,
        skip: Option<u32>,
        entering: bool,
    ) -> Option<(u32, f64)> {
        let origin = (o - self.shift).as_vec3();
        let dir = d.as_vec3();
        let mut t_min = 0.0f32;
        // Hits on the face just left (or at t ≈ 0 by f32 round-off) are
        // passed over by restarting just beyond them: a gap narrower than
        // this (a few f32 roundings of the mesh's size) is not seen.
        let size = (self.bounds.max - self.bounds.min).length() as f32 + origin.length();
        let slack = 8.0 * f32::EPSILON * size;
        for _ in 0..16 {
            let ray = Ray::with_range(origin, dir, t_min, f32::INFINITY);
            let hit = self.bvh.closest_hit(&ray)?;
            let face = self.boundary[hit.prim as usize];
            let (nrm, a) = self.plane((face / 4) as usize, (face % 4) as usize);
            let den = nrm.dot(d);
            let t = if den != 0.0 { nrm.dot(a - o) / den } else { f64::from(hit.t) };
            if Some(face) != skip && t > 0.0 && !(entering && den >= 0.0) {
                return Some((face, t));
            }
            // Past this hit by the f32 rounding of the BVH's coordinates.
            t_min = hit.t.max(t_min) + slack;
        }
        None
    }

    /// The tetrahedron containing `origin`, found by walking straight back
    /// from the boundary face `face` that the ray `origin + t·d` leaves by
    /// at `t`.
    fn locate_back(&self, origin: DVec3, d: DVec3, face: u32, t: f64) -> Option<usize> {
        let mut tet = (face / 4) as usize;
        let mut cur = origin + t * d;
        let mut left = t;
        let back = -d;
        for _ in 0..2 * self.tets.len() + 64 {
            let arc = Arc { x0: cur, t0: back, n0: 1.0, grad: DVec3::ZERO, g: 0.0, k: 0.0 };
            let step = self.leave(tet, &arc, None);
            if step.t >= left {
                return Some(tet);
            }
            left -= step.t;
            cur += back * step.t;
            let next = self.neighbors[tet][step.face];
            if next == NONE {
                return None;
            }
            tet = next as usize;
        }
        None
    }
}

/// `v/|v|`, scaled first where `|v|²` under- or overflows.
fn unit(v: DVec3) -> DVec3 {
    let l2 = v.length_squared();
    if l2.is_normal() { v.normalize() } else { (v / v.abs().max_element()).normalize() }
}

#[cfg(test)]
mod tests {
    use super::hyper;

    /// The series and the closed forms agree where they meet, and with
    /// the closed forms' own values elsewhere.
    #[test]
    fn hyper_matches_its_closed_forms() {
        for u in [1e-9, 1e-5, 9.99e-4, 1.001e-3, 0.01, 0.1, 0.3, 0.4999, 0.5001, 1.0, 3.0] {
            let (s, c, m) = hyper(u);
            let (sh, ch) = (f64::sinh(u), f64::cosh(u));
            let rel = |a: f64, b: f64| ((a - b) / b).abs();
            assert!(rel(s, sh / u) < 1e-15, "{u}");
            // (cosh − 1)/u² and (sinh − u)/u³ lose digits to cancellation in
            // the closed form at small u; compare against extended series.
            let c_ref =
                if u < 0.1 { 0.5 + u * u / 24.0 + u.powi(4) / 720.0 } else { (ch - 1.0) / (u * u) };
            let m_ref = if u < 0.1 {
                1.0 / 6.0 + u * u / 120.0 + u.powi(4) / 5040.0
            } else {
                (sh - u) / u.powi(3)
            };
            assert!(rel(c, c_ref) < 1e-12, "{u}: {c} vs {c_ref}");
            assert!(rel(m, m_ref) < 1e-11, "{u}: {m} vs {m_ref}");
        }
        assert_eq!(hyper(0.0), (1.0, 0.5, 1.0 / 6.0));
    }
}
