//! The recorder's state machine: matrix stacks, current attributes,
//! lights and materials, and the dispatch of each call.

use std::{
    collections::{BTreeMap, HashMap},
    sync::Arc,
};

use glam::{Mat3, Mat4, Vec3, Vec4};

use super::{
    Command, Counters, Fog, Frame, FrameDraws, LIST_BUDGET, Lighting, MAX_PASSES, MaterialState,
    Pass, Recorded, Shading, TextureUse, View,
    arrays::{ArrayState, DrawKey},
    assemble::Vert,
    capture::{Capture, Inherited},
    lighting::apply_color_material,
    lists::List,
    texture::{self, BaseFormat, PixelStore, TexEnv, Texture},
};
use crate::gl;

/// Deepest matrix stack kept (GL guarantees 32 modelview entries).
pub const MAX_STACK: usize = 256;

/// The fixed-function state machine; see the [module documentation](super).
pub struct Recorder {
    modelview: Vec<Mat4>,
    projection: Vec<Mat4>,
    texture: Vec<Mat4>,
    matrix_mode: u32,
    /// `glViewport(x, y, width, height)`.
    pub viewport: [i32; 4],
    /// `glClearColor`.
    pub clear_color: Vec4,
    pub(super) color: Vec4,
    pub(super) normal: Vec3,
    /// `glTexCoord`.
    pub(super) texcoord: Vec4,
    /// Texture objects by name (level 0), the one bound to
    /// `GL_TEXTURE_2D`, unit 0's environment, the unpack state, whether
    /// unit 0 is the active one, and `GL_TEXTURE_GEN_*` switches.
    pub(super) textures: HashMap<u32, Arc<Texture>>,
    bound_texture: u32,
    tex_env: TexEnv,
    /// `glPixelStore`'s unpack state.
    pub unpack: PixelStore,
    unit0: bool,
    /// `GL_TEXTURE_GEN_S`…`_Q` on (a bit each), their modes, object and
    /// eye planes (eye planes as GL keeps them: times the inverse
    /// modelview at the call).
    texgen: u8,
    pub(super) texgen_mode: [u32; 4],
    pub(super) texgen_planes: [[Vec4; 2]; 4],
    /// `glDepthFunc`.
    depth_func: u32,
    /// The current raster position: window coordinates and depth
    /// (`None`: invalid, pixel operations draw nothing).
    raster_pos: Option<Vec3>,
    /// `GL_ALPHA_TEST` and `glAlphaFunc`.
    alpha_test_on: bool,
    alpha_func: (u32, f32),
    pub(super) point_size: f32,
    pub(super) line_width: f32,
    lit: bool,
    flat: bool,
    /// `GL_NORMALIZE` or `GL_RESCALE_NORMAL` is on.
    normalize: [bool; 2],
    /// `GL_FOG` is on, and the fog.
    fog_on: bool,
    fog: Fog,
    /// `GL_BLEND` is on; the blend function is (source alpha, one minus
    /// source alpha).
    blend_on: bool,
    blend_over: bool,
    /// `GL_CULL_FACE` is on; `glCullFace`.
    cull_on: bool,
    cull_face: u32,
    /// `glColorMask`: some channel is written. Draws made with none are
    /// depth-only passes, not seen: they are not recorded.
    pub(super) color_write: bool,
    /// `glPolygonMode`: front and back.
    pub(super) polygon_mode: [u32; 2],
    color_material_on: bool,
    color_material: (u32, u32),
    front: MaterialState,
    /// The lights (eye space) and light model.
    pub lighting: Lighting,
    pub(super) lists: HashMap<u32, List>,
    pub(super) list_base: u32,
    /// Bumped whenever a list is defined or deleted.
    pub(super) generation: u64,
    pub(super) compiling: Option<(u32, u32, Vec<Command>)>,
    pub(super) begin: Option<(u32, Vec<Vert>)>,
    pub(super) capture: Option<Capture>,
    /// > 0 while replaying a cached list for its state changes only.
    pub(super) state_only: u32,
    pub(super) depth: u32,
    /// Commands the current top-level list call may still execute.
    pub(super) budget: u64,
    pub(super) list_budget: u64,
    /// Per list: its recordings, each with the calling state it was
    /// recorded for and how many of its first vertices took the caller's
    /// colour.
    pub(super) cache: HashMap<u32, Vec<(Inherited, Arc<Recorded>, u32)>>,
    pub(super) frame: Frame,
    /// `GL_DEPTH_TEST` is on.
    depth_test: bool,
    /// Which texture targets are on (a bit each).
    texture_targets: u8,
    /// `GL_SCISSOR_TEST` is on (a colour clear then clears a rectangle,
    /// not the frame).
    scissor: bool,
    /// The clear colour of the last colour clear.
    background: Vec4,
    /// The depth buffer was cleared since the last draw.
    depth_cleared: bool,
    /// Vertex arrays and buffer objects.
    pub(super) arrays: ArrayState,
    pub(super) draw_cache: HashMap<DrawKey, (Inherited, Arc<Recorded>)>,
    /// Per draw shape ([`DrawKey::shape`]): the key of its latest entry in
    /// `draw_cache`, whose BVHs the next recording of the shape refits.
    pub(super) draw_shapes: HashMap<DrawKey, DrawKey>,
    /// `glFrontFace(GL_CW)`: clockwise triangles face front.
    pub(super) front_cw: bool,
    /// What has been done so far.
    pub counters: Counters,
    /// GL features the program used that the trace does not honour, by
    /// name (`GL_BLEND`, `glRect`, …), with how often they were used.
    pub unsupported: BTreeMap<&'static str, u64>,
}

