/*
 * A program that loads its GL the way toolkits do (Qt's GLX plugin,
 * Python bindings): libGL is opened with dlopen(RTLD_LOCAL), never
 * linked, and every entry point comes from glXGetProcAddressARB, itself
 * found through the global scope (RTLD_DEFAULT) first, as a toolkit that
 * also supports an already-loaded GL does. Under an interposer that finds
 * the real GL only in the global scope, the entry points come back null.
 * It knows nothing of rt-gl.
 *
 *   private_gl frames [noviewport|shadow]
 *                       draw a lit, rotating ball of triangles for
 *                       `frames` frames; prints "frames <n>". With
 *                       `noviewport`, never call glViewport: GL's initial
 *                       viewport (the window's size) is the one in force.
 *                       With `shadow`, the ball is a display list, drawn
 *                       again flattened onto a floor by a projective
 *                       (planar-shadow) matrix, dark, blended and
 *                       stencilled.
 *                       With `arrays`, the ball comes from one interleaved
 *                       array (glInterleavedArrays GL_C4F_N3F_V3F, colour
 *                       varying with height, glDrawArrays) beside a panel
 *                       drawn with glRectf.
 *                       With `cw`, the ball is wound clockwise under
 *                       glFrontFace(GL_CW) and two-sided lighting: its
 *                       outside is its front.
 *                       With `lightsoff`, lighting and the light are
 *                       turned off after the ball is drawn, before the
 *                       swap (as a viewer does before its 2-D overlays).
 *                       With `overlay`, a mesh generator's frame: a band
 *                       under the identity projection with the depth
 *                       test off, behind; the ball under a 3-D glOrtho;
 *                       then 2-D overlays (a bar, a frame of lines) under
 *                       a pixel glOrtho, the depth test off.
 *                       With `viewports`, two views side by side, each
 *                       cleared under the scissor test: the ball in
 *                       perspective on the left, under glOrtho and in
 *                       another colour on the right.
 *                       With `depthclear`, a second, smaller ball behind
 *                       the first drawn after glClear(GL_DEPTH_BUFFER_BIT):
 *                       GL shows it in front.
 *                       With `fog`, the ball in fog: linear, exp and exp2
 *                       in turn, frame by frame.
 *                       With `blend`, two translucent balls (alpha
 *                       blending, back faces culled, GL_NORMALIZE for
 *                       their scale) drawn back to front after the ball.
 *                       With `wireframe`, the ball as its edges
 *                       (glPolygonMode GL_LINE), unlit.
 *                       With `still`, the ball does not turn.
 *                       With `texture`, a checkerboard (RGB, nearest,
 *                       modulating the lit colour) on a turning quad,
 *                       and in front of the ball a quad whose RGBA
 *                       texture (linear, replacing the colour) has round
 *                       holes cut by the alpha test.
 *                       With `texgen`, the checkerboard sphere-mapped on
 *                       the turning ball, and object-linear on a quad.
 *                       With `bitmap`, the ball with bitmap text: a
 *                       label at a 3-D raster position in front of it
 *                       (glRasterPos3f, glBitmap glyphs moving the raster
 *                       position), a line at a window position
 *                       (glWindowPos2i), and a small image
 *                       (glDrawPixels), all unlit.
 *
 * Build: cc -O2 -o private_gl private_gl.c -lX11 -ldl -lm
 */
#include <GL/gl.h>
#include <GL/glx.h>
#include <X11/Xlib.h>
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef void (*fn)(void);
/* The entry points ball() draws with (set in main). */
static int clockwise;
static void (*p_begin)(GLenum), (*p_end)(void), (*p_color3f)(GLfloat, GLfloat, GLfloat),
    (*p_normal3f)(GLfloat, GLfloat, GLfloat), (*p_vertex3f)(GLfloat, GLfloat, GLfloat);

/* A faceted ball of radius 1.2: latitude bands of quads as triangle
 * pairs, in the current colour. */
