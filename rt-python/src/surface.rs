//! Ray-traced surfaces: meshes coloured by a scalar, sphere glyphs and
//! tubes, rendered into premultiplied RGBA and depth.

use glam::Vec3;
use numpy::{
    IntoPyArray, PyArray2, PyArray3, PyReadonlyArray1, PyReadonlyArray2,
    ndarray::{Array2, Array3},
};
use pyo3::{
    exceptions::{PyMemoryError, PyRuntimeError},
    prelude::*,
};
use rt_core::{Camera, ColorMap, ColorStop, FrameError, Projection, intersect::Sphere};
use rt_surface::{
    Light, Material, Mesh, RenderError, Renderer, Settings,
    scene::{Glyphs, Paint, SurfaceScene, Tube},
};

use crate::{optics::filled, value_error, watch::watched};

/// How an object is coloured, as given.
#[derive(Clone, Debug)]
struct PaintSpec {
    /// One colour (linear RGB), or `None` to map the scalars.
    solid: Option<[f32; 3]>,
    /// The colour map: a name, or the caller's own stops.
    map: MapSpec,
    /// Scalar range of the colour map.
    range: (f32, f32),
}

/// A colour map by name, or the caller's stops (`(position, r, g, b)`,
/// colours on the sRGB curve, as a table holds them).
#[derive(Clone, Debug)]
enum MapSpec {
    Named(&'static str),
    Stops(Vec<ColorStop>),
}

impl PaintSpec {
    fn paint(&self) -> PyResult<Paint<'_>> {
        if let Some(c) = self.solid {
            return Ok(Paint::Solid(c));
        }
        let (lo, hi) = self.range;
        let map = match &self.map {
            MapSpec::Named("viridis") => ColorMap::viridis(),
            MapSpec::Named("grayscale") => ColorMap::grayscale(),
            MapSpec::Named(_) => ColorMap::cool_to_warm(),
            MapSpec::Stops(stops) => ColorMap::from_stops(stops, lo, hi)
                .map_err(|e| value_error(format!("colormap: {e}")))?,
        };
        Ok(Paint::Mapped(map.with_range(lo, hi).map_err(|e| value_error(format!("range: {e}")))?))
    }
}

/// The colour map `colormap` names, or its stops: an `(n, 4)` float32
/// array of `(position in [0, 1], r, g, b)`.
fn map_spec(colormap: &Bound<'_, PyAny>) -> PyResult<MapSpec> {
    if let Ok(name) = colormap.extract::<String>() {
        return match name.as_str() {
            "viridis" => Ok(MapSpec::Named("viridis")),
            "grayscale" => Ok(MapSpec::Named("grayscale")),
            "cool_to_warm" => Ok(MapSpec::Named("cool_to_warm")),
            other => Err(value_error(format!(
                "colormap: unknown `{other}` (known: viridis, cool_to_warm, grayscale, or (n, 4) stops)"
            ))),
        };
    }
    let a: PyReadonlyArray2<'_, f32> = colormap.extract()?;
    let a = a.as_array();
    if a.ncols() != 4 || a.nrows() < 2 {
        return Err(value_error(format!(
            "colormap: expected (n, 4) stops (position, r, g, b), n ≥ 2; got {:?}",
            a.dim()
        )));
    }
    let stops: Vec<ColorStop> =
        a.rows().into_iter().map(|r| ColorStop::rgb(r[0], r[1], r[2], r[3])).collect();
    // Checked here, where the caller can be told which stop.
    ColorMap::from_stops(&stops, 0.0, 1.0).map_err(|e| value_error(format!("colormap: {e}")))?;
    Ok(MapSpec::Stops(stops))
}

/// One object of a scene.
#[derive(Clone, Debug)]
enum Object {
    Mesh(Mesh, PaintSpec, Material),
    Spheres(Vec<Sphere>, Option<Vec<f32>>, PaintSpec, Material),
    Tube(Vec<Vec3>, f32, Option<Vec<f32>>, PaintSpec, Material),
}

/// Objects to render; BVHs are built when rendering.
#[pyclass(name = "_Scene", module = "rtvis._rtvis")]
#[derive(Default)]
pub(crate) struct PyScene {
    objects: Vec<Object>,
}