impl Default for Recorder {
    fn default() -> Self {
        Self::new()
    }
}

impl Recorder {
    /// GL's initial state.
    #[must_use]
    pub fn new() -> Self {
        Self {
            modelview: vec![Mat4::IDENTITY],
            projection: vec![Mat4::IDENTITY],
            texture: vec![Mat4::IDENTITY],
            matrix_mode: gl::MODELVIEW,
            viewport: [0, 0, 0, 0],
            clear_color: Vec4::ZERO,
            color: Vec4::ONE,
            normal: Vec3::Z,
            texcoord: Vec4::W,
            textures: HashMap::new(),
            bound_texture: 0,
            tex_env: TexEnv::default(),
            unpack: PixelStore::default(),
            unit0: true,
            texgen: 0,
            texgen_mode: [gl::EYE_LINEAR; 4],
            texgen_planes: [
                [Vec4::X, Vec4::X],
                [Vec4::Y, Vec4::Y],
                [Vec4::ZERO, Vec4::ZERO],
                [Vec4::ZERO, Vec4::ZERO],
            ],
            alpha_test_on: false,
            depth_func: gl::LESS,
            raster_pos: Some(Vec3::ZERO),
            alpha_func: (gl::ALWAYS, 0.0),
            point_size: 1.0,
            line_width: 1.0,
            lit: false,
            flat: false,
            normalize: [false; 2],
            fog_on: false,
            fog: Fog::default(),
            blend_on: false,
            blend_over: false,
            polygon_mode: [gl::FILL; 2],
            cull_on: false,
            color_write: true,
            cull_face: gl::BACK,
            color_material_on: false,
            color_material: (gl::FRONT_AND_BACK, gl::AMBIENT_AND_DIFFUSE),
            front: MaterialState::default(),
            lighting: Lighting::default(),
            lists: HashMap::new(),
            list_base: 0,
            generation: 0,
            compiling: None,
            begin: None,
            capture: None,
            state_only: 0,
            depth: 0,
            budget: LIST_BUDGET,
            list_budget: LIST_BUDGET,
            cache: HashMap::new(),
            frame: Frame::default(),
            depth_test: false,
            texture_targets: 0,
            scissor: false,
            background: Vec4::ZERO,
            depth_cleared: false,
            arrays: ArrayState::default(),
            draw_cache: HashMap::new(),
            draw_shapes: HashMap::new(),
            front_cw: false,
            counters: Counters::default(),
            unsupported: BTreeMap::new(),
        }
    }

    /// The current modelview matrix.
    #[must_use]
    pub fn modelview(&self) -> Mat4 {
        *self.modelview.last().unwrap_or(&Mat4::IDENTITY)
    }

    /// The current texture matrix.
    #[must_use]
    pub fn texture_matrix(&self) -> Mat4 {
        *self.texture.last().unwrap_or(&Mat4::IDENTITY)
    }

    /// The current projection matrix.
    #[must_use]
    pub fn projection(&self) -> Mat4 {
        *self.projection.last().unwrap_or(&Mat4::IDENTITY)
    }

