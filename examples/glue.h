/* glue.h - gluing a heml.h or tensormass.h mesh to a frames.h body (issue 14): user-level
   code, not a library header. The headers never include each other; a program that holds
   both models includes frames.h and the mesh header(s) it uses (the implementations where
   it wants them), then this file: the adapter of each mesh header included before it is
   compiled (on its guard macro, HEML_H or TENSORMASS_H), glue_init_heml / glue_init_tmass.
   Used by tests/test_frames_coupling.c, examples/frames_connective.c and
   bench/model_glue.c; frames.h's COUPLING section explains the schemes and their measured
   limits. Everything is static; errors: 0, a frames.h code, 1000 + the mesh header's code,
   or GLUE_ERR_NOT_CONVERGED (glue_solve at its cap); glue_error_string names each. Allocation: the
   glue_init_* functions only. The glue owns the frames' external loads and the glued
   nodes' external forces (the coupling writes and clears them). */
#ifndef GLUE_H
#define GLUE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The glue of a mesh to a frames body (the recipe of frames.h COUPLING; the headers never
   see each other): n glued nodes of the mesh, a probe of the frames body at their rest
   positions. Stiff coupling: zero-length springs (stiffness k each) between each glued
   node x_n and its mapped point p_n(q), energy k/2 |x_n - p_n|^2, entered in both models
   as anchors (heml_set_anchors or tmass_set_anchors: targets p; frm_model_set_anchors:
   targets x). A coupled step or static solve is the minimisation of both models' objectives
   plus the springs' energy; glue_solve reaches it by a Robin-Neumann iteration (glue_map:
   the side carrying the springs solves with their other ends held, the other side under
   the springs' forces as loads; each from the step's start state) on the interface
   points, accelerated by Anderson mixing (depth GLUE_DEPTH), until they move less than tol
   (m) in an iteration. Plain block Gauss-Seidel with springs on both sides stalls (each
   side, held by stiff springs, hardly moves: 1e-6 m an iteration on R1 while 0.055 m
   remained), and plain Robin-Neumann diverged on R1's interface modes; Anderson mixing
   fixes the few slow or unstable modes. Staggered coupling (glue_staggered_step): the
   glued nodes are prescribed at the mapped points and the mesh's forces on them go to the
   frames as loads (J^T f), once a step. Steps: implicit Euler in the mesh (HEML_ /
   TMASS_IMPLICIT_EULER), the frames model's own integrator (frm_model_step_ex). */
#define GLUE_DEPTH 6
#define GLUE_ERR_NOT_CONVERGED (-1000) /* glue_solve at max_iterations (not a header's code) */
typedef struct glue glue;

/* What the glue asks of a mesh: one table per mesh header (the adapters below). The
   functions return 0 or the mesh header's code; glued node a is gl->nodes[a]. */
enum { GLUE_REST, GLUE_POSITION, GLUE_VELOCITY, GLUE_MASS };
typedef struct glue_mesh_ops {
    const char *name; /* "heml.h", "tensormass.h" */
    int (*node_count)(const glue *gl);
    double (*get)(const glue *gl, int what, int i); /* GLUE_REST, _POSITION, _VELOCITY: value i of
                                                       the 3 x node_count; GLUE_MASS: node i's, kg */
    int (*set_anchors)(glue *gl, const double *x);  /* springs gl->k from the glued nodes to x
                                                       (3n, m); NULL removes every anchor */
    int (*set_force)(glue *gl, int a, const double f[3]); /* external force on glued node a, N */
    int (*solve)(glue *gl, double dt);                /* dt > 0: an implicit Euler step; 0: static */
    int (*state)(glue *gl, int restore);              /* 0 saves the state (positions, velocities)
                                                         at a step's start, 1 puts it back */
    int (*prescribe)(glue *gl, int a, const double x[3]); /* pins glued node a at x (m) */
    int (*forces)(glue *gl, double *f);               /* elastic forces on the glued nodes (3n, N) */
    const char *(*error_string)(int code);
} glue_mesh_ops;

