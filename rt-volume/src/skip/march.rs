//! Octree skipping: cross smooth regions of a gridded field in one
//! straight step each.

use glam::DVec3;

use super::{Octree, OctreeError};
use crate::{
    GridField, TraceError, TraceParams, TraceResult,
    trace::{Offer, Skip, trace_impl},
};

/// An octree over a gridded field's samples, bounding the field's own
/// interpolant (trilinear or Catmull–Rom; see [`Octree`]).
///
/// # Errors
/// [`OctreeError`] for grids with fewer than 2 samples per axis.
pub fn build_octree(field: &GridField) -> Result<Octree, OctreeError> {
    let g = field.grid();
    Octree::build_for(field.interp(), g.dims(), g.data(), g.spacing().to_array())
}

/// Traces like [`crate::trace`], but wherever the octree says the field is
/// smooth the ray crosses the whole node in one straight step. The
/// deflection a straight step can miss is at most `max|∇n| · length /
/// min n`; their sum over the ray, [`crate::TraceStats::skip_bound`], is
/// the ray's **budget**: a node is crossed straight only while
/// `spent + max|∇n| · diagonal / min n < tolerance`, `spent` the bound of
/// the ray's earlier skips. So `tolerance` bounds the deflection (radians)
/// that skipping can change along the whole ray, however many nodes it
/// crosses; once it is spent, the ray is integrated step by step.
///
/// # Errors
/// As [`crate::trace`]; also [`TraceError::InvalidParams`] for a
/// tolerance that is not finite and positive, or an octree built for
/// another interpolant than the field's (its bounds would not hold).
pub fn trace_skipping(
    field: &GridField,
    tree: &Octree,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
    tolerance: f64,
) -> Result<TraceResult, TraceError> {
    if !(tolerance.is_finite() && tolerance > 0.0) || field.interp() != tree.interp() {
        return Err(TraceError::InvalidParams);
    }
    let g = field.grid();
    let (o, h) = (g.origin(), g.spacing());
    let inv_h = h.recip();
    // The smallest index anywhere: `Σ max|∇n|·len / n_min` bounds the
    // deflection of a chain of straight moves.
    let n_min = f64::from(tree.root().min).max(1e-6);
    let tiny = 1e-9 * h.min_element();
    let cells = (DVec3::from(g.dims().map(|d| d as f64)) - 1.0).to_array();
    // The brick last found too rough to skip: a chain stops there without
    // asking the tree again (the budget only shrinks, so it stays rough).
    let mut rough: Option<[usize; 3]> = None;
    // The skip bound spent so far, in `max|∇n| · length` (times `n_min`,
    // radians).
    let budget = tolerance * n_min;
    let mut spent = 0.0;
    trace_impl(
        field,
        origin,
        direction,
        params,
        |x, d| {
            // Chain the smooth nodes the straight ray crosses, up to the
            // first rough brick or the cells' end: one move, no evaluation
            // between nodes. Positions in sample coordinates `p0 + t·ds`,
            // `t` the world length moved.
            let p0 = (x - o) * inv_h;
            let clamp = |p: DVec3| [0, 1, 2].map(|a| p[a].clamp(0.0, cells[a]));
            let ds = d.normalize() * inv_h;
            let inv = ds.recip();
            let (mut t, mut bound) = (0.0, 0.0);
            let mut hint = usize::MAX;
            // Whether every node so far holds the one constant `value`.
            let (mut uniform, mut value) = (true, None);
            // A straight line crosses each cell plane at most once: more
            // moves than that means no progress (bounded work whatever the
            // grid's geometry).
            let mut moves_left = cells.iter().sum::<f64>() as usize * 3 + 16;
            // The outer half cells repeat the edge samples (zero slope
            // across the faces), so the edge nodes' statistics cover them
            // too.
            while let Some(brick) = tree.brick_of(clamp(p0 + t * ds)) {
                if Some(brick) == rough {
                    break;
                }
                let Some(node) = tree.smooth_node_in(brick, budget - spent - bound, hint) else {
                    rough = Some(brick);
                    break;
                };
                // The far faces along d; the outermost nodes reach the
                // bounds (half a cell beyond the edge samples).
                hint = node.level;
                let (mut exit, mut leaves) = (f64::INFINITY, false);
                for a in 0..3 {
                    let face = if ds[a] > 0.0 {
                        if node.hi[a] >= cells[a] { cells[a] + 0.5 } else { node.hi[a] }
                    } else if ds[a] < 0.0 {
                        if node.lo[a] <= 0.0 { -0.5 } else { node.lo[a] }
                    } else {
                        continue;
                    };
                    let at = (face - p0[a]) * inv[a];
                    if at < exit {
                        exit = at;
                        leaves = face < 0.0 || face > cells[a];
                    }
                }
                if !exit.is_finite() || moves_left == 0 {
                    break;
                }
                moves_left -= 1;
                // Past the face by `tiny`, and by at least a few ulps of
                // `t`: where `t` is huge next to the spacing (found by the
                // `octree` fuzz target with a 3e38 spacing), `+ tiny` alone
                // was absorbed and the loop never moved.
                let next = (exit.max(t) + tiny).max(t + 4.0 * f64::EPSILON * t.abs());
                if next <= t {
                    break;
                }
                bound += f64::from(node.stats.grad_max) * (next - t);
                t = next;
                let (lo, hi) = (node.stats.min, node.stats.max);
                uniform &= lo == hi && value.is_none_or(|c| c == lo);
                value = Some(lo);
                if leaves {
                    break;
                }
            }
            if t == 0.0 {
                // Rough where the ray is: integrate across the run of
                // bricks too rough for the budget left that the straight
                // line crosses (the budget only shrinks, so they stay
                // rough), not asking at every step of a dense field.
                return match tree.rough_run(clamp(p0), ds.to_array(), budget - spent) {
                    0.0 => Offer::None,
                    run => Offer::IntegrateFor(run),
                };
            }
            spent += bound;
            Offer::Skip(Skip {
                len: t,
                bound: bound / n_min,
                n: value.filter(|_| uniform).map(f64::from),
            })
        },
        |_| {},
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Interp;

    /// Found by the `octree` fuzz target: with a cell spacing of 3.4e38
    /// along x, `t + tiny` was absorbed by rounding and the node walk
    /// never moved (a hang). It must finish, here within 10 s.
    #[test]
    fn fuzz_regression_huge_spacing_does_not_hang() {
        extern crate std;
        let mut data = alloc::vec![0.999f32; 72];
        for (i, v) in [(34, 1.096), (67, 1.1), (68, 1.0), (69, 1.054), (70, 1.0), (71, 1.0)] {
            data[i] = v;
        }
        let grid = crate::Grid::new(
            [2, 6, 6],
            DVec3::splat(0.1),
            DVec3::new(3.402_823_466_385_288_6e38, 3.875, 3.875),
            data,
        )
        .unwrap();
        let field = GridField::new(grid, Interp::Trilinear, 1.0).unwrap();
        let tree = build_octree(&field).unwrap();
        let params = TraceParams {
            method: crate::Method::Symplectic,
            step: 3.875,
            tolerance: 3.875,
            max_step: 3.875,
            max_steps: 2705,
            max_length: 0.01,
        };
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let o = DVec3::new(-1.401_298_464_324_817e-45, 0.625, 1.192_092_895_507_812_5e-7);
            let d = DVec3::new(3.875, 0.0, 1.192_092_895_507_812_5e-7);
            let r = trace_skipping(&field, &tree, o, d, &params, 3.1875);
            tx.send(r.map(|r| r.position.is_finite())).ok();
        });
        let r = rx.recv_timeout(core::time::Duration::from_secs(10)).expect("finished");
        assert!(r.unwrap_or(true), "a non-finite position");
    }
    use crate::{Grid, Method};

    #[test]
    fn uniform_field_is_one_straight_step() {
        let g =
            Grid::new([9, 9, 9], DVec3::ZERO, DVec3::splat(0.25), alloc::vec![1.2; 729]).unwrap();
        let f = GridField::new(g, Interp::Trilinear, 1.2).unwrap();
        let t = build_octree(&f).unwrap();
        let p = TraceParams::fixed(Method::Rk4, 0.01);
        let r = trace_skipping(&f, &t, DVec3::new(1.0, 1.0, -1.0), DVec3::Z, &p, 1e-6).unwrap();
        assert!(r.stats.skipped == 1 && r.stats.skip_bound == 0.0);
        // The nodes say the index is 1.2 throughout: nothing to evaluate.
        assert_eq!(r.stats.field_evals, 0);
        assert_eq!(r.exit, crate::Exit::Left);
        assert!((r.optical_path - 1.2 * (0.875 + 2.25)).abs() < 1e-6, "{}", r.optical_path);
        assert_eq!(r.direction, DVec3::Z);
        assert!(matches!(
            trace_skipping(&f, &t, DVec3::ZERO, DVec3::Z, &p, 0.0),
            Err(TraceError::InvalidParams)
        ));
    }
}