    /// The frame drawn so far.
    #[must_use]
    pub fn frame(&self) -> &Frame {
        &self.frame
    }

    /// What a draw made now is made under.
    #[must_use]
    pub fn view(&self) -> View {
        View {
            projection: self.projection(),
            viewport: self.viewport,
            depth_test: self.depth_test,
            textured: self.untraced_texturing(),
            pixels: false,
        }
    }

    /// Where a pixel operation (`glBitmap`, `glDrawPixels`) draws: a pass
    /// of its own, kept as GL drew it.
    fn pixel_rect(&mut self, rect: [i32; 4], depth: f32) {
        let view = View { pixels: true, ..self.view() };
        let split = self.frame.passes.last().is_none_or(|p| p.view != view || self.depth_cleared);
        if split && self.frame.passes.len() < MAX_PASSES {
            self.frame.passes.push(Pass {
                view,
                depth_cleared: core::mem::take(&mut self.depth_cleared),
                background: self.background,
                draws: FrameDraws::default(),
            });
        } else if split {
            self.counters.passes_merged += 1;
        }
        if let Some(p) = self.frame.passes.last_mut() {
            p.draws.pixels.push((rect, depth));
        }
    }

    /// The window coordinates and depth of object point `v` under the
    /// current matrices and viewport, if it is inside the clip volume
    /// (`glRasterPos`).
    fn window_of(&self, v: Vec4) -> Option<Vec3> {
        let c = self.projection() * (self.modelview() * v);
        let inside = c.w > 0.0 && c.truncate().abs().cmple(Vec3::splat(c.w)).all();
        let [x, y, w, h] = self.viewport;
        (inside && w > 0 && h > 0).then(|| {
            let n = c.truncate() / c.w;
            Vec3::new(
                x as f32 + (n.x + 1.0) * 0.5 * w as f32,
                y as f32 + (n.y + 1.0) * 0.5 * h as f32,
                (n.z + 1.0) * 0.5,
            )
        })
    }

    /// The pass a draw made now goes into (`lit`, `fogged`: the draw is
    /// lit, fogged): the last one, or a new one if the view changed, the
    /// depth buffer was cleared, or a lit (fogged) draw sees other lights
    /// (fog) than the pass's.
    pub(super) fn draws(&mut self, lit: bool, fogged: bool) -> &mut FrameDraws {
        let view = self.view();
        let split = self.frame.passes.last().is_none_or(|p| {
            p.view != view
                || self.depth_cleared
                || (lit && p.draws.lighting.as_ref().is_some_and(|l| *l != self.lighting))
                || (fogged && p.draws.fog.is_some_and(|f| f != self.fog))
        });
        if split && self.frame.passes.len() >= MAX_PASSES {
            self.counters.passes_merged += 1;
        } else if split {
            self.frame.passes.push(Pass {
                view,
                depth_cleared: core::mem::take(&mut self.depth_cleared),
                background: self.background,
                draws: FrameDraws::default(),
            });
        }
        let lighting = lit.then(|| self.lighting.clone());
        let fog = self.fog;
        let pass = self.frame.passes.last_mut().expect("a pass was just pushed if none");
        if lighting.is_some() {
            pass.draws.lighting = lighting;
        }
        if fogged {
            pass.draws.fog = Some(fog);
        }
        &mut pass.draws
    }

    /// Whether a display list is being compiled with `GL_COMPILE` (calls
    /// are stored, not executed).
    #[must_use]
    pub fn compiling_only(&self) -> bool {
        matches!(self.compiling, Some((_, gl::COMPILE, _)))
    }

    /// Ends the frame: returns what was drawn and starts an empty one.
    pub fn end_frame(&mut self) -> Frame {
        let draws = || self.frame.passes.iter().map(|p| &p.draws);
        self.counters.frames += 1;
        self.counters.passes = self.frame.passes.len() as u64;
        self.counters.instances = draws().map(|d| d.instances.len()).sum::<usize>() as u64;
        self.counters.triangles = draws()
            .map(|d| {
                d.immediate.triangles.len()
                    + d.instances
                        .iter()
                        .map(|i| i.recorded.geometry().triangles.len())
                        .sum::<usize>()
            })
            .sum::<usize>() as u64;
        self.depth_cleared = false;
        let textures = Arc::new(self.textures.clone());
        let mut frame = core::mem::take(&mut self.frame);
        for p in &mut frame.passes {
            p.draws.textures = Arc::clone(&textures);
        }
        frame
    }

