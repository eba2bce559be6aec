/*
 * A plain OpenGL 1.x/2.1 program for rt-gl's tests: one scene per frame,
 * through every path the interposer records. It knows nothing of rt-gl.
 *
 *   scenes [frames]     draw the scenes in turn for `frames` frames
 *                       (default: each scene once)
 *   scenes mesh N F     a grid of N triangles in a static VBO, F frames,
 *                       in a 512² window; prints "frame <i> <seconds>" per
 *                       frame (the frame time includes glFinish after the
 *                       swap)
 *   scenes wave F       a waving grid, F frames: its vertices and normals
 *                       rewritten every frame (glBufferSubData, and every
 *                       fourth frame glBufferData) over a static element
 *                       buffer, drawn twice per frame
 *
 * Build: cc -O2 -o scenes scenes.c -lGL -lX11 -lm
 */
#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/glx.h>
#include <X11/Xlib.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The window: 256² for the scenes, 512² for the mesh timing. */
static int W = 256, H = 256;
#define SCENES 10

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static void perspective(void) {
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glTranslatef(0.0f, 0.0f, -4.0f);
}

static void orthographic(void) {
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(-2.0, 2.0, -2.0, 2.0, -5.0, 5.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
}

static void lights(void) {
    GLfloat pos[4] = {1.0f, 2.0f, 3.0f, 0.0f};
    GLfloat white[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    GLfloat amb[4] = {0.15f, 0.15f, 0.15f, 1.0f};
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glLightfv(GL_LIGHT0, GL_POSITION, pos);
    glLightfv(GL_LIGHT0, GL_DIFFUSE, white);
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, amb);
    glEnable(GL_NORMALIZE);
}

static void material(float r, float g, float b) {
    GLfloat c[4] = {r, g, b, 1.0f};
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, c);
}

/* A box of six quads with face normals, edge 2s, centred at the origin. */
static void box(float s) {
    static const float n[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    glBegin(GL_QUADS);
    for (int f = 0; f < 6; f++) {
        float a[3], b[3], c[3];
        for (int k = 0; k < 3; k++) c[k] = n[f][k];
        /* Two axes spanning the face, right-handed with the normal. */
        int i = f / 2, j = (i + 1) % 3, l = (i + 2) % 3;
        float sg = (f % 2 == 0) ? 1.0f : -1.0f;
        memset(a, 0, sizeof a);
        memset(b, 0, sizeof b);
        a[j] = 1.0f;
        b[l] = sg;
        glNormal3fv(c);
        float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int q = 0; q < 4; q++) {
            float p[3];
            for (int k = 0; k < 3; k++)
                p[k] = s * (c[k] + corners[q][0] * a[k] + corners[q][1] * b[k]);
            glVertex3fv(p);
        }
    }
    glEnd();
}

/* A sphere of `stacks` quad strips. */
static void sphere(float r, int slices, int stacks) {
    for (int i = 0; i < stacks; i++) {
        float t0 = M_PI * i / stacks - M_PI / 2, t1 = M_PI * (i + 1) / stacks - M_PI / 2;
        glBegin(GL_QUAD_STRIP);
        for (int j = 0; j <= slices; j++) {
            float p = 2 * M_PI * j / slices;
            float x1 = cosf(t1) * cosf(p), y1 = sinf(t1), z1 = cosf(t1) * sinf(p);
            float x0 = cosf(t0) * cosf(p), y0 = sinf(t0), z0 = cosf(t0) * sinf(p);
            glNormal3f(x1, y1, z1);
            glVertex3f(r * x1, r * y1, r * z1);
            glNormal3f(x0, y0, z0);
            glVertex3f(r * x0, r * y0, r * z0);
        }
        glEnd();
    }
}

