//! A min/max octree over a gridded scalar field, for skipping the regions
//! of a refractive-index volume where rays go (almost) straight.
//!
//! The grid's samples sit at integer *sample coordinates*. On the dual cell
//! `[i, i+1]×[j, j+1]×[k, k+1]`:
//! - the **trilinear** interpolant is bounded by its eight corner samples,
//!   and its gradient component along axis `a` by the largest corner
//!   difference along `a` divided by the spacing;
//! - the **Catmull–Rom** interpolant `f = Σ wᵢ(tx) wⱼ(ty) wₖ(tz) pᵢⱼₖ` reads
//!   the 4³ samples `i−1 … i+2`, with one layer of ghost samples outside
//!   the grid extrapolated linearly (`s₋₁ = 2s₀ − s₁`) as the sampler
//!   does; the bounds below run over that extended grid. Its weights sum to 1 with `Σ|wᵢ(t)| ≤ W = 5/4` (at
//!   `t = ½`), so `f` lies within the samples' range widened by
//!   `(W³ − 1)/2 = 0.4765625` of it. Summing by parts, `∂f/∂x · h =
//!   Σⱼₖ wⱼ wₖ Σₘ cₘ(tx) Δₘ` over the three differences `Δₘ = p_{m+1} − p_m`
//!   along x, with `c₋₁ = (3t² − 4t + 1)/2`, `c₀ = (−6t² + 6t + 1)/2`,
//!   `c₁ = (3t² − 2t)/2` and `Σ|cₘ| ≤ D = 3/2` (at `t = ½`); so
//!   `|∂f/∂x| ≤ D·W² · max|Δ| / h = 2.34375 · max|Δ| / h` over the 3 × 4 × 4
//!   differences along x in the neighbourhood (likewise y, z). Both bounds
//!   are checked against the sampler in the tests.
//!
//! Leaves
//! are bricks of [`BRICK`]³ dual cells; each node stores, over everything it
//! covers, `min n`, `max n` and `max |∇n|` (the Euclidean norm of the
//! per-axis bounds). Levels are dense arrays, finest first, over a
//! power-of-two cube of bricks.
//!
//! A ray may cross a node in one straight step when
//! `max|∇n| · diagonal < tolerance`: the deflection it skips is at most
//! `∫|∇⊥n|/n ds ≤ max|∇n| · diagonal / min n`, so `tolerance` is the
//! deflection (radians, for `n ≈ 1`) allowed per skipped node.
//! [`crate::trace_skipping`] asks with what is left of a per-ray budget,
//! so the sum over all the nodes a ray skips stays within its tolerance.

use alloc::vec::Vec;

use crate::{Interp, math::sqrt};

/// Dual cells per brick edge.
pub const BRICK: usize = 4;

/// Statistics of one octree node.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct OctNode {
    /// Smallest value covered.
    pub min: f32,
    /// Largest value covered.
    pub max: f32,
    /// Bound on `|∇|` of the trilinear interpolant (per world unit).
    pub grad_max: f32,
}

impl OctNode {
    const EMPTY: Self = Self { min: f32::INFINITY, max: f32::NEG_INFINITY, grad_max: 0.0 };

    fn merge(self, o: Self) -> Self {
        Self {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
            grad_max: self.grad_max.max(o.grad_max),
        }
    }
}

/// A node the ray may cross straight: its box in sample coordinates and
/// its statistics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothNode {
    /// Lower corner (sample coordinates).
    pub lo: [f64; 3],
    /// Upper corner.
    pub hi: [f64; 3],
    /// Its level (0: a brick).
    pub level: usize,
    /// Its statistics.
    pub stats: OctNode,
}

/// `(W³ − 1)/2`: how far past the samples' range (as a fraction of it) a
/// Catmull–Rom interpolant can overshoot (see the module docs).
const CATMULL_ROM_OVERSHOOT: f32 = 0.476_562_5;

/// `D·W²`: the Catmull–Rom gradient bound per unit sample difference.
const CATMULL_ROM_SLOPE: f32 = 2.343_75;

