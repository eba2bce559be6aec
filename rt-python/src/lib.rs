//! `rtvis._rtvis`: the native half of the Python package `rtvis`.
//!
//! The Python half (`python/rtvis/__init__.py`) holds the documented API:
//! it checks and converts arguments (dtypes, shapes, option names) and
//! calls the functions here with exactly typed values. These functions
//! check again what the rt crates would otherwise refuse or misread
//! (shapes, index ranges, finiteness), release the GIL while they render
//! and turn every error into a Python exception; nothing here panics on
//! user data, and a panic would surface as Python's `PanicException`, not
//! an abort.

mod bricks;
mod cast;
mod composite;
mod optics;
mod surface;
mod volume;
mod watch;

use pyo3::{exceptions::PyValueError, prelude::*};

/// A `ValueError` carrying `e`'s message.
pub(crate) fn value_error(e: impl core::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{e:#}"))
}

/// The native module.
#[pymodule]
fn _rtvis(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<volume::PyVolume>()?;
    m.add_function(wrap_pyfunction!(volume::read_volume, m)?)?;
    m.add_function(wrap_pyfunction!(volume::read_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(optics::optics, m)?)?;
    m.add_function(wrap_pyfunction!(optics::record, m)?)?;
    m.add_function(wrap_pyfunction!(optics::bos, m)?)?;
    m.add_function(wrap_pyfunction!(optics::focusing, m)?)?;
    m.add_class::<surface::PyScene>()?;
    m.add_class::<cast::PyRayMesh>()?;
    m.add_function(wrap_pyfunction!(composite::composite, m)?)?;
    m.add_function(wrap_pyfunction!(composite::composite_comm, m)?)?;
    m.add_function(wrap_pyfunction!(bricks::brick_box, m)?)?;
    m.add_function(wrap_pyfunction!(bricks::schlieren_piece, m)?)?;
    m.add_function(wrap_pyfunction!(bricks::bos_piece, m)?)?;
    m.add_function(wrap_pyfunction!(bricks::focusing_piece, m)?)?;
    m.add("GLADSTONE_DALE_AIR", rt_volume::GLADSTONE_DALE_AIR)?;
    Ok(())
}