/// `[n, 3]` points from `a` (any strides), named `name` in errors.
fn read_points(name: &str, a: &PyReadonlyArray2<'_, f32>) -> PyResult<Vec<Vec3>> {
    let v = a.as_array();
    if v.ncols() != 3 {
        return Err(value_error(format!("{name}: expected shape (n, 3), got {:?}", v.shape())));
    }
    let pts: Vec<Vec3> = v.rows().into_iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect();
    if let Some(i) = pts.iter().position(|p| !p.is_finite()) {
        return Err(value_error(format!("{name}: point {i} is not finite ({})", pts[i])));
    }
    Ok(pts)
}

/// One scalar per item from `a`, `n` expected.
fn read_scalars(a: Option<PyReadonlyArray1<'_, f32>>, n: usize) -> PyResult<Option<Vec<f32>>> {
    let Some(a) = a else { return Ok(None) };
    let s: Vec<f32> = a.as_array().iter().copied().collect();
    if s.len() != n {
        return Err(value_error(format!(
            "scalars: expected {n} values (one per point), got {}",
            s.len()
        )));
    }
    Ok(Some(s))
}

/// The paint from the Python arguments: a colour, or a map over `range`
/// (default: the finite scalars' extent).
fn paint_spec(
    color: Option<[f32; 3]>,
    colormap: &Bound<'_, PyAny>,
    range: Option<(f32, f32)>,
    scalars: Option<&[f32]>,
) -> PyResult<PaintSpec> {
    let map = map_spec(colormap)?;
    if let Some(c) = color.filter(|c| !c.iter().all(|v| v.is_finite() && *v >= 0.0)) {
        return Err(value_error(format!("color must be finite and ≥ 0 (got {c:?})")));
    }
    let range = match range {
        Some((lo, hi)) => {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return Err(value_error(format!(
                    "range must be finite with lo < hi (got ({lo}, {hi}))"
                )));
            }
            (lo, hi)
        }
        None => {
            let finite = scalars.into_iter().flatten().copied().filter(|v| v.is_finite());
            let (lo, hi) =
                finite.fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
            if lo < hi {
                (lo, hi)
            } else if lo.is_finite() {
                (lo - 0.5, lo + 0.5)
            } else {
                (0.0, 1.0)
            }
        }
    };
    Ok(PaintSpec { solid: color, map, range })
}

/// A material from `(diffuse, specular, shininess, opacity, mirror)`.
fn make_material(m: [f32; 5]) -> PyResult<Material> {
    let [diffuse, specular, shininess, opacity, mirror] = m;
    let mat = Material { diffuse, specular, shininess, opacity, mirror };
    mat.validate().map_err(|e| value_error(format!("material: {e}")))?;
    Ok(mat)
}

/// `(rgba [h, w, 4] premultiplied linear, depth [h, w])`.
type Image<'py> = (Bound<'py, PyArray3<f32>>, Bound<'py, PyArray2<f32>>);

#[pymethods]
impl PyScene {
    #[new]
    fn new() -> Self {
        Self::default()
    }

    #[pyo3(signature = (points, triangles, scalars, color, colormap, range, material, smooth, normals))]
    #[allow(clippy::too_many_arguments)]
    fn add_mesh(
        &mut self,
        points: PyReadonlyArray2<'_, f32>,
        triangles: PyReadonlyArray2<'_, i64>,
        scalars: Option<PyReadonlyArray1<'_, f32>>,
        color: Option<[f32; 3]>,
        colormap: &Bound<'_, PyAny>,
        range: Option<(f32, f32)>,
        material: [f32; 5],
        smooth: bool,
        normals: Option<PyReadonlyArray2<'_, f32>>,
    ) -> PyResult<()> {
        let pts = read_points("points", &points)?;
        let t = triangles.as_array();
        if t.ncols() != 3 {
            return Err(value_error(format!(
                "triangles: expected shape (m, 3), got {:?}",
                t.shape()
            )));
        }
        let n = pts.len() as i64;
        let mut tris = Vec::with_capacity(t.nrows());
        for (i, r) in t.rows().into_iter().enumerate() {
            if let Some(&bad) = r.iter().find(|&&v| !(0..n).contains(&v)) {
                return Err(value_error(format!(
                    "triangles: triangle {i} refers to point {bad}, outside 0..{n}"
                )));
            }
            tris.push([r[0] as u32, r[1] as u32, r[2] as u32]);
        }
        let s = read_scalars(scalars, pts.len())?;
        let paint = paint_spec(color, colormap, range, s.as_deref())?;
        let mat = make_material(material)?;
        let mut mesh = Mesh::new(pts, tris, s).map_err(|e| value_error(format!("mesh: {e}")))?;
        if let Some(n) = normals {
            let n = read_points("normals", &n)?;
            mesh = mesh.with_normals(n).map_err(|e| value_error(format!("normals: {e}")))?;
        } else if smooth {
            mesh = mesh.with_smooth_normals();
        }
        self.objects.push(Object::Mesh(mesh, paint, mat));
        Ok(())
    }

