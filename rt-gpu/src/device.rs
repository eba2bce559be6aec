//! Which device traces a render: the choice the front ends offer as
//! `--device` / `device=`, made here so they all choose alike.

use rt_photo::{Film, SchlierenSetup, SetupError};
use rt_volume::{Interp, Medium, Method};

use crate::{Gpu, GpuError, GridTracer};

/// Where the photons are traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Device {
    /// On the CPU's cores (f64; the same image on every machine).
    #[default]
    Cpu,
    /// On the GPU: an error where there is none or the medium is not one it
    /// traces.
    Gpu,
    /// On the GPU where there is one and it traces the medium, else on the
    /// CPU.
    Auto,
}

impl Device {
    /// `"cpu"`, `"gpu"` or `"auto"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Cpu => "cpu",
            Self::Gpu => "gpu",
            Self::Auto => "auto",
        }
    }
}

/// The device a render runs on, and why.
#[derive(Debug)]
pub enum Chosen {
    /// The CPU, and why (`"asked for"`, or why not the GPU).
    Cpu(String),
    /// This GPU (boxed: a device handle is large beside a reason).
    Gpu(Box<Gpu>),
}

impl Chosen {
    /// One line for the user: `gpu (NVIDIA H100)`, `cpu (asked for)`,
    /// `cpu (no GPU adapter found …)`.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::Cpu(why) => format!("cpu ({why})"),
            Self::Gpu(g) if g.is_software() => format!("gpu ({}, a software driver)", g.name()),
            Self::Gpu(g) => format!("gpu ({})", g.name()),
        }
    }
}

/// Why the GPU does not trace `medium`, if it does not: it traces grids
/// with the trilinear interpolant and the leapfrog scheme.
#[must_use]
pub fn unsupported(medium: &Medium) -> Option<&'static str> {
    match medium {
        Medium::Grid(g) if g.field().interp() != Interp::Trilinear => {
            Some("the GPU traces the trilinear interpolant only (--interp linear)")
        }
        Medium::Grid(_) if medium.params().method != Method::Symplectic => {
            Some("the GPU traces the leapfrog scheme only")
        }
        Medium::Grid(_) => None,
        _ => Some("the GPU traces grids only, not meshes"),
    }
}

/// The device for a render of `medium` as `device` asks.
///
/// # Errors
/// For [`Device::Gpu`]: [`GpuError::Unsupported`] for a medium the GPU
/// does not trace, and [`Gpu::new`]'s errors.
pub fn choose(device: Device, medium: &Medium) -> Result<Chosen, GpuError> {
    match device {
        Device::Cpu => Ok(Chosen::Cpu("asked for".into())),
        Device::Gpu => match unsupported(medium) {
            Some(why) => Err(GpuError::Unsupported(why)),
            None => Gpu::new().map(|g| Chosen::Gpu(Box::new(g))),
        },
        Device::Auto => Ok(match unsupported(medium) {
            Some(why) => Chosen::Cpu(why.into()),
            None => match Gpu::new() {
                Ok(g) => Chosen::Gpu(Box::new(g)),
                Err(e) => Chosen::Cpu(e.to_string()),
            },
        }),
    }
}

/// [`SchlierenSetup::render`] with its photons traced on `gpu`: the same
/// passes, optics and film. `stop` is asked before each pass.
///
/// # Errors
/// [`GpuError::Unsupported`] for a medium the GPU does not trace,
/// [`GpuError::Stopped`] once `stop` says so; the device's and the
/// bench's errors.
pub fn render_schlieren(
    gpu: &Gpu,
    setup: &SchlierenSetup,
    medium: &Medium,
    seed: u64,
    progress: &mut dyn FnMut(u64, u64),
    stop: &dyn Fn() -> bool,
) -> Result<Film, GpuError> {
    if let Some(why) = unsupported(medium) {
        return Err(GpuError::Unsupported(why));
    }
    let Medium::Grid(grid) = medium else { return Err(GpuError::Unsupported("grids only")) };
    let tracer = GridTracer::new(gpu, grid.field())?;
    let mut failed = None;
    let film = setup.render_passes(progress, &mut |bench, film, pass| {
        if stop() {
            failed = Some(GpuError::Stopped);
            return Err(SetupError::Stopped);
        }
        tracer.schlieren_pass(bench, film, pass, seed).map_err(|e| {
            let out = match &e {
                GpuError::Bench(b) => SetupError::SchlierenBench(*b),
                _ => SetupError::Stopped,
            };
            failed = Some(e);
            out
        })
    });
    match (film, failed) {
        (_, Some(e)) => Err(e),
        (Ok(f), None) => Ok(f),
        (Err(e), None) => Err(GpuError::Setup(e.to_string())),
    }
}
