/* app.c - the viewer's simulation side (app.h): building and switching models, stepping
   one frame, picking and dragging handles, the scalpel, the readout. */
#include "app.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

const char *const vw_model_names[VW_MODEL_COUNT] = {"tensormass linear", "heml Neo-Hookean", "frames SVK"};
const char *const vw_integrator_names[VW_INTEGRATOR_COUNT] = {"semi-implicit Euler", "implicit Euler",
                                                             "implicit Euler linearised"};
const char *const vw_field_names[VW_FIELD_COUNT] = {"displacement m", "von Mises stress Pa", "volume ratio J"};

#define VW_FRAME_SECONDS (1.0 / 60.0)
#define VW_MAX_SUBSTEPS 400

/* processor time, s: the models run on this thread (OpenMP builds: all threads' time) */
static double vw__seconds(void) { return (double)clock() / CLOCKS_PER_SEC; }

static void vw__fill_mesh(vw_app *a)
{
    vw_scene *s = &a->scene;
    memset(&a->mesh, 0, sizeof a->mesh);
    memset(&a->config, 0, sizeof a->config);
    a->mesh.node_count = s->mesh.node_count;
    a->mesh.tet_count = s->mesh.tet_count;
    a->mesh.nodes = s->mesh.nodes;
    a->mesh.tets = s->mesh.tets;
    a->mesh.fixed = s->fixed;
    a->mesh.fixed_count = s->fixed_count;
    a->mesh.boundary = s->boundary;
    a->mesh.boundary_count = s->boundary_count;
    a->config.young_modulus = s->young_modulus;
    a->config.poisson_ratio = s->poisson_ratio;
    a->config.density = s->density;
    a->config.mass_damping = s->mass_damping;
    a->config.frame_spacing = s->frame_spacing;
    a->config.surface = s->surface;
    a->config.surface_triangles = s->surface_triangles;
    a->config.surface_vertex_count = s->surface_vertex_count;
    a->config.surface_triangle_count = s->surface_triangle_count;
}

static int vw__buffers(vw_app *a)
{
    int n = a->api->point_count(a->sim), frames = a->api->frames(a->sim, NULL);
    a->points = (float *)malloc(sizeof(float) * 3 * (size_t)n);
    a->values = (float *)malloc(sizeof(float) * (size_t)n);
    a->frames = (float *)malloc(sizeof(float) * 12 * (size_t)(frames + 1));
    return a->points && a->values && a->frames ? 0 : -1;
}

int vw_app_open(vw_app *a, char *err)
{
    int rc;
    if (a->scene.surface) a->model = VW_FRAMES; /* a surface has no tetrahedra */
    vw__fill_mesh(a);
    a->config.model = a->model;
    a->api = a->precision ? &vw_sim_float : &vw_sim_double;
    rc = a->api->create(&a->mesh, &a->config, &a->sim, err);
    if (rc) return -1;
    if (!a->api->supports(a->sim, a->integrator)) a->integrator = VW_IMPLICIT;
    a->grabbed = -1;
    a->error[0] = 0;
    a->removed_total = 0;
    if (vw__buffers(a)) return snprintf(err, 256, "out of memory"), -1;
    a->api->points(a->sim, a->points);
    return 0;
}

void vw_app_close(vw_app *a)
{
    if (a->sim) a->api->destroy(a->sim);
    a->sim = NULL;
    free(a->points);
    free(a->values);
    free(a->frames);
    a->points = a->values = a->frames = NULL;
}

int vw_app_switch(vw_app *a, int model, int precision)
{
    int old_model = a->model, old_precision = a->precision;
    char err[256];
    vw_app_close(a);
    a->model = model;
    a->precision = precision;
    if (vw_app_open(a, err) == 0) return 0;
    snprintf(a->error, sizeof a->error, "%s", err);
    vw_app_close(a);
    a->model = old_model;
    a->precision = old_precision;
    return vw_app_open(a, err) ? -2 : -1;
}

/* Time step and steps per frame: implicit, two steps a frame (frames: one); explicit, the
   model's stable step estimate, as many as a frame needs (at most VW_MAX_SUBSTEPS: slow
   motion beyond). */
