//! Vertex arrays and buffer objects through the fixed-function pointers
//! (`glVertexPointer`, `glNormalPointer`, `glColorPointer`), drawn by
//! `glDrawArrays`/`glDrawElements` (GL 2.1 §2.8–2.9).
//!
//! Buffer contents are shadowed here (`glBufferData`/`glBufferSubData`
//! copy them), so a draw whose arrays and indices all live in buffer
//! objects is recorded once and instanced while the buffers keep their
//! contents; draws from client memory are read at the call, as GL reads
//! them, and become immediate geometry. When a buffer's contents change,
//! the draw is recorded again; if only its vertices moved (the same draw
//! shape — the cache key without the array buffers' generations — and the
//! same triangles) the new recording refits the previous one's BVHs
//! instead of building its own ([`Recorded::moved`]).

use std::{collections::HashMap, sync::Arc};

use glam::{Vec3, Vec4};

use super::{Command, Recorded, Recorder};
use crate::gl;

/// `GL_ARRAY_BUFFER`.
pub const ARRAY_BUFFER: u32 = 0x8892;
/// `GL_ELEMENT_ARRAY_BUFFER`.
pub const ELEMENT_ARRAY_BUFFER: u32 = 0x8893;
/// `GL_VERTEX_ARRAY`.
pub const VERTEX_ARRAY: u32 = 0x8074;
/// `GL_NORMAL_ARRAY`.
pub const NORMAL_ARRAY: u32 = 0x8075;
/// `GL_COLOR_ARRAY`.
pub const COLOR_ARRAY: u32 = 0x8076;
/// `GL_TEXTURE_COORD_ARRAY`.
pub const TEXTURE_COORD_ARRAY: u32 = 0x8078;
/// Largest buffer shadowed (bigger `glBufferData` calls are not recorded;
/// draws from them fall back to the program's own image).
pub const MAX_BUFFER_BYTES: usize = 1 << 30;
/// Most vertices one array draw may send (more is taken as a malformed
/// count: ignored, not read).
pub const MAX_DRAW_VERTICES: usize = 1 << 26;
/// Most cached array draws kept.
const MAX_CACHED_DRAWS: usize = 4096;

/// One array pointer as GL keeps it: `pointer` is an address in client
/// memory, or an offset into `buffer` when a buffer was bound to
/// `GL_ARRAY_BUFFER` at the `gl*Pointer` call.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ArrayPointer {
    /// Components per element (normals: 3).
    pub size: i32,
    /// Component type (`GL_FLOAT`, …).
    pub ty: u32,
    /// Bytes between elements (0: tightly packed).
    pub stride: i32,
    /// Address or offset.
    pub pointer: usize,
    /// The buffer object (0: client memory).
    pub buffer: u32,
}

impl ArrayPointer {
    fn component_bytes(ty: u32) -> Option<usize> {
        match ty {
            gl::BYTE | gl::UNSIGNED_BYTE => Some(1),
            gl::SHORT | gl::UNSIGNED_SHORT => Some(2),
            gl::INT | gl::UNSIGNED_INT | gl::FLOAT => Some(4),
            gl::DOUBLE => Some(8),
            _ => None,
        }
    }

    fn is_valid(&self) -> bool {
        (1..=4).contains(&self.size) && self.stride >= 0 && Self::component_bytes(self.ty).is_some()
    }
}

#[derive(Clone, Debug)]
struct Buffer {
    data: Arc<[u8]>,
    generation: u64,
}

/// The client array state and the shadowed buffers.
#[derive(Clone, Debug, Default)]
pub(crate) struct ArrayState {
    vertex: Option<ArrayPointer>,
    normal: Option<ArrayPointer>,
    color: Option<ArrayPointer>,
    texcoord: Option<ArrayPointer>,
    vertex_on: bool,
    normal_on: bool,
    color_on: bool,
    texcoord_on: bool,
    array_buffer: u32,
    element_buffer: u32,
    /// `GL_PIXEL_UNPACK_BUFFER`: image pointers are offsets into it.
    unpack_buffer: u32,
    buffers: HashMap<u32, Buffer>,
    generation: u64,
}

