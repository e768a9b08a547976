/* Tests of heml.h, part 4: accuracy in time and in space (issue 19). BDF2 (HEML_BDF2): its
   order on a linear oscillator against implicit Euler's, its amplitude decay and period per
   period against the closed form of its amplification factor (on the oscillator and on
   R3's first mode), its restart rules (first step, set state, pins, failed steps), mass
   damping against its own recurrence, no allocation, its steps against their own BDF2
   equations in a reduced stress sweep. Point probes: affine fields interpolated exactly,
   errors. Modal analysis: a free cube's rigid modes, a clamped bar's axial modes, R3's
   frequencies on the bench beams and no spurious modes, M-orthonormality, errors. */
#define HEML_IMPLEMENTATION
#include "../heml.h"
#define TETMESH_IMPLEMENTATION
#include "../examples/tetmesh.h"
#include "test.h"
#include "fixtures.h"

#define IS_FLOAT (sizeof(heml_real) == sizeof(float))
#define PI 3.14159265358979323846

static heml_real *alloc_reals(int count)
{
    return (heml_real *)calloc(count > 0 ? (size_t)count : 1, sizeof(heml_real));
}

static heml_model *make_model_ex(const tetmesh *mesh, heml_material mt, double gz, heml_desc *dd)
{
    heml_real *x = alloc_reals(3 * mesh->node_count);
    heml_desc d = dd ? *dd : heml_default_desc();
    heml_model *m = NULL;
    int i;
    for (i = 0; i < 3 * mesh->node_count; i++) x[i] = (heml_real)mesh->nodes[i];
    d.rest_positions = x;
    d.node_count = mesh->node_count;
    d.tets = mesh->tets;
    d.tet_count = mesh->tet_count;
    d.material = mt;
    d.gravity[2] = (heml_real)gz;
    if (heml_create(&d, &m)) m = NULL;
    free(x);
    return m;
}

/* ---- a one-degree-of-freedom oscillator --------------------------------------------- */

/* One tetrahedron, nodes 0-2 pinned, node 3 on rollers (x and y pinned): one degree of
   freedom z, m z'' = -k z at small amplitude, k from heml_apply_stiffness. */
typedef struct osc1 {
    heml_model *m;
    double k, mass, omega, amp;
} osc1;

static int osc1_make(osc1 *o, double alpha, heml_allocator *allocator)
{
    static const int tet[4] = {0, 1, 2, 3};
    static const double nodes[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.2, 0.3, 1};
    heml_real X[12], dx[12], out[12], zero[3] = {0, 0, 0};
    heml_desc d = heml_default_desc();
    int i;
    for (i = 0; i < 12; i++) X[i] = (heml_real)nodes[i];
    d.rest_positions = X;
    d.node_count = 4;
    d.tets = tet;
    d.tet_count = 1;
    d.material = heml_material_from_young(HEML_NEO_HOOKEAN, 1e4, 0.3);
    d.gravity[2] = 0;
    d.mass_damping = (heml_real)alpha;
    d.newton_tolerance = (heml_real)(IS_FLOAT ? 1e-5 : 1e-12); /* the integrator's error, not Newton's */
    d.cg_tolerance = (heml_real)(IS_FLOAT ? 1e-6 : 1e-12);
    if (allocator) d.allocator = *allocator;
    if (heml_create(&d, &o->m)) return 0;
    for (i = 0; i < 3; i++) heml_fix_node(o->m, i);
    heml_set_displacement_axes(o->m, 3, 3u, zero);
    memset(dx, 0, sizeof dx);
    dx[11] = 1;
    heml_apply_stiffness(o->m, dx, out);
    o->k = -(double)out[11];
    o->mass = (double)heml_masses(o->m)[3];
    o->omega = sqrt(o->k / o->mass);
    o->amp = IS_FLOAT ? 1e-3 : 1e-6;
    return 1;
}

/* Starts at z = amp, v = 0. */
static void osc1_start(osc1 *o)
{
    heml_real z[12], w[12];
    memset(z, 0, sizeof z);
    memset(w, 0, sizeof w);
    z[11] = (heml_real)o->amp;
    heml_set_displacements(o->m, z);
    heml_set_velocities(o->m, w);
}

/* |z(t) - amp cos(omega t)| / amp after `steps` steps over one period. */
static double osc1_error(osc1 *o, heml_integrator integ, int steps)
{
    double T = 2 * PI / o->omega;
    int s;
    osc1_start(o);
    for (s = 0; s < steps; s++)
        if (heml_step_ex(o->m, (heml_real)(T / steps), integ)) return 1e9;
    return fabs((double)heml_displacements(o->m)[11] - o->amp) / o->amp;
}

/* The principal root zeta (re, im) of a scheme's amplification for y' = i w y, wh = w h:
   implicit Euler zeta = 1 / (1 - i wh); BDF2 (1 - 2 i wh / 3) zeta^2 - 4/3 zeta + 1/3 = 0,
   the root near 1. */
static void amplification(int bdf2, double wh, double *re, double *im)
{
    if (!bdf2) {
        *re = 1 / (1 + wh * wh);
        *im = wh / (1 + wh * wh);
    } else {
        /* zeta = (4/3 + sqrt(16/9 - 4/3 a)) / (2 a), a = 1 - 2 i wh / 3 */
        double ar = 1, ai = -2 * wh / 3, dr = 16.0 / 9 - 4.0 / 3 * ar, di = -4.0 / 3 * ai;
        double mod = sqrt(sqrt(dr * dr + di * di)), arg = 0.5 * atan2(di, dr);
        double sr = mod * cos(arg), si = mod * sin(arg), nr = 4.0 / 3 + sr, ni = si;
        double den = 4 * (ar * ar + ai * ai); /* (n / (2 a)) = n conj(a) / (2 |a|^2) */
        *re = 2 * (nr * ar + ni * ai) / den;
        *im = 2 * (ni * ar - nr * ai) / den;
    }
}

