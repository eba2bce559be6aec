//! The recorder: a mirror of the fixed-function state a program sets
//! (matrix stacks, current colour and normal, lights, materials, display
//! lists) that turns its draws into geometry.
//!
//! Geometry lands in one of two places. Immediate-mode draws go into the
//! frame in **eye space** (transformed by the modelview at the vertex, as
//! GL does), rebuilt every frame. A call of a display list is recorded
//! once in the list's **entry space** (eye space under the modelview at
//! the call, inverted) and cached; every call, this frame and later ones,
//! becomes an instance: the cached geometry and the modelview at the call.
//! A cache entry is keyed by the list, its definition and every attribute
//! its geometry can inherit from the caller (colour, normal, material,
//! lighting switches), so a hit draws exactly what executing the list
//! would.
//!
//! The recorder is plain Rust, with no GL in it: the interposer feeds it
//! the calls it forwards, and the tests feed it directly.

use std::{collections::HashMap, sync::Arc};

use glam::{Mat3, Mat4, Vec3, Vec4};
use rt_accel::{BuildError, BuildParams, Scene, build_capsules, build_spheres, build_triangles};
use rt_core::intersect::{Capsule, Sphere};

use crate::gl;

pub mod arrays;
mod check;
mod recorded;

pub use arrays::ArrayPointer;
use arrays::{ArrayState, DrawKey};
pub use check::{GeometryError, Primitive};
pub use recorded::Recorded;

/// One recorded call, as display lists store them.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// `glBegin(mode)`.
    Begin(u32),
    /// `glEnd`.
    End,
    /// `glVertex*` (missing coordinates as GL fills them: `z = 0, w = 1`).
    Vertex(Vec4),
    /// `glNormal*`.
    Normal(Vec3),
    /// `glColor*` (RGBA in `[0, 1]`).
    Color(Vec4),
    /// `glMatrixMode`.
    MatrixMode(u32),
    /// `glLoadIdentity`.
    LoadIdentity,
    /// `glLoadMatrix*`.
    LoadMatrix(Mat4),
    /// `glMultMatrix*`, and `glTranslate`/`glRotate`/`glScale`/`glFrustum`/
    /// `glOrtho` as the matrices they multiply by.
    MultMatrix(Mat4),
    /// `glPushMatrix`.
    PushMatrix,
    /// `glPopMatrix`.
    PopMatrix,
    /// `glEnable(cap)`.
    Enable(u32),
    /// `glDisable(cap)`.
    Disable(u32),
    /// `glLight*(light, pname, value)` (scalars in `value[0]`).
    Light(u32, u32, Vec4),
    /// `glLightModel*(pname, value)`.
    LightModel(u32, Vec4),
    /// `glMaterial*(face, pname, value)`.
    Material(u32, u32, Vec4),
    /// `glColorMaterial(face, mode)`.
    ColorMaterial(u32, u32),
    /// `glShadeModel`.
    ShadeModel(u32),
    /// `glPointSize` (pixels).
    PointSize(f32),
    /// `glLineWidth` (pixels).
    LineWidth(f32),
    /// `glCallList`.
    CallList(u32),
}

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

/// How a primitive is shaded, besides its vertices' colours and normals.
#[derive(Clone, Copy, Debug, PartialEq)]
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