/// What a cached buffer draw depends on besides the inherited state.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) struct DrawKey {
    mode: u32,
    /// `(first, count)` of `glDrawArrays`, or `(offset, count)` and type
    /// of `glDrawElements`.
    range: (usize, usize, u32),
    /// The enabled pointers and the generations of their buffers.
    arrays: [Option<(ArrayPointer, u64)>; 4],
    /// The element buffer and its generation (`glDrawElements`).
    elements: Option<(u32, u64)>,
}

impl DrawKey {
    /// The draw's shape: the key with the array buffers' generations
    /// left out (0). Two draws of one shape differ only in their vertex
    /// data, so the later one may refit the earlier one's BVHs.
    fn shape(&self) -> Self {
        Self { arrays: self.arrays.map(|a| a.map(|(p, _)| (p, 0))), ..self.clone() }
    }
}

/// Where a draw's vertex indices come from.
#[derive(Clone, Copy, Debug)]
enum Indices {
    /// `first..first + count`.
    Range(usize, usize),
    /// `count` indices of type `ty` at `pointer` (client memory, or an
    /// offset into `buffer`).
    Elements { count: usize, ty: u32, pointer: usize, buffer: u32 },
}

/// Reads component `k` of type `ty` at `p`, normalised to `[−1, 1]` or
/// `[0, 1]` when `normalize` (GL's rule for integer colours and normals).
fn component(bytes: &[u8], ty: u32, normalize: bool) -> Option<f32> {
    let b = |n: usize| bytes.get(..n);
    Some(match ty {
        gl::FLOAT => f32::from_ne_bytes(b(4)?.try_into().ok()?),
        gl::DOUBLE => f64::from_ne_bytes(b(8)?.try_into().ok()?) as f32,
        gl::BYTE => {
            let v = f32::from(b(1)?[0] as i8);
            if normalize { v / 127.0 } else { v }
        }
        gl::UNSIGNED_BYTE => {
            let v = f32::from(b(1)?[0]);
            if normalize { v / 255.0 } else { v }
        }
        gl::SHORT => {
            let v = f32::from(i16::from_ne_bytes(b(2)?.try_into().ok()?));
            if normalize { v / 32767.0 } else { v }
        }
        gl::UNSIGNED_SHORT => {
            let v = f32::from(u16::from_ne_bytes(b(2)?.try_into().ok()?));
            if normalize { v / 65535.0 } else { v }
        }
        gl::INT => {
            let v = i32::from_ne_bytes(b(4)?.try_into().ok()?) as f32;
            if normalize { v / 2_147_483_647.0 } else { v }
        }
        gl::UNSIGNED_INT => {
            let v = u32::from_ne_bytes(b(4)?.try_into().ok()?) as f32;
            if normalize { v / 4_294_967_295.0 } else { v }
        }
        _ => return None,
    })
}

impl Recorder {
    /// `glEnableClientState`/`glDisableClientState`.
    pub fn client_state(&mut self, array: u32, on: bool) {
        let a = &mut self.arrays;
        match array {
            VERTEX_ARRAY => a.vertex_on = on,
            NORMAL_ARRAY => a.normal_on = on,
            COLOR_ARRAY => a.color_on = on,
            TEXTURE_COORD_ARRAY => a.texcoord_on = on,
            _ => {}
        }
    }

    /// `glVertexPointer`, `glNormalPointer` (`size` 3) or `glColorPointer`
    /// for `array` (`GL_VERTEX_ARRAY`, …).
    pub fn pointer(&mut self, array: u32, size: i32, ty: u32, stride: i32, pointer: usize) {
        let p = ArrayPointer { size, ty, stride, pointer, buffer: self.arrays.array_buffer };
        if !p.is_valid() {
            self.counters.ignored += 1;
            return;
        }
        let a = &mut self.arrays;
        match array {
            VERTEX_ARRAY => a.vertex = Some(p),
            NORMAL_ARRAY => a.normal = Some(p),
            COLOR_ARRAY => a.color = Some(p),
            TEXTURE_COORD_ARRAY => a.texcoord = Some(p),
            _ => {}
        }
    }