/* Runs `periods` periods at `per` steps per exact period and fits z_n+2 = a z_n+1 + b z_n
   by least squares over the last `periods - 1` periods (BDF2's parasitic root, |zeta| of
   about 1/3 per step, has died out by then): |zeta|^2 = -b, arg zeta = acos(a / (2
   |zeta|)). Returns the decay of the amplitude per exact period, 1 - |zeta|^per, and the
   relative period error T_h / T - 1 = 2 pi / (per arg zeta) - 1. */
static int osc1_fit(osc1 *o, heml_integrator integ, int per, int periods, double *decay, double *period_error)
{
    double T = 2 * PI / o->omega, h = T / per, s11 = 0, s12 = 0, s22 = 0, r1 = 0, r2 = 0, zm2 = 0, zm1 = 0;
    double a, b, det, mod, arg;
    int s, steps = per * periods;
    osc1_start(o);
    for (s = 1; s <= steps; s++) {
        double z;
        if (heml_step_ex(o->m, (heml_real)h, integ)) return 0;
        z = (double)heml_displacements(o->m)[11] / o->amp;
        if (s > per + 2) {
            s11 += zm1 * zm1;
            s12 += zm1 * zm2;
            s22 += zm2 * zm2;
            r1 += z * zm1;
            r2 += z * zm2;
        }
        zm2 = zm1;
        zm1 = z;
    }
    det = s11 * s22 - s12 * s12;
    a = (r1 * s22 - r2 * s12) / det;
    b = (s11 * r2 - s12 * r1) / det;
    mod = sqrt(-b);
    arg = acos(a / (2 * mod));
    *decay = 1 - pow(mod, per);
    *period_error = 2 * PI / (per * arg) - 1;
    return 1;
}

/* ---- BDF2 ---------------------------------------------------------------------------- */

/* Halving dt divides BDF2's error at t = T by 4 and implicit Euler's by 2 (BDF2's first
   step is implicit Euler: its local error O(dt^2) keeps the global error second order). */
static void test_bdf2_order(void)
{
    osc1 o;
    heml_integrator integ[2] = {HEML_IMPLICIT_EULER, HEML_BDF2};
    int k, l;
    REQUIRE(osc1_make(&o, 0.0, NULL));
    for (k = 0; k < 2; k++) {
        double e[4], lo = k ? 3.5 : 1.8, hi = k ? 4.5 : 2.2;
        int base = 50, levels = IS_FLOAT && k ? 2 : 3; /* float: BDF2's finest errors reach its rounding */
        for (l = 0; l < 4; l++) e[l] = osc1_error(&o, integ[k], base << l);
        printf("    %s: error at T with T/%d..T/%d: %.3g %.3g %.3g %.3g, ratios %.3f %.3f %.3f\n",
               k ? "BDF2" : "implicit Euler", base, base << 3, e[0], e[1], e[2], e[3], e[0] / e[1], e[1] / e[2],
               e[2] / e[3]);
        for (l = 0; l < levels; l++) {
            CHECK(e[l] / e[l + 1] > lo);
            CHECK(e[l] / e[l + 1] < hi);
        }
    }
    heml_destroy(o.m);
}

/* The amplitude decay per period and the period error of both schemes, measured from the
   simulated sequence (osc1_fit), against the closed form of their amplification factor:
   decay to 3 digits (relative 1e-3) wherever it is above 1e-6 of the amplitude per
   period (float: 1e-2 where above 1e-3), the period to 1e-5 of T (float 1e-3). Prints the
   table of issue 19 (T/20, T/50, T/100, T/400). */
static void test_bdf2_decay_closed_form(void)
{
    static const int pers[4] = {20, 50, 100, 400};
    osc1 o;
    int k, l;
    REQUIRE(osc1_make(&o, 0.0, NULL));
    printf("    scheme          dt      decay/period (theory)      period error (theory)\n");
    for (k = 0; k < 2; k++)
        for (l = 0; l < 4; l++) {
            double decay, perr, re, im, mod, arg, tdecay, tperr, wh = 2 * PI / pers[l];
            int periods = pers[l] >= 400 ? 3 : 5;
            if (TEST_IS_QUICK && pers[l] >= 400) continue;
            REQUIRE(osc1_fit(&o, k ? HEML_BDF2 : HEML_IMPLICIT_EULER, pers[l], periods, &decay, &perr));
            amplification(k, wh, &re, &im);
            mod = sqrt(re * re + im * im);
            arg = atan2(im, re);
            tdecay = 1 - pow(mod, pers[l]);
            tperr = 2 * PI / (pers[l] * arg) - 1;
            printf("    %-14s T/%-4d %.6f (%.6f)       %+.6f (%+.6f)\n", k ? "BDF2" : "implicit Euler", pers[l], decay,
                   tdecay, perr, tperr);
            if (tdecay > (IS_FLOAT ? 1e-3 : 1e-6)) CHECK_REL(tdecay, decay, IS_FLOAT ? 1e-2 : 1e-3);
            CHECK_NEAR(tperr, perr, IS_FLOAT ? 1e-3 : 1e-5);
        }
    heml_destroy(o.m);
}

/* The first BDF2 step, and the first after heml_set_velocities, a pin, a step of another
   integrator, a change of dt or a failed step, is exactly an implicit Euler step (the two
   models stay bit-identical); the second is not. A failed step keeps the state. */
