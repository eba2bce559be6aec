//! The grid interpolants, written once for a whole [`Grid`](crate::Grid)
//! and for a [`BrickField`](crate::BrickField) holding a box of its
//! samples.
//!
//! Invariant: a value depends only on the GLOBAL grid (dims, origin,
//! `1/spacing`) and on the samples its stencil reads, never on which box
//! of samples is stored. [`locate`] works in global sample coordinates,
//! the fast/slow path choice is made from the global dims, the ghost-sample
//! rule is applied in global indices, and only the final fetch of a
//! sample maps its global index into the stored box. So a brick's value at
//! any point whose stencil ([`footprint`]) it stores is bit for bit the
//! whole grid's.

use glam::DVec3;

use crate::Interp;

/// A box of stored samples: global indices `lo .. lo + dims`, x fastest.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Samples<'a> {
    /// The samples of the box.
    pub(crate) data: &'a [f32],
    /// Global index of the box's first sample.
    pub(crate) lo: [usize; 3],
    /// Samples per axis in the box.
    pub(crate) dims: [usize; 3],
}

/// The global grid a box belongs to, as the interpolants need it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Lattice {
    /// Samples per axis of the whole grid.
    pub(crate) dims: [usize; 3],
    /// Centre of global sample `(0, 0, 0)`.
    pub(crate) origin: DVec3,
    /// `1 / spacing`.
    pub(crate) inv_spacing: DVec3,
}

/// Where a point falls in the grid: the stencil's base sample, the
/// fractions within its cell, and the axes where the point lies in the
/// outer half cell (edge value, zero slope across the face).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Located {
    pub(crate) base: [isize; 3],
    pub(crate) frac: [f64; 3],
    pub(crate) flat: [bool; 3],
}

impl Samples<'_> {
    /// Linear index in the box of global sample `idx` (inside the box).
    #[inline]
    fn index(&self, idx: [usize; 3]) -> usize {
        (idx[0] - self.lo[0])
            + self.dims[0] * ((idx[1] - self.lo[1]) + self.dims[1] * (idx[2] - self.lo[2]))
    }

    /// Global sample `idx` of a grid of `dims` samples; one layer of ghost
    /// samples outside the grid is extrapolated linearly
    /// (`s₋₁ = 2s₀ − s₁`), so the cubic stencil reproduces linear data up
    /// to the faces.
    #[inline]
    pub(crate) fn at(&self, dims: [usize; 3], idx: [isize; 3]) -> f64 {
        for a in 0..3 {
            let n = dims[a] as isize;
            let (edge, inner) = if idx[a] < 0 {
                (0, 1)
            } else if idx[a] >= n {
                (n - 1, n - 2)
            } else {
                continue;
            };
            let mut e = idx;
            e[a] = edge;
            if n < 2 {
                return self.at(dims, e);
            }
            let mut i = idx;
            i[a] = inner;
            return 2.0 * self.at(dims, e) - self.at(dims, i);
        }
        f64::from(self.data[self.index(idx.map(|v| v as usize))])
    }
}

/// Where `x` falls in the grid (see [`Located`]).
#[inline]
pub(crate) fn locate(l: &Lattice, x: DVec3) -> Located {
    // Continuous sample coordinates (sample centres at integers).
    let u = (x - l.origin) * l.inv_spacing;
    let mut base = [0isize; 3];
    let mut frac = [0.0f64; 3];
    let mut flat = [false; 3];
    for a in 0..3 {
        let hi = (l.dims[a] - 1) as f64;
        // Within half a cell of the faces: edge samples, zero slope.
        let ua = if u[a] < 0.0 {
            flat[a] = true;
            0.0
        } else if u[a] > hi {
            flat[a] = true;
            hi
        } else {
            u[a]
        };
        // Truncation is floor here (ua ≥ 0); the last sample is reached
        // as the end of the last interval, so `base + 1` stays inside.
        let mut b = ua as isize;
        if b as f64 == hi && hi > 0.0 {
            b -= 1;
        }
        base[a] = b;
        frac[a] = ua - b as f64;
    }
    Located { base, frac, flat }
}

/// The global samples the stencil at `base` reads, per axis the inclusive
/// range `lo[a] ..= hi[a]` (the ghost rule's samples included).
#[inline]
pub(crate) fn footprint(
    dims: [usize; 3],
    base: [isize; 3],
    interp: Interp,
) -> ([usize; 3], [usize; 3]) {
    let mut lo = [0usize; 3];
    let mut hi = [0usize; 3];
    for a in 0..3 {
        let last = dims[a] as isize - 1;
        let (from, to) = match interp {
            Interp::Trilinear => (base[a], base[a] + 1),
            Interp::CatmullRom => (base[a] - 1, base[a] + 2),
        };
        // A ghost below reads samples 0 and 1; one above, n − 1 and n − 2.
        let mut l = from.max(0);
        let mut h = to.min(last);
        if from < 0 {
            l = 0;
            h = h.max(1.min(last));
        }
        if to > last {
            h = last;
            l = l.min((last - 1).max(0));
        }
        lo[a] = l.clamp(0, last) as usize;
        hi[a] = h.clamp(0, last) as usize;
    }
    (lo, hi)
}

