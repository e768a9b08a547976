/* glue.h - gluing a heml.h mesh to a frames.h body (issue 14): user-level code, not a
   library header. The two headers never include each other; a program that holds both
   models includes frames.h and heml.h (the implementations where it wants them), then this
   file. Used by tests/test_frames_coupling.c and examples/frames_connective.c; frames.h's
   COUPLING section explains the schemes and their measured limits. Everything is static;
   errors: 0, a frames.h code, 1000 + a heml.h code, or -1 (glue_solve at its cap).
   Allocation: glue_init only. The glue owns the frames' external loads and the glued
   nodes' external forces (the coupling writes and clears them). */
#ifndef GLUE_H
#define GLUE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The glue of a heml.h mesh to a frames body (the recipe of frames.h COUPLING; the headers
   never see each other): n glued nodes of the mesh, a probe of the frames body at their
   rest positions. Stiff coupling: zero-length springs (stiffness k each) between each
   glued node x_n and its mapped point p_n(q), energy k/2 |x_n - p_n|^2, entered in both
   models as anchors (heml_set_anchors: targets p; frm_model_set_anchors: targets x). A
   coupled step or static solve is the minimisation of both models' objectives plus the
   springs' energy; glue_solve reaches it by a Robin-Neumann iteration (glue_map: the side
   carrying the springs solves with their other ends held, the other side under the
   springs' forces as loads; each from the step's start state) on the interface points,
   accelerated by Anderson mixing (depth GLUE_DEPTH), until they move less than tol (m)
   in an iteration. Plain block Gauss-Seidel with springs on both sides stalls (each side,
   held by stiff springs, hardly moves: 1e-6 m an iteration on R1 while 0.055 m remained),
   and plain Robin-Neumann diverged on R1's interface modes; Anderson mixing fixes the few
   slow or unstable modes. Staggered coupling (glue_staggered_step):
   the glued nodes are prescribed at the mapped points and the mesh's forces on them go to
   the frames as loads (J^T f), once a step. */
#define GLUE_DEPTH 6
typedef struct glue {
    heml_model *h;
    frm_model *f;
    frm_probe *p;
    int n, iterations; /* glued nodes; the last solve's iterations */
    int robin_frames;  /* 0: the mesh carries the springs, 1: the frames (glue_map) */
    int springs_on;    /* the side that last carried them: 0 none yet, 1 the mesh, 2 the frames */
    int depth;         /* Anderson mixing's depth (<= GLUE_DEPTH; 0: plain iteration) */
    double gz;         /* gravity along z, m/s^2 (the staggered scheme's weight of the glued nodes) */
    double mesh_seconds, frames_seconds; /* CPU time in each model's solves (clock), summed */
    const int *nodes;
    heml_real *hk, *ht, *hu, *hv; /* heml anchors (k, targets); its start state */
    frm_real *fk, *ft, *mp, *fp, *fq, *fv, *gen;
    double *x, *g, *r, *dG, *dR, *gprev, *rprev; /* Anderson: 3n each, dG and dR GLUE_DEPTH columns */
} glue;

static inline int glue_init(glue *gl, heml_model *h, frm_model *f, const frm_probe_desc *pd, const int *nodes, int n, double k)
{
    int i, r, N = 3 * n, nh = heml_node_count(h), nf = frm_model_frame_count(f), err;
    frm_real *pts = (frm_real *)malloc(sizeof(frm_real) * (size_t)N);
    memset(gl, 0, sizeof *gl);
    gl->h = h, gl->f = f, gl->n = n, gl->nodes = nodes, gl->gz = -9.81;
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) pts[3 * i + r] = (frm_real)heml_rest_positions(h)[3 * nodes[i] + r];
    err = frm_probe_create(f, pd, pts, n, &gl->p);
    free(pts);
    if (err) return err;
    gl->hk = (heml_real *)malloc(sizeof(heml_real) * (size_t)n);
    gl->ht = (heml_real *)malloc(sizeof(heml_real) * (size_t)N);
    gl->hu = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)nh);
    gl->hv = (heml_real *)malloc(sizeof(heml_real) * 3 * (size_t)nh);
    gl->fk = (frm_real *)malloc(sizeof(frm_real) * (size_t)n);
    gl->ft = (frm_real *)malloc(sizeof(frm_real) * (size_t)N);
    gl->mp = (frm_real *)malloc(sizeof(frm_real) * (size_t)N);
    gl->fp = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)nf);
    gl->fq = (frm_real *)malloc(sizeof(frm_real) * 4 * (size_t)nf);
    gl->fv = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)nf);
    gl->gen = (frm_real *)malloc(sizeof(frm_real) * 6 * (size_t)nf);
    gl->x = (double *)malloc(sizeof(double) * (size_t)N * (5 + 2 * GLUE_DEPTH));
    gl->g = gl->x + N, gl->r = gl->g + N, gl->gprev = gl->r + N, gl->rprev = gl->gprev + N, gl->dG = gl->rprev + N;
    gl->dR = gl->dG + (size_t)N * GLUE_DEPTH;
    for (i = 0; i < n; i++) gl->hk[i] = (heml_real)k, gl->fk[i] = (frm_real)k;
    return 0;
}