static void test_bdf2_restarts(void)
{
    osc1 a, b;
    double T, dt;
    heml_real w[12], zero[3] = {0, 0, 0};
    int s;
    REQUIRE(osc1_make(&a, 0.5, NULL));
    REQUIRE(osc1_make(&b, 0.5, NULL));
    T = 2 * PI / a.omega;
    dt = T / 30;
    osc1_start(&a);
    osc1_start(&b);
    CHECK_INT(HEML_OK, heml_step_ex(a.m, (heml_real)dt, HEML_BDF2));
    CHECK_INT(HEML_OK, heml_step_ex(b.m, (heml_real)dt, HEML_IMPLICIT_EULER));
    CHECK(heml_displacements(a.m)[11] == heml_displacements(b.m)[11]);
    CHECK(heml_velocities(a.m)[11] == heml_velocities(b.m)[11]);
    /* a second BDF2 step differs from implicit Euler (b restarts its own BDF2 from a's state) */
    CHECK_INT(HEML_OK, heml_step_ex(a.m, (heml_real)dt, HEML_BDF2));
    CHECK_INT(HEML_OK, heml_step_ex(b.m, (heml_real)dt, HEML_IMPLICIT_EULER));
    CHECK(heml_displacements(a.m)[11] != heml_displacements(b.m)[11]);
    for (s = 0; s < (IS_FLOAT ? 4 : 5); s++) { /* each restart (float: its one Newton iteration
                                                   converges, so no failed step here; the stress
                                                   sweep checks failed steps); a BDF2 step
                                                   equals implicit Euler's from the same state */
        heml_set_displacements(b.m, heml_displacements(a.m));
        memcpy(w, heml_velocities(a.m), sizeof w);
        heml_set_velocities(b.m, w);
        CHECK_INT(HEML_OK, heml_step_ex(a.m, (heml_real)dt, HEML_BDF2)); /* history valid again */
        heml_set_displacements(b.m, heml_displacements(a.m));
        memcpy(w, heml_velocities(a.m), sizeof w);
        heml_set_velocities(b.m, w);
        if (s == 0) heml_set_velocities(a.m, w);
        if (s == 1) heml_set_displacement_axes(a.m, 3, 3u, zero);
        if (s == 2) CHECK_INT(HEML_OK, heml_step_ex(a.m, (heml_real)dt, HEML_SEMI_EXPLICIT_EULER));
        if (s == 2) CHECK_INT(HEML_OK, heml_step_ex(b.m, (heml_real)dt, HEML_SEMI_EXPLICIT_EULER));
        if (s == 3) dt *= 0.5;
        if (s == 4) { /* a failed step (one Newton iteration at a tolerance it cannot reach) keeps the state */
            heml_real u = heml_displacements(a.m)[11], v = heml_velocities(a.m)[11];
            heml_set_newton_iterations(a.m, 1);
            heml_set_solver(a.m, (heml_real)1e-30, 1);
            CHECK(heml_step_ex(a.m, (heml_real)dt, HEML_BDF2) != HEML_OK);
            CHECK(heml_displacements(a.m)[11] == u);
            CHECK(heml_velocities(a.m)[11] == v);
            heml_set_newton_iterations(a.m, 20);
            heml_set_solver(a.m, (heml_real)(IS_FLOAT ? 1e-6 : 1e-12), 1000);
        }
        CHECK_INT(HEML_OK, heml_step_ex(a.m, (heml_real)dt, HEML_BDF2));
        CHECK_INT(HEML_OK, heml_step_ex(b.m, (heml_real)dt, HEML_IMPLICIT_EULER));
        CHECK(heml_displacements(a.m)[11] == heml_displacements(b.m)[11]);
        CHECK(heml_velocities(a.m)[11] == heml_velocities(b.m)[11]);
    }
    heml_destroy(a.m);
    heml_destroy(b.m);
}

/* BDF2 steps allocate nothing (the history is part of the model). */
static void test_bdf2_no_allocation(void)
{
    counting_allocator c = {0, 0, 0, 0};
    heml_allocator al;
    osc1 o;
    int s, before;
    al.alloc = count_alloc;
    al.free = count_free;
    al.user = &c;
    REQUIRE(osc1_make(&o, 0.0, &al));
    osc1_start(&o);
    before = c.allocs;
    for (s = 0; s < 10; s++) CHECK_INT(HEML_OK, heml_step_ex(o.m, (heml_real)(2 * PI / o.omega / 50), HEML_BDF2));
    CHECK_INT(before, c.allocs);
    heml_destroy(o.m);
}

/* The residual of the BDF2 equations at the model's state, f + M g - M (u - ubar - beta
   vbar) / beta^2 over the free axes, relative to the largest of its terms' norms (the
   scale of the step's Newton tolerance; the forces' norm includes the reactions). */
static double bdf2_residual(heml_model *m, const heml_real *ubar, const heml_real *vbar, double beta, double gz)
{
    const heml_real *f = heml_compute_forces(m), *x = heml_displacements(m), *mass = heml_masses(m);
    double s = 0.0, g = 0.0, ff = 0.0, in = 0.0;
    int i, r, n = heml_node_count(m);
    for (i = 0; i < 3 * n; i++) ff += (double)f[i] * (double)f[i]; /* reactions too, as Newton's scale */
    for (i = 0; i < n; i++) {
        if (heml_node_pinned(m, i)) continue;
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            double mi = (double)mass[i], e = (double)x[j] - (double)ubar[j] - beta * (double)vbar[j];
            double R = (double)f[j] + mi * (r == 2 ? gz : 0.0) - mi * e / (beta * beta);
            s += R * R;
            g += mi * mi * (r == 2 ? gz * gz : 0.0);
            in += pow(mi * e / (beta * beta), 2);
        }
    }
    if (ff > g) g = ff;
    if (in > g) g = in;
    return sqrt(s / g);
}

/* E from 1 Pa to 200 GPa, nu from 0 to 0.4999, dt from 1e-6 to 1 s: a clamped beam under
   gravity, one implicit Euler start and a BDF2 step; every BDF2 step that succeeds
   satisfies its BDF2 equations (residual computed here from the test's own copy of the
   history) to 10 times the Newton tolerance (1e-5, float 1e-3), or the step returns an
   error code and keeps the state. */
