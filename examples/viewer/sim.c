/* sim.c - the viewer's adapters from sim.h to tensormass.h, heml.h and frames.h, through
   their public APIs only. Compiled twice: in double (defines vw_sim_double) and with
   -DVW_FLOAT in float (vw_sim_float); the headers rename their float entry points, so
   both copies link into one program.

   Sections: >>common (mesh data the colour fields need), >>create, >>step, >>handles,
   >>topology, >>fields, >>table. */
#ifdef VW_FLOAT
#define TMASS_REAL float
#define HEML_REAL float
#define FRM_REAL float
#define VW_API vw_sim_float
#define VW_PRECISION "float"
#else
#define VW_API vw_sim_double
#define VW_PRECISION "double"
#endif
#define TENSORMASS_IMPLEMENTATION
#include "../../tensormass.h"
#define HEML_IMPLEMENTATION
#include "../../heml.h"
#define FRAMES_IMPLEMENTATION
#include "../../frames.h"
#include "sim.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct vw_sim {
    int model;
    tmass_model *tm;
    heml_model *hm;
    frm_model *fm;
    frm_sampling sampling;
    int point_count, tet_count;
    double *rest;          /* 3 per point, m */
    int *tets;             /* 4 per tetrahedron (tensormass, heml) */
    double *rest_inverse;  /* 9 per tetrahedron: inverse of the rest edge matrix */
    const int *boundary;   /* the mesh's boundary triangles (heml) */
    int boundary_count;
    double lambda, mu;     /* Pa, Lame coefficients */
    double stable_dt;      /* s, 0 where the model has no explicit integrator */
    float *scratch;        /* one value per tetrahedron or sample */
    float *weights;        /* per point: how many values were summed into it */
};

/* >>common */

static double vw__det3(const double a[9])
{
    return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
           a[2] * (a[3] * a[7] - a[4] * a[6]);
}

static void vw__inverse3(const double a[9], double out[9])
{
    double d = vw__det3(a);
    out[0] = (a[4] * a[8] - a[5] * a[7]) / d;
    out[1] = (a[2] * a[7] - a[1] * a[8]) / d;
    out[2] = (a[1] * a[5] - a[2] * a[4]) / d;
    out[3] = (a[5] * a[6] - a[3] * a[8]) / d;
    out[4] = (a[0] * a[8] - a[2] * a[6]) / d;
    out[5] = (a[2] * a[3] - a[0] * a[5]) / d;
    out[6] = (a[3] * a[7] - a[4] * a[6]) / d;
    out[7] = (a[1] * a[6] - a[0] * a[7]) / d;
    out[8] = (a[0] * a[4] - a[1] * a[3]) / d;
}

/* Edge matrix of tetrahedron t: columns x1 - x0, x2 - x0, x3 - x0 (row-major). */
static void vw__edges(const double *x, const int *t, double out[9])
{
    int r, c;
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) out[3 * r + c] = x[3 * t[c + 1] + r] - x[3 * t[0] + r];
}

static void vw__mul3(const double a[9], const double b[9], double out[9])
{
    int r, c;
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) out[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
}

static int vw__mesh_data(vw_sim *s, const vw_mesh *mesh)
{
    int t;
    s->point_count = mesh->node_count;
    s->tet_count = mesh->tet_count;
    s->rest = (double *)malloc(sizeof(double) * 3 * mesh->node_count);
    s->tets = (int *)malloc(sizeof(int) * 4 * mesh->tet_count);
    s->rest_inverse = (double *)malloc(sizeof(double) * 9 * mesh->tet_count);
    if (!s->rest || !s->tets || !s->rest_inverse) return -1;
    memcpy(s->rest, mesh->nodes, sizeof(double) * 3 * mesh->node_count);
    memcpy(s->tets, mesh->tets, sizeof(int) * 4 * mesh->tet_count);
    for (t = 0; t < mesh->tet_count; t++) {
        double d0[9];
        vw__edges(s->rest, s->tets + 4 * t, d0);
        vw__inverse3(d0, s->rest_inverse + 9 * t);
    }
    s->boundary = mesh->boundary;
    s->boundary_count = mesh->boundary_count;
    return 0;
}

