//! The exported GL and GLX entry points.
//!
//! Each one records the call ([`crate::record::Recorder`]) and forwards
//! it, unchanged, to the real GL, so the program's own state, queries and
//! raster output keep working. Recording never unwinds into the program:
//! a panic is caught, logged once, and the call is forwarded as if rt-gl
//! were not there. `glXSwapBuffers` ray traces the frame before the real
//! swap (see [`crate::present`]).
//!
//! Pointer arguments are read only when non-null; GL's own rules for them
//! are the real GL's business (the call is forwarded as given).

// The exported symbols are `pub` for the linker, not for Rust callers.
#![allow(non_snake_case, missing_docs, unreachable_pub, clippy::missing_safety_doc)]

use core::ffi::{CStr, c_void};

use glam::{Mat4, Vec3, Vec4};

use crate::{
    gl,
    real::RealFn,
    record::{Command, Recorder, arrays, frustum, ortho, rotate, scale, translate},
    with_recorder,
};

/// Reads `n` values of type `T` from `p` (none if `p` is null).
///
/// # Safety
/// A non-null `p` must point at `n` readable values.
unsafe fn read<T: Copy + Default, const N: usize>(p: *const T) -> Option<[T; N]> {
    if p.is_null() {
        return None;
    }
    // SAFETY: the caller guarantees N readable values.
    Some(core::array::from_fn(|i| unsafe { *p.add(i) }))
}

fn v4(x: f32, y: f32, z: f32, w: f32) -> Command {
    Command::Vertex(Vec4::new(x, y, z, w))
}

fn ub(c: u8) -> f32 {
    f32::from(c) / 255.0
}

fn mat_f(m: [f32; 16]) -> Mat4 {
    Mat4::from_cols_array(&m)
}

fn mat_d(m: [f64; 16]) -> Mat4 {
    Mat4::from_cols_array(&m.map(|x| x as f32))
}

/// Lights and materials take 1 value for scalar names, 4 for vectors
/// (3 for the spot direction).
fn param_count(pname: u32) -> usize {
    match pname {
        gl::SPOT_DIRECTION => 3,
        gl::AMBIENT
        | gl::DIFFUSE
        | gl::SPECULAR
        | gl::POSITION
        | gl::EMISSION
        | gl::AMBIENT_AND_DIFFUSE
        | gl::LIGHT_MODEL_AMBIENT
        | gl::FOG_COLOR
        | gl::TEXTURE_ENV_COLOR
        | gl::OBJECT_PLANE
        | gl::EYE_PLANE => 4,
        _ => 1,
    }
}

/// Reads a parameter vector of `pname`'s size (lights, materials, fog,
/// texture environment and coordinate generation).
///
/// # Safety
/// A non-null `p` must point at that many values.
unsafe fn params<T: Copy + Into<f64>>(pname: u32, p: *const T) -> Option<Vec4> {
    if p.is_null() {
        return None;
    }
    let n = param_count(pname);
    let mut v = [0.0f32; 4];
    for (i, x) in v.iter_mut().enumerate().take(n) {
        // SAFETY: the caller guarantees `n` readable values.
        *x = unsafe { (*p.add(i)).into() } as f32;
    }
    Some(Vec4::from_array(v))
}

/// Integer colour and material parameters map `[−2³¹, 2³¹ − 1]` to
/// `[−1, 1]` (GL 2.1 §2.14.1); positions and scalars are taken as is.
fn int_param(pname: u32, v: Vec4) -> Vec4 {
    match pname {
        gl::AMBIENT
        | gl::DIFFUSE
        | gl::SPECULAR
        | gl::EMISSION
        | gl::AMBIENT_AND_DIFFUSE
        | gl::LIGHT_MODEL_AMBIENT
        | gl::FOG_COLOR
        | gl::TEXTURE_ENV_COLOR => v / 2_147_483_647.0,
        _ => v,
    }
}

/// Defines exported entry points: record with the body, then forward.
macro_rules! intercept {
    ($($name:ident($($a:ident: $t:ty),*) $body:block)*) => {
        $(
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name($($a: $t),*) {
                static REAL: RealFn = RealFn::new(
                    // SAFETY: the literal ends in its only NUL.
                    unsafe { CStr::from_bytes_with_nul_unchecked(concat!(stringify!($name), "\0").as_bytes()) },
                );
                // The body only reads arguments (through null-checked
                // pointers) and records.
                #[allow(unused_unsafe, clippy::redundant_closure_call)]
                let _ = (|| $body)();
                if let Some(p) = REAL.get() {
                    // SAFETY: the system GL's symbol of that name has this
                    // signature (the GL specification's C prototype).
                    let f: unsafe extern "C" fn($($t),*) = unsafe { core::mem::transmute(p) };
                    // SAFETY: the program's own arguments, forwarded.
                    unsafe { f($($a),*) }
                }
            }
        )*

        /// Our entry point for a GL function name, for `glXGetProcAddress`.
        pub(crate) fn lookup(name: &[u8]) -> Option<unsafe extern "C" fn()> {
            match name {
                $(
                    // SAFETY: only ever called back through its own
                    // signature by a program that asked for this name.
                    #[allow(clippy::useless_transmute)]
                    n if n == stringify!($name).as_bytes() => Some(unsafe {
                        core::mem::transmute::<unsafe extern "C" fn($($t),*), unsafe extern "C" fn()>($name)
                    }),
                )*
                _ => None,
            }
        }
    };
}

