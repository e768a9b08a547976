/* model_heml.c - bench adapter of heml.h: its hyperelastic laws and the mass-spring
   degenerate case. Compiled twice by the Makefile, in double and with -DBENCH_FLOAT. */
#ifdef BENCH_FLOAT
#define HEML_REAL float
#define BENCH_TABLE bench_models_heml_float
#define BENCH_PRECISION "float"
#else
#define BENCH_TABLE bench_models_heml_double
#define BENCH_PRECISION "double"
#endif
#define HEML_STATIC
#define HEML_IMPLEMENTATION
#include "../heml.h"
#define TETMESH_STATIC
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "bench.h"
#include "body_mesh.h"
#include "model_common.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct hm_sim {
    heml_model *m;
    int nodes, tets;
    int *tet_nodes;
    double *rest; /* 3n, with the offset, in double */
    heml_real *dx, *out; /* K*v kernel vectors */
    /* the CSR matrix of the tangent (BENCH_KERNEL_CSR), assembled at its first call */
    int *csr_row, *csr_col, csr_failed;
    heml_real *csr_val;
    heml_probe *probe;   /* the last probed point (hm_probe) */
    double probe_at[3];
} hm_sim;

static int hm_create(const bench_body *b, heml_law law, int nodal, void **out)
{
    tetmesh mesh;
    heml_desc d = heml_default_desc();
    hm_sim *s;
    heml_real *x;
    int i, err;
    *out = NULL;
    if (bench_body_mesh(b, &mesh)) return HEML_ERR_ALLOC;
    x = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)mesh.node_count);
    s = (hm_sim *)calloc(1, sizeof *s);
    if (s) {
        s->dx = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)mesh.node_count);
        s->out = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)mesh.node_count);
    }
    if (!x || !s || !s->dx || !s->out) {
        free(x);
        if (s) free(s->dx), free(s->out);
        free(s);
        tetmesh_free(&mesh);
        return HEML_ERR_ALLOC;
    }
    bench_to_reals(mesh.nodes, x, 3 * mesh.node_count);
    bench_kernel_direction(s->dx, 3 * mesh.node_count);
    d.rest_positions = x;
    d.node_count = mesh.node_count;
    d.tets = mesh.tets;
    d.tet_count = mesh.tet_count;
    d.material = heml_material_from_young(law, b->young, b->poisson);
    d.material.density = (heml_real)b->density;
    d.mass_damping = (heml_real)b->damping;
    for (i = 0; i < 3; i++) d.gravity[i] = (heml_real)b->gravity[i];
    d.cg_max_iterations = 20000; /* stiff slender beams need many CG iterations */
    d.nodal_pressure = nodal;
    err = heml_create(&d, &s->m);
    free(x);
    if (err) {
        free(s->dx), free(s->out), free(s);
        tetmesh_free(&mesh);
        return err;
    }
    s->nodes = mesh.node_count;
    s->tets = mesh.tet_count;
    s->tet_nodes = mesh.tets;
    s->rest = mesh.nodes;
    if (b->clamp)
        for (i = 0; i < s->nodes; i++)
            if (bench_body_clamped(b, s->rest, i)) heml_fix_node(s->m, i);
    *out = s;
    return 0;
}

static int hm_create_svk(const bench_body *b, void **out) { return hm_create(b, HEML_STVK, 0, out); }
static int hm_create_nh(const bench_body *b, void **out) { return hm_create(b, HEML_NEO_HOOKEAN, 0, out); }
static int hm_create_mr(const bench_body *b, void **out) { return hm_create(b, HEML_MOONEY_RIVLIN, 0, out); }
static int hm_create_springs(const bench_body *b, void **out) { return hm_create(b, HEML_MASS_SPRING, 0, out); }
/* Neo-Hookean with desc.nodal_pressure = 1 (average nodal pressure tetrahedra) */
static int hm_create_nh_nodal(const bench_body *b, void **out) { return hm_create(b, HEML_NEO_HOOKEAN, 1, out); }
/* Neo-Hookean with desc.nodal_pressure = 2 (the volumetric energy over pressure aggregates) */
static int hm_create_nh_nodal_agg(const bench_body *b, void **out) { return hm_create(b, HEML_NEO_HOOKEAN, 2, out); }

