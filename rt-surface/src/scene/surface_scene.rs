//! The scene: one BVH per primitive kind, the objects' paints and
//! materials, refits for moved vertices and rebuilds for new topology.

use alloc::vec::Vec;
use core::fmt;

use glam::Vec3;
use rt_accel::{
    BuildError, BuildParams, Bvh, Scene, build_capsules, build_spheres, build_triangles,
};
use rt_core::{Aabb, Hit, PrimKind, Ray, SceneQuery, intersect::Capsule};

use super::{Glyphs, ObjectKind, Paint, SceneBuilder, SceneError, Tube};
use crate::{Material, Mesh, ShadeScene, Surface};

struct MeshPart<'m> {
    mesh: Mesh,
    paint: Paint<'m>,
    material: Material,
    first_triangle: u32,
    first_vertex: u32,
}

/// Meshes, glyphs and tubes with materials behind one BVH per kind: the
/// [`ShadeScene`] of the surface renderer. Moving a mesh's vertices
/// refits its BVH; replacing a mesh (new topology) rebuilds it; the
/// counters [`SurfaceScene::refits`] and [`SurfaceScene::rebuilds`] say
/// which happened.
pub struct SurfaceScene<'m> {
    scene: Scene,
    meshes: Vec<MeshPart<'m>>,
    /// All meshes' vertices and triangles, concatenated.
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    glyphs: Vec<(Glyphs<'m>, u32)>,
    /// Each tube with its first capsule index.
    tubes: Vec<(Tube<'m>, u32)>,
    params: BuildParams,
    refits: u32,
    rebuilds: u32,
}

impl fmt::Debug for SurfaceScene<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SurfaceScene")
            .field("meshes", &self.meshes.len())
            .field("triangles", &self.indices.len())
            .field("glyphs", &self.glyphs.len())
            .field("tubes", &self.tubes.len())
            .finish_non_exhaustive()
    }
}

impl<'m> SurfaceScene<'m> {
    /// Builds the scene.
    ///
    /// # Errors
    /// [`SceneError`] naming the object (and, for bad geometry, the vertex
    /// or primitive within it).
    pub fn build(
        meshes: Vec<(Mesh, Paint<'m>, Material)>,
        glyphs: Vec<Glyphs<'m>>,
        tubes: Vec<Tube<'m>>,
        params: &BuildParams,
    ) -> Result<Self, SceneError> {
        let material = |kind, object, m: &Material| {
            m.validate().map_err(|error| SceneError::Material { kind, object, error })
        };
        let mut parts = Vec::with_capacity(meshes.len());
        for (i, (mesh, paint, m)) in meshes.into_iter().enumerate() {
            material(ObjectKind::Mesh, i, &m)?;
            parts.push(MeshPart { mesh, paint, material: m, first_triangle: 0, first_vertex: 0 });
        }
        let mut spheres = Vec::new();
        let mut placed_glyphs = Vec::with_capacity(glyphs.len());
        for (i, g) in glyphs.into_iter().enumerate() {
            material(ObjectKind::Glyphs, i, &g.material)?;
            if g.scalars.as_ref().is_some_and(|s| s.len() != g.spheres.len()) {
                return Err(SceneError::Shape { kind: ObjectKind::Glyphs, object: i });
            }
            let first = spheres.len() as u32;
            spheres.extend_from_slice(&g.spheres);
            placed_glyphs.push((g, first));
        }
        let mut capsules = Vec::new();
        let mut placed_tubes = Vec::with_capacity(tubes.len());
        for (i, t) in tubes.into_iter().enumerate() {
            material(ObjectKind::Tube, i, &t.material)?;
            if t.points.len() < 2 || t.scalars.as_ref().is_some_and(|s| s.len() != t.points.len()) {
                return Err(SceneError::Shape { kind: ObjectKind::Tube, object: i });
            }
            let first = capsules.len() as u32;
            capsules.extend(t.points.windows(2).map(|w| Capsule::new(w[0], w[1], t.radius)));
            placed_tubes.push((t, first));
        }
        // A bad primitive is named within its object.
        let locate = |kind, firsts: &[u32], error| {
            let (object, error) = match error {
                BuildError::InvalidPrimitive { index } => {
                    let o = firsts.partition_point(|&f| f as usize <= index).saturating_sub(1);
                    let first = firsts.get(o).map_or(0, |&f| f as usize);
                    (o, BuildError::InvalidPrimitive { index: index - first })
                }
                e => (0, e),
            };
            SceneError::Build { kind, object, error }
        };
        let sphere_firsts: Vec<u32> = placed_glyphs.iter().map(|g| g.1).collect();
        let tube_firsts: Vec<u32> = placed_tubes.iter().map(|t| t.1).collect();
        let scene = Scene {
            triangles: Bvh::empty(),
            spheres: build_spheres(&spheres, params)
                .map_err(|e| locate(ObjectKind::Glyphs, &sphere_firsts, e))?,
            capsules: build_capsules(&capsules, params)
                .map_err(|e| locate(ObjectKind::Tube, &tube_firsts, e))?,
        };
        let mut s = Self {
            scene,
            meshes: parts,
            positions: Vec::new(),
            indices: Vec::new(),
            glyphs: placed_glyphs,
            tubes: placed_tubes,
            params: *params,
            refits: 0,
            rebuilds: 0,
        };
        s.rebuild_triangles()?;
        s.rebuilds = 0;
        Ok(s)
    }

    /// The short way to assemble a scene: add objects, then
    /// [`SceneBuilder::build`].
    pub fn builder() -> SceneBuilder<'m> {
        SceneBuilder::new()
    }

