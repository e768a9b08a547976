/* Tests of frames.h's issue 15: the block-tridiagonal solver (against dense Cholesky and
   residuals), the box QP (KKT conditions), the reduced chain model (forces against the
   energy's finite differences, stiffness against the force's, beam closed forms, the full
   frames model of the same cylinder, a moving base, implicit dynamics against the scheme's
   recurrence), actuators (cable and cavity rows against finite differences of their length
   and volume, a cavity's push against its closed form) and the inverse model (reach,
   bounds, the closest pose of an unreachable target), with the validation codes. */
#define FRAMES_IMPLEMENTATION
#include "../frames.h"
#include "test.h"

#define IS_FLOAT (sizeof(frm_real) == sizeof(float))
#define PI 3.14159265358979323846

static unsigned rng_state = 12345u;
static double rnd(void) /* uniform in [-1, 1), deterministic */
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (double)(rng_state >> 8) / 8388608.0 - 1.0;
}

/* ---- block-tridiagonal solver ----------------------------------------------------------- */

/* A random symmetric positive definite block-tridiagonal matrix of n blocks: diagonally
   dominant, then scaled symmetrically by s_k = 10^(spread rnd) per row (the condition number
   grows by up to 10^(4 spread)). */
static void random_btd(int n, double spread, frm_real *diag, frm_real *lower, double *scale)
{
    int i, a, b, k;
    for (k = 0; k < 6 * n; k++) scale[k] = pow(10.0, spread * rnd());
    for (i = 0; i < n; i++) {
        double *D = (double *)calloc(36, sizeof(double)), rs[6] = {0, 0, 0, 0, 0, 0};
        for (a = 0; a < 6; a++)
            for (b = 0; b <= a; b++) D[6 * a + b] = D[6 * b + a] = rnd();
        if (i + 1 < n)
            for (a = 0; a < 36; a++) lower[36 * i + a] = (frm_real)rnd();
        for (a = 0; a < 6; a++) {
            for (b = 0; b < 6; b++) {
                if (b != a) rs[a] += fabs(D[6 * a + b]);
                if (i + 1 < n) rs[a] += fabs((double)lower[36 * i + 6 * b + a]); /* column of A(i+1, i) */
                if (i > 0) rs[a] += fabs((double)lower[36 * (i - 1) + 6 * a + b]);
            }
            D[7 * a] = rs[a] + 0.5 + fabs(rnd());
        }
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) diag[36 * i + 6 * a + b] = (frm_real)(D[6 * a + b] * scale[6 * i + a] * scale[6 * i + b]);
        free(D);
    }
    for (i = 0; i + 1 < n; i++)
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) lower[36 * i + 6 * a + b] = (frm_real)((double)lower[36 * i + 6 * a + b] * scale[6 * (i + 1) + a] * scale[6 * i + b]);
}

/* y = A x from the blocks (double). */
static void btd_apply(int n, const frm_real *diag, const frm_real *lower, const double *x, double *y)
{
    int i, a, b;
    for (i = 0; i < 6 * n; i++) y[i] = 0;
    for (i = 0; i < n; i++)
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) {
                y[6 * i + a] += (double)diag[36 * i + 6 * a + b] * x[6 * i + b];
                if (i + 1 < n) {
                    y[6 * (i + 1) + a] += (double)lower[36 * i + 6 * a + b] * x[6 * i + b];
                    y[6 * i + b] += (double)lower[36 * i + 6 * a + b] * x[6 * (i + 1) + a];
                }
            }
}

/* Dense Cholesky solve of the same matrix (an independent path). */
static int dense_solve(int n, const frm_real *diag, const frm_real *lower, const double *b, double *x)
{
    int N = 6 * n, i, j, k;
    double *A = (double *)calloc((size_t)N * N, sizeof(double));
    for (i = 0; i < N; i++) {
        double e[1];
        (void)e;
    }
    for (i = 0; i < n; i++) {
        int a, c;
        for (a = 0; a < 6; a++)
            for (c = 0; c < 6; c++) {
                A[(size_t)(6 * i + a) * N + 6 * i + c] = (double)diag[36 * i + 6 * a + c];
                if (i + 1 < n) {
                    A[(size_t)(6 * (i + 1) + a) * N + 6 * i + c] = (double)lower[36 * i + 6 * a + c];
                    A[(size_t)(6 * i + c) * N + 6 * (i + 1) + a] = (double)lower[36 * i + 6 * a + c];
                }
            }
    }
    for (j = 0; j < N; j++) {
        double d = A[(size_t)j * N + j];
        for (k = 0; k < j; k++) d -= A[(size_t)j * N + k] * A[(size_t)j * N + k];
        if (!(d > 0)) {
            free(A);
            return -1;
        }
        d = sqrt(d);
        A[(size_t)j * N + j] = d;
        for (i = j + 1; i < N; i++) {
            double s = A[(size_t)i * N + j];
            for (k = 0; k < j; k++) s -= A[(size_t)i * N + k] * A[(size_t)j * N + k];
            A[(size_t)i * N + j] = s / d;
        }
    }
    for (i = 0; i < N; i++) {
        double s = b[i];
        for (k = 0; k < i; k++) s -= A[(size_t)i * N + k] * x[k];
        x[i] = s / A[(size_t)i * N + i];
    }
    for (i = N - 1; i >= 0; i--) {
        double s = x[i];
        for (k = i + 1; k < N; k++) s -= A[(size_t)k * N + i] * x[k];
        x[i] = s / A[(size_t)i * N + i];
    }
    free(A);
    return 0;
}

/* BTD against dense Cholesky for 1 .. 100 blocks and by the residual for 1,000, with
   symmetric scalings up to 10^(+-2.5) (condition numbers up to about 1e10 in double; float
   10^(+-0.5)). Tolerances: the forward error of a backward-stable solve is about cond eps;
   the scaled problem's error is measured in the scaled norm (x_k s_k), where it is
   cond(unscaled) eps (the unscaled matrices are diagonally dominant: cond < 100): 1e-9
   double, 1e-3 float. The residual |A x - b| <= 1e-12 (float 1e-4) |A| |x| row-wise. */
static void test_btd_dense(void)
{
    static const int sizes[] = {1, 2, 7, 60, 1000};
    int s, count = (int)(sizeof sizes / sizeof sizes[0]);
    double spread = IS_FLOAT ? 0.5 : 2.5;
#ifdef TEST_QUICK
    count = 4;
#endif
    for (s = 0; s < count; s++) {
        int n = sizes[s], N = 6 * n, k, err, failed = 7, r;
        frm_real *diag = (frm_real *)calloc((size_t)36 * n, sizeof(frm_real));
        frm_real *lower = (frm_real *)calloc((size_t)36 * n, sizeof(frm_real));
        frm_real *factor = (frm_real *)calloc(frm_btd_factor_size(n), sizeof(frm_real));
        frm_real *b = (frm_real *)calloc((size_t)2 * N, sizeof(frm_real));
        double *sc = (double *)calloc((size_t)N, sizeof(double)), *xt = (double *)calloc((size_t)N, sizeof(double));
        double *bd = (double *)calloc((size_t)N, sizeof(double)), *xd = (double *)calloc((size_t)N, sizeof(double));
        double worst = 0, resid = 0;
        random_btd(n, spread, diag, lower, sc);
        for (k = 0; k < N; k++) xt[k] = rnd() / sc[k];
        btd_apply(n, diag, lower, xt, bd);
        for (k = 0; k < N; k++) b[k] = (frm_real)bd[k], b[N + k] = (frm_real)(2 * bd[k]);
        err = frm_btd_factor(n, diag, n > 1 ? lower : NULL, factor, &failed);
        CHECK_INT(FRM_OK, err);
        CHECK_INT(-1, failed);
        CHECK_INT(FRM_OK, frm_btd_solve(n, factor, 2, b));
        if (n <= 100) {
            CHECK_INT(0, dense_solve(n, diag, lower, bd, xd));
            for (k = 0; k < N; k++) {
                double e1 = fabs((double)b[k] - xd[k]) * sc[k], e2 = fabs((double)b[N + k] - 2 * xd[k]) * sc[k] / 2;
                if (e1 > worst) worst = e1;
                if (e2 > worst) worst = e2;
            }
            CHECK(worst <= (IS_FLOAT ? 1e-3 : 1e-9));
        }
        {
            double *x = (double *)calloc((size_t)N, sizeof(double)), *y = (double *)calloc((size_t)N, sizeof(double));
            for (k = 0; k < N; k++) x[k] = (double)b[k];
            btd_apply(n, diag, lower, x, y);
            for (r = 0; r < n; r++) {
                int a, c;
                for (a = 0; a < 6; a++) {
                    double row = 0; /* sum_j |A_kj| |x_j| */
                    for (c = 0; c < 6; c++) {
                        row += fabs((double)diag[36 * r + 6 * a + c] * x[6 * r + c]);
                        if (r + 1 < n) row += fabs((double)lower[36 * r + 6 * c + a] * x[6 * (r + 1) + c]);
                        if (r > 0) row += fabs((double)lower[36 * (r - 1) + 6 * a + c] * x[6 * (r - 1) + c]);
                    }
                    k = 6 * r + a;
                    if (fabs(y[k] - bd[k]) / row > resid) resid = fabs(y[k] - bd[k]) / row;
                }
            }
            CHECK(resid <= (IS_FLOAT ? 1e-4 : 1e-12));
            free(x);
            free(y);
        }
        printf("    %4d blocks: scaled error vs dense %.2e, relative residual %.2e\n", n, worst, resid);
        free(diag), free(lower), free(factor), free(b), free(sc), free(xt), free(bd), free(xd);
    }
}

