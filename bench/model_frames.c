/* model_frames.c - bench adapter of frames.h: 6-DoF frames at the nodes of a hexahedral
   grid (trilinear, 8 sub-cell samples a cell) or of the bench's tetrahedral mesh
   (barycentric, one sample a tet), St Venant-Kirchhoff or Neo-Hookean. The bench's "nodes"
   are the frames. Compiled twice by the Makefile, in double and with -DBENCH_FLOAT. */
#define _POSIX_C_SOURCE 199309L
#ifdef BENCH_FLOAT
#define FRM_REAL float
#define BENCH_TABLE bench_models_frames_float
#define BENCH_PRECISION "float"
#else
#define BENCH_TABLE bench_models_frames_double
#define BENCH_PRECISION "double"
#endif
#define FRM_STATIC
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
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

typedef struct fr_sim {
    frm_model *m;
    int frames, prepared; /* prepared: the stiffness is linearised at the current state */
    int integrator;       /* frm_integrator of the model (FRM_IMPLICIT_EULER at creation) */
    double *rest;         /* 3 per frame, with the offset, in double */
    frm_real *v, *out;    /* K*v kernel vectors, 6 per frame */
    int *elements, element_count, hex; /* the mesh (frame indices), for the point probe */
    frm_probe *probe;     /* the last probed point (fr_probe) */
    double probe_at[3];
} fr_sim;

/* Frames and samples of the body: hexahedral (8 sub-cell samples a cell) or tetrahedral
   (the centroid of each tet); node coordinates in double, copied to frm_real. */
static int fr_sampling(const bench_body *b, int hex, frm_sampling *s, double **rest, int **elements,
                       int *element_count)
{
    frm_real *x;
    double *nodes;
    int n, i, err;
    if (hex) {
        hexmesh mesh;
        double lo[3], hi[3];
        for (i = 0; i < 3; i++) {
            lo[i] = (i ? -0.5 * b->size[i] : 0) + b->offset[i];
            hi[i] = (i ? 0.5 * b->size[i] : b->size[0]) + b->offset[i];
        }
        if (hexmesh_grid(&mesh, lo, hi, b->cells[0], b->cells[1], b->cells[2])) return FRM_ERR_ALLOC;
        n = mesh.node_count;
        x = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)n);
        if (!x) return hexmesh_free(&mesh), FRM_ERR_ALLOC;
        bench_to_reals(mesh.nodes, x, 3 * n);
        err = frm_sampling_hexes(s, x, n, mesh.hexes, mesh.hex_count, 2, FRM_QUADRATURE_SUBCELL, NULL);
        nodes = mesh.nodes;
        *elements = mesh.hexes;
        *element_count = mesh.hex_count;
    } else {
        tetmesh mesh;
        if (bench_body_mesh(b, &mesh)) return FRM_ERR_ALLOC;
        if (getenv("BENCH_SHUFFLE_TETS")) { /* measurements only: the tetrahedra in a shuffled order
                                               (fixed seed), so no grid order is left to use */
            unsigned seed = 12345u;
            for (i = mesh.tet_count - 1; i > 0; i--) {
                int j, t[4];
                seed = seed * 1664525u + 1013904223u;
                j = (int)((seed >> 8) % (unsigned)(i + 1));
                memcpy(t, mesh.tets + 4 * i, sizeof t);
                memcpy(mesh.tets + 4 * i, mesh.tets + 4 * j, sizeof t);
                memcpy(mesh.tets + 4 * j, t, sizeof t);
            }
        }
        n = mesh.node_count;
        x = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)n);
        if (!x) return tetmesh_free(&mesh), FRM_ERR_ALLOC;
        bench_to_reals(mesh.nodes, x, 3 * n);
        err = frm_sampling_tets(s, x, n, mesh.tets, mesh.tet_count, 1, NULL, NULL);
        nodes = mesh.nodes;
        *elements = mesh.tets;
        *element_count = mesh.tet_count;
    }
    free(x);
    if (err) {
        free(nodes);
        free(*elements);
        *elements = NULL;
        return err;
    }
    *rest = nodes;
    return 0;
}