/* Half the smallest edge over the dilatational wave speed: the explicit step's CFL
   estimate where the model has none of its own (tensormass). */
static double vw__cfl_estimate(const vw_sim *s, double density)
{
    double h = 1e30, c = sqrt((s->lambda + 2 * s->mu) / density);
    int t, a, b;
    for (t = 0; t < s->tet_count; t++)
        for (a = 0; a < 4; a++)
            for (b = a + 1; b < 4; b++) {
                const double *p = s->rest + 3 * s->tets[4 * t + a], *q = s->rest + 3 * s->tets[4 * t + b];
                double l = sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                (p[2] - q[2]) * (p[2] - q[2]));
                if (l < h) h = l;
            }
    return 0.5 * h / c;
}

/* >>create */

static tmass_real *vw__to_tmass(const double *x, int n)
{
    tmass_real *r = (tmass_real *)malloc(sizeof(tmass_real) * (size_t)n);
    int i;
    if (r)
        for (i = 0; i < n; i++) r[i] = (tmass_real)x[i];
    return r;
}

static int vw__create_tensormass(vw_sim *s, const vw_mesh *mesh, const vw_config *c, char *err)
{
    tmass_desc d = tmass_default_desc();
    tmass_real *nodes = vw__to_tmass(mesh->nodes, 3 * mesh->node_count);
    int i, rc;
    if (!nodes) return TMASS_ERR_ALLOC;
    d.rest_positions = nodes;
    d.node_count = mesh->node_count;
    d.tets = mesh->tets;
    d.tet_count = mesh->tet_count;
    d.young_modulus = (tmass_real)c->young_modulus;
    d.poisson_ratio = (tmass_real)c->poisson_ratio;
    d.density = (tmass_real)c->density;
    d.mass_damping = (tmass_real)c->mass_damping;
    rc = tmass_create(&d, &s->tm);
    free(nodes);
    if (rc) {
        snprintf(err, 256, "tensormass: %s", tmass_error_string(rc));
        return rc;
    }
    for (i = 0; i < mesh->fixed_count; i++) tmass_fix_node(s->tm, mesh->fixed[i]);
    s->stable_dt = vw__cfl_estimate(s, c->density);
    return 0;
}

static int vw__create_heml(vw_sim *s, const vw_mesh *mesh, const vw_config *c, char *err)
{
    heml_desc d = heml_default_desc();
    heml_real *nodes = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)mesh->node_count);
    int i, rc;
    if (!nodes) return HEML_ERR_ALLOC;
    for (i = 0; i < 3 * mesh->node_count; i++) nodes[i] = (heml_real)mesh->nodes[i];
    d.rest_positions = nodes;
    d.node_count = mesh->node_count;
    d.tets = mesh->tets;
    d.tet_count = mesh->tet_count;
    d.material = heml_material_from_young(HEML_NEO_HOOKEAN, c->young_modulus, c->poisson_ratio);
    d.material.density = (heml_real)c->density;
    d.mass_damping = (heml_real)c->mass_damping;
    d.allow_inversion = 1; /* a hard pull may invert a tetrahedron: show it, do not stop */
    rc = heml_create(&d, &s->hm);
    free(nodes);
    if (rc) {
        snprintf(err, 256, "heml: %s", heml_error_string(rc));
        return rc;
    }
    for (i = 0; i < mesh->fixed_count; i++) heml_fix_node(s->hm, mesh->fixed[i]);
    s->stable_dt = heml_stable_time_step(s->hm);
    return 0;
}

/* Frames at the mesh nodes and one sample per tetrahedron, or, from a closed surface,
   Poisson-disk frames and samples inside it (frames' meshless sampling). */