struct glue {
    void *mesh;                /* the heml_model or tmass_model */
    const glue_mesh_ops *ops;  /* its adapter */
    void *mesh_buffer;         /* the adapter's arrays in the mesh's real type: the anchors'
                                  stiffnesses and targets (kept by pointer in the model), the
                                  start state */
    frm_model *f;
    frm_probe *p;
    int n, iterations; /* glued nodes; the last solve's iterations */
    int robin_frames;  /* 0: the mesh carries the springs, 1: the frames (glue_map) */
    int springs_on;    /* the side that last carried them: 0 none yet, 1 the mesh, 2 the frames */
    int depth;         /* Anderson mixing's depth (<= GLUE_DEPTH; 0: plain iteration) */
    double k, mesh_k;  /* the springs' stiffness, N/m; as the mesh holds it (its real type) */
    double gz;         /* gravity along z, m/s^2 (the staggered scheme's weight of the glued nodes) */
    double mesh_seconds, frames_seconds; /* CPU time in each model's solves (clock), summed */
    const int *nodes;
    frm_real *fk, *ft, *mp, *fp, *fq, *fv, *gen;
    double *x, *g, *r, *dG, *dR, *gprev, *rprev, *fm; /* Anderson: 3n each, dG and dR GLUE_DEPTH
                                                         columns; fm: the mesh's forces (3n) */
};

/* The common part of glue_init_*: the probe at the glued nodes' rest positions and the
   glue's arrays. Returns 0 or a frames.h code (nothing allocated then). */
static inline int glue__init(glue *gl, void *mesh, const glue_mesh_ops *ops, frm_model *f, const frm_probe_desc *pd,
                             const int *nodes, int n, double k)
{
    int i, N = 3 * n, nf = frm_model_frame_count(f), err;
    frm_real *pts = (frm_real *)malloc(sizeof(frm_real) * (size_t)N);
    memset(gl, 0, sizeof *gl);
    gl->mesh = mesh, gl->ops = ops, gl->f = f, gl->n = n, gl->nodes = nodes, gl->k = k, gl->gz = -9.81;
    for (i = 0; i < N; i++) pts[i] = (frm_real)ops->get(gl, GLUE_REST, 3 * nodes[i / 3] + i % 3);
    err = frm_probe_create(f, pd, pts, n, &gl->p);
    free(pts);
    if (err) return err;
    gl->fk = (frm_real *)malloc(sizeof(frm_real) * (size_t)n);
    gl->ft = (frm_real *)malloc(sizeof(frm_real) * (size_t)N);
    gl->mp = (frm_real *)malloc(sizeof(frm_real) * (size_t)N);
    gl->fp = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)nf);
    gl->fq = (frm_real *)malloc(sizeof(frm_real) * 4 * (size_t)nf);
    gl->fv = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)nf);
    gl->gen = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)nf);
    gl->x = (double *)malloc(sizeof(double) * (size_t)N * (6 + 2 * GLUE_DEPTH));
    gl->g = gl->x + N, gl->r = gl->g + N, gl->gprev = gl->r + N, gl->rprev = gl->gprev + N, gl->fm = gl->rprev + N;
    gl->dG = gl->fm + N, gl->dR = gl->dG + (size_t)N * GLUE_DEPTH;
    for (i = 0; i < n; i++) gl->fk[i] = (frm_real)k;
    return 0;
}

static inline void glue_free(glue *gl)
{
    frm_probe_destroy(gl->p);
    free(gl->mesh_buffer), free(gl->fk), free(gl->ft), free(gl->mp);
    free(gl->fp), free(gl->fq), free(gl->fv), free(gl->gen), free(gl->x);
}

#ifdef HEML_H
/* heml.h's adapter. Buffer (heml_real): k (n), targets (3n), displacements and velocities
   at the step's start (3 node_count each). */
