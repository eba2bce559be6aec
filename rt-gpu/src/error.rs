//! What can go wrong on the GPU path, one cause per variant.

use core::fmt;

/// An error of the GPU backend.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum GpuError {
    /// No adapter (Vulkan, Metal or DX12 driver) was found: run on the
    /// CPU instead (`RT_GPU_ADAPTER` may name one by part of its name).
    NoAdapter,
    /// The adapter refused a device (its message).
    Device(String),
    /// A grid sample or photon coordinate is NaN or infinite (its index).
    NonFinite {
        /// Which input: `"sample"`, `"origin"` or `"direction"`.
        what: &'static str,
        /// Its position in the input.
        index: usize,
    },
    /// A photon's direction is zero (its index).
    ZeroDirection {
        /// Its position in the input.
        index: usize,
    },
    /// An input larger than the device accepts in one buffer.
    TooLarge {
        /// Bytes asked for.
        bytes: u64,
        /// The device's largest storage buffer.
        limit: u64,
    },
    /// A field the GPU path does not trace yet (what).
    Unsupported(&'static str),
    /// The trace settings are not usable: a step that is not finite and
    /// positive, or no steps at all.
    BadSettings,
    /// The device failed while tracing or reading back (its message).
    Lost(String),
    /// The schlieren bench refused its parameters or a pass.
    Bench(rt_photo::BenchError),
    /// The set-up refused the render (its message: a film too large).
    Setup(String),
    /// The caller's stop said so, between two passes.
    Stopped,
}

impl fmt::Display for GpuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoAdapter => write!(f, "no GPU adapter found (Vulkan, Metal or DX12)"),
            Self::Device(m) => write!(f, "the GPU adapter refused a device: {m}"),
            Self::NonFinite { what, index } => write!(f, "{what} {index} is not finite"),
            Self::ZeroDirection { index } => write!(f, "photon {index} has a zero direction"),
            Self::TooLarge { bytes, limit } => {
                write!(f, "{bytes} bytes exceed the device's storage buffers ({limit} bytes)")
            }
            Self::Unsupported(what) => write!(f, "not on the GPU: {what}"),
            Self::BadSettings => write!(f, "the step must be finite and positive, with steps > 0"),
            Self::Lost(m) => write!(f, "the GPU failed: {m}"),
            Self::Bench(e) => write!(f, "{e}"),
            Self::Setup(e) => write!(f, "{e}"),
            Self::Stopped => write!(f, "stopped"),
        }
    }
}

impl core::error::Error for GpuError {}
