//! A shadeable scene of triangle meshes (coloured by a per-vertex scalar
//! or one colour), sphere glyphs and tubes along polylines, each with a
//! [`Material`](crate::Material), behind one BVH per primitive kind
//! ([`rt_accel::Scene`]): the [`ShadeScene`](crate::ShadeScene) the
//! renderer draws.
//!
//! Build one with [`SurfaceScene::builder`] (or [`SurfaceScene::from_mesh`]
//! for a single mesh); errors name the object and, for bad geometry, the
//! vertex or primitive within it.

mod builder;
mod error;
mod objects;
mod surface_scene;

pub use builder::SceneBuilder;
pub use error::SceneError;
pub use objects::{Glyphs, ObjectKind, Paint, Tube};
pub use surface_scene::SurfaceScene;
