//! Occlusion answered outside the scene, for geometry split between ranks
//! (rt-composite's `resolve_occlusion`): render once recording every
//! shadow and AO ray the shading asks about, resolve them elsewhere, then
//! render again with those answers.
//!
//! This works because the shading's queries never depend on the answers:
//! a pixel's shadow rays and AO directions come from its hit and its own
//! random stream, whether or not an earlier one was blocked. So the second
//! render asks exactly the rays the first recorded, and a ray is a value
//! (its eight `f32`s, compared by bits), so each answer is found by the
//! ray alone, on any thread, in any order. When every answer equals what
//! the whole scene's `occluded` gives, the frame equals the whole scene's
//! frame bit for bit.
//!
//! Closest hits are the local scene's: mirrors and translucent layers see
//! only this rank's geometry, so a distributed render that must equal the
//! whole scene's keeps its materials opaque and non-mirroring.

use alloc::vec::Vec;
use core::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use rt_core::{Aabb, Hit, Ray, SceneQuery};

use super::{ShadeScene, Surface};

/// A ray's identity: its eight `f32`s as bits.
type RayKey = [u32; 8];

fn key(r: &Ray) -> RayKey {
    [
        r.origin.x.to_bits(),
        r.origin.y.to_bits(),
        r.origin.z.to_bits(),
        r.direction.x.to_bits(),
        r.direction.y.to_bits(),
        r.direction.z.to_bits(),
        r.t_min.to_bits(),
        r.t_max.to_bits(),
    ]
}

/// A scene that records the occlusion rays asked of it and answers them
/// "open": the first of the two renders (see the module docs). Hits and
/// surfaces are `scene`'s; [`ShadeScene::bounds`] is `bounds`, which must
/// contain the whole distributed scene (the renderer skips rays that miss
/// it).
#[derive(Debug)]
pub struct RecordOcclusion<'a, S> {
    scene: &'a S,
    bounds: Aabb,
    rays: Mutex<Vec<Ray>>,
}

impl<'a, S: ShadeScene> RecordOcclusion<'a, S> {
    /// Records over `scene`, reporting `bounds` (the whole scene's).
    #[must_use]
    pub fn new(scene: &'a S, bounds: Aabb) -> Self {
        Self { scene, bounds, rays: Mutex::new(Vec::new()) }
    }

    /// The rays asked, each once, in a fixed order (by their bits).
    #[must_use]
    pub fn into_queries(self) -> Vec<Ray> {
        let mut rays = self.rays.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner);
        rays.sort_unstable_by_key(key);
        rays.dedup_by_key(|r| key(r));
        rays
    }
}

impl<S: ShadeScene> SceneQuery for RecordOcclusion<'_, S> {
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.scene.closest_hit(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.rays.lock().unwrap_or_else(std::sync::PoisonError::into_inner).push(*ray);
        false
    }
    fn closest_hit_packet(&self, rays: &[Ray; 8]) -> [Option<Hit>; 8] {
        self.scene.closest_hit_packet(rays)
    }
    fn closest_hit_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.scene.closest_hit_batch(rays, out);
    }
}

impl<S: ShadeScene> ShadeScene for RecordOcclusion<'_, S> {
    fn surface(&self, hit: &Hit) -> Surface {
        self.scene.surface(hit)
    }
    fn bounds(&self) -> Aabb {
        self.bounds
    }
}

/// Why answers cannot be attached to recorded rays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AnswerCountError {
    /// Rays recorded.
    pub rays: usize,
    /// Answers given.
    pub answers: usize,
}

impl core::fmt::Display for AnswerCountError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{} answers for {} recorded occlusion rays", self.answers, self.rays)
    }
}

impl core::error::Error for AnswerCountError {}

/// A scene whose occlusion queries are answered from a table: the second
/// of the two renders. A ray not in the table (which a render of the same
/// pixels with the same settings never asks) is answered by `scene` and
/// counted in [`AnsweredOcclusion::unknown`].
#[derive(Debug)]
pub struct AnsweredOcclusion<'a, S> {
    scene: &'a S,
    bounds: Aabb,
    keys: Vec<RayKey>,
    occluded: Vec<bool>,
    unknown: AtomicU64,
}

impl<'a, S: ShadeScene> AnsweredOcclusion<'a, S> {
    /// `occluded[i]` answers `rays[i]` (the order
    /// [`RecordOcclusion::into_queries`] gave).
    ///
    /// # Errors
    /// [`AnswerCountError`] when the lengths differ.
    pub fn new(
        scene: &'a S,
        bounds: Aabb,
        rays: &[Ray],
        occluded: Vec<bool>,
    ) -> Result<Self, AnswerCountError> {
        if rays.len() != occluded.len() {
            return Err(AnswerCountError { rays: rays.len(), answers: occluded.len() });
        }
        let mut pairs: Vec<(RayKey, bool)> =
            rays.iter().map(key).zip(occluded.iter().copied()).collect();
        pairs.sort_unstable_by_key(|p| p.0);
        let (keys, occluded) = pairs.into_iter().unzip();
        Ok(Self { scene, bounds, keys, occluded, unknown: AtomicU64::new(0) })
    }

    /// Queries that were not in the table (0 when the two renders asked
    /// the same rays).
    #[must_use]
    pub fn unknown(&self) -> u64 {
        self.unknown.load(Ordering::Relaxed)
    }
}

impl<S: ShadeScene> SceneQuery for AnsweredOcclusion<'_, S> {
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.scene.closest_hit(ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        match self.keys.binary_search(&key(ray)) {
            Ok(i) => self.occluded[i],
            Err(_) => {
                self.unknown.fetch_add(1, Ordering::Relaxed);
                self.scene.occluded(ray)
            }
        }
    }
    fn closest_hit_packet(&self, rays: &[Ray; 8]) -> [Option<Hit>; 8] {
        self.scene.closest_hit_packet(rays)
    }
    fn closest_hit_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.scene.closest_hit_batch(rays, out);
    }
}

impl<S: ShadeScene> ShadeScene for AnsweredOcclusion<'_, S> {
    fn surface(&self, hit: &Hit) -> Surface {
        self.scene.surface(hit)
    }
    fn bounds(&self) -> Aabb {
        self.bounds
    }
}
