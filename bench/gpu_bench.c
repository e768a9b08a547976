/* gpu_bench.c - the GPU rows of issue 16 (run by bench/gpu.sh): the linearised implicit
   Euler step of a tetrahedral body with one sample per tetrahedron (4 neighbours, the
   thesis's tables 4.5 / 4.6 setting) at exactly 60 CG iterations a step, on the device
   (frames_cuda.cu) and on the CPU (frames.h, OpenMP when built with it) in the same run:
   time per step and per (sample, neighbour, CG iteration), and pair products per second.
   The CG tolerance is set below reach so that every step runs its 60 iterations; the step
   then ends at its cap (FRM_ERR_NO_CONVERGENCE, state kept): the work timed is that of a
   60-iteration step (the linearisation, 60 products, the restore).

       gpu_bench [max_samples]   (default 1100000: the thesis's 34,610 and 1e6 samples)

   One line per size and path; columns: samples, pairs, ms/step, ns per (pair, iteration),
   pair products per second. */
#define _POSIX_C_SOURCE 199309L
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#include "../frames_cuda.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* nx x ny x nz unit cells of 0.1 m, 6 tetrahedra each, one sample a tetrahedron; clamped at x = 0 */
static frm_model *body(int nx, int ny, int nz)
{
    static const int K[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
    int nn = (nx + 1) * (ny + 1) * (nz + 1), cells = nx * ny * nz, i, c, j, q, x, y, z, err;
    frm_real *nodes = (frm_real *)malloc(sizeof(frm_real) * 3 * (size_t)nn);
    int *tets = (int *)malloc(sizeof(int) * 24 * (size_t)cells);
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m = NULL;
    if (!nodes || !tets) return NULL;
    for (i = 0; i < nn; i++) {
        nodes[3 * i] = (frm_real)(0.1 * (i % (nx + 1)));
        nodes[3 * i + 1] = (frm_real)(0.1 * (i / (nx + 1) % (ny + 1)));
        nodes[3 * i + 2] = (frm_real)(0.1 * (i / ((nx + 1) * (ny + 1))));
    }
    c = 0;
    for (z = 0; z < nz; z++)
        for (y = 0; y < ny; y++)
            for (x = 0; x < nx; x++, c++)
                for (j = 0; j < 6; j++) {
                    int corner[8], a, *t = tets + 24 * (size_t)c + 4 * j;
                    const frm_real *p[4];
                    double u[3], v[3], w[3], det;
                    for (a = 0; a < 8; a++) corner[a] = (x + (a & 1)) + (nx + 1) * ((y + (a >> 1 & 1)) + (ny + 1) * (z + (a >> 2)));
                    for (q = 0; q < 4; q++) t[q] = corner[K[j][q]], p[q] = nodes + 3 * (size_t)t[q];
                    for (q = 0; q < 3; q++) u[q] = p[1][q] - p[0][q], v[q] = p[2][q] - p[0][q], w[q] = p[3][q] - p[0][q];
                    det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
                    if (det < 0) q = t[1], t[1] = t[2], t[2] = q;
                }
    err = frm_sampling_tets(&s, nodes, nn, tets, 6 * cells, 1, NULL, NULL);
    free(nodes);
    free(tets);
    if (err) return NULL;
    frm_sampling_apply(&s, &d);
    d.material.young_modulus = 1e5;
    d.material.density = 1000;
    d.time_step = 0.01;
    d.integrator = FRM_IMPLICIT_EULER_LINEARIZED;
    d.stiffness_mode = FRM_STIFFNESS_PAIRS;
    d.cg_tolerance = 1e-30; /* below reach: every step runs cg_max_iterations */
    d.cg_max_iterations = 60;
    err = frm_model_create(&d, &m);
    frm_sampling_free(&s);
    if (err) return NULL;
    for (i = 0; i < nn; i += nx + 1) frm_model_fix_frame(m, i);
    return m;
}

static void row(const char *path, int samples, int pairs, double seconds)
{
    printf("%-4s samples %8d pairs %9d  %9.3f ms/step  %7.3f ns/(pair, iteration)  %.3e pair products/s\n", path, samples,
           pairs, 1e3 * seconds, 1e9 * seconds / (60.0 * pairs), 60.0 * pairs / seconds);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    static const int sizes[][3] = {{48, 12, 10}, {96, 42, 42}}; /* 34,560 and 1,016,064 samples */
    long max_samples = argc > 1 ? atol(argv[1]) : 1100000;
    int k;
    printf("frames.h %s, %s, linearised implicit Euler, 60 CG iterations a step, tetrahedra with 4 neighbours\n",
           frm_version(), sizeof(frm_real) == sizeof(float) ? "float" : "double");
    for (k = 0; k < 2; k++) {
        int nx = sizes[k][0], ny = sizes[k][1], nz = sizes[k][2], steps, i, err;
        frm_model *m;
        frm_cuda *g = NULL;
        double t0, t;
        if (6L * nx * ny * nz > max_samples) break;
        m = body(nx, ny, nz);
        if (!m) {
            printf("size %d: the model could not be created\n", 6 * nx * ny * nz);
            return 1;
        }
        err = frm_cuda_create(m, &g);
        if (err) {
            printf("frm_cuda_create: %s\n", frm_error_string(err));
            return 1;
        }
        err = frm_cuda_step(g); /* warm-up */
        frm_cuda_synchronize(g);
        steps = k == 0 ? 50 : 10;
        t0 = now();
        for (i = 0; i < steps; i++) err = frm_cuda_step(g);
        frm_cuda_synchronize(g);
        t = (now() - t0) / steps;
        row("GPU", frm_model_sample_count(m), frm_model_pair_count(m), t);
        printf("     (device step: %s, %d CG iterations)\n", frm_error_string(err), frm_cuda_last_iterations(g));
        steps = k == 0 ? 5 : 1;
        t0 = now();
        for (i = 0; i < steps; i++) err = frm_model_step(m);
        t = (now() - t0) / steps;
        row("CPU", frm_model_sample_count(m), frm_model_pair_count(m), t);
        printf("     (host step: %s, %d CG iterations)\n", frm_error_string(err), frm_model_last_stats(m)->cg_iterations_last);
        frm_cuda_destroy(g);
        frm_model_destroy(m);
    }
    return 0;
}