    /// A scene of one matte mesh, BVH built with [`BuildParams::medium`].
    ///
    /// # Errors
    /// As [`SurfaceScene::build`].
    pub fn from_mesh(mesh: impl Into<Mesh>, paint: Paint<'m>) -> Result<Self, SceneError> {
        Self::builder().mesh(mesh, paint, Material::MATTE).build()
    }

    /// Concatenates the meshes and builds their BVH.
    fn rebuild_triangles(&mut self) -> Result<(), SceneError> {
        let (mut positions, mut indices) = (Vec::new(), Vec::new());
        for (i, part) in self.meshes.iter_mut().enumerate() {
            let too_many = SceneError::Build {
                kind: ObjectKind::Mesh,
                object: i,
                error: BuildError::TooManyPrimitives,
            };
            part.first_vertex = u32::try_from(positions.len()).map_err(|_| too_many)?;
            part.first_triangle = u32::try_from(indices.len()).map_err(|_| too_many)?;
            let base = part.first_vertex;
            positions.extend_from_slice(part.mesh.positions());
            for t in part.mesh.indices() {
                let shifted = [0, 1, 2].map(|k| t[k].checked_add(base));
                let [Some(a), Some(b), Some(c)] = shifted else { return Err(too_many) };
                indices.push([a, b, c]);
            }
        }
        let bvh = build_triangles(&positions, &indices, &self.params).map_err(|error| {
            // Name the mesh and its own vertex.
            self.locate(error)
        })?;
        self.scene.triangles = bvh;
        self.positions = positions;
        self.indices = indices;
        self.rebuilds += 1;
        Ok(())
    }

    fn locate(&self, error: BuildError) -> SceneError {
        let (object, error) = match error {
            BuildError::NonFiniteVertex { vertex } => {
                let i = self.meshes.partition_point(|p| p.first_vertex as usize <= vertex) - 1;
                let local = vertex - self.meshes[i].first_vertex as usize;
                (i, BuildError::NonFiniteVertex { vertex: local })
            }
            e => (0, e),
        };
        SceneError::Build { kind: ObjectKind::Mesh, object, error }
    }

    /// Moves mesh `index`'s vertices (same count, same triangles) and
    /// refits the triangle BVH: no rebuild.
    ///
    /// # Errors
    /// [`SceneError::NoSuchMesh`], or [`SceneError::Build`] for a count
    /// mismatch or a non-finite vertex (named); nothing changes on error.
    pub fn set_mesh_positions(
        &mut self,
        index: usize,
        positions: &[Vec3],
    ) -> Result<(), SceneError> {
        let part = self.meshes.get_mut(index).ok_or(SceneError::NoSuchMesh(index))?;
        part.mesh.set_positions(positions).map_err(|error| SceneError::Build {
            kind: ObjectKind::Mesh,
            object: index,
            error,
        })?;
        let start = part.first_vertex as usize;
        self.positions[start..start + positions.len()].copy_from_slice(positions);
        self.scene
            .triangles
            .refit_triangles(&self.positions, &self.indices)
            .map_err(|error| SceneError::Build { kind: ObjectKind::Mesh, object: index, error })?;
        self.refits += 1;
        Ok(())
    }

