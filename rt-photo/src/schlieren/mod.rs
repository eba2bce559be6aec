//! The schlieren bench: a collimated beam traced through the field, its
//! photons weighed by a cutoff in the focal plane (or phased, for
//! interferometry) and gathered on a film, one by one or as a sheet.

pub(crate) mod bench;
mod cutoff;
mod film;
mod sheet;

pub use bench::{BatchTracer, BenchError, Mode, Reconstruction, SchlierenBench, Weighting};
pub use cutoff::{Cutoff, CutoffError, CutoffParam, FilterImage};
pub use film::{Film, FilmError, Filter, Photon};