    /// `glClear(mask)`: clearing the colour buffer starts the frame over
    /// (unless the scissor test limits it to a rectangle: then only the
    /// passes after it take its colour); clearing the depth buffer alone
    /// makes the next draws a pass drawn over everything before.
    pub fn clear(&mut self, mask: u32) {
        if self.compiling_only() {
            return;
        }
        let color = mask & gl::COLOR_BUFFER_BIT != 0;
        if color {
            self.background = self.clear_color;
        }
        if color && !self.scissor {
            self.frame = Frame::default();
            self.depth_cleared = false;
        } else if mask & gl::DEPTH_BUFFER_BIT != 0 && !self.frame.passes.is_empty() {
            self.depth_cleared = true;
        }
    }

    /// Records or executes one call, as GL would in the current list mode.
    pub fn command(&mut self, c: Command) {
        if let Some((_, mode, commands)) = &mut self.compiling {
            commands.push(c.clone());
            if *mode == gl::COMPILE {
                return;
            }
        }
        self.execute(&c);
    }

    fn stack(&mut self) -> &mut Vec<Mat4> {
        match self.matrix_mode {
            gl::PROJECTION => &mut self.projection,
            gl::TEXTURE => &mut self.texture,
            _ => &mut self.modelview,
        }
    }

    fn top(&mut self) -> &mut Mat4 {
        let s = self.stack();
        if s.is_empty() {
            s.push(Mat4::IDENTITY);
        }
        s.last_mut().expect("non-empty")
    }

    pub(super) fn shading(&self) -> Shading {
        let mut material = self.front;
        // What colour material covers is the vertex colour at shading
        // time: kept constant here, so colours alone make no new shading.
        if self.color_material_on {
            apply_color_material(&mut material, self.color_material.1, Vec4::ZERO);
        }
        Shading {
            lit: self.lit,
            normalize: self.normalize[0] || self.normalize[1],
            fog: self.fog_on,
            blend: self.blend_on && self.blend_over,
            cull: if self.cull_on { self.cull_face } else { 0 },
            texture: self.texture_use(),
            alpha_test: self.alpha_test_on.then_some(self.alpha_func),
            nearest_only: self.blend_on && self.blend_over && self.depth_func == gl::EQUAL,
            flat: self.flat,
            material,
            color_material: self.color_material_on.then_some(self.color_material.1),
        }
    }