    /// `glInterleavedArrays`: the vertex array and, as `format` holds
    /// them, the colour and normal arrays (on or off) at their offsets in
    /// one interleaved record; texture coordinates are not traced. An
    /// unknown format or a negative stride is ignored, as GL ignores it.
    pub fn interleaved_arrays(&mut self, format: u32, stride: i32, pointer: usize) {
        const F: i32 = 4;
        const UB: u32 = 0x1401;
        const FLOAT: u32 = 0x1406;
        // (colour: (size, type, offset), normal offset, vertex (size,
        // offset), record size), in bytes.
        type Layout = (Option<(i32, u32, i32)>, Option<i32>, (i32, i32), i32);
        let layout: Layout = match format {
            0x2A20 => (None, None, (2, 0), 2 * F),
            0x2A21 => (None, None, (3, 0), 3 * F),
            0x2A22 => (Some((4, UB, 0)), None, (2, 4), 4 + 2 * F),
            0x2A23 => (Some((4, UB, 0)), None, (3, 4), 4 + 3 * F),
            0x2A24 => (Some((3, FLOAT, 0)), None, (3, 3 * F), 6 * F),
            0x2A25 => (None, Some(0), (3, 3 * F), 6 * F),
            0x2A26 => (Some((4, FLOAT, 0)), Some(4 * F), (3, 7 * F), 10 * F),
            0x2A27 => (None, None, (3, 2 * F), 5 * F),
            0x2A28 => (None, None, (4, 4 * F), 8 * F),
            0x2A29 => (Some((4, UB, 2 * F)), None, (3, 4 + 2 * F), 4 + 5 * F),
            0x2A2A => (Some((3, FLOAT, 2 * F)), None, (3, 5 * F), 8 * F),
            0x2A2B => (None, Some(2 * F), (3, 5 * F), 8 * F),
            0x2A2C => (Some((4, FLOAT, 2 * F)), Some(6 * F), (3, 9 * F), 12 * F),
            0x2A2D => (Some((4, FLOAT, 4 * F)), Some(8 * F), (4, 11 * F), 15 * F),
            _ => {
                self.counters.ignored += 1;
                return;
            }
        };
        if stride < 0 {
            self.counters.ignored += 1;
            return;
        }
        let (color, normal, (vsize, voffset), record) = layout;
        let stride = if stride == 0 { record } else { stride };
        let at = |offset: i32| pointer.wrapping_add(offset as usize);
        self.client_state(COLOR_ARRAY, color.is_some());
        if let Some((size, ty, offset)) = color {
            self.pointer(COLOR_ARRAY, size, ty, stride, at(offset));
        }
        self.client_state(NORMAL_ARRAY, normal.is_some());
        if let Some(offset) = normal {
            self.pointer(NORMAL_ARRAY, 3, FLOAT, stride, at(offset));
        }
        self.client_state(VERTEX_ARRAY, true);
        self.pointer(VERTEX_ARRAY, vsize, FLOAT, stride, at(voffset));
        // The T*F formats lead with their texture coordinates.
        let texcoord = match format {
            0x2A27 | 0x2A29..=0x2A2C => Some(2),
            0x2A28 | 0x2A2D => Some(4),
            _ => None,
        };
        self.client_state(TEXTURE_COORD_ARRAY, texcoord.is_some());
        if let Some(size) = texcoord {
            self.pointer(TEXTURE_COORD_ARRAY, size, FLOAT, stride, at(0));
        }
    }

    /// `glBindBuffer(target, buffer)`.
    pub fn bind_buffer(&mut self, target: u32, buffer: u32) {
        match target {
            ARRAY_BUFFER => self.arrays.array_buffer = buffer,
            ELEMENT_ARRAY_BUFFER => self.arrays.element_buffer = buffer,
            0x88EC => self.arrays.unpack_buffer = buffer,
            _ => {}
        }
    }