    /// Replaces mesh `index` (new topology): the triangle BVH is rebuilt.
    ///
    /// # Errors
    /// [`SceneError::NoSuchMesh`], or a build error; the old mesh stays on
    /// error.
    pub fn replace_mesh(&mut self, index: usize, mesh: Mesh) -> Result<(), SceneError> {
        let part = self.meshes.get_mut(index).ok_or(SceneError::NoSuchMesh(index))?;
        let old = core::mem::replace(&mut part.mesh, mesh);
        if let Err(e) = self.rebuild_triangles() {
            self.meshes[index].mesh = old;
            return Err(e);
        }
        Ok(())
    }

    /// Triangle BVH refits so far (vertex moves).
    #[must_use]
    pub fn refits(&self) -> u32 {
        self.refits
    }

    /// Triangle BVH rebuilds so far (topology changes), not counting the
    /// first build.
    #[must_use]
    pub fn rebuilds(&self) -> u32 {
        self.rebuilds
    }

    /// Triangles in all meshes.
    #[must_use]
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// The underlying BVHs.
    #[must_use]
    pub fn scene(&self) -> &Scene {
        &self.scene
    }
}

impl SceneQuery for SurfaceScene<'_> {
    fn closest_hit(&self, ray: &Ray) -> Option<Hit> {
        self.scene.closest_hit(ray)
    }

    fn closest_hit_packet(&self, rays: &[Ray; 8]) -> [Option<Hit>; 8] {
        self.scene.closest_hit_packet(rays)
    }

    fn closest_hit_batch(&self, rays: &[Ray], out: &mut [Option<Hit>]) {
        self.scene.closest_hit_batch(rays, out);
    }

    fn occluded(&self, ray: &Ray) -> bool {
        self.scene.occluded(ray)
    }

    fn occluded_batch(&self, rays: &[Ray], out: &mut [bool]) {
        self.scene.occluded_batch(rays, out);
    }
}

impl ShadeScene for SurfaceScene<'_> {
    fn surface(&self, hit: &Hit) -> Surface {
        let fallback = Surface { albedo: [1.0; 3], normal: hit.normal, material: Material::MATTE };
        match hit.kind {
            PrimKind::Triangle => {
                let i = self.meshes.partition_point(|p| p.first_triangle <= hit.prim);
                let Some(part) = i.checked_sub(1).and_then(|i| self.meshes.get(i)) else {
                    return fallback;
                };
                let local = Hit { prim: hit.prim - part.first_triangle, ..*hit };
                Surface {
                    albedo: part.paint.color(part.mesh.interpolate_scalar(&local)),
                    normal: part.mesh.shading_normal(&local),
                    material: part.material,
                }
            }
            PrimKind::Sphere => {
                let i = self.glyphs.partition_point(|g| g.1 <= hit.prim);
                let Some((g, first)) = i.checked_sub(1).and_then(|i| self.glyphs.get(i)) else {
                    return fallback;
                };
                let k = (hit.prim - first) as usize;
                let scalar = g.scalars.as_ref().and_then(|s| s.get(k).copied());
                Surface { albedo: g.paint.color(scalar), normal: hit.normal, material: g.material }
            }
            PrimKind::Capsule => {
                let i = self.tubes.partition_point(|t| t.1 <= hit.prim);
                let Some((t, first)) = i.checked_sub(1).and_then(|i| self.tubes.get(i)) else {
                    return fallback;
                };
                let k = (hit.prim - first) as usize;
                let scalar = t.scalars.as_ref().and_then(|s| {
                    let a = hit.uv.x.clamp(0.0, 1.0);
                    Some((1.0 - a) * *s.get(k)? + a * *s.get(k + 1)?)
                });
                Surface { albedo: t.paint.color(scalar), normal: hit.normal, material: t.material }
            }
        }
    }

    fn bounds(&self) -> Aabb {
        self.scene
            .triangles
            .bounds()
            .union(self.scene.spheres.bounds())
            .union(self.scene.capsules.bounds())
    }
}