static int vw__frames_sampling(vw_sim *s, const vw_mesh *mesh, const vw_config *c)
{
    int i, rc;
    if (c->surface) {
        frm_poisson_desc p = frm_poisson_default_desc();
        frm_real *v = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)c->surface_vertex_count);
        if (!v) return FRM_ERR_ALLOC;
        for (i = 0; i < 3 * c->surface_vertex_count; i++) v[i] = (frm_real)c->surface[i];
        p.frame_spacing = (frm_real)c->frame_spacing;
        p.sample_spacing = (frm_real)(c->frame_spacing / 2.5);
        rc = frm_sampling_surface(&s->sampling, v, c->surface_vertex_count, c->surface_triangles,
                                  c->surface_triangle_count, &p, NULL, NULL);
        free(v);
    } else {
        frm_real *v = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)mesh->node_count);
        if (!v) return FRM_ERR_ALLOC;
        for (i = 0; i < 3 * mesh->node_count; i++) v[i] = (frm_real)mesh->nodes[i];
        rc = frm_sampling_tets(&s->sampling, v, mesh->node_count, mesh->tets, mesh->tet_count, 1, NULL, NULL);
        free(v);
    }
    return rc;
}

/* The frames nearest the fixed mesh nodes (the same nodes for tetrahedral sampling), or,
   for a surface, every frame within one frame spacing of the smallest x. */
static void vw__frames_pins(vw_sim *s, const vw_mesh *mesh, const vw_config *c)
{
    const frm_real *x = frm_model_positions(s->fm);
    int i, n = frm_model_frame_count(s->fm);
    double lo = 1e30;
    if (!c->surface) {
        for (i = 0; i < mesh->fixed_count; i++) frm_model_fix_frame(s->fm, mesh->fixed[i]);
        return;
    }
    for (i = 0; i < n; i++)
        if (x[3 * i] < lo) lo = x[3 * i];
    for (i = 0; i < n; i++)
        if (x[3 * i] < lo + c->frame_spacing) frm_model_fix_frame(s->fm, i);
}

static int vw__create_frames(vw_sim *s, const vw_mesh *mesh, const vw_config *c, char *err)
{
    frm_desc d = frm_model_default_desc();
    const frm_real *x;
    int i, rc = vw__frames_sampling(s, mesh, c);
    if (!rc) {
        frm_sampling_apply(&s->sampling, &d);
        d.material.law = FRM_LAW_SVK;
        d.material.young_modulus = (frm_real)c->young_modulus;
        d.material.poisson_ratio = (frm_real)c->poisson_ratio;
        d.material.density = (frm_real)c->density;
        d.mass_damping = (frm_real)c->mass_damping;
        rc = frm_model_create(&d, &s->fm);
    }
    if (rc) {
        snprintf(err, 256, "frames: %s", frm_error_string(rc));
        return rc;
    }
    vw__frames_pins(s, mesh, c);
    s->point_count = frm_model_sample_count(s->fm);
    s->rest = (double *)malloc(sizeof(double) * 3 * (size_t)s->point_count);
    s->scratch = (float *)malloc(sizeof(float) * (size_t)s->point_count);
    if (!s->rest || !s->scratch) return FRM_ERR_ALLOC;
    x = frm_model_sample_positions(s->fm);
    for (i = 0; i < 3 * s->point_count; i++) s->rest[i] = (double)x[i];
    s->stable_dt = 0; /* implicit Euler only */
    return 0;
}

static void vw__destroy(vw_sim *s)
{
    if (!s) return;
    if (s->tm) tmass_destroy(s->tm);
    if (s->hm) heml_destroy(s->hm);
    if (s->fm) frm_model_destroy(s->fm);
    frm_sampling_free(&s->sampling);
    free(s->rest);
    free(s->tets);
    free(s->rest_inverse);
    free(s->scratch);
    free(s->weights);
    free(s);
}

static int vw__create(const vw_mesh *mesh, const vw_config *c, vw_sim **out, char *err)
{
    vw_sim *s = (vw_sim *)calloc(1, sizeof(vw_sim));
    int rc = -1;
    *out = NULL;
    snprintf(err, 256, "out of memory");
    if (!s) return -1;
    s->model = c->model;
    s->mu = c->young_modulus / (2 * (1 + c->poisson_ratio));
    s->lambda = c->young_modulus * c->poisson_ratio / ((1 + c->poisson_ratio) * (1 - 2 * c->poisson_ratio));
    if (c->model == VW_FRAMES) rc = vw__create_frames(s, mesh, c, err);
    else if (vw__mesh_data(s, mesh) == 0) {
        s->scratch = (float *)malloc(sizeof(float) * (size_t)mesh->tet_count);
        if (s->scratch)
            rc = c->model == VW_HEML ? vw__create_heml(s, mesh, c, err) : vw__create_tensormass(s, mesh, c, err);
    }
    if (!rc) s->weights = (float *)malloc(sizeof(float) * (size_t)s->point_count);
    if (!rc && !s->weights) rc = -1;
    if (rc) {
        vw__destroy(s);
        return rc;
    }
    *out = s;
    return 0;
}