static void hm_destroy(void *v)
{
    hm_sim *s = (hm_sim *)v;
    if (!s) return;
    heml_probe_destroy(s->probe);
    heml_destroy(s->m);
    free(s->csr_row), free(s->csr_col), free(s->csr_val);
    free(s->tet_nodes);
    free(s->rest);
    free(s->dx);
    free(s->out);
    free(s);
}

static int hm_dof(void *v) { return 3 * ((hm_sim *)v)->nodes; }
static int hm_node_count(void *v) { return ((hm_sim *)v)->nodes; }

static void hm_rest(void *v, int i, double p[3]) { bench_rest_position(((hm_sim *)v)->rest, i, p); }

static void hm_position(void *v, int i, double p[3])
{
    hm_sim *s = (hm_sim *)v;
    bench_displaced_position(s->rest, heml_positions(s->m), heml_rest_positions(s->m), i, p);
}

static int hm_pin(void *v, int i, const double u[3], const double *rotation)
{
    heml_real w[3];
    (void)rotation;
    bench_to_reals(u, w, 3);
    return heml_set_displacement(((hm_sim *)v)->m, i, w);
}

static int hm_release(void *v, int i) { return heml_release_node(((hm_sim *)v)->m, i); }

static int hm_set_gravity(void *v, const double g[3])
{
    heml_real w[3];
    bench_to_reals(g, w, 3);
    return heml_set_gravity(((hm_sim *)v)->m, w);
}

static int hm_solve_static(void *v) { return heml_solve_static(((hm_sim *)v)->m); }

static int hm_step(void *v, double dt, int integrator)
{
    if (integrator == BENCH_SEMI_IMPLICIT_EULER) /* eq. 32 is the symplectic Euler */
        return heml_step_ex(((hm_sim *)v)->m, (heml_real)dt, HEML_SEMI_EXPLICIT_EULER);
    if (integrator == BENCH_IMPLICIT_EULER) return heml_step_ex(((hm_sim *)v)->m, (heml_real)dt, HEML_IMPLICIT_EULER);
    if (integrator == BENCH_BDF2) return heml_step_ex(((hm_sim *)v)->m, (heml_real)dt, HEML_BDF2);
    return BENCH_UNSUPPORTED;
}

static int hm_forces(void *v, double *f)
{
    hm_sim *s = (hm_sim *)v;
    const heml_real *g = heml_compute_forces(s->m);
    if (!g) return HEML_ERR_ARG;
    bench_to_doubles(g, f, 3 * s->nodes);
    return 0;
}

/* The displacement at rest point p, through a probe made at the first call for p. */
static int hm_probe(void *v, const double p[3], double u[3])
{
    hm_sim *s = (hm_sim *)v;
    heml_real q[3], r[3];
    int k, err;
    if (!s->probe || memcmp(p, s->probe_at, sizeof s->probe_at)) {
        heml_probe_destroy(s->probe);
        s->probe = NULL;
        for (k = 0; k < 3; k++) q[k] = (heml_real)p[k];
        err = heml_probe_create(s->m, q, 1, &s->probe);
        if (err) return err;
        memcpy(s->probe_at, p, sizeof s->probe_at);
    }
    err = heml_probe_displacements(s->probe, s->m, r);
    for (k = 0; k < 3; k++) u[k] = (double)r[k];
    return err;
}

static double hm_elements(void *v) { return (double)((hm_sim *)v)->tets; }

static int hm_csr_nnz(const hm_sim *s) { return s->csr_row ? s->csr_row[3 * s->nodes] : 0; }

static int hm_kernel(void *v, int kernel);

static double hm_kernel_bytes(void *v, int kernel)
{
    hm_sim *s = (hm_sim *)v;
    size_t r = 0, w = 0;
    if (kernel == BENCH_KERNEL_CSR && !s->csr_row && !s->csr_failed)
        (void)hm_kernel(v, BENCH_KERNEL_CSR); /* (assembled at its first call: its size) */
    if (kernel == BENCH_KERNEL_CSR) /* values and column indices, row starts, x read, y written */
        return (double)hm_csr_nnz(s) * (sizeof(heml_real) + sizeof(int)) + (3.0 * s->nodes + 1) * sizeof(int) +
               6.0 * s->nodes * sizeof(heml_real);
    heml_kernel_bytes(s->m, kernel == BENCH_KERNEL_MOVE || kernel == BENCH_KERNEL_ARITH ? BENCH_KERNEL_FORCE : kernel,
                      &r, &w);
    return (double)(r + w);
}

