/* bench.h - the bench's interface to a model: one bench_model per (model, variant,
   precision). bench.c runs every scene on every entry; adding a model, a law, a shape
   function or an integrator is one more entry in an adapter's table (bench/model_*.c),
   and a new adapter file is one line in bench.c's registry.

   Every scene is built from a bench_body: a box along +x, [0, L] x [-W/2, W/2] x
   [-H/2, H/2] (the tetmesh_beam convention), optionally translated, with `cells` cells
   per axis. "Nodes" are what the model moves: mesh vertices, or frames. Values cross the
   interface in double whatever the model's precision. */
#ifndef BENCH_H
#define BENCH_H

/* Integrators and solvers, as bits of bench_model.integrators. */
enum {
    BENCH_EXPLICIT_EULER = 0,
    BENCH_SEMI_IMPLICIT_EULER = 1,
    BENCH_RK4 = 2,
    BENCH_IMPLICIT_EULER = 3,
    BENCH_STATIC = 4, /* a static (equilibrium) solver */
    BENCH_BDF2 = 5,   /* second-order backward differentiation (issue 19) */
    BENCH_INTEGRATOR_COUNT = 6
};

/* What an adapter call returns besides 0 (ok) and the library's own negative codes. */
#define BENCH_UNSUPPORTED 1000

/* Kernels timed by the throughput part. */
enum {
    BENCH_KERNEL_FORCE = 0,     /* the internal force */
    BENCH_KERNEL_KV = 1,        /* K * v, matrix-free (the force differential) */
    BENCH_KERNEL_KV_BLOCKS = 2, /* K * v by assembled blocks, where a model has them */
    BENCH_KERNEL_MOVE = 3,      /* the force pass with its arithmetic taken out (gather the
                                   nodes, stream the per-element data, scatter): the floor
                                   under the force, where a model can time it */
    BENCH_KERNEL_CSR = 4,       /* K * v by a CSR matrix (scalar rows, 4-byte column
                                   indices, the model's real type) of the same tangent
                                   stiffness, assembled by the adapter at the first call
                                   (issue 21: the differential against an assembled matrix) */
    BENCH_KERNEL_ARITH = 5,     /* the force pass's arithmetic alone (no gather or scatter:
                                   one gathered block reused), the arithmetic floor */
    BENCH_KERNEL_STEP = 6,      /* one implicit step of 1 ms under gravity (per element), where
                                   an adapter times it: the peer comparison (issue 21) */
    BENCH_KERNEL_COUNT = 7
};

typedef struct bench_body {
    double size[3];     /* L, W, H, m */
    int cells[3];       /* cells along x, y, z */
    double offset[3];   /* translation of the whole body, m */
    double young;       /* Pa */
    double poisson;
    double density;     /* kg/m^3 */
    double gravity[3];  /* m/s^2 */
    double damping;     /* mass damping, 1/s */
    int clamp;          /* 1: the nodes on x = 0 are pinned at rest */
    /* optional: elements whose rest centroid (before the offset) satisfies exclude() are
       left out of the mesh (a body "rebuilt without" a cut region) */
    int (*exclude)(const double centroid[3], void *user);
    void *exclude_user;
} bench_body;

typedef struct bench_model {
    const char *model;     /* header: "tensormass", "heml", "frames" */
    const char *variant;   /* law / kind / shape function, as shown in tables */
    const char *law;       /* "linear", "springs", "svk", "neo-hookean", "mooney-rivlin":
                              which closed forms (R4 SVK, R5 Neo-Hookean) apply */
    const char *precision; /* "double" or "float" */
    unsigned integrators;  /* bit (1u << BENCH_x) set for each supported integrator/solver */
    int nonlinear;         /* 1: geometrically exact (large deformation) */
    int primary;           /* 1: every scene; 0: a variant of a primary entry (another law)
                              that runs only the static scenes and the smallest kernels,
                              to keep `make bench` within its time; -1: an opt-in option of
                              a primary entry (e.g. a volumetric treatment against locking)
                              that runs only the stability part's Poisson rows and the
                              kernels' two smallest sizes */
    const char *element;   /* unit of the kernel counts: "tet", "pair" */
    /* 0 or the library's error code; *sim NULL on failure */
    int (*create)(const bench_body *b, void **sim);
    void (*destroy)(void *sim);
    int (*dof)(void *sim);
    int (*node_count)(void *sim);
    void (*rest)(void *sim, int node, double p[3]);     /* rest position, m */
    void (*position)(void *sim, int node, double p[3]); /* current position, m */
    /* Pins a node at rest + u (m); rotation (row-major 3x3, or NULL for none) is the
       orientation imposed on models whose nodes have one (frames) and is ignored by the
       others (u already carries it). */
    int (*pin)(void *sim, int node, const double u[3], const double *rotation);
    int (*release)(void *sim, int node);
    int (*set_gravity)(void *sim, const double g[3]);
    int (*solve_static)(void *sim);                             /* equilibrium */
    int (*step)(void *sim, double dt, int integrator);          /* one time step */
    int (*forces)(void *sim, double *f);                        /* 3n elastic forces, N */
    /* cutting: removes the elements whose rest centroid (before the offset) satisfies
       inside(); NULL when the model cannot cut. *removed receives the count. */
    int (*cut)(void *sim, int (*inside)(const double c[3], void *user), void *user, int *removed);
    /* kernels: element count, bytes one call must move at least (the header's figures),
       and one call (BENCH_UNSUPPORTED if the model has no such kernel) */
    double (*elements)(void *sim);
    double (*kernel_bytes)(void *sim, int kernel);
    int (*kernel)(void *sim, int kernel);
    /* optional (NULL): the model's haptic scene (a precomputed contact model with about
       2,000 surface nodes); fills the median seconds per update with 1, 2, 3 contacts */
    int (*haptic)(int quick, double update_seconds[3], int *surface_nodes, double *precompute_seconds,
                  double *memory_bytes);
    /* optional (NULL): the displacement u (m) of the material point whose rest position
       (with the offset) is p, through the model's point probe (issue 19); 0 or an error
       (then the caller falls back to node averages) */
    int (*probe)(void *sim, const double p[3], double u[3]);
    /* optional (NULL): mapped points (issue 14), a render mesh's cost: about `points` points
       inside the body's elements made once, then the median ns per point of their positions
       [0], velocities [1] and the forces' transpose J^T f [2]; *points the count made */
    int (*mapped)(void *sim, int *points, double ns_per_point[3]);
} bench_model;

/* An adapter's table: *count entries. */
typedef const bench_model *(*bench_models_fn)(int *count);

/* One row of heml.h's implicit steps with and without the coarse correction (issue 21,
   bench/model_heml.c bench_heml_coarse_rows_*): a beam, E, dt, integrator and
   desc.implicit_coarse (-1 never, 0 automatic, 1 always); per step the CG iterations, the
   Newton iterations, the coarse factorisations and the seconds (best of the repeats), and
   the status of the run. */
typedef struct bench_coarse_row {
    const char *scene, *integrator;
    double young, dt;
    int mode, dof, code;
    double cg_per_step, newton_per_step, factors_per_step, seconds_per_step;
} bench_coarse_row;

#endif