/// The octree (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Octree {
    /// The interpolant whose bounds the nodes hold.
    interp: Interp,
    /// Bricks per edge at the finest level (a power of two).
    side: usize,
    /// Dual cells per axis.
    cells: [usize; 3],
    /// Levels, finest first; level `l` has `(side >> l)³` nodes, x fastest.
    levels: Vec<Vec<OctNode>>,
    /// World diagonal of a level's (unclipped) node, finest first: a bound
    /// on every node's own diagonal there.
    diag: Vec<f64>,
    /// The least `grad_max` of a brick of the cells.
    smoothest_brick: f32,
}

/// Why an octree could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OctreeError {
    /// Fewer than 2 samples on an axis, or `samples.len()` is not the product
    /// of `dims`.
    BadDims,
    /// A sample is not finite or the spacing is not finite and positive.
    NonFinite,
}

impl core::fmt::Display for OctreeError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::BadDims => "octree needs ≥ 2 samples per axis and matching data",
            Self::NonFinite => "octree samples and spacing must be finite (spacing > 0)",
        })
    }
}

impl core::error::Error for OctreeError {}

impl Octree {
    /// Builds the octree over `samples` (x fastest) of a `dims` grid with
    /// the given spacing, for the trilinear interpolant.
    ///
    /// # Errors
    /// [`OctreeError`] for bad dimensions or non-finite input.
    pub fn build(
        dims: [usize; 3],
        samples: &[f32],
        spacing: [f64; 3],
    ) -> Result<Self, OctreeError> {
        Self::build_for(Interp::Trilinear, dims, samples, spacing)
    }

    /// Builds the octree for the interpolant `interp` (its nodes bound that
    /// interpolant's values and gradient; see the module docs).
    ///
    /// # Errors
    /// [`OctreeError`] for bad dimensions or non-finite input.
    pub fn build_for(
        interp: Interp,
        dims: [usize; 3],
        samples: &[f32],
        spacing: [f64; 3],
    ) -> Result<Self, OctreeError> {
        if dims.iter().any(|&d| d < 2)
            || dims[0].checked_mul(dims[1]).and_then(|v| v.checked_mul(dims[2]))
                != Some(samples.len())
        {
            return Err(OctreeError::BadDims);
        }
        if !samples.iter().all(|v| v.is_finite())
            || !spacing.iter().all(|h| h.is_finite() && *h > 0.0)
        {
            return Err(OctreeError::NonFinite);
        }
        let cells = [dims[0] - 1, dims[1] - 1, dims[2] - 1];
        let bricks = cells.map(|c| c.div_ceil(BRICK));
        let side = bricks.iter().copied().max().unwrap_or(1).next_power_of_two();
        let at = |i: usize, j: usize, k: usize| samples[i + dims[0] * (j + dims[1] * k)];
        // Finest level: one node per brick.
        let mut finest = alloc::vec![OctNode::EMPTY; side * side * side];
        let cell_bound = |(lo, hi): (f32, f32), d: [f32; 3]| {
            let g = (0..3).map(|a| f64::from(d[a]) / spacing[a]).map(|q| q * q).sum::<f64>();
            OctNode { min: lo, max: hi, grad_max: (sqrt(g) * (1.0 + 1e-6)) as f32 }
        };
        match interp {
            Interp::Trilinear => {
                for_each_cell(cells, |[i, j, k]| {
                    let mut lo = f32::INFINITY;
                    let mut hi = f32::NEG_INFINITY;
                    let mut d = [0.0f32; 3];
                    for c in 0..8 {
                        let (di, dj, dk) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
                        let v = at(i + di, j + dj, k + dk);
                        lo = lo.min(v);
                        hi = hi.max(v);
                        // Differences along each axis between paired corners.
                        if di == 0 {
                            d[0] = d[0].max((at(i + 1, j + dj, k + dk) - v).abs());
                        }
                        if dj == 0 {
                            d[1] = d[1].max((at(i + di, j + 1, k + dk) - v).abs());
                        }
                        if dk == 0 {
                            d[2] = d[2].max((at(i + di, j + dj, k + 1) - v).abs());
                        }
                    }
                    let b = (i / BRICK) + side * ((j / BRICK) + side * (k / BRICK));
                    finest[b] = finest[b].merge(cell_bound((lo, hi), d));
                });
            }
            Interp::CatmullRom => {
                let w = Windows::new(dims, samples);
                for_each_cell(cells, |[i, j, k]| {
                    let (lo, hi, d) = w.cell(i, j, k);
                    let over = CATMULL_ROM_OVERSHOOT * (hi - lo);
                    let range = (lo - over, hi + over);
                    let b = (i / BRICK) + side * ((j / BRICK) + side * (k / BRICK));
                    finest[b] =
                        finest[b].merge(cell_bound(range, d.map(|x| CATMULL_ROM_SLOPE * x)));
                });
            }
        }
        let mut levels = alloc::vec![finest];
        let mut s = side;
        while s > 1 {
            let prev = levels.last().expect("a level");
            let n = s / 2;
            let mut next = alloc::vec![OctNode::EMPTY; n * n * n];
            for k in 0..s {
                for j in 0..s {
                    for i in 0..s {
                        let p = (i / 2) + n * ((j / 2) + n * (k / 2));
                        next[p] = next[p].merge(prev[i + s * (j + s * k)]);
                    }
                }
            }
            levels.push(next);
            s = n;
        }
        let diag = (0..levels.len())
            .map(|l| {
                let size = (BRICK << l) as f64;
                sqrt(spacing.iter().map(|h| (size * h) * (size * h)).sum())
            })
            .collect();
        let mut smoothest_brick = f32::INFINITY;
        for k in 0..bricks[2] {
            for j in 0..bricks[1] {
                for i in 0..bricks[0] {
                    let g = levels[0][i + side * (j + side * k)].grad_max;
                    smoothest_brick = smoothest_brick.min(g);
                }
            }
        }
        Ok(Self { interp, side, cells, levels, diag, smoothest_brick })
    }

