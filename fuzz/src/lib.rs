//! What the fuzz targets share: numbers drawn with a bias toward the values
//! that break numerics (NaN, ±∞, ±0, subnormals, huge and tiny
//! magnitudes), and the checks made on every answer.

use arbitrary::{Result, Unstructured};
use rt_core::{Ray, glam::Vec3};

/// Values that break numerics, each drawn often.
const SPECIAL_F32: [f32; 16] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.5,
    f32::NAN,
    f32::INFINITY,
    f32::NEG_INFINITY,
    f32::MIN_POSITIVE,
    1.0e-40, // subnormal
    -1.0e-45,
    1.0e-8,
    1.0e8,
    1.0e30,
    f32::MAX,
    f32::EPSILON,
];

/// An `f32`: a special value, any bit pattern, a power of ten from 1e-8 to
/// 1e8 with a sign, or a small number on a coarse grid (so that
/// coincidences — shared vertices, axis-aligned rays — happen often).
pub fn f32_any(u: &mut Unstructured<'_>) -> Result<f32> {
    Ok(match u.int_in_range(0u8..=7)? {
        0 => SPECIAL_F32[u.choose_index(SPECIAL_F32.len())?],
        1 => f32::from_bits(u.arbitrary()?),
        2 => {
            let e = u.int_in_range(-8i32..=8)?;
            let s = if u.arbitrary()? { -1.0 } else { 1.0 };
            s * 10f32.powi(e)
        }
        _ => f32::from(u.int_in_range(-64i8..=64)?) / 16.0,
    })
}

/// An `f64` drawn like [`f32_any`].
pub fn f64_any(u: &mut Unstructured<'_>) -> Result<f64> {
    Ok(match u.int_in_range(0u8..=7)? {
        0 => f64::from(SPECIAL_F32[u.choose_index(SPECIAL_F32.len())?]),
        1 => f64::from_bits(u.arbitrary()?),
        2 => {
            let e = u.int_in_range(-8i32..=8)?;
            let s = if u.arbitrary()? { -1.0 } else { 1.0 };
            s * 10f64.powi(e)
        }
        _ => f64::from(u.int_in_range(-64i8..=64)?) / 16.0,
    })
}

/// A point or direction.
pub fn vec3(u: &mut Unstructured<'_>) -> Result<Vec3> {
    Ok(Vec3::new(f32_any(u)?, f32_any(u)?, f32_any(u)?))
}

/// A ray with any origin, direction and range (valid or not).
pub fn ray(u: &mut Unstructured<'_>) -> Result<Ray> {
    let (origin, direction) = (vec3(u)?, vec3(u)?);
    let (t_min, t_max) = match u.int_in_range(0u8..=3)? {
        0 => (0.0, f32::INFINITY),
        _ => (f32_any(u)?, f32_any(u)?),
    };
    Ok(Ray { origin, direction, t_min, t_max })
}

/// A hit distance must be a number inside the ray's range.
pub fn check_t(ray: &Ray, t: f32, what: &str) {
    assert!(t.is_finite(), "{what}: t = {t} for {ray:?}");
    assert!(t >= ray.t_min && t <= ray.t_max, "{what}: t = {t} outside the range of {ray:?}");
}

/// Three points.
pub fn triangle(u: &mut Unstructured<'_>) -> Result<[Vec3; 3]> {
    Ok([vec3(u)?, vec3(u)?, vec3(u)?])
}

/// A small grid (2–6 samples per axis) from any numbers: origin, spacing
/// and samples may be anything, so `Grid::new` sees bad input too.
pub fn grid(u: &mut Unstructured<'_>) -> Result<Option<rt_volume::Grid>> {
    use rt_volume::glam::DVec3;
    let dims =
        [u.int_in_range(2usize..=6)?, u.int_in_range(2usize..=6)?, u.int_in_range(2usize..=6)?];
    let origin = DVec3::new(f64_any(u)?, f64_any(u)?, f64_any(u)?);
    let spacing = DVec3::new(f64_any(u)?, f64_any(u)?, f64_any(u)?);
    // Mostly indices near 1 (a refractive index), sometimes anything.
    let wild = u.ratio(1u8, 8)?;
    let mut data = Vec::with_capacity(dims.iter().product());
    for _ in 0..dims.iter().product::<usize>() {
        data.push(if wild { f32_any(u)? } else { 1.0 + f32::from(u.arbitrary::<i8>()?) * 1e-3 });
    }
    Ok(rt_volume::Grid::new(dims, origin, spacing, data).ok())
}