    pub(super) fn execute(&mut self, c: &Command) {
        match *c {
            Command::Begin(mode) => {
                if self.begin.is_some() || mode > gl::POLYGON {
                    self.counters.ignored += 1;
                } else {
                    self.begin = Some((mode, Vec::new()));
                }
            }
            Command::End => match self.begin.take() {
                Some((mode, verts)) => {
                    if self.state_only == 0 {
                        self.assemble(mode, &verts);
                    }
                }
                None => self.counters.ignored += 1,
            },
            Command::Vertex(v) => self.vertex(v),
            Command::Normal(n) => self.normal = n,
            Command::Color(col) => {
                self.color = col;
                if let Some(c) = &mut self.capture {
                    // The vertices so far took the caller's colour.
                    let pending = self.begin.as_ref().map_or(0, |(_, v)| v.len());
                    c.color_from.get_or_insert(c.geometry.positions.len() + pending);
                }
                if self.color_material_on {
                    apply_color_material(&mut self.front, self.color_material.1, col);
                }
            }
            Command::MatrixMode(m) => {
                if matches!(m, gl::MODELVIEW | gl::PROJECTION | gl::TEXTURE) {
                    self.matrix_mode = m;
                } else {
                    self.counters.ignored += 1;
                }
            }
            Command::LoadIdentity => *self.top() = Mat4::IDENTITY,
            Command::LoadMatrix(m) => *self.top() = m,
            Command::MultMatrix(m) => {
                *self.top() *= m;
            }
            Command::PushMatrix => {
                let s = self.stack();
                match s.last().copied() {
                    Some(top) if s.len() < MAX_STACK => s.push(top),
                    _ => self.counters.ignored += 1,
                }
            }
            Command::PopMatrix => {
                let s = self.stack();
                if s.len() > 1 {
                    s.pop();
                } else {
                    self.counters.ignored += 1;
                }
            }
            Command::Enable(cap) => self.set_cap(cap, true),
            Command::Disable(cap) => self.set_cap(cap, false),
            Command::Light(light, pname, v) => self.light(light, pname, v),
            Command::LightModel(pname, v) => match pname {
                gl::LIGHT_MODEL_AMBIENT => self.lighting.model_ambient = v,
                gl::LIGHT_MODEL_TWO_SIDE => self.lighting.two_side = v.x != 0.0,
                _ => {}
            },
            Command::Material(face, pname, v) => {
                // Back materials are not kept: one-sided lighting, and
                // two-sided lighting with the front material on both sides.
                if face == gl::FRONT || face == gl::FRONT_AND_BACK {
                    let m = &mut self.front;
                    match pname {
                        gl::SHININESS => m.shininess = v.x.clamp(0.0, 128.0),
                        mode => apply_color_material(m, mode, v),
                    }
                }
            }
            Command::ColorMaterial(face, mode) => {
                self.color_material = (face, mode);
                if self.color_material_on {
                    apply_color_material(&mut self.front, mode, self.color);
                }
            }
            Command::ShadeModel(m) => self.flat = m == gl::FLAT,
            Command::FrontFace(m) => self.front_cw = m == gl::CW,
            Command::PointSize(s) => {
                if s > 0.0 && s.is_finite() {
                    self.point_size = s;
                }
            }
            Command::LineWidth(w) => {
                if w > 0.0 && w.is_finite() {
                    self.line_width = w;
                }
            }
            Command::CallList(id) => self.call_list(id),
            Command::PolygonMode(face, mode) => {
                if matches!(mode, gl::POINT | gl::LINE | gl::FILL) {
                    match face {
                        gl::FRONT => self.polygon_mode[0] = mode,
                        gl::BACK => self.polygon_mode[1] = mode,
                        gl::FRONT_AND_BACK => self.polygon_mode = [mode; 2],
                        _ => self.counters.ignored += 1,
                    }
                } else {
                    self.counters.ignored += 1;
                }
            }
            Command::Fog(pname, v) => match pname {
                gl::FOG_MODE if matches!(v.x as u32, gl::LINEAR | gl::EXP | gl::EXP2) => {
                    self.fog.mode = v.x as u32;
                }
                gl::FOG_DENSITY if v.x >= 0.0 => self.fog.density = v.x,
                gl::FOG_START => self.fog.start = v.x,
                gl::FOG_END => self.fog.end = v.x,
                gl::FOG_COLOR => self.fog.color = v.clamp(Vec4::ZERO, Vec4::ONE),
                _ => self.counters.ignored += 1,
            },
            Command::ColorMask(any) => self.color_write = any,
            Command::TexCoord(t) => self.texcoord = t,
            Command::BindTexture(target, name) => {
                if target == gl::TEXTURE_2D && self.unit0 {
                    self.bound_texture = name;
                }
            }
            Command::TexEnv(pname, v) => {
                if self.unit0 {
                    match pname {
                        gl::TEXTURE_ENV_MODE => self.tex_env.mode = v.x as u32,
                        gl::TEXTURE_ENV_COLOR => {
                            self.tex_env.color = v.clamp(Vec4::ZERO, Vec4::ONE);
                        }
                        _ => {}
                    }
                }
            }
            Command::DepthFunc(func) => self.depth_func = func,
            Command::TexGen(coord, pname, v) => {
                let Some(i) = coord.checked_sub(gl::S).filter(|&i| i < 4 && self.unit0) else {
                    self.counters.ignored += 1;
                    return;
                };
                let i = i as usize;
                match pname {
                    gl::TEXTURE_GEN_MODE => self.texgen_mode[i] = v.x as u32,
                    gl::OBJECT_PLANE => self.texgen_planes[i][0] = v,
                    gl::EYE_PLANE => {
                        // GL: (p1 p2 p3 p4) times the inverse modelview.
                        let inv = Self::to_local(&self.modelview()).unwrap_or(Mat4::IDENTITY);
                        self.texgen_planes[i][1] = inv.transpose() * v;
                    }
                    _ => self.counters.ignored += 1,
                }
            }
            Command::RasterPos(v) => self.raster_pos = self.window_of(v),
            Command::WindowPos(p) => self.raster_pos = Some(p),
            Command::Bitmap { size: [w, h], origin, advance } => {
                if let Some(p) = self.raster_pos {
                    if w > 0 && h > 0 {
                        let at = (p.truncate() - origin).floor();
                        self.pixel_rect([at.x as i32, at.y as i32, w, h], p.z);
                    }
                    self.raster_pos = Some(p + advance.extend(0.0));
                }
            }
            Command::DrawPixels([w, h]) => {
                if let (Some(p), true) = (self.raster_pos, w > 0 && h > 0) {
                    self.pixel_rect([p.x as i32, p.y as i32, w, h], p.z);
                }
            }
            Command::AlphaFunc(func, reference) => {
                self.alpha_func = (func, reference.clamp(0.0, 1.0));
            }
            Command::CullFace(face) => match face {
                gl::FRONT | gl::BACK | gl::FRONT_AND_BACK => self.cull_face = face,
                _ => self.counters.ignored += 1,
            },
            Command::BlendFunc(src, dst) => {
                self.blend_over = (src, dst) == (gl::SRC_ALPHA, gl::ONE_MINUS_SRC_ALPHA);
                if !self.blend_over {
                    self.unsupported("glBlendFunc.other_than_src_alpha");
                }
            }
        }
    }

