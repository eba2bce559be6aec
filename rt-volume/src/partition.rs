//! Partitioning a grid into bricks, one per rank of a distributed trace.
//!
//! The samples along each axis are cut into contiguous runs; the brick
//! `(i, j, k)` (rank `i + px·(j + py·k)`) owns the cells of its samples:
//! the world-space box between the cell faces at its first and one past
//! its last sample. The planes are computed once, in f64, from the global
//! origin and spacing, and [`Bricks::owner`] uses them half-open (the last
//! brick closed), so every point belongs to exactly one brick; that is
//! what a distributed trace's legs agree on.

use alloc::vec::Vec;

use glam::DVec3;

use crate::{
    Bounds, Interp,
    brick::{BrickError, GridInfo},
    stencil::{footprint, locate},
};

/// A partition of a grid's samples into `px × py × pz` bricks.
#[derive(Clone, Debug, PartialEq)]
pub struct Bricks {
    info: GridInfo,
    parts: [usize; 3],
    /// Per axis, the first sample of each brick and the sample count last.
    splits: [Vec<usize>; 3],
    /// Per axis, the cell faces at `splits` (the outer two the grid's
    /// bounds).
    planes: [Vec<f64>; 3],
}

impl Bricks {
    /// `parts[a]` bricks along axis `a`, each run of samples `⌊i·n/p⌋ ..
    /// ⌊(i+1)·n/p⌋`.
    ///
    /// # Errors
    /// [`BrickError::Grid`] for a bad header; [`BrickError::Partition`]
    /// for a zero part count or more parts than samples along an axis.
    pub fn new(info: GridInfo, parts: [usize; 3]) -> Result<Self, BrickError> {
        info.check()?;
        if (0..3).any(|a| parts[a] == 0 || parts[a] > info.dims[a]) {
            return Err(BrickError::Partition);
        }
        let b = info.bounds();
        let splits = [0, 1, 2].map(|a| {
            let (n, p) = (info.dims[a] as u128, parts[a] as u128);
            (0..=p).map(|i| (i * n / p) as usize).collect::<Vec<_>>()
        });
        let planes = [0, 1, 2].map(|a| {
            let s = &splits[a];
            let mut v: Vec<f64> =
                s.iter().map(|&i| info.origin[a] + (i as f64 - 0.5) * info.spacing[a]).collect();
            v[0] = b.min[a];
            v[parts[a]] = b.max[a];
            v
        });
        Ok(Self { info, parts, splits, planes })
    }

    /// A near-cubic partition into exactly `ranks` bricks: of all
    /// factorisations `px·py·pz = ranks` that fit the samples, the one
    /// whose bricks have the least surface (the ghost layers and the
    /// traffic between ranks scale with it); the first such in the order
    /// `px`, then `py`, ascending. A prime count cuts the longest axis.
    ///
    /// # Errors
    /// [`BrickError::Partition`] for zero ranks, more than 2²⁰, or no
    /// factorisation that fits; [`BrickError::Grid`] for a bad header.
    pub fn for_ranks(info: GridInfo, ranks: usize) -> Result<Self, BrickError> {
        info.check()?;
        if ranks == 0 || ranks > 1 << 20 {
            return Err(BrickError::Partition);
        }
        let divisors: Vec<usize> = (1..=ranks).filter(|&d| ranks.is_multiple_of(d)).collect();
        let extent = [0, 1, 2].map(|a| info.dims[a] as f64 * info.spacing[a]);
        let mut best: Option<([usize; 3], f64)> = None;
        for &px in &divisors {
            for &py in divisors.iter().filter(|&&py| (ranks / px).is_multiple_of(py)) {
                let p = [px, py, ranks / px / py];
                if (0..3).any(|a| p[a] > info.dims[a]) {
                    continue;
                }
                let e = [0, 1, 2].map(|a| extent[a] / p[a] as f64);
                let area = e[0] * e[1] + e[1] * e[2] + e[0] * e[2];
                if best.is_none_or(|(_, b)| area < b) {
                    best = Some((p, area));
                }
            }
        }
        let (parts, _) = best.ok_or(BrickError::Partition)?;
        Self::new(info, parts)
    }