/// Records a command.
fn rec(c: Command) {
    with_recorder(|r| r.command(c));
}

/// `glRect`: GL's own definition, a polygon of the four corners at z = 0
/// (`glBegin(GL_POLYGON)`, `(x1, y1)`, `(x2, y1)`, `(x2, y2)`, `(x1, y2)`).
fn rect(x1: f32, y1: f32, x2: f32, y2: f32) {
    for c in [
        Command::Begin(gl::POLYGON),
        v4(x1, y1, 0.0, 1.0),
        v4(x2, y1, 0.0, 1.0),
        v4(x2, y2, 0.0, 1.0),
        v4(x1, y2, 0.0, 1.0),
        Command::End,
    ] {
        rec(c);
    }
}

/// The client image a `glTex(Sub)Image2D` call points at, if it can be
/// read: not null, not an offset into a pixel buffer object, of a layout
/// whose size is known.
///
/// # Safety
/// GL requires `data`, if not null and no unpack buffer is bound, to
/// hold the image as the unpack state lays it out.
unsafe fn client_image<'a>(
    r: &Recorder,
    [w, h]: [i32; 2],
    format: u32,
    ty: u32,
    data: *const c_void,
) -> Option<&'a [u8]> {
    if data.is_null() || r.unpacks_from_buffer() {
        return None;
    }
    let n = r.unpack.image_bytes(usize::try_from(w).ok()?, usize::try_from(h).ok()?, format, ty)?;
    // SAFETY: as the caller guarantees.
    Some(unsafe { core::slice::from_raw_parts(data.cast::<u8>(), n) })
}

fn tex_image(
    target: u32,
    level: i32,
    internal: u32,
    size: [i32; 2],
    format: u32,
    ty: u32,
    data: *const c_void,
) {
    with_recorder(|r| {
        // SAFETY: the program's own image, as GL reads it.
        let image = unsafe { client_image(r, size, format, ty, data) };
        // Null data is an image left undefined; anything else unread is
        // an image not known.
        let image = if data.is_null() { None } else { Some(image.unwrap_or(&[])) };
        r.tex_image_2d(target, level, internal, size, format, ty, image);
    });
}

fn tex_sub_image(
    target: u32,
    level: i32,
    at: [i32; 2],
    size: [i32; 2],
    format: u32,
    ty: u32,
    data: *const c_void,
) {
    with_recorder(|r| {
        // SAFETY: the program's own image, as GL reads it.
        let image = unsafe { client_image(r, size, format, ty, data) };
        r.tex_sub_image_2d(target, level, at, size, format, ty, image);
    });
}

fn delete_textures(n: i32, names: *const u32) {
    let Ok(n) = usize::try_from(n) else { return };
    if names.is_null() {
        return;
    }
    // SAFETY: GL requires `names` to hold `n` names.
    let names = unsafe { core::slice::from_raw_parts(names, n) };
    with_recorder(|r| r.delete_textures(names));
}

/// Notes a call the trace does not honour (reported at the next frame).
fn unsupported(what: &'static str) {
    with_recorder(|r| r.unsupported(what));
}

