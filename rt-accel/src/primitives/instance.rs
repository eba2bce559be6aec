//! Two-level hierarchies: objects (each with its own bottom-level BVHs,
//! built once) placed in the world by affine transforms, under a small
//! top-level tree over the instances' world boxes, rebuilt whenever the
//! placements change (one box per instance: cheap).
//!
//! A ray is carried into each candidate object's space by the inverse
//! transform, direction unnormalised, so the parameter `t` is the same in
//! both spaces and the object's closest hit is the world's (pbrt-v4's
//! `TransformedPrimitive`, Pharr, Jakob & Humphreys 2023, §7.1.4). Hits
//! come back with the position and normal in world space and a rounding
//! bound on the position that includes the transform's own rounding.

use alloc::{sync::Arc, vec::Vec};

use glam::{Mat3, Mat4, Vec3};
use rt_core::{Aabb, Hit, Ray, SceneQuery, gamma};

use crate::{Bvh, Primitive, Scene};

/// Geometry an instance can place: anything with bounds and ray queries.
pub trait Object {
    /// A box around everything, in the object's own space.
    fn bounds(&self) -> Aabb;
    /// The closest hit in `[ray.t_min, ray.t_max]` (object space).
    fn closest_hit(&self, ray: &Ray) -> Option<Hit>;
    /// Whether anything is hit in `[ray.t_min, ray.t_max]`.
    fn occluded(&self, ray: &Ray) -> bool;
}

impl Object for Scene {
    fn bounds(&self) -> Aabb {
        self.triangles
            .as_ref()
            .bounds()
            .union(self.spheres.as_ref().bounds())
            .union(self.capsules.as_ref().bounds())
    }
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        SceneQuery::closest_hit(self, ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        SceneQuery::occluded(self, ray)
    }
}

impl<P: Primitive> Object for Bvh<P> {
    fn bounds(&self) -> Aabb {
        self.as_ref().bounds()
    }
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        Bvh::closest_hit(self, ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        Bvh::occluded(self, ray)
    }
}

impl<T: Object + ?Sized> Object for &T {
    fn bounds(&self) -> Aabb {
        (**self).bounds()
    }
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        (**self).closest_hit(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        (**self).occluded(ray)
    }
}

impl<T: Object + ?Sized> Object for Arc<T> {
    fn bounds(&self) -> Aabb {
        (**self).bounds()
    }
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        (**self).closest_hit(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        (**self).occluded(ray)
    }
}

/// Why instances could not be placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InstanceError {
    /// An instance names an object past the end of the object list.
    NoSuchObject {
        /// Index of the instance.
        instance: usize,
    },
    /// An instance's transform is not finite or not invertible (or its
    /// inverse is not finite).
    BadTransform {
        /// Index of the instance.
        instance: usize,
    },
}

impl core::fmt::Display for InstanceError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NoSuchObject { instance } => write!(f, "instance {instance} names no object"),
            Self::BadTransform { instance } => {
                write!(f, "instance {instance} has a singular or non-finite transform")
            }
        }
    }
}

impl core::error::Error for InstanceError {}

/// One placed instance, with what queries need precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Placed {
    object: u32,
    to_world: Mat4,
    to_object: Mat4,
    /// Carries object normals to world space (inverse transpose).
    normal: Mat3,
    /// `|to_world|` (element-wise absolute), for the error bound.
    abs3: Mat3,
}

/// A top-level node: its box and either two children (`count == 0`,
/// children at `first` and `first + 1`) or instances `order[first..first + count]`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct TopNode {
    bounds: Aabb,
    first: u32,
    count: u32,
}

/// Most instances in one top-level leaf.
const LEAF: usize = 2;
/// Top-level traversal stack (a median split halves the instances per
/// level: 2³² instances fit in 32 levels).
const TOP_STACK: usize = 64;

/// Objects placed by transforms, behind a top-level tree; see the module
/// documentation. Ties in `t` go to the lower instance index, then to the
/// object's own rule.
#[derive(Clone, Debug)]
pub struct Instances<O> {
    objects: Vec<O>,
    placed: Vec<Placed>,
    order: Vec<u32>,
    nodes: Vec<TopNode>,
}