static void test_bdf2_stress_sweep(void)
{
    static const double Es[4] = {1, 1e4, 1e7, 2e11}, nus[4] = {0, 0.3, 0.45, 0.4999}, dts[3] = {1e-6, 1e-2, 1};
    tetmesh beam;
    int ie, in, id, ok = 0, codes = 0, wrong = 0;
    tetmesh_beam(&beam, 1.0, 0.1, 0.1, 4, 1, 1, TETMESH_SPLIT6);
    for (ie = 0; ie < 4; ie++)
        for (in = 0; in < 4; in++)
            for (id = 0; id < 3; id++) {
                heml_material mt = heml_material_from_young(HEML_NEO_HOOKEAN, Es[ie], nus[in]);
                heml_model *m = make_model_ex(&beam, mt, -9.81, NULL);
                int i, n3 = 3 * beam.node_count, err;
                heml_real *u0 = alloc_reals(n3), *v0 = alloc_reals(n3), *ub = alloc_reals(n3), *vb = alloc_reals(n3);
                REQUIRE(m != NULL);
                for (i = 0; i < beam.node_count; i++)
                    if (beam.nodes[3 * i] == 0.0) heml_fix_node(m, i);
                err = heml_step_ex(m, (heml_real)dts[id], HEML_BDF2);
                if (err == HEML_OK) {
                    memcpy(u0, heml_displacements(m), sizeof(heml_real) * n3);
                    memcpy(v0, heml_velocities(m), sizeof(heml_real) * n3);
                    err = heml_step_ex(m, (heml_real)dts[id], HEML_BDF2);
                    if (err) { /* a failed step keeps the state */
                        CHECK(memcmp(u0, heml_displacements(m), sizeof(heml_real) * n3) == 0);
                        CHECK(memcmp(v0, heml_velocities(m), sizeof(heml_real) * n3) == 0);
                    }
                }
                if (err == HEML_OK) {
                    double r;
                    for (i = 0; i < n3; i++) { /* the history: u_n-1 = 0, v_n-1 = 0 */
                        ub[i] = (heml_real)(4.0 * (double)u0[i] / 3.0);
                        vb[i] = (heml_real)(4.0 * (double)v0[i] / 3.0);
                    }
                    r = bdf2_residual(m, ub, vb, 2.0 * dts[id] / 3.0, -9.81);
                    ok++;
                    if (!(r <= (IS_FLOAT ? 1e-3 : 1e-5))) {
                        wrong++;
                        printf("    WRONG BDF2 E %g nu %g dt %g: residual %.3g of its terms\n", Es[ie], nus[in],
                               dts[id], r);
                    }
                } else {
                    codes++;
                    printf("    BDF2 E %g nu %g dt %g: %s\n", Es[ie], nus[in], dts[id], heml_error_string(err));
                }
                free(u0);
                free(v0);
                free(ub);
                free(vb);
                heml_destroy(m);
            }
    printf("    %d BDF2 steps right, %d error codes, %d wrong\n", ok - wrong, codes, wrong);
    CHECK_INT(0, wrong);
    tetmesh_free(&beam);
}


/* ---- point probes -------------------------------------------------------------------- */

static heml_model *box_model(int nx, int ny, int nz, double sx, double sy, double sz, heml_allocator *al, tetmesh *mesh)
{
    heml_desc d = heml_default_desc();
    box_mesh(mesh, nx, ny, nz, sx, sy, sz, TETMESH_SPLIT5);
    if (al) d.allocator = *al;
    return make_model_ex(mesh, heml_material_from_young(HEML_NEO_HOOKEAN, 1e4, 0.3), 0.0, &d);
}

/* An affine displacement and velocity field is interpolated exactly (P1): probes at random
   interior points, at nodes and on faces give rest + A X + b, A X + b and B X + c to
   round-off; evaluation allocates nothing, creation once. */
static void test_probe_affine_exact(void)
{
    static const double A[3][3] = {{0.01, -0.02, 0.005}, {0.003, 0.02, -0.01}, {-0.004, 0.006, 0.015}};
    static const double bv[3] = {0.1, -0.2, 0.05}, B[3][3] = {{1, 2, 3}, {-1, 0.5, 0}, {0.2, -0.3, 0.7}};
    counting_allocator c = {0, 0, 0, 0};
    heml_allocator al;
    tetmesh mesh;
    heml_model *m;
    heml_probe *p = NULL;
    enum { NP = 40 };
    heml_real pts[3 * NP], out[3 * NP], *u, *v;
    unsigned seed = 7;
    int i, r, k, n3, allocs;
    double worst[3] = {0, 0, 0};
    al.alloc = count_alloc;
    al.free = count_free;
    al.user = &c;
    m = box_model(3, 2, 2, 1.5, 1.0, 0.8, &al, &mesh);
    REQUIRE(m != NULL);
    n3 = 3 * mesh.node_count;
    u = alloc_reals(n3);
    v = alloc_reals(n3);
    for (i = 0; i < mesh.node_count; i++)
        for (r = 0; r < 3; r++) {
            const double *X = mesh.nodes + 3 * i;
            u[3 * i + r] = (heml_real)(A[r][0] * X[0] + A[r][1] * X[1] + A[r][2] * X[2] + bv[r]);
            v[3 * i + r] = (heml_real)(B[r][0] * X[0] + B[r][1] * X[1] + B[r][2] * X[2] - bv[r]);
        }
    heml_set_displacements(m, u);
    heml_set_velocities(m, v);
    for (i = 0; i < NP; i++) { /* interior, then nodes, then points on the faces x = 0 and z = 0.8 */
        double x = 0.75 + 0.74 * rnd(&seed), y = 0.5 + 0.49 * rnd(&seed), z = 0.4 + 0.39 * rnd(&seed);
        if (i >= 20 && i < 30) {
            const double *X = mesh.nodes + 3 * ((i * 7) % mesh.node_count);
            x = X[0], y = X[1], z = X[2];
        }
        if (i >= 30) {
            if (i & 1) x = 0.0;
            else z = 0.8;
        }
        pts[3 * i] = (heml_real)x, pts[3 * i + 1] = (heml_real)y, pts[3 * i + 2] = (heml_real)z;
    }
    CHECK_INT(HEML_OK, heml_probe_create(m, pts, NP, &p));
    REQUIRE(p != NULL);
    allocs = c.allocs;
    for (k = 0; k < 3; k++) {
        CHECK_INT(HEML_OK, k == 0 ? heml_probe_positions(p, m, out)
                                  : k == 1 ? heml_probe_displacements(p, m, out) : heml_probe_velocities(p, m, out));
        for (i = 0; i < NP; i++)
            for (r = 0; r < 3; r++) {
                double X[3], e;
                X[0] = (double)pts[3 * i], X[1] = (double)pts[3 * i + 1], X[2] = (double)pts[3 * i + 2];
                e = k == 2 ? B[r][0] * X[0] + B[r][1] * X[1] + B[r][2] * X[2] - bv[r]
                           : A[r][0] * X[0] + A[r][1] * X[1] + A[r][2] * X[2] + bv[r] + (k == 0 ? X[r] : 0.0);
                e = fabs((double)out[3 * i + r] - e);
                worst[k] = e > worst[k] ? e : worst[k];
            }
    }
    printf("    worst errors: positions %.2g m, displacements %.2g m, velocities %.2g m/s\n", worst[0], worst[1],
           worst[2]);
    CHECK(worst[0] <= (IS_FLOAT ? 1e-6 : 1e-14));
    CHECK(worst[1] <= (IS_FLOAT ? 1e-7 : 1e-15));
    CHECK(worst[2] <= (IS_FLOAT ? 1e-5 : 1e-13));
    CHECK_INT(allocs, c.allocs);
    heml_probe_destroy(p);
    CHECK_INT(1, c.allocs - c.frees); /* the model only */
    free(u);
    free(v);
    heml_destroy(m);
    CHECK_INT(c.allocs, c.frees);
    tetmesh_free(&mesh);
}