    #[pyo3(signature = (centers, radii, scalars, color, colormap, range, material))]
    #[allow(clippy::too_many_arguments)]
    fn add_spheres(
        &mut self,
        centers: PyReadonlyArray2<'_, f32>,
        radii: PyReadonlyArray1<'_, f32>,
        scalars: Option<PyReadonlyArray1<'_, f32>>,
        color: Option<[f32; 3]>,
        colormap: &Bound<'_, PyAny>,
        range: Option<(f32, f32)>,
        material: [f32; 5],
    ) -> PyResult<()> {
        let c = read_points("centers", &centers)?;
        let r: Vec<f32> = radii.as_array().iter().copied().collect();
        if r.len() != c.len() {
            return Err(value_error(format!(
                "radii: expected {} values (one per centre), got {}",
                c.len(),
                r.len()
            )));
        }
        if let Some(i) = r.iter().position(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(value_error(format!(
                "radii: radius {i} must be finite and > 0 (got {})",
                r[i]
            )));
        }
        let s = read_scalars(scalars, c.len())?;
        let paint = paint_spec(color, colormap, range, s.as_deref())?;
        let spheres = c.into_iter().zip(r).map(|(p, r)| Sphere::new(p, r)).collect();
        self.objects.push(Object::Spheres(spheres, s, paint, make_material(material)?));
        Ok(())
    }

    #[pyo3(signature = (polyline, radius, scalars, color, colormap, range, material))]
    #[allow(clippy::too_many_arguments)]
    fn add_tube(
        &mut self,
        polyline: PyReadonlyArray2<'_, f32>,
        radius: f32,
        scalars: Option<PyReadonlyArray1<'_, f32>>,
        color: Option<[f32; 3]>,
        colormap: &Bound<'_, PyAny>,
        range: Option<(f32, f32)>,
        material: [f32; 5],
    ) -> PyResult<()> {
        let p = read_points("polyline", &polyline)?;
        if p.len() < 2 {
            return Err(value_error(format!(
                "polyline: a tube needs at least 2 points, got {}",
                p.len()
            )));
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(value_error(format!("radius must be finite and > 0 (got {radius})")));
        }
        let s = read_scalars(scalars, p.len())?;
        let paint = paint_spec(color, colormap, range, s.as_deref())?;
        self.objects.push(Object::Tube(p, radius, s, paint, make_material(material)?));
        Ok(())
    }

    /// Number of objects added.
    fn __len__(&self) -> usize {
        self.objects.len()
    }

    /// `((xmin, ymin, zmin), (xmax, ymax, zmax))` over every object, or
    /// `None` for an empty scene.
    fn bounds(&self) -> Option<([f32; 3], [f32; 3])> {
        let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
        let mut grow = |p: Vec3, r: f32| {
            lo = lo.min(p - r);
            hi = hi.max(p + r);
        };
        for o in &self.objects {
            match o {
                Object::Mesh(m, ..) => m.positions().iter().for_each(|&p| grow(p, 0.0)),
                Object::Spheres(s, ..) => s.iter().for_each(|s| grow(s.center, s.radius)),
                Object::Tube(p, r, ..) => p.iter().for_each(|&p| grow(p, *r)),
            }
        }
        (lo.cmple(hi).all()).then(|| (lo.to_array(), hi.to_array()))
    }

