//! Surface rendering for scientific visualization: Blinn–Phong shading
//! under ambient, directional and point lights with hard shadows, ambient
//! occlusion, mirror reflections and transparency composited in depth
//! order, over any [`ShadeScene`].
//!
//! Each pixel's samples use their own random stream from `(seed, pass,
//! pixel)`, so a frame is the same bit for bit at any thread count
//! (feature `parallel`: tiles on rayon). Work a scene does not need is not
//! done, and [`RayCounts`] proves it: no shadow rays without lights that
//! cast them, no AO rays with AO off (or without an ambient light for it
//! to darken), no reflection rays without a mirror material, no
//! transparency rays through opaque surfaces, and a ray that misses the
//! scene's bounds is not traversed ([`RayCounts::culled`]).

#[cfg(feature = "std")]
mod deferred;
mod material;
mod renderer;
mod settings;
mod shade;

#[cfg(feature = "std")]
pub use deferred::{AnswerCountError, AnsweredOcclusion, RecordOcclusion};
pub use material::{Material, MaterialError, ShadeScene, Surface};
pub use renderer::{RayCounts, RenderError, Renderer, TILE};
pub use settings::{Light, Settings, SettingsError};
