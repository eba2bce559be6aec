//! Integrating the ray equation `d/ds (n dx/ds) = ∇n`.
//!
//! With the parameter `dt = ds/n` and `T = n dx/ds` the equation becomes
//! the first-order system `dx/dt = T`, `dT/dt = n∇n = ½∇(n²)`, with the
//! invariant `|T| = n`; the optical path obeys `d(OPL)/dt = n²`. The system
//! is Hamiltonian (`H = ½|T|² − ½n²(x)`, separable), which the symplectic
//! leapfrog scheme exploits. Step sizes are in `t`, which equals arc length
//! where `n = 1`; the arc length itself is integrated along (`ds/dt = n`).
//!
//! A trace ends on an event: the ray leaves the bounds, or its arc length
//! inside them reaches [`TraceParams::max_length`]. The step that would
//! pass the event is replaced by one of the same scheme shortened to land
//! on it (regula falsi on the step length), so every scheme keeps its
//! order up to the exit. Stage points of that step (and of any step near a
//! face) may fall just outside the box; they see the field's first-order
//! continuation from the nearest point of the box, never the ambient index
//! the ray meets only after leaving (see `Eval::n`).

mod path_state;

use core::fmt;

use glam::DVec3;
pub use path_state::PathState;

use crate::{Bounds, IndexField, math::powf};

/// The integration scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Method {
    /// Explicit Euler, first order: the original tool's scheme, kept as the
    /// baseline. One field evaluation per step.
    Euler,
    /// Classic fourth-order Runge–Kutta; four evaluations per step.
    Rk4,
    /// Dormand–Prince 5(4) with error control (local error per step ≤
    /// `tolerance`, absolute in position and `T`); seven evaluations per
    /// attempt. Steps are also capped at 1/24 of the ray's straight chord
    /// through the bounds (see [`TraceParams::max_step`]).
    Adaptive,
    /// Störmer–Verlet leapfrog (kick–drift–kick), second order, symplectic:
    /// `|T|² − n²` stays bounded on long paths. One evaluation per step.
    Symplectic,
}

impl Method {
    /// Every method.
    pub const ALL: [Self; 4] = [Self::Euler, Self::Rk4, Self::Adaptive, Self::Symplectic];

    /// Lower-case name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Euler => "euler",
            Self::Rk4 => "rk4",
            Self::Adaptive => "adaptive",
            Self::Symplectic => "symplectic",
        }
    }
}

/// Integration settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceParams {
    /// The scheme.
    pub method: Method,
    /// Step in `t` (fixed-step methods; the first trial step for `Adaptive`).
    pub step: f64,
    /// Local error bound per step (`Adaptive` only).
    pub tolerance: f64,
    /// Largest step (in `t`) any method may take. Keep it below the
    /// field's smallest feature (a grid spacing, a layer's width): a step
    /// whose stages all fall outside a thin layer cannot see it.
    ///
    /// `Adaptive` steps are further capped at 1/24 of the straight chord
    /// through the bounds along the ray's entry direction (in `t`: divided
    /// by the index at entry), so every ray is resolved by at least ~24
    /// steps. An embedded error estimate is only valid for steps that
    /// resolve the field; in a weak field every estimate is tiny, and
    /// without the cap the steps grew (×5 a step) until one spanned a whole
    /// feature, where the estimate no longer measures the error: a Gaussian
    /// bump of index excess 1e-8 deflected 1e-3 off (up to 0.3 in its
    /// tails) under estimates below 1e-10. With the cap, the deflection is
    /// within 2e-7 relative at any excess from 1e-8 to 1e-2 (rays within
    /// 3σ of the centre, bounds 6σ to 16σ wide), at the cost of ≥ 24 steps
    /// a ray.
    pub max_step: f64,
    /// Most steps (accepted + rejected) before giving up.
    pub max_steps: u32,
    /// Longest arc length `∫ ds` inside the bounds, measured from where the
    /// ray enters them (its origin, if that is inside). The trace stops
    /// exactly there, to round-off (the last step is shortened to land on
    /// it, as on an exit face), with [`Exit::MaxLength`].
    pub max_length: f64,
}

