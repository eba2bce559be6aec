//! A brick of a gridded field: a box of a grid's samples, interpolated in
//! the global grid's coordinates.
//!
//! Invariant: for every point whose interpolation stencil lies in the
//! stored box ([`BrickField::covers`]), [`BrickField`]'s `eval` is bit for
//! bit the whole grid's [`GridField`](crate::GridField) `eval` (one
//! interpolation code, see `stencil.rs`); anywhere else it is NaN, so a
//! trace that strays past a brick's ghost layers ends in
//! [`TraceError::BadField`](crate::TraceError::BadField), never in a
//! wrong value.

use alloc::vec::Vec;
use core::fmt;

use glam::DVec3;

use crate::{
    Bounds, Grid, GridError, IndexField, Interp,
    stencil::{Lattice, Located, Samples, footprint, interpolate, locate},
};

/// A grid's header: its geometry without its samples (what every rank of
/// a distributed trace knows about the whole grid).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridInfo {
    /// Samples per axis.
    pub dims: [usize; 3],
    /// Centre of sample `(0, 0, 0)`.
    pub origin: DVec3,
    /// Cell size.
    pub spacing: DVec3,
}

impl GridInfo {
    /// A header, checked: no zero dimension, a sample count that fits a
    /// `usize` (it may exceed [`Grid::MAX_SAMPLES`]: no rank needs to hold
    /// it all), a finite origin and a finite positive spacing.
    ///
    /// # Errors
    /// [`GridError::ZeroDim`], [`GridError::TooLarge`] or
    /// [`GridError::BadGeometry`].
    pub fn new(dims: [usize; 3], origin: DVec3, spacing: DVec3) -> Result<Self, GridError> {
        let info = Self { dims, origin, spacing };
        info.check()?;
        Ok(info)
    }

    /// [`GridInfo::new`]'s checks (the fields are public).
    pub(crate) fn check(&self) -> Result<(), GridError> {
        if self.dims.contains(&0) {
            return Err(GridError::ZeroDim);
        }
        self.total().ok_or(GridError::TooLarge)?;
        let s = self.spacing;
        if !(self.origin.is_finite() && s.is_finite() && s.cmpgt(DVec3::ZERO).all()) {
            return Err(GridError::BadGeometry);
        }
        Ok(())
    }

    /// `nx·ny·nz`, or `None` if it overflows.
    #[must_use]
    pub fn total(&self) -> Option<usize> {
        self.dims[0].checked_mul(self.dims[1])?.checked_mul(self.dims[2])
    }

    /// The outer cell faces: `origin − h/2` to `origin + (dims − ½)·h`
    /// (the same expression as [`Grid::bounds`]).
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        let d = DVec3::new(self.dims[0] as f64, self.dims[1] as f64, self.dims[2] as f64);
        Bounds::new(self.origin - 0.5 * self.spacing, self.origin + (d - 0.5) * self.spacing)
    }

    pub(crate) fn lattice(&self) -> Lattice {
        Lattice { dims: self.dims, origin: self.origin, inv_spacing: self.spacing.recip() }
    }
}

impl Grid {
    /// The grid's header.
    #[must_use]
    pub fn info(&self) -> GridInfo {
        GridInfo { dims: self.dims(), origin: self.origin(), spacing: self.spacing() }
    }

    /// Bounds on `interp`'s index and gradient anywhere in the grid (for
    /// [`crate::step_reach`]).
    #[must_use]
    pub fn index_bounds(&self, interp: Interp) -> IndexBounds {
        index_bounds(&self.samples(), self.spacing().recip(), interp)
    }
}

/// Upper bounds on an interpolated index and the length of its gradient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IndexBounds {
    /// `n ≤ n_max`.
    pub n_max: f64,
    /// `|∇n| ≤ grad_max`.
    pub grad_max: f64,
}

impl IndexBounds {
    /// Bounds holding where either holds (e.g. over all bricks).
    #[must_use]
    pub fn max(self, o: Self) -> Self {
        let m = |a: f64, b: f64| if b > a { b } else { a };
        Self { n_max: m(self.n_max, o.n_max), grad_max: m(self.grad_max, o.grad_max) }
    }
}

