//! One frame's draws, as the recorder hands them to the renderer: a
//! sequence of passes, each drawn under one projection and viewport.
//!
//! GL applies its projection, viewport and depth test per draw, so one
//! frame may hold a 3-D pass, a 2-D overlay in pixel coordinates drawn
//! over it, and a second 3-D pass in another viewport. The recorder
//! starts a new [`Pass`] whenever the view a draw is made under differs
//! from the last pass's, the depth buffer was cleared, or a lit (fogged)
//! draw sees other lights (fog) than the pass's earlier ones; the renderer traces
//! each 3-D pass in its own rectangle and composites them as GL's depth
//! buffer would (see `composite.rs`).

use std::{collections::HashMap, sync::Arc};

use glam::{Mat4, Vec4};

use super::{Fog, Geometry, GeometryError, Lighting, Recorded, Shading, texture::Texture};

/// Most passes kept in one frame: past it, draws join the last pass
/// (counted in [`Counters::passes_merged`](super::Counters::passes_merged)),
/// as a program that changes its lights for every object would otherwise
/// cost one trace of the viewport per object.
pub const MAX_PASSES: usize = 32;

/// What an instance of a display list takes from its call rather than
/// from its recording: lists that set no shading state of their own are
/// recorded once whatever colour and material they are called with (a
/// program may call one list a hundred times a frame, each time after
/// another colour), and each call paints its instance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Paint {
    /// The shading in force at the call, for every primitive.
    pub shading: Shading,
    /// The colour in force at the call.
    pub color: Vec4,
    /// How many of the recording's first vertices take `color` (those
    /// drawn before the list's own first `glColor`).
    pub vertices: u32,
}

/// One call of cached geometry.
#[derive(Clone, Debug)]
pub struct Instance {
    /// The geometry, in its entry space.
    pub recorded: Arc<Recorded>,
    /// The modelview at the call: entry space to eye space.
    pub transform: Mat4,
    /// What the call paints it with (`None`: as recorded).
    pub paint: Option<Paint>,
}

impl Instance {
    /// The instance's geometry in eye space, painted.
    ///
    /// # Errors
    /// What [`Geometry::check`] finds in the recording.
    pub fn flatten_into(&self, g: &mut Geometry) -> Result<(), GeometryError> {
        let own = self.recorded.geometry();
        own.check()?;
        let (v0, s0) = (g.positions.len(), g.shadings.len());
        g.append_checked(own, &self.transform);
        if let Some(p) = self.paint {
            let n = (p.vertices as usize).min(own.positions.len());
            g.colors[v0..v0 + n].fill(p.color);
            g.shadings[s0..].fill(p.shading);
        }
        Ok(())
    }
}

/// Draws of one pass (or, [`Frame::flatten`]ed, of a whole frame):
/// immediate geometry in eye space and instances of cached display lists.
#[derive(Clone, Debug, Default)]
pub struct FrameDraws {
    /// Immediate-mode geometry, eye space.
    pub immediate: Geometry,
    /// Calls of cached geometry.
    pub instances: Vec<Instance>,
    /// The lights in force at the pass's last lit draw (`None`: nothing
    /// lit was drawn): a program may turn its lights off after its 3-D
    /// pass, before the swap, as GL only applies them per draw.
    pub lighting: Option<Lighting>,
    /// The fog in force at the pass's last fogged draw (`None`: nothing
    /// fogged was drawn).
    pub fog: Option<Fog>,
    /// The texture objects at the frame's end, by name (what
    /// [`Shading::texture`] names).
    pub textures: Arc<HashMap<u32, Arc<Texture>>>,
    /// Rectangles drawn by pixel operations (`glBitmap`, `glDrawPixels`)
    /// in window coordinates `[x, y, width, height]`, with the raster
    /// position's window depth: GL's pixels, kept where they win.
    pub pixels: Vec<([i32; 4], f32)>,
}

impl FrameDraws {
    /// Whether nothing was drawn.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.immediate.is_empty()
            && self.pixels.is_empty()
            && self.instances.iter().all(|i| i.recorded.geometry().is_empty())
    }

    /// Everything in eye space, in one piece.
    ///
    /// # Errors
    /// What [`Geometry::check`] finds in the immediate geometry or in a
    /// recording's.
    pub fn flatten(&self) -> Result<Geometry, GeometryError> {
        self.immediate.check()?;
        let mut g = self.immediate.clone();
        for inst in &self.instances {
            inst.flatten_into(&mut g)?;
        }
        Ok(g)
    }
}

