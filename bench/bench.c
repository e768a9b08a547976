/* bench.c - what each model costs and how accurate it is, on this machine.

   make bench         the full run (about 11 minutes on 2 cores: 672 s on an AMD EPYC Zen 5, 2 vCPUs,
                      2026-12-02; trade 261, stability 67, sweep 104, time 26, coarse 6, kernels 207; the race,
                      added since, 92 s on the Intel Xeon of README under a load of 8-9): bench/results/
   make bench-quick   the smallest sizes (about a minute: 58 s there): build/bench-quick/

   build/bench/bench [--quick] [--out DIR] [--parts trade,race,stability,sweep,time,coarse,kernels]
                     [--filter TEXT] [--scenes R1,R3,...] [--repeats N] [--threads N] [--budget SECONDS]
                     [--race-budget SECONDS]

   --budget: a refinement series stops at the first level whose answer takes longer
   (default 2 s; law variants get a quarter). Raise it to see finer levels.

   1. trade: scenes with known answers (REFERENCES.md R1-R5, a cutting scene and NI, a
      near-incompressible cantilever against Timoshenko (issue 13); R1 and R3
      against the converged 3D solid, R3's frequency corrected for the integrator's phase
      error, see integrator_frequency; beam tips read at the free face's centre through
      the models' point probes, tip_deflection), for every
      model entry x resolution x integrator: DoF, seconds per step, seconds to the answer,
      error. trade.csv, one SVG per scene (error against time, Pareto front), and the
      cheapest configuration reaching 10 %, 1 % and 0.1 % error.
   1b. race (>>race, alone with --parts race): frames (hexahedral, tetrahedral), heml.h's
      P1 Neo-Hookean and tensormass.h's linear tetrahedra refined level by level on R1 until
      within 1 %, or --race-budget seconds each (default 60; --quick 0.5): issue 21's
      same-run comparison. race.csv and a ratio line.
   2. stability: largest stable time step by bisection, Poisson ratio towards 0.5, a
      tetrahedron pushed through zero volume, a 180 degree twist, the scene 1e6 m from the
      origin; each outcome classified. stability.csv. Then the stress sweep (>>sweep, also
      alone with --parts sweep): every model entry over E, nu, static and implicit Euler
      at dt 1e-6 to 1 s, each run right, an error code, or a success with a wrong answer
      (the count issue 18 wants at zero). sweep.csv.
   3. time (>>time, alone with --parts time): the R3 beam and the R2 cantilever released
      from a static deflection, implicit Euler and BDF2 at dt = T/20 to T/400: period
      error, amplitude decay per period, seconds of computing per simulated second.
      time.csv.
   3b. coarse (>>coarse, alone with --parts coarse): heml.h's and tensormass.h's implicit
      steps on the R3 and R1 beams at E = 1 kPa to 10 MPa and dt = 1 ms to 1 s, with and
      without the coarse correction (issue 21): iterations and time per step (--filter
      tensormass or heml for one library). coarse.csv.
   4. kernels: force and K*v per element from 1e3 to 1e6 elements, 1 and 2 threads, against
      the memory-bandwidth bound of the bytes each header says its kernel moves, with the
      bandwidth measured in the same run by a STREAM triad. kernels.csv.

   Every CSV row carries the date, compiler, flags, CPU and git revision. Timing uses the
   monotonic clock, medians of repeated runs after a warm-up. Figures are printed, never
   asserted. Adding a model: an entry in an adapter's table (bench/model_*.c) or one more
   line in `registry` below. */
#define _POSIX_C_SOURCE 199309L
#include "bench.h"
#include "svg.h"
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#ifndef BENCH_FLAGS
#define BENCH_FLAGS "unknown"
#endif
#ifndef BENCH_GIT
#define BENCH_GIT "unknown"
#endif

/* >>registry: one line per adapter table (each compiled in double and in float) */
const bench_model *bench_models_tensormass_double(int *count);
const bench_model *bench_models_tensormass_float(int *count);
const bench_model *bench_models_heml_double(int *count);
const bench_model *bench_models_heml_float(int *count);
const bench_model *bench_models_frames_double(int *count);
const bench_model *bench_models_frames_float(int *count);
int bench_chain_rows_double(int quick, double (*clock_s)(void), const char **names, double *sizes, double *seconds);
int bench_chain_rows_float(int quick, double (*clock_s)(void), const char **names, double *sizes, double *seconds);
/* heml.h's implicit steps with and without the coarse correction (issue 21): bench/model_heml.c */
int bench_heml_coarse_rows_double(int quick, double (*clock_s)(void), bench_coarse_row *rows, int max);
/* tensormass.h's (issue 21): bench/model_tensormass.c */
int bench_tensormass_coarse_rows_double(int quick, double (*clock_s)(void), bench_coarse_row *rows, int max);
/* the coupled scenes (issue 14): bench/model_glue.c, not a bench_model (two models glued) */
int bench_glue_rows_double(int quick, double *v);
int bench_glue_rows_float(int quick, double *v);

static const bench_models_fn registry[] = {
    bench_models_tensormass_double, bench_models_tensormass_float, bench_models_heml_double,
    bench_models_heml_float,        bench_models_frames_double,    bench_models_frames_float,
};

/* peers (issue 21): other libraries, timed by the kernels part only (bench/peer_*.cpp,
   built when their packages are installed: see the Makefile) */
#ifdef BENCH_HAVE_BULLET
#ifdef __cplusplus
extern "C"
#endif
const bench_model *bench_models_bullet(int *count);
#endif

#define BIT(i) (1u << (i))
#define PI 3.14159265358979323846
static const char *integrator_name[BENCH_INTEGRATOR_COUNT] = {"explicit-euler", "semi-implicit-euler", "rk4",
                                                              "implicit-euler", "static", "bdf2"};

/* >>options and environment */
typedef struct options {
    int quick, repeats, threads;
    const char *out, *filter;
    const char *scenes; /* --scenes: trade scenes to run (comma list of names; NULL: all) */
    int parts; /* bits: 1 trade, 2 stability, 4 kernels, 8 sweep, 16 time, 32 coarse, 64 race */
    double budget; /* s: a configuration slower than this stops its refinement */
    double race_budget; /* s: the race's per-entry budget (negative: the default) */
} options;

static char env_date[32], env_cpu[128], env_compiler[128];

static void read_environment(void)
{
    time_t t = time(NULL);
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[256];
    strftime(env_date, sizeof env_date, "%Y-%m-%dT%H:%M:%SZ", gmtime(&t));
    strcpy(env_cpu, "unknown");
    while (f && fgets(line, sizeof line, f))
        if (strncmp(line, "model name", 10) == 0) {
            char *c = strchr(line, ':');
            if (c) {
                size_t n;
                snprintf(env_cpu, sizeof env_cpu, "%s", c + 2);
                n = strlen(env_cpu);
                while (n && (env_cpu[n - 1] == '\n' || env_cpu[n - 1] == ' ')) env_cpu[--n] = 0;
            }
            break;
        }
    if (f) fclose(f);
#if defined(__clang__)
    snprintf(env_compiler, sizeof env_compiler, "clang %s", __clang_version__);
#elif defined(__GNUC__)
    snprintf(env_compiler, sizeof env_compiler, "gcc %s", __VERSION__);
#else
    strcpy(env_compiler, "unknown");
#endif
    for (t = 0; env_cpu[t]; t++)
        if (env_cpu[t] == ',') env_cpu[t] = ' ';
}

static FILE *open_csv(const options *o, const char *name, const char *columns)
{
    char path[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", o->out, name);
    f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "bench: cannot write %s\n", path);
        exit(1);
    }
    fprintf(f, "date,compiler,flags,cpu,git,%s\n", columns);
    return f;
}

static void csv_prefix(FILE *f) { fprintf(f, "%s,%s,%s,%s,%s,", env_date, env_compiler, BENCH_FLAGS, env_cpu, BENCH_GIT); }

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

static void set_threads(int n)
{
#ifdef _OPENMP
    omp_set_num_threads(n);
#else
    (void)n;
#endif
}

static int selected(const options *o, const bench_model *m)
{
    char name[128];
    if (!o->filter) return 1;
    snprintf(name, sizeof name, "%s/%s/%s", m->model, m->variant, m->precision);
    return strstr(name, o->filter) != NULL;
}

/* >>scene helpers */

static bench_body make_body(double L, double W, double H, int nx, int ny, int nz, double young,
                            double poisson, double density)
{
    bench_body b;
    memset(&b, 0, sizeof b);
    b.size[0] = L, b.size[1] = W, b.size[2] = H;
    b.cells[0] = nx, b.cells[1] = ny, b.cells[2] = nz;
    b.young = young, b.poisson = poisson, b.density = density;
    b.gravity[2] = -9.81;
    b.clamp = 1;
    return b;
}

/* Mean displacement of the nodes whose rest coordinate `axis` (offset removed) is within
   tol of value. Returns the number of such nodes. */
static int face_mean(const bench_model *m, void *sim, const bench_body *b, int axis, double value,
                     double tol, double u[3])
{
    int i, k, n = 0, count = m->node_count(sim);
    double p0[3], p[3];
    u[0] = u[1] = u[2] = 0;
    for (i = 0; i < count; i++) {
        m->rest(sim, i, p0);
        if (fabs(p0[axis] - b->offset[axis] - value) > tol) continue;
        m->position(sim, i, p);
        for (k = 0; k < 3; k++) u[k] += p[k] - p0[k];
        n++;
    }
    for (k = 0; n && k < 3; k++) u[k] /= n;
    return n;
}

/* The tip deflection (-u_z) at the centre of the free end face (REFERENCES R1), through
   the model's point probe; the mean over the free face's nodes where a model has no probe
   or the probe fails (a float body far from the origin). */
static double tip_deflection(const bench_model *m, void *sim, const bench_body *b)
{
    double u[3], p[3];
    p[0] = b->offset[0] + b->size[0], p[1] = b->offset[1], p[2] = b->offset[2];
    if (m->probe && !m->probe(sim, p, u)) return -u[2];
    face_mean(m, sim, b, 0, b->size[0], 1e-6 * b->size[0], u);
    return -u[2];
}

static int all_finite(const bench_model *m, void *sim)
{
    int i, k, n = m->node_count(sim);
    double p[3];
    for (i = 0; i < n; i++) {
        m->position(sim, i, p);
        for (k = 0; k < 3; k++)
            if (!(fabs(p[k]) < HUGE_VAL)) return 0;
    }
    return 1;
}

/* Timoshenko tip deflection of a clamped cantilever of square section a x a under its own
   weight (kappa = 10 (1 + nu) / (12 + 11 nu), rectangular section). */
static double timoshenko_tip(double L, double a, double young, double nu, double density, double g)
{
    double A = a * a, I = a * a * a * a / 12.0, q = density * g * A, G = young / (2 * (1 + nu));
    double kappa = 10 * (1 + nu) / (12 + 11 * nu);
    return q * L * L * L * L / (8 * young * I) + q * L * L / (2 * kappa * G * A);
}

/* >>trade */

typedef struct trade_row {
    char scene[24], setting[48];
    const bench_model *m;
    int level, dof, status;
    double elements, setup_s, step_s, answer_s, value, reference, error;
    double time_step; /* s, dynamic scenes */
    double measured;  /* the value before a correction (R3: the integrator's phase error) */
} trade_row;

static trade_row rows[4096];
static int row_count;

static trade_row *new_row(const char *scene, const bench_model *m, const char *setting, int level)
{
    trade_row *r;
    if (row_count == (int)(sizeof rows / sizeof rows[0])) return NULL;
    r = rows + row_count++;
    memset(r, 0, sizeof *r);
    snprintf(r->scene, sizeof r->scene, "%s", scene);
    snprintf(r->setting, sizeof r->setting, "%s", setting);
    r->m = m;
    r->level = level;
    r->error = r->value = r->reference = r->measured = NAN;
    return r;
}

static void print_row(const trade_row *r)
{
    printf("  %-6s %-10s %-12s %-6s %-22s L%-2d %8d dof  step %9.3g s  answer %9.3g s  value %11.5g  "
           "error %9.3g%s",
           r->scene, r->m->model, r->m->variant, r->m->precision, r->setting, r->level, r->dof, r->step_s,
           r->answer_s, r->value, r->error, r->status ? "  failed:" : "");
    if (r->measured == r->measured && r->measured != r->value) printf("  (measured %.6g)", r->measured);
    printf(r->status ? " code %d\n" : "\n", r->status);
    fflush(stdout);
}

/* Creates the body, runs the static solve `repeats` times on fresh models (only the solve
   is timed) and leaves the last model in *sim for the caller to measure. */
static int timed_static(const bench_model *m, const bench_body *b, int repeats, void **sim, trade_row *r)
{
    double t[8], t0;
    int i, err = 0;
    if (repeats > 8) repeats = 8;
    for (i = 0; i < repeats; i++) {
        if (i) m->destroy(*sim);
        t0 = now();
        err = m->create(b, sim);
        r->setup_s = now() - t0;
        if (err) return err;
        r->dof = m->dof(*sim);
        r->elements = m->elements(*sim);
        t0 = now();
        err = m->solve_static(*sim);
        t[i] = now() - t0;
        if (err) break;
        if (t[i] > 0.3) { /* long solves are not repeated */
            repeats = i + 1;
            break;
        }
    }
    r->step_s = r->answer_s = median(t, err ? i + 1 : repeats);
    return err;
}

static double relative_error(double value, double reference) { return fabs(value - reference) / fabs(reference); }

/* Seconds to the answer after which an entry's refinement stops: the budget for primary
   entries, a quarter of it for their law variants (they repeat the primary's mesh). */
static double budget_of(const bench_model *m, const options *o) { return m->primary ? o->budget : o->budget / 4; }

/* A refinement series stops past the budget, at a failure other than on the coarsest
   level (a mesh one cell across can defeat a model that converges on the next one), or
   when the next level is predicted to take over twice the budget: seconds grow at least
   as the cells, (k_next / k)^3 (the solves' iterations grow too, so this underestimates);
   before this rule a float frames R1 solve at L6 ran 55 s after 0.4 s at L4. levels: the
   scene's refinement levels, n of them, level_index the one just run. */
static int series_done(const trade_row *r, int level_index, const bench_model *m, const options *o,
                       const int *levels, int n)
{
    double growth = level_index + 1 < n ? pow((double)levels[level_index + 1] / levels[level_index], 3) : 0;
    return r->answer_s > budget_of(m, o) || (r->status && level_index > 0) ||
           r->answer_s * growth > 2 * budget_of(m, o);
}