/* vol: the volumetric treatment (issue 13): 0 none, 1 FRM_VOLUMETRIC_CELLS (hexahedra: a
   hexahedral cell; tetrahedra: the 5 tetrahedra of a grid cell, the bench's TETMESH_SPLIT5
   mesh emits them cell by cell), 2 FRM_VOLUMETRIC_FRAMES (nodal averaging), 3
   FRM_VOLUMETRIC_PATCHES (patches the library builds from the neighbour table; the
   environment variable BENCH_PATCH_SIZE sets desc.volumetric_patch_size for measurements) */
static int fr_create_vol(const bench_body *b, int hex, frm_law law, int vol, void **out);
static int fr_create(const bench_body *b, int hex, frm_law law, void **out) { return fr_create_vol(b, hex, law, 0, out); }

static int fr_create_vol(const bench_body *b, int hex, frm_law law, int vol, void **out)
{
    frm_sampling smp;
    frm_desc d = frm_model_default_desc();
    fr_sim *s;
    double *rest = NULL;
    int i, err;
    *out = NULL;
    if (b->exclude) return BENCH_UNSUPPORTED; /* frames do not cut */
    int *elements = NULL, element_count = 0;
    err = fr_sampling(b, hex, &smp, &rest, &elements, &element_count);
    if (err) return err;
    s = (fr_sim *)calloc(1, sizeof *s);
    if (s) {
        s->v = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)smp.frame_count);
        s->out = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)smp.frame_count);
    }
    if (!s || !s->v || !s->out) {
        if (s) free(s->v), free(s->out);
        free(s);
        free(rest);
        free(elements);
        frm_sampling_free(&smp);
        return FRM_ERR_ALLOC;
    }
    frm_sampling_apply(&smp, &d);
    d.material.law = law;
    d.material.young_modulus = (frm_real)b->young;
    d.material.poisson_ratio = (frm_real)b->poisson;
    d.material.density = (frm_real)b->density;
    d.mass_damping = (frm_real)b->damping;
    for (i = 0; i < 3; i++) d.gravity[i] = (frm_real)b->gravity[i];
    d.cg_max_iterations = 20000; /* stiff slender beams need many CG iterations */
    if (vol == 1 && !hex) /* macro-cells: the 5 tetrahedra of each grid cell */
        for (i = 0; i < smp.sample_count; i++) smp.sample_cells[i] = i / 5;
    d.volumetric = vol == 1   ? FRM_VOLUMETRIC_CELLS
                   : vol == 2 ? FRM_VOLUMETRIC_FRAMES
                   : vol == 3 ? FRM_VOLUMETRIC_PATCHES
                              : FRM_VOLUMETRIC_NONE;
    if (vol == 3 && getenv("BENCH_PATCH_SIZE")) d.volumetric_patch_size = atoi(getenv("BENCH_PATCH_SIZE"));
    err = frm_model_create(&d, &s->m);
    frm_sampling_free(&smp);
    if (err) {
        free(s->v), free(s->out), free(s), free(rest), free(elements);
        return err;
    }
    s->frames = frm_model_frame_count(s->m);
    s->rest = rest;
    s->elements = elements;
    s->element_count = element_count;
    s->hex = hex;
    bench_kernel_direction(s->v, 6 * s->frames);
    if (b->clamp)
        for (i = 0; i < s->frames; i++)
            if (bench_body_clamped(b, s->rest, i)) frm_model_fix_frame(s->m, i);
    *out = s;
    return 0;
}