/* Points outside the body fail with HEML_ERR_ARG (and leave *out NULL), points on the
   surface within rounding do not; bad arguments; a probe read with another model. */
static void test_probe_errors(void)
{
    tetmesh mesh, mesh2;
    heml_model *m = box_model(2, 2, 2, 1.0, 1.0, 1.0, NULL, &mesh), *m2 = box_model(1, 1, 2, 1.0, 1.0, 1.0, NULL, &mesh2);
    heml_probe *p = (heml_probe *)&mesh; /* must be set to NULL on failure */
    heml_real out[6], far[6] = {0.5, 0.5, 0.5, 1.01, 0.5, 0.5}, edge[6] = {0.5, 0.5, 0.5, 1.0, 1.0, 0.3};
    heml_real nan_pt[3] = {0.5, 0.5, 0.5};
    REQUIRE(m && m2);
    nan_pt[1] = (heml_real)NAN;
    CHECK_INT(HEML_ERR_ARG, heml_probe_create(m, far, 2, &p));
    CHECK(p == NULL);
    CHECK_INT(HEML_ERR_ARG, heml_probe_create(NULL, edge, 2, &p));
    CHECK_INT(HEML_ERR_ARG, heml_probe_create(m, NULL, 2, &p));
    CHECK_INT(HEML_ERR_ARG, heml_probe_create(m, edge, 0, &p));
    CHECK_INT(HEML_ERR_ARG, heml_probe_create(m, edge, 2, NULL));
    CHECK_INT(HEML_ERR_ARG, heml_probe_create(m, nan_pt, 1, &p));
    CHECK_INT(HEML_OK, heml_probe_create(m, edge, 2, &p));
    REQUIRE(p != NULL);
    CHECK_INT(HEML_OK, heml_probe_positions(p, m, out));
    CHECK_NEAR(1.0, (double)out[3], 1e-6);
    CHECK_NEAR(0.3, (double)out[5], 1e-6);
    CHECK_INT(HEML_ERR_ARG, heml_probe_positions(p, m2, out));
    CHECK_INT(HEML_ERR_ARG, heml_probe_velocities(p, m, NULL));
    CHECK_INT(HEML_ERR_ARG, heml_probe_displacements(NULL, m, out));
    heml_probe_destroy(p);
    heml_probe_destroy(NULL);
    heml_destroy(m);
    heml_destroy(m2);
    tetmesh_free(&mesh);
    tetmesh_free(&mesh2);
}


/* ---- modal analysis ------------------------------------------------------------------ */

/* max |x_i . M x_j - delta_ij| over the first k modes */
static double modal_orthonormality(const heml_modal *md, const heml_model *m, int k)
{
    const heml_real *mass = heml_masses(m);
    int i, j, a, n3 = 3 * heml_node_count(m);
    double worst = 0.0;
    for (i = 0; i < k; i++)
        for (j = 0; j <= i; j++) {
            const heml_real *xi = heml_modal_shape(md, i), *xj = heml_modal_shape(md, j);
            double s = 0.0;
            for (a = 0; a < n3; a++) s += (double)mass[a / 3] * (double)xi[a] * (double)xj[a];
            s = fabs(s - (i == j));
            worst = s > worst ? s : worst;
        }
    return worst;
}

/* A free cube (no pins, no gravity) has six rigid modes at 0 Hz, then elastic ones; the
   modes are M-orthonormal to round-off; the model's state and stats are untouched; the
   solve allocates nothing. */
static void test_modal_free_cube(void)
{
    counting_allocator c = {0, 0, 0, 0};
    heml_allocator al;
    tetmesh mesh;
    heml_model *m;
    heml_modal *md = NULL;
    heml_modal_desc d = heml_modal_default_desc();
    heml_stats before;
    int i, allocs, err;
    double f7, orth;
    al.alloc = count_alloc;
    al.free = count_free;
    al.user = &c;
    m = box_model(2, 2, 2, 1.0, 1.0, 1.0, &al, &mesh);
    REQUIRE(m != NULL);
    d.count = 8;
    CHECK_INT(HEML_OK, heml_modal_create(m, &d, &md));
    REQUIRE(md != NULL);
    CHECK_INT(0, heml_modal_count(md));
    CHECK_INT(HEML_OK, heml_step_ex(m, (heml_real)1e-3, HEML_SEMI_EXPLICIT_EULER)); /* some stats */
    before = *heml_last_stats(m);
    allocs = c.allocs;
    err = heml_modal_solve(md, m);
    CHECK_INT(HEML_OK, err);
    CHECK_INT(allocs, c.allocs);
    CHECK(memcmp(&before, heml_last_stats(m), sizeof before) == 0);
    REQUIRE(err == HEML_OK);
    CHECK_INT(8, heml_modal_count(md));
    f7 = heml_modal_frequency(md, 6);
    printf("    frequencies (Hz):");
    for (i = 0; i < 8; i++) printf(" %.3g", heml_modal_frequency(md, i));
    orth = modal_orthonormality(md, m, 8);
    printf("\n    M-orthonormality: %.2g\n", orth);
    for (i = 0; i < 6; i++) CHECK(fabs(heml_modal_frequency(md, i)) <= (IS_FLOAT ? 1e-2 : 1e-5) * f7);
    CHECK(f7 > 0.1);
    CHECK(orth <= (IS_FLOAT ? 1e-5 : 1e-12));
    CHECK(heml_modal_frequency(md, 8) != heml_modal_frequency(md, 8)); /* NaN: out of range */
    CHECK(heml_modal_shape(md, -1) == NULL);
    heml_modal_destroy(md);
    heml_destroy(m);
    CHECK_INT(c.allocs, c.frees);
    tetmesh_free(&mesh);
}

