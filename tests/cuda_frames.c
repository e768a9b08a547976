/* cuda_frames.c - GPU tests of the CUDA companion (frames_cuda.cu, issue 16): K v, forces
   and one linearised implicit Euler step on the device against the CPU path, a device run
   repeated bit for bit, a provoked failed step keeping the last valid state, refusals.
   Built and run by tests/test_cuda.sh only where a GPU is present (C99, linked with
   frames_cuda.o and -lcudart); FRM_REAL as frames_cuda.o was compiled.

   Tolerances. The device evaluates the same expressions (frames.h >>passes) but nvcc
   contracts a * b + c into fused multiply-adds and the CG's dot products add in a tree
   order, so single values differ by a few roundings: forces and K v by at most about 16
   (terms per frame) x 8 (roundings per term) eps relative to the largest entry of a
   deformed, unbalanced state (no cancellation below it): 1e-12 in double, 1e-4 in float
   (eps 1.2e-7, a margin of about 8 for the pairs' sums in float). A step solves to
   cg_tolerance (1e-10 double, 1e-5 float) on both sides, so the velocity change agrees to
   a few times that relative to its size: positions after one step within 1e-8 (double)
   and 1e-3 (float) of the step's largest displacement. */
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#include "../frames_cuda.h"
#include "test.h"

#define IS_FLOAT (sizeof(frm_real) == sizeof(float))

/* a 4 x 1 x 1 m beam of 8 x 2 x 2 hexahedral cells (tet = 0, 8 sub-cell samples each) or
   the same cells split into 6 tetrahedra with one sample (tet = 1: frames with unseen
   rotations, the stabilisation's general pairs), clamped at x = 0 */
static frm_model *beam(int tet, int law)
{
    static frm_real nodes[3 * 81];
    static int hexes[8 * 32], tets[4 * 6 * 32];
    static const int K[6][4] = {{0, 1, 3, 7}, {0, 3, 2, 7}, {0, 2, 6, 7}, {0, 6, 4, 7}, {0, 4, 5, 7}, {0, 5, 1, 7}};
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m = NULL;
    int i, c, a, err;
    for (i = 0; i < 81; i++) {
        nodes[3 * i] = (frm_real)(0.5 * (i % 9));
        nodes[3 * i + 1] = (frm_real)(0.5 * (i / 9 % 3));
        nodes[3 * i + 2] = (frm_real)(0.5 * (i / 27));
    }
    for (c = 0; c < 32; c++)
        for (a = 0; a < 8; a++)
            hexes[8 * c + a] = (c % 8 + (a & 1)) + 9 * ((c / 8 % 2 + (a >> 1 & 1)) + 3 * (c / 16 + (a >> 2)));
    if (!tet)
        err = frm_sampling_hexes(&s, nodes, 81, hexes, 32, 2, FRM_QUADRATURE_SUBCELL, NULL);
    else {
        int t = 0, j, q;
        for (c = 0; c < 32; c++)
            for (j = 0; j < 6; j++, t++) {
                const frm_real *p[4];
                double u[3], v[3], w[3], det;
                for (q = 0; q < 4; q++) tets[4 * t + q] = hexes[8 * c + K[j][q]], p[q] = nodes + 3 * tets[4 * t + q];
                for (q = 0; q < 3; q++) u[q] = p[1][q] - p[0][q], v[q] = p[2][q] - p[0][q], w[q] = p[3][q] - p[0][q];
                det = u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
                if (det < 0) q = tets[4 * t + 1], tets[4 * t + 1] = tets[4 * t + 2], tets[4 * t + 2] = q;
            }
        err = frm_sampling_tets(&s, nodes, 81, tets, t, 1, NULL, NULL);
    }
    if (err) return NULL;
    frm_sampling_apply(&s, &d);
    d.material.law = (frm_law)law;
    d.material.young_modulus = 1e6;
    d.material.density = 1000;
    d.material.c1 = 2e5;
    d.material.c2 = 5e4;
    d.material.bulk_modulus = 2e6;
    d.time_step = 0.01;
    d.integrator = FRM_IMPLICIT_EULER_LINEARIZED;
    d.stiffness_mode = FRM_STIFFNESS_PAIRS;
    d.cg_tolerance = IS_FLOAT ? 1e-5 : 1e-10;
    d.cg_max_iterations = 5000;
    err = frm_model_create(&d, &m);
    frm_sampling_free(&s);
    if (err) return NULL;
    for (i = 0; i < 81; i += 9) frm_model_fix_frame(m, i);
    return m;
}