impl TraceParams {
    /// Adaptive Dormand–Prince with a tight tolerance (1e-10).
    #[must_use]
    pub const fn accurate() -> Self {
        Self {
            method: Method::Adaptive,
            step: 1e-2,
            tolerance: 1e-10,
            max_step: f64::INFINITY,
            max_steps: 1_000_000,
            max_length: 1e6,
        }
    }

    /// A fixed-step method with step `step`.
    #[must_use]
    pub const fn fixed(method: Method, step: f64) -> Self {
        Self {
            method,
            step,
            tolerance: 1e-10,
            max_step: f64::INFINITY,
            max_steps: 10_000_000,
            max_length: 1e6,
        }
    }
}

/// Work done and error measured while tracing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TraceStats {
    /// Steps taken (accepted), including the final partial step(s) that
    /// land on the boundary.
    pub steps: u32,
    /// Field evaluations (calls to [`IndexField::eval`]).
    pub field_evals: u32,
    /// Rejected adaptive steps.
    pub rejected: u32,
    /// Sum of the embedded local error estimates (`Adaptive`; 0 otherwise).
    pub error_estimate: f64,
    /// Largest `| |T| − n |` seen at step ends (the invariant's drift).
    pub invariant_drift: f64,
    /// Straight steps across smooth octree nodes (skipping tracers only).
    pub skipped: u32,
    /// Sum over those steps of the deflection each may have missed
    /// (`max|∇n| · length / min n` of its node).
    pub skip_bound: f64,
}

/// How a trace ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exit {
    /// The ray never entered the bounds: it went straight.
    Missed,
    /// The ray left the bounds; position is on their surface.
    Left,
    /// `max_steps` ran out (position is where it stopped).
    MaxSteps,
    /// The arc length inside the bounds reached `max_length`; position
    /// is the point at exactly that arc length.
    MaxLength,
}

/// The result of tracing one ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TraceResult {
    /// Where the ray left the bounds (or stopped; the origin if it missed).
    pub position: DVec3,
    /// Unit direction there.
    pub direction: DVec3,
    /// Optical path `∫ n ds` from the origin to `position`.
    pub optical_path: f64,
    /// How it ended.
    pub exit: Exit,
    /// Work and error.
    pub stats: TraceStats,
}

impl TraceResult {
    /// A ray that never entered the bounds: straight, nothing done.
    pub(crate) fn missed(origin: DVec3, direction: DVec3) -> Self {
        Self {
            position: origin,
            direction,
            optical_path: 0.0,
            exit: Exit::Missed,
            stats: TraceStats::default(),
        }
    }
}

/// Why a ray could not be traced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TraceError {
    /// Origin or direction not finite, or a zero direction.
    InvalidRay,
    /// Step, tolerance or limits not finite and positive.
    InvalidParams,
    /// The field returned a NaN/∞ index or gradient (or `n ≤ 0`) at a point,
    /// or its values are so large that the path overflowed there.
    BadField {
        /// Where.
        at: DVec3,
    },
    /// Words that no [`PathState`] writes ([`PathState::from_words`]).
    InvalidState,
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidRay => write!(f, "ray origin/direction not finite or zero"),
            Self::InvalidParams => write!(f, "trace parameters must be finite and positive"),
            Self::BadField { at } => write!(f, "field is not finite and positive at {at}"),
            Self::InvalidState => write!(f, "not the words of a ray's path state"),
        }
    }
}

impl core::error::Error for TraceError {}

/// The integrated state: position, `T = n dx/ds`, optical path, arc
/// length since entering the bounds.
#[derive(Clone, Copy, Debug, PartialEq)]
struct State {
    x: DVec3,
    t: DVec3,
    opl: f64,
    s: f64,
}

impl State {
    fn axpy(self, h: f64, d: &State) -> State {
        State {
            x: self.x + h * d.x,
            t: self.t + h * d.t,
            opl: self.opl + h * d.opl,
            s: self.s + h * d.s,
        }
    }
}

/// Field access that never evaluates outside the bounds and counts calls.
struct Eval<'a, F: IndexField> {
    field: &'a F,
    bounds: crate::Bounds,
    ambient: f64,
    evals: u32,
    /// The last evaluation: steps that end where the next begins (FSAL,
    /// leapfrog) reuse it instead of calling the field again.
    last: Option<(DVec3, f64, DVec3)>,
}

