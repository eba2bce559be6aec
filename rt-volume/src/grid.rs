//! Gridded index fields: cell-centred `f32` samples on a structured grid.
//!
//! Sample `(i, j, k)` sits at the centre of its cell,
//! `origin + (i, j, k)·spacing` (the convention of the project's CFD data:
//! no half-voxel shift). The field's bounds are the outer cell faces; within
//! half a cell of them the interpolant uses the edge samples (constant
//! extrapolation), so its gradient across the faces there is zero. Outside
//! the bounds the index is the ambient one (the tracer never asks).

use alloc::vec::Vec;
use core::fmt;

use glam::DVec3;

use crate::{
    Bounds, IndexField,
    stencil::{Lattice, Samples, interpolate, locate},
};

/// The interpolant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Interp {
    /// Trilinear: C⁰, piecewise-constant-per-axis gradient (the interpolant's
    /// own derivative, so gradient and value stay consistent).
    Trilinear,
    /// Tricubic Catmull–Rom: C¹ (smooth gradient), interpolating, with the
    /// interpolant's analytic gradient.
    CatmullRom,
}

/// Why a grid could not be made.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GridError {
    /// A dimension is zero.
    ZeroDim,
    /// The sample count overflows or exceeds [`Grid::MAX_SAMPLES`].
    TooLarge,
    /// `data.len()` differs from `nx·ny·nz`.
    DataLength {
        /// `nx·ny·nz`.
        expected: usize,
        /// What was given.
        found: usize,
    },
    /// A sample is NaN or infinite.
    NonFinite {
        /// Its linear index (`i + nx·(j + ny·k)`).
        index: usize,
    },
    /// An index sample is not positive (only checked for index grids).
    NonPositive {
        /// Its linear index.
        index: usize,
    },
    /// Origin not finite, spacing not finite and positive, or ambient
    /// index not finite and positive.
    BadGeometry,
}

impl fmt::Display for GridError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ZeroDim => write!(f, "grid dimension is zero"),
            Self::TooLarge => write!(f, "grid has too many samples"),
            Self::DataLength { expected, found } => {
                write!(f, "grid needs {expected} samples, got {found}")
            }
            Self::NonFinite { index } => write!(f, "sample {index} is not finite"),
            Self::NonPositive { index } => write!(f, "index sample {index} is not positive"),
            Self::BadGeometry => write!(f, "grid origin/spacing/ambient not finite and positive"),
        }
    }
}

impl core::error::Error for GridError {}

/// A scalar field on a structured grid of `f32` samples (x fastest).
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    dims: [usize; 3],
    origin: DVec3,
    spacing: DVec3,
    data: Vec<f32>,
    /// `1 / spacing`, so sampling multiplies instead of dividing.
    inv_spacing: DVec3,
}

/// A grid's samples as a file holds them, before [`Grid::new`]'s checks:
/// NaN and infinite samples (blanked cells) kept, so a caller can count
/// them or fill them ([`GridSamples::into_grid_filling`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GridSamples {
    /// Samples per axis.
    pub dims: [usize; 3],
    /// Centre of sample `(0, 0, 0)`.
    pub origin: DVec3,
    /// Distance between samples.
    pub spacing: DVec3,
    /// The samples, x fastest.
    pub data: Vec<f32>,
}

impl GridSamples {
    /// How many samples are NaN or infinite.
    #[must_use]
    pub fn non_finite(&self) -> usize {
        self.data.iter().filter(|v| !v.is_finite()).count()
    }

    /// The grid, as [`Grid::new`] makes it.
    ///
    /// # Errors
    /// As [`Grid::new`] (a non-finite sample is [`GridError::NonFinite`]).
    pub fn into_grid(self) -> Result<Grid, GridError> {
        Grid::new(self.dims, self.origin, self.spacing, self.data)
    }

    /// The grid with every NaN or infinite sample replaced by `fill`
    /// (blanked cells as a uniform medium), and how many were.
    ///
    /// # Errors
    /// As [`Grid::new`], and [`GridError::NonFinite`] if `fill` is not
    /// finite.
    pub fn into_grid_filling(mut self, fill: f32) -> Result<(Grid, usize), GridError> {
        if !fill.is_finite() {
            return Err(GridError::NonFinite { index: usize::MAX });
        }
        let mut count = 0;
        for v in &mut self.data {
            if !v.is_finite() {
                *v = fill;
                count += 1;
            }
        }
        Ok((self.into_grid()?, count))
    }
}

