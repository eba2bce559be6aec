//! Unstructured meshes: tetrahedra (and cells split into them) with `n`
//! linear in each, traced cell by cell in closed form.

mod cell;
mod error;

pub use cell::Cell;
pub use error::MeshError;
mod field;
mod trace;

pub use field::UnstructuredField;