/* R1: the steel cantilever 16 x 0.5 x 0.5 m under its own weight, static, k cells across
   (32k x k x k cells): the solve timed by timed_static (`repeats`), the tip deflection and
   its error against the converged 3D solid of REFERENCES.md R1 (beam theory is 0.28 % off
   it), into r. The trade part's R1 rows and the race. */
static void r1_solve(const bench_model *m, int k, int repeats, trade_row *r)
{
    bench_body b = make_body(16, 0.5, 0.5, 32 * k, k, k, 200e9, 0.3, 7800);
    void *sim = NULL;
    r->reference = !strcmp(m->law, "linear") || !strcmp(m->law, "springs") ? 0.150169 : 0.150158;
    r->status = timed_static(m, &b, repeats, &sim, r);
    if (!r->status) {
        r->value = tip_deflection(m, sim, &b);
        r->error = relative_error(r->value, r->reference);
    }
    if (sim) m->destroy(sim);
}

static void trade_r1(const bench_model *m, const options *o)
{
    static const int levels[] = {1, 2, 3, 4, 6, 8};
    int l, n = o->quick ? 1 : 6;
    if (!(m->integrators & BIT(BENCH_STATIC))) return;
    for (l = 0; l < n; l++) {
        trade_row *r = new_row("R1", m, "static", levels[l]);
        if (!r) return;
        r1_solve(m, levels[l], o->repeats, r);
        print_row(r);
        if (series_done(r, l, m, o, levels, n)) break;
    }
}

/* R2: the soft cantilever 16 x 1 x 1 m, 5 kg, E = 40 kPa: large deformation, no closed
   form. Errors are filled in afterwards against each entry's finest level. */
static void trade_r2(const bench_model *m, const options *o)
{
    static const int levels[] = {1, 2, 3, 4, 6};
    int l, n = o->quick ? 1 : 5;
    if (!(m->integrators & BIT(BENCH_STATIC))) return;
    for (l = 0; l < n; l++) {
        int k = levels[l];
        bench_body b = make_body(16, 1, 1, 16 * k, k, k, 40e3, 0.3, 5.0 / 16.0);
        void *sim = NULL;
        trade_row *r = new_row("R2", m, "static", k);
        if (!r) return;
        r->status = timed_static(m, &b, o->repeats, &sim, r);
        if (!r->status) r->value = tip_deflection(m, sim, &b);
        if (sim) m->destroy(sim);
        print_row(r);
        if (series_done(r, l, m, o, levels, n)) break;
    }
}

/* Self-convergence of R2: each entry against its own finest converged level. */
static void finish_r2(void)
{
    int i, j;
    for (i = 0; i < row_count; i++) {
        trade_row *best = NULL;
        if (strcmp(rows[i].scene, "R2") || rows[i].status) continue;
        for (j = 0; j < row_count; j++)
            if (!strcmp(rows[j].scene, "R2") && rows[j].m == rows[i].m && !rows[j].status &&
                (!best || rows[j].level > best->level))
                best = rows + j;
        rows[i].reference = best->value;
        rows[i].error = best == rows + i ? NAN : relative_error(rows[i].value, best->value);
    }
}

/* The period of a sampled oscillation about zero from its zero crossings (both
   directions, linear interpolation): twice the mean time between consecutive crossings,
   or NAN with fewer than three. */
static double period_of(const double *z, int n, double dt)
{
    double first = -1, last = -1;
    int i, crossings = 0;
    for (i = 1; i < n; i++)
        if ((z[i - 1] < 0) != (z[i] < 0)) {
            double t = dt * (i - 1 + z[i - 1] / (z[i - 1] - z[i]));
            if (first < 0) first = t;
            last = t;
            crossings++;
        }
    return crossings >= 3 ? 2 * (last - first) / (crossings - 1) : NAN;
}

/* The frequency an integrator's discrete oscillation of measured frequency f_h (Hz) at
   step dt comes from. For x'' = -w^2 x, one step multiplies (x, v) by a matrix whose
   eigenvalues turn by theta per step, theta = w_h dt:
     explicit and implicit Euler: (1 -+ i w dt) and its inverse, theta = atan(w dt), so
       w = tan(w_h dt) / dt (the frequency reads low, the period long, by about
       (w dt)^2 / 3: 0.13 % at T/100);
     semi-implicit (symplectic) Euler: cos theta = 1 - (w dt)^2 / 2, so
       w = 2 sin(w_h dt / 2) / dt (reads high by (w dt)^2 / 24);
     RK4: the error is (w dt)^4 / 120, below 1e-7 at the bench's steps: left as measured;
     BDF2: theta = bdf2_turn(w dt) (below), inverted by bisection: the period reads long
       by about (w dt)^2 / 3 too (0.131 % at T/100, as implicit Euler's 0.132 %), but the
       amplitude decays by 0.04 % a period there against implicit Euler's 18 %.
   The first mode of a linear(ised) lumped-mass model is such an oscillator, so the
   correction is exact for it; the other modes decay faster under the Euler schemes. */
static double bdf2_turn(double x)
{
    /* BDF2 on y' = i w y: (3/2 - i x) z^2 - 2 z + 1/2 = 0, the principal root
       z = (2 + sqrt(1 + 2 i x)) / (3 - 2 i x), x = w dt; its argument */
    double r = sqrt(sqrt(1 + 4 * x * x)), a = 0.5 * atan2(2 * x, 1);
    double nr = 2 + r * cos(a), ni = r * sin(a);
    return atan2(nr * 2 * x + ni * 3, nr * 3 - ni * 2 * x);
}

static double integrator_frequency(int integrator, double f_h, double dt)
{
    double wh = 2 * PI * f_h, x = wh * dt;
    if (integrator == BENCH_EXPLICIT_EULER || integrator == BENCH_IMPLICIT_EULER)
        return x < 0.5 * PI ? tan(x) / dt / (2 * PI) : NAN;
    if (integrator == BENCH_SEMI_IMPLICIT_EULER) return 2 * sin(0.5 * x) / dt / (2 * PI);
    if (integrator == BENCH_BDF2) {
        double lo = 0, hi = 4 * x;
        int i;
        if (!(x > 0 && x < 1)) return NAN;
        for (i = 0; i < 60; i++) {
            double mid = 0.5 * (lo + hi);
            if (bdf2_turn(mid) < x) lo = mid;
            else hi = mid;
        }
        return 0.5 * (lo + hi) / dt / (2 * PI);
    }
    return f_h;
}

/* R3: first bending frequency of the clamped 1 x 0.1 x 0.1 m beam (E = 1 MPa), released
   from its static deflection under a small load (tip about 1.5 mm), per integrator. The
   frequency is measured from the tip's zero crossings and corrected for the integrator's
   phase error (integrator_frequency); the uncorrected one is the row's `measured`. */
static void trade_r3(const bench_model *m, const options *o)
{
    static const int levels[] = {1, 2, 3, 4};
    const double f_ref = 0.5091, T = 1.0 / f_ref; /* the converged 3D solid, REFERENCES.md R3 */
    int l, it, n = o->quick ? 1 : 4;
    if (!(m->integrators & BIT(BENCH_STATIC)) || !m->primary) return;
    for (it = 0; it < BENCH_STATIC; it++) {
        int variants = it == BENCH_IMPLICIT_EULER ? 2 : 1, v;
        if (!(m->integrators & BIT(it))) continue;
        for (v = 0; v < variants; v++)
            for (l = 0; l < n; l++) {
                int k = levels[l], steps, s, err = 0;
                bench_body b = make_body(1, 0.1, 0.1, 10 * k, k, k, 1e6, 0.3, 1000);
                double h = 0.1 / k, lambda = b.young * b.poisson / ((1 + b.poisson) * (1 - 2 * b.poisson)),
                       mu = b.young / (2 * (1 + b.poisson)), cp = sqrt((lambda + 2 * mu) / b.density), dt, t0,
                       *z, g0[3] = {0, 0, 0};
                void *sim = NULL;
                char setting[48];
                trade_row *r;
                /* explicit schemes: a fifth of the P-wave transit time of a cell (below
                   their stability limit); implicit: 100 and 400 steps per period */
                dt = it == BENCH_IMPLICIT_EULER ? T / (v ? 400 : 100) : 0.2 * h / cp;
                snprintf(setting, sizeof setting, "%s dt=%s", integrator_name[it],
                         it == BENCH_IMPLICIT_EULER ? (v ? "T/400" : "T/100") : "0.2h/c");
                r = new_row("R3", m, setting, k);
                if (!r) return;
                r->time_step = dt;
                r->reference = f_ref;
                b.gravity[2] = -0.01;
                t0 = now();
                err = m->create(&b, &sim);
                r->setup_s = now() - t0;
                if (!err) err = m->solve_static(sim);
                if (!err) err = m->set_gravity(sim, g0);
                steps = (int)ceil(1.4 * T / dt); /* crossings at T/4, 3T/4, 5T/4 */
                z = (double *)malloc(sizeof(double) * (size_t)(steps + 1));
                if (!err && z) {
                    r->dof = m->dof(sim);
                    r->elements = m->elements(sim);
                    z[0] = -tip_deflection(m, sim, &b);
                    t0 = now();
                    for (s = 1; s <= steps && !err; s++) {
                        err = m->step(sim, dt, it);
                        z[s] = -tip_deflection(m, sim, &b); /* measured, not timed apart */
                    }
                    r->answer_s = now() - t0;
                    r->step_s = r->answer_s / (s - 1);
                    if (!err && !all_finite(m, sim)) err = -9999; /* silent non-finite */
                    if (!err) {
                        r->measured = 1.0 / period_of(z, steps + 1, dt);
                        r->value = integrator_frequency(it, r->measured, dt);
                        r->error = relative_error(r->value, f_ref);
                        if (!(r->error < HUGE_VAL)) r->error = 1.0; /* no oscillation left */
                    }
                }
                free(z);
                r->status = err;
                if (sim) m->destroy(sim);
                print_row(r);
                if (series_done(r, l, m, o, levels, n)) break;
            }
    }
}

/* Lateral stretch t and P_zz of a uniaxial stretch s (REFERENCES.md R4, R5). */
static void uniaxial_reference(int neo_hookean, double mu, double lambda, double s, double *t, double *pzz)
{
    if (!neo_hookean) { /* St Venant-Kirchhoff: S_xx = 0 gives t^2 */
        *t = sqrt(1 - lambda * (s * s - 1) / (2 * (lambda + mu)));
        *pzz = mu * (3 * lambda + 2 * mu) / (2 * (lambda + mu)) * (s * s * s - s);
    } else { /* P_xx = mu (t - 1/t) + lambda ln(s t^2) / t = 0, scalar Newton from t = 1 */
        double x = 1;
        int i;
        for (i = 0; i < 50; i++) {
            double f = mu * (x - 1 / x) + lambda * log(s * x * x) / x;
            double df = mu * (1 + 1 / (x * x)) + lambda * (2 - log(s * x * x)) / (x * x);
            x -= f / df;
        }
        *t = x;
        *pzz = mu * (s - 1 / s) + lambda * log(s * x * x) / s;
    }
}

/* R4 / R5: a unit cube stretched along z to s, its end faces held at the uniaxial
   solution (lateral stretch t of the closed form), its sides free; P_zz from the force
   holding the top face, loaded in four increments. */
static void trade_uniaxial(const bench_model *m, const options *o, int neo_hookean)
{
    static const int levels[] = {1, 2, 3, 4};
    static const double stretches[] = {0.7, 1.3};
    const char *scene = neo_hookean ? "R5" : "R4";
    int l, q, n = o->quick ? 1 : 4;
    if (!(m->integrators & BIT(BENCH_STATIC))) return;
    if (strcmp(m->law, neo_hookean ? "neo-hookean" : "svk") && strcmp(m->law, "linear") && strcmp(m->law, "springs"))
        return;
    for (q = 0; q < 2; q++)
        for (l = 0; l < n; l++) {
            int k = levels[l], inc, i, count, err;
            bench_body b = make_body(1, 1, 1, k, k, k, 1e4, 0.3, 1000);
            double mu = b.young / (2 * (1 + b.poisson)),
                   lambda = b.young * b.poisson / ((1 + b.poisson) * (1 - 2 * b.poisson)), t, pzz, t0, *f;
            void *sim = NULL;
            char setting[48];
            trade_row *r;
            snprintf(setting, sizeof setting, "static s=%.1f", stretches[q]);
            r = new_row(scene, m, setting, k);
            if (!r) return;
            b.clamp = 0;
            b.gravity[2] = 0;
            uniaxial_reference(neo_hookean, mu, lambda, stretches[q], &t, &pzz);
            r->reference = pzz;
            t0 = now();
            err = m->create(&b, &sim);
            r->setup_s = now() - t0;
            if (err) {
                r->status = err;
                print_row(r);
                break;
            }
            count = m->node_count(sim);
            r->dof = m->dof(sim);
            r->elements = m->elements(sim);
            t0 = now();
            for (inc = 1; inc <= 4 && !err; inc++) {
                double si = 1 + (stretches[q] - 1) * inc / 4.0, ti, pi;
                uniaxial_reference(neo_hookean, mu, lambda, si, &ti, &pi);
                for (i = 0; i < count; i++) {
                    double p[3], u[3];
                    m->rest(sim, i, p);
                    if (fabs(fabs(p[2]) - 0.5) > 1e-9) continue;
                    u[0] = (ti - 1) * (p[0] - 0.5);
                    u[1] = (ti - 1) * p[1];
                    u[2] = (si - 1) * p[2];
                    m->pin(sim, i, u, NULL);
                }
                err = m->solve_static(sim);
            }
            r->answer_s = now() - t0;
            r->step_s = r->answer_s / 4;
            f = (double *)malloc(sizeof(double) * 3 * (size_t)count);
            if (!err && f && !(err = m->forces(sim, f))) {
                double sum = 0;
                for (i = 0; i < count; i++) {
                    double p[3];
                    m->rest(sim, i, p);
                    if (p[2] > 0.5 - 1e-9) sum -= f[3 * i + 2];
                }
                r->value = sum; /* reference area 1 m^2 */
                r->error = relative_error(r->value, pzz);
            }
            free(f);
            r->status = err;
            m->destroy(sim);
            print_row(r);
            if (series_done(r, l, m, o, levels, n)) break;
        }
}

static void trade_r4(const bench_model *m, const options *o) { trade_uniaxial(m, o, 0); }
static void trade_r5(const bench_model *m, const options *o) { trade_uniaxial(m, o, 1); }