/// Tracing parameters from any numbers, with the step count capped so
/// every trace is bounded work.
pub fn trace_params(u: &mut Unstructured<'_>) -> Result<rt_volume::TraceParams> {
    use rt_volume::{Method, TraceParams};
    let method = Method::ALL[u.choose_index(Method::ALL.len())?];
    let mut p = if u.arbitrary()? {
        TraceParams::fixed(method, f64_any(u)?)
    } else {
        TraceParams { method, ..TraceParams::accurate() }
    };
    if u.arbitrary()? {
        p.tolerance = f64_any(u)?;
        p.max_step = f64_any(u)?;
        p.max_length = f64_any(u)?;
    }
    p.max_steps = u.int_in_range(0u32..=20_000)?;
    Ok(p)
}

/// A traced ray's answer: finite numbers, and on leaving the field, a
/// point on its bounds within rounding (relative to the coordinates'
/// magnitudes, the launch point's included).
pub fn check_trace(
    r: &rt_volume::TraceResult,
    bounds: &rt_volume::Bounds,
    origin: rt_volume::glam::DVec3,
    what: &str,
) {
    assert!(r.position.is_finite() && r.direction.is_finite(), "{what}: {r:?}");
    assert!(r.optical_path.is_finite(), "{what}: {r:?}");
    if r.exit == rt_volume::Exit::Left {
        let scale = bounds.max.abs().max(bounds.min.abs()).max(origin.abs()).max_element();
        let slack = scale * 1e-9 + 1e-300;
        let lo = bounds.min - slack;
        let hi = bounds.max + slack;
        assert!(
            lo.cmple(r.position).all() && r.position.cmple(hi).all(),
            "{what}: left outside the bounds {bounds:?}: {r:?}"
        );
    }
}

/// A grid a reader returned: its samples fill its dimensions.
pub fn check_grid(g: &rt_volume::Grid) {
    let n: usize = g.dims().iter().product();
    assert_eq!(g.data().len(), n, "{:?} with {} samples", g.dims(), g.data().len());
    assert!(
        g.origin().is_finite() && g.spacing().is_finite(),
        "{:?} {:?}",
        g.origin(),
        g.spacing()
    );
}

/// A mesh a reader returned: every index points at a vertex, every
/// normal and scalar array has one value per vertex; and building the
/// mesh either works or is an `Err`.
pub fn check_mesh(m: rt_surface::io::MeshData) {
    let n = m.positions.len();
    assert!(m.indices.iter().flatten().all(|&i| (i as usize) < n), "index past {n} vertices");
    if let Some(normals) = &m.normals {
        assert_eq!(normals.len(), n);
    }
    for (name, s) in &m.scalars {
        assert_eq!(s.len(), n, "scalar {name}");
    }
    let first = m.scalars.first().map(|(name, _)| name.clone());
    if let Ok(mesh) = m.into_mesh(first.as_deref()) {
        let _ = mesh.geometry().build_bvh(&rt_accel::BuildParams::fast());
    }
}

/// A pixel from any numbers (NaN colours, ±∞ and NaN depths, `-0.0`),
/// the background now and then.
pub fn pixel(u: &mut Unstructured<'_>) -> Result<rt_core::Pixel> {
    if u.ratio(1u8, 4)? {
        return Ok(rt_core::Pixel::BACKGROUND);
    }
    Ok(rt_core::Pixel {
        color: [f32_any(u)?, f32_any(u)?, f32_any(u)?, f32_any(u)?],
        depth: f32_any(u)?,
    })
}

/// A pixel's bits, for exact comparison (NaN included).
pub fn bits(p: &rt_core::Pixel) -> [u32; 5] {
    [p.color[0], p.color[1], p.color[2], p.color[3], p.depth].map(f32::to_bits)
}