/* Refusals: an indefinite block row (reported at its block), a singular one, a non-finite
   entry, bad arguments; the solve's output never holds NaN. */
static void test_btd_refusals(void)
{
    int n = 6, failed = -5, k;
    frm_real diag[36 * 6], lower[36 * 5], factor[72 * 6], b[36];
    double sc[36];
    random_btd(n, 0.0, diag, lower, sc);
    diag[36 * 3 + 7 * 2] = -diag[36 * 3 + 7 * 2]; /* block 3 indefinite */
    CHECK_INT(FRM_ERR_BTD_INDEFINITE, frm_btd_factor(n, diag, lower, factor, &failed));
    CHECK_INT(3, failed);
    random_btd(n, 0.0, diag, lower, sc);
    for (k = 0; k < 36; k++) diag[36 * 4 + k] = 0; /* block 4 with a zero row coupled to nothing on it */
    for (k = 0; k < 36; k++) lower[36 * 3 + k] = lower[36 * 4 + k] = 0;
    CHECK_INT(FRM_ERR_BTD_SINGULAR, frm_btd_factor(n, diag, lower, factor, &failed));
    CHECK_INT(4, failed);
    random_btd(n, 0.0, diag, lower, sc);
    lower[36 * 1 + 3] = (frm_real)NAN;
    CHECK_INT(FRM_ERR_NOT_FINITE, frm_btd_factor(n, diag, lower, factor, &failed));
    CHECK(failed == 1 || failed == 2);
    CHECK_INT(FRM_ERR_ARG, frm_btd_factor(0, diag, lower, factor, NULL));
    CHECK_INT(FRM_ERR_ARG, frm_btd_factor(2, diag, NULL, factor, NULL));
    CHECK_INT(FRM_ERR_ARG, frm_btd_solve(1, factor, 1, NULL));
    /* a factor holding a zero diagonal inverse: the solve stays finite or reports */
    random_btd(n, 0.0, diag, lower, sc);
    CHECK_INT(FRM_OK, frm_btd_factor(n, diag, lower, factor, NULL));
    factor[7] = (frm_real)HUGE_VAL;
    for (k = 0; k < 36; k++) b[k] = 1;
    CHECK_INT(FRM_ERR_NOT_FINITE, frm_btd_solve(n, factor, 1, b));
    for (k = 0; k < 36; k++) CHECK(b[k] == 0);
}

/* The factorisation's two implementations: frm_btd_factor (the AVX-512 path where the build
   has it, double) against frm__btd_factor_rows (the portable rows), entry by entry, with
   NaN in the diagonal blocks' upper triangles (never read), and the same refusal codes and
   blocks. Unscaled, diagonally dominant chains (cond < 100): the paths differ only by
   roundings (fused or separate multiply-adds; the AVX-512 path's deferred column scaling),
   each a few eps relative to the block's entries, times the blocks' condition numbers:
   1e-13 of the block's largest entry (float builds use one path: 0). */
static void test_btd_paths(void)
{
    static const int sizes[] = {1, 2, 7, 60};
    int s, k;
    for (s = 0; s < 4; s++) {
        int n = sizes[s], f1 = 7, f2 = 8, i, a;
        frm_real *diag = (frm_real *)calloc((size_t)36 * n, sizeof(frm_real));
        frm_real *lower = (frm_real *)calloc((size_t)36 * n, sizeof(frm_real));
        frm_real *F1 = (frm_real *)calloc(frm_btd_factor_size(n), sizeof(frm_real));
        frm_real *F2 = (frm_real *)calloc(frm_btd_factor_size(n), sizeof(frm_real));
        double *sc = (double *)calloc((size_t)6 * n, sizeof(double)), worst = 0;
        const double tol = 4.0 * (double)(n + 16) * (IS_FLOAT ? (double)FLT_EPSILON : DBL_EPSILON);
        random_btd(n, 0.0, diag, lower, sc);
        for (i = 0; i < n; i++)
            for (a = 0; a < 6; a++)
                for (k = a + 1; k < 6; k++) diag[36 * i + 6 * a + k] = (frm_real)NAN;
        CHECK_INT(FRM_OK, frm_btd_factor(n, diag, n > 1 ? lower : NULL, F1, &f1));
        CHECK_INT(FRM_OK, frm__btd_factor_rows(n, diag, n > 1 ? lower : NULL, F2, &f2, tol));
        CHECK_INT(-1, f1);
        for (i = 0; i < n; i++) {
            double big = 0, diff = 0;
            for (k = 0; k < 72; k++) {
                double x = fabs((double)F2[72 * i + k]), d = fabs((double)F1[72 * i + k] - (double)F2[72 * i + k]);
                if (x > big) big = x;
                if (!(d <= diff)) diff = d; /* NaN counts */
            }
            if (!(diff / big <= worst)) worst = diff / big;
        }
        CHECK(worst <= (IS_FLOAT ? 0.0 : 1e-13));
        printf("    %2d blocks: largest difference %.2e of the block's largest entry\n", n, worst);
        if (n == 60) { /* refusals: the same code and block from both */
            int b;
            for (b = 0; b < 3; b++) {
                int e1, e2;
                random_btd(n, 0.0, diag, lower, sc);
                if (b == 0) diag[36 * 33 + 7 * 4] = -diag[36 * 33 + 7 * 4]; /* indefinite at block 33 */
                if (b == 1) /* block 41 zero and coupled to nothing: singular there */
                    for (k = 0; k < 36; k++) diag[36 * 41 + k] = lower[36 * 40 + k] = lower[36 * 41 + k] = 0;
                if (b == 2) lower[36 * 12 + 20] = (frm_real)HUGE_VAL;
                f1 = f2 = -7;
                e1 = frm_btd_factor(n, diag, lower, F1, &f1);
                e2 = frm__btd_factor_rows(n, diag, lower, F2, &f2, tol);
                CHECK_INT(b == 0 ? FRM_ERR_BTD_INDEFINITE : b == 1 ? FRM_ERR_BTD_SINGULAR : FRM_ERR_NOT_FINITE, e1);
                CHECK_INT(e2, e1);
                CHECK_INT(f2, f1);
                CHECK_INT(b == 0 ? 33 : b == 1 ? 41 : 12, f1);
            }
        }
        free(diag), free(lower), free(F1), free(F2), free(sc);
    }
}

/* W = J A^-1 J^T for 4 dense random rows against dense solves (same tolerance argument as
   above, unscaled: 1e-10 relative, float 1e-4). */
static void test_btd_compliance_blocks(void)
{
    int n = 25, N = 150, rows = 4, r, q, k;
    frm_real *diag = (frm_real *)calloc(36 * 25, sizeof(frm_real)), *lower = (frm_real *)calloc(36 * 25, sizeof(frm_real));
    frm_real *factor = (frm_real *)calloc(frm_btd_factor_size(n), sizeof(frm_real));
    frm_real *J = (frm_real *)calloc((size_t)rows * N, sizeof(frm_real)), *work = (frm_real *)calloc((size_t)rows * N, sizeof(frm_real));
    frm_real W[16];
    double sc[150], xd[150], bd[150], wmax = 0;
    random_btd(n, 0.0, diag, lower, sc);
    for (k = 0; k < rows * N; k++) J[k] = (frm_real)(k % 7 == 0 || k / N == 3 ? rnd() : 0);
    CHECK_INT(FRM_OK, frm_btd_factor(n, diag, lower, factor, NULL));
    CHECK_INT(FRM_OK, frm_btd_compliance(n, factor, rows, J, W, work));
    for (r = 0; r < 16; r++) wmax = fabs((double)W[r]) > wmax ? fabs((double)W[r]) : wmax;
    for (q = 0; q < rows; q++) {
        for (k = 0; k < N; k++) bd[k] = (double)J[N * q + k];
        CHECK_INT(0, dense_solve(n, diag, lower, bd, xd));
        for (r = 0; r < rows; r++) {
            double s = 0;
            for (k = 0; k < N; k++) s += (double)J[N * r + k] * xd[k];
            CHECK_NEAR(s, (double)W[rows * r + q], (IS_FLOAT ? 1e-4 : 1e-10) * wmax);
        }
    }
    free(diag), free(lower), free(factor), free(J), free(work);
}

/* ---- box QP ------------------------------------------------------------------------------ */

/* KKT conditions on random convex QPs (definite and rank-deficient H), with finite and
   infinite bounds: stationarity on free variables, the multipliers' signs at bounds, and
   feasibility; tolerance 1e-9 of the gradient's scale (the active-set solve is a Cholesky
   of at most 12 variables). */
