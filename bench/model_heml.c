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
#include <stdlib.h>
#include <string.h>

typedef struct hm_sim {
    heml_model *m;
    int nodes, tets;
    int *tet_nodes;
    double *rest; /* 3n, with the offset, in double */
    heml_real *dx, *out; /* K*v kernel vectors */
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

static void hm_destroy(void *v)
{
    hm_sim *s = (hm_sim *)v;
    if (!s) return;
    heml_probe_destroy(s->probe);
    heml_destroy(s->m);
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

static double hm_kernel_bytes(void *v, int kernel)
{
    size_t r = 0, w = 0;
    heml_kernel_bytes(((hm_sim *)v)->m, kernel == BENCH_KERNEL_MOVE ? BENCH_KERNEL_FORCE : kernel, &r, &w);
    return (double)(r + w);
}

/* The move kernel: the force pass of heml.h (its colours, groups and blocks, its gather
   and scatter, reached through the implementation this file includes) with the law's
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
            heml__gather(idx, m->disp, b.e);
            hm_move_links(m->blk_rest + (size_t)blk * HEML__NR * HEML__W, &b);
            heml__scatter(idx, b.f, p->out);
        }
}

static int hm_kernel(void *v, int kernel)
{
    hm_sim *s = (hm_sim *)v;
    if (kernel == BENCH_KERNEL_FORCE) return heml_compute_forces(s->m) ? 0 : HEML_ERR_ARG;
    if (kernel == BENCH_KERNEL_KV) return heml_apply_stiffness(s->m, s->dx, s->out);
    if (kernel == BENCH_KERNEL_MOVE && !s->m->has_springs) { /* (springs stream more) */
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
};

const bench_model *BENCH_TABLE(int *count);
const bench_model *BENCH_TABLE(int *count)
{
    *count = (int)(sizeof hm_models / sizeof hm_models[0]);
    return hm_models;
}
