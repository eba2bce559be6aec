//! A scene of triangles, spheres and capsules behind one query.

use rt_core::{Hit, Ray, SceneQuery};

use crate::{Bvh, CapsuleItem, SphereItem, TriPacket};

/// One BVH per primitive kind; kinds a scene lacks cost nothing. Hits from
/// different kinds are told apart by [`Hit::kind`].
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Triangle meshes.
    pub triangles: Bvh<TriPacket>,
    /// Spheres.
    pub spheres: Bvh<SphereItem>,
    /// Capsules.
    pub capsules: Bvh<CapsuleItem>,
}

impl Default for Scene {
    fn default() -> Self {
        Self { triangles: Bvh::empty(), spheres: Bvh::empty(), capsules: Bvh::empty() }
    }
}

impl Scene {
    /// The closest hit of `ray` given its closest triangle hit: each later
    /// kind searches only up to the best hit so far; on equal `t` the
    /// earlier kind wins.
    fn after_triangles(&self, ray: &Ray, best: Option<Hit>) -> Option<Hit> {
        let closer = |best: Option<Hit>, next: &dyn Fn(&Ray) -> Option<Hit>| {
            let r = Ray { t_max: best.map_or(ray.t_max, |h| h.t), ..*ray };
            next(&r).filter(|h| best.is_none_or(|b| h.t < b.t)).or(best)
        };
        let best = closer(best, &|r| self.spheres.closest_hit(r));
        closer(best, &|r| self.capsules.closest_hit(r))
    }
}

impl SceneQuery for Scene {
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.after_triangles(ray, self.triangles.closest_hit(ray))
    }

    /// The triangles as one packet (the kind that holds most of a scene);
    /// spheres and capsules ray by ray, as [`Scene::closest_hit`].
    fn closest_hit_packet(&self, rays: &[Ray; crate::PACKET]) -> [Option<Hit>; crate::PACKET] {
        let tri = self.triangles.closest_hit_packet(rays);
        core::array::from_fn(|i| self.after_triangles(&rays[i], tri[i]))
    }

    /// The triangles as one stream; spheres and capsules ray by ray, as
    /// [`Scene::closest_hit`].
    fn closest_hit_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.triangles.closest_hit_batch(rays, out);
        for (ray, o) in rays.iter().zip(out) {
            *o = self.after_triangles(ray, *o);
        }
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.triangles.occluded(ray) || self.spheres.occluded(ray) || self.capsules.occluded(ray)
    }

    /// The triangles as one stream; spheres and capsules ray by ray for
    /// the rays the triangles leave open, as [`Scene::occluded`].
    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        self.triangles.occluded_batch(rays, out);
        for (ray, o) in rays.iter().zip(out) {
            *o = *o || self.spheres.occluded(ray) || self.capsules.occluded(ray);
        }
    }
}