static void test_qp_kkt(void)
{
    int t, i, j, k;
    for (t = 0; t < 60; t++) {
        int n = 1 + t % 12, rank = t % 3 == 0 && t % 5 && t % 7 ? (n + 1) / 2 : n, /* semi-definite only with finite bounds (else unbounded) */ it = 0, err;
        double H[144], G[144], c[12], lo[12], hi[12], x[12], g[12], scale = 0;
        for (i = 0; i < rank * n; i++) G[i] = rnd();
        for (i = 0; i < n; i++)
            for (j = 0; j < n; j++) {
                double s = 0;
                for (k = 0; k < rank; k++) s += G[n * k + i] * G[n * k + j];
                H[n * i + j] = s;
            }
        for (i = 0; i < n; i++) {
            c[i] = 3 * rnd();
            lo[i] = t % 5 == 0 ? -HUGE_VAL : -0.5 + 0.3 * rnd();
            hi[i] = t % 7 == 0 ? HUGE_VAL : (t % 5 == 0 ? 0.3 : lo[i] + 0.2) + fabs(rnd());
            if (t % 5 == 0 && t % 7 == 0) hi[i] = 1;
            x[i] = 0;
            scale += fabs(c[i]);
        }
        err = frm_qp_box(n, H, c, lo, hi, x, &it);
        CHECK_INT(FRM_OK, err);
        for (i = 0; i < n; i++) {
            double s = c[i];
            for (j = 0; j < n; j++) s += H[n * i + j] * x[j];
            g[i] = s;
            CHECK(x[i] >= lo[i] && x[i] <= hi[i]);
            if (x[i] > lo[i] && x[i] < hi[i])
                CHECK_NEAR(0.0, g[i], 1e-9 * (scale + 1));
            else if (x[i] == lo[i])
                CHECK(g[i] >= -1e-9 * (scale + 1));
            else
                CHECK(g[i] <= 1e-9 * (scale + 1));
        }
    }
    {
        double H[4] = {1, 0, 0, -1}, c[2] = {1, 1}, lo[2] = {0, 0}, hi[2] = {1, 1}, x[2] = {0.5, 0.5};
        double Hn[1] = {NAN}, c1[1] = {0}, l1[1] = {1}, h1[1] = {0}, x1[1] = {0};
        CHECK_INT(FRM_ERR_QP_INDEFINITE, frm_qp_box(2, H, c, lo, hi, x, NULL));
        CHECK(x[0] == x[0] && x[1] == x[1]);
        CHECK_INT(FRM_ERR_ARG, frm_qp_box(1, Hn, c1, lo, hi, x1, NULL));
        CHECK_INT(FRM_ERR_ARG, frm_qp_box(1, H, c1, l1, h1, x1, NULL)); /* lo > hi */
        CHECK_INT(FRM_ERR_ARG, frm_qp_box(0, H, c1, lo, hi, x1, NULL));
    }
}

/* ---- chain model -------------------------------------------------------------------------- */

/* Euler-Bernoulli compliance of a link of length l along local x (E, G, area, I, polar J):
   the cantilever's exact response at its tip to a tip force and moment. */
static void beam_compliance(double l, double E, double G, double A, double I, double Jp, frm_real C[36])
{
    int k;
    for (k = 0; k < 36; k++) C[k] = 0;
    C[0] = (frm_real)(l / (E * A));
    C[7] = C[14] = (frm_real)(l * l * l / (3 * E * I));
    C[21] = (frm_real)(l / (G * Jp));
    C[28] = C[35] = (frm_real)(l / (E * I));
    C[6 * 1 + 5] = C[6 * 5 + 1] = (frm_real)(l * l / (2 * E * I));  /* uy <-> theta_z */
    C[6 * 2 + 4] = C[6 * 4 + 2] = (frm_real)(-l * l / (2 * E * I)); /* uz <-> theta_y */
}

static frm_chain *straight_chain(int n, double len, const frm_real *C, int per_link, const frm_actuator *act, int na,
                                 const frm_real *mass, const frm_real *inertia)
{
    frm_chain_desc d = frm_chain_default_desc();
    frm_real *pos = (frm_real *)calloc((size_t)3 * n, sizeof(frm_real)), *comp = (frm_real *)calloc((size_t)36 * n, sizeof(frm_real));
    frm_chain *c = NULL;
    int i, k;
    for (i = 0; i < n; i++) pos[3 * i] = (frm_real)(len * i / (n - 1));
    for (i = 0; i + 1 < n; i++)
        for (k = 0; k < 36; k++) comp[36 * i + k] = C[(per_link ? 36 * i : 0) + k];
    d.frame_count = n;
    d.positions = pos;
    d.compliances = comp;
    d.actuators = act;
    d.actuator_count = na;
    d.masses = mass;
    d.inertias = inertia;
    d.gravity[2] = 0;
    CHECK_INT(FRM_OK, frm_chain_create(&d, &c));
    free(pos);
    free(comp);
    return c;
}

static void rot_apply(frm_real *q, const double t[3]) /* q = exp(t) q */
{
    double a = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]), s = a > 0 ? sin(a / 2) / a : 0.5, e[4], r[4], nq = 0;
    int k;
    e[0] = s * t[0], e[1] = s * t[1], e[2] = s * t[2], e[3] = cos(a / 2);
    r[0] = e[3] * q[0] + e[0] * q[3] + e[1] * q[2] - e[2] * q[1];
    r[1] = e[3] * q[1] - e[0] * q[2] + e[1] * q[3] + e[2] * q[0];
    r[2] = e[3] * q[2] + e[0] * q[1] - e[1] * q[0] + e[2] * q[3];
    r[3] = e[3] * q[3] - e[0] * q[0] - e[1] * q[1] - e[2] * q[2];
    for (k = 0; k < 4; k++) nq += r[k] * r[k];
    for (k = 0; k < 4; k++) q[k] = (frm_real)(r[k] / sqrt(nq));
}

/* A chain of 5 frames with random SPD compliances, moved to a random large deformation
   (rotations up to 0.6 rad per frame): force = -dE/dq and K = -df/dq by central
   differences along every coordinate (h = 1e-6, float 1e-3; tolerance 1e-6, float 2e-2 of
   the largest entry: the differences' truncation h^2 and round-off eps/h); the symmetric
   product equals the exact one's symmetric part. */
static void test_chain_derivatives(void)
{
    int n = 5, i, k, j;
    frm_real C[36 * 4], pos[15], quat[20], p0[15], q0[20], f[30], fp[30], fm[30], v[30], kv[30];
    double h = IS_FLOAT ? 1e-3 : 1e-6, tol = IS_FLOAT ? 2e-2 : 1e-6, fmax = 0, kmax = 0;
    frm_chain *c;
    for (i = 0; i < 4; i++) {
        double G[36];
        int a, b;
        for (k = 0; k < 36; k++) G[k] = rnd();
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) {
                double s = a == b ? 0.5 : 0;
                for (k = 0; k < 6; k++) s += G[6 * k + a] * G[6 * k + b];
                C[36 * i + 6 * a + b] = (frm_real)(1e-3 * s);
            }
    }
    c = straight_chain(n, 0.4, C, 1, NULL, 0, NULL, NULL);
    if (!c) return;
    for (i = 0; i < n; i++) {
        double t[3] = {0.6 * rnd(), 0.6 * rnd(), 0.6 * rnd()};
        for (k = 0; k < 3; k++) pos[3 * i + k] = (frm_real)(0.1 * i * (k == 0) + 0.02 * rnd());
        quat[4 * i] = quat[4 * i + 1] = quat[4 * i + 2] = 0, quat[4 * i + 3] = 1;
        rot_apply(quat + 4 * i, t);
    }
    memcpy(p0, pos, sizeof pos), memcpy(q0, quat, sizeof quat);
    CHECK_INT(FRM_OK, frm_chain_set_poses(c, pos, quat));
    CHECK_INT(FRM_OK, frm_chain_forces(c, f, NULL));
    for (k = 0; k < 30; k++) fmax = fabs((double)f[k]) > fmax ? fabs((double)f[k]) : fmax;
    for (j = 0; j < 6 * n; j++) {
        double Ep, Em, t[3] = {0, 0, 0};
        int fr = j / 6, comp = j % 6;
        memcpy(pos, p0, sizeof pos), memcpy(quat, q0, sizeof quat);
        if (comp < 3) pos[3 * fr + comp] = (frm_real)((double)pos[3 * fr + comp] + h);
        else t[comp - 3] = h, rot_apply(quat + 4 * fr, t);
        frm_chain_set_poses(c, pos, quat);
        frm_chain_forces(c, fp, &Ep);
        memcpy(pos, p0, sizeof pos), memcpy(quat, q0, sizeof quat);
        if (comp < 3) pos[3 * fr + comp] = (frm_real)((double)pos[3 * fr + comp] - h);
        else t[comp - 3] = -h, rot_apply(quat + 4 * fr, t);
        frm_chain_set_poses(c, pos, quat);
        frm_chain_forces(c, fm, &Em);
        CHECK_NEAR(-(Ep - Em) / (2 * h), (double)f[j], tol * fmax);
        /* column j of K = -(f(+h) - f(-h)) / 2h */
        frm_chain_set_poses(c, p0, q0);
        for (k = 0; k < 30; k++) v[k] = 0;
        v[j] = 1;
        frm_chain_apply_stiffness(c, v, kv, 0);
        for (k = 0; k < 30; k++) kmax = fabs((double)kv[k]) > kmax ? fabs((double)kv[k]) : kmax;
        for (k = 0; k < 30; k++) CHECK_NEAR(-((double)fp[k] - (double)fm[k]) / (2 * h), (double)kv[k], tol * (kmax + 1e-30) * 10);
    }
    {
        frm_real a[30], ka[30], ks[30], kt[30];
        for (k = 0; k < 30; k++) a[k] = (frm_real)rnd();
        frm_chain_apply_stiffness(c, a, ka, 0);
        frm_chain_apply_stiffness(c, a, ks, 1);
        /* K^T a by columns */
        for (j = 0; j < 30; j++) {
            for (k = 0; k < 30; k++) v[k] = 0;
            v[j] = 1;
            frm_chain_apply_stiffness(c, v, kv, 0);
            kt[j] = 0;
            for (k = 0; k < 30; k++) kt[j] += kv[k] * a[k];
        }
        for (k = 0; k < 30; k++) CHECK_NEAR(0.5 * ((double)ka[k] + (double)kt[k]), (double)ks[k], 1e-9 * kmax + (IS_FLOAT ? 1e-4 * kmax : 0));
    }
    frm_chain_destroy(c);
}