/* a deformed state: two CPU steps under gravity (unbalanced, so forces do not cancel) */
static void deform(frm_model *m)
{
    frm_real g[3] = {2, 0, -40};
    frm_model_set_gravity(m, g);
    frm_model_step(m);
    frm_model_step(m);
}

static double max_abs(const frm_real *a, int n)
{
    double t = 0;
    int k;
    for (k = 0; k < n; k++)
        if (fabs((double)a[k]) > t) t = fabs((double)a[k]);
    return t;
}

static void test_forces_and_kv(void)
{
    int tet, k;
    double tol = IS_FLOAT ? 1e-4 : 1e-12;
    for (tet = 0; tet < 2; tet++) {
        frm_model *m = beam(tet, FRM_LAW_NEO_HOOKEAN);
        frm_cuda *g = NULL;
        const frm_real *fc;
        frm_real *fg, *v, *kc, *kg;
        int n;
        REQUIRE(m);
        deform(m);
        n = 6 * frm_model_frame_count(m);
        fg = (frm_real *)malloc(sizeof(frm_real) * 4 * (size_t)n);
        REQUIRE(fg);
        v = fg + n, kc = v + n, kg = kc + n;
        CHECK_INT(0, frm_cuda_create(m, &g));
        REQUIRE(g);
        CHECK_INT(0, frm_model_forces(m, &fc));
        CHECK_INT(0, frm_cuda_forces(g, fg));
        for (k = 0; k < n; k++) CHECK_NEAR((double)fc[k], (double)fg[k], tol * max_abs(fc, n));
        for (k = 0; k < n; k++) v[k] = (frm_real)(1e-3 * ((k * 37) % 11 - 5));
        CHECK_INT(0, frm_model_prepare_stiffness(m));
        CHECK_INT(0, frm_model_apply_stiffness(m, v, kc, 1));
        CHECK_INT(0, frm_cuda_linearize(g));
        CHECK_INT(0, frm_cuda_apply_stiffness(g, v, kg));
        for (k = 0; k < n; k++) CHECK_NEAR((double)kc[k], (double)kg[k], tol * max_abs(kc, n));
        printf("    %s: max |f| %.3e N, max |K v| %.3e\n", tet ? "tetrahedra" : "hexahedra", max_abs(fc, n), max_abs(kc, n));
        frm_cuda_destroy(g);
        frm_model_destroy(m);
        free(fg);
    }
}

static void test_step(void)
{
    int tet, k;
    double tol = IS_FLOAT ? 1e-3 : 1e-8;
    for (tet = 0; tet < 2; tet++) {
        frm_model *a = beam(tet, FRM_LAW_SVK), *b = beam(tet, FRM_LAW_SVK);
        frm_cuda *g = NULL;
        int n;
        double scale = 0;
        REQUIRE(a && b);
        deform(a);
        deform(b);
        n = 3 * frm_model_frame_count(a);
        CHECK_INT(0, frm_cuda_create(b, &g));
        REQUIRE(g);
        {
            frm_real *x0 = (frm_real *)malloc(sizeof(frm_real) * (size_t)n);
            REQUIRE(x0);
            memcpy(x0, frm_model_positions(a), sizeof(frm_real) * (size_t)n);
            CHECK_INT(0, frm_model_step(a));
            CHECK_INT(0, frm_cuda_step(g));
            CHECK_INT(0, frm_cuda_download(g, b));
            for (k = 0; k < n; k++)
                if (fabs((double)(frm_model_positions(a)[k] - x0[k])) > scale) scale = fabs((double)(frm_model_positions(a)[k] - x0[k]));
            CHECK(scale > 0);
            for (k = 0; k < n; k++) CHECK_NEAR((double)frm_model_positions(a)[k], (double)frm_model_positions(b)[k], tol * scale);
            printf("    %s: step moved %.3e m; CG %d (CPU %d) iterations\n", tet ? "tetrahedra" : "hexahedra", scale,
                   frm_cuda_last_iterations(g), frm_model_last_stats(a)->cg_iterations_last);
            free(x0);
        }
        frm_cuda_destroy(g);
        frm_model_destroy(a);
        frm_model_destroy(b);
    }
}

