//! Best-of-N timing with the spread.

use std::time::Instant;

/// Times of repeated runs of one implementation.
#[derive(Clone, Debug, Default)]
pub(crate) struct Samples(pub(crate) Vec<f64>);

impl Samples {
    pub(crate) fn best(&self) -> f64 {
        self.0.iter().copied().fold(f64::INFINITY, f64::min)
    }

    pub(crate) fn worst(&self) -> f64 {
        self.0.iter().copied().fold(0.0, f64::max)
    }

    /// How much slower the slowest run was than the fastest, in percent.
    pub(crate) fn spread(&self) -> f64 {
        (self.worst() / self.best() - 1.0) * 100.0
    }
}

/// Seconds taken by `f`, with its result.
pub(crate) fn time<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let t = Instant::now();
    let r = f();
    (t.elapsed().as_secs_f64(), r)
}
