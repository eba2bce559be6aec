//! rt's GPU backend: photons traced through a gridded refractive index in
//! a compute shader ([wgpu], WGSL), on whatever Vulkan, Metal or DX12
//! driver the machine has — a discrete GPU, or Mesa's software Vulkan
//! (lavapipe), which is how the tests run without one.
//!
//! - [`Gpu`]: an adapter and its device; [`GpuError::NoAdapter`] where
//!   there is none (so a caller falls back to the CPU).
//! - [`GridTracer`]: a grid uploaded once, and batches of photons traced
//!   through it with the CPU's default scheme for grids (leapfrog,
//!   kick–drift–kick, one cell a step), landing on the face it leaves
//!   by. [`Exit`] gives the exit point, the deflection `T − n₀·d` (kept
//!   apart from `n₀·d` in f32, so a weak deflection keeps its bits) and
//!   the optical path.
//! - [`GridTracer::schlieren_pass`]: a pass of rt-photo's schlieren bench
//!   (any cutoff, shadowgraph, interferometry; splatted photons or the
//!   sheet) with its photons traced here, cut and splatted on the host by
//!   the bench's own code (`SchlierenBench::render_batched`).
//!
//! Accuracy: the shader works in f32 on coordinates relative to the box's
//! corner; `tests/against_cpu.rs` bounds its deflections against the f64
//! CPU tracer (`rt_volume::trace` with `TraceParams::for_grid`) and the
//! Gaussian bump's exact deflection. The same photons give the same exits
//! on the same device, bit for bit (each photon is one invocation, with
//! no shared sums).

mod device;
mod error;
mod gpu;
mod photons;
mod schlieren;

pub use device::{Chosen, Device, choose, render_schlieren, unsupported};
pub use error::GpuError;
pub use gpu::{Gpu, quiet_without_session};
pub use photons::{Exit, ExitStatus, GridTracer, Photon, TraceSettings};

/// The README's example, compiled as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
