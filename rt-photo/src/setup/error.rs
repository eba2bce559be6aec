//! Why an instrument could not be set up.

use alloc::string::String;
use core::fmt;

use crate::{BenchError, BosError, FilmError, FocusingError};

/// Why a set-up failed.
#[derive(Debug)]
#[non_exhaustive]
pub enum SetupError {
    /// An option out of its range: its name and what it must be.
    Invalid {
        /// The option's name.
        name: &'static str,
        /// What it must be (`"finite and > 0"`, `"1 to 16384"`).
        must_be: String,
        /// What it was.
        got: String,
    },
    /// More photons than one render traces.
    TooManyPhotons {
        /// Photons asked for.
        photons: u64,
        /// The most one render traces ([`crate::MAX_PHOTONS`]).
        max: u64,
    },
    /// The camera would sit inside its focal length of the volume.
    TooClose {
        /// Distance from the lens to the volume's centre, metres.
        distance: f64,
        /// The lens's focal length, metres.
        focal_length: f64,
    },
    /// The survey's or the render's film could not be made.
    Film(FilmError),
    /// The bench (or its survey) failed.
    SchlierenBench(BenchError),
    /// The BOS rig or render failed.
    Bos(BosError),
    /// The focusing rig or render failed.
    Focusing(FocusingError),
    /// The caller's `stop` asked the render to end (`render_until`).
    Stopped,
}

impl fmt::Display for SetupError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Invalid { name, must_be, got } => {
                write!(f, "{name} must be {must_be} (got {got})")
            }
            Self::TooManyPhotons { photons, max } => {
                write!(f, "{photons} photons is more than one run traces ({max})")
            }
            Self::TooClose { distance, focal_length } => write!(
                f,
                "the volume must be farther from the lens ({distance} m) than its focal length ({focal_length} m)"
            ),
            Self::Film(e) => e.fmt(f),
            Self::SchlierenBench(e) => e.fmt(f),
            Self::Bos(e) => e.fmt(f),
            Self::Focusing(e) => e.fmt(f),
            Self::Stopped => write!(f, "the render was stopped"),
        }
    }
}

impl core::error::Error for SetupError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Film(e) => Some(e),
            Self::SchlierenBench(e) => Some(e),
            Self::Bos(e) => Some(e),
            Self::Focusing(e) => Some(e),
            _ => None,
        }
    }
}

impl SetupError {
    /// [`SetupError::Stopped`] once `stop` says so (the trace failed
    /// because it was told to), else `e`.
    pub(crate) fn stopped_or(stop: &dyn Fn() -> bool, e: impl Into<Self>) -> Self {
        if stop() { Self::Stopped } else { e.into() }
    }
}

impl From<FilmError> for SetupError {
    fn from(e: FilmError) -> Self {
        Self::Film(e)
    }
}

impl From<BenchError> for SetupError {
    fn from(e: BenchError) -> Self {
        Self::SchlierenBench(e)
    }
}

impl From<BosError> for SetupError {
    fn from(e: BosError) -> Self {
        Self::Bos(e)
    }
}

impl From<FocusingError> for SetupError {
    fn from(e: FocusingError) -> Self {
        Self::Focusing(e)
    }
}

/// `Ok(v)` if `v` is finite and `> 0`.
pub(crate) fn positive(name: &'static str, v: f64) -> Result<f64, SetupError> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(invalid(name, "finite and > 0", v)) }
}

/// `Ok(v)` if `v` is finite.
pub(crate) fn finite(name: &'static str, v: f64) -> Result<f64, SetupError> {
    if v.is_finite() { Ok(v) } else { Err(invalid(name, "finite", v)) }
}

/// `Ok(v)` if `lo ≤ v ≤ hi`.
pub(crate) fn within(name: &'static str, v: u32, lo: u32, hi: u32) -> Result<u32, SetupError> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(invalid(name, &alloc::format!("{lo} to {hi}"), v))
    }
}

/// An [`SetupError::Invalid`].
pub(crate) fn invalid(name: &'static str, must_be: &str, got: impl fmt::Display) -> SetupError {
    SetupError::Invalid { name, must_be: must_be.into(), got: alloc::format!("{got}") }
}