intercept! {
    glBegin(mode: u32) { rec(Command::Begin(mode)) }
    glEnd() { rec(Command::End) }

    glVertex2f(x: f32, y: f32) { rec(v4(x, y, 0.0, 1.0)) }
    glVertex2d(x: f64, y: f64) { rec(v4(x as f32, y as f32, 0.0, 1.0)) }
    glVertex2i(x: i32, y: i32) { rec(v4(x as f32, y as f32, 0.0, 1.0)) }
    glVertex2s(x: i16, y: i16) { rec(v4(x.into(), y.into(), 0.0, 1.0)) }
    glVertex3f(x: f32, y: f32, z: f32) { rec(v4(x, y, z, 1.0)) }
    glVertex3d(x: f64, y: f64, z: f64) { rec(v4(x as f32, y as f32, z as f32, 1.0)) }
    glVertex3i(x: i32, y: i32, z: i32) { rec(v4(x as f32, y as f32, z as f32, 1.0)) }
    glVertex3s(x: i16, y: i16, z: i16) { rec(v4(x.into(), y.into(), z.into(), 1.0)) }
    glVertex4f(x: f32, y: f32, z: f32, w: f32) { rec(v4(x, y, z, w)) }
    glVertex4d(x: f64, y: f64, z: f64, w: f64) { rec(v4(x as f32, y as f32, z as f32, w as f32)) }
    glVertex2fv(v: *const f32) { if let Some([x, y]) = unsafe { read(v) } { rec(v4(x, y, 0.0, 1.0)) } }
    glVertex2dv(v: *const f64) { if let Some([x, y]) = unsafe { read(v) } { rec(v4(x as f32, y as f32, 0.0, 1.0)) } }
    glVertex3fv(v: *const f32) { if let Some([x, y, z]) = unsafe { read(v) } { rec(v4(x, y, z, 1.0)) } }
    glVertex3dv(v: *const f64) { if let Some([x, y, z]) = unsafe { read(v) } { rec(v4(x as f32, y as f32, z as f32, 1.0)) } }
    glVertex3iv(v: *const i32) { if let Some([x, y, z]) = unsafe { read(v) } { rec(v4(x as f32, y as f32, z as f32, 1.0)) } }
    glVertex4fv(v: *const f32) { if let Some([x, y, z, w]) = unsafe { read(v) } { rec(v4(x, y, z, w)) } }
    glVertex4dv(v: *const f64) { if let Some([x, y, z, w]) = unsafe { read(v) } { rec(v4(x as f32, y as f32, z as f32, w as f32)) } }

    glNormal3f(x: f32, y: f32, z: f32) { rec(Command::Normal(Vec3::new(x, y, z))) }
    glNormal3d(x: f64, y: f64, z: f64) { rec(Command::Normal(Vec3::new(x as f32, y as f32, z as f32))) }
    glNormal3fv(v: *const f32) { if let Some(n) = unsafe { read(v) } { rec(Command::Normal(Vec3::from_array(n))) } }
    glNormal3dv(v: *const f64) { if let Some(n) = unsafe { read(v) } { rec(Command::Normal(Vec3::from_array(n.map(|x: f64| x as f32)))) } }

    glColor3f(r: f32, g: f32, b: f32) { rec(Command::Color(Vec4::new(r, g, b, 1.0))) }
    glColor4f(r: f32, g: f32, b: f32, a: f32) { rec(Command::Color(Vec4::new(r, g, b, a))) }
    glColor3d(r: f64, g: f64, b: f64) { rec(Command::Color(Vec4::new(r as f32, g as f32, b as f32, 1.0))) }
    glColor4d(r: f64, g: f64, b: f64, a: f64) { rec(Command::Color(Vec4::new(r as f32, g as f32, b as f32, a as f32))) }
    glColor3ub(r: u8, g: u8, b: u8) { rec(Command::Color(Vec4::new(ub(r), ub(g), ub(b), 1.0))) }
    glColor4ub(r: u8, g: u8, b: u8, a: u8) { rec(Command::Color(Vec4::new(ub(r), ub(g), ub(b), ub(a)))) }
    glColor3fv(v: *const f32) { if let Some([r, g, b]) = unsafe { read(v) } { rec(Command::Color(Vec4::new(r, g, b, 1.0))) } }
    glColor4fv(v: *const f32) { if let Some(c) = unsafe { read(v) } { rec(Command::Color(Vec4::from_array(c))) } }
    glColor3dv(v: *const f64) { if let Some([r, g, b]) = unsafe { read(v) } { rec(Command::Color(Vec4::new(r as f32, g as f32, b as f32, 1.0))) } }
    glColor3ubv(v: *const u8) { if let Some([r, g, b]) = unsafe { read(v) } { rec(Command::Color(Vec4::new(ub(r), ub(g), ub(b), 1.0))) } }
    glColor4ubv(v: *const u8) { if let Some(c) = unsafe { read(v) } { rec(Command::Color(Vec4::from_array(c.map(ub)))) } }

    glNewList(list: u32, mode: u32) { with_recorder(|r| r.new_list(list, mode)) }
    glEndList() { with_recorder(|r| r.end_list()) }
    glCallList(list: u32) { rec(Command::CallList(list)) }
    glCallLists(n: i32, ty: u32, lists: *const c_void) { call_lists(n, ty, lists) }
    glListBase(base: u32) { with_recorder(|r| r.list_base(base)) }
    glDeleteLists(list: u32, range: i32) { with_recorder(|r| r.delete_lists(list, range)) }

    glMatrixMode(mode: u32) { rec(Command::MatrixMode(mode)) }
    glLoadIdentity() { rec(Command::LoadIdentity) }
    glLoadMatrixf(m: *const f32) { if let Some(m) = unsafe { read(m) } { rec(Command::LoadMatrix(mat_f(m))) } }
    glLoadMatrixd(m: *const f64) { if let Some(m) = unsafe { read(m) } { rec(Command::LoadMatrix(mat_d(m))) } }
    glMultMatrixf(m: *const f32) { if let Some(m) = unsafe { read(m) } { rec(Command::MultMatrix(mat_f(m))) } }
    glMultMatrixd(m: *const f64) { if let Some(m) = unsafe { read(m) } { rec(Command::MultMatrix(mat_d(m))) } }
    glTranslatef(x: f32, y: f32, z: f32) { rec(Command::MultMatrix(translate(Vec3::new(x, y, z)))) }
    glTranslated(x: f64, y: f64, z: f64) { rec(Command::MultMatrix(translate(Vec3::new(x as f32, y as f32, z as f32)))) }
    glRotatef(a: f32, x: f32, y: f32, z: f32) { rec(Command::MultMatrix(rotate(a, Vec3::new(x, y, z)))) }
    glRotated(a: f64, x: f64, y: f64, z: f64) { rec(Command::MultMatrix(rotate(a as f32, Vec3::new(x as f32, y as f32, z as f32)))) }
    glScalef(x: f32, y: f32, z: f32) { rec(Command::MultMatrix(scale(Vec3::new(x, y, z)))) }
    glScaled(x: f64, y: f64, z: f64) { rec(Command::MultMatrix(scale(Vec3::new(x as f32, y as f32, z as f32)))) }
    glFrustum(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) { if let Some(m) = frustum(l, r, b, t, n, f) { rec(Command::MultMatrix(m)) } }
    glOrtho(l: f64, r: f64, b: f64, t: f64, n: f64, f: f64) { if let Some(m) = ortho(l, r, b, t, n, f) { rec(Command::MultMatrix(m)) } }
    glPushMatrix() { rec(Command::PushMatrix) }
    glPopMatrix() { rec(Command::PopMatrix) }

    glViewport(x: i32, y: i32, w: i32, h: i32) { if w >= 0 && h >= 0 { with_recorder(|r| r.viewport = [x, y, w, h]); } }
    glClearColor(r: f32, g: f32, b: f32, a: f32) { with_recorder(|rec| rec.clear_color = Vec4::new(r, g, b, a).clamp(Vec4::ZERO, Vec4::ONE)) }
    glClear(mask: u32) { with_recorder(|r| r.clear(mask)) }
    glEnable(cap: u32) { rec(Command::Enable(cap)) }
    glPolygonMode(face: u32, mode: u32) { rec(Command::PolygonMode(face, mode)) }
    glFogf(pname: u32, v: f32) { rec(Command::Fog(pname, Vec4::new(v, 0.0, 0.0, 0.0))) }
    glFogi(pname: u32, v: i32) { rec(Command::Fog(pname, Vec4::new(v as f32, 0.0, 0.0, 0.0))) }
    glFogfv(pname: u32, v: *const f32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::Fog(pname, p)) } }
    glFogiv(pname: u32, v: *const i32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::Fog(pname, int_param(pname, p))) } }
    glBlendFunc(src: u32, dst: u32) { rec(Command::BlendFunc(src, dst)) }
    glCullFace(face: u32) { rec(Command::CullFace(face)) }
    glColorMask(r: u8, g: u8, b: u8, a: u8) { rec(Command::ColorMask(r != 0 || g != 0 || b != 0 || a != 0)) }
    glFrontFace(mode: u32) { rec(Command::FrontFace(mode)) }
    glRectf(x1: f32, y1: f32, x2: f32, y2: f32) { rect(x1, y1, x2, y2) }
    glRectd(x1: f64, y1: f64, x2: f64, y2: f64) { rect(x1 as f32, y1 as f32, x2 as f32, y2 as f32) }
    glRecti(x1: i32, y1: i32, x2: i32, y2: i32) { rect(x1 as f32, y1 as f32, x2 as f32, y2 as f32) }
    glRects(x1: i16, y1: i16, x2: i16, y2: i16) { rect(x1.into(), y1.into(), x2.into(), y2.into()) }
    glRectfv(a: *const f32, b: *const f32) { if let (Some([x1, y1]), Some([x2, y2])) = unsafe { (read(a), read(b)) } { rect(x1, y1, x2, y2) } }
    glRectdv(a: *const f64, b: *const f64) { if let (Some([x1, y1]), Some([x2, y2])) = unsafe { (read(a), read(b)) } { rect(x1 as f32, y1 as f32, x2 as f32, y2 as f32) } }
    glInterleavedArrays(format: u32, stride: i32, p: *const c_void) { with_recorder(|r| r.interleaved_arrays(format, stride, p as usize)); }
    glTexCoord1f(s: f32) { rec(Command::TexCoord(Vec4::new(s, 0.0, 0.0, 1.0))) }
    glTexCoord1d(s: f64) { rec(Command::TexCoord(Vec4::new(s as f32, 0.0, 0.0, 1.0))) }
    glTexCoord2f(s: f32, t: f32) { rec(Command::TexCoord(Vec4::new(s, t, 0.0, 1.0))) }
    glTexCoord2d(s: f64, t: f64) { rec(Command::TexCoord(Vec4::new(s as f32, t as f32, 0.0, 1.0))) }
    glTexCoord2i(s: i32, t: i32) { rec(Command::TexCoord(Vec4::new(s as f32, t as f32, 0.0, 1.0))) }
    glTexCoord2s(s: i16, t: i16) { rec(Command::TexCoord(Vec4::new(s.into(), t.into(), 0.0, 1.0))) }
    glTexCoord3f(s: f32, t: f32, r: f32) { rec(Command::TexCoord(Vec4::new(s, t, r, 1.0))) }
    glTexCoord4f(s: f32, t: f32, r: f32, q: f32) { rec(Command::TexCoord(Vec4::new(s, t, r, q))) }
    glTexCoord2fv(v: *const f32) { if let Some([s, t]) = unsafe { read(v) } { rec(Command::TexCoord(Vec4::new(s, t, 0.0, 1.0))) } }
    glTexCoord2dv(v: *const f64) { if let Some([s, t]) = unsafe { read(v) } { rec(Command::TexCoord(Vec4::new(s as f32, t as f32, 0.0, 1.0))) } }
    glTexCoord3fv(v: *const f32) { if let Some([s, t, r]) = unsafe { read(v) } { rec(Command::TexCoord(Vec4::new(s, t, r, 1.0))) } }
    glTexCoord4fv(v: *const f32) { if let Some(c) = unsafe { read(v) } { rec(Command::TexCoord(Vec4::from_array(c))) } }
    glMultiTexCoord2f(unit: u32, s: f32, t: f32) { if unit == 0x84C0 { rec(Command::TexCoord(Vec4::new(s, t, 0.0, 1.0))) } }
    glMultiTexCoord2fv(unit: u32, v: *const f32) { if let (0x84C0, Some([s, t])) = (unit, unsafe { read(v) }) { rec(Command::TexCoord(Vec4::new(s, t, 0.0, 1.0))) } }
    glTexCoordPointer(size: i32, ty: u32, stride: i32, p: *const c_void) { with_recorder(|r| r.pointer(arrays::TEXTURE_COORD_ARRAY, size, ty, stride, p as usize)); }
    glBindTexture(target: u32, name: u32) { rec(Command::BindTexture(target, name)) }
    glDeleteTextures(n: i32, names: *const u32) { delete_textures(n, names) }
    glActiveTexture(unit: u32) { with_recorder(|r| r.active_texture(unit)); }
    glActiveTextureARB(unit: u32) { with_recorder(|r| r.active_texture(unit)); }
    glTexImage2D(target: u32, level: i32, internal: i32, w: i32, h: i32, border: i32, format: u32, ty: u32, data: *const c_void) { let _ = border; tex_image(target, level, internal as u32, [w, h], format, ty, data) }
    glTexSubImage2D(target: u32, level: i32, x: i32, y: i32, w: i32, h: i32, format: u32, ty: u32, data: *const c_void) { tex_sub_image(target, level, [x, y], [w, h], format, ty, data) }
    glTexParameteri(target: u32, pname: u32, v: i32) { with_recorder(|r| r.tex_parameter(target, pname, v as f32)); }
    glTexParameterf(target: u32, pname: u32, v: f32) { with_recorder(|r| r.tex_parameter(target, pname, v)); }
    glTexParameteriv(target: u32, pname: u32, v: *const i32) { if let Some([x]) = unsafe { read(v) } { with_recorder(|r| r.tex_parameter(target, pname, x as f32)); } }
    glTexParameterfv(target: u32, pname: u32, v: *const f32) { if let Some([x]) = unsafe { read(v) } { with_recorder(|r| r.tex_parameter(target, pname, x)); } }
    glTexEnvi(target: u32, pname: u32, v: i32) { if target == 0x2300 { rec(Command::TexEnv(pname, Vec4::new(v as f32, 0.0, 0.0, 0.0))) } }
    glTexEnvf(target: u32, pname: u32, v: f32) { if target == 0x2300 { rec(Command::TexEnv(pname, Vec4::new(v, 0.0, 0.0, 0.0))) } }
    glTexEnvfv(target: u32, pname: u32, v: *const f32) { if target == 0x2300 && let Some(p) = unsafe { params(pname, v) } { rec(Command::TexEnv(pname, p)) } }
    glTexEnviv(target: u32, pname: u32, v: *const i32) { if target == 0x2300 && let Some(p) = unsafe { params(pname, v) } { rec(Command::TexEnv(pname, int_param(pname, p))) } }
    glPixelStorei(pname: u32, v: i32) { with_recorder(|r| r.pixel_store(pname, v)); }
    glAlphaFunc(func: u32, reference: f32) { rec(Command::AlphaFunc(func, reference)) }
    glDepthFunc(func: u32) { rec(Command::DepthFunc(func)) }
    glTexGeni(coord: u32, pname: u32, v: i32) { rec(Command::TexGen(coord, pname, Vec4::new(v as f32, 0.0, 0.0, 0.0))) }
    glTexGenf(coord: u32, pname: u32, v: f32) { rec(Command::TexGen(coord, pname, Vec4::new(v, 0.0, 0.0, 0.0))) }
    glTexGenfv(coord: u32, pname: u32, v: *const f32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::TexGen(coord, pname, p)) } }
    glTexGendv(coord: u32, pname: u32, v: *const f64) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::TexGen(coord, pname, p)) } }
    glBitmap(w: i32, h: i32, xo: f32, yo: f32, xm: f32, ym: f32, b: *const u8) { let _ = b; rec(Command::Bitmap { size: [w, h], origin: glam::Vec2::new(xo, yo), advance: glam::Vec2::new(xm, ym) }) }
    glDrawPixels(w: i32, h: i32, format: u32, ty: u32, data: *const c_void) { let _ = (format, ty, data); rec(Command::DrawPixels([w, h])) }
    glRasterPos2i(x: i32, y: i32) { rec(Command::RasterPos(Vec4::new(x as f32, y as f32, 0.0, 1.0))) }
    glRasterPos2f(x: f32, y: f32) { rec(Command::RasterPos(Vec4::new(x, y, 0.0, 1.0))) }
    glRasterPos2d(x: f64, y: f64) { rec(Command::RasterPos(Vec4::new(x as f32, y as f32, 0.0, 1.0))) }
    glRasterPos3i(x: i32, y: i32, z: i32) { rec(Command::RasterPos(Vec4::new(x as f32, y as f32, z as f32, 1.0))) }
    glRasterPos3f(x: f32, y: f32, z: f32) { rec(Command::RasterPos(Vec4::new(x, y, z, 1.0))) }
    glRasterPos3d(x: f64, y: f64, z: f64) { rec(Command::RasterPos(Vec4::new(x as f32, y as f32, z as f32, 1.0))) }
    glRasterPos4f(x: f32, y: f32, z: f32, w: f32) { rec(Command::RasterPos(Vec4::new(x, y, z, w))) }
    glRasterPos2fv(v: *const f32) { if let Some([x, y]) = unsafe { read(v) } { rec(Command::RasterPos(Vec4::new(x, y, 0.0, 1.0))) } }
    glRasterPos3fv(v: *const f32) { if let Some([x, y, z]) = unsafe { read(v) } { rec(Command::RasterPos(Vec4::new(x, y, z, 1.0))) } }
    glRasterPos3dv(v: *const f64) { if let Some([x, y, z]) = unsafe { read(v) } { rec(Command::RasterPos(Vec4::new(x as f32, y as f32, z as f32, 1.0))) } }
    glWindowPos2i(x: i32, y: i32) { rec(Command::WindowPos(Vec3::new(x as f32, y as f32, 0.0))) }
    glWindowPos2f(x: f32, y: f32) { rec(Command::WindowPos(Vec3::new(x, y, 0.0))) }
    glWindowPos3f(x: f32, y: f32, z: f32) { rec(Command::WindowPos(Vec3::new(x, y, z))) }
    glUseProgram(program: u32) { if program != 0 { unsupported("glUseProgram") } }
    glDisable(cap: u32) { rec(Command::Disable(cap)) }
    glShadeModel(mode: u32) { rec(Command::ShadeModel(mode)) }
    glPointSize(size: f32) { rec(Command::PointSize(size)) }
    glLineWidth(width: f32) { rec(Command::LineWidth(width)) }

    glLightf(light: u32, pname: u32, v: f32) { rec(Command::Light(light, pname, Vec4::new(v, 0.0, 0.0, 0.0))) }
    glLighti(light: u32, pname: u32, v: i32) { rec(Command::Light(light, pname, Vec4::new(v as f32, 0.0, 0.0, 0.0))) }
    glLightfv(light: u32, pname: u32, v: *const f32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::Light(light, pname, p)) } }
    glLightiv(light: u32, pname: u32, v: *const i32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::Light(light, pname, int_param(pname, p))) } }
    glLightModelf(pname: u32, v: f32) { rec(Command::LightModel(pname, Vec4::new(v, 0.0, 0.0, 0.0))) }
    glLightModeli(pname: u32, v: i32) { rec(Command::LightModel(pname, Vec4::new(v as f32, 0.0, 0.0, 0.0))) }
    glLightModelfv(pname: u32, v: *const f32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::LightModel(pname, p)) } }
    glMaterialf(face: u32, pname: u32, v: f32) { rec(Command::Material(face, pname, Vec4::new(v, 0.0, 0.0, 0.0))) }
    glMateriali(face: u32, pname: u32, v: i32) { rec(Command::Material(face, pname, Vec4::new(v as f32, 0.0, 0.0, 0.0))) }
    glMaterialfv(face: u32, pname: u32, v: *const f32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::Material(face, pname, p)) } }
    glMaterialiv(face: u32, pname: u32, v: *const i32) { if let Some(p) = unsafe { params(pname, v) } { rec(Command::Material(face, pname, int_param(pname, p))) } }
    glColorMaterial(face: u32, mode: u32) { rec(Command::ColorMaterial(face, mode)) }

    glEnableClientState(array: u32) { with_recorder(|r| r.client_state(array, true)); }
    glDisableClientState(array: u32) { with_recorder(|r| r.client_state(array, false)); }
    glVertexPointer(size: i32, ty: u32, stride: i32, p: *const c_void) { with_recorder(|r| r.pointer(arrays::VERTEX_ARRAY, size, ty, stride, p as usize)); }
    glNormalPointer(ty: u32, stride: i32, p: *const c_void) { with_recorder(|r| r.pointer(arrays::NORMAL_ARRAY, 3, ty, stride, p as usize)); }
    glColorPointer(size: i32, ty: u32, stride: i32, p: *const c_void) { with_recorder(|r| r.pointer(arrays::COLOR_ARRAY, size, ty, stride, p as usize)); }
    glBindBuffer(target: u32, buffer: u32) { with_recorder(|r| r.bind_buffer(target, buffer)); }
    glBindBufferARB(target: u32, buffer: u32) { with_recorder(|r| r.bind_buffer(target, buffer)); }
    glBufferData(target: u32, size: isize, data: *const c_void, usage: u32) { buffer_data(target, size, data, usage) }
    glBufferDataARB(target: u32, size: isize, data: *const c_void, usage: u32) { buffer_data(target, size, data, usage) }
    glBufferSubData(target: u32, offset: isize, size: isize, data: *const c_void) { buffer_sub_data(target, offset, size, data) }
    glBufferSubDataARB(target: u32, offset: isize, size: isize, data: *const c_void) { buffer_sub_data(target, offset, size, data) }
    glDeleteBuffers(n: i32, ids: *const u32) { delete_buffers(n, ids) }
    glDeleteBuffersARB(n: i32, ids: *const u32) { delete_buffers(n, ids) }
    // SAFETY (the draws): GL requires enabled client arrays and client
    // indices to cover what is drawn; the recorder reads no more.
    glDrawArrays(mode: u32, first: i32, count: i32) { with_recorder(|r| unsafe { r.draw_arrays(mode, first, count) }); }
    glDrawElements(mode: u32, count: i32, ty: u32, indices: *const c_void) { with_recorder(|r| unsafe { r.draw_elements(mode, count, ty, indices as usize) }); }
    glDrawRangeElements(mode: u32, start: u32, end: u32, count: i32, ty: u32, indices: *const c_void) { let _ = (start, end); with_recorder(|r| unsafe { r.draw_elements(mode, count, ty, indices as usize) }); }
    glMultiDrawArrays(mode: u32, first: *const i32, count: *const i32, n: i32) { multi_draw_arrays(mode, first, count, n) }
    glMultiDrawElements(mode: u32, count: *const i32, ty: u32, indices: *const *const c_void, n: i32) { multi_draw_elements(mode, count, ty, indices, n) }

    glFlush() { crate::present::single_buffered_frame() }
    glFinish() { crate::present::single_buffered_frame() }
}