/* A straight chain of Euler-Bernoulli links under a small tip load: the cantilever's tip
   deflection P L^3 / (3 E I) (each link's compliance is exact for a linear moment, so the
   chain is exact up to the geometric nonlinearity, (w / L)^2 = 1e-8 here; tolerance 1e-5
   relative, float 1e-3). */
static void test_chain_cantilever_small(void)
{
    double E = 1e7, G = E / 2.6, r = 0.01, A = PI * r * r, I = PI * r * r * r * r / 4, L = 0.5, P = 1e-3;
    frm_real C[36], tipf[3] = {0, 0, (frm_real)-P};
    frm_chain *c;
    beam_compliance(L / 15, E, G, A, I, 2 * I, C);
    c = straight_chain(16, L, C, 0, NULL, 0, NULL, NULL);
    if (!c) return;
    CHECK_INT(FRM_OK, frm_chain_set_external(c, 15, tipf, NULL));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    CHECK_REL(-P * L * L * L / (3 * E * I), (double)frm_chain_positions(c)[3 * 15 + 2], IS_FLOAT ? 1e-3 : 1e-5);
    frm_chain_destroy(c);
}

/* Large rotations: a constant end moment M bends the chain into a circular arc of angle
   theta = M L / (E I) (the elastica of pure bending); at 90 degrees the tip sits at
   (L sin(theta) / theta, 0, L (1 - cos theta) / theta). The chain of 16 links is exact for
   the moment in each link up to the link's linear kinematics: per link the chord of a
   5.6-degree arc differs from the linear link's by (l phi^2 / 6) (0.16 %), and the
   rotation measure 2 sin(phi/2) from phi by 0.04 %; tolerance 0.5 % of L. */
static void test_chain_bend_90(void)
{
    double E = 1e7, G = E / 2.6, r = 0.01, A = PI * r * r, I = PI * r * r * r * r / 4, L = 0.5;
    double th = PI / 2, M = th * E * I / L;
    frm_real C[36], tor[3] = {0, (frm_real)-M, 0};
    const frm_real *x;
    frm_chain *c;
    beam_compliance(L / 16, E, G, A, I, 2 * I, C);
    c = straight_chain(17, L, C, 0, NULL, 0, NULL, NULL);
    if (!c) return;
    CHECK_INT(FRM_OK, frm_chain_set_external(c, 16, NULL, tor));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    x = frm_chain_positions(c);
    printf("    tip (%.5f, %.5f, %.5f) m, arc (%.5f, 0, %.5f)\n", (double)x[48], (double)x[49], (double)x[50],
           L * sin(th) / th, L * (1 - cos(th)) / th);
    CHECK_NEAR(L * sin(th) / th, (double)x[48], 5e-3 * L);
    CHECK_NEAR(0.0, (double)x[49], 1e-6 * L);
    CHECK_NEAR(L * (1 - cos(th)) / th, (double)x[50], 5e-3 * L);
    frm_chain_destroy(c);
}

/* A moving base: the unloaded chain follows a rigid motion of its base exactly (float:
   the 1-rad turn's rounding through 8 links, 3e-4 m). */
static void test_chain_moving_base(void)
{
    double E = 1e7, G = E / 2.6, r = 0.01, A = PI * r * r, I = PI * r * r * r * r / 4;
    frm_real C[36], bp[3] = {(frm_real)0.1, (frm_real)-0.2, (frm_real)0.3}, bq[4] = {0, 0, 0, 1};
    double t[3] = {0.3, -0.5, 0.8}, R[9];
    const frm_real *x;
    frm_chain *c;
    int i, k;
    beam_compliance(0.05, E, G, A, I, 2 * I, C);
    c = straight_chain(9, 0.4, C, 0, NULL, 0, NULL, NULL);
    if (!c) return;
    rot_apply(bq, t);
    CHECK_INT(FRM_OK, frm_chain_set_base(c, bp, bq));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    {
        double x_ = bq[0], y = bq[1], z = bq[2], w = bq[3];
        R[0] = 1 - 2 * (y * y + z * z), R[3] = 2 * (x_ * y + z * w), R[6] = 2 * (x_ * z - y * w);
    }
    x = frm_chain_positions(c);
    for (i = 0; i < 9; i++)
        for (k = 0; k < 3; k++) CHECK_NEAR((double)bp[k] + R[3 * k] * 0.05 * i, (double)x[3 * i + k], IS_FLOAT ? 3e-4 : 1e-10);
    frm_chain_destroy(c);
}

/* Implicit dynamics: a single axial link with a point mass is the oscillator whose implicit
   Euler recurrence is x_{n+1} (1 + h^2 w^2) = x_n + h v_n, v_{n+1} = (x_{n+1} - x_n) / h;
   40 steps against it (the link is linear along its axis: tolerance 1e-9 of the amplitude,
   float 1e-4). */
static void test_chain_dynamics_recurrence(void)
{
    frm_real C[36], mass[2] = {1, 2}, inertia[2] = {1, 1}, tipf[3];
    double k = 100, h = 0.01, w2 = k / 2.0, x = 0, v = 0.3;
    frm_chain *c;
    frm_real vel[12] = {0}, pos[6] = {0, 0, 0, 1, 0, 0}, quat[8] = {0, 0, 0, 1, 0, 0, 0, 1};
    int i, s;
    for (i = 0; i < 36; i++) C[i] = 0;
    for (i = 0; i < 6; i++) C[7 * i] = (frm_real)(i == 0 ? 1 / k : 1e-6);
    c = straight_chain(2, 1.0, C, 0, NULL, 0, mass, inertia);
    if (!c) return;
    (void)tipf;
    (void)vel;
    (void)pos;
    (void)quat;
    /* start with velocity 0.3 m/s along the axis: one step of a constant external impulse
       is not available, so give the velocity through an exact first step of the scheme */
    {
        frm_real f[3] = {(frm_real)(2 * 0.3 / h), 0, 0};
        /* one step under force F from rest: x1 (1 + h^2 w^2) = h^2 F / m */
        CHECK_INT(FRM_OK, frm_chain_set_external(c, 1, f, NULL));
        CHECK_INT(FRM_OK, frm_chain_step(c));
        x = (h * h * (double)f[0] / 2.0) / (1 + h * h * w2);
        v = x / h;
        CHECK_NEAR(1 + x, (double)frm_chain_positions(c)[3], IS_FLOAT ? 1e-6 : 1e-12);
        CHECK_INT(FRM_OK, frm_chain_set_external(c, 1, NULL, NULL));
    }
    for (s = 0; s < 40; s++) {
        double xn = (x + h * v) / (1 + h * h * w2);
        v = (xn - x) / h;
        x = xn;
        CHECK_INT(FRM_OK, frm_chain_step(c));
    }
    CHECK_NEAR(1 + x, (double)frm_chain_positions(c)[3], IS_FLOAT ? 1e-4 * 0.03 : 1e-9 * 0.03);
    CHECK_NEAR(v, (double)frm_chain_velocities(c)[6], IS_FLOAT ? 1e-3 : 1e-8);
    frm_chain_destroy(c);
}

/* ---- actuators ---------------------------------------------------------------------------- */

/* The soft arm of the example and the inverse tests: n frames along x over L, radius 0.03 m
   at the base tapering to 0.015 m, two sections of three cables at 120 degrees (section 1
   ends at the middle frame, section 2 at the tip), routed through every vertebra at 0.8 of
   its radius. Tension bounds 0 .. 60 N. */
#define ARM_N 17
static frm_chain *make_arm(double L, int with_gravity, frm_actuator *act, int *pf, frm_real *pp)
{
    frm_chain_desc d = frm_chain_default_desc();
    frm_real pos[3 * ARM_N], comp[36 * ARM_N], mass[ARM_N], inertia[ARM_N];
    frm_chain *c = NULL;
    int i, a, np = 0;
    double E = 3e6, G = E / 2.8;
    for (i = 0; i < ARM_N; i++) {
        double r = 0.03 - 0.015 * i / (ARM_N - 1.0);
        pos[3 * i] = (frm_real)(L * i / (ARM_N - 1)), pos[3 * i + 1] = pos[3 * i + 2] = 0;
        mass[i] = (frm_real)(1000 * PI * r * r * L / (ARM_N - 1));
        inertia[i] = (frm_real)(mass[i] * r * r / 2);
        if (i + 1 < ARM_N) {
            double rm = 0.03 - 0.015 * (i + 0.5) / (ARM_N - 1.0);
            beam_compliance(L / (ARM_N - 1), E, G, PI * rm * rm, PI * rm * rm * rm * rm / 4, PI * rm * rm * rm * rm / 2,
                            comp + 36 * i);
        }
    }
    for (a = 0; a < 6; a++) {
        int last = a < 3 ? (ARM_N - 1) / 2 : ARM_N - 1, k;
        double ang = 2 * PI * (a % 3) / 3 + (a < 3 ? 0 : PI / 3);
        act[a].kind = FRM_ACTUATOR_CABLE;
        act[a].point_count = last + 1;
        act[a].point_frames = pf + np;
        act[a].points = pp + 3 * np;
        act[a].triangle_count = 0;
        act[a].triangles = NULL;
        act[a].min_effort = 0;
        act[a].max_effort = 60;
        for (k = 0; k <= last; k++) {
            double r = 0.8 * (0.03 - 0.015 * k / (ARM_N - 1.0));
            pf[np + k] = k;
            pp[3 * (np + k)] = pos[3 * k];
            pp[3 * (np + k) + 1] = (frm_real)(r * cos(ang));
            pp[3 * (np + k) + 2] = (frm_real)(r * sin(ang));
        }
        np += last + 1;
    }
    d.frame_count = ARM_N;
    d.positions = pos;
    d.compliances = comp;
    d.masses = mass;
    d.inertias = inertia;
    if (!with_gravity) d.gravity[2] = 0;
    d.actuators = act;
    d.actuator_count = 6;
    CHECK_INT(FRM_OK, frm_chain_create(&d, &c));
    return c;
}