impl Grid {
    /// The largest sample count accepted (2³¹, 8 GiB of `f32`).
    pub const MAX_SAMPLES: usize = 1 << 31;

    /// A grid of `dims` samples, sample `(0,0,0)` centred at `origin`, cell
    /// size `spacing`, `data` x fastest (`index = i + nx·(j + ny·k)`).
    ///
    /// # Errors
    /// [`GridError`] for zero or too large dimensions, a data length
    /// mismatch, a non-finite sample or bad geometry.
    pub fn new(
        dims: [usize; 3],
        origin: DVec3,
        spacing: DVec3,
        data: Vec<f32>,
    ) -> Result<Self, GridError> {
        if dims.contains(&0) {
            return Err(GridError::ZeroDim);
        }
        let n = dims[0]
            .checked_mul(dims[1])
            .and_then(|v| v.checked_mul(dims[2]))
            .filter(|&v| v <= Self::MAX_SAMPLES)
            .ok_or(GridError::TooLarge)?;
        if data.len() != n {
            return Err(GridError::DataLength { expected: n, found: data.len() });
        }
        if !(origin.is_finite() && spacing.is_finite() && spacing.cmpgt(DVec3::ZERO).all()) {
            return Err(GridError::BadGeometry);
        }
        if let Some(index) = data.iter().position(|v| !v.is_finite()) {
            return Err(GridError::NonFinite { index });
        }
        Ok(Self { dims, origin, spacing, data, inv_spacing: spacing.recip() })
    }

    /// Samples per axis.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Centre of sample `(0, 0, 0)`.
    #[must_use]
    pub fn origin(&self) -> DVec3 {
        self.origin
    }

    /// Cell size.
    #[must_use]
    pub fn spacing(&self) -> DVec3 {
        self.spacing
    }

    /// The samples, x fastest.
    #[must_use]
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The outer cell faces: `origin − h/2` to `origin + (dims − ½)·h`.
    #[must_use]
    pub fn bounds(&self) -> Bounds {
        self.info().bounds()
    }

    /// The whole grid as a box of stored samples.
    #[inline]
    pub(crate) fn samples(&self) -> Samples<'_> {
        Samples { data: &self.data, lo: [0; 3], dims: self.dims }
    }

    /// The grid as the interpolants see it.
    #[inline]
    pub(crate) fn lattice(&self) -> Lattice {
        Lattice { dims: self.dims, origin: self.origin, inv_spacing: self.inv_spacing }
    }

    /// The samples, x fastest, given up.
    #[must_use]
    pub fn into_data(self) -> Vec<f32> {
        self.data
    }

    /// Applies `f` to every sample (e.g. density → index).
    ///
    /// # Errors
    /// [`GridError::NonFinite`] if `f` produces a NaN or infinity.
    pub fn map(mut self, f: impl Fn(f32) -> f32) -> Result<Self, GridError> {
        for v in &mut self.data {
            *v = f(*v);
        }
        if let Some(index) = self.data.iter().position(|v| !v.is_finite()) {
            return Err(GridError::NonFinite { index });
        }
        Ok(self)
    }

    /// Value and gradient of the interpolant at `x`.
    #[must_use]
    pub fn sample(&self, x: DVec3, interp: Interp) -> (f64, DVec3) {
        let l = self.lattice();
        interpolate(&self.samples(), &l, &locate(&l, x), interp)
    }
}

/// A gridded refractive-index field.
#[derive(Clone, Debug, PartialEq)]
pub struct GridField {
    grid: Grid,
    interp: Interp,
    ambient: f64,
}

impl GridField {
    /// An index field from a grid of index samples.
    ///
    /// # Errors
    /// [`GridError::NonPositive`] for a sample `≤ 0`,
    /// [`GridError::BadGeometry`] for an ambient index not finite and
    /// positive.
    pub fn new(grid: Grid, interp: Interp, ambient: f64) -> Result<Self, GridError> {
        if !(ambient.is_finite() && ambient > 0.0) {
            return Err(GridError::BadGeometry);
        }
        if let Some(index) = grid.data.iter().position(|&v| v <= 0.0) {
            return Err(GridError::NonPositive { index });
        }
        Ok(Self { grid, interp, ambient })
    }

