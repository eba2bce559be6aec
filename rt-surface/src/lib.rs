//! # rt-surface
//!
//! Ray-traced surfaces for scientific visualization: triangle meshes
//! coloured by a per-vertex scalar (interpolated across each triangle,
//! then colour-mapped), sphere glyphs and tubes along polylines, shaded
//! with Blinn–Phong under ambient, directional and point lights, with hard
//! shadows, ambient occlusion, mirror reflections and transparency, on
//! all cores, the same image bit for bit at any thread count.
//!
//! - [`SurfaceScene`]: the objects behind one `rt-accel` BVH per primitive
//!   kind; moved vertices refit, new topology rebuilds.
//! - [`Renderer`]: progressive passes over any [`ShadeScene`] (implement
//!   it to draw your own geometry), into an [`rt_core::Frame`] of
//!   premultiplied colour and depth, ready for sort-last compositing.
//! - [`io`] (feature `io`): OBJ, PLY (with every per-vertex scalar) and VTK
//!   polydata readers; a PLY writer.
//!
//! Work a scene does not need is not done: no shadow rays without lights,
//! no AO rays with AO off, no reflection rays without mirrors, no
//! traversal for rays that miss the scene's box; [`RayCounts`] shows it.
//!
//! ## Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | std float functions; [`SurfaceScene`] (building BVHs needs std) |
//! | `libm` | no | float functions from `libm` for `no_std` (the renderer over your own [`ShadeScene`], [`Mesh`], materials) |
//! | `parallel` | no | [`Renderer`] renders 16 × 16 tiles on rayon; frames stay bit-identical |
//! | `io` | no | [`io`]: mesh readers (OBJ, PLY, VTK) and a PLY writer |
//!
//! ## Example
//! ```
//! use rt_surface::{
//!     Light, Mesh, Paint, Renderer, Settings, SurfaceScene,
//!     rt_core::{Camera, ColorMap, Projection, glam::Vec3},
//! };
//!
//! // A triangle coloured by a scalar that rises from 0 to 1 across it.
//! let mesh = Mesh::new(
//!     vec![Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, -1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
//!     vec![[0, 1, 2]],
//!     Some(vec![0.0, 0.5, 1.0]),
//! )?;
//! let scene = SurfaceScene::from_mesh(mesh, Paint::Mapped(ColorMap::viridis()))?;
//! let camera = Camera::look_at(
//!     Vec3::new(0.0, 0.0, 3.0),
//!     Vec3::ZERO,
//!     Vec3::Y,
//!     Projection::Perspective { fov_y: 0.8 },
//!     64,
//!     48,
//! )?;
//! let settings = Settings { lights: vec![Light::Ambient { color: [1.0; 3] }], ..Settings::default() };
//! let mut renderer = Renderer::new(camera, settings)?;
//! renderer.render_pass(&scene);
//! let frame = renderer.frame()?;
//! let centre = frame.get(32, 24).unwrap();
//! assert!((centre.depth - 3.0).abs() < 1e-3); // the triangle, straight ahead
//! assert_eq!(centre.color[3], 1.0); // opaque
//! assert_eq!(frame.get(0, 0).unwrap().depth, f32::INFINITY); // background
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![no_std]

extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

#[cfg(feature = "std")]
pub mod cast;
#[cfg(feature = "io")]
pub mod io;
mod math;
mod mesh;
pub mod render;
#[cfg(feature = "std")]
pub mod scene;

#[cfg(feature = "std")]
pub use cast::RayCaster;
pub use mesh::{Mesh, MeshError};
#[cfg(feature = "std")]
pub use render::{AnswerCountError, AnsweredOcclusion, RecordOcclusion};
pub use render::{
    Light, Material, MaterialError, RayCounts, RenderError, Renderer, Settings, SettingsError,
    ShadeScene, Surface,
};
pub use rt_accel;
pub use rt_core;
#[cfg(feature = "std")]
pub use scene::{Glyphs, ObjectKind, Paint, SceneBuilder, SceneError, SurfaceScene, Tube};

/// The crate README's example, compiled and run as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