/* >>step */

static int vw__supports(const vw_sim *s, int integrator)
{
    if (s->model == VW_FRAMES) return integrator == VW_IMPLICIT;
    return integrator >= 0 && integrator < VW_INTEGRATOR_COUNT;
}

static int vw__step(vw_sim *s, double dt, int integrator, char *err)
{
    static const tmass_integrator tm[3] = {TMASS_SEMI_IMPLICIT_EULER, TMASS_IMPLICIT_EULER,
                                           TMASS_IMPLICIT_EULER_LINEARIZED};
    static const heml_integrator hm[3] = {HEML_SEMI_EXPLICIT_EULER, HEML_IMPLICIT_EULER,
                                          HEML_IMPLICIT_EULER_LINEARIZED};
    int rc;
    if (s->tm) {
        rc = tmass_step_ex(s->tm, (tmass_real)dt, tm[integrator]);
        if (rc) snprintf(err, 256, "tensormass: %s", tmass_error_string(rc));
    } else if (s->hm) {
        rc = heml_step_ex(s->hm, (heml_real)dt, hm[integrator]);
        if (rc) snprintf(err, 256, "heml: %s", heml_error_string(rc));
    } else {
        rc = frm_model_step_ex(s->fm, (frm_real)dt);
        if (rc) snprintf(err, 256, "frames: %s", frm_error_string(rc));
    }
    return rc;
}

static double vw__stable_time_step(const vw_sim *s) { return s->stable_dt; }

static int vw__point_count(const vw_sim *s) { return s->point_count; }

static void vw__points(vw_sim *s, float *xyz)
{
    int i, n = 3 * s->point_count;
    if (s->tm) {
        const tmass_real *x = tmass_positions(s->tm);
        for (i = 0; i < n; i++) xyz[i] = (float)x[i];
    } else if (s->hm) {
        const heml_real *x = heml_positions(s->hm);
        for (i = 0; i < n; i++) xyz[i] = (float)x[i];
    } else {
        const frm_real *x = frm_model_sample_positions(s->fm);
        for (i = 0; i < n; i++) xyz[i] = (float)x[i];
    }
}

/* >>handles */

static int vw__handle_count(const vw_sim *s) { return s->fm ? frm_model_frame_count(s->fm) : s->point_count; }

static void vw__handle_position(vw_sim *s, int i, double p[3])
{
    int k;
    for (k = 0; k < 3; k++)
        p[k] = s->tm   ? (double)tmass_positions(s->tm)[3 * i + k]
               : s->hm ? (double)heml_positions(s->hm)[3 * i + k]
                       : (double)frm_model_positions(s->fm)[3 * i + k];
}

static int vw__handle_pinned(const vw_sim *s, int i)
{
    if (s->tm) return tmass_node_pinned(s->tm, i) != 0;
    if (s->hm) return heml_node_pinned(s->hm, i) != 0;
    return frm_model_frame_state(s->fm, i) != 0;
}

static int vw__drag(vw_sim *s, int i, const double p[3])
{
    int k;
    if (s->tm) {
        tmass_real u[3];
        for (k = 0; k < 3; k++) u[k] = (tmass_real)(p[k] - s->rest[3 * i + k]);
        return tmass_set_displacement(s->tm, i, u);
    }
    if (s->hm) {
        heml_real u[3];
        for (k = 0; k < 3; k++) u[k] = (heml_real)(p[k] - s->rest[3 * i + k]);
        return heml_set_displacement(s->hm, i, u);
    } else {
        frm_real x[3], q[4];
        for (k = 0; k < 3; k++) x[k] = (frm_real)p[k];
        for (k = 0; k < 4; k++) q[k] = frm_model_orientations(s->fm)[4 * i + k];
        return frm_model_drive_frame(s->fm, i, x, q);
    }
}

