/* Tests of tensormass.h's accuracy features (issue 19): the BDF2 integrator against the
   closed-form amplification factor of the scheme and its order of accuracy, its history
   rules; point probes and tmass_displacements; modal analysis against closed forms. */
#define TENSORMASS_IMPLEMENTATION
#include "../tensormass.h"
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "test.h"
#include "fixtures.h"

#define IS_FLOAT (sizeof(tmass_real) == sizeof(float))
#define PI 3.14159265358979323846

/* ---- small complex arithmetic (C and C++ alike) ---------------------------------------- */

typedef struct cplx {
    double re, im;
} cplx;

static cplx c_make(double re, double im)
{
    cplx z;
    z.re = re;
    z.im = im;
    return z;
}
static cplx c_div(cplx a, cplx b)
{
    double d = b.re * b.re + b.im * b.im;
    return c_make((a.re * b.re + a.im * b.im) / d, (a.im * b.re - a.re * b.im) / d);
}
static cplx c_sqrt(cplx a) /* principal root */
{
    double r = sqrt(a.re * a.re + a.im * a.im), re = sqrt(0.5 * (r + a.re)), im = sqrt(0.5 * (r - a.re));
    return c_make(re, a.im < 0 ? -im : im);
}
static double c_abs(cplx a) { return sqrt(a.re * a.re + a.im * a.im); }
static double c_arg(cplx a) { return atan2(a.im, a.re); }

/* The principal root z of each scheme on u'' = -omega^2 u (x_n ~ Re(A z^n)), w = omega h:
   backward Euler z = 1 / (1 - i w); BDF2, from (3/2 - i w) z^2 - 2 z + 1/2 = 0,
   z = (2 + sqrt(1 + 2 i w)) / (3 - 2 i w). */
static cplx amplification(tmass_integrator integ, double w)
{
    if (integ == TMASS_BDF2) {
        cplx r = c_sqrt(c_make(1.0, 2.0 * w));
        return c_div(c_make(2.0 + r.re, r.im), c_make(3.0, -2.0 * w));
    }
    return c_div(c_make(1.0, 0.0), c_make(1.0, -w));
}

/* Period error (T_h - T) / T and amplitude decay per period 1 - |z|^(T_h / h) of the root z
   of a step h = T / steps_per_period: T_h = 2 pi h / arg z. */
static void root_figures(cplx z, double w, double *period_error, double *decay)
{
    double theta = c_arg(z);
    *period_error = w / theta - 1.0;
    *decay = 1.0 - pow(c_abs(z), 2.0 * PI / theta);
}

/* ---- a one-mode oscillator --------------------------------------------------------------- */

/* A regular tetrahedron of edge 1 m with its base pinned: by the threefold symmetry about
   the apex's axis, the apex moving along z is one mode, u'' = -omega^2 u, omega^2 =
   K_zz / m_apex (the apex's vertex tensor over its lumped mass). */