    /// Bricks per axis.
    #[must_use]
    pub fn parts(&self) -> [usize; 3] {
        self.parts
    }

    /// How many bricks (ranks).
    #[must_use]
    pub fn count(&self) -> usize {
        self.parts[0] * self.parts[1] * self.parts[2]
    }

    /// The grid's header.
    #[must_use]
    pub fn info(&self) -> GridInfo {
        self.info
    }

    /// The brick owning `x`: per axis, the run whose planes hold it
    /// half-open, `plane_i ≤ x < plane_{i+1}`, the last closed; points
    /// outside the grid's bounds belong to the nearest brick (NaN to the
    /// first).
    #[must_use]
    pub fn owner(&self, x: DVec3) -> usize {
        let i = [0, 1, 2].map(|a| {
            let inner = &self.planes[a][1..self.parts[a]];
            inner.partition_point(|&p| p <= x[a])
        });
        i[0] + self.parts[0] * (i[1] + self.parts[1] * i[2])
    }

    fn coords(&self, rank: usize) -> [usize; 3] {
        assert!(rank < self.count(), "rank {rank} of {} bricks", self.count());
        let [px, py, _] = self.parts;
        [rank % px, (rank / px) % py, rank / (px * py)]
    }

    /// The box brick `rank` owns (closed; [`Bricks::owner`] breaks the
    /// ties on shared faces).
    ///
    /// # Panics
    /// If `rank ≥` [`Bricks::count`].
    #[must_use]
    pub fn owned(&self, rank: usize) -> Bounds {
        let c = self.coords(rank);
        let p = |a: usize, i: usize| self.planes[a][c[a] + i];
        Bounds::new(DVec3::new(p(0, 0), p(1, 0), p(2, 0)), DVec3::new(p(0, 1), p(1, 1), p(2, 1)))
    }

    /// The samples brick `rank` owns, `(lo, hi)` (global, `hi` exclusive).
    ///
    /// # Panics
    /// If `rank ≥` [`Bricks::count`].
    #[must_use]
    pub fn samples_owned(&self, rank: usize) -> ([usize; 3], [usize; 3]) {
        let c = self.coords(rank);
        ([0, 1, 2].map(|a| self.splits[a][c[a]]), [0, 1, 2].map(|a| self.splits[a][c[a] + 1]))
    }

    /// The sample box `(lo, hi)` (global, `hi` exclusive, clamped to the
    /// grid) brick `rank` must load so that `interp`'s stencil is stored
    /// at every point of the grid's bounds within `reach` (world distance,
    /// per axis) of its owned box — where a step that starts in it may
    /// evaluate the field (see [`crate::step_reach`]; the tracer evaluates
    /// points outside the bounds at their nearest point inside). One
    /// sample more on each side absorbs the rounding of the points.
    ///
    /// # Errors
    /// [`BrickError::Reach`] for a reach not finite and `≥ 0` (an infinite
    /// one is accepted: the whole grid).
    ///
    /// # Panics
    /// If `rank ≥` [`Bricks::count`].
    pub fn samples_needed(
        &self,
        rank: usize,
        reach: f64,
        interp: Interp,
    ) -> Result<([usize; 3], [usize; 3]), BrickError> {
        if reach.is_nan() || reach < 0.0 {
            return Err(BrickError::Reach);
        }
        let own = self.owned(rank);
        let l = self.info.lattice();
        // Stencil bases are monotone in x: the corners bound them.
        let (lo, _) = footprint(self.info.dims, locate(&l, own.min - reach).base, interp);
        let (_, hi) = footprint(self.info.dims, locate(&l, own.max + reach).base, interp);
        Ok((lo.map(|v| v.saturating_sub(1)), [0, 1, 2].map(|a| (hi[a] + 2).min(self.info.dims[a]))))
    }
}