    /// Whether image pointers are offsets into a pixel buffer object
    /// (whose contents are not shadowed).
    #[must_use]
    pub fn unpacks_from_buffer(&self) -> bool {
        self.arrays.unpack_buffer != 0
    }

    fn bound(&self, target: u32) -> u32 {
        match target {
            ARRAY_BUFFER => self.arrays.array_buffer,
            ELEMENT_ARRAY_BUFFER => self.arrays.element_buffer,
            _ => 0,
        }
    }

    /// `glBufferData(target, size, data)`: `data` is `None` for GL's null
    /// pointer (contents undefined: zeros here).
    pub fn buffer_data(&mut self, target: u32, size: usize, data: Option<&[u8]>) {
        let id = self.bound(target);
        if id == 0 {
            return;
        }
        if size > MAX_BUFFER_BYTES {
            self.arrays.buffers.remove(&id);
            self.counters.ignored += 1;
            return;
        }
        let data: Arc<[u8]> = match data {
            Some(d) => d.get(..size).unwrap_or(d).into(),
            None => vec![0u8; size].into(),
        };
        self.arrays.generation += 1;
        let generation = self.arrays.generation;
        self.arrays.buffers.insert(id, Buffer { data, generation });
    }

    /// `glBufferSubData(target, offset, data)` (ignored past the end, as
    /// GL raises `GL_INVALID_VALUE`).
    pub fn buffer_sub_data(&mut self, target: u32, offset: usize, data: &[u8]) {
        let id = self.bound(target);
        self.arrays.generation += 1;
        let generation = self.arrays.generation;
        let Some(b) = self.arrays.buffers.get_mut(&id) else {
            return;
        };
        let Some(end) = offset.checked_add(data.len()).filter(|&e| e <= b.data.len()) else {
            self.counters.ignored += 1;
            return;
        };
        let mut copy = b.data.to_vec();
        copy[offset..end].copy_from_slice(data);
        *b = Buffer { data: copy.into(), generation };
    }

    /// `glDeleteBuffers`.
    pub fn delete_buffers(&mut self, ids: &[u32]) {
        for id in ids {
            self.arrays.buffers.remove(id);
            let a = &mut self.arrays;
            for p in [&mut a.vertex, &mut a.normal, &mut a.color].into_iter().flatten() {
                if p.buffer == *id {
                    // GL keeps the pointer, but its storage is gone.
                    p.buffer = u32::MAX;
                }
            }
            if a.array_buffer == *id {
                a.array_buffer = 0;
            }
            if a.element_buffer == *id {
                a.element_buffer = 0;
            }
        }
    }

    /// The bytes of element `index` of `p`.
    ///
    /// # Safety
    /// Client-memory pointers must be valid for the element (GL's rule
    /// for the duration of a draw call).
    unsafe fn element(&self, p: &ArrayPointer, index: usize) -> Option<&[u8]> {
        let comp = ArrayPointer::component_bytes(p.ty)?;
        let len = comp * p.size as usize;
        let stride = if p.stride == 0 { len } else { p.stride as usize };
        let off = p.pointer.checked_add(index.checked_mul(stride)?)?;
        if p.buffer == 0 {
            if p.pointer == 0 {
                return None;
            }
            // SAFETY: the caller guarantees the program's array covers it.
            Some(unsafe { core::slice::from_raw_parts(off as *const u8, len) })
        } else {
            let b = self.arrays.buffers.get(&p.buffer)?;
            b.data.get(off..off.checked_add(len)?)
        }
    }

    /// # Safety
    /// As [`Self::element`].
    unsafe fn fetch(&self, p: &ArrayPointer, index: usize, normalize: bool) -> Option<Vec4> {
        // SAFETY: passed on from the caller.
        let bytes = unsafe { self.element(p, index)? };
        let comp = ArrayPointer::component_bytes(p.ty)?;
        let mut v = Vec4::new(0.0, 0.0, 0.0, 1.0);
        for k in 0..p.size as usize {
            v[k] = component(&bytes[k * comp..], p.ty, normalize)?;
        }
        Some(v)
    }

