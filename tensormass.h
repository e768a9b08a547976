/* tensormass.h - v0.2.0 - linear tensor-mass elasticity with cutting, tearing, precomputed and hybrid models - MIT or public domain

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
                       double and stores them in TMASS_REAL. In float builds every public
                       function is renamed (tmass_step -> tmass_step_f32, and so on for all
                       84), so mixing float and double translation units fails at link
                       time, not at run time (a test lists them all).
       TMASS_MALLOC(size, user) / TMASS_FREE(ptr, user)
                       default allocator (malloc/free) when the desc gives none.
       TMASS_ASSERT(x) internal sanity checks (default: assert from <assert.h>).
       TMASS_STATIC    make every function static (private to the including file).
       TMASS_NO_SIMD   keep the edge pass's portable loop in double builds with AVX2 and
                       FMA (which otherwise run it with 4-wide vectors: another rounding
                       of the same sums; see PERFORMANCE).

   STEP BY STEP
       1. tmass_desc d = tmass_default_desc(); fill the mesh, the material, the time step.
       2. tmass_create(&d, &m) validates everything and allocates all memory once.
       3. Boundary conditions: tmass_fix_node (pinned where it is), tmass_set_displacement
          (pinned at rest + u, e.g. driven by a tool), tmass_release_node, gravity,
          tmass_set_external_force, tmass_set_anchors (springs to targets: gluing to
          another model, see ANCHORS).
       4. tmass_step(m) (desc integrator and time step) or tmass_step_ex(m, dt, integrator);
          tmass_solve_static(m) for the equilibrium.
       5. Read tmass_positions / tmass_velocities / tmass_displacements /
          tmass_boundary_triangles to render; material points that are not nodes through
          a probe (tmass_probe_create once, tmass_probe_positions each frame).
       6. Topology: tmass_remove_tets (cutting), tmass_tear (tearing by criteria).
       7. tmass_destroy(m).
       Accuracy (issue 19): TMASS_BDF2 for second order in time (INTEGRATORS);
       tmass_modal_create / tmass_modal_solve for natural frequencies and mode shapes
       about the current state (how far the mesh is from a known frequency: the spatial
       error, locking included; see the modal analysis part of the API below).
       Precomputed quasi-static model (haptic rates, frozen topology): create a model as
       above with its pinned nodes, then tmass_qs_create(m, &qd, &qs) (minutes on large
       meshes; tmass_qs_save / tmass_qs_load keep the result), then per haptic frame
       tmass_qs_update(qs, contact_nodes, displacements, count, forces) and read
       tmass_qs_displacements. Hybrid model (cut one region, precompute the rest):
       tmass_hybrid_desc hd = tmass_hybrid_default_desc(); hd.model = the whole mesh,
       hd.tet_dynamic = which tets are dynamic, hd.fixed_nodes; tmass_hybrid_create, then
       tmass_hybrid_step / tmass_hybrid_set_displacement / tmass_hybrid_remove_tets.

   HOW TO EXTEND (a new model kind, integrator or linear solver is a local change: one
   enum value before its _COUNT sentinel, one row in one private table, the functions the
   row names; nothing else dispatches on these enums)
       Model kind (a "law": another force model on the same mesh). tmass_model_kind gets a
         value before TMASS_MODEL_KIND_COUNT; tmass__kinds[] (section >>laws) gets a row:
         name; assemble_tet (add or remove one tetrahedron's stiffness and lumped mass, at
         creation and when cutting); force (internal force, elastic plus stiffness
         damping, at u and v); differential (the linearised implicit Euler step: the force
         term and the tangent left in the edge tensors, returning its factor c); energy;
         implicit_newton (the full nonlinear implicit step, or NULL when the model is
         linear); static_solve; tangent (the full tangent at a state into the tensors, for
         the modal analysis, or NULL when the tensors always hold K); flags (TMASS__KIND_LINEAR: constant tensors, so the
         quasi-static and hybrid models and tmass_vertex_tensor accept it;
         TMASS__KIND_POISSON: poisson_ratio is validated and lambda, mu stored). The
         table's length is checked at compile time against the sentinel.
       Integrator. tmass_integrator gets a value before TMASS_INTEGRATOR_COUNT;
         tmass__integrators[] (section >>integrators) gets a row {name, step, is_explicit,
         keeps_history} (keeps_history: a multistep scheme; tmass_step_ex saves the state
         before each accepted step in history_u / history_v, and every other event that
         breaks the history clears m->history_ready, see TMASS_BDF2).
         step(m, dt) reads m->step_u0, m->step_v0 (pinned nodes already at their targets)
         and writes m->step_u1, m->step_v1; tmass_step_ex does the rest (finiteness,
         divergence check when is_explicit, precision check, inverted count when not,
         commit, state kept on failure). Work vectors are named by role in tmass_model and
         carved in tmass__layout: reuse one whose role cannot overlap yours (say so at the
         aliasing in tmass__layout) or add one there (3n reals per node count).
       Linear solver. tmass_linear_solver gets a value before TMASS_LINEAR_SOLVER_COUNT
         (selected by desc.linear_solver); tmass__linear_solvers[] (section >>solver) gets
         a row {name, solve, solve_block}. solve(m, diag, c, b, x) solves
         (diag + c K) x = b on the free degrees of freedom (K applied by tmass__matvec,
         including a hybrid's coupling block and the anchors), x holding the initial guess; solve_block
         solves K X = B for TMASS__RHS interleaved columns (the quasi-static
         precomputation). Both return TMASS_OK, TMASS_ERR_NO_CONVERGENCE (cap reached or a
         direction of non-positive curvature) or TMASS_ERR_NOT_FINITE, add to stats
         (cg_iterations, cg_residual, stiffness_products, negative_curvature) and set
         m->cg_indefinite when the matrix was not positive definite along a direction,
         leaving that direction in m->cg_p and mask A p in m->cg_q (the springs' static
         minimum check, tmass__spring_check_minimum, reads them). m->cg_coarse set: an
         implicit step asks for the coarse correction (>>coarse; CG adds it, another
         solver may ignore it). Every solve of the header calls tmass__linear_solve / tmass__linear_solve_block:
         never call a solver directly.
       Tests each must add (tests/test_tensormass.c, test_tensormass_qs.c for the
         precomputed paths): a model kind, force = -gradient of its energy by finite
         differences (as test_force_is_minus_energy_gradient and
         test_spring_force_is_minus_energy_gradient), differential = derivative of the
         force (test_stiffness_is_minus_force_gradient,
         test_spring_incremental_potential_gradient), a closed form where one exists
         (test_stiffness_equals_p1_fem, test_cantilever_r1, test_masses), the static and
         implicit solves agreeing (test_springs_implicit_matches_static); an integrator,
         its order of accuracy on the oscillator (test_integrator_order: halving dt
         divides the error by 2^order) and its energy behaviour
         (test_semi_implicit_energy_bounded, test_explicit_euler_grows_rk4_decays); a
         linear solver, the same answers as CG within the tolerance on the static,
         implicit and quasi-static tests, its failure codes (test_cg_cap_fails,
         test_huge_load_not_finite); all three, determinism (test_threads_bit_identical:
         bit-identical for 1 and 2 threads) and no allocation after creation
         (test_no_allocation_after_create); test_extension_enums_validated covers the
         sentinels.
       Bench (bench/model_tensormass.c: a kind is a row of tm_models with its create
         function; an integrator a BENCH_ id of bench/bench.h mapped in tm_step): the new
         entry's speed/accuracy rows (R1-R5) and stability table next to the existing
         ones, and the existing rows no slower (callgrind instruction counts of a step
         loop per integrator, or make bench-quick, before and after, in the note).

   UNITS: SI throughout. Positions m, Young's modulus Pa, density kg/m^3, time s, forces
   N, mass_damping 1/s, stiffness_damping s, gravity m/s^2 (default 9.81 along -z).

   MEMORY: tmass_create makes one allocation (one block; every array in it 64-byte aligned)
   through the desc's allocator (or TMASS_MALLOC), plus a temporary one it frees before
   returning. A custom allocator must honour the alignment it is asked for (64).
   Nothing else allocates: stepping, forces, solves, cutting and tearing reuse that block
   (cutting only removes, so capacity never runs out). The block holds the implicit steps'
   coarse correction (SOLVERS) unless desc.implicit_coarse = -1, on the tensor model with
   at least 96 nodes: two (6 A)^2 matrices of doubles for A = min(64, nodes / 24)
   aggregates (up to 2.4 MB; 130 KB on a 1025-node beam) and an int per node. The description's arrays are read
   during tmass_create only. Pointers returned by tmass_positions and friends point into
   the model and stay valid until tmass_destroy.

   ERRORS: every fallible function returns 0 or a negative TMASS_ERR_* code;
   tmass_error_string names it, and the optional desc.log callback receives a detailed
   message for validation failures (the library never prints). A description without the
   cookie of tmass_default_desc (garbage, or a struct zeroed by hand) is refused with
   TMASS_ERR_DESC before anything in it is used, its log callback included. No step or
   solve reports success for an answer it could not verify; every failure below leaves
   positions and velocities exactly as they were, so the caller may retry (smaller time
   step, implicit integrator, looser tolerance, more iterations):
       TMASS_ERR_NO_CONVERGENCE  a linear solve (CG) stopped at its iteration cap above its
                                 tolerance or met a direction of non-positive curvature
                                 (singular: nothing pinned), or a Newton solve or the
                                 static continuation did not reach its tolerance within
                                 its caps. stats.cg_residual / stats.residual say how far
                                 it got. There is no option to accept an unconverged
                                 iterate: a fixed-cost caller sets a cap and a tolerance
                                 that fit and reads the code.
       TMASS_ERR_NOT_FINITE      a non-finite value anywhere, including a load whose norm
                                 |b|^2 overflows (from about 1e154 N in double; it used
                                 to make the CG tolerance infinite and pass at once).
       TMASS_ERR_DIVERGED        an explicit step (explicit Euler, semi-implicit Euler,
                                 RK4) stretched an edge by more than desc.divergence_strain
                                 (default 100 %): the step is unstable at this dt (see
                                 LIMITS). Caught a few steps into a blow-up, long before
                                 anything overflows.
       TMASS_ERR_PRECISION       eps(tmass_real) * max|u| > desc.precision_limit * the
                                 shortest rest edge, u = x - X the displacement (see
                                 LIMITS: float bodies that travel far from their rest
                                 position).
       TMASS_ERR_UNSTABLE        a spring model's static solve converged to a saddle, not
                                 a minimum (the minimum check of tmass_solve_static: a
                                 tetrahedron flattened through its base balances there);
                                 nudge the state or change the pins and solve again.
   Creation refuses, besides bad numbers and indices: flat and inverted rest tetrahedra,
   a triangle shared by three tetrahedra (TMASS_ERR_NONMANIFOLD) and the same tetrahedron
   listed twice in any node order (TMASS_ERR_TET_DUPLICATE: it would double that
   tetrahedron's mass and stiffness). tmass_qs_load refuses a file whose payload holds a
   NaN or an infinity even with a valid checksum (TMASS_ERR_FILE_FORMAT).

   SOLVERS AND STATISTICS: tmass_last_stats returns the tmass_stats of the last step or
   static solve, the same fields in the same order as heml_stats and frm_stats:
   newton_iterations, cg_iterations, cg_residual, residual, increments, increment_cuts,
   line_search_cuts, negative_curvature, inverted, force_evaluations, stiffness_products.
       Linear solves (desc.linear_solver; TMASS_LINEAR_SOLVER_CG, the only one today):
       Jacobi-preconditioned CG to |r| <= cg_tolerance |b| (default 1e-6,
       1e-5 float) within cg_max_iterations (2000); at the cap it fails (see ERRORS). Its
       dot products accumulate in double. A relative residual does not bound the error
       (error <= cond |r| / |b|): in float, nearly incompressible materials are refused at
       creation for that reason (LIMITS); stats.cg_condition is a lower bound of the
       Jacobi-scaled condition number, the largest over the call's solves.
       Tensor-mass static solve: the model is linear, so one converged CG solve is the
       exact answer of the model (newton_iterations = increments = 1, residual = 0). It is
       accepted whatever the deformation: tetrahedra that end inverted are counted in
       stats.inverted, not refused, because the linear answer is exact for its model; a
       state with inverted tetrahedra is far outside the model's validity (small strains)
       and the caller should read the count. The same holds for implicit steps.
       Tensor-mass implicit Euler: one linear solve, exact for the linear model.
       Coarse correction of the tensor model's implicit steps (issue 21;
       desc.implicit_coarse, heml.h's option and semantics, its own code): implicit Euler,
       its linearised form and BDF2 solve (D + c K) dv = b, D = M (1 + dt alpha), c = dt^2
       + dt beta (BDF2: 2 dt / 3 in place of dt). Jacobi alone is good while D dominates
       (small dt, soft bodies) and needs hundreds of iterations once c K does on slender
       bodies (bending, which Jacobi resolves slowest). The correction adds P A_c^-1 P^T
       to Jacobi: the nodes binned into up to 64 cells of the rest bounding box
       (aggregates, at least 24 nodes each: meshes under 96 nodes have none), each with
       the six rigid motions of its nodes (P), A_c = P^T (D + c K) P on the free axes with
       K exactly the operator CG multiplies by (edge tensors, a hybrid's coupling block,
       the anchors), dense Cholesky in double (6 A unknowns; a mode that pins or cuts
       leave singular is dropped). P^T K P is one pass over the live edges (about 650
       multiply-adds each: 0.43 ms on R3's 1025 nodes and 4,896 edges, 15 aggregates),
       redone at the next step after a cut or tear, a pin change, tmass_set_anchors or
       a hybrid's coupling change (anchor stiffnesses changed in place without the call
       keep the old one: slower, never wrong); the factor (0.2 ms there) is kept with its
       key (c, P^T D P bit for bit, those events) and reused by every step of one dt
       (BDF2: one more for its 2 dt / 3). Applying it costs two serial node passes and
       two triangular solves per iteration (7.4 us on R3 against 20 us for a K product;
       with the extra r . z about half an iteration's cost). CG checks its answer as
       before (results change within the CG tolerance); stats.cg_condition then bounds
       the two-level preconditioned matrix's condition number. Modes: 0 (default)
       automatic: Jacobi alone until a step's CG needed TMASS__COARSE_MIN_ITERATIONS (50)
       iterations, the correction from the next step on (never off again); 1 always; -1
       never (and no memory: MEMORY). stats.coarse_solves counts the solves that used
       it, stats.coarse_factors its factorisations in the step. The spring model has
       none (its tangent changes every Newton iteration; implicit_coarse is ignored).
       Why 50, not heml's 20: a K product is cheaper here (one pass over edge tensors), so
       the correction's cost weighs more; on R3 at dt = 1 ms over 30 steps (1 thread,
       the machine below) it lost at E = 1, 2 MPa (Jacobi 31, 43 iterations a step -> 25,
       30: x1.21, x1.15 the time) and won from 3 MPa (52 -> 32: x0.81; 10 MPa, 93 -> 38:
       x0.65). Measured (`build/bench/bench --parts coarse --filter tensormass`, bench.c
       >>coarse, the heml rows' beams clamped at x = 0, 6 implicit Euler steps from rest,
       CG tolerance 1e-9; Intel Xeon under KVM (family 6 model 167, AVX-512), 2 vCPUs,
       load average 6, OMP_NUM_THREADS=1; CG iterations per
       step Jacobi only -> always, and the time ratio always / never, range of 2 runs of
       2 interleaved repeats each):
                              dt = 1 ms          10 ms            0.1 s            1 s
           R3, E = 1 kPa      3 -> 4   x2.3 *   11 -> 12  x3.6 *  103 -> 40 x0.58  183 -> 51 x0.35-0.45
           R3, E = 1 MPa     34 -> 25  x0.8-1.9 156 -> 47 x0.39-0.50 233 -> 58 x0.33-0.37 282 -> 65 x0.33
           R3, E = 10 MPa   103 -> 40  x0.42-0.62 183 -> 51 x0.45-0.49 268 -> 61 x0.36-0.38 288 -> 67 x0.28-0.38
           R1, steel        252 -> 43  x0.19-0.44 459 -> 51 x0.17-0.18 576 -> 56 x0.15-0.19 596 -> 60 x0.16-0.18
       (R3: 1 x 0.1 x 0.1 m, 40 x 4 x 4 cells, 3075 dof; R1: 16 x 0.5 x 0.5 m, 64 x 2 x 2
       cells, 1755 dof. * the first step's assembly and factor, about 0.6 ms once, over 6
       steps of 0.16-0.36 ms; the automatic mode stays Jacobi in the rows whose Jacobi
       count is under 50: 1 kPa at 1 and 10 ms, 1 MPa at 1 ms.) BDF2's rows are alike
       (R1 598 -> 57 at 1 s). The automatic mode's first step is Jacobi only: over the 6
       steps it reads x0.23 to x0.78 where it switches on. Tests: tests/test_tensormass.c
       test_implicit_coarse_correction (same states as Jacobi only within 1e-4 of the
       displacement at CG tolerance 1e-12, measured 1e-13; 2.4 to 3 times fewer
       iterations in double, 5 in float, at E = 10 MPa, dt = 0.1 s on a 20 x 2 x 2 beam;
       after a cut; with anchors and a driven node; one factorisation per coefficient; no
       allocation; mass-dominated steps not slowed by more than 2 x Jacobi's count);
       tests/test_tensormass_qs.c test_hybrid_coarse_correction (a hybrid's dynamic part,
       its coupling block in A_c: 835 -> 287 iterations over 5 steps, same positions).
       Springs static solve: load continuation. The load fraction s goes from 0 to 1
       (gravity and external forces scaled by s, pinned nodes moved from where they are
       towards their targets by s); each increment is solved by Newton with a line search
       (tmass_solve_static below). The whole load is tried first; a failed increment is
       cut to a quarter, an accepted one lets the next double; the solve fails (state
       kept) below an increment of 1e-4 or after 64 attempts. Accepted only when the
       residual |f| <= newton_tolerance (default 1e-6, 1e-5 float) times the reference
       |f| of the free nodes at rest with the pinned nodes at their targets under the
       whole load (the problem's own scale, whatever the starting state), or when |f| is
       at its round-off floor eps sqrt(sum_i (|u_i| K_ii)^2) (the residual that rounding
       u alone produces; in float on stiff meshes often 1e-4 of the load). stats.residual
       is |f| over the reference. newton_iterations caps each increment (default 20).
       Springs implicit Euler (TMASS_IMPLICIT_EULER): Newton on the incremental potential
       (see INTEGRATORS) to the same kind of tolerance, at most newton_iterations, then
       fails. The spring model, like the tensor model, counts inverted tetrahedra in
       stats.inverted and does not refuse them (springs have no volume term: a spring
       network can pass through an inverted configuration and come back). TMASS_IMPLICIT_EULER_LINEARIZED keeps the single linearised iteration (no
       tolerance on the nonlinear residual: its error is the linearisation's, about the
       square of the step's strain increment; fine for small steps, wrong for large
       deformations within one step).

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
       Each stretch is formed from the displacements as
       |P_iP_j| - l_ij = (|P_iP_j|^2 - l_ij^2) / (|P_iP_j| + l_ij), the numerator
       (2 d0 + du) . du with d0 the rest edge and du the difference of the end
       displacements, so a strain of 1e-6 keeps its digits in float (the difference of two
       lengths would lose them all). The static solve is Newton on the full tangent (its
       positive-definite part where compressed springs make it indefinite) with a
       backtracking line search on the potential or the residual, in load increments
       (SOLVERS).

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
                                   matrix-free over the edge tensors (beyond the paper), plus
                                   a coarse correction at large dt (SOLVERS).
                                   Unconditionally stable (strongly damps high frequencies).
                                   Pinned nodes move to their targets over the step; their
                                   velocity enters the damping only. Springs: Newton
                                   minimisation of the incremental potential
                                     Phi(x) = dt^2 (E(x) - f.x) + |x - x0 - dt v0|_M^2 / 2
                                              + dt alpha |x - x0|_M^2 / 2
                                   (axial spring damping added to the residual and tangent,
                                   not to Phi), each iteration a CG solve on
                                   M (1 + dt alpha) + dt^2 K_t + dt D with K_t's compressive
                                   geometric part clamped (positive definite), a line search
                                   on Phi or the residual. The default.
       TMASS_IMPLICIT_EULER_LINEARIZED
                                   the same step linearised once at the start of the step
                                   (one CG solve; identical to TMASS_IMPLICIT_EULER for the
                                   tensor model). For springs: cheaper, no nonlinear
                                   tolerance (see SOLVERS).
       TMASS_BDF2                  second-order backward differentiation (issue 19):
                                     3 x1 - 4 x0 + x_-1 = 2 dt v1,
                                     3 v1 - 4 v0 + v_-1 = 2 dt a(x1, v1).
                                   With beta = 2 dt / 3, xbar = (4 x0 - x_-1) / 3 and
                                   vbar = (4 v0 - v_-1) / 3 this is implicit Euler's step
                                   with (dt, x0, v0) replaced by (beta, xbar, vbar):
                                     x1 = argmin 1/(2 beta^2) |x - xbar - beta vbar|_M^2
                                          + E(x) - f.x (+ alpha / (2 beta) |x - xbar|_M^2),
                                     v1 = (x1 - xbar) / beta,
                                   so the tensor model's step is the same one CG solve
                                   and the springs' the same Newton minimisation, line
                                   search and acceptance test (the same code, called with
                                   the substituted arguments), at the cost of implicit
                                   Euler's step plus two vector copies. Second order,
                                   A-stable (unconditionally stable), and strongly damping
                                   at large w dt like implicit Euler (no high-frequency
                                   ringing, no energy growth on the nonlinear springs,
                                   unlike the implicit midpoint rule or Newmark's average
                                   acceleration, energy-conserving only for linear
                                   problems), while a resolved mode keeps its amplitude:
                                   decay per period of an undamped mode (measured on a
                                   one-tetrahedron oscillator and on the R3 beam released
                                   from its first bending mode, read by a tip probe; both
                                   equal the schemes' closed forms to 4 digits)
                                       dt     implicit Euler   BDF2
                                       T/20   62.1 %           3.95 %
                                       T/50   32.5 %           0.301 %
                                       T/100  17.9 %           0.0386 %
                                       T/400   4.81 %          0.00061 %
                                   and period error +3.2 %, +0.52 %, +0.13 %, +0.0082 %
                                   (both schemes alike, second order). History: the model
                                   keeps x_-1, v_-1 (allocated at creation). The first
                                   BDF2 step after creation, and the first after a change
                                   of dt, a step of another integrator,
                                   tmass_set_positions / _velocities, tmass_fix_node /
                                   _set_displacement / _release_node (a node driven by
                                   tmass_set_displacement every step restarts every step:
                                   drive it with implicit Euler or accept first order
                                   there), a cut or tear, a static solve or a failed step,
                                   is one implicit Euler step (it has no valid x_-1). A
                                   failed step keeps the state and the stored history, and
                                   the retry restarts with implicit Euler. The hybrid
                                   model's dynamic part steps with BDF2 like any model
                                   (tmass_hybrid_step_ex, tested); the precomputed part is
                                   static.
   The explicit integrators check each step for divergence (ERRORS: TMASS_ERR_DIVERGED);
   one pass over the edges, no square root. Measured orders on a one-tetrahedron
   oscillator (tests): halving dt halves the error of the three Euler schemes, divides
   BDF2's by 4 (both kinds) and RK4's by 16.

   CUTTING AND TEARING (sec. 5.5): tmass_remove_tets removes tetrahedra by subtracting their
   ten tensors (four vertex, six edge) and their mass, drops edges left without a
   tetrahedron, marks vertices left without one inactive (frozen, mass 0) and updates the
   boundary-triangle list; cost linear in the tetrahedra removed. Tetrahedron indices are
   those of the description and stay valid forever (cutting never creates or renumbers
   tetrahedra); removing one twice is harmless. tmass_tear removes every tetrahedron past
   any enabled threshold of: relative volume change |V - V0| / V0, mean relative edge
   elongation, maximum relative edge elongation ((l - l0) / l0, positive in tension).

   PRECOMPUTED QUASI-STATIC MODEL (sec. 4): with the pinned nodes as fixed boundary
   conditions, one CG solve per precomputed node and direction gives the columns of the
   compliance C = K^-1 (a unit force on that degree of freedom), restricted to the output
   nodes (the precomputed nodes, or every node), plus the static preload g under gravity,
   external forces and the pinned nodes' targets (a pinned node driven away from rest by
   tmass_set_displacement is a boundary condition of the preload). An update with imposed displacements u_I on a contact set I solves
   the small dense system C_II f = u_I - g_I (Cholesky, 3|I| unknowns) for the forces f
   that hold the contacts, then u = g + C_.I f on every output node: the constraints are
   met exactly (superposition of elementary fields, valid because the model is linear).
   Cost per update: 9 |I| |output| multiply-adds + (3|I|)^3 / 3; memory 9 |P| |output|
   reals (tmass_qs_memory_bytes). Precomputation: 3 |P| + 1 solves, 8 at a time sharing
   each pass over the tensors; it reports progress and can be cancelled. The file format
   (tmass_qs_save) is a versioned header (magic, version, byte order, real size, counts,
   a fingerprint of mesh, material, pins and loads), the payload and a checksum; loading
   refuses a truncated, corrupted, other-version or other-model file with its own code.
   Topology changes are refused (TMASS_ERR_PRECOMPUTED): the paper's limit.

   HYBRID MODEL (sec. 6, fig. 5): the caller marks the dynamic tetrahedra; the rest is
   precomputed on its boundary nodes. Connection nodes belong to both parts. Each step the
   dynamic part's connection displacements are imposed on the precomputed part, which
   returns the forces needed to hold them, applied to the dynamic part. Beyond the paper
   the precomputed part's exact connection stiffness S = (C_cc)^-1 is included in the
   dynamic part's implicit solve, so the coupling adds no time-step limit; at steady
   state the hybrid equals a single tensor-mass model of the whole mesh (tested, also
   after cuts). A face-connected piece of the precomputed part held by fewer than three
   non-collinear fixed nodes would be singular: it is moved to the dynamic part (and
   reported through desc.log). Cutting and tearing apply to the dynamic part; connection
   nodes left without a dynamic tetrahedron stop coupling.

   ANCHORS (tmass_set_anchors, issue 14; the same hook, arguments and semantics as
       heml_set_anchors and frm_model_set_anchors): zero-length springs from chosen nodes to
       target points, energy sum_a k_a / 2 |x_a - t_a|^2, part of the model from the call
       on: forces (-k (x - t), formed in double as (rest - t) + u), the stiffness (k I on
       the node: in every K product, so tmass_apply_stiffness, the CG products, the Jacobi
       diagonal and the modal analysis include it), every integrator (explicit ones through
       the force; implicit Euler, its linearised form and BDF2 through force and
       operator; the springs' Newton through residual, tangent and incremental potential),
       the static solves (the springs' saddle check too); tmass_energy's elastic part
       includes them. They belong to K, so stiffness damping (beta > 0) damps them like
       the rest of K (force -beta k v: frames.h's Rayleigh damping does the same; heml.h
       has none); a glued node's damping then acts on its absolute velocity, so keep beta
       small in glued scenes. The arrays are the caller's (kept by pointer, read at every
       evaluation). Off by default: without the call every result is bit-identical. One
       serial loop over the anchors per pass (in order: deterministic), no allocation.
       They are the hook for gluing a mesh to another model without either header
       including the other: the targets are the other model's points (frames.h: mapped
       points of a probe), updated between solves, and the springs' stiffness is inside
       each implicit and static solve (frames.h COUPLING; tests/test_frames_coupling.c
       glues a tensormass.h half of R1 to a frames half: 6 coupling iterations, tip +0.10 %
       of Timoshenko, float +0.00 %, and steps the soft beam glued at dt = 10 ms, stiff
       and staggered, through examples/glue.h's tensormass.h adapter, glue_init_tmass). The precomputed quasi-static model refuses an anchored model
       (tmass_qs_create, tmass_qs_load: TMASS_ERR_ANCHORED): its compliance C = K^-1 and
       preload are fixed at creation, while the anchors' targets move with the other model
       (a moving target is a load on the anchored node, k (t - X), which the precomputed
       preload cannot follow unless every anchored node were a contact node, and k would
       change C). A hybrid model's precomputed part is made inside tmass_hybrid_create and
       never sees anchors; its dynamic part (tmass_hybrid_dynamic_part) is a model like any
       and takes them in its steps and static solve (not tested). Tested
       (tests/test_tensormass.c): force = -grad energy and K d = -df by central
       differences with anchors on both kinds (below 1e-10 relative in double, 3e-6 float); a bar
       held only by anchors of k = 1e4 E h at one end equals the clamped bar statically
       (tip 3.1e-7 m off against a bound of 7.2e-7 m from k and the reactions) and through
       20 implicit steps of each implicit integrator; every integrator keeps the anchored
       equilibrium; bad input refused; no allocation in steps.

   PERFORMANCE: a force evaluation is one pass over the live edges. Per edge it reads two
   int node indices and one 3x3 tensor (8 + 72 = 80 bytes in double, 8 + 36 = 44 in
   float) and the displacements of both ends, and updates the forces of both ends; per
   vertex it touches 3 displacements and 3 forces (zeroed, then accumulated). There is no
   vertex pass: eq. 6 is evaluated in its difference form (see THE MODEL). Edges are sorted
   by their lower vertex and grouped in contiguous chunks, so the tensors stream from
   memory; a run of edges sharing their lower vertex accumulates in registers. Issue 21
   (out of cache the pass fell to 34 % of its bandwidth bound on Zen 5): the force pass
   now forms -K u itself (d = p_a - p_b) instead of negating K u in a second pass over
   the nodes (bit-identical); models of TMASS_PARALLEL_MIN_EDGES edges or more chunk
   their edges in bands of the node numbering run in two colours (tmass__chunk_size),
   where the small chunks' greedy colouring ran 4 colours on a 1e6-tet cube, each
   sweeping all the nodes (summation order changed: forces move by round-off, within
   3e-16 of the largest in double, deterministic for any thread count); and double builds
   with AVX2 and FMA (-march=native on x86-64) run the pass with 4-wide vectors
   (tmass__edge_pass_avx2: the K d sums of a run are formed lane-wise, another rounding
   than the portable loop's, within 1 eps of eq. 6 like it, tested against it). callgrind
   (x86-64-v3 build, cube of 40^3 cells, 320,000 tetrahedra, simulated 2 MB last-level
   cache, per tetrahedron and force evaluation): 79.1 instructions before, 74.9 with the
   fused sign and bands in the portable loop, 61.7 with the AVX2 loop (in cache, 10,985
   tetrahedra: 86.4, 81.8, 67.7); memory lines missed 2.02 before, 1.86 after (129 and
   119 bytes; the stated 110 bytes are 1.72 lines). Interleaved timings (old and new
   programs alternated, 6 to 8 rounds of 10 repeats, CPU-time minima; Intel Xeon,
   Sapphire Rapids class, KVM, 2 vCPUs shared with a load of 7 to 10, gcc 12 -O3
   -march=native, STREAM triad 14.5 to 14.9 GB/s at its quietest; the bench's wall-clock
   rows swung 3x under that load), two runs, each figure the range over both: ns per
   tetrahedron before -> after, after / before, ratio to the bound (time / (stated bytes
   / triad rate)):
       double      1,080 tets  5.28-5.40 -> 3.96-3.97  0.73-0.75  0.57 -> 0.42
                  10,985       4.77-4.84 -> 3.63-3.64  0.75-0.76  0.59 -> 0.44
                 109,760       4.93-5.18 -> 4.48-4.55  0.87-0.92  0.65-0.67 -> 0.58-0.60
               1,026,895       7.42-8.62 -> 7.00-7.01  0.81-0.95  0.99-1.17 -> 0.94-0.95
       float (no vector loop): 1.00 to 1.04 up to 110k tets, 0.91 and 1.01 at 1e6 (ratio
       1.09 to 1.15 there).
   So on this machine the pass runs at 0.94 to 0.95 times its bound out of cache, inside
   the goal's 1.43 (a triad's rate undercounts a pure read stream: reading the tensors
   and indices alone took 0.9 of the bound). The old pass was at 0.99 to 1.17 here by the
   same minima: the 2.92 of the Zen 5 run is not reproduced on this machine, where a core
   streams 15 GB/s against Zen 5's 32 and the arithmetic hides under the memory time. On
   Zen 5 the in-cache arithmetic (5.4 ns a tetrahedron there, above its 1e6 bound of 3.3)
   is what the vector loop cuts; whether the goal is met there is for the next full bench
   to say. Tried and not kept: prefetch distances of 12, 64 and 128 edges (none at all is
   1.4 times slower out of cache; the others within the noise of 24). Not done: folding
   the zeroing of the forces into the bands (each even chunk zeroing its own and the next
   odd chunk's nodes before its sweep) would save the memset's 24 bytes per node, about
   5 % of the traffic; a float vector loop (float is at its bound in cache already). What
   bounds it now: out of cache the tensor stream; in cache the arithmetic and the
   scattered updates of p_b's forces. Before issue 21, measured on
   an AMD EPYC (Zen 5) core, gcc -O3 -march=native, double, beam meshes of 768 to 768,000
   tetrahedra: 3.4 to 3.6 ns per edge (4.1 to 5.1 ns per tetrahedron), 1.5 to 1.6 times the
   time to stream the 80 bytes per edge at the STREAM triad rate measured in the same run
   (1.2 to 1.4 times when the vertex traffic is counted too). In ISO mode (-std=c99) gcc
   does not contract multiply-adds into FMAs and the loop is about 8 % slower. The spring
   force reads less (40 bytes per edge) but computes a square root and a division per
   edge (k (l - l0) / l = k (l^2 - l0^2) / ((l + l0) l); damping adds one): in blocks of
   32 edges a vectorised loop forms the force factors, a second one scatters them; about 1.4 times the tensor pass per edge (9 ns against 6.4 ns on a
   25,600-tet beam in one run), compute-bound, not memory-bound. Removing a
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
         the mesh across thin parts; a bending beam needs several tets across. Volumetric
         locking is not refinement-friendly: at nu = 0.499 a beam 3 cells across split
         into six tetrahedra per cell comes out 95 % too stiff (heml's P1 tetrahedra, the
         same stiffness at small strain), and Cook's membrane (REFERENCES R10) converges
         to the wrong value. For nearly incompressible tissue use heml.h with
         desc.nodal_pressure = 1 (average nodal pressure tetrahedra: the same mesh within
         1 % for both splits on Cook's membrane; see its NEAR-INCOMPRESSIBLE BODIES).
         Why tensormass.h has no such option: the linear form of the average nodal
         pressure replaces each tetrahedron's bulk term by sum_a V_a K (div u)_a^2 with
         (div u)_a the volume-weighted mean of the divergence over node a's tetrahedra, a
         row that reaches every node of every tetrahedron at a. Its stiffness couples
         nodes two edges apart (through the shared node a), which the tensor-mass form
         (one 3x3 tensor per vertex and per mesh edge, updated locally by a cut) cannot
         hold: it would need a second, matrix-free pass (a scalar gather and scatter per
         node, as heml.h does) besides the edge pass, in the dynamic, static,
         quasi-static and hybrid solvers alike, and the precomputed quasi-static inverse
         would lose its locality. Cutting itself would survive (a removed tetrahedron
         subtracts its volume from its four nodes' V_a), so the obstacle is the edge
         structure and the precomputation, not topology changes; not done.
       - The explicit integrators are conditionally stable (semi-implicit Euler for
         dt < 2 / w_max, RK4 about 2.8 / w_max; explicit Euler grows every undamped mode
         at any dt). A blow-up is stopped by the divergence check (TMASS_ERR_DIVERGED,
         state kept) once an edge is stretched past desc.divergence_strain (100 %): at
         dt = 10 s on a 1 GPa block at the first or second step. Below that bound an
         explicit Euler run at a stable-looking dt can grow (29-fold in energy in the
         test before the check trips): explicit Euler is for teaching and comparison.
       - Precision: the state is u = x - X, and forces use differences of u and of rest
         positions (the latter formed in double): a body whose rest mesh lies 1e6 m from
         the origin is exact in float (tested). A body that has travelled far from its
         rest position carries a large u, whose rounding eps |u| fakes strains
         eps |u| / h; steps and static solves refuse it with TMASS_ERR_PRECISION once
         eps |u| > precision_limit h_min (default 1e-4: in float with 0.25 m edges from
         |u| of about 200 m; in double never in practice). Re-create the model at the new
         place, or use double. Float also cannot represent a step that moves the body by
         less than eps |u|: at dt = 1e-6 s a float body may not move at all.
       - Near incompressibility in float: the tensors are stored in tmass_real, and
         rounding them perturbs the shear (bending) stiffness by about eps lambda / mu,
         which a nearly incompressible body amplifies. Float builds refuse eps lambda / mu
         > 1e-4, nu > 0.4994, at creation (TMASS_ERR_POISSON_RATIO; double: nu >
         0.5 - 1e-12, never in practice). Measured on a 1 x 0.1 x 0.1 m beam of 20 x 2 x 2
         five-tet cells against a double P1 solve of the same mesh: at nu = 0.4999 the
         float-stored K, solved exactly, is 1.8 % off at the tip, and float's static
         solve and damped implicit steps returned success 1.1 % off (their CG also cannot
         resolve it: the true residual was 55 |b| when CG's recursive one read 8.6e-6).
         At nu = 0.499 float is within 0.05 % (0.2 % at 40 x 4 x 4 cells), at 0.45 within
         0.007 %. No check on a single solve can catch this: an implicit step's matrix
         M + dt^2 K is well conditioned, and the steps converge to the float K's
         equilibrium. stats.cg_condition reports a lower bound of the Jacobi-scaled
         condition number (Rayleigh quotients of CG's directions) for information; it
         underestimates by 30 to 200 times and is not used to refuse anything.
       - Tetrahedra inverted by a large load are counted (stats.inverted) but not refused
         by the linear model (see SOLVERS).
       - Inactive (cut-off) vertices keep their last position and do not move.
       - Quasi-static and hybrid: the precomputed part is static (no inertia), linear, and
         its topology is frozen; pinned nodes driven away from rest (tmass_set_displacement
         before tmass_qs_create) are part of the preload; contacts on it enter the dynamic solve with a one-step
         lag. Memory grows as |P| x |output| (about 19.5 MB for 531 precomputed nodes
         with every node output, in double; examples/tensormass_hybrid.c).

   HISTORY
       unreleased (issue 21) the tensor model's implicit steps add a coarse correction to
             their Jacobi CG (desc.implicit_coarse: 0 automatic, 1, -1; SOLVERS):
             tmass_stats gains coarse_solves and coarse_factors, the model block up to
             2.4 MB (MEMORY). Results change within the CG tolerance where it is on;
             with -1, or while the automatic mode has not switched, bit-identical.
       unreleased (issue 14) tmass_set_anchors (springs from nodes to caller-owned targets,
             as heml.h and frames.h), tmass_apply_stiffness (the public K v),
             TMASS_ERR_ANCHORED (the quasi-static precomputation of an anchored model).
             Results without anchors bit-identical.
       unreleased (issue 19) TMASS_BDF2 (second-order implicit, the implicit Euler
             minimisation reused); the model block grows by 2 vectors of 3n reals (BDF2's
             history, 48 bytes per node in double). Modal analysis (tmass_modal_*), point
             probes (tmass_probe_*), tmass_displacements, tmass_set_damping,
             TMASS_ERR_PROBE_OUTSIDE; the
             kinds table gains a tangent column, the integrators table keeps_history.
       unreleased (issue 20) explicit extension points, results bit-identical: the
             private tables tmass__kinds, tmass__integrators, tmass__linear_solvers (see
             HOW TO EXTEND); TMASS_MODEL_KIND_COUNT, TMASS_INTEGRATOR_COUNT,
             tmass_linear_solver and desc.linear_solver; work vectors named by role, CG
             with its own (the model block grows by 5 vectors of 3n reals, 120 bytes per
             node in double); tmass_create and tmass_hybrid_create in named stages.
       unreleased (issue 18) no silent wrong answers: an implicit step after driving a node
             counted the node's move twice (free nodes 2x the static answer at long dt);
             the quasi-static preload ignored pinned nodes away from rest; CG at its cap,
             and loads whose |b|^2 overflows, returned success; a garbage desc crashed in
             its log callback; duplicated tetrahedra were accepted; explicit blow-ups ran
             to 1e305 m with success. New: TMASS_ERR_TET_DUPLICATE, _DIVERGED, _PRECISION;
             desc fields newton_iterations, newton_tolerance, divergence_strain,
             precision_limit; TMASS_IMPLICIT_EULER_LINEARIZED; springs' static
             continuation and Newton implicit Euler; the common stats struct; every
             entry point renamed in float builds. Float builds refuse nu > 0.4994 (the
             float-stored tensors were 1-2 % off at nu = 0.4999, with success codes);
             stats.cg_condition.
       0.2.0 (2026-12-01) precomputed quasi-static model (save/load, progress) and the
             hybrid model; compliance columns precomputed 8 per CG sweep. Springs: the
             stretch without cancellation (float static solves of stiff meshes used to
             stall at round-off), the static Newton on the full tangent with a line
             search (a 180 degree twist converges in 6 iterations per increment instead
             of 48, or not at all within the cap of 50); the spring force pass in two
             loops, the first vectorised (about twice as fast).
       0.1.0 (2026-11-22) first release: tensor-mass and mass-spring models, four
             integrators, static solve, cutting, tearing.

   Licence at the end of the file. */
