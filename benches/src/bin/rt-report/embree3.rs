//! Embree 3 (feature `embree3`) as one more implementation in the
//! traversal table: its own BVH (default build quality) and single-ray
//! `rtcIntersect1` / `rtcOccluded1`, same triangles, same rays, in its
//! default mode and in its robust one.

use cgmath::{Vector3, Vector4};
use embree::{
    CommittedScene, Device, Geometry, IntersectContext, Ray, RayHit, Scene, TriangleMesh,
};
use glam::Vec3;

/// A committed Embree scene. The device and scene are leaked: the report
/// builds two scenes and exits, and Embree's API ties the committed scene's
/// lifetime to both.
pub(crate) struct EmbreeScene {
    scene: CommittedScene<'static>,
}

impl EmbreeScene {
    /// `robust`: with `RTC_SCENE_FLAG_ROBUST`, Embree's mode that avoids
    /// the optimizations that cost accuracy (its robust box test and a
    /// watertight triangle test, as rt always does).
    pub(crate) fn new(positions: &[Vec3], indices: &[[u32; 3]], robust: bool) -> Self {
        Self::build(positions, indices, robust, false)
    }

    /// A scene for [`EmbreeScene::all_hits`]: its geometry records and
    /// rejects every hit ([`crate::filter`]).
    pub(crate) fn recording(positions: &[Vec3], indices: &[[u32; 3]], robust: bool) -> Self {
        Self::build(positions, indices, robust, true)
    }

    fn build(positions: &[Vec3], indices: &[[u32; 3]], robust: bool, record: bool) -> Self {
        let device: &'static Device = Box::leak(Box::new(Device::new()));
        let mut mesh = TriangleMesh::unanimated(device, indices.len(), positions.len());
        {
            let mut v = mesh.vertex_buffer.map();
            for (i, p) in positions.iter().enumerate() {
                v[i] = Vector4::new(p.x, p.y, p.z, 0.0);
            }
            let mut ib = mesh.index_buffer.map();
            for (i, t) in indices.iter().enumerate() {
                ib[i] = Vector3::new(t[0], t[1], t[2]);
            }
        }
        let mut geom = Geometry::Triangle(mesh);
        if record {
            /// The shared filter, under the crate's declaration of its type.
            unsafe extern "C" fn record(args: *const embree::sys::RTCFilterFunctionNArguments) {
                // SAFETY: Embree 3's arguments, laid out as `FilterArgs`.
                unsafe { crate::filter::record_and_reject(args.cast()) }
            }
            // SAFETY: the live geometry, not yet committed.
            unsafe {
                embree::sys::rtcSetGeometryIntersectFilterFunction(geom.handle(), Some(record))
            };
        }
        geom.commit();
        let scene: &'static mut Scene<'static> = Box::leak(Box::new(Scene::new(device)));
        scene.attach_geometry(geom);
        if robust {
            // SAFETY: the handle is the live scene's, not yet committed.
            unsafe {
                embree::sys::rtcSetSceneFlags(scene.handle(), embree::SceneFlags::ROBUST);
            }
        }
        Self { scene: scene.commit() }
    }

    /// `(t, primitive)` of the closest hit.
    pub(crate) fn closest(
        &self,
        ctx: &mut IntersectContext,
        r: &rt_core::Ray,
    ) -> Option<(f32, u32)> {
        let (o, d) = (r.origin, r.direction);
        let mut rh = RayHit::new(Ray::segment(
            Vector3::new(o.x, o.y, o.z),
            Vector3::new(d.x, d.y, d.z),
            r.t_min,
            r.t_max,
        ));
        self.scene.intersect(ctx, &mut rh);
        rh.hit.hit().then_some((rh.ray.tfar, rh.hit.primID))
    }
}

impl EmbreeScene {
    /// Every hit along `r`, `(t, primitive)` in the order Embree found
    /// them (a scene made by [`EmbreeScene::recording`]).
    pub(crate) fn all_hits(&self, ctx: &mut IntersectContext, r: &rt_core::Ray) -> Vec<(f32, u32)> {
        crate::filter::collect(|| {
            self.closest(ctx, r);
        })
    }

    /// Whether anything is hit (`rtcOccluded1`, which sets `tfar` to −∞
    /// when it finds a hit).
    pub(crate) fn occluded(&self, ctx: &mut IntersectContext, r: &rt_core::Ray) -> bool {
        let (o, d) = (r.origin, r.direction);
        let mut ray = Ray::segment(
            Vector3::new(o.x, o.y, o.z),
            Vector3::new(d.x, d.y, d.z),
            r.t_min,
            r.t_max,
        );
        self.scene.occluded(ctx, &mut ray);
        ray.tfar == f32::NEG_INFINITY
    }
}

/// A context for single incoherent rays.
pub(crate) fn context() -> IntersectContext {
    IntersectContext::incoherent()
}

impl EmbreeScene {
    /// All rays at once through Embree's stream API (`rtcIntersect1M` /
    /// `rtcOccluded1M`, array of structures): (hits, Σt).
    pub(crate) fn stream(
        &self,
        ctx: &mut IntersectContext,
        rays: &[rt_core::Ray],
        closest: bool,
    ) -> (u64, f64) {
        let to = |r: &rt_core::Ray| {
            let (o, d) = (r.origin, r.direction);
            Ray::segment(Vector3::new(o.x, o.y, o.z), Vector3::new(d.x, d.y, d.z), r.t_min, r.t_max)
        };
        if closest {
            let mut rh: Vec<RayHit> = rays.iter().map(|r| RayHit::new(to(r))).collect();
            self.scene.intersect_stream_aos(ctx, &mut rh);
            rh.iter()
                .filter(|h| h.hit.hit())
                .fold((0, 0.0), |(n, s), h| (n + 1, s + f64::from(h.ray.tfar)))
        } else {
            let mut r: Vec<Ray> = rays.iter().map(to).collect();
            self.scene.occluded_stream_aos(ctx, &mut r);
            (r.iter().filter(|r| r.tfar == f32::NEG_INFINITY).count() as u64, 0.0)
        }
    }
}
