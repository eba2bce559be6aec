//! How far from its start a step may evaluate the field: the ghost layers
//! a brick of a distributed trace needs beyond the box it owns.

use crate::{Method, TraceError, TraceParams, trace::check_params};

/// `|T|` at a step start may exceed `n` by the invariant's drift
/// ([`crate::TraceStats::invariant_drift`], `O(hᵖ)`); allowed for: 25 %.
const T_OVER_N: f64 = 1.25;

/// The second-order coefficient `K` of each scheme's reach (see
/// [`step_reach`]).
fn k(m: Method) -> f64 {
    match m {
        Method::Euler => 0.0,
        Method::Rk4 | Method::Symplectic => 0.5,
        // max over the stages i of Σₖ |a_ik| Σⱼ |a_kj|: 16.487 (the
        // 5th-order result, the FSAL row); checked against `A` below.
        Method::Adaptive => 16.5,
    }
}

/// The farthest (world distance) from its start that one step of
/// `params` evaluates the field, for an index `n ≤ n_max` and
/// `|∇n| ≤ grad_max` everywhere (for a grid, see
/// [`Grid::index_bounds`](crate::Grid::index_bounds) and
/// [`BrickField::index_bounds`](crate::BrickField::index_bounds)):
/// `h·1.25·n_max + K·h²·n_max·grad_max`, `h` the largest step.
///
/// A distributed trace hands a ray on where a step starts outside the
/// rank's box ([`crate::trace_leg`]); the step it started inside runs to
/// its end, so a brick needs the samples within this reach of its box
/// ([`Bricks::samples_needed`](crate::Bricks::samples_needed)). If it is
/// too small the trace fails with [`TraceError::BadField`]; the answer is
/// never wrong.
///
/// Derivation. With `T = n dx/ds`, `|T| = n`, up to the invariant's
/// drift (25 % allowed). A stage of an explicit scheme sits at
/// `xᵢ = x₀ + h Σₖ aᵢₖ Tₖ`, `Tₖ = T₀ + h Σⱼ aₖⱼ Fⱼ` with `F = n∇n`; the
/// rows sum to the nodes `cᵢ ≤ 1`, so
/// `|xᵢ − x₀| ≤ h|T₀| + h²·max|F|·Σₖ |aᵢₖ| Σⱼ |aₖⱼ| = h|T₀| + K h² max|F|`:
/// - Euler, `x₀ + hT₀`: `K = 0`.
/// - RK4: its halves `x₀ + ½hT₀`, `x₀ + ½hT₁` and `x₀ + hT₂` (each `T`
///   half a step of `F` from `T₀`) and the end `x₀ + h(T₀ + 2T₁ + 2T₂ +
///   T₃)/6`: `K = ½`.
/// - Leapfrog's drift `x₀ + h(T₀ + ½hF₀)`: `K = ½`.
/// - Dormand–Prince: the rows' alternating coefficients (up to 11.6 in
///   magnitude) make `K = 16.49` (its 5th-order result).
///
/// Every step the tracer takes is at most `h`: the fixed methods' `min(step,
/// max_step)`; Adaptive's `max_step` (its trial, rejected and landing
/// steps too; the chord cap only lowers it), which must then be finite.
/// The last evaluation of a trace, at its exit point, lies on such a step.
///
/// # Errors
/// [`TraceError::InvalidParams`] for invalid `params`, an `Adaptive`
/// `max_step` that is infinite, or `n_max` not finite and positive or
/// `grad_max` not finite and `≥ 0`.
pub fn step_reach(params: &TraceParams, n_max: f64, grad_max: f64) -> Result<f64, TraceError> {
    check_params(params)?;
    let h = match params.method {
        Method::Adaptive => params.max_step,
        _ => params.step.min(params.max_step),
    };
    if !(h.is_finite() && n_max.is_finite() && n_max > 0.0 && grad_max.is_finite())
        || grad_max < 0.0
    {
        return Err(TraceError::InvalidParams);
    }
    let reach = h * T_OVER_N * n_max + k(params.method) * h * h * n_max * grad_max;
    if reach.is_finite() { Ok(reach) } else { Err(TraceError::InvalidParams) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::A;

    /// `K` for Dormand–Prince, recomputed from the tableau.
    #[test]
    fn dormand_prince_reach_coefficient_matches_the_tableau() {
        let row_sum = |r: &[f64; 6]| r.iter().map(|a| a.abs()).sum::<f64>();
        let mut worst = 0.0f64;
        for r in &A {
            let kk: f64 = r
                .iter()
                .enumerate()
                .map(|(j, a)| a.abs() * if j == 0 { 0.0 } else { row_sum(&A[j - 1]) })
                .sum();
            worst = worst.max(kk);
        }
        assert!((worst - 16.487).abs() < 1e-3, "{worst}");
        assert!(worst <= k(Method::Adaptive));
    }

    #[test]
    fn reach_needs_a_finite_step() {
        let p = TraceParams::accurate();
        assert_eq!(step_reach(&p, 1.0, 0.0), Err(TraceError::InvalidParams));
        let p = TraceParams { max_step: 0.1, ..p };
        assert_eq!(step_reach(&p, 1.0, 0.0), Ok(0.125));
        let q = TraceParams::fixed(Method::Rk4, 0.2);
        let r = step_reach(&q, 2.0, 1.0).unwrap();
        assert!((r - (0.2 * 1.25 * 2.0 + 0.5 * 0.04 * 2.0)).abs() < 1e-15, "{r}");
        for (n, g) in [(0.0, 1.0), (f64::NAN, 1.0), (1.0, -1.0), (1.0, f64::INFINITY)] {
            assert_eq!(step_reach(&q, n, g), Err(TraceError::InvalidParams));
        }
    }
}
