//! The short way to assemble a scene.

use alloc::vec::Vec;

use rt_accel::BuildParams;

use super::{Glyphs, Paint, SceneError, SurfaceScene, Tube};
use crate::{Material, Mesh};

/// Collects a scene's objects, then builds it in one call: the short form
/// of [`SurfaceScene::build`]. BVHs are built with
/// [`BuildParams::medium`] unless [`SceneBuilder::params`] says otherwise.
///
/// ```
/// use rt_surface::{Material, Mesh, Paint, SurfaceScene, rt_core::{ColorMap, glam::Vec3}};
///
/// let mesh = Mesh::new(
///     vec![Vec3::ZERO, Vec3::X, Vec3::Y],
///     vec![[0, 1, 2]],
///     Some(vec![0.0, 1.0, 2.0]),
/// )?;
/// let scene = SurfaceScene::builder()
///     .mesh(mesh, Paint::Mapped(ColorMap::viridis()), Material::GLOSSY)
///     .build()?;
/// assert_eq!(scene.triangle_count(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug, Default)]
#[must_use]
pub struct SceneBuilder<'m> {
    meshes: Vec<(Mesh, Paint<'m>, Material)>,
    glyphs: Vec<Glyphs<'m>>,
    tubes: Vec<Tube<'m>>,
    params: BuildParams,
}

impl<'m> SceneBuilder<'m> {
    /// An empty scene.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a mesh (a [`Mesh`], or plain [`rt_accel::TriangleMesh`]
    /// geometry) painted and shaded as given.
    pub fn mesh(mut self, mesh: impl Into<Mesh>, paint: Paint<'m>, material: Material) -> Self {
        self.meshes.push((mesh.into(), paint, material));
        self
    }

    /// Adds a set of sphere glyphs.
    pub fn glyphs(mut self, glyphs: Glyphs<'m>) -> Self {
        self.glyphs.push(glyphs);
        self
    }

    /// Adds a tube.
    pub fn tube(mut self, tube: Tube<'m>) -> Self {
        self.tubes.push(tube);
        self
    }

    /// BVH build settings (default [`BuildParams::medium`]).
    pub fn params(mut self, params: BuildParams) -> Self {
        self.params = params;
        self
    }

    /// Builds the scene.
    ///
    /// # Errors
    /// As [`SurfaceScene::build`].
    pub fn build(self) -> Result<SurfaceScene<'m>, SceneError> {
        SurfaceScene::build(self.meshes, self.glyphs, self.tubes, &self.params)
    }
}
