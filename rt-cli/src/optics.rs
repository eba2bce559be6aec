//! What `rt schlieren`, `rt demo` and `rt info` share: a volume loaded as
//! an index field on the fast path, the bench looking through it along an
//! axis, a quick survey of the deflections it will see (automatic
//! exposure), and progressive rendering with a progress bar.

use std::time::Instant;

use anyhow::{Context, bail};
use clap::ValueEnum;
use rt_photo::{
    Bench, Bos, BosImages, Cutoff, Film, Filter, FocusingImages, FocusingSchlieren, Mode, Octree,
    Reconstruction, TraceParams, Weighting, build_octree,
};
use rt_photo::{SmoothField, UnstructuredField};
use rt_volume::{
    Bounds, GLADSTONE_DALE_AIR, Grid, GridField, Interp, gladstone_dale, glam::DVec3,
    io::UnstructuredData,
};

use crate::progress;

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

impl Axis {
    /// The beam direction and the image's u axis.
    pub(crate) fn frame(self) -> (DVec3, DVec3) {
        match self {
            Self::X => (DVec3::X, DVec3::Y),
            Self::Y => (DVec3::Y, DVec3::Z),
            Self::Z => (DVec3::Z, DVec3::X),
        }
    }
}

/// A volume ready for the bench.
#[derive(Debug)]
pub struct Volume {
    /// The index field.
    pub field: GridField,
    /// Its octree, bounding the field's interpolant (the fast path).
    pub tree: Octree,
}

impl Volume {
    /// The samples `grid` holds as `quantity`, mapped to index (`k` the
    /// Gladstone–Dale constant in m³/kg). The index outside the volume is
    /// that of its first sample (a corner: undisturbed gas, usually).
    ///
    /// # Errors
    /// Non-positive densities (or indices below 1) unless
    /// `allow_nonphysical`; a grid too small for the octree.
    pub fn new(
        grid: Grid,
        quantity: Quantity,
        k: f64,
        allow_nonphysical: bool,
        interp: Interpolation,
    ) -> anyhow::Result<Self> {
        let lowest = grid.data().iter().copied().fold(f32::INFINITY, f32::min);
        let (bad, what) = match quantity {
            Quantity::Density => (lowest <= 0.0, "density ≤ 0 kg/m³"),
            Quantity::Index => (lowest < 1.0, "index below 1"),
        };
        if bad && !allow_nonphysical {
            bail!(
                "the volume holds a {what} (lowest sample {lowest}); check --quantity, or pass --allow-nonphysical"
            );
        }
        let grid = match quantity {
            Quantity::Density => {
                if !(k.is_finite() && k > 0.0) {
                    bail!("the Gladstone–Dale constant must be finite and > 0 (got {k})");
                }
                grid.map(|rho| gladstone_dale(f64::from(rho), k) as f32)?
            }
            Quantity::Index => grid,
        };
        let ambient = grid.data().first().map_or(1.0, |&n| f64::from(n));
        let interp = match interp {
            Interpolation::Linear => Interp::Trilinear,
            Interpolation::Cubic => Interp::CatmullRom,
        };
        let field = GridField::new(grid, interp, ambient)?;
        let tree = build_octree(&field).context("building the octree")?;
        Ok(Self { field, tree })
    }

    /// The volume as density with the air's Gladstone–Dale constant,
    /// interpolated as `interp`.
    ///
    /// # Errors
    /// As [`Volume::new`].
    pub fn density(grid: Grid, interp: Interpolation) -> anyhow::Result<Self> {
        Self::new(grid, Quantity::Density, GLADSTONE_DALE_AIR, false, interp)
    }