impl<F: IndexField> Eval<'_, F> {
    /// `(n, ∇n)` at `x`: inside the bounds, the field's own values.
    ///
    /// Outside them, at stage points of a step that crosses a face (the
    /// trace never integrates beyond one), the field's first-order
    /// continuation from the nearest point `c` of the box:
    /// `(n(c) + ∇n(c)·(x − c), ∇n(c))`, exact for linear fields and off by
    /// `O(|x − c|²)` for smooth ones. The ambient index there (what the ray
    /// meets after leaving) put a jump inside the last step, and every
    /// scheme lost its order at a slanted exit through a face where
    /// `∇n ≠ 0` (RK4's exit direction erred at first order in the step).
    /// Where the continuation is no valid index (far outside, after a huge
    /// trial step), the nearest point's own values are used.
    fn n(&mut self, x: DVec3) -> Result<(f64, DVec3), TraceError> {
        if self.bounds.contains(x) {
            return self.n_inside(x);
        }
        if x.is_nan() {
            // An overflowed state: the caller reports it.
            return Ok((self.ambient, DVec3::ZERO));
        }
        let c = nearest_in(&self.bounds, x);
        let (n, g) = self.n_inside(c)?;
        let continued = n + g.dot(x - c);
        Ok((if continued.is_finite() && continued > 0.0 { continued } else { n }, g))
    }

    /// `(n, ∇n)` from the field at a point of the bounds.
    fn n_inside(&mut self, x: DVec3) -> Result<(f64, DVec3), TraceError> {
        if let Some((lx, n, g)) = self.last
            && lx == x
        {
            return Ok((n, g));
        }
        self.evals += 1;
        let (n, g) = self.field.eval(x);
        if !(n.is_finite() && n > 0.0 && g.is_finite()) {
            return Err(TraceError::BadField { at: x });
        }
        self.last = Some((x, n, g));
        Ok((n, g))
    }

    /// `dy/dt = (T, n∇n, n², n)`.
    fn deriv(&mut self, y: &State) -> Result<State, TraceError> {
        let (n, g) = self.n(y.x)?;
        Ok(State { x: y.t, t: n * g, opl: n * n, s: n })
    }
}

/// The point of `b` nearest to `x` (explicit comparisons: nothing relies on
/// how `min`/`max` treat NaN).
fn nearest_in(b: &crate::Bounds, x: DVec3) -> DVec3 {
    let c = |a: usize| {
        if x[a] < b.min[a] {
            b.min[a]
        } else if x[a] > b.max[a] {
            b.max[a]
        } else {
            x[a]
        }
    };
    DVec3::new(c(0), c(1), c(2))
}

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
    trace_impl(field, origin, direction, params, |_, _| None, |_| {})
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
    trace_impl(field, origin, direction, params, |_, _| None, visit)
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
fn unit(v: DVec3) -> DVec3 {
    let l2 = v.length_squared();
    if l2.is_normal() { v.normalize() } else { (v / v.abs().max_element()).normalize() }
}

/// `Adaptive` steps are at most the straight chord through the bounds
/// over this (see [`TraceParams::max_step`]).
const ADAPTIVE_STEPS_PER_CHORD: f64 = 24.0;

/// [`trace`] with a skip oracle: before each step, `skip(x, T)` may return
/// a [`Skip`]: the ray then moves `len` straight along `d̂ = T/|T|` (`T`
/// keeps its direction, optical path by the trapezoid rule), and `bound`
/// is added to [`TraceStats::skip_bound`].
///
/// Every tracer is this: [`trace_begin`] and one leg that owns all space
/// (the code a distributed trace runs leg by leg).
pub(crate) fn trace_impl<F: IndexField>(
    field: &F,
    origin: DVec3,
    direction: DVec3,
    params: &TraceParams,
    skip: impl FnMut(DVec3, DVec3) -> Option<Skip>,
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
    leg(field, state, params, owns, |_, _| None, |_| {})
}

