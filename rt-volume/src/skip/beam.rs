//! Beam masks: which rays of a collimated beam cross nothing but smooth
//! octree nodes, and so go straight through a gridded field.

use alloc::vec::Vec;

use glam::DVec3;

use super::{BRICK, Octree, trace_skipping};
use crate::{
    Bounds, Exit, GridField, IndexField, TraceError, TraceParams, TraceResult, TraceStats,
    trace::check_params,
};

/// A collimated beam's cross-section, divided into cells (e.g. one per
/// film pixel): rays start at `center + a·u + b·v` (`v = direction × u`,
/// `|a| ≤ size[0]/2`, `|b| ≤ size[1]/2`) and run along `direction`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamWindow {
    /// Centre of the cross-section.
    pub center: DVec3,
    /// Beam direction (any length).
    pub direction: DVec3,
    /// First cross-section axis (made orthogonal to `direction`).
    pub u: DVec3,
    /// Extent along `u` and `v`.
    pub size: [f64; 2],
    /// Cells along `u` and `v`.
    pub cells: [usize; 2],
}

/// Most cells a [`BeamMask`] may have.
pub const MAX_BEAM_CELLS: usize = 1 << 26;

/// For each cell of a [`BeamWindow`], whether every line of the beam
/// through it is one that [`trace_skipping`] crosses straight from entry
/// to exit within its per-ray budget, and a bound on `|∇n|` along it.
/// [`trace_beam`] answers such a ray without walking the octree: the
/// answer a skip chain would give.
///
/// Built from the shadows of the octree's partition ([`Octree::partition`])
/// cast along the beam: each node's box (dilated by 1e-6 of a cell) is
/// projected on the cross-section and the cells its bounding rectangle
/// touches inherit its gradient bound, or become rough. A cell is clear
/// when no rough brick's shadow touches it and its bound `G` keeps the
/// whole chain within budget: `G · (L + b) < tolerance · min n`, `L` the
/// field's bounding-box diagonal (the longest straight path through it)
/// and `b` a brick's diagonal (the skip chain takes nodes down to a brick
/// while `spent + max|∇n| · diagonal` stays below the budget, and `spent ≤
/// G · L`). Conservative: a clear line never needs an integration step.
#[derive(Clone, Debug, PartialEq)]
pub struct BeamMask {
    center: DVec3,
    direction: DVec3,
    u: DVec3,
    v: DVec3,
    size: [f64; 2],
    cells: [usize; 2],
    /// Per cell (u fastest): the largest `max|∇n|` of the smooth nodes
    /// whose shadow touches it; `+∞` where a rough brick's does.
    grad: Vec<f32>,
    tolerance: f64,
    /// The largest `G` of a clear cell (exclusive).
    grad_limit: f64,
    /// The field the mask was built for.
    bounds: Bounds,
    n_min: f64,
}

impl BeamMask {
    /// The mask of `window` over `field` and its octree `tree` (from
    /// [`crate::build_octree`]) at the skip `tolerance` of
    /// [`trace_skipping`].
    ///
    /// # Errors
    /// [`TraceError::InvalidParams`] for a tolerance that is not finite and
    /// positive, an octree built for another interpolant than the field's,
    /// a degenerate window
    /// (direction or `u` zero, parallel or not finite; size not finite and
    /// positive; no cells or more than [`MAX_BEAM_CELLS`]).
    pub fn build(
        field: &GridField,
        tree: &Octree,
        window: &BeamWindow,
        tolerance: f64,
    ) -> Result<Self, TraceError> {
        let bad = Err(TraceError::InvalidParams);
        let BeamWindow { center, direction, u, size, cells } = *window;
        if !(tolerance.is_finite() && tolerance > 0.0) || field.interp() != tree.interp() {
            return bad;
        }
        let finite = center.is_finite() && direction.is_finite() && u.is_finite();
        if !(finite && size.iter().all(|s| s.is_finite() && *s > 0.0))
            || cells.contains(&0)
            || cells[0].checked_mul(cells[1]).is_none_or(|c| c > MAX_BEAM_CELLS)
        {
            return bad;
        }
        let Some(d) = direction.try_normalize() else { return bad };
        let Some(u) = (u - d * d.dot(u)).try_normalize() else { return bad };
        let v = d.cross(u);
        let g = field.grid();
        let (origin, h) = (g.origin(), g.spacing());
        let last = g.dims().map(|n| (n - 1) as f64);
        let mut mask = Self {
            center,
            direction: d,
            u,
            v,
            size,
            cells,
            grad: alloc::vec![0.0; cells[0] * cells[1]],
            tolerance,
            grad_limit: 0.0,
            bounds: field.bounds(),
            n_min: f64::from(tree.root().min).max(1e-6),
        };
        let budget = tolerance * mask.n_min;
        let chord = (mask.bounds.max - mask.bounds.min).length();
        let brick = (h * BRICK as f64).length();
        mask.grad_limit = budget / (chord + brick);
        let scale = [cells[0] as f64 / size[0], cells[1] as f64 / size[1]];
        tree.partition(budget, |node, smooth| {
            let grad = if smooth { node.stats.grad_max } else { f32::INFINITY };
            if grad == 0.0 {
                return;
            }
            // The node's box in world space: the outermost nodes reach the
            // bounds, half a cell beyond the edge samples.
            let pad = 1e-6;
            let lo = DVec3::from_array(
                [0, 1, 2].map(|a| if node.lo[a] <= 0.0 { -0.5 } else { node.lo[a] } - pad),
            );
            let hi = DVec3::from_array(
                [0, 1, 2]
                    .map(|a| if node.hi[a] >= last[a] { last[a] + 0.5 } else { node.hi[a] } + pad),
            );
            let (lo, hi) = (origin + lo * h, origin + hi * h);
            let (mut amin, mut amax) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for c in 0..8 {
                let p = DVec3::new(
                    if c & 1 == 0 { lo.x } else { hi.x },
                    if c & 2 == 0 { lo.y } else { hi.y },
                    if c & 4 == 0 { lo.z } else { hi.z },
                ) - center;
                for (k, axis) in [u, v].into_iter().enumerate() {
                    let s = (p.dot(axis) + 0.5 * size[k]) * scale[k];
                    amin[k] = amin[k].min(s);
                    amax[k] = amax[k].max(s);
                }
            }
            // The cells the shadow's bounding rectangle touches.
            let range = |k: usize| {
                // Truncation is floor here: both ends are ≥ 0 when cast.
                (amax[k] >= 0.0 && amin[k] < cells[k] as f64)
                    .then(|| (amin[k].max(0.0) as usize, (amax[k] as usize).min(cells[k] - 1)))
            };
            let (Some((i0, i1)), Some((j0, j1))) = (range(0), range(1)) else { return };
            for j in j0..=j1 {
                for cell in &mut mask.grad[j * cells[0] + i0..=j * cells[0] + i1] {
                    *cell = cell.max(grad);
                }
            }
        });
        Ok(mask)
    }

