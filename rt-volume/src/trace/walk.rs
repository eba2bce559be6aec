//! A trace from its entry into the bounds to its exit, leg by leg.

use glam::DVec3;

use super::eval::{Eval, State};
use super::run::{RunLimits, leapfrog_run};
use super::schemes::{adaptive_step, fixed_step, land};
use super::{Exit, Method, PathState, TraceError, TraceParams, TraceResult, TraceStats};
use crate::{Bounds, IndexField};

/// Traces a ray from `origin` along `direction` (any non-zero length)
/// through `field`: straight to the bounds, integrated inside them, and
/// stopped exactly on the bounds' surface where it leaves (or exactly at
/// the arc length [`TraceParams::max_length`] inside them).
///
/// # Errors
/// [`TraceError`] for a bad ray, bad parameters, or a field returning a
/// non-finite or non-positive index.
pub fn trace<F: IndexField>(
    field: &F,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
) -> Result<TraceResult, TraceError> {
    trace_impl(field, origin, direction, params, never_skip, |_| {})
}

/// [`trace`], calling `visit(x)` at the end of every step inside the
/// bounds (for sampling a second field along the bent path).
///
/// # Errors
/// As [`trace`].
pub fn trace_visiting<F: IndexField>(
    field: &F,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
    visit: impl FnMut(DVec3),
) -> Result<TraceResult, TraceError> {
    trace_impl(field, origin, direction, params, never_skip, visit)
}

/// The oracle of a trace without skipping: never asked after the entry.
fn never_skip(_: DVec3, _: DVec3) -> Offer {
    Offer::IntegrateFor(f64::INFINITY)
}

/// What a skip oracle answers before a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Offer {
    /// No straight move here: integrate the step.
    None,
    /// No straight move for at least this arc length ahead (what lies
    /// there along the straight line is too rough to skip, and stays so):
    /// integrate, and do not ask again until the ray has gone that far.
    /// Asking later than needed only integrates more; never a wrong skip.
    IntegrateFor(f64),
    /// Move straight.
    Skip(Skip),
}

/// A straight move offered by a skip oracle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Skip {
    /// Length along the current direction.
    pub len: f64,
    /// The deflection the straight move may miss.
    pub bound: f64,
    /// The index where it is known to be this constant along the whole
    /// move (no field evaluation needed at its ends).
    pub n: Option<f64>,
}

/// Step, tolerance and limits finite and positive.
pub(crate) fn check_params(params: &TraceParams) -> Result<(), TraceError> {
    let ok = |v: f64| v.is_finite() && v > 0.0;
    // `max_step` may be `+∞` (no cap) but must be positive: it caps every
    // method's step, and a negative one would trace the ray backwards.
    let cap = params.max_step > 0.0;
    if !(ok(params.step) && ok(params.tolerance) && ok(params.max_length) && cap)
        || params.max_steps == 0
    {
        return Err(TraceError::InvalidParams);
    }
    Ok(())
}

/// `v / |v|` for any finite non-zero `v`: where `|v|²` underflows or
/// overflows (a tiny or huge vector) it is scaled first, since a plain
/// `normalize` would give NaN. (`T = n·d̂` is tiny where `n` is.)
pub(super) fn unit(v: DVec3) -> DVec3 {
    let l2 = v.length_squared();
    if l2.is_normal() { v.normalize() } else { (v / v.abs().max_element()).normalize() }
}

/// `Adaptive` steps are at most the straight chord through the bounds
/// over this (see [`TraceParams::max_step`]).
const ADAPTIVE_STEPS_PER_CHORD: f64 = 24.0;

/// [`trace`] with a skip oracle: before each step, `skip(x, T)` may offer
/// a [`Skip`]: the ray then moves `len` straight along `d̂ = T/|T|` (`T`
/// keeps its direction, optical path by the trapezoid rule), and `bound`
/// is added to [`TraceStats::skip_bound`]; or [`Offer::IntegrateFor`], and
/// is not asked again until the ray has gone that far.
///
/// Every tracer is this: [`trace_begin`] and one leg that owns all space
/// (the code a distributed trace runs leg by leg).
pub(crate) fn trace_impl<F: IndexField>(
    field: &F,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
    skip: impl FnMut(DVec3, DVec3) -> Offer,
    visit: impl FnMut(DVec3),
) -> Result<TraceResult, TraceError> {
    match trace_begin(field.bounds(), field.ambient(), origin, direction, params)? {
        Begin::Missed(r) => Ok(r),
        Begin::Inside(state) => match leg(field, state, params, |_| true, skip, visit)? {
            Leg::Finished(r) => Ok(r),
            Leg::Left(_) => unreachable!("a leg that owns all space never hands the ray on"),
        },
    }
}

