//! GL's lighting state: the lights, the light model, the front material,
//! and how a primitive is shaded with them.

use glam::{Vec3, Vec4};

use super::texture::TexEnv;

use crate::gl;

/// A material's fixed-function parameters (one face).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialState {
    /// `GL_AMBIENT`.
    pub ambient: Vec4,
    /// `GL_DIFFUSE` (its alpha is the fragment's).
    pub diffuse: Vec4,
    /// `GL_SPECULAR`.
    pub specular: Vec4,
    /// `GL_EMISSION`.
    pub emission: Vec4,
    /// `GL_SHININESS`, `[0, 128]`.
    pub shininess: f32,
}

impl Default for MaterialState {
    fn default() -> Self {
        Self {
            ambient: Vec4::new(0.2, 0.2, 0.2, 1.0),
            diffuse: Vec4::new(0.8, 0.8, 0.8, 1.0),
            specular: Vec4::new(0.0, 0.0, 0.0, 1.0),
            emission: Vec4::new(0.0, 0.0, 0.0, 1.0),
            shininess: 0.0,
        }
    }
}

/// One of GL's eight lights, in eye space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightState {
    /// `glEnable(GL_LIGHTi)`.
    pub enabled: bool,
    /// `GL_AMBIENT`.
    pub ambient: Vec4,
    /// `GL_DIFFUSE`.
    pub diffuse: Vec4,
    /// `GL_SPECULAR`.
    pub specular: Vec4,
    /// `GL_POSITION` in eye space (`w = 0`: a direction toward the light).
    pub position: Vec4,
    /// `GL_SPOT_DIRECTION` in eye space.
    pub spot_direction: Vec3,
    /// `GL_SPOT_EXPONENT`.
    pub spot_exponent: f32,
    /// `GL_SPOT_CUTOFF` in degrees (180: no spot).
    pub spot_cutoff: f32,
    /// Constant, linear and quadratic attenuation.
    pub attenuation: Vec3,
}

impl LightState {
    fn new(index: usize) -> Self {
        // LIGHT0 is white by default; the others black.
        let c = if index == 0 { Vec4::ONE } else { Vec4::new(0.0, 0.0, 0.0, 1.0) };
        Self {
            enabled: false,
            ambient: Vec4::new(0.0, 0.0, 0.0, 1.0),
            diffuse: c,
            specular: c,
            position: Vec4::new(0.0, 0.0, 1.0, 0.0),
            spot_direction: Vec3::new(0.0, 0.0, -1.0),
            spot_exponent: 0.0,
            spot_cutoff: 180.0,
            attenuation: Vec3::new(1.0, 0.0, 0.0),
        }
    }
}

/// Everything about lighting that is global to a frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// The eight lights.
    pub lights: [LightState; 8],
    /// `GL_LIGHT_MODEL_AMBIENT`.
    pub model_ambient: Vec4,
    /// `GL_LIGHT_MODEL_TWO_SIDE`.
    pub two_side: bool,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            lights: core::array::from_fn(LightState::new),
            model_ambient: Vec4::new(0.2, 0.2, 0.2, 1.0),
            two_side: false,
        }
    }
}

/// GL's fog: the fragment's colour blended toward `color` by its eye
/// distance (OpenGL 2.1 §3.10).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fog {
    /// `GL_FOG_MODE`: `GL_LINEAR`, `GL_EXP` or `GL_EXP2`.
    pub mode: u32,
    /// `GL_FOG_DENSITY` (`GL_EXP`, `GL_EXP2`).
    pub density: f32,
    /// `GL_FOG_START` (`GL_LINEAR`).
    pub start: f32,
    /// `GL_FOG_END` (`GL_LINEAR`).
    pub end: f32,
    /// `GL_FOG_COLOR`.
    pub color: Vec4,
}

impl Default for Fog {
    fn default() -> Self {
        Self { mode: gl::EXP, density: 1.0, start: 0.0, end: 1.0, color: Vec4::ZERO }
    }
}