    /// The trace settings for a grid: leapfrog with steps of two cells,
    /// the report's `rt-2voxel` setting, which reaches the same image error
    /// as one-cell steps in less time (`rt-report schlieren`).
    fn grid_params(&self) -> TraceParams {
        let base = TraceParams::for_grid(&self.field);
        TraceParams { step: 2.0 * base.step, max_step: 2.0 * base.max_step, ..base }
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

impl Default for MeshOptions {
    fn default() -> Self {
        Self { array: None, mesh: MeshTrace::Smooth }
    }
}

impl MeshOptions {
    /// Reads the mesh `file` and maps its values as `samples` says.
    ///
    /// # Errors
    /// An unreadable file, non-physical values unless `allow_nonphysical`,
    /// a bad mesh; each naming the file.
    pub fn load(
        &self,
        file: &std::path::Path,
        samples: Samples,
        allow_nonphysical: bool,
    ) -> anyhow::Result<MeshVolume> {
        let data = rt_volume::io::read_unstructured(file, self.array.as_deref())?;
        MeshVolume::new(data, samples.quantity, samples.k, allow_nonphysical, self.mesh)
            .with_context(|| file.display().to_string())
    }
}

/// A volume read from an unstructured mesh (`.vtu`, or a legacy `.vtk`
/// unstructured grid).
#[derive(Debug)]
pub enum MeshVolume {
    /// Traced exactly cell by cell.
    Exact(UnstructuredField),
    /// With recovered gradients, integrated.
    Smooth(SmoothField),
}

impl MeshVolume {
    /// The mesh `data` holds as `quantity`, mapped to index as
    /// [`Volume::new`] maps a grid's samples; the index outside is that
    /// of its first point.
    ///
    /// # Errors
    /// Non-physical values unless `allow_nonphysical`; a bad mesh.
    pub fn new(
        data: UnstructuredData,
        quantity: Quantity,
        k: f64,
        allow_nonphysical: bool,
        how: MeshTrace,
    ) -> anyhow::Result<Self> {
        let lowest = data.values.iter().copied().fold(f64::INFINITY, f64::min);
        let (bad, what) = match quantity {
            Quantity::Density => (lowest <= 0.0, "density ≤ 0 kg/m³"),
            Quantity::Index => (lowest < 1.0, "index below 1"),
        };
        if bad && !allow_nonphysical {
            bail!(
                "the mesh holds a {what} (lowest value {lowest} in array {:?}); check --quantity, or pass --allow-nonphysical",
                data.array
            );
        }
        if quantity == Quantity::Density && !(k.is_finite() && k > 0.0) {
            bail!("the Gladstone–Dale constant must be finite and > 0 (got {k})");
        }
        let index: Vec<f64> = match quantity {
            Quantity::Density => data.values.iter().map(|&rho| gladstone_dale(rho, k)).collect(),
            Quantity::Index => data.values,
        };
        let ambient = index.first().copied().unwrap_or(1.0);
        let field = UnstructuredField::new(data.points, &data.cells, index, ambient)?;
        Ok(match how {
            MeshTrace::Exact => Self::Exact(field),
            MeshTrace::Smooth => Self::Smooth(SmoothField::new(field)),
        })
    }

    /// The mesh.
    #[must_use]
    pub fn mesh(&self) -> &UnstructuredField {
        match self {
            Self::Exact(f) => f,
            Self::Smooth(s) => s.mesh(),
        }
    }
}

/// A bench looking through the box `b` along `axis` (what
/// [`Source::bench`] builds): the beam covers the box's cross-section and
/// starts upstream of it; the optics image the box's mid-plane, the film
/// sits `film_distance` behind it (negative: in front).
#[must_use]
pub fn bench_through(
    b: Bounds,
    axis: Axis,
    mode: Mode,
    film_distance: f64,
    params: TraceParams,
) -> Bench {
    let (direction, u) = axis.frame();
    let v = direction.cross(u);
    let ext = b.max - b.min;
    let upstream = 0.5 * ext.dot(direction) + 0.1 * ext.length();
    Bench {
        center: 0.5 * (b.min + b.max) - upstream * direction,
        image_plane: upstream,
        direction,
        u,
        width: ext.dot(u),
        height: ext.dot(v),
        film_distance,
        mode,
        weighting: Weighting::Weight,
        reconstruction: Reconstruction::Sheet,
        strata: 1,
        params,
    }
}

/// What the bench looks through: a gridded [`Volume`] or a [`MeshVolume`].
pub trait Source {
    /// The box the field fills.
    fn bounds(&self) -> Bounds;
    /// The undisturbed index (interferometry's reference).
    fn n_ref(&self) -> f64;
    /// The trace settings the bench carries.
    fn params(&self) -> TraceParams;
    /// One pass of `bench` onto `film` on the field's fast path.
    ///
    /// # Errors
    /// A failing trace.
    fn pass(&self, bench: &Bench, film: &mut Film, pass: u64, seed: u64) -> anyhow::Result<()>;
    /// One pass tracing every step (no skipping), for surveys.
    ///
    /// # Errors
    /// A failing trace.
    fn probe(&self, bench: &Bench, film: &mut Film) -> anyhow::Result<()>;
    /// The BOS images of `bos` on the field's fast path.
    ///
    /// # Errors
    /// A failing trace or a bad set-up.
    fn bos(&self, bos: &Bos, seed: u64) -> anyhow::Result<BosImages>;
    /// The focusing-schlieren images of `fs` on the field's fast path.
    ///
    /// # Errors
    /// A failing trace or a bad set-up.
    fn focusing(&self, fs: &FocusingSchlieren, seed: u64) -> anyhow::Result<FocusingImages>;

    /// A bench looking through the whole volume along `axis`: the beam
    /// covers the box's cross-section and starts upstream of it; the optics
    /// image the volume's mid-plane, the film sits `film_distance` behind
    /// it (negative: in front). Mode and film distance are the caller's.
    #[must_use]
    fn bench(&self, axis: Axis, mode: Mode, film_distance: f64) -> Bench {
        bench_through(self.bounds(), axis, mode, film_distance, self.params())
    }

    /// Renders `photons` photons per pixel (rounded up to whole passes of
    /// `strata²`) onto a `width`-wide film, with a progress bar; returns
    /// the film and the seconds it took.
    ///
    /// # Errors
    /// A film too large, or a failing trace.
    fn render(
        &self,
        bench: &Bench,
        width: usize,
        photons: u32,
        seed: u64,
    ) -> anyhow::Result<(Film, f64)> {
        let height = ((width as f64) * bench.height / bench.width).round().max(1.0) as usize;
        let mut film = Film::new(width, height, Filter::Tent)?;
        let (strata, passes) = lattice(photons);
        let bench = Bench { strata, ..bench.clone() };
        let per_pass = (width * height) as u64 * u64::from(strata * strata);
        let bar = progress::bar(per_pass * passes, "photons");
        let t = Instant::now();
        for pass in 0..passes {
            self.pass(&bench, &mut film, pass, seed)?;
            bar.inc(per_pass);
        }
        bar.finish_and_clear();
        Ok((film, t.elapsed().as_secs_f64()))
    }

    /// The deflections the bench will see: one photon per pixel of a
    /// coarse film, no cutoff, the mean deflection per pixel, traced
    /// without skipping (so weak flows are measured too).
    ///
    /// # Errors
    /// As [`Volume::render`].
    fn survey(&self, bench: &Bench) -> anyhow::Result<Survey> {
        self.survey_at(bench, 96)
    }

    /// [`Source::survey`] on a film `width` pixels wide: finer shows the
    /// peaks a coarse film's pixel means smooth away (a colour filter's
    /// rim must clear them).
    ///
    /// # Errors
    /// As [`Source::survey`].
    fn survey_at(&self, bench: &Bench, width: usize) -> anyhow::Result<Survey> {
        let width = width.max(1);
        let height = ((width as f64) * bench.height / bench.width).round().clamp(1.0, 4096.0);
        let mut film = Film::new(width, height as usize, Filter::Box)?;
        let probe =
            Bench { mode: Mode::Schlieren(Cutoff::None), film_distance: 0.0, ..bench.clone() };
        // Every step traced, no octree skipping: a bench without cutoff
        // and with the film in the image plane cannot see deflections, so
        // its skipping tolerance (1e-3 rad) would hide every deflection
        // below it, i.e. all of a weak flow's. 96 photons a row: cheap.
        self.probe(&probe, &mut film)?;
        Ok(Survey {
            eps: film.mean_deflection(),
            width,
            pixel: (bench.width / width as f64, bench.height / height),
        })
    }
}

/// A gridded [`Volume`] or a [`MeshVolume`], for callers that hold either
/// (the Python package's volume class).
#[derive(Debug)]
pub enum AnyVolume {
    /// A grid.
    Grid(Box<Volume>),
    /// An unstructured mesh.
    Mesh(Box<MeshVolume>),
}

impl Source for AnyVolume {
    fn bounds(&self) -> Bounds {
        match self {
            Self::Grid(v) => v.bounds(),
            Self::Mesh(m) => m.bounds(),
        }
    }
    fn n_ref(&self) -> f64 {
        match self {
            Self::Grid(v) => v.n_ref(),
            Self::Mesh(m) => m.n_ref(),
        }
    }
    fn params(&self) -> TraceParams {
        match self {
            Self::Grid(v) => v.params(),
            Self::Mesh(m) => m.params(),
        }
    }
    fn pass(&self, bench: &Bench, film: &mut Film, pass: u64, seed: u64) -> anyhow::Result<()> {
        match self {
            Self::Grid(v) => v.pass(bench, film, pass, seed),
            Self::Mesh(m) => m.pass(bench, film, pass, seed),
        }
    }
    fn probe(&self, bench: &Bench, film: &mut Film) -> anyhow::Result<()> {
        match self {
            Self::Grid(v) => v.probe(bench, film),
            Self::Mesh(m) => m.probe(bench, film),
        }
    }
    fn bos(&self, bos: &Bos, seed: u64) -> anyhow::Result<BosImages> {
        match self {
            Self::Grid(v) => v.bos(bos, seed),
            Self::Mesh(m) => m.bos(bos, seed),
        }
    }
    fn focusing(&self, fs: &FocusingSchlieren, seed: u64) -> anyhow::Result<FocusingImages> {
        match self {
            Self::Grid(v) => v.focusing(fs, seed),
            Self::Mesh(m) => m.focusing(fs, seed),
        }
    }
}

impl Source for Volume {
    fn bounds(&self) -> Bounds {
        self.field.grid().bounds()
    }
    fn n_ref(&self) -> f64 {
        self.field.grid().data().first().map_or(1.0, |&n| f64::from(n))
    }
    fn params(&self) -> TraceParams {
        self.grid_params()
    }
    fn pass(&self, bench: &Bench, film: &mut Film, pass: u64, seed: u64) -> anyhow::Result<()> {
        Ok(bench.render_grid(&self.field, &self.tree, film, pass, seed)?)
    }
    fn probe(&self, bench: &Bench, film: &mut Film) -> anyhow::Result<()> {
        Ok(bench.render(&self.field, film, 0, 0x5eed)?)
    }
    fn bos(&self, bos: &Bos, seed: u64) -> anyhow::Result<BosImages> {
        Ok(bos.render_grid(&self.field, &self.tree, seed)?)
    }
    fn focusing(&self, fs: &FocusingSchlieren, seed: u64) -> anyhow::Result<FocusingImages> {
        Ok(fs.render_grid(&self.field, &self.tree, seed)?)
    }
}

impl Source for MeshVolume {
    fn bounds(&self) -> Bounds {
        self.mesh().bounds()
    }
    fn n_ref(&self) -> f64 {
        self.mesh().ambient()
    }
    fn params(&self) -> TraceParams {
        match self {
            // Unused: the mesh is traced in closed form.
            Self::Exact(_) => TraceParams::accurate(),
            Self::Smooth(s) => s.params(),
        }
    }
    fn pass(&self, bench: &Bench, film: &mut Film, pass: u64, seed: u64) -> anyhow::Result<()> {
        match self {
            Self::Exact(f) => Ok(bench.render_mesh(f, film, pass, seed)?),
            Self::Smooth(s) => {
                let params = bench.params;
                Ok(bench.render_with(&|o, d| s.trace(o, d, &params), film, pass, seed)?)
            }
        }
    }
    fn probe(&self, bench: &Bench, film: &mut Film) -> anyhow::Result<()> {
        self.pass(bench, film, 0, 0x5eed)
    }
    fn bos(&self, bos: &Bos, seed: u64) -> anyhow::Result<BosImages> {
        match self {
            Self::Exact(f) => Ok(bos.render_mesh(f, seed)?),
            Self::Smooth(s) => Ok(bos.render_with(&|o, d| s.trace(o, d, &bos.params), seed)?),
        }
    }
    fn focusing(&self, fs: &FocusingSchlieren, seed: u64) -> anyhow::Result<FocusingImages> {
        match self {
            Self::Exact(f) => Ok(fs.render_mesh(f, seed)?),
            Self::Smooth(s) => Ok(fs.render_with(&|o, d| s.trace(o, d, &fs.params), seed)?),
        }
    }
}

/// The lattice that traces `photons` photons per pixel: `(k, passes)`, a
/// `k × k` lattice per pixel in each pass. The sheet spreads each cell's
/// light over the cell's image, which blurs a jump in the image (trilinear
/// data's gradient jumps at cell faces) over `1/k` of a pixel; so `k`
/// grows with the photons — the largest power of two with at least 4
/// passes of `k²` (2 from 4 photons per pixel: 16 → 2, 64 → 4, 256 → 8)
/// — and the passes, shifted along R2, fill in between. `photons` rounds
/// up to whole passes.
#[must_use]
pub fn lattice(photons: u32) -> (u32, u64) {
    let mut k = 1u32;
    while 4 * (2 * k) * (2 * k) <= photons.max(16) && k < 64 {
        k *= 2;
    }
    let k = if photons < 4 { 1 } else { k };
    (k, u64::from(photons.div_ceil(k * k)))
}

/// The photons per pixel [`lattice`] traces for `photons`: whole passes.
#[must_use]
pub fn traced_per_pixel(photons: u32) -> u64 {
    let (k, passes) = lattice(photons);
    passes * u64::from(k * k)
}

/// Mean deflection per pixel of a coarse, uncut image of the volume.
#[derive(Clone, Debug)]
pub struct Survey {
    /// `(εu, εv)` per pixel, radians (`None`: no photon landed).
    pub eps: Vec<Option<(f64, f64)>>,
    /// Pixels per row.
    pub width: usize,
    /// Pixel size `(du, dv)` in the scene's length unit.
    pub pixel: (f64, f64),
}

/// The `q`-quantile (0–1) of `values` (0 for none).
fn quantile(mut values: Vec<f64>, q: f64) -> f64 {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    let i = ((values.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
    values[i]
}

impl Survey {
    /// The `q`-quantile of `|ε|`.
    #[must_use]
    pub fn magnitude(&self, q: f64) -> f64 {
        quantile(self.eps.iter().flatten().map(|&(a, b)| a.hypot(b)).collect(), q)
    }

    /// The `q`-quantile of `|ε|` over the disturbed pixels (those
    /// deflected by more than a thousandth of the largest deflection):
    /// undisturbed pixels do not dilute it, however much of the image they
    /// fill.
    #[must_use]
    pub fn disturbed_magnitude(&self, q: f64) -> f64 {
        let all: Vec<f64> = self.eps.iter().flatten().map(|&(a, b)| a.hypot(b)).collect();
        let floor = 1e-3 * all.iter().copied().filter(|m| m.is_finite()).fold(0.0, f64::max);
        quantile(all.into_iter().filter(|&m| m > floor).collect(), q)
    }

    /// The `q`-quantile of `|ε⊥|`, the deflection along `angle` (radians
    /// from the image's u axis), as a knife edge there sees it.
    #[must_use]
    pub fn along(&self, angle: f64, q: f64) -> f64 {
        let (s, c) = angle.sin_cos();
        quantile(self.eps.iter().flatten().map(|&(a, b)| (a * c + b * s).abs()).collect(), q)
    }

    /// The `q`-quantile of `|∇⊥·ε|` (per length unit): what a film at
    /// distance `L` sees as the relative contrast `L·∇⊥·ε` (shadowgraph).
    #[must_use]
    pub fn divergence(&self, q: f64) -> f64 {
        let w = self.width;
        let at = |i: usize, j: usize| self.eps.get(i + w * j).copied().flatten();
        let rows = self.eps.len() / w.max(1);
        let mut div = Vec::new();
        for j in 1..rows.saturating_sub(1) {
            for i in 1..w.saturating_sub(1) {
                if let (Some(l), Some(r), Some(up), Some(down)) =
                    (at(i - 1, j), at(i + 1, j), at(i, j - 1), at(i, j + 1))
                {
                    // Rows grow downward, v upward.
                    let du = (r.0 - l.0) / (2.0 * self.pixel.0);
                    let dv = (up.1 - down.1) / (2.0 * self.pixel.1);
                    div.push((du + dv).abs());
                }
            }
        }
        quantile(div, q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_ignore_non_finite_values() {
        assert_eq!(quantile(vec![], 0.5), 0.0);
        assert_eq!(quantile(vec![3.0, f64::NAN, 1.0, 2.0], 0.5), 2.0);
        assert_eq!(quantile((1..=100).map(f64::from).collect(), 0.99), 99.0);
    }

    /// The disturbed quantile ignores the undisturbed pixels: a flow in a
    /// small corner of the image has the same rim as one filling it,
    /// where the plain quantile would sink toward 0.
    #[test]
    fn the_disturbed_quantile_is_not_diluted_by_still_air() {
        let flow: Vec<Option<(f64, f64)>> = (1..=100).map(|i| Some((f64::from(i), 0.0))).collect();
        let mut sparse = vec![Some((0.0, 0.0)); 9900];
        sparse.extend(flow.iter().copied());
        let survey = |eps| Survey { eps, width: 100, pixel: (1.0, 1.0) };
        let (full, corner) = (survey(flow), survey(sparse));
        assert_eq!(full.disturbed_magnitude(0.99), corner.disturbed_magnitude(0.99));
        assert_eq!(corner.disturbed_magnitude(0.99), 99.0);
        assert_eq!(corner.magnitude(0.99), 0.0);
    }

    /// `--k`'s default is written out for `--help`; it is the constant.
    #[test]
    fn the_gladstone_dale_default_is_the_constant() {
        let a = crate::schlieren::Args::from_args(std::path::Path::new("v"), [""; 0]).unwrap();
        assert_eq!(a.samples.k, GLADSTONE_DALE_AIR);
    }

    #[test]
    fn the_lattice_refines_with_the_photons() {
        assert_eq!(lattice(1), (1, 1));
        assert_eq!(lattice(3), (1, 3));
        assert_eq!(lattice(4), (2, 1));
        assert_eq!(lattice(16), (2, 4));
        assert_eq!(lattice(17), (2, 5));
        assert_eq!(lattice(63), (2, 16));
        assert_eq!(lattice(64), (4, 4));
        assert_eq!(lattice(256), (8, 4));
        assert_eq!(lattice(65536), (64, 16));
    }

    /// A weak flow (a Gaussian density bump, peak deflection 1e-4 rad,
    /// below the skipping tolerance of a bench without cutoff) is
    /// measured, not skipped: the survey's largest deflection is the
    /// analytic `K·A·√(2π)·e^(−1/2)` of the bump (docs/oracles.md §5) within the
    /// coarse survey's sampling. Before, it read 0, so the automatic
    /// exposure saturated knife-edge images and put the shadowgraph film
    /// at 0 m.
    #[test]
    fn the_survey_measures_weak_flows() {
        let (n, h, sigma, amp) = (48usize, 1.5e-3, 8e-3, 0.3);
        let c = 0.5 * (n as f64 - 1.0) * h;
        let mut data = Vec::with_capacity(n * n * n);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let p = DVec3::new(i as f64, j as f64, k as f64) * h - c;
                    data.push(
                        (1.2 + amp * (-p.length_squared() / (2.0 * sigma * sigma)).exp()) as f32,
                    );
                }
            }
        }
        let grid = Grid::new([n; 3], DVec3::ZERO, DVec3::splat(h), data).unwrap();
        let v = Volume::density(grid, Interpolation::Cubic).unwrap();
        let survey = v.survey(&v.bench(Axis::Z, Mode::Schlieren(Cutoff::None), 0.0)).unwrap();
        let exact = GLADSTONE_DALE_AIR * amp * (core::f64::consts::TAU).sqrt() * (-0.5f64).exp();
        let got = survey.magnitude(1.0);
        assert!((got / exact - 1.0).abs() < 0.1, "survey max |ε| {got:e}, analytic {exact:e}");
    }
}
