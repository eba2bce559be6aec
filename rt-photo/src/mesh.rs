//! Multifield colouring on unstructured meshes (feature `mesh`): photons
//! traced cell by cell in closed form through an [`UnstructuredField`],
//! carrying the colour of a second field. Meshes on every instrument go
//! through `render_medium` (`rt_volume::Medium`).

use glam::DVec3;
use rt_core::ColorMap;
use rt_volume::UnstructuredField;

use crate::{BenchError, Film, SchlierenBench};

impl SchlierenBench {
    /// [`SchlierenBench::render_colored`] for an unstructured mesh: `s̄` is the mean
    /// of `scalar` at the points where the photon leaves each cell.
    ///
    /// # Errors
    /// As [`SchlierenBench::render`].
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
