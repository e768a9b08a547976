/* model_tensormass.c - bench adapter of tensormass.h: the tensor-mass model and its
   mass-spring baseline. Compiled twice by the Makefile, in double and with
   -DBENCH_FLOAT; each build exports its own table. */
#define _POSIX_C_SOURCE 199309L
#ifdef BENCH_FLOAT
#define TMASS_REAL float
#define BENCH_TABLE bench_models_tensormass_float
#define BENCH_PRECISION "float"
#else
#define BENCH_TABLE bench_models_tensormass_double
#define BENCH_PRECISION "double"
#endif
#define TMASS_STATIC
#define TENSORMASS_IMPLEMENTATION
#include "../tensormass.h"
#define TETMESH_STATIC
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "bench.h"
#include "body_mesh.h"
#include "model_common.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

typedef struct tm_sim {
    tmass_model *m;
    int nodes, tets;
    int *tet_nodes; /* 4 per tet, for cutting by centroid */
    double *rest;   /* 3n, with the offset */
    double offset[3];
    tmass_probe *probe; /* the last probed point (tm_probe); dropped by a cut */
    double probe_at[3];
} tm_sim;

static int tm_create(const bench_body *b, tmass_model_kind kind, void **out)
{
    tetmesh mesh;
    tmass_desc d = tmass_default_desc();
    tm_sim *s;
    tmass_real *x;
    int i, err;
    *out = NULL;
    if (bench_body_mesh(b, &mesh)) return TMASS_ERR_ALLOC;
    x = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)mesh.node_count);
    s = (tm_sim *)calloc(1, sizeof *s);
    if (!x || !s) {
        free(x);
        free(s);
        tetmesh_free(&mesh);
        return TMASS_ERR_ALLOC;
    }
    bench_to_reals(mesh.nodes, x, 3 * mesh.node_count);
    d.rest_positions = x;
    d.node_count = mesh.node_count;
    d.tets = mesh.tets;
    d.tet_count = mesh.tet_count;
    d.kind = kind;
    d.young_modulus = (tmass_real)b->young;
    d.poisson_ratio = (tmass_real)b->poisson;
    d.density = (tmass_real)b->density;
    d.mass_damping = (tmass_real)b->damping;
    for (i = 0; i < 3; i++) d.gravity[i] = (tmass_real)b->gravity[i];
    /* static solves of stiff slender beams need tight tolerances and many iterations */
    d.cg_tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-5 : 1e-9);
    d.cg_max_iterations = 100000;
    err = tmass_create(&d, &s->m);
    free(x);
    if (err) {
        free(s);
        tetmesh_free(&mesh);
        return err;
    }
    s->nodes = mesh.node_count;
    s->tets = mesh.tet_count;
    s->tet_nodes = mesh.tets;
    s->rest = mesh.nodes;
    memcpy(s->offset, b->offset, sizeof s->offset);
    if (b->clamp)
        for (i = 0; i < s->nodes; i++)
            if (bench_body_clamped(b, s->rest, i)) tmass_fix_node(s->m, i);
    *out = s;
    return 0;
}

static int tm_create_tensor(const bench_body *b, void **out) { return tm_create(b, TMASS_TENSOR_MASS, out); }
static int tm_create_springs(const bench_body *b, void **out) { return tm_create(b, TMASS_MASS_SPRING, out); }

static void tm_destroy(void *v)
{
    tm_sim *s = (tm_sim *)v;
    if (!s) return;
    tmass_probe_destroy(s->probe);
    tmass_destroy(s->m);
    free(s->tet_nodes);
    free(s->rest);
    free(s);
}

static int tm_dof(void *v) { return 3 * ((tm_sim *)v)->nodes; }
static int tm_node_count(void *v) { return ((tm_sim *)v)->nodes; }

static void tm_rest(void *v, int i, double p[3]) { bench_rest_position(((tm_sim *)v)->rest, i, p); }

static void tm_position(void *v, int i, double p[3])
{
    tm_sim *s = (tm_sim *)v;
    bench_displaced_position(s->rest, tmass_positions(s->m), tmass_rest_positions(s->m), i, p);
}

static int tm_pin(void *v, int i, const double u[3], const double *rotation)
{
    tmass_real w[3];
    (void)rotation;
    bench_to_reals(u, w, 3);
    return tmass_set_displacement(((tm_sim *)v)->m, i, w);
}

static int tm_release(void *v, int i) { return tmass_release_node(((tm_sim *)v)->m, i); }