/* A clamped bar held to axial motion (every node's y and z pinned, x = 0 clamped), nu = 0:
   its axial modes f_n = (2 n - 1) / (4 L) sqrt(E / rho). 20 cells along the bar: the lumped
   linear elements' dispersion, 1 - (k h)^2 / 24, puts the third mode 0.64 % low (measured
   -0.04, -0.32, -0.90 %: the tetrahedral cells add a little), so each of the first three
   within 1 %. */
static void test_modal_clamped_bar(void)
{
    tetmesh mesh;
    heml_desc dd = heml_default_desc();
    heml_model *m;
    heml_modal *md = NULL;
    heml_modal_desc d = heml_modal_default_desc();
    heml_real zero[3] = {0, 0, 0};
    int i;
    tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 20, 1, 1, TETMESH_SPLIT5);
    m = make_model_ex(&mesh, heml_material_from_young(HEML_NEO_HOOKEAN, 1e6, 0.0), 0.0, &dd);
    REQUIRE(m != NULL);
    for (i = 0; i < mesh.node_count; i++) heml_set_displacement_axes(m, i, mesh.nodes[3 * i] == 0.0 ? 7u : 6u, zero);
    d.count = 3;
    CHECK_INT(HEML_OK, heml_modal_create(m, &d, &md));
    CHECK_INT(HEML_OK, heml_modal_solve(md, m));
    for (i = 0; i < heml_modal_count(md); i++) {
        double exact = (2 * i + 1) / 4.0 * sqrt(1e6 / 1000.0);
        printf("    axial mode %d: %.5f Hz, closed form %.5f Hz (%+.3f %%)\n", i + 1, heml_modal_frequency(md, i), exact,
               100 * (heml_modal_frequency(md, i) / exact - 1));
        CHECK_REL(exact, heml_modal_frequency(md, i), 1e-2);
    }
    CHECK(modal_orthonormality(md, m, 3) <= (IS_FLOAT ? 1e-5 : 1e-12));
    heml_modal_destroy(md);
    heml_destroy(m);
    tetmesh_free(&mesh);
}

/* R3 (REFERENCES.md): the clamped 1 x 0.1 x 0.1 m beam, E = 1 MPa, nu = 0.3, on the bench's
   beams (10 k x k x k cells of 5 tetrahedra). P1 tetrahedra lock in bending, so the
   bending frequencies converge from above as h^2: measured 0.8334 / 0.6188 / 0.5394 Hz at
   k = 1, 2, 4 (+64, +22, +6 %), the axial mode within 0.5 % at k = 2 (no locking).
   Checked: at k = 2 both first bending frequencies between 0.5091 and 1.25 times it (the
   locking error of this mesh), the axial mode (7.9276 Hz) within 0.5 %; no mode below the
   first physical mode (spurious modes) on k = 1 and 2: every computed frequency above
   0.5091 Hz (P1 only stiffens bending), for Neo-Hookean and the mass-spring law; and,
   outside TEST_QUICK, k = 4: the error falls by 3 to 4.5 from k = 2 (second order) and
   the Richardson extrapolation of k = 2 and 4 is within 1.5 % of 0.5091 Hz. */
static void test_modal_r3_beam(void)
{
    static const double f1 = 0.5091, faxial = 7.9276;
    int k, law, kmax = TEST_IS_QUICK || IS_FLOAT ? 2 : 4;
    double fb[5] = {0, 0, 0, 0, 0};
    for (law = 0; law < 2; law++)
        for (k = 1; k <= kmax; k *= 2) {
            tetmesh mesh;
            heml_model *m;
            heml_modal *md = NULL;
            heml_modal_desc d = heml_modal_default_desc();
            heml_material mt = heml_material_from_young(law ? HEML_MASS_SPRING : HEML_NEO_HOOKEAN, 1e6, 0.3);
            int i, err;
            if (law && k > 2) break;
            tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 10 * k, k, k, TETMESH_SPLIT5);
            m = make_model_ex(&mesh, mt, 0.0, NULL);
            REQUIRE(m != NULL);
            for (i = 0; i < mesh.node_count; i++)
                if (mesh.nodes[3 * i] == 0.0) heml_fix_node(m, i);
            d.count = k > 2 ? 2 : 6; /* k = 4: only the first bending pair (time) */
            CHECK_INT(HEML_OK, heml_modal_create(m, &d, &md));
            err = heml_modal_solve(md, m);
            CHECK_INT(HEML_OK, err);
            printf("    %s %d x %d x %d:", law ? "springs" : "Neo-Hookean", 10 * k, k, k);
            for (i = 0; i < heml_modal_count(md); i++) printf(" %.4f", heml_modal_frequency(md, i));
            printf(" Hz\n");
            if (err == HEML_OK) {
                for (i = 0; i < d.count; i++) CHECK(heml_modal_frequency(md, i) > f1); /* no spurious mode */
                if (!law) fb[k] = heml_modal_frequency(md, 0);
                if (!law && k == 2) {
                    CHECK(heml_modal_frequency(md, 1) < 1.25 * f1);
                    CHECK_REL(faxial, heml_modal_frequency(md, 5), 5e-3);
                }
                CHECK(modal_orthonormality(md, m, d.count) <= (IS_FLOAT ? 1e-5 : 1e-12));
            }
            heml_modal_destroy(md);
            heml_destroy(m);
            tetmesh_free(&mesh);
        }
    if (kmax >= 4) {
        double ratio = (fb[2] - f1) / (fb[4] - f1), extra = (4 * fb[4] - fb[2]) / 3;
        printf("    error ratio k = 2 / k = 4: %.2f, Richardson %.4f Hz (%+.2f %%)\n", ratio, extra, 100 * (extra / f1 - 1));
        CHECK(ratio > 3.0 && ratio < 4.5);
        CHECK_REL(f1, extra, 1.5e-2);
    }
}

