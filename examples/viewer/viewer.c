/* viewer.c - an interactive viewer for tensormass.h, heml.h and frames.h: pick and drag the
   body with the mouse and read the force it pushes back with, cut a tensormass body with a
   scalpel stroke, switch model, precision and integrator live on the same shape, colour by
   displacement, stress or volume ratio J. GLFW and OpenGL 3.3 core (Debian: libglfw3-dev,
   libgl-dev); nothing else.

       make viewer && build/viewer/viewer [options]

   Options:
       --scene cantilever|lobe   a built-in scene (default cantilever)
       --mesh FILE               a TetGen .node (with its .ele), Gmsh .msh or closed .obj
                                 surface (the .obj is simulated by frames, sampled inside)
       --model tensormass|heml|frames   --precision double|float
       --integrator explicit|implicit|linearized   --field displacement|stress|J
       --size WxH                window size (default 960x640)
       --wireframe
   Headless (tests, pictures): render N frames of 1/60 s without input, write a PNG, print
   the readout and the tip position, and exit:
       --frames N --screenshot FILE.png
       --drag X,Y,DX,DY          press the left button at window point (X, Y) (picking the
                                 handle there) and move the mouse by (DX, DY), ramped over
                                 the first half of the frames: what a hand does
       --stroke X0,Y0,X1,Y1      first a scalpel stroke (right button) from (X0, Y0) to
                                 (X1, Y1), window coordinates, y down
       --keys KEYS               first press these keys (e.g. MP: next model, then float)

   Keys: mouse left on the body drags it (left elsewhere orbits), right drags the scalpel,
   wheel zooms; M model, P precision, I integrator, C colour field, W wireframe, T tearing,
   space pause, R reset, 1 cantilever, 2 lobe, S screenshot (viewer.png), Esc quit.
   Exit status 0, 1 when the model, OpenGL or the PNG fails, 2 for a bad argument. */
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include "app.h"
#include "png.h"
#include "render.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct vw_options {
    const char *scene, *mesh, *screenshot, *keys;
    int frames, headless, width, height, drag, stroke;
    double drag_at[4], stroke_at[4];
} vw_options;

static void vw__usage(const char *why)
{
    fprintf(stderr, "usage: viewer [--scene cantilever|lobe | --mesh FILE] [--model tensormass|heml|frames]\n"
                    "       [--precision double|float] [--integrator explicit|implicit|linearized]\n"
                    "       [--field displacement|stress|J] [--size WxH] [--wireframe]\n"
                    "       [--frames N --screenshot FILE.png [--keys KEYS] [--drag X,Y,DX,DY] [--stroke X0,Y0,X1,Y1]]\n"
                    "(%s)\n",
            why);
    exit(2);
}

static int vw__choice(const char *value, const char *const *names, int count, const char *option)
{
    int i;
    for (i = 0; i < count; i++)
        if (strcmp(value, names[i]) == 0) return i;
    fprintf(stderr, "viewer: %s: unknown value '%s'\n", option, value);
    vw__usage("bad value");
    return -1;
}