/// [`trace_leg`] with a skip oracle and a visitor (see [`trace_impl`]).
fn leg<F: IndexField>(
    field: &F,
    state: PathState,
    params: &TraceParams,
    owns: impl Fn(DVec3) -> bool,
    mut skip: impl FnMut(DVec3, DVec3) -> Option<Skip>,
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
            Some(Skip { n: Some(n), .. }) => n,
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
            None => skip(y.x, y.t),
        };
        if let Some(Skip { len, bound, n: known }) = offer {
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

/// One step of size `h` (for `Adaptive`: one uncontrolled Dormand–Prince
/// step).
fn fixed_step<F: IndexField>(
    m: Method,
    ev: &mut Eval<'_, F>,
    y: &State,
    h: f64,
) -> Result<State, TraceError> {
    Ok(match m {
        Method::Euler => {
            let k = ev.deriv(y)?;
            y.axpy(h, &k)
        }
        // One Dormand–Prince step without control (the landing step).
        Method::Adaptive => dopri(ev, y, h)?.0,
        Method::Rk4 => {
            let k1 = ev.deriv(y)?;
            let k2 = ev.deriv(&y.axpy(0.5 * h, &k1))?;
            let k3 = ev.deriv(&y.axpy(0.5 * h, &k2))?;
            let k4 = ev.deriv(&y.axpy(h, &k3))?;
            State {
                x: y.x + h / 6.0 * (k1.x + 2.0 * k2.x + 2.0 * k3.x + k4.x),
                t: y.t + h / 6.0 * (k1.t + 2.0 * k2.t + 2.0 * k3.t + k4.t),
                opl: y.opl + h / 6.0 * (k1.opl + 2.0 * k2.opl + 2.0 * k3.opl + k4.opl),
                s: y.s + h / 6.0 * (k1.s + 2.0 * k2.s + 2.0 * k3.s + k4.s),
            }
        }
        Method::Symplectic => {
            // Kick–drift–kick. Optical path and arc length along the
            // chord the drift actually moved, `n` by the trapezoid rule:
            // leapfrog keeps `|T|² − n²` bounded, not zero, so a ray
            // leaves a refracting region with `|T|` off `n` by O(h²) and,
            // in the uniform region after it, `∫ n² dt` would drift from
            // `n × (distance moved)` in proportion to that distance (a
            // 2.5 % phase error through a Gaussian bump at two-cell
            // steps, docs/oracles.md §5); the chord never does.
            let (n_a, g_a) = ev.n(y.x)?;
            let t_half = y.t + 0.5 * h * n_a * g_a;
            let x = y.x + h * t_half;
            let (n_b, g_b) = ev.n(x)?;
            let len = (x - y.x).length();
            State {
                x,
                t: t_half + 0.5 * h * n_b * g_b,
                opl: y.opl + 0.5 * (n_a + n_b) * len,
                s: y.s + len,
            }
        }
    })
}

// Dormand–Prince 5(4) tableau (Dormand & Prince 1980).
pub(crate) const A: [[f64; 6]; 6] = [
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0, 0.0, 0.0],
    [9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0, 0.0],
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0],
];
/// 5th-order weights (= last row of `A`, FSAL).
const B5: [f64; 7] =
    [35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0, 0.0];
/// 4th-order weights.
const B4: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];

/// One Dormand–Prince step of size `h`: the 5th-order result and the
/// max-norm of its difference from the 4th-order one (position and `T`).
fn dopri<F: IndexField>(
    ev: &mut Eval<'_, F>,
    y: &State,
    h: f64,
) -> Result<(State, f64), TraceError> {
    let mut k = [*y; 7];
    k[0] = ev.deriv(y)?;
    for s in 1..7 {
        let mut yi = *y;
        for (j, a) in A[s - 1].iter().enumerate().take(s) {
            yi = yi.axpy(h * a, &k[j]);
        }
        k[s] = ev.deriv(&yi)?;
    }
    let (mut y5, mut y4) = (*y, *y);
    for s in 0..7 {
        y5 = y5.axpy(h * B5[s], &k[s]);
        y4 = y4.axpy(h * B4[s], &k[s]);
    }
    let err = (y5.x - y4.x).abs().max_element().max((y5.t - y4.t).abs().max_element());
    Ok((y5, err))
}

