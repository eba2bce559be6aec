//! Embree 4 (feature `embree4`) as one more implementation in the
//! traversal table and the watertight suite: its own BVH (default build
//! quality) and single rays (`rtcIntersect1` / `rtcOccluded1` with no
//! arguments), in its default mode and its robust one.
//!
//! Debian 12 ships only Embree 3; the `embreex` wheel on PyPI bundles
//! `libembree4` (and its own TBB, found through the library's
//! `$ORIGIN` rpath). The report loads it at run time from the path in
//! `RT_EMBREE4` (`.ci/run` unpacks the wheel), so nothing links against
//! it at build time, and says which version it loaded. The few calls and
//! structures used are declared here from Embree 4's public API.

use core::ffi::{c_char, c_void};
use std::sync::OnceLock;

use libloading::Library;

use crate::filter::FilterArgs;

type Device = *mut c_void;
type Scene = *mut c_void;
type Geometry = *mut c_void;

// Values of Embree's enums (rtcore_common.h, rtcore_buffer.h, ...).
const GEOMETRY_TYPE_TRIANGLE: i32 = 0;
const BUFFER_TYPE_INDEX: i32 = 0;
const BUFFER_TYPE_VERTEX: i32 = 1;
const FORMAT_UINT3: i32 = 0x5003;
const FORMAT_FLOAT3: i32 = 0x9003;
const SCENE_FLAG_ROBUST: i32 = 1 << 2;
const DEVICE_PROPERTY_VERSION: i32 = 0;
const INVALID_GEOMETRY_ID: u32 = u32::MAX;

/// `RTCRay`: 48 bytes, 16-byte aligned.
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRay {
    org: [f32; 3],
    tnear: f32,
    dir: [f32; 3],
    time: f32,
    tfar: f32,
    mask: u32,
    id: u32,
    flags: u32,
}

/// `RTCRayHit`: the ray, then `RTCHit` (normal, u, v, primID, geomID,
/// instance ids; room left for a build with deeper instancing).
#[repr(C, align(16))]
#[derive(Clone, Copy)]
struct RtcRayHit {
    ray: RtcRay,
    ng: [f32; 3],
    u: f32,
    v: f32,
    prim_id: u32,
    geom_id: u32,
    rest: [u32; 17],
}

/// The entry points the report calls.
struct Api {
    device_property: unsafe extern "C" fn(Device, i32) -> isize,
    new_scene: unsafe extern "C" fn(Device) -> Scene,
    scene_flags: unsafe extern "C" fn(Scene, i32),
    new_geometry: unsafe extern "C" fn(Device, i32) -> Geometry,
    new_buffer: unsafe extern "C" fn(Geometry, i32, u32, i32, usize, usize) -> *mut c_void,
    commit_geometry: unsafe extern "C" fn(Geometry),
    attach: unsafe extern "C" fn(Scene, Geometry) -> u32,
    release_geometry: unsafe extern "C" fn(Geometry),
    commit_scene: unsafe extern "C" fn(Scene),
    intersect1: unsafe extern "C" fn(Scene, *mut RtcRayHit, *mut c_void),
    set_filter: unsafe extern "C" fn(Geometry, Option<unsafe extern "C" fn(*const FilterArgs)>),
    occluded1: unsafe extern "C" fn(Scene, *mut RtcRay, *mut c_void),
    device: Device,
    /// Kept loaded for the process's life.
    _lib: Library,
}

// SAFETY: Embree's device and committed scenes are safe to query from
// any thread; the pointers are only read.
unsafe impl Send for Api {}
unsafe impl Sync for Api {}

static API: OnceLock<Result<Api, String>> = OnceLock::new();

fn api() -> Result<&'static Api, String> {
    API.get_or_init(load).as_ref().map_err(Clone::clone)
}

fn load() -> Result<Api, String> {
    let path = std::env::var_os("RT_EMBREE4").ok_or(
        "feature embree4: set RT_EMBREE4 to a libembree4 (e.g. the embreex wheel's embreex.libs/libembree4-*.so.4; see .ci/run)",
    )?;
    // Deep binding: its own TBB first, not the one Embree 3 brought in.
    const RTLD_DEEPBIND: i32 = 0x0008;
    let flags = libloading::os::unix::RTLD_NOW | libloading::os::unix::RTLD_LOCAL | RTLD_DEEPBIND;
    // SAFETY: loading Embree runs only its own initialisers.
    let lib: Library = unsafe { libloading::os::unix::Library::open(Some(&path), flags) }
        .map_err(|e| format!("RT_EMBREE4={}: {e}", path.to_string_lossy()))?
        .into();
    // SAFETY: each symbol is declared with its C signature from Embree 4's
    // headers.
    unsafe {
        macro_rules! f {
            ($name:literal) => {
                *lib.get(concat!($name, "\0").as_bytes()).map_err(|e| format!("{}: {e}", $name))?
            };
        }
        let new_device: unsafe extern "C" fn(*const c_char) -> Device = f!("rtcNewDevice");
        let device = new_device(core::ptr::null());
        if device.is_null() {
            return Err("rtcNewDevice failed".into());
        }
        Ok(Api {
            device_property: f!("rtcGetDeviceProperty"),
            new_scene: f!("rtcNewScene"),
            scene_flags: f!("rtcSetSceneFlags"),
            new_geometry: f!("rtcNewGeometry"),
            new_buffer: f!("rtcSetNewGeometryBuffer"),
            commit_geometry: f!("rtcCommitGeometry"),
            attach: f!("rtcAttachGeometry"),
            release_geometry: f!("rtcReleaseGeometry"),
            commit_scene: f!("rtcCommitScene"),
            intersect1: f!("rtcIntersect1"),
            set_filter: f!("rtcSetGeometryIntersectFilterFunction"),
            occluded1: f!("rtcOccluded1"),
            device,
            _lib: lib,
        })
    }
}