static tmass_model *one_mode(tmass_model_kind kind, double mass_damping, double *omega)
{
    static const double s3 = 1.7320508075688772;
    tmass_real nodes[12];
    int tet[4] = {0, 1, 2, 3}, i;
    tmass_real g[3] = {0, 0, 0};
    tmass_desc d = tmass_default_desc();
    tmass_model *m = NULL;
    double base[9] = {1.0 / s3, 0, 0, -0.5 / s3, 0.5, 0, -0.5 / s3, -0.5, 0}, h = sqrt(2.0 / 3.0);
    for (i = 0; i < 9; i++) nodes[i] = (tmass_real)base[i];
    nodes[9] = nodes[10] = 0;
    nodes[11] = (tmass_real)h;
    d.rest_positions = nodes;
    d.node_count = 4;
    d.tets = tet;
    d.tet_count = 1;
    d.kind = kind;
    d.young_modulus = (tmass_real)2e3;
    d.poisson_ratio = (tmass_real)0.25;
    d.density = (tmass_real)1000;
    d.mass_damping = (tmass_real)mass_damping;
    d.cg_tolerance = (tmass_real)(IS_FLOAT ? 1e-7 : kind == TMASS_TENSOR_MASS ? 1e-15 : 1e-12);
    d.newton_tolerance = (tmass_real)(IS_FLOAT ? 1e-6 : 1e-10);
    if (tmass_create(&d, &m)) return NULL;
    for (i = 0; i < 3; i++) tmass_fix_node(m, i);
    tmass_set_gravity(m, g);
    if (kind == TMASS_TENSOR_MASS) {
        tmass_real K[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
        tmass_vertex_tensor(m, 3, K);
        *omega = sqrt((double)K[8] / (double)tmass_masses(m)[3]);
    } else { /* three springs k = E l0 ... : read the stiffness back from a small move */
        tmass_real x[12];
        memcpy(x, tmass_rest_positions(m), sizeof x);
        x[11] = (tmass_real)((double)x[11] + 1e-6);
        tmass_set_positions(m, x);
        *omega = sqrt(-(double)tmass_forces(m)[11] / 1e-6 / (double)tmass_masses(m)[3]);
        memcpy(x, tmass_rest_positions(m), sizeof x);
        tmass_set_positions(m, x);
    }
    return m;
}

/* Starts the apex at u_z = amplitude, at rest. */
static void pluck(tmass_model *m, double amplitude)
{
    tmass_real x[12];
    memcpy(x, tmass_rest_positions(m), sizeof x);
    x[11] = (tmass_real)((double)x[11] + amplitude);
    tmass_set_positions(m, x);
}

/* The principal root of a run: x_{n+1} = p x_n - q x_{n-1} holds exactly for a sequence
   Re(A z^n) with p = 2 Re z, q = |z|^2; least squares over samples [first, count) once
   BDF2's parasitic root (|z_2| about 1/3 per step) has died out. */
static cplx fitted_root(const double *x, int first, int count)
{
    double s00 = 0, s01 = 0, s11 = 0, b0 = 0, b1 = 0, det, p, q;
    int n;
    for (n = first; n + 1 < count; n++) {
        s00 += x[n] * x[n];
        s01 += x[n] * x[n - 1];
        s11 += x[n - 1] * x[n - 1];
        b0 += x[n + 1] * x[n];
        b1 += x[n + 1] * x[n - 1];
    }
    /* p s00 - q s01 = b0, p s01 - q s11 = b1 */
    det = s01 * s01 - s00 * s11;
    p = (s01 * b1 - s11 * b0) / det;
    q = (s00 * b1 - s01 * b0) / det;
    return c_make(0.5 * p, sqrt(q > 0.25 * p * p ? q - 0.25 * p * p : 0.0));
}

/* Runs `steps` steps of T / steps_per_period from the plucked state and fits the root. */
static int measure_root(tmass_model_kind kind, tmass_integrator integ, int steps_per_period, int periods,
                        cplx *z, double *w)
{
    double omega = 0, T, *x;
    int count = steps_per_period * periods + 60, s, err = TMASS_OK;
    tmass_model *m = one_mode(kind, 0.0, &omega);
    if (!m) return -1;
    T = 2 * PI / omega;
    *w = omega * T / steps_per_period;
    x = (double *)malloc(sizeof(double) * (size_t)count);
    pluck(m, 1e-3);
    for (s = 0; s < count && !err; s++) {
        err = tmass_step_ex(m, (tmass_real)(T / steps_per_period), integ);
        x[s] = (double)m->disp[11];
    }
    if (!err) *z = fitted_root(x, 40, count);
    free(x);
    tmass_destroy(m);
    return err;
}

/* ---- BDF2 ----------------------------------------------------------------------------- */

/* Period error and amplitude decay per period of implicit Euler and BDF2 at T/20 .. T/400
   equal the schemes' closed forms (from their amplification factors) to 3 digits. Float:
   the decay of BDF2 (3e-6 per period at T/400) is below the float state's resolution, so
   float checks T/20 and T/50 only. */
static void test_bdf2_amplification_closed_form(void)
{
    static const int N[4] = {20, 50, 100, 400};
    static const tmass_integrator integ[2] = {TMASS_IMPLICIT_EULER, TMASS_BDF2};
    int k, i;
    for (k = 0; k < 2; k++)
        for (i = 0; i < (IS_FLOAT ? 2 : 4); i++) {
            cplx z, zt;
            double w = 0, pe, de, pt, dt_;
            int periods = N[i] >= 100 ? 2 : 5;
            REQUIRE(measure_root(TMASS_TENSOR_MASS, integ[k], N[i], periods, &z, &w) == TMASS_OK);
            zt = amplification(integ[k], w);
            root_figures(z, w, &pe, &de);
            root_figures(zt, w, &pt, &dt_);
            printf("    %-14s T/%-3d period error %+.4e (theory %+.4e), decay per period %.4e (theory %.4e)\n",
                   k ? "BDF2" : "implicit Euler", N[i], pe, pt, de, dt_);
            CHECK_REL(pt, pe, IS_FLOAT ? 1e-2 : 1e-3);
            CHECK_REL(dt_, de, IS_FLOAT ? 1e-2 : 1e-3);
        }
}

/* Exact u(T) of the plucked oscillator: u0 cos(omega T). */
static double one_mode_error(tmass_model_kind kind, tmass_integrator integ, int steps, double periods)
{
    double omega = 0, T, e, amp = IS_FLOAT ? 1e-2 : 1e-3;
    int s;
    tmass_model *m = one_mode(kind, 0.0, &omega);
    if (!m) return -1;
    T = periods * 2 * PI / omega;
    pluck(m, amp);
    amp = (double)m->disp[11]; /* the rounded start */
    for (s = 0; s < steps; s++)
        if (tmass_step_ex(m, (tmass_real)(T / steps), integ)) {
            tmass_destroy(m);
            return -1;
        }
    e = fabs((double)m->disp[11] - amp * cos(omega * T));
    tmass_destroy(m);
    return e;
}

/* Order of accuracy: halving dt divides the error at t = 1.125 periods (phase and
   amplitude errors both show there) by 4 for BDF2 (its
   backward Euler start step included: a local error O(h^2), once) and by 2 for implicit
   Euler; the period error from the fitted root too. The spring model's BDF2 (its Newton
   minimisation with beta, xbar, vbar) as well, at a small amplitude (|u| / l = 1e-3) where
   its frequency is the linearised one; its reference is the same model's RK4 at a tiny
   step (the exact solution of the nonlinear oscillator is not in closed form). */
static void test_bdf2_order(void)
{
    int N = 100, k;
    double e[3], ie[2], pe[2];
    for (k = 0; k < 3; k++) e[k] = one_mode_error(TMASS_TENSOR_MASS, TMASS_BDF2, N << k, 1.125);
    for (k = 0; k < 2; k++) ie[k] = one_mode_error(TMASS_TENSOR_MASS, TMASS_IMPLICIT_EULER, (N << k) * 4, 1.125);
    printf("    BDF2 N = %d, %d, %d: error %.3e %.3e %.3e, ratios %.3f %.3f (4)\n", N, 2 * N, 4 * N, e[0], e[1],
           e[2], e[0] / e[1], e[1] / e[2]);
    printf("    implicit Euler N = %d, %d: error %.3e %.3e, ratio %.3f (2)\n", 4 * N, 8 * N, ie[0], ie[1],
           ie[0] / ie[1]);
    REQUIRE(e[0] > 0 && e[1] > 0 && e[2] > 0 && ie[0] > 0 && ie[1] > 0);
    CHECK_NEAR(4.0, e[0] / e[1], 0.3);
    CHECK_NEAR(4.0, e[1] / e[2], 0.2);
    CHECK_NEAR(2.0, ie[0] / ie[1], 0.1);
    for (k = 0; k < 2; k++) {
        cplx z;
        double w = 0, d;
        REQUIRE(measure_root(TMASS_TENSOR_MASS, TMASS_BDF2, 50 << k, 3, &z, &w) == TMASS_OK);
        root_figures(z, w, &pe[k], &d);
    }
    printf("    BDF2 period error T/50 %.4e, T/100 %.4e: ratio %.3f (4)\n", pe[0], pe[1], pe[0] / pe[1]);
    CHECK_NEAR(4.0, pe[0] / pe[1], 0.1);
    if (!IS_FLOAT) { /* springs */
        double r[3], ref;
        tmass_model *m;
        double omega = 0, T;
        int s, err;
        m = one_mode(TMASS_MASS_SPRING, 0.0, &omega);
        REQUIRE(m != NULL);
        T = 1.125 * 2 * PI / omega;
        pluck(m, 1e-3);
        for (s = 0; s < 4000; s++) tmass_step_ex(m, (tmass_real)(T / 4000), TMASS_RK4);
        ref = (double)m->disp[11];
        tmass_destroy(m);
        for (k = 0; k < 3; k++) {
            m = one_mode(TMASS_MASS_SPRING, 0.0, &omega);
            REQUIRE(m != NULL);
            pluck(m, 1e-3);
            for (s = 0, err = 0; s < (N << k) && !err; s++) err = tmass_step_ex(m, (tmass_real)(T / (N << k)), TMASS_BDF2);
            CHECK_INT(TMASS_OK, err);
            r[k] = fabs((double)m->disp[11] - ref);
            tmass_destroy(m);
        }
        printf("    springs BDF2 N = %d, %d, %d: error %.3e %.3e %.3e, ratios %.3f %.3f (4)\n", N, 2 * N, 4 * N,
               r[0], r[1], r[2], r[0] / r[1], r[1] / r[2]);
        CHECK_NEAR(4.0, r[0] / r[1], 0.3);
        CHECK_NEAR(4.0, r[1] / r[2], 0.3);
    }
}

/* A general oscillator (the tetrahedron of test_tensormass.c's integrator tests): three
   nodes pinned, the fourth u'' = -A u - alpha u' - beta A u', A = K_33 / m_3 (3x3). */
static tmass_model *oscillator3(double mass_damping, double stiffness_damping, double A[9])
{
    tmass_real nodes[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2f, 0.3f, 1};
    int tet[4] = {0, 1, 2, 3}, i;
    tmass_real K[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, g[3] = {0, 0, 0};
    tmass_desc d = tmass_default_desc();
    tmass_model *m = NULL;
    d.rest_positions = nodes;
    d.node_count = 4;
    d.tets = tet;
    d.tet_count = 1;
    d.young_modulus = (tmass_real)2e3;
    d.poisson_ratio = (tmass_real)0.25;
    d.density = (tmass_real)1000;
    d.mass_damping = (tmass_real)mass_damping;
    d.stiffness_damping = (tmass_real)stiffness_damping;
    d.cg_tolerance = (tmass_real)(IS_FLOAT ? 1e-7 : 1e-15);
    if (tmass_create(&d, &m)) return NULL;
    for (i = 0; i < 3; i++) tmass_fix_node(m, i);
    tmass_set_gravity(m, g);
    tmass_vertex_tensor(m, 3, K);
    for (i = 0; i < 9; i++) A[i] = (double)K[i] / (double)tmass_masses(m)[3];
    return m;
}

static void mat3_vec(const double A[9], const double *x, double *y)
{
    int r;
    for (r = 0; r < 3; r++) y[r] = A[3 * r] * x[0] + A[3 * r + 1] * x[1] + A[3 * r + 2] * x[2];
}

static void solve3(const double M[9], const double b[3], double x[3])
{
    double det = M[0] * (M[4] * M[8] - M[5] * M[7]) - M[1] * (M[3] * M[8] - M[5] * M[6]) +
                 M[2] * (M[3] * M[7] - M[4] * M[6]);
    double inv[9];
    inv[0] = (M[4] * M[8] - M[5] * M[7]) / det;
    inv[1] = (M[2] * M[7] - M[1] * M[8]) / det;
    inv[2] = (M[1] * M[5] - M[2] * M[4]) / det;
    inv[3] = (M[5] * M[6] - M[3] * M[8]) / det;
    inv[4] = (M[0] * M[8] - M[2] * M[6]) / det;
    inv[5] = (M[2] * M[3] - M[0] * M[5]) / det;
    inv[6] = (M[3] * M[7] - M[4] * M[6]) / det;
    inv[7] = (M[1] * M[6] - M[0] * M[7]) / det;
    inv[8] = (M[0] * M[4] - M[1] * M[3]) / det;
    mat3_vec(inv, b, x);
}

/* BDF2 with mass and stiffness damping from a moving start equals the scheme's own
   recurrence, written here in its two-step form (not through the library's substitution):
       3 u1 - 4 u0 + u_-1 = 2 h v1,   3 v1 - 4 v0 + v_-1 = 2 h (-A u1 - alpha v1 - beta A v1)
   i.e. ((3 + 2 h alpha) I + (4 h^2 / 3 + 2 h beta) A) v1 = 4 v0 - v_-1 - 2 h / 3 A (4 u0 - u_-1),
   after one backward Euler step
       (I (1 + h alpha) + (h^2 + h beta) A) v1 = v0 - h A u0,   u1 = u0 + h v1. */
static void test_bdf2_damped_recurrence(void)
{
    double A[9], u[3] = {0.01, -0.004, 0.006}, v[3] = {-0.02, 0.01, 0.015}, up[3], vp[3];
    double alpha = 0.7, beta = 0.01, h = 0.05, worst = 0.0, scale = 0.0;
    tmass_real x[12], w[12];
    tmass_model *m = oscillator3(alpha, beta, A);
    int i, s, r;
    REQUIRE(m != NULL);
    memcpy(x, tmass_rest_positions(m), sizeof x);
    memset(w, 0, sizeof w);
    for (i = 0; i < 3; i++) {
        x[9 + i] = (tmass_real)((double)x[9 + i] + u[i]);
        w[9 + i] = (tmass_real)v[i];
    }
    tmass_set_positions(m, x);
    tmass_set_velocities(m, w);
    for (i = 0; i < 3; i++) { /* the model's rounded start */
        u[i] = (double)m->disp[9 + i];
        v[i] = (double)tmass_velocities(m)[9 + i];
    }
    for (s = 0; s < 60; s++) {
        double Mx[9], b[3], Au[3], v1[3], ub[3];
        CHECK_INT(TMASS_OK, tmass_step_ex(m, (tmass_real)h, TMASS_BDF2));
        if (s == 0) {
            mat3_vec(A, u, Au);
            for (r = 0; r < 9; r++) Mx[r] = (h * h + h * beta) * A[r] + (r % 4 == 0 ? 1.0 + h * alpha : 0.0);
            for (r = 0; r < 3; r++) b[r] = v[r] - h * Au[r];
            solve3(Mx, b, v1);
            for (r = 0; r < 3; r++) ub[r] = u[r] + h * v1[r];
        } else {
            for (r = 0; r < 3; r++) ub[r] = 4.0 * u[r] - up[r];
            mat3_vec(A, ub, Au);
            for (r = 0; r < 9; r++)
                Mx[r] = (4.0 * h * h / 3.0 + 2.0 * h * beta) * A[r] + (r % 4 == 0 ? 3.0 + 2.0 * h * alpha : 0.0);
            for (r = 0; r < 3; r++) b[r] = 4.0 * v[r] - vp[r] - 2.0 * h / 3.0 * Au[r];
            solve3(Mx, b, v1);
            for (r = 0; r < 3; r++) ub[r] = (4.0 * u[r] - up[r] + 2.0 * h * v1[r]) / 3.0;
        }
        for (r = 0; r < 3; r++) {
            double d;
            up[r] = u[r];
            vp[r] = v[r];
            u[r] = ub[r];
            v[r] = v1[r];
            d = fabs((double)m->disp[9 + r] - u[r]);
            if (d > worst) worst = d;
            if (fabs(u[r]) > scale) scale = fabs(u[r]);
            d = fabs((double)tmass_velocities(m)[9 + r] - v[r]);
            if (d * h > worst) worst = d * h;
        }
    }
    printf("    60 damped BDF2 steps: max |u - u_recurrence| / max |u| = %.2e\n", worst / scale);
    CHECK(worst < (IS_FLOAT ? 1e-5 : 1e-12) * scale);
    tmass_destroy(m);
}

/* tmass_set_damping: a model given its damping after creation steps bit-identically to
   one created with it (implicit Euler and BDF2); bad values refused, nothing changed. */
static void test_set_damping(void)
{
    double A[9];
    tmass_model *a = oscillator3(0.0, 0.0, A), *b = oscillator3(0.7, 0.01, A);
    tmass_real x[12];
    int s;
    REQUIRE(a && b);
    CHECK_INT(TMASS_ERR_DAMPING, tmass_set_damping(a, (tmass_real)-1, 0));
    CHECK_INT(TMASS_ERR_DAMPING, tmass_set_damping(a, 0, (tmass_real)(0.0 * HUGE_VAL)));
    CHECK_INT(TMASS_ERR_ARG, tmass_set_damping(NULL, 0, 0));
    CHECK(a->mass_damping == 0 && a->stiffness_damping == 0);
    CHECK_INT(TMASS_OK, tmass_set_damping(a, (tmass_real)0.7, (tmass_real)0.01));
    memcpy(x, tmass_rest_positions(a), sizeof x);
    x[9] = (tmass_real)((double)x[9] + 0.01);
    tmass_set_positions(a, x);
    tmass_set_positions(b, x);
    for (s = 0; s < 20; s++) {
        tmass_integrator integ = s < 10 ? TMASS_IMPLICIT_EULER : TMASS_BDF2;
        CHECK_INT(TMASS_OK, tmass_step_ex(a, (tmass_real)0.05, integ));
        CHECK_INT(TMASS_OK, tmass_step_ex(b, (tmass_real)0.05, integ));
    }
    CHECK(memcmp(a->disp, b->disp, sizeof(tmass_real) * 12) == 0 && memcmp(a->vel, b->vel, sizeof(tmass_real) * 12) == 0);
    tmass_destroy(a);
    tmass_destroy(b);
}

/* A cube of 2 x 2 x 2 cells, bottom pinned, under gravity, of either kind. */
static tmass_model *cube_model(tmass_model_kind kind, tetmesh *mesh)
{
    tmass_desc d = tmass_default_desc();
    tmass_model *m = NULL;
    tmass_real *x = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)mesh->node_count);
    int i;
    for (i = 0; i < 3 * mesh->node_count; i++) x[i] = (tmass_real)mesh->nodes[i];
    d.rest_positions = x;
    d.node_count = mesh->node_count;
    d.tets = mesh->tets;
    d.tet_count = mesh->tet_count;
    d.kind = kind;
    d.young_modulus = (tmass_real)1e4;
    i = tmass_create(&d, &m);
    free(x);
    if (i) return NULL;
    for (i = 0; i < mesh->node_count; i++)
        if (mesh->nodes[3 * i + 2] == 0.0) tmass_fix_node(m, i);
    return m;
}

