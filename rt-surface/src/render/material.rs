//! Materials and the seam between the renderer and a scene: what a hit
//! surface looks like ([`Surface`]) and the queries a scene answers
//! ([`ShadeScene`]).

use core::fmt;

use glam::Vec3;
use rt_core::{Aabb, Hit, SceneQuery};

/// How a surface reflects light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Lambertian weight of the albedo (0–1).
    pub diffuse: f32,
    /// Blinn–Phong specular weight (0–1), white highlights.
    pub specular: f32,
    /// Blinn–Phong exponent (> 0).
    pub shininess: f32,
    /// Opacity (0–1): below 1 the surface is composited `over` what lies
    /// behind it.
    pub opacity: f32,
    /// Mirror reflectance (0–1): that fraction of the colour comes from the
    /// reflected ray.
    pub mirror: f32,
}

impl Material {
    /// Opaque and purely diffuse.
    pub const MATTE: Self =
        Self { diffuse: 1.0, specular: 0.0, shininess: 32.0, opacity: 1.0, mirror: 0.0 };
    /// Opaque, diffuse with a highlight.
    pub const GLOSSY: Self =
        Self { diffuse: 0.8, specular: 0.3, shininess: 48.0, opacity: 1.0, mirror: 0.0 };

    /// Checks every weight is in `[0, 1]` and the exponent positive.
    ///
    /// # Errors
    /// The first bad parameter, as a [`MaterialError`].
    pub fn validate(&self) -> Result<(), MaterialError> {
        let unit = |v: f32| (0.0..=1.0).contains(&v);
        if !unit(self.diffuse) {
            Err(MaterialError::Diffuse)
        } else if !unit(self.specular) {
            Err(MaterialError::Specular)
        } else if !(self.shininess.is_finite() && self.shininess > 0.0) {
            Err(MaterialError::Shininess)
        } else if !unit(self.opacity) {
            Err(MaterialError::Opacity)
        } else if !unit(self.mirror) {
            Err(MaterialError::Mirror)
        } else {
            Ok(())
        }
    }
}

impl Default for Material {
    fn default() -> Self {
        Self::MATTE
    }
}

/// What the renderer needs to know about a hit surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// Linear RGB before lighting (e.g. a colour-mapped scalar).
    pub albedo: [f32; 3],
    /// Unit shading normal (interpolated or geometric); either side.
    pub normal: Vec3,
    /// How it reflects.
    pub material: Material,
}

/// A scene the renderer can shade: hits, occlusion, the surface at a hit
/// and the bounds of everything in it.
pub trait ShadeScene: SceneQuery {
    /// The surface at `hit` (one this scene returned).
    fn surface(&self, hit: &Hit) -> Surface;
    /// A box containing every primitive (empty for an empty scene).
    fn bounds(&self) -> Aabb;
}

/// Which parameter of a [`Material`] is out of range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MaterialError {
    /// `diffuse` is not in `[0, 1]` (or is NaN).
    Diffuse,
    /// `specular` is not in `[0, 1]` (or is NaN).
    Specular,
    /// `shininess` is not finite and positive.
    Shininess,
    /// `opacity` is not in `[0, 1]` (or is NaN).
    Opacity,
    /// `mirror` is not in `[0, 1]` (or is NaN).
    Mirror,
}

impl fmt::Display for MaterialError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Diffuse => "material diffuse must be in [0, 1]",
            Self::Specular => "material specular must be in [0, 1]",
            Self::Shininess => "material shininess must be finite and > 0",
            Self::Opacity => "material opacity must be in [0, 1]",
            Self::Mirror => "material mirror must be in [0, 1]",
        })
    }
}

impl core::error::Error for MaterialError {}