static int fr_create_svk_hex(const bench_body *b, void **out) { return fr_create(b, 1, FRM_LAW_SVK, out); }
static int fr_create_nh_hex(const bench_body *b, void **out) { return fr_create(b, 1, FRM_LAW_NEO_HOOKEAN, out); }
static int fr_create_svk_tet(const bench_body *b, void **out) { return fr_create(b, 0, FRM_LAW_SVK, out); }
static int fr_create_nh_tet(const bench_body *b, void **out) { return fr_create(b, 0, FRM_LAW_NEO_HOOKEAN, out); }
#ifndef BENCH_FLOAT
static int fr_create_svk_hex_cells(const bench_body *b, void **out) { return fr_create_vol(b, 1, FRM_LAW_SVK, 1, out); }
static int fr_create_svk_tet_cells(const bench_body *b, void **out) { return fr_create_vol(b, 0, FRM_LAW_SVK, 1, out); }
static int fr_create_svk_tet_patches(const bench_body *b, void **out) { return fr_create_vol(b, 0, FRM_LAW_SVK, 3, out); }
#endif

static void fr_destroy(void *v)
{
    fr_sim *s = (fr_sim *)v;
    if (!s) return;
    frm_probe_destroy(s->probe);
    frm_model_destroy(s->m);
    free(s->rest), free(s->v), free(s->out), free(s->elements), free(s);
}

static int fr_dof(void *v) { return 6 * ((fr_sim *)v)->frames; }
static int fr_node_count(void *v) { return ((fr_sim *)v)->frames; }

static void fr_rest(void *v, int i, double p[3]) { bench_rest_position(((fr_sim *)v)->rest, i, p); }

static void fr_position(void *v, int i, double p[3])
{
    const frm_real *x = frm_model_positions(((fr_sim *)v)->m);
    int k;
    for (k = 0; k < 3; k++) p[k] = (double)x[3 * i + k];
}

/* Unit quaternion (x, y, z, w) of a rotation matrix (row-major), largest-component form. */
static void fr_quaternion(const double *R, frm_real q[4])
{
    double t = R[0] + R[4] + R[8], x, y, z, w, r;
    if (t > 0) {
        r = sqrt(1 + t) * 2;
        w = 0.25 * r, x = (R[7] - R[5]) / r, y = (R[2] - R[6]) / r, z = (R[3] - R[1]) / r;
    } else if (R[0] > R[4] && R[0] > R[8]) {
        r = sqrt(1 + R[0] - R[4] - R[8]) * 2;
        w = (R[7] - R[5]) / r, x = 0.25 * r, y = (R[1] + R[3]) / r, z = (R[2] + R[6]) / r;
    } else if (R[4] > R[8]) {
        r = sqrt(1 + R[4] - R[0] - R[8]) * 2;
        w = (R[2] - R[6]) / r, x = (R[1] + R[3]) / r, y = 0.25 * r, z = (R[5] + R[7]) / r;
    } else {
        r = sqrt(1 + R[8] - R[0] - R[4]) * 2;
        w = (R[3] - R[1]) / r, x = (R[2] + R[6]) / r, y = (R[5] + R[7]) / r, z = 0.25 * r;
    }
    r = 1 / sqrt(x * x + y * y + z * z + w * w);
    q[0] = (frm_real)(x * r), q[1] = (frm_real)(y * r), q[2] = (frm_real)(z * r), q[3] = (frm_real)(w * r);
}

static int fr_pin(void *v, int i, const double u[3], const double *rotation)
{
    fr_sim *s = (fr_sim *)v;
    frm_real p[3], q[4] = {0, 0, 0, 1};
    int k;
    for (k = 0; k < 3; k++) p[k] = (frm_real)(s->rest[3 * i + k] + u[k]);
    if (rotation) fr_quaternion(rotation, q);
    s->prepared = 0;
    return frm_model_drive_frame(s->m, i, p, q);
}

static int fr_release(void *v, int i) { return frm_model_release_frame(((fr_sim *)v)->m, i); }

static int fr_set_gravity(void *v, const double g[3])
{
    frm_real w[3];
    bench_to_reals(g, w, 3);
    return frm_model_set_gravity(((fr_sim *)v)->m, w);
}

static int fr_solve_static(void *v)
{
    ((fr_sim *)v)->prepared = 0;
    return frm_model_solve_static(((fr_sim *)v)->m);
}