static int same_state(const tmass_model *a, const tmass_model *b)
{
    size_t bytes = sizeof(tmass_real) * 3 * (size_t)a->node_count;
    return memcmp(a->disp, b->disp, bytes) == 0 && memcmp(a->vel, b->vel, bytes) == 0;
}

/* Applies reset number i (test_bdf2_history_rules) to one model. */
static int history_reset(tmass_model *m, int i, tmass_real dt)
{
    size_t bytes = sizeof(tmass_real) * 3 * (size_t)m->node_count;
    int cut = 0, err;
    tmass_real *copy = (tmass_real *)malloc(bytes);
    memcpy(copy, m->vel, bytes);
    switch (i) {
    case 0: err = tmass_set_velocities(m, copy); break;
    case 1: err = tmass_set_positions(m, tmass_positions(m)); break;
    case 2: err = tmass_fix_node(m, 0); break; /* already pinned: the values do not change */
    case 3: err = tmass_release_node(m, m->node_count - 1); break; /* a free node */
    case 4: err = tmass_remove_tets(m, &cut, 1, NULL); break;
    case 5: err = tmass_step_ex(m, dt, TMASS_IMPLICIT_EULER); break;
    case 6: err = tmass_step_ex(m, dt / 2, TMASS_BDF2); break; /* then a step of dt */
    default: err = tmass_solve_static(m); break;
    }
    free(copy);
    return err;
}

/* The history rules (INTEGRATORS): the first BDF2 step, and the first after
   tmass_set_positions / _velocities, a pin, a release, a cut, another integrator's step,
   a different dt, a static solve or a failed step, is exactly an implicit Euler step
   (two models in lockstep, one taking BDF2 and the other implicit Euler there, must stay
   bit-identical); a failed step leaves the state and the stored history untouched.
   Both kinds. */