static void ball(void) {
    p_begin(GL_TRIANGLES);
    const int n = 16;
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < 2 * n; j++) {
            double t0 = M_PI * i / n, t1 = M_PI * (i + 1) / n;
            double p0 = M_PI * j / n, p1 = M_PI * (j + 1) / n;
            double v[4][3] = {
                {sin(t0) * cos(p0), cos(t0), sin(t0) * sin(p0)},
                {sin(t1) * cos(p0), cos(t1), sin(t1) * sin(p0)},
                {sin(t1) * cos(p1), cos(t1), sin(t1) * sin(p1)},
                {sin(t0) * cos(p1), cos(t0), sin(t0) * sin(p1)},
            };
            int ccw[6] = {0, 1, 2, 0, 2, 3}, cw[6] = {0, 2, 1, 0, 3, 2};
            int *tri = clockwise ? cw : ccw;
            for (int k = 0; k < 6; k++) {
                double *p = v[tri[k]];
                p_normal3f(p[0], p[1], p[2]);
                p_vertex3f(1.2 * p[0], 1.2 * p[1], 1.2 * p[2]);
            }
        }
    }
    p_end();
}
typedef fn (*getproc_t)(const GLubyte *);
static getproc_t getproc;

/* `name` from GL, or exit 2 with its name: a null entry point is the
 * crash this program exists to catch, told apart from others. */
static fn need(const char *name) {
    fn f = getproc((const GLubyte *)name);
    if (!f) {
        fprintf(stderr, "private_gl: %s is null\n", name);
        exit(2);
    }
    return f;
}