impl<O: Object> Instances<O> {
    /// Places `objects` by `instances`: `(object index, object-to-world
    /// transform)` each. The top-level tree is built here.
    ///
    /// # Errors
    /// [`InstanceError`] naming the first bad instance.
    pub fn new(objects: Vec<O>, instances: &[(u32, Mat4)]) -> Result<Self, InstanceError> {
        let mut placed = Vec::with_capacity(instances.len());
        let mut boxes = Vec::with_capacity(instances.len());
        for (i, &(object, to_world)) in instances.iter().enumerate() {
            let obj =
                objects.get(object as usize).ok_or(InstanceError::NoSuchObject { instance: i })?;
            let to_object = to_world.inverse();
            if !to_world.is_finite()
                || to_world.determinant() == 0.0
                || !to_object.is_finite()
                || to_world.row(3) != glam::Vec4::W
            {
                return Err(InstanceError::BadTransform { instance: i });
            }
            let m3 = Mat3::from_mat4(to_world);
            let abs3 = Mat3::from_cols(m3.x_axis.abs(), m3.y_axis.abs(), m3.z_axis.abs());
            placed.push(Placed {
                object,
                to_world,
                to_object,
                normal: m3.inverse().transpose(),
                abs3,
            });
            boxes.push(world_box(obj.bounds(), &to_world));
        }
        let mut order: Vec<u32> = (0..instances.len() as u32).collect();
        let mut nodes = Vec::new();
        if !order.is_empty() {
            nodes.push(TopNode { bounds: Aabb::EMPTY, first: 0, count: 0 });
            build(&boxes, &mut order, 0, instances.len(), 0, &mut nodes);
        }
        Ok(Self { objects, placed, order, nodes })
    }

    /// The objects.
    #[must_use]
    pub fn objects(&self) -> &[O] {
        &self.objects
    }

    /// The object instance `i` places (`None` past the last instance).
    #[must_use]
    pub fn object_of(&self, i: u32) -> Option<u32> {
        self.placed.get(i as usize).map(|p| p.object)
    }

    /// Number of instances.
    #[must_use]
    pub fn len(&self) -> usize {
        self.placed.len()
    }

    /// Whether there are no instances.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.placed.is_empty()
    }

    /// The world box around every instance.
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::EMPTY, |n| n.bounds)
    }

    /// The closest hit and the instance it belongs to.
    #[must_use]
    pub fn closest_hit_instance(&self, ray: &Ray) -> Option<(u32, Hit)> {
        if !ray.is_valid() || self.nodes.is_empty() {
            return None;
        }
        let mut best: Option<(u32, Hit)> = None;
        let t_max = |best: &Option<(u32, Hit)>| best.map_or(ray.t_max, |(_, h)| h.t);
        let entry = |c: u32, t_max: f32| {
            self.nodes[c as usize].bounds.intersect_ray(&Ray { t_max, ..*ray }).map(|(t, _)| t)
        };
        // Nodes with the distance at which the ray enters their box: each
        // box is tested once, when its parent is opened.
        let mut stack = [(0u32, 0.0f32); TOP_STACK];
        let mut sp = 0;
        if let Some(t) = entry(0, ray.t_max) {
            stack[0] = (0, t);
            sp = 1;
        }
        while sp > 0 {
            sp -= 1;
            let (at, t_entry) = stack[sp];
            if t_entry > t_max(&best) {
                continue;
            }
            let node = self.nodes[at as usize];
            if node.count == 0 {
                // Push the farther child first: the nearer is opened next.
                let bound = t_max(&best);
                let (a, b) = (node.first, node.first + 1);
                let mut kids = [(a, entry(a, bound)), (b, entry(b, bound))];
                if kids[1].1.unwrap_or(f32::INFINITY) < kids[0].1.unwrap_or(f32::INFINITY) {
                    kids.swap(0, 1);
                }
                for (c, t) in kids.into_iter().rev() {
                    if let (Some(t), true) = (t, sp < TOP_STACK) {
                        stack[sp] = (c, t);
                        sp += 1;
                    }
                }
                continue;
            }
            for &i in &self.order[node.first as usize..(node.first + node.count) as usize] {
                let r = Ray { t_max: t_max(&best), ..*ray };
                if let Some(h) = self.hit_instance(i, &r) {
                    let better = best.is_none_or(|(bi, bh)| h.t < bh.t || (h.t == bh.t && i < bi));
                    if better {
                        best = Some((i, h));
                    }
                }
            }
        }
        best
    }

    /// Instance `i`'s closest hit of `ray`, in world space.
    fn hit_instance(&self, i: u32, ray: &Ray) -> Option<Hit> {
        let p = &self.placed[i as usize];
        let local = Ray::with_range(
            p.to_object.transform_point3(ray.origin),
            p.to_object.transform_vector3(ray.direction),
            ray.t_min,
            ray.t_max,
        );
        let h = self.objects[p.object as usize].closest_hit(&local)?;
        let position = p.to_world.transform_point3(h.position);
        // The object's bound carried through |M|, plus the rounding of
        // the transform itself (pbrt-v4's Transform on Point3fi).
        let t = p.to_world.w_axis.truncate();
        let err = p.abs3 * h.position_error
            + gamma(3) * (p.abs3 * h.position.abs() + t.abs())
            + gamma(3) * (p.abs3 * h.position_error);
        Some(Hit {
            position,
            position_error: err,
            normal: (p.normal * h.normal).normalize_or_zero(),
            ..h
        })
    }
}