#ifndef TENSORMASS_H
#define TENSORMASS_H

#include <stddef.h>

#define TMASS_VERSION_MAJOR 0
#define TMASS_VERSION_MINOR 2
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

/* Float builds rename every public entry point (..._f32) so that a float and a double
   translation unit cannot be linked together by mistake (a float program calling any
   tmass_ function fails to link against a double build). TMASS_REAL must be the single
   token float or double. tests/test_tensormass.c lists every name and checks it. */
#define TMASS__IS_float 1
#define TMASS__IS_double 0
#define TMASS__CAT2(a, b) a##b
#define TMASS__CAT(a, b) TMASS__CAT2(a, b)
#if TMASS__CAT(TMASS__IS_, TMASS_REAL)
#define tmass_version tmass_version_f32
#define tmass_error_string tmass_error_string_f32
#define tmass_default_desc tmass_default_desc_f32
#define tmass_create tmass_create_f32
#define tmass_destroy tmass_destroy_f32
#define tmass_fix_node tmass_fix_node_f32
#define tmass_set_displacement tmass_set_displacement_f32
#define tmass_release_node tmass_release_node_f32
#define tmass_node_pinned tmass_node_pinned_f32
#define tmass_set_external_force tmass_set_external_force_f32
#define tmass_clear_external_forces tmass_clear_external_forces_f32
#define tmass_set_gravity tmass_set_gravity_f32
#define tmass_set_damping tmass_set_damping_f32
#define tmass_set_solver tmass_set_solver_f32
#define tmass_set_anchors tmass_set_anchors_f32
#define tmass_apply_stiffness tmass_apply_stiffness_f32
#define tmass_step tmass_step_f32
#define tmass_step_ex tmass_step_ex_f32
#define tmass_solve_static tmass_solve_static_f32
#define tmass_node_count tmass_node_count_f32
#define tmass_tet_count tmass_tet_count_f32
#define tmass_live_tet_count tmass_live_tet_count_f32
#define tmass_edge_count tmass_edge_count_f32
#define tmass_positions tmass_positions_f32
#define tmass_displacements tmass_displacements_f32
#define tmass_probe_create tmass_probe_create_f32
#define tmass_probe_positions tmass_probe_positions_f32
#define tmass_probe_displacements tmass_probe_displacements_f32
#define tmass_probe_velocities tmass_probe_velocities_f32
#define tmass_probe_destroy tmass_probe_destroy_f32
#define tmass_modal_default_desc tmass_modal_default_desc_f32
#define tmass_modal_create tmass_modal_create_f32
#define tmass_modal_solve tmass_modal_solve_f32
#define tmass_modal_count tmass_modal_count_f32
#define tmass_modal_frequency tmass_modal_frequency_f32
#define tmass_modal_shape tmass_modal_shape_f32
#define tmass_modal_destroy tmass_modal_destroy_f32
#define tmass_velocities tmass_velocities_f32
#define tmass_rest_positions tmass_rest_positions_f32
#define tmass_masses tmass_masses_f32
#define tmass_forces tmass_forces_f32
#define tmass_set_positions tmass_set_positions_f32
#define tmass_set_velocities tmass_set_velocities_f32
#define tmass_last_stats tmass_last_stats_f32
#define tmass_energy tmass_energy_f32
#define tmass_remove_tets tmass_remove_tets_f32
#define tmass_default_tear_criteria tmass_default_tear_criteria_f32
#define tmass_tear tmass_tear_f32
#define tmass_tet_deformation tmass_tet_deformation_f32
#define tmass_tet_alive tmass_tet_alive_f32
#define tmass_node_active tmass_node_active_f32
#define tmass_boundary_triangles tmass_boundary_triangles_f32
#define tmass_vertex_tensor tmass_vertex_tensor_f32
#define tmass_edge_tensor tmass_edge_tensor_f32
#define tmass_memory_bytes tmass_memory_bytes_f32
#define tmass_qs_default_desc tmass_qs_default_desc_f32
#define tmass_qs_create tmass_qs_create_f32
#define tmass_qs_destroy tmass_qs_destroy_f32
#define tmass_qs_update tmass_qs_update_f32
#define tmass_qs_displacements tmass_qs_displacements_f32
#define tmass_qs_positions tmass_qs_positions_f32
#define tmass_qs_nodes tmass_qs_nodes_f32
#define tmass_qs_memory_bytes tmass_qs_memory_bytes_f32
#define tmass_qs_remove_tets tmass_qs_remove_tets_f32
#define tmass_qs_save tmass_qs_save_f32
#define tmass_qs_load tmass_qs_load_f32
#define tmass_qs_save_memory tmass_qs_save_memory_f32
#define tmass_qs_load_memory tmass_qs_load_memory_f32
#define tmass_hybrid_default_desc tmass_hybrid_default_desc_f32
#define tmass_hybrid_create tmass_hybrid_create_f32
#define tmass_hybrid_destroy tmass_hybrid_destroy_f32
#define tmass_hybrid_step tmass_hybrid_step_f32
#define tmass_hybrid_step_ex tmass_hybrid_step_ex_f32
#define tmass_hybrid_solve_static tmass_hybrid_solve_static_f32
#define tmass_hybrid_set_displacement tmass_hybrid_set_displacement_f32
#define tmass_hybrid_release_node tmass_hybrid_release_node_f32
#define tmass_hybrid_contact_force tmass_hybrid_contact_force_f32
#define tmass_hybrid_remove_tets tmass_hybrid_remove_tets_f32
#define tmass_hybrid_tear tmass_hybrid_tear_f32
#define tmass_hybrid_positions tmass_hybrid_positions_f32
#define tmass_hybrid_boundary_triangles tmass_hybrid_boundary_triangles_f32
#define tmass_hybrid_dynamic_part tmass_hybrid_dynamic_part_f32
#define tmass_hybrid_precomputed_part tmass_hybrid_precomputed_part_f32
#define tmass_hybrid_connection_count tmass_hybrid_connection_count_f32
#endif

/* Edges below which loops run serially (parallel start-up costs more than it saves). */
#ifndef TMASS_PARALLEL_MIN_EDGES
#define TMASS_PARALLEL_MIN_EDGES 20000
#endif

/* The least memory traffic of one force evaluation (tmass_forces), for bandwidth bounds
   (the bench divides it by a measured STREAM rate): per live edge the two node indices and
   the data of the edge; per node its displacement read and its force written (springs
   also read the rest position). Tensor-mass: the 3x3 edge tensor (80 bytes per edge in
   double, 44 in float); springs: stiffness and rest length. */
#define TMASS_FORCE_BYTES_PER_EDGE (2 * sizeof(int) + 9 * sizeof(tmass_real))
#define TMASS_FORCE_BYTES_PER_NODE (6 * sizeof(tmass_real))
#define TMASS_SPRING_BYTES_PER_EDGE (2 * sizeof(int) + 2 * sizeof(tmass_real))
#define TMASS_SPRING_BYTES_PER_NODE (9 * sizeof(tmass_real))

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
    X(TMASS_ERR_POISSON_RATIO, -13, "Poisson ratio outside (-1, 0.5), or too close to 0.5 for float (above 0.4994)") \
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
    X(TMASS_ERR_NO_EDGE, -25, "the two nodes share no edge") \
    X(TMASS_ERR_PRECOMPUTED, -26, "a precomputed (quasi-static) model or part cannot change topology") \
    X(TMASS_ERR_NOT_PRECOMPUTED, -27, "node has no precomputed response (not one of the precomputed nodes)") \
    X(TMASS_ERR_NODE_PINNED, -28, "node is pinned (a fixed boundary condition)") \
    X(TMASS_ERR_CONTACTS, -29, "too many contact nodes, or one listed twice") \
    X(TMASS_ERR_SINGULAR, -30, "singular system (contacts or connections not independent)") \
    X(TMASS_ERR_CANCELLED, -31, "precomputation cancelled by the progress callback") \
    X(TMASS_ERR_FILE_IO, -32, "file could not be opened, read or written") \
    X(TMASS_ERR_FILE_FORMAT, -33, "not a precomputation file, or its contents are corrupted") \
    X(TMASS_ERR_FILE_VERSION, -34, "precomputation file of another format version or real type") \
    X(TMASS_ERR_FILE_MISMATCH, -35, "precomputation file made for another mesh, material or setting") \
    X(TMASS_ERR_FILE_TRUNCATED, -36, "precomputation file or buffer is truncated") \
    X(TMASS_ERR_TET_DUPLICATE, -37, "the same tetrahedron (same four nodes, any order) is listed twice") \
    X(TMASS_ERR_DIVERGED, -38, "explicit step diverged (an edge stretched past divergence_strain); the last valid state was kept") \
    X(TMASS_ERR_PRECISION, -39, "displacements too large for the precision of tmass_real relative to the smallest edge; the last valid state was kept") \
    X(TMASS_ERR_UNSTABLE, -40, "static solve (spring model) converged to a saddle (an unstable equilibrium: the tangent has a direction of negative curvature); the last valid state was kept") \
    X(TMASS_ERR_PROBE_OUTSIDE, -41, "probe point outside every tetrahedron of the mesh (or its tetrahedron was cut away)") \
    X(TMASS_ERR_ANCHORED, -42, "a model with anchors (tmass_set_anchors) cannot be precomputed: the quasi-static compliance and preload are fixed at creation, the anchors' targets move")

enum {
#define TMASS__ENUM(name, value, text) name = value,
    TMASS_ERROR_LIST(TMASS__ENUM)
#undef TMASS__ENUM
    TMASS_ERR_LAST_ = -43
};

typedef enum tmass_model_kind {
    TMASS_TENSOR_MASS = 0, /* linear elasticity, Cotin et al. eqs. 5-6 (default) */
    TMASS_MASS_SPRING = 1, /* springs on the mesh edges, eq. 7 (baseline) */
    TMASS_MODEL_KIND_COUNT /* number of kinds (validation), not a kind */
} tmass_model_kind;

typedef enum tmass_integrator {
    TMASS_EXPLICIT_EULER = 0,
    TMASS_SEMI_IMPLICIT_EULER = 1,
    TMASS_RK4 = 2,
    TMASS_IMPLICIT_EULER = 3,            /* springs: Newton on the incremental potential */
    TMASS_IMPLICIT_EULER_LINEARIZED = 4, /* one linearised Newton iteration (see INTEGRATORS) */
    TMASS_BDF2 = 5,                      /* second-order backward differentiation (see INTEGRATORS) */
    TMASS_INTEGRATOR_COUNT               /* number of integrators (validation), not one */
} tmass_integrator;

/* The solver of every linear system (static solve, implicit steps, Newton iterations,
   quasi-static precomputation). */
typedef enum tmass_linear_solver {
    TMASS_LINEAR_SOLVER_CG = 0, /* Jacobi-preconditioned conjugate gradient (SOLVERS) */
    TMASS_LINEAR_SOLVER_COUNT   /* number of solvers (validation), not one */
} tmass_linear_solver;

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
    tmass_real poisson_ratio;             /* in (-1, 0.5) (float: <= 0.4994, LIMITS), default 0.3 */
    const tmass_real *tet_young_modulus;  /* optional per-tet Pa (tet_count values) or NULL */
    const tmass_real *tet_poisson_ratio;  /* optional per-tet ratio or NULL */
    tmass_real density;                   /* kg/m^3, default 1000 */
    tmass_real mass_damping;              /* Rayleigh alpha, 1/s, default 0 */
    tmass_real stiffness_damping;         /* Rayleigh beta, s, default 0 */

    /* dynamics */
    tmass_real gravity[3];       /* m/s^2, default (0, 0, -9.81) */
    tmass_real time_step;        /* s, default 1e-3, used by tmass_step */
    tmass_integrator integrator; /* default TMASS_IMPLICIT_EULER */
    tmass_linear_solver linear_solver; /* default TMASS_LINEAR_SOLVER_CG */
    tmass_real cg_tolerance;     /* relative residual of CG solves, default 1e-6 (1e-5 float) */
    int cg_max_iterations;       /* default 2000 */
    int implicit_coarse;         /* the tensor model's implicit steps (implicit Euler, its
                                    linearised form, BDF2): 0 (default) add a coarse
                                    correction to Jacobi once a step's CG needed
                                    TMASS__COARSE_MIN_ITERATIONS (20); 1 always; -1 never
                                    (nothing allocated for it). Meshes under 96 nodes and
                                    the spring model have none (SOLVERS) */

    /* Newton solves: the springs' implicit Euler step (TMASS_IMPLICIT_EULER) and static
       solve; the tensor model is linear and needs one linear solve */
    int newton_iterations;       /* cap per implicit step or static load increment, default 20 */
    tmass_real newton_tolerance; /* residual over its reference scale, default 1e-6 (1e-5
                                    float); a residual at its round-off floor is accepted too
                                    (see SOLVERS) */

    /* failure checks (see ERRORS and LIMITS) */
    tmass_real divergence_strain; /* explicit integrators: a step that stretches any edge by
                                     more than this relative elongation fails with
                                     TMASS_ERR_DIVERGED, default 1 (100 %); 0 disables */
    tmass_real precision_limit;   /* steps and static solves fail with TMASS_ERR_PRECISION when
                                     eps(tmass_real) * max|u| > precision_limit * shortest rest
                                     edge (u = x - X), default 1e-4; 0 disables */

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
    int newton_iterations;  /* Newton iterations, summed over increments (1 for a linear
                               solve or a linearised step, 0 for an explicit step) */
    int cg_iterations;      /* CG iterations, summed over every linear solve of the call */
    tmass_real cg_residual; /* relative residual |r| / |b| of the last linear solve */
    tmass_real residual;    /* final nonlinear residual |f| over its reference scale (the
                               springs' static solve: |f| / |f_0|, f_0 the residual at the
                               start); 0 where there is none (linear model, steps) */
    int increments;         /* load increments accepted (1: the whole load at once) */
    int increment_cuts;     /* increments cut back after a failed attempt */
    int line_search_cuts;   /* line-search step halvings, summed */
    int negative_curvature; /* linear solves that met a direction with p . A p <= 0 */
    int inverted;           /* live tetrahedra with non-positive volume at the end (static
                               solves and implicit steps; explicit steps do not count: 0) */
    int force_evaluations;  /* force passes (elastic force or spring force + tangent) */
    int stiffness_products; /* K times vector products (CG iterations and setup) */
    tmass_real cg_condition; /* (tensormass extra) estimated condition number of the
                                Jacobi-scaled matrix, largest over the call's linear
                                solves; a lower bound, see SOLVERS and LIMITS) */
    int coarse_solves;      /* implicit steps: CG solves preconditioned with the coarse
                               correction (desc.implicit_coarse; SOLVERS) */
    int coarse_factors;     /* implicit steps: factorisations of its coarse matrix (0 when the
                               last one was reused: same dt, masses, pins and mesh) */
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
/* Rayleigh damping after creation (as desc.mass_damping, 1/s, and desc.stiffness_damping,
   s; finite and >= 0, else TMASS_ERR_DAMPING and nothing changes), for later steps. Like
   frm_model_set_damping (frames.h) and heml_set_mass_damping (heml.h). */
TMASSDEF int tmass_set_damping(tmass_model *m, tmass_real mass_damping, tmass_real stiffness_damping);
/* CG tolerance (relative residual, > 0) and iteration cap (>= 1) for later solves. */
TMASSDEF int tmass_set_solver(tmass_model *m, tmass_real tolerance, int max_iterations);
/* Anchors (issue 14; the same hook, arguments and semantics as heml_set_anchors and
   frm_model_set_anchors): zero-length springs from nodes[a] to the point targets[3a..3a+2]
   (m) with stiffness stiffness[a] (N/m, >= 0), energy sum_a k_a / 2 |x_nodes[a] - t_a|^2.
   They are part of the model from then on, exactly (force -k (x - t), stiffness k I on the
   node): every force (tmass_forces, the integrators' accelerations), energy (tmass_energy's
   elastic part), stiffness product (tmass_apply_stiffness, the CG products and its Jacobi
   preconditioner), static solve, step of every integrator and modal analysis. They belong
   to K, so stiffness damping (beta > 0) damps them like the rest of K (force -beta k v, as
   in frames.h; heml.h has no stiffness damping). This is how a mesh is glued to another
   model (frames.h COUPLING: the targets are the other model's mapped points, updated
   between solves). The three arrays are the caller's: kept by pointer and read at every
   evaluation until the next call, so they must outlive the model's use of them (update
   targets or stiffnesses in place, or call again). count = 0 removes every anchor (the
   arrays may then be NULL); default none (results bit-identical to a model without the
   call). A node may carry several anchors (they add). No allocation. The precomputed
   quasi-static model refuses an anchored model (tmass_qs_create, tmass_qs_load:
   TMASS_ERR_ANCHORED; see ANCHORS). Errors (nothing kept): TMASS_ERR_ARG (NULL model or
   array, count < 0, a stiffness negative or not finite, a target not finite),
   TMASS_ERR_NODE_RANGE (a node index). */
TMASSDEF int tmass_set_anchors(tmass_model *m, int count, const int *nodes, const tmass_real *stiffness,
                               const tmass_real *targets);

/* ---- simulation ---- */

/* One step with the description's time step and integrator. */
TMASSDEF int tmass_step(tmass_model *m);
/* One step of dt seconds with the given integrator. On any error the state is unchanged
   (ERRORS). */
TMASSDEF int tmass_step_ex(tmass_model *m, tmass_real dt, tmass_integrator integrator);
/* Moves the free nodes to the static equilibrium under gravity, external forces and the
   pinned nodes, and sets velocities to zero. Tensor-mass: one CG solve (the model is
   linear). Springs: load continuation, each increment Newton (at most newton_iterations)
   with a CG solve each on the full tangent (on its positive-definite part where
   compressed springs make it indefinite) and a backtracking line search (see SOLVERS).
   On failure (TMASS_ERR_NO_CONVERGENCE: a CG cap, a singular problem such as nothing
   pinned, or the continuation giving up; TMASS_ERR_NOT_FINITE; TMASS_ERR_PRECISION) the
   state is unchanged. A spring model's answer must be a minimum: a probe CG solve with
   the full tangent at it (to 1e-7, float 1e-5) that meets negative curvature beyond
   round-off fails the solve with TMASS_ERR_UNSTABLE (a saddle; state unchanged). It costs
   one more CG solve; the tensor model is linear and needs no probe (its K is constant). */
TMASSDEF int tmass_solve_static(tmass_model *m);

/* ---- state access (pointers into the model, valid until tmass_destroy) ---- */

TMASSDEF int tmass_node_count(const tmass_model *m);
TMASSDEF int tmass_tet_count(const tmass_model *m);           /* as in the description */
TMASSDEF int tmass_live_tet_count(const tmass_model *m);      /* not removed */
TMASSDEF int tmass_edge_count(const tmass_model *m);          /* live edges */
TMASSDEF const tmass_real *tmass_positions(const tmass_model *m);      /* 3n, m */
TMASSDEF const tmass_real *tmass_displacements(const tmass_model *m);  /* 3n, m: u = x - X, the
                                                                          state itself (exact far
                                                                          from the origin) */
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
/* The stiffness product at the current state: out = K dx = -(df/dx) dx (3n values each,
   N for dx in m; out overwritten, caller-owned), every node included (pinned or not).
   Tensor-mass: the constant K; springs: the full tangent at the current displacement
   (compressed springs' negative geometric term included; it overwrites the tensors the
   solvers rebuild anyway). Anchors included. Stiffness damping plays no part. Sign as
   frm_model_apply_stiffness (K v); heml_apply_stiffness returns the force differential
   (df/dx) dx, the opposite sign. One pass over the edges, no allocation. */
TMASSDEF int tmass_apply_stiffness(tmass_model *m, const tmass_real *dx, tmass_real *out);
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

/* ---- point probes (issue 19) ----

   Displacement, position and velocity at material points that need not be nodes (a
   beam's tip centre, sensors, markers), given by their rest positions: each point's
   containing tetrahedron and barycentric weights w are found once, at creation, and
   every read is the P1 interpolation u(p) = sum_j w_j u_j over its four nodes (the
   model's own displacement field, exact for it). A point on a face or edge shared by
   several tetrahedra takes the one it is most inside (the largest smallest weight,
   lowest index on ties: deterministic); a point outside every tetrahedron by more than
   1e-6 of a weight (about 1e-6 of the tetrahedron's size) is refused with
   TMASS_ERR_PROBE_OUTSIDE, one just outside within that tolerance (round-off on the
   boundary) takes its nearest tetrahedron. */
typedef struct tmass_probe tmass_probe;

/* Locates `count` points (3 * count rest coordinates, m) in the live tetrahedra of m.
   Allocates one block through m's allocator (and a temporary uniform grid over the
   tetrahedra, about one cell each, freed before returning); cost O(tetrahedra + count x
   tetrahedra per cell), a point outside the mesh O(tetrahedra) (its check scans all).
   Fails with TMASS_ERR_PROBE_OUTSIDE (nothing left allocated) when a point lies outside
   the mesh. Measured: 20,000 points in 24,000 tetrahedra located in 20 ms; reading their
   positions 0.2 ms (one core, double). The probe is read-only afterwards and may be used from several
   threads. */
TMASSDEF int tmass_probe_create(const tmass_model *m, const tmass_real *rest_points, int count,
                                tmass_probe **out);
/* 3 * count values each, written to out (m, m, m/s), for the model the probe was made
   for (TMASS_ERR_ARG for a model with another node count). Positions are the rest point
   plus the interpolated displacement. A tetrahedron cut away since creation: its point
   still follows the four nodes (which may be inactive, frozen) and the call returns
   TMASS_ERR_PROBE_OUTSIDE after writing every point. No allocation. */
TMASSDEF int tmass_probe_positions(const tmass_probe *p, const tmass_model *m, tmass_real *out);
TMASSDEF int tmass_probe_displacements(const tmass_probe *p, const tmass_model *m, tmass_real *out);
TMASSDEF int tmass_probe_velocities(const tmass_probe *p, const tmass_model *m, tmass_real *out);
/* Frees the probe. NULL is allowed. */
TMASSDEF void tmass_probe_destroy(tmass_probe *p);

/* ---- modal analysis (issue 19) ----

   The lowest `count` natural frequencies and mode shapes of a model about its current
   state, with its pinned nodes held: K phi = lambda M phi on the free degrees of freedom,
   f = sqrt(lambda) / (2 pi). K is the tensor model's stiffness (constant), or the
   springs' full tangent at the current displacement (which may be indefinite under
   compression: the solve then fails); M the lumped masses. Stiffness damping and gravity
   play no part. Matrix-free: block shift-invert subspace iteration with Rayleigh-Ritz
   (Bathe's subspace iteration), a block of q = min(free dofs, max(2 count, count + 8))
   vectors, each iteration q solves (K + shift M) y = M x through the model's linear
   solver (Jacobi CG) and q stiffness products, then the q x q projected problem
   (Cholesky and Jacobi rotations, in double). The shift makes K + shift M definite, so
   free bodies work: their rigid modes come out at 0 Hz (within round-off, reported as
   sqrt(max(lambda, 0))). Converged when every wanted pair has
   |K phi - lambda M phi|_{M^-1} <= tolerance (lambda + shift) + 30 eps(tmass_real) k_max,
   k_max the largest K_ii / m_i (the second term is the round-off of K phi: it matters in
   float only). The inner solves run to 1e-10 (float 1e-5) with at least 10,000
   iterations; stats.newton_iterations reports the subspace iterations. Deterministic
   (fixed pseudo-random start). Measured on the R3 beam (1 x 0.1 x 0.1 m clamped,
   E = 1 MPa, nu = 0.3; 3D reference 0.5091 Hz first bending): 0.6592 Hz on 20 x 2 x 2
   six-tet cells, 0.5830 on 30 x 3 x 3, 0.5528 on 40 x 4 x 4 (+29, +15, +8.6 %: linear
   tetrahedra lock in bending, the error falls as h^2), first axial 7.9644 / 7.9495 /
   7.9428 Hz against 7.9276; no mode below the first bending one. A dense eigen-solve of
   the same discrete problem agrees to 1e-10 (tests). Cost: about 8 subspace iterations
   of q solves for count 6 (about 0.5 s on 30 x 3 x 3 cells, 1620 tets, one core). */
typedef struct tmass_modal tmass_modal;

typedef struct tmass_modal_desc {
    int count;            /* modes wanted, default 6 */
    int max_iterations;   /* subspace iterations, default 200 */
    tmass_real tolerance; /* relative eigen-residual, default 1e-8 (float 1e-4) */
    tmass_real shift;     /* 1/s^2; 0 (default): automatic, 1e-6 (float 1e-4) times the
                             largest K_ii / m_i of the free degrees of freedom (about the
                             top of the spectrum); > 0: that value */
    unsigned int internal_cookie;
} tmass_modal_desc;

TMASSDEF tmass_modal_desc tmass_modal_default_desc(void);
/* Sizes and allocates the workspace (through m's allocator, one block: about 3 q vectors
   of 3n reals plus the q x q matrices) for models with m's node count. */
TMASSDEF int tmass_modal_create(const tmass_model *m, const tmass_modal_desc *d, tmass_modal **out);
/* Solves about m's current state and pins. No allocation; m's state (positions,
   velocities, pins) is not changed; its statistics are those of the last inner solve
   (stats.cg_iterations summed). TMASS_ERR_ARG (another node count, or fewer free degrees
   of freedom than count), TMASS_ERR_NO_CONVERGENCE (max_iterations reached, or an inner
   solve failed: an indefinite tangent), TMASS_ERR_NOT_FINITE; on failure
   tmass_modal_count is 0. */
TMASSDEF int tmass_modal_solve(tmass_modal *md, tmass_model *m);
/* Modes of the last successful solve (0 before). */
TMASSDEF int tmass_modal_count(const tmass_modal *md);
/* Frequency of mode i, Hz, ascending; -1 out of range. */
TMASSDEF double tmass_modal_frequency(const tmass_modal *md, int i);
/* Shape of mode i: 3n values per degree of freedom (zero on pinned nodes), M-orthonormal
   (phi_i^T M phi_j = delta_ij); NULL out of range. Valid until the next solve. */
TMASSDEF const tmass_real *tmass_modal_shape(const tmass_modal *md, int i);
TMASSDEF void tmass_modal_destroy(tmass_modal *md);

/* ---- precomputed quasi-static model (Cotin et al. sec. 4) ----

   Precomputes, with its pinned nodes as fixed boundary conditions, the static response of
   a tensor-mass model to a unit force on each precomputed node in each direction (one CG
   solve each: the columns of the compliance C = K^-1 restricted to the output nodes), and
   its static displacement g under gravity, the external forces and the pinned nodes'
   targets (the preload). At run
   time, imposed displacements u_I on a few contact nodes I give the contact forces f by
   the small dense system C_II f = u_I - g_I (Cholesky), then every output node's
   displacement u = g + C_{.,I} f: the imposed displacements are met exactly, and the cost
   is 9 |I| |output nodes| multiply-adds plus (3 |I|)^3 / 3 for the solve. No allocation
   per update. The model is linear and its topology is frozen (sec. 4: changing the mesh
   would need a new precomputation). */
typedef struct tmass_qs tmass_qs;

typedef struct tmass_qs_desc {
    const int *nodes;     /* nodes to precompute (contact candidates, output), or NULL for
                             every node of the boundary triangles that is not pinned */
    int node_count;
    int all_nodes;        /* 0 (default): displacements are updated at the precomputed nodes;
                             1: at every node (memory and update cost grow to 9 n per
                             precomputed node instead of 9 |nodes|) */
    int max_contacts;     /* most contact nodes in one update, default 16 */
    tmass_real cg_tolerance; /* relative residual of each solve, default 1e-10 (1e-6 float) */
    int cg_max_iterations;   /* default 20000 */
    int (*progress)(int done, int total, void *user); /* solves done of total, called
                                                         after the preload and after each
                                                         block of 8 solves; return non-zero
                                                         to cancel. May be NULL */
    void *progress_user;
    tmass_allocator allocator; /* NULL entries: TMASS_MALLOC / TMASS_FREE */
    unsigned int internal_cookie;
} tmass_qs_desc;

/* Defaults as documented in the fields. */
TMASSDEF tmass_qs_desc tmass_qs_default_desc(void);
/* Precomputes the quasi-static model of the tensor-mass model m (its mesh, material, pinned
   nodes, gravity and external forces at this moment). Costs 3 * |nodes| + 1 CG solves,
   run 8 at a time so that each K product serves eight; uses m's work vectors and a
   temporary block of 6 x 8 vectors (freed before returning) and leaves m's state
   unchanged. */
TMASSDEF int tmass_qs_create(tmass_model *m, const tmass_qs_desc *d, tmass_qs **out);
TMASSDEF void tmass_qs_destroy(tmass_qs *qs);
/* Imposes displacements (3 * count, m, from rest) on `count` precomputed nodes (the rest
   are free) and updates the displacements; forces (3 * count, may be NULL) receives the
   force applied to the body at each contact node to hold it there, N (the reaction a
   haptic tool feels is its opposite). count = 0 gives the preload. */
TMASSDEF int tmass_qs_update(tmass_qs *qs, const int *nodes, const tmass_real *displacements,
                             int count, tmass_real *forces);
/* Displacements and positions of every node (3n), valid after create/load and each
   update; nodes outside the output set keep the preload. */
TMASSDEF const tmass_real *tmass_qs_displacements(const tmass_qs *qs);
TMASSDEF const tmass_real *tmass_qs_positions(const tmass_qs *qs);
/* The precomputed nodes (*count of them). */
TMASSDEF const int *tmass_qs_nodes(const tmass_qs *qs, int *count);
/* Bytes held (the compliance is 9 |nodes| |output nodes| reals). */
TMASSDEF size_t tmass_qs_memory_bytes(const tmass_qs *qs);
/* Always TMASS_ERR_PRECOMPUTED: the precomputation fixes the topology (the paper's limit;
   use the hybrid model to cut). */
TMASSDEF int tmass_qs_remove_tets(tmass_qs *qs, const int *tets, int count);
/* Saves the precomputation (versioned binary: header, preload, compliance, checksum). */
TMASSDEF int tmass_qs_save(const tmass_qs *qs, const char *path);
/* Loads a precomputation made for the same model state and description (mesh, material,
   pinned nodes, loads, nodes, real type): anything else is refused with a TMASS_ERR_FILE_*
   code. No CG solve. */
TMASSDEF int tmass_qs_load(const tmass_model *m, const tmass_qs_desc *d, const char *path,
                           tmass_qs **out);
/* The same to and from memory: with buffer NULL, *size receives the bytes needed. */
TMASSDEF int tmass_qs_save_memory(const tmass_qs *qs, void *buffer, size_t capacity, size_t *size);
TMASSDEF int tmass_qs_load_memory(const tmass_model *m, const tmass_qs_desc *d, const void *buffer,
                                  size_t size, tmass_qs **out);

/* ---- hybrid model (Cotin et al. sec. 6) ----

   One mesh split into a dynamic tensor-mass part (where cutting and tearing happen) and a
   precomputed quasi-static part, sharing connection nodes. The loop of fig. 5: the
   dynamic part imposes its displacements on the connection nodes of the quasi-static
   part, which returns the forces on them. Beyond the paper, the quasi-static part's exact
   stiffness at the connection nodes, S = (C_cc)^-1, is included implicitly in the dynamic
   part's solve, so the coupling adds no stability limit; contacts on the quasi-static
   part enter through the Schur complement of the contact block (exact at steady state,
   lagged by one step in dynamics). The steady state equals that of one tensor-mass model
   of the whole mesh. */
typedef struct tmass_hybrid tmass_hybrid;

typedef struct tmass_hybrid_desc {
    tmass_desc model;                 /* the whole mesh, material, dynamics (tensor-mass) */
    const unsigned char *tet_dynamic; /* tet_count flags: 1 dynamic part, 0 precomputed */
    const int *fixed_nodes;           /* nodes pinned at rest (both parts), or NULL */
    int fixed_count;
    tmass_qs_desc precompute;         /* options of the precomputed part; its node list is
                                         ignored (its boundary nodes are precomputed) */
    unsigned int internal_cookie;
} tmass_hybrid_desc;

TMASSDEF tmass_hybrid_desc tmass_hybrid_default_desc(void);
/* Splits the mesh, creates the dynamic part and precomputes the other (see
   tmass_qs_create for the cost). Both parts must be non-empty. */
TMASSDEF int tmass_hybrid_create(const tmass_hybrid_desc *d, tmass_hybrid **out);
TMASSDEF void tmass_hybrid_destroy(tmass_hybrid *h);
/* One step of the loop (dynamic part: the description's time step and integrator, or
   the given ones), then the precomputed part's displacements. */
TMASSDEF int tmass_hybrid_step(tmass_hybrid *h);
TMASSDEF int tmass_hybrid_step_ex(tmass_hybrid *h, tmass_real dt, tmass_integrator integrator);
/* The steady state of the coupled model (one CG solve on the dynamic part). */
TMASSDEF int tmass_hybrid_solve_static(tmass_hybrid *h);
/* A user contact on any node of the mesh (node indices of the whole mesh): pinned at
   rest + u in the dynamic part, or imposed on the precomputed part. */