int main(int argc, char **argv) {
    int frames = argc >= 2 ? atoi(argv[1]) : 4;
    int set_viewport = !(argc >= 3 && strcmp(argv[2], "noviewport") == 0);
    int shadow = argc >= 3 && strcmp(argv[2], "shadow") == 0;
    int arrays = argc >= 3 && strcmp(argv[2], "arrays") == 0;
    clockwise = argc >= 3 && strcmp(argv[2], "cw") == 0;
    int lightsoff = argc >= 3 && strcmp(argv[2], "lightsoff") == 0;
    void *gl = dlopen("libGL.so.1", RTLD_NOW | RTLD_LOCAL);
    if (!gl) {
        fprintf(stderr, "private_gl: %s\n", dlerror());
        return 1;
    }
    getproc = (getproc_t)dlsym(RTLD_DEFAULT, "glXGetProcAddressARB");
    if (!getproc) getproc = (getproc_t)dlsym(gl, "glXGetProcAddressARB");
    if (!getproc) {
        fprintf(stderr, "private_gl: no glXGetProcAddressARB\n");
        return 1;
    }
    XVisualInfo *(*chooseVisual)(Display *, int, int *) = (void *)need("glXChooseVisual");
    GLXContext (*createContext)(Display *, XVisualInfo *, GLXContext, Bool) =
        (void *)need("glXCreateContext");
    Bool (*makeCurrent)(Display *, GLXDrawable, GLXContext) = (void *)need("glXMakeCurrent");
    void (*swapBuffers)(Display *, GLXDrawable) = (void *)need("glXSwapBuffers");
    void (*destroyContext)(Display *, GLXContext) = (void *)need("glXDestroyContext");

    Display *dpy = XOpenDisplay(NULL);
    if (!dpy) {
        fprintf(stderr, "private_gl: cannot open the X display\n");
        return 1;
    }
    int attrs[] = {GLX_RGBA, GLX_DOUBLEBUFFER, GLX_DEPTH_SIZE, 16, GLX_RED_SIZE, 8, None};
    XVisualInfo *vi = chooseVisual(dpy, DefaultScreen(dpy), attrs);
    if (!vi) {
        fprintf(stderr, "private_gl: no double-buffered RGBA visual\n");
        return 1;
    }
    XSetWindowAttributes swa;
    swa.colormap = XCreateColormap(dpy, RootWindow(dpy, vi->screen), vi->visual, AllocNone);
    swa.event_mask = ExposureMask;
    Window win = XCreateWindow(dpy, RootWindow(dpy, vi->screen), 0, 0, 256, 256, 0, vi->depth,
                               InputOutput, vi->visual, CWColormap | CWEventMask, &swa);
    GLXContext ctx = createContext(dpy, vi, NULL, True);
    XMapWindow(dpy, win);
    makeCurrent(dpy, win, ctx);

    void (*viewport)(GLint, GLint, GLsizei, GLsizei) = (void *)need("glViewport");
    void (*clearColor)(GLfloat, GLfloat, GLfloat, GLfloat) = (void *)need("glClearColor");
    void (*clear)(GLbitfield) = (void *)need("glClear");
    void (*enable)(GLenum) = (void *)need("glEnable");
    void (*matrixMode)(GLenum) = (void *)need("glMatrixMode");
    void (*loadIdentity)(void) = (void *)need("glLoadIdentity");
    void (*frustum)(GLdouble, GLdouble, GLdouble, GLdouble, GLdouble, GLdouble) =
        (void *)need("glFrustum");
    void (*translatef)(GLfloat, GLfloat, GLfloat) = (void *)need("glTranslatef");
    void (*rotatef)(GLfloat, GLfloat, GLfloat, GLfloat) = (void *)need("glRotatef");
    void (*lightfv)(GLenum, GLenum, const GLfloat *) = (void *)need("glLightfv");
    void (*begin)(GLenum) = (void *)need("glBegin");
    void (*end)(void) = (void *)need("glEnd");
    void (*color3f)(GLfloat, GLfloat, GLfloat) = (void *)need("glColor3f");
    void (*normal3f)(GLfloat, GLfloat, GLfloat) = (void *)need("glNormal3f");
    void (*vertex3f)(GLfloat, GLfloat, GLfloat) = (void *)need("glVertex3f");
    void (*finish)(void) = (void *)need("glFinish");
    void (*newList)(GLuint, GLenum) = (void *)need("glNewList");
    void (*endList)(void) = (void *)need("glEndList");
    void (*callList)(GLuint) = (void *)need("glCallList");
    void (*pushMatrix)(void) = (void *)need("glPushMatrix");
    void (*popMatrix)(void) = (void *)need("glPopMatrix");
    void (*multMatrixf)(const GLfloat *) = (void *)need("glMultMatrixf");
    void (*disable)(GLenum) = (void *)need("glDisable");
    void (*blendFunc)(GLenum, GLenum) = (void *)need("glBlendFunc");
    void (*color4f)(GLfloat, GLfloat, GLfloat, GLfloat) = (void *)need("glColor4f");
    void (*interleavedArrays)(GLenum, GLsizei, const void *) = (void *)need("glInterleavedArrays");
    void (*drawArrays)(GLenum, GLint, GLsizei) = (void *)need("glDrawArrays");
    void (*rectf)(GLfloat, GLfloat, GLfloat, GLfloat) = (void *)need("glRectf");
    void (*frontFace)(GLenum) = (void *)need("glFrontFace");
    void (*lightModeli)(GLenum, GLint) = (void *)need("glLightModeli");
    void (*ortho)(GLdouble, GLdouble, GLdouble, GLdouble, GLdouble, GLdouble) =
        (void *)need("glOrtho");
    void (*scissor)(GLint, GLint, GLsizei, GLsizei) = (void *)need("glScissor");
    void (*lineWidth)(GLfloat) = (void *)need("glLineWidth");
    void (*vertex2f)(GLfloat, GLfloat) = (void *)need("glVertex2f");
    void (*scalef)(GLfloat, GLfloat, GLfloat) = (void *)need("glScalef");
    const char *mode = argc >= 3 ? argv[2] : "";
    int overlay = strcmp(mode, "overlay") == 0;
    int viewports = strcmp(mode, "viewports") == 0;
    int depthclear = strcmp(mode, "depthclear") == 0;
    int fog = strcmp(mode, "fog") == 0;
    int blend = strcmp(mode, "blend") == 0;
    int wireframe = strcmp(mode, "wireframe") == 0;
    int still = strcmp(mode, "still") == 0;
    int texture = strcmp(mode, "texture") == 0;
    int bitmap = strcmp(mode, "bitmap") == 0;
    int texgen = strcmp(mode, "texgen") == 0;
    void (*texGeni)(GLenum, GLenum, GLint) = (void *)need("glTexGeni");
    void (*texGenfv)(GLenum, GLenum, const GLfloat *) = (void *)need("glTexGenfv");
    void (*rasterPos3f)(GLfloat, GLfloat, GLfloat) = (void *)need("glRasterPos3f");
    void (*windowPos2i)(GLint, GLint) = (void *)need("glWindowPos2i");
    void (*bitmapf)(GLsizei, GLsizei, GLfloat, GLfloat, GLfloat, GLfloat, const GLubyte *) =
        (void *)need("glBitmap");
    void (*drawPixels)(GLsizei, GLsizei, GLenum, GLenum, const void *) = (void *)need("glDrawPixels");
    void (*genTextures)(GLsizei, GLuint *) = (void *)need("glGenTextures");
    void (*bindTexture)(GLenum, GLuint) = (void *)need("glBindTexture");
    void (*texImage2D)(GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum,
                       const void *) = (void *)need("glTexImage2D");
    void (*texParameteri)(GLenum, GLenum, GLint) = (void *)need("glTexParameteri");
    void (*texEnvi)(GLenum, GLenum, GLint) = (void *)need("glTexEnvi");
    void (*texCoord2f)(GLfloat, GLfloat) = (void *)need("glTexCoord2f");
    void (*alphaFunc)(GLenum, GLclampf) = (void *)need("glAlphaFunc");
    void (*pixelStorei)(GLenum, GLint) = (void *)need("glPixelStorei");
    GLuint tex[2] = {0, 0};
    if (texture || texgen) {
        /* An 8x8 RGB checkerboard, rows of 3 bytes: unpack alignment 1. */
        static GLubyte checker[8][8][3];
        for (int i = 0; i < 8; i++)
            for (int j = 0; j < 8; j++) {
                int on = (i + j) % 2;
                checker[i][j][0] = on ? 240 : 40;
                checker[i][j][1] = on ? 230 : 90;
                checker[i][j][2] = on ? 60 : 200;
            }
        /* A 32x32 RGBA disc grid: alpha 0 inside four round holes. */
        static GLubyte holes[32][32][4];
        for (int i = 0; i < 32; i++)
            for (int j = 0; j < 32; j++) {
                double x = (j % 16) - 7.5, y = (i % 16) - 7.5;
                holes[i][j][0] = 200;
                holes[i][j][1] = (GLubyte)(60 + 6 * i);
                holes[i][j][2] = (GLubyte)(60 + 6 * j);
                holes[i][j][3] = x * x + y * y < 30.0 ? 0 : 255;
            }
        genTextures(2, tex);
        pixelStorei(GL_UNPACK_ALIGNMENT, 1);
        bindTexture(GL_TEXTURE_2D, tex[0]);
        texImage2D(GL_TEXTURE_2D, 0, GL_RGB, 8, 8, 0, GL_RGB, GL_UNSIGNED_BYTE, checker);
        texParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        texParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        bindTexture(GL_TEXTURE_2D, tex[1]);
        pixelStorei(GL_UNPACK_ALIGNMENT, 4);
        texImage2D(GL_TEXTURE_2D, 0, GL_RGBA, 32, 32, 0, GL_RGBA, GL_UNSIGNED_BYTE, holes);
        texParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        texParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    }
    void (*fogi)(GLenum, GLint) = (void *)need("glFogi");
    void (*fogf)(GLenum, GLfloat) = (void *)need("glFogf");
    void (*fogfv)(GLenum, const GLfloat *) = (void *)need("glFogfv");
    void (*polygonMode)(GLenum, GLenum) = (void *)need("glPolygonMode");
    void (*cullFace)(GLenum) = (void *)need("glCullFace");

    if (clockwise) {
        frontFace(GL_CW);
        lightModeli(GL_LIGHT_MODEL_TWO_SIDE, 1);
    }
    p_begin = begin, p_end = end, p_color3f = color3f, p_normal3f = normal3f,
    p_vertex3f = vertex3f;
    if (set_viewport) viewport(0, 0, 256, 256);
    if (shadow) {
        newList(1, GL_COMPILE);
        ball();
        endList();
    }
    /* The ball as one interleaved array: r, g, b, a, nx, ny, nz, x, y, z. */
    enum { N = 16, VERTS = N * 2 * N * 6 };
    static GLfloat record[VERTS][10];
    if (arrays) {
        int v = 0;
        for (int i = 0; i < N; i++) {
            for (int j = 0; j < 2 * N; j++) {
                double t0 = M_PI * i / N, t1 = M_PI * (i + 1) / N;
                double p0 = M_PI * j / N, p1 = M_PI * (j + 1) / N;
                double q[4][3] = {
                    {sin(t0) * cos(p0), cos(t0), sin(t0) * sin(p0)},
                    {sin(t1) * cos(p0), cos(t1), sin(t1) * sin(p0)},
                    {sin(t1) * cos(p1), cos(t1), sin(t1) * sin(p1)},
                    {sin(t0) * cos(p1), cos(t0), sin(t0) * sin(p1)},
                };
                int tri[6] = {0, 1, 2, 0, 2, 3};
                for (int k = 0; k < 6; k++, v++) {
                    double *p = q[tri[k]];
                    GLfloat r[10] = {0.2f + 0.35f * (float)(1.0 + p[1]), 0.5f, 0.9f - 0.3f * (float)(1.0 + p[1]),
                                     1.0f, (float)p[0], (float)p[1], (float)p[2],
                                     (float)(1.2 * p[0]), (float)(1.2 * p[1]), (float)(1.2 * p[2])};
                    for (int c = 0; c < 10; c++) record[v][c] = r[c];
                }
            }
        }
    }
    clearColor(0.1f, 0.1f, 0.15f, 1.0f);
    enable(GL_DEPTH_TEST);
    enable(GL_LIGHTING);
    enable(GL_LIGHT0);
    enable(GL_COLOR_MATERIAL);
    GLfloat pos[4] = {1.0f, 2.0f, 3.0f, 0.0f};
    for (int f = 0; f < frames; f++) {
        if (bitmap) {
            /* A 16x16 glyph: a box with a diagonal, rows of 2 bytes. */
            static GLubyte glyph[16][2];
            for (int i = 0; i < 16; i++) {
                unsigned bits = (i == 0 || i == 15) ? 0xFFFF : (0x8001 | (0x8000 >> i));
                glyph[i][0] = (GLubyte)(bits >> 8);
                glyph[i][1] = (GLubyte)bits;
            }
            static GLubyte image[12][12][4];
            for (int i = 0; i < 12; i++)
                for (int j = 0; j < 12; j++) {
                    image[i][j][0] = (GLubyte)(20 * i);
                    image[i][j][1] = (GLubyte)(20 * j);
                    image[i][j][2] = 200;
                    image[i][j][3] = 255;
                }
            clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            matrixMode(GL_PROJECTION);
            loadIdentity();
            frustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
            matrixMode(GL_MODELVIEW);
            loadIdentity();
            lightfv(GL_LIGHT0, GL_POSITION, pos);
            translatef(0.0f, 0.0f, -4.0f);
            pushMatrix();
            rotatef(20.0f * f, 0.3f, 1.0f, 0.0f);
            p_color3f(0.9f, 0.5f, 0.2f);
            ball();
            popMatrix();
            disable(GL_LIGHTING);
            pixelStorei(GL_UNPACK_ALIGNMENT, 1);
            /* The label, in front of the ball's centre. */
            color3f(0.2f, 1.0f, 0.4f);
            rasterPos3f(-0.5f, 0.0f, 1.5f);
            for (int k = 0; k < 4; k++) bitmapf(16, 16, 0.0f, 0.0f, 18.0f, 0.0f, &glyph[0][0]);
            /* A line of glyphs near the window's bottom, moving. */
            color3f(1.0f, 1.0f, 0.3f);
            windowPos2i(10 + 4 * f, 10);
            for (int k = 0; k < 6; k++) bitmapf(16, 16, 0.0f, 0.0f, 20.0f, 0.0f, &glyph[0][0]);
            windowPos2i(200, 220);
            drawPixels(12, 12, GL_RGBA, GL_UNSIGNED_BYTE, image);
            pixelStorei(GL_UNPACK_ALIGNMENT, 4);
            enable(GL_LIGHTING);
            swapBuffers(dpy, win);
            finish();
            continue;
        }
        if (texgen) {
            clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            matrixMode(GL_PROJECTION);
            loadIdentity();
            frustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
            matrixMode(GL_MODELVIEW);
            loadIdentity();
            lightfv(GL_LIGHT0, GL_POSITION, pos);
            enable(GL_TEXTURE_2D);
            bindTexture(GL_TEXTURE_2D, tex[0]);
            texParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
            texEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
            /* The ball, sphere-mapped. */
            texGeni(GL_S, GL_TEXTURE_GEN_MODE, GL_SPHERE_MAP);
            texGeni(GL_T, GL_TEXTURE_GEN_MODE, GL_SPHERE_MAP);
            enable(GL_TEXTURE_GEN_S);
            enable(GL_TEXTURE_GEN_T);
            pushMatrix();
            translatef(0.5f, 0.3f, -5.0f);
            rotatef(20.0f * f, 0.3f, 1.0f, 0.0f);
            p_color3f(1.0f, 1.0f, 1.0f);
            ball();
            popMatrix();
            /* A quad, object-linear: s = x, t = y. */
            const GLfloat sp[4] = {1.0f, 0.0f, 0.0f, 0.0f}, tp[4] = {0.0f, 1.0f, 0.0f, 0.0f};
            texGeni(GL_S, GL_TEXTURE_GEN_MODE, GL_OBJECT_LINEAR);
            texGeni(GL_T, GL_TEXTURE_GEN_MODE, GL_OBJECT_LINEAR);
            texGenfv(GL_S, GL_OBJECT_PLANE, sp);
            texGenfv(GL_T, GL_OBJECT_PLANE, tp);
            pushMatrix();
            translatef(-1.2f, -1.0f, -5.0f);
            rotatef(15.0f * f, 0.0f, 1.0f, 0.0f);
            begin(GL_QUADS);
            normal3f(0.0f, 0.0f, 1.0f);
            vertex3f(-0.8f, -0.8f, 0.0f);
            vertex3f(0.8f, -0.8f, 0.0f);
            vertex3f(0.8f, 0.8f, 0.0f);
            vertex3f(-0.8f, 0.8f, 0.0f);
            end();
            popMatrix();
            disable(GL_TEXTURE_GEN_S);
            disable(GL_TEXTURE_GEN_T);
            disable(GL_TEXTURE_2D);
            swapBuffers(dpy, win);
            finish();
            continue;
        }
        if (texture) {
            clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            matrixMode(GL_PROJECTION);
            loadIdentity();
            frustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
            matrixMode(GL_MODELVIEW);
            loadIdentity();
            lightfv(GL_LIGHT0, GL_POSITION, pos);
            /* The ball, behind, untextured. */
            pushMatrix();
            translatef(0.4f, 0.3f, -6.0f);
            p_color3f(0.9f, 0.5f, 0.2f);
            ball();
            popMatrix();
            enable(GL_TEXTURE_2D);
            /* The checkerboard, lit and modulated, turning. */
            pushMatrix();
            translatef(-1.0f, -1.0f, -5.0f);
            rotatef(25.0f * f, 0.0f, 1.0f, 0.0f);
            bindTexture(GL_TEXTURE_2D, tex[0]);
            texEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
            p_color3f(1.0f, 1.0f, 1.0f);
            begin(GL_QUADS);
            normal3f(0.0f, 0.0f, 1.0f);
            texCoord2f(0.0f, 0.0f);
            vertex3f(-1.0f, -1.0f, 0.0f);
            texCoord2f(2.0f, 0.0f);
            vertex3f(1.0f, -1.0f, 0.0f);
            texCoord2f(2.0f, 2.0f);
            vertex3f(1.0f, 1.0f, 0.0f);
            texCoord2f(0.0f, 2.0f);
            vertex3f(-1.0f, 1.0f, 0.0f);
            end();
            popMatrix();
            /* The holed quad in front of the ball, unlit, replacing. */
            disable(GL_LIGHTING);
            enable(GL_ALPHA_TEST);
            alphaFunc(GL_GREATER, 0.5f);
            bindTexture(GL_TEXTURE_2D, tex[1]);
            texEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_REPLACE);
            pushMatrix();
            translatef(0.6f, 0.5f, -4.0f);
            rotatef(10.0f * f, 0.0f, 0.0f, 1.0f);
            begin(GL_QUADS);
            texCoord2f(0.0f, 0.0f);
            vertex3f(-0.9f, -0.9f, 0.0f);
            texCoord2f(1.0f, 0.0f);
            vertex3f(0.9f, -0.9f, 0.0f);
            texCoord2f(1.0f, 1.0f);
            vertex3f(0.9f, 0.9f, 0.0f);
            texCoord2f(0.0f, 1.0f);
            vertex3f(-0.9f, 0.9f, 0.0f);
            end();
            popMatrix();
            disable(GL_ALPHA_TEST);
            disable(GL_TEXTURE_2D);
            enable(GL_LIGHTING);
            swapBuffers(dpy, win);
            finish();
            continue;
        }
        if (fog || blend || wireframe) {
            clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
            matrixMode(GL_PROJECTION);
            loadIdentity();
            frustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
            matrixMode(GL_MODELVIEW);
            loadIdentity();
            lightfv(GL_LIGHT0, GL_POSITION, pos);
            translatef(0.0f, 0.0f, -4.0f);
            rotatef(20.0f * f, 0.3f, 1.0f, 0.0f);
            if (fog) {
                const GLfloat grey[4] = {0.5f, 0.5f, 0.55f, 1.0f};
                const GLint modes[3] = {GL_LINEAR, GL_EXP, GL_EXP2};
                enable(GL_FOG);
                fogi(GL_FOG_MODE, modes[f % 3]);
                fogf(GL_FOG_START, 3.0f);
                fogf(GL_FOG_END, 5.5f);
                fogf(GL_FOG_DENSITY, f % 3 == 1 ? 0.3f : 0.25f);
                fogfv(GL_FOG_COLOR, grey);
                p_color3f(0.9f, 0.5f, 0.2f);
                ball();
                disable(GL_FOG);
            } else if (blend) {
                p_color3f(0.9f, 0.5f, 0.2f);
                ball();
                enable(GL_BLEND);
                blendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
                enable(GL_CULL_FACE);
                cullFace(GL_BACK);
                enable(GL_NORMALIZE);
                const float at[2][4] = {{-1.5f, -0.9f, -1.5f, 0.5f}, {0.6f, 0.5f, 1.5f, 0.45f}};
                for (int k = 0; k < 2; k++) {
                    pushMatrix();
                    loadIdentity();
                    translatef(at[k][0], at[k][1], -4.0f + at[k][2]);
                    scalef(at[k][3], at[k][3], at[k][3]);
                    if (k == 0) color4f(0.2f, 0.9f, 0.3f, 0.5f);
                    else color4f(0.3f, 0.5f, 1.0f, 0.4f);
                    ball();
                    popMatrix();
                }
                disable(GL_NORMALIZE);
                disable(GL_CULL_FACE);
                disable(GL_BLEND);
            } else {
                disable(GL_LIGHTING);
                polygonMode(GL_FRONT_AND_BACK, GL_LINE);
                p_color3f(0.3f, 0.9f, 0.5f);
                ball();
                polygonMode(GL_FRONT_AND_BACK, GL_FILL);
                enable(GL_LIGHTING);
            }
            swapBuffers(dpy, win);
            finish();
            continue;
        }
        if (overlay || viewports || depthclear) {
            /* The views of the frame, whole in themselves. */
            if (overlay) {
                clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                /* A band behind everything, in normalized device
                 * coordinates: identity matrices, no depth test. */
                matrixMode(GL_PROJECTION);
                loadIdentity();
                matrixMode(GL_MODELVIEW);
                loadIdentity();
                disable(GL_DEPTH_TEST);
                disable(GL_LIGHTING);
                begin(GL_QUADS);
                color3f(0.25f, 0.3f, 0.45f);
                vertex2f(-1.0f, 0.2f);
                vertex2f(1.0f, 0.2f);
                color3f(0.5f, 0.55f, 0.7f);
                vertex2f(1.0f, 1.0f);
                vertex2f(-1.0f, 1.0f);
                end();
                /* The mesh under a 3-D glOrtho, lit, depth-tested. */
                enable(GL_DEPTH_TEST);
                enable(GL_LIGHTING);
                matrixMode(GL_PROJECTION);
                loadIdentity();
                ortho(-2.0, 2.0, -2.0, 2.0, -10.0, 10.0);
                matrixMode(GL_MODELVIEW);
                loadIdentity();
                lightfv(GL_LIGHT0, GL_POSITION, pos);
                rotatef(20.0f * f, 0.3f, 1.0f, 0.0f);
                p_color3f(0.9f, 0.5f, 0.2f);
                ball();
                /* 2-D overlays in pixels: a bar and a frame of lines. */
                disable(GL_DEPTH_TEST);
                disable(GL_LIGHTING);
                matrixMode(GL_PROJECTION);
                loadIdentity();
                ortho(0.0, 256.0, 0.0, 256.0, -1.0, 1.0);
                matrixMode(GL_MODELVIEW);
                loadIdentity();
                color3f(0.9f, 0.9f, 0.3f);
                rectf(16.0f, 8.0f, 16.0f + 4.0f * (float)(f + 1), 20.0f);
                lineWidth(2.0f);
                color3f(0.2f, 0.9f, 0.4f);
                begin(GL_LINE_LOOP);
                vertex2f(4.0f, 4.0f);
                vertex2f(252.0f, 4.0f);
                vertex2f(252.0f, 252.0f);
                vertex2f(4.0f, 252.0f);
                end();
                lineWidth(1.0f);
                enable(GL_DEPTH_TEST);
                enable(GL_LIGHTING);
            } else if (viewports) {
                enable(GL_SCISSOR_TEST);
                for (int side = 0; side < 2; side++) {
                    viewport(128 * side, 0, 128, 256);
                    scissor(128 * side, 0, 128, 256);
                    clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                    matrixMode(GL_PROJECTION);
                    loadIdentity();
                    if (side == 0)
                        frustum(-0.3, 0.3, -0.6, 0.6, 1.0, 20.0);
                    else
                        ortho(-1.0, 1.0, -2.0, 2.0, -10.0, 10.0);
                    matrixMode(GL_MODELVIEW);
                    loadIdentity();
                    lightfv(GL_LIGHT0, GL_POSITION, pos);
                    if (side == 0) translatef(0.0f, 0.0f, -4.0f);
                    rotatef(20.0f * f, 0.3f, 1.0f, 0.0f);
                    scalef(0.7f, 0.7f, 0.7f);
                    if (side == 0) p_color3f(0.9f, 0.5f, 0.2f);
                    else p_color3f(0.3f, 0.6f, 0.9f);
                    ball();
                }
                disable(GL_SCISSOR_TEST);
            } else {
                clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
                matrixMode(GL_PROJECTION);
                loadIdentity();
                frustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
                matrixMode(GL_MODELVIEW);
                loadIdentity();
                lightfv(GL_LIGHT0, GL_POSITION, pos);
                translatef(0.0f, 0.0f, -4.0f);
                rotatef(20.0f * f, 0.3f, 1.0f, 0.0f);
                p_color3f(0.9f, 0.5f, 0.2f);
                ball();
                /* Behind the first ball, drawn over it. */
                clear(GL_DEPTH_BUFFER_BIT);
                loadIdentity();
                translatef(0.6f, 0.4f, -7.0f);
                p_color3f(0.3f, 0.6f, 0.9f);
                ball();
            }
            swapBuffers(dpy, win);
            finish();
            continue;
        }
        clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        matrixMode(GL_PROJECTION);
        loadIdentity();
        frustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
        matrixMode(GL_MODELVIEW);
        loadIdentity();
        lightfv(GL_LIGHT0, GL_POSITION, pos);
        translatef(0.0f, 0.0f, -4.0f);
        rotatef(still ? 0.0f : 20.0f * f, 0.3f, 1.0f, 0.0f);
        p_color3f(0.9f, 0.5f, 0.2f);
        if (shadow) {
            callList(1);
            /* Flattened onto the floor y = -1.5 along the light's
             * direction (1, 2, 3): a projective matrix (column-major). */
            const float l[3] = {1.0f, 2.0f, 3.0f}, d = 1.5f;
            const GLfloat m[16] = {l[1], 0, 0, 0,  -l[0], 0, -l[2], -1,
                                   0, 0, l[1], 0,  -d * l[0], -d * l[1], -d * l[2], l[1] - d};
            pushMatrix();
            multMatrixf(m);
            disable(GL_LIGHTING);
            enable(GL_BLEND);
            enable(GL_STENCIL_TEST);
            blendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
            color4f(0.0f, 0.0f, 0.0f, 0.5f);
            callList(1);
            disable(GL_STENCIL_TEST);
            disable(GL_BLEND);
            enable(GL_LIGHTING);
            popMatrix();
        } else if (arrays) {
            interleavedArrays(GL_C4F_N3F_V3F, 0, record);
            drawArrays(GL_TRIANGLES, 0, VERTS);
            disable(GL_LIGHTING);
            color3f(0.2f, 0.7f, 0.6f);
            rectf(1.0f, -2.2f, 2.0f, -1.4f);
            enable(GL_LIGHTING);
        } else {
            ball();
        }
        if (lightsoff) {
            disable(GL_LIGHT0);
            disable(GL_LIGHTING);
        }
        swapBuffers(dpy, win);
        if (lightsoff) {
            enable(GL_LIGHTING);
            enable(GL_LIGHT0);
        }
        finish();
    }
    printf("frames %d\n", frames);
    makeCurrent(dpy, None, NULL);
    destroyContext(dpy, ctx);
    XDestroyWindow(dpy, win);
    XCloseDisplay(dpy);
    return 0;
}