fn buffer_data(target: u32, size: isize, data: *const c_void, _usage: u32) {
    let Ok(size) = usize::try_from(size) else { return };
    let bytes = (!data.is_null() && size <= arrays::MAX_BUFFER_BYTES)
        // SAFETY: GL requires `data` to hold `size` bytes.
        .then(|| unsafe { core::slice::from_raw_parts(data.cast::<u8>(), size) });
    with_recorder(|r| r.buffer_data(target, size, bytes));
}

fn buffer_sub_data(target: u32, offset: isize, size: isize, data: *const c_void) {
    let (Ok(offset), Ok(size)) = (usize::try_from(offset), usize::try_from(size)) else { return };
    if data.is_null() || size > arrays::MAX_BUFFER_BYTES {
        return;
    }
    // SAFETY: GL requires `data` to hold `size` bytes.
    let bytes = unsafe { core::slice::from_raw_parts(data.cast::<u8>(), size) };
    with_recorder(|r| r.buffer_sub_data(target, offset, bytes));
}

fn delete_buffers(n: i32, ids: *const u32) {
    let Ok(n) = usize::try_from(n) else { return };
    if ids.is_null() {
        return;
    }
    // SAFETY: GL requires `ids` to hold `n` names.
    let ids = unsafe { core::slice::from_raw_parts(ids, n) };
    with_recorder(|r| r.delete_buffers(ids));
}