fn apply_color_material(m: &mut MaterialState, mode: u32, c: Vec4) {
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

/// Recorded geometry in one space, with what shading needs.
///
/// The fields are public, and nothing stops a hand-made geometry from
/// breaking the rules below; [`Geometry::check`] tells, and building or
/// tracing such a geometry is a [`GeometryError`], never a panic.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Geometry {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals (unnormalised, as transformed), one per position.
    pub normals: Vec<Vec3>,
    /// Vertex colours, one per position.
    pub colors: Vec<Vec4>,
    /// Triangles (vertex indices, counter-clockwise as drawn).
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle (one entry each): its shading (index into
    /// `shadings`) and provoking vertex (for flat shading).
    pub triangle_info: Vec<(u32, u32)>,
    /// Points drawn as spheres: vertex, radius, shading.
    pub spheres: Vec<(u32, f32, u32)>,
    /// Line segments drawn as tubes: vertices, radius, shading.
    pub tubes: Vec<([u32; 2], f32, u32)>,
    /// The shadings used.
    pub shadings: Vec<Shading>,
}

impl Geometry {
    /// Whether nothing was drawn.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty() && self.spheres.is_empty() && self.tubes.is_empty()
    }

    /// Appends `other` transformed by `m` (positions) and `m`'s normal
    /// matrix (normals).
    ///
    /// # Errors
    /// What [`Geometry::check`] finds in `self` or in `other`; nothing is
    /// appended then (an index out of range, offset, could name a vertex
    /// of the other geometry and pass unnoticed).
    pub fn append_transformed(&mut self, other: &Self, m: &Mat4) -> Result<(), GeometryError> {
        self.check()?;
        other.check()?;
        self.append_checked(other, m);
        Ok(())
    }

    /// [`Geometry::append_transformed`] of two geometries that have
    /// passed [`Geometry::check`].
    fn append_checked(&mut self, other: &Self, m: &Mat4) {
        // Saturating: past 2³² vertices an index cannot be offset (nor
        // made), and must not wrap onto a vertex that exists.
        let base = u32::try_from(self.positions.len()).unwrap_or(u32::MAX);
        let sbase = u32::try_from(self.shadings.len()).unwrap_or(u32::MAX);
        let v = |i: u32| i.saturating_add(base);
        let s = |i: u32| i.saturating_add(sbase);
        let nm = normal_matrix(m);
        // Radii scale with the transform's mean scale.
        let scale = Mat3::from_mat4(*m).determinant().abs().cbrt();
        self.positions.extend(other.positions.iter().map(|&p| m.transform_point3(p)));
        self.normals.extend(other.normals.iter().map(|&n| nm * n));
        self.colors.extend_from_slice(&other.colors);
        self.triangles.extend(other.triangles.iter().map(|t| t.map(v)));
        self.triangle_info.extend(other.triangle_info.iter().map(|&(k, p)| (s(k), v(p))));
        self.spheres.extend(other.spheres.iter().map(|&(i, r, k)| (v(i), r * scale, s(k))));
        self.tubes.extend(other.tubes.iter().map(|&(e, r, k)| (e.map(v), r * scale, s(k))));
        self.shadings.extend_from_slice(&other.shadings);
    }

    /// BVHs over the triangles, spheres and tubes, once the geometry has
    /// passed [`Geometry::check`].
    ///
    /// # Errors
    /// What [`Geometry::check`] finds, or [`GeometryError::Build`] if a
    /// primitive is not finite (or a radius not positive).
    pub fn build(&self) -> Result<Scene, GeometryError> {
        self.check()?;
        Ok(self.build_checked()?)
    }

    /// [`Geometry::build`] for a geometry that has passed
    /// [`Geometry::check`].
    fn build_checked(&self) -> Result<Scene, BuildError> {
        let params = BuildParams::fast();
        Ok(Scene {
            triangles: build_triangles(&self.positions, &self.triangles, &params)?,
            spheres: build_spheres(&self.sphere_shapes(), &params)?,
            capsules: build_capsules(&self.tube_shapes(), &params)?,
        })
    }

    /// The points as spheres, in the order of [`Self::spheres`].
    ///
    /// # Panics
    /// On a geometry that has not passed [`Geometry::check`].
    fn sphere_shapes(&self) -> Vec<Sphere> {
        self.spheres.iter().map(|&(v, r, _)| Sphere::new(self.positions[v as usize], r)).collect()
    }

    /// The line segments as capsules, in the order of [`Self::tubes`].
    ///
    /// # Panics
    /// On a geometry that has not passed [`Geometry::check`].
    fn tube_shapes(&self) -> Vec<Capsule> {
        self.tubes
            .iter()
            .map(|&([a, b], r, _)| {
                Capsule::new(self.positions[a as usize], self.positions[b as usize], r)
            })
            .collect()
    }

    fn shading_index(&mut self, s: Shading) -> u32 {
        if self.shadings.last() != Some(&s) {
            self.shadings.push(s);
        }
        self.shadings.len() as u32 - 1
    }
}