/* The cut region: a notch through the upper half at mid-length, one cell wide. */
typedef struct notch {
    double half_width;
} notch;

static int in_notch(const double c[3], void *user)
{
    const notch *n = (const notch *)user;
    return fabs(c[0] - 0.5) < n->half_width && c[2] > 0;
}

/* Cutting: a 1 x 0.1 x 0.1 m cantilever (E = 100 MPa) notched at mid-length, then solved
   statically. "cut" removes the notch from a live model (step = the cut); "rebuild"
   creates the model without it. Reference: the double "rebuild" of the same variant. */
static void trade_cut(const bench_model *m, const options *o)
{
    static const int levels[] = {1, 2, 3, 4, 6};
    int l, n = o->quick ? 1 : 5, pass;
    if (!m->cut || !(m->integrators & BIT(BENCH_STATIC))) return;
    for (l = 0; l < n; l++) {
        int k = levels[l];
        notch region;
        double reference = NAN, slow = 0;
        region.half_width = 0.5 * 0.1 / k;
        for (pass = 0; pass < 2; pass++) { /* 0: rebuild, 1: cut */
            bench_body b = make_body(1, 0.1, 0.1, 10 * k, k, k, 1e8, 0.3, 1000);
            void *sim = NULL;
            trade_row *r = new_row("cut", m, pass ? "cut + static" : "rebuild + static", k);
            double t0;
            int err, removed = 0, j;
            if (!r) return;
            if (!pass) {
                b.exclude = in_notch;
                b.exclude_user = &region;
            }
            t0 = now();
            err = m->create(&b, &sim);
            r->setup_s = now() - t0;
            if (!err) {
                t0 = now();
                if (pass) err = m->cut(sim, in_notch, &region, &removed);
                r->step_s = now() - t0;
                if (!err) err = m->solve_static(sim);
                r->answer_s = now() - t0 + (pass ? 0 : r->setup_s);
                if (!pass) r->step_s = r->setup_s;
                r->dof = m->dof(sim);
                r->elements = m->elements(sim);
            }
            if (!err) {
                r->value = tip_deflection(m, sim, &b);
                if (!pass) /* the reference: this variant in double, rebuilt */
                    for (j = 0; j < row_count; j++)
                        if (!strcmp(rows[j].scene, "cut") && rows[j].level == k && rows[j].m->model == m->model &&
                            !strcmp(rows[j].m->variant, m->variant) && !strcmp(rows[j].m->precision, "double") &&
                            !strncmp(rows[j].setting, "rebuild", 7))
                            reference = rows[j].value;
                r->reference = reference;
                r->error = relative_error(r->value, reference);
            }
            r->status = err;
            if (sim) m->destroy(sim);
            print_row(r);
            slow = slow > r->answer_s ? slow : r->answer_s;
            if (err) return;
        }
        if (slow > budget_of(m, o)) break;
    }
}

/* NI: near-incompressible tissue (issue 13). The Poisson rows' cantilever (1 x 0.1 x
   0.1 m, E = 1 MPa, nu = 0.499, its own weight scaled for a tip deflection of about 1 cm:
   strains below 1e-3, where every law is linear elasticity) refined as 10k x k x k cells,
   static, against Timoshenko's tip deflection with shear (timoshenko_tip, kappa = 10 (1 +
   nu) / (12 + 11 nu)): an analytic answer valid as nu -> 0.5, independent of every model.
   How far beam theory is from the 3D solid at this slenderness (the clamped face restrains
   the section's warping and its lateral contraction) bounds what the table's 1 % row can
   mean: see the README's figures. Every entry with a static solver runs it, the option
   entries (primary -1: heml nodal-p, frames vol=) included, at the full budget (they are
   what the scene is for); law variants (primary 0) do not (at 1e-3 strain a law is a law),
   nor float entries (locking is not a matter of precision; floats doubled the scene's time
   and a float frames tet4 solve at k = 6 ran 79 s to fail). Levels from k = 2: one cell
   across cannot bend a near-incompressible section, its errors are accidents of
   cancellation (frames svk tet4 measured 2.4 % at k = 1, 15.5 % at k = 2); to k = 6: k = 8
   took 3 to 5 s an entry and no entry reached 10 % there that had not at k = 6 (plain P1
   10.8 %), which kept the scene near 40 s. */
static void trade_ni(const bench_model *m, const options *o)
{
    static const int levels[] = {2, 3, 4, 6};
    int l, n = o->quick ? 1 : 4;
    if (!(m->integrators & BIT(BENCH_STATIC)) || !m->primary || strcmp(m->precision, "double")) return;
    for (l = 0; l < n; l++) {
        int k = levels[l];
        bench_body b = make_body(1, 0.1, 0.1, 10 * k, k, k, 1e6, 0.499, 1000);
        void *sim = NULL;
        trade_row *r = new_row("NI", m, "static nu=0.499", k);
        if (!r) return;
        b.gravity[2] = -0.01 / 1.5e5 * b.young;
        r->reference = timoshenko_tip(1, 0.1, b.young, b.poisson, b.density, -b.gravity[2]);
        r->status = timed_static(m, &b, o->repeats, &sim, r);
        if (!r->status) {
            r->value = tip_deflection(m, sim, &b);
            r->error = relative_error(r->value, r->reference);
        }
        if (sim) m->destroy(sim);
        print_row(r);
        /* (the predicted stop first cut frames svk tet4's k = 6 here: 8 s on the loaded
           Zen 5 for 9.3 %) */
        if (series_done(r, l, m, o, levels, n)) break;
    }
}

typedef struct scene {
    const char *name, *title;
    void (*run)(const bench_model *m, const options *o);
} scene;

static const scene scenes[] = {
    {"R1", "R1 steel cantilever, static tip deflection vs the 3D solid", trade_r1},
    {"R2", "R2 soft cantilever (large deformation), self-convergence", trade_r2},
    {"R3", "R3 first bending frequency vs the 3D solid (corrected for the integrator's phase error)", trade_r3},
    {"R4", "R4 uniaxial stretch, St Venant-Kirchhoff P_zz", trade_r4},
    {"R5", "R5 uniaxial stretch, Neo-Hookean P_zz", trade_r5},
    {"cut", "cutting a notch vs rebuilding the mesh without it", trade_cut},
    {"NI", "NI near-incompressible cantilever (nu = 0.499), static tip vs Timoshenko", trade_ni},
};

static void series_name(const trade_row *r, char *out, size_t size)
{
    const char *s = r->setting;
    if (!strncmp(s, "static", 6) && s[6] == 0) s = "";
    snprintf(out, size, "%s %s %s%s%s", r->m->model, r->m->variant, r->m->precision, *s ? " " : "", s);
}

/* One SVG per scene: error against seconds to the answer, one series per entry and
   setting, and the Pareto front (no configuration both faster and more accurate). */
static void plot_scene(const options *o, const scene *sc)
{
    enum { MAX_SERIES = 48 };
    svg_series series[MAX_SERIES + 1];
    char names[MAX_SERIES][96], path[512], title[160];
    static double xs[MAX_SERIES + 1][64], ys[MAX_SERIES + 1][64];
    int i, j, ns = 0, nf = 0;
    for (i = 0; i < row_count; i++) {
        char name[96];
        const trade_row *r = rows + i;
        if (strcmp(r->scene, sc->name) || r->status || !(r->error > 0)) continue;
        series_name(r, name, sizeof name);
        for (j = 0; j < ns && strcmp(names[j], name); j++) continue;
        if (j == ns) {
            if (ns == MAX_SERIES) continue;
            snprintf(names[ns], sizeof names[ns], "%s", name);
            series[ns].name = names[ns];
            series[ns].count = 0;
            series[ns].x = xs[ns];
            series[ns].y = ys[ns];
            series[ns].front = 0;
            ns++;
        }
        if (series[j].count < 64) {
            xs[j][series[j].count] = r->answer_s;
            ys[j][series[j].count++] = r->error;
        }
    }
    /* the front: sort every point by time, keep those more accurate than all faster ones */
    {
        static double pts[4096][2];
        int np = 0;
        double best = HUGE_VAL;
        for (i = 0; i < ns; i++)
            for (j = 0; j < series[i].count; j++) {
                pts[np][0] = series[i].x[j];
                pts[np++][1] = series[i].y[j];
            }
        qsort(pts, (size_t)np, sizeof pts[0], cmp_double); /* by time (first member) */
        for (i = 0; i < np && nf < 64; i++)
            if (pts[i][1] < best) {
                best = pts[i][1];
                xs[ns][nf] = pts[i][0];
                ys[ns][nf++] = pts[i][1];
            }
    }
    series[ns].name = "Pareto front";
    series[ns].count = nf;
    series[ns].x = xs[ns];
    series[ns].y = ys[ns];
    series[ns].front = 1;
    snprintf(path, sizeof path, "%s/trade_%s.svg", o->out, sc->name);
    snprintf(title, sizeof title, "%s", sc->title);
    if (ns && svg_plot(path, title, "seconds to the answer", "relative error", series, ns + 1))
        fprintf(stderr, "bench: cannot write %s\n", path);
}

/* For each scene, the cheapest configuration reaching 10 %, 1 % and 0.1 %. */
static void print_cheapest(void)
{
    static const double goals[3] = {0.1, 0.01, 0.001};
    int s, g, i;
    printf("\ncheapest configuration reaching each error (seconds to the answer)\n");
    printf("%-5s %-8s %s\n", "scene", "error", "configuration");
    for (s = 0; s < (int)(sizeof scenes / sizeof scenes[0]); s++)
        for (g = 0; g < 3; g++) {
            const trade_row *best = NULL;
            char name[96];
            for (i = 0; i < row_count; i++) {
                const trade_row *r = rows + i;
                if (strcmp(r->scene, scenes[s].name) || r->status || !(r->error <= goals[g])) continue;
                if (!best || r->answer_s < best->answer_s) best = r;
            }
            if (!best) {
                printf("%-5s %-8g none reached it\n", scenes[s].name, goals[g]);
                continue;
            }
            series_name(best, name, sizeof name);
            printf("%-5s %-8g %s, level %d (%d dof): %.3g s, error %.2g\n", scenes[s].name, goals[g], name,
                   best->level, best->dof, best->answer_s, best->error);
        }
}

static void run_trade(const options *o, const bench_model *const *models, int count,
                      const bench_model *const *variants, int variant_count)
{
    FILE *f;
    int s, i;
    printf("== 1. speed/accuracy trade ==\n");
    for (s = 0; s < (int)(sizeof scenes / sizeof scenes[0]); s++) {
        double t0 = now();
        if (o->scenes && !strstr(o->scenes, scenes[s].name)) continue;
        printf("%s\n", scenes[s].title);
        if (!strcmp(scenes[s].name, "R3"))
            printf("  (frequency from the tip's zero crossings, corrected for the integrator's phase error: Euler "
                   "schemes w = tan(w_h dt) / dt, semi-implicit Euler w = 2 sin(w_h dt / 2) / dt; \"measured\" is "
                   "the uncorrected one)\n");
        for (i = 0; i < count; i++) scenes[s].run(models[i], o);
        if (scenes[s].run == trade_ni) /* the options against locking (primary -1) too */
            for (i = 0; i < variant_count; i++) scenes[s].run(variants[i], o);
        printf("  (%s: %.1f s)\n", scenes[s].name, now() - t0);
    }
    finish_r2();
    f = open_csv(o, "trade.csv",
                 "scene,model,variant,precision,setting,level,dof,elements,time_step,setup_s,step_s,answer_s,"
                 "value,reference,error,status,measured");
    for (i = 0; i < row_count; i++) {
        const trade_row *r = rows + i;
        csv_prefix(f);
        fprintf(f, "%s,%s,%s,%s,%s,%d,%d,%.0f,%.6g,%.6g,%.6g,%.6g,%.9g,%.9g,%.6g,%d,%.9g\n", r->scene, r->m->model,
                r->m->variant, r->m->precision, r->setting, r->level, r->dof, r->elements, r->time_step, r->setup_s,
                r->step_s, r->answer_s, r->value, r->reference, r->error, r->status,
                r->measured == r->measured ? r->measured : r->value);
    }
    fclose(f);
    for (s = 0; s < (int)(sizeof scenes / sizeof scenes[0]); s++) plot_scene(o, scenes + s);
    print_cheapest();
}

/* >>race: issue 21's same-run comparison on R1. Each entry below refines through
   race_levels (cells across: one at a time to 6, then two at a time, then four; one static
   solve per level, r1_solve, judged as the trade part judges R1) until its error is within
   1 %, or its budget (--race-budget, seconds of setup + solve summed over its levels) is
   spent or would be by the next level (predicted from the last level's seconds, times the
   larger of the cells' growth and the growth from the level before, extrapolated as a power
   of the cells across: tensor-mass's solves grew 4.8x from 10 to 12 cells, and the cells'
   growth alone let a 77 s solve start past a 60 s budget), or a solve fails past the
   coarsest level. The row kept
   is the first level within 1 %, else the most accurate one: its solve's seconds (the mesh
   known beforehand) and the seconds summed up to it (found by refining). race.csv and a
   ratio line: heml.h's P1 tetrahedra over each frames entry. One run each, no repeats: on a
   busy machine the seconds are as noisy as the load. */

static const char *const race_entries[][2] = {
    {"frames", "svk hex8"}, {"frames", "svk tet4"}, {"heml", "neo-hookean"}, {"tensormass", "linear"}};
#define RACE_COUNT ((int)(sizeof race_entries / sizeof race_entries[0]))
static const int race_levels[] = {1, 2, 3, 4, 5, 6, 8, 10, 12, 14, 16, 20, 24, 28, 32};
#define RACE_LEVELS ((int)(sizeof race_levels / sizeof race_levels[0]))
#define RACE_GOAL 0.01

typedef struct race_result {
    trade_row row;      /* the first level within RACE_GOAL, else the most accurate */
    double cumulative;  /* s: setup + solve summed over the levels up to row's */
    const char *outcome; /* "reached", "budget", "failed" */
} race_result;