static void test_bdf2_history_rules(void)
{
    tetmesh mesh;
    int kind, i, s;
    box_mesh(&mesh, 2, 2, 2, 1, 1, 1, TETMESH_SPLIT6);
    for (kind = 0; kind < 2; kind++) {
        tmass_model *a = cube_model((tmass_model_kind)kind, &mesh), *b = cube_model((tmass_model_kind)kind, &mesh);
        tmass_real dt = (tmass_real)0.01, *saved;
        size_t bytes;
        REQUIRE(a && b);
        bytes = sizeof(tmass_real) * 3 * (size_t)a->node_count;
        saved = (tmass_real *)malloc(4 * bytes);
        /* the first step */
        CHECK_INT(TMASS_OK, tmass_step_ex(a, dt, TMASS_BDF2));
        CHECK_INT(TMASS_OK, tmass_step_ex(b, dt, TMASS_IMPLICIT_EULER));
        CHECK(same_state(a, b));
        /* a failed step (CG capped at one iteration): state and history kept */
        CHECK_INT(TMASS_OK, tmass_step_ex(a, dt, TMASS_BDF2));
        CHECK_INT(1, a->history_ready);
        memcpy(saved, a->disp, bytes);
        memcpy(saved + 3 * a->node_count, a->vel, bytes);
        memcpy(saved + 6 * a->node_count, a->history_u, bytes);
        memcpy(saved + 9 * a->node_count, a->history_v, bytes);
        tmass_set_solver(a, (tmass_real)1e-12, 1);
        CHECK_INT(TMASS_ERR_NO_CONVERGENCE, tmass_step_ex(a, dt, TMASS_BDF2));
        CHECK(memcmp(saved, a->disp, bytes) == 0 && memcmp(saved + 3 * a->node_count, a->vel, bytes) == 0);
        CHECK(memcmp(saved + 6 * a->node_count, a->history_u, bytes) == 0 &&
              memcmp(saved + 9 * a->node_count, a->history_v, bytes) == 0);
        CHECK_INT(0, a->history_ready);
        tmass_set_solver(a, b->cg_tolerance, b->cg_max_iterations);
        tmass_destroy(a);
        a = cube_model((tmass_model_kind)kind, &mesh);
        tmass_destroy(b);
        b = cube_model((tmass_model_kind)kind, &mesh);
        REQUIRE(a && b);
        for (i = 0; i < 8; i++) {
            for (s = 0; s < 3; s++) { /* lockstep, BDF2 proper (the first of them may restart) */
                CHECK_INT(TMASS_OK, tmass_step_ex(a, dt, TMASS_BDF2));
                CHECK_INT(TMASS_OK, tmass_step_ex(b, dt, TMASS_BDF2));
            }
            CHECK_INT(1, a->history_ready);
            CHECK_INT(TMASS_OK, history_reset(a, i, dt));
            CHECK_INT(TMASS_OK, history_reset(b, i, dt));
            CHECK(same_state(a, b));
            CHECK_INT(i == 6, a->history_ready); /* the dt / 2 step keeps history, of dt / 2 */
            CHECK_INT(TMASS_OK, tmass_step_ex(a, dt, TMASS_BDF2));
            CHECK_INT(TMASS_OK, tmass_step_ex(b, dt, TMASS_IMPLICIT_EULER));
            if (!same_state(a, b)) printf("    reset %d (kind %d): the next BDF2 step is not implicit Euler\n", i, kind);
            CHECK(same_state(a, b));
            /* and a BDF2 step with history differs from implicit Euler */
            CHECK_INT(TMASS_OK, tmass_step_ex(a, dt, TMASS_BDF2));
            CHECK_INT(TMASS_OK, tmass_step_ex(a, dt, TMASS_BDF2));
            CHECK_INT(TMASS_OK, tmass_step_ex(b, dt, TMASS_IMPLICIT_EULER));
            CHECK_INT(TMASS_OK, tmass_step_ex(b, dt, TMASS_IMPLICIT_EULER));
            if (i != 7) CHECK(!same_state(a, b)); /* (after the static solve both rest) */
            tmass_destroy(a);
            tmass_destroy(b);
            a = cube_model((tmass_model_kind)kind, &mesh);
            b = cube_model((tmass_model_kind)kind, &mesh);
            REQUIRE(a && b);
        }
        free(saved);
        tmass_destroy(a);
        tmass_destroy(b);
    }
    tetmesh_free(&mesh);
}

/* ---- point probes and tmass_displacements --------------------------------------------- */

/* A box model (2 x 1 x 1 m, 4 x 2 x 2 cells) of either kind, nothing pinned. */
static tmass_model *box_model(tetmesh *mesh, tmass_model_kind kind, counting_allocator *count)
{
    tmass_desc d = tmass_default_desc();
    tmass_model *m = NULL;
    tmass_real *x;
    int i;
    box_mesh(mesh, 4, 2, 2, 2, 1, 1, TETMESH_SPLIT5);
    x = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)mesh->node_count);
    for (i = 0; i < 3 * mesh->node_count; i++) x[i] = (tmass_real)mesh->nodes[i];
    d.rest_positions = x;
    d.node_count = mesh->node_count;
    d.tets = mesh->tets;
    d.tet_count = mesh->tet_count;
    d.kind = kind;
    if (count) {
        d.allocator.alloc = count_alloc;
        d.allocator.free = count_free;
        d.allocator.user = count;
    }
    i = tmass_create(&d, &m);
    free(x);
    return i ? NULL : m;
}

/* The affine field u(X) = c + G X (and v likewise) is reproduced exactly by the P1
   interpolation, so probes at random points read it to round-off; nodes read their own
   values; tmass_displacements is x - X. */
static void test_probe_reads_affine_fields(void)
{
    static const double G[9] = {1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 1.5e-3, 3e-3, 1e-3, 0.2e-3}, c[3] = {0.01, -0.02, 0.005};
    tetmesh mesh;
    counting_allocator count = {0, 0, 0, 0};
    tmass_model *m = box_model(&mesh, TMASS_TENSOR_MASS, &count);
    tmass_probe *p = NULL;
    enum { P = 60 };
    tmass_real pts[3 * P], out[3 * P], *x, *v;
    unsigned seed = 7;
    int i, r, k, n, allocs;
    double worst = 0.0, tol = IS_FLOAT ? 1e-4 : 1e-13; /* float: x rounds to eps |X| */
    REQUIRE(m != NULL);
    n = tmass_node_count(m);
    x = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)n);
    v = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)n);
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            const double *X = mesh.nodes + 3 * i;
            double u = c[r] + G[3 * r] * X[0] + G[3 * r + 1] * X[1] + G[3 * r + 2] * X[2];
            x[3 * i + r] = (tmass_real)(X[r] + u);
            v[3 * i + r] = (tmass_real)(10 * u);
        }
    CHECK_INT(TMASS_OK, tmass_set_positions(m, x));
    CHECK_INT(TMASS_OK, tmass_set_velocities(m, v));
    for (i = 0; i < 3 * n; i++) /* the accessor: the state itself */
        CHECK((double)tmass_displacements(m)[i] ==
              (double)(tmass_real)((double)tmass_positions(m)[i] - (double)tmass_rest_positions(m)[i]));
    for (k = 0; k < P; k++) { /* random points, the last 8 on the box's corners and faces */
        pts[3 * k] = (tmass_real)(1.0 + rnd(&seed));
        pts[3 * k + 1] = (tmass_real)(0.5 + 0.5 * rnd(&seed));
        pts[3 * k + 2] = (tmass_real)(0.5 + 0.5 * rnd(&seed));
        if (k >= P - 8) {
            pts[3 * k] = (tmass_real)(2.0 * (k & 1));
            pts[3 * k + 1] = (tmass_real)((k >> 1) & 1);
            pts[3 * k + 2] = (tmass_real)(k == P - 1 ? 0.5 : ((k >> 2) & 1));
        }
    }
    allocs = count.allocs - count.frees;
    CHECK_INT(TMASS_OK, tmass_probe_create(m, pts, P, &p));
    CHECK_INT(allocs + 1, count.allocs - count.frees); /* the probe's block (the grid is freed) */
    REQUIRE(p != NULL);
    allocs = count.allocs;
    for (k = 0; k < 3; k++) {
        CHECK_INT(TMASS_OK, k == 0 ? tmass_probe_displacements(p, m, out)
                            : k == 1 ? tmass_probe_positions(p, m, out) : tmass_probe_velocities(p, m, out));
        for (i = 0; i < P; i++)
            for (r = 0; r < 3; r++) {
                const tmass_real *X = pts + 3 * i;
                double u = c[r] + G[3 * r] * X[0] + G[3 * r + 1] * X[1] + G[3 * r + 2] * X[2];
                double want = k == 0 ? u : k == 1 ? (double)X[r] + u : 10 * u;
                double e = fabs((double)out[3 * i + r] - want) / (k == 1 ? 2.0 : k == 2 ? 0.1 : 0.01);
                if (e > worst) worst = e;
            }
    }
    CHECK_INT(allocs, count.allocs); /* reads allocate nothing */
    printf("    %d probes, affine field: worst relative error %.2e\n", P, worst);
    CHECK(worst < tol);
    tmass_probe_destroy(p);
    /* nodes as probes: their own values */
    CHECK_INT(TMASS_OK, tmass_probe_create(m, tmass_rest_positions(m), n, &p));
    CHECK_INT(TMASS_OK, tmass_probe_displacements(p, m, x));
    worst = 0.0;
    for (i = 0; i < 3 * n; i++) {
        double e = fabs((double)x[i] - (double)tmass_displacements(m)[i]);
        if (e > worst) worst = e;
    }
    CHECK(worst <= (IS_FLOAT ? 1e-8 : 1e-17));
    tmass_probe_destroy(p);
    tmass_destroy(m);
    CHECK_INT(count.allocs, count.frees);
    free(x);
    free(v);
    tetmesh_free(&mesh);
}

