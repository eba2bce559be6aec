//! Display lists: compiling them, calling them (recorded once per calling
//! state and instanced, or executed inline), and deleting them.

use std::sync::Arc;

use glam::{Vec3, Vec4};

use super::{Command, Paint, Recorder, Shading, capture::Inherited};
use crate::gl;

/// Commands one top-level display-list call may execute (see
/// [`Recorder::set_list_budget`]): 2²⁶, several times the largest lists
/// real programs compile.
pub const LIST_BUDGET: u64 = 1 << 26;
/// Deepest `glCallList` nesting executed (GL's minimum `GL_MAX_LIST_NESTING`).
pub const MAX_LIST_NESTING: u32 = 64;
/// Cached variants kept per display list (one per distinct inherited state).
const VARIANTS_PER_LIST: usize = 4;

#[derive(Clone, Debug)]
pub(super) struct List {
    commands: Arc<[Command]>,
    /// Recordable once per calling state (no matrix loads, no points or
    /// lines, which depend on the depth they are drawn at).
    cacheable: bool,
    /// Calls other lists: cached entries also depend on their definitions.
    nested: bool,
    /// Sets no shading state (materials, switches, shade model, textures,
    /// alpha, blend and cull functions) and calls no list: every
    /// primitive takes the caller's shading, and the vertices before its
    /// first `glColor` the caller's colour, so one recording serves every
    /// calling colour and material, each call painting its instance.
    paintable: bool,
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
    front: bool,
}

impl Overrides {
    /// Scans `commands` up to the first vertex or nested call.
    fn of(commands: &[Command]) -> Self {
        let mut o = Self::default();
        for c in commands {
            match *c {
                Command::Vertex(_)
                | Command::CallList(_)
                | Command::Bitmap { .. }
                | Command::DrawPixels(_) => break,
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
                Command::FrontFace(_) => o.front = true,
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
        if self.front {
            key.front_cw = false;
        }
        key
    }
}

impl Recorder {
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
                    | Command::PolygonMode(_, gl::LINE | gl::POINT)
                    | Command::TexGen(..)
                    | Command::Enable(0x0C60..=0x0C63)
            )
        });
        let nested = commands.iter().any(|c| matches!(c, Command::CallList(_)));
        let paintable = !commands.iter().any(|c| {
            matches!(
                c,
                Command::CallList(_)
                    | Command::Material(..)
                    | Command::ColorMaterial(..)
                    | Command::ShadeModel(_)
                    | Command::BindTexture(..)
                    | Command::TexEnv(..)
                    | Command::AlphaFunc(..)
                    | Command::DepthFunc(_)
                    | Command::TexGen(..)
                    | Command::BlendFunc(..)
                    | Command::CullFace(_)
                    | Command::ColorMask(_)
                    | Command::Enable(_)
                    | Command::Disable(_)
            )
        });
        let overrides = Overrides::of(&commands);
        self.generation += 1;
        self.cache.remove(&id);
        self.lists.insert(
            id,
            List { commands: commands.into(), cacheable, nested, paintable, overrides },
        );
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

    pub(super) fn call_list(&mut self, id: u32) {
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
            // Polygons drawn as lines or points are sized in pixels at
            // their depth, as lines are: not recordable once.
            Some(to_local)
                if plain
                    && list.cacheable
                    && self.polygon_mode == [gl::FILL; 2]
                    && !self.view_dependent_texgen() =>
            {
                let mut key = list.overrides.mask(self.inherited(if list.nested {
                    self.generation
                } else {
                    0
                }));
                if list.paintable {
                    // Painted per call: neither is part of the recording.
                    key.color = Vec4::ZERO;
                    key.shading = Shading::default();
                }
                let paint = |r: &Self, vertices| list.paintable.then(|| r.paint(vertices));
                let hit = self.cache.get(&id).and_then(|v| v.iter().find(|(k, ..)| *k == key));
                let (geometry, paint) = if let Some((_, g, inherit)) = hit {
                    let (g, paint) = (Arc::clone(g), paint(self, *inherit));
                    self.counters.list_reuses += 1;
                    // Replay for the state the list leaves behind.
                    self.state_only += 1;
                    self.run(&list.commands);
                    self.state_only -= 1;
                    (g, paint)
                } else {
                    let before = paint(self, 0);
                    let (g, inherit) = self.captured(mv, to_local, |r| r.run(&list.commands));
                    let variants = self.cache.entry(id).or_default();
                    if variants.len() >= VARIANTS_PER_LIST {
                        variants.remove(0);
                    }
                    variants.push((key, Arc::clone(&g), inherit));
                    self.counters.list_builds += 1;
                    (g, before.map(|p| Paint { vertices: inherit, ..p }))
                };
                self.instance(geometry, mv, paint);
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