static void race_entry(const bench_model *m, const options *o, race_result *out)
{
    double spent = 0, prev_s = 0;
    int l;
    memset(out, 0, sizeof *out);
    out->row.error = HUGE_VAL;
    out->outcome = "budget";
    for (l = 0; l < RACE_LEVELS; l++) {
        int k = race_levels[l];
        trade_row r;
        double level_s;
        memset(&r, 0, sizeof r);
        strcpy(r.scene, "race");
        strcpy(r.setting, "static");
        r.m = m;
        r.level = k;
        r.error = r.value = r.measured = NAN;
        r1_solve(m, k, 1, &r);
        print_row(&r);
        level_s = r.setup_s + r.answer_s;
        spent += level_s;
        if (!r.status && r.error < out->row.error) out->row = r, out->cumulative = spent;
        if (!r.status && r.error <= RACE_GOAL) {
            out->outcome = "reached";
            return;
        }
        if (r.status && k > 1) {
            out->outcome = "failed";
            return;
        }
        if (l + 1 == RACE_LEVELS) return;
        {
            double step = log((double)race_levels[l + 1] / k), growth = exp(3 * step);
            if (l > 0 && prev_s > 0)
                growth = fmax(growth, pow(level_s / prev_s, step / log((double)k / race_levels[l - 1])));
            if (spent + level_s * growth > o->race_budget) return;
        }
        prev_s = level_s;
    }
}

static void run_race(const options *o, const bench_model *const *models, int count)
{
    race_result res[RACE_COUNT];
    const bench_model *entry[RACE_COUNT];
    FILE *f;
    int e, i;
    printf("\n== race: R1 to 1 %% (issue 21), each entry refined until within 1 %% or %g s spent ==\n",
           o->race_budget);
    f = open_csv(o, "race.csv",
                 "model,variant,precision,budget_s,outcome,level,dof,error,value,reference,setup_s,solve_s,"
                 "cumulative_s");
    for (e = 0; e < RACE_COUNT; e++) {
        entry[e] = NULL;
        for (i = 0; i < count && !entry[e]; i++)
            if (!strcmp(models[i]->model, race_entries[e][0]) && !strcmp(models[i]->variant, race_entries[e][1]) &&
                !strcmp(models[i]->precision, "double") && (models[i]->integrators & BIT(BENCH_STATIC)))
                entry[e] = models[i];
        if (!entry[e]) continue;
        race_entry(entry[e], o, res + e);
        printf("  race %s %s: %s", entry[e]->model, entry[e]->variant,
               !strcmp(res[e].outcome, "reached") ? "within 1 %" : "NOT within 1 %, best");
        if (res[e].row.dof)
            printf(" at %d cells across (%d dof): error %.3g %%, solve %.3g s, summed %.3g s", res[e].row.level,
                   res[e].row.dof, 100 * res[e].row.error, res[e].row.answer_s, res[e].cumulative);
        printf(" (%s)\n", res[e].outcome);
        csv_prefix(f);
        fprintf(f, "%s,%s,%s,%g,%s,%d,%d,%.6g,%.9g,%.9g,%.6g,%.6g,%.6g\n", entry[e]->model, entry[e]->variant,
                entry[e]->precision, o->race_budget, res[e].outcome, res[e].row.level, res[e].row.dof,
                res[e].row.error, res[e].row.value, res[e].row.reference, res[e].row.setup_s, res[e].row.answer_s,
                res[e].cumulative);
    }
    fclose(f);
    /* heml neo-hookean (entry 2) against each frames entry (0, 1) */
    for (e = 0; e < 2; e++) {
        const race_result *p = res + 2, *q = res + e;
        int p_in = entry[2] && !strcmp(p->outcome, "reached");
        if (!entry[2] || !entry[e] || strcmp(q->outcome, "reached") || !strcmp(p->outcome, "failed")) continue;
        printf("  race ratio, time to 1 %%, heml neo-hookean P1 / frames %s: solve %s%.3g (%.3g s / %.3g s), "
               "summed %s%.3g (%.3g s / %.3g s)\n",
               entry[e]->variant, p_in ? "" : ">= ", p->row.answer_s / q->row.answer_s, p->row.answer_s,
               q->row.answer_s, p_in ? "" : ">= ", (p_in ? p->cumulative : o->race_budget) / q->cumulative,
               p_in ? p->cumulative : o->race_budget, q->cumulative);
    }
}

/* >>stability */

typedef struct stability_row {
    const char *test;
    const bench_model *m;
    char setting[40];
    double parameter, value, error;
    const char *outcome;
    int code;
} stability_row;

static FILE *stability_csv;
static double stability_clock; /* when the previous row was printed */

static void stability_out(const stability_row *r)
{
    double t = now();
    printf("  %-12s %-10s %-12s %-6s %-28s %-16s value %10.4g  error %9.3g  code %d  (%.1f s)\n", r->test,
           r->m->model, r->m->variant, r->m->precision, r->setting, r->outcome, r->value, r->error, r->code,
           t - stability_clock);
    stability_clock = t;
    csv_prefix(stability_csv);
    fprintf(stability_csv, "%s,%s,%s,%s,%s,%.6g,%.9g,%.6g,%s,%d\n", r->test, r->m->model, r->m->variant,
            r->m->precision, r->setting, r->parameter, r->value, r->error, r->outcome, r->code);
    fflush(stdout);
}

/* How a run ended: an error code the library reported, a non-finite state it did not
   report, or a finite state judged by its error. */
static const char *classify(int code, int finite, double error)
{
    if (code == BENCH_UNSUPPORTED) return "unsupported";
    if (code) return finite ? "error-reported" : "non-finite-bug";
    if (!finite) return "silent-nan";
    return error > 0.1 ? "visibly-wrong" : "stable";
}

/* A 1 x 0.1 x 0.1 m cantilever released from rest under a load that would deflect it by
   about 1 % of its length; stable when `steps` steps (1000 explicit, 200 implicit, 50 when quick) stay finite,
   raise no error and keep the tip within 10 deflections (an undamped unstable mode grows
   past that). */
static int stable_at(const bench_model *m, const bench_body *b, int integrator, double dt, int steps, int *code)
{
    void *sim = NULL;
    int s, ok = 1;
    double limit = 10 * 0.01;
    *code = m->create(b, &sim);
    if (*code) return 0;
    for (s = 0; s < steps && ok; s++) {
        *code = m->step(sim, dt, integrator);
        if (*code) ok = 0;
        else if (s % 50 == 49 || s == steps - 1) {
            double d = tip_deflection(m, sim, b);
            ok = fabs(d) < limit && all_finite(m, sim);
        }
    }
    m->destroy(sim);
    return ok;
}

static void stability_time_step(const bench_model *m, const options *o)
{
    int halvings = o->quick ? 5 : 12;
    static const double youngs[3] = {1e3, 1e5, 1e7};
    int e, it;
    for (it = 0; it < BENCH_STATIC; it++) {
        if (!(m->integrators & BIT(it))) continue;
        for (e = 0; e < 3; e++) {
            bench_body b = make_body(1, 0.1, 0.1, 20, 2, 2, youngs[e], 0.3, 1000);
            /* an implicit scheme is unconditionally stable or not at all: 200 steps tell */
            int steps = o->quick ? 50 : it == BENCH_IMPLICIT_EULER ? 200 : 1000;
            stability_row r;
            double lo = 1e-7, hi = 1.0;
            int i, code = 0, last = 0;
            /* gravity scaled so the static tip deflection is about 1 cm */
            b.gravity[2] = -0.01 / 1.5e5 * youngs[e];
            memset(&r, 0, sizeof r);
            r.test = "max-dt";
            r.m = m;
            snprintf(r.setting, sizeof r.setting, "%s E=%.0e", integrator_name[it], youngs[e]);
            r.parameter = youngs[e];
            if (stable_at(m, &b, it, hi, steps, &code)) {
                r.value = hi;
                r.outcome = "stable-at-1s";
            } else if (!stable_at(m, &b, it, lo, steps, &last)) {
                r.value = 0;
                r.outcome = "unstable-at-1e-7s";
                code = last;
            } else {
                for (i = 0; i < halvings; i++) { /* log bisection: 1e7^(2^-12), 0.4 % */
                    double mid = sqrt(lo * hi);
                    if (stable_at(m, &b, it, mid, steps, &last)) lo = mid;
                    else hi = mid, code = last;
                }
                r.value = lo;
                r.outcome = "bisected";
            }
            r.code = code;
            r.error = NAN;
            stability_out(&r);
        }
    }
}

/* Tip deflection of a 1 x 0.1 x 0.1 m cantilever (E = 1 MPa, load for about 1 cm) against
   Timoshenko, at several Poisson ratios and optionally far from the origin. */
static void beam_static(const bench_model *m, double nu, const double offset[3], int k, double *value,
                        double *error, int *code, int *finite)
{
    bench_body b = make_body(1, 0.1, 0.1, 10 * k, k, k, 1e6, nu, 1000);
    void *sim = NULL;
    double ref;
    memcpy(b.offset, offset, sizeof b.offset);
    b.gravity[2] = -0.01 / 1.5e5 * b.young;
    ref = timoshenko_tip(1, 0.1, b.young, nu, b.density, -b.gravity[2]);
    *value = *error = NAN;
    *finite = 1;
    *code = m->create(&b, &sim);
    if (!*code) *code = m->solve_static(sim);
    if (sim) {
        *finite = all_finite(m, sim);
        if (!*code && *finite) {
            *value = tip_deflection(m, sim, &b);
            *error = relative_error(*value, ref);
        }
        m->destroy(sim);
    }
}

static void stability_poisson(const bench_model *m, const options *o)
{
    static const double nus[4] = {0.3, 0.45, 0.49, 0.499};
    static const double zero[3] = {0, 0, 0};
    int i, finite;
    if (!(m->integrators & BIT(BENCH_STATIC))) return;
    for (i = 0; i < 4; i++) {
        stability_row r;
        memset(&r, 0, sizeof r);
        r.test = "poisson";
        r.m = m;
        r.parameter = nus[i];
        snprintf(r.setting, sizeof r.setting, "static nu=%g", nus[i]);
        beam_static(m, nus[i], zero, o->quick ? 2 : 3, &r.value, &r.error, &r.code, &finite);
        r.outcome = classify(r.code, finite, r.error);
        stability_out(&r);
    }
}

static void stability_far(const bench_model *m)
{
    static const double zero[3] = {0, 0, 0}, far[3] = {1e6, 1e6, 1e6};
    stability_row r;
    double near_value, near_error;
    int finite;
    if (!(m->integrators & BIT(BENCH_STATIC))) return;
    memset(&r, 0, sizeof r);
    r.test = "far-origin";
    r.m = m;
    r.parameter = 1e6;
    snprintf(r.setting, sizeof r.setting, "static offset=1e6 m");
    beam_static(m, 0.3, zero, 2, &near_value, &near_error, &r.code, &finite);
    beam_static(m, 0.3, far, 2, &r.value, &r.error, &r.code, &finite);
    r.error = relative_error(r.value, near_value); /* against the same beam at the origin */
    if (r.code == 0 && !(r.error < HUGE_VAL)) r.error = 1;
    r.outcome = classify(r.code, finite, r.error);
    stability_out(&r);
}

/* One cell, its far corner pushed through the opposite corner's side to invert the
   tetrahedra that hold it, then released with damping: stable if it returns within 10 %
   of the cell size after 2 s. */
static void stability_squash(const bench_model *m)
{
    int it;
    for (it = 0; it < BENCH_STATIC; it++) {
        bench_body b = make_body(1, 1, 1, 1, 1, 1, 1e4, 0.3, 1000);
        stability_row r;
        void *sim = NULL;
        int i, s, corner = -1, finite = 1, steps;
        double u[3] = {-1.5, -1.5, -1.5}, dt, zero[3] = {0, 0, 0};
        if (!(m->integrators & BIT(it))) continue;
        memset(&r, 0, sizeof r);
        r.test = "squash";
        r.m = m;
        b.clamp = 0;
        b.gravity[2] = 0;
        b.damping = 5;
        /* explicit schemes at a tenth of the cell's P-wave transit time */
        dt = it == BENCH_IMPLICIT_EULER ? 1e-2 : 0.1 / sqrt(1.35 * b.young / b.density);
        steps = (int)(2.0 / dt);
        snprintf(r.setting, sizeof r.setting, "%s dt=%.2g", integrator_name[it], dt);
        r.code = m->create(&b, &sim);
        if (!r.code) {
            for (i = 0; i < m->node_count(sim); i++) {
                double p[3];
                m->rest(sim, i, p);
                if (p[0] > 0.5 && p[1] > 0 && p[2] > 0) corner = i;
                else m->pin(sim, i, zero, NULL);
            }
            r.code = m->pin(sim, corner, u, NULL);
            if (!r.code) r.code = m->step(sim, dt, it); /* moves the pinned corner there */
            if (!r.code) r.code = m->release(sim, corner);
            for (s = 0; s < steps && !r.code; s++) r.code = m->step(sim, dt, it);
            finite = all_finite(m, sim);
            if (finite) {
                double p0[3], p[3];
                m->rest(sim, corner, p0);
                m->position(sim, corner, p);
                r.value = sqrt((p[0] - p0[0]) * (p[0] - p0[0]) + (p[1] - p0[1]) * (p[1] - p0[1]) +
                               (p[2] - p0[2]) * (p[2] - p0[2]));
                r.error = r.value; /* cell size 1 m */
            }
            m->destroy(sim);
        }
        r.outcome = classify(r.code, finite, r.error);
        stability_out(&r);
    }
}

/* A 1 x 0.1 x 0.1 m bar clamped at x = 0, its end face turned 180 degrees about the axis
   in eight static increments. Away from the ends the twist of an exact model is uniform,
   so the mid-length cross-section turns by 90 degrees and keeps its corner radius (to
   within the small Poynting-type change). A linear model superposes displacements: the end
   face's imposed displacement (R - I) p = -2 p is a radial squeeze, which decays within a
   width of the end (Saint-Venant), so its mid-length section barely turns. Value: the
   mid-length corners' mean rotation in degrees; error: the larger of |angle / 90 - 1|
   and |corner radius / rest radius - 1|. */