/// The version of the Embree 4 loaded (`"4.4.0"`).
pub(crate) fn version() -> Result<String, String> {
    let api = api()?;
    // SAFETY: a live device; the property is a plain integer.
    let v = unsafe { (api.device_property)(api.device, DEVICE_PROPERTY_VERSION) };
    Ok(format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100))
}

/// A committed Embree 4 scene of one triangle mesh (never released: the
/// report builds a few and exits).
pub(crate) struct Embree4Scene {
    api: &'static Api,
    scene: Scene,
}

// SAFETY: a committed scene is read-only; Embree allows queries from any
// thread.
unsafe impl Sync for Embree4Scene {}

impl Embree4Scene {
    /// `robust`: with `RTC_SCENE_FLAG_ROBUST` (its robust box test and
    /// watertight triangle test).
    pub(crate) fn new(
        positions: &[glam::Vec3],
        indices: &[[u32; 3]],
        robust: bool,
    ) -> Result<Self, String> {
        Self::build(positions, indices, robust, false)
    }

    /// A scene for [`Embree4Scene::all_hits`]: its geometry records and
    /// rejects every hit ([`crate::filter`]).
    pub(crate) fn recording(
        positions: &[glam::Vec3],
        indices: &[[u32; 3]],
        robust: bool,
    ) -> Result<Self, String> {
        Self::build(positions, indices, robust, true)
    }

    fn build(
        positions: &[glam::Vec3],
        indices: &[[u32; 3]],
        robust: bool,
        record: bool,
    ) -> Result<Self, String> {
        let api = api()?;
        // SAFETY: Embree allocates both buffers (padded for its loads) with
        // the counts given; each is written within them before commit.
        unsafe {
            let scene = (api.new_scene)(api.device);
            if robust {
                (api.scene_flags)(scene, SCENE_FLAG_ROBUST);
            }
            let geom = (api.new_geometry)(api.device, GEOMETRY_TYPE_TRIANGLE);
            let v =
                (api.new_buffer)(geom, BUFFER_TYPE_VERTEX, 0, FORMAT_FLOAT3, 12, positions.len())
                    .cast::<[f32; 3]>();
            let ib = (api.new_buffer)(geom, BUFFER_TYPE_INDEX, 0, FORMAT_UINT3, 12, indices.len())
                .cast::<[u32; 3]>();
            if scene.is_null() || geom.is_null() || v.is_null() || ib.is_null() {
                return Err("Embree 4 could not make the scene".into());
            }
            for (i, p) in positions.iter().enumerate() {
                v.add(i).write(p.to_array());
            }
            for (i, t) in indices.iter().enumerate() {
                ib.add(i).write(*t);
            }
            if record {
                (api.set_filter)(geom, Some(crate::filter::record_and_reject));
            }
            (api.commit_geometry)(geom);
            (api.attach)(scene, geom);
            (api.release_geometry)(geom);
            (api.commit_scene)(scene);
            Ok(Self { api, scene })
        }
    }

    fn ray(r: &rt_core::Ray) -> RtcRay {
        RtcRay {
            org: r.origin.to_array(),
            tnear: r.t_min,
            dir: r.direction.to_array(),
            time: 0.0,
            tfar: r.t_max,
            mask: u32::MAX,
            id: 0,
            flags: 0,
        }
    }

    /// `(t, primitive)` of the closest hit.
    pub(crate) fn closest(&self, r: &rt_core::Ray) -> Option<(f32, u32)> {
        let mut rh = RtcRayHit {
            ray: Self::ray(r),
            ng: [0.0; 3],
            u: 0.0,
            v: 0.0,
            prim_id: INVALID_GEOMETRY_ID,
            geom_id: INVALID_GEOMETRY_ID,
            rest: [INVALID_GEOMETRY_ID; 17],
        };
        // SAFETY: a committed scene and a ray-hit laid out as RTCRayHit.
        unsafe { (self.api.intersect1)(self.scene, &mut rh, core::ptr::null_mut()) };
        (rh.geom_id != INVALID_GEOMETRY_ID).then_some((rh.ray.tfar, rh.prim_id))
    }

    /// Every hit along `r`, `(t, primitive)` in the order Embree found
    /// them (a scene made by [`Embree4Scene::recording`]).
    pub(crate) fn all_hits(&self, r: &rt_core::Ray) -> Vec<(f32, u32)> {
        crate::filter::collect(|| {
            self.closest(r);
        })
    }

    /// Whether anything is hit (`tfar` set to −∞ on a hit).
    pub(crate) fn occluded(&self, r: &rt_core::Ray) -> bool {
        let mut ray = Self::ray(r);
        // SAFETY: a committed scene and a ray laid out as RTCRay.
        unsafe { (self.api.occluded1)(self.scene, &mut ray, core::ptr::null_mut()) };
        ray.tfar == f32::NEG_INFINITY
    }
}
