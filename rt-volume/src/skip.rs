//! Octree skipping: cross smooth regions of a gridded field in one
//! straight step each.

use glam::DVec3;
use rt_accel::Octree;

use crate::{GridField, Interp, TraceError, TraceParams, TraceResult, trace::trace_impl};

/// An octree over a gridded field's samples (see [`rt_accel::Octree`]).
///
/// # Errors
/// [`rt_accel::OctreeError`] for grids with fewer than 2 samples per axis.
pub fn build_octree(field: &GridField) -> Result<Octree, rt_accel::OctreeError> {
    let g = field.grid();
    Octree::build(g.dims(), g.data(), g.spacing().to_array())
}

/// Traces like [`crate::trace`], but wherever the octree says the field is
/// smooth (`max|∇n| · node diagonal < tolerance`) the ray crosses the whole
/// node in one straight step. The deflection so skipped is bounded by
/// `Σ max|∇n| · length / min n` over the skipped steps, reported as
/// [`crate::TraceStats::skip_bound`]; `tolerance` is thus the deflection
/// (radians) allowed per skipped node.
///
/// # Errors
/// As [`crate::trace`]; also [`TraceError::InvalidParams`] for a
/// tolerance that is not finite and positive, or a field whose interpolant
/// is not trilinear (the octree's bounds are proven for trilinear only).
pub fn trace_skipping(
    field: &GridField,
    tree: &Octree,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
    tolerance: f64,
) -> Result<TraceResult, TraceError> {
    if !(tolerance.is_finite() && tolerance > 0.0) || field.interp() != Interp::Trilinear {
        return Err(TraceError::InvalidParams);
    }
    let g = field.grid();
    let (o, h) = (g.origin(), g.spacing());
    let tiny = 1e-9 * h.min_element();
    let cells = (DVec3::from(g.dims().map(|d| d as f64)) - 1.0).to_array();
    trace_impl(
        field,
        origin,
        direction,
        params,
        |x, d| {
            // The outer half cells repeat the edge samples (zero slope across
            // the faces), so the edge nodes' statistics cover them too.
            let p = ((x - o) / h).to_array();
            let q = [0, 1, 2].map(|a| p[a].clamp(0.0, cells[a]));
            let mut node = tree.smooth_node(q, tolerance)?;
            for ((lo, hi), c) in node.lo.iter_mut().zip(&mut node.hi).zip(cells) {
                if *lo <= 0.0 {
                    *lo = -0.5;
                }
                if *hi >= c {
                    *hi = c + 0.5;
                }
            }
            // Distance along d to the node's far faces (world units).
            let mut len = f64::INFINITY;
            for a in 0..3 {
                let face = if d[a] > 0.0 {
                    node.hi[a]
                } else if d[a] < 0.0 {
                    node.lo[a]
                } else {
                    continue;
                };
                len = len.min((o[a] + face * h[a] - x[a]) / d[a]);
            }
            let len = len.max(0.0) + tiny;
            let n_min = f64::from(node.stats.min).max(1e-6);
            Some((len, f64::from(node.stats.grad_max) * len / n_min))
        },
        |_| {},
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Grid, Method};

    #[test]
    fn uniform_field_is_one_straight_step() {
        let g =
            Grid::new([9, 9, 9], DVec3::ZERO, DVec3::splat(0.25), alloc::vec![1.2; 729]).unwrap();
        let f = GridField::new(g, Interp::Trilinear, 1.2).unwrap();
        let t = build_octree(&f).unwrap();
        let p = TraceParams::fixed(Method::Rk4, 0.01);
        let r = trace_skipping(&f, &t, DVec3::new(1.0, 1.0, -1.0), DVec3::Z, &p, 1e-6).unwrap();
        assert!(r.stats.skipped >= 1 && r.stats.skip_bound == 0.0);
        assert!(r.stats.field_evals < 20, "{}", r.stats.field_evals);
        assert_eq!(r.direction, DVec3::Z);
        assert!(matches!(
            trace_skipping(&f, &t, DVec3::ZERO, DVec3::Z, &p, 0.0),
            Err(TraceError::InvalidParams)
        ));
    }
}
