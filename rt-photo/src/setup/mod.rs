//! Instruments set up from the data: plain option structs where an unset
//! option means "choose it from the medium", a survey of the deflections
//! the medium will cause ([`Survey`]), and the set-ups that come back
//! ([`SchlierenSetup`], [`BosSetup`], [`FocusingSetup`]) holding the
//! instrument, what was chosen (with `Display` for the line a tool
//! prints) and one `render` over any [`Medium`](rt_volume::Medium).
//! These are what `rt schlieren`, `rt bos`, `rt focusing`, the demo and
//! `rtvis` run; they map their options here and nothing else.

mod bos;
mod error;
mod focusing;
mod schlieren;
mod survey;
mod view;

pub use bos::{BosOptions, BosSetup};

/// The widest camera image (BOS, focusing schlieren) a set-up accepts,
/// in pixels.
pub const MAX_CAMERA_EDGE: u32 = 8192;
/// The most aperture samples per axis of a camera set-up.
pub const MAX_APERTURE_SAMPLES: u32 = 64;
pub use error::SetupError;
pub use focusing::{FocusingOptions, FocusingSetup};
pub use schlieren::{
    CutoffKind, MAX_EDGE, MAX_PHOTONS, MAX_PHOTONS_PER_PIXEL, SchlierenOptions, SchlierenSetup,
    lattice, traced_per_pixel,
};
pub use survey::Survey;
pub use view::Axis;