/// Value and gradient of the interpolant at the located point, reading
/// samples from `s` (which must hold the point's [`footprint`]).
#[inline]
pub(crate) fn interpolate(
    s: &Samples<'_>,
    l: &Lattice,
    at: &Located,
    interp: Interp,
) -> (f64, DVec3) {
    let (value, grad) = match interp {
        Interp::Trilinear => trilinear(s, l.dims, at.base, at.frac),
        Interp::CatmullRom => catmull_rom(s, l.dims, at.base, at.frac),
    };
    let mut g = grad * l.inv_spacing;
    for a in 0..3 {
        if at.flat[a] {
            g[a] = 0.0;
        }
    }
    (value, g)
}

fn trilinear(s: &Samples<'_>, dims: [usize; 3], b: [isize; 3], f: [f64; 3]) -> (f64, DVec3) {
    let [nx, ny, nz] = dims;
    if nx >= 2 && ny >= 2 && nz >= 2 {
        // The common case: all eight corners inside, loaded directly.
        let (sx, sy) = (1, s.dims[0]);
        let sz = s.dims[0] * s.dims[1];
        let i = s.index(b.map(|v| v as usize));
        let d = s.data;
        let c = |o: usize| f64::from(d[i + o]);
        let (c000, c100, c010, c110) = (c(0), c(sx), c(sy), c(sx + sy));
        let (c001, c101, c011, c111) = (c(sz), c(sx + sz), c(sy + sz), c(sx + sy + sz));
        let [fx, fy, fz] = f;
        let lerp = |a: f64, b: f64, t: f64| a + t * (b - a);
        // Along x on the four edges, then y, then z.
        let (e00, e10) = (lerp(c000, c100, fx), lerp(c010, c110, fx));
        let (e01, e11) = (lerp(c001, c101, fx), lerp(c011, c111, fx));
        let (f0, f1) = (lerp(e00, e10, fy), lerp(e01, e11, fy));
        let v = lerp(f0, f1, fz);
        let gx = lerp(lerp(c100 - c000, c110 - c010, fy), lerp(c101 - c001, c111 - c011, fy), fz);
        let gy = lerp(e10 - e00, e11 - e01, fz);
        let gz = f1 - f0;
        return (v, DVec3::new(gx, gy, gz));
    }
    let w = |t: f64| [1.0 - t, t];
    let dw = [-1.0, 1.0];
    let (wx, wy, wz) = (w(f[0]), w(f[1]), w(f[2]));
    let (mut v, mut g) = (0.0, DVec3::ZERO);
    for dk in 0..2 {
        for dj in 0..2 {
            for di in 0..2 {
                let c = s.at(dims, [b[0] + di as isize, b[1] + dj as isize, b[2] + dk as isize]);
                v += wx[di] * wy[dj] * wz[dk] * c;
                g += c * DVec3::new(
                    dw[di] * wy[dj] * wz[dk],
                    wx[di] * dw[dj] * wz[dk],
                    wx[di] * wy[dj] * dw[dk],
                );
            }
        }
    }
    (v, g)
}

fn catmull_rom(s: &Samples<'_>, dims: [usize; 3], b: [isize; 3], f: [f64; 3]) -> (f64, DVec3) {
    // Weights of samples at offsets −1, 0, 1, 2 and their derivatives.
    let w = |t: f64| {
        let (t2, t3) = (t * t, t * t * t);
        [
            0.5 * (-t3 + 2.0 * t2 - t),
            0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
            0.5 * (-3.0 * t3 + 4.0 * t2 + t),
            0.5 * (t3 - t2),
        ]
    };
    let dw = |t: f64| {
        let t2 = t * t;
        [
            0.5 * (-3.0 * t2 + 4.0 * t - 1.0),
            0.5 * (9.0 * t2 - 10.0 * t),
            0.5 * (-9.0 * t2 + 8.0 * t + 1.0),
            0.5 * (3.0 * t2 - 2.0 * t),
        ]
    };
    let (wx, wy, wz) = (w(f[0]), w(f[1]), w(f[2]));
    let (dx, dy, dz) = (dw(f[0]), dw(f[1]), dw(f[2]));
    let st = stencil_4x4x4(s, dims, b);
    // Separable: contract along x (value and x-derivative per row),
    // then y, then z — 4³ samples in ~200 flops instead of ~700.
    let dot = |w: &[f64; 4], v: &[f64; 4]| w[0] * v[0] + w[1] * v[1] + w[2] * v[2] + w[3] * v[3];
    let (mut v, mut gx, mut gy, mut gz) = (0.0, 0.0, 0.0, 0.0);
    for (k, plane) in st.chunks_exact(16).enumerate() {
        let (mut a, mut ax) = ([0.0; 4], [0.0; 4]);
        for (j, row) in plane.chunks_exact(4).enumerate() {
            let row: &[f64; 4] = row.try_into().expect("rows of 4");
            a[j] = dot(&wx, row);
            ax[j] = dot(&dx, row);
        }
        let (c, cy, cx) = (dot(&wy, &a), dot(&dy, &a), dot(&wy, &ax));
        v += wz[k] * c;
        gz += dz[k] * c;
        gy += wz[k] * cy;
        gx += wz[k] * cx;
    }
    (v, DVec3::new(gx, gy, gz))
}

