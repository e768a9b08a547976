/* model_glue.c - the bench's coupled scenes (issue 14): a heml.h half beam glued to a
   frames.h half beam by examples/glue.h's stiff coupling. Not a bench_model (a coupled
   scene has two models); bench.c's kernels part calls bench_glue_rows_* and writes the
   rows: the coupled step's time and its split by model on the soft beam (REFERENCES R3's
   1 x 0.1 x 0.1 m, E = 1 MPa, dt = 10 ms), and R1's tip error glued against each model
   alone (Timoshenko 0.15059 m). Compiled in double and float like the adapters; the float
   build reports nothing (the coupled solves fail in float: frames.h LIMITS). */
#ifdef BENCH_FLOAT
#define FRM_REAL float
#define HEML_REAL float
#define BENCH_GLUE_ROWS bench_glue_rows_float
#else
#define BENCH_GLUE_ROWS bench_glue_rows_double
#endif
#define FRM_STATIC
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#define HEML_STATIC
#define HEML_IMPLEMENTATION
#include "../heml.h"
#define TETMESH_STATIC
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "../examples/glue.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

int BENCH_GLUE_ROWS(int quick, double *v);

/* CPU seconds (clock), like examples/glue.h's split by model: on a shared machine wall time
   counts the neighbours */
static double glue_now(void) { return (double)clock() / CLOCKS_PER_SEC; }

/* A frames half beam [0, lx] x [0, b]^2, nx x nb x nb hexahedral cells (8 samples a cell),
   Neo-Hookean, clamped at x = 0; its hexahedral probe description (cells in *hexes). */
static int glue_frames(int nx, int nb, double lx, double b, double E, double rho, frm_model **m, frm_probe_desc *pd,
                       int **hexes)
{
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    int nn = (nx + 1) * (nb + 1) * (nb + 1), nc = nx * nb * nb, i, c, a, err;
    frm_real *x = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)nn);
    int *hex = (int *)malloc(sizeof(int) * 8 * (size_t)nc);
    for (i = 0; i < nn; i++) {
        x[3 * i] = (frm_real)(lx / nx * (i % (nx + 1)));
        x[3 * i + 1] = (frm_real)(b / nb * (i / (nx + 1) % (nb + 1)));
        x[3 * i + 2] = (frm_real)(b / nb * (i / ((nx + 1) * (nb + 1))));
    }
    for (c = 0; c < nc; c++)
        for (a = 0; a < 8; a++)
            hex[8 * c + a] = (c % nx + (a & 1)) + (nx + 1) * ((c / nx % nb + (a >> 1 & 1)) + (nb + 1) * (c / (nx * nb) + (a >> 2)));
    err = frm_sampling_hexes(&s, x, nn, hex, nc, 2, FRM_QUADRATURE_SUBCELL, NULL);
    free(x);
    if (err) {
        free(hex);
        return err;
    }
    frm_sampling_apply(&s, &d);
    d.material.law = FRM_LAW_NEO_HOOKEAN;
    d.material.young_modulus = (frm_real)E;
    d.material.density = (frm_real)rho;
    d.time_step = (frm_real)0.01;
    err = frm_model_create(&d, m);
    frm_sampling_free(&s);
    if (err) {
        free(hex);
        return err;
    }
    for (i = 0; i < nn; i++)
        if (i % (nx + 1) == 0) frm_model_fix_frame(*m, i);
    frm_model_set_solver(*m, (frm_real)1e-10, 20000, (frm_real)1e-10, 50);
    *hexes = hex;
    *pd = frm_probe_default_desc();
    pd->kind = FRM_PROBE_HEXES;
    pd->elements = hex;
    pd->element_count = nc;
    return 0;
}

static int glue_heml(int nx, int nb, double x0, double lx, double b, double E, double rho, heml_model **m)
{
    tetmesh tm;
    heml_desc d = heml_default_desc();
    const double lo[3] = {0, 0, 0};
    double hi[3];
    heml_real *x;
    int i, err;
    hi[0] = lx, hi[1] = hi[2] = b;
    if (tetmesh_box(&tm, lo, hi, nx, nb, nb, TETMESH_SPLIT6) != TETMESH_OK) return -1;
    x = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)tm.node_count);
    for (i = 0; i < 3 * tm.node_count; i++) x[i] = (heml_real)(tm.nodes[i] + (i % 3 == 0 ? x0 : 0));
    d.rest_positions = x;
    d.node_count = tm.node_count;
    d.tets = tm.tets;
    d.tet_count = tm.tet_count;
    d.material = heml_material_from_young(HEML_NEO_HOOKEAN, E, 0.3);
    d.material.density = (heml_real)rho;
    d.integrator = HEML_IMPLICIT_EULER;
    err = heml_create(&d, m);
    free(x);
    tetmesh_free(&tm);
    if (!err) heml_set_solver(*m, (heml_real)1e-10, 20000);
    return err;
}

static int *glue_face(int nx, int nb, int *count)
{
    int *v = (int *)malloc(sizeof(int) * (size_t)((nb + 1) * (nb + 1))), i;
    for (i = 0; i < (nb + 1) * (nb + 1); i++) v[i] = (nx + 1) * i;
    *count = (nb + 1) * (nb + 1);
    return v;
}

