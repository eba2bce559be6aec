//! Geometry recorded once and its BVHs: built on first use, or refitted
//! from an earlier recording of the same primitives in other places.

use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use rt_accel::{Object, Scene};
use rt_core::{Aabb, Hit, Ray, SceneQuery, intersect::is_degenerate_triangle};

use super::{Geometry, GeometryError};

/// Geometry recorded once (a display list or a buffer draw) and its
/// BVHs, made the first time a frame is traced and kept while the
/// recording is.
///
/// The BVHs are built from scratch, or — for a recording made with
/// [`Recorded::moved`] — copied from an earlier recording of the same
/// primitives and refitted to the new vertices: the same tree with new
/// boxes, which answers every ray exactly as a fresh build would (it may
/// only be slower to traverse once vertices have moved far from where
/// the tree was built).
///
/// The geometry cannot be changed once recorded ([`Recorded::geometry`]
/// reads it): the BVHs and the shading of their hits must agree.
#[derive(Debug)]
pub struct Recorded {
    /// The geometry, in its entry space.
    geometry: Geometry,
    scene: OnceLock<Result<Scene, GeometryError>>,
    /// A built recording whose BVHs are refitted for this one, taken out
    /// at first use. Only built recordings go here, and a built one has
    /// already taken out its own source: no chain of recordings is kept
    /// alive.
    refit_from: Mutex<Option<Arc<Recorded>>>,
    /// Whether the BVHs are (to be) refitted rather than built.
    refit: bool,
}

impl Recorded {
    /// A recording whose BVHs are not built yet.
    #[must_use]
    pub fn new(geometry: Geometry) -> Self {
        Self { geometry, scene: OnceLock::new(), refit_from: Mutex::new(None), refit: false }
    }

    /// A recording of `previous`'s primitives with its vertices moved:
    /// its BVHs will be `previous`'s refitted, at first use, if
    /// `previous` has been built (or is itself still waiting on a built
    /// recording, whose BVHs are used then), with no error, and has the
    /// same triangles, points and segments over the same vertex indices,
    /// with no triangle left out of that build as degenerate that has an
    /// area now; otherwise its BVHs are built as [`Recorded::new`]'s are.
    /// [`Recorded::is_refit`] tells which.
    #[must_use]
    pub fn moved(geometry: Geometry, previous: &Arc<Self>) -> Self {
        let source = if previous.is_built() {
            Some(Arc::clone(previous))
        } else {
            // Not traced yet: its own source, if it waits on one (which
            // is built), serves as well; it is shared, not taken.
            previous.refit_from.lock().unwrap_or_else(PoisonError::into_inner).clone()
        };
        let source = source.filter(|s| {
            matches!(s.scene.get(), Some(Ok(_))) && same_primitives(&s.geometry, &geometry)
        });
        let refit = source.is_some();
        Self { geometry, scene: OnceLock::new(), refit_from: Mutex::new(source), refit }
    }

    /// The geometry, in its entry space.
    #[must_use]
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// The BVHs over the geometry, built (or refitted) on first use.
    ///
    /// # Errors
    /// As [`Geometry::build`]: a malformed geometry (see
    /// [`Geometry::check`]) or a primitive that is not finite.
    pub fn scene(&self) -> Result<&Scene, GeometryError> {
        self.scene
            .get_or_init(|| {
                let source = self.refit_from.lock().unwrap_or_else(PoisonError::into_inner).take();
                // Checked before anything indexes it, refit or build.
                self.geometry.check()?;
                // A refit that fails (only a vertex that is not finite
                // can make it) falls back to the build, which reports it.
                match source.and_then(|s| self.refitted(&s)) {
                    Some(scene) => Ok(scene),
                    None => Ok(self.geometry.build_checked()?),
                }
            })
            .as_ref()
            .map_err(Clone::clone)
    }

    /// `source`'s BVHs moved to this recording's vertices (checked).
    fn refitted(&self, source: &Self) -> Option<Scene> {
        let g = &self.geometry;
        let mut scene = source.scene.get()?.as_ref().ok()?.clone();
        scene.triangles.refit_triangles(&g.positions, &g.triangles).ok()?;
        scene.spheres.refit_spheres(&g.sphere_shapes()).ok()?;
        scene.capsules.refit_capsules(&g.tube_shapes()).ok()?;
        Some(scene)
    }

    /// Whether the BVHs have been built.
    #[must_use]
    pub fn is_built(&self) -> bool {
        self.scene.get().is_some()
    }

    /// Whether the BVHs come from refitting an earlier recording's (see
    /// [`Recorded::moved`]) rather than from a build.
    #[must_use]
    pub fn is_refit(&self) -> bool {
        self.refit
    }
}

/// Whether a BVH built (or refitted) over `old` can be refitted to `new`
/// and answer as a build over `new` would: the same primitives over the
/// same vertex indices, and no triangle degenerate in `old` (so perhaps
/// left out of the build) that is not degenerate in `new`.
fn same_primitives(old: &Geometry, new: &Geometry) -> bool {
    let corners = |g: &Geometry, t: &[u32; 3]| t.map(|i| g.positions.get(i as usize).copied());
    let degenerate = |g: &Geometry, t: &[u32; 3]| match corners(g, t) {
        [Some(a), Some(b), Some(c)] => is_degenerate_triangle(a, b, c),
        _ => true,
    };
    old.triangles == new.triangles
        && old.spheres.iter().map(|s| s.0).eq(new.spheres.iter().map(|s| s.0))
        && old.tubes.iter().map(|s| s.0).eq(new.tubes.iter().map(|s| s.0))
        && old.triangles.iter().all(|t| !degenerate(old, t) || degenerate(new, t))
}

impl Object for Recorded {
    fn bounds(&self) -> Aabb {
        self.scene().map_or(Aabb::EMPTY, Object::bounds)
    }
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        SceneQuery::closest_hit(self.scene().ok()?, ray)
    }
    fn occluded(&self, ray: &Ray) -> bool {
        self.scene().is_ok_and(|s| SceneQuery::occluded(s, ray))
    }
}