static int tm_set_gravity(void *v, const double g[3])
{
    tmass_real w[3];
    bench_to_reals(g, w, 3);
    return tmass_set_gravity(((tm_sim *)v)->m, w);
}

static int tm_solve_static(void *v) { return tmass_solve_static(((tm_sim *)v)->m); }

static int tm_step(void *v, double dt, int integrator)
{
    static const tmass_integrator map[4] = {TMASS_EXPLICIT_EULER, TMASS_SEMI_IMPLICIT_EULER, TMASS_RK4,
                                            TMASS_IMPLICIT_EULER};
    if (integrator == BENCH_BDF2) return tmass_step_ex(((tm_sim *)v)->m, (tmass_real)dt, TMASS_BDF2);
    if (integrator < 0 || integrator > 3) return BENCH_UNSUPPORTED;
    return tmass_step_ex(((tm_sim *)v)->m, (tmass_real)dt, map[integrator]);
}

static int tm_forces(void *v, double *f)
{
    tm_sim *s = (tm_sim *)v;
    bench_to_doubles(tmass_forces(s->m), f, 3 * s->nodes);
    return 0;
}

static int tm_cut(void *v, int (*inside)(const double c[3], void *user), void *user, int *removed)
{
    tm_sim *s = (tm_sim *)v;
    int t, j, k, n = 0, err, *list = (int *)malloc(sizeof(int) * (size_t)s->tets);
    if (!list) return TMASS_ERR_ALLOC;
    for (t = 0; t < s->tets; t++) {
        double c[3] = {0, 0, 0};
        for (j = 0; j < 4; j++)
            for (k = 0; k < 3; k++) c[k] += 0.25 * (s->rest[3 * s->tet_nodes[4 * t + j] + k] - s->offset[k]);
        if (inside(c, user)) list[n++] = t;
    }
    err = tmass_remove_tets(s->m, list, n, removed);
    free(list);
    tmass_probe_destroy(s->probe); /* its tetrahedron may be gone */
    s->probe = NULL;
    return err;
}

/* The displacement at rest point p, through a probe made at the first call for p. */
static int tm_probe(void *v, const double p[3], double u[3])
{
    tm_sim *s = (tm_sim *)v;
    tmass_real q[3], r[3];
    int k, err;
    if (!s->probe || memcmp(p, s->probe_at, sizeof s->probe_at)) {
        tmass_probe_destroy(s->probe);
        s->probe = NULL;
        for (k = 0; k < 3; k++) q[k] = (tmass_real)p[k];
        err = tmass_probe_create(s->m, q, 1, &s->probe);
        if (err) return err;
        memcpy(s->probe_at, p, sizeof s->probe_at);
    }
    err = tmass_probe_displacements(s->probe, s->m, r);
    for (k = 0; k < 3; k++) u[k] = (double)r[k];
    return err;
}

static double tm_elements(void *v) { return (double)tmass_live_tet_count(((tm_sim *)v)->m); }

static double tm_bytes_tensor(void *v, int kernel)
{
    tm_sim *s = (tm_sim *)v;
    (void)kernel;
    return (double)tmass_edge_count(s->m) * (double)TMASS_FORCE_BYTES_PER_EDGE +
           (double)s->nodes * (double)TMASS_FORCE_BYTES_PER_NODE;
}

static double tm_bytes_springs(void *v, int kernel)
{
    tm_sim *s = (tm_sim *)v;
    (void)kernel;
    return (double)tmass_edge_count(s->m) * (double)TMASS_SPRING_BYTES_PER_EDGE +
           (double)s->nodes * (double)TMASS_SPRING_BYTES_PER_NODE;
}

/* The tensor model is linear: its K * v is the force kernel itself (tmass_forces is
   -K u), so both kernels time the same loop. Springs have no public K * v. */
static int tm_kernel_tensor(void *v, int kernel)
{
    if (kernel != BENCH_KERNEL_FORCE && kernel != BENCH_KERNEL_KV) return BENCH_UNSUPPORTED;
    return tmass_forces(((tm_sim *)v)->m) ? 0 : TMASS_ERR_ARG;
}

static int tm_kernel_springs(void *v, int kernel)
{
    if (kernel != BENCH_KERNEL_FORCE) return BENCH_UNSUPPORTED;
    return tmass_forces(((tm_sim *)v)->m) ? 0 : TMASS_ERR_ARG;
}