static void stability_twist(const bench_model *m, const options *o)
{
    int k = o->quick ? 2 : 3;
    bench_body b = make_body(1, 0.1, 0.1, 10 * k, k, k, 1e5, 0.3, 1000);
    stability_row r;
    void *sim = NULL;
    int i, inc, finite = 1;
    if (!(m->integrators & BIT(BENCH_STATIC))) return;
    memset(&r, 0, sizeof r);
    r.test = "twist-180";
    r.m = m;
    r.parameter = 180;
    snprintf(r.setting, sizeof r.setting, "static 8 increments");
    b.gravity[2] = 0;
    r.code = m->create(&b, &sim);
    for (inc = 1; inc <= 8 && !r.code; inc++) {
        double a = PI * inc / 8, c = cos(a), s = sin(a), R[9];
        R[0] = 1, R[1] = 0, R[2] = 0, R[3] = 0, R[4] = c, R[5] = -s, R[6] = 0, R[7] = s, R[8] = c;
        for (i = 0; i < m->node_count(sim); i++) {
            double p[3], u[3];
            m->rest(sim, i, p);
            if (p[0] < 1 - 1e-9) continue;
            u[0] = 0;
            u[1] = c * p[1] - s * p[2] - p[1];
            u[2] = s * p[1] + c * p[2] - p[2];
            m->pin(sim, i, u, R);
        }
        r.code = m->solve_static(sim);
    }
    if (sim) {
        finite = all_finite(m, sim);
        if (!r.code && finite) {
            double radius = 0, angle = 0, rest_r = sqrt(0.05 * 0.05 * 2);
            int n = 0;
            for (i = 0; i < m->node_count(sim); i++) {
                double p0[3], p[3];
                m->rest(sim, i, p0);
                if (fabs(p0[0] - 0.5) > 1e-9 || fabs(fabs(p0[1]) - 0.05) > 1e-9 || fabs(fabs(p0[2]) - 0.05) > 1e-9)
                    continue;
                m->position(sim, i, p);
                radius += sqrt(p[1] * p[1] + p[2] * p[2]);
                /* signed angle from the rest corner (y0, z0) to the current one (y, z) */
                angle += atan2(p0[1] * p[2] - p0[2] * p[1], p0[1] * p[1] + p0[2] * p[2]);
                n++;
            }
            if (n) {
                double ratio = radius / n / rest_r, degrees = angle / n * 180 / PI;
                r.value = degrees;
                r.error = fmax(fabs(degrees / 90 - 1), fabs(ratio - 1));
            } else {
                r.value = r.error = NAN;
            }
        }
        m->destroy(sim);
    }
    r.outcome = classify(r.code, finite, r.error);
    stability_out(&r);
}

static void run_stability(const options *o, const bench_model *const *models, int count,
                          const bench_model *const *variants, int variant_count)
{
    int i;
    printf("\n== 2. stability at the extremes ==\n");
    stability_csv = open_csv(o, "stability.csv", "test,model,variant,precision,setting,parameter,value,error,outcome,code");
    stability_clock = now();
    for (i = 0; i < count; i++) {
        if (!models[i]->primary) continue;
        stability_time_step(models[i], o);
        stability_poisson(models[i], o);
        stability_squash(models[i]);
        stability_twist(models[i], o);
        stability_far(models[i]);
    }
    for (i = 0; i < variant_count; i++) stability_poisson(variants[i], o); /* the primary = -1 entries */
    fclose(stability_csv);
}

/* >>sweep: the stress sweep (issue 18). Every (scene, E, nu, solver, dt) run must either
   converge to the right answer or return an error code; a success with a wrong answer is
   the one outcome a caller cannot detect, and the sweep counts it.

   Scenes: "beam", the bench's 1 x 0.1 x 0.1 m cantilever on 10 x 1 x 1 cells (the coarsest
   bench beam: the whole sweep must fit in about a minute of `make bench`) clamped at x = 0
   under a gravity scaled with E so that Euler-Bernoulli's tip
   deflection is 0.1 m (g = 0.1 * 8 E I / (rho A L^4): moderately large deformation, the
   same shape at every E, so E changes only the time scale and the round-off); "cube", a
   unit cube (2^3 cells) whose bottom face is held and whose top face is
   pushed down 0.5 m (squashed to half its height; St Venant-Kirchhoff, whose equilibrium
   is not unique beyond a stretch of about 0.58, by 0.25 m), both faces held laterally.
   Grid: E = 1 Pa, 1 kPa, 1 MPa, 200 GPa; nu = 0, 0.45, 0.4999; static, and implicit Euler and
   BDF2 (issue 19; where the entry has it) at dt = 1e-6, 1e-3, 1 s; density 1000 kg/m^3; every model entry, double and float (quick:
   E = 1 Pa and 200 GPa, nu = 0 and 0.4999, dt = 1e-6 and 1 s, the primary double entries;
   the near-incompressible options' entries, primary = -1, not in quick: E = 1 kPa and 1 MPa,
   nu = 0.45 and 0.4999, dt = 1e-3 and 1 s).
   A disagreement between two successes of the same model means one of them is wrong; the
   sweep counts it against the one-call or large-step run.
   The right answer, from the same model by a more careful path:
   - static: the one-call solve against the same load applied in 8 increments (a static
     solve each, from the previous answer). Right when the largest node difference is
     within 1 % of the largest displacement.
   - implicit, "damped" regime (w1 dt >= 0.09, w1 the first mode's estimated angular
     frequency): mass damping 2 w1 (critical for that mode), N steps from rest with the
     load (or the squash) applied at once, N = 3 ln(1000) / ln(1 + w1 dt) + 2 <= 242: a
     correct implicit Euler contracts the distance to the static equilibrium by
     1 / (1 + w dt) per step for a critically damped linear mode, so a third of N steps
     brings it within 0.1 % of the increments' answer; the factor 3 is the margin for the
     estimate of w1 and for large deformation (on the code of issue 18's start, 1 instead
     of 3 left 14 of the 960 double runs short of the answer, 5 instead of 3 changed one).
     Right within 1 %. BDF2: the same rule with its own contraction per step, the larger
     root modulus rho of (3/2 + w dt) z^2 - 2 z + 1/2 = 0 (sweep_bdf2_rho): N = 3 ln(1000) /
     ln(1 / rho) + 2 (rho = 0.914 against Euler's 0.917 at w dt = 0.09, but sqrt(1 / (3 + 2 w dt))
     beyond w dt = 1/2, slower than Euler's 1 / (1 + w dt) beyond w dt = sqrt(2): at w dt = 1000,
     8 steps where Euler needs 5).
   - implicit, "resolved" regime (beam only; n = 8, 4 or 2 steps, the most with
     n dt <= L / (4 c_p), c_p the P-wave speed): the free end has not heard of the clamp
     (the implicit solve's reach per step decays like exp(-x / (c_p dt))), so its mean
     displacement is the integrator's own free fall: implicit Euler's v <- (v + dt g) / (1 + c dt),
     u <- u + dt v; BDF2's the same first step, then y <- (4 y - y_prev) / 3 + (2 dt / 3) y' for
     u and v. Right within 1 % plus 100 eps(precision) m of position round-off.
   - otherwise "unjudged" (8 steps are still run: an error code counts as one, a non-finite
     state as wrong).
   A non-finite state after a success is always wrong. sweep.csv has every run. */

enum { SWEEP_BEAM = 0, SWEEP_CUBE = 1 };
static const char *sweep_scene_name[2] = {"beam", "cube"};

typedef struct sweep_counts {
    int right, error, wrong, unjudged;
} sweep_counts;

static FILE *sweep_csv;

static bench_body sweep_body(int scene, double young, double nu, int k)
{
    bench_body b;
    if (scene == SWEEP_BEAM) {
        double a = 0.1, L = 1, I = a * a * a * a / 12, A = a * a;
        b = make_body(L, a, a, 10 * k, k, k, young, nu, 1000);
        b.gravity[2] = -0.1 * 8 * young * I / (b.density * A * L * L * L * L);
    } else {
        b = make_body(1, 1, 1, 2 * k, 2 * k, 2 * k, young, nu, 1000);
        b.clamp = 0;
        b.gravity[2] = 0;
    }
    return b;
}

/* The first mode's angular frequency, estimated: the beam's Euler-Bernoulli first bending
   mode; the cube's shear mode between its held faces, pi c_s / H. */
static double sweep_omega1(int scene, const bench_body *b)
{
    double mu = b->young / (2 * (1 + b->poisson));
    if (scene == SWEEP_BEAM) {
        double a = b->size[1], L = b->size[0];
        return 1.8751 * 1.8751 * sqrt(b->young * a * a / (12 * b->density * L * L * L * L));
    }
    return PI * sqrt(mu / b->density) / b->size[2];
}

static double sweep_p_wave(const bench_body *b)
{
    double nu = b->poisson, mu = b->young / (2 * (1 + nu)), lambda = b->young * nu / ((1 + nu) * (1 - 2 * nu));
    return sqrt((lambda + 2 * mu) / b->density);
}

/* Applies `fraction` of the scene's load: the beam's gravity, the cube's squash. */
static int sweep_load(const bench_model *m, void *sim, const bench_body *b, int scene, double fraction)
{
    int i, err = 0;
    if (scene == SWEEP_BEAM) {
        double g[3];
        for (i = 0; i < 3; i++) g[i] = fraction * b->gravity[i];
        return m->set_gravity(sim, g);
    }
    for (i = 0; i < m->node_count(sim) && !err; i++) {
        double p[3], u[3] = {0, 0, 0};
        m->rest(sim, i, p);
        if (fabs(p[2] - b->offset[2] + 0.5) < 1e-9) err = m->pin(sim, i, u, NULL);
        else if (fabs(p[2] - b->offset[2] - 0.5) < 1e-9) {
            /* St Venant-Kirchhoff softens in compression and loses uniqueness beyond a
               stretch of about 0.58: squashed by a quarter only */
            u[2] = -(strcmp(m->law, "svk") ? 0.5 : 0.25) * fraction;
            err = m->pin(sim, i, u, NULL);
        }
    }
    return err;
}

/* Node positions, 3n doubles (malloc'd), or NULL. */
static double *sweep_positions(const bench_model *m, void *sim)
{
    int i, n = m->node_count(sim);
    double *x = (double *)malloc(sizeof(double) * 3 * (size_t)n);
    for (i = 0; x && i < n; i++) m->position(sim, i, x + 3 * i);
    return x;
}

/* Largest node distance between x and ref over the largest displacement in ref. */
static double sweep_field_error(const bench_model *m, void *sim, const double *x, const double *ref, double *umax)
{
    int i, k, n = m->node_count(sim);
    double dmax = 0;
    *umax = 0;
    for (i = 0; i < n; i++) {
        double p0[3], d = 0, u = 0;
        m->rest(sim, i, p0);
        for (k = 0; k < 3; k++) {
            d += (x[3 * i + k] - ref[3 * i + k]) * (x[3 * i + k] - ref[3 * i + k]);
            u += (ref[3 * i + k] - p0[k]) * (ref[3 * i + k] - p0[k]);
        }
        if (!(sqrt(d) <= dmax)) dmax = sqrt(d); /* a NaN wins */
        if (sqrt(u) > *umax) *umax = sqrt(u);
    }
    return *umax > 0 ? dmax / *umax : dmax;
}

/* The cube's scene has the square's symmetry about its vertical axis (the dihedral group
   D4: four rotations by quarter turns, four mirrors), so the image of a right answer under
   any of them is right too. Where the equilibrium is not unique (a squashed cube that
   tilts one way or its mirror way), two careful solves may return mirror images: the
   error is the smallest over the eight images of ref whose nodes map onto nodes (node j
   at g(rest_i) must carry g(u_ref,i)). Other scenes: sweep_field_error. */
static double sweep_symmetric_error(const bench_model *m, void *sim, const bench_body *b, int scene, const double *x,
                                    const double *ref, double *umax)
{
    static const int g[8][4] = {{1, 0, 0, 1}, {0, -1, 1, 0}, {-1, 0, 0, -1}, {0, 1, -1, 0},
                                {-1, 0, 0, 1}, {1, 0, 0, -1}, {0, 1, 1, 0},  {0, -1, -1, 0}};
    int i, j, k, n = m->node_count(sim), t;
    /* the vertical axis: x from 0 to L, y centred, both shifted by the offset */
    double best = sweep_field_error(m, sim, x, ref, umax), tol = 1e-6 * b->size[0];
    double cx = b->offset[0] + 0.5 * b->size[0], cy = b->offset[1];
    if (scene != SWEEP_CUBE) return best;
    for (t = 1; t < 8; t++) {
        double dmax = 0;
        int mapped = 1;
        for (i = 0; i < n && mapped; i++) {
            double pi[3], gp[3], gu[3], pj[3], ui[3], d = 0;
            m->rest(sim, i, pi);
            for (k = 0; k < 3; k++) ui[k] = ref[3 * i + k] - pi[k];
            gp[0] = cx + g[t][0] * (pi[0] - cx) + g[t][1] * (pi[1] - cy);
            gp[1] = cy + g[t][2] * (pi[0] - cx) + g[t][3] * (pi[1] - cy);
            gp[2] = pi[2];
            gu[0] = g[t][0] * ui[0] + g[t][1] * ui[1];
            gu[1] = g[t][2] * ui[0] + g[t][3] * ui[1];
            gu[2] = ui[2];
            for (j = 0; j < n; j++) {
                m->rest(sim, j, pj);
                if (fabs(pj[0] - gp[0]) + fabs(pj[1] - gp[1]) + fabs(pj[2] - gp[2]) <= tol) break;
            }
            if (j == n) {
                mapped = 0; /* this mesh is not symmetric under g */
                break;
            }
            for (k = 0; k < 3; k++) d += (x[3 * j + k] - pj[k] - gu[k]) * (x[3 * j + k] - pj[k] - gu[k]);
            if (!(sqrt(d) <= dmax)) dmax = sqrt(d);
        }
        if (mapped && *umax > 0 && dmax / *umax < best) best = dmax / *umax;
    }
    return best;
}

/* The reference: the load in 8 increments, a static solve each. NULL if any failed. */
static double *sweep_reference(const bench_model *m, const bench_body *b, int scene, int *code)
{
    void *sim = NULL;
    double *x = NULL;
    int inc;
    *code = m->create(b, &sim);
    for (inc = 1; inc <= 8 && !*code; inc++) {
        *code = sweep_load(m, sim, b, scene, inc / 8.0);
        if (!*code) *code = m->solve_static(sim);
    }
    if (!*code && all_finite(m, sim)) x = sweep_positions(m, sim);
    if (sim) m->destroy(sim);
    return x;
}

typedef struct sweep_run {
    int scene, solver, steps, code;
    double young, poisson, dt, value, reference, error, seconds;
    const char *regime, *outcome;
} sweep_run;