/// What a pass's draws were made under.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// The projection matrix.
    pub projection: Mat4,
    /// `glViewport` (all zero: never set, GL's initial viewport, the
    /// drawable's size).
    pub viewport: [i32; 4],
    /// `GL_DEPTH_TEST` was on.
    pub depth_test: bool,
    /// Texturing the trace does not do was on (1-D, 3-D or cube-map
    /// textures, generated coordinates): the pass's pixels are GL's own
    /// (see [`View::is_kept`]).
    pub textured: bool,
    /// The pass holds pixel operations (`glBitmap`, `glDrawPixels`),
    /// whose pixels are GL's own.
    pub pixels: bool,
}

impl View {
    /// Whether the pass is a 2-D overlay, shown as GL rasterized it rather
    /// than traced: an orthographic projection with the depth test off,
    /// or one that maps units to the pixels of `viewport` (the viewport
    /// in force, resolved when the pass's own was never set).
    #[must_use]
    pub fn is_overlay(&self, viewport: [i32; 4]) -> bool {
        self.is_2d(viewport)
    }

    /// Whether the pass is shown as GL drew it where it covers, not
    /// traced: a 2-D overlay ([`View::is_overlay`]), a pass of pixel
    /// operations or one textured as the trace cannot.
    #[must_use]
    pub fn is_kept(&self, viewport: [i32; 4]) -> bool {
        self.textured || self.pixels || self.is_2d(viewport)
    }

    fn is_2d(&self, viewport: [i32; 4]) -> bool {
        let p = &self.projection;
        let orthographic = p.row(3) == Vec4::W;
        // One unit per pixel, within 2 % (gluOrtho2D(0, w, 0, h) and its
        // flipped form (0, w, h, 0)).
        let pixels =
            |scale: f32, n: i32| n > 0 && (scale.abs() * n as f32 * 0.5 - 1.0).abs() < 0.02;
        orthographic
            && (!self.depth_test
                || (pixels(p.x_axis.x, viewport[2]) && pixels(p.y_axis.y, viewport[3])))
    }
}

/// One pass: draws made under one [`View`].
#[derive(Clone, Debug)]
pub struct Pass {
    /// What the draws were made under.
    pub view: View,
    /// The depth buffer was cleared just before the pass
    /// (`glClear(GL_DEPTH_BUFFER_BIT)` mid-frame): it draws over
    /// everything before it.
    pub depth_cleared: bool,
    /// The clear colour of the frame's last colour clear before the pass.
    pub background: Vec4,
    /// The draws.
    pub draws: FrameDraws,
}

/// One frame: its passes in the order they were drawn.
#[derive(Clone, Debug, Default)]
pub struct Frame {
    /// The passes, first drawn first.
    pub passes: Vec<Pass>,
}

impl Frame {
    /// Whether nothing was drawn.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.passes.iter().all(|p| p.draws.is_empty())
    }

    /// Every pass's draws together, in eye space (which all passes
    /// share): the immediate geometry appended, the instances and the
    /// last lighting kept.
    #[must_use]
    pub fn draws(self) -> FrameDraws {
        let mut all = FrameDraws::default();
        for p in self.passes {
            let d = p.draws;
            if all.immediate.is_empty() {
                all.immediate = d.immediate;
            } else {
                // Offsets indices only (saturating): what is malformed
                // stays malformed, for `check` to find.
                all.immediate.append_checked(&d.immediate, &Mat4::IDENTITY);
            }
            all.instances.extend(d.instances);
            all.lighting = d.lighting.or(all.lighting);
            all.fog = d.fog.or(all.fog);
            all.textures = d.textures;
            all.pixels.extend(d.pixels);
        }
        all
    }

    /// Everything in eye space, in one piece.
    ///
    /// # Errors
    /// What [`Geometry::check`] finds in a pass's geometry.
    pub fn flatten(&self) -> Result<Geometry, GeometryError> {
        let mut g = Geometry::default();
        for p in &self.passes {
            g.append_checked(&p.draws.flatten()?, &Mat4::IDENTITY);
        }
        Ok(g)
    }
}