static double tm_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int tm_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The haptic scene of the precomputed model: a 0.32 x 0.32 x 0.02 m plate, 32 x 32 x 1
   cells (8 x 8 x 1 when quick), clamped on x = 0: every one of its 2,178 nodes is on the
   surface, and an update returns the displacement of all of them. A tool presses 1 to 3
   nodes near the middle of the top face; only the 24 nodes there are precomputed (the
   update cost is 9 x contacts x output nodes whatever the precomputed set, and 24 nodes
   keep the precomputation to 72 CG solves). */
static int tm_haptic(int quick, double update_seconds[3], int *surface_nodes, double *precompute_seconds,
                     double *memory_bytes)
{
    bench_body b;
    void *v;
    tm_sim *s;
    tmass_qs *qs = NULL;
    tmass_qs_desc qd = tmass_qs_default_desc();
    int err, c, i, candidates[24], found = 0;
    double t0;
    memset(&b, 0, sizeof b);
    b.size[0] = b.size[1] = 0.32;
    b.size[2] = 0.02;
    b.cells[0] = b.cells[1] = quick ? 8 : 32;
    b.cells[2] = 1;
    b.young = 1e4, b.poisson = 0.45, b.density = 1000, b.clamp = 1;
    b.gravity[2] = -9.81;
    err = tm_create(&b, TMASS_TENSOR_MASS, &v);
    if (err) return err;
    s = (tm_sim *)v;
    for (i = 0; i < s->nodes && found < 24; i++) { /* top-face nodes around the middle */
        const double *p = s->rest + 3 * i;
        double h = 0.32 / b.cells[0]; /* a 5 x 5 patch of nodes */
        if (p[2] > 0.01 - 1e-9 && fabs(p[0] - 0.16) < 2.5 * h && fabs(p[1]) < 2.5 * h) candidates[found++] = i;
    }
    qd.nodes = candidates;
    qd.node_count = found;
    qd.all_nodes = 1;
    t0 = tm_now();
    err = found < 3 ? TMASS_ERR_ARG : tmass_qs_create(s->m, &qd, &qs);
    *precompute_seconds = tm_now() - t0;
    if (err) {
        tm_destroy(v);
        return err;
    }
    *surface_nodes = s->nodes;
    *memory_bytes = (double)tmass_qs_memory_bytes(qs);
    for (c = 0; c < 3; c++) {
        double t[9];
        int r, rep, reps = quick ? 200 : 2000;
        for (r = 0; r < 9; r++) {
            t0 = tm_now();
            for (rep = 0; rep < reps; rep++) {
                tmass_real u[9], f[9];
                for (i = 0; i < 3 * (c + 1); i++) u[i] = (tmass_real)(i % 3 == 2 ? -0.001 * (1 + rep % 7) : 0);
                err |= tmass_qs_update(qs, candidates + 5 * c, u, c + 1, f);
            }
            t[r] = (tm_now() - t0) / reps;
        }
        qsort(t, 9, sizeof t[0], tm_cmp);
        update_seconds[c] = t[4];
    }
    tmass_qs_destroy(qs);
    tm_destroy(v);
    return err;
}

#define TM_ALL ((1u << BENCH_EXPLICIT_EULER) | (1u << BENCH_SEMI_IMPLICIT_EULER) | (1u << BENCH_RK4) | \
                (1u << BENCH_IMPLICIT_EULER) | (1u << BENCH_STATIC) | (1u << BENCH_BDF2))

static const bench_model tm_models[] = {
    {"tensormass", "linear", "linear", BENCH_PRECISION, TM_ALL, 0, 1, "tet", tm_create_tensor, tm_destroy, tm_dof,
     tm_node_count, tm_rest, tm_position, tm_pin, tm_release, tm_set_gravity, tm_solve_static, tm_step, tm_forces,
     tm_cut, tm_elements, tm_bytes_tensor, tm_kernel_tensor, tm_haptic, tm_probe, NULL},
    {"tensormass", "springs", "springs", BENCH_PRECISION, TM_ALL, 1, 1, "tet", tm_create_springs, tm_destroy, tm_dof,
     tm_node_count, tm_rest, tm_position, tm_pin, tm_release, tm_set_gravity, tm_solve_static, tm_step, tm_forces,
     tm_cut, tm_elements, tm_bytes_springs, tm_kernel_springs, NULL, tm_probe, NULL},
};