/* Bad descriptions and models; an unstable state (a body squashed beyond buckling would
   do; here a negative shift is refused at create instead, so: a pinned model with every
   axis pinned has no free degree of freedom: HEML_ERR_ARG). */
static void test_modal_errors(void)
{
    tetmesh mesh, mesh2;
    heml_model *m = box_model(1, 1, 1, 1.0, 1.0, 1.0, NULL, &mesh), *m2 = box_model(1, 1, 2, 1.0, 1.0, 1.0, NULL, &mesh2);
    heml_modal *md = (heml_modal *)&mesh;
    heml_modal_desc d = heml_modal_default_desc();
    int i;
    REQUIRE(m && m2);
    d.count = 0;
    CHECK_INT(HEML_ERR_ARG, heml_modal_create(m, &d, &md));
    CHECK(md == NULL);
    d = heml_modal_default_desc();
    d.tolerance = 0;
    CHECK_INT(HEML_ERR_ARG, heml_modal_create(m, &d, &md));
    d = heml_modal_default_desc();
    CHECK_INT(HEML_ERR_ARG, heml_modal_create(NULL, &d, &md));
    CHECK_INT(HEML_OK, heml_modal_create(m, &d, &md));
    CHECK_INT(HEML_ERR_ARG, heml_modal_solve(md, m2)); /* another model */
    for (i = 0; i < heml_node_count(m); i++) heml_fix_node(m, i);
    CHECK_INT(HEML_ERR_ARG, heml_modal_solve(md, m)); /* no free degree of freedom */
    CHECK_INT(0, heml_modal_count(md));
    d.max_iterations = 1;
    heml_modal_destroy(md);
    for (i = 0; i < heml_node_count(m); i++) heml_release_node(m, i);
    CHECK_INT(HEML_OK, heml_modal_create(m, &d, &md));
    CHECK_INT(HEML_ERR_NO_CONVERGENCE, heml_modal_solve(md, m)); /* one iteration cannot tell */
    heml_modal_destroy(md);
    heml_modal_destroy(NULL);
    heml_destroy(m);
    heml_destroy(m2);
    tetmesh_free(&mesh);
    tetmesh_free(&mesh2);
}


/* BDF2 with mass damping and a start velocity against its own recurrence computed here:
   beta = 2 dt / 3, xbar = (4 x_n - x_n-1) / 3, vbar likewise, and
       v1 = (x1 - xbar) / beta,  m (v1 - vbar) / beta = -k x1 - alpha m v1,
   i.e. x1 = (m (1 + beta alpha) xbar + m beta vbar) / (m (1 + beta alpha) + beta^2 k),
   the first step being implicit Euler (the same with beta = dt, xbar = x0, vbar = v0). */
static void test_bdf2_damped_recurrence(void)
{
    osc1 o;
    double alpha = 3.0, dt, x = 0, v = 0, xp = 0, vp = 0, worst = 0.0;
    heml_real z[12], w[12];
    int s;
    REQUIRE(osc1_make(&o, alpha, NULL));
    dt = 2 * PI / o.omega / 40;
    memset(z, 0, sizeof z);
    memset(w, 0, sizeof w);
    x = 0.4 * o.amp, v = 0.5 * o.omega * o.amp; /* an excursion of about the amplitude (small: linear) */
    z[11] = (heml_real)x;
    w[11] = (heml_real)v;
    heml_set_displacements(o.m, z);
    heml_set_velocities(o.m, w);
    for (s = 0; s < 60; s++) {
        double beta = s ? 2 * dt / 3 : dt, xbar = s ? (4 * x - xp) / 3 : x, vbar = s ? (4 * v - vp) / 3 : v, x1, v1, e;
        x1 = (o.mass * (1 + beta * alpha) * xbar + o.mass * beta * vbar) / (o.mass * (1 + beta * alpha) + beta * beta * o.k);
        v1 = (x1 - xbar) / beta;
        xp = x, vp = v, x = x1, v = v1;
        CHECK_INT(HEML_OK, heml_step_ex(o.m, (heml_real)dt, HEML_BDF2));
        e = fabs((double)heml_displacements(o.m)[11] - x) / o.amp;
        worst = e > worst ? e : worst;
    }
    printf("    worst relative difference from the recurrence over 60 steps: %.2g (|x| now %.3g of the amplitude)\n",
           worst, fabs(x) / o.amp);
    CHECK(worst <= (IS_FLOAT ? 3e-3 : 1e-5)); /* measured 3e-4 and 3.1e-7 */
    heml_destroy(o.m);
}

/* R3's first mode (the bench's 10 x 1 x 1 beam, clamped, released from its first discrete
   mode shape found by heml_modal_solve, 1 mm at the tip, read by a probe at the tip centre):
   per period the decay and the period error fitted from the tip's motion equal the
   schemes' closed forms of the linear oscillator at that mode's frequency (decay to 1e-3
   relative where it is above 1 % a period, else to 1e-5 absolute: the other modes, excited
   at the 1e-4 level by the mode shape's own tolerance, perturb the fit there; period error
   to 1e-4 of T; float: 1e-2 relative, 1e-4 absolute, 1e-3), and BDF2's period error falls
   by 4 (3.5 .. 4.5) from T/25 to T/50 to T/100. */