    /// The interpolant the nodes bound: skipping through a field is exact
    /// to its bound only if the field uses this interpolant.
    #[must_use]
    pub fn interp(&self) -> Interp {
        self.interp
    }

    /// Number of levels (finest is 0).
    #[must_use]
    pub fn levels(&self) -> usize {
        self.levels.len()
    }

    /// The root's statistics: the whole field's range and gradient bound.
    #[must_use]
    pub fn root(&self) -> OctNode {
        self.levels.last().map_or(OctNode::EMPTY, |l| l[0])
    }

    /// The finest-level brick holding the sample-coordinate point `p`, or
    /// `None` outside the cells. Points in one brick share their answer to
    /// [`Octree::smooth_node`] whenever the brick itself is not smooth.
    #[must_use]
    pub fn brick_of(&self, p: [f64; 3]) -> Option<[usize; 3]> {
        if (0..3).any(|a| !(p[a] >= 0.0 && p[a] <= self.cells[a] as f64)) {
            return None;
        }
        Some([0, 1, 2].map(|a| ((p[a] as usize).min(self.cells[a] - 1)) / BRICK))
    }

    /// The largest node containing the sample-coordinate point `p` that a
    /// ray may cross straight (`grad_max · diagonal < tolerance`, with the
    /// diagonal of an unclipped node of its level), or `None` where even
    /// the brick holding `p` is not smooth enough (or `p` lies outside the
    /// cells).
    #[must_use]
    pub fn smooth_node(&self, p: [f64; 3], tolerance: f64) -> Option<SmoothNode> {
        self.smooth_node_near(p, tolerance, self.levels.len() - 1)
    }

    /// [`Octree::smooth_node`], searching from level `hint` (e.g. the
    /// level of the previous node a ray crossed: neighbours tend to share
    /// it). The answer does not depend on the hint: a node's
    /// `grad_max · diagonal` never decreases from child to parent, so the
    /// smooth ancestors of a brick are exactly the levels below some `L`.
    #[must_use]
    pub fn smooth_node_near(&self, p: [f64; 3], tolerance: f64, hint: usize) -> Option<SmoothNode> {
        self.smooth_node_in(self.brick_of(p)?, tolerance, hint)
    }