/* >>coarse-rows (issue 21): tensormass.h's implicit steps with and without the coarse
   correction (desc.implicit_coarse), on heml's coarse scenes (bench/model_heml.c
   >>coarse-rows: R3's beam at E = 1 kPa, 1 MPa, 10 MPa loaded by g = 0.01 E / 1 MPa, R1's
   steel beam under its own weight; dt = 1 ms .. 1 s; implicit Euler and BDF2; `steps`
   steps from rest, each mode on its own model, interleaved, best of `repeats`). The
   model is linear: one CG solve a step (CG tolerance 1e-9 in double, tm_create). */
static int tm_coarse_run(const bench_body *b, tmass_integrator integrator, double dt, int mode, int steps,
                         double (*clock_s)(void), bench_coarse_row *row)
{
    void *v = NULL;
    tm_sim *s;
    double t0, cg = 0, fc = 0;
    int k, err = tm_create(b, TMASS_TENSOR_MASS, &v);
    if (err) return err;
    s = (tm_sim *)v;
    s->m->implicit_coarse = mode; /* (the arrays exist: created with the default, 0) */
    row->dof = 3 * s->nodes;
    t0 = clock_s();
    for (k = 0; k < steps && !err; k++) {
        const tmass_stats *st;
        err = tmass_step_ex(s->m, (tmass_real)dt, integrator);
        st = tmass_last_stats(s->m);
        cg += st->cg_iterations, fc += st->coarse_factors;
    }
    t0 = (clock_s() - t0) / steps;
    if (row->seconds_per_step == 0 || t0 < row->seconds_per_step) row->seconds_per_step = t0;
    row->cg_per_step = cg / steps, row->newton_per_step = 1, row->factors_per_step = fc / steps;
    row->code = err;
    tm_destroy(v);
    return 0;
}

#ifdef BENCH_FLOAT
#define BENCH_COARSE_ROWS bench_tensormass_coarse_rows_float
#else
#define BENCH_COARSE_ROWS bench_tensormass_coarse_rows_double
#endif
int BENCH_COARSE_ROWS(int quick, double (*clock_s)(void), bench_coarse_row *rows, int max);
int BENCH_COARSE_ROWS(int quick, double (*clock_s)(void), bench_coarse_row *rows, int max)
{
    static const double youngs[3] = {1e3, 1e6, 1e7}, dts[4] = {1e-3, 1e-2, 0.1, 1.0};
    static const tmass_integrator integrators[2] = {TMASS_IMPLICIT_EULER, TMASS_BDF2};
    int scene, e, d, it, mode, rep, n = 0, k = quick ? 1 : 2, steps = quick ? 2 : 6, repeats = quick ? 1 : 2;
    for (scene = 0; scene < 2; scene++)
        for (e = 0; e < (scene ? 1 : 3); e++)
            for (d = 0; d < 4; d++)
                for (it = 0; it < 2; it++) {
                    bench_body b;
                    if (n + 3 > max) return n;
                    memset(&b, 0, sizeof b);
                    b.clamp = 1;
                    b.poisson = 0.3;
                    if (scene) {
                        b.size[0] = 16, b.size[1] = b.size[2] = 0.5;
                        b.cells[0] = 32 * k, b.cells[1] = b.cells[2] = k;
                        b.young = 200e9, b.density = 7800, b.gravity[2] = -9.81;
                    } else {
                        b.size[0] = 1, b.size[1] = b.size[2] = 0.1;
                        b.cells[0] = 20 * k, b.cells[1] = b.cells[2] = 2 * k;
                        b.young = youngs[e], b.density = 1000, b.gravity[2] = -0.01 * youngs[e] / 1e6;
                    }
                    for (mode = 0; mode < 3; mode++) {
                        bench_coarse_row *r = rows + n + mode;
                        memset(r, 0, sizeof *r);
                        r->scene = scene ? "R1 steel" : "R3 beam";
                        r->integrator = it ? "bdf2" : "implicit-euler";
                        r->young = b.young, r->dt = dts[d], r->mode = mode - 1;
                    }
                    for (rep = 0; rep < repeats; rep++)
                        for (mode = 0; mode < 3; mode++)
                            if (tm_coarse_run(&b, integrators[it], dts[d], mode - 1, steps, clock_s, rows + n + mode))
                                rows[n + mode].code = -1;
                    n += 3;
                }
    return n;
}

const bench_model *BENCH_TABLE(int *count);
const bench_model *BENCH_TABLE(int *count)
{
    *count = (int)(sizeof tm_models / sizeof tm_models[0]);
    return tm_models;
}