    /// # Safety
    /// Client-memory indices must hold `count` values of type `ty`.
    unsafe fn index_list(&self, idx: Indices) -> Option<Vec<usize>> {
        let count = match idx {
            Indices::Range(_, count) | Indices::Elements { count, .. } => count,
        };
        if count > MAX_DRAW_VERTICES {
            return None;
        }
        match idx {
            Indices::Range(first, count) => Some((first..first.checked_add(count)?).collect()),
            Indices::Elements { count, ty, pointer, buffer } => {
                let size = ArrayPointer::component_bytes(ty).filter(|_| {
                    matches!(ty, gl::UNSIGNED_BYTE | gl::UNSIGNED_SHORT | gl::UNSIGNED_INT)
                })?;
                let bytes: &[u8] = if buffer == 0 {
                    if pointer == 0 {
                        return None;
                    }
                    // SAFETY: the caller guarantees `count` indices there.
                    unsafe {
                        core::slice::from_raw_parts(pointer as *const u8, count.checked_mul(size)?)
                    }
                } else {
                    let b = self.arrays.buffers.get(&buffer)?;
                    b.data.get(pointer..pointer.checked_add(count.checked_mul(size)?)?)?
                };
                Some(
                    bytes
                        .chunks_exact(size)
                        .map(|c| component(c, ty, false).map_or(0, |v| v as usize))
                        .collect(),
                )
            }
        }
    }

    /// Sends the draw as immediate mode would have, one call at a time,
    /// through [`Recorder::command`] (so an open display list stores it).
    ///
    /// # Safety
    /// As [`Self::element`] and [`Self::index_list`].
    unsafe fn emit(&mut self, mode: u32, idx: Indices) {
        // SAFETY: passed on from the caller.
        let Some(indices) = (unsafe { self.index_list(idx) }) else {
            self.counters.ignored += 1;
            return;
        };
        let a = &self.arrays;
        let (Some(vp), true) = (a.vertex, a.vertex_on) else {
            return;
        };
        let np = a.normal.filter(|_| a.normal_on);
        let cp = a.color.filter(|_| a.color_on);
        let tp = a.texcoord.filter(|_| a.texcoord_on);
        self.command(Command::Begin(mode));
        let mut missing = false;
        for i in indices {
            // SAFETY (all three): passed on from the caller.
            if let Some(c) = cp.and_then(|p| unsafe { self.fetch(&p, i, true) }) {
                self.command(Command::Color(c));
            }
            if let Some(n) = np.and_then(|p| unsafe { self.fetch(&p, i, true) }) {
                self.command(Command::Normal(Vec3::new(n.x, n.y, n.z)));
            }
            if let Some(t) = tp.and_then(|p| unsafe { self.fetch(&p, i, false) }) {
                self.command(Command::TexCoord(t));
            }
            match unsafe { self.fetch(&vp, i, false) } {
                Some(v) => self.command(Command::Vertex(v)),
                None => missing = true,
            }
        }
        if missing {
            // An index past a buffer's end: GL's behaviour is undefined.
            self.counters.ignored += 1;
        }
        self.command(Command::End);
    }

    /// `glDrawArrays(mode, first, count)`.
    ///
    /// # Safety
    /// Enabled client-memory arrays must cover `first..first + count`.
    pub unsafe fn draw_arrays(&mut self, mode: u32, first: i32, count: i32) {
        if first < 0 || count < 0 || mode > gl::POLYGON {
            self.counters.ignored += 1;
            return;
        }
        // SAFETY: passed on from the caller.
        unsafe { self.draw(mode, Indices::Range(first as usize, count as usize)) }
    }

    /// `glDrawElements(mode, count, ty, indices)`: `indices` is an
    /// address, or an offset when an element buffer is bound.
    ///
    /// # Safety
    /// Client-memory indices must hold `count` values of type `ty`, and
    /// enabled client-memory arrays cover every index.
    pub unsafe fn draw_elements(&mut self, mode: u32, count: i32, ty: u32, indices: usize) {
        if count < 0 || mode > gl::POLYGON {
            self.counters.ignored += 1;
            return;
        }
        let idx = Indices::Elements {
            count: count as usize,
            ty,
            pointer: indices,
            buffer: self.arrays.element_buffer,
        };
        // SAFETY: passed on from the caller.
        unsafe { self.draw(mode, idx) }
    }