/* The differential of one block for the link directions already in b->de (heml__block_diff
   without its gathers; St Venant-Kirchhoff through the general path, so that the CSR check
   below compares two evaluations). heml__block_diff_general zeroes the nodal pressure's dp
   (this adapter called heml__diff_general with b->dp uninitialised: malloc's garbage, at
   times subnormal, entered the matrix and slowed its product 5 to 7 times). */
static void hm_block_diff(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b)
{
    if (mt->dk == HEML__DK_NH) heml__diff_nh(m, mt, blk, b);
    else heml__block_diff_general(m, mt, blk, b);
}

static int hm_int_cmp(const void *a, const void *b) { return *(const int *)a - *(const int *)b; }

/* Assembles the tangent (the differential's matrix: out = A dx) at the current state into
   CSR: rows 3 i + r, for every neighbour j of node i (itself included) the columns 3 j ..
   3 j + 2. Element columns come from the library's own differential of each block applied
   to the 12 unit directions of its tetrahedra's nodes. Not springs (their differential has
   its own kernel; no CSR row). */
static int hm_csr_build(hm_sim *s)
{
    heml_model *m = s->m;
    int n = s->nodes, i, t, a, b, blk, *deg = (int *)calloc((size_t)n + 1, sizeof(int)), *nb, *start;
    heml__blk *w = (heml__blk *)malloc(sizeof *w);
    if (!deg || !w || m->has_springs || m->has_prony) {
        free(deg), free(w);
        return BENCH_UNSUPPORTED;
    }
    for (t = 0; t < s->tets; t++)
        for (a = 0; a < 4; a++) deg[s->tet_nodes[4 * t + a]] += 4;
    start = (int *)malloc(sizeof(int) * ((size_t)n + 1));
    nb = (int *)malloc(sizeof(int) * (size_t)s->tets * 16);
    if (!start || !nb) {
        free(deg), free(w), free(start), free(nb);
        return HEML_ERR_ALLOC;
    }
    for (start[0] = 0, i = 0; i < n; i++) start[i + 1] = start[i] + deg[i], deg[i] = 0;
    for (t = 0; t < s->tets; t++)
        for (a = 0; a < 4; a++)
            for (b = 0; b < 4; b++) {
                int p = s->tet_nodes[4 * t + a];
                nb[start[p] + deg[p]++] = s->tet_nodes[4 * t + b];
            }
    for (i = 0; i < n; i++) { /* sort, unique */
        int *l = nb + start[i], c = 0, k;
        qsort(l, (size_t)deg[i], sizeof(int), hm_int_cmp);
        for (k = 0; k < deg[i]; k++)
            if (!c || l[k] != l[c - 1]) l[c++] = l[k];
        deg[i] = c;
    }
    s->csr_row = (int *)malloc(sizeof(int) * (3 * (size_t)n + 1));
    for (i = 0, t = 0; s->csr_row && i < n; i++) t += 9 * deg[i];
    s->csr_col = (int *)malloc(sizeof(int) * (size_t)t);
    s->csr_val = (heml_real *)calloc((size_t)t, sizeof(heml_real));
    if (!s->csr_row || !s->csr_col || !s->csr_val) {
        free(deg), free(w), free(start), free(nb);
        return HEML_ERR_ALLOC;
    }
    s->csr_row[0] = 0;
    for (i = 0; i < n; i++) {
        int r, k, c;
        for (r = 0; r < 3; r++) {
            int row = 3 * i + r, p = s->csr_row[row];
            for (k = 0; k < deg[i]; k++)
                for (c = 0; c < 3; c++) s->csr_col[p++] = 3 * nb[start[i] + k] + c;
            s->csr_row[row + 1] = p;
        }
    }
    for (blk = 0; blk < m->block_count; blk++) {
        const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
        const heml__mat *mt = m->mats + m->chunk_material[0];
        int ci, jn, c, k, r, valid = m->blk_valid[blk];
        for (ci = 0; ci < m->chunk_count; ci++)
            if (blk >= m->chunk_begin[ci] && blk < m->chunk_end[ci]) mt = m->mats + m->chunk_material[ci];
        heml__gather(m, idx, m->disp, w->e);
        for (jn = 0; jn < 4; jn++)
            for (c = 0; c < 3; c++) { /* unit direction on node jn, component c */
                memset(w->de, 0, sizeof w->de);
                for (k = 0; k < HEML__W; k++) {
                    if (jn) w->de[3 * (jn - 1) + c][k] = 1;
                    else w->de[c][k] = w->de[3 + c][k] = w->de[6 + c][k] = -1;
                }
                hm_block_diff(m, mt, blk, w);
                for (k = 0; k < valid; k++) {
                    int col = 3 * idx[jn * HEML__W + k] + c;
                    for (a = 0; a < 4; a++)
                        for (r = 0; r < 3; r++) {
                            int row = 3 * idx[a * HEML__W + k] + r, p;
                            heml_real v = a ? w->f[3 * (a - 1) + r][k]
                                            : -((w->f[r][k] + w->f[3 + r][k]) + w->f[6 + r][k]);
                            for (p = s->csr_row[row]; s->csr_col[p] != col; p++) continue;
                            s->csr_val[p] += v;
                        }
                }
            }
    }
    free(deg), free(w), free(start), free(nb);
    return 0;
}