    /// Texturing the trace does not do: 1-D, 3-D or cube-map textures,
    /// generated texture coordinates, or a 2-D texture whose image could
    /// not be read.
    fn untraced_texturing(&self) -> bool {
        let on_2d = self.texture_targets & 2 != 0;
        let unread = || self.textures.get(&self.bound_texture).is_some_and(|t| !t.readable);
        // Normal and reflection maps (cube-map coordinates) are not made.
        let odd_gen = (0..4).any(|i| {
            self.texgen & (1 << i) != 0
                && !matches!(
                    self.texgen_mode[i],
                    gl::OBJECT_LINEAR | gl::EYE_LINEAR | gl::SPHERE_MAP
                )
        });
        self.texture_targets & !2 != 0 || (on_2d && (odd_gen || unread()))
    }

    /// Whether texture coordinates depend on where a draw is seen from
    /// (`glTexGen` eye-linear or sphere-map): such draws are not cached
    /// in entry space.
    pub(super) fn view_dependent_texgen(&self) -> bool {
        (0..4).any(|i| self.texgen & (1 << i) != 0 && self.texgen_mode[i] != gl::OBJECT_LINEAR)
    }

    /// The texture coordinates of a vertex at object position `v`, eye
    /// position `e` and eye normal `n`: the current ones, with those
    /// `glTexGen` generates in their place (GL 2.1 §2.12.4).
    pub(super) fn generated_texcoord(&self, v: Vec4, e: Vec4, n: Vec3) -> Vec4 {
        let mut t = self.texcoord;
        if self.texgen == 0 {
            return t;
        }
        let sphere = || {
            let u = (e.truncate() / e.w).normalize_or_zero();
            let n = n.normalize_or_zero();
            let r = u - 2.0 * n.dot(u) * n;
            let m = 2.0 * (r.x * r.x + r.y * r.y + (r.z + 1.0) * (r.z + 1.0)).sqrt();
            if m > 0.0 { [r.x / m + 0.5, r.y / m + 0.5] } else { [0.5, 0.5] }
        };
        for i in 0..4 {
            if self.texgen & (1 << i) == 0 {
                continue;
            }
            t[i] = match self.texgen_mode[i] {
                gl::OBJECT_LINEAR => self.texgen_planes[i][0].dot(v),
                gl::EYE_LINEAR => self.texgen_planes[i][1].dot(e),
                gl::SPHERE_MAP if i < 2 => sphere()[i],
                _ => t[i],
            };
        }
        t
    }

    /// The 2-D texture a draw made now is textured with.
    fn texture_use(&self) -> Option<TextureUse> {
        let on = self.texture_targets & 2 != 0;
        let complete =
            self.textures.get(&self.bound_texture).is_some_and(|t| t.is_complete() && t.readable);
        (on && complete).then_some(TextureUse { name: self.bound_texture, env: self.tex_env })
    }

    /// `glActiveTexture(unit)`: only unit 0 (`GL_TEXTURE0`) is traced;
    /// texture calls for the others are left to GL.
    pub fn active_texture(&mut self, unit: u32) {
        self.unit0 = unit == 0x84C0;
        if !self.unit0 {
            self.unsupported("glActiveTexture.other_units");
        }
    }