/* Errors: a point outside the mesh (beyond the tolerance), bad arguments, a model of
   another size, and a probe whose tetrahedron was cut away (still written, with the
   code). */
static void test_probe_errors(void)
{
    tetmesh mesh, other_mesh;
    tmass_model *m = box_model(&mesh, TMASS_MASS_SPRING, NULL), *other = box_model(&other_mesh, TMASS_TENSOR_MASS, NULL);
    tmass_probe *p = (tmass_probe *)&p;
    tmass_real outside[6] = {1.0f, 0.5f, 0.5f, 2.01f, 0.5f, 0.5f}, inside[3] = {0.1f, 0.1f, 0.1f}, out[6];
    tmass_real nan_point[3] = {0, 0, 0};
    int t, cut = 0;
    REQUIRE(m && other);
    nan_point[1] = (tmass_real)(0.0 * HUGE_VAL);
    CHECK_INT(TMASS_ERR_PROBE_OUTSIDE, tmass_probe_create(m, outside, 2, &p));
    CHECK(p == NULL);
    CHECK_INT(TMASS_ERR_ARG, tmass_probe_create(m, nan_point, 1, &p));
    CHECK_INT(TMASS_ERR_ARG, tmass_probe_create(m, inside, 0, &p));
    CHECK_INT(TMASS_ERR_ARG, tmass_probe_create(NULL, inside, 1, &p));
    CHECK_INT(TMASS_ERR_ARG, tmass_probe_create(m, inside, 1, NULL));
    CHECK_INT(TMASS_OK, tmass_probe_create(m, outside, 1, &p));
    REQUIRE(p != NULL);
    CHECK_INT(TMASS_ERR_ARG, tmass_probe_positions(p, NULL, out));
    CHECK_INT(TMASS_ERR_ARG, tmass_probe_positions(NULL, m, out));
    CHECK_INT(TMASS_ERR_ARG, tmass_probe_positions(p, m, NULL));
    CHECK_INT(TMASS_OK, tmass_probe_positions(p, m, out));
    CHECK_INT(TMASS_OK, tmass_probe_positions(p, other, out)); /* same node count: allowed */
    tmass_probe_destroy(p);
    CHECK_INT(TMASS_OK, tmass_probe_create(m, inside, 1, &p));
    for (t = 0; t < tmass_tet_count(m); t++) /* cut the probe's tetrahedron */
        if (p->tet[0] == t) cut = t;
    CHECK_INT(TMASS_OK, tmass_remove_tets(m, &cut, 1, NULL));
    out[0] = (tmass_real)-7;
    CHECK_INT(TMASS_ERR_PROBE_OUTSIDE, tmass_probe_positions(p, m, out));
    CHECK(fabs((double)out[0] - 0.1) < 1e-6); /* written anyway */
    tmass_probe_destroy(p);
    tmass_probe_destroy(NULL);
    tmass_destroy(m);
    tmass_destroy(other);
    tetmesh_free(&mesh);
    tetmesh_free(&other_mesh);
}

/* ---- modal analysis ----------------------------------------------------------------- */

/* A model of the mesh; nodes with coordinate `axis` equal to 0 pinned (axis < 0: none). */
static tmass_model *mesh_model(const tetmesh *mesh, tmass_model_kind kind, double E, double nu, int axis,
                               counting_allocator *count)
{
    tmass_desc d = tmass_default_desc();
    tmass_model *m = NULL;
    tmass_real *x = (tmass_real *)malloc(sizeof(tmass_real) * 3 * (size_t)mesh->node_count);
    int i;
    for (i = 0; i < 3 * mesh->node_count; i++) x[i] = (tmass_real)mesh->nodes[i];
    d.rest_positions = x;
    d.node_count = mesh->node_count;
    d.tets = mesh->tets;
    d.tet_count = mesh->tet_count;
    d.kind = kind;
    d.young_modulus = (tmass_real)E;
    d.poisson_ratio = (tmass_real)nu;
    d.density = (tmass_real)1000;
    if (count) {
        d.allocator.alloc = count_alloc;
        d.allocator.free = count_free;
        d.allocator.user = count;
    }
    i = tmass_create(&d, &m);
    free(x);
    if (i) return NULL;
    if (axis >= 0)
        for (i = 0; i < mesh->node_count; i++)
            if (mesh->nodes[3 * i + axis] == 0.0) tmass_fix_node(m, i);
    return m;
}

/* Symmetric eigenvalues (ascending) of a dense n x n matrix by cyclic Jacobi, in the
   test's own code. */
static void dense_eigenvalues(double *A, int n, double *w)
{
    int i, j, k, sweep;
    for (sweep = 0; sweep < 60; sweep++) {
        double off = 0.0;
        for (i = 0; i < n; i++)
            for (j = i + 1; j < n; j++) off += A[i * n + j] * A[i * n + j];
        if (off < 1e-40) break;
        for (i = 0; i < n; i++)
            for (j = i + 1; j < n; j++) {
                double a = A[i * n + j], th, t, c, sn;
                if (fabs(a) < 1e-300) continue;
                th = (A[j * n + j] - A[i * n + i]) / (2 * a);
                t = (th >= 0 ? 1 : -1) / (fabs(th) + sqrt(th * th + 1));
                c = 1 / sqrt(t * t + 1);
                sn = t * c;
                for (k = 0; k < n; k++) {
                    double x = A[k * n + i], y = A[k * n + j];
                    A[k * n + i] = c * x - sn * y;
                    A[k * n + j] = sn * x + c * y;
                }
                for (k = 0; k < n; k++) {
                    double x = A[i * n + k], y = A[j * n + k];
                    A[i * n + k] = c * x - sn * y;
                    A[j * n + k] = sn * x + c * y;
                }
            }
    }
    for (i = 0; i < n; i++) w[i] = A[i * n + i];
    for (i = 1; i < n; i++)
        for (j = i; j > 0 && w[j] < w[j - 1]; j--) {
            double t = w[j];
            w[j] = w[j - 1];
            w[j - 1] = t;
        }
}

/* The lowest frequencies equal a dense eigen-solve of the same discrete problem (K by
   columns from the model's forces, M^-1/2 K M^-1/2 by Jacobi in the test), both kinds, on
   a cube pinned at its base; shapes M-orthonormal to round-off and true eigenvectors
   (residual); the model's state untouched; no allocation in the solve. */