/* A grid of nx × ny quads as positions, normals and indexed triangles. */
static int grid(int nx, int ny, float **pos, float **nrm, unsigned **idx) {
    int nv = (nx + 1) * (ny + 1);
    *pos = malloc(sizeof(float) * 3 * nv);
    *nrm = malloc(sizeof(float) * 3 * nv);
    *idx = malloc(sizeof(unsigned) * 6 * nx * ny);
    for (int y = 0; y <= ny; y++)
        for (int x = 0; x <= nx; x++) {
            int v = y * (nx + 1) + x;
            float u = 3.0f * x / nx - 1.5f, w = 3.0f * y / ny - 1.5f;
            float h = 0.25f * sinf(3 * u) * cosf(2 * w);
            (*pos)[3 * v] = u;
            (*pos)[3 * v + 1] = w;
            (*pos)[3 * v + 2] = h;
            float dx = 0.75f * cosf(3 * u) * cosf(2 * w), dy = -0.5f * sinf(3 * u) * sinf(2 * w);
            float l = sqrtf(dx * dx + dy * dy + 1);
            (*nrm)[3 * v] = -dx / l;
            (*nrm)[3 * v + 1] = -dy / l;
            (*nrm)[3 * v + 2] = 1 / l;
        }
    int k = 0;
    for (int y = 0; y < ny; y++)
        for (int x = 0; x < nx; x++) {
            unsigned a = y * (nx + 1) + x, b = a + 1, c = a + nx + 1, d = c + 1;
            (*idx)[k++] = a; (*idx)[k++] = b; (*idx)[k++] = d;
            (*idx)[k++] = a; (*idx)[k++] = d; (*idx)[k++] = c;
        }
    return nv;
}

/* The grid in three new buffer objects b: positions, normals, indices;
   returns the vertex count. */
static int upload_grid(int nx, int ny, GLuint b[3], float **pos, float **nrm, unsigned **idx) {
    int nv = grid(nx, ny, pos, nrm, idx);
    glGenBuffers(3, b);
    glBindBuffer(GL_ARRAY_BUFFER, b[0]);
    glBufferData(GL_ARRAY_BUFFER, sizeof(float) * 3 * nv, *pos, GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, b[1]);
    glBufferData(GL_ARRAY_BUFFER, sizeof(float) * 3 * nv, *nrm, GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, b[2]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, sizeof(unsigned) * 6 * nx * ny, *idx, GL_STATIC_DRAW);
    return nv;
}

static GLuint lists;
static GLuint vbo[3];
static float *gpos, *gnrm;
static unsigned *gidx;
static int gnx = 24, gny = 24;

static void setup(void) {
    /* Display lists: a box (GL_COMPILE) and a sphere. */
    lists = glGenLists(2);
    glNewList(lists, GL_COMPILE);
    material(0.9f, 0.3f, 0.2f);
    box(0.35f);
    glEndList();
    glNewList(lists + 1, GL_COMPILE);
    material(0.2f, 0.5f, 0.9f);
    sphere(0.4f, 24, 12);
    glEndList();
    /* A static VBO grid with an element buffer (the arrays are kept for
       the client-memory scene too). */
    upload_grid(gnx, gny, vbo, &gpos, &gnrm, &gidx);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
}

static void begin_frame(void) {
    glViewport(0, 0, W, H);
    glClearColor(0.1f, 0.1f, 0.15f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_LIGHTING);
    glShadeModel(GL_SMOOTH);
}

