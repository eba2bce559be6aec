//! Why a distributed volume render failed (on a rank).

use alloc::string::String;
use core::fmt;
use std::path::PathBuf;

use glam::DVec3;
use rt_volume::{BrickError, GridError, MediumError, TraceError, io::ReadError};

use crate::{BenchError, FilmError, SetupError};

/// Why a distributed volume render failed on this rank (every rank learns
/// of a failure within the communicator's timeout).
#[derive(Debug)]
#[non_exhaustive]
pub enum DistributedError {
    /// The volume is not read a brick at a time: only raw + JSON and NRRD
    /// with raw encoding are.
    Format(PathBuf),
    /// The file could not be read (the error names it).
    Read(ReadError),
    /// The samples make no index (a bad Gladstone–Dale constant, values
    /// that overflow).
    Samples(MediumError),
    /// The brick's samples make no grid.
    Grid(GridError),
    /// The grid cannot be split for these ranks, or a brick is bad.
    Brick(BrickError),
    /// A trace failed, or the trace settings cannot bound a step's reach.
    Trace(TraceError),
    /// A step reached past this rank's brick and its ghost layers.
    BeyondBrick {
        /// This rank.
        rank: usize,
        /// Where the step reached.
        at: DVec3,
    },
    /// The bench's set-up is bad.
    Bench(BenchError),
    /// The film could not be made.
    Film(FilmError),
    /// A BOS or focusing set-up is bad, or its render failed.
    Setup(SetupError),
    /// More photons than one distributed run traces (each rank lists
    /// their identities once).
    TooManyPhotons {
        /// Photons asked for.
        photons: u64,
        /// The most a run traces ([`super::MAX_PHOTONS`]).
        max: u64,
    },
    /// Rank `from` sent bytes no rank writes.
    Malformed {
        /// The sender.
        from: usize,
    },
    /// Exchanging with the other ranks failed (a timeout, a peer that
    /// failed, too many rounds).
    Exchange {
        /// This rank.
        rank: usize,
        /// What the exchange reported.
        message: String,
    },
    /// Rank 0 holds no result for a photon the bench emits.
    MissingResult,
    /// This rank's [`super::Watch`] said to stop (its peers fail with
    /// [`DistributedError::Exchange`], "rank r failed").
    Stopped,
    /// A [`super::Piece`] lacks samples the run reads.
    Piece {
        /// First sample asked for.
        lo: [usize; 3],
        /// One past the last sample asked for.
        hi: [usize; 3],
        /// The piece's first sample and samples per axis.
        held: ([usize; 3], [usize; 3]),
    },
}

impl fmt::Display for DistributedError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Format(path) => write!(
                f,
                "{}: a distributed volume is read a brick at a time, from raw + JSON (.json) or NRRD with raw encoding (.nrrd, .nhdr)",
                path.display()
            ),
            Self::Read(e) => e.fmt(f),
            Self::Samples(e) => e.fmt(f),
            Self::Grid(e) => e.fmt(f),
            Self::Brick(e) => e.fmt(f),
            Self::Trace(e) => e.fmt(f),
            Self::BeyondBrick { rank, at } => write!(
                f,
                "rank {rank}: a step reached {at} beyond this rank's brick and its ghost layers"
            ),
            Self::Bench(e) => e.fmt(f),
            Self::Film(e) => e.fmt(f),
            Self::Setup(e) => e.fmt(f),
            Self::TooManyPhotons { photons, max } => {
                write!(f, "{photons} photons is more than a distributed run traces ({max})")
            }
            Self::Malformed { from } => write!(f, "rank {from} sent a malformed batch"),
            Self::Exchange { rank, message } => write!(f, "rank {rank}: {message}"),
            Self::MissingResult => f.write_str("rank 0: a photon's result is missing"),
            Self::Stopped => f.write_str("the run was stopped"),
            Self::Piece { lo, hi, held: (at, dims) } => write!(
                f,
                "samples {lo:?}..{hi:?} are needed, the piece holds {dims:?} from {at:?} (too few ghost layers)"
            ),
        }
    }
}

impl core::error::Error for DistributedError {
    fn source(&self) -> Option<&(dyn core::error::Error + 'static)> {
        match self {
            Self::Read(e) => Some(e),
            Self::Samples(e) => Some(e),
            Self::Grid(e) => Some(e),
            Self::Brick(e) => Some(e),
            Self::Trace(e) => Some(e),
            Self::Bench(e) => Some(e),
            Self::Film(e) => Some(e),
            Self::Setup(e) => Some(e),
            _ => None,
        }
    }
}

macro_rules! from {
    ($($t:ty => $v:ident),*) => {$(
        impl From<$t> for DistributedError {
            fn from(e: $t) -> Self {
                Self::$v(e)
            }
        }
    )*};
}

from!(ReadError => Read, MediumError => Samples, GridError => Grid, BrickError => Brick,
    TraceError => Trace, BenchError => Bench, FilmError => Film, SetupError => Setup);

impl From<core::convert::Infallible> for DistributedError {
    fn from(e: core::convert::Infallible) -> Self {
        match e {}
    }
}