    /// The grid.
    #[must_use]
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The interpolant.
    #[must_use]
    pub fn interp(&self) -> Interp {
        self.interp
    }
}

impl crate::TraceParams {
    /// rt's default for a gridded field: Störmer–Verlet leapfrog at one
    /// cell (the smallest spacing). One field evaluation per step like the
    /// original tool's Euler scheme, but second order and symplectic; the
    /// steps are capped at a cell so no sample is stepped over.
    #[must_use]
    pub fn for_grid(field: &GridField) -> Self {
        let cell = field.grid.spacing.min_element();
        Self { max_step: cell, ..Self::fixed(crate::Method::Symplectic, cell) }
    }
}

impl IndexField for GridField {
    fn eval(&self, x: DVec3) -> (f64, DVec3) {
        self.grid.sample(x, self.interp)
    }
    fn bounds(&self) -> Bounds {
        self.grid.bounds()
    }
    fn ambient(&self) -> f64 {
        self.ambient
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linear_grid() -> Grid {
        // f = 1 + 0.1x + 0.2y − 0.3z sampled at cell centres.
        let (dims, h, o) = ([6, 5, 4], DVec3::new(0.5, 0.25, 1.0), DVec3::new(-1.0, 0.0, 2.0));
        let mut data = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let p = o + DVec3::new(i as f64, j as f64, k as f64) * h;
                    data.push((1.0 + 0.1 * p.x + 0.2 * p.y - 0.3 * p.z) as f32);
                }
            }
        }
        Grid::new(dims, o, h, data).unwrap()
    }

    #[test]
    fn interpolants_reproduce_linear_fields_with_exact_gradients() {
        let g = linear_grid();
        for interp in [Interp::Trilinear, Interp::CatmullRom] {
            for p in
                [DVec3::new(-0.6, 0.3, 2.2), DVec3::new(0.77, 0.81, 3.9), DVec3::new(1.3, 0.5, 4.5)]
            {
                let (v, grad) = g.sample(p, interp);
                let want = 1.0 + 0.1 * p.x + 0.2 * p.y - 0.3 * p.z;
                assert!((v - want).abs() < 1e-6, "{interp:?} {p}: {v} vs {want}");
                assert!((grad - DVec3::new(0.1, 0.2, -0.3)).length() < 1e-5, "{interp:?}: {grad}");
            }
        }
    }

    #[test]
    fn samples_are_cell_centred_and_bounds_are_cell_faces() {
        let g = linear_grid();
        let (v, _) = g.sample(g.origin(), Interp::Trilinear);
        assert!((f64::from(g.data()[0]) - v).abs() < 1e-7, "no half-voxel shift");
        let b = g.bounds();
        assert_eq!(b.min, DVec3::new(-1.25, -0.125, 1.5));
        assert_eq!(b.max, DVec3::new(1.75, 1.125, 5.5));
        // In the outer half cell: edge value, no slope across the face.
        let (_, grad) = g.sample(DVec3::new(-1.2, 0.5, 3.0), Interp::Trilinear);
        assert_eq!(grad.x, 0.0);
    }

    #[test]
    fn catmull_rom_gradient_matches_finite_differences() {
        let mut data = Vec::new();
        for i in 0..512 {
            data.push(((i as f32) * 0.37).sin());
        }
        let g = Grid::new([8, 8, 8], DVec3::ZERO, DVec3::splat(0.1), data).unwrap();
        let p = DVec3::new(0.33, 0.41, 0.27);
        let (_, grad) = g.sample(p, Interp::CatmullRom);
        let e = 1e-6;
        for a in 0..3 {
            let mut d = DVec3::ZERO;
            d[a] = e;
            let fd = (g.sample(p + d, Interp::CatmullRom).0
                - g.sample(p - d, Interp::CatmullRom).0)
                / (2.0 * e);
            assert!(
                (fd - grad[a]).abs() < 1e-5 * (1.0 + fd.abs()),
                "axis {a}: {fd} vs {}",
                grad[a]
            );
        }
    }

    /// The separable evaluation (fast path inside, ghost samples next to
    /// the faces) equals the plain 4³ sum of weights times samples, and
    /// its gradient the central difference of its value, everywhere.
    #[test]
    #[allow(clippy::needless_range_loop, reason = "the reference sum reads as the formula")]
    fn catmull_rom_equals_the_plain_stencil_sum_everywhere() {
        let data: Vec<f32> = (0..7 * 6 * 5).map(|i| ((i as f32) * 0.61).sin() + 2.0).collect();
        let g = Grid::new([7, 6, 5], DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.1, 0.2, 0.15), data)
            .unwrap();
        let w = |t: f64| {
            let (t2, t3) = (t * t, t * t * t);
            [
                0.5 * (-t3 + 2.0 * t2 - t),
                0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
                0.5 * (-3.0 * t3 + 4.0 * t2 + t),
                0.5 * (t3 - t2),
            ]
        };
        for n in 0..400 {
            let t = f64::from(n);
            // Sample coordinates over the whole grid, faces included.
            let u = DVec3::new(
                (0.37 * t).fract() * 6.0,
                (0.71 * t).fract() * 5.0,
                (0.13 * t + 0.05).fract() * 4.0,
            );
            let x = g.origin + u * g.spacing;
            let (v, grad) = g.sample(x, Interp::CatmullRom);
            let b = u.to_array().map(|c| (c.floor() as isize).min(5));
            let b = [b[0].min(5), b[1].min(4), b[2].min(3)];
            let f = [0, 1, 2].map(|a| u[a] - b[a] as f64);
            let (wx, wy, wz) = (w(f[0]), w(f[1]), w(f[2]));
            let mut want = 0.0;
            for k in 0..4 {
                for j in 0..4 {
                    for i in 0..4 {
                        let idx =
                            [b[0] + i as isize - 1, b[1] + j as isize - 1, b[2] + k as isize - 1];
                        want += wx[i] * wy[j] * wz[k] * g.samples().at(g.dims, idx);
                    }
                }
            }
            assert!((v - want).abs() < 1e-12, "{u}: {v} vs {want}");
            let e = 1e-7;
            for a in 0..3 {
                let mut d = DVec3::ZERO;
                d[a] = e;
                // Within half a cell of a face the slope is flat by design.
                let du = e / g.spacing[a];
                let hi = (g.dims[a] - 1) as f64;
                if u[a] - du < 0.0 || u[a] + du > hi {
                    continue;
                }
                let fd = (g.sample(x + d, Interp::CatmullRom).0
                    - g.sample(x - d, Interp::CatmullRom).0)
                    / (2.0 * e);
                assert!(
                    (fd - grad[a]).abs() < 1e-4 * (1.0 + fd.abs()),
                    "{u} axis {a}: {fd} vs {}",
                    grad[a]
                );
            }
        }
    }

    #[test]
    fn bad_grids_are_errors() {
        let o = DVec3::ZERO;
        let h = DVec3::ONE;
        assert_eq!(Grid::new([0, 1, 1], o, h, alloc::vec![]), Err(GridError::ZeroDim));
        assert_eq!(Grid::new([usize::MAX, 2, 2], o, h, alloc::vec![]), Err(GridError::TooLarge));
        assert_eq!(
            Grid::new([2, 2, 2], o, h, alloc::vec![1.0; 7]),
            Err(GridError::DataLength { expected: 8, found: 7 })
        );
        let mut d = alloc::vec![1.0; 8];
        d[5] = f32::NAN;
        assert_eq!(Grid::new([2, 2, 2], o, h, d), Err(GridError::NonFinite { index: 5 }));
        assert_eq!(Grid::new([2, 2, 2], o, -h, alloc::vec![1.0; 8]), Err(GridError::BadGeometry));
        let g = Grid::new([2, 2, 2], o, h, alloc::vec![1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0])
            .unwrap();
        assert_eq!(
            GridField::new(g, Interp::Trilinear, 1.0),
            Err(GridError::NonPositive { index: 2 })
        );
    }
}