/// An accepted adaptive step: `(state, step used, local error)`; adapts `h`
/// (never above `max_step`).
fn adaptive_step<F: IndexField>(
    ev: &mut Eval<'_, F>,
    y: &State,
    h: &mut f64,
    max_step: f64,
    params: &TraceParams,
    stats: &mut TraceStats,
) -> Result<(State, f64, f64), TraceError> {
    loop {
        let (next, err) = dopri(ev, y, *h)?;
        // Standard controller: safety 0.9, growth in [0.2, 5].
        let factor = if err > 0.0 { 0.9 * powf(params.tolerance / err, 0.2) } else { 5.0 };
        let factor = factor.clamp(0.2, 5.0);
        if err <= params.tolerance {
            let used = *h;
            *h = (*h * factor).min(max_step);
            return Ok((next, used, err));
        }
        stats.rejected += 1;
        let tried = *h;
        *h *= factor;
        if stats.rejected + stats.steps >= params.max_steps || *h < 1e-300 {
            // Give up controlling: accept (the caller stops on max_steps).
            return Ok((next, tried, err));
        }
    }
}

/// Finds the step `h* ∈ (0, h]` from `y` (inside the bounds, arc length
/// below `limit`) to the first event on the step to `past`: the bounds'
/// surface, or the arc length `limit`. The Illinois variant of regula
/// falsi on the larger of the signed distance outside the box (per unit
/// of box size) and the arc length past `limit` (per unit of `limit`),
/// with the scheme's own step of each trial length, so the last step is
/// as accurate as the others. Returns the state there, snapped onto the
/// face it left through, and which event it was.
fn land<F: IndexField>(
    m: Method,
    ev: &mut Eval<'_, F>,
    y: &State,
    past: &State,
    h: f64,
    limit: f64,
    stats: &mut TraceStats,
) -> Result<(State, Exit), TraceError> {
    let b = ev.bounds;
    // Signed distance outside the box, per unit of box size: ≤ 0 inside,
    // > 0 outside; its zero on the step is where the ray leaves.
    let size = (b.max - b.min).max(DVec3::splat(f64::MIN_POSITIVE));
    let outside_by = |s: &State| -> (f64, usize, f64) {
        let mut worst = (f64::NEG_INFINITY, 0, 0.0);
        for a in 0..3 {
            for (over, plane) in [
                ((s.x[a] - b.max[a]) / size[a], b.max[a]),
                ((b.min[a] - s.x[a]) / size[a], b.min[a]),
            ] {
                if over > worst.0 {
                    worst = (over, a, plane);
                }
            }
        }
        worst
    };
    // Arc length past the limit, per unit of the limit.
    let beyond = |s: &State| (s.s - limit) / limit;
    let g = |s: &State| {
        let (over, _, _) = outside_by(s);
        let late = beyond(s);
        if late > over { late } else { over }
    };
    let (mut lo, mut g_lo) = (0.0, g(y));
    let (mut hi, mut g_hi) = (h, g(past));
    let mut landed = *past;
    let mut side = 0i8;
    let tol = 1e-14;
    for _ in 0..60 {
        let hm = if g_hi != g_lo { hi - g_hi * (hi - lo) / (g_hi - g_lo) } else { 0.5 * (lo + hi) };
        let hm = if hm > lo && hm < hi { hm } else { 0.5 * (lo + hi) };
        let s = fixed_step(m, ev, y, hm)?;
        let gm = g(&s);
        landed = s;
        if gm.abs() <= tol || hi - lo <= 1e-15 * h {
            break;
        }
        if gm > 0.0 {
            hi = hm;
            g_hi = gm;
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        } else {
            lo = hm;
            g_lo = gm;
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        }
    }
    stats.steps += 1;
    let (over, axis, plane) = outside_by(&landed);
    if beyond(&landed) > over {
        // The arc-length limit came first: the ray is inside the box (the
        // clamp only guards against rounding).
        landed.x = landed.x.clamp(b.min, b.max);
        return Ok((landed, Exit::MaxLength));
    }
    // Snap the exit coordinate onto the face it is on (within `tol`).
    landed.x[axis] = plane;
    // Where the search could not resolve the crossing (a field so extreme
    // that one step is far from straight: found by fuzzing with n ≈ 1e38),
    // the other coordinates may still lie outside: the exit is on the box.
    landed.x = landed.x.clamp(b.min, b.max);
    Ok((landed, Exit::Left))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bounds, LinearIndex};

    /// Found by the `integrators` fuzz target: a direction of length
    /// 3e-241 squared to 0 in `normalize`, and the trace returned NaN with
    /// `Exit::Left`. Tiny and huge directions now trace as their unit
    /// vector does.
    #[test]
    fn fuzz_regression_tiny_and_huge_directions() {
        let f = LinearIndex {
            n0: 1.0,
            gradient: DVec3::new(0.0, 0.1, 0.0),
            bounds: Bounds::new(DVec3::splat(-1.0), DVec3::splat(1.0)),
        };
        let p = TraceParams::accurate();
        let unit = trace(&f, DVec3::new(-2.0, 0.0, 0.0), DVec3::X, &p).unwrap();
        for s in [-2.999393638964874e-241, 1e-300, 1e300, f64::MAX] {
            let r = trace(&f, DVec3::new(-2.0, 0.0, 0.0), DVec3::X * s.abs(), &p).unwrap();
            assert_eq!(r, unit, "direction scaled by {s:e}");
        }
        // A negative step cap (also from the fuzzer) traced backwards out
        // of the box; it is an error now, as is NaN.
        for max_step in [-0.1875, 0.0, f64::NAN] {
            let q = TraceParams { max_step, ..TraceParams::fixed(Method::Symplectic, 3.875) };
            assert_eq!(trace(&f, DVec3::ZERO, DVec3::X, &q), Err(TraceError::InvalidParams));
        }
        // n ≈ 3.4e38 with a gradient: one Euler step leaves far from
        // straight and the exit search cannot resolve it; the exit point
        // must still be on the box (it was 1e21 away).
        let huge = LinearIndex {
            n0: 3.4028234663852886e38,
            gradient: DVec3::new(0.0, -1.625, -1.625),
            bounds: Bounds::new(DVec3::new(-2.3125, -1.5, -4.0), DVec3::ZERO),
        };
        let r = trace(
            &huge,
            DVec3::new(-1.125, -1.625, -1.625),
            DVec3::new(-3.9375, 3.4028234663852886e38, 3.4028234663852886e38),
            &TraceParams::fixed(Method::Euler, 0.01),
        )
        .unwrap();
        assert_eq!(r.exit, Exit::Left);
        assert!(huge.bounds.contains(r.position), "{r:?}");
        // An ambient index of 4e281 around a field of n ≈ 1. The entry
        // point rounds to just outside the box (x = 1.9375 − 9e-16), where
        // the trace used to take the ambient index for the field's:
        // `T = 4e281·d` inside, and the path overflowed (an error, rather
        // than an infinite result). The field's continuation now gives its
        // own index there: a finite trace, `|T| = n` throughout, the
        // optical path dominated by the ambient stretch (4e281 · 5.9).
        let grid = crate::Grid::new(
            [2, 2, 2],
            DVec3::splat(3.875),
            DVec3::splat(3.875),
            alloc::vec![0.999, 0.999, 0.999, 0.999, 0.999, 1.0, 1.008, 1.0],
        )
        .unwrap();
        let field =
            crate::GridField::new(grid, crate::Interp::CatmullRom, 4.147_771_230_004_15e281)
                .unwrap();
        let q = TraceParams {
            tolerance: 1.1920928955078125e-7,
            max_step: 3.875,
            max_steps: 5020,
            max_length: 3.875,
            ..TraceParams::fixed(Method::Symplectic, 1.1920928955078125e-7)
        };
        let r =
            trace(&field, DVec3::new(-2.125, 3.4375, 3.4375), DVec3::new(3.4375, -1.125, 3.5), &q)
                .unwrap();
        assert!(r.position.is_finite() && r.optical_path.is_finite(), "{r:?}");
        assert!(r.stats.invariant_drift < 1e-12, "{r:?}");
        assert!((r.optical_path / 4.147_771_230_004_15e281 - 5.948).abs() < 1e-3, "{r:?}");
        // The fuzzer's own case: a ray beside the box along a tiny -z.
        let f = LinearIndex {
            n0: 1.5,
            gradient: DVec3::splat(-1.625),
            bounds: Bounds::new(DVec3::new(-2.3125, -1.625, -4.0), DVec3::ZERO),
        };
        let r = trace(
            &f,
            DVec3::new(-3.5, 0.0, 0.0),
            DVec3::new(0.0, 0.0, -2.999393638964874e-241),
            &p,
        )
        .unwrap();
        assert_eq!(r.exit, Exit::Missed);
        assert!(r.position.is_finite() && r.direction.is_finite());
    }
}