static void test_modal_matches_dense(void)
{
    tetmesh mesh;
    int kind;
    box_mesh(&mesh, 2, 2, 2, 1, 1, 1, TETMESH_SPLIT6);
    for (kind = 0; kind < 2; kind++) {
        counting_allocator count = {0, 0, 0, 0};
        tmass_model *m = mesh_model(&mesh, (tmass_model_kind)kind, 1e4, 0.3, 2, &count);
        tmass_modal_desc d = tmass_modal_default_desc();
        tmass_modal *md = NULL;
        int n, n3, i, j, k, nf = 0, *map, allocs;
        double *K, *A, *w, worst = 0.0, orth = 0.0, res = 0.0, eps = 1e-7;
        tmass_real *x;
        REQUIRE(m != NULL);
        n = tmass_node_count(m);
        n3 = 3 * n;
        map = (int *)malloc(sizeof(int) * (size_t)n3);
        for (i = 0; i < n3; i++)
            if (!tmass_node_pinned(m, i / 3)) map[nf++] = i;
        K = (double *)calloc((size_t)nf * nf, sizeof(double));
        A = (double *)calloc((size_t)nf * nf, sizeof(double));
        w = (double *)calloc((size_t)nf, sizeof(double));
        x = (tmass_real *)malloc(sizeof(tmass_real) * (size_t)n3);
        for (j = 0; j < nf; j++) { /* K e_j = -(f(eps e_j) - f(-eps e_j)) / (2 eps) */
            double sgn;
            for (sgn = -1; sgn <= 1; sgn += 2) {
                memcpy(x, tmass_rest_positions(m), sizeof(tmass_real) * (size_t)n3);
                x[map[j]] = (tmass_real)((double)x[map[j]] + sgn * (IS_FLOAT ? 1e-3 : eps));
                tmass_set_positions(m, x);
                tmass_forces(m);
                for (i = 0; i < nf; i++)
                    K[i * nf + j] -= sgn * (double)tmass_forces(m)[map[i]] / (2 * (IS_FLOAT ? 1e-3 : eps));
            }
        }
        memcpy(x, tmass_rest_positions(m), sizeof(tmass_real) * (size_t)n3);
        tmass_set_positions(m, x);
        for (i = 0; i < nf; i++)
            for (j = 0; j < nf; j++)
                A[i * nf + j] = 0.5 * (K[i * nf + j] + K[j * nf + i]) /
                                sqrt((double)tmass_masses(m)[map[i] / 3] * (double)tmass_masses(m)[map[j] / 3]);
        dense_eigenvalues(A, nf, w);
        allocs = count.allocs;
        CHECK_INT(TMASS_OK, tmass_modal_create(m, &d, &md));
        CHECK_INT(allocs + 1, count.allocs);
        REQUIRE(md != NULL);
        CHECK_INT(0, tmass_modal_count(md));
        allocs = count.allocs;
        CHECK_INT(TMASS_OK, tmass_modal_solve(md, m));
        CHECK_INT(allocs, count.allocs);
        CHECK_INT(6, tmass_modal_count(md));
        for (i = 0; i < 6; i++) {
            double f = sqrt(w[i]) / (2 * PI), e = fabs(tmass_modal_frequency(md, i) - f) / f;
            if (e > worst) worst = e;
            for (j = 0; j <= i; j++) {
                const tmass_real *a = tmass_modal_shape(md, i), *b = tmass_modal_shape(md, j);
                double s = 0.0;
                for (k = 0; k < n3; k++) s += (double)a[k] * (double)tmass_masses(m)[k / 3] * (double)b[k];
                s -= i == j;
                if (fabs(s) > orth) orth = fabs(s);
            }
            { /* |K phi - lambda M phi|_M^-1 / lambda, with the dense K */
                const tmass_real *a = tmass_modal_shape(md, i);
                double lambda = pow(2 * PI * tmass_modal_frequency(md, i), 2), rr = 0.0;
                for (j = 0; j < nf; j++) {
                    double r = -lambda * (double)tmass_masses(m)[map[j] / 3] * (double)a[map[j]];
                    for (k = 0; k < nf; k++) r += K[j * nf + k] * (double)a[map[k]];
                    rr += r * r / (double)tmass_masses(m)[map[j] / 3];
                }
                if (sqrt(rr) / lambda > res) res = sqrt(rr) / lambda;
            }
        }
        printf("    %s: f = %.5f %.5f %.5f %.5f %.5f %.5f Hz; dense: worst relative difference %.2e, "
               "M-orthonormality %.2e, residual %.2e, %d CG iterations\n",
               kind ? "springs" : "tensor", tmass_modal_frequency(md, 0), tmass_modal_frequency(md, 1),
               tmass_modal_frequency(md, 2), tmass_modal_frequency(md, 3), tmass_modal_frequency(md, 4),
               tmass_modal_frequency(md, 5), worst, orth, res, tmass_last_stats(m)->cg_iterations);
        CHECK(worst < (IS_FLOAT ? 1e-3 : 1e-7));
        CHECK(orth < (IS_FLOAT ? 1e-4 : 1e-12));
        CHECK(res < (IS_FLOAT ? 1e-2 : 1e-6));
        for (i = 0; i < n3; i++) CHECK((double)tmass_positions(m)[i] == (double)x[i]);
        CHECK(tmass_modal_frequency(md, 6) < 0 && tmass_modal_shape(md, 6) == NULL && tmass_modal_shape(md, -1) == NULL);
        tmass_modal_destroy(md);
        tmass_destroy(m);
        CHECK_INT(count.allocs, count.frees);
        free(map); free(K); free(A); free(w); free(x);
    }
    tetmesh_free(&mesh);
}

/* A free body (nothing pinned): six rigid modes at 0 Hz within round-off (the automatic
   shift makes K + shift M definite), the seventh elastic. Both kinds. */
static void test_modal_free_cube_rigid_modes(void)
{
    tetmesh mesh;
    int kind, i;
    box_mesh(&mesh, 2, 2, 2, 1, 1, 1, TETMESH_SPLIT6);
    for (kind = 0; kind < 2; kind++) {
        tmass_model *m = mesh_model(&mesh, (tmass_model_kind)kind, 1e4, 0.3, -1, NULL);
        tmass_modal_desc d = tmass_modal_default_desc();
        tmass_modal *md = NULL;
        double worst = 0.0, f7;
        REQUIRE(m != NULL);
        d.count = 7;
        CHECK_INT(TMASS_OK, tmass_modal_create(m, &d, &md));
        REQUIRE(md != NULL);
        CHECK_INT(TMASS_OK, tmass_modal_solve(md, m));
        for (i = 0; i < 6; i++)
            if (tmass_modal_frequency(md, i) > worst) worst = tmass_modal_frequency(md, i);
        f7 = tmass_modal_frequency(md, 6);
        printf("    %s free cube: six rigid modes up to %.2e Hz, first elastic %.4f Hz\n", kind ? "springs" : "tensor",
               worst, f7);
        CHECK(worst < (IS_FLOAT ? 1e-2 : 1e-5) * f7);
        CHECK(f7 > 0.5);
        tmass_modal_destroy(md);
        tmass_destroy(m);
    }
    tetmesh_free(&mesh);
}

/* The mode whose shape is the most axial (largest share of M-weighted x motion). */
static int most_axial(const tmass_modal *md, const tmass_model *m)
{
    int i, k, best = -1;
    double best_share = 0.0;
    for (i = 0; i < tmass_modal_count(md); i++) {
        const tmass_real *a = tmass_modal_shape(md, i);
        double sx = 0.0, st = 0.0;
        for (k = 0; k < 3 * tmass_node_count(m); k++) {
            double e = (double)tmass_masses(m)[k / 3] * (double)a[k] * (double)a[k];
            st += e;
            if (k % 3 == 0) sx += e;
        }
        if (sx / st > best_share) {
            best_share = sx / st;
            best = i;
        }
    }
    return best;
}

/* The R3 beam (1 x 0.1 x 0.1 m, E = 1 MPa, nu = 0.3, 1000 kg/m^3, clamped at x = 0): the
   3D frequencies of REFERENCES (0.5091 Hz first bending, 3.0531 second, 4.5101 first
   torsion, 7.9276 first axial) within the discretisation error of linear tetrahedra,
   which lock in bending: on 20 x 2 x 2 and 30 x 3 x 3 six-tet cells (quick builds: the
   first only) the bending frequencies lie above the 3D value and the error falls as h^2
   (by 1.8 to 2.6 for h / 1.5; measured 40 x 4 x 4: +8.6 % first bending, ratio 3.4 from
   20 x 2 x 2); no mode lies below the first bending value (no spurious low mode); torsion
   above its value (locking: +15 % on 30 x 3 x 3, +10 % on 40 x 4 x 4) and axial (no
   locking) within 0.5 %. And the same
   beam with nu = 0 whose first axial mode is the 1D closed form c / (4 L), c = sqrt(E /
   rho) (nu = 0: no lateral coupling), within 0.5 % on 20 x 2 x 2. */
