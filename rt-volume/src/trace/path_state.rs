//! A ray's whole integration state between two legs of a distributed
//! trace, and the wire format of a distributed trace: that state and a
//! finished ray's result, each as a fixed number of f64 words (for the
//! network; bit-exact, so a trace handed between ranks is the trace of
//! one process).

use glam::DVec3;

use super::eval::State;
use super::walk::unit;
use super::{Exit, TraceError, TraceResult, TraceStats};

/// A ray's whole integration state between two legs of a distributed
/// trace ([`trace_begin`](crate::trace_begin), [`trace_leg`](crate::trace_leg)):
/// position `x`, `T = n dx/ds`, optical path, arc length inside the
/// bounds, the current step (Adaptive changes it) and the step cap (fixed
/// at entry from the chord through the bounds), the chord, the
/// [`TraceStats`] so far, the last field evaluation (steps reuse it: the
/// count of evaluations depends on it), and whether the entry evaluation
/// was done (before it, `T` holds the unit direction).
///
/// Nothing else is carried from one step to the next, so a trace resumed
/// from it is the trace that was interrupted, bit for bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathState {
    pub(super) y: State,
    pub(super) h: f64,
    pub(super) max_step: f64,
    pub(super) chord: f64,
    pub(super) stats: TraceStats,
    pub(super) last: Option<(DVec3, f64, DVec3)>,
    pub(super) entered: bool,
}

impl PathState {
    /// Words in [`PathState::to_words`].
    pub const WORDS: usize = 27;

    /// Where the ray is (the start of its next step).
    #[must_use]
    pub fn position(&self) -> DVec3 {
        self.y.x
    }

    /// Its unit direction there.
    #[must_use]
    pub fn direction(&self) -> DVec3 {
        unit(self.y.t)
    }

    /// Optical path from the ray's origin so far.
    #[must_use]
    pub fn optical_path(&self) -> f64 {
        self.y.opl
    }

    /// Work and error so far.
    #[must_use]
    pub fn stats(&self) -> TraceStats {
        self.stats
    }

    /// The state as f64 words (counts are integers, flags 0 or 1; an
    /// absent last evaluation is zeros). Layout: `x` (3), `T` (3), optical
    /// path, arc length, step, step cap, chord, the seven [`TraceStats`]
    /// in declaration order, a flag and the last evaluation's `x` (3),
    /// `n`, `∇n` (3), the entry flag.
    #[must_use]
    pub fn to_words(&self) -> [f64; Self::WORDS] {
        let mut w = [0.0; Self::WORDS];
        let s = &self.stats;
        w[0..3].copy_from_slice(&self.y.x.to_array());
        w[3..6].copy_from_slice(&self.y.t.to_array());
        w[6] = self.y.opl;
        w[7] = self.y.s;
        w[8] = self.h;
        w[9] = self.max_step;
        w[10] = self.chord;
        w[11] = f64::from(s.steps);
        w[12] = f64::from(s.field_evals);
        w[13] = f64::from(s.rejected);
        w[14] = s.error_estimate;
        w[15] = s.invariant_drift;
        w[16] = f64::from(s.skipped);
        w[17] = s.skip_bound;
        if let Some((x, n, g)) = self.last {
            w[18] = 1.0;
            w[19..22].copy_from_slice(&x.to_array());
            w[22] = n;
            w[23..26].copy_from_slice(&g.to_array());
        }
        w[26] = if self.entered { 1.0 } else { 0.0 };
        w
    }

