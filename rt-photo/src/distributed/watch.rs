//! A run across ranks watched by its caller: asked whether to stop,
//! told how far it is. `stop` is asked before every ray an instrument
//! lists, before every photon's leg through a brick and at the start of
//! every round of the trade; once it says yes, the rank fails its next
//! round, which tells every peer (they fail with the exchange's "rank r
//! failed" within a round), so no rank waits for a timeout. A rank told
//! to stop while it lists its rays lists no more and fails at the first
//! round, for the same reason. `progress(done, total)` is told on rank 0
//! only (the rank that lands the results): the image's rays whose
//! results it holds, of all of them, after every round; a survey that
//! chooses a rig first is not counted (its rays are few).

/// What a run across ranks asks and tells its caller (module doc).
#[derive(Clone, Copy)]
pub struct Watch<'a> {
    pub(crate) stop: &'a (dyn Fn() -> bool + Sync),
    pub(crate) progress: &'a (dyn Fn(u64, u64) + Sync),
}

fn never() -> bool {
    false
}

fn ignore(_: u64, _: u64) {}

impl<'a> Watch<'a> {
    /// Never stops, tells nobody.
    pub const NONE: Watch<'static> = Watch { stop: &never, progress: &ignore };

    /// A watch that stops once `stop` says so and tells `progress(done,
    /// total)`.
    pub fn new(
        stop: &'a (dyn Fn() -> bool + Sync),
        progress: &'a (dyn Fn(u64, u64) + Sync),
    ) -> Self {
        Self { stop, progress }
    }

    /// Whether to stop.
    pub(crate) fn stopped(&self) -> bool {
        (self.stop)()
    }
}

impl core::fmt::Debug for Watch<'_> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("Watch")
    }
}