fn multi_draw_arrays(mode: u32, first: *const i32, count: *const i32, n: i32) {
    let Ok(n) = usize::try_from(n) else { return };
    if first.is_null() || count.is_null() {
        return;
    }
    for i in 0..n {
        // SAFETY: GL requires both arrays to hold `n` values, and the
        // client arrays to cover each range.
        unsafe { with_recorder(|r| r.draw_arrays(mode, *first.add(i), *count.add(i))) };
    }
}

fn multi_draw_elements(
    mode: u32,
    count: *const i32,
    ty: u32,
    indices: *const *const c_void,
    n: i32,
) {
    let Ok(n) = usize::try_from(n) else { return };
    if count.is_null() || indices.is_null() {
        return;
    }
    for i in 0..n {
        // SAFETY: GL requires both arrays to hold `n` values, and each
        // index list to hold its count.
        unsafe {
            let (c, p) = (*count.add(i), *indices.add(i) as usize);
            with_recorder(|r| r.draw_elements(mode, c, ty, p));
        }
    }
}

/// `glCallLists`: reads `n` ids of type `ty` (GL 2.1 §5.4).
fn call_lists(n: i32, ty: u32, lists: *const c_void) {
    if n <= 0 || lists.is_null() {
        return;
    }
    let n = n as usize;
    // SAFETY (all arms): GL requires `lists` to hold `n` ids of type `ty`.
    let ids: Vec<u32> = unsafe {
        match ty {
            gl::UNSIGNED_BYTE => (0..n).map(|i| u32::from(*lists.cast::<u8>().add(i))).collect(),
            gl::BYTE => (0..n).map(|i| *lists.cast::<i8>().add(i) as u32).collect(),
            gl::UNSIGNED_SHORT => (0..n).map(|i| u32::from(*lists.cast::<u16>().add(i))).collect(),
            gl::SHORT => (0..n).map(|i| *lists.cast::<i16>().add(i) as u32).collect(),
            gl::UNSIGNED_INT => (0..n).map(|i| *lists.cast::<u32>().add(i)).collect(),
            gl::INT => (0..n).map(|i| *lists.cast::<i32>().add(i) as u32).collect(),
            gl::FLOAT => (0..n).map(|i| *lists.cast::<f32>().add(i) as u32).collect(),
            _ => return,
        }
    };
    with_recorder(|r| r.call_lists(&ids));
}