    /// The state [`PathState::to_words`] wrote, checked (it comes off the
    /// network): position, `T`, optical path and arc length finite, `T`
    /// not zero; step and cap positive (zero before the entry evaluation),
    /// chord `≥ 0`; counts integers in `u32`'s range; error sums `≥ 0`;
    /// flags 0 or 1; a last evaluation finite with `n > 0`, or all zeros.
    ///
    /// # Errors
    /// [`TraceError::InvalidState`] for words no state writes.
    pub fn from_words(w: &[f64; Self::WORDS]) -> Result<Self, TraceError> {
        let bad = Err(TraceError::InvalidState);
        let v3 = |i: usize| DVec3::new(w[i], w[i + 1], w[i + 2]);
        let flag = |v: f64| {
            if v == 0.0 {
                Some(false)
            } else if v == 1.0 {
                Some(true)
            } else {
                None
            }
        };
        let sum = |v: f64| v >= 0.0;
        let (Some(has_last), Some(entered)) = (flag(w[18]), flag(w[26])) else {
            return bad;
        };
        let (Some(steps), Some(field_evals), Some(rejected), Some(skipped)) =
            (count(w[11]), count(w[12]), count(w[13]), count(w[16]))
        else {
            return bad;
        };
        let y = State { x: v3(0), t: v3(3), opl: w[6], s: w[7] };
        let (h, max_step, chord) = (w[8], w[9], w[10]);
        let ray_ok = y.x.is_finite()
            && y.t.is_finite()
            && y.t != DVec3::ZERO
            && y.opl.is_finite()
            && y.s.is_finite()
            && chord >= 0.0;
        let steps_ok =
            if entered { h > 0.0 && max_step > 0.0 } else { h == 0.0 && max_step == 0.0 };
        let sums_ok = sum(w[14]) && sum(w[15]) && sum(w[17]);
        let last = if has_last {
            let (x, n, g) = (v3(19), w[22], v3(23));
            if !(x.is_finite() && n.is_finite() && n > 0.0 && g.is_finite()) {
                return bad;
            }
            Some((x, n, g))
        } else {
            if w[19..26].iter().any(|&v| v != 0.0) {
                return bad;
            }
            None
        };
        if !(ray_ok && steps_ok && sums_ok) {
            return bad;
        }
        let stats = TraceStats {
            steps,
            field_evals,
            rejected,
            error_estimate: w[14],
            invariant_drift: w[15],
            skipped,
            skip_bound: w[17],
        };
        Ok(Self { y, h, max_step, chord, stats, last, entered })
    }
}

/// The exits in their wire order.
const EXITS: [Exit; 4] = [Exit::Missed, Exit::Left, Exit::MaxSteps, Exit::MaxLength];

/// `v` as a count if it is an integer in `u32`'s range.
fn count(v: f64) -> Option<u32> {
    (v >= 0.0 && v <= f64::from(u32::MAX) && v == (v as u32) as f64).then_some(v as u32)
}

impl TraceResult {
    /// Words in [`TraceResult::to_words`].
    pub const WORDS: usize = 15;

    /// The result as words, bit-exact: position (3), direction (3),
    /// optical path, the exit (0 missed, 1 left, 2 out of steps, 3 out of
    /// length), then the [`TraceStats`] in declaration order.
    #[must_use]
    pub fn to_words(&self) -> [f64; Self::WORDS] {
        let s = &self.stats;
        let exit = EXITS.iter().position(|e| *e == self.exit).unwrap_or(0);
        let (p, d) = (self.position, self.direction);
        [
            p.x,
            p.y,
            p.z,
            d.x,
            d.y,
            d.z,
            self.optical_path,
            exit as f64,
            f64::from(s.steps),
            f64::from(s.field_evals),
            f64::from(s.rejected),
            s.error_estimate,
            s.invariant_drift,
            f64::from(s.skipped),
            s.skip_bound,
        ]
    }

    /// The result [`TraceResult::to_words`] wrote, checked: the exit one
    /// of the four, counts integers in `u32`'s range.
    ///
    /// # Errors
    /// [`TraceError::InvalidState`] for words no result writes.
    pub fn from_words(w: &[f64; Self::WORDS]) -> Result<Self, TraceError> {
        let bad = TraceError::InvalidState;
        let exit = *count(w[7]).and_then(|e| EXITS.get(e as usize)).ok_or(bad)?;
        let (Some(steps), Some(field_evals), Some(rejected), Some(skipped)) =
            (count(w[8]), count(w[9]), count(w[10]), count(w[13]))
        else {
            return Err(bad);
        };
        Ok(Self {
            position: DVec3::new(w[0], w[1], w[2]),
            direction: DVec3::new(w[3], w[4], w[5]),
            optical_path: w[6],
            exit,
            stats: TraceStats {
                steps,
                field_evals,
                rejected,
                error_estimate: w[11],
                invariant_drift: w[12],
                skipped,
                skip_bound: w[14],
            },
        })
    }
}