static inline int glue__heml_count(const glue *gl) { return heml_node_count((const heml_model *)gl->mesh); }
static inline double glue__heml_get(const glue *gl, int what, int i)
{
    const heml_model *h = (const heml_model *)gl->mesh;
    return (double)(what == GLUE_REST       ? heml_rest_positions(h)
                    : what == GLUE_POSITION ? heml_positions(h)
                    : what == GLUE_VELOCITY ? heml_velocities(h)
                                            : heml_masses(h))[i];
}
static inline int glue__heml_anchors(glue *gl, const double *x)
{
    heml_real *k = (heml_real *)gl->mesh_buffer, *t = k + gl->n;
    int i;
    if (!x) return heml_set_anchors((heml_model *)gl->mesh, 0, NULL, NULL, NULL);
    for (i = 0; i < gl->n; i++) k[i] = (heml_real)gl->k;
    for (i = 0; i < 3 * gl->n; i++) t[i] = (heml_real)x[i];
    return heml_set_anchors((heml_model *)gl->mesh, gl->n, gl->nodes, k, t);
}
static inline int glue__heml_force(glue *gl, int a, const double f[3])
{
    heml_real F[3];
    F[0] = (heml_real)f[0], F[1] = (heml_real)f[1], F[2] = (heml_real)f[2];
    return heml_set_external_force((heml_model *)gl->mesh, gl->nodes[a], F);
}
static inline int glue__heml_solve(glue *gl, double dt)
{
    heml_model *h = (heml_model *)gl->mesh;
    return dt > 0 ? heml_step_ex(h, (heml_real)dt, HEML_IMPLICIT_EULER) : heml_solve_static(h);
}
static inline int glue__heml_state(glue *gl, int restore)
{
    heml_model *h = (heml_model *)gl->mesh;
    int N = 3 * heml_node_count(h), err;
    heml_real *u = (heml_real *)gl->mesh_buffer + 4 * gl->n, *v = u + N;
    if (restore) return (err = heml_set_displacements(h, u)) != 0 ? err : heml_set_velocities(h, v);
    memcpy(u, heml_displacements(h), sizeof(heml_real) * (size_t)N);
    memcpy(v, heml_velocities(h), sizeof(heml_real) * (size_t)N);
    return 0;
}
static inline int glue__heml_prescribe(glue *gl, int a, const double x[3])
{
    heml_model *h = (heml_model *)gl->mesh;
    heml_real u[3];
    int r;
    for (r = 0; r < 3; r++) u[r] = (heml_real)(x[r] - (double)heml_rest_positions(h)[3 * gl->nodes[a] + r]);
    return heml_set_displacement(h, gl->nodes[a], u);
}
static inline int glue__heml_forces(glue *gl, double *f)
{
    const heml_real *fi = heml_compute_forces((heml_model *)gl->mesh);
    int i;
    if (!fi) return HEML_ERR_ARG;
    for (i = 0; i < 3 * gl->n; i++) f[i] = (double)fi[3 * gl->nodes[i / 3] + i % 3];
    return 0;
}
static const glue_mesh_ops glue_heml_ops = {"heml.h", glue__heml_count, glue__heml_get, glue__heml_anchors,
                                            glue__heml_force, glue__heml_solve, glue__heml_state,
                                            glue__heml_prescribe, glue__heml_forces, heml_error_string};

/* Glues nodes[0..n) of the heml.h mesh h (the array is kept by pointer) to the frames body
   f (probe description pd), springs of k N/m for the stiff coupling (0 for the staggered
   one). Returns 0 or a frames.h code. */
static inline int glue_init_heml(glue *gl, heml_model *h, frm_model *f, const frm_probe_desc *pd, const int *nodes,
                                 int n, double k)
{
    int err = glue__init(gl, h, &glue_heml_ops, f, pd, nodes, n, k);
    if (err) return err;
    gl->mesh_k = (double)(heml_real)k;
    gl->mesh_buffer = malloc(sizeof(heml_real) * (4 * (size_t)n + 6 * (size_t)heml_node_count(h)));
    return 0;
}
#endif /* HEML_H */

#ifdef TENSORMASS_H
/* tensormass.h's adapter. Buffer (tmass_real): k (n), targets (3n), positions and
   velocities at the step's start (3 node_count each; tensormass.h sets positions, not
   displacements: a restored displacement is x - X rounded, within round-off of |x|). */