static int vw__release(vw_sim *s, int i)
{
    if (s->tm) return tmass_release_node(s->tm, i);
    if (s->hm) return heml_release_node(s->hm, i);
    return frm_model_release_frame(s->fm, i);
}

static void vw__reaction(vw_sim *s, int i, double f[3])
{
    int k;
    const frm_real *g = NULL;
    if (s->fm && frm_model_forces(s->fm, &g) != 0) g = NULL;
    for (k = 0; k < 3; k++)
        f[k] = s->tm   ? (double)tmass_forces(s->tm)[3 * i + k]
               : s->hm ? (double)heml_compute_forces(s->hm)[3 * i + k]
               : g     ? (double)g[6 * i + k]
                       : 0.0;
}

/* >>topology */

static const int *vw__triangles(vw_sim *s, int *count)
{
    if (s->tm) return tmass_boundary_triangles(s->tm, count);
    *count = s->hm ? s->boundary_count : 0;
    return s->hm ? s->boundary : NULL;
}

static int vw__cut(vw_sim *s, const int *tets, int count, int *removed)
{
    *removed = 0;
    return s->tm ? tmass_remove_tets(s->tm, tets, count, removed) : 1;
}

static int vw__tear(vw_sim *s, double max_elongation, int *removed)
{
    tmass_tear_criteria c = tmass_default_tear_criteria();
    *removed = 0;
    if (!s->tm) return 1;
    c.max_elongation = (tmass_real)max_elongation;
    return tmass_tear(s->tm, &c, removed);
}

static int vw__tet_alive(const vw_sim *s, int tet) { return s->tm ? tmass_tet_alive(s->tm, tet) == 1 : 1; }

/* >>fields */

/* von Mises equivalent of a symmetric stress (row-major 3x3), Pa. */
static double vw__von_mises(const double a[9])
{
    double d = (a[0] - a[4]) * (a[0] - a[4]) + (a[4] - a[8]) * (a[4] - a[8]) + (a[8] - a[0]) * (a[8] - a[0]);
    double o = a[1] * a[1] + a[2] * a[2] + a[5] * a[5];
    return sqrt(0.5 * d + 3 * o);
}

/* Stress from a deformation gradient F: linear (sigma = lambda tr(eps) I + 2 mu eps,
   eps = sym(F) - I) for tensormass, St Venant-Kirchhoff's second Piola-Kirchhoff
   (lambda tr(E) I + 2 mu E, E = (F^T F - I) / 2) for frames; its von Mises value. */
static double vw__stress_from_gradient(const vw_sim *s, const double F[9], int green)
{
    double e[9], sig[9], tr;
    int r, c, k;
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) {
            double v = 0;
            if (green)
                for (k = 0; k < 3; k++) v += 0.5 * F[3 * k + r] * F[3 * k + c];
            else v = 0.5 * (F[3 * r + c] + F[3 * c + r]);
            e[3 * r + c] = v - (r == c ? (green ? 0.5 : 1.0) : 0.0);
        }
    tr = e[0] + e[4] + e[8];
    for (k = 0; k < 9; k++) sig[k] = 2 * s->mu * e[k] + (k % 4 == 0 ? s->lambda * tr : 0);
    return vw__von_mises(sig);
}

/* Per tetrahedron (into scratch): J = det F or the von Mises stress; heml's stress from
   heml_tet_stresses (Cauchy, its own law; 0 where a tetrahedron is inverted). */
static void vw__tet_values(vw_sim *s, int kind, const double *x)
{
    heml_real *sig = NULL;
    int t, k;
    if (s->hm && kind == VW_FIELD_STRESS) {
        sig = (heml_real *)malloc(sizeof(heml_real) * 9 * (size_t)s->tet_count);
        if (sig) heml_tet_stresses(s->hm, HEML_STRESS_CAUCHY, sig);
    }
    for (t = 0; t < s->tet_count; t++) {
        double d[9], F[9], a[9];
        vw__edges(x, s->tets + 4 * t, d);
        vw__mul3(d, s->rest_inverse + 9 * t, F);
        if (kind == VW_FIELD_VOLUME_RATIO) s->scratch[t] = (float)vw__det3(F);
        else if (s->hm) {
            for (k = 0; k < 9; k++) a[k] = sig ? (double)sig[9 * t + k] : 0.0;
            s->scratch[t] = a[0] == a[0] ? (float)vw__von_mises(a) : 0.0f;
        } else s->scratch[t] = (float)vw__stress_from_gradient(s, F, 0);
    }
    free(sig);
}