static void sweep_record(const bench_model *m, sweep_run *r, sweep_counts *c, int verbose)
{
    csv_prefix(sweep_csv);
    fprintf(sweep_csv, "%s,%s,%s,%s,%s,%.6g,%.6g,%.6g,%d,%s,%d,%.9g,%.9g,%.6g,%s,%.4g\n", sweep_scene_name[r->scene],
            m->model, m->variant, m->precision, integrator_name[r->solver], r->young,
            r->poisson, r->dt, r->steps, r->regime, r->code, r->value, r->reference, r->error, r->outcome, r->seconds);
    if (!strcmp(r->outcome, "right")) c->right++;
    else if (!strcmp(r->outcome, "error")) c->error++;
    else if (!strcmp(r->outcome, "WRONG")) c->wrong++;
    else c->unjudged++;
    if (verbose || !strcmp(r->outcome, "WRONG")) {
        char what[48];
        if (r->solver == BENCH_STATIC) snprintf(what, sizeof what, "static");
        else snprintf(what, sizeof what, "%s dt=%g x%d %s", integrator_name[r->solver], r->dt, r->steps, r->regime);
        printf("    %-5s %-5s E=%-7.0e nu=%-6g %-34s %-8s error %9.3g  code %d\n", r->outcome, sweep_scene_name[r->scene],
               r->young, r->poisson, what, r->outcome, r->error, r->code);
    }
}

/* Judges a finished run: code, finiteness, error against tolerance. */
static const char *sweep_outcome(int code, int finite, double error, double tolerance)
{
    if (code) return "error";
    if (!finite) return "WRONG";
    if (tolerance < 0) return "unjudged";
    return error <= tolerance ? "right" : "WRONG"; /* a NaN error is wrong */
}

/* BDF2's contraction per step of a critically damped linear mode (w dt = x): the larger root
   modulus of (3/2 + x) z^2 - 2 z + 1/2 = 0. */
static double sweep_bdf2_rho(double x)
{
    if (x >= 0.5) return sqrt(0.5 / (1.5 + x));
    return (2 + sqrt(1 - 2 * x)) / (3 + 2 * x);
}

static void sweep_model(const bench_model *m, const options *o, sweep_counts *total)
{
    static const double youngs_full[4] = {1, 1e3, 1e6, 2e11}, youngs_quick[2] = {1, 2e11};
    static const double dts_full[3] = {1e-6, 1e-3, 1}, dts_quick[2] = {1e-6, 1};
    static const double nus_full[3] = {0, 0.45, 0.4999}, nus_quick[2] = {0, 0.4999};
    /* the primary = -1 entries (issue 13's near-incompressible options): their regime only,
       tissue stiffnesses, the user's time steps (a quarter of the full grid's runs) */
    static const double youngs_option[2] = {1e3, 1e6}, dts_option[2] = {1e-3, 1}, nus_option[2] = {0.45, 0.4999};
    int option = m->primary < 0;
    const double *nus = option ? nus_option : o->quick ? nus_quick : nus_full,
                 *youngs = option ? youngs_option : o->quick ? youngs_quick : youngs_full,
                 *dts = option ? dts_option : o->quick ? dts_quick : dts_full;
    int nnu = o->quick || option ? 2 : 3, ne = o->quick || option ? 2 : 4, ndt = o->quick || option ? 2 : 3, k = 1, scene,
        e, q, d, it;
    double eps = strcmp(m->precision, "float") ? DBL_EPSILON : FLT_EPSILON, t_model = now();
    sweep_counts c;
    memset(&c, 0, sizeof c);
    if (!(m->integrators & BIT(BENCH_STATIC)) || !(m->integrators & BIT(BENCH_IMPLICIT_EULER))) return;
    if (o->quick && (!m->primary || strcmp(m->precision, "double"))) return; /* quick: the primary entries */
    for (scene = 0; scene < 2; scene++)
        for (e = 0; e < ne; e++)
            for (q = 0; q < nnu; q++) {
                bench_body b = sweep_body(scene, youngs[e], nus[q], k);
                double *ref, t0 = now(), w1 = sweep_omega1(scene, &b), cp = sweep_p_wave(&b);
                int ref_code;
                sweep_run r;
                ref = sweep_reference(m, &b, scene, &ref_code);
                /* static, in one call */
                {
                    void *sim = NULL;
                    memset(&r, 0, sizeof r);
                    r.scene = scene, r.solver = BENCH_STATIC, r.young = youngs[e], r.poisson = nus[q];
                    r.regime = ref ? "increments" : "reference-failed";
                    r.value = r.reference = r.error = NAN;
                    r.code = m->create(&b, &sim);
                    if (!r.code) r.code = sweep_load(m, sim, &b, scene, 1);
                    if (!r.code) r.code = m->solve_static(sim);
                    if (sim) {
                        int finite = all_finite(m, sim);
                        double *x = finite ? sweep_positions(m, sim) : NULL;
                        if (x && ref) r.error = sweep_symmetric_error(m, sim, &b, scene, x, ref, &r.reference);
                        r.value = scene == SWEEP_BEAM ? tip_deflection(m, sim, &b) : NAN;
                        r.outcome = sweep_outcome(r.code, finite, r.error, ref ? 0.01 : -1);
                        free(x);
                        m->destroy(sim);
                    } else r.outcome = "error";
                    r.seconds = now() - t0;
                    sweep_record(m, &r, &c, 0);
                }
                /* the implicit integrators: implicit Euler, then BDF2 where the entry has it */
                for (it = 0; it < 2; it++)
                for (d = 0; d < ndt; d++) {
                    int integrator = it ? BENCH_BDF2 : BENCH_IMPLICIT_EULER;
                    double dt = dts[d], wdt = w1 * dt;
                    void *sim = NULL;
                    int s, damped = wdt >= 0.09 && ref,
                           resolved = 0;
                    if (!(m->integrators & BIT(integrator))) continue;
                    bench_body bd = b;
                    t0 = now();
                    memset(&r, 0, sizeof r);
                    r.scene = scene, r.solver = integrator, r.young = youngs[e], r.poisson = nus[q];
                    r.dt = dt;
                    r.value = r.reference = r.error = NAN;
                    r.steps = !damped                       ? 8
                              : integrator == BENCH_IMPLICIT_EULER ? 3 * (int)ceil(log(1000.0) / log(1 + wdt)) + 2
                                                                   : 3 * (int)ceil(log(1000.0) / -log(sweep_bdf2_rho(wdt))) + 2;
                    /* resolved: 8, 4 or 2 steps that the clamp's influence cannot cross */
                    while (!damped && scene == SWEEP_BEAM && !resolved && r.steps >= 2) {
                        if (r.steps * dt <= b.size[0] / (4 * cp)) resolved = 1;
                        else r.steps /= 2;
                    }
                    if (!damped && !resolved) r.steps = 8;
                    r.regime = damped ? "damped" : resolved ? "resolved" : "unjudged";
                    bd.damping = 2 * w1;
                    r.code = m->create(&bd, &sim);
                    if (!r.code) r.code = sweep_load(m, sim, &bd, scene, 1);
                    for (s = 0; s < r.steps && !r.code; s++) r.code = m->step(sim, dt, integrator);
                    if (sim) {
                        int finite = all_finite(m, sim);
                        double tolerance = -1;
                        if (finite && scene == SWEEP_BEAM) r.value = tip_deflection(m, sim, &bd);
                        if (finite && damped) {
                            double *x = sweep_positions(m, sim);
                            if (x) r.error = sweep_symmetric_error(m, sim, &bd, scene, x, ref, &r.reference);
                            free(x);
                            tolerance = 0.01;
                        } else if (finite && resolved) {
                            double u[3], v = 0, z = 0, v_old = 0, z_old = 0, c_damp = bd.damping, dz;
                            for (s = 0; s < r.steps; s++) { /* the integrator's own free fall */
                                double v_new, z_new;
                                if (integrator == BENCH_IMPLICIT_EULER || s == 0) { /* BDF2 starts with Euler */
                                    v_new = (v + dt * bd.gravity[2]) / (1 + c_damp * dt);
                                    z_new = z + dt * v_new;
                                } else { /* y+ = (4 y - y-) / 3 + (2 dt / 3) y+' */
                                    double h = 2 * dt / 3;
                                    v_new = ((4 * v - v_old) / 3 + h * bd.gravity[2]) / (1 + c_damp * h);
                                    z_new = (4 * z - z_old) / 3 + h * v_new;
                                }
                                v_old = v, z_old = z, v = v_new, z = z_new;
                            }
                            face_mean(m, sim, &bd, 0, bd.size[0], 1e-6 * bd.size[0], u);
                            dz = sqrt(u[0] * u[0] + u[1] * u[1] + (u[2] - z) * (u[2] - z));
                            r.value = u[2];
                            r.reference = z;
                            r.error = dz / fabs(z);
                            /* 1 % plus the round-off of the positions, as a relative bound */
                            tolerance = 0.01 + 100 * eps * (1 + fabs(bd.offset[0])) / fabs(z);
                        } else if (finite) {
                            r.error = 0;
                        }
                        r.outcome = sweep_outcome(r.code, finite, r.error, tolerance);
                        m->destroy(sim);
                    } else r.outcome = "error";
                    r.seconds = now() - t0;
                    sweep_record(m, &r, &c, 0);
                }
                free(ref);
            }
    printf("  sweep  %-10s %-12s %-6s right %3d  error %3d  WRONG %3d  unjudged %3d  (%.1f s)\n", m->model, m->variant,
           m->precision, c.right, c.error, c.wrong, c.unjudged, now() - t_model);
    fflush(stdout);
    total->right += c.right, total->error += c.error, total->wrong += c.wrong, total->unjudged += c.unjudged;
}

static void run_sweep(const options *o, const bench_model *const *models, int count)
{
    sweep_counts total;
    double t0 = now();
    int i;
    memset(&total, 0, sizeof total);
    printf("\nstress sweep: beam and squashed cube, E 1 Pa to 200 GPa, nu 0 to 0.4999, static and implicit Euler at "
           "dt 1e-6 to 1 s\n  (and BDF2 where the entry has it);\n  each run right (against the same model by a more careful path), an error code, WRONG "
           "(success with a wrong answer) or unjudged (see bench.c >>sweep)\n");
    sweep_csv = open_csv(o, "sweep.csv",
                         "scene,model,variant,precision,solver,young,poisson,time_step,steps,regime,code,value,"
                         "reference,error,outcome,seconds");
    for (i = 0; i < count; i++) {
        /* a guard for make bench's 10 minutes: the sweep takes about 40 s of CPU (3 s
           quick) on the code at issue 18's start; slower solvers must not take the rest */
        double limit = o->quick ? 20 : 150;
        if (now() - t0 > limit) {
            printf("  sweep: stopped after %.0f s (limit %.0f s); %d entries from %s %s %s on not run\n", now() - t0,
                   limit, count - i, models[i]->model, models[i]->variant, models[i]->precision);
            break;
        }
        sweep_model(models[i], o, &total);
    }
    fclose(sweep_csv);
    printf("  sweep total: right %d, error %d, WRONG %d, unjudged %d (%.1f s)\n", total.right, total.error, total.wrong,
           total.unjudged, now() - t0);
}

/* >>time: accuracy in time (issue 19). The R3 beam (1 x 0.1 x 0.1 m, 10 x 1 x 1 cells,
   E = 1 MPa, released from its static deflection under a small load) and the R2 soft
   cantilever (16 x 1 x 1 m, 16 x 1 x 1 cells, released from its large static sag under
   gravity), for the first primary double entry of each header and each of its
   integrators (the explicit ones too: at these steps, far above their stable step, they
   end in an error code, which is the row's answer), at dt = T/20, T/50,
   T/100, T/400, T the model's own period: measured first at dt = T_est/800 (BDF2 where
   the entry has it, else implicit Euler with its exact phase correction for a linear
   mode, integrator_frequency; within 2e-5 of the limit either way), T_est
   R3's 3D period or R2's Euler-Bernoulli estimate (4.43 s). Each run lasts 2.2 T.
   Columns:
   - period_error: the period from the tip's zero crossings against that reference
     period: the integrator's error alone, not the mesh's (the zero crossings also carry
     the higher modes the release excites, which the schemes damp differently).
   - decay_per_period: the tip's amplitude in its second period over its first (the
     first Fourier coefficient over each, decay_per_period(); 1 = no numerical damping).
     Theory for one mode: implicit Euler (1 + (w dt)^2)^(-T/(2 dt)), 0.821 at T/100;
     BDF2 0.9996 at T/100, 0.962 at T/20. This reading sits up to about 1 % below the
     one-mode theory (implicit Euler on heml's R3: 0.8126 at T/100, 0.9406 at T/400 against
     0.821 and 0.952): the other modes and the measured period's own error leak into the
     projection; the header tests check the schemes against their closed forms exactly.
   - cost: seconds of computing per simulated second (step time / dt). */
static FILE *time_csv;

/* Tip signal z (n + 1 samples from the release) of one run, and its step time. */
static int time_run(const bench_model *m, const bench_body *b0, int integrator, double dt, int n, double *z,
                    double *step_s)
{
    bench_body b = *b0;
    double g0[3] = {0, 0, 0}, t0;
    void *sim = NULL;
    int s, err = m->create(&b, &sim);
    if (!err) err = m->solve_static(sim);
    if (!err) err = m->set_gravity(sim, g0);
    if (!err) z[0] = -tip_deflection(m, sim, &b);
    t0 = now();
    for (s = 1; s <= n && !err; s++) {
        err = m->step(sim, dt, integrator);
        z[s] = -tip_deflection(m, sim, &b);
    }
    *step_s = (now() - t0) / (s > 1 ? s - 1 : 1);
    if (!err && !all_finite(m, sim)) err = -9999;
    if (sim) m->destroy(sim);
    return err;
}

/* The amplitude's decay over one period T_h (the measured period) of the sampled signal z
   (n + 1 samples, step dt): the first Fourier coefficient at 2 pi / T_h over [T_h, 2 T_h]
   over the one over [0, T_h]. The higher modes the release excites (a few % of the tip's
   motion, which BDF2 hardly damps) average out over a period (to about their amplitude
   over pi times their frequency ratio), where the peaks would carry them whole. NAN
   without two whole periods. */
static double decay_per_period(const double *z, int n, double dt, double T_h)
{
    double re[2] = {0, 0}, im[2] = {0, 0}, w = 2 * PI / T_h;
    int s, k, per = (int)floor(T_h / dt);
    if (!(T_h > 0) || 2 * per > n) return NAN;
    for (k = 0; k < 2; k++)
        for (s = k * per; s < (k + 1) * per; s++) { /* midpoint rule on the samples */
            double t = (s + 0.5) * dt, zm = 0.5 * (z[s] + z[s + 1]);
            re[k] += zm * cos(w * t);
            im[k] += zm * sin(w * t);
        }
    return sqrt(re[1] * re[1] + im[1] * im[1]) / sqrt(re[0] * re[0] + im[0] * im[0]);
}

