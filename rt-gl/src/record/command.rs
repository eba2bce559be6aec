//! The calls the recorder takes, one value each: what display lists store
//! and what [`Recorder::command`](super::Recorder::command) executes.

use glam::{Mat4, Vec3, Vec4};

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
    /// `glFrontFace`: which winding faces front (`GL_CCW`, `GL_CW`).
    FrontFace(u32),
    /// `glPointSize` (pixels).
    PointSize(f32),
    /// `glLineWidth` (pixels).
    LineWidth(f32),
    /// `glCallList`.
    CallList(u32),
    /// `glPolygonMode(face, mode)`.
    PolygonMode(u32, u32),
    /// `glFog*(pname, value)` (scalars in `value[0]`).
    Fog(u32, Vec4),
    /// `glBlendFunc(source, destination)`.
    BlendFunc(u32, u32),
    /// `glCullFace(face)`.
    CullFace(u32),
    /// `glColorMask`: whether any colour channel is written (a depth-only
    /// pass writes none).
    ColorMask(bool),
    /// `glTexCoord*` (missing coordinates as GL fills them: `t = 0, r =
    /// 0, q = 1`).
    TexCoord(Vec4),
    /// `glBindTexture(target, name)`.
    BindTexture(u32, u32),
    /// `glTexEnv*(pname, value)` of `GL_TEXTURE_ENV` (scalars in
    /// `value[0]`).
    TexEnv(u32, Vec4),
    /// `glAlphaFunc(function, reference)`.
    AlphaFunc(u32, f32),
    /// `glDepthFunc(function)`.
    DepthFunc(u32),
    /// `glTexGen*(coord, pname, value)` (scalars in `value[0]`).
    TexGen(u32, u32, Vec4),
    /// `glRasterPos*` (object coordinates).
    RasterPos(Vec4),
    /// `glWindowPos*` (window coordinates and depth).
    WindowPos(Vec3),
    /// `glBitmap(width, height, xorig, yorig, xmove, ymove, …)`: the
    /// rectangle it draws at the raster position (its bits are GL's to
    /// draw), and the raster position's move.
    Bitmap {
        /// Width and height in pixels.
        size: [i32; 2],
        /// `(xorig, yorig)`.
        origin: glam::Vec2,
        /// `(xmove, ymove)`.
        advance: glam::Vec2,
    },
    /// `glDrawPixels(width, height, …)`: the rectangle it draws at the
    /// raster position.
    DrawPixels([i32; 2]),
}