    /// The bound 2-D texture object, made if it does not exist yet.
    fn bound_2d(&mut self) -> &mut Texture {
        Arc::make_mut(self.textures.entry(self.bound_texture).or_default())
    }

    /// `glTexImage2D(GL_TEXTURE_2D, level, internal, width, height, …)`
    /// with the client image `data` (spanning
    /// [`PixelStore::image_bytes`]; `None`: no image, the texels
    /// undefined). Levels other than 0 are not kept.
    #[allow(clippy::too_many_arguments)]
    pub fn tex_image_2d(
        &mut self,
        target: u32,
        level: i32,
        internal: u32,
        [width, height]: [i32; 2],
        format: u32,
        ty: u32,
        data: Option<&[u8]>,
    ) {
        if target != gl::TEXTURE_2D || level != 0 || !self.unit0 {
            return;
        }
        let max = texture::MAX_TEXTURE_SIZE as i32;
        if !(0..=max).contains(&width) || !(0..=max).contains(&height) {
            self.counters.ignored += 1;
            return;
        }
        let unpack = self.unpack;
        let n = width as usize * height as usize;
        let mut texels = Vec::new();
        // The host program must not be aborted by a copy it never asked
        // for: a texture too large to shadow is left to GL.
        let fits = texels.try_reserve_exact(n).is_ok();
        let t = self.bound_2d();
        t.width = width as u32;
        t.height = height as u32;
        t.format = BaseFormat::of(internal);
        if !fits {
            t.readable = false;
            t.texels = Vec::new();
            self.unsupported("glTexImage2D.too_large");
            return;
        }
        texels.resize(n, [255; 4]);
        t.texels = texels;
        let size = [width as usize, height as usize];
        // No data: texels GL leaves undefined, for glTexSubImage2D.
        t.readable = data.is_none_or(|d| t.store([0, 0], size, format, ty, d, &unpack));
        if !t.readable {
            self.unsupported("glTexImage2D.unread_format");
        }
    }

    /// `glTexSubImage2D(GL_TEXTURE_2D, 0, x, y, width, height, …)` with
    /// the client image `data` (`None`: not readable, as from a pixel
    /// buffer object).
    #[allow(clippy::too_many_arguments)]
    pub fn tex_sub_image_2d(
        &mut self,
        target: u32,
        level: i32,
        [x, y]: [i32; 2],
        [width, height]: [i32; 2],
        format: u32,
        ty: u32,
        data: Option<&[u8]>,
    ) {
        if target != gl::TEXTURE_2D || level != 0 || !self.unit0 {
            return;
        }
        if x < 0 || y < 0 || width < 0 || height < 0 {
            self.counters.ignored += 1;
            return;
        }
        let unpack = self.unpack;
        let t = self.bound_2d();
        let at = [x as usize, y as usize];
        let size = [width as usize, height as usize];
        if !data.is_some_and(|d| t.store(at, size, format, ty, d, &unpack)) {
            t.readable = false;
            self.unsupported("glTexSubImage2D.unread_format");
        }
    }

    /// `glTexParameter*(GL_TEXTURE_2D, pname, value)`.
    pub fn tex_parameter(&mut self, target: u32, pname: u32, value: f32) {
        if target != gl::TEXTURE_2D || !self.unit0 {
            return;
        }
        let v = value as u32;
        match pname {
            gl::TEXTURE_WRAP_S => self.bound_2d().wrap[0] = v,
            gl::TEXTURE_WRAP_T => self.bound_2d().wrap[1] = v,
            gl::TEXTURE_MAG_FILTER => self.bound_2d().linear[0] = v != gl::NEAREST,
            // LINEAR and LINEAR_MIPMAP_* filter linearly within a level.
            gl::TEXTURE_MIN_FILTER => {
                self.bound_2d().linear[1] = matches!(v, 0x2601 | 0x2701 | 0x2703);
            }
            _ => {}
        }
    }

    /// The texture objects by name (level 0 and parameters).
    #[must_use]
    pub fn textures(&self) -> &HashMap<u32, Arc<Texture>> {
        &self.textures
    }

    /// `glDeleteTextures`.
    pub fn delete_textures(&mut self, names: &[u32]) {
        for n in names {
            self.textures.remove(n);
        }
    }

