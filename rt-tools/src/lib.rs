//! # rt-tools
//!
//! What rt's tools share, so that neither the `rt` command (`rt-cli`) nor
//! the report (`rt-report` in `benches/`) stands on the other: the
//! instruments themselves live in the libraries (`rt_photo`'s set-ups
//! over an `rt_volume::Medium`); this crate holds what turns their
//! results into files and what the tools render from.
//!
//! - [`figure`]: an image with axes in metres, ticks, a scale bar, a
//!   title and a legend (colour bar or deflection wheel), as a PNG;
//! - [`image`]: 8-bit sRGB and 16-bit linear PNGs, sensor counts, raw +
//!   JSON arrays; [`output`]: outputs checked before the work and
//!   committed together after it; [`text`]: the embedded font;
//!   [`vtu`]: unstructured meshes written as VTK XML;
//! - [`builtin`]: the built-in blast wave (a real PyClaw solution, 64³)
//!   as a medium, a mesh or files; [`scenes`]: the demo's terrain;
//! - [`distributed`]: a terrain (shadow and AO rays answered by every
//!   rank) rendered across ranks and checked against one process bit for
//!   bit; volumes (photons handed between bricks) are
//!   `rt_photo::distributed`'s.
//!
//! Not a stable API: it changes with the tools (it is packaged only
//! because the `rt` program depends on it).
#![allow(clippy::std_instead_of_core, clippy::std_instead_of_alloc, clippy::alloc_instead_of_core)]

pub mod builtin;
pub mod distributed;
pub mod figure;
pub mod image;
pub mod output;
pub mod scenes;
pub mod text;
pub mod vtu;
