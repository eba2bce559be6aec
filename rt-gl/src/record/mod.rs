//! The recorder: a mirror of the fixed-function state a program sets
//! (matrix stacks, current colour and normal, lights, materials, display
//! lists) that turns its draws into geometry.
//!
//! Geometry lands in one of two places. Immediate-mode draws go into the
//! frame in **eye space** (transformed by the modelview at the vertex, as
//! GL does), rebuilt every frame. A call of a display list is recorded
//! once in the list's **entry space** (eye space under the modelview at
//! the call, inverted) and cached; every call, this frame and later ones,
//! becomes an instance: the cached geometry and the modelview at the call.
//! A cache entry is keyed by the list, its definition and every attribute
//! its geometry can inherit from the caller (colour, normal, material,
//! lighting switches), so a hit draws exactly what executing the list
//! would.
//!
//! The recorder is plain Rust, with no GL in it: the interposer feeds it
//! the calls it forwards, and the tests feed it directly.
//!
//! Where each part lives:
//!
//! - `recorder.rs`: [`Recorder`], the state machine and its dispatch.
//! - `command.rs`: [`Command`], one recorded call.
//! - `lighting.rs`: lights, materials and [`Shading`].
//! - `assemble.rs`: `glBegin`/`glEnd` vertices into primitives.
//! - `lists.rs`: display lists, compiled, called and deleted.
//! - `capture.rs`: recording into entry space, and instancing.
//! - [`arrays`]: vertex arrays and buffer objects.
//! - `geometry.rs`: [`Geometry`] and its BVHs; `check.rs`: its checks.
//! - `recorded.rs`: [`Recorded`], cached geometry and its BVHs.
//! - `frame.rs`: [`Frame`], its [`Pass`]es and their [`FrameDraws`];
//!   `counters.rs`: [`Counters`].
//! - `matrix.rs`: the matrices of GL's matrix calls.
//! - [`texture`]: 2-D textures, their unpacking, sampling and environment.

pub mod arrays;
mod assemble;
mod capture;
mod check;
mod command;
mod counters;
mod frame;
mod geometry;
mod lighting;
mod lists;
mod matrix;
mod recorded;
mod recorder;
pub mod texture;

pub use arrays::ArrayPointer;
pub use check::{GeometryError, Primitive};
pub use command::Command;
pub use counters::Counters;
pub use frame::{Frame, FrameDraws, Instance, MAX_PASSES, Paint, Pass, View};
pub use geometry::Geometry;
pub use lighting::{Fog, LightState, Lighting, MaterialState, Shading, TextureUse, alpha_passes};
pub use lists::{LIST_BUDGET, MAX_LIST_NESTING};
pub use matrix::{frustum, normal_matrix, ortho, rotate, scale, translate};
pub use recorded::Recorded;
pub use recorder::{MAX_STACK, Recorder};