/// How a trace starts ([`trace_begin`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Begin {
    /// The ray never enters the bounds: this is its whole result.
    Missed(TraceResult),
    /// The ray at its entry point, for [`trace_leg`] on the rank owning it.
    Inside(PathState),
}

/// How a leg of a trace ends ([`trace_leg`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Leg {
    /// The trace is over: the same result [`trace`] gives.
    Finished(TraceResult),
    /// A step would start outside the space this leg owns: hand the state
    /// to the owner of [`PathState::position`].
    Left(PathState),
}

/// The first part of a distributed [`trace`]: checks the ray and the
/// parameters and moves straight through the ambient medium to where the
/// ray enters `bounds`, evaluating no field (any rank can do it knowing
/// only the whole field's `bounds` and `ambient` index). The entry
/// evaluation happens in the first [`trace_leg`], on the rank owning the
/// entry point.
///
/// # Errors
/// [`TraceError::InvalidRay`] and [`TraceError::InvalidParams`] as
/// [`trace`].
pub fn trace_begin(
    bounds: Bounds,
    ambient: f64,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
) -> Result<Begin, TraceError> {
    if !(origin.is_finite() && direction.is_finite()) || direction == DVec3::ZERO {
        return Err(TraceError::InvalidRay);
    }
    check_params(params)?;
    let d = unit(direction);
    let Some((t0, t1)) = bounds.clip(origin, d) else {
        return Ok(Begin::Missed(TraceResult::missed(origin, d)));
    };
    // Straight through the ambient medium to the entry point.
    let x0 = origin + t0 * d;
    // A NaN chord (bounds at infinity) caps nothing, as an infinite one.
    let chord = t1 - t0;
    Ok(Begin::Inside(PathState {
        y: State { x: x0, t: d, opl: ambient * t0, s: 0.0 },
        h: 0.0,
        max_step: 0.0,
        chord: if chord >= 0.0 { chord } else { f64::INFINITY },
        stats: TraceStats::default(),
        last: None,
        entered: false,
    }))
}

/// One leg of a distributed [`trace`]: integrates from `state` while the
/// position at the start of each step is owned (`owns(x)`); as soon as a
/// step would start outside, returns [`Leg::Left`] for the owner of that
/// point to continue. A step started inside is completed, landing on the
/// exit included, so its stage points and its end may lie up to one step
/// ([`crate::step_reach`]) beyond the owned space: the field must be
/// exact there.
///
/// `field` must be the whole field as far as the trace can tell: its
/// [`IndexField::bounds`] and ambient index those of the whole field
/// (exit detection and the continuation outside the box use them), its
/// values the whole field's wherever this leg evaluates it (a
/// [`BrickField`](crate::BrickField) is NaN elsewhere, which ends the
/// trace with [`TraceError::BadField`]). `params` must be those given to
/// [`trace_begin`], and `owns` the same partition of space on every rank
/// (each point owned by exactly one). Then the legs' final result is bit
/// for bit what [`trace`] returns on the whole field: both run this code.
///
/// # Errors
/// As [`trace`].
pub fn trace_leg<F: IndexField>(
    field: &F,
    state: PathState,
    params: &TraceParams,
    owns: impl Fn(DVec3) -> bool,
) -> Result<Leg, TraceError> {
    check_params(params)?;
    leg(field, state, params, owns, never_skip, |_| {})
}