static void test_bdf2_r3_first_mode(void)
{
    static const int pers[3] = {25, 50, 100};
    tetmesh mesh;
    heml_desc dd = heml_default_desc();
    heml_model *m;
    heml_modal *md = NULL;
    heml_modal_desc d = heml_modal_default_desc();
    heml_probe *p = NULL;
    heml_real tip[3] = {1.0, 0.0, 0.0}, out[3], *u0, *zero; /* the tip centre (tetmesh_beam is centred on y, z = 0) */
    double f, T, amp, dir[3], perr_bdf2[3];
    int i, n3, k, l;
    tetmesh_beam(&mesh, 1.0, 0.1, 0.1, 10, 1, 1, TETMESH_SPLIT5);
    dd.newton_tolerance = (heml_real)(IS_FLOAT ? 1e-5 : 1e-10);
    dd.cg_tolerance = (heml_real)(IS_FLOAT ? 1e-6 : 1e-10);
    m = make_model_ex(&mesh, heml_material_from_young(HEML_NEO_HOOKEAN, 1e6, 0.3), 0.0, &dd);
    REQUIRE(m != NULL);
    n3 = 3 * mesh.node_count;
    for (i = 0; i < mesh.node_count; i++)
        if (mesh.nodes[3 * i] == 0.0) heml_fix_node(m, i);
    d.count = 1;
    REQUIRE(heml_modal_create(m, &d, &md) == HEML_OK);
    REQUIRE(heml_modal_solve(md, m) == HEML_OK);
    REQUIRE(heml_probe_create(m, tip, 1, &p) == HEML_OK);
    f = heml_modal_frequency(md, 0);
    T = 1 / f;
    u0 = alloc_reals(n3);
    zero = alloc_reals(n3);
    memcpy(u0, heml_modal_shape(md, 0), sizeof(heml_real) * n3);
    heml_set_displacements(m, u0);
    heml_probe_displacements(p, m, out);
    amp = sqrt((double)out[0] * out[0] + (double)out[1] * out[1] + (double)out[2] * out[2]);
    for (i = 0; i < 3; i++) dir[i] = (double)out[i] / amp;
    for (i = 0; i < n3; i++) u0[i] = (heml_real)((double)u0[i] * 1e-3 / amp);
    for (k = 0; k < 2; k++)
        for (l = 0; l < 3; l++) {
            int per = pers[l], s, steps = 3 * per;
            double h = T / per, s11 = 0, s12 = 0, s22 = 0, r1 = 0, r2 = 0, zm1 = 0, zm2 = 0, a, b, det, mod, arg;
            double decay, perr, re, im, tdecay, tperr;
            heml_set_displacements(m, u0);
            heml_set_velocities(m, zero);
            for (s = 1; s <= steps; s++) {
                double zt;
                REQUIRE(heml_step_ex(m, (heml_real)h, k ? HEML_BDF2 : HEML_IMPLICIT_EULER) == HEML_OK);
                heml_probe_displacements(p, m, out);
                zt = ((double)out[0] * dir[0] + (double)out[1] * dir[1] + (double)out[2] * dir[2]) / 1e-3;
                if (s > per / 2 + 2) {
                    s11 += zm1 * zm1;
                    s12 += zm1 * zm2;
                    s22 += zm2 * zm2;
                    r1 += zt * zm1;
                    r2 += zt * zm2;
                }
                zm2 = zm1;
                zm1 = zt;
            }
            det = s11 * s22 - s12 * s12;
            a = (r1 * s22 - r2 * s12) / det;
            b = (s11 * r2 - s12 * r1) / det;
            mod = sqrt(-b);
            arg = acos(a / (2 * mod));
            decay = 1 - pow(mod, per);
            perr = 2 * PI / (per * arg) - 1;
            amplification(k, 2 * PI / per, &re, &im);
            tdecay = 1 - pow(sqrt(re * re + im * im), per);
            tperr = 2 * PI / (per * atan2(im, re)) - 1;
            printf("    R3 %.4f Hz, %-14s T/%-3d decay %.6f (%.6f), period error %+.6f (%+.6f)\n", f,
                   k ? "BDF2" : "implicit Euler", per, decay, tdecay, perr, tperr);
            if (tdecay > 1e-2) CHECK_REL(tdecay, decay, IS_FLOAT ? 1e-2 : 1e-3);
            else CHECK_NEAR(tdecay, decay, IS_FLOAT ? 1e-4 : 1e-5);
            CHECK_NEAR(tperr, perr, IS_FLOAT ? 1e-3 : 1e-4);
            if (k) perr_bdf2[l] = perr;
        }
    printf("    BDF2 period error ratios %.3f %.3f\n", perr_bdf2[0] / perr_bdf2[1], perr_bdf2[1] / perr_bdf2[2]);
    CHECK(perr_bdf2[0] / perr_bdf2[1] > 3.5 && perr_bdf2[0] / perr_bdf2[1] < 4.5);
    CHECK(perr_bdf2[1] / perr_bdf2[2] > 3.5 && perr_bdf2[1] / perr_bdf2[2] < 4.5);
    free(u0);
    free(zero);
    heml_probe_destroy(p);
    heml_modal_destroy(md);
    heml_destroy(m);
    tetmesh_free(&mesh);
}

static const test_case cases[] = {
    TEST(test_bdf2_order),
    TEST(test_bdf2_decay_closed_form),
    TEST(test_bdf2_restarts),
    TEST(test_bdf2_no_allocation),
    TEST(test_bdf2_stress_sweep),
    TEST(test_probe_affine_exact),
    TEST(test_probe_errors),
    TEST(test_modal_free_cube),
    TEST(test_modal_clamped_bar),
    TEST(test_modal_r3_beam),
    TEST(test_modal_errors),
    TEST(test_bdf2_damped_recurrence),
    TEST(test_bdf2_r3_first_mode),
};

int main(int argc, char **argv) { return TEST_MAIN(argc, argv, cases); }