static inline int glue__tmass_count(const glue *gl) { return tmass_node_count((const tmass_model *)gl->mesh); }
static inline double glue__tmass_get(const glue *gl, int what, int i)
{
    const tmass_model *t = (const tmass_model *)gl->mesh;
    return (double)(what == GLUE_REST       ? tmass_rest_positions(t)
                    : what == GLUE_POSITION ? tmass_positions(t)
                    : what == GLUE_VELOCITY ? tmass_velocities(t)
                                            : tmass_masses(t))[i];
}
static inline int glue__tmass_anchors(glue *gl, const double *x)
{
    tmass_real *k = (tmass_real *)gl->mesh_buffer, *t = k + gl->n;
    int i;
    if (!x) return tmass_set_anchors((tmass_model *)gl->mesh, 0, NULL, NULL, NULL);
    for (i = 0; i < gl->n; i++) k[i] = (tmass_real)gl->k;
    for (i = 0; i < 3 * gl->n; i++) t[i] = (tmass_real)x[i];
    return tmass_set_anchors((tmass_model *)gl->mesh, gl->n, gl->nodes, k, t);
}
static inline int glue__tmass_force(glue *gl, int a, const double f[3])
{
    tmass_real F[3];
    F[0] = (tmass_real)f[0], F[1] = (tmass_real)f[1], F[2] = (tmass_real)f[2];
    return tmass_set_external_force((tmass_model *)gl->mesh, gl->nodes[a], F);
}
static inline int glue__tmass_solve(glue *gl, double dt)
{
    tmass_model *t = (tmass_model *)gl->mesh;
    return dt > 0 ? tmass_step_ex(t, (tmass_real)dt, TMASS_IMPLICIT_EULER) : tmass_solve_static(t);
}
static inline int glue__tmass_state(glue *gl, int restore)
{
    tmass_model *t = (tmass_model *)gl->mesh;
    int N = 3 * tmass_node_count(t), err;
    tmass_real *x = (tmass_real *)gl->mesh_buffer + 4 * gl->n, *v = x + N;
    if (restore) return (err = tmass_set_positions(t, x)) != 0 ? err : tmass_set_velocities(t, v);
    memcpy(x, tmass_positions(t), sizeof(tmass_real) * (size_t)N);
    memcpy(v, tmass_velocities(t), sizeof(tmass_real) * (size_t)N);
    return 0;
}
static inline int glue__tmass_prescribe(glue *gl, int a, const double x[3])
{
    tmass_model *t = (tmass_model *)gl->mesh;
    tmass_real u[3];
    int r;
    for (r = 0; r < 3; r++) u[r] = (tmass_real)(x[r] - (double)tmass_rest_positions(t)[3 * gl->nodes[a] + r]);
    return tmass_set_displacement(t, gl->nodes[a], u);
}
static inline int glue__tmass_forces(glue *gl, double *f)
{
    const tmass_real *fi = tmass_forces((tmass_model *)gl->mesh);
    int i;
    if (!fi) return TMASS_ERR_ARG;
    for (i = 0; i < 3 * gl->n; i++) f[i] = (double)fi[3 * gl->nodes[i / 3] + i % 3];
    return 0;
}
static const glue_mesh_ops glue_tmass_ops = {"tensormass.h", glue__tmass_count, glue__tmass_get, glue__tmass_anchors,
                                             glue__tmass_force, glue__tmass_solve, glue__tmass_state,
                                             glue__tmass_prescribe, glue__tmass_forces, tmass_error_string};

/* As glue_init_heml for the tensormass.h mesh t. */
static inline int glue_init_tmass(glue *gl, tmass_model *t, frm_model *f, const frm_probe_desc *pd, const int *nodes,
                                  int n, double k)
{
    int err = glue__init(gl, t, &glue_tmass_ops, f, pd, nodes, n, k);
    if (err) return err;
    gl->mesh_k = (double)(tmass_real)k;
    gl->mesh_buffer = malloc(sizeof(tmass_real) * (4 * (size_t)n + 6 * (size_t)tmass_node_count(t)));
    return 0;
}
#endif /* TENSORMASS_H */