static void test_modal_r3_beam(void)
{
    static const double ref[6] = {0.5091, 0.5091, 3.0531, 3.0531, 4.5101, 7.9276};
    double err_prev[6] = {0, 0, 0, 0, 0, 0};
    int level, levels = TEST_IS_QUICK ? 1 : 2, i;
    for (level = 0; level < levels; level++) {
        tetmesh mesh;
        tmass_model *m;
        tmass_modal_desc d = tmass_modal_default_desc();
        tmass_modal *md = NULL;
        int c = 2 + level; /* 20 x 2 x 2, then 30 x 3 x 3 */
        tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 10 * c, c, c, TETMESH_SPLIT6);
        m = mesh_model(&mesh, TMASS_TENSOR_MASS, 1e6, 0.3, 0, NULL);
        REQUIRE(m != NULL);
        CHECK_INT(TMASS_OK, tmass_modal_create(m, &d, &md));
        REQUIRE(md != NULL);
        CHECK_INT(TMASS_OK, tmass_modal_solve(md, m));
        printf("    R3 beam %d x %d x %d (%d tets): f =", 10 * c, c, c, mesh.tet_count);
        for (i = 0; i < 6; i++) printf(" %.4f", tmass_modal_frequency(md, i));
        printf(" Hz (errors");
        for (i = 0; i < 6; i++) printf(" %+.2f %%", 100 * (tmass_modal_frequency(md, i) / ref[i] - 1));
        printf("), %d subspace iterations, %d CG iterations\n", tmass_last_stats(m)->newton_iterations,
               tmass_last_stats(m)->cg_iterations);
        CHECK(tmass_modal_frequency(md, 0) > ref[0]); /* none below the first physical mode */
        for (i = 0; i < 4; i++) {
            double e = tmass_modal_frequency(md, i) / ref[i] - 1;
            CHECK(e > 0);
            if (level > 0) CHECK(err_prev[i] / e > 1.8 && err_prev[i] / e < 2.6); /* (3/2)^2 = 2.25 */
            err_prev[i] = e;
        }
        CHECK(tmass_modal_frequency(md, 4) > ref[4]); /* torsion locks too */
        if (level > 0) {
            CHECK(tmass_modal_frequency(md, 4) / ref[4] - 1 < 0.16);
            CHECK_REL(ref[5], tmass_modal_frequency(md, 5), 0.005);
            CHECK_INT(5, most_axial(md, m));
        }
        tmass_modal_destroy(md);
        tmass_destroy(m);
        tetmesh_free(&mesh);
    }
    { /* nu = 0: the axial mode is the 1D one */
        tetmesh mesh;
        tmass_model *m;
        tmass_modal_desc d = tmass_modal_default_desc();
        tmass_modal *md = NULL;
        double f1d = sqrt(1e6 / 1000.0) / 4.0, f;
        tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 20, 2, 2, TETMESH_SPLIT6);
        m = mesh_model(&mesh, TMASS_TENSOR_MASS, 1e6, 0.0, 0, NULL);
        REQUIRE(m != NULL);
        d.count = 8;
        CHECK_INT(TMASS_OK, tmass_modal_create(m, &d, &md));
        REQUIRE(md != NULL);
        CHECK_INT(TMASS_OK, tmass_modal_solve(md, m));
        i = most_axial(md, m);
        REQUIRE(i >= 0);
        f = tmass_modal_frequency(md, i);
        printf("    nu = 0 beam: first axial mode %d at %.4f Hz, 1D closed form c / (4 L) = %.4f Hz (%+.3f %%)\n", i, f,
               f1d, 100 * (f / f1d - 1));
        CHECK_REL(f1d, f, 0.005);
        tmass_modal_destroy(md);
        tmass_destroy(m);
        tetmesh_free(&mesh);
    }
}

/* The R3 beam (1 x 0.1 x 0.1 m, E = 1 MPa, nu = 0.3, clamped; 20 x 2 x 2 six-tet cells)
   released from its first bending mode's shape (tmass_modal), read at the tip centre by a
   probe: the tip signal's period error and amplitude decay per period equal each scheme's
   closed form at the model's own frequency (3 digits; float 1 %, BDF2's decay 10 %: it is
   3e-3 of the amplitude per period), at T/50 and T/100 (quick builds T/40, T/80), and
   halving dt divides
   the period error by 4 (both schemes: phase is second order in both) and the log
   decrement per period by 2 for implicit Euler (first order) and by 8 for BDF2 (its
   amplitude error is third order). */
static void test_bdf2_r3_beam_mode(void)
{
    static const tmass_integrator integ[2] = {TMASS_IMPLICIT_EULER, TMASS_BDF2};
    tetmesh mesh;
    tmass_real tip[3] = {1, 0, 0}, g[3] = {0, 0, 0}, *start; /* tetmesh_beam: y, z centred on 0 */
    double pe[2][2], lg[2][2], f;
    int k, l, n3, i;
    tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 20, 2, 2, TETMESH_SPLIT6);
    n3 = 3 * mesh.node_count;
    start = (tmass_real *)malloc(sizeof(tmass_real) * (size_t)n3);
    { /* the first mode, once */
        tmass_model *m = mesh_model(&mesh, TMASS_TENSOR_MASS, 1e6, 0.3, 0, NULL);
        tmass_modal_desc d = tmass_modal_default_desc();
        tmass_modal *md = NULL;
        REQUIRE(m != NULL);
        CHECK_INT(TMASS_OK, tmass_modal_create(m, &d, &md));
        REQUIRE(md != NULL);
        CHECK_INT(TMASS_OK, tmass_modal_solve(md, m));
        f = tmass_modal_frequency(md, 0);
        for (i = 0; i < n3; i++)
            start[i] = (tmass_real)((double)tmass_rest_positions(m)[i] + 0.01 * (double)tmass_modal_shape(md, 0)[i]);
        tmass_modal_destroy(md);
        tmass_destroy(m);
    }
    for (k = 0; k < 2; k++)
        for (l = 0; l < 2; l++) {
            tmass_model *m = mesh_model(&mesh, TMASS_TENSOR_MASS, 1e6, 0.3, 0, NULL);
            tmass_probe *p = NULL;
            tmass_real u[3];
            int N = (TEST_IS_QUICK ? 40 : 50) << l, steps = 2 * N + 50, s, axis;
            double T = 1.0 / f, w, *z, de, pt, dt_;
            cplx zr;
            REQUIRE(m != NULL);
            tmass_set_gravity(m, g);
            tmass_set_solver(m, (tmass_real)(IS_FLOAT ? 1e-6 : 1e-11), 10000);
            CHECK_INT(TMASS_OK, tmass_probe_create(m, tip, 1, &p));
            REQUIRE(p != NULL);
            tmass_set_positions(m, start);
            tmass_probe_displacements(p, m, u);
            axis = fabs((double)u[1]) > fabs((double)u[2]) ? 1 : 2;
            z = (double *)malloc(sizeof(double) * (size_t)steps);
            for (s = 0; s < steps; s++) {
                CHECK_INT(TMASS_OK, tmass_step_ex(m, (tmass_real)(T / N), integ[k]));
                tmass_probe_displacements(p, m, u);
                z[s] = (double)u[axis];
            }
            zr = fitted_root(z, 40, steps);
            w = 2 * PI / N;
            root_figures(zr, w, &pe[k][l], &de);
            root_figures(amplification(integ[k], w), w, &pt, &dt_);
            lg[k][l] = -log(1.0 - de);
            printf("    R3 beam f1 = %.4f Hz, %-14s T/%-3d period error %+.4e (theory %+.4e), decay per period "
                   "%.4e (theory %.4e)\n", f, k ? "BDF2" : "implicit Euler", N, pe[k][l], pt, de, dt_);
            CHECK_REL(pt, pe[k][l], IS_FLOAT ? 1e-2 : 1e-3);
            CHECK_REL(dt_, de, IS_FLOAT ? (k ? 0.1 : 1e-2) : 1e-3);
            free(z);
            tmass_probe_destroy(p);
            tmass_destroy(m);
        }
    printf("    halving dt: period error / %.3f (implicit Euler), / %.3f (BDF2); log decrement / %.3f (implicit "
           "Euler), / %.3f (BDF2)\n", pe[0][0] / pe[0][1], pe[1][0] / pe[1][1], lg[0][0] / lg[0][1],
           lg[1][0] / lg[1][1]);
    CHECK_NEAR(4.0, pe[0][0] / pe[0][1], 0.15);
    CHECK_NEAR(4.0, pe[1][0] / pe[1][1], 0.15);
    CHECK_NEAR(2.0, lg[0][0] / lg[0][1], 0.05);
    if (!IS_FLOAT) CHECK_NEAR(8.0, lg[1][0] / lg[1][1], 0.6);
    free(start);
    tetmesh_free(&mesh);
}