/* y = A x by the CSR rows (the threads of the bench's OpenMP build, static rows). */
static void hm_csr_product(const hm_sim *s, const heml_real *x, heml_real *y)
{
    const int *rp = s->csr_row, *col = s->csr_col;
    const heml_real *val = s->csr_val;
    int row, rows = 3 * s->nodes;
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
    for (row = 0; row < rows; row++) {
        heml_real acc = 0;
        int p;
        for (p = rp[row]; p < rp[row + 1]; p++) acc += val[p] * x[col[p]];
        y[row] = acc;
    }
}

/* The arithmetic floor: the force pass's blocks, colours and groups with the law's
   arithmetic and the rest-constant stream (prefetched a block ahead, as the force pass
   does), but no gather or scatter (every block computes
   on the links gathered once for block 0; the forces are summed into a sink). With the
   nodal pressure, its element pass alone (heml__forces_nh with the pressures last
   computed, or the general path), without its sums pass and node pass. */
static volatile double hm_sink;
static int hm_arith(hm_sim *s)
{
    heml_model *m = s->m;
    heml__blk *b = (heml__blk *)malloc(sizeof *b);
    double acc = 0;
    int ci, blk;
    if (!b) return HEML_ERR_ALLOC;
    heml__gather(m, m->blk_idx, m->disp, b->e);
    for (ci = 0; ci < m->chunk_count; ci++) {
        const heml__mat *mt = m->mats + m->chunk_material[ci];
        for (blk = m->chunk_begin[ci]; blk < m->chunk_end[ci]; blk++) {
            const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
            size_t o;
            for (o = 0; blk + 1 < m->chunk_end[ci] && o < HEML__NR * HEML__W * sizeof(heml_real); o += 64)
                __builtin_prefetch((const char *)(R + HEML__NR * HEML__W) + o); /* (the force pass's prefetch) */
            if (mt->fast || mt->fast_nodal) /* (nodal: the element pass alone, at the pressures last computed) */
                heml__forces_nh(mt, m->jm1_0, R, mt->fast_nodal ? m->nod_p : NULL, m->blk_idx + (size_t)blk * 4 * HEML__W, b);
            else {
                heml__block_stress(m, mt, blk, b, 0, 0);
                heml__pk1_forces(R, b);
            }
            acc += (double)b->f[0][0];
        }
    }
    hm_sink = acc;
    free(b);
    return 0;
}

/* The move kernel: the force pass of heml.h (its colours, groups and blocks, its prefetch,
   gather and scatter, reached through the implementation this file includes) with the law's
   arithmetic replaced by one multiply-add per link component, so that it still reads
   every rest constant. What is left is the data movement the force cannot avoid (for
   the hyperelastic laws; the spring law streams its own constants as well, so it has no
   such row). */
typedef struct hm_move {
    heml_model *m;
    int colour;
    heml_real *out;
} hm_move;

static void hm_move_links(const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int r, k;
    for (r = 0; r < 9; r++)
        for (k = 0; k < HEML__W; k++) b->f[r][k] = b->e[r][k] * R[r * HEML__W + k] + R[9 * HEML__W + k];
}