    #[pyo3(signature = (eye, target, up, fov, ortho_height, width, height, lights, shadows, ao, ao_distance, passes, seed, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn render<'py>(
        &self,
        py: Python<'py>,
        eye: [f32; 3],
        target: [f32; 3],
        up: [f32; 3],
        fov: f32,
        ortho_height: Option<f32>,
        width: u32,
        height: u32,
        lights: Vec<(String, [f32; 3], [f32; 3])>,
        shadows: bool,
        ao: u32,
        ao_distance: f32,
        passes: u32,
        seed: u64,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Image<'py>> {
        if !(1..=16384).contains(&width) || !(1..=16384).contains(&height) {
            return Err(value_error(format!(
                "size must be 1 to 16384 pixels a side (got {width}×{height})"
            )));
        }
        if !(1..=65536).contains(&passes) {
            return Err(value_error(format!("passes must be 1 to 65536 (got {passes})")));
        }
        let projection = match ortho_height {
            Some(h) => Projection::Orthographic { height: h },
            None => Projection::Perspective { fov_y: fov.to_radians() },
        };
        let camera =
            Camera::look_at(eye.into(), target.into(), up.into(), projection, width, height)
                .map_err(|e| value_error(format!("camera: {e}")))?;
        let mut ls = Vec::with_capacity(lights.len());
        for (kind, v, color) in lights {
            ls.push(match kind.as_str() {
                "ambient" => Light::Ambient { color },
                "directional" => Light::Directional { direction: v.into(), color },
                "point" => Light::Point { position: v.into(), color },
                other => {
                    return Err(value_error(format!(
                        "lights: unknown kind `{other}` (known: ambient, directional, point)"
                    )));
                }
            });
        }
        let settings = Settings {
            lights: ls,
            shadows,
            ao_samples: ao,
            ao_distance,
            seed,
            ..Settings::default()
        };
        settings.validate().map_err(|e| value_error(format!("settings: {e}")))?;
        let mut b = SurfaceScene::builder();
        for o in &self.objects {
            b = match o {
                Object::Mesh(m, p, mat) => b.mesh(m.clone(), p.paint()?, *mat),
                Object::Spheres(s, sc, p, mat) => b.glyphs(Glyphs {
                    spheres: s.clone(),
                    scalars: sc.clone(),
                    paint: p.paint()?,
                    material: *mat,
                }),
                Object::Tube(pts, r, sc, p, mat) => b.tube(Tube {
                    points: pts.clone(),
                    radius: *r,
                    scalars: sc.clone(),
                    paint: p.paint()?,
                    material: *mat,
                }),
            };
        }
        // Stopped between tiles; the progress counts tiles over all passes.
        let frame = watched(py, progress, |w| -> Result<_, RenderFailure> {
            let scene = b.build().map_err(|e| RenderFailure::Other(format!("scene: {e}")))?;
            let mut r = Renderer::new(camera, settings).map_err(RenderFailure::render)?;
            for pass in 0..u64::from(passes) {
                if w.stopped() {
                    return Err(RenderFailure::Stopped);
                }
                let report = |done: usize, tiles: usize| {
                    let tiles = tiles as u64;
                    w.progress(pass * tiles + done as u64, u64::from(passes) * tiles);
                };
                if r.render_pass_until(&scene, report, &|| w.stopped()).is_none() {
                    return Err(RenderFailure::Stopped);
                }
            }
            r.frame().map_err(|e| RenderFailure::render(RenderError::Frame(e)))
        })?
        .map_err(RenderFailure::into_py)?;
        let (w, h) = (frame.width() as usize, frame.height() as usize);
        let rgba = filled(4 * w * h, frame.pixels().iter().flat_map(|p| p.color))?;
        let depth = filled(w * h, frame.pixels().iter().map(|p| p.depth))?;
        Ok((
            Array3::from_shape_vec((h, w, 4), rgba).map_err(value_error)?.into_pyarray(py),
            Array2::from_shape_vec((h, w), depth).map_err(value_error)?.into_pyarray(py),
        ))
    }
}

/// Why a surface render failed.
enum RenderFailure {
    /// The frame did not fit in memory.
    OutOfMemory,
    /// Told to stop (the watcher raises the reason itself).
    Stopped,
    /// Anything else, said.
    Other(String),
}

impl RenderFailure {
    fn render(e: RenderError) -> Self {
        match e {
            RenderError::Frame(FrameError::OutOfMemory) => Self::OutOfMemory,
            e => Self::Other(format!("renderer: {e}")),
        }
    }

    fn into_py(self) -> PyErr {
        match self {
            Self::OutOfMemory => PyMemoryError::new_err(
                "rtvis: the image's accumulators do not fit in memory (a smaller size fits)",
            ),
            Self::Stopped => PyRuntimeError::new_err("rtvis: the render was stopped"),
            Self::Other(e) => value_error(e),
        }
    }
}