static void vw__parse(int argc, char **argv, vw_options *o, vw_app *a)
{
    static const char *const models[] = {"tensormass", "heml", "frames"}, *const precisions[] = {"double", "float"};
    static const char *const integrators[] = {"explicit", "implicit", "linearized"};
    static const char *const fields[] = {"displacement", "stress", "J"};
    int i;
    for (i = 1; i < argc; i++) {
        const char *k = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(k, "--wireframe") == 0) {
            a->wireframe = 1;
            continue;
        }
        if (!v) vw__usage("missing value");
        i++;
        if (strcmp(k, "--scene") == 0) o->scene = v;
        else if (strcmp(k, "--mesh") == 0) o->mesh = v;
        else if (strcmp(k, "--model") == 0) a->model = vw__choice(v, models, 3, k);
        else if (strcmp(k, "--precision") == 0) a->precision = vw__choice(v, precisions, 2, k);
        else if (strcmp(k, "--integrator") == 0) a->integrator = vw__choice(v, integrators, 3, k);
        else if (strcmp(k, "--field") == 0) a->field = vw__choice(v, fields, 3, k);
        else if (strcmp(k, "--frames") == 0 && sscanf(v, "%d", &o->frames) == 1 && o->frames >= 0) o->headless = 1;
        else if (strcmp(k, "--screenshot") == 0) o->screenshot = v;
        else if (strcmp(k, "--keys") == 0) o->keys = v;
        else if (strcmp(k, "--size") == 0 && sscanf(v, "%dx%d", &o->width, &o->height) == 2 && o->width > 0 &&
                 o->height > 0 && o->width <= 4096 && o->height <= 4096) continue;
        else if (strcmp(k, "--drag") == 0 && sscanf(v, "%lf,%lf,%lf,%lf", &o->drag_at[0], &o->drag_at[1],
                                                      &o->drag_at[2], &o->drag_at[3]) == 4) o->drag = 1;
        else if (strcmp(k, "--stroke") == 0 && sscanf(v, "%lf,%lf,%lf,%lf", &o->stroke_at[0], &o->stroke_at[1],
                                                        &o->stroke_at[2], &o->stroke_at[3]) == 4) o->stroke = 1;
        else vw__usage("unknown option or bad value");
    }
    if (o->headless != (o->screenshot != NULL)) vw__usage("--frames and --screenshot go together");
    if (o->scene && o->mesh) vw__usage("--scene or --mesh, not both");
}

/* >>input */

static vw_app *vw__app(GLFWwindow *w) { return (vw_app *)glfwGetWindowUserPointer(w); }

static void vw__load_scene(vw_app *a, const char *name)
{
    char err[256];
    vw_scene next;
    if (vw_scene_builtin(&next, name, err)) {
        fprintf(stderr, "viewer: %s\n", err);
        return;
    }
    vw_app_close(a);
    vw_scene_free(&a->scene);
    a->scene = next;
    if (vw_app_open(a, err)) fprintf(stderr, "viewer: %s\n", err);
    vw_camera_fit(&a->camera, a->scene.lo, a->scene.hi);
}

static int vw__screenshot(vw_app *a, const char *path)
{
    unsigned char *rgb = (unsigned char *)malloc(3 * (size_t)a->fb_width * (size_t)a->fb_height);
    int rc = -1;
    if (rgb) {
        vw_render_read(a->fb_width, a->fb_height, rgb);
        rc = vw_png_write(path, a->fb_width, a->fb_height, rgb);
    }
    free(rgb);
    if (rc) fprintf(stderr, "viewer: cannot write %s\n", path);
    return rc;
}

static void vw__next_integrator(vw_app *a)
{
    int k;
    for (k = 1; k <= VW_INTEGRATOR_COUNT; k++) {
        int next = (a->integrator + k) % VW_INTEGRATOR_COUNT;
        if (a->api->supports(a->sim, next)) {
            a->integrator = next;
            a->error[0] = 0;
            return;
        }
    }
}

static void vw__on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    vw_app *a = vw__app(w);
    (void)scancode;
    (void)mods;
    if (action != GLFW_PRESS) return;
    vw_app_release(a);
    switch (key) {
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(w, 1); break;
    case GLFW_KEY_M: vw_app_switch(a, (a->model + 1) % VW_MODEL_COUNT, a->precision); break;
    case GLFW_KEY_P: vw_app_switch(a, a->model, !a->precision); break;
    case GLFW_KEY_R: vw_app_switch(a, a->model, a->precision); break;
    case GLFW_KEY_I: vw__next_integrator(a); break;
    case GLFW_KEY_C: a->field = (a->field + 1) % VW_FIELD_COUNT; break;
    case GLFW_KEY_W: a->wireframe = !a->wireframe; break;
    case GLFW_KEY_T: a->tearing = !a->tearing; break;
    case GLFW_KEY_SPACE: a->paused = !a->paused; break;
    case GLFW_KEY_1: vw__load_scene(a, "cantilever"); break;
    case GLFW_KEY_2: vw__load_scene(a, "lobe"); break;
    case GLFW_KEY_S: vw__screenshot(a, "viewer.png"); break;
    default: break;
    }
}

