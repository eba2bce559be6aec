//! # rt-photo
//!
//! The optical bench of computational schlieren photography: a collimated
//! beam of photons is traced along curved paths through a refractive-index
//! field (`rt-volume`); each photon's deflection `ε` meets a cutoff (knife
//! edge, graded filter, pinhole / dark field, colour filter) or, for
//! interferometry, its optical path sets a phase; it lands on a film at its
//! exit point carried a distance `L` further (shadowgraph). The film
//! gathers photons one by one ([`Reconstruction::Photons`], stratified,
//! spread by a [`Filter`]) or as a sheet ([`Reconstruction::Sheet`]: the
//! photons of a pass form a lattice whose cells carry their light onto
//! the film by exact area — no grain).
//!
//! Images are normalised to the background (1 = undisturbed, uncut) and
//! deterministic: the same seed gives the same image, bit for bit, at any
//! thread count (feature `parallel`). Beside the image the film keeps, per
//! pixel, the photons' mean deflection ([`Film::mean_deflection`]) and,
//! for interferometry, their mean phase, unwrapped ([`Film::mean_phase`]).
//! A [`Sensor`] records an image as a camera would: diffraction blur
//! ([`Airy`]), exposure, shot and read noise, full well, bit depth.
//! [`Bos`] renders background-oriented schlieren through a [`ThinLens`]
//! camera: the reference and flow images of a [`Background`] (random
//! dots, a dot grid or an image) and the ground-truth displacement, in the
//! convention of PIV/BOS software; [`BosRig::choose`] and
//! [`FocusingRig::choose`] size a laboratory rig for a flow.
//! [`FocusingSchlieren`] renders a lens-and-grid system focused on a
//! plane in the flow, which it shows sharply while the rest blurs away.
//!
//! The `rt-volume` types this crate's API takes are re-exported at the
//! root ([`IndexField`], [`GridField`], [`Octree`], [`TraceParams`], …),
//! the whole of [`rt_volume`] (analytic fields, grids, readers) beside
//! them, and [`glam`] for `DVec3`: one dependency is enough.
//!
//! ## Features
//! | feature | default | what it does |
//! |---|---|---|
//! | `std` | yes | float functions from std (here, in `rt-volume` and `rt-core`) |
//! | `libm` | no | float functions from `libm` for `no_std` builds |
//! | `parallel` | no | rows traced and films splatted with rayon (implies `std`); images stay bit-identical |
//! | `distributed` | no | [`distributed`]: a grid's photons handed between bricks on the ranks of an `rt_composite::Communicator`, equal to one process bit for bit (implies `parallel`) |
//! | `png` | no | [`BackgroundChoice::read_png`]: BOS background images from PNG files (implies `std`) |
//! | `mesh` | no | multifield colour on unstructured meshes (`SchlierenBench::render_mesh_colored`); meshes on every instrument come through `render_medium` with `rt-volume`'s `mesh` (implies `std`) |
//!
//! Without `std`, one of `std` or `libm` must be on; an allocator is always
//! needed (films and photon rows live on `alloc`).
//!
//! ## Example
//! A knife-edge schlieren image of a weak Gaussian bump of index: light
//! bends toward the higher index at the centre, so with the edge across
//! the u axis the left side brightens and the right side darkens.
//! ```
//! use rt_photo::glam::DVec3;
//! use rt_photo::rt_volume::GaussianBump;
//! use rt_photo::{SchlierenBench, Cutoff, Film, Filter, Mode, Reconstruction, TraceParams, Weighting};
//!
//! // n = 1 + 1e-4·exp(−r²/2), σ = 1, cut off beyond r = 5.
//! let field = GaussianBump::new(DVec3::ZERO, 1e-4, 1.0, 5.0);
//! let bench = SchlierenBench {
//!     center: DVec3::new(0.0, 0.0, -6.0), // the beam starts upstream
//!     direction: DVec3::Z,
//!     u: DVec3::X,
//!     width: 6.0,
//!     height: 6.0,
//!     image_plane: 6.0,   // the bump's mid-plane, z = 0
//!     film_distance: 0.0, // image it (no shadowgraph)
//!     // f/h = 1500: a deflection of 1/3000 rad changes the image by 0.5.
//!     mode: Mode::Schlieren(Cutoff::KnifeEdge { angle: 0.0, offset: 0.0, f: 1.5, h: 1e-3 }),
//!     weighting: Weighting::Weight,
//!     reconstruction: Reconstruction::Photons,
//!     strata: 4, // 4 × 4 photons per pixel
//!     params: TraceParams::accurate(),
//! };
//! let mut film = Film::new(16, 16, Filter::Tent)?;
//! bench.render(&field, &mut film, 0, 42)?;
//! let image = film.normalized(); // 0.5 = undisturbed, half cut
//! // Row 8 (through the centre): brighter left of it, darker right of it.
//! let row = &image[16 * 8..16 * 9];
//! let left = row[..8].iter().map(|p| p[0]).sum::<f32>() / 8.0;
//! let right = row[8..].iter().map(|p| p[0]).sum::<f32>() / 8.0;
//! assert!(left > 0.55 && right < 0.45, "{left} {right}");
//! # Ok::<(), Box<dyn core::error::Error>>(())
//! ```
#![no_std]

extern crate alloc;
#[cfg(feature = "std")]
extern crate std;

mod bos;
mod camera;
#[cfg(feature = "distributed")]
pub mod distributed;
mod focusing;
mod math;
mod medium;
#[cfg(feature = "mesh")]
mod mesh;
mod rows;
mod schlieren;
mod setup;
pub mod units;

#[cfg(feature = "png")]
pub use bos::PngError;
pub use bos::{
    Background, BackgroundChoice, Bos, BosError, BosImages, BosRig, BosRigOptions, DotBackground,
    DotGrid, ImageBackground,
};
pub use camera::{Airy, AiryKernel, CameraError, Sensor, SensorError, ThinLens};
pub use focusing::{
    FocusingError, FocusingImages, FocusingRig, FocusingRigOptions, FocusingSchlieren, SourceGrid,
};
pub use schlieren::{
    BatchTracer, BenchError, Cutoff, CutoffError, CutoffParam, Film, FilmError, Filter,
    FilterImage, Mode, Photon, Reconstruction, SchlierenBench, Weighting,
};
pub use setup::{
    Axis, BosOptions, BosSetup, CutoffKind, FocusingOptions, FocusingSetup, MAX_APERTURE_SAMPLES,
    MAX_CAMERA_EDGE, MAX_EDGE, MAX_PHOTONS, MAX_PHOTONS_PER_PIXEL, SchlierenOptions,
    SchlierenSetup, SetupError, Survey, lattice, traced_per_pixel,
};
// The types in this crate's signatures, from the crates below it (and
// `build_octree`, the way to a grid's `Octree`).
pub use rt_core::ColorMap;
#[cfg(feature = "mesh")]
pub use rt_volume::{Cell, MeshError, SmoothField, UnstructuredField};
pub use rt_volume::{
    GridField, GridMedium, IndexField, Medium, MediumError, MeshTrace, Octree, Samples, TraceError,
    TraceParams, TraceResult, build_octree,
};

/// The whole of `rt-volume`: analytic and gridded fields, integrators,
/// octree skipping, readers (feature `io` of `rt-volume`).
pub use rt_volume;
/// The `glam` of `rt-volume` and `rt-core` (`DVec3` for beams).
pub use rt_volume::glam;

/// The crate README's example, compiled and run as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
struct ReadmeDoctests;