static void time_model(const bench_model *m, const options *o)
{
    static const int divisions[4] = {20, 50, 100, 400};
    static const int integrators[5] = {BENCH_EXPLICIT_EULER, BENCH_SEMI_IMPLICIT_EULER, BENCH_RK4,
                                       BENCH_IMPLICIT_EULER, BENCH_BDF2};
    int scene, i, d;
    if (!m->primary || strcmp(m->precision, "double") || !(m->integrators & BIT(BENCH_IMPLICIT_EULER)) ||
        !(m->integrators & BIT(BENCH_STATIC)))
        return; /* the primary entries in double: the time error does not depend on the precision */
    for (scene = 0; scene < 2; scene++) {
        bench_body b = scene ? make_body(16, 1, 1, 16, 1, 1, 40e3, 0.3, 5.0 / 16.0) : make_body(1, 0.1, 0.1, 10, 1, 1, 1e6, 0.3, 1000);
        double T = scene ? 4.43 : 1.0 / 0.5091, T_ref, step_s, *z;
        int ref_it = (m->integrators & BIT(BENCH_BDF2)) ? BENCH_BDF2 : BENCH_IMPLICIT_EULER;
        int n_ref = (int)ceil(1.3 * 800 * 1.7), err; /* three crossings of a period up to 1.7 T_est */
        if (!scene) b.gravity[2] = -0.01;
        z = (double *)malloc(sizeof(double) * (size_t)(ceil(2.2 * 800 * 1.7) + 1));
        if (!z) return;
        err = time_run(m, &b, ref_it, T / 800, n_ref, z, &step_s);
        T_ref = err ? NAN : 1.0 / integrator_frequency(ref_it, 1.0 / period_of(z, n_ref + 1, T / 800), T / 800);
        for (i = 0; i < 5 && T_ref > 0; i++) {
            if (!(m->integrators & BIT(integrators[i]))) continue;
            for (d = 0; d < (o->quick ? 2 : 4); d++) {
                double dt = T_ref / divisions[d], Th = NAN, decay = NAN;
                int n = (int)ceil(2.2 * divisions[d]);
                if (n > (int)ceil(2.2 * 800 * 1.7)) n = (int)ceil(2.2 * 800 * 1.7);
                err = time_run(m, &b, integrators[i], dt, n, z, &step_s);
                if (!err) {
                    Th = period_of(z, n + 1, dt);
                    decay = decay_per_period(z, n, dt, Th);
                }
                printf("  %-10s %-12s %-6s %-3s %-15s T/%-4d period %+9.3f %%  decay/period %.4f  %8.3g s/s  code %d\n",
                       m->model, m->variant, m->precision, scene ? "R2" : "R3", integrator_name[integrators[i]],
                       divisions[d], 100 * (Th / T_ref - 1), decay, step_s / dt, err);
                csv_prefix(time_csv);
                fprintf(time_csv, "%s,%s,%s,%s,%s,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%d\n", m->model, m->variant, m->precision,
                        scene ? "R2" : "R3", integrator_name[integrators[i]], divisions[d], dt, T_ref,
                        Th / T_ref - 1, decay, step_s / dt, err);
            }
        }
        free(z);
    }
    fflush(stdout);
}

static void run_time(const options *o, const bench_model *const *models, int count)
{
    int i;
    double t0 = now();
    printf("\naccuracy in time: R3 beam and R2 cantilever released from a static deflection, every integrator at "
           "dt = T/20 to T/400;\n  period error against the same model at T/1600, amplitude decay per period, seconds "
           "of computing per simulated second (see bench.c >>time)\n");
    time_csv = open_csv(o, "time.csv",
                        "model,variant,precision,scene,integrator,steps_per_period,time_step,reference_period,"
                        "period_error,decay_per_period,cost_per_simulated_second,status");
    for (i = 0; i < count; i++) { /* the first eligible entry of each header: the scheme, not the law, sets the error */
        int j, seen = 0;
        for (j = 0; j < i; j++) seen |= !strcmp(models[j]->model, models[i]->model) && models[j]->primary &&
                                        !strcmp(models[j]->precision, "double");
        if (!seen) time_model(models[i], o);
    }
    fclose(time_csv);
    printf("  time: %.1f s\n", now() - t0);
}

/* >>coarse: heml.h's and tensormass.h's implicit steps with and without their coarse
   corrections (issue 21; desc.implicit_coarse, the scenes in bench/model_heml.c and
   bench/model_tensormass.c >>coarse-rows): CG and Newton iterations, coarse
   factorisations and seconds per step, Jacobi only ("never"), automatic (the default) and
   "always", the time ratios against "never" from the same run (best of the repeats, the
   modes interleaved). coarse.csv (model column: heml, tensormass). */
static void run_coarse(const options *o)
{
    static const char *mode_name[3] = {"never", "auto", "always"};
    static bench_coarse_row rows[128];
    double t0 = now();
    int n, i, lib;
    FILE *f;
    if (o->filter && !strstr("heml tensormass coarse", o->filter)) return;
    f = open_csv(o, "coarse.csv", "model,scene,integrator,young,time_step,mode,dof,cg_per_step,newton_per_step,"
                                  "factors_per_step,seconds_per_step,time_ratio_to_never,status");
    for (lib = 0; lib < 2; lib++) {
        const char *name = lib ? "tensormass" : "heml";
        if (o->filter && !strstr(name, o->filter) && !strstr("coarse", o->filter)) continue;
        if (lib)
            printf("\ntensormass.h implicit steps, coarse correction (issue 21): linear tensor-mass beams clamped at "
                   "x = 0, steps from rest, one CG solve a step (tolerance 1e-9); the same columns\n");
        else
            printf("\nheml.h implicit steps, coarse correction (issue 21): Neo-Hookean beams clamped at x = 0, steps "
                   "from rest; per step: CG and Newton iterations, coarse factorisations, ms (best of the repeats); "
                   "time ratio against Jacobi only (see bench.c >>coarse)\n");
        n = lib ? bench_tensormass_coarse_rows_double(o->quick, now, rows, 128)
                : bench_heml_coarse_rows_double(o->quick, now, rows, 128);
        for (i = 0; i < n; i++) {
            const bench_coarse_row *r = rows + i, *base = rows + i - (r->mode + 1);
            double ratio = r->seconds_per_step / base->seconds_per_step;
            printf("  %-8s %-14s E=%-6.0e dt=%-6g %-6s %5d dof: %7.1f CG %5.2f Newton %4.2f fact %9.3f ms  x%5.2f  "
                   "code %d\n",
                   r->scene, r->integrator, r->young, r->dt, mode_name[r->mode + 1], r->dof, r->cg_per_step,
                   r->newton_per_step, r->factors_per_step, 1e3 * r->seconds_per_step, ratio, r->code);
            if (f) {
                csv_prefix(f);
                fprintf(f, "%s,%s,%s,%.6g,%.6g,%s,%d,%.6g,%.6g,%.6g,%.6g,%.6g,%d\n", name, r->scene, r->integrator,
                        r->young, r->dt, mode_name[r->mode + 1], r->dof, r->cg_per_step, r->newton_per_step,
                        r->factors_per_step, r->seconds_per_step, ratio, r->code);
            }
        }
    }
    if (f) fclose(f);
    printf("  coarse: %.1f s\n", now() - t0);
}

/* >>kernels */

/* STREAM triad a = b + s c over three arrays of n doubles: best of five, GB/s (24 bytes
   per element, as STREAM counts). */
static double stream_triad(size_t n, int threads)
{
    double *a = (double *)malloc(n * sizeof *a), *b = (double *)malloc(n * sizeof *b),
           *c = (double *)malloc(n * sizeof *c), best = 0;
    long i, len = (long)n;
    int r;
    if (!a || !b || !c) {
        free(a), free(b), free(c);
        return NAN;
    }
    set_threads(threads);
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
    for (i = 0; i < len; i++) a[i] = 0, b[i] = 1, c[i] = 2;
    for (r = 0; r < 5; r++) {
        double t0 = now(), t;
#ifdef _OPENMP
#pragma omp parallel for schedule(static)
#endif
        for (i = 0; i < len; i++) a[i] = b[i] + 3.0 * c[i];
        t = now() - t0;
        if (24.0 * (double)n / t > best) best = 24.0 * (double)n / t;
    }
    if (a[len / 2] != 7.0) best = NAN; /* the loop really ran */
    free(a), free(b), free(c);
    return best / 1e9;
}

/* Seconds per kernel call: batches of calls until a batch lasts min_s, five batches,
   the median. */
static double time_kernel(const bench_model *m, void *sim, int kernel, double min_s, int *code)
{
    double t[5];
    int r, calls = 1;
    *code = m->kernel(sim, kernel); /* warm-up */
    if (*code) return NAN;
    for (;;) { /* find the batch size */
        double t0 = now();
        int c;
        for (c = 0; c < calls; c++) m->kernel(sim, kernel);
        if (now() - t0 >= min_s || calls > (1 << 24)) break;
        calls *= 2;
    }
    for (r = 0; r < 5; r++) {
        double t0 = now();
        int c;
        for (c = 0; c < calls; c++) m->kernel(sim, kernel);
        t[r] = (now() - t0) / calls;
    }
    return median(t, 5);
}

/* Each model's single-thread cost per element at its smallest and largest size, for the
   cache-to-memory summary. */
typedef struct kernel_span {
    const bench_model *m;
    int kernel;
    double small_elems, small_ns, large_elems, large_ns;
} kernel_span;

static void print_kernel_spans(const kernel_span *spans, int count, const char *const *kernel_name)
{
    int i, any = 0;
    for (i = 0; i < count; i++) any |= spans[i].large_elems > spans[i].small_elems;
    if (!any) return; /* one size per model (quick) */
    printf("\ncost per element from the smallest to the largest size, 1 thread (cache to memory):\n");
    for (i = 0; i < count; i++) {
        const kernel_span *k = spans + i;
        if (k->large_elems <= k->small_elems) continue;
        printf("  %-10s %-12s %-6s %-7s %9.0f -> %9.0f elements: %7.2f -> %7.2f ns (x %.2f)\n", k->m->model,
               k->m->variant, k->m->precision, kernel_name[k->kernel], k->small_elems, k->large_elems, k->small_ns,
               k->large_ns, k->large_ns / k->small_ns);
    }
}

/* The reduced chain of frames.h (issue 15), in the kernels part: block-tridiagonal factor
   and solve against the block count, one inverse control step of the 16-vertebra arm
   (examples/frames_soft_arm.c). One thread. chain.csv; --filter chain or btd selects it. */
static void run_chain(const options *o)
{
    const char *names[16];
    double sizes[16], seconds[16];
    int p, i, rows;
    FILE *f;
    if (o->filter && !strstr("frames chain btd", o->filter)) return;
    printf("\n== frames.h reduced chain (issue 15), 1 thread ==\n");
    f = open_csv(o, "chain.csv", "precision,kernel,blocks,us,ns_per_block");
    for (p = 0; p < 2; p++) {
        rows = (p ? bench_chain_rows_float : bench_chain_rows_double)(o->quick, now, names, sizes, seconds);
        for (i = 0; i < rows; i++) {
            printf("  %-6s %-17s %6.0f blocks: %10.2f us (%.1f ns a block)\n", p ? "float" : "double", names[i],
                   sizes[i], 1e6 * seconds[i], 1e9 * seconds[i] / sizes[i]);
            if (f) csv_prefix(f);
            if (f)
                fprintf(f, "%s,%s,%.0f,%.3f,%.2f\n", p ? "float" : "double", names[i], sizes[i], 1e6 * seconds[i],
                        1e9 * seconds[i] / sizes[i]);
        }
    }
    if (f) fclose(f);
}

/* single-thread results of this run, for the peer ratios */
typedef struct kernel_result {
    const bench_model *m;
    int kernel;
    double elems, ns;
} kernel_result;
static kernel_result kernel_results[4096];
static int kernel_result_count;

/* The kernels part's model list: the selected entries, then the peers (when built, and the
   filter is empty or names them or heml, their comparison). */
static int kernel_models(const options *o, const bench_model *const *models, int count, const bench_model **out)
{
    int i, n = 0;
    for (i = 0; i < count && n < 250; i++) out[n++] = models[i];
#ifdef BENCH_HAVE_BULLET
    {
        int pc = 0;
        const bench_model *peers = bench_models_bullet(&pc);
        if (!o->filter || strstr("bullet heml neo-hookean corotated", o->filter))
            for (i = 0; i < pc && n < 256; i++) out[n++] = peers + i;
    }
#else
    (void)o;
    printf("Bullet rows skipped: install Debian's libbullet-dev (apt-get install libbullet-dev) and rebuild the "
           "bench (make build/bench/bench) to time Bullet's Neo-Hookean and corotated forces and implicit step\n");
#endif
    return n;
}

static void print_peer_ratios(const char *const *kernel_name)
{
    int i, j;
    for (i = 0; i < kernel_result_count; i++) {
        const kernel_result *p = kernel_results + i;
        if (strcmp(p->m->model, "bullet")) continue;
        for (j = 0; j < kernel_result_count; j++) {
            const kernel_result *h = kernel_results + j;
            if (strcmp(h->m->model, "heml") || strcmp(h->m->variant, "neo-hookean") || h->kernel != p->kernel ||
                h->elems != p->elems)
                continue;
            printf("  peer: bullet %-11s %-5s %7.0f tets: %8.1f ns = %6.1f x heml neo-hookean %s (%.1f ns)\n",
                   p->m->variant, kernel_name[p->kernel], p->elems, p->ns, p->ns / h->ns, h->m->precision, h->ns);
        }
    }
}