    /// [`Octree::smooth_node_near`] for the brick `b` (as returned by
    /// [`Octree::brick_of`]); `None` also for a brick outside the tree.
    #[must_use]
    pub fn smooth_node_in(&self, b: [usize; 3], tolerance: f64, hint: usize) -> Option<SmoothNode> {
        if b.iter().any(|&v| v >= self.side) {
            return None;
        }
        let top = self.levels.len() - 1;
        let node_at = |l: usize| {
            let s = self.side >> l;
            let idx = [b[0] >> l, b[1] >> l, b[2] >> l];
            (idx, self.levels[l][idx[0] + s * (idx[1] + s * idx[2])])
        };
        let smooth = |n: &OctNode, l: usize| f64::from(n.grad_max) * self.diag[l] < tolerance;
        let mut l = hint.min(top);
        let (mut idx, mut node) = node_at(l);
        if smooth(&node, l) {
            // Up while the parent is smooth too.
            while l < top {
                let (pi, pn) = node_at(l + 1);
                if !smooth(&pn, l + 1) {
                    break;
                }
                (l, idx, node) = (l + 1, pi, pn);
            }
        } else {
            // Down until smooth (or the brick itself is not).
            loop {
                if l == 0 {
                    return None;
                }
                l -= 1;
                (idx, node) = node_at(l);
                if smooth(&node, l) {
                    break;
                }
            }
        }
        let size = (BRICK << l) as f64;
        let lo = idx.map(|v| v as f64 * size);
        let hi = [0, 1, 2].map(|a| (lo[a] + size).min(self.cells[a] as f64));
        Some(SmoothNode { lo, hi, level: l, stats: node })
    }
}

impl Octree {
    /// How far the straight line `p + t·ds` (`p` in sample coordinates,
    /// `ds` the sample coordinates moved per unit of `t`) runs through
    /// bricks that are not smooth at `tolerance` (see
    /// [`Octree::smooth_node`]) from the brick holding `p`: the `t` where
    /// it enters the first smooth brick, 0 if the brick holding `p` is
    /// smooth or `p` lies outside the cells, `+∞` if it leaves the cells
    /// without meeting one. A brick walk (Amanatides & Woo 1987) reading
    /// the finest level only: a brick not smooth has no smooth ancestor.
    #[must_use]
    pub fn rough_run(&self, p: [f64; 3], ds: [f64; 3], tolerance: f64) -> f64 {
        let Some(mut b) = self.brick_of(p) else { return 0.0 };
        // The smoothest brick rough: the line leaves the cells in rough
        // bricks (a dense field answers here, walking nothing).
        if f64::from(self.smoothest_brick) * self.diag[0] >= tolerance {
            return f64::INFINITY;
        }
        let smooth = |b: [usize; 3]| {
            let n = self.levels[0][b[0] + self.side * (b[1] + self.side * b[2])];
            f64::from(n.grad_max) * self.diag[0] < tolerance
        };
        let mut t = 0.0f64;
        // Each move enters a new brick along one axis, monotonically: at
        // most the bricks of the three axes together.
        for _ in 0..3 * self.side + 3 {
            if smooth(b) {
                return t;
            }
            let (mut exit, mut axis) = (f64::INFINITY, None);
            for a in 0..3 {
                let face = if ds[a] > 0.0 {
                    ((b[a] + 1) * BRICK) as f64
                } else if ds[a] < 0.0 {
                    (b[a] * BRICK) as f64
                } else {
                    continue;
                };
                let at = (face - p[a]) / ds[a];
                if at < exit {
                    (exit, axis) = (at, Some(a));
                }
            }
            let Some(a) = axis.filter(|_| exit.is_finite()) else { return f64::INFINITY };
            t = t.max(exit);
            if ds[a] > 0.0 {
                b[a] += 1;
                if b[a] * BRICK >= self.cells[a] {
                    return f64::INFINITY;
                }
            } else if b[a] == 0 {
                return f64::INFINITY;
            } else {
                b[a] -= 1;
            }
        }
        t
    }

    /// Covers the cells with the largest smooth nodes (the ones
    /// [`Octree::smooth_node`] returns) and the bricks that are not smooth,
    /// calling `f(node, smooth)` once for each, in no particular order.
    /// Each node's box is clipped to the cells, as there.
    pub fn partition(&self, tolerance: f64, mut f: impl FnMut(&SmoothNode, bool)) {
        self.partition_at(self.levels.len() - 1, [0; 3], tolerance, &mut f);
    }

