//! The options `rt schlieren`, `rt bos`, `rt focusing`, `rt info` and
//! `rt distributed` share, as clap arguments mapped onto the library's
//! (`rt_volume::MediumOptions`, `rt_photo::Axis`), and opening a file as
//! a medium with the command line's hints on errors.

use std::path::Path;

use clap::ValueEnum;
use rt_photo::SetupError;
use rt_volume::{Interp, Medium, MediumError, MediumOptions};

/// What the volume's samples are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Quantity {
    /// Gas density in kg/m³, mapped to index by Gladstone–Dale
    /// `n = 1 + K·ρ`.
    Density,
    /// Refractive index itself.
    Index,
}

/// What a volume's samples are, as `rt schlieren` and `rt info` take it.
#[derive(Clone, Copy, Debug, clap::Args)]
pub struct Samples {
    /// What the samples are.
    #[arg(long, value_enum, default_value_t = Quantity::Density)]
    pub quantity: Quantity,
    /// Gladstone–Dale constant K in m³/kg (n = 1 + K·ρ; air at 589 nm).
    // Written out (2.26e-4, the constant's value: a test holds them
    // equal), as clap would print 0.000226.
    #[arg(long, default_value = "2.26e-4", value_parser = crate::parse::positive, allow_hyphen_values = true)]
    pub k: f64,
}

impl From<Samples> for rt_volume::Samples {
    fn from(s: Samples) -> Self {
        match s.quantity {
            Quantity::Density => Self::Density { gladstone_dale: s.k },
            Quantity::Index => Self::Index,
        }
    }
}

/// Where the photons are traced.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum DeviceArg {
    /// The CPU's cores (f64; the same image on every machine).
    #[default]
    Cpu,
    /// The GPU (any Vulkan, Metal or DX12 driver; f32, within 1e-5 rms of
    /// the CPU's image): grids with `--interp linear` only.
    Gpu,
    /// The GPU where there is one and it traces the volume, else the CPU;
    /// the choice is printed.
    Auto,
}

impl From<DeviceArg> for rt_gpu::Device {
    fn from(d: DeviceArg) -> Self {
        match d {
            DeviceArg::Cpu => Self::Cpu,
            DeviceArg::Gpu => Self::Gpu,
            DeviceArg::Auto => Self::Auto,
        }
    }
}

/// How the field is interpolated between samples. Both take the fast
/// path: the octree bounds either interpolant (rt-volume's `skip`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Interpolation {
    /// Trilinear: the gradient jumps at cell faces (a shadowgraph, which
    /// sees its derivative, shows the grid); the tightest skip bound and
    /// about twice as fast.
    Linear,
    /// Catmull–Rom tricubic (the default): C¹, smooth shadowgraphs and
    /// edges; its gradient bound is 2.3× looser, so somewhat less is
    /// skipped.
    Cubic,
}

impl From<Interpolation> for Interp {
    fn from(i: Interpolation) -> Self {
        match i {
            Interpolation::Linear => Self::Trilinear,
            Interpolation::Cubic => Self::CatmullRom,
        }
    }
}

/// The axis the beam travels along.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Axis {
    /// Along +x (image axes y, z).
    X,
    /// Along +y (image axes z, x).
    Y,
    /// Along +z (image axes x, y).
    Z,
}

impl From<Axis> for rt_photo::Axis {
    fn from(a: Axis) -> Self {
        match a {
            Axis::X => Self::X,
            Axis::Y => Self::Y,
            Axis::Z => Self::Z,
        }
    }
}

/// How an unstructured mesh is traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MeshTrace {
    /// Exactly through the data's piecewise-linear interpolant (cells
    /// split into tetrahedra about their face and cell centres), cell by
    /// cell in closed form (a single ray's deflection is first order in
    /// the cell size; coarse cells show as facets).
    Exact,
    /// Gradients recovered at the points and interpolated on the same
    /// tetrahedra, RK4 at half an edge: second order per ray and no facets
    /// (`rt-report unstructured`, 64 cells a side: 4.5× less error than
    /// `exact` in about two thirds of its time). The default: it reaches a
    /// given error sooner.
    Smooth,
}

/// How `rt schlieren`, `rt bos` and `rt focusing` read an unstructured mesh.
#[derive(Clone, Debug, clap::Args)]
pub struct MeshOptions {
    /// The point- or cell-data array of an unstructured mesh to read
    /// (default: its first scalar point array, else its first scalar cell
    /// array, averaged to the points).
    #[arg(long)]
    pub array: Option<String>,
    /// How an unstructured mesh is traced.
    #[arg(long, value_enum, default_value_t = MeshTrace::Smooth)]
    pub mesh: MeshTrace,
}

/// Reads `file` as a medium: a mesh as `mesh` says, a grid interpolated
/// as `interp`, the values as `samples`.
///
/// # Errors
/// An unreadable file; values that make no medium (with the options that
/// would fix a non-physical one).
pub fn open(
    file: &Path,
    samples: Samples,
    allow_nonphysical: bool,
    interp: Interpolation,
    mesh: &MeshOptions,
) -> anyhow::Result<Medium> {
    let options = MediumOptions {
        samples: samples.into(),
        allow_nonphysical,
        interp: interp.into(),
        mesh: match mesh.mesh {
            MeshTrace::Exact => rt_volume::MeshTrace::Exact,
            MeshTrace::Smooth => rt_volume::MeshTrace::Smooth,
        },
        array: mesh.array.clone(),
    };
    Medium::open(file, &options).map_err(|e| match &e {
        MediumError::InFile { source, .. }
            if matches!(**source, MediumError::NonPhysical { .. }) =>
        {
            anyhow::anyhow!("{e}; check --quantity, or pass --allow-nonphysical")
        }
        _ => e.into(),
    })
}

/// A set-up error with the options that would fix it.
pub(crate) fn hint(e: SetupError) -> anyhow::Error {
    match e {
        SetupError::TooManyPhotons { .. } => anyhow::anyhow!("{e}; lower --size or --photons"),
        e => e.into(),
    }
}

#[cfg(test)]
mod tests {
    use rt_volume::GLADSTONE_DALE_AIR;

    /// `--k`'s default is written out for `--help`; it is the constant.
    #[test]
    fn the_gladstone_dale_default_is_the_constant() {
        let a: crate::schlieren::Args =
            crate::parse::subcommand("schlieren", std::path::Path::new("v"), [""; 0]).unwrap();
        assert_eq!(a.samples.k, GLADSTONE_DALE_AIR);
    }
}