impl<O: Object> SceneQuery for Instances<O> {
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.closest_hit_instance(ray).map(|(_, h)| h)
    }

    fn occluded(&self, ray: &Ray) -> bool {
        if !ray.is_valid() || self.nodes.is_empty() {
            return false;
        }
        let mut stack = [0u32; TOP_STACK];
        let mut sp = 1;
        while sp > 0 {
            sp -= 1;
            let node = self.nodes[stack[sp] as usize];
            if node.bounds.intersect_ray(ray).is_none() {
                continue;
            }
            if node.count == 0 {
                for c in [node.first, node.first + 1] {
                    if sp < TOP_STACK {
                        stack[sp] = c;
                        sp += 1;
                    }
                }
                continue;
            }
            for &i in &self.order[node.first as usize..(node.first + node.count) as usize] {
                let p = &self.placed[i as usize];
                let local = Ray::with_range(
                    p.to_object.transform_point3(ray.origin),
                    p.to_object.transform_vector3(ray.direction),
                    ray.t_min,
                    ray.t_max,
                );
                if self.objects[p.object as usize].occluded(&local) {
                    return true;
                }
            }
        }
        false
    }
}

/// The world box of an object box under `m`, widened by the rounding of
/// transforming its corners.
fn world_box(b: Aabb, m: &Mat4) -> Aabb {
    if b.is_empty() {
        return Aabb::EMPTY;
    }
    let mut out = Aabb::EMPTY;
    for k in 0..8 {
        let c = Vec3::new(
            if k & 1 == 0 { b.min.x } else { b.max.x },
            if k & 2 == 0 { b.min.y } else { b.max.y },
            if k & 4 == 0 { b.min.z } else { b.max.z },
        );
        out = out.grow(m.transform_point3(c));
    }
    let pad = gamma(3) * out.min.abs().max(out.max.abs());
    Aabb::new(out.min - pad, out.max + pad)
}

/// Builds node `at` over `order[lo..hi]`: a median split along the
/// widest axis of the centroids, down to [`LEAF`] instances.
fn build(
    boxes: &[Aabb],
    order: &mut [u32],
    lo: usize,
    hi: usize,
    at: usize,
    nodes: &mut Vec<TopNode>,
) {
    let bounds = order[lo..hi].iter().fold(Aabb::EMPTY, |b, &i| b.union(boxes[i as usize]));
    if hi - lo <= LEAF {
        nodes[at] = TopNode { bounds, first: lo as u32, count: (hi - lo) as u32 };
        return;
    }
    let cent = order[lo..hi].iter().fold(Aabb::EMPTY, |b, &i| b.grow(center(boxes[i as usize])));
    let e = cent.extent();
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let mid = lo + (hi - lo) / 2;
    order[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
        center(boxes[a as usize])[axis].total_cmp(&center(boxes[b as usize])[axis])
    });
    let first = nodes.len();
    nodes.push(TopNode { bounds: Aabb::EMPTY, first: 0, count: 0 });
    nodes.push(TopNode { bounds: Aabb::EMPTY, first: 0, count: 0 });
    nodes[at] = TopNode { bounds, first: first as u32, count: 0 };
    build(boxes, order, lo, mid, first, nodes);
    build(boxes, order, mid, hi, first + 1, nodes);
}

/// A box's centre (empty boxes at the origin, so the split stays finite).
fn center(b: Aabb) -> Vec3 {
    if b.is_empty() { Vec3::ZERO } else { b.center() }
}