/// The matrix that carries normals along with `m`: the inverse transpose
/// of its upper 3 × 3 (the identity where that is singular).
#[must_use]
pub fn normal_matrix(m: &Mat4) -> Mat3 {
    let a = Mat3::from_mat4(*m);
    if a.determinant() == 0.0 { Mat3::IDENTITY } else { a.inverse().transpose() }
}

/// One frame's draws: immediate geometry in eye space and instances of
/// cached display lists.
#[derive(Clone, Debug, Default)]
pub struct Frame {
    /// Immediate-mode geometry, eye space.
    pub immediate: Geometry,
    /// Cached list geometry and the modelview of each call.
    pub instances: Vec<(Arc<Recorded>, Mat4)>,
}

impl Frame {
    /// Whether nothing was drawn.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.immediate.is_empty() && self.instances.iter().all(|(r, _)| r.geometry().is_empty())
    }

    /// Everything in eye space, in one piece.
    ///
    /// # Errors
    /// What [`Geometry::check`] finds in the immediate geometry or in a
    /// recording's.
    pub fn flatten(&self) -> Result<Geometry, GeometryError> {
        self.immediate.check()?;
        let mut g = self.immediate.clone();
        for (inst, m) in &self.instances {
            inst.geometry().check()?;
            g.append_checked(inst.geometry(), m);
        }
        Ok(g)
    }
}

/// What the recorder has done, for the logs and the tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Frames ended ([`Recorder::end_frame`]).
    pub frames: u64,
    /// Display-list calls recorded into a new cache entry.
    pub list_builds: u64,
    /// Display-list calls answered from the cache.
    pub list_reuses: u64,
    /// Display-list calls that could not be cached (executed as immediate
    /// geometry: lists that load matrices, draw points or lines, or are
    /// called inside `glBegin`).
    pub list_inline: u64,
    /// Array draws from buffer objects recorded into a new cache entry
    /// whose BVHs are built.
    pub draw_builds: u64,
    /// Array draws from buffer objects answered from the cache.
    pub draw_reuses: u64,
    /// Array draws from buffer objects recorded into a new cache entry
    /// whose BVHs are refitted from the previous entry of the same draw
    /// (its buffers' contents changed, its triangles did not) rather than
    /// built: not also counted in `draw_builds`.
    pub draw_refits: u64,
    /// Array draws from client memory (or with points and lines),
    /// recorded as immediate geometry.
    pub draw_inline: u64,
    /// Instances in the last frame ended.
    pub instances: u64,
    /// Triangles in the last frame ended (immediate and instanced).
    pub triangles: u64,
    /// Calls ignored because they break GL's rules (a vertex outside
    /// `glBegin`, an unknown primitive type, a stack over- or underflow, …).
    pub ignored: u64,
}

/// Commands one top-level display-list call may execute (see
/// [`Recorder::set_list_budget`]): 2²⁶, several times the largest lists
/// real programs compile.
pub const LIST_BUDGET: u64 = 1 << 26;
/// Deepest `glCallList` nesting executed (GL's minimum `GL_MAX_LIST_NESTING`).
pub const MAX_LIST_NESTING: u32 = 64;
/// Deepest matrix stack kept (GL guarantees 32 modelview entries).
pub const MAX_STACK: usize = 256;
/// Cached variants kept per display list (one per distinct inherited state).
const VARIANTS_PER_LIST: usize = 4;

#[derive(Clone, Debug)]
struct List {
    commands: Arc<[Command]>,
    /// Recordable once per calling state (no matrix loads, no points or
    /// lines, which depend on the depth they are drawn at).
    cacheable: bool,
    /// Calls other lists: cached entries also depend on their definitions.
    nested: bool,
    /// What the list sets before its first vertex (so does not inherit).
    overrides: Overrides,
}