TMASSDEF int tmass_hybrid_set_displacement(tmass_hybrid *h, int node, const tmass_real u[3]);
TMASSDEF int tmass_hybrid_release_node(tmass_hybrid *h, int node);
/* Force applied to the body at a contact node to hold it (N); zero for a free node. */
TMASSDEF int tmass_hybrid_contact_force(tmass_hybrid *h, int node, tmass_real f[3]);
/* Cutting and tearing of the dynamic part (tet indices of the whole mesh). A tetrahedron
   of the precomputed part gives TMASS_ERR_PRECOMPUTED and nothing is removed. */
TMASSDEF int tmass_hybrid_remove_tets(tmass_hybrid *h, const int *tets, int count, int *removed);
TMASSDEF int tmass_hybrid_tear(tmass_hybrid *h, const tmass_tear_criteria *c, int *removed);
/* Positions of every node of the whole mesh (3N, m). */
TMASSDEF const tmass_real *tmass_hybrid_positions(const tmass_hybrid *h);
/* Boundary triangles of the whole live mesh (global node indices), outward; rebuilt on
   each call (cost linear in the boundary, no allocation). */
TMASSDEF const int *tmass_hybrid_boundary_triangles(tmass_hybrid *h, int *count);
/* The parts, for diagnostics (their node and tet numbering is local). */
TMASSDEF tmass_model *tmass_hybrid_dynamic_part(tmass_hybrid *h);
TMASSDEF const tmass_qs *tmass_hybrid_precomputed_part(const tmass_hybrid *h);
/* Number of connection nodes currently coupling the parts. */
TMASSDEF int tmass_hybrid_connection_count(const tmass_hybrid *h);

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
/* How many edges ahead the force pass prefetches the tensor stream (see PERFORMANCE) */
#ifndef TMASS__PREFETCH_EDGES
#define TMASS__PREFETCH_EDGES 24
#endif

/* The edge pass's AVX2 path (double, compiled with AVX2 and FMA, e.g. -march=native on
   x86-64; TMASS_NO_SIMD turns it off): see tmass__edge_pass_avx2 */
#if !TMASS__CAT(TMASS__IS_, TMASS_REAL) && defined(__AVX2__) && defined(__FMA__) && !defined(TMASS_NO_SIMD)
#define TMASS__AVX2 1
#include <immintrin.h>
#else
#define TMASS__AVX2 0
#endif

#define TMASS__COOKIE 0x544D4153u /* "TMAS" */
#define TMASS__ALIGN 64
#define TMASS__VEC_BLOCK 4096 /* reals per block of vector loops and dot partial sums */
#define TMASS__EPS (sizeof(tmass_real) == sizeof(float) ? (double)FLT_EPSILON : DBL_EPSILON)
/* largest eps(tmass_real) lambda / mu the tensor model accepts (LIMITS; float: nu <= 0.4994) */
#define TMASS__LAMBDA_MU_LIMIT 1e-4

/* node states */
#define TMASS__FREE 0
#define TMASS__PINNED 1
#define TMASS__INACTIVE 2

struct tmass_model {
    int node_count, tet_count, edge_total, edge_count, live_tets;
    tmass_model_kind kind;
    tmass_integrator integrator;
    tmass_linear_solver linear_solver;
    tmass_real time_step, mass_damping, stiffness_damping, gravity[3], cg_tolerance;
    int cg_max_iterations;
    double divergence_strain, precision_limit, newton_tolerance;
    int newton_iterations;
    double load_scale; /* springs' static continuation: fraction of the loads applied (1) */
    double shortest_edge; /* shortest rest edge at creation, m */
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
    int plain_pass; /* 1: the edge pass runs its portable loop even where the AVX2 one is
                       compiled in (tests compare the two) */

    /* boundary triangles */
    int *tri, *tri_owner, *face_pos;
    int tri_count;

    /* working vectors (3n reals each), named by role; tmass__layout carves them and says
       which roles share memory (roles of different entry points or integrators that never
       run at the same time) */
    tmass_real *step_u0, *step_v0;   /* a step's start: displacements and velocities, pinned
                                        nodes at their targets (tmass__begin_step) */
    tmass_real *step_u1, *step_v1;   /* a step's result, committed when it is accepted */
    tmass_real *step_accel;          /* accelerations (explicit integrators, RK4 stages) */
    tmass_real *force_work;          /* u + beta v for the stiffness-damped elastic force */
    tmass_real *rk4_u, *rk4_v;       /* RK4 stage state */
    tmass_real *implicit_rhs;        /* linearised implicit Euler: right-hand side */
    tmass_real *implicit_diag;       /* M (1 + dt alpha) per degree of freedom (also Newton's) */
    tmass_real *implicit_dv;         /* velocity increment solved for */
    tmass_real *implicit_vfree;      /* springs: v0 on the free nodes */
    tmass_real *implicit_kv;         /* springs: K v0_free */
    tmass_real *newton_residual;     /* springs' Newton (implicit step, static solve) */
    tmass_real *newton_dx, *newton_trial; /* Newton step and line-search trial point */
    tmass_real *static_u;            /* static solve: the displacement solved for */
    tmass_real *static_accepted;     /* springs' continuation: last accepted state */
    tmass_real *static_probe_rhs, *static_probe_x; /* springs' minimum check: probe solve */
    tmass_real *qs_rhs, *qs_x;       /* quasi-static preload solve */
    tmass_real *qs_mark;             /* quasi-static creation: precomputed-node marks (n) */
    tmass_real *cg_r, *cg_z, *cg_p, *cg_q, *cg_pinv; /* CG: residual, preconditioned
                                        residual, direction, A p, Jacobi inverse diagonal */
    tmass_real *dv_prev; /* implicit warm start */
    tmass_real *history_u, *history_v; /* TMASS_BDF2: the state one step back (x_{n-1}, v_{n-1}) */
    int history_ready;     /* 1: history_u/v hold the state before the last step, a step of
                              history_dt taken by an integrator that keeps history (BDF2) */
    tmass_real history_dt; /* s */
    double *partials; /* 2 * partial_count block sums */
    int cg_indefinite; /* the last CG stopped on p . A p <= 0 */
    int cg_last_iterations; /* iterations of the last CG */
    int cg_coarse;          /* the next CG adds the coarse correction (set by the step) */
    int partial_count;
    int *tear_list;

    tmass_stats stats;

    /* coupling stiffness (hybrid models): a dense symmetric block S over some nodes,
       added to K in every force and K-product; allocated separately */
    int coupling_count;  /* nodes */
    int *coupling_nodes; /* node indices */
    double *coupling;    /* (3c)^2, row-major, N/m */
    double *coupling_x;  /* 2 * 3c scratch */
    void *coupling_block;
    size_t coupling_bytes;

    /* anchors (tmass_set_anchors, issue 14): the caller's arrays, read at every evaluation */
    int anchor_count;
    const int *anchor_nodes;
    const tmass_real *anchor_k, *anchor_target;
    double anchor_scale; /* the anchors' weight in the operator the edge tensors hold: 1 for
                            the tensor model (K itself), the springs' tangent scale kx + kv
                            beta while their tensors hold kx K + kv D (tmass__spring_forces) */

    /* the implicit steps' coarse correction (>>coarse; desc.implicit_coarse) */
    int implicit_coarse;    /* -1 never, 0 once a step's CG needed the minimum, 1 always */
    int coarse_on;          /* automatic mode: switched on (never off again) */
    int agg_count;          /* aggregates (0: no coarse space) */
    int *node_agg;          /* n: each node's aggregate */
    double *agg_centre;     /* 3 A: mean rest position of its nodes */
    double *coarse_k;       /* (6 A)^2: P^T K P, unfactored */
    double *coarse_step;    /* (6 A)^2: Cholesky factor of P^T (D + c K) P */
    double *coarse_pdp, *coarse_pdp_new; /* 36 A each: P^T D P of the factor, of this solve */
    double *coarse_y;       /* 6 A: coarse right-hand side and solution */
    double coarse_step_c;   /* c of the factor */
    unsigned coarse_version; /* bumped when K's tensors, the masks or the anchors change */
    unsigned coarse_k_version, coarse_step_version; /* coarse_version they were built at */
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
    /* working vectors: 16 distinct 3n arrays (the 11 of 0.2.0 plus CG's own five, so no
       output or state buffer is lent to CG any more). Roles that never run at the same
       time share memory, set up here and only here:
         - RK4's stage state, the linearised implicit Euler's vectors and the springs'
           Newton vectors belong to different integrators of one step;
         - the static solve and the quasi-static preload solve are entry points of their
           own, never inside a step: they reuse the step's state vectors. */
    TMASS__CARVE(c, m->step_u0, tmass_real, 3 * n);
    TMASS__CARVE(c, m->step_v0, tmass_real, 3 * n);
    TMASS__CARVE(c, m->step_u1, tmass_real, 3 * n);
    TMASS__CARVE(c, m->step_v1, tmass_real, 3 * n);
    TMASS__CARVE(c, m->step_accel, tmass_real, 3 * n);
    TMASS__CARVE(c, m->force_work, tmass_real, 3 * n);
    TMASS__CARVE(c, m->implicit_rhs, tmass_real, 3 * n);
    TMASS__CARVE(c, m->implicit_diag, tmass_real, 3 * n);
    TMASS__CARVE(c, m->implicit_dv, tmass_real, 3 * n);
    TMASS__CARVE(c, m->newton_trial, tmass_real, 3 * n);
    TMASS__CARVE(c, m->cg_r, tmass_real, 3 * n);
    TMASS__CARVE(c, m->cg_z, tmass_real, 3 * n);
    TMASS__CARVE(c, m->cg_p, tmass_real, 3 * n);
    TMASS__CARVE(c, m->cg_q, tmass_real, 3 * n);
    TMASS__CARVE(c, m->cg_pinv, tmass_real, 3 * n);
    TMASS__CARVE(c, m->dv_prev, tmass_real, 3 * n);
    TMASS__CARVE(c, m->history_u, tmass_real, 3 * n); /* state, not scratch: never shared */
    TMASS__CARVE(c, m->history_v, tmass_real, 3 * n);
    m->rk4_u = m->implicit_rhs;
    m->rk4_v = m->implicit_diag;
    m->implicit_vfree = m->step_u1; /* read before the step's result is written */
    m->implicit_kv = m->force_work; /* the springs' force needs no work vector */
    m->newton_residual = m->implicit_rhs;
    m->newton_dx = m->implicit_dv;
    m->static_u = m->step_u1;
    m->static_accepted = m->step_u0;
    m->static_probe_rhs = m->implicit_rhs; /* after the continuation, its Newton is over */
    m->static_probe_x = m->implicit_dv;
    m->qs_rhs = m->step_u0;
    m->qs_x = m->step_u1;
    m->qs_mark = m->step_v0;
    TMASS__CARVE(c, m->partials, double, 2 * (size_t)m->partial_count);
    TMASS__CARVE(c, m->tear_list, int, t);
    { /* the coarse correction's arrays (agg_count 0: none; >>coarse) */
        size_t A = (size_t)m->agg_count;
        TMASS__CARVE(c, m->node_agg, int, A ? n : 0);
        TMASS__CARVE(c, m->agg_centre, double, 3 * A);
        TMASS__CARVE(c, m->coarse_k, double, 36 * A * A);
        TMASS__CARVE(c, m->coarse_step, double, 36 * A * A);
        TMASS__CARVE(c, m->coarse_pdp, double, 36 * A);
        TMASS__CARVE(c, m->coarse_pdp_new, double, 36 * A);
        TMASS__CARVE(c, m->coarse_y, double, 6 * A);
    }
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

/* Face neighbours: returns TMASS_ERR_TET_DUPLICATE if two tets have the same four nodes,
   TMASS_ERR_NONMANIFOLD if a face has more than two tets. */
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
                        /* the same face with the same opposite node: the same tet twice */
                        if (tets[4 * ta + fa % 4] == tets[4 * tb + fb % 4]) return TMASS_ERR_TET_DUPLICATE;
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
    if (m->free_mask[3 * i] != (tmass_real)is_free) m->coarse_version++; /* P changes (>>coarse) */
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

/* Adds (sign +1) or subtracts (-1) the contribution of tetrahedron t: tensors and
   lumped masses. The ten tensor updates of sec. 5.5. */
static void tmass__tensor_assemble_tet(tmass_model *m, int t, double sign)
{
    double K[4][4][9], v;
    const int *q = m->tet_nodes + 4 * t;
    int j, l;
    v = tmass__tet_tensors(m, t, K);
    for (j = 0; j < 4; j++) {
        m->mass[q[j]] = (tmass_real)((double)m->mass[q[j]] + sign * m->density * v / 4.0);
        tmass__add_tensor(m->vertex_tensor + 9 * q[j], K[j][j], sign);
    }
    for (l = 0; l < 6; l++) {
        int j0 = tmass__edge_local[l][0], j1 = tmass__edge_local[l][1];
        int slot = m->edge_slot[m->tet_edges[6 * t + l]];
        /* the slot stores K_ab with a < b */
        if (q[j0] < q[j1])
            tmass__add_tensor(m->edge_tensor + 9 * slot, K[j0][j1], sign);
        else
            tmass__add_tensor(m->edge_tensor + 9 * slot, K[j1][j0], sign);
    }
}

/* The same for springs: lumped masses and the six spring stiffnesses k = E V / l0^2. */
static void tmass__spring_assemble_tet(tmass_model *m, int t, double sign)
{
    double v;
    const int *q = m->tet_nodes + 4 * t;
    int j, l;
    v = tmass__rest_volume(m, t);
    for (j = 0; j < 4; j++) m->mass[q[j]] = (tmass_real)((double)m->mass[q[j]] + sign * m->density * v / 4.0);
    for (l = 0; l < 6; l++) {
        int slot = m->edge_slot[m->tet_edges[6 * t + l]];
        double l0 = m->edge_rest_length[slot];
        m->edge_stiffness[slot] =
            (tmass_real)((double)m->edge_stiffness[slot] + sign * m->tet_young[t] * v / (l0 * l0));
    }
}

/* >>laws ------------------------------------------------------------------------------ */

/* The model kinds (the "laws" of this header), one row per tmass_model_kind: every place
   where the kind selects physics goes through this table (HOW TO EXTEND). */
typedef struct tmass__kind_ops {
    const char *name;
    /* per-tetrahedron precomputation: add (sign +1) or remove (-1) tetrahedron t's
       stiffness and lumped mass (creation, cutting) */
    void (*assemble_tet)(tmass_model *m, int t, double sign);
    /* internal force (elastic plus stiffness damping) at displacement u and velocity v
       (v may be NULL) into out; w: a 3n work vector */
    void (*force)(tmass_model *m, const tmass_real *u, const tmass_real *v, tmass_real *out, tmass_real *w);
    /* the force's differential for the linearised implicit Euler step from (x0, v0):
       writes f(x0, v0) - dt K v0_free into f, leaves the system's stiffness part in the
       edge tensors (what tmass__matvec applies) and returns its factor c, so that the
       step solves (M (1 + dt alpha) + c K) dv = dt (f + loads) */
    double (*differential)(tmass_model *m, tmass_real dt, const tmass_real *x0, const tmass_real *v0,
                           tmass_real *f);
    /* elastic energy at displacement u, J (may use m->force as work) */
    double (*energy)(tmass_model *m, const tmass_real *u);
    /* TMASS_IMPLICIT_EULER: a Newton solve of the nonlinear step, or NULL when the kind is
       linear (the linearised step is then exact) */
    int (*implicit_newton)(tmass_model *m, tmass_real dt);
    /* static equilibrium from u (pinned entries at their targets), in place */
    int (*static_solve)(tmass_model *m, tmass_real *u);
    /* the full tangent stiffness at displacement u into the vertex and edge tensors (what
       tmass__matvec applies), or NULL when the tensors always hold K (a linear kind);
       used by the modal analysis */
    void (*tangent)(tmass_model *m, const tmass_real *u);
    int flags; /* TMASS__KIND_* */
} tmass__kind_ops;

/* linear with constant tensors in the model: K is what the edge tensors hold, so the
   quasi-static precomputation, the hybrid model and tmass_vertex_tensor apply */
#define TMASS__KIND_LINEAR 1
/* uses poisson_ratio (validated; lambda and mu stored per tetrahedron) */
#define TMASS__KIND_POISSON 2

static void tmass__tensor_force(tmass_model *m, const tmass_real *u, const tmass_real *v, tmass_real *out,
                                tmass_real *w);
static void tmass__spring_force(tmass_model *m, const tmass_real *u, const tmass_real *v, tmass_real *out,
                                tmass_real *w);
static double tmass__tensor_differential(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                         const tmass_real *v0, tmass_real *f);
static double tmass__spring_differential(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                         const tmass_real *v0, tmass_real *f);
static double tmass__tensor_energy(tmass_model *m, const tmass_real *u);
static double tmass__spring_energy_of(tmass_model *m, const tmass_real *u);
static int tmass__spring_implicit_newton(tmass_model *m, tmass_real dt);
static int tmass__tensor_static(tmass_model *m, tmass_real *u);
static int tmass__spring_static_solve(tmass_model *m, tmass_real *u);
static void tmass__spring_tangent(tmass_model *m, const tmass_real *u);

static const tmass__kind_ops tmass__kinds[] = {
    /* TMASS_TENSOR_MASS */
    {"tensor-mass", tmass__tensor_assemble_tet, tmass__tensor_force, tmass__tensor_differential,
     tmass__tensor_energy, NULL, tmass__tensor_static, NULL, TMASS__KIND_LINEAR | TMASS__KIND_POISSON},
    /* TMASS_MASS_SPRING */
    {"mass-spring", tmass__spring_assemble_tet, tmass__spring_force, tmass__spring_differential,
     tmass__spring_energy_of, tmass__spring_implicit_newton, tmass__spring_static_solve, tmass__spring_tangent, 0}};
/* one row per kind (a negative array size stops the build otherwise) */
typedef char tmass__kinds_size_check[sizeof tmass__kinds / sizeof tmass__kinds[0] == TMASS_MODEL_KIND_COUNT ? 1 : -1];

static void tmass__apply_tet(tmass_model *m, int t, double sign)
{
    m->coarse_version++; /* K changed: the coarse matrix is rebuilt when next used (>>coarse) */
    tmass__kinds[m->kind].assemble_tet(m, t, sign);
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
    int poisson = (tmass__kinds[d->kind].flags & TMASS__KIND_POISSON) != 0;
    if (poisson && !(tmass__finite(nu) && nu > -1.0 && nu < 0.5)) {
        snprintf(msg, msg_size, "Poisson ratio %g of tetrahedron %d", nu, t);
        return TMASS_ERR_POISSON_RATIO;
    }
    /* the tensors are stored in tmass_real: rounding them perturbs the shear (bending)
       stiffness by about eps lambda / mu, which near-incompressibility amplifies (LIMITS) */
    if (poisson && TMASS__EPS * 2.0 * nu / (1.0 - 2.0 * nu) > TMASS__LAMBDA_MU_LIMIT) {
        snprintf(msg, msg_size, "Poisson ratio %.6g of tetrahedron %d: too close to 0.5 for float (<= 0.4994)",
                 nu, t);
        return TMASS_ERR_POISSON_RATIO;
    }
    return TMASS_OK;
}

/* Stage 1 of tmass_create (and of tmass_hybrid_create): every check on the description,
   before anything is allocated. */
static int tmass__create_validate(const tmass_desc *d)
{
    char msg[160];
    int i, t, err;
    /* a desc without the cookie was not made by tmass_default_desc: nothing in it can be
       trusted, its log callback least of all (issue 18) */
    if (d->internal_cookie != TMASS__COOKIE) return TMASS_ERR_DESC;
    if ((unsigned)d->kind >= TMASS_MODEL_KIND_COUNT) return tmass__fail(d, TMASS_ERR_MODEL_KIND, "kind");
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
    if ((unsigned)d->integrator >= TMASS_INTEGRATOR_COUNT)
        return tmass__fail(d, TMASS_ERR_INTEGRATOR, "integrator");
    if ((unsigned)d->linear_solver >= TMASS_LINEAR_SOLVER_COUNT)
        return tmass__fail(d, TMASS_ERR_SOLVER, "linear_solver");
    if (!(tmass__finite(d->cg_tolerance) && d->cg_tolerance > 0) || d->cg_max_iterations < 1)
        return tmass__fail(d, TMASS_ERR_SOLVER, "cg_tolerance / cg_max_iterations");
    if (!(tmass__finite(d->newton_tolerance) && d->newton_tolerance > 0) || d->newton_iterations < 1)
        return tmass__fail(d, TMASS_ERR_SOLVER, "newton_tolerance / newton_iterations");
    if (d->implicit_coarse < -1 || d->implicit_coarse > 1)
        return tmass__fail(d, TMASS_ERR_SOLVER, "implicit_coarse must be -1, 0 or 1");
    if (!(tmass__finite(d->divergence_strain) && d->divergence_strain >= 0) ||
        !(tmass__finite(d->precision_limit) && d->precision_limit >= 0))
        return tmass__fail(d, TMASS_ERR_SOLVER, "divergence_strain / precision_limit must be finite and >= 0");
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

/* >>coarse ---------------------------------------------------------------------------- */

/* The implicit steps' coarse correction (desc.implicit_coarse; SOLVERS): the nodes are
   binned into up to TMASS__MAX_AGG roughly cubic cells of the rest bounding box
   (aggregates), each carrying the six rigid motions of its nodes about its centre,
   P = [I | -[X - c]x] per node on its free axes. CG's preconditioner becomes Jacobi plus
   P A_c^-1 P^T with A_c = P^T (D + c K) P, K exactly what the solve multiplies by (the
   edge tensors, a hybrid's coupling block, the anchors). P^T K P is assembled from the
   tensors when coarse_version moved (cuts, pin changes, tmass_set_anchors, the hybrid's
   coupling changes) and kept unfactored in coarse_k; the factor of A_c (dense Cholesky
   in double) is kept with its key (c, P^T D P bit for bit, coarse_version), so the steps
   of one dt share one factorisation. A stale factor would only precondition worse: CG
   checks the answer. */
#define TMASS__MAX_AGG 64
#define TMASS__MIN_AGG_NODES 24         /* nodes per aggregate at least */
#define TMASS__COARSE_MIN_ITERATIONS 50 /* the automatic mode's switch (SOLVERS: why 50) */

/* The cell of point p in a dims grid over [lo, lo + ext]. */
static int tmass__agg_cell(const tmass_real *p, const double *lo, const double *ext, const int *dims)
{
    int r, c = 0;
    for (r = 2; r >= 0; r--) {
        int k = (int)(((double)p[r] - lo[r]) / ext[r] * dims[r]);
        if (k >= dims[r]) k = dims[r] - 1;
        if (k < 0) k = 0;
        c = c * dims[r] + k;
    }
    return c;
}

/* Aggregate cells of the rest bounding box for the n nodes at x: returns the number of
   non-empty cells (0 under 4 TMASS__MIN_AGG_NODES nodes); with agg, writes each node's
   cell, renumbered 0.. in cell order. */
static int tmass__aggregate(const tmass_real *x, int n, int *agg)
{
    double lo[3], hi[3], ext[3], size, vol = 1.0, big = 0.0;
    int dims[3], i, r, target = n / TMASS__MIN_AGG_NODES, cells, count = 0, id[TMASS__MAX_AGG];
    if (target > TMASS__MAX_AGG) target = TMASS__MAX_AGG;
    if (target < 4) return 0;
    for (r = 0; r < 3; r++) lo[r] = hi[r] = (double)x[r];
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            double v = (double)x[3 * i + r];
            if (v < lo[r]) lo[r] = v;
            if (v > hi[r]) hi[r] = v;
        }
    for (r = 0; r < 3; r++) big = hi[r] - lo[r] > big ? hi[r] - lo[r] : big;
    if (!(big > 0)) return 0;
    for (r = 0; r < 3; r++) {
        ext[r] = hi[r] - lo[r] > 1e-6 * big ? hi[r] - lo[r] : 1e-6 * big;
        vol *= ext[r];
    }
    size = cbrt(vol / target);
    for (;;) {
        cells = 1;
        for (r = 0; r < 3; r++) {
            dims[r] = (int)(ext[r] / size + 0.5);
            if (dims[r] < 1) dims[r] = 1;
            cells *= dims[r];
        }
        if (cells <= target) break;
        size *= 1.05;
    }
    for (i = 0; i < cells; i++) id[i] = -1;
    for (i = 0; i < n; i++) id[tmass__agg_cell(x + 3 * i, lo, ext, dims)] = 0;
    for (i = 0; i < cells; i++)
        if (id[i] == 0) id[i] = count++;
    if (agg)
        for (i = 0; i < n; i++) agg[i] = id[tmass__agg_cell(x + 3 * i, lo, ext, dims)];
    return count;
}

/* Each node's aggregate and the aggregates' centres (mean rest position), at creation. */
static void tmass__aggregate_centres(tmass_model *m)
{
    int i, r;
    double *cnt = m->coarse_y; /* (scratch, 6 A >= A) */
    if (!m->agg_count) return;
    tmass__aggregate(m->rest, m->node_count, m->node_agg);
    memset(m->agg_centre, 0, sizeof(double) * 3 * (size_t)m->agg_count);
    memset(cnt, 0, sizeof(double) * (size_t)m->agg_count);
    for (i = 0; i < m->node_count; i++) {
        for (r = 0; r < 3; r++) m->agg_centre[3 * m->node_agg[i] + r] += (double)m->rest[3 * i + r];
        cnt[m->node_agg[i]] += 1.0;
    }
    for (i = 0; i < m->agg_count; i++)
        for (r = 0; r < 3; r++) m->agg_centre[3 * i + r] /= cnt[i];
    m->coarse_version = 1; /* nothing built yet (versions 0) */
}

/* Rows of P for node i: P[r][0..2] = e_r, P[r][3..5] = (-[rho]x)_r, rho = X - c; rows of
   pinned or inactive axes are zero. */
static void tmass__node_modes(const tmass_model *m, int i, double P[3][6])
{
    const double *c = m->agg_centre + 3 * m->node_agg[i];
    double rho[3];
    int r, k;
    for (r = 0; r < 3; r++) rho[r] = (double)m->rest[3 * i + r] - c[r];
    memset(P, 0, sizeof(double) * 18);
    P[0][0] = P[1][1] = P[2][2] = 1.0;
    P[0][4] = rho[2];
    P[0][5] = -rho[1];
    P[1][3] = -rho[2];
    P[1][5] = rho[0];
    P[2][3] = rho[1];
    P[2][4] = -rho[0];
    for (r = 0; r < 3; r++)
        if (!(m->free_mask[3 * i + r] > 0))
            for (k = 0; k < 6; k++) P[r][k] = 0.0;
}

/* Ac's block (aggregates ga, gb) += Pa^T B Pb, B a 3x3 row-major block of K times s. */
static void tmass__coarse_add(const tmass_model *m, double *Ac, int ga, int gb, double Pa[3][6], double Pb[3][6],
                              const double *B)
{
    int D = 6 * m->agg_count, r, a, b;
    double T[3][6], *blk = Ac + (size_t)(6 * ga) * D + 6 * gb;
    for (r = 0; r < 3; r++)
        for (b = 0; b < 6; b++) T[r][b] = B[3 * r] * Pb[0][b] + B[3 * r + 1] * Pb[1][b] + B[3 * r + 2] * Pb[2][b];
    for (a = 0; a < 6; a++)
        for (b = 0; b < 6; b++) blk[(size_t)a * D + b] += Pa[0][a] * T[0][b] + Pa[1][a] * T[1][b] + Pa[2][a] * T[2][b];
}

/* coarse_k = P^T K P from what tmass__matvec multiplies by: per live edge (a, b) with
   tensor T, out_a += T (p_b - p_a) and out_b -= T^T (p_b - p_a), i.e. the blocks
   (a, a) -T, (a, b) T, (b, a) T^T, (b, b) -T^T; a hybrid's coupling block; the anchors'
   k I. About 650 multiply-adds per edge, once per coarse_version. */
static void tmass__coarse_k_update(tmass_model *m)
{
    int D = 6 * m->agg_count, c, e, i, j, r, s;
    double *Ac = m->coarse_k, Pa[3][6], Pb[3][6], B[4][9];
    if (m->coarse_k_version == m->coarse_version) return;
    memset(Ac, 0, sizeof(double) * (size_t)D * (size_t)D);
    for (c = 0; c < m->chunk_total; c++)
        for (e = m->chunk_start[c]; e < m->chunk_start[c] + m->chunk_live[c]; e++) {
            int a = m->edge_a[e], b = m->edge_b[e], ga = m->node_agg[a], gb = m->node_agg[b];
            const tmass_real *T = m->edge_tensor + 9 * (size_t)e;
            for (r = 0; r < 3; r++)
                for (s = 0; s < 3; s++) {
                    double t = (double)T[3 * r + s];
                    B[0][3 * r + s] = -t; /* (a, a) */
                    B[1][3 * r + s] = t;  /* (a, b) */
                    B[2][3 * s + r] = t;  /* (b, a) */
                    B[3][3 * s + r] = -t; /* (b, b) */
                }
            tmass__node_modes(m, a, Pa);
            tmass__node_modes(m, b, Pb);
            tmass__coarse_add(m, Ac, ga, ga, Pa, Pa, B[0]);
            tmass__coarse_add(m, Ac, ga, gb, Pa, Pb, B[1]);
            tmass__coarse_add(m, Ac, gb, ga, Pb, Pa, B[2]);
            tmass__coarse_add(m, Ac, gb, gb, Pb, Pb, B[3]);
        }
    for (i = 0; i < m->coupling_count; i++) { /* the coupling block S: P_i^T S_ij P_j */
        int n3c = 3 * m->coupling_count, vi = m->coupling_nodes[i];
        tmass__node_modes(m, vi, Pa);
        for (j = 0; j < m->coupling_count; j++) {
            int vj = m->coupling_nodes[j];
            for (r = 0; r < 3; r++)
                for (s = 0; s < 3; s++) B[0][3 * r + s] = m->coupling[(size_t)(3 * i + r) * n3c + 3 * j + s];
            tmass__node_modes(m, vj, Pb);
            tmass__coarse_add(m, Ac, m->node_agg[vi], m->node_agg[vj], Pa, Pb, B[0]);
        }
    }
    for (i = 0; i < m->anchor_count; i++) { /* the anchors' k I (times anchor_scale: 1 here) */
        int v = m->anchor_nodes[i];
        double k = m->anchor_scale * (double)m->anchor_k[i];
        memset(B[0], 0, sizeof B[0]);
        B[0][0] = B[0][4] = B[0][8] = k;
        tmass__node_modes(m, v, Pa);
        tmass__coarse_add(m, Ac, m->node_agg[v], m->node_agg[v], Pa, Pa, B[0]);
    }
    m->coarse_k_version = m->coarse_version;
}

/* Cholesky factor of the D x D matrix Ac in place (lower triangle, row-major); a mode
   whose pivot falls below 1e-10 of its diagonal (an aggregate whose nodes are all pinned
   or cut off, a mode the pins remove) is dropped: zero row and column of L. dg: D doubles
   of scratch. */
static void tmass__coarse_factor(double *Ac, int D, double *dg)
{
    int i, j, k;
    for (i = 0; i < D; i++) dg[i] = Ac[(size_t)i * D + i];
    for (k = 0; k < D; k++) {
        double *Lk = Ac + (size_t)k * D, d = Lk[k];
        for (j = 0; j < k; j++) d -= Lk[j] * Lk[j];
        if (!(d > 1e-10 * dg[k])) {
            for (i = k; i < D; i++) Ac[(size_t)i * D + k] = 0.0;
            continue;
        }
        d = sqrt(d);
        Lk[k] = d;
        for (i = k + 1; i < D; i++) {
            double *Li = Ac + (size_t)i * D, t = Li[k];
            for (j = 0; j < k; j++) t -= Li[j] * Lk[j];
            Li[k] = t / d;
        }
    }
}

/* The factor of A_c = P^T (D + c K) P into coarse_step, unless the one there has this
   key: P^T D P (one pass over the nodes, compared bit for bit), c and coarse_version. */
static void tmass__coarse_step_build(tmass_model *m, const tmass_real *diag, double c)
{
    int A = m->agg_count, D = 6 * A, i, r, a, b;
    double *pdp = m->coarse_pdp_new, *Ac = m->coarse_step;
    memset(pdp, 0, sizeof(double) * 36 * (size_t)A);
    for (i = 0; i < m->node_count; i++) {
        double P[3][6], *blk = pdp + 36 * (size_t)m->node_agg[i];
        tmass__node_modes(m, i, P);
        for (r = 0; r < 3; r++) {
            double d = diag ? (double)diag[3 * i + r] : 0.0;
            if (d == 0.0 || !(m->free_mask[3 * i + r] > 0)) continue;
            for (a = 0; a < 6; a++)
                for (b = 0; b < 6; b++) blk[6 * a + b] += d * P[r][a] * P[r][b];
        }
    }
    if (m->coarse_step_version == m->coarse_version && m->coarse_step_c == c &&
        !memcmp(pdp, m->coarse_pdp, sizeof(double) * 36 * (size_t)A))
        return;
    tmass__coarse_k_update(m);
    for (i = 0; i < D * D; i++) Ac[i] = c * m->coarse_k[i];
    for (i = 0; i < A; i++)
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) Ac[(size_t)(6 * i + a) * D + 6 * i + b] += pdp[36 * i + 6 * a + b];
    tmass__coarse_factor(Ac, D, m->coarse_y);
    memcpy(m->coarse_pdp, pdp, sizeof(double) * 36 * (size_t)A);
    m->coarse_step_c = c;
    m->coarse_step_version = m->coarse_version;
    m->stats.coarse_factors++;
}

/* z += P A_c^-1 P^T r on the free degrees of freedom (serial, in node order). */
static void tmass__coarse_apply(const tmass_model *m, const tmass_real *rv, tmass_real *z)
{
    int D = 6 * m->agg_count, i, j, r;
    const double *L = m->coarse_step;
    double *y = m->coarse_y;
    memset(y, 0, sizeof(double) * (size_t)D);
    for (i = 0; i < m->node_count; i++) { /* y += P^T r: per node (q, rho x q) */
        const double *c = m->agg_centre + 3 * m->node_agg[i];
        double *ya = y + 6 * m->node_agg[i], rho[3], q[3];
        for (r = 0; r < 3; r++) {
            rho[r] = (double)m->rest[3 * i + r] - c[r];
            q[r] = m->free_mask[3 * i + r] > 0 ? (double)rv[3 * i + r] : 0.0;
            ya[r] += q[r];
        }
        ya[3] += rho[1] * q[2] - rho[2] * q[1];
        ya[4] += rho[2] * q[0] - rho[0] * q[2];
        ya[5] += rho[0] * q[1] - rho[1] * q[0];
    }
    for (i = 0; i < D; i++) { /* L y' = y */
        const double *Li = L + (size_t)i * D;
        double t = y[i];
        if (Li[i] == 0.0) {
            y[i] = 0.0;
            continue;
        }
        for (j = 0; j < i; j++) t -= Li[j] * y[j];
        y[i] = t / Li[i];
    }
    for (i = D - 1; i >= 0; i--) { /* L^T y'' = y', by rows of L (contiguous) */
        const double *Li = L + (size_t)i * D;
        double t;
        if (Li[i] == 0.0) {
            y[i] = 0.0;
            continue;
        }
        t = y[i] /= Li[i];
        for (j = 0; j < i; j++) y[j] -= Li[j] * t;
    }
    for (i = 0; i < m->node_count; i++) { /* z += P y: per node t + w x rho */
        const double *c = m->agg_centre + 3 * m->node_agg[i], *ya = y + 6 * m->node_agg[i];
        double rho[3], d[3];
        for (r = 0; r < 3; r++) rho[r] = (double)m->rest[3 * i + r] - c[r];
        d[0] = ya[0] + (ya[4] * rho[2] - ya[5] * rho[1]);
        d[1] = ya[1] + (ya[5] * rho[0] - ya[3] * rho[2]);
        d[2] = ya[2] + (ya[3] * rho[1] - ya[4] * rho[0]);
        for (r = 0; r < 3; r++)
            if (m->free_mask[3 * i + r] > 0) z[3 * i + r] += (tmass_real)d[r];
    }
}

/* >>creation -------------------------------------------------------------------------- */

TMASSDEF const char *tmass_version(void) { return "0.2.0"; }

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
    d.linear_solver = TMASS_LINEAR_SOLVER_CG;
    d.cg_tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-5 : 1e-6);
    d.cg_max_iterations = 2000;
    d.newton_iterations = 20;
    d.newton_tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-5 : 1e-6);
    d.divergence_strain = (tmass_real)1;
    d.precision_limit = (tmass_real)1e-4;
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

/* tmass_create in four stages that read top to bottom: validate the description, size
   the model (the temporary edge and face tables, the edge count, every array's length),
   lay out the one block (allocate and carve), precompute (copy the mesh and settings,
   edges, tensors or springs, masses, chunks and colours, neighbours, boundary). */

/* Temporary tables of creation: start[n+1], key[6T], payload[6T], tet_edge[6T]. */
typedef struct tmass__create_tables {
    char *block;
    size_t bytes;
    int *start, *key, *payload, *tet_edge;
} tmass__create_tables;