static void vw__on_button(GLFWwindow *w, int button, int action, int mods)
{
    vw_app *a = vw__app(w);
    double x, y;
    (void)mods;
    glfwGetCursorPos(w, &x, &y);
    a->last_mouse[0] = x;
    a->last_mouse[1] = y;
    if (action == GLFW_RELEASE) {
        vw_app_release(a);
        a->orbiting = a->cutting = 0;
    } else if (button == GLFW_MOUSE_BUTTON_LEFT) {
        int h = vw_app_pick(a, x, y);
        if (h >= 0) vw_app_grab(a, h, x, y);
        else a->orbiting = 1;
    } else if (button == GLFW_MOUSE_BUTTON_RIGHT) a->cutting = 1;
}

static void vw__on_move(GLFWwindow *w, double x, double y)
{
    vw_app *a = vw__app(w);
    double p[2] = {x, y};
    if (a->grabbed >= 0) vw_app_move_grab(a, x, y);
    else if (a->orbiting) {
        a->camera.yaw += 0.01 * (x - a->last_mouse[0]);
        a->camera.pitch += 0.01 * (y - a->last_mouse[1]);
        if (a->camera.pitch > 1.5) a->camera.pitch = 1.5;
        if (a->camera.pitch < -1.5) a->camera.pitch = -1.5;
    } else if (a->cutting) vw_app_cut_segment(a, a->last_mouse, p);
    a->last_mouse[0] = x;
    a->last_mouse[1] = y;
}

static void vw__on_scroll(GLFWwindow *w, double dx, double dy)
{
    (void)dx;
    vw__app(w)->camera.distance *= pow(0.9, dy);
}

/* >>main */

static GLFWwindow *vw__window(const vw_options *o, vw_app *a)
{
    char err[256];
    GLFWwindow *w;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, 1);
    glfwWindowHint(GLFW_VISIBLE, o->headless ? GLFW_FALSE : GLFW_TRUE);
    w = glfwCreateWindow(o->width, o->height, "soft-body viewer", NULL, NULL);
    if (!w) return fprintf(stderr, "viewer: no OpenGL 3.3 core window\n"), NULL;
    glfwMakeContextCurrent(w);
    glfwSwapInterval(1);
    if (vw_render_init((vw_gl_loader)glfwGetProcAddress, err)) {
        fprintf(stderr, "viewer: %s\n", err);
        glfwDestroyWindow(w);
        return NULL;
    }
    glfwSetWindowUserPointer(w, a);
    glfwGetWindowSize(w, &a->width, &a->height);
    glfwGetFramebufferSize(w, &a->fb_width, &a->fb_height);
    return w;
}

static void vw__interactive(GLFWwindow *w, vw_app *a)
{
    double shown = 0;
    char title[512];
    glfwSetKeyCallback(w, vw__on_key);
    glfwSetMouseButtonCallback(w, vw__on_button);
    glfwSetCursorPosCallback(w, vw__on_move);
    glfwSetScrollCallback(w, vw__on_scroll);
    while (!glfwWindowShouldClose(w)) {
        glfwPollEvents();
        glfwGetWindowSize(w, &a->width, &a->height);
        glfwGetFramebufferSize(w, &a->fb_width, &a->fb_height);
        vw_app_advance(a);
        vw_draw(a);
        glfwSwapBuffers(w);
        if (glfwGetTime() - shown > 0.25) { /* the readout, four times a second */
            vw_app_readout(a, title, sizeof title);
            glfwSetWindowTitle(w, title);
            shown = glfwGetTime();
        }
    }
}