static int fr_step(void *v, double dt, int integrator)
{
    frm_integrator want = integrator == BENCH_BDF2 ? FRM_BDF2 : FRM_IMPLICIT_EULER;
    fr_sim *s = (fr_sim *)v;
    if (integrator != BENCH_IMPLICIT_EULER && integrator != BENCH_BDF2) return BENCH_UNSUPPORTED;
    if (s->integrator != (int)want) { /* switching restarts BDF2's history */
        int err = frm_model_set_integrator(s->m, want);
        if (err) return err;
        s->integrator = (int)want;
    }
    s->prepared = 0;
    return frm_model_step_ex(((fr_sim *)v)->m, (frm_real)dt);
}

static int fr_forces(void *v, double *f)
{
    fr_sim *s = (fr_sim *)v;
    const frm_real *g = NULL;
    int i, k, err = frm_model_forces(s->m, &g);
    for (i = 0; !err && i < s->frames; i++)
        for (k = 0; k < 3; k++) f[3 * i + k] = g[6 * i + k];
    return err;
}

/* The displacement at rest point p, through a probe on the sampling's mesh made at the
   first call for p. */
static int fr_probe(void *v, const double p[3], double u[3])
{
    fr_sim *s = (fr_sim *)v;
    frm_real q[3], r[3];
    int k, err;
    if (!s->probe || memcmp(p, s->probe_at, sizeof s->probe_at)) {
        frm_probe_desc d = frm_probe_default_desc();
        frm_probe_destroy(s->probe);
        s->probe = NULL;
        d.kind = s->hex ? FRM_PROBE_HEXES : FRM_PROBE_TETS;
        d.elements = s->elements;
        d.element_count = s->element_count;
        for (k = 0; k < 3; k++) q[k] = (frm_real)p[k];
        err = frm_probe_create(s->m, &d, q, 1, &s->probe);
        if (err) return err;
        memcpy(s->probe_at, p, sizeof s->probe_at);
    }
    err = frm_probe_displacements(s->probe, s->m, r);
    for (k = 0; k < 3; k++) u[k] = (double)r[k];
    return err;
}

static double fr_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Mapped points: one point between each element's centroid and each of its corners (8 a
   hexahedron, 4 a tetrahedron), as a render mesh's vertices would sit; then the median
   time of each evaluation over calls lasting 20 ms at least. */
static int fr_mapped(void *v, int *points, double ns[3])
{
    fr_sim *s = (fr_sim *)v;
    frm_probe_desc d = frm_probe_default_desc();
    frm_probe *p = NULL;
    int per = s->hex ? 8 : 4, count = per * s->element_count, e, a, k, what, err;
    frm_real *pts = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)count), *out, *q6;
    if (!pts) return FRM_ERR_ALLOC;
    for (e = 0; e < s->element_count; e++) {
        double c[3] = {0, 0, 0};
        const int *el = s->elements + per * e;
        for (a = 0; a < per; a++)
            for (k = 0; k < 3; k++) c[k] += s->rest[3 * el[a] + k] / per;
        for (a = 0; a < per; a++)
            for (k = 0; k < 3; k++) pts[3 * (per * e + a) + k] = (frm_real)(0.5 * c[k] + 0.5 * s->rest[3 * el[a] + k]);
    }
    d.kind = s->hex ? FRM_PROBE_HEXES : FRM_PROBE_TETS;
    d.elements = s->elements;
    d.element_count = s->element_count;
    err = frm_probe_create(s->m, &d, pts, count, &p);
    out = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)count);
    q6 = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)s->frames);
    if (!err && (!out || !q6)) err = FRM_ERR_ALLOC;
    for (k = 0; !err && k < 3 * count; k++) pts[k] = (frm_real)(k % 3 == 2 ? -1 : 0); /* the forces: 1 N down */
    for (what = 0; !err && what < 3; what++) {
        double t[5];
        int r, calls = 1, c;
        for (;;) {
            double t0 = fr_now();
            for (c = 0; c < calls; c++)
                err |= what == 0 ? frm_probe_positions(p, s->m, out)
                                 : what == 1 ? frm_probe_velocities(p, s->m, out)
                                             : frm_probe_jacobian_transpose(p, s->m, pts, q6, 0);
            if (fr_now() - t0 >= 0.02 || calls > (1 << 24)) break;
            calls *= 2;
        }
        for (r = 0; r < 5; r++) {
            double t0 = fr_now();
            for (c = 0; c < calls; c++)
                err |= what == 0 ? frm_probe_positions(p, s->m, out)
                                 : what == 1 ? frm_probe_velocities(p, s->m, out)
                                             : frm_probe_jacobian_transpose(p, s->m, pts, q6, 0);
            t[r] = (fr_now() - t0) / calls;
        }
        for (r = 1; r < 5; r++) /* the median of five */
            for (c = r; c > 0 && t[c] < t[c - 1]; c--) {
                double x = t[c];
                t[c] = t[c - 1], t[c - 1] = x;
            }
        ns[what] = 1e9 * t[2] / count;
    }
    *points = count;
    frm_probe_destroy(p);
    free(pts), free(out), free(q6);
    return err;
}

