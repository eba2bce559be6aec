//! tinybvh (feature `tinybvh`) in the traversal table: its high-quality
//! (spatial split) BVH with the standard traversal, and, when compiled with
//! AVX2, its BVH8_CPU layout.
//!
//! `tinybvh_rs::Ray::new` lets the C++ side write its 128-byte ray into the
//! wrapper's 64-byte struct; rays are therefore filled field by field inside
//! a 64-byte aligned, 128-byte slot.

use glam::Vec3;
use tinybvh_rs::{INFINITE, Intersection, Intersector, Ray, bvh};

/// A tinybvh BVH over a triangle soup (leaked: the BVH borrows it and the
/// report exits after two scenes).
pub(crate) struct TinyScene {
    bvh: bvh::BVH<'static>,
    #[cfg(target_feature = "avx2")]
    bvh8: tinybvh_rs::bvh8_cpu::BVH,
}

#[repr(C, align(64))]
struct RaySlot {
    ray: Ray,
    _tail: [u8; 64],
}

fn rcp(x: f32) -> f32 {
    if x.abs() > 1e-12 {
        1.0 / x
    } else if x >= 0.0 {
        INFINITE
    } else {
        -INFINITE
    }
}

impl TinyScene {
    pub(crate) fn new(positions: &[Vec3], indices: &[[u32; 3]]) -> Result<Self, String> {
        let soup: Vec<[f32; 4]> = indices
            .iter()
            .flat_map(|t| t.map(|i| positions[i as usize].extend(0.0).to_array()))
            .collect();
        let soup: &'static [[f32; 4]] = Box::leak(soup.into_boxed_slice());
        let bvh = bvh::BVH::new_hq(soup.into()).map_err(|e| format!("tinybvh: {e:?}"))?;
        #[cfg(target_feature = "avx2")]
        let bvh8 = {
            let mut b = bvh::BVH::new_hq(soup.into()).map_err(|e| format!("tinybvh: {e:?}"))?;
            b.split_leaves(4);
            let m = tinybvh_rs::mbvh::BVH::new(&b);
            tinybvh_rs::bvh8_cpu::BVH::new(&m).map_err(|e| format!("tinybvh: {e:?}"))?
        };
        Ok(Self {
            bvh,
            #[cfg(target_feature = "avx2")]
            bvh8,
        })
    }

    fn trace(bvh: &impl Intersector, r: &rt_core::Ray) -> Option<(f32, u32)> {
        let (o, d) = (r.origin, r.direction);
        let t_max = r.t_max.min(INFINITE);
        let mut slot = RaySlot {
            ray: Ray {
                origin: o.to_array(),
                padding_0: 0,
                dir: d.to_array(),
                padding_1: 0,
                r_d: [rcp(d.x), rcp(d.y), rcp(d.z)],
                padding_2: 0,
                hit: Intersection { t: t_max, u: 0.0, v: 0.0, prim: u32::MAX },
            },
            _tail: [0; 64],
        };
        bvh.intersect(&mut slot.ray);
        (slot.ray.hit.t < t_max).then_some((slot.ray.hit.t, slot.ray.hit.prim))
    }

    /// Closest hit with the standard BVH.
    pub(crate) fn closest(&self, r: &rt_core::Ray) -> Option<(f32, u32)> {
        Self::trace(&self.bvh, r)
    }

    /// Closest hit with BVH8_CPU (AVX2 builds only).
    #[cfg(target_feature = "avx2")]
    pub(crate) fn closest8(&self, r: &rt_core::Ray) -> Option<(f32, u32)> {
        Self::trace(&self.bvh8, r)
    }
}