static void run_kernels(const options *o, const bench_model *const *models_in, int count_in)
{
    static const bench_model *models[256];
    int count;
    static kernel_span spans[256 * BENCH_KERNEL_COUNT]; /* 256 model entries at most (main) */
    int span_count = 0;
    static const double targets[4] = {1e3, 1e4, 1e5, 1e6};
    static const char *kernel_name[BENCH_KERNEL_COUNT] = {"force", "K*v", "K*v-blk", "move", "K*v-csr", "arith", "step"};
    double bandwidth[3];
    int i, s, th, kern, sizes = o->quick ? 1 : 4, max_threads = o->threads;
    FILE *f;
    printf("\n== 3. kernel throughput ==\n");
    count = kernel_models(o, models_in, count_in, models);
    for (th = 1; th <= max_threads; th++) {
        bandwidth[th] = stream_triad(o->quick ? (size_t)1 << 22 : (size_t)1 << 25, th);
        printf("STREAM triad, %d thread%s: %.1f GB/s\n", th, th > 1 ? "s" : "", bandwidth[th]);
    }
    f = open_csv(o, "kernels.csv",
                 "model,variant,precision,kernel,threads,elements,element,ns_per_element,bytes_per_element,"
                 "bound_ns_per_element,ratio_to_bound,stream_gbs");
    printf("%-10s %-12s %-6s %-6s %-2s %9s %10s %10s %9s %7s\n", "model", "variant", "prec", "kernel", "th",
           "elements", "ns/elem", "bytes/elem", "bound ns", "ratio");
    for (i = 0; i < count; i++) {
        const bench_model *m = models[i];
        double per_cell = 6.0;
        void *probe = NULL;
        /* elements per cell of this model (tetrahedra, or sample-frame pairs), from a cube
           of 2^3 cells, so that every model's sizes meet the targets */
        {
            bench_body b = make_body(0.02, 0.02, 0.02, 2, 2, 2, 1e5, 0.3, 1000);
            if (!m->create(&b, &probe)) {
                per_cell = m->elements(probe) / 8.0;
                m->destroy(probe);
            }
        }
        for (s = 0; s < (m->primary > 0 || o->quick ? sizes : 2); s++) {
            /* a cube of n^3 cells; adapters report the elements they built */
            int n = (int)ceil(cbrt(targets[s] / per_cell)), code;
            bench_body b = make_body(n * 0.01, n * 0.01, n * 0.01, n, n, n, 1e5, 0.3, 1000);
            void *sim = NULL;
            if (m->create(&b, &sim)) continue;
            double ns1[BENCH_KERNEL_COUNT], bound1 = NAN;
            for (kern = 0; kern < BENCH_KERNEL_COUNT; kern++) ns1[kern] = NAN;
            /* one step under gravity, so the kernels see a generic deformed state */
            m->step(sim, 1e-5, (m->integrators & BIT(BENCH_SEMI_IMPLICIT_EULER)) ? BENCH_SEMI_IMPLICIT_EULER
                                                                                 : BENCH_IMPLICIT_EULER);
            for (kern = 0; kern < BENCH_KERNEL_COUNT; kern++)
                for (th = 1; th <= max_threads; th++) {
                    double sec, elems = m->elements(sim), bytes = m->kernel_bytes(sim, kern), bound, ns;
                    if (kern == BENCH_KERNEL_STEP && (th > 1 || elems > 2e5)) break; /* (seconds per step) */
                    set_threads(th);
                    sec = time_kernel(m, sim, kern, o->quick ? 0.01 : 0.02, &code);
                    if (code) break;
                    ns = 1e9 * sec / elems;
                    if (th == 1 && span_count < (int)(sizeof spans / sizeof spans[0])) {
                        kernel_span *k = NULL;
                        int j;
                        for (j = 0; j < span_count; j++)
                            if (spans[j].m == m && spans[j].kernel == kern) k = spans + j;
                        if (!k) {
                            k = spans + span_count++;
                            k->m = m, k->kernel = kern, k->small_elems = elems, k->small_ns = ns;
                        }
                        k->large_elems = elems, k->large_ns = ns;
                    }
                    bound = bytes > 0 ? bytes / (bandwidth[th] * 1e9) * 1e9 / elems : NAN;
                    if (th == 1 && kernel_result_count < (int)(sizeof kernel_results / sizeof kernel_results[0])) {
                        kernel_result *r = kernel_results + kernel_result_count++;
                        r->m = m, r->kernel = kern, r->elems = elems, r->ns = ns;
                    }
                    if (th == 1) {
                        ns1[kern] = ns;
                        if (kern == BENCH_KERNEL_FORCE) bound1 = bound;
                    }
                    printf("%-10s %-12s %-6s %-6s %-2d %9.0f %10.2f %10.1f %9.2f %7.2f\n", m->model, m->variant,
                           m->precision, kernel_name[kern], th, elems, ns, bytes / elems, bound, ns / bound);
                    fflush(stdout);
                    csv_prefix(f);
                    fprintf(f, "%s,%s,%s,%s,%d,%.0f,%s,%.4g,%.4g,%.4g,%.4g,%.4g\n", m->model, m->variant,
                            m->precision, kernel_name[kern], th, elems, m->element, ns, bytes / elems, bound,
                            ns / bound, bandwidth[th]);
                }
            /* the issue-21 ratios, measured in this run (1 thread) */
            if (ns1[BENCH_KERNEL_FORCE] > 0 && (ns1[BENCH_KERNEL_ARITH] > 0 || ns1[BENCH_KERNEL_CSR] > 0)) {
                printf("  ratios %s %s %s, %.0f elements, 1 thread: force at %.0f %% of its bandwidth bound", m->model,
                       m->variant, m->precision, m->elements(sim), 100 * bound1 / ns1[BENCH_KERNEL_FORCE]);
                if (ns1[BENCH_KERNEL_ARITH] > 0)
                    printf(", %.2f x its arithmetic floor", ns1[BENCH_KERNEL_FORCE] / ns1[BENCH_KERNEL_ARITH]);
                if (ns1[BENCH_KERNEL_CSR] > 0)
                    printf(", K*v %.2f x the CSR product's time", ns1[BENCH_KERNEL_KV] / ns1[BENCH_KERNEL_CSR]);
                printf("\n");
            }
            m->destroy(sim);
        }
    }
    print_kernel_spans(spans, span_count, kernel_name);
    print_peer_ratios(kernel_name);
    /* haptic scenes: precomputed contact models */
    for (i = 0; i < count; i++) {
        double upd[3], pre = 0, mem = 0;
        int surf = 0, c;
        if (!models[i]->haptic) continue;
        set_threads(1);
        if (models[i]->haptic(o->quick, upd, &surf, &pre, &mem)) continue;
        printf("haptic update %s %s %s: %d surface nodes, precomputed in %.1f s, %.1f MB:", models[i]->model,
               models[i]->variant, models[i]->precision, surf, pre, mem / 1e6);
        for (c = 0; c < 3; c++) {
            printf("  %d contact%s %.2f us (%.0f Hz)", c + 1, c ? "s" : "", 1e6 * upd[c], 1 / upd[c]);
            csv_prefix(f);
            fprintf(f, "%s,%s,%s,qs-update-%d-contacts,1,%d,surface-node,%.4g,,,,%.4g\n", models[i]->model,
                    models[i]->variant, models[i]->precision, c + 1, surf, 1e9 * upd[c] / surf, bandwidth[1]);
        }
        printf("\n");
    }
    /* mapped points (issue 14): a render mesh's vertices inside the elements, about 30,000
       (quick: 4,000) */
    for (i = 0; i < count; i++) {
        const bench_model *m = models[i];
        static const char *what[3] = {"mapped-positions", "mapped-velocities", "mapped-JTf"};
        double ns[3];
        int n = o->quick ? 8 : 16, points = 0, c;
        bench_body b = make_body(n * 0.01, n * 0.01, n * 0.01, n, n, n, 1e5, 0.3, 1000);
        void *sim = NULL;
        if (!m->mapped || !m->primary || m->create(&b, &sim)) continue;
        set_threads(1);
        m->step(sim, 1e-5, BENCH_IMPLICIT_EULER); /* a generic deformed state */
        if (!m->mapped(sim, &points, ns)) {
            printf("%s %s %s mapped points (%d, 1 thread): positions %.1f ns, velocities %.1f ns, J^T f %.1f ns a point\n",
                   m->model, m->variant, m->precision, points, ns[0], ns[1], ns[2]);
            for (c = 0; c < 3; c++) {
                csv_prefix(f);
                fprintf(f, "%s,%s,%s,%s,1,%d,point,%.4g,,,,%.4g\n", m->model, m->variant, m->precision, what[c], points,
                        ns[c], bandwidth[1]);
            }
        }
        m->destroy(sim);
    }
    /* the glue (issue 14): a heml.h half beam glued to a frames half beam, stiff coupling
       (bench/model_glue.c); --filter glue runs these rows alone */
    if (!o->filter || strstr(o->filter, "glue")) {
        double v[8];
        set_threads(1);
        if (!bench_glue_rows_double(o->quick, v)) {
            static const char *what[4] = {"glue-step", "glue-step-frames", "glue-step-heml", "glue-R1-error-glued"};
            printf("glue heml+frames double: soft beam at dt 10 ms %.1f ms a step (frames %.1f, heml %.1f, %.1f "
                   "iterations); R1 tip against Timoshenko: glued %+.2f %%, frames alone %+.2f %%, heml alone %+.2f "
                   "%% (%g iterations)\n", v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]);
            for (i = 0; i < 3; i++) {
                csv_prefix(f);
                fprintf(f, "glue,heml+frames,double,%s,1,1,step,%.4g,,,,\n", what[i], 1e6 * v[i]); /* ns a step */
            }
            csv_prefix(f);
            fprintf(f, "glue,heml+frames,double,%s,1,1,percent,%.4g,,,,\n", what[3], v[4]);
            csv_prefix(f);
            fprintf(f, "glue,frames-alone,double,glue-R1-error-frames,1,1,percent,%.4g,,,,\n", v[5]);
            csv_prefix(f);
            fprintf(f, "glue,heml-alone,double,glue-R1-error-heml,1,1,percent,%.4g,,,,\n", v[6]);
        } else
            printf("glue heml+frames: a coupled solve failed\n");
        (void)bench_glue_rows_float;
    }
    fclose(f);
}

/* >>main */

static void usage(void)
{
    fprintf(stderr, "usage: bench [--quick] [--out DIR] [--parts trade,race,stability,sweep,time,coarse,kernels] "
                    "[--filter TEXT] [--scenes R1,R3,...] [--repeats N] [--threads N] [--budget SECONDS] "
                    "[--race-budget SECONDS]\n");
    exit(2);
}

int main(int argc, char **argv)
{
    options o;
    static const bench_model *models[256], *variants[64];
    int i, count = 0, variant_count = 0;
    /* trade, stability, sweep, time, kernels, coarse, race */
    double t0 = now(), tp, part_time[7] = {0, 0, 0, 0, 0, 0, 0};
    memset(&o, 0, sizeof o);
    o.repeats = 3;
    o.threads = 2;
    o.out = "bench/results";
    o.parts = 127;
    o.budget = 2;
    o.race_budget = -1;
    for (i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--quick")) o.quick = 1;
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) o.out = argv[++i];
        else if (!strcmp(argv[i], "--filter") && i + 1 < argc) o.filter = argv[++i];
        else if (!strcmp(argv[i], "--scenes") && i + 1 < argc) o.scenes = argv[++i];
        else if (!strcmp(argv[i], "--repeats") && i + 1 < argc) o.repeats = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--budget") && i + 1 < argc) o.budget = atof(argv[++i]);
        else if (!strcmp(argv[i], "--race-budget") && i + 1 < argc) o.race_budget = atof(argv[++i]);
        else if (!strcmp(argv[i], "--threads") && i + 1 < argc) o.threads = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--parts") && i + 1 < argc) {
            const char *p = argv[++i];
            o.parts = (strstr(p, "trade") ? 1 : 0) | (strstr(p, "stability") ? 2 | 8 : 0) | (strstr(p, "kernels") ? 4 : 0) |
                      (strstr(p, "sweep") ? 8 : 0) | (strstr(p, "time") ? 16 : 0) | (strstr(p, "coarse") ? 32 : 0) |
                      (strstr(p, "race") ? 64 : 0);
        } else usage();
    }
    if (o.repeats < 1 || o.threads < 1 || o.threads > 2 || !o.parts) usage();
    if (o.race_budget < 0) o.race_budget = o.quick ? 0.5 : 60;
    mkdir(o.out, 0755); /* may exist already; open_csv reports a real failure */
    read_environment();
    for (i = 0; i < (int)(sizeof registry / sizeof registry[0]); i++) {
        int n, j;
        const bench_model *table = registry[i](&n);
        for (j = 0; j < n && count < 256; j++)
            if (selected(&o, table + j)) {
                if (table[j].primary >= 0) models[count++] = table + j;
                else if (variant_count < 64) variants[variant_count++] = table + j;
            }
    }
    {
        const char *wait = getenv("OMP_WAIT_POLICY");
        printf("bench: %d model entries, %s, %s, %s, git %s%s, OMP_WAIT_POLICY=%s\n", count, env_cpu, env_compiler,
               BENCH_FLAGS, BENCH_GIT, o.quick ? ", quick" : "", wait ? wait : "(unset)");
#ifdef _OPENMP
        /* spinning threads on a busy machine time the neighbours, not the kernel (Makefile) */
        if ((o.parts & 4) && o.threads > 1 && !wait)
            fprintf(stderr, "bench: OMP_WAIT_POLICY is unset: on a busy machine the 2-thread rows may measure "
                            "spinning; `make bench` sets it to passive\n");
#endif
    }
    set_threads(1);
    tp = now();
    if (o.parts & 1) run_trade(&o, models, count, variants, variant_count), part_time[0] = now() - tp, tp = now();
    if (o.parts & 64) run_race(&o, models, count), part_time[6] = now() - tp, tp = now();
    set_threads(1);
    if (o.parts & 2) run_stability(&o, models, count, variants, variant_count), part_time[1] = now() - tp, tp = now();
    set_threads(1);
    if (o.parts & 8) { /* the primary = -1 entries too (issue 13's options near nu = 0.5), not in --quick */
        static const bench_model *all[256];
        int n = 0;
        for (i = 0; i < count && n < 256; i++) all[n++] = models[i];
        for (i = 0; i < variant_count && n < 256 && !o.quick; i++) all[n++] = variants[i];
        run_sweep(&o, all, n);
        part_time[2] = now() - tp, tp = now();
    }
    set_threads(1);
    if (o.parts & 16) run_time(&o, models, count), part_time[3] = now() - tp, tp = now();
    if (o.parts & 32) run_coarse(&o), part_time[5] = now() - tp, tp = now();
    if (o.parts & 4) { /* the primary = -1 entries too (their two smallest sizes) */
        static const bench_model *all[256];
        int n = 0;
        for (i = 0; i < count && n < 256; i++) all[n++] = models[i];
        for (i = 0; i < variant_count && n < 256; i++) all[n++] = variants[i];
        run_kernels(&o, all, n);
    }
    if (o.parts & 4) run_chain(&o), part_time[4] = now() - tp;
    printf("\nbench: done in %.0f s (trade %.0f, race %.0f, stability %.0f, sweep %.0f, time %.0f, coarse %.0f, "
           "kernels %.0f); results in %s/\n", now() - t0, part_time[0], part_time[6], part_time[1], part_time[2],
           part_time[3], part_time[5], part_time[4], o.out);
    return 0;
}