    fn partition_at(
        &self,
        l: usize,
        idx: [usize; 3],
        tolerance: f64,
        f: &mut impl FnMut(&SmoothNode, bool),
    ) {
        let size = (BRICK << l) as f64;
        let lo = idx.map(|v| v as f64 * size);
        if (0..3).any(|a| lo[a] >= self.cells[a] as f64) {
            return;
        }
        let s = self.side >> l;
        let stats = self.levels[l][idx[0] + s * (idx[1] + s * idx[2])];
        // Top down, the first smooth node is the largest: smoothness only
        // grows from parent to child.
        let smooth = f64::from(stats.grad_max) * self.diag[l] < tolerance;
        if smooth || l == 0 {
            let hi = [0, 1, 2].map(|a| (lo[a] + size).min(self.cells[a] as f64));
            f(&SmoothNode { lo, hi, level: l, stats }, smooth);
            return;
        }
        for c in 0..8 {
            let child = [2 * idx[0] + (c & 1), 2 * idx[1] + ((c >> 1) & 1), 2 * idx[2] + (c >> 2)];
            self.partition_at(l - 1, child, tolerance, f);
        }
    }
}

/// Calls `f([i, j, k])` for every dual cell, x fastest.
fn for_each_cell(cells: [usize; 3], mut f: impl FnMut([usize; 3])) {
    for k in 0..cells[2] {
        for j in 0..cells[1] {
            for i in 0..cells[0] {
                f([i, j, k]);
            }
        }
    }
}

/// Per-cell maxima and minima over the Catmull–Rom neighbourhoods,
/// computed separably (three passes of a sliding window per axis) so a
/// cell costs a few lookups, not 4³. They run over the grid extended by
/// the sampler's ghost layer, so the cell with lower corner `(i, j, k)`
/// reads extended samples `i … i+3` (sample `i − 1` is extended `i`).
struct Windows {
    /// The extended grid's dimensions (`dims + 2`).
    ext: [usize; 3],
    /// Samples' min and max over extended offsets `0 … 3` on every axis.
    lo: Vec<f32>,
    hi: Vec<f32>,
    /// Per axis `a`: `max |Δ|` of the differences along `a` that a cell's
    /// interpolant reads (pairs `0 … 2` along `a`, samples `0 … 3` across
    /// it, in extended offsets).
    diff: [Vec<f32>; 3],
}

impl Windows {
    fn new(dims: [usize; 3], samples: &[f32]) -> Self {
        let ext = dims.map(|n| n + 2);
        let e = extend(dims, samples);
        let lo = window(ext, e.clone(), [(0, 3); 3], f32::min);
        let hi = window(ext, e.clone(), [(0, 3); 3], f32::max);
        let diff = [0, 1, 2].map(|a| {
            // |p(x + eₐ) − p(x)| at each extended sample, 0 on the last.
            let stride = [1, ext[0], ext[0] * ext[1]][a];
            let mut d = alloc::vec![0.0f32; e.len()];
            for (idx, v) in d.iter_mut().enumerate() {
                let c = [idx % ext[0], (idx / ext[0]) % ext[1], idx / (ext[0] * ext[1])];
                if c[a] + 1 < ext[a] {
                    *v = (e[idx + stride] - e[idx]).abs();
                }
            }
            let mut reach = [(0, 3); 3];
            reach[a] = (0, 2);
            window(ext, d, reach, f32::max)
        });
        Self { ext, lo, hi, diff }
    }

    /// `(min, max, max |Δ| per axis)` over the neighbourhood of the dual
    /// cell with lower corner `(i, j, k)`.
    fn cell(&self, i: usize, j: usize, k: usize) -> (f32, f32, [f32; 3]) {
        let idx = i + self.ext[0] * (j + self.ext[1] * k);
        (self.lo[idx], self.hi[idx], [self.diff[0][idx], self.diff[1][idx], self.diff[2][idx]])
    }
}

