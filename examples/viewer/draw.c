/* draw.c - the viewer's camera and what it draws each frame (app.h): the body's boundary
   triangles (tensormass, heml) or its samples (frames) coloured by the chosen field, the
   frames as axis triads, pinned handles, the dragged handle's force, the scalpel-cut count
   in the title, and a colour legend with its range in seven-segment digits. */
#include "app.h"
#include "render.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* >>camera */

void vw_camera_fit(vw_camera *c, const double lo[3], const double hi[3])
{
    double r = 0;
    int k;
    for (k = 0; k < 3; k++) {
        c->target[k] = 0.5 * (lo[k] + hi[k]);
        r += 0.25 * (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    c->fov = 0.7;
    c->yaw = 0;
    c->pitch = 0.15;
    c->distance = 1.3 * sqrt(r) / tan(c->fov / 2);
}

void vw_camera_axes(const vw_camera *c, double right[3], double up[3], double forward[3])
{
    forward[0] = sin(c->yaw) * cos(c->pitch);
    forward[1] = cos(c->yaw) * cos(c->pitch);
    forward[2] = -sin(c->pitch);
    right[0] = cos(c->yaw); /* forward x (0, 0, 1), normalised */
    right[1] = -sin(c->yaw);
    right[2] = 0;
    up[0] = right[1] * forward[2] - right[2] * forward[1];
    up[1] = right[2] * forward[0] - right[0] * forward[2];
    up[2] = right[0] * forward[1] - right[1] * forward[0];
}

/* Column-major projection * view. */
static void vw__mvp(const vw_app *a, float out[16])
{
    const vw_camera *c = &a->camera;
    double r[3], u[3], f[3], eye[3], aspect = a->fb_height > 0 ? (double)a->fb_width / a->fb_height : 1;
    double n = 0.02 * c->distance, fa = 20 * c->distance, t = 1 / tan(c->fov / 2), view[16], proj[16];
    int k, i, j;
    vw_camera_axes(c, r, u, f);
    for (k = 0; k < 3; k++) eye[k] = c->target[k] - c->distance * f[k];
    memset(view, 0, sizeof view);
    memset(proj, 0, sizeof proj);
    for (k = 0; k < 3; k++) { /* rows: right, up, -forward */
        view[4 * k] = r[k];
        view[4 * k + 1] = u[k];
        view[4 * k + 2] = -f[k];
    }
    view[12] = -(r[0] * eye[0] + r[1] * eye[1] + r[2] * eye[2]);
    view[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    view[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
    view[15] = 1;
    proj[0] = t / aspect;
    proj[5] = t;
    proj[10] = -(fa + n) / (fa - n);
    proj[11] = -1;
    proj[14] = -2 * fa * n / (fa - n);
    for (i = 0; i < 4; i++)
        for (j = 0; j < 4; j++) {
            double s = 0;
            for (k = 0; k < 4; k++) s += proj[4 * k + j] * view[4 * i + k];
            out[4 * i + j] = (float)s;
        }
}

void vw_camera_project(const vw_app *a, const double p[3], double screen[2], double *depth)
{
    const vw_camera *c = &a->camera;
    double r[3], u[3], f[3], d[3], x = 0, y = 0, z = 0, t = 1 / tan(c->fov / 2);
    double aspect = a->height > 0 ? (double)a->width / a->height : 1;
    int k;
    vw_camera_axes(c, r, u, f);
    for (k = 0; k < 3; k++) d[k] = p[k] - (c->target[k] - c->distance * f[k]);
    for (k = 0; k < 3; k++) {
        x += d[k] * r[k];
        y += d[k] * u[k];
        z += d[k] * f[k];
    }
    *depth = z;
    if (z <= 0) z = 1e-9;
    screen[0] = (1 + x * t / aspect / z) * 0.5 * a->width;
    screen[1] = (1 - y * t / z) * 0.5 * a->height;
}

/* >>vertices */

static float *vw__reserve(vw_app *a, size_t floats)
{
    if (floats > a->vertex_capacity) {
        float *g = (float *)realloc(a->vertices, sizeof(float) * floats);
        if (!g) return NULL;
        a->vertices = g;
        a->vertex_capacity = floats;
    }
    return a->vertices;
}

static void vw__vertex(float *v, const float p[3], const float n[3], const float c[3])
{
    memcpy(v, p, 3 * sizeof(float));
    memcpy(v + 3, n, 3 * sizeof(float));
    memcpy(v + 6, c, 3 * sizeof(float));
}

/* Blue (low) - yellow - red (high): no colour close to the light background. */
static void vw__colour(float t, float c[3])
{
    float u;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    if (t < 0.5f) {
        u = 2 * t;
        c[0] = 0.2f + 0.75f * u, c[1] = 0.3f + 0.55f * u, c[2] = 1 - 0.8f * u;
    } else {
        u = 2 * t - 1;
        c[0] = 0.95f - 0.05f * u, c[1] = 0.85f - 0.75f * u, c[2] = 0.2f - 0.1f * u;
    }
}

static void vw__field_range(vw_app *a)
{
    int i, n = a->api->point_count(a->sim);
    a->field_lo = 1e30;
    a->field_hi = -1e30;
    for (i = 0; i < n; i++) {
        if (a->values[i] < a->field_lo) a->field_lo = a->values[i];
        if (a->values[i] > a->field_hi) a->field_hi = a->values[i];
    }
    if (a->field == VW_FIELD_DISPLACEMENT) a->field_lo = 0;
    if (a->field_hi - a->field_lo < 1e-12) a->field_hi = a->field_lo + 1e-12;
}

static float vw__unit(const vw_app *a, float v) { return (float)((v - a->field_lo) / (a->field_hi - a->field_lo)); }

/* Boundary triangles, flat-shaded, each vertex coloured by its point's value. */
static int vw__body_triangles(vw_app *a)
{
    int count = 0, t, j;
    const int *tri = a->api->triangles(a->sim, &count);
    float *v = tri ? vw__reserve(a, (size_t)VW_VERTEX_FLOATS * 3 * (size_t)count) : NULL;
    if (!v) return 0;
    for (t = 0; t < count; t++) {
        const float *p0 = a->points + 3 * tri[3 * t], *p1 = a->points + 3 * tri[3 * t + 1],
                    *p2 = a->points + 3 * tri[3 * t + 2];
        float e[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]}, g[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
        float n[3] = {e[1] * g[2] - e[2] * g[1], e[2] * g[0] - e[0] * g[2], e[0] * g[1] - e[1] * g[0]};
        float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]) + 1e-30f, c[3];
        for (j = 0; j < 3; j++) n[j] /= len;
        for (j = 0; j < 3; j++) {
            vw__colour(vw__unit(a, a->values[tri[3 * t + j]]), c);
            vw__vertex(v + VW_VERTEX_FLOATS * (3 * t + j), a->points + 3 * tri[3 * t + j], n, c);
        }
    }
    return 3 * count;
}

/* Samples (frames bodies) as coloured points. */
static int vw__body_points(vw_app *a)
{
    int i, n = a->api->point_count(a->sim);
    float *v = vw__reserve(a, (size_t)VW_VERTEX_FLOATS * (size_t)n), zero[3] = {0, 0, 0}, c[3];
    if (!v) return 0;
    for (i = 0; i < n; i++) {
        vw__colour(vw__unit(a, a->values[i]), c);
        vw__vertex(v + VW_VERTEX_FLOATS * i, a->points + 3 * i, zero, c);
    }
    return n;
}

/* A line from p to q into v (2 vertices). */
static void vw__line(float *v, const float p[3], const float q[3], const float c[3])
{
    static const float zero[3] = {0, 0, 0};
    vw__vertex(v, p, zero, c);
    vw__vertex(v + VW_VERTEX_FLOATS, q, zero, c);
}

/* Frames as triads (x red, y green, z blue), pinned handles as dark points, the grabbed
   handle's pull as a line to its target. */
static int vw__overlay_lines(vw_app *a, double size)
{
    static const float axis[3][3] = {{0.9f, 0.1f, 0.1f}, {0.1f, 0.6f, 0.1f}, {0.1f, 0.2f, 0.9f}};
    static const float black[3] = {0, 0, 0};
    int i, k, n = a->api->frames(a->sim, a->frames), count = 0;
    float *v = vw__reserve(a, (size_t)VW_VERTEX_FLOATS * (size_t)(6 * n + 2));
    if (!v) return 0;
    for (i = 0; i < n; i++)
        for (k = 0; k < 3; k++) {
            const float *o = a->frames + 12 * i, *d = o + 3 + 3 * k;
            float q[3] = {o[0] + (float)size * d[0], o[1] + (float)size * d[1], o[2] + (float)size * d[2]};
            vw__line(v + VW_VERTEX_FLOATS * count, o, q, axis[k]);
            count += 2;
        }
    if (a->grabbed >= 0) {
        double p[3];
        float fp[3], ft[3];
        a->api->handle_position(a->sim, a->grabbed, p);
        for (k = 0; k < 3; k++) {
            fp[k] = (float)p[k];
            ft[k] = (float)a->grab_target[k];
        }
        vw__line(v + VW_VERTEX_FLOATS * count, fp, ft, black);
        count += 2;
    }
    return count;
}

static int vw__pinned_points(vw_app *a)
{
    int i, n = a->api->handle_count(a->sim), count = 0;
    float *v = vw__reserve(a, (size_t)VW_VERTEX_FLOATS * (size_t)(n + 1)), c[3] = {0.2f, 0.2f, 0.2f}, zero[3] = {0};
    if (!v) return 0;
    for (i = 0; i < n; i++) {
        double p[3];
        float f[3];
        if (!a->api->handle_pinned(a->sim, i) && i != a->grabbed) continue;
        a->api->handle_position(a->sim, i, p);
        f[0] = (float)p[0];
        f[1] = (float)p[1];
        f[2] = (float)p[2];
        vw__vertex(v + VW_VERTEX_FLOATS * count++, f, zero, i == a->grabbed ? zero : c);
    }
    return count;
}

/* >>legend */

/* Seven-segment digits: segments a (top), b, c (right, top to bottom), d (bottom), e, f
   (left, bottom to top), g (middle), as bits 0 to 6. */
static int vw__segments(char ch)
{
    static const int digits[10] = {0x3f, 0x06, 0x5b, 0x4f, 0x66, 0x6d, 0x7d, 0x07, 0x7f, 0x6f};
    if (ch >= '0' && ch <= '9') return digits[ch - '0'];
    if (ch == '-') return 0x40;
    if (ch == 'e') return 0x79; /* E */
    return 0;
}

/* Text of digits, '.', '-', 'e' at (x, y) in normalised device coordinates, height h;
   returns the vertices written. */
static int vw__text(float *v, const char *text, float x, float y, float h)
{
    static const float seg[7][4] = {{0, 1, 1, 1}, {1, 1, 1, .5f}, {1, .5f, 1, 0}, {0, 0, 1, 0},
                                    {0, 0, 0, .5f}, {0, .5f, 0, 1}, {0, .5f, 1, .5f}};
    static const float ink[3] = {0.1f, 0.1f, 0.1f};
    float w = 0.5f * h, p[3] = {0, 0, 0}, q[3] = {0, 0, 0};
    int count = 0, s;
    for (; *text; text++, x += 1.5f * w) {
        int bits = vw__segments(*text);
        if (*text == '.') { /* a small square on the baseline, in a narrow slot */
            float sq[5][2] = {{.1f, 0}, {.4f, 0}, {.4f, .15f}, {.1f, .15f}, {.1f, 0}};
            for (s = 0; s < 4; s++) {
                p[0] = x + sq[s][0] * w, p[1] = y + sq[s][1] * h, q[0] = x + sq[s + 1][0] * w, q[1] = y + sq[s + 1][1] * h;
                vw__line(v + VW_VERTEX_FLOATS * count, p, q, ink);
                count += 2;
            }
            x -= 0.8f * w;
            continue;
        }
        for (s = 0; s < 7; s++) {
            if (!(bits & (1 << s))) continue;
            p[0] = x + seg[s][0] * w, p[1] = y + seg[s][1] * h, q[0] = x + seg[s][2] * w, q[1] = y + seg[s][3] * h;
            vw__line(v + VW_VERTEX_FLOATS * count, p, q, ink);
            count += 2;
        }
    }
    return count;
}

/* A value as "%.2g" without '+' and leading exponent zeros: 1.2e4, 3.5e-3. */
static void vw__number(double value, char *out, size_t size)
{
    char raw[32], *e;
    snprintf(raw, sizeof raw, "%.2g", value);
    e = strchr(raw, 'e');
    if (e) {
        int exponent = atoi(e + 1);
        *e = 0;
        snprintf(out, size, "%se%d", raw, exponent);
    } else snprintf(out, size, "%s", raw);
}

/* The colour bar on the right (16 bands) with its low and high values. */
static void vw__legend(vw_app *a, const float *identity, const float *light)
{
    float *v = vw__reserve(a, (size_t)VW_VERTEX_FLOATS * 600), zero[3] = {0, 0, 0}, c[3];
    float x0 = 0.86f, x1 = 0.93f, y0 = -0.7f, y1 = 0.7f, h = (y1 - y0) / 16;
    char text[32];
    int i, k, count = 0;
    if (!v) return;
    vw_render_wireframe(0);
    for (i = 0; i < 16; i++) {
        float q[6][3] = {{x0, y0 + i * h, 0}, {x1, y0 + i * h, 0}, {x1, y0 + (i + 1) * h, 0},
                         {x0, y0 + i * h, 0}, {x1, y0 + (i + 1) * h, 0}, {x0, y0 + (i + 1) * h, 0}};
        vw__colour((i + 0.5f) / 16, c);
        for (k = 0; k < 6; k++) vw__vertex(v + VW_VERTEX_FLOATS * count++, q[k], zero, c);
    }
    vw_render_batch(VW_TRIANGLES, v, count, identity, light, 0, 1);
    vw__number(a->field_hi, text, sizeof text);
    count = vw__text(v, text, 0.62f, y1 + 0.06f, 0.07f);
    vw__number(a->field_lo, text, sizeof text);
    count += vw__text(v + VW_VERTEX_FLOATS * count, text, 0.62f, y0 - 0.13f, 0.07f);
    vw_render_batch(VW_LINES, v, count, identity, light, 0, 1);
}

/* >>frame */

void vw_draw(vw_app *a)
{
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    float mvp[16], light[3];
    double r[3], u[3], f[3], size = 0;
    int k, n;
    vw__mvp(a, mvp);
    vw_camera_axes(&a->camera, r, u, f);
    for (k = 0; k < 3; k++) {
        light[k] = (float)(0.3 * r[k] + 0.5 * u[k] - 0.8 * f[k]);
        size += (a->scene.hi[k] - a->scene.lo[k]) * (a->scene.hi[k] - a->scene.lo[k]);
    }
    a->api->field(a->sim, a->field, a->values);
    vw__field_range(a);
    vw_render_begin(a->fb_width, a->fb_height, a->wireframe);
    if (a->model == VW_FRAMES) {
        n = vw__body_points(a);
        vw_render_batch(VW_POINTS, a->vertices, n, mvp, light, 0, 5);
    } else {
        n = vw__body_triangles(a);
        vw_render_batch(VW_TRIANGLES, a->vertices, n, mvp, light, 1, 1);
    }
    n = vw__overlay_lines(a, 0.03 * sqrt(size));
    vw_render_batch(VW_LINES, a->vertices, n, mvp, light, 0, 1);
    n = vw__pinned_points(a);
    vw_render_batch(VW_POINTS, a->vertices, n, mvp, light, 0, 4);
    vw__legend(a, identity, light);
}