/* The generalized force per unit effort is -dL/dq for a cable, dV/dq for a cavity: both
   checked through the direct simulation's equilibrium. Here: the cable's length falls by
   the work identity. With efforts set, the static solve's equilibrium satisfies
   f_elastic + sum lambda J_a = 0, so the elastic energy's derivative along any admissible
   motion equals the actuators' work; checked by finite differences of the cable length
   along the equilibrium path: dE_el / dlambda = -lambda dL / dlambda (Clapeyron for this
   conservative system, gravity off). Tolerance 1e-4 relative (central differences,
   h = 0.5 N of 20 N). */
static void test_cable_work_identity(void)
{
    frm_actuator act[6];
    int pf[200];
    frm_real pp[600], lam[6] = {20, 0, 0, 0, 0, 0};
    double Lp[6], Lm[6], Ep, Em, h = 0.5;
    frm_chain *c = make_arm(0.5, 0, act, pf, pp);
    if (!c) return;
    lam[0] = (frm_real)(20 + h);
    CHECK_INT(FRM_OK, frm_chain_set_efforts(c, lam));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    Ep = frm_chain_energy(c);
    frm_chain_actuator_measures(c, Lp);
    lam[0] = (frm_real)(20 - h);
    CHECK_INT(FRM_OK, frm_chain_set_efforts(c, lam));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    Em = frm_chain_energy(c);
    frm_chain_actuator_measures(c, Lm);
    CHECK_REL(-20 * (Lp[0] - Lm[0]) / (2 * h), (Ep - Em) / (2 * h), IS_FLOAT ? 5e-2 : 1e-4);
    CHECK(Lp[0] < Lm[0]); /* pulling harder shortens the cable */
    frm_chain_destroy(c);
}

/* A cavity between the base and frame 1: a box of cross-section a x a from x = 0 to the
   frame, closed (12 triangles), its far face fixed to frame 1. Pressure p pushes frame 1 by
   p a^2 along the axis (eq. 5.20: the walls' forces cancel, the far face carries p A): the
   axial displacement is p a^2 l / (E A_link) to first order (tolerance 1e-4 relative: the
   geometric nonlinearity (u / l) is 4e-5). The link's bending and torsion are stiff: the
   one-third rule on the walls' diagonals gives the far face a small torque, whose rotation
   would couple to the axis at second order. */
static void test_cavity_push(void)
{
    static const int tris[36] = {0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
                                 1, 2, 6, 1, 6, 5, 2, 3, 7, 2, 7, 6, 3, 0, 4, 3, 4, 7};
    frm_real pts[24], C[36], p = 1000;
    int pf[8], k;
    double E = 1e7, A = 1e-3, a = 0.02, l = 0.1, V;
    frm_actuator act;
    frm_chain_desc d = frm_chain_default_desc();
    frm_real pos[6] = {0, 0, 0, (frm_real)l, 0, 0};
    frm_chain *c = NULL;
    for (k = 0; k < 8; k++) { /* corners: x = 0 (k < 4, base) or l (frame 1); square in y, z */
        pts[3 * k] = (frm_real)(k < 4 ? 0 : l);
        pts[3 * k + 1] = (frm_real)((k % 4 == 1 || k % 4 == 2) ? a / 2 : -a / 2);
        pts[3 * k + 2] = (frm_real)((k % 4 >= 2) ? a / 2 : -a / 2);
        pf[k] = k < 4 ? 0 : 1;
    }
    beam_compliance(l, E, E / 2.6, A, 1e-5, 2e-5, C);
    memset(&act, 0, sizeof act);
    act.kind = FRM_ACTUATOR_CAVITY;
    act.point_count = 8;
    act.point_frames = pf;
    act.points = pts;
    act.triangle_count = 12;
    act.triangles = tris;
    act.max_effort = (frm_real)1e5;
    d.frame_count = 2;
    d.positions = pos;
    d.compliances = C;
    d.actuators = &act;
    d.actuator_count = 1;
    d.gravity[2] = 0;
    CHECK_INT(FRM_OK, frm_chain_create(&d, &c));
    if (!c) return;
    frm_chain_actuator_measures(c, &V);
    CHECK_REL(a * a * l, V, 1e-12 + (IS_FLOAT ? 1e-6 : 0));
    CHECK_INT(FRM_OK, frm_chain_set_efforts(c, &p));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    CHECK_REL(l + p * a * a * l / (E * A), (double)frm_chain_positions(c)[3], IS_FLOAT ? 1e-6 : 1e-9);
    CHECK_REL(p * a * a * l / (E * A), (double)frm_chain_positions(c)[3] - l, IS_FLOAT ? 3e-3 : 1e-4); /* float: ulp(0.1 m) = 7e-9 m */
    frm_chain_destroy(c);
}

/* ---- inverse model ------------------------------------------------------------------------ */

/* A reachable target (made by the direct simulation with known efforts) is reached within
   0.1 % of the arm's length in at most 6 linearisations, from the straight rest pose, with
   gravity; every effort stays within its bounds after every step. */
static void test_inverse_reach(void)
{
    frm_actuator act[6];
    int pf[200], it;
    frm_real pp[600], lam[6] = {12, 0, 3, 0, 8, 0}, target[3], tip[3];
    double L = 0.5;
    frm_inverse_stats st;
    frm_chain *c = make_arm(L, 1, act, pf, pp);
    if (!c) return;
    CHECK_INT(FRM_OK, frm_chain_set_efforts(c, lam));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    CHECK_INT(FRM_OK, frm_chain_effector(c, target, NULL));
    frm_chain_destroy(c);
    c = make_arm(L, 1, act, pf, pp);
    CHECK_INT(FRM_OK, frm_chain_solve_static(c)); /* sagging under gravity, no effort */
    for (it = 0; it < 6; it++) {
        int a, err = frm_chain_inverse_step(c, target, 1e-3 * L, &st);
        CHECK(err == FRM_OK);
        for (a = 0; a < 6; a++) CHECK(frm_chain_efforts(c)[a] >= 0 && frm_chain_efforts(c)[a] <= 60);
        if (st.reached) break;
    }
    frm_chain_effector(c, tip, NULL);
    printf("    reached in %d linearisations: error %.2e m (%.4f %% of L), %d QP iterations\n", it + 1, st.error,
           100 * st.error / L, st.qp_iterations);
    CHECK(st.reached);
    CHECK(st.error <= 1e-3 * L);
    CHECK(it < 6);
    /* the solve does the same in one call */
    frm_chain_destroy(c);
    c = make_arm(L, 1, act, pf, pp);
    CHECK_INT(FRM_OK, frm_chain_inverse_solve(c, target, 1e-4 * L, 10, &st));
    CHECK(st.error <= 1e-4 * L);
    frm_chain_destroy(c);
}

/* An unreachable target (far beyond the arm, sideways) gives FRM_ERR_UNREACHABLE, finite
   state, bounds kept, and the closest pose: no single effort moved within its bounds by 1 N
   (direct simulation) brings the tip closer by more than 1e-6 m plus 1e-3 of the change it
   makes (a first-order KKT check of the nonlinear problem at bounds and free efforts). */