    /// The skip tolerance the mask was built for.
    #[must_use]
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// Whether the line through `p` along the beam is clear: `Some(bound on
    /// |∇n| along it)`, or `None` where it may meet a rough brick or would
    /// spend more than the budget (or `p` lies outside the window).
    #[must_use]
    pub fn clear_at(&self, p: DVec3) -> Option<f64> {
        let r = p - self.center;
        let cell = |k: usize, axis: DVec3| {
            let s = (r.dot(axis) / self.size[k] + 0.5) * self.cells[k] as f64;
            (s >= 0.0 && s < self.cells[k] as f64).then_some(s as usize)
        };
        let g = f64::from(self.grad[cell(1, self.v)? * self.cells[0] + cell(0, self.u)?]);
        (g < self.grad_limit).then_some(g)
    }

    /// The fraction of cells that are clear.
    #[must_use]
    pub fn clear_fraction(&self) -> f64 {
        let clear = self.grad.iter().filter(|&&g| f64::from(g) < self.grad_limit).count();
        clear as f64 / self.grad.len() as f64
    }
}

/// [`trace_skipping`] at the mask's tolerance, answering a ray of the
/// mask's beam whose line is clear ([`BeamMask::clear_at`]) at once: it
/// goes straight from entry to exit, two field evaluations for the optical
/// path (trapezoid rule, as a skip), [`TraceStats::skip_bound`] from the
/// cell's gradient bound. Other rays, and rays in other directions, are
/// traced by [`trace_skipping`]. `mask` must be built from `field` and
/// `tree`.
///
/// # Errors
/// As [`trace_skipping`]; also [`TraceError::InvalidParams`] for a mask
/// built for a field with other bounds.
pub fn trace_beam(
    field: &GridField,
    tree: &Octree,
    mask: &BeamMask,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
) -> Result<TraceResult, TraceError> {
    let bounds = field.bounds();
    if mask.bounds != bounds {
        return Err(TraceError::InvalidParams);
    }
    let along = origin.is_finite() && direction.try_normalize() == Some(mask.direction);
    let Some(grad) = along.then(|| mask.clear_at(origin)).flatten() else {
        return trace_skipping(field, tree, origin, direction, params, mask.tolerance);
    };
    check_params(params)?;
    let d = mask.direction;
    let Some((t0, t1)) = bounds.clip(origin, d) else {
        return Ok(TraceResult::missed(origin, d));
    };
    let x0 = origin + t0 * d;
    let x1 = (origin + t1 * d).clamp(bounds.min, bounds.max);
    let n = |x: DVec3| {
        let (n, g) = field.eval(x);
        if n.is_finite() && n > 0.0 && g.is_finite() {
            Ok(n)
        } else {
            Err(TraceError::BadField { at: x })
        }
    };
    let (n0, n1) = (n(x0)?, n(x1)?);
    let len = t1 - t0;
    let stats = TraceStats {
        steps: 1,
        skipped: 1,
        field_evals: 2,
        skip_bound: grad * len / mask.n_min,
        ..TraceStats::default()
    };
    Ok(TraceResult {
        position: x1,
        direction: d,
        optical_path: field.ambient() * t0 + 0.5 * (n0 + n1) * len,
        exit: Exit::Left,
        stats,
    })
}