static void scene(int s, int frame) {
    float spin = 7.0f * frame;
    switch (s) {
    case 0: /* immediate triangles, strip, fan; lit, perspective */
        perspective();
        lights();
        material(0.8f, 0.8f, 0.3f);
        glRotatef(20 + spin, 0.3f, 1.0f, 0.0f);
        glBegin(GL_TRIANGLES);
        glNormal3f(0, 0, 1);
        glVertex3f(-1.5f, -1.0f, 0.0f); glVertex3f(-0.5f, -1.0f, 0.0f); glVertex3f(-1.0f, 0.2f, 0.0f);
        glEnd();
        glBegin(GL_TRIANGLE_STRIP);
        for (int i = 0; i < 8; i++) {
            float x = -0.3f + 0.25f * (i / 2), y = (i % 2) ? 0.8f : -0.8f;
            glNormal3f(0.3f * (i % 3 - 1), 0.0f, 1.0f);
            glVertex3f(x, y, 0.2f * (i % 2));
        }
        glEnd();
        glBegin(GL_TRIANGLE_FAN);
        glNormal3f(0, 0, 1);
        glVertex3f(1.2f, 0.0f, 0.0f);
        for (int i = 0; i <= 6; i++) {
            float a = 2 * M_PI * i / 6;
            glNormal3f(0.4f * cosf(a), 0.4f * sinf(a), 1.0f);
            glVertex3f(1.2f + 0.5f * cosf(a), 0.5f * sinf(a), 0.0f);
        }
        glEnd();
        break;
    case 1: /* quads, quad strip, polygon; unlit colours, orthographic */
        orthographic();
        glRotatef(spin, 0, 0, 1);
        glBegin(GL_QUADS);
        glColor3f(1, 0, 0); glVertex2f(-1.8f, -1.8f);
        glColor3f(0, 1, 0); glVertex2f(-0.6f, -1.8f);
        glColor3f(0, 0, 1); glVertex2f(-0.6f, -0.6f);
        glColor3f(1, 1, 0); glVertex2f(-1.8f, -0.6f);
        glEnd();
        glBegin(GL_QUAD_STRIP);
        for (int i = 0; i < 6; i++) {
            glColor3ub(40 * i, 200, 255 - 40 * i);
            glVertex3f(0.2f + 0.3f * i, -1.5f, 0.0f);
            glVertex3f(0.2f + 0.3f * i, -0.5f + 0.1f * i, 0.0f);
        }
        glEnd();
        glShadeModel(GL_FLAT);
        glBegin(GL_POLYGON);
        glColor3f(0.9f, 0.5f, 0.1f);
        for (int i = 0; i < 7; i++) {
            float a = 2 * M_PI * i / 7;
            glVertex2d(0.8 * cos(a) - 0.5, 0.8 * sin(a) + 1.0);
        }
        glEnd();
        break;
    case 2: /* client-memory vertex arrays: glDrawArrays and glDrawElements */
        perspective();
        lights();
        material(0.3f, 0.8f, 0.4f);
        glRotatef(-50 + spin, 1, 0, 0);
        glEnableClientState(GL_VERTEX_ARRAY);
        glEnableClientState(GL_NORMAL_ARRAY);
        glVertexPointer(3, GL_FLOAT, 0, gpos);
        glNormalPointer(GL_FLOAT, 0, gnrm);
        glDrawElements(GL_TRIANGLES, 3 * gnx * gny, GL_UNSIGNED_INT, gidx);
        glTranslatef(0, 0, 0.6f);
        glDrawArrays(GL_TRIANGLE_STRIP, 0, 2 * (gnx + 1));
        glDisableClientState(GL_VERTEX_ARRAY);
        glDisableClientState(GL_NORMAL_ARRAY);
        break;
    case 3: /* a static VBO with an element buffer, drawn under two transforms */
        perspective();
        lights();
        material(0.7f, 0.7f, 0.9f);
        glEnableClientState(GL_VERTEX_ARRAY);
        glEnableClientState(GL_NORMAL_ARRAY);
        glBindBuffer(GL_ARRAY_BUFFER, vbo[0]);
        glVertexPointer(3, GL_FLOAT, 0, 0);
        glBindBuffer(GL_ARRAY_BUFFER, vbo[1]);
        glNormalPointer(GL_FLOAT, 0, 0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, vbo[2]);
        for (int k = 0; k < 2; k++) {
            glPushMatrix();
            glTranslatef(-0.8f + 1.6f * k, 0.0f, 0.0f);
            glRotatef(-60 + 20 * k + spin, 1, 0, 0);
            glScalef(0.45f, 0.45f, 0.45f);
            glDrawElements(GL_TRIANGLES, 6 * gnx * gny, GL_UNSIGNED_INT, 0);
            glPopMatrix();
        }
        glBindBuffer(GL_ARRAY_BUFFER, 0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
        glDisableClientState(GL_VERTEX_ARRAY);
        glDisableClientState(GL_NORMAL_ARRAY);
        break;
    case 4: /* display lists under several transforms */
        perspective();
        lights();
        for (int k = 0; k < 4; k++) {
            glPushMatrix();
            glRotatef(90 * k + spin, 0, 0, 1);
            glTranslatef(1.0f, 0.0f, 0.0f);
            glRotatef(30 * k + spin, 1, 1, 0);
            glCallList(lists + (k % 2));
            glPopMatrix();
        }
        break;
    case 5: /* points and lines, unlit */
        perspective();
        glPointSize(6.0f);
        glBegin(GL_POINTS);
        for (int i = 0; i < 12; i++) {
            glColor3f(1.0f, 0.2f + 0.06f * i, 0.2f);
            glVertex3f(-1.4f + 0.25f * i, 1.0f, 0.0f);
        }
        glEnd();
        glLineWidth(3.0f);
        glBegin(GL_LINE_STRIP);
        glColor3f(0.2f, 1.0f, 0.4f);
        for (int i = 0; i < 8; i++) glVertex3f(-1.4f + 0.4f * i, -0.2f + 0.4f * (i % 2), 0.0f);
        glEnd();
        glBegin(GL_LINE_LOOP);
        glColor3f(0.4f, 0.6f, 1.0f);
        glVertex3f(-1.0f, -1.4f, 0.0f); glVertex3f(1.0f, -1.4f, 0.0f); glVertex3f(0.0f, -0.6f, 0.0f);
        glEnd();
        glBegin(GL_LINES);
        glColor3f(1, 1, 1);
        glVertex3f(-1.5f, 0.5f, 0.0f); glVertex3f(1.5f, 0.6f, 0.0f);
        glEnd();
        break;
    case 6: /* glMultiDrawArrays and glDrawRangeElements, with a colour array */
        orthographic();
        glRotatef(spin, 0, 0, 1);
        {
            static float v[12][2];
            static unsigned char c[12][3];
            for (int i = 0; i < 12; i++) {
                v[i][0] = -1.5f + 0.25f * i;
                v[i][1] = (i % 2) ? 0.5f : -0.5f;
                c[i][0] = 20 * i; c[i][1] = 255 - 20 * i; c[i][2] = 128;
            }
            GLint first[2] = {0, 6};
            GLsizei count[2] = {5, 6};
            glEnableClientState(GL_VERTEX_ARRAY);
            glEnableClientState(GL_COLOR_ARRAY);
            glVertexPointer(2, GL_FLOAT, 0, v);
            glColorPointer(3, GL_UNSIGNED_BYTE, 0, c);
            glMultiDrawArrays(GL_TRIANGLE_STRIP, first, count, 2);
            static const unsigned short tri[6] = {0, 2, 1, 3, 5, 4};
            glTranslatef(0.0f, 1.2f, 0.0f);
            glDrawRangeElements(GL_TRIANGLES, 0, 5, 6, GL_UNSIGNED_SHORT, tri);
            glDisableClientState(GL_VERTEX_ARRAY);
            glDisableClientState(GL_COLOR_ARRAY);
        }
        break;
    case 7: /* GL_COMPILE_AND_EXECUTE, nested lists, glCallLists */
        perspective();
        lights();
        {
            static GLuint outer = 0;
            if (!outer) {
                outer = glGenLists(1);
                glNewList(outer, GL_COMPILE_AND_EXECUTE);
                glPushMatrix();
                glTranslatef(-0.9f, 0.0f, 0.0f);
                glCallList(lists + 1);
                glTranslatef(1.8f, 0.0f, 0.0f);
                glCallList(lists);
                glPopMatrix();
                glEndList();
            } else {
                glRotatef(spin, 0, 1, 0);
                glCallList(outer);
            }
            GLubyte ids[2] = {0, 1};
            glTranslatef(0.0f, 1.0f, 0.0f);
            glListBase(lists);
            glCallLists(2, GL_UNSIGNED_BYTE, ids);
            glListBase(0);
        }
        break;
    case 8: /* calls rt-gl does not record, and malformed ones: the frame
               must still come out and the program keep running */
        perspective();
        lights();
        material(0.8f, 0.5f, 0.8f);
        glVertex3f(0, 0, 0);             /* outside glBegin */
        glBegin(GL_TRIANGLES);
        glTexCoord2f(0.5f, 0.5f);        /* recorded as nothing */
        glNormal3f(0, 0, 1);
        glVertex3f(-1, -1, 0); glVertex3f(1, -1, 0); glVertex3f(0, 1, 0);
        glEnd();
        glEnd();                         /* unmatched */
        glDrawArrays(GL_TRIANGLES, 0, -3);
        glCallLists(-2, GL_UNSIGNED_BYTE, NULL);
        glDeleteLists(12345, -1);
        glBegin(0x7777);                 /* not a primitive */
        glEnd();
        glPopMatrix(); glPopMatrix();    /* underflow */
        glCallList(999999);              /* no such list */
        while (glGetError() != GL_NO_ERROR) {}
        break;
    case 9: /* a frame rt-gl cannot trace (a singular projection): it must
               keep what GL drew (here nothing) and carry on */
        {
            static const GLfloat zero[16] = {0};
            glMatrixMode(GL_PROJECTION);
            glLoadMatrixf(zero);
            glMatrixMode(GL_MODELVIEW);
            glLoadIdentity();
            glColor3f(1, 1, 1);
            glBegin(GL_TRIANGLES);
            glVertex2f(0, 0); glVertex2f(1, 0); glVertex2f(0, 1);
            glEnd();
        }
        break;
    }
}

static double mesh_frames(int n, int frames) {
    int nx = (int)sqrt(n / 2.0);
    if (nx < 1) nx = 1;
    int ny = n / (2 * nx);
    if (ny < 1) ny = 1;
    float *p, *nr;
    unsigned *idx;
    GLuint b[3];
    upload_grid(nx, ny, b, &p, &nr, &idx);
    printf("triangles %d\n", 2 * nx * ny);
    for (int f = 0; f < frames; f++) {
        double t0 = now();
        begin_frame();
        perspective();
        lights();
        material(0.7f, 0.7f, 0.9f);
        glRotatef(-55.0f + 0.5f * f, 1, 0, 0);
        glEnableClientState(GL_VERTEX_ARRAY);
        glEnableClientState(GL_NORMAL_ARRAY);
        glBindBuffer(GL_ARRAY_BUFFER, b[0]);
        glVertexPointer(3, GL_FLOAT, 0, 0);
        glBindBuffer(GL_ARRAY_BUFFER, b[1]);
        glNormalPointer(GL_FLOAT, 0, 0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, b[2]);
        glDrawElements(GL_TRIANGLES, 6 * nx * ny, GL_UNSIGNED_INT, 0);
        glXSwapBuffers(glXGetCurrentDisplay(), glXGetCurrentDrawable());
        glFinish();
        printf("frame %d %.6f\n", f, now() - t0);
        fflush(stdout);
    }
    return 0;
}

/* The grid's heights and normals at time `phase`: the same vertices in
   x and y every frame, a travelling wave in z. */
static void wave_grid(int nx, int ny, float phase, float *pos, float *nrm) {
    for (int y = 0; y <= ny; y++)
        for (int x = 0; x <= nx; x++) {
            int v = y * (nx + 1) + x;
            float u = 3.0f * x / nx - 1.5f, w = 3.0f * y / ny - 1.5f;
            pos[3 * v] = u;
            pos[3 * v + 1] = w;
            pos[3 * v + 2] = 0.3f * sinf(3 * u + phase) * cosf(2 * w);
            float dx = 0.9f * cosf(3 * u + phase) * cosf(2 * w);
            float dy = -0.6f * sinf(3 * u + phase) * sinf(2 * w);
            float l = sqrtf(dx * dx + dy * dy + 1);
            nrm[3 * v] = -dx / l;
            nrm[3 * v + 1] = -dy / l;
            nrm[3 * v + 2] = 1 / l;
        }
}

static void wave_frames(int frames) {
    float *p, *nr;
    unsigned *idx;
    GLuint b[3];
    int nx = 24, ny = 24, nv = upload_grid(nx, ny, b, &p, &nr, &idx);
    GLsizeiptr bytes = sizeof(float) * 3 * nv;
    for (int f = 0; f < frames; f++) {
        wave_grid(nx, ny, 0.6f * f, p, nr);
        glBindBuffer(GL_ARRAY_BUFFER, b[0]);
        if (f % 4 == 3) {
            glBufferData(GL_ARRAY_BUFFER, bytes, p, GL_DYNAMIC_DRAW);
        } else {
            /* In two pieces, as programs that update ranges do. */
            glBufferSubData(GL_ARRAY_BUFFER, 0, bytes / 2, p);
            glBufferSubData(GL_ARRAY_BUFFER, bytes / 2, bytes - bytes / 2, (char *)p + bytes / 2);
        }
        glBindBuffer(GL_ARRAY_BUFFER, b[1]);
        glBufferSubData(GL_ARRAY_BUFFER, 0, bytes, nr);
        begin_frame();
        perspective();
        lights();
        material(0.4f, 0.7f, 0.9f);
        glEnableClientState(GL_VERTEX_ARRAY);
        glEnableClientState(GL_NORMAL_ARRAY);
        glBindBuffer(GL_ARRAY_BUFFER, b[0]);
        glVertexPointer(3, GL_FLOAT, 0, 0);
        glBindBuffer(GL_ARRAY_BUFFER, b[1]);
        glNormalPointer(GL_FLOAT, 0, 0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, b[2]);
        for (int k = 0; k < 2; k++) {
            glPushMatrix();
            glTranslatef(-0.8f + 1.6f * k, 0.0f, 0.0f);
            glRotatef(-60 + 20 * k, 1, 0, 0);
            glScalef(0.45f, 0.45f, 0.45f);
            glDrawElements(GL_TRIANGLES, 6 * nx * ny, GL_UNSIGNED_INT, 0);
            glPopMatrix();
        }
        glBindBuffer(GL_ARRAY_BUFFER, 0);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, 0);
        glDisableClientState(GL_VERTEX_ARRAY);
        glDisableClientState(GL_NORMAL_ARRAY);
        glXSwapBuffers(glXGetCurrentDisplay(), glXGetCurrentDrawable());
    }
    printf("frames %d\n", frames);
}