static void hm_move_groups(void *ctx, int begin, int end)
{
    const hm_move *p = (const hm_move *)ctx;
    const heml_model *m = p->m;
    heml__blk b;
    int g0 = m->colour_start[p->colour] + begin, g1 = m->colour_start[p->colour] + end, ci, blk;
    for (ci = m->group_start[g0]; ci < m->group_start[g1]; ci++)
        for (blk = m->chunk_begin[ci]; blk < m->chunk_end[ci]; blk++) {
            const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
            if (blk + 1 < m->chunk_end[ci]) /* (the force pass's prefetch) */
                heml__prefetch_block(m->blk_rest + (size_t)(blk + 1) * HEML__NR * HEML__W, HEML__NR, idx + 4 * HEML__W);
            heml__gather(m, idx, m->disp, b.e);
            hm_move_links(m->blk_rest + (size_t)blk * HEML__NR * HEML__W, &b);
            heml__scatter(m, idx, b.f, p->out);
        }
}

static int hm_kernel(void *v, int kernel)
{
    hm_sim *s = (hm_sim *)v;
    if (kernel == BENCH_KERNEL_FORCE) return heml_compute_forces(s->m) ? 0 : HEML_ERR_ARG;
    if (kernel == BENCH_KERNEL_KV) return heml_apply_stiffness(s->m, s->dx, s->out);
    if (kernel == BENCH_KERNEL_CSR) {
        if (!s->csr_row && !s->csr_failed) { /* first call: assemble, and check it against the differential */
            int err = hm_csr_build(s), i, n3 = 3 * s->nodes;
            double dmax = 0, fmax = 0;
            heml_real *y = (heml_real *)malloc(sizeof(heml_real) * (size_t)n3);
            if (!err && y && !heml_apply_stiffness(s->m, s->dx, s->out)) {
                hm_csr_product(s, s->dx, y);
                for (i = 0; i < n3; i++) {
                    double d = fabs((double)y[i] - (double)s->out[i]), f = fabs((double)s->out[i]);
                    dmax = d > dmax ? d : dmax;
                    fmax = f > fmax ? f : fmax;
                }
                if (!(dmax <= 1e-3 * fmax)) err = HEML_ERR_NOT_FINITE; /* (a wrong matrix times nothing) */
            }
            free(y);
            if (err) {
                free(s->csr_row), free(s->csr_col), free(s->csr_val);
                s->csr_row = s->csr_col = NULL, s->csr_val = NULL, s->csr_failed = 1;
                return err;
            }
        }
        if (s->csr_failed) return BENCH_UNSUPPORTED;
        hm_csr_product(s, s->dx, s->out);
        return 0;
    }
    if (kernel == BENCH_KERNEL_ARITH && !s->m->has_springs) return hm_arith(s);
    if (kernel == BENCH_KERNEL_STEP) return heml_step_ex(s->m, (heml_real)1e-3, HEML_IMPLICIT_EULER);
    if (kernel == BENCH_KERNEL_MOVE && !s->m->has_springs) { /* (springs: their own kernels, which move does not model; they stream the same bytes since issue 21) */
        hm_move p;
        p.m = s->m;
        p.out = s->out;
        memset(s->out, 0, sizeof(heml_real) * 3 * (size_t)s->nodes);
        for (p.colour = 0; p.colour < s->m->colour_count; p.colour++)
            heml__run(s->m, s->m->colour_start[p.colour + 1] - s->m->colour_start[p.colour], hm_move_groups, &p);
        return 0;
    }
    return BENCH_UNSUPPORTED;
}

/* >>coarse-rows (issue 21): implicit steps with and without the coarse correction of the
   static solve (desc.implicit_coarse). Beams clamped at x = 0: R3's soft beam (1 x 0.1 x
   0.1 m, 40 x 4 x 4 cells; 20 x 2 x 2 quick; rho 1000, nu 0.3) at E = 1 kPa, 1 MPa and
   10 MPa, loaded by g = 0.01 E / (1 MPa) m/s^2 (the time part's R3 load: a 1.5 mm tip
   deflection, so the steps stay near-linear and the Krylov solves are what is compared),
   and R1's steel beam (16 x 0.5 x 0.5 m, 64 x 2 x 2 cells; 32 x 1 x 1 quick; E = 200 GPa,
   its own weight); dt = 1 ms, 10 ms, 0.1 s and 1 s; implicit Euler and BDF2; `steps` (6; 2 quick)
   steps from rest, each mode (-1 never, 0 automatic, 1 always) on its own model, the modes
   interleaved, best of `repeats` for the time. */