impl Fog {
    /// The share of the fragment's own colour at eye distance `z`
    /// (GL's `f`, clamped to `[0, 1]`).
    #[must_use]
    pub fn factor(&self, z: f32) -> f32 {
        let f = match self.mode {
            gl::LINEAR if self.end != self.start => (self.end - z) / (self.end - self.start),
            gl::LINEAR => 1.0,
            gl::EXP2 => (-(self.density * z) * (self.density * z)).exp(),
            _ => (-self.density * z).exp(),
        };
        if f.is_nan() { 1.0 } else { f.clamp(0.0, 1.0) }
    }
}

/// How a primitive is shaded, besides its vertices' colours and normals
/// (default: GL's initial state, unlit).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shading {
    /// `GL_LIGHTING` was on: the lighting equation; off: the colour.
    pub lit: bool,
    /// `glShadeModel(GL_FLAT)`: the provoking vertex's colour and normal.
    pub flat: bool,
    /// The front material.
    pub material: MaterialState,
    /// `GL_COLOR_MATERIAL` on: the parameter (`GL_AMBIENT_AND_DIFFUSE`, …)
    /// the vertex colour stands for.
    pub color_material: Option<u32>,
    /// `GL_NORMALIZE` or `GL_RESCALE_NORMAL` was on: normals are made
    /// unit before lighting. Off, GL lights with the normal as the
    /// modelview left it, so a scaled object lights brighter or darker,
    /// and so does the trace.
    pub normalize: bool,
    /// `GL_FOG` was on: the pass's [`Fog`] applies.
    pub fog: bool,
    /// `GL_BLEND` was on with `glBlendFunc(GL_SRC_ALPHA,
    /// GL_ONE_MINUS_SRC_ALPHA)`: the surface is seen through by its alpha.
    pub blend: bool,
    /// `GL_CULL_FACE` was on: the faces culled (`GL_BACK`, `GL_FRONT`,
    /// `GL_FRONT_AND_BACK`; 0: none). Rays pass through them.
    pub cull: u32,
    /// The 2-D texture applied (`GL_TEXTURE_2D` on, a complete texture
    /// bound), and how.
    pub texture: Option<TextureUse>,
    /// `GL_ALPHA_TEST` on: `glAlphaFunc`'s function and reference; rays
    /// pass through fragments it discards.
    pub alpha_test: Option<(u32, f32)>,
    /// Blended under `glDepthFunc(GL_EQUAL)`: after a depth-only pass of
    /// the same surfaces (the usual way to show only the nearest layer of
    /// a translucent object), only the nearest such surface on a ray
    /// shows.
    pub nearest_only: bool,
}

/// A texture as a primitive uses it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureUse {
    /// The texture object's name (looked up in the frame's textures).
    pub name: u32,
    /// The texture environment.
    pub env: TexEnv,
}

/// Whether alpha `a` passes GL's alpha test `(function, reference)`.
#[must_use]
pub fn alpha_passes((func, reference): (u32, f32), a: f32) -> bool {
    match func {
        gl::NEVER => false,
        gl::LESS => a < reference,
        gl::EQUAL => a == reference,
        gl::LEQUAL => a <= reference,
        gl::GREATER => a > reference,
        gl::NOTEQUAL => a != reference,
        gl::GEQUAL => a >= reference,
        _ => true,
    }
}

impl Shading {
    /// The material at a vertex of colour `color`.
    #[must_use]
    pub fn material_with(&self, color: Vec4) -> MaterialState {
        let mut m = self.material;
        if let Some(mode) = self.color_material {
            apply_color_material(&mut m, mode, color);
        }
        m
    }
}

pub(super) fn apply_color_material(m: &mut MaterialState, mode: u32, c: Vec4) {
    match mode {
        gl::AMBIENT => m.ambient = c,
        gl::DIFFUSE => m.diffuse = c,
        gl::SPECULAR => m.specular = c,
        gl::EMISSION => m.emission = c,
        gl::AMBIENT_AND_DIFFUSE => {
            m.ambient = c;
            m.diffuse = c;
        }
        _ => {}
    }
}