/* Slots per edge chunk. Small models (serial): E / 32 in [256, 4096]. Models large enough
   to run in parallel get bands instead when their numbering allows (issue 21): chunks of
   at least `width` slots, the most edges whose lower vertices lie within reach + 1 of
   each other (reach: the largest b - a of an edge), so that chunks c and c + 2 never share
   a vertex (chunk c + 1 holds every edge whose lower vertex lies within reach of chunk
   c's last one) and the greedy colouring (tmass__colour_chunks) finds two colours, even
   and odd chunks, each run in slot order. Chunks of 4 widths (at least 16 chunks) keep
   most node accesses of a sweep in cache: a node is visited in one colour's pass as the
   lower vertex, and again in the other's only when it lies within reach of a chunk's
   end. The greedy colouring of small chunks it replaces ran 4 colours on a 1e6-tet cube,
   each colour sweeping all the nodes. A mesh without such locality (reach near the node
   count: width above E / 16) keeps the small chunks. Cuts only remove edges, so the
   colouring stays valid. Uses start and key as build_edges left them (start is
   overwritten). */
static int tmass__chunk_size(int n, int E, int *start, const int *key)
{
    int v, i, lo = start[0], cum = 0, reach = 0, width = 0, size = E / 32, band;
    if (size < 256) size = 256;
    if (size > 4096) size = 4096;
    if (E < TMASS_PARALLEL_MIN_EDGES) return size;
    for (v = 0; v < n; v++) { /* start: distinct edges before lower vertex v */
        int hi = start[v + 1], distinct = 0;
        for (i = lo; i < hi; i++) distinct += i == lo || key[i] != key[i - 1];
        if (hi > lo && key[hi - 1] - v > reach) reach = key[hi - 1] - v; /* keys sorted */
        start[v] = cum;
        cum += distinct;
        lo = hi;
    }
    start[n] = cum;
    for (v = 0; v < n; v++) {
        int w = start[reach + 1 > n - v ? n : v + reach + 1] - start[v];
        if (w > width) width = w;
    }
    if (width > E / 16) return size; /* no locality to use */
    band = width > E / 64 ? E / 16 : 4 * width;
    return band > size ? band : size;
}

/* Allocates the temporary tables and counts the edges; sizes holds every array length
   tmass__layout needs. */
static int tmass__create_size(const tmass_desc *d, tmass_model *sizes, tmass__create_tables *w)
{
    int n = d->node_count, T = d->tet_count, E;
    w->bytes = sizeof(int) * ((size_t)n + 1 + 18 * (size_t)T);
    w->block = (char *)tmass__alloc(&d->allocator, w->bytes);
    if (!w->block) return tmass__fail(d, TMASS_ERR_ALLOC, "temporary tables");
    w->start = (int *)w->block;
    w->key = w->start + n + 1;
    w->payload = w->key + 6 * (size_t)T;
    w->tet_edge = w->payload + 6 * (size_t)T;
    E = tmass__build_edges(d->tets, T, n, w->start, w->key, w->payload, w->tet_edge, NULL, NULL);
    memset(sizes, 0, sizeof *sizes);
    sizes->node_count = n;
    sizes->tet_count = T;
    sizes->edge_total = E;
    sizes->chunk_size = tmass__chunk_size(n, E, w->start, w->key);
    sizes->chunk_total = (E + sizes->chunk_size - 1) / sizes->chunk_size;
    sizes->partial_count = (3 * n + TMASS__VEC_BLOCK - 1) / TMASS__VEC_BLOCK;
    sizes->implicit_coarse = d->implicit_coarse;
    if (d->implicit_coarse >= 0 && (tmass__kinds[d->kind].flags & TMASS__KIND_LINEAR))
        sizes->agg_count = tmass__aggregate(d->rest_positions, n, NULL);
    return TMASS_OK;
}

/* Allocates the model's block (the struct first, then every array, 64-byte aligned) and
   carves it; *out points at the zeroed model with its arrays in place. */
static int tmass__create_layout(const tmass_desc *d, const tmass_model *sizes, tmass_model **out)
{
    tmass_model tmp = *sizes;
    tmass__carver carver;
    carver.base = NULL;
    carver.offset = sizeof(tmass_model);
    tmass__layout(&tmp, &carver);
    tmp.block_bytes = carver.offset;
    tmp.block = tmass__alloc(&d->allocator, tmp.block_bytes);
    if (!tmp.block) return TMASS_ERR_ALLOC;
    memset(tmp.block, 0, tmp.block_bytes);
    carver.base = (char *)tmp.block;
    carver.offset = sizeof(tmass_model);
    tmass__layout(&tmp, &carver);
    *out = (tmass_model *)tmp.block;
    **out = tmp;
    (*out)->allocator = d->allocator;
    return TMASS_OK;
}

/* The description's settings into the model. */
static void tmass__create_settings(const tmass_desc *d, tmass_model *m)
{
    int i;
    m->kind = d->kind;
    m->integrator = d->integrator;
    m->linear_solver = d->linear_solver;
    m->time_step = d->time_step;
    m->mass_damping = d->mass_damping;
    m->stiffness_damping = d->stiffness_damping;
    for (i = 0; i < 3; i++) m->gravity[i] = d->gravity[i];
    m->cg_tolerance = d->cg_tolerance;
    m->cg_max_iterations = d->cg_max_iterations;
    m->divergence_strain = (double)d->divergence_strain;
    m->newton_tolerance = (double)d->newton_tolerance;
    m->newton_iterations = d->newton_iterations;
    m->load_scale = 1.0;
    m->anchor_scale = 1.0;
    m->precision_limit = (double)d->precision_limit;
    m->density = (double)d->density;
    m->parallel_for = d->parallel_for;
    m->parallel_user = d->parallel_user;
    m->parallel = m->edge_total >= TMASS_PARALLEL_MIN_EDGES;
}

/* The mesh, its edges and per-tetrahedron materials; rest lengths (springs, the
   precision check). */
static void tmass__create_mesh(const tmass_desc *d, tmass_model *m, tmass__create_tables *w)
{
    int i, t, n = m->node_count, T = m->tet_count, E;
    memcpy(m->rest, d->rest_positions, sizeof(tmass_real) * 3 * (size_t)n);
    memcpy(m->pos, d->rest_positions, sizeof(tmass_real) * 3 * (size_t)n);
    memcpy(m->tet_nodes, d->tets, sizeof(int) * 4 * (size_t)T);
    E = tmass__build_edges(d->tets, T, n, w->start, w->key, w->payload, m->tet_edges, m->edge_a, m->edge_b);
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
        if (tmass__kinds[d->kind].flags & TMASS__KIND_POISSON) {
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
        if (i == 0 || (double)m->edge_rest_length[i] < m->shortest_edge)
            m->shortest_edge = (double)m->edge_rest_length[i];
    }
}

/* Everything the rest state determines: the kind's per-tetrahedron assembly (tensors or
   spring stiffnesses, lumped masses), node states, edge chunks and their colours, face
   neighbours, boundary triangles. Returns TMASS_ERR_TET_DUPLICATE or _NONMANIFOLD from
   the neighbour search. */
static int tmass__create_precompute(const tmass_desc *d, tmass_model *m, tmass__create_tables *w)
{
    int i, t, err, E;
    tmass__create_settings(d, m);
    tmass__create_mesh(d, m, w);
    E = m->edge_count;
    for (t = 0; t < m->tet_count; t++) tmass__apply_tet(m, t, 1.0);
    for (i = 0; i < m->node_count; i++) {
        m->node_state[i] = m->node_tets[i] > 0 ? TMASS__FREE : TMASS__INACTIVE;
        m->inv_mass[i] = m->mass[i] > 0 ? (tmass_real)(1.0 / (double)m->mass[i]) : (tmass_real)0;
        tmass__set_masks(m, i, m->node_state[i] == TMASS__FREE, 0);
    }
    for (i = 0; i < m->chunk_total; i++) {
        int b = i * m->chunk_size, e = b + m->chunk_size;
        m->chunk_live[i] = (e > E ? E : e) - b;
    }
    tmass__colour_chunks(m, w->start, w->key);
    err = tmass__build_neighbors(m, w->start, w->key, w->payload);
    if (err) return err;
    tmass__init_boundary(m);
    tmass__aggregate_centres(m);
    m->stats.newton_iterations = 1;
    return TMASS_OK;
}

TMASSDEF int tmass_create(const tmass_desc *d, tmass_model **out)
{
    tmass_model sizes, *m = NULL;
    tmass__create_tables w;
    tmass_allocator alloc;
    int err;
    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (!d) return TMASS_ERR_ARG;
    err = tmass__create_validate(d);
    if (err) return err;
    alloc = d->allocator;
    memset(&w, 0, sizeof w);
    err = tmass__create_size(d, &sizes, &w);
    if (err) return err;
    err = tmass__create_layout(d, &sizes, &m);
    if (err) {
        tmass__free(&alloc, w.block, w.bytes);
        return tmass__fail(d, err, "model block");
    }
    err = tmass__create_precompute(d, m, &w);
    tmass__free(&alloc, w.block, w.bytes);
    if (err) {
        tmass__free(&alloc, m->block, m->block_bytes);
        return tmass__fail(d, err, err == TMASS_ERR_TET_DUPLICATE ? "a tetrahedron is listed twice"
                                   : "a triangle is shared by three or more tetrahedra");
    }
    *out = m;
    return TMASS_OK;
}