static int hm_coarse_run(const bench_body *b, int integrator, double dt, int mode, int steps, double (*clock_s)(void),
                         bench_coarse_row *row)
{
    void *v = NULL;
    hm_sim *s;
    double t0, cg = 0, nw = 0, fc = 0;
    int k, err = hm_create(b, HEML_NEO_HOOKEAN, 0, &v);
    if (err) return err;
    s = (hm_sim *)v;
    s->m->implicit_coarse = mode;
    row->dof = 3 * s->nodes;
    t0 = clock_s();
    for (k = 0; k < steps && !err; k++) {
        const heml_stats *st;
        err = heml_step_ex(s->m, (heml_real)dt, integrator);
        st = heml_last_stats(s->m);
        cg += st->cg_iterations, nw += st->newton_iterations, fc += st->coarse_factors;
    }
    t0 = (clock_s() - t0) / steps;
    if (row->seconds_per_step == 0 || t0 < row->seconds_per_step) row->seconds_per_step = t0;
    row->cg_per_step = cg / steps, row->newton_per_step = nw / steps, row->factors_per_step = fc / steps;
    row->code = err;
    hm_destroy(v);
    return 0;
}

#ifdef BENCH_FLOAT
#define BENCH_COARSE_ROWS bench_heml_coarse_rows_float
#else
#define BENCH_COARSE_ROWS bench_heml_coarse_rows_double
#endif
int BENCH_COARSE_ROWS(int quick, double (*clock_s)(void), bench_coarse_row *rows, int max);
int BENCH_COARSE_ROWS(int quick, double (*clock_s)(void), bench_coarse_row *rows, int max)
{
    static const double youngs[3] = {1e3, 1e6, 1e7}, dts[4] = {1e-3, 1e-2, 0.1, 1.0};
    static const int integrators[2] = {HEML_IMPLICIT_EULER, HEML_BDF2};
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
                            if (hm_coarse_run(&b, integrators[it], dts[d], mode - 1, steps, clock_s, rows + n + mode))
                                rows[n + mode].code = -1;
                    n += 3;
                }
    return n;
}

#define HM_ALL ((1u << BENCH_SEMI_IMPLICIT_EULER) | (1u << BENCH_IMPLICIT_EULER) | (1u << BENCH_STATIC) | (1u << BENCH_BDF2))
#define HM_FUNCTIONS                                                                                          \
    hm_destroy, hm_dof, hm_node_count, hm_rest, hm_position, hm_pin, hm_release, hm_set_gravity, hm_solve_static, \
        hm_step, hm_forces, NULL, hm_elements, hm_kernel_bytes, hm_kernel, NULL, hm_probe, NULL

static const bench_model hm_models[] = {
    {"heml", "svk", "svk", BENCH_PRECISION, HM_ALL, 1, 1, "tet", hm_create_svk, HM_FUNCTIONS},
    {"heml", "neo-hookean", "neo-hookean", BENCH_PRECISION, HM_ALL, 1, 1, "tet", hm_create_nh, HM_FUNCTIONS},
    {"heml", "mooney-rivlin", "mooney-rivlin", BENCH_PRECISION, HM_ALL, 1, 0, "tet", hm_create_mr, HM_FUNCTIONS},
    {"heml", "springs", "springs", BENCH_PRECISION, HM_ALL, 1, 0, "tet", hm_create_springs, HM_FUNCTIONS},
    {"heml", "neo-hookean nodal-p", "neo-hookean", BENCH_PRECISION, HM_ALL, 1, -1, "tet", hm_create_nh_nodal, HM_FUNCTIONS},
    {"heml", "neo-hookean nodal-agg", "neo-hookean", BENCH_PRECISION, HM_ALL, 1, -1, "tet", hm_create_nh_nodal_agg,
     HM_FUNCTIONS},
};

const bench_model *BENCH_TABLE(int *count);
const bench_model *BENCH_TABLE(int *count)
{
    *count = (int)(sizeof hm_models / sizeof hm_models[0]);
    return hm_models;
}