static void test_inverse_unreachable(void)
{
    frm_actuator act[6];
    int pf[200], a, k, err;
    frm_real pp[600], target[3] = {(frm_real)0.2, (frm_real)0.6, (frm_real)0.3}, lam[6], tip[3];
    double L = 0.5, d0;
    frm_inverse_stats st;
    frm_chain *c = make_arm(L, 0, act, pf, pp);
    if (!c) return;
    err = frm_chain_inverse_solve(c, target, 1e-3 * L, 30, &st);
    CHECK_INT(FRM_ERR_UNREACHABLE, err);
    CHECK(!st.reached);
    frm_chain_effector(c, tip, NULL);
    for (k = 0; k < 3; k++) CHECK(tip[k] == tip[k]);
    d0 = sqrt((tip[0] - target[0]) * (tip[0] - target[0]) + (tip[1] - target[1]) * (tip[1] - target[1]) +
              (tip[2] - target[2]) * (tip[2] - target[2]));
    memcpy(lam, frm_chain_efforts(c), sizeof lam);
    printf("    closest distance %.4f m, efforts %.2f %.2f %.2f %.2f %.2f %.2f N\n", d0, (double)lam[0], (double)lam[1],
           (double)lam[2], (double)lam[3], (double)lam[4], (double)lam[5]);
    for (a = 0; a < 6; a++) CHECK(lam[a] >= 0 && lam[a] <= 60);
    for (a = 0; a < 6; a++) {
        int s;
        for (s = -1; s <= 1; s += 2) {
            frm_real l2[6];
            double dd;
            memcpy(l2, lam, sizeof l2);
            l2[a] = (frm_real)((double)l2[a] + s);
            if (l2[a] < 0 || l2[a] > 60) continue;
            frm_chain_destroy(c);
            c = make_arm(L, 0, act, pf, pp);
            CHECK_INT(FRM_OK, frm_chain_set_efforts(c, l2));
            CHECK_INT(FRM_OK, frm_chain_solve_static(c));
            frm_chain_effector(c, tip, NULL);
            dd = sqrt((tip[0] - target[0]) * (tip[0] - target[0]) + (tip[1] - target[1]) * (tip[1] - target[1]) +
                      (tip[2] - target[2]) * (tip[2] - target[2]));
            CHECK(dd >= d0 - 1e-5);
        }
    }
    frm_chain_destroy(c);
}

/* An orientation target too (effector_orientation = 1, 6 rows for 6 cables): a pose made
   by the direct simulation with known efforts is reached in position (1e-4 of L) and
   orientation (1e-3 rad) by frm_chain_inverse_solve from the rest pose. */
static void test_inverse_orientation(void)
{
    frm_actuator act[6];
    int pf[200], k;
    frm_real pp[600], lam[6] = {10, 0, 4, 0, 6, 2}, target[6], tip[3], q[4], pos[3 * ARM_N], comp[36 * ARM_N];
    double L = 0.5, th;
    frm_inverse_stats st;
    frm_chain_desc d = frm_chain_default_desc();
    frm_chain *c = make_arm(L, 0, act, pf, pp), *c2 = NULL;
    if (!c) return;
    CHECK_INT(FRM_OK, frm_chain_set_efforts(c, lam));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    CHECK_INT(FRM_OK, frm_chain_effector(c, tip, q));
    /* the rest orientation is the identity: the target rotation vector is log(q) */
    th = 2 * atan2(sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2]), (double)q[3]);
    for (k = 0; k < 3; k++) {
        double s = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2]);
        target[k] = tip[k];
        target[3 + k] = (frm_real)(s > 0 ? th * (double)q[k] / s : 0);
    }
    frm_chain_destroy(c);
    /* the same arm with the orientation rows */
    for (k = 0; k < ARM_N; k++) {
        double rm = 0.03 - 0.015 * (k + 0.5) / (ARM_N - 1.0);
        pos[3 * k] = (frm_real)(L * k / (ARM_N - 1)), pos[3 * k + 1] = pos[3 * k + 2] = 0;
        if (k + 1 < ARM_N)
            beam_compliance(L / (ARM_N - 1), 3e6, 3e6 / 2.8, PI * rm * rm, PI * rm * rm * rm * rm / 4, PI * rm * rm * rm * rm / 2,
                            comp + 36 * k);
    }
    d.frame_count = ARM_N;
    d.positions = pos;
    d.compliances = comp;
    d.gravity[2] = 0;
    d.actuators = act;
    d.actuator_count = 6;
    d.effector_orientation = 1;
    CHECK_INT(FRM_OK, frm_chain_create(&d, &c2));
    if (!c2) return;
    CHECK_INT(FRM_OK, frm_chain_inverse_solve(c2, target, 1e-4 * L, 10, &st));
    frm_chain_effector(c2, tip, q);
    printf("    position and orientation reached in %d linearisations: error %.2e\n", st.linearizations, st.error);
    for (k = 0; k < 3; k++) CHECK_NEAR((double)target[k], (double)tip[k], 1e-4 * L);
    CHECK(st.error <= 1e-4 * L);
    frm_chain_destroy(c2);
}

/* ---- validation --------------------------------------------------------------------------- */

static void test_chain_validation(void)
{
    frm_chain_desc d = frm_chain_default_desc();
    frm_real pos[9] = {0, 0, 0, (frm_real)0.1, 0, 0, (frm_real)0.2, 0, 0}, C[72], pts[6] = {0, 0, 0, (frm_real)0.2, 0, 0};
    int pf[2] = {0, 2}, k;
    frm_actuator act;
    frm_chain *c = (frm_chain *)&c;
    frm_real lam = -1;
    beam_compliance(0.1, 1e7, 4e6, 1e-3, 1e-7, 2e-7, C);
    beam_compliance(0.1, 1e7, 4e6, 1e-3, 1e-7, 2e-7, C + 36);
    memset(&act, 0, sizeof act);
    act.kind = FRM_ACTUATOR_CABLE;
    act.point_count = 2;
    act.point_frames = pf;
    act.points = pts;
    act.max_effort = 10;
    d.frame_count = 3;
    d.positions = pos;
    d.compliances = C;
    d.actuators = &act;
    d.actuator_count = 1;
    CHECK_INT(FRM_OK, frm_chain_create(&d, &c));
    CHECK_INT(FRM_ERR_ACTUATOR_BOUNDS, frm_chain_set_efforts(c, &lam));
    lam = 11;
    CHECK_INT(FRM_ERR_ACTUATOR_BOUNDS, frm_chain_set_efforts(c, &lam));
    frm_chain_destroy(c);
    C[36 + 7] = -C[36 + 7]; /* link 1 indefinite */
    CHECK_INT(FRM_ERR_COMPLIANCE, frm_chain_create(&d, &c));
    CHECK(c == NULL);
    C[36 + 7] = -C[36 + 7];
    C[36 + 1] = (frm_real)((double)C[36 + 6] + 1e-3 * (double)C[36 + 7]); /* not symmetric */
    CHECK_INT(FRM_ERR_COMPLIANCE, frm_chain_create(&d, &c));
    C[36 + 1] = C[36 + 6];
    pf[1] = 3; /* a point on a frame outside the chain */
    CHECK_INT(FRM_ERR_ACTUATOR, frm_chain_create(&d, &c));
    pf[1] = 2;
    act.min_effort = 5, act.max_effort = 4; /* min > max */
    CHECK_INT(FRM_ERR_ACTUATOR_BOUNDS, frm_chain_create(&d, &c));
    act.min_effort = -1, act.max_effort = 4; /* a cable cannot push */
    CHECK_INT(FRM_ERR_ACTUATOR_BOUNDS, frm_chain_create(&d, &c));
    act.min_effort = 0;
    pts[3] = 0; /* coincident cable points */
    CHECK_INT(FRM_ERR_ACTUATOR, frm_chain_create(&d, &c));
    pts[3] = (frm_real)0.2;
    d.frame_count = 1;
    CHECK_INT(FRM_ERR_FRAME_COUNT, frm_chain_create(&d, &c));
    d.frame_count = 3;
    d.internal_cookie = 0;
    CHECK_INT(FRM_ERR_DESC, frm_chain_create(&d, &c));
    memset(&d, 0xA5, sizeof d);
    CHECK_INT(FRM_ERR_DESC, frm_chain_create(&d, &c));
    for (k = 0; k < 1; k++) CHECK(c == NULL);
}

/* ---- reduced chain against the full frames model -------------------------------------------- */

/* A square cylinder a x a x (segs * l), cells: cx along the axis per segment, 2 x 2 across;
   node i = ix + (nx + 1) (iy + 3 iz). */
static frm_model *box_beam(int ncells_x, double len, double a, double E)
{
    int nx = ncells_x, nn = (nx + 1) * 9, nc = nx * 4, i, cc, k, err;
    frm_real *nodes = (frm_real *)calloc((size_t)3 * nn, sizeof(frm_real));
    int *hexes = (int *)calloc((size_t)8 * nc, sizeof(int));
    frm_sampling s;
    frm_desc d = frm_model_default_desc();
    frm_model *m = NULL;
    for (i = 0; i < nn; i++) {
        nodes[3 * i] = (frm_real)(len * (i % (nx + 1)) / nx);
        nodes[3 * i + 1] = (frm_real)(a / 2 * (i / (nx + 1) % 3) - a / 2);
        nodes[3 * i + 2] = (frm_real)(a / 2 * (i / (nx + 1) / 3) - a / 2);
    }
    for (cc = 0; cc < nc; cc++)
        for (k = 0; k < 8; k++)
            hexes[8 * cc + k] = (cc % nx + (k & 1)) + (nx + 1) * ((cc / nx % 2 + (k >> 1 & 1)) + 3 * (cc / nx / 2 + (k >> 2)));
    err = frm_sampling_hexes(&s, nodes, nn, hexes, nc, 2, FRM_QUADRATURE_SUBCELL, NULL);
    CHECK_INT(FRM_OK, err);
    if (!err) {
        frm_sampling_apply(&s, &d);
        d.material.young_modulus = (frm_real)E;
        d.material.poisson_ratio = (frm_real)0.3;
        d.gravity[2] = 0;
        CHECK_INT(FRM_OK, frm_model_create(&d, &m));
        frm_sampling_free(&s);
    }
    free(nodes);
    free(hexes);
    return m;
}

