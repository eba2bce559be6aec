//! Unstructured meshes on every optical system (feature `mesh`): photons
//! traced cell by cell in closed form through an
//! [`UnstructuredField`] ([`UnstructuredField::trace`]), so a mesh renders
//! like a grid — knife edge, shadowgraph, interferometry, colour, BOS and
//! focusing schlieren — with no integration step to choose.

use glam::DVec3;
use rt_core::ColorMap;
use rt_volume::UnstructuredField;

use crate::{
    Bench, BenchError, Bos, BosError, BosImages, Film, FocusingError, FocusingImages,
    FocusingSchlieren,
};

impl Bench {
    /// [`Bench::render`] for an unstructured mesh: each photon is traced
    /// exactly through the mesh's piecewise-linear index
    /// ([`UnstructuredField::trace`]); [`Bench::params`] is not used.
    ///
    /// # Errors
    /// As [`Bench::render`].
    pub fn render_mesh(
        &self,
        field: &UnstructuredField,
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        self.render_with(&|o, d| field.trace(o, d), film, pass, seed)
    }

    /// [`Bench::render_colored`] for an unstructured mesh: `s̄` is the mean
    /// of `scalar` at the points where the photon leaves each cell.
    ///
    /// # Errors
    /// As [`Bench::render`].
    pub fn render_mesh_colored(
        &self,
        field: &UnstructuredField,
        scalar: &(impl Fn(DVec3) -> f64 + Sync),
        map: &ColorMap<'_>,
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), BenchError> {
        let tracer = |o: DVec3, d: DVec3| {
            crate::schlieren::bench::mean_colour(scalar, map, |visit| {
                field.trace_visiting(o, d, visit)
            })
        };
        self.render_colored_with(&tracer, film, pass, seed)
    }
}

impl Bos {
    /// [`Bos::render`] for an unstructured mesh, traced exactly cell by
    /// cell; [`Bos::params`] is not used.
    ///
    /// # Errors
    /// As [`Bos::render`].
    pub fn render_mesh(&self, field: &UnstructuredField, seed: u64) -> Result<BosImages, BosError> {
        self.render_with(&|o, d| field.trace(o, d), seed)
    }
}

impl FocusingSchlieren {
    /// [`FocusingSchlieren::render`] for an unstructured mesh, traced
    /// exactly cell by cell; [`FocusingSchlieren::params`] is not used.
    ///
    /// # Errors
    /// As [`FocusingSchlieren::render`].
    pub fn render_mesh(
        &self,
        field: &UnstructuredField,
        seed: u64,
    ) -> Result<FocusingImages, FocusingError> {
        self.render_with(&|o, d| field.trace(o, d), seed)
    }
}
