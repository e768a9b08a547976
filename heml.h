/* heml.h - v0.3.0 - hyper-elastic mass links (hyperelastic tetrahedra) - MIT or public domain

   A drop-in soft-body model after Goulette & Chen, "Fast computation of soft tissue
   deformations in real-time simulation with Hyper-Elastic Mass Links" (CMAME 2015): P1
   tetrahedra whose energy is a function of the six squared edge lengths, so the force on
   a node is a sum of scalar tensions times the links (edge vectors) to its neighbours.
   Any isotropic hyperelastic law plugs in (St Venant-Kirchhoff, Neo-Hookean, Mooney-
   Rivlin, a mass-spring network as the degenerate case, or your own law through
   callbacks), flat and inverted tetrahedra stay finite and restoring, and a Prony series
   adds viscosity. Semi-explicit Euler (the paper's scheme, with a divergence check),
   implicit Euler as the Newton minimisation of the incremental potential with the exact
   force differential inside matrix-free conjugate gradient, and a static solve by
   continuation; none reports success with an answer it has not converged.

   DO THIS in exactly one C or C++ file:

       #define HEML_IMPLEMENTATION
       #include "heml.h"

   MINIMAL PROGRAM (a cube of six tetrahedra hanging from its top face; cc app.c -lm)

       #define HEML_IMPLEMENTATION
       #include "heml.h"
       #include <stdio.h>

       int main(void)
       {
           static const heml_real nodes[8 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0,
                                                  0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 1};
           static const int tets[6 * 4] = {0, 1, 3, 7, 0, 5, 1, 7, 0, 3, 2, 7,
                                           0, 2, 6, 7, 0, 4, 5, 7, 0, 6, 4, 7};
           heml_desc d = heml_default_desc();
           heml_model *m;
           int i, err;
           d.rest_positions = nodes;
           d.node_count = 8;
           d.tets = tets;
           d.tet_count = 6;
           d.material = heml_material_from_young(HEML_NEO_HOOKEAN, 1e5, 0.45); // Pa, -
           d.mass_damping = 10; // 1/s
           d.time_step = 1e-3;  // s
           err = heml_create(&d, &m);
           if (err) {
               printf("%s\n", heml_error_string(err));
               return 1;
           }
           for (i = 4; i < 8; i++) heml_fix_node(m, i); // the face z = 1
           for (i = 0; i < 1000; i++) heml_step(m);     // one simulated second
           printf("corner 0 sagged to z = %g m\n", (double)heml_positions(m)[2]);
           heml_destroy(m);
           return 0;
       }

   OVERRIDES (define before including the implementation)

       HEML_REAL       float or double (default double): storage and kernels. Creation
                       computes the rest constants in double. In float builds every
                       public function is renamed (heml_create -> heml_create_f32, ...),
                       so mixing float and double translation units fails at link time,
                       not at run time.
       HEML_MALLOC(size, user) / HEML_FREE(ptr, user)
                       default allocator (malloc/free) when the desc gives none.
       HEML_ASSERT(x)  internal sanity checks (default: assert from <assert.h>).
       HEML_STATIC     make every function static (private to the including file).
       HEML_PARALLEL_MIN_TETS
                       meshes with fewer tetrahedra run serially (default 16384).
       HEML_NO_SIMD    no intrinsics: the portable scalar gather, scatter and square
                       roots even where the target has AVX (results are the same bits).

   STEP BY STEP
       1. heml_desc d = heml_default_desc(); fill the mesh, the material (or a table of
          materials and a material index per tetrahedron), the time step.
       2. heml_create(&d, &m) validates everything and allocates all memory once.
       3. Boundary conditions: heml_fix_node (pinned where it is), heml_set_displacement
          (pinned at rest + u, e.g. driven by a tool), heml_set_displacement_axes (only some
          axes pinned: rollers, symmetry planes), heml_release_node, gravity,
          heml_set_external_force, heml_set_anchors (springs to targets: gluing to another
          model, see ANCHORS).
       4. heml_step(m) (desc integrator and time step) or heml_step_ex(m, dt, integrator);
          heml_solve_static(m) for the equilibrium.
       5. Read heml_positions / heml_velocities to render (heml_displacements for the
          state itself); heml_probe_* at any material point; heml_tet_volume_ratios,
          heml_tet_stresses and heml_energy for diagnostics; heml_modal_* for natural
          frequencies and mode shapes.
       6. heml_destroy(m).

   HOW TO EXTEND (where a new law, integrator or linear solver goes; each kind is one enum
   value, one row of one private table, and the functions that row names)
       A constitutive law: a heml_law value before HEML_LAW_COUNT (validation uses the
           count) and its row of heml__laws (>>laws-table; a static assert refuses a table
           that does not have one row per law): `name`; `kind` (HEML__K_INVARIANTS for a
           law w(I1, I2, J)); `stress`, `energy`, `differential`: functions of the form of
           heml__law_svk that fill, for a block of tetrahedra (heml__blk), w_1, w_2, w_J and
           s0 = 2 w_1 + 4 w_2 + w_J formed without cancellation at rest, plus w (energy) and
           the six second derivatives h (differential), continued below J0 (FLAT AND
           INVERTED TETRAHEDRA); `make` (its constants into heml__mat) and `check` (their
           ranges, HEML_ERR_MATERIAL); heml_material_from_young's case. Leave `fast_path`
           at 0: the vectorised kernels (heml__forces_nh, heml__diff_nh) compute
           Neo-Hookean and nothing else; set it only for a law that is exactly heml__law_raw
           without an I2 term, or write a kernel for the law and a flag for it (as the St
           Venant-Kirchhoff and split Mooney-Rivlin differentials, heml__diff_svk and
           heml__diff_mr: heml__mat.dk, chosen in heml__make_mat, their point values in the
           stiffness cache, HEML__DK_ROWS). Everything
           else (the general path's kinematics, stress coefficients, P1 forces and their
           differential, Prony, energies, stresses, the small-strain moduli for the
           preconditioner and heml_stable_time_step) comes from those functions.
       An integrator: a heml_integrator value before HEML_INTEGRATOR_COUNT and its row of
           heml__integrators (>>integrators-table): `name`, `step` (start state -> candidate,
           no change of the model's state: heml_step_ex commits it or keeps the state),
           `is_explicit` (needs no force differential), `uses_history` (heml_step_ex keeps
           the step's start as the history hist_u, hist_v, hist_dt that the next step reads,
           and heml__history_reset invalidates it: HEML_BDF2). An implicit scheme whose step
           is a minimisation reuses heml__incremental (h, ubar, vbar) as implicit Euler and
           BDF2 do. Its scratch vectors are named
           fields of heml_model, carved in heml__layout_scratch (where any sharing with
           another role is written down).
       A linear solver (or a preconditioner: heml__precond is the one place): a
           heml_linear_solver value before HEML_LINEAR_SOLVER_COUNT and its row of
           heml__linear_solvers (>>linear-solvers): `solve` and `solve_indefinite`, with the
           return codes listed there (HEML_OK, HEML_ERR_NO_CONVERGENCE, HEML_ERR_NOT_FINITE,
           the private negative-curvature signal). Every solve goes through
           heml__linear_solve; no solver calls heml__cg directly.
       The tests it must add (tests/test_heml*.c): a law: forces = -gradient of its energy
           and differential = derivative of the force by finite differences, at moderate
           strain and below J0, through the model (the all-law loops of test_heml.c:
           all_laws, test_law_table_forces_and_differentials), against an energy written
           independently from F (fem_energy_forces), zero force at rest and under rigid
           motions, and its closed form where there is one (uniaxial stretch: R4 for St
           Venant-Kirchhoff, R5 for Neo-Hookean, of /work/shared/REFERENCES.md, in
           test_uniaxial_closed_forms; Mooney-Rivlin has none there yet); an integrator: its order of accuracy on the linear oscillator
           (test_integrator_order), a failed step keeping the state, no allocation, and
           bit-identical results across thread counts (test_threads_bit_identical); a
           linear solver: the static and implicit tests unchanged, the same return codes
           (NO_CONVERGENCE at the cap, NOT_FINITE), determinism across threads.
       What the bench must show (make bench, bench/model_heml.c): a law: its force and
           differential ns per tetrahedron in kernels.csv next to Neo-Hookean's, and its
           R1/R2/R4/R5 rows; an integrator or solver: the R2/R3 rows (error and time) and
           the stability sweep; a change to an existing path: no row slower (callgrind
           instruction counts where the machine is noisy) and every result bit-identical.

   UNITS: SI throughout. Positions m, moduli Pa, density kg/m^3, time s, forces N,
   mass_damping 1/s, gravity m/s^2 (default 9.81 along -z), Prony tau s.

   MEMORY: heml_create makes one allocation (one block; every array in it 64-byte aligned)
   through the desc's allocator (or HEML_MALLOC), plus a temporary one it frees before
   returning. A custom allocator must honour the alignment it is asked for (64).
   heml_probe_create and heml_modal_create make one allocation each (through the model's
   allocator), freed by their destroy functions. Nothing else allocates: steps, forces,
   stiffness products, solves and diagnostics reuse that block. The description's arrays (and the materials' Prony arrays) are read during
   heml_create only. Pointers returned by heml_positions and friends point into the model
   and stay valid until heml_destroy. Meshes of 96 nodes or more also hold the static
   solve's coarse space: a dense matrix of (6 A)^2 doubles for A aggregates (A = nodes /
   24, at most 64: up to 1.2 MB), and for the implicit steps' coarse correction two more
   (the unfactored P^T K0 P and the step's factor: up to 2.4 MB more; none with
   desc.implicit_coarse = -1). desc.nodal_pressure = 2 with at most HEML_PAGG_PC_MAX
   (1024) pressure aggregates also holds the static solve's pressure-aggregate
   preconditioner (PRESSURE AGGREGATES): per node w slots of an int and 3 doubles (w the
   most aggregates around a node: 8 or 9 in 3D meshes, 28 w bytes a node) and 3 reals,
   and for P pressure aggregates P^2 + 6 P A + P doubles (P = 466, A = 64: 3.2 MB; P =
   1024: 11.5 MB); allocated whether or not the materials' moduli turn it on. The
   stiffness cache (desc.stiffness_cache = 1, the
   default; PERFORMANCE) holds 17 reals per tetrahedron slot (136 bytes in double, 68 in
   float: the model's largest array, against 80 / 40 of rest constants) when a material in
   use takes the vectorised Neo-Hookean kernels (Neo-Hookean, its incompressible variant,
   incompressible Mooney-Rivlin with c2 = 0), 21 (168 / 84 bytes) when one is St Venant-
   Kirchhoff, 26 (208 / 104 bytes) when one is the split Mooney-Rivlin (the largest of
   those in use), plus a byte per block of 16; only without a Prony series and without
   nodal pressure; none otherwise (springs, user laws); desc.stiffness_cache = 0 leaves it
   out (each product then recomputes them: see PERFORMANCE for the cost). Float builds
   compiled for AVX hold the Neo-Hookean force pass's node forces padded to 4 components as
   well (16 bytes a node; PERFORMANCE, issue 21). Mass-spring
   materials hold nothing per tetrahedron beyond the rest constants (their rest lengths
   and stiffnesses are derived from them in each pass; before issue 21's change they held
   12 reals a slot more).

   ERRORS: every fallible function returns 0 or a negative HEML_ERR_* code;
   heml_error_string names it, and the optional desc.log callback receives a detailed
   message for validation failures (the library never prints; a description not made by
   heml_default_desc is refused with HEML_ERR_DESC before its log callback, which is
   garbage too, is touched). Every step and solve that fails leaves positions, velocities
   and the viscous state exactly as they were, so the caller may retry (smaller time step,
   the implicit integrator, a looser tolerance, more iterations). No solver reports success
   with an answer it has not converged, and an unconverged linear solve never passes:
       HEML_ERR_NOT_FINITE      a non-finite value anywhere, including a load or residual
                                whose squared norm overflows (a 1e162 N force: |b|^2 = inf
                                would have made every tolerance pass).
       HEML_ERR_NO_CONVERGENCE  a Newton solve (static, HEML_IMPLICIT_EULER) did not reach
                                its tolerance within its caps, the static continuation ran
                                out of increments, or the linearised step's CG hit
                                cg_max_iterations; stats.residual / stats.cg_residual say
                                how far it got.
       HEML_ERR_ROUND_OFF       a Newton solve stalled at the round-off level of its
                                forces above its tolerance (loosen it or use double).
       HEML_ERR_INVERTED        the answer of a static solve or implicit step has more
                                inverted tetrahedra (J <= 0) than its start, and
                                allow_inversion is 0 (also: a Cauchy stress asked of an
                                inverted tetrahedron).
       HEML_ERR_UNSTABLE        a static solve converged to a saddle, an unstable
                                equilibrium (see STATIC SOLVE: a buckled or squashed body
                                held at its symmetric state); set leave_saddles = 1 for a
                                minimum.
       HEML_ERR_DIVERGED        a semi-explicit step failed its divergence check (see
                                INTEGRATORS): the time step is beyond the stability limit
                                of the current state.
       HEML_ERR_PRECISION       eps(heml_real) max|u| > precision_limit h_min (h_min the
                                shortest rest edge, precision_limit default 1e-4): the
                                rounding of the displacements would fake strains above
                                0.01 %. Checked on the state before every step and solve
                                and on a static solve's answer. Only the displacement
                                counts (the state is u = x - X, and the rest constants come
                                from double), so a body created far from the origin is
                                fine; one moved 1e6 m in float is not (its rounding is
                                0.06 m). Create the body near where it works, use
                                double, or set precision_limit = 0 to accept the
                                rounding.
   Inside Newton, a Krylov solve that stops at its cap still gives a search direction;
   only the nonlinear residual decides success.

   THREADING AND DETERMINISM: no global state; one model may be used by one thread at a
   time, different models by different threads. Loops run in parallel through desc.
   parallel_for (an engine's job system) when given, through OpenMP when compiled with
   -fopenmp, serially otherwise; meshes under HEML_PARALLEL_MIN_TETS tetrahedra run
   serially. Tetrahedra are cut into fixed chunks of up to 256 (16 blocks of 16) and the
   chunks, in mesh order, into groups of up to 16 consecutive chunks (fewer per group on
   small meshes, so that there are at least 64 groups), none of which depends on the
   thread count; groups are coloured so that no two groups of a colour share a node,
   colours run in a fixed order, a group is run by one thread chunk after chunk and each
   chunk adds into the node forces in a fixed order, so every node receives its
   contributions in the same order whatever the threads (element colouring, no
   per-element buffer, no atomics). A group sweeps a compact piece of the mesh, so its
   nodes stay in cache. Reductions (energy, CG
   dot products) add fixed block partial sums in a fixed order. Results are bit-identical
   for any number of threads. The colouring was chosen over a two-pass gather by
   measurement (see PERFORMANCE).

   THE MODEL (Goulette & Chen equation numbers; our derivations where the printed ones
   differ or where we use a cheaper equivalent form)
       Tetrahedron (x0, x1, x2, x3) and its six links (sec. 3.1):
           v1 = x1 - x0, v2 = x2 - x0, v3 = x3 - x0, v4 = x2 - x1, v5 = x3 - x2, v6 = x1 - x3
       and v = (v1 v2 v3), V the same at rest. Squared lengths l_e = |v_e|^2.
       Appendix A: C = V^-T D V^-1 with D = v^T v the Gram matrix of the links, linear in l
       (eq. A.4), so C = sum_e l_e C_e, C_e = V^-T D_e V^-1. We precompute per tetrahedron
           G = V^-1 V^-T (symmetric; G_jk = grad N_j . grad N_k), Vol = det V / 6, 1/det V
       (8 numbers) instead of the six C_e, vtr and the 6x6 Mtr: the paper's quantities
       follow from G (vtr_e = tr C_e = G : D_e, Mtr_ef = tr(G D_e G D_f)), and
           I1 = tr C = G : D,    I2 = (I1^2 - tr (G D G D)) / 2,    J = det v / det V.
       Appendix B-C, eqs. 12-13 and 29: W = Vol w(I1, I2, J) and dW/dl_e = (Sigma / 2) : D_e
       with the symmetric "edge-space stress"
           Sigma = 2 Vol [ (w_1 + I1 w_2) G - w_2 G D G ] + (J-part below),
       which is V^-1 S V^-T Vol for the second Piola-Kirchhoff stress S. The chain rule
       through the links (DLM_i of eq. B.2) collapses to a 3x3 product: the force on node
       k = 1..3 and on node 0 is
           f_k = -( sum_j Sigma_jk v_j + gamma c_k ),   f_0 = -(f_1 + f_2 + f_3),
       c_1 = v2 x v3, c_2 = v3 x v1, c_3 = v1 x v2 (6 dVol/dx, eq. C.4) and gamma = w_J / 6
       (the volumetric term of eq. 30: Vol w_J dJ/dx = w_J / 6 c). So the links carry the
       tensions, as the paper says. This is the classical P1 force f_k = -Vol P grad N_k
       (P = F S the first Piola-Kirchhoff stress, F = v V^-1; REFERENCES R7, a test checks
       it to round-off). Table 3's printed Saint Venant-Kirchhoff force lacks the factor 2
       of d(l^T MW l)/dl; the derivation above, the finite-difference tests and the FEM
       test decide.
       How it is evaluated (our form, for precision): the state is the displacement
       u = x - X, and a tetrahedron at rest must give exactly zero force, small strains
       their full relative precision. Written on the links, Sigma V and gamma C (the rest
       links and cofactors) are each of the size of the moduli and cancel at rest, so the
       force would carry an absolute round-off of eps (lambda + 2 mu) Vol |grad N| whatever
       the strain (in float, 1e-7 of the moduli: the strains of stiff bodies under gravity).
       So we store per tetrahedron the rest gradients grad N_1..3 (the rows of V^-1) and
       Vol (10 numbers, from double), form the displacement gradient H = F - I = du V^-1
       from the link displacements du_j = u_j - u_0, and every quantity that vanishes at
       rest as a polynomial in H without a constant term:
           J - 1 = tr H + tr cof H + det H,       cof F - I = K = tr H I - H^T + cof H,
           C - I = H + H^T + H^T H,               I1 - 3 = tr (C - I),
           I2 - 3 = 2 (I1 - 3) + ((I1 - 3)^2 - tr (C - I)^2) / 2.
       (C - I is the change of the squared link lengths in the rest frame:
       l_e - L_e = V_e . (C - I) V_e = 2 V_e . du_e + |du_e|^2.) Then, with
       P = 2 w_1 F + 2 w_2 (I1 F - F C) + w_J cof F regrouped,
           P = c0 I + 2 a H + w_J K - F M,   a = w_1 + (I1 - 1) w_2,  M = 2 w_2 (C - I),
           c0 = 2 a + w_J = s0 + 2 w_2 (I1 - 3),   s0 = 2 w_1 + 4 w_2 + w_J,
       and each law forms s0 (zero at rest, the stress-free condition) from J - 1 and the
       invariants' offsets directly (ln J by log1p, e.g. Neo-Hookean s0 = (lambda ln J +
       mu (J - 1)) / J), so the only term that survives at rest in exact arithmetic is
       absent in floating point too. It is f_k = -(sum_j Sigma_jk v_j + gamma c_k)
       regrouped (S = 2 a I - M + w_J J C^-1), the same energy and the same forces.
       Laws (heml_law):
         HEML_STVK  w = lambda/2 (tr E)^2 + mu tr E^2 = lambda/8 (I1-3)^2
                        + mu/4 (I1^2 - 2 I1 - 2 I2 + 3) (table 3). It has no J term, so an
                        inverted tetrahedron would settle in its mirror image; below J0 we
                        add (lambda + 2 mu)/2 (J0 - J)^2 (zero above J0, our addition).
         HEML_NEO_HOOKEAN  compressible, eq. 26 with C1 = mu/2 (the only choice that is
                        stress-free at rest): w = mu/2 (I1 - 3) - mu ln J + lambda/2 ln^2 J.
         HEML_MOONEY_RIVLIN  compressible, isochoric/volumetric split (eqs. 21-25):
                        w = c1 (I1 J^-2/3 - 3) + c2 (I2 J^-4/3 - 3) + kappa/2 (J - 1)^2.
         HEML_NEO_HOOKEAN_INCOMPRESSIBLE, HEML_MOONEY_RIVLIN_INCOMPRESSIBLE  table 3:
                        w = c1 (I1 - 3) + c2 (I2 - 3) (c2 = 0 for Neo-Hookean) on J = 1.
                        Table 3 alone has no volumetric stiffness (a free body would shrink
                        to a point); incompressibility is enforced by the penalty
                        U = -(2 c1 + 4 c2) ln J + kappa/2 ln^2 J, which vanishes on J = 1
                        (so w is table 3 on every incompressible motion) and makes the rest
                        state stress-free. The Neo-Hookean one therefore equals eq. 26 with
                        mu = 2 c1, lambda = kappa: eq. 26 is table 3 plus a penalty.
         HEML_MASS_SPRING  sec. 5.3: W = sum over the six links of k/2 (l - L)^2
                        (eq. 38) with k = E Vol / L^2 per tetrahedron (the volume-weighted
                        rule of tensormass.h); forces are eq. 41, the classical springs.
         HEML_USER      any isotropic w(I1, I2, J) through callbacks (heml_user_law).
       Small-strain moduli for all laws follow from the derivatives at rest:
       mu = -2 w_2 - w_J, lambda = 4 w_2 + w_J + 4 w_11 + 16 w_12 + 16 w_22 + 4 w_1J
       + 8 w_2J + w_JJ (at I1 = I2 = 3, J = 1); heml_material_from_young inverts them.
   FLAT AND INVERTED TETRAHEDRA (sec. 4.4): below the threshold J0 (desc.
       inversion_threshold, default 0.4) every law is continued by its second-order Taylor
       polynomial in J at J0 (I1 and I2 held): the volumetric stress w_J becomes its
       tangent at J0, exactly the paper's rule for eq. 26, and for the split Mooney-Rivlin
       the factors J^-2/3 and J^-4/3 become quadratics too (our extension: they would
       otherwise blow up at J = 0). Energy, force and force differential stay finite and
       consistent through J = 0 and for J < 0, and the volumetric force keeps pushing J
       back up. (The paper's printed tangent, P11 = ((lambda - lambda log J0 - mu) J
       + ...) / (6 J0^2), has the sign of mu wrong; the derivative of (lambda ln J - mu)/J
       is (lambda (1 - ln J) + mu)/J^2.) Mass-spring networks cannot see an inversion (a
       mirrored tetrahedron has the same links) and are not inversion-safe.
   VISCOSITY (sec. 3.5, eqs. 14-20): a material's Prony series alpha(t) = 1 - sum_i alpha_i
       (1 - exp(-t / tau_i)) relaxes its stress: with gamma_i^n = A_i f^n + B_i gamma_i^(n-1),
       A_i = dt alpha_i / (dt + tau_i), B_i = tau_i / (dt + tau_i) (eq. 20), applied per
       tetrahedron to the stress coefficients a, w_J, M (the second Piola-Kirchhoff stress
       S = 2 a I - M + w_J J C^-1, i.e. Sigma and gamma) and c0 = 2 a + w_J (filtered on its
       own so that it keeps its precision at rest); for springs, to the six link tensions;
       rather than to the node forces: the same recursion under a held deformation (where
       the force is linear in them), and frame-indifferent under large rotations, which
       forces are not. The state (9 numbers per tetrahedron and term) advances once per
       successful step.
       heml_compute_forces uses the description's time step; heml_solve_static uses the
       limit dt -> infinity (A_i = alpha_i, B_i = 0: the fully relaxed equilibrium) and
       leaves the state relaxed there.

   NEAR-INCOMPRESSIBLE BODIES (desc.nodal_pressure = 1; off by default, and then every
       result is bit-identical to 0.3.0): average nodal pressure tetrahedra (Bonet and
       Burton 1998's ANP element, the volumetric part moved from the tetrahedra to the
       nodes), for every law but mass-spring, user laws included. P1 tetrahedra lock near
       nu = 0.5 because every tetrahedron must keep its own volume (one constraint per
       tetrahedron, about 5 per node against 3 degrees of freedom per node); here the
       volume is constrained per node (one per node). Our formulation, in energy form so
       that forces and differential follow exactly:
           W = sum_e Vol_e (w(F_e) - U(J_e)) + sum_a sum_mat W_a,mat U_mat(J_a),
       U(J) = w(J^(1/3) I) the law's energy on a pure dilation (I1 = 3 J^(2/3), I2 =
       3 J^(4/3)), continued below J0 by its quadratic Taylor polynomial (J^(2/3) has no
       second derivative at 0); W_a,mat = sum Vol_e / 4 over node a's tetrahedra of that
       material, V_a = sum_mat W_a,mat, and the nodal volume ratio J_a = sum_e Vol_e J_e /
       (4 V_a) (current over rest nodal volume). So each tetrahedron keeps its law minus
       the law's own dilation energy, w - U, which has no bulk stiffness at small strain
       (Neo-Hookean: w - U = mu/2 (I1 - 3 J^(2/3)), the isochoric part exactly; split
       Mooney-Rivlin: U = kappa/2 (J - 1)^2, its volumetric term exactly; St Venant-
       Kirchhoff: w - U is O(strain^3)), and the nodes carry the volumetric energy. A
       homogeneous deformation gives every J_a = J_e = J, the two U terms cancel, and the
       stress is the law's P(F) (the patch test) for any law; rigid motions give J = 1 and
       zero force. Our choice where the papers offer several: U from the law itself (no
       separate volumetric law to specify, user laws work unchanged) rather than Bonet and
       Burton's assumed split, and the nodal energy weighted per material (a node on a
       material interface carries each material's U on its own volume share).
       Forces: dW/dx = sum_e Vol_e (dw - U'(J_e) dJ_e) + sum_a V_a P_a dJ_a with the nodal
       pressure P_a = sum_mat W_a,mat U'_mat(J_a) / V_a and dJ_a = sum_e Vol_e dJ_e / (4 V_a),
       so regrouped per tetrahedron:
           w_J  ->  w_J - U'(J_e) + p_e,   p_e = (P_a + P_b + P_c + P_d) / 4
       (and s0 the same), its four nodes' mean pressure: the P1 force kernel unchanged.
       Differential: dp_e = sum_{a in e} dP_a / 4, dP_a = (sum_mat W_a,mat U''_mat(J_a) /
       V_a) dJ_a, so in the element's differential w_JJ -> w_JJ - U''(J_e) and dw_J gains
       dp_e: the exact tangent, which couples a node to its neighbours' neighbours
       (through J_a), matrix-free. Each pass (force, energy, differential, stresses) is
       three: the tetrahedra scatter Vol (J - 1) / 4 (the differential also Vol dJ / 4 =
       Vol cof F : dH / 4) into two scalars per node (coloured as the force pass); a node
       pass (chunks of 1024 nodes) evaluates U', U'' (and U) at J_a in blocks of 16
       through the law's own row of heml__laws (one evaluation per material present); the
       usual pass then gathers the four P_a (and dP_a) and evaluates the element's U at
       J_e besides the law. U', U'' are formed from the law's s0 and second derivatives at
       the dilation point: U' = s0 - 2 w_1 (s - 1) / s + 4 w_2 (s - 1), s = J^(1/3), s - 1 =
       (J - 1) / (s^2 + s + 1), without cancellation at rest. The force of a law with the
       fast-path flag (heml__mat.fast_nodal: Neo-Hookean, its incompressible form,
       incompressible Mooney-Rivlin with c2 = 0; no Prony) runs the vectorised Neo-Hookean
       kernel with w_J - U'(J_e) = -2 c1 J^(-1/3) in closed form and the nodes' mean
       pressure gathered into it (heml__nh_nodal_s0), on the H its sums pass kept
       (heml__nodal_sums_keep, heml__forces_nh_kept: "Cost" below), and its node pass U',
       U'' in closed form (heml__dilation_nh); its energy and differential, and every other law, the
       general path. Prony: the nodal pressure enters w_J
       before the filter, so it relaxes with the rest of the stress. Inversion: the
       continued U is restoring below J0 at the nodes; a single tetrahedron's own
       resistance to inversion is that of w - U (about mu), the neighbours' nodes carry
       the bulk part. Memory: 9 reals per node (3 of them the deviatoric diagonal of the
       probe below) plus one per node and material.
       Measured (tests/test_heml_solve.c, Cook's membrane R10, nu = 0.4999, corner u_y in
       mm at N x N x 1 cells, N = 4, 8, 16, 32; converged about 6.9):
           six tetrahedra per cell   plain 2.15 2.17 2.22 2.38   nodal 2.65 4.38 5.99 6.61
           five tetrahedra per cell  plain 2.26 3.19 5.20 6.33   nodal 2.46 4.23 6.13 6.68
       so the two splits, 35 % and 8 % apart at N = 32 without it, agree within 1 % with
       it and converge (as O(h)) towards the published value. What it does not fix
       (LIMITS): the static solve's Krylov iterations grow with the bulk-to-shear ratio
       (nodal_pressure = 2 has a preconditioner that removes that growth: PRESSURE
       AGGREGATES, "Krylov iterations").
       Measured (Zen 5, 2 vCPUs, loaded; gcc -O2 -march=native, double; heml_solve_static,
       Krylov iterations in total (Newton iterations), for nu = 0.3, 0.49, 0.499, 0.4999 at
       mu fixed, the bulk modulus from nu; Cook six tetrahedra per cell; the beam 1 x 0.1 x
       0.1, 40 x 4 x 4 cells of five, clamped, tip load, linear range):
           Cook N = 8     490 (4)    745 (5)   2,243 (9)    5,738 (11)
           Cook N = 16    449 (5)  1,480 (9)   3,434 (10)  13,446 (13)
           beam 40x4x4    111 (2)    455 (3)     933 (3)    2,223 (3)
       (bench/heml_nodal_krylov.c. Before the K_dev probe below, on the code before issue
       21's coarse changes, at nu = 0.49, 0.499, 0.4999: Cook N = 8 814, 2,701, 7,262,
       N = 16 1,658, 4,350, 20,692 (16), the beam 458, 1,357, 3,653; with it, on that code,
       743, 2,256, 5,729, 1,484, 3,430, 17,103 (16), 455, 933, 2,228: the round-off of the
       coarse correction moves Newton's path at 0.4999, by up to a fifth of the count. The
       answers the same to every printed digit; time at 0.4999, best of 2 or 3 interleaved
       runs: Cook N = 8 0.76 -> 0.64 s, the beam 3.9 -> 2.3 s), so still 12 to 30 times the
       nu = 0.3 count at 0.4999. The probe on K_dev: the saddle
       probe (heml__saddle_escape) solves K x = b to 1e-10 after Newton converged, and with
       the nodal pressure K = K_dev + s G^T Dn G (K_dev the tangent with the nodal dP_a held
       at 0, G du = (sum Vol dJ / 4)_a, Dn = diag(d_a), d_a = sum_mat W U''_mat(J_a) / V_a^2,
       s the Prony factor): where every d_a >= 0 and all materials share s, K >= K_dev, so
       when CG meets no negative curvature on K_dev (preconditioned by the deviatoric
       small-strain diagonal and a coarse space built from the deviatoric small-strain
       stiffness, lambda -> -2 mu / 3) there is none on K either; otherwise the full probe
       runs as before. Its conditioning is that of mu: 169 iterations on Cook N = 8 at
       every nu, against 155 (nu = 0.3) to 1,706 (0.4999) for the full probe (3,744 on
       Cook N = 16 at 0.4999); dearer than the full probe at small bulk-to-shear ratios, so it runs
       only where every material's kappa >= 20 mu (nu >= 0.476). Tested: K_dev against
       closed forms at rest (a dilation gives 0, an isochoric shear gives K v), symmetric
       and below K at a deformed state, the same Cook answer bit for bit, a compressed
       column's saddle still caught (in double; in float the static solve accepts that
       saddle with or without the shortcut). Tried, and not kept (git history of branch i-anp, commit 84d59f2, reverted): the textbook
       kappa-robust route, the equivalent saddle-point system [D + c K_dev, G^T E; E G,
       -Sigma] (K_dev the element pass with dP_a = 0, G du = sum Vol dJ / 4, E =
       sqrt(c s |d_a|), d_a = sum W U'' / V_a^2: eliminating the pressure gives exactly
       today's operator; the answers agreed to every printed digit) by MINRES with the
       block-diagonal preconditioner diag(deviatoric Jacobi + deviatoric coarse space,
       1 / (1 + s |d_a| V_a / (beta mu_a))): Cook N = 8: 798, 1,626, 5,076, 35,055
       iterations; with a grad-div share alpha mu / V_a of d_a kept in the displacement
       block (alpha = 20, beta = 3, the best of alpha 0..20, beta 0.1..10) 513, 1,077, 3,345,
       7,152, and on Cook N = 16 130,685 at nu = 0.4999. The reason: this pair (P1
       displacements, nodal pressures) is not inf-sup stable (the same cause as the
       pressure's checkerboard below), so the Schur complement C + G K_dev^-1 G^T falls to
       C = V / kappa on nearly spurious pressure modes, which no diagonal pressure
       preconditioner sees; kappa-robustness needs a Schur approximation with G's own
       sparsity (C + G diag(K_dev)^-1 G^T, applied by an inner solve) or a stabilised
       formulation (which changes the answers): not done. Also tried: the coarse space built with a
       smaller lambda (the deviatoric -2 mu / 3, mu, 10 mu, 100 mu): 30,638, 27,246,
       22,080, 14,574 against 7,262 on Cook N = 8 at 0.4999 (the coarse space must carry
       the bulk stiffness); earlier, scaling the Jacobi diagonal's bulk share by 0.2 or
       0.02: no gain.
       The nodal pressure field also oscillates between neighbouring nodes
       near incompressibility (its largest jump between neighbours is 0.8 to 1.0 of its
       range on Cook's membrane at nu = 0.4999, 0.15 to 0.2 at nu = 0.3): a checkerboard, as
       linear displacements with nodal pressures are not an inf-sup stable pair. One pass of
       smoothing (element means p_e spread back to the nodes) is not enough (a neighbour
       indicator of 0.5 to 1.15 against a smooth field's 0.04 to 0.4); three passes give a
       smooth field that both tetrahedral splits agree on (tests/test_heml_solve.c
       test_nodal_pressure_cook): read pressures smoothed three times, never node by node.
       desc.nodal_pressure = 2 removes it (PRESSURE AGGREGATES below). The bench's Poisson beam
       (1 x 0.1 x 0.1 m, 30 x 3 x 3 cells of five tetrahedra, tip against Timoshenko): 14.4,
       18.9, 22.5, 25.9 % off at nu = 0.3, 0.45, 0.49, 0.499 (plain 18.5, 22.4, 26.6,
       30.2 %); of six tetrahedra per cell at nu = 0.499 the tip is 0.0071 m instead of
       plain P1's 0.0004 m. The growth with nu that remains halves with h: P1 bending
       error, not locking (the same beam, 10 N x N x N cells of five tetrahedra, fully
       clamped, tip load, against Timoshenko: N = 3, 6, 9 cells across -14.2, -4.6, -2.5 %
       at nu = 0.3, -21.1, -8.0, -4.9 % at 0.49, -23.8, -9.5, -5.9 % at 0.499: the gap to
       nu = 0.3 is 9.6, 4.9, 3.4 points at 0.499, O(h), and the O(h) extrapolations from
       N = 6 and 9 agree within half a point, +1.7, +1.3, +1.3 %). So the issue's 2-point
       target on the bench's beam (3 cells across: 8.1 points at 0.49, 11.5 at 0.499) is
       not met, and would be from about 15 cells across.
       Cost (callgrind --dump-instr=no, gcc 12 -O3 -mavx2 -mfma (GNU C, so -ffp-contract=
       fast), a 12 x 12 x 3 box of six: 2,592 tetrahedra, 676 nodes, Neo-Hookean, 100
       heml_compute_forces or heml_apply_stiffness less the creation; instructions per
       tetrahedron and pass): force 225 against 160 for the plain force in double (1.41
       times; nodal_pressure = 2: 217, 1.36), 177 and 173 against 123 in float (1.44, 1.41);
       with -std=c99 (no contraction) 243 and 234 against 176 in double (1.38, 1.33), 185
       and 181 against 131 in float (1.41, 1.38). Before this (git f754a39: H formed again in
       the element pass from a second gather): 256 and 249 against 159 (1.62, 1.57), float
       201 and 197 against 123 (1.63, 1.60). Where the force's go now (double): the sums
       pass (heml__nodal_tets, coloured as the force pass) 24 for the gather + 28 for H and
       J - 1, H stored per slot (heml__nodal_sums_keep) + 20 for the scalar scatter to the
       four nodes; the node pass 14; the element pass (heml__forces_nh_kept) 72, as the
       plain kernel's 72 but without a gather (it reads the kept H; the cube root and the
       gather of the four pressures, heml__nh_nodal_s0, 26, in place of the logarithm),
       + the scatter 47 as the plain force's. What bounds it above 1.3 (207 in double): the
       sums pass, 72 instructions, 0.45 of the plain force alone: the nodal pressure needs
       every tetrahedron's J before any element's force, so the displacements are
       gathered, H formed and J - 1 scattered in a pass of their own; keeping H saves the
       second gather and H, not that pass. The differential (its sums pass the same but
       for the prefetch): 588 (590 before) against the plain cached product's 134 (579,
       581 before, for nodal_pressure = 2).
       Timed (Intel Xeon, Sapphire Rapids class, KVM, 2 vCPUs at load 7 to 9; gcc 12 -O3
       -march=native -ffp-contract=fast, a 6 x 6 x 6 box of six: 1,296 tetrahedra, one
       thread, min over 12 interleaved runs of 20 rounds of 100 forces, against git
       f754a39): double 14.95 ns per tetrahedron against the plain 9.92 (1.51 times;
       nodal_pressure = 2: 13.87, 1.40), before 16.75 and 15.61 against 9.88 (1.69, 1.58);
       float 11.04 and 10.44 against 7.52 (1.47, 1.39), before 12.26 and 11.64 against 7.47
       (1.64, 1.56). Beyond the caches (24,576 and 105,456 tetrahedra, min of 5 interleaved
       runs, noisy at this load) no loss measured from the kept H (72 bytes per tetrahedron
       written and read again): 19.0 and 38.8 ns against 18.7 and 46.6 before. The bench's
       rows (build/bench/bench --quick --parts kernels --filter heml/neo-hookean --repeats
       5, 21 runs of each build interleaved, same machine at load 6 to 10) spread 2 to 5
       times between runs (medians of time slices): their minima, 15.6 ns for nodal-p
       double against 11.4 plain, 14.4 nodal-agg, are no measure of the ratio at that
       load; the timing above is. The results
       are those of the code before bit for bit (forces, differential, energy and nodal
       pressures of a two-material Neo-Hookean and Mooney-Rivlin body, both splits,
       nodal_pressure 1 and 2, double and float; tests/test_heml.c
       test_nodal_pressure_kept_h checks the nodal J against a plain computation and the
       kept path against the gathered one). Memory: with a fast_nodal law in use, 9 reals
       per tetrahedron slot more (the kept H). Before the fast path (the general path:
       heml__kinematics, the law, heml__dilation's Halley root and the law again at every element, heml__pk1_forces;
       the sums in a loop with a branch that did not vectorise): force 500 (476),
       differential 730 (705). Tried and dropped here: the sums pass without its
       coloured read-modify-write scatter, each tetrahedron's term stored (plain stores) at
       precomputed places of a node-major table (rows per 16 nodes, padded with zeros,
       each node's terms in the coloured pass's order: the same sums bit for bit, any
       order of the tetrahedra) and the rows summed by a vectorised loop: no faster (15.6
       against 15.1 ns per tetrahedron with H kept, the stores costing what the scatter
       did) for 4 ints and about 11 reals per tetrahedron more; summing per node over a
       list of slots instead (CSR order, scalar loads): 1.8 ns per tetrahedron for those
       sums alone, slower than the scatter (gcc 12 generates no gathers for it here).
       Tried and reverted (branch anpcost, commit 9d4b379): the differential on the Neo-Hookean
       product with the stiffness cache (w_J as the force's, w_JJ = (2/3) c1 J^(-4/3), dp_e
       / 6 times the cofactor links): exact (against the general path 1.5e-15 in double,
       1.6e-6 in float; the finite-difference tests pass; cached and uncached bit for bit),
       590 -> 306 instructions, 48.4 -> 21.9 ns on the timing above; but in float
       tests/test_heml_solve.c test_nodal_pressure_squash_release (nodal_pressure = 2,
       implicit steps from J = -0.2) then fails its first step (HEML_ERR_NO_CONVERGENCE,
       every Newton iteration meeting negative curvature). That step sits at a round-off
       edge: on a 2 x 2 x 2 tetmesh_box cube of five tetrahedra this code, the code before
       this fast path (git f3bae68) and the general path (the same law with a zero Prony
       term) fail it in float too, the last in double as well; the Newton solve from that
       state, not the product, needs the work.

   PRESSURE AGGREGATES (desc.nodal_pressure = 2; issue 13's stabilised pressure): the
       energy of NEAR-INCOMPRESSIBLE BODIES with the volume held per aggregate of nodes
       instead of per node,
           W = sum_e Vol_e (w(F_e) - U(J_e)) + sum_A sum_mat W_A,mat U_mat(J_A),
       W_A,mat = sum_{a in A} W_a,mat, V_A = sum_{a in A} V_a, J_A = sum_{a in A} V_a J_a / V_A
       (current over rest volume of the tetrahedra's shares around the aggregate's nodes).
       The aggregates come from the mesh alone, at create, greedy in node order
       (heml__pressure_aggregates): a node whose neighbours are all unassigned seeds an
       aggregate of itself and them (its star), then every node left joins the aggregate of
       a neighbour a seed took; one aggregate per 8 to 27 nodes (Cook's membrane below at
       N = 8: 162 nodes, 9 aggregates with six tetrahedra a cell, 14 with five; a box of
       20^3 cells: 9,261 nodes, 343 with six, whose stars are 3 x 3 x 3 blocks of nodes, 672
       with five; a 3 x 3 x 3-cell box 64 nodes, 8). Why: the checkerboard of
       nodal_pressure = 1 is the inf-sup defect of P1 displacements against one volume
       constraint per node (nearly spurious pressure modes that the displacements cannot
       see). A local change of the energy that keeps one full-rank constraint per node
       leaves the incompressible limit, and with it the pressure, as it is: tried and
       measured below. One constraint per patch, each patch holding a whole node star (an
       interior vertex, whose displacement changes the patch's volume), follows the
       macroelement argument for P1 displacements with a constant pressure per patch
       (Stenberg, Math. Comp. 42, 1984: stable when every patch has such a vertex); here
       only by analogy, as each aggregate's volume reaches a ring of tetrahedra beyond its
       nodes: not proved, measured below. It keeps a tenth to a 27th of the constraints:
       the pressure comes out smooth and the locking stays away. Forces: dW/dJ_b = V_b P_A
       for every node b of aggregate A, P_A = sum_mat W_A,mat U'_mat(J_A) / V_A: each node
       carries its aggregate's pressure and the element pass is that of nodal_pressure = 1
       unchanged (p_e the mean of its four nodes' P). Differential: dP_A = (sum_mat W_A,mat U''_mat(J_A)
       / V_A) dJ_A, dJ_A = sum_{a in A} (sum Vol dJ / 4)_a / V_A, each node carrying dP_A: the
       exact tangent, matrix-free, coupling every tetrahedron at an aggregate's nodes. The
       patch test and rigid motions hold as for nodal_pressure = 1 (a homogeneous J gives
       every J_A = J). Inversion, Prony, the integrators, float: as nodal_pressure = 1 (the
       same node pass, on the aggregates). Deterministic: the sums fold into the aggregates
       and the pressures go back to the nodes in node order on the calling thread. Memory:
       one int per node and 5 + M reals per aggregate (M materials). Cost per pass: force
       248 instructions per tetrahedron against 256 for nodal_pressure = 1, differential
       581 against 590 (the callgrind set-up of NEAR-INCOMPRESSIBLE BODIES; the node pass
       runs on the aggregates; the fold and the broadcast are two loops over the nodes).
       Measured (tests/test_heml_solve.c test_nodal_pressure_aggregates_cook; Cook's
       membrane R10, nu = 0.4999, corner u_y in mm at N = 4, 8, 16, 32; converged about 6.9):
           six tetrahedra per cell    4.90 6.34 6.66 6.91   (nodal_pressure = 1: 2.65 4.38 5.99 6.61)
           five tetrahedra per cell   3.10 5.59 6.76 6.89   (2.46 4.23 6.13 6.68)
       the splits 37, 12, 1.5 and 0.2 % apart, both within 0.2 % of the published value at
       N = 32. The pressure's neighbour indicator (the RMS of P_a minus its neighbours'
       mean over P's spread, tests/test_heml_solve.c checkerboard(); a node-to-node
       oscillation gives 1 or more, nodal_pressure = 1 gives 1.2 at every N): 0.40 0.28
       0.17 0.10 (six) and 0.53 0.41 0.18 0.12 (five), falling with h as a smooth field
       read in steps of a patch does; smoothed once (element means back to the nodes) 0.11
       and 0.15 at N = 8, a smooth field's own 0.21 and 0.10 there. P_A is constant over an
       aggregate: read it as it is, or smoothed once.
       Krylov iterations: the static solve's preconditioner (heml__pagg_pc_build; on where
       every material's kappa >= 20 mu, nu >= 0.476, the saddle probe's rule, and the mesh
       has at most HEML_PAGG_PC_MAX = 1024 pressure aggregates; below or beyond, Jacobi and
       the rigid-mode coarse space as before, bit for bit). The tangent is K = K_dev + s G^T
       Dn G with one row of G per aggregate (g_A = dJ_A V_A, sparse: the 3-vectors Vol_e cof
       F_e grad N / 4 of the tetrahedra at its nodes), so its stiff part has rank A. The
       preconditioner is B = (B_dev^-1 + s G^T Dn G)^-1, B_dev the deviatoric two-level one
       of the saddle probe (Jacobi of the deviatoric small-strain diagonal, the rigid-mode
       coarse space of the deviatoric small-strain stiffness), applied exactly by the
       Woodbury identity: z = B_dev r - B_dev G^^T S^-1 G^ B_dev r, G^ = sqrt(s Dn) G,
       S = I + G^ B_dev G^^T (A x A, dense Cholesky). The bulk part cancels exactly: v.K v /
       v.B^-1 v lies within the extremes of v.K_dev v / v.B_dev^-1 v, so the iterations are
       those of the deviatoric problem at every kappa. G^ is the current state's (one sums
       and node pass for d_A, one loop over the tetrahedra), kept per node (the aggregates of
       the node's star, 3 on Cook's one-cell-thick membrane, 8 or 9 in the beams below), and
       S is factored once per Krylov solve: O(n w^2 + A (6 A_c)^2 + A^2 6 A_c + A^3 / 3);
       each application costs two Jacobi-and-coarse applications, two passes over the per-
       node vectors and two triangular solves of A. The answers are the same to the solve
       tolerances (printed digits unchanged below; tests/test_heml_solve.c
       test_pagg_preconditioner: 1e-9 relative in double). Measured (bench/heml_nodal_krylov.c,
       third argument 2; Xeon Sapphire Rapids class, KVM, 2 vCPUs loaded by other jobs; gcc
       -O2 -march=native, double; Krylov iterations in total (Newton iterations), time the
       minimum of 6 interleaved runs, before -> after), nu = 0.3, 0.49, 0.499, 0.4999:
           Cook N = 8    526 (4)          726 -> 529 (5)    1,577 -> 679 (9)    2,305 -> 691 (11)
                         0.038 s          0.053 -> 0.043    0.119 -> 0.058      0.168 -> 0.059 s
           Cook N = 16   478 (5)        1,272 -> 663 (9)    2,313 -> 627 (10)   6,563 -> 1,101 (18 -> 17)
                         0.153 s          0.388 -> 0.245    0.700 -> 0.223      1.957 -> 0.418 s
           beam 40x4x4   121 (2)          402 -> 261 (3)      509 -> 261 (3)      617 -> 271 (3 -> 4)
                         0.084 s          0.251 -> 0.179    0.303 -> 0.178      0.377 -> 0.187 s
       (nodal_pressure = 1, which has no such preconditioner: 490 745 2,243 5,738; 449 1,480
       3,434 13,446; 111 455 933 2,223), so 1.3, 2.3 and 2.2 times the nu = 0.3 count at
       0.4999 (before: 4.4, 13.7, 5.1); what remains is Newton's iteration count, which grows
       with nu (Cook N = 16: 65 Krylov iterations per Newton iteration at 0.4999, 96 at 0.3).
       On a finer beam (80 x 8 x 8 cells, 6,561 nodes, 466 pressure aggregates, 64 rigid-mode
       aggregates; one run each): 148 at nu = 0.3, then 813 -> 573, 1,361 -> 571, 2,653 ->
       586 (4 times the 0.3 count), 6.1 -> 5.6, 9.8 -> 5.3, 18.2 -> 5.5 s: the deviatoric
       problem's own conditioning grows with the mesh (its coarse space is 64 aggregates at
       most), and an iteration costs more (9.9 against 7.5 ms at nu = 0.49, builds included:
       S, about 0.1 GFlop by count there, once per Krylov solve); at 100 x 10 x 10 cells
       (12,221 nodes, 895 pressure aggregates, near the cap; one run each, the bench's fourth
       argument 0 for "before"): 181 at nu = 0.3, then 1,106 -> 808, 1,808 -> 801, 3,149 ->
       823 (4.5 times), 10.9 -> 10.2, 13.9 -> 10.6, 22.4 -> 10.9 s (S: about 0.46 GFlop
       by count a Krylov solve there). With it forced on at
       nu = 0.3 (the bench's fourth argument 1): 494, 422, 109 iterations, but the
       beam 1.27 times slower (0.094 -> 0.119 s, min of 5 interleaved: the build and the
       second coarse application), hence the kappa >= 20 mu rule. Memory (MEMORY): per node
       w slots of one int and 3 doubles and 3 reals of scratch, A^2 + 6 A A_c + A doubles.
       Not used by the implicit steps (their D + c K has the same structure; not done), nor
       by nodal_pressure = 1 (one aggregate per node: S would be n x n).
       Tried first, on dense copies of the operators (Cook 8 x 8, nodal_pressure = 2, one
       linear solve to 1e-6 at the rest state and at the converged state, nu = 0.3 / 0.4999;
       today's Jacobi and K0 coarse space: 126 / 500 and 126 / 615): the coarse space
       augmented with the A vectors g_A next to the rigid modes (coarse matrix Z^T K Z exact,
       dense) used additively, 117-122 / 276-279 (the stiff part's range is in the coarse
       space, but the soft, nearly volume-preserving modes that Jacobi leaves are not);
       as deflation or balancing (BNN) with the deviatoric Jacobi, 97-100 / 93-94, robust,
       but it needs K Z at the current state: 6 A_c + A stiffness products per Newton
       iteration (176 on Cook 16 x 16), and with the rest state's K in Z^T K Z and the
       projection instead, 277 at the converged state (K - K0's bulk part, of order kappa
       times the strain squared, is then not deflated); the deviatoric Jacobi alone with
       today's coarse space, in the solver: Cook 8 x 8 2,135 instead of 2,305, the beam
       2,392 instead of 617. The Woodbury form on the same dense copies: 118-119 / 113-122.
       The saddle-point MINRES retried with these aggregates was not needed. The
       bench's Poisson beam (30 x 3 x 3 cells of five, against Timoshenko): 4.3, 11.3, 13.9,
       14.6 % off at nu = 0.3, 0.45, 0.49, 0.499 (nodal_pressure = 1: 14.4, 18.9, 22.5, 25.9;
       build/bench/bench --parts stability --filter nodal; plain P1: 18.5 % at 0.3, 30.2 % at
       0.499). Issue 13's target, "within 2 points of the same mesh's error at nu = 0.3",
       read as: no further off than plain P1 on that mesh at 0.3 (its error is bending
       locking): met, 13.9 and 14.6 % against 18.5 (tests/test_heml_solve.c
       test_nodal_pressure_poisson_beam; nodal_pressure = 1's 22.5 and 25.9 % do not meet
       it). Read against this option's own 4.3 % at nu = 0.3 (the aggregates also relax part
       of P1's volumetric stiffness in bending there), it is not: 10.3 points, O(h), P1
       bending on 3 cells across. What it gives up: the
       volume is held per patch, so inside a patch it is restored by the shear stiffness
       alone: on very coarse meshes the body is softer (the bench's NI beam at nu = 0.499,
       build/bench/bench --parts trade --scenes NI --filter nodal: 20 % too far at 2 cells
       across, 567 dof, then 14.6, 10.3, 6.8 % short at 3, 4, 6 cells, where
       nodal_pressure = 1 is 41, 26, 18, 10.9 % short; a 2 x 2 x 2-cell cube squashed
       through zero volume, 2 aggregates, took 4 s instead of 2 to return within 5 % of its
       rest volumes at 20 / s of mass damping: test_nodal_pressure_squash_release), and large deformations may need more
       Newton iterations (the bench's stress sweep: 3 error codes against 2, no wrong
       answer; a one-cell-thick beam at nu = 0.4999 under an implicit step of 1 s from rest
       needs 30 against the cap of 20, where nodal_pressure = 1 needs 20).
       Tried first, and not kept (branch anpstab, commit ed2e6ab, reverted; exact energies,
       Cook N = 8 at nu = 0.4999, indicator of the model's own nodal pressure, six / five
       tetrahedra per cell, nodal_pressure = 1 alone: u_y 4.38 / 4.23, indicator 1.22 / 1.24):
       the classical blend W_vol = (1 - alpha) sum_a V_a U(J_a) + alpha sum_e Vol_e U(J_e),
       alpha = min(1, c mu / kappa): c = 1: 4.23 / 4.19 mm, 1.22 / 1.24; c = 10: 3.52 / 4.00,
       1.22 / 1.25; c = 1000: 2.22 / 3.41, 1.01 / 1.25 (it locks before it smooths); the
       nodal energy at smoothed volume ratios J_bar = S^k J (S: element means back to the
       nodes, self-adjoint in the nodal volumes, so the forces read S^k P): k = 1: 5.33 /
       5.08 mm, 1.12 / 1.19; k = 3: 5.68 / 5.32, 0.87 / 0.82, and at N = 16 k = 2 still
       0.85 / 0.88 (S is invertible: the limit constraint and its spurious pressure modes
       stay, amplified by S^-k before S^k smooths them back).

   INTEGRATORS (the desc picks a default, heml_step_ex picks per call)
       HEML_SEMI_EXPLICIT_EULER  eq. 32: v1 = v + dt a(u, v), u1 = u + dt v1, lumped masses
                             m_i = sum rho Vol / 4 (sec. 3.3). One force evaluation per
                             step: the fastest, and the paper's. Conditionally stable:
                             dt below about h / c with c = sqrt((lambda + 2 mu) / rho) and
                             h the smallest tetrahedron altitude (heml_stable_time_step
                             returns half of that). Use it for soft tissue with small steps
                             (haptics at 1 kHz), or when the step is small anyway.
                             Divergence check (cheap: no extra force pass): the energy
                             of the free degrees of freedom, kinetic plus the trapezoidal
                             potential -sum (F_n-1 + F_n) / 2 . du of every force (exact for
                             linear forces), may not grow beyond twice the energy the body
                             was given (kinetic and elastic energy at its reference state
                             plus the magnitudes of the loads' work and the driven axes'
                             work since), and a step's result may not carry more kinetic
                             energy than that: HEML_ERR_DIVERGED, state kept. The reference
                             is reset by heml_set_positions / displacements / velocities, a
                             change of the pinned axes, a static solve or an implicit step.
                             Stable runs stay far below the bound (the energy of symplectic
                             Euler oscillates by about omega dt / 2 of itself); a blow-up
                             grows exponentially and is caught within a few steps, before
                             anything overflows (a released inverted tetrahedron at half the
                             estimated stable step: caught at its first step, where 0.2.1
                             ran Mooney-Rivlin to |u| = 1e17 m with success). Not checked
                             for user laws without an energy callback.
       HEML_IMPLICIT_EULER   backward Euler as a minimisation: u1 minimises the incremental
                             potential
                                 W(u) - (f_ext + M g) . u + sum m |u - u0 - dt v0|^2 / (2 dt^2)
                                      + alpha sum m |u - u0|^2 / (2 dt)
                             (mass damping alpha enters as its dissipation potential), whose
                             stationarity is backward Euler, by Newton iterations (cap
                             desc.newton_iterations, default 20) to desc.newton_tolerance
                             (default 1e-6, float 1e-4) on the residual relative to its
                             largest force term, each solving (M (1 + dt alpha) / dt^2 -
                             df/du) delta = R by CG with the exact force differential
                             applied matrix-free (an Eisenstat-Walker tolerance;
                             preconditioned by Jacobi, plus the static solve's coarse
                             correction where it pays: IMPLICIT COARSE CORRECTION below),
                             then an energy line search (backtracking until the
                             potential decreases; with a Prony series the force has no
                             potential and the residual must decrease instead). Where CG
                             meets negative curvature (stats.negative_curvature) a
                             Levenberg-Marquardt shift is added, so every iteration
                             descends. So a step lowers its own objective at any dt, E and
                             nu: 1e-6 to 1 s, 1 Pa to 200 GPa, nu up to 0.4999 (the test
                             sweep). Cost: one force and energy pass per line-search trial
                             plus one differential per CG iteration; 1 to 3 Newton
                             iterations on mild steps, about 15 on a soft beam falling at
                             dt = 1 s (1 m, E = 100 kPa, nu = 0.45), about 140 at nu =
                             0.4999 (then raise newton_iterations: with the default cap the
                             step returns HEML_ERR_NO_CONVERGENCE). The answer must also
                             not invert more tetrahedra than its start (allow_inversion).
       HEML_IMPLICIT_EULER_LINEARIZED  one Newton iteration of backward Euler from u0 (the
                             Baraff-Witkin linearly implicit step; 0.2.x's default): one
                             linear solve, no line search, no check of the nonlinear
                             equations. Stable, cheap and accurate while the step is nearly
                             linear (small strain increments: dt well below the period of
                             the motion that matters); wrong, with success, beyond: a soft
                             beam (1 m, 10 cells, E = 100 kPa, nu = 0.45) falling at
                             dt = 1 s took steps whose backward-Euler residual was 1e7
                             times its weight, its tip swinging to -1.37 m (issue 18 saw
                             steps 40 to 50 % off, and with a raised CG cap a tip at -4.6 m
                             or 0.88 m above its clamp). Its CG switches to MINRES under
                             negative curvature and fails the step (HEML_ERR_NO_CONVERGENCE)
                             at cg_max_iterations.
       HEML_BDF2             the second-order backward differentiation formula,
                                 u1 - 4/3 u0 + 1/3 u_-1 = beta v1,  v1 - 4/3 v0 + 1/3 v_-1 = beta a1,
                             beta = 2 dt / 3, solved exactly as HEML_IMPLICIT_EULER: it is
                             the stationarity of implicit Euler's incremental potential
                             with (dt, u0, v0) replaced by (beta, ubar, vbar), ubar =
                             (4 u0 - u_-1) / 3, vbar = (4 v0 - v_-1) / 3 (mass damping as
                             its dissipation potential alpha sum m |u - ubar|^2 / (2 beta)),
                             so the same Newton minimisation, line search, acceptance test,
                             error codes and costs (Newton starts from u0). The model keeps
                             the history (u_-1, v_-1: two 3n vectors allocated at create).
                             The first BDF2 step, and the first after anything that changes
                             the state or the constraints other than a BDF2 step of the same
                             dt (heml_set_positions / displacements / velocities, every
                             heml_fix_node, heml_set_displacement(_axes), heml_release_node,
                             a static solve, a step of another integrator, a failed step, a
                             different dt), is one implicit Euler step: its local error is
                             O(dt^2), so the method stays second order. A failed step keeps
                             the state and the history arrays (the retry starts with
                             implicit Euler). The Prony recursion (eq. 20) stays first
                             order. Why BDF2 (measured: tests/test_heml_time.c on a linear
                             oscillator; a throwaway run of R3's bench beam, 10 x 1 x 1
                             cells released in its first discrete mode, tip by a probe,
                             gave the same figures to the digits shown, BDF2 at T/400
                             below the fit's noise; decay of the amplitude per period /
                             period error):
                                 dt      implicit Euler        BDF2
                                 T/20    61.0 %  / +3.21 %     3.84 %   / +3.02 %
                                 T/50    32.4 %  / +0.52 %     0.30 %   / +0.52 %
                                 T/100   17.9 %  / +0.13 %     0.039 %  / +0.13 %
                                 T/400    4.8 %  / +0.008 %    0.0006 % / +0.008 %
                             (both equal to their amplification factors' closed forms to 3
                             digits; the period error of both is second order, about
                             (omega dt)^2 / 3: it is the amplitude that implicit Euler gets
                             wrong to first order). BDF2 is A-stable and L-stable: the
                             highest mesh modes (omega dt >> 1) are damped out within a few
                             steps (no high-frequency ringing at game time steps), and on a
                             nonlinear problem it adds no energy, where the energy-
                             conserving trapezoidal rule / Newmark average acceleration and
                             the implicit midpoint rule conserve energy only for linear
                             forces, keep every mesh mode ringing at large dt, and have no
                             minimisation form with BDF2's line-search guarantee. What
                             BDF2 loses: it damps a mode at T/20 by 4 % a period (use dt of
                             T/50 or less for the modes that matter) and it needs a
                             constant dt (a change restarts it with one implicit Euler
                             step).
   ANCHORS (heml_set_anchors, issue 14; the same hook as frm_model_set_anchors and
       tensormass.h's tmass_set_anchors): zero-length springs from chosen nodes to target points,
       energy sum_a k_a / 2 |x_a - t_a|^2, part of the model's energy W from the call on:
       forces (-k (x - t)), the differential (-k dx, so heml_apply_stiffness is the public
       stiffness product of the model with its anchors), the Jacobi preconditioner (k on the
       anchored diagonal), the coarse spaces of static solves and implicit steps (P^T k P on
       the anchored nodes' aggregates, rebuilt after each heml_set_anchors: a body held only by anchors keeps
       its rigid modes there; the glued R1 half went from about 900 to 120 CG iterations
       a Newton solve; a stiffness changed in place without the call keeps the old coarse
       space, slower, not wrong), every integrator, the static solve, its saddle check and modal
       analysis; heml_energy's elastic part includes them. They are the hook for gluing a
       mesh to another model without either header including the other: the targets are
       the other model's points (frames.h: mapped points of a probe), updated between
       solves; the springs' stiffness is then inside each implicit and static solve, so a
       coupling iteration stays stable at the time steps the models run alone (frames.h
       COUPLING: a steel beam half heml.h, half frames, static; a soft one at dt = 10 ms).
       The arrays are the caller's (kept by pointer). Off by default: without the call every
       result is bit-identical. One loop over the anchors per pass (after the tetrahedra),
       allocation-free.
   STATIC SOLVE (heml_solve_static): the minimum of the potential W(u) - (f_ext + M g) . u
       over the free axes (the fully relaxed Prony response), by continuation and Newton.
       Continuation: the loads and the pinned axes' moves to their targets are applied with
       a factor lambda from 0 to 1, first in one increment; a failed increment is cut in
       half from the last converged state (stats.increment_cuts), a converged one doubles
       the next; it stops after desc.max_increments attempts (default 64) or below an
       increment of desc.min_increment (default 1e-4) with HEML_ERR_NO_CONVERGENCE. Each
       increment starts from a tangent predictor: the pinned axes move by their share and
       the free ones by the small-strain response to it (one Krylov solve of K delta =
       R + df/du dpin), so a boundary layer moves with the pins instead of being crushed by
       them (0.2.1 moved only the pins: a 1 m Neo-Hookean cube, nu = 0.45, 4 x 4 x 4 cells,
       stretched to s = 1.5 in one call returned success with the field 0.37 m off the
       affine one, a tetrahedron at J = -0.01 and 2684 J against the minimum's 986 J; now
       the affine field to 1e-10 m in one increment of 7 Newton iterations, and likewise
       squashed to s = 0.5). Newton: each iteration solves K delta = R (K = -df/du, the
       exact tangent, matrix-free) by CG to an Eisenstat-Walker relative residual (1e-3,
       then 0.9 (|R_k| / |R_k-1|)^2, never tighter than the tolerance needs), with a
       Levenberg-Marquardt shift where CG meets negative curvature; the preconditioner is
       Jacobi plus a coarse correction: the nodes are binned into up to 64 aggregates of the rest shape, and the
       small-strain stiffness projected on their rigid motions (6 per aggregate) is solved
       exactly (slender bodies bend by rotating their sections, which Jacobi alone resolves
       slowest: 15 times fewer iterations on R1); with nodal_pressure = 2 and every material's
       kappa >= 20 mu, Jacobi and the coarse space are the deviatoric ones, corrected for the
       bulk part exactly (PRESSURE AGGREGATES, "Krylov iterations": the iterations no longer
       grow with kappa). A backtracking line search accepts a step
       only when it lowers the potential (Armijo, up to its round-off), so Newton descends
       to minima and does not converge to the unstable equilibria it may start near (St
       Venant-Kirchhoff compressed beyond its softening point settles in its lower, sheared
       state). Acceptance of an increment:
           |R| <= static_tolerance max(|f_ext + M g| (free), |f| (all, reactions included)),
       and (allow_inversion = 0) no more tetrahedra inverted (J <= 0) than at the start
       (else HEML_ERR_INVERTED, counted in stats.inverted). Where the residual stops
       falling (no progress in 4 iterations, no acceptable step, or static_max_iterations)
       within 100 times its round-off floor (eps times the terms each degree of freedom
       sums, and the stiffness times one ulp of the displacements), the answer is accepted
       only if it is converged in energy: the last Newton correction's energy R . K^-1 R
       below static_tolerance^2 times the answer's max(|f . u|, 2 W) (an energy-norm error
       below static_tolerance); otherwise HEML_ERR_ROUND_OFF. Elsewhere it fails with
       HEML_ERR_NO_CONVERGENCE. On the steel cantilever R1 (a nearly linear problem) Newton
       takes 3 or 4 iterations in double; in float, 7 or 8, the energy criterion ending them
       (see LIMITS for what float resolves). stats.below_threshold counts the tetrahedra of
       the answer below J0, whose stress is the continuation's (LIMITS).
       A converged answer must also be a minimum: a zero residual holds at saddles too,
       and Newton converges to them (its line search only lowers the energy, so it cannot
       climb out of one it started near, and a symmetric start stays symmetric). A probe
       solve K x = b (a fixed pseudo-random b, CG to 1e-10, float 1e-5) looks for a
       direction of negative curvature; one found is sharpened by a Rayleigh-quotient
       minimisation (v . K v / v . K0 v, K0 the small-strain stiffness diagonal, up to 40
       products) and counts when that quotient is below -1e3 eps (flatter is round-off).
       At a saddle the solve fails with HEML_ERR_UNSTABLE (leave_saddles = 0, the default)
       or (leave_saddles = 1) steps along -+v, |v|max = h_min / 4 halved up to 12 times, to
       the first point whose potential is lower by more than its round-off, and Newton goes
       on (up to 8 escapes per increment; a saddle no step lowers measurably:
       HEML_ERR_ROUND_OFF). 0.3.0 without the probe returned saddles with success: the
       bench's squashed cube (1 m, 2 x 2 x 2 cells of five tetrahedra, top face pushed down
       0.5 m, E-independent) came back at its symmetric state for Neo-Hookean at
       nu = 0.4999 with 16 % more energy than the minimum (W/E 155.9 against 134.3),
       Mooney-Rivlin 27 % (89.07 / 70.37), St Venant-Kirchhoff pushed 0.25 m at nu = 0.45
       3.8 % (0.04999 / 0.04815), and the mass-spring cube in float at a buckled saddle
       3e-5 above its minimum (W/E 0.1090467 / 0.1090434, the tangent's lowest eigenvalue
       -0.0027 E), a different one for each path and E (fields 14 to 129 % apart); in the
       hyperelastic cases Newton's own solves met no negative curvature at all. The probe
       costs one Krylov solve per accepted increment: on a nearly linear solve it doubles
       the CG work (a steel beam 1 x 0.1 x 0.1 m, 40 x 4 x 4 cells, under gravity: 64 to
       129 iterations, 0.029 to 0.058 s), on a large deformation less (E = 100 kPa, the
       tip 1.06 m down: 2278 to 2854, 0.59 to 0.72 s); answers unchanged.

   POINT PROBES (heml_probe_*): material points given by their rest positions, e.g. a
       beam's tip centre on any mesh, sensors, markers. heml_probe_create finds each point's
       tetrahedron and barycentric coordinates once (double, from the rest positions: the
       first tetrahedron that contains it, else the one it is least outside of, accepted
       within 1e-6 in barycentric coordinates, i.e. on the surface up to rounding; farther
       out HEML_ERR_ARG), through a temporary uniform grid of about one cell per
       tetrahedron listing the tetrahedra whose bounding box overlaps it (a point outside
       or on the surface scans all tetrahedra; the answer is the same as a full scan's). Then position, displacement and velocity are the P1 interpolation
       of the four nodes' values (exact for affine fields), 3 per point, no allocation.

   IMPLICIT COARSE CORRECTION (issue 21; desc.implicit_coarse): the implicit steps'
       Krylov solves (HEML_IMPLICIT_EULER and HEML_BDF2 Newton solves, the linearised
       step's solve, CG and its MINRES fallback) solve (D + c K) x = b, D = M (1 + h alpha)
       / h^2 (c = 1; the linearised step: D = M (1 + dt alpha), c = dt^2). Jacobi alone
       is good while D dominates (small dt, soft bodies) and needs hundreds of iterations
       once c K does on slender bodies (their bending modes are what Jacobi resolves
       slowest). The static solve's two-level preconditioner is reused with the step's
       operator: Jacobi of D + c diag K0 plus P A_c^-1 P^T, A_c = P^T (D + c K0) P on the
       same aggregates and rigid modes (>>coarse), K0 the rest state's small-strain
       stiffness (assembled once per set of pinned axes, shared with the static solve),
       D's projection 6 x 6 per aggregate. The factor (dense Cholesky of 6 A unknowns,
       double) is kept with its key (c, P^T D P bit for bit, the pins) and reused while
       the key holds: a step's Newton iterations, and every step of one dt, share one
       factorisation (frames.h rebuilds its coarse matrix at every Newton iteration from
       the tangent; here K0 is constant, so the step's first factor serves until dt, the
       masses or the pins change; BDF2 has two keys: its implicit Euler start and h =
       2 dt / 3). The preconditioner is inexact (K0, not the tangent); CG checks the
       answer as before, so results change only within the solve tolerances. Modes:
       0 (default) automatic: Jacobi alone until an implicit step's solves needed
       HEML_COARSE_MIN_ITERATIONS (20) CG iterations each on average, the coarse
       correction from the next step on (never switched off again); 1 always; -1 never
       (and its arrays are not allocated: MEMORY). stats.coarse_solves counts the solves
       that used it, stats.coarse_factors its factorisations in the step. Why 20: a coarse
       correction costs about 0.6 of a stiffness product per iteration on the bench beam
       (two node passes and two triangular solves) plus one node pass per solve for the
       key; on R3 (40 x 4 x 4 cells, 1025 nodes, 15 aggregates) at dt = 1 ms it loses
       below about 15 Jacobi iterations a solve (E = 1 MPa, 11 a solve: x1.19 the time
       over 20 steps; E = 2 MPa, 15: x1.02; E = 3 MPa, 19: x0.95; E = 10 MPa, 32: x0.69).
       Measured (`build/bench/bench --parts coarse`, bench.c >>coarse, Neo-Hookean beams
       clamped at x = 0, 6 implicit Euler steps from rest, Zen 5, 2 vCPUs, loaded; CG
       iterations per step Jacobi only -> always, and the time ratio always / never,
       best of 3 interleaved repeats in one run; the bench now runs 2):
                              dt = 1 ms         10 ms           0.1 s            1 s
           R3, E = 1 kPa      2 -> 4   x7.3 *   8 -> 9   x1.67  81 -> 30  x0.68  274 -> 38 x0.24
           R3, E = 1 MPa     25 -> 19  x1.27  206 -> 34  x0.26 423 -> 53  x0.21  341 -> 51 x0.24
           R3, E = 10 MPa    81 -> 30  x0.64  274 -> 38  x0.24 401 -> 57  x0.52  210 -> 36 x0.32
           R1, steel        356 -> 30  x0.17  808 -> 46  x0.14 1007 -> 66 x0.13  364 -> 31 x0.19
       (R3: 1 x 0.1 x 0.1 m, 40 x 4 x 4 cells, 3075 dof, load g = 0.01 E / 1 MPa; R1: 16 x
       0.5 x 0.5 m, 64 x 2 x 2 cells, 1755 dof, its own weight. * the first step assembles
       P^T K0 P, about 2 ms, once per model: in 6 steps of a fraction of a millisecond it
       is the whole difference; the automatic mode stays Jacobi there. Rows under a few
       ms a step vary by +-25 % between runs on this loaded machine.)
       BDF2 gives the same picture (bench rows). The automatic mode matches "always" from
       its second step on where Jacobi needed 20 iterations a solve, and stays Jacobi
       where it did not (the 1 kPa rows at 1-10 ms, 1 MPa at 1 ms). Tests:
       tests/test_heml_sim.c test_implicit_coarse_correction (same states as Jacobi only
       to 1e-6 of the displacement, 7.1 times fewer iterations, one factorisation per
       coefficient).

   MODAL ANALYSIS (heml_modal_*): the lowest `count` natural frequencies and M-orthonormal
       mode shapes of K x = lambda M x about the current state (K = -df/du, the exact
       tangent of heml_apply_stiffness, so a prestressed or deformed state has its own
       modes) with the pinned axes, M the lumped masses. Method: block shift-invert
       subspace iteration (Bathe) with p = max(2 count, count + 8) vectors: Y = (K +
       sigma M)^-1 M X by the model's linear solver (heml__linear_solve: CG with Jacobi and
       the static solve's coarse space, warm-started at X / mu, to min(tolerance, 1e-3)),
       the Rayleigh-Ritz pairs of (K + sigma M, M) on span Y with exact products (K +
       sigma M) Y (p x p Cholesky and Jacobi rotations), the next X the Ritz vectors;
       converged when every wanted Ritz value moves by at most `tolerance` of itself. The
       shift sigma (default automatic, 1e-5 of the largest stiffness diagonal over mass)
       makes K + sigma M definite for free bodies, whose six rigid modes come out at 0 Hz
       within round-off (1e-10 Hz on a free 1 m cube whose first elastic mode is 0.93 Hz).
       Deterministic (a fixed pseudo-random start), matrix-free, no allocation after
       heml_modal_create. Cost per iteration: p Krylov solves and p stiffness products;
       4 to 5 iterations on the tests' meshes (R3 on 40 x 4 x 4 cells, 1025 nodes, 6
       modes: 0.9 s). LOBPCG was not tried (time): with the coarse space the inner solves
       are cheap and the outer iteration converges in a handful of steps. Measured on R3
       (bench beams, 10 k x k x k cells of 5 tetrahedra, Neo-Hookean): first bending
       0.8334 / 0.6188 / 0.5394 Hz at k = 1, 2, 4 against the 3D solid's 0.5091 (P1
       locking: +64, +22, +6 %, converging as h^2; Richardson from k = 2, 4: 0.5129 Hz,
       +0.75 %), first torsion 5.655 / 5.294 / 4.853 Hz (4.5101), first axial 7.9997 /
       7.9605 / 7.9410 Hz (7.9276, +0.17 % at k = 4); no spurious mode below the first
       bending one, for springs either.

   PERFORMANCE: per tetrahedron the force kernel reads 4 int node indices and the 10 rest
   constants (HEML_KERNEL_BYTES_PER_TET: 96 bytes in double, 56 in float; springs read no
   more since issue 21's second spring change, below, and share their six divisions since
   the third; a Prony series 72 per term, which it also writes), gathers the displacements of
   its 4 nodes (96 bytes, mostly cache hits when nodes are numbered with locality: the
   tetrahedra are ordered by their lowest node, see heml__node_order) and adds into their
   forces (96 bytes read and written, likewise). heml_kernel_bytes gives the
   least a pass must move from memory: the stream plus each node's displacement read once
   and force written once (105 bytes per tetrahedron on the beam below). Tetrahedra sit in
   blocks of 16 (structure of arrays inside a block); a block's arithmetic is vectorised
   loops over its lanes; gather and scatter are vector code where the target has AVX
   (issue 21, below), scalar loops elsewhere. The
   Neo-Hookean force: 9 subtractions (the link displacements), H = du V^-1 (27
   multiply-adds), cof H (18), J - 1, one logarithm with its log1p correction (a
   branch-free fdlibm polynomial, which vectorises where libm's log is a call), two
   divisions, P (about 30 operations) and P grad N (27 multiply-adds): about 140
   operations, where 0.1.0's position form needed about 90 (it let the rest terms cancel,
   which cost float its small strains).
   Measured with gcc 12, one thread, on tetmesh_beam(2, 1, 1, n, n/2, n/2, TETMESH_SPLIT6)
   stretched by up to 2 % with a small perturbation, minimum (median) per tetrahedron of
   150 calls of heml_compute_forces / heml_apply_stiffness (400 for the small beam),
   0.1.0 and 0.2.0 built and run interleaved in the same session, min over 3 to 5 rounds;
   gcc -O3 -march=native (FMA contraction on) unless stated. Machine: this project's AMD
   EPYC virtual machine (family 25, model 1: Zen 3, AVX2 without AVX-512; not the Zen 5
   with AVX-512 at 4.2 GHz and 40 GB/s of REFERENCES.md), two vCPUs shared with other
   jobs (figures move by 20 % between runs; compare within a row), an effective clock of
   3.1 GHz by a dependent add chain, triad 18.8 GB/s, both measured in the same session.
                                           0.1.0            0.2.0
       n = 20: 12,000 tetrahedra (1.2 MB, cache-resident)
       Neo-Hookean force                   15.8 ns          19.9 ns
       Neo-Hookean differential            21.4             25.1
       Neo-Hookean, float: force, diff.    11.7, 15.7       14.4, 17.9
       St Venant-Kirchhoff force, diff.    20.2, 34.8       21.4, 34.9
       Mooney-Rivlin (split) force, diff.  44.6, 59.2       52.4, 65.5
       springs force, diff.                42.1, 58.3       45.5, 50.4
       n = 40: 96,000 tetrahedra, 18,081 nodes (10 MB)
       Neo-Hookean force                   19.1 (30.3)      20.9 (24.8)
       Neo-Hookean differential            30.6 (44.1)      30.5 (39.4)
       Neo-Hookean, float: force, diff.    12.0, 16.1       14.6, 18.3
       St Venant-Kirchhoff force, diff.    24.7, 39.6       22.1, 38.6
       Neo-Hookean force, -O2 -march=native 20.1             22.9
       -std=c99 -O3 (no FMA contraction)   19.4             23.4
       -O2, generic x86-64 (SSE2)          34.3             41.0
       memory bound (bytes at 18.8 GB/s)   4.7 ns (89 B)    5.6 ns (105 B), float 3.2 ns
   So the displacement form costs the Neo-Hookean force about 25 % on cache-resident
   meshes and under 10 % on larger ones (where 0.1.0's extra memory stalls hide the
   arithmetic), about 20 % in float; the differential up to 15 %. It sits at 3.7 times
   the memory bound in double (4.6 in float), not 2, and at 20 ns rather than the 15 ns
   this work was designed for: the gather and scatter alone (62 scalar memory operations:
   a kernel doing only them and the stream reads runs at 10 ns on the small beam) and the
   vectorised arithmetic (about 10 ns) each exceed the bound. For comparison REFERENCES lists Bullet's Neo-Hookean at 181 ns and
   Vega's at 377 ns per tetrahedron on its Zen 5 machine. Mooney-Rivlin (split) costs
   about 2.6 times Neo-Hookean (J^-2/3 by libm's cbrt, a call), springs about 2.3 times
   (six square roots, calls under errno semantics). Rejected after measurement: one fused
   loop for the Neo-Hookean force or differential (it spills the 16 AVX2 registers: 10 %
   slower than the split loops kept); the link form with the rest terms regrouped
   analytically (Sigma V + gamma C = s0 C / 6 ...), which needs the rest links besides
   their inverse (17 constants, 152 bytes) and no fewer operations; springs streaming
   their rest links (9 more constants) instead of recomputing them from V^-1 (20 % slower
   on the small beam, 40 % on the large one). From 0.1.0: a two-pass gather (per-tetrahedron forces into a
   buffer, then a per-node sum) cost 30 to 35 ns against 24 to 27 ns for the colouring;
   blocks of 32, interleaving neighbouring tetrahedra across lanes, computing node 0's
   force in the vector loop and software prefetch did not help; vector gathers are slower
   than scalar loads (4 against 3 ns), so the gather loop is kept scalar
   (HEML__SCALAR_FN).
   0.2.1 colours groups of up to 16 chunks instead of single chunks (a colour of single
   chunks spread over the whole mesh, so each colour swept all the node arrays again),
   orders the tetrahedra by their lowest node and runs the Neo-Hookean force in short
   stage loops (heml__forces_nh). Same method, 0.2.0 and 0.2.1 interleaved, min of 6
   rounds (3 for random order), double, ns per tetrahedron, force / differential; figures
   move by 15 % between rounds on this machine:
                                                   0.2.0            0.2.1
       12,000 tetrahedra (n = 20 above)            23.6 / 29.5      19.9 / 33.5 (*)
       975,560 (58^3 cubes of 5, nodes row by row) 36.1 / 54.3      32.2 / 42.5
       the same, tetrahedra in random order        141 / 195        26.5 / 44.6
   (*) the differential's code and this mesh's order did not change: noise. Where the
   time goes (0.2.1, the same loops run apart, 12,000 tetrahedra): the vectorised
   Neo-Hookean arithmetic 10.5 to 11 ns (14 as one loop up to the stress and one for the
   product, as in 0.2.0), the gather and scatter 9.5 to 10 ns (about 85 scalar
   instructions per tetrahedron at about 3 per cycle; with no node shared inside a block
   they run no faster, so it is not the chains of updates to shared nodes). The 15 ns
   target needs the sum cut by a quarter. Tried for the gather and scatter: AVX2
   intrinsics with explicit transposes (128-bit loads and stores of x, y per node, 4
   lanes at a time) took them from 9.6 to 8.1 ns and the force from 22.4 to 20.8 ns on
   the 12,000-tetrahedron beam: not enough for a second, non-portable code path, so not
   kept. For the differential, splitting its volumetric scalars into a loop of their own
   gained 3 % (14.7 to 14.3 ns of arithmetic): not kept either.
   The two floors under the target. Data movement: bench/ times a `move` kernel, this force
   pass itself (colours, groups, heml__gather, heml__scatter) with the law's arithmetic
   replaced by one multiply-add per link component, so that it still streams every rest
   constant. In the committed run (bench/results, git 2ac37d3, double, one thread,
   5-tetrahedron cubes, triad 19.5 GB/s) it costs 10 to 14 ns per tetrahedron at 1e3
   tetrahedra and 18 to 26 ns at 1e6, 3.3 to 4.8 times the bound, against the Neo-Hookean
   force's 21 and 41 ns: on large meshes the movement alone is above twice the bound,
   whatever the arithmetic costs. (Run apart in an ad-hoc harness, gather and scatter
   without the rest constants cost the same 9 to 10 ns at 1e6 as on a cache-resident mesh;
   streaming the constants adds about their own transfer time, 5 to 6 ns: the stream does
   not overlap the scalar gather and scatter.) Arithmetic: the compiled Neo-Hookean loops
   issue about 135 multiplies and fused multiply-adds and 2 divisions per 4 lanes, on the 2
   pipes that run them: at least 6 ns per tetrahedron at 3.1 GHz; they run in 9 to 11. For
   comparison tensor-mass's edge kernel is within 1.7 times its bound at 1e6: it makes about
   5 node accesses per tetrahedron (about 1.2 edges of 2 nodes, each read and written)
   against these 8, for as many streamed bytes. Meeting the target would take hardware
   scatter (AVX-512) or a traversal that keeps a node's data in registers between its
   tetrahedra (whole cells per lane), and an arithmetic near its floor; not done. The target
   was set for REFERENCES.md's machine (Zen 5, 4.2 GHz, AVX-512, a 40 GB/s triad); the
   kernel figures above come from the Zen 3 named earlier. There the clock alone would bring
   20 ns near 15, and the bound halves with the bandwidth; neither is measured.
   Issue 21 (this machine is not the Zen 3 above any more: /proc/cpuinfo says AMD EPYC
   family 26 (Zen 5) with AVX-512, gcc 12 takes -march=native as znver3 plus AVX-512;
   shared by several jobs, load 4 to 7 on 2 vCPUs, so timings move by 2x: figures are the
   minimum of 5 to 15 interleaved runs, ns per tetrahedron, 8,640-tetrahedron beam, force /
   differential, and instruction counts by callgrind of -march=x86-64-v3 builds, which
   valgrind can run):
                                    before           after         instructions (v3)
       Neo-Hookean, -march=native   12.5 / 15.9      10.1 / 12.4
       Neo-Hookean, x86-64-v3       13.5 / 21.1      11.4 / 17.7   213 / 278 -> 160 / 198
       St Venant-Kirchhoff          14.6             (unchanged)   259 / 376 -> 207 / 296
       Mooney-Rivlin (split)        39 / 45          17 / 22       490 / 606 -> 230 / 320
       springs                      284 / 34         17            451 / 509 -> 248 / 270
   So every law's force is within 1.5 times the Neo-Hookean force (SVK 1.17, Mooney-Rivlin
   1.35, springs 1.34, all measured in one interleaved run before the gather change; the
   gather and scatter serve every law alike). What changed, all bit-identical to the scalar
   path except the cube root:
   - the spring force: heml__spring_forces took the differential's terms under a branch on
     dt, which gcc if-converted, so the force pass multiplied the unset workspace de, whose
     stack garbage held subnormals (microcode assists: 15x). The differential is now
     heml__spring_dforces. Its six square roots per tetrahedron go through
     heml__sqrt_lanes (AVX _mm256_sqrt, correctly rounded like sqrt; libm's sqrt keeps
     errno, so gcc does not vectorise it, and optimize("no-math-errno") on the function
     had no effect).
   - Mooney-Rivlin: J^-1/3 by heml__inv_cbrt (a float bit-trick guess and Newton steps,
     3.6 ulp in double, 2 in float, where libm's cbrt is a call), its energy terms
     (log1p, expm1 calls) in a loop of their own: the law's loop vectorises. Forces move
     by round-off against 0.3.0's.
   - the gather (heml__gather_vec): per lane and node one masked 3-component load
     (AVX-512 VL masks, or AVX's vmaskmov: never reads past an array's end), differences in
     AoS, a 4 x 4 transpose per link into the lanes' rows. The scatter (heml__scatter_vec):
     per lane and node a 16-byte (x, y) and a scalar z read-modify-write, lanes in order;
     masked 3-component stores were tried and lost (force 12.7 -> 20.4 ns: a masked store
     does not forward to the next lane's load of a shared node), as did unmasked 32-byte
     stores (they would write a neighbour node's x, a race with another colour group).
     AVX-512 gather/scatter instructions were not tried (slow on AMD; the scatter needs
     conflict handling for nodes shared inside a block). m->simd = 0 runs the scalar path
     (tests compare both, bit for bit, every law). The float Neo-Hookean force pass now
     differs (below, "The float force against its arithmetic floor"): nodes padded to 4
     components, and with AVX-512 VL a gather of 8 lanes a register.
   - tried and not kept then: software prefetch of the next block's nodes and the rest
     constants of the block after (large meshes): no difference measurable above this
     machine's noise at 975,000 tetrahedra (force 27 -> 15 ns and differential 24 -> 29 ns
     in the same interleaved series: noise). The rest constants' prefetch is now kept (the
     force's out-of-cache gap, below); the nodes' is still not.
   The bench's ratio lines (bench/bench.c, kernels part, `--filter heml`; one loaded run of
   git ea15902 plus these kernels, double, 1 thread) put the Neo-Hookean force at 20 to 23 %
   of its bandwidth bound at 1e3 to 1e4 tetrahedra and 13 to 14 % at 1e5 to 1e6 (goal 40 %:
   not met), at 2.3 to 2.6 times its arithmetic floor in cache (the `arith` rows: the same
   pass without gather and scatter; goal 2: not met, the gather/scatter still costs more than
   the arithmetic), and the differential at 0.85 to 0.89 times a CSR product of the same
   assembled tangent at 1e3 tetrahedra but 1.2 to 2.1 times at 1e4 to 1e6 in double; in float
   0.46 to 0.98 times at every size (a float CSR still reads a 4-byte column index per value,
   so halving the real size saves it less than it saves the kernel).
   The stiffness cache (issue 21, second part; desc.stiffness_cache, default on): the
   implicit step's and the static solve's CG multiply the tangent at one linearisation
   point 10 to 1000 times, so what that point fixes is computed once per linear solve and
   kept per tetrahedron. The differential is rewritten in the links (heml__diff_nh):
       df = -2 c1 dv A - s1 (cof v : dv) cof v - s2 dcof v,
       A = Vol G G^T (6),  v the current links (9),  s1 = U''(J) / (36 Vol),  s2 = w_J / 6,
   from cof F = cof v cof G and cof G G^T = det G I = I / (6 Vol), G = V^-1 (the classical
   form, exact: the finite-difference tests hold it). A product then reads 17 reals of cache
   and the 4 indices per tetrahedron and no rest constants (152 bytes in double against the
   uncached 96 plus a second gather, and the CSR matrix's about 280: 23 values and column
   indices per tetrahedron on 5-tetrahedron cubes; in float 84 against 190), and costs about 110 arithmetic operations (145 through F, and
   the logarithm and division of the uncached kernel are gone). The first product after the
   state or the pins or J0 change fills the cache while it computes (the same apply on the
   same values: cached and uncached products are bit-identical, tests/test_heml.c
   test_stiffness_cache, and so are implicit steps with and without it); the cache is keyed
   by the linearisation point and invalidated at every linear solve's start and end and by
   every public function that changes the state, the pins, J0 or the viscous state (Prony
   and nodal pressure models do not take the Neo-Hookean kernels and have no cache; caching
   the general path would need about 40 reals per tetrahedron, more than a CSR row share in
   float: not done). The cached pass prefetches the next block's cache and indices
   (__builtin_prefetch where the compiler has it): the prefetch alone took the cached
   product from 1.4 to 0.7-0.8 times the CSR product at 1e5 tetrahedra (interleaved, min of
   3). Measured, Neo-Hookean K*v / CSR at 1e3, 1e4, 1e5, 1e6 tetrahedra, one thread: the
   bench (`--parts kernels --filter heml/neo-hookean/ --threads 1`, one loaded run, medians)
   double 0.55, 0.66, 0.99, 1.16, float 0.28, 0.27, 0.30, 0.60; a harness linking the
   bench's adapter, the three kernels interleaved, minimum of 3 to 5 rounds, over five
   runs: double 0.45-0.54, 0.63-0.74, 0.50-0.84, 0.70-1.05, float 0.24-0.36, 0.32-0.48,
   0.39-0.56, 0.45-0.74 (before the cache, the previous report: double 0.85-0.89 at 1e3,
   1.2-2.1 beyond). So the goal holds in float everywhere and in double to 1e4 with a
   margin; in double at 1e5 to 1e6 the product is at par with the CSR product (within the
   noise of this shared machine, 3.3 times its bandwidth bound against the CSR's 1.5: its
   gather and scatter, not its stream, now bound it; prefetching the next block's nodes
   too showed nothing above noise). Tried: the F form of the cache (F, U''(J) Vol, w_J Vol: 11 reals plus the
   rest constants, 184 bytes): 0.9 to 1.05 of the CSR at 1e6 in double; one fused loop for
   the F form's apply instead of three: no difference above noise; prefetching the rest
   constants in the uncached general path (St Venant-Kirchhoff): none either.
   St Venant-Kirchhoff's and the split Mooney-Rivlin's differentials (issue 21, third part:
   heml__diff_svk, heml__diff_mr, the same scheme). St Venant-Kirchhoff: dP = dF S + F dS
   in the links, df = -(dv B + v K), B = Vol G S G^T, K = lambda (X : Ah) Ah + 2 mu Ah X Ah,
   X = sym(v^T dv), Ah = sqrt(Vol) G G^T: 21 reals of cache per tetrahedron (v, Ah, B),
   about 150 operations a product. A block of 16 with a tetrahedron below J0 (the law's
   guard) takes the general path (m->dc_gen, a byte per block). Mooney-Rivlin: its second
   derivatives in I1 and I2 vanish (w_11 = w_12 = w_22 = 0, also continued below J0), so
   its tangent in the links needs, besides v and Ah, Nh = sqrt(Vol) G (C - I) G^T and seven
   scalars (28 reals; storing B = Vol G (2 a I - M) G^T instead of two of them, 32 reals,
   was slower at 1e4 tetrahedra: 1.22-1.38 against 0.97-1.05 times the CSR product in
   one interleaved run), about 290 operations; the law and the stress coefficients at the
   point come from heml__law_split and heml__coefficients, so it needs no fallback below
   J0. Both fill the cache at the first product like Neo-Hookean's (bit-identical to the
   uncached product) and run without Prony (the general path's viscous scaling) and without
   nodal pressure. Callgrind (x86-64-v3, 10,985 tetrahedra, instructions per tetrahedron
   and product at one state): St Venant-Kirchhoff 294 -> 153, Mooney-Rivlin 320 -> 203
   (Neo-Hookean's cached product 137; the filling products 281 and 534). Measured
   (bench/model_heml.c's adapter for both versions in one program, old and new and the CSR
   product of the same tangent interleaved, minimum of 12 to 20 rounds, one thread; Zen 5,
   2 vCPUs at load 5 to 9, so absolute figures are about twice a quiet run's and ratios
   move by 0.1 to 0.2 between runs), K*v / CSR at 1e3, 1e4, 1e5, 1e6 tetrahedra:
       St Venant-Kirchhoff, double  before 1.28 1.16 0.81 0.89 / 1.11 1.20 0.87 0.93 (two runs)
                                    after  0.65 0.75 0.62 0.87 / 0.74 0.70 0.74 0.80
       St Venant-Kirchhoff, float   before 0.85 1.28 0.80 0.89 / 0.95 1.04 1.12 0.78
                                    after  0.44 0.67 0.51 0.56 / 0.53 0.65 0.50 0.48
       Mooney-Rivlin, double        before 1.48 1.59 / 1.43 1.67 (two runs)
                                    after  0.82 1.25 / 0.96 1.18
       Mooney-Rivlin, float         before 1.02 1.21,  after 0.67 0.80
   (the bench runs Mooney-Rivlin at the two small sizes only). The bench itself, one run
   of its medians (`--parts kernels --filter heml/svk/double --threads 1`, same load):
   St Venant-Kirchhoff 0.65, 0.73, 1.04, 0.99, Mooney-Rivlin 0.87, 1.09. So St Venant-
   Kirchhoff's product beats the CSR product at 1e3 and 1e4 in both precisions by a
   margin, and at 1e5 and 1e6 in the interleaved minima (0.62 to 0.87 in double) but
   within this machine's noise in the bench's medians (its cache and indices, 200 bytes a
   tetrahedron, against the CSR matrix's 301, plus the node gather and scatter);
   Mooney-Rivlin's in
   float and at 1e3 in double, but at 1e4 in double it stays 1.18 to 1.25 times the CSR
   product (not met: its stream, 240 bytes a tetrahedron with the indices, is near the
   CSR matrix's 276, and it does 1.3 times St Venant-Kirchhoff's instructions; float
   K*v instructions: Neo-Hookean 112, St Venant-Kirchhoff 120, Mooney-Rivlin 145). Tried
   for it: the apply as two loops (scalars and K, then the product, as the Neo-Hookean
   force's stages): 214 instructions against 203, no gain measurable. The bench's CSR rows for the laws on the general path were
   slowed 5 to 7 times at small sizes by subnormal garbage: its adapter left the
   differential's dp uninitialised (fixed there).
   Issue 21, fourth part (the split Mooney-Rivlin product at 1e4 tetrahedra; Intel Xeon,
   Sapphire Rapids class, KVM, 2 vCPUs shared with other jobs at load 4 to 9): the cache
   keeps B = za Ah - zm Nh in place of Nh and its two scalars, 26 reals (the beta form,
   heml__diff_mr_point), and both kernels take X : Ah as tr(X Ah) from the T they form
   anyway. Callgrind (x86-64-v3, 10,985 tetrahedra, per tetrahedron and product):
   Mooney-Rivlin 198 -> 193 instructions in double, 142 -> 139 in float, St Venant-
   Kirchhoff 150 -> 148 and 118 -> 117 (Neo-Hookean's 135 and 111; the CSR product 165
   in double). Timed with bench/model_heml.c's adapter for the code before and after in
   one program, old, new and the CSR product of the same tangent interleaved, minimum of
   60 to 100 rounds of short batches (about 2 ms: longer ones are all preempted by the other
   jobs, and their minima were 2x these and moved by 20 %), one thread, K*v / CSR at 1e3,
   1e4, 1e5, 1e6 tetrahedra:
       Mooney-Rivlin, double        before 0.91-0.92  1.05-1.10  1.08  1.04 (4 runs at 1e3, 1e4)
                                    after  0.85-0.91  1.00-1.05  0.89  0.92
       Mooney-Rivlin, float         before 0.70-0.72  0.77-0.78  0.69  0.78
                                    after  0.67-0.68  0.73-0.75  0.65  0.69
       St Venant-Kirchhoff, double  before 0.67-0.74  0.74-0.79  0.66-0.71  0.82-0.84
                                    after  0.66-0.76  0.72-0.76  0.65-0.70  0.77-0.78
       St Venant-Kirchhoff, float   before 0.56  0.62-0.64  0.47  0.51
                                    after  0.56-0.60  0.61-0.62  0.47  0.49
   So St Venant-Kirchhoff's product beats the CSR product at every size in both
   precisions by this measure (the full bench's 1.01 at 1e5 was its medians' noise), and
   Mooney-Rivlin's does in float and at 1e3, 1e5, 1e6 in double, but at 1e4 in double it
   is at par (1.00-1.05: the goal is not met there). What bounds it: 13.2 ns a tetrahedron
   at 1e3 (its arithmetic: the product is about 250 operations against Neo-Hookean's 115)
   but 16.6 at 1e4, where the CSR product takes 15-17 ns at both sizes: beyond the 2 MB of
   L2 its stream (208 bytes of cache and 16 of indices a tetrahedron) moves at about the
   rate that bounds the CSR product's 276 bytes, so it needs fewer bytes and fewer
   instructions at once. Tried and dropped (same method):
   - the cache as the symmetric 9 x 9 matrix of the product in the links (45 reals, filled
     by applying the product to the nine unit links; a product is 81 multiply-adds, 122
     instructions a tetrahedron against 193): 0.69 of the 26-real product's time at 1e3
     (0.56 of the CSR product), 1.02-1.05 at 1e4, 2.7 at 1e5 and 1.2 at 1e6 (376 bytes a
     tetrahedron with the indices);
   - v not cached but formed again from two gathers (the rest positions and the point's
     displacements: 17 reals, 152 bytes a tetrahedron with the indices, as Neo-Hookean's):
     249 instructions, 1.28-1.37 times the 26-real product at 1e3 and 1.08-1.16 at 1e4;
   - the St Venant-Kirchhoff and Mooney-Rivlin lane loops compiled for 512-bit vectors
     (gcc target("prefer-vector-width=512"), half the instructions of the loops): 0.89 to
     1.09 of the 256-bit code, noise (as for the Neo-Hookean force above);
   - the Mooney-Rivlin apply in two loops again (K and t, then the product): 410 static
     instructions against 417 in the x86-64-v3 loop, 386 against 354 with AVX-512's 32
     registers; prefetching two blocks ahead: 1.00 and 1.09 of one ahead at 1e4 and 1e5;
     one prefetch per 128 bytes instead of per 64: 195 -> 194 instructions. None kept.
   Forces, against the Neo-Hookean force (unchanged here; callgrind, the same mesh, per
   tetrahedron): St Venant-Kirchhoff 207, Mooney-Rivlin 231, springs 248 against 160
   instructions in double (1.29, 1.44, 1.55), 160, 171, 200 against 128 in float (1.25,
   1.34, 1.56). Timed, the four laws interleaved in one program (minimum of 20 rounds,
   same load), at 1e3 and 1e4 tetrahedra, two runs each: double St Venant-Kirchhoff
   0.98-1.12 and 1.22-1.51, Mooney-Rivlin 1.21-1.29 and 1.49-1.63, springs 1.23-1.79 and
   1.59-1.63; float St Venant-Kirchhoff 1.37-1.92 and 1.19-1.43, Mooney-Rivlin 1.23-2.20
   and 1.55-1.81, springs 0.65-1.22 and 1.07. So the goal of 1.5 times the Neo-Hookean
   force holds in instructions except for springs (1.55) and is not shown in time on this
   loaded machine (Mooney-Rivlin at 1e4 and float St Venant-Kirchhoff measured above it);
   a quiet machine must decide.
   The split Mooney-Rivlin force on a kernel of its own (issue 21, heml__forces_mr,
   heml__mat.fast_mr: no Prony, no nodal pressure; those keep the general path): the
   general path's kinematics, law, coefficients and stress in three lane loops as
   heml__forces_nh's, H (2 a I - M) in place of 2 a H - H M, C - I kept from the first stage,
   nothing stored for the energy or the differential. Instructions per tetrahedron and
   force (callgrind, -march=x86-64-v3 -O3, 11,000-tetrahedron box, c2 != 0): double 229 ->
   217 against Neo-Hookean's 159 (1.44 -> 1.37), float 167 -> 148 against 122 (1.37 ->
   1.21). Of the double kernel's 217: the kernel's stages 115 (Neo-Hookean's 56) and
   f = -P grad N 14, gather 24, scatter 47 (both as Neo-Hookean's): what Mooney-Rivlin needs
   more is arithmetic, C - I (six entries, their squares summed for I2), J^-1/3 by four
   Newton steps and the stress's H M (27 products); J, 1/J and the scatter are shared.
   Storing cof F - I from the first stage too (213 instructions) measured no faster
   (1.34-1.40 against 1.28-1.34 of the Neo-Hookean force, interleaved), the version
   without the H (2 a I - M) form and with C - I formed twice (227) about 4 % slower.
   Timed (Intel Xeon, Sapphire Rapids class, KVM, 2 vCPUs, one other job running; min of
   3 interleaved runs of build/bench/bench --parts kernels --filter mooney / neo-hookean
   --repeats 5, double, one thread, ns per tetrahedron at 1,080 / 10,985): Mooney-Rivlin
   15.11 / 15.57 -> 13.46 / 14.48, Neo-Hookean 10.76 / 11.56, so 1.40 / 1.35 -> 1.25 / 1.25
   times the Neo-Hookean force (the quiet full bench before it: 16.5 / 16.3 against
   10.1 / 10.25, 1.63 / 1.59). In a program of its own (both laws interleaved, min of 8
   rounds, 18,720 tetrahedra, same machine and load) 1.39-1.49 -> 1.28-1.34 in double,
   1.37-1.40 -> 1.10-1.15 in float. The differential's goal (Mooney-Rivlin's K*v below the
   CSR product at 1e4) is not touched here: 1.03-1.17 in the same bench runs.
   The spring force's stream (issue 21, again: the bench's kernels.csv of git dbb91aa on an
   Intel Xeon, Sapphire Rapids class, KVM, 2 vCPUs, one thread, double: springs 16.9 / 19.6
   ns per tetrahedron at 1,080 / 10,985 against Neo-Hookean's 10.1 / 10.25, 208.7 bytes
   against 112): the law streamed 12 reals per tetrahedron of its own (6 rest lengths, 6
   stiffnesses k = E Vol / L^2) besides the 10 rest constants it already reads for its
   rest links. Now heml__spring_tensions derives them: L^2 = |V|^2 from the rest links
   (3 multiply-adds a link), k from the law's E and Vol, and the tension as
   t = E Vol (l^2 - L^2) / (L^2 (l^2 + sqrt(L^2 l^2))), so still one square root and one
   division a link (the differential's dt = s E Vol (v . dv) / (L l^3) reuses L l^3). The
   stream is the 96 bytes of every law (112 bytes a tetrahedron with the node traffic on
   the bench's beams, half of the 208.7 before; the spring arrays, 96 bytes a slot in
   double, are gone from MEMORY). l = L exactly at rest (both from the same V), and the
   lengths are clamped as before (l^2 at 1e-24 L^2). Measured (harness: heml_compute_forces
   on tetmesh_beam(2, 1, 1, 12, 6, 6, SPLIT6), 2,592 tetrahedra, 2 % stretch, old and new
   builds alternated, minimum of 10 rounds of 100 calls, gcc 12 -O3 -march=native, the
   Xeon above at load about 1): springs / Neo-Hookean 1.51-1.80 after against 1.51-1.66
   before, springs 19.0-20.0 ns against 18.5-19.2 ns: no gain in cache, where the stream
   was not the limit. Callgrind (x86-64-v3, the same harness, 20 calls less setup): 246 ->
   209 instructions per tetrahedron against Neo-Hookean's 158 (1.56 -> 1.32), mostly from
   heml__spring_J, whose conditional division kept its loop scalar without AVX-512's
   masks ("control flow in loop"; now a branch-free select). (A first version of the link
   loop with from/to tables lost vectorisation the same way: 3.3 times the instructions of
   heml__spring_tensions; the links 4 to 6 now have a loop of their own.) What bounds the
   spring force in cache is the divider: 6 square roots and 7 divisions per tetrahedron
   (the J - 1 of the statistics is one) against Neo-Hookean's 2 divisions; replacing the
   6 tension divisions by products (wrong forces, a timing probe only) took it from 17.6 to
   15.4 ns (1.63 -> 1.44 times Neo-Hookean, same harness). So 1.5 times the Neo-Hookean
   force in cache needs the square roots or divisions off the divider (pairs of divisions
   through one reciprocal, or Newton reciprocal square roots from a bit-trick guess, both
   bit-reproducible but 1 to 2 ulp instead of correctly rounded): not done. The bench
   (`build/bench/bench --parts kernels --filter springs --repeats 5` and `--filter
   neo-hookean`, old and new binaries alternated, 3 rounds, same machine and load): springs
   17.2-17.7 / 17.5-17.9 ns before, 17.4-18.6 / 17.0-19.1 after at 1,080 / 10,985
   tetrahedra, Neo-Hookean 10.7-11.6 ns at 10,985: 1.55 to 1.6 times, not 1.5 (ratio to
   the bandwidth bound now 2.2-2.5 at 112 bytes: the stream is not what limits it). At
   96,000 tetrahedra (the harness, tetmesh_beam(2, 1, 1, 40, 20, 20), 3 rounds) 19.7-20.1
   after against 19.6-21.0 ns before, 1.61-1.69 against 1.62-1.67 times Neo-Hookean: the
   halved stream shows no gain there either on this machine (its large last-level cache).
   Kept: a smaller model and no loss.
   The spring force's divider (issue 21, a third spring change): in double the six
   tension divisions of a tetrahedron now go through one, 1 / (d1 ... d6) and 15
   multiplications that back out each 1 / d (heml__spring_tensions; a lane whose product
   leaves [DBL_MIN, DBL_MAX / 4], cells below about 1e-13 m or above 1e13 m, divides six
   times as before). Float keeps its six divisions: d ~ L^4, so the product of six would
   leave float's range on millimetre meshes, and float's springs were already within 1.2
   times its Neo-Hookean force. The divider now runs 6 square roots and 2 divisions a
   tetrahedron in double instead of 6 and 7; forces move by round-off (tests/test_heml.c
   test_spring_roundoff: 4 to 19 eps of the terms' magnitude against a long-double
   reference, tolerance 64, the fallback included). Measured in a harness (heml_compute_forces
   on the bench's cubes of n^3 cells of 5 tetrahedra, 2 % stretch and noise; old, new and
   the Neo-Hookean force compiled into one program and alternated, minimum of 300 rounds
   of about 1 ms, 30 single calls at 1e6; gcc 12 -O3 -march=native; Intel Xeon, Sapphire
   Rapids class, KVM, 2 vCPUs at load 4 to 8 from other jobs; several runs), double, ns per
   tetrahedron and springs / Neo-Hookean in the same run:
       1,080 tetrahedra       16.6-18.8 -> 15.5-16.7     1.66-1.77 -> 1.57-1.69
       10,985                 16.7-16.9 -> 15.7-15.9     1.59-1.66 -> 1.50-1.56
       109,760                18.4-19.3 -> 17.2-17.4     1.50-1.61 -> 1.41-1.45
       1,026,895              20.8-21.5 -> 19.0-19.6     1.35-1.40 -> 1.35-1.44
   and float 1.10-1.21 (unchanged). The bench (`--parts kernels --filter heml/springs/` and
   `heml/neo-hookean/`, `--repeats 5`, old and new binaries alternated, minimum of 6
   rounds, same machine): springs / Neo-Hookean 1.84 -> 1.74 and 1.64 -> 1.51 at 1,080 and
   10,985 tetrahedra in double (its medians run 2 to 3 times the harness's minima on this
   loaded machine), float 0.96 -> 1.10 and 1.08 -> 1.11 (noise: the float code did not
   change). Callgrind (-march=x86-64-v3, 10,985 tetrahedra, instructions a tetrahedron and
   force): springs 209 -> 221 in double against Neo-Hookean's 158, 144 in float (122). So
   the goal of 1.5 holds at 1e5 and 1e6 in double and at every size in float, not at 1e3
   and 1e4 in double (1.50-1.69): not met. Timing probes (wrong forces): without the square
   roots the new force takes 13.2-14.8 ns (1.24-1.33), without square roots and divisions
   11.2-13.5 (1.08-1.21): the denominators still cost about 4 ns of the 15.5. Tried and not
   kept, same harness: Newton reciprocal square roots r = 1 / (L l) from a float bit-trick
   guess (4 steps in double, 3 in float, vectorised) with x = 1 + L / l and t = E Vol
   (l^2 - L^2) r^2 / x, the six 1 / x through two divisions: no square root and 2 divisions
   a tetrahedron, but 249 instructions and slower (1.70-1.83 against 1.67-1.75 before; float
   1.3-2.0 against 1.1); the same with AVX-512's vrsqrt14pd and two Newton steps, for all
   six links or for links 1 to 3 with 4 to 6 by square roots (the divider and the
   multiply-add units sharing the work): 15.6-16.5 / 15.9-16.1 / 16.9-17.0 ns against
   15.8 / 16.3 / 17.3 for the shared division in the same run at 1e3 / 1e4 / 1e5, no gain
   for an intrinsic path; the
   statistics' J - 1 with det V^-1 in place of its division (4 more instructions): 15.7-16.8
   against 15.5 ns; 512-bit square roots in heml__sqrt_lanes: slower (16.8 against 15.3 ns);
   the denominators, the shared reciprocal and the tensions in one lane loop: 1 to 7 %
   faster with -march=native, but that loop stays scalar for AVX2 (292 instructions).
   What the force's remaining gap needs (not done): more independent chains per block in
   double (HEML__W = 32: a change of the chunk structure, so of every sum's order).
   Why the force cost twice the cached differential out of cache (issue 21: the bench's
   kernels.csv of git 59471d0 on the Zen 5, one thread, double: force 29.9 / 36.1 ns per
   tetrahedron at 1.1e5 / 1e6 against K*v's 14.2 / 17.6, though the product streams 162
   bytes per tetrahedron and the force 106): not a per-element stream of the force's own.
   The force pass writes nothing per tetrahedron (its statistics are per chunk, its only
   writes the node forces, which K*v writes too; no linearisation cache: the stiffness
   cache is filled by the first product, never by the force), so no write-allocate traffic
   either, and both read their streams in the same order. The difference was the prefetch:
   the cached product prefetches the next block's stream and indices (above), the force
   did not, and its longer arithmetic per block (70 instructions per tetrahedron against
   the cached product's 44, callgrind, x86-64-v3) keeps the next block's loads out of the
   reorder window, so each block waited for its rest constants (most likely also why the
   arith floor, which streams them alone, rose from 6.8 to 12.1 ns at 1e6 on the Zen 5).
   The force pass now prefetches the next block's rest constants and indices
   (heml__prefetch_block), and its statistics' counts are a vectorised lane loop
   (heml__count_lanes: gcc had unrolled the loop inside heml__chunks and left it scalar,
   7 of 159 instructions per tetrahedron).
   Measured (this session's machine is not the Zen 5: an Intel Xeon virtual machine, gcc
   12 -march=native = rocketlake, 2 vCPUs shared with other jobs, load 3 to 8; 2 MB L2 per
   core, so 1e6 tetrahedra are out of L2 but, with its large L3, not in memory, hence the
   5e6 row), Neo-Hookean force, double, one thread, 5-tetrahedron cubes as the bench's,
   before and after built into one program (two models on the same mesh), single calls
   alternated, minimum of 400 calls (60 at 1e6 and above), ns per tetrahedron:
       tetrahedra          1,080    10,985    109,760    1.08e6    5.0e6
       before              10.8     10.9      14.8       40.3      47.6
       after               10.1     10.3      11.7       35.3      37.9
       after / before      0.94     0.95      0.79       0.88      0.80
   (two series of earlier states of the change: 0.95-1.05 at 1e3-1e4, 0.84-0.93 at 1.1e5,
   0.78-0.80 at 1e6, 0.78 at 5e6; the same program with both sides before: 0.99-1.06 in
   cache, 0.90-1.02 at 1.1e5, 0.85-0.93 at 1e6: in cache the change is within the noise,
   at 1.1e5 and beyond it is a gain of about 15 to 20 %, the 1e6 figure the least sure).
   In float (same method): 1.01 at 1e3-1e4, 0.95 at 1.1e5, 0.68 and 0.68 at 1e6 in two
   series (a third, 1.18 by its minimum but 0.83 by its tenth percentile), 0.86 at 5e6.
   Instructions (callgrind, x86-64-v3, 11k tetrahedra): 159 -> 157 per tetrahedron. The
   Zen 5 is not measured here: the bench's next run there says how much of the 2x is
   gone. Tried and not kept:
   prefetching the next block's nodes (positions and forces, 128 prefetches a block) as
   well: 11 % slower in cache, no gain at 1e6; prefetching two blocks ahead instead of
   one: 1.01, 0.99 and 1.11 at 1.1e5, 1e6 and 5e6 (noise); compiling the Neo-Hookean force loops for
   512-bit vectors (gcc target("prefer-vector-width=512") on heml__forces_nh: 531 zmm
   instructions): 0.96 to 1.02 of the 256-bit code in cache here (0.92 to 1.00 with the
   whole program at 512 bits), within the noise, so not worth a compiler-specific
   attribute. What is left in cache is the arithmetic (70 of 157
   instructions per tetrahedron), the scatter (47: per lane and node a 16-byte and an
   8-byte read-modify-write) and the gather (24), run one after the other per block.
   The float force against its arithmetic floor (issue 21's goal: at most 2 times the
   `arith` row in cache; the bench's last full run on the Intel Xeon below: 2.04 to 2.45 in
   float, 1.69 to 1.95 in double). In float the arithmetic runs on twice the lanes of a
   register, so the gather and scatter, which move the same 8 node accesses per
   tetrahedron as in double, weigh twice as much. Changed (bit-identical to the scalar path,
   tests/test_heml.c test_vector_paths_match_scalar in the float and double builds):
   - the Neo-Hookean force pass is software-pipelined (heml__chunk_forces_nh, a chunk at a
     time, for the fast materials in the plain force pass): heml__forces_nh's three stages
     are functions of their own, and between them a block gathers the next block's links
     (after the first stage, which consumes b->e) and scatters the previous block's forces
     (after the volumetric stage, before the last stage overwrites b->f); a chunk's last
     block is scattered after its loop. The scatters keep their order, so the sums are the
     same.
   - in float builds with AVX, when every material takes that kernel, the pass scatters into
     m->force4 (nodes padded to 4 components, 16-byte aligned: MEMORY) with one aligned
     16-byte read-modify-write per lane and node (heml__scatter_vecf4: a 4 x 4 transpose per
     128-bit half gives 8 lanes' (x, y, z, z) at once), then copies x, y, z to the 3n
     forces.
   - with AVX-512 VL the pass's float gather puts lanes q and 4 + q in the halves of one
     256-bit register (a zeroing masked load, then a merging one 16 bytes below the node
     with mask bits 4 to 6), so a transpose per half moves 8 lanes (heml__gather_vecf8).
     The other passes keep the 4-lane gather: in the stiffness product this one cost 3 to
     5 % (5.96-5.97 -> 6.27-6.33 ns at 1e3-1e4 in float).
   - the float scatter's 8-byte (x, y) moves go through memcpy (heml__ld2f, heml__st2f):
     the cast double pointers they replace were misaligned accesses (UBSan, in a
     sanitizer build for the native target; the Makefile's sanitizer build targets generic
     x86-64 and never compiled this code).
   Measured (a harness on the bench's adapter: heml_compute_forces, the adapter's arith row
   and heml_apply_stiffness on the bench's 5-tetrahedron cubes after its step, old and new
   builds alternated, minimum of 10 rounds of 3 x 2e6 tetrahedron evaluations; Intel Xeon,
   Sapphire Rapids class, KVM, 2 vCPUs, gcc 12 -O3 -march=native, load about 1 from other
   jobs), ns per tetrahedron at 1,080 / 10,985 tetrahedra, force (arith), force / arith:
                   before                          after
       float       7.40 (3.19) / 7.43 (3.15)       6.26 (3.27) / 6.34 (3.22)
                   2.32 / 2.36                     1.91 / 1.97
       double      9.55 (5.44) / 9.77 (5.00)       9.29 (5.56) / 9.37 (5.02)
                   1.76 / 1.95                     1.67 / 1.87
   (per round, float: 2.31-2.36 / 2.35-2.43 before, 1.87-1.93 / 1.96-1.98 after; earlier
   states of the change at load 5 to 7: 1.92-1.98 / 1.97-2.03). The stiffness product in
   the same series: float 5.93 / 5.96 -> 5.97 / 6.04, double 8.36 / 8.72 -> 8.20 / 8.73
   (unchanged). The bench itself (`build/bench/bench --parts kernels --filter
   heml/neo-hookean/ --threads 1 --repeats 5`, its medians, old and new alternated, 2 runs
   each, load about 1, and once more with the final code): float force / arith 2.34-2.39 /
   2.37-2.39 -> 1.93 / 1.94-2.00 at 1e3 / 1e4 (2.46-2.48 -> 2.07-2.12 at 1e5, 2.36-2.53 -> 2.18-2.28 at 1e6, where the padded
   nodes move a third more bytes: the force still 4 to 7 % faster there), double 1.92-1.93 /
   2.04-2.07 -> 1.84-1.86 / 1.91-1.93. So the float force is 15 % faster in cache and at
   1.9 to 2.0 times its floor: the goal is met at 1e3 and at its edge at 1e4, with no
   margin; double 3 % faster. The arith row rose by 2 % with the split of heml__forces_nh
   into three functions (it calls the same three: the floor is the force's own arithmetic,
   so the force paid the same 2 %). Instructions (callgrind, x86-64-v3, which has no
   AVX-512, 10,985 tetrahedra, per tetrahedron): float force 123 -> 111 (the scatter 54 ->
   42), arith 38 -> 39; double force 159 -> 157, arith 77 -> 79. Steps, in the same
   harness, float force: a scatter of (x, y) pairs by two unpacks (1 shuffle a tetrahedron
   where the transposes and z extractions take 12) with the pipelining 7.6-8.0 -> 7.3-7.5
   ns (that scatter then dropped: no gain left in the stiffness product, whose scatter it
   was), the padded scatter 7.05-7.24 -> 6.55-6.85, the 8-lane gather 1 to 2 % more (gather
   alone 1.42-1.46 -> 1.28-1.37 ns), the pipelined loop as a function per chunk
   (heml__chunks' own loop left as it was) 2 % more. Tried and not kept: vgatherdps (16
   lanes, 12 gathers a block): the gather alone 1.6-1.7 against 1.45 ns but the force
   10.1-10.4 against 7.9-8.1 ns, the 512-bit instructions slowing the arithmetic around them (its
   arith row 3.6 -> 3.7-4.0 in the same program); 4 lanes a 512-bit register by masked
   merging loads: gather 2.0-2.2 ns, force 10.4 (the same); masked 3-component stores in
   the float scatter (AVX-512 VL): scatter 9.2-9.5 against 2.9 ns (no store forwarding from
   masked stores to the next lane's load, as on the Zen 5); the pair read as 16 bytes folded
   into the add (4 instructions a tetrahedron fewer): no faster (the reads that straddle
   two buffer stores miss store forwarding); node offsets 3 idx formed per block by vector
   adds: scatter 3.0-3.1 against 2.75-2.9 ns; the scatter before the volumetric stage, or
   the gather after it: 1 to 3 % slower. Conflicts are not what bounds the scatter: on the
   bench's beams a lane's node is shared by 5 of the block's 64 (lane, node) slots on
   average (33 at most), yet an index set with 64 distinct nodes in every block scatters in
   the same time. The force now runs at about 5 instructions a cycle in cache, so what is
   left is the count of node moves (about 72 of the 111 instructions): fewer would need the
   node traffic of a block cut (a node shared by 5 slots moves 5 times; accumulating a
   block's shared nodes needs a per-block table and changes the sums' order) or nodes
   padded in the state itself (u as 4n: an interface change). Not done; double's scatter
   into padded nodes (32 bytes a node more) was not tried.
   Static solve (bench/, R1 steel cantilever, Neo-Hookean, double, 5-tetrahedron cells):
   3 ms at 32 x 1 x 1 cells (396 dof), 74 ms at 128 x 4 x 4, 1.0 s at 256 x 8 x 8 (62,451
   dof), 4 Newton iterations each; R2 (large deformation) 2.1 s at 96 x 6 x 6 (14,259
   dof). Without the coarse space the same solves took 10 ms, 1.2 s and 21 s.

   LIMITS
       - Linear (P1) tetrahedra: they lock in bending and near incompressibility (nu close
         to 0.5 or a stiff penalty): refine the mesh across thin parts, and set
         desc.nodal_pressure = 2 (or 1) for nearly incompressible bodies (NEAR-INCOMPRESSIBLE
         BODIES), which removes the volumetric locking, not the bending one.
       - nodal_pressure = 1: the static solve's Krylov iterations still grow with the bulk-
         to-shear ratio (12 to 30 times more at nu = 0.4999 than at nu = 0.3; the saddle
         probe's share is cut by running it on the deviatoric stiffness first, but a
         saddle-point MINRES with a block-diagonal preconditioner was tried and is not
         robust for this inf-sup-unstable pair, NEAR-INCOMPRESSIBLE BODIES), and the nodal
         pressure oscillates between neighbouring nodes near nu = 0.5 (a checkerboard: read
         it smoothed three times, or use nodal_pressure = 2, whose pressure is smooth and
         whose static solve has a preconditioner whose Krylov counts do not grow with the
         bulk modulus: 1.3 to 2.3 times the nu = 0.3 count at 0.4999 on the meshes measured,
         4 on a 6,561-node beam, the rest Newton's growing iteration count; PRESSURE
         AGGREGATES; the implicit steps' solves do not use it); nodal_pressure = 2 holds
         the volume patch by patch, so on
         very coarse meshes (a few aggregates) a body's internal volume changes return only
         at the shear stiffness's pace and large-deformation Newton solves may need more
         iterations; either costs the vectorised Neo-Hookean kernels and the St Venant-Kirchhoff
         and Mooney-Rivlin differential kernels (the general path runs)
         and two extra passes; not for mass-spring (HEML_ERR_NODAL_PRESSURE) nor for user
         laws without second derivatives (the continuation of U needs U'').
       - The semi-explicit integrator is conditionally stable. The divergence check
         (HEML_ERR_DIVERGED) catches growth of more than twice the energy the body was
         given, so slower growth below that still passes: respect the time-step estimate.
         heml_stable_time_step is a rest-state estimate: below J0 the volumetric tangent
         of the continuation is (lambda (1 - ln J0) + mu) / J0^2 for Neo-Hookean, about 12
         lambda at J0 = 0.4 instead of lambda + 2 mu, and a flattened tetrahedron's
         altitude shrinks with J, so while tetrahedra are inverted the stable step is
         about 3 times smaller or less: use a third of the estimate, or the implicit
         integrator, to recover inverted meshes (a released inverted tetrahedron at half
         the estimate: HEML_ERR_DIVERGED at its first step).
       - HEML_IMPLICIT_EULER at large steps on nearly incompressible P1 meshes needs many
         Newton iterations (about 140 for a 1 m beam at nu = 0.4999, dt = 1 s) and the
         static solve of the same beam from rest, a large rotation of a locked mesh, does
         not converge within its caps (HEML_ERR_NO_CONVERGENCE; from the state the damped
         dynamics reach, 1 increment): both say so rather than return a wrong answer.
       - St Venant-Kirchhoff has no uniaxial state beyond a stretch where its lateral
         contraction would take J below zero (s = 2 at nu = 0.4): there, and wherever a
         tetrahedron ends below J0, the answer's stress is that of the J0 guard (our
         continuation), not the law's; heml_solve_static and the steps still succeed (the
         guarded law is a valid hyperelastic law) and report those tetrahedra in
         stats.below_threshold: check it when the law's own answer matters.
       - The linearised implicit step's linear solve must converge: under strong
         compression or inversion CG meets negative curvature and MINRES takes over
         (slower); a solve capped by cg_max_iterations fails the step rather than return an
         unconverged one.
       - The implicit steps' coarse correction (IMPLICIT COARSE CORRECTION) uses the rest
         state's small-strain stiffness K0, not the tangent: under large rotations or
         strains it helps less (never wrongly: CG checks its answer). Its automatic mode
         turns it on after one Jacobi-only step that needed HEML_COARSE_MIN_ITERATIONS
         iterations a solve and keeps it on (a later, much smaller dt keeps paying its
         cost per iteration: set implicit_coarse = -1 for such runs); meshes under 96 nodes
         have none. tensormass.h's implicit steps have their own (its SOLVERS, issue 21;
         on its linear model K is exact, so its A_c is P^T (D + c K) P).
       - St Venant-Kirchhoff softens in compression (the stress falls to zero as a
         tetrahedron flattens, sec. 4.2); the J0 guard keeps it from settling inverted, but
         a homogeneous uniaxial compression is unstable in the law itself beyond about
         s = 0.67 at nu = 0.3 (the cube of examples/heml_compression.c shears sideways
         there), and P_zz has its extremum at s = 1/sqrt(3).
       - Eq. 26 with lambda < 0 (nu below about -0.5): the tangent continuation below J0 is
         no longer restoring (its slope lambda (1 - ln J0) + mu turns negative).
       - Symmetric bodies past a bifurcation (squashed, buckled) have several minima of equal
         energy, mirror images of each other. By default heml_solve_static refuses the
         symmetric saddle (HEML_ERR_UNSTABLE) rather than pick one; with leave_saddles = 1 it
         returns one of them, and which one depends on the path (one call or increments)
         and the round-off: compare such answers by energy, not by node positions (the
         mass-spring cube above, float: one call and 8 increments end 0.65 m apart at the
         same W/E 0.1090434, as double does, within 4e-8). Dynamics are not checked:
         implicit and explicit steps from a symmetric state stay symmetric (in exact
         arithmetic too), so damped dynamics can settle on the saddle.
       - Mass-spring networks: central forces only (Poisson ratio pinned near 1/4, shear
         stiffness set by the mesh), not inversion-safe.
       - Float builds: forces are exactly zero at rest and carry a relative round-off of
         about 1e-7 of the forces themselves, but the state u is stored in float, so a
         strain is resolved to about eps |u| / (h |strain|) (eps = 6e-8, h the element
         size): deflections and rigid motions large against the strains cost digits. On the
         steel cantilever R1 (strains 1e-4, tip 0.05 to 0.15 m) the static solve's residual
         stalls at the stiffness times one ulp of u, where the energy-norm error is 3e-5 at
         one cell across, 8e-5 at two, 1.2e-4 at three, 2.8e-4 at six and 3.9e-4 at eight:
         with float's default static_tolerance (1e-4) the solve succeeds at one and two
         cells across and returns HEML_ERR_ROUND_OFF from three on; with 5e-4 it succeeds
         at every level and the tip deflection is within 1e-4 of double's. Softer bodies
         with larger strains (R2: within 2e-5 of double) are not limited.
         heml_set_positions rounds u = x - X once (at 1e3 m from the origin that is
         6e-5 m); heml_set_displacements sets u exactly. Use double for stiff slender
         bodies that need more than 3 to 4 digits.
       - User laws (HEML_USER): s0 = 2 w_1 + 4 w_2 + w_J is summed from the callbacks'
         values, so their rest state cancels only to the callbacks' round-off (eps times
         the moduli: in float, the forces of strains below about 1e-5 drown) and their
         energies lose relative accuracy at small strains; the built-in laws form both
         without cancellation.
       - HEML_BDF2 needs a constant dt and an undisturbed history: every pin call (also
         heml_set_displacement to drive a node each step), state setter, other integrator
         or failed step restarts it with one implicit Euler step, so a node driven every
         step makes every step implicit Euler (first order). Modal analysis: the cost is
         p = max(2 count, count + 8) Krylov solves per iteration; heml_probe_create scans
         every tetrahedron for each point outside or on the surface of the body.
       - Do not compile the implementation with -ffast-math: reassociation would undo the
         cancellation-free sums (and the rounding correction of ln J).

   HISTORY
       unreleased (issue 21, solvers) the implicit steps' Krylov solves take the static
             solve's coarse correction with the step's operator (desc.implicit_coarse,
             default automatic; stats.coarse_solves, coarse_factors; IMPLICIT COARSE
             CORRECTION): 3 to 15 times fewer CG iterations on slender bodies at large
             dt, answers within the solve tolerances; up to 2.4 MB more per model.
       unreleased (issue 21) the Neo-Hookean force pass software-pipelined (the next
             block's gather and the previous block's scatter between the stages); in
             float with AVX its scatter into nodes padded to 4 (16 bytes a node more), and
             with AVX-512 VL an 8-lane gather: the float force 15 % faster in cache, at 1.9
             to 2.0 times its arithmetic floor; results bit-identical. See PERFORMANCE.
       unreleased (issue 21) vector gather and scatter where the target has AVX (AVX-512 VL
             masks where present; HEML_NO_SIMD for the scalar path), bit-identical; the
             spring force 15x faster (no differential terms on an unset workspace) and its
             square roots vectorised; Mooney-Rivlin's J^-1/3 by a branch-free Newton cube
             root (forces change by round-off). See PERFORMANCE, issue 21.
       unreleased (issue 19) HEML_BDF2 (second order, the same Newton minimisation as
             implicit Euler; the model keeps its history, 2 more 3n vectors, and 2 3n
             scratch vectors); point probes (heml_probe_*); modal analysis (heml_modal_*).
             Existing integrators' results unchanged.
       unreleased (issue 20) extension points: laws, integrators and linear solvers through
             one private table each (heml__laws, heml__integrators, heml__linear_solvers;
             see HOW TO EXTEND); HEML_LAW_COUNT, HEML_INTEGRATOR_COUNT, heml_linear_solver
             and desc.linear_solver; the Neo-Hookean kernels run only for laws whose
             fast_path flag is set; results bit-identical to 0.3.0.
       0.3.0 (2026-12-02) no silent wrong answers (issue 18): the static solve is a
             continuation with a tangent predictor, an energy line search, a
             Levenberg-Marquardt shift at negative curvature and an inversion acceptance
             test (allow_inversion, max_increments, min_increment); HEML_IMPLICIT_EULER is
             the Newton minimisation of the incremental potential (newton_iterations is
             its cap, default 20, newton_tolerance new) and HEML_IMPLICIT_EULER_LINEARIZED
             the old single iteration; the semi-explicit step has a divergence check
             (HEML_ERR_DIVERGED); HEML_ERR_PRECISION (precision_limit); every public
             function is renamed in float builds; a static answer must be a minimum (a
             saddle fails with HEML_ERR_UNSTABLE, or leave_saddles = 1 descends from it);
             a garbage description no longer crashes
             heml_create; a load whose squared norm overflows fails; the stats have the
             names shared with tensormass.h and frames.h (residual, increments,
             increment_cuts, line_search_cuts, first eleven fields in a common order).
       0.2.1 (2026-12-01) passes colour groups of consecutive chunks (compact pieces of
             the mesh) and the tetrahedra are ordered by their lowest node: large and
             randomly ordered meshes run 1.3 to 5 times faster; the Neo-Hookean force
             runs in short stage loops (about 15 % faster); results change in their
             last digits (the order of the sums changed), still bit-identical across
             thread counts.
       0.2.0 (2026-12-01) displacements as the state (heml_displacements,
             heml_set_displacements; heml_positions is rest + u); forces, differentials and
             energies formed from H = du V^-1 without rest cancellation (float resolves
             small strains; 10 rest constants per tetrahedron instead of 8); static solve by
             inexact Newton with CG, a residual-or-energy line search and honest stops
             (new HEML_ERR_ROUND_OFF; float's default static_tolerance 1e-4); the implicit
             step fails (HEML_ERR_NO_CONVERGENCE) instead of accepting an unconverged CG.
       0.1.0 (2026-12-01) first release: St Venant-Kirchhoff, Neo-Hookean and Mooney-Rivlin
             (incompressible and compressible), mass-spring and user laws, inversion
             handling, Prony viscosity, semi-explicit and implicit Euler, static solve.

   Licence at the end of the file. */
#ifndef HEML_H
#define HEML_H

#include <stddef.h>

#define HEML_VERSION_MAJOR 0
#define HEML_VERSION_MINOR 3
#define HEML_VERSION_PATCH 0

#ifndef HEML_REAL
#define HEML_REAL double
#endif
typedef HEML_REAL heml_real;

#ifdef HEML_STATIC
#define HEMLDEF static
#else
#define HEMLDEF extern
#endif

/* Float builds rename every public entry point so that a float and a double translation
   unit cannot be linked together by mistake. HEML_REAL must be the single token float or
   double. */
#define HEML__IS_float 1
#define HEML__IS_double 0
#define HEML__CAT2(a, b) a##b
#define HEML__CAT(a, b) HEML__CAT2(a, b)
#if HEML__CAT(HEML__IS_, HEML_REAL)
#define HEML__FLOAT 1
#define heml_version heml_version_f32
#define heml_error_string heml_error_string_f32
#define heml_default_desc heml_default_desc_f32
#define heml_material_from_young heml_material_from_young_f32
#define heml_create heml_create_f32
#define heml_destroy heml_destroy_f32
#define heml_fix_node heml_fix_node_f32
#define heml_set_displacement heml_set_displacement_f32
#define heml_set_displacement_axes heml_set_displacement_axes_f32
#define heml_release_node heml_release_node_f32
#define heml_node_pinned heml_node_pinned_f32
#define heml_set_external_force heml_set_external_force_f32
#define heml_clear_external_forces heml_clear_external_forces_f32
#define heml_set_anchors heml_set_anchors_f32
#define heml_set_gravity heml_set_gravity_f32
#define heml_set_mass_damping heml_set_mass_damping_f32
#define heml_set_solver heml_set_solver_f32
#define heml_set_newton_iterations heml_set_newton_iterations_f32
#define heml_set_inversion_threshold heml_set_inversion_threshold_f32
#define heml_reset_viscous_state heml_reset_viscous_state_f32
#define heml_step heml_step_f32
#define heml_step_ex heml_step_ex_f32
#define heml_solve_static heml_solve_static_f32
#define heml_compute_forces heml_compute_forces_f32
#define heml_apply_stiffness heml_apply_stiffness_f32
#define heml_kernel_bytes heml_kernel_bytes_f32
#define heml_node_count heml_node_count_f32
#define heml_tet_count heml_tet_count_f32
#define heml_positions heml_positions_f32
#define heml_displacements heml_displacements_f32
#define heml_velocities heml_velocities_f32
#define heml_rest_positions heml_rest_positions_f32
#define heml_masses heml_masses_f32
#define heml_set_positions heml_set_positions_f32
#define heml_set_displacements heml_set_displacements_f32
#define heml_set_velocities heml_set_velocities_f32
#define heml_last_stats heml_last_stats_f32
#define heml_energy heml_energy_f32
#define heml_tet_volume_ratios heml_tet_volume_ratios_f32
#define heml_tet_stresses heml_tet_stresses_f32
#define heml_tet_stress heml_tet_stress_f32
#define heml_stable_time_step heml_stable_time_step_f32
#define heml_memory_bytes heml_memory_bytes_f32
#define heml_probe_create heml_probe_create_f32
#define heml_probe_positions heml_probe_positions_f32
#define heml_probe_displacements heml_probe_displacements_f32
#define heml_probe_velocities heml_probe_velocities_f32
#define heml_probe_destroy heml_probe_destroy_f32
#define heml_modal_default_desc heml_modal_default_desc_f32
#define heml_modal_create heml_modal_create_f32
#define heml_modal_solve heml_modal_solve_f32
#define heml_modal_count heml_modal_count_f32
#define heml_modal_frequency heml_modal_frequency_f32
#define heml_modal_shape heml_modal_shape_f32
#define heml_modal_destroy heml_modal_destroy_f32
#else
#define HEML__FLOAT 0
#endif

/* Tetrahedra below which loops run serially (parallel start-up costs more than it saves). */
#ifndef HEML_PARALLEL_MIN_TETS
#define HEML_PARALLEL_MIN_TETS 16384
#endif

/* Bytes the force kernel streams per tetrahedron (4 node indices and 10 rest constants:
   the gradients of N_1..N_3 and the rest volume), not counting the gathered displacements
   and scattered forces of its nodes (see PERFORMANCE and heml_kernel_bytes). */
#define HEML_KERNEL_BYTES_PER_TET (4 * sizeof(int) + 10 * sizeof(heml_real))

/* Error codes and their messages, one list so they cannot drift apart. */
#define HEML_ERROR_LIST(X) \
    X(HEML_OK, 0, "ok") \
    X(HEML_ERR_ARG, -1, "invalid argument (NULL pointer, bad count or non-finite value)") \
    X(HEML_ERR_ALLOC, -2, "out of memory") \
    X(HEML_ERR_DESC, -3, "description not initialised with heml_default_desc") \
    X(HEML_ERR_NODE_COUNT, -4, "node count below 4 or too large") \
    X(HEML_ERR_TET_COUNT, -5, "tetrahedron count below 1 or too large") \
    X(HEML_ERR_NODE_NOT_FINITE, -6, "rest position not finite") \
    X(HEML_ERR_INDEX_RANGE, -7, "tetrahedron node index out of range") \
    X(HEML_ERR_INDEX_REPEATED, -8, "tetrahedron uses the same node twice") \
    X(HEML_ERR_TET_DEGENERATE, -9, "degenerate (flat) rest tetrahedron") \
    X(HEML_ERR_TET_INVERTED, -10, "negatively oriented rest tetrahedron") \
    X(HEML_ERR_LAW, -11, "unknown material law") \
    X(HEML_ERR_MATERIAL, -12, "material parameters not finite or outside the law's range") \
    X(HEML_ERR_MATERIAL_INDEX, -13, "material table empty or a tetrahedron's material index out of range") \
    X(HEML_ERR_USER_LAW, -14, "user law: no first-derivative callback, or not finite, stress-free and stable at rest") \
    X(HEML_ERR_DENSITY, -15, "density not finite and > 0") \
    X(HEML_ERR_PRONY, -16, "Prony series: need alpha_i >= 0, sum alpha_i < 1, tau_i > 0") \
    X(HEML_ERR_THRESHOLD, -17, "inversion threshold J0 not in (0, 1)") \
    X(HEML_ERR_TIME_STEP, -18, "time step not finite and > 0") \
    X(HEML_ERR_DAMPING, -19, "damping coefficient not finite and >= 0") \
    X(HEML_ERR_INTEGRATOR, -20, "unknown integrator") \
    X(HEML_ERR_SOLVER, -21, "solver settings invalid (tolerance > 0, iterations >= 1)") \
    X(HEML_ERR_NOT_FINITE, -22, "result not finite; the last valid state was kept") \
    X(HEML_ERR_NO_CONVERGENCE, -23, "solver did not converge; the last valid state was kept") \
    X(HEML_ERR_NODE_RANGE, -24, "node index out of range") \
    X(HEML_ERR_TET_RANGE, -25, "tetrahedron index out of range") \
    X(HEML_ERR_NO_SECOND_DERIVATIVES, -26, "the user law gives no second derivatives (needed for the force differential)") \
    X(HEML_ERR_INVERTED, -27, "tetrahedron inverted or flat (J <= 0): a static solve or implicit step would newly invert one (allow_inversion = 0), or a Cauchy stress is undefined; the last valid state was kept") \
    X(HEML_ERR_ROUND_OFF, -28, "static solve stalled at the round-off level of the forces above static_tolerance; the last valid state was kept") \
    X(HEML_ERR_DIVERGED, -29, "explicit step failed its divergence check (energy grew beyond the work done on the body); the last valid state was kept") \
    X(HEML_ERR_PRECISION, -30, "state too far from the origin for the precision of heml_real (eps max|u| > precision_limit h_min); the last valid state was kept") \
    X(HEML_ERR_UNSTABLE, -31, "static solve converged to a saddle (an unstable equilibrium: the tangent has a direction of negative curvature); set leave_saddles = 1 to descend to a minimum; the last valid state was kept") \
    X(HEML_ERR_NODAL_PRESSURE, -32, "nodal_pressure not 0, 1 or 2, or set with a law it cannot average (mass-spring, a user law without second derivatives)")

enum {
#define HEML__ENUM(name, value, text) name = value,
    HEML_ERROR_LIST(HEML__ENUM)
#undef HEML__ENUM
    HEML_ERR_LAST_ = -33
};

typedef enum heml_law {
    HEML_STVK = 0,                          /* St Venant-Kirchhoff (table 3): mu, lambda */
    HEML_NEO_HOOKEAN = 1,                   /* compressible, eq. 26: mu, lambda */
    HEML_MOONEY_RIVLIN = 2,                 /* compressible split, eqs. 21-25: c1, c2, kappa */
    HEML_NEO_HOOKEAN_INCOMPRESSIBLE = 3,    /* table 3 + penalty: c1, kappa */
    HEML_MOONEY_RIVLIN_INCOMPRESSIBLE = 4,  /* table 3 + penalty: c1, c2, kappa */
    HEML_MASS_SPRING = 5,                   /* sec. 5.3: young_modulus */
    HEML_USER = 6,                          /* callbacks (heml_user_law) */
    HEML_LAW_COUNT                          /* number of laws (not a law): validation only */
} heml_law;

typedef enum heml_integrator {
    HEML_SEMI_EXPLICIT_EULER = 0,      /* eq. 32 (default) */
    HEML_IMPLICIT_EULER = 1,           /* backward Euler: Newton minimisation of the incremental
                                          potential to newton_tolerance, matrix-free CG, line search */
    HEML_IMPLICIT_EULER_LINEARIZED = 2, /* one linearised Newton iteration, no line search (fast,
                                          accurate only while the step is nearly linear) */
    HEML_BDF2 = 3,                      /* second-order backward differentiation: the same Newton
                                          minimisation with (2 dt / 3, (4 u_n - u_n-1) / 3, ...);
                                          its first step (and after a restart) is implicit Euler */
    HEML_INTEGRATOR_COUNT               /* number of integrators (not one): validation only */
} heml_integrator;

/* Linear solvers of the implicit steps and the static solve (desc.linear_solver). */
typedef enum heml_linear_solver {
    HEML_LINEAR_SOLVER_CG = 0, /* Jacobi-preconditioned conjugate gradient (plus the coarse space
                                  in static solves), MINRES where an indefinite system needs it */
    HEML_LINEAR_SOLVER_COUNT   /* number of linear solvers (not one): validation only */
} heml_linear_solver;

typedef enum heml_stress_kind {
    HEML_STRESS_PK1 = 0,   /* first Piola-Kirchhoff P, force per rest area, Pa */
    HEML_STRESS_CAUCHY = 1 /* Cauchy (true) stress sigma = P F^T / J, Pa; needs J > 0 */
} heml_stress_kind;

/* Custom allocator: alloc(size, align, user) returns memory aligned to `align` (a power
   of two <= 64) or NULL; free(ptr, size, user) releases it. */
typedef struct heml_allocator {
    void *(*alloc)(size_t size, size_t align, void *user);
    void (*free)(void *ptr, size_t size, void *user);
    void *user;
} heml_allocator;

/* An engine's job system: run task(task_context, begin, end) over a partition of
   [0, item_count) (any split, any threads) and return when every item is done. */
typedef void (*heml_task_fn)(void *task_context, int begin, int end);
typedef void (*heml_parallel_for_fn)(int item_count, heml_task_fn task, void *task_context,
                                     void *user);

/* One Prony term (eq. 15): relaxation weight alpha_i (>= 0) and time tau_i (s, > 0). */
typedef struct heml_prony_term {
    heml_real alpha;
    heml_real tau;
} heml_prony_term;

/* Points at which a user law is evaluated: `count` values of each array. The inputs are
   the invariants I1 = tr C, I2 = (I1^2 - tr C^2) / 2 and J = det F (J >= J0 always: the
   library continues the law below J0 itself); each callback fills its outputs (Pa). */
typedef struct heml_law_points {
    int count;
    const heml_real *I1, *I2, *J;
    heml_real *w;                               /* energy density w, J/m^3 */
    heml_real *w_1, *w_2, *w_J;                 /* dw/dI1, dw/dI2, dw/dJ */
    heml_real *w_11, *w_12, *w_1J, *w_22, *w_2J, *w_JJ; /* second derivatives */
} heml_law_points;

/* An isotropic law given by its derivatives. `first` is required; `second` is needed by
   the implicit integrator, heml_solve_static and heml_apply_stiffness (they return
   HEML_ERR_NO_SECOND_DERIVATIVES without it) and gives the J0 continuation its tangent
   (without it the volumetric stress is held at its J0 value below J0); `energy` (may be
   NULL) feeds heml_energy. The law must be stress-free at rest (2 w_1 + 4 w_2 + w_J = 0
   at I1 = I2 = 3, J = 1) and, when `second` is given, have positive small-strain shear
   and bulk moduli: heml_create checks both. Callbacks run on the calling thread or on
   worker threads (parallel_for / OpenMP), on blocks of up to 16 points, and must be
   thread-safe and deterministic. Coupled laws (whose I-derivatives depend on J) are
   continued below J0 to first order in J only, so there the force is not exactly the
   gradient of the reported energy; laws of the form f(I1, I2) + g(J) are exact. */
typedef struct heml_user_law {
    void (*energy)(heml_law_points *points, void *user);
    void (*first)(heml_law_points *points, void *user);
    void (*second)(heml_law_points *points, void *user);
    void *user;
} heml_user_law;

/* A material: one law and its constants (only those the law uses are read; see heml_law),
   its density and an optional Prony series. heml_material_from_young fills the constants
   of any law from a Young's modulus and a Poisson ratio. */
typedef struct heml_material {
    heml_law law;
    heml_real mu, lambda;     /* Pa: Lame coefficients (St Venant-Kirchhoff, eq. 26) */
    heml_real c1, c2;         /* Pa: Mooney-Rivlin / table 3 constants (c2 unused by NH) */
    heml_real bulk_modulus;   /* Pa: kappa of the penalty or volumetric term */
    heml_real young_modulus;  /* Pa: mass-spring stiffness k = E Vol / L^2 */
    heml_real density;        /* kg/m^3, default 1000 */
    const heml_prony_term *prony; /* prony_count terms (read at create), or NULL */
    int prony_count;
    heml_user_law user;       /* HEML_USER */
} heml_material;

typedef struct heml_desc {
    /* mesh (read during heml_create only) */
    const heml_real *rest_positions; /* 3 * node_count coordinates, m */
    int node_count;                  /* >= 4 */
    const int *tets;                 /* 4 * tet_count zero-based node indices, positive
                                        orientation: (x1-x0).((x2-x0)x(x3-x0)) > 0 */
    int tet_count;                   /* >= 1 */

    /* material: one for every tetrahedron, or a table and an index per tetrahedron */
    heml_material material;          /* default: Neo-Hookean, E = 1e4 Pa, nu = 0.3, 1000 kg/m^3 */
    const heml_material *materials;  /* material_count entries, or NULL to use `material` */
    int material_count;
    const int *tet_material;         /* tet_count indices into materials, or NULL (all 0) */
    heml_real inversion_threshold;   /* J0 of sec. 4.4, in (0, 1), default 0.4 */
    int nodal_pressure;              /* 0 (default): plain P1 tetrahedra; 1: average nodal
                                        pressure tetrahedra for nearly incompressible bodies
                                        (NEAR-INCOMPRESSIBLE BODIES): every law but mass-spring,
                                        user laws with second derivatives; 2 (recommended
                                        there): the same over pressure aggregates, no
                                        pressure checkerboard (PRESSURE AGGREGATES) */
    int stiffness_cache;             /* 1 (default): the Neo-Hookean, St Venant-Kirchhoff and
                                        Mooney-Rivlin stiffness products cache per tetrahedron
                                        what their linearisation point fixes (PERFORMANCE,
                                        MEMORY: 17, 21 or 26 reals a tetrahedron); 0: no cache,
                                        no memory */

    /* dynamics */
    heml_real mass_damping;          /* 1/s: damping force -mass_damping m v, default 0 */
    heml_real gravity[3];            /* m/s^2, default (0, 0, -9.81) */
    heml_real time_step;             /* s, default 1e-3, used by heml_step */
    heml_integrator integrator;      /* default HEML_SEMI_EXPLICIT_EULER */
    int newton_iterations;           /* HEML_IMPLICIT_EULER: cap of Newton iterations per step,
                                        default 20 */
    heml_real newton_tolerance;      /* HEML_IMPLICIT_EULER: residual of the step's equations
                                        relative to its largest force term, default 1e-6 (1e-4 float) */
    heml_real cg_tolerance;          /* relative residual of the implicit step's CG, default 1e-6
                                        (1e-5 float) */
    int cg_max_iterations;           /* Krylov iterations per linear solve, default 1000 */
    heml_linear_solver linear_solver; /* every linear solve (implicit steps, static solve and its
                                        saddle probe), default HEML_LINEAR_SOLVER_CG */
    int implicit_coarse;             /* the implicit steps' Krylov solves (issue 21, SOLVERS): 0
                                        (default) add the static solve's coarse correction when it
                                        pays (once a step's Jacobi-only solves need
                                        HEML_COARSE_MIN_ITERATIONS each), 1 always, -1 never (Jacobi
                                        only); meshes under 96 nodes have no coarse space */
    int static_max_iterations;       /* Newton iterations of heml_solve_static per load step,
                                        default 50 */
    heml_real static_tolerance;      /* its residual relative to the larger of the loads and the
                                        internal forces (see STATIC SOLVE), default 1e-9 (1e-4 float) */
    int max_increments;              /* heml_solve_static: continuation increments tried (accepted
                                        and cut), default 64 */
    heml_real min_increment;         /* heml_solve_static: smallest load fraction of an increment
                                        before giving up, default 1e-4 */
    int allow_inversion;             /* 0 (default): a static solve or implicit step that would
                                        leave more tetrahedra inverted (J <= 0) than at its start
                                        fails with HEML_ERR_INVERTED; 1: allowed (stats.inverted) */
    int leave_saddles;               /* heml_solve_static where its answer is a saddle (an unstable
                                        equilibrium: a buckled or squashed body at its symmetric
                                        state): 0 (default) fails with HEML_ERR_UNSTABLE; 1 moves
                                        off it along its negative curvature to a minimum (one of
                                        several equal ones where the body is symmetric: which one
                                        depends on the path and the round-off) */
    heml_real precision_limit;       /* steps and solves fail with HEML_ERR_PRECISION when
                                        eps(heml_real) max|u| > precision_limit h_min (h_min the
                                        shortest rest edge): the rounding of the state may not fake
                                        strains above it; default 1e-4, 0 disables the check */

    /* environment */
    heml_allocator allocator;          /* all NULL: HEML_MALLOC / HEML_FREE */
    heml_parallel_for_fn parallel_for; /* NULL: OpenMP if compiled with it, else serial */
    void *parallel_user;
    void (*log)(int code, const char *message, void *user); /* validation details, or NULL */
    void *log_user;

    unsigned int internal_cookie;      /* set by heml_default_desc; do not touch */
} heml_desc;

/* Statistics of the last step, solve or force evaluation (read with heml_last_stats). The
   first eleven fields have the same names and meanings in tensormass.h and frames.h. */
typedef struct heml_stats {
    int newton_iterations;     /* Newton iterations, summed over increments (1 for the
                                  linearised implicit step; 0 for a semi-explicit step) */
    int cg_iterations;         /* CG (or MINRES) iterations, summed */
    heml_real cg_residual;     /* relative residual |r| / |b| of the last Krylov solve */
    heml_real residual;        /* final nonlinear residual over its reference scale (static
                                  solve, HEML_IMPLICIT_EULER); 0 where there is none */
    int increments;            /* heml_solve_static: continuation increments accepted (1: the
                                  whole load at once) */
    int increment_cuts;        /* heml_solve_static: increments cut back after a failed attempt */
    int line_search_cuts;      /* line-search step reductions, summed */
    int negative_curvature;    /* Krylov solves that met a direction of negative curvature (the
                                  tangent was not positive definite there) */
    int inverted;              /* tetrahedra with J <= 0 at the last force evaluation (the
                                  answer's, after a successful solve or implicit step) */
    int force_evaluations;     /* force passes */
    int stiffness_products;    /* force-differential passes */
    int below_threshold;       /* tetrahedra with J < J0 at the last force evaluation: their
                                  stress is the J0 continuation's, not the law's (for St
                                  Venant-Kirchhoff: the inversion guard's; see LIMITS) */
    int coarse_solves;         /* implicit steps: Krylov solves preconditioned with the coarse
                                  correction (desc.implicit_coarse; SOLVERS) */
    int coarse_factors;        /* implicit steps: factorisations of its coarse matrix (0 when the
                                  last one was reused: same dt, mass and pins) */
} heml_stats;

/* Energies of the current state (heml_energy). */
typedef struct heml_energies {
    double kinetic;       /* J, 1/2 sum m v^2 */
    double elastic;       /* J, sum Vol w (the hyperelastic energy, without the Prony state);
                             NaN for a user law without an energy callback */
    double gravitational; /* J, -sum m g . (x - X) (zero at rest) */
    double external;      /* J, -sum f_ext . (x - X) */
} heml_energies;

typedef struct heml_model heml_model;

/* Library version string "major.minor.patch". */
HEMLDEF const char *heml_version(void);
/* Name of an error code (static string). */
HEMLDEF const char *heml_error_string(int code);

/* A description with the documented defaults; always start from it. */
HEMLDEF heml_desc heml_default_desc(void);
/* A material of the given law whose small-strain response is that of Young's modulus E
   (Pa) and Poisson ratio nu: SVK and eq. 26 take mu, lambda; the incompressible forms
   c1 = mu/2 (Neo-Hookean) or c1 = c2 = mu/4 and kappa = K - 4 (c1 + 4 c2) / 3 (which
   needs nu > 1/4 for Mooney-Rivlin); the split Mooney-Rivlin c1 = c2 = mu/4, kappa = K;
   springs E. Density 1000 kg/m^3, no Prony terms. Invalid E or nu give constants that
   heml_create refuses. */
HEMLDEF heml_material heml_material_from_young(heml_law law, double young_modulus,
                                               double poisson_ratio);
/* Validates the description and creates a model in *out (NULL on failure). Allocates
   all the model's memory; the description's arrays may be freed afterwards. */
HEMLDEF int heml_create(const heml_desc *desc, heml_model **out);
/* Frees the model and everything it owns. NULL is allowed. */
HEMLDEF void heml_destroy(heml_model *m);

/* ---- boundary conditions and loads (no allocation) ---- */

/* Pins node i where it is now (all three axes). */
HEMLDEF int heml_fix_node(heml_model *m, int i);
/* Pins node i at rest position + u (m); the next step moves it there. */
HEMLDEF int heml_set_displacement(heml_model *m, int i, const heml_real u[3]);
/* Pins the axes of node i named in `axes` (bit 0 x, bit 1 y, bit 2 z) at rest + u on those
   axes, and frees the others (rollers, symmetry planes). axes = 0 releases the node. */
HEMLDEF int heml_set_displacement_axes(heml_model *m, int i, unsigned axes, const heml_real u[3]);
/* Releases a pinned node (all axes). */
HEMLDEF int heml_release_node(heml_model *m, int i);
/* The pinned axes of node i (0 free, 7 fully pinned), or < 0 on error. */
HEMLDEF int heml_node_pinned(const heml_model *m, int i);
/* Constant external force on node i, N (replaces the previous one). */
HEMLDEF int heml_set_external_force(heml_model *m, int i, const heml_real f[3]);
/* Sets every external force to zero. */
HEMLDEF void heml_clear_external_forces(heml_model *m);
/* Anchors (issue 14; the same hook as frm_model_set_anchors and tmass_set_anchors): zero-
   length springs from nodes[a] to the point targets[3a..3a+2] (m) with stiffness
   stiffness[a] (N/m, >= 0), energy sum_a k_a / 2 |x_nodes[a] - t_a|^2. They are part of the
   model from then on: every force, energy, stiffness product (heml_apply_stiffness, the
   solvers' Krylov products and Jacobi preconditioner), static solve, step and modal
   analysis includes them, exactly (force -k (x - t), differential -k dx). This is how a
   mesh is glued to another model (frames.h COUPLING: the targets are the other model's
   mapped points, updated between solves). The three arrays are the caller's: kept by
   pointer and read at every evaluation until the next call, so they must outlive the
   model's use of them (update targets in place or call again). count = 0 removes every
   anchor (the arrays may then be NULL); default none (results bit-identical to a model
   without the call). A node may carry several anchors (they add). Errors (nothing kept):
   HEML_ERR_ARG (NULL model or array, count < 0, a stiffness negative or not finite, a target
   not finite), HEML_ERR_NODE_RANGE (a node index). */
HEMLDEF int heml_set_anchors(heml_model *m, int count, const int *nodes, const heml_real *stiffness,
                             const heml_real *targets);
/* Gravity, m/s^2. */
HEMLDEF int heml_set_gravity(heml_model *m, const heml_real g[3]);
/* Mass damping coefficient (1/s, >= 0): damping force -alpha m v. */
HEMLDEF int heml_set_mass_damping(heml_model *m, heml_real alpha);
/* CG tolerance (relative residual, > 0) and iteration cap (>= 1) for later solves (the
   linearised step fails at the cap; Newton solves use the cap per Krylov solve). */
HEMLDEF int heml_set_solver(heml_model *m, heml_real tolerance, int max_iterations);
/* Cap of Newton iterations per HEML_IMPLICIT_EULER step (>= 1; default 20). */
HEMLDEF int heml_set_newton_iterations(heml_model *m, int iterations);
/* The inversion threshold J0 (in (0, 1)) for later evaluations. */
HEMLDEF int heml_set_inversion_threshold(heml_model *m, heml_real J0);
/* Sets the viscous (Prony) state to zero: the material forgets its history. */
HEMLDEF void heml_reset_viscous_state(heml_model *m);

/* ---- simulation ---- */

/* One step with the description's time step and integrator. */
HEMLDEF int heml_step(heml_model *m);
/* One step of dt seconds with the given integrator. */
HEMLDEF int heml_step_ex(heml_model *m, heml_real dt, heml_integrator integrator);
/* Moves the free degrees of freedom to the static equilibrium under gravity, external
   forces and the pinned axes: the minimum of the potential, by continuation (loads and
   pin moves in adaptive increments, each from a tangent predictor) and Newton with
   preconditioned CG and an energy line search (the fully relaxed Prony response); sets
   velocities to zero and the viscous state to its relaxed value. Returns HEML_OK only
   when the residual is below static_tolerance, the answer is a minimum (not a saddle:
   HEML_ERR_UNSTABLE, or with leave_saddles = 1 the solve descends from it) and
   (allow_inversion = 0) no more tetrahedra are inverted than at the start (see STATIC
   SOLVE). On failure the state is
   unchanged: HEML_ERR_NO_CONVERGENCE (caps reached: static_max_iterations per increment,
   max_increments, min_increment), HEML_ERR_ROUND_OFF (the residual stopped falling at the
   round-off level of the forces, above the tolerance: loosen it or use double),
   HEML_ERR_UNSTABLE (a saddle), HEML_ERR_INVERTED, HEML_ERR_PRECISION,
   HEML_ERR_NOT_FINITE. */
HEMLDEF int heml_solve_static(heml_model *m);

/* ---- kernels (for benchmarks and custom solvers) ---- */

/* Evaluates the elastic forces (Prony included, with the desc time step; no gravity,
   external force or damping) at the current displacements into the model's array of 3n
   values, N, and returns it. One force pass; no allocation, no change of state. */
HEMLDEF const heml_real *heml_compute_forces(heml_model *m);
/* The force differential at the current positions: out = (d f / d x) dx (3n values each,
   N for dx in m; out is overwritten, caller-owned), i.e. minus the tangent stiffness
   times dx, exact for every law (the J0 continuation and Prony scaling included). One
   pass; HEML_ERR_NO_SECOND_DERIVATIVES for a user law without `second`. With the stiffness
   cache (desc.stiffness_cache, Neo-Hookean, St Venant-Kirchhoff and Mooney-Rivlin
   tetrahedra) the first call after a change of the state fills it, the next ones at the
   same state read it (bit-identical results). */
HEMLDEF int heml_apply_stiffness(heml_model *m, const heml_real *dx, heml_real *out);
/* Bytes one force pass (kernel 0) or one differential pass (kernel 1) must move at least:
   the tetrahedron stream (HEML_KERNEL_BYTES_PER_TET each, plus Prony data)
   and each node's displacement (and dx) read once and force written once; for kernel 1
   the cached tetrahedra (desc.stiffness_cache) stream their 4 indices and 17 (Neo-
   Hookean), 21 (St Venant-Kirchhoff) or 28 (split Mooney-Rivlin) reals of cache instead,
   and read dx only. */
HEMLDEF int heml_kernel_bytes(const heml_model *m, int kernel, size_t *read, size_t *written);

/* ---- state access (pointers into the model, valid until heml_destroy) ---- */

HEMLDEF int heml_node_count(const heml_model *m);
HEMLDEF int heml_tet_count(const heml_model *m);
HEMLDEF const heml_real *heml_positions(const heml_model *m);      /* 3n, m: rest + displacement */
/* The state: displacements from rest, u = x - X (3n, m). Forces are computed from them, so
   small deformations keep their relative precision far from the origin and in float. */
HEMLDEF const heml_real *heml_displacements(const heml_model *m);  /* 3n, m */
HEMLDEF const heml_real *heml_velocities(const heml_model *m);     /* 3n, m/s */
HEMLDEF const heml_real *heml_rest_positions(const heml_model *m); /* 3n, m */
HEMLDEF const heml_real *heml_masses(const heml_model *m);         /* n lumped masses, kg */
/* Overwrites the positions (3n values, m) or velocities (m/s) of all nodes, for example
   to start from a deformed state. Values must be finite. heml_set_positions stores
   u = x - X (rounded once: in float, positions far from the origin carry the resolution
   of their coordinates); heml_set_displacements sets u itself (exact). */
HEMLDEF int heml_set_positions(heml_model *m, const heml_real *positions);
HEMLDEF int heml_set_displacements(heml_model *m, const heml_real *displacements);
HEMLDEF int heml_set_velocities(heml_model *m, const heml_real *velocities);
/* Statistics of the last step, static solve or force evaluation. */
HEMLDEF const heml_stats *heml_last_stats(const heml_model *m);

/* ---- diagnostics (no allocation; caller-owned output arrays) ---- */

/* Energies of the current state (one energy pass). */
HEMLDEF int heml_energy(heml_model *m, heml_energies *out);
/* J = vol / Vol of every tetrahedron (tet_count values, description order). */
HEMLDEF int heml_tet_volume_ratios(const heml_model *m, heml_real *out);
/* The stress of every tetrahedron (9 * tet_count values, row-major 3x3 each, description
   order), consistent with the forces (Prony included). For HEML_STRESS_CAUCHY a
   tetrahedron with J <= 0 gets NaN and the call returns HEML_ERR_INVERTED. */
HEMLDEF int heml_tet_stresses(heml_model *m, heml_stress_kind kind, heml_real *out);
/* The same for one tetrahedron (costs a block of 16). */
HEMLDEF int heml_tet_stress(heml_model *m, int tet, heml_stress_kind kind, heml_real out[9]);
/* Estimate of the largest stable semi-explicit time step, s: half the smallest over the
   tetrahedra of altitude / sqrt((lambda + 2 mu) / rho) with small-strain moduli, at rest.
   A CFL heuristic with a safety factor of about 2 (on box meshes the scheme blew up at 1.7
   to 2.8 times it), not a guarantee: large deformations stiffen most laws, and inverted or
   flattened tetrahedra (below J0) need about a third of it or less (LIMITS). */
HEMLDEF double heml_stable_time_step(const heml_model *m);
/* Bytes held by the model. */
HEMLDEF size_t heml_memory_bytes(const heml_model *m);

/* ---- point probes (see POINT PROBES) ---- */

typedef struct heml_probe heml_probe;
/* Locates `count` material points given by their rest positions (3 per point, m) in the
   model's rest mesh, once: each point's containing tetrahedron and its barycentric
   coordinates (computed in double). A point outside every tetrahedron by no more than 1e-6
   of its nearest tetrahedron's size (in barycentric coordinates: points on the surface, up
   to rounding) takes that tetrahedron; farther out: HEML_ERR_ARG. Allocates the probe (the
   model's allocator; a temporary grid of about one cell per tetrahedron finds the
   candidates, O(count + tetrahedra) for points inside, a scan of all tetrahedra for a point
   outside or on the surface). The probe reads only the model it was made for (the same
   node count is checked). */
HEMLDEF int heml_probe_create(const heml_model *m, const heml_real *rest_points, int count, heml_probe **out);
/* The points' current positions (rest + u), displacements and velocities, 3 per point
   (caller-owned out), interpolated from the containing tetrahedron's nodes; no allocation. */
HEMLDEF int heml_probe_positions(const heml_probe *p, const heml_model *m, heml_real *out);
HEMLDEF int heml_probe_displacements(const heml_probe *p, const heml_model *m, heml_real *out);
HEMLDEF int heml_probe_velocities(const heml_probe *p, const heml_model *m, heml_real *out);
/* Frees the probe (NULL allowed). */
HEMLDEF void heml_probe_destroy(heml_probe *p);

/* ---- modal analysis (see MODAL ANALYSIS) ---- */

typedef struct heml_modal_desc {
    int count;           /* modes wanted (>= 1), the lowest; default 6 */
    int max_iterations;  /* subspace iterations before HEML_ERR_NO_CONVERGENCE, default 100 */
    heml_real tolerance; /* relative change of each wanted eigenvalue between iterations at
                            convergence, default 1e-8 (float 1e-4) */
    heml_real shift;     /* 1/s^2: sigma of K + sigma M (the shift-invert operator); < 0
                            (default -1): automatic, 1e-5 of the largest stiffness diagonal over
                            mass (free bodies' rigid modes need sigma > 0) */
} heml_modal_desc;
typedef struct heml_modal heml_modal;
/* The defaults above. */
HEMLDEF heml_modal_desc heml_modal_default_desc(void);
/* Sizes and allocates the workspace of a modal analysis of model m (the model's allocator):
   for count modes about 2 count (at least count + 8) vectors of 3n reals, three times.
   HEML_ERR_ARG for a bad description, HEML_ERR_ALLOC. */
HEMLDEF int heml_modal_create(const heml_model *m, const heml_modal_desc *d, heml_modal **out);
/* The lowest `count` natural frequencies and mode shapes of the model about its current
   state (the tangent stiffness there, K = -df/du, Prony terms as heml_apply_stiffness)
   with its pinned axes, M the lumped masses. No allocation; the model's state is not
   changed (its stats are kept). HEML_ERR_NO_CONVERGENCE after max_iterations (the previous
   results are then invalid: count reads 0), HEML_ERR_UNSTABLE when K + shift M is not
   positive definite (an unstable state: raise shift), HEML_ERR_ARG when the model has fewer
   free degrees of freedom than the workspace's vectors, or is not the one the workspace
   was sized for, HEML_ERR_NO_SECOND_DERIVATIVES, HEML_ERR_NOT_FINITE. */
HEMLDEF int heml_modal_solve(heml_modal *md, heml_model *m);
/* Modes available (count after a successful solve, else 0). */
HEMLDEF int heml_modal_count(const heml_modal *md);
/* Frequency of mode i, Hz, ascending: sqrt(lambda) / (2 pi) for K x = lambda M x (rigid
   modes of a free body: 0 within round-off; an unstable direction, lambda < 0, gives
   -sqrt(-lambda) / (2 pi)). NaN for a bad i. */
HEMLDEF double heml_modal_frequency(const heml_modal *md, int i);
/* Shape of mode i: 3n values, zero on pinned axes, M-orthonormal: x_i . M x_j = delta_ij
   with M in kg (so the shape is in 1/sqrt(kg) per unit of a modal coordinate in sqrt(kg)
   m; scale it as needed), pointing into the workspace (valid until the next solve or
   heml_modal_destroy). NULL for a bad i. */
HEMLDEF const heml_real *heml_modal_shape(const heml_modal *md, int i);
/* Frees the workspace (NULL allowed). */
HEMLDEF void heml_modal_destroy(heml_modal *md);

#endif /* HEML_H */

/* ======================================================================================
   IMPLEMENTATION
   ====================================================================================== */
#if defined(HEML_IMPLEMENTATION) && !defined(HEML_IMPLEMENTATION_ONCE)
#define HEML_IMPLEMENTATION_ONCE

/* With HEML_STATIC the functions a program does not call are unused statics. */
#if defined(HEML_STATIC) && defined(__GNUC__)
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

#ifndef HEML_MALLOC
#include <stdlib.h>
#define HEML_MALLOC(size, user) ((void)(user), malloc(size))
#define HEML_FREE(ptr, user) ((void)(user), free(ptr))
#endif
#ifndef HEML_ASSERT
#include <assert.h>
#define HEML_ASSERT(x) assert(x)
#endif

#if defined(__cplusplus)
#define HEML__RESTRICT __restrict
#else
#define HEML__RESTRICT restrict
#endif

/* the logarithm must inline into the kernels' loops for them to vectorise */
#if defined(__GNUC__)
#define HEML__INLINE static inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define HEML__INLINE static __forceinline
#else
#define HEML__INLINE static inline
#endif

/* The gather of node positions runs faster as scalar loads than as the vector gathers
   compilers otherwise emit for it (measured: 3 against 4 ns per tetrahedron on AVX2). */
#if defined(__GNUC__) && !defined(__clang__)
#define HEML__SCALAR_FN __attribute__((noinline, optimize("no-tree-vectorize")))
#else
#define HEML__SCALAR_FN
#endif
/* Short lane loops that gcc unrolls and then leaves scalar when they are inlined into a
   large caller (heml__count_lanes) stay functions of their own. */
#if defined(__GNUC__) || defined(__clang__)
#define HEML__NOINLINE __attribute__((noinline))
#else
#define HEML__NOINLINE
#endif
/* Vector intrinsics, only where the target has them (compile-time checks; never required):
   the square roots of the spring lengths (libm's sqrt keeps errno semantics, so compilers
   do not vectorise it; _mm*_sqrt_* round the same, correctly, so results are
   bit-identical to the scalar path), and the node gather and scatter (heml__gather_vec).
   HEML_NO_SIMD forces the portable scalar code. */
#if !defined(HEML_NO_SIMD) && (defined(__GNUC__) || defined(__clang__)) && defined(__AVX__)
#include <immintrin.h>
#include <stdint.h> /* (uintptr_t: heml__gather_vecf8) */
#define HEML__AVX 1
#if defined(__AVX512F__) && defined(__AVX512VL__)
#define HEML__AVX512 1 /* the gather's masked node loads with AVX-512 masks (else AVX's vmaskmov) */
#endif
#endif
#if defined(__clang__)
#define HEML__SCALAR_LOOP _Pragma("clang loop vectorize(disable)")
#else
#define HEML__SCALAR_LOOP
#endif

#define HEML__COOKIE 0x48454D4Cu /* "HEML" */
#define HEML__ALIGN 64
#define HEML__W 16          /* tetrahedra per block: the SIMD width of the kernels' loops */
/* Work units (overridable so that tests reach groups of several chunks on small meshes;
   results never depend on the thread count, whatever their values). */
#ifndef HEML__CHUNK
#define HEML__CHUNK 16      /* blocks per chunk: the unit of the per-chunk sums */
#endif
#ifndef HEML__GROUP
#define HEML__GROUP 16      /* chunks per group at most: the unit of threading and colouring */
#endif
#ifndef HEML__GROUPS_MIN
#define HEML__GROUPS_MIN 64 /* groups are made smaller until there are this many (or one chunk each) */
#endif
#define HEML__NR 10         /* rest constants per tetrahedron: grad N_1, grad N_2, grad N_3, Vol */
#define HEML__NC_NH 17      /* stiffness cache per tetrahedron, Neo-Hookean: v (9), A (6), s1, s2 (heml__diff_nh) */
#define HEML__NC_SVK 21     /* St Venant-Kirchhoff: v (9), A / sqrt(Vol) (6), Vol G S G^T (6) (heml__diff_svk) */
#define HEML__NC_MR 26      /* split Mooney-Rivlin: v, Ah, B (21), 5 scalars (heml__diff_mr) */
#define HEML__NC 26         /* the largest of them (the uncached kernels' workspace, heml__blk.lin) */
#define HEML__DK_NH 1       /* heml__mat.dk: the differential kernel of a material (0: the general path) */
#define HEML__DK_SVK 2
#define HEML__DK_MR 3
#define HEML__DK_ROWS(dk) ((dk) == HEML__DK_SVK ? HEML__NC_SVK : (dk) == HEML__DK_MR ? HEML__NC_MR : HEML__NC_NH)
#define HEML__NQ 9          /* Prony state per tetrahedron and term: the stress coefficients
                               (c0, a, w_J, M), see heml__coefficients */
#define HEML__KRYLOV 8      /* 3n vectors of the linear solvers' workspace (m->krylov) */
#define HEML__DEV_PROBE_RATIO 20.0 /* kappa / mu from which the probe runs on K_dev first (nu of
                                      0.476; measured on Cook's membrane, 8 x 8: 169 iterations at
                                      every nu, the full probe 155 at nu = 0.3, 236 at 0.49) */
#ifndef HEML_PAGG_PC_MAX
#define HEML_PAGG_PC_MAX 1024 /* pressure aggregates at most for the static solve's pressure-
                                 aggregate preconditioner (heml__pagg_pc_build: a dense A^2
                                 matrix, factored once per Krylov solve; beyond: Jacobi and
                                 the rigid-mode coarse space alone) */
#endif
#define HEML__VEC_BLOCK 4096 /* reals per partial sum of the vector reductions */
#define HEML__NODE_CHUNK 1024 /* nodes per work item of the nodal pressure's node pass */
#define HEML__MAX_TETS 100000000
#define HEML__SIXTH ((heml_real)(1.0 / 6.0))
#define HEML__MAX_NODES 200000000

/* kernel kinds: which kernels evaluate a law (the law's row in heml__laws says) */
#define HEML__K_INVARIANTS 0 /* a function w(I1, I2, J): the general path (and the fast one
                                where the law's fast_path flag allows it) */
#define HEML__K_USER 1       /* the same through user callbacks (checked at rest at create) */
#define HEML__K_SPRING 2     /* mass-spring: link tensions, its own kernels (heml__spring_*) */

/* what a law evaluation must produce besides the first derivatives */
#define HEML__WANT_ENERGY 1
#define HEML__WANT_SECOND 2

/* pass modes */
#define HEML__FORCE 0
#define HEML__DIFF 1
#define HEML__ENERGY 2
#define HEML__STRESS 3
#define HEML__FORCE_ENERGY 4 /* forces and the elastic energy (static line search) */
#define HEML__ABS 5          /* sum of |tetrahedron force| per dof (the round-off floor) */
#define HEML__DC_FILL 1      /* m->dc_pass: the DIFF pass fills the stiffness cache, */
#define HEML__DC_USE 2       /* or reads it (heml__diff_run) */

/* A material in kernel form. */
typedef struct heml__mat {
    int kind, uses_i2;
    int fast;                    /* its law's fast_path flag, and no I2 term, and no Prony: the
                                    vectorised Neo-Hookean kernels (heml__forces_nh, heml__diff_nh) */
    int dk;                      /* its differential kernel (HEML__DK_*, cached in the stiffness
                                    cache), 0: the general path (Prony, nodal pressure, other laws) */
    int fast_mr;                 /* split Mooney-Rivlin without Prony or the nodal pressure: the
                                    force kernel heml__forces_mr */
    int fast_nodal;              /* fast, with desc.nodal_pressure (fast is then 0): the force
                                    kernel heml__forces_nh with the nodal pressure (in a force
                                    pass heml__forces_nh_kept, on the sums' kept H), and the node
                                    pass's heml__dilation_nh (NEAR-INCOMPRESSIBLE BODIES) */
    heml_law law;
    const struct heml__law_ops *ops; /* its law's row of heml__laws */
    heml_real c1, c2, p0, kappa; /* heml__law_raw, heml__law_split (c1, c2, kappa) */
    heml_real mu, lambda, guard; /* heml__law_svk */
    heml_real young;             /* mass-spring */
    double density;
    double small_mu, small_lambda; /* small-strain moduli: preconditioner, time step */
    heml_user_law user;
    int prony_count, prony_first; /* its terms in the model's Prony arrays */
} heml__mat;

struct heml__blk;
/* A law's evaluation on a block of HEML__W tetrahedra (see heml__law). */
typedef void (*heml__law_fn)(const heml__mat *mt, struct heml__blk *b, int valid, int want);

/* One row of heml__laws (>>laws-table), indexed by heml_law: everything the library knows
   about a law. `energy`, `stress` and `differential` evaluate the law in invariants on a
   block (heml__blk): each fills the stress terms (w_1, w_2, w_J, s0); `energy` also w
   (called with HEML__WANT_ENERGY), `differential` also the second derivatives h (with
   HEML__WANT_SECOND). The built-in laws share J, ln J and J^-2/3 between the three, so
   each gives one function for all of them; NULL for mass-spring, whose kernels are the
   heml__spring_* functions (kind HEML__K_SPRING). `make` fills the kernel constants from a
   heml_material, `check` validates them (0, or an error code with a message).
   `fast_path`: the vectorised Neo-Hookean kernels (heml__forces_nh, heml__diff_nh) may
   evaluate this law's forces and differentials; they compute w = c1 (I1 - 3) - p0 ln J +
   kappa/2 ln^2 J from heml__mat's c1, p0, kappa and nothing else, so set it only for a law
   that is exactly that (they also run only without an I2 term and without Prony). Default
   0: a new law goes through the general path; tests/test_heml.c's
   test_law_table_forces_and_differentials fails if a law is routed to the fast path
   wrongly. */
typedef struct heml__law_ops {
    const char *name;
    int kind; /* HEML__K_* */
    heml__law_fn energy, stress, differential;
    void (*make)(const heml_material *src, heml__mat *mt);
    int (*check)(const heml_material *src, int index, char *msg, size_t msg_size);
    int fast_path;
} heml__law_ops;

struct heml_model {
    int node_count, tet_count, block_count, slot_count, chunk_count, group_count, colour_count;
    int material_count, prony_total, has_prony, has_springs, has_user_without_second;
    int agg_count;                         /* aggregates of the coarse space (0: none) */
    int nodal;                             /* desc.nodal_pressure (NEAR-INCOMPRESSIBLE BODIES) */
    int simd;                              /* 1: the vector gather and scatter where compiled in
                                              (HEML__AVX); tests set 0 to compare with the scalar path */
    unsigned pin_version, coarse_version;  /* A_c is rebuilt when the pins change */
    unsigned coarse_k_version, coarse_step_version; /* coarse_k's and coarse_step's pins */
    int implicit_coarse;                   /* desc.implicit_coarse: -1 never, 0 when it pays, 1 always */
    int coarse_plain;                      /* CG iterations per solve of the last implicit step
                                              without the coarse correction (-1: none yet) */
    int step_solves;                       /* Krylov solves of the running step */
    double coarse_step_c;                  /* c of the factor in coarse_step */
    heml_integrator integrator;
    heml_linear_solver linear_solver;
    heml_real time_step, mass_damping, gravity[3], cg_tolerance, J0, jm1_0, static_tolerance;
    heml_real newton_tolerance, min_increment, precision_limit;
    int cg_max_iterations, newton_iterations, static_max_iterations, max_increments, allow_inversion, leave_saddles;
    double h_min; /* shortest rest edge, m (the precision check) */
    /* divergence check of the semi-explicit step (heml__diverged): valid, the energy H0 and
       the energy scale at its reference state, the free degrees of freedom's potential
       -int F . du so far, and the last step's displacements and forces */
    int div_valid;
    unsigned div_pin_version;
    double div_H0, div_scale, div_phi;
    heml_real *div_u, *div_f;
    int parallel;

    heml_allocator allocator;
    heml_parallel_for_fn parallel_for;
    void *parallel_user;
    void *block;
    size_t block_bytes;

    /* nodes; the state is the displacement u (disp), pos = rest + u is kept for rendering */
    heml_real *rest, *pos, *disp, *vel, *force, *ext, *target, *mass, *inv_mass;
    heml_real *force4;                     /* float builds with AVX: the Neo-Hookean force pass's
                                              node forces padded to 4 components (heml__pass_run;
                                              NULL elsewhere) */
    heml_real *free_mask, *pin_mask; /* per degree of freedom: 1 free / 1 pinned */
    heml_real *diag;                 /* per degree of freedom: small-strain stiffness diagonal */
    double energy_noise;             /* J: round-off of the energy of user laws (static line search) */
    unsigned char *axes;             /* pinned axes per node; target: their displacements */
    /* anchors (heml_set_anchors, issue 14): the caller's arrays, read at every evaluation */
    int anchor_count;
    const int *anchor_nodes;
    const heml_real *anchor_k, *anchor_target;

    /* tetrahedra, in blocks of HEML__W slots (structure of arrays inside a block) */
    int *blk_idx;         /* 4 W per block: node j of lane k at [4 W b + W j + k] */
    heml_real *blk_rest;  /* NR W per block */
    int *blk_valid;       /* lanes holding a tetrahedron (the rest is padding) */
    size_t *blk_prony;    /* offset of the block's Prony state, reals */
    int *slot_tet, *tet_slot;

    /* chunks of consecutive blocks of one material; groups of consecutive chunks (group g:
       chunks group_start[g] .. group_start[g + 1] - 1), listed colour by colour (colour c:
       groups colour_start[c] .. colour_start[c + 1] - 1) */
    int *chunk_begin, *chunk_end, *chunk_material, *group_start, *colour_start;
    double *chunk_energy;
    int *chunk_below, *chunk_inverted;

    /* materials and the Prony series */
    heml__mat *mats;
    heml_real *prony_alpha, *prony_tau;
    heml_real *prony_a, *prony_b, *prony_s; /* coefficients of the current pass */
    heml_real *prony_q, *prony_q_next;      /* committed state and the one being built */
    size_t prony_reals;

    /* scratch vectors (3n reals each), named by role; heml__layout_scratch carves them and is
       the one place where two roles share memory (the pairs named there never live at once) */
    heml_real *step_u0, *step_v0, *step_u1, *step_v1; /* heml_step_ex: start and candidate */
    heml_real *static_u, *static_saved, *static_dpin, *static_dfdpin; /* heml_solve_static: current,
                                          last converged, the pins' move, df/du times it */
    heml_real *work_f;                 /* forces at the current point (every integrator, Newton) */
    heml_real *newton_R, *newton_delta; /* Newton: residual, direction */
    heml_real *newton_ut, *newton_ft, *newton_Rt; /* Newton: the line search's trial point, its
                                          forces and residual (also the saddle escape's) */
    heml_real *newton_shift_diag;      /* Newton: D + shift diag K0 after negative curvature */
    heml_real *probe_b, *probe_x;      /* saddle probe: K x = b */
    heml_real *lin_dmass, *lin_du, *lin_rhs; /* linearised implicit step: D, du, dt^2 R */
    heml_real *objective_load;         /* Newton's objective: f_ext + M g (static and implicit) */
    heml_real *implicit_dmass, *implicit_warm; /* implicit Euler: D, the first solve's guess */
    heml_real *static_rhs, *static_pred; /* static solve: the tangent predictor's K pred = rhs */
    heml_real *krylov[HEML__KRYLOV];   /* the linear solvers' workspace (heml__cg, heml__minres) */
    heml_real *dv_prev; /* implicit warm start */
    /* BDF2's history: the start state (u_n-1, v_n-1) of the last successful step, valid when
       that step was a BDF2 step of hist_dt seconds and nothing has changed the state or the
       constraints since (heml__history_reset) */
    heml_real *hist_u, *hist_v;
    heml_real *bdf2_ubar, *bdf2_vbar;  /* BDF2 scratch: (4 u_n - u_n-1) / 3, (4 v_n - v_n-1) / 3 */
    int hist_valid;
    heml_real hist_dt;
    const heml_real *lin_x; /* linearisation point of the CG operator */
    /* the stiffness cache (heml__diff_run): HEML__NC W reals per block (NULL: none), valid for
       the fast-path blocks at the linearisation point dc_key (NULL: invalid; every change of
       the state, the pins, J0 or the viscous state sets it NULL: heml__dc_invalidate) */
    heml_real *dc;
    const heml_real *dc_key;
    int has_dc, dc_pass; /* dc carved; the running DIFF pass's use of it (HEML__DC_*) */
    int dc_rows;         /* reals per tetrahedron slot of dc: the largest HEML__NC_* of a cached
                            material in use */
    unsigned char *dc_gen; /* per block: 1 when the cache holds no point values for it (a St
                            Venant-Kirchhoff block with a tetrahedron below J0: general path) */

    /* coarse space (heml__coarse_build) */
    int *node_agg;      /* aggregate of each node */
    double *agg_centre; /* 3 per aggregate */
    double *coarse;     /* (6 A)^2: A_c, then its Cholesky factor */
    double *coarse_rhs; /* 6 A */
    double *coarse_k;   /* (6 A)^2: P^T K0 P (unfactored; heml__coarse_assemble) */
    double *coarse_step; /* (6 A)^2: the implicit steps' P^T (D + c K0) P, Cholesky-factored */
    double *coarse_pdp, *coarse_pdp_new; /* 36 A each: P^T D P of coarse_step's factor, and of the
                                            solve asking (its key, with c and the pins) */

    /* average nodal pressure (heml__nodal_prepare): per node the rest volume weights of
       each material, W[mat n + a] = sum Vol_e / 4 over the node's tetrahedra of that
       material, 1 / V_a (V_a their sum over materials), the sums sum Vol_e (J_e - 1) / 4
       and sum Vol_e dJ_e / 4 of the current pass, the nodal pressure P_a and its
       differential dP_a; per node chunk its energy */
    heml_real *nod_w, *nod_inv, *nod_j, *nod_dj, *nod_p, *nod_dp;
    /* with a heml__mat.fast_nodal material in use (nod_keep_h): the force's sums keep each
       slot's H = grad u (9 rows of HEML__W per block) in tet_h for the element pass of the
       same pass (heml__forces_nh_kept), nod_hx the x they were formed at, NULL outside that pass */
    int nod_keep_h;
    heml_real *tet_h;
    const heml_real *nod_hx;
    /* nodal_pressure = 2: the pressure aggregates (heml__pressure_aggregates): count, node
       -> aggregate (-1: a node of no tetrahedron), and the node pass's arrays per aggregate
       (weights per material and aggregate, 1 / V_A, the sums, P_A and dP_A) */
    int pagg_count, *pagg;
    heml_real *pagg_w, *pagg_inv, *pagg_j, *pagg_dj, *pagg_p, *pagg_dp;
    double *nod_energy;
    int nod_chunks;
    /* the deviatoric probe (heml__dev_probe): kdev 1 while a solve runs on K_dev (the node
       pass writes dP_a = 0; Jacobi reads diag_dev, the deviatoric small-strain stiffness
       diagonal, 3n; the coarse space is built from the deviatoric small-strain stiffness,
       coarse_dev says which one is factored), 2 for the node pass to write d_a = dP_a /
       dj_a instead; dev_probe: the model's bulk-to-shear ratio makes it pay */
    int kdev, coarse_dev, dev_probe;
    heml_real *diag_dev;
    /* the static solve's pressure-aggregate preconditioner (nodal_pressure = 2,
       heml__pagg_pc_build): pagg_pc on for this model, pc_live while a Krylov solve uses it
       (Jacobi and the coarse space then deviatoric); per node its pgt_width aggregates
       (pgt_agg, -1: none) and the 3-vectors of G^T sqrt(s d_A) e_A there (pgt_val,
       refilled per solve); pc_s the factored A x A matrix I + G^ B_dev G^T^, pc_gp (A x 6
       agg_count) scratch, pc_y (A) the coarse unknowns, pc_w (3n) scratch */
    int pagg_pc, pc_live, pgt_width, *pgt_agg;
    double *pgt_val, *pc_s, *pc_gp, *pc_y;
    heml_real *pc_w;

    heml_stats stats;
};

/* >>math ------------------------------------------------------------------------------ */

static int heml__finite(double x) { return x == x && x - x == 0.0; }

static int heml__all_finite(const heml_real *a, size_t count)
{
    size_t i;
    int ok = 1;
    for (i = 0; i < count; i++) ok &= heml__finite((double)a[i]);
    return ok;
}

static heml_real heml__max(heml_real a, heml_real b) { return a > b ? a : b; }
static double heml__max_d(double a, double b) { return a > b ? a : b; }

/* Natural logarithm of a positive finite x, branch-free so that the kernels' loops
   vectorise (libm's log is a call): fdlibm's e_log.c / e_logf.c reduction to
   m in [sqrt(2)/2, sqrt(2)) and its minimax polynomial in s = (m - 1)/(m + 1), within
   one ulp. The exponent goes to floating point through the 2^52 (2^23) trick. */
#if HEML__FLOAT
HEML__INLINE heml_real heml__log(heml_real x)
{
    const float Lg1 = 6.6666662693e-01f, Lg2 = 4.0000972152e-01f, Lg3 = 2.8498786688e-01f,
                Lg4 = 2.4279078841e-01f, ln2_hi = 6.9313812256e-01f, ln2_lo = 9.0580006145e-06f;
    unsigned int ix, kb;
    float mant, f, s, z, w, R, hfsq, dk;
    memcpy(&ix, &x, sizeof ix);
    ix += 0x3f800000u - 0x3f3504f3u;
    kb = (ix >> 23) | 0x4b000000u;
    memcpy(&dk, &kb, sizeof dk);
    dk -= 8388608.0f + 127.0f;
    ix = (ix & 0x007fffffu) + 0x3f3504f3u;
    memcpy(&mant, &ix, sizeof mant);
    f = mant - 1.0f;
    s = f / (2.0f + f);
    z = s * s;
    w = z * z;
    R = z * (Lg1 + w * Lg3) + w * (Lg2 + w * Lg4);
    hfsq = 0.5f * f * f;
    return s * (hfsq + R) + dk * ln2_lo - hfsq + f + dk * ln2_hi;
}
#else
HEML__INLINE heml_real heml__log(heml_real x)
{
    const double Lg1 = 6.666666666666735130e-01, Lg2 = 3.999999999940941908e-01,
                 Lg3 = 2.857142874366239149e-01, Lg4 = 2.222219843214978396e-01,
                 Lg5 = 1.818357216161805012e-01, Lg6 = 1.531383769920937332e-01,
                 Lg7 = 1.479819860511658591e-01, ln2_hi = 6.93147180369123816490e-01,
                 ln2_lo = 1.90821492927058770002e-10;
    unsigned long long u, kb;
    double mant, f, s, z, w, t1, t2, R, hfsq, dk;
    memcpy(&u, &x, sizeof u);
    u += (unsigned long long)(0x3ff00000u - 0x3fe6a09eu) << 32;
    kb = (u >> 52) | 0x4330000000000000ull;
    memcpy(&dk, &kb, sizeof dk);
    dk -= 4503599627370496.0 + 1023.0;
    u = (u & 0x000fffffffffffffull) + ((unsigned long long)0x3fe6a09eu << 32);
    memcpy(&mant, &u, sizeof mant);
    f = mant - 1.0;
    hfsq = 0.5 * f * f;
    s = f / (2.0 + f);
    z = s * s;
    w = z * z;
    t1 = w * (Lg2 + w * (Lg4 + w * Lg6));
    t2 = z * (Lg1 + w * (Lg3 + w * (Lg5 + w * Lg7)));
    R = t2 + t1;
    return dk * ln2_hi - ((hfsq - (s * (hfsq + R) + dk * ln2_lo)) - f);
}
#endif

/* Rest constants of a tetrahedron in double: G = V^-1 V^-T (rows of V^-1 are the
   gradients of the barycentric coordinates N1..N3), Vol and 1/det V. Returns det V = 6 Vol
   (0 when flat). Edge vectors are formed in double from the given coordinates. */
static double heml__rest_constants(const heml_real *p0, const heml_real *p1, const heml_real *p2,
                                   const heml_real *p3, double g[3][3], double G[6])
{
    double e1[3], e2[3], e3[3], c[3][3], det;
    int k;
    for (k = 0; k < 3; k++) {
        e1[k] = (double)p1[k] - (double)p0[k];
        e2[k] = (double)p2[k] - (double)p0[k];
        e3[k] = (double)p3[k] - (double)p0[k];
    }
    c[0][0] = e2[1] * e3[2] - e2[2] * e3[1];
    c[0][1] = e2[2] * e3[0] - e2[0] * e3[2];
    c[0][2] = e2[0] * e3[1] - e2[1] * e3[0];
    c[1][0] = e3[1] * e1[2] - e3[2] * e1[1];
    c[1][1] = e3[2] * e1[0] - e3[0] * e1[2];
    c[1][2] = e3[0] * e1[1] - e3[1] * e1[0];
    c[2][0] = e1[1] * e2[2] - e1[2] * e2[1];
    c[2][1] = e1[2] * e2[0] - e1[0] * e2[2];
    c[2][2] = e1[0] * e2[1] - e1[1] * e2[0];
    det = e1[0] * c[0][0] + e1[1] * c[0][1] + e1[2] * c[0][2];
    if (det == 0.0) return 0.0;
    for (k = 0; k < 3; k++) {
        g[0][k] = c[0][k] / det;
        g[1][k] = c[1][k] / det;
        g[2][k] = c[2][k] / det;
    }
    G[0] = g[0][0] * g[0][0] + g[0][1] * g[0][1] + g[0][2] * g[0][2];
    G[1] = g[1][0] * g[1][0] + g[1][1] * g[1][1] + g[1][2] * g[1][2];
    G[2] = g[2][0] * g[2][0] + g[2][1] * g[2][1] + g[2][2] * g[2][2];
    G[3] = g[0][0] * g[1][0] + g[0][1] * g[1][1] + g[0][2] * g[1][2];
    G[4] = g[0][0] * g[2][0] + g[0][1] * g[2][1] + g[0][2] * g[2][2];
    G[5] = g[1][0] * g[2][0] + g[1][1] * g[2][1] + g[1][2] * g[2][2];
    return det;
}

/* x - log(1 + x) for x > -1 without cancellation at small |x| (the energies' volumetric
   part, in double): the series 2 u^3 (1/3 + u^2/5 + ...) subtracted from u x,
   u = x / (2 + x), below |x| = 0.1. */
static double heml__x_minus_log1p(double x)
{
    double u, u2, sum = 0.0;
    int k;
    if (!(fabs(x) < 0.1)) return x - log1p(x);
    u = x / (2.0 + x);
    u2 = u * u;
    for (k = 8; k >= 0; k--) sum = sum * u2 + 1.0 / (2 * k + 3);
    return u * x - 2.0 * u * u2 * sum;
}

/* >>laws ------------------------------------------------------------------------------ */

/* The workspace of one block of HEML__W tetrahedra: every stage of a kernel is a loop
   over the lanes of these arrays. Everything that vanishes at rest is formed from the
   displacements without cancellation (see THE MODEL). */
struct heml__blk {
    heml_real e[9][HEML__W];  /* link displacements du_j = u_j - u_0: component r of j at [3 (j-1) + r] */
    heml_real H[9][HEML__W];  /* displacement gradient H = F - I = du V^-1, row-major */
    heml_real K[9][HEML__W];  /* cof F - I = tr H I - H^T + cof H, row-major */
    heml_real E2[6][HEML__W]; /* C - I = H + H^T + H^T H (twice the Green strain): 00 11 22 01 02 12 */
    heml_real jm1[HEML__W];   /* J - 1 = tr H + tr cof H + det H */
    heml_real jc1[HEML__W], Jc[HEML__W], dJ0[HEML__W]; /* Jc - 1, Jc = max(J, J0), min(J - J0, 0) */
    heml_real I1m3[HEML__W], I2m3[HEML__W]; /* I1 - 3 = tr E2, I2 - 3 = 2 (I1 - 3) + ((I1 - 3)^2 - tr2) / 2 */
    heml_real tr2[HEML__W];   /* tr (C - I)^2 */
    heml_real q1[HEML__W];    /* I1 - 3 - 2 (J - 1) = |H|^2 - 2 tr cof H - 2 det H (energies) */
    heml_real I1[HEML__W], I2[HEML__W]; /* user laws */
    heml_real w[HEML__W], w1[HEML__W], w2[HEML__W], wJ[HEML__W];
    heml_real s0[HEML__W];    /* 2 w_1 + 4 w_2 + w_J, zero at rest, formed without cancellation */
    heml_real h[6][HEML__W];  /* w_11 w_12 w_1J w_22 w_2J w_JJ */
    heml_real co[9][HEML__W]; /* stress coefficients c0 a w_J M (heml__coefficients); springs:
                                 the six link tensions */
    heml_real f[9][HEML__W];  /* forces (or differentials) on nodes 1..3 */
    heml_real de[9][HEML__W]; /* differential: the links of dx */
    heml_real len[6][HEML__W]; /* springs: L l^3, L the rest and l the clamped link length */
    heml_real dp[HEML__W];    /* differential: the nodal pressure's dp (0 without it), see
                                 NEAR-INCOMPRESSIBLE BODIES */
    heml_real lin[HEML__NC][HEML__W]; /* the uncached Neo-Hookean differential's point values
                                 (heml__diff_nh_point; the stiffness cache's layout) */
};
typedef struct heml__blk heml__blk;

/* Kinematics of the block from its link displacements (e) and rest gradients (R): H, cof F - I,
   J - 1, C - I and the invariants, each a polynomial in H without a constant term (a
   tetrahedron at rest gives exact zeros, small strains keep their relative precision). */
static void heml__kinematics(const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
        heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
        heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real H00 = a0 * g10 + b0 * g20 + d0 * g30, H01 = a0 * g11 + b0 * g21 + d0 * g31;
        heml_real H02 = a0 * g12 + b0 * g22 + d0 * g32, H10 = a1 * g10 + b1 * g20 + d1 * g30;
        heml_real H11 = a1 * g11 + b1 * g21 + d1 * g31, H12 = a1 * g12 + b1 * g22 + d1 * g32;
        heml_real H20 = a2 * g10 + b2 * g20 + d2 * g30, H21 = a2 * g11 + b2 * g21 + d2 * g31;
        heml_real H22 = a2 * g12 + b2 * g22 + d2 * g32;
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c10 = H02 * H21 - H01 * H22, c11 = H00 * H22 - H02 * H20, c12 = H01 * H20 - H00 * H21;
        heml_real c20 = H01 * H12 - H02 * H11, c21 = H02 * H10 - H00 * H12, c22 = H00 * H11 - H01 * H10;
        heml_real tr = H00 + H11 + H22, i2 = c00 + c11 + c22, det = H00 * c00 + H01 * c01 + H02 * c02;
        heml_real E00 = 2 * H00 + (H00 * H00 + H10 * H10 + H20 * H20);
        heml_real E11 = 2 * H11 + (H01 * H01 + H11 * H11 + H21 * H21);
        heml_real E22 = 2 * H22 + (H02 * H02 + H12 * H12 + H22 * H22);
        heml_real E01 = H01 + H10 + (H00 * H01 + H10 * H11 + H20 * H21);
        heml_real E02 = H02 + H20 + (H00 * H02 + H10 * H12 + H20 * H22);
        heml_real E12 = H12 + H21 + (H01 * H02 + H11 * H12 + H21 * H22);
        heml_real t = E00 + E11 + E22;
        heml_real tr2 = E00 * E00 + E11 * E11 + E22 * E22 + 2 * (E01 * E01 + E02 * E02 + E12 * E12);
        heml_real hh = H00 * H00 + H01 * H01 + H02 * H02 + H10 * H10 + H11 * H11 + H12 * H12 + H20 * H20 +
                       H21 * H21 + H22 * H22;
        b->H[0][k] = H00;
        b->H[1][k] = H01;
        b->H[2][k] = H02;
        b->H[3][k] = H10;
        b->H[4][k] = H11;
        b->H[5][k] = H12;
        b->H[6][k] = H20;
        b->H[7][k] = H21;
        b->H[8][k] = H22;
        b->K[0][k] = tr - H00 + c00;
        b->K[1][k] = c01 - H10;
        b->K[2][k] = c02 - H20;
        b->K[3][k] = c10 - H01;
        b->K[4][k] = tr - H11 + c11;
        b->K[5][k] = c12 - H21;
        b->K[6][k] = c20 - H02;
        b->K[7][k] = c21 - H12;
        b->K[8][k] = tr - H22 + c22;
        b->E2[0][k] = E00;
        b->E2[1][k] = E11;
        b->E2[2][k] = E22;
        b->E2[3][k] = E01;
        b->E2[4][k] = E02;
        b->E2[5][k] = E12;
        b->jm1[k] = tr + i2 + det;
        b->I1m3[k] = t;
        b->tr2[k] = tr2;
        b->I2m3[k] = 2 * t + (t * t - tr2) / 2;
        b->q1[k] = hh - 2 * (i2 + det);
    }
}

/* J continuation below J0 (jm1_0 = J0 - 1): Jc - 1 = max(J, J0) - 1, Jc, and the
   (non-positive) distance d = J - Jc. */
static void heml__clamp_J(heml_real jm1_0, heml__blk *b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real j = b->jm1[k], jc = heml__max(j, jm1_0);
        b->jc1[k] = jc;
        b->Jc[k] = 1 + jc;
        b->dJ0[k] = j - jc;
    }
}

/* ln Jc = log1p(Jc - 1), accurate at small strains: the rounding of 1 + (Jc - 1) corrected
   to first order (iJ = 1 / Jc). */
HEML__INLINE heml_real heml__log_jc(heml_real Jc, heml_real jc1, heml_real iJ)
{
    return heml__log(Jc) + (jc1 - (Jc - 1)) * iJ;
}

/* heml__law_raw (Neo-Hookean eq. 26 and table 3 + penalty): w = c1 (I1 - 3) + c2 (I2 - 3) + U(J), U = -p0 ln J + kappa/2 ln^2 J (p0 = 2 c1 +
   4 c2), U' = (kappa ln J - p0) / J, U'' = (kappa (1 - ln J) + p0) / J^2, continued below
   J0 by U(J0) + U'(J0) d + U''(J0) d^2 / 2 (d = J - J0): the tangent of the volumetric
   stress, sec. 4.4. Neo-Hookean eq. 26: c1 = mu/2, c2 = 0, p0 = mu, kappa = lambda.
   s0 = p0 + w_J = (kappa ln Jc + p0 (Jc - 1)) / Jc + U'' d. The energy uses
   c1 (I1 - 3) - 2 c1 ln J = c1 (q1 + 2 d + 2 (x - log1p x)), x = Jc - 1, and
   I2 - 3 - 4 ln J = 2 (I1 - 3 - 2 ln J) + ((I1 - 3)^2 - tr2) / 2. */
static void heml__law_raw(const heml__mat *mt, heml__blk *b, int valid, int want)
{
    (void)valid;
    const heml_real c1 = mt->c1, c2 = mt->c2, p0 = mt->p0, kappa = mt->kappa;
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real Jc = b->Jc[k], jc1 = b->jc1[k], d = b->dJ0[k], iJ = 1 / Jc;
        heml_real L = heml__log_jc(Jc, jc1, iJ);
        heml_real hh = (kappa * (1 - L) + p0) * iJ * iJ;
        heml_real s0 = (kappa * L + p0 * jc1) * iJ + hh * d;
        b->s0[k] = s0;
        b->wJ[k] = s0 - p0;
        b->h[5][k] = hh;
        b->w1[k] = c1;
        b->w2[k] = c2;
    }
    if (want & HEML__WANT_SECOND)
        for (k = 0; k < HEML__W; k++) b->h[0][k] = b->h[1][k] = b->h[2][k] = b->h[3][k] = b->h[4][k] = 0;
    if (want & HEML__WANT_ENERGY)
        for (k = 0; k < HEML__W; k++) {
            double Jc = (double)b->Jc[k], jc1 = (double)b->jc1[k], d = (double)b->dJ0[k], t = (double)b->I1m3[k];
            double L = log1p(jc1), up = ((double)kappa * L - (double)p0) / Jc;
            double hh = ((double)kappa * (1 - L) + (double)p0) / (Jc * Jc);
            double q = (double)b->q1[k] + 2 * d + 2 * heml__x_minus_log1p(jc1);
            b->w[k] = (heml_real)((double)c1 * q + (double)c2 * (2 * q + (t * t - (double)b->tr2[k]) / 2) +
                                  (double)kappa / 2 * L * L + d * (up + hh / 2 * d));
        }
}

/* Jc^(-1/3) for Jc > 0, branch-free so that the law's loop vectorises (libm's cbrt is a
   call): a first guess from the bits of the float (the exponent divided by 3, error below
   4 %), then Newton steps r <- r (4 - Jc r^3) / 3, whose relative error e becomes about
   2 e^2: 4 steps in double, 3 in float, to within a few ulps (libm's cbrt, correctly
   rounded to 1 ulp, gave the same forces to round-off in the all-law tests). Valid for
   Jc in [2^-60, 2^60]; heml__law_split sends other lanes to libm. */
HEML__INLINE heml_real heml__inv_cbrt(heml_real Jc)
{
    float xf = (float)Jc, gf;
    int i;
    heml_real r, x3 = Jc / 3;
    memcpy(&i, &xf, sizeof i);
    i = 0x54a21d2a - (int)((float)i * (1.0f / 3.0f));
    memcpy(&gf, &i, sizeof gf);
    r = (heml_real)gf;
    r = r * ((heml_real)(4.0 / 3.0) - x3 * (r * r * r));
    r = r * ((heml_real)(4.0 / 3.0) - x3 * (r * r * r));
    r = r * ((heml_real)(4.0 / 3.0) - x3 * (r * r * r));
    if (sizeof(heml_real) > sizeof(float)) r = r * ((heml_real)(4.0 / 3.0) - x3 * (r * r * r));
    return r;
}

/* heml__law_split, the compressible Mooney-Rivlin (eqs. 21-25): w = c1 (I1 a - 3) + c2 (I2 b - 3) + kappa/2 (J - 1)^2 with
   a = J^-2/3, b = J^-4/3, both continued below J0 by their quadratic Taylor polynomials
   (a' = -2/3 a / J, a'' = 10/9 a / J^2, b' = -4/3 b / J, b'' = 28/9 b / J^2). s0 uses
   2 a + I1 a' = 2/3 a (3 (Jc - 1) - (I1 - 3)) / Jc and 4 b + I2 b' = 4/3 b (3 (Jc - 1) -
   (I2 - 3)) / Jc, plus the continuation terms in d. */
static void heml__law_split(const heml__mat *mt, heml__blk *b, int valid, int want)
{
    (void)valid;
    const heml_real c1 = mt->c1, c2 = mt->c2, kappa = mt->kappa;
    const heml_real lo = (heml_real)8.7e-19, hi = (heml_real)1.15e18; /* 2^-60, 2^60 */
    heml_real rc[HEML__W];
    int k, outside = 0;
    for (k = 0; k < HEML__W; k++) {
        heml_real Jc = b->Jc[k];
        rc[k] = heml__inv_cbrt(Jc);
        outside += (Jc < lo) | (Jc > hi);
    }
    if (outside) /* (NaN lanes stay NaN either way) */
        for (k = 0; k < HEML__W; k++)
            if (b->Jc[k] < lo || b->Jc[k] > hi) rc[k] = (heml_real)(1 / cbrt((double)b->Jc[k]));
    for (k = 0; k < HEML__W; k++) {
        heml_real Jc = b->Jc[k], jc1 = b->jc1[k], d = b->dJ0[k], jm1 = b->jm1[k];
        heml_real I1m3 = b->I1m3[k], I2m3 = b->I2m3[k], I1 = 3 + I1m3, I2 = 3 + I2m3;
        heml_real r = rc[k], iJ = 1 / Jc;
        heml_real a = r * r, bq = a * a;
        heml_real a1 = (heml_real)(-2.0 / 3.0) * a * iJ, a2 = (heml_real)(10.0 / 9.0) * a * iJ * iJ;
        heml_real b1 = (heml_real)(-4.0 / 3.0) * bq * iJ, b2 = (heml_real)(28.0 / 9.0) * bq * iJ * iJ;
        heml_real at = a + d * (a1 + d / 2 * a2), at1 = a1 + d * a2;
        heml_real bt = bq + d * (b1 + d / 2 * b2), bt1 = b1 + d * b2;
        heml_real sa = (heml_real)(2.0 / 3.0) * a * iJ * (3 * jc1 - I1m3) + d * (2 * a1 + I1 * a2 + d * a2);
        heml_real sb = (heml_real)(4.0 / 3.0) * bq * iJ * (3 * jc1 - I2m3) + d * (4 * b1 + I2 * b2 + 2 * d * b2);
        b->w1[k] = c1 * at;
        b->w2[k] = c2 * bt;
        b->wJ[k] = c1 * I1 * at1 + c2 * I2 * bt1 + kappa * jm1;
        b->s0[k] = c1 * sa + c2 * sb + kappa * jm1;
        b->h[0][k] = b->h[1][k] = b->h[3][k] = 0;
        b->h[2][k] = c1 * at1;
        b->h[4][k] = c2 * bt1;
        b->h[5][k] = c1 * I1 * a2 + c2 * I2 * b2 + kappa;
    }
    /* the energy in a loop of its own (library calls), so that the one above vectorises */
    if (want & HEML__WANT_ENERGY)
        for (k = 0; k < HEML__W; k++) { /* I1 at - 3 = 3 (at - 1) + (I1 - 3) at, a - 1 by expm1 (double) */
            heml_real Jc = b->Jc[k], jc1 = b->jc1[k], d = b->dJ0[k], jm1 = b->jm1[k];
            heml_real I1m3 = b->I1m3[k], I2m3 = b->I2m3[k], r = rc[k], iJ = 1 / Jc;
            heml_real a = r * r, bq = a * a;
            heml_real a1 = (heml_real)(-2.0 / 3.0) * a * iJ, a2 = (heml_real)(10.0 / 9.0) * a * iJ * iJ;
            heml_real b1 = (heml_real)(-4.0 / 3.0) * bq * iJ, b2 = (heml_real)(28.0 / 9.0) * bq * iJ * iJ;
            double L = log1p((double)jc1), dd = (double)d;
            double am1 = expm1(-2.0 / 3.0 * L) + dd * ((double)a1 + dd / 2 * (double)a2);
            double bm1 = expm1(-4.0 / 3.0 * L) + dd * ((double)b1 + dd / 2 * (double)b2);
            b->w[k] = (heml_real)((double)c1 * (3 * am1 + (double)I1m3 * (1 + am1)) +
                                  (double)c2 * (3 * bm1 + (double)I2m3 * (1 + bm1)) + (double)kappa / 2 * jm1 * jm1);
        }
}

/* heml__law_svk (table 3) in invariants: w = lambda/8 (I1 - 3)^2 + mu/4 (I1^2 - 2 I1 - 2 I2 + 3)
   = lambda/8 (I1 - 3)^2 + mu/4 tr (C - I)^2, w_1 = lambda/4 (I1 - 3) + mu/2 (I1 - 1),
   w_2 = -mu/2, s0 = (lambda/2 + mu) (I1 - 3) + w_J, plus the guard (lambda + 2 mu)/2 d^2
   below J0. */
static void heml__law_svk(const heml__mat *mt, heml__blk *b, int valid, int want)
{
    (void)valid;
    const heml_real mu = mt->mu, lambda = mt->lambda, guard = mt->guard;
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real t = b->I1m3[k], d = b->dJ0[k];
        b->w1[k] = lambda / 4 * t + mu / 2 * (t + 2);
        b->w2[k] = -mu / 2;
        b->wJ[k] = guard * d;
        b->s0[k] = (lambda / 2 + mu) * t + guard * d;
        b->h[0][k] = lambda / 4 + mu / 2;
        b->h[1][k] = b->h[2][k] = b->h[3][k] = b->h[4][k] = 0;
        b->h[5][k] = d < 0 ? guard : 0;
        if (want & HEML__WANT_ENERGY) b->w[k] = lambda / 8 * t * t + mu / 4 * b->tr2[k] + guard / 2 * d * d;
    }
}

/* heml__law_user: the callbacks at (I1, I2, Jc) for the `valid` lanes (padding lanes get zeros),
   continued below J0 to first order in J: w += w_J d + w_JJ d^2 / 2, w_1 += w_1J d,
   w_2 += w_2J d, w_J += w_JJ d (second derivatives held at J0); without `second`, w_J is
   held at its J0 value. s0 = 2 w_1 + 4 w_2 + w_J is formed from the callbacks' values, so
   the rest state cancels only to their round-off. */
static void heml__law_user(const heml__mat *mt, heml__blk *b, int valid, int want)
{
    heml_law_points p;
    int k, below = 0, second = mt->user.second != NULL;
    for (k = 0; k < HEML__W; k++) {
        below |= b->dJ0[k] < 0;
        b->I1[k] = 3 + b->I1m3[k];
        b->I2[k] = 3 + b->I2m3[k];
    }
    p.count = valid;
    p.I1 = b->I1;
    p.I2 = b->I2;
    p.J = b->Jc;
    p.w = b->w;
    p.w_1 = b->w1;
    p.w_2 = b->w2;
    p.w_J = b->wJ;
    p.w_11 = b->h[0];
    p.w_12 = b->h[1];
    p.w_1J = b->h[2];
    p.w_22 = b->h[3];
    p.w_2J = b->h[4];
    p.w_JJ = b->h[5];
    mt->user.first(&p, mt->user.user);
    if (second && ((want & HEML__WANT_SECOND) || below)) mt->user.second(&p, mt->user.user);
    else
        for (k = 0; k < HEML__W; k++) b->h[0][k] = b->h[1][k] = b->h[2][k] = b->h[3][k] = b->h[4][k] = b->h[5][k] = 0;
    if (want & HEML__WANT_ENERGY) {
        if (mt->user.energy) mt->user.energy(&p, mt->user.user);
        else
            for (k = 0; k < valid; k++) b->w[k] = (heml_real)NAN;
    }
    for (k = 0; k < valid; k++) {
        heml_real d = b->dJ0[k];
        if (d < 0) {
            if (want & HEML__WANT_ENERGY) b->w[k] += d * (b->wJ[k] + d / 2 * b->h[5][k]);
            b->w1[k] += b->h[2][k] * d;
            b->w2[k] += b->h[4][k] * d;
            b->wJ[k] += b->h[5][k] * d;
        }
    }
    for (k = valid; k < HEML__W; k++) {
        int r;
        b->w[k] = b->w1[k] = b->w2[k] = b->wJ[k] = 0;
        for (r = 0; r < 6; r++) b->h[r][k] = 0;
    }
    for (k = 0; k < HEML__W; k++) b->s0[k] = 2 * b->w1[k] + 4 * b->w2[k] + b->wJ[k];
}

/* The law of a material on a block, through its row of heml__laws (the one dispatch of
   the general path): energy when asked for it, else the differential when asked for
   second derivatives, else the stress. */
static void heml__law(const heml__mat *mt, heml__blk *b, int valid, int want)
{
    const heml__law_ops *ops = mt->ops;
    if (want & HEML__WANT_ENERGY) ops->energy(mt, b, valid, want);
    else if (want & HEML__WANT_SECOND) ops->differential(mt, b, valid, want);
    else ops->stress(mt, b, valid, want);
}

/* Evaluates a law at rest (I1 = I2 = 3, J = 1) for creation checks: fills w_1, w_2, w_J,
   s0 and the second derivatives (h) in lane 0 of a workspace. */
static void heml__law_at_rest(const heml__mat *mt, heml_real jm1_0, heml__blk *b)
{
    int k;
    for (k = 0; k < HEML__W; k++) b->I1m3[k] = b->I2m3[k] = b->tr2[k] = b->q1[k] = b->jm1[k] = 0;
    heml__clamp_J(jm1_0, b);
    heml__law(mt, b, 1, HEML__WANT_SECOND);
}

/* The volumetric function of a law (NEAR-INCOMPRESSIBLE BODIES): U(J) = w at the pure
   dilation F = J^(1/3) I (I1 = 3 s^2, I2 = 3 s^4, s = J^(1/3)) for J >= J0, continued
   below J0 by its quadratic Taylor polynomial; U, U' and U'' at the `W` lanes' J - 1 (jm1)
   into U (when want has HEML__WANT_ENERGY), U1, U2. s is a workspace. With the law's
   derivatives at the dilation point,
       U'  = 2 w_1 / s + 4 w_2 s + w_J = s0 - 2 w_1 (s - 1) / s + 4 w_2 (s - 1),
       U'' = -2/3 w_1 / s^4 + 4/3 w_2 / s^2 + 4 w_11 / s^2 + 16 w_12 + 16 s^2 w_22
             + 4 w_1J / s + 8 s w_2J + w_JJ
   (dI1/dJ = 2 / s, dI2/dJ = 4 s); s - 1 = (J - 1) / (s^2 + s + 1) and the invariants'
   offsets I1 - 3 = 3 (s^2 - 1), q1 = I1 - 3 - 2 (J - 1) = -(s - 1)^2 (2 s + 1) are formed
   without cancellation, so U' keeps the law's precision at small strains. */
static void heml__dilation(const heml__mat *mt, heml_real jm1_0, const heml_real *jm1, int valid, int want,
                           heml__blk *s, heml_real *U, heml_real *U1, heml_real *U2)
{
    heml_real dd[HEML__W], sv[HEML__W], sm[HEML__W];
    int k;
    for (k = 0; k < HEML__W; k++) { /* s = J^(1/3): Halley from the tangent 1 + (J - 1) / 3,
                                       to round-off in 4 steps for J in [1/8, 8] (vectorised;
                                       libm's cbrt is a call) */
        heml_real jc = heml__max(jm1[k], jm1_0), x = 1 + jc, t = 1 + jc / 3;
        int r;
        for (r = 0; r < 4; r++) {
            heml_real t3 = t * t * t;
            t = t * (t3 + 2 * x) / (2 * t3 + x);
        }
        sv[k] = t;
    }
    for (k = 0; k < HEML__W; k++) {
        heml_real jc = heml__max(jm1[k], jm1_0);
        if (jc < (heml_real)-0.875 || jc > 7) sv[k] = (heml_real)cbrt(1.0 + (double)jc);
    }
    for (k = 0; k < HEML__W; k++) {
        heml_real j = jm1[k], jc = heml__max(j, jm1_0), t = sv[k];
        heml_real t1 = jc / (t * t + t + 1), t2 = t1 * (t + 1);
        dd[k] = j - jc;
        sm[k] = t1;
        s->jm1[k] = jc;
        s->I1m3[k] = 3 * t2;
        s->I2m3[k] = 3 * t2 * (t * t + 1);
        s->tr2[k] = 3 * t2 * t2;
        s->q1[k] = -t1 * t1 * (2 * t + 1);
    }
    heml__clamp_J(jm1_0, s);
    heml__law(mt, s, valid, (want & HEML__WANT_ENERGY) | HEML__WANT_SECOND);
    for (k = 0; k < HEML__W; k++) {
        heml_real t = sv[k], it = 1 / t, d = dd[k], w1 = s->w1[k], w2 = s->w2[k];
        heml_real u1 = s->s0[k] - 2 * w1 * sm[k] * it + 4 * w2 * sm[k];
        heml_real u2 = (heml_real)(-2.0 / 3.0) * w1 * it * it * it * it + (heml_real)(4.0 / 3.0) * w2 * it * it +
                       4 * s->h[0][k] * it * it + 16 * s->h[1][k] + 16 * t * t * s->h[3][k] + 4 * s->h[2][k] * it +
                       8 * t * s->h[4][k] + s->h[5][k];
        if (want & HEML__WANT_ENERGY) U[k] = s->w[k] + d * (u1 + d / 2 * u2);
        U1[k] = u1 + u2 * d;
        U2[k] = u2;
    }
}

/* heml__dilation for a heml__mat.fast_nodal law (w = c1 (I1 - 3) + V(J), c2 = 0, p0 =
   2 c1) without the energy, in closed form: U(J) = 3 c1 (J^(2/3) - 1) + V(J), so with
   r = Jc^(-1/3) and the law's s0 = V'(Jc) + p0, V'' (heml__law_raw)
       U'  = s0 - 2 c1 (1 - r) + U'' d,   U'' = V''(Jc) - (2/3) c1 r^4,
   1 - r = (Jc - 1) / (Jc (1 + r + r^2)) as in heml__nh_nodal_s0: the same values as
   heml__dilation's to round-off, without its Halley root and its law evaluation. */
static void heml__dilation_nh(const heml__mat *mt, heml_real jm1_0, const heml_real *jm1, heml_real *U1,
                              heml_real *U2)
{
    const heml_real mu = 2 * mt->c1, p0 = mt->p0, kappa = mt->kappa;
    const heml_real lo = (heml_real)8.7e-19, hi = (heml_real)1.15e18; /* 2^-60, 2^60 */
    heml_real rc[HEML__W];
    int k, outside = 0;
    for (k = 0; k < HEML__W; k++) {
        heml_real Jc = 1 + heml__max(jm1[k], jm1_0);
        rc[k] = heml__inv_cbrt(Jc);
        outside += (Jc < lo) | (Jc > hi);
    }
    if (outside)
        for (k = 0; k < HEML__W; k++) {
            heml_real Jc = 1 + heml__max(jm1[k], jm1_0);
            if (Jc < lo || Jc > hi) rc[k] = (heml_real)(1 / cbrt((double)Jc));
        }
    for (k = 0; k < HEML__W; k++) {
        heml_real j = jm1[k], jc1 = heml__max(j, jm1_0), Jc = 1 + jc1, d = j - jc1, iJ = 1 / Jc, r = rc[k];
        heml_real r2 = r * r, L = heml__log_jc(Jc, jc1, iJ);
        heml_real u2 = (kappa * (1 - L) + p0) * iJ * iJ - mu / 3 * (r2 * r2);
        heml_real u1 = (kappa * L + p0 * jc1) * iJ - mu * jc1 * iJ / (1 + r + r2);
        U1[k] = u1 + u2 * d;
        U2[k] = u2;
    }
}

/* >>forces ---------------------------------------------------------------------------- */

/* Links du_1, du_2, du_3 of the block's lanes from a 3n field (displacements or dx). */
HEML__SCALAR_FN static void heml__gather_scalar(const int *HEML__RESTRICT idx, const heml_real *HEML__RESTRICT x,
                                                heml_real (*HEML__RESTRICT e)[HEML__W])
{
    int k, r;
    HEML__SCALAR_LOOP
    for (k = 0; k < HEML__W; k++) {
        const heml_real *p0 = x + 3 * idx[k], *p1 = x + 3 * idx[HEML__W + k];
        const heml_real *p2 = x + 3 * idx[2 * HEML__W + k], *p3 = x + 3 * idx[3 * HEML__W + k];
        for (r = 0; r < 3; r++) {
            e[r][k] = p1[r] - p0[r];
            e[3 + r][k] = p2[r] - p0[r];
            e[6 + r][k] = p3[r] - p0[r];
        }
    }
}

/* Adds the block's node forces (f on nodes 1..3, minus their sum on node 0) into out. The
   lanes go in order, so a node shared by two lanes of a block is updated twice in a
   fixed order. */
static void heml__scatter_scalar(const int *HEML__RESTRICT idx, heml_real (*HEML__RESTRICT f)[HEML__W],
                                 heml_real *HEML__RESTRICT out)
{
    int k, r;
    for (k = 0; k < HEML__W; k++) {
        heml_real *o0 = out + 3 * idx[k], *o1 = out + 3 * idx[HEML__W + k];
        heml_real *o2 = out + 3 * idx[2 * HEML__W + k], *o3 = out + 3 * idx[3 * HEML__W + k];
        for (r = 0; r < 3; r++) {
            heml_real a = f[r][k], b = f[3 + r][k], c = f[6 + r][k];
            o1[r] += a;
            o2[r] += b;
            o3[r] += c;
            o0[r] -= (a + b) + c;
        }
    }
}

#if defined(HEML__AVX)
/* The vector gather and scatter (AVX; AVX-512 VL masks where present), 4 lanes at a time.
   Gather: one masked load moves a node's 3 components (the mask never faults past the
   array's end), 4 x 4 transposes turn them into the lanes' rows. Scatter: per node a
   16-byte (x, y) and a scalar z read-modify-write (masked stores were tried: 1.6 times
   slower, their store-to-load forwarding fails where the next lane updates the same node).
   The same operations in the same order as the scalar loops (the links are differences of
   the same pairs; a node shared by lanes receives the lanes' terms in lane order, node 0
   the same (a + b) + c), so the forces are bit-identical to the scalar path. */
#if defined(HEML__AVX512)
#define HEML__LOAD3D(p) _mm256_maskz_loadu_pd((__mmask8)7, (p))
#define HEML__LOAD3F(p) _mm_maskz_loadu_ps((__mmask8)7, (p))
#else
#define HEML__LOAD3D(p) _mm256_maskload_pd((p), _mm256_set_epi64x(0, -1, -1, -1))
#define HEML__LOAD3F(p) _mm_maskload_ps((p), _mm_set_epi32(0, -1, -1, -1))
#endif
#if defined(HEML__AVX512)
/* The float gather with AVX-512 VL masks, 8 lanes at a time in 256-bit registers: register q
   holds lane q in its low half and lane 4 + q in its high half (a zeroing 3-element load,
   then a merging one at the node's address minus 16 bytes with mask bits 4 to 6: masked-off
   elements never fault), so one 4 x 4 transpose per half moves 8 lanes at once: half the
   shuffles, subtractions and stores of 4 lanes in 128-bit registers. */
static void heml__gather_vecf8(const int *HEML__RESTRICT idx, const heml_real *HEML__RESTRICT x,
                               heml_real (*HEML__RESTRICT e)[HEML__W])
{
    const float *xf = (const float *)(const void *)x;
    float *row = (float *)(void *)e[0];
    int h, j, q;
#define HEML__LOAD8F(i, l)                                                                                        \
    _mm256_mask_loadu_ps(_mm256_maskz_loadu_ps((__mmask8)7, xf + 3 * (size_t)(i)[l]), (__mmask8)0x70,            \
                         (const float *)(const void *)((uintptr_t)(xf + 3 * (size_t)(i)[(l) + 4]) - 16))
    for (h = 0; h < HEML__W; h += 8) {
        __m256 n0[4];
        for (q = 0; q < 4; q++) n0[q] = HEML__LOAD8F(idx, h + q);
        for (j = 1; j < 4; j++) {
            __m256 d[4], t0, t1, t2, t3;
            for (q = 0; q < 4; q++) d[q] = _mm256_sub_ps(HEML__LOAD8F(idx + j * HEML__W, h + q), n0[q]);
            t0 = _mm256_unpacklo_ps(d[0], d[1]); /* x0 x1 y0 y1 in each half */
            t1 = _mm256_unpackhi_ps(d[0], d[1]); /* z0 z1 .. */
            t2 = _mm256_unpacklo_ps(d[2], d[3]);
            t3 = _mm256_unpackhi_ps(d[2], d[3]);
            _mm256_storeu_ps(row + 3 * (j - 1) * HEML__W + h, _mm256_shuffle_ps(t0, t2, 0x44));
            _mm256_storeu_ps(row + (3 * (j - 1) + 1) * HEML__W + h, _mm256_shuffle_ps(t0, t2, 0xEE));
            _mm256_storeu_ps(row + (3 * (j - 1) + 2) * HEML__W + h, _mm256_shuffle_ps(t1, t3, 0x44));
        }
    }
#undef HEML__LOAD8F
}
#endif

static void heml__gather_vec(const int *HEML__RESTRICT idx, const heml_real *HEML__RESTRICT x,
                             heml_real (*HEML__RESTRICT e)[HEML__W])
{
    int k, j, l;
    for (k = 0; k < HEML__W; k += 4) {
        if (sizeof(heml_real) == sizeof(double)) {
            const double *xd = (const double *)(const void *)x;
            __m256d p0[4];
            for (l = 0; l < 4; l++) p0[l] = HEML__LOAD3D(xd + 3 * (size_t)idx[k + l]);
            for (j = 1; j < 4; j++) {
                __m256d d[4], t0, t1, t2, t3;
                double *row = (double *)(void *)e[3 * (j - 1)];
                for (l = 0; l < 4; l++)
                    d[l] = _mm256_sub_pd(HEML__LOAD3D(xd + 3 * (size_t)idx[j * HEML__W + k + l]),
                                         p0[l]);
                t0 = _mm256_unpacklo_pd(d[0], d[1]); /* x0 x1 z0 z1 */
                t1 = _mm256_unpackhi_pd(d[0], d[1]); /* y0 y1 .. */
                t2 = _mm256_unpacklo_pd(d[2], d[3]);
                t3 = _mm256_unpackhi_pd(d[2], d[3]);
                _mm256_storeu_pd(row + k, _mm256_permute2f128_pd(t0, t2, 0x20));
                _mm256_storeu_pd(row + HEML__W + k, _mm256_permute2f128_pd(t1, t3, 0x20));
                _mm256_storeu_pd(row + 2 * HEML__W + k, _mm256_permute2f128_pd(t0, t2, 0x31));
            }
        } else {
            const float *xf = (const float *)(const void *)x;
            __m128 p0[4];
            for (l = 0; l < 4; l++) p0[l] = HEML__LOAD3F(xf + 3 * (size_t)idx[k + l]);
            for (j = 1; j < 4; j++) {
                __m128 d0, d1, d2, d3;
                float *row = (float *)(void *)e[3 * (j - 1)];
                d0 = _mm_sub_ps(HEML__LOAD3F(xf + 3 * (size_t)idx[j * HEML__W + k]), p0[0]);
                d1 = _mm_sub_ps(HEML__LOAD3F(xf + 3 * (size_t)idx[j * HEML__W + k + 1]), p0[1]);
                d2 = _mm_sub_ps(HEML__LOAD3F(xf + 3 * (size_t)idx[j * HEML__W + k + 2]), p0[2]);
                d3 = _mm_sub_ps(HEML__LOAD3F(xf + 3 * (size_t)idx[j * HEML__W + k + 3]), p0[3]);
                _MM_TRANSPOSE4_PS(d0, d1, d2, d3);
                _mm_storeu_ps(row + k, d0);
                _mm_storeu_ps(row + HEML__W + k, d1);
                _mm_storeu_ps(row + 2 * HEML__W + k, d2);
            }
        }
    }
}

/* Two floats (8 bytes, any 4-byte alignment) into a register's low half and back: memcpy
   through a double, which compilers turn into one 8-byte move (a cast pointer would be a
   misaligned double access). */
HEML__INLINE __m128 heml__ld2f(const float *p)
{
    double t;
    memcpy(&t, p, sizeof t);
    return _mm_castpd_ps(_mm_set_sd(t));
}

HEML__INLINE void heml__st2f(float *p, __m128 v)
{
    double t = _mm_cvtsd_f64(_mm_castps_pd(v));
    memcpy(p, &t, sizeof t);
}

/* The float scatter into nodes padded to 4 components (m->force4, 16-byte aligned): per 8
   lanes and node a 4 x 4 transpose in each 128-bit half turns the rows x, y, z into the
   lanes' (x, y, z, z) (a buffer), and each lane's goes to its node by one aligned 16-byte
   read-modify-write (the fourth component is padding, never read back). The same sums in
   the same order as the scalar loop: heml__pass_run copies x, y, z to the 3n forces. */
static void heml__scatter_vecf4(const int *HEML__RESTRICT idx, heml_real (*HEML__RESTRICT f)[HEML__W],
                                heml_real *HEML__RESTRICT out4)
{
    const float *fr = (const float *)(const void *)f[0];
    /* lane l's (x, y, z, z) in a node's buffer: 8 (l & 3) + 4 ((l >> 2) & 1) + 32 (l >> 3) */
    static const int at[16] = {0, 8, 16, 24, 4, 12, 20, 28, 32, 40, 48, 56, 36, 44, 52, 60};
    float *of = (float *)(void *)out4;
    float q[4][4 * HEML__W];
    int j, h, l;
    for (j = 0; j < 4; j++)
        for (h = 0; h < HEML__W; h += 8) {
            __m256 X, Y, Z, t0, t1, t2, t3;
            if (j == 0) { /* node 0: (a + b) + c of the other three, as the scalar loop */
                X = _mm256_add_ps(_mm256_add_ps(_mm256_loadu_ps(fr + h), _mm256_loadu_ps(fr + 3 * HEML__W + h)),
                                  _mm256_loadu_ps(fr + 6 * HEML__W + h));
                Y = _mm256_add_ps(_mm256_add_ps(_mm256_loadu_ps(fr + HEML__W + h), _mm256_loadu_ps(fr + 4 * HEML__W + h)),
                                  _mm256_loadu_ps(fr + 7 * HEML__W + h));
                Z = _mm256_add_ps(_mm256_add_ps(_mm256_loadu_ps(fr + 2 * HEML__W + h), _mm256_loadu_ps(fr + 5 * HEML__W + h)),
                                  _mm256_loadu_ps(fr + 8 * HEML__W + h));
            } else {
                X = _mm256_loadu_ps(fr + 3 * (j - 1) * HEML__W + h);
                Y = _mm256_loadu_ps(fr + (3 * (j - 1) + 1) * HEML__W + h);
                Z = _mm256_loadu_ps(fr + (3 * (j - 1) + 2) * HEML__W + h);
            }
            t0 = _mm256_unpacklo_ps(X, Y); /* x0 y0 x1 y1 | x4 y4 x5 y5 */
            t1 = _mm256_unpackhi_ps(X, Y); /* x2 y2 x3 y3 | x6 y6 x7 y7 */
            t2 = _mm256_unpacklo_ps(Z, Z);
            t3 = _mm256_unpackhi_ps(Z, Z);
            _mm256_storeu_ps(q[j] + 4 * h, _mm256_shuffle_ps(t0, t2, 0x44));      /* lanes 0 | 4 */
            _mm256_storeu_ps(q[j] + 4 * h + 8, _mm256_shuffle_ps(t0, t2, 0xEE));  /* lanes 1 | 5 */
            _mm256_storeu_ps(q[j] + 4 * h + 16, _mm256_shuffle_ps(t1, t3, 0x44)); /* lanes 2 | 6 */
            _mm256_storeu_ps(q[j] + 4 * h + 24, _mm256_shuffle_ps(t1, t3, 0xEE)); /* lanes 3 | 7 */
        }
    for (l = 0; l < HEML__W; l++) { /* lanes in order: shared nodes see the scalar order */
        const int a = at[l];
        float *o;
        for (j = 1; j < 4; j++) {
            o = of + 4 * (size_t)idx[j * HEML__W + l];
            _mm_store_ps(o, _mm_add_ps(_mm_load_ps(o), _mm_loadu_ps(q[j] + a)));
        }
        o = of + 4 * (size_t)idx[l];
        _mm_store_ps(o, _mm_sub_ps(_mm_load_ps(o), _mm_loadu_ps(q[0] + a)));
    }
}

static void heml__scatter_vec(const int *HEML__RESTRICT idx, heml_real (*HEML__RESTRICT f)[HEML__W],
                              heml_real *HEML__RESTRICT out)
{
    int k, j, l;
    for (k = 0; k < HEML__W; k += 4) {
        if (sizeof(heml_real) == sizeof(double)) {
            double *od = (double *)(void *)out;
            __m128d xy[4][4]; /* [node][lane] */
            double zz[4][4];
            for (j = 0; j < 4; j++) {
                __m256d X, Y, Z, t0, t1;
                if (j == 0) { /* node 0: (a + b) + c of the other three, as the scalar loop */
                    const double *f0 = (const double *)(const void *)f[0] + k;
                    X = _mm256_add_pd(_mm256_add_pd(_mm256_loadu_pd(f0), _mm256_loadu_pd(f0 + 3 * HEML__W)),
                                      _mm256_loadu_pd(f0 + 6 * HEML__W));
                    Y = _mm256_add_pd(_mm256_add_pd(_mm256_loadu_pd(f0 + HEML__W), _mm256_loadu_pd(f0 + 4 * HEML__W)),
                                      _mm256_loadu_pd(f0 + 7 * HEML__W));
                    Z = _mm256_add_pd(_mm256_add_pd(_mm256_loadu_pd(f0 + 2 * HEML__W), _mm256_loadu_pd(f0 + 5 * HEML__W)),
                                      _mm256_loadu_pd(f0 + 8 * HEML__W));
                } else {
                    const double *fj = (const double *)(const void *)f[3 * (j - 1)] + k;
                    X = _mm256_loadu_pd(fj);
                    Y = _mm256_loadu_pd(fj + HEML__W);
                    Z = _mm256_loadu_pd(fj + 2 * HEML__W);
                }
                t0 = _mm256_unpacklo_pd(X, Y); /* x0 y0 x2 y2 */
                t1 = _mm256_unpackhi_pd(X, Y); /* x1 y1 x3 y3 */
                xy[j][0] = _mm256_castpd256_pd128(t0);
                xy[j][1] = _mm256_castpd256_pd128(t1);
                xy[j][2] = _mm256_extractf128_pd(t0, 1);
                xy[j][3] = _mm256_extractf128_pd(t1, 1);
                _mm256_storeu_pd(zz[j], Z);
            }
            for (l = 0; l < 4; l++) { /* lanes in order: shared nodes see the scalar order */
                for (j = 1; j < 4; j++) {
                    double *o = od + 3 * (size_t)idx[j * HEML__W + k + l];
                    _mm_storeu_pd(o, _mm_add_pd(_mm_loadu_pd(o), xy[j][l]));
                    o[2] += zz[j][l];
                }
                {
                    double *o = od + 3 * (size_t)idx[k + l];
                    _mm_storeu_pd(o, _mm_sub_pd(_mm_loadu_pd(o), xy[0][l]));
                    o[2] -= zz[0][l];
                }
            }
        } else {
            float *of = (float *)(void *)out;
            __m128 v[4][4];
            for (j = 0; j < 4; j++) {
                __m128 X, Y, Z, W = _mm_setzero_ps();
                if (j == 0) {
                    const float *f0 = (const float *)(const void *)f[0] + k;
                    X = _mm_add_ps(_mm_add_ps(_mm_loadu_ps(f0), _mm_loadu_ps(f0 + 3 * HEML__W)),
                                   _mm_loadu_ps(f0 + 6 * HEML__W));
                    Y = _mm_add_ps(_mm_add_ps(_mm_loadu_ps(f0 + HEML__W), _mm_loadu_ps(f0 + 4 * HEML__W)),
                                   _mm_loadu_ps(f0 + 7 * HEML__W));
                    Z = _mm_add_ps(_mm_add_ps(_mm_loadu_ps(f0 + 2 * HEML__W), _mm_loadu_ps(f0 + 5 * HEML__W)),
                                   _mm_loadu_ps(f0 + 8 * HEML__W));
                } else {
                    const float *fj = (const float *)(const void *)f[3 * (j - 1)] + k;
                    X = _mm_loadu_ps(fj);
                    Y = _mm_loadu_ps(fj + HEML__W);
                    Z = _mm_loadu_ps(fj + 2 * HEML__W);
                }
                _MM_TRANSPOSE4_PS(X, Y, Z, W);
                v[j][0] = X, v[j][1] = Y, v[j][2] = Z, v[j][3] = W;
            }
            for (l = 0; l < 4; l++) {
                for (j = 0; j < 4; j++) {
                    float *o = of + 3 * (size_t)idx[j * HEML__W + k + l];
                    __m128 xyo = heml__ld2f(o);
                    heml__st2f(o, j ? _mm_add_ps(xyo, v[j][l]) : _mm_sub_ps(xyo, v[j][l]));
                    o[2] = j ? o[2] + _mm_cvtss_f32(_mm_shuffle_ps(v[j][l], v[j][l], 2))
                             : o[2] - _mm_cvtss_f32(_mm_shuffle_ps(v[j][l], v[j][l], 2));
                }
            }
        }
    }
}
#endif

/* The gather and scatter of a model: vector where compiled in and m->simd, else scalar. */
static void heml__gather(const heml_model *m, const int *idx, const heml_real *x, heml_real (*e)[HEML__W])
{
#if defined(HEML__AVX)
    if (m->simd) {
        heml__gather_vec(idx, x, e);
        return;
    }
#endif
    (void)m;
    heml__gather_scalar(idx, x, e);
}

static void heml__scatter(const heml_model *m, const int *idx, heml_real (*f)[HEML__W], heml_real *out)
{
#if defined(HEML__AVX)
    if (m->simd) {
        heml__scatter_vec(idx, f, out);
        return;
    }
#endif
    (void)m;
    heml__scatter_scalar(idx, f, out);
}

/* The same as calls (never inlined), for the pipelined Neo-Hookean force pass between
   heml__forces_nh's stages (heml__chunk_forces_nh); with `four` the scatter goes to nodes
   padded to 4 components (m->force4, heml__pass_run). Inlined or not measured the same.
   The float gather of 8 lanes a register (AVX-512 VL) serves this pass only: 1 to 2 %
   faster force, but a 3 to 5 % slower stiffness product (PERFORMANCE). */
HEML__NOINLINE static void heml__gather_call(const heml_model *m, const int *idx, const heml_real *x, heml_real (*e)[HEML__W])
{
#if defined(HEML__AVX512)
    if (m->simd && sizeof(heml_real) != sizeof(double)) { /* (here only: it slowed the stiffness product) */
        heml__gather_vecf8(idx, x, e);
        return;
    }
#endif
    heml__gather(m, idx, x, e);
}

HEML__NOINLINE static void heml__scatter_call(const heml_model *m, const int *idx, heml_real (*f)[HEML__W], heml_real *out,
                                              int four)
{
#if defined(HEML__AVX)
    if (four) { /* (m->force4: heml__pass_run) */
        heml__scatter_vecf4(idx, f, out);
        return;
    }
#endif
    (void)four;
    heml__scatter(m, idx, f, out);
}

/* The same with absolute values (the size of the terms each node's force sums). */
static void heml__scatter_abs(const int *idx, heml_real (*f)[HEML__W], heml_real *out)
{
    int k, r;
    for (k = 0; k < HEML__W; k++) {
        heml_real *o0 = out + 3 * idx[k], *o1 = out + 3 * idx[HEML__W + k];
        heml_real *o2 = out + 3 * idx[2 * HEML__W + k], *o3 = out + 3 * idx[3 * HEML__W + k];
        for (r = 0; r < 3; r++) {
            heml_real a = f[r][k], b = f[3 + r][k], c = f[6 + r][k];
            o1[r] += (heml_real)fabs((double)a);
            o2[r] += (heml_real)fabs((double)b);
            o3[r] += (heml_real)fabs((double)c);
            o0[r] += (heml_real)fabs((double)((a + b) + c));
        }
    }
}

/* Stress coefficients of P = c0 I + 2 a H + w_J K - F M (K = cof F - I), the first
   Piola-Kirchhoff stress of w(I1, I2, J) written so that no term survives at rest:
       P = 2 w_1 F + 2 w_2 (I1 F - F C) + w_J cof F = 2 a F - F M + w_J cof F,
       a = w_1 + (I1 - 1) w_2,  M = 2 w_2 (C - I),  c0 = 2 a + w_J = s0 + 2 w_2 (I1 - 3).
   In the paper's terms the second Piola-Kirchhoff stress is S = 2 a I - M + w_J J C^-1 and
   the link tensions Sigma = Vol V^-1 S V^-T (eqs. 29-30). */
static void heml__coefficients(heml__blk *b, int uses_i2)
{
    int k, r;
    for (k = 0; k < HEML__W; k++) {
        heml_real w2 = b->w2[k], t = b->I1m3[k];
        b->co[0][k] = b->s0[k] + 2 * w2 * t;
        b->co[1][k] = b->w1[k] + (2 + t) * w2;
        b->co[2][k] = b->wJ[k];
    }
    for (r = 0; r < 6; r++)
        for (k = 0; k < HEML__W; k++) b->co[3 + r][k] = uses_i2 ? 2 * b->w2[k] * b->E2[r][k] : 0;
}

/* Prony (eq. 20) on the block's `comps` stress components: the force uses
   s X - sum_i b_i Q_i (s = 1 - sum_i a_i) and, when `write`, the new state
   a_i X + b_i Q_i goes to the next buffer. */
static void heml__prony(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b, int comps,
                        int write)
{
    const heml_real *q = m->prony_q + m->blk_prony[blk];
    heml_real *qn = m->prony_q_next + m->blk_prony[blk];
    heml_real s = m->prony_s[mt - m->mats];
    int i, r, k;
    for (r = 0; r < comps; r++) {
        heml_real raw[HEML__W];
        for (k = 0; k < HEML__W; k++) {
            raw[k] = b->co[r][k];
            b->co[r][k] = s * raw[k];
        }
        for (i = 0; i < mt->prony_count; i++) {
            heml_real a = m->prony_a[mt->prony_first + i], bb = m->prony_b[mt->prony_first + i];
            const heml_real *qi = q + (size_t)(i * HEML__NQ + r) * HEML__W;
            for (k = 0; k < HEML__W; k++) b->co[r][k] -= bb * qi[k];
            if (write) {
                heml_real *qni = qn + (size_t)(i * HEML__NQ + r) * HEML__W;
                for (k = 0; k < HEML__W; k++) qni[k] = a * raw[k] + bb * qi[k];
            }
        }
    }
}

/* f_k = -Vol P grad N_k (k = 1..3), P = c0 I + 2 a H + w_J K - M - H M. */
static void heml__pk1_forces(const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real vol = R[9 * HEML__W + k];
        heml_real c0 = vol * b->co[0][k], a2 = 2 * vol * b->co[1][k], wj = vol * b->co[2][k];
        heml_real M00 = vol * b->co[3][k], M11 = vol * b->co[4][k], M22 = vol * b->co[5][k];
        heml_real M01 = vol * b->co[6][k], M02 = vol * b->co[7][k], M12 = vol * b->co[8][k];
        heml_real H00 = b->H[0][k], H01 = b->H[1][k], H02 = b->H[2][k];
        heml_real H10 = b->H[3][k], H11 = b->H[4][k], H12 = b->H[5][k];
        heml_real H20 = b->H[6][k], H21 = b->H[7][k], H22 = b->H[8][k];
        heml_real P00 = c0 + a2 * H00 + wj * b->K[0][k] - M00 - (H00 * M00 + H01 * M01 + H02 * M02);
        heml_real P01 = a2 * H01 + wj * b->K[1][k] - M01 - (H00 * M01 + H01 * M11 + H02 * M12);
        heml_real P02 = a2 * H02 + wj * b->K[2][k] - M02 - (H00 * M02 + H01 * M12 + H02 * M22);
        heml_real P10 = a2 * H10 + wj * b->K[3][k] - M01 - (H10 * M00 + H11 * M01 + H12 * M02);
        heml_real P11 = c0 + a2 * H11 + wj * b->K[4][k] - M11 - (H10 * M01 + H11 * M11 + H12 * M12);
        heml_real P12 = a2 * H12 + wj * b->K[5][k] - M12 - (H10 * M02 + H11 * M12 + H12 * M22);
        heml_real P20 = a2 * H20 + wj * b->K[6][k] - M02 - (H20 * M00 + H21 * M01 + H22 * M02);
        heml_real P21 = a2 * H21 + wj * b->K[7][k] - M12 - (H20 * M01 + H21 * M11 + H22 * M12);
        heml_real P22 = c0 + a2 * H22 + wj * b->K[8][k] - M22 - (H20 * M02 + H21 * M12 + H22 * M22);
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        b->f[0][k] = -(P00 * g10 + P01 * g11 + P02 * g12);
        b->f[1][k] = -(P10 * g10 + P11 * g11 + P12 * g12);
        b->f[2][k] = -(P20 * g10 + P21 * g11 + P22 * g12);
        b->f[3][k] = -(P00 * g20 + P01 * g21 + P02 * g22);
        b->f[4][k] = -(P10 * g20 + P11 * g21 + P12 * g22);
        b->f[5][k] = -(P20 * g20 + P21 * g21 + P22 * g22);
        b->f[6][k] = -(P00 * g30 + P01 * g31 + P02 * g32);
        b->f[7][k] = -(P10 * g30 + P11 * g31 + P12 * g32);
        b->f[8][k] = -(P20 * g30 + P21 * g31 + P22 * g32);
    }
}

/* The rest links V1, V2, V3 of the block's lanes into b->H (springs do not use H), from
   the rest gradients: V = (V^-1)^-1 = 6 Vol adj(V^-1), V_1 = 6 Vol grad N_2 x grad N_3 and
   cyclically. Force, energy and differential use the same V, so the energy's gradient is
   exact whatever its rounding; the stream stays 10 rest constants per tetrahedron. */
static void heml__spring_rest_links(const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real v6 = 6 * R[9 * HEML__W + k];
        b->H[0][k] = v6 * (g21 * g32 - g22 * g31);
        b->H[1][k] = v6 * (g22 * g30 - g20 * g32);
        b->H[2][k] = v6 * (g20 * g31 - g21 * g30);
        b->H[3][k] = v6 * (g31 * g12 - g32 * g11);
        b->H[4][k] = v6 * (g32 * g10 - g30 * g12);
        b->H[5][k] = v6 * (g30 * g11 - g31 * g10);
        b->H[6][k] = v6 * (g11 * g22 - g12 * g21);
        b->H[7][k] = v6 * (g12 * g20 - g10 * g22);
        b->H[8][k] = v6 * (g10 * g21 - g11 * g20);
    }
}

/* x[i] = sqrt(x[i]) for n non-negative values: vector
   square roots where the target has them (HEML__AVX), the same correctly rounded values. */
static void heml__sqrt_lanes(heml_real *HEML__RESTRICT x, int n)
{
    int i = 0;
#if defined(HEML__AVX)
    if (sizeof(heml_real) == sizeof(double)) {
        double *d = (double *)(void *)x;
        for (; i + 4 <= n; i += 4) _mm256_storeu_pd(d + i, _mm256_sqrt_pd(_mm256_loadu_pd(d + i)));
    } else {
        float *f = (float *)(void *)x;
        for (; i + 8 <= n; i += 8) _mm256_storeu_ps(f + i, _mm256_sqrt_ps(_mm256_loadu_ps(f + i)));
    }
#endif
    HEML__SCALAR_LOOP
    for (; i < n; i++) x[i] = (heml_real)sqrt((double)x[i]);
}

/* Mass-spring (sec. 5.3): the change of the squared link lengths without cancellation,
   l^2 - L^2 = 2 V . du + |du|^2 (V the rest link, L^2 = |V|^2), and the tensions
   t = k (l - L) / l = k (l^2 - L^2) / ((l + L) l) (eq. 35), k = E Vol / L^2, as
       t = E Vol (l^2 - L^2) / d,   d = L^2 (l^2 + s),   s = L l = sqrt(L^2 l^2)
   (one square root per link; in double the six divisions 1 / d through one, 1 / (d1 ... d6)
   and 15 multiplications that back out each 1 / d, within a few ulps of the quotients,
   and six divisions for a lane whose product leaves [DBL_MIN, DBL_MAX / 4], d ~ L^4 off
   1e-13 m to 1e13 m or clamped lengths; float keeps the six divisions, whose product,
   L^24, would leave its range on millimetre meshes) into co[0..5]; len gets l^2 s = L l^3 for
   the differential (dt = s_p E Vol (v . dv) / (L l^3)); with `energy`, w (per lane, J) =
   sum k/2 (l - L)^2 = sum E Vol (l^2 - L^2)^2 / (2 L^2 (l^2 + 2 s + L^2)). Lengths are
   clamped at 1e-12 L (l^2 at 1e-24 L^2) so coincident nodes give finite forces. Every
   per-link constant comes from the 10 rest constants (the rest links of
   heml__spring_rest_links, V4..V6 the differences of V1..V3, the same in force, energy and
   differential, so the energy's gradient is exact, and l = L exactly at rest); `young` the
   law's E. Padding lanes (Vol = 0, V = 0) get t = 0. */
static void heml__spring_tensions(heml_real young, const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b,
                                  int energy)
{
    heml_real dl2[6][HEML__W], L2[6][HEML__W], q2[6][HEML__W], dn[6][HEML__W];
    int k, l, r;
    for (l = 0; l < 3; l++) /* L^2 = |V|^2 and l^2 - L^2 = 2 V . du + |du|^2 (vectorised) */
        for (k = 0; k < HEML__W; k++) {
            heml_real acc = 0, vv = 0;
            for (r = 0; r < 3; r++) {
                heml_real V = b->H[3 * l + r][k], du = b->e[3 * l + r][k];
                acc += (2 * V + du) * du;
                vv += V * V;
            }
            dl2[l][k] = acc;
            L2[l][k] = vv;
        }
    for (l = 3; l < 6; l++) /* the links 2 - 1, 3 - 2, 1 - 3 */
        for (k = 0; k < HEML__W; k++) {
            heml_real acc = 0, vv = 0;
            int a = l - 3, c = l == 5 ? 0 : l - 2;
            for (r = 0; r < 3; r++) {
                heml_real V = b->H[3 * c + r][k] - b->H[3 * a + r][k], du = b->e[3 * c + r][k] - b->e[3 * a + r][k];
                acc += (2 * V + du) * du;
                vv += V * V;
            }
            dl2[l][k] = acc;
            L2[l][k] = vv;
        }
    for (l = 0; l < 6; l++) /* l^2 clamped at 1e-24 L^2, and L^2 l^2 */
        for (k = 0; k < HEML__W; k++) {
            heml_real q = L2[l][k] + dl2[l][k], lo = (heml_real)1e-24 * L2[l][k];
            q = q > lo ? q : lo;
            q2[l][k] = q;
            b->len[l][k] = L2[l][k] * q;
        }
    heml__sqrt_lanes(b->len[0], 6 * HEML__W);
    for (l = 0; l < 6; l++) /* the denominators L^2 (l^2 + L l) into dn, l^2 L l = L l^3 into len */
        for (k = 0; k < HEML__W; k++) {
            heml_real sl = b->len[l][k], q = q2[l][k], den = L2[l][k] * (q + sl);
            dn[l][k] = den > 0 ? den : 1; /* (padding: dl2 = 0; unconditional, so it vectorises) */
            b->len[l][k] = q * sl;
        }
    if (sizeof(heml_real) > sizeof(float)) { /* double: the six 1 / den through one division */
        heml_real inv[6][HEML__W], bad[HEML__W];
        int nbad = 0;
        for (k = 0; k < HEML__W; k++) {
            heml_real d0 = dn[0][k], d1 = dn[1][k], d2 = dn[2][k], d3 = dn[3][k], d4 = dn[4][k], d5 = dn[5][k];
            heml_real p01 = d0 * d1, p23 = d2 * d3, p45 = d4 * d5, p0123 = p01 * p23, P = p0123 * p45;
            heml_real iP = 1 / P, i45 = p0123 * iP, i0123 = p45 * iP, i01 = p23 * i0123, i23 = p01 * i0123;
            inv[0][k] = d1 * i01;
            inv[1][k] = d0 * i01;
            inv[2][k] = d3 * i23;
            inv[3][k] = d2 * i23;
            inv[4][k] = d5 * i45;
            inv[5][k] = d4 * i45;
            bad[k] = (heml_real)((P < (heml_real)DBL_MIN) | (P > (heml_real)(DBL_MAX / 4)));
        }
        for (k = 0; k < HEML__W; k++) nbad += bad[k] != 0;
        if (nbad) /* (a product out of range: lengths far from 1 m, or clamped) */
            for (k = 0; k < HEML__W; k++)
                if (bad[k] != 0)
                    for (l = 0; l < 6; l++) inv[l][k] = 1 / dn[l][k];
        for (l = 0; l < 6; l++)
            for (k = 0; k < HEML__W; k++) b->co[l][k] = young * R[9 * HEML__W + k] * dl2[l][k] * inv[l][k];
    } else
        for (l = 0; l < 6; l++)
            for (k = 0; k < HEML__W; k++) b->co[l][k] = young * R[9 * HEML__W + k] * dl2[l][k] / dn[l][k];
    if (energy)
        for (k = 0; k < HEML__W; k++) {
            double we = 0.0, ev = (double)young * (double)R[9 * HEML__W + k];
            for (l = 0; l < 6; l++) {
                double LL = (double)L2[l][k], q = (double)q2[l][k], sl = sqrt(LL * q), d = (double)dl2[l][k];
                double den = LL * (q + 2 * sl + LL);
                if (den > 0) we += ev / 2 * d * d / den;
            }
            b->w[k] = (heml_real)we;
        }
}

/* The six spring links v_e = V_e + du_e of lane k into v. */
static void heml__spring_links(const heml__blk *b, int k, heml_real v[6][3])
{
    int r;
    for (r = 0; r < 3; r++) {
        v[0][r] = b->H[r][k] + b->e[r][k];
        v[1][r] = b->H[3 + r][k] + b->e[3 + r][k];
        v[2][r] = b->H[6 + r][k] + b->e[6 + r][k];
        v[3][r] = v[1][r] - v[0][r];
        v[4][r] = v[2][r] - v[1][r];
        v[5][r] = v[0][r] - v[2][r];
    }
}

/* Node forces from the link tensions t_e: t_e v_e on the link's start, -t_e v_e on its end
   (v4 = v2 - v1, v5 = v3 - v2, v6 = v1 - v3, v = V + du). */
static void heml__spring_forces(heml__blk *HEML__RESTRICT b, heml_real (*HEML__RESTRICT t)[HEML__W])
{
    int k, r;
    for (r = 0; r < 3; r++)
        for (k = 0; k < HEML__W; k++) {
            heml_real v1 = b->H[r][k] + b->e[r][k], v2 = b->H[3 + r][k] + b->e[3 + r][k];
            heml_real v3 = b->H[6 + r][k] + b->e[6 + r][k];
            heml_real p1 = t[0][k] * v1, p2 = t[1][k] * v2, p3 = t[2][k] * v3;
            heml_real p4 = t[3][k] * (v2 - v1), p5 = t[4][k] * (v3 - v2), p6 = t[5][k] * (v1 - v3);
            b->f[r][k] = -p1 + p4 - p6;
            b->f[3 + r][k] = -p2 - p4 + p5;
            b->f[6 + r][k] = -p3 - p5 + p6;
        }
}

/* The differential of heml__spring_forces: each term t v becomes t dv + dt v, dv the links
   of de. A function of its own: one loop with a branch on dt was if-converted by gcc, so
   the force pass computed (and discarded) the differential's products from the unset
   workspace de, whose garbage included subnormals: 15 times the Neo-Hookean force on Zen
   (measured, issue 21). */
static void heml__spring_dforces(heml__blk *HEML__RESTRICT b, heml_real (*HEML__RESTRICT t)[HEML__W],
                                 heml_real (*HEML__RESTRICT dt)[HEML__W])
{
    int k, r;
    for (r = 0; r < 3; r++)
        for (k = 0; k < HEML__W; k++) {
            heml_real v1 = b->H[r][k] + b->e[r][k], v2 = b->H[3 + r][k] + b->e[3 + r][k];
            heml_real v3 = b->H[6 + r][k] + b->e[6 + r][k];
            heml_real d1 = b->de[r][k], d2 = b->de[3 + r][k], d3 = b->de[6 + r][k];
            heml_real p1 = t[0][k] * d1 + dt[0][k] * v1;
            heml_real p2 = t[1][k] * d2 + dt[1][k] * v2;
            heml_real p3 = t[2][k] * d3 + dt[2][k] * v3;
            heml_real p4 = t[3][k] * (d2 - d1) + dt[3][k] * (v2 - v1);
            heml_real p5 = t[4][k] * (d3 - d2) + dt[4][k] * (v3 - v2);
            heml_real p6 = t[5][k] * (d1 - d3) + dt[5][k] * (v1 - v3);
            b->f[r][k] = -p1 + p4 - p6;
            b->f[3 + r][k] = -p2 - p4 + p5;
            b->f[6 + r][k] = -p3 - p5 + p6;
        }
}

/* J - 1 of spring tetrahedra, for the statistics only: det(V + du) / (6 Vol) - 1. */
static void heml__spring_J(const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real a0 = b->H[0][k] + b->e[0][k], a1 = b->H[1][k] + b->e[1][k];
        heml_real a2 = b->H[2][k] + b->e[2][k], b0 = b->H[3][k] + b->e[3][k];
        heml_real b1 = b->H[4][k] + b->e[4][k], b2 = b->H[5][k] + b->e[5][k];
        heml_real d0 = b->H[6][k] + b->e[6][k], d1 = b->H[7][k] + b->e[7][k];
        heml_real d2 = b->H[8][k] + b->e[8][k], v6 = 6 * R[9 * HEML__W + k];
        heml_real det = a0 * (b1 * d2 - b2 * d1) + a1 * (b2 * d0 - b0 * d2) + a2 * (b0 * d1 - b1 * d0);
        heml_real ok = (heml_real)(v6 > 0); /* (no branch: the loop vectorises without
                                                AVX-512's masks) */
        b->jm1[k] = ok * (det / (v6 + (1 - ok)) - 1);
    }
}

/* f_k = -P grad N_k (k = 1..3) for the Vol-scaled P held in b->K. */
static void heml__p_times_grad(const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real P00 = b->K[0][k], P01 = b->K[1][k], P02 = b->K[2][k];
        heml_real P10 = b->K[3][k], P11 = b->K[4][k], P12 = b->K[5][k];
        heml_real P20 = b->K[6][k], P21 = b->K[7][k], P22 = b->K[8][k];
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        b->f[0][k] = -(P00 * g10 + P01 * g11 + P02 * g12);
        b->f[1][k] = -(P10 * g10 + P11 * g11 + P12 * g12);
        b->f[2][k] = -(P20 * g10 + P21 * g11 + P22 * g12);
        b->f[3][k] = -(P00 * g20 + P01 * g21 + P02 * g22);
        b->f[4][k] = -(P10 * g20 + P11 * g21 + P12 * g22);
        b->f[5][k] = -(P20 * g20 + P21 * g21 + P22 * g22);
        b->f[6][k] = -(P00 * g30 + P01 * g31 + P02 * g32);
        b->f[7][k] = -(P10 * g30 + P11 * g31 + P12 * g32);
        b->f[8][k] = -(P20 * g30 + P21 * g31 + P22 * g32);
    }
}

/* The Neo-Hookean force's volumetric scalar with the nodal pressure (heml__mat.fast_nodal,
   NEAR-INCOMPRESSIBLE BODIES), from b->jm1 into b->s0: what heml__law_raw and
   heml__nodal_element give together, in closed form. For w = c1 (I1 - 3) + V(J) (c2 = 0,
   p0 = 2 c1) the dilation energy is U(J) = 3 c1 (J^(2/3) - 1) + V(J), so w_J - U'(J) =
   -2 c1 r with r = Jc^(-1/3): V cancels exactly (below J0 both are the same quadratic
   continuation, leaving -(2 c1 r)' d = (2/3) c1 r^4 d), and with the nodes' mean pressure
   p_e = (P_a + P_b + P_c + P_d) / 4
       w_J = -2 c1 r + (2/3) c1 r^4 d + p_e,   s0 = 2 c1 + w_J = 2 c1 (1 - r) + (2/3) c1 r^4 d + p_e,
   1 - r = (Jc - 1) / (Jc (1 + r + r^2)) formed without cancellation (r^3 = 1 / Jc). The
   stress stage of heml__forces_nh is then unchanged (w_J = s0 - p0, p0 = 2 c1). r by
   heml__inv_cbrt (libm outside [2^-60, 2^60], as heml__law_split); the general path
   (heml__dilation's Halley root, the law's logarithm twice, cancelling) gives the same
   forces to round-off (tests/test_heml.c test_nodal_pressure_fast_force). */
static void heml__nh_nodal_s0(const heml__mat *mt, heml_real jm1_0, const heml_real *HEML__RESTRICT np,
                              const int *HEML__RESTRICT idx, heml__blk *HEML__RESTRICT b)
{
    const heml_real mu = 2 * mt->c1, mu3 = mu / 3;
    const heml_real lo = (heml_real)8.7e-19, hi = (heml_real)1.15e18; /* 2^-60, 2^60 */
    heml_real rc[HEML__W], pe[HEML__W];
    int k, outside = 0;
    for (k = 0; k < HEML__W; k++) {
        heml_real Jc = 1 + heml__max(b->jm1[k], jm1_0);
        rc[k] = heml__inv_cbrt(Jc);
        outside += (Jc < lo) | (Jc > hi);
    }
    if (outside)
        for (k = 0; k < HEML__W; k++) {
            heml_real Jc = 1 + heml__max(b->jm1[k], jm1_0);
            if (Jc < lo || Jc > hi) rc[k] = (heml_real)(1 / cbrt((double)Jc));
        }
    for (k = 0; k < HEML__W; k++) /* (the one more scalar gather) */
        pe[k] = ((np[idx[k]] + np[idx[HEML__W + k]]) + (np[idx[2 * HEML__W + k]] + np[idx[3 * HEML__W + k]])) / 4;
    for (k = 0; k < HEML__W; k++) {
        heml_real jm1 = b->jm1[k], jc1 = heml__max(jm1, jm1_0), Jc = 1 + jc1, d = jm1 - jc1, r = rc[k];
        heml_real r2 = r * r;
        b->s0[k] = mu * jc1 / (Jc * (1 + r + r2)) + mu3 * (r2 * r2) * d + pe[k];
    }
}

/* The Neo-Hookean kernel (heml__law_raw without I2 and without Prony: heml__mat.fast), in stages that are each a
   short loop over the lanes: H and J - 1; the volumetric scalars (w_J = U'(J), continued
   below J0, s0 = p0 + w_J); the stress
       P = s0 I + 2 c1 H + w_J (tr H I - H^T + cof H)   (times Vol, into b->K)
   (cof H formed again from H: cheaper than storing it); then f_k = -P grad N_k. The same
   arithmetic as heml__kinematics, heml__law_raw, heml__coefficients and heml__pk1_forces.
   Short loops let the processor overlap the lanes' long dependency chains (the logarithm
   and two divisions): measured 11 against 14 ns per tetrahedron for one loop up to the
   stress and one for the product (12,000 tetrahedra, arithmetic alone); one loop for all
   of it spills the 16 AVX2 registers and was slower still. With np (the nodal pressures
   P_a, heml__mat.fast_nodal; idx the block's nodes) the volumetric stage is
   heml__nh_nodal_s0 instead and the rest is unchanged (w_J = s0 - p0 there too). The
   stages are functions of their own, never inlined (heml__forces_nh_h, _s, _p): the force
   pass calls them with the next block's gather and the previous block's scatter between
   them (heml__chunks, PERFORMANCE), the bench's arith row through heml__forces_nh, so both
   run the same machine code for the arithmetic. */
HEML__NOINLINE static void heml__forces_nh_h(const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
        heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
        heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real H00 = a0 * g10 + b0 * g20 + d0 * g30, H01 = a0 * g11 + b0 * g21 + d0 * g31;
        heml_real H02 = a0 * g12 + b0 * g22 + d0 * g32, H10 = a1 * g10 + b1 * g20 + d1 * g30;
        heml_real H11 = a1 * g11 + b1 * g21 + d1 * g31, H12 = a1 * g12 + b1 * g22 + d1 * g32;
        heml_real H20 = a2 * g10 + b2 * g20 + d2 * g30, H21 = a2 * g11 + b2 * g21 + d2 * g31;
        heml_real H22 = a2 * g12 + b2 * g22 + d2 * g32;
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c11 = H00 * H22 - H02 * H20, c22 = H00 * H11 - H01 * H10;
        b->H[0][k] = H00;
        b->H[1][k] = H01;
        b->H[2][k] = H02;
        b->H[3][k] = H10;
        b->H[4][k] = H11;
        b->H[5][k] = H12;
        b->H[6][k] = H20;
        b->H[7][k] = H21;
        b->H[8][k] = H22;
        b->jm1[k] = (H00 + H11 + H22) + (c00 + c11 + c22) + (H00 * c00 + H01 * c01 + H02 * c02);
    }
}

HEML__NOINLINE static void heml__forces_nh_s(const heml__mat *mt, heml_real jm1_0, const heml_real *HEML__RESTRICT np,
                                             const int *HEML__RESTRICT idx, heml__blk *HEML__RESTRICT b)
{
    const heml_real p0 = mt->p0, kappa = mt->kappa;
    int k;
    if (np) /* the nodal pressure (NEAR-INCOMPRESSIBLE BODIES): heml__nh_nodal_s0 */
        heml__nh_nodal_s0(mt, jm1_0, np, idx, b);
    else
        for (k = 0; k < HEML__W; k++) {
            heml_real jm1 = b->jm1[k];
            heml_real jc1 = heml__max(jm1, jm1_0), Jc = 1 + jc1, d = jm1 - jc1, iJ = 1 / Jc;
            heml_real L = heml__log_jc(Jc, jc1, iJ);
            heml_real hh = (kappa * (1 - L) + p0) * iJ * iJ;
            heml_real s0 = (kappa * L + p0 * jc1) * iJ + hh * d;
            b->s0[k] = s0;
        }
}

/* (H: 9 rows of HEML__W, b->H[0] or the nodal pressure's kept H) */
HEML__NOINLINE static void heml__forces_nh_p(const heml__mat *mt, const heml_real *HEML__RESTRICT R,
                                             const heml_real *HEML__RESTRICT H, heml__blk *HEML__RESTRICT b)
{
    const heml_real mu = 2 * mt->c1, p0 = mt->p0;
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real H00 = H[k], H01 = H[HEML__W + k], H02 = H[2 * HEML__W + k];
        heml_real H10 = H[3 * HEML__W + k], H11 = H[4 * HEML__W + k], H12 = H[5 * HEML__W + k];
        heml_real H20 = H[6 * HEML__W + k], H21 = H[7 * HEML__W + k], H22 = H[8 * HEML__W + k];
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c10 = H02 * H21 - H01 * H22, c11 = H00 * H22 - H02 * H20, c12 = H01 * H20 - H00 * H21;
        heml_real c20 = H01 * H12 - H02 * H11, c21 = H02 * H10 - H00 * H12, c22 = H00 * H11 - H01 * H10;
        heml_real vol = R[9 * HEML__W + k], s0 = b->s0[k], tr = H00 + H11 + H22;
        heml_real mv = mu * vol, wv = (s0 - p0) * vol, dv = s0 * vol + wv * tr, ev = mv - wv;
        b->K[0][k] = dv + ev * H00 + wv * c00;
        b->K[4][k] = dv + ev * H11 + wv * c11;
        b->K[8][k] = dv + ev * H22 + wv * c22;
        b->K[1][k] = mv * H01 + wv * (c01 - H10);
        b->K[2][k] = mv * H02 + wv * (c02 - H20);
        b->K[3][k] = mv * H10 + wv * (c10 - H01);
        b->K[5][k] = mv * H12 + wv * (c12 - H21);
        b->K[6][k] = mv * H20 + wv * (c20 - H02);
        b->K[7][k] = mv * H21 + wv * (c21 - H12);
    }
    heml__p_times_grad(R, b);
}

/* heml__forces_nh with the nodal pressure on H kept by this pass's sums (heml__nodal_sums_keep,
   Hk: 9 rows of HEML__W; NEAR-INCOMPRESSIBLE BODIES, "Cost"): no gather and no H, J - 1
   formed from Hk as heml__forces_nh_h does, then the same stages _s (nodal) and _p on Hk. */
static void heml__forces_nh_kept(const heml__mat *mt, heml_real jm1_0, const heml_real *HEML__RESTRICT R,
                                 const heml_real *HEML__RESTRICT np, const int *HEML__RESTRICT idx,
                                 const heml_real *HEML__RESTRICT Hk, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real H00 = Hk[k], H01 = Hk[HEML__W + k], H02 = Hk[2 * HEML__W + k];
        heml_real H10 = Hk[3 * HEML__W + k], H11 = Hk[4 * HEML__W + k], H12 = Hk[5 * HEML__W + k];
        heml_real H20 = Hk[6 * HEML__W + k], H21 = Hk[7 * HEML__W + k], H22 = Hk[8 * HEML__W + k];
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c11 = H00 * H22 - H02 * H20, c22 = H00 * H11 - H01 * H10;
        b->jm1[k] = (H00 + H11 + H22) + (c00 + c11 + c22) + (H00 * c00 + H01 * c01 + H02 * c02);
    }
    heml__forces_nh_s(mt, jm1_0, np, idx, b);
    heml__forces_nh_p(mt, R, Hk, b);
}

static void heml__forces_nh(const heml__mat *mt, heml_real jm1_0, const heml_real *HEML__RESTRICT R,
                            const heml_real *HEML__RESTRICT np, const int *HEML__RESTRICT idx,
                            heml__blk *HEML__RESTRICT b)
{
    heml__forces_nh_h(R, b);
    heml__forces_nh_s(mt, jm1_0, np, idx, b);
    heml__forces_nh_p(mt, R, b->H[0], b);
}

/* The split Mooney-Rivlin force kernel (heml__law_split without Prony or the nodal
   pressure: heml__mat.fast_mr), in stages as heml__forces_nh: H, J - 1, C - I and the
   invariants (heml__kinematics' formulas; H and C - I kept, cof F - I formed again later
   rather than stored), J^-1/3 by heml__inv_cbrt; the law's stress terms (heml__law_split's
   w_1, w_2, w_J, s0, continued below J0: no fallback) and heml__coefficients' c0 and a;
   the stress
       P = c0 I + H (2 a I - M) - M + w_J K,  c0 = s0 + 2 w_2 (I1 - 3), a = w_1 + (I1 - 1) w_2,
       M = 2 w_2 (C - I), K = cof F - I   (times Vol, into b->K)
   then f_k = -P grad N_k. The general path's arithmetic (heml__kinematics, heml__law_split,
   heml__coefficients, heml__pk1_forces) but for H (2 a I - M) in place of 2 a H - H M
   (forces differ by round-off: 2e-16 of the largest, tests/test_heml.c
   test_mooney_rivlin_fast_force), without the stores of K, the second derivatives and the
   coefficients that the general path keeps for the energy and the differential. See
   PERFORMANCE (issue 21) for what it costs against the Neo-Hookean kernel and why. */
static void heml__forces_mr(const heml__mat *mt, heml_real jm1_0, const heml_real *HEML__RESTRICT R,
                            heml__blk *HEML__RESTRICT b)
{
    const heml_real c1 = mt->c1, c2 = mt->c2, kappa = mt->kappa;
    const heml_real lo = (heml_real)8.7e-19, hi = (heml_real)1.15e18; /* 2^-60, 2^60 */
    heml_real rc[HEML__W];
    int k, outside = 0;
    for (k = 0; k < HEML__W; k++) {
        heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
        heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
        heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real H00 = a0 * g10 + b0 * g20 + d0 * g30, H01 = a0 * g11 + b0 * g21 + d0 * g31;
        heml_real H02 = a0 * g12 + b0 * g22 + d0 * g32, H10 = a1 * g10 + b1 * g20 + d1 * g30;
        heml_real H11 = a1 * g11 + b1 * g21 + d1 * g31, H12 = a1 * g12 + b1 * g22 + d1 * g32;
        heml_real H20 = a2 * g10 + b2 * g20 + d2 * g30, H21 = a2 * g11 + b2 * g21 + d2 * g31;
        heml_real H22 = a2 * g12 + b2 * g22 + d2 * g32;
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c11 = H00 * H22 - H02 * H20, c22 = H00 * H11 - H01 * H10;
        heml_real tr = H00 + H11 + H22, i2 = c00 + c11 + c22, det = H00 * c00 + H01 * c01 + H02 * c02;
        heml_real E00 = 2 * H00 + (H00 * H00 + H10 * H10 + H20 * H20);
        heml_real E11 = 2 * H11 + (H01 * H01 + H11 * H11 + H21 * H21);
        heml_real E22 = 2 * H22 + (H02 * H02 + H12 * H12 + H22 * H22);
        heml_real E01 = H01 + H10 + (H00 * H01 + H10 * H11 + H20 * H21);
        heml_real E02 = H02 + H20 + (H00 * H02 + H10 * H12 + H20 * H22);
        heml_real E12 = H12 + H21 + (H01 * H02 + H11 * H12 + H21 * H22);
        heml_real t = E00 + E11 + E22;
        heml_real tr2 = E00 * E00 + E11 * E11 + E22 * E22 + 2 * (E01 * E01 + E02 * E02 + E12 * E12);
        heml_real jm1 = tr + i2 + det, jc = heml__max(jm1, jm1_0), Jc = 1 + jc;
        b->H[0][k] = H00;
        b->H[1][k] = H01;
        b->H[2][k] = H02;
        b->H[3][k] = H10;
        b->H[4][k] = H11;
        b->H[5][k] = H12;
        b->H[6][k] = H20;
        b->H[7][k] = H21;
        b->H[8][k] = H22;
        b->E2[0][k] = E00;
        b->E2[1][k] = E11;
        b->E2[2][k] = E22;
        b->E2[3][k] = E01;
        b->E2[4][k] = E02;
        b->E2[5][k] = E12;
        b->jm1[k] = jm1;
        b->I1m3[k] = t;
        b->I2m3[k] = 2 * t + (t * t - tr2) / 2;
        rc[k] = heml__inv_cbrt(Jc);
        outside += (Jc < lo) | (Jc > hi);
    }
    if (outside) /* (NaN lanes stay NaN either way) */
        for (k = 0; k < HEML__W; k++) {
            heml_real Jc = 1 + heml__max(b->jm1[k], jm1_0);
            if (Jc < lo || Jc > hi) rc[k] = (heml_real)(1 / cbrt((double)Jc));
        }
    for (k = 0; k < HEML__W; k++) { /* heml__law_split's stress terms, then heml__coefficients' */
        heml_real jm1 = b->jm1[k], jc1 = heml__max(jm1, jm1_0), Jc = 1 + jc1, d = jm1 - jc1;
        heml_real I1m3 = b->I1m3[k], I2m3 = b->I2m3[k], I1 = 3 + I1m3, I2 = 3 + I2m3;
        heml_real r = rc[k], iJ = 1 / Jc;
        heml_real a = r * r, bq = a * a;
        heml_real a1 = (heml_real)(-2.0 / 3.0) * a * iJ, a2 = (heml_real)(10.0 / 9.0) * a * iJ * iJ;
        heml_real b1 = (heml_real)(-4.0 / 3.0) * bq * iJ, b2 = (heml_real)(28.0 / 9.0) * bq * iJ * iJ;
        heml_real at = a + d * (a1 + d / 2 * a2), at1 = a1 + d * a2;
        heml_real bt = bq + d * (b1 + d / 2 * b2), bt1 = b1 + d * b2;
        heml_real sa = (heml_real)(2.0 / 3.0) * a * iJ * (3 * jc1 - I1m3) + d * (2 * a1 + I1 * a2 + d * a2);
        heml_real sb = (heml_real)(4.0 / 3.0) * bq * iJ * (3 * jc1 - I2m3) + d * (4 * b1 + I2 * b2 + 2 * d * b2);
        heml_real w1 = c1 * at, w2 = c2 * bt;
        b->wJ[k] = c1 * I1 * at1 + c2 * I2 * bt1 + kappa * jm1;
        b->co[0][k] = (c1 * sa + c2 * sb + kappa * jm1) + 2 * w2 * I1m3;
        b->co[1][k] = w1 + (2 + I1m3) * w2;
        b->w2[k] = 2 * w2;
    }
    for (k = 0; k < HEML__W; k++) {
        heml_real H00 = b->H[0][k], H01 = b->H[1][k], H02 = b->H[2][k];
        heml_real H10 = b->H[3][k], H11 = b->H[4][k], H12 = b->H[5][k];
        heml_real H20 = b->H[6][k], H21 = b->H[7][k], H22 = b->H[8][k];
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c10 = H02 * H21 - H01 * H22, c11 = H00 * H22 - H02 * H20, c12 = H01 * H20 - H00 * H21;
        heml_real c20 = H01 * H12 - H02 * H11, c21 = H02 * H10 - H00 * H12, c22 = H00 * H11 - H01 * H10;
        heml_real tr = H00 + H11 + H22;
        heml_real vol = R[9 * HEML__W + k], w2 = b->w2[k]; /* b->w2: 2 w_2 here */
        heml_real c0 = vol * b->co[0][k], a2 = 2 * vol * b->co[1][k], wj = vol * b->wJ[k];
        heml_real M00 = vol * (w2 * b->E2[0][k]), M11 = vol * (w2 * b->E2[1][k]), M22 = vol * (w2 * b->E2[2][k]);
        heml_real M01 = vol * (w2 * b->E2[3][k]), M02 = vol * (w2 * b->E2[4][k]), M12 = vol * (w2 * b->E2[5][k]);
        heml_real A00 = a2 - M00, A11 = a2 - M11, A22 = a2 - M22; /* A = 2 a I - M: H A = 2 a H - H M */
        heml_real A01 = -M01, A02 = -M02, A12 = -M12;
        b->K[0][k] = c0 + wj * (tr - H00 + c00) - M00 + (H00 * A00 + H01 * A01 + H02 * A02);
        b->K[1][k] = wj * (c01 - H10) - M01 + (H00 * A01 + H01 * A11 + H02 * A12);
        b->K[2][k] = wj * (c02 - H20) - M02 + (H00 * A02 + H01 * A12 + H02 * A22);
        b->K[3][k] = wj * (c10 - H01) - M01 + (H10 * A00 + H11 * A01 + H12 * A02);
        b->K[4][k] = c0 + wj * (tr - H11 + c11) - M11 + (H10 * A01 + H11 * A11 + H12 * A12);
        b->K[5][k] = wj * (c12 - H21) - M12 + (H10 * A02 + H11 * A12 + H12 * A22);
        b->K[6][k] = wj * (c20 - H02) - M02 + (H20 * A00 + H21 * A01 + H22 * A02);
        b->K[7][k] = wj * (c21 - H12) - M12 + (H20 * A01 + H21 * A11 + H22 * A12);
        b->K[8][k] = c0 + wj * (tr - H22 + c22) - M22 + (H20 * A02 + H21 * A12 + H22 * A22);
    }
    heml__p_times_grad(R, b);
}

/* The Neo-Hookean force differential: with F = I + H, dH = dv V^-1, dJ = cof F : dH,
       dP = 2 c1 dH + U''(J) dJ cof F + w_J dcof F,   df_k = -Vol dP grad N_k,
   dcof F the derivative of the cofactors. Evaluated in the links (our form): with
   G = V^-1, F = v G, cof F = cof v cof G, cof G G^T = det G I and det G = 1 / (6 Vol), the
   three terms of df = -Vol dP G^T are
       df = -2 c1 dv A - s1 (cof v : dv) cof v - s2 dcof v,
       A = Vol G G^T,  s1 = U''(J) / (36 Vol),  s2 = w_J / 6,
   with v the current links and the columns of cof v the cross products c_1 = v2 x v3,
   c_2 = v3 x v1, c_3 = v1 x v2 (dcof v: their derivatives dv2 x v3 + v2 x dv3, ...). So
   what the linearisation point fixes is v, A, s1 and s2 (HEML__NC = 17 reals per
   tetrahedron: heml__diff_nh_point, the stiffness cache's layout) and a product needs
   nothing else (heml__diff_nh_apply: no rest constants, about 110 operations against 145
   for the same product through F). J, U''(J) and w_J as the force's (F = I + du V^-1 formed
   directly: J is not small at rest); v = (X_j - X_0) + du_j from the rest positions. Every
   product runs the same apply on the same point values, cached or not, so the cached
   product is bit-identical to the uncached one. */
static void heml__diff_nh_point(const heml__mat *mt, heml_real jm1_0, const heml_real *HEML__RESTRICT R,
                                const heml_real (*HEML__RESTRICT V)[HEML__W], const heml__blk *HEML__RESTRICT b,
                                heml_real *HEML__RESTRICT C)
{
    const heml_real p0 = mt->p0, kappa = mt->kappa;
    int k, r;
    for (r = 0; r < 9; r++) /* v = V + du */
        for (k = 0; k < HEML__W; k++) C[r * HEML__W + k] = V[r][k] + b->e[r][k];
    for (k = 0; k < HEML__W; k++) { /* A = Vol G G^T */
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real vol = R[9 * HEML__W + k];
        C[9 * HEML__W + k] = vol * (g10 * g10 + g11 * g11 + g12 * g12);
        C[10 * HEML__W + k] = vol * (g20 * g20 + g21 * g21 + g22 * g22);
        C[11 * HEML__W + k] = vol * (g30 * g30 + g31 * g31 + g32 * g32);
        C[12 * HEML__W + k] = vol * (g10 * g20 + g11 * g21 + g12 * g22);
        C[13 * HEML__W + k] = vol * (g10 * g30 + g11 * g31 + g12 * g32);
        C[14 * HEML__W + k] = vol * (g20 * g30 + g21 * g31 + g22 * g32);
    }
    for (k = 0; k < HEML__W; k++) { /* J, s1 = U''(J) / (36 Vol), s2 = w_J / 6 */
        heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
        heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
        heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real vol = R[9 * HEML__W + k];
        heml_real F00 = 1 + (a0 * g10 + b0 * g20 + d0 * g30), F01 = a0 * g11 + b0 * g21 + d0 * g31;
        heml_real F02 = a0 * g12 + b0 * g22 + d0 * g32, F10 = a1 * g10 + b1 * g20 + d1 * g30;
        heml_real F11 = 1 + (a1 * g11 + b1 * g21 + d1 * g31), F12 = a1 * g12 + b1 * g22 + d1 * g32;
        heml_real F20 = a2 * g10 + b2 * g20 + d2 * g30, F21 = a2 * g11 + b2 * g21 + d2 * g31;
        heml_real F22 = 1 + (a2 * g12 + b2 * g22 + d2 * g32);
        heml_real J = F00 * (F11 * F22 - F12 * F21) + F01 * (F12 * F20 - F10 * F22) + F02 * (F10 * F21 - F11 * F20);
        heml_real jc1 = heml__max(J - 1, jm1_0), Jc = 1 + jc1, d = (J - 1) - jc1, iJ = 1 / Jc;
        heml_real L = heml__log(Jc);
        heml_real hh = (kappa * (1 - L) + p0) * iJ * iJ;
        C[15 * HEML__W + k] = vol > 0 ? hh / (36 * vol) : 0; /* (padding lanes: 0) */
        C[16 * HEML__W + k] = ((kappa * L - p0) * iJ + hh * d) * (heml_real)(1.0 / 6.0);
    }
}

/* The product of the point values C (heml__diff_nh_point) with the links dv of dx in
   b->de, into b->f (nodes 1..3). */
static void heml__diff_nh_apply(const heml__mat *mt, const heml_real *HEML__RESTRICT C, heml__blk *HEML__RESTRICT b)
{
    const heml_real mu = 2 * mt->c1;
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real x0 = b->de[0][k], x1 = b->de[1][k], x2 = b->de[2][k]; /* dv1 */
        heml_real y0 = b->de[3][k], y1 = b->de[4][k], y2 = b->de[5][k]; /* dv2 */
        heml_real z0 = b->de[6][k], z1 = b->de[7][k], z2 = b->de[8][k]; /* dv3 */
        heml_real p0 = C[k], p1 = C[HEML__W + k], p2 = C[2 * HEML__W + k];               /* v1 */
        heml_real q0 = C[3 * HEML__W + k], q1 = C[4 * HEML__W + k], q2 = C[5 * HEML__W + k]; /* v2 */
        heml_real r0 = C[6 * HEML__W + k], r1 = C[7 * HEML__W + k], r2 = C[8 * HEML__W + k]; /* v3 */
        heml_real A11 = mu * C[9 * HEML__W + k], A22 = mu * C[10 * HEML__W + k], A33 = mu * C[11 * HEML__W + k];
        heml_real A12 = mu * C[12 * HEML__W + k], A13 = mu * C[13 * HEML__W + k], A23 = mu * C[14 * HEML__W + k];
        heml_real s1 = C[15 * HEML__W + k], s2 = C[16 * HEML__W + k];
        /* cof v: c1 = v2 x v3, c2 = v3 x v1, c3 = v1 x v2 */
        heml_real c10 = q1 * r2 - q2 * r1, c11 = q2 * r0 - q0 * r2, c12 = q0 * r1 - q1 * r0;
        heml_real c20 = r1 * p2 - r2 * p1, c21 = r2 * p0 - r0 * p2, c22 = r0 * p1 - r1 * p0;
        heml_real c30 = p1 * q2 - p2 * q1, c31 = p2 * q0 - p0 * q2, c32 = p0 * q1 - p1 * q0;
        heml_real t = s1 * ((c10 * x0 + c11 * x1 + c12 * x2) + (c20 * y0 + c21 * y1 + c22 * y2) +
                            (c30 * z0 + c31 * z1 + c32 * z2));
        /* dcof v: dc1 = dv2 x v3 + v2 x dv3, dc2 = dv3 x v1 + v3 x dv1, dc3 = dv1 x v2 + v1 x dv2 */
        heml_real e10 = (y1 * r2 - y2 * r1) + (q1 * z2 - q2 * z1), e11 = (y2 * r0 - y0 * r2) + (q2 * z0 - q0 * z2);
        heml_real e12 = (y0 * r1 - y1 * r0) + (q0 * z1 - q1 * z0);
        heml_real e20 = (z1 * p2 - z2 * p1) + (r1 * x2 - r2 * x1), e21 = (z2 * p0 - z0 * p2) + (r2 * x0 - r0 * x2);
        heml_real e22 = (z0 * p1 - z1 * p0) + (r0 * x1 - r1 * x0);
        heml_real e30 = (x1 * q2 - x2 * q1) + (p1 * y2 - p2 * y1), e31 = (x2 * q0 - x0 * q2) + (p2 * y0 - p0 * y2);
        heml_real e32 = (x0 * q1 - x1 * q0) + (p0 * y1 - p1 * y0);
        b->f[0][k] = -((x0 * A11 + y0 * A12 + z0 * A13) + t * c10 + s2 * e10);
        b->f[1][k] = -((x1 * A11 + y1 * A12 + z1 * A13) + t * c11 + s2 * e11);
        b->f[2][k] = -((x2 * A11 + y2 * A12 + z2 * A13) + t * c12 + s2 * e12);
        b->f[3][k] = -((x0 * A12 + y0 * A22 + z0 * A23) + t * c20 + s2 * e20);
        b->f[4][k] = -((x1 * A12 + y1 * A22 + z1 * A23) + t * c21 + s2 * e21);
        b->f[5][k] = -((x2 * A12 + y2 * A22 + z2 * A23) + t * c22 + s2 * e22);
        b->f[6][k] = -((x0 * A13 + y0 * A23 + z0 * A33) + t * c30 + s2 * e30);
        b->f[7][k] = -((x1 * A13 + y1 * A23 + z1 * A33) + t * c31 + s2 * e31);
        b->f[8][k] = -((x2 * A13 + y2 * A23 + z2 * A33) + t * c32 + s2 * e32);
    }
}

/* The uncached differential of block blk (links of u in b->e, of dx in b->de): point
   values into the workspace (the rest links gathered into b->H), then the product. */
static void heml__diff_nh(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b)
{
    const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
    heml__gather(m, m->blk_idx + (size_t)blk * 4 * HEML__W, m->rest, b->H);
    heml__diff_nh_point(mt, m->jm1_0, R, (const heml_real(*)[HEML__W])b->H, b, b->lin[0]);
    heml__diff_nh_apply(mt, b->lin[0], b);
}

/* The St Venant-Kirchhoff force differential (law heml__law_svk, HEML__DK_SVK): with
   S = lambda tr E I + 2 mu E, P = F S,
       dP = dF S + F dS,   dS = lambda tr dE I + 2 mu dE,   dE = sym(F^T dF),
   and in the links as heml__diff_nh's (F = v G, dF = dv G, G = V^-1, df = -Vol dP G^T):
   dE = G^T X G with X = sym(v^T dv), tr dE = X : G G^T, so
       df = -(dv B + v K),   B = Vol G S G^T,
       K = lambda (X : Ah) Ah + 2 mu Ah X Ah,   Ah = Vol G G^T / sqrt(Vol) = sqrt(Vol) G G^T
   (lambda Vol tr dE v G G^T = lambda (X : Ah) v Ah, 2 mu Vol v G G^T X G G^T = 2 mu v Ah X Ah).
   What the linearisation point fixes: v (9), Ah (6), B (6): HEML__NC_SVK = 21 reals
   (heml__diff_svk_point); a product (heml__diff_svk_apply) costs about 150 operations: v^T dv
   (27 multiply-adds), X Ah and Ah (X Ah) (45), v K and dv B (54) and a few. B comes from
   E = (H + H^T + H^T H) / 2 formed from the displacements (no cancellation at small
   strain, as the force's). Below J0 the law adds its guard (lambda + 2 mu) d^2 / 2: a block
   with a tetrahedron below J0 returns 1 from the point function and takes the general path
   (heml__block_diff_general), so does a material with a Prony series (mt->dk = 0) or a
   model with the nodal pressure. Cached and uncached products run the same functions on
   the same values: bit-identical. */
static int heml__diff_svk_point(const heml__mat *mt, heml_real jm1_0, int valid, const heml_real *HEML__RESTRICT R,
                                const heml_real (*HEML__RESTRICT V)[HEML__W], const heml__blk *HEML__RESTRICT b,
                                heml_real *HEML__RESTRICT C)
{
    const heml_real mu = mt->mu, lambda = mt->lambda;
    heml_real sv[HEML__W];
    int k, r, below = 0;
    for (r = 0; r < 9; r++) /* v = V + du */
        for (k = 0; k < HEML__W; k++) C[r * HEML__W + k] = V[r][k] + b->e[r][k];
    for (k = 0; k < HEML__W; k++) sv[k] = R[9 * HEML__W + k] > 0 ? R[9 * HEML__W + k] : 1; /* (padding: G = 0) */
    heml__sqrt_lanes(sv, HEML__W);
    for (k = 0; k < HEML__W; k++) {
        heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
        heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
        heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real vol = R[9 * HEML__W + k], ah = sv[k];
        heml_real H00 = a0 * g10 + b0 * g20 + d0 * g30, H01 = a0 * g11 + b0 * g21 + d0 * g31;
        heml_real H02 = a0 * g12 + b0 * g22 + d0 * g32, H10 = a1 * g10 + b1 * g20 + d1 * g30;
        heml_real H11 = a1 * g11 + b1 * g21 + d1 * g31, H12 = a1 * g12 + b1 * g22 + d1 * g32;
        heml_real H20 = a2 * g10 + b2 * g20 + d2 * g30, H21 = a2 * g11 + b2 * g21 + d2 * g31;
        heml_real H22 = a2 * g12 + b2 * g22 + d2 * g32;
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c11 = H00 * H22 - H02 * H20, c22 = H00 * H11 - H01 * H10;
        heml_real jm1 = (H00 + H11 + H22) + (c00 + c11 + c22) + (H00 * c00 + H01 * c01 + H02 * c02);
        /* S = lambda / 2 tr E2 I + mu E2, E2 = C - I = H + H^T + H^T H */
        heml_real E00 = 2 * H00 + (H00 * H00 + H10 * H10 + H20 * H20);
        heml_real E11 = 2 * H11 + (H01 * H01 + H11 * H11 + H21 * H21);
        heml_real E22 = 2 * H22 + (H02 * H02 + H12 * H12 + H22 * H22);
        heml_real E01 = H01 + H10 + (H00 * H01 + H10 * H11 + H20 * H21);
        heml_real E02 = H02 + H20 + (H00 * H02 + H10 * H12 + H20 * H22);
        heml_real E12 = H12 + H21 + (H01 * H02 + H11 * H12 + H21 * H22);
        heml_real st = lambda / 2 * (E00 + E11 + E22);
        heml_real S00 = st + mu * E00, S11 = st + mu * E11, S22 = st + mu * E22;
        heml_real S01 = mu * E01, S02 = mu * E02, S12 = mu * E12;
        /* u_j = S g_j, B_jl = Vol g_j . u_l, Ah_jl = sqrt(Vol) g_j . g_l */
        heml_real u10 = S00 * g10 + S01 * g11 + S02 * g12, u11 = S01 * g10 + S11 * g11 + S12 * g12;
        heml_real u12 = S02 * g10 + S12 * g11 + S22 * g12;
        heml_real u20 = S00 * g20 + S01 * g21 + S02 * g22, u21 = S01 * g20 + S11 * g21 + S12 * g22;
        heml_real u22 = S02 * g20 + S12 * g21 + S22 * g22;
        heml_real u30 = S00 * g30 + S01 * g31 + S02 * g32, u31 = S01 * g30 + S11 * g31 + S12 * g32;
        heml_real u32 = S02 * g30 + S12 * g31 + S22 * g32;
        below |= (k < valid) & (jm1 < jm1_0);
        C[9 * HEML__W + k] = ah * (g10 * g10 + g11 * g11 + g12 * g12);
        C[10 * HEML__W + k] = ah * (g20 * g20 + g21 * g21 + g22 * g22);
        C[11 * HEML__W + k] = ah * (g30 * g30 + g31 * g31 + g32 * g32);
        C[12 * HEML__W + k] = ah * (g10 * g20 + g11 * g21 + g12 * g22);
        C[13 * HEML__W + k] = ah * (g10 * g30 + g11 * g31 + g12 * g32);
        C[14 * HEML__W + k] = ah * (g20 * g30 + g21 * g31 + g22 * g32);
        C[15 * HEML__W + k] = vol * (g10 * u10 + g11 * u11 + g12 * u12);
        C[16 * HEML__W + k] = vol * (g20 * u20 + g21 * u21 + g22 * u22);
        C[17 * HEML__W + k] = vol * (g30 * u30 + g31 * u31 + g32 * u32);
        C[18 * HEML__W + k] = vol * (g10 * u20 + g11 * u21 + g12 * u22);
        C[19 * HEML__W + k] = vol * (g10 * u30 + g11 * u31 + g12 * u32);
        C[20 * HEML__W + k] = vol * (g20 * u30 + g21 * u31 + g22 * u32);
    }
    return below;
}

/* The product of the point values C (heml__diff_svk_point) with the links dv of dx in
   b->de, into b->f (nodes 1..3): df = -(dv B + v K). */
static void heml__diff_svk_apply(const heml__mat *mt, const heml_real *HEML__RESTRICT C, heml__blk *HEML__RESTRICT b)
{
    const heml_real lambda = mt->lambda, mu2 = 2 * mt->mu;
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real x0 = b->de[0][k], x1 = b->de[1][k], x2 = b->de[2][k]; /* dv1 */
        heml_real y0 = b->de[3][k], y1 = b->de[4][k], y2 = b->de[5][k]; /* dv2 */
        heml_real z0 = b->de[6][k], z1 = b->de[7][k], z2 = b->de[8][k]; /* dv3 */
        heml_real p0 = C[k], p1 = C[HEML__W + k], p2 = C[2 * HEML__W + k];               /* v1 */
        heml_real q0 = C[3 * HEML__W + k], q1 = C[4 * HEML__W + k], q2 = C[5 * HEML__W + k]; /* v2 */
        heml_real r0 = C[6 * HEML__W + k], r1 = C[7 * HEML__W + k], r2 = C[8 * HEML__W + k]; /* v3 */
        heml_real A11 = C[9 * HEML__W + k], A22 = C[10 * HEML__W + k], A33 = C[11 * HEML__W + k];
        heml_real A12 = C[12 * HEML__W + k], A13 = C[13 * HEML__W + k], A23 = C[14 * HEML__W + k];
        heml_real B11 = C[15 * HEML__W + k], B22 = C[16 * HEML__W + k], B33 = C[17 * HEML__W + k];
        heml_real B12 = C[18 * HEML__W + k], B13 = C[19 * HEML__W + k], B23 = C[20 * HEML__W + k];
        /* X = sym(v^T dv): X_jl = (v_j . dv_l + v_l . dv_j) / 2 */
        heml_real X11 = p0 * x0 + p1 * x1 + p2 * x2, X22 = q0 * y0 + q1 * y1 + q2 * y2;
        heml_real X33 = r0 * z0 + r1 * z1 + r2 * z2;
        heml_real X12 = ((p0 * y0 + p1 * y1 + p2 * y2) + (q0 * x0 + q1 * x1 + q2 * x2)) / 2;
        heml_real X13 = ((p0 * z0 + p1 * z1 + p2 * z2) + (r0 * x0 + r1 * x1 + r2 * x2)) / 2;
        heml_real X23 = ((q0 * z0 + q1 * z1 + q2 * z2) + (r0 * y0 + r1 * y1 + r2 * y2)) / 2;
        /* T = X Ah, K = la Ah + 2 mu Ah T (symmetric), la = lambda X : Ah = lambda tr T */
        heml_real T11 = X11 * A11 + X12 * A12 + X13 * A13, T12 = X11 * A12 + X12 * A22 + X13 * A23;
        heml_real T13 = X11 * A13 + X12 * A23 + X13 * A33, T21 = X12 * A11 + X22 * A12 + X23 * A13;
        heml_real T22 = X12 * A12 + X22 * A22 + X23 * A23, T23 = X12 * A13 + X22 * A23 + X23 * A33;
        heml_real T31 = X13 * A11 + X23 * A12 + X33 * A13, T32 = X13 * A12 + X23 * A22 + X33 * A23;
        heml_real T33 = X13 * A13 + X23 * A23 + X33 * A33, la = lambda * (T11 + T22 + T33);
        heml_real K11 = la * A11 + mu2 * (A11 * T11 + A12 * T21 + A13 * T31);
        heml_real K22 = la * A22 + mu2 * (A12 * T12 + A22 * T22 + A23 * T32);
        heml_real K33 = la * A33 + mu2 * (A13 * T13 + A23 * T23 + A33 * T33);
        heml_real K12 = la * A12 + mu2 * (A11 * T12 + A12 * T22 + A13 * T32);
        heml_real K13 = la * A13 + mu2 * (A11 * T13 + A12 * T23 + A13 * T33);
        heml_real K23 = la * A23 + mu2 * (A12 * T13 + A22 * T23 + A23 * T33);
        b->f[0][k] = -((x0 * B11 + y0 * B12 + z0 * B13) + (p0 * K11 + q0 * K12 + r0 * K13));
        b->f[1][k] = -((x1 * B11 + y1 * B12 + z1 * B13) + (p1 * K11 + q1 * K12 + r1 * K13));
        b->f[2][k] = -((x2 * B11 + y2 * B12 + z2 * B13) + (p2 * K11 + q2 * K12 + r2 * K13));
        b->f[3][k] = -((x0 * B12 + y0 * B22 + z0 * B23) + (p0 * K12 + q0 * K22 + r0 * K23));
        b->f[4][k] = -((x1 * B12 + y1 * B22 + z1 * B23) + (p1 * K12 + q1 * K22 + r1 * K23));
        b->f[5][k] = -((x2 * B12 + y2 * B22 + z2 * B23) + (p2 * K12 + q2 * K22 + r2 * K23));
        b->f[6][k] = -((x0 * B13 + y0 * B23 + z0 * B33) + (p0 * K13 + q0 * K23 + r0 * K33));
        b->f[7][k] = -((x1 * B13 + y1 * B23 + z1 * B33) + (p1 * K13 + q1 * K23 + r1 * K33));
        b->f[8][k] = -((x2 * B13 + y2 * B23 + z2 * B33) + (p2 * K13 + q2 * K23 + r2 * K33));
    }
}

/* The uncached St Venant-Kirchhoff differential of block blk (links of u in b->e, of dx in
   b->de), as heml__diff_nh; returns 1 (nothing computed) for a block below J0. */
static int heml__diff_svk(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b)
{
    const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
    heml__gather(m, m->blk_idx + (size_t)blk * 4 * HEML__W, m->rest, b->H);
    if (heml__diff_svk_point(mt, m->jm1_0, m->blk_valid[blk], R, (const heml_real(*)[HEML__W])b->H, b, b->lin[0]))
        return 1;
    heml__diff_svk_apply(mt, b->lin[0], b);
    return 0;
}

/* The split Mooney-Rivlin force differential (law heml__law_split, HEML__DK_MR), in the
   links as heml__diff_nh's and heml__diff_svk's. With P = 2 a F - F M + w_J cof F
   (heml__coefficients: a = w_1 + (I1 - 1) w_2, M = 2 w_2 (C - I)) and this law's second
   derivatives (w_11 = w_12 = w_22 = 0, also below J0, where its factors are continued),
       dP = 2 da F + 2 a dF - dF M - F dM + dw_J cof F + w_J dcof F,
       dw_1 = w_1J dJ, dw_2 = w_2J dJ, dw_J = w_1J dI1 + w_2J dI2 + w_JJ dJ,
       da = dw_1 + (I1 - 1) dw_2 + w_2 dI1, dM = 2 (dw_2 (C - I) + w_2 dC),
   and in the links (X = sym(v^T dv), z = sqrt(Vol), Ah = z G G^T, Nh = z G (C - I) G^T,
   dC = 2 G^T X G, dI1 = 2 (X : Ah) / z, dI2 = (I1 - 1) dI1 - 2 (X : Nh) / z,
   dJ = (cof v : dv) / (6 Vol), r = 1 / (6 z)):
       df = -(dv B + v K + t cof v + (w_J / 6) dcof v),   B = Vol G (2 a I - M) G^T
                                                          = z (2 a Ah - 2 w_2 Nh),
       K = (2 ca g + 4 w_2 al) Ah - 2 cb g Nh - 4 w_2 Ah X Ah,
       t = 2 ca al - 2 cb nu + cc g,
   al = X : Ah, nu = X : Nh, g = cof v : dv, ca = r (w_1J + (I1 - 1) w_2J), cb = r w_2J,
   cc = r^2 w_JJ. Nh enters only with B: with za = 2 a z, zm = 2 w_2 z (B = za Ah - zm Nh)
   and beta = 2 cb / zm = w_2J / (6 Vol w_2) (the law's c2 cancels; 0 where w_2 = 0, which
   has cb = 0 too), 2 cb Nh = beta (za Ah - B) and 2 cb nu = beta (za al - X : B), so
       K = (ca' g + 4 w_2 al) Ah + beta g B - 4 w_2 Ah X Ah,   t = ca' al + beta X : B + cc g,
   ca' = 2 ca - beta za (the two beta za terms are of the size of 2 ca's: no cancellation
   beyond round-off). The point values: v (9), Ah, B (6 each), ca', beta, cc, w_J / 6,
   4 w_2: HEML__NC_MR = 26 reals (until issue 21's fourth part Nh and its two scalars, 28
   reals and 12 operations more a product; B stored besides them, 32 reals, was measured
   no faster); a product about 250 operations, al = tr(X Ah) from T = X Ah. The law and the stress
   coefficients at the point come from heml__law_split and heml__coefficients themselves
   (the general path's kinematics), so the continuation below J0 needs no fallback; Prony
   and the nodal pressure take the general path (mt->dk = 0). */
static void heml__diff_mr_point(const heml_model *m, const heml__mat *mt, int blk, heml__blk *HEML__RESTRICT b,
                                heml_real *HEML__RESTRICT C)
{
    const heml_real *HEML__RESTRICT R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
    heml_real sv[HEML__W];
    int k, r;
    for (r = 0; r < 9; r++) /* v = V + du (the rest links in b->f) */
        for (k = 0; k < HEML__W; k++) C[r * HEML__W + k] = b->f[r][k] + b->e[r][k];
    heml__kinematics(R, b);
    heml__clamp_J(m->jm1_0, b);
    heml__law(mt, b, m->blk_valid[blk], HEML__WANT_SECOND);
    heml__coefficients(b, mt->uses_i2);
    for (k = 0; k < HEML__W; k++) sv[k] = R[9 * HEML__W + k] > 0 ? R[9 * HEML__W + k] : 1; /* (padding: G = 0) */
    heml__sqrt_lanes(sv, HEML__W);
    for (k = 0; k < HEML__W; k++) {
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real vol = R[9 * HEML__W + k], z = sv[k], rr = vol > 0 ? 1 / (6 * z) : 0;
        heml_real E00 = b->E2[0][k], E11 = b->E2[1][k], E22 = b->E2[2][k];
        heml_real E01 = b->E2[3][k], E02 = b->E2[4][k], E12 = b->E2[5][k];
        heml_real a2 = 2 * b->co[1][k], w2 = b->w2[k], m2 = 2 * w2, I1m1 = 2 + b->I1m3[k];
        /* u_j = E2 g_j; S = 2 a I - 2 w_2 E2, so S g_j = 2 a g_j - 2 w_2 u_j */
        heml_real u10 = E00 * g10 + E01 * g11 + E02 * g12, u11 = E01 * g10 + E11 * g11 + E12 * g12;
        heml_real u12 = E02 * g10 + E12 * g11 + E22 * g12;
        heml_real u20 = E00 * g20 + E01 * g21 + E02 * g22, u21 = E01 * g20 + E11 * g21 + E12 * g22;
        heml_real u22 = E02 * g20 + E12 * g21 + E22 * g22;
        heml_real u30 = E00 * g30 + E01 * g31 + E02 * g32, u31 = E01 * g30 + E11 * g31 + E12 * g32;
        heml_real u32 = E02 * g30 + E12 * g31 + E22 * g32;
        heml_real q11 = g10 * g10 + g11 * g11 + g12 * g12, q22 = g20 * g20 + g21 * g21 + g22 * g22;
        heml_real q33 = g30 * g30 + g31 * g31 + g32 * g32, q12 = g10 * g20 + g11 * g21 + g12 * g22;
        heml_real q13 = g10 * g30 + g11 * g31 + g12 * g32, q23 = g20 * g30 + g21 * g31 + g22 * g32;
        heml_real n11 = g10 * u10 + g11 * u11 + g12 * u12, n22 = g20 * u20 + g21 * u21 + g22 * u22;
        heml_real n33 = g30 * u30 + g31 * u31 + g32 * u32, n12 = g10 * u20 + g11 * u21 + g12 * u22;
        heml_real n13 = g10 * u30 + g11 * u31 + g12 * u32, n23 = g20 * u30 + g21 * u31 + g22 * u32;
        heml_real za = vol > 0 ? z * a2 : 0, zm = vol > 0 ? z * m2 : 0;
        heml_real ca2 = 2 * rr * (b->h[2][k] + I1m1 * b->h[4][k]), cb2 = 2 * rr * b->h[4][k];
        heml_real be = zm != 0 ? cb2 / zm : 0; /* beta = cb2 / zm = w_2J / (6 Vol w_2): c2 cancels */
        C[9 * HEML__W + k] = z * q11;
        C[10 * HEML__W + k] = z * q22;
        C[11 * HEML__W + k] = z * q33;
        C[12 * HEML__W + k] = z * q12;
        C[13 * HEML__W + k] = z * q13;
        C[14 * HEML__W + k] = z * q23;
        /* B = Vol G (2 a I - 2 w_2 (C - I)) G^T = z (2 a Ah - 2 w_2 Nh) = za Ah - zm Nh */
        C[15 * HEML__W + k] = za * (z * q11) - zm * (z * n11);
        C[16 * HEML__W + k] = za * (z * q22) - zm * (z * n22);
        C[17 * HEML__W + k] = za * (z * q33) - zm * (z * n33);
        C[18 * HEML__W + k] = za * (z * q12) - zm * (z * n12);
        C[19 * HEML__W + k] = za * (z * q13) - zm * (z * n13);
        C[20 * HEML__W + k] = za * (z * q23) - zm * (z * n23);
        C[21 * HEML__W + k] = ca2 - be * za; /* ca2 - beta za */
        C[22 * HEML__W + k] = be;
        C[23 * HEML__W + k] = rr * rr * b->h[5][k];
        C[24 * HEML__W + k] = b->co[2][k] * (heml_real)(1.0 / 6.0);
        C[25 * HEML__W + k] = 4 * w2;
    }
}

/* The product of the point values C (heml__diff_mr_point) with the links dv of dx in
   b->de, into b->f (nodes 1..3). */
static void heml__diff_mr_apply(const heml_real *HEML__RESTRICT C, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real x0 = b->de[0][k], x1 = b->de[1][k], x2 = b->de[2][k]; /* dv1 */
        heml_real y0 = b->de[3][k], y1 = b->de[4][k], y2 = b->de[5][k]; /* dv2 */
        heml_real z0 = b->de[6][k], z1 = b->de[7][k], z2 = b->de[8][k]; /* dv3 */
        heml_real p0 = C[k], p1 = C[HEML__W + k], p2 = C[2 * HEML__W + k];               /* v1 */
        heml_real q0 = C[3 * HEML__W + k], q1 = C[4 * HEML__W + k], q2 = C[5 * HEML__W + k]; /* v2 */
        heml_real r0 = C[6 * HEML__W + k], r1 = C[7 * HEML__W + k], r2 = C[8 * HEML__W + k]; /* v3 */
        heml_real A11 = C[9 * HEML__W + k], A22 = C[10 * HEML__W + k], A33 = C[11 * HEML__W + k];
        heml_real A12 = C[12 * HEML__W + k], A13 = C[13 * HEML__W + k], A23 = C[14 * HEML__W + k];
        heml_real B11 = C[15 * HEML__W + k], B22 = C[16 * HEML__W + k], B33 = C[17 * HEML__W + k];
        heml_real B12 = C[18 * HEML__W + k], B13 = C[19 * HEML__W + k], B23 = C[20 * HEML__W + k];
        heml_real cap = C[21 * HEML__W + k], be = C[22 * HEML__W + k], cc = C[23 * HEML__W + k];
        heml_real s2 = C[24 * HEML__W + k], w4 = C[25 * HEML__W + k];
        heml_real X11 = p0 * x0 + p1 * x1 + p2 * x2, X22 = q0 * y0 + q1 * y1 + q2 * y2;
        heml_real X33 = r0 * z0 + r1 * z1 + r2 * z2;
        heml_real X12 = ((p0 * y0 + p1 * y1 + p2 * y2) + (q0 * x0 + q1 * x1 + q2 * x2)) / 2;
        heml_real X13 = ((p0 * z0 + p1 * z1 + p2 * z2) + (r0 * x0 + r1 * x1 + r2 * x2)) / 2;
        heml_real X23 = ((q0 * z0 + q1 * z1 + q2 * z2) + (r0 * y0 + r1 * y1 + r2 * y2)) / 2;
        heml_real xb = (X11 * B11 + X22 * B22 + X33 * B33) + 2 * (X12 * B12 + X13 * B13 + X23 * B23);
        /* cof v: c1 = v2 x v3, c2 = v3 x v1, c3 = v1 x v2; g = cof v : dv */
        heml_real c10 = q1 * r2 - q2 * r1, c11 = q2 * r0 - q0 * r2, c12 = q0 * r1 - q1 * r0;
        heml_real c20 = r1 * p2 - r2 * p1, c21 = r2 * p0 - r0 * p2, c22 = r0 * p1 - r1 * p0;
        heml_real c30 = p1 * q2 - p2 * q1, c31 = p2 * q0 - p0 * q2, c32 = p0 * q1 - p1 * q0;
        heml_real g = (c10 * x0 + c11 * x1 + c12 * x2) + (c20 * y0 + c21 * y1 + c22 * y2) + (c30 * z0 + c31 * z1 + c32 * z2);
        heml_real e10 = (y1 * r2 - y2 * r1) + (q1 * z2 - q2 * z1), e11 = (y2 * r0 - y0 * r2) + (q2 * z0 - q0 * z2);
        heml_real e12 = (y0 * r1 - y1 * r0) + (q0 * z1 - q1 * z0);
        heml_real e20 = (z1 * p2 - z2 * p1) + (r1 * x2 - r2 * x1), e21 = (z2 * p0 - z0 * p2) + (r2 * x0 - r0 * x2);
        heml_real e22 = (z0 * p1 - z1 * p0) + (r0 * x1 - r1 * x0);
        heml_real e30 = (x1 * q2 - x2 * q1) + (p1 * y2 - p2 * y1), e31 = (x2 * q0 - x0 * q2) + (p2 * y0 - p0 * y2);
        heml_real e32 = (x0 * q1 - x1 * q0) + (p0 * y1 - p1 * y0);
        /* T = X Ah, Ah X Ah = Ah T, al = X : Ah = tr T */
        heml_real T11 = X11 * A11 + X12 * A12 + X13 * A13, T12 = X11 * A12 + X12 * A22 + X13 * A23;
        heml_real T13 = X11 * A13 + X12 * A23 + X13 * A33, T21 = X12 * A11 + X22 * A12 + X23 * A13;
        heml_real T22 = X12 * A12 + X22 * A22 + X23 * A23, T23 = X12 * A13 + X22 * A23 + X23 * A33;
        heml_real T31 = X13 * A11 + X23 * A12 + X33 * A13, T32 = X13 * A12 + X23 * A22 + X33 * A23;
        heml_real T33 = X13 * A13 + X23 * A23 + X33 * A33, al = T11 + T22 + T33;
        heml_real t = cap * al + be * xb + cc * g, kA = cap * g + w4 * al, kB = be * g;
        heml_real K11 = kA * A11 + kB * B11 - w4 * (A11 * T11 + A12 * T21 + A13 * T31);
        heml_real K22 = kA * A22 + kB * B22 - w4 * (A12 * T12 + A22 * T22 + A23 * T32);
        heml_real K33 = kA * A33 + kB * B33 - w4 * (A13 * T13 + A23 * T23 + A33 * T33);
        heml_real K12 = kA * A12 + kB * B12 - w4 * (A11 * T12 + A12 * T22 + A13 * T32);
        heml_real K13 = kA * A13 + kB * B13 - w4 * (A11 * T13 + A12 * T23 + A13 * T33);
        heml_real K23 = kA * A23 + kB * B23 - w4 * (A12 * T13 + A22 * T23 + A23 * T33);
        b->f[0][k] = -((x0 * B11 + y0 * B12 + z0 * B13) + (p0 * K11 + q0 * K12 + r0 * K13) + t * c10 + s2 * e10);
        b->f[1][k] = -((x1 * B11 + y1 * B12 + z1 * B13) + (p1 * K11 + q1 * K12 + r1 * K13) + t * c11 + s2 * e11);
        b->f[2][k] = -((x2 * B11 + y2 * B12 + z2 * B13) + (p2 * K11 + q2 * K12 + r2 * K13) + t * c12 + s2 * e12);
        b->f[3][k] = -((x0 * B12 + y0 * B22 + z0 * B23) + (p0 * K12 + q0 * K22 + r0 * K23) + t * c20 + s2 * e20);
        b->f[4][k] = -((x1 * B12 + y1 * B22 + z1 * B23) + (p1 * K12 + q1 * K22 + r1 * K23) + t * c21 + s2 * e21);
        b->f[5][k] = -((x2 * B12 + y2 * B22 + z2 * B23) + (p2 * K12 + q2 * K22 + r2 * K23) + t * c22 + s2 * e22);
        b->f[6][k] = -((x0 * B13 + y0 * B23 + z0 * B33) + (p0 * K13 + q0 * K23 + r0 * K33) + t * c30 + s2 * e30);
        b->f[7][k] = -((x1 * B13 + y1 * B23 + z1 * B33) + (p1 * K13 + q1 * K23 + r1 * K33) + t * c31 + s2 * e31);
        b->f[8][k] = -((x2 * B13 + y2 * B23 + z2 * B33) + (p2 * K13 + q2 * K23 + r2 * K33) + t * c32 + s2 * e32);
    }
}

/* The uncached split Mooney-Rivlin differential of block blk (links of u in b->e, of dx in
   b->de): the rest links gathered into b->f, the point values into b->lin, the product. */
static void heml__diff_mr(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b)
{
    heml__gather(m, m->blk_idx + (size_t)blk * 4 * HEML__W, m->rest, b->f);
    heml__diff_mr_point(m, mt, blk, b, b->lin[0]);
    heml__diff_mr_apply(b->lin[0], b);
}

/* The average nodal pressure's share of a block whose law was just evaluated (NEAR-
   INCOMPRESSIBLE BODIES): the element's own volumetric function U(J_e) comes off (w -= U,
   w_J -= U', w_JJ -= U'') and the mean of its four nodes' pressures p_e = sum P_a / 4 goes
   on (w_J += p_e; s0 the same, as s0 = 2 w_1 + 4 w_2 + w_J); with second derivatives also
   dp (the mean of the nodes' dP_a, read by heml__diff_general). */
static void heml__nodal_element(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b, int want)
{
    const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
    const heml_real *p = m->nod_p, *dp = m->nod_dp;
    heml_real U[HEML__W], U1[HEML__W], U2[HEML__W];
    heml__blk s;
    int k;
    heml__dilation(mt, m->jm1_0, b->jm1, m->blk_valid[blk], want, &s, U, U1, U2);
    for (k = 0; k < HEML__W; k++) {
        int i0 = idx[k], i1 = idx[HEML__W + k], i2 = idx[2 * HEML__W + k], i3 = idx[3 * HEML__W + k];
        heml_real pe = ((p[i0] + p[i1]) + (p[i2] + p[i3])) / 4 - U1[k];
        b->wJ[k] += pe;
        b->s0[k] += pe;
        b->h[5][k] -= U2[k];
        if (want & HEML__WANT_ENERGY) b->w[k] -= U[k];
        if (want & HEML__WANT_SECOND) b->dp[k] = ((dp[i0] + dp[i1]) + (dp[i2] + dp[i3])) / 4;
    }
}

/* Kinematics, law and stress coefficients of one general block (not springs), Prony
   applied (written to the next state when prony_write). */
static void heml__block_stress(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b, int want,
                               int prony_write)
{
    const heml_real *HEML__RESTRICT R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
    heml__kinematics(R, b);
    heml__clamp_J(m->jm1_0, b);
    heml__law(mt, b, m->blk_valid[blk], want);
    if (m->nodal) heml__nodal_element(m, mt, blk, b, want);
    heml__coefficients(b, mt->uses_i2);
    if (mt->prony_count) heml__prony(m, mt, blk, b, mt->uses_i2 ? 9 : 3, prony_write);
}

/* Elastic energy of the block's valid lanes (J, sum Vol w, in double) from a workspace
   whose law was evaluated with HEML__WANT_ENERGY. */
static double heml__lanes_energy(const heml_model *m, const heml__mat *mt, int blk, const heml__blk *b)
{
    const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
    double sum = 0.0;
    int k, valid = m->blk_valid[blk];
    for (k = 0; k < valid; k++) sum += (mt->kind == HEML__K_SPRING ? 1.0 : (double)R[9 * HEML__W + k]) * (double)b->w[k];
    return sum;
}

/* Forces of one block at displacements u into b->f (and J - 1, for the statistics);
   with want_energy also its elastic energy (returned, J; 0 otherwise). */
static double heml__block_forces(const heml_model *m, const heml__mat *mt, int blk, const heml_real *u,
                                 heml__blk *b, int prony_write, int want_energy)
{
    const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
    const heml_real *HEML__RESTRICT R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
    if (mt->fast_nodal && !want_energy && u == m->nod_hx) { /* (H kept by this pass's sums) */
        heml__forces_nh_kept(mt, m->jm1_0, R, m->nod_p, idx, m->tet_h + (size_t)blk * 9 * HEML__W, b);
        return 0.0;
    }
    heml__gather(m, idx, u, b->e);
    if (mt->kind == HEML__K_SPRING) {
        heml__spring_rest_links(R, b);
        heml__spring_J(R, b);
        heml__spring_tensions(mt->young, R, b, want_energy);
        if (mt->prony_count) heml__prony(m, mt, blk, b, 6, prony_write);
        heml__spring_forces(b, b->co);
        return want_energy ? heml__lanes_energy(m, mt, blk, b) : 0.0;
    }
    if (mt->fast && !want_energy) { /* (the law's fast_path flag: heml__laws) */
        heml__forces_nh(mt, m->jm1_0, R, NULL, idx, b);
        return 0.0;
    }
    if (mt->fast_nodal && !want_energy) {
        heml__forces_nh(mt, m->jm1_0, R, m->nod_p, idx, b);
        return 0.0;
    }
    if (mt->fast_mr && !want_energy) {
        heml__forces_mr(mt, m->jm1_0, R, b);
        return 0.0;
    }
    heml__block_stress(m, mt, blk, b, want_energy ? HEML__WANT_ENERGY : 0, prony_write);
    heml__pk1_forces(R, b);
    return want_energy ? heml__lanes_energy(m, mt, blk, b) : 0.0;
}

/* The differential's last stage, one loop (see heml__block_diff), written out so that it
   vectorises (restrict parameters: the workspace escapes to user callbacks). */
static void heml__diff_general(heml_real sp, const heml_real *HEML__RESTRICT R, heml__blk *HEML__RESTRICT b)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real x0 = b->de[0][k], x1 = b->de[1][k], x2 = b->de[2][k];
        heml_real y0 = b->de[3][k], y1 = b->de[4][k], y2 = b->de[5][k];
        heml_real z0 = b->de[6][k], z1 = b->de[7][k], z2 = b->de[8][k];
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real vol = R[9 * HEML__W + k];
        heml_real H00 = b->H[0][k], H01 = b->H[1][k], H02 = b->H[2][k];
        heml_real H10 = b->H[3][k], H11 = b->H[4][k], H12 = b->H[5][k];
        heml_real H20 = b->H[6][k], H21 = b->H[7][k], H22 = b->H[8][k];
        heml_real F00 = 1 + H00, F11 = 1 + H11, F22 = 1 + H22;
        heml_real C00 = 1 + b->K[0][k], C01 = b->K[1][k], C02 = b->K[2][k];
        heml_real C10 = b->K[3][k], C11 = 1 + b->K[4][k], C12 = b->K[5][k];
        heml_real C20 = b->K[6][k], C21 = b->K[7][k], C22 = 1 + b->K[8][k];
        heml_real E00 = b->E2[0][k], E11 = b->E2[1][k], E22 = b->E2[2][k];
        heml_real E01 = b->E2[3][k], E02 = b->E2[4][k], E12 = b->E2[5][k];
        heml_real t = b->I1m3[k], w2 = b->w2[k];
        heml_real D00 = x0 * g10 + y0 * g20 + z0 * g30, D01 = x0 * g11 + y0 * g21 + z0 * g31;
        heml_real D02 = x0 * g12 + y0 * g22 + z0 * g32, D10 = x1 * g10 + y1 * g20 + z1 * g30;
        heml_real D11 = x1 * g11 + y1 * g21 + z1 * g31, D12 = x1 * g12 + y1 * g22 + z1 * g32;
        heml_real D20 = x2 * g10 + y2 * g20 + z2 * g30, D21 = x2 * g11 + y2 * g21 + z2 * g31;
        heml_real D22 = x2 * g12 + y2 * g22 + z2 * g32;
        /* dE2 = dH^T F + F^T dH (symmetric) */
        heml_real q00 = 2 * (D00 * F00 + D10 * H10 + D20 * H20);
        heml_real q11 = 2 * (D01 * H01 + D11 * F11 + D21 * H21);
        heml_real q22 = 2 * (D02 * H02 + D12 * H12 + D22 * F22);
        heml_real q01 = D00 * H01 + D10 * F11 + D20 * H21 + F00 * D01 + H10 * D11 + H20 * D21;
        heml_real q02 = D00 * H02 + D10 * H12 + D20 * F22 + F00 * D02 + H10 * D12 + H20 * D22;
        heml_real q12 = D01 * H02 + D11 * H12 + D21 * F22 + H01 * D02 + F11 * D12 + H21 * D22;
        heml_real dI1 = q00 + q11 + q22;
        heml_real dI2 = (2 + t) * dI1 - (E00 * q00 + E11 * q11 + E22 * q22 + 2 * (E01 * q01 + E02 * q02 + E12 * q12));
        heml_real dJ = C00 * D00 + C01 * D01 + C02 * D02 + C10 * D10 + C11 * D11 + C12 * D12 + C20 * D20 +
                       C21 * D21 + C22 * D22;
        heml_real dw1 = b->h[0][k] * dI1 + b->h[1][k] * dI2 + b->h[2][k] * dJ;
        heml_real dw2 = b->h[1][k] * dI1 + b->h[3][k] * dI2 + b->h[4][k] * dJ;
        heml_real dwJ = b->h[2][k] * dI1 + b->h[4][k] * dI2 + b->h[5][k] * dJ + b->dp[k];
        heml_real da2 = 2 * sp * vol * (dw1 + (2 + t) * dw2 + w2 * dI1), dwj = sp * vol * dwJ;
        heml_real a2 = 2 * vol * b->co[1][k], wj = vol * b->co[2][k];
        /* M~ (filtered) and s dM = 2 s (dw2 E2 + w2 dE2), both times Vol */
        heml_real m00 = vol * b->co[3][k], m11 = vol * b->co[4][k], m22 = vol * b->co[5][k];
        heml_real m01 = vol * b->co[6][k], m02 = vol * b->co[7][k], m12 = vol * b->co[8][k];
        heml_real sd = 2 * sp * vol * dw2, sw = 2 * sp * vol * w2;
        heml_real n00 = sd * E00 + sw * q00, n11 = sd * E11 + sw * q11, n22 = sd * E22 + sw * q22;
        heml_real n01 = sd * E01 + sw * q01, n02 = sd * E02 + sw * q02, n12 = sd * E12 + sw * q12;
        /* dcof F */
        heml_real dC00 = D11 * F22 + F11 * D22 - D12 * H21 - H12 * D21;
        heml_real dC01 = D12 * H20 + H12 * D20 - D10 * F22 - H10 * D22;
        heml_real dC02 = D10 * H21 + H10 * D21 - D11 * H20 - F11 * D20;
        heml_real dC10 = D02 * H21 + H02 * D21 - D01 * F22 - H01 * D22;
        heml_real dC11 = D00 * F22 + F00 * D22 - D02 * H20 - H02 * D20;
        heml_real dC12 = D01 * H20 + H01 * D20 - D00 * H21 - F00 * D21;
        heml_real dC20 = D01 * H12 + H01 * D12 - D02 * F11 - H02 * D11;
        heml_real dC21 = D02 * H10 + H02 * D10 - D00 * H12 - F00 * D12;
        heml_real dC22 = D00 * F11 + F00 * D11 - D01 * H10 - H01 * D10;
        /* dP = 2 s da F + s dw_J cof F + 2 a dH + w_J dcof F - dH M~ - F s dM */
        heml_real P00 = da2 * F00 + dwj * C00 + a2 * D00 + wj * dC00 - (D00 * m00 + D01 * m01 + D02 * m02) -
                        (F00 * n00 + H01 * n01 + H02 * n02);
        heml_real P01 = da2 * H01 + dwj * C01 + a2 * D01 + wj * dC01 - (D00 * m01 + D01 * m11 + D02 * m12) -
                        (F00 * n01 + H01 * n11 + H02 * n12);
        heml_real P02 = da2 * H02 + dwj * C02 + a2 * D02 + wj * dC02 - (D00 * m02 + D01 * m12 + D02 * m22) -
                        (F00 * n02 + H01 * n12 + H02 * n22);
        heml_real P10 = da2 * H10 + dwj * C10 + a2 * D10 + wj * dC10 - (D10 * m00 + D11 * m01 + D12 * m02) -
                        (H10 * n00 + F11 * n01 + H12 * n02);
        heml_real P11 = da2 * F11 + dwj * C11 + a2 * D11 + wj * dC11 - (D10 * m01 + D11 * m11 + D12 * m12) -
                        (H10 * n01 + F11 * n11 + H12 * n12);
        heml_real P12 = da2 * H12 + dwj * C12 + a2 * D12 + wj * dC12 - (D10 * m02 + D11 * m12 + D12 * m22) -
                        (H10 * n02 + F11 * n12 + H12 * n22);
        heml_real P20 = da2 * H20 + dwj * C20 + a2 * D20 + wj * dC20 - (D20 * m00 + D21 * m01 + D22 * m02) -
                        (H20 * n00 + H21 * n01 + F22 * n02);
        heml_real P21 = da2 * H21 + dwj * C21 + a2 * D21 + wj * dC21 - (D20 * m01 + D21 * m11 + D22 * m12) -
                        (H20 * n01 + H21 * n11 + F22 * n12);
        heml_real P22 = da2 * F22 + dwj * C22 + a2 * D22 + wj * dC22 - (D20 * m02 + D21 * m12 + D22 * m22) -
                        (H20 * n02 + H21 * n12 + F22 * n22);
        b->f[0][k] = -(P00 * g10 + P01 * g11 + P02 * g12);
        b->f[1][k] = -(P10 * g10 + P11 * g11 + P12 * g12);
        b->f[2][k] = -(P20 * g10 + P21 * g11 + P22 * g12);
        b->f[3][k] = -(P00 * g20 + P01 * g21 + P02 * g22);
        b->f[4][k] = -(P10 * g20 + P11 * g21 + P12 * g22);
        b->f[5][k] = -(P20 * g20 + P21 * g21 + P22 * g22);
        b->f[6][k] = -(P00 * g30 + P01 * g31 + P02 * g32);
        b->f[7][k] = -(P10 * g30 + P11 * g31 + P12 * g32);
        b->f[8][k] = -(P20 * g30 + P21 * g31 + P22 * g32);
    }
}

/* The force differential of one block at displacements u in direction dx into b->f:
   df_k = -Vol dP grad N_k with dF = dH = dv V^-1, dE2 = dH^T F + F^T dH, dI1 = tr dE2,
   dI2 = (I1 - 1) dI1 - (C - I) : dE2, dJ = cof F : dH, dw_a = sum_b w_ab dI_b,
       dP = 2 s da F + s dw_J cof F + 2 a dH + w_J dcof F - dH M - s F dM,
       da = dw_1 + (I1 - 1) dw_2 + w_2 dI1,   dM = 2 (dw_2 (C - I) + w_2 dE2),
   a, w_J and M those of the force (Prony-filtered), s the Prony factor (1 without
   viscosity). Springs: d(t v) = t dv + dt v, dt = s k L (v . dv) / l^3. The links of u are
   in b->e, those of dx in b->de (heml__block_diff gathers them). */
static void heml__block_diff_general(const heml_model *m, const heml__mat *mt, int blk, heml__blk *b)
{
    const heml_real *HEML__RESTRICT R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
    heml_real sp;
    int k;
    sp = mt->prony_count ? m->prony_s[mt - m->mats] : 1;
    if (mt->kind == HEML__K_SPRING) {
        heml_real dsig[6][HEML__W];
        heml__spring_rest_links(R, b);
        heml__spring_tensions(mt->young, R, b, 0);
        if (mt->prony_count) heml__prony(m, mt, blk, b, 6, 0);
        for (k = 0; k < HEML__W; k++) {
            heml_real v[6][3], dv[6][3];
            int l, r;
            heml__spring_links(b, k, v);
            for (r = 0; r < 3; r++) {
                dv[0][r] = b->de[r][k];
                dv[1][r] = b->de[3 + r][k];
                dv[2][r] = b->de[6 + r][k];
                dv[3][r] = dv[1][r] - dv[0][r];
                dv[4][r] = dv[2][r] - dv[1][r];
                dv[5][r] = dv[0][r] - dv[2][r];
            }
            for (l = 0; l < 6; l++) { /* len = L l^3 (heml__spring_tensions); 0 on padding */
                heml_real vdv = v[l][0] * dv[l][0] + v[l][1] * dv[l][1] + v[l][2] * dv[l][2];
                dsig[l][k] = b->len[l][k] > 0 ? sp * mt->young * R[9 * HEML__W + k] * vdv / b->len[l][k] : 0;
            }
        }
        heml__spring_dforces(b, b->co, dsig);
        return;
    }
    /* (fast-path laws reach here only with Prony: the general path covers them, with
       zero I-derivatives) */
    if (!m->nodal)
        for (k = 0; k < HEML__W; k++) b->dp[k] = 0;
    heml__block_stress(m, mt, blk, b, HEML__WANT_SECOND, 0);
    heml__diff_general(sp, R, b);
}

/* The same with the gathers, through the material's differential kernel where it has one
   (mt->dk: heml__diff_nh, heml__diff_svk; the general path where that declines). */
static void heml__block_diff(const heml_model *m, const heml__mat *mt, int blk, const heml_real *u,
                             const heml_real *dx, heml__blk *b)
{
    const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
    heml__gather(m, idx, u, b->e);
    heml__gather(m, idx, dx, b->de);
    if (mt->dk == HEML__DK_NH) { /* (the law's fast_path flag: heml__laws) */
        heml__diff_nh(m, mt, blk, b);
        return;
    }
    if (mt->dk == HEML__DK_MR) {
        heml__diff_mr(m, mt, blk, b);
        return;
    }
    if (mt->dk == HEML__DK_SVK && !heml__diff_svk(m, mt, blk, b)) return;
    heml__block_diff_general(m, mt, blk, b);
}

/* Stress of one lane from its node forces (double): P = -(1/Vol) sum_k f_k V_k^T (the
   virtual-work identity behind f_k = -Vol P grad N_k); Cauchy sigma = P F^T / J with
   F = I + du V^-1. Returns 1 when a Cauchy stress was asked for a tetrahedron with J <= 0
   (out then holds NaN). */
static int heml__lane_stress(const heml_model *m, int blk, int k, const heml__blk *b,
                             heml_stress_kind kind, heml_real *out)
{
    const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
    const heml_real *X0 = m->rest + 3 * idx[k];
    double V[3][3], P[3][3], g[3][3], G[6], F[3][3], det, J;
    int r, s, j;
    for (j = 0; j < 3; j++) {
        const heml_real *X = m->rest + 3 * idx[(j + 1) * HEML__W + k];
        for (r = 0; r < 3; r++) V[r][j] = (double)X[r] - (double)X0[r];
    }
    det = heml__rest_constants(X0, m->rest + 3 * idx[HEML__W + k], m->rest + 3 * idx[2 * HEML__W + k],
                               m->rest + 3 * idx[3 * HEML__W + k], g, G);
    for (r = 0; r < 3; r++)
        for (s = 0; s < 3; s++) {
            double acc = 0.0;
            for (j = 0; j < 3; j++) acc += (double)b->f[3 * j + r][k] * V[s][j];
            P[r][s] = -6.0 * acc / det;
        }
    if (kind == HEML_STRESS_PK1) {
        for (r = 0; r < 3; r++)
            for (s = 0; s < 3; s++) out[3 * r + s] = (heml_real)P[r][s];
        return 0;
    }
    /* F = I + du V^-1: rows of V^-1 are g[j] */
    for (r = 0; r < 3; r++)
        for (s = 0; s < 3; s++) {
            double acc = r == s ? 1.0 : 0.0;
            for (j = 0; j < 3; j++) acc += (double)b->e[3 * j + r][k] * g[j][s];
            F[r][s] = acc;
        }
    J = F[0][0] * (F[1][1] * F[2][2] - F[1][2] * F[2][1]) - F[0][1] * (F[1][0] * F[2][2] - F[1][2] * F[2][0]) +
        F[0][2] * (F[1][0] * F[2][1] - F[1][1] * F[2][0]);
    for (r = 0; r < 3; r++)
        for (s = 0; s < 3; s++) {
            double acc = 0.0;
            for (j = 0; j < 3; j++) acc += P[r][j] * F[s][j];
            out[3 * r + s] = (heml_real)(J > 0.0 ? acc / J : NAN);
        }
    return !(J > 0.0);
}

/* heml__nodal_sums without dJ, keeping H = grad u (9 rows) in Hk for the element pass
   (heml__forces_nh_kept; heml__forces_nh's expressions, so the same H). */
static void heml__nodal_sums_keep(const heml_real *HEML__RESTRICT R, const heml__blk *HEML__RESTRICT b,
                                  heml_real *HEML__RESTRICT jq, heml_real *HEML__RESTRICT Hk)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real q = R[9 * HEML__W + k] / 4;
        heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
        heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
        heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
        heml_real H00 = a0 * g10 + b0 * g20 + d0 * g30, H01 = a0 * g11 + b0 * g21 + d0 * g31;
        heml_real H02 = a0 * g12 + b0 * g22 + d0 * g32, H10 = a1 * g10 + b1 * g20 + d1 * g30;
        heml_real H11 = a1 * g11 + b1 * g21 + d1 * g31, H12 = a1 * g12 + b1 * g22 + d1 * g32;
        heml_real H20 = a2 * g10 + b2 * g20 + d2 * g30, H21 = a2 * g11 + b2 * g21 + d2 * g31;
        heml_real H22 = a2 * g12 + b2 * g22 + d2 * g32;
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c11 = H00 * H22 - H02 * H20, c22 = H00 * H11 - H01 * H10;
        heml_real tr = H00 + H11 + H22, i2 = c00 + c11 + c22, det = H00 * c00 + H01 * c01 + H02 * c02;
        jq[k] = q * (tr + i2 + det);
        Hk[k] = H00, Hk[HEML__W + k] = H01, Hk[2 * HEML__W + k] = H02;
        Hk[3 * HEML__W + k] = H10, Hk[4 * HEML__W + k] = H11, Hk[5 * HEML__W + k] = H12;
        Hk[6 * HEML__W + k] = H20, Hk[7 * HEML__W + k] = H21, Hk[8 * HEML__W + k] = H22;
    }
}

/* The nodal pressure's first pass on a block: Vol (J - 1) / 4 into jq and, with_d,
   Vol dJ / 4 = Vol cof F : dH / 4 into dq (J - 1 formed as in heml__kinematics). */
static void heml__nodal_sums(const heml_real *HEML__RESTRICT R, const heml__blk *HEML__RESTRICT b, int with_d,
                             heml_real *HEML__RESTRICT jq, heml_real *HEML__RESTRICT dq)
{
    int k;
    if (!with_d) { /* (a loop of its own, without the branch: it vectorises) */
        for (k = 0; k < HEML__W; k++) {
            heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
            heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
            heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
            heml_real q = R[9 * HEML__W + k] / 4;
            heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
            heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
            heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
            heml_real H00 = a0 * g10 + b0 * g20 + d0 * g30, H01 = a0 * g11 + b0 * g21 + d0 * g31;
            heml_real H02 = a0 * g12 + b0 * g22 + d0 * g32, H10 = a1 * g10 + b1 * g20 + d1 * g30;
            heml_real H11 = a1 * g11 + b1 * g21 + d1 * g31, H12 = a1 * g12 + b1 * g22 + d1 * g32;
            heml_real H20 = a2 * g10 + b2 * g20 + d2 * g30, H21 = a2 * g11 + b2 * g21 + d2 * g31;
            heml_real H22 = a2 * g12 + b2 * g22 + d2 * g32;
            heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
            heml_real c11 = H00 * H22 - H02 * H20, c22 = H00 * H11 - H01 * H10;
            heml_real tr = H00 + H11 + H22, i2 = c00 + c11 + c22, det = H00 * c00 + H01 * c01 + H02 * c02;
            jq[k] = q * (tr + i2 + det);
        }
        return;
    }
    for (k = 0; k < HEML__W; k++) {
        heml_real g10 = R[k], g11 = R[HEML__W + k], g12 = R[2 * HEML__W + k];
        heml_real g20 = R[3 * HEML__W + k], g21 = R[4 * HEML__W + k], g22 = R[5 * HEML__W + k];
        heml_real g30 = R[6 * HEML__W + k], g31 = R[7 * HEML__W + k], g32 = R[8 * HEML__W + k];
        heml_real q = R[9 * HEML__W + k] / 4;
        heml_real a0 = b->e[0][k], a1 = b->e[1][k], a2 = b->e[2][k];
        heml_real b0 = b->e[3][k], b1 = b->e[4][k], b2 = b->e[5][k];
        heml_real d0 = b->e[6][k], d1 = b->e[7][k], d2 = b->e[8][k];
        heml_real H00 = a0 * g10 + b0 * g20 + d0 * g30, H01 = a0 * g11 + b0 * g21 + d0 * g31;
        heml_real H02 = a0 * g12 + b0 * g22 + d0 * g32, H10 = a1 * g10 + b1 * g20 + d1 * g30;
        heml_real H11 = a1 * g11 + b1 * g21 + d1 * g31, H12 = a1 * g12 + b1 * g22 + d1 * g32;
        heml_real H20 = a2 * g10 + b2 * g20 + d2 * g30, H21 = a2 * g11 + b2 * g21 + d2 * g31;
        heml_real H22 = a2 * g12 + b2 * g22 + d2 * g32;
        heml_real c00 = H11 * H22 - H12 * H21, c01 = H12 * H20 - H10 * H22, c02 = H10 * H21 - H11 * H20;
        heml_real c10 = H02 * H21 - H01 * H22, c11 = H00 * H22 - H02 * H20, c12 = H01 * H20 - H00 * H21;
        heml_real c20 = H01 * H12 - H02 * H11, c21 = H02 * H10 - H00 * H12, c22 = H00 * H11 - H01 * H10;
        heml_real tr = H00 + H11 + H22, i2 = c00 + c11 + c22, det = H00 * c00 + H01 * c01 + H02 * c02;
        jq[k] = q * (tr + i2 + det);
        { /* (with_d) cof F = (tr H + 1) I - H^T + cof H */
            heml_real x0 = b->de[0][k], x1 = b->de[1][k], x2 = b->de[2][k];
            heml_real y0 = b->de[3][k], y1 = b->de[4][k], y2 = b->de[5][k];
            heml_real z0 = b->de[6][k], z1 = b->de[7][k], z2 = b->de[8][k];
            heml_real D00 = x0 * g10 + y0 * g20 + z0 * g30, D01 = x0 * g11 + y0 * g21 + z0 * g31;
            heml_real D02 = x0 * g12 + y0 * g22 + z0 * g32, D10 = x1 * g10 + y1 * g20 + z1 * g30;
            heml_real D11 = x1 * g11 + y1 * g21 + z1 * g31, D12 = x1 * g12 + y1 * g22 + z1 * g32;
            heml_real D20 = x2 * g10 + y2 * g20 + z2 * g30, D21 = x2 * g11 + y2 * g21 + z2 * g31;
            heml_real D22 = x2 * g12 + y2 * g22 + z2 * g32, t1 = 1 + tr;
            dq[k] = q * ((t1 - H00 + c00) * D00 + (c01 - H10) * D01 + (c02 - H20) * D02 + (c10 - H01) * D10 +
                            (t1 - H11 + c11) * D11 + (c12 - H21) * D12 + (c20 - H02) * D20 + (c21 - H12) * D21 +
                            (t1 - H22 + c22) * D22);
        }
    }
}

/* Adds the block's scalar v of each lane into out at its four nodes (lanes in order). */
static void heml__scatter_lane_values(const int *HEML__RESTRICT idx, const heml_real *HEML__RESTRICT v,
                                      heml_real *HEML__RESTRICT out)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        out[idx[k]] += v[k];
        out[idx[HEML__W + k]] += v[k];
        out[idx[2 * HEML__W + k]] += v[k];
        out[idx[3 * HEML__W + k]] += v[k];
    }
}

/* >>parallel -------------------------------------------------------------------------- */

typedef void (*heml__range_fn)(void *ctx, int begin, int end);

/* Runs fn over items [0, count); items are independent and fixed by the caller, so the
   result does not depend on how they are spread over threads. */
static void heml__run(const heml_model *m, int count, heml__range_fn fn, void *ctx)
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

/* One pass over the tetrahedra, colour by colour, group by group, chunk by chunk. */
typedef struct heml__pass {
    heml_model *m;
    int mode, prony_write, colour;
    heml_stress_kind kind;
    const heml_real *x, *dx;
    heml_real *out;
    heml_real *out4; /* the force pass into m->force4 (heml__pass_run), or NULL */
} heml__pass;

/* Software prefetch of a block's streams: its stiffness cache (the cached product) or its
   rest constants (the force pass) and its node indices, a block ahead (the cached
   stiffness product: measured 1.4 times faster on meshes beyond the caches; the force
   0.8 times the time at 1e5 to 5e6 tetrahedra, see PERFORMANCE). A hint only: nothing
   where the compiler has no prefetch builtin. */
static void heml__prefetch_block(const heml_real *C, int rows, const int *idx)
{
#if defined(__GNUC__) || defined(__clang__)
    size_t o;
    for (o = 0; o < (size_t)rows * HEML__W * sizeof(heml_real); o += 128) /* (two lines a turn) */
        __builtin_prefetch((const char *)C + o), __builtin_prefetch((const char *)C + o + 64);
    for (o = 0; o < 4 * HEML__W * sizeof(int); o += 64) __builtin_prefetch((const char *)idx + o);
#else
    (void)C, (void)rows, (void)idx;
#endif
}

/* The force pass's statistics per lane: J - 1 below J0 - 1, J <= 0 (padding lanes hold
   J - 1 = 0: neither). */
HEML__NOINLINE static void heml__count_lanes(const heml_real *HEML__RESTRICT jm1, heml_real jm1_0, heml_real *HEML__RESTRICT below,
                              heml_real *HEML__RESTRICT inverted)
{
    int k;
    for (k = 0; k < HEML__W; k++) {
        below[k] += jm1[k] < jm1_0 ? (heml_real)1 : (heml_real)0;
        inverted[k] += jm1[k] <= -1 ? (heml_real)1 : (heml_real)0;
    }
}

/* The Neo-Hookean force of one chunk (heml__mat.fast, the plain force pass), software-
   pipelined: between heml__forces_nh's stages a block gathers the next block's links (its
   first stage has consumed b->e) and scatters the previous block's forces (before its last
   stage overwrites b->f); the chunk's last block is scattered after the loop. The
   scatters keep their order, so the sums are those of the plain loop. With `four`, out is
   m->force4 (nodes padded to 4 components, heml__pass_run). PERFORMANCE, issue 21. */
HEML__NOINLINE static void heml__chunk_forces_nh(const heml_model *m, const heml__mat *mt, int ci, const heml_real *x,
                                                 heml_real *out, int four, heml__blk *HEML__RESTRICT b,
                                                 heml_real *HEML__RESTRICT below_l, heml_real *HEML__RESTRICT inverted_l)
{
    const int b0 = m->chunk_begin[ci], b1 = m->chunk_end[ci];
    int blk;
    if (b1 > b0) heml__gather_call(m, m->blk_idx + (size_t)b0 * 4 * HEML__W, x, b->e);
    for (blk = b0; blk < b1; blk++) {
        const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
        const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
        if (blk + 1 < b1) /* the next block's streams (PERFORMANCE) */
            heml__prefetch_block(R + HEML__NR * HEML__W, HEML__NR, idx + 4 * HEML__W);
        heml__forces_nh_h(R, b);
        if (blk + 1 < b1) heml__gather_call(m, idx + 4 * HEML__W, x, b->e);
        heml__forces_nh_s(mt, m->jm1_0, NULL, idx, b);
        if (blk > b0) heml__scatter_call(m, idx - 4 * HEML__W, b->f, out, four);
        heml__forces_nh_p(mt, R, b->H[0], b);
        heml__count_lanes(b->jm1, m->jm1_0, below_l, inverted_l);
    }
    if (b1 > b0) heml__scatter_call(m, m->blk_idx + (size_t)(b1 - 1) * 4 * HEML__W, b->f, out, four);
}

static void heml__chunks(void *vctx, int begin, int end)
{
    const heml__pass *p = (const heml__pass *)vctx;
    heml_model *m = p->m;
    heml__blk b;
    const heml_real jm1_0 = m->jm1_0;
    int g0 = m->colour_start[p->colour] + begin, g1 = m->colour_start[p->colour] + end, ci, blk, k;
    for (ci = m->group_start[g0]; ci < m->group_start[g1]; ci++) {
        const heml__mat *mt = m->mats + m->chunk_material[ci];
        double energy = 0.0;
        int below = 0, inverted = 0;
        heml_real below_l[HEML__W], inverted_l[HEML__W]; /* the force's counts per lane (a loop that vectorises) */
        const int nh = p->mode == HEML__FORCE && mt->fast && mt->kind != HEML__K_SPRING; /* (the Neo-Hookean kernel) */
        for (k = 0; k < HEML__W; k++) below_l[k] = inverted_l[k] = 0;
        if (nh) heml__chunk_forces_nh(m, mt, ci, p->x, p->out4 ? p->out4 : p->out, p->out4 != NULL, &b, below_l, inverted_l);
        for (blk = nh ? m->chunk_end[ci] : m->chunk_begin[ci]; blk < m->chunk_end[ci]; blk++) { /* (the other kernels) */
            const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
            int valid = m->blk_valid[blk];
            switch (p->mode) {
            case HEML__FORCE:
            case HEML__FORCE_ENERGY: /* (the energy of the relaxed Prony response: s W) */
                if (blk + 1 < m->chunk_end[ci]) /* the next block's streams (PERFORMANCE) */
                    heml__prefetch_block(m->blk_rest + (size_t)(blk + 1) * HEML__NR * HEML__W, HEML__NR,
                                         idx + 4 * HEML__W);
                energy += heml__block_forces(m, mt, blk, p->x, &b, p->prony_write, p->mode == HEML__FORCE_ENERGY) *
                          (mt->prony_count ? (double)m->prony_s[mt - m->mats] : 1.0);
                heml__scatter(m, idx, b.f, p->out);
                heml__count_lanes(b.jm1, jm1_0, below_l, inverted_l);
                break;
            case HEML__DIFF:
                if (m->dc_pass && mt->dk) { /* the stiffness cache: fill it, or read it */
                    const heml_real *HEML__RESTRICT R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
                    const int rows = m->dc_rows;
                    heml_real *C = m->dc + (size_t)blk * (size_t)rows * HEML__W;
                    if (blk + 1 < m->chunk_end[ci]) /* the next block's streams (PERFORMANCE) */
                        heml__prefetch_block(C + rows * HEML__W, HEML__DK_ROWS(mt->dk), idx + 4 * HEML__W);
                    if (m->dc_pass == HEML__DC_FILL) {
                        heml__gather(m, idx, p->x, b.e);
                        if (mt->dk == HEML__DK_MR) { /* (the rest links in b.f: the point uses b.H) */
                            heml__gather(m, idx, m->rest, b.f);
                            heml__diff_mr_point(m, mt, blk, &b, C);
                        } else {
                            heml__gather(m, idx, m->rest, b.H);
                            if (mt->dk == HEML__DK_SVK)
                                m->dc_gen[blk] = (unsigned char)heml__diff_svk_point(
                                    mt, jm1_0, valid, R, (const heml_real(*)[HEML__W])b.H, &b, C);
                            else
                                heml__diff_nh_point(mt, jm1_0, R, (const heml_real(*)[HEML__W])b.H, &b, C);
                        }
                    }
                    if (mt->dk == HEML__DK_SVK && m->dc_gen[blk]) { /* (below J0: the general path) */
                        heml__gather(m, idx, p->x, b.e);
                        heml__gather(m, idx, p->dx, b.de);
                        heml__block_diff_general(m, mt, blk, &b);
                    } else {
                        heml__gather(m, idx, p->dx, b.de);
                        if (mt->dk == HEML__DK_SVK) heml__diff_svk_apply(mt, C, &b);
                        else if (mt->dk == HEML__DK_MR) heml__diff_mr_apply(C, &b);
                        else heml__diff_nh_apply(mt, C, &b);
                    }
                } else
                    heml__block_diff(m, mt, blk, p->x, p->dx, &b);
                heml__scatter(m, idx, b.f, p->out);
                break;
            case HEML__ABS:
                heml__block_forces(m, mt, blk, p->x, &b, 0, 0);
                heml__scatter_abs(idx, b.f, p->out);
                break;
            case HEML__ENERGY:
                heml__gather(m, idx, p->x, b.e);
                if (mt->kind == HEML__K_SPRING) {
                    heml__spring_rest_links(m->blk_rest + (size_t)blk * HEML__NR * HEML__W, &b);
                    heml__spring_tensions(mt->young, m->blk_rest + (size_t)blk * HEML__NR * HEML__W, &b, 1);
                } else {
                    heml__kinematics(m->blk_rest + (size_t)blk * HEML__NR * HEML__W, &b);
                    heml__clamp_J(m->jm1_0, &b);
                    heml__law(mt, &b, valid, HEML__WANT_ENERGY);
                    if (m->nodal) heml__nodal_element(m, mt, blk, &b, HEML__WANT_ENERGY);
                }
                energy += heml__lanes_energy(m, mt, blk, &b);
                break;
            default:
                heml__block_forces(m, mt, blk, p->x, &b, 0, 0);
                for (k = 0; k < valid; k++)
                    inverted += heml__lane_stress(m, blk, k, &b, p->kind,
                                                  p->out + 9 * (size_t)m->slot_tet[blk * HEML__W + k]);
                break;
            }
        }
        for (k = 0; k < HEML__W; k++) { /* (exact: at most HEML__CHUNK per lane) */
            below += (int)below_l[k];
            inverted += (int)inverted_l[k];
        }
        m->chunk_energy[ci] = energy;
        m->chunk_below[ci] = below;
        m->chunk_inverted[ci] = inverted;
    }
}

/* The node pass of the nodal pressure on node chunks [begin, end): J_a - 1 = inv_a sum Vol
   (J - 1) / 4, the pressure P_a = inv_a sum_mat W U'_mat(J_a), with `diff` its differential
   dP_a = inv_a^2 (sum_mat W U''_mat(J_a)) sum Vol dJ / 4, with `energy` sum_mat W U_mat(J_a)
   (times the material's Prony factor when `relaxed`) into the chunk's energy. */
typedef struct heml__nodal_ctx {
    heml_model *m;
    int diff, energy, relaxed;
    int count;                            /* nodes, or pressure aggregates (nodal_pressure 2) */
    const heml_real *w, *inv, *j, *dj;    /* their weights (stride count), 1 / V, sums */
    heml_real *p, *dp;                    /* P and dP out */
} heml__nodal_ctx;

static void heml__nodal_chunks(void *vctx, int begin, int end)
{
    const heml__nodal_ctx *cx = (const heml__nodal_ctx *)vctx;
    heml_model *m = cx->m;
    const int n = cx->count, want = cx->energy ? HEML__WANT_ENERGY : 0;
    heml__blk s;
    int c, a, k, i;
    for (c = begin; c < end; c++) {
        int a1 = (c + 1) * HEML__NODE_CHUNK < n ? (c + 1) * HEML__NODE_CHUNK : n;
        double energy = 0.0;
        for (a = c * HEML__NODE_CHUNK; a < a1; a += HEML__W) {
            int valid = a1 - a < HEML__W ? a1 - a : HEML__W;
            heml_real jm1[HEML__W], P[HEML__W], Q[HEML__W], U[HEML__W], U1[HEML__W], U2[HEML__W];
            for (k = 0; k < HEML__W; k++) {
                jm1[k] = k < valid ? cx->j[a + k] * cx->inv[a + k] : 0;
                P[k] = Q[k] = 0;
            }
            for (i = 0; i < m->material_count; i++) {
                const heml_real *w = cx->w + (size_t)i * (size_t)n + (size_t)a;
                const heml__mat *mt = m->mats + i;
                double sp = cx->relaxed && mt->prony_count ? (double)m->prony_s[i] : 1.0;
                int any = 0;
                for (k = 0; k < valid; k++) any |= w[k] != 0;
                if (!any) continue;
                if (mt->fast_nodal && !cx->energy) heml__dilation_nh(mt, m->jm1_0, jm1, U1, U2);
                else heml__dilation(mt, m->jm1_0, jm1, valid, want, &s, U, U1, U2);
                for (k = 0; k < valid; k++) {
                    P[k] += w[k] * U1[k];
                    Q[k] += w[k] * U2[k];
                    if (cx->energy) energy += sp * (double)w[k] * (double)U[k];
                }
            }
            for (k = 0; k < valid; k++) {
                heml_real inv = cx->inv[a + k];
                cx->p[a + k] = P[k] * inv;
                if (cx->diff) /* (kdev: heml__dev_probe) */
                    cx->dp[a + k] = m->kdev == 1 ? 0 : Q[k] * inv * inv * (m->kdev ? 1 : cx->dj[a + k]);
            }
        }
        m->nod_energy[c] = energy;
    }
}

/* The nodal pressure's tetrahedron pass on the groups [begin, end) of a colour (coloured as
   the force pass, in its order: the same sums for any thread count): Vol (J - 1) / 4 at x
   (and Vol dJ / 4 at dx) of each lane scattered into nod_j (nod_dj); with keep, a
   fast_nodal material's blocks keep H in tet_h for the element pass (heml__forces_nh_kept).
   The next block's rest constants and indices prefetched as in the force pass. */
typedef struct heml__sums_ctx {
    heml_model *m;
    const heml_real *x, *dx;
    int colour, keep;
} heml__sums_ctx;

static void heml__nodal_tets(void *vctx, int begin, int end)
{
    const heml__sums_ctx *cx = (const heml__sums_ctx *)vctx;
    heml_model *m = cx->m;
    heml__blk b;
    int g0 = m->colour_start[cx->colour] + begin, g1 = m->colour_start[cx->colour] + end, ci, blk;
    for (ci = m->group_start[g0]; ci < m->group_start[g1]; ci++) {
        int keep = cx->keep && m->mats[m->chunk_material[ci]].fast_nodal;
        for (blk = m->chunk_begin[ci]; blk < m->chunk_end[ci]; blk++) {
            const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
            const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
            if (blk + 1 < m->chunk_end[ci]) /* the next block's streams (PERFORMANCE) */
                heml__prefetch_block(R + HEML__NR * HEML__W, HEML__NR, idx + 4 * HEML__W);
            heml__gather(m, idx, cx->x, b.e);
            if (cx->dx) heml__gather(m, idx, cx->dx, b.de);
            if (keep) heml__nodal_sums_keep(R, &b, b.jm1, m->tet_h + (size_t)blk * 9 * HEML__W);
            else heml__nodal_sums(R, &b, cx->dx != NULL, b.jm1, b.dp);
            heml__scatter_lane_values(idx, b.jm1, m->nod_j);
            if (cx->dx) heml__scatter_lane_values(idx, b.dp, m->nod_dj);
        }
    }
}

/* The nodal pressure's first two passes before a pass of `mode` at x (and dx): the sums
   over the tetrahedra (heml__nodal_tets), then the node pass. Returns the nodal energy
   (ENERGY, FORCE_ENERGY; 0 otherwise). A FORCE or ABS pass keeps H for its element pass
   (nod_hx = x until heml__pass_run ends). */
static double heml__nodal_prepare(heml_model *m, int mode, const heml_real *x, const heml_real *dx)
{
    heml__nodal_ctx cx;
    heml__sums_ctx sx;
    double energy = 0.0;
    int c, chunks, diff = mode == HEML__DIFF;
    memset(m->nod_j, 0, sizeof(heml_real) * (size_t)m->node_count);
    if (diff) memset(m->nod_dj, 0, sizeof(heml_real) * (size_t)m->node_count);
    sx.m = m, sx.x = x, sx.dx = diff ? dx : NULL;
    sx.keep = m->nod_keep_h && (mode == HEML__FORCE || mode == HEML__ABS);
    for (sx.colour = 0; sx.colour < m->colour_count; sx.colour++)
        heml__run(m, m->colour_start[sx.colour + 1] - m->colour_start[sx.colour], heml__nodal_tets, &sx);
    m->nod_hx = sx.keep ? x : NULL;
    cx.m = m;
    cx.diff = diff;
    cx.energy = mode == HEML__ENERGY || mode == HEML__FORCE_ENERGY;
    cx.relaxed = mode == HEML__FORCE_ENERGY;
    if (m->pagg_count) { /* the sums per pressure aggregate (in node order), the node pass on them */
        int a, A = m->pagg_count;
        memset(m->pagg_j, 0, sizeof(heml_real) * (size_t)A);
        if (diff) memset(m->pagg_dj, 0, sizeof(heml_real) * (size_t)A);
        for (a = 0; a < m->node_count; a++)
            if (m->pagg[a] >= 0) {
                m->pagg_j[m->pagg[a]] += m->nod_j[a];
                if (diff) m->pagg_dj[m->pagg[a]] += m->nod_dj[a];
            }
        cx.count = A;
        cx.w = m->pagg_w, cx.inv = m->pagg_inv, cx.j = m->pagg_j, cx.dj = m->pagg_dj;
        cx.p = m->pagg_p, cx.dp = m->pagg_dp;
    } else {
        cx.count = m->node_count;
        cx.w = m->nod_w, cx.inv = m->nod_inv, cx.j = m->nod_j, cx.dj = m->nod_dj;
        cx.p = m->nod_p, cx.dp = m->nod_dp;
    }
    chunks = (cx.count + HEML__NODE_CHUNK - 1) / HEML__NODE_CHUNK;
    heml__run(m, chunks, heml__nodal_chunks, &cx);
    if (m->pagg_count) { /* every node carries its aggregate's P_A (and dP_A) */
        int a;
        for (a = 0; a < m->node_count; a++) {
            int i = m->pagg[a];
            m->nod_p[a] = i >= 0 ? m->pagg_p[i] : 0;
            if (diff) m->nod_dp[a] = i >= 0 ? m->pagg_dp[i] : 0;
        }
    }
    if (cx.energy)
        for (c = 0; c < chunks; c++) energy += m->nod_energy[c];
    return energy;
}

/* Runs a pass; FORCE and DIFF overwrite out (3n). Returns the energy (ENERGY) or 0, and
   leaves the per-chunk counts in the model. */
/* The anchors' part of a pass (heml_set_anchors): per anchor a on node n, d = x_n - t_a
   (rest + u - t, formed as (rest - t) + u), energy k |d|^2 / 2, force -k d, differential
   -k dx, round-off size |k d|. Anchors in order: deterministic. */
static double heml__anchor_pass(heml_model *m, int mode, const heml_real *x, const heml_real *dx, heml_real *out)
{
    double energy = 0.0;
    int a, r;
    for (a = 0; a < m->anchor_count; a++) {
        int n = m->anchor_nodes[a];
        double k = (double)m->anchor_k[a];
        for (r = 0; r < 3; r++) {
            int j = 3 * n + r;
            double d = ((double)m->rest[j] - (double)m->anchor_target[3 * a + r]) + (double)x[j];
            energy += 0.5 * k * d * d;
            if (mode == HEML__FORCE || mode == HEML__FORCE_ENERGY) out[j] = (heml_real)((double)out[j] - k * d);
            else if (mode == HEML__DIFF) out[j] = (heml_real)((double)out[j] - k * (double)dx[j]);
            else if (mode == HEML__ABS) out[j] = (heml_real)((double)out[j] + fabs(k * d));
        }
    }
    return mode == HEML__DIFF || mode == HEML__ABS ? 0.0 : energy;
}

static double heml__pass_run(heml_model *m, int mode, const heml_real *x, const heml_real *dx,
                             heml_real *out, int prony_write, heml_stress_kind kind)
{
    heml__pass p;
    double energy = 0.0;
    int c, below = 0, inverted = 0;
    if (m->nodal) energy = heml__nodal_prepare(m, mode, x, dx);
    p.m = m;
    p.mode = mode;
    p.prony_write = prony_write && m->has_prony;
    p.kind = kind;
    p.x = x;
    p.dx = dx;
    p.out = out;
    p.out4 = NULL;
    if (mode == HEML__FORCE && m->force4 && m->simd) { /* every block pipelined: nodes padded to 4 */
        for (c = 0; c < m->material_count && m->mats[c].fast && m->mats[c].kind != HEML__K_SPRING; c++) continue;
        if (c == m->material_count) p.out4 = m->force4;
    }
    if (p.out4)
        memset(p.out4, 0, sizeof(heml_real) * 4 * (size_t)m->node_count);
    else if (mode == HEML__FORCE || mode == HEML__DIFF || mode == HEML__FORCE_ENERGY || mode == HEML__ABS)
        memset(out, 0, sizeof(heml_real) * 3 * (size_t)m->node_count);
    for (p.colour = 0; p.colour < m->colour_count; p.colour++)
        heml__run(m, m->colour_start[p.colour + 1] - m->colour_start[p.colour], heml__chunks, &p);
    if (p.out4) {
        const heml_real *HEML__RESTRICT f4 = p.out4;
        heml_real *HEML__RESTRICT o3 = out;
        size_t i, n = (size_t)m->node_count;
        for (i = 0; i < n; i++) o3[3 * i] = f4[4 * i], o3[3 * i + 1] = f4[4 * i + 1], o3[3 * i + 2] = f4[4 * i + 2];
    }
    for (c = 0; c < m->chunk_count; c++) {
        energy += m->chunk_energy[c];
        below += m->chunk_below[c];
        inverted += m->chunk_inverted[c];
    }
    m->nod_hx = NULL; /* (the kept H belongs to this pass only) */
    if (m->anchor_count && mode != HEML__STRESS) energy += heml__anchor_pass(m, mode, x, dx, out);
    if (mode == HEML__FORCE || mode == HEML__FORCE_ENERGY) {
        m->stats.below_threshold = below;
        m->stats.inverted = inverted;
        m->stats.force_evaluations++;
    } else if (mode == HEML__DIFF) {
        m->stats.stiffness_products++;
    } else if (mode == HEML__STRESS) {
        energy = inverted;
    }
    return energy;
}

/* Prony coefficients of eq. 20 for a step dt (dt <= 0: the relaxed limit dt -> inf,
   A_i = alpha_i, B_i = 0). */
static void heml__prony_coefficients(heml_model *m, double dt)
{
    int i, t;
    for (i = 0; i < m->material_count; i++) {
        const heml__mat *mt = m->mats + i;
        double s = 1.0;
        for (t = mt->prony_first; t < mt->prony_first + mt->prony_count; t++) {
            double alpha = (double)m->prony_alpha[t], tau = (double)m->prony_tau[t];
            double a = dt > 0 ? dt * alpha / (dt + tau) : alpha, b = dt > 0 ? tau / (dt + tau) : 0.0;
            m->prony_a[t] = (heml_real)a;
            m->prony_b[t] = (heml_real)b;
            s -= a;
        }
        m->prony_s[i] = (heml_real)s;
    }
}

/* The stiffness cache (m->dc, PERFORMANCE): the force differential's products at one
   linearisation point x share what x fixes per tetrahedron (heml__diff_nh_point: F, U''
   Vol, w_J Vol on the fast-path blocks, the others have no cache). The first product at x
   after an invalidation computes them into the cache besides the product (HEML__DC_FILL),
   the next ones read them (HEML__DC_USE): the same apply on the same values, so the
   results are bit-identical to the uncached pass. Only two callers pass through the cache,
   each with a key whose contents cannot change unseen: the linear solvers' operator
   (heml__cg_apply, key lin_x: every solve starts and ends with an invalidation) and
   heml_apply_stiffness (key m->disp: every public function that changes the state, the
   pins, J0 or the viscous state invalidates). */
static void heml__dc_invalidate(heml_model *m) { m->dc_key = NULL; }

static void heml__diff_run(heml_model *m, const heml_real *x, const heml_real *dx, heml_real *out)
{
    if (!m->has_dc) {
        heml__pass_run(m, HEML__DIFF, x, dx, out, 0, HEML_STRESS_PK1);
        return;
    }
    m->dc_pass = m->dc_key == x ? HEML__DC_USE : HEML__DC_FILL;
    heml__pass_run(m, HEML__DIFF, x, dx, out, 0, HEML_STRESS_PK1);
    m->dc_pass = 0;
    m->dc_key = x;
}

/* Elastic forces at x into out (Prony coefficients as last set). */
static void heml__forces(heml_model *m, const heml_real *x, heml_real *out, int prony_write)
{
    heml__pass_run(m, HEML__FORCE, x, NULL, out, prony_write, HEML_STRESS_PK1);
}

/* >>memory ---------------------------------------------------------------------------- */

/* The desc's allocator, or HEML_MALLOC with the block aligned to HEML__ALIGN by hand
   (the pointer malloc returned is kept just before the aligned block). */
static void *heml__alloc(const heml_allocator *a, size_t size)
{
    char *raw, *p;
    if (a->alloc) return a->alloc(size, HEML__ALIGN, a->user);
    raw = (char *)HEML_MALLOC(size + HEML__ALIGN + sizeof(void *), a->user);
    if (!raw) return NULL;
    p = raw + sizeof(void *);
    p += (HEML__ALIGN - (size_t)p % HEML__ALIGN) % HEML__ALIGN;
    memcpy(p - sizeof(void *), &raw, sizeof(void *));
    return p;
}

static void heml__free(const heml_allocator *a, void *ptr, size_t size)
{
    void *raw;
    if (!ptr) return;
    if (a->free) {
        a->free(ptr, size, a->user);
        return;
    }
    memcpy(&raw, (char *)ptr - sizeof(void *), sizeof(void *));
    HEML_FREE(raw, a->user);
}

/* Carves aligned arrays out of one block; with base NULL it only measures. */
typedef struct heml__carver {
    char *base;
    size_t offset;
} heml__carver;

static void *heml__carve(heml__carver *c, size_t bytes)
{
    void *p;
    c->offset = (c->offset + HEML__ALIGN - 1) & ~(size_t)(HEML__ALIGN - 1);
    p = c->base ? (void *)(c->base + c->offset) : NULL;
    c->offset += bytes ? bytes : 1;
    return p;
}

#define HEML__CARVE(c, ptr, type, count) ((ptr) = (type *)heml__carve((c), sizeof(type) * (size_t)(count)))

/* The scratch vectors, 3n reals each (24: 16 by role and 8 for Krylov), and the roles that share
   memory: a static solve and a step never run at once (static_* = step_*, static_rhs and
   static_pred = implicit_dmass and implicit_warm); the linearised implicit step does not
   run Newton (lin_* = newton_R, newton_delta, newton_ut); the saddle probe runs between
   Newton iterations, whose direction and shifted diagonal are then spent (probe_b =
   newton_delta, probe_x = newton_shift_diag). */
static void heml__layout_scratch(heml_model *m, heml__carver *c)
{
    size_t n3 = 3 * (size_t)m->node_count;
    int i;
    HEML__CARVE(c, m->step_u0, heml_real, n3);
    HEML__CARVE(c, m->step_v0, heml_real, n3);
    HEML__CARVE(c, m->step_u1, heml_real, n3);
    HEML__CARVE(c, m->step_v1, heml_real, n3);
    HEML__CARVE(c, m->work_f, heml_real, n3);
    HEML__CARVE(c, m->newton_R, heml_real, n3);
    HEML__CARVE(c, m->newton_delta, heml_real, n3);
    HEML__CARVE(c, m->newton_ut, heml_real, n3);
    HEML__CARVE(c, m->newton_ft, heml_real, n3);
    HEML__CARVE(c, m->newton_Rt, heml_real, n3);
    for (i = 0; i < HEML__KRYLOV; i++) HEML__CARVE(c, m->krylov[i], heml_real, n3);
    HEML__CARVE(c, m->objective_load, heml_real, n3);
    HEML__CARVE(c, m->implicit_dmass, heml_real, n3);
    HEML__CARVE(c, m->implicit_warm, heml_real, n3);
    HEML__CARVE(c, m->newton_shift_diag, heml_real, n3);
    HEML__CARVE(c, m->bdf2_ubar, heml_real, n3);
    HEML__CARVE(c, m->bdf2_vbar, heml_real, n3);
    m->static_u = m->step_u0;
    m->static_saved = m->step_v0;
    m->static_dpin = m->step_u1;
    m->static_dfdpin = m->step_v1;
    m->static_rhs = m->implicit_dmass;
    m->static_pred = m->implicit_warm;
    m->lin_dmass = m->newton_R;
    m->lin_du = m->newton_delta;
    m->lin_rhs = m->newton_ut;
    m->probe_b = m->newton_delta;
    m->probe_x = m->newton_shift_diag;
}

/* Lays out every array of the model in the block at c->base (or measures it). */
static void heml__layout(heml_model *m, heml__carver *c)
{
    size_t n = (size_t)m->node_count, s = (size_t)m->slot_count, B = (size_t)m->block_count;
    size_t C = (size_t)m->chunk_count, P = (size_t)m->prony_total, M = (size_t)m->material_count;
    HEML__CARVE(c, m->rest, heml_real, 3 * n);
    HEML__CARVE(c, m->pos, heml_real, 3 * n);
    HEML__CARVE(c, m->disp, heml_real, 3 * n);
    HEML__CARVE(c, m->vel, heml_real, 3 * n);
    HEML__CARVE(c, m->force, heml_real, 3 * n);
    HEML__CARVE(c, m->ext, heml_real, 3 * n);
    HEML__CARVE(c, m->target, heml_real, 3 * n);
    HEML__CARVE(c, m->mass, heml_real, n);
    HEML__CARVE(c, m->inv_mass, heml_real, n);
    HEML__CARVE(c, m->free_mask, heml_real, 3 * n);
    HEML__CARVE(c, m->pin_mask, heml_real, 3 * n);
    HEML__CARVE(c, m->diag, heml_real, 3 * n);
    HEML__CARVE(c, m->axes, unsigned char, n);
    HEML__CARVE(c, m->blk_idx, int, 4 * s);
    HEML__CARVE(c, m->blk_rest, heml_real, HEML__NR * s);
    HEML__CARVE(c, m->blk_valid, int, B);
    HEML__CARVE(c, m->blk_prony, size_t, B);
    HEML__CARVE(c, m->slot_tet, int, s);
    HEML__CARVE(c, m->tet_slot, int, m->tet_count);
    HEML__CARVE(c, m->chunk_begin, int, C);
    HEML__CARVE(c, m->chunk_end, int, C);
    HEML__CARVE(c, m->chunk_material, int, C);
    HEML__CARVE(c, m->group_start, int, C + 1);
    HEML__CARVE(c, m->colour_start, int, C + 1);
    HEML__CARVE(c, m->chunk_energy, double, C);
    HEML__CARVE(c, m->chunk_below, int, C);
    HEML__CARVE(c, m->chunk_inverted, int, C);
    HEML__CARVE(c, m->mats, heml__mat, M);
    HEML__CARVE(c, m->prony_alpha, heml_real, P);
    HEML__CARVE(c, m->prony_tau, heml_real, P);
    HEML__CARVE(c, m->prony_a, heml_real, P);
    HEML__CARVE(c, m->prony_b, heml_real, P);
    HEML__CARVE(c, m->prony_s, heml_real, M);
    HEML__CARVE(c, m->prony_q, heml_real, m->prony_reals);
    HEML__CARVE(c, m->prony_q_next, heml_real, m->prony_reals);
    heml__layout_scratch(m, c);
    HEML__CARVE(c, m->dv_prev, heml_real, 3 * n);
    HEML__CARVE(c, m->hist_u, heml_real, 3 * n);
    HEML__CARVE(c, m->hist_v, heml_real, 3 * n);
    HEML__CARVE(c, m->div_u, heml_real, 3 * n);
    HEML__CARVE(c, m->div_f, heml_real, 3 * n);
    HEML__CARVE(c, m->node_agg, int, m->agg_count ? n : 0);
    HEML__CARVE(c, m->agg_centre, double, 3 * (size_t)m->agg_count);
    HEML__CARVE(c, m->coarse, double, 36 * (size_t)m->agg_count * (size_t)m->agg_count);
    HEML__CARVE(c, m->coarse_rhs, double, 6 * (size_t)m->agg_count);
    {
        size_t A = m->implicit_coarse >= 0 ? (size_t)m->agg_count : 0; /* the implicit steps' */
        HEML__CARVE(c, m->coarse_k, double, 36 * A * A);
        HEML__CARVE(c, m->coarse_step, double, 36 * A * A);
        HEML__CARVE(c, m->coarse_pdp, double, 36 * A);
        HEML__CARVE(c, m->coarse_pdp_new, double, 36 * A);
    }
    {
        size_t nn = m->nodal ? n : 0;
        HEML__CARVE(c, m->nod_w, heml_real, nn * M);
        HEML__CARVE(c, m->nod_inv, heml_real, nn);
        HEML__CARVE(c, m->nod_j, heml_real, nn);
        HEML__CARVE(c, m->nod_dj, heml_real, nn);
        HEML__CARVE(c, m->nod_p, heml_real, nn);
        HEML__CARVE(c, m->nod_dp, heml_real, nn);
        HEML__CARVE(c, m->tet_h, heml_real, m->nod_keep_h ? 9 * s : 0);
        HEML__CARVE(c, m->pagg, int, m->pagg_count ? n : 0);
        HEML__CARVE(c, m->pagg_w, heml_real, (size_t)m->pagg_count * M);
        HEML__CARVE(c, m->pagg_inv, heml_real, (size_t)m->pagg_count);
        HEML__CARVE(c, m->pagg_j, heml_real, (size_t)m->pagg_count);
        HEML__CARVE(c, m->pagg_dj, heml_real, (size_t)m->pagg_count);
        HEML__CARVE(c, m->pagg_p, heml_real, (size_t)m->pagg_count);
        HEML__CARVE(c, m->pagg_dp, heml_real, (size_t)m->pagg_count);
        HEML__CARVE(c, m->nod_energy, double, m->nodal ? (size_t)m->nod_chunks : 0);
        HEML__CARVE(c, m->diag_dev, heml_real, 3 * nn);
    }
    {
        size_t A = m->pgt_width ? (size_t)m->pagg_count : 0, nw = m->pgt_width ? n * (size_t)m->pgt_width : 0;
        HEML__CARVE(c, m->pgt_agg, int, nw);
        HEML__CARVE(c, m->pgt_val, double, 3 * nw);
        HEML__CARVE(c, m->pc_s, double, A * A);
        HEML__CARVE(c, m->pc_gp, double, A * 6 * (size_t)m->agg_count);
        HEML__CARVE(c, m->pc_y, double, A);
        HEML__CARVE(c, m->pc_w, heml_real, A ? 3 * n : 0);
    }
    HEML__CARVE(c, m->dc, heml_real, m->has_dc ? (size_t)m->dc_rows * s : 0);
    HEML__CARVE(c, m->dc_gen, unsigned char, m->has_dc ? B : 0);
#if defined(HEML__AVX)
    if (sizeof(heml_real) == sizeof(float)) HEML__CARVE(c, m->force4, heml_real, 4 * n); /* (last: the others keep their offsets) */
#endif
    if (!m->nodal) m->diag_dev = NULL;
    if (!m->pagg_count) m->pagg = NULL;
    if (!m->has_dc) m->dc = NULL, m->dc_gen = NULL;
}

/* >>validation ------------------------------------------------------------------------ */

static int heml__fail(const heml_desc *d, int code, const char *detail)
{
    if (d && d->log) d->log(code, detail, d->log_user);
    return code;
}

/* >>laws-table: each law's kernel constants (make), parameter checks (check) and its row
   of heml__laws. */

static void heml__make_svk(const heml_material *src, heml__mat *mt)
{
    mt->mu = src->mu;
    mt->lambda = src->lambda;
    mt->guard = src->lambda + 2 * src->mu;
    mt->uses_i2 = 1;
}

static void heml__make_nh(const heml_material *src, heml__mat *mt)
{
    mt->c1 = src->mu / 2;
    mt->p0 = src->mu;
    mt->kappa = src->lambda;
}

static void heml__make_nh_incompressible(const heml_material *src, heml__mat *mt)
{
    mt->c1 = src->c1;
    mt->p0 = 2 * src->c1;
    mt->kappa = src->bulk_modulus;
}

static void heml__make_mr_incompressible(const heml_material *src, heml__mat *mt)
{
    mt->c1 = src->c1;
    mt->c2 = src->c2;
    mt->p0 = 2 * src->c1 + 4 * src->c2;
    mt->kappa = src->bulk_modulus;
    mt->uses_i2 = src->c2 != 0;
}

static void heml__make_mr(const heml_material *src, heml__mat *mt)
{
    mt->c1 = src->c1;
    mt->c2 = src->c2;
    mt->kappa = src->bulk_modulus;
    mt->uses_i2 = src->c2 != 0;
}

static void heml__make_spring(const heml_material *src, heml__mat *mt) { mt->young = src->young_modulus; }

static void heml__make_user(const heml_material *src, heml__mat *mt)
{
    (void)src;
    mt->uses_i2 = 1;
}

static int heml__check_lame(const heml_material *src, int index, char *msg, size_t msg_size)
{
    if (!(heml__finite((double)src->mu) && heml__finite((double)src->lambda) && src->mu > 0 &&
          3 * src->lambda + 2 * src->mu > 0)) {
        snprintf(msg, msg_size, "material %d: mu %g, lambda %g (need mu > 0, 3 lambda + 2 mu > 0)", index,
                 (double)src->mu, (double)src->lambda);
        return HEML_ERR_MATERIAL;
    }
    return HEML_OK;
}

static int heml__check_c1_c2_kappa(double c1, double c2, double kappa, int index, char *msg, size_t msg_size)
{
    if (!(heml__finite(c1) && heml__finite(c2) && heml__finite(kappa) && c1 >= 0.0 && c2 >= 0.0 && c1 + c2 > 0.0 &&
          kappa > 0.0)) {
        snprintf(msg, msg_size, "material %d: c1 %g, c2 %g, kappa %g (need c1, c2 >= 0, c1 + c2 > 0, "
                 "kappa > 0)", index, c1, c2, kappa);
        return HEML_ERR_MATERIAL;
    }
    return HEML_OK;
}

static int heml__check_nh_incompressible(const heml_material *src, int index, char *msg, size_t msg_size)
{
    return heml__check_c1_c2_kappa((double)src->c1, 0.0, (double)src->bulk_modulus, index, msg, msg_size);
}

static int heml__check_mr(const heml_material *src, int index, char *msg, size_t msg_size)
{
    return heml__check_c1_c2_kappa((double)src->c1, (double)src->c2, (double)src->bulk_modulus, index, msg, msg_size);
}

static int heml__check_spring(const heml_material *src, int index, char *msg, size_t msg_size)
{
    if (!(heml__finite((double)src->young_modulus) && src->young_modulus > 0)) {
        snprintf(msg, msg_size, "material %d: Young's modulus %g", index, (double)src->young_modulus);
        return HEML_ERR_MATERIAL;
    }
    return HEML_OK;
}

/* (the user law's rest-state checks need the law evaluated: heml__validate_material) */
static int heml__check_user(const heml_material *src, int index, char *msg, size_t msg_size)
{
    if (!src->user.first) {
        snprintf(msg, msg_size, "material %d: user law without a first-derivative callback", index);
        return HEML_ERR_USER_LAW;
    }
    return HEML_OK;
}

/* The laws, indexed by heml_law (see heml__law_ops and HOW TO EXTEND). fast_path is set
   where heml__law_raw without an I2 term is the law: Neo-Hookean (eq. 26: c1 = mu/2,
   p0 = mu, kappa = lambda), its table 3 + penalty form, and the incompressible
   Mooney-Rivlin, which has an I2 term unless c2 = 0 (heml__mat.fast also needs no I2
   term). */
static const heml__law_ops heml__laws[] = {
    {"St Venant-Kirchhoff", HEML__K_INVARIANTS, heml__law_svk, heml__law_svk, heml__law_svk, heml__make_svk,
     heml__check_lame, 0},
    {"Neo-Hookean", HEML__K_INVARIANTS, heml__law_raw, heml__law_raw, heml__law_raw, heml__make_nh, heml__check_lame,
     1},
    {"Mooney-Rivlin", HEML__K_INVARIANTS, heml__law_split, heml__law_split, heml__law_split, heml__make_mr,
     heml__check_mr, 0},
    {"Neo-Hookean (incompressible)", HEML__K_INVARIANTS, heml__law_raw, heml__law_raw, heml__law_raw,
     heml__make_nh_incompressible, heml__check_nh_incompressible, 1},
    {"Mooney-Rivlin (incompressible)", HEML__K_INVARIANTS, heml__law_raw, heml__law_raw, heml__law_raw,
     heml__make_mr_incompressible, heml__check_mr, 1},
    {"mass-spring", HEML__K_SPRING, NULL, NULL, NULL, heml__make_spring, heml__check_spring, 0},
    {"user", HEML__K_USER, heml__law_user, heml__law_user, heml__law_user, heml__make_user, heml__check_user, 0},
};
/* a law added to heml_law without its row (or the reverse) fails to compile here */
typedef char heml__laws_has_a_row_per_law[sizeof heml__laws / sizeof heml__laws[0] == HEML_LAW_COUNT ? 1 : -1];

/* A material in kernel form (no checks; src->law valid). */
static void heml__make_mat(const heml_material *src, heml__mat *mt)
{
    const heml__law_ops *ops = heml__laws + src->law;
    memset(mt, 0, sizeof *mt);
    mt->law = src->law;
    mt->ops = ops;
    mt->kind = ops->kind;
    mt->density = (double)src->density;
    mt->user = src->user;
    mt->prony_count = src->prony_count;
    ops->make(src, mt);
    mt->fast = ops->fast_path && !mt->uses_i2 && !mt->prony_count;
    mt->fast_mr = src->law == HEML_MOONEY_RIVLIN && !mt->prony_count;
    mt->dk = mt->fast                                           ? HEML__DK_NH
             : mt->prony_count                                  ? 0
             : src->law == HEML_STVK                            ? HEML__DK_SVK
             : src->law == HEML_MOONEY_RIVLIN                   ? HEML__DK_MR
                                                                : 0;
}

/* Small-strain shear and Lame moduli of a law from its derivatives at rest (see THE
   MODEL); springs count as nu = 1/4. Returns 0, or -1 if a derivative is not finite. */
static int heml__small_strain(heml__mat *mt, heml_real jm1_0, double *mu, double *lambda)
{
    heml__blk b;
    double w2, wJ;
    int r;
    if (mt->kind == HEML__K_SPRING) {
        *mu = *lambda = 0.4 * (double)mt->young;
        return 0;
    }
    heml__law_at_rest(mt, jm1_0, &b);
    w2 = (double)b.w2[0];
    wJ = (double)b.wJ[0];
    if (!heml__finite((double)b.w1[0]) || !heml__finite(w2) || !heml__finite(wJ)) return -1;
    for (r = 0; r < 6; r++)
        if (!heml__finite((double)b.h[r][0])) return -1;
    *mu = -2.0 * w2 - wJ;
    if (mt->kind == HEML__K_USER && !mt->user.second)
        *lambda = 1.5 * *mu; /* unknown without second derivatives: as nu = 0.3 */
    else
        *lambda = 4.0 * w2 + wJ + 4.0 * b.h[0][0] + 16.0 * b.h[1][0] + 16.0 * b.h[3][0] +
                  4.0 * b.h[2][0] + 8.0 * b.h[4][0] + b.h[5][0];
    return 0;
}

static int heml__validate_material(const heml_material *src, heml_real jm1_0, int index, char *msg,
                                   size_t msg_size)
{
    heml__mat mt;
    double mu, lambda, sum = 0.0;
    int i, err;
    if ((unsigned)src->law >= HEML_LAW_COUNT) {
        snprintf(msg, msg_size, "material %d: unknown law %d", index, (int)src->law);
        return HEML_ERR_LAW;
    }
    if (!(heml__finite((double)src->density) && src->density > 0)) {
        snprintf(msg, msg_size, "material %d: density %g", index, (double)src->density);
        return HEML_ERR_DENSITY;
    }
    if (src->prony_count < 0 || (src->prony_count > 0 && !src->prony)) {
        snprintf(msg, msg_size, "material %d: %d Prony terms without an array", index, src->prony_count);
        return HEML_ERR_PRONY;
    }
    for (i = 0; i < src->prony_count; i++) {
        double a = (double)src->prony[i].alpha, tau = (double)src->prony[i].tau;
        if (!(heml__finite(a) && a >= 0.0 && heml__finite(tau) && tau > 0.0)) {
            snprintf(msg, msg_size, "material %d: Prony term %d (alpha %g, tau %g)", index, i, a, tau);
            return HEML_ERR_PRONY;
        }
        sum += a;
    }
    if (!(sum < 1.0)) {
        snprintf(msg, msg_size, "material %d: Prony weights sum to %g (must be < 1)", index, sum);
        return HEML_ERR_PRONY;
    }
    err = heml__laws[src->law].check(src, index, msg, msg_size);
    if (err) return err;
    if (heml__laws[src->law].kind == HEML__K_USER) { /* stress-free and stable at rest */
        heml__blk b;
        double w1, w2, wJ, tol = HEML__FLOAT ? 1e-4 : 1e-9;
        heml__make_mat(src, &mt);
        heml__law_at_rest(&mt, jm1_0, &b);
        w1 = (double)b.w1[0];
        w2 = (double)b.w2[0];
        wJ = (double)b.wJ[0];
        if (heml__small_strain(&mt, jm1_0, &mu, &lambda) ||
            !(fabs(2 * w1 + 4 * w2 + wJ) <= tol * (2 * fabs(w1) + 4 * fabs(w2) + fabs(wJ))) ||
            !(mu > 0.0) || !(lambda + 2.0 * mu / 3.0 > 0.0)) {
            snprintf(msg, msg_size, "material %d: user law at rest: 2 w_1 + 4 w_2 + w_J = %g, "
                     "small-strain mu %g, lambda %g", index, 2 * w1 + 4 * w2 + wJ, mu, lambda);
            return HEML_ERR_USER_LAW;
        }
    }
    return HEML_OK;
}

/* Creation stage 1 (see heml_create): every check of the description, before anything is
   allocated. */
static int heml__create_validate(const heml_desc *d)
{
    char msg[200];
    int i, t, err, M;
    /* a description not made by heml_default_desc: its log callback is garbage too */
    if (d->internal_cookie != HEML__COOKIE) return HEML_ERR_DESC;
    if (d->node_count < 4 || d->node_count > HEML__MAX_NODES || !d->rest_positions)
        return heml__fail(d, HEML_ERR_NODE_COUNT, "node_count must be >= 4 with positions");
    if (d->tet_count < 1 || d->tet_count > HEML__MAX_TETS || !d->tets)
        return heml__fail(d, HEML_ERR_TET_COUNT, "tet_count must be >= 1 with indices");
    if (!(heml__finite((double)d->inversion_threshold) && d->inversion_threshold > 0 &&
          d->inversion_threshold < 1))
        return heml__fail(d, HEML_ERR_THRESHOLD, "inversion_threshold");
    if (!(heml__finite((double)d->time_step) && d->time_step > 0))
        return heml__fail(d, HEML_ERR_TIME_STEP, "time_step");
    if (!(heml__finite((double)d->mass_damping) && d->mass_damping >= 0))
        return heml__fail(d, HEML_ERR_DAMPING, "mass_damping");
    if ((unsigned)d->integrator >= HEML_INTEGRATOR_COUNT)
        return heml__fail(d, HEML_ERR_INTEGRATOR, "integrator");
    if ((unsigned)d->linear_solver >= HEML_LINEAR_SOLVER_COUNT)
        return heml__fail(d, HEML_ERR_SOLVER, "linear_solver");
    if (!(heml__finite((double)d->cg_tolerance) && d->cg_tolerance > 0) || d->cg_max_iterations < 1 ||
        d->newton_iterations < 1 || d->static_max_iterations < 1 ||
        !(heml__finite((double)d->static_tolerance) && d->static_tolerance > 0) ||
        !(heml__finite((double)d->newton_tolerance) && d->newton_tolerance > 0) || d->max_increments < 1 ||
        !(heml__finite((double)d->min_increment) && d->min_increment > 0 && d->min_increment <= 1) ||
        !(heml__finite((double)d->precision_limit) && d->precision_limit >= 0) ||
        (d->allow_inversion != 0 && d->allow_inversion != 1) || (d->leave_saddles != 0 && d->leave_saddles != 1))
        return heml__fail(d, HEML_ERR_SOLVER, "cg_tolerance, cg_max_iterations, newton_iterations, newton_tolerance, "
                                              "static_max_iterations, static_tolerance, max_increments, "
                                              "min_increment, precision_limit, allow_inversion or leave_saddles");
    for (i = 0; i < 3; i++)
        if (!heml__finite((double)d->gravity[i])) return heml__fail(d, HEML_ERR_ARG, "gravity");
    if (d->nodal_pressure < 0 || d->nodal_pressure > 2)
        return heml__fail(d, HEML_ERR_NODAL_PRESSURE, "nodal_pressure must be 0, 1 or 2");
    if (d->stiffness_cache != 0 && d->stiffness_cache != 1)
        return heml__fail(d, HEML_ERR_ARG, "stiffness_cache must be 0 or 1");
    if (d->implicit_coarse < -1 || d->implicit_coarse > 1)
        return heml__fail(d, HEML_ERR_SOLVER, "implicit_coarse must be -1, 0 or 1");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return heml__fail(d, HEML_ERR_ARG, "allocator needs both alloc and free");
    M = d->materials ? d->material_count : 1;
    if (M < 1 || M > HEML__MAX_TETS || (d->tet_material && !d->materials))
        return heml__fail(d, HEML_ERR_MATERIAL_INDEX, "material_count must be >= 1 with materials "
                                                      "(and tet_material needs materials)");
    for (i = 0; i < M; i++) {
        err = heml__validate_material(d->materials ? d->materials + i : &d->material,
                                      (heml_real)((double)d->inversion_threshold - 1.0), i, msg, sizeof msg);
        if (err) return heml__fail(d, err, msg);
        if (d->nodal_pressure) {
            const heml_material *mi = d->materials ? d->materials + i : &d->material;
            if (heml__laws[mi->law].kind == HEML__K_SPRING ||
                (heml__laws[mi->law].kind == HEML__K_USER && !mi->user.second)) {
                snprintf(msg, sizeof msg, "nodal_pressure: material %d is mass-spring or a user law without "
                                          "second derivatives", i);
                return heml__fail(d, HEML_ERR_NODAL_PRESSURE, msg);
            }
        }
    }
    for (i = 0; i < 3 * d->node_count; i++)
        if (!heml__finite((double)d->rest_positions[i])) {
            snprintf(msg, sizeof msg, "rest position of node %d is not finite", i / 3);
            return heml__fail(d, HEML_ERR_NODE_NOT_FINITE, msg);
        }
    for (t = 0; t < d->tet_count; t++) {
        const int *q = d->tets + 4 * t;
        double g[3][3], G[6], det, longest = 0.0;
        int a, b;
        if (d->tet_material && (d->tet_material[t] < 0 || d->tet_material[t] >= M)) {
            snprintf(msg, sizeof msg, "tetrahedron %d: material %d of %d", t, d->tet_material[t], M);
            return heml__fail(d, HEML_ERR_MATERIAL_INDEX, msg);
        }
        for (a = 0; a < 4; a++) {
            if (q[a] < 0 || q[a] >= d->node_count) {
                snprintf(msg, sizeof msg, "tetrahedron %d: node index %d out of range", t, q[a]);
                return heml__fail(d, HEML_ERR_INDEX_RANGE, msg);
            }
            for (b = 0; b < a; b++)
                if (q[a] == q[b]) {
                    snprintf(msg, sizeof msg, "tetrahedron %d uses node %d twice", t, q[a]);
                    return heml__fail(d, HEML_ERR_INDEX_REPEATED, msg);
                }
        }
        for (a = 0; a < 4; a++)
            for (b = a + 1; b < 4; b++) {
                const heml_real *pa = d->rest_positions + 3 * q[a], *pb = d->rest_positions + 3 * q[b];
                double dx = (double)pa[0] - pb[0], dy = (double)pa[1] - pb[1], dz = (double)pa[2] - pb[2];
                double l2 = dx * dx + dy * dy + dz * dz;
                if (l2 > longest) longest = l2;
            }
        det = heml__rest_constants(d->rest_positions + 3 * q[0], d->rest_positions + 3 * q[1],
                                   d->rest_positions + 3 * q[2], d->rest_positions + 3 * q[3], g, G);
        /* a regular tetrahedron has det V = l^3 / sqrt(2); flag slivers 1e8 times flatter */
        if (!(fabs(det) > 1e-8 * longest * sqrt(longest))) {
            snprintf(msg, sizeof msg, "tetrahedron %d is flat (6V = %g)", t, det);
            return heml__fail(d, HEML_ERR_TET_DEGENERATE, msg);
        }
        if (det < 0.0) {
            snprintf(msg, sizeof msg, "tetrahedron %d is negatively oriented", t);
            return heml__fail(d, HEML_ERR_TET_INVERTED, msg);
        }
    }
    return HEML_OK;
}

/* >>precomputation -------------------------------------------------------------------- */

/* The order tetrahedra take in the blocks: by material, then by their lowest node index
   (ties by index), so that the passes walk the node arrays in order whatever the order
   the tetrahedra came in: neighbouring tetrahedra share blocks, chunks and groups, the
   gathers and scatters stream through memory and groups of a colour are few. Measured on
   a beam of 1e6 tetrahedra with nodes numbered row by row: given in random order, a
   Neo-Hookean force pass took 160 ns per tetrahedron unsorted and 40 ns sorted (30 to 35
   for the mesh's own cell-by-cell order, which the sort keeps within noise). Rejected: a
   Morton order of the centroids and the sum of the node indices (40 to 60 % slower on
   that beam: they interleave tetrahedra many rows apart). Node numbering with locality
   (row by row, a space-filling curve, reverse Cuthill-McKee) is left to the mesh. */
typedef struct heml__order {
    int material, key, tet; /* sorted in this order */
} heml__order;

static int heml__order_cmp(const void *pa, const void *pb)
{
    const heml__order *a = (const heml__order *)pa, *b = (const heml__order *)pb;
    if (a->material != b->material) return a->material < b->material ? -1 : 1;
    if (a->key != b->key) return a->key < b->key ? -1 : 1;
    return (a->tet > b->tet) - (a->tet < b->tet);
}

static void heml__node_order(const heml_desc *d, heml__order *o)
{
    int t, j;
    for (t = 0; t < d->tet_count; t++) {
        int lo = d->tets[4 * t];
        for (j = 1; j < 4; j++) lo = d->tets[4 * t + j] < lo ? d->tets[4 * t + j] : lo;
        o[t].key = lo;
        o[t].material = d->tet_material ? d->tet_material[t] : 0;
        o[t].tet = t;
    }
    qsort(o, (size_t)d->tet_count, sizeof *o, heml__order_cmp);
}

/* Groups of consecutive chunks (in their original, mesh order), then a greedy colouring
   of the groups so that no two groups of a colour share a node; the chunk arrays are
   reordered group by group, colour by colour. A group is the unit a thread runs, so its
   chunks sweep a compact piece of the mesh one after the other (its nodes stay in cache);
   colouring single chunks instead spread each colour over the whole mesh (measured: 40
   against 24 ns per tetrahedron for the Neo-Hookean force at 1e6 tetrahedra). stamp is n
   ints of scratch, colour_of C ints, order 3 C ints. */
static void heml__colour_groups(heml_model *m, int *stamp, int *colour_of, int *order)
{
    int g, c, colour = 0, done = 0, pos = 0, i, C = m->chunk_count, per = C / HEML__GROUPS_MIN, G;
    if (per < 1) per = 1;
    if (per > HEML__GROUP) per = HEML__GROUP;
    G = (C + per - 1) / per;
    m->group_count = G;
    for (g = 0; g < G; g++) colour_of[g] = -1;
    for (i = 0; i < m->node_count; i++) stamp[i] = -1;
    while (done < G) {
        for (g = 0; g < G; g++) {
            int c1 = (g + 1) * per < C ? (g + 1) * per : C, ok = 1;
            int b0 = m->chunk_begin[g * per] * 4 * HEML__W, b1 = m->chunk_end[c1 - 1] * 4 * HEML__W;
            if (colour_of[g] >= 0) continue;
            for (i = b0; i < b1 && ok; i++)
                if (stamp[m->blk_idx[i]] == colour) ok = 0;
            if (!ok) continue;
            colour_of[g] = colour;
            done++;
            for (i = b0; i < b1; i++) stamp[m->blk_idx[i]] = colour;
        }
        colour++;
    }
    m->colour_count = colour;
    for (c = 0; c < C; c++) {
        order[c] = m->chunk_begin[c];
        order[C + c] = m->chunk_end[c];
        order[2 * C + c] = m->chunk_material[c];
    }
    for (colour = 0, g = 0; colour < m->colour_count; colour++) {
        int h;
        m->colour_start[colour] = g;
        for (h = 0; h < G; h++) {
            if (colour_of[h] != colour) continue;
            m->group_start[g++] = pos;
            for (c = h * per; c < (h + 1) * per && c < C; c++, pos++) {
                m->chunk_begin[pos] = order[c];
                m->chunk_end[pos] = order[C + c];
                m->chunk_material[pos] = order[2 * C + c];
            }
        }
    }
    m->colour_start[m->colour_count] = g;
    m->group_start[G] = pos;
}

/* The masks of node i from its pinned axes; pin_version counts changes of the masks (not
   of the targets: a driven node moved every step keeps its coarse space and its
   divergence reference). */
static void heml__set_masks(heml_model *m, int i)
{
    int r, changed = 0;
    for (r = 0; r < 3; r++) {
        int pinned = (m->axes[i] >> r) & 1, movable = m->mass[i] > 0;
        changed |= m->pin_mask[3 * i + r] != (heml_real)pinned || m->free_mask[3 * i + r] != (heml_real)(!pinned && movable);
        m->pin_mask[3 * i + r] = (heml_real)pinned;
        m->free_mask[3 * i + r] = (heml_real)(!pinned && movable);
    }
    m->pin_version += (unsigned)changed;
}

/* Fills the block arrays (constants of every slot, padding), the masses and the
   stiffness diagonal. mass_acc, diag_acc: n and 3n doubles of scratch. */
static void heml__fill_tets(heml_model *m, const heml_desc *d, double *mass_acc, double *diag_acc)
{
    int s, blk, k, j, r;
    double noise2 = 0.0;
    memset(mass_acc, 0, sizeof(double) * (size_t)m->node_count);
    memset(diag_acc, 0, sizeof(double) * 3 * (size_t)m->node_count);
    if (m->diag_dev) memset(m->diag_dev, 0, sizeof(heml_real) * 3 * (size_t)m->node_count);
    for (s = 0; s < m->slot_count; s++) {
        int t = m->slot_tet[s], *idx;
        heml_real *R;
        blk = s / HEML__W;
        k = s % HEML__W;
        idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
        R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
        if (t < 0) { /* padding: all four nodes the first node of lane 0, zero constants */
            for (j = 0; j < 4; j++) idx[j * HEML__W + k] = idx[0];
            for (r = 0; r < HEML__NR; r++) R[r * HEML__W + k] = 0;
            continue;
        }
        {
            const int *q = d->tets + 4 * t;
            const heml__mat *mt = m->mats + (d->tet_material ? d->tet_material[t] : 0);
            double g[4][3], G[6], det, vol;
            det = heml__rest_constants(m->rest + 3 * q[0], m->rest + 3 * q[1], m->rest + 3 * q[2],
                                       m->rest + 3 * q[3], g + 1, G);
            vol = det / 6.0;
            if (mt->kind == HEML__K_USER) { /* its w is a sum of terms of the size of the moduli */
                double e = (HEML__FLOAT ? FLT_EPSILON : DBL_EPSILON) * vol * (mt->small_lambda + 2.0 * mt->small_mu);
                noise2 += e * e;
            }
            for (j = 0; j < 4; j++) idx[j * HEML__W + k] = q[j];
            for (j = 0; j < 3; j++)
                for (r = 0; r < 3; r++) R[(3 * j + r) * HEML__W + k] = (heml_real)g[j + 1][r];
            R[9 * HEML__W + k] = (heml_real)vol;
            for (r = 0; r < 3; r++) g[0][r] = -(g[1][r] + g[2][r] + g[3][r]);
            for (j = 0; j < 4; j++) {
                double gg = g[j][0] * g[j][0] + g[j][1] * g[j][1] + g[j][2] * g[j][2];
                mass_acc[q[j]] += mt->density * vol / 4.0;
                for (r = 0; r < 3; r++) {
                    diag_acc[3 * q[j] + r] +=
                        vol * ((mt->small_lambda + mt->small_mu) * g[j][r] * g[j][r] + mt->small_mu * gg);
                    if (m->diag_dev) /* lambda - kappa = -2 mu / 3: the law less its dilation energy */
                        m->diag_dev[3 * q[j] + r] +=
                            (heml_real)(vol * (mt->small_mu / 3.0 * g[j][r] * g[j][r] + mt->small_mu * gg));
                }
            }
            m->blk_valid[blk] = k + 1;
        }
    }
    m->energy_noise = sqrt(noise2);
    for (s = 0; s < m->node_count; s++) {
        m->mass[s] = (heml_real)mass_acc[s];
        m->inv_mass[s] = mass_acc[s] > 0 ? (heml_real)(1.0 / mass_acc[s]) : (heml_real)0;
        for (r = 0; r < 3; r++) m->diag[3 * s + r] = (heml_real)diag_acc[3 * s + r];
    }
}

/* The nodal pressure's rest weights (NEAR-INCOMPRESSIBLE BODIES): W[mat n + a] = sum of
   Vol_e / 4 over the tetrahedra e of material mat at node a (the stored Vol, so that a
   homogeneous J gives each node exactly that J), and 1 / V_a, V_a = sum_mat W (0 for a node
   of no tetrahedron). acc: n doubles of scratch. */
static void heml__nodal_weights(heml_model *m, const heml_desc *d, double *acc)
{
    size_t n = (size_t)m->node_count;
    int s, j;
    memset(acc, 0, sizeof(double) * n);
    memset(m->nod_w, 0, sizeof(heml_real) * n * (size_t)m->material_count);
    for (s = 0; s < m->slot_count; s++) {
        int t = m->slot_tet[s], blk = s / HEML__W, k = s % HEML__W;
        const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
        heml_real q;
        size_t base;
        if (t < 0) continue;
        q = m->blk_rest[((size_t)blk * HEML__NR + 9) * HEML__W + k] / 4;
        base = (size_t)(d->tet_material ? d->tet_material[t] : 0) * n;
        for (j = 0; j < 4; j++) {
            int a = idx[j * HEML__W + k];
            acc[a] += (double)q;
            m->nod_w[base + (size_t)a] += q;
        }
    }
    for (s = 0; s < m->node_count; s++) m->nod_inv[s] = acc[s] > 0 ? (heml_real)(1.0 / acc[s]) : (heml_real)0;
}

/* The pressure aggregates of nodal_pressure = 2 (NEAR-INCOMPRESSIBLE BODIES), from the
   mesh alone, greedy in node order: a node of at least one tetrahedron whose neighbours
   are all unassigned seeds an aggregate of itself and them (its star); then every node
   left joins the aggregate of its first neighbour (in the order of d->tets) assigned by a
   seed (it has one: it was no seed because a neighbour was taken). agg (n): the aggregate
   of each node, -1 for a node of no tetrahedron; start (n + 1), adj (12 T): scratch (the
   adjacency, each neighbour once per shared tetrahedron). Returns the count. */
static int heml__pressure_aggregates(const heml_desc *d, int *agg, int *start, int *adj)
{
    int n = d->node_count, T = d->tet_count, t, j, l, a, count = 0;
    memset(start, 0, sizeof(int) * ((size_t)n + 1));
    for (t = 0; t < T; t++)
        for (j = 0; j < 4; j++) start[d->tets[4 * t + j] + 1] += 3;
    for (a = 0; a < n; a++) start[a + 1] += start[a];
    for (a = 0; a < n; a++) agg[a] = start[a]; /* (the fill cursor) */
    for (t = 0; t < T; t++)
        for (j = 0; j < 4; j++)
            for (l = 0; l < 4; l++)
                if (l != j) adj[agg[d->tets[4 * t + j]]++] = d->tets[4 * t + l];
    for (a = 0; a < n; a++) agg[a] = -1;
    for (a = 0; a < n; a++) {
        int free_star = start[a + 1] > start[a] && agg[a] < 0;
        for (l = start[a]; l < start[a + 1] && free_star; l++) free_star = agg[adj[l]] < 0;
        if (!free_star) continue;
        agg[a] = count;
        for (l = start[a]; l < start[a + 1]; l++) agg[adj[l]] = count;
        count++;
    }
    for (a = 0; a < n; a++) /* (joined: -2 - aggregate until all have joined) */
        if (agg[a] == -1)
            for (l = start[a]; l < start[a + 1]; l++)
                if (agg[adj[l]] >= 0) {
                    agg[a] = -2 - agg[adj[l]];
                    break;
                }
    for (a = 0; a < n; a++)
        if (agg[a] <= -2) agg[a] = -2 - agg[a];
    return count;
}

/* The aggregates' node-pass weights (after heml__nodal_weights): pagg_w[mat A + i] = sum of
   W[mat n + a] over the nodes a of aggregate i, and 1 / V_A, V_A the sum of their V_a (in
   acc, n doubles, as heml__nodal_weights left them; vol: A doubles of scratch). */
static void heml__pressure_aggregate_weights(heml_model *m, const int *agg, const double *acc, double *vol)
{
    size_t n = (size_t)m->node_count, A = (size_t)m->pagg_count, i;
    int a, mat;
    memcpy(m->pagg, agg, sizeof(int) * n);
    memset(m->pagg_w, 0, sizeof(heml_real) * A * (size_t)m->material_count);
    memset(vol, 0, sizeof(double) * A);
    for (a = 0; a < m->node_count; a++)
        if (agg[a] >= 0) {
            vol[agg[a]] += acc[a];
            for (mat = 0; mat < m->material_count; mat++)
                m->pagg_w[(size_t)mat * A + (size_t)agg[a]] += m->nod_w[(size_t)mat * n + (size_t)a];
        }
    for (i = 0; i < A; i++) m->pagg_inv[i] = vol[i] > 0 ? (heml_real)(1.0 / vol[i]) : (heml_real)0;
}

/* >>coarse ---------------------------------------------------------------------------- */

/* A coarse space for the Krylov solves of the static problem: the nodes are binned into up
   to HEML__MAX_AGG roughly cubic cells of the rest bounding box (aggregates), each carrying
   the six rigid motions of its nodes about its centre, P = [I | -[X - c]x] per node. The
   preconditioner adds P A_c^-1 P^T to Jacobi, A_c = P^T K0 P with K0 the small-strain
   stiffness of the rest state on the free degrees of freedom (assembled from 3x3 node
   blocks, dense, Cholesky-factored in double; a mode that pins make singular is dropped).
   Slender bodies bend as their aggregates rotate, which is what Jacobi alone resolves
   slowest: on the steel cantilever R1 it cuts the CG iterations by about ten. The anchors
   (heml_set_anchors) add P^T k P on their nodes: a body held only by anchors keeps its
   rigid modes in the coarse space (without them those modes were singular and dropped:
   the glued R1 half of tests/test_frames_coupling.c took about 900 CG iterations a
   Newton solve instead of 120; the implicit steps' P^T (D + c K0) P holds them through
   K0 too). A_c is rebuilt when the pinned axes change and after heml_set_anchors. */
#define HEML__MAX_AGG 64
#define HEML__MIN_AGG_NODES 24 /* nodes per aggregate at least (fewer aggregates otherwise) */

/* Bins the rest nodes into aggregate cells: writes each node's cell (or -1 for none) into
   cell_of and returns the number of non-empty cells, renumbered 0.. in cell order. */
static int heml__aggregate(const heml_real *x, int n, int *cell_of, int *scratch)
{
    double lo[3], hi[3], ext[3], size, vol = 1.0, big = 0.0;
    int dims[3], i, r, target = n / HEML__MIN_AGG_NODES, cells, count = 0;
    if (target > HEML__MAX_AGG) target = HEML__MAX_AGG;
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
    for (i = 0; i < cells; i++) scratch[i] = -1;
    for (i = 0; i < n; i++) {
        int c = 0;
        for (r = 2; r >= 0; r--) {
            int k = (int)(((double)x[3 * i + r] - lo[r]) / ext[r] * dims[r]);
            if (k >= dims[r]) k = dims[r] - 1;
            if (k < 0) k = 0;
            c = c * dims[r] + k;
        }
        cell_of[i] = c;
        scratch[c] = 0;
    }
    for (i = 0; i < cells; i++)
        if (scratch[i] == 0) scratch[i] = count++;
    for (i = 0; i < n; i++) cell_of[i] = scratch[cell_of[i]];
    return count;
}

/* Aggregate centres (mean rest position of their nodes), at creation. */
static void heml__aggregate_centres(heml_model *m)
{
    int i, r;
    double *cnt = m->coarse_rhs; /* (scratch) */
    if (!m->agg_count) return;
    memset(m->agg_centre, 0, sizeof(double) * 3 * (size_t)m->agg_count);
    for (i = 0; i < m->agg_count; i++) cnt[i] = 0;
    for (i = 0; i < m->node_count; i++) {
        for (r = 0; r < 3; r++) m->agg_centre[3 * m->node_agg[i] + r] += (double)m->rest[3 * i + r];
        cnt[m->node_agg[i]] += 1.0;
    }
    for (i = 0; i < m->agg_count; i++)
        for (r = 0; r < 3; r++) m->agg_centre[3 * i + r] /= cnt[i] > 0 ? cnt[i] : 1;
}

/* Rows of P for node i on the free axes: P[r][0..2] = e_r, P[r][3..5] = (-[rho]x)_r. */
static void heml__node_modes(const heml_model *m, int i, double P[3][6])
{
    const double *c = m->agg_centre + 3 * m->node_agg[i];
    double rho[3];
    int r, k;
    for (r = 0; r < 3; r++) rho[r] = (double)m->rest[3 * i + r] - c[r];
    for (r = 0; r < 3; r++)
        for (k = 0; k < 6; k++) P[r][k] = 0.0;
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

/* Ac = P^T K0 P on the free degrees of freedom (unfactored, (6 A)^2 doubles); with dev,
   of the deviatoric small-strain stiffness (lambda -> -2 mu / 3: heml__dev_probe). */
static void heml__coarse_assemble(const heml_model *m, double *Ac, int dev)
{
    int A = m->agg_count, D = 6 * A, c, blk, k, i, j, r, s, a, b;
    memset(Ac, 0, sizeof(double) * (size_t)D * (size_t)D);
    for (c = 0; c < m->chunk_count; c++) {
        const heml__mat *mt = m->mats + m->chunk_material[c];
        double mu = mt->small_mu, lam = dev ? -2.0 / 3.0 * mt->small_mu : mt->small_lambda;
        for (blk = m->chunk_begin[c]; blk < m->chunk_end[c]; blk++) {
            const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
            const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
            for (k = 0; k < m->blk_valid[blk]; k++) {
                double g[4][3], P[4][3][6], vol = (double)R[9 * HEML__W + k];
                for (j = 0; j < 3; j++)
                    for (r = 0; r < 3; r++) g[j + 1][r] = (double)R[(3 * j + r) * HEML__W + k];
                for (r = 0; r < 3; r++) g[0][r] = -(g[1][r] + g[2][r] + g[3][r]);
                for (i = 0; i < 4; i++) heml__node_modes(m, idx[i * HEML__W + k], P[i]);
                for (i = 0; i < 4; i++)
                    for (j = 0; j < 4; j++) {
                        double Kij[3][3], T[3][6], gg = g[i][0] * g[j][0] + g[i][1] * g[j][1] + g[i][2] * g[j][2];
                        double *blockp;
                        for (r = 0; r < 3; r++)
                            for (s = 0; s < 3; s++)
                                Kij[r][s] = vol * (lam * g[i][r] * g[j][s] + mu * g[i][s] * g[j][r] + (r == s ? mu * gg : 0.0));
                        for (r = 0; r < 3; r++)
                            for (b = 0; b < 6; b++)
                                T[r][b] = Kij[r][0] * P[j][0][b] + Kij[r][1] * P[j][1][b] + Kij[r][2] * P[j][2][b];
                        blockp = Ac + (size_t)(6 * m->node_agg[idx[i * HEML__W + k]]) * D + 6 * m->node_agg[idx[j * HEML__W + k]];
                        for (a = 0; a < 6; a++)
                            for (b = 0; b < 6; b++)
                                blockp[(size_t)a * D + b] += P[i][0][a] * T[0][b] + P[i][1][a] * T[1][b] + P[i][2][a] * T[2][b];
                    }
            }
        }
    }
    for (i = 0; i < m->anchor_count; i++) { /* the anchors' k I on their nodes: P^T k P */
        double P[3][6], ka = (double)m->anchor_k[i];
        double *blockp = Ac + (size_t)(6 * m->node_agg[m->anchor_nodes[i]]) * D + 6 * m->node_agg[m->anchor_nodes[i]];
        heml__node_modes(m, m->anchor_nodes[i], P);
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) blockp[(size_t)a * D + b] += ka * (P[0][a] * P[0][b] + P[1][a] * P[1][b] + P[2][a] * P[2][b]);
    }
}

/* coarse_k = P^T K0 P, when the pins changed since its last assembly (implicit_coarse >= 0:
   the static solve and the implicit steps share it). */
static void heml__coarse_k_update(heml_model *m)
{
    if (m->coarse_k_version == m->pin_version) return;
    heml__coarse_assemble(m, m->coarse_k, 0);
    m->coarse_k_version = m->pin_version;
}

/* Cholesky factor of the D x D matrix Ac in place (lower triangle, row-major); a mode whose
   pivot falls below 1e-10 of its diagonal is dropped (zero row and column of L). dg:
   D doubles of scratch. */
static void heml__coarse_factor(double *Ac, int D, double *dg)
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

/* The static solve's A_c = P^T K0 P, Cholesky-factored into `coarse`, when the pins
   changed since (assembled into coarse_k first, which the implicit steps share, unless
   implicit_coarse = -1 left it out); while kdev (heml__dev_probe), the deviatoric one
   (coarse_dev says which one `coarse` holds). */
static void heml__coarse_build(heml_model *m)
{
    size_t D = 6 * (size_t)m->agg_count;
    int dev = m->kdev || m->pc_live;
    if (!m->agg_count || (m->coarse_version == m->pin_version && m->coarse_dev == dev)) return;
    if (m->implicit_coarse < 0 || dev) heml__coarse_assemble(m, m->coarse, dev); /* (no coarse_k) */
    else {
        heml__coarse_k_update(m);
        memcpy(m->coarse, m->coarse_k, sizeof(double) * D * D);
    }
    heml__coarse_factor(m->coarse, (int)D, m->coarse_rhs);
    m->coarse_version = m->pin_version;
    m->coarse_dev = dev;
}

/* The implicit steps' coarse matrix P^T (D + c K0) P (D the solve's diagonal, NULL: 0),
   Cholesky-factored into coarse_step, unless the factor there already has this D's
   projection P^T D P (compared bit for bit: 36 doubles per aggregate, one pass over the
   nodes), this c and these pins: a step's Newton iterations, and the steps of one dt,
   reuse one factor. K0 is the rest state's small-strain stiffness (the static solve's),
   not the tangent at the iterate: the correction is a preconditioner, CG checks the
   answer. */
static void heml__coarse_step_build(heml_model *m, const heml_real *diag, double c)
{
    int A = m->agg_count, D = 6 * A, i, r, a, b;
    double *pdp = m->coarse_pdp_new, *Ac = m->coarse_step;
    memset(pdp, 0, sizeof(double) * 36 * (size_t)A);
    if (diag)
        for (i = 0; i < m->node_count; i++) {
            double P[3][6], *blk = pdp + 36 * (size_t)m->node_agg[i];
            heml__node_modes(m, i, P);
            for (r = 0; r < 3; r++) {
                double d = (double)diag[3 * i + r];
                if (d == 0.0) continue;
                for (a = 0; a < 6; a++) {
                    double pa = d * P[r][a];
                    if (pa == 0.0) continue;
                    for (b = 0; b < 6; b++) blk[6 * a + b] += pa * P[r][b];
                }
            }
        }
    if (m->coarse_step_version == m->pin_version && m->coarse_step_c == c &&
        !memcmp(pdp, m->coarse_pdp, sizeof(double) * 36 * (size_t)A))
        return;
    heml__coarse_k_update(m);
    for (i = 0; i < D * D; i++) Ac[i] = c * m->coarse_k[i];
    for (i = 0; i < A; i++)
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) Ac[(size_t)(6 * i + a) * D + 6 * i + b] += pdp[36 * i + 6 * a + b];
    heml__coarse_factor(Ac, D, m->coarse_rhs);
    memcpy(m->coarse_pdp, pdp, sizeof(double) * 36 * (size_t)A);
    m->coarse_step_c = c;
    m->coarse_step_version = m->pin_version;
    m->stats.coarse_factors++;
}

/* Which coarse correction a Krylov solve asked for (HEML__COARSE_*) gets: the static one
   or the step's, built or reused here; 0 on a mesh without a coarse space. */
#define HEML__COARSE_STATIC 1 /* P^T K0 P (the static solve, its saddle probe, the modal solve) */
#define HEML__COARSE_STEP 2   /* P^T (D + c K0) P (the implicit steps) */
static int heml__coarse_prepare(heml_model *m, int coarse, const heml_real *diag, double c)
{
    if (!coarse || !m->agg_count) return 0;
    if (coarse == HEML__COARSE_STEP) heml__coarse_step_build(m, diag, c);
    else heml__coarse_build(m);
    return coarse;
}

/* y = L^-1 y (forward) or L^-T y (backward) for a heml__coarse_factor factor L (D x D). */
static void heml__chol_forward(const double *L, int D, double *y)
{
    int i, j;
    for (i = 0; i < D; i++) {
        const double *Li = L + (size_t)i * D;
        double t = y[i];
        if (Li[i] == 0.0) {
            y[i] = 0.0;
            continue;
        }
        for (j = 0; j < i; j++) t -= Li[j] * y[j];
        y[i] = t / Li[i];
    }
}
static void heml__chol_backward(const double *L, int D, double *y)
{
    int i, j;
    for (i = D - 1; i >= 0; i--) {
        double t = y[i], Lii = L[(size_t)i * D + i];
        if (Lii == 0.0) {
            y[i] = 0.0;
            continue;
        }
        for (j = i + 1; j < D; j++) t -= L[(size_t)j * D + i] * y[j];
        y[i] = t / Lii;
    }
}

/* z += P A_c^-1 P^T r on the free degrees of freedom. */
static void heml__coarse_apply(heml_model *m, const double *L, const heml_real *rv, heml_real *z)
{
    int A = m->agg_count, D = 6 * A, i, r;
    double *y = m->coarse_rhs;
    memset(y, 0, sizeof(double) * (size_t)D);
    for (i = 0; i < m->node_count; i++) { /* y += P^T r: per node (r, rho x r), rho = X - c (heml__node_modes) */
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
    heml__chol_forward(L, D, y);  /* L y' = y */
    heml__chol_backward(L, D, y); /* L^T x = y' */
    for (i = 0; i < m->node_count; i++) { /* z += P y: per node t + w x rho on the free axes */
        const double *c = m->agg_centre + 3 * m->node_agg[i], *ya = y + 6 * m->node_agg[i];
        double rho[3], d[3];
        for (r = 0; r < 3; r++) rho[r] = (double)m->rest[3 * i + r] - c[r];
        d[0] = ya[0] + (ya[4] * rho[2] - ya[5] * rho[1]);
        d[1] = ya[1] + (ya[5] * rho[0] - ya[3] * rho[2]);
        d[2] = ya[2] + (ya[3] * rho[1] - ya[4] * rho[0]);
        for (r = 0; r < 3; r++)
            if (m->free_mask[3 * i + r] > 0) z[3 * i + r] += (heml_real)d[r];
    }
}

/* The static solve's pressure-aggregate preconditioner (nodal_pressure = 2; SOLVERS, PRESSURE
   AGGREGATES "Krylov iterations"). The tangent is K = K_dev + s G^T Dn G (heml__dev_probe):
   G's row A is g_A(v) = sum_{a in A} sum_{e at a} Vol_e dJ_e(v) / 4 (the sums pass folded
   into the aggregate), Dn = diag(d_A), d_A = sum_mat W_A,mat U''(J_A) / V_A^2, s the Prony
   factor. With B_dev the deviatoric two-level preconditioner (Jacobi of the deviatoric
   small-strain diagonal plus the coarse space of the deviatoric small-strain stiffness),
   the preconditioner is (B_dev^-1 + G^T Dn G)^-1 (s Dn clamped at 0), applied by the
   Sherman-Morrison-Woodbury identity with G^ = sqrt(s Dn) G:
       z = B_dev r - B_dev G^^T S^-1 G^ B_dev r,   S = I + G^ B_dev G^^T  (A x A, dense),
   so that z^T K z / z^T B^-1 z lies between the extremes of v^T K_dev v / v^T B_dev^-1 v:
   the bulk modulus cancels exactly, and the iterations are those of the deviatoric
   problem. G^ is held explicitly per node (pgt_*: the aggregates of the node's star), from
   the current state, once per Krylov solve, with S (O(n w^2 + A (6 A_c)^2 + A^3)). */

/* pgt_agg: per node the aggregates of its tetrahedra's nodes, in the order met in d->tets
   (at creation). */
static void heml__pagg_pc_lists(heml_model *m, const heml_desc *d)
{
    int W = m->pgt_width, t, j, l, i;
    for (i = 0; i < m->node_count * W; i++) m->pgt_agg[i] = -1;
    for (t = 0; t < d->tet_count; t++)
        for (j = 0; j < 4; j++) {
            int *list = m->pgt_agg + (size_t)d->tets[4 * t + j] * W;
            for (l = 0; l < 4; l++) {
                int A = m->pagg[d->tets[4 * t + l]];
                for (i = 0; i < W && list[i] >= 0 && list[i] != A; i++) continue;
                if (i < W && list[i] < 0) list[i] = A; /* (i < W always: the width counted them) */
            }
        }
}

/* Whether a static Krylov solve may use the preconditioner: the model has it, and every
   material has the same Prony factor s > 0 (else K is no K_dev + s G^T Dn G); *sp = s. */
static int heml__pagg_pc_usable(const heml_model *m, double *sp)
{
    int i;
    double s = 1.0;
    if (!m->pagg_pc || m->kdev) return 0;
    for (i = 0; i < m->material_count; i++) {
        double si = m->mats[i].prony_count ? (double)m->prony_s[i] : 1.0;
        if (i == 0) s = si;
        else if (si != s) return 0;
    }
    *sp = s;
    return s > 0;
}

/* Fills pgt_val with G^ at x (sqrt(s d_A) g_A on the free axes) and factors S = I + G^
   B_dev G^^T into pc_s (B_dev: pinv, the deviatoric Jacobi, and the factored deviatoric
   coarse matrix in m->coarse when the mesh has one). One sums and node pass (d_A), one
   loop over the tetrahedra, all on the calling thread in a fixed order. */
static void heml__pagg_pc_build(heml_model *m, const heml_real *x, const heml_real *pinv, double s)
{
    int W = m->pgt_width, A = m->pagg_count, Dc = 6 * m->agg_count, slot, i, j, l, r, a, b;
    double *S = m->pc_s;
    memset(m->pc_w, 0, sizeof(heml_real) * 3 * (size_t)m->node_count);
    m->kdev = 2; /* the node pass writes d_A into pagg_dp */
    heml__nodal_prepare(m, HEML__DIFF, x, m->pc_w);
    m->kdev = 0;
    memset(m->pgt_val, 0, sizeof(double) * 3 * (size_t)m->node_count * (size_t)W);
    for (slot = 0; slot < m->slot_count; slot++) {
        int blk = slot / HEML__W, k = slot % HEML__W, q[4];
        const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
        const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
        double g[4][3], H[3][3], cof[3][3], cf[3][3], tr, vq, v[4][3];
        if (m->slot_tet[slot] < 0) continue;
        for (j = 0; j < 4; j++) q[j] = idx[j * HEML__W + k];
        for (j = 0; j < 3; j++)
            for (r = 0; r < 3; r++) g[j + 1][r] = (double)R[(3 * j + r) * HEML__W + k];
        for (r = 0; r < 3; r++) g[0][r] = -(g[1][r] + g[2][r] + g[3][r]);
        vq = (double)R[9 * HEML__W + k] / 4;
        for (r = 0; r < 3; r++) /* H = grad u, as heml__nodal_sums */
            for (l = 0; l < 3; l++) {
                H[r][l] = 0;
                for (j = 1; j < 4; j++) H[r][l] += ((double)x[3 * q[j] + r] - (double)x[3 * q[0] + r]) * g[j][l];
            }
        cof[0][0] = H[1][1] * H[2][2] - H[1][2] * H[2][1], cof[0][1] = H[1][2] * H[2][0] - H[1][0] * H[2][2];
        cof[0][2] = H[1][0] * H[2][1] - H[1][1] * H[2][0], cof[1][0] = H[0][2] * H[2][1] - H[0][1] * H[2][2];
        cof[1][1] = H[0][0] * H[2][2] - H[0][2] * H[2][0], cof[1][2] = H[0][1] * H[2][0] - H[0][0] * H[2][1];
        cof[2][0] = H[0][1] * H[1][2] - H[0][2] * H[1][1], cof[2][1] = H[0][2] * H[1][0] - H[0][0] * H[1][2];
        cof[2][2] = H[0][0] * H[1][1] - H[0][1] * H[1][0];
        tr = H[0][0] + H[1][1] + H[2][2];
        for (r = 0; r < 3; r++) /* cof F = (tr H + 1) I - H^T + cof H */
            for (l = 0; l < 3; l++) cf[r][l] = (r == l ? tr + 1 : 0) - H[l][r] + cof[r][l];
        for (j = 0; j < 4; j++) /* Vol dJ / 4 = sum_j v_j . du_j */
            for (r = 0; r < 3; r++) v[j][r] = vq * (cf[r][0] * g[j][0] + cf[r][1] * g[j][1] + cf[r][2] * g[j][2]);
        for (b = 0; b < 4; b++) {
            int Ab = m->pagg[q[b]];
            for (j = 0; j < 4; j++) {
                const int *list = m->pgt_agg + (size_t)q[j] * W;
                double *val = m->pgt_val + 3 * (size_t)q[j] * W;
                for (i = 0; list[i] != Ab; i++) continue; /* (listed at creation) */
                for (r = 0; r < 3; r++) val[3 * i + r] += v[j][r];
            }
        }
    }
    for (i = 0; i < m->node_count; i++) /* times sqrt(s d_A), on the free axes */
        for (l = 0; l < W && m->pgt_agg[(size_t)i * W + l] >= 0; l++) {
            double dA = s * (double)m->pagg_dp[m->pgt_agg[(size_t)i * W + l]], f = dA > 0 ? sqrt(dA) : 0.0;
            for (r = 0; r < 3; r++) m->pgt_val[3 * ((size_t)i * W + l) + r] *= m->free_mask[3 * i + r] > 0 ? f : 0.0;
        }
    memset(S, 0, sizeof(double) * (size_t)A * (size_t)A);
    for (i = 0; i < m->node_count; i++) /* S = G^ pinv G^^T */
        for (l = 0; l < W && m->pgt_agg[(size_t)i * W + l] >= 0; l++) {
            const double *vl = m->pgt_val + 3 * ((size_t)i * W + l);
            double *row = S + (size_t)m->pgt_agg[(size_t)i * W + l] * A;
            for (j = 0; j < W && m->pgt_agg[(size_t)i * W + j] >= 0; j++) {
                const double *vj = m->pgt_val + 3 * ((size_t)i * W + j);
                row[m->pgt_agg[(size_t)i * W + j]] += vl[0] * vj[0] * (double)pinv[3 * i] +
                                                     vl[1] * vj[1] * (double)pinv[3 * i + 1] +
                                                     vl[2] * vj[2] * (double)pinv[3 * i + 2];
            }
        }
    if (Dc) { /* + (L^-1 P^T G^^T)^T (L^-1 P^T G^^T), rows of pc_gp per aggregate */
        double *GP = m->pc_gp;
        memset(GP, 0, sizeof(double) * (size_t)A * (size_t)Dc);
        for (i = 0; i < m->node_count; i++) {
            double P[3][6];
            heml__node_modes(m, i, P);
            for (l = 0; l < W && m->pgt_agg[(size_t)i * W + l] >= 0; l++) {
                const double *vl = m->pgt_val + 3 * ((size_t)i * W + l);
                double *row = GP + (size_t)m->pgt_agg[(size_t)i * W + l] * Dc + 6 * m->node_agg[i];
                for (a = 0; a < 6; a++) row[a] += vl[0] * P[0][a] + vl[1] * P[1][a] + vl[2] * P[2][a];
            }
        }
        for (a = 0; a < A; a++) heml__chol_forward(m->coarse, Dc, GP + (size_t)a * Dc);
        for (a = 0; a < A; a++)
            for (b = 0; b <= a; b++) {
                const double *ga = GP + (size_t)a * Dc, *gb = GP + (size_t)b * Dc;
                double t = 0;
                for (i = 0; i < Dc; i++) t += ga[i] * gb[i];
                S[(size_t)a * A + b] += t;
            }
    }
    for (a = 0; a < A; a++) S[(size_t)a * A + a] += 1.0;
    heml__coarse_factor(S, A, m->pc_y);
}

/* z = B r with B = (B_dev^-1 + G^^T G^)^-1 (the Woodbury form above); pinv the deviatoric
   Jacobi. */
static void heml__pagg_pc_apply(heml_model *m, const heml_real *pinv, const heml_real *r, heml_real *z)
{
    int W = m->pgt_width, A = m->pagg_count, i, l, k, n3 = 3 * m->node_count;
    double *y = m->pc_y;
    heml_real *w = m->pc_w;
    for (i = 0; i < n3; i++) z[i] = pinv[i] * r[i];
    if (m->agg_count) heml__coarse_apply(m, m->coarse, r, z);
    memset(y, 0, sizeof(double) * (size_t)A);
    for (i = 0; i < m->node_count; i++) /* y = G^ z */
        for (l = 0; l < W && m->pgt_agg[(size_t)i * W + l] >= 0; l++) {
            const double *v = m->pgt_val + 3 * ((size_t)i * W + l);
            y[m->pgt_agg[(size_t)i * W + l]] +=
                v[0] * (double)z[3 * i] + v[1] * (double)z[3 * i + 1] + v[2] * (double)z[3 * i + 2];
        }
    heml__chol_forward(m->pc_s, A, y);
    heml__chol_backward(m->pc_s, A, y);
    for (i = 0; i < m->node_count; i++) { /* w = -G^^T y */
        double t[3] = {0, 0, 0};
        for (l = 0; l < W && m->pgt_agg[(size_t)i * W + l] >= 0; l++) {
            const double *v = m->pgt_val + 3 * ((size_t)i * W + l);
            double ya = y[m->pgt_agg[(size_t)i * W + l]];
            for (k = 0; k < 3; k++) t[k] += v[k] * ya;
        }
        for (k = 0; k < 3; k++) w[3 * i + k] = (heml_real)-t[k];
    }
    for (i = 0; i < n3; i++) z[i] += pinv[i] * w[i];
    if (m->agg_count) heml__coarse_apply(m, m->coarse, w, z);
}

/* >>creation -------------------------------------------------------------------------- */

/* The shortest rest edge of the mesh, m (the precision check's element size). */
static double heml__shortest_edge(const heml_desc *d)
{
    static const int ends[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {2, 3}, {3, 1}};
    double best = INFINITY;
    int t, e, r;
    for (t = 0; t < d->tet_count; t++)
        for (e = 0; e < 6; e++) {
            const heml_real *a = d->rest_positions + 3 * d->tets[4 * t + ends[e][0]];
            const heml_real *b = d->rest_positions + 3 * d->tets[4 * t + ends[e][1]];
            double l2 = 0.0;
            for (r = 0; r < 3; r++) l2 += ((double)a[r] - (double)b[r]) * ((double)a[r] - (double)b[r]);
            if (l2 < best) best = l2;
        }
    return sqrt(best);
}

HEMLDEF const char *heml_version(void) { return "0.3.0"; }

HEMLDEF const char *heml_error_string(int code)
{
    switch (code) {
#define HEML__CASE(name, value, text) \
    case name: return text;
        HEML_ERROR_LIST(HEML__CASE)
#undef HEML__CASE
    default: return "unknown error code";
    }
}

HEMLDEF heml_material heml_material_from_young(heml_law law, double young_modulus, double poisson_ratio)
{
    heml_material mt;
    double E = young_modulus, nu = poisson_ratio;
    double mu = E / (2.0 * (1.0 + nu)), lambda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    double K = E / (3.0 * (1.0 - 2.0 * nu));
    memset(&mt, 0, sizeof mt);
    mt.law = law;
    mt.mu = (heml_real)mu;
    mt.lambda = (heml_real)lambda;
    mt.young_modulus = (heml_real)E;
    mt.density = (heml_real)1000;
    switch (law) {
    case HEML_NEO_HOOKEAN_INCOMPRESSIBLE:
        mt.c1 = (heml_real)(mu / 2.0);
        mt.bulk_modulus = (heml_real)(K - 4.0 * (mu / 2.0) / 3.0);
        break;
    case HEML_MOONEY_RIVLIN_INCOMPRESSIBLE:
        mt.c1 = mt.c2 = (heml_real)(mu / 4.0);
        mt.bulk_modulus = (heml_real)(K - 4.0 * (mu / 4.0 + mu) / 3.0);
        break;
    case HEML_MOONEY_RIVLIN:
        mt.c1 = mt.c2 = (heml_real)(mu / 4.0);
        mt.bulk_modulus = (heml_real)K;
        break;
    default:
        mt.c1 = (heml_real)(mu / 2.0);
        mt.bulk_modulus = (heml_real)K;
        break;
    }
    return mt;
}

HEMLDEF heml_desc heml_default_desc(void)
{
    heml_desc d;
    memset(&d, 0, sizeof d);
    d.material = heml_material_from_young(HEML_NEO_HOOKEAN, 1e4, 0.3);
    d.inversion_threshold = (heml_real)0.4;
    d.stiffness_cache = 1;
    d.gravity[2] = (heml_real)-9.81;
    d.time_step = (heml_real)1e-3;
    d.integrator = HEML_SEMI_EXPLICIT_EULER;
    d.newton_iterations = 20;
    d.newton_tolerance = (heml_real)(HEML__FLOAT ? 1e-4 : 1e-6);
    d.max_increments = 64;
    d.min_increment = (heml_real)1e-4;
    d.allow_inversion = 0;
    d.leave_saddles = 0;
    d.precision_limit = (heml_real)1e-4;
    d.cg_tolerance = (heml_real)(HEML__FLOAT ? 1e-5 : 1e-6);
    d.cg_max_iterations = 1000;
    d.linear_solver = HEML_LINEAR_SOLVER_CG;
    d.static_max_iterations = 50;
    d.static_tolerance = (heml_real)(HEML__FLOAT ? 1e-4 : 1e-9);
    d.internal_cookie = HEML__COOKIE;
    return d;
}

/* Creation in four stages that read top to bottom: heml__create_validate (the description,
   every check before anything is allocated), heml__create_size (counts: blocks, chunks,
   Prony state, aggregates; the temporary workspace), heml__create_layout (the model's one
   block carved, the settings copied), heml__create_precompute (materials, the tetrahedra's
   order and rest constants, masses, chunks, colours, masks). */

/* Temporary workspace of heml_create (one allocation, freed before it returns): mass and
   stiffness-diagonal accumulators, the tetrahedra's order, per-material counts, fills and
   first blocks, node stamps (then the aggregate of each node), chunk colours and reorder
   space. */
typedef struct heml__create_tmp {
    void *block;
    size_t bytes;
    double *mass_acc, *diag_acc;
    heml__order *order_of;
    int *counts, *fill, *bstart, *stamp, *colour_of, *order;
    int *pagg; /* nodal_pressure = 2: node -> pressure aggregate (heml__pressure_aggregates) */
} heml__create_tmp;

/* Creation stage 2: sizes the model (in *tmp, a model not yet allocated) and allocates the
   temporary workspace w. */
static int heml__create_size(const heml_desc *d, heml_model *tmp, heml__create_tmp *w)
{
    const heml_material *src = d->materials ? d->materials : &d->material;
    int i, t, M = d->materials ? d->material_count : 1, T = d->tet_count, n = d->node_count;
    int C_max = M + T / (HEML__W * HEML__CHUNK) + 1;
    size_t agg_ints = d->nodal_pressure == 2 ? 2 * (size_t)n + 1 + 12 * (size_t)T : 0;
    w->bytes = sizeof(double) * 4 * (size_t)n + sizeof(heml__order) * (size_t)T +
               sizeof(int) * (3 * (size_t)M + (size_t)n + 4 * (size_t)C_max + agg_ints);
    w->block = heml__alloc(&d->allocator, w->bytes);
    if (!w->block) return heml__fail(d, HEML_ERR_ALLOC, "temporary block");
    w->mass_acc = (double *)w->block;
    w->diag_acc = w->mass_acc + n;
    w->order_of = (heml__order *)(w->diag_acc + 3 * (size_t)n);
    w->counts = (int *)(w->order_of + T);
    w->fill = w->counts + M;
    w->bstart = w->fill + M;
    w->stamp = w->bstart + M;
    w->colour_of = w->stamp + n;
    w->order = w->colour_of + C_max;
    w->pagg = agg_ints ? w->order + C_max : NULL;

    memset(tmp, 0, sizeof *tmp);
    tmp->node_count = n;
    tmp->tet_count = T;
    tmp->material_count = M;
    for (i = 0; i < M; i++) w->counts[i] = w->fill[i] = 0;
    for (t = 0; t < T; t++) w->counts[d->tet_material ? d->tet_material[t] : 0]++;
    for (i = 0; i < M; i++) {
        int blocks = (w->counts[i] + HEML__W - 1) / HEML__W, used = w->counts[i] > 0;
        w->bstart[i] = tmp->block_count;
        tmp->block_count += blocks;
        tmp->chunk_count += (blocks + HEML__CHUNK - 1) / HEML__CHUNK;
        tmp->prony_total += src[i].prony_count;
        tmp->prony_reals += (size_t)blocks * HEML__W * HEML__NQ * (size_t)src[i].prony_count;
        if (heml__laws[src[i].law].kind == HEML__K_SPRING && used) tmp->has_springs = 1;
        if (src[i].prony_count && used) tmp->has_prony = 1;
        if (heml__laws[src[i].law].kind == HEML__K_USER && !src[i].user.second && used)
            tmp->has_user_without_second = 1;
    }
    tmp->slot_count = tmp->block_count * HEML__W;
    tmp->nodal = d->nodal_pressure;
    for (i = 0; i < M && d->stiffness_cache && !tmp->nodal; i++) { /* a fast-path material in use */
        heml__mat mt;
        heml__make_mat(src + i, &mt);
        if (mt.dk && w->counts[i] > 0) {
            int rows = HEML__DK_ROWS(mt.dk);
            tmp->has_dc = 1;
            if (rows > tmp->dc_rows) tmp->dc_rows = rows;
        }
    }
    for (i = 0; i < M && tmp->nodal; i++) { /* a fast_nodal material in use: heml__forces_nh's kept H */
        heml__mat mt;
        heml__make_mat(src + i, &mt);
        if (mt.fast && w->counts[i] > 0) tmp->nod_keep_h = 1;
    }
    tmp->nod_chunks = (n + HEML__NODE_CHUNK - 1) / HEML__NODE_CHUNK;
    if (w->pagg) tmp->pagg_count = heml__pressure_aggregates(d, w->pagg, w->pagg + n, w->pagg + 2 * (size_t)n + 1);
    if (tmp->pagg_count > 0 && tmp->pagg_count <= HEML_PAGG_PC_MAX) { /* heml__pagg_pc_build's width: the */
        const int *agg = w->pagg, *start = w->pagg + n, *adj = w->pagg + 2 * (size_t)n + 1; /* most */
        int a, l;                           /* aggregates among a node and its neighbours */
        for (a = 0; a < tmp->pagg_count; a++) w->stamp[a] = -1;
        for (a = 0; a < n; a++) {
            int count = 0;
            if (agg[a] < 0) continue;
            w->stamp[agg[a]] = a, count = 1;
            for (l = start[a]; l < start[a + 1]; l++)
                if (w->stamp[agg[adj[l]]] != a) w->stamp[agg[adj[l]]] = a, count++;
            if (count > tmp->pgt_width) tmp->pgt_width = count;
        }
    }
    {
        int cells[HEML__MAX_AGG];
        tmp->agg_count = heml__aggregate(d->rest_positions, n, w->stamp, cells);
    }
    tmp->implicit_coarse = d->implicit_coarse; /* (-1: the step's coarse arrays are not carved) */
    return HEML_OK;
}

/* Creation stage 3: allocates the model's block, carves every array in it (heml__layout)
   and copies the description's settings and rest positions. */
static int heml__create_layout(const heml_desc *d, const heml_model *sized, heml_model **out)
{
    heml_model tmp = *sized, *m;
    heml__carver carver;
    int i;
    carver.base = NULL;
    carver.offset = sizeof(heml_model);
    heml__layout(&tmp, &carver);
    tmp.block_bytes = carver.offset;
    tmp.block = heml__alloc(&d->allocator, tmp.block_bytes);
    if (!tmp.block) return heml__fail(d, HEML_ERR_ALLOC, "model block");
    memset(tmp.block, 0, tmp.block_bytes);
    carver.base = (char *)tmp.block;
    carver.offset = sizeof(heml_model);
    heml__layout(&tmp, &carver);
    m = (heml_model *)tmp.block;
    *m = tmp;

    m->integrator = d->integrator;
    m->linear_solver = d->linear_solver;
    m->time_step = d->time_step;
    m->mass_damping = d->mass_damping;
    for (i = 0; i < 3; i++) m->gravity[i] = d->gravity[i];
    m->cg_tolerance = d->cg_tolerance;
    m->cg_max_iterations = d->cg_max_iterations;
    m->newton_iterations = d->newton_iterations;
    m->static_max_iterations = d->static_max_iterations;
    m->static_tolerance = d->static_tolerance;
    m->newton_tolerance = d->newton_tolerance;
    m->max_increments = d->max_increments;
    m->min_increment = d->min_increment;
    m->allow_inversion = d->allow_inversion;
    m->leave_saddles = d->leave_saddles;
    m->implicit_coarse = d->implicit_coarse;
    m->precision_limit = d->precision_limit;
    m->J0 = d->inversion_threshold;
    m->jm1_0 = (heml_real)((double)d->inversion_threshold - 1.0);
    m->allocator = d->allocator;
    m->parallel_for = d->parallel_for;
    m->parallel_user = d->parallel_user;
    m->parallel = d->tet_count >= HEML_PARALLEL_MIN_TETS;
    m->simd = 1;
    memcpy(m->rest, d->rest_positions, sizeof(heml_real) * 3 * (size_t)d->node_count);
    memcpy(m->pos, d->rest_positions, sizeof(heml_real) * 3 * (size_t)d->node_count);
    *out = m;
    return HEML_OK;
}

/* Materials in kernel form with their Prony terms and small-strain moduli. */
static void heml__create_materials(heml_model *m, const heml_material *src)
{
    int i, k, t;
    for (i = 0, t = 0; i < m->material_count; i++) {
        heml__mat *mt = m->mats + i;
        heml__make_mat(src + i, mt);
        mt->prony_first = t;
        for (k = 0; k < src[i].prony_count; k++, t++) {
            m->prony_alpha[t] = src[i].prony[k].alpha;
            m->prony_tau[t] = src[i].prony[k].tau;
        }
        if (m->nodal) { /* the general path carries the nodal pressure, but for the force */
            mt->fast_nodal = mt->fast;
            mt->fast = mt->dk = mt->fast_mr = 0;
        }
        (void)heml__small_strain(mt, m->jm1_0, &mt->small_mu, &mt->small_lambda);
        if (mt->small_mu < 0) mt->small_mu = 0;
        if (mt->small_lambda + mt->small_mu < 0) mt->small_lambda = -mt->small_mu;
    }
}

/* Chunks of consecutive blocks of one material, and each block's Prony state offset. */
static void heml__create_chunks(heml_model *m, const heml_material *src, const heml__create_tmp *w)
{
    int i, c = 0;
    size_t off = 0;
    for (i = 0; i < m->material_count; i++) {
        int blocks = (w->counts[i] + HEML__W - 1) / HEML__W, b;
        for (b = 0; b < blocks; b++) {
            m->blk_prony[w->bstart[i] + b] = off;
            off += (size_t)HEML__W * HEML__NQ * (size_t)src[i].prony_count;
        }
        for (b = 0; b < blocks; b += HEML__CHUNK, c++) {
            m->chunk_begin[c] = w->bstart[i] + b;
            m->chunk_end[c] = w->bstart[i] + (b + HEML__CHUNK < blocks ? b + HEML__CHUNK : blocks);
            m->chunk_material[c] = i;
        }
    }
    HEML_ASSERT(c == m->chunk_count && off == m->prony_reals);
}

/* Creation stage 4: everything the rest state determines: materials, the tetrahedra's
   slots (grouped by material, in node order: heml__node_order, each material padded to
   whole blocks), rest constants, masses and the stiffness diagonal (heml__fill_tets),
   chunks, aggregates, colours, masks, Prony coefficients, the shortest edge. */
static void heml__create_precompute(const heml_desc *d, heml_model *m, heml__create_tmp *w)
{
    const heml_material *src = d->materials ? d->materials : &d->material;
    int i, t;
    heml__create_materials(m, src);
    heml__node_order(d, w->order_of);
    for (i = 0; i < m->slot_count; i++) m->slot_tet[i] = -1;
    for (i = 0; i < m->tet_count; i++) {
        int mi = w->order_of[i].material, slot = w->bstart[mi] * HEML__W + w->fill[mi]++;
        t = w->order_of[i].tet;
        m->slot_tet[slot] = t;
        m->tet_slot[t] = slot;
    }
    heml__fill_tets(m, d, w->mass_acc, w->diag_acc);
    if (m->nodal) heml__nodal_weights(m, d, w->mass_acc);
    if (m->pagg_count) heml__pressure_aggregate_weights(m, w->pagg, w->mass_acc, w->diag_acc);
    if (m->pgt_width) heml__pagg_pc_lists(m, d);
    m->dev_probe = m->nodal; /* where it pays: every material's bulk modulus at least
                                HEML__DEV_PROBE_RATIO times its shear modulus (heml__dev_probe) */
    for (i = 0; i < m->material_count; i++)
        if (m->mats[i].small_lambda + 2.0 / 3.0 * m->mats[i].small_mu < HEML__DEV_PROBE_RATIO * m->mats[i].small_mu)
            m->dev_probe = 0;
    m->pagg_pc = m->pgt_width > 0 && m->dev_probe; /* the same rule: where it pays (SOLVERS) */
    heml__create_chunks(m, src, w);
    if (m->agg_count) memcpy(m->node_agg, w->stamp, sizeof(int) * (size_t)m->node_count);
    heml__aggregate_centres(m);
    heml__colour_groups(m, w->stamp, w->colour_of, w->order);
    for (i = 0; i < m->node_count; i++) heml__set_masks(m, i);
    m->coarse_version = m->coarse_k_version = m->coarse_step_version = m->pin_version - 1;
    m->coarse_plain = -1;
    heml__prony_coefficients(m, (double)m->time_step);
    m->h_min = heml__shortest_edge(d);
    m->stats.newton_iterations = 0;
}

HEMLDEF int heml_create(const heml_desc *d, heml_model **out)
{
    heml_model sized, *m = NULL;
    heml__create_tmp w;
    heml_allocator alloc;
    int err;
    if (!out) return HEML_ERR_ARG;
    *out = NULL;
    if (!d) return HEML_ERR_ARG;
    memset(&w, 0, sizeof w);
    err = heml__create_validate(d);
    if (err) return err;
    alloc = d->allocator;
    err = heml__create_size(d, &sized, &w);
    if (err) return err;
    err = heml__create_layout(d, &sized, &m);
    if (!err) heml__create_precompute(d, m, &w);
    heml__free(&alloc, w.block, w.bytes);
    if (err) return err;
    *out = m;
    return HEML_OK;
}

HEMLDEF void heml_destroy(heml_model *m)
{
    heml_allocator a;
    if (!m) return;
    a = m->allocator;
    heml__free(&a, m->block, m->block_bytes);
}

/* >>solver ---------------------------------------------------------------------------- */

static double heml__dot(const heml_real *a, const heml_real *b, int n)
{
    /* fixed blocks, four interleaved accumulators, blocks summed in order */
    double total = 0.0;
    int i0, i;
    for (i0 = 0; i0 < n; i0 += HEML__VEC_BLOCK) {
        double s[4] = {0, 0, 0, 0};
        int i1 = i0 + HEML__VEC_BLOCK < n ? i0 + HEML__VEC_BLOCK : n;
        for (i = i0; i < i1; i++) s[i & 3] += (double)a[i] * (double)b[i];
        total += (s[0] + s[1]) + (s[2] + s[3]);
    }
    return total;
}

/* q = mask (D p - c df(x_lin) p) */
static void heml__cg_apply(heml_model *m, const heml_real *diag, double c, const heml_real *p, heml_real *q)
{
    int i, n3 = 3 * m->node_count;
    heml_real cc = (heml_real)c;
    heml__diff_run(m, m->lin_x, p, q);
    for (i = 0; i < n3; i++) q[i] = m->free_mask[i] * ((diag ? diag[i] * p[i] : 0) - cc * q[i]);
}

/* The Jacobi preconditioner of D - c df/dx: 1 / (D + c times the small-strain stiffness
   diagonal) on the free degrees of freedom, 0 on the others. */
static void heml__jacobi(const heml_model *m, const heml_real *diag, double c, heml_real *pinv)
{
    int i, n3 = 3 * m->node_count;
    const heml_real *kd = m->kdev || m->pc_live ? m->diag_dev : m->diag;
    for (i = 0; i < n3; i++) {
        double dgl = (diag ? (double)diag[i] : 0.0) + c * (double)kd[i];
        pinv[i] = (heml_real)(m->free_mask[i] > 0 && dgl > 0 ? 1.0 / dgl : 0.0);
    }
    if (m->anchor_count) { /* the anchors' k joins the diagonal of the nodes they hold */
        int a, r, j;
        for (a = 0; a < m->anchor_count; a++) /* pinv holds each anchored entry's sum of k first */
            for (r = 0; r < 3; r++) pinv[3 * m->anchor_nodes[a] + r] = 0;
        for (a = 0; a < m->anchor_count; a++)
            for (r = 0; r < 3; r++) pinv[3 * m->anchor_nodes[a] + r] += m->anchor_k[a];
        for (a = 0; a < m->anchor_count; a++) /* then its inverse, stored negated: each entry once */
            for (r = 0; r < 3; r++) {
                double dgl;
                j = 3 * m->anchor_nodes[a] + r;
                if (pinv[j] < 0) continue;
                dgl = (diag ? (double)diag[j] : 0.0) + c * ((double)kd[j] + (double)pinv[j]);
                pinv[j] = (heml_real)(m->free_mask[j] > 0 && dgl > 0 ? -1.0 / dgl : -0.0);
            }
        for (a = 0; a < m->anchor_count; a++)
            for (r = 0; r < 3; r++) {
                j = 3 * m->anchor_nodes[a] + r;
                pinv[j] = pinv[j] < 0 ? -pinv[j] : 0;
            }
    }
}

/* z = pinv r, plus the coarse correction `coarse` (HEML__COARSE_*, as heml__coarse_prepare
   returned it; 0: none). */
static void heml__precond(heml_model *m, const heml_real *pinv, const heml_real *r, heml_real *z, int coarse)
{
    int i, n3 = 3 * m->node_count;
    if (m->pc_live) {
        heml__pagg_pc_apply(m, pinv, r, z);
        return;
    }
    for (i = 0; i < n3; i++) z[i] = pinv[i] * r[i];
    if (coarse) heml__coarse_apply(m, coarse == HEML__COARSE_STEP ? m->coarse_step : m->coarse, r, z);
}

#define HEML__NEGATIVE_CURVATURE 1 /* private result of heml__cg */
/* heml__cg's workspace vectors that callers read after a solve: the last direction p, its
   product q = A p, the Jacobi preconditioner; HEML__CG_FREE and the next are unused by CG */
#define HEML__CG_P 2
#define HEML__CG_Q 3
#define HEML__CG_PINV 4
#define HEML__CG_FREE 5

/* Solves (D - c df/dx(x_lin)) x = b on the free degrees of freedom by Jacobi-
   preconditioned CG. x holds the initial guess; pinned entries are held at 0. Returns
   HEML_OK when |r| <= rtol |b|, HEML_ERR_NO_CONVERGENCE after cg_max_iterations (x is
   the last iterate), HEML__NEGATIVE_CURVATURE at a direction of non-positive curvature
   (the system is not positive definite; x is the iterate before it). With `coarse` (the
   static problem, diag NULL and c = 1) the preconditioner adds the coarse correction.
   Workspace s[0..4]: r, z, p, q, pinv (HEML__CG_*; p, q and pinv are read after a solve). */
static int heml__cg(heml_model *m, const heml_real *x_lin, const heml_real *diag, double c,
                    const heml_real *b, heml_real *x, double rtol, int coarse, heml_real **s)
{
    heml_real *r = s[0], *z = s[1], *p = s[2], *q = s[3], *pinv = s[4];
    int n3 = 3 * m->node_count, i, it;
    double bb, rr, rz, tol2, ps = 0; /* set by heml__pagg_pc_usable where pc_live */
    m->lin_x = x_lin;
    heml__dc_invalidate(m);
    m->pc_live = coarse == HEML__COARSE_STATIC && heml__pagg_pc_usable(m, &ps);
    coarse = heml__coarse_prepare(m, coarse, diag, c);
    heml__jacobi(m, diag, c, pinv);
    if (m->pc_live) heml__pagg_pc_build(m, x_lin, pinv, ps * c);
    for (i = 0; i < n3; i++) {
        x[i] *= m->free_mask[i];
        r[i] = b[i] * m->free_mask[i];
    }
    bb = heml__dot(r, r, n3);
    m->stats.cg_residual = 0;
    if (!heml__finite(bb)) return HEML_ERR_NOT_FINITE; /* |b|^2 overflowed: never a pass */
    if (bb == 0.0) {
        memset(x, 0, sizeof(heml_real) * (size_t)n3);
        return HEML_OK;
    }
    tol2 = rtol * rtol * bb;
    heml__cg_apply(m, diag, c, x, q);
    for (i = 0; i < n3; i++) r[i] -= q[i];
    heml__precond(m, pinv, r, z, coarse);
    memcpy(p, z, sizeof(heml_real) * (size_t)n3);
    rr = heml__dot(r, r, n3);
    rz = heml__dot(r, z, n3);
    for (it = 0; it < m->cg_max_iterations && rr > tol2; it++) {
        double pq, alpha, beta, rz_new;
        heml__cg_apply(m, diag, c, p, q);
        pq = heml__dot(p, q, n3);
        if (!(pq > 0.0)) {
            m->stats.negative_curvature++;
            m->stats.cg_iterations += it;
            return HEML__NEGATIVE_CURVATURE;
        }
        alpha = rz / pq;
        for (i = 0; i < n3; i++) {
            x[i] += (heml_real)alpha * p[i];
            r[i] -= (heml_real)alpha * q[i];
        }
        heml__precond(m, pinv, r, z, coarse);
        rr = heml__dot(r, r, n3);
        rz_new = heml__dot(r, z, n3);
        beta = rz_new / rz;
        rz = rz_new;
        for (i = 0; i < n3; i++) p[i] = z[i] + (heml_real)beta * p[i];
    }
    m->stats.cg_iterations += it;
    m->stats.cg_residual = (heml_real)sqrt(rr / bb);
    if (!heml__finite(rr)) return HEML_ERR_NOT_FINITE;
    return rr <= tol2 ? HEML_OK : HEML_ERR_NO_CONVERGENCE;
}

/* Solves (D - c df/dx(x_lin)) x = b (symmetric, possibly indefinite) on the free degrees
   of freedom by MINRES (Paige & Saunders 1975) with the Jacobi preconditioner, from
   x = 0, until the preconditioned residual is below rtol times its initial value or after
   cg_max_iterations (x is then the last iterate: its residual never exceeds |b|). Used
   by the static solve (Newton iterates far from equilibrium, or beyond a buckling load,
   have an indefinite tangent, where CG would stop) and by the implicit step after CG met
   negative curvature. `coarse` as for heml__cg. Returns HEML_OK or
   HEML_ERR_NO_CONVERGENCE (or HEML_ERR_NOT_FINITE for a right-hand side whose norm
   overflows). Workspace s[0..7]. */
static int heml__minres(heml_model *m, const heml_real *x_lin, const heml_real *diag, double c,
                        const heml_real *b, heml_real *x, double rtol, int coarse, heml_real **s)
{
    heml_real *r1 = s[0], *r2 = s[1], *y = s[2], *v = s[3], *w = s[4], *w1 = s[5], *w2 = s[6];
    heml_real *pinv = s[7];
    int n3 = 3 * m->node_count, i, it;
    double beta1, beta, oldb = 0, dbar = 0, epsln = 0, phibar, cs = -1, sn = 0, tol, ps = 0;
    m->lin_x = x_lin;
    heml__dc_invalidate(m);
    m->pc_live = coarse == HEML__COARSE_STATIC && heml__pagg_pc_usable(m, &ps);
    coarse = heml__coarse_prepare(m, coarse, diag, c);
    heml__jacobi(m, diag, c, pinv);
    if (m->pc_live) heml__pagg_pc_build(m, x_lin, pinv, ps * c);
    for (i = 0; i < n3; i++) {
        x[i] = w[i] = w2[i] = 0;
        r1[i] = r2[i] = b[i] * m->free_mask[i];
    }
    heml__precond(m, pinv, r1, y, coarse);
    beta1 = heml__dot(r1, y, n3);
    m->stats.cg_residual = 0;
    if (!heml__finite(beta1)) return HEML_ERR_NOT_FINITE;
    if (!(beta1 > 0.0)) return HEML_OK;
    beta1 = sqrt(beta1);
    beta = phibar = beta1;
    tol = rtol * beta1;
    for (it = 0; it < m->cg_max_iterations && phibar > tol; it++) {
        double alfa, oldeps, delta, gbar, gamma, phi, sb = 1.0 / beta;
        for (i = 0; i < n3; i++) v[i] = (heml_real)(sb * y[i]);
        heml__cg_apply(m, diag, c, v, y); /* y = A v on the free degrees of freedom */
        if (it > 0)
            for (i = 0; i < n3; i++) y[i] -= (heml_real)(beta / oldb) * r1[i];
        alfa = heml__dot(v, y, n3);
        for (i = 0; i < n3; i++) {
            y[i] -= (heml_real)(alfa / beta) * r2[i];
            r1[i] = r2[i];
            r2[i] = y[i];
        }
        heml__precond(m, pinv, r2, y, coarse);
        oldb = beta;
        beta = heml__dot(r2, y, n3);
        beta = beta > 0 ? sqrt(beta) : 0.0;
        oldeps = epsln;
        delta = cs * dbar + sn * alfa;
        gbar = sn * dbar - cs * alfa;
        epsln = sn * beta;
        dbar = -cs * beta;
        gamma = sqrt(gbar * gbar + beta * beta);
        if (gamma < 1e-300) gamma = 1e-300;
        cs = gbar / gamma;
        sn = beta / gamma;
        phi = cs * phibar;
        phibar = sn * phibar;
        for (i = 0; i < n3; i++) {
            heml_real t = w2[i];
            w2[i] = w[i];
            w1[i] = t;
            w[i] = (heml_real)(((double)v[i] - oldeps * (double)w1[i] - delta * (double)w2[i]) / gamma);
            x[i] += (heml_real)phi * w[i];
        }
        if (beta == 0.0) break; /* invariant subspace: exact */
    }
    m->stats.cg_iterations += it;
    m->stats.cg_residual = (heml_real)(phibar / beta1);
    return phibar <= tol ? HEML_OK : HEML_ERR_NO_CONVERGENCE;
}

/* >>linear-solvers: one row per heml_linear_solver, indexed by it (see HOW TO EXTEND).
   `solve` is for systems expected to be positive definite, `solve_indefinite` for
   symmetric indefinite ones. Both solve (D - c df/dx(x_lin)) x = b on the free degrees of
   freedom (D a diagonal or NULL; with `coarse` the static solve's coarse correction) from
   the guess in x, to |r| <= rtol |b|, in the model's Krylov workspace (m->krylov), and
   return the same codes:
       HEML_OK                   converged;
       HEML_ERR_NO_CONVERGENCE   cg_max_iterations reached (x is the last iterate);
       HEML_ERR_NOT_FINITE       |b|^2 or the residual is not finite;
       HEML__NEGATIVE_CURVATURE  (private, positive; `solve` only) a direction of
                                 non-positive curvature: the system is not positive
                                 definite, x is the iterate before it. Callers decide: the
                                 linearised step switches to solve_indefinite, Newton adds a
                                 Levenberg-Marquardt shift, the saddle probe has found its
                                 saddle, the static predictor drops the prediction. */
typedef int (*heml__solve_fn)(heml_model *m, const heml_real *x_lin, const heml_real *diag, double c,
                              const heml_real *b, heml_real *x, double rtol, int coarse, heml_real **s);
typedef struct heml__linear_solver_ops {
    const char *name;
    heml__solve_fn solve, solve_indefinite;
} heml__linear_solver_ops;

static const heml__linear_solver_ops heml__linear_solvers[] = {
    {"conjugate gradient (MINRES if indefinite)", heml__cg, heml__minres},
};
typedef char heml__linear_solvers_has_a_row_per_solver
    [sizeof heml__linear_solvers / sizeof heml__linear_solvers[0] == HEML_LINEAR_SOLVER_COUNT ? 1 : -1];

#define HEML__SPD 0
#define HEML__INDEFINITE 1
#define HEML__PROBE 2 /* the saddle probe's solve (positive definite; CG must see its curvature) */

/* The saddle probe's solve on the deviatoric stiffness (NEAR-INCOMPRESSIBLE BODIES,
   "Solvers"): with the nodal pressure the tangent is K = K_dev + s G^T Dn G (K_dev the
   element pass with the nodal dP_a held at 0, G du = (sum Vol_e dJ_e / 4)_a, Dn =
   diag(d_a), d_a = sum_mat W U''_mat(J_a) / V_a^2, s the Prony factor), so where every d_a
   >= 0 and every material has the same factor s > 0, D + c K >= D + c K_dev: a probe that
   meets no negative curvature of D + c K_dev has shown the same of D + c K, at the
   conditioning of the shear modulus rather than the bulk modulus (Jacobi of the
   deviatoric small-strain diagonal, the coarse space of the deviatoric small-strain
   stiffness). Returns the CG's code (x as CG left it), or HEML__NEGATIVE_CURVATURE (x
   reset to 0) where the full probe must decide: K_dev has negative curvature, the
   conditions fail, or the model's bulk-to-shear ratio is too low for it to pay
   (dev_probe 0). One more sums and node pass, d_a in nod_dp (scratch: krylov[0]). */
static int heml__dev_probe(heml_model *m, const struct heml__linear_solver_ops *ops, const heml_real *x_lin,
                           const heml_real *diag, double c, const heml_real *b, heml_real *x, double rtol, int coarse)
{
    int i, err, n3 = 3 * m->node_count;
    double s = 0.0;
    if (!m->dev_probe || !(c > 0)) return HEML__NEGATIVE_CURVATURE;
    for (i = 0; i < m->material_count; i++) {
        double sp = m->mats[i].prony_count ? (double)m->prony_s[i] : 1.0;
        if (i == 0) s = sp;
        else if (sp != s) return HEML__NEGATIVE_CURVATURE;
    }
    if (!(s > 0)) return HEML__NEGATIVE_CURVATURE;
    memset(m->krylov[0], 0, sizeof(heml_real) * (size_t)n3);
    m->kdev = 2;
    heml__nodal_prepare(m, HEML__DIFF, x_lin, m->krylov[0]);
    for (i = 0; i < m->node_count; i++)
        if (!(m->nod_dp[i] >= 0)) break;
    m->kdev = 1;
    err = i < m->node_count ? HEML__NEGATIVE_CURVATURE
                            : ops->solve(m, x_lin, diag, c, b, x, rtol, coarse, m->krylov);
    m->kdev = 0;
    heml__dc_invalidate(m);
    if (err == HEML__NEGATIVE_CURVATURE) memset(x, 0, sizeof(heml_real) * (size_t)n3);
    return err;
}

/* Every linear solve of the library goes through here, to the model's linear solver. */
static int heml__linear_solve(heml_model *m, int kind, const heml_real *x_lin, const heml_real *diag, double c,
                              const heml_real *b, heml_real *x, double rtol, int coarse)
{
    const heml__linear_solver_ops *ops = heml__linear_solvers + m->linear_solver;
    int err;
    m->step_solves++;
    if (coarse == HEML__COARSE_STEP && m->agg_count) m->stats.coarse_solves++;
    heml__dc_invalidate(m); /* (x_lin's contents may be new: the stiffness cache refills) */
    if (kind == HEML__PROBE) {
        err = heml__dev_probe(m, ops, x_lin, diag, c, b, x, rtol, coarse);
        if (err != HEML__NEGATIVE_CURVATURE) return err;
        kind = HEML__SPD; /* the full probe decides */
    }
    err = (kind == HEML__INDEFINITE ? ops->solve_indefinite : ops->solve)(m, x_lin, diag, c, b, x, rtol, coarse,
                                                                           m->krylov);
    m->pc_live = 0;
    heml__dc_invalidate(m);
    return err;
}

/* >>integrators ----------------------------------------------------------------------- */

/* The implicit steps' coarse correction (desc.implicit_coarse, SOLVERS): HEML__COARSE_STEP
   or 0. Automatic (0): on once an implicit step's Jacobi-only solves needed
   HEML_COARSE_MIN_ITERATIONS CG iterations each on average (heml_step_ex records it in
   coarse_plain), and from then on: below that the mass term dominates, Jacobi alone
   converges in a few dozen iterations and the coarse correction's cost per iteration (two
   triangular solves of 6 A unknowns and a pass over the nodes) and its factorisation
   (once per dt) do not pay back (measured: SOLVERS). */
#ifndef HEML_COARSE_MIN_ITERATIONS
#define HEML_COARSE_MIN_ITERATIONS 20
#endif
static int heml__step_coarse(const heml_model *m)
{
    if (!m->agg_count || m->implicit_coarse < 0) return 0;
    return m->implicit_coarse > 0 || m->coarse_plain >= HEML_COARSE_MIN_ITERATIONS ? HEML__COARSE_STEP : 0;
}

/* Working copies (u0, v0) of displacements and velocities with pinned axes moved to their
   targets over this step: v = (target - u) / dt, u = target. */
static void heml__begin_step(heml_model *m, heml_real dt, heml_real *u0, heml_real *v0)
{
    int i, n3 = 3 * m->node_count;
    heml_real inv_dt = 1 / dt;
    for (i = 0; i < n3; i++) {
        heml_real pin = m->pin_mask[i], jump = m->target[i] - m->disp[i];
        u0[i] = m->disp[i] + pin * jump;
        v0[i] = pin ? jump * inv_dt : m->vel[i] * (m->free_mask[i] > 0);
    }
}

/* pos = rest + u */
static void heml__update_positions(heml_model *m)
{
    int i, n3 = 3 * m->node_count;
    for (i = 0; i < n3; i++) m->pos[i] = m->rest[i] + m->disp[i];
}

/* Commits displacements u and velocities v (NULL: zero) and the Prony state being built. */
static void heml__commit(heml_model *m, const heml_real *u, const heml_real *v)
{
    size_t n3 = 3 * (size_t)m->node_count;
    heml__dc_invalidate(m);
    memcpy(m->disp, u, sizeof(heml_real) * n3);
    heml__update_positions(m);
    if (v) memcpy(m->vel, v, sizeof(heml_real) * n3);
    else memset(m->vel, 0, sizeof(heml_real) * n3);
    if (m->has_prony) {
        heml_real *q = m->prony_q;
        m->prony_q = m->prony_q_next;
        m->prony_q_next = q;
    }
}

/* The divergence check of the semi-explicit step, on its start state (u0, v0) and forces f
   at u0 (no extra force pass). It tracks the energy of the free degrees of freedom,
       H = kinetic + Phi,   Phi = - sum over steps of (F_n-1 + F_n) / 2 . (u_n - u_n-1)
   (F = f + f_ext + M g on the free degrees of freedom: the trapezoidal potential of every
   force, exact for linear forces), from a reference state (the first semi-explicit step
   after creation, heml_set_* of the state, a change of the pinned axes, a static solve or
   an implicit step), where
   H = H0. A stable run keeps H near H0 (damping and Prony lower it); an unstable one
   grows it exponentially. The step fails when H - H0 exceeds twice the energy the body
   was given: the kinetic and elastic energy at the reference state plus the magnitudes of
   the work of the loads and of the pinned axes' moves since (a sum of absolute values, so
   the bound only grows). Returns 1 when diverged; the first call costs one energy pass;
   user laws without an energy callback are not checked. */
#ifndef HEML__DIV_FACTOR
#define HEML__DIV_FACTOR 2.0 /* energy growth allowed, times the energy the body was given */
#endif
static int heml__diverged(heml_model *m, const heml_real *u0, const heml_real *v0, const heml_real *f)
{
    int i, r, n = m->node_count, n3 = 3 * n;
    double K = 0.0, dphi = 0.0, budget = 0.0, noise = 0.0, eps = HEML__FLOAT ? FLT_EPSILON : DBL_EPSILON;
    for (i = 0; i < n3; i++)
        if (m->free_mask[i] > 0) K += 0.5 * (double)m->mass[i / 3] * (double)v0[i] * (double)v0[i];
    if (!m->div_valid || m->div_pin_version != m->pin_version) {
        double W = heml__pass_run(m, HEML__ENERGY, u0, NULL, NULL, 0, HEML_STRESS_PK1);
        m->div_valid = 1;
        m->div_pin_version = m->pin_version;
        m->div_H0 = K;
        m->div_scale = heml__finite(W) ? K + fabs(W) : NAN;
        m->div_phi = 0.0;
        memcpy(m->div_u, u0, sizeof(heml_real) * (size_t)n3);
        memcpy(m->div_f, f, sizeof(heml_real) * (size_t)n3);
        return 0;
    }
    if (!heml__finite(m->div_scale)) return 0;
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            double du = (double)u0[j] - (double)m->div_u[j];
            double load = (double)m->ext[j] + (double)m->mass[i] * (double)m->gravity[r];
            double favg = 0.5 * ((double)f[j] + (double)m->div_f[j]);
            if (m->free_mask[j] > 0) {
                dphi -= (favg + load) * du;
                budget += fabs(load * du);
                noise += fabs(favg * du) + fabs(load * du);
            } else {
                budget += fabs(favg * du); /* the work of a driven axis */
            }
        }
    m->div_phi += dphi;
    m->div_scale += budget + 64.0 * eps * noise;
    if (!(K + m->div_phi - m->div_H0 <= HEML__DIV_FACTOR * m->div_scale)) return 1;
    memcpy(m->div_u, u0, sizeof(heml_real) * (size_t)n3);
    memcpy(m->div_f, f, sizeof(heml_real) * (size_t)n3);
    return 0;
}

/* eq. 32: v1 = v0 + dt a(u0, v0), u1 = u0 + dt v1; a = (f + f_ext)/m + g - alpha v0.
   HEML_ERR_DIVERGED when heml__diverged flags the start state, or when the result's
   kinetic energy exceeds twice the energy the body was given (heml__diverged's scale
   plus the loads' work over this step; the elastic energy is never negative, so no stable
   motion gets there): an overshoot is caught before it is accepted. */
static int heml__semi_explicit(heml_model *m, heml_real dt, const heml_real *u0, const heml_real *v0,
                               heml_real *u1, heml_real *v1)
{
    int i, r, n = m->node_count;
    heml_real *f = m->work_f, alpha = m->mass_damping;
    double K1 = 0.0, work = 0.0;
    heml__forces(m, u0, f, 1);
    if (heml__all_finite(f, 3 * (size_t)n) && heml__diverged(m, u0, v0, f)) return HEML_ERR_DIVERGED;
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            heml_real fm = m->free_mask[j];
            heml_real a = (f[j] + m->ext[j]) * m->inv_mass[i] + m->gravity[r] - alpha * v0[j];
            v1[j] = v0[j] + fm * dt * a;
            u1[j] = u0[j] + fm * dt * v1[j];
            if (fm > 0) {
                K1 += 0.5 * (double)m->mass[i] * (double)v1[j] * (double)v1[j];
                work += fabs(((double)m->ext[j] + (double)m->mass[i] * (double)m->gravity[r]) *
                             ((double)u1[j] - (double)u0[j]));
            }
        }
    /* the candidate's kinetic energy cannot exceed the energy the body was given */
    if (heml__finite(m->div_scale) && !(K1 <= HEML__DIV_FACTOR * (m->div_scale + work))) return HEML_ERR_DIVERGED;
    return HEML_OK;
}

/* The linearised implicit step (HEML_IMPLICIT_EULER_LINEARIZED): one Newton iteration of
   backward Euler from du = u1 - u0 = 0,
       (M (1 + dt alpha) - dt^2 df/du(u0)) du = dt^2 R,
       R = f(u0) + f_ext + M g + M v0 / dt,
   the Baraff-Witkin step: no line search, no check of the nonlinear equations. The linear
   solve is CG, or MINRES when CG meets negative curvature; one that does not reach
   cg_tolerance in cg_max_iterations fails the step (HEML_ERR_NO_CONVERGENCE). */
static int heml__implicit_linearized(heml_model *m, heml_real dt, const heml_real *u0, const heml_real *v0,
                                     heml_real *u1, heml_real *v1)
{
    int i, r, err, coarse, n = m->node_count, n3 = 3 * n;
    heml_real *f = m->work_f, *dmass = m->lin_dmass, *du = m->lin_du, *rhs = m->lin_rhs;
    heml_real alpha = m->mass_damping;
    double dt2 = (double)dt * dt;
    for (i = 0; i < n3; i++) dmass[i] = (heml_real)((1.0 + (double)dt * alpha) * (double)m->mass[i / 3]);
    heml__forces(m, u0, f, 1);
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            double mi = (double)m->mass[i];
            double R = (double)f[j] + (double)m->ext[j] + mi * (double)m->gravity[r] + mi * (double)v0[j] / (double)dt;
            rhs[j] = (heml_real)(dt2 * R) * m->free_mask[j];
            du[j] = dt * (v0[j] + m->dv_prev[j]);
        }
    if (!heml__all_finite(rhs, (size_t)n3)) return HEML_ERR_NOT_FINITE;
    coarse = heml__step_coarse(m);
    err = heml__linear_solve(m, HEML__SPD, u0, dmass, dt2, rhs, du, (double)m->cg_tolerance, coarse);
    if (err == HEML__NEGATIVE_CURVATURE)
        err = heml__linear_solve(m, HEML__INDEFINITE, u0, dmass, dt2, rhs, du, (double)m->cg_tolerance, coarse);
    if (err) return err;
    m->stats.newton_iterations = 1;
    for (i = 0; i < n3; i++) {
        heml_real fm = m->free_mask[i];
        u1[i] = u0[i] + du[i] * fm;
        v1[i] = fm > 0 ? du[i] / dt : v0[i];
        m->dv_prev[i] = (v1[i] - v0[i]) * fm;
    }
    return HEML_OK;
}

/* >>minimisation: Newton on an energy (the static solve and implicit Euler) ------------ */

/* The objective Phi(u) over the free degrees of freedom, minimised by heml__newton:
       static:   Phi = W(u) - load . u
       implicit: Phi = W(u) - load . u + sum m |u - u0 - dt v0|^2 / (2 dt^2)
                                       + alpha sum m |u - u0|^2 / (2 dt)
   (the incremental potential of backward Euler with mass damping: its stationarity is
   M (u - u0 - dt v0) / dt^2 + alpha M (u - u0) / dt = f(u) + load). -grad Phi is the
   residual R = f + load - M (u - u0 - dt v0) / dt^2 - alpha M (u - u0) / dt and its
   Hessian D - df/du with D = M (1 + dt alpha) / dt^2 (0 static). */
typedef struct heml__objective {
    const heml_real *load;    /* 3n: f_ext + M g on the free degrees of freedom, scaled */
    const heml_real *u0, *v0; /* implicit: the step's start; NULL: static */
    const heml_real *dmass;   /* implicit: D per degree of freedom; NULL: static */
    const heml_real *warm;    /* implicit: the first Krylov solve's initial guess, or NULL */
    double dt, alpha, tol;
    int max_iterations, coarse, energy_search, inverted_start;
    int check_minimum; /* static: an answer must be a minimum (heml__saddle_escape) */
    int leave_saddles; /* ... and a saddle is left for a minimum (else HEML_ERR_UNSTABLE) */
} heml__objective;

/* One evaluation of the objective at u: f, R, |R|, the reference scale max(|load|, |f|
   (all degrees of freedom, reactions included), |inertia|), Phi, its parts and its
   round-off size. */
typedef struct heml__point {
    double res, scale, energy, work, kinetic, potential, noise;
} heml__point;

static void heml__eval(heml_model *m, const heml__objective *ob, const heml_real *u, heml_real *f, heml_real *R,
                       heml__point *pt)
{
    int i, n3 = 3 * m->node_count;
    double W = heml__pass_run(m, HEML__FORCE_ENERGY, u, NULL, f, 1, HEML_STRESS_PK1), ff, ll, ii = 0.0, kin = 0.0;
    double eps = HEML__FLOAT ? FLT_EPSILON : DBL_EPSILON;
    for (i = 0; i < n3; i++) {
        double Rj = (double)f[i] + (double)ob->load[i];
        if (ob->u0 && m->free_mask[i] > 0) {
            double mi = (double)m->mass[i / 3], d = (double)u[i] - (double)ob->u0[i];
            double e = d - ob->dt * (double)ob->v0[i];
            double in = mi * e / (ob->dt * ob->dt) + ob->alpha * mi * d / ob->dt;
            Rj -= in;
            ii += in * in;
            kin += 0.5 * mi * (e * e / (ob->dt * ob->dt) + ob->alpha * d * d / ob->dt);
        }
        R[i] = (heml_real)Rj * m->free_mask[i];
    }
    ff = heml__dot(f, f, n3);
    ll = heml__dot(ob->load, ob->load, n3);
    pt->res = sqrt(heml__dot(R, R, n3));
    pt->scale = sqrt(ff > ll ? (ff > ii ? ff : ii) : (ll > ii ? ll : ii));
    pt->energy = W;
    pt->work = heml__dot(ob->load, u, n3);
    pt->kinetic = kin;
    pt->potential = W - pt->work + kin;
    pt->noise = 64.0 * eps * (fabs(W) + fabs(pt->work) + kin) + 4.0 * m->energy_noise;
}

/* The round-off level of the residual at u (one pass): per free degree of freedom the
   unit round-off times the size of the terms its force sums, and the force that rounding
   the displacements moves (the stiffness diagonal, plus D of implicit Euler, times one ulp
   of the node's largest displacement component), in quadrature. */
static double heml__round_off_floor(heml_model *m, const heml_real *u, const heml_real *dmass, heml_real *scratch)
{
    int i, r;
    double eps = HEML__FLOAT ? FLT_EPSILON : DBL_EPSILON, sum = 0.0;
    heml__pass_run(m, HEML__ABS, u, NULL, scratch, 0, HEML_STRESS_PK1);
    for (i = 0; i < m->node_count; i++) {
        double umax = 0.0;
        for (r = 0; r < 3; r++)
            if (fabs((double)u[3 * i + r]) > umax) umax = fabs((double)u[3 * i + r]);
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            double a = (double)scratch[j], k = ((double)m->diag[j] + (dmass ? (double)dmass[j] : 0.0)) * umax;
            if (m->free_mask[j] > 0) sum += eps * eps * (a * a + k * k);
        }
    }
    return sqrt(sum);
}

/* Newton made no more progress at u (current point pt, direction with slope R . delta,
   krylov_ok whether its solve reached its tolerance). Within 100 times the round-off
   floor the answer is accepted (HEML_OK) only when it is converged in energy: the Newton
   correction's energy R . K^-1 R (the slope) is below tol^2 times the energy of the
   answer, max(|load . u|, 2 W, 2 kinetic), i.e. the energy-norm error is below tol;
   otherwise HEML_ERR_ROUND_OFF. Above the floor: HEML_ERR_NO_CONVERGENCE. */
static int heml__stalled(heml_model *m, const heml__objective *ob, const heml_real *u, const heml__point *pt,
                         double slope, int krylov_ok, heml_real *scratch)
{
    double tol = ob->tol, ref = fabs(pt->work);
    if (heml__finite(pt->energy) && 2.0 * fabs(pt->energy) > ref) ref = 2.0 * fabs(pt->energy);
    if (2.0 * pt->kinetic > ref) ref = 2.0 * pt->kinetic;
    if (!(pt->res <= 100.0 * heml__round_off_floor(m, u, ob->dmass, scratch))) return HEML_ERR_NO_CONVERGENCE;
    if (krylov_ok && slope > 0 && slope <= tol * tol * ref) return HEML_OK;
    return HEML_ERR_ROUND_OFF;
}

#define HEML__HALVINGS 12   /* line search: steps down to 2^-12 */
#define HEML__ESCAPES 8     /* saddle escapes per Newton solve */

/* Is the converged point u (pt, residual R) a minimum? A probe solve K x = b (b a fixed
   pseudo-random vector on the free axes) by the Newton solves' preconditioned CG to a
   tight tolerance: CG meets a direction of negative curvature p (p . K p <= 0) where the
   tangent is indefinite, i.e. u is a saddle, an unstable equilibrium that damped dynamics
   would leave (0.3.0 accepted such saddles: a mass-spring cube squashed by half in float,
   success 3e-5 of the energy above the minimum, its tangent with an eigenvalue of
   -0.0027 E). p is then sharpened into a direction of most negative curvature by up to
   HEML__RAYLEIGH steps of a two-vector Rayleigh-Ritz minimisation of v . K v / v . K0 v
   (K0 the small-strain stiffness diagonal, Jacobi-preconditioned gradient); a quotient
   above -1e3 eps counts as flat within round-off (a minimum). At a saddle the state moves
   along -+v (first the sign that does not ascend), |v|max = h_min / 4 halved up to
   HEML__HALVINGS times, to the first point whose objective is lower by more than its
   round-off, and Newton goes on from there. Returns HEML_OK (a minimum, as far as the
   probe sees), 1 (escaped: u, R, pt updated), HEML_ERR_ROUND_OFF (a saddle that no step
   lowers measurably: heml_real cannot tell it from a minimum) or HEML_ERR_NO_CONVERGENCE
   (HEML__ESCAPES escapes already). Scratch: probe_b, probe_x, newton_ut/ft/Rt, krylov. */
#define HEML__RAYLEIGH 40
static int heml__saddle_escape(heml_model *m, const heml__objective *ob, heml_real *u, heml_real *R, heml__point *pt,
                               int *escapes)
{
    heml_real *b = m->probe_b, *ut = m->newton_ut, *ft = m->newton_ft, *Rt = m->newton_Rt;
    heml_real *x = m->probe_x, *v, *kv, *w, *kw, *pinv;
    int i, n3 = 3 * m->node_count, kerr, ls, sgn, it;
    double eps = HEML__FLOAT ? FLT_EPSILON : DBL_EPSILON, rho = 0.0, vmax = 0.0, step, first, norm;
    heml__point tp;
    if (!ob->check_minimum) return HEML_OK;
    for (i = 0; i < n3; i++) {
        unsigned h = (unsigned)i * 2654435761u;
        h ^= h >> 15;
        h *= 2246822519u;
        h ^= h >> 13;
        b[i] = (heml_real)(((double)(h & 0xffffu) / 32768.0 - 1.0) * (double)m->free_mask[i]);
        x[i] = 0;
    }
    kerr = heml__linear_solve(m, HEML__PROBE, u, ob->dmass, 1.0, b, x, HEML__FLOAT ? 1e-5 : 1e-10, ob->coarse);
    if (kerr == HEML_ERR_NOT_FINITE) return kerr;
    if (kerr != HEML__NEGATIVE_CURVATURE) return HEML_OK;
    /* the solve's last direction p and K p, its preconditioner, and two free vectors */
    v = m->krylov[HEML__CG_P], kv = m->krylov[HEML__CG_Q], pinv = m->krylov[HEML__CG_PINV];
    w = m->krylov[HEML__CG_FREE], kw = m->krylov[HEML__CG_FREE + 1];
    for (it = 0; it <= HEML__RAYLEIGH; it++) { /* v . K v / v . K0 v down, in span{v, P (K v - rho K0 v)} */
        double a11 = 0, a12 = 0, a22 = 0, b11 = 0, b12 = 0, b22 = 0, det, mid, mu, cx, cy;
        for (i = 0; i < n3; i++) {
            double dg = (double)m->diag[i] * (double)m->free_mask[i];
            a11 += (double)v[i] * (double)kv[i];
            b11 += (double)v[i] * dg * (double)v[i];
        }
        if (!(b11 > 0) || !heml__finite(a11)) return HEML_OK;
        rho = a11 / b11;
        if (it == HEML__RAYLEIGH) break;
        for (i = 0; i < n3; i++)
            w[i] = (heml_real)((double)pinv[i] * ((double)kv[i] - rho * (double)m->diag[i] * (double)v[i]) *
                               (double)m->free_mask[i]);
        heml__cg_apply(m, ob->dmass, 1.0, w, kw);
        for (i = 0; i < n3; i++) {
            double dg = (double)m->diag[i] * (double)m->free_mask[i];
            a12 += (double)v[i] * (double)kw[i];
            a22 += (double)w[i] * (double)kw[i];
            b12 += (double)v[i] * dg * (double)w[i];
            b22 += (double)w[i] * dg * (double)w[i];
        }
        det = b11 * b22 - b12 * b12;
        if (!(det > 1e-10 * b11 * b22) || !heml__finite(a22)) break; /* w adds no direction */
        /* smallest root of det(A - mu B) = 0 */
        mid = a11 * b22 + a22 * b11 - 2.0 * a12 * b12;
        mu = (mid - sqrt(heml__max_d(mid * mid - 4.0 * det * (a11 * a22 - a12 * a12), 0.0))) / (2.0 * det);
        cx = a12 - mu * b12, cy = -(a11 - mu * b11);
        if (fabs(cx) + fabs(cy) == 0.0) cx = a22 - mu * b22, cy = -(a12 - mu * b12);
        if (fabs(cx) + fabs(cy) == 0.0) break;
        norm = sqrt(cx * cx * b11 + 2.0 * cx * cy * b12 + cy * cy * b22);
        if (!(norm > 0)) break;
        cx /= norm, cy /= norm;
        for (i = 0; i < n3; i++) {
            v[i] = (heml_real)(cx * (double)v[i] + cy * (double)w[i]);
            kv[i] = (heml_real)(cx * (double)kv[i] + cy * (double)kw[i]);
        }
        if (!(mu < rho - 1e-3 * fabs(rho))) break; /* converged enough */
    }
    for (i = 0; i < n3; i++)
        if (m->free_mask[i] > 0 && fabs((double)v[i]) > vmax) vmax = fabs((double)v[i]);
    if (!(vmax > 0) || rho >= -1e3 * eps) return HEML_OK; /* flat within round-off */
    if (!ob->leave_saddles) return HEML_ERR_UNSTABLE;
    if (*escapes >= HEML__ESCAPES) return HEML_ERR_NO_CONVERGENCE;
    first = heml__dot(R, v, n3) >= 0.0 ? 1.0 : -1.0; /* R = -grad: this sign does not ascend */
    for (ls = 0, step = 0.25 * m->h_min / vmax; ls <= HEML__HALVINGS; ls++, step *= 0.5)
        for (sgn = 0; sgn < 2; sgn++) {
            heml_real t = (heml_real)((sgn ? -first : first) * step);
            for (i = 0; i < n3; i++) ut[i] = u[i] + t * v[i] * m->free_mask[i];
            heml__eval(m, ob, ut, ft, Rt, &tp);
            if (!(heml__finite(tp.res) && tp.potential < pt->potential - pt->noise)) {
                m->stats.line_search_cuts++;
                continue;
            }
            ++*escapes;
            *pt = tp;
            memcpy(u, ut, sizeof(heml_real) * (size_t)n3);
            memcpy(R, Rt, sizeof(heml_real) * (size_t)n3);
            return 1;
        }
    return HEML_ERR_ROUND_OFF;
}
#define HEML__STALL 4       /* Newton iterations without progress that end a solve */
#define HEML__SHIFT_MIN 1e-6 /* Levenberg-Marquardt shift after negative curvature, times the */
#define HEML__SHIFT_MAX 1e3  /* small-strain stiffness diagonal: first and largest */

/* Newton minimisation of the objective from u (pinned axes already placed), in place.
   Each iteration solves (D - df/du) delta = R by preconditioned CG to an Eisenstat-Walker
   relative residual (1e-3, then 0.9 (|R_k| / |R_k-1|)^2, never tighter than the
   tolerance needs). Where CG meets negative curvature (the tangent is not positive
   definite: stats.negative_curvature) the solve is repeated with a Levenberg-Marquardt
   shift, shift times the small-strain stiffness diagonal added to the tangent (1e-3,
   raised tenfold until CG meets no negative curvature, up to 1e3, and lowered tenfold
   after each accepted step), so the direction descends and the iteration never steers
   towards a saddle; where even the largest shift fails, the preconditioned residual. A
   capped solve still gives a usable direction. The backtracking line search accepts a step that lowers Phi (Armijo, up to
   its round-off); where Phi is not a potential of the forces (a Prony history in a
   dynamic step, or a user law without an energy callback) a step that lowers |R|.
   Converged when |R| <= tol max(|load|, |f|, |inertia|) and, for the static solve
   (check_minimum), heml__saddle_escape finds no negative curvature. When neither |R| nor Phi made
   progress in HEML__STALL iterations, or the line search found no acceptable step, or
   after max_iterations: heml__stalled decides. Scratch: work_f, newton_*, krylov. */
static int heml__newton(heml_model *m, heml__objective *ob, heml_real *u)
{
    heml_real *f = m->work_f, *R = m->newton_R, *delta = m->newton_delta, *ut = m->newton_ut;
    heml_real *ft = m->newton_ft, *Rt = m->newton_Rt, *reg = m->newton_shift_diag;
    int i, it, n3 = 3 * m->node_count, quiet = 0, escapes = 0, done;
    double best, prev = 0.0, eta = 1e-3, tol = ob->tol, shift = 0.0;
    heml__point pt, tp;
    heml__eval(m, ob, u, f, R, &pt);
    ob->inverted_start = m->stats.inverted;
    best = pt.res;
    for (it = 0;; it++) {
        double step = 1.0, slope;
        int ls, accepted = 0, krylov_ok, kerr, by_energy = ob->energy_search && heml__finite(pt.potential);
        m->stats.residual = (heml_real)(pt.scale > 0 ? pt.res / pt.scale : 0.0);
        if (!heml__finite(pt.res) || !heml__finite(pt.scale)) return HEML_ERR_NOT_FINITE;
        if (pt.res <= tol * pt.scale) {
            done = heml__saddle_escape(m, ob, u, R, &pt, &escapes);
            if (done != 1) return done;
            quiet = 0, best = pt.res, prev = pt.res, shift = 0.0; /* escaped a saddle: go on */
            continue;
        }
        if (it > 0) {
            eta = 0.9 * (pt.res / prev) * (pt.res / prev);
            if (eta > 1e-3) eta = 1e-3;
        }
        if (eta < 0.1 * tol * pt.scale / pt.res) eta = 0.1 * tol * pt.scale / pt.res;
        if (eta > 1e-3) eta = 1e-3;
        for (;;) { /* (D + shift diag K0 - df/du) delta = R: the shift only after negative curvature */
            const heml_real *D = ob->dmass;
            if (shift > 0) {
                for (i = 0; i < n3; i++) reg[i] = (heml_real)((ob->dmass ? (double)ob->dmass[i] : 0.0) + shift * (double)m->diag[i]);
                D = reg;
            }
            for (i = 0; i < n3; i++) delta[i] = it == 0 && ob->warm ? ob->warm[i] * m->free_mask[i] : 0;
            kerr = heml__linear_solve(m, HEML__SPD, u, D, 1.0, R, delta, eta, ob->coarse);
            if (kerr != HEML__NEGATIVE_CURVATURE || shift >= HEML__SHIFT_MAX) break;
            shift = shift > 0 ? 10.0 * shift : HEML__SHIFT_MIN;
        }
        if (kerr == HEML_ERR_NOT_FINITE) return kerr;
        krylov_ok = kerr == HEML_OK && shift == 0.0;
        slope = heml__dot(R, delta, n3);
        if (!(slope > 0.0)) { /* still negative curvature, or a warm start that ascends */
            const heml_real *pinv = m->krylov[HEML__CG_PINV];
            for (i = 0; i < n3; i++) delta[i] = pinv[i] * R[i];
            slope = heml__dot(R, delta, n3);
            krylov_ok = 0;
        }
        if (it >= ob->max_iterations || quiet >= HEML__STALL) {
            done = heml__stalled(m, ob, u, &pt, slope, krylov_ok, ft);
            if (done == HEML_OK) done = heml__saddle_escape(m, ob, u, R, &pt, &escapes);
            if (done != 1 || it >= ob->max_iterations) return done == 1 ? HEML_ERR_NO_CONVERGENCE : done;
            quiet = 0, best = pt.res, prev = pt.res, shift = 0.0;
            continue;
        }
        m->stats.newton_iterations++;
        for (ls = 0; ls <= HEML__HALVINGS && !accepted; ls++, step *= 0.5) {
            heml_real t = (heml_real)step;
            for (i = 0; i < n3; i++) ut[i] = u[i] + t * delta[i];
            heml__eval(m, ob, ut, ft, Rt, &tp);
            if (!heml__finite(tp.res)) {
                m->stats.line_search_cuts++;
                continue;
            }
            accepted = by_energy ? tp.potential - pt.potential <= -1e-4 * step * slope + pt.noise
                                 : tp.res <= (1.0 - 1e-4 * step) * pt.res;
            m->stats.line_search_cuts += !accepted;
        }
        if (!accepted) {
            done = heml__stalled(m, ob, u, &pt, slope, krylov_ok, ft);
            if (done == HEML_OK) done = heml__saddle_escape(m, ob, u, R, &pt, &escapes);
            if (done != 1) return done;
            quiet = 0, best = pt.res, prev = pt.res, shift = 0.0;
            continue;
        }
        shift = shift > HEML__SHIFT_MIN ? 0.1 * shift : 0.0;
        quiet = tp.res < 0.9 * best || tp.potential < pt.potential - pt.noise ? 0 : quiet + 1;
        if (tp.res < best) best = tp.res;
        prev = pt.res;
        pt = tp;
        memcpy(u, ut, sizeof(heml_real) * (size_t)n3);
        memcpy(R, Rt, sizeof(heml_real) * (size_t)n3);
    }
}

/* eps(heml_real) max|u| <= precision_limit h_min: the rounding of the state cannot fake
   strains above precision_limit (0 disables the check). */
static int heml__precision_ok(const heml_model *m, const heml_real *u)
{
    double umax = 0.0, eps = HEML__FLOAT ? FLT_EPSILON : DBL_EPSILON;
    int i, n3 = 3 * m->node_count;
    if (!(m->precision_limit > 0)) return 1;
    for (i = 0; i < n3; i++)
        if (fabs((double)u[i]) > umax) umax = fabs((double)u[i]);
    return eps * umax <= (double)m->precision_limit * m->h_min;
}

/* The incremental potential's minimisation shared by implicit Euler and BDF2: u1 minimises
       W(u) - load . u + sum m |u - ubar - h vbar|^2 / (2 h^2) + alpha sum m |u - ubar|^2 / (2 h)
   (heml__objective with u0 = ubar, v0 = vbar, dt = h) by heml__newton to newton_tolerance in
   at most newton_iterations iterations, from u1 = start with the first Krylov solve
   warm-started at dt (vstart + the last step's dv); then v1 = (u1 - ubar) / h on the free
   axes (vbar on the pinned ones). Implicit Euler: h = dt, ubar = start = u0, vbar = vstart
   = v0; BDF2: h = 2 dt / 3, ubar = (4 u0 - u_n-1) / 3, vbar likewise, start = u0. Fails
   (state kept) with HEML_ERR_NO_CONVERGENCE / HEML_ERR_ROUND_OFF when Newton does not get
   there, HEML_ERR_INVERTED when the answer has more inverted tetrahedra than its start and
   allow_inversion is 0. */
static int heml__incremental(heml_model *m, heml_real h, const heml_real *ubar, const heml_real *vbar,
                             heml_real dt, const heml_real *start, const heml_real *vstart, heml_real *u1,
                             heml_real *v1)
{
    int i, r, err, n = m->node_count, n3 = 3 * n;
    heml_real *dmass = m->implicit_dmass, *load = m->objective_load, *warm = m->implicit_warm;
    heml__objective ob;
    double cm = (1.0 + (double)h * (double)m->mass_damping) / ((double)h * (double)h);
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            int j = 3 * i + r;
            dmass[j] = (heml_real)(cm * (double)m->mass[i]);
            load[j] = (m->ext[j] + m->mass[i] * m->gravity[r]) * m->free_mask[j];
            warm[j] = dt * (vstart[j] + m->dv_prev[j]);
        }
    memset(&ob, 0, sizeof ob);
    ob.load = load;
    ob.u0 = ubar;
    ob.v0 = vbar;
    ob.dmass = dmass;
    ob.warm = warm;
    ob.dt = (double)h;
    ob.alpha = (double)m->mass_damping;
    ob.tol = (double)m->newton_tolerance;
    ob.max_iterations = m->newton_iterations;
    ob.energy_search = !m->has_prony; /* a Prony history's force has no potential */
    ob.coarse = heml__step_coarse(m);
    memcpy(u1, start, sizeof(heml_real) * (size_t)n3);
    err = heml__newton(m, &ob, u1);
    if (err) return err;
    if (!m->allow_inversion && m->stats.inverted > ob.inverted_start) return HEML_ERR_INVERTED;
    for (i = 0; i < n3; i++) {
        heml_real fm = m->free_mask[i];
        v1[i] = fm > 0 ? (u1[i] - ubar[i]) / h : vbar[i];
        m->dv_prev[i] = (v1[i] - vstart[i]) * fm;
    }
    return HEML_OK;
}

/* Backward Euler (HEML_IMPLICIT_EULER): heml__incremental with h = dt from (u0, v0). */
static int heml__implicit(heml_model *m, heml_real dt, const heml_real *u0, const heml_real *v0,
                          heml_real *u1, heml_real *v1)
{
    return heml__incremental(m, dt, u0, v0, dt, u0, v0, u1, v1);
}

/* BDF2 (HEML_BDF2): u_n+1 - 4/3 u_n + 1/3 u_n-1 = beta v_n+1 and the same for v with the
   acceleration, beta = 2 dt / 3, is the stationarity of the incremental potential of
   heml__incremental with (h, ubar, vbar) = (beta, (4 u_n - u_n-1) / 3, (4 v_n - v_n-1) / 3):
   one Newton minimisation, the same line search and acceptance test as implicit Euler.
   Newton starts from u_n (ubar is an extrapolation, which may invert what u_n does not).
   Without a valid history of the same dt (the first step, or after a restart: see
   heml__history_reset) the step is one implicit Euler step. Pinned axes: ubar = u0 (their
   target) and vbar = v0 (their velocity over the step), as implicit Euler. */
static int heml__bdf2(heml_model *m, heml_real dt, const heml_real *u0, const heml_real *v0, heml_real *u1,
                      heml_real *v1)
{
    heml_real *ubar = m->bdf2_ubar, *vbar = m->bdf2_vbar;
    heml_real beta = (heml_real)(2.0 * (double)dt / 3.0);
    int i, n3 = 3 * m->node_count;
    if (!m->hist_valid || m->hist_dt != dt) return heml__implicit(m, dt, u0, v0, u1, v1);
    for (i = 0; i < n3; i++) {
        int free_axis = m->free_mask[i] > 0;
        ubar[i] = free_axis ? (heml_real)((4.0 * (double)u0[i] - (double)m->hist_u[i]) / 3.0) : u0[i];
        vbar[i] = free_axis ? (heml_real)((4.0 * (double)v0[i] - (double)m->hist_v[i]) / 3.0) : v0[i];
    }
    return heml__incremental(m, beta, ubar, vbar, dt, u0, v0, u1, v1);
}

/* Forgets BDF2's history: its next step is an implicit Euler step. Called wherever the state
   or the constraints change other than by a BDF2 step (heml_set_positions, displacements,
   velocities, every pin, release or drive of a node, a static solve, a step of another
   integrator, a failed step). */
static void heml__history_reset(heml_model *m)
{
    m->hist_valid = 0;
    heml__dc_invalidate(m); /* (every change of the state or the pins passes here) */
}

/* >>integrators-table: one row per heml_integrator, indexed by it (see HOW TO EXTEND).
   `step` advances the working copies: from the start (u0, v0: pinned axes already at their
   targets, see heml__begin_step) to a candidate (u1, v1) in dt seconds, leaving the model's
   state alone (heml_step_ex commits the candidate, or keeps the state on an error).
   `is_explicit`: the step needs no force differential (so a user law without second
   derivatives may use it) and keeps the semi-explicit divergence check's reference (an
   implicit step resets it). `uses_history`: after a successful step heml_step_ex keeps its
   start (u0, v0) and dt as the history (hist_u, hist_v, hist_dt) that the next step reads;
   any other step, and any failed one, resets the history. */
typedef int (*heml__step_fn)(heml_model *m, heml_real dt, const heml_real *u0, const heml_real *v0,
                             heml_real *u1, heml_real *v1);
typedef struct heml__integrator_ops {
    const char *name;
    heml__step_fn step;
    int is_explicit;
    int uses_history; /* the step reads the last step's start (hist_u, hist_v): heml_step_ex keeps it */
} heml__integrator_ops;

static const heml__integrator_ops heml__integrators[] = {
    {"semi-explicit Euler", heml__semi_explicit, 1, 0},
    {"implicit Euler", heml__implicit, 0, 0},
    {"linearised implicit Euler", heml__implicit_linearized, 0, 0},
    {"BDF2", heml__bdf2, 0, 1},
};
/* an integrator added to heml_integrator without its row (or the reverse) fails to compile */
typedef char heml__integrators_has_a_row_per_integrator
    [sizeof heml__integrators / sizeof heml__integrators[0] == HEML_INTEGRATOR_COUNT ? 1 : -1];

HEMLDEF int heml_step_ex(heml_model *m, heml_real dt, heml_integrator integrator)
{
    const heml__integrator_ops *ops;
    heml_real *u0, *v0, *u1, *v1;
    size_t n3;
    int err = HEML_OK;
    if (!m) return HEML_ERR_ARG;
    if (!(heml__finite((double)dt) && dt > 0)) return HEML_ERR_TIME_STEP;
    if ((unsigned)integrator >= HEML_INTEGRATOR_COUNT) return HEML_ERR_INTEGRATOR;
    ops = heml__integrators + integrator;
    if (!ops->is_explicit && m->has_user_without_second) return HEML_ERR_NO_SECOND_DERIVATIVES;
    n3 = 3 * (size_t)m->node_count;
    u0 = m->step_u0;
    v0 = m->step_v0;
    u1 = m->step_u1;
    v1 = m->step_v1;
    memset(&m->stats, 0, sizeof m->stats);
    heml__prony_coefficients(m, (double)dt);
    heml__begin_step(m, dt, u0, v0);
    if (!heml__precision_ok(m, u0)) {
        heml__history_reset(m);
        return HEML_ERR_PRECISION;
    }
    m->step_solves = 0;
    err = ops->step(m, dt, u0, v0, u1, v1);
    if (!m->stats.coarse_solves && m->step_solves > 0) /* Jacobi alone: its cost per solve (heml__step_coarse) */
        m->coarse_plain = m->stats.cg_iterations / m->step_solves;
    if (!err && (!heml__all_finite(u1, n3) || !heml__all_finite(v1, n3))) err = HEML_ERR_NOT_FINITE;
    if (err) {
        memset(m->dv_prev, 0, sizeof(heml_real) * n3);
        heml__history_reset(m);
        return err;
    }
    if (ops->uses_history) {
        memcpy(m->hist_u, u0, sizeof(heml_real) * n3);
        memcpy(m->hist_v, v0, sizeof(heml_real) * n3);
        m->hist_dt = dt;
        m->hist_valid = 1;
    } else {
        heml__history_reset(m);
    }
    heml__commit(m, u1, v1);
    if (!ops->is_explicit) m->div_valid = 0;
    return HEML_OK;
}

HEMLDEF int heml_step(heml_model *m)
{
    if (!m) return HEML_ERR_ARG;
    return heml_step_ex(m, m->time_step, m->integrator);
}

/* >>static ---------------------------------------------------------------------------- */

/* Equilibrium by continuation: loads (gravity, external forces) and the pinned axes' moves
   to their targets are applied with a factor lambda from 0 to 1, first in one increment;
   a failed increment is cut in half (from the last converged state), a successful one
   doubles the next. Each increment starts from a tangent predictor: the pinned axes moved
   by their share and the free ones by the small-strain response to it and to the new
   load, K delta = R(u; load) + df/du (u) dpin (one Krylov solve), so that the boundary
   layer moves with the pins instead of being crushed by them; Newton (heml__newton, Phi =
   W - load . u) takes it from there. An increment is accepted when Newton converged and
   (allow_inversion = 0) no more tetrahedra are inverted than at the start; where the
   predictor inverts more, Newton starts from the pinned axes' move alone. Stops: max_increments attempts, an
   increment below min_increment, a round-off stall (HEML_ERR_ROUND_OFF: a smaller load
   would not help), or a load whose norm is not finite (HEML_ERR_NOT_FINITE). Scratch:
   static_*, objective_load and work_f here, Newton's (work_f, newton_*, krylov). */
HEMLDEF int heml_solve_static(heml_model *m)
{
    heml_real *u, *saved, *dpin, *q, *load, *rhs, *pred, *f;
    int i, r, n3, err = HEML_OK, attempts = 0, inverted_start;
    double lambda = 0.0, increment = 1.0;
    heml__objective ob;
    if (!m) return HEML_ERR_ARG;
    if (m->has_user_without_second) return HEML_ERR_NO_SECOND_DERIVATIVES;
    n3 = 3 * m->node_count;
    u = m->static_u;
    saved = m->static_saved;
    dpin = m->static_dpin;
    q = m->static_dfdpin;
    f = m->work_f;
    load = m->objective_load;
    rhs = m->static_rhs;
    pred = m->static_pred;
    memset(&m->stats, 0, sizeof m->stats);
    if (!heml__precision_ok(m, m->disp) || !heml__precision_ok(m, m->target)) return HEML_ERR_PRECISION;
    heml__prony_coefficients(m, -1.0);
    memcpy(u, m->disp, sizeof(heml_real) * (size_t)n3);
    heml__forces(m, u, f, 0);
    inverted_start = m->stats.inverted;
    memset(&ob, 0, sizeof ob);
    ob.load = load;
    ob.tol = (double)m->static_tolerance;
    ob.max_iterations = m->static_max_iterations;
    ob.coarse = 1;
    ob.energy_search = 1; /* the relaxed Prony response is s f, of potential s W */
    ob.check_minimum = 1;
    ob.leave_saddles = m->leave_saddles;
    while (lambda < 1.0) {
        double trial = lambda + increment > 1.0 ? 1.0 : lambda + increment, slope;
        heml_real t = (heml_real)trial;
        int kerr;
        if (attempts++ >= m->max_increments) {
            if (!err) err = HEML_ERR_NO_CONVERGENCE;
            break;
        }
        memcpy(saved, u, sizeof(heml_real) * (size_t)n3);
        for (i = 0; i < m->node_count; i++)
            for (r = 0; r < 3; r++) {
                int j = 3 * i + r;
                load[j] = t * (m->ext[j] + m->mass[i] * m->gravity[r]) * m->free_mask[j];
                dpin[j] = m->pin_mask[j] > 0 ? m->disp[j] + t * (m->target[j] - m->disp[j]) - u[j] : 0;
            }
        if (!heml__finite(heml__dot(load, load, n3))) {
            err = HEML_ERR_NOT_FINITE;
            break;
        }
        /* the tangent predictor */
        heml__forces(m, u, f, 0);
        heml__pass_run(m, HEML__DIFF, u, dpin, q, 0, HEML_STRESS_PK1);
        for (i = 0; i < n3; i++) {
            rhs[i] = (f[i] + load[i] + q[i]) * m->free_mask[i];
            pred[i] = 0;
        }
        kerr = heml__linear_solve(m, HEML__SPD, u, NULL, 1.0, rhs, pred, 1e-3, 1);
        if (kerr == HEML_ERR_NOT_FINITE) {
            err = kerr;
            break;
        }
        slope = heml__dot(rhs, pred, n3);
        if (!(slope > 0 && heml__finite(slope))) memset(pred, 0, sizeof(heml_real) * (size_t)n3);
        for (i = 0; i < n3; i++) u[i] += dpin[i] + pred[i] * m->free_mask[i];
        heml__forces(m, u, f, 0);
        if (!m->allow_inversion && m->stats.inverted > inverted_start) /* no prediction then */
            for (i = 0; i < n3; i++) u[i] = saved[i] + dpin[i];
        err = heml__newton(m, &ob, u);
        if ((!err || err == HEML_ERR_UNSTABLE) && !m->allow_inversion && m->stats.inverted > inverted_start)
            err = HEML_ERR_INVERTED; /* (a saddle that is also inverted: the inversion says more) */
        if (err == HEML_OK) {
            lambda = trial;
            increment *= 2.0;
            m->stats.increments++;
        } else {
            memcpy(u, saved, sizeof(heml_real) * (size_t)n3);
            increment *= 0.5;
            m->stats.increment_cuts++;
            if (err == HEML_ERR_ROUND_OFF || err == HEML_ERR_NOT_FINITE || err == HEML_ERR_UNSTABLE ||
                increment < (double)m->min_increment)
                break;
        }
    }
    if (lambda < 1.0) return err;
    if (!heml__all_finite(u, (size_t)n3)) return HEML_ERR_NOT_FINITE;
    if (!heml__precision_ok(m, u)) return HEML_ERR_PRECISION;
    if (m->has_prony) { /* the Prony state of the last pass at u: make sure it is at u */
        heml__forces(m, u, m->work_f, 1);
    }
    heml__commit(m, u, NULL);
    m->div_valid = 0;
    heml__history_reset(m);
    memset(m->dv_prev, 0, sizeof(heml_real) * (size_t)n3);
    return HEML_OK;
}

/* >>boundary-conditions --------------------------------------------------------------- */

static int heml__check_node(const heml_model *m, int i)
{
    if (!m) return HEML_ERR_ARG;
    if (i < 0 || i >= m->node_count) return HEML_ERR_NODE_RANGE;
    return HEML_OK;
}

static int heml__vec3_finite(const heml_real *v)
{
    return v && heml__finite((double)v[0]) && heml__finite((double)v[1]) && heml__finite((double)v[2]);
}

HEMLDEF int heml_fix_node(heml_model *m, int i)
{
    int err = heml__check_node(m, i), r;
    if (err) return err;
    m->axes[i] = 7;
    for (r = 0; r < 3; r++) m->target[3 * i + r] = m->disp[3 * i + r];
    heml__set_masks(m, i);
    heml__history_reset(m);
    return HEML_OK;
}

HEMLDEF int heml_set_displacement_axes(heml_model *m, int i, unsigned axes, const heml_real u[3])
{
    int err = heml__check_node(m, i), r;
    if (err) return err;
    if (axes > 7 || (axes && !heml__vec3_finite(u))) return HEML_ERR_ARG;
    m->axes[i] = (unsigned char)axes;
    for (r = 0; r < 3; r++)
        if ((axes >> r) & 1) m->target[3 * i + r] = u[r];
    heml__set_masks(m, i);
    heml__history_reset(m);
    return HEML_OK;
}

HEMLDEF int heml_set_displacement(heml_model *m, int i, const heml_real u[3])
{
    return heml_set_displacement_axes(m, i, 7u, u);
}

HEMLDEF int heml_release_node(heml_model *m, int i)
{
    return heml_set_displacement_axes(m, i, 0u, NULL);
}

HEMLDEF int heml_node_pinned(const heml_model *m, int i)
{
    int err = heml__check_node(m, i);
    return err ? err : (int)m->axes[i];
}

HEMLDEF int heml_set_external_force(heml_model *m, int i, const heml_real f[3])
{
    int err = heml__check_node(m, i), r;
    if (err) return err;
    if (!heml__vec3_finite(f)) return HEML_ERR_ARG;
    for (r = 0; r < 3; r++) m->ext[3 * i + r] = f[r];
    return HEML_OK;
}

HEMLDEF int heml_set_anchors(heml_model *m, int count, const int *nodes, const heml_real *stiffness,
                             const heml_real *targets)
{
    int a;
    if (!m || count < 0 || (count > 0 && (!nodes || !stiffness || !targets))) return HEML_ERR_ARG;
    for (a = 0; a < count; a++) {
        if (nodes[a] < 0 || nodes[a] >= m->node_count) return HEML_ERR_NODE_RANGE;
        if (!(heml__finite((double)stiffness[a]) && stiffness[a] >= 0) || !heml__vec3_finite(targets + 3 * a))
            return HEML_ERR_ARG;
    }
    m->anchor_count = count;
    m->anchor_nodes = count ? nodes : NULL;
    m->anchor_k = count ? stiffness : NULL;
    m->anchor_target = count ? targets : NULL;
    m->coarse_version = m->coarse_k_version = m->coarse_step_version = m->pin_version - 1; /* the coarse spaces hold the anchors' k */
    return HEML_OK;
}

HEMLDEF void heml_clear_external_forces(heml_model *m)
{
    if (m) memset(m->ext, 0, sizeof(heml_real) * 3 * (size_t)m->node_count);
}

HEMLDEF int heml_set_gravity(heml_model *m, const heml_real g[3])
{
    int r;
    if (!m || !heml__vec3_finite(g)) return HEML_ERR_ARG;
    for (r = 0; r < 3; r++) m->gravity[r] = g[r];
    return HEML_OK;
}

HEMLDEF int heml_set_mass_damping(heml_model *m, heml_real alpha)
{
    if (!m) return HEML_ERR_ARG;
    if (!(heml__finite((double)alpha) && alpha >= 0)) return HEML_ERR_DAMPING;
    m->mass_damping = alpha;
    return HEML_OK;
}

HEMLDEF int heml_set_solver(heml_model *m, heml_real tolerance, int max_iterations)
{
    if (!m) return HEML_ERR_ARG;
    if (!(heml__finite((double)tolerance) && tolerance > 0) || max_iterations < 1) return HEML_ERR_SOLVER;
    m->cg_tolerance = tolerance;
    m->cg_max_iterations = max_iterations;
    return HEML_OK;
}

HEMLDEF int heml_set_newton_iterations(heml_model *m, int iterations)
{
    if (!m) return HEML_ERR_ARG;
    if (iterations < 1) return HEML_ERR_SOLVER;
    m->newton_iterations = iterations;
    return HEML_OK;
}

HEMLDEF int heml_set_inversion_threshold(heml_model *m, heml_real J0)
{
    if (!m) return HEML_ERR_ARG;
    if (!(heml__finite((double)J0) && J0 > 0 && J0 < 1)) return HEML_ERR_THRESHOLD;
    m->J0 = J0;
    m->jm1_0 = (heml_real)((double)J0 - 1.0);
    heml__dc_invalidate(m);
    return HEML_OK;
}

HEMLDEF void heml_reset_viscous_state(heml_model *m)
{
    if (m) heml__dc_invalidate(m);
    if (m && m->prony_reals) {
        memset(m->prony_q, 0, sizeof(heml_real) * m->prony_reals);
        memset(m->prony_q_next, 0, sizeof(heml_real) * m->prony_reals);
    }
}

/* >>state ----------------------------------------------------------------------------- */

HEMLDEF int heml_node_count(const heml_model *m) { return m ? m->node_count : 0; }
HEMLDEF int heml_tet_count(const heml_model *m) { return m ? m->tet_count : 0; }
HEMLDEF const heml_real *heml_positions(const heml_model *m) { return m ? m->pos : NULL; }
HEMLDEF const heml_real *heml_displacements(const heml_model *m) { return m ? m->disp : NULL; }
HEMLDEF const heml_real *heml_velocities(const heml_model *m) { return m ? m->vel : NULL; }
HEMLDEF const heml_real *heml_rest_positions(const heml_model *m) { return m ? m->rest : NULL; }
HEMLDEF const heml_real *heml_masses(const heml_model *m) { return m ? m->mass : NULL; }
HEMLDEF const heml_stats *heml_last_stats(const heml_model *m) { return m ? &m->stats : NULL; }
HEMLDEF size_t heml_memory_bytes(const heml_model *m) { return m ? m->block_bytes : 0; }

HEMLDEF int heml_set_positions(heml_model *m, const heml_real *positions)
{
    int i;
    if (!m || !positions) return HEML_ERR_ARG;
    if (!heml__all_finite(positions, 3 * (size_t)m->node_count)) return HEML_ERR_ARG;
    for (i = 0; i < 3 * m->node_count; i++) m->disp[i] = positions[i] - m->rest[i];
    memcpy(m->pos, positions, sizeof(heml_real) * 3 * (size_t)m->node_count);
    m->div_valid = 0;
    heml__history_reset(m);
    return HEML_OK;
}

HEMLDEF int heml_set_displacements(heml_model *m, const heml_real *displacements)
{
    if (!m || !displacements) return HEML_ERR_ARG;
    if (!heml__all_finite(displacements, 3 * (size_t)m->node_count)) return HEML_ERR_ARG;
    memcpy(m->disp, displacements, sizeof(heml_real) * 3 * (size_t)m->node_count);
    heml__update_positions(m);
    m->div_valid = 0;
    heml__history_reset(m);
    return HEML_OK;
}

HEMLDEF int heml_set_velocities(heml_model *m, const heml_real *velocities)
{
    int i;
    if (!m || !velocities) return HEML_ERR_ARG;
    if (!heml__all_finite(velocities, 3 * (size_t)m->node_count)) return HEML_ERR_ARG;
    for (i = 0; i < 3 * m->node_count; i++) m->vel[i] = velocities[i] * (m->mass[i / 3] > 0);
    m->div_valid = 0;
    heml__history_reset(m);
    return HEML_OK;
}

/* >>kernels --------------------------------------------------------------------------- */

HEMLDEF const heml_real *heml_compute_forces(heml_model *m)
{
    if (!m) return NULL;
    heml__prony_coefficients(m, (double)m->time_step);
    heml__forces(m, m->disp, m->force, 0);
    return m->force;
}

HEMLDEF int heml_apply_stiffness(heml_model *m, const heml_real *dx, heml_real *out)
{
    if (!m || !dx || !out) return HEML_ERR_ARG;
    if (m->has_user_without_second) return HEML_ERR_NO_SECOND_DERIVATIVES;
    heml__prony_coefficients(m, (double)m->time_step);
    heml__diff_run(m, m->disp, dx, out);
    return HEML_OK;
}

HEMLDEF int heml_kernel_bytes(const heml_model *m, int kernel, size_t *read, size_t *written)
{
    size_t R = sizeof(heml_real), nodes, stream, prony;
    int i;
    if (!m || !read || !written || kernel < 0 || kernel > 1) return HEML_ERR_ARG;
    nodes = 3 * (size_t)m->node_count * R;
    stream = (size_t)m->slot_count * HEML_KERNEL_BYTES_PER_TET;
    prony = 0;
    for (i = 0; i < m->chunk_count; i++) {
        const heml__mat *mt = m->mats + m->chunk_material[i];
        size_t slots = (size_t)(m->chunk_end[i] - m->chunk_begin[i]) * HEML__W;
        prony += slots * HEML__NQ * (size_t)mt->prony_count * R;
    }
    {   /* the differential: cached blocks read the cache and dx, not u */
        size_t cached = 0, slots_all = (size_t)m->slot_count;
        for (i = 0; i < m->chunk_count && kernel == 1 && m->has_dc; i++)
            if (m->mats[m->chunk_material[i]].dk) {
                size_t slots = (size_t)(m->chunk_end[i] - m->chunk_begin[i]) * HEML__W;
                int rows = HEML__DK_ROWS(m->mats[m->chunk_material[i]].dk);
                cached += slots;
                stream += slots * (size_t)(rows - HEML__NR) * R; /* (the cache instead of the rest constants) */
            }
        *read = stream + prony + nodes * (kernel == 1 ? (cached == slots_all ? 1 : 2) : 1);
    }
    *written = nodes + (kernel == 0 ? prony : 0);
    return HEML_OK;
}

/* >>diagnostics ----------------------------------------------------------------------- */

HEMLDEF int heml_energy(heml_model *m, heml_energies *out)
{
    int i, r, n;
    double kinetic = 0.0, grav = 0.0, ext = 0.0;
    if (!m || !out) return HEML_ERR_ARG;
    n = m->node_count;
    out->elastic = heml__pass_run(m, HEML__ENERGY, m->disp, NULL, NULL, 0, HEML_STRESS_PK1);
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            double v = m->vel[3 * i + r], u = (double)m->disp[3 * i + r];
            kinetic += 0.5 * (double)m->mass[i] * v * v;
            grav -= (double)m->mass[i] * m->gravity[r] * u;
            ext -= (double)m->ext[3 * i + r] * u;
        }
    out->kinetic = kinetic;
    out->gravitational = grav;
    out->external = ext;
    return HEML_OK;
}

HEMLDEF int heml_tet_volume_ratios(const heml_model *m, heml_real *out)
{
    int blk, k;
    if (!m || !out) return HEML_ERR_ARG;
    for (blk = 0; blk < m->block_count; blk++) {
        const int *idx = m->blk_idx + (size_t)blk * 4 * HEML__W;
        const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
        for (k = 0; k < m->blk_valid[blk]; k++) {
            /* J = 1 + tr H + tr cof H + det H, H = du V^-1, in double */
            const heml_real *u0 = m->disp + 3 * idx[k];
            double H[3][3], c0, c1, c2;
            int r, s2, j;
            for (r = 0; r < 3; r++)
                for (s2 = 0; s2 < 3; s2++) {
                    double acc = 0.0;
                    for (j = 0; j < 3; j++)
                        acc += ((double)m->disp[3 * idx[(j + 1) * HEML__W + k] + r] - (double)u0[r]) *
                               (double)R[(3 * j + s2) * HEML__W + k];
                    H[r][s2] = acc;
                }
            c0 = H[1][1] * H[2][2] - H[1][2] * H[2][1];
            c1 = H[1][2] * H[2][0] - H[1][0] * H[2][2];
            c2 = H[1][0] * H[2][1] - H[1][1] * H[2][0];
            out[m->slot_tet[blk * HEML__W + k]] =
                (heml_real)(1.0 + (H[0][0] + H[1][1] + H[2][2]) + (c0 + (H[0][0] * H[2][2] - H[0][2] * H[2][0]) +
                                                                     (H[0][0] * H[1][1] - H[0][1] * H[1][0])) +
                            (H[0][0] * c0 + H[0][1] * c1 + H[0][2] * c2));
        }
    }
    return HEML_OK;
}

HEMLDEF int heml_tet_stresses(heml_model *m, heml_stress_kind kind, heml_real *out)
{
    if (!m || !out || (kind != HEML_STRESS_PK1 && kind != HEML_STRESS_CAUCHY)) return HEML_ERR_ARG;
    heml__prony_coefficients(m, (double)m->time_step);
    return heml__pass_run(m, HEML__STRESS, m->disp, NULL, out, 0, kind) > 0 ? HEML_ERR_INVERTED : HEML_OK;
}

HEMLDEF int heml_tet_stress(heml_model *m, int tet, heml_stress_kind kind, heml_real out[9])
{
    heml__blk b;
    int slot, blk;
    if (!m || !out || (kind != HEML_STRESS_PK1 && kind != HEML_STRESS_CAUCHY)) return HEML_ERR_ARG;
    if (tet < 0 || tet >= m->tet_count) return HEML_ERR_TET_RANGE;
    slot = m->tet_slot[tet];
    blk = slot / HEML__W;
    heml__prony_coefficients(m, (double)m->time_step);
    {
        int c, mi = 0;
        for (c = 0; c < m->chunk_count; c++)
            if (blk >= m->chunk_begin[c] && blk < m->chunk_end[c]) mi = m->chunk_material[c];
        heml__block_forces(m, m->mats + mi, blk, m->disp, &b, 0, 0);
    }
    return heml__lane_stress(m, blk, slot % HEML__W, &b, kind, out) ? HEML_ERR_INVERTED : HEML_OK;
}

HEMLDEF double heml_stable_time_step(const heml_model *m)
{
    double best = INFINITY;
    int c, blk, k;
    if (!m) return 0.0;
    for (c = 0; c < m->chunk_count; c++) {
        const heml__mat *mt = m->mats + m->chunk_material[c];
        double speed = sqrt((mt->small_lambda + 2.0 * mt->small_mu) / mt->density);
        for (blk = m->chunk_begin[c]; blk < m->chunk_end[c]; blk++) {
            const heml_real *R = m->blk_rest + (size_t)blk * HEML__NR * HEML__W;
            for (k = 0; k < m->blk_valid[blk]; k++) {
                /* |grad N_j| = 1 / altitude_j; node 0's gradient is minus the sum */
                double gmax = 0.0, g0[3] = {0, 0, 0}, h, gg;
                int j, r;
                for (j = 0; j < 3; j++) {
                    gg = 0.0;
                    for (r = 0; r < 3; r++) {
                        double g = (double)R[(3 * j + r) * HEML__W + k];
                        gg += g * g;
                        g0[r] += g;
                    }
                    if (gg > gmax) gmax = gg;
                }
                gg = g0[0] * g0[0] + g0[1] * g0[1] + g0[2] * g0[2];
                if (gg > gmax) gmax = gg;
                h = 0.5 / sqrt(gmax);
                if (speed > 0 && h / speed < best) best = h / speed;
            }
        }
    }
    return best;
}

/* >>probes ---------------------------------------------------------------------------- */

struct heml_probe {
    heml_allocator allocator;
    size_t bytes;
    int count, node_count;
    int *nodes;       /* 4 per point: the containing tetrahedron's nodes */
    heml_real *weights; /* 4 per point: their barycentric coordinates */
};

/* Node j of tetrahedron t (description numbering). */
static int heml__tet_node(const heml_model *m, int t, int j)
{
    int slot = m->tet_slot[t];
    return m->blk_idx[(size_t)(slot / HEML__W) * 4 * HEML__W + (size_t)HEML__W * j + slot % HEML__W];
}

/* Barycentric coordinates b of point p in the rest tetrahedron t (double, Cramer's rule). */
static void heml__barycentric(const heml_model *m, int t, const double p[3], double b[4])
{
    double x0[3], e[3][3], d[3], det, c[3][3];
    int j, r, n0 = heml__tet_node(m, t, 0);
    for (r = 0; r < 3; r++) {
        x0[r] = (double)m->rest[3 * n0 + r];
        d[r] = p[r] - x0[r];
    }
    for (j = 0; j < 3; j++) {
        int nj = heml__tet_node(m, t, j + 1);
        for (r = 0; r < 3; r++) e[j][r] = (double)m->rest[3 * nj + r] - x0[r];
    }
    /* rows of the inverse of the matrix whose columns are e[0..2]: cross products / det */
    c[0][0] = e[1][1] * e[2][2] - e[1][2] * e[2][1];
    c[0][1] = e[1][2] * e[2][0] - e[1][0] * e[2][2];
    c[0][2] = e[1][0] * e[2][1] - e[1][1] * e[2][0];
    c[1][0] = e[2][1] * e[0][2] - e[2][2] * e[0][1];
    c[1][1] = e[2][2] * e[0][0] - e[2][0] * e[0][2];
    c[1][2] = e[2][0] * e[0][1] - e[2][1] * e[0][0];
    c[2][0] = e[0][1] * e[1][2] - e[0][2] * e[1][1];
    c[2][1] = e[0][2] * e[1][0] - e[0][0] * e[1][2];
    c[2][2] = e[0][0] * e[1][1] - e[0][1] * e[1][0];
    det = e[0][0] * c[0][0] + e[0][1] * c[0][1] + e[0][2] * c[0][2];
    for (j = 0; j < 3; j++) b[j + 1] = (c[j][0] * d[0] + c[j][1] * d[1] + c[j][2] * d[2]) / det;
    b[0] = 1.0 - b[1] - b[2] - b[3];
}

/* A uniform grid over the rest nodes' bounding box, about one cell per tetrahedron or
   fewer; cell c lists (ascending) the tetrahedra whose bounding box overlaps it, in
   items[start[c] .. start[c + 1] - 1]. Temporary (heml_probe_create). */
typedef struct heml__grid {
    double lo[3], inv[3];
    int n[3];
    int *start, *cursor, *items;
    size_t start_bytes, item_bytes;
} heml__grid;

static int heml__grid_axis(const heml__grid *g, int r, double x)
{
    double f = (x - g->lo[r]) * g->inv[r];
    return f < 0 ? 0 : f >= (double)g->n[r] ? g->n[r] - 1 : (int)f;
}

/* The cell ranges a[r] .. b[r] of tetrahedron t's rest bounding box. */
static void heml__grid_range(const heml_model *m, const heml__grid *g, int t, int a[3], int b[3])
{
    int j, r;
    for (r = 0; r < 3; r++) {
        double lo = INFINITY, hi = -INFINITY;
        for (j = 0; j < 4; j++) {
            double x = (double)m->rest[3 * heml__tet_node(m, t, j) + r];
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
        }
        a[r] = heml__grid_axis(g, r, lo);
        b[r] = heml__grid_axis(g, r, hi);
    }
}

static int heml__grid_build(const heml_model *m, heml__grid *g)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, big = 0.0, vol = 1.0, s;
    int i, r, t, T = m->tet_count, a[3], b[3], x, y, z;
    size_t cells, total = 0;
    for (i = 0; i < m->node_count; i++)
        for (r = 0; r < 3; r++) {
            double v = (double)m->rest[3 * i + r];
            lo[r] = v < lo[r] ? v : lo[r];
            hi[r] = v > hi[r] ? v : hi[r];
        }
    for (r = 0; r < 3; r++) big = hi[r] - lo[r] > big ? hi[r] - lo[r] : big;
    for (r = 0; r < 3; r++) vol *= heml__max_d(hi[r] - lo[r], 1e-3 * big);
    s = cbrt(vol / (double)T);
    for (;;) {
        for (r = 0, cells = 1; r < 3; r++) {
            double k = (hi[r] - lo[r]) / s;
            g->n[r] = k < 1.0 ? 1 : k > 1e6 ? 1000000 : (int)k;
            cells *= (size_t)g->n[r];
        }
        if (cells <= (size_t)T + 1) break;
        s *= 1.25;
    }
    for (r = 0; r < 3; r++) {
        g->lo[r] = lo[r];
        g->inv[r] = hi[r] > lo[r] ? (double)g->n[r] / (hi[r] - lo[r]) : 0.0;
    }
    g->start_bytes = sizeof(int) * (2 * cells + 1);
    g->start = (int *)heml__alloc(&m->allocator, g->start_bytes);
    if (!g->start) return HEML_ERR_ALLOC;
    g->cursor = g->start + cells + 1;
    memset(g->start, 0, g->start_bytes);
    for (t = 0; t < T; t++) {
        heml__grid_range(m, g, t, a, b);
        for (z = a[2]; z <= b[2]; z++)
            for (y = a[1]; y <= b[1]; y++)
                for (x = a[0]; x <= b[0]; x++) g->start[((size_t)z * g->n[1] + y) * g->n[0] + x + 1]++;
    }
    for (i = 0; i < (int)cells; i++) {
        total += (size_t)g->start[i + 1];
        g->start[i + 1] = (int)total;
        g->cursor[i] = g->start[i];
    }
    g->item_bytes = sizeof(int) * (total ? total : 1);
    g->items = (int *)heml__alloc(&m->allocator, g->item_bytes);
    if (!g->items) return HEML_ERR_ALLOC;
    for (t = 0; t < T; t++) {
        heml__grid_range(m, g, t, a, b);
        for (z = a[2]; z <= b[2]; z++)
            for (y = a[1]; y <= b[1]; y++)
                for (x = a[0]; x <= b[0]; x++) g->items[g->cursor[((size_t)z * g->n[1] + y) * g->n[0] + x]++] = t;
    }
    return HEML_OK;
}

/* The tetrahedron for point x and its barycentric coordinates: the first (lowest index)
   tetrahedron containing it, from the grid cell's list (every tetrahedron containing x
   overlaps x's cell); else, by a scan of all, the one x is least outside of, accepted
   within 1e-6 in barycentric coordinates. Returns the tetrahedron or -1. */
static int heml__locate(const heml_model *m, const heml__grid *g, const double x[3], double best_b[4])
{
    double b[4], best = -INFINITY, lo;
    int k, j, t, best_t = -1;
    size_t c = ((size_t)heml__grid_axis(g, 2, x[2]) * g->n[1] + heml__grid_axis(g, 1, x[1])) * g->n[0] +
               heml__grid_axis(g, 0, x[0]);
    for (k = g->start[c]; k < g->start[c + 1]; k++) {
        t = g->items[k];
        heml__barycentric(m, t, x, b);
        for (j = 1, lo = b[0]; j < 4; j++) lo = b[j] < lo ? b[j] : lo;
        if (lo >= 0.0) {
            memcpy(best_b, b, sizeof b);
            return t;
        }
    }
    for (t = 0; t < m->tet_count && best < 0.0; t++) {
        heml__barycentric(m, t, x, b);
        for (j = 1, lo = b[0]; j < 4; j++) lo = b[j] < lo ? b[j] : lo;
        if (lo > best) {
            best = lo;
            best_t = t;
            memcpy(best_b, b, sizeof b);
        }
    }
    return best >= -1e-6 ? best_t : -1;
}

HEMLDEF int heml_probe_create(const heml_model *m, const heml_real *rest_points, int count, heml_probe **out)
{
    heml_probe *p;
    heml__carver c;
    heml__grid g;
    int i, j, err;
    if (!out) return HEML_ERR_ARG;
    *out = NULL;
    if (!m || !rest_points || count < 1 || count > HEML__MAX_NODES) return HEML_ERR_ARG;
    if (!heml__all_finite(rest_points, 3 * (size_t)count)) return HEML_ERR_ARG;
    c.base = NULL;
    c.offset = sizeof(heml_probe);
    heml__carve(&c, sizeof(int) * 4 * (size_t)count);
    heml__carve(&c, sizeof(heml_real) * 4 * (size_t)count);
    p = (heml_probe *)heml__alloc(&m->allocator, c.offset);
    if (!p) return HEML_ERR_ALLOC;
    memset(p, 0, sizeof *p);
    p->bytes = c.offset;
    c.base = (char *)p;
    c.offset = sizeof(heml_probe);
    HEML__CARVE(&c, p->nodes, int, 4 * (size_t)count);
    HEML__CARVE(&c, p->weights, heml_real, 4 * (size_t)count);
    p->allocator = m->allocator;
    p->count = count;
    p->node_count = m->node_count;
    memset(&g, 0, sizeof g);
    err = heml__grid_build(m, &g);
    for (i = 0; i < count && !err; i++) {
        double x[3], b[4];
        int t;
        for (j = 0; j < 3; j++) x[j] = (double)rest_points[3 * i + j];
        t = heml__locate(m, &g, x, b);
        if (t < 0) {
            err = HEML_ERR_ARG;
            break;
        }
        for (j = 0; j < 4; j++) {
            p->nodes[4 * i + j] = heml__tet_node(m, t, j);
            p->weights[4 * i + j] = (heml_real)b[j];
        }
    }
    heml__free(&m->allocator, g.items, g.item_bytes);
    heml__free(&m->allocator, g.start, g.start_bytes);
    if (err) {
        heml_probe_destroy(p);
        return err;
    }
    *out = p;
    return HEML_OK;
}

/* out = the field f (3 per node) interpolated at the probe's points, plus base (or NULL). */
static int heml__probe_eval(const heml_probe *p, const heml_model *m, const heml_real *f, const heml_real *base,
                            heml_real *out)
{
    int i, j, r;
    if (!p || !m || !out || p->node_count != m->node_count) return HEML_ERR_ARG;
    for (i = 0; i < p->count; i++)
        for (r = 0; r < 3; r++) {
            double s = 0.0;
            for (j = 0; j < 4; j++) {
                int n = p->nodes[4 * i + j];
                s += (double)p->weights[4 * i + j] * ((double)f[3 * n + r] + (base ? (double)base[3 * n + r] : 0.0));
            }
            out[3 * i + r] = (heml_real)s;
        }
    return HEML_OK;
}

HEMLDEF int heml_probe_positions(const heml_probe *p, const heml_model *m, heml_real *out)
{
    return m ? heml__probe_eval(p, m, m->disp, m->rest, out) : HEML_ERR_ARG;
}

HEMLDEF int heml_probe_displacements(const heml_probe *p, const heml_model *m, heml_real *out)
{
    return m ? heml__probe_eval(p, m, m->disp, NULL, out) : HEML_ERR_ARG;
}

HEMLDEF int heml_probe_velocities(const heml_probe *p, const heml_model *m, heml_real *out)
{
    return m ? heml__probe_eval(p, m, m->vel, NULL, out) : HEML_ERR_ARG;
}

HEMLDEF void heml_probe_destroy(heml_probe *p)
{
    if (p) {
        heml_allocator a = p->allocator;
        heml__free(&a, p, p->bytes);
    }
}

/* >>modal ----------------------------------------------------------------------------- */

struct heml_modal {
    heml_allocator allocator;
    size_t bytes;
    int count, vectors, node_count, max_iterations, solved, iterations;
    double tolerance, shift;
    double *freq;               /* count, Hz */
    double *mu, *mu_prev;       /* vectors: Ritz values of K + sigma M */
    double *Kr, *Mr, *L, *W;    /* vectors^2: the Rayleigh-Ritz matrices, Cholesky factor, eigenvectors */
    heml_real *X, *Y, *KY;      /* vectors x 3n: the basis, (K + sigma M)^-1 M X, (K + sigma M) Y */
    heml_real *smass, *rhs;     /* 3n: sigma m per degree of freedom; M X_j */
};

HEMLDEF heml_modal_desc heml_modal_default_desc(void)
{
    heml_modal_desc d;
    d.count = 6;
    d.max_iterations = 100;
    d.tolerance = (heml_real)(HEML__FLOAT ? 1e-4 : 1e-8);
    d.shift = -1;
    return d;
}

static void heml__modal_layout(heml_modal *md, heml__carver *c, size_t n3)
{
    size_t p = (size_t)md->vectors;
    HEML__CARVE(c, md->freq, double, md->count);
    HEML__CARVE(c, md->mu, double, p);
    HEML__CARVE(c, md->mu_prev, double, p);
    HEML__CARVE(c, md->Kr, double, p * p);
    HEML__CARVE(c, md->Mr, double, p * p);
    HEML__CARVE(c, md->L, double, p * p);
    HEML__CARVE(c, md->W, double, p * p);
    HEML__CARVE(c, md->X, heml_real, p * n3);
    HEML__CARVE(c, md->Y, heml_real, p * n3);
    HEML__CARVE(c, md->KY, heml_real, p * n3);
    HEML__CARVE(c, md->smass, heml_real, n3);
    HEML__CARVE(c, md->rhs, heml_real, n3);
}

HEMLDEF int heml_modal_create(const heml_model *m, const heml_modal_desc *d, heml_modal **out)
{
    heml_modal tmp, *md;
    heml__carver c;
    size_t n3;
    if (!out) return HEML_ERR_ARG;
    *out = NULL;
    if (!m || !d || d->count < 1 || d->max_iterations < 1 || !(heml__finite((double)d->tolerance) && d->tolerance > 0) ||
        !heml__finite((double)d->shift))
        return HEML_ERR_ARG;
    n3 = 3 * (size_t)m->node_count;
    if ((size_t)d->count > n3) return HEML_ERR_ARG;
    memset(&tmp, 0, sizeof tmp);
    tmp.count = d->count;
    tmp.vectors = 2 * d->count > d->count + 8 ? 2 * d->count : d->count + 8;
    if ((size_t)tmp.vectors > n3) tmp.vectors = (int)n3;
    c.base = NULL;
    c.offset = sizeof(heml_modal);
    heml__modal_layout(&tmp, &c, n3);
    md = (heml_modal *)heml__alloc(&m->allocator, c.offset);
    if (!md) return HEML_ERR_ALLOC;
    memset(md, 0, c.offset);
    md->allocator = m->allocator;
    md->bytes = c.offset;
    md->count = tmp.count;
    md->vectors = tmp.vectors;
    md->node_count = m->node_count;
    md->max_iterations = d->max_iterations;
    md->tolerance = (double)d->tolerance;
    md->shift = (double)d->shift;
    c.base = (char *)md;
    c.offset = sizeof(heml_modal);
    heml__modal_layout(md, &c, n3);
    *out = md;
    return HEML_OK;
}

/* Eigen-decomposition of the symmetric p x p matrix A (destroyed) by cyclic Jacobi
   rotations: eigenvalues in d, eigenvectors in the columns of V (row-major). */
static void heml__jacobi_eigen(double *A, int p, double *d, double *V)
{
    int i, j, k, sweep;
    for (i = 0; i < p; i++)
        for (j = 0; j < p; j++) V[i * p + j] = i == j;
    for (sweep = 0; sweep < 64; sweep++) {
        double off = 0.0, diag = 0.0;
        for (i = 0; i < p; i++) {
            diag += A[i * p + i] * A[i * p + i];
            for (j = i + 1; j < p; j++) off += A[i * p + j] * A[i * p + j];
        }
        if (off <= 1e-32 * diag || off == 0.0) break;
        for (i = 0; i < p; i++)
            for (j = i + 1; j < p; j++) {
                double apq = A[i * p + j], theta, t, cs, sn;
                if (apq == 0.0) continue;
                theta = (A[j * p + j] - A[i * p + i]) / (2.0 * apq);
                t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                cs = 1.0 / sqrt(t * t + 1.0);
                sn = t * cs;
                for (k = 0; k < p; k++) { /* columns i, j */
                    double aki = A[k * p + i], akj = A[k * p + j];
                    A[k * p + i] = cs * aki - sn * akj;
                    A[k * p + j] = sn * aki + cs * akj;
                }
                for (k = 0; k < p; k++) { /* rows i, j */
                    double aik = A[i * p + k], ajk = A[j * p + k];
                    A[i * p + k] = cs * aik - sn * ajk;
                    A[j * p + k] = sn * aik + cs * ajk;
                }
                for (k = 0; k < p; k++) {
                    double vki = V[k * p + i], vkj = V[k * p + j];
                    V[k * p + i] = cs * vki - sn * vkj;
                    V[k * p + j] = sn * vki + cs * vkj;
                }
            }
    }
    for (i = 0; i < p; i++) d[i] = A[i * p + i];
}

/* The Rayleigh-Ritz step: Kr w = mu Mr w (p x p, Mr positive definite) by Cholesky
   Mr = L L^T and Jacobi on L^-1 Kr L^-T; mu ascending, the M-orthonormal Ritz vectors'
   coefficients in the columns of W. Returns 0 when Mr is not positive definite. Kr is
   destroyed. */
static int heml__ritz(heml_modal *md)
{
    int p = md->vectors, i, j, k;
    double *Kr = md->Kr, *Mr = md->Mr, *L = md->L, *W = md->W, *mu = md->mu;
    double *C = md->Mr; /* Mr is spent once factored */
    for (i = 0; i < p; i++)
        for (j = 0; j <= i; j++) {
            double s = Mr[i * p + j];
            for (k = 0; k < j; k++) s -= L[i * p + k] * L[j * p + k];
            if (i == j) {
                if (!(s > 0)) return 0;
                L[i * p + i] = sqrt(s);
            } else {
                L[i * p + j] = s / L[j * p + j];
            }
        }
    for (i = 0; i < p; i++) /* Kr := L^-1 Kr (columns), then C = (L^-1 (L^-1 Kr)^T) */
        for (j = 0; j < p; j++) {
            double s = Kr[i * p + j];
            for (k = 0; k < i; k++) s -= L[i * p + k] * Kr[k * p + j];
            Kr[i * p + j] = s / L[i * p + i];
        }
    for (j = 0; j < p; j++)
        for (i = 0; i < p; i++) {
            double s = Kr[j * p + i]; /* (L^-1 Kr)^T [i][j] */
            for (k = 0; k < i; k++) s -= L[i * p + k] * C[k * p + j];
            C[i * p + j] = s / L[i * p + i];
        }
    for (i = 0; i < p; i++) /* symmetrise the round-off */
        for (j = 0; j < i; j++) C[i * p + j] = C[j * p + i] = 0.5 * (C[i * p + j] + C[j * p + i]);
    heml__jacobi_eigen(C, p, mu, Kr); /* eigenvectors of C into Kr */
    for (j = 0; j < p; j++) /* W = L^-T V */
        for (i = p - 1; i >= 0; i--) {
            double s = Kr[i * p + j];
            for (k = i + 1; k < p; k++) s -= L[k * p + i] * W[k * p + j];
            W[i * p + j] = s / L[i * p + i];
        }
    for (i = 1; i < p; i++) /* sort ascending (insertion: p is small), columns of W with mu */
        for (j = i; j > 0 && mu[j - 1] > mu[j]; j--) {
            double t = mu[j];
            mu[j] = mu[j - 1];
            mu[j - 1] = t;
            for (k = 0; k < p; k++) {
                t = W[k * p + j];
                W[k * p + j] = W[k * p + j - 1];
                W[k * p + j - 1] = t;
            }
        }
    return 1;
}

/* Block shift-invert subspace iteration (Bathe) with Rayleigh-Ritz: Y = (K + sigma M)^-1
   M X by the model's linear solver (heml__linear_solve: preconditioned CG with the static
   solve's coarse space, warm-started at X / mu), then the Ritz pairs of (K + sigma M, M) in
   span Y, with the exact products (K + sigma M) Y, give the next M-orthonormal X. Converged
   when every wanted Ritz value moved by at most tolerance of itself. */
HEMLDEF int heml_modal_solve(heml_modal *md, heml_model *m)
{
    int p, n3, i, j, a, it, err = HEML_ERR_NO_CONVERGENCE, nfree = 0;
    double sigma, pi2 = 2.0 * 3.14159265358979323846, inner;
    heml_stats saved;
    if (!md || !m || md->node_count != m->node_count) return HEML_ERR_ARG;
    if (m->has_user_without_second) return HEML_ERR_NO_SECOND_DERIVATIVES;
    p = md->vectors;
    n3 = 3 * m->node_count;
    md->solved = 0;
    for (i = 0; i < n3; i++) nfree += m->free_mask[i] > 0;
    if (nfree < p) return HEML_ERR_ARG;
    sigma = md->shift;
    if (sigma < 0) {
        double top = 0.0;
        for (i = 0; i < n3; i++)
            if (m->free_mask[i] > 0 && (double)m->diag[i] / (double)m->mass[i / 3] > top)
                top = (double)m->diag[i] / (double)m->mass[i / 3];
        sigma = 1e-5 * top;
    }
    for (i = 0; i < n3; i++) md->smass[i] = (heml_real)(sigma * (double)m->mass[i / 3]) * m->free_mask[i];
    inner = md->tolerance < 1e-3 ? md->tolerance : 1e-3;
    saved = m->stats;
    heml__prony_coefficients(m, (double)m->time_step);
    for (j = 0; j < p; j++) { /* a fixed pseudo-random start on the free axes */
        heml_real *x = md->X + (size_t)j * n3;
        for (i = 0; i < n3; i++) {
            unsigned h = (unsigned)i * 2654435761u + (unsigned)j * 40503u + 1u;
            h ^= h >> 15;
            h *= 2246822519u;
            h ^= h >> 13;
            x[i] = (heml_real)(((double)(h & 0xffffu) / 32768.0 - 1.0) * (double)m->free_mask[i]);
        }
        md->mu[j] = 0.0;
    }
    for (it = 0; it < md->max_iterations; it++) {
        int done = it > 0;
        for (j = 0; j < p; j++) {
            heml_real *x = md->X + (size_t)j * n3, *y = md->Y + (size_t)j * n3;
            int kerr;
            for (i = 0; i < n3; i++) {
                md->rhs[i] = m->mass[i / 3] * x[i] * m->free_mask[i];
                y[i] = md->mu[j] > 0 ? (heml_real)((double)x[i] / md->mu[j]) : 0;
            }
            kerr = heml__linear_solve(m, HEML__SPD, m->disp, md->smass, 1.0, md->rhs, y, inner, 1);
            if (kerr == HEML__NEGATIVE_CURVATURE) kerr = HEML_ERR_UNSTABLE;
            if (kerr == HEML_ERR_NO_CONVERGENCE) kerr = HEML_OK; /* the iterate still improves the basis */
            if (kerr) {
                m->stats = saved;
                return kerr;
            }
        }
        m->lin_x = m->disp;
        heml__dc_invalidate(m);
        for (j = 0; j < p; j++) heml__cg_apply(m, md->smass, 1.0, md->Y + (size_t)j * n3, md->KY + (size_t)j * n3);
        for (a = 0; a < p; a++)
            for (j = 0; j <= a; j++) {
                const heml_real *ya = md->Y + (size_t)a * n3, *yj = md->Y + (size_t)j * n3;
                double k1 = heml__dot(ya, md->KY + (size_t)j * n3, n3), k2 = heml__dot(yj, md->KY + (size_t)a * n3, n3);
                double s = 0.0;
                for (i = 0; i < n3; i++) s += (double)m->mass[i / 3] * (double)m->free_mask[i] * (double)ya[i] * (double)yj[i];
                md->Kr[a * p + j] = md->Kr[j * p + a] = 0.5 * (k1 + k2);
                md->Mr[a * p + j] = md->Mr[j * p + a] = s;
            }
        if (!heml__all_finite(md->Y, (size_t)p * (size_t)n3)) {
            m->stats = saved;
            return HEML_ERR_NOT_FINITE;
        }
        memcpy(md->mu_prev, md->mu, sizeof(double) * (size_t)p);
        if (!heml__ritz(md)) {
            m->stats = saved;
            return HEML_ERR_NOT_FINITE;
        }
        for (j = 0; j < p; j++) { /* X = Y W */
            heml_real *x = md->X + (size_t)j * n3;
            for (i = 0; i < n3; i++) {
                double s = 0.0;
                for (a = 0; a < p; a++) s += (double)md->Y[(size_t)a * n3 + i] * md->W[a * p + j];
                x[i] = (heml_real)s;
            }
        }
        for (j = 0; j < md->count; j++)
            if (!(fabs(md->mu[j] - md->mu_prev[j]) <= md->tolerance * fabs(md->mu[j]))) done = 0;
        if (done) {
            err = HEML_OK;
            break;
        }
    }
    md->iterations = it;
    m->stats = saved;
    if (err) return err;
    for (j = 0; j < md->count; j++) {
        double lambda = md->mu[j] - sigma;
        md->freq[j] = (lambda >= 0 ? sqrt(lambda) : -sqrt(-lambda)) / pi2;
    }
    md->solved = 1;
    return HEML_OK;
}

HEMLDEF int heml_modal_count(const heml_modal *md) { return md && md->solved ? md->count : 0; }

HEMLDEF double heml_modal_frequency(const heml_modal *md, int i)
{
    if (!md || !md->solved || i < 0 || i >= md->count) return NAN;
    return md->freq[i];
}

HEMLDEF const heml_real *heml_modal_shape(const heml_modal *md, int i)
{
    if (!md || !md->solved || i < 0 || i >= md->count) return NULL;
    return md->X + (size_t)i * 3 * (size_t)md->node_count;
}

HEMLDEF void heml_modal_destroy(heml_modal *md)
{
    if (md) {
        heml_allocator a = md->allocator;
        heml__free(&a, md, md->bytes);
    }
}

#if defined(HEML_STATIC) && defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif /* HEML_IMPLEMENTATION */

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