/* The z sag at (x, b/2, b/2) of a heml model or a frames model (one of them NULL). */
static double glue_sag(heml_model *h, frm_model *f, const frm_probe_desc *pd, double x, double b)
{
    double v = NAN;
    if (h) {
        heml_real pt[3], out[3] = {0, 0, 0};
        heml_probe *p;
        pt[0] = (heml_real)x, pt[1] = pt[2] = (heml_real)(b / 2);
        if (!heml_probe_create(h, pt, 1, &p)) {
            heml_probe_displacements(p, h, out);
            v = -(double)out[2];
            heml_probe_destroy(p);
        }
    } else {
        frm_real pt[3], out[3] = {0, 0, 0};
        frm_probe *p;
        pt[0] = (frm_real)x, pt[1] = pt[2] = (frm_real)(b / 2);
        if (!frm_probe_create(f, pd, pt, 1, &p)) {
            frm_probe_displacements(p, f, out);
            v = -(double)out[2];
            frm_probe_destroy(p);
        }
    }
    return v;
}

/* v: [0] ms a coupled step, [1] of it in frames, [2] in heml, [3] coupling iterations a
   step (soft beam, 20 steps of 10 ms from rest under g / 10); [4] R1 glued, [5] frames
   alone, [6] heml alone: tip error against Timoshenko, %; [7] R1's coupling iterations.
   Returns 0, or -1 (float, or a failed solve). */
int BENCH_GLUE_ROWS(int quick, double *v)
{
    frm_model *f = NULL;
    heml_model *h = NULL;
    frm_probe_desc pd;
    glue gl;
    int *hexes = NULL, *nodes, n, step, err = 0, its = 0, nx = quick ? 8 : 16;
    double t0, timo = 0.15059, rho = 31200.0 / 4;
    if (sizeof(frm_real) == sizeof(float)) return -1;
    /* the soft beam's steps */
    if (glue_frames(5, 1, 0.5, 0.1, 1e6, 1000, &f, &pd, &hexes) || glue_heml(10, 2, 0.5, 0.5, 0.1, 1e6, 1000, &h)) return -1;
    {
        frm_real g[3] = {0, 0, (frm_real)-0.981};
        heml_real gh[3] = {0, 0, (heml_real)-0.981};
        frm_model_set_gravity(f, g);
        heml_set_gravity(h, gh);
    }
    frm_model_set_solver(f, (frm_real)1e-9, 20000, (frm_real)1e-6, 50);
    heml_set_solver(h, (heml_real)1e-9, 20000);
    nodes = glue_face(10, 2, &n);
    if (glue_init_heml(&gl, h, f, &pd, nodes, n, 0.3 * 1e6 * 0.05)) return -1;
    gl.depth = GLUE_DEPTH;
    t0 = glue_now();
    for (step = 0; step < 20 && !err; step++) {
        err = glue_solve(&gl, 0.01, 1e-7, 30);
        its += gl.iterations;
    }
    v[0] = 1e3 * (glue_now() - t0) / 20;
    v[1] = 1e3 * gl.frames_seconds / 20;
    v[2] = 1e3 * gl.mesh_seconds / 20;
    v[3] = its / 20.0;
    glue_free(&gl);
    free(nodes), free(hexes);
    frm_model_destroy(f);
    heml_destroy(h);
    if (err) return -1;
    /* R1: each model alone, then glued */
    if (glue_frames(2 * nx, 2, 16, 0.5, 2e11, rho, &f, &pd, &hexes) || frm_model_solve_static(f)) return -1;
    v[5] = 100 * (glue_sag(NULL, f, &pd, 16, 0.5) / timo - 1);
    frm_model_destroy(f), free(hexes);
    if (glue_heml(2 * nx, 2, 0, 16, 0.5, 2e11, rho, &h)) return -1;
    nodes = glue_face(2 * nx, 2, &n);
    while (n--) heml_fix_node(h, nodes[n]);
    free(nodes);
    if (heml_solve_static(h)) return -1;
    v[6] = 100 * (glue_sag(h, NULL, NULL, 16, 0.5) / timo - 1);
    heml_destroy(h);
    if (glue_frames(nx, 2, 8, 0.5, 2e11, rho, &f, &pd, &hexes) || glue_heml(nx, 2, 8, 8, 0.5, 2e11, rho, &h)) return -1;
    nodes = glue_face(nx, 2, &n);
    if (glue_init_heml(&gl, h, f, &pd, nodes, n, 0.3 * 2e11 * 0.25)) return -1;
    gl.depth = GLUE_DEPTH;
    err = glue_solve(&gl, 0, 1e-6, 30);
    v[4] = 100 * (glue_sag(h, NULL, NULL, 16, 0.5) / timo - 1);
    v[7] = gl.iterations;
    glue_free(&gl);
    free(nodes), free(hexes);
    frm_model_destroy(f);
    heml_destroy(h);
    return err ? -1 : 0;
}