/// The 4³ samples `b − 1 … b + 2` the Catmull–Rom stencil at `b` reads,
/// x fastest (`i + 4j + 16k`), ghost samples included: the same values as
/// [`Samples::at`] gives one by one. Next to a face the stored samples are
/// loaded with their indices clamped into the grid and the ghost rule is
/// then applied along each axis in turn (`s₋₁ = 2s₀ − s₁`,
/// `s_n = 2s_{n−1} − s_{n−2}`; a one-sample axis repeats it, as the
/// clamped loads already do): the rule is linear per axis, so this is
/// `at`'s recursion done for the whole block at once, 64 loads instead of
/// up to 64 recursive lookups. Every sample it loads lies in the
/// [`footprint`].
#[inline]
fn stencil_4x4x4(s: &Samples<'_>, dims: [usize; 3], b: [isize; 3]) -> [f64; 64] {
    let mut st = [0.0f64; 64];
    let n = dims.map(|n| n as isize);
    let inside = (0..3).all(|a| b[a] >= 1 && b[a] + 2 < n[a]);
    if inside {
        let (sy, sz) = (s.dims[0], s.dims[0] * s.dims[1]);
        let base = s.index([b[0] - 1, b[1] - 1, b[2] - 1].map(|v| v as usize));
        for (k, plane) in st.chunks_exact_mut(16).enumerate() {
            for (j, row) in plane.chunks_exact_mut(4).enumerate() {
                let r = base + j * sy + k * sz;
                for (i, v) in row.iter_mut().enumerate() {
                    *v = f64::from(s.data[r + i]);
                }
            }
        }
        return st;
    }
    let clamped = |a: usize| [0, 1, 2, 3].map(|o| (b[a] + o - 1).clamp(0, n[a] - 1) as usize);
    let (ix, iy, iz) = (clamped(0), clamped(1), clamped(2));
    for (k, &gk) in iz.iter().enumerate() {
        for (j, &gj) in iy.iter().enumerate() {
            for (i, &gi) in ix.iter().enumerate() {
                st[i + 4 * j + 16 * k] = f64::from(s.data[s.index([gi, gj, gk])]);
            }
        }
    }
    let stride = [1, 4, 16];
    for a in 0..3 {
        if n[a] < 2 {
            continue;
        }
        // `b[a]` is in `0 ..= n − 2`, so only offset 0 (below) or 3
        // (above) can be a ghost, and its edge and inner samples are in
        // the block: positions 1, 2 below; 2, 1 above.
        for (o, edge, inner) in [(0, 1, 2), (3, 2, 1)] {
            let g = b[a] + o as isize - 1;
            if g >= 0 && g < n[a] {
                continue;
            }
            let others: [usize; 2] = match a {
                0 => [4, 16],
                1 => [1, 16],
                _ => [1, 4],
            };
            for p in 0..4 {
                for q in 0..4 {
                    let at = |t: usize| p * others[0] + q * others[1] + t * stride[a];
                    st[at(o)] = 2.0 * st[at(edge)] - st[at(inner)];
                }
            }
        }
    }
    st
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The block loader gives, sample for sample and bit for bit, what the
    /// ghost rule of [`Samples::at`] gives, on every axis length from one
    /// sample up (one and two samples: every offset a ghost or a repeat)
    /// and at every base a stencil can have.
    #[test]
    fn the_block_equals_the_ghost_rule_sample_by_sample() {
        for dims in [[1, 2, 3], [2, 1, 5], [3, 4, 2], [5, 5, 5], [2, 2, 2], [1, 1, 1]] {
            let len = dims.iter().product::<usize>();
            let data: alloc::vec::Vec<f32> =
                (0..len).map(|i| 1.0 + ((i as f32) * 0.77).sin() * 0.3).collect();
            let s = Samples { data: &data, lo: [0; 3], dims };
            let bases = |n: usize| 0..(n as isize - 1).max(1);
            for bz in bases(dims[2]) {
                for by in bases(dims[1]) {
                    for bx in bases(dims[0]) {
                        let b = [bx, by, bz];
                        let st = stencil_4x4x4(&s, dims, b);
                        for k in 0..4 {
                            for j in 0..4 {
                                for i in 0..4 {
                                    let idx = [b[0] + i - 1, b[1] + j - 1, b[2] + k - 1];
                                    let want = s.at(dims, idx);
                                    let got = st[(i + 4 * j + 16 * k) as usize];
                                    assert_eq!(got.to_bits(), want.to_bits(), "{dims:?} {idx:?}");
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}
