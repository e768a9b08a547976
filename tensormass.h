/* tensormass.h - v0.1.0 - linear tensor-mass elasticity with cutting and tearing - MIT or public domain

   A drop-in soft-body model after Cotin, Delingette & Ayache, "Efficient linear elastic
   models of soft tissues for real-time surgery simulation" (INRIA RR-3510, 1998): linear
   elasticity on tetrahedra written as one 3x3 tensor per vertex and per edge, so a force
   evaluation costs one pass over the edges and cutting a tetrahedron costs ten local
   tensor subtractions. A mass-spring network on the same mesh (eq. 7) is included as the
   baseline the paper compares against.

   DO THIS in exactly one C or C++ file:

       #define TENSORMASS_IMPLEMENTATION
       #include "tensormass.h"

   MINIMAL PROGRAM (examples/tensormass_hello.c: a cube of six tetrahedra hanging from its
   top face; cc app.c -lm)

       #define TENSORMASS_IMPLEMENTATION
       #include "tensormass.h"
       #include <stdio.h>

       int main(void)
       {
           static const tmass_real nodes[8 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                                   0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
           static const int tets[6 * 4] = {0, 1, 3, 7, 0, 5, 1, 7, 0, 3, 2, 7,
                                           0, 2, 6, 7, 0, 4, 5, 7, 0, 6, 4, 7};
           tmass_desc d = tmass_default_desc();
           tmass_model *m;
           int i, err;
           d.rest_positions = nodes;
           d.node_count = 8;
           d.tets = tets;
           d.tet_count = 6;
           d.young_modulus = 1e5; // Pa
           d.poisson_ratio = 0.3;
           d.density = 1000;      // kg/m^3
           d.time_step = 1e-3;    // s
           d.integrator = TMASS_IMPLICIT_EULER;
           err = tmass_create(&d, &m);
           if (err) {
               printf("%s\n", tmass_error_string(err));
               return 1;
           }
           for (i = 4; i < 8; i++) tmass_fix_node(m, i); // the face z = 1
           for (i = 0; i < 1000; i++) tmass_step(m);     // one simulated second
           printf("corner 0 sagged to z = %g m\n", (double)tmass_positions(m)[2]);
           tmass_destroy(m);
           return 0;
       }

   OVERRIDES (define before including the implementation)

       TMASS_REAL      float or double (default double). Creation computes the tensors in
                       double and stores them in TMASS_REAL. In float builds tmass_create
                       and tmass_default_desc are renamed (..._f32), so mixing float and
                       double translation units fails at link time, not at run time.
       TMASS_MALLOC(size, user) / TMASS_FREE(ptr, user)
                       default allocator (malloc/free) when the desc gives none.
       TMASS_ASSERT(x) internal sanity checks (default: assert from <assert.h>).
       TMASS_STATIC    make every function static (private to the including file).

   STEP BY STEP
       1. tmass_desc d = tmass_default_desc(); fill the mesh, the material, the time step.
       2. tmass_create(&d, &m) validates everything and allocates all memory once.
       3. Boundary conditions: tmass_fix_node (pinned where it is), tmass_set_displacement
          (pinned at rest + u, e.g. driven by a tool), tmass_release_node, gravity,
          tmass_set_external_force.
       4. tmass_step(m) (desc integrator and time step) or tmass_step_ex(m, dt, integrator);
          tmass_solve_static(m) for the equilibrium.
       5. Read tmass_positions / tmass_velocities / tmass_boundary_triangles to render.
       6. Topology: tmass_remove_tets (cutting), tmass_tear (tearing by criteria).
       7. tmass_destroy(m).

   UNITS: SI throughout. Positions m, Young's modulus Pa, density kg/m^3, time s, forces
   N, mass_damping 1/s, stiffness_damping s, gravity m/s^2 (default 9.81 along -z).

   MEMORY: tmass_create makes one allocation (one block; every array in it 64-byte aligned)
   through the desc's allocator (or TMASS_MALLOC), plus a temporary one it frees before
   returning. A custom allocator must honour the alignment it is asked for (64).
   Nothing else allocates: stepping, forces, solves, cutting and tearing reuse that block
   (cutting only removes, so capacity never runs out). The description's arrays are read
   during tmass_create only. Pointers returned by tmass_positions and friends point into
   the model and stay valid until tmass_destroy.

   ERRORS: every fallible function returns 0 or a negative TMASS_ERR_* code;
   tmass_error_string names it, and the optional desc.log callback receives a detailed
   message for validation failures (the library never prints). A step whose result is not
   finite returns TMASS_ERR_NOT_FINITE and leaves positions and velocities exactly as they
   were, so the caller may retry with a smaller time step or the implicit integrator.

   THREADING AND DETERMINISM: no global state; one model may be used by one thread at a
   time, different models by different threads. Loops run in parallel through desc.
   parallel_for (an engine's job system) when given, through OpenMP when compiled with
   -fopenmp, serially otherwise; small meshes (under TMASS_PARALLEL_MIN_EDGES edges) run
   serially. Work is cut into fixed chunks that do not depend on the thread count, edges
   are processed in colour order (no two edges of a colour group share a vertex), and
   reductions add fixed block partial sums in a fixed order, so results are bit-identical
   whatever the number of threads. There are no atomics.

   THE MODEL (paper equations; our derivations where the printed ones differ)
       Each tetrahedron T with rest vertices P0..P3 has linear shape functions N_j with
       constant gradients g_j = -M_j / (6 V) (appendix A: M_j is twice the outward area
       vector of the face opposite j; we compute it from edge vectors, which is exact and
       keeps precision far from the origin). Its 3x3 stiffness tensors (eq. 5) are
           K_jk = V (lambda g_j g_k^T + mu g_k g_j^T + mu (g_j . g_k) I)
                = (lambda M_j M_k^T + mu M_k M_j^T + mu (M_j . M_k) I) / (36 V).
       (The report prints the first two products transposed, which is K_kj; the finite-
       difference and P1-FEM tests decide for the form above.) Vertex tensors K_ii and edge
       tensors K_ij sum the tetrahedra around a vertex or an edge, and the elastic force on
       vertex i is (eq. 6, with the sign of a force, minus the energy gradient)
           F_i = -(K_ii u_i + sum_{j in N(i)} K_ij u_j),   u = P - P0.
       Dynamics (eq. 4): m_i a_i = F_i + f_ext,i + m_i g - damping, with lumped masses
       m_i = density * (sum of adjacent tet volumes) / 4 and Rayleigh damping
       C = mass_damping M + stiffness_damping K.
       Mass-spring model (eq. 7): F_i = sum_j k_ij (|P_i P_j| - l_ij) P_iP_j / |P_iP_j| on
       the mesh edges with k_ij = E sum_{T contains ij} V_T / l_ij^2 (a volume-weighted rule
       after Van Gelder 1998: for a uniform dilation it stores exactly the energy of a
       continuum with Poisson ratio 1/4, on any mesh). A spring network only has central
       forces, so its effective Poisson ratio is pinned near 1/4 by the Cauchy relations
       and its shear stiffness depends on how the mesh is cut: it cannot match a continuum
       with another Poisson ratio or on an irregular mesh, which is why the paper prefers
       tensors. poisson_ratio is ignored by the spring model. Damping for springs: mass
       part as above, stiffness part along each spring, c_ij = stiffness_damping * k_ij.

   INTEGRATORS (the desc picks a default, tmass_step_ex picks per call)
       TMASS_EXPLICIT_EULER        x1 = x + dt v, v1 = v + dt a(x, v). Unstable without
                                   damping: every undamped mode grows by sqrt(1 + (w dt)^2)
                                   per step. For teaching and comparison only.
       TMASS_SEMI_IMPLICIT_EULER   v1 = v + dt a(x, v), x1 = x + dt v1. Symplectic: the energy
                                   of an undamped vibration stays bounded; stable for
                                   dt < 2 / w_max (w_max the highest mesh frequency).
       TMASS_RK4                   classical fourth-order Runge-Kutta on (x, v) (sec. 5.4):
                                   four force evaluations, stable up to about 2.8 / w_max,
                                   slightly dissipative.
       TMASS_IMPLICIT_EULER        (M (1 + dt alpha) + (dt^2 + dt beta) K) dv = dt (f - dt K v),
                                   solved by Jacobi-preconditioned conjugate gradient applied
                                   matrix-free over the edge tensors (beyond the paper).
                                   Unconditionally stable (strongly damps high frequencies);
                                   for springs the tangent stiffness is rebuilt each step with
                                   its compressive geometric part clamped so the system stays
                                   positive definite. The default.

   CUTTING AND TEARING (sec. 5.5): tmass_remove_tets removes tetrahedra by subtracting their
   ten tensors (four vertex, six edge) and their mass, drops edges left without a
   tetrahedron, marks vertices left without one inactive (frozen, mass 0) and updates the
   boundary-triangle list; cost linear in the tetrahedra removed. Tetrahedron indices are
   those of the description and stay valid forever (cutting never creates or renumbers
   tetrahedra); removing one twice is harmless. tmass_tear removes every tetrahedron past
   any enabled threshold of: relative volume change |V - V0| / V0, mean relative edge
   elongation, maximum relative edge elongation ((l - l0) / l0, positive in tension).

   PERFORMANCE: a force evaluation is one pass over the live edges. Per edge it reads two
   int node indices and one 3x3 tensor (8 + 72 = 80 bytes in double, 8 + 36 = 44 in
   float) and the displacements of both ends, and updates the forces of both ends; per
   vertex it touches 3 displacements and 3 forces (zeroed, then accumulated). There is no
   vertex pass: eq. 6 is evaluated in its difference form (see THE MODEL). Edges are sorted
   by their lower vertex and grouped in contiguous chunks, so the tensors stream from
   memory; a run of edges sharing their lower vertex accumulates in registers. Measured on
   an AMD EPYC (Zen 5) core, gcc -O3 -march=native, double, beam meshes of 768 to 768,000
   tetrahedra: 3.4 to 3.6 ns per edge (4.1 to 5.1 ns per tetrahedron), 1.5 to 1.6 times the
   time to stream the 80 bytes per edge at the STREAM triad rate measured in the same run
   (1.2 to 1.4 times when the vertex traffic is counted too). In ISO mode (-std=c99) gcc
   does not contract multiply-adds into FMAs and the loop is about 8 % slower. Removing a
   tetrahedron is constant work (ten tensor updates, its edges, faces and boundary
   triangles): 0.26 us per tetrahedron on a 6,000-tet mesh, 1.4 us on a 1.3-million-tet
   mesh with tetrahedra picked at random (cache misses). Number mesh nodes with locality
   (as the box generators and most meshers do) to keep vertex accesses in cache.

   LIMITS
       - Linear elasticity: valid for small displacements (a few % strain). It is not
         rotation invariant: a rigid rotation produces "ghost" forces proportional to the
         rotation (a 90 degree turn yields forces of the order of E times the element size
         squared). Use heml.h or frames.h for large rotations.
       - Linear tetrahedra lock in bending and near incompressibility (nu -> 0.5): refine
         the mesh across thin parts; a bending beam needs several tets across.
       - The explicit integrators are conditionally stable; tmass_step returns
         TMASS_ERR_NOT_FINITE rather than NaN when they blow up.
       - Inactive (cut-off) vertices keep their last position and do not move.

   HISTORY
       0.1.0 (2026-11-22) first release: tensor-mass and mass-spring models, four
             integrators, static solve, cutting, tearing.

   Licence at the end of the file. */
#ifndef TENSORMASS_H
#define TENSORMASS_H

#include <stddef.h>

#define TMASS_VERSION_MAJOR 0
#define TMASS_VERSION_MINOR 1
#define TMASS_VERSION_PATCH 0

#ifndef TMASS_REAL
#define TMASS_REAL double
#endif
typedef TMASS_REAL tmass_real;

#ifdef TMASS_STATIC
#define TMASSDEF static
#else
#define TMASSDEF extern
#endif

/* Float builds rename the constructors so that a float and a double translation unit
   cannot be linked together by mistake. TMASS_REAL must be the single token float or
   double. */
#define TMASS__IS_float 1
#define TMASS__IS_double 0
#define TMASS__CAT2(a, b) a##b
#define TMASS__CAT(a, b) TMASS__CAT2(a, b)
#if TMASS__CAT(TMASS__IS_, TMASS_REAL)
#define tmass_create tmass_create_f32
#define tmass_default_desc tmass_default_desc_f32
#endif

/* Edges below which loops run serially (parallel start-up costs more than it saves). */
#ifndef TMASS_PARALLEL_MIN_EDGES
#define TMASS_PARALLEL_MIN_EDGES 20000
#endif