/* The scripted input of the headless mode before the first frame: a cut, a grab. */
static int vw__script_start(vw_app *a, const vw_options *o)
{
    if (o->stroke)
        printf("cut: %d tetrahedra removed by the stroke\n", vw_app_cut_segment(a, o->stroke_at, o->stroke_at + 2));
    if (o->drag) {
        int h = vw_app_pick(a, o->drag_at[0], o->drag_at[1]);
        if (h < 0) return fprintf(stderr, "viewer: nothing to grab at %g, %g\n", o->drag_at[0], o->drag_at[1]), -1;
        vw_app_grab(a, h, o->drag_at[0], o->drag_at[1]);
    }
    return 0;
}

/* The mouse of frame i, ramped over the first half of the frames. */
static void vw__script_frame(vw_app *a, const vw_options *o, int i)
{
    double ramp = o->frames > 1 ? 2.0 * (i + 1) / o->frames : 1;
    if (ramp > 1) ramp = 1;
    if (a->grabbed >= 0)
        vw_app_move_grab(a, o->drag_at[0] + ramp * o->drag_at[2], o->drag_at[1] + ramp * o->drag_at[3]);
}

static int vw__headless(GLFWwindow *w, vw_app *a, const vw_options *o)
{
    char readout[512];
    double tip[3];
    int i, tip_handle;
    for (i = 0; o->keys && o->keys[i]; i++) /* GLFW's codes of letters, digits, space: ASCII */
        vw__on_key(w, o->keys[i] >= 'a' && o->keys[i] <= 'z' ? o->keys[i] - 'a' + 'A' : o->keys[i], 0, GLFW_PRESS, 0);
    tip_handle = vw_app_tip(a);
    if (vw__script_start(a, o)) return 1;
    for (i = 0; i < o->frames; i++) {
        vw__script_frame(a, o, i);
        vw_app_advance(a);
    }
    vw_draw(a);
    a->api->handle_position(a->sim, tip_handle, tip);
    vw_app_readout(a, readout, sizeof readout);
    printf("readout: %s\n", readout);
    printf("tip: %.6g %.6g %.6g m after %d frames\n", tip[0], tip[1], tip[2], o->frames);
    if (a->error[0]) fprintf(stderr, "viewer: %s\n", a->error);
    return vw__screenshot(a, o->screenshot) || a->error[0] ? 1 : 0;
}

int main(int argc, char **argv)
{
    vw_options o;
    vw_app a;
    char err[256];
    GLFWwindow *w;
    int rc = 0;
    memset(&o, 0, sizeof o);
    memset(&a, 0, sizeof a);
    o.width = 960;
    o.height = 640;
    a.integrator = VW_IMPLICIT;
    a.grabbed = -1;
    vw__parse(argc, argv, &o, &a);
    if (o.mesh ? vw_scene_load(&a.scene, o.mesh, err) : vw_scene_builtin(&a.scene, o.scene ? o.scene : "cantilever", err))
        return fprintf(stderr, "viewer: %s\n", err), 1;
    if (vw_app_open(&a, err)) return fprintf(stderr, "viewer: %s\n", err), 1;
    vw_camera_fit(&a.camera, a.scene.lo, a.scene.hi);
    if (!glfwInit()) return fprintf(stderr, "viewer: GLFW cannot start (no display?)\n"), 1;
    w = vw__window(&o, &a);
    if (!w) rc = 1;
    else if (o.headless) rc = vw__headless(w, &a, &o);
    else vw__interactive(w, &a);
    if (w) {
        vw_render_shutdown();
        glfwDestroyWindow(w);
    }
    glfwTerminate();
    vw_app_close(&a);
    free(a.vertices);
    vw_scene_free(&a.scene);
    return rc;
}
