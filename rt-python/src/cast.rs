//! `rtvis.RayMesh`'s engine: rt-surface's `RayCaster` over numpy arrays,
//! the GIL released while rays are traced (rtvis's `_rays.py` checks the
//! arrays and gives the trimesh-style names).

use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2,
    ndarray::{Array1, Array2},
};
use pyo3::{prelude::*, types::PyBytes};
use rt_surface::{
    RayCaster,
    rt_core::{Hit, Ray, glam::Vec3},
};

use crate::value_error;

/// A triangle mesh built for rays (its BVH holds the triangles).
#[pyclass(name = "_RayMesh", module = "rtvis._rtvis", frozen)]
pub(crate) struct PyRayMesh {
    caster: RayCaster,
}

/// Rows of an `(n, 3)` float32 array as vectors (a C-contiguous one read
/// as one slice).
fn rows(a: &PyReadonlyArray2<'_, f32>) -> Vec<Vec3> {
    match a.as_slice() {
        Ok(flat) => flat.chunks_exact(3).map(Vec3::from_slice).collect(),
        Err(_) => a.as_array().rows().into_iter().map(|r| Vec3::new(r[0], r[1], r[2])).collect(),
    }
}

/// Rays from `origins` along `directions` (same length, checked by the
/// caller), over `[0, ∞)`.
fn rays(origins: &PyReadonlyArray2<'_, f32>, directions: &PyReadonlyArray2<'_, f32>) -> Vec<Ray> {
    rows(origins).into_iter().zip(rows(directions)).map(|(o, d)| Ray::new(o, d)).collect()
}

/// Triangle indices as numpy takes them; −1 for a miss.
fn triangles(hits: impl Iterator<Item = Option<u32>>) -> Array1<i64> {
    hits.map(|h| h.map_or(-1, i64::from)).collect()
}

type Hits<'py> = (
    Bound<'py, PyArray1<f32>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f32>>,
    Bound<'py, PyArray2<f32>>,
);

/// `(t, triangle, uv, position)` columns of `hits` (a miss: `inf`, −1,
/// NaN, NaN).
fn columns<'py>(py: Python<'py>, hits: &[Option<Hit>]) -> PyResult<Hits<'py>> {
    let n = hits.len();
    let t: Array1<f32> = hits.iter().map(|h| h.map_or(f32::INFINITY, |h| h.t)).collect();
    let tri = triangles(hits.iter().map(|h| h.map(|h| h.prim)));
    let uv: Vec<f32> =
        hits.iter().flat_map(|h| h.map_or([f32::NAN; 2], |h| h.uv.to_array())).collect();
    let at: Vec<f32> =
        hits.iter().flat_map(|h| h.map_or([f32::NAN; 3], |h| h.position.to_array())).collect();
    Ok((
        t.into_pyarray(py),
        tri.into_pyarray(py),
        Array2::from_shape_vec((n, 2), uv).map_err(value_error)?.into_pyarray(py),
        Array2::from_shape_vec((n, 3), at).map_err(value_error)?.into_pyarray(py),
    ))
}

#[pymethods]
impl PyRayMesh {
    /// The mesh `vertices` `(n, 3)` float32, `faces` `(m, 3)` int64
    /// (checked by the caller to lie in `0..n`).
    #[new]
    fn new(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f32>,
        faces: PyReadonlyArray2<'_, i64>,
    ) -> PyResult<Self> {
        let p = rows(&vertices);
        let tris: Vec<[u32; 3]> = faces
            .as_array()
            .rows()
            .into_iter()
            .map(|r| {
                let at = |k: usize| {
                    u32::try_from(r[k]).map_err(|_| value_error("faces: an index out of range"))
                };
                Ok([at(0)?, at(1)?, at(2)?])
            })
            .collect::<PyResult<_>>()?;
        let caster = py.detach(|| RayCaster::new(&p, &tris)).map_err(value_error)?;
        Ok(Self { caster })
    }

    /// The mesh saved by `to_bytes`.
    #[staticmethod]
    fn from_bytes(py: Python<'_>, data: &[u8]) -> PyResult<Self> {
        let caster = py.detach(|| RayCaster::from_bytes(data)).map_err(value_error)?;
        Ok(Self { caster })
    }

    /// The BVH and triangles as bytes.
    fn to_bytes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.caster.to_bytes())
    }

    /// Triangles of the mesh.
    fn triangle_count(&self) -> u32 {
        self.caster.triangle_count()
    }

    /// First hit of each ray: `(t, triangle, uv, position)`.
    fn first<'py>(
        &self,
        py: Python<'py>,
        origins: PyReadonlyArray2<'py, f32>,
        directions: PyReadonlyArray2<'py, f32>,
    ) -> PyResult<Hits<'py>> {
        let rays = rays(&origins, &directions);
        let hits = py.detach(|| self.caster.first(&rays));
        columns(py, &hits)
    }

    /// The triangle each ray hits first (−1: none), without the rest.
    fn first_triangle<'py>(
        &self,
        py: Python<'py>,
        origins: PyReadonlyArray2<'py, f32>,
        directions: PyReadonlyArray2<'py, f32>,
    ) -> Bound<'py, PyArray1<i64>> {
        let rays = rays(&origins, &directions);
        let hits = py.detach(|| self.caster.nearest(&rays));
        triangles(hits.iter().map(|h| h.map(|h| h.1))).into_pyarray(py)
    }

    /// Whether each ray hits anything.
    fn any<'py>(
        &self,
        py: Python<'py>,
        origins: PyReadonlyArray2<'py, f32>,
        directions: PyReadonlyArray2<'py, f32>,
    ) -> Bound<'py, PyArray1<bool>> {
        let rays = rays(&origins, &directions);
        let any = py.detach(|| self.caster.any(&rays));
        Array1::from(any).into_pyarray(py)
    }

    /// Every crossing, at most `most` a ray: `(ray, (t, triangle, uv,
    /// position))`.
    fn all<'py>(
        &self,
        py: Python<'py>,
        origins: PyReadonlyArray2<'py, f32>,
        directions: PyReadonlyArray2<'py, f32>,
        most: usize,
    ) -> PyResult<(Bound<'py, PyArray1<i64>>, Hits<'py>)> {
        let rays = rays(&origins, &directions);
        let all = py.detach(|| self.caster.all(&rays, most));
        let index: Array1<i64> = all.iter().map(|(i, _)| i64::from(*i)).collect();
        let hits: Vec<Option<Hit>> = all.into_iter().map(|(_, h)| Some(h)).collect();
        Ok((index.into_pyarray(py), columns(py, &hits)?))
    }
}