/* Error codes and their messages, one list so they cannot drift apart. */
#define TMASS_ERROR_LIST(X) \
    X(TMASS_OK, 0, "ok") \
    X(TMASS_ERR_ARG, -1, "invalid argument (NULL pointer, bad count or non-finite value)") \
    X(TMASS_ERR_ALLOC, -2, "out of memory") \
    X(TMASS_ERR_DESC, -3, "description not initialised with tmass_default_desc") \
    X(TMASS_ERR_NODE_COUNT, -4, "node count below 4 or too large") \
    X(TMASS_ERR_TET_COUNT, -5, "tetrahedron count below 1 or too large") \
    X(TMASS_ERR_NODE_NOT_FINITE, -6, "rest position not finite") \
    X(TMASS_ERR_INDEX_RANGE, -7, "tetrahedron node index out of range") \
    X(TMASS_ERR_INDEX_REPEATED, -8, "tetrahedron uses the same node twice") \
    X(TMASS_ERR_TET_DEGENERATE, -9, "degenerate (flat) rest tetrahedron") \
    X(TMASS_ERR_TET_INVERTED, -10, "negatively oriented rest tetrahedron") \
    X(TMASS_ERR_NONMANIFOLD, -11, "a triangle is shared by more than two tetrahedra") \
    X(TMASS_ERR_YOUNG_MODULUS, -12, "Young's modulus not finite and > 0") \
    X(TMASS_ERR_POISSON_RATIO, -13, "Poisson ratio outside (-1, 0.5)") \
    X(TMASS_ERR_DENSITY, -14, "density not finite and > 0") \
    X(TMASS_ERR_TIME_STEP, -15, "time step not finite and > 0") \
    X(TMASS_ERR_DAMPING, -16, "damping coefficient not finite and >= 0") \
    X(TMASS_ERR_INTEGRATOR, -17, "unknown integrator") \
    X(TMASS_ERR_MODEL_KIND, -18, "unknown model kind") \
    X(TMASS_ERR_SOLVER, -19, "solver settings invalid (tolerance > 0, iterations >= 1)") \
    X(TMASS_ERR_NOT_FINITE, -20, "result not finite; the last valid state was kept") \
    X(TMASS_ERR_NO_CONVERGENCE, -21, "solver did not converge; the last valid state was kept") \
    X(TMASS_ERR_NODE_RANGE, -22, "node index out of range") \
    X(TMASS_ERR_TET_RANGE, -23, "tetrahedron index out of range") \
    X(TMASS_ERR_NODE_INACTIVE, -24, "node belongs to no tetrahedron any more") \
    X(TMASS_ERR_NO_EDGE, -25, "the two nodes share no edge")

enum {
#define TMASS__ENUM(name, value, text) name = value,
    TMASS_ERROR_LIST(TMASS__ENUM)
#undef TMASS__ENUM
    TMASS_ERR_LAST_ = -26
};

typedef enum tmass_model_kind {
    TMASS_TENSOR_MASS = 0, /* linear elasticity, Cotin et al. eqs. 5-6 (default) */
    TMASS_MASS_SPRING = 1  /* springs on the mesh edges, eq. 7 (baseline) */
} tmass_model_kind;

typedef enum tmass_integrator {
    TMASS_EXPLICIT_EULER = 0,
    TMASS_SEMI_IMPLICIT_EULER = 1,
    TMASS_RK4 = 2,
    TMASS_IMPLICIT_EULER = 3
} tmass_integrator;

/* Custom allocator: alloc(size, align, user) returns memory aligned to `align` (a power
   of two <= 64) or NULL; free(ptr, size, user) releases it. */
typedef struct tmass_allocator {
    void *(*alloc)(size_t size, size_t align, void *user);
    void (*free)(void *ptr, size_t size, void *user);
    void *user;
} tmass_allocator;

/* An engine's job system: run task(task_context, begin, end) over a partition of
   [0, item_count) (any split, any threads) and return when every item is done. */
typedef void (*tmass_task_fn)(void *task_context, int begin, int end);
typedef void (*tmass_parallel_for_fn)(int item_count, tmass_task_fn task, void *task_context,
                                      void *user);

typedef struct tmass_desc {
    /* mesh (read during tmass_create only) */
    const tmass_real *rest_positions; /* 3 * node_count coordinates, m */
    int node_count;                   /* >= 4 */
    const int *tets;                  /* 4 * tet_count zero-based node indices, positive
                                         orientation: (P1-P0).((P2-P0)x(P3-P0)) > 0 */
    int tet_count;                    /* >= 1 */

    tmass_model_kind kind; /* default TMASS_TENSOR_MASS */

    /* material */
    tmass_real young_modulus;             /* Pa, default 1e4 (soft tissue) */
    tmass_real poisson_ratio;             /* in (-1, 0.5), default 0.3 */
    const tmass_real *tet_young_modulus;  /* optional per-tet Pa (tet_count values) or NULL */
    const tmass_real *tet_poisson_ratio;  /* optional per-tet ratio or NULL */
    tmass_real density;                   /* kg/m^3, default 1000 */
    tmass_real mass_damping;              /* Rayleigh alpha, 1/s, default 0 */
    tmass_real stiffness_damping;         /* Rayleigh beta, s, default 0 */

    /* dynamics */
    tmass_real gravity[3];       /* m/s^2, default (0, 0, -9.81) */
    tmass_real time_step;        /* s, default 1e-3, used by tmass_step */
    tmass_integrator integrator; /* default TMASS_IMPLICIT_EULER */
    tmass_real cg_tolerance;     /* relative residual of CG solves, default 1e-6 (1e-5 float) */
    int cg_max_iterations;       /* default 2000 */

    /* environment */
    tmass_allocator allocator;          /* all NULL: TMASS_MALLOC / TMASS_FREE */
    tmass_parallel_for_fn parallel_for; /* NULL: OpenMP if compiled with it, else serial */
    void *parallel_user;
    void (*log)(int code, const char *message, void *user); /* validation details, or NULL */
    void *log_user;

    unsigned int internal_cookie; /* set by tmass_default_desc; do not touch */
} tmass_desc;

/* Statistics of the last step or solve (read with tmass_last_stats). */
typedef struct tmass_stats {
    int cg_iterations;      /* CG iterations (implicit step or static solve), summed over Newton */
    tmass_real cg_residual; /* final relative residual |r| / |b| */
    int newton_iterations;  /* static solve of the spring model; 1 otherwise */
    int force_evaluations;  /* force (or K times vector) evaluations in the step */
} tmass_stats;

/* Energies of the current state (tmass_energy). */
typedef struct tmass_energies {
    double kinetic;       /* J, 1/2 sum m v^2 */
    double elastic;       /* J, 1/2 u^T K u (tensor) or sum 1/2 k (l - l0)^2 (springs) */
    double gravitational; /* J, -sum m g . u (zero at rest) */
    double external;      /* J, -sum f_ext . u (potential of the constant external forces) */
} tmass_energies;

/* Tearing thresholds; a value <= 0 disables that criterion (tmass_default_tear_criteria
   disables all three). */
typedef struct tmass_tear_criteria {
    tmass_real volume_change;   /* |V - V0| / V0 */
    tmass_real mean_elongation; /* mean over the six edges of (l - l0) / l0 */
    tmass_real max_elongation;  /* largest (l - l0) / l0 of the six edges */
} tmass_tear_criteria;

typedef struct tmass_model tmass_model;

/* Library version string "major.minor.patch". */
TMASSDEF const char *tmass_version(void);
/* Name of an error code (static string). */
TMASSDEF const char *tmass_error_string(int code);

/* A description with the documented defaults; always start from it. */
TMASSDEF tmass_desc tmass_default_desc(void);
/* Validates the description and creates a model in *out (NULL on failure). Allocates
   all the model's memory; the description's arrays may be freed afterwards. */
TMASSDEF int tmass_create(const tmass_desc *desc, tmass_model **out);
/* Frees the model and everything it owns. NULL is allowed. */
TMASSDEF void tmass_destroy(tmass_model *m);

/* ---- boundary conditions and loads (no allocation) ---- */

/* Pins node i where it is now. */
TMASSDEF int tmass_fix_node(tmass_model *m, int i);
/* Pins node i at rest position + u (m); the next step moves it there. */
TMASSDEF int tmass_set_displacement(tmass_model *m, int i, const tmass_real u[3]);
/* Releases a pinned node. */
TMASSDEF int tmass_release_node(tmass_model *m, int i);
/* 1 if node i is pinned (fixed or driven), 0 if free or inactive, <0 on error. */
TMASSDEF int tmass_node_pinned(const tmass_model *m, int i);
/* Constant external force on node i, N (replaces the previous one). */
TMASSDEF int tmass_set_external_force(tmass_model *m, int i, const tmass_real f[3]);
/* Sets every external force to zero. */
TMASSDEF void tmass_clear_external_forces(tmass_model *m);
/* Gravity, m/s^2. */
TMASSDEF int tmass_set_gravity(tmass_model *m, const tmass_real g[3]);
/* CG tolerance (relative residual, > 0) and iteration cap (>= 1) for later solves. */
TMASSDEF int tmass_set_solver(tmass_model *m, tmass_real tolerance, int max_iterations);

/* ---- simulation ---- */

/* One step with the description's time step and integrator. */
TMASSDEF int tmass_step(tmass_model *m);
/* One step of dt seconds with the given integrator. */
TMASSDEF int tmass_step_ex(tmass_model *m, tmass_real dt, tmass_integrator integrator);
/* Moves the free nodes to the static equilibrium under gravity, external forces and the
   pinned nodes, and sets velocities to zero. Tensor-mass: one CG solve (the model is
   linear). Springs: Newton iterations (up to 50) with a CG solve each. On failure
   (no convergence within the CG cap, or a singular problem such as nothing pinned) the
   state is unchanged. */
TMASSDEF int tmass_solve_static(tmass_model *m);

/* ---- state access (pointers into the model, valid until tmass_destroy) ---- */

TMASSDEF int tmass_node_count(const tmass_model *m);
TMASSDEF int tmass_tet_count(const tmass_model *m);           /* as in the description */
TMASSDEF int tmass_live_tet_count(const tmass_model *m);      /* not removed */
TMASSDEF int tmass_edge_count(const tmass_model *m);          /* live edges */
TMASSDEF const tmass_real *tmass_positions(const tmass_model *m);      /* 3n, m */
TMASSDEF const tmass_real *tmass_velocities(const tmass_model *m);     /* 3n, m/s */
TMASSDEF const tmass_real *tmass_rest_positions(const tmass_model *m); /* 3n, m */
TMASSDEF const tmass_real *tmass_masses(const tmass_model *m);         /* n lumped masses, kg */
/* Evaluates the elastic forces (no gravity, external force or damping) at the current
   positions and returns the model's array of 3n values, N. One force evaluation. */
TMASSDEF const tmass_real *tmass_forces(tmass_model *m);
/* Overwrites the positions (3n values, m) or velocities (m/s) of all nodes, for example
   to start from a deformed state. Values must be finite. */
TMASSDEF int tmass_set_positions(tmass_model *m, const tmass_real *positions);
TMASSDEF int tmass_set_velocities(tmass_model *m, const tmass_real *velocities);
/* Statistics of the last step or static solve. */
TMASSDEF const tmass_stats *tmass_last_stats(const tmass_model *m);
/* Energies of the current state. Costs one force evaluation. */
TMASSDEF int tmass_energy(tmass_model *m, tmass_energies *out);

/* ---- topology ---- */

/* Removes `count` tetrahedra (indices of the description); already removed ones are
   skipped. *removed (may be NULL) receives how many were removed now. Validates all
   indices first: on TMASS_ERR_TET_RANGE nothing is removed. Cost linear in count. */
TMASSDEF int tmass_remove_tets(tmass_model *m, const int *tets, int count, int *removed);
/* Thresholds with every criterion disabled. */
TMASSDEF tmass_tear_criteria tmass_default_tear_criteria(void);
/* Removes every live tetrahedron past any enabled threshold (all are evaluated on the
   current state before any is removed); *removed receives how many. Cost linear in the
   live tetrahedra. */
TMASSDEF int tmass_tear(tmass_model *m, const tmass_tear_criteria *criteria, int *removed);
/* Deformation measures of one tetrahedron: out[0] = |V - V0| / V0, out[1] mean and
   out[2] maximum relative edge elongation. */
TMASSDEF int tmass_tet_deformation(const tmass_model *m, int tet, tmass_real out[3]);
/* 1 if the tetrahedron is alive, 0 if removed, <0 on error. */
TMASSDEF int tmass_tet_alive(const tmass_model *m, int tet);
/* 1 if the node still belongs to a tetrahedron, 0 if inactive, <0 on error. */
TMASSDEF int tmass_node_active(const tmass_model *m, int i);
/* Boundary triangles of the live mesh, oriented outwards: 3 * *count node indices. The
   list is kept current by cutting; its order changes when triangles come and go. */
TMASSDEF const int *tmass_boundary_triangles(const tmass_model *m, int *count);

/* ---- diagnostics ---- */

/* Copies the vertex tensor K_ii (row-major 3x3, N/m) of node i. Tensor-mass model only. */
TMASSDEF int tmass_vertex_tensor(const tmass_model *m, int i, tmass_real out[9]);
/* Copies the edge tensor K_ab (force on a per displacement of b, row-major, N/m);
   TMASS_ERR_NO_EDGE if a and b share no live edge. Searches the edges: O(edges). */
TMASSDEF int tmass_edge_tensor(const tmass_model *m, int a, int b, tmass_real out[9]);
/* Bytes held by the model. */
TMASSDEF size_t tmass_memory_bytes(const tmass_model *m);

#endif /* TENSORMASS_H */

/* ======================================================================================
   IMPLEMENTATION
   ====================================================================================== */
#if defined(TENSORMASS_IMPLEMENTATION) && !defined(TENSORMASS_IMPLEMENTATION_ONCE)
#define TENSORMASS_IMPLEMENTATION_ONCE

/* With TMASS_STATIC the functions a program does not call are unused statics. */
#if defined(TMASS_STATIC) && defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#endif

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#ifndef TMASS_MALLOC
#include <stdlib.h>
#define TMASS_MALLOC(size, user) ((void)(user), malloc(size))
#define TMASS_FREE(ptr, user) ((void)(user), free(ptr))
#endif
#ifndef TMASS_ASSERT
#include <assert.h>
#define TMASS_ASSERT(x) assert(x)
#endif

#if defined(__cplusplus)
#define TMASS__RESTRICT __restrict
#else
#define TMASS__RESTRICT restrict
#endif