static double fr_elements(void *v) { return (double)frm_model_pair_count(((fr_sim *)v)->m); }

static double fr_kernel_bytes(void *v, int kernel)
{
    fr_sim *s = (fr_sim *)v;
    double pairs = (double)frm_model_pair_count(s->m);
    const int *row_start = NULL, *cols = NULL;
    if (kernel == BENCH_KERNEL_FORCE) return pairs * (double)FRM_FORCE_BYTES_PER_PAIR;
    if (kernel == BENCH_KERNEL_KV) return pairs * (double)FRM_KV_BYTES_PER_PAIR;
    frm_model_stiffness_blocks(s->m, &row_start, &cols);
    return row_start ? (double)row_start[s->frames] * (double)FRM_KV_BYTES_PER_BLOCK : 0;
}

/* K*v in pair mode (matrix-free) or block mode (assembled 6x6 blocks); the
   linearisation is prepared once per state, outside the timed calls after the first. */
static int fr_kernel(void *v, int kernel)
{
    fr_sim *s = (fr_sim *)v;
    const frm_real *g;
    int err = 0;
    if (kernel == BENCH_KERNEL_FORCE) return frm_model_forces(s->m, &g);
    if (kernel != BENCH_KERNEL_KV && kernel != BENCH_KERNEL_KV_BLOCKS) return BENCH_UNSUPPORTED;
    if (s->prepared != kernel) {
        err = frm_model_set_stiffness_mode(s->m, kernel == BENCH_KERNEL_KV ? FRM_STIFFNESS_PAIRS : FRM_STIFFNESS_BLOCKS);
        if (!err) err = kernel == BENCH_KERNEL_KV ? frm_model_prepare_stiffness(s->m) : frm_model_assemble_stiffness(s->m);
        if (err) return err;
        s->prepared = kernel;
    }
    return frm_model_apply_stiffness(s->m, s->v, s->out, 1);
}

#define FR_ALL ((1u << BENCH_IMPLICIT_EULER) | (1u << BENCH_BDF2) | (1u << BENCH_STATIC))
#define FR_FUNCTIONS                                                                                          \
    fr_destroy, fr_dof, fr_node_count, fr_rest, fr_position, fr_pin, fr_release, fr_set_gravity, fr_solve_static, \
        fr_step, fr_forces, NULL, fr_elements, fr_kernel_bytes, fr_kernel, NULL, fr_probe, fr_mapped

