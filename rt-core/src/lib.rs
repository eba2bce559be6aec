//! # rt-core
//!
//! The base of the `rt` ray-tracing crates for scientific visualization:
//! rays, boxes, cameras, exact and robust ray–primitive intersection tests,
//! frames of premultiplied colour plus depth, colour maps and seeded
//! sampling. It knows nothing of acceleration structures: shading code is
//! written against [`SceneQuery`], which `rt-accel` implements; the
//! renderer that uses it lives in `rt-surface`.
//!
//! ## Conventions
//! - Right-handed coordinates; angles in radians.
//! - Colours are linear RGB; frame colours are premultiplied by alpha.
//! - Depth is the ray parameter `t` of the visible surface (`+∞` for
//!   background). Cameras emit unit directions, so depth is a distance.
//! - A miss is `None`; bad input is an `Err` with a small error enum;
//!   misuse by the programmer panics and is documented under `# Panics`.
//!
//! ## Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | float functions from std; implies `alloc` |
//! | `alloc` | via `std` | [`Frame`] (owned pixel storage) |
//! | `libm` | no | float functions from `libm` for `no_std` builds |
//!
//! Everything else (intersections, cameras, colour maps, sampling) needs
//! neither std nor an allocator.
//!
//! ## Example
//! ```
//! use rt_core::{Ray, intersect::{Sphere, intersect_sphere}};
//! use glam::Vec3;
//!
//! let ray = Ray::new(Vec3::new(0.0, 0.0, 5.0), Vec3::NEG_Z);
//! let hit = intersect_sphere(&ray, &Sphere::new(Vec3::ZERO, 1.0), 0).unwrap();
//! assert_eq!(hit.t, 4.0);
//! assert_eq!(hit.normal, Vec3::Z);
//! ```
#![no_std]

#[cfg(feature = "alloc")]
extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod aabb;
pub mod camera;
pub mod colormap;
#[cfg(feature = "alloc")]
pub mod frame;
mod hit;
pub mod intersect;
mod math;
mod ray;
pub mod sampling;
pub mod srgb;

pub use aabb::Aabb;
pub use camera::{Camera, CameraError, Projection};
pub use colormap::{ColorMap, ColorMapError, ColorStop};
#[cfg(feature = "alloc")]
pub use frame::{Frame, FrameError, Pixel};
pub use hit::{Hit, PrimKind, SceneQuery};
pub use intersect::{offset_ray_origin, spawn_ray, spawn_ray_to};
pub use math::gamma;
pub use ray::Ray;

pub use glam;

/// What `rt-accel`'s SIMD kernels share with the scalar tests here, so that
/// both round the same way and a BVH answers bit for bit like a brute-force
/// loop. Not part of the documented API: it may change in any release.
#[doc(hidden)]
pub mod internal {
    pub use crate::{
        aabb::{FAR_INV_SCALE, SLAB_FAR_SCALE, SLAB_FAR_SCALE_NEG, widen_far},
        intersect::triangle::{settle_triangle_t, triangle_admits_hit},
    };
}

/// The crate README's example, compiled and run as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