/* Averages the live tetrahedra's values onto their nodes. */
static void vw__tets_to_points(vw_sim *s, float *out)
{
    int t, k;
    for (k = 0; k < s->point_count; k++) out[k] = s->weights[k] = 0;
    for (t = 0; t < s->tet_count; t++) {
        if (!vw__tet_alive(s, t)) continue;
        for (k = 0; k < 4; k++) {
            out[s->tets[4 * t + k]] += s->scratch[t];
            s->weights[s->tets[4 * t + k]] += 1;
        }
    }
    for (k = 0; k < s->point_count; k++)
        if (s->weights[k] > 0) out[k] /= s->weights[k];
}

static void vw__sample_values(vw_sim *s, int kind, float *out)
{
    const frm_real *G = frm_model_deformation_gradients(s->fm);
    int i, k;
    for (i = 0; i < s->point_count; i++) {
        double F[9];
        for (k = 0; k < 9; k++) F[k] = (double)G[9 * i + k];
        out[i] = (float)(kind == VW_FIELD_VOLUME_RATIO ? vw__det3(F) : vw__stress_from_gradient(s, F, 1));
    }
}

static void vw__field(vw_sim *s, int kind, float *out)
{
    int i, k, n = s->point_count;
    float *x = (float *)malloc(sizeof(float) * 3 * (size_t)n);
    double *xd = (double *)malloc(sizeof(double) * 3 * (size_t)n);
    if (!x || !xd) {
        for (i = 0; i < n; i++) out[i] = 0;
    } else if (kind == VW_FIELD_DISPLACEMENT) {
        vw__points(s, x);
        for (i = 0; i < n; i++) {
            double u2 = 0;
            for (k = 0; k < 3; k++) u2 += (x[3 * i + k] - s->rest[3 * i + k]) * (x[3 * i + k] - s->rest[3 * i + k]);
            out[i] = (float)sqrt(u2);
        }
    } else if (s->fm) vw__sample_values(s, kind, out);
    else {
        vw__points(s, x);
        for (i = 0; i < 3 * n; i++) xd[i] = x[i];
        vw__tet_values(s, kind, xd);
        vw__tets_to_points(s, out);
    }
    free(x);
    free(xd);
}

static int vw__frames(vw_sim *s, float *out)
{
    const frm_real *x, *q;
    int i, k, n;
    if (!s->fm) return 0;
    x = frm_model_positions(s->fm);
    q = frm_model_orientations(s->fm);
    n = frm_model_frame_count(s->fm);
    for (i = 0; out && i < n; i++) {
        double a = q[4 * i], b = q[4 * i + 1], c = q[4 * i + 2], w = q[4 * i + 3];
        double R[9] = {1 - 2 * (b * b + c * c), 2 * (a * b - c * w),     2 * (a * c + b * w),
                       2 * (a * b + c * w),     1 - 2 * (a * a + c * c), 2 * (b * c - a * w),
                       2 * (a * c - b * w),     2 * (b * c + a * w),     1 - 2 * (a * a + b * b)};
        float *o = out + 12 * i;
        for (k = 0; k < 3; k++) {
            o[k] = (float)x[3 * i + k];
            o[3 + k] = (float)R[3 * k];     /* x axis: first column */
            o[6 + k] = (float)R[3 * k + 1];
            o[9 + k] = (float)R[3 * k + 2];
        }
    }
    return n;
}

/* >>table */

const vw_sim_api VW_API = {VW_PRECISION,      vw__create,        vw__destroy,         vw__step,
                           vw__supports,      vw__stable_time_step, vw__point_count,  vw__points,
                           vw__handle_count,  vw__handle_position, vw__handle_pinned, vw__drag,
                           vw__release,       vw__reaction,      vw__triangles,       vw__cut,
                           vw__tear,          vw__tet_alive,     vw__field,           vw__frames};