/// The inherited attributes a list sets before drawing anything: those
/// are left out of its cache key, so the state the previous draw left
/// behind (glxgears: the last gear's material and normal) does not make
/// a new variant.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Overrides {
    normal: bool,
    color: bool,
    ambient: bool,
    diffuse: bool,
    specular: bool,
    emission: bool,
    shininess: bool,
    lit: bool,
    flat: bool,
}

impl Overrides {
    /// Scans `commands` up to the first vertex or nested call.
    fn of(commands: &[Command]) -> Self {
        let mut o = Self::default();
        for c in commands {
            match *c {
                Command::Vertex(_) | Command::CallList(_) => break,
                Command::Normal(_) => o.normal = true,
                Command::Color(_) => o.color = true,
                Command::Material(gl::FRONT | gl::FRONT_AND_BACK, pname, _) => match pname {
                    gl::AMBIENT => o.ambient = true,
                    gl::DIFFUSE => o.diffuse = true,
                    gl::SPECULAR => o.specular = true,
                    gl::EMISSION => o.emission = true,
                    gl::SHININESS => o.shininess = true,
                    gl::AMBIENT_AND_DIFFUSE => {
                        o.ambient = true;
                        o.diffuse = true;
                    }
                    _ => {}
                },
                Command::Enable(gl::LIGHTING) | Command::Disable(gl::LIGHTING) => o.lit = true,
                Command::ShadeModel(_) => o.flat = true,
                // Colour material ties colour and material together: keep
                // everything in the key.
                Command::Enable(gl::COLOR_MATERIAL) | Command::ColorMaterial(..) => {
                    return Self::default();
                }
                _ => {}
            }
        }
        o
    }

    /// `key` with what the list overrides replaced by a constant.
    fn mask(self, mut key: Inherited) -> Inherited {
        let m = &mut key.shading.material;
        let zero = Vec4::ZERO;
        if self.normal {
            key.normal = Vec3::ZERO;
        }
        // Lit without colour material, the colour is never seen.
        let unseen = !self.lit && key.shading.lit && key.shading.color_material.is_none();
        if (self.color || unseen) && key.shading.color_material.is_none() {
            key.color = zero;
        }
        if self.ambient {
            m.ambient = zero;
        }
        if self.diffuse {
            m.diffuse = zero;
        }
        if self.specular {
            m.specular = zero;
        }
        if self.emission {
            m.emission = zero;
        }
        if self.shininess {
            m.shininess = 0.0;
        }
        if self.lit {
            key.shading.lit = false;
        }
        if self.flat {
            key.shading.flat = false;
        }
        key
    }
}

/// The inherited state a cached list's geometry depends on.
#[derive(Clone, Debug, PartialEq)]
struct Inherited {
    color: Vec4,
    normal: Vec3,
    shading: Shading,
    /// Definitions seen (lists that call others).
    generation: u64,
}

struct Capture {
    geometry: Geometry,
    /// Eye space to the list's entry space.
    to_local: Mat4,
    /// Eye-space normals to entry space.
    normal_to_local: Mat3,
}

/// A vertex between `glBegin` and `glEnd`: eye-space position, normal and
/// colour.
type Vert = (Vec3, Vec3, Vec4);