/* The name of a glue code: the mesh header's for 1000 + its code, else frames.h's. */
static inline const char *glue_error_string(const glue *gl, int err)
{
    if (err == GLUE_ERR_NOT_CONVERGED) return "the coupling iteration did not converge within max_iterations";
    return err > 500 ? gl->ops->error_string(err - 1000) : frm_error_string(err);
}

/* One application of the coupling map at x, the Robin side's targets: the Robin side (the
   model carrying the springs as anchors) solves with its springs' other ends at x, then the
   Neumann side solves under the springs' forces as loads and gives g, the new positions
   of its interface points. robin_frames = 0: the mesh carries the springs (targets x = the
   mapped points), the frames take J^T F (J at their latest iterate, so exact at
   convergence); 1: the frames carry them (x = the glued nodes), the mesh takes F at its
   nodes. dt > 0: steps of dt from the saved start state; dt = 0: static solves from the
   current state. The springs live on one side only: each map removes the other side's
   (its anchors; the mesh's glued nodes' external forces, which the glue owns, as it owns
   the frames' external loads), so robin_frames may change between solves. Returns a
   model's code (the mesh's as 1000 + code). */
static inline int glue_map(glue *gl, double dt, const double *x, double *g)
{
    int i, r, err, nf = frm_model_frame_count(gl->f);
    clock_t t0;
    if (dt > 0) {
        if ((err = gl->ops->state(gl, 1)) != 0) return 1000 + err;
    }
    if (!gl->robin_frames) {
        if (gl->springs_on == 2) { /* they were on the frames: remove them and their forces */
            static const double zero[3] = {0, 0, 0};
            if ((err = frm_model_set_anchors(gl->f, NULL, NULL, NULL)) != 0) return err;
            for (i = 0; i < gl->n; i++)
                if ((err = gl->ops->set_force(gl, i, zero)) != 0) return 1000 + err;
        }
        gl->springs_on = 1;
        if ((err = gl->ops->set_anchors(gl, x)) != 0) return 1000 + err;
        t0 = clock();
        err = gl->ops->solve(gl, dt);
        gl->mesh_seconds += (double)(clock() - t0) / CLOCKS_PER_SEC;
        if (err) return 1000 + err;
        for (i = 0; i < gl->n; i++) /* the springs' force on the mapped points, k (x_n - p_n) */
            for (r = 0; r < 3; r++)
                gl->ft[3 * i + r] = (frm_real)(gl->mesh_k * (gl->ops->get(gl, GLUE_POSITION, 3 * gl->nodes[i] + r) - x[3 * i + r]));
        frm_probe_jacobian_transpose(gl->p, gl->f, gl->ft, gl->gen, 0);
        if (dt > 0) {
            frm_model_set_poses(gl->f, gl->fp, gl->fq);
            frm_model_set_velocities(gl->f, gl->fv);
        }
        for (i = 0; i < nf; i++) frm_model_set_external(gl->f, i, gl->gen + 6 * i, gl->gen + 6 * i + 3);
        t0 = clock();
        err = dt > 0 ? frm_model_step_ex(gl->f, (frm_real)dt) : frm_model_solve_static(gl->f);
        gl->frames_seconds += (double)(clock() - t0) / CLOCKS_PER_SEC;
        if (err) return err;
        frm_probe_positions(gl->p, gl->f, gl->mp);
        for (i = 0; i < 3 * gl->n; i++) g[i] = (double)gl->mp[i];
        return 0;
    }
    if (gl->springs_on == 1) { /* they were on the mesh: remove them and their loads */
        if ((err = gl->ops->set_anchors(gl, NULL)) != 0) return 1000 + err;
        frm_model_clear_external(gl->f);
    }
    gl->springs_on = 2;
    for (i = 0; i < 3 * gl->n; i++) gl->ft[i] = (frm_real)x[i];
    if (dt > 0) {
        frm_model_set_poses(gl->f, gl->fp, gl->fq);
        frm_model_set_velocities(gl->f, gl->fv);
    }
    if ((err = frm_model_set_anchors(gl->f, gl->p, gl->fk, gl->ft)) != 0) return err;
    t0 = clock();
    err = dt > 0 ? frm_model_step_ex(gl->f, (frm_real)dt) : frm_model_solve_static(gl->f);
    gl->frames_seconds += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (err) return err;
    frm_probe_positions(gl->p, gl->f, gl->mp);
    for (i = 0; i < gl->n; i++) { /* the springs' force on the glued nodes, k (p_n - x_n) */
        double F[3];
        for (r = 0; r < 3; r++) F[r] = (double)gl->fk[i] * ((double)gl->mp[3 * i + r] - x[3 * i + r]);
        if ((err = gl->ops->set_force(gl, i, F)) != 0) return 1000 + err;
    }
    t0 = clock();
    err = gl->ops->solve(gl, dt);
    gl->mesh_seconds += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (err) return 1000 + err;
    for (i = 0; i < 3 * gl->n; i++) g[i] = gl->ops->get(gl, GLUE_POSITION, 3 * gl->nodes[i / 3] + i % 3);
    return 0;
}

