/*
 * A legacy-GL program that makes its context with EGL on X11 and
 * presents with eglSwapBuffers (no GLX at all), as newer toolkits and
 * headless renderers do. It knows nothing of rt-gl.
 *
 *   egl_gl frames       draw a lit, rotating ball for `frames` frames;
 *                       prints "frames <n>"
 *
 * Build: cc -O2 -o egl_gl egl_gl.c -lEGL -lGL -lX11 -lm
 */
#include <EGL/egl.h>
#include <GL/gl.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static void ball(void) {
    glBegin(GL_TRIANGLES);
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
            int tri[6] = {0, 1, 2, 0, 2, 3};
            for (int k = 0; k < 6; k++) {
                double *p = v[tri[k]];
                glNormal3d(p[0], p[1], p[2]);
                glVertex3d(1.2 * p[0], 1.2 * p[1], 1.2 * p[2]);
            }
        }
    }
    glEnd();
}

int main(int argc, char **argv) {
    int frames = argc >= 2 ? atoi(argv[1]) : 4;
    Display *x = XOpenDisplay(NULL);
    if (!x) {
        fprintf(stderr, "egl_gl: cannot open the X display\n");
        return 1;
    }
    EGLDisplay dpy = eglGetDisplay((EGLNativeDisplayType)x);
    EGLint major, minor;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor)) {
        fprintf(stderr, "egl_gl: no EGL display\n");
        return 1;
    }
    const EGLint attrs[] = {EGL_SURFACE_TYPE, EGL_WINDOW_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                            EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                            EGL_DEPTH_SIZE, 16, EGL_NONE};
    EGLConfig config;
    EGLint count = 0;
    if (!eglChooseConfig(dpy, attrs, &config, 1, &count) || count < 1) {
        fprintf(stderr, "egl_gl: no EGL config for desktop GL\n");
        return 1;
    }
    EGLint visual_id;
    eglGetConfigAttrib(dpy, config, EGL_NATIVE_VISUAL_ID, &visual_id);
    XVisualInfo tmpl = {.visualid = (VisualID)visual_id};
    int nvis = 0;
    XVisualInfo *vi = XGetVisualInfo(x, VisualIDMask, &tmpl, &nvis);
    if (!vi) {
        fprintf(stderr, "egl_gl: no X visual for the config\n");
        return 1;
    }
    XSetWindowAttributes swa;
    swa.colormap = XCreateColormap(x, RootWindow(x, vi->screen), vi->visual, AllocNone);
    swa.event_mask = ExposureMask;
    Window win = XCreateWindow(x, RootWindow(x, vi->screen), 0, 0, 256, 256, 0, vi->depth,
                               InputOutput, vi->visual, CWColormap | CWEventMask, &swa);
    XMapWindow(x, win);
    eglBindAPI(EGL_OPENGL_API);
    EGLContext ctx = eglCreateContext(dpy, config, EGL_NO_CONTEXT, NULL);
    EGLSurface surface = eglCreateWindowSurface(dpy, config, (EGLNativeWindowType)win, NULL);
    if (ctx == EGL_NO_CONTEXT || surface == EGL_NO_SURFACE ||
        !eglMakeCurrent(dpy, surface, surface, ctx)) {
        fprintf(stderr, "egl_gl: cannot make a desktop GL context current\n");
        return 1;
    }

    glViewport(0, 0, 256, 256);
    glClearColor(0.1f, 0.1f, 0.15f, 1.0f);
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glEnable(GL_COLOR_MATERIAL);
    GLfloat pos[4] = {1.0f, 2.0f, 3.0f, 0.0f};
    for (int f = 0; f < frames; f++) {
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glMatrixMode(GL_PROJECTION);
        glLoadIdentity();
        glFrustum(-0.6, 0.6, -0.6, 0.6, 1.0, 20.0);
        glMatrixMode(GL_MODELVIEW);
        glLoadIdentity();
        glLightfv(GL_LIGHT0, GL_POSITION, pos);
        glTranslatef(0.0f, 0.0f, -4.0f);
        glRotatef(20.0f * f, 0.3f, 1.0f, 0.0f);
        glColor3f(0.3f, 0.7f, 0.4f);
        ball();
        eglSwapBuffers(dpy, surface);
    }
    printf("frames %d\n", frames);
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroySurface(dpy, surface);
    eglDestroyContext(dpy, ctx);
    eglTerminate(dpy);
    XDestroyWindow(x, win);
    XCloseDisplay(x);
    return 0;
}