/// The fixed-function state machine; see the module documentation.
pub struct Recorder {
    modelview: Vec<Mat4>,
    projection: Vec<Mat4>,
    texture: Vec<Mat4>,
    matrix_mode: u32,
    /// `glViewport(x, y, width, height)`.
    pub viewport: [i32; 4],
    /// `glClearColor`.
    pub clear_color: Vec4,
    color: Vec4,
    normal: Vec3,
    point_size: f32,
    line_width: f32,
    lit: bool,
    flat: bool,
    color_material_on: bool,
    color_material: (u32, u32),
    front: MaterialState,
    /// The lights (eye space) and light model.
    pub lighting: Lighting,
    lists: HashMap<u32, List>,
    list_base: u32,
    /// Bumped whenever a list is defined or deleted.
    generation: u64,
    compiling: Option<(u32, u32, Vec<Command>)>,
    begin: Option<(u32, Vec<Vert>)>,
    capture: Option<Capture>,
    /// > 0 while replaying a cached list for its state changes only.
    state_only: u32,
    depth: u32,
    /// Commands the current top-level list call may still execute.
    budget: u64,
    list_budget: u64,
    cache: HashMap<u32, Vec<(Inherited, Arc<Recorded>)>>,
    frame: Frame,
    /// Vertex arrays and buffer objects.
    arrays: ArrayState,
    draw_cache: HashMap<DrawKey, (Inherited, Arc<Recorded>)>,
    /// Per draw shape ([`DrawKey::shape`]): the key of its latest entry in
    /// `draw_cache`, whose BVHs the next recording of the shape refits.
    draw_shapes: HashMap<DrawKey, DrawKey>,
    /// What has been done so far.
    pub counters: Counters,
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
            point_size: 1.0,
            line_width: 1.0,
            lit: false,
            flat: false,
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
            arrays: ArrayState::default(),
            draw_cache: HashMap::new(),
            draw_shapes: HashMap::new(),
            counters: Counters::default(),
        }
    }

    /// The current modelview matrix.
    #[must_use]
    pub fn modelview(&self) -> Mat4 {
        *self.modelview.last().unwrap_or(&Mat4::IDENTITY)
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

    /// Whether a display list is being compiled with `GL_COMPILE` (calls
    /// are stored, not executed).
    #[must_use]
    pub fn compiling_only(&self) -> bool {
        matches!(self.compiling, Some((_, gl::COMPILE, _)))
    }

    /// Ends the frame: returns what was drawn and starts an empty one.
    pub fn end_frame(&mut self) -> Frame {
        self.counters.frames += 1;
        self.counters.instances = self.frame.instances.len() as u64;
        self.counters.triangles = (self.frame.immediate.triangles.len()
            + self.frame.instances.iter().map(|(r, _)| r.geometry().triangles.len()).sum::<usize>())
            as u64;
        core::mem::take(&mut self.frame)
    }

    /// `glClear(mask)`: clearing the colour buffer starts the frame over.
    pub fn clear(&mut self, mask: u32) {
        if mask & gl::COLOR_BUFFER_BIT != 0 && !self.compiling_only() {
            self.frame = Frame::default();
        }
    }

    /// `glNewList(id, mode)`.
    pub fn new_list(&mut self, id: u32, mode: u32) {
        if id == 0
            || self.compiling.is_some()
            || !matches!(mode, gl::COMPILE | gl::COMPILE_AND_EXECUTE)
        {
            self.counters.ignored += 1;
            return;
        }
        self.compiling = Some((id, mode, Vec::new()));
    }

    /// `glEndList`.
    pub fn end_list(&mut self) {
        let Some((id, _, commands)) = self.compiling.take() else {
            self.counters.ignored += 1;
            return;
        };
        let cacheable = !commands.iter().any(|c| {
            matches!(
                c,
                Command::LoadIdentity
                    | Command::LoadMatrix(_)
                    | Command::MatrixMode(_)
                    | Command::Begin(gl::POINTS | gl::LINES | gl::LINE_LOOP | gl::LINE_STRIP)
            )
        });
        let nested = commands.iter().any(|c| matches!(c, Command::CallList(_)));
        let overrides = Overrides::of(&commands);
        self.generation += 1;
        self.cache.remove(&id);
        self.lists.insert(id, List { commands: commands.into(), cacheable, nested, overrides });
    }

    /// `glListBase(base)`.
    pub fn list_base(&mut self, base: u32) {
        self.list_base = base;
    }

    /// `glCallLists` with the ids already read: each offset by the list base.
    pub fn call_lists(&mut self, ids: &[u32]) {
        for &id in ids {
            self.command(Command::CallList(self.list_base.wrapping_add(id)));
        }
    }

    /// `glDeleteLists(first, range)`.
    pub fn delete_lists(&mut self, first: u32, range: i32) {
        if range < 0 {
            self.counters.ignored += 1;
            return;
        }
        let ids = first..first.saturating_add(range as u32);
        // Whichever is shorter: the range (one list at a time) or the
        // lists (`glDeleteLists(1, INT_MAX)` must not walk 2³¹ ids).
        if ids.len() <= self.lists.len() {
            for id in ids {
                self.lists.remove(&id);
                self.cache.remove(&id);
            }
        } else {
            self.lists.retain(|id, _| !ids.contains(id));
            self.cache.retain(|id, _| !ids.contains(id));
        }
        self.generation += 1;
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

    fn shading(&self) -> Shading {
        Shading {
            lit: self.lit,
            flat: self.flat,
            material: self.front,
            color_material: self.color_material_on.then_some(self.color_material.1),
        }
    }

    fn execute(&mut self, c: &Command) {
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
        }
    }

    fn set_cap(&mut self, cap: u32, on: bool) {
        match cap {
            gl::LIGHTING => self.lit = on,
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

    fn vertex(&mut self, v: Vec4) {
        let mv = self.modelview();
        let Some((_, verts)) = &mut self.begin else {
            self.counters.ignored += 1;
            return;
        };
        let e = mv * v;
        if e.w == 0.0 || !e.is_finite() {
            return;
        }
        let n = normal_matrix(&mv) * self.normal;
        verts.push((e.truncate() / e.w, n, self.color));
    }

    /// The size of one pixel at eye-space depth `z` (negative in front).
    fn pixel_size_at(&self, z: f32) -> f32 {
        let p = self.projection();
        let h = self.viewport[3].max(1) as f32;
        // Perspective: w = −z; orthographic: w = 1.
        let w = if p.w_axis.w == 0.0 { -z } else { 1.0 };
        (2.0 * w.abs() / (p.y_axis.y.abs() * h)).max(f32::MIN_POSITIVE)
    }

    /// Turns one `glBegin`/`glEnd` into triangles, spheres or tubes.
    fn assemble(&mut self, mode: u32, verts: &[Vert]) {
        let shading = self.shading();
        let point_r = self.point_size * 0.5;
        let line_r = self.line_width * 0.5;
        let radius: Vec<f32> = match mode {
            gl::POINTS => verts.iter().map(|v| point_r * self.pixel_size_at(v.0.z)).collect(),
            gl::LINES | gl::LINE_LOOP | gl::LINE_STRIP => {
                verts.iter().map(|v| line_r * self.pixel_size_at(v.0.z)).collect()
            }
            _ => Vec::new(),
        };
        let (g, to_local, n_to_local) = match &mut self.capture {
            Some(c) => (&mut c.geometry, c.to_local, c.normal_to_local),
            None => (&mut self.frame.immediate, Mat4::IDENTITY, Mat3::IDENTITY),
        };
        let base = g.positions.len() as u32;
        for &(p, n, c) in verts {
            g.positions.push(to_local.transform_point3(p));
            g.normals.push(n_to_local * n);
            g.colors.push(c);
        }
        let s = g.shading_index(shading);
        let n = verts.len() as u32;
        let v = |i: u32| base + i;
        let mut tri = |a: u32, b: u32, c: u32, provoking: u32| {
            g.triangles.push([v(a), v(b), v(c)]);
            g.triangle_info.push((s, v(provoking)));
        };
        match mode {
            gl::TRIANGLES => (0..n / 3).for_each(|i| tri(3 * i, 3 * i + 1, 3 * i + 2, 3 * i + 2)),
            gl::TRIANGLE_STRIP => (0..n.saturating_sub(2)).for_each(|i| {
                // Every other triangle swaps its first two vertices to
                // keep the strip's orientation.
                if i % 2 == 0 { tri(i, i + 1, i + 2, i + 2) } else { tri(i + 1, i, i + 2, i + 2) }
            }),
            gl::TRIANGLE_FAN => (1..n.saturating_sub(1)).for_each(|i| tri(0, i, i + 1, i + 1)),
            // Quads split along the diagonal from their second vertex to
            // their last, as Mesa does (it decides how colours interpolate).
            gl::QUADS => (0..n / 4).for_each(|q| {
                let a = 4 * q;
                tri(a, a + 1, a + 3, a + 3);
                tri(a + 1, a + 2, a + 3, a + 3);
            }),
            gl::QUAD_STRIP => (0..n.saturating_sub(2) / 2).for_each(|q| {
                let a = 2 * q;
                tri(a, a + 1, a + 2, a + 3);
                tri(a + 1, a + 3, a + 2, a + 3);
            }),
            gl::POLYGON => (1..n.saturating_sub(1)).for_each(|i| tri(0, i, i + 1, 0)),
            gl::POINTS => (0..n).for_each(|i| g.spheres.push((v(i), radius[i as usize], s))),
            _ => {
                let seg: Vec<[u32; 2]> = match mode {
                    gl::LINES => (0..n / 2).map(|i| [2 * i, 2 * i + 1]).collect(),
                    gl::LINE_STRIP => (1..n).map(|i| [i - 1, i]).collect(),
                    // LINE_LOOP: the strip and the closing segment.
                    _ if n >= 2 => (1..=n).map(|i| [i - 1, i % n]).collect(),
                    _ => Vec::new(),
                };
                for [a, b] in seg {
                    let r = 0.5 * (radius[a as usize] + radius[b as usize]);
                    g.tubes.push(([v(a), v(b)], r, s));
                }
            }
        }
    }

    fn call_list(&mut self, id: u32) {
        if self.depth >= MAX_LIST_NESTING {
            self.counters.ignored += 1;
            return;
        }
        let Some(list) = self.lists.get(&id).cloned() else {
            return;
        };
        if self.depth == 0 {
            self.budget = self.list_budget;
        }
        self.depth += 1;
        let mv = self.modelview();
        let plain = self.state_only == 0 && self.capture.is_none() && self.begin.is_none();
        match Self::to_local(&mv) {
            Some(to_local) if plain && list.cacheable => {
                let key = list.overrides.mask(self.inherited(if list.nested {
                    self.generation
                } else {
                    0
                }));
                let hit = self.cache.get(&id).and_then(|v| v.iter().find(|(k, _)| *k == key));
                let geometry = if let Some((_, g)) = hit {
                    let g = Arc::clone(g);
                    self.counters.list_reuses += 1;
                    // Replay for the state the list leaves behind.
                    self.state_only += 1;
                    self.run(&list.commands);
                    self.state_only -= 1;
                    g
                } else {
                    let g = self.captured(mv, to_local, |r| r.run(&list.commands));
                    let variants = self.cache.entry(id).or_default();
                    if variants.len() >= VARIANTS_PER_LIST {
                        variants.remove(0);
                    }
                    variants.push((key, Arc::clone(&g)));
                    self.counters.list_builds += 1;
                    g
                };
                self.instance(geometry, mv);
            }
            _ => {
                if plain {
                    self.counters.list_inline += 1;
                }
                self.run(&list.commands);
            }
        }
        self.depth -= 1;
    }

    /// The state a cached draw inherits; `generation`: the list
    /// definitions it depends on (0: none).
    fn inherited(&self, generation: u64) -> Inherited {
        Inherited { color: self.color, normal: self.normal, shading: self.shading(), generation }
    }

    /// Runs `f` with its geometry recorded in the entry space of the
    /// modelview `mv` (`to_local` its inverse).
    fn captured(&mut self, mv: Mat4, to_local: Mat4, f: impl FnOnce(&mut Self)) -> Arc<Recorded> {
        Arc::new(Recorded::new(self.capture_geometry(mv, to_local, f)))
    }

    /// The geometry `f` draws, in the entry space of the modelview `mv`
    /// (`to_local` its inverse).
    fn capture_geometry(
        &mut self,
        mv: Mat4,
        to_local: Mat4,
        f: impl FnOnce(&mut Self),
    ) -> Geometry {
        self.capture = Some(Capture {
            geometry: Geometry::default(),
            to_local,
            normal_to_local: Mat3::from_mat4(mv).transpose(),
        });
        f(self);
        self.capture.take().map(|c| c.geometry).unwrap_or_default()
    }

    /// Adds an instance of cached geometry to the frame.
    fn instance(&mut self, geometry: Arc<Recorded>, mv: Mat4) {
        if !geometry.geometry().is_empty() && self.state_only == 0 {
            self.frame.instances.push((geometry, mv));
        }
    }

    /// The modelview's inverse, if it has a finite one.
    fn to_local(mv: &Mat4) -> Option<Mat4> {
        (mv.determinant() != 0.0).then(|| mv.inverse()).filter(|m| m.is_finite())
    }

    fn run(&mut self, commands: &[Command]) {
        for c in commands {
            if self.depth > 0 {
                // Inside a list call: spend the call's budget.
                if self.budget == 0 {
                    self.counters.ignored += 1;
                    return;
                }
                self.budget -= 1;
            }
            self.execute(c);
        }
    }

    /// Most commands one top-level `glCallList` may execute, nested calls
    /// included (default [`LIST_BUDGET`]): lists that call each other
    /// several times over can ask for 2⁶⁴ commands within GL's nesting
    /// limit; past the budget the call stops, counted as ignored.
    pub fn set_list_budget(&mut self, commands: u64) {
        self.list_budget = commands;
    }
}

/// `glTranslate(x, y, z)`.
#[must_use]
pub fn translate(v: Vec3) -> Mat4 {
    Mat4::from_translation(v)
}

/// `glRotate(angle_degrees, x, y, z)` (the identity for a zero axis).
#[must_use]
pub fn rotate(degrees: f32, axis: Vec3) -> Mat4 {
    let a = axis.normalize_or_zero();
    if a == Vec3::ZERO { Mat4::IDENTITY } else { Mat4::from_axis_angle(a, degrees.to_radians()) }
}

/// `glScale(x, y, z)`.
#[must_use]
pub fn scale(v: Vec3) -> Mat4 {
    Mat4::from_scale(v)
}

/// `glFrustum(l, r, b, t, n, f)` as the OpenGL specification writes it
/// (`None` where GL raises `GL_INVALID_VALUE`).
#[must_use]
pub fn frustum(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) -> Option<Mat4> {
    if n <= 0.0 || f <= 0.0 || l == r || b == t || n == f {
        return None;
    }
    let m = [
        [2.0 * n / (r - l), 0.0, 0.0, 0.0],
        [0.0, 2.0 * n / (t - b), 0.0, 0.0],
        [(r + l) / (r - l), (t + b) / (t - b), -(f + n) / (f - n), -1.0],
        [0.0, 0.0, -2.0 * f * n / (f - n), 0.0],
    ];
    Some(Mat4::from_cols_array_2d(&m.map(|c| c.map(|x| x as f32))))
}

/// `glOrtho(l, r, b, t, n, f)` (`None` where GL raises `GL_INVALID_VALUE`).
#[must_use]
pub fn ortho(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) -> Option<Mat4> {
    if l == r || b == t || n == f {
        return None;
    }
    let m = [
        [2.0 / (r - l), 0.0, 0.0, 0.0],
        [0.0, 2.0 / (t - b), 0.0, 0.0],
        [0.0, 0.0, -2.0 / (f - n), 0.0],
        [-(r + l) / (r - l), -(t + b) / (t - b), -(f + n) / (f - n), 1.0],
    ];
    Some(Mat4::from_cols_array_2d(&m.map(|c| c.map(|x| x as f32))))
}