/* Least squares min |r - dR c| over the m columns (normal equations, Cholesky with a
   relative shift 1e-12: the columns are the residuals' differences). */
static inline void glue_lsq(const double *dR, int N, int m, const double *r, double *c)
{
    double A[GLUE_DEPTH * GLUE_DEPTH], b[GLUE_DEPTH], tr = 0;
    int i, j, l;
    for (i = 0; i < m; i++) {
        for (j = 0; j < m; j++) {
            double t = 0;
            for (l = 0; l < N; l++) t += dR[(size_t)i * N + l] * dR[(size_t)j * N + l];
            A[i * m + j] = t;
        }
        for (b[i] = 0, l = 0; l < N; l++) b[i] += dR[(size_t)i * N + l] * r[l];
        tr += A[i * m + i];
    }
    for (i = 0; i < m; i++) A[i * m + i] += 1e-12 * tr + 1e-300;
    for (j = 0; j < m; j++) { /* Cholesky in place, then the two triangular solves */
        for (l = 0; l < j; l++) A[j * m + j] -= A[j * m + l] * A[j * m + l];
        A[j * m + j] = sqrt(A[j * m + j] > 0 ? A[j * m + j] : 1e-300);
        for (i = j + 1; i < m; i++) {
            for (l = 0; l < j; l++) A[i * m + j] -= A[i * m + l] * A[j * m + l];
            A[i * m + j] /= A[j * m + j];
        }
    }
    for (i = 0; i < m; i++) {
        for (l = 0; l < i; l++) b[i] -= A[i * m + l] * b[l];
        b[i] /= A[i * m + i];
    }
    for (i = m - 1; i >= 0; i--) {
        for (l = i + 1; l < m; l++) b[i] -= A[l * m + i] * b[l];
        b[i] /= A[i * m + i];
    }
    for (i = 0; i < m; i++) c[i] = b[i];
}

/* The coupled step (dt > 0) or static solve (dt = 0), stiff coupling: Gauss-Seidel with
   Anderson mixing until max |g - x| <= tol (m), at most max_iterations maps. Returns 0, a
   model's code or GLUE_ERR_NOT_CONVERGED at the cap (both models back at the start state
   for a step). */