/// The samples with one ghost layer on every side, extrapolated linearly
/// one axis after another (`s₋₁ = 2s₀ − s₁`, `s_n = 2s_{n−1} − s_{n−2}`;
/// a one-sample axis repeats its sample), as the grid's sampler does.
fn extend(dims: [usize; 3], samples: &[f32]) -> Vec<f32> {
    let ext = dims.map(|n| n + 2);
    let mut e = alloc::vec![0.0f32; ext[0] * ext[1] * ext[2]];
    let at = |i: usize, j: usize, k: usize| i + ext[0] * (j + ext[1] * k);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                e[at(i + 1, j + 1, k + 1)] = samples[i + dims[0] * (j + dims[1] * k)];
            }
        }
    }
    // Along each axis in turn, over the lines already filled.
    for a in 0..3 {
        let n = dims[a];
        let stride = [1, ext[0], ext[0] * ext[1]][a];
        for idx in 0..e.len() {
            let c = [idx % ext[0], (idx / ext[0]) % ext[1], idx / (ext[0] * ext[1])];
            // Lines start at extended index 0 on axis `a`; the axes done
            // before are filled everywhere, the ones after only inside.
            let inside = (0..3).all(|b| b <= a || (1..=dims[b]).contains(&c[b]));
            if c[a] != 0 || !inside {
                continue;
            }
            let s = |t: usize| e[idx + t * stride];
            let (first, last) =
                if n < 2 { (s(1), s(n)) } else { (2.0 * s(1) - s(2), 2.0 * s(n) - s(n - 1)) };
            e[idx] = first;
            e[idx + (n + 1) * stride] = last;
        }
    }
    e
}