/// [`IndexBounds`] over the cells of a box of samples, from the largest
/// sample `M` and the largest difference `Δₐ` between neighbours along
/// each axis.
///
/// Trilinear: a convex combination, `n ≤ M`; `∂ₐn` a weighted mean of
/// differences along `a` over `hₐ`, `|∂ₐn| ≤ Δₐ/hₐ`. Catmull–Rom: the
/// ghost samples `2s₀ − s₁` keep every difference an interior one and
/// exceed `M` by at most `ΣΔ`; the 4³ stencil spans at most `3ΣΔ` and the
/// negative weights sum to at most `(1.25³ − 1)/2` (`Σ|w| ≤ 1.25` per
/// axis), so `n ≤ M + ΣΔ + 1.43·ΣΔ`; the derivative, written on the three
/// differences along `a`, has weights summing to at most 1.5 in
/// magnitude, times `1.25²` across, so `|∂ₐn| ≤ 2.35·Δₐ/hₐ`.
pub(crate) fn index_bounds(s: &Samples<'_>, inv_spacing: DVec3, interp: Interp) -> IndexBounds {
    let [nx, ny, nz] = s.dims;
    let (mut top, mut diff) = (f64::NEG_INFINITY, [0.0f64; 3]);
    let at = |i: usize, j: usize, k: usize| f64::from(s.data[i + nx * (j + ny * k)]);
    let mut widen = |a: usize, d: f64| {
        if d > diff[a] {
            diff[a] = d;
        }
    };
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let v = at(i, j, k);
                if v > top {
                    top = v;
                }
                if i + 1 < nx {
                    widen(0, (at(i + 1, j, k) - v).abs());
                }
                if j + 1 < ny {
                    widen(1, (at(i, j + 1, k) - v).abs());
                }
                if k + 1 < nz {
                    widen(2, (at(i, j, k + 1) - v).abs());
                }
            }
        }
    }
    let d = DVec3::from(diff);
    match interp {
        Interp::Trilinear => IndexBounds { n_max: top, grad_max: (d * inv_spacing).length() },
        Interp::CatmullRom => {
            let sum = d.x + d.y + d.z;
            let negative = 0.5 * (1.25f64 * 1.25 * 1.25 - 1.0);
            IndexBounds {
                n_max: top + sum + negative * 3.0 * sum,
                grad_max: 1.5 * 1.25 * 1.25 * (d * inv_spacing).length(),
            }
        }
    }
}

/// Why a brick or a partition could not be made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BrickError {
    /// The grid's header, the ambient index or a sample is invalid.
    Grid(GridError),
    /// A sample box is empty or reaches past the grid's dims (or its
    /// samples do not fill it).
    SampleBox {
        /// First sample (global indices).
        lo: [usize; 3],
        /// One past the last sample.
        hi: [usize; 3],
    },
    /// A brick count is zero or exceeds the samples along its axis, or no
    /// factorisation of the rank count fits the grid.
    Partition,
    /// A reach that is not finite and `≥ 0`.
    Reach,
}

impl fmt::Display for BrickError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Grid(e) => write!(f, "{e}"),
            Self::SampleBox { lo, hi } => {
                write!(f, "sample box {lo:?}..{hi:?} is empty or outside the grid")
            }
            Self::Partition => write!(f, "the bricks do not fit the grid's samples"),
            Self::Reach => write!(f, "a brick's reach must be finite and non-negative"),
        }
    }
}

impl core::error::Error for BrickError {}

impl From<GridError> for BrickError {
    fn from(e: GridError) -> Self {
        Self::Grid(e)
    }
}

/// A box of a gridded index field's samples (global indices `lo..hi`),
/// interpolated exactly as the whole grid's [`GridField`](crate::GridField)
/// is (see the module's invariant): one rank's brick, with its ghost
/// layers, of a field too large for one node.
///
/// Its [`IndexField::bounds`] are the WHOLE grid's (a trace needs them to
/// find its exit); its values are NaN wherever the stencil is not stored
/// (tell that apart with [`BrickField::covers`]).
#[derive(Clone, Debug, PartialEq)]
pub struct BrickField {
    info: GridInfo,
    lattice: Lattice,
    lo: [usize; 3],
    dims: [usize; 3],
    data: Vec<f32>,
    interp: Interp,
    ambient: f64,
}