/// `glXSwapBuffers`: ray trace the frame into the back buffer, then swap.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn glXSwapBuffers(dpy: *mut c_void, drawable: u64) {
    crate::present::swap_frame();
    // SAFETY: the program's own arguments, forwarded.
    unsafe { crate::real::glXSwapBuffers(dpy, drawable) }
}

/// `eglSwapBuffers`: as [`glXSwapBuffers`], for programs that make their
/// context with EGL.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eglSwapBuffers(dpy: *mut c_void, surface: *mut c_void) -> u32 {
    crate::present::swap_frame();
    // SAFETY: the program's own arguments, forwarded.
    unsafe { crate::real::eglSwapBuffers(dpy, surface) }
}

/// `eglGetProcAddress`: our entry points for the names we record (GL's
/// and `eglSwapBuffers`), the real EGL's for the rest.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn eglGetProcAddress(name: *const u8) -> Option<unsafe extern "C" fn()> {
    if name.is_null() {
        return None;
    }
    // SAFETY: EGL passes a NUL-terminated name.
    let bytes = unsafe { CStr::from_ptr(name.cast()) }.to_bytes();
    if bytes == b"eglSwapBuffers" {
        // SAFETY: called back only through its own signature.
        return Some(unsafe {
            core::mem::transmute::<
                unsafe extern "C" fn(*mut c_void, *mut c_void) -> u32,
                unsafe extern "C" fn(),
            >(eglSwapBuffers)
        });
    }
    // SAFETY: forwarded as given.
    lookup(bytes).or_else(|| unsafe { crate::real::eglGetProcAddress(name) })
}

