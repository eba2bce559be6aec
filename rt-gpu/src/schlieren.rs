//! The schlieren bench's passes with their photons traced on the GPU: the
//! bench lists a pass's photons, the device traces them in one batch, and
//! the bench cuts, lands and splats them with its own code, so nothing of
//! the optics is written twice.

use glam::DVec3;
use rt_photo::{Film, SchlierenBench};
use rt_volume::{Exit as CpuExit, Method, TraceError, TraceResult, TraceStats};

use crate::{Exit, ExitStatus, GpuError, GridTracer, Photon, TraceSettings};

impl GridTracer<'_> {
    /// Adds pass `pass` of `bench` to `film`, as
    /// [`SchlierenBench::render`] does, with the photons traced on the
    /// device (the bench's step and step limit; its scheme must be the
    /// leapfrog, [`Method::Symplectic`], the CPU's default for grids).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] for another scheme, [`GpuError::Bench`]
    /// for the bench's own refusals, the device's errors as in
    /// [`GridTracer::trace`]; the film is unchanged then.
    pub fn schlieren_pass(
        &self,
        bench: &SchlierenBench,
        film: &mut Film,
        pass: u64,
        seed: u64,
    ) -> Result<(), GpuError> {
        if bench.params.method != Method::Symplectic {
            return Err(GpuError::Unsupported("only the leapfrog scheme runs on the GPU"));
        }
        let settings = TraceSettings { step: bench.params.step, max_steps: bench.params.max_steps };
        let mut failed = None;
        let mut batch = |rays: &[(DVec3, DVec3)]| {
            let photons: Vec<Photon> =
                rays.iter().map(|&(origin, direction)| Photon { origin, direction }).collect();
            match self.trace(&photons, &settings) {
                Ok(exits) => Ok(exits.iter().map(as_trace).collect()),
                Err(e) => {
                    failed = Some(e);
                    Err(TraceError::InvalidRay)
                }
            }
        };
        let done = bench.render_batched(&mut batch, film, pass, seed);
        match failed {
            Some(e) => Err(e),
            None => done.map_err(GpuError::Bench),
        }
    }
}

/// An exit as the CPU's trace would report it.
fn as_trace(e: &Exit) -> TraceResult {
    TraceResult {
        position: e.position,
        direction: e.direction,
        optical_path: e.optical_path,
        exit: match e.status {
            ExitStatus::Missed => CpuExit::Missed,
            ExitStatus::Left => CpuExit::Left,
            ExitStatus::OutOfSteps => CpuExit::MaxSteps,
        },
        stats: TraceStats { steps: e.steps, field_evals: e.steps + 1, ..TraceStats::default() },
    }
}