static inline int glue_solve(glue *gl, double dt, double tol, int max_iterations)
{
    int N = 3 * gl->n, it, i, m = 0, head = 0, err = 0, nf = frm_model_frame_count(gl->f);
    double c[GLUE_DEPTH];
    if ((err = gl->ops->state(gl, 0)) != 0) return 1000 + err;
    memcpy(gl->fp, frm_model_positions(gl->f), sizeof(frm_real) * 3 * (size_t)nf);
    memcpy(gl->fq, frm_model_orientations(gl->f), sizeof(frm_real) * 4 * (size_t)nf);
    memcpy(gl->fv, frm_model_velocities(gl->f), sizeof(frm_real) * 6 * (size_t)nf);
    if (!gl->robin_frames) { /* start: the Neumann side's points moved by dt v */
        frm_probe_positions(gl->p, gl->f, gl->mp);
        for (i = 0; i < N; i++) gl->x[i] = (double)gl->mp[i];
        if (dt > 0) {
            frm_probe_velocities(gl->p, gl->f, gl->mp);
            for (i = 0; i < N; i++) gl->x[i] += dt * (double)gl->mp[i];
        }
    } else
        for (i = 0; i < N; i++)
            gl->x[i] = gl->ops->get(gl, GLUE_POSITION, 3 * gl->nodes[i / 3] + i % 3) +
                       (dt > 0 ? dt * gl->ops->get(gl, GLUE_VELOCITY, 3 * gl->nodes[i / 3] + i % 3) : 0.0);
    for (it = 1; it <= max_iterations; it++) {
        double rmax = 0;
        if ((err = glue_map(gl, dt, gl->x, gl->g)) != 0) break;
        for (i = 0; i < N; i++) {
            gl->r[i] = gl->g[i] - gl->x[i];
            if (fabs(gl->r[i]) > rmax) rmax = fabs(gl->r[i]);
        }
        gl->iterations = it;
        if (rmax <= tol) return 0;
        if (it > 1 && gl->depth) { /* new columns: differences of g and r */
            for (i = 0; i < N; i++) {
                gl->dG[(size_t)head * N + i] = gl->g[i] - gl->gprev[i];
                gl->dR[(size_t)head * N + i] = gl->r[i] - gl->rprev[i];
            }
            head = gl->depth ? (head + 1) % gl->depth : 0;
            if (m < gl->depth) m++;
        }
        memcpy(gl->gprev, gl->g, sizeof(double) * (size_t)N);
        memcpy(gl->rprev, gl->r, sizeof(double) * (size_t)N);
        if (m > 0) {
            int j;
            glue_lsq(gl->dR, N, m, gl->r, c);
            for (i = 0; i < N; i++) {
                double t = gl->g[i];
                for (j = 0; j < m; j++) t -= c[j] * gl->dG[(size_t)j * N + i];
                gl->x[i] = t;
            }
        } else
            memcpy(gl->x, gl->g, sizeof(double) * (size_t)N);
    }
    if (!err) err = GLUE_ERR_NOT_CONVERGED;
    if (dt > 0) { /* failed: both back at the step's start */
        gl->ops->state(gl, 1);
        frm_model_set_poses(gl->f, gl->fp, gl->fq);
        frm_model_set_velocities(gl->f, gl->fv);
    }
    return err;
}

/* Staggered coupling, one step: the frames step under the mesh's last forces on the glued
   nodes (J^T fh as loads), then the glued nodes are prescribed at the new mapped points
   and the mesh steps; fh (3n, N) becomes the mesh's elastic force on each glued node plus
   its weight (the node's inertia neglected). Returns a model's code (the mesh's: 1000 +
   code). */
static inline int glue_staggered_step(glue *gl, double dt, frm_real *fh)
{
    int i, r, err;
    double y[3];
    frm_model_clear_external(gl->f);
    if ((err = frm_probe_add_external(gl->p, gl->f, fh)) != 0) return err;
    if ((err = frm_model_step_ex(gl->f, (frm_real)dt)) != 0) return err;
    frm_probe_positions(gl->p, gl->f, gl->mp);
    for (i = 0; i < gl->n; i++) {
        for (r = 0; r < 3; r++) y[r] = (double)gl->mp[3 * i + r];
        if ((err = gl->ops->prescribe(gl, i, y)) != 0) return 1000 + err;
    }
    if ((err = gl->ops->solve(gl, dt)) != 0) return 1000 + err;
    if ((err = gl->ops->forces(gl, gl->fm)) != 0) return 1000 + err;
    for (i = 0; i < gl->n; i++)
        for (r = 0; r < 3; r++)
            fh[3 * i + r] = (frm_real)(gl->fm[3 * i + r] + gl->ops->get(gl, GLUE_MASS, gl->nodes[i]) * (r == 2 ? gl->gz : 0.0));
    return 0;
}

#endif /* GLUE_H */