    /// The cache key of a draw whose data all live in buffer objects.
    fn draw_key(&self, mode: u32, idx: Indices) -> Option<DrawKey> {
        let a = &self.arrays;
        let gen_of = |p: Option<ArrayPointer>, on: bool| -> Option<Option<(ArrayPointer, u64)>> {
            match p.filter(|_| on) {
                None => Some(None),
                Some(p) => a.buffers.get(&p.buffer).map(|b| Some((p, b.generation))),
            }
        };
        let vertex = gen_of(a.vertex, a.vertex_on)?;
        vertex?;
        let arrays = [
            vertex,
            gen_of(a.normal, a.normal_on)?,
            gen_of(a.color, a.color_on)?,
            gen_of(a.texcoord, a.texcoord_on)?,
        ];
        let (range, elements) = match idx {
            Indices::Range(first, count) => ((first, count, 0), None),
            Indices::Elements { count, ty, pointer, buffer } => {
                let b = a.buffers.get(&buffer)?;
                ((pointer, count, ty), Some((buffer, b.generation)))
            }
        };
        Some(DrawKey { mode, range, arrays, elements })
    }

    /// # Safety
    /// As [`Self::emit`].
    unsafe fn draw(&mut self, mode: u32, idx: Indices) {
        let points_or_lines =
            matches!(mode, gl::POINTS | gl::LINES | gl::LINE_LOOP | gl::LINE_STRIP)
                || self.polygon_mode != [gl::FILL; 2]
                || self.view_dependent_texgen();
        let plain = self.compiling.is_none()
            && self.state_only == 0
            && self.capture.is_none()
            && self.begin.is_none()
            && !points_or_lines;
        let mv = self.modelview();
        let cacheable =
            if plain { self.draw_key(mode, idx).zip(Self::to_local(&mv)) } else { None };
        if let Some((key, to_local)) = cacheable {
            // The current colour and normal matter only where no array
            // replaces them.
            let mut inherited = self.inherited(0);
            if self.arrays.color_on {
                inherited.color = Vec4::ZERO;
            }
            if self.arrays.normal_on {
                inherited.normal = Vec3::ZERO;
            }
            if let Some((_, g)) = self.draw_cache.get(&key).filter(|(k, _)| *k == inherited) {
                let g = Arc::clone(g);
                self.counters.draw_reuses += 1;
                self.instance(g, mv, None);
                return;
            }
            // SAFETY: passed on from the caller.
            let geometry = self.capture_geometry(mv, to_local, |r| unsafe { r.emit(mode, idx) });
            // The same draw before its buffers changed: its BVHs are
            // refitted if the triangles are the same.
            let shape = key.shape();
            let previous = self.draw_shapes.get(&shape).and_then(|k| self.draw_cache.get(k));
            let g = Arc::new(match previous {
                Some((_, p)) => Recorded::moved(geometry, p),
                None => Recorded::new(geometry),
            });
            if g.is_refit() {
                self.counters.draw_refits += 1;
            } else {
                self.counters.draw_builds += 1;
            }
            if self.draw_cache.len() >= MAX_CACHED_DRAWS {
                self.draw_cache.clear();
                self.draw_shapes.clear();
            }
            // The shape's previous entry can never be hit again (its
            // buffers' generations are gone): dropped, so a buffer
            // updated every frame keeps one entry, not one per frame.
            if let Some(old) = self.draw_shapes.insert(shape, key.clone())
                && old != key
            {
                self.draw_cache.remove(&old);
            }
            self.draw_cache.insert(key, (inherited, Arc::clone(&g)));
            self.instance(g, mv, None);
        } else {
            if self.compiling.is_none() {
                self.counters.draw_inline += 1;
            }
            // In a display list the arrays are read now and the list
            // stores the vertices, as GL does.
            // SAFETY: passed on from the caller.
            unsafe { self.emit(mode, idx) };
        }
    }
}
