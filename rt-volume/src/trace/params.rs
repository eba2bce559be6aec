//! What a trace is asked for and what it returns: the integration scheme
//! and its limits, the result, its statistics and errors.

use core::fmt;

use glam::DVec3;

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
    /// Field evaluations (calls to [`IndexField::eval`](crate::IndexField::eval)).
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
    /// Words that no [`PathState`](super::PathState) writes ([`PathState::from_words`](super::PathState::from_words)).
    InvalidState,
    /// The caller asked the trace to stop (a render interrupted between
    /// rays; nothing wrong with the ray).
    Stopped,
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InvalidRay => write!(f, "ray origin/direction not finite or zero"),
            Self::InvalidParams => write!(f, "trace parameters must be finite and positive"),
            Self::BadField { at } => write!(f, "field is not finite and positive at {at}"),
            Self::InvalidState => write!(f, "not the words of a ray's path state"),
            Self::Stopped => write!(f, "stopped on request"),
        }
    }
}

impl core::error::Error for TraceError {}