static void vw__schedule(vw_app *a)
{
    double stable = a->api->stable_time_step(a->sim);
    if (a->integrator == VW_EXPLICIT && stable > 0) {
        a->steps_per_frame = (int)ceil(VW_FRAME_SECONDS / stable);
        if (a->steps_per_frame > VW_MAX_SUBSTEPS) a->steps_per_frame = VW_MAX_SUBSTEPS;
        a->dt = VW_FRAME_SECONDS / a->steps_per_frame;
        if (a->dt > stable) a->dt = stable;
    } else {
        a->steps_per_frame = a->model == VW_FRAMES ? 1 : 2;
        a->dt = VW_FRAME_SECONDS / a->steps_per_frame;
    }
}

void vw_app_advance(vw_app *a)
{
    double t0;
    int i, rc = 0, removed = 0;
    if (!a->sim) return;
    a->frame++;
    if (!a->paused && !a->error[0]) {
        vw__schedule(a);
        t0 = vw__seconds();
        for (i = 0; i < a->steps_per_frame && !rc; i++) rc = a->api->step(a->sim, a->dt, a->integrator, a->error);
        a->step_seconds = (vw__seconds() - t0) / (i > 0 ? i : 1);
        a->steps_per_second = a->step_seconds > 0 ? 1 / a->step_seconds : 0;
        if (rc) fprintf(stderr, "viewer: %s (paused; R resets)\n", a->error);
        if (a->tearing && a->api->tear(a->sim, 0.5, &removed) == 0) a->removed_total += removed;
    }
    if (a->grabbed >= 0) a->api->reaction(a->sim, a->grabbed, a->force);
    a->api->points(a->sim, a->points);
}

int vw_app_pick(vw_app *a, double x, double y)
{
    int i, best = -1, n = a->api->handle_count(a->sim);
    double best_depth = 1e30;
    for (i = 0; i < n; i++) {
        double p[3], s[2], depth;
        if (a->api->handle_pinned(a->sim, i)) continue;
        a->api->handle_position(a->sim, i, p);
        vw_camera_project(a, p, s, &depth);
        if ((s[0] - x) * (s[0] - x) + (s[1] - y) * (s[1] - y) > 15.0 * 15.0) continue;
        if (depth > 0 && depth < best_depth) {
            best_depth = depth;
            best = i;
        }
    }
    return best;
}

void vw_app_grab(vw_app *a, int handle, double x, double y)
{
    double s[2], depth;
    a->grabbed = handle;
    a->api->handle_position(a->sim, handle, a->grab_start);
    memcpy(a->grab_target, a->grab_start, sizeof a->grab_target);
    vw_camera_project(a, a->grab_start, s, &depth);
    a->grab_mouse[0] = x;
    a->grab_mouse[1] = y;
    /* metres per screen unit at the handle's depth */
    a->grab_scale = 2 * depth * tan(a->camera.fov / 2) / (a->height > 0 ? a->height : 1);
}

/* The handle follows the mouse in the plane through its start facing the camera. */
void vw_app_move_grab(vw_app *a, double x, double y)
{
    double right[3], up[3], forward[3], offset[3];
    int k;
    if (a->grabbed < 0) return;
    vw_camera_axes(&a->camera, right, up, forward);
    for (k = 0; k < 3; k++)
        offset[k] = a->grab_scale * ((x - a->grab_mouse[0]) * right[k] - (y - a->grab_mouse[1]) * up[k]);
    vw_app_pull(a, offset);
}

void vw_app_pull(vw_app *a, const double offset[3])
{
    int k;
    if (a->grabbed < 0) return;
    for (k = 0; k < 3; k++) a->grab_target[k] = a->grab_start[k] + offset[k];
    a->api->drag(a->sim, a->grabbed, a->grab_target);
}

void vw_app_release(vw_app *a)
{
    if (a->grabbed >= 0) a->api->release(a->sim, a->grabbed);
    a->grabbed = -1;
    a->force[0] = a->force[1] = a->force[2] = 0;
}

/* Twice the signed area of the triangle (a, b, c) in the screen plane. */
static double vw__cross(const double a[2], const double b[2], const double c[2])
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* 1 if segments p-q and a-b intersect (touching counts). */
static int vw__segments_cross(const double p[2], const double q[2], const double a[2], const double b[2])
{
    double d1 = vw__cross(p, q, a), d2 = vw__cross(p, q, b), d3 = vw__cross(a, b, p), d4 = vw__cross(a, b, q);
    return d1 * d2 <= 0 && d3 * d4 <= 0 && (d1 != 0 || d2 != 0);
}