static inline void glue_free(glue *gl)
{
    frm_probe_destroy(gl->p);
    free(gl->hk), free(gl->ht), free(gl->hu), free(gl->hv), free(gl->fk), free(gl->ft), free(gl->mp);
    free(gl->fp), free(gl->fq), free(gl->fv), free(gl->gen), free(gl->x);
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
   model's code (heml codes as 1000 + code). */
static inline int glue_map(glue *gl, double dt, const double *x, double *g)
{
    int i, r, err, nf = frm_model_frame_count(gl->f);
    clock_t t0;
    if (dt > 0) {
        heml_set_displacements(gl->h, gl->hu);
        heml_set_velocities(gl->h, gl->hv);
    }
    if (!gl->robin_frames) {
        if (gl->springs_on == 2) { /* they were on the frames: remove them and their forces */
            static const heml_real zero[3] = {0, 0, 0};
            if ((err = frm_model_set_anchors(gl->f, NULL, NULL, NULL)) != 0) return err;
            for (i = 0; i < gl->n; i++)
                if ((err = heml_set_external_force(gl->h, gl->nodes[i], zero)) != 0) return 1000 + err;
        }
        gl->springs_on = 1;
        for (i = 0; i < 3 * gl->n; i++) gl->ht[i] = (heml_real)x[i];
        if ((err = heml_set_anchors(gl->h, gl->n, gl->nodes, gl->hk, gl->ht)) != 0) return 1000 + err;
        t0 = clock();
        err = dt > 0 ? heml_step_ex(gl->h, (heml_real)dt, HEML_IMPLICIT_EULER) : heml_solve_static(gl->h);
        gl->mesh_seconds += (double)(clock() - t0) / CLOCKS_PER_SEC;
        if (err) return 1000 + err;
        for (i = 0; i < gl->n; i++) /* the springs' force on the mapped points, k (x_n - p_n) */
            for (r = 0; r < 3; r++)
                gl->ft[3 * i + r] = (frm_real)((double)gl->hk[i] * ((double)heml_positions(gl->h)[3 * gl->nodes[i] + r] - x[3 * i + r]));
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
        if ((err = heml_set_anchors(gl->h, 0, NULL, NULL, NULL)) != 0) return 1000 + err;
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
        heml_real F[3];
        for (r = 0; r < 3; r++) F[r] = (heml_real)((double)gl->fk[i] * ((double)gl->mp[3 * i + r] - x[3 * i + r]));
        if ((err = heml_set_external_force(gl->h, gl->nodes[i], F)) != 0) return 1000 + err;
    }
    t0 = clock();
    err = dt > 0 ? heml_step_ex(gl->h, (heml_real)dt, HEML_IMPLICIT_EULER) : heml_solve_static(gl->h);
    gl->mesh_seconds += (double)(clock() - t0) / CLOCKS_PER_SEC;
    if (err) return 1000 + err;
    for (i = 0; i < gl->n; i++)
        for (r = 0; r < 3; r++) g[3 * i + r] = (double)heml_positions(gl->h)[3 * gl->nodes[i] + r];
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
   model's code (both models back at the start state for a step) or -1 at the cap. */
static inline int glue_solve(glue *gl, double dt, double tol, int max_iterations)
{
    int N = 3 * gl->n, it, i, m = 0, head = 0, err = 0, nf = frm_model_frame_count(gl->f);
    double c[GLUE_DEPTH];
    memcpy(gl->hu, heml_displacements(gl->h), sizeof(heml_real) * 3 * (size_t)heml_node_count(gl->h));
    memcpy(gl->hv, heml_velocities(gl->h), sizeof(heml_real) * 3 * (size_t)heml_node_count(gl->h));
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
            gl->x[i] = (double)heml_positions(gl->h)[3 * gl->nodes[i / 3] + i % 3] +
                       (dt > 0 ? dt * (double)heml_velocities(gl->h)[3 * gl->nodes[i / 3] + i % 3] : 0.0);
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
    if (!err) err = -1;
    if (dt > 0) { /* failed: both back at the step's start */
        heml_set_displacements(gl->h, gl->hu);
        heml_set_velocities(gl->h, gl->hv);
        frm_model_set_poses(gl->f, gl->fp, gl->fq);
        frm_model_set_velocities(gl->f, gl->fv);
    }
    return err;
}

/* Staggered coupling, one step: the frames step under the mesh's last forces on the glued
   nodes (J^T fh as loads), then the glued nodes are prescribed at the new mapped points
   and the mesh steps; fh (3n, N) becomes the mesh's elastic force on each glued node plus
   its weight (the node's inertia neglected). Returns a model's code (heml: 1000 + code). */
static inline int glue_staggered_step(glue *gl, double dt, frm_real *fh)
{
    int i, r, err;
    const heml_real *fi;
    heml_real u[3];
    frm_model_clear_external(gl->f);
    if ((err = frm_probe_add_external(gl->p, gl->f, fh)) != 0) return err;
    if ((err = frm_model_step_ex(gl->f, (frm_real)dt)) != 0) return err;
    frm_probe_positions(gl->p, gl->f, gl->mp);
    for (i = 0; i < gl->n; i++) {
        for (r = 0; r < 3; r++) u[r] = (heml_real)((double)gl->mp[3 * i + r] - (double)heml_rest_positions(gl->h)[3 * gl->nodes[i] + r]);
        if ((err = heml_set_displacement(gl->h, gl->nodes[i], u)) != 0) return 1000 + err;
    }
    if ((err = heml_step_ex(gl->h, (heml_real)dt, HEML_IMPLICIT_EULER)) != 0) return 1000 + err;
    fi = heml_compute_forces(gl->h);
    for (i = 0; i < gl->n; i++)
        for (r = 0; r < 3; r++)
            fh[3 * i + r] = (frm_real)((double)fi[3 * gl->nodes[i] + r] + (double)heml_masses(gl->h)[gl->nodes[i]] * (r == 2 ? gl->gz : 0.0));
    return 0;
}

#endif /* GLUE_H */