/// [`trace_leg`] with a skip oracle and a visitor (see [`trace_impl`]).
pub(super) fn leg<F: IndexField>(
    field: &F,
    state: PathState,
    params: &TraceParams,
    owns: impl Fn(DVec3) -> bool,
    mut skip: impl FnMut(DVec3, DVec3) -> Offer,
    mut visit: impl FnMut(DVec3),
) -> Result<Leg, TraceError> {
    if !owns(state.y.x) {
        return Ok(Leg::Left(state));
    }
    let bounds = field.bounds();
    let ambient = field.ambient();
    let mut ev = Eval { field, bounds, ambient, evals: state.stats.field_evals, last: state.last };
    let mut stats = state.stats;
    let mut y = state.y;
    let mut first = None;
    let (max_step, mut h) = if state.entered {
        (state.max_step, state.h)
    } else {
        // The entry point; `y.t` holds the unit direction. The first skip
        // is asked before the first evaluation: a ray that only crosses
        // constant regions needs none.
        let d = y.t;
        let offer = skip(y.x, d);
        let n0 = match offer {
            Offer::Skip(Skip { n: Some(n), .. }) => n,
            _ => ev.n(y.x)?.0,
        };
        first = Some(offer);
        y.t = n0 * d;
        let max_step = match params.method {
            Method::Adaptive => {
                // `t` advances by `ds/n`: the chord over 24, in `t` at entry.
                let cap = state.chord / (ADAPTIVE_STEPS_PER_CHORD * n0);
                if cap > 0.0 && cap < params.max_step { cap } else { params.max_step }
            }
            _ => params.max_step,
        };
        (max_step, params.step.min(max_step))
    };
    // Arc length inside the bounds where the trace stops.
    let limit = params.max_length;
    // The index at `y.x` where a skip knew it without evaluating.
    let mut known_here = None;
    // The arc length before which the oracle is not asked again.
    let mut ask_from = f64::NEG_INFINITY;
    let exit = loop {
        if !owns(y.x) {
            // Hand the ray on before the step: the state is whole.
            if !(y.t.is_finite() && y.opl.is_finite()) {
                // Overflowed (see the end): no state to hand on.
                return Err(TraceError::BadField { at: y.x });
            }
            stats.field_evals = ev.evals;
            let chord = state.chord;
            let last = ev.last;
            return Ok(Leg::Left(PathState { y, h, max_step, chord, stats, last, entered: true }));
        }
        if stats.steps + stats.rejected >= params.max_steps {
            break Exit::MaxSteps;
        }
        let offer = match first.take() {
            Some(offer) => offer,
            None if y.s < ask_from => {
                if params.method == Method::Symplectic {
                    let lim = RunLimits {
                        h,
                        limit,
                        until_s: ask_from,
                        max_steps: params.max_steps,
                        owns: &owns,
                    };
                    if leapfrog_run(&mut ev, &mut y, &mut stats, &lim, &mut visit)? > 0 {
                        known_here = None;
                        continue;
                    }
                }
                Offer::None
            }
            None => skip(y.x, y.t),
        };
        if let Offer::IntegrateFor(len) = offer {
            ask_from = y.s + len;
        }
        if let Offer::Skip(Skip { len, bound, n: known }) = offer {
            let d = unit(y.t);
            // A skip that would leave the bounds stops on their surface;
            // one that would pass the arc-length limit stops there.
            let inside = bounds.contains(y.x + len * d);
            let len = if inside { len } else { bounds.clip(y.x, d).map_or(0.0, |(_, t1)| t1) };
            let room = limit - y.s;
            let (len, stop) = if room <= len {
                (room, Some(Exit::MaxLength))
            } else {
                (len, (!inside).then_some(Exit::Left))
            };
            let x = y.x + len * d;
            let x = if inside && stop.is_none() { x } else { x.clamp(bounds.min, bounds.max) };
            // Straight across a smooth region: T keeps its direction and
            // |T| = n where the ray lands; the optical path by the trapezoid
            // rule (n varies by less than the skip tolerance there). The
            // start value is the cached evaluation of the previous step.
            let (n_start, n_end) = match known {
                Some(n) => (n, n),
                None => (ev.n(y.x)?.0, ev.n(x)?.0),
            };
            y = State { x, t: n_end * d, opl: y.opl + 0.5 * (n_start + n_end) * len, s: y.s + len };
            stats.steps += 1;
            stats.skipped += 1;
            stats.skip_bound += bound;
            known_here = known;
            visit(y.x);
            if let Some(stop) = stop {
                break stop;
            }
            continue;
        }
        let (next, used, err) = match params.method {
            Method::Adaptive => adaptive_step(&mut ev, &y, &mut h, max_step, params, &mut stats)?,
            m => (fixed_step(m, &mut ev, &y, h)?, h, 0.0),
        };
        known_here = None;
        if bounds.contains(next.x) && next.s < limit {
            y = next;
            visit(y.x);
            stats.steps += 1;
            stats.error_estimate += err;
            let (n, _) = ev.n(y.x)?;
            stats.invariant_drift = stats.invariant_drift.max((y.t.length() - n).abs());
            stats.field_evals = ev.evals;
            continue;
        }
        // The step leaves the bounds or passes the arc-length limit: land
        // exactly on whichever comes first.
        let (landed, event) = land(params.method, &mut ev, &y, &next, used, limit, &mut stats)?;
        y = landed;
        break event;
    };
    let n = match known_here {
        Some(n) => n,
        None => ev.n(y.x)?.0,
    };
    stats.field_evals = ev.evals;
    stats.invariant_drift = stats.invariant_drift.max((y.t.length() - n).abs());
    // `T = 0` after a step (a state off the network with a subnormal `T`,
    // found by the `distributed` fuzz target) has no direction.
    let direction = unit(y.t);
    if !(y.x.is_finite() && y.t.is_finite() && y.opl.is_finite() && direction.is_finite()) {
        // n near f64's range (found by fuzzing with n ≈ 1e38): the optical
        // path or momentum overflowed.
        return Err(TraceError::BadField { at: y.x });
    }
    Ok(Leg::Finished(TraceResult { position: y.x, direction, optical_path: y.opl, exit, stats }))
}
