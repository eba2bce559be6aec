//! Unstructured meshes: tetrahedra (and cells split into them) with `n`
//! linear in each, traced cell by cell in closed form
//! ([`UnstructuredField`]), or with gradients recovered at the points for
//! an integrator ([`SmoothField`]).

mod cell;
mod error;
mod field;
mod smooth;
mod trace;

pub use cell::Cell;
pub use error::MeshError;
pub use field::UnstructuredField;
pub use smooth::SmoothField;