#if defined(__GNUC__)
#define TMASS__PREFETCH(p) __builtin_prefetch(p)
#else
#define TMASS__PREFETCH(p) ((void)0)
#endif

#define TMASS__COOKIE 0x544D4153u /* "TMAS" */
#define TMASS__ALIGN 64
#define TMASS__VEC_BLOCK 4096 /* reals per block of vector loops and dot partial sums */
#define TMASS__SCRATCH 10      /* 3n scratch vectors */

/* node states */
#define TMASS__FREE 0
#define TMASS__PINNED 1
#define TMASS__INACTIVE 2

struct tmass_model {
    int node_count, tet_count, edge_total, edge_count, live_tets;
    tmass_model_kind kind;
    tmass_integrator integrator;
    tmass_real time_step, mass_damping, stiffness_damping, gravity[3], cg_tolerance;
    int cg_max_iterations;
    int parallel;
    double density; /* kg/m^3, uniform */

    tmass_allocator allocator;
    tmass_parallel_for_fn parallel_for;
    void *parallel_user;
    void *block;
    size_t block_bytes;

    /* nodes */
    tmass_real *rest, *disp, *pos, *vel, *force, *ext;
    tmass_real *target; /* target displacement of pinned nodes, m */
    tmass_real *mass, *inv_mass;
    tmass_real *free_mask, *pin_mask; /* per degree of freedom (3n): 1 free / 1 pinned */
    tmass_real *vertex_tensor; /* 9n: K_ii, or the spring tangent diagonal during a solve */
    unsigned char *node_state;
    int *node_tets; /* live tetrahedra around each node */

    /* tetrahedra */
    int *tet_nodes;     /* 4T */
    int *tet_edges;     /* 6T edge ids, local pairs (0,1)(0,2)(0,3)(1,2)(1,3)(2,3) */
    int *tet_neighbors; /* 4T: tetrahedron across the face opposite local node f, or -1 */
    double *tet_lambda, *tet_mu, *tet_young;
    unsigned char *tet_alive;

    /* edges, by slot (the order the force loop streams them in) */
    int *edge_a, *edge_b, *edge_id;
    tmass_real *edge_tensor;      /* 9 per slot: K_ab (tensor), or the spring tangent */
    tmass_real *edge_rest_length; /* springs */
    tmass_real *edge_stiffness;   /* springs */
    /* edges, by id (ids never change) */
    int *edge_slot, *edge_tets;

    /* chunks of contiguous slots, listed colour by colour */
    int chunk_size, chunk_total, colour_count;
    int *chunk_start, *chunk_live, *chunk_of_orig, *colour_start;

    /* boundary triangles */
    int *tri, *tri_owner, *face_pos;
    int tri_count;

    /* scratch */
    tmass_real *scratch[TMASS__SCRATCH];
    tmass_real *dv_prev; /* implicit warm start */
    double *partials; /* 2 * partial_count block sums */
    int partial_count;
    int *tear_list;

    tmass_stats stats;
};

/* >>math ------------------------------------------------------------------------------ */

static int tmass__finite(double x) { return x == x && x - x == 0.0; }

static double tmass__dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Shape-function gradients g[4][3] and volume of a rest tetrahedron, in double. Returns
   6V (signed). */
