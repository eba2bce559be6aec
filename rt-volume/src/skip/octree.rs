//! A min/max octree over a gridded scalar field, for skipping the regions
//! of a refractive-index volume where rays go (almost) straight.
//!
//! The grid's samples sit at integer *sample coordinates*; the trilinear
//! interpolant on the dual cell `[i, i+1]×[j, j+1]×[k, k+1]` is bounded by
//! its eight corner samples, and its gradient component along axis `a` by
//! the largest corner difference along `a` divided by the spacing. Leaves
//! are bricks of [`BRICK`]³ dual cells; each node stores, over everything it
//! covers, `min n`, `max n` and `max |∇n|` (the Euclidean norm of the
//! per-axis bounds). Levels are dense arrays, finest first, over a
//! power-of-two cube of bricks.
//!
//! A ray may cross a node in one straight step when
//! `max|∇n| · diagonal < tolerance`: the deflection it skips is at most
//! `∫|∇⊥n|/n ds ≤ max|∇n| · diagonal / min n`, so `tolerance` is the
//! deflection (radians, for `n ≈ 1`) allowed per skipped node.

use alloc::vec::Vec;

use crate::math::sqrt;

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

/// The octree (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Octree {
    /// Bricks per edge at the finest level (a power of two).
    side: usize,
    /// Dual cells per axis.
    cells: [usize; 3],
    /// Levels, finest first; level `l` has `(side >> l)³` nodes, x fastest.
    levels: Vec<Vec<OctNode>>,
    /// World diagonal of a level's (unclipped) node, finest first: a bound
    /// on every node's own diagonal there.
    diag: Vec<f64>,
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
    /// the given spacing.
    ///
    /// # Errors
    /// [`OctreeError`] for bad dimensions or non-finite input.
    pub fn build(
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
        for k in 0..cells[2] {
            for j in 0..cells[1] {
                for i in 0..cells[0] {
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
                    let g =
                        (0..3).map(|a| f64::from(d[a]) / spacing[a]).map(|q| q * q).sum::<f64>();
                    let node =
                        OctNode { min: lo, max: hi, grad_max: (sqrt(g) * (1.0 + 1e-6)) as f32 };
                    let b = (i / BRICK) + side * ((j / BRICK) + side * (k / BRICK));
                    finest[b] = finest[b].merge(node);
                }
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
        Ok(Self { side, cells, levels, diag })
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

#[cfg(test)]
mod tests {
    use super::*;

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