static void test_repeatable(void)
{
    frm_model *a = beam(1, FRM_LAW_NEO_HOOKEAN), *b = beam(1, FRM_LAW_NEO_HOOKEAN);
    frm_cuda *ga = NULL, *gb = NULL;
    int k, n;
    REQUIRE(a && b);
    deform(a);
    deform(b);
    CHECK_INT(0, frm_cuda_create(a, &ga));
    CHECK_INT(0, frm_cuda_create(b, &gb));
    REQUIRE(ga && gb);
    for (k = 0; k < 5; k++) {
        CHECK_INT(0, frm_cuda_step(ga));
        CHECK_INT(0, frm_cuda_step(gb));
    }
    CHECK_INT(0, frm_cuda_download(ga, a));
    CHECK_INT(0, frm_cuda_download(gb, b));
    n = frm_model_frame_count(a);
    CHECK(!memcmp(frm_model_positions(a), frm_model_positions(b), sizeof(frm_real) * 3 * (size_t)n));
    CHECK(!memcmp(frm_model_orientations(a), frm_model_orientations(b), sizeof(frm_real) * 4 * (size_t)n));
    CHECK(!memcmp(frm_model_velocities(a), frm_model_velocities(b), sizeof(frm_real) * 6 * (size_t)n));
    frm_cuda_destroy(ga);
    frm_cuda_destroy(gb);
    frm_model_destroy(a);
    frm_model_destroy(b);
}

/* a step under a load that inverts samples (1e9 N on the tip frames) fails with
   FRM_ERR_INVERTED (or FRM_ERR_NO_CONVERGENCE / NOT_FINITE if CG gives up first) and the
   device state stays the last valid one, bit for bit */
static void test_failed_step_keeps_state(void)
{
    frm_model *m = beam(0, FRM_LAW_NEO_HOOKEAN);
    frm_cuda *g = NULL;
    frm_real *before, f[3] = {0, 0, (frm_real)-1e9}, t[3] = {0, 0, 0};
    int n, i, err;
    REQUIRE(m);
    deform(m);
    CHECK_INT(0, frm_cuda_create(m, &g));
    REQUIRE(g);
    CHECK_INT(0, frm_cuda_step(g));
    CHECK_INT(0, frm_cuda_download(g, m));
    n = frm_model_frame_count(m);
    before = (frm_real *)malloc(sizeof(frm_real) * 13 * (size_t)n);
    REQUIRE(before);
    memcpy(before, frm_model_positions(m), sizeof(frm_real) * 3 * (size_t)n);
    memcpy(before + 3 * n, frm_model_orientations(m), sizeof(frm_real) * 4 * (size_t)n);
    memcpy(before + 7 * n, frm_model_velocities(m), sizeof(frm_real) * 6 * (size_t)n);
    for (i = 8; i < 81; i += 9) frm_model_set_external(m, i, f, t);
    CHECK_INT(0, frm_cuda_upload_state(g, m));
    err = frm_cuda_step(g);
    printf("    the overloaded step: %s\n", frm_error_string(err));
    CHECK(err == FRM_ERR_INVERTED || err == FRM_ERR_NO_CONVERGENCE || err == FRM_ERR_NOT_FINITE);
    CHECK_INT(0, frm_cuda_download(g, m));
    CHECK(!memcmp(before, frm_model_positions(m), sizeof(frm_real) * 3 * (size_t)n));
    CHECK(!memcmp(before + 3 * n, frm_model_orientations(m), sizeof(frm_real) * 4 * (size_t)n));
    CHECK(!memcmp(before + 7 * n, frm_model_velocities(m), sizeof(frm_real) * 6 * (size_t)n));
    free(before);
    frm_cuda_destroy(g);
    frm_model_destroy(m);
}

static void test_refusals(void)
{
    frm_model *m = beam(0, FRM_LAW_MOONEY_RIVLIN);
    frm_cuda *g = (frm_cuda *)&g;
    REQUIRE(m);
    CHECK_INT(FRM_ERR_DEVICE, frm_cuda_create(m, &g));
    CHECK(g == NULL);
    CHECK_INT(FRM_ERR_ARG, frm_cuda_create(NULL, &g));
    frm_model_destroy(m);
}

static const test_case cases[] = {TEST(test_forces_and_kv), TEST(test_step), TEST(test_repeatable),
                                  TEST(test_failed_step_keeps_state), TEST(test_refusals)};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