static double tmass__shape_gradients(const tmass_real *p0, const tmass_real *p1,
                                     const tmass_real *p2, const tmass_real *p3, double g[4][3])
{
    double e1[3], e2[3], e3[3], c23[3], c31[3], c12[3], det;
    int k;
    for (k = 0; k < 3; k++) {
        e1[k] = (double)p1[k] - (double)p0[k];
        e2[k] = (double)p2[k] - (double)p0[k];
        e3[k] = (double)p3[k] - (double)p0[k];
    }
    c23[0] = e2[1] * e3[2] - e2[2] * e3[1];
    c23[1] = e2[2] * e3[0] - e2[0] * e3[2];
    c23[2] = e2[0] * e3[1] - e2[1] * e3[0];
    c31[0] = e3[1] * e1[2] - e3[2] * e1[1];
    c31[1] = e3[2] * e1[0] - e3[0] * e1[2];
    c31[2] = e3[0] * e1[1] - e3[1] * e1[0];
    c12[0] = e1[1] * e2[2] - e1[2] * e2[1];
    c12[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c12[2] = e1[0] * e2[1] - e1[1] * e2[0];
    det = tmass__dot3(e1, c23);
    if (det == 0.0) return 0.0;
    /* rows of the inverse edge matrix are the gradients of N1, N2, N3 */
    for (k = 0; k < 3; k++) {
        g[1][k] = c23[k] / det;
        g[2][k] = c31[k] / det;
        g[3][k] = c12[k] / det;
        g[0][k] = -(g[1][k] + g[2][k] + g[3][k]);
    }
    return det;
}

/* The 16 tensors K_jk (eq. 5) of one tetrahedron, row-major, and its volume. */
static double tmass__tet_tensors(const tmass_model *m, int t, double K[4][4][9])
{
    const int *q = m->tet_nodes + 4 * t;
    double g[4][3], six_v, v, lambda = m->tet_lambda[t], mu = m->tet_mu[t];
    int j, k, r, c;
    six_v = tmass__shape_gradients(m->rest + 3 * q[0], m->rest + 3 * q[1], m->rest + 3 * q[2],
                                   m->rest + 3 * q[3], g);
    v = six_v / 6.0;
    for (j = 0; j < 4; j++)
        for (k = 0; k < 4; k++) {
            double gjgk = tmass__dot3(g[j], g[k]);
            for (r = 0; r < 3; r++)
                for (c = 0; c < 3; c++)
                    K[j][k][3 * r + c] = v * (lambda * g[j][r] * g[k][c] + mu * g[k][r] * g[j][c] +
                                              (r == c ? mu * gjgk : 0.0));
        }
    return v;
}

static double tmass__rest_volume(const tmass_model *m, int t)
{
    const int *q = m->tet_nodes + 4 * t;
    double g[4][3];
    return tmass__shape_gradients(m->rest + 3 * q[0], m->rest + 3 * q[1], m->rest + 3 * q[2],
                                  m->rest + 3 * q[3], g) / 6.0;
}

static const int tmass__edge_local[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
/* face opposite local node f of a positive tetrahedron, wound outwards */
static const int tmass__face_local[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

/* >>parallel -------------------------------------------------------------------------- */

typedef void (*tmass__range_fn)(void *ctx, int begin, int end);

/* Runs fn over items [0, count); items are independent and fixed by the caller, so the
   result does not depend on how they are spread over threads. */
static void tmass__run(const tmass_model *m, int count, tmass__range_fn fn, void *ctx)
{
    if (count <= 0) return;
    if (count == 1 || !m->parallel) {
        fn(ctx, 0, count);
        return;
    }
    if (m->parallel_for) {
        m->parallel_for(count, fn, ctx, m->parallel_user);
        return;
    }
#ifdef _OPENMP
    {
        int i;
#pragma omp parallel for schedule(static)
        for (i = 0; i < count; i++) fn(ctx, i, i + 1);
    }
#else
    fn(ctx, 0, count);
#endif
}

/* >>memory ---------------------------------------------------------------------------- */

/* The desc's allocator, or TMASS_MALLOC with the block aligned to TMASS__ALIGN by hand
   (the pointer malloc returned is kept just before the aligned block). */
static void *tmass__alloc(const tmass_allocator *a, size_t size)
{
    char *raw, *p;
    if (a->alloc) return a->alloc(size, TMASS__ALIGN, a->user);
    raw = (char *)TMASS_MALLOC(size + TMASS__ALIGN + sizeof(void *), a->user);
    if (!raw) return NULL;
    p = raw + sizeof(void *);
    p += (TMASS__ALIGN - (size_t)p % TMASS__ALIGN) % TMASS__ALIGN;
    memcpy(p - sizeof(void *), &raw, sizeof(void *));
    return p;
}

static void tmass__free(const tmass_allocator *a, void *ptr, size_t size)
{
    void *raw;
    if (!ptr) return;
    if (a->free) {
        a->free(ptr, size, a->user);
        return;
    }
    memcpy(&raw, (char *)ptr - sizeof(void *), sizeof(void *));
    TMASS_FREE(raw, a->user);
}

/* Carves aligned arrays out of one block; with base NULL it only measures. */
typedef struct tmass__carver {
    char *base;
    size_t offset;
} tmass__carver;

static void *tmass__carve(tmass__carver *c, size_t bytes)
{
    void *p;
    c->offset = (c->offset + TMASS__ALIGN - 1) & ~(size_t)(TMASS__ALIGN - 1);
    p = c->base ? (void *)(c->base + c->offset) : NULL;
    c->offset += bytes ? bytes : 1;
    return p;
}

#define TMASS__CARVE(c, ptr, type, count) ((ptr) = (type *)tmass__carve((c), sizeof(type) * (size_t)(count)))

/* Lays out every array of the model in the block at c->base (or measures it). */
static void tmass__layout(tmass_model *m, tmass__carver *c)
{
    size_t n = (size_t)m->node_count, t = (size_t)m->tet_count, e = (size_t)m->edge_total;
    int s;
    TMASS__CARVE(c, m->rest, tmass_real, 3 * n);
    TMASS__CARVE(c, m->disp, tmass_real, 3 * n);
    TMASS__CARVE(c, m->pos, tmass_real, 3 * n);
    TMASS__CARVE(c, m->vel, tmass_real, 3 * n);
    TMASS__CARVE(c, m->force, tmass_real, 3 * n);
    TMASS__CARVE(c, m->ext, tmass_real, 3 * n);
    TMASS__CARVE(c, m->target, tmass_real, 3 * n);
    TMASS__CARVE(c, m->mass, tmass_real, n);
    TMASS__CARVE(c, m->inv_mass, tmass_real, n);
    TMASS__CARVE(c, m->free_mask, tmass_real, 3 * n);
    TMASS__CARVE(c, m->pin_mask, tmass_real, 3 * n);
    TMASS__CARVE(c, m->vertex_tensor, tmass_real, 9 * n);
    TMASS__CARVE(c, m->node_state, unsigned char, n);
    TMASS__CARVE(c, m->node_tets, int, n);
    TMASS__CARVE(c, m->tet_nodes, int, 4 * t);
    TMASS__CARVE(c, m->tet_edges, int, 6 * t);
    TMASS__CARVE(c, m->tet_neighbors, int, 4 * t);
    TMASS__CARVE(c, m->tet_lambda, double, t);
    TMASS__CARVE(c, m->tet_mu, double, t);
    TMASS__CARVE(c, m->tet_young, double, t);
    TMASS__CARVE(c, m->tet_alive, unsigned char, t);
    TMASS__CARVE(c, m->edge_a, int, e);
    TMASS__CARVE(c, m->edge_b, int, e);
    TMASS__CARVE(c, m->edge_id, int, e);
    TMASS__CARVE(c, m->edge_tensor, tmass_real, 9 * e);
    TMASS__CARVE(c, m->edge_rest_length, tmass_real, e);
    TMASS__CARVE(c, m->edge_stiffness, tmass_real, e);
    TMASS__CARVE(c, m->edge_slot, int, e);
    TMASS__CARVE(c, m->edge_tets, int, e);
    TMASS__CARVE(c, m->chunk_start, int, m->chunk_total);
    TMASS__CARVE(c, m->chunk_live, int, m->chunk_total);
    TMASS__CARVE(c, m->chunk_of_orig, int, m->chunk_total);
    TMASS__CARVE(c, m->colour_start, int, m->chunk_total + 1);
    TMASS__CARVE(c, m->tri, int, 12 * t);
    TMASS__CARVE(c, m->tri_owner, int, 4 * t);
    TMASS__CARVE(c, m->face_pos, int, 4 * t);
    for (s = 0; s < TMASS__SCRATCH; s++) TMASS__CARVE(c, m->scratch[s], tmass_real, 3 * n);
    TMASS__CARVE(c, m->dv_prev, tmass_real, 3 * n);
    TMASS__CARVE(c, m->partials, double, 2 * (size_t)m->partial_count);
    TMASS__CARVE(c, m->tear_list, int, t);
}

/* >>validation ------------------------------------------------------------------------ */

static int tmass__fail(const tmass_desc *d, int code, const char *detail)
{
    if (d && d->log) d->log(code, detail, d->log_user);
    return code;
}

static int tmass__validate_material(const tmass_desc *d, double E, double nu, int t, char *msg,
                                    size_t msg_size)
{
    if (!(tmass__finite(E) && E > 0.0)) {
        snprintf(msg, msg_size, "Young's modulus %g of tetrahedron %d", E, t);
        return TMASS_ERR_YOUNG_MODULUS;
    }
    if (d->kind == TMASS_TENSOR_MASS && !(tmass__finite(nu) && nu > -1.0 && nu < 0.5)) {
        snprintf(msg, msg_size, "Poisson ratio %g of tetrahedron %d", nu, t);
        return TMASS_ERR_POISSON_RATIO;
    }
    return TMASS_OK;
}

static int tmass__validate(const tmass_desc *d)
{
    char msg[160];
    int i, t, err;
    if (d->internal_cookie != TMASS__COOKIE)
        return tmass__fail(d, TMASS_ERR_DESC, "start from tmass_default_desc()");
    if (d->kind != TMASS_TENSOR_MASS && d->kind != TMASS_MASS_SPRING)
        return tmass__fail(d, TMASS_ERR_MODEL_KIND, "kind");
    if (d->node_count < 4 || d->node_count > 200000000 || !d->rest_positions)
        return tmass__fail(d, TMASS_ERR_NODE_COUNT, "node_count must be >= 4 with positions");
    if (d->tet_count < 1 || d->tet_count > 200000000 || !d->tets)
        return tmass__fail(d, TMASS_ERR_TET_COUNT, "tet_count must be >= 1 with indices");
    if (!(tmass__finite(d->density) && d->density > 0))
        return tmass__fail(d, TMASS_ERR_DENSITY, "density");
    if (!(tmass__finite(d->time_step) && d->time_step > 0))
        return tmass__fail(d, TMASS_ERR_TIME_STEP, "time_step");
    if (!(tmass__finite(d->mass_damping) && d->mass_damping >= 0) ||
        !(tmass__finite(d->stiffness_damping) && d->stiffness_damping >= 0))
        return tmass__fail(d, TMASS_ERR_DAMPING, "damping");
    if ((int)d->integrator < 0 || (int)d->integrator > 3)
        return tmass__fail(d, TMASS_ERR_INTEGRATOR, "integrator");
    if (!(tmass__finite(d->cg_tolerance) && d->cg_tolerance > 0) || d->cg_max_iterations < 1)
        return tmass__fail(d, TMASS_ERR_SOLVER, "cg_tolerance / cg_max_iterations");
    for (i = 0; i < 3; i++)
        if (!tmass__finite(d->gravity[i])) return tmass__fail(d, TMASS_ERR_ARG, "gravity");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return tmass__fail(d, TMASS_ERR_ARG, "allocator needs both alloc and free");
    for (i = 0; i < 3 * d->node_count; i++)
        if (!tmass__finite(d->rest_positions[i])) {
            snprintf(msg, sizeof msg, "rest position of node %d is not finite", i / 3);
            return tmass__fail(d, TMASS_ERR_NODE_NOT_FINITE, msg);
        }
    for (t = 0; t < d->tet_count; t++) {
        const int *q = d->tets + 4 * t;
        double E = d->tet_young_modulus ? (double)d->tet_young_modulus[t] : (double)d->young_modulus;
        double nu = d->tet_poisson_ratio ? (double)d->tet_poisson_ratio[t] : (double)d->poisson_ratio;
        double g[4][3], six_v, longest = 0.0;
        int a, b;
        for (a = 0; a < 4; a++) {
            if (q[a] < 0 || q[a] >= d->node_count) {
                snprintf(msg, sizeof msg, "tetrahedron %d: node index %d out of range", t, q[a]);
                return tmass__fail(d, TMASS_ERR_INDEX_RANGE, msg);
            }
            for (b = 0; b < a; b++)
                if (q[a] == q[b]) {
                    snprintf(msg, sizeof msg, "tetrahedron %d uses node %d twice", t, q[a]);
                    return tmass__fail(d, TMASS_ERR_INDEX_REPEATED, msg);
                }
        }
        err = tmass__validate_material(d, E, nu, t, msg, sizeof msg);
        if (err) return tmass__fail(d, err, msg);
        for (a = 0; a < 4; a++)
            for (b = a + 1; b < 4; b++) {
                const tmass_real *pa = d->rest_positions + 3 * q[a], *pb = d->rest_positions + 3 * q[b];
                double dx = (double)pa[0] - pb[0], dy = (double)pa[1] - pb[1], dz = (double)pa[2] - pb[2];
                double l2 = dx * dx + dy * dy + dz * dz;
                if (l2 > longest) longest = l2;
            }
        six_v = tmass__shape_gradients(d->rest_positions + 3 * q[0], d->rest_positions + 3 * q[1],
                                       d->rest_positions + 3 * q[2], d->rest_positions + 3 * q[3], g);
        /* a regular tetrahedron has 6V = l^3 / sqrt(2); flag slivers 1e8 times flatter */
        if (!(fabs(six_v) > 1e-8 * longest * sqrt(longest))) {
            snprintf(msg, sizeof msg, "tetrahedron %d is flat (6V = %g)", t, six_v);
            return tmass__fail(d, TMASS_ERR_TET_DEGENERATE, msg);
        }
        if (six_v < 0.0) {
            snprintf(msg, sizeof msg, "tetrahedron %d is negatively oriented", t);
            return tmass__fail(d, TMASS_ERR_TET_INVERTED, msg);
        }
    }
    return TMASS_OK;
}

/* >>precomputation -------------------------------------------------------------------- */

/* Bucket entries (key, payload) by their first vertex, then sort each small bucket by
   key with insertion sort: linear time for meshes of bounded vertex degree. */
static void tmass__bucket_sort(int *start, int n, int *key, int *payload)
{
    int v, i, j;
    for (v = 0; v < n; v++)
        for (i = start[v] + 1; i < start[v + 1]; i++) {
            int k = key[i], p = payload[i];
            for (j = i - 1; j >= start[v] && key[j] > k; j--) {
                key[j + 1] = key[j];
                payload[j + 1] = payload[j];
            }
            key[j + 1] = k;
            payload[j + 1] = p;
        }
}

/* Counts the distinct edges (temporary arrays supplied). Fills tet_edge_tmp[6T] with edge
   ids in (lower vertex, upper vertex) order and ea/eb when non-NULL. */
static int tmass__build_edges(const int *tets, int tet_count, int node_count, int *start,
                              int *key, int *payload, int *tet_edge_tmp, int *ea, int *eb)
{
    int t, l, v, i, count = 0;
    memset(start, 0, sizeof(int) * (size_t)(node_count + 1));
    for (t = 0; t < tet_count; t++)
        for (l = 0; l < 6; l++) {
            int a = tets[4 * t + tmass__edge_local[l][0]], b = tets[4 * t + tmass__edge_local[l][1]];
            start[(a < b ? a : b) + 1]++;
        }
    for (v = 0; v < node_count; v++) start[v + 1] += start[v];
    /* fill with start[] as moving cursors, then shift it back */
    for (t = 0; t < tet_count; t++)
        for (l = 0; l < 6; l++) {
            int a = tets[4 * t + tmass__edge_local[l][0]], b = tets[4 * t + tmass__edge_local[l][1]];
            int lo = a < b ? a : b, hi = a < b ? b : a;
            int slot = start[lo]++;
            key[slot] = hi;
            payload[slot] = 6 * t + l;
        }
    for (v = node_count; v > 0; v--) start[v] = start[v - 1];
    start[0] = 0;
    tmass__bucket_sort(start, node_count, key, payload);
    for (v = 0; v < node_count; v++)
        for (i = start[v]; i < start[v + 1]; i++) {
            if (i == start[v] || key[i] != key[i - 1]) {
                if (ea) {
                    ea[count] = v;
                    eb[count] = key[i];
                }
                count++;
            }
            tet_edge_tmp[payload[i]] = count - 1;
        }
    return count;
}

/* Face neighbours: returns TMASS_ERR_NONMANIFOLD if a face has more than two tets. */
static int tmass__build_neighbors(tmass_model *m, int *start, int *key, int *payload)
{
    int t, f, v, i, n = m->node_count, T = m->tet_count;
    const int *tets = m->tet_nodes;
    memset(start, 0, sizeof(int) * (size_t)(n + 1));
    for (i = 0; i < 4 * T; i++) m->tet_neighbors[i] = -1;
    /* key = mid * n + high would overflow int: sort by (mid, high) via two passes using
       the payload to look the face up again */
    for (t = 0; t < T; t++)
        for (f = 0; f < 4; f++) {
            int a = tets[4 * t + tmass__face_local[f][0]], b = tets[4 * t + tmass__face_local[f][1]],
                c = tets[4 * t + tmass__face_local[f][2]];
            int lo = a < b ? (a < c ? a : c) : (b < c ? b : c);
            start[lo + 1]++;
        }
    for (v = 0; v < n; v++) start[v + 1] += start[v];
    for (t = 0; t < T; t++)
        for (f = 0; f < 4; f++) {
            int a = tets[4 * t + tmass__face_local[f][0]], b = tets[4 * t + tmass__face_local[f][1]],
                c = tets[4 * t + tmass__face_local[f][2]], s;
            int lo, mid, hi;
            if (a > b) { s = a; a = b; b = s; }
            if (b > c) { s = b; b = c; c = s; }
            if (a > b) { s = a; a = b; b = s; }
            lo = a; mid = b; hi = c;
            s = start[lo]++;
            key[s] = mid;
            payload[s] = 4 * t + f;
            (void)hi;
        }
    for (v = n; v > 0; v--) start[v] = start[v - 1];
    start[0] = 0;
    tmass__bucket_sort(start, n, key, payload);
    /* within a run of equal (lo, mid), match equal highs by a quadratic scan: runs are
       as short as the number of faces around an edge */
    for (v = 0; v < n; v++) {
        for (i = start[v]; i < start[v + 1];) {
            int j = i, a, b;
            while (j < start[v + 1] && key[j] == key[i]) j++;
            for (a = i; a < j; a++) {
                int fa = payload[a], ta = fa / 4, ha = -1, q;
                int matches = 0;
                for (q = 0; q < 3; q++) {
                    int x = tets[4 * ta + tmass__face_local[fa % 4][q]];
                    if (x != v && x != key[a]) ha = x;
                }
                for (b = i; b < j; b++) {
                    int fb = payload[b], tb = fb / 4, hb = -1;
                    if (b == a) continue;
                    for (q = 0; q < 3; q++) {
                        int x = tets[4 * tb + tmass__face_local[fb % 4][q]];
                        if (x != v && x != key[b]) hb = x;
                    }
                    if (ha == hb) {
                        matches++;
                        m->tet_neighbors[fa] = tb;
                    }
                }
                if (matches > 1) return TMASS_ERR_NONMANIFOLD;
            }
            i = j;
        }
    }
    return TMASS_OK;
}

/* Greedy colouring of the edge chunks: a chunk joins the first colour none of whose
   chunks shares a vertex with it. stamp[n] is temporary. */
static void tmass__colour_chunks(tmass_model *m, int *stamp, int *colour_of)
{
    int c, colour = 0, done = 0, pos = 0, s, n = m->node_count, C = m->chunk_total;
    for (c = 0; c < C; c++) colour_of[c] = -1;
    for (s = 0; s < n; s++) stamp[s] = -1;
    while (done < C) {
        for (c = 0; c < C; c++) {
            int b = c * m->chunk_size, e = b + m->chunk_live[c], ok = 1;
            if (colour_of[c] >= 0) continue;
            for (s = b; s < e && ok; s++)
                if (stamp[m->edge_a[s]] == colour || stamp[m->edge_b[s]] == colour) ok = 0;
            if (!ok) continue;
            colour_of[c] = colour;
            done++;
            for (s = b; s < e; s++) stamp[m->edge_a[s]] = stamp[m->edge_b[s]] = colour;
        }
        colour++;
    }
    m->colour_count = colour;
    for (colour = 0; colour < m->colour_count; colour++) {
        m->colour_start[colour] = pos;
        for (c = 0; c < C; c++)
            if (colour_of[c] == colour) {
                m->chunk_of_orig[c] = pos;
                pos++;
            }
    }
    m->colour_start[m->colour_count] = pos;
    /* chunk_start/chunk_live are indexed by list position from now on */
    {
        int *live_orig = colour_of; /* reuse: copy live counts by original index */
        for (c = 0; c < C; c++) live_orig[c] = m->chunk_live[c];
        for (c = 0; c < C; c++) {
            m->chunk_start[m->chunk_of_orig[c]] = c * m->chunk_size;
            m->chunk_live[m->chunk_of_orig[c]] = live_orig[c];
        }
    }
}

static void tmass__set_masks(tmass_model *m, int i, int is_free, int is_pinned)
{
    int r;
    for (r = 0; r < 3; r++) {
        m->free_mask[3 * i + r] = (tmass_real)is_free;
        m->pin_mask[3 * i + r] = (tmass_real)is_pinned;
    }
}

static void tmass__add_tensor(tmass_real *dst, const double *src, double sign)
{
    int k;
    for (k = 0; k < 9; k++) dst[k] = (tmass_real)((double)dst[k] + sign * src[k]);
}

/* Adds (sign +1) or subtracts (-1) the contribution of tetrahedron t: tensors, spring
   stiffnesses and lumped masses. The ten tensor updates of sec. 5.5. */
static void tmass__apply_tet(tmass_model *m, int t, double sign)
{
    double K[4][4][9], v;
    const int *q = m->tet_nodes + 4 * t;
    int j, l;
    v = m->kind == TMASS_TENSOR_MASS ? tmass__tet_tensors(m, t, K) : tmass__rest_volume(m, t);
    for (j = 0; j < 4; j++) {
        m->mass[q[j]] = (tmass_real)((double)m->mass[q[j]] + sign * m->density * v / 4.0);
        if (m->kind == TMASS_TENSOR_MASS) tmass__add_tensor(m->vertex_tensor + 9 * q[j], K[j][j], sign);
    }
    for (l = 0; l < 6; l++) {
        int j0 = tmass__edge_local[l][0], j1 = tmass__edge_local[l][1];
        int slot = m->edge_slot[m->tet_edges[6 * t + l]];
        if (m->kind == TMASS_TENSOR_MASS) {
            /* the slot stores K_ab with a < b */
            if (q[j0] < q[j1])
                tmass__add_tensor(m->edge_tensor + 9 * slot, K[j0][j1], sign);
            else
                tmass__add_tensor(m->edge_tensor + 9 * slot, K[j1][j0], sign);
        } else {
            double l0 = m->edge_rest_length[slot];
            m->edge_stiffness[slot] =
                (tmass_real)((double)m->edge_stiffness[slot] + sign * m->tet_young[t] * v / (l0 * l0));
        }
    }
}

/* >>creation -------------------------------------------------------------------------- */

TMASSDEF const char *tmass_version(void) { return "0.1.0"; }

TMASSDEF const char *tmass_error_string(int code)
{
    switch (code) {
#define TMASS__CASE(name, value, text) \
    case name: return text;
        TMASS_ERROR_LIST(TMASS__CASE)
#undef TMASS__CASE
    default: return "unknown error code";
    }
}

TMASSDEF tmass_desc tmass_default_desc(void)
{
    tmass_desc d;
    memset(&d, 0, sizeof d);
    d.kind = TMASS_TENSOR_MASS;
    d.young_modulus = (tmass_real)1e4;
    d.poisson_ratio = (tmass_real)0.3;
    d.density = (tmass_real)1000;
    d.gravity[2] = (tmass_real)-9.81;
    d.time_step = (tmass_real)1e-3;
    d.integrator = TMASS_IMPLICIT_EULER;
    d.cg_tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-5 : 1e-6);
    d.cg_max_iterations = 2000;
    d.internal_cookie = TMASS__COOKIE;
    return d;
}

static void tmass__init_boundary(tmass_model *m)
{
    int t, f;
    m->tri_count = 0;
    for (t = 0; t < m->tet_count; t++)
        for (f = 0; f < 4; f++) {
            int id = 4 * t + f;
            m->face_pos[id] = -1;
            if (m->tet_neighbors[id] < 0) {
                int k;
                for (k = 0; k < 3; k++)
                    m->tri[3 * m->tri_count + k] = m->tet_nodes[4 * t + tmass__face_local[f][k]];
                m->tri_owner[m->tri_count] = id;
                m->face_pos[id] = m->tri_count++;
            }
        }
}

TMASSDEF int tmass_create(const tmass_desc *d, tmass_model **out)
{
    tmass_model tmp, *m;
    tmass__carver carver;
    int err, i, t, n, T, E;
    int *start = NULL, *key = NULL, *payload = NULL, *tet_edge_tmp = NULL;
    size_t tmp_bytes;
    char *tmp_block = NULL;
    tmass_allocator alloc;

    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (!d) return TMASS_ERR_ARG;
    err = tmass__validate(d);
    if (err) return err;

    n = d->node_count;
    T = d->tet_count;
    alloc = d->allocator;

    /* temporary arrays for edge and face tables: start[n+1], key[6T], payload[6T],
       tet_edge_tmp[6T] */
    tmp_bytes = sizeof(int) * ((size_t)n + 1 + 18 * (size_t)T);
    tmp_block = (char *)tmass__alloc(&alloc, tmp_bytes);
    if (!tmp_block) return tmass__fail(d, TMASS_ERR_ALLOC, "temporary tables");
    start = (int *)tmp_block;
    key = start + n + 1;
    payload = key + 6 * (size_t)T;
    tet_edge_tmp = payload + 6 * (size_t)T;
    E = tmass__build_edges(d->tets, T, n, start, key, payload, tet_edge_tmp, NULL, NULL);

    memset(&tmp, 0, sizeof tmp);
    tmp.node_count = n;
    tmp.tet_count = T;
    tmp.edge_total = E;
    tmp.chunk_size = E / 32;
    if (tmp.chunk_size < 256) tmp.chunk_size = 256;
    if (tmp.chunk_size > 4096) tmp.chunk_size = 4096;
    tmp.chunk_total = (E + tmp.chunk_size - 1) / tmp.chunk_size;
    tmp.partial_count = (3 * n + TMASS__VEC_BLOCK - 1) / TMASS__VEC_BLOCK;
    carver.base = NULL;
    carver.offset = sizeof(tmass_model);
    tmass__layout(&tmp, &carver);
    tmp.block_bytes = carver.offset;
    tmp.block = tmass__alloc(&alloc, tmp.block_bytes);
    if (!tmp.block) {
        tmass__free(&alloc, tmp_block, tmp_bytes);
        return tmass__fail(d, TMASS_ERR_ALLOC, "model block");
    }
    memset(tmp.block, 0, tmp.block_bytes);
    carver.base = (char *)tmp.block;
    carver.offset = sizeof(tmass_model);
    tmass__layout(&tmp, &carver);
    m = (tmass_model *)tmp.block;
    *m = tmp;

    m->kind = d->kind;
    m->integrator = d->integrator;
    m->time_step = d->time_step;
    m->mass_damping = d->mass_damping;
    m->stiffness_damping = d->stiffness_damping;
    for (i = 0; i < 3; i++) m->gravity[i] = d->gravity[i];
    m->cg_tolerance = d->cg_tolerance;
    m->cg_max_iterations = d->cg_max_iterations;
    m->density = (double)d->density;
    m->allocator = alloc;
    m->parallel_for = d->parallel_for;
    m->parallel_user = d->parallel_user;
    m->parallel = E >= TMASS_PARALLEL_MIN_EDGES;

    memcpy(m->rest, d->rest_positions, sizeof(tmass_real) * 3 * (size_t)n);
    memcpy(m->pos, d->rest_positions, sizeof(tmass_real) * 3 * (size_t)n);
    memcpy(m->tet_nodes, d->tets, sizeof(int) * 4 * (size_t)T);
    E = tmass__build_edges(d->tets, T, n, start, key, payload, m->tet_edges, m->edge_a, m->edge_b);
    m->edge_count = E;
    for (i = 0; i < E; i++) {
        m->edge_id[i] = i;
        m->edge_slot[i] = i;
    }
    for (t = 0; t < T; t++) {
        double E_t = d->tet_young_modulus ? (double)d->tet_young_modulus[t] : (double)d->young_modulus;
        double nu = d->tet_poisson_ratio ? (double)d->tet_poisson_ratio[t] : (double)d->poisson_ratio;
        int l;
        m->tet_young[t] = E_t;
        if (d->kind == TMASS_TENSOR_MASS) {
            m->tet_lambda[t] = E_t * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
            m->tet_mu[t] = E_t / (2.0 * (1.0 + nu));
        }
        m->tet_alive[t] = 1;
        for (l = 0; l < 4; l++) m->node_tets[m->tet_nodes[4 * t + l]]++;
        for (l = 0; l < 6; l++) m->edge_tets[m->tet_edges[6 * t + l]]++;
    }
    m->live_tets = T;
    for (i = 0; i < E; i++) {
        const tmass_real *pa = m->rest + 3 * m->edge_a[i], *pb = m->rest + 3 * m->edge_b[i];
        double dx = (double)pb[0] - pa[0], dy = (double)pb[1] - pa[1], dz = (double)pb[2] - pa[2];
        m->edge_rest_length[i] = (tmass_real)sqrt(dx * dx + dy * dy + dz * dz);
    }
    for (t = 0; t < T; t++) tmass__apply_tet(m, t, 1.0);
    for (i = 0; i < n; i++) {
        m->node_state[i] = m->node_tets[i] > 0 ? TMASS__FREE : TMASS__INACTIVE;
        m->inv_mass[i] = m->mass[i] > 0 ? (tmass_real)(1.0 / (double)m->mass[i]) : (tmass_real)0;
        tmass__set_masks(m, i, m->node_state[i] == TMASS__FREE, 0);
    }
    for (i = 0; i < m->chunk_total; i++) {
        int b = i * m->chunk_size, e = b + m->chunk_size;
        m->chunk_live[i] = (e > E ? E : e) - b;
    }
    tmass__colour_chunks(m, start, key);
    err = tmass__build_neighbors(m, start, key, payload);
    tmass__free(&alloc, tmp_block, tmp_bytes);
    if (err) {
        tmass__free(&alloc, m->block, m->block_bytes);
        return tmass__fail(d, err, "a triangle is shared by three or more tetrahedra");
    }
    tmass__init_boundary(m);
    m->stats.newton_iterations = 1;
    *out = m;
    return TMASS_OK;
}

TMASSDEF void tmass_destroy(tmass_model *m)
{
    tmass_allocator a;
    if (!m) return;
    a = m->allocator;
    tmass__free(&a, m->block, m->block_bytes);
}

/* >>forces ---------------------------------------------------------------------------- */

/* out = K p over the edge tensors alone, in difference form:
       (K p)_a = sum_b K_ab (p_b - p_a),
   equal to eq. 6's K_aa p_a + sum_b K_ab p_b because every tetrahedron's tensors satisfy
   K_jj = -sum_{k != j} K_jk (a rigid translation creates no force). It needs no vertex
   pass, is exactly translation invariant, and keeps precision for smooth fields where
   the two terms of eq. 6 cancel (which matters in float). Used for the elastic force
   (p = u) and for the K products of CG; during implicit spring steps the same arrays hold
   the spring tangent. Chunks run colour by colour. */
typedef struct tmass__matvec_ctx {
    const tmass_model *m;
    const tmass_real *p;
    tmass_real *out;
    int colour;
} tmass__matvec_ctx;

static void tmass__matvec_chunks(void *vctx, int begin, int end)
{
    const tmass__matvec_ctx *c = (const tmass__matvec_ctx *)vctx;
    const tmass_model *m = c->m;
    const int *TMASS__RESTRICT ea = m->edge_a;
    const int *TMASS__RESTRICT eb = m->edge_b;
    const tmass_real *TMASS__RESTRICT T = m->edge_tensor;
    const tmass_real *TMASS__RESTRICT p = c->p;
    tmass_real *TMASS__RESTRICT out = c->out;
    int k;
    for (k = m->colour_start[c->colour] + begin; k < m->colour_start[c->colour] + end; k++) {
        int s = m->chunk_start[k], s1 = s + m->chunk_live[k];
        /* Edges come sorted by their lower vertex a: sum a run of equal a in registers
           (f_a += K_ab d) and write it once; f_b -= K_ab^T d goes straight out. */
        while (s < s1) {
            int a = ea[s];
            tmass_real a0 = p[3 * a], a1 = p[3 * a + 1], a2 = p[3 * a + 2];
            tmass_real f0 = 0, f1 = 0, f2 = 0;
            do {
                const tmass_real *K = T + 9 * s, *pb = p + 3 * eb[s];
                tmass_real *ob = out + 3 * eb[s];
                tmass_real d0 = pb[0] - a0, d1 = pb[1] - a1, d2 = pb[2] - a2;
                TMASS__PREFETCH(K + 9 * 24); /* the tensor stream, a few lines ahead */
                f0 += K[0] * d0 + K[1] * d1 + K[2] * d2;
                f1 += K[3] * d0 + K[4] * d1 + K[5] * d2;
                f2 += K[6] * d0 + K[7] * d1 + K[8] * d2;
                ob[0] -= K[0] * d0 + K[3] * d1 + K[6] * d2;
                ob[1] -= K[1] * d0 + K[4] * d1 + K[7] * d2;
                ob[2] -= K[2] * d0 + K[5] * d1 + K[8] * d2;
                s++;
            } while (s < s1 && ea[s] == a);
            out[3 * a] += f0;
            out[3 * a + 1] += f1;
            out[3 * a + 2] += f2;
        }
    }
}

static void tmass__matvec(const tmass_model *m, const tmass_real *p, tmass_real *out)
{
    tmass__matvec_ctx c;
    c.m = m;
    c.p = p;
    c.out = out;
    memset(out, 0, sizeof(tmass_real) * 3 * (size_t)m->node_count);
    for (c.colour = 0; c.colour < m->colour_count; c.colour++)
        tmass__run(m, m->colour_start[c.colour + 1] - m->colour_start[c.colour],
                   tmass__matvec_chunks, &c);
}

/* Spring forces (eq. 7) with axial damping, into out (overwritten):
       f = k (l - l0) + c ((v_b - v_a) . d),  out_a += f d,  out_b -= f d,
   d the unit vector from a to b and c = stiffness_damping * k. When tangent_kx > 0 it
   also writes the tangent S_e = kx K_e + kv c d d^T into the edge tensors (as the
   off-diagonal block -S_e) and vertex tensors (sum of S_e), where
       K_e = k [ max(0, 1 - l0/l) (I - d d^T) + d d^T ]
   is minus the force Jacobian with its compressive geometric part clamped (positive
   semi-definite), and, when kv_out is given, kv_out = K(x) v_kv. */
typedef struct tmass__spring_ctx {
    tmass_model *m;
    const tmass_real *u, *v, *v_kv; /* displacement, velocity, vector for kv_out */
    tmass_real *out, *kv_out;
    int colour;
    double kx, kv;
} tmass__spring_ctx;

static void tmass__spring_edge(tmass__spring_ctx *c, int s)
{
    tmass_model *m = c->m;
    int a = m->edge_a[s], b = m->edge_b[s], r, q;
    tmass_real d[3], l, f, k = m->edge_stiffness[s], kd = m->stiffness_damping * k;
    for (r = 0; r < 3; r++) /* x_b - x_a from rest and displacement differences */
        d[r] = (m->rest[3 * b + r] - m->rest[3 * a + r]) + (c->u[3 * b + r] - c->u[3 * a + r]);
    l = (tmass_real)sqrt((double)(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    if (l > 0)
        for (r = 0; r < 3; r++) d[r] /= l;
    f = k * (l - m->edge_rest_length[s]);
    if (c->v && kd != 0) {
        const tmass_real *va = c->v + 3 * a, *vb = c->v + 3 * b;
        f += kd * ((vb[0] - va[0]) * d[0] + (vb[1] - va[1]) * d[1] + (vb[2] - va[2]) * d[2]);
    }
    for (r = 0; r < 3; r++) {
        c->out[3 * a + r] += f * d[r];
        c->out[3 * b + r] -= f * d[r];
    }
    if (c->kx > 0) {
        tmass_real geo = l > 0 ? 1 - m->edge_rest_length[s] / l : 0, dv[3] = {0, 0, 0};
        tmass_real *T = m->edge_tensor + 9 * s;
        if (geo < 0) geo = 0;
        if (c->kv_out)
            for (r = 0; r < 3; r++) dv[r] = c->v_kv[3 * a + r] - c->v_kv[3 * b + r];
        for (r = 0; r < 3; r++)
            for (q = 0; q < 3; q++) {
                tmass_real ddt = d[r] * d[q];
                tmass_real ke = k * (geo * ((tmass_real)(r == q) - ddt) + ddt);
                tmass_real S = (tmass_real)(c->kx * ke + c->kv * kd * ddt);
                T[3 * r + q] = -S;
                m->vertex_tensor[9 * a + 3 * r + q] += S;
                m->vertex_tensor[9 * b + 3 * r + q] += S;
                if (c->kv_out) {
                    c->kv_out[3 * a + r] += ke * dv[q];
                    c->kv_out[3 * b + r] -= ke * dv[q];
                }
            }
    }
}

static void tmass__spring_chunks(void *vctx, int begin, int end)
{
    tmass__spring_ctx *c = (tmass__spring_ctx *)vctx;
    const tmass_model *m = c->m;
    int k, s;
    for (k = m->colour_start[c->colour] + begin; k < m->colour_start[c->colour] + end; k++)
        for (s = m->chunk_start[k]; s < m->chunk_start[k] + m->chunk_live[k]; s++)
            tmass__spring_edge(c, s);
}

static void tmass__spring_forces(tmass_model *m, const tmass_real *u, const tmass_real *v,
                                 tmass_real *out, double tangent_kx, double tangent_kv,
                                 const tmass_real *v_kv, tmass_real *kv_out)
{
    tmass__spring_ctx c;
    size_t n3 = 3 * (size_t)m->node_count;
    c.m = m;
    c.u = u;
    c.v = v;
    c.v_kv = v_kv;
    c.out = out;
    c.kv_out = kv_out;
    c.kx = tangent_kx;
    c.kv = tangent_kv;
    memset(out, 0, sizeof(tmass_real) * n3);
    if (kv_out) memset(kv_out, 0, sizeof(tmass_real) * n3);
    if (tangent_kx > 0) memset(m->vertex_tensor, 0, sizeof(tmass_real) * 3 * n3);
    for (c.colour = 0; c.colour < m->colour_count; c.colour++)
        tmass__run(m, m->colour_start[c.colour + 1] - m->colour_start[c.colour],
                   tmass__spring_chunks, &c);
    m->stats.force_evaluations++;
}

/* Elastic force plus stiffness damping at displacement u and velocity v into out (v may
   be NULL):
   tensor:  out = -K (u + beta v)   (w is scratch)
   springs: out = eq. 7 plus axial damping. */
static void tmass__internal_force(tmass_model *m, const tmass_real *u, const tmass_real *v,
                                  tmass_real *out, tmass_real *w)
{
    int i, n3 = 3 * m->node_count;
    if (m->kind == TMASS_MASS_SPRING) {
        tmass__spring_forces(m, u, v, out, 0.0, 0.0, NULL, NULL);
        return;
    }
    if (v && m->stiffness_damping != 0) {
        tmass_real beta = m->stiffness_damping;
        for (i = 0; i < n3; i++) w[i] = u[i] + beta * v[i];
        tmass__matvec(m, w, out);
    } else {
        tmass__matvec(m, u, out);
    }
    for (i = 0; i < n3; i++) out[i] = -out[i];
    m->stats.force_evaluations++;
}

/* Acceleration of the free nodes (zero elsewhere):
   a = (f_int(x, v) + f_ext) / m + g - alpha v. */
static void tmass__acceleration(tmass_model *m, const tmass_real *x, const tmass_real *v,
                                tmass_real *a, tmass_real *w)
{
    int i, r, n = m->node_count;
    tmass_real alpha = m->mass_damping;
    tmass__internal_force(m, x, v, a, w);
    for (i = 0; i < n; i++) {
        tmass_real im = m->inv_mass[i], fm = m->free_mask[3 * i];
        for (r = 0; r < 3; r++)
            a[3 * i + r] = fm * ((a[3 * i + r] + m->ext[3 * i + r]) * im + m->gravity[r] -
                                 alpha * v[3 * i + r]);
    }
}

/* >>solver ---------------------------------------------------------------------------- */

/* Conjugate gradient on (D + c K) x = b over the free degrees of freedom, D a diagonal
   (per degree of freedom, kg) or none. The vector work runs in fixed blocks of
   TMASS__VEC_BLOCK reals; each block writes its partial sums (four interleaved
   accumulators), which are added in block order: deterministic for any thread count. */
typedef struct tmass__cg_ctx {
    const tmass_model *m;
    tmass_real *x, *r, *z, *p, *q;
    const tmass_real *pinv, *diag;
    double c, alpha, beta;
    int n3;
} tmass__cg_ctx;

static void tmass__block_range(const tmass__cg_ctx *k, int blk, int *i0, int *i1)
{
    *i0 = blk * TMASS__VEC_BLOCK;
    *i1 = *i0 + TMASS__VEC_BLOCK;
    if (*i1 > k->n3) *i1 = k->n3;
}

/* q = mask (D p + c q) (q holds K p on entry); partial p . q */
static void tmass__cg_apply(void *vctx, int begin, int end)
{
    tmass__cg_ctx *k = (tmass__cg_ctx *)vctx;
    const tmass_real *TMASS__RESTRICT mask = k->m->free_mask;
    const tmass_real *TMASS__RESTRICT p = k->p;
    tmass_real *TMASS__RESTRICT q = k->q;
    tmass_real c = (tmass_real)k->c;
    int blk, i, i0, i1;
    for (blk = begin; blk < end; blk++) {
        double s[4] = {0, 0, 0, 0};
        tmass__block_range(k, blk, &i0, &i1);
        for (i = i0; i < i1; i++) {
            tmass_real d = k->diag ? k->diag[i] * p[i] : 0;
            q[i] = mask[i] * (d + c * q[i]);
            s[i & 3] += (double)p[i] * (double)q[i];
        }
        k->m->partials[blk] = (s[0] + s[1]) + (s[2] + s[3]);
    }
}

/* x += alpha p, r -= alpha q, z = P^-1 r; partials r . r and r . z */
static void tmass__cg_update(void *vctx, int begin, int end)
{
    tmass__cg_ctx *k = (tmass__cg_ctx *)vctx;
    const tmass_real *TMASS__RESTRICT pinv = k->pinv;
    const tmass_real *TMASS__RESTRICT p = k->p;
    const tmass_real *TMASS__RESTRICT q = k->q;
    tmass_real *TMASS__RESTRICT x = k->x;
    tmass_real *TMASS__RESTRICT r = k->r;
    tmass_real *TMASS__RESTRICT z = k->z;
    tmass_real alpha = (tmass_real)k->alpha;
    int blk, i, i0, i1, parts = k->m->partial_count;
    for (blk = begin; blk < end; blk++) {
        double rr[4] = {0, 0, 0, 0}, rz[4] = {0, 0, 0, 0};
        tmass__block_range(k, blk, &i0, &i1);
        for (i = i0; i < i1; i++) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
            z[i] = pinv[i] * r[i];
            rr[i & 3] += (double)r[i] * (double)r[i];
            rz[i & 3] += (double)r[i] * (double)z[i];
        }
        k->m->partials[blk] = (rr[0] + rr[1]) + (rr[2] + rr[3]);
        k->m->partials[parts + blk] = (rz[0] + rz[1]) + (rz[2] + rz[3]);
    }
}

/* p = z + beta p */
static void tmass__cg_direction(void *vctx, int begin, int end)
{
    tmass__cg_ctx *k = (tmass__cg_ctx *)vctx;
    const tmass_real *TMASS__RESTRICT z = k->z;
    tmass_real *TMASS__RESTRICT p = k->p;
    tmass_real beta = (tmass_real)k->beta;
    int blk, i, i0, i1;
    for (blk = begin; blk < end; blk++) {
        tmass__block_range(k, blk, &i0, &i1);
        for (i = i0; i < i1; i++) p[i] = z[i] + beta * p[i];
    }
}

static double tmass__sum_partials(const tmass_model *m, int offset)
{
    double s = 0.0;
    int blk;
    for (blk = 0; blk < m->partial_count; blk++) s += m->partials[offset + blk];
    return s;
}

/* Solves (D + c K) x = b on the free degrees of freedom by Jacobi-preconditioned CG
   (diag: D per degree of freedom, or NULL). x holds the initial guess; pinned and
   inactive entries are held at 0. Stops when |r| <= cg_tolerance |b| or after
   cg_max_iterations. Scratch s[0..4]. Returns TMASS_OK or TMASS_ERR_NO_CONVERGENCE. */
static int tmass__cg(tmass_model *m, const tmass_real *diag, double c, const tmass_real *b,
                     tmass_real *x, tmass_real **s)
{
    tmass__cg_ctx k;
    int n3 = 3 * m->node_count, i, it, blocks = m->partial_count;
    tmass_real *pinv = s[4];
    double bb = 0.0, rr, rz, tol2;
    k.m = m;
    k.r = s[0];
    k.z = s[1];
    k.p = s[2];
    k.q = s[3];
    k.x = x;
    k.pinv = pinv;
    k.diag = diag;
    k.c = c;
    k.n3 = n3;
    for (i = 0; i < n3; i++) {
        double dgl = (diag ? (double)diag[i] : 0.0) + c * (double)m->vertex_tensor[9 * (i / 3) + 4 * (i % 3)];
        pinv[i] = (tmass_real)(m->free_mask[i] > 0 && dgl > 0 ? 1.0 / dgl : 0.0);
        x[i] *= m->free_mask[i];
        bb += (double)b[i] * b[i] * m->free_mask[i];
    }
    m->stats.cg_iterations = 0;
    m->stats.cg_residual = 0;
    if (bb == 0.0) {
        memset(x, 0, sizeof(tmass_real) * (size_t)n3);
        return TMASS_OK;
    }
    tol2 = (double)m->cg_tolerance * (double)m->cg_tolerance * bb;
    /* r = b - A x, z = P^-1 r, p = z (once per solve: a plain serial loop) */
    tmass__matvec(m, x, k.q);
    rr = rz = 0.0;
    for (i = 0; i < n3; i++) {
        double ax = (diag ? (double)diag[i] * x[i] : 0.0) + c * (double)k.q[i];
        k.r[i] = (tmass_real)(((double)b[i] - ax) * m->free_mask[i]);
        k.z[i] = pinv[i] * k.r[i];
        k.p[i] = k.z[i];
        rr += (double)k.r[i] * k.r[i];
        rz += (double)k.r[i] * k.z[i];
    }
    for (it = 0; it < m->cg_max_iterations && rr > tol2; it++) {
        double pq, rz_new;
        tmass__matvec(m, k.p, k.q);
        tmass__run(m, blocks, tmass__cg_apply, &k);
        pq = tmass__sum_partials(m, 0);
        if (!(pq > 0.0)) break; /* not positive definite along p: singular problem */
        k.alpha = rz / pq;
        tmass__run(m, blocks, tmass__cg_update, &k);
        rr = tmass__sum_partials(m, 0);
        rz_new = tmass__sum_partials(m, blocks);
        k.beta = rz_new / rz;
        rz = rz_new;
        tmass__run(m, blocks, tmass__cg_direction, &k);
    }
    m->stats.cg_iterations = it;
    m->stats.cg_residual = (tmass_real)sqrt(rr / bb);
    m->stats.force_evaluations += it + 1;
    return rr <= tol2 ? TMASS_OK : TMASS_ERR_NO_CONVERGENCE;
}

/* >>integrators ----------------------------------------------------------------------- */

static int tmass__all_finite(const tmass_real *a, int count)
{
    int i, ok = 1;
    for (i = 0; i < count; i++) ok &= tmass__finite((double)a[i]);
    return ok;
}

/* Working copies (u0, v0) of the state (displacements and velocities) with pinned nodes
   moved to their targets over this step: v = (target - u) / dt, u = target. */
static void tmass__begin_step(tmass_model *m, tmass_real dt, tmass_real *u0, tmass_real *v0)
{
    int i, n3 = 3 * m->node_count;
    tmass_real inv_dt = 1 / dt;
    for (i = 0; i < n3; i++) {
        tmass_real pin = m->pin_mask[i];
        tmass_real jump = m->target[i] - m->disp[i];
        u0[i] = m->disp[i] + pin * jump;
        v0[i] = (1 - pin) * m->vel[i] + pin * jump * inv_dt;
    }
}

/* Commits displacements u and velocities v and refreshes the positions. */
static void tmass__commit(tmass_model *m, const tmass_real *u, const tmass_real *v)
{
    int i, n3 = 3 * m->node_count;
    memcpy(m->disp, u, sizeof(tmass_real) * (size_t)n3);
    if (v) memcpy(m->vel, v, sizeof(tmass_real) * (size_t)n3);
    else memset(m->vel, 0, sizeof(tmass_real) * (size_t)n3);
    for (i = 0; i < n3; i++) m->pos[i] = m->rest[i] + u[i];
}

static void tmass__explicit_euler(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                  const tmass_real *v0, tmass_real *x1, tmass_real *v1)
{
    int i, n3 = 3 * m->node_count;
    tmass_real *a = m->scratch[4];
    tmass__acceleration(m, x0, v0, a, m->scratch[5]);
    for (i = 0; i < n3; i++) {
        x1[i] = x0[i] + dt * v0[i] * m->free_mask[i];
        v1[i] = v0[i] + dt * a[i];
    }
}

static void tmass__semi_implicit_euler(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                       const tmass_real *v0, tmass_real *x1, tmass_real *v1)
{
    int i, n3 = 3 * m->node_count;
    tmass_real *a = m->scratch[4];
    tmass__acceleration(m, x0, v0, a, m->scratch[5]);
    for (i = 0; i < n3; i++) {
        v1[i] = v0[i] + dt * a[i];
        x1[i] = x0[i] + dt * v1[i] * m->free_mask[i];
    }
}

static void tmass__rk4(tmass_model *m, tmass_real dt, const tmass_real *x0, const tmass_real *v0,
                       tmass_real *x1, tmass_real *v1)
{
    /* k1 = f(y0), k2 = f(y0 + dt/2 k1), k3 = f(y0 + dt/2 k2), k4 = f(y0 + dt k3),
       y1 = y0 + dt/6 (k1 + 2 k2 + 2 k3 + k4); y = (x, v), f(y) = (v, a(x, v)).
       x1, v1 accumulate; (xs, vs) is the stage state, a its acceleration. */
    int i, stage, n3 = 3 * m->node_count;
    tmass_real *xs = m->scratch[4], *vs = m->scratch[5], *a = m->scratch[6], *w = m->scratch[7];
    static const double weight[4] = {1.0, 2.0, 2.0, 1.0};
    static const double next[4] = {0.5, 0.5, 1.0, 0.0};
    memcpy(xs, x0, sizeof(tmass_real) * (size_t)n3);
    memcpy(vs, v0, sizeof(tmass_real) * (size_t)n3);
    memcpy(x1, x0, sizeof(tmass_real) * (size_t)n3);
    memcpy(v1, v0, sizeof(tmass_real) * (size_t)n3);
    for (stage = 0; stage < 4; stage++) {
        tmass_real h = (tmass_real)(dt * weight[stage] / 6.0), hn = (tmass_real)(dt * next[stage]);
        tmass__acceleration(m, xs, vs, a, w);
        for (i = 0; i < n3; i++) {
            tmass_real fm = m->free_mask[i], dx = vs[i] * fm;
            x1[i] += h * dx;
            v1[i] += h * a[i];
            xs[i] = x0[i] + hn * dx;
            vs[i] = v0[i] + hn * a[i];
        }
    }
}

/* Backward Euler, linearised once (exact for the linear tensor model):
       (M (1 + dt alpha) + dt^2 K + dt D) dv = dt (f(x0, v0) - dt K v0 + f_ext + M g
                                                  - alpha M v0),
   x1 = x0 + dt (v0 + dv), where D = beta K (tensor) or the axial spring damping. The
   real-time step accepts the CG iterate when the iteration cap is reached (the stats
   say so). */
static int tmass__implicit_euler(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                 const tmass_real *v0, tmass_real *x1, tmass_real *v1)
{
    int i, r, n = m->node_count, n3 = 3 * n;
    tmass_real *f = m->scratch[4], *dmass = m->scratch[5], *dv = m->scratch[6], *w = m->scratch[7];
    tmass_real *cg_scratch[5];
    tmass_real alpha = m->mass_damping;
    double c;
    /* x1, v1 and w are free while CG runs: lend them to it */
    cg_scratch[0] = m->scratch[8];
    cg_scratch[1] = m->scratch[9];
    cg_scratch[2] = x1;
    cg_scratch[3] = v1;
    cg_scratch[4] = w;
    for (i = 0; i < n3; i++) dmass[i] = (tmass_real)((1.0 + (double)dt * alpha) * (double)m->mass[i / 3]);
    if (m->kind == TMASS_TENSOR_MASS) {
        /* f(x0, v0) - dt K v0 = -K (u0 + (beta + dt) v0) */
        tmass_real k = m->stiffness_damping + dt;
        for (i = 0; i < n3; i++) w[i] = x0[i] + k * v0[i];
        tmass__matvec(m, w, f);
        for (i = 0; i < n3; i++) f[i] = -f[i];
        m->stats.force_evaluations++;
        c = (double)dt * dt + (double)dt * m->stiffness_damping;
    } else {
        /* spring force, tangent S = dt^2 K + dt D into the tensors (c = 1), and K v0 */
        tmass__spring_forces(m, x0, v0, f, (double)dt * dt, (double)dt, v0, w);
        for (i = 0; i < n3; i++) f[i] -= dt * w[i];
        c = 1.0;
    }
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            f[j] = dt * (f[j] + m->ext[j] + m->mass[i] * (m->gravity[r] - alpha * v0[j]));
        }
    memcpy(dv, m->dv_prev, sizeof(tmass_real) * (size_t)n3);
    (void)tmass__cg(m, dmass, c, f, dv, cg_scratch);
    for (i = 0; i < n3; i++) {
        tmass_real fm = m->free_mask[i];
        v1[i] = v0[i] + dv[i] * fm;
        x1[i] = x0[i] + dt * v1[i] * fm;
    }
    memcpy(m->dv_prev, dv, sizeof(tmass_real) * (size_t)n3);
    return TMASS_OK;
}

TMASSDEF int tmass_step_ex(tmass_model *m, tmass_real dt, tmass_integrator integrator)
{
    tmass_real *x0, *v0, *x1, *v1;
    int n3;
    if (!m) return TMASS_ERR_ARG;
    if (!(tmass__finite((double)dt) && dt > 0)) return TMASS_ERR_TIME_STEP;
    if ((int)integrator < 0 || (int)integrator > 3) return TMASS_ERR_INTEGRATOR;
    n3 = 3 * m->node_count;
    x0 = m->scratch[0];
    v0 = m->scratch[1];
    x1 = m->scratch[2];
    v1 = m->scratch[3];
    memset(&m->stats, 0, sizeof m->stats);
    m->stats.newton_iterations = 1;
    tmass__begin_step(m, dt, x0, v0);
    switch (integrator) {
    case TMASS_EXPLICIT_EULER: tmass__explicit_euler(m, dt, x0, v0, x1, v1); break;
    case TMASS_SEMI_IMPLICIT_EULER: tmass__semi_implicit_euler(m, dt, x0, v0, x1, v1); break;
    case TMASS_RK4: tmass__rk4(m, dt, x0, v0, x1, v1); break;
    case TMASS_IMPLICIT_EULER: tmass__implicit_euler(m, dt, x0, v0, x1, v1); break;
    }
    if (!tmass__all_finite(x1, n3) || !tmass__all_finite(v1, n3)) {
        memset(m->dv_prev, 0, sizeof(tmass_real) * (size_t)n3);
        return TMASS_ERR_NOT_FINITE;
    }
    tmass__commit(m, x1, v1);
    return TMASS_OK;
}

TMASSDEF int tmass_step(tmass_model *m)
{
    if (!m) return TMASS_ERR_ARG;
    return tmass_step_ex(m, m->time_step, m->integrator);
}

/* Static equilibrium: Newton on f_int(x) + f_ext + M g = 0 over the free nodes, each
   iteration solving K_t du = f by CG (one iteration is exact for the tensor model). */
TMASSDEF int tmass_solve_static(tmass_model *m)
{
    int i, n3, it, max_newton, cg_total = 0, err = TMASS_OK;
    tmass_real *x, *f, *du, *cg_scratch[5];
    if (!m) return TMASS_ERR_ARG;
    n3 = 3 * m->node_count;
    x = m->scratch[0];
    f = m->scratch[1];
    du = m->scratch[2];
    for (i = 0; i < 5; i++) cg_scratch[i] = m->scratch[3 + i];
    memset(&m->stats, 0, sizeof m->stats);
    max_newton = m->kind == TMASS_TENSOR_MASS ? 1 : 50;
    for (i = 0; i < n3; i++) {
        tmass_real pin = m->pin_mask[i];
        x[i] = m->disp[i] + pin * (m->target[i] - m->disp[i]);
    }
    for (it = 0; it < max_newton; it++) {
        double dn = 0.0, xn = 0.0;
        if (m->kind == TMASS_TENSOR_MASS)
            tmass__internal_force(m, x, NULL, f, m->scratch[8]);
        else
            tmass__spring_forces(m, x, NULL, f, 1.0, 0.0, NULL, NULL);
        for (i = 0; i < n3; i++)
            f[i] = (f[i] + m->ext[i] + m->mass[i / 3] * m->gravity[i % 3]) * m->free_mask[i];
        memset(du, 0, sizeof(tmass_real) * (size_t)n3);
        err = tmass__cg(m, NULL, 1.0, f, du, cg_scratch);
        cg_total += m->stats.cg_iterations;
        m->stats.newton_iterations = it + 1;
        if (err) break;
        for (i = 0; i < n3; i++) {
            x[i] += du[i];
            dn += (double)du[i] * du[i];
            xn += (double)x[i] * x[i];
        }
        if (m->kind == TMASS_TENSOR_MASS ||
            dn <= (double)m->cg_tolerance * m->cg_tolerance * (xn > 0 ? xn : 1.0))
            break;
    }
    m->stats.cg_iterations = cg_total;
    if (err) return err;
    if (it == max_newton) return TMASS_ERR_NO_CONVERGENCE;
    if (!tmass__all_finite(x, n3)) return TMASS_ERR_NOT_FINITE;
    tmass__commit(m, x, NULL);
    return TMASS_OK;
}

/* >>topology -------------------------------------------------------------------------- */

static void tmass__boundary_remove(tmass_model *m, int face_id)
{
    int pos = m->face_pos[face_id], last = m->tri_count - 1;
    if (pos < 0) return;
    if (pos != last) {
        memcpy(m->tri + 3 * pos, m->tri + 3 * last, 3 * sizeof(int));
        m->tri_owner[pos] = m->tri_owner[last];
        m->face_pos[m->tri_owner[pos]] = pos;
    }
    m->face_pos[face_id] = -1;
    m->tri_count--;
}

static void tmass__boundary_add(tmass_model *m, int face_id)
{
    int t = face_id / 4, f = face_id % 4, k;
    for (k = 0; k < 3; k++) m->tri[3 * m->tri_count + k] = m->tet_nodes[4 * t + tmass__face_local[f][k]];
    m->tri_owner[m->tri_count] = face_id;
    m->face_pos[face_id] = m->tri_count++;
}

/* Moves the edge in `slot` out of the live part of its chunk (swap with the chunk's last
   live slot). */
static void tmass__edge_remove(tmass_model *m, int slot)
{
    int k = m->chunk_of_orig[slot / m->chunk_size];
    int last = m->chunk_start[k] + m->chunk_live[k] - 1;
    if (slot != last) {
        int id = m->edge_id[last], moved = m->edge_id[slot];
        m->edge_a[slot] = m->edge_a[last];
        m->edge_b[slot] = m->edge_b[last];
        memcpy(m->edge_tensor + 9 * slot, m->edge_tensor + 9 * last, 9 * sizeof(tmass_real));
        m->edge_rest_length[slot] = m->edge_rest_length[last];
        m->edge_stiffness[slot] = m->edge_stiffness[last];
        m->edge_id[slot] = id;
        m->edge_slot[id] = slot;
        m->edge_id[last] = moved;
        m->edge_slot[moved] = last;
    }
    m->chunk_live[k]--;
    m->edge_count--;
}

static void tmass__remove_one(tmass_model *m, int t)
{
    int j, l, f;
    tmass__apply_tet(m, t, -1.0);
    m->tet_alive[t] = 0;
    m->live_tets--;
    for (j = 0; j < 4; j++) {
        int v = m->tet_nodes[4 * t + j];
        if (--m->node_tets[v] == 0) {
            /* no tetrahedron left: exact zeros instead of round-off residue */
            m->node_state[v] = TMASS__INACTIVE;
            m->mass[v] = 0;
            tmass__set_masks(m, v, 0, 0);
            memset(m->vertex_tensor + 9 * v, 0, 9 * sizeof(tmass_real));
            memset(m->vel + 3 * v, 0, 3 * sizeof(tmass_real));
        }
        m->inv_mass[v] = m->mass[v] > 0 ? (tmass_real)(1.0 / (double)m->mass[v]) : (tmass_real)0;
    }
    for (l = 0; l < 6; l++) {
        int id = m->tet_edges[6 * t + l];
        if (--m->edge_tets[id] == 0) tmass__edge_remove(m, m->edge_slot[id]);
    }
    for (f = 0; f < 4; f++) {
        int other = m->tet_neighbors[4 * t + f];
        if (other < 0) {
            tmass__boundary_remove(m, 4 * t + f);
        } else {
            int g;
            for (g = 0; g < 4; g++)
                if (m->tet_neighbors[4 * other + g] == t) {
                    m->tet_neighbors[4 * other + g] = -1;
                    tmass__boundary_add(m, 4 * other + g);
                    break;
                }
            m->tet_neighbors[4 * t + f] = -1;
        }
    }
}


TMASSDEF int tmass_remove_tets(tmass_model *m, const int *tets, int count, int *removed)
{
    int i, done = 0;
    if (removed) *removed = 0;
    if (!m || (count > 0 && !tets) || count < 0) return TMASS_ERR_ARG;
    for (i = 0; i < count; i++)
        if (tets[i] < 0 || tets[i] >= m->tet_count) return TMASS_ERR_TET_RANGE;
    for (i = 0; i < count; i++)
        if (m->tet_alive[tets[i]]) {
            tmass__remove_one(m, tets[i]);
            done++;
        }
    if (removed) *removed = done;
    return TMASS_OK;
}

TMASSDEF tmass_tear_criteria tmass_default_tear_criteria(void)
{
    tmass_tear_criteria c;
    c.volume_change = 0;
    c.mean_elongation = 0;
    c.max_elongation = 0;
    return c;
}

static void tmass__deformation(const tmass_model *m, int t, tmass_real out[3])
{
    const int *q = m->tet_nodes + 4 * t;
    double g[4][3], v0, v, mean = 0.0, mx = -1e300;
    int l, k;
    v0 = tmass__shape_gradients(m->rest + 3 * q[0], m->rest + 3 * q[1], m->rest + 3 * q[2],
                                m->rest + 3 * q[3], g);
    v = tmass__shape_gradients(m->pos + 3 * q[0], m->pos + 3 * q[1], m->pos + 3 * q[2],
                               m->pos + 3 * q[3], g);
    for (l = 0; l < 6; l++) {
        int a = q[tmass__edge_local[l][0]], b = q[tmass__edge_local[l][1]];
        double d0 = 0.0, d = 0.0, e;
        for (k = 0; k < 3; k++) {
            double r0 = (double)m->rest[3 * b + k] - m->rest[3 * a + k];
            double r = (double)m->pos[3 * b + k] - m->pos[3 * a + k];
            d0 += r0 * r0;
            d += r * r;
        }
        e = sqrt(d) / sqrt(d0) - 1.0;
        mean += e / 6.0;
        if (e > mx) mx = e;
    }
    out[0] = (tmass_real)(fabs(v - v0) / v0);
    out[1] = (tmass_real)mean;
    out[2] = (tmass_real)mx;
}

TMASSDEF int tmass_tet_deformation(const tmass_model *m, int tet, tmass_real out[3])
{
    if (!m || !out) return TMASS_ERR_ARG;
    if (tet < 0 || tet >= m->tet_count) return TMASS_ERR_TET_RANGE;
    tmass__deformation(m, tet, out);
    return TMASS_OK;
}

TMASSDEF int tmass_tear(tmass_model *m, const tmass_tear_criteria *c, int *removed)
{
    int t, count = 0;
    if (removed) *removed = 0;
    if (!m || !c) return TMASS_ERR_ARG;
    if (!tmass__finite((double)c->volume_change) || !tmass__finite((double)c->mean_elongation) ||
        !tmass__finite((double)c->max_elongation))
        return TMASS_ERR_ARG;
    for (t = 0; t < m->tet_count; t++) {
        tmass_real d[3];
        if (!m->tet_alive[t]) continue;
        tmass__deformation(m, t, d);
        if ((c->volume_change > 0 && d[0] > c->volume_change) ||
            (c->mean_elongation > 0 && d[1] > c->mean_elongation) ||
            (c->max_elongation > 0 && d[2] > c->max_elongation))
            m->tear_list[count++] = t;
    }
    return tmass_remove_tets(m, m->tear_list, count, removed);
}


TMASSDEF int tmass_tet_alive(const tmass_model *m, int tet)
{
    if (!m) return TMASS_ERR_ARG;
    if (tet < 0 || tet >= m->tet_count) return TMASS_ERR_TET_RANGE;
    return m->tet_alive[tet];
}

TMASSDEF int tmass_node_active(const tmass_model *m, int i)
{
    if (!m) return TMASS_ERR_ARG;
    if (i < 0 || i >= m->node_count) return TMASS_ERR_NODE_RANGE;
    return m->node_state[i] != TMASS__INACTIVE;
}

TMASSDEF const int *tmass_boundary_triangles(const tmass_model *m, int *count)
{
    if (count) *count = m ? m->tri_count : 0;
    return m ? m->tri : NULL;
}

/* >>boundary-conditions --------------------------------------------------------------- */

static int tmass__check_node(const tmass_model *m, int i)
{
    if (!m) return TMASS_ERR_ARG;
    if (i < 0 || i >= m->node_count) return TMASS_ERR_NODE_RANGE;
    if (m->node_state[i] == TMASS__INACTIVE) return TMASS_ERR_NODE_INACTIVE;
    return TMASS_OK;
}

static int tmass__vec3_finite(const tmass_real *v)
{
    return v && tmass__finite((double)v[0]) && tmass__finite((double)v[1]) &&
           tmass__finite((double)v[2]);
}

static void tmass__pin(tmass_model *m, int i, const tmass_real *target)
{
    int r;
    m->node_state[i] = TMASS__PINNED;
    tmass__set_masks(m, i, 0, 1);
    for (r = 0; r < 3; r++) m->target[3 * i + r] = target[r];
}

TMASSDEF int tmass_fix_node(tmass_model *m, int i)
{
    int err = tmass__check_node(m, i);
    if (err) return err;
    tmass__pin(m, i, m->disp + 3 * i);
    return TMASS_OK;
}

TMASSDEF int tmass_set_displacement(tmass_model *m, int i, const tmass_real u[3])
{
    int err = tmass__check_node(m, i);
    if (err) return err;
    if (!tmass__vec3_finite(u)) return TMASS_ERR_ARG;
    tmass__pin(m, i, u);
    return TMASS_OK;
}

TMASSDEF int tmass_release_node(tmass_model *m, int i)
{
    int err = tmass__check_node(m, i);
    if (err) return err;
    m->node_state[i] = TMASS__FREE;
    tmass__set_masks(m, i, 1, 0);
    return TMASS_OK;
}

TMASSDEF int tmass_node_pinned(const tmass_model *m, int i)
{
    if (!m) return TMASS_ERR_ARG;
    if (i < 0 || i >= m->node_count) return TMASS_ERR_NODE_RANGE;
    return m->node_state[i] == TMASS__PINNED;
}

TMASSDEF int tmass_set_external_force(tmass_model *m, int i, const tmass_real f[3])
{
    int r;
    if (!m) return TMASS_ERR_ARG;
    if (i < 0 || i >= m->node_count) return TMASS_ERR_NODE_RANGE;
    if (!tmass__vec3_finite(f)) return TMASS_ERR_ARG;
    for (r = 0; r < 3; r++) m->ext[3 * i + r] = f[r];
    return TMASS_OK;
}

TMASSDEF void tmass_clear_external_forces(tmass_model *m)
{
    if (m) memset(m->ext, 0, sizeof(tmass_real) * 3 * (size_t)m->node_count);
}

TMASSDEF int tmass_set_gravity(tmass_model *m, const tmass_real g[3])
{
    int r;
    if (!m || !tmass__vec3_finite(g)) return TMASS_ERR_ARG;
    for (r = 0; r < 3; r++) m->gravity[r] = g[r];
    return TMASS_OK;
}

TMASSDEF int tmass_set_solver(tmass_model *m, tmass_real tolerance, int max_iterations)
{
    if (!m) return TMASS_ERR_ARG;
    if (!(tmass__finite((double)tolerance) && tolerance > 0) || max_iterations < 1)
        return TMASS_ERR_SOLVER;
    m->cg_tolerance = tolerance;
    m->cg_max_iterations = max_iterations;
    return TMASS_OK;
}

/* >>state ----------------------------------------------------------------------------- */

TMASSDEF int tmass_node_count(const tmass_model *m) { return m ? m->node_count : 0; }
TMASSDEF int tmass_tet_count(const tmass_model *m) { return m ? m->tet_count : 0; }
TMASSDEF int tmass_live_tet_count(const tmass_model *m) { return m ? m->live_tets : 0; }
TMASSDEF int tmass_edge_count(const tmass_model *m) { return m ? m->edge_count : 0; }
TMASSDEF const tmass_real *tmass_positions(const tmass_model *m) { return m ? m->pos : NULL; }
TMASSDEF const tmass_real *tmass_velocities(const tmass_model *m) { return m ? m->vel : NULL; }
TMASSDEF const tmass_real *tmass_rest_positions(const tmass_model *m) { return m ? m->rest : NULL; }
TMASSDEF const tmass_real *tmass_masses(const tmass_model *m) { return m ? m->mass : NULL; }
TMASSDEF const tmass_stats *tmass_last_stats(const tmass_model *m) { return m ? &m->stats : NULL; }
TMASSDEF size_t tmass_memory_bytes(const tmass_model *m) { return m ? m->block_bytes : 0; }

TMASSDEF const tmass_real *tmass_forces(tmass_model *m)
{
    if (!m) return NULL;
    tmass__internal_force(m, m->disp, NULL, m->force, m->scratch[0]);
    return m->force;
}

TMASSDEF int tmass_set_positions(tmass_model *m, const tmass_real *positions)
{
    if (!m || !positions) return TMASS_ERR_ARG;
    if (!tmass__all_finite(positions, 3 * m->node_count)) return TMASS_ERR_ARG;
    {
        int i;
        for (i = 0; i < 3 * m->node_count; i++) {
            m->disp[i] = (tmass_real)((double)positions[i] - (double)m->rest[i]);
            m->pos[i] = positions[i];
        }
    }
    return TMASS_OK;
}

TMASSDEF int tmass_set_velocities(tmass_model *m, const tmass_real *velocities)
{
    int i;
    if (!m || !velocities) return TMASS_ERR_ARG;
    if (!tmass__all_finite(velocities, 3 * m->node_count)) return TMASS_ERR_ARG;
    for (i = 0; i < 3 * m->node_count; i++)
        m->vel[i] = m->node_state[i / 3] == TMASS__INACTIVE ? (tmass_real)0 : velocities[i];
    return TMASS_OK;
}

TMASSDEF int tmass_energy(tmass_model *m, tmass_energies *out)
{
    int i, r, n;
    double kinetic = 0.0, elastic = 0.0, grav = 0.0, ext = 0.0;
    if (!m || !out) return TMASS_ERR_ARG;
    n = m->node_count;
    if (m->kind == TMASS_TENSOR_MASS) {
        /* 1/2 u^T K u = -1/2 u . f */
        tmass__internal_force(m, m->disp, NULL, m->force, m->scratch[0]);
        for (i = 0; i < 3 * n; i++) elastic -= 0.5 * (double)m->disp[i] * (double)m->force[i];
    } else {
        int s, k;
        for (k = 0; k < m->chunk_total; k++)
            for (s = m->chunk_start[k]; s < m->chunk_start[k] + m->chunk_live[k]; s++) {
                int a = m->edge_a[s], b = m->edge_b[s];
                double d2 = 0.0, stretch;
                for (r = 0; r < 3; r++) {
                    double dr = ((double)m->rest[3 * b + r] - m->rest[3 * a + r]) +
                                ((double)m->disp[3 * b + r] - m->disp[3 * a + r]);
                    d2 += dr * dr;
                }
                stretch = sqrt(d2) - (double)m->edge_rest_length[s];
                elastic += 0.5 * (double)m->edge_stiffness[s] * stretch * stretch;
            }
    }
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            double v = m->vel[3 * i + r], u = m->disp[3 * i + r];
            kinetic += 0.5 * (double)m->mass[i] * v * v;
            grav -= (double)m->mass[i] * m->gravity[r] * u;
            ext -= (double)m->ext[3 * i + r] * u;
        }
    out->kinetic = kinetic;
    out->elastic = elastic;
    out->gravitational = grav;
    out->external = ext;
    return TMASS_OK;
}

/* >>diagnostics ----------------------------------------------------------------------- */

TMASSDEF int tmass_vertex_tensor(const tmass_model *m, int i, tmass_real out[9])
{
    if (!m || !out || m->kind != TMASS_TENSOR_MASS) return TMASS_ERR_ARG;
    if (i < 0 || i >= m->node_count) return TMASS_ERR_NODE_RANGE;
    memcpy(out, m->vertex_tensor + 9 * i, 9 * sizeof(tmass_real));
    return TMASS_OK;
}

TMASSDEF int tmass_edge_tensor(const tmass_model *m, int a, int b, tmass_real out[9])
{
    int k, s, r, c;
    if (!m || !out || m->kind != TMASS_TENSOR_MASS) return TMASS_ERR_ARG;
    if (a < 0 || a >= m->node_count || b < 0 || b >= m->node_count) return TMASS_ERR_NODE_RANGE;
    for (k = 0; k < m->chunk_total; k++)
        for (s = m->chunk_start[k]; s < m->chunk_start[k] + m->chunk_live[k]; s++) {
            const tmass_real *T = m->edge_tensor + 9 * s;
            if (m->edge_a[s] == a && m->edge_b[s] == b) {
                memcpy(out, T, 9 * sizeof(tmass_real));
                return TMASS_OK;
            }
            if (m->edge_a[s] == b && m->edge_b[s] == a) {
                for (r = 0; r < 3; r++)
                    for (c = 0; c < 3; c++) out[3 * r + c] = T[3 * c + r]; /* K_ba = K_ab^T */
                return TMASS_OK;
            }
        }
    return TMASS_ERR_NO_EDGE;
}

#if defined(TMASS_STATIC) && defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif /* TENSORMASS_IMPLEMENTATION */

/*
------------------------------------------------------------------------------
This software is available under 2 licenses -- choose whichever you prefer.
------------------------------------------------------------------------------
ALTERNATIVE A - MIT License
Copyright (c) 2026 The soft-body library authors
Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
of the Software, and to permit persons to whom the Software is furnished to do
so, subject to the following conditions:
The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.
THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
------------------------------------------------------------------------------
ALTERNATIVE B - Public Domain (www.unlicense.org)
This is free and unencumbered software released into the public domain.
Anyone is free to copy, modify, publish, use, compile, sell, or distribute this
software, either in source code form or as a compiled binary, for any purpose,
commercial or non-commercial, and by any means.
In jurisdictions that recognize copyright laws, the author or authors of this
software dedicate any and all copyright interest in the software to the public
domain. We make this dedication for the benefit of the public at large and to
the detriment of our heirs and successors. We intend this dedication to be an
overt act of relinquishment in perpetuity of all present and future rights to
this software under copyright law.
THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN AN
ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION
WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
------------------------------------------------------------------------------
*/