/* The thesis's fig. 5.4 check: the compliance of one segment (eqs. 5.1-5.11 through
   frm_chain_link_compliance on the segment's frames sub-model, ends rigid) chained segs
   times against the full frames model of the whole cylinder under a small tip load (the
   end face's nodes share it): tip deflection within 1 % (the thesis: 0.72 %; the reduced
   model holds every segment's end sections rigid, the full one does not). */
static void test_chain_vs_frames_cylinder(void)
{
    int segs = 5, cps = 4, i, nx = segs * cps, nb = 9;
    double a = 0.1, l = 0.4, E = 1e6, P = 0.1, full = 0, red;
    frm_model *sub = box_beam(cps, l, a, E), *m;
    int ea[9], eb[9];
    frm_real C[36], origin[3] = {(frm_real)l, 0, 0}, f[3] = {0, 0, (frm_real)(-P / 9)}, tip[3] = {0, 0, (frm_real)-P};
    frm_chain *c;
    if (!sub) return;
    for (i = 0; i < nb; i++) ea[i] = (cps + 1) * i, eb[i] = (cps + 1) * i + cps;
    CHECK_INT(FRM_OK, frm_chain_link_compliance(sub, ea, nb, eb, nb, origin, C));
    frm_model_destroy(sub);
    c = straight_chain(segs + 1, l * segs, C, 0, NULL, 0, NULL, NULL);
    if (!c) return;
    CHECK_INT(FRM_OK, frm_chain_set_external(c, segs, tip, NULL));
    CHECK_INT(FRM_OK, frm_chain_solve_static(c));
    red = (double)frm_chain_positions(c)[3 * segs + 2];
    frm_chain_destroy(c);
    m = box_beam(nx, l * segs, a, E);
    if (!m) return;
    for (i = 0; i < nb; i++) {
        frm_model_fix_frame(m, (nx + 1) * i);
        frm_model_set_external(m, (nx + 1) * i + nx, f, NULL);
    }
    {
        int err = frm_model_solve_static(m);
        if (IS_FLOAT && err) { /* the full model's float limits, not the chain's (measured: FRM_ERR_NO_CONVERGENCE) */
            printf("    float: the full frames model's solve returned %s; compared in double builds\n", frm_error_string(err));
            frm_model_destroy(m);
            return;
        }
        CHECK_INT(FRM_OK, err);
    }
    for (i = 0; i < nb; i++) full += (double)frm_model_displacements(m)[3 * ((nx + 1) * i + nx) + 2] / nb;
    printf("    tip deflection: full frames model %.6e m, reduced chain %.6e m (%+.3f %%)\n", full, red,
           100 * (red - full) / full);
    CHECK_REL(full, red, 1e-2);
    frm_model_destroy(m);
}

/* Nothing allocates after frm_chain_create: the inverse step and the dynamics run on the
   block carved at creation (a counting allocator). */
static int alloc_count;
static void *count_alloc(size_t size, size_t align, void *user)
{
    char *raw = (char *)malloc(size + align + sizeof(void *)), *p;
    (void)user;
    alloc_count++;
    if (!raw) return NULL;
    p = raw + sizeof(void *);
    p += (align - (size_t)p % align) % align;
    memcpy(p - sizeof(void *), &raw, sizeof(void *));
    return p;
}
static void count_free(void *ptr, size_t size, void *user)
{
    void *raw;
    (void)size, (void)user;
    memcpy(&raw, (char *)ptr - sizeof(void *), sizeof(void *));
    free(raw);
}

static void test_chain_no_allocation(void)
{
    frm_chain_desc d = frm_chain_default_desc();
    frm_real pos[9] = {0, 0, 0, (frm_real)0.1, 0, 0, (frm_real)0.2, 0, 0}, C[72], pts[6] = {0, (frm_real)0.01, 0, (frm_real)0.2, (frm_real)0.01, 0};
    frm_real m3[3] = {(frm_real)0.1, (frm_real)0.1, (frm_real)0.1}, target[3] = {(frm_real)0.19, (frm_real)0.02, 0};
    int pf[2] = {0, 2};
    frm_actuator act;
    frm_chain *c = NULL;
    frm_inverse_stats st;
    beam_compliance(0.1, 1e6, 4e5, 1e-3, 1e-7, 2e-7, C);
    beam_compliance(0.1, 1e6, 4e5, 1e-3, 1e-7, 2e-7, C + 36);
    memset(&act, 0, sizeof act);
    act.kind = FRM_ACTUATOR_CABLE;
    act.point_count = 2;
    act.point_frames = pf;
    act.points = pts;
    act.max_effort = 100;
    d.frame_count = 3;
    d.positions = pos;
    d.compliances = C;
    d.masses = m3;
    d.inertias = m3;
    d.actuators = &act;
    d.actuator_count = 1;
    d.allocator.alloc = count_alloc;
    d.allocator.free = count_free;
    alloc_count = 0;
    CHECK_INT(FRM_OK, frm_chain_create(&d, &c));
    CHECK_INT(1, alloc_count);
    if (!c) return;
    frm_chain_inverse_step(c, target, 1e-6, &st);
    frm_chain_step(c);
    frm_chain_solve_static(c);
    CHECK_INT(1, alloc_count);
    frm_chain_destroy(c);
}

/* ---- FRM_LINEAR_SOLVER_BTD in the frames solvers ------------------------------------------ */

/* The displacements of n frames of models a and b agree within tol (m). */
static void check_same_displacements(const frm_model *a, const frm_model *b, int n, double tol)
{
    int i;
    for (i = 0; i < 3 * n; i++)
        CHECK_NEAR((double)frm_model_displacements(a)[i], (double)frm_model_displacements(b)[i], tol);
}

/* A rod of frames whose samples each see two consecutive frames (a chain pattern): the
   static sag under gravity and ten implicit Euler steps with FRM_LINEAR_SOLVER_BTD equal
   CG's (both to a Newton tolerance of 1e-10: 1e-6 of the sag; float 1e-4: 1e-3); a model
   that is not a chain is refused at creation with FRM_ERR_SOLVER. */
static frm_model *rod_model(frm_linear_solver solver, int chain, int pairs)
{
    enum { NF = 12, PER = 4 };
    frm_real fp[3 * NF], sp[3 * NF * PER], vol[NF * PER], w[3 * NF * PER], g[9 * NF * PER];
    int start[NF * PER + 1], fr[3 * NF * PER], s = 0, e = 0, i, q, k;
    double h = 0.1, r = 0.01;
    frm_desc d = frm_model_default_desc();
    frm_model *m = NULL;
    for (i = 0; i < NF; i++) fp[3 * i] = (frm_real)(h * i), fp[3 * i + 1] = fp[3 * i + 2] = 0;
    for (i = 0; i + 1 < NF; i++)
        for (q = 0; q < PER; q++) {
            double t = (q + 0.5) / PER, y = (q % 2 ? r : -r) * 0.5, z = (q / 2 ? r : -r) * 0.5;
            sp[3 * s] = (frm_real)(h * (i + t)), sp[3 * s + 1] = (frm_real)y, sp[3 * s + 2] = (frm_real)z;
            vol[s] = (frm_real)(h * 4 * r * r / PER);
            start[s] = e;
            fr[e] = i, w[e] = (frm_real)(1 - t), g[3 * e] = (frm_real)(-1 / h), g[3 * e + 1] = g[3 * e + 2] = 0, e++;
            fr[e] = i + 1, w[e] = (frm_real)t, g[3 * e] = (frm_real)(1 / h), g[3 * e + 1] = g[3 * e + 2] = 0, e++;
            if (!chain && i + 2 < NF && q == 0) { /* a third, farther neighbour with zero weight */
                fr[e] = i + 2, w[e] = 0, g[3 * e] = g[3 * e + 1] = g[3 * e + 2] = 0, e++;
            }
            s++;
        }
    start[s] = e;
    (void)k;
    d.frame_positions = fp;
    d.frame_count = NF;
    d.sample_positions = sp;
    d.sample_volumes = vol;
    d.sample_count = s;
    d.neighbor_start = start;
    d.neighbor_frames = fr;
    d.neighbor_weights = w;
    d.neighbor_gradients = g;
    d.material.young_modulus = (frm_real)1e8;
    d.material.density = 1000;
    d.linear_solver = solver;
    if (pairs) d.stiffness_mode = FRM_STIFFNESS_PAIRS;
    d.newton_tolerance = (frm_real)(IS_FLOAT ? 1e-4 : 1e-10);
    d.cg_tolerance = (frm_real)(IS_FLOAT ? 1e-5 : 1e-12);
    d.time_step = (frm_real)0.01;
    CHECK_INT(chain || solver != FRM_LINEAR_SOLVER_BTD ? FRM_OK : FRM_ERR_SOLVER, frm_model_create(&d, &m));
    if (m) frm_model_fix_frame(m, 0);
    return m;
}

static void test_frames_btd_solver(void)
{
    frm_model *a = rod_model(FRM_LINEAR_SOLVER_CG, 1, 0), *b = rod_model(FRM_LINEAR_SOLVER_BTD, 1, 0);
    double sag, tol = IS_FLOAT ? 1e-3 : 1e-6;
    int i;
    if (!a || !b) return;
    CHECK_INT(FRM_OK, frm_model_solve_static(a));
    CHECK_INT(FRM_OK, frm_model_solve_static(b));
    sag = fabs((double)frm_model_displacements(a)[3 * 11 + 2]);
    CHECK(sag > 1e-4);
    check_same_displacements(a, b, 12, tol * sag);
    printf("    rod sag %.6e m (CG) and %.6e m (BTD); BTD's last static solve: %d CG iterations\n", sag,
           fabs((double)frm_model_displacements(b)[3 * 11 + 2]), frm_model_last_stats(b)->cg_iterations);
    for (i = 0; i < 10; i++) {
        CHECK_INT(FRM_OK, frm_model_step(a));
        CHECK_INT(FRM_OK, frm_model_step(b));
    }
    check_same_displacements(a, b, 12, tol * sag);
    frm_model_destroy(a);
    frm_model_destroy(b);
    a = rod_model(FRM_LINEAR_SOLVER_BTD, 0, 0);
    CHECK(a == NULL);
}