static const bench_model fr_models[] = {
    {"frames", "svk hex8", "svk", BENCH_PRECISION, FR_ALL, 1, 1, "pair", fr_create_svk_hex, FR_FUNCTIONS},
    {"frames", "nh hex8", "neo-hookean", BENCH_PRECISION, FR_ALL, 1, 0, "pair", fr_create_nh_hex, FR_FUNCTIONS},
    {"frames", "svk tet4", "svk", BENCH_PRECISION, FR_ALL, 1, 1, "pair", fr_create_svk_tet, FR_FUNCTIONS},
    {"frames", "nh tet4", "neo-hookean", BENCH_PRECISION, FR_ALL, 1, 0, "pair", fr_create_nh_tet, FR_FUNCTIONS},
#ifndef BENCH_FLOAT /* issue 13: the volumetric treatment, Poisson rows only (primary -1), double; the
                       nodal averaging (vol = 2) of tetrahedral frames measured +8.8, -4.2, -7.1 %
                       at nu = 0.3, 0.49, 0.499 (k = 3), left out for the bench's time; vol=patches:
                       FRM_VOLUMETRIC_PATCHES, the cells built by the library from any mesh */
    {"frames", "svk hex8 vol=cells", "svk", BENCH_PRECISION, FR_ALL, 1, -1, "pair", fr_create_svk_hex_cells, FR_FUNCTIONS},
    {"frames", "svk tet4 vol=cells5", "svk", BENCH_PRECISION, FR_ALL, 1, -1, "pair", fr_create_svk_tet_cells, FR_FUNCTIONS},
    {"frames", "svk tet4 vol=patches", "svk", BENCH_PRECISION, FR_ALL, 1, -1, "pair", fr_create_svk_tet_patches, FR_FUNCTIONS},
#endif
};

const bench_model *BENCH_TABLE(int *count);
const bench_model *BENCH_TABLE(int *count)
{
    *count = (int)(sizeof fr_models / sizeof fr_models[0]);
    return fr_models;
}

/* >>chain (issue 15): the block-tridiagonal solver's factor + solve per block count and one
   inverse control step of the 16-vertebra tapered arm of examples/frames_soft_arm.c, the
   median of 5 batches of repeated calls (seconds each, measured by the caller's clock). Fills
   up to 8 rows: BTD at 10, 100, 1,000, 10,000 blocks (factor, solve), then the arm. Returns
   the row count. */