impl BrickField {
    /// The brick of `info`'s grid whose samples `lo .. lo + dims` are
    /// `samples` (as the `io` feature's `read_grid_box` returns them; only
    /// its dims and data are used, its origin and spacing are ignored).
    ///
    /// # Errors
    /// [`BrickError::Grid`] for a bad header, an ambient index not finite
    /// and positive or a sample `≤ 0` ([`GridError::NonPositive`], its
    /// index in the box); [`BrickError::SampleBox`] for a box past the
    /// grid.
    pub fn new(
        info: GridInfo,
        lo: [usize; 3],
        samples: Grid,
        interp: Interp,
        ambient: f64,
    ) -> Result<Self, BrickError> {
        info.check()?;
        if !(ambient.is_finite() && ambient > 0.0) {
            return Err(GridError::BadGeometry.into());
        }
        let dims = samples.dims();
        let hi = [0, 1, 2].map(|a| lo[a].saturating_add(dims[a]));
        if (0..3).any(|a| hi[a] > info.dims[a] || lo[a] >= hi[a]) {
            return Err(BrickError::SampleBox { lo, hi });
        }
        let data = samples.into_data();
        if let Some(index) = data.iter().position(|&v| v <= 0.0) {
            return Err(GridError::NonPositive { index }.into());
        }
        Ok(Self { info, lattice: info.lattice(), lo, dims, data, interp, ambient })
    }

    /// The brick of samples `lo..hi` copied out of a whole grid (for tests
    /// and in-process ranks).
    ///
    /// # Errors
    /// As [`BrickField::new`].
    pub fn from_grid(
        grid: &Grid,
        lo: [usize; 3],
        hi: [usize; 3],
        interp: Interp,
        ambient: f64,
    ) -> Result<Self, BrickError> {
        let n = grid.dims();
        if (0..3).any(|a| lo[a] >= hi[a] || hi[a] > n[a]) {
            return Err(BrickError::SampleBox { lo, hi });
        }
        let mut data = Vec::with_capacity((hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]));
        for k in lo[2]..hi[2] {
            for j in lo[1]..hi[1] {
                let row = n[0] * (j + n[1] * k);
                data.extend_from_slice(&grid.data()[row + lo[0]..row + hi[0]]);
            }
        }
        let dims = [0, 1, 2].map(|a| hi[a] - lo[a]);
        let origin =
            grid.origin() + grid.spacing() * DVec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64);
        let samples = Grid::new(dims, origin, grid.spacing(), data)?;
        Self::new(grid.info(), lo, samples, interp, ambient)
    }

    /// Whether the stencil at `x` is stored, i.e. `eval(x)` is the whole
    /// grid's value (and not NaN).
    #[must_use]
    pub fn covers(&self, x: DVec3) -> bool {
        self.holds(&locate(&self.lattice, x))
    }

    fn holds(&self, at: &Located) -> bool {
        let (lo, hi) = footprint(self.info.dims, at.base, self.interp);
        (0..3).all(|a| self.lo[a] <= lo[a] && hi[a] < self.lo[a] + self.dims[a])
    }

    /// The stored sample box `(lo, hi)` (global indices, `hi` exclusive).
    #[must_use]
    pub fn sample_box(&self) -> ([usize; 3], [usize; 3]) {
        (self.lo, [0, 1, 2].map(|a| self.lo[a] + self.dims[a]))
    }

    /// How many samples the brick holds.
    #[must_use]
    pub fn stored_samples(&self) -> usize {
        self.data.len()
    }

    /// The whole grid's header.
    #[must_use]
    pub fn info(&self) -> GridInfo {
        self.info
    }

    /// The interpolant.
    #[must_use]
    pub fn interp(&self) -> Interp {
        self.interp
    }

    /// [`IndexBounds`] over the cells of the stored box; their
    /// [`IndexBounds::max`] over bricks that together store every sample
    /// and every pair of neighbours (as bricks with ghost layers do)
    /// holds for the whole grid.
    #[must_use]
    pub fn index_bounds(&self) -> IndexBounds {
        index_bounds(&self.samples(), self.info.spacing.recip(), self.interp)
    }

    fn samples(&self) -> Samples<'_> {
        Samples { data: &self.data, lo: self.lo, dims: self.dims }
    }
}

impl IndexField for BrickField {
    /// The whole grid's value where the stencil is stored; NaN elsewhere.
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        let at = locate(&self.lattice, x);
        if !self.holds(&at) {
            return (f64::NAN, DVec3::NAN);
        }
        interpolate(&self.samples(), &self.lattice, &at, self.interp)
    }
    /// The whole grid's bounds.
    fn bounds(&self) -> Bounds {
        self.info.bounds()
    }
    fn ambient(&self) -> f64 {
        self.ambient
    }
}