/// `glXGetProcAddress`: our entry points for the names we record, the
/// real GL's for the rest.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn glXGetProcAddress(name: *const u8) -> Option<unsafe extern "C" fn()> {
    // SAFETY: GLX passes a NUL-terminated name.
    unsafe { proc_address(name, false) }
}

/// `glXGetProcAddressARB`: as [`glXGetProcAddress`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn glXGetProcAddressARB(name: *const u8) -> Option<unsafe extern "C" fn()> {
    // SAFETY: GLX passes a NUL-terminated name.
    unsafe { proc_address(name, true) }
}

/// # Safety
/// `name` must be null or NUL-terminated.
unsafe fn proc_address(name: *const u8, arb: bool) -> Option<unsafe extern "C" fn()> {
    if name.is_null() {
        return None;
    }
    // SAFETY: the caller guarantees a NUL-terminated string.
    let bytes = unsafe { CStr::from_ptr(name.cast()) }.to_bytes();
    match bytes {
        b"glXSwapBuffers" => {
            return Some(
                // SAFETY: called back only through its own signature.
                unsafe {
                    core::mem::transmute::<
                        unsafe extern "C" fn(*mut c_void, u64),
                        unsafe extern "C" fn(),
                    >(glXSwapBuffers)
                },
            );
        }
        b"glXGetProcAddress" | b"glXGetProcAddressARB" => {
            // SAFETY: as above.
            return Some(unsafe {
                core::mem::transmute::<
                    unsafe extern "C" fn(*const u8) -> Option<unsafe extern "C" fn()>,
                    unsafe extern "C" fn(),
                >(if arb { glXGetProcAddressARB } else { glXGetProcAddress })
            });
        }
        _ => {}
    }
    if let Some(f) = lookup(bytes) {
        return Some(f);
    }
    // SAFETY: forwarded as given.
    unsafe {
        if arb {
            crate::real::glXGetProcAddressARB(name)
        } else {
            crate::real::glXGetProcAddress(name)
        }
    }
}
