//! Exact ray–primitive intersection tests, one file per primitive.
//!
//! Each test returns the ray parameter first (`*_t` functions, cheap, used
//! inside traversal) and builds the full [`crate::Hit`] only for the closest
//! hit. All of them return `None` for rays that fail [`crate::Ray::is_valid`].

mod capsule;
mod offset;
mod sphere;
pub(crate) mod triangle;

pub use capsule::{Capsule, intersect_capsule, intersect_capsule_t};
pub use offset::{next_float_down, next_float_up, offset_ray_origin, spawn_ray, spawn_ray_to};
pub use sphere::{Sphere, intersect_sphere, intersect_sphere_t, solve_quadratic};
pub use triangle::{
    TriangleHit, WatertightRay, intersect_triangle, intersect_triangle_t, is_degenerate_triangle,
    triangle_barycentrics, triangle_hit,
};