    /// `glPixelStorei(pname, value)` (the unpack state; packing is GL's).
    pub fn pixel_store(&mut self, pname: u32, value: i32) {
        let Ok(v) = usize::try_from(value) else { return };
        match pname {
            0x0CF5 if matches!(v, 1 | 2 | 4 | 8) => self.unpack.alignment = v,
            0x0CF2 => self.unpack.row_length = v,
            0x0CF3 => self.unpack.skip_rows = v,
            0x0CF4 => self.unpack.skip_pixels = v,
            _ => {}
        }
    }

    /// Notes one use of a GL feature the trace does not honour.
    pub fn unsupported(&mut self, what: &'static str) {
        *self.unsupported.entry(what).or_insert(0) += 1;
    }

    fn set_cap(&mut self, cap: u32, on: bool) {
        if let (true, Some(what)) = (on, unsupported_cap(cap)) {
            self.unsupported(what);
        }
        match cap {
            gl::LIGHTING => self.lit = on,
            gl::NORMALIZE => self.normalize[0] = on,
            gl::FOG => self.fog_on = on,
            gl::BLEND => self.blend_on = on,
            gl::CULL_FACE => self.cull_on = on,
            gl::ALPHA_TEST => self.alpha_test_on = on,
            0x0C60..=0x0C63 if self.unit0 => {
                let bit = 1 << (cap - 0x0C60);
                self.texgen = if on { self.texgen | bit } else { self.texgen & !bit };
            }
            gl::RESCALE_NORMAL => self.normalize[1] = on,
            gl::DEPTH_TEST => self.depth_test = on,
            // One texture unit's targets: any on makes draws textured.
            0x0DE0 | 0x0DE1 | 0x806F | 0x8513 => {
                let bit = match cap {
                    0x0DE0 => 1,
                    0x0DE1 => 2,
                    0x806F => 4,
                    _ => 8,
                };
                if self.unit0 {
                    self.texture_targets =
                        if on { self.texture_targets | bit } else { self.texture_targets & !bit };
                }
            }
            gl::SCISSOR_TEST => self.scissor = on,
            gl::COLOR_MATERIAL => {
                self.color_material_on = on;
                if on {
                    apply_color_material(&mut self.front, self.color_material.1, self.color);
                }
            }
            c if (gl::LIGHT0..gl::LIGHT0 + 8).contains(&c) => {
                self.lighting.lights[(c - gl::LIGHT0) as usize].enabled = on;
            }
            _ => {}
        }
    }

    fn light(&mut self, light: u32, pname: u32, v: Vec4) {
        let Some(i) = light.checked_sub(gl::LIGHT0).filter(|&i| i < 8) else {
            self.counters.ignored += 1;
            return;
        };
        let mv = self.modelview();
        let l = &mut self.lighting.lights[i as usize];
        match pname {
            gl::AMBIENT => l.ambient = v,
            gl::DIFFUSE => l.diffuse = v,
            gl::SPECULAR => l.specular = v,
            // Positions and directions are kept in eye space, as GL does.
            gl::POSITION => l.position = mv * v,
            gl::SPOT_DIRECTION => l.spot_direction = Mat3::from_mat4(mv) * v.truncate(),
            gl::SPOT_EXPONENT => l.spot_exponent = v.x,
            gl::SPOT_CUTOFF => l.spot_cutoff = v.x,
            gl::CONSTANT_ATTENUATION => l.attenuation.x = v.x,
            gl::LINEAR_ATTENUATION => l.attenuation.y = v.x,
            gl::QUADRATIC_ATTENUATION => l.attenuation.z = v.x,
            _ => {}
        }
    }
}

/// The name of a capability whose effect the trace does not reproduce
/// (the image shows the geometry as if it were off).
fn unsupported_cap(cap: u32) -> Option<&'static str> {
    Some(match cap {
        0x0DE0 => "GL_TEXTURE_1D",
        0x806F => "GL_TEXTURE_3D",
        0x8513 => "GL_TEXTURE_CUBE_MAP",
        0x0B90 => "GL_STENCIL_TEST",
        0x0B24 => "GL_LINE_STIPPLE",
        0x0B42 => "GL_POLYGON_STIPPLE",
        0x3000..=0x3005 => "GL_CLIP_PLANE",
        _ => return None,
    })
}
