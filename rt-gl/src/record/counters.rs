//! What the recorder has done: list and buffer-draw cache builds, refits
//! and reuses, the last frame's size, and the calls it ignored.

/// What the recorder has done, for the logs and the tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Frames ended ([`Recorder::end_frame`](super::Recorder::end_frame)).
    pub frames: u64,
    /// Display-list calls recorded into a new cache entry.
    pub list_builds: u64,
    /// Display-list calls answered from the cache.
    pub list_reuses: u64,
    /// Display-list calls that could not be cached (executed as immediate
    /// geometry: lists that load matrices, draw points or lines, or are
    /// called inside `glBegin`).
    pub list_inline: u64,
    /// Array draws from buffer objects recorded into a new cache entry
    /// whose BVHs are built.
    pub draw_builds: u64,
    /// Array draws from buffer objects answered from the cache.
    pub draw_reuses: u64,
    /// Array draws from buffer objects recorded into a new cache entry
    /// whose BVHs are refitted from the previous entry of the same draw
    /// (its buffers' contents changed, its triangles did not) rather than
    /// built: not also counted in `draw_builds`.
    pub draw_refits: u64,
    /// Array draws from client memory (or with points and lines),
    /// recorded as immediate geometry.
    pub draw_inline: u64,
    /// Passes in the last frame ended (see [`Frame`](super::Frame)).
    pub passes: u64,
    /// Draws that joined the last pass of a frame because it already had
    /// [`MAX_PASSES`](super::MAX_PASSES).
    pub passes_merged: u64,
    /// Instances in the last frame ended.
    pub instances: u64,
    /// Triangles in the last frame ended (immediate and instanced).
    pub triangles: u64,
    /// Calls ignored because they break GL's rules (a vertex outside
    /// `glBegin`, an unknown primitive type, a stack over- or underflow, …).
    pub ignored: u64,
}