#ifdef BENCH_FLOAT
#define BENCH_CHAIN_ROWS bench_chain_rows_float
#else
#define BENCH_CHAIN_ROWS bench_chain_rows_double
#endif
int BENCH_CHAIN_ROWS(int quick, double (*clock_s)(void), const char **names, double *sizes, double *seconds);
static double fr_median5(double *t)
{
    int i, j;
    for (i = 0; i < 5; i++)
        for (j = i + 1; j < 5; j++)
            if (t[j] < t[i]) {
                double x = t[i];
                t[i] = t[j], t[j] = x;
            }
    return t[2];
}
int BENCH_CHAIN_ROWS(int quick, double (*clock_s)(void), const char **names, double *sizes, double *seconds)
{
    static const int counts[4] = {10, 100, 1000, 10000};
    int rows = 0, s, i, k, r;
    for (s = 0; s < (quick ? 3 : 4); s++) {
        int n = counts[s], reps = 20000 / n + 1;
        frm_real *d = (frm_real *)malloc(sizeof(frm_real) * 36 * (size_t)n), *l = (frm_real *)malloc(sizeof(frm_real) * 36 * (size_t)n);
        frm_real *f = (frm_real *)malloc(sizeof(frm_real) * 72 * (size_t)n), *b = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)n);
        double tf[5], ts[5];
        if (!d || !l || !f || !b) {
            free(d), free(l), free(f), free(b);
            return rows;
        }
        for (i = 0; i < n; i++) /* a diagonally dominant chain */
            for (k = 0; k < 36; k++) {
                d[36 * i + k] = (frm_real)(k % 7 == 0 ? 10.0 : 0.1);
                l[36 * i + k] = (frm_real)((k * 7) % 5 == 0 ? 0.5 : 0.0);
            }
        for (r = 0; r < 5; r++) {
            double t0 = clock_s(), t1, t2;
            for (k = 0; k < reps; k++) frm_btd_factor(n, d, l, f, NULL);
            t1 = clock_s();
            for (k = 0; k < reps; k++) {
                for (i = 0; i < 6 * n; i++) b[i] = 1;
                frm_btd_solve(n, f, 1, b);
            }
            t2 = clock_s();
            tf[r] = (t1 - t0) / reps, ts[r] = (t2 - t1) / reps;
        }
        names[rows] = "btd factor", sizes[rows] = n, seconds[rows++] = fr_median5(tf);
        names[rows] = "btd solve", sizes[rows] = n, seconds[rows++] = fr_median5(ts);
        free(d), free(l), free(f), free(b);
    }
    { /* the arm of examples/frames_soft_arm.c: one inverse step per 20 ms along the circle */
        enum { NA = 17 };
        frm_real pos[3 * NA], comp[36 * NA], mass[NA], inertia[NA], pts[3 * 2 * NA * 3], tip[3], target[3];
        int pf[2 * NA * 3], np = 0, a, steps = quick ? 20 : 100;
        frm_actuator act[6];
        frm_chain_desc cd = frm_chain_default_desc();
        frm_chain *c = NULL;
        double L = 0.5, E = 2e7, t[5], pi = 3.14159265358979323846;
        for (i = 0; i < NA; i++) {
            double rr = 0.03 - 0.015 * i / (NA - 1.0), rm = 0.03 - 0.015 * (i + 0.5) / (NA - 1.0), l = L / (NA - 1);
            double A = pi * rm * rm, I = pi * rm * rm * rm * rm / 4, G = E / 2.9;
            pos[3 * i] = (frm_real)(L * i / (NA - 1)), pos[3 * i + 1] = pos[3 * i + 2] = 0;
            mass[i] = (frm_real)(1100 * pi * rr * rr * l), inertia[i] = (frm_real)(mass[i] * rr * rr / 2);
            for (k = 0; k < 36; k++) comp[36 * i + k] = 0;
            comp[36 * i] = (frm_real)(l / (E * A));
            comp[36 * i + 7] = comp[36 * i + 14] = (frm_real)(l * l * l / (3 * E * I));
            comp[36 * i + 21] = (frm_real)(l / (G * 2 * I));
            comp[36 * i + 28] = comp[36 * i + 35] = (frm_real)(l / (E * I));
            comp[36 * i + 11] = comp[36 * i + 31] = (frm_real)(l * l / (2 * E * I));
            comp[36 * i + 16] = comp[36 * i + 26] = (frm_real)(-l * l / (2 * E * I));
        }
        for (a = 0; a < 6; a++) {
            int last = a < 3 ? 8 : 16;
            double ang = 2 * pi * (a % 3) / 3 + (a < 3 ? 0 : pi / 3);
            memset(&act[a], 0, sizeof act[a]);
            act[a].kind = FRM_ACTUATOR_CABLE, act[a].point_count = last + 1, act[a].point_frames = pf + np;
            act[a].points = pts + 3 * np, act[a].max_effort = 300;
            for (k = 0; k <= last; k++) {
                double rr = 0.8 * (0.03 - 0.015 * k / (NA - 1.0));
                pf[np + k] = k, pts[3 * (np + k)] = pos[3 * k];
                pts[3 * (np + k) + 1] = (frm_real)(rr * cos(ang)), pts[3 * (np + k) + 2] = (frm_real)(rr * sin(ang));
            }
            np += last + 1;
        }
        cd.frame_count = NA, cd.positions = pos, cd.compliances = comp, cd.masses = mass, cd.inertias = inertia;
        cd.actuators = act, cd.actuator_count = 6;
        if (frm_chain_create(&cd, &c) || frm_chain_solve_static(c)) {
            frm_chain_destroy(c);
            return rows;
        }
        frm_chain_effector(c, tip, NULL);
        for (r = 0; r < 5; r++) {
            double t0 = clock_s();
            for (k = 1; k <= steps; k++) {
                double ang = 0.025 * 0.02 * (k + r * steps) / 0.06;
                target[0] = (frm_real)(tip[0] - 0.01), target[1] = (frm_real)(tip[1] + 0.06 * cos(ang));
                target[2] = (frm_real)(tip[2] + 0.06 * sin(ang));
                frm_chain_inverse_step(c, target, 1e-4, NULL);
            }
            t[r] = (clock_s() - t0) / steps;
        }
        frm_chain_destroy(c);
        names[rows] = "arm inverse step", sizes[rows] = 16, seconds[rows++] = fr_median5(t);
    }
    return rows;
}