TMASSDEF void tmass_destroy(tmass_model *m)
{
    tmass_allocator a;
    if (!m) return;
    a = m->allocator;
    tmass__free(&a, m->coupling_block, m->coupling_bytes);
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

#if TMASS__AVX2
/* The edge pass (tmass__edge_pass below) with 4-wide vectors (lane 3 unused: masked
   loads never read past a node's 3 reals or a tensor's 9). Per edge: d = p_b - p_a (or
   p_a - p_b) in one register; K^T d = d0 row0 + d1 row1 + d2 row2 (rows of the
   row-major tensor; the multiply-adds in the order gcc 12 contracts the portable loop's:
   the b side came out bit-identical); K d accumulated lane-wise over the run of edges
   sharing a (acc_r += row_r * d) and summed across lanes once at the run's end,
   (l0 + l1) + l2: another summation order than the portable loop's row dot products
   (within round-off of it; deterministic for any thread count). About 20 % fewer
   instructions than the portable loop (callgrind) and 25 % less time in cache
   (PERFORMANCE). */
static void tmass__edge_pass_avx2(const tmass__matvec_ctx *c, int begin, int end, const int neg)
{
    const tmass_model *m = c->m;
    const int *TMASS__RESTRICT ea = m->edge_a;
    const int *TMASS__RESTRICT eb = m->edge_b;
    const double *TMASS__RESTRICT T = m->edge_tensor;
    const double *TMASS__RESTRICT p = c->p;
    double *TMASS__RESTRICT out = c->out;
    const __m256i three = _mm256_set_epi64x(0, -1, -1, -1);
    int k;
    for (k = m->colour_start[c->colour] + begin; k < m->colour_start[c->colour] + end; k++) {
        int s = m->chunk_start[k], s1 = s + m->chunk_live[k];
        while (s < s1) {
            int a = ea[s];
            __m256d pa = _mm256_maskload_pd(p + 3 * a, three), acc0 = _mm256_setzero_pd(), acc1 = acc0,
                    acc2 = acc0, f;
            double *oa = out + 3 * a;
            do {
                const double *K = T + 9 * s;
                double *ob = out + 3 * eb[s];
                __m256d pb = _mm256_maskload_pd(p + 3 * eb[s], three);
                __m256d d = neg ? _mm256_sub_pd(pa, pb) : _mm256_sub_pd(pb, pa);
                __m256d r0 = _mm256_loadu_pd(K), r1 = _mm256_loadu_pd(K + 3),
                        r2 = _mm256_maskload_pd(K + 6, three);
                __m256d t, o;
                TMASS__PREFETCH(K + 9 * TMASS__PREFETCH_EDGES);
                acc0 = _mm256_fmadd_pd(r0, d, acc0);
                acc1 = _mm256_fmadd_pd(r1, d, acc1);
                acc2 = _mm256_fmadd_pd(r2, d, acc2);
                t = _mm256_mul_pd(r1, _mm256_permute4x64_pd(d, 0x55));
                t = _mm256_fmadd_pd(r0, _mm256_permute4x64_pd(d, 0x00), t);
                t = _mm256_fmadd_pd(r2, _mm256_permute4x64_pd(d, 0xAA), t);
                o = _mm256_sub_pd(_mm256_maskload_pd(ob, three), t);
                _mm_storeu_pd(ob, _mm256_castpd256_pd128(o));
                _mm_store_sd(ob + 2, _mm256_extractf128_pd(o, 1));
                s++;
            } while (s < s1 && ea[s] == a);
            {
                /* lanes of acc_r: l0 l1 l2 0; hadd(acc0, acc1) = (a0+a1, b0+b1, a2+0, b2+0) */
                __m256d h01 = _mm256_hadd_pd(acc0, acc1), h22 = _mm256_hadd_pd(acc2, acc2);
                __m128d s01 = _mm_add_pd(_mm256_castpd256_pd128(h01), _mm256_extractf128_pd(h01, 1));
                __m128d s2 = _mm_add_sd(_mm256_castpd256_pd128(h22), _mm256_extractf128_pd(h22, 1));
                f = _mm256_insertf128_pd(_mm256_castpd128_pd256(s01), s2, 1);
                f = _mm256_add_pd(_mm256_maskload_pd(oa, three), f);
                _mm_storeu_pd(oa, _mm256_castpd256_pd128(f));
                _mm_store_sd(oa + 2, _mm256_extractf128_pd(f, 1));
            }
        }
    }
}
#endif

/* The edge pass over chunks [begin, end) of the context's colour: out += K p (neg 0) or
   out -= K p (neg 1). The negated pass forms each difference the other way round,
   d = p_a - p_b: every product and sum is then the exact negative of the neg = 0 one
   (rounding to nearest is symmetric), so -K p comes out bit for bit as the negation of
   K p, signed zeros aside, without a pass over the nodes to negate it (issue 21). */

static void tmass__edge_pass(const tmass__matvec_ctx *c, int begin, int end, const int neg)
{
    const tmass_model *m = c->m;
    const int *TMASS__RESTRICT ea = m->edge_a;
    const int *TMASS__RESTRICT eb = m->edge_b;
    const tmass_real *TMASS__RESTRICT T = m->edge_tensor;
    const tmass_real *TMASS__RESTRICT p = c->p;
    tmass_real *TMASS__RESTRICT out = c->out;
    int k;
#if TMASS__AVX2
    if (!m->plain_pass) {
        tmass__edge_pass_avx2(c, begin, end, neg);
        return;
    }
#endif
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
                tmass_real d0 = neg ? a0 - pb[0] : pb[0] - a0, d1 = neg ? a1 - pb[1] : pb[1] - a1,
                           d2 = neg ? a2 - pb[2] : pb[2] - a2;
                TMASS__PREFETCH(K + 9 * TMASS__PREFETCH_EDGES); /* the tensor stream, pages ahead */
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

static void tmass__matvec_chunks(void *vctx, int begin, int end)
{
    tmass__edge_pass((const tmass__matvec_ctx *)vctx, begin, end, 0);
}

static void tmass__matvec_chunks_neg(void *vctx, int begin, int end)
{
    tmass__edge_pass((const tmass__matvec_ctx *)vctx, begin, end, 1);
}

/* out += S p over the coupling nodes (serial: the block is small and dense). */
static void tmass__coupling_matvec(const tmass_model *m, const tmass_real *p, tmass_real *out)
{
    int n3 = 3 * m->coupling_count, i, j;
    double *x = m->coupling_x, *y = m->coupling_x + n3;
    for (i = 0; i < m->coupling_count; i++)
        for (j = 0; j < 3; j++) x[3 * i + j] = (double)p[3 * m->coupling_nodes[i] + j];
    for (i = 0; i < n3; i++) {
        const double *row = m->coupling + (size_t)i * n3;
        double acc = 0.0;
        for (j = 0; j < n3; j++) acc += row[j] * x[j];
        y[i] = acc;
    }
    for (i = 0; i < m->coupling_count; i++)
        for (j = 0; j < 3; j++) out[3 * m->coupling_nodes[i] + j] += (tmass_real)y[3 * i + j];
}

/* out = K p over the edge tensors and a hybrid's coupling block, without the anchors (the
   force passes add the anchors' own force, formed in double: tmass__anchor_force). */
static void tmass__matvec_signed(const tmass_model *m, const tmass_real *p, tmass_real *out, int neg)
{
    tmass__matvec_ctx c;
    int i, n3 = 3 * m->node_count;
    c.m = m;
    c.p = p;
    c.out = out;
    memset(out, 0, sizeof(tmass_real) * (size_t)n3);
    for (c.colour = 0; c.colour < m->colour_count; c.colour++)
        tmass__run(m, m->colour_start[c.colour + 1] - m->colour_start[c.colour],
                   neg ? tmass__matvec_chunks_neg : tmass__matvec_chunks, &c);
    if (m->coupling_count) {
        /* (serial, small): negate around it so that it adds as in K p */
        if (neg)
            for (i = 0; i < n3; i++) out[i] = -out[i];
        tmass__coupling_matvec(m, p, out);
        if (neg)
            for (i = 0; i < n3; i++) out[i] = -out[i];
    }
}

static void tmass__matvec_elastic(const tmass_model *m, const tmass_real *p, tmass_real *out)
{
    tmass__matvec_signed(m, p, out, 0);
}

/* out = -K p (tmass__matvec_elastic negated, bit for bit but for signed zeros): the
   force passes */
static void tmass__matvec_elastic_neg(const tmass_model *m, const tmass_real *p, tmass_real *out)
{
    tmass__matvec_signed(m, p, out, 1);
}

/* The anchors' part of a force pass (tmass_set_anchors): per anchor a on node n,
   d = x_n - t_a (rest + u - t, formed in double as (rest - t) + u), energy k |d|^2 / 2
   (returned), force -k (d + beta v) added to out when out is given (v may be NULL: no
   damping term). Anchors in order, serial: deterministic. */
static double tmass__anchor_force(const tmass_model *m, const tmass_real *u, const tmass_real *v, double beta,
                                  tmass_real *out)
{
    double energy = 0.0;
    int a, r;
    for (a = 0; a < m->anchor_count; a++) {
        int n = m->anchor_nodes[a];
        double k = (double)m->anchor_k[a];
        for (r = 0; r < 3; r++) {
            int j = 3 * n + r;
            double d = ((double)m->rest[j] - (double)m->anchor_target[3 * a + r]) + (double)u[j];
            energy += 0.5 * k * d * d;
            if (out) out[j] = (tmass_real)((double)out[j] - k * (d + (v ? beta * (double)v[j] : 0.0)));
        }
    }
    return energy;
}

/* out = K p, K the operator the solvers use: the edge tensors, a hybrid's coupling block
   and the anchors' k I on their nodes (times m->anchor_scale). */
static void tmass__matvec(const tmass_model *m, const tmass_real *p, tmass_real *out)
{
    int a, r;
    tmass__matvec_elastic(m, p, out);
    for (a = 0; a < m->anchor_count; a++) {
        int j = 3 * m->anchor_nodes[a];
        double k = m->anchor_scale * (double)m->anchor_k[a];
        for (r = 0; r < 3; r++) out[j + r] = (tmass_real)((double)out[j + r] + k * (double)p[j + r]);
    }
}

/* Spring forces (eq. 7) with axial damping, into out (overwritten):
       f = k (l - l0) + c ((v_b - v_a) . d),  out_a += f d,  out_b -= f d,
   d the unit vector from a to b and c = stiffness_damping * k. When tangent_kx > 0 it
   also writes the tangent S_e = kx K_e + kv c d d^T into the edge tensors (as the
   off-diagonal block -S_e) and vertex tensors (sum of S_e), where
       K_e = k [ max(0, 1 - l0/l) (I - d d^T) + d d^T ]
   is minus the force Jacobian with its compressive geometric part clamped (positive
   semi-definite; full_tangent keeps the negative part), and, when kv_out is given,
   kv_out = K(x) v_kv. */
typedef struct tmass__spring_ctx {
    tmass_model *m;
    const tmass_real *u, *v, *v_kv; /* displacement, velocity, vector for kv_out */
    tmass_real *out, *kv_out;
    int colour, full_tangent; /* full: keep compressed springs' negative geometric term */
    double kx, kv;
} tmass__spring_ctx;

static void tmass__spring_edge(tmass__spring_ctx *c, int s)
{
    tmass_model *m = c->m;
    int a = m->edge_a[s], b = m->edge_b[s], r, q;
    tmass_real d[3], du[3], l, l0 = m->edge_rest_length[s], dl2 = 0, stretch, f, k = m->edge_stiffness[s],
                              kd = m->stiffness_damping * k;
    for (r = 0; r < 3; r++) { /* x_b - x_a from rest and displacement differences */
        tmass_real d0 = m->rest[3 * b + r] - m->rest[3 * a + r];
        du[r] = c->u[3 * b + r] - c->u[3 * a + r];
        d[r] = d0 + du[r];
        dl2 += du[r] * (d0 + d0 + du[r]); /* l^2 - l0^2 = (2 d0 + du) . du */
    }
    l = (tmass_real)sqrt((double)(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    if (l > 0)
        for (r = 0; r < 3; r++) d[r] /= l;
    /* l - l0 = (l^2 - l0^2) / (l + l0): no cancellation between two nearly equal lengths,
       so small strains keep their precision (in float, l - l0 would lose 7 digits on a
       steel beam's 1e-6 strains) */
    stretch = l + l0 > 0 ? dl2 / (l + l0) : 0;
    f = k * stretch;
    if (c->v && kd != 0) {
        const tmass_real *va = c->v + 3 * a, *vb = c->v + 3 * b;
        f += kd * ((vb[0] - va[0]) * d[0] + (vb[1] - va[1]) * d[1] + (vb[2] - va[2]) * d[2]);
    }
    for (r = 0; r < 3; r++) {
        c->out[3 * a + r] += f * d[r];
        c->out[3 * b + r] -= f * d[r];
    }
    if (c->kx > 0) {
        tmass_real geo = l > 0 ? stretch / l : 0, dv[3] = {0, 0, 0}; /* 1 - l0 / l */
        tmass_real *T = m->edge_tensor + 9 * s;
        if (geo < 0 && !c->full_tangent) geo = 0;
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

/* The force alone (no tangent), chunk k: the same arithmetic as tmass__spring_edge,
   written for the compiler in blocks of 32 edges: a first loop (gathers, one square root
   and one division per edge, vectorisable) gives each edge's force factor g, the force
   on b being -g (x_b - x_a); a second loop scatters, a run of edges sharing their lower
   vertex a (edges come sorted by it) summing f_a in registers as the tensor pass does. */
#define TMASS__SPRING_BLOCK 32
static void tmass__spring_force_chunk(const tmass__spring_ctx *c, int k)
{
    const tmass_model *m = c->m;
    const int *TMASS__RESTRICT ea = m->edge_a;
    const int *TMASS__RESTRICT eb = m->edge_b;
    const tmass_real *TMASS__RESTRICT rest = m->rest;
    const tmass_real *TMASS__RESTRICT u = c->u;
    const tmass_real *TMASS__RESTRICT v = c->v;
    const tmass_real *TMASS__RESTRICT stiffness = m->edge_stiffness;
    const tmass_real *TMASS__RESTRICT rest_length = m->edge_rest_length;
    tmass_real *TMASS__RESTRICT out = c->out;
    tmass_real beta = v ? m->stiffness_damping : 0;
    tmass_real g[TMASS__SPRING_BLOCK], dx[3][TMASS__SPRING_BLOCK];
    int s0 = m->chunk_start[k], s1 = s0 + m->chunk_live[k];
    for (; s0 < s1; s0 += TMASS__SPRING_BLOCK) {
        int n = s1 - s0 < TMASS__SPRING_BLOCK ? s1 - s0 : TMASS__SPRING_BLOCK, j = 0;
        for (j = 0; j < n; j++) {
            int a = ea[s0 + j], b = eb[s0 + j];
            tmass_real e0 = rest[3 * b] - rest[3 * a], e1 = rest[3 * b + 1] - rest[3 * a + 1],
                       e2 = rest[3 * b + 2] - rest[3 * a + 2];
            tmass_real w0 = u[3 * b] - u[3 * a], w1 = u[3 * b + 1] - u[3 * a + 1], w2 = u[3 * b + 2] - u[3 * a + 2];
            tmass_real d0 = e0 + w0, d1 = e1 + w1, d2 = e2 + w2;
            tmass_real l2 = d0 * d0 + d1 * d1 + d2 * d2, l = (tmass_real)sqrt((double)l2);
            tmass_real l0 = rest_length[s0 + j];
            tmass_real dl2 = w0 * (e0 + e0 + w0) + w1 * (e1 + e1 + w1) + w2 * (e2 + e2 + w2);
            tmass_real ll = l + l0 > 0 ? l + l0 : 1, il = l > 0 ? l : 1;
            g[j] = stiffness[s0 + j] * dl2 / (ll * il); /* k (l - l0) / l */
            dx[0][j] = d0;
            dx[1][j] = d1;
            dx[2][j] = d2;
        }
        if (beta != 0)
            for (j = 0; j < n; j++) { /* axial damping beta k ((v_b - v_a) . d) / l^2 */
                int a = ea[s0 + j], b = eb[s0 + j];
                tmass_real l2 = dx[0][j] * dx[0][j] + dx[1][j] * dx[1][j] + dx[2][j] * dx[2][j];
                tmass_real rate = (v[3 * b] - v[3 * a]) * dx[0][j] + (v[3 * b + 1] - v[3 * a + 1]) * dx[1][j] +
                                  (v[3 * b + 2] - v[3 * a + 2]) * dx[2][j];
                g[j] += beta * stiffness[s0 + j] * rate / (l2 > 0 ? l2 : 1);
            }
        j = 0;
        while (j < n) {
            int a = ea[s0 + j];
            tmass_real f0 = 0, f1 = 0, f2 = 0;
            do {
                tmass_real *ob = out + 3 * eb[s0 + j];
                tmass_real q0 = g[j] * dx[0][j], q1 = g[j] * dx[1][j], q2 = g[j] * dx[2][j];
                f0 += q0, f1 += q1, f2 += q2;
                ob[0] -= q0, ob[1] -= q1, ob[2] -= q2;
                j++;
            } while (j < n && ea[s0 + j] == a);
            out[3 * a] += f0;
            out[3 * a + 1] += f1;
            out[3 * a + 2] += f2;
        }
    }
}

static void tmass__spring_chunks(void *vctx, int begin, int end)
{
    tmass__spring_ctx *c = (tmass__spring_ctx *)vctx;
    const tmass_model *m = c->m;
    int k, s;
    for (k = m->colour_start[c->colour] + begin; k < m->colour_start[c->colour] + end; k++) {
        if (c->kx > 0) {
            for (s = m->chunk_start[k]; s < m->chunk_start[k] + m->chunk_live[k]; s++)
                tmass__spring_edge(c, s);
        } else {
            tmass__spring_force_chunk(c, k);
        }
    }
}

static void tmass__spring_forces(tmass_model *m, const tmass_real *u, const tmass_real *v,
                                 tmass_real *out, double tangent_kx, double tangent_kv,
                                 const tmass_real *v_kv, tmass_real *kv_out, int full_tangent)
{
    tmass__spring_ctx c;
    size_t n3 = 3 * (size_t)m->node_count;
    c.m = m;
    c.full_tangent = full_tangent;
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
    if (m->anchor_count) { /* the anchors: force, their k in the tangent's scale, K v */
        int a, r;
        tmass__anchor_force(m, u, v, (double)m->stiffness_damping, out);
        if (tangent_kx > 0) m->anchor_scale = tangent_kx + tangent_kv * (double)m->stiffness_damping;
        if (kv_out)
            for (a = 0; a < m->anchor_count; a++)
                for (r = 0; r < 3; r++) {
                    int j = 3 * m->anchor_nodes[a] + r;
                    kv_out[j] = (tmass_real)((double)kv_out[j] + (double)m->anchor_k[a] * (double)v_kv[j]);
                }
    }
    m->stats.force_evaluations++;
}

/* Elastic force plus stiffness damping at displacement u and velocity v into out (v may
   be NULL):
   tensor:  out = -K (u + beta v)   (w is scratch)
   springs: out = eq. 7 plus axial damping. */
static void tmass__spring_force(tmass_model *m, const tmass_real *u, const tmass_real *v, tmass_real *out,
                                tmass_real *w)
{
    (void)w;
    tmass__spring_forces(m, u, v, out, 0.0, 0.0, NULL, NULL, 0);
}

static void tmass__tensor_force(tmass_model *m, const tmass_real *u, const tmass_real *v, tmass_real *out,
                                tmass_real *w)
{
    int i, n3 = 3 * m->node_count;
    if (v && m->stiffness_damping != 0) {
        tmass_real beta = m->stiffness_damping;
        for (i = 0; i < n3; i++) w[i] = u[i] + beta * v[i];
        tmass__matvec_elastic_neg(m, w, out);
    } else {
        tmass__matvec_elastic_neg(m, u, out);
    }
    if (m->anchor_count) tmass__anchor_force(m, u, v, (double)m->stiffness_damping, out);
    m->stats.force_evaluations++;
}

static void tmass__internal_force(tmass_model *m, const tmass_real *u, const tmass_real *v,
                                  tmass_real *out, tmass_real *w)
{
    tmass__kinds[m->kind].force(m, u, v, out, w);
}

/* 1/2 u^T K u (K u into m->force as work, without the anchors), plus the
   anchors' energy */
static double tmass__tensor_energy(tmass_model *m, const tmass_real *u)
{
    int i, n3 = 3 * m->node_count;
    double elastic = 0.0;
    tmass__matvec_elastic(m, u, m->force);
    for (i = 0; i < n3; i++) elastic += 0.5 * (double)u[i] * (double)m->force[i];
    m->stats.force_evaluations++;
    return elastic + (m->anchor_count ? tmass__anchor_force(m, u, NULL, 0.0, NULL) : 0.0);
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

/* The anchors' k (times m->anchor_scale) joins the Jacobi diagonal of the nodes they
   hold: pinv first holds each anchored entry's sum of k (several anchors on a node add),
   then its inverse stored negated (each entry once), then the sign is restored. A node of
   a hybrid's coupling block also keeps its block's diagonal entry. */
static void tmass__anchor_jacobi(const tmass_model *m, const tmass_real *diag, double c, tmass_real *pinv)
{
    int a, r, j, i;
    for (a = 0; a < m->anchor_count; a++)
        for (r = 0; r < 3; r++) pinv[3 * m->anchor_nodes[a] + r] = 0;
    for (a = 0; a < m->anchor_count; a++)
        for (r = 0; r < 3; r++) pinv[3 * m->anchor_nodes[a] + r] += m->anchor_k[a];
    for (a = 0; a < m->anchor_count; a++)
        for (r = 0; r < 3; r++) {
            int v = m->anchor_nodes[a];
            double dgl, coupled = 0.0;
            j = 3 * v + r;
            if (pinv[j] < 0) continue;
            for (i = 0; i < m->coupling_count; i++)
                if (m->coupling_nodes[i] == v)
                    coupled = m->coupling[(size_t)(3 * i + r) * (size_t)(3 * m->coupling_count) + 3 * i + r];
            dgl = (diag ? (double)diag[j] : 0.0) +
                  c * ((double)m->vertex_tensor[9 * v + 4 * r] + coupled + m->anchor_scale * (double)pinv[j]);
            pinv[j] = (tmass_real)(m->free_mask[j] > 0 && dgl > 0 ? -1.0 / dgl : -0.0);
        }
    for (a = 0; a < m->anchor_count; a++)
        for (r = 0; r < 3; r++) {
            j = 3 * m->anchor_nodes[a] + r;
            pinv[j] = pinv[j] < 0 ? -pinv[j] : 0;
        }
}

/* Solves (D + c K) x = b on the free degrees of freedom by Jacobi-preconditioned CG
   (diag: D per degree of freedom, or NULL). x holds the initial guess; pinned and
   inactive entries are held at 0. Stops when |r| <= cg_tolerance |b| or after
   cg_max_iterations. Works in the model's CG vectors (m->cg_r, cg_z, cg_p, cg_q, cg_pinv),
   which nothing else uses; b and x must not be any of them. Returns TMASS_OK, TMASS_ERR_NOT_FINITE (|b|^2 or the
   residual not finite) or TMASS_ERR_NO_CONVERGENCE (the cap reached above the tolerance,
   or a direction of non-positive curvature: the caller fails, issue 18's policy). Adds
   its iterations to the stats and sets stats.cg_residual. */
static int tmass__cg(tmass_model *m, const tmass_real *diag, double c, const tmass_real *b,
                     tmass_real *x)
{
    tmass__cg_ctx k;
    int n3 = 3 * m->node_count, i, it, blocks = m->partial_count;
    tmass_real *pinv = m->cg_pinv;
    double bb = 0.0, rr, rz, tol2, pdp, rho_min = HUGE_VAL, rho_max = 0.0;
    int coarse = m->cg_coarse && m->agg_count > 0; /* Jacobi plus P A_c^-1 P^T (>>coarse) */
    k.m = m;
    k.r = m->cg_r;
    k.z = m->cg_z;
    k.p = m->cg_p;
    k.q = m->cg_q;
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
    for (i = 0; i < m->coupling_count; i++) { /* the coupling block's diagonal too */
        int r, v = m->coupling_nodes[i], n3c = 3 * m->coupling_count;
        for (r = 0; r < 3; r++) {
            int dof = 3 * v + r;
            double dgl = (diag ? (double)diag[dof] : 0.0) +
                         c * ((double)m->vertex_tensor[9 * v + 4 * r] +
                              m->coupling[(size_t)(3 * i + r) * n3c + 3 * i + r]);
            pinv[dof] = (tmass_real)(m->free_mask[dof] > 0 && dgl > 0 ? 1.0 / dgl : 0.0);
        }
    }
    if (m->anchor_count) tmass__anchor_jacobi(m, diag, c, pinv);
    m->stats.cg_residual = 0;
    m->cg_indefinite = 0;
    m->cg_last_iterations = 0;
    /* |b|^2 overflowing (or a non-finite load) would make the tolerance infinite and pass
       any iterate: a failure, never a pass (issue 18 item 13) */
    if (!tmass__finite(bb)) return TMASS_ERR_NOT_FINITE;
    if (bb == 0.0) {
        memset(x, 0, sizeof(tmass_real) * (size_t)n3);
        return TMASS_OK;
    }
    tol2 = (double)m->cg_tolerance * (double)m->cg_tolerance * bb;
    if (coarse) {
        tmass__coarse_step_build(m, diag, c);
        m->stats.coarse_solves++;
    }
    /* r = b - A x, z = P^-1 r, p = z (once per solve: plain serial loops) */
    tmass__matvec(m, x, k.q);
    rr = rz = 0.0;
    for (i = 0; i < n3; i++) {
        double ax = (diag ? (double)diag[i] * x[i] : 0.0) + c * (double)k.q[i];
        k.r[i] = (tmass_real)(((double)b[i] - ax) * m->free_mask[i]);
        k.z[i] = pinv[i] * k.r[i];
        rr += (double)k.r[i] * k.r[i];
    }
    if (coarse) tmass__coarse_apply(m, k.r, k.z);
    for (i = 0; i < n3; i++) {
        k.p[i] = k.z[i];
        rz += (double)k.r[i] * k.z[i];
    }
    pdp = rz; /* p . B^-1 p for p = z = B r (B the preconditioner): r . z */
    for (it = 0; it < m->cg_max_iterations && rr > tol2; it++) {
        double pq, rz_new, rho;
        tmass__matvec(m, k.p, k.q);
        tmass__run(m, blocks, tmass__cg_apply, &k);
        pq = tmass__sum_partials(m, 0);
        if (!tmass__finite(pq)) { /* overflow in K p */
            it++;
            rr = HUGE_VAL;
            break;
        }
        if (!(pq > 0.0)) { /* not positive definite along p: singular or indefinite */
            m->cg_indefinite = 1;
            break;
        }
        /* the Rayleigh quotient of D^-1 A along p (D the Jacobi diagonal) lies between
           its extreme eigenvalues: their ratio bounds cond from below */
        rho = pq / pdp;
        if (rho > rho_max) rho_max = rho;
        if (rho < rho_min) rho_min = rho;
        k.alpha = rz / pq;
        tmass__run(m, blocks, tmass__cg_update, &k);
        rr = tmass__sum_partials(m, 0);
        rz_new = tmass__sum_partials(m, blocks);
        if (coarse) { /* z = Jacobi r + P A_c^-1 P^T r: r . z again (serial, in order) */
            tmass__coarse_apply(m, k.r, k.z);
            rz_new = 0.0;
            for (i = 0; i < n3; i++) rz_new += (double)k.r[i] * k.z[i];
        }
        if (!tmass__finite(rr) || !tmass__finite(rz_new)) {
            it++;
            rr = HUGE_VAL;
            break;
        }
        k.beta = rz_new / rz;
        pdp = rz_new + k.beta * k.beta * pdp; /* z_new . B^-1 p_old = r_new . p_old = 0 */
        rz = rz_new;
        tmass__run(m, blocks, tmass__cg_direction, &k);
    }
    m->cg_last_iterations = it;
    m->stats.cg_iterations += it;
    m->stats.cg_residual = (tmass_real)sqrt(rr / bb);
    m->stats.stiffness_products += it + 1;
    m->stats.negative_curvature += m->cg_indefinite;
    if (rho_max > 0.0 && rho_min > 0.0 && rho_max / rho_min > (double)m->stats.cg_condition)
        m->stats.cg_condition = (tmass_real)(rho_max / rho_min);
    if (rr <= tol2) return TMASS_OK;
    return tmass__finite(rr) ? TMASS_ERR_NO_CONVERGENCE : TMASS_ERR_NOT_FINITE;
}

/* The linear solvers, one row per tmass_linear_solver (HOW TO EXTEND). Every linear
   solve of this header goes through tmass__linear_solve (one system) or
   tmass__linear_solve_block (TMASS__RHS systems with the same matrix, the quasi-static
   precomputation); both return TMASS_OK, TMASS_ERR_NO_CONVERGENCE (iteration cap, or
   non-positive curvature) or TMASS_ERR_NOT_FINITE. */
typedef struct tmass__linear_solver_ops {
    const char *name;
    /* (D + c K) x = b on the free degrees of freedom, x the initial guess (see tmass__cg).
       Stopping on a direction p with p . A p <= 0, it sets m->cg_indefinite and leaves p
       in m->cg_p and mask A p in m->cg_q (the springs' minimum check reads them). */
    int (*solve)(tmass_model *m, const tmass_real *diag, double c, const tmass_real *b, tmass_real *x);
    /* K X = B for TMASS__RHS interleaved columns; w four work arrays like X, pinv the
       Jacobi inverse diagonal (see tmass__cg_block) */
    int (*solve_block)(tmass_model *m, const tmass_real *B, tmass_real *X, tmass_real **w,
                       const tmass_real *pinv, double tol, int max_iterations);
} tmass__linear_solver_ops;

static int tmass__cg_block(tmass_model *m, const tmass_real *B, tmass_real *X, tmass_real **w,
                           const tmass_real *pinv, double tol, int max_iterations);

static const tmass__linear_solver_ops tmass__linear_solvers[] = {
    {"Jacobi-preconditioned CG", tmass__cg, tmass__cg_block}};
typedef char tmass__linear_solvers_size_check[sizeof tmass__linear_solvers / sizeof tmass__linear_solvers[0] ==
                                                      TMASS_LINEAR_SOLVER_COUNT ? 1 : -1];

static int tmass__linear_solve(tmass_model *m, const tmass_real *diag, double c, const tmass_real *b,
                               tmass_real *x)
{
    return tmass__linear_solvers[m->linear_solver].solve(m, diag, c, b, x);
}

static int tmass__linear_solve_block(tmass_model *m, const tmass_real *B, tmass_real *X, tmass_real **w,
                                     const tmass_real *pinv, double tol, int max_iterations)
{
    return tmass__linear_solvers[m->linear_solver].solve_block(m, B, X, w, pinv, tol, max_iterations);
}

/* >>integrators ----------------------------------------------------------------------- */

static int tmass__all_finite(const tmass_real *a, size_t count)
{
    size_t i;
    int ok = 1;
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

/* The integrators. Each step function reads the step's start (m->step_u0, m->step_v0:
   displacements and velocities, pinned nodes at their targets) and writes its result to
   m->step_u1, m->step_v1; tmass_step_ex checks and commits it. They are listed in
   tmass__integrators (below), indexed by tmass_integrator. */
static int tmass__explicit_euler(tmass_model *m, tmass_real dt)
{
    int i, n3 = 3 * m->node_count;
    const tmass_real *x0 = m->step_u0, *v0 = m->step_v0;
    tmass_real *x1 = m->step_u1, *v1 = m->step_v1, *a = m->step_accel;
    tmass__acceleration(m, x0, v0, a, m->force_work);
    for (i = 0; i < n3; i++) {
        x1[i] = x0[i] + dt * v0[i] * m->free_mask[i];
        v1[i] = v0[i] + dt * a[i];
    }
    return TMASS_OK;
}

static int tmass__semi_implicit_euler(tmass_model *m, tmass_real dt)
{
    int i, n3 = 3 * m->node_count;
    const tmass_real *x0 = m->step_u0, *v0 = m->step_v0;
    tmass_real *x1 = m->step_u1, *v1 = m->step_v1, *a = m->step_accel;
    tmass__acceleration(m, x0, v0, a, m->force_work);
    for (i = 0; i < n3; i++) {
        v1[i] = v0[i] + dt * a[i];
        x1[i] = x0[i] + dt * v1[i] * m->free_mask[i];
    }
    return TMASS_OK;
}

static int tmass__rk4(tmass_model *m, tmass_real dt)
{
    /* k1 = f(y0), k2 = f(y0 + dt/2 k1), k3 = f(y0 + dt/2 k2), k4 = f(y0 + dt k3),
       y1 = y0 + dt/6 (k1 + 2 k2 + 2 k3 + k4); y = (x, v), f(y) = (v, a(x, v)).
       x1, v1 accumulate; (xs, vs) is the stage state, a its acceleration. */
    int i, stage, n3 = 3 * m->node_count;
    const tmass_real *x0 = m->step_u0, *v0 = m->step_v0;
    tmass_real *x1 = m->step_u1, *v1 = m->step_v1;
    tmass_real *xs = m->rk4_u, *vs = m->rk4_v, *a = m->step_accel, *w = m->force_work;
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
    return TMASS_OK;
}

/* Backward Euler, linearised once (exact for the linear tensor model):
       (M (1 + dt alpha) + dt^2 K + dt D) dv = dt (f(x0, v0) - dt K v0_free + f_ext + M g
                                                  - alpha M v0),
   x1 = x0 + dt (v0 + dv) on the free nodes, where D = beta K (tensor) or the axial spring
   damping. x0 already holds the pinned nodes at their targets (tmass__begin_step) and v0
   their velocity (target - u) / dt: that velocity enters the damping forces only, never
   the elastic prediction x0 + dt v0 (which would count the pinned move twice, issue 18
   item 6). A CG that does not reach its tolerance fails the step (issue 18 item 9). */
/* tensor: f(x0, v0) - dt K v0_free = -K (u0 + beta v0 + dt v0_free); c = dt^2 + dt beta */
static double tmass__tensor_differential(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                         const tmass_real *v0, tmass_real *f)
{
    int i, n3 = 3 * m->node_count;
    tmass_real *w = m->force_work, beta = m->stiffness_damping;
    for (i = 0; i < n3; i++) w[i] = x0[i] + (beta + dt * m->free_mask[i]) * v0[i];
    tmass__matvec_elastic_neg(m, w, f);
    if (m->anchor_count) tmass__anchor_force(m, w, NULL, 0.0, f); /* -k ((rest - t) + w) */
    m->stats.force_evaluations++;
    return (double)dt * dt + (double)dt * m->stiffness_damping;
}

/* springs: the force (damping with the full v0), the tangent S = dt^2 K + dt D into the
   tensors (c = 1), and K v0_free */
static double tmass__spring_differential(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                         const tmass_real *v0, tmass_real *f)
{
    int i, n3 = 3 * m->node_count;
    tmass_real *vfree = m->implicit_vfree, *kv = m->implicit_kv;
    for (i = 0; i < n3; i++) vfree[i] = v0[i] * m->free_mask[i];
    tmass__spring_forces(m, x0, v0, f, (double)dt * dt, (double)dt, vfree, kv, 0);
    for (i = 0; i < n3; i++) f[i] -= dt * kv[i];
    return 1.0;
}

static int tmass__implicit_euler_linear(tmass_model *m, tmass_real dt)
{
    int i, r, n = m->node_count, n3 = 3 * n, err;
    const tmass_real *x0 = m->step_u0, *v0 = m->step_v0;
    tmass_real *x1 = m->step_u1, *v1 = m->step_v1;
    tmass_real *f = m->implicit_rhs, *dmass = m->implicit_diag, *dv = m->implicit_dv;
    tmass_real alpha = m->mass_damping;
    double c;
    for (i = 0; i < n3; i++) dmass[i] = (tmass_real)((1.0 + (double)dt * alpha) * (double)m->mass[i / 3]);
    c = tmass__kinds[m->kind].differential(m, dt, x0, v0, f);
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            f[j] = dt * (f[j] + m->ext[j] + m->mass[i] * (m->gravity[r] - alpha * v0[j]));
        }
    memcpy(dv, m->dv_prev, sizeof(tmass_real) * (size_t)n3);
    /* the coarse correction (>>coarse): a linear kind's K is in the tensors; the automatic
       mode switches it on for good after a solve that needed the minimum */
    m->cg_coarse = (tmass__kinds[m->kind].flags & TMASS__KIND_LINEAR) && m->agg_count > 0 &&
                   (m->implicit_coarse > 0 || m->coarse_on);
    err = tmass__linear_solve(m, dmass, c, f, dv);
    if (!m->cg_coarse && m->implicit_coarse == 0 && m->cg_last_iterations >= TMASS__COARSE_MIN_ITERATIONS)
        m->coarse_on = 1;
    m->cg_coarse = 0;
    if (err) return err;
    for (i = 0; i < n3; i++) {
        tmass_real fm = m->free_mask[i];
        v1[i] = v0[i] + dv[i] * fm;
        x1[i] = x0[i] + dt * v1[i] * fm;
    }
    memcpy(m->dv_prev, dv, sizeof(tmass_real) * (size_t)n3);
    return TMASS_OK;
}

/* Implicit Euler of the spring model as the minimisation of the incremental potential
   (issue 18): x1 solves, on the free nodes, with v(x) = (x - x0) / dt (pinned nodes keep
   x0, their targets, and v0, their velocity)
       R(x) = dt^2 (f_spring(x, v(x)) + f_ext + M g - alpha M v(x)) - M (x - x0 - dt v0) = 0,
   by Newton: (M (1 + dt alpha) + dt^2 K_t(x) + dt D(x)) dx = R(x), K_t the tangent with
   compressed springs' negative geometric term clamped (positive definite), D the axial
   damping. A backtracking line search (up to 10 halvings) accepts a step that lowers the
   incremental potential
       Phi(x) = dt^2 (E(x) - (f_ext + M g) . x) + 1/2 |x - x0 - dt v0|_M^2 + dt alpha / 2 |x - x0|_M^2
   (the axial damping, dissipative, is left out of Phi) or the residual. Converged when
   |R| <= newton_tolerance * max(|R(x0 + dt v0)|, dt^2 |f_ext + M g|); the cap
   newton_iterations or a failed linear solve fails the step, state kept. */
static double tmass__spring_energy(const tmass_model *m, const tmass_real *u);

/* Round-off floor of a spring residual at displacement u (squared): a displacement is
   rounded to eps |u_i|, which moves the residual by about eps |u_i| A_ii, A the system's
   diagonal (diag, or none, plus the tangent built by the last residual evaluation in the
   vertex tensors). A Newton solve cannot get below it whatever its tolerance: in float it
   is often 1e-4 of the load on stiff meshes. */
static double tmass__roundoff_floor2(const tmass_model *m, const tmass_real *u, const tmass_real *diag)
{
    double eps = sizeof(tmass_real) == sizeof(float) ? (double)FLT_EPSILON : DBL_EPSILON, s = 0.0;
    int i, n3 = 3 * m->node_count;
    for (i = 0; i < n3; i++) {
        double a = (diag ? (double)diag[i] : 0.0) + (double)m->vertex_tensor[9 * (i / 3) + 4 * (i % 3)];
        double e = eps * fabs((double)u[i]) * a * m->free_mask[i];
        s += e * e;
    }
    for (i = 0; i < m->anchor_count; i++) { /* the anchors' k (in the tangent's scale) */
        int r, j;
        for (r = 0; r < 3; r++) {
            double e;
            j = 3 * m->anchor_nodes[i] + r;
            e = eps * fabs((double)u[j]) * m->anchor_scale * (double)m->anchor_k[i] * m->free_mask[j];
            s += e * e;
        }
    }
    return s;
}

static double tmass__spring_dyn_residual(tmass_model *m, tmass_real dt, const tmass_real *x0,
                                         const tmass_real *v0, const tmass_real *x, tmass_real *R,
                                         tmass_real *v)
{
    int i, n3 = 3 * m->node_count;
    double rr = 0.0, h2 = (double)dt * dt, alpha = m->mass_damping;
    for (i = 0; i < n3; i++) v[i] = m->free_mask[i] > 0 ? (x[i] - x0[i]) / dt : v0[i];
    tmass__spring_forces(m, x, v, R, h2, (double)dt, NULL, NULL, 0);
    for (i = 0; i < n3; i++) {
        double mi = (double)m->mass[i / 3];
        double r = h2 * ((double)R[i] + m->ext[i] + mi * (m->gravity[i % 3] - alpha * v[i])) -
                   mi * ((double)x[i] - x0[i] - (double)dt * v0[i]);
        R[i] = (tmass_real)(r * m->free_mask[i]);
        rr += (double)R[i] * R[i];
    }
    return rr;
}

static double tmass__spring_incremental_potential(const tmass_model *m, tmass_real dt, const tmass_real *x0,
                                                  const tmass_real *v0, const tmass_real *x)
{
    int i, n3 = 3 * m->node_count;
    double h2 = (double)dt * dt, work = 0.0, inertia = 0.0;
    for (i = 0; i < n3; i++) {
        double mi = (double)m->mass[i / 3], fm = m->free_mask[i];
        double dx = (double)x[i] - x0[i], pred = dx - (double)dt * v0[i];
        work += fm * ((double)m->ext[i] + mi * m->gravity[i % 3]) * x[i];
        inertia += fm * 0.5 * mi * (pred * pred + (double)dt * m->mass_damping * dx * dx);
    }
    return h2 * (tmass__spring_energy(m, x) - work) + inertia;
}

static int tmass__spring_implicit_newton(tmass_model *m, tmass_real dt)
{
    int i, n3 = 3 * m->node_count, it, err, halvings;
    const tmass_real *x0 = m->step_u0, *v0 = m->step_v0;
    tmass_real *x1 = m->step_u1, *v1 = m->step_v1; /* v1 holds v(x) */
    tmass_real *R = m->newton_residual, *dmass = m->implicit_diag, *dx = m->newton_dx, *xt = m->newton_trial;
    double rr, ref2, load2 = 0.0, tol2, h2 = (double)dt * dt;
    for (i = 0; i < n3; i++) {
        dmass[i] = (tmass_real)((1.0 + (double)dt * m->mass_damping) * (double)m->mass[i / 3]);
        x1[i] = x0[i] + dt * v0[i] * m->free_mask[i]; /* the predictor */
        load2 += m->free_mask[i] * h2 * h2 *
                 ((double)m->ext[i] + (double)m->mass[i / 3] * m->gravity[i % 3]) *
                 ((double)m->ext[i] + (double)m->mass[i / 3] * m->gravity[i % 3]);
    }
    rr = tmass__spring_dyn_residual(m, dt, x0, v0, x1, R, v1);
    if (!tmass__finite(rr) || !tmass__finite(load2)) return TMASS_ERR_NOT_FINITE;
    ref2 = rr > load2 ? rr : load2;
    tol2 = m->newton_tolerance * m->newton_tolerance * ref2;
    for (it = 0;; it++) {
        double slope = 0.0, phi, rt = 0.0, alpha = 1.0;
        m->stats.residual = (tmass_real)(ref2 > 0 ? sqrt(rr / ref2) : 0.0);
        if (rr <= tol2 || rr <= tmass__roundoff_floor2(m, x1, dmass)) break;
        if (it >= m->newton_iterations) return TMASS_ERR_NO_CONVERGENCE;
        m->stats.newton_iterations++;
        memset(dx, 0, sizeof(tmass_real) * (size_t)n3);
        err = tmass__linear_solve(m, dmass, 1.0, R, dx);
        if (err) return err;
        for (i = 0; i < n3; i++) slope += (double)R[i] * dx[i];
        phi = tmass__spring_incremental_potential(m, dt, x0, v0, x1);
        for (halvings = 0; halvings <= 10; halvings++, alpha *= 0.5) {
            for (i = 0; i < n3; i++) xt[i] = x1[i] + (tmass_real)alpha * dx[i];
            rt = tmass__spring_dyn_residual(m, dt, x0, v0, xt, R, v1);
            if (rt < rr || tmass__spring_incremental_potential(m, dt, x0, v0, xt) <= phi - 1e-4 * alpha * slope)
                break;
            m->stats.line_search_cuts++;
        }
        memcpy(x1, xt, sizeof(tmass_real) * (size_t)n3); /* R and v1 are at xt */
        rr = rt;
        if (!tmass__finite(rr)) return TMASS_ERR_NOT_FINITE;
    }
    memset(m->dv_prev, 0, sizeof(tmass_real) * (size_t)n3);
    for (i = 0; i < n3; i++) v1[i] = m->free_mask[i] > 0 ? (x1[i] - x0[i]) / dt : v0[i];
    return TMASS_OK;
}

/* Divergence check of the explicit integrators (issue 18 item 15): 1 if a live edge is
   stretched past divergence_strain at displacement u, i.e. l^2 - l0^2 =
   (2 d0 + du) . du > s (2 + s) l0^2 (no square root). An unstable explicit step grows
   the highest mesh modes, which are edge stretches, geometrically: the check trips within
   a few steps of a blow-up, long before anything overflows. */
static int tmass__stretched_past(const tmass_model *m, const tmass_real *u)
{
    double s = m->divergence_strain, k = s * (2.0 + s);
    int c, e;
    if (s <= 0.0) return 0;
    for (c = 0; c < m->chunk_total; c++)
        for (e = m->chunk_start[c]; e < m->chunk_start[c] + m->chunk_live[c]; e++) {
            int a = m->edge_a[e], b = m->edge_b[e], r;
            double dl2 = 0.0, l0 = (double)m->edge_rest_length[e];
            for (r = 0; r < 3; r++) {
                double d0 = (double)m->rest[3 * b + r] - (double)m->rest[3 * a + r];
                double du = (double)u[3 * b + r] - (double)u[3 * a + r];
                dl2 += (2.0 * d0 + du) * du;
            }
            if (!(dl2 <= k * l0 * l0)) return 1;
        }
    return 0;
}

/* Precision check (issue 18 item 10): the model works on displacements u = x - X, so rest
   positions far from the origin cost nothing, but a displacement of size |u| is rounded
   to eps |u|, and differences of rounded displacements fake strains of eps |u| / h on an
   edge of length h. 1 if eps(tmass_real) * max|u| > precision_limit * shortest edge. */
static int tmass__imprecise(const tmass_model *m, const tmass_real *u)
{
    double eps = sizeof(tmass_real) == sizeof(float) ? (double)FLT_EPSILON : DBL_EPSILON, big = 0.0;
    int i, n3 = 3 * m->node_count;
    if (m->precision_limit <= 0.0) return 0;
    for (i = 0; i < n3; i++) {
        double a = fabs((double)u[i]);
        if (a > big) big = a;
    }
    return eps * big > m->precision_limit * m->shortest_edge;
}

/* Live tetrahedra with non-positive volume at displacement u (O(tets)). */
static int tmass__count_inverted(const tmass_model *m, const tmass_real *u)
{
    int t, count = 0;
    for (t = 0; t < m->tet_count; t++) {
        const int *q = m->tet_nodes + 4 * t;
        double e[3][3], det;
        int j, r;
        if (!m->tet_alive[t]) continue;
        for (j = 0; j < 3; j++)
            for (r = 0; r < 3; r++)
                e[j][r] = ((double)m->rest[3 * q[j + 1] + r] - (double)m->rest[3 * q[0] + r]) +
                          ((double)u[3 * q[j + 1] + r] - (double)u[3 * q[0] + r]);
        det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
              e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
              e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
        count += !(det > 0.0);
    }
    return count;
}

/* TMASS_IMPLICIT_EULER: the kind's Newton solve where it has one, else the linearised
   step (exact for a linear kind). */
static int tmass__implicit_euler(tmass_model *m, tmass_real dt)
{
    m->stats.increments = 1;
    if (tmass__kinds[m->kind].implicit_newton) return tmass__kinds[m->kind].implicit_newton(m, dt);
    m->stats.newton_iterations = 1;
    return tmass__implicit_euler_linear(m, dt);
}

static int tmass__implicit_euler_linearized(tmass_model *m, tmass_real dt)
{
    m->stats.increments = 1;
    m->stats.newton_iterations = 1;
    return tmass__implicit_euler_linear(m, dt);
}

/* TMASS_BDF2 (issue 19): the two-step backward differentiation formula
       3 x1 - 4 x0 + x_-1 = 2 h v1,   3 v1 - 4 v0 + v_-1 = 2 h a(x1, v1),
   written as implicit Euler's step with (h, x0, v0) replaced by
       beta = 2 h / 3,  xbar = (4 x0 - x_-1) / 3,  vbar = (4 v0 - v_-1) / 3:
   x1 = xbar + beta v1, v1 = vbar + beta a(x1, v1), i.e. x1 minimises implicit Euler's
   incremental potential with beta, xbar, vbar in place of h, x0, v0 (the mass damping
   term too). So the tensor model's step is one linear solve and the springs' step is
   their Newton minimisation with its line search and acceptance test, unchanged
   (tmass__implicit_euler called with the substituted arguments, nothing copied). Pinned
   nodes keep their targets and velocities from tmass__begin_step. Without a valid
   history (first step, a different dt, or after tmass_step_ex reset it: see INTEGRATORS)
   the step is one implicit Euler step of h. */
static int tmass__bdf2(tmass_model *m, tmass_real dt)
{
    int i, n3 = 3 * m->node_count;
    tmass_real *xbar = m->step_u0, *vbar = m->step_v0;
    if (!m->history_ready || m->history_dt != dt) return tmass__implicit_euler(m, dt);
    for (i = 0; i < n3; i++)
        if (m->free_mask[i] > 0) {
            xbar[i] = (tmass_real)((4.0 * (double)m->disp[i] - (double)m->history_u[i]) / 3.0);
            vbar[i] = (tmass_real)((4.0 * (double)m->vel[i] - (double)m->history_v[i]) / 3.0);
        }
    return tmass__implicit_euler(m, (tmass_real)(2.0 * (double)dt / 3.0));
}

/* The integrators, one row per tmass_integrator (HOW TO EXTEND). is_explicit: the step
   is checked for divergence (TMASS_ERR_DIVERGED) and does not count inverted tetrahedra.
   keeps_history: an accepted step first saves the state it leaves in history_u/v (a
   multistep scheme's x_{n-1}, v_{n-1}); a step of any other integrator marks the
   history stale. */
typedef struct tmass__integrator_ops {
    const char *name;
    int (*step)(tmass_model *m, tmass_real dt); /* step_u0/v0 -> step_u1/v1 */
    int is_explicit;
    int keeps_history;
} tmass__integrator_ops;

static const tmass__integrator_ops tmass__integrators[] = {
    {"explicit Euler", tmass__explicit_euler, 1, 0},
    {"semi-implicit Euler", tmass__semi_implicit_euler, 1, 0},
    {"RK4", tmass__rk4, 1, 0},
    {"implicit Euler", tmass__implicit_euler, 0, 0},
    {"implicit Euler, linearised", tmass__implicit_euler_linearized, 0, 0},
    {"BDF2", tmass__bdf2, 0, 1}};
typedef char tmass__integrators_size_check[sizeof tmass__integrators / sizeof tmass__integrators[0] ==
                                                   TMASS_INTEGRATOR_COUNT ? 1 : -1];

TMASSDEF int tmass_step_ex(tmass_model *m, tmass_real dt, tmass_integrator integrator)
{
    const tmass__integrator_ops *ops;
    tmass_real *x1, *v1;
    int n3, err;
    if (!m) return TMASS_ERR_ARG;
    if (!(tmass__finite((double)dt) && dt > 0)) return TMASS_ERR_TIME_STEP;
    if ((unsigned)integrator >= TMASS_INTEGRATOR_COUNT) return TMASS_ERR_INTEGRATOR;
    ops = &tmass__integrators[integrator];
    n3 = 3 * m->node_count;
    x1 = m->step_u1;
    v1 = m->step_v1;
    memset(&m->stats, 0, sizeof m->stats);
    tmass__begin_step(m, dt, m->step_u0, m->step_v0);
    err = ops->step(m, dt);
    if (!err && (!tmass__all_finite(x1, (size_t)n3) || !tmass__all_finite(v1, (size_t)n3))) err = TMASS_ERR_NOT_FINITE;
    if (!err && ops->is_explicit && tmass__stretched_past(m, x1)) err = TMASS_ERR_DIVERGED;
    if (!err && tmass__imprecise(m, x1)) err = TMASS_ERR_PRECISION;
    if (err) {
        memset(m->dv_prev, 0, sizeof(tmass_real) * (size_t)n3);
        m->history_ready = 0; /* history_u/v untouched; the next BDF2 step restarts */
        return err;
    }
    if (!ops->is_explicit) m->stats.inverted = tmass__count_inverted(m, x1);
    if (ops->keeps_history) {
        memcpy(m->history_u, m->disp, sizeof(tmass_real) * (size_t)n3);
        memcpy(m->history_v, m->vel, sizeof(tmass_real) * (size_t)n3);
        m->history_dt = dt;
    }
    m->history_ready = ops->keeps_history;
    tmass__commit(m, x1, v1);
    return TMASS_OK;
}

TMASSDEF int tmass_step(tmass_model *m)
{
    if (!m) return TMASS_ERR_ARG;
    return tmass_step_ex(m, m->time_step, m->integrator);
}

/* Residual f = f_int(x) + f_ext + M g over the free degrees of freedom of the spring
   model, with the tangent stiffness built alongside (full or with compressed springs'
   negative geometric term dropped); returns |f|^2. */
static double tmass__spring_residual(tmass_model *m, const tmass_real *x, tmass_real *f, int full_tangent)
{
    int i, n3 = 3 * m->node_count;
    double ff = 0.0;
    tmass__spring_forces(m, x, NULL, f, 1.0, 0.0, NULL, NULL, full_tangent);
    for (i = 0; i < n3; i++) {
        f[i] = (f[i] + (tmass_real)m->load_scale * (m->ext[i] + m->mass[i / 3] * m->gravity[i % 3])) *
               m->free_mask[i];
        ff += (double)f[i] * f[i];
    }
    return ff;
}

/* Elastic energy of the springs at displacement u, in double, each stretch l - l0 from
   (l^2 - l0^2) / (l + l0) as in the force. */
static double tmass__spring_energy(const tmass_model *m, const tmass_real *u)
{
    int s, k, r;
    double elastic = 0.0;
    for (k = 0; k < m->chunk_total; k++)
        for (s = m->chunk_start[k]; s < m->chunk_start[k] + m->chunk_live[k]; s++) {
            int a = m->edge_a[s], b = m->edge_b[s];
            double d2 = 0.0, dl2 = 0.0, l, l0 = m->edge_rest_length[s], stretch;
            for (r = 0; r < 3; r++) {
                double d0 = (double)m->rest[3 * b + r] - m->rest[3 * a + r];
                double du = (double)u[3 * b + r] - u[3 * a + r];
                d2 += (d0 + du) * (d0 + du);
                dl2 += du * (2 * d0 + du);
            }
            l = sqrt(d2);
            stretch = l + l0 > 0 ? dl2 / (l + l0) : 0;
            elastic += 0.5 * (double)m->edge_stiffness[s] * stretch * stretch;
        }
    return elastic + (m->anchor_count ? tmass__anchor_force(m, u, NULL, 0.0, NULL) : 0.0);
}

/* Total potential of the spring model at x: elastic energy minus the work of gravity and
   the external forces on the free nodes. */
static double tmass__spring_potential(const tmass_model *m, const tmass_real *x)
{
    int i, n3 = 3 * m->node_count;
    double work = 0.0;
    for (i = 0; i < n3; i++)
        work += m->load_scale * ((double)m->ext[i] + (double)m->mass[i / 3] * m->gravity[i % 3]) * x[i] *
                m->free_mask[i];
    return tmass__spring_energy(m, x) - work;
}

/* The springs' full tangent (compressed springs' negative geometric term included) at u
   into the tensors; m->step_accel receives the force, as scratch (never inside a step). */
static void tmass__spring_tangent(tmass_model *m, const tmass_real *u)
{
    tmass__spring_forces(m, u, NULL, m->step_accel, 1.0, 0.0, NULL, NULL, 1);
}

/* Newton for the static equilibrium of the spring model at the current load_scale, from
   x (pinned entries already placed). Each iteration solves K_t du = f by CG with the full
   tangent (quadratic convergence); where compressed springs make K_t indefinite (CG meets
   p . K_t p <= 0, or du is no descent direction) it solves again with their negative
   geometric term dropped, which is positive definite, so du descends the potential. A
   backtracking line search (up to 10 halvings) accepts a step that lowers the potential
   (Armijo) or the residual: the potential guards large load increments on stiff,
   bending-dominated meshes (where the right Newton step raises |f| at first), the
   residual decides below the potential's round-off. Converged only when the residual
   |f| <= newton_tolerance * reference (ref2 = reference^2); a step that cannot move x any
   more, or the iteration cap, end the attempt with TMASS_ERR_NO_CONVERGENCE (the caller
   cuts the load increment back). */
static int tmass__spring_newton(tmass_model *m, tmass_real *x, double ref2, int cap)
{
    int i, n3 = 3 * m->node_count, it, err = TMASS_OK;
    tmass_real *f = m->newton_residual, *du = m->newton_dx, *xt = m->newton_trial;
    double ff, tol = m->newton_tolerance, tol2 = tol * tol * ref2;
    double eps = sizeof(tmass_real) == sizeof(float) ? (double)FLT_EPSILON : DBL_EPSILON;
    ff = tmass__spring_residual(m, x, f, 1);
    for (it = 0; it < cap; it++) {
        double dn = 0.0, xn = 0.0, alpha = 1.0, fft = 0.0, slope, potential;
        int halvings;
        m->stats.residual = (tmass_real)sqrt(ff / ref2);
        if (!tmass__finite(ff)) return TMASS_ERR_NOT_FINITE;
        if (ff <= tol2 || ff <= tmass__roundoff_floor2(m, x, NULL)) return TMASS_OK;
        m->stats.newton_iterations++;
        memset(du, 0, sizeof(tmass_real) * (size_t)n3);
        err = tmass__linear_solve(m, NULL, 1.0, f, du);
        slope = 0.0; /* f . du = minus the potential's slope along du */
        for (i = 0; i < n3; i++) slope += (double)f[i] * du[i];
        if ((err && m->cg_indefinite) || (!err && !(slope > 0))) { /* on the PD part */
            tmass__spring_residual(m, x, f, 0);
            memset(du, 0, sizeof(tmass_real) * (size_t)n3);
            err = tmass__linear_solve(m, NULL, 1.0, f, du);
            slope = 0.0;
            for (i = 0; i < n3; i++) slope += (double)f[i] * du[i];
        }
        if (err) return err;
        potential = tmass__spring_potential(m, x);
        for (halvings = 0; halvings <= 10; halvings++, alpha *= 0.5) {
            for (i = 0; i < n3; i++) xt[i] = x[i] + (tmass_real)alpha * du[i];
            fft = tmass__spring_residual(m, xt, f, 1);
            if (fft < ff || tmass__spring_potential(m, xt) <= potential - 1e-4 * alpha * slope) break;
            m->stats.line_search_cuts++;
        }
        /* no decrease even at 1/1024 of the step: take it anyway (f and the tangent are
           at xt); the iteration cap ends an attempt that cannot progress */
        for (i = 0; i < n3; i++) {
            double step = (double)xt[i] - x[i];
            x[i] = xt[i];
            dn += step * step;
            xn += (double)x[i] * x[i];
        }
        ff = fft;
        if (ff <= tol2 || ff <= tmass__roundoff_floor2(m, x, NULL)) continue; /* accepted above */
        if (dn <= 16.0 * eps * eps * (xn > 0 ? xn : 1.0)) { /* stalled */
            m->stats.residual = (tmass_real)sqrt(ff / ref2);
            return TMASS_ERR_NO_CONVERGENCE;
        }
    }
    m->stats.residual = (tmass_real)sqrt(ff / ref2);
    if (!tmass__finite(ff)) return TMASS_ERR_NOT_FINITE;
    return ff <= tol2 || ff <= tmass__roundoff_floor2(m, x, NULL) ? TMASS_OK : TMASS_ERR_NO_CONVERGENCE;
}

/* Static equilibrium of the spring model with load continuation (issue 18): the load
   fraction s goes from 0 to 1, scaling gravity and the external forces and moving each
   pinned node from where it is to its target; each increment is a Newton solve
   (tmass__spring_newton) from the last accepted state. The whole load is tried first; a
   failed increment is cut to a quarter, an accepted one lets the next double. Gives up
   with the last error (state kept) below an increment of TMASS__MIN_INCREMENT or past
   TMASS__MAX_INCREMENTS attempts. The residual reference is the residual with the free
   nodes at rest and the pinned nodes at their targets under the whole load (the scale of
   the problem, whatever the starting state). */
#define TMASS__MAX_INCREMENTS 64
#define TMASS__MIN_INCREMENT 1e-4
static int tmass__spring_static(tmass_model *m, tmass_real *x)
{
    int i, n3 = 3 * m->node_count, err = TMASS_OK, attempts = 0;
    tmass_real *accepted = m->static_accepted, *f = m->newton_residual;
    double s = 0.0, ds = 1.0, ref2;
    for (i = 0; i < n3; i++) accepted[i] = m->pin_mask[i] * m->target[i];
    m->load_scale = 1.0;
    ref2 = tmass__spring_residual(m, accepted, f, 1);
    if (!tmass__finite(ref2)) return TMASS_ERR_NOT_FINITE;
    if (ref2 == 0.0) ref2 = tmass__spring_residual(m, x, f, 1);
    if (ref2 == 0.0) return TMASS_OK; /* at rest, unloaded: nothing to do */
    memcpy(accepted, m->disp, sizeof(tmass_real) * (size_t)n3);
    while (s < 1.0) {
        double next = s + ds < 1.0 ? s + ds : 1.0;
        if (++attempts > TMASS__MAX_INCREMENTS) break;
        for (i = 0; i < n3; i++) {
            tmass_real pin = m->pin_mask[i];
            x[i] = pin > 0 ? m->disp[i] + (tmass_real)next * (m->target[i] - m->disp[i]) : accepted[i];
        }
        m->load_scale = next;
        err = tmass__spring_newton(m, x, ref2, m->newton_iterations);
        if (err == TMASS_OK) {
            memcpy(accepted, x, sizeof(tmass_real) * (size_t)n3);
            s = next;
            m->stats.increments++;
            ds *= 2.0;
        } else {
            m->stats.increment_cuts++;
            ds *= 0.25;
            if (ds < TMASS__MIN_INCREMENT) break;
        }
    }
    m->load_scale = 1.0;
    if (s < 1.0) return err ? err : TMASS_ERR_NO_CONVERGENCE;
    memcpy(x, accepted, sizeof(tmass_real) * (size_t)n3);
    return TMASS_OK;
}

/* Static equilibrium of the tensor model: one linear solve K du = f (it is linear: a
   converged, finite solve is exact for the model). */
static int tmass__tensor_static(tmass_model *m, tmass_real *x)
{
    int i, n3 = 3 * m->node_count, err;
    tmass_real *f = m->newton_residual, *du = m->newton_dx;
    m->stats.newton_iterations = 1;
    m->stats.increments = 1;
    tmass__internal_force(m, x, NULL, f, m->force_work);
    for (i = 0; i < n3; i++)
        f[i] = (f[i] + m->ext[i] + m->mass[i / 3] * m->gravity[i % 3]) * m->free_mask[i];
    memset(du, 0, sizeof(tmass_real) * (size_t)n3);
    err = tmass__linear_solve(m, NULL, 1.0, f, du);
    for (i = 0; i < n3; i++) x[i] += du[i];
    return err;
}

static double tmass__spring_energy_of(tmass_model *m, const tmass_real *u) { return tmass__spring_energy(m, u); }

/* Is the spring model's converged static state x a minimum? A zero residual holds at
   saddles too (a tetrahedron flattened through its base: its compressed springs balance,
   and either mirror image of the rest shape lies lower). A probe solve K_t y = b with the
   full tangent at x (b a fixed pseudo-random vector on the free axes, CG to 1e-7, float
   1e-5) meets a direction p of negative curvature where K_t is indefinite; p . K_t p below
   -1e3 eps sum_k |p_k (K_t p)_k| (its round-off) is a saddle: TMASS_ERR_UNSTABLE. So is a
   diagonal entry below -1e3 eps max |diagonal| (the Jacobi preconditioner hides those
   axes from CG). A probe at its cap counts as a minimum. It reads the direction the
   linear solver stopped on (m->cg_p, and m->cg_q = mask K_t p: the contract of a solver
   that reports m->cg_indefinite, see tmass__linear_solver_ops). Works in the static
   probe vectors (x is m->static_u). */
static int tmass__spring_check_minimum(tmass_model *m, const tmass_real *x)
{
    int i, n3 = 3 * m->node_count, err;
    tmass_real *b = m->static_probe_rhs, *y = m->static_probe_x, *p = m->cg_p, *q = m->cg_q;
    tmass_real tolerance = m->cg_tolerance;
    double pq = 0.0, scale = 0.0, eps = sizeof(tmass_real) == sizeof(float) ? (double)FLT_EPSILON : DBL_EPSILON;
    double dmax = 0.0, dmin = 0.0;
    tmass__spring_residual(m, x, b, 1); /* the full tangent at x */
    /* a negative diagonal entry is negative curvature along that axis (and the Jacobi
       preconditioner zeroes such axes, so CG would not see them) */
    for (i = 0; i < n3; i++) {
        double dg = (double)m->vertex_tensor[9 * (i / 3) + 4 * (i % 3)] * (double)m->free_mask[i];
        if (fabs(dg) > dmax) dmax = fabs(dg);
        if (dg < dmin) dmin = dg;
    }
    if (dmin < -1e3 * eps * dmax) return TMASS_ERR_UNSTABLE;
    for (i = 0; i < n3; i++) {
        unsigned h = (unsigned)i * 2654435761u;
        h ^= h >> 15;
        h *= 2246822519u;
        h ^= h >> 13;
        b[i] = (tmass_real)(((double)(h & 0xffffu) / 32768.0 - 1.0) * (double)m->free_mask[i]);
        y[i] = 0;
    }
    m->cg_tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-5 : 1e-7);
    err = tmass__linear_solve(m, NULL, 1.0, b, y);
    m->cg_tolerance = tolerance;
    if (err == TMASS_ERR_NOT_FINITE) return err;
    if (!m->cg_indefinite) return TMASS_OK;
    for (i = 0; i < n3; i++) { /* p: the direction CG stopped on, q = mask K_t p */
        pq += (double)p[i] * (double)q[i] * (double)m->free_mask[i];
        scale += fabs((double)p[i] * (double)q[i]) * (double)m->free_mask[i];
    }
    return pq < -1e3 * eps * scale ? TMASS_ERR_UNSTABLE : TMASS_OK;
}

/* The springs' static solve (their row of tmass__kinds): the load continuation, then the
   minimum check. */
static int tmass__spring_static_solve(tmass_model *m, tmass_real *x)
{
    int err = tmass__spring_static(m, x);
    if (!err) err = tmass__spring_check_minimum(m, x);
    return err;
}

/* Static equilibrium: one CG solve K u = f_ext + M g for the tensor model (it is
   linear: a converged, finite solve is exact for the model), the continuation of
   tmass__spring_static for the spring model. Accepted only with finite values inside
   the precision limit; the state is kept otherwise. */
TMASSDEF int tmass_solve_static(tmass_model *m)
{
    int i, n3, err = TMASS_OK;
    tmass_real *x;
    if (!m) return TMASS_ERR_ARG;
    n3 = 3 * m->node_count;
    x = m->static_u;
    memset(&m->stats, 0, sizeof m->stats);
    for (i = 0; i < n3; i++) {
        tmass_real pin = m->pin_mask[i];
        x[i] = m->disp[i] + pin * (m->target[i] - m->disp[i]);
    }
    err = tmass__kinds[m->kind].static_solve(m, x);
    if (err) return err;
    if (!tmass__all_finite(x, n3)) return TMASS_ERR_NOT_FINITE;
    if (tmass__imprecise(m, x)) return TMASS_ERR_PRECISION;
    m->stats.inverted = tmass__count_inverted(m, x);
    tmass__commit(m, x, NULL);
    m->history_ready = 0;
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
    m->history_ready = 0; /* the forces changed discontinuously: BDF2 restarts */
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
    m->history_ready = 0;
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
    m->history_ready = 0;
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

TMASSDEF int tmass_set_anchors(tmass_model *m, int count, const int *nodes, const tmass_real *stiffness,
                               const tmass_real *targets)
{
    int a;
    if (!m || count < 0 || (count > 0 && (!nodes || !stiffness || !targets))) return TMASS_ERR_ARG;
    for (a = 0; a < count; a++) {
        if (nodes[a] < 0 || nodes[a] >= m->node_count) return TMASS_ERR_NODE_RANGE;
        if (!(tmass__finite((double)stiffness[a]) && stiffness[a] >= 0) || !tmass__vec3_finite(targets + 3 * a))
            return TMASS_ERR_ARG;
    }
    m->anchor_count = count;
    m->coarse_version++; /* the anchors' k joins the coarse matrix (>>coarse) */
    m->anchor_nodes = count ? nodes : NULL;
    m->anchor_k = count ? stiffness : NULL;
    m->anchor_target = count ? targets : NULL;
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

TMASSDEF int tmass_set_damping(tmass_model *m, tmass_real mass_damping, tmass_real stiffness_damping)
{
    if (!m) return TMASS_ERR_ARG;
    if (!(tmass__finite((double)mass_damping) && mass_damping >= 0) ||
        !(tmass__finite((double)stiffness_damping) && stiffness_damping >= 0))
        return TMASS_ERR_DAMPING;
    m->mass_damping = mass_damping;
    m->stiffness_damping = stiffness_damping;
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
TMASSDEF const tmass_real *tmass_displacements(const tmass_model *m) { return m ? m->disp : NULL; }
TMASSDEF const tmass_real *tmass_velocities(const tmass_model *m) { return m ? m->vel : NULL; }
TMASSDEF const tmass_real *tmass_rest_positions(const tmass_model *m) { return m ? m->rest : NULL; }
TMASSDEF const tmass_real *tmass_masses(const tmass_model *m) { return m ? m->mass : NULL; }
TMASSDEF const tmass_stats *tmass_last_stats(const tmass_model *m) { return m ? &m->stats : NULL; }
TMASSDEF size_t tmass_memory_bytes(const tmass_model *m) { return m ? m->block_bytes : 0; }

TMASSDEF const tmass_real *tmass_forces(tmass_model *m)
{
    if (!m) return NULL;
    tmass__internal_force(m, m->disp, NULL, m->force, m->force_work);
    return m->force;
}

TMASSDEF int tmass_apply_stiffness(tmass_model *m, const tmass_real *dx, tmass_real *out)
{
    if (!m || !dx || !out) return TMASS_ERR_ARG;
    if (tmass__kinds[m->kind].tangent) tmass__kinds[m->kind].tangent(m, m->disp);
    tmass__matvec(m, dx, out);
    m->stats.stiffness_products++;
    return TMASS_OK;
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
    m->history_ready = 0;
    return TMASS_OK;
}

TMASSDEF int tmass_set_velocities(tmass_model *m, const tmass_real *velocities)
{
    int i;
    if (!m || !velocities) return TMASS_ERR_ARG;
    if (!tmass__all_finite(velocities, 3 * m->node_count)) return TMASS_ERR_ARG;
    for (i = 0; i < 3 * m->node_count; i++)
        m->vel[i] = m->node_state[i / 3] == TMASS__INACTIVE ? (tmass_real)0 : velocities[i];
    m->history_ready = 0;
    return TMASS_OK;
}

TMASSDEF int tmass_energy(tmass_model *m, tmass_energies *out)
{
    int i, r, n;
    double kinetic = 0.0, elastic = 0.0, grav = 0.0, ext = 0.0;
    if (!m || !out) return TMASS_ERR_ARG;
    n = m->node_count;
    elastic = tmass__kinds[m->kind].energy(m, m->disp);
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
    if (!m || !out || !(tmass__kinds[m->kind].flags & TMASS__KIND_LINEAR)) return TMASS_ERR_ARG;
    if (i < 0 || i >= m->node_count) return TMASS_ERR_NODE_RANGE;
    memcpy(out, m->vertex_tensor + 9 * i, 9 * sizeof(tmass_real));
    return TMASS_OK;
}

TMASSDEF int tmass_edge_tensor(const tmass_model *m, int a, int b, tmass_real out[9])
{
    int k, s, r, c;
    if (!m || !out || !(tmass__kinds[m->kind].flags & TMASS__KIND_LINEAR)) return TMASS_ERR_ARG;
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

/* >>probes ---------------------------------------------------------------------------- */

struct tmass_probe {
    tmass_allocator allocator;
    size_t bytes;
    int count, node_count;
    int *tet;          /* count: containing tetrahedron */
    int *nodes;        /* 4 * count */
    tmass_real *weight; /* 4 * count barycentric weights */
    tmass_real *rest;  /* 3 * count rest points */
};

/* Barycentric weights of point x in tetrahedron t (rest state), from differences formed in
   double; returns the smallest weight. */
static double tmass__barycentric(const tmass_model *m, int t, const tmass_real *x, double w[4])
{
    const int *q = m->tet_nodes + 4 * t;
    double e[3][3], d[3], det, inv[3][3], lo;
    int j, r;
    for (j = 0; j < 3; j++)
        for (r = 0; r < 3; r++) e[r][j] = (double)m->rest[3 * q[j + 1] + r] - (double)m->rest[3 * q[0] + r];
    for (r = 0; r < 3; r++) d[r] = (double)x[r] - (double)m->rest[3 * q[0] + r];
    det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) - e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
          e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
    inv[0][0] = (e[1][1] * e[2][2] - e[1][2] * e[2][1]) / det;
    inv[0][1] = (e[0][2] * e[2][1] - e[0][1] * e[2][2]) / det;
    inv[0][2] = (e[0][1] * e[1][2] - e[0][2] * e[1][1]) / det;
    inv[1][0] = (e[1][2] * e[2][0] - e[1][0] * e[2][2]) / det;
    inv[1][1] = (e[0][0] * e[2][2] - e[0][2] * e[2][0]) / det;
    inv[1][2] = (e[0][2] * e[1][0] - e[0][0] * e[1][2]) / det;
    inv[2][0] = (e[1][0] * e[2][1] - e[1][1] * e[2][0]) / det;
    inv[2][1] = (e[0][1] * e[2][0] - e[0][0] * e[2][1]) / det;
    inv[2][2] = (e[0][0] * e[1][1] - e[0][1] * e[1][0]) / det;
    w[0] = 1.0;
    for (j = 0; j < 3; j++) {
        w[j + 1] = inv[j][0] * d[0] + inv[j][1] * d[1] + inv[j][2] * d[2];
        w[0] -= w[j + 1];
    }
    lo = w[0];
    for (j = 1; j < 4; j++)
        if (w[j] < lo) lo = w[j];
    return lo;
}

#define TMASS__PROBE_TOLERANCE 1e-6 /* how far outside (in barycentric weight) still counts */

/* Bounding box of tetrahedron t along axis r, widened by the tolerance. */
static void tmass__tet_box(const tmass_model *m, int t, int r, double *a, double *b)
{
    const int *q = m->tet_nodes + 4 * t;
    double lo = (double)m->rest[3 * q[0] + r], hi = lo, pad;
    int j;
    for (j = 1; j < 4; j++) {
        double c = (double)m->rest[3 * q[j] + r];
        if (c < lo) lo = c;
        if (c > hi) hi = c;
    }
    pad = TMASS__PROBE_TOLERANCE * (hi - lo) + 1e-300;
    *a = lo - pad;
    *b = hi + pad;
}

/* Of the live tetrahedra listed in cand (count of them, ascending; NULL: all), the one
   point x is most inside (largest smallest weight, the lowest index on ties), or -1 when
   every one leaves it outside by more than the tolerance. */
static int tmass__locate(const tmass_model *m, const tmass_real *x, const int *cand, int count, double w_best[4])
{
    double best = -TMASS__PROBE_TOLERANCE;
    int k, found = -1, j, r;
    for (k = 0; k < count; k++) {
        int t = cand ? cand[k] : k, outside = 0;
        double w[4], lo;
        if (!m->tet_alive[t]) continue;
        for (r = 0; r < 3 && !outside; r++) {
            double a, b;
            tmass__tet_box(m, t, r, &a, &b);
            outside = (double)x[r] < a || (double)x[r] > b;
        }
        if (outside) continue;
        lo = tmass__barycentric(m, t, x, w);
        if (lo > best) {
            best = lo;
            found = t;
            for (j = 0; j < 4; j++) w_best[j] = w[j];
        }
    }
    return found;
}

/* A temporary uniform grid over the live tetrahedra's widened boxes (about one cell per
   tetrahedron), each cell listing, in ascending order, the tetrahedra whose box meets it:
   every tetrahedron whose box holds a point is listed in the point's cell (the cell index
   is monotonic in the coordinate), so the search over the cell gives the answer of the
   search over all. */
typedef struct tmass__grid {
    double lo[3], inv[3];
    int dim[3];
    int *start, *tets; /* cells + 1, entries */
    size_t start_bytes, tets_bytes;
} tmass__grid;

static int tmass__grid_cell(const tmass__grid *g, int r, double x)
{
    double c = floor((x - g->lo[r]) * g->inv[r]);
    if (!(c >= 0.0)) return 0;
    if (c >= (double)(g->dim[r] - 1)) return g->dim[r] - 1;
    return (int)c;
}

static void tmass__grid_free(const tmass_model *m, tmass__grid *g)
{
    tmass__free(&m->allocator, g->start, g->start_bytes);
    tmass__free(&m->allocator, g->tets, g->tets_bytes);
}

static int tmass__grid_build(const tmass_model *m, tmass__grid *g)
{
    double hi[3], volume = 1.0, h;
    int t, r, pass, cells, live = 0;
    memset(g, 0, sizeof *g);
    for (r = 0; r < 3; r++) {
        g->lo[r] = HUGE_VAL;
        hi[r] = -HUGE_VAL;
    }
    for (t = 0; t < m->tet_count; t++) {
        if (!m->tet_alive[t]) continue;
        live++;
        for (r = 0; r < 3; r++) {
            double a, b;
            tmass__tet_box(m, t, r, &a, &b);
            if (a < g->lo[r]) g->lo[r] = a;
            if (b > hi[r]) hi[r] = b;
        }
    }
    if (live == 0) return TMASS_ERR_PROBE_OUTSIDE;
    for (r = 0; r < 3; r++) volume *= hi[r] - g->lo[r];
    h = cbrt(volume / live);
    cells = 1;
    for (r = 0; r < 3; r++) {
        double d = ceil((hi[r] - g->lo[r]) / h);
        g->dim[r] = d < 1.0 ? 1 : d > 1024.0 ? 1024 : (int)d;
        g->inv[r] = g->dim[r] / (hi[r] - g->lo[r]);
        cells *= g->dim[r];
    }
    g->start_bytes = sizeof(int) * ((size_t)cells + 1);
    g->start = (int *)tmass__alloc(&m->allocator, g->start_bytes);
    if (!g->start) return TMASS_ERR_ALLOC;
    memset(g->start, 0, g->start_bytes);
    for (pass = 0; pass < 2; pass++) { /* count per cell, then fill in tetrahedron order */
        for (t = 0; t < m->tet_count; t++) {
            int i0[3], i1[3], i, j, k;
            if (!m->tet_alive[t]) continue;
            for (r = 0; r < 3; r++) {
                double a, b;
                tmass__tet_box(m, t, r, &a, &b);
                i0[r] = tmass__grid_cell(g, r, a);
                i1[r] = tmass__grid_cell(g, r, b);
            }
            for (k = i0[2]; k <= i1[2]; k++)
                for (j = i0[1]; j <= i1[1]; j++)
                    for (i = i0[0]; i <= i1[0]; i++) {
                        int c = (k * g->dim[1] + j) * g->dim[0] + i;
                        if (pass == 0) g->start[c + 1]++;
                        else g->tets[g->start[c]++] = t;
                    }
        }
        if (pass == 0) {
            int c;
            for (c = 0; c < cells; c++) g->start[c + 1] += g->start[c];
            g->tets_bytes = sizeof(int) * ((size_t)g->start[cells] + 1);
            g->tets = (int *)tmass__alloc(&m->allocator, g->tets_bytes);
            if (!g->tets) {
                tmass__grid_free(m, g);
                return TMASS_ERR_ALLOC;
            }
        }
    }
    for (t = cells; t > 0; t--) g->start[t] = g->start[t - 1]; /* the fill advanced each start */
    g->start[0] = 0;
    return TMASS_OK;
}

/* The point's cell's candidates; a point no candidate holds (outside) is searched among
   all, which confirms it is outside. */
static int tmass__grid_locate(const tmass_model *m, const tmass__grid *g, const tmass_real *x, double w[4])
{
    int c = (tmass__grid_cell(g, 2, (double)x[2]) * g->dim[1] + tmass__grid_cell(g, 1, (double)x[1])) * g->dim[0] +
            tmass__grid_cell(g, 0, (double)x[0]);
    int t = tmass__locate(m, x, g->tets + g->start[c], g->start[c + 1] - g->start[c], w);
    return t >= 0 ? t : tmass__locate(m, x, NULL, m->tet_count, w);
}

TMASSDEF int tmass_probe_create(const tmass_model *m, const tmass_real *rest_points, int count,
                                tmass_probe **out)
{
    tmass__carver c;
    tmass__grid grid;
    tmass_probe tmp, *p;
    int i, j, err;
    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (!m || count < 1 || !rest_points || !tmass__all_finite(rest_points, 3 * (size_t)count)) return TMASS_ERR_ARG;
    err = tmass__grid_build(m, &grid);
    if (err) return err;
    memset(&tmp, 0, sizeof tmp);
    c.base = NULL;
    c.offset = sizeof(tmass_probe);
    TMASS__CARVE(&c, tmp.tet, int, count);
    TMASS__CARVE(&c, tmp.nodes, int, 4 * (size_t)count);
    TMASS__CARVE(&c, tmp.weight, tmass_real, 4 * (size_t)count);
    TMASS__CARVE(&c, tmp.rest, tmass_real, 3 * (size_t)count);
    tmp.bytes = c.offset;
    p = (tmass_probe *)tmass__alloc(&m->allocator, tmp.bytes);
    if (!p) {
        tmass__grid_free(m, &grid);
        return TMASS_ERR_ALLOC;
    }
    c.base = (char *)p;
    c.offset = sizeof(tmass_probe);
    TMASS__CARVE(&c, tmp.tet, int, count);
    TMASS__CARVE(&c, tmp.nodes, int, 4 * (size_t)count);
    TMASS__CARVE(&c, tmp.weight, tmass_real, 4 * (size_t)count);
    TMASS__CARVE(&c, tmp.rest, tmass_real, 3 * (size_t)count);
    tmp.allocator = m->allocator;
    tmp.count = count;
    tmp.node_count = m->node_count;
    for (i = 0; i < count && !err; i++) {
        double w[4];
        int t = tmass__grid_locate(m, &grid, rest_points + 3 * i, w);
        if (t < 0) {
            err = TMASS_ERR_PROBE_OUTSIDE;
            break;
        }
        tmp.tet[i] = t;
        for (j = 0; j < 4; j++) {
            tmp.nodes[4 * i + j] = m->tet_nodes[4 * t + j];
            tmp.weight[4 * i + j] = (tmass_real)w[j];
        }
        for (j = 0; j < 3; j++) tmp.rest[3 * i + j] = rest_points[3 * i + j];
    }
    tmass__grid_free(m, &grid);
    if (err) {
        tmass__free(&m->allocator, p, tmp.bytes);
        return err;
    }
    *p = tmp;
    *out = p;
    return TMASS_OK;
}

/* out = the interpolation of field f (3 per node) at every point, plus the rest point
   when add_rest; TMASS_ERR_PROBE_OUTSIDE when a point's tetrahedron was cut away. */
static int tmass__probe_eval(const tmass_probe *p, const tmass_model *m, const tmass_real *f, int add_rest,
                             tmass_real *out)
{
    int i, j, r, cut = 0;
    if (!p || !m || !out) return TMASS_ERR_ARG;
    if (m->node_count != p->node_count) return TMASS_ERR_ARG;
    for (i = 0; i < p->count; i++) {
        const int *q = p->nodes + 4 * i;
        const tmass_real *w = p->weight + 4 * i;
        for (r = 0; r < 3; r++) {
            double s = add_rest ? (double)p->rest[3 * i + r] : 0.0;
            for (j = 0; j < 4; j++) s += (double)w[j] * (double)f[3 * q[j] + r];
            out[3 * i + r] = (tmass_real)s;
        }
        cut |= !m->tet_alive[p->tet[i]];
    }
    return cut ? TMASS_ERR_PROBE_OUTSIDE : TMASS_OK;
}

TMASSDEF int tmass_probe_positions(const tmass_probe *p, const tmass_model *m, tmass_real *out)
{
    return tmass__probe_eval(p, m, m ? m->disp : NULL, 1, out);
}

TMASSDEF int tmass_probe_displacements(const tmass_probe *p, const tmass_model *m, tmass_real *out)
{
    return tmass__probe_eval(p, m, m ? m->disp : NULL, 0, out);
}

TMASSDEF int tmass_probe_velocities(const tmass_probe *p, const tmass_model *m, tmass_real *out)
{
    return tmass__probe_eval(p, m, m ? m->vel : NULL, 0, out);
}

TMASSDEF void tmass_probe_destroy(tmass_probe *p)
{
    tmass_allocator a;
    if (!p) return;
    a = p->allocator;
    tmass__free(&a, p, p->bytes);
}

/* >>modal ----------------------------------------------------------------------------- */

#define TMASS__MODAL_COOKIE 0x4D4F4441u /* "MODA" */

struct tmass_modal {
    tmass_allocator allocator;
    size_t bytes;
    int count, block, node_count, max_iterations, solved;
    double tolerance, shift;
    tmass_real *X;     /* block x 3n: the subspace (Ritz vectors after each iteration) */
    tmass_real *Y;     /* block x 3n: (K + shift M)^-1 M X */
    tmass_real *KY;    /* block x 3n: K Y, then K X */
    tmass_real *diag;  /* 3n: shift M */
    tmass_real *rhs;   /* 3n */
    double *Kr, *Mr, *V, *L, *work; /* block x block */
    double *theta, *frequency;      /* block */
};

TMASSDEF tmass_modal_desc tmass_modal_default_desc(void)
{
    tmass_modal_desc d;
    d.count = 6;
    d.max_iterations = 200;
    d.tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-4 : 1e-8);
    d.shift = 0;
    d.internal_cookie = TMASS__MODAL_COOKIE;
    return d;
}

static void tmass__modal_layout(tmass_modal *md, tmass__carver *c, size_t n3)
{
    size_t q = (size_t)md->block;
    TMASS__CARVE(c, md->X, tmass_real, q * n3);
    TMASS__CARVE(c, md->Y, tmass_real, q * n3);
    TMASS__CARVE(c, md->KY, tmass_real, q * n3);
    TMASS__CARVE(c, md->diag, tmass_real, n3);
    TMASS__CARVE(c, md->rhs, tmass_real, n3);
    TMASS__CARVE(c, md->Kr, double, q * q);
    TMASS__CARVE(c, md->Mr, double, q * q);
    TMASS__CARVE(c, md->V, double, q * q);
    TMASS__CARVE(c, md->L, double, q * q);
    TMASS__CARVE(c, md->work, double, q * q);
    TMASS__CARVE(c, md->theta, double, q);
    TMASS__CARVE(c, md->frequency, double, q);
}

TMASSDEF int tmass_modal_create(const tmass_model *m, const tmass_modal_desc *d, tmass_modal **out)
{
    tmass_modal tmp, *md;
    tmass__carver c;
    size_t n3;
    int q;
    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (!m || !d) return TMASS_ERR_ARG;
    if (d->internal_cookie != TMASS__MODAL_COOKIE) return TMASS_ERR_DESC;
    if (d->count < 1 || d->max_iterations < 1 || !(tmass__finite((double)d->tolerance) && d->tolerance > 0) ||
        !(tmass__finite((double)d->shift) && d->shift >= 0))
        return TMASS_ERR_ARG;
    n3 = 3 * (size_t)m->node_count;
    q = d->count + 8 > 2 * d->count ? d->count + 8 : 2 * d->count;
    if ((size_t)q > n3) q = (int)n3;
    if (d->count > q) return TMASS_ERR_ARG;
    memset(&tmp, 0, sizeof tmp);
    tmp.block = q;
    c.base = NULL;
    c.offset = sizeof(tmass_modal);
    tmass__modal_layout(&tmp, &c, n3);
    tmp.bytes = c.offset;
    md = (tmass_modal *)tmass__alloc(&m->allocator, tmp.bytes);
    if (!md) return TMASS_ERR_ALLOC;
    memset(md, 0, tmp.bytes);
    c.base = (char *)md;
    c.offset = sizeof(tmass_modal);
    tmass__modal_layout(&tmp, &c, n3);
    tmp.allocator = m->allocator;
    tmp.count = d->count;
    tmp.node_count = m->node_count;
    tmp.max_iterations = d->max_iterations;
    tmp.tolerance = (double)d->tolerance;
    tmp.shift = (double)d->shift;
    *md = tmp;
    *out = md;
    return TMASS_OK;
}

TMASSDEF void tmass_modal_destroy(tmass_modal *md)
{
    tmass_allocator a;
    if (!md) return;
    a = md->allocator;
    tmass__free(&a, md, md->bytes);
}

TMASSDEF int tmass_modal_count(const tmass_modal *md) { return md && md->solved ? md->count : 0; }

TMASSDEF double tmass_modal_frequency(const tmass_modal *md, int i)
{
    if (!md || !md->solved || i < 0 || i >= md->count) return -1.0;
    return md->frequency[i];
}

TMASSDEF const tmass_real *tmass_modal_shape(const tmass_modal *md, int i)
{
    if (!md || !md->solved || i < 0 || i >= md->count) return NULL;
    return md->X + (size_t)i * 3 * (size_t)md->node_count;
}

/* Symmetric eigenproblem A = V diag(w) V^T (q x q, row-major, A destroyed) by cyclic
   Jacobi rotations; w ascending with V's columns. */
static void tmass__jacobi_eigen(double *A, int q, double *V, double *w)
{
    int i, j, k, sweep;
    for (i = 0; i < q; i++)
        for (j = 0; j < q; j++) V[i * q + j] = i == j;
    for (sweep = 0; sweep < 100; sweep++) {
        double off = 0.0, diag = 0.0;
        for (i = 0; i < q; i++)
            for (j = 0; j < q; j++) {
                if (i == j) diag += A[i * q + i] * A[i * q + i];
                else off += A[i * q + j] * A[i * q + j];
            }
        if (off <= 1e-30 * diag || off == 0.0) break;
        for (i = 0; i < q; i++)
            for (j = i + 1; j < q; j++) {
                double aij = A[i * q + j], t, cs, sn, tau;
                if (aij == 0.0) continue;
                tau = (A[j * q + j] - A[i * q + i]) / (2.0 * aij);
                t = (tau >= 0 ? 1.0 : -1.0) / (fabs(tau) + sqrt(1.0 + tau * tau));
                cs = 1.0 / sqrt(1.0 + t * t);
                sn = t * cs;
                for (k = 0; k < q; k++) { /* A = J^T A J */
                    double aki = A[k * q + i], akj = A[k * q + j];
                    A[k * q + i] = cs * aki - sn * akj;
                    A[k * q + j] = sn * aki + cs * akj;
                }
                for (k = 0; k < q; k++) {
                    double aik = A[i * q + k], ajk = A[j * q + k];
                    A[i * q + k] = cs * aik - sn * ajk;
                    A[j * q + k] = sn * aik + cs * ajk;
                }
                for (k = 0; k < q; k++) {
                    double vki = V[k * q + i], vkj = V[k * q + j];
                    V[k * q + i] = cs * vki - sn * vkj;
                    V[k * q + j] = sn * vki + cs * vkj;
                }
            }
    }
    for (i = 0; i < q; i++) w[i] = A[i * q + i];
    for (i = 1; i < q; i++) /* insertion sort, ascending, columns along */
        for (j = i; j > 0 && w[j] < w[j - 1]; j--) {
            double t = w[j];
            w[j] = w[j - 1];
            w[j - 1] = t;
            for (k = 0; k < q; k++) {
                t = V[k * q + j];
                V[k * q + j] = V[k * q + j - 1];
                V[k * q + j - 1] = t;
            }
        }
}

/* Rayleigh-Ritz on span(Y): Kr = Y^T K Y, Mr = Y^T M Y; Kr Q = Mr Q Theta through
   Mr = L L^T and the symmetric L^-1 Kr L^-T; Q = L^-T V (in V). 0, or -1 when Mr is not
   positive definite (a collapsed subspace). */
static int tmass__modal_ritz(tmass_modal *md, const tmass_model *m, int q)
{
    int n3 = 3 * m->node_count, i, j, k;
    double *Kr = md->Kr, *Mr = md->Mr, *L = md->L, *W = md->work;
    for (i = 0; i < q; i++)
        for (j = 0; j <= i; j++) {
            const tmass_real *yi = md->Y + (size_t)i * n3, *yj = md->Y + (size_t)j * n3, *kyj = md->KY + (size_t)j * n3;
            double kk = 0.0, mm = 0.0;
            for (k = 0; k < n3; k++) {
                kk += (double)yi[k] * (double)kyj[k];
                mm += (double)yi[k] * (double)m->mass[k / 3] * (double)yj[k];
            }
            Kr[i * q + j] = Kr[j * q + i] = kk;
            Mr[i * q + j] = Mr[j * q + i] = mm;
        }
    for (j = 0; j < q; j++) { /* Cholesky Mr = L L^T */
        double d = Mr[j * q + j];
        for (k = 0; k < j; k++) d -= L[j * q + k] * L[j * q + k];
        if (!(d > 0)) return -1;
        L[j * q + j] = sqrt(d);
        for (i = j + 1; i < q; i++) {
            double s = Mr[i * q + j];
            for (k = 0; k < j; k++) s -= L[i * q + k] * L[j * q + k];
            L[i * q + j] = s / L[j * q + j];
        }
        for (i = 0; i < j; i++) L[i * q + j] = 0.0;
    }
    /* W = L^-1 Kr (forward substitution per column), then Kr = L^-1 W^T = L^-1 Kr L^-T */
    for (k = 0; k < 2; k++) {
        for (j = 0; j < q; j++)
            for (i = 0; i < q; i++) {
                double s = k == 0 ? Kr[i * q + j] : W[j * q + i];
                int l;
                for (l = 0; l < i; l++) s -= L[i * q + l] * (k == 0 ? W[l * q + j] : Kr[l * q + j]);
                if (k == 0) W[i * q + j] = s / L[i * q + i];
                else Kr[i * q + j] = s / L[i * q + i];
            }
    }
    for (i = 0; i < q; i++) /* symmetrise the round-off */
        for (j = 0; j < i; j++) Kr[i * q + j] = Kr[j * q + i] = 0.5 * (Kr[i * q + j] + Kr[j * q + i]);
    tmass__jacobi_eigen(Kr, q, W, md->theta);
    /* V = L^-T W (back substitution per column) */
    for (j = 0; j < q; j++)
        for (i = q - 1; i >= 0; i--) {
            double s = W[i * q + j];
            for (k = i + 1; k < q; k++) s -= L[k * q + i] * md->V[k * q + j];
            md->V[i * q + j] = s / L[i * q + i];
        }
    return 0;
}

TMASSDEF int tmass_modal_solve(tmass_modal *md, tmass_model *m)
{
    int q, n3, i, j, k, it, err = TMASS_OK, free_dofs = 0, saved_iterations;
    double shift, top = 0.0, saved_tolerance, floor;
    unsigned seed = 12345u;
    if (!md || !m) return TMASS_ERR_ARG;
    md->solved = 0;
    if (m->node_count != md->node_count) return TMASS_ERR_ARG;
    q = md->block;
    n3 = 3 * m->node_count;
    memset(&m->stats, 0, sizeof m->stats);
    if (tmass__kinds[m->kind].tangent) tmass__kinds[m->kind].tangent(m, m->disp); /* about the state */
    for (i = 0; i < n3; i++) {
        double kii = (double)m->vertex_tensor[9 * (i / 3) + 4 * (i % 3)], mi = (double)m->mass[i / 3];
        free_dofs += m->free_mask[i] > 0;
        if (m->free_mask[i] > 0 && mi > 0 && kii / mi > top) top = kii / mi;
    }
    if (free_dofs < q) q = free_dofs; /* the whole space */
    if (md->count > q) return TMASS_ERR_ARG;
    shift = md->shift > 0 ? md->shift : (sizeof(tmass_real) == sizeof(float) ? 1e-4 : 1e-6) * top;
    if (!(shift > 0) || !tmass__finite(shift)) return TMASS_ERR_NOT_FINITE;
    floor = 30.0 * TMASS__EPS * top; /* round-off of K x for an M-normalised x (float: above
                                         tolerance * shift for the rigid modes) */
    for (i = 0; i < n3; i++) md->diag[i] = (tmass_real)(shift * (double)m->mass[i / 3]);
    for (j = 0; j < q; j++) /* deterministic start */
        for (i = 0; i < n3; i++) {
            seed = seed * 1664525u + 1013904223u;
            md->X[(size_t)j * n3 + i] = (tmass_real)((((seed >> 8) & 0xFFFFFF) / (double)0x7FFFFF - 1.0) * m->free_mask[i]);
        }
    saved_tolerance = (double)m->cg_tolerance;
    saved_iterations = m->cg_max_iterations;
    m->cg_tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-5 : 1e-10);
    if (m->cg_max_iterations < 10000) m->cg_max_iterations = 10000;
    for (it = 0; it < md->max_iterations && !err; it++) {
        int converged = 1;
        for (j = 0; j < q && !err; j++) { /* Y = (K + shift M)^-1 M X */
            tmass_real *x = md->X + (size_t)j * n3, *y = md->Y + (size_t)j * n3;
            double guess = it > 0 ? 1.0 / (md->theta[j] + shift) : 0.0; /* y = x / (theta + shift)
                                                                             for an eigenvector */
            for (i = 0; i < n3; i++) {
                md->rhs[i] = (tmass_real)((double)m->mass[i / 3] * (double)x[i] * m->free_mask[i]);
                y[i] = (tmass_real)(guess * (double)x[i]);
            }
            err = tmass__linear_solve(m, md->diag, 1.0, md->rhs, y);
            for (i = 0; i < n3; i++) y[i] *= m->free_mask[i];
            if (!err) {
                tmass__matvec(m, y, md->KY + (size_t)j * n3);
                for (i = 0; i < n3; i++) md->KY[(size_t)j * n3 + i] *= m->free_mask[i];
            }
        }
        if (err) break;
        if (tmass__modal_ritz(md, m, q)) {
            err = TMASS_ERR_NO_CONVERGENCE;
            break;
        }
        for (j = 0; j < q; j++) { /* X = Y V, and K X = KY V into Y's place column by column */
            tmass_real *x = md->X + (size_t)j * n3;
            for (i = 0; i < n3; i++) {
                double s = 0.0;
                for (k = 0; k < q; k++) s += (double)md->Y[(size_t)k * n3 + i] * md->V[k * q + j];
                x[i] = (tmass_real)s;
            }
        }
        for (j = 0; j < md->count; j++) { /* residuals of the wanted pairs */
            const tmass_real *x = md->X + (size_t)j * n3;
            double rr = 0.0, theta = md->theta[j];
            for (i = 0; i < n3; i++) {
                double kx = 0.0, mi = (double)m->mass[i / 3], r;
                if (!(m->free_mask[i] > 0) || !(mi > 0)) continue;
                for (k = 0; k < q; k++) kx += (double)md->KY[(size_t)k * n3 + i] * md->V[k * q + j];
                r = kx - theta * mi * (double)x[i];
                rr += r * r / mi;
            }
            if (!tmass__finite(rr)) err = TMASS_ERR_NOT_FINITE;
            if (!(sqrt(rr) <= md->tolerance * (fabs(theta) + shift) + floor)) converged = 0;
        }
        if (!err && converged) {
            for (j = 0; j < md->count; j++)
                md->frequency[j] = sqrt(md->theta[j] > 0 ? md->theta[j] : 0.0) / (2.0 * 3.14159265358979323846);
            md->solved = 1;
            break;
        }
    }
    m->cg_tolerance = (tmass_real)saved_tolerance;
    m->cg_max_iterations = saved_iterations;
    m->stats.newton_iterations = it + 1;
    if (err) return err;
    return md->solved ? TMASS_OK : TMASS_ERR_NO_CONVERGENCE;
}

/* >>dense ----------------------------------------------------------------------------- */

/* In-place Cholesky factorisation A = L L^T of a symmetric positive definite n x n
   row-major matrix (the lower triangle receives L). Returns 0, or -1 if not positive
   definite. */
static int tmass__cholesky(double *A, int n)
{
    int i, j, k;
    for (j = 0; j < n; j++) {
        double d = A[(size_t)j * n + j];
        for (k = 0; k < j; k++) d -= A[(size_t)j * n + k] * A[(size_t)j * n + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        A[(size_t)j * n + j] = d;
        for (i = j + 1; i < n; i++) {
            double s = A[(size_t)i * n + j];
            for (k = 0; k < j; k++) s -= A[(size_t)i * n + k] * A[(size_t)j * n + k];
            A[(size_t)i * n + j] = s / d;
        }
    }
    return 0;
}

/* Solves L L^T x = b in place (x holds b on entry). */
static void tmass__cholesky_solve(const double *L, int n, double *x)
{
    int i, k;
    for (i = 0; i < n; i++) {
        double s = x[i];
        for (k = 0; k < i; k++) s -= L[(size_t)i * n + k] * x[k];
        x[i] = s / L[(size_t)i * n + i];
    }
    for (i = n - 1; i >= 0; i--) {
        double s = x[i];
        for (k = i + 1; k < n; k++) s -= L[(size_t)k * n + i] * x[k];
        x[i] = s / L[(size_t)i * n + i];
    }
}

/* FNV-1a, 64 bits. */
static unsigned long long tmass__hash(unsigned long long h, const void *data, size_t bytes)
{
    const unsigned char *p = (const unsigned char *)data;
    size_t i;
    for (i = 0; i < bytes; i++) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

/* >>quasi-static ---------------------------------------------------------------------- */

#define TMASS__QS_COOKIE 0x514D4153u /* "TMSQ" */
#define TMASS__QS_VERSION 2u /* 2: the preload includes driven pinned nodes (issue 18) */
#define TMASS__FNV_BASIS 14695981039346656037ull

struct tmass_qs {
    int node_count, pre_count, out_count, max_contacts, all_nodes;
    unsigned long long fingerprint;
    tmass_allocator allocator;
    void *block;
    size_t block_bytes;
    int *pre_nodes;         /* P: precomputed nodes */
    int *out_nodes;         /* O: output nodes (P, or every node) */
    int *row_of_node;       /* node -> index in O, or -1 */
    int *col_of_node;       /* node -> index in P, or -1 */
    tmass_real *rest, *preload, *disp, *pos; /* 3n each */
    tmass_real *compliance; /* column j < 3|P| holds 3|O| rows: C[j * 3|O| + row] */
    tmass_real *out_disp;   /* 3|O| accumulator */
    double *dense;          /* (3 max_contacts)^2 */
    double *rhs;            /* 3 max_contacts */
    int *contact_cols;      /* 3 max_contacts column indices */
};

TMASSDEF tmass_qs_desc tmass_qs_default_desc(void)
{
    tmass_qs_desc d;
    memset(&d, 0, sizeof d);
    d.max_contacts = 16;
    d.cg_tolerance = (tmass_real)(sizeof(tmass_real) == sizeof(float) ? 1e-6 : 1e-10);
    d.cg_max_iterations = 20000;
    d.internal_cookie = TMASS__QS_COOKIE;
    return d;
}

static void tmass__qs_layout(tmass_qs *q, tmass__carver *c)
{
    size_t n = (size_t)q->node_count, p = (size_t)q->pre_count, o = (size_t)q->out_count;
    size_t k = (size_t)q->max_contacts;
    TMASS__CARVE(c, q->pre_nodes, int, p);
    TMASS__CARVE(c, q->out_nodes, int, o);
    TMASS__CARVE(c, q->row_of_node, int, n);
    TMASS__CARVE(c, q->col_of_node, int, n);
    TMASS__CARVE(c, q->rest, tmass_real, 3 * n);
    TMASS__CARVE(c, q->preload, tmass_real, 3 * n);
    TMASS__CARVE(c, q->disp, tmass_real, 3 * n);
    TMASS__CARVE(c, q->pos, tmass_real, 3 * n);
    TMASS__CARVE(c, q->compliance, tmass_real, 9 * p * o);
    TMASS__CARVE(c, q->out_disp, tmass_real, 3 * o);
    TMASS__CARVE(c, q->dense, double, 9 * k * k);
    TMASS__CARVE(c, q->rhs, double, 3 * k);
    TMASS__CARVE(c, q->contact_cols, int, 3 * k);
}

/* Everything a precomputation depends on: mesh, live tets, materials, pinned nodes and
   their targets, loads, the node set, the output choice and the real type. */
static unsigned long long tmass__qs_fingerprint(const tmass_model *m, const tmass_qs *q)
{
    unsigned long long h = TMASS__FNV_BASIS;
    int t, i, real_size = (int)sizeof(tmass_real);
    h = tmass__hash(h, &real_size, sizeof real_size);
    h = tmass__hash(h, &m->node_count, sizeof m->node_count);
    h = tmass__hash(h, &m->tet_count, sizeof m->tet_count);
    h = tmass__hash(h, m->rest, sizeof(tmass_real) * 3 * (size_t)m->node_count);
    for (t = 0; t < m->tet_count; t++) {
        if (!m->tet_alive[t]) continue;
        h = tmass__hash(h, &t, sizeof t);
        h = tmass__hash(h, m->tet_nodes + 4 * t, 4 * sizeof(int));
        h = tmass__hash(h, m->tet_lambda + t, sizeof(double));
        h = tmass__hash(h, m->tet_mu + t, sizeof(double));
    }
    for (i = 0; i < m->node_count; i++)
        if (m->node_state[i] == TMASS__PINNED) {
            h = tmass__hash(h, &i, sizeof i);
            h = tmass__hash(h, m->target + 3 * i, 3 * sizeof(tmass_real));
        }
    h = tmass__hash(h, m->gravity, sizeof m->gravity);
    h = tmass__hash(h, m->ext, sizeof(tmass_real) * 3 * (size_t)m->node_count);
    h = tmass__hash(h, &m->density, sizeof m->density);
    h = tmass__hash(h, q->pre_nodes, sizeof(int) * (size_t)q->pre_count);
    h = tmass__hash(h, &q->all_nodes, sizeof q->all_nodes);
    return h;
}

/* Validates (m, d) and builds an empty quasi-static model with its node sets, rest and
   fingerprint (no solve). */
static int tmass__qs_prepare(const tmass_model *m, const tmass_qs_desc *d, tmass_qs **out)
{
    tmass_qs tmp, *q;
    tmass__carver carver;
    int i, k, count = 0;
    tmass_real *mark;
    *out = NULL;
    if (!m || !d) return TMASS_ERR_ARG;
    if (d->internal_cookie != TMASS__QS_COOKIE) return TMASS_ERR_DESC;
    if (!(tmass__kinds[m->kind].flags & TMASS__KIND_LINEAR)) return TMASS_ERR_MODEL_KIND;
    if (d->max_contacts < 1 || d->max_contacts > 4096 || (d->nodes && d->node_count < 1) ||
        (d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return TMASS_ERR_ARG;
    if (!(tmass__finite((double)d->cg_tolerance) && d->cg_tolerance > 0) || d->cg_max_iterations < 1)
        return TMASS_ERR_SOLVER;
    /* mark the precomputed nodes in the model's qs_mark work vector */
    mark = m->qs_mark;
    memset(mark, 0, sizeof(tmass_real) * (size_t)m->node_count);
    if (d->nodes) {
        for (i = 0; i < d->node_count; i++) {
            int v = d->nodes[i];
            if (v < 0 || v >= m->node_count) return TMASS_ERR_NODE_RANGE;
            if (m->node_state[v] == TMASS__INACTIVE) return TMASS_ERR_NODE_INACTIVE;
            if (m->node_state[v] == TMASS__PINNED) return TMASS_ERR_NODE_PINNED;
            if (mark[v] != 0) return TMASS_ERR_ARG; /* listed twice */
            mark[v] = 1;
        }
    } else {
        for (i = 0; i < 3 * m->tri_count; i++)
            if (m->node_state[m->tri[i]] == TMASS__FREE) mark[m->tri[i]] = 1;
    }
    for (i = 0; i < m->node_count; i++) count += mark[i] != 0;
    if (count == 0) return TMASS_ERR_ARG;
    memset(&tmp, 0, sizeof tmp);
    tmp.node_count = m->node_count;
    tmp.pre_count = count;
    tmp.all_nodes = d->all_nodes != 0;
    tmp.out_count = tmp.all_nodes ? m->node_count : count;
    tmp.max_contacts = d->max_contacts;
    tmp.allocator = d->allocator;
    carver.base = NULL;
    carver.offset = sizeof(tmass_qs);
    tmass__qs_layout(&tmp, &carver);
    tmp.block_bytes = carver.offset;
    tmp.block = tmass__alloc(&tmp.allocator, tmp.block_bytes);
    if (!tmp.block) return TMASS_ERR_ALLOC;
    memset(tmp.block, 0, tmp.block_bytes);
    carver.base = (char *)tmp.block;
    carver.offset = sizeof(tmass_qs);
    tmass__qs_layout(&tmp, &carver);
    q = (tmass_qs *)tmp.block;
    *q = tmp;
    for (i = 0, k = 0; i < m->node_count; i++) {
        q->col_of_node[i] = mark[i] != 0 ? k : -1;
        if (mark[i] != 0) q->pre_nodes[k++] = i;
    }
    for (i = 0; i < m->node_count; i++) q->row_of_node[i] = q->all_nodes ? i : q->col_of_node[i];
    for (i = 0; i < q->out_count; i++) q->out_nodes[i] = q->all_nodes ? i : q->pre_nodes[i];
    memcpy(q->rest, m->rest, sizeof(tmass_real) * 3 * (size_t)m->node_count);
    q->fingerprint = tmass__qs_fingerprint(m, q);
    *out = q;
    return TMASS_OK;
}

static void tmass__qs_set_preload_state(tmass_qs *q)
{
    int i;
    memcpy(q->disp, q->preload, sizeof(tmass_real) * 3 * (size_t)q->node_count);
    for (i = 0; i < 3 * q->node_count; i++) q->pos[i] = q->rest[i] + q->disp[i];
}

TMASSDEF void tmass_qs_destroy(tmass_qs *qs)
{
    tmass_allocator a;
    if (!qs) return;
    a = qs->allocator;
    tmass__free(&a, qs->block, qs->block_bytes);
}

/* >>quasi-static-solver --------------------------------------------------------------- */

/* The precomputation solves K x = b for many b. TMASS__RHS independent CG runs advance in
   lock step and share each K product, so a tensor is read once for all of them; vectors
   are interleaved ([degree of freedom][rhs]) so the work vectorises across the runs. */
#define TMASS__RHS 8

typedef struct tmass__block_ctx {
    const tmass_model *m;
    const tmass_real *p;
    tmass_real *out;
    int colour;
} tmass__block_ctx;

static void tmass__matvec_block_chunks(void *vctx, int begin, int end)
{
    const tmass__block_ctx *c = (const tmass__block_ctx *)vctx;
    const tmass_model *m = c->m;
    const tmass_real *p = c->p;
    tmass_real *out = c->out;
    int k;
    enum { R = TMASS__RHS };
    for (k = m->colour_start[c->colour] + begin; k < m->colour_start[c->colour] + end; k++) {
        int s = m->chunk_start[k], s1 = s + m->chunk_live[k];
        while (s < s1) {
            int a = m->edge_a[s], r;
            const tmass_real *pa = p + 3 * R * a;
            tmass_real fa[3 * R];
            for (r = 0; r < 3 * R; r++) fa[r] = 0;
            do {
                const tmass_real *K = m->edge_tensor + 9 * s, *pb = p + 3 * R * m->edge_b[s];
                tmass_real *ob = out + 3 * R * m->edge_b[s];
                for (r = 0; r < R; r++) {
                    tmass_real d0 = pb[r] - pa[r], d1 = pb[R + r] - pa[R + r], d2 = pb[2 * R + r] - pa[2 * R + r];
                    fa[r] += K[0] * d0 + K[1] * d1 + K[2] * d2;
                    fa[R + r] += K[3] * d0 + K[4] * d1 + K[5] * d2;
                    fa[2 * R + r] += K[6] * d0 + K[7] * d1 + K[8] * d2;
                    ob[r] -= K[0] * d0 + K[3] * d1 + K[6] * d2;
                    ob[R + r] -= K[1] * d0 + K[4] * d1 + K[7] * d2;
                    ob[2 * R + r] -= K[2] * d0 + K[5] * d1 + K[8] * d2;
                }
                s++;
            } while (s < s1 && m->edge_a[s] == a);
            for (r = 0; r < 3 * R; r++) out[3 * R * a + r] += fa[r];
        }
    }
}

/* out = K p for TMASS__RHS interleaved vectors. */
static void tmass__matvec_block(const tmass_model *m, const tmass_real *p, tmass_real *out)
{
    tmass__block_ctx c;
    c.m = m;
    c.p = p;
    c.out = out;
    memset(out, 0, sizeof(tmass_real) * 3 * TMASS__RHS * (size_t)m->node_count);
    for (c.colour = 0; c.colour < m->colour_count; c.colour++)
        tmass__run(m, m->colour_start[c.colour + 1] - m->colour_start[c.colour],
                   tmass__matvec_block_chunks, &c);
}

/* Solves K X = B (interleaved, TMASS__RHS columns) on the free degrees of freedom by
   Jacobi-preconditioned CG, each column to |r| <= tol |b|. w: four arrays like X.
   Returns TMASS_OK or TMASS_ERR_NO_CONVERGENCE. */
static int tmass__cg_block(tmass_model *m, const tmass_real *B, tmass_real *X, tmass_real **w,
                           const tmass_real *pinv, double tol, int max_iterations)
{
    enum { R = TMASS__RHS };
    tmass_real *res = w[0], *z = w[1], *p = w[2], *q = w[3];
    double bb[R], rr[R], rz[R], pq[R], alpha[R], beta[R], tol2[R];
    int n3 = 3 * m->node_count, i, r, it, done, active[R];
    for (r = 0; r < R; r++) bb[r] = rr[r] = rz[r] = 0.0;
    for (i = 0; i < n3; i++)
        for (r = 0; r < R; r++) {
            tmass_real b = B[i * R + r] * m->free_mask[i];
            X[i * R + r] = 0;
            res[i * R + r] = b;
            z[i * R + r] = pinv[i] * b;
            p[i * R + r] = z[i * R + r];
            bb[r] += (double)b * b;
            rz[r] += (double)b * z[i * R + r];
        }
    for (r = 0; r < R; r++) {
        rr[r] = bb[r];
        tol2[r] = tol * tol * bb[r];
    }
    for (it = 0; it < max_iterations; it++) {
        for (r = 0, done = 1; r < R; r++) done &= rr[r] <= tol2[r];
        if (done) break;
        tmass__matvec_block(m, p, q);
        for (r = 0; r < R; r++) pq[r] = 0.0;
        for (i = 0; i < n3; i++)
            for (r = 0; r < R; r++) {
                q[i * R + r] *= m->free_mask[i];
                pq[r] += (double)p[i * R + r] * q[i * R + r];
            }
        for (r = 0; r < R; r++) m->stats.negative_curvature += rr[r] > tol2[r] && !(pq[r] > 0.0);
        for (r = 0; r < R; r++) { /* a converged (or empty) column stops moving */
            active[r] = rr[r] > tol2[r] && pq[r] > 0.0;
            alpha[r] = active[r] ? rz[r] / pq[r] : 0.0;
            beta[r] = rz[r];
            rr[r] = rz[r] = 0.0;
        }
        for (i = 0; i < n3; i++)
            for (r = 0; r < R; r++) {
                int j = i * R + r;
                X[j] += (tmass_real)alpha[r] * p[j];
                res[j] -= (tmass_real)alpha[r] * q[j];
                z[j] = pinv[i] * res[j];
                rr[r] += (double)res[j] * res[j];
                rz[r] += (double)res[j] * z[j];
            }
        for (r = 0; r < R; r++) beta[r] = active[r] && beta[r] > 0.0 ? rz[r] / beta[r] : 0.0;
        for (i = 0; i < n3; i++)
            for (r = 0; r < R; r++) p[i * R + r] = z[i * R + r] + (tmass_real)beta[r] * p[i * R + r];
    }
    m->stats.cg_iterations += it;
    m->stats.stiffness_products += it;
    for (r = 0; r < R; r++)
        if (!tmass__finite(rr[r])) return TMASS_ERR_NOT_FINITE;
    for (r = 0; r < R; r++)
        if (!(rr[r] <= tol2[r])) return TMASS_ERR_NO_CONVERGENCE;
    for (i = 0; i < n3 * R; i++)
        if (!tmass__finite((double)X[i])) return TMASS_ERR_NOT_FINITE;
    return TMASS_OK;
}

TMASSDEF int tmass_qs_create(tmass_model *m, const tmass_qs_desc *d, tmass_qs **out)
{
    enum { R = TMASS__RHS };
    tmass_qs *q;
    tmass_real *b, *x, *block, *w[4], *B, *X, *pinv, saved_tol;
    size_t vec, block_bytes;
    int err, i, j0, r, saved_iter, total, n3, o3, p3;
    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (m && m->coupling_count) return TMASS_ERR_ARG; /* a hybrid's dynamic part */
    if (m && m->anchor_count) return TMASS_ERR_ANCHORED; /* ANCHORS: targets move, C is fixed */
    err = tmass__qs_prepare(m, d, &q);
    if (err) return err;
    n3 = 3 * m->node_count;
    o3 = 3 * q->out_count;
    p3 = 3 * q->pre_count;
    total = p3 + 1;
    /* the preload: K g = f_ext + M g_vec - K u_pinned on the free nodes (one CG), the
       pinned nodes at their targets (pinned nodes away from rest are boundary conditions
       too, issue 18 item 7) */
    b = m->qs_rhs;
    x = m->qs_x;
    saved_tol = m->cg_tolerance;
    saved_iter = m->cg_max_iterations;
    m->cg_tolerance = d->cg_tolerance;
    m->cg_max_iterations = d->cg_max_iterations;
    memset(&m->stats, 0, sizeof m->stats);
    for (i = 0; i < n3; i++) x[i] = m->pin_mask[i] * m->target[i];
    tmass__matvec(m, x, b); /* K u_pinned */
    for (i = 0; i < n3; i++) {
        b[i] = m->ext[i] + m->mass[i / 3] * m->gravity[i % 3] - b[i];
        x[i] = 0;
    }
    err = tmass__linear_solve(m, NULL, 1.0, b, x);
    m->cg_tolerance = saved_tol;
    m->cg_max_iterations = saved_iter;
    for (i = 0; i < n3; i++) x[i] += m->pin_mask[i] * m->target[i];
    if (!err && !tmass__all_finite(x, n3)) err = TMASS_ERR_NOT_FINITE;
    memcpy(q->preload, x, sizeof(tmass_real) * (size_t)n3);
    if (!err && d->progress && d->progress(1, total, d->progress_user)) err = TMASS_ERR_CANCELLED;
    /* the compliance columns, TMASS__RHS at a time (temporary block: six interleaved
       vectors and the Jacobi preconditioner) */
    vec = (size_t)n3 * R;
    block_bytes = sizeof(tmass_real) * (6 * vec + (size_t)n3);
    block = err ? NULL : (tmass_real *)tmass__alloc(&q->allocator, block_bytes);
    if (!err && !block) err = TMASS_ERR_ALLOC;
    if (!err) {
        B = block;
        X = B + vec;
        for (i = 0; i < 4; i++) w[i] = X + vec * (1 + i);
        pinv = X + 5 * vec;
        for (i = 0; i < n3; i++) {
            double dgl = (double)m->vertex_tensor[9 * (i / 3) + 4 * (i % 3)];
            pinv[i] = (tmass_real)(m->free_mask[i] > 0 && dgl > 0 ? 1.0 / dgl : 0.0);
        }
        for (j0 = 0; j0 < p3 && !err; j0 += R) {
            memset(B, 0, sizeof(tmass_real) * vec);
            for (r = 0; r < R && j0 + r < p3; r++)
                B[(size_t)(3 * q->pre_nodes[(j0 + r) / 3] + (j0 + r) % 3) * R + r] = 1;
            err = tmass__linear_solve_block(m, B, X, w, pinv, (double)d->cg_tolerance, d->cg_max_iterations);
            for (r = 0; r < R && j0 + r < p3 && !err; r++) {
                tmass_real *col = q->compliance + (size_t)(j0 + r) * o3;
                for (i = 0; i < q->out_count; i++) {
                    int v = q->out_nodes[i];
                    col[3 * i] = X[(size_t)(3 * v) * R + r];
                    col[3 * i + 1] = X[(size_t)(3 * v + 1) * R + r];
                    col[3 * i + 2] = X[(size_t)(3 * v + 2) * R + r];
                }
            }
            if (!err && d->progress && d->progress((j0 + R < p3 ? j0 + R : p3) + 1, total, d->progress_user))
                err = TMASS_ERR_CANCELLED;
        }
        tmass__free(&q->allocator, block, block_bytes);
    }
    if (err) {
        tmass_qs_destroy(q);
        return err;
    }
    tmass__qs_set_preload_state(q);
    *out = q;
    return TMASS_OK;
}

/* Compliance entry between output row `row` and precomputed column `col`. */
static double tmass__qs_entry(const tmass_qs *q, int row, int col)
{
    return (double)q->compliance[(size_t)col * 3 * q->out_count + row];
}

/* disp = preload + sum_j C[:, cols[j]] f[j] over the output nodes; positions follow. */
static void tmass__qs_superpose(tmass_qs *q, const int *cols, const double *f, int ncols)
{
    int i, j, o3 = 3 * q->out_count;
    tmass_real *acc = q->out_disp;
    for (i = 0; i < q->out_count; i++) {
        const tmass_real *g = q->preload + 3 * q->out_nodes[i];
        acc[3 * i] = g[0];
        acc[3 * i + 1] = g[1];
        acc[3 * i + 2] = g[2];
    }
    for (j = 0; j < ncols; j++) {
        const tmass_real *TMASS__RESTRICT col = q->compliance + (size_t)cols[j] * o3;
        tmass_real *TMASS__RESTRICT a = acc;
        tmass_real fj = (tmass_real)f[j];
        for (i = 0; i < o3; i++) a[i] += fj * col[i];
    }
    for (i = 0; i < q->out_count; i++) {
        int v = q->out_nodes[i], r;
        for (r = 0; r < 3; r++) {
            q->disp[3 * v + r] = acc[3 * i + r];
            q->pos[3 * v + r] = q->rest[3 * v + r] + acc[3 * i + r];
        }
    }
}

TMASSDEF int tmass_qs_update(tmass_qs *q, const int *nodes, const tmass_real *u, int count,
                             tmass_real *forces)
{
    int a, b, k3, *cols;
    if (!q || count < 0 || (count > 0 && (!nodes || !u))) return TMASS_ERR_ARG;
    if (count > q->max_contacts) return TMASS_ERR_CONTACTS;
    for (a = 0; a < count; a++) {
        if (nodes[a] < 0 || nodes[a] >= q->node_count) return TMASS_ERR_NODE_RANGE;
        if (q->col_of_node[nodes[a]] < 0) return TMASS_ERR_NOT_PRECOMPUTED;
        for (b = 0; b < a; b++)
            if (nodes[b] == nodes[a]) return TMASS_ERR_CONTACTS;
        if (!tmass__vec3_finite(u + 3 * a)) return TMASS_ERR_ARG;
    }
    k3 = 3 * count;
    cols = q->contact_cols;
    /* C_II f = u_I - g_I (rows of contact a, columns of contact b) */
    for (a = 0; a < k3; a++) {
        int va = nodes[a / 3], row = 3 * q->row_of_node[va] + a % 3;
        for (b = 0; b < k3; b++)
            q->dense[(size_t)a * k3 + b] =
                tmass__qs_entry(q, row, 3 * q->col_of_node[nodes[b / 3]] + b % 3);
        q->rhs[a] = (double)u[a] - (double)q->preload[3 * va + a % 3];
    }
    if (count && tmass__cholesky(q->dense, k3)) return TMASS_ERR_SINGULAR;
    if (count) tmass__cholesky_solve(q->dense, k3, q->rhs);
    for (a = 0; a < k3; a++)
        if (!tmass__finite(q->rhs[a])) return TMASS_ERR_NOT_FINITE;
    for (a = 0; a < k3; a++) cols[a] = 3 * q->col_of_node[nodes[a / 3]] + a % 3;
    tmass__qs_superpose(q, cols, q->rhs, k3);
    if (forces)
        for (a = 0; a < k3; a++) forces[a] = (tmass_real)q->rhs[a];
    return TMASS_OK;
}

TMASSDEF const tmass_real *tmass_qs_displacements(const tmass_qs *q) { return q ? q->disp : NULL; }
TMASSDEF const tmass_real *tmass_qs_positions(const tmass_qs *q) { return q ? q->pos : NULL; }
TMASSDEF size_t tmass_qs_memory_bytes(const tmass_qs *q) { return q ? q->block_bytes : 0; }

TMASSDEF const int *tmass_qs_nodes(const tmass_qs *q, int *count)
{
    if (count) *count = q ? q->pre_count : 0;
    return q ? q->pre_nodes : NULL;
}

TMASSDEF int tmass_qs_remove_tets(tmass_qs *q, const int *tets, int count)
{
    (void)tets;
    (void)count;
    return q ? TMASS_ERR_PRECOMPUTED : TMASS_ERR_ARG;
}

/* >>quasi-static-io ------------------------------------------------------------------- */

/* File layout (native byte order, checked by the byte-order field):
     char magic[8] "TMASSQS"    u32 version      u32 byte_order 0x01020304
     u32 real_size              u32 all_nodes    i32 node_count, pre_count, out_count
     u32 reserved               u64 fingerprint  u64 payload_bytes
     payload: preload (3n reals), compliance (9 |P| |O| reals)
     u64 FNV-1a checksum of the payload */
#define TMASS__QS_HEADER_BYTES 56

static size_t tmass__qs_payload_bytes(const tmass_qs *q)
{
    return sizeof(tmass_real) * (3 * (size_t)q->node_count + 9 * (size_t)q->pre_count * q->out_count);
}

static void tmass__put(unsigned char **p, const void *v, size_t n)
{
    memcpy(*p, v, n);
    *p += n;
}

TMASSDEF int tmass_qs_save_memory(const tmass_qs *q, void *buffer, size_t capacity, size_t *size)
{
    unsigned char *p = (unsigned char *)buffer;
    size_t payload, total;
    unsigned int u32;
    int i32;
    unsigned long long u64, sum;
    if (!q || !size) return TMASS_ERR_ARG;
    payload = tmass__qs_payload_bytes(q);
    total = TMASS__QS_HEADER_BYTES + payload + 8;
    *size = total;
    if (!buffer) return TMASS_OK;
    if (capacity < total) return TMASS_ERR_ARG;
    tmass__put(&p, "TMASSQS", 8);
    u32 = TMASS__QS_VERSION;
    tmass__put(&p, &u32, 4);
    u32 = 0x01020304u;
    tmass__put(&p, &u32, 4);
    u32 = (unsigned int)sizeof(tmass_real);
    tmass__put(&p, &u32, 4);
    u32 = (unsigned int)q->all_nodes;
    tmass__put(&p, &u32, 4);
    i32 = q->node_count;
    tmass__put(&p, &i32, 4);
    i32 = q->pre_count;
    tmass__put(&p, &i32, 4);
    i32 = q->out_count;
    tmass__put(&p, &i32, 4);
    u32 = 0;
    tmass__put(&p, &u32, 4);
    tmass__put(&p, &q->fingerprint, 8);
    u64 = (unsigned long long)payload;
    tmass__put(&p, &u64, 8);
    tmass__put(&p, q->preload, sizeof(tmass_real) * 3 * (size_t)q->node_count);
    tmass__put(&p, q->compliance, payload - sizeof(tmass_real) * 3 * (size_t)q->node_count);
    sum = tmass__hash(TMASS__FNV_BASIS, (const unsigned char *)buffer + TMASS__QS_HEADER_BYTES, payload);
    tmass__put(&p, &sum, 8);
    return TMASS_OK;
}

TMASSDEF int tmass_qs_load_memory(const tmass_model *m, const tmass_qs_desc *d, const void *buffer,
                                  size_t size, tmass_qs **out)
{
    const unsigned char *p = (const unsigned char *)buffer;
    tmass_qs *q;
    unsigned int version, order, real_size, all_nodes, reserved;
    int node_count, pre_count, out_count, err;
    unsigned long long fingerprint, payload, sum, stored_sum;
    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (!buffer) return TMASS_ERR_ARG;
    if (m && m->anchor_count) return TMASS_ERR_ANCHORED;
    if (size < 8) return TMASS_ERR_FILE_TRUNCATED;
    if (memcmp(p, "TMASSQS", 8) != 0) return TMASS_ERR_FILE_FORMAT;
    if (size < TMASS__QS_HEADER_BYTES) return TMASS_ERR_FILE_TRUNCATED;
    memcpy(&version, p + 8, 4);
    memcpy(&order, p + 12, 4);
    memcpy(&real_size, p + 16, 4);
    memcpy(&all_nodes, p + 20, 4);
    memcpy(&node_count, p + 24, 4);
    memcpy(&pre_count, p + 28, 4);
    memcpy(&out_count, p + 32, 4);
    memcpy(&reserved, p + 36, 4);
    memcpy(&fingerprint, p + 40, 8);
    memcpy(&payload, p + 48, 8);
    if (order != 0x01020304u) return TMASS_ERR_FILE_VERSION; /* other byte order */
    if (version != TMASS__QS_VERSION || real_size != sizeof(tmass_real)) return TMASS_ERR_FILE_VERSION;
    err = tmass__qs_prepare(m, d, &q);
    if (err) return err;
    if ((int)all_nodes != q->all_nodes || node_count != q->node_count || pre_count != q->pre_count ||
        out_count != q->out_count || fingerprint != q->fingerprint) {
        tmass_qs_destroy(q);
        return TMASS_ERR_FILE_MISMATCH;
    }
    if (payload != tmass__qs_payload_bytes(q) || reserved != 0) {
        tmass_qs_destroy(q);
        return TMASS_ERR_FILE_FORMAT;
    }
    if (size < TMASS__QS_HEADER_BYTES + payload + 8) {
        tmass_qs_destroy(q);
        return TMASS_ERR_FILE_TRUNCATED;
    }
    sum = tmass__hash(TMASS__FNV_BASIS, p + TMASS__QS_HEADER_BYTES, (size_t)payload);
    memcpy(&stored_sum, p + TMASS__QS_HEADER_BYTES + payload, 8);
    if (sum != stored_sum) {
        tmass_qs_destroy(q);
        return TMASS_ERR_FILE_FORMAT;
    }
    memcpy(q->preload, p + TMASS__QS_HEADER_BYTES, sizeof(tmass_real) * 3 * (size_t)q->node_count);
    memcpy(q->compliance, p + TMASS__QS_HEADER_BYTES + sizeof(tmass_real) * 3 * (size_t)q->node_count,
           (size_t)payload - sizeof(tmass_real) * 3 * (size_t)q->node_count);
    /* a valid checksum only says the bytes are those written: a NaN or an infinity in
       them (written by another tool, or a checksum recomputed by hand) is refused too */
    if (!tmass__all_finite(q->preload, 3 * q->node_count) ||
        !tmass__all_finite(q->compliance, 9 * (size_t)q->pre_count * (size_t)q->out_count)) {
        tmass_qs_destroy(q);
        return TMASS_ERR_FILE_FORMAT;
    }
    tmass__qs_set_preload_state(q);
    *out = q;
    return TMASS_OK;
}

TMASSDEF int tmass_qs_save(const tmass_qs *q, const char *path)
{
    FILE *f;
    size_t size;
    void *buffer;
    int err;
    if (!q || !path) return TMASS_ERR_ARG;
    tmass_qs_save_memory(q, NULL, 0, &size);
    buffer = tmass__alloc(&q->allocator, size);
    if (!buffer) return TMASS_ERR_ALLOC;
    err = tmass_qs_save_memory(q, buffer, size, &size);
    if (!err) {
        f = fopen(path, "wb");
        if (!f) {
            err = TMASS_ERR_FILE_IO;
        } else {
            if (fwrite(buffer, 1, size, f) != size) err = TMASS_ERR_FILE_IO;
            if (fclose(f) != 0) err = TMASS_ERR_FILE_IO;
        }
    }
    tmass__free(&q->allocator, buffer, size);
    return err;
}

TMASSDEF int tmass_qs_load(const tmass_model *m, const tmass_qs_desc *d, const char *path,
                           tmass_qs **out)
{
    FILE *f;
    long length;
    size_t size;
    void *buffer;
    int err = TMASS_OK;
    tmass_allocator a;
    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (m && m->anchor_count) return TMASS_ERR_ANCHORED;
    if (!path || !d) return TMASS_ERR_ARG;
    a = d->allocator;
    f = fopen(path, "rb");
    if (!f) return TMASS_ERR_FILE_IO;
    if (fseek(f, 0, SEEK_END) != 0 || (length = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return TMASS_ERR_FILE_IO;
    }
    size = (size_t)length;
    buffer = tmass__alloc(&a, size ? size : 1);
    if (!buffer) {
        fclose(f);
        return TMASS_ERR_ALLOC;
    }
    if (fread(buffer, 1, size, f) != size) err = TMASS_ERR_FILE_IO;
    fclose(f);
    if (!err) err = tmass_qs_load_memory(m, d, buffer, size, out);
    tmass__free(&a, buffer, size ? size : 1);
    return err;
}

/* >>hybrid ---------------------------------------------------------------------------- */

#define TMASS__HY_COOKIE 0x59484D54u /* "TMHY" */

struct tmass_hybrid {
    int node_count, tet_count, dyn_tets;
    tmass_allocator allocator;
    void *block;
    size_t block_bytes;
    tmass_model *dyn;
    tmass_qs *qs;
    int *dyn_of, *qs_of;        /* whole-mesh node -> local node of each part, or -1 */
    int *dyn_global;            /* dynamic-part node -> whole-mesh node */
    int *tet_local;             /* whole-mesh tet -> tet of its part */
    unsigned char *tet_dynamic; /* whole-mesh tet -> 1 dynamic, 0 precomputed */
    unsigned char *fixed;       /* whole-mesh node -> pinned at rest */
    /* connection nodes: shared by both parts, free, still active in the dynamic part */
    int conn_count;
    int *conn_qs;     /* their precomputed-part nodes */
    double *S;        /* (3c)^2 row-major: (C_cc)^-1, the precomputed part's stiffness there */
    double *g_conn;   /* 3c preload at the connections */
    /* contacts on the precomputed part */
    int contact_count, max_contacts, contacts_dirty;
    int *contact_qs;        /* precomputed-part nodes */
    tmass_real *contact_u;  /* 3K imposed displacements */
    double *W;              /* 3c x 3K: S C_ck */
    double *V;              /* 3K x 3c: Z^-1 W^T */
    double *Z;              /* (3K)^2: Cholesky of C_kk - C_kc S C_ck */
    double *f_contact;      /* 3K forces at the contacts */
    double *f_all;          /* 3c + 3K forces at connections, then contacts */
    double *work;           /* 3c + 3K */
    int *cols;              /* 3c + 3K compliance columns */
    tmass_real *pos;        /* 3N */
    /* rendering: static faces of the precomputed part, interface faces (precomputed-side
       orientation) with the dynamic tet across, flags on the dynamic part's faces */
    int qs_tri_count, iface_count, tri_count, tri_capacity;
    int *qs_tri, *iface_tri, *iface_dyn_tet, *tri;
    unsigned char *dyn_face_iface;
};

TMASSDEF tmass_hybrid_desc tmass_hybrid_default_desc(void)
{
    tmass_hybrid_desc d;
    memset(&d, 0, sizeof d);
    d.model = tmass_default_desc();
    d.precompute = tmass_qs_default_desc();
    d.internal_cookie = TMASS__HY_COOKIE;
    return d;
}

typedef struct tmass__hy_sizes {
    int N, T, c, K, qs_tris, ifaces, dyn_tets, dyn_nodes, tri_capacity;
} tmass__hy_sizes;

static void tmass__hybrid_layout(tmass_hybrid *h, const tmass__hy_sizes *z, tmass__carver *c)
{
    size_t c3 = 3 * (size_t)z->c, K3 = 3 * (size_t)z->K;
    TMASS__CARVE(c, h->dyn_of, int, z->N);
    TMASS__CARVE(c, h->qs_of, int, z->N);
    TMASS__CARVE(c, h->dyn_global, int, z->dyn_nodes);
    TMASS__CARVE(c, h->tet_local, int, z->T);
    TMASS__CARVE(c, h->tet_dynamic, unsigned char, z->T);
    TMASS__CARVE(c, h->fixed, unsigned char, z->N);
    TMASS__CARVE(c, h->conn_qs, int, z->c);
    TMASS__CARVE(c, h->S, double, c3 * c3);
    TMASS__CARVE(c, h->g_conn, double, c3);
    TMASS__CARVE(c, h->contact_qs, int, z->K);
    TMASS__CARVE(c, h->contact_u, tmass_real, K3);
    TMASS__CARVE(c, h->W, double, c3 * K3);
    TMASS__CARVE(c, h->V, double, K3 * c3);
    TMASS__CARVE(c, h->Z, double, K3 * K3);
    TMASS__CARVE(c, h->f_contact, double, K3);
    TMASS__CARVE(c, h->f_all, double, c3 + K3);
    TMASS__CARVE(c, h->work, double, c3 + K3);
    TMASS__CARVE(c, h->cols, int, c3 + K3);
    TMASS__CARVE(c, h->pos, tmass_real, 3 * (size_t)z->N);
    TMASS__CARVE(c, h->qs_tri, int, 3 * (size_t)z->qs_tris);
    TMASS__CARVE(c, h->iface_tri, int, 3 * (size_t)z->ifaces);
    TMASS__CARVE(c, h->iface_dyn_tet, int, z->ifaces);
    TMASS__CARVE(c, h->tri, int, 3 * (size_t)z->tri_capacity);
    TMASS__CARVE(c, h->dyn_face_iface, unsigned char, 4 * (size_t)z->dyn_tets);
}

/* Compliance entry between two precomputed-part nodes' degrees of freedom. */
static double tmass__hy_C(const tmass_hybrid *h, int row_node, int row_dir, int col_node, int col_dir)
{
    const tmass_qs *q = h->qs;
    return tmass__qs_entry(q, 3 * q->row_of_node[row_node] + row_dir,
                           3 * q->col_of_node[col_node] + col_dir);
}

/* Installs S' = S + W V (contacts on the precomputed part) as the dynamic part's coupling
   stiffness; recomputes W, Z and V when the contact set changed. */
static int tmass__hybrid_coupling(tmass_hybrid *h)
{
    int c3 = 3 * h->conn_count, K3 = 3 * h->contact_count, r, s, i, j;
    double *Sp = h->dyn->coupling;
    if (!h->contacts_dirty) return TMASS_OK;
    memcpy(Sp, h->S, sizeof(double) * (size_t)c3 * c3);
    if (K3 > 0) {
        /* W = S C_ck, column by column */
        for (j = 0; j < K3; j++) {
            int kn = h->contact_qs[j / 3];
            for (r = 0; r < c3; r++) h->work[r] = tmass__hy_C(h, h->conn_qs[r / 3], r % 3, kn, j % 3);
            for (r = 0; r < c3; r++) {
                const double *row = h->S + (size_t)r * c3;
                double acc = 0.0;
                for (s = 0; s < c3; s++) acc += row[s] * h->work[s];
                h->W[(size_t)r * K3 + j] = acc;
            }
        }
        /* Z = C_kk - C_kc W */
        for (i = 0; i < K3; i++)
            for (j = 0; j < K3; j++) {
                double z = tmass__hy_C(h, h->contact_qs[i / 3], i % 3, h->contact_qs[j / 3], j % 3);
                for (r = 0; r < c3; r++)
                    z -= tmass__hy_C(h, h->conn_qs[r / 3], r % 3, h->contact_qs[i / 3], i % 3) *
                         h->W[(size_t)r * K3 + j];
                h->Z[(size_t)i * K3 + j] = z;
            }
        if (tmass__cholesky(h->Z, K3)) return TMASS_ERR_SINGULAR;
        /* V = Z^-1 W^T, then S' = S + W V */
        for (r = 0; r < c3; r++) {
            for (i = 0; i < K3; i++) h->work[i] = h->W[(size_t)r * K3 + i];
            tmass__cholesky_solve(h->Z, K3, h->work);
            for (i = 0; i < K3; i++) h->V[(size_t)i * c3 + r] = h->work[i];
        }
        for (r = 0; r < c3; r++)
            for (s = 0; s < c3; s++) {
                double acc = 0.0;
                for (i = 0; i < K3; i++) acc += h->W[(size_t)r * K3 + i] * h->V[(size_t)i * c3 + s];
                Sp[(size_t)r * c3 + s] += acc;
            }
    }
    h->dyn->coupling_count = h->conn_count;
    h->dyn->coarse_version++; /* the coupling block joins the coarse matrix (>>coarse) */
    h->contacts_dirty = 0;
    return TMASS_OK;
}

/* The constant part of the connection forces felt by the dynamic part:
   S' g_c + V^T (u_k - g_k), written into its external forces. */
static void tmass__hybrid_loads(tmass_hybrid *h)
{
    int c3 = 3 * h->conn_count, K3 = 3 * h->contact_count, r, s, i;
    const tmass_qs *q = h->qs;
    for (r = 0; r < c3; r++) {
        const double *row = h->dyn->coupling + (size_t)r * c3;
        double acc = 0.0;
        for (s = 0; s < c3; s++) acc += row[s] * h->g_conn[s];
        for (i = 0; i < K3; i++)
            acc += h->V[(size_t)i * c3 + r] *
                   ((double)h->contact_u[i] - (double)q->preload[3 * h->contact_qs[i / 3] + i % 3]);
        h->dyn->ext[3 * h->dyn->coupling_nodes[r / 3] + r % 3] = (tmass_real)acc;
    }
}

/* After the dynamic part moved: forces on the precomputed part at connections and
   contacts, its displacements, and the positions of the whole mesh. */
static void tmass__hybrid_finish(tmass_hybrid *h)
{
    int c3 = 3 * h->conn_count, K3 = 3 * h->contact_count, r, s, i, n;
    const tmass_qs *q = h->qs;
    double *rc = h->work; /* u_c - g_c */
    for (r = 0; r < c3; r++)
        rc[r] = (double)h->dyn->disp[3 * h->dyn->coupling_nodes[r / 3] + r % 3] - h->g_conn[r];
    if (K3 > 0) { /* f_k = Z^-1 (u_k - g_k - W^T r_c) */
        for (i = 0; i < K3; i++) {
            double acc = (double)h->contact_u[i] - (double)q->preload[3 * h->contact_qs[i / 3] + i % 3];
            for (r = 0; r < c3; r++) acc -= h->W[(size_t)r * K3 + i] * rc[r];
            h->f_contact[i] = acc;
        }
        tmass__cholesky_solve(h->Z, K3, h->f_contact);
    }
    for (r = 0; r < c3; r++) { /* f_c = S r_c - W f_k */
        const double *row = h->S + (size_t)r * c3;
        double acc = 0.0;
        for (s = 0; s < c3; s++) acc += row[s] * rc[s];
        for (i = 0; i < K3; i++) acc -= h->W[(size_t)r * K3 + i] * h->f_contact[i];
        h->f_all[r] = acc;
        h->cols[r] = 3 * q->col_of_node[h->conn_qs[r / 3]] + r % 3;
    }
    for (i = 0; i < K3; i++) {
        h->f_all[c3 + i] = h->f_contact[i];
        h->cols[c3 + i] = 3 * q->col_of_node[h->contact_qs[i / 3]] + i % 3;
    }
    tmass__qs_superpose(h->qs, h->cols, h->f_all, c3 + K3);
    for (n = 0; n < h->node_count; n++) {
        /* a node cut off the dynamic part follows the precomputed part if it belongs to it */
        int d = h->dyn_of[n], in_dyn = d >= 0 && h->dyn->node_state[d] != TMASS__INACTIVE;
        const tmass_real *p = in_dyn || (d >= 0 && h->qs_of[n] < 0) ? h->dyn->pos + 3 * d
                                                                   : q->pos + 3 * h->qs_of[n];
        memcpy(h->pos + 3 * n, p, 3 * sizeof(tmass_real));
    }
}

/* Removes connection nodes whose dynamic node has no tetrahedron left: the inverse of a
   principal submatrix of C from its inverse S, S_rr - S_rd S_dd^-1 S_dr, one node at a
   time (a rank-3 update), then compaction. */
static void tmass__hybrid_drop_connections(tmass_hybrid *h)
{
    int k = 0;
    while (k < h->conn_count) {
        int v = h->dyn->coupling_nodes[k], c3 = 3 * h->conn_count, a, b, r, s, w;
        double A[9], inv[9], det;
        if (h->dyn->node_state[v] != TMASS__INACTIVE) {
            k++;
            continue;
        }
        for (a = 0; a < 3; a++)
            for (b = 0; b < 3; b++) A[3 * a + b] = h->S[(size_t)(3 * k + a) * c3 + 3 * k + b];
        inv[0] = A[4] * A[8] - A[5] * A[7];
        inv[1] = A[2] * A[7] - A[1] * A[8];
        inv[2] = A[1] * A[5] - A[2] * A[4];
        inv[3] = A[5] * A[6] - A[3] * A[8];
        inv[4] = A[0] * A[8] - A[2] * A[6];
        inv[5] = A[2] * A[3] - A[0] * A[5];
        inv[6] = A[3] * A[7] - A[4] * A[6];
        inv[7] = A[1] * A[6] - A[0] * A[7];
        inv[8] = A[0] * A[4] - A[1] * A[3];
        det = A[0] * inv[0] + A[1] * inv[3] + A[2] * inv[6];
        for (a = 0; a < 9; a++) inv[a] /= det;
        for (r = 0; r < c3; r++) {
            double t[3];
            if (r / 3 == k) continue;
            for (a = 0; a < 3; a++) { /* t = S_r,d S_dd^-1 */
                t[a] = 0.0;
                for (b = 0; b < 3; b++) t[a] += h->S[(size_t)r * c3 + 3 * k + b] * inv[3 * b + a];
            }
            for (s = 0; s < c3; s++) {
                if (s / 3 == k) continue;
                h->S[(size_t)r * c3 + s] -= t[0] * h->S[(size_t)(3 * k) * c3 + s] +
                                            t[1] * h->S[(size_t)(3 * k + 1) * c3 + s] +
                                            t[2] * h->S[(size_t)(3 * k + 2) * c3 + s];
            }
        }
        /* compact rows and columns (in place, destinations never pass their sources) */
        for (r = 0, w = 0; r < c3; r++) {
            if (r / 3 == k) continue;
            for (s = 0; s < c3; s++)
                if (s / 3 != k) h->S[w++] = h->S[(size_t)r * c3 + s];
        }
        for (r = 3 * k; r < c3 - 3; r++) h->g_conn[r] = h->g_conn[r + 3];
        for (r = k; r < h->conn_count - 1; r++) {
            h->conn_qs[r] = h->conn_qs[r + 1];
            h->dyn->coupling_nodes[r] = h->dyn->coupling_nodes[r + 1];
        }
        memset(h->dyn->ext + 3 * v, 0, 3 * sizeof(tmass_real));
        h->conn_count--;
        h->contacts_dirty = 1;
    }
    h->dyn->coupling_count = h->contacts_dirty ? 0 : h->conn_count;
    h->dyn->coarse_version++;
}

typedef struct tmass__face_key {
    int key[3], tri[3], source, owner; /* source 0 precomputed part, 1 dynamic part */
} tmass__face_key;

static int tmass__face_key_cmp(const void *pa, const void *pb)
{
    const tmass__face_key *a = (const tmass__face_key *)pa, *b = (const tmass__face_key *)pb;
    int k;
    for (k = 0; k < 3; k++)
        if (a->key[k] != b->key[k]) return a->key[k] < b->key[k] ? -1 : 1;
    return a->source - b->source;
}

static void tmass__sort3(const int *t, int *key)
{
    int a = t[0], b = t[1], c = t[2], s;
    if (a > b) { s = a; a = b; b = s; }
    if (b > c) { s = b; b = c; c = s; }
    if (a > b) { s = a; a = b; b = s; }
    key[0] = a;
    key[1] = b;
    key[2] = c;
}

static int tmass__root(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* Adds fixed node v to a set of up to three non-collinear supports (indices in s[3]). */
static void tmass__add_support(const tmass_real *x, int *s, int v)
{
    double e1[3], e2[3], c[3], l1 = 0.0, lc = 0.0;
    int k;
    if (s[0] < 0) {
        s[0] = v;
        return;
    }
    for (k = 0; k < 3; k++) e1[k] = (double)x[3 * v + k] - x[3 * s[0] + k];
    for (k = 0; k < 3; k++) l1 += e1[k] * e1[k];
    if (s[1] < 0) {
        if (l1 > 0.0) s[1] = v;
        return;
    }
    if (s[2] >= 0) return;
    for (k = 0; k < 3; k++) {
        e1[k] = (double)x[3 * s[1] + k] - x[3 * s[0] + k];
        e2[k] = (double)x[3 * v + k] - x[3 * s[0] + k];
    }
    c[0] = e1[1] * e2[2] - e1[2] * e2[1];
    c[1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2] = e1[0] * e2[1] - e1[1] * e2[0];
    for (k = 0, l1 = 0.0; k < 3; k++) {
        lc += c[k] * c[k];
        l1 += e1[k] * e1[k];
    }
    if (lc > 1e-12 * l1 * l1) s[2] = v;
}

/* A face-connected piece of the precomputed part that is not held by three non-collinear
   fixed nodes has a singular stiffness (its precomputation cannot converge): such pieces
   move to the dynamic part, where they hang on the connection nodes. work: 4T ints.
   Returns the number of tetrahedra moved. */
static int tmass__hybrid_support(const tmass_desc *m, unsigned char *dynamic, const unsigned char *fixed,
                                 tmass__face_key *keys, int *work)
{
    int T = m->tet_count, t, f, i, k, n = 0, moved = 0, *parent = work, *support = work + T;
    for (t = 0; t < T; t++) {
        parent[t] = t;
        support[3 * t] = support[3 * t + 1] = support[3 * t + 2] = -1;
        if (dynamic[t]) continue;
        for (f = 0; f < 4; f++, n++) {
            for (k = 0; k < 3; k++) keys[n].tri[k] = m->tets[4 * t + tmass__face_local[f][k]];
            tmass__sort3(keys[n].tri, keys[n].key);
            keys[n].source = 0;
            keys[n].owner = t;
        }
    }
    qsort(keys, (size_t)n, sizeof *keys, tmass__face_key_cmp);
    for (i = 0; i + 1 < n; i++)
        if (memcmp(keys[i].key, keys[i + 1].key, sizeof keys[i].key) == 0) {
            int a = tmass__root(parent, keys[i].owner), b = tmass__root(parent, keys[i + 1].owner);
            if (a != b) parent[a] = b;
        }
    for (t = 0; t < T; t++)
        if (!dynamic[t])
            for (k = 0; k < 4; k++)
                if (fixed[m->tets[4 * t + k]])
                    tmass__add_support(m->rest_positions, support + 3 * tmass__root(parent, t), m->tets[4 * t + k]);
    for (t = 0; t < T; t++)
        if (!dynamic[t] && support[3 * tmass__root(parent, t) + 2] < 0) {
            dynamic[t] = 1;
            moved++;
        }
    return moved;
}

/* Sub-description of one part: its tets (and per-tet materials) with local node numbers. */
static void tmass__hybrid_subdesc(const tmass_hybrid_desc *d, const unsigned char *dynamic, int part, const int *local_of,
                                  int node_total, tmass_real *rest, int *tets, tmass_real *young,
                                  tmass_real *poisson, tmass_desc *sub)
{
    int t, j, n = 0, i;
    *sub = d->model;
    for (i = 0; i < d->model.node_count; i++)
        if (local_of[i] >= 0) memcpy(rest + 3 * local_of[i], d->model.rest_positions + 3 * i, 3 * sizeof(tmass_real));
    for (t = 0; t < d->model.tet_count; t++) {
        if ((dynamic[t] != 0) != (part == 1)) continue;
        for (j = 0; j < 4; j++) tets[4 * n + j] = local_of[d->model.tets[4 * t + j]];
        if (d->model.tet_young_modulus) young[n] = d->model.tet_young_modulus[t];
        if (d->model.tet_poisson_ratio) poisson[n] = d->model.tet_poisson_ratio[t];
        n++;
    }
    sub->rest_positions = rest;
    sub->node_count = node_total;
    sub->tets = tets;
    sub->tet_count = n;
    sub->tet_young_modulus = d->model.tet_young_modulus ? young : NULL;
    sub->tet_poisson_ratio = d->model.tet_poisson_ratio ? poisson : NULL;
}

/* tmass_hybrid_create in stages that read top to bottom: validate the description, size
   the parts (which tetrahedra are dynamic, the node maps), create the two parts (the
   dynamic model, the precomputed model and its compliance), find the interface faces and
   size the hybrid block, lay it out, precompute the coupling (S = C_cc^-1) and the
   rendering lists. tmass__hy_build carries the creation-time state between them. */
typedef struct tmass__hy_build {
    tmass_allocator a;
    char *tmp_block; /* temporary: face keys, a rest copy and per-tet materials of a part,
                        node maps, tets of a part, fixed and dynamic flags */
    size_t tmp_bytes;
    tmass__face_key *keys;
    tmass_real *rtmp;
    int *dyn_of, *qs_of, *itmp;
    unsigned char *fixed, *dynamic;
    int n_dyn, n_qs, t_dyn, c0, faces;
    tmass_model *dyn, *src; /* the dynamic part; the precomputed part's model (temporary) */
    tmass_qs *qs;
    tmass__hy_sizes z;
} tmass__hy_build;

static int tmass__hybrid_create_validate(const tmass_hybrid_desc *d)
{
    int i, err;
    if (d->internal_cookie != TMASS__HY_COOKIE) return TMASS_ERR_DESC;
    err = tmass__create_validate(&d->model);
    if (err) return err;
    if (!(tmass__kinds[d->model.kind].flags & TMASS__KIND_LINEAR)) return TMASS_ERR_MODEL_KIND;
    if (!d->tet_dynamic || d->fixed_count < 0 || (d->fixed_count > 0 && !d->fixed_nodes))
        return TMASS_ERR_ARG;
    for (i = 0; i < d->fixed_count; i++)
        if (d->fixed_nodes[i] < 0 || d->fixed_nodes[i] >= d->model.node_count) return TMASS_ERR_NODE_RANGE;
    return TMASS_OK;
}

/* The temporary tables; which tetrahedra are dynamic (unsupported precomputed pieces
   moved over, reported through the log); each part's node numbering. */
static int tmass__hybrid_create_size(const tmass_hybrid_desc *d, tmass__hy_build *b)
{
    int i, t, k, N = d->model.node_count, T = d->model.tet_count;
    tmass__carver carver;
    b->tmp_bytes = sizeof(int) * (2 * (size_t)N + 4 * (size_t)T) + (size_t)N + (size_t)T +
                   sizeof(tmass_real) * (3 * (size_t)N + 2 * (size_t)T) + sizeof(tmass__face_key) * 8 * (size_t)T +
                   4 * TMASS__ALIGN;
    b->tmp_block = (char *)tmass__alloc(&b->a, b->tmp_bytes);
    if (!b->tmp_block) return TMASS_ERR_ALLOC;
    carver.base = b->tmp_block;
    carver.offset = 0;
    b->keys = (tmass__face_key *)tmass__carve(&carver, sizeof(tmass__face_key) * 8 * (size_t)T);
    b->rtmp = (tmass_real *)tmass__carve(&carver, sizeof(tmass_real) * (3 * (size_t)N + 2 * (size_t)T));
    b->dyn_of = (int *)tmass__carve(&carver, sizeof(int) * (2 * (size_t)N + 4 * (size_t)T));
    b->qs_of = b->dyn_of + N;
    b->itmp = b->qs_of + N;
    b->fixed = (unsigned char *)tmass__carve(&carver, (size_t)N);
    b->dynamic = (unsigned char *)tmass__carve(&carver, (size_t)T);
    memset(b->fixed, 0, (size_t)N);
    for (i = 0; i < d->fixed_count; i++) b->fixed[d->fixed_nodes[i]] = 1;
    for (t = 0; t < T; t++) b->dynamic[t] = d->tet_dynamic[t] != 0;
    i = tmass__hybrid_support(&d->model, b->dynamic, b->fixed, b->keys, b->itmp);
    if (i && d->model.log) {
        char msg[160];
        snprintf(msg, sizeof msg, "%d tetrahedra of the precomputed part were not held by fixed nodes "
                 "and were moved to the dynamic part", i);
        d->model.log(TMASS_OK, msg, d->model.log_user);
    }
    for (i = 0; i < N; i++) b->dyn_of[i] = b->qs_of[i] = -1;
    for (t = 0; t < T; t++) {
        int *map = b->dynamic[t] ? b->dyn_of : b->qs_of;
        b->t_dyn += b->dynamic[t] != 0;
        for (k = 0; k < 4; k++) map[d->model.tets[4 * t + k]] = 1;
    }
    for (i = 0; i < N; i++) {
        if (b->dyn_of[i] >= 0) b->dyn_of[i] = b->n_dyn++;
        if (b->qs_of[i] >= 0) b->qs_of[i] = b->n_qs++;
    }
    return b->t_dyn == 0 || b->t_dyn == T ? TMASS_ERR_ARG : TMASS_OK;
}

/* The two parts: the dynamic model, the precomputed part's model and its compliance
   (every node output), each with its fixed nodes pinned. */
static int tmass__hybrid_create_parts(const tmass_hybrid_desc *d, tmass__hy_build *b)
{
    int i, err, N = d->model.node_count, T = d->model.tet_count;
    tmass_desc sub;
    tmass_qs_desc qd;
    tmass__hybrid_subdesc(d, b->dynamic, 1, b->dyn_of, b->n_dyn, b->rtmp, b->itmp, b->rtmp + 3 * N,
                          b->rtmp + 3 * N + T, &sub);
    err = tmass_create(&sub, &b->dyn);
    for (i = 0; i < N && !err; i++)
        if (b->fixed[i] && b->dyn_of[i] >= 0) err = tmass_fix_node(b->dyn, b->dyn_of[i]);
    if (!err) {
        tmass__hybrid_subdesc(d, b->dynamic, 0, b->qs_of, b->n_qs, b->rtmp, b->itmp, b->rtmp + 3 * N,
                              b->rtmp + 3 * N + T, &sub);
        sub.implicit_coarse = -1; /* the precomputed part never steps */
        err = tmass_create(&sub, &b->src);
    }
    for (i = 0; i < N && !err; i++)
        if (b->fixed[i] && b->qs_of[i] >= 0) err = tmass_fix_node(b->src, b->qs_of[i]);
    if (!err) {
        qd = d->precompute;
        qd.nodes = NULL;
        qd.node_count = 0;
        qd.allocator = b->a;
        err = tmass_qs_create(b->src, &qd, &b->qs);
    }
    return err;
}

/* Interface faces: the triangles of both parts' boundaries, sorted by their sorted nodes
   (global numbering; itmp holds each part's local -> global map in turn), so a face on
   both boundaries appears twice in a row. Counts the connection nodes and sizes the
   hybrid block (b->z). */
static void tmass__hybrid_create_faces(const tmass_hybrid_desc *d, tmass__hy_build *b)
{
    int i, k, f, nk = 0, ifaces = 0, qs_tris = 0, N = d->model.node_count;
    tmass__face_key *keys = b->keys;
    for (i = 0; i < N; i++)
        if (b->qs_of[i] >= 0) b->itmp[b->qs_of[i]] = i;
    for (f = 0; f < b->src->tri_count; f++, nk++) {
        for (k = 0; k < 3; k++) keys[nk].tri[k] = b->itmp[b->src->tri[3 * f + k]];
        keys[nk].source = 0;
        keys[nk].owner = f;
    }
    for (i = 0; i < N; i++)
        if (b->dyn_of[i] >= 0) b->itmp[b->dyn_of[i]] = i;
    for (f = 0; f < b->dyn->tri_count; f++, nk++) {
        for (k = 0; k < 3; k++) keys[nk].tri[k] = b->itmp[b->dyn->tri[3 * f + k]];
        keys[nk].source = 1;
        keys[nk].owner = b->dyn->tri_owner[f];
    }
    for (f = 0; f < nk; f++) tmass__sort3(keys[f].tri, keys[f].key);
    qsort(keys, (size_t)nk, sizeof *keys, tmass__face_key_cmp);
    b->faces = nk;
    for (i = 0; i < N; i++)
        if (b->dyn_of[i] >= 0 && b->qs_of[i] >= 0 && !b->fixed[i]) b->c0++;
    for (i = 0; i < b->faces; i++) {
        int shared = (i + 1 < b->faces && memcmp(keys[i].key, keys[i + 1].key, sizeof keys[i].key) == 0) ||
                     (i > 0 && memcmp(keys[i].key, keys[i - 1].key, sizeof keys[i].key) == 0);
        if (keys[i].source == 0) {
            if (shared)
                ifaces++;
            else
                qs_tris++;
        }
    }
    b->z.N = N;
    b->z.T = d->model.tet_count;
    b->z.c = b->c0;
    b->z.K = d->precompute.max_contacts;
    b->z.qs_tris = qs_tris;
    b->z.ifaces = ifaces;
    b->z.dyn_tets = b->t_dyn;
    b->z.dyn_nodes = b->n_dyn;
    b->z.tri_capacity = qs_tris + ifaces + 4 * b->t_dyn;
}

/* Allocates and carves the hybrid block; fills the maps between the whole mesh and the
   parts. */
static int tmass__hybrid_create_layout(const tmass__hy_build *b, tmass_hybrid **out)
{
    tmass_hybrid tmp, *h;
    tmass__carver carver;
    int i, t, N = b->z.N, T = b->z.T, nd = 0, nq = 0;
    memset(&tmp, 0, sizeof tmp);
    carver.base = NULL;
    carver.offset = sizeof(tmass_hybrid);
    tmass__hybrid_layout(&tmp, &b->z, &carver);
    tmp.block_bytes = carver.offset;
    tmp.block = tmass__alloc(&b->a, tmp.block_bytes);
    if (!tmp.block) return TMASS_ERR_ALLOC;
    memset(tmp.block, 0, tmp.block_bytes);
    carver.base = (char *)tmp.block;
    carver.offset = sizeof(tmass_hybrid);
    tmass__hybrid_layout(&tmp, &b->z, &carver);
    h = (tmass_hybrid *)tmp.block;
    *h = tmp;
    h->allocator = b->a;
    h->node_count = N;
    h->tet_count = T;
    h->dyn_tets = b->t_dyn;
    h->dyn = b->dyn;
    h->qs = b->qs;
    h->max_contacts = b->z.K;
    h->tri_capacity = b->z.tri_capacity;
    memcpy(h->dyn_of, b->dyn_of, sizeof(int) * (size_t)N);
    memcpy(h->qs_of, b->qs_of, sizeof(int) * (size_t)N);
    memcpy(h->fixed, b->fixed, (size_t)N);
    for (i = 0; i < N; i++)
        if (b->dyn_of[i] >= 0) h->dyn_global[b->dyn_of[i]] = i;
    for (t = 0; t < T; t++) {
        h->tet_dynamic[t] = b->dynamic[t];
        h->tet_local[t] = h->tet_dynamic[t] ? nd++ : nq++;
    }
    *out = h;
    return TMASS_OK;
}

/* The coupling block of the dynamic model (connection nodes, S = (C_cc)^-1 by Cholesky
   column by column, exactly symmetric; freed with the model) and the connections'
   preload. */
static int tmass__hybrid_create_coupling(const tmass__hy_build *b, tmass_hybrid *h)
{
    tmass_model *dyn = b->dyn;
    int i, k, err = TMASS_OK, c0 = b->c0, N = b->z.N;
    tmass__carver cc;
    size_t cb = sizeof(int) * (size_t)c0 + sizeof(double) * (9 * (size_t)c0 * c0 + 6 * (size_t)c0) + 2 * TMASS__ALIGN;
    dyn->coupling_block = tmass__alloc(&b->a, cb);
    if (!dyn->coupling_block) return TMASS_ERR_ALLOC;
    dyn->coupling_bytes = cb;
    cc.base = (char *)dyn->coupling_block;
    cc.offset = 0;
    dyn->coupling = (double *)tmass__carve(&cc, sizeof(double) * 9 * (size_t)c0 * c0);
    dyn->coupling_x = (double *)tmass__carve(&cc, sizeof(double) * 6 * (size_t)c0);
    dyn->coupling_nodes = (int *)tmass__carve(&cc, sizeof(int) * (size_t)c0);
    for (i = 0, k = 0; i < N; i++)
        if (b->dyn_of[i] >= 0 && b->qs_of[i] >= 0 && !b->fixed[i]) {
            h->conn_qs[k] = b->qs_of[i];
            dyn->coupling_nodes[k] = b->dyn_of[i];
            if (b->qs->col_of_node[b->qs_of[i]] < 0) err = TMASS_ERR_NOT_PRECOMPUTED;
            k++;
        }
    h->conn_count = c0;
    if (!err && c0 > 0) {
        int c3 = 3 * c0, r, s;
        double *L = dyn->coupling; /* scratch for the factor */
        for (r = 0; r < c3; r++)
            for (s = 0; s < c3; s++) L[(size_t)r * c3 + s] = tmass__hy_C(h, h->conn_qs[r / 3], r % 3, h->conn_qs[s / 3], s % 3);
        if (tmass__cholesky(L, c3)) err = TMASS_ERR_SINGULAR;
        for (s = 0; s < c3 && !err; s++) {
            for (r = 0; r < c3; r++) h->work[r] = r == s;
            tmass__cholesky_solve(L, c3, h->work);
            for (r = 0; r < c3; r++) h->S[(size_t)r * c3 + s] = h->work[r];
        }
        for (r = 0; r < c3 && !err; r++) /* exact symmetry */
            for (s = 0; s < r; s++) {
                double v = 0.5 * (h->S[(size_t)r * c3 + s] + h->S[(size_t)s * c3 + r]);
                h->S[(size_t)r * c3 + s] = h->S[(size_t)s * c3 + r] = v;
            }
        for (r = 0; r < c3; r++) h->g_conn[r] = (double)b->qs->preload[3 * h->conn_qs[r / 3] + r % 3];
    }
    return err;
}

/* The coupling, then the rendering lists (static faces of the precomputed part,
   interface faces with the dynamic tet across, flags on the dynamic part's faces) and
   the coupling stiffness in the dynamic model. */
static int tmass__hybrid_create_precompute(const tmass__hy_build *b, tmass_hybrid *h)
{
    const tmass__face_key *keys = b->keys;
    int i, nq = 0, ni = 0, faces = b->faces;
    int err = tmass__hybrid_create_coupling(b, h);
    if (err) return err;
    for (i = 0; i < faces; i++) {
        int partner = -1;
        if (i + 1 < faces && memcmp(keys[i].key, keys[i + 1].key, sizeof keys[i].key) == 0) partner = i + 1;
        if (i > 0 && memcmp(keys[i].key, keys[i - 1].key, sizeof keys[i].key) == 0) partner = i - 1;
        if (keys[i].source == 0 && partner < 0) {
            memcpy(h->qs_tri + 3 * nq++, keys[i].tri, 3 * sizeof(int));
        } else if (keys[i].source == 0) {
            memcpy(h->iface_tri + 3 * ni, keys[i].tri, 3 * sizeof(int));
            h->iface_dyn_tet[ni++] = keys[partner].owner / 4;
        } else if (partner >= 0) {
            h->dyn_face_iface[keys[i].owner] = 1;
        }
    }
    h->qs_tri_count = nq;
    h->iface_count = ni;
    h->contacts_dirty = 1;
    return tmass__hybrid_coupling(h);
}

TMASSDEF int tmass_hybrid_create(const tmass_hybrid_desc *d, tmass_hybrid **out)
{
    tmass__hy_build b;
    tmass_hybrid *h = NULL;
    int err;
    if (!out) return TMASS_ERR_ARG;
    *out = NULL;
    if (!d) return TMASS_ERR_ARG;
    err = tmass__hybrid_create_validate(d);
    if (err) return err;
    memset(&b, 0, sizeof b);
    b.a = d->model.allocator;
    err = tmass__hybrid_create_size(d, &b);
    if (!b.tmp_block) return err;
    if (!err) err = tmass__hybrid_create_parts(d, &b);
    if (!err) tmass__hybrid_create_faces(d, &b);
    if (!err) err = tmass__hybrid_create_layout(&b, &h);
    if (!err) {
        err = tmass__hybrid_create_precompute(&b, h);
        if (err) {
            tmass__free(&b.a, h->block, h->block_bytes);
        } else {
            tmass__hybrid_loads(h);
            tmass__hybrid_finish(h);
            *out = h;
        }
    }
    tmass_destroy(b.src);
    if (err) {
        tmass_destroy(b.dyn);
        tmass_qs_destroy(b.qs);
    }
    tmass__free(&b.a, b.tmp_block, b.tmp_bytes);
    return err;
}

TMASSDEF void tmass_hybrid_destroy(tmass_hybrid *h)
{
    tmass_allocator a;
    if (!h) return;
    a = h->allocator;
    tmass_destroy(h->dyn);
    tmass_qs_destroy(h->qs);
    tmass__free(&a, h->block, h->block_bytes);
}

TMASSDEF int tmass_hybrid_step_ex(tmass_hybrid *h, tmass_real dt, tmass_integrator integrator)
{
    int err;
    if (!h) return TMASS_ERR_ARG;
    err = tmass__hybrid_coupling(h);
    if (err) return err;
    tmass__hybrid_loads(h);
    err = tmass_step_ex(h->dyn, dt, integrator);
    if (err) return err;
    tmass__hybrid_finish(h);
    return TMASS_OK;
}

TMASSDEF int tmass_hybrid_step(tmass_hybrid *h)
{
    if (!h) return TMASS_ERR_ARG;
    return tmass_hybrid_step_ex(h, h->dyn->time_step, h->dyn->integrator);
}

TMASSDEF int tmass_hybrid_solve_static(tmass_hybrid *h)
{
    int err;
    if (!h) return TMASS_ERR_ARG;
    err = tmass__hybrid_coupling(h);
    if (err) return err;
    tmass__hybrid_loads(h);
    err = tmass_solve_static(h->dyn);
    if (err) return err;
    tmass__hybrid_finish(h);
    return TMASS_OK;
}

TMASSDEF int tmass_hybrid_set_displacement(tmass_hybrid *h, int node, const tmass_real u[3])
{
    int k, q;
    if (!h || !tmass__vec3_finite(u)) return TMASS_ERR_ARG;
    if (node < 0 || node >= h->node_count) return TMASS_ERR_NODE_RANGE;
    if (h->fixed[node]) return TMASS_ERR_NODE_PINNED;
    if (h->dyn_of[node] >= 0) return tmass_set_displacement(h->dyn, h->dyn_of[node], u);
    q = h->qs_of[node];
    if (q < 0) return TMASS_ERR_NODE_INACTIVE;
    if (h->qs->col_of_node[q] < 0) return TMASS_ERR_NOT_PRECOMPUTED;
    for (k = 0; k < h->contact_count && h->contact_qs[k] != q; k++) {
    }
    if (k == h->contact_count) {
        if (k == h->max_contacts) return TMASS_ERR_CONTACTS;
        h->contact_qs[k] = q;
        h->contact_count++;
        h->contacts_dirty = 1;
    }
    memcpy(h->contact_u + 3 * k, u, 3 * sizeof(tmass_real));
    return TMASS_OK;
}

TMASSDEF int tmass_hybrid_release_node(tmass_hybrid *h, int node)
{
    int k, q;
    if (!h) return TMASS_ERR_ARG;
    if (node < 0 || node >= h->node_count) return TMASS_ERR_NODE_RANGE;
    if (h->fixed[node]) return TMASS_ERR_NODE_PINNED;
    if (h->dyn_of[node] >= 0) return tmass_release_node(h->dyn, h->dyn_of[node]);
    q = h->qs_of[node];
    for (k = 0; k < h->contact_count; k++)
        if (h->contact_qs[k] == q) {
            int last = h->contact_count - 1;
            h->contact_qs[k] = h->contact_qs[last];
            memcpy(h->contact_u + 3 * k, h->contact_u + 3 * last, 3 * sizeof(tmass_real));
            h->contact_count--;
            h->contacts_dirty = 1;
            break;
        }
    return TMASS_OK;
}

TMASSDEF int tmass_hybrid_contact_force(tmass_hybrid *h, int node, tmass_real f[3])
{
    int k, r;
    if (!h || !f) return TMASS_ERR_ARG;
    if (node < 0 || node >= h->node_count) return TMASS_ERR_NODE_RANGE;
    f[0] = f[1] = f[2] = 0;
    if (h->dyn_of[node] >= 0) {
        int v = h->dyn_of[node];
        if (h->dyn->node_state[v] == TMASS__PINNED) {
            const tmass_real *fi = tmass_forces(h->dyn); /* includes the coupling stiffness */
            for (r = 0; r < 3; r++)
                f[r] = -(fi[3 * v + r] + h->dyn->ext[3 * v + r] + h->dyn->mass[v] * h->dyn->gravity[r]);
        }
        return TMASS_OK;
    }
    for (k = 0; k < h->contact_count; k++)
        if (h->contact_qs[k] == h->qs_of[node])
            for (r = 0; r < 3; r++) f[r] = (tmass_real)h->f_contact[3 * k + r];
    return TMASS_OK;
}

TMASSDEF int tmass_hybrid_remove_tets(tmass_hybrid *h, const int *tets, int count, int *removed)
{
    int i, done = 0, total = 0, err = TMASS_OK;
    if (removed) *removed = 0;
    if (!h || count < 0 || (count > 0 && !tets)) return TMASS_ERR_ARG;
    for (i = 0; i < count; i++) {
        if (tets[i] < 0 || tets[i] >= h->tet_count) return TMASS_ERR_TET_RANGE;
        if (!h->tet_dynamic[tets[i]]) return TMASS_ERR_PRECOMPUTED;
    }
    /* local indices through the dynamic part's tear list, in batches */
    while (done < count && !err) {
        int batch = count - done < h->dyn_tets ? count - done : h->dyn_tets, r = 0;
        for (i = 0; i < batch; i++) h->dyn->tear_list[i] = h->tet_local[tets[done + i]];
        err = tmass_remove_tets(h->dyn, h->dyn->tear_list, batch, &r);
        total += r;
        done += batch;
    }
    tmass__hybrid_drop_connections(h);
    if (removed) *removed = total;
    return err;
}

TMASSDEF int tmass_hybrid_tear(tmass_hybrid *h, const tmass_tear_criteria *c, int *removed)
{
    int err;
    if (!h) return TMASS_ERR_ARG;
    err = tmass_tear(h->dyn, c, removed);
    tmass__hybrid_drop_connections(h);
    return err;
}

TMASSDEF const tmass_real *tmass_hybrid_positions(const tmass_hybrid *h) { return h ? h->pos : NULL; }
TMASSDEF tmass_model *tmass_hybrid_dynamic_part(tmass_hybrid *h) { return h ? h->dyn : NULL; }
TMASSDEF const tmass_qs *tmass_hybrid_precomputed_part(const tmass_hybrid *h) { return h ? h->qs : NULL; }
TMASSDEF int tmass_hybrid_connection_count(const tmass_hybrid *h) { return h ? h->conn_count : 0; }

TMASSDEF const int *tmass_hybrid_boundary_triangles(tmass_hybrid *h, int *count)
{
    int f, n, k;
    if (count) *count = 0;
    if (!h) return NULL;
    /* the precomputed part's own boundary, the interface faces a cut has exposed, and the
       dynamic part's boundary without the faces it shares with the precomputed part */
    memcpy(h->tri, h->qs_tri, sizeof(int) * 3 * (size_t)h->qs_tri_count);
    n = h->qs_tri_count;
    for (f = 0; f < h->iface_count; f++)
        if (!h->dyn->tet_alive[h->iface_dyn_tet[f]]) memcpy(h->tri + 3 * n++, h->iface_tri + 3 * f, 3 * sizeof(int));
    for (f = 0; f < h->dyn->tri_count; f++) {
        if (h->dyn_face_iface[h->dyn->tri_owner[f]]) continue;
        for (k = 0; k < 3; k++) h->tri[3 * n + k] = h->dyn_global[h->dyn->tri[3 * f + k]];
        n++;
    }
    if (count) *count = n;
    return h->tri;
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