/* 1 if point s lies in the triangle (a, b, c). */
static int vw__inside(const double s[2], const double a[2], const double b[2], const double c[2])
{
    double u = vw__cross(a, b, s), v = vw__cross(b, c, s), w = vw__cross(c, a, s);
    return (u >= 0 && v >= 0 && w >= 0) || (u <= 0 && v <= 0 && w <= 0);
}

/* 1 if the stroke p-q crosses the screen footprint of tetrahedron t (the convex hull of
   its four projected corners): it crosses one of its six edges or starts inside it. */
static int vw__stroke_crosses(const vw_app *a, int t, const double p[2], const double q[2])
{
    double s[4][2], depth, x[3];
    int i, j, k;
    for (i = 0; i < 4; i++) {
        for (k = 0; k < 3; k++) x[k] = a->points[3 * a->mesh.tets[4 * t + i] + k];
        vw_camera_project(a, x, s[i], &depth);
        if (depth <= 0) return 0;
    }
    for (i = 0; i < 4; i++)
        for (j = i + 1; j < 4; j++)
            if (vw__segments_cross(p, q, s[i], s[j])) return 1;
    for (i = 0; i < 4; i++) /* p inside the triangle of the three other corners */
        if (vw__inside(p, s[(i + 1) % 4], s[(i + 2) % 4], s[(i + 3) % 4])) return 1;
    return 0;
}

/* The scalpel: removes the live tetrahedra the stroke segment p-q crosses on the screen,
   through the whole depth of the body. */
int vw_app_cut_segment(vw_app *a, const double p[2], const double q[2])
{
    int t, n = 0, removed = 0;
    int *list = (int *)malloc(sizeof(int) * (size_t)(a->mesh.tet_count + 1));
    if (!list || a->model != VW_TENSORMASS) return free(list), 0;
    for (t = 0; t < a->mesh.tet_count; t++)
        if (a->api->tet_alive(a->sim, t) && vw__stroke_crosses(a, t, p, q)) list[n++] = t;
    if (n) a->api->cut(a->sim, list, n, &removed);
    free(list);
    a->removed_total += removed;
    return removed;
}

int vw_app_tip(const vw_app *a)
{
    int i, best = -1, n = a->api->handle_count(a->sim);
    double bp[3] = {-1e30, 0, -1e30};
    for (i = 0; i < n; i++) {
        double p[3];
        if (a->api->handle_pinned(a->sim, i)) continue;
        a->api->handle_position(a->sim, i, p);
        if (p[0] > bp[0] + 1e-9 || (fabs(p[0] - bp[0]) <= 1e-9 && p[2] > bp[2])) {
            memcpy(bp, p, sizeof bp);
            best = i;
        }
    }
    return best;
}

void vw_app_readout(const vw_app *a, char *out, size_t size)
{
    double f = sqrt(a->force[0] * a->force[0] + a->force[1] * a->force[1] + a->force[2] * a->force[2]);
    double stable = a->api->stable_time_step(a->sim);
    char stable_text[32];
    if (stable > 0) snprintf(stable_text, sizeof stable_text, "%.3g ms", 1e3 * stable);
    else snprintf(stable_text, sizeof stable_text, "n/a, implicit only");
    snprintf(out, size,
             "%s | %s %s, %s | dt %.3g ms (stable %s) | %.3g ms/step, %.0f steps/s | %s %.3g..%.3g | "
             "hand force %.3g N | %d tets cut%s%s%s",
             a->scene.name, vw_model_names[a->model], a->api->precision, vw_integrator_names[a->integrator],
             1e3 * a->dt, stable_text, 1e3 * a->step_seconds, a->steps_per_second, vw_field_names[a->field],
             a->field_lo, a->field_hi, f, a->removed_total, a->tearing ? " | tearing" : "",
             a->paused ? " | paused" : "", a->error[0] ? " | STOPPED: " : "");
    if (a->error[0]) {
        size_t used = strlen(out);
        snprintf(out + used, size - used, "%s", a->error);
    }
}