int main(int argc, char **argv) {
    int mesh = argc >= 4 && strcmp(argv[1], "mesh") == 0;
    int wave = argc >= 3 && strcmp(argv[1], "wave") == 0;
    if (mesh) W = H = 512;
    Display *dpy = XOpenDisplay(NULL);
    if (!dpy) {
        fprintf(stderr, "scenes: cannot open the X display\n");
        return 1;
    }
    int attrs[] = {GLX_RGBA, GLX_DOUBLEBUFFER, GLX_DEPTH_SIZE, 16, GLX_RED_SIZE, 8, None};
    XVisualInfo *vi = glXChooseVisual(dpy, DefaultScreen(dpy), attrs);
    if (!vi) {
        fprintf(stderr, "scenes: no double-buffered RGBA visual\n");
        return 1;
    }
    XSetWindowAttributes swa;
    swa.colormap = XCreateColormap(dpy, RootWindow(dpy, vi->screen), vi->visual, AllocNone);
    swa.event_mask = ExposureMask;
    Window win = XCreateWindow(dpy, RootWindow(dpy, vi->screen), 0, 0, W, H, 0, vi->depth,
                               InputOutput, vi->visual, CWColormap | CWEventMask, &swa);
    GLXContext ctx = glXCreateContext(dpy, vi, NULL, True);
    XMapWindow(dpy, win);
    glXMakeCurrent(dpy, win, ctx);

    if (mesh) {
        mesh_frames(atoi(argv[2]), atoi(argv[3]));
    } else if (wave) {
        wave_frames(atoi(argv[2]));
    } else {
        int frames = argc >= 2 ? atoi(argv[1]) : SCENES;
        setup();
        for (int f = 0; f < frames; f++) {
            begin_frame();
            scene(f % SCENES, f);
            glXSwapBuffers(dpy, win);
        }
        printf("frames %d\n", frames);
    }
    glXMakeCurrent(dpy, None, NULL);
    glXDestroyContext(dpy, ctx);
    XDestroyWindow(dpy, win);
    XCloseDisplay(dpy);
    return 0;
}