/// `data` with each value replaced by `pick` over the window
/// `reach[a].0 ..= reach[a].1` around it on every axis `a` (indices clamped
/// to the grid, as the Catmull–Rom sampler clamps).
fn window(
    dims: [usize; 3],
    mut data: Vec<f32>,
    reach: [(isize, isize); 3],
    pick: fn(f32, f32) -> f32,
) -> Vec<f32> {
    let mut line = Vec::new();
    for a in 0..3 {
        let (n, stride) = (dims[a], [1, dims[0], dims[0] * dims[1]][a]);
        let lines = data.len() / n;
        for l in 0..lines {
            // The first index of line `l` along axis `a`.
            let start = match a {
                0 => l * n,
                1 => (l % dims[0]) + (l / dims[0]) * dims[0] * dims[1],
                _ => l,
            };
            line.clear();
            line.extend((0..n).map(|t| data[start + t * stride]));
            for t in 0..n {
                let (from, to) = (
                    (t as isize + reach[a].0).clamp(0, n as isize - 1) as usize,
                    (t as isize + reach[a].1).clamp(0, n as isize - 1) as usize,
                );
                data[start + t * stride] = line[from..=to].iter().copied().fold(line[from], pick);
            }
        }
    }
    data
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Catmull–Rom constants: `Σ|wᵢ(t)| ≤ 5/4` and `Σ|cₘ(t)| ≤ 3/2`
    /// over `t ∈ [0, 1]` (finely sampled; the maxima are at `t = ½`).
    #[test]
    fn catmull_rom_weight_sums_are_bounded_as_stated() {
        let (mut w_max, mut c_max) = (0.0f64, 0.0f64);
        for n in 0..=10_000 {
            let t = f64::from(n) / 10_000.0;
            let (t2, t3) = (t * t, t * t * t);
            let w = [
                0.5 * (-t3 + 2.0 * t2 - t),
                0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
                0.5 * (-3.0 * t3 + 4.0 * t2 + t),
                0.5 * (t3 - t2),
            ];
            let c = [
                0.5 * (3.0 * t2 - 4.0 * t + 1.0),
                0.5 * (-6.0 * t2 + 6.0 * t + 1.0),
                0.5 * (3.0 * t2 - 2.0 * t),
            ];
            w_max = w_max.max(w.iter().map(|v| v.abs()).sum());
            c_max = c_max.max(c.iter().map(|v| v.abs()).sum());
        }
        assert!((w_max - 1.25).abs() < 1e-12 && (c_max - 1.5).abs() < 1e-12, "{w_max} {c_max}");
        let (w3, slope) = (w_max.powi(3), c_max * w_max * w_max);
        assert_eq!(((w3 - 1.0) / 2.0) as f32, CATMULL_ROM_OVERSHOOT);
        assert_eq!(slope as f32, CATMULL_ROM_SLOPE);
    }

    /// The Catmull–Rom slope bound is attained: samples `q(i)·s(j)·s(k)`
    /// with `q = (0, −1, 0, −1)` (differences −1, +1, −1, matching the signs
    /// of `cₘ(½)`) and `s = (−1, 1, 1, −1)` (the signs of `wⱼ(½)`) give
    /// `∂f/∂x = D·W² · max|Δ| / h` at the cell centre, so no smaller
    /// constant would do.
    #[test]
    fn catmull_rom_slope_bound_is_tight() {
        let (q, sgn) = ([0.0f32, -1.0, 0.0, -1.0], [-1.0f32, 1.0, 1.0, -1.0]);
        let mut data = alloc::vec::Vec::new();
        for sk in sgn {
            for sj in sgn {
                for qi in q {
                    data.push(5.0 + qi * sj * sk);
                }
            }
        }
        let h = 0.5;
        let grid = crate::Grid::new([4; 3], glam::DVec3::ZERO, glam::DVec3::splat(h), data.clone())
            .unwrap();
        let (_, g) = grid.sample(glam::DVec3::splat(1.5 * h), Interp::CatmullRom);
        let (_, _, d) = Windows::new([4; 3], &data).cell(1, 1, 1);
        let bound = f64::from(CATMULL_ROM_SLOPE * d[0]) / h;
        assert_eq!(d[0], 1.0);
        assert!((g.x.abs() - bound).abs() < 1e-9 * bound, "{} vs {bound}", g.x);
    }

    /// On random grids, the interpolant's value and gradient at random
    /// points (faces included) stay within the bounds the finest node over
    /// them holds — for both interpolants.
    #[test]
    fn nodes_bound_the_interpolant_they_were_built_for() {
        let mut state = 0x1234_5678_9abc_def0u64;
        // SplitMix64: a fixed stream of uniform numbers in [0, 1).
        let mut next = || {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        };
        for interp in [Interp::Trilinear, Interp::CatmullRom] {
            for trial in 0..6 {
                let dims = [5 + trial, 7, 4 + 2 * trial];
                let spacing = [0.5, 0.25 + 0.1 * trial as f64, 1.0];
                let n = dims[0] * dims[1] * dims[2];
                // Rough data: sharp steps and noise, where overshoot shows.
                let data: alloc::vec::Vec<f32> = (0..n)
                    .map(|_| {
                        if next() < 0.2 { 2.0 + next() as f32 } else { 1.0 + 0.01 * next() as f32 }
                    })
                    .collect();
                let origin = glam::DVec3::new(-1.0, 0.5, 2.0);
                let grid = crate::Grid::new(dims, origin, spacing.into(), data.clone()).unwrap();
                let tree = Octree::build_for(interp, dims, &data, spacing).unwrap();
                for n in 0..4000 {
                    // Half the points in the cells next to a face, where
                    // the sampler's ghost samples enter the stencil.
                    let mut p = [0, 1, 2].map(|a| next() * (dims[a] - 1) as f64);
                    if n % 2 == 0 {
                        let a = n / 2 % 3;
                        let hi = (dims[a] - 1) as f64;
                        p[a] = if next() < 0.5 { next() } else { hi - next() };
                    }
                    let b = tree.brick_of(p).unwrap();
                    let node = tree.levels[0][b[0] + tree.side * (b[1] + tree.side * b[2])];
                    let x = origin + glam::DVec3::from(p) * glam::DVec3::from(spacing);
                    let (v, g) = grid.sample(x, interp);
                    assert!(
                        v >= f64::from(node.min) - 1e-6 && v <= f64::from(node.max) + 1e-6,
                        "{interp:?}: value {v} outside [{}, {}]",
                        node.min,
                        node.max
                    );
                    assert!(
                        g.length() <= f64::from(node.grad_max) * (1.0 + 1e-5),
                        "{interp:?}: |∇| {} above {}",
                        g.length(),
                        node.grad_max
                    );
                }
            }
        }
    }

    #[test]
    fn stats_bound_a_linear_ramp_and_uniform_regions_are_smooth() {
        // n = 1 + 0.01·x on 17³ samples, spacing 0.5 → |∇n| = 0.01.
        let dims = [17, 17, 17];
        let data: alloc::vec::Vec<f32> =
            (0..17 * 17 * 17).map(|i| 1.0 + 0.01 * 0.5 * (i % 17) as f32).collect();
        let t = Octree::build(dims, &data, [0.5; 3]).unwrap();
        let r = t.root();
        assert!((r.grad_max - 0.01).abs() < 1e-5, "{}", r.grad_max);
        assert_eq!((r.min, r.max), (1.0, 1.0 + 0.01 * 0.5 * 16.0));
        // The whole volume (diagonal 8·√3) is smooth for a loose tolerance…
        let n = t.smooth_node([3.0, 3.0, 3.0], 0.2).unwrap();
        assert_eq!((n.lo, n.hi), ([0.0; 3], [16.0; 3]));
        // …only a brick for a tighter one, nothing for a tight one.
        let n = t.smooth_node([3.0, 3.0, 3.0], 0.04).unwrap();
        assert_eq!(n.hi, [4.0; 3]);
        assert!(t.smooth_node([3.0, 3.0, 3.0], 1e-3).is_none());
        assert!(t.smooth_node([-1.0, 3.0, 3.0], 1.0).is_none());
        assert_eq!(Octree::build([1, 2, 2], &[0.0; 4], [1.0; 3]), Err(OctreeError::BadDims));
        assert_eq!(Octree::build([2, 2, 2], &[f32::NAN; 8], [1.0; 3]), Err(OctreeError::NonFinite));
    }

    #[test]
    fn the_search_hint_never_changes_the_answer() {
        // Two bumps of different strength on 33³ samples: nodes of every
        // level are smooth somewhere for some tolerance.
        let n = 33;
        let data: alloc::vec::Vec<f32> = (0..n * n * n)
            .map(|i| {
                let (x, y, z) = ((i % n) as f32, ((i / n) % n) as f32, (i / (n * n)) as f32);
                let b = |cx: f32, a: f32| {
                    a * (-((x - cx).powi(2) + (y - 9.0).powi(2) + (z - 20.0).powi(2)) / 8.0).exp()
                };
                1.0 + b(6.0, 1e-2) + b(26.0, 1e-4)
            })
            .collect();
        let t = Octree::build([n; 3], &data, [0.1; 3]).unwrap();
        let mut smooth_levels = [0usize; 8];
        for tol in [1e-7, 1e-5, 1e-3, 1e-1, 1.0] {
            for k in (0..32).step_by(3) {
                for j in (0..32).step_by(5) {
                    for i in 0..32 {
                        let p = [i as f64 + 0.5, j as f64 + 0.25, k as f64 + 0.75];
                        let want = t.smooth_node(p, tol);
                        if let Some(w) = want {
                            smooth_levels[w.level] += 1;
                        }
                        for hint in 0..=t.levels() {
                            assert_eq!(
                                t.smooth_node_near(p, tol, hint),
                                want,
                                "{p:?} {tol} {hint}"
                            );
                        }
                    }
                }
            }
        }
        assert!(smooth_levels[..t.levels()].iter().all(|&c| c > 0), "{smooth_levels:?}");
    }

    #[test]
    fn the_partition_tiles_the_cells_with_the_nodes_smooth_node_finds() {
        // The two-bump field on 29³ samples (28 cells: a partial brick
        // row on the padded side), several tolerances.
        let n = 29;
        let data: alloc::vec::Vec<f32> = (0..n * n * n)
            .map(|i| {
                let (x, y, z) = ((i % n) as f32, ((i / n) % n) as f32, (i / (n * n)) as f32);
                let r2 = (x - 7.0).powi(2) + (y - 9.0).powi(2) + (z - 20.0).powi(2);
                1.0 + 1e-2 * (-r2 / 8.0).exp()
            })
            .collect();
        let t = Octree::build([n; 3], &data, [0.1; 3]).unwrap();
        for tol in [1e-7, 1e-4, 1e-3, 1e-2, 1.0] {
            let mut volume = 0.0;
            let (mut rough, mut smooth) = (0, 0);
            t.partition(tol, |node, is_smooth| {
                volume += (0..3).map(|a| node.hi[a] - node.lo[a]).product::<f64>();
                let mid = [0, 1, 2].map(|a| 0.5 * (node.lo[a] + node.hi[a]));
                if is_smooth {
                    smooth += 1;
                    assert_eq!(t.smooth_node(mid, tol).as_ref(), Some(node), "{tol} {mid:?}");
                } else {
                    rough += 1;
                    assert_eq!(node.level, 0);
                    assert!(t.smooth_node(mid, tol).is_none(), "{tol} {mid:?}");
                }
            });
            // Disjoint boxes (each is what smooth_node returns for its
            // points) whose volumes add up to the cells': a tiling.
            assert_eq!(volume, 28.0f64.powi(3), "{tol}");
            assert!(tol > 1e-3 || rough > 0, "{tol}");
            assert!(tol < 1e-4 || smooth > 0, "{tol}");
        }
    }
}