/* The grid search gives exactly the full scan's answer (the same tetrahedron, the most
   inside, lowest index on ties) for random points, points on nodes, edges and faces of
   the cells, and after cuts (dead tetrahedra excluded); points outside are refused. */
static void test_probe_grid_matches_scan(void)
{
    tetmesh mesh;
    tmass_model *m;
    tmass_probe *p = NULL;
    enum { P = 3000 };
    tmass_real *pts = (tmass_real *)malloc(sizeof(tmass_real) * 3 * P);
    unsigned seed = 11;
    int i, k, cut[40], mismatches = 0, removed = 0, outside = 0;
    tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 20, 2, 2, TETMESH_SPLIT6);
    m = mesh_model(&mesh, TMASS_TENSOR_MASS, 1e6, 0.3, 0, NULL);
    REQUIRE(m && pts);
    for (i = 0; i < 40; i++) cut[i] = 3 * i + 100;
    CHECK_INT(TMASS_OK, tmass_remove_tets(m, cut, 40, &removed));
    for (k = 0; k < P; k++) {
        if (k % 3 == 0) { /* random */
            pts[3 * k] = (tmass_real)(0.5 + 0.5 * rnd(&seed));
            pts[3 * k + 1] = (tmass_real)(0.05 * rnd(&seed));
            pts[3 * k + 2] = (tmass_real)(0.05 * rnd(&seed));
        } else { /* on the cell grid's planes: nodes, edges, faces */
            pts[3 * k] = (tmass_real)(0.05 * (int)(10.5 + 10 * rnd(&seed)));
            pts[3 * k + 1] = (tmass_real)(k % 3 == 1 ? 0.05 * (int)(1.5 + 1.5 * rnd(&seed)) - 0.05 : 0.05 * rnd(&seed));
            pts[3 * k + 2] = (tmass_real)(0.05 * (int)(1.5 + 1.5 * rnd(&seed)) - 0.05);
        }
    }
    for (k = 0; k < P; k++) { /* points in the holes the cuts left are outside: move them to a node */
        double w[4];
        if (tmass__locate(m, pts + 3 * k, NULL, m->tet_count, w) < 0) {
            memcpy(pts + 3 * k, tmass_rest_positions(m), 3 * sizeof(tmass_real));
            outside++;
        }
    }
    CHECK(outside > 0 && outside < P / 4);
    CHECK_INT(TMASS_OK, tmass_probe_create(m, pts, P, &p));
    REQUIRE(p != NULL);
    for (k = 0; k < P; k++) {
        double w[4];
        int t = tmass__locate(m, pts + 3 * k, NULL, m->tet_count, w);
        if (t != p->tet[k]) mismatches++;
    }
    printf("    %d points (%d removed tetrahedra, %d points in their holes moved): %d differ from the full scan\n", P,
           removed, outside, mismatches);
    CHECK_INT(0, mismatches);
    tmass_probe_destroy(p);
    pts[0] = (tmass_real)1.001; /* beyond the tip */
    CHECK_INT(TMASS_ERR_PROBE_OUTSIDE, tmass_probe_create(m, pts, P, &p));
    CHECK(p == NULL);
    tmass_destroy(m);
    tetmesh_free(&mesh);
    free(pts);
}

/* Errors: a desc not from the default function, bad fields, more modes than free degrees
   of freedom, another model size, and no convergence within the cap (count 0, state
   kept). */
static void test_modal_errors(void)
{
    tetmesh mesh, small;
    tmass_model *m, *other;
    tmass_modal_desc d = tmass_modal_default_desc(), bad;
    tmass_modal *md = (tmass_modal *)&md;
    box_mesh(&mesh, 2, 2, 2, 1, 1, 1, TETMESH_SPLIT6);
    box_mesh(&small, 1, 1, 1, 1, 1, 1, TETMESH_SPLIT6);
    m = mesh_model(&mesh, TMASS_TENSOR_MASS, 1e4, 0.3, 2, NULL);
    other = mesh_model(&small, TMASS_TENSOR_MASS, 1e4, 0.3, 2, NULL);
    REQUIRE(m && other);
    memset(&bad, 0, sizeof bad);
    CHECK_INT(TMASS_ERR_DESC, tmass_modal_create(m, &bad, &md));
    CHECK(md == NULL);
    bad = d; bad.count = 0;             CHECK_INT(TMASS_ERR_ARG, tmass_modal_create(m, &bad, &md));
    bad = d; bad.tolerance = 0;         CHECK_INT(TMASS_ERR_ARG, tmass_modal_create(m, &bad, &md));
    bad = d; bad.shift = -1;            CHECK_INT(TMASS_ERR_ARG, tmass_modal_create(m, &bad, &md));
    bad = d; bad.max_iterations = 0;    CHECK_INT(TMASS_ERR_ARG, tmass_modal_create(m, &bad, &md));
    CHECK_INT(TMASS_ERR_ARG, tmass_modal_create(NULL, &d, &md));
    bad = d; bad.count = 30;            /* more than the small cube's 8 nodes have dofs */
    CHECK_INT(TMASS_ERR_ARG, tmass_modal_create(other, &bad, &md));
    bad.count = 13;                     /* its 4 free nodes have 12 */
    CHECK_INT(TMASS_OK, tmass_modal_create(other, &bad, &md));
    CHECK_INT(TMASS_ERR_ARG, tmass_modal_solve(md, other));
    tmass_modal_destroy(md);
    bad.count = 12;                     /* all of them: the whole space */
    CHECK_INT(TMASS_OK, tmass_modal_create(other, &bad, &md));
    CHECK_INT(TMASS_OK, tmass_modal_solve(md, other));
    CHECK_INT(12, tmass_modal_count(md));
    tmass_modal_destroy(md);
    CHECK_INT(TMASS_OK, tmass_modal_create(m, &d, &md));
    CHECK_INT(TMASS_ERR_ARG, tmass_modal_solve(md, other));
    tmass_modal_destroy(md);
    bad = d;
    bad.max_iterations = 1;
    CHECK_INT(TMASS_OK, tmass_modal_create(m, &bad, &md));
    CHECK_INT(TMASS_ERR_NO_CONVERGENCE, tmass_modal_solve(md, m));
    CHECK_INT(0, tmass_modal_count(md));
    CHECK(tmass_modal_shape(md, 0) == NULL);
    tmass_modal_destroy(md);
    tmass_modal_destroy(NULL);
    tmass_destroy(m);
    tmass_destroy(other);
    tetmesh_free(&mesh);
    tetmesh_free(&small);
}

int main(int argc, char **argv)
{
    static const test_case cases[] = {
        TEST(test_bdf2_amplification_closed_form),
        TEST(test_bdf2_order),
        TEST(test_bdf2_damped_recurrence),
        TEST(test_bdf2_history_rules),
        TEST(test_set_damping),
        TEST(test_probe_reads_affine_fields),
        TEST(test_probe_errors),
        TEST(test_probe_grid_matches_scan),
        TEST(test_modal_matches_dense),
        TEST(test_modal_free_cube_rigid_modes),
        TEST(test_modal_r3_beam),
        TEST(test_modal_errors),
        TEST(test_bdf2_r3_beam_mode),
    };
    return TEST_MAIN(argc, argv, cases);
}