/* FRM_LINEAR_SOLVER_AUTO (the default) chooses BTD for the chain-pattern rod, whose
   static sag and ten implicit steps then equal CG's to the same tolerances as above (the
   two solvers' answers differ by their solve tolerances only), and for a rod of
   frm_sampling_curve (same check of the sag; in float, where AUTO keeps CG (see the
   manual), with BTD chosen: its refinement stalls and CG finishes); CG for the same rod with a
   third, farther neighbour (not a chain), for the chain in the matrix-free pair mode (no
   assembled blocks), and for a 3D block of hexahedra; explicit choices are kept; anchors
   (not in BTD's assembled blocks) switch an AUTO model to CG while they are set, and the
   anchored answer equals CG's. */
static void test_frames_btd_auto(void)
{
    frm_model *a = rod_model(FRM_LINEAR_SOLVER_CG, 1, 0), *b = rod_model(FRM_LINEAR_SOLVER_AUTO, 1, 0), *c;
    double sag, tol = IS_FLOAT ? 1e-3 : 1e-6;
    int i, k, chosen = IS_FLOAT ? FRM_LINEAR_SOLVER_CG : FRM_LINEAR_SOLVER_BTD; /* AUTO on a chain */
    if (!a || !b) return;
    CHECK_INT(FRM_LINEAR_SOLVER_CG, frm_model_linear_solver(a));
    CHECK_INT(chosen, frm_model_linear_solver(b));
    CHECK_INT(FRM_LINEAR_SOLVER_AUTO, frm_model_default_desc().linear_solver);
    CHECK_INT(FRM_LINEAR_SOLVER_COUNT, frm_model_linear_solver(NULL));
    CHECK_INT(FRM_OK, frm_model_solve_static(a));
    CHECK_INT(FRM_OK, frm_model_solve_static(b));
    sag = fabs((double)frm_model_displacements(a)[3 * 11 + 2]);
    CHECK(sag > 1e-4);
    check_same_displacements(a, b, 12, tol * sag);
    for (i = 0; i < 10; i++) {
        CHECK_INT(FRM_OK, frm_model_step(a));
        CHECK_INT(FRM_OK, frm_model_step(b));
    }
    check_same_displacements(a, b, 12, tol * sag);
    frm_model_destroy(a);
    frm_model_destroy(b);
    { /* anchors: the rod's tip pulled toward a point 1 cm up, AUTO's model against CG's */
        frm_probe_desc pd = frm_probe_default_desc();
        frm_probe *p = NULL;
        frm_real pt[3] = {(frm_real)1.1, 0, 0}, target[3] = {(frm_real)1.1, 0, (frm_real)0.01}, ks = (frm_real)1e3;
        a = rod_model(FRM_LINEAR_SOLVER_CG, 1, 0), b = rod_model(FRM_LINEAR_SOLVER_AUTO, 1, 0);
        c = rod_model(FRM_LINEAR_SOLVER_BTD, 1, 0);
        if (a && b && c && frm_probe_create(b, &pd, pt, 1, &p) == FRM_OK) {
            CHECK_INT(FRM_ERR_ARG, frm_model_set_anchors(c, p, &ks, target)); /* chosen BTD: refused */
            CHECK_INT(FRM_LINEAR_SOLVER_BTD, frm_model_linear_solver(c));
            CHECK_INT(FRM_OK, frm_model_set_anchors(a, p, &ks, target));
            CHECK_INT(FRM_OK, frm_model_set_anchors(b, p, &ks, target));
            CHECK_INT(FRM_LINEAR_SOLVER_CG, frm_model_linear_solver(b));
            CHECK_INT(FRM_OK, frm_model_solve_static(a));
            CHECK_INT(FRM_OK, frm_model_solve_static(b));
            sag = fabs((double)frm_model_displacements(a)[3 * 11 + 2]);
            for (i = 0; i < 12; i++)
                for (k = 0; k < 3; k++)
                    CHECK_NEAR((double)frm_model_displacements(a)[3 * i + k], (double)frm_model_displacements(b)[3 * i + k], tol * sag);
            CHECK_INT(FRM_OK, frm_model_set_anchors(b, NULL, NULL, NULL));
            CHECK_INT(chosen, frm_model_linear_solver(b));
            CHECK_INT(FRM_OK, frm_model_solve_static(b));
        } else
            CHECK(0);
        frm_probe_destroy(p);
        frm_model_destroy(a);
        frm_model_destroy(b);
        frm_model_destroy(c);
    }
    { /* a rod of frm_sampling_curve (16 segments along x, each station between its two
         frames): BTD under AUTO, the same cantilever sag as CG (tolerances as above) */
        frm_real x[3 * 17], sec[2] = {(frm_real)0.02, (frm_real)0.02};
        frm_sampling cs;
        frm_model *r[2] = {NULL, NULL};
        memset(x, 0, sizeof x);
        for (i = 0; i <= 16; i++) x[3 * i] = (frm_real)(0.05 * i);
        CHECK_INT(FRM_OK, frm_sampling_curve(&cs, x, 17, sec, NULL, NULL));
        for (k = 0; k < 2; k++) {
            frm_desc d = frm_model_default_desc();
            frm_sampling_apply(&cs, &d);
            d.material.young_modulus = (frm_real)1e8;
            d.material.density = 1000;
            /* float: BTD chosen explicitly (AUTO keeps CG there), whose iterative refinement
               stalls on this rod and hands over to CG (without that the static solve failed) */
            d.linear_solver = k ? FRM_LINEAR_SOLVER_CG : IS_FLOAT ? FRM_LINEAR_SOLVER_BTD : FRM_LINEAR_SOLVER_AUTO;
            d.newton_tolerance = (frm_real)(IS_FLOAT ? 1e-4 : 1e-10);
            d.cg_tolerance = (frm_real)(IS_FLOAT ? 1e-5 : 1e-12);
            CHECK_INT(FRM_OK, frm_model_create(&d, &r[k]));
            if (!r[k]) continue;
            CHECK_INT(k ? FRM_LINEAR_SOLVER_CG : FRM_LINEAR_SOLVER_BTD, frm_model_linear_solver(r[k]));
            CHECK_INT(FRM_OK, frm_model_fix_frame(r[k], 0));
            CHECK_INT(FRM_OK, frm_model_solve_static(r[k]));
        }
        if (r[0] && r[1]) {
            sag = fabs((double)frm_model_displacements(r[1])[3 * 16 + 2]);
            CHECK(sag > 1e-4);
            printf("    curve rod sag %.6e m (CG) and %.6e m (%s)\n", sag,
                   fabs((double)frm_model_displacements(r[0])[3 * 16 + 2]), IS_FLOAT ? "BTD chosen" : "AUTO: BTD");
            for (i = 0; i < 17; i++)
                for (k = 0; k < 3; k++)
                    CHECK_NEAR((double)frm_model_displacements(r[0])[3 * i + k], (double)frm_model_displacements(r[1])[3 * i + k],
                               tol * sag);
        }
        frm_model_destroy(r[0]);
        frm_model_destroy(r[1]);
        frm_sampling_free(&cs);
    }
    a = rod_model(FRM_LINEAR_SOLVER_AUTO, 0, 0); /* not a chain */
    b = rod_model(FRM_LINEAR_SOLVER_AUTO, 1, 1); /* a chain, but no assembled blocks */
    c = box_beam(4, 0.4, 0.1, 1e7);              /* default desc: AUTO; 3D */
    CHECK(a && b && c);
    if (a) CHECK_INT(FRM_LINEAR_SOLVER_CG, frm_model_linear_solver(a));
    if (b) CHECK_INT(FRM_LINEAR_SOLVER_CG, frm_model_linear_solver(b));
    if (c) CHECK_INT(FRM_LINEAR_SOLVER_CG, frm_model_linear_solver(c));
    frm_model_destroy(a);
    frm_model_destroy(b);
    frm_model_destroy(c);
}

static const test_case cases[] = {
    TEST(test_btd_dense),
    TEST(test_btd_refusals),
    TEST(test_btd_paths),
    TEST(test_btd_compliance_blocks),
    TEST(test_qp_kkt),
    TEST(test_chain_derivatives),
    TEST(test_chain_cantilever_small),
    TEST(test_chain_bend_90),
    TEST(test_chain_moving_base),
    TEST(test_chain_dynamics_recurrence),
    TEST(test_cable_work_identity),
    TEST(test_cavity_push),
    TEST(test_inverse_reach),
    TEST(test_inverse_unreachable),
    TEST(test_inverse_orientation),
    TEST(test_chain_validation),
    TEST(test_chain_vs_frames_cylinder),
    TEST(test_chain_no_allocation),
    TEST(test_frames_btd_solver),
    TEST(test_frames_btd_auto),
};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
