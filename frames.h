/* frames.h - v0.1.0 - 6-DoF frames and samples: meshless or mesh-based hyperelastic bodies - MIT or public domain

   A drop-in model of soft bodies after Bosman, "Physically-based 6-DoF nodes deformable
   models" (PhD thesis, Lille 2015, ch. 3-4) and Bosman, Duriez & Cotin, "Connective
   tissues simulation on GPU" (2013): the body is carried by frames, 6-DoF nodes (a
   position and a unit quaternion), and integrated at samples, points that know their
   neighbouring frames through shape functions. Mesh-based (tetrahedral barycentric or
   hexahedral trilinear) and meshless (Shepard, linear moving least squares) shape
   functions, Poisson-disk sampling of boxes and closed surfaces, St Venant-Kirchhoff,
   compressible Neo-Hookean, compressible Mooney-Rivlin and user-defined (callback)
   samples, exact forces and stiffness (material and geometric),
   a static Newton solver, implicit Euler and BDF2, all with conjugate gradient
   preconditioned by block-Jacobi plus a coarse space (two levels), matrix-free or by
   assembled 6x6 blocks, modal analysis (the lowest natural
   frequencies and modes about the current state), point probes (a material point's
   position, displacement and velocity through the shape functions) that double as mapped
   points (their Jacobian J and J^T: point forces as frame loads, coupling), and coupling:
   one model from several parts sharing frames, rigid bodies (see COUPLING). The per-sample and per-frame math are
   FRM_HOSTDEV static inline kernels (>>kernels) in the same two-pass structure a GPU
   uses: pass 1 per sample writes a contribution per (sample, slot), pass 2 per frame
   gathers them through a reverse table; the passes' bodies are FRM_HOSTDEV functions on
   a plain view of the model's arrays (frm_view, >>passes) that the CPU loops and the
   CUDA companion (frames_cuda.cu, see CUDA: compiled, not yet run on a GPU) both call.

   DO THIS in exactly one C or C++ file:

       #define FRAMES_IMPLEMENTATION
       #include "frames.h"

   MINIMAL PROGRAM (a 4 x 1 x 1 m beam of 8 x 2 x 2 cells clamped at x = 0, sagging
   under its own weight; cc app.c -lm)

       #define FRAMES_IMPLEMENTATION
       #include "frames.h"
       #include <stdio.h>

       int main(void)
       {
           frm_real nodes[81 * 3];
           int hexes[32 * 8], i, c, a, err;
           frm_sampling s;
           frm_desc d = frm_model_default_desc();
           frm_model *m;
           for (i = 0; i < 81; i++) { // node i = x + 9 (y + 3 z) on a 0.5 m grid
               nodes[3 * i] = (frm_real)(0.5 * (i % 9));
               nodes[3 * i + 1] = (frm_real)(0.5 * (i / 9 % 3));
               nodes[3 * i + 2] = (frm_real)(0.5 * (i / 27));
           }
           for (c = 0; c < 32; c++) // cell (c % 8, c / 8 % 2, c / 16), corner a = (a&1, a>>1&1, a>>2)
               for (a = 0; a < 8; a++)
                   hexes[8 * c + a] = (c % 8 + (a & 1)) + 9 * ((c / 8 % 2 + (a >> 1 & 1)) + 3 * (c / 16 + (a >> 2)));
           err = frm_sampling_hexes(&s, nodes, 81, hexes, 32, 2, FRM_QUADRATURE_SUBCELL, NULL);
           if (err) return printf("%s\n", frm_error_string(err)), 1;
           frm_sampling_apply(&s, &d);      // frames at the nodes, 8 samples a cell
           d.material.young_modulus = 1e8;  // Pa
           d.material.density = 1000;       // kg/m^3
           err = frm_model_create(&d, &m);
           frm_sampling_free(&s);           // the model keeps its own copy
           if (err) return printf("%s\n", frm_error_string(err)), 1;
           for (i = 0; i < 81; i += 9) frm_model_fix_frame(m, i); // clamp the face x = 0
           err = frm_model_solve_static(m);                       // sag under gravity
           printf("%s: the tip sagged %.4f m\n", frm_error_string(err),
                  0.5 - (double)frm_model_positions(m)[3 * 44 + 2]); // 0.0399, beam theory 0.040
           for (i = 0; i < 100; i++) frm_model_step(m); // then one second of implicit dynamics
           frm_model_destroy(m);
           return 0;
       }

   More: examples/frames_beam.c (the thesis's steel cantilever Newton iteration by
   Newton iteration, VTK of samples and frames, nanoseconds per pair of the CG product).

   OVERRIDES (define before including the implementation)

       FRM_REAL        float or double (default double). Kernels and stored data are
                       FRM_REAL; creation, shape functions, sampling, dot products and
                       energies run in double. In float builds every public entry point
                       is renamed (..._f32), so float and double translation units cannot
                       be linked together.
       FRM_MALLOC(size, user) / FRM_FREE(ptr, user)
                       default allocator (malloc/free) when the desc gives none.
       FRM_ASSERT(x)   internal sanity checks (default: assert from <assert.h>).
       FRM_STATIC      make every function static (private to the including file).
       FRM_PARALLEL_MIN_PAIRS
                       default of desc.parallel_min_pairs (20000).
       FRAMES_KERNELS  define (without FRAMES_IMPLEMENTATION) to get only the
                       FRM_HOSTDEV kernels and pass functions (frm_pass1_*, frm_pass2_*
                       on a frm_view), e.g. in a .cu file (FRM_HOSTDEV is
                       __host__ __device__ under nvcc, empty otherwise).

   STEP BY STEP
       1. Frames, samples and the neighbour table: frm_sampling_hexes / _tets (mesh-based),
          frm_sampling_curve (a rod: frames along a polyline), frm_sampling_meshless (given
          points), frm_sampling_box / _surface (Poisson disks); or fill the table yourself
          (any weights that sum to one, gradients to zero). Thin parts (a layer one element
          thick, a curve): frm_material_thin (LIMITS, thin parts).
          Several parts (own sampling, material, density) sharing frames, and rigid bodies:
          frm_parts_combine, then frm_assembly_apply instead of frm_sampling_apply (COUPLING).
       2. frm_desc d = frm_model_default_desc(); frm_sampling_apply(&s, &d); set the
          material (or a per-sample table), gravity, time step, solver settings.
       3. frm_model_create(&d, &m) validates everything and allocates all memory once.
       4. Boundary conditions and loads: frm_model_fix_frame, frm_model_drive_frame (a
          prescribed pose), frm_model_release_frame, frm_model_set_frame_axes (some
          translation and rotation axes held: symmetry planes, rollers, plane strain),
          frm_model_set_external (force and torque), frm_model_set_gravity.
       5. frm_model_step (implicit Euler, or desc.integrator: FRM_BDF2 for second order)
          or frm_model_solve_static (Newton), or frm_model_newton_step to watch a solve;
          frm_model_last_stats for iterations. frm_model_set_damping, _set_integrator
          change the dynamics' settings after creation.
       6. Read frm_model_positions / _orientations / _velocities / _displacements, and
          frm_model_sample_positions / _deformation_gradients, to render or measure; any
          material point through a probe (frm_probe_create once, then frm_probe_positions
          / _displacements / _velocities; see PROBES: this is how a frames body is rendered,
          a render mesh's vertices as mapped points; forces at them as loads through
          frm_probe_add_external, see COUPLING); natural frequencies and modes about
          the current state with frm_modal_create / _solve (see MODAL ANALYSIS).
       7. frm_model_destroy(m); frm_sampling_free(&s) (any time after step 3).

   HOW TO EXTEND (each kind of extension has one table or switch; add a row, not a branch)
       A constitutive law: a value before FRM_LAW_COUNT in frm_law (public, documented
          with its energy and the frm_material fields it reads); in frm__law_params what
          its FRM_LAW_PARAMS block holds (and the small-strain shear modulus that scales
          the stabilisation and the coupling); one row of frm__laws[] (>>laws) with its
          name, cache_size (raise FRM__LAW_CACHE_MAX if needed), energy, stress (S, energy,
          tangent data; FRM_ERR_INVERTED where the law is undefined), differential (dS for
          dE), definite (NULL, or how the tangent data keep the material term >= 0 for the
          static solve's definite linearisation) and fast_path = 0. An isotropic law in
          invariants only needs its w and derivatives next to frm__mr_derivatives. Set
          fast_path only if frm_material_stress / frm_material_dstress (>>kernels, shared
          with a CUDA build) implement the law, and validation in frm__validate_material
          for its fields. The model's loops call frm__law_stress, frm__law_dstress,
          frm__law_dP and the law's definite rule, never the law by name.
          Tests (tests/test_frames_elem.c, test_law_*): add the law's material to
          law_material; then force = -gradient of the table's energy and differential =
          derivative of the stress at the law level and through the model (force and K v
          against finite differences) run for it by themselves; add its uniaxial closed
          form to test_law_uniaxial_closed_forms where it has one (REFERENCES R4, R5).
       An integrator: a value before FRM_INTEGRATOR_COUNT in frm_integrator and one row of
          frm__integrators[] (>>integrator) with name, step(m, dt) (restores the step's start
          state on failure) and is_explicit. Linear solves go through frm__linear_solve. A
          scheme whose step minimises implicit Euler's incremental potential about other
          data (as BDF2: step length, offset xbar - x_n, reference velocity) fills a
          frm__step_target and calls frm__implicit_solve (Newton, line search, acceptance);
          a multistep scheme keeps its history in the model (as m->history, carved in
          frm__layout) and resets it where frm_model_set_poses and the others clear
          history_valid.
          Tests: its order of accuracy on an oscillator (halve dt, the error falls by
          2^order), energy behaviour on a free body, bit-identical results for 1 and 2
          threads (the determinism test of tests/test_frames.c), refusal of bad values.
       A linear solver: a value before FRM_LINEAR_SOLVER_COUNT in frm_linear_solver (AUTO,
          -1, is the choice at creation, not a solver: frm__create_size resolves it; a solver
          with a pattern condition adds its test there) and a
          case in frm__linear_solve (>>solver; FRM_LINEAR_SOLVER_BTD's is in >>btd) returning the FRM__CG_* statuses (OK, CAP,
          NEGATIVE, NOT_FINITE), which the Newton loops map to FRM_ERR_NO_CONVERGENCE and
          FRM_ERR_NOT_FINITE. Scratch vectors are named by role in frm_model (cg_r, ...,
          newton_dx) and carved in frm__layout. Tests: the same solutions as CG to the
          tolerance on the static and implicit scenes of tests/test_frames.c, the cap and
          non-finite policies (issue 18).
       A shape function: a frm__*_functions evaluator (>>shape-functions) returning weights
          and gradients, a public frm_shape_* wrapper (with a float rename, and listed in
          tests/test_frames_elem.c's test_float_renames) and a frm_shape value used by
          frm_sampling_meshless. Tests: partition of unity and zero-sum gradients, linear
          reproduction where claimed, gradients against finite differences.
       The bench (make bench, bench/model_frames.c) must show no loss on the existing
       scenes (or callgrind instruction counts of the force and K v loop, which are
       deterministic on a busy machine) and, for a new law or solver, its cost and
       accuracy on the bench's scenes next to the existing ones.

   UNITS: SI throughout. Positions m, Young's modulus Pa, density kg/m^3, volumes m^3,
   time s, forces N, torques N m, rotations rad (world axes), gravity m/s^2 (default 9.81
   along -z), mass_damping 1/s, stiffness_damping s.

   MEMORY: frm_model_create makes one allocation (one block, every array in it 64-byte
   aligned) through the desc's allocator (or FRM_MALLOC), plus temporary tables it frees
   before returning. A custom allocator must honour the alignment it is asked for (64).
   Nothing else allocates: forces, stiffness products and assembly, steps and solves
   reuse the block. Per (sample, neighbour) pair the model holds about 230 bytes in
   double (index, weight, gradient, levers, the linearisation's G and Hs, the pass-1
   buffer; 24 more with the rotation stabilisation's divergence term, the default), per
   block 292 when block storage is reserved (every stiffness mode but
   FRM_STIFFNESS_PAIRS), per sample about 200 (290 with the divergence term), per frame
   about 1 kB (BDF2's history included: 25 reals); frm_model_memory_bytes tells. A probe
   makes one allocation at frm_probe_create (through the model's allocator: about 40 bytes
   per (point, frame) pair) plus temporaries freed before it returns. The description's arrays are read during frm_model_create only. The samplings
   allocate their arrays in one block each (frm_sampling_free) and free their temporaries;
   frm_parts_combine two blocks (the sampling's and its own: frm_assembly_free).

   ERRORS: every fallible function returns 0 or a negative FRM_ERR_* code; frm_error_string
   names it, and the optional desc.log callback receives a detailed message for validation
   failures (the library never prints). A description not made by its default function
   (frm_model_default_desc, frm_shape_default_desc, frm_poisson_default_desc: a private
   cookie) is refused with FRM_ERR_DESC before anything in it is read, its log callback
   included (it may be garbage). Shape functions refuse non-finite points, corners, frames
   or radii and a Shepard exponent <= 1 (FRM_ERR_ARG); samplings refuse a Shepard exponent
   <= 1 and frame_spacing < sample_spacing (FRM_ERR_SAMPLING). Creation refuses: counts out of range, non-finite
   positions, orientations that are not unit quaternions (|q|^2 off by more than 1e-5),
   zero, negative or non-finite sample volumes, samples without neighbours or with more
   than FRM_MAX_NEIGHBORS (16), frame indices out of range or repeated in a sample,
   weights that do not sum to one (1e-9; float 1e-5) or gradients that do not sum to zero
   (relative to sum |grad w|), frames no sample gives a weight (no mass), unknown laws,
   E <= 0, nu outside (-1, 0.5), density <= 0, bad time step, damping or solver settings,
   an unknown desc.volumetric, FRM_VOLUMETRIC_CELLS without sample_cells or with a negative
   index, a volumetric_patch_size outside 0..FRM_VOLUMETRIC_PATCH_MAX (FRM_VOLUMETRIC_PATCHES),
   a negative or non-finite volumetric_stabilization, or a frame whose averaging
   volume sum_s v_s w_s is not > 0 (FRM_ERR_VOLUMETRIC), FRM_STIFFNESS_BLOCKS with the
   volumetric option (FRM_ERR_STIFFNESS_MODE).
   Coupling (issue 14): frm_parts_combine refuses a malformed frame map (FRM_ERR_PART_FRAME:
   an index out of range or repeated within a part, a model frame nobody gives, shared frames
   at different rest positions) and a rigid body with mass <= 0 or an inertia not symmetric
   positive definite (FRM_ERR_RIGID, as creation does for desc.frame_masses / _inertias, and
   FRM_ERR_SAMPLE_SIZE for desc.sample_sizes); frm_probe_create a point outside the body
   (FRM_ERR_POINT_OUTSIDE: in no element, or farther from each of its meshless frames than
   that frame's farthest sample). The CUDA companion (frames_cuda.h) returns FRM_ERR_DEVICE
   for no device, a failed CUDA call or a model feature it does not run (see CUDA).
   A step or solve never reports success with an unconverged or unchecked result: one that
   meets a non-finite value, including a load or residual whose norm overflows (1e156 N:
   FRM_ERR_NOT_FINITE), would leave a sample inverted (det F <= 0) that was not inverted at
   its start (FRM_ERR_INVERTED: det F <= 0, Neo-Hookean and St Venant-Kirchhoff alike;
   frm_model_forces and _energy refuse such a state too), does not converge (FRM_ERR_NO_CONVERGENCE: a Newton run at its
   cap, a CG solve at cg_max_iterations above its tolerance, a line search that finds no
   decrease, a continuation cut below min_increment or past max_increments; FRM_ERR_STALLED
   when its last increment stopped because the residual had not halved in 15 Newton
   iterations, see LIMITS), converges to a saddle rather than a minimum (FRM_ERR_UNSTABLE,
   static solves: see SOLVERS), or starts or ends with a state too far from rest for frm_real
   (FRM_ERR_PRECISION: eps(frm_real) max|u| > precision_limit h_min, see LIMITS) leaves
   positions, orientations and velocities exactly as they were.

   THREADING AND DETERMINISM: no global state; one model may be used by one thread at a
   time, different models by different threads. The per-sample and per-frame passes run
   through desc.parallel_for (an engine's job system) when given, through OpenMP when
   compiled with -fopenmp, serially otherwise, and serially for models under
   desc.parallel_min_pairs pairs. The work is cut into fixed chunks (64 samples, 32
   frames) that do not depend on the thread count; every frame sums its pairs'
   contributions in pair order through the reverse table (pass 2), energies add chunk
   partial sums in chunk order, and the CG's vector work is serial: results are
   bit-identical whatever the number of threads or the job system's split. No atomics.
   The chunks' bodies are the pass functions of >>passes (see CUDA).

   THE MODEL (thesis equations; our derivations where the printed ones differ)
       Kinematics. A sample s has rest position pbar_s, volume v_s and neighbours i with
       weight w_i, gradient grad w_i (rest coordinates) and rest local position
       lbar_i = Rbar_i^T (pbar_s - xbar_i) (eq. 3.33). Its position (eq. 3.34) and
       deformation gradient (eq. 3.40) are
           p_s = sum_i w_i d_i,   d_i = x_i + R_i lbar_i,
           F_s = sum_i d_i grad w_i^T + w_i R_i Rbar_i^T.
       The kernels form H = F - I without cancellation: since xbar_i + Rbar_i lbar_i =
       pbar_s, d_i - d_0 = (u_i - u_0) + (Q_i - I) abar_i - (Q_0 - I) abar_0 with u = x -
       xbar, Q_i = R_i Rbar_i^T (Q - I from the relative quaternion) and abar_i =
       pbar_s - xbar_i; the state is kept as displacements u. Float keeps small strains.
       Variations. A frame's rotation varies as R -> exp([dtheta]x) R, dtheta in world
       axes, and its generalized vectors are (translation, rotation): 6 per frame. Then
       (eqs. 3.42-3.44; our form of the 9 x 6 matrix B)
           dF = sum_i dx_i grad w_i^T + [dtheta_i]x G_i,   G_i = a_i grad w_i^T + w_i Q_i,
       a_i = R_i lbar_i the lever. Forces (eq. 3.52) need no M: with dE = sym(F^T dF),
       S : dE = (F S) : dF, so M^T {S} = B^T vec(P) with P = F S, and
           f_i = -sum_s v_s (P grad w_i,  sum_j g_ij x p_j)      (force, torque)
       (g_ij, p_j the columns of G_i and P). The printed eq. 3.49 repeats [B]^4 where
       [B]^3 belongs, and the cross-product matrix of eq. A.3 has its last row's middle
       sign wrong ((-v1, v0, 0) is right); the finite-difference tests decided.
       Laws (per sample): St Venant-Kirchhoff S = lambda tr(E) I + 2 mu E (eq. 3.53),
       compressible Neo-Hookean W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2,
       S = mu (I - C^-1) + lambda ln J C^-1, compressible Mooney-Rivlin (heml.h's
       HEML_MOONEY_RIVLIN) W = c1 (I1 J^-2/3 - 3) + c2 (I2 J^-4/3 - 3) + kappa/2 (J - 1)^2,
       and user laws W(I1, I2, J) by callbacks; the last two through
       S = 2 w_1 I + 2 w_2 (I1 I - C) + J w_J C^-1 (see >>laws).
       Stiffness, K = -df/dq (the thesis writes K = df/dq). Differentiating f:
           K v = sum_s v_s B^T vec(dP) + H dtheta,  dP = dF S + F dS,  dS = C : sym(F^T dF)
       where F dS is the material part (eqs. 3.67-3.70), dF S the geometric part of
       eqs. 3.71-3.73, and H_i = v_s (G_i P^T - tr(G_i^T P) I) the derivative of B through
       the frame's own rotation (eqs. 3.74-3.75, appendix B's K^R). Gravity acting on the
       samples adds the torque's stiffness per frame. K is not symmetric: because
       rotations do not commute, the rotational diagonal blocks carry an antisymmetric
       part 1/2 [tau_i]x, tau_i the frame's internal plus gravity torque (it vanishes at
       equilibrium without external torques). The solvers use the symmetric part, which
       is the Hessian of the energy in rotation-vector coordinates;
       frm_model_apply_stiffness gives either.
       Coupling term (optional, desc.frame_coupling = eps, default 0 = the thesis's model):
           E_c = 1/2 sum_s eps mu_s v_s / h_s^2 sum_i |w_i| |d_i - p_s|^2,
       h_s^2 the weighted mean squared lever: it ties each frame's own prediction of a
       sample to the blended position. Zero under rigid motion, of higher order for smooth
       fields, it stiffens the rotations a trilinear grid cannot see (see LIMITS), at the
       price of bending stiffness on coarse, elongated cells.

       Rotation stabilisation: two terms that give the frames' rotations the stiffness the
       continuum has where the samples do not see them; both are zero for rigid motions and
       whenever the frames turn with the material.
       (1) Unseen rotations (desc.rotation_stabilization = beta, default 0.5; 0 = the
       thesis's model). A frame whose samples lie on a line (or are a single one) has a
       rotation they do not see at first order: turning it about that line while
       translating it by -dtheta x a_s leaves every sample's prediction d = x + R lbar in
       place, and F changes only by the skew w [dtheta]x. The energy is flat along it, and
       under stress its second-order term w (Q - I) relieves the samples' strain, so it
       buckles: the thesis's model has no equilibrium near the natural one (with one sample
       per tetrahedron every edge frame of a beam is such a frame, and Newton wandered to
       FRM_ERR_NO_CONVERGENCE on every beam of the bench; measured: the energy minimum
       sits at 0.04 rad of spurious rotation and 78 % more sag on R1 one cell across). For
       those frames only (found at creation: the kernel of the samples' second moment
       J = tr(L) I - L, projector N in rest axes, unless the whole neighbourhood is
       collinear too, a rod whose torsion lives in that rotation; L by centred running
       sums, exactly zero for one sample whatever the compiler contracts, see SOLVERS'
       minimum check for what the one-pass form did) the model adds, per
       (sample, frame), beta mu v / 2 omega . N omega with omega = axial(skew(Q^T F)), the
       frame's rotation relative to the sample's, about the unseen axes only (measured:
       beta 0.5 against 0.1 moves the tip by 0.49 % on R3 one cell across, by 0.09 % at
       two; tests/test_frames.c checks it). frm_model_stabilized_frames counts the frames.
       (2) Divergence (desc.rotation_divergence = gamma, default 4; 0 = the thesis's
       model). Frame rotations can also move no material collectively: with weights that
       reproduce linear fields, turning every frame by the same theta moves nothing
       (sum_i w_i theta x (x - x_i) = 0), and on a tensor-product hexahedral grid neither
       does a layer of frames normal to an axis turning about it (the bilinear face
       interpolation reproduces the in-plane coordinates): zero-energy modes of the
       linearisation, which stalled the static solves of hexahedral frames one cell across
       and of R2. With one sample per tetrahedron the slowly varying version costs only
       the under-integrated bubble energy mu h^2 |grad theta|^2: the R3 beam had modes at
       0.39-0.42 Hz below its first bending mode (0.509 Hz) at every resolution and at
       2.3-2.5 Hz below the second, the frames turning about the beam's axis while the
       material hardly moves, which beta did not touch (0.4164 against 0.4168 Hz for 0.5
       and 2). A tie of each frame's rotation to the material's (|omega|^2 per pair or per
       sample) removes them but locks bending: the frames' natural rotation in bending is
       not the material's (on R1 with 24 x 4 x 4 hexahedral cells it is half of it: the
       rotation gradient makes the quadratic bubble through sum_i w_i (G d_i) x d_i with
       G = omega'/2), so even gamma = 1e-2 put R1 31 % too stiff. What the continuum does
       fix is the divergence: a material rotation field, half the curl of the
       displacement, has none, and neither has the frames' natural field in bending
       (theta_y varying along x), while every mode above has (theta_x varying along x,
       a layer's jump). Per sample, with omega_k = axial(skew(Q_k^T F)) the sample's
       rotation relative to frame k (rest axes) and, linearised, omega_k = omega_s - theta_k
       and sum_k grad w_k = 0,
           D = sum_k grad w_k . omega_k  (= -div theta, the frames' interpolated field)
           E_d = gamma mu v h^2 / 2 D^2,
       h^2 the sample's mean squared lever (sum |w| |lbar|^2 / sum |w|): of order h^2 for
       smooth fields, so it vanishes under refinement, zero for rigid motions (omega_k = 0)
       and for a uniform turn relative to the material. Only samples whose weights
       reproduce linear fields (sum_k lbar_k grad w_k^T = -I to 1e-3: tetrahedra,
       hexahedra, MLS) carry it; zero-order Shepard samples keep the thesis's model.
       Forces: with Z_k = Q_k [grad w_k]x, grad w_k . omega_k = [grad w_k]x : Q_k^T F / 2
       = Z_k : F / 2, so D = Y : F / 2 (Y = sum_k Z_k), the stress c g D / 2 Y joins
       P (c = mu v, g = gamma h^2) and each frame's own torque is c g D / 2 sum_j f_j x z_kj.
       Stiffness, exact: dD = Y : dF / 2 - sum_k dtheta_k . t_k / 2 (t_k = sum_j f_j x z_kj),
       the Gauss-Newton part c g dD (Y / 2, -t_k / 2) and the second-order part of
       T_k = c g D / 2 Z_k ([dtheta_k]x T_k, -sum_j df_j x t_kj and the frame-own
       sym(F T^T) - tr(F^T T) I), tested against finite differences of the force, which are
       tested against an independent energy (tests/test_frames.c). Measured on the R3 beam
       (generalized eigenvalues of (K, M), tests/test_frames_elem.c), tetrahedral frames
       with one sample each, two cells across: lowest modes 0.4164 (spurious), 0.4976,
       0.4976, 2.4879 (spurious), 2.9943 Hz with gamma = 0; 0.4982, 0.4982, 2.9982, 2.9982,
       4.8506 (torsion, 3D 4.5101) Hz with gamma = 4; one cell across 0.3901 (spurious),
       0.4447 against 0.4480, 0.4484 (bending), 2.69 (second bending) Hz; hexahedral frames
       one cell across: six and more zero eigenvalues with gamma = 0, lowest 0.4681 Hz
       (bending) with gamma = 4. gamma trades the hexahedral one-cell rotation mode (0.27,
       0.35, 0.47, 0.64, 0.96 Hz for gamma = 0.5, 1, 2, 4, 10) against the tetrahedral
       frames' torsion, which the term stiffens at coarse resolution (4.44 Hz at gamma 0,
       4.67, 4.80, 4.85, 4.87 Hz at 0.5, 2, 4, 10 on two cells across; of order h^2).
       Both terms: the stabilisation's stress joins the sample's P, the frame-own torques
       apart; the unseen-rotations term's stiffness is exact too (Gauss-Newton part and
       second-order part).

   VOLUMETRIC AVERAGING (issue 13; desc.volumetric, default FRM_VOLUMETRIC_NONE, which
   leaves every result bit-identical). Near incompressibility (nu -> 0.5) a sample's own J
   is a constraint the frames cannot all meet: the bench's Poisson beam (1 m, 3 cells
   across) with hexahedral frames is 19 % too stiff at nu = 0.49 and 41 % at 0.499. The
   option evaluates every sample's law (any row of the law table, user laws included) at
   the F-bar of de Souza Neto et al. (1996),
       F_bar_s = alpha_s F_s,   alpha_s = (J_bar_s / J_s)^(1/3),   J_bar = A J,
   A a fixed averaging of the samples' J with A 1 = 1 (a homogeneous J is kept) and
   v^T A = v^T (volume is conserved), and adds a stabilisation of the fluctuation:
       E = sum_s v_s [ W(F_bar_s) + eta mu_s / 2 ln^2(J_bar_s / J_s) ]
   (eta = desc.volumetric_stabilization, default 2; mu_s the law's small-strain shear
   modulus). At small strain W(F_bar) is W's deviatoric part at the sample plus the bulk
   term of the average, kappa / 2 (tr eps_bar)^2 (the B-bar element), so the bulk modulus
   acts on one constraint per cell or frame instead of one per sample; the fluctuation
   J_s - J_bar_s, which the average does not see, costs eta mu: a shear-like stiffness,
   which does not lock, and without which coarse meshes have soft modes (the bench's beam
   with hexahedral frames 2 cells across: +14.3 % at nu = 0.3 with eta = 0, +7.5 % with
   1, +3.1 % with 2, the plain model +2.4 %; one-sample tetrahedral frames one cell across
   with 5-tetrahedra cells: +830 % with eta = 0). The averages (choices of this library):
       FRM_VOLUMETRIC_CELLS: mean dilatation, J_bar_s = sum_{t in c(s)} v_t J_t / V_c over
           the sample's cell (desc.sample_cells; frm_sampling_hexes / _tets fill
           frm_sampling.sample_cells and frm_sampling_apply sets it). For hexahedral frames
           with several samples a cell, or any grouping of samples the user gives (e.g. the 5
           tetrahedra of a hexahedral cell split).
       FRM_VOLUMETRIC_PATCHES: the same mean dilatation over patches that frm_model_create
           builds from the neighbour table alone (samples that share frames; no cells,
           no mesh needed): for one-sample tetrahedral frames of any mesh, where a
           tetrahedron is its own cell and CELLS would lock like the plain model. Greedy
           and serial (frm__volumetric_patches): a patch grows from a seed by the
           unassigned sample sharing the most frames with it (face neighbours first, ties
           to the lower index), within the seed's material, up to k =
           desc.volumetric_patch_size samples (default FRM_VOLUMETRIC_PATCH_SIZE = 12,
           at most FRM_VOLUMETRIC_PATCH_MAX = 64); the next seed is the finished patch's
           best candidate left (an advancing front: the samples' numbering matters
           little), and a patch left under ceil(k / 2) gives each sample to the
           neighbouring full patch it shares most frames with. Deterministic (any thread
           count), connected, one material each; k = 1 is the plain model plus the
           stabilisation. The bench's beam, 10 x 2 x 2 cells of five: patches of 12 to
           15, mean 12.5; create-time cost O(pairs x frame star) (a box of 160,000
           tetrahedra: creation 2.5-3.0 s against 2.35-2.5 s without the option, three
           runs each on the loaded Intel Xeon), 5 ints a sample of temporary memory,
           then the model holds what CELLS holds.
           Why 12 (k, then the bench's Poisson beam 3 cells across, error at nu = 0.3,
           0.45, 0.49, 0.499, double, static; tetrahedra in the mesh's grid order): k = 2
           +0.69, -3.95, -7.57, -9.31 %; 4 +0.75, -2.53, -4.11, -4.54; 6 +0.79, -2.12,
           -3.61, -4.03; 8 +0.81, -1.61, -2.73, -3.02; 12 +0.83, -1.31, -2.29, -2.55; 20
           +0.92, -0.30, -1.04, -1.25 (CELLS over each grid cell's 5: +0.81, -1.46, -2.51,
           -2.78; plain +0.64, -9.5, -13 at 0.3, 0.49, 0.499). Larger patches hold fewer
           volume constraints (a tetrahedral mesh has 5 to 6 tetrahedra a frame, so k =
           12 leaves about one constraint per two frames, 12 degrees of freedom) and lock
           less, but leave more of the J field to the stabilisation alone and turn soft on
           coarse meshes: on the 0.5 m beam 2 cells across of tests/test_frames_elem.c,
           tetrahedra shuffled and inner nodes moved, k = 20 gives +0.11 % at nu = 0.3 and
           +8.6 % at 0.499 (above the answer), k = 30 +13 %, k = 12 -0.40 and -1.85 %, k =
           8 -0.68 and -8.21 %. Of the sizes measured (2 to 30), 12 is the largest that
           never went above its nu = 0.3 answer by more than a point on these beams; the patch shapes move the
           answer by a few points (the bench's beam with the tetrahedra shuffled: k = 12
           +1.14, +1.68, +1.10, +0.90 %, k = 8 +0.96, -0.54, -1.79, -2.17 %; 2 cells
           across in grid order: k = 12 +3.96, +2.09, +0.87, +0.53 %, CELLS(5) +3.91,
           +1.44, +0.03, -0.43 %). The stabilisation moves all four answers alike, not the
           gap (k = 12, 3 cells across: eta = 0.5 +3.55, +1.15, +0.28, +0.06 %; 1 +2.35,
           +0.04, -0.88, -1.11 %; 4 -0.87, -2.81, -3.88, -4.17 %: 3.3 to 3.5 points from
           nu = 0.3 to 0.499 for every eta), so the default stays 2.
       FRM_VOLUMETRIC_FRAMES: nodal averaging through the frames, J_i = sum_t v_t w_ti J_t /
           m_i at frame i (m_i = sum_t v_t w_ti > 0, else FRM_ERR_VOLUMETRIC), J_bar_s =
           sum_i w_si J_i (Bonet & Burton 1998's average nodal pressure tetrahedron, in
           F-bar form): any neighbour table with weights >= 0, e.g. one-sample tetrahedra.
   All are A = B N over entries e (the pairs, or one a sample): y_g = sum_{e of g} to_e
   x_{sample e}, (A x)_s = sum_{e of s} back_e y_{group e}, and A^T the same with back and
   to swapped, run serially in entry order (deterministic; O(entries)).
   Forces (minus the gradient, exact): with dJ/J = e = F^-T : dF, dJ_bar / J_bar = e_bar,
   dF_bar = alpha (dF + (e_bar - e) / 3 F) and pi~_s = P(F_bar_s) : F_bar_s / 3 + eta mu_s
   ln(J_bar_s / J_s),
       dE = sum_s v_s [alpha_s P_bar_s : dF_s + pi~_s (e_bar_s - e_s)],
   and since sum_s v_s pi~_s e_bar_s = sum_t J_t e_t Q_t with Q = A^T (v pi~ / J_bar), every
   sample's stress is
       P_s = alpha_s P(F_bar_s) + beta_s F_s^-T,   beta_s = Q_s J_s / v_s - pi~_s,
   which then enters the force (eq. 3.52) and the rest of the model as P did: the force pass
   runs F and J per sample, the average, the law at F_bar, the transposed average, then
   the pairs. Differential, exact (the averaging couples the samples of a cell, or through
   the frames the samples two frames apart):
       dP = alpha dP_bar + (dQ J / v - dpi~) F^-T
            + alpha (e_bar - e) / 3 P_bar + (beta + pi~) e F^-T - beta F^-T dF^T F^-T,
       dP_bar = the law's dP at F_bar for dF_bar,  dpi~ = (dP_bar : F_bar + P_bar : dF_bar) / 3
            + eta mu (e_bar - e),  dQ = A^T (v (dpi~ - pi~ e_bar) / J_bar),
   so K v is also five passes (dF and e, the average, dP_bar, the transposed average, dP
   and the pairs). K's positive-definite part (SOLVERS) keeps the Gauss-Newton part
   L^T (C_bar+ + eta mu) L of the map L: dF -> (dF_bar, dphi) (the law's definite
   tangent at F_bar, the positive part of S_bar), i.e. it drops P_bar : dF_bar, pi~ e_bar,
   the (e_bar - e) P_bar, (beta + pi~) e and beta dF^-T terms. Tested against finite
   differences of an energy the test computes itself, for every law and every average,
   rotations and the stabilisation included (tests/test_frames_elem.c test_vol_*).
   Patch test: a homogeneous deformation (the frames' interpolation reproduces it) gives
   every sample J_bar = J, F_bar = F and the forces of the plain model to 1e-15; rigid
   motions far from the origin give zero force. The model is matrix-free with the option
   (AUTO takes pairs, FRM_STIFFNESS_BLOCKS is refused: the averaging couples frames beyond
   the block pattern); the block-Jacobi preconditioner keeps the plain law's rest
   diagonal. Memory: about 70 reals per sample and 3 per pair (entry) more. Cost, one run
   on a loaded machine, the bench's beam 3 cells across: force pass 1.4-1.7x (hexahedra),
   1.35x (tetrahedra), K v 1.45x and 1.5x.
   Measured (the bench's Poisson beam: 1 m, 0.1 m square, E = 1 MPa, Timoshenko; static
   Newton, CG iterations summed, the minimum check's probe solve included):
       hexahedral frames, CELLS, 3 cells across (2,976 DoF): +0.70, -0.38, -0.50 % at nu =
           0.3, 0.49, 0.499, Newton 3, 6, 9, CG 1,512, 6,221, 17,404 (plain: +0.42, -18.9,
           -40.6 %, CG 1,553, 2,907, 14,156); 2 cells across (1,134 DoF): +3.06, +3.10,
           +2.99 %, Newton 3, 6, 10, CG 1,016, 4,092, 10,672 (plain +2.44, -21.2, -47.5 %);
       one-sample tetrahedral frames (the 5-tetrahedra split), 3 cells across: FRAMES +8.7,
           -4.2, -7.1 % (plain +0.64, -9.5, -13 %: the nodal average about halves the locking,
           it does not remove it, see LIMITS), CELLS over each grid cell's 5 tetrahedra
           +0.82, -2.49, -2.76 %; 2 cells across FRAMES +20.5, -2.5, -7.5 %, CELLS(5) +3.9,
           -0.02, -0.42 %; PATCHES (default 12, no cells given) 3 cells across +0.83,
           -2.29, -2.55 % (tetrahedra shuffled: +1.14, +1.10, +0.90 %), 2 cells across
           +3.96, +0.87, +0.53 %. The bench's NI scene (the same beam at nu = 0.499, 10k x
           k x k cells; one run, Intel Xeon 2 vCPUs shared with 6 other jobs): PATCHES
           +0.53, -2.55, -3.15 % at k = 2, 3, 4 in 2.2, 19.5, 73 s, CELLS(5) +0.43, -2.78 %
           at k = 2, 3 in 1.1, 21.5 s, plain -15.5, -13.5, -11.8, -9.3 % at k = 2, 3, 4, 6.
   nu = 0.499 no longer stalls or locks with hexahedral frames, nor with one-sample
   tetrahedral frames with CELLS(5) or PATCHES (within 3.4 points of nu = 0.3's error on
   the bench's beam 3 cells across, against 13.6 points plain); its CG iterations grow
   with the bulk-to-shear ratio (block Jacobi does not precondition the averaged
   constraint): 17,404 against 1,512 at nu = 0.3 above (tetrahedral frames, PATCHES, the
   short beam of tests/test_frames_elem.c: 2,812 against 490).

   MASS (the thesis leaves it open; our derivation). Each sample's mass m_s = rho v_s is
   split among its frames in the fractions mu_is = |w_is| / sum_k |w_ks|, and each frame
   sees its shares as points rigidly attached to it: the kinetic energy
       T = 1/2 sum_s m_s sum_i mu_is |xdot_i + omega_i x a_is|^2
   bounds the interpolated field's 1/2 sum_s m_s |sum_i w_is (xdot_i + omega_i x a_is)|^2
   from above (Jensen, weights >= 0) and equals it for every rigid motion, since then all
   frames predict the same sample velocity. So the frames carry the body's mass, mass
   centre and inertia tensor exactly. Each sample is a ball of its volume (its own
   inertia 2/5 m r^2), which keeps every block positive definite. Per frame, world axes:
       M_i = [m_i I, -[c_i]x; [c_i]x, J_i],   m_i = sum_s mu m,  c_i = sum_s mu m a,
       J_i = sum_s mu m (|a|^2 I - a a^T + 2/5 r_s^2 I),
   rotated with the frame (c = R cbar, J = R Jbar R^T), evaluated at the start of each
   step (gyroscopic terms neglected). Gravity uses the signed weights, m_gi = sum_s w m,
   c_gi = sum_s w m a: it is the exact weight of the interpolated samples, a force m_gi g
   and a torque c_gi x g per frame.

   SOLVERS
       Static (sec. 3.6): Newton iterations K dq = f on the free frames (f the total
       force), each by two-level preconditioned CG (below) stopped at an Eisenstat-Walker
       relative residual (1e-3, then as fast as the residual falls, never below
       cg_tolerance, never tighter than the step can use), then a backtracking Armijo line
       search on the total potential (elastic + gravity - f_ext . dq; constant torques have
       no potential, their work along the step is exact); where the potential's change is
       below its round-off the trial must lower |f| instead. Indefinite linearisations
       (compressed samples, the rotations' second-order terms, gravity's torque on frames
       whose samples hang above them): when CG meets non-positive curvature, or its step
       is not a descent direction, the iteration is solved again with K's positive-definite
       part (below; frm_stats.definite_solves counts them), which always gives a descent
       direction. A line search that finds no decrease fails the iteration (it never takes a
       step that raises the potential). Converged when |f| <= newton_tolerance * max(|load|,
       |reactions|) at the returned state (|f| over the free components; the load: gravity
       and external forces on them; the reactions: the total force on the held components,
       i.e. fixed and driven frames and held axes; under pure displacement control the
       reactions are the scale), or when |f| is below the round-off floor (64 eps times the
       size of the partial forces it sums, plus K times one ulp of the displacements) and a
       further Newton iteration no longer halves it (below the floor the 2-norm does not
       tell how far the soft modes are: a slender steel beam in float has a floor above its
       load). frm_stats.residual is |f| over that scale (residual_force: |f| itself).
       Continuation: the solve first tries the whole load (gravity and external loads
       scaled by lambda, driven frames moved lambda of the way from their starting poses,
       along the rotation for orientations) in one increment; an increment whose Newton run
       fails (cap, no decrease, an increment whose residual has not halved in 15
       iterations: FRM_ERR_STALLED, a non-finite or inverted trial, a sample newly
       inverted) restarts from its starting state at a quarter of its size
       (frm_stats.increment_cuts), an increment that converged in 6 Newton iterations or
       fewer doubles the next; intermediate increments converge to 1e-3 (or
       newton_tolerance if tighter), the last one to newton_tolerance. The solve gives up
       (the last attempt's code, state kept) below min_increment (default 1e-4 of the
       load) or after max_increments attempts (default 64). A CG solve at its cap fails at
       once (smaller increments do not help it). Acceptance before success: the residual
       test above, every value finite, no sample inverted (det F <= 0: both laws refuse it), the
       precision check; frm_stats.negative_curvature counts the CG solves that met
       non-positive curvature (each then redone with K+, below). And the answer must be a
       minimum (issue 18): a zero residual holds at saddles too, such as a squashed cube's
       symmetric state past its bifurcation (LIMITS). A probe solve K x = b with the full
       tangent at the answer (b a fixed pseudo-random vector on the free components, CG to
       1e-7, float 1e-5) meets a direction p of negative curvature where K is indefinite;
       p . K p below -1e3 eps sum_k |p_k (K p)_k| (its round-off) fails the solve with
       FRM_ERR_UNSTABLE, state kept. It costs one more CG solve per static solve (R1's
       25 x 5 x 5 frames: 2,574 CG iterations before, 6,263 with the probe; a probe at its
       cap counts as a minimum). Hold the symmetric components (frm_model_set_frame_axes)
       or nudge the state and solve again to reach a minimum. Held axes' values (and
       the rest of the state) are the starting point: they are not continued.
       What it caught (measured, bench R1 with one-sample tetrahedral frames, 32 k x k x k
       cells): in double at k = 3 the bench (-O3 -ffp-contract=fast) got FRM_ERR_UNSTABLE
       where float solved. A correct refusal of a wrongly built model: the rotation
       stabilisation's second moment, then sum(y y^T)/n - mean mean^T, kept in a fused
       multiply-add the rounding error of y y^T, so the beam's corner frames (one sample
       each) had one random axis stabilised instead of three, and gravity's torque made
       the tangent indefinite (a banded LDL^T of the probe's operator at rest: one negative
       pivot, -1.2 N m against pivots up to 1.4e11; none without contraction, smallest
       1.05e6); Newton took 19 iterations with 18 positive-definite fallbacks instead of 3.
       Float built the model right (products of float coordinates are exact in double).
       Fixed at the moment (centred sums; tests/test_frames.c test_unseen_rotations_exact):
       3 Newton, 179 CG, a minimum, as without contraction. Not fixed, float's precision
       limit: at k = 6 (56,742 dof) float's K v carries more round-off than the beam's
       soft modes have curvature (k = 4: 6 Newton, 305 CG; k = 6: 8 Newton, 39,643 CG, its
       linear solves meeting "negative curvature" in the positive-definite part too and
       ending with relative residuals of 24 and 97 after 2,557 and 23,424 iterations;
       double at k = 6: 3 Newton, 293 CG, a minimum), so the float solve takes minutes and
       its probe can call round-off a saddle: p . K p / sum |p_k (K p)_k| = -2.35e-4 against
       the threshold 1.2e-4 (FRM_ERR_UNSTABLE after 8 Newton iterations, gcc -O3
       -march=native -ffp-contract=fast, this revision and the one before it alike; the
       bench's run at revision 59471d0 returned success, tip 0.15105 m, in 64 s). The
       allowance's scale sum |p_k (K p)_k| underestimates the round-off of K p where K p
       cancels (soft modes): against sum K_kk p_k^2 the same p . K p is -8.6e-10, far
       inside float's round-off. Not done: an allowance on that scale would also pass a
       genuine saddle that shallow, which float cannot tell apart; FRM_ERR_PRECISION there
       may be the honest answer. Float's accepted answers on this beam are limited the
       same way: at k = 4 its end-face sag is 0.75 % (St Venant-Kirchhoff; Neo-Hookean
       0.02 %; k = 3: 0.001 %, 0.08 %) off double's for the same model, its relative
       residual stopping at 2.6e-3 on the round-off floor. Use double for a stiff, slender
       body that fine.
       static_regularization (default 1e-10; 1e-6 at least in the positive-definite
       attempt) adds that fraction of |K_ii| to each frame's rotational diagonal inside CG
       only: the forces and the equilibrium are unchanged. Keep it small: a slender beam's
       softest bending mode sits near 1e-7 of the diagonal, and 1e-6 made Newton linear.
       Implicit Euler (eq. 3.64) with Rayleigh damping D = alpha M + beta K, by default as
       the minimisation of the step's incremental potential over the step's displacement
       dq (translation, rotation vector from the start orientation), v = dq / dt:
           Psi(dq) = 1/2 |dq - dt v_t|_M^2 + dt/2 dq^T D dq + dt^2 (W + V_g - f_ext . dq),
       whose stationarity is M (v - v_t) = dt (f - D v). Newton iterations
           (M (1 + dt alpha) + (dt^2 + dt beta) K) delta_v = r,   r = dt f - M (v - v_t) - dt D v,
       each followed by a backtracking Armijo line search on Psi (the damping's K frozen at
       the iteration's linearisation), until |r| <= newton_tolerance * max(|r_0|, dt
       |load|, dt |reactions|), r_0 the residual at the step's start (frm_stats.residual
       is the ratio), at most newton_max_iterations (else FRM_ERR_NO_CONVERGENCE, state
       kept). So a step lowers its own objective at any dt, E and nu (measured: one step of
       1e3 s from rest lands on the static solution to 1e-4 with a soft beam sagging 19 %
       of its length; the single linearisation lands 2.9 % off). The first iteration is
       exactly the linearised step below. M is taken at the step's start. Driven frames
       are put at their targets before the first iteration; velocities are dq / dt (q =
       exp(dt omega) q_t renormalised: |q| = 1 to round-off for ever). If CG meets
       non-positive curvature (M + dt^2 K indefinite: a large dt on a stressed body), the
       iteration is solved again with K's positive-definite part, with which the system is
       positive definite at any dt. Cost: usually 2 to 3 linear solves a step where the
       linearised step makes one (tests/test_frames.c's R3: 2.9 times the time).
       implicit_linearized = 1: the thesis's single linearisation per step,
           (M (1 + dt alpha) + (dt^2 + dt beta) K) dv = dt (f - (dt + beta) K v - alpha M v),
       then v += dv, x += dt v; driven frames reach their targets in the step and enter the
       right-hand side through K; the CG starts from the previous step's dv. Stable at any
       dt (with the positive-definite fallback) but accurate only while a step changes K
       little: under large deformation per step (soft bodies, large dt, nu near 0.5) its
       result is not the implicit Euler step (2.9 % off the static answer above at dt =
       1e3 s) and nothing reports it.
       BDF2 (desc.integrator or frm_model_set_integrator FRM_BDF2, issue 19): second order,
       A-stable and strongly damping at large h omega (no high-frequency ringing, no energy
       growth on nonlinear problems, unlike the average acceleration or the implicit
       midpoint rule, which conserve energy only for linear problems), and variational: with
       beta = 2 dt / 3, xbar = (4 x_n - x_{n-1}) / 3 and vbar = (4 v_n - v_{n-1}) / 3,
           x_{n+1} = argmin 1/2 |x - xbar - beta vbar|_M^2 + beta/2 |x - xbar|_D^2
                            + beta^2 (W + V_g - f_ext . x),   v_{n+1} = (x_{n+1} - xbar) / beta,
       implicit Euler's incremental potential with (beta, xbar, vbar) for (dt, x_n, v_n):
       the same Newton iterations, line search and acceptance run on it (frm__step_target),
       over z = x - xbar. Orientations: in the step's tangent coordinates at q_n (world-axis
       rotation vectors, implicit Euler's), x_{n-1} is phi = log(q_{n-1} q_n^*), so xbar -
       x_n = -phi / 3; the world angular velocities serve as coordinate velocities (they
       differ by phi x omega / 2 at q_{n-1}: second order in the rotation over a step,
       neglected, as are the gyroscopic terms and the mass's turn over the step; the scheme
       is second order for the frames' translations and for small rotations per step, the
       elastic vibrations, first order in those terms for frames spinning fast). History:
       the model keeps the start state of its last successful step (x, q, v one step back,
       13 reals a frame, carved at creation: nothing allocates). The first step after
       creation, after frm_model_set_poses / _set_velocities / _fix_frame / _release_frame /
       _set_frame_axes / _set_integrator, a static solve or Newton step, driving a frame that
       was not driven (a new target of a driven frame keeps it), and any step whose dt
       differs from the history's, is one implicit Euler step, and so is the step after a
       failed one (which keeps the state; as in heml.h and tensormass.h). Measured (tests/test_frames.c test_i19_oscillator_decay: a one-degree-of-
       freedom oscillator of frames; amplitude decay a period, period error), against the
       closed-form roots to 4 digits:
           dt       implicit Euler           BDF2
           T/20     0.621   +3.21e-2         0.0395    +3.02e-2
           T/50     0.325   +5.24e-3         3.01e-3   +5.18e-3
           T/100    0.179   +1.31e-3         3.86e-4   +1.31e-3
           T/400    0.0481  +8.23e-5         6.09e-6   +8.22e-5
       (implicit Euler's phase is second order too; its amplitude is first order, BDF2's
       decay a period falls as dt^3). Tests: the model against BDF2's discrete recurrence
       with Rayleigh damping (3.8e-8), order 2 on a damped beam (changes of u(T) fall 3.84
       times a halving; implicit Euler 1.85), bit-identical threads, history restarts, the
       stress sweep. The R3 beam's first mode (tetrahedral frames one cell across, 0.4480
       Hz by frm_modal), released along its shape (tests/test_frames_elem.c
       test_modal_r3_time_order): decay and period error equal the oscillator's figures
       above to 5 digits for both schemes, rotations included (the modal coordinate is an
       exact one-degree-of-freedom oscillator in the linear regime); period error / 3.93
       from T/40 to T/80 with BDF2. The R3 beam (10 x 2 x 2 hexahedral cells, released from a 0.15 mm
       sag; period from zero crossings against BDF2 at T/1600, 1.98766 s): implicit Euler
       +3.19, +0.52, +0.11 % at T/20, T/50, T/100, BDF2 +3.03, +0.47, +0.11, +0.005 % at
       T/20..T/400 (the crossings' floor is about 0.03 %: the higher modes that BDF2 keeps);
       bench/bench.c's time part (issue 19) measures both on the bench's beams. Same cost
       per step as implicit Euler (one more vector update).
       Held axes (frm_model_set_frame_axes): the held components are projected out of every
       linear solve (right-hand side, iterates, products and the block-Jacobi blocks), the
       line search and the step update; their velocity is zero; their forces count as
       reactions in the residual's scale.
       Preconditioner (issue 21): two levels. The fine level is block-Jacobi (the inverse
       6x6 diagonal blocks); the coarse level adds P A_c^-1 P^T, with the frames binned
       into at most desc.coarse_aggregates (default FRM_COARSE_AGGREGATES = 32) cells of
       their rest bounding box, at least FRM_COARSE_MIN_FRAMES (8) frames each, and 9
       modes per aggregate: its translation t, its rigid rotation omega (frame i moves by
       t + omega x (x_i - c), turns by omega) and the frames' own rotation phi (turns by
       phi, does not move). The last is the one slender and stabilised bodies need: a
       field of frame rotations that moves no material costs only the stabilisation's
       h^2 energy, so block-Jacobi resolves it slowest, and rigid modes alone gained only
       2-3 times (measured on R1). A_c = P^T (a_mass M + a_stiff K) P is the exact Galerkin
       product of the linearisation (rotation stabilisation and held axes included, the
       coupling term left out), from the assembled blocks in block mode (about 150
       multiply-adds a block) or a per-sample pass in pair mode (9 sample products per
       aggregate the sample touches), dense and Cholesky-factored in double, a pivot at or
       below 1e-10 of its diagonal dropping its mode; built at the first CG iteration after
       each linearisation, serially in a fixed order (bit-identical for any thread count),
       in the model's block (no allocation: (9 A)^2 doubles, 663 kB for 32 aggregates).
       Static solves always use it; solves with mass (implicit steps, shifted modal
       solves) once a solve by block-Jacobi alone needed FRM__COARSE_MIN_ITERATIONS (40)
       or met cg_max_iterations (that solve is then continued with it): below that the
       build (about ten products) costs more than it saves (float builds: only after a
       solve met the cap; with it, a float implicit step of a tetrahedral plate one cell
       thick met round-off curvature at 8e-4 relative residual and failed, tests/
       test_frames.c test_i14_thin_plate). coarse_aggregates = 0 gives
       block-Jacobi alone. Measured (issue 21; one core, gcc -O2 -march=native, CPU time;
       R1 16 x 0.5 x 0.5 m steel cantilever, 32k x k x k cells, clamped, own weight), CG
       iterations of the first Newton solve (to 1e-3) with / without the coarse level (64
       aggregates; the default 32 measured 60 against 57 at k = 4):
           hexahedral frames, 2^3 samples a cell:
             k = 1 (132 frames) 35 / 424, k = 2 (585) 36 / 579, k = 3 (1,552) 45 / 829,
             k = 4 (3,225) 57 / 1,097, k = 6 (9,457) 78 / 1,637
           tetrahedral frames (6 a cube), one sample each:
             k = 1 138 / 1,545, k = 2 61 / 2,125, k = 3 67 / 3,094, k = 4 81 / 4,101
       so within 3x of the smallest mesh's count as the frames grow 72x. The whole static
       solve (Newton and the minimum check's probe solve): hexahedral k = 3 (1.7 % off
       R1's 3D solid) 0.92 s against 2.48 s CPU, k = 4 (0.91 %) 2.45 s against 9.9 s,
       k = 6 (0.39 %) 13.3 s against 59 s; tetrahedral k = 4 0.61 s against 5.6 s. The
       probe (CG to 1e-7 from a pseudo-random right-hand side) is now most of the hexahedral
       solve: 1,112 of 1,233 iterations at k = 4 (it excites the stabilised rotation modes of
       every wavelength, which no coarse mode holds). Implicit Euler on the same beam (k = 2,
       five steps and creation, CPU, default 32 aggregates): steel at dt = 1 ms, 10 ms,
       0.1 s 0.40 / 0.48 s, 0.66 / 1.02 s, 0.64 / 1.36 s (with / without; the last step's
       solves 42 / 355, 66 / 1,282, 68 / 1,968 CG iterations); E = 1 MPa: dt = 1 ms and
       10 ms need under 40 iterations (it stays off: same time), at dt = 0.1 s it turns on
       and breaks even (0.72 against 0.70 s; 87 against 233 iterations; 64 aggregates
       lost 30 %: its Cholesky each Newton iteration), see LIMITS.
       One CG policy: a linear solve stopped at cg_max_iterations above its tolerance fails
       the step or solve (FRM_ERR_NO_CONVERGENCE, state kept; stats.cg_residual tells how
       far it got); a non-finite |b|^2 or iterate is FRM_ERR_NOT_FINITE.
       K's positive-definite part K+: the material term (positive for SVK; Neo-Hookean with
       2 (mu - lambda ln J) kept >= 0; Mooney-Rivlin and user laws as they are, so their
       first static iterations may meet negative curvature), the geometric term dF S with the positive part of
       S, each frame's own rotational term (its pairs' derivative of B through the frame's
       rotation, gravity's torque, the coupling's and the stabilisation's second-order
       parts, summed) replaced by its positive part, and the stabilisation's Gauss-Newton
       part: a sum of positive semi-definite terms, equal to K on a stress-free state
       without gravity.
       Preconditioner: 6x6 block Jacobi, the inverse of a_M M_i + a_K K_ii per frame
       (Cholesky; V |Lambda|^-1 V^T from its eigen-decomposition if a block is not positive
       definite). In block mode K_ii is exact; in pair mode it is the rest state's, turned
       with the frame (T K_rest T^T, T = diag(Q, Q)), plus the current frame-own rotational
       term: exact for rigid motions, an approximation under strain, and free where the
       exact blocks cost about 25 CG iterations.

   SHAPE FUNCTIONS AND SAMPLING (sec. 4.1)
       frm_shape_tet: barycentric (4 neighbours). frm_shape_hex: trilinear (8), gradients
       through the inverse Jacobian. frm_shape_shepard: 1/d^p (eqs. 4.8-4.9, or the
       Franke-Little ((R - d)+ / (R d))^p with a radius), any layout of frames, zero
       order. frm_shape_mls: linear moving least squares, Wendland C2 kernel, first order
       (reproduces linear fields), needs 4 frames not coplanar in its radius. All sum to
       one with gradients summing to zero, and are tested against finite differences.
       Mesh-based sampling puts frames at the nodes and samples at chosen points of each
       element with the element's volume split over them: sub-cell centres or Gauss
       points in hexahedra, centroid, the 4-point Gauss rule or any barycentric points in
       tetrahedra. Meshless sampling: Poisson-disk points (Bridson 2007, then a fill pass
       that seeds every empty cell, so thin and separate parts get points) inside a box
       (an axis may be flat) or a closed triangle surface (parity of a +z ray, triangles
       binned by their xy boxes, shared edges counted once), frames from a coarser
       distance than samples, the volume split evenly; the k nearest frames or all within
       a radius (a grid search). The same seed gives the same points everywhere.
       Curves (frm_sampling_curve, issue 14): frames at the nodes of a polyline, weights
       linear along each segment (1/2 each at its midpoint, gradients -+ t / l), one
       station a segment (the reduced rule: two Gauss stations lock the rod's shear) with
       4 samples across the section (2 x 2 Gauss points of a rectangle, or a disk's 4
       points at r / sqrt 2): an off-axis sample sees its frames' rotations through the
       lever, so bending strain linear across the section is integrated exactly. The
       frames carry rigid sections (no lateral contraction): frm_material_thin(m, 1) gives
       the law whose lambda' + 2 mu = E with mu kept, so the rod bends with E and shears
       with G. frm_material_thin(m, 2) gives a layer one element thick the plane-stress
       modulus (lambda' = 2 mu lambda / (lambda + 2 mu)) its constant through-thickness
       strain cannot give it. Measured: LIMITS, thin parts.

   PERFORMANCE
       Bytes each kernel streams per (sample, neighbour) pair, double (float about half):
           force pass (frm_model_forces)         pass 1 reads 60 (index, weight,
               gradient, rest lever) and writes 48, pass 2 reads 52: 160; linearising
               (before a solve) writes 120 more (G, Hs), 168 with the coupling term.
           K v, pair mode (matrix-free)           pass 1 reads 100 (index, gradient,
               G) and writes 48, pass 2 reads 52: 200, plus the sample's F, S (and the
               Neo-Hookean tangent) over its neighbours, 15 to 45 a pair; 48 more with
               the coupling term. About 120 flops a pair. The derivative of B through a
               frame's own rotation (the pairs' Hs) is summed per frame at the
               linearisation and applied in pass 2 (6 reals a frame).
           K v, block mode                        292 per 6x6 block (36 reals and a
               column index), about 0.5 block a pair with 8 neighbours (hexahedra), 0.2
               with 4 (tetrahedra).
       Within a Newton iteration or a step the linearisation is fixed, so both modes
       prepare once: the pair mode stores G and Hs per pair in the force pass; the block
       mode assembles row by row (about 1 us a pair with 8 neighbours). Measured on the
       development machine (a shared 2-core AMD EPYC VM at 2.45 GHz streaming 17.5 GB/s,
       one core, double, gcc -std=c99 -O2; examples/frames_beam.c and a timing harness on
       the thesis cantilever, 25 x 5 x 5 frames, 24576 pairs):
           force pass 42 ns a pair; K v pair mode 28-42 ns a pair (20.6 with -O3
           -march=native); K v block mode 7-8 ns a block, 3.6-4 ns a pair; assembly
           0.8-1.7 us a pair; so blocks pay off after 4 to 25 CG iterations.
       The rotation stabilisation's divergence term (default on, issue 18) adds to these: on
       the same beam, in one run on a loaded machine, force pass 82 against 48 ns a pair
       and K v pair mode 59 against 28 ns with and without it (tetrahedra, one sample each,
       4 neighbours: 93 against 74 and 48 against 41 ns); block products unchanged.
       On the reference machine of REFERENCES.md (4.2 GHz, 40 GB/s) expect about half.
       Float and subnormal numbers (issue 21): at the bench's kernel state (a clamped cube
       after one step of 10 us under gravity) the float force pass took 400 to 1300 ns a
       pair on an Intel Xeon (Sapphire Rapids class, KVM) against 35 to 38 in double: the
       quaternions held components of 1e-18 to 1e-29 (rotations about axes the load
       leaves alone) and their products, and the strains' and stresses' products after
       them, were subnormal, which Intel's cores compute by microcode assists (the AMD
       Zen 5 at full speed: 52-62 ns). Float builds now flush what lies below eps^2 of its
       scale (FRM_TINY, >>kernels). The bench's rows on that machine (build/bench/bench
       --parts kernels --filter "svk hex8/float", old and new code alternated, minima of
       3 rounds, load about 2 on its 2 vCPUs), 1,728 to 1e6 pairs: force 405-538 ->
       33.7-37.3 ns a pair (double 30.2-41.2, unchanged), K v 62-73 -> 15.4-19.6 ns; an
       implicit step of the cube at 1,728 pairs 17-25 -> 2.3 ms (double 2.4); float's
       difference from double unchanged (forces 1.4e-4 of the largest at that state,
       2e-6 after 20 steps of 1 ms, before and after); double builds unchanged bit for
       bit. The linearisation (prepare, assembly) and the implicit residual's conversion
       still meet a few subnormals at that state (the stabilisation's F T^T, frames that
       barely move); they cost nothing measurable. The library never sets FTZ/DAZ (the
       caller's floating-point environment is the caller's).
       FRM_STIFFNESS_AUTO assembles when the previous solve's iteration count (50 before
       any) times the pair mode's cost exceeds the assembly plus the block products
       (measured per-item costs above): with 8 neighbours, beyond about 30 iterations.
       Thesis figures on this machine (one core): 72 frames, 400 samples, 4 neighbours,
       50 CG iterations a step: 3.3 ms a step matrix-free, 1.6 ms by blocks (thesis:
       32.65 ms, Xeon W3520); 34,610 samples, 4 neighbours, 60 iterations: 402 ms
       matrix-free, 139 ms by blocks (thesis: 3468 ms CPU, 66.1 ms on a GTX 570).

   ACCURACY (tests/test_frames.c prints these)
       R1, steel cantilever, 25 x 5 x 5 frames, sub-cell samples: +0.21 % of Timoshenko,
       +0.49 % of the 3D value 0.150169 m (before the divergence term: +0.39 % / +0.67 %);
       float +0.17 % of Timoshenko (+0.16 % before); with Gauss points -1.7 % (Poisson locking of 4
       cells across). Hexahedral frames one cell across (32 x 1 x 1 cells, which stalled
       before): +20.4 % of the 3D value, two cells across (64 x 2 x 2) +4.1 %
       (tests/test_frames_elem.c): one cell is soft, as with tetrahedral frames.
       Tetrahedral frames with one sample per tetrahedron (the bench's tet4 body, 5
       tetrahedra a cube, rotation stabilisation on): R1 on 32k x k x k cells +32.9 %,
       +6.1 %, +2.5 %, +1.3 % of the 3D value for k = 1, 2, 3, 4 (+33.4, +6.2, +2.5, +1.4 %
       before the divergence term), float within 8e-4 of double at k = 2 and 4e-4 at k = 4
       (2e-4 before: float's Newton stops on the round-off floor a little earlier);
       the R3 beam's static sag +29 % and +4.6 % of beam theory at one and two cells
       across (+30 % and +4.9 % before; soft at one cell: the frames' rotations let a
       single tetrahedron bend). Its lowest modes: see MODEL, rotation stabilisation.
       R2, soft cantilever, 4-neighbour frames (tetrahedra) at h = 1, 1/2, 1/3 m: 5.225,
       6.112, 6.319 m (5.289, 6.132, 6.327 before), order 1.6, limit 6.54 m, about 45,000 DoF
       for 1 % of it. Hexahedral frames (stalled before at every resolution): 7.203, 6.656,
       6.569 m at 16 x 1 x 1, 32 x 2 x 2, 48 x 3 x 3 cells.
       R3, beam frequency from the implicit dynamics, 11 x 3 x 3 frames: -0.69 % of
       Timoshenko (-0.96 % before).
       A 180 degree torsion of a 10-frame Shepard bar (thesis fig. 4.11) spreads linearly
       to within 3.5 degrees; a coplanar Shepard sheet under 300 N (fig. 4.10) converges.

   LIMITS
       - Invisible rotations. (a) A frame whose samples are collinear (or a single one) has
         a rotation they do not see at first order; under stress it buckles (see MODEL).
         With one sample per tetrahedron every edge frame of a mesh is such a frame. The
         default rotation_stabilization (0.5) holds exactly those; with 0 (the thesis's
         model) static solves of stressed bodies fail or end in the buckled minimum (R1
         one cell across: 0.04 rad of spurious rotation, 78 % too much sag). (b) Rotations
         that move no material collectively: on tensor-product hexahedral grids a layer of
         frames normal to an axis turning about it (zero energy), with one sample per
         tetrahedron the frames turning slowly about a beam's axis (spurious modes below
         the first bending mode at every resolution). The default rotation_divergence (4)
         holds them (see MODEL): hexahedral frames one cell across and R2 now solve, the
         tetrahedral frames' R3 beam has no mode below its bending modes. What remains:
         hexahedral frames one cell across keep frame-rotation modes above the first
         bending mode but below the second (0.64 and 1.75 Hz on R3, bending 0.47 and
         2.82 Hz; 1.75 Hz does not depend on gamma), and bend 20 % too soft on R1 (4 % at two
         cells across); at coarse resolution the divergence term stiffens the tetrahedral
         frames' torsion (R3 at two cells across: 4.85 Hz against 4.44 Hz without it, 3D
         4.51 Hz; of order h^2). With rotation_divergence = 0 (the thesis's model) static
         solves of hexahedral frames one cell across or in large deformation end in an
         error code (FRM_ERR_STALLED, or FRM_ERR_NO_CONVERGENCE once the load continuation
         has cut its increments to min_increment), never in a wrong success. Shepard samples (zero order)
         carry no divergence term (see MODEL).
         The stabilisation costs: on every sample with linear weights its force pass
         carries the term (measured +70 % on the hexahedral R1 beam, +26 % on tetrahedra)
         and the matrix-free K v about twice the time on hexahedra (+20 % on tetrahedra);
         assembled blocks are unchanged.
       - Homogeneous states are not exact: the frames' rotations enter F through
         sum_k w_k R_k, so free frames enrich the strain field beyond a compatible one and
         a coarse model is softer than the continuum even where every displacement field
         it needs is linear. Measured (issue 18): a unit cube of 2 x 2 x 2 hexahedral cells
         in uniaxial stress (symmetry planes, the top face held at stretch s) carries 11 to
         21 % less stress than REFERENCES R4 / R5 for s from 0.7 to 1.5 (18 % for St
         Venant-Kirchhoff at s = 1.1, 21 % for Neo-Hookean at s = 0.9; measured with
         test_i18_cube_uniaxial_load's cube_uniaxial in tests/test_frames.c).
       - Thin parts (issue 14). Measured with tests/test_frames.c (gcc -O2, double; the
         plate: 1 x 1 x 0.05 m, E = 1 GPa, nu = 0.3, Neo-Hookean, clamped along x = 0,
         its own weight; beam theory 5.89 mm, the 3D answer 5.54 mm by hexahedral frames
         4 cells thick, 16 x 16 x 4: 5.524, 32 x 32 x 4: 5.544 mm):
           hexahedral frames one cell thick, 2^3 sub-cell samples (test_i14_thin_plate):
             5.85, 6.12, 6.20, 6.22 mm at 4, 8, 16, 32 cells a side: converges, to +12 %
             of the 3D answer (+6 % of beam theory; at nu = 0 +31 %: 7.85 mm against
             5.98): the sub-cell rule under-integrates the layer and is soft;
           tetrahedral frames one cell thick (6 a cube), one sample each: 2.87, 5.47,
             7.54, 11.0, 13.3 mm at 4 to 64 cells: no limit (a centroid sees the layer's
             bending only through its offset from the mid-plane; refinement adds rotation
             modes it does not see). Use instead:
           tetrahedral frames one cell thick, 4 Gauss points (frm_sampling_tets(.., 4,
             NULL, ..)) and frm_material_thin(&material, 2) (test_i14_thin_tet): 1.43,
             3.13, 4.42, 5.05, 5.37 mm at 4, 8, 16, 32, 64 cells (0.01, 0.1, 0.5, 2, 8 s
             static on one core, Zen 5, loaded), monotone from below: the 4-point rule
             integrates the blended field's energy exactly (a conforming model), and its
             first-order extrapolation 2 t(n) - t(n/2) is 5.71, 5.69, 5.69 mm at n = 16,
             32, 64 (+3 % of the 3D answer). With the true material the limit is 15 % stiff (1.37, 2.90,
             3.96, 4.39, 4.58 mm): the layer's through-thickness strain is constant (a
             rotated vertical lever moves sideways only), so the bending's Poisson strain
             is held. What is still missing: the convergence is first order while the
             cells are wider than the layer is thick (at n = 16, -20 %; at 64, -3 % of the
             3D answer): the tetrahedra's transverse shear locks (the blended field
             bends with an O(h) shear strain costing about 12 G / E (h / t)^2 times the
             bending energy). Reduced rules that avoid it are soft instead: two samples a
             tetrahedron on the centroid's vertical at the layer's Gauss levels give
             3.53, 5.31, 6.21, 6.42 mm (limit about 6.5, +17 %; +32 % at nu = 0), for
             any rotation_divergence (measured 4, 16, 64); an assumed-strain treatment
             of the shear is not done. Mean dilatation (FRM_VOLUMETRIC_CELLS) does not
             remove the Poisson stiffening (it is not volumetric) and its solves are slow.
           a curve of frames (frm_sampling_curve, 2 x 2 section points, frm_material_thin(
             &material, 1); test_i14_curve) on REFERENCES R1: -6.33, -1.57, -0.40, -0.10 %
             of the rod answer (Euler-Bernoulli plus a rigid section's uniform shear,
             q L^4 / (8 E I) + q L^2 / (2 G A) = 0.150567 m) at 4, 8, 16, 32 segments,
             second order; 3D's 0.150169 m is 0.26 % below the rod (the clamp holds the
             section). Static solves in 3 Newton iterations, implicit steps keep the
             static state; R3's beam as a rod of 16 segments swings at 0.5082 Hz under
             implicit Euler (-0.18 % of the 3D 0.5091 Hz). With the true material 25.8 % too stiff ((1 - nu) / ((1 + nu)
             (1 - 2 nu)) = 1.346: the rigid sections hold the lateral contraction); with
             two Gauss stations a segment the sag is 67 % short at 16 segments (shear
             locking; measured with nu = 0).
             The rigid, unwarped section makes the torsion stiffer than the continuum's
             (a square's St Venant constant is 0.141 a^4, the rigid section's a^4 / 6:
             +18 %; a disk's is exact); not measured in a test. Meshless Shepard frames on
             a line stay inconsistent (zero-order weights: tip 0.65, 1.6, 3.1, 8.9 mm at
             4 to 32 frames against 5.9 mm).
         A thin slab loaded in its plane can buckle: Cook's membrane one element
         thick (48 x 44..60 x 1, E = 240.565 Pa, nu = 0.3) has no stable flat state beyond
         F = 2.05 N (hexahedral frames, 16 cells a side; 4.5 N at 4): at the usual F = 32 N
         the flat state is a saddle and, the load being symmetric about the mid-plane,
         Newton cannot leave the plane: the static solve refuses (FRM_ERR_UNSTABLE, or
         FRM_ERR_STALLED when the continuation wanders near the saddle; the stall message's
         "rotations the samples do not see" is then not the cause). Hold the out-of-plane
         axes for the plane problem (frm_model_set_frame_axes(m, i, 4, 3): test_i18_cook_membrane)
         or nudge it out of plane (1e-3 of the load) for the buckled one (corner u_y 7.8,
         11.8, 13.1 mm at 4, 8, 16 cells; 136 to 305 Newton iterations).
       - Models with volumetric averaging (desc.volumetric, issue 13) solve with
         block-Jacobi alone: the coarse matrix's per-sample pass does not know the cell
         averages (not measured; to do).
       - The coarse correction of implicit steps turns on after a solve needs 40
         block-Jacobi iterations; on soft bodies at large steps (E = 1 MPa beam, dt = 0.1 s,
         40 to 90 iterations a solve) it only breaks even (it is rebuilt every Newton
         iteration; reusing it across a step's iterations is not done); more aggregates
         lose there (64: 30 % slower than block-Jacobi alone).
       - Indefinite linearisations (compression, buckling, the invisible rotations above)
         make the static Newton fall back to K's positive-definite part, which converges
         linearly, not quadratically, while K stays indefinite.
       - Spurious frame-rotation branch of coarse hexahedral frames in strong compression
         (issue 18, measured). The bench sweep's cube (1 m, 2 x 2 x 2 trilinear cells, 8
         sub-cell samples each, bottom fixed, top driven down, nu = 0.45): squashed by
         half, Neo-Hookean, its symmetric equilibrium (the mirror symmetries the
         continuum's unique answer has; frames' rotations held at zero) has W = 348.09 J at
         E = 1 kPa, but it is a saddle of the frames model: two mirror images with the
         middle layer's frames turned up to 0.87 rad (0.67 rad from the mean material
         rotation of their samples) have W = 290.90 J, 16 % less, and are the model's
         minima (the minimum check finds no negative curvature there). St Venant-Kirchhoff
         squashed by a quarter: the symmetric state 0.038211 J is a saddle too, a tilted
         minimum 0.033747 J (0.54 rad). Before the minimum check (SOLVERS) the solves
         returned the symmetric saddles with success (SVK in one call, Neo-Hookean in 8
         increments in double); now they fail with FRM_ERR_UNSTABLE at the increment that
         reaches one, and a one-call Neo-Hookean solve in float ends on a tilted minimum
         with success: an answer of the model, mirror-asymmetric (25 % of the largest
         displacement), not of the continuum; no acceptance check separates it (the angle
         between a free frame and the mean material rotation of its samples is 0.43-0.67
         rad there and up to 0.62 rad in correct solves: tests/test_frames.c's uniaxial
         cube). rotation_divergence moves the branch (16: 293.4 J, 0.80 rad; 64: every
         solve stalls) but does not remove it at the default. At 4 x 4 x 4 cells the same
         squash returns FRM_ERR_STALLED in one call and in 8 increments (float; the
         symmetric state 280.50 J). Holding the free frames' rotations
         (frm_model_set_frame_axes, rotation mask 7; zero is what the symmetries impose
         here) gives the symmetric answer in 11 Newton iterations, one call and 8
         increments 2e-5 apart in float. tests/test_frames.c test_i18_squashed_cube
         measures it (its symmetry checks run with FRM_TEST_KNOWN_LIMITS set, and fail in
         float); test_i18_saddle_refused checks the saddle is refused.
       - Hexahedral frames with Gauss points lock in bending near incompressibility, like
         trilinear elements (R1: -1.7 % at nu = 0.3, -7.8 % at nu = 0.45 on 4 cells
         across); sub-cell samples lock less (-16 % at nu = 0.49 on the bench's 40 x 4 x 4
         beam, and no convergence at 0.499). Tetrahedral frames with one sample each lock
         less (-8 % at 0.49, -11 % at 0.499) but converge slowly (R2). The volumetric
         option (VOLUMETRIC AVERAGING) removes the volumetric locking of hexahedral frames
         (FRM_VOLUMETRIC_CELLS: within 1.2 points of nu = 0.3's error at 0.49 and 0.499 on
         the bench's beam 3 cells across). What it leaves:
         one-sample tetrahedral frames with FRM_VOLUMETRIC_FRAMES (nodal averaging) are
         still 7 % stiff at nu = 0.499 and 9-20 % soft at nu = 0.3 on the bench's beam at 3
         and 2 cells across: the average over frames smooths the J field over two rings of
         samples, and the frames' rotations give J fluctuations the average does not see
         (held by eta mu only); mean dilatation over each grid cell's 5 tetrahedra does
         better there (-2.8 % at 0.499, +0.8 % at 0.3) where the mesh has such cells, and
         FRM_VOLUMETRIC_PATCHES (mean dilatation over patches of about 12 tetrahedra that
         the model builds from any mesh) as well (-2.55 % at 0.499, +0.83 % at 0.3; the
         issue's 2-point target is not met: 3.4 points, and the patches' shapes move the
         answer by a few points, see VOLUMETRIC AVERAGING). One
         cell across, the option is soft (hexahedra +38 % at 0.49 against +20 % at 0.3,
         tetrahedra with 5-tetrahedra cells +50 %): the one-cell rotation modes that the
         volumetric stiffness was holding. The CG iterations of static solves grow with
         kappa / mu (17,404 at nu = 0.499 against 1,512 at 0.3, hexahedra 3 cells across:
         block Jacobi with the plain law's rest diagonal); the option is matrix-free (no
         assembled blocks); its force pass costs 1.35-1.7x. Not validated on Cook's
         membrane (issue 13 asks it of heml.h).
       - St Venant-Kirchhoff softens and can collapse under strong compression, and its
         energy has a minimum of zero at every mirror image of the rest state (F =
         diag(1, 1, -1)): a solve once settled a compressed cube's top layer there, with
         success and P_zz = 0. Both laws now refuse det F <= 0 (a Neo-Hookean sample's
         energy is infinite there): a step or solve that would reach it returns
         FRM_ERR_INVERTED and keeps the last valid state (the bench's squash test, a corner
         driven through the opposite face, is refused with either law). There is no
         inversion-safe continuation (as heml.h's linearised volumetric term below J0). The
         kernel frm_material_stress still computes St Venant-Kirchhoff's S and energy of a
         mirrored sample before returning FRM_ERR_INVERTED, for a caller that allows it.
       - Shepard functions are zero-order (no linear reproduction): meshless Shepard
         bodies are stiffer and less accurate than MLS ones, but take any point layout
         (coplanar, collinear); MLS needs 3D spread and may give negative weights (the
         mass uses |w|).
       - The mass is lumped per frame (exact rigid-body inertia, not the consistent mass)
         and taken at the start of each step; gyroscopic terms are neglected.
       - Constant external torques have no potential: with them the static Newton's
         symmetric Jacobian converges linearly, not quadratically.
       - Precision far from rest. The state is kept as displacements u from the rest
         pose, so a body at rest far from the origin is exact, but once it has moved far
         (u of 1e6 m in float: ghost forces 16-29 times a 1 % stretch's) the rounding of u
         fakes strains. A step or solve that starts or would end with eps(frm_real) max|u|
         > precision_limit h_min (default 1e-4; h_min the smallest sample's support, its
         largest rest lever) fails with FRM_ERR_PRECISION and keeps the state: in float
         with h_min = 0.1 m that is |u| above about 84 m, in double 4e10 m. Move the rest
         pose with the body (re-create it) for long travels in float; 0 disables the
         check. There is no per-body origin. Rest positions far from the origin carry
         float's rounding at creation (1e6 m: a mesh of centimetres degenerates,
         FRM_ERR_SHAPE_DEGENERATE); steel-like
         stiffness needs the round-off floor to stop Newton, which it does only once
         Newton no longer halves the residual (R1 float +0.17 %).
       - Free bodies have more zero-energy modes than the six rigid ones (issue 19, measured
         by frm_modal on a free 2 x 2 x 2-cell hexahedral cube: 11): every frame turning by
         the same small angle moves no sample (weights that reproduce linear fields) and
         leaves F a rotation, which no term of the default model sees (the divergence term
         sees only non-uniform turns); two more such modes on that grid. frame_coupling =
         1e-2 leaves exactly the six rigid modes (next 0.25 Hz there). They carry no load
         and do not move the material, but they are modes of the frames' dynamics.
       - BDF2 treats orientations in the tangent coordinates at the current one and keeps
         the mass at the step's start: second order for translations and small rotations
         per step, first order in the terms of frames spinning fast (see SOLVERS).
       - Coupling (issue 14): the frames' equations of motion neglect the centripetal and
         gyroscopic terms (omega x (omega x c), omega x J omega), so a body spinning with mass
         off its frame's origin does not conserve its momentum exactly; each step does
         conserve sum_i M_i(t_n) v (its start masses): measured on a rigid block turning at 1
         rad/s with a beam's first cell merged onto it, 1e-2 of sum |m v| over 0.4 s, the same
         at dt and dt / 2 (tests/test_frames_coupling.c). A rigid body is a frame with its
         own mass at its origin (its centre of mass); no joints, no contact, no constraints
         between bodies but shared or attached frames. Mesh-based probes on a combined model
         need the part's own nodes (frm_probe_desc.nodes, node_frames) when frames were
         attached to a rigid body (the attached frames are no longer frames of the model).
       - At most 16 neighbours per sample. The CUDA companion runs a subset and has not run on a
         GPU yet (see CUDA).
       - Coupling to heml.h and tensormass.h meshes is by iteration between the models
         (COUPLING), not one monolithic solve: each coupled step costs several steps of
         each model (7 to 9 measured), the staggered exchange has a small time-step limit,
         and the glue is a penalty (its compliance is a modelling error, about 1 / k per
         glued node). Assembled blocks (frm_model_stiffness_blocks) hold the anchors' own
         rotational term on the diagonal but not J^T k J (the products add it). Float: the
         coupled beams of tests/test_frames_coupling.c run with tolerances float can reach
         (they were skipped before, failing): heml.h's static solve of the glued R1 half
         stalls at its round-off floor above float's default static_tolerance 1e-4
         (HEML_ERR_ROUND_OFF in the first map; 1e-3 passes, R1 glued +3.40 % against
         double's +3.57 %), the glue iterates to 1e-4 m; the soft beam's Newton steps of
         the frames, under the springs' forces as loads, stop in their line search at
         1e-4 (FRM_ERR_NO_CONVERGENCE at the first step): with the springs on the frames'
         side (robin_frames = 1) and the frames' Newton tolerance 1e-3 every step converges
         and the trajectory equals double's to 4 digits.
       - Reduced chain (issue 15): each link is linear in its proximal frame's axes (small
         strain, large rotations: the thesis's model), so a link bent by tens of degrees is
         inaccurate (its rotation measure 2 sin(theta/2) saturates); use more vertebrae.
         Vertebra masses are points with isotropic inertia; the actuators' geometric
         stiffness is left out of the tangent; BTD factor + solve measured 4 to 5 times the
         issue's 50 us goal for 1,000 blocks on this machine.

   MODAL ANALYSIS (issue 19): frm_modal_create(m, &desc, &md) sizes a workspace (block =
   count + max(count, 8) vectors); frm_modal_solve(md, m) linearises m at its current state
   (the symmetric part of K, gravity's and the stresses' geometric terms included; the
   constraints as set) and runs block shift-invert subspace iteration: Y = (K + shift M)^-1
   M X by the model's linear solver (two-level preconditioned CG, warm-started at X / (lambda + shift)
   once a Ritz value exists), Rayleigh-Ritz on Y (Cholesky of Y^T M Y, Jacobi), X the
   M-orthonormal Ritz vectors, until every wanted residual is below tolerance (or the Ritz
   values stop moving). Chosen over LOBPCG for its simplicity with a matrix-free K and an
   existing CG; measured: the R3 beam one cell across, 8 modes, about 40,000 CG iterations
   (0.5 s), equal to the dense eigenvalues to 1e-6 (tests/test_frames_elem.c). The
   automatic shift (1e-4 of the mean K_ii / m_i) keeps K + shift M definite for free
   bodies; 1e-2 and 1e-3 took 60 % and 20 % more CG iterations on R3. Where CG meets
   negative curvature (K + shift M indefinite: gravity's torques at a state off
   equilibrium, compression) the automatic shift grows a hundredfold and the iteration
   restarts (three times at most; a given shift is not changed: FRM_ERR_NO_CONVERGENCE);
   negative eigenvalues then come out as negative frequencies (a clamped beam at rest
   under gravity, not an equilibrium: -0.60 Hz in tests/test_frames.c). Measured: R3 with
   tetrahedral frames two cells across 0.4982, 0.4982, 2.9982, 2.9982, 4.8506 Hz (3D:
   0.5091 twice, 3.0531 twice, torsion 4.5101: -2.1 %, -1.8 %, +7.6 %, the discretisation's
   error, see ACCURACY and LIMITS), no mode below the bending pair; a clamped-free bar with
   axial motion only 7.9037 and 23.662 Hz against 7.9057 and 23.717 (c / 4L, 3c / 4L: the
   linear elements' dispersion). A free body has six rigid modes at 0 Hz and, with the
   default model, more: every frame turning alike moves no material (frame_coupling > 0
   removes them; LIMITS).

   PROBES (issue 19; mapped points, issue 14: see COUPLING): frm_probe_create(m, &desc,
   rest_points, count, &p) finds each point
   once, among the elements whose bounding box (widened by 1e-3 of its size) covers the
   point's cell of a temporary uniform grid of about one cell per element (5,000 points in
   1,600 tetrahedra: 12 ms): FRM_PROBE_TETS the tetrahedron of desc.elements (frame indices) containing it
   (barycentric coordinates >= -tolerance; the one most inside wins, so points on shared
   faces and on the boundary are found), FRM_PROBE_HEXES the hexahedron whose trilinear
   map reaches it (Newton from the centre, parametric coordinates in [-tol, 1 + tol]),
   FRM_PROBE_MESHLESS the frames and weights frm_sampling_meshless would give a sample
   there (desc.shape: Shepard or MLS, nearest or radius support). A point in no element
   is FRM_ERR_POINT_OUTSIDE (no nearest-element fallback beyond the tolerance; meshless: a
   point farther from each of its frames than that frame's farthest sample). Then, per point,
   p = pbar + sum_i w_i (u_i + (Q_i - I) abar_i), abar_i = pbar - xbar_i (eq. 3.34 in the
   kernels' displacement form), and its velocity sum_i w_i (v_i + omega_i x Q_i abar_i):
   exact for rigid motions with any weights, and for affine fields of the frames'
   positions with tetrahedral, hexahedral and MLS weights (tests/test_frames_elem.c).

   COUPLING (issue 14; Bosman, Duriez & Cotin 2013 sec. 4.2 and fig. 5; thesis sec. 4.2)
       Mapped points. A probe is the mapping p = M(q) of eq. 4.11 from the frames to any
       points given by their rest positions (eq. 3.34 with the weights found once; see
       PROBES): a render mesh (frm_probe_positions each frame: this is how a frames body is
       drawn), contact points, another model's nodes. Its Jacobian at the current state,
       J dq = sum_i w_i (dx_i + dtheta_i x a_i) with a_i = Q_i abar_i the frame's own lever
       to the point (frm_probe_jacobian; velocities are J v), and the transpose
       (frm_probe_jacobian_transpose) give a point force f_n to frame i as the force
       w_in f_n (eq. 4.12) and the torque w_in a_in x f_n: eq. 4.13 with the frame's own
       prediction a_in for p_n - x_i. They differ once frames disagree about a point (under
       strain); ours is the exact transpose of the mapping, so the work f . dp equals the
       frames' generalized work (tested by finite differences) and a coupling through it
       neither creates nor loses energy; the total force sum f_n and moment sum p_n x f_n
       are carried exactly in any state. frm_probe_add_external adds J^T f to the external
       loads (constant through the following steps and solves: once per step for a
       staggered coupling). Measured cost: see README (bench kernels part, "frames mapped
       point").
       Anchors (frm_model_set_anchors; heml_set_anchors and tmass_set_anchors are the same
       hook for nodes): zero-length springs from a probe's mapped points to targets, energy
       sum_n k_n / 2 |p_n(q) - t_n|^2, part of the model (forces J^T (-k d), d = p - t; the
       stiffness J^T k J plus the levers' own term k w (a d^T - (a . d) I) per pair, whose
       antisymmetric half is the 1/2 [tau]x of every torque; energies; the block-Jacobi
       blocks; every solve). Tested against central differences of the energy and force
       (tests/test_frames_coupling.c, with heml's).
       Coupling a heml.h or tensormass.h mesh (no header includes another; the user's code
       holds both models; examples/glue.h is one, used by the tests, the bench and
       examples/frames_connective.c: glue_init_heml or glue_init_tmass picks an adapter, a
       table of the few mesh operations it needs, compiled when that header is included
       before it). Glued nodes x_n of the mesh and the mapped points p_n(q) of a probe at
       their rest positions:
       (a) Staggered, once a step: the frames step under J^T of the mesh's last forces on
       the glued nodes (elastic force plus weight; their inertia left out), then the glued
       nodes are prescribed at the new mapped points (heml_set_displacement,
       tmass_set_displacement) and the mesh steps. Explicit in the exchange: measured on R3's soft beam (1 x 0.1 x 0.1 m,
       E = 1 MPa, 1000 kg/m^3, half frames 0.1 m hexahedra, half heml.h, glued at mid-span),
       stable up to 1.5 ms and diverging from 2 ms with the mesh's 0.05 m cells, 0.95 /
       1.19 ms with 0.1 m cells (T/1300 of the beam's first period; heavier glued nodes,
       whose inertia the exchange leaves out, lower it). Above it the frames' Newton fails
       within a few steps (FRM_ERR_NO_CONVERGENCE, state kept), never a silent blow-up in
       the tests; use it only for light meshes and small steps.
       (b) Stiff: springs of stiffness k between x_n and p_n, as anchors in one model
       (targets the other's interface points) and as loads in the other (heml: the
       springs' force on the nodes; frames: J^T of it). One coupled step minimises both
       models' incremental potentials plus the springs' energy; a Robin-Neumann iteration
       reaches it (the side with the anchors solves with the other held, the other under
       the springs' forces, each from the step's start; J at the latest iterate, so the
       transfer is exact at convergence), accelerated by Anderson mixing of the interface
       points (depth 6), until they move less than a tolerance. Put the anchors on the side
       that is less held (the outer part of a beam; a Neumann side must be held, or its
       static solve has rigid modes). Measured: plain block Gauss-Seidel with springs in
       both models stalls (a side held by stiff springs moves 1e-6 m an iteration on R1
       with 0.055 m to go); plain Robin-Neumann diverges on R1's interface modes; with
       Anderson mixing R1 (half frames 16 x 2 x 2 hexahedra clamped, half heml.h 16 x 2 x 2
       cells of P1 tetrahedra) converges in 7 iterations to +0.13 % of Timoshenko (frames
       alone +3.49 %, heml alone -64.9 %: P1 locking, which the outer half feels 1/16 of);
       with the heml half refined until heml alone is within 5 % (6 x 6 x 128 cells of five
       tetrahedra a half: -4.16 % alone) the glued tip is +3.57 % in 4 iterations; a
       tensormass.h half (16 x 2 x 2 cells, tmass_set_anchors through glue_init_tmass)
       +0.10 % in 6 (tensormass alone -64.9 %: the same P1 stiffness); and the soft beam
       above steps at dt = 10 ms with at most 9 iterations a step (a tensormass.h half, its
       implicit Euler, the springs on the frames' side: at most 7, peak 0.1141 m against heml.h's 0.1138 m; its staggered
       exchange, like heml.h's, is stable at 0.5 ms and fails at 5 ms). k
       trades the glue's compliance against the iteration: k = 0.1, 0.3, 1, 3 E h (h the
       mesh's cell size across) gave +1.41, +0.13, -0.40, -0.57 % on R1 (the last not
       converged in 30 iterations); 0.3 E h is the tests' choice.
       Several parts (frm_parts_combine): each part's samples keep their weights and
       gradients, their frames are renumbered by the part's frame_map into the model's;
       frames several parts give are one frame (same rest position required), so a shared
       frame receives the mass, forces and stiffness of every part whose samples use it
       (the 2013 paper's sharing of frames between connective tissue and organs: the DoF
       sharing of thesis fig. 4.5, assembled by the existing solvers as one system). Each
       part has one material (law, constants, density: desc.materials with a material per
       part); split a part to give it several. A body split into two parts sharing their
       interface frames is the same discrete model as the whole, samples reordered:
       static sag and an implicit step agree to 4e-12 (tests/test_frames_coupling.c).
       Rigid bodies (frm_rigid_body): a frame with its own mass and inertia (not from
       samples; desc.frame_masses / frame_inertias, added to the frame's mass block and
       gravity at its origin). Part frames mapped onto a body's frame are attached: they
       move rigidly with it (x_j = x_b + Q_b (xbar_j - xbar_b), R_j = Q_b Rbar_j). The
       thesis couples them by bilateral constraints (fig. 4.7); we eliminate them through
       the rigid map, exactly: an attached frame predicts a sample at
       x_j + R_j lbar_j = x_b + Q_b (pbar - xbar_b), the body's own prediction, so in each
       sample the entries of frames attached to one body merge into one entry of the body's
       frame with the summed weight and gradient (p and F of eq. 3.34, 3.40 unchanged, and
       with them the energy, forces, stiffness, mass and gravity); the merged table is an
       ordinary one, so every solver, the mass and the reaction on the body come for free
       and nothing changes in the solvers. Only the stabilisation's per-sample length h^2
       and linear flag depend on levers: they are taken from the parts' own tables
       (desc.sample_sizes, sample_linear). Tests: a beam on a fixed block sags as the beam
       with its face frames fixed (1.6e-15 m), a beam on a free block falls with g (the
       momentum gains M g t to 2e-7) while the beam springs back from its sag, the
       momentum balance of each step with an internal impulse (7e-10), a weight on a strap
       reaches the strap's extension within 0.15 % (static solve and damped steps).

   CUDA (issue 16; thesis sec. 4.4, Bosman, Duriez & Cotin 2013 sec. 3-5)
       One kernel code. The bodies of the two passes are FRM_HOSTDEV functions (>>passes) on
       a frm_view, a public struct of counts and pointers (frm_model_view fills one that
       points into the model): pass 1 per sample, frm_pass1_deform (H, F, position), then the
       law (the backend's: the CPU runs the law table, user callbacks included; a GPU the
       kernels' laws frm_material_stress / frm_sample_dP), frm_pass1_stab_force (the
       rotation stabilisation's stress and energy), frm_pass1_force_pairs (each pair's
       partial force, the linearisation's G, Hs, levers); for K v frm_pass1_apply_dF, the
       law's dP, frm_pass1_apply_pairs; pass 2 per frame frm_pass2_gather (the reverse
       table, in pair order, in double) and frm_pass2_rotational. The CPU loops call exactly
       these (results bit-identical to the loops they replaced, for every thread count:
       measured on 12 scenes, hexahedra and tetrahedra, every law, the coupling term,
       volumetric averaging, blocks, BDF2, double, float and 2 OpenMP threads, and
       tests/test_frames_elem.c test_view_passes runs a serial backend of its own on the
       view and gets the model's forces and K v bit for bit). No per-pair arrays on the
       stack (a GPU thread's 290 numbers would spill): what a sample's sums need twice (a
       pair's lever, the stabilisation's T_k and omega_k) is recomputed by the same
       expression, and the stabilisation's K v torques wait in p_out until dP is complete;
       only the coupling term (frame_coupling, off by default) keeps 96 reals (nvcc -Xptxas
       -v: pass 1 of the force 768 bytes of stack, of K v 384, both from that term; no
       spills). The per-frame pieces around pass 2 are shared the same way: the world mass
       data, block and product (frm_pass_mass_world, frm_pass_mass_matrix,
       frm_pass_mass_apply), the gravity moment and its stiffness (frm_pass_gravity_moment,
       frm_pass_gravity_stiffness), the pair mode's block-Jacobi block and its Cholesky
       inverse (frm_pass_precond_block, frm_pass_invert6); the CUDA file keeps only launches,
       the device CG's scalar kernels and the reductions. The volumetric option's extra
       stages (VOLUMETRIC AVERAGING) stay CPU-only.
       The companion (frames_cuda.cu, declared in frames_cuda.h: a separate header, so that
       frames.h needs no CUDA types and programs without a GPU see nothing of it; nvcc -c
       frames_cuda.cu [-DFRM_REAL=float], link with -lcudart; frames.h's functions with C
       linkage): frm_cuda_create uploads a created model (structure, rest data, state,
       loads, settings) once; frm_cuda_step runs the linearised implicit Euler step (the
       thesis's scheme, one linear solve a step) on one stream: the force pass and its
       linearisation (pass 1 one thread a sample, pass 2 one thread a frame, 128 a block:
       not measured yet; the thesis's 6 threads a frame in blocks of 96 parallelise inside
       a frame, which pays when frames are few), the pair mode's block-Jacobi blocks
       inverted per frame, CG with its dot products in double reduced by a fixed-order tree
       (no floating-point atomics: repeatable bit for bit on one GPU) and the scalars on the
       device (16 iterations between two looks at convergence; the iterations past it change
       nothing, so the count equals the CPU's rule), then the update and the acceptance
       (finite state, no sample with det F <= 0); a failed step restores the device state
       of the step's start (FRM_ERR_NO_CONVERGENCE, FRM_ERR_NOT_FINITE, FRM_ERR_INVERTED,
       as the CPU path). frm_cuda_forces, frm_cuda_linearize, frm_cuda_apply_stiffness (K v,
       symmetric part), frm_cuda_download (into the host model), frm_cuda_upload_state.
       Not on the device: the static solve, Newton-based implicit Euler and BDF2, the
       definite fallback (the device step fails where the CPU retries with K's positive
       part), the precision check, assembled blocks, volumetric averaging, Mooney-Rivlin
       and user laws, driven frames (FRM_ERR_DEVICE at creation).
       Verified: frames_cuda.cu compiles with nvcc 13.0 for sm_80 and sm_90 with warnings as
       errors (make test, tests/test_cuda.sh: about 30 s); tests/cuda_frames.c builds and
       links, and on a machine without a GPU frm_cuda_create returns FRM_ERR_DEVICE. NOT
       verified: nothing of it has run on a GPU. tests/cuda_frames.c (forces, K v and one
       step against the CPU within tolerances it justifies, two device runs bit-identical,
       an overloaded step keeping the last valid state) and bench/gpu.sh (the thesis's
       34,610-sample step at 60 CG iterations, 1e6 samples, device and CPU of the same run,
       written to bench/results/gpu-<name>/) are ready for the first session with a GPU.

   BLOCK-TRIDIAGONAL SOLVER (issue 15): frm_btd_factor / frm_btd_solve / frm_btd_compliance,
   usable on their own for any chain of 6-DoF nodes (rods, cables, catheters, trunk robots).
   The matrix: n diagonal 6x6 blocks and n - 1 sub-diagonal blocks A(i + 1, i), symmetric
   positive definite. Block LDL^T without square roots: A = L D L^T, L unit block-bidiagonal
   with L(i + 1, i) = E_i = B_i D_i^-1 (B_i = A(i + 1, i)), D_{i+1} = A(i + 1, i + 1) - E_i B_i^T;
   the factor stores D_i^-1 and E_i^T, so the solve is two sweeps of 6x6 products: forward
   y_i = b_i - E_{i-1} y_{i-1} (and z_i = D_i^-1 y_i off the chain), backward
   x_i = z_i - E_i^T x_{i+1} (each 6x6 product as two partial sums, so a block adds three
   multiply-adds and an add to a sweep's dependency chain instead of six multiply-adds).
   D_i^-1, E_i and D_{i+1} come from one symmetric sweep
   (Gauss-Jordan) of the 12 x 12 window [D_i B_i^T; B_i A(i + 1, i + 1)] over its first six
   pivots: each pivot costs one division, and the next pivot is formed from it by one
   multiply-add, so the sequential chain of the whole factorisation is 6 (division +
   multiply-add) a block; every other operation is a row update of fixed size (rows as one
   zmm register in double builds with AVX-512, vectors of 4 + 2 doubles with other GCC /
   Clang targets, plain loops elsewhere). O(n), 72 reals a block,
   one or many right-hand sides, arithmetic in double whatever frm_real. The pivots are
   LDL^T's (Cholesky's squared diagonal): one at or below 4 (n + 16) eps(frm_real) times the
   block's own diagonal entry is refused: FRM_ERR_BTD_INDEFINITE (negative) or
   FRM_ERR_BTD_SINGULAR (zero), the failing block reported; a non-finite pivot or result is
   FRM_ERR_NOT_FINITE (the solve then zeroes its output: never NaN). frm_btd_compliance gives
   W = J A^-1 J^T for a few constraint rows (eqs. 5.24-5.25) by rows solves, without A^-1.
   Tested against dense Cholesky for 1 to 60 blocks and by residuals at 1,000, with
   symmetric scalings that put the condition number near 1e10 (tests/test_frames_chain.c;
   the sweep's rounding is invariant under such scalings, errors 4e-16 to 7e-16 as with the
   Cholesky it replaced).
   Choice by measurement (one core of the development machine, 1,000 blocks, double, best
   of 50 runs, both builds run interleaved in one session, the machine shared): the block
   Cholesky this replaced (L_i^-1 stored; 6 square roots and 6 divisions a block on the
   chain) took 165 us to factor and 28 us to solve with gcc -O3 -march=native (AVX-512),
   203 + 28 us with -march=x86-64-v3, 244 + 67 us with plain -O2; the LDL^T sweep takes
   100-104 + 22 us, 161-172 + 21 us and 199-222 + 40 us. The issue's goal of 50 us for factor +
   solve is not met: the sweep is bound by its row updates' throughput (about 650
   multiply-adds a block on 6-wide rows) more than by the division chain (about 100 cycles
   a block); the bench's btd rows give the timings under the bench's load.
   Kept since (issue 15's speed item, second pass): in double builds with vector rows the
   factor stores D_i^-1 and E_i^T straight from the registers instead of staging them
   through arrays, and the solve's 6x6 products are two partial sums each. Measured
   (AMD EPYC Zen 5, family 26, 2 vCPUs shared with other builds, gcc -O3 -march=native,
   1,000 blocks, best of 50, the two versions run interleaved, 10 times each):
   factor + solve 109.3 + 23.1 = 132.9 us before, 96.8 + 20.2 = 117.3 us after; plain
   gcc -O2: 217.0 + 42.8 = 260.5 us before, 228.1 + 41.2 = 269.7 us after (the factor
   within the noise). The 50 us goal is still not met.
   Tried for the goal and not kept (AMD EPYC Zen 5, family 26, AVX-512, about 3.6 GHz by a
   multiply-add latency loop, 2 vCPUs shared with other builds, load average 7-9; gcc 12-14
   -O3 -march=native, best of 50, 1,000 blocks, factor / solve in us; the original 107 /
   22.9): rows of 6 padded to 8 in one AVX-512 register each with the row loops unrolled:
   105 / 22.9 (within the noise); a two-ended factorisation (block 0 downwards and block
   n - 1 upwards at once, pivots interleaved, the two Schur complements summed in the
   middle block; exact, refusals kept): 110.7 / 18.8 with AVX-512 rows, 134 / 18.7 with
   4 + 2 rows, and 318 / 40 at plain -O2 against 207 / 41 (two windows of 18 rows do not fit
   the registers and spill); interleaving whole blocks instead of pivots: 133 / 22 native,
   300 / 42 at -O2. So on this machine the factorisation is bound by its instruction
   throughput (about 380 cycles a block at 3.6 GHz; the loop body is some 1,150
   instructions, objdump, many of them moves of the window's rows to and from the stack and
   lane extractions for the broadcasts) rather than by its dependency chain (6 x (division
   13 + multiply-add 4) ~ 100 cycles a block), and halving the chain does not pay; 50 us
   would need a kernel of roughly a third of those instructions (an estimate: broadcasts
   from memory, T's column scaling folded away), not attempted.
   Third pass (issue 15's speed item, last; the padded AVX-512 rows above had kept three
   branches a pivot and broadcasts by lane extraction, and with both gone they pay): three
   changes. (1) Every build judges a block's six pivots together after the sixth
   (frm__btd_judge: one branch a block instead of three a pivot; on a refusal the first
   refused pivot is found again, so the codes and failed blocks are those of the
   pivot-by-pivot test, and a refused block's output is not stored). (2) Every build defers
   the pivots' column scaling (frm__btd_sweep: T held as T diag(1 / sigma), sigma_b = r_b
   once column b has been pivoted, D^-1 = -T~ sigma stored; one product of row k by sigma a
   pivot instead of one of every row by s). The results are no longer bit-identical to the
   second pass's (the scaled columns are rounded once, at the end): errors in the tests as
   before (scaled error against dense Cholesky 6.4e-16 at 60 blocks, was 6.0e-16; residual
   6.8e-16 at 1,000; float unchanged). (3) Double builds with AVX-512 (GCC / Clang;
   FRM_BTD_NO_AVX512 opts out) factor with frm__btd_factor_zmm: one zmm register a row (lanes
   6, 7 zero), the 18 rows as named variables, lane masks for the pivot's column, the pivot's
   rows read back from a small array so that the lane broadcasts are loads (an empty asm
   statement keeps GCC from turning them back into shuffles), B^T and the mirrored lower
   triangles by gathers of constant indices; the same operations and roundings as the
   portable rows where the compiler fuses their multiply-adds (bit-identical at
   -ffp-contract=fast; within 3e-16 of a block's largest entry otherwise: test_btd_paths
   compares the two). Measured on a 2-vCPU Intel Xeon VM (AVX-512, reported as family 6 model
   167; shared with other builds, load average 6-10), 1,000 blocks, best of 20 x 50 runs, the
   second pass's header (main) and this one built as separate objects and run interleaved in
   one process; factor, solve, best factor + solve:
       gcc -O3 -march=native -ffp-contract=fast (the bench's flags)
                                   84.4 + 17.0, 101.4 us -> 47.7 + 17.7, 66.3 us (0.65)
       gcc -O2 -march=native       134.9 + 36.7, 171.6 us -> 51.3 + 37.2, 88.7 us (0.52)
       gcc -O3 -march=x86-64-v3 -ffp-contract=fast (AVX2, 4 + 2 rows)
                                   128.1 + 20.1, 148.2 us -> 100.6 + 19.4, 120.3 us (0.81)
       plain gcc -O2 (SSE2)        211.9 + 36.1, 249.0 us -> 168.9 + 35.2, 205.2 us (0.82)
   The issue's 50 us for factor + solve is not met (66 us at best). What bounds it: the
   factor is throughput-bound, not chain-bound: with the division taken off the chain (r from
   a constant, timing only) it ran no faster (49 against 48-51 us, before (2)), while its
   chain alone (6,000 dependent divisions and multiply-adds) takes 26 us here; its loop is
   about 360 instructions a block (objdump, gcc -O3 -march=native): 96 multiply-adds, 24
   multiplies, 36 broadcast loads (30 more folded into the multiply-adds), 13 gathers, 24
   stores, some 60 register copies and 23 mask moves, the 512-bit arithmetic on two ports.
   The 13 gathers a block cost about 6 us (rows loaded without them, timing only: 44.7 us).
   The solve (17-18 us) keeps its scalar loops (each vector form tried was slower); it judges
   its answers by six running sums of t - t instead of a test an element (17.4 -> 17.1 us;
   plain -O2 36.4 -> 35.0 us). Tried and dropped (same harness, the factor unless said): GCC
   vector_size(64) rows in the portable sweep (91 against 86 us for the 4 + 2 rows, and
   contracted differently); arrays of zmm rows (left on the stack: 69 us); broadcasts by
   shuffles of the registers (no asm statement: 76 us); the next pivot's two entries formed
   as scalars straight from r (bit-identical, 54 against 50 us: the chain is not the bound);
   the masks replaced by constant vectors (51-52 us); B^T by an in-register transpose (16
   shuffles, 57 us) or by scalar copies staged in the factor's next block (50.4 against 50.0
   us); the solve in zmm registers (both sweeps, the backward one gathering E_i^T's columns:
   30 us; the forward one alone: 26.5 us; only z = D^-1 y: 27.7 us, against 17-19 us for the
   scalar loops); the solve's answers judged finite in one pass after the sweeps (21.6
   against 17 us).
   In the frames solvers: desc.linear_solver (frm_linear_solver) defaults to
   FRM_LINEAR_SOLVER_AUTO, resolved at creation (frm_model_linear_solver tells which):
   FRM_LINEAR_SOLVER_BTD when the block pattern is a chain in frame order (every sample's
   frames within one index of each other, so frame i couples to i - 1 and i + 1 only; a
   chain numbered in another order is not detected), the blocks are assembled (not
   stiffness_mode FRM_STIFFNESS_PAIRS, not volumetric) and frm_real is double,
   FRM_LINEAR_SOLVER_CG otherwise. Float builds keep CG under AUTO: the factor is stored in
   float, and on slender rods (condition numbers near 1 / eps(float)) BTD's answers met the
   residual test yet were less accurate than CG's (tests/test_frames.c test_i14_curve in
   float: the 32-segment rod's tip 0.150560 m under BTD against 0.150410 m in double, and
   implicit steps that stopped converging); an explicit FRM_LINEAR_SOLVER_BTD still works
   in float;
   the BTD workspace (144 reals a frame) is allocated only then. Anchors
   (frm_model_set_anchors: J^T k J couples the frames of each anchor's point, outside the
   assembled blocks) switch a model where AUTO chose BTD to CG while they are set (an
   explicit FRM_LINEAR_SOLVER_BTD refuses them, FRM_ERR_ARG). The coarse space and
   coarse_aggregates concern CG only. Explicit CG or BTD are kept (BTD on a pattern that is
   not a chain: FRM_ERR_SOLVER at creation). Measured: a 12-frame rod whose samples each see
   two neighbouring frames gets BTD under AUTO, with the static sag and ten implicit steps
   equal to CG's within 1e-6 of the sag, as does a 16-segment rod of frm_sampling_curve
   (rods from frm_sampling_curve are chains); a 3D block of hexahedra gets CG
   (tests/test_frames_chain.c test_frames_btd_auto); the two-frame models of
   tests/test_frames.c's validation tests now solve with BTD. BTD assembles the blocks
   (block stiffness mode forced), makes held components identity rows, factors
   a_mass M + a_stiff K, checks |b - A x| <= tolerance |b| against the model's own product
   (up to three steps of iterative refinement: float needs them; where they stall, as for
   a slender rod whose condition number nears 1 / eps(float), CG goes on from BTD's answer:
   a 16-segment frm_sampling_curve rod in float failed its static solve under BTD alone and
   matches CG's sag with this), and reports a failed
   factorisation as negative curvature (the Newton loops then retry with K's
   positive-definite part, as after CG). The reduced chain below always uses BTD.

   REDUCED CHAIN (issue 15; thesis sec. 5.2): frm_chain, a soft arm with rigid vertebrae as
   frames 0..n-1 (frame 0 the base, held at its pose: frm_chain_set_base moves it) joined by
   n - 1 linear 6-DoF springs, each given by its compliance C_i (eq. 5.10) in frame i's rest
   axes: the response (displacement, rotation) of frame i + 1 to a force and torque at its
   origin with frame i held. A tapered arm is one compliance per link. Link energy, with
   q_0, q_1 the link's frames (our formulation of eqs. 5.12-5.18, the thesis's rotations
   carried in Omega_0):
       d = R_0^T (x_1 - x_0) - dbar,   phi = 2 vec(q_e), q_e = conj(q_0) q_1 conj(qbar_rel)
       (w >= 0),   E = 1/2 e^T C^-1 e,   e = (d, phi),
   the link linear in frame 0's axes (dbar and qbar_rel the rest lever and relative
   orientation); phi equals the relative rotation vector to O(theta^3) (0.04 % at 0.1 rad
   a link). Forces: with g = C^-1 e, F = R_0 g_t and m = R_0 (w g_r + v x g_r) (v, w the parts
   of q_e): frame 1 gets (-F, -m), frame 0 (F, m + (x_1 - x_0) x F), which is eq. 5.13-5.15
   with H_{0,1} built on the current lever (exact moment balance) and the measure's Jacobian
   w I + [v]x in place of I. The tangent K = -df/dq is the exact derivative (a 12 x 12 matrix
   per link by 12 directional derivatives, closed form), whose symmetric part the solvers
   factor; at rest it equals Omega Gamma Omega^T of eqs. 5.16-5.17. Where the exact symmetric
   part is not positive definite (a link past a bifurcation) the Newton iteration factors the
   Gauss-Newton part J^T C^-1 J instead (eqs. 5.16-5.17 with the current lever; positive
   semi-definite, definite with the base held). Tests: force = -dE/dq and K = -df/dq by
   central differences at a random large deformation, Euler-Bernoulli links reproducing the
   cantilever's P L^3 / 3 E I (1e-5), pure bending to 90 degrees against the circular arc
   (0.5 % of L; measured +0.01 % and +0.25 %), a moving base carrying the chain rigidly.
   Masses are lumped at the frames' origins (kg) with an isotropic rotational inertia (kg m^2);
   gravity acts at the origins (no torque), external loads are constant forces and torques.
   frm_chain_solve_static: Newton (eq. 5.19) on frames 1..n-1 through the BTD solver, a
   backtracking line search on the potential (elastic energy, gravity's and external forces'
   work, cables' tension times length, cavities' -p V; constant torques by their work along
   the step), converged when |f| <= newton_tolerance (|loads| + |base reaction| + |actuator
   forces|), or, once an iteration no longer halves |f|, below its round-off floor (16 eps
   times the links' force sums and stiffness times the positions' rounding); state unchanged
   on failure. frm_chain_step: implicit Euler by the same Newton on the step's incremental
   potential (mass M/dt^2, mass damping alpha; rotations as the step's accumulated world
   rotation vectors, gyroscopic terms neglected), tested against the scheme's own recurrence.
   The compliance of an intervertebra from a frames sub-model (eqs. 5.1-5.11):
   frm_chain_link_compliance(m, end_a, end_b, origin_b, C) holds end A's frames' translations,
   moves end B's frames' translations rigidly with a virtual frame at origin_b, and forms the
   Schur complement of the model's linear stiffness at its current (rest) state by six
   imposed unit rigid motions, the interior solved by the model's linear solver; C = K_red^-1.
   The ends' frame rotations are left free: a frames model's frames do not turn with the
   material in bending (on hexahedral grids about half as much, see MODEL), and holding them
   to the rigid rotation made the sub-model 22 % too stiff in bending (measured on a 4-cell
   segment). The reduced chain of a 0.1 x 0.1 x 2 m square cylinder (5 segments of 4 x 2 x 2
   hexahedral cells) matches the full frames model's tip deflection within +0.34 % (the
   thesis: 0.72 %; the reduced model keeps each segment's end sections rigid);
   examples/heml_link_compliance.c does the same from a heml.h mesh by imposed motions and
   reactions, without the headers including each other.

   INVERSE ACTUATION (issue 15; thesis sec. 5.3). Actuators (frm_actuator, at creation): a
   cable through points fixed to vertebrae (rest positions, world axes), its effort the
   tension lambda >= 0 (force -lambda dL/dq, L the path's length through the points: each
   point gets the difference of its segments' unit vectors); a pneumatic cavity, a closed
   surface of triangles whose vertices are fixed to vertebrae, its effort the pressure p
   (force p dV/dq: each vertex gets sum_j A_j n_j / 3 over its triangles, eq. 5.20, mapped to
   its frame as a force and a torque about the frame's origin, the rigid mapping's J^T).
   Bounds 0 <= min <= max per actuator. The actuators' own geometric stiffness (lambda d2L/dq2)
   is not in the tangent: Newton converges linearly under large efforts (the line search and
   the residual test keep the answer exact). Direct simulation: frm_chain_set_efforts, then
   frm_chain_solve_static. Inverse (frm_chain_inverse_step, one control step): the free
   motion dq_f = K^-1 f(q) without actuators (eq. 5.23's linearisation), W_ea = J_e K^-1 J_a^T,
   W_aa = J_a K^-1 J_a^T by one BTD factorisation and na + 1 solves (eqs. 5.24-5.25), the
   effector's linearised gap delta_free = p_e(q) - target + J_e dq_f (3 rows, or 6 with the
   orientation: the rotation from the target to the effector frame), then the QP of eq. 5.29,
       min 1/2 lambda^T (W_ea^T W_ea + eps W_aa) lambda + lambda^T W_ea^T delta_free
   over the bounds, eps = inverse_epsilon tr(W_ea^T W_ea) / tr(W_aa) (default 1e-5: small
   enough not to bias a reachable answer, large enough to make the QP definite when there
   are more actuators than effector rows), solved by frm_qp_box, a primal active-set method
   (chosen over projected Newton: exact finite termination for these sizes, a Cholesky of
   the free set per change; at most 64 variables, 8 n + 32 changes), then the efforts are
   applied by the direct simulation from the current state. frm_chain_inverse_solve repeats
   the step with the linearisation updated (eq. 5.23) until the effector is within tolerance.
   An unreachable target (the QP's own linearised error above tolerance, stalled over two
   steps) returns FRM_ERR_UNREACHABLE with the chain at the closest pose found (a valid
   equilibrium: the one code that leaves a new state); a QP that is not convex returns
   FRM_ERR_QP_INDEFINITE, never NaN. Measured (tests/test_frames_chain.c, 16-vertebra
   tapered arm, 2 x 3 cables): a reachable target within 0.03 % of the arm's length after
   one linearisation; the unreachable target's closest pose passes a first-order check (no
   single effort moved by 1 N within its bounds brings the tip closer). examples/
   frames_soft_arm.c tracks the thesis's 60 mm circle and 80 mm square with one
   linearisation a 20 ms control step: mean error 0.01-0.02 mm, about 0.45 ms a step.
   PATENT NOTE: the thesis's control method, inverse simulation by a QP in constraint space
   (this section's frm_chain_inverse_step / _solve), is the subject of patent FR3002047 /
   WO2014122134A1 (Inria, priority 8 February 2013). The solver building blocks (BTD, the
   box QP, the chain model, the actuators' direct simulation) are general; users deploying
   the inverse controller commercially must check that patent's status themselves.

   HISTORY
       unreleased (issue 16): frm_view and frm_model_view (frm_model_view_f32), the pass
             functions frm_pass1_* and frm_pass2_* (>>passes) that the CPU loops now call;
             frames_cuda.cu / frames_cuda.h (frm_cuda_*), FRM_ERR_DEVICE (-49). Results of
             existing models bit-identical.
       unreleased (issue 15): the block-tridiagonal solver (frm_btd_*, and
             FRM_LINEAR_SOLVER_BTD for chain-pattern models), the box QP frm_qp_box, the
             reduced chain model with actuators and the inverse model (frm_chain_*,
             frm_actuator), error codes FRM_ERR_BTD_INDEFINITE .. FRM_ERR_QP_INDEFINITE;
             desc.linear_solver defaults to FRM_LINEAR_SOLVER_AUTO (-1; BTD for chain-pattern
             models with assembled blocks in double builds, CG otherwise) and
             frm_model_linear_solver tells the choice: results of chain-pattern models (rods
             of frm_sampling_curve, two-frame models) change within the solve tolerances in
             double, other models and float builds bit-identical.
       unreleased (issue 14): coupling: mapped points (frm_probe_jacobian,
             frm_probe_jacobian_transpose, frm_probe_add_external; frm_probe_desc.nodes,
             node_frames, node_count), several parts (frm_part, frm_parts_combine,
             frm_assembly_apply / _free), rigid bodies (frm_rigid_body, desc.frame_masses,
             frame_inertias, sample_sizes, sample_linear); FRM_ERR_POINT_OUTSIDE (was
             FRM_ERR_ARG for a probe point in no element), FRM_ERR_PART_FRAME, FRM_ERR_RIGID,
             FRM_ERR_SAMPLE_SIZE. Results of existing models bit-identical.
       unreleased (issue 19): FRM_BDF2 (see SOLVERS), frm_model_set_integrator,
             frm_model_set_damping, frm_model_displacements, frm_model_rest_positions,
             point probes (frm_probe_*), modal analysis (frm_modal_*). Results of existing models bit-identical; the
             model block grows by 25 reals a frame.
       unreleased (issue 20): extension points. Laws through one table (frm__laws) with a
             per-sample parameter block (FRM_LAW_PARAMS) and FRM_LAW_COUNT; new laws
             FRM_LAW_MOONEY_RIVLIN (frm_material.c1, c2, bulk_modulus) and FRM_LAW_USER
             (frm_material.user, frm_user_law / frm_law_points as in heml.h); integrators by
             desc.integrator (frm_integrator, FRM_INTEGRATOR_COUNT; implicit_linearized = 1
             still selects the linearised one); desc.linear_solver (frm_linear_solver, CG);
             HOW TO EXTEND. Results of existing models bit-identical.
       0.1.0 (2026-12-01) first release: frames and samples, four shape functions, mesh
             and Poisson-disk sampling, SVK and Neo-Hookean, exact stiffness, static
             Newton and implicit Euler with block-Jacobi CG, matrix-free or by blocks.
       unreleased (issue 21): CG preconditioned by two levels, block-Jacobi plus a coarse
             space of 9 modes per aggregate of frames (desc.coarse_aggregates, default 32;
             0 = block-Jacobi alone): results change within the solve tolerances.
       unreleased (issue 18): the divergence term of the rotation stabilisation
             (desc.rotation_divergence, default 4: removes the tetrahedral frames' spurious
             low modes and the hexahedral frames' zero-energy rotations; changes results
             slightly, see ACCURACY); St Venant-Kirchhoff refuses det F <= 0
             (FRM_ERR_INVERTED); descriptions without their cookie refused before their log
             callback is called, frm_shape_desc and frm_poisson_desc gained cookies (start
             them from their default functions); shape functions refuse non-finite input and
             Shepard exponents <= 1, samplings frame_spacing < sample_spacing; every entry
             point renamed in float builds.
       unreleased (issue 18): static solve with load continuation (max_increments,
             min_increment), a line search that never climbs and an acceptance test
             (residual against max(|load|, |reactions|), no inverted sample,
             precision_limit / FRM_ERR_PRECISION); implicit Euler by Newton on the
             incremental potential (implicit_linearized = 1 keeps the single
             linearisation); frm_model_set_frame_axes / frm_model_frame_axes; CG fails
             at its cap and on a non-finite |b|^2 (cg_fail_at_cap removed); frm_stats in
             the common layout (line_search_halvings -> line_search_cuts, residual
             relative, residual_force, increments, increment_cuts, negative_curvature,
             inverted).
       earlier, unreleased: rotation stabilisation for frames with collinear samples (default on:
             changes tetrahedral one-sample models); static and implicit solvers fall back
             to K's positive-definite part on indefinite linearisations; static line search
             judged by the residual below the energy's round-off; the round-off floor stops
             Newton only without progress; FRM_ERR_STALLED; static_regularization default
             1e-10 (was 1e-6); frm_stats.definite_solves, frm_model_stabilized_frames; the
             frame-own rotational term applied per frame (frm_pair_apply and
             frm_sample_coupling_apply lost their Hs / g arguments).

   Licence at the end of the file. */
#ifndef FRAMES_H
#define FRAMES_H

#include <stddef.h>

#define FRM_VERSION_MAJOR 0
#define FRM_VERSION_MINOR 1
#define FRM_VERSION_PATCH 0

#ifndef FRM_REAL
#define FRM_REAL double
#endif
typedef FRM_REAL frm_real;

#ifdef FRM_STATIC
#define FRMDEF static
#else
#define FRMDEF extern
#endif

/* The per-sample and per-frame kernels (>>kernels) run on the host and, compiled by nvcc
   in frames_cuda.cu, on the device. */
#if defined(__CUDACC__)
#define FRM_HOSTDEV __host__ __device__
#else
#define FRM_HOSTDEV
#endif

/* Float builds rename every public entry point (every FRMDEF function, ..._f32), so that
   a float and a double translation unit cannot be linked together by mistake, whichever
   functions a program calls (tests/test_frames_elem.c reads this list back against the
   declarations). FRM_REAL must be the single token float or double. */
#define FRM__IS_float 1
#define FRM__IS_double 0
#define FRM__CAT2(a, b) a##b
#define FRM__CAT(a, b) FRM__CAT2(a, b)
#if FRM__CAT(FRM__IS_, FRM_REAL)
#define frm_version frm_version_f32
#define frm_error_string frm_error_string_f32
#define frm_shape_tet frm_shape_tet_f32
#define frm_shape_hex frm_shape_hex_f32
#define frm_shape_shepard frm_shape_shepard_f32
#define frm_shape_mls frm_shape_mls_f32
#define frm_sampling_hexes frm_sampling_hexes_f32
#define frm_sampling_tets frm_sampling_tets_f32
#define frm_sampling_meshless frm_sampling_meshless_f32
#define frm_sampling_curve frm_sampling_curve_f32
#define frm_material_thin frm_material_thin_f32
#define frm_sampling_box frm_sampling_box_f32
#define frm_sampling_surface frm_sampling_surface_f32
#define frm_sampling_apply frm_sampling_apply_f32
#define frm_sampling_free frm_sampling_free_f32
#define frm_shape_default_desc frm_shape_default_desc_f32
#define frm_poisson_default_desc frm_poisson_default_desc_f32
#define frm_part_default frm_part_default_f32
#define frm_rigid_body_default frm_rigid_body_default_f32
#define frm_parts_combine frm_parts_combine_f32
#define frm_assembly_apply frm_assembly_apply_f32
#define frm_assembly_free frm_assembly_free_f32
#define frm_model_default_desc frm_model_default_desc_f32
#define frm_model_create frm_model_create_f32
#define frm_model_destroy frm_model_destroy_f32
#define frm_model_view frm_model_view_f32
#define frm_model_fix_frame frm_model_fix_frame_f32
#define frm_model_drive_frame frm_model_drive_frame_f32
#define frm_model_release_frame frm_model_release_frame_f32
#define frm_model_frame_state frm_model_frame_state_f32
#define frm_model_set_external frm_model_set_external_f32
#define frm_model_clear_external frm_model_clear_external_f32
#define frm_model_set_gravity frm_model_set_gravity_f32
#define frm_model_set_solver frm_model_set_solver_f32
#define frm_model_set_damping frm_model_set_damping_f32
#define frm_model_set_integrator frm_model_set_integrator_f32
#define frm_model_set_stiffness_mode frm_model_set_stiffness_mode_f32
#define frm_model_step frm_model_step_f32
#define frm_model_step_ex frm_model_step_ex_f32
#define frm_model_solve_static frm_model_solve_static_f32
#define frm_model_newton_step frm_model_newton_step_f32
#define frm_model_frame_count frm_model_frame_count_f32
#define frm_model_sample_count frm_model_sample_count_f32
#define frm_model_pair_count frm_model_pair_count_f32
#define frm_model_positions frm_model_positions_f32
#define frm_model_orientations frm_model_orientations_f32
#define frm_model_velocities frm_model_velocities_f32
#define frm_model_displacements frm_model_displacements_f32
#define frm_model_rest_positions frm_model_rest_positions_f32
#define frm_model_set_poses frm_model_set_poses_f32
#define frm_model_set_velocities frm_model_set_velocities_f32
#define frm_model_sample_positions frm_model_sample_positions_f32
#define frm_model_deformation_gradients frm_model_deformation_gradients_f32
#define frm_model_forces frm_model_forces_f32
#define frm_model_total_forces frm_model_total_forces_f32
#define frm_model_energy frm_model_energy_f32
#define frm_model_last_stats frm_model_last_stats_f32
#define frm_model_linear_solver frm_model_linear_solver_f32
#define frm_model_mass_block frm_model_mass_block_f32
#define frm_model_memory_bytes frm_model_memory_bytes_f32
#define frm_model_stabilized_frames frm_model_stabilized_frames_f32
#define frm_model_prepare_stiffness frm_model_prepare_stiffness_f32
#define frm_model_apply_stiffness frm_model_apply_stiffness_f32
#define frm_model_assemble_stiffness frm_model_assemble_stiffness_f32
#define frm_model_stiffness_blocks frm_model_stiffness_blocks_f32
#define frm_model_stiffness_block frm_model_stiffness_block_f32
#define frm_model_set_frame_axes frm_model_set_frame_axes_f32
#define frm_model_frame_axes frm_model_frame_axes_f32
#define frm_probe_default_desc frm_probe_default_desc_f32
#define frm_probe_create frm_probe_create_f32
#define frm_probe_positions frm_probe_positions_f32
#define frm_probe_displacements frm_probe_displacements_f32
#define frm_probe_velocities frm_probe_velocities_f32
#define frm_probe_count frm_probe_count_f32
#define frm_probe_jacobian frm_probe_jacobian_f32
#define frm_probe_jacobian_transpose frm_probe_jacobian_transpose_f32
#define frm_probe_add_external frm_probe_add_external_f32
#define frm_model_set_anchors frm_model_set_anchors_f32
#define frm_probe_destroy frm_probe_destroy_f32
#define frm_modal_default_desc frm_modal_default_desc_f32
#define frm_modal_create frm_modal_create_f32
#define frm_modal_solve frm_modal_solve_f32
#define frm_modal_count frm_modal_count_f32
#define frm_modal_frequency frm_modal_frequency_f32
#define frm_modal_shape frm_modal_shape_f32
#define frm_modal_destroy frm_modal_destroy_f32
#endif

/* Most frames one sample may depend on (the GPU pass keeps a sample's slots in fast
   memory, thesis sec. 4.4). */
#define FRM_MAX_NEIGHBORS 16

/* The two-level preconditioner's coarse space (desc.coarse_aggregates, see SOLVERS): the
   default and largest number of aggregates, and the fewest frames an aggregate holds. */
#define FRM_COARSE_AGGREGATES 32
#define FRM_COARSE_MAX_AGGREGATES 256
#define FRM_COARSE_MIN_FRAMES 8

/* FRM_VOLUMETRIC_PATCHES (desc.volumetric_patch_size): the default and largest number of
   samples a patch is grown to (see MODEL, volumetric averaging). */
#define FRM_VOLUMETRIC_PATCH_SIZE 12
#define FRM_VOLUMETRIC_PATCH_MAX 64

/* The least bytes each kernel streams per (sample, neighbour) pair (see PERFORMANCE), for
   bandwidth bounds: the force pass (pass 1 reads index, weight, gradient and rest lever,
   writes 6 reals; pass 2 reads them back with the pair index), the matrix-free K v (pass 1
   reads index, gradient and G, then the same 6-real round trip), and one assembled
   6x6 block with its column index (block mode). Sample data (F, S) comes on top. */
#define FRM_FORCE_BYTES_PER_PAIR (2 * sizeof(int) + 19 * sizeof(frm_real))
#define FRM_KV_BYTES_PER_PAIR (2 * sizeof(int) + 24 * sizeof(frm_real))
#define FRM_KV_BYTES_PER_BLOCK (sizeof(int) + 36 * sizeof(frm_real))

/* Pairs (sample, neighbour) below which loops run serially (starting threads costs more
   than it saves on small models). */
#ifndef FRM_PARALLEL_MIN_PAIRS
#define FRM_PARALLEL_MIN_PAIRS 20000
#endif

/* Error codes and their messages, one list so they cannot drift apart. */
#define FRM_ERROR_LIST(X) \
    X(FRM_OK, 0, "ok") \
    X(FRM_ERR_ARG, -1, "invalid argument (NULL pointer, bad count or non-finite value)") \
    X(FRM_ERR_ALLOC, -2, "out of memory") \
    X(FRM_ERR_DESC, -3, "description not initialised with its default function") \
    X(FRM_ERR_FRAME_COUNT, -4, "frame count below 1 or too large") \
    X(FRM_ERR_SAMPLE_COUNT, -5, "sample count below 1 or too large") \
    X(FRM_ERR_FRAME_NOT_FINITE, -6, "frame position not finite") \
    X(FRM_ERR_QUATERNION, -7, "orientation not a finite unit quaternion") \
    X(FRM_ERR_SAMPLE_NOT_FINITE, -8, "sample position not finite") \
    X(FRM_ERR_SAMPLE_VOLUME, -9, "sample volume not finite and > 0") \
    X(FRM_ERR_NO_NEIGHBOR, -10, "a sample has no neighbouring frame") \
    X(FRM_ERR_TOO_MANY_NEIGHBORS, -11, "a sample has more than FRM_MAX_NEIGHBORS (16) neighbouring frames") \
    X(FRM_ERR_NEIGHBOR_TABLE, -12, "neighbour table malformed (start not 0 or decreasing, frame index out of range or repeated)") \
    X(FRM_ERR_WEIGHT_NOT_FINITE, -13, "shape function weight or gradient not finite") \
    X(FRM_ERR_WEIGHT_SUM, -14, "weights of a sample do not sum to one") \
    X(FRM_ERR_GRADIENT_SUM, -15, "weight gradients of a sample do not sum to zero") \
    X(FRM_ERR_FRAME_UNUSED, -16, "a frame carries no mass (no sample gives it a non-zero weight)") \
    X(FRM_ERR_MATERIAL, -17, "unknown constitutive law or material index out of range") \
    X(FRM_ERR_YOUNG_MODULUS, -18, "Young's modulus not finite and > 0") \
    X(FRM_ERR_POISSON_RATIO, -19, "Poisson ratio outside (-1, 0.5)") \
    X(FRM_ERR_DENSITY, -20, "density not finite and > 0") \
    X(FRM_ERR_TIME_STEP, -21, "time step not finite and > 0") \
    X(FRM_ERR_DAMPING, -22, "damping coefficient not finite and >= 0") \
    X(FRM_ERR_SOLVER, -23, "solver settings invalid (tolerances > 0, iteration caps >= 1)") \
    X(FRM_ERR_STIFFNESS_MODE, -24, "unknown stiffness mode, or assembled blocks requested from a matrix-free model") \
    X(FRM_ERR_NOT_FINITE, -25, "result not finite; the last valid state was kept") \
    X(FRM_ERR_NO_CONVERGENCE, -26, "solver did not converge; the last valid state was kept") \
    X(FRM_ERR_INVERTED, -27, "a step or solve would leave a sample inverted or mirrored (det F <= 0; both laws are undefined there); the last valid state was kept") \
    X(FRM_ERR_FRAME_RANGE, -28, "frame index out of range") \
    X(FRM_ERR_NOT_NEIGHBORS, -29, "the two frames share no sample (no stiffness block between them)") \
    X(FRM_ERR_SHAPE_DEGENERATE, -30, "shape function undefined: flat or inverted element, coincident or coplanar frames") \
    X(FRM_ERR_INDEX_RANGE, -31, "element or triangle node index out of range") \
    X(FRM_ERR_SAMPLING, -32, "sampling settings invalid (spacing, Gauss order, support) or too many points") \
    X(FRM_ERR_SURFACE, -33, "triangle surface not closed or encloses no volume") \
    X(FRM_ERR_STALLED, -34, "static solve stalled: the residual stopped falling (a mechanism: rotations the samples do not see, see LIMITS); the last valid state was kept") \
    X(FRM_ERR_PRECISION, -35, "the state is too far from the rest state for the precision of frm_real to represent the strains (see desc.precision_limit); the last valid state was kept") \
    X(FRM_ERR_UNSTABLE, -36, "static solve converged to a saddle (an unstable equilibrium: the tangent has a direction of negative curvature); the last valid state was kept") \
    X(FRM_ERR_POINT_OUTSIDE, -37, "a mapped point lies outside the body: in no element, or farther from each of its frames than that frame's farthest sample") \
    X(FRM_ERR_PART_FRAME, -38, "a part's frame map is malformed: an index out of range or repeated, a model frame no part gives, or two parts giving one frame different rest poses") \
    X(FRM_ERR_RIGID, -39, "rigid body mass not finite and > 0, or its inertia not finite, symmetric positive definite") \
    X(FRM_ERR_SAMPLE_SIZE, -40, "sample size (desc.sample_sizes) not finite and >= 0") \
    X(FRM_ERR_VOLUMETRIC, -41, "volumetric averaging settings invalid (unknown mode, sample_cells missing or out of range, or a frame's averaging volume not > 0)") \
    X(FRM_ERR_BTD_INDEFINITE, -42, "block-tridiagonal factorisation met a negative pivot: the matrix is not positive definite (the failing block is reported)") \
    X(FRM_ERR_BTD_SINGULAR, -43, "block-tridiagonal factorisation met a zero pivot: the matrix is singular to working precision (the failing block is reported)") \
    X(FRM_ERR_COMPLIANCE, -44, "link compliance not finite, not symmetric or not positive definite") \
    X(FRM_ERR_ACTUATOR, -45, "actuator malformed: unknown kind, too few points, a point on a frame outside the chain, coincident cable points, a triangle index out of range or a cavity enclosing no volume") \
    X(FRM_ERR_ACTUATOR_BOUNDS, -46, "actuator bounds invalid (not 0 <= min <= max) or an effort outside them") \
    X(FRM_ERR_UNREACHABLE, -47, "target out of reach: the chain was left at the closest pose found (a valid equilibrium)") \
    X(FRM_ERR_QP_INDEFINITE, -48, "quadratic program not convex (negative curvature beyond round-off)") \
    X(FRM_ERR_DEVICE, -49, "the CUDA companion (frames_cuda.h): no usable device, a device call failed, or the model uses what it does not run (volumetric averaging, a law without a kernel fast path, driven frames)")

enum {
#define FRM__ENUM(name, value, text) name = value,
    FRM_ERROR_LIST(FRM__ENUM)
#undef FRM__ENUM
    FRM_ERR_LAST_ = -50
};

/* Constitutive laws (per sample). They are written in terms of the Green-Lagrange strain
   E = (F^T F - I) / 2 and the second Piola-Kirchhoff stress S (total Lagrangian, eq. 3.37).
   Each law reads its own constants from frm_material (see there) into a block of
   FRM_LAW_PARAMS reals per sample; see HOW TO EXTEND for adding one. */
typedef enum frm_law {
    FRM_LAW_SVK = 0,           /* St Venant-Kirchhoff, W = lambda/2 tr(E)^2 + mu E:E, S eq. 3.53
                                  (young_modulus, poisson_ratio) */
    FRM_LAW_NEO_HOOKEAN = 1,   /* compressible, W = mu/2 (I1 - 3) - mu ln J + lambda/2 (ln J)^2
                                  (young_modulus, poisson_ratio) */
    FRM_LAW_MOONEY_RIVLIN = 2, /* compressible isochoric/volumetric split, the energy of heml.h's
                                  HEML_MOONEY_RIVLIN: W = c1 (I1 J^-2/3 - 3) + c2 (I2 J^-4/3 - 3)
                                  + kappa/2 (J - 1)^2 (c1, c2, bulk_modulus = kappa) */
    FRM_LAW_USER = 3,          /* any isotropic W(I1, I2, J) through callbacks (frm_user_law) */
    FRM_LAW_COUNT              /* sentinel: the number of laws (validation), not a law */
} frm_law;

/* Reals per sample of a law's parameter block (what each law reads, in order):
   SVK, Neo-Hookean: mu, lambda (Pa, from young_modulus and poisson_ratio);
   Mooney-Rivlin: c1, c2, kappa (Pa); user: mu, lambda (Pa, the small-strain moduli given
   by young_modulus and poisson_ratio; the callbacks receive the material's `user`). */
#define FRM_LAW_PARAMS 4

/* Points at which a user law is evaluated: `count` values of each array (frames passes
   one point per call). The inputs are the invariants I1 = tr C, I2 = (I1^2 - tr C^2) / 2
   and J = det F (> 0: frames refuses inverted samples before calling); each callback
   fills its outputs (Pa). The same structure as heml.h's heml_law_points. */
typedef struct frm_law_points {
    int count;
    const frm_real *I1, *I2, *J;
    frm_real *w;                                       /* energy density w, J/m^3 */
    frm_real *w_1, *w_2, *w_J;                         /* dw/dI1, dw/dI2, dw/dJ */
    frm_real *w_11, *w_12, *w_1J, *w_22, *w_2J, *w_JJ; /* second derivatives */
} frm_law_points;

/* An isotropic law given by its derivatives (as heml.h's heml_user_law). `first` and
   `second` are required (frm_model_create refuses FRM_LAW_USER without them: every solver
   of frames needs the tangent); `energy` (may be NULL: the energy then counts 0) feeds
   frm_model_energy and the line searches of the static solve and the implicit step, so
   give it. S = 2 w_1 I + 2 w_2 (I1 I - C) + J w_J C^-1. The law should be stress-free at
   rest (2 w_1 + 4 w_2 + w_J = 0 at I1 = I2 = 3, J = 1) and its small-strain moduli should
   be those of the material's young_modulus and poisson_ratio (they scale the rotation
   stabilisation and the frame coupling). Callbacks run on the calling thread or on worker
   threads (parallel_for / OpenMP) and must be thread-safe and deterministic. */
typedef struct frm_user_law {
    void (*energy)(frm_law_points *points, void *user);
    void (*first)(frm_law_points *points, void *user);
    void (*second)(frm_law_points *points, void *user);
    void *user;
} frm_user_law;

/* How K * v is evaluated inside CG (see PERFORMANCE). */
/* Volumetric treatment against volumetric locking near incompressibility (desc.volumetric;
   see MODEL, volumetric averaging). Every sample's law is evaluated at the F-bar
   F_bar = (J_bar / J)^(1/3) F, J_bar a volume-weighted average of the samples' J. */
typedef enum frm_volumetric {
    FRM_VOLUMETRIC_NONE = 0, /* default: every sample at its own F (the thesis's model) */
    FRM_VOLUMETRIC_CELLS,    /* mean dilatation: J_bar the volume-weighted mean J of the sample's cell
                                (desc.sample_cells; frm_sampling_hexes / _tets fill it): hexahedral
                                frames with several samples a cell */
    FRM_VOLUMETRIC_FRAMES,   /* nodal averaging: J averaged at the frames, then interpolated back to
                                the samples: one-sample tetrahedral frames (any weights >= 0) */
    FRM_VOLUMETRIC_PATCHES,  /* mean dilatation over automatic patches: the samples grouped at create
                                from the neighbour table alone (samples that share frames, about
                                desc.volumetric_patch_size each): one-sample tetrahedral frames of
                                any mesh, no sample_cells needed */
    FRM_VOLUMETRIC_COUNT
} frm_volumetric;

typedef enum frm_stiffness_mode {
    FRM_STIFFNESS_AUTO = 0,  /* choose per linearisation from the cost model (default) */
    FRM_STIFFNESS_PAIRS = 1, /* matrix-free: per-pair data computed once per linearisation */
    FRM_STIFFNESS_BLOCKS = 2 /* 6x6 blocks between neighbouring frames, assembled once */
} frm_stiffness_mode;

/* Time integrators of frm_model_step (see SOLVERS; HOW TO EXTEND for adding one). */
typedef enum frm_integrator {
    FRM_IMPLICIT_EULER = 0,            /* backward Euler: Newton minimisation of the step's incremental
                                          potential to newton_tolerance, line search (default) */
    FRM_IMPLICIT_EULER_LINEARIZED = 1, /* one linearised iteration per step (the thesis's eq. 3.64;
                                          cheaper, accurate only while the step moves little) */
    FRM_BDF2 = 2,                      /* second-order backward differentiation (issue 19): the same
                                          Newton minimisation with (2 dt / 3, xbar, vbar) for
                                          (dt, x_n, v_n); the first step after a discontinuity is
                                          implicit Euler (see SOLVERS, BDF2) */
    FRM_INTEGRATOR_COUNT               /* sentinel: the number of integrators, not one */
} frm_integrator;

/* Linear solvers of every Newton iteration (static solve and implicit steps). */
typedef enum frm_linear_solver {
    FRM_LINEAR_SOLVER_AUTO = -1, /* not a solver: the choice at creation (default): BTD when the model's
                                    stiffness pattern is a chain in frame order, its blocks are
                                    assembled and frm_real is double, CG otherwise (see
                                    BLOCK-TRIDIAGONAL SOLVER);
                                    frm_model_linear_solver tells which */
    FRM_LINEAR_SOLVER_CG = 0,    /* conjugate gradients, block-Jacobi plus the coarse space */
    FRM_LINEAR_SOLVER_BTD = 1,   /* block-tridiagonal LDL^T (issue 15): models whose stiffness pattern is a
                                    chain (frame i coupled to i - 1 and i + 1 only); assembled blocks */
    FRM_LINEAR_SOLVER_COUNT      /* sentinel: the number of solvers (AUTO is none), not one */
} frm_linear_solver;

/* Meshless shape functions (sec. 4.1). */
typedef enum frm_shape {
    FRM_SHAPE_SHEPARD = 0, /* inverse distance, eqs. 4.8-4.9; any point layout, zero order */
    FRM_SHAPE_MLS = 1      /* linear moving least squares: first order, needs 3D spread */
} frm_shape;

/* Where mesh-based samples sit in each hexahedron (frm_sampling_hexes). */
typedef enum frm_quadrature {
    FRM_QUADRATURE_SUBCELL = 0, /* n^3 sub-cell centres, the cell's volume split over them
                                   (sec. 4.1: the thesis's choice; less locking, see LIMITS) */
    FRM_QUADRATURE_GAUSS = 1    /* n^3 Gauss-Legendre points with their weights */
} frm_quadrature;

typedef enum frm_support {
    FRM_SUPPORT_NEAREST = 0, /* the k nearest frames */
    FRM_SUPPORT_RADIUS = 1   /* every frame closer than a radius */
} frm_support;

/* Custom allocator: alloc(size, align, user) returns memory aligned to `align` (a power
   of two <= 64) or NULL; free(ptr, size, user) releases it. */
typedef struct frm_allocator {
    void *(*alloc)(size_t size, size_t align, void *user);
    void (*free)(void *ptr, size_t size, void *user);
    void *user;
} frm_allocator;

/* An engine's job system: run task(task_context, begin, end) over a partition of
   [0, item_count) (any split, any threads) and return when every item is done. */
typedef void (*frm_task_fn)(void *task_context, int begin, int end);
typedef void (*frm_parallel_for_fn)(int item_count, frm_task_fn task, void *task_context, void *user);

/* A material: law and parameters. */
typedef struct frm_material {
    frm_law law;            /* default FRM_LAW_SVK (the thesis's law) */
    frm_real young_modulus; /* Pa, default 1e4 (SVK, Neo-Hookean, user) */
    frm_real poisson_ratio; /* in (-1, 0.5), default 0.3 (SVK, Neo-Hookean, user) */
    frm_real density;       /* kg/m^3, default 1000 */
    frm_real c1, c2;        /* Pa, Mooney-Rivlin constants (>= 0, c1 + c2 > 0); default mu/4 each
                               for the default E and nu (c1 = c2 = 961.5 Pa): small-strain
                               shear modulus 2 (c1 + c2) */
    frm_real bulk_modulus;  /* Pa, Mooney-Rivlin kappa (> 0), default E / (3 (1 - 2 nu)) of the
                               default E and nu (8333.3 Pa) */
    frm_user_law user;      /* FRM_LAW_USER: the callbacks (default all NULL) */
} frm_material;

typedef struct frm_desc {
    /* frames (read during frm_model_create only) */
    const frm_real *frame_positions;    /* 3 * frame_count rest positions, m */
    const frm_real *frame_orientations; /* 4 * frame_count rest orientations, unit quaternions
                                           (x, y, z, w), or NULL for the identity */
    int frame_count;                    /* >= 1 */
    const frm_real *frame_masses;   /* rigid bodies (issue 14): frame_count own masses, kg (>= 0; 0 for a
                                       frame that carries only its samples' mass), or NULL for none;
                                       added to the mass the samples give the frame (see MASS).
                                       frm_parts_combine fills it for its rigid bodies */
    const frm_real *frame_inertias; /* 6 per frame: own inertia about the frame's origin in its rest axes
                                       (xx, yy, zz, yz, xz, xy), kg m^2, positive definite where the
                                       own mass is > 0, zero elsewhere; NULL: none. The own mass sits
                                       at the frame's origin (its centre of mass: gravity acts there) */

    /* samples (integration points) */
    const frm_real *sample_positions; /* 3 * sample_count rest positions, m */
    const frm_real *sample_volumes;   /* sample_count volumes, m^3, > 0; they should add up
                                         to the body's volume */
    int sample_count;                 /* >= 1 */
    const frm_real *sample_sizes;     /* optional sample_count values h^2 (m^2, finite, >= 0): each
                                         sample's mean squared rest lever sum |w| |lbar|^2 / sum |w|,
                                         the length scale of the rotation stabilisation's divergence
                                         term and of the frame coupling (see MODEL); NULL: computed
                                         from the table. frm_parts_combine gives the values of the
                                         parts' own tables where frames attached to a rigid body were
                                         merged (whose levers to the body's origin are not the
                                         sample's size) */
    const unsigned char *sample_linear; /* optional sample_count flags: 1 where the sample's weights
                                           reproduce linear fields (sum_k xbar_k grad w_k^T = I: it
                                           carries the divergence term), 0 where not; NULL: checked
                                           from the table (to 1e-3). frm_parts_combine gives the
                                           parts' own with rigid bodies, as sample_sizes */

    /* neighbour table, compressed rows: sample s uses entries neighbor_start[s] to
       neighbor_start[s + 1] - 1 (1 to FRM_MAX_NEIGHBORS of them). Fill it yourself or
       with frm_sampling_* and frm_sampling_apply. */
    const int *neighbor_start;          /* sample_count + 1 values, neighbor_start[0] = 0 */
    const int *neighbor_frames;         /* frame index of each entry (distinct per sample) */
    const frm_real *neighbor_weights;   /* w_i(p_s) of each entry; per sample they sum to 1 */
    const frm_real *neighbor_gradients; /* 3 per entry, grad w_i(p_s), 1/m; sum to 0 */

    /* materials */
    frm_material material;         /* used by every sample when `materials` is NULL */
    const frm_material *materials; /* optional table of material_count materials */
    int material_count;
    const int *sample_materials; /* optional sample_count indices into `materials` (NULL:
                                    every sample uses materials[0]) */

    frm_real rotation_stabilization; /* dimensionless, default 0.5 (0: the thesis's model exactly):
                                        ties the rotations that a frame's samples do not see
                                        at first order (collinear or single samples, e.g. the
                                        boundary frames of tetrahedra with one sample each) to
                                        the samples' rotation; frames whose samples spread in
                                        3D are not affected (see MODEL and LIMITS) */
    frm_real rotation_divergence; /* dimensionless, default 4 (0: the thesis's model): ties the
                                     divergence of the frames' rotation field to the
                                     material's, which is zero (a rotation field half the curl
                                     of the displacement has none). Removes the frames'
                                     rotations that move no material (tetrahedral frames'
                                     spurious low modes, hexahedral frames' layers turning about
                                     their normal); of order h^2 for smooth fields (see MODEL) */
    frm_volumetric volumetric; /* default FRM_VOLUMETRIC_NONE; _CELLS or _FRAMES remove volumetric
                                  locking near nu = 0.5 (see MODEL, volumetric averaging). The
                                  model is then matrix-free (FRM_STIFFNESS_PAIRS: AUTO picks it,
                                  BLOCKS is refused with FRM_ERR_STIFFNESS_MODE) */
    frm_real volumetric_stabilization; /* dimensionless eta >= 0, default 2: with volumetric averaging,
                                          adds eta mu v / 2 ln^2(J_bar / J) per sample (mu the small-strain
                                          shear modulus): holds the J fluctuations the average does not
                                          see at a shear-like stiffness, which does not lock (see MODEL) */
    const int *sample_cells;   /* FRM_VOLUMETRIC_CELLS: sample_count cell indices >= 0 (the samples
                                  of a cell average their J); frm_sampling_apply sets it from
                                  frm_sampling_hexes / _tets, NULL for meshless samplings */
    int volumetric_patch_size; /* FRM_VOLUMETRIC_PATCHES: samples a patch, about (0: the default,
                                  FRM_VOLUMETRIC_PATCH_SIZE; 1 to FRM_VOLUMETRIC_PATCH_MAX, else
                                  FRM_ERR_VOLUMETRIC); see MODEL, volumetric averaging */
    frm_real frame_coupling; /* dimensionless, default 0 (the thesis's model exactly): weight
                                of the coupling term that ties each frame's own prediction
                                of a sample to the blended position (see MODEL); 1e-2
                                stiffens the rotations a trilinear grid cannot see and is of
                                higher order for smooth fields */

    /* dynamics */
    frm_real gravity[3];        /* m/s^2, default (0, 0, -9.81) */
    frm_real time_step;         /* s, default 1e-2, used by frm_model_step */
    frm_real mass_damping;      /* Rayleigh alpha, 1/s, default 0 */
    frm_real stiffness_damping; /* Rayleigh beta, s, default 0 */

    /* solvers */
    frm_real cg_tolerance;     /* relative residual of each CG solve, default 1e-6 (1e-4 float) */
    int cg_max_iterations;     /* default 1000; a CG solve stopped by it above its tolerance
                                  fails the step or solve (FRM_ERR_NO_CONVERGENCE, state kept):
                                  an unconverged solve never reports success */
    frm_real newton_tolerance; /* static solve: |residual| <= tol * max(|load|, |reactions|);
                                  implicit step: |residual| <= tol * its scale (see SOLVERS);
                                  default 1e-6 (1e-4 float) */
    int newton_max_iterations; /* Newton iterations per static increment or implicit step,
                                  default 30 */
    frm_integrator integrator; /* default FRM_IMPLICIT_EULER: implicit Euler minimises the step's
                                  incremental potential by Newton iterations with a line search;
                                  FRM_IMPLICIT_EULER_LINEARIZED: one linearised iteration per step
                                  (the thesis's eq. 3.64; cheaper, accurate only while the step
                                  moves little, see SOLVERS); FRM_BDF2: second order, the same
                                  Newton (see SOLVERS); frm_model_set_integrator changes it */
    int implicit_linearized;   /* the older spelling of integrator = FRM_IMPLICIT_EULER_LINEARIZED:
                                  0 (default) or 1, which selects the linearised integrator */
    frm_linear_solver linear_solver; /* default FRM_LINEAR_SOLVER_AUTO: BTD for a chain-pattern
                                        model with assembled blocks in double builds, CG
                                        otherwise (resolved at
                                        creation; frm_model_linear_solver); CG or BTD to choose
                                        (BTD refused with FRM_ERR_SOLVER where the pattern is not
                                        a chain) */
    int max_increments;        /* static solve: load increments at most (continuation), default 64 */
    frm_real min_increment;    /* static solve: smallest load fraction of an increment before the
                                  solve gives up, default 1e-4 */
    frm_real precision_limit;  /* dimensionless, default 1e-4: a step or solve fails with
                                  FRM_ERR_PRECISION when eps(frm_real) max|u| > precision_limit
                                  h_min (u the frames' displacement from rest, h_min the
                                  smallest rest lever between a sample and its frames): the
                                  rounding of the state would fake strains above it; 0 disables */
    frm_real static_regularization; /* static solves add this times |K_ii| to each frame's
                                       rotational diagonal inside CG (not to the forces: the
                                       equilibrium is unchanged), default 1e-10 (at least 1e-6
                                       in the positive-definite fallback). Larger values slow
                                       Newton on slender bodies, whose softest bending modes
                                       sit near 1e-7 of the diagonal; 0 gives the plain
                                       Newton step */
    frm_stiffness_mode stiffness_mode; /* default FRM_STIFFNESS_AUTO */
    int coarse_aggregates;     /* two-level preconditioner (see SOLVERS, >>coarse): at most this
                                  many aggregates of frames (cells of the rest bounding box, at
                                  least FRM_COARSE_MIN_FRAMES frames each), whose rigid motions
                                  form a coarse space solved exactly on top of block-Jacobi in
                                  every CG solve; 0 = block-Jacobi only. Default
                                  FRM_COARSE_AGGREGATES (0 to FRM_COARSE_MAX_AGGREGATES) */

    /* environment */
    frm_allocator allocator;          /* all NULL: FRM_MALLOC / FRM_FREE */
    frm_parallel_for_fn parallel_for; /* NULL: OpenMP if compiled with it, else serial */
    void *parallel_user;
    int parallel_min_pairs;           /* models with fewer pairs run serially (starting
                                         threads costs more), default FRM_PARALLEL_MIN_PAIRS */
    void (*log)(int code, const char *message, void *user); /* validation details, or NULL */
    void *log_user;

    unsigned int internal_cookie; /* set by frm_model_default_desc; do not touch */
} frm_desc;

/* Statistics of the last step or static solve (frm_model_last_stats). The first eleven
   fields are common to the three headers (same names, meanings and order). */
typedef struct frm_stats {
    int newton_iterations;     /* Newton iterations, summed over increments (1 for a linearised
                                  implicit step) */
    int cg_iterations;         /* CG iterations, summed */
    frm_real cg_residual;      /* relative residual |r| / |b| of the last linear solve */
    frm_real residual;         /* final nonlinear residual over its reference scale (static
                                  solve: |f| / max(|load|, |reactions|); Newton implicit step:
                                  see SOLVERS); 0 where there is none */
    int increments;            /* static solve: continuation increments accepted (1: the whole
                                  load at once) */
    int increment_cuts;        /* static solve: increments cut back after a failed attempt */
    int line_search_cuts;      /* line-search step reductions, summed */
    int negative_curvature;    /* linear solves that met a direction of non-positive curvature */
    int inverted;              /* samples with det F <= 0 at the end (0 on success: both laws
                                  refuse det F <= 0, no allow_inversion option in frames) */
    int force_evaluations;     /* force passes */
    int stiffness_products;    /* K * v products */
    /* frames' own */
    int cg_iterations_last;    /* CG iterations of the last linear solve */
    frm_real residual_force;   /* the final residual itself, |f| over the free components (N and
                                  N m; implicit: N s) */
    frm_real initial_residual; /* static solve: |f| before the first iteration */
    int definite_solves;       /* linear solves redone with the positive-definite part of K because the
                                  linearisation was indefinite (see SOLVERS) */
    int stiffness_mode;        /* FRM_STIFFNESS_PAIRS or FRM_STIFFNESS_BLOCKS (last linearisation) */
} frm_stats;

/* Energies of the current state (frm_model_energy), J. */
typedef struct frm_energies {
    double elastic;       /* sum over samples of v_s W(F_s) */
    double kinetic;       /* 1/2 sum over frames of v^T M_i v (generalized mass, see MASS) */
    double gravitational; /* -g . (moved mass moments), zero at rest */
    double external;      /* -sum f_ext . (x - x_rest): potential of the external forces */
} frm_energies;

/* Meshless shape functions for frm_sampling_meshless / _box / _surface. */
typedef struct frm_shape_desc {
    frm_shape shape;     /* default FRM_SHAPE_SHEPARD */
    frm_support support; /* default FRM_SUPPORT_NEAREST */
    int nearest;         /* k for FRM_SUPPORT_NEAREST, 1..16 (MLS needs >= 4), default 8 */
    frm_real radius;     /* m: the support radius for FRM_SUPPORT_RADIUS; ignored otherwise */
    frm_real power;      /* Shepard exponent p of eq. 4.9, > 1, default 2 */
    unsigned int internal_cookie; /* set by frm_shape_default_desc; do not touch */
} frm_shape_desc;

/* Poisson-disk sampling of a domain (thesis sec. 4.1, "Domain sampling", after Bridson
   2007): frames from a coarser distance than samples. */
typedef struct frm_poisson_desc {
    frm_real frame_spacing;  /* m, least distance between frames, >= sample_spacing */
    frm_real sample_spacing; /* m, least distance between samples */
    unsigned int seed;       /* same seed, same points, on every platform; default 1 */
    frm_real volume;         /* m^3 split evenly over the samples; <= 0 (default): the
                                domain's own volume (needed for a flat or linear box) */
    int max_points;          /* refuse (FRM_ERR_SAMPLING) to make more points, default 1e6 */
    unsigned int internal_cookie; /* set by frm_poisson_default_desc; do not touch */
} frm_poisson_desc;

/* Frames, samples and their neighbour table, owning its arrays: what frm_sampling_*
   make and frm_sampling_apply puts into a description. Free with frm_sampling_free. */
typedef struct frm_sampling {
    int frame_count, sample_count, pair_count;
    frm_real *frame_positions;    /* 3 * frame_count, m */
    frm_real *sample_positions;   /* 3 * sample_count, m */
    frm_real *sample_volumes;     /* sample_count, m^3 */
    int *neighbor_start;          /* sample_count + 1 */
    int *neighbor_frames;         /* pair_count */
    frm_real *neighbor_weights;   /* pair_count */
    frm_real *neighbor_gradients; /* 3 * pair_count, 1/m */
    int cell_count;               /* mesh samplings: the elements; 0 for meshless ones */
    int *sample_cells;            /* sample_count element indices (NULL when cell_count is 0) */
    frm_allocator allocator;      /* the one the arrays came from */
} frm_sampling;

typedef struct frm_model frm_model;

/* A plain view of a created model's arrays: what a backend running the two passes of the
   force and of K v needs (>>kernels: frm_pass1_*, frm_pass2_*), and nothing else. The CPU
   loops and the CUDA companion (frames_cuda.cu, see CUDA) call the same FRM_HOSTDEV pass
   functions on it; frm_model_view fills one that points into the model's block (valid
   until frm_model_destroy; a GPU backend copies the arrays and points a view of its own at
   its copies). Counts: frames, samples, pairs; per frame i the reverse table
   rev_pair[rev_start[i] .. rev_start[i + 1]) lists its pairs in pair order; per sample s
   its pairs are s_start[s] .. s_start[s + 1]. Arrays the pass functions only read are
   const; the outputs (p_out: 6 per pair, pass 1's partial force or K v) and the
   linearisation's data (written by the force pass when it linearises) are not. NULL for
   an option that is off (p_stab, s_stabY, s_stabD without the rotation stabilisation,
   p_C without the coupling term). Units as in struct frm_model's comments (SI). */
typedef struct frm_view {
    int frame_count, sample_count, pair_count;
    int law_cache;                   /* reals of lin_cache per sample */
    /* per frame */
    const frm_real *disp;            /* 3: u = x - xbar (m), the state */
    const frm_real *rel, *relm;      /* 9 each: Q = R Rbar^T and Q - I (frm_frame_rotations) */
    const frm_real *f_stab;          /* 6: projector on the rotations its samples do not see, or 0 */
    const unsigned char *f_stab_on;  /* 1: f_stab is not zero */
    const int *rev_start, *rev_pair; /* frame_count + 1, pair_count: the reverse table */
    frm_real *lin_hrot;              /* 6: the frame-own rotational term at the linearisation */
    /* per sample */
    const int *s_start;                        /* sample_count + 1 */
    const frm_real *s_rest, *s_volume;         /* 3 (m), 1 (m^3) */
    const frm_real *s_couple, *s_mu, *s_hstab; /* coupling coefficient, shear modulus (Pa), gamma h^2 (m^2) */
    const unsigned char *s_law, *s_stab;       /* frm_law; 1 if the stabilisation acts on it */
    const frm_real *s_law_params;              /* FRM_LAW_PARAMS per sample (mu, lambda first for the
                                                  kernels' laws, frm_material_stress) */
    frm_real *s_stabY, *s_stabD;               /* 9, 1: the stabilisation at the linearisation */
    frm_real *lin_F, *lin_S, *lin_cache;       /* 9, 6, law_cache: the linearisation's F, S, tangent data */
    frm_real *s_pos;                           /* 3: sample positions (outputs) */
    /* per pair (sample, neighbour) */
    const int *p_frame;                        /* the neighbour's frame */
    const frm_real *p_weight, *p_grad, *p_rlev; /* 1, 3 (1/m), 3 (m): w, grad w, rest lever abar */
    frm_real *p_G, *p_H, *p_A, *p_C, *p_stab;  /* 9, 6, 3, 3, 3: the linearisation's G, Hs, lever a,
                                                  coupling g, stabilisation conjugate */
    frm_real *p_out;                           /* 6: pass 1's partial contributions */
    /* what a backend's solver needs besides the passes (frames_cuda.cu's implicit step) */
    const frm_real *quat, *rest_quat, *vel;    /* 4, 4, 6 per frame: the state (with disp) */
    const frm_real *ext;                       /* 6 per frame: external force (N), torque (N m) */
    const unsigned char *state, *axes;         /* per frame: 0 free, 1 fixed, 2 driven; held axes bits */
    const double *mass_local, *grav_local;     /* 10, 4 per frame: m, cbar, Jbar (rest axes); m_g, cbar_g */
    const frm_real *kdiag_rest;                /* 36 per frame: the rest K_ii (pair mode's preconditioner) */
    frm_real gravity[3];                       /* m/s^2 */
    frm_real time_step, mass_damping, stiffness_damping, cg_tolerance; /* s, 1/s, s, relative */
    int cg_max_iterations;
    int volumetric;                            /* desc.volumetric (frm_volumetric): the CPU passes' extra stages */
} frm_view;

/* Library version string "major.minor.patch". */
FRMDEF const char *frm_version(void);
/* Name of an error code (static string). */
FRMDEF const char *frm_error_string(int code);

/* ---- shape functions (sec. 4.1): pure functions, no allocation. Each gives weights that
   sum to one and their exact gradients, which sum to zero. Computed in double. ---- */

/* Tetrahedral barycentric (linear) functions of the 4 corners (12 coordinates, m, any
   orientation) at point: weights[4], gradients[4 * 3] (1/m, constant in the element).
   FRM_ERR_SHAPE_DEGENERATE for a flat tetrahedron; FRM_ERR_ARG for a non-finite corner or point. */
FRMDEF int frm_shape_tet(const frm_real corners[12], const frm_real point[3], frm_real weights[4],
                         frm_real gradients[12]);
/* Hexahedral trilinear functions of the 8 corners (corner (a, b, c), a, b, c in {0, 1}, is
   index a + 2 b + 4 c, as hexmesh_grid in examples/tetmesh.h) at the parametric point
   xi in [0, 1]^3: the physical point (may be NULL), weights[8], gradients[8 * 3] (1/m)
   and det(dx/dxi) (m^3, may be NULL). FRM_ERR_SHAPE_DEGENERATE if det <= 0 there;
   FRM_ERR_ARG for a non-finite corner or xi. */
FRMDEF int frm_shape_hex(const frm_real corners[24], const frm_real xi[3], frm_real point[3],
                         frm_real weights[8], frm_real gradients[24], frm_real *jacobian_det);
/* Shepard inverse-distance functions (eqs. 4.8-4.9) of `count` frames (3 * count
   coordinates) at point, exponent power > 1. radius <= 0: w_i ~ 1/d_i^p (the thesis's
   form); radius > 0: w_i ~ ((R - d_i)+ / (R d_i))^p (Franke-Little, zero at the support's
   edge; frames beyond R get weight 0, at least one must be inside). A point on a frame
   gets that frame's weight 1 and zero gradients (the limit for p > 1). Coplanar and
   collinear frames are fine. FRM_ERR_SHAPE_DEGENERATE if two frames coincide; FRM_ERR_ARG
   for a non-finite frame or point, power <= 1 or not finite, radius not finite. */
FRMDEF int frm_shape_shepard(const frm_real *frames, int count, const frm_real point[3], frm_real power,
                             frm_real radius, frm_real *weights, frm_real *gradients);
/* Linear moving least squares functions (eqs. 4.5-4.7 with p = [1 x y z]) of `count`
   frames at point, Wendland C2 kernel of support radius > 0 (m). First-order
   consistent: sum w_i x_i = point and sum x_i grad w_i^T = I. Weights may be negative.
   FRM_ERR_SHAPE_DEGENERATE if the frames inside the radius are fewer than 4 or (nearly)
   coplanar: the moment matrix is singular (table 4.1); FRM_ERR_ARG for a non-finite frame,
   point or radius. */
FRMDEF int frm_shape_mls(const frm_real *frames, int count, const frm_real point[3], frm_real radius,
                         frm_real *weights, frm_real *gradients);

/* ---- sampling: frames, samples and neighbour tables (allocate; free with
   frm_sampling_free). allocator may be NULL (FRM_MALLOC / FRM_FREE). On failure *out
   is left empty. ---- */

/* Mesh-based, hexahedra: a frame at every node (nodes: 3 * node_count, m; every node must
   belong to a hexahedron) and points^3 samples per hexahedron (points = 1 to 4 per axis)
   with the 8 trilinear neighbours (frm_shape_hex): at the centres of points^3 equal
   sub-cells of the parameter cube, each with the volume of its sub-cell (rule
   FRM_QUADRATURE_SUBCELL), or at the Gauss-Legendre points with their quadrature weights
   (FRM_QUADRATURE_GAUSS); volumes are weight * det(dx/dxi). Hex node order as in
   frm_shape_hex; each must be positively oriented (det > 0 at every sample). */
FRMDEF int frm_sampling_hexes(frm_sampling *out, const frm_real *nodes, int node_count, const int *hexes,
                              int hex_count, int points, frm_quadrature rule, const frm_allocator *allocator);
/* Mesh-based, tetrahedra: a frame at every node and `points` samples per tetrahedron at
   the barycentric coordinates `barycentric` (4 per point, summing to 1), or, when it is
   NULL, at the symmetric Gauss points for points = 1 (centroid) or 4 (degree 2); the
   element's volume is split evenly over its samples; 4 barycentric neighbours each. */
FRMDEF int frm_sampling_tets(frm_sampling *out, const frm_real *nodes, int node_count, const int *tets,
                             int tet_count, int points, const frm_real *barycentric,
                             const frm_allocator *allocator);
/* Mesh-based, a curve (issue 14, thin parts): a rod of constant cross-section along the
   open polyline of node_count >= 2 nodes (3 each, m; consecutive nodes distinct), a frame
   at every node. Each segment (length l, unit tangent t) gets one station at its midpoint
   with 4 samples of volume l A / 4 in its cross-section, weights 1/2 and gradients -+ t / l
   (linear along the curve, the frames' rotations carry the section): a rectangle
   section[0] x section[1] (section[1] along the height axis `up`, made normal to t per
   segment; NULL: world z, or world y for a segment within 45 degrees of z) at the 2 x 2
   Gauss points +-w / (2 sqrt 3), +-h / (2 sqrt 3), or, with section[1] = 0, a disk of
   radius section[0] at 4 points r / sqrt 2 off the axis: both integrate a bending strain
   linear across the section exactly. One station a segment is the reduced axial rule that
   keeps the rod's shear from locking (two Gauss stations: the sag 67 % short at 16
   segments, see LIMITS, thin parts). The sections are rigid (the frames carry them): give the
   material through frm_material_thin(.., 1). sample_cells holds the segment. FRM_ERR_ARG
   for missing or non-finite arguments, FRM_ERR_SAMPLING for a section not > 0, a repeated
   node or an `up` along a segment. */
FRMDEF int frm_sampling_curve(frm_sampling *out, const frm_real *nodes, int node_count, const frm_real section[2],
                              const frm_real up[3], const frm_allocator *allocator);
/* Material constants for thin parts whose thickness the frames do not resolve (issue 14;
   St Venant-Kirchhoff and Neo-Hookean, whose small-strain moduli are E and nu): replaces
   m->young_modulus and m->poisson_ratio by those of the isotropic law with the same shear
   modulus mu whose response under the thin part's kinematic constraint is the thin
   continuum's. dimensions = 1, a curve of frames (frm_sampling_curve: rigid sections,
   eps_yy = eps_zz = 0): lambda' = E nu / (1 + nu), so that lambda' + 2 mu = E (uniaxial
   stress); nu' = nu / (1 + 2 nu), E' = E (1 + 3 nu) / ((1 + nu) (1 + 2 nu)). dimensions =
   2, a layer one element thick whose through-thickness strain is constant (tetrahedral
   frames, 4 Gauss points: the bending's Poisson strain across the layer is not
   representable): lambda' = 2 mu lambda / (lambda + 2 mu), the plane-stress modulus;
   nu' = nu / (1 + nu), E' = E (1 + 2 nu) / (1 + nu)^2. Exact for bending; a membrane
   state whose thickness is free is then 5 % soft in E at nu = 0.3 (keep the true material
   for membranes). FRM_ERR_ARG for another law, dimensions or a NULL m;
   FRM_ERR_MATERIAL for E or nu out of range. */
FRMDEF int frm_material_thin(frm_material *m, int dimensions);
/* Meshless: the given frames and samples (3 coordinates each), total volume (m^3) split
   evenly over the samples, neighbours and weights from the shape description (NULL: the
   default one). */
FRMDEF int frm_sampling_meshless(frm_sampling *out, const frm_real *frames, int frame_count,
                                 const frm_real *samples, int sample_count, frm_real volume,
                                 const frm_shape_desc *shape, const frm_allocator *allocator);
/* Meshless, Poisson-disk points in the box [lo, hi] (an axis with lo = hi gives a flat or
   linear domain; give its volume, e.g. area times thickness, in p->volume). */
FRMDEF int frm_sampling_box(frm_sampling *out, const frm_real lo[3], const frm_real hi[3],
                            const frm_poisson_desc *p, const frm_shape_desc *shape,
                            const frm_allocator *allocator);
/* Meshless, Poisson-disk points inside a closed, consistently oriented triangle surface
   (3 * vertex_count coordinates, 3 * triangle_count zero-based indices). Inside means an
   odd number of crossings of a ray along +z; the volume defaults to the enclosed one. */
FRMDEF int frm_sampling_surface(frm_sampling *out, const frm_real *vertices, int vertex_count,
                                const int *triangles, int triangle_count, const frm_poisson_desc *p,
                                const frm_shape_desc *shape, const frm_allocator *allocator);
/* Points the description's frame, sample and neighbour fields and sample_cells (NULL for
   meshless samplings) at the sampling's arrays (which must outlive frm_model_create, not
   the model); it does not set desc.volumetric. */
FRMDEF void frm_sampling_apply(const frm_sampling *s, frm_desc *d);
/* Frees the arrays and empties the struct. */
FRMDEF void frm_sampling_free(frm_sampling *s);
/* Defaults as documented in the fields. */
FRMDEF frm_shape_desc frm_shape_default_desc(void);
FRMDEF frm_poisson_desc frm_poisson_default_desc(void);

/* ---- several parts in one model (issue 14; 2013 paper sec. 4.2 and fig. 5): each part
   has its own sampling (frames, samples, neighbour table, any shape functions), material
   and density, and says which of the model's frames its frames are, so parts share frames
   where the caller says (the interface frames of a split body, the surface frames of two
   organs a connective layer joins). frm_parts_combine makes one sampling of them with a
   material per part; the model built from it is one mechanical system (one mass, one
   stiffness, one solve): a shared frame gets the mass, forces and stiffness of every part
   whose samples use it. ---- */

typedef struct frm_part {
    const frm_sampling *sampling; /* the part alone: its frames, samples and neighbour table (read
                                     during frm_parts_combine only) */
    frm_material material;        /* law, constants and density of every sample of the part
                                     (default: frm_model_default_desc's material) */
    const int *frame_map;         /* sampling->frame_count model frame indices: the part's frame j is
                                     the model's frame frame_map[j] (distinct within the part);
                                     NULL: frame j is the model's frame j */
} frm_part;

/* A rigid body (issue 14; 2013 paper sec. 4.2): one model frame with its own mass and
   inertia (not from samples), its origin at the body's centre of mass. Part frames mapped
   onto it (frame_map[j] = frame) are attached: they move rigidly with the body ("the frames
   of the interface have a rigid motion w.r.t. the rigid body") and are eliminated through
   the rigid map (see RIGID BODIES): the samples that used them use the body's frame, so the
   deformable part's reaction moves the body. A body no part attaches to is a free rigid
   body. */
typedef struct frm_rigid_body {
    int frame;            /* the model frame that is the body (default -1: set it) */
    frm_real position[3]; /* m, its rest position: the centre of mass */
    frm_real mass;        /* kg, > 0 */
    frm_real inertia[6];  /* kg m^2, the inertia tensor about the centre of mass in world axes at rest
                             (xx, yy, zz, yz, xz, xy), symmetric positive definite */
} frm_rigid_body;

/* The combined model description's arrays, owned (frm_assembly_free). */
typedef struct frm_assembly {
    frm_sampling sampling;   /* the model's frame_count frames (rest positions from the parts
                                that give them, a rigid body's from the body), the samples of
                                part 0, then part 1, ... with their neighbour tables mapped to
                                the model's frames (entries of frames attached to one rigid
                                body merged) */
    frm_material *materials; /* part_count: part k's material */
    int *sample_materials;   /* sample_count: the part of each sample */
    int *part_samples;       /* part_count + 1: part k's samples are part_samples[k] ..
                                part_samples[k + 1] - 1 */
    frm_real *frame_masses;   /* frame_count: the rigid bodies' masses, 0 elsewhere (kg) */
    frm_real *frame_inertias; /* 6 per frame: the rigid bodies' inertias, 0 elsewhere (kg m^2) */
    frm_real *sample_sizes;   /* sample_count: h^2 of each sample from its part's own table (m^2, see
                                 desc.sample_sizes), given to the model with rigid bodies */
    unsigned char *sample_linear; /* sample_count: its part's weights reproduce linear fields (see
                                     desc.sample_linear), given to the model with rigid bodies */
    int part_count, rigid_count;
    frm_allocator allocator;  /* the one the arrays came from */
    size_t bytes;             /* of the block holding the arrays above but the sampling's */
} frm_assembly;

/* A part with the default material and no frame map. */
FRMDEF frm_part frm_part_default(void);
/* A rigid body with every field zero and frame -1 (to be set). */
FRMDEF frm_rigid_body frm_rigid_body_default(void);
/* Combines part_count parts and rigid_count rigid bodies (rigids may be NULL for 0) into a
   model of frame_count frames. Every model frame must be given by a part or be a rigid
   body's; parts giving the same (non-rigid) frame must give it the same rest position
   (within 1e-9 of the body's size; float 1e-5); part frames mapped onto a rigid body's
   frame are attached to it (any rest position). Errors: FRM_ERR_ARG (NULL, part_count < 1,
   frame_count < 1, a part without frames or samples, a body's position not finite),
   FRM_ERR_PART_FRAME (a map index out of range, or repeated within a part on a non-rigid
   frame, a NULL map with more part frames than frame_count, a model frame nobody gives,
   rest positions that differ, a body's frame out of range or two bodies on one frame),
   FRM_ERR_RIGID (a body's mass not > 0, its inertia not positive definite),
   FRM_ERR_NEIGHBOR_TABLE (a part's row malformed), FRM_ERR_ALLOC; *out is then empty.
   Materials and the merged table are validated by frm_model_create. Cells (issue 13's
   FRM_VOLUMETRIC_CELLS): when every part's sampling has them (mesh samplings), the
   combination numbers each part's cells after the previous parts' (no averaging across
   parts); otherwise it has none and a model asking for cell averaging is refused.
   FRM_VOLUMETRIC_PATCHES needs no cells: its patches may span parts that share frames,
   never two materials. */
FRMDEF int frm_parts_combine(frm_assembly *out, const frm_part *parts, int part_count, const frm_rigid_body *rigids,
                             int rigid_count, int frame_count, const frm_allocator *allocator);
/* Points the description's frames, samples, neighbour table, materials, sample_materials
   and (with rigid bodies) frame_masses and frame_inertias at the assembly (which must outlive frm_model_create, not the model). */
FRMDEF void frm_assembly_apply(const frm_assembly *a, frm_desc *d);
/* Frees the assembly's arrays and empties it. */
FRMDEF void frm_assembly_free(frm_assembly *a);

/* ---- model ---- */

/* A description with the documented defaults; always start from it. */
FRMDEF frm_desc frm_model_default_desc(void);
/* Validates the description and creates a model in *out (NULL on failure). Allocates all
   the model's memory (one block, plus temporary tables freed before returning); the
   description's arrays may be freed afterwards. */
FRMDEF int frm_model_create(const frm_desc *desc, frm_model **out);
/* Frees the model and everything it owns. NULL is allowed. */
FRMDEF void frm_model_destroy(frm_model *m);

/* ---- boundary conditions and loads (no allocation) ---- */

/* Holds frame i at its current pose (position and orientation). */
FRMDEF int frm_model_fix_frame(frm_model *m, int i);
/* Drives frame i to a prescribed pose (position m, unit quaternion (x, y, z, w)): the
   next step moves it there (its velocity over the step follows), a static solve starts
   with it there. The pose stays prescribed until frm_model_release_frame. */
FRMDEF int frm_model_drive_frame(frm_model *m, int i, const frm_real position[3],
                                 const frm_real orientation[4]);
/* Frees a fixed or driven frame (and its held axes). */
FRMDEF int frm_model_release_frame(frm_model *m, int i);
/* Holds some components of a free frame at their current values: bit k (k = 0, 1, 2 for
   x, y, z, world axes) of translation_axes holds the position's component k, bit k of
   rotation_axes the rotation about world axis k (symmetry planes: the normal translation
   and the two in-plane rotations; rollers; plane strain). The static solve, the implicit
   step and CG project those components out (their velocity is zero). 0, 0 frees them;
   fixing, driving or releasing the frame clears them. FRM_ERR_ARG for masks above 7 or a
   fixed or driven frame. */
FRMDEF int frm_model_set_frame_axes(frm_model *m, int i, unsigned translation_axes, unsigned rotation_axes);
/* The held axes of frame i: translation mask | rotation mask << 3 (0 for none), < 0 on
   error. */
FRMDEF int frm_model_frame_axes(const frm_model *m, int i);
/* 0 free, 1 fixed, 2 driven, < 0 error. */
FRMDEF int frm_model_frame_state(const frm_model *m, int i);
/* Constant external force (N) and torque (N m, about the frame's origin), world axes, on
   frame i (replaces the previous ones). Either may be NULL for zero. */
FRMDEF int frm_model_set_external(frm_model *m, int i, const frm_real force[3], const frm_real torque[3]);
/* Sets every external force and torque to zero. */
FRMDEF void frm_model_clear_external(frm_model *m);
/* Gravity, m/s^2. */
FRMDEF int frm_model_set_gravity(frm_model *m, const frm_real g[3]);
/* Rayleigh damping after creation: mass_damping alpha (1/s) and stiffness_damping beta (s),
   both finite and >= 0 (FRM_ERR_DAMPING otherwise, nothing changed); the next step uses
   them (as desc.mass_damping / stiffness_damping). No allocation. */
FRMDEF int frm_model_set_damping(frm_model *m, frm_real mass_damping, frm_real stiffness_damping);
/* The integrator of later steps (as desc.integrator; heml.h and tensormass.h take it per
   step in *_step_ex). BDF2's history restarts: the next step is implicit Euler.
   FRM_ERR_SOLVER for a value outside frm_integrator. No allocation. */
FRMDEF int frm_model_set_integrator(frm_model *m, frm_integrator integrator);
/* CG tolerance (> 0) and cap (>= 1), Newton tolerance (> 0) and cap (>= 1). */
FRMDEF int frm_model_set_solver(frm_model *m, frm_real cg_tolerance, int cg_max_iterations,
                                frm_real newton_tolerance, int newton_max_iterations);
/* Chooses how later linear solves evaluate K * v. FRM_STIFFNESS_BLOCKS and AUTO need the
   block storage, reserved at creation unless the description asked for PAIRS. */
FRMDEF int frm_model_set_stiffness_mode(frm_model *m, frm_stiffness_mode mode);

/* ---- simulation ---- */

/* One implicit Euler step (eq. 3.64) of the description's time step (see frm_model_step_ex). */
FRMDEF int frm_model_step(frm_model *m);
/* One implicit Euler step of dt seconds: Newton iterations with a line search on the
   step's incremental potential to newton_tolerance (or, with implicit_linearized, the
   single linearisation
       (M (1 + dt alpha) + (dt^2 + dt beta) K) dv = dt (f - (dt + beta) K v - alpha M v),
   v += dv, x += dt v), q = exp(dt omega) q (renormalised); see SOLVERS. On failure (not
   finite, not converged, a CG solve at its cap, a sample newly inverted, precision) the
   state is unchanged. */
FRMDEF int frm_model_step_ex(frm_model *m, frm_real dt);
/* Static equilibrium (sec. 3.6) by Newton iterations with a backtracking line search on
   the total potential energy, each solved by two-level preconditioned CG, inside an adaptive load
   continuation (see SOLVERS); velocities are set to zero. Driven frames end at their
   prescribed poses. On failure (see ERRORS) the state is unchanged. */
FRMDEF int frm_model_solve_static(frm_model *m);
/* One Newton iteration of the static solve (for watching it converge). *residual (may be
   NULL) receives |f| over the free frames after the iteration. Velocities set to zero. */
FRMDEF int frm_model_newton_step(frm_model *m, frm_real *residual);

/* ---- state access (pointers into the model, valid until frm_model_destroy) ---- */

FRMDEF int frm_model_frame_count(const frm_model *m);
FRMDEF int frm_model_sample_count(const frm_model *m);
FRMDEF int frm_model_pair_count(const frm_model *m); /* (sample, neighbour) entries */
FRMDEF const frm_real *frm_model_positions(const frm_model *m);    /* 3 per frame, m */
FRMDEF const frm_real *frm_model_orientations(const frm_model *m); /* 4 per frame (x, y, z, w) */
FRMDEF const frm_real *frm_model_velocities(const frm_model *m);   /* 6 per frame: m/s, rad/s (world) */
FRMDEF const frm_real *frm_model_displacements(const frm_model *m); /* 3 per frame: x - xbar, m (the state) */
FRMDEF const frm_real *frm_model_rest_positions(const frm_model *m); /* 3 per frame, m */
/* Overwrites every frame's pose (3 + 4 values per frame; quaternions must be unit) or
   velocities (6 per frame). Finite values only. */
FRMDEF int frm_model_set_poses(frm_model *m, const frm_real *positions, const frm_real *orientations);
FRMDEF int frm_model_set_velocities(frm_model *m, const frm_real *velocities);
/* Current sample positions (eq. 3.34), 3 per sample, m: computed into the model's array. */
FRMDEF const frm_real *frm_model_sample_positions(frm_model *m);
/* Current deformation gradients (eq. 3.40), 9 per sample, row-major: computed. */
FRMDEF const frm_real *frm_model_deformation_gradients(frm_model *m);
/* Internal elastic generalized forces (eq. 3.52), 6 per frame: force N, torque N m about
   the frame origin, world axes (no gravity or external load). One force pass (see
   PERFORMANCE). FRM_ERR_INVERTED / FRM_ERR_NOT_FINITE leave *out NULL. */
FRMDEF int frm_model_forces(frm_model *m, const frm_real **out);
/* The total generalized force, 6 per frame: internal + gravity (the samples' weight, which
   also has a torque about the frame's origin) + external. The static solve drives it to
   zero on the free frames. One force pass; same errors as frm_model_forces. */
FRMDEF int frm_model_total_forces(frm_model *m, const frm_real **out);
/* Energies of the current state (one force pass). */
FRMDEF int frm_model_energy(frm_model *m, frm_energies *out);
/* Statistics of the last step or solve. */
FRMDEF const frm_stats *frm_model_last_stats(const frm_model *m);
/* The linear solver the model's Newton iterations use: FRM_LINEAR_SOLVER_CG or
   FRM_LINEAR_SOLVER_BTD, desc.linear_solver as resolved at creation (never AUTO; CG while
   anchors are set on a model where AUTO chose BTD); FRM_LINEAR_SOLVER_COUNT for NULL. */
FRMDEF frm_linear_solver frm_model_linear_solver(const frm_model *m);
/* The 6x6 generalized mass of frame i at its current orientation, row-major (kg, kg m,
   kg m^2; see MASS). */
FRMDEF int frm_model_mass_block(const frm_model *m, int i, frm_real out[36]);
/* Bytes held by the model. */
FRMDEF size_t frm_model_memory_bytes(const frm_model *m);
/* Frames whose rotation the rotation stabilisation holds (their samples do not see it at
   first order; see MODEL), 0 with rotation_stabilization = 0. */
FRMDEF int frm_model_stabilized_frames(const frm_model *m);
/* Fills *out with a view of the model's arrays (see frm_view), for a backend running the
   passes (frames_cuda.cu). FRM_ERR_ARG on NULL. */
FRMDEF int frm_model_view(const frm_model *m, frm_view *out);

/* ---- stiffness (K = -df/dq, 6 per frame: translation, then rotation about world axes:
   a rotation dtheta moves R to exp([dtheta]x) R) ---- */

/* Linearises at the current state: one force pass that also stores the per-pair data of
   the chosen stiffness mode (or assembles the blocks). */
FRMDEF int frm_model_prepare_stiffness(frm_model *m);
/* out = K v (6 per frame each) at the last linearisation, every frame included (fixed or
   not). symmetric = 0: the exact derivative of the force (the rotational diagonal blocks
   carry an antisymmetric part 1/2 [tau]x from the torques, because rotations do not
   commute); 1: its symmetric part, the Hessian of the energy in rotation-vector
   coordinates, which the solvers use. Matrix-free or by blocks as prepared. */
FRMDEF int frm_model_apply_stiffness(frm_model *m, const frm_real *v, frm_real *out, int symmetric);
/* Assembles the 6x6 blocks (symmetric part) at the current state. Needs the block storage
   (FRM_ERR_STIFFNESS_MODE otherwise). */
FRMDEF int frm_model_assemble_stiffness(frm_model *m);
/* The assembled block pattern: row i holds blocks row_start[i] .. row_start[i + 1] - 1
   with frame columns cols[...] (sorted, the diagonal included); blocks (36 per block,
   row-major, N/m, N/rad, N m/rad) valid after frm_model_assemble_stiffness or a solve in
   block mode. NULL without block storage. */
FRMDEF const frm_real *frm_model_stiffness_blocks(const frm_model *m, const int **row_start,
                                                  const int **cols);
/* Copies the block between frames i and j (after assembling). */
FRMDEF int frm_model_stiffness_block(const frm_model *m, int i, int j, frm_real out[36]);

/* ---- point probes (issue 19): a material point's position, displacement and velocity
   from the frames through the shape functions at its rest position, p = sum_i w_i (x_i +
   R_i lbar_i) (eq. 3.34), the weights found once at frm_probe_create. The model keeps no
   mesh, so the description says which shape functions the samples came from. ---- */

typedef enum frm_probe_kind {
    FRM_PROBE_TETS = 0,    /* mesh-based tetrahedra (frm_sampling_tets): `elements` holds 4 frame
                              indices per tetrahedron; barycentric weights in the containing one */
    FRM_PROBE_HEXES = 1,   /* mesh-based hexahedra (frm_sampling_hexes): 8 frame indices per
                              hexahedron in frm_shape_hex's corner order; trilinear weights at the
                              point's parametric coordinates in the containing one (Newton) */
    FRM_PROBE_MESHLESS = 2 /* the meshless shape functions of `shape` (as given to
                              frm_sampling_meshless / _box / _surface) on the model's frames */
} frm_probe_kind;

typedef struct frm_probe_desc {
    frm_probe_kind kind;   /* default FRM_PROBE_MESHLESS */
    const int *elements;   /* TETS, HEXES: frame indices (as the mesh's node indices: the mesh-based
                              samplings put frame i at node i), read during frm_probe_create only */
    int element_count;
    frm_shape_desc shape;  /* MESHLESS: default frm_shape_default_desc() */
    const frm_real *nodes; /* TETS, HEXES, optional (issue 14): node_count rest positions (3 each, m) of the
                              mesh's nodes: `elements` then holds node indices and node_frames[node] is
                              the model frame of each node (frm_parts_combine's frame_map of the part the
                              mesh sampled; several nodes may share a frame, e.g. frames attached to a
                              rigid body). NULL: elements hold frame indices, at the frames' rest
                              positions. Read during frm_probe_create only */
    const int *node_frames;
    int node_count;
    frm_real tolerance;    /* dimensionless, default 1e-6: a point at most this far outside an element
                              (barycentric or parametric coordinate down to -tolerance) counts as
                              in it (the element most inside wins); farther: FRM_ERR_ARG */
    unsigned int internal_cookie; /* set by frm_probe_default_desc; do not touch */
} frm_probe_desc;

typedef struct frm_probe frm_probe;

/* Defaults as documented in the fields. */
FRMDEF frm_probe_desc frm_probe_default_desc(void);
/* Finds each of the `count` rest points (3 each, m) in the description's elements (or its
   meshless neighbours among the model's rest frames) and keeps its frames, weights and rest
   levers pbar - xbar_i. Allocates one block (the model's allocator). Errors: FRM_ERR_DESC
   (no cookie), FRM_ERR_ARG (NULL, count < 1, non-finite point), FRM_ERR_POINT_OUTSIDE (a
   point in no element; meshless: no frame within the radius, or farther from each of its
   frames than that frame's farthest sample in the model, beyond 1e-3 + tolerance of it),
   FRM_ERR_INDEX_RANGE (an element's frame index), FRM_ERR_SAMPLING (shape settings),
   FRM_ERR_SHAPE_DEGENERATE (meshless), FRM_ERR_ALLOC; *out NULL then. */
FRMDEF int frm_probe_create(const frm_model *m, const frm_probe_desc *d, const frm_real *rest_points, int count,
                            frm_probe **out);
/* 3 values per point into out (m, m, m/s) for the model's current state: positions
   pbar + sum_i w_i (u_i + (Q_i - I) abar_i) (the displacement form of eq. 3.34, exact for
   small motions in float), displacements (the same less pbar), velocities sum_i w_i (v_i +
   omega_i x Q_i abar_i). No allocation; FRM_ERR_ARG for NULL or a probe made for a model
   with another frame count. */
FRMDEF int frm_probe_positions(const frm_probe *p, const frm_model *m, frm_real *out);
FRMDEF int frm_probe_displacements(const frm_probe *p, const frm_model *m, frm_real *out);
FRMDEF int frm_probe_velocities(const frm_probe *p, const frm_model *m, frm_real *out);
/* Mapped points (issue 14): a probe is the mapping p = M(q) of its points from the frames
   (thesis eq. 4.11), the way to embed a render mesh, contact points or another model's
   nodes in a frames body. Its Jacobian at the model's current state, J = dp/dq, with q's
   variations as everywhere in frames.h (6 per frame: translation, then rotation dtheta
   about world axes, R -> exp([dtheta]x) R):
       J dq = sum_i w_i (dx_i + dtheta_i x a_i),   a_i = Q_i abar_i = R_i lbar_i,
   and its transpose, the generalized forces of point forces f_n (the virtual work
   dq . J^T f = sum_n f_n . dp_n), per frame i
       force sum_n w_in f_n (eq. 4.12),   torque sum_n w_in a_in x f_n,
   the thesis's eq. 4.13 with the frame's own prediction a_in of the point for p_n - x_i
   (equal for rigid motions; ours is the exact transpose, so work is conserved across an
   interface). frm_probe_jacobian: dq 6 per frame -> out 3 per point (m for rad and m, or
   m/s for a velocity). frm_probe_jacobian_transpose: f 3 per point (N) -> out 6 per frame
   (N, N m about the frame's origin, world axes), overwriting every frame's six values
   (add = 0) or adding to them (add = 1). No allocation; FRM_ERR_ARG for NULL or a probe
   made for a model with another frame count. */
FRMDEF int frm_probe_jacobian(const frm_probe *p, const frm_model *m, const frm_real *dq, frm_real *out);
FRMDEF int frm_probe_jacobian_transpose(const frm_probe *p, const frm_model *m, const frm_real *f, frm_real *out,
                                        int add);
/* Adds J^T f (forces f, 3 per point, N, at the current state) to the model's external
   loads (frm_model_set_external's force and torque), which stay constant through the next
   steps and solves until frm_model_clear_external or frm_model_set_external: call it once
   per step with the points' current forces (a staggered coupling, a render mesh's
   contact). FRM_ERR_ARG as above, or a non-finite force (nothing added). */
FRMDEF int frm_probe_add_external(const frm_probe *p, frm_model *m, const frm_real *f);
/* Anchors (issue 14; the same hook as heml_set_anchors and tmass_set_anchors): zero-length
   springs from each mapped point p_n of the probe to targets[3n..3n+2] (m) with stiffness
   stiffness[n] (N/m, >= 0), energy sum_n k_n / 2 |p_n(q) - t_n|^2. They are part of the
   model from then on: internal forces (frm_model_forces; J^T of -k (p - t)), energies,
   stiffness products (frm_model_apply_stiffness: J^T k J plus the levers' second-order
   term, exact), the block-Jacobi preconditioner, every static solve, step and modal
   analysis. This is how a frames body is glued to a heml.h or tensormass.h mesh (COUPLING:
   the targets are the mesh's glued nodes, updated between solves). The probe and both
   arrays are the caller's: kept by pointer and read at every evaluation until the next
   call, so they must outlive the model's use of them (update targets in place or call
   again). p = NULL removes the anchors (default none: results bit-identical to a model
   without the call). Errors (nothing kept): FRM_ERR_ARG (NULL model or array, a probe made
   for a model with another frame count, a stiffness negative or not finite, a target not
   finite, a model with FRM_LINEAR_SOLVER_BTD: its factor holds the assembled blocks, which
   lack the anchors' J^T k J). */
FRMDEF int frm_model_set_anchors(frm_model *m, const frm_probe *p, const frm_real *stiffness, const frm_real *targets);
/* Points of the probe. */
FRMDEF int frm_probe_count(const frm_probe *p);
/* Frees the probe. NULL is allowed. */
FRMDEF void frm_probe_destroy(frm_probe *p);

/* ---- modal analysis (issue 19): the lowest natural frequencies and mode shapes of the
   model linearised about its current state, with its constraints (fixed and driven frames,
   held axes), K x = lambda M x with K the stiffness's symmetric part and M the frames'
   mass (see MASS). Matrix-free: block shift-invert subspace iteration, each solve of
   (K + shift M) y = M x by the model's linear solver (frm__linear_solve), Rayleigh-Ritz
   on the block, until every wanted mode's residual |K x - lambda M x| / ((|lambda| +
   shift) |M x|) <= tolerance, or their Ritz values change by less than 1e-2 tolerance
   (|lambda| + shift) in an iteration (the rounding of the K products bounds the residual
   near eps |K| / (lambda + shift): above 1e-4 for a slender beam in float). ---- */

typedef struct frm_modal_desc {
    int count;          /* modes wanted, >= 1, default 6 */
    int max_iterations; /* subspace iterations, default 100 */
    frm_real tolerance; /* each wanted mode's relative residual, default 1e-8 (float 1e-2: float's
                           K products and CG leave a residual of 2e-3 on the R3 beam; the
                           eigenvalue's error is of the order of its square) */
    frm_real shift;     /* 1/s^2: K + shift M must be positive definite; <= 0 (default): automatic,
                           1e-4 times the mean of the free frames' K_ii / m_i (translational), so
                           free bodies' rigid modes (0 Hz) work, raised a hundredfold (three
                           times at most) where K + shift M turns out indefinite (gravity's
                           torques at a state off equilibrium, compression) */
    unsigned int internal_cookie; /* set by frm_modal_default_desc; do not touch */
} frm_modal_desc;

typedef struct frm_modal frm_modal;

FRMDEF frm_modal_desc frm_modal_default_desc(void);
/* Sizes the workspace for model m (three blocks of count + max(count, 8) vectors of 6 reals
   a frame, and small dense matrices): one allocation through the model's allocator.
   FRM_ERR_DESC, FRM_ERR_ARG (count < 1, max_iterations < 1, tolerance not > 0, shift not
   finite), FRM_ERR_ALLOC. */
FRMDEF int frm_modal_create(const frm_model *m, const frm_modal_desc *d, frm_modal **out);
/* Linearises m at its current state and computes the modes. No allocation; the model's
   state is untouched (its linearisation and last stats are the solve's). Fewer free
   degrees of freedom than count: that many modes. FRM_ERR_NO_CONVERGENCE (iterations
   spent, or K + shift M not positive definite: a stressed or unstable state, raise
   shift), FRM_ERR_NOT_FINITE, FRM_ERR_INVERTED; FRM_ERR_ARG for a modal made for another
   frame count. Deterministic (fixed start vectors). */
FRMDEF int frm_modal_solve(frm_modal *md, frm_model *m);
/* Modes computed by the last successful solve (0 before). */
FRMDEF int frm_modal_count(const frm_modal *md);
/* Frequency of mode i in Hz, ascending: sqrt(lambda) / 2 pi (rigid modes 0 to round-off);
   a negative lambda (an unstable direction of a state off equilibrium) gives
   -sqrt(-lambda) / 2 pi; -1 for i out of range (check frm_modal_count). */
FRMDEF double frm_modal_frequency(const frm_modal *md, int i);
/* Mode i's shape, 6 per frame (translation, rotation about world axes), M-orthonormal,
   zero on held components; NULL for i out of range. Valid until the next solve. */
FRMDEF const frm_real *frm_modal_shape(const frm_modal *md, int i);
FRMDEF void frm_modal_destroy(frm_modal *md);

/* >>btd (public) ----------------------------------------------------------------------
   Block-tridiagonal solver (issue 15): symmetric positive definite matrices of 6x6 blocks
   coupling each block row only to its two neighbours (a chain of 6-DoF frames: rods,
   cables, catheters, trunk robots; the reduced chain below). Block LDL^T without square
   roots (the pivot blocks inverted by a symmetric sweep), O(n) in the number of blocks, no
   allocation: the caller owns every array. See BLOCK-TRIDIAGONAL SOLVER in the manual. */
#if FRM__CAT(FRM__IS_, FRM_REAL)
#define frm_btd_factor_size frm_btd_factor_size_f32
#define frm_btd_factor frm_btd_factor_f32
#define frm_btd_solve frm_btd_solve_f32
#define frm_btd_compliance frm_btd_compliance_f32
#define frm_qp_box frm_qp_box_f32
#define frm_chain_default_desc frm_chain_default_desc_f32
#define frm_chain_create frm_chain_create_f32
#define frm_chain_destroy frm_chain_destroy_f32
#define frm_chain_frame_count frm_chain_frame_count_f32
#define frm_chain_actuator_count frm_chain_actuator_count_f32
#define frm_chain_positions frm_chain_positions_f32
#define frm_chain_orientations frm_chain_orientations_f32
#define frm_chain_velocities frm_chain_velocities_f32
#define frm_chain_efforts frm_chain_efforts_f32
#define frm_chain_set_poses frm_chain_set_poses_f32
#define frm_chain_set_base frm_chain_set_base_f32
#define frm_chain_set_external frm_chain_set_external_f32
#define frm_chain_set_gravity frm_chain_set_gravity_f32
#define frm_chain_set_efforts frm_chain_set_efforts_f32
#define frm_chain_forces frm_chain_forces_f32
#define frm_chain_energy frm_chain_energy_f32
#define frm_chain_apply_stiffness frm_chain_apply_stiffness_f32
#define frm_chain_actuator_measures frm_chain_actuator_measures_f32
#define frm_chain_effector frm_chain_effector_f32
#define frm_chain_solve_static frm_chain_solve_static_f32
#define frm_chain_step frm_chain_step_f32
#define frm_chain_inverse_step frm_chain_inverse_step_f32
#define frm_chain_inverse_solve frm_chain_inverse_solve_f32
#define frm_chain_link_compliance frm_chain_link_compliance_f32
#endif

/* Reals of a factor of n blocks (72 n: per block the inverse pivot block D_i^-1 and
   E_i^T = D_i^-1 A(i + 1, i)^T). */
FRMDEF size_t frm_btd_factor_size(int n);
/* Factors the symmetric block-tridiagonal matrix of n >= 1 blocks: diag holds the n
   diagonal blocks (36 each, row-major; only their lower triangles are read), lower the
   n - 1 sub-diagonal blocks A(i + 1, i) (36 each, row-major; NULL when n = 1); factor
   receives frm_btd_factor_size(n) reals. Returns 0, FRM_ERR_BTD_INDEFINITE (a pivot below
   -tol), FRM_ERR_BTD_SINGULAR (a pivot within tol of zero; tol = 4 (n + 16) eps(frm_real)
   times the block's original diagonal entry) or FRM_ERR_NOT_FINITE; *failed_block (may be
   NULL) receives the block where it stopped (-1 on success). FRM_ERR_ARG for n < 1 or NULL
   arrays. No allocation. */
FRMDEF int frm_btd_factor(int n, const frm_real *diag, const frm_real *lower, frm_real *factor, int *failed_block);
/* Solves A x = b in place for nrhs right-hand sides, each 6 n contiguous reals (b + 6 n r
   is the r-th). FRM_ERR_NOT_FINITE if a result is not finite (then b holds zeros). */
FRMDEF int frm_btd_solve(int n, const frm_real *factor, int nrhs, frm_real *b);
/* The compliance W = J A^-1 J^T (rows x rows, row-major) of `rows` constraint rows J
   (row-major, rows x 6 n) without forming A^-1: rows solves of the factor. work: 6 n rows
   reals. Symmetrised. Errors as frm_btd_solve. */
FRMDEF int frm_btd_compliance(int n, const frm_real *factor, int rows, const frm_real *J, frm_real *W, frm_real *work);
/* Small dense box-constrained convex QP: minimise 1/2 x^T H x + c^T x over lo <= x <= hi
   (n <= 64, H row-major symmetric positive semi-definite, lo <= hi; +-HUGE_VAL allowed).
   Primal active-set method (see INVERSE ACTUATION): x (in: a start, clamped; out: the
   minimiser) satisfies the KKT conditions to round-off. A semi-definite H gets a diagonal
   shift of 1e-12 of its largest diagonal entry (the minimiser of smallest H-norm step then);
   *iterations (may be NULL) receives the active-set changes. Errors: FRM_ERR_ARG (n out of
   range, NULL, non-finite entries, lo > hi), FRM_ERR_QP_INDEFINITE (H has a negative
   curvature beyond round-off: x is then the feasible start), FRM_ERR_NO_CONVERGENCE (more
   than 8 n + 32 active-set changes: cycling; x is feasible). Never returns non-finite x. */
FRMDEF int frm_qp_box(int n, const double *H, const double *c, const double *lo, const double *hi, double *x,
                      int *iterations);

/* >>chain (public) ---------------------------------------------------------------------
   Reduced chain model of a soft arm with rigid vertebrae (thesis sec. 5.2, issue 15): frames
   0..n-1 (frame 0 the base, fixed or moved by frm_chain_set_base) joined by n - 1 linear
   6-DoF springs given by their compliance in the proximal frame's rest axes. See REDUCED
   CHAIN in the manual. */

typedef enum frm_actuator_kind {
    FRM_ACTUATOR_CABLE = 0, /* effort: tension (N); pulls the routed points together along the path */
    FRM_ACTUATOR_CAVITY = 1 /* effort: pressure (Pa) on a closed surface of triangles (eq. 5.20) */
} frm_actuator_kind;

typedef struct frm_actuator {
    frm_actuator_kind kind;
    int point_count;              /* cable: routed points in path order (>= 2); cavity: vertices (>= 4) */
    const int *point_frames;      /* frame each point is fixed to (0 .. frame_count - 1) */
    const frm_real *points;       /* 3 per point: rest position, m, world axes */
    int triangle_count;           /* cavity: triangles (>= 4), outward normals (counter-clockwise seen
                                     from outside) */
    const int *triangles;         /* cavity: 3 point indices per triangle */
    frm_real min_effort;          /* N or Pa, >= 0 (default 0) */
    frm_real max_effort;          /* N or Pa, >= min_effort (default HUGE_VAL: no upper bound) */
} frm_actuator;

typedef struct frm_chain_desc {
    int frame_count;                 /* vertebrae, the base included: >= 2 */
    const frm_real *positions;       /* 3 per frame: rest positions, m, world axes */
    const frm_real *orientations;    /* 4 per frame (x, y, z, w): rest orientations; NULL: identity */
    const frm_real *compliances;     /* 36 per link (frame_count - 1), row-major, symmetric positive definite:
                                        link i maps a force (N) and torque (N m) applied at frame i + 1's
                                        origin, frame i held, to frame i + 1's displacement (m) and rotation
                                        (rad), all in frame i's rest axes (eq. 5.10; m/N, 1/N, rad/(N m)) */
    const frm_real *masses;          /* 1 per frame, kg, lumped at the frame's origin; NULL: none (quasi-static
                                        only: frm_chain_step then refuses with FRM_ERR_DENSITY) */
    const frm_real *inertias;        /* 1 per frame, kg m^2 (isotropic); NULL: none */
    frm_real gravity[3];             /* m/s^2, default (0, 0, -9.81) */
    frm_real time_step;              /* s, default 0.01 (frm_chain_step) */
    frm_real mass_damping;           /* 1/s, default 0 */
    frm_real newton_tolerance;       /* relative residual, default 1e-9 (float 1e-4) */
    int newton_max_iterations;       /* default 50 */
    const frm_actuator *actuators;   /* read during frm_chain_create only */
    int actuator_count;              /* 0 .. 64 */
    int effector_frame;              /* default -1: the last frame */
    frm_real effector_offset[3];     /* the effector point in that frame's rest axes, m (default 0) */
    int effector_orientation;        /* 1: the inverse model also targets the effector frame's orientation */
    frm_real inverse_epsilon;        /* eq. 5.29's eps relative to tr(W_ea^T W_ea) / tr(W_aa), default 1e-5 */
    frm_allocator allocator;         /* all NULL: FRM_MALLOC / FRM_FREE */
    void (*log)(int code, const char *message, void *user); /* validation details, or NULL */
    void *log_user;
    unsigned int internal_cookie;    /* set by frm_chain_default_desc; do not touch */
} frm_chain_desc;

/* Statistics of an inverse step or solve. */
typedef struct frm_inverse_stats {
    int linearizations;     /* eq. 5.23 linearisations (QPs) run */
    int qp_iterations;      /* active-set changes, summed */
    int newton_iterations;  /* direct-simulation Newton iterations, summed */
    int active_bounds;      /* efforts at a bound in the last QP */
    int reached;            /* 1: the effector is within tolerance of the target */
    double error;           /* |effector - target| at the returned state, m (orientation rows in rad
                               when targeted, added in the 2-norm) */
    double predicted_error; /* the last QP's linearised error |W_ea lambda + delta_free|, m */
} frm_inverse_stats;

typedef struct frm_chain frm_chain;

FRMDEF frm_chain_desc frm_chain_default_desc(void);
/* Validates and allocates once. Errors: FRM_ERR_DESC, FRM_ERR_ARG (NULL arrays, non-finite
   values), FRM_ERR_FRAME_COUNT, FRM_ERR_QUATERNION, FRM_ERR_COMPLIANCE (a link's compliance not
   finite, not symmetric to 1e-6 relative, or not positive definite), FRM_ERR_DENSITY (negative
   mass or inertia), FRM_ERR_ACTUATOR, FRM_ERR_ACTUATOR_BOUNDS, FRM_ERR_TIME_STEP,
   FRM_ERR_DAMPING, FRM_ERR_SOLVER, FRM_ERR_ALLOC. */
FRMDEF int frm_chain_create(const frm_chain_desc *d, frm_chain **out);
FRMDEF void frm_chain_destroy(frm_chain *c);
FRMDEF int frm_chain_frame_count(const frm_chain *c);
FRMDEF int frm_chain_actuator_count(const frm_chain *c);
FRMDEF const frm_real *frm_chain_positions(const frm_chain *c);    /* 3 per frame, m */
FRMDEF const frm_real *frm_chain_orientations(const frm_chain *c); /* 4 per frame (x, y, z, w) */
FRMDEF const frm_real *frm_chain_velocities(const frm_chain *c);   /* 6 per frame, m/s, rad/s (world) */
FRMDEF const frm_real *frm_chain_efforts(const frm_chain *c);      /* 1 per actuator, N or Pa */
/* Every frame's pose (the base's too; unit quaternions). Velocities zeroed. */
FRMDEF int frm_chain_set_poses(frm_chain *c, const frm_real *positions, const frm_real *orientations);
/* The base frame's pose (a moving base): later solves and steps hold it there. */
FRMDEF int frm_chain_set_base(frm_chain *c, const frm_real position[3], const frm_real orientation[4]);
/* Constant force (N) and torque (N m, about the frame's origin), world axes; NULL for zero. */
FRMDEF int frm_chain_set_external(frm_chain *c, int frame, const frm_real force[3], const frm_real torque[3]);
FRMDEF int frm_chain_set_gravity(frm_chain *c, const frm_real g[3]);
/* Actuator efforts (N, Pa), each within its bounds (FRM_ERR_ACTUATOR_BOUNDS otherwise). */
FRMDEF int frm_chain_set_efforts(frm_chain *c, const frm_real *efforts);
/* The links' elastic generalized forces (6 per frame: N, N m about the frame's origin, world
   axes) into out, and their energy (J) into *energy (either may be NULL). */
FRMDEF int frm_chain_forces(frm_chain *c, frm_real *out, double *energy);
/* The links' elastic energy, J. */
FRMDEF double frm_chain_energy(const frm_chain *c);
/* out = K v, K = -d(elastic force)/dq at the current state (6 per frame, rotations about
   world axes: R -> exp([dtheta]x) R), every frame; symmetric = 0 the exact derivative,
   1 its symmetric part (what the solvers factor). */
FRMDEF int frm_chain_apply_stiffness(frm_chain *c, const frm_real *v, frm_real *out, int symmetric);
/* Each actuator's measure at the current state: a cable's path length (m), a cavity's volume
   (m^3). Its generalized force is -tension dL/dq, pressure dV/dq. */
FRMDEF int frm_chain_actuator_measures(const frm_chain *c, double *out);
/* The effector point (3, m, world), and with orientation != NULL its frame's orientation. */
FRMDEF int frm_chain_effector(const frm_chain *c, frm_real position[3], frm_real orientation[4]);
/* Direct simulation: static equilibrium under gravity, external loads and the current
   efforts by Newton iterations (eq. 5.19) through the block-tridiagonal solver, with a line
   search; the base held. On failure the state is unchanged. */
FRMDEF int frm_chain_solve_static(frm_chain *c);
/* One implicit Euler step of time_step (needs masses and inertias > 0 on the free frames). */
FRMDEF int frm_chain_step(frm_chain *c);
/* One control step of the inverse model (sec. 5.3): linearise (eq. 5.23), factor, the
   compliance blocks W_ea, W_aa (eqs. 5.24-5.25), the QP of eq. 5.29 with the efforts' bounds,
   then apply the efforts (direct simulation from the current state). target: 3 reals (m), 6
   with effector_orientation (the last 3 a rotation vector, world axes, of the target
   orientation relative to the effector's rest orientation). stats may be NULL. Returns 0
   when the effector ends within `tolerance` (m) of the target, FRM_ERR_UNREACHABLE when the
   QP's own linearised prediction is farther (the state is then the applied pose: the
   closest the linearisation found), or the direct simulation's error (state unchanged). */
FRMDEF int frm_chain_inverse_step(frm_chain *c, const frm_real *target, double tolerance, frm_inverse_stats *stats);
/* Inverse steps until the effector is within tolerance, at most max_linearizations (>= 1).
   FRM_ERR_UNREACHABLE: the target is out of reach; the chain is left at the closest pose
   found (a valid equilibrium). FRM_ERR_NO_CONVERGENCE: not reached in max_linearizations
   although the last linearisation predicted it reachable; the chain is likewise left at
   the closest pose found (at worst the start state). A direct simulation's failure returns
   its code with the state of the step before it. */
FRMDEF int frm_chain_inverse_solve(frm_chain *c, const frm_real *target, double tolerance, int max_linearizations,
                                   frm_inverse_stats *stats);
/* The compliance of an intervertebra sub-model of frames with rigid ends (eqs. 5.1-5.11):
   the frames end_a[0 .. na-1] are held, the frames end_b[] move rigidly with a virtual frame
   at origin_b; C (36, row-major) is that frame's compliance in the model's world axes (build
   the sub-model in the proximal vertebra's rest axes), the Schur complement of the model's
   linear stiffness at its current (rest) state through its own linear solver, by six imposed
   unit rigid motions and their reactions (ends' frame rotations free: see REDUCED CHAIN).
   Give the sub-model no gravity (its stiffness terms would enter). The model's fixed /
   driven frames and held axes are restored; its state is untouched. One temporary
   allocation (3 vectors) through the model's allocator. Errors: FRM_ERR_ARG, FRM_ERR_FRAME_RANGE, the linear solver's
   FRM_ERR_NO_CONVERGENCE / FRM_ERR_NOT_FINITE, FRM_ERR_COMPLIANCE (the reduced stiffness
   is not positive definite: end B not held by the material). */
FRMDEF int frm_chain_link_compliance(frm_model *m, const int *end_a, int na, const int *end_b, int nb,
                                     const frm_real origin_b[3], frm_real C[36]);

#endif /* FRAMES_H */

/* ======================================================================================
   KERNELS: the per-frame, per-sample and per-pair math, FRM_HOSTDEV static inline so that
   frames_cuda.cu (which defines FRAMES_KERNELS) runs the very code the CPU path runs.
   Conventions: 3x3 matrices row-major (A[3 r + c]); symmetric tensors as 6 values in the
   thesis's Voigt order (A.1) 00 11 22 12 02 01, tensor components (not doubled);
   quaternions (x, y, z, w); a frame's generalized vector is (translation, rotation about
   world axes).
   ====================================================================================== */
#if (defined(FRAMES_IMPLEMENTATION) || defined(FRAMES_KERNELS)) && !defined(FRAMES_KERNELS_ONCE)
#define FRAMES_KERNELS_ONCE
#include <float.h>
#include <math.h>

/* Subnormal guard (issue 21), float builds only: FRM_TINY = eps^2 (1.4e-14), and the
   flush of a value below a threshold to zero. The state's quaternions (unit: a component
   below eps^2 turns the frame by less than 2 eps^2 rad, an eps-th of one rounding of R's
   unit entries), each sample's displacement gradient H,
   Green strain E and the minors of det(I + H) keep no component below eps^2; the
   stabilisation's sums Y and D none below eps^2 times the largest gradient (an eps-th of
   one rounding of their terms), the stress P that the pairs read none below eps max|P|
   (one rounding of its largest entry: Q - I keeps second-order entries of 1e-23 at small
   rotations, whose products with P's eps^2-level entries were still subnormal; Q - I
   itself is not flushed: that moved a float Newton of test_i14_thin_tet, marginal at its
   third step, past its line search). Products of the survivors (squares, H^T H, E : E,
   Q P) stay far above the smallest normal float (FLT_MIN = 1.2e-38; eps^4 = 2e-28 leaves
   10 decades for the model's scales). Without it a float
   state at rest about some axes carries components of 1e-20 to 1e-29 (rotations about
   axes the load leaves alone, a solver's rounding noise, second-order terms of small
   rotations) whose products are subnormal, which Intel's x86 cores handle by microcode
   assists: the bench's force pass took 400-1300 ns a pair instead of 36 (PERFORMANCE).
   A comparison, not a change of the caller's floating-point environment (FTZ/DAZ); NaN
   passes unchanged. Double builds compile it away (results bit for bit as before): their
   noise of 1e-31 squares to 1e-62, some 250 decades above DBL_MIN. */
#define FRM__FLUSH_ON (sizeof(frm_real) == sizeof(float))
#define FRM_TINY ((frm_real)(FRM__FLUSH_ON ? (double)FLT_EPSILON * FLT_EPSILON : 0))
FRM_HOSTDEV static inline frm_real frm_flush_below(frm_real x, frm_real t)
{
    return FRM__FLUSH_ON && fabsf((float)x) < (float)t ? (frm_real)0 : x; /* float only: no double on a GPU */
}
FRM_HOSTDEV static inline frm_real frm_flush_tiny(frm_real x) { return frm_flush_below(x, FRM_TINY); }

/* Values per sample of a law's tangent data (frm_material_stress). */
#define FRM_LAW_CACHE 7

/* >>kernels ---------------------------------------------------------------------------- */

FRM_HOSTDEV static inline void frm_cross(const frm_real a[3], const frm_real b[3], frm_real out[3])
{
    frm_real x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    out[0] = x;
    out[1] = y;
    out[2] = z;
}

/* Rotation matrix of a unit quaternion (x, y, z, w). */
FRM_HOSTDEV static inline void frm_quat_to_matrix(const frm_real q[4], frm_real R[9])
{
    frm_real x = q[0], y = q[1], z = q[2], w = q[3];
    R[0] = 1 - 2 * (y * y + z * z);
    R[1] = 2 * (x * y - z * w);
    R[2] = 2 * (x * z + y * w);
    R[3] = 2 * (x * y + z * w);
    R[4] = 1 - 2 * (x * x + z * z);
    R[5] = 2 * (y * z - x * w);
    R[6] = 2 * (x * z - y * w);
    R[7] = 2 * (y * z + x * w);
    R[8] = 1 - 2 * (x * x + y * y);
}

/* out = a b (Hamilton product: the rotation b, then a). out may alias a or b. */
FRM_HOSTDEV static inline void frm_quat_multiply(const frm_real a[4], const frm_real b[4], frm_real out[4])
{
    frm_real x = a[3] * b[0] + b[3] * a[0] + a[1] * b[2] - a[2] * b[1];
    frm_real y = a[3] * b[1] + b[3] * a[1] + a[2] * b[0] - a[0] * b[2];
    frm_real z = a[3] * b[2] + b[3] * a[2] + a[0] * b[1] - a[1] * b[0];
    frm_real w = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    out[0] = x;
    out[1] = y;
    out[2] = z;
    out[3] = w;
}

/* q <- exp(theta) q, renormalised: q followed by the rotation of vector theta (rad, world
   axes). Renormalising after every update keeps |q| = 1 to round-off for ever. */
FRM_HOSTDEV static inline void frm_quat_integrate(frm_real q[4], const frm_real theta[3])
{
    double t2 = (double)theta[0] * theta[0] + (double)theta[1] * theta[1] + (double)theta[2] * theta[2];
    double t = sqrt(t2), s, c, n;
    frm_real d[4];
    if (t < 1e-4) { /* sin(t/2)/t and cos(t/2) by their series (error below t^4 / 4000) */
        s = 0.5 - t2 / 48.0;
        c = 1.0 - t2 / 8.0;
    } else {
        s = sin(0.5 * t) / t;
        c = cos(0.5 * t);
    }
    d[0] = (frm_real)(s * theta[0]);
    d[1] = (frm_real)(s * theta[1]);
    d[2] = (frm_real)(s * theta[2]);
    d[3] = (frm_real)c;
    frm_quat_multiply(d, q, q);
    n = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
    q[0] = (frm_real)(q[0] / n);
    q[1] = (frm_real)(q[1] / n);
    q[2] = (frm_real)(q[2] / n);
    q[3] = (frm_real)(q[3] / n);
    q[0] = frm_flush_tiny(q[0]); /* |q| = 1: components below eps^2 turn it by less than 2 eps^2 rad */
    q[1] = frm_flush_tiny(q[1]);
    q[2] = frm_flush_tiny(q[2]);
    q[3] = frm_flush_tiny(q[3]);
}

/* Per frame: R from q, Q = R Rbar^T (the rotation since the rest pose; it maps the rest
   axes to the current ones, the second term of eq. 3.40) and Qm = Q - I, from the
   relative quaternion (v, w) = q qbar^* as 2 w [v]x + 2 [v]x^2, exact to the precision of
   v (so small rotations keep their digits in float). */
FRM_HOSTDEV static inline void frm_frame_rotations(const frm_real q[4], const frm_real rest_q[4], frm_real R[9],
                                                   frm_real Q[9], frm_real Qm[9])
{
    frm_real c[4], d[4], x, y, z, w;
    int k;
    c[0] = -rest_q[0];
    c[1] = -rest_q[1];
    c[2] = -rest_q[2];
    c[3] = rest_q[3];
    frm_quat_to_matrix(q, R);
    frm_quat_multiply(q, c, d);
    x = d[0];
    y = d[1];
    z = d[2];
    w = d[3];
    Qm[0] = -2 * (y * y + z * z);
    Qm[1] = 2 * (x * y - z * w);
    Qm[2] = 2 * (x * z + y * w);
    Qm[3] = 2 * (x * y + z * w);
    Qm[4] = -2 * (x * x + z * z);
    Qm[5] = 2 * (y * z - x * w);
    Qm[6] = 2 * (x * z - y * w);
    Qm[7] = 2 * (y * z + x * w);
    Qm[8] = -2 * (x * x + y * y);
    for (k = 0; k < 9; k++) Q[k] = Qm[k] + (k % 4 == 0 ? 1 : 0);
}

/* Per sample, eqs. 3.34 and 3.40. Its n neighbours: frame indices, weights w_k, gradients
   (3 n), rest levers abar_k = Rbar_k lbar_k = pbar_s - xbar_k (3 n, world axes; lbar is
   eq. 3.33). Frame arrays: displacements u = x - xbar (3 per frame) and Qm = Q - I (9).
   Out: the displacement gradient H = F - I of the deformation gradient
       F = sum_k d_k grad w_k^T + w_k Q_k,   d_k = x_k + R_k lbar_k,
   the levers a_k = R_k lbar_k = Q_k abar_k (3 n, may be NULL), the offsets d_k - p of each
   frame's own prediction from the blended position (3 n, may be NULL; see the coupling
   term) and the position p = sum_k w_k d_k (may be NULL; needs sample_rest, the rest
   position). Since xbar_k + abar_k = pbar_s for every neighbour, d_k - d_0 is exactly
   (u_k - u_0) + (Qm_k abar_k - Qm_0 abar_0), and with sum w = 1,
       H = sum_k (d_k - d_0) grad w_k^T + w_k Qm_k:
   no large terms cancel, so the precision follows the strain, not the distance to the
   origin or the size of 1 (which matters in float). */
FRM_HOSTDEV static inline void frm_sample_deformation(int n, const int *frame, const frm_real *weight,
                                                      const frm_real *grad, const frm_real *rest_lever,
                                                      const frm_real *sample_rest, const frm_real *frame_disp,
                                                      const frm_real *frame_relm, frm_real H[9], frm_real *lever,
                                                      frm_real *offset, frm_real *position)
{
    int k, r, c, i0 = frame[0];
    frm_real da0[3], p[3] = {0, 0, 0};
    const frm_real *Q0 = frame_relm + 9 * i0, *b0 = rest_lever;
    for (r = 0; r < 3; r++) da0[r] = Q0[3 * r] * b0[0] + Q0[3 * r + 1] * b0[1] + Q0[3 * r + 2] * b0[2];
    for (r = 0; r < 9; r++) H[r] = 0;
    for (k = 0; k < n; k++) {
        int i = frame[k];
        const frm_real *Qm = frame_relm + 9 * i, *ab = rest_lever + 3 * k, *g = grad + 3 * k;
        frm_real da[3], e[3], w = weight[k];
        for (r = 0; r < 3; r++) {
            da[r] = Qm[3 * r] * ab[0] + Qm[3 * r + 1] * ab[1] + Qm[3 * r + 2] * ab[2];
            e[r] = (frame_disp[3 * i + r] - frame_disp[3 * i0 + r]) + (da[r] - da0[r]);
            p[r] += w * e[r];
        }
        for (r = 0; r < 3; r++)
            for (c = 0; c < 3; c++) H[3 * r + c] += e[r] * g[c] + w * Qm[3 * r + c];
        if (lever)
            for (r = 0; r < 3; r++) lever[3 * k + r] = ab[r] + da[r];
        if (offset)
            for (r = 0; r < 3; r++) offset[3 * k + r] = e[r];
    }
    if (offset)
        for (k = 0; k < n; k++)
            for (r = 0; r < 3; r++) offset[3 * k + r] -= p[r];
    if (position)
        for (r = 0; r < 3; r++) position[r] = sample_rest[r] + (frame_disp[3 * i0 + r] + da0[r] + p[r]);
    for (r = 0; r < 9; r++) H[r] = frm_flush_tiny(H[r]); /* strain below eps^2: FRM_TINY */
}

/* det(I + H) - 1 by the invariants, without cancellation: tr H + (tr(H)^2 - tr(H^2))/2 + det H. */
FRM_HOSTDEV static inline frm_real frm_det_minus_one(const frm_real H[9])
{
    frm_real tr = H[0] + H[4] + H[8];
    frm_real tr2 = H[0] * H[0] + H[4] * H[4] + H[8] * H[8] + 2 * (H[1] * H[3] + H[2] * H[6] + H[5] * H[7]);
    /* the minors flushed (FRM_TINY): the cubic term stays normal; it moves by less than
       3 eps^2 max|H|, an eps-th of the rounding of tr */
    frm_real m0 = frm_flush_tiny(H[4] * H[8] - H[5] * H[7]), m1 = frm_flush_tiny(H[3] * H[8] - H[5] * H[6]),
             m2 = frm_flush_tiny(H[3] * H[7] - H[4] * H[6]);
    frm_real det = H[0] * m0 - H[1] * m1 + H[2] * m2;
    return tr + (frm_real)0.5 * (tr * tr - tr2) + det;
}

/* Symmetric tensor (6) to a full 3x3. */
FRM_HOSTDEV static inline void frm_sym_to_matrix(const frm_real s[6], frm_real A[9])
{
    A[0] = s[0];
    A[4] = s[1];
    A[8] = s[2];
    A[5] = A[7] = s[3];
    A[2] = A[6] = s[4];
    A[1] = A[3] = s[5];
}

/* P = F S (first Piola-Kirchhoff from the second). */
FRM_HOSTDEV static inline void frm_first_piola(const frm_real F[9], const frm_real S[6], frm_real P[9])
{
    frm_real A[9];
    int r, c;
    frm_sym_to_matrix(S, A);
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) P[3 * r + c] = F[3 * r] * A[c] + F[3 * r + 1] * A[3 + c] + F[3 * r + 2] * A[6 + c];
}

/* The law at F = I + H (H the displacement gradient): second Piola-Kirchhoff stress S
   (6), energy density psi (J/m^3) and the tangent data (FRM_LAW_CACHE values)
   frm_material_dstress needs. With E = (H + H^T + H^T H) / 2 = (C - I) / 2:
       SVK (eq. 3.53):  S = lambda tr(E) I + 2 mu E
       Neo-Hookean:     S = mu (I - C^-1) + lambda ln J C^-1 = 2 mu C^-1 E + lambda ln J C^-1
   (J - 1 by frm_det_minus_one, ln J by log1p: small strains keep their digits). Returns 0,
   or FRM_ERR_INVERTED for a sample with J <= 0: Neo-Hookean's energy is infinite there
   (S, psi not computed); St Venant-Kirchhoff's is finite and has a minimum of zero at
   every mirror image of the rest state (F = diag(1, 1, -1): E = 0), so a solver would
   happily settle a layer there; S and psi are computed, and a caller that accepts
   mirrored SVK samples may use them. Room for more laws: add a case here and in
   frm_material_dstress. */
FRM_HOSTDEV static inline int frm_material_stress(int law, frm_real mu, frm_real lambda, const frm_real H[9],
                                                  frm_real S[6], frm_real *psi, frm_real *cache)
{
    frm_real E[6], tr;
    int k;
    E[0] = H[0] + (frm_real)0.5 * (H[0] * H[0] + H[3] * H[3] + H[6] * H[6]);
    E[1] = H[4] + (frm_real)0.5 * (H[1] * H[1] + H[4] * H[4] + H[7] * H[7]);
    E[2] = H[8] + (frm_real)0.5 * (H[2] * H[2] + H[5] * H[5] + H[8] * H[8]);
    E[3] = (frm_real)0.5 * (H[5] + H[7] + H[1] * H[2] + H[4] * H[5] + H[7] * H[8]);
    E[4] = (frm_real)0.5 * (H[2] + H[6] + H[0] * H[2] + H[3] * H[5] + H[6] * H[8]);
    E[5] = (frm_real)0.5 * (H[1] + H[3] + H[0] * H[1] + H[3] * H[4] + H[6] * H[7]);
    for (k = 0; k < 6; k++) E[k] = frm_flush_tiny(E[k]); /* E : E stays normal: FRM_TINY */
    tr = E[0] + E[1] + E[2];
    if (law == FRM_LAW_NEO_HOOKEAN) {
        frm_real jm1 = frm_det_minus_one(H), J = 1 + jm1, lnJ, inv_det, C[6], ci[9], e[9], x[9];
        int r, c;
        if (!(J > 0)) return FRM_ERR_INVERTED;
        lnJ = (frm_real)log1p((double)jm1);
        for (k = 0; k < 6; k++) C[k] = 2 * E[k] + (k < 3 ? 1 : 0);
        inv_det = 1 / (J * J); /* det C = J^2 */
        ci[0] = (C[1] * C[2] - C[3] * C[3]) * inv_det;
        ci[4] = (C[0] * C[2] - C[4] * C[4]) * inv_det;
        ci[8] = (C[0] * C[1] - C[5] * C[5]) * inv_det;
        ci[5] = ci[7] = (C[4] * C[5] - C[0] * C[3]) * inv_det;
        ci[2] = ci[6] = (C[5] * C[3] - C[1] * C[4]) * inv_det;
        ci[1] = ci[3] = (C[3] * C[4] - C[2] * C[5]) * inv_det;
        frm_sym_to_matrix(E, e);
        for (r = 0; r < 3; r++)
            for (c = 0; c < 3; c++) x[3 * r + c] = ci[3 * r] * e[c] + ci[3 * r + 1] * e[3 + c] + ci[3 * r + 2] * e[6 + c];
        S[0] = 2 * mu * x[0] + lambda * lnJ * ci[0];
        S[1] = 2 * mu * x[4] + lambda * lnJ * ci[4];
        S[2] = 2 * mu * x[8] + lambda * lnJ * ci[8];
        S[3] = mu * (x[5] + x[7]) + lambda * lnJ * ci[5];
        S[4] = mu * (x[2] + x[6]) + lambda * lnJ * ci[2];
        S[5] = mu * (x[1] + x[3]) + lambda * lnJ * ci[1];
        *psi = mu * (tr - lnJ) + (frm_real)0.5 * lambda * lnJ * lnJ;
        if (cache) {
            cache[0] = ci[0];
            cache[1] = ci[4];
            cache[2] = ci[8];
            cache[3] = ci[5];
            cache[4] = ci[2];
            cache[5] = ci[1];
            cache[6] = lnJ;
        }
        return 0;
    }
    for (k = 0; k < 6; k++) S[k] = 2 * mu * E[k];
    S[0] += lambda * tr;
    S[1] += lambda * tr;
    S[2] += lambda * tr;
    *psi = (frm_real)0.5 * lambda * tr * tr +
           mu * (E[0] * E[0] + E[1] * E[1] + E[2] * E[2] + 2 * (E[3] * E[3] + E[4] * E[4] + E[5] * E[5]));
    (void)cache;
    return 1 + frm_det_minus_one(H) <= 0 ? FRM_ERR_INVERTED : 0; /* NaN: left to the non-finite checks */
}

/* dS for a strain variation dE (6) at the state frm_material_stress cached (eq. 3.68):
       SVK:          dS = lambda tr(dE) I + 2 mu dE
       Neo-Hookean:  dS = lambda (C^-1 : dE) C^-1 + 2 (mu - lambda ln J) C^-1 dE C^-1 */
FRM_HOSTDEV static inline void frm_material_dstress(int law, frm_real mu, frm_real lambda, const frm_real *cache,
                                                    const frm_real dE[6], frm_real dS[6])
{
    if (law == FRM_LAW_NEO_HOOKEAN) {
        frm_real c[9], d[9], t[9], x[9], a, b;
        int r, k;
        frm_sym_to_matrix(cache, c);
        frm_sym_to_matrix(dE, d);
        a = lambda * (cache[0] * dE[0] + cache[1] * dE[1] + cache[2] * dE[2] +
                      2 * (cache[3] * dE[3] + cache[4] * dE[4] + cache[5] * dE[5]));
        b = 2 * (mu - lambda * cache[6]);
        for (r = 0; r < 3; r++)
            for (k = 0; k < 3; k++) t[3 * r + k] = d[3 * r] * c[k] + d[3 * r + 1] * c[3 + k] + d[3 * r + 2] * c[6 + k];
        for (r = 0; r < 3; r++)
            for (k = 0; k < 3; k++) x[3 * r + k] = c[3 * r] * t[k] + c[3 * r + 1] * t[3 + k] + c[3 * r + 2] * t[6 + k];
        dS[0] = a * cache[0] + b * x[0];
        dS[1] = a * cache[1] + b * x[4];
        dS[2] = a * cache[2] + b * x[8];
        dS[3] = a * cache[3] + b * (frm_real)0.5 * (x[5] + x[7]);
        dS[4] = a * cache[4] + b * (frm_real)0.5 * (x[2] + x[6]);
        dS[5] = a * cache[5] + b * (frm_real)0.5 * (x[1] + x[3]);
    } else {
        frm_real tr = lambda * (dE[0] + dE[1] + dE[2]);
        int k;
        for (k = 0; k < 6; k++) dS[k] = 2 * mu * dE[k];
        dS[0] += tr;
        dS[1] += tr;
        dS[2] += tr;
        (void)cache;
    }
}

/* sum_j a_j x b_j over the columns a_j of A and b_j of B (row-major 3x3). It is the
   rotational row of B^T: for dF = [dtheta]x A, B : dF = dtheta . sum_j a_j x b_j. */
FRM_HOSTDEV static inline void frm_column_cross_sum(const frm_real A[9], const frm_real B[9], frm_real out[3])
{
    out[0] = (A[3] * B[6] + A[4] * B[7] + A[5] * B[8]) - (A[6] * B[3] + A[7] * B[4] + A[8] * B[5]);
    out[1] = (A[6] * B[0] + A[7] * B[1] + A[8] * B[2]) - (A[0] * B[6] + A[1] * B[7] + A[2] * B[8]);
    out[2] = (A[0] * B[3] + A[1] * B[4] + A[2] * B[5]) - (A[3] * B[0] + A[4] * B[1] + A[5] * B[2]);
}

/* Pass 1 of the force: what one sample (volume v, first Piola stress P) puts on one of its
   frames (eq. 3.52, f_i = -sum_s M^T S v_s, written as -v B^T vec(P) since
   M^T {S} = B^T vec(F S)):
       force  = -v P grad w
       torque = -v sum_j g_j x p_j = -v (a x (P grad w) + w sum_j q_j x p_j),
   g_j, p_j, q_j the columns of G = a grad w^T + w Q, P and Q; a the lever R lbar. */
FRM_HOSTDEV static inline void frm_pair_force(frm_real volume, const frm_real P[9], const frm_real grad[3],
                                              frm_real weight, const frm_real lever[3], const frm_real Q[9],
                                              frm_real out[6])
{
    frm_real b[3], t[3], u[3];
    int r;
    for (r = 0; r < 3; r++) b[r] = P[3 * r] * grad[0] + P[3 * r + 1] * grad[1] + P[3 * r + 2] * grad[2];
    frm_cross(lever, b, t);
    frm_column_cross_sum(Q, P, u);
    for (r = 0; r < 3; r++) {
        out[r] = -volume * b[r];
        out[3 + r] = -volume * (t[r] + weight * u[r]);
    }
}

/* Per-pair data of the stiffness at the linearisation point:
       G = a grad w^T + w Q, so that dF = dx grad w^T + [dtheta]x G  (eqs. 3.42-3.44),
       H = v (G P^T - tr(G^T P) I), the derivative of B^T through the frame's own rotation
           (eqs. 3.74-3.75, the K^R part of appendix B): (dB^T vec P) = H dtheta.
   Hs receives the symmetric part of H (6); its antisymmetric part adds up, over a frame's
   samples, to 1/2 [tau]x with tau the frame's internal torque. */
FRM_HOSTDEV static inline void frm_pair_linearize(frm_real volume, const frm_real P[9], const frm_real grad[3],
                                                  frm_real weight, const frm_real lever[3], const frm_real Q[9],
                                                  frm_real G[9], frm_real Hs[6])
{
    frm_real h[9], tr = 0;
    int r, c;
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) G[3 * r + c] = lever[r] * grad[c] + weight * Q[3 * r + c];
    for (r = 0; r < 3; r++) {
        for (c = 0; c < 3; c++) h[3 * r + c] = G[3 * r] * P[3 * c] + G[3 * r + 1] * P[3 * c + 1] + G[3 * r + 2] * P[3 * c + 2];
        tr += h[4 * r];
    }
    Hs[0] = volume * (h[0] - tr);
    Hs[1] = volume * (h[4] - tr);
    Hs[2] = volume * (h[8] - tr);
    Hs[3] = volume * (frm_real)0.5 * (h[5] + h[7]);
    Hs[4] = volume * (frm_real)0.5 * (h[2] + h[6]);
    Hs[5] = volume * (frm_real)0.5 * (h[1] + h[3]);
}

/* dF += dx grad w^T + [dtheta]x G for one pair, dq = (dx, dtheta) (eq. 3.43). */
FRM_HOSTDEV static inline void frm_pair_dF(const frm_real dq[6], const frm_real grad[3], const frm_real G[9],
                                           frm_real dF[9])
{
    int c;
    for (c = 0; c < 3; c++) {
        frm_real g0 = G[c], g1 = G[3 + c], g2 = G[6 + c];
        dF[c] += dq[0] * grad[c] + (dq[4] * g2 - dq[5] * g1);
        dF[3 + c] += dq[1] * grad[c] + (dq[5] * g0 - dq[3] * g2);
        dF[6 + c] += dq[2] * grad[c] + (dq[3] * g1 - dq[4] * g0);
    }
}

/* The strain variation dE = sym(F^T dF) (Voigt: xx, yy, zz, yz, xz, xy), the first half of
   frm_sample_dP, shared with the law table's general path (frm__law_dP). */
FRM_HOSTDEV static inline void frm_strain_variation(const frm_real F[9], const frm_real dF[9], frm_real dE[6])
{
    frm_real t[9];
    int r, c;
    for (r = 0; r < 3; r++) /* t = F^T dF */
        for (c = 0; c < 3; c++) t[3 * r + c] = F[r] * dF[c] + F[3 + r] * dF[3 + c] + F[6 + r] * dF[6 + c];
    dE[0] = t[0];
    dE[1] = t[4];
    dE[2] = t[8];
    dE[3] = (frm_real)0.5 * (t[5] + t[7]);
    dE[4] = (frm_real)0.5 * (t[2] + t[6]);
    dE[5] = (frm_real)0.5 * (t[1] + t[3]);
}

/* dP = dF S + F dS from the stress S and its variation dS, the second half of
   frm_sample_dP. */
FRM_HOSTDEV static inline void frm_piola_variation(const frm_real F[9], const frm_real S[6], const frm_real dF[9],
                                                   const frm_real dS[6], frm_real dP[9])
{
    frm_real t[9];
    int r;
    frm_first_piola(dF, S, dP);
    frm_first_piola(F, dS, t);
    for (r = 0; r < 9; r++) dP[r] += t[r];
}

/* Per sample: dP = dF S + F dS, dS = dS/dE : sym(F^T dF) (the material part, eqs.
   3.67-3.69, and the geometric part dF S, eqs. 3.71-3.73, in one). */
FRM_HOSTDEV static inline void frm_sample_dP(int law, frm_real mu, frm_real lambda, const frm_real *cache,
                                             const frm_real F[9], const frm_real S[6], const frm_real dF[9],
                                             frm_real dP[9])
{
    frm_real dE[6], dS[6];
    frm_strain_variation(F, dF, dE);
    frm_material_dstress(law, mu, lambda, cache, dE, dS);
    frm_piola_variation(F, S, dF, dS, dP);
}

/* Pass 1 of K v: what one pair gives its frame, v B^T vec(dP):
       (v dP grad w,  v sum_j g_j x dp_j).
   The derivative of B^T through the frame's own rotation (the pairs' Hs) is summed per
   frame once per linearisation and applied in pass 2 (frm__stiffness_product). */
FRM_HOSTDEV static inline void frm_pair_apply(frm_real volume, const frm_real dP[9], const frm_real grad[3],
                                              const frm_real G[9], frm_real out[6])
{
    frm_real t[3];
    int r;
    for (r = 0; r < 3; r++) out[r] = volume * (dP[3 * r] * grad[0] + dP[3 * r + 1] * grad[1] + dP[3 * r + 2] * grad[2]);
    frm_column_cross_sum(G, dP, t);
    out[3] = volume * t[0];
    out[4] = volume * t[1];
    out[5] = volume * t[2];
}

/* The coupling term (see MODEL): E_c = 1/2 sum_k c |w_k| |d_k - p|^2 per sample, c =
   frame_coupling * mu v / h^2. It vanishes under rigid motion and pins the rotations the
   interpolation cannot see. Adds its generalized forces (-g_k, -a_k x g_k),
   g_k = dE_c/dd_k = c |w_k| e_k - w_k sum_j c |w_j| e_j, to out (6 per slot); stores g
   (3 per slot) when gout is not NULL; returns E_c. */
FRM_HOSTDEV static inline frm_real frm_sample_coupling_force(int n, const frm_real *weight, const frm_real *lever,
                                                             const frm_real *offset, frm_real c, frm_real *out,
                                                             frm_real *gout)
{
    frm_real ebar[3] = {0, 0, 0}, energy = 0;
    int k, r;
    for (k = 0; k < n; k++) {
        frm_real a = c * (weight[k] < 0 ? -weight[k] : weight[k]);
        const frm_real *e = offset + 3 * k;
        for (r = 0; r < 3; r++) ebar[r] += a * e[r];
        energy += (frm_real)0.5 * a * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    }
    for (k = 0; k < n; k++) {
        frm_real a = c * (weight[k] < 0 ? -weight[k] : weight[k]), g[3], t[3];
        for (r = 0; r < 3; r++) g[r] = a * offset[3 * k + r] - weight[k] * ebar[r];
        frm_cross(lever + 3 * k, g, t);
        for (r = 0; r < 3; r++) {
            out[6 * k + r] -= g[r];
            out[6 * k + 3 + r] -= t[r];
        }
        if (gout)
            for (r = 0; r < 3; r++) gout[3 * k + r] = g[r];
    }
    return energy;
}

/* Its stiffness applied to v (6 per frame, gathered through frame[]), added to out (6 per
   slot): the Gauss-Newton part, y_k = c |w_k| (dd_k - dp) - w_k sum_j c |w_j| (dd_j - dp)
   with dd = dx + dtheta x a and dp = sum w dd, mapped as (y, a x y). The rotation's
   second-order part M dtheta (frm_pair_coupling_rotation) is a frame-own term: the
   linearisation adds it to the pair's Hs. */
FRM_HOSTDEV static inline void frm_sample_coupling_apply(int n, const int *frame, const frm_real *weight,
                                                         const frm_real *lever, frm_real c, const frm_real *v,
                                                         frm_real *out)
{
    frm_real dd[3 * FRM_MAX_NEIGHBORS], dp[3] = {0, 0, 0}, rbar[3] = {0, 0, 0};
    int k, r;
    for (k = 0; k < n; k++) {
        const frm_real *q = v + 6 * frame[k];
        frm_real t[3];
        frm_cross(q + 3, lever + 3 * k, t);
        for (r = 0; r < 3; r++) {
            dd[3 * k + r] = q[r] + t[r];
            dp[r] += weight[k] * dd[3 * k + r];
        }
    }
    for (k = 0; k < n; k++) {
        frm_real a = c * (weight[k] < 0 ? -weight[k] : weight[k]);
        for (r = 0; r < 3; r++) {
            dd[3 * k + r] = a * (dd[3 * k + r] - dp[r]);
            rbar[r] += dd[3 * k + r];
        }
    }
    for (k = 0; k < n; k++) {
        const frm_real *a = lever + 3 * k;
        frm_real y[3], t[3];
        for (r = 0; r < 3; r++) y[r] = dd[3 * k + r] - weight[k] * rbar[r];
        frm_cross(a, y, t);
        for (r = 0; r < 3; r++) {
            out[6 * k + r] += y[r];
            out[6 * k + 3 + r] += t[r];
        }
    }
}

/* Assembly of the coupling: K_ab += coef J_a^T J_b, J_k = [I, -[a_k]x] (dd_k = J_k dq_k),
   coef = c (|w_a| delta_ab - |w_a| w_b - w_a |w_b| + sum|w| w_a w_b); the caller adds M on
   the diagonal. J_a^T J_b = [I, -[b]x; [a]x, (a . b) I - b a^T]. */
FRM_HOSTDEV static inline void frm_pair_coupling_block(frm_real coef, const frm_real la[3], const frm_real lb[3],
                                                       frm_real K[36])
{
    frm_real ab = la[0] * lb[0] + la[1] * lb[1] + la[2] * lb[2];
    int r, c;
    for (r = 0; r < 3; r++) K[7 * r] += coef;
    /* -[b]x top right, [a]x bottom left */
    K[4] += coef * lb[2];
    K[5] -= coef * lb[1];
    K[9] -= coef * lb[2];
    K[11] += coef * lb[0];
    K[15] += coef * lb[1];
    K[16] -= coef * lb[0];
    K[19] -= coef * la[2];
    K[20] += coef * la[1];
    K[24] += coef * la[2];
    K[26] -= coef * la[0];
    K[30] -= coef * la[1];
    K[31] += coef * la[0];
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) K[6 * (3 + r) + 3 + c] += coef * ((r == c ? ab : 0) - lb[r] * la[c]);
}

/* The coupling's second-order rotational part M = (g a^T + a g^T)/2 - (g . a) I of one
   slot, added to its Hs (6, Voigt). */
FRM_HOSTDEV static inline void frm_pair_coupling_rotation(const frm_real g[3], const frm_real a[3], frm_real Hs[6])
{
    frm_real ga = g[0] * a[0] + g[1] * a[1] + g[2] * a[2];
    Hs[0] += g[0] * a[0] - ga;
    Hs[1] += g[1] * a[1] - ga;
    Hs[2] += g[2] * a[2] - ga;
    Hs[3] += (frm_real)0.5 * (g[1] * a[2] + a[1] * g[2]);
    Hs[4] += (frm_real)0.5 * (g[0] * a[2] + a[0] * g[2]);
    Hs[5] += (frm_real)0.5 * (g[0] * a[1] + a[0] * g[1]);
}

/* axial(skew A) = ((A21 - A12)... ): the vector u with skew(A) = [u]x; u . axial(A) =
   [u]x : A / 2. */
FRM_HOSTDEV static inline void frm_skew_axial(const frm_real A[9], frm_real u[3])
{
    u[0] = (frm_real)0.5 * (A[7] - A[5]);
    u[1] = (frm_real)0.5 * (A[2] - A[6]);
    u[2] = (frm_real)0.5 * (A[3] - A[1]);
}

/* T = c/2 Q [u]x with Q = I + Qm. */
FRM_HOSTDEV static inline void frm_stab_stress(frm_real c, const frm_real Qm[9], const frm_real u[3], frm_real T[9])
{
    frm_real X[9], h = (frm_real)0.5 * c;
    int r, k;
    X[0] = 0, X[1] = -u[2], X[2] = u[1];
    X[3] = u[2], X[4] = 0, X[5] = -u[0];
    X[6] = -u[1], X[7] = u[0], X[8] = 0;
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++)
            T[3 * r + k] = h * (X[3 * r + k] + Qm[3 * r] * X[k] + Qm[3 * r + 1] * X[3 + k] + Qm[3 * r + 2] * X[6 + k]);
}

/* The rotation of a sample relative to one of its frames (see MODEL, rotation
   stabilisation): with A = Q^T F the sample's deformation seen in the frame's rest axes,
   omega = axial(skew A). H = F - I and Qm = Q - I keep small rotations' digits:
   skew(Q^T F) = skew(Qm^T + H + Qm^T H). */
FRM_HOSTDEV static inline void frm_pair_stab_omega(const frm_real H[9], const frm_real Qm[9], frm_real om[3])
{
    frm_real A[9];
    int r, k;
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++)
            A[3 * r + k] = Qm[3 * k + r] + H[3 * r + k] + Qm[r] * H[k] + Qm[3 + r] * H[3 + k] + Qm[6 + r] * H[6 + k];
    frm_skew_axial(A, om);
}

/* Its variation for the sample's dF and the frame's rotation dtheta (Q -> exp([dtheta]x) Q):
   domega = axial(skew(Q^T (dF - [dtheta]x F))). dtheta may be NULL (zero). */
FRM_HOSTDEV static inline void frm_pair_stab_domega(const frm_real F[9], const frm_real dF[9], const frm_real Qm[9],
                                                    const frm_real *dtheta, frm_real om[3])
{
    frm_real D[9], A[9];
    int r, k;
    for (k = 0; k < 9; k++) D[k] = dF[k];
    if (dtheta)
        for (k = 0; k < 3; k++) { /* D = dF - [dtheta]x F, column by column */
            D[k] -= dtheta[1] * F[6 + k] - dtheta[2] * F[3 + k];
            D[3 + k] -= dtheta[2] * F[k] - dtheta[0] * F[6 + k];
            D[6 + k] -= dtheta[0] * F[3 + k] - dtheta[1] * F[k];
        }
    for (r = 0; r < 3; r++) /* A = Q^T D */
        for (k = 0; k < 3; k++)
            A[3 * r + k] = D[3 * r + k] + Qm[r] * D[k] + Qm[3 + r] * D[3 + k] + Qm[6 + r] * D[6 + k];
    frm_skew_axial(A, om);
}

/* Z = Q [g]x = [g]x + Qm [g]x for a pair's weight gradient g: the divergence term's
   direction, g . axial(skew(Q^T A)) = Z : A / 2 for any A (row r of Qm [g]x is qm_r x g). */
FRM_HOSTDEV static inline void frm_stab_direction(const frm_real Qm[9], const frm_real g[3], frm_real Z[9])
{
    int r;
    for (r = 0; r < 3; r++) {
        const frm_real *q = Qm + 3 * r;
        Z[3 * r] = q[1] * g[2] - q[2] * g[1];
        Z[3 * r + 1] = q[2] * g[0] - q[0] * g[2];
        Z[3 * r + 2] = q[0] * g[1] - q[1] * g[0];
    }
    Z[1] -= g[2];
    Z[2] += g[1];
    Z[3] += g[2];
    Z[5] -= g[0];
    Z[6] -= g[1];
    Z[7] += g[0];
}

/* The frame-own second-order part of the stabilisation, X = sym(F T^T) - tr(F^T T) I (6,
   Voigt), added to the pair's Hs at the linearisation (dtheta . X dtheta = T : [dtheta]x^2 F). */
FRM_HOSTDEV static inline void frm_pair_stab_rotation(const frm_real F[9], const frm_real T[9], frm_real Hs[6])
{
    frm_real h[9], tr;
    int r, k;
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) h[3 * r + k] = F[3 * r] * T[3 * k] + F[3 * r + 1] * T[3 * k + 1] + F[3 * r + 2] * T[3 * k + 2];
    tr = h[0] + h[4] + h[8];
    Hs[0] += h[0] - tr;
    Hs[1] += h[4] - tr;
    Hs[2] += h[8] - tr;
    Hs[3] += (frm_real)0.5 * (h[5] + h[7]);
    Hs[4] += (frm_real)0.5 * (h[2] + h[6]);
    Hs[5] += (frm_real)0.5 * (h[1] + h[3]);
}

/* The stabilisation's stiffness (symmetric part, less the frame-own X above) for one pair:
   for the sample's dF, the frame's dtheta and u = N domega + g dD grad w the Gauss-Newton
   conjugate of the pair's domega (frm_pair_stab_domega; see frm__stab_sample_apply),
       Ta = c/2 Q [u]x,   dPx = Ta + [dtheta]x T,   torque = -sum_j (f_j x ta_j + df_j x t_j),
   dPx a stress-like term (absolute: the caller divides by the volume and adds it to dP,
   which B^T takes to every frame), torque the frame's own row, T = c/2 Q [m]x with m the
   linearisation's conjugate. definite = 1 keeps the Gauss-Newton part only (Ta;
   -sum f_j x ta_j), which is positive semi-definite. dtheta may be NULL (zero). */
FRM_HOSTDEV static inline void frm_pair_stab_apply(const frm_real F[9], const frm_real dF[9], const frm_real Qm[9],
                                                   frm_real c, const frm_real u[3], const frm_real m[3],
                                                   const frm_real *dtheta, int definite, frm_real dPx[9],
                                                   frm_real torque[3])
{
    frm_real t[3];
    int r, k;
    frm_stab_stress(c, Qm, u, dPx);
    frm_column_cross_sum(F, dPx, torque);
    for (r = 0; r < 3; r++) torque[r] = -torque[r];
    if (!definite) {
        frm_real T[9];
        frm_stab_stress(c, Qm, m, T);
        frm_column_cross_sum(dF, T, t);
        for (r = 0; r < 3; r++) torque[r] -= t[r];
        if (dtheta)
            for (k = 0; k < 3; k++) { /* dPx += [dtheta]x T */
                dPx[k] += dtheta[1] * T[6 + k] - dtheta[2] * T[3 + k];
                dPx[3 + k] += dtheta[2] * T[k] - dtheta[0] * T[6 + k];
                dPx[6 + k] += dtheta[0] * T[3 + k] - dtheta[1] * T[k];
            }
    }
}

/* Assembly: the 6 tangent columns cols[c] = A B e_c (9 each) of one pair, A = dP/dF. */
FRM_HOSTDEV static inline void frm_pair_tangent_columns(int law, frm_real mu, frm_real lambda, const frm_real *cache,
                                                        const frm_real F[9], const frm_real S[6],
                                                        const frm_real grad[3], const frm_real G[9],
                                                        frm_real cols[54])
{
    int c, k;
    for (c = 0; c < 6; c++) {
        frm_real dq[6] = {0, 0, 0, 0, 0, 0}, dF[9];
        for (k = 0; k < 9; k++) dF[k] = 0;
        dq[c] = 1;
        frm_pair_dF(dq, grad, G, dF);
        frm_sample_dP(law, mu, lambda, cache, F, S, dF, cols + 9 * c);
    }
}

/* Assembly: block K_ab += v B_a^T A B_b between slots a (rows, its tangent columns) and b
   (grad w_b, G_b): row r is v B_b^T cols_a[r]. Row-major 6x6. */
FRM_HOSTDEV static inline void frm_pair_block(frm_real volume, const frm_real cols_a[54], const frm_real grad_b[3],
                                              const frm_real G_b[9], frm_real K[36])
{
    int r, c;
    for (r = 0; r < 6; r++) {
        const frm_real *Y = cols_a + 9 * r;
        frm_real t[3];
        for (c = 0; c < 3; c++) K[6 * r + c] += volume * (Y[3 * c] * grad_b[0] + Y[3 * c + 1] * grad_b[1] + Y[3 * c + 2] * grad_b[2]);
        frm_column_cross_sum(G_b, Y, t);
        for (c = 0; c < 3; c++) K[6 * r + 3 + c] += volume * t[c];
    }
}


/* >>passes: the bodies of the two passes over a frm_view, shared by the CPU loops (which
   run them over fixed chunks, see THREADING) and the CUDA companion (one thread a sample
   in pass 1, one a frame in pass 2). Pass 1 per sample s writes each of its pairs'
   partial contribution (6 reals) into p_out; pass 2 per frame sums them through the
   reverse table. The constitutive law sits between frm_pass1_deform and the pair loop:
   a backend evaluates it its own way (the CPU through the law table, which also runs
   user callbacks; the GPU through frm_material_stress / frm_sample_dP, the laws with a
   fast path). Nothing here keeps a per-pair array on the stack: per-pair quantities the
   sample's sums need twice (levers, the stabilisation's T_k and omega_k) are recomputed
   by the same expressions (the same bits), and the stabilisation's K v torques wait in
   p_out; only the coupling term (desc.frame_coupling, off by default) keeps 3 n levers
   and offsets on the stack. */

/* Pass 1, force and K v: the lever a = Q abar = abar + Qm abar of pair p (world axes, m),
   by the expression of frm_sample_deformation. */
FRM_HOSTDEV static inline void frm_pass_lever(const frm_view *w, int p, frm_real lever[3])
{
    const frm_real *Qm = w->relm + 9 * w->p_frame[p], *ab = w->p_rlev + 3 * (size_t)p;
    int r;
    for (r = 0; r < 3; r++) lever[r] = ab[r] + (Qm[3 * r] * ab[0] + Qm[3 * r + 1] * ab[1] + Qm[3 * r + 2] * ab[2]);
}

/* Pass 1 of the force, first part: H = F - I and F of sample s (eqs. 3.34, 3.40), and its
   position into position (3; NULL: not wanted). */
FRM_HOSTDEV static inline void frm_pass1_deform(const frm_view *w, int s, frm_real H[9], frm_real F[9],
                                                frm_real *position)
{
    int b = w->s_start[s], n = w->s_start[s + 1] - b, r;
    frm_sample_deformation(n, w->p_frame + b, w->p_weight + b, w->p_grad + 3 * (size_t)b, w->p_rlev + 3 * (size_t)b,
                           w->s_rest + 3 * (size_t)s, w->disp, w->relm, H, NULL, NULL, position);
    for (r = 0; r < 9; r++) F[r] = H[r];
    F[0] += 1; /* F = I + H */
    F[4] += 1;
    F[8] += 1;
}

/* Pass 1 of the force, the rotation stabilisation of sample s (see MODEL): adds its stress
   to P (divided by the volume), sets *D (the divergence D = Y : F / 2, with Y = sum_k Z_k
   over the pairs of frames without unseen rotations, Dall over all) and returns its
   energy (J). With linearize, stores the data K v needs (p_stab per pair: the frames with
   unseen rotations m_k = N omega_k + g D grad w_k, the others t_k = sum_j f_j x z_kj; Y
   and D per sample). The frame-own torques and T_k: frm_pass1_stab_pair. */
FRM_HOSTDEV static inline double frm_pass1_stab_force(const frm_view *w, int s, const frm_real H[9],
                                                      const frm_real F[9], frm_real P[9], int linearize, frm_real *Dout)
{
    int b = w->s_start[s], n = w->s_start[s + 1] - b, k, r, i;
    frm_real v = w->s_volume[s], c = w->s_mu[s] * v, g = w->s_hstab[s], Y[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, D = 0, Dall[9];
    frm_real sD, Z[9], gmax = 0;
    double energy = 0;
    for (r = 0; r < 9; r++) Dall[r] = 0;
    for (k = 0; k < n; k++) { /* Z_k: Y over the plain pairs, Dall over the others */
        const frm_real *gk = w->p_grad + 3 * (size_t)(b + k);
        i = w->p_frame[b + k];
        frm_stab_direction(w->relm + 9 * i, gk, Z);
        for (r = 0; r < 9; r++) {
            if (w->f_stab_on[i]) Dall[r] += Z[r];
            else Y[r] += Z[r];
        }
        for (r = 0; r < 3; r++) gmax = gk[r] > gmax ? gk[r] : -gk[r] > gmax ? -gk[r] : gmax;
    }
    /* Y and D sum terms of the size of the gradients (the [g]x parts cancel, sum g_k = 0):
       parts below eps^2 max|g| are an eps-th of their rounding, flushed (FRM_TINY) so that
       sD Y stays normal at rest */
    gmax *= FRM_TINY;
    for (r = 0; r < 9; r++) Y[r] = frm_flush_below(Y[r], gmax);
    for (r = 0; r < 9; r++) Dall[r] += Y[r];
    D = (frm_real)0.5 * (Dall[0] + Dall[4] + Dall[8] + Dall[0] * H[0] + Dall[1] * H[1] + Dall[2] * H[2] + Dall[3] * H[3] +
                         Dall[4] * H[4] + Dall[5] * H[5] + Dall[6] * H[6] + Dall[7] * H[7] + Dall[8] * H[8]);
    D = frm_flush_below(D, gmax);
    energy += 0.5 * (double)c * (double)g * (double)D * (double)D;
    sD = (frm_real)0.5 * c * g * D;
    for (r = 0; r < 9; r++) P[r] += sD * Y[r] / v;
    for (k = 0; k < n; k++) {
        const frm_real *gk = w->p_grad + 3 * (size_t)(b + k);
        i = w->p_frame[b + k];
        if (w->f_stab_on[i]) {
            const frm_real *N = w->f_stab + 6 * i;
            frm_real om[3], mk[3], T[9];
            frm_pair_stab_omega(H, w->relm + 9 * i, om);
            mk[0] = N[0] * om[0] + N[5] * om[1] + N[4] * om[2];
            mk[1] = N[5] * om[0] + N[1] * om[1] + N[3] * om[2];
            mk[2] = N[4] * om[0] + N[3] * om[1] + N[2] * om[2];
            energy += 0.5 * (double)c * (double)(om[0] * mk[0] + om[1] * mk[1] + om[2] * mk[2]);
            for (r = 0; r < 3; r++) mk[r] += g * D * gk[r];
            frm_stab_stress(c, w->relm + 9 * i, mk, T);
            for (r = 0; r < 9; r++) P[r] += T[r] / v;
            if (linearize)
                for (r = 0; r < 3; r++) w->p_stab[3 * (size_t)(b + k) + r] = mk[r];
        } else if (linearize) {
            frm_real t[3];
            frm_stab_direction(w->relm + 9 * i, gk, Z);
            frm_column_cross_sum(F, Z, t);
            for (r = 0; r < 3; r++) w->p_stab[3 * (size_t)(b + k) + r] = t[r];
        }
    }
    if (linearize) {
        for (r = 0; r < 9; r++) w->s_stabY[9 * (size_t)s + r] = Y[r];
        w->s_stabD[s] = D;
    }
    *Dout = D;
    return energy;
}

/* Pass 1 of the force, the stabilisation's T_k (9) and frame-own torque (3) of slot k of
   sample s, given the sample's D (frm_pass1_stab_force computed the same values). */
FRM_HOSTDEV static inline void frm_pass1_stab_pair(const frm_view *w, int s, int k, const frm_real H[9],
                                                   const frm_real F[9], frm_real D, frm_real T[9], frm_real stq[3])
{
    int b = w->s_start[s], i = w->p_frame[b + k], r;
    frm_real v = w->s_volume[s], c = w->s_mu[s] * v, g = w->s_hstab[s];
    const frm_real *gk = w->p_grad + 3 * (size_t)(b + k);
    if (w->f_stab_on[i]) {
        const frm_real *N = w->f_stab + 6 * i;
        frm_real om[3], mk[3];
        frm_pair_stab_omega(H, w->relm + 9 * i, om);
        mk[0] = N[0] * om[0] + N[5] * om[1] + N[4] * om[2];
        mk[1] = N[5] * om[0] + N[1] * om[1] + N[3] * om[2];
        mk[2] = N[4] * om[0] + N[3] * om[1] + N[2] * om[2];
        for (r = 0; r < 3; r++) mk[r] += g * D * gk[r];
        frm_stab_stress(c, w->relm + 9 * i, mk, T);
        frm_column_cross_sum(F, T, stq);
    } else {
        frm_real t[3], sD = (frm_real)0.5 * c * g * D;
        frm_stab_direction(w->relm + 9 * i, gk, T);
        frm_column_cross_sum(F, T, t);
        for (r = 0; r < 3; r++) stq[r] = sD * t[r];
        for (r = 0; r < 9; r++) T[r] *= sD;
    }
}

/* Pass 1 of the force, the pairs of sample s for its final stress P (the law's, plus the
   stabilisation's; D from frm_pass1_stab_force, unused without it): each pair's partial
   force into p_out (eq. 3.52; the stabilisation's frame-own torque and the coupling
   term's forces added), the coupling term's energy added to *energy; with linearize, the
   pairs' lever a, G and Hs (the frame-own terms of the stabilisation and the coupling
   included) and the coupling's g. */
FRM_HOSTDEV static inline void frm_pass1_force_pairs(const frm_view *w, int s, const frm_real H[9],
                                                     const frm_real F[9], const frm_real P[9], frm_real D,
                                                     int linearize, double *energy)
{
    int b = w->s_start[s], n = w->s_start[s + 1] - b, k, r, stab = w->s_stab[s];
    frm_real v = w->s_volume[s], Pf[9], top = 0;
    for (r = 0; r < 9; r++) top = P[r] > top ? P[r] : -P[r] > top ? -P[r] : top;
    top *= FRM_TINY / FLT_EPSILON; /* P's entries below eps max|P|, one rounding of its largest: FRM_TINY */
    for (r = 0; r < 9; r++) Pf[r] = frm_flush_below(P[r], top);
    P = Pf;
    for (k = 0; k < n; k++) {
        int p = b + k, i = w->p_frame[p];
        frm_real lever[3], T[9], stq[3], *out = w->p_out + 6 * (size_t)p;
        frm_pass_lever(w, p, lever);
        frm_pair_force(v, P, w->p_grad + 3 * (size_t)p, w->p_weight[p], lever, w->rel + 9 * i, out);
        if (stab) {
            frm_pass1_stab_pair(w, s, k, H, F, D, T, stq);
            for (r = 0; r < 3; r++) out[3 + r] += stq[r];
        }
        if (linearize) {
            frm_real *Hs = w->p_H + 6 * (size_t)p;
            for (r = 0; r < 3; r++) w->p_A[3 * (size_t)p + r] = lever[r];
            frm_pair_linearize(v, P, w->p_grad + 3 * (size_t)p, w->p_weight[p], lever, w->rel + 9 * i,
                               w->p_G + 9 * (size_t)p, Hs);
            if (stab) frm_pair_stab_rotation(F, T, Hs);
        }
    }
    if (w->s_couple[s] != 0) {
        frm_real lever[3 * FRM_MAX_NEIGHBORS], offset[3 * FRM_MAX_NEIGHBORS], Hc[9];
        frm_sample_deformation(n, w->p_frame + b, w->p_weight + b, w->p_grad + 3 * (size_t)b, w->p_rlev + 3 * (size_t)b,
                               w->s_rest + 3 * (size_t)s, w->disp, w->relm, Hc, lever, offset, NULL);
        *energy += (double)frm_sample_coupling_force(n, w->p_weight + b, lever, offset, w->s_couple[s],
                                                     w->p_out + 6 * (size_t)b, linearize ? w->p_C + 3 * (size_t)b : NULL);
        if (linearize)
            for (k = 0; k < n; k++)
                frm_pair_coupling_rotation(w->p_C + 3 * (size_t)(b + k), lever + 3 * k, w->p_H + 6 * (size_t)(b + k));
    }
}

/* Pass 1 of K v (pair mode), first part: dF of sample s from its neighbours' v (6 per
   frame: translation, rotation) through the linearisation's G (eq. 3.43). */
FRM_HOSTDEV static inline void frm_pass1_apply_dF(const frm_view *w, int s, const frm_real *v, frm_real dF[9])
{
    int b = w->s_start[s], e = w->s_start[s + 1], k;
    for (k = 0; k < 9; k++) dF[k] = 0;
    for (k = b; k < e; k++) frm_pair_dF(v + 6 * w->p_frame[k], w->p_grad + 3 * (size_t)k, w->p_G + 9 * (size_t)k, dF);
}

/* Pass 1 of K v, the pairs of sample s for its dF and the law's dP (dP receives the
   stabilisation's stress-like part): each pair's v_s B^T vec(dP) (plus the stabilisation's
   frame-own torque and the coupling's Gauss-Newton part) into p_out. definite: the
   linearisation is K's positive-definite part (the stabilisation's Gauss-Newton part
   only). The stabilisation (see frm_pair_stab_apply): dD = Y : dF / 2 + sum over the pairs
   of frames with unseen rotations g_k . domega_k - sum over the others dtheta_k . t_k / 2;
   its torques wait in p_out's rotational half until dP is complete. */
FRM_HOSTDEV static inline void frm_pass1_apply_pairs(const frm_view *w, int s, const frm_real *v, const frm_real dF[9],
                                                     frm_real dP[9], int definite)
{
    int b = w->s_start[s], n = w->s_start[s + 1] - b, k, r, i, stab = w->s_stab[s];
    frm_real vol = w->s_volume[s];
    if (stab) {
        const frm_real *F = w->lin_F + 9 * (size_t)s, *Y = w->s_stabY + 9 * (size_t)s;
        frm_real c = w->s_mu[s] * w->s_volume[s], g = w->s_hstab[s], D = w->s_stabD[s], dD, s1, s2, dPx[9];
        dD = (frm_real)0.5 * (Y[0] * dF[0] + Y[1] * dF[1] + Y[2] * dF[2] + Y[3] * dF[3] + Y[4] * dF[4] + Y[5] * dF[5] +
                              Y[6] * dF[6] + Y[7] * dF[7] + Y[8] * dF[8]);
        for (k = 0; k < n; k++) {
            const frm_real *t = w->p_stab + 3 * (size_t)(b + k), *gk = w->p_grad + 3 * (size_t)(b + k);
            const frm_real *th = v + 6 * w->p_frame[b + k] + 3;
            i = w->p_frame[b + k];
            if (w->f_stab_on[i]) {
                frm_real om[3];
                frm_pair_stab_domega(F, dF, w->relm + 9 * i, th, om);
                dD += gk[0] * om[0] + gk[1] * om[1] + gk[2] * om[2];
            } else
                dD -= (frm_real)0.5 * (th[0] * t[0] + th[1] * t[1] + th[2] * t[2]);
        }
        s1 = (frm_real)0.5 * c * g * dD;
        s2 = (frm_real)0.5 * c * g * D;
        for (r = 0; r < 9; r++) dPx[r] = s1 * Y[r];
        for (k = 0; k < n; k++) {
            const frm_real *t = w->p_stab + 3 * (size_t)(b + k), *gk = w->p_grad + 3 * (size_t)(b + k);
            const frm_real *th = v + 6 * w->p_frame[b + k] + 3;
            frm_real *stq = w->p_out + 6 * (size_t)(b + k) + 3;
            i = w->p_frame[b + k];
            if (w->f_stab_on[i]) {
                const frm_real *N = w->f_stab + 6 * i;
                frm_real o[3], u[3], d[9];
                frm_pair_stab_domega(F, dF, w->relm + 9 * i, th, o);
                u[0] = N[0] * o[0] + N[5] * o[1] + N[4] * o[2] + g * dD * gk[0];
                u[1] = N[5] * o[0] + N[1] * o[1] + N[3] * o[2] + g * dD * gk[1];
                u[2] = N[4] * o[0] + N[3] * o[1] + N[2] * o[2] + g * dD * gk[2];
                frm_pair_stab_apply(F, dF, w->relm + 9 * i, c, u, t, th, definite, d, stq);
                for (r = 0; r < 9; r++) dPx[r] += d[r];
                continue;
            }
            for (r = 0; r < 3; r++) stq[r] = -s1 * t[r];
            if (!definite && s2 != 0) {
                frm_real Z[9], x[3];
                frm_stab_direction(w->relm + 9 * i, gk, Z);
                frm_column_cross_sum(dF, Z, x);
                for (r = 0; r < 3; r++) stq[r] -= s2 * x[r];
                for (r = 0; r < 3; r++) { /* dPx += [dtheta]x T_k, column r */
                    dPx[r] += s2 * (th[1] * Z[6 + r] - th[2] * Z[3 + r]);
                    dPx[3 + r] += s2 * (th[2] * Z[r] - th[0] * Z[6 + r]);
                    dPx[6 + r] += s2 * (th[0] * Z[3 + r] - th[1] * Z[r]);
                }
            }
        }
        for (r = 0; r < 9; r++) dP[r] += dPx[r] / vol;
        for (k = b; k < b + n; k++) { /* the pairs' products, the waiting torques added (the same sum) */
            frm_real y[6], *out = w->p_out + 6 * (size_t)k;
            frm_pair_apply(vol, dP, w->p_grad + 3 * (size_t)k, w->p_G + 9 * (size_t)k, y);
            for (r = 0; r < 3; r++) {
                out[r] = y[r];
                out[3 + r] = y[3 + r] + out[3 + r];
            }
        }
    } else
        for (k = b; k < b + n; k++)
            frm_pair_apply(vol, dP, w->p_grad + 3 * (size_t)k, w->p_G + 9 * (size_t)k, w->p_out + 6 * (size_t)k);
    if (w->s_couple[s] != 0)
        frm_sample_coupling_apply(n, w->p_frame + b, w->p_weight + b, w->p_A + 3 * (size_t)b, w->s_couple[s], v,
                                  w->p_out + 6 * (size_t)b);
}

/* Pass 2 of frame i: dst (6) = the sum of src (6 per pair) over its pairs in pair order
   through the reverse table, in double; scale (may be NULL) = the sum of their |src|^2. */
FRM_HOSTDEV static inline void frm_pass2_gather(const frm_view *w, int i, const frm_real *src, frm_real *dst,
                                                double *scale)
{
    double sum[6] = {0, 0, 0, 0, 0, 0}, sq = 0;
    int e, k;
    for (e = w->rev_start[i]; e < w->rev_start[i + 1]; e++) {
        const frm_real *x = src + 6 * (size_t)w->rev_pair[e];
        for (k = 0; k < 6; k++) sum[k] += (double)x[k];
        if (scale)
            for (k = 0; k < 6; k++) sq += (double)x[k] * x[k];
    }
    for (k = 0; k < 6; k++) dst[6 * i + k] = (frm_real)sum[k];
    if (scale) scale[i] = sq;
}

/* Adds a frame-own rotational term H (6: xx yy zz yz xz xy) to the rotation block of a
   6x6 block D. */
FRM_HOSTDEV static inline void frm__add_rotational(const frm_real *H, frm_real *D)
{
    D[21] += H[0];
    D[28] += H[1];
    D[35] += H[2];
    D[29] += H[3];
    D[34] += H[3];
    D[23] += H[4];
    D[33] += H[4];
    D[22] += H[5];
    D[27] += H[5];
}

/* One frame's pair-mode block-Jacobi block: the rest block K0 turned with the frame,
   T K0 T^T with T = diag(Q, Q), plus the frame-own rotational term H (6). frm__prepare_mode
   and the CUDA companion call it. */
FRM_HOSTDEV static inline void frm_pass_precond_block(const frm_real *Q, const frm_real *K0, const frm_real *H,
                                                      frm_real *K)
{
    double T[36], KT[36];
    int r, k, l;
    for (k = 0; k < 36; k++) T[k] = 0;
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) T[6 * r + k] = T[6 * (r + 3) + k + 3] = Q[3 * r + k];
    for (r = 0; r < 6; r++)
        for (k = 0; k < 6; k++) {
            double t = 0;
            for (l = 0; l < 6; l++) t += (double)K0[6 * r + l] * T[6 * k + l];
            KT[6 * r + k] = t; /* K0 T^T */
        }
    for (r = 0; r < 6; r++)
        for (k = 0; k < 6; k++) {
            double t = 0;
            for (l = 0; l < 6; l++) t += T[6 * r + l] * KT[6 * l + k];
            K[6 * r + k] = (frm_real)t;
        }
    frm__add_rotational(H, K);
}

/* One frame's world mass data from its rest-axes data ml (m, cbar, Jbar: 10 numbers) and
   its rotation R: m, c = R cbar, J = R Jbar R^T (symmetrised). frm__mass_update and the
   CUDA companion call it. */
FRM_HOSTDEV static inline void frm_pass_mass_world(const double *ml, const frm_real *R, frm_real *mw)
{
    double J[9], RJ[9], W[9];
    int r, k, l;
    J[0] = ml[4];
    J[4] = ml[5];
    J[8] = ml[6];
    J[5] = J[7] = ml[7];
    J[2] = J[6] = ml[8];
    J[1] = J[3] = ml[9];
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) {
            double t = 0;
            for (l = 0; l < 3; l++) t += (double)R[3 * r + l] * J[3 * l + k];
            RJ[3 * r + k] = t;
        }
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) {
            double t = 0;
            for (l = 0; l < 3; l++) t += RJ[3 * r + l] * (double)R[3 * k + l];
            W[3 * r + k] = t;
        }
    mw[0] = (frm_real)ml[0];
    for (r = 0; r < 3; r++) mw[1 + r] = (frm_real)(R[3 * r] * ml[1] + R[3 * r + 1] * ml[2] + R[3 * r + 2] * ml[3]);
    mw[4] = (frm_real)W[0];
    mw[5] = (frm_real)W[4];
    mw[6] = (frm_real)W[8];
    mw[7] = (frm_real)(0.5 * (W[5] + W[7]));
    mw[8] = (frm_real)(0.5 * (W[2] + W[6]));
    mw[9] = (frm_real)(0.5 * (W[1] + W[3]));
}

/* One frame's 6x6 mass block [m I, -[c]x; [c]x, J] from its world mass data w
   (frm_pass_mass_world's 10 numbers). frm__mass_matrix and the CUDA companion call it. */
FRM_HOSTDEV static inline void frm_pass_mass_matrix(const frm_real *w, double M[36])
{
    double c0 = w[1], c1 = w[2], c2 = w[3];
    int k;
    for (k = 0; k < 36; k++) M[k] = 0;
    for (k = 0; k < 3; k++) M[7 * k] = w[0];
    M[4] = c2; /* -[c]x, top right */
    M[5] = -c1;
    M[9] = -c2;
    M[11] = c0;
    M[15] = c1;
    M[16] = -c0;
    M[19] = -c2; /* [c]x, bottom left */
    M[20] = c1;
    M[24] = c2;
    M[26] = -c0;
    M[30] = -c1;
    M[31] = c0;
    M[21] = w[4];
    M[28] = w[5];
    M[35] = w[6];
    M[29] = M[34] = w[7];
    M[23] = M[33] = w[8];
    M[22] = M[27] = w[9];
}

/* out = M v for one frame from its world mass data w (6 values): (m x + omega x c,
   c x x + J omega). frm__mass_apply and the CUDA companion call it. */
FRM_HOSTDEV static inline void frm_pass_mass_apply(const frm_real *w, const frm_real *v, double out[6])
{
    double x0 = v[0], x1 = v[1], x2 = v[2], o0 = v[3], o1 = v[4], o2 = v[5];
    out[0] = (double)w[0] * x0 + (o1 * w[3] - o2 * w[2]);
    out[1] = (double)w[0] * x1 + (o2 * w[1] - o0 * w[3]);
    out[2] = (double)w[0] * x2 + (o0 * w[2] - o1 * w[1]);
    out[3] = (w[2] * x2 - w[3] * x1) + w[4] * o0 + w[9] * o1 + w[8] * o2;
    out[4] = (w[3] * x0 - w[1] * x2) + w[9] * o0 + w[5] * o1 + w[7] * o2;
    out[5] = (w[1] * x1 - w[2] * x0) + w[8] * o0 + w[7] * o1 + w[6] * o2;
}

/* 6x6 symmetric positive definite inverse by Cholesky of the symmetric part, in double.
   Returns 0 (inv unset) when a pivot is not a finite number above 1e-300. The block-Jacobi
   preconditioner of the CPU and of the CUDA companion call it. */
FRM_HOSTDEV static inline int frm_pass_invert6(const double A[36], double inv[36])
{
    double L[36], y[6];
    int i, j, k, c;
    for (k = 0; k < 36; k++) L[k] = 0;
    for (j = 0; j < 6; j++) {
        double d = A[6 * j + j];
        for (k = 0; k < j; k++) d -= L[6 * j + k] * L[6 * j + k];
        if (!(d > 1e-300) || !(d - d == 0.0)) return 0; /* not above the floor, or infinite */
        L[6 * j + j] = sqrt(d);
        for (i = j + 1; i < 6; i++) {
            double s = 0.5 * (A[6 * i + j] + A[6 * j + i]);
            for (k = 0; k < j; k++) s -= L[6 * i + k] * L[6 * j + k];
            L[6 * i + j] = s / L[6 * j + j];
        }
    }
    for (c = 0; c < 6; c++) { /* column c of the inverse: L L^T x = e_c */
        for (i = 0; i < 6; i++) {
            double s = (i == c);
            for (k = 0; k < i; k++) s -= L[6 * i + k] * y[k];
            y[i] = s / L[6 * i + i];
        }
        for (i = 5; i >= 0; i--) {
            double s = y[i];
            for (k = i + 1; k < 6; k++) s -= L[6 * k + i] * inv[6 * k + c];
            inv[6 * i + c] = s / L[6 * i + i];
        }
    }
    return 1;
}

/* One frame's world gravity moment c = R cbar_g (gl: the frame's 4 gravity numbers m_g,
   cbar_g) and the symmetric part of its torque's stiffness at c,
   K_g dtheta = -1/2 (c (g . dtheta) + g (c . dtheta)) + (c . g) dtheta. The CPU force pass,
   frm__total_force and the CUDA companion call them. */
FRM_HOSTDEV static inline void frm_pass_gravity_moment(const frm_real *R, const double *gl, frm_real c[3])
{
    int r;
    for (r = 0; r < 3; r++) c[r] = (frm_real)(R[3 * r] * gl[1] + R[3 * r + 1] * gl[2] + R[3 * r + 2] * gl[3]);
}

FRM_HOSTDEV static inline void frm_pass_gravity_stiffness(const frm_real *c, const frm_real *g, double K[9])
{
    double cg = (double)c[0] * g[0] + (double)c[1] * g[1] + (double)c[2] * g[2];
    int r, k;
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) K[3 * r + k] = -0.5 * ((double)c[r] * g[k] + (double)g[r] * c[k]) + (r == k ? cg : 0.0);
}

/* Pass 2 of K v (pair mode), after the gather: the frame-own rotational term of frame i
   (the pairs' Hs and gravity, lin_hrot) applied to v's rotation, added to out (6 per frame). */
FRM_HOSTDEV static inline void frm_pass2_rotational(const frm_view *w, int i, const frm_real *v, frm_real *out)
{
    const frm_real *h = w->lin_hrot + 6 * i, *t = v + 6 * i + 3;
    out[6 * i + 3] += h[0] * t[0] + h[5] * t[1] + h[4] * t[2];
    out[6 * i + 4] += h[5] * t[0] + h[1] * t[1] + h[3] * t[2];
    out[6 * i + 5] += h[4] * t[0] + h[3] * t[1] + h[2] * t[2];
}

#endif /* FRAMES_KERNELS */

/* ======================================================================================
   IMPLEMENTATION
   ====================================================================================== */
#if defined(FRAMES_IMPLEMENTATION) && !defined(FRAMES_IMPLEMENTATION_ONCE)
#define FRAMES_IMPLEMENTATION_ONCE

/* With FRM_STATIC the functions a program does not call are unused statics. */
#if defined(FRM_STATIC) && defined(__GNUC__)
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

#ifndef FRM_MALLOC
#include <stdlib.h>
#define FRM_MALLOC(size, user) ((void)(user), malloc(size))
#define FRM_FREE(ptr, user) ((void)(user), free(ptr))
#endif
#ifndef FRM_ASSERT
#include <assert.h>
#define FRM_ASSERT(x) assert(x)
#endif

#define FRM__COOKIE 0x46524D53u         /* "FRMS" */
#ifndef FRM__COARSE_MODES
#define FRM__COARSE_MODES 9 /* per aggregate: translation, rigid rotation, the frames' own rotation */
#endif
#define FRM__COARSE_MIN_ITERATIONS 40 /* solves with mass: block-Jacobi iterations that turn the coarse correction on */

#define FRM__SHAPE_COOKIE 0x46524D48u   /* "FRMH" */
#define FRM__POISSON_COOKIE 0x46524D50u /* "FRMP" */
#define FRM__PROBE_COOKIE 0x46524D51u   /* "FRMQ" */
#define FRM__MODAL_COOKIE 0x46524D4Du   /* "FRMM" */
#define FRM__ALIGN 64
#define FRM__SAMPLE_CHUNK 64  /* samples per task of the per-sample passes */
#define FRM__FRAME_CHUNK 32   /* frames per task of the per-frame passes */
#define FRM__IS_FLOAT (sizeof(frm_real) == sizeof(float))
/* tolerance on sum w = 1 and sum grad w = 0 (relative to sum |grad w|): a few roundings
   of 16 terms in frm_real */
#define FRM__SUM_TOL (FRM__IS_FLOAT ? 1e-5 : 1e-9)
/* tolerance on |q|^2 = 1 for given orientations (a normalised quaternion rounded to
   float is within 3e-7) */
#define FRM__UNIT_TOL 1e-5

/* frame states */
#define FRM__FREE 0
#define FRM__FIXED 1
#define FRM__DRIVEN 2

/* scratch vector roles (6 per frame each) */

struct frm_model {
    int frame_count, sample_count, pair_count, block_count, sq_total;
    int sample_chunks, frame_chunks, parallel;
    frm_allocator allocator;
    frm_parallel_for_fn parallel_for;
    void *parallel_user;
    void *block;
    size_t block_bytes;

    /* settings */
    frm_real gravity[3], time_step, mass_damping, stiffness_damping;
    frm_real cg_tolerance, newton_tolerance;
    int cg_max_iterations, newton_max_iterations, max_increments;
    int integrator;    /* frm_integrator: the row of frm__integrators frm_model_step runs */
    int linear_solver; /* frm_linear_solver: the solver frm__linear_solve runs (never AUTO) */
    int auto_btd;      /* 1: FRM_LINEAR_SOLVER_AUTO chose BTD (anchors switch to CG while set) */
    double min_increment, precision_limit, h_min; /* h_min: smallest rest lever (see precision_limit) */
    double load_scale;                            /* continuation: fraction of gravity and external loads */
    int stiffness_mode, has_blocks;
    double regularization, solve_regularization; /* static solves: eps added to K's rotational diagonal */
    frm_real stab_beta;                          /* rotation_stabilization */
    frm_real stab_gamma;                         /* rotation_divergence */
    int stab_on;                                 /* the stabilisation has a term (beta with unseen rotations, or gamma) */
    int stab_frames;                             /* frames with a rotation their samples do not see */
    double newton_previous;                      /* |f| at the previous Newton iteration */
    double floor_residual;                       /* |f| of the last iteration below the round-off floor, or 0 */

    /* frames */
    frm_real *disp, *pos, *quat, *vel;         /* 3 (u = x - xbar, the state), 3 (xbar + u, output), 4, 6 */
    frm_real *rest_pos, *rest_quat, *rest_rot; /* 3, 4, 9 */
    frm_real *rot, *rel, *relm;                /* 9, 9, 9: R, Q = R Rbar^T and Q - I of the current pose */
    double *mass_local;                        /* 10: m, cbar (3), Jbar (6), frame axes */
    double *grav_local;                        /* 4: m_g, cbar_g (3), frame axes */
    frm_real *mass_world;                      /* 10: m, c (3), J (6), world axes (mass_update) */
    frm_real *ext;                             /* 6: external force, torque */
    const frm_probe *anchor_probe;             /* anchors (frm_model_set_anchors): the caller's */
    const frm_real *anchor_k, *anchor_target;  /* probe and arrays, or NULL */
    unsigned char *state;
    unsigned char *axes;   /* 1: held components of a free frame (bits 0-2 translation, 3-5 rotation) */
    frm_real *ext_full;    /* 6: the external loads while a static solve scales them */
    frm_real *inc_state;   /* 13: the state at the start of a static increment */
    frm_real *drive_start; /* 7: driven frames' poses at the start of a static solve */
    frm_real *target;      /* 7: prescribed position, orientation */
    frm_real *force;       /* 6: internal generalized force (last pass) */
    double *force_scale;   /* 1: sum over the frame's pairs of |partial force|^2 (round-off scale) */
    frm_real *lin_torque;  /* 3: conservative torque at the linearisation */
    frm_real *lin_gravity; /* 3: world gravity moment c_g at the linearisation */
    frm_real *lin_hrot;    /* 6: the frame-own rotational term at the linearisation: sum of its pairs' Hs + the
                              gravity stiffness (projected on its positive part when definite) */
    frm_real *f_stab;      /* 6: projector on the rotations the frame's samples do not see (rest axes), or 0 */
    unsigned char *f_stab_on; /* 1: f_stab is not zero */
    frm_real *kdiag;       /* 36: K_ii (symmetric part) at the linearisation (pair mode: kdiag_rest rotated) */
    frm_real *kdiag_rest;  /* 36: K_ii of the rest state without gravity (pair mode's preconditioner) */
    frm_real *precond;     /* 36: inverse of the block-Jacobi blocks */
    int *rev_start, *rev_pair; /* frame -> pairs (the reverse table) */
    int *blk_start, *blk_col;  /* block pattern (frame adjacency) */
    frm_real *blocks;          /* 36 per block (assembled K, symmetric part) */
    frm_real *btd;             /* 144 per frame with FRM_LINEAR_SOLVER_BTD: diagonal, sub-diagonal, factor */
    int *sq_start, *pair_blk;  /* per sample n^2 block indices of its slot pairs */

    /* samples */
    frm_real *s_rest, *s_volume, *s_couple; /* s_couple: c of the coupling */
    frm_real *s_mu;         /* small-strain shear modulus (Pa): scales the stabilisation and the coupling */
    frm_real *s_law_params; /* FRM_LAW_PARAMS: the law's parameter block (see frm_law, frm__laws) */
    const frm_user_law **s_user; /* FRM_LAW_USER: the material's callbacks (in user_laws), else NULL */
    frm_user_law *user_laws;     /* a copy of every material's callbacks (user_law_count) */
    int user_law_count, law_cache; /* law_cache: lin_cache reals per sample, the largest cache_size in use */
    frm_real *s_hstab; /* g = gamma h^2 of the stabilisation's divergence term (m^2) */
    frm_real *s_stabY; /* 9: Y = sum of Z_k over the pairs of frames without unseen rotations, at the linearisation */
    frm_real *s_stabD; /* 1: D at the linearisation */
    unsigned char *s_law, *s_stab; /* s_stab: 1 if a neighbour has f_stab_on */
    unsigned char *s_inverted;     /* 1: det F <= 0 at the start of the step or solve */
    int *s_start;
    frm_real *lin_F, *lin_S, *lin_cache; /* 9, 6, law_cache at the linearisation */
    frm_real *s_pos, *s_F;               /* outputs: 3, 9 */

    /* pairs */
    int *p_frame, *p_sample;
    frm_real *p_weight, *p_grad, *p_local, *p_rlev; /* 1, 3, 3, 3: rest lever abar = Rbar lbar = pbar - xbar */
    frm_real *p_G, *p_H, *p_A, *p_C;       /* 9, 6, 3 (lever), 3 (coupling g) at the linearisation */
    frm_real *p_out;                       /* 6: pass-1 partial contributions */
    frm_real *p_stab;                      /* 3: the stabilisation at the linearisation: pairs of frames with
                                              unseen rotations m_k = N omega_k + g D grad w_k, the others
                                              t_k = sum_j f_j x z_j (F, Z_k); NULL without stabilisation */

    /* volumetric averaging (desc.volumetric, see MODEL): J_bar = A J with A = B N, entries e
       per sample (the pairs for FRAMES, one a sample for CELLS) of group (frame or cell)
       ve_group[e]: (A x)_s = sum_{e of s} ve_back[e] y_g, y_g = sum_{e of g} ve_to[e] x_{sample e};
       NULL arrays when off */
    int vol_mode, vol_groups, vol_entries;
    frm_real vol_eta; /* volumetric_stabilization */
    int *ve_start, *ve_group, *ve_sample, *vg_start, *vg_entry; /* S + 1, E, E, G + 1, E */
    frm_real *ve_back, *ve_to;                                  /* E, E */
    double *vg_y;                                               /* G: scratch of the averages */
    frm_real *v_H, *v_Pbar;                     /* 9, 9 per sample: H = F - I, P(F_bar) of the last pass */
    frm_real *v_jm1, *v_jbm1, *v_am1, *v_pi, *v_beta, *v_x, *v_y; /* 1 each: J - 1, J_bar - 1, alpha - 1, pi,
                                                                   beta of the last pass; scratch x, y */
    frm_real *vl_Finv, *vl_Fbar, *vl_Pbar;      /* 9 each at the linearisation: F^-1, F_bar, P(F_bar) */
    frm_real *vl_J, *vl_Jbar, *vl_alpha, *vl_pi, *vl_beta; /* 1 each at the linearisation */
    frm_real *vk_dF, *vk_dPbar, *vk_e, *vk_ebar, *vk_dpi;  /* K v scratch: 9, 9, 1, 1, 1 per sample */

    /* per sample chunk: energy partial sums and errors of the last pass */
    double *chunk_energy;
    int *chunk_err;

    /* scratch */
    /* 6 reals per frame each, named by role */
    frm_real *cg_r, *cg_z, *cg_p, *cg_q; /* CG residual, preconditioned residual, direction, A p */
    frm_real *newton_dx;                 /* a Newton iteration's solution (step, velocity change) */
    frm_real *newton_rhs;                /* its right-hand side */
    frm_real *total_force;               /* total generalized force */
    frm_real *work;                      /* temporary: a load, a trial force, K v */
    frm_real *warm_dv;                   /* the previous step's velocity change (CG warm start) */
    frm_real *drive_dv;                  /* driven frames' velocity change (Newton step: their dq) */
    frm_real *backup;      /* 13 per frame: position, orientation, velocity */
    frm_real *start_state; /* 13 per frame: the state a static solve started from */
    /* BDF2 (carved for every model: frm_model_set_integrator may choose it later) */
    frm_real *history;       /* 13 per frame: the state one step back (x_{n-1}, q_{n-1}, v_{n-1}) */
    frm_real *step_offset;   /* 6 per frame: xbar - x_n in the step's tangent coordinates */
    frm_real *step_velocity; /* 6 per frame: vbar, the step's reference velocity */
    int history_valid;       /* 0: the next BDF2 step is implicit Euler (after creation, a
                                discontinuity or a change of dt) */
    double history_dt;       /* the step length the history was made with */

    /* coarse space (>>coarse): rigid motions of aggregates of frames */
    int agg_count;       /* aggregates (0: block-Jacobi only) */
    int *f_agg;          /* 1 per frame: its aggregate */
    double *coarse;      /* (6 A)^2: A_c = P^T (a_mass M + a_stiff K) P, then its Cholesky factor */
    double *coarse_rhs;  /* 6 A: the coarse right-hand side and solution */
    double *agg_centre;  /* 3 A: the aggregates' mean position at the coarse matrix's build */
    frm_real *coarse_dq; /* 6 per slot of a sample (scratch): a coarse mode's dq on its frames */
    int coarse_ready;    /* the factor matches the last frm__build_precond */
    double precond_mass, precond_stiff; /* a_mass, a_stiff of the last frm__build_precond */
    int coarse_use;      /* the coarse correction serves the solves after the last frm__build_precond */
    int coarse_plain;    /* CG iterations of the last solve without it (-1: none yet) */

    int lin_valid, lin_mode, lin_iterations;
    int lin_predict; /* the next linear solve's iterations, predicted: max(last, previous prediction / 2) (-1: none yet) */
    int lin_definite; /* the linearisation holds the positive-definite part of K (see SOLVERS) */
    frm_stats stats;
    frm_view view; /* the passes' arrays (frm__fill_view, after the layout) */
};

/* >>math ------------------------------------------------------------------------------- */

static int frm__finite(double x) { return x == x && x - x == 0.0; }

static int frm__all_finite(const frm_real *a, size_t count)
{
    size_t i;
    int ok = 1;
    for (i = 0; i < count; i++) ok &= frm__finite((double)a[i]);
    return ok;
}

/* Eigen-decomposition of a symmetric n x n matrix (n <= 6, row-major, destroyed) by cyclic
   Jacobi rotations: eigenvalues in ev, eigenvectors in the columns of V. A fixed order of
   rotations: deterministic. */
static void frm__jacobi(double *A, int n, double *V, double *ev)
{
    int sweep, p, q, k;
    for (p = 0; p < n * n; p++) V[p] = 0;
    for (p = 0; p < n; p++) V[(n + 1) * p] = 1;
    for (sweep = 0; sweep < 60; sweep++) {
        double off = 0, diag = 0;
        for (p = 0; p < n; p++) {
            diag += A[(n + 1) * p] * A[(n + 1) * p];
            for (q = p + 1; q < n; q++) off += A[n * p + q] * A[n * p + q];
        }
        if (!(off > 1e-30 * diag)) break;
        for (p = 0; p < n; p++)
            for (q = p + 1; q < n; q++) {
                double apq = A[n * p + q], theta, t, c, sn;
                if (apq == 0) continue;
                theta = (A[(n + 1) * q] - A[(n + 1) * p]) / (2 * apq);
                t = (theta >= 0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1));
                c = 1 / sqrt(t * t + 1);
                sn = t * c;
                for (k = 0; k < n; k++) { /* A <- J^T A J */
                    double akp = A[n * k + p], akq = A[n * k + q];
                    A[n * k + p] = c * akp - sn * akq;
                    A[n * k + q] = sn * akp + c * akq;
                }
                for (k = 0; k < n; k++) {
                    double apk = A[n * p + k], aqk = A[n * q + k];
                    A[n * p + k] = c * apk - sn * aqk;
                    A[n * q + k] = sn * apk + c * aqk;
                }
                for (k = 0; k < n; k++) {
                    double vkp = V[n * k + p], vkq = V[n * k + q];
                    V[n * k + p] = c * vkp - sn * vkq;
                    V[n * k + q] = sn * vkp + c * vkq;
                }
            }
    }
    for (p = 0; p < n; p++) ev[p] = A[(n + 1) * p];
}

/* The positive part of a symmetric 3x3 (6 values, Voigt 00 11 22 12 02 01): its negative
   eigenvalues set to zero. */
static void frm__positive_part3(double s[6])
{
    double A[9], V[9], ev[3];
    int r, c, k;
    if (s[3] == 0 && s[4] == 0 && s[5] == 0) {
        for (k = 0; k < 3; k++)
            if (s[k] < 0) s[k] = 0;
        return;
    }
    A[0] = s[0], A[4] = s[1], A[8] = s[2];
    A[5] = A[7] = s[3], A[2] = A[6] = s[4], A[1] = A[3] = s[5];
    frm__jacobi(A, 3, V, ev);
    if (ev[0] >= 0 && ev[1] >= 0 && ev[2] >= 0) return;
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) {
            double t = 0;
            for (k = 0; k < 3; k++)
                if (ev[k] > 0) t += V[3 * r + k] * ev[k] * V[3 * c + k];
            A[3 * r + c] = t;
        }
    s[0] = A[0], s[1] = A[4], s[2] = A[8];
    s[3] = 0.5 * (A[5] + A[7]), s[4] = 0.5 * (A[2] + A[6]), s[5] = 0.5 * (A[1] + A[3]);
}

/* Rotation vector (rad) of the rotation taking quaternion a to quaternion b: b = exp(t) a. */
static void frm__quat_delta(const frm_real a[4], const frm_real b[4], frm_real t[3])
{
    frm_real ai[4], d[4];
    double s, angle, f;
    ai[0] = -a[0];
    ai[1] = -a[1];
    ai[2] = -a[2];
    ai[3] = a[3];
    frm_quat_multiply(b, ai, d);
    if (d[3] < 0) {
        d[0] = -d[0];
        d[1] = -d[1];
        d[2] = -d[2];
        d[3] = -d[3];
    }
    s = sqrt((double)d[0] * d[0] + (double)d[1] * d[1] + (double)d[2] * d[2]);
    angle = 2.0 * atan2(s, (double)d[3]);
    f = s > 1e-12 ? angle / s : 2.0;
    t[0] = (frm_real)(f * d[0]);
    t[1] = (frm_real)(f * d[1]);
    t[2] = (frm_real)(f * d[2]);
}

static int frm__quat_valid(const frm_real *q)
{
    double n;
    if (!frm__finite((double)q[0]) || !frm__finite((double)q[1]) || !frm__finite((double)q[2]) ||
        !frm__finite((double)q[3]))
        return 0;
    n = (double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3];
    return fabs(n - 1.0) <= FRM__UNIT_TOL;
}

static void frm__quat_normalized(const frm_real *q, frm_real *out)
{
    double n = sqrt((double)q[0] * q[0] + (double)q[1] * q[1] + (double)q[2] * q[2] + (double)q[3] * q[3]);
    int k;
    for (k = 0; k < 4; k++) out[k] = frm_flush_tiny((frm_real)(q[k] / n)); /* as frm_quat_integrate */
}

/* >>laws -------------------------------------------------------------------------------- */
/* Every constitutive law is one row of frm__laws[], indexed by frm_law. A law reads its
   parameter block (FRM_LAW_PARAMS reals per sample, filled by frm__law_params at creation)
   and, for FRM_LAW_USER, the material's callbacks; it returns through:
     energy        W at F = I + H (J/m^3); 0 or FRM_ERR_INVERTED
     stress        S (6, Voigt), W and the tangent data (cache_size reals) differential reads
     differential  dS for a strain variation dE (6) at the state stress cached
     definite      NULL, or the change of the cached tangent data that keeps the material
                   part of K positive where the law allows it (used by the definite
                   linearisation of the static solve's first iterations, see SOLVERS)
     fast_path     1: the model's loops may evaluate the law by the inlined kernels
                   frm_material_stress / frm_material_dstress (the >>kernels section, shared
                   with a CUDA build), which implement SVK and Neo-Hookean only. A law without
                   the flag always goes through its own functions. The law tests compare
                   the path the model uses (frm__law_stress, frm__law_dstress) with finite
                   differences of each law's `energy`, so a flag set on the wrong law fails.
   frm__law_stress, frm__law_dstress, frm__law_dP, frm__law_tangent_columns (below) and the
   pair-mode K v loop (frm__apply_chunks, which tests the flag before the call to keep the
   old instruction count) are the only readers of fast_path; the model's loops never name
   a law. */

#define FRM__LAW_CACHE_MAX 23 /* the largest cache_size of frm__laws (the invariant laws) */

typedef struct frm__law_ops {
    const char *name;
    int cache_size;
    int (*energy)(const frm_real *params, const frm_user_law *user, const frm_real H[9], frm_real *psi);
    int (*stress)(const frm_real *params, const frm_user_law *user, const frm_real H[9], frm_real S[6], frm_real *psi,
                  frm_real *cache);
    void (*differential)(const frm_real *params, const frm_user_law *user, const frm_real *cache, const frm_real dE[6],
                         frm_real dS[6]);
    void (*definite)(const frm_real *params, frm_real *cache);
    int fast_path;
} frm__law_ops;

/* SVK and Neo-Hookean: the kernels' formulas (frm_material_stress, frm_material_dstress),
   params = (mu, lambda). */
static int frm__svk_stress(const frm_real *p, const frm_user_law *user, const frm_real H[9], frm_real S[6],
                           frm_real *psi, frm_real *cache)
{
    (void)user;
    return frm_material_stress(FRM_LAW_SVK, p[0], p[1], H, S, psi, cache);
}

static void frm__svk_differential(const frm_real *p, const frm_user_law *user, const frm_real *cache,
                                  const frm_real dE[6], frm_real dS[6])
{
    (void)user;
    frm_material_dstress(FRM_LAW_SVK, p[0], p[1], cache, dE, dS);
}

static int frm__nh_stress(const frm_real *p, const frm_user_law *user, const frm_real H[9], frm_real S[6],
                          frm_real *psi, frm_real *cache)
{
    (void)user;
    return frm_material_stress(FRM_LAW_NEO_HOOKEAN, p[0], p[1], H, S, psi, cache);
}

static void frm__nh_differential(const frm_real *p, const frm_user_law *user, const frm_real *cache,
                                 const frm_real dE[6], frm_real dS[6])
{
    (void)user;
    frm_material_dstress(FRM_LAW_NEO_HOOKEAN, p[0], p[1], cache, dE, dS);
}

/* Neo-Hookean's tangent 2 (mu - lambda ln J) C^-1 dE C^-1 kept >= 0: ln J (cache[6]) capped
   at mu / lambda. */
static void frm__nh_definite(const frm_real *p, frm_real *cache)
{
    if (p[1] * cache[6] > p[0]) cache[6] = p[0] / p[1];
}

/* Invariant laws (Mooney-Rivlin, user): W(I1, I2, J) with I1 = tr C, I2 = (I1^2 - tr C^2)/2,
   J = det F. Evaluated in double:
       S  = 2 w_1 I + 2 w_2 (I1 I - C) + J w_J C^-1
       dS = 2 dw_1 I + 2 dw_2 (I1 I - C) + 2 w_2 (dI1 I - 2 dE) + (dJ w_J + J dw_J) C^-1
            - 2 J w_J C^-1 dE C^-1,
   dI1 = 2 tr dE, dI2 = 2 (I1 tr dE - C : dE), dJ = J C^-1 : dE, dw_a = sum_b w_ab dI_b.
   Cache (23): C^-1 (6), C (6), I1, J, w_1, w_2, w_J, w_11, w_12, w_1J, w_22, w_2J, w_JJ.
   Unlike the Neo-Hookean kernel, the stress at small strain is a difference of terms of
   the size of the moduli (2 w_1 + 4 w_2 + J w_J = 0 at rest): relative round-off of the
   stress is eps(double) of the moduli, then rounded to frm_real. */
typedef struct frm__invariants {
    double I1, I2, J, w, d1[3], d2[6]; /* d1: w_1, w_2, w_J; d2: w_11, w_12, w_1J, w_22, w_2J, w_JJ */
} frm__invariants;

/* C (6, Voigt), C^-1 (6), I1, I2, J from H; 0 or FRM_ERR_INVERTED. */
static int frm__invariants_of(const frm_real H[9], double C[6], double Ci[6], frm__invariants *v)
{
    double F[9], J, tr2;
    int r;
    for (r = 0; r < 9; r++) F[r] = (double)H[r] + (r % 4 == 0 ? 1.0 : 0.0);
    C[0] = F[0] * F[0] + F[3] * F[3] + F[6] * F[6];
    C[1] = F[1] * F[1] + F[4] * F[4] + F[7] * F[7];
    C[2] = F[2] * F[2] + F[5] * F[5] + F[8] * F[8];
    C[3] = F[1] * F[2] + F[4] * F[5] + F[7] * F[8];
    C[4] = F[0] * F[2] + F[3] * F[5] + F[6] * F[8];
    C[5] = F[0] * F[1] + F[3] * F[4] + F[6] * F[7];
    J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
    if (!(J > 0)) return FRM_ERR_INVERTED;
    Ci[0] = (C[1] * C[2] - C[3] * C[3]) / (J * J);
    Ci[1] = (C[0] * C[2] - C[4] * C[4]) / (J * J);
    Ci[2] = (C[0] * C[1] - C[5] * C[5]) / (J * J);
    Ci[3] = (C[4] * C[5] - C[0] * C[3]) / (J * J);
    Ci[4] = (C[5] * C[3] - C[1] * C[4]) / (J * J);
    Ci[5] = (C[3] * C[4] - C[2] * C[5]) / (J * J);
    v->I1 = C[0] + C[1] + C[2];
    tr2 = C[0] * C[0] + C[1] * C[1] + C[2] * C[2] + 2 * (C[3] * C[3] + C[4] * C[4] + C[5] * C[5]);
    v->I2 = 0.5 * (v->I1 * v->I1 - tr2);
    v->J = J;
    return 0;
}

/* Mooney-Rivlin (heml.h's HEML_MOONEY_RIVLIN, eqs. 21-25 of the HEML paper), p = (c1, c2,
   kappa): W = c1 (I1 J^-2/3 - 3) + c2 (I2 J^-4/3 - 3) + kappa/2 (J - 1)^2,
       w_1 = c1 J^-2/3, w_2 = c2 J^-4/3, w_J = -2/3 c1 I1 J^-5/3 - 4/3 c2 I2 J^-7/3 + kappa (J - 1),
       w_11 = w_12 = w_22 = 0, w_1J = -2/3 c1 J^-5/3, w_2J = -4/3 c2 J^-7/3,
       w_JJ = 10/9 c1 I1 J^-8/3 + 28/9 c2 I2 J^-10/3 + kappa. */
static void frm__mr_derivatives(const frm_real *p, frm__invariants *v, int order)
{
    double c1 = (double)p[0], c2 = (double)p[1], kappa = (double)p[2], J = v->J;
    double a = pow(J, -2.0 / 3.0), b = a * a; /* J^-2/3, J^-4/3 */
    v->w = c1 * (v->I1 * a - 3) + c2 * (v->I2 * b - 3) + 0.5 * kappa * (J - 1) * (J - 1);
    if (order < 1) return;
    v->d1[0] = c1 * a;
    v->d1[1] = c2 * b;
    v->d1[2] = (-2.0 / 3.0 * c1 * v->I1 * a - 4.0 / 3.0 * c2 * v->I2 * b) / J + kappa * (J - 1);
    if (order < 2) return;
    v->d2[0] = v->d2[1] = v->d2[3] = 0;
    v->d2[2] = -2.0 / 3.0 * c1 * a / J;
    v->d2[4] = -4.0 / 3.0 * c2 * b / J;
    v->d2[5] = (10.0 / 9.0 * c1 * v->I1 * a + 28.0 / 9.0 * c2 * v->I2 * b) / (J * J) + kappa;
}

/* The user's callbacks at one point: order 0 energy, 1 and first, 2 and second. */
static void frm__user_derivatives(const frm_user_law *u, frm__invariants *v, int order)
{
    frm_real I1 = (frm_real)v->I1, I2 = (frm_real)v->I2, J = (frm_real)v->J, w = 0, d[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    frm_law_points pt;
    int k;
    pt.count = 1;
    pt.I1 = &I1;
    pt.I2 = &I2;
    pt.J = &J;
    pt.w = &w;
    pt.w_1 = d;
    pt.w_2 = d + 1;
    pt.w_J = d + 2;
    pt.w_11 = d + 3;
    pt.w_12 = d + 4;
    pt.w_1J = d + 5;
    pt.w_22 = d + 6;
    pt.w_2J = d + 7;
    pt.w_JJ = d + 8;
    if (u->energy) u->energy(&pt, u->user);
    v->w = (double)w;
    if (order >= 1) u->first(&pt, u->user);
    if (order >= 2) u->second(&pt, u->user);
    for (k = 0; k < 3; k++) v->d1[k] = (double)d[k];
    for (k = 0; k < 6; k++) v->d2[k] = (double)d[3 + k];
}

static void frm__invariant_derivatives(const frm_real *p, const frm_user_law *user, frm__invariants *v, int order)
{
    if (user) frm__user_derivatives(user, v, order);
    else frm__mr_derivatives(p, v, order);
}

static int frm__invariant_energy(const frm_real *p, const frm_user_law *user, const frm_real H[9], frm_real *psi)
{
    double C[6], Ci[6];
    frm__invariants v;
    int e = frm__invariants_of(H, C, Ci, &v);
    if (e) return e;
    frm__invariant_derivatives(p, user, &v, 0);
    *psi = (frm_real)v.w;
    return 0;
}

static int frm__invariant_stress(const frm_real *p, const frm_user_law *user, const frm_real H[9], frm_real S[6],
                                 frm_real *psi, frm_real *cache)
{
    double C[6], Ci[6], a, b, c;
    frm__invariants v;
    int k, e = frm__invariants_of(H, C, Ci, &v);
    if (e) return e;
    frm__invariant_derivatives(p, user, &v, cache ? 2 : 1);
    a = 2 * v.d1[0] + 2 * v.d1[1] * v.I1; /* S = a I - b C + c C^-1 */
    b = 2 * v.d1[1];
    c = v.J * v.d1[2];
    for (k = 0; k < 6; k++) S[k] = (frm_real)((k < 3 ? a : 0.0) - b * C[k] + c * Ci[k]);
    *psi = (frm_real)v.w;
    if (cache) {
        for (k = 0; k < 6; k++) {
            cache[k] = (frm_real)Ci[k];
            cache[6 + k] = (frm_real)C[k];
        }
        cache[12] = (frm_real)v.I1;
        cache[13] = (frm_real)v.J;
        for (k = 0; k < 3; k++) cache[14 + k] = (frm_real)v.d1[k];
        for (k = 0; k < 6; k++) cache[17 + k] = (frm_real)v.d2[k];
    }
    return 0;
}

static void frm__invariant_differential(const frm_real *p, const frm_user_law *user, const frm_real *cache,
                                        const frm_real dE[6], frm_real dS[6])
{
    const frm_real *Ci = cache, *C = cache + 6, *w = cache + 14, *h = cache + 17;
    double I1 = (double)cache[12], J = (double)cache[13], tr = (double)dE[0] + dE[1] + dE[2], CdE = 0, CidE = 0;
    double dI1, dI2, dJ, dw1, dw2, dwJ, x[9], c[9], d[9], t[9], a, b, g, q;
    int k, r;
    (void)p;
    (void)user;
    for (k = 0; k < 6; k++) {
        double f = k < 3 ? 1.0 : 2.0;
        CdE += f * (double)C[k] * (double)dE[k];
        CidE += f * (double)Ci[k] * (double)dE[k];
    }
    dI1 = 2 * tr;
    dI2 = 2 * (I1 * tr - CdE);
    dJ = J * CidE;
    dw1 = (double)h[0] * dI1 + (double)h[1] * dI2 + (double)h[2] * dJ;
    dw2 = (double)h[1] * dI1 + (double)h[3] * dI2 + (double)h[4] * dJ;
    dwJ = (double)h[2] * dI1 + (double)h[4] * dI2 + (double)h[5] * dJ;
    /* x = C^-1 dE C^-1 */
    c[0] = Ci[0], c[4] = Ci[1], c[8] = Ci[2], c[5] = c[7] = Ci[3], c[2] = c[6] = Ci[4], c[1] = c[3] = Ci[5];
    d[0] = dE[0], d[4] = dE[1], d[8] = dE[2], d[5] = d[7] = dE[3], d[2] = d[6] = dE[4], d[1] = d[3] = dE[5];
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) t[3 * r + k] = d[3 * r] * c[k] + d[3 * r + 1] * c[3 + k] + d[3 * r + 2] * c[6 + k];
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) x[3 * r + k] = c[3 * r] * t[k] + c[3 * r + 1] * t[3 + k] + c[3 * r + 2] * t[6 + k];
    a = 2 * dw1 + 2 * dw2 * I1 + 2 * (double)w[1] * dI1; /* dS = a I - g C - 4 w_2 dE + q C^-1 - b x */
    g = 2 * dw2;
    q = dJ * (double)w[2] + J * dwJ;
    b = 2 * J * (double)w[2];
    dS[0] = (frm_real)(a - g * C[0] - 4 * (double)w[1] * dE[0] + q * Ci[0] - b * x[0]);
    dS[1] = (frm_real)(a - g * C[1] - 4 * (double)w[1] * dE[1] + q * Ci[1] - b * x[4]);
    dS[2] = (frm_real)(a - g * C[2] - 4 * (double)w[1] * dE[2] + q * Ci[2] - b * x[8]);
    dS[3] = (frm_real)(-g * C[3] - 4 * (double)w[1] * dE[3] + q * Ci[3] - b * 0.5 * (x[5] + x[7]));
    dS[4] = (frm_real)(-g * C[4] - 4 * (double)w[1] * dE[4] + q * Ci[4] - b * 0.5 * (x[2] + x[6]));
    dS[5] = (frm_real)(-g * C[5] - 4 * (double)w[1] * dE[5] + q * Ci[5] - b * 0.5 * (x[1] + x[3]));
}

/* The energy of the built-in kernels alone (the stress discarded). */
static int frm__svk_energy(const frm_real *p, const frm_user_law *user, const frm_real H[9], frm_real *psi)
{
    frm_real S[6];
    (void)user;
    return frm_material_stress(FRM_LAW_SVK, p[0], p[1], H, S, psi, NULL);
}

/* Neo-Hookean's energy written out on its own (not through the kernel), so that the law
   tests check the kernel's stress against an independent energy:
   W = mu (tr E - ln J) + lambda/2 ln^2 J, tr E = (I1 - 3)/2. */
static int frm__nh_energy(const frm_real *p, const frm_user_law *user, const frm_real H[9], frm_real *psi)
{
    double C[6], Ci[6], lnJ;
    frm__invariants v;
    int e = frm__invariants_of(H, C, Ci, &v);
    (void)user;
    if (e) return e;
    lnJ = log(v.J);
    *psi = (frm_real)((double)p[0] * (0.5 * (v.I1 - 3) - lnJ) + 0.5 * (double)p[1] * lnJ * lnJ);
    return 0;
}

static const frm__law_ops frm__laws[FRM_LAW_COUNT] = {
    /* name, cache_size, energy, stress, differential, definite, fast_path */
    {"St Venant-Kirchhoff", 0, frm__svk_energy, frm__svk_stress, frm__svk_differential, NULL, 1},
    {"Neo-Hookean", FRM_LAW_CACHE, frm__nh_energy, frm__nh_stress, frm__nh_differential, frm__nh_definite, 1},
    {"Mooney-Rivlin", FRM__LAW_CACHE_MAX, frm__invariant_energy, frm__invariant_stress, frm__invariant_differential,
     NULL, 0},
    {"user", FRM__LAW_CACHE_MAX, frm__invariant_energy, frm__invariant_stress, frm__invariant_differential, NULL, 0}};

/* One entry per law, no more, no less (negative array size otherwise). */
typedef char frm__laws_cover_every_law[(sizeof frm__laws / sizeof frm__laws[0] == FRM_LAW_COUNT) ? 1 : -1];

/* The model's path: the inlined kernels for a law with fast_path, its own functions
   otherwise. user is the material's callbacks for FRM_LAW_USER, NULL for the others. */
static inline int frm__law_stress(int law, const frm_real *params, const frm_user_law *user, const frm_real H[9],
                                  frm_real S[6], frm_real *psi, frm_real *cache)
{
    if (frm__laws[law].fast_path) return frm_material_stress(law, params[0], params[1], H, S, psi, cache);
    return frm__laws[law].stress(params, user, H, S, psi, cache);
}

static inline void frm__law_dstress(int law, const frm_real *params, const frm_user_law *user, const frm_real *cache,
                                    const frm_real dE[6], frm_real dS[6])
{
    if (frm__laws[law].fast_path) frm_material_dstress(law, params[0], params[1], cache, dE, dS);
    else frm__laws[law].differential(params, user, cache, dE, dS);
}

/* dP = dF S + F dS, dS = dS/dE : sym(F^T dF): frm_sample_dP for a fast_path law,
   otherwise the same steps with the law's differential. */
static inline void frm__law_dP(int law, const frm_real *params, const frm_user_law *user, const frm_real *cache,
                               const frm_real F[9], const frm_real S[6], const frm_real dF[9], frm_real dP[9])
{
    frm_real dE[6], dS[6];
    if (frm__laws[law].fast_path) {
        frm_sample_dP(law, params[0], params[1], cache, F, S, dF, dP);
        return;
    }
    frm_strain_variation(F, dF, dE);
    frm__laws[law].differential(params, user, cache, dE, dS);
    frm_piola_variation(F, S, dF, dS, dP);
}

/* The 6 tangent columns of one pair (frm_pair_tangent_columns through the law table). */
static void frm__law_tangent_columns(int law, const frm_real *params, const frm_user_law *user, const frm_real *cache,
                                     const frm_real F[9], const frm_real S[6], const frm_real grad[3],
                                     const frm_real G[9], frm_real cols[54])
{
    int c, k;
    if (frm__laws[law].fast_path) {
        frm_pair_tangent_columns(law, params[0], params[1], cache, F, S, grad, G, cols);
        return;
    }
    for (c = 0; c < 6; c++) {
        frm_real dq[6] = {0, 0, 0, 0, 0, 0}, dF[9];
        for (k = 0; k < 9; k++) dF[k] = 0;
        dq[c] = 1;
        frm_pair_dF(dq, grad, G, dF);
        frm__law_dP(law, params, user, cache, F, S, dF, cols + 9 * c);
    }
}

/* A material's parameter block (FRM_LAW_PARAMS reals) and its small-strain shear modulus
   (which scales the rotation stabilisation and the frame coupling). */
static void frm__law_params(const frm_material *mat, frm_real *params, frm_real *shear_modulus)
{
    double E = (double)mat->young_modulus, nu = (double)mat->poisson_ratio;
    int k;
    for (k = 0; k < FRM_LAW_PARAMS; k++) params[k] = 0;
    if (mat->law == FRM_LAW_MOONEY_RIVLIN) {
        params[0] = mat->c1;
        params[1] = mat->c2;
        params[2] = mat->bulk_modulus;
        *shear_modulus = (frm_real)(2.0 * ((double)mat->c1 + (double)mat->c2));
        return;
    }
    params[0] = (frm_real)(E / (2.0 * (1.0 + nu)));
    params[1] = (frm_real)(E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)));
    *shear_modulus = params[0];
}

/* >>parallel --------------------------------------------------------------------------- */

typedef void (*frm__range_fn)(void *ctx, int begin, int end);

/* Runs fn over items [0, count) (chunks fixed by the caller, so the result does not depend
   on how they are spread over threads). */
static void frm__run(const frm_model *m, int count, frm__range_fn fn, void *ctx)
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

/* >>memory ----------------------------------------------------------------------------- */

/* The allocator's alloc, or FRM_MALLOC with the block aligned to FRM__ALIGN by hand (the
   pointer malloc returned is kept just before the aligned block). */
static void *frm__alloc(const frm_allocator *a, size_t size)
{
    char *raw, *p;
    if (a && a->alloc) return a->alloc(size, FRM__ALIGN, a->user);
    raw = (char *)FRM_MALLOC(size + FRM__ALIGN + sizeof(void *), a ? a->user : NULL);
    if (!raw) return NULL;
    p = raw + sizeof(void *);
    p += (FRM__ALIGN - (size_t)p % FRM__ALIGN) % FRM__ALIGN;
    memcpy(p - sizeof(void *), &raw, sizeof(void *));
    return p;
}

static void frm__free(const frm_allocator *a, void *ptr, size_t size)
{
    void *raw;
    if (!ptr) return;
    if (a && a->free) {
        a->free(ptr, size, a->user);
        return;
    }
    memcpy(&raw, (char *)ptr - sizeof(void *), sizeof(void *));
    FRM_FREE(raw, a ? a->user : NULL);
}

/* Carves aligned arrays out of one block; with base NULL it only measures. */
typedef struct frm__carver {
    char *base;
    size_t offset;
} frm__carver;

static void *frm__carve(frm__carver *c, size_t bytes)
{
    void *p;
    c->offset = (c->offset + FRM__ALIGN - 1) & ~(size_t)(FRM__ALIGN - 1);
    p = c->base ? (void *)(c->base + c->offset) : NULL;
    c->offset += bytes ? bytes : 1;
    return p;
}

#define FRM__CARVE(c, ptr, type, count) ((ptr) = (type *)frm__carve((c), sizeof(type) * (size_t)(count)))

static void frm__layout(frm_model *m, frm__carver *c)
{
    size_t n = (size_t)m->frame_count, S = (size_t)m->sample_count, P = (size_t)m->pair_count;
    size_t B = (size_t)m->block_count, sq = (size_t)m->sq_total;
    FRM__CARVE(c, m->disp, frm_real, 3 * n);
    FRM__CARVE(c, m->pos, frm_real, 3 * n);
    FRM__CARVE(c, m->quat, frm_real, 4 * n);
    FRM__CARVE(c, m->vel, frm_real, 6 * n);
    FRM__CARVE(c, m->rest_pos, frm_real, 3 * n);
    FRM__CARVE(c, m->rest_quat, frm_real, 4 * n);
    FRM__CARVE(c, m->rest_rot, frm_real, 9 * n);
    FRM__CARVE(c, m->rot, frm_real, 9 * n);
    FRM__CARVE(c, m->rel, frm_real, 9 * n);
    FRM__CARVE(c, m->relm, frm_real, 9 * n);
    FRM__CARVE(c, m->mass_local, double, 10 * n);
    FRM__CARVE(c, m->grav_local, double, 4 * n);
    FRM__CARVE(c, m->mass_world, frm_real, 10 * n);
    FRM__CARVE(c, m->ext, frm_real, 6 * n);
    FRM__CARVE(c, m->state, unsigned char, n);
    FRM__CARVE(c, m->axes, unsigned char, n);
    FRM__CARVE(c, m->ext_full, frm_real, 6 * n);
    FRM__CARVE(c, m->inc_state, frm_real, 13 * n);
    FRM__CARVE(c, m->drive_start, frm_real, 7 * n);
    FRM__CARVE(c, m->target, frm_real, 7 * n);
    FRM__CARVE(c, m->force, frm_real, 6 * n);
    FRM__CARVE(c, m->force_scale, double, n);
    FRM__CARVE(c, m->lin_torque, frm_real, 3 * n);
    FRM__CARVE(c, m->lin_gravity, frm_real, 3 * n);
    FRM__CARVE(c, m->lin_hrot, frm_real, 6 * n);
    FRM__CARVE(c, m->f_stab, frm_real, 6 * n);
    FRM__CARVE(c, m->f_stab_on, unsigned char, n);
    FRM__CARVE(c, m->kdiag, frm_real, 36 * n);
    FRM__CARVE(c, m->kdiag_rest, frm_real, 36 * n);
    FRM__CARVE(c, m->precond, frm_real, 36 * n);
    FRM__CARVE(c, m->rev_start, int, n + 1);
    FRM__CARVE(c, m->rev_pair, int, P);
    if (m->has_blocks) {
        FRM__CARVE(c, m->blk_start, int, n + 1);
        FRM__CARVE(c, m->blk_col, int, B);
        FRM__CARVE(c, m->blocks, frm_real, 36 * B);
        FRM__CARVE(c, m->sq_start, int, S + 1);
        FRM__CARVE(c, m->pair_blk, int, sq);
    }
    if (m->linear_solver == FRM_LINEAR_SOLVER_BTD) FRM__CARVE(c, m->btd, frm_real, 144 * n);
    FRM__CARVE(c, m->s_rest, frm_real, 3 * S);
    FRM__CARVE(c, m->s_volume, frm_real, S);
    FRM__CARVE(c, m->s_mu, frm_real, S);
    FRM__CARVE(c, m->s_law_params, frm_real, FRM_LAW_PARAMS * S);
    FRM__CARVE(c, m->s_user, const frm_user_law *, S);
    FRM__CARVE(c, m->user_laws, frm_user_law, m->user_law_count);
    FRM__CARVE(c, m->s_couple, frm_real, S);
    FRM__CARVE(c, m->s_hstab, frm_real, S);
    if (m->stab_on) {
        FRM__CARVE(c, m->s_stabY, frm_real, 9 * S);
        FRM__CARVE(c, m->s_stabD, frm_real, S);
    }
    FRM__CARVE(c, m->s_law, unsigned char, S);
    FRM__CARVE(c, m->s_stab, unsigned char, S);
    FRM__CARVE(c, m->s_inverted, unsigned char, S);
    FRM__CARVE(c, m->s_start, int, S + 1);
    FRM__CARVE(c, m->lin_F, frm_real, 9 * S);
    FRM__CARVE(c, m->lin_S, frm_real, 6 * S);
    FRM__CARVE(c, m->lin_cache, frm_real, (size_t)m->law_cache * S);
    FRM__CARVE(c, m->s_pos, frm_real, 3 * S);
    FRM__CARVE(c, m->s_F, frm_real, 9 * S);
    FRM__CARVE(c, m->p_frame, int, P);
    FRM__CARVE(c, m->p_sample, int, P);
    FRM__CARVE(c, m->p_weight, frm_real, P);
    FRM__CARVE(c, m->p_grad, frm_real, 3 * P);
    FRM__CARVE(c, m->p_local, frm_real, 3 * P);
    FRM__CARVE(c, m->p_rlev, frm_real, 3 * P);
    FRM__CARVE(c, m->p_G, frm_real, 9 * P);
    FRM__CARVE(c, m->p_H, frm_real, 6 * P);
    FRM__CARVE(c, m->p_A, frm_real, 3 * P);
    FRM__CARVE(c, m->p_C, frm_real, 3 * P);
    FRM__CARVE(c, m->p_out, frm_real, 6 * P);
    if (m->stab_on) FRM__CARVE(c, m->p_stab, frm_real, 3 * P);
    if (m->vol_mode) {
        size_t E = (size_t)m->vol_entries, G = (size_t)m->vol_groups;
        FRM__CARVE(c, m->ve_start, int, S + 1);
        FRM__CARVE(c, m->ve_group, int, E);
        FRM__CARVE(c, m->ve_sample, int, E);
        FRM__CARVE(c, m->vg_start, int, G + 1);
        FRM__CARVE(c, m->vg_entry, int, E);
        FRM__CARVE(c, m->ve_back, frm_real, E);
        FRM__CARVE(c, m->ve_to, frm_real, E);
        FRM__CARVE(c, m->vg_y, double, G);
        FRM__CARVE(c, m->v_H, frm_real, 9 * S);
        FRM__CARVE(c, m->v_Pbar, frm_real, 9 * S);
        FRM__CARVE(c, m->v_jm1, frm_real, S);
        FRM__CARVE(c, m->v_jbm1, frm_real, S);
        FRM__CARVE(c, m->v_am1, frm_real, S);
        FRM__CARVE(c, m->v_pi, frm_real, S);
        FRM__CARVE(c, m->v_beta, frm_real, S);
        FRM__CARVE(c, m->v_x, frm_real, S);
        FRM__CARVE(c, m->v_y, frm_real, S);
        FRM__CARVE(c, m->vl_Finv, frm_real, 9 * S);
        FRM__CARVE(c, m->vl_Fbar, frm_real, 9 * S);
        FRM__CARVE(c, m->vl_Pbar, frm_real, 9 * S);
        FRM__CARVE(c, m->vl_J, frm_real, S);
        FRM__CARVE(c, m->vl_Jbar, frm_real, S);
        FRM__CARVE(c, m->vl_alpha, frm_real, S);
        FRM__CARVE(c, m->vl_pi, frm_real, S);
        FRM__CARVE(c, m->vl_beta, frm_real, S);
        FRM__CARVE(c, m->vk_dF, frm_real, 9 * S);
        FRM__CARVE(c, m->vk_dPbar, frm_real, 9 * S);
        FRM__CARVE(c, m->vk_e, frm_real, S);
        FRM__CARVE(c, m->vk_ebar, frm_real, S);
        FRM__CARVE(c, m->vk_dpi, frm_real, S);
    }
    FRM__CARVE(c, m->chunk_energy, double, m->sample_chunks);
    FRM__CARVE(c, m->chunk_err, int, m->sample_chunks);
    FRM__CARVE(c, m->cg_r, frm_real, 6 * n);
    FRM__CARVE(c, m->cg_z, frm_real, 6 * n);
    FRM__CARVE(c, m->cg_p, frm_real, 6 * n);
    FRM__CARVE(c, m->cg_q, frm_real, 6 * n);
    FRM__CARVE(c, m->newton_dx, frm_real, 6 * n);
    FRM__CARVE(c, m->newton_rhs, frm_real, 6 * n);
    FRM__CARVE(c, m->total_force, frm_real, 6 * n);
    FRM__CARVE(c, m->work, frm_real, 6 * n);
    FRM__CARVE(c, m->warm_dv, frm_real, 6 * n);
    FRM__CARVE(c, m->drive_dv, frm_real, 6 * n);
    FRM__CARVE(c, m->backup, frm_real, 13 * n);
    FRM__CARVE(c, m->start_state, frm_real, 13 * n);
    FRM__CARVE(c, m->history, frm_real, 13 * n);
    FRM__CARVE(c, m->step_offset, frm_real, 6 * n);
    FRM__CARVE(c, m->step_velocity, frm_real, 6 * n);
    if (m->agg_count) {
        size_t D = FRM__COARSE_MODES * (size_t)m->agg_count;
        FRM__CARVE(c, m->f_agg, int, n);
        FRM__CARVE(c, m->coarse, double, D * D);
        FRM__CARVE(c, m->coarse_rhs, double, D);
        FRM__CARVE(c, m->agg_centre, double, 3 * (size_t)m->agg_count);
        FRM__CARVE(c, m->coarse_dq, frm_real, 6 * FRM_MAX_NEIGHBORS);
    }
}

/* >>coarse (aggregation) ---------------------------------------------------------------- */

/* Bins the frames' rest positions into roughly cubic cells of their bounding box, at most
   min(max_agg, n / FRM_COARSE_MIN_FRAMES) cells; returns the number of non-empty cells (0:
   no coarse space, fewer than 2 aggregates) and, when agg is not NULL, each frame's cell
   renumbered 0.. in cell order. Deterministic: a function of the rest positions only. */
static int frm__aggregate(const frm_real *x, int n, int max_agg, int *agg)
{
    double lo[3], hi[3], ext[3], size, vol = 1.0, big = 0.0;
    int dims[3], i, r, target = n / FRM_COARSE_MIN_FRAMES, cells, count = 0;
    int used[FRM_COARSE_MAX_AGGREGATES];
    if (target > max_agg) target = max_agg;
    if (target < 2) return 0;
    for (r = 0; r < 3; r++) lo[r] = hi[r] = (double)x[r];
    for (i = 0; i < n; i++)
        for (r = 0; r < 3; r++) {
            double v = (double)x[3 * i + r];
            if (v < lo[r]) lo[r] = v;
            if (v > hi[r]) hi[r] = v;
        }
    for (r = 0; r < 3; r++) big = hi[r] - lo[r] > big ? hi[r] - lo[r] : big;
    if (!(big > 0)) return 0;
    for (r = 0; r < 3; r++) { /* a flat or thin body: its thin axes count as 1e-6 of the largest */
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
    for (i = 0; i < cells; i++) used[i] = -1;
    for (i = 0; i < n; i++) {
        int c = 0;
        for (r = 2; r >= 0; r--) {
            int k = (int)(((double)x[3 * i + r] - lo[r]) / ext[r] * dims[r]);
            if (k >= dims[r]) k = dims[r] - 1;
            if (k < 0) k = 0;
            c = c * dims[r] + k;
        }
        if (agg) agg[i] = c;
        used[c] = 0;
    }
    for (i = 0; i < cells; i++)
        if (used[i] == 0) used[i] = count++;
    if (count < 2) return 0;
    if (agg)
        for (i = 0; i < n; i++) agg[i] = used[agg[i]];
    return count;
}

/* >>validation ------------------------------------------------------------------------- */

static int frm__fail(const frm_desc *d, int code, const char *detail)
{
    if (d && d->log) d->log(code, detail, d->log_user);
    return code;
}

static int frm__validate_material(const frm_material *mat, int index, char *msg, size_t size)
{
    if ((unsigned)mat->law >= FRM_LAW_COUNT) {
        snprintf(msg, size, "material %d: unknown law %d", index, (int)mat->law);
        return FRM_ERR_MATERIAL;
    }
    if (mat->law == FRM_LAW_USER && (!mat->user.first || !mat->user.second)) {
        snprintf(msg, size, "material %d: a user law needs its first and second callbacks", index);
        return FRM_ERR_MATERIAL;
    }
    if (mat->law == FRM_LAW_MOONEY_RIVLIN) {
        if (!(frm__finite((double)mat->c1) && frm__finite((double)mat->c2) && mat->c1 >= 0 && mat->c2 >= 0 &&
              mat->c1 + mat->c2 > 0)) {
            snprintf(msg, size, "material %d: Mooney-Rivlin c1 %g, c2 %g", index, (double)mat->c1, (double)mat->c2);
            return FRM_ERR_MATERIAL;
        }
        if (!(frm__finite((double)mat->bulk_modulus) && mat->bulk_modulus > 0)) {
            snprintf(msg, size, "material %d: bulk modulus %g", index, (double)mat->bulk_modulus);
            return FRM_ERR_MATERIAL;
        }
    }
    if (mat->law != FRM_LAW_MOONEY_RIVLIN && !(frm__finite((double)mat->young_modulus) && mat->young_modulus > 0)) {
        snprintf(msg, size, "material %d: Young's modulus %g", index, (double)mat->young_modulus);
        return FRM_ERR_YOUNG_MODULUS;
    }
    if (mat->law != FRM_LAW_MOONEY_RIVLIN &&
        !(frm__finite((double)mat->poisson_ratio) && mat->poisson_ratio > -1 && mat->poisson_ratio < 0.5)) {
        snprintf(msg, size, "material %d: Poisson ratio %g", index, (double)mat->poisson_ratio);
        return FRM_ERR_POISSON_RATIO;
    }
    if (!(frm__finite((double)mat->density) && mat->density > 0)) {
        snprintf(msg, size, "material %d: density %g", index, (double)mat->density);
        return FRM_ERR_DENSITY;
    }
    return FRM_OK;
}

static int frm__validate_settings(const frm_desc *d)
{
    int i;
    for (i = 0; i < 3; i++)
        if (!frm__finite((double)d->gravity[i])) return frm__fail(d, FRM_ERR_ARG, "gravity");
    if (!(frm__finite((double)d->time_step) && d->time_step > 0))
        return frm__fail(d, FRM_ERR_TIME_STEP, "time_step");
    if (!(frm__finite((double)d->mass_damping) && d->mass_damping >= 0) ||
        !(frm__finite((double)d->stiffness_damping) && d->stiffness_damping >= 0))
        return frm__fail(d, FRM_ERR_DAMPING, "damping");
    if (!(frm__finite((double)d->cg_tolerance) && d->cg_tolerance > 0) || d->cg_max_iterations < 1 ||
        !(frm__finite((double)d->newton_tolerance) && d->newton_tolerance > 0) || d->newton_max_iterations < 1 ||
        !(frm__finite((double)d->static_regularization) && d->static_regularization >= 0) || d->max_increments < 1 ||
        !(frm__finite((double)d->min_increment) && d->min_increment > 0 && d->min_increment <= 1) ||
        !(frm__finite((double)d->precision_limit) && d->precision_limit >= 0) || d->implicit_linearized < 0 ||
        d->implicit_linearized > 1)
        return frm__fail(d, FRM_ERR_SOLVER, "solver tolerances, caps and regularization");
    if ((unsigned)d->integrator >= FRM_INTEGRATOR_COUNT) return frm__fail(d, FRM_ERR_SOLVER, "integrator");
    if ((int)d->linear_solver < (int)FRM_LINEAR_SOLVER_AUTO || (int)d->linear_solver >= (int)FRM_LINEAR_SOLVER_COUNT)
        return frm__fail(d, FRM_ERR_SOLVER, "linear_solver");
    if (!(frm__finite((double)d->frame_coupling) && d->frame_coupling >= 0))
        return frm__fail(d, FRM_ERR_ARG, "frame_coupling must be finite and >= 0");
    if (!(frm__finite((double)d->rotation_stabilization) && d->rotation_stabilization >= 0))
        return frm__fail(d, FRM_ERR_ARG, "rotation_stabilization must be finite and >= 0");
    if (!(frm__finite((double)d->rotation_divergence) && d->rotation_divergence >= 0))
        return frm__fail(d, FRM_ERR_ARG, "rotation_divergence must be finite and >= 0");
    if ((int)d->stiffness_mode < 0 || (int)d->stiffness_mode > 2)
        return frm__fail(d, FRM_ERR_STIFFNESS_MODE, "stiffness_mode");
    if (d->coarse_aggregates < 0 || d->coarse_aggregates > FRM_COARSE_MAX_AGGREGATES)
        return frm__fail(d, FRM_ERR_SOLVER, "coarse_aggregates must be 0 to FRM_COARSE_MAX_AGGREGATES");
    if ((unsigned)d->volumetric >= FRM_VOLUMETRIC_COUNT) return frm__fail(d, FRM_ERR_VOLUMETRIC, "volumetric");
    if (!(frm__finite((double)d->volumetric_stabilization) && d->volumetric_stabilization >= 0))
        return frm__fail(d, FRM_ERR_VOLUMETRIC, "volumetric_stabilization must be finite and >= 0");
    if (d->volumetric != FRM_VOLUMETRIC_NONE && d->stiffness_mode == FRM_STIFFNESS_BLOCKS)
        return frm__fail(d, FRM_ERR_STIFFNESS_MODE, "volumetric averaging is matrix-free: no assembled blocks");
    if ((d->allocator.alloc == NULL) != (d->allocator.free == NULL))
        return frm__fail(d, FRM_ERR_ARG, "allocator needs both alloc and free");
    return FRM_OK;
}

static int frm__validate_neighbors(const frm_desc *d, int *marker)
{
    char msg[200];
    int s, k;
    if (d->neighbor_start[0] != 0) return frm__fail(d, FRM_ERR_NEIGHBOR_TABLE, "neighbor_start[0] must be 0");
    for (s = 0; s < d->sample_count; s++) {
        int b = d->neighbor_start[s], e = d->neighbor_start[s + 1];
        double wsum = 0, gsum[3] = {0, 0, 0}, gabs = 0;
        if (e < b) {
            snprintf(msg, sizeof msg, "neighbor_start decreases at sample %d", s);
            return frm__fail(d, FRM_ERR_NEIGHBOR_TABLE, msg);
        }
        if (e == b) {
            snprintf(msg, sizeof msg, "sample %d has no neighbour", s);
            return frm__fail(d, FRM_ERR_NO_NEIGHBOR, msg);
        }
        if (e - b > FRM_MAX_NEIGHBORS) {
            snprintf(msg, sizeof msg, "sample %d has %d neighbours (at most %d)", s, e - b, FRM_MAX_NEIGHBORS);
            return frm__fail(d, FRM_ERR_TOO_MANY_NEIGHBORS, msg);
        }
        for (k = b; k < e; k++) {
            int f = d->neighbor_frames[k], c;
            if (f < 0 || f >= d->frame_count || marker[f] == s) {
                snprintf(msg, sizeof msg, "sample %d: neighbour frame %d out of range or repeated", s, f);
                return frm__fail(d, FRM_ERR_NEIGHBOR_TABLE, msg);
            }
            marker[f] = s;
            if (!frm__finite((double)d->neighbor_weights[k])) {
                snprintf(msg, sizeof msg, "sample %d: weight not finite", s);
                return frm__fail(d, FRM_ERR_WEIGHT_NOT_FINITE, msg);
            }
            wsum += d->neighbor_weights[k];
            for (c = 0; c < 3; c++) {
                double g = (double)d->neighbor_gradients[3 * k + c];
                if (!frm__finite(g)) {
                    snprintf(msg, sizeof msg, "sample %d: weight gradient not finite", s);
                    return frm__fail(d, FRM_ERR_WEIGHT_NOT_FINITE, msg);
                }
                gsum[c] += g;
                gabs += fabs(g);
            }
        }
        if (!(fabs(wsum - 1.0) <= FRM__SUM_TOL)) {
            snprintf(msg, sizeof msg, "sample %d: weights sum to %.17g", s, wsum);
            return frm__fail(d, FRM_ERR_WEIGHT_SUM, msg);
        }
        if (!(fabs(gsum[0]) + fabs(gsum[1]) + fabs(gsum[2]) <= FRM__SUM_TOL * gabs)) {
            snprintf(msg, sizeof msg, "sample %d: weight gradients sum to (%g, %g, %g)", s, gsum[0], gsum[1], gsum[2]);
            return frm__fail(d, FRM_ERR_GRADIENT_SUM, msg);
        }
    }
    return FRM_OK;
}

/* A frame's own mass and inertia (J: xx, yy, zz, yz, xz, xy, or NULL): mass 0 with no
   inertia (NULL or zero), or mass > 0 with a positive definite J (Sylvester's criterion with
   room for rounding); all finite. */
static int frm__rigid_valid(double mass, const frm_real *J)
{
    double a, b, c, yz, xz, xy, m2, m3;
    int k, zero = 1;
    if (!frm__finite(mass) || mass < 0) return 0;
    if (J)
        for (k = 0; k < 6; k++) {
            if (!frm__finite((double)J[k])) return 0;
            zero &= J[k] == 0;
        }
    if (mass == 0) return zero;
    if (!J) return 0;
    a = (double)J[0], b = (double)J[1], c = (double)J[2], yz = (double)J[3], xz = (double)J[4], xy = (double)J[5];
    m2 = a * b - xy * xy;
    m3 = a * (b * c - yz * yz) - xy * (xy * c - yz * xz) + xz * (xy * yz - b * xz);
    return a > 0 && m2 > 1e-12 * a * b && m3 > 1e-12 * a * b * c;
}

/* Everything but the frames' masses (checked once they are computed). marker: frame_count
   ints of scratch. */
static int frm__validate(const frm_desc *d, int *marker)
{
    char msg[200];
    int i, s, err;
    for (i = 0; i < d->frame_count; i++) marker[i] = -1;
    for (i = 0; i < 3 * d->frame_count; i++)
        if (!frm__finite((double)d->frame_positions[i])) {
            snprintf(msg, sizeof msg, "position of frame %d is not finite", i / 3);
            return frm__fail(d, FRM_ERR_FRAME_NOT_FINITE, msg);
        }
    if (d->frame_orientations)
        for (i = 0; i < d->frame_count; i++)
            if (!frm__quat_valid(d->frame_orientations + 4 * i)) {
                snprintf(msg, sizeof msg, "orientation of frame %d is not a unit quaternion", i);
                return frm__fail(d, FRM_ERR_QUATERNION, msg);
            }
    for (i = 0; i < d->frame_count && (d->frame_masses || d->frame_inertias); i++) {
        double mass = d->frame_masses ? (double)d->frame_masses[i] : 0;
        const frm_real *J = d->frame_inertias ? d->frame_inertias + 6 * (size_t)i : NULL;
        if (!frm__rigid_valid(mass, J)) {
            snprintf(msg, sizeof msg, "frame %d: own mass %g kg, inertia not positive definite or given without mass", i,
                     mass);
            return frm__fail(d, FRM_ERR_RIGID, msg);
        }
    }
    for (s = 0; s < 3 * d->sample_count; s++)
        if (!frm__finite((double)d->sample_positions[s])) {
            snprintf(msg, sizeof msg, "position of sample %d is not finite", s / 3);
            return frm__fail(d, FRM_ERR_SAMPLE_NOT_FINITE, msg);
        }
    for (s = 0; s < d->sample_count; s++)
        if (!(frm__finite((double)d->sample_volumes[s]) && d->sample_volumes[s] > 0)) {
            snprintf(msg, sizeof msg, "volume %g of sample %d", (double)d->sample_volumes[s], s);
            return frm__fail(d, FRM_ERR_SAMPLE_VOLUME, msg);
        }
    for (s = 0; d->sample_sizes && s < d->sample_count; s++)
        if (!(frm__finite((double)d->sample_sizes[s]) && d->sample_sizes[s] >= 0)) {
            snprintf(msg, sizeof msg, "size %g of sample %d", (double)d->sample_sizes[s], s);
            return frm__fail(d, FRM_ERR_SAMPLE_SIZE, msg);
        }
    err = frm__validate_neighbors(d, marker);
    if (err) return err;
    if (d->volumetric == FRM_VOLUMETRIC_PATCHES &&
        (d->volumetric_patch_size < 0 || d->volumetric_patch_size > FRM_VOLUMETRIC_PATCH_MAX)) {
        snprintf(msg, sizeof msg, "volumetric_patch_size %d not in 0..%d", d->volumetric_patch_size,
                 FRM_VOLUMETRIC_PATCH_MAX);
        return frm__fail(d, FRM_ERR_VOLUMETRIC, msg);
    }
    if (d->volumetric == FRM_VOLUMETRIC_CELLS) {
        if (!d->sample_cells) return frm__fail(d, FRM_ERR_VOLUMETRIC, "FRM_VOLUMETRIC_CELLS needs sample_cells");
        for (s = 0; s < d->sample_count; s++)
            if (d->sample_cells[s] < 0 || d->sample_cells[s] >= 100000000) {
                snprintf(msg, sizeof msg, "sample %d: cell index %d", s, d->sample_cells[s]);
                return frm__fail(d, FRM_ERR_VOLUMETRIC, msg);
            }
    }
    if (!d->materials) {
        err = frm__validate_material(&d->material, 0, msg, sizeof msg);
        if (err) return frm__fail(d, err, msg);
        if (d->sample_materials) return frm__fail(d, FRM_ERR_MATERIAL, "sample_materials needs a materials table");
    } else {
        if (d->material_count < 1) return frm__fail(d, FRM_ERR_MATERIAL, "material_count must be >= 1");
        for (i = 0; i < d->material_count; i++) {
            err = frm__validate_material(d->materials + i, i, msg, sizeof msg);
            if (err) return frm__fail(d, err, msg);
        }
        if (d->sample_materials)
            for (s = 0; s < d->sample_count; s++)
                if (d->sample_materials[s] < 0 || d->sample_materials[s] >= d->material_count) {
                    snprintf(msg, sizeof msg, "sample %d: material index %d", s, d->sample_materials[s]);
                    return frm__fail(d, FRM_ERR_MATERIAL, msg);
                }
    }
    return FRM_OK;
}

/* >>creation --------------------------------------------------------------------------- */

FRMDEF const char *frm_version(void) { return "0.1.0"; }

FRMDEF const char *frm_error_string(int code)
{
    switch (code) {
#define FRM__CASE(name, value, text) \
    case name: return text;
        FRM_ERROR_LIST(FRM__CASE)
#undef FRM__CASE
    default: return "unknown error code";
    }
}

static frm_material frm__default_material(void)
{
    frm_material mat;
    mat.law = FRM_LAW_SVK;
    mat.young_modulus = (frm_real)1e4;
    mat.poisson_ratio = (frm_real)0.3;
    mat.density = (frm_real)1000;
    mat.c1 = mat.c2 = (frm_real)(1e4 / (8 * 1.3)); /* mu / 4 of E = 1e4 Pa, nu = 0.3 */
    mat.bulk_modulus = (frm_real)(1e4 / (3 * 0.4));  /* E / (3 (1 - 2 nu)) */
    mat.user.energy = NULL;
    mat.user.first = NULL;
    mat.user.second = NULL;
    mat.user.user = NULL;
    return mat;
}

FRMDEF frm_desc frm_model_default_desc(void)
{
    frm_desc d;
    memset(&d, 0, sizeof d);
    d.material = frm__default_material();
    d.gravity[2] = (frm_real)-9.81;
    d.time_step = (frm_real)1e-2;
    d.cg_tolerance = (frm_real)(FRM__IS_FLOAT ? 1e-4 : 1e-6);
    d.cg_max_iterations = 1000;
    d.newton_tolerance = (frm_real)(FRM__IS_FLOAT ? 1e-4 : 1e-6);
    d.newton_max_iterations = 30;
    d.integrator = FRM_IMPLICIT_EULER;
    d.implicit_linearized = 0;
    d.linear_solver = FRM_LINEAR_SOLVER_AUTO;
    d.max_increments = 64;
    d.min_increment = (frm_real)1e-4;
    d.precision_limit = (frm_real)1e-4;
    d.static_regularization = (frm_real)1e-10;
    d.frame_coupling = 0;
    d.rotation_stabilization = (frm_real)0.5;
    d.rotation_divergence = (frm_real)4;
    d.volumetric_stabilization = 2;
    d.stiffness_mode = FRM_STIFFNESS_AUTO;
    d.coarse_aggregates = FRM_COARSE_AGGREGATES;
    d.parallel_min_pairs = FRM_PARALLEL_MIN_PAIRS;
    d.internal_cookie = FRM__COOKIE;
    return d;
}

/* Sorts a short int array (a row of the block pattern). */
static void frm__sort_ints(int *a, int n)
{
    int i, j;
    for (i = 1; i < n; i++) {
        int v = a[i];
        for (j = i - 1; j >= 0 && a[j] > v; j--) a[j + 1] = a[j];
        a[j + 1] = v;
    }
}

/* Builds the reverse table (frame -> pairs in increasing pair order) in rev_start/rev_pair
   and the pair -> sample map. */
static void frm__build_reverse(int n, int S, const int *start, const int *frames, int *rev_start, int *rev_pair,
                               int *pair_sample, int *cursor)
{
    int i, s, p;
    memset(rev_start, 0, sizeof(int) * ((size_t)n + 1));
    for (s = 0; s < S; s++)
        for (p = start[s]; p < start[s + 1]; p++) {
            rev_start[frames[p] + 1]++;
            pair_sample[p] = s;
        }
    for (i = 0; i < n; i++) rev_start[i + 1] += rev_start[i];
    for (i = 0; i < n; i++) cursor[i] = rev_start[i];
    for (p = 0; p < start[S]; p++) rev_pair[cursor[frames[p]]++] = p;
}

/* FRM_VOLUMETRIC_PATCHES: groups the samples into patches from the neighbour table alone
   (MODEL, volumetric averaging), serially and deterministically; writes each sample's patch
   into patch[S] and returns the patch count. A patch grows from a seed by the unassigned
   sample that shares the most frames with it (a tetrahedron's face neighbour before its
   edge and vertex neighbours; ties to the lower index), among the samples of the seed's
   material (no averaging across materials), up to target samples; the next seed is the
   finished patch's best candidate left (an advancing front, so the numbering of the
   samples matters little), else the first unassigned sample. Patches smaller than half
   the target then give each sample to the patch of its neighbour sharing the most frames
   among the full enough patches. in: n ints, cand, score, stamp, size: S ints of scratch. Cost:
   O(pairs x frame star) once. */
static int frm__volumetric_patches(const frm_desc *d, const int *rev_start, const int *rev_pair, const int *pair_sample,
                                   int *in, int *patch, int *cand, int *score, int *stamp, int *size)
{
    const int *start = d->neighbor_start, *fr = d->neighbor_frames, *mat = d->materials ? d->sample_materials : NULL;
    int S = d->sample_count, n = d->frame_count, s, c, p, r, g, count = 0, low = 0, seed = -1, k, nc, small;
    int target = d->volumetric_patch_size > 0 ? d->volumetric_patch_size : FRM_VOLUMETRIC_PATCH_SIZE;
    int members[FRM_VOLUMETRIC_PATCH_MAX];
    for (s = 0; s < S; s++) patch[s] = -1, stamp[s] = -1;
    for (s = 0; s < n; s++) in[s] = 0;
    for (;;) {
        int best = -1;
        if (seed < 0) {
            while (low < S && patch[low] >= 0) low++;
            if (low == S) break;
            seed = low;
        }
        k = 0, nc = 0;
        for (;;) { /* add seed, then the best candidate, until the target or no candidate */
            members[k++] = seed;
            patch[seed] = count;
            for (p = start[seed]; p < start[seed + 1]; p++)
                if (in[fr[p]]++ == 0)
                    for (r = rev_start[fr[p]]; r < rev_start[fr[p] + 1]; r++) {
                        c = pair_sample[rev_pair[r]];
                        if (patch[c] >= 0 || (mat && mat[c] != mat[members[0]])) continue;
                        if (stamp[c] != count) stamp[c] = count, score[c] = 0, cand[nc++] = c;
                        score[c]++; /* c's frames the patch touches (frames in a row are distinct) */
                    }
            best = -1;
            for (c = 0; c < nc; c++) {
                int q = cand[c];
                if (patch[q] < 0 && (best < 0 || score[q] > score[best] || (score[q] == score[best] && q < best))) best = q;
            }
            if (best < 0 || k == target) break;
            seed = best;
        }
        for (c = 0; c < k; c++)
            for (p = start[members[c]]; p < start[members[c] + 1]; p++) in[fr[p]] = 0;
        size[count++] = k;
        seed = best;
    }
    small = (target + 1) / 2;
    for (g = 0; g < count; g++) cand[g] = size[g] >= small; /* full enough */
    for (s = 0; s < S; s++) {
        int best = -1, most = 0, q;
        g = patch[s];
        if (cand[g]) continue;
        for (p = start[s]; p < start[s + 1]; p++)
            for (r = rev_start[fr[p]]; r < rev_start[fr[p] + 1]; r++) {
                c = pair_sample[rev_pair[r]];
                if (patch[c] == g || !cand[patch[c]] || (mat && mat[c] != mat[s])) continue;
                /* the frames c shares with s (rows are short) */
                for (q = 0, k = start[c]; k < start[c + 1]; k++) {
                    int e;
                    for (e = start[s]; e < start[s + 1]; e++) q += fr[e] == fr[k];
                }
                if (q > most || (q == most && best >= 0 && patch[c] < patch[best])) most = q, best = c;
            }
        if (best >= 0) patch[s] = patch[best];
    }
    /* renumber the patches left non-empty in order of first appearance */
    for (g = 0; g < count; g++) cand[g] = -1;
    for (s = 0, k = 0; s < S; s++) {
        if (cand[patch[s]] < 0) cand[patch[s]] = k++;
        patch[s] = cand[patch[s]];
    }
    return k;
}

/* Counts (cols == NULL) or fills the block pattern: row i holds every frame that shares a
   sample with i, sorted. marker: n ints set to -1. Returns the block count. */
static long long frm__block_pattern(int n, const int *start, const int *frames, const int *rev_start,
                                    const int *rev_pair, const int *pair_sample, int *marker, int *row_start,
                                    int *cols)
{
    long long total = 0;
    int i, e, p;
    for (i = 0; i < n; i++) {
        int count = 0;
        if (row_start) row_start[i] = (int)total;
        for (e = rev_start[i]; e < rev_start[i + 1]; e++) {
            int s = pair_sample[rev_pair[e]];
            for (p = start[s]; p < start[s + 1]; p++) {
                int j = frames[p];
                if (marker[j] == i) continue;
                marker[j] = i;
                if (cols) cols[total + count] = j;
                count++;
            }
        }
        if (cols) frm__sort_ints(cols + total, count);
        total += count;
    }
    if (row_start) row_start[n] = (int)total;
    return total;
}

static int frm__find_block(const frm_model *m, int i, int j)
{
    int lo = m->blk_start[i], hi = m->blk_start[i + 1] - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (m->blk_col[mid] == j) return mid;
        if (m->blk_col[mid] < j) lo = mid + 1;
        else hi = mid - 1;
    }
    return -1;
}

/* Generalized frame masses (see MASS in the manual) and the gravity moments, in double, in
   pair order. Returns the first frame without mass, or -1. */
static int frm__compute_masses(frm_model *m, const frm_desc *d)
{
    int s, p, k, r, c;
    const double pi = 3.14159265358979323846;
    memset(m->mass_local, 0, sizeof(double) * 10 * (size_t)m->frame_count);
    memset(m->grav_local, 0, sizeof(double) * 4 * (size_t)m->frame_count);
    for (s = 0; s < m->sample_count; s++) {
        int b = m->s_start[s], e = m->s_start[s + 1];
        int mi = d->materials ? (d->sample_materials ? d->sample_materials[s] : 0) : -1;
        double rho = mi >= 0 ? (double)d->materials[mi].density : (double)d->material.density;
        double v = (double)d->sample_volumes[s], ms = rho * v, wabs = 0;
        double r2 = pow(3.0 * v / (4.0 * pi), 2.0 / 3.0); /* squared radius of a ball of volume v */
        for (p = b; p < e; p++) wabs += fabs((double)m->p_weight[p]);
        for (p = b; p < e; p++) {
            double *ml = m->mass_local + 10 * (size_t)m->p_frame[p];
            double *gl = m->grav_local + 4 * (size_t)m->p_frame[p];
            double l[3], mu = ms * fabs((double)m->p_weight[p]) / wabs, wg = ms * (double)m->p_weight[p], ll;
            for (k = 0; k < 3; k++) l[k] = (double)m->p_local[3 * p + k];
            ll = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
            ml[0] += mu;
            gl[0] += wg;
            for (k = 0; k < 3; k++) {
                ml[1 + k] += mu * l[k];
                gl[1 + k] += wg * l[k];
            }
            /* Jbar (6, Voigt 00 11 22 12 02 01) += mu (|l|^2 I - l l^T + 2/5 r^2 I) */
            for (r = 0; r < 3; r++) ml[4 + r] += mu * (ll - l[r] * l[r] + 0.4 * r2);
            ml[7] -= mu * l[1] * l[2];
            ml[8] -= mu * l[0] * l[2];
            ml[9] -= mu * l[0] * l[1];
        }
    }
    if (d->frame_masses) /* rigid bodies' own mass at the origin and inertia (issue 14) */
        for (c = 0; c < m->frame_count; c++) {
            double *ml = m->mass_local + 10 * (size_t)c, own = (double)d->frame_masses[c];
            ml[0] += own;
            m->grav_local[4 * (size_t)c] += own;
            if (d->frame_inertias)
                for (k = 0; k < 6; k++) ml[4 + k] += (double)d->frame_inertias[6 * (size_t)c + k];
        }
    for (c = 0; c < m->frame_count; c++)
        if (!(m->mass_local[10 * (size_t)c] > 0)) return c;
    return -1;
}

/* Second moment J = tr(L) I - L of a set of points (L their covariance about the mean),
   accumulated by frm__spread_add relative to a nearby origin o (far from the world origin
   the raw products would cancel) as running mean and centred co-moments (Welford):
   acc[0..2] the mean, acc[3..11] sum (y - mean_old)(y - mean_new)^T, acc[12] the count.
   A rotation dtheta moves some point relative to the others at first order iff
   dtheta . J dtheta > 0. The centred update makes L exactly zero for one point or several
   coincident ones, whatever the compiler contracts: the one-pass form sum(y y^T)/n - mean
   mean^T it replaces cancels to round-off there, and a contracted multiply-add
   (-ffp-contract=fast with FMA, gcc's default outside ISO C mode) keeps the rounding error
   of y y^T, so a frame with a single sample (a tetrahedral mesh's corner frames) got a
   J of noise whose eigenvalue ratios made one random axis, not all three, "unseen"
   (issue: bench R1 tet4 in double, FRM_ERR_UNSTABLE; see SOLVERS, the minimum check). */
static void frm__spread_add(double acc[13], const frm_real *x, const frm_real *o)
{
    double y[3], d[3];
    int r, c;
    acc[12] += 1;
    for (r = 0; r < 3; r++) {
        y[r] = (double)x[r] - (double)o[r];
        d[r] = y[r] - acc[r];
        acc[r] += d[r] / acc[12];
    }
    for (r = 0; r < 3; r++)
        for (c = 0; c < 3; c++) acc[3 + 3 * r + c] += d[r] * (y[c] - acc[c]);
}

static void frm__spread_J(const double acc[13], double J[9])
{
    double L[9], n = acc[12] > 0 ? acc[12] : 1;
    int r, c;
    for (r = 0; r < 3; r++) /* the co-moment sums are symmetric up to round-off: average them */
        for (c = 0; c < 3; c++) L[3 * r + c] = 0.5 * (acc[3 + 3 * r + c] + acc[3 + 3 * c + r]) / n;
    for (r = 0; r < 9; r++) J[r] = -L[r];
    for (r = 0; r < 3; r++) J[4 * r] += L[0] + L[4] + L[8];
}

/* The rotations of frame i its samples do not see at first order (see MODEL, rotation
   stabilisation): a rotation dtheta with the translation -dtheta x a_s leaves every
   sample s's prediction d = x + R lbar where it was iff dtheta x (p_s - p_t) = 0 for all
   its samples: the kernel of their J (collinear samples: the line; a single sample: every
   axis). N (6, Voigt, world rest axes) = sum over J's eigenvectors e of
   phi(lambda_e / lambda_max) (1 - phi(e . J2 e / lambda2_max)) e e^T with
   phi(x) = clamp(1 - x / 1e-2, 0, 1): exact kernels get 1, well-spread samples 0; J2 is
   the same moment over the samples of every frame that shares a sample with i, so that a
   rotation the whole neighbourhood cannot see either (a rod of collinear samples, the
   thesis's fig. 4.11, whose torsion lives in that rotation) is left to the thesis's
   model. Counts every sample that uses a frame (weight or gradient not zero). Returns 1
   if N is not zero. */
static int frm__invisible_rotations(const frm_desc *d, const int *rev_start, const int *rev_pair,
                                    const int *pair_sample, int i, double N[6])
{
    double acc[13], acc2[13], J[9], J2[9], V[9], ev[3], top, top2, ev2[3], A2[9], V2[9];
    int e, r, c, any = 0;
    for (r = 0; r < 6; r++) N[r] = 0;
    memset(acc, 0, sizeof acc);
    memset(acc2, 0, sizeof acc2);
    for (e = rev_start[i]; e < rev_start[i + 1]; e++) {
        int p = rev_pair[e], s = pair_sample[p];
        const frm_real *g = d->neighbor_gradients + 3 * (size_t)p;
        if (d->neighbor_weights[p] == 0 && g[0] == 0 && g[1] == 0 && g[2] == 0) continue;
        frm__spread_add(acc, d->sample_positions + 3 * (size_t)s, d->frame_positions + 3 * (size_t)i);
    }
    if (acc[12] == 0) return 0;
    frm__spread_J(acc, J);
    frm__jacobi(J, 3, V, ev);
    top = ev[0] > ev[1] ? ev[0] : ev[1];
    if (ev[2] > top) top = ev[2];
    for (c = 0; c < 3; c++)
        if (!(top > 0) || ev[c] < 1e-2 * top) any = 1;
    if (!any) return 0;
    any = 0;
    for (e = rev_start[i]; e < rev_start[i + 1]; e++) { /* the neighbourhood's samples */
        int s = pair_sample[rev_pair[e]], q;
        for (q = d->neighbor_start[s]; q < d->neighbor_start[s + 1]; q++) {
            int j = d->neighbor_frames[q], f;
            for (f = rev_start[j]; f < rev_start[j + 1]; f++)
                frm__spread_add(acc2, d->sample_positions + 3 * (size_t)pair_sample[rev_pair[f]], d->frame_positions + 3 * (size_t)i);
        }
    }
    frm__spread_J(acc2, J2);
    memcpy(A2, J2, sizeof A2);
    frm__jacobi(A2, 3, V2, ev2); /* only the largest eigenvalue is needed */
    top2 = ev2[0] > ev2[1] ? ev2[0] : ev2[1];
    if (ev2[2] > top2) top2 = ev2[2];
    for (c = 0; c < 3; c++) {
        double phi = top > 0 ? 1 - ev[c] / (1e-2 * top) : 1, u[3], m2, psi;
        if (phi <= 0) continue;
        if (phi > 1) phi = 1;
        for (r = 0; r < 3; r++) u[r] = V[3 * r + c];
        m2 = 0;
        for (r = 0; r < 3; r++) m2 += u[r] * (J2[3 * r] * u[0] + J2[3 * r + 1] * u[1] + J2[3 * r + 2] * u[2]);
        psi = top2 > 0 ? m2 / (1e-2 * top2) : 0;
        if (psi > 1) psi = 1;
        phi *= psi;
        if (phi <= 0) continue;
        any = 1;
        N[0] += phi * u[0] * u[0];
        N[1] += phi * u[1] * u[1];
        N[2] += phi * u[2] * u[2];
        N[3] += phi * u[1] * u[2];
        N[4] += phi * u[0] * u[2];
        N[5] += phi * u[0] * u[1];
    }
    return any;
}

static void frm__update_frames(frm_model *m);
static void frm__rest_diagonal(frm_model *m);

/* Creation reads top to bottom: validate the description, size the model (temporary
   frame -> pair tables, block pattern and stabilisation counts), lay out its one block of
   memory, precompute what the rest state determines. */

/* The temporary tables of creation, one allocation: marker[n], cursor[n], rev_start[n+1],
   rev_pair[P], pair_sample[P]. */
typedef struct frm__create_tables {
    char *block;
    size_t bytes;
    int *marker, *cursor, *rev_start, *rev_pair, *pair_sample;
    int *patch; /* FRM_VOLUMETRIC_PATCHES: each sample's patch (and 4 S ints of scratch after it) */
} frm__create_tables;

/* Stage 1: every check of the description (counts, settings, materials, neighbour table). */
static int frm__create_validate(const frm_desc *d)
{
    frm_allocator alloc;
    size_t bytes;
    char *block;
    int err;
    /* not made by frm_model_default_desc: every field, the log callback included, may be
       garbage, so refuse without calling it */
    if (d->internal_cookie != FRM__COOKIE) return FRM_ERR_DESC;
    if (d->frame_count < 1 || d->frame_count > 100000000 || !d->frame_positions)
        return frm__fail(d, FRM_ERR_FRAME_COUNT, "frame_count must be >= 1 with positions");
    if (d->sample_count < 1 || d->sample_count > 100000000 || !d->sample_positions || !d->sample_volumes)
        return frm__fail(d, FRM_ERR_SAMPLE_COUNT, "sample_count must be >= 1 with positions and volumes");
    if (!d->neighbor_start || !d->neighbor_frames || !d->neighbor_weights || !d->neighbor_gradients)
        return frm__fail(d, FRM_ERR_NEIGHBOR_TABLE, "the four neighbour arrays are required");
    err = frm__validate_settings(d);
    if (err) return err;
    alloc = d->allocator;
    bytes = sizeof(int) * (size_t)d->frame_count;
    block = (char *)frm__alloc(&alloc, bytes);
    if (!block) return frm__fail(d, FRM_ERR_ALLOC, "temporary tables");
    err = frm__validate(d, (int *)block);
    frm__free(&alloc, block, bytes);
    return err;
}

static void frm__create_free_tables(const frm_desc *d, frm__create_tables *t)
{
    frm_allocator alloc = d->allocator;
    frm__free(&alloc, t->block, t->bytes);
    t->block = NULL;
}

/* Stage 2: the temporary tables and every count the layout needs, into *tmp. */
static int frm__create_size(const frm_desc *d, frm_model *tmp, frm__create_tables *t)
{
    frm_allocator alloc = d->allocator;
    int n = d->frame_count, S = d->sample_count, P = d->neighbor_start[S], i, s;
    t->bytes = sizeof(int) * (3 * (size_t)n + 1 + 2 * (size_t)P +
                              (d->volumetric == FRM_VOLUMETRIC_PATCHES ? 5 * (size_t)S : 0));
    t->block = (char *)frm__alloc(&alloc, t->bytes);
    if (!t->block) return frm__fail(d, FRM_ERR_ALLOC, "temporary tables");
    t->marker = (int *)t->block;
    t->cursor = t->marker + n;
    t->rev_start = t->cursor + n;
    t->rev_pair = t->rev_start + n + 1;
    t->pair_sample = t->rev_pair + P;
    frm__build_reverse(n, S, d->neighbor_start, d->neighbor_frames, t->rev_start, t->rev_pair, t->pair_sample,
                       t->cursor);

    memset(tmp, 0, sizeof *tmp);
    tmp->frame_count = n;
    tmp->sample_count = S;
    tmp->pair_count = P;
    tmp->sample_chunks = (S + FRM__SAMPLE_CHUNK - 1) / FRM__SAMPLE_CHUNK;
    tmp->frame_chunks = (n + FRM__FRAME_CHUNK - 1) / FRM__FRAME_CHUNK;
    tmp->vol_mode = (int)d->volumetric;
    tmp->has_blocks = d->stiffness_mode != FRM_STIFFNESS_PAIRS && !tmp->vol_mode;
    if (tmp->vol_mode == FRM_VOLUMETRIC_FRAMES) {
        tmp->vol_groups = n;
        tmp->vol_entries = P;
    } else if (tmp->vol_mode == FRM_VOLUMETRIC_PATCHES) {
        int *pt = t->pair_sample + P;
        t->patch = pt;
        tmp->vol_entries = S;
        tmp->vol_groups = frm__volumetric_patches(d, t->rev_start, t->rev_pair, t->pair_sample, t->cursor, pt,
                                                  pt + S, pt + 2 * (size_t)S, pt + 3 * (size_t)S, pt + 4 * (size_t)S);
    } else if (tmp->vol_mode == FRM_VOLUMETRIC_CELLS) {
        tmp->vol_entries = S;
        for (s = 0; s < S; s++)
            if (d->sample_cells[s] + 1 > tmp->vol_groups) tmp->vol_groups = d->sample_cells[s] + 1;
    }
    /* FRM_LINEAR_SOLVER_BTD carves its blocks; AUTO resolves here: BTD for assembled blocks
       whose pattern (every sample's frames pairwise coupled) is a chain in frame order, in
       double builds (float keeps CG: see BLOCK-TRIDIAGONAL SOLVER) */
    tmp->linear_solver = (int)d->linear_solver;
    if (d->linear_solver == FRM_LINEAR_SOLVER_AUTO) {
        int chain = tmp->has_blocks && !FRM__IS_FLOAT;
        for (s = 0; s < S && chain; s++) {
            int lo = n, hi = -1, e;
            for (e = d->neighbor_start[s]; e < d->neighbor_start[s + 1]; e++) {
                if (d->neighbor_frames[e] < lo) lo = d->neighbor_frames[e];
                if (d->neighbor_frames[e] > hi) hi = d->neighbor_frames[e];
            }
            chain = hi - lo <= 1;
        }
        tmp->linear_solver = chain ? FRM_LINEAR_SOLVER_BTD : FRM_LINEAR_SOLVER_CG;
        tmp->auto_btd = chain;
    }
    if (tmp->has_blocks) {
        long long blocks, sq = 0;
        for (i = 0; i < n; i++) t->marker[i] = -1;
        blocks = frm__block_pattern(n, d->neighbor_start, d->neighbor_frames, t->rev_start, t->rev_pair,
                                    t->pair_sample, t->marker, NULL, NULL);
        for (s = 0; s < S; s++) {
            long long c = d->neighbor_start[s + 1] - d->neighbor_start[s];
            sq += c * c;
        }
        if (blocks > 200000000 || sq > 2000000000) {
            frm__create_free_tables(d, t);
            return frm__fail(d, FRM_ERR_ALLOC, "block pattern too large; use FRM_STIFFNESS_PAIRS");
        }
        tmp->block_count = (int)blocks;
        tmp->sq_total = (int)sq;
    }
    tmp->agg_count = frm__aggregate(d->frame_positions, n, d->coarse_aggregates, NULL);
    tmp->stab_beta = d->rotation_stabilization;
    tmp->stab_gamma = d->rotation_divergence;
    if (tmp->stab_beta > 0)
        for (i = 0; i < n; i++) {
            double N[6];
            tmp->stab_frames += frm__invisible_rotations(d, t->rev_start, t->rev_pair, t->pair_sample, i, N);
        }
    tmp->stab_on = tmp->stab_frames > 0 || tmp->stab_gamma > 0;
    tmp->user_law_count = d->materials ? d->material_count : 1;
    for (s = 0; s < S; s++) {
        const frm_material *mat =
            d->materials ? d->materials + (d->sample_materials ? d->sample_materials[s] : 0) : &d->material;
        if (frm__laws[mat->law].cache_size > tmp->law_cache) tmp->law_cache = frm__laws[mat->law].cache_size;
    }
    return FRM_OK;
}

/* Stage 3: measure, allocate (zeroed) and carve the model's one block; the model struct
   sits at its start. */
static int frm__create_layout(const frm_desc *d, frm_model *tmp, frm_model **out)
{
    frm__carver carver;
    frm_allocator alloc = d->allocator;
    carver.base = NULL;
    carver.offset = sizeof(frm_model);
    frm__layout(tmp, &carver);
    tmp->block_bytes = carver.offset;
    tmp->block = frm__alloc(&alloc, tmp->block_bytes);
    if (!tmp->block) return frm__fail(d, FRM_ERR_ALLOC, "model block");
    memset(tmp->block, 0, tmp->block_bytes);
    carver.base = (char *)tmp->block;
    carver.offset = sizeof(frm_model);
    frm__layout(tmp, &carver);
    *out = (frm_model *)tmp->block;
    **out = *tmp;
    (*out)->allocator = alloc;
    return FRM_OK;
}

/* Stage 4a: the settings the solvers read. */
static void frm__create_settings(frm_model *m, const frm_desc *d)
{
    int k;
    m->parallel_for = d->parallel_for;
    m->parallel_user = d->parallel_user;
    m->parallel = m->pair_count >= d->parallel_min_pairs;
    for (k = 0; k < 3; k++) m->gravity[k] = d->gravity[k];
    m->time_step = d->time_step;
    m->mass_damping = d->mass_damping;
    m->stiffness_damping = d->stiffness_damping;
    m->cg_tolerance = d->cg_tolerance;
    m->cg_max_iterations = d->cg_max_iterations;
    m->newton_tolerance = d->newton_tolerance;
    m->newton_max_iterations = d->newton_max_iterations;
    /* implicit_linearized = 1 is the older spelling of the linearised integrator */
    m->integrator = d->implicit_linearized ? FRM_IMPLICIT_EULER_LINEARIZED : (int)d->integrator;
    m->max_increments = d->max_increments;
    m->min_increment = (double)d->min_increment;
    m->precision_limit = (double)d->precision_limit;
    m->load_scale = 1;
    m->stiffness_mode = d->stiffness_mode;
    m->regularization = (double)d->static_regularization;
    m->vol_eta = d->volumetric_stabilization;
}

/* Stage 4b: frames' rest poses, the reverse table, the frames with unseen rotations. */
static void frm__create_frames(frm_model *m, const frm_desc *d, const frm__create_tables *t)
{
    int n = m->frame_count, P = m->pair_count, i, k;
    memcpy(m->rest_pos, d->frame_positions, sizeof(frm_real) * 3 * (size_t)n);
    memcpy(m->pos, d->frame_positions, sizeof(frm_real) * 3 * (size_t)n);
    for (i = 0; i < n; i++) {
        frm_real *q = m->rest_quat + 4 * i;
        if (d->frame_orientations) frm__quat_normalized(d->frame_orientations + 4 * i, q);
        else q[0] = q[1] = q[2] = 0, q[3] = 1;
        memcpy(m->quat + 4 * i, q, 4 * sizeof(frm_real));
        frm_quat_to_matrix(q, m->rest_rot + 9 * i);
        memcpy(m->target + 7 * i, m->rest_pos + 3 * i, 3 * sizeof(frm_real));
        memcpy(m->target + 7 * i + 3, q, 4 * sizeof(frm_real));
    }
    memcpy(m->rev_start, t->rev_start, sizeof(int) * ((size_t)n + 1));
    memcpy(m->rev_pair, t->rev_pair, sizeof(int) * (size_t)P);
    memcpy(m->p_sample, t->pair_sample, sizeof(int) * (size_t)P);
    if (m->stab_frames) /* beta N: the unseen rotations of frames with collinear samples */
        for (i = 0; i < n; i++) {
            double N[6];
            m->f_stab_on[i] = (unsigned char)frm__invisible_rotations(d, t->rev_start, t->rev_pair, t->pair_sample, i, N);
            for (k = 0; k < 6; k++) m->f_stab[6 * i + k] = (frm_real)(N[k] * (double)m->stab_beta);
            for (k = m->rev_start[i]; m->f_stab_on[i] && k < m->rev_start[i + 1]; k++)
                m->s_stab[t->pair_sample[m->rev_pair[k]]] = 1;
        }
}

/* Stage 4c: samples' rest data and laws (parameter blocks, user callbacks). */
static void frm__create_samples(frm_model *m, const frm_desc *d)
{
    int S = m->sample_count, s;
    memcpy(m->s_rest, d->sample_positions, sizeof(frm_real) * 3 * (size_t)S);
    memcpy(m->s_volume, d->sample_volumes, sizeof(frm_real) * (size_t)S);
    memcpy(m->s_start, d->neighbor_start, sizeof(int) * ((size_t)S + 1));
    for (s = 0; s < S; s++) {
        const frm_material *mat =
            d->materials ? d->materials + (d->sample_materials ? d->sample_materials[s] : 0) : &d->material;
        frm__law_params(mat, m->s_law_params + FRM_LAW_PARAMS * (size_t)s, m->s_mu + s);
        m->s_law[s] = (unsigned char)mat->law;
        m->s_user[s] = NULL;
        if (mat->law == FRM_LAW_USER) {
            int u = d->materials ? (int)(mat - d->materials) : 0;
            m->user_laws[u] = mat->user;
            m->s_user[s] = m->user_laws + u;
        }
    }
}

/* Stage 4d: pairs' weights, gradients and rest levers lbar = Rbar^T (pbar_s - xbar_i)
   (eq. 3.33, in double); per sample the coupling constant, the stabilisation's h^2 and
   the smallest lever h_min. */
static void frm__create_pairs(frm_model *m, const frm_desc *d)
{
    int S = m->sample_count, P = m->pair_count, s, p;
    memcpy(m->p_frame, d->neighbor_frames, sizeof(int) * (size_t)P);
    memcpy(m->p_weight, d->neighbor_weights, sizeof(frm_real) * (size_t)P);
    memcpy(m->p_grad, d->neighbor_gradients, sizeof(frm_real) * 3 * (size_t)P);
    for (p = 0; p < P; p++) {
        int f = m->p_frame[p], sm = m->p_sample[p], r;
        const frm_real *Rb = m->rest_rot + 9 * f;
        double dx[3];
        for (r = 0; r < 3; r++) dx[r] = (double)m->s_rest[3 * sm + r] - (double)m->rest_pos[3 * f + r];
        for (r = 0; r < 3; r++) {
            m->p_local[3 * p + r] = (frm_real)(Rb[r] * dx[0] + Rb[3 + r] * dx[1] + Rb[6 + r] * dx[2]);
            m->p_rlev[3 * p + r] = (frm_real)dx[r];
        }
    }
    m->h_min = HUGE_VAL;
    for (s = 0; s < S; s++) { /* c = eps mu v / h^2, h^2 the mean squared lever */
        double h2 = 0, wsum = 0, lmax = 0;
        for (p = m->s_start[s]; p < m->s_start[s + 1]; p++) {
            double w = fabs((double)m->p_weight[p]);
            const frm_real *l = m->p_local + 3 * p;
            double l2 = (double)l[0] * l[0] + (double)l[1] * l[1] + (double)l[2] * l[2];
            h2 += w * l2;
            wsum += w;
            if (l2 > lmax) lmax = l2;
        }
        if (lmax > 0 && sqrt(lmax) < m->h_min) m->h_min = sqrt(lmax); /* the sample's support size */
        h2 = wsum > 0 ? h2 / wsum : 0;
        if (d->sample_sizes) h2 = (double)d->sample_sizes[s]; /* the parts' own (rigid bodies, issue 14) */
        m->s_couple[s] = (frm_real)(h2 > 0 ? (double)d->frame_coupling * m->s_mu[s] * m->s_volume[s] / h2 : 0.0);
        m->s_hstab[s] = (frm_real)((double)m->stab_gamma * h2);
        if (m->stab_gamma > 0 && d->sample_linear) { /* as the description says (rigid bodies, issue 14) */
            if (d->sample_linear[s]) m->s_stab[s] = 1;
            else m->s_hstab[s] = 0;
        } else if (m->stab_gamma > 0) { /* the divergence term needs weights that reproduce linear fields:
                                    sum_k xbar_k grad w_k^T = I, i.e. sum_k abar_k grad w_k^T = -I */
            double A[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, err = 0;
            int q, r;
            for (p = m->s_start[s]; p < m->s_start[s + 1]; p++)
                for (r = 0; r < 3; r++)
                    for (q = 0; q < 3; q++) A[3 * r + q] += (double)m->p_rlev[3 * p + r] * (double)m->p_grad[3 * p + q];
            for (r = 0; r < 9; r++) err += fabs(A[r]);
            if (err <= 1e-3) m->s_stab[s] = 1;
            else m->s_hstab[s] = 0; /* zero-order (Shepard): left to the thesis's model */
        }
    }
}

/* Stage 4e: the block pattern and the block index of every (pair, other slot of its
   sample). */
static void frm__create_blocks(frm_model *m, int *marker)
{
    int n = m->frame_count, S = m->sample_count, i, s;
    if (!m->has_blocks) return;
    for (i = 0; i < n; i++) marker[i] = -1;
    frm__block_pattern(n, m->s_start, m->p_frame, m->rev_start, m->rev_pair, m->p_sample, marker, m->blk_start,
                       m->blk_col);
    m->sq_start[0] = 0;
    for (s = 0; s < S; s++) {
        int b = m->s_start[s], c = m->s_start[s + 1] - b, a, q;
        m->sq_start[s + 1] = m->sq_start[s] + c * c;
        for (a = 0; a < c; a++)
            for (q = 0; q < c; q++)
                m->pair_blk[m->sq_start[s] + a * c + q] = frm__find_block(m, m->p_frame[b + a], m->p_frame[b + q]);
    }
}

/* Stage 4f: the averaging operator A = B N of the volumetric treatment (see MODEL):
   FRAMES: entries the pairs, groups the frames, back w_si, to v_s w_si / m_i with
   m_i = sum_s v_s w_si; CELLS: one entry a sample, groups the cells, back 1, to v_s / V_c;
   PATCHES: the same with the patches of frm__volumetric_patches (patch[]) as cells.
   All give A 1 = 1 and v^T A = v^T (the patch test). Returns -1, or a frame with
   m_i <= 0 (FRAMES). */
static int frm__create_volumetric(frm_model *m, const frm_desc *d, const int *patch)
{
    int S = m->sample_count, E = m->vol_entries, G = m->vol_groups, s, e, g;
    if (!m->vol_mode) return -1;
    for (g = 0; g <= G; g++) m->vg_start[g] = 0;
    if (m->vol_mode == FRM_VOLUMETRIC_FRAMES) {
        memcpy(m->ve_start, m->s_start, sizeof(int) * ((size_t)S + 1));
        memcpy(m->ve_group, m->p_frame, sizeof(int) * (size_t)E);
        memcpy(m->ve_sample, m->p_sample, sizeof(int) * (size_t)E);
        memcpy(m->ve_back, m->p_weight, sizeof(frm_real) * (size_t)E);
    } else {
        for (s = 0; s <= S; s++) m->ve_start[s] = s;
        for (s = 0; s < S; s++) {
            m->ve_group[s] = m->vol_mode == FRM_VOLUMETRIC_PATCHES ? patch[s] : d->sample_cells[s];
            m->ve_sample[s] = s;
            m->ve_back[s] = 1;
        }
    }
    /* the reverse table (group -> entries in entry order) and the group volumes */
    for (e = 0; e < E; e++) m->vg_start[m->ve_group[e] + 1]++;
    for (g = 0; g < G; g++) m->vg_start[g + 1] += m->vg_start[g];
    for (g = 0; g < G; g++) m->vg_y[g] = 0;
    for (e = 0; e < E; e++) {
        g = m->ve_group[e];
        m->vg_entry[m->vg_start[g] + (int)m->vg_y[g]] = e;
        m->vg_y[g] += 1;
    }
    for (g = 0; g < G; g++) {
        double vol = 0;
        for (e = m->vg_start[g]; e < m->vg_start[g + 1]; e++) {
            int q = m->vg_entry[e];
            vol += (double)m->s_volume[m->ve_sample[q]] * (double)m->ve_back[q];
        }
        if (m->vg_start[g + 1] > m->vg_start[g] && !(vol > 0)) return g;
        for (e = m->vg_start[g]; e < m->vg_start[g + 1]; e++) {
            int q = m->vg_entry[e];
            m->ve_to[q] = (frm_real)((double)m->s_volume[m->ve_sample[q]] * (double)m->ve_back[q] / vol);
        }
    }
    return -1;
}

/* Stage 4: everything the rest state determines; fails only on a frame without mass. */
static int frm__create_precompute(frm_model *m, const frm_desc *d, frm__create_tables *t)
{
    char msg[120];
    int i;
    frm__create_settings(m, d);
    frm__create_frames(m, d, t);
    if (m->agg_count) frm__aggregate(d->frame_positions, m->frame_count, d->coarse_aggregates, m->f_agg);
    frm__create_samples(m, d);
    frm__create_pairs(m, d);
    i = frm__compute_masses(m, d);
    if (i >= 0) {
        snprintf(msg, sizeof msg, "frame %d carries no mass", i);
        return frm__fail(d, FRM_ERR_FRAME_UNUSED, msg);
    }
    i = frm__create_volumetric(m, d, t->patch);
    if (i >= 0) {
        snprintf(msg, sizeof msg, "frame %d: averaging volume sum_s v_s w_s not > 0", i);
        return frm__fail(d, FRM_ERR_VOLUMETRIC, msg);
    }
    frm__create_blocks(m, t->marker);
    m->lin_iterations = -1;
    m->lin_predict = -1;
    m->coarse_plain = -1;
    frm__update_frames(m);
    frm__rest_diagonal(m);
    return FRM_OK;
}

/* The view the passes run on (frm_view): pointers into the block, set once. */
static void frm__fill_view(frm_model *m)
{
    frm_view *w = &m->view;
    w->frame_count = m->frame_count;
    w->sample_count = m->sample_count;
    w->pair_count = m->pair_count;
    w->law_cache = m->law_cache;
    w->disp = m->disp;
    w->rel = m->rel;
    w->relm = m->relm;
    w->f_stab = m->f_stab;
    w->f_stab_on = m->f_stab_on;
    w->rev_start = m->rev_start;
    w->rev_pair = m->rev_pair;
    w->lin_hrot = m->lin_hrot;
    w->s_start = m->s_start;
    w->s_rest = m->s_rest;
    w->s_volume = m->s_volume;
    w->s_couple = m->s_couple;
    w->s_mu = m->s_mu;
    w->s_hstab = m->s_hstab;
    w->s_law = m->s_law;
    w->s_stab = m->s_stab;
    w->s_law_params = m->s_law_params;
    w->s_stabY = m->s_stabY;
    w->s_stabD = m->s_stabD;
    w->lin_F = m->lin_F;
    w->lin_S = m->lin_S;
    w->lin_cache = m->lin_cache;
    w->s_pos = m->s_pos;
    w->p_frame = m->p_frame;
    w->p_weight = m->p_weight;
    w->p_grad = m->p_grad;
    w->p_rlev = m->p_rlev;
    w->p_G = m->p_G;
    w->p_H = m->p_H;
    w->p_A = m->p_A;
    w->p_C = m->p_C;
    w->p_stab = m->p_stab;
    w->p_out = m->p_out;
    w->quat = m->quat;
    w->rest_quat = m->rest_quat;
    w->vel = m->vel;
    w->ext = m->ext;
    w->state = m->state;
    w->axes = m->axes;
    w->mass_local = m->mass_local;
    w->grav_local = m->grav_local;
    w->kdiag_rest = m->kdiag_rest;
    w->volumetric = m->vol_mode;
}

static int frm__btd_model_check(const frm_model *m, const frm_desc *d);
FRMDEF int frm_model_create(const frm_desc *d, frm_model **out)
{
    frm_model tmp, *m = NULL;
    frm__create_tables tables;
    frm_allocator alloc;
    int err;
    if (!out) return FRM_ERR_ARG;
    *out = NULL;
    if (!d) return FRM_ERR_ARG;
    memset(&tables, 0, sizeof tables);
    err = frm__create_validate(d);
    if (err) return err;
    err = frm__create_size(d, &tmp, &tables);
    if (err) return err;
    err = frm__create_layout(d, &tmp, &m);
    if (!err) frm__fill_view(m); /* the precomputation runs passes */
    if (!err) err = frm__create_precompute(m, d, &tables);
    if (!err && m->linear_solver == FRM_LINEAR_SOLVER_BTD) err = frm__btd_model_check(m, d);
    frm__create_free_tables(d, &tables);
    if (err) {
        if (m) {
            alloc = m->allocator;
            frm__free(&alloc, m->block, m->block_bytes);
        }
        return err;
    }
    *out = m;
    return FRM_OK;
}

FRMDEF void frm_model_destroy(frm_model *m)
{
    frm_allocator a;
    if (!m) return;
    a = m->allocator;
    frm__free(&a, m->block, m->block_bytes);
}

/* >>forces ----------------------------------------------------------------------------- */

/* R and Q = R Rbar^T of every frame from its quaternion. */
static void frm__update_frames(frm_model *m)
{
    int i, r;
    for (i = 0; i < m->frame_count; i++) {
        frm_frame_rotations(m->quat + 4 * i, m->rest_quat + 4 * i, m->rot + 9 * i, m->rel + 9 * i, m->relm + 9 * i);
        for (r = 0; r < 3; r++) m->pos[3 * i + r] = m->rest_pos[3 * i + r] + m->disp[3 * i + r];
    }
}

/* World gravity moment c_g = R cbar_g of frame i (frm_pass_gravity_moment). */
static void frm__gravity_moment(const frm_model *m, int i, frm_real c[3])
{
    frm_pass_gravity_moment(m->rot + 9 * i, m->grav_local + 4 * (size_t)i, c);
}

/* The stabilisation's part of K v for sample s (see frm_pass1_stab_force), for the assembly: for the
   sample's dF and each pair's frame rotation dth[k] (NULL: zero), the stress-like sum
   dPx (absolute: divide by the volume) and each pair's frame-own torque row stq (3 n).
   dD = Y : dF / 2 - sum_k dtheta_k . t_k / 2 (+ g_k . domega_k for the general pairs), the
   Gauss-Newton part c g dD Z_k / 2 (stress) and -c g dD t_k / 2 (torque), and unless
   definite the second-order part of T_k = c g D Z_k / 2: [dtheta_k]x T_k and
   -sum_j df_j x t_kj. */
static void frm__stab_sample_apply(const frm_model *m, int s, const frm_real dF[9], const frm_real *const *dth,
                                   int definite, frm_real dPx[9], frm_real *stq)
{
    int b = m->s_start[s], n = m->s_start[s + 1] - b, k, r, i;
    const frm_real *F = m->lin_F + 9 * (size_t)s, *Y = m->s_stabY + 9 * (size_t)s;
    frm_real c = m->s_mu[s] * m->s_volume[s], g = m->s_hstab[s], D = m->s_stabD[s], dD, s1, s2, om[3 * FRM_MAX_NEIGHBORS];
    dD = (frm_real)0.5 * (Y[0] * dF[0] + Y[1] * dF[1] + Y[2] * dF[2] + Y[3] * dF[3] + Y[4] * dF[4] + Y[5] * dF[5] +
                          Y[6] * dF[6] + Y[7] * dF[7] + Y[8] * dF[8]);
    for (k = 0; k < n; k++) {
        const frm_real *t = m->p_stab + 3 * (size_t)(b + k), *gk = m->p_grad + 3 * (size_t)(b + k);
        i = m->p_frame[b + k];
        if (m->f_stab_on[i]) {
            frm_pair_stab_domega(F, dF, m->relm + 9 * i, dth[k], om + 3 * k);
            dD += gk[0] * om[3 * k] + gk[1] * om[3 * k + 1] + gk[2] * om[3 * k + 2];
        } else if (dth[k])
            dD -= (frm_real)0.5 * (dth[k][0] * t[0] + dth[k][1] * t[1] + dth[k][2] * t[2]);
    }
    s1 = (frm_real)0.5 * c * g * dD;
    s2 = (frm_real)0.5 * c * g * D;
    for (r = 0; r < 9; r++) dPx[r] = s1 * Y[r];
    for (k = 0; k < n; k++) {
        const frm_real *t = m->p_stab + 3 * (size_t)(b + k), *gk = m->p_grad + 3 * (size_t)(b + k);
        i = m->p_frame[b + k];
        if (m->f_stab_on[i]) {
            const frm_real *N = m->f_stab + 6 * i, *o = om + 3 * k;
            frm_real u[3], d[9];
            u[0] = N[0] * o[0] + N[5] * o[1] + N[4] * o[2] + g * dD * gk[0];
            u[1] = N[5] * o[0] + N[1] * o[1] + N[3] * o[2] + g * dD * gk[1];
            u[2] = N[4] * o[0] + N[3] * o[1] + N[2] * o[2] + g * dD * gk[2];
            frm_pair_stab_apply(F, dF, m->relm + 9 * i, c, u, t, dth[k], definite, d, stq + 3 * k);
            for (r = 0; r < 9; r++) dPx[r] += d[r];
            continue;
        }
        for (r = 0; r < 3; r++) stq[3 * k + r] = -s1 * t[r];
        if (!definite && s2 != 0) {
            frm_real Z[9], w[3];
            const frm_real *th = dth[k];
            frm_stab_direction(m->relm + 9 * i, gk, Z);
            frm_column_cross_sum(dF, Z, w);
            for (r = 0; r < 3; r++) stq[3 * k + r] -= s2 * w[r];
            if (th)
                for (r = 0; r < 3; r++) { /* dPx += [dtheta]x T_k, column r */
                    dPx[r] += s2 * (th[1] * Z[6 + r] - th[2] * Z[3 + r]);
                    dPx[3 + r] += s2 * (th[2] * Z[r] - th[0] * Z[6 + r]);
                    dPx[6 + r] += s2 * (th[0] * Z[3 + r] - th[1] * Z[r]);
                }
        }
    }
}


/* >>volumetric ------------------------------------------------------------------------- */

/* out = A x (transpose 0) or A^T x (transpose 1) over the samples, A the averaging
   operator of frm__create_volumetric: serial, sums in double in entry order (the same
   result for any thread count; O(entries), small beside the force pass). */
static void frm__vol_average(const frm_model *m, const frm_real *x, frm_real *out, int transpose)
{
    const frm_real *wg = transpose ? m->ve_back : m->ve_to, *ws = transpose ? m->ve_to : m->ve_back;
    int g, e, s;
    for (g = 0; g < m->vol_groups; g++) {
        double y = 0;
        for (e = m->vg_start[g]; e < m->vg_start[g + 1]; e++) {
            int q = m->vg_entry[e];
            y += (double)wg[q] * (double)x[m->ve_sample[q]];
        }
        m->vg_y[g] = y;
    }
    for (s = 0; s < m->sample_count; s++) {
        double o = 0;
        for (e = m->ve_start[s]; e < m->ve_start[s + 1]; e++) o += (double)ws[e] * m->vg_y[m->ve_group[e]];
        out[s] = (frm_real)o;
    }
}

/* F^-1 of F = I + H with J = det F (adjugate / J). */
static void frm__vol_inverse(const frm_real F[9], frm_real J, frm_real Fi[9])
{
    frm_real r = 1 / J;
    Fi[0] = (F[4] * F[8] - F[5] * F[7]) * r;
    Fi[1] = (F[2] * F[7] - F[1] * F[8]) * r;
    Fi[2] = (F[1] * F[5] - F[2] * F[4]) * r;
    Fi[3] = (F[5] * F[6] - F[3] * F[8]) * r;
    Fi[4] = (F[0] * F[8] - F[2] * F[6]) * r;
    Fi[5] = (F[2] * F[3] - F[0] * F[5]) * r;
    Fi[6] = (F[3] * F[7] - F[4] * F[6]) * r;
    Fi[7] = (F[1] * F[6] - F[0] * F[7]) * r;
    Fi[8] = (F[0] * F[4] - F[1] * F[3]) * r;
}

typedef struct frm__vol_ctx {
    frm_model *m;
    int linearize, outputs;
    const frm_real *v; /* K v: the direction */
} frm__vol_ctx;

/* Force stage 1 over sample chunks: H = F - I and J - 1 of every sample (and the outputs). */
static void frm__vol_deform_chunks(void *vctx, int begin, int end)
{
    frm__vol_ctx *ctx = (frm__vol_ctx *)vctx;
    frm_model *m = ctx->m;
    int c;
    for (c = begin; c < end; c++) {
        int s0 = c * FRM__SAMPLE_CHUNK, s1 = s0 + FRM__SAMPLE_CHUNK, s, err = 0;
        if (s1 > m->sample_count) s1 = m->sample_count;
        for (s = s0; s < s1; s++) {
            int b = m->s_start[s], n = m->s_start[s + 1] - b;
            frm_real *H = m->v_H + 9 * (size_t)s;
            frm_sample_deformation(n, m->p_frame + b, m->p_weight + b, m->p_grad + 3 * b, m->p_rlev + 3 * b,
                                   m->s_rest + 3 * s, m->disp, m->relm, H, NULL, NULL,
                                   ctx->outputs ? m->s_pos + 3 * s : NULL);
            m->v_jm1[s] = frm_det_minus_one(H);
            if (ctx->outputs) {
                int r;
                for (r = 0; r < 9; r++) m->s_F[9 * s + r] = H[r] + (r % 4 == 0 ? 1 : 0);
            }
            if (!(1 + m->v_jm1[s] > 0)) err = FRM_ERR_INVERTED;
        }
        m->chunk_err[c] = err;
    }
}

/* Force stage 3 over sample chunks: the law at F_bar = alpha F (H_bar = alpha H +
   (alpha - 1) I), P_bar = F_bar S_bar, pi = P_bar : F_bar / 3, the energy; with linearize
   the law's data at F_bar (lin_S, lin_cache; made definite for linearize = 2). */
static void frm__vol_stress_chunks(void *vctx, int begin, int end)
{
    frm__vol_ctx *ctx = (frm__vol_ctx *)vctx;
    frm_model *m = ctx->m;
    int c;
    for (c = begin; c < end; c++) {
        int s0 = c * FRM__SAMPLE_CHUNK, s1 = s0 + FRM__SAMPLE_CHUNK, s, err = 0;
        double energy = 0;
        if (s1 > m->sample_count) s1 = m->sample_count;
        for (s = s0; s < s1; s++) {
            const frm_real *H = m->v_H + 9 * (size_t)s, *prm = m->s_law_params + FRM_LAW_PARAMS * (size_t)s;
            frm_real Hb[9], Fb[9], S[6], psi, cache[FRM__LAW_CACHE_MAX], *P = m->v_Pbar + 9 * (size_t)s, am1 = m->v_am1[s];
            int r, e;
            for (r = 0; r < 9; r++) Hb[r] = H[r] + am1 * H[r] + (r % 4 == 0 ? am1 : 0);
            e = frm__law_stress(m->s_law[s], prm, m->s_user[s], Hb, S, &psi, cache);
            if (e) {
                err = e;
                continue;
            }
            for (r = 0; r < 9; r++) Fb[r] = Hb[r] + (r % 4 == 0 ? 1 : 0);
            frm_first_piola(Fb, S, P);
            {
                /* pi~ = P_bar : F_bar / 3 + c phi, the stabilisation c phi^2 / 2 with phi = ln(J_bar / J) */
                frm_real cst = m->vol_eta * m->s_mu[s], phi = 3 * (frm_real)log1p((double)am1);
                m->v_pi[s] = (P[0] * Fb[0] + P[1] * Fb[1] + P[2] * Fb[2] + P[3] * Fb[3] + P[4] * Fb[4] + P[5] * Fb[5] +
                              P[6] * Fb[6] + P[7] * Fb[7] + P[8] * Fb[8]) / 3 + cst * phi;
                energy += (double)m->s_volume[s] * ((double)psi + 0.5 * (double)cst * (double)phi * (double)phi);
            }
            if (ctx->linearize) {
                memcpy(m->vl_Fbar + 9 * (size_t)s, Fb, sizeof Fb);
                if (ctx->linearize == 2) {
                    double Sd[6];
                    for (r = 0; r < 6; r++) Sd[r] = (double)S[r];
                    frm__positive_part3(Sd);
                    for (r = 0; r < 6; r++) S[r] = (frm_real)Sd[r];
                    if (frm__laws[m->s_law[s]].definite) frm__laws[m->s_law[s]].definite(prm, cache);
                }
                memcpy(m->lin_S + 6 * (size_t)s, S, sizeof S);
                memcpy(m->lin_cache + (size_t)m->law_cache * s, cache, sizeof(frm_real) * (size_t)m->law_cache);
            }
        }
        m->chunk_energy[c] = energy;
        m->chunk_err[c] = err;
    }
}

static void frm__force_chunks(void *vctx, int begin, int end);

/* The volumetric force pass, stages 1 to 4 (stage 5 is frm__force_chunks with vol on):
   J per sample, J_bar = A J, alpha = (J_bar / J)^(1/3), the law at F_bar, and
   beta_t = (A^T (v pi / J_bar))_t J_t / v_t - pi_t, so that stage 5's stress is
   P_t = alpha_t P_bar_t + beta_t F_t^-T (see MODEL). Returns 0 or the first error. */
static int frm__vol_force_stages(frm_model *m, int linearize, int outputs)
{
    frm__vol_ctx ctx;
    int c, s;
    ctx.m = m;
    ctx.linearize = linearize;
    ctx.outputs = outputs;
    ctx.v = NULL;
    frm__run(m, m->sample_chunks, frm__vol_deform_chunks, &ctx);
    for (c = 0; c < m->sample_chunks; c++)
        if (m->chunk_err[c]) return m->chunk_err[c];
    frm__vol_average(m, m->v_jm1, m->v_jbm1, 0); /* A 1 = 1: A (J - 1) = J_bar - 1 */
    for (s = 0; s < m->sample_count; s++) {
        double x = ((double)m->v_jbm1[s] - (double)m->v_jm1[s]) / (1.0 + (double)m->v_jm1[s]); /* J_bar / J - 1 */
        if (!(1.0 + (double)m->v_jbm1[s] > 0) || !(x > -1)) return FRM_ERR_INVERTED;
        m->v_am1[s] = (frm_real)expm1(log1p(x) / 3.0);
    }
    frm__run(m, m->sample_chunks, frm__vol_stress_chunks, &ctx);
    for (c = 0; c < m->sample_chunks; c++)
        if (m->chunk_err[c]) return m->chunk_err[c];
    for (s = 0; s < m->sample_count; s++)
        m->v_x[s] = (frm_real)((double)m->s_volume[s] * (double)m->v_pi[s] / (1.0 + (double)m->v_jbm1[s]));
    frm__vol_average(m, m->v_x, m->v_y, 1);
    for (s = 0; s < m->sample_count; s++)
        m->v_beta[s] = (frm_real)((double)m->v_y[s] * (1.0 + (double)m->v_jm1[s]) / (double)m->s_volume[s] -
                                  (double)m->v_pi[s]);
    return FRM_OK;
}

typedef struct frm__force_ctx {
    frm_model *m;
    int linearize, outputs;
} frm__force_ctx;

/* Pass 1 of the force over sample chunks [begin, end): F, S, P per sample, the partial
   force of every pair into p_out, the chunk's energy; with linearize, the per-pair G and
   Hs and the per-sample F, S and tangent data too. Reads per pair 1 int and 7 reals
   (weight, gradient, lbar), writes 6 (+ 15 when linearising); gathers the frames' x, R, Q. */
static void frm__force_chunks(void *vctx, int begin, int end)
{
    frm__force_ctx *ctx = (frm__force_ctx *)vctx;
    frm_model *m = ctx->m;
    const frm_view *w = &m->view;
    int c;
    for (c = begin; c < end; c++) {
        int s0 = c * FRM__SAMPLE_CHUNK, s1 = s0 + FRM__SAMPLE_CHUNK, s, err = 0;
        double energy = m->vol_mode ? m->chunk_energy[c] : 0; /* volumetric: the law's energy of stage 3 */
        if (s1 > m->sample_count) s1 = m->sample_count;
        for (s = s0; s < s1; s++) {
            int b = m->s_start[s], n = m->s_start[s + 1] - b, k, e, r;
            frm_real F[9], H[9], S[6], P[9], cache[FRM__LAW_CACHE_MAX], psi, D = 0, v = m->s_volume[s];
            const frm_real *prm = m->s_law_params + FRM_LAW_PARAMS * (size_t)s;
            frm_pass1_deform(w, s, H, F, ctx->outputs ? m->s_pos + 3 * s : NULL);
            if (m->vol_mode) { /* P = alpha P_bar + beta F^-T (the law ran in stage 3) */
                frm_real Fi[9], J = 1 + m->v_jm1[s], al = 1 + m->v_am1[s], be = m->v_beta[s];
                const frm_real *Pb = m->v_Pbar + 9 * (size_t)s;
                frm__vol_inverse(F, J, Fi);
                for (r = 0; r < 3; r++)
                    for (k = 0; k < 3; k++) P[3 * r + k] = al * Pb[3 * r + k] + be * Fi[3 * k + r];
                if (ctx->linearize) {
                    memcpy(m->vl_Finv + 9 * (size_t)s, Fi, sizeof Fi);
                    memcpy(m->vl_Pbar + 9 * (size_t)s, Pb, sizeof Fi);
                    m->vl_J[s] = J;
                    m->vl_Jbar[s] = 1 + m->v_jbm1[s];
                    m->vl_alpha[s] = al;
                    m->vl_pi[s] = m->v_pi[s];
                    m->vl_beta[s] = be;
                }
                e = 0;
                psi = 0;
            } else {
                e = frm__law_stress(m->s_law[s], prm, m->s_user[s], H, S, &psi, cache);
                if (ctx->outputs) memcpy(m->s_F + 9 * s, F, sizeof F);
                if (!e) frm_first_piola(F, S, P);
            }
            if (e) {
                err = e;
                memset(m->p_out + 6 * (size_t)b, 0, sizeof(frm_real) * 6 * (size_t)n);
                continue;
            }
            energy += (double)v * (double)psi; /* volumetric: 0 here, the law's energy came from stage 3 */
            if (m->s_stab[s]) /* the rotation stabilisation: T / v joins P, the frame's own torque apart */
                energy += frm_pass1_stab_force(w, s, H, F, P, ctx->linearize, &D);
            frm_pass1_force_pairs(w, s, H, F, P, D, ctx->linearize, &energy);
            if (ctx->linearize) {
                memcpy(m->lin_F + 9 * (size_t)s, F, sizeof F);
                if (m->vol_mode) { /* the law's data at F_bar were stored in stage 3 */
                } else if (ctx->linearize == 2) { /* definite: the geometric term with the positive part of S, the
                                              law's tangent data made definite where it has a rule */
                    double Sd[6];
                    for (r = 0; r < 6; r++) Sd[r] = (double)S[r];
                    frm__positive_part3(Sd);
                    for (r = 0; r < 6; r++) S[r] = (frm_real)Sd[r];
                    if (frm__laws[m->s_law[s]].definite) frm__laws[m->s_law[s]].definite(prm, cache);
                }
                if (!m->vol_mode) {
                    memcpy(m->lin_S + 6 * (size_t)s, S, sizeof S);
                    memcpy(m->lin_cache + (size_t)m->law_cache * s, cache, sizeof(frm_real) * (size_t)m->law_cache);
                }
            }
        }
        m->chunk_energy[c] = energy;
        m->chunk_err[c] = err;
    }
}

typedef struct frm__gather_ctx {
    const frm_model *m;
    const frm_real *src;
    frm_real *dst;
    double *scale; /* when not NULL: per frame, sum over its pairs of |partial|^2 */
} frm__gather_ctx;

/* Pass 2 over frame chunks: each frame sums the partials of its pairs through the reverse
   table, in pair order (the order never depends on threads). Reads 1 int and 6 reals per
   pair, writes 6 reals per frame. */
static void frm__gather_chunks(void *vctx, int begin, int end)
{
    frm__gather_ctx *ctx = (frm__gather_ctx *)vctx;
    const frm_model *m = ctx->m;
    int c;
    for (c = begin; c < end; c++) {
        int i0 = c * FRM__FRAME_CHUNK, i1 = i0 + FRM__FRAME_CHUNK, i;
        if (i1 > m->frame_count) i1 = m->frame_count;
        for (i = i0; i < i1; i++) frm_pass2_gather(&m->view, i, ctx->src, ctx->dst, ctx->scale);
    }
}

static void frm__gather(const frm_model *m, const frm_real *src, frm_real *dst, double *scale)
{
    frm__gather_ctx g;
    g.m = m;
    g.src = src;
    g.dst = dst;
    g.scale = scale;
    frm__run(m, m->frame_chunks, frm__gather_chunks, &g);
}

static void frm__gravity_stiffness(const frm_model *m, int i, double K[9]);

/* Internal forces into m->force (both passes) and the elastic energy. With linearize (1:
   the symmetric part of K; 2: its positive-definite part, see SOLVERS), the stiffness data
   of the state too (and lin_torque, lin_gravity, lin_hrot). Returns FRM_OK,
   FRM_ERR_INVERTED or FRM_ERR_NOT_FINITE. */
static double frm__anchor_force(frm_model *m, int linearize);
static void frm__anchor_product(const frm_model *m, const frm_real *v, frm_real *out);
static void frm__anchor_diagonal(frm_model *m);

static int frm__force_pass(frm_model *m, int linearize, int outputs, double *energy)
{
    frm__force_ctx ctx;
    double W = 0;
    int c, err = FRM_OK;
    frm__update_frames(m);
    ctx.m = m;
    ctx.linearize = linearize;
    ctx.outputs = outputs;
    if (linearize) m->lin_valid = 0;
    if (m->vol_mode) {
        err = frm__vol_force_stages(m, linearize, outputs);
        if (err) {
            m->stats.force_evaluations++;
            if (energy) *energy = 0;
            return err;
        }
        ctx.outputs = 0; /* stage 1 wrote them */
    }
    frm__run(m, m->sample_chunks, frm__force_chunks, &ctx);
    m->stats.force_evaluations++;
    for (c = 0; c < m->sample_chunks; c++) {
        W += m->chunk_energy[c];
        if (m->chunk_err[c] && !err) err = m->chunk_err[c];
    }
    if (err) {
        if (energy) *energy = W;
        return err;
    }
    frm__gather(m, m->p_out, m->force, m->force_scale);
    if (linearize) frm__gather(m, m->p_H, m->lin_hrot, NULL); /* the frame-own rotational terms, summed in pair order */
    if (m->anchor_probe) W += frm__anchor_force(m, linearize);
    if (energy) *energy = W;
    if (!frm__finite(W) || !frm__all_finite(m->force, 6 * (size_t)m->frame_count)) return FRM_ERR_NOT_FINITE;
    if (linearize) {
        int i, r;
        for (i = 0; i < m->frame_count; i++) {
            frm_real cg[3], tg[3];
            double Kg[9], h[6];
            frm__gravity_moment(m, i, cg);
            frm_cross(cg, m->gravity, tg);
            for (r = 0; r < 3; r++) {
                m->lin_gravity[3 * i + r] = cg[r];
                m->lin_torque[3 * i + r] = m->force[6 * i + 3 + r] + tg[r];
            }
            frm__gravity_stiffness(m, i, Kg);
            for (r = 0; r < 6; r++) h[r] = (double)m->lin_hrot[6 * i + r];
            h[0] += Kg[0], h[1] += Kg[4], h[2] += Kg[8], h[3] += Kg[5], h[4] += Kg[2], h[5] += Kg[1];
            if (linearize == 2) frm__positive_part3(h);
            for (r = 0; r < 6; r++) m->lin_hrot[6 * i + r] = (frm_real)h[r];
        }
        m->lin_definite = linearize == 2;
        m->lin_valid = 1;
    }
    return FRM_OK;
}

/* Total generalized force on every frame: internal + gravity (m_g g, c_g x g) + external. */
static void frm__total_force(const frm_model *m, frm_real *f)
{
    int i, r;
    for (i = 0; i < m->frame_count; i++) {
        frm_real cg[3], tg[3], mg = (frm_real)m->grav_local[4 * (size_t)i];
        frm__gravity_moment(m, i, cg);
        frm_cross(cg, m->gravity, tg);
        for (r = 0; r < 3; r++) {
            f[6 * i + r] = m->force[6 * i + r] + mg * m->gravity[r] + m->ext[6 * i + r];
            f[6 * i + 3 + r] = m->force[6 * i + 3 + r] + tg[r] + m->ext[6 * i + 3 + r];
        }
    }
}

/* The residual's round-off floor, below which nothing more can be resolved (chiefly in
   float): the sum of each frame's partial forces, which nearly cancel at equilibrium
   (64 eps times the root of the sum of |partial|^2), and the force a displacement or an
   orientation moves when rounded to the next representable value (K_ii times one ulp,
   from the diagonal blocks of the last linearisation). */
static double frm__round_off_floor(const frm_model *m)
{
    double sq = 0, pq = 0, eps = FRM__IS_FLOAT ? FLT_EPSILON : DBL_EPSILON;
    int i, k;
    for (i = 0; i < m->frame_count; i++)
        if (m->state[i] == FRM__FREE) {
            const frm_real *x = m->disp + 3 * i, *K = m->kdiag + 36 * (size_t)i;
            double xm = fabs((double)x[0]) > fabs((double)x[1]) ? fabs((double)x[0]) : fabs((double)x[1]);
            if (fabs((double)x[2]) > xm) xm = fabs((double)x[2]);
            sq += m->force_scale[i];
            for (k = 0; k < 6; k++) {
                double t = fabs((double)K[7 * k]) * (k < 3 ? xm : 1.0) * eps;
                pq += t * t;
            }
        }
    return 64.0 * eps * sqrt(sq) + sqrt(pq);
}

/* Euclidean norm over the free frames. */
static double frm__norm_free(const frm_model *m, const frm_real *v)
{
    double s[4] = {0, 0, 0, 0};
    int i, k;
    for (i = 0; i < m->frame_count; i++)
        if (m->state[i] == FRM__FREE)
            for (k = 0; k < 6; k++)
                if (!((m->axes[i] >> k) & 1)) s[k & 3] += (double)v[6 * i + k] * v[6 * i + k];
    return sqrt((s[0] + s[1]) + (s[2] + s[3]));
}

/* Euclidean norm over the held components (fixed and driven frames, held axes): the
   reactions when v is the total force. */
static double frm__norm_held(const frm_model *m, const frm_real *v)
{
    double s[4] = {0, 0, 0, 0};
    int i, k;
    for (i = 0; i < m->frame_count; i++)
        for (k = 0; k < 6; k++)
            if (m->state[i] != FRM__FREE || ((m->axes[i] >> k) & 1)) s[k & 3] += (double)v[6 * i + k] * v[6 * i + k];
    return sqrt((s[0] + s[1]) + (s[2] + s[3]));
}

/* >>stiffness -------------------------------------------------------------------------- */

typedef struct frm__apply_ctx {
    const frm_model *m;
    const frm_real *v;
} frm__apply_ctx;


/* K v stage 1 over sample chunks (volumetric): dF of every sample, e = tr(F^-1 dF) (dJ = J e),
   x = J e for the average. */
static void frm__vol_dF_chunks(void *vctx, int begin, int end)
{
    frm__vol_ctx *ctx = (frm__vol_ctx *)vctx;
    frm_model *m = ctx->m;
    int c;
    for (c = begin; c < end; c++) {
        int s0 = c * FRM__SAMPLE_CHUNK, s1 = s0 + FRM__SAMPLE_CHUNK, s;
        if (s1 > m->sample_count) s1 = m->sample_count;
        for (s = s0; s < s1; s++) {
            int b = m->s_start[s], n = m->s_start[s + 1] - b, k;
            frm_real *dF = m->vk_dF + 9 * (size_t)s, e;
            const frm_real *Fi = m->vl_Finv + 9 * (size_t)s;
            for (k = 0; k < 9; k++) dF[k] = 0;
            for (k = b; k < b + n; k++) frm_pair_dF(ctx->v + 6 * m->p_frame[k], m->p_grad + 3 * k, m->p_G + 9 * (size_t)k, dF);
            e = Fi[0] * dF[0] + Fi[1] * dF[3] + Fi[2] * dF[6] + Fi[3] * dF[1] + Fi[4] * dF[4] + Fi[5] * dF[7] +
                Fi[6] * dF[2] + Fi[7] * dF[5] + Fi[8] * dF[8];
            m->vk_e[s] = e;
            m->v_x[s] = m->vl_J[s] * e;
        }
    }
}

/* K v stage 3 over sample chunks: dF_bar = alpha (dF + (ebar - e) / 3 F), dP_bar by the law
   at F_bar, dpi = (dP_bar : F_bar + P_bar : dF_bar) / 3 and y = v (dpi - pi ebar) / J_bar
   (definite: the Gauss-Newton part only, dpi = dP_bar : F_bar / 3 and y = v dpi / J_bar). */
static void frm__vol_dstress_chunks(void *vctx, int begin, int end)
{
    frm__vol_ctx *ctx = (frm__vol_ctx *)vctx;
    frm_model *m = ctx->m;
    int c, full = !m->lin_definite;
    for (c = begin; c < end; c++) {
        int s0 = c * FRM__SAMPLE_CHUNK, s1 = s0 + FRM__SAMPLE_CHUNK, s;
        if (s1 > m->sample_count) s1 = m->sample_count;
        for (s = s0; s < s1; s++) {
            const frm_real *dF = m->vk_dF + 9 * (size_t)s, *F = m->lin_F + 9 * (size_t)s;
            const frm_real *Fb = m->vl_Fbar + 9 * (size_t)s, *Pb = m->vl_Pbar + 9 * (size_t)s;
            const frm_real *prm = m->s_law_params + FRM_LAW_PARAMS * (size_t)s, *cache = m->lin_cache + (size_t)m->law_cache * s;
            frm_real dFb[9], *dP = m->vk_dPbar + 9 * (size_t)s, al = m->vl_alpha[s], t, dpi = 0;
            int law = m->s_law[s], r;
            t = (m->vk_ebar[s] - m->vk_e[s]) / 3;
            for (r = 0; r < 9; r++) dFb[r] = al * (dF[r] + t * F[r]);
            if (frm__laws[law].fast_path)
                frm_sample_dP(law, prm[0], prm[1], cache, Fb, m->lin_S + 6 * (size_t)s, dFb, dP);
            else
                frm__law_dP(law, prm, m->s_user[s], cache, Fb, m->lin_S + 6 * (size_t)s, dFb, dP);
            for (r = 0; r < 9; r++) dpi += dP[r] * Fb[r] + (full ? Pb[r] * dFb[r] : 0);
            dpi = dpi / 3 + m->vol_eta * m->s_mu[s] * 3 * t; /* + c dphi, dphi = ebar - e */
            m->vk_dpi[s] = dpi;
            m->v_x[s] = m->s_volume[s] * (dpi - (full ? m->vl_pi[s] * m->vk_ebar[s] : 0)) / m->vl_Jbar[s];
        }
    }
}

/* K v stages 1 to 4 (volumetric): stage 5 in frm__apply_chunks forms, per sample,
       dP = alpha dP_bar + (dQ J / v - dpi) F^-T
            + [alpha (ebar - e) / 3 P_bar + (beta + pi) e F^-T - beta F^-T dF^T F^-T]  (not definite)
   with dQ = A^T y (the derivative of P = alpha P_bar + beta F^-T, see MODEL). */
static void frm__vol_apply_stages(frm_model *m, const frm_real *v)
{
    frm__vol_ctx ctx;
    int s;
    ctx.m = m;
    ctx.linearize = 0;
    ctx.outputs = 0;
    ctx.v = v;
    frm__run(m, m->sample_chunks, frm__vol_dF_chunks, &ctx);
    frm__vol_average(m, m->v_x, m->vk_ebar, 0);
    for (s = 0; s < m->sample_count; s++) m->vk_ebar[s] /= m->vl_Jbar[s];
    frm__run(m, m->sample_chunks, frm__vol_dstress_chunks, &ctx);
    frm__vol_average(m, m->v_x, m->v_y, 1);
}

/* K v stage 5 for sample s (volumetric): dP as in frm__vol_apply_stages; dF its dF. */
static void frm__vol_sample_dP(const frm_model *m, int s, frm_real dF[9], frm_real dP[9])
{
    const frm_real *Fi = m->vl_Finv + 9 * (size_t)s, *dPb = m->vk_dPbar + 9 * (size_t)s, *Pb = m->vl_Pbar + 9 * (size_t)s;
    frm_real al = m->vl_alpha[s], J = m->vl_J[s], be = m->vl_beta[s], e = m->vk_e[s], c;
    int r, k;
    memcpy(dF, m->vk_dF + 9 * (size_t)s, sizeof(frm_real) * 9);
    c = m->v_y[s] * J / m->s_volume[s] - m->vk_dpi[s];
    if (!m->lin_definite) c += (be + m->vl_pi[s]) * e;
    for (r = 0; r < 3; r++)
        for (k = 0; k < 3; k++) dP[3 * r + k] = al * dPb[3 * r + k] + c * Fi[3 * k + r];
    if (!m->lin_definite) {
        frm_real a = al * (m->vk_ebar[s] - e) / 3, X[9], Y[9];
        for (r = 0; r < 9; r++) dP[r] += a * Pb[r];
        /* - beta F^-T dF^T F^-T: X = dF^T F^-T, Y = F^-T X */
        for (r = 0; r < 3; r++)
            for (k = 0; k < 3; k++) X[3 * r + k] = dF[r] * Fi[3 * k] + dF[3 + r] * Fi[3 * k + 1] + dF[6 + r] * Fi[3 * k + 2];
        for (r = 0; r < 3; r++)
            for (k = 0; k < 3; k++) Y[3 * r + k] = Fi[r] * X[k] + Fi[3 + r] * X[3 + k] + Fi[6 + r] * X[6 + k];
        for (r = 0; r < 9; r++) dP[r] -= be * Y[r];
    }
}

/* Pass 1 of K v in pair mode over sample chunks: dF from the neighbours' dq, dP, then
   each pair's contribution into p_out. Reads per pair 1 int and 3 + 9 + 6 reals (grad,
   G, Hs), writes 6; per sample 9 + 6 (+ FRM_LAW_CACHE for Neo-Hookean) reals; gathers 6
   per neighbour. */
static void frm__apply_chunks(void *vctx, int begin, int end)
{
    frm__apply_ctx *ctx = (frm__apply_ctx *)vctx;
    const frm_model *m = ctx->m;
    const frm_view *w = &m->view;
    const frm_real *v = ctx->v;
    int c;
    for (c = begin; c < end; c++) {
        int s0 = c * FRM__SAMPLE_CHUNK, s1 = s0 + FRM__SAMPLE_CHUNK, s;
        if (s1 > m->sample_count) s1 = m->sample_count;
        for (s = s0; s < s1; s++) {
            frm_real dF[9], dP[9];
            if (m->vol_mode) frm__vol_sample_dP(m, s, dF, dP);
            else {
                int law = m->s_law[s];
                const frm_real *prm = m->s_law_params + FRM_LAW_PARAMS * (size_t)s;
                frm_pass1_apply_dF(w, s, v, dF);
                if (frm__laws[law].fast_path)
                    frm_sample_dP(law, prm[0], prm[1], m->lin_cache + (size_t)m->law_cache * s, m->lin_F + 9 * (size_t)s,
                                  m->lin_S + 6 * (size_t)s, dF, dP);
                else
                    frm__law_dP(law, prm, m->s_user[s], m->lin_cache + (size_t)m->law_cache * s, m->lin_F + 9 * (size_t)s,
                                m->lin_S + 6 * (size_t)s, dF, dP);
            }
            frm_pass1_apply_pairs(w, s, v, dF, dP, m->lin_definite);
        }
    }
}

/* K v by assembled blocks over frame chunks: each row i, sum_j K_ij v_j. Reads 36 reals
   and 1 int per block. */
static void frm__block_chunks(void *vctx, int begin, int end)
{
    frm__gather_ctx *ctx = (frm__gather_ctx *)vctx;
    const frm_model *m = ctx->m;
    int c;
    for (c = begin; c < end; c++) {
        int i0 = c * FRM__FRAME_CHUNK, i1 = i0 + FRM__FRAME_CHUNK, i;
        if (i1 > m->frame_count) i1 = m->frame_count;
        for (i = i0; i < i1; i++) {
            frm_real y0 = 0, y1 = 0, y2 = 0, y3 = 0, y4 = 0, y5 = 0; /* six independent chains */
            int e, k;
            for (e = m->blk_start[i]; e < m->blk_start[i + 1]; e++) {
                const frm_real *K = m->blocks + 36 * (size_t)e, *x = ctx->src + 6 * m->blk_col[e];
                for (k = 0; k < 6; k++) {
                    frm_real xk = x[k];
                    y0 += K[k] * xk;
                    y1 += K[6 + k] * xk;
                    y2 += K[12 + k] * xk;
                    y3 += K[18 + k] * xk;
                    y4 += K[24 + k] * xk;
                    y5 += K[30 + k] * xk;
                }
            }
            ctx->dst[6 * i] = y0;
            ctx->dst[6 * i + 1] = y1;
            ctx->dst[6 * i + 2] = y2;
            ctx->dst[6 * i + 3] = y3;
            ctx->dst[6 * i + 4] = y4;
            ctx->dst[6 * i + 5] = y5;
        }
    }
}

/* The gravity torque's stiffness at the linearisation, symmetric part:
   K_g dtheta = -1/2 (c (g . dtheta) + g (c . dtheta)) + (c . g) dtheta, c = R cbar_g. */
static void frm__gravity_stiffness(const frm_model *m, int i, double K[9])
{
    frm_pass_gravity_stiffness(m->lin_gravity + 3 * i, m->gravity, K);
}

/* out = K v (all frames): pairs or blocks as linearised; the symmetric part, or with
   exact = 1 the force derivative itself, which adds 1/2 tau x dtheta per frame (tau the
   internal plus gravity torque at the linearisation). */
static void frm__stiffness_product(frm_model *m, const frm_real *v, frm_real *out, int exact)
{
    int i, r;
    if (m->lin_mode == FRM_STIFFNESS_BLOCKS) {
        frm__gather_ctx g;
        g.m = m;
        g.src = v;
        g.dst = out;
        g.scale = NULL;
        frm__run(m, m->frame_chunks, frm__block_chunks, &g);
    } else {
        frm__apply_ctx a;
        a.m = m;
        a.v = v;
        if (m->vol_mode) frm__vol_apply_stages(m, v);
        frm__run(m, m->sample_chunks, frm__apply_chunks, &a);
        frm__gather(m, m->p_out, out, NULL);
        for (i = 0; i < m->frame_count; i++) frm_pass2_rotational(&m->view, i, v, out); /* pairs' Hs + gravity */
    }
    if (m->anchor_probe) frm__anchor_product(m, v, out);
    if (exact)
        for (i = 0; i < m->frame_count; i++) {
            frm_real t[3];
            frm_cross(m->lin_torque + 3 * i, v + 6 * i + 3, t);
            for (r = 0; r < 3; r++) out[6 * i + 3 + r] += (frm_real)0.5 * t[r];
        }
    m->stats.stiffness_products++;
}

/* Adds the symmetric Hs (6) to the rotational block of a 6x6 row-major block. */

/* The stabilisation's part of the tangent columns of slot a of sample s (assembly): for
   each unit dq_c of slot a's frame, adds dPx / v to cols[c] and writes the torque row of
   every stabilised slot k into rows[18 k + 3 c + r] (the column (a, c) of K's rotational
   rows of frame k, i.e. by symmetry row c of block (a, k), columns 3 + r). */
static void frm__stab_columns(const frm_model *m, int s, int a, frm_real cols[54], frm_real *rows)
{
    int b = m->s_start[s], n = m->s_start[s + 1] - b, c, k, r, pa = b + a;
    frm_real vol = m->s_volume[s], tq[3 * FRM_MAX_NEIGHBORS];
    const frm_real *dth[FRM_MAX_NEIGHBORS];
    for (c = 0; c < 6; c++) {
        frm_real dq[6] = {0, 0, 0, 0, 0, 0}, dF[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, dPx[9];
        dq[c] = 1;
        frm_pair_dF(dq, m->p_grad + 3 * (size_t)pa, m->p_G + 9 * (size_t)pa, dF);
        for (k = 0; k < n; k++) dth[k] = k == a && c >= 3 ? dq + 3 : NULL;
        frm__stab_sample_apply(m, s, dF, dth, m->lin_definite, dPx, tq);
        for (r = 0; r < 9; r++) cols[9 * c + r] += dPx[r] / vol;
        for (k = 0; k < n; k++)
            for (r = 0; r < 3; r++) rows[18 * k + 3 * c + r] = tq[3 * k + r];
    }
}

/* The coupling's Gauss-Newton coefficient between slots a and b of sample s. */
static frm_real frm__coupling_coef(const frm_model *m, int s, int a, int b)
{
    const frm_real *w = m->p_weight + m->s_start[s];
    double wa = (double)w[a], wb = (double)w[b], sum = 0;
    int k;
    for (k = 0; k < m->s_start[s + 1] - m->s_start[s]; k++) sum += fabs((double)w[k]);
    return (frm_real)((double)m->s_couple[s] * ((a == b ? fabs(wa) : 0.0) - fabs(wa) * wb - wa * fabs(wb) + sum * wa * wb));
}

/* Per-frame diagonal block of the stiffness (symmetric part) from its pairs, computed in
   a gather pass, once, at the rest state (kdiag_rest, for the pair mode's preconditioner;
   the block mode takes the exact one from the assembled row). About 700 ns a pair: the
   six tangent columns of every pair. */
static void frm__diag_chunks(void *vctx, int begin, int end)
{
    frm__gather_ctx *ctx = (frm__gather_ctx *)vctx;
    frm_model *m = (frm_model *)ctx->m;
    int c;
    for (c = begin; c < end; c++) {
        int i0 = c * FRM__FRAME_CHUNK, i1 = i0 + FRM__FRAME_CHUNK, i;
        if (i1 > m->frame_count) i1 = m->frame_count;
        for (i = i0; i < i1; i++) {
            double acc[36];
            int e, k, r;
            memset(acc, 0, sizeof acc);
            for (e = m->rev_start[i]; e < m->rev_start[i + 1]; e++) {
                int p = m->rev_pair[e], s = m->p_sample[p], a = p - m->s_start[s];
                frm_real cols[54], K[36], rows[18 * FRM_MAX_NEIGHBORS];
                for (k = 0; k < 36; k++) K[k] = 0;
                frm__law_tangent_columns(m->s_law[s], m->s_law_params + FRM_LAW_PARAMS * (size_t)s, m->s_user[s],
                                         m->lin_cache + (size_t)m->law_cache * s, m->lin_F + 9 * (size_t)s,
                                         m->lin_S + 6 * (size_t)s, m->p_grad + 3 * (size_t)p, m->p_G + 9 * (size_t)p, cols);
                if (m->s_stab[s]) frm__stab_columns(m, s, a, cols, rows);
                frm_pair_block(m->s_volume[s], cols, m->p_grad + 3 * (size_t)p, m->p_G + 9 * (size_t)p, K);
                if (m->s_stab[s])
                    for (k = 0; k < 6; k++)
                        for (r = 0; r < 3; r++) K[6 * k + 3 + r] += rows[18 * a + 3 * k + r];
                frm__add_rotational(m->p_H + 6 * (size_t)p, K);
                if (m->s_couple[s] != 0)
                    frm_pair_coupling_block(frm__coupling_coef(m, s, a, a), m->p_A + 3 * (size_t)p, m->p_A + 3 * (size_t)p, K);
                for (k = 0; k < 36; k++) acc[k] += (double)K[k];
            }
            /* the rest blocks carry no gravity: the rotated ones get the current frame-own term */
            for (r = 0; r < 6; r++)
                for (k = 0; k < 6; k++) m->kdiag_rest[36 * (size_t)i + 6 * r + k] = (frm_real)(0.5 * (acc[6 * r + k] + acc[6 * k + r]));
        }
    }
}

/* The rest-state diagonal blocks for the pair mode's preconditioner (at creation). */
static void frm__rest_diagonal(frm_model *m)
{
    frm__gather_ctx g;
    g.m = m;
    g.src = NULL;
    g.dst = NULL;
    g.scale = NULL;
    frm__force_pass(m, 1, 0, NULL);
    frm__run(m, m->frame_chunks, frm__diag_chunks, &g);
    m->lin_valid = 0;
    m->stats.force_evaluations = 0;
}

/* Assembly over frame chunks: row i's blocks from the pairs of frame i (slot a of sample
   s): K_{i, frame of slot b} += v B_a^T A B_b for every slot b (with the stabilisation's
   columns and torque rows), plus the frame-own rotational term lin_hrot on the diagonal.
   Rows are independent: no two tasks write the same block. */
static void frm__assemble_chunks(void *vctx, int begin, int end)
{
    frm__gather_ctx *ctx = (frm__gather_ctx *)vctx;
    frm_model *m = (frm_model *)ctx->m;
    int c;
    for (c = begin; c < end; c++) {
        int i0 = c * FRM__FRAME_CHUNK, i1 = i0 + FRM__FRAME_CHUNK, i;
        if (i1 > m->frame_count) i1 = m->frame_count;
        for (i = i0; i < i1; i++) {
            int e, k, r, diag = frm__find_block(m, i, i);
            frm_real *D = m->blocks + 36 * (size_t)diag;
            memset(m->blocks + 36 * (size_t)m->blk_start[i], 0,
                   sizeof(frm_real) * 36 * (size_t)(m->blk_start[i + 1] - m->blk_start[i]));
            for (e = m->rev_start[i]; e < m->rev_start[i + 1]; e++) {
                int p = m->rev_pair[e], s = m->p_sample[p], b = m->s_start[s], n = m->s_start[s + 1] - b, a = p - b, q;
                frm_real cols[54], rows[18 * FRM_MAX_NEIGHBORS];
                frm__law_tangent_columns(m->s_law[s], m->s_law_params + FRM_LAW_PARAMS * (size_t)s, m->s_user[s],
                                         m->lin_cache + (size_t)m->law_cache * s, m->lin_F + 9 * (size_t)s,
                                         m->lin_S + 6 * (size_t)s, m->p_grad + 3 * (size_t)p, m->p_G + 9 * (size_t)p, cols);
                if (m->s_stab[s]) frm__stab_columns(m, s, a, cols, rows);
                for (q = 0; q < n; q++) {
                    frm_real *K = m->blocks + 36 * (size_t)m->pair_blk[m->sq_start[s] + a * n + q];
                    frm_pair_block(m->s_volume[s], cols, m->p_grad + 3 * (size_t)(b + q), m->p_G + 9 * (size_t)(b + q), K);
                    if (m->s_stab[s])
                        for (k = 0; k < 6; k++)
                            for (r = 0; r < 3; r++) K[6 * k + 3 + r] += rows[18 * q + 3 * k + r];
                    if (m->s_couple[s] != 0)
                        frm_pair_coupling_block(frm__coupling_coef(m, s, a, q), m->p_A + 3 * (size_t)p, m->p_A + 3 * (size_t)(b + q), K);
                }
            }
            frm__add_rotational(m->lin_hrot + 6 * (size_t)i, D);
            for (r = 0; r < 6; r++)
                for (k = 0; k < 6; k++) m->kdiag[36 * (size_t)i + 6 * r + k] = (frm_real)0.5 * (D[6 * r + k] + D[6 * k + r]);
        }
    }
}

/* Cost model of AUTO (see PERFORMANCE): estimated time of a linear solve in each mode
   from per-item costs measured with gcc -O2 on one core (double, ns): the pair mode pays
   its product every iteration, the block mode assembles once and then streams 288 bytes
   a block. With 8 neighbours blocks win beyond about 30 CG iterations a linearisation. */
#define FRM__COST_PAIR_ITER 35.0      /* pair-mode K v, per pair per iteration */
#define FRM__COST_PAIR_STAB 30.0      /* its rotation stabilisation's divergence term (hexahedra, 8 neighbours) */
#define FRM__COST_BLOCK_ITER 8.0      /* block-mode K v, per block per iteration */
#define FRM__COST_ASSEMBLE_PAIR 500.0 /* assembly: the tangent columns, per pair */
#define FRM__COST_ASSEMBLE_SLOT 60.0  /* assembly: one slot-pair block, per (pair, slot) */

static int frm__choose_mode(const frm_model *m)
{
    double it, pairs, blocks;
    if (m->stiffness_mode == FRM_STIFFNESS_PAIRS || !m->has_blocks) return FRM_STIFFNESS_PAIRS;
    if (m->stiffness_mode == FRM_STIFFNESS_BLOCKS || m->linear_solver == FRM_LINEAR_SOLVER_BTD) return FRM_STIFFNESS_BLOCKS;
    /* the last solve's iteration count predicts the next; before any, a typical 50 */
    it = m->lin_predict >= 0 ? (double)m->lin_predict + 1 : 50.0;
    if (it > m->cg_max_iterations + 1) it = m->cg_max_iterations + 1;
    pairs = it * (FRM__COST_PAIR_ITER + (m->stab_gamma > 0 ? FRM__COST_PAIR_STAB : 0.0)) * m->pair_count;
    blocks = FRM__COST_ASSEMBLE_PAIR * m->pair_count + FRM__COST_ASSEMBLE_SLOT * m->sq_total +
             it * FRM__COST_BLOCK_ITER * m->block_count;
    if (m->coarse_use) { /* the coarse matrix: from the blocks, or a sample pass of 9 products per aggregate */
        pairs += FRM__COARSE_MODES * 1.5 * (FRM__COST_PAIR_ITER + (m->stab_gamma > 0 ? FRM__COST_PAIR_STAB : 0.0)) * m->pair_count;
        blocks += 3 * FRM__COST_BLOCK_ITER * m->block_count;
    }
    return blocks < pairs ? FRM_STIFFNESS_BLOCKS : FRM_STIFFNESS_PAIRS;
}

/* After a linearising force pass: the chosen mode's data (assembled blocks, or the
   diagonal blocks for the preconditioner). */
static void frm__prepare_mode(frm_model *m, int mode)
{
    frm__gather_ctx g;
    int i;
    g.m = m;
    g.src = NULL;
    g.dst = NULL;
    g.scale = NULL;
    m->lin_mode = mode;
    m->stats.stiffness_mode = mode;
    if (mode == FRM_STIFFNESS_BLOCKS) {
        frm__run(m, m->frame_chunks, frm__assemble_chunks, &g);
        if (m->anchor_probe) frm__anchor_diagonal(m);
        return;
    }
    /* pair mode: the block-Jacobi blocks are the rest ones turned with the frame,
       T K_rest T^T with T = diag(Q, Q), plus the current frame-own rotational term (its
       pairs' Hs and gravity): exact for a rigid motion of the rest state, an approximation
       under strain (the preconditioner only) */
    for (i = 0; i < m->frame_count; i++)
        frm_pass_precond_block(m->rel + 9 * i, m->kdiag_rest + 36 * (size_t)i, m->lin_hrot + 6 * (size_t)i,
                               m->kdiag + 36 * (size_t)i);
    if (m->anchor_probe) frm__anchor_diagonal(m);
}

/* World mass data (m, c = R cbar, J = R Jbar R^T) of every frame at its current pose
   (frm_pass_mass_world, shared with the CUDA companion). */
static void frm__mass_update(frm_model *m)
{
    int i;
    for (i = 0; i < m->frame_count; i++)
        frm_pass_mass_world(m->mass_local + 10 * (size_t)i, m->rot + 9 * i, m->mass_world + 10 * (size_t)i);
}

/* The 6x6 mass block of frame i from mass_world: [m I, -[c]x; [c]x, J]. */
static void frm__mass_matrix(const frm_model *m, int i, double M[36])
{
    frm_pass_mass_matrix(m->mass_world + 10 * (size_t)i, M);
}

/* out = M_i v for frame i (6 values): (m x + omega x c, c x x + J omega). */
static void frm__mass_apply(const frm_model *m, int i, const frm_real *v, double out[6])
{
    frm_pass_mass_apply(m->mass_world + 10 * (size_t)i, v, out);
}

/* Block-Jacobi preconditioner: the inverse of a_mass M_i + a_stiff K_ii per free frame (a
   Cholesky inverse; if that block is not positive definite, V |Lambda|^-1 V^T from its
   eigen-decomposition, eigenvalues of magnitude below 1e-9 of the largest raised to it),
   zero for fixed and driven frames. Returns the number of blocks that needed the
   eigen-decomposition (an indefinite linearisation). */
static int frm__build_precond(frm_model *m, double a_mass, double a_stiff)
{
    int i, k, fixed = 0;
    for (i = 0; i < m->frame_count; i++) {
        frm_real *P = m->precond + 36 * (size_t)i;
        double A[36], M[36], inv[36];
        if (m->state[i] != FRM__FREE) {
            for (k = 0; k < 36; k++) P[k] = 0;
            continue;
        }
        frm__mass_matrix(m, i, M);
        for (k = 0; k < 36; k++) A[k] = a_mass * M[k] + a_stiff * (double)m->kdiag[36 * (size_t)i + k];
        for (k = 3; k < 6; k++) A[7 * k] += a_stiff * m->solve_regularization * fabs((double)m->kdiag[36 * (size_t)i + 7 * k]);
        if (m->axes[i]) /* held components: identity rows and columns, zeroed in the inverse below */
            for (k = 0; k < 6; k++)
                if ((m->axes[i] >> k) & 1) {
                    int l;
                    for (l = 0; l < 6; l++) A[6 * k + l] = A[6 * l + k] = 0;
                    A[7 * k] = 1;
                }
        if (!frm_pass_invert6(A, inv)) {
            double V[36], ev[6], top = 0;
            int r, c;
            for (r = 0; r < 6; r++)
                for (c = 0; c < r; c++) A[6 * r + c] = A[6 * c + r] = 0.5 * (A[6 * r + c] + A[6 * c + r]);
            frm__jacobi(A, 6, V, ev);
            for (k = 0; k < 6; k++) {
                ev[k] = fabs(ev[k]);
                if (ev[k] > top) top = ev[k];
            }
            for (k = 0; k < 6; k++) ev[k] = ev[k] > 1e-9 * top ? 1 / ev[k] : (top > 0 ? 1 / (1e-9 * top) : 0);
            for (r = 0; r < 6; r++)
                for (c = 0; c < 6; c++) {
                    double t = 0;
                    for (k = 0; k < 6; k++) t += V[6 * r + k] * ev[k] * V[6 * c + k];
                    inv[6 * r + c] = t;
                }
            fixed++;
        }
        if (m->axes[i])
            for (k = 0; k < 36; k++)
                if (((m->axes[i] >> (k / 6)) & 1) || ((m->axes[i] >> (k % 6)) & 1)) inv[k] = 0;
        for (k = 0; k < 36; k++) P[k] = (frm_real)inv[k];
    }
    m->precond_mass = a_mass;
    m->precond_stiff = a_stiff;
    m->coarse_ready = 0;
    /* static solves always; a solve with mass (implicit steps, shifted modal solves) once
       block-Jacobi alone needed FRM__COARSE_MIN_ITERATIONS: below that the coarse matrix's
       build (about ten stiffness products) costs more than it saves */
    m->coarse_use = m->agg_count && !m->vol_mode && (a_mass == 0 || m->coarse_plain >= m->cg_max_iterations ||
                                     (!FRM__IS_FLOAT && m->coarse_plain >= FRM__COARSE_MIN_ITERATIONS));
    return fixed;
}

/* >>coarse ------------------------------------------------------------------------------ */

/* The two-level preconditioner (SOLVERS): block-Jacobi plus a coarse correction
   P A_c^-1 P^T over the aggregates of frm__aggregate, 9 modes each: a translation t, a
   rigid rotation omega (frame i moves by omega x d_i, d_i = x_i - c_a with current
   positions and c_a the aggregate's mean, and turns by omega) and the frames' own
   rotation phi (frame i turns by phi and does not move), so per frame
   P_i = [I, -[d_i]x, 0; 0, I, I], masked by its held components (fixed and driven frames
   take no part). A_c = P^T (a_mass M + a_stiff K) P is the exact Galerkin product of the
   linearisation the solve uses: frm__coarse_row from the assembled blocks (block mode),
   frm__coarse_sample per sample as the pair-mode product computes it (pair mode; the
   coupling term left out), plus per frame the mass, the frame-own rotational terms (pair
   mode) and the regularisation. Serial, in frame or sample order: deterministic for any
   thread count. Dense, symmetrised and Cholesky-factored in double; a pivot at or below
   1e-10 of its diagonal (a mode held by fixed frames, an indefinite linearisation) drops
   that mode. */

/* The components of frame i that take part in the coarse space: 0 for fixed and driven
   frames, the free axes of a free one (bit k for component k). */
static unsigned frm__coarse_mask(const frm_model *m, int i) { return m->state[i] == FRM__FREE ? 63u & ~(unsigned)m->axes[i] : 0u; }

/* dq = mask (P_i e) for the coarse direction e of frame i's aggregate (0-2: translation
   t, 3-5: rigid rotation omega, 6-8: the frames' own rotation phi). */
static void frm__coarse_mode(const frm_model *m, int i, int e, frm_real dq[6])
{
    const double *c = m->agg_centre + 3 * m->f_agg[i];
    double d[3], v[6] = {0, 0, 0, 0, 0, 0};
    unsigned mask = frm__coarse_mask(m, i);
    int r;
    for (r = 0; r < 3; r++) d[r] = (double)m->pos[3 * i + r] - c[r];
    if (e >= 6) e -= 3; /* phi: the rotation alone */
    else if (e >= 3) { /* omega: and omega x d */
        v[e] = 1;
        v[0] = v[4] * d[2] - v[5] * d[1];
        v[1] = v[5] * d[0] - v[3] * d[2];
        v[2] = v[3] * d[1] - v[4] * d[0];
    }
    v[e] = 1;
    for (r = 0; r < 6; r++) dq[r] = (mask >> r) & 1 ? (frm_real)v[r] : 0;
}

/* y += (mask P_i)^T r for frame i's 6 values r: (r_t, r_w + d x r_t, r_w) of the masked r. */
static void frm__coarse_restrict(const frm_model *m, int i, const frm_real *rv, double *y)
{
    const double *c = m->agg_centre + 3 * m->f_agg[i];
    unsigned mask = frm__coarse_mask(m, i);
    double d[3], x[6];
    int r;
    for (r = 0; r < 3; r++) d[r] = (double)m->pos[3 * i + r] - c[r];
    for (r = 0; r < 6; r++) x[r] = (mask >> r) & 1 ? (double)rv[r] : 0.0;
    for (r = 0; r < 3; r++) y[r] += x[r];
    y[3] += x[3] + (d[1] * x[2] - d[2] * x[1]);
    y[4] += x[4] + (d[2] * x[0] - d[0] * x[2]);
    y[5] += x[5] + (d[0] * x[1] - d[1] * x[0]);
    for (r = 6; r < FRM__COARSE_MODES; r++) y[r] += x[r - 3];
}

/* z += mask P_i u: (u_t + u_w x d, u_w + u_phi) on frame i's free components. */
static void frm__coarse_prolong(const frm_model *m, int i, const double *u, frm_real *z)
{
    const double *c = m->agg_centre + 3 * m->f_agg[i];
    unsigned mask = frm__coarse_mask(m, i);
    double d[3], o[6];
    int r;
    for (r = 0; r < 3; r++) d[r] = (double)m->pos[3 * i + r] - c[r];
    o[0] = u[0] + (u[4] * d[2] - u[5] * d[1]);
    o[1] = u[1] + (u[5] * d[0] - u[3] * d[2]);
    o[2] = u[2] + (u[3] * d[1] - u[4] * d[0]);
    for (r = 3; r < 6; r++) o[r] = u[r] + (FRM__COARSE_MODES > 6 ? u[r + 3] : 0.0);
    for (r = 0; r < 6; r++)
        if ((mask >> r) & 1) z[r] += (frm_real)o[r];
}

/* Sample s's part of P^T K P: for each aggregate among its neighbours and each of its six
   rigid motions, the sample's K v exactly as the pair-mode product computes it (dF, the
   law's dP, the rotation stabilisation's stress and torques; not the coupling term), its
   output per slot projected by P^T. */
static void frm__coarse_sample(frm_model *m, int s, double a_stiff)
{
    int b = m->s_start[s], n = m->s_start[s + 1] - b, slots[FRM_MAX_NEIGHBORS], agg_of[FRM_MAX_NEIGHBORS];
    int na = 0, j, e, k, r, c, D = FRM__COARSE_MODES * m->agg_count, law = m->s_law[s];
    const frm_real *prm = m->s_law_params + FRM_LAW_PARAMS * (size_t)s;
    frm_real *dqs = m->coarse_dq, vol = m->s_volume[s];
    for (k = 0; k < n; k++) {
        int f = m->p_frame[b + k];
        agg_of[k] = -1;
        if (!frm__coarse_mask(m, f)) continue;
        for (j = 0; j < na && slots[j] != m->f_agg[f]; j++) {}
        if (j == na) slots[na++] = m->f_agg[f];
        agg_of[k] = j;
    }
    for (j = 0; j < na; j++)
        for (e = 0; e < FRM__COARSE_MODES; e++) {
            frm_real dF[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, dP[9], stq[3 * FRM_MAX_NEIGHBORS], out[6];
            const frm_real *dth[FRM_MAX_NEIGHBORS];
            static const frm_real zero[3] = {0, 0, 0};
            for (k = 0; k < n; k++) {
                frm_real *dq = dqs + 6 * k;
                if (agg_of[k] == j) frm__coarse_mode(m, m->p_frame[b + k], e, dq);
                else
                    for (r = 0; r < 6; r++) dq[r] = 0;
                frm_pair_dF(dq, m->p_grad + 3 * (size_t)(b + k), m->p_G + 9 * (size_t)(b + k), dF);
                dth[k] = agg_of[k] == j ? dq + 3 : zero;
            }
            frm__law_dP(law, prm, m->s_user[s], m->lin_cache + (size_t)m->law_cache * s, m->lin_F + 9 * (size_t)s,
                        m->lin_S + 6 * (size_t)s, dF, dP);
            if (m->s_stab[s]) {
                frm_real dPx[9];
                frm__stab_sample_apply(m, s, dF, dth, m->lin_definite, dPx, stq);
                for (r = 0; r < 9; r++) dP[r] += dPx[r] / vol;
            }
            for (k = 0; k < n; k++) {
                int q = agg_of[k];
                double y[FRM__COARSE_MODES] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
                if (q < 0) continue;
                frm_pair_apply(vol, dP, m->p_grad + 3 * (size_t)(b + k), m->p_G + 9 * (size_t)(b + k), out);
                if (m->s_stab[s])
                    for (r = 0; r < 3; r++) out[3 + r] += stq[3 * k + r];
                /* row block slots[q], column 6 slots[j] + e: (mask P_f)^T out */
                frm__coarse_restrict(m, m->p_frame[b + k], out, y);
                for (c = 0; c < FRM__COARSE_MODES; c++) m->coarse[(size_t)(FRM__COARSE_MODES * slots[q] + c) * D + FRM__COARSE_MODES * slots[j] + e] += a_stiff * y[c];
            }
        }
}

/* Row i of the assembled blocks' part of P^T K P (block mode): (mask P_i)^T K_ij (mask P_j)
   for each block, K P_j and then P_i^T by their structure (about 150 multiply-adds a
   block). The blocks hold the lin_hrot term on the diagonal, which the per-frame loop of
   frm__coarse_build then does not add again. */
static void frm__coarse_row(frm_model *m, int i, double a_stiff)
{
    const int NM = FRM__COARSE_MODES;
    int e, r, c, D = NM * m->agg_count;
    unsigned mi = frm__coarse_mask(m, i);
    double di[3];
    if (!mi) return;
    for (r = 0; r < 3; r++) di[r] = (double)m->pos[3 * i + r] - m->agg_centre[3 * m->f_agg[i] + r];
    for (e = m->blk_start[i]; e < m->blk_start[i + 1]; e++) {
        const frm_real *K = m->blocks + 36 * (size_t)e;
        int f = m->blk_col[e];
        unsigned mj = frm__coarse_mask(m, f);
        double Km[36], X[6 * FRM__COARSE_MODES], Y[FRM__COARSE_MODES * FRM__COARSE_MODES], dj[3], *blk;
        if (!mj) continue;
        for (r = 0; r < 3; r++) dj[r] = (double)m->pos[3 * f + r] - m->agg_centre[3 * m->f_agg[f] + r];
        for (r = 0; r < 6; r++)
            for (c = 0; c < 6; c++) Km[6 * r + c] = ((mi >> r) & 1) && ((mj >> c) & 1) ? (double)K[6 * r + c] : 0.0;
        for (r = 0; r < 6; r++) { /* X = Km P_j: (K_t, K_w + K_t (e_k x d), K_w) */
            const double *k = Km + 6 * r;
            double *x = X + NM * r;
            x[0] = k[0], x[1] = k[1], x[2] = k[2];
            x[3] = k[3] + (k[2] * dj[1] - k[1] * dj[2]); /* K_t (e_k x d) */
            x[4] = k[4] + (k[0] * dj[2] - k[2] * dj[0]);
            x[5] = k[5] + (k[1] * dj[0] - k[0] * dj[1]);
            if (NM > 6) x[6] = k[3], x[7] = k[4], x[8] = k[5];
        }
        for (c = 0; c < NM; c++) { /* Y = P_i^T X: (X_t, X_w + d x X_t, X_w) */
            double t0 = X[c], t1 = X[NM + c], t2 = X[2 * NM + c];
            Y[c] = t0, Y[NM + c] = t1, Y[2 * NM + c] = t2;
            Y[3 * NM + c] = X[3 * NM + c] + (di[1] * t2 - di[2] * t1);
            Y[4 * NM + c] = X[4 * NM + c] + (di[2] * t0 - di[0] * t2);
            Y[5 * NM + c] = X[5 * NM + c] + (di[0] * t1 - di[1] * t0);
            if (NM > 6) Y[6 * NM + c] = X[3 * NM + c], Y[7 * NM + c] = X[4 * NM + c], Y[8 * NM + c] = X[5 * NM + c];
        }
        blk = m->coarse + (size_t)(NM * m->f_agg[i]) * D + NM * m->f_agg[f];
        for (r = 0; r < NM; r++)
            for (c = 0; c < NM; c++) blk[(size_t)r * D + c] += a_stiff * Y[NM * r + c];
    }
}

static void frm__coarse_build(frm_model *m, double a_mass, double a_stiff)
{
    int A = m->agg_count, D = FRM__COARSE_MODES * A, i, s, j, k, r, c;
    double *Ac = m->coarse, *cnt = m->coarse_rhs, *ctr = m->agg_centre;
    m->coarse_ready = 0;
    if (!A) return;
    memset(Ac, 0, sizeof(double) * (size_t)D * (size_t)D);
    memset(ctr, 0, sizeof(double) * 3 * (size_t)A);
    for (k = 0; k < A; k++) cnt[k] = 0;
    for (i = 0; i < m->frame_count; i++)
        if (frm__coarse_mask(m, i)) {
            for (r = 0; r < 3; r++) ctr[3 * m->f_agg[i] + r] += (double)m->pos[3 * i + r];
            cnt[m->f_agg[i]] += 1;
        }
    for (k = 0; k < A; k++)
        for (r = 0; r < 3; r++) ctr[3 * k + r] /= cnt[k] > 0 ? cnt[k] : 1;
    if (a_stiff != 0 && m->lin_mode == FRM_STIFFNESS_BLOCKS)
        for (i = 0; i < m->frame_count; i++)
            frm__coarse_row(m, i, a_stiff);
    else if (a_stiff != 0)
        for (s = 0; s < m->sample_count; s++)
            frm__coarse_sample(m, s, a_stiff);
    for (i = 0; i < m->frame_count; i++) { /* per frame: frame-own terms, regularisation, mass */
        double A6[36], PM[6 * FRM__COARSE_MODES], T[6 * FRM__COARSE_MODES], *blk;
        frm_real col[6];
        if (!frm__coarse_mask(m, i)) continue;
        blk = Ac + (size_t)(FRM__COARSE_MODES * m->f_agg[i]) * D + FRM__COARSE_MODES * m->f_agg[i];
        frm__mass_matrix(m, i, A6);
        for (k = 0; k < 36; k++) A6[k] *= a_mass;
        if (a_stiff != 0) {
            frm_real H[36];
            for (k = 0; k < 36; k++) H[k] = 0;
            if (m->lin_mode != FRM_STIFFNESS_BLOCKS) frm__add_rotational(m->lin_hrot + 6 * (size_t)i, H); /* in the blocks */
            for (k = 3; k < 6; k++) H[7 * k] += (frm_real)(m->solve_regularization * fabs((double)m->kdiag[36 * (size_t)i + 7 * k]));
            for (k = 0; k < 36; k++) A6[k] += a_stiff * (double)H[k];
        }
        for (c = 0; c < FRM__COARSE_MODES; c++) { /* PM = mask P_i, 6 x modes */
            frm__coarse_mode(m, i, c, col);
            for (r = 0; r < 6; r++) PM[FRM__COARSE_MODES * r + c] = (double)col[r];
        }
        for (r = 0; r < 6; r++)
            for (c = 0; c < FRM__COARSE_MODES; c++) {
                double t = 0;
                for (k = 0; k < 6; k++) t += A6[6 * r + k] * PM[FRM__COARSE_MODES * k + c];
                T[FRM__COARSE_MODES * r + c] = t;
            }
        for (r = 0; r < FRM__COARSE_MODES; r++)
            for (c = 0; c < FRM__COARSE_MODES; c++) {
                double t = 0;
                for (k = 0; k < 6; k++) t += PM[FRM__COARSE_MODES * k + r] * T[FRM__COARSE_MODES * k + c];
                blk[(size_t)r * D + c] += t;
            }
    }
    for (r = 0; r < D; r++) /* the symmetric part */
        for (c = 0; c < r; c++) {
            double t = 0.5 * (Ac[(size_t)r * D + c] + Ac[(size_t)c * D + r]);
            Ac[(size_t)r * D + c] = Ac[(size_t)c * D + r] = t;
        }
    for (k = 0; k < D; k++) cnt[k] = Ac[(size_t)k * D + k];
    for (k = 0; k < D; k++) { /* Cholesky, lower triangle, in place */
        double *Lk = Ac + (size_t)k * D, dk = Lk[k];
        for (j = 0; j < k; j++) dk -= Lk[j] * Lk[j];
        if (!(dk > 1e-10 * cnt[k]) || !frm__finite(dk)) {
            for (i = k; i < D; i++) Ac[(size_t)i * D + k] = 0.0;
            continue;
        }
        dk = sqrt(dk);
        Lk[k] = dk;
        for (i = k + 1; i < D; i++) {
            double *Li = Ac + (size_t)i * D, t = Li[k];
            for (j = 0; j < k; j++) t -= Li[j] * Lk[j];
            Li[k] = t / dk;
        }
    }
    m->coarse_ready = 1;
}

/* z += P A_c^-1 P^T r (P masked by the held components). */
static void frm__coarse_apply(frm_model *m, const frm_real *rv, frm_real *z)
{
    int A = m->agg_count, D = FRM__COARSE_MODES * A, i, j;
    double *y = m->coarse_rhs, *L = m->coarse;
    memset(y, 0, sizeof(double) * (size_t)D);
    for (i = 0; i < m->frame_count; i++) /* y = P^T r */
        if (frm__coarse_mask(m, i)) frm__coarse_restrict(m, i, rv + 6 * i, y + FRM__COARSE_MODES * m->f_agg[i]);
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
    for (i = D - 1; i >= 0; i--) { /* L^T x = y' */
        double t = y[i], Lii = L[(size_t)i * D + i];
        if (Lii == 0.0) {
            y[i] = 0.0;
            continue;
        }
        for (j = i + 1; j < D; j++) t -= L[(size_t)j * D + i] * y[j];
        y[i] = t / Lii;
    }
    for (i = 0; i < m->frame_count; i++) /* z += P u */
        if (frm__coarse_mask(m, i)) frm__coarse_prolong(m, i, y + FRM__COARSE_MODES * m->f_agg[i], z + 6 * i);
}

/* >>solver ----------------------------------------------------------------------------- */

/* Zeroes the components that are not solved for: fixed and driven frames, held axes. */
static void frm__mask(const frm_model *m, frm_real *v)
{
    int i, k;
    for (i = 0; i < m->frame_count; i++)
        if (m->state[i] != FRM__FREE)
            for (k = 0; k < 6; k++) v[6 * i + k] = 0;
        else if (m->axes[i])
            for (k = 0; k < 6; k++)
                if ((m->axes[i] >> k) & 1) v[6 * i + k] = 0;
}

/* out = (a_mass M + a_stiff K) v on the free components, 0 on the others. */
static void frm__system_product(frm_model *m, double a_mass, double a_stiff, const frm_real *v, frm_real *out)
{
    int i, k;
    frm__stiffness_product(m, v, out, 0);
    for (i = 0; i < m->frame_count; i++) {
        double mv[6] = {0, 0, 0, 0, 0, 0};
        double reg[6] = {0, 0, 0, 0, 0, 0};
        if (m->state[i] != FRM__FREE) {
            for (k = 0; k < 6; k++) out[6 * i + k] = 0;
            continue;
        }
        if (a_mass != 0) frm__mass_apply(m, i, v + 6 * i, mv);
        if (m->solve_regularization != 0)
            for (k = 3; k < 6; k++) reg[k] = m->solve_regularization * fabs((double)m->kdiag[36 * (size_t)i + 7 * k]) * v[6 * i + k];
        for (k = 0; k < 6; k++) out[6 * i + k] = (frm_real)(a_stiff * ((double)out[6 * i + k] + reg[k]) + a_mass * mv[k]);
    }
    frm__mask(m, out);
}

/* z = P r per frame, plus the coarse correction (built here at the first use after
   frm__build_precond). */
static void frm__precond_apply(frm_model *m, const frm_real *r, frm_real *z)
{
    int i, a, b;
    for (i = 0; i < m->frame_count; i++) {
        const frm_real *P = m->precond + 36 * (size_t)i, *x = r + 6 * i;
        for (a = 0; a < 6; a++) {
            frm_real t = 0;
            for (b = 0; b < 6; b++) t += P[6 * a + b] * x[b];
            z[6 * i + a] = t;
        }
    }
    if (m->coarse_use) {
        if (!m->coarse_ready) frm__coarse_build(m, m->precond_mass, m->precond_stiff);
        frm__coarse_apply(m, r, z);
    }
}

static double frm__dot(const frm_model *m, const frm_real *a, const frm_real *b)
{
    double s[4] = {0, 0, 0, 0};
    int k, n6 = 6 * m->frame_count;
    for (k = 0; k < n6; k++) s[k & 3] += (double)a[k] * (double)b[k];
    return (s[0] + s[1]) + (s[2] + s[3]);
}

#define FRM__CG_OK 0
#define FRM__CG_CAP 1
#define FRM__CG_NEGATIVE 2
#define FRM__CG_NOT_FINITE 3

/* Block-Jacobi preconditioned CG on (a_mass M + a_stiff K) x = b over the free components
   (b and the initial x are masked here). Stops at |r| <= tolerance |b|, at the cap
   (FRM__CG_CAP), on a direction of non-positive curvature (FRM__CG_NEGATIVE: x then holds
   the last iterate, or the preconditioned residual if that happened at once; counted in
   stats.negative_curvature), or on a non-finite |b|^2 or iterate (FRM__CG_NOT_FINITE: an
   overflowing load must never pass an infinite tolerance). The vector work is serial, in a
   fixed order. */
static int frm__cg(frm_model *m, double a_mass, double a_stiff, double tolerance, frm_real *b, frm_real *x)
{
    frm_real *r = m->cg_r, *z = m->cg_z, *p = m->cg_p, *q = m->cg_q;
    int k, it, n6 = 6 * m->frame_count, status = FRM__CG_OK, nonzero = 0;
    double bb, rr, rz, tol2;
    frm__mask(m, b);
    frm__mask(m, x);
    for (k = 0; k < n6; k++) nonzero |= x[k] != 0;
    bb = frm__dot(m, b, b);
    m->stats.cg_iterations_last = 0;
    m->stats.cg_residual = 0;
    if (!frm__finite(bb)) return FRM__CG_NOT_FINITE;
    if (bb == 0) {
        memset(x, 0, sizeof(frm_real) * (size_t)n6);
        return FRM__CG_OK;
    }
    tol2 = tolerance * tolerance * bb;
    if (nonzero) {
        frm__system_product(m, a_mass, a_stiff, x, q);
        for (k = 0; k < n6; k++) r[k] = b[k] - q[k];
    } else
        memcpy(r, b, sizeof(frm_real) * (size_t)n6);
    frm__precond_apply(m, r, z);
    memcpy(p, z, sizeof(frm_real) * (size_t)n6);
    rr = frm__dot(m, r, r);
    rz = frm__dot(m, r, z);
    for (it = 0; it < m->cg_max_iterations && rr > tol2; it++) {
        double pq, alpha, beta, rz_new;
        frm__system_product(m, a_mass, a_stiff, p, q);
        pq = frm__dot(m, p, q);
        if (!(pq > 0) || !(rz > 0)) {
            status = frm__finite(pq) && frm__finite(rz) ? FRM__CG_NEGATIVE : FRM__CG_NOT_FINITE;
            if (it == 0) memcpy(x, z, sizeof(frm_real) * (size_t)n6);
            break;
        }
        alpha = rz / pq;
        for (k = 0; k < n6; k++) {
            x[k] += (frm_real)alpha * p[k];
            r[k] -= (frm_real)alpha * q[k];
        }
        frm__precond_apply(m, r, z);
        rr = frm__dot(m, r, r);
        rz_new = frm__dot(m, r, z);
        beta = rz_new / rz;
        rz = rz_new;
        for (k = 0; k < n6; k++) p[k] = z[k] + (frm_real)beta * p[k];
    }
    if (status == FRM__CG_OK && !frm__finite(rr)) status = FRM__CG_NOT_FINITE;
    if (status == FRM__CG_OK && !(rr <= tol2)) status = FRM__CG_CAP;
    if (status == FRM__CG_NEGATIVE) m->stats.negative_curvature++;
    m->stats.cg_iterations_last = it;
    m->stats.cg_iterations += it;
    m->stats.cg_residual = (frm_real)sqrt(rr / bb);
    m->lin_iterations = it;
    /* a short solve (a Newton iteration near convergence) does not predict the next: the
       probe's or the next increment's solves are long again */
    m->lin_predict = it > m->lin_predict / 2 ? it : m->lin_predict / 2;
    if (!m->coarse_use) m->coarse_plain = it;
    return status;
}

/* Every linear solve of the header goes through here: (a_mass M + a_stiff K) x = b over
   the free components to |r| <= tolerance |b|, by the model's linear_solver. Returns the
   FRM__CG_* statuses (OK, CAP, NEGATIVE, NOT_FINITE), which the Newton loops map to
   FRM_OK, FRM_ERR_NO_CONVERGENCE (cap; negative curvature when no retry helps) and
   FRM_ERR_NOT_FINITE. A new solver adds a frm_linear_solver value and a case here, with
   the same statuses. */
static int frm__btd_model_solve(frm_model *m, double a_mass, double a_stiff, double tolerance, frm_real *b, frm_real *x);
static int frm__linear_solve(frm_model *m, double a_mass, double a_stiff, double tolerance, frm_real *b, frm_real *x)
{
    switch (m->linear_solver) {
    case FRM_LINEAR_SOLVER_BTD:
        return frm__btd_model_solve(m, a_mass, a_stiff, tolerance, b, x);
    case FRM_LINEAR_SOLVER_CG:
    default: {
        int st = frm__cg(m, a_mass, a_stiff, tolerance, b, x);
        if (st == FRM__CG_CAP && !m->coarse_use && m->agg_count && !m->vol_mode) { /* block-Jacobi alone was not enough: */
            int first = m->stats.cg_iterations_last;                /* on from here, and again from its iterate */
            m->coarse_use = 1;
            st = frm__cg(m, a_mass, a_stiff, tolerance, b, x);
            m->stats.cg_iterations_last += first;
        } else if ((st == FRM__CG_NEGATIVE || st == FRM__CG_CAP) && m->coarse_use) {
            /* The coarse correction failed: once more from zero with block-Jacobi alone.
               Near-singular systems (free rotations, no regularisation) make the coarse
               matrix's solve amplify float's round-off until p.Kp or r.z turns non-positive
               (float: frm_chain_link_compliance's cylinder, at 70 iterations); a genuinely
               indefinite system stays NEGATIVE without it, so the minimum checks see the
               same answer at twice the cost. */
            int first = m->stats.cg_iterations_last;
            m->coarse_use = 0;
            memset(x, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
            st = frm__cg(m, a_mass, a_stiff, tolerance, b, x);
            m->coarse_use = 1;
            m->stats.cg_iterations_last += first;
        }
        return st;
    }
    }
}

static void frm__copy_state(const frm_model *m, frm_real *dst)
{
    int i;
    for (i = 0; i < m->frame_count; i++) {
        frm_real *b = dst + 13 * (size_t)i;
        memcpy(b, m->disp + 3 * i, 3 * sizeof(frm_real));
        memcpy(b + 3, m->quat + 4 * i, 4 * sizeof(frm_real));
        memcpy(b + 7, m->vel + 6 * i, 6 * sizeof(frm_real));
    }
}

static void frm__paste_state(frm_model *m, const frm_real *src)
{
    int i;
    for (i = 0; i < m->frame_count; i++) {
        const frm_real *b = src + 13 * (size_t)i;
        memcpy(m->disp + 3 * i, b, 3 * sizeof(frm_real));
        memcpy(m->quat + 4 * i, b + 3, 4 * sizeof(frm_real));
        memcpy(m->vel + 6 * i, b + 7, 6 * sizeof(frm_real));
    }
    frm__update_frames(m);
    m->lin_valid = 0;
}

static void frm__save_state(frm_model *m) { frm__copy_state(m, m->backup); }
static void frm__restore_state(frm_model *m) { frm__paste_state(m, m->backup); }

/* Puts the driven frames at their prescribed poses. */
static void frm__apply_driven(frm_model *m)
{
    int i;
    for (i = 0; i < m->frame_count; i++)
        if (m->state[i] == FRM__DRIVEN) {
            int r;
            for (r = 0; r < 3; r++) m->disp[3 * i + r] = m->target[7 * i + r] - m->rest_pos[3 * i + r];
            memcpy(m->quat + 4 * i, m->target + 7 * i + 3, 4 * sizeof(frm_real));
        }
    frm__update_frames(m);
    m->lin_valid = 0;
}

/* Free frames: x = x0 + alpha dx, q = exp(alpha dtheta) q0 (x0, q0 from the backup). */
static void frm__set_trial(frm_model *m, const frm_real *step, double alpha)
{
    int i, r;
    for (i = 0; i < m->frame_count; i++) {
        const frm_real *b = m->backup + 13 * (size_t)i;
        frm_real t[3];
        if (m->state[i] != FRM__FREE) continue;
        for (r = 0; r < 3; r++) {
            m->disp[3 * i + r] = b[r] + (frm_real)alpha * step[6 * i + r];
            t[r] = (frm_real)alpha * step[6 * i + 3 + r];
        }
        memcpy(m->quat + 4 * i, b + 3, 4 * sizeof(frm_real));
        frm_quat_integrate(m->quat + 4 * i, t);
    }
}

/* The step-time precision check (desc.precision_limit): eps(frm_real) max |u| against
   precision_limit h_min. */
static int frm__check_precision(const frm_model *m)
{
    double top = 0, eps = FRM__IS_FLOAT ? FLT_EPSILON : DBL_EPSILON;
    int k;
    if (!(m->precision_limit > 0)) return FRM_OK;
    for (k = 0; k < 3 * m->frame_count; k++) {
        double u = fabs((double)m->disp[k]);
        if (u > top) top = u;
    }
    return eps * top > m->precision_limit * m->h_min ? FRM_ERR_PRECISION : FRM_OK;
}

/* det F of every sample at the current state. mark: records which are inverted (the start
   of a step or solve) and returns 0; otherwise sets stats.inverted to the inverted count
   and returns how many were not inverted at the mark. */
static int frm__inversions(frm_model *m, int mark)
{
    int s, total = 0, fresh = 0;
    frm__update_frames(m);
    for (s = 0; s < m->sample_count; s++) {
        int b = m->s_start[s], inv;
        frm_real H[9], J;
        frm_sample_deformation(m->s_start[s + 1] - b, m->p_frame + b, m->p_weight + b, m->p_grad + 3 * b,
                               m->p_rlev + 3 * b, NULL, m->disp, m->relm, H, NULL, NULL, NULL);
        J = 1 + frm_det_minus_one(H);
        inv = !(J > 0);
        if (mark) m->s_inverted[s] = (unsigned char)inv;
        else {
            total += inv;
            fresh += inv && !m->s_inverted[s];
        }
    }
    if (!mark) m->stats.inverted = total;
    return fresh;
}

/* The checks of a result before it is accepted: finite, no sample newly inverted (unless
   both laws are undefined at det F <= 0), within the precision limit. */
static int frm__accept(frm_model *m)
{
    int fresh;
    if (!frm__all_finite(m->disp, 3 * (size_t)m->frame_count) || !frm__all_finite(m->quat, 4 * (size_t)m->frame_count) ||
        !frm__all_finite(m->vel, 6 * (size_t)m->frame_count))
        return FRM_ERR_NOT_FINITE;
    fresh = frm__inversions(m, 0);
    if (fresh) return FRM_ERR_INVERTED;
    return frm__check_precision(m);
}

#define FRM__MAX_HALVINGS 12
/* A static increment whose residual has not halved for this many Newton iterations stops
   (mechanisms make it wander) instead of running to the cap; the continuation then cuts
   the increment. Not fewer: near incompressibility the residual (dominated by the stiff
   volumetric modes) swings by orders of magnitude while the energy falls steadily. */
#define FRM__STALL_ITERATIONS 15
/* Least regularisation (fraction of |K_ii| on the rotational diagonal) of a static solve's
   positive-definite attempt, whose K may be singular along rotations nothing holds. */
#define FRM__DEFINITE_REGULARIZATION 1e-6
/* Intermediate increments of the continuation converge to this relative residual (or the
   Newton tolerance if tighter): their equilibria are only starting points. */
#define FRM__INCREMENT_TOLERANCE 1e-3
/* An increment that converged in at most this many Newton iterations doubles the next. */
#define FRM__GROW_ITERATIONS 6

/* The change of the total potential along the line search from the backup state:
       W - W0 + V_g - V_g(0) - alpha f_ext . dq
   (the constant external torques have no potential; their work along the path is exact). */
static double frm__potential_change(const frm_model *m, double W, double W0, const frm_real *dq, double alpha)
{
    double dphi = W - W0;
    int i, r;
    for (i = 0; i < m->frame_count; i++) {
        frm_real cg_new[3];
        const frm_real *b = m->backup + 13 * (size_t)i;
        double mg = m->grav_local[4 * (size_t)i];
        if (m->state[i] != FRM__FREE) continue;
        frm__gravity_moment(m, i, cg_new);
        for (r = 0; r < 3; r++) {
            dphi -= (double)m->gravity[r] *
                    (mg * ((double)m->disp[3 * i + r] - b[r]) + ((double)cg_new[r] - m->lin_gravity[3 * i + r]));
            dphi -= alpha * ((double)m->ext[6 * i + r] * dq[6 * i + r] + (double)m->ext[6 * i + 3 + r] * dq[6 * i + 3 + r]);
        }
    }
    return dphi;
}

/* The static residual's scale: max(|load|, |reactions|), the load being gravity and the
   external forces on the free components, the reactions the total force on the held ones
   (f: the total force, m->force the internal one). */
static double frm__static_scale(const frm_model *m, const frm_real *f, double *load_norm)
{
    frm_real *load = m->work;
    double l, reaction;
    int k;
    for (k = 0; k < 6 * m->frame_count; k++) load[k] = f[k] - m->force[k];
    l = frm__norm_free(m, load);
    reaction = frm__norm_held(m, f);
    if (load_norm) *load_norm = l;
    return l > reaction ? l : reaction;
}

/* One Newton iteration (sec. 3.6): K dq = f by CG, then a backtracking (Armijo) line
   search on the total potential along q(alpha) = q (+) alpha dq. first: the first
   iteration of an increment. tol: the relative residual that counts as converged;
   *converged tells whether it held before the iteration (nothing moves then). *res gets
   |f| after, *scale the residual's scale. */
static int frm__newton_iteration(frm_model *m, int first, double tol, int *converged, double *res, double *scale)
{
    frm_real *f = m->total_force, *dq = m->newton_dx, *trial_f = m->work;
    double W0, norm, slope, best = HUGE_VAL, best_alpha = 0, noise, eta, ref;
    int err, h, attempt, accepted = 0;
    *converged = 0;
    err = frm__force_pass(m, 1, 0, &W0);
    if (err) return err;
    frm__total_force(m, f);
    norm = frm__norm_free(m, f);
    ref = frm__static_scale(m, f, NULL);
    *res = norm;
    *scale = ref;
    if (!frm__finite(norm) || !frm__finite(ref)) return FRM_ERR_NOT_FINITE;
    if (first && m->stats.newton_iterations == 0) m->stats.initial_residual = (frm_real)norm;
    if (norm <= tol * ref) {
        *converged = 1;
        return FRM_OK;
    }
    /* below the round-off floor the residual's 2-norm no longer tells how far the soft modes
       are from equilibrium (a slender steel beam in float: the floor exceeds the load):
       iterate while Newton still halves the residual, stop when it cannot */
    if (norm <= frm__round_off_floor(m)) {
        if (!first && m->floor_residual > 0 && norm > 0.5 * m->floor_residual) {
            *converged = 1;
            return FRM_OK;
        }
        m->floor_residual = norm;
    } else
        m->floor_residual = 0;
    /* inexact Newton (Eisenstat-Walker): solve as accurately as the step can use */
    eta = first ? 1e-3 : (norm / m->newton_previous) * (norm / m->newton_previous);
    if (eta > 1e-3) eta = 1e-3;
    if (eta < 0.1 * tol * ref / norm) eta = 0.1 * tol * ref / norm;
    if (eta < (double)m->cg_tolerance) eta = (double)m->cg_tolerance;
    m->newton_previous = norm;
    for (attempt = 0;; attempt++) {
        int cg;
        frm__prepare_mode(m, frm__choose_mode(m));
        /* the definite attempt adds at least FRM__DEFINITE_REGULARIZATION: its K may be singular */
        m->solve_regularization = attempt && m->regularization < FRM__DEFINITE_REGULARIZATION ? FRM__DEFINITE_REGULARIZATION
                                                                                              : m->regularization;
        frm__build_precond(m, 0.0, 1.0);
        memset(dq, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
        cg = frm__linear_solve(m, 0.0, 1.0, eta, f, dq);
        m->solve_regularization = 0;
        if (cg == FRM__CG_NOT_FINITE) return FRM_ERR_NOT_FINITE;
        if (cg == FRM__CG_CAP) return FRM_ERR_NO_CONVERGENCE; /* one CG policy: capped is not converged */
        slope = frm__dot(m, f, dq);
        if (m->lin_definite || (cg != FRM__CG_NEGATIVE && slope > 0 && frm__all_finite(dq, 6 * (size_t)m->frame_count)))
            break;
        /* the linearisation is indefinite along the search (compressed samples, the rotations'
           second-order terms, gravity): Newton's step may climb; solve with K's positive-definite
           part instead (see SOLVERS) */
        err = frm__force_pass(m, 2, 0, NULL);
        if (err) return err;
        m->stats.definite_solves++;
    }
    if (!(slope > 0) || !frm__all_finite(dq, 6 * (size_t)m->frame_count)) { /* not a descent direction */
        frm__precond_apply(m, f, dq);
        frm__mask(m, dq);
        slope = frm__dot(m, f, dq);
        if (!(slope > 0)) return FRM_ERR_NO_CONVERGENCE;
    }
    frm__save_state(m);
    noise = 64.0 * (FRM__IS_FLOAT ? FLT_EPSILON : DBL_EPSILON) * (fabs(W0) + slope);
    for (h = 0; h <= FRM__MAX_HALVINGS && !accepted; h++) {
        double alpha = ldexp(1.0, -h), W, dphi;
        frm__set_trial(m, dq, alpha);
        err = frm__force_pass(m, 0, 0, &W);
        m->stats.line_search_cuts += h > 0;
        if (err) continue;
        dphi = frm__potential_change(m, W, W0, dq, alpha);
        if (dphi <= -1e-4 * alpha * slope && dphi < -noise) accepted = 1; /* a real decrease (Armijo) */
        else if (dphi <= noise) { /* the energy cannot tell (round-off): the residual must fall */
            double rn;
            frm__total_force(m, trial_f);
            rn = frm__norm_free(m, trial_f);
            if (rn < norm) accepted = 1;
            else if (dphi < best) {
                best = dphi;
                best_alpha = alpha;
            }
        } else if (dphi < best) {
            best = dphi;
            best_alpha = alpha;
        }
    }
    if (!accepted) { /* no Armijo decrease: take the best trial only if the energy did not rise */
        if (best_alpha == 0 || best > noise) {
            frm__restore_state(m);
            return err ? err : FRM_ERR_NO_CONVERGENCE;
        }
        frm__set_trial(m, dq, best_alpha);
        err = frm__force_pass(m, 0, 0, NULL);
        if (err) {
            frm__restore_state(m);
            return err;
        }
    }
    memset(m->vel, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    m->lin_valid = 0;
    frm__total_force(m, f);
    *res = frm__norm_free(m, f);
    *scale = frm__static_scale(m, f, NULL);
    m->stats.newton_iterations++;
    return FRM_OK;
}

static void frm__reset_stats(frm_model *m)
{
    int mode = m->stats.stiffness_mode;
    memset(&m->stats, 0, sizeof m->stats);
    m->stats.stiffness_mode = mode;
}

/* The start of a static solve or Newton step: fresh stats, the precision check, the state
   saved (the backup a failure restores, and start_state, the continuation's origin). */
static int frm__begin_solve(frm_model *m)
{
    int err;
    frm__reset_stats(m);
    err = frm__check_precision(m);
    if (err) return err;
    frm__save_state(m);
    memcpy(m->start_state, m->backup, sizeof(frm_real) * 13 * (size_t)m->frame_count);
    return FRM_OK;
}

FRMDEF int frm_model_newton_step(frm_model *m, frm_real *residual)
{
    double res = 0, scale = 0;
    int converged, err;
    if (!m) return FRM_ERR_ARG;
    err = frm__begin_solve(m);
    if (err) return err;
    m->history_valid = 0;
    frm__apply_driven(m);
    err = frm__newton_iteration(m, 1, (double)m->newton_tolerance, &converged, &res, &scale);
    if (err) {
        memcpy(m->backup, m->start_state, sizeof(frm_real) * 13 * (size_t)m->frame_count);
        frm__restore_state(m);
        return err;
    }
    memset(m->vel, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    m->stats.residual_force = (frm_real)res;
    m->stats.residual = (frm_real)(scale > 0 ? res / scale : (res > 0 ? HUGE_VAL : 0));
    if (residual) *residual = (frm_real)res;
    return FRM_OK;
}

/* Newton iterations of one static increment until |f| <= tol * scale; a residual that has
   not halved in FRM__STALL_ITERATIONS stalls the increment (FRM_ERR_STALLED). */
static int frm__static_increment(frm_model *m, double tol, int *iterations, double *res, double *scale)
{
    double mark = 0;
    int it, mark_it = 0, converged = 0, err = FRM_OK;
    m->floor_residual = 0;
    for (it = 0;; it++) {
        err = frm__newton_iteration(m, it == 0, tol, &converged, res, scale);
        if (err || converged || it == m->newton_max_iterations) break;
        if (it == 0 || *res < mark) { /* progress: the residual halved since the last mark */
            mark = 0.5 * *res;
            mark_it = it;
        } else if (it - mark_it >= FRM__STALL_ITERATIONS) {
            err = FRM_ERR_STALLED;
            break;
        }
    }
    *iterations = it;
    if (!err && !converged) err = FRM_ERR_NO_CONVERGENCE;
    return err;
}

/* The loads at fraction lambda of the continuation: gravity and external loads scaled,
   driven frames on the way from their starting poses (position linearly, orientation
   along the rotation from start to target). */
static void frm__set_load(frm_model *m, double lambda, const frm_real g_full[3])
{
    int i, r;
    for (r = 0; r < 3; r++) m->gravity[r] = (frm_real)(lambda * (double)g_full[r]);
    for (i = 0; i < 6 * m->frame_count; i++) m->ext[i] = (frm_real)(lambda * (double)m->ext_full[i]);
    for (i = 0; i < m->frame_count; i++)
        if (m->state[i] == FRM__DRIVEN) {
            const frm_real *s = m->drive_start + 7 * i, *t = m->target + 7 * i;
            frm_real w[3];
            for (r = 0; r < 3; r++)
                m->disp[3 * i + r] = (frm_real)((double)s[r] + lambda * ((double)t[r] - (double)s[r]) - m->rest_pos[3 * i + r]);
            if (lambda >= 1) memcpy(m->quat + 4 * i, t + 3, 4 * sizeof(frm_real));
            else {
                frm__quat_delta(s + 3, t + 3, w);
                for (r = 0; r < 3; r++) w[r] = (frm_real)(lambda * (double)w[r]);
                memcpy(m->quat + 4 * i, s + 3, 4 * sizeof(frm_real));
                frm_quat_integrate(m->quat + 4 * i, w);
            }
        }
    frm__update_frames(m);
    m->lin_valid = 0;
}

/* Is the converged static state a minimum? A zero residual holds at saddles too (a
   squashed cube's symmetric state, which the model's tilted branches lie below: LIMITS).
   A probe solve K x = b (b a fixed pseudo-random vector on the free components, K the
   full tangent at the state, block-Jacobi CG to 1e-7, float 1e-5) meets a direction p of
   negative curvature where K is indefinite. A saddle is reported when p . K p is below
   -1e3 eps sum_k |p_k (K p)_k| (the round-off of that sum: a singular or nearly singular
   positive semi-definite K, e.g. rotations held only by static_regularization, stays
   within it). FRM_OK (a minimum as far as the probe sees, including a probe at its cap),
   FRM_ERR_UNSTABLE or a force pass's error. */
static int frm__check_minimum(frm_model *m)
{
    /* p, q: CG's direction and its product, which the probe reads after CG stops */
    frm_real *b = m->newton_rhs, *x = m->newton_dx, *p = m->cg_p, *q = m->cg_q;
    int k, cg, err, n6 = 6 * m->frame_count;
    double pq = 0, scale = 0, eps = FRM__IS_FLOAT ? FLT_EPSILON : DBL_EPSILON;
    err = frm__force_pass(m, 1, 0, NULL);
    if (err) return err;
    frm__prepare_mode(m, frm__choose_mode(m));
    m->solve_regularization = m->regularization;
    frm__build_precond(m, 0.0, 1.0);
    for (k = 0; k < n6; k++) {
        unsigned h = (unsigned)k * 2654435761u;
        h ^= h >> 15;
        h *= 2246822519u;
        h ^= h >> 13;
        b[k] = (frm_real)((double)(h & 0xffffu) / 32768.0 - 1.0);
        x[k] = 0;
    }
    /* a curvature probe, not a linear solve: it needs CG's own direction of negative
       curvature, so it calls CG whatever desc.linear_solver chose (the one direct call) */
    cg = frm__cg(m, 0.0, 1.0, FRM__IS_FLOAT ? 1e-5 : 1e-7, b, x);
    m->solve_regularization = 0;
    if (cg == FRM__CG_NOT_FINITE) return FRM_ERR_NOT_FINITE;
    if (cg != FRM__CG_NEGATIVE) return FRM_OK;
    frm__mask(m, p);
    frm__mask(m, q);
    for (k = 0; k < n6; k++) {
        pq += (double)p[k] * (double)q[k];
        scale += fabs((double)p[k] * (double)q[k]);
    }
    return pq < -1e3 * eps * scale ? FRM_ERR_UNSTABLE : FRM_OK;
}

FRMDEF int frm_model_solve_static(frm_model *m)
{
    frm_real g_full[3];
    double lambda = 0, inc = 1, res = 0, scale = 0, tol;
    int i, r, attempts = 0, err = FRM_OK, iterations;
    if (!m) return FRM_ERR_ARG;
    err = frm__begin_solve(m);
    if (err) return err;
    m->history_valid = 0; /* a static solve moves the state (velocities to zero) */
    frm__inversions(m, 1);
    for (r = 0; r < 3; r++) g_full[r] = m->gravity[r];
    memcpy(m->ext_full, m->ext, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    for (i = 0; i < m->frame_count; i++) {
        for (r = 0; r < 3; r++) m->drive_start[7 * i + r] = m->rest_pos[3 * i + r] + m->disp[3 * i + r];
        memcpy(m->drive_start + 7 * i + 3, m->quat + 4 * i, 4 * sizeof(frm_real));
    }
    /* load continuation: the whole load first; an increment that fails (no convergence, a
       stall, an inversion, a non-finite trial) is cut to a quarter from its start, one that
       converged quickly doubles the next */
    while (lambda < 1) {
        double trial = lambda + inc;
        if (trial > 1 - 1e-12) trial = 1;
        tol = trial < 1 && (double)m->newton_tolerance < FRM__INCREMENT_TOLERANCE ? FRM__INCREMENT_TOLERANCE
                                                                               : (double)m->newton_tolerance;
        frm__copy_state(m, m->inc_state);
        frm__set_load(m, trial, g_full);
        err = frm__static_increment(m, tol, &iterations, &res, &scale);
        if (!err) err = frm__accept(m);
        attempts++;
        if (!err) {
            lambda = trial;
            m->stats.increments++;
            if (iterations <= FRM__GROW_ITERATIONS) inc *= 2;
            if (lambda < 1 && attempts >= m->max_increments) {
                err = FRM_ERR_NO_CONVERGENCE;
                break;
            }
            continue;
        }
        frm__paste_state(m, m->inc_state);
        /* a non-finite load or a linear solve at its cap does not get better in smaller
           increments; neither does the precision limit */
        if (err == FRM_ERR_PRECISION || (err == FRM_ERR_NOT_FINITE && !frm__finite(scale)) ||
            (err == FRM_ERR_NO_CONVERGENCE && m->stats.cg_residual > 0 && m->lin_iterations >= m->cg_max_iterations))
            break;
        m->stats.increment_cuts++;
        inc *= 0.25;
        if (inc < m->min_increment || attempts >= m->max_increments) break;
    }
    for (r = 0; r < 3; r++) m->gravity[r] = g_full[r];
    memcpy(m->ext, m->ext_full, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    if (!err) err = frm__check_minimum(m);
    m->stats.residual_force = (frm_real)res;
    m->stats.residual = (frm_real)(scale > 0 ? res / scale : (res > 0 ? HUGE_VAL : 0));
    memset(m->warm_dv, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    if (err) {
        memcpy(m->backup, m->start_state, sizeof(frm_real) * 13 * (size_t)m->frame_count);
        frm__restore_state(m);
        return err;
    }
    memset(m->vel, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    return FRM_OK;
}

/* >>integrator ------------------------------------------------------------------------- */

static int frm__linearize(frm_model *m, double *energy, int definite);

/* Driven frames: the velocity change that reaches the target in dt (into drive). */
static int frm__drive_velocities(frm_model *m, double dt, frm_real *drive)
{
    int i, k, any = 0;
    for (i = 0; i < m->frame_count; i++) {
        for (k = 0; k < 6; k++) drive[6 * i + k] = 0;
        if (m->state[i] == FRM__DRIVEN) {
            frm_real w[3];
            frm__quat_delta(m->quat + 4 * i, m->target + 7 * i + 3, w);
            for (k = 0; k < 3; k++) {
                drive[6 * i + k] = (frm_real)(((double)m->target[7 * i + k] - m->rest_pos[3 * i + k] - m->disp[3 * i + k]) / dt) -
                                   m->vel[6 * i + k];
                drive[6 * i + 3 + k] = (frm_real)(w[k] / dt) - m->vel[6 * i + 3 + k];
            }
            any = 1;
        }
    }
    return any;
}

/* The linearised implicit Euler (desc.implicit_linearized = 1), eq. 3.64 with our sign of
   K (K = -df/dq) and Rayleigh damping D = alpha M + beta K:
       (M (1 + dt alpha) + (dt^2 + dt beta) K) dv = dt (f - (dt + beta) K v - alpha M v),
   one linearisation at the start of the step (M and K at q_t): the first Newton iteration
   of the incremental potential below, with a full step. Driven frames move to their
   targets, which enter the right-hand side through K. */
static int frm__implicit_linearized(frm_model *m, double dt)
{
    frm_real *f = m->total_force, *b = m->newton_rhs, *dv = m->newton_dx, *t = m->work;
    frm_real *drive = m->drive_dv;
    double a_mass = 1.0 + dt * (double)m->mass_damping, a_stiff = dt * dt + dt * (double)m->stiffness_damping;
    int err, i, k, cg, attempt, any_driven;
    frm__save_state(m);
    any_driven = frm__drive_velocities(m, dt, drive);
    for (attempt = 0;; attempt++) {
        err = frm__linearize(m, NULL, attempt);
        if (err) return err;
        frm__mass_update(m);
        frm__total_force(m, f);
        frm__build_precond(m, a_mass, a_stiff);
        /* b = dt (f - (dt + beta) K v - alpha M v) - a_stiff K dv_driven */
        frm__stiffness_product(m, m->vel, t, 0);
        for (i = 0; i < m->frame_count; i++) {
            double mv[6];
            frm__mass_apply(m, i, m->vel + 6 * i, mv);
            for (k = 0; k < 6; k++)
                b[6 * i + k] = (frm_real)(dt * ((double)f[6 * i + k] - (dt + (double)m->stiffness_damping) * t[6 * i + k] -
                                                (double)m->mass_damping * mv[k]));
        }
        if (any_driven) {
            frm__stiffness_product(m, drive, t, 0);
            for (k = 0; k < 6 * m->frame_count; k++) b[k] -= (frm_real)(a_stiff * t[k]);
        }
        memcpy(dv, m->warm_dv, sizeof(frm_real) * 6 * (size_t)m->frame_count); /* warm start */
        cg = frm__linear_solve(m, a_mass, a_stiff, (double)m->cg_tolerance, b, dv);
        if (attempt || cg != FRM__CG_NEGATIVE) break;
        /* M + dt^2 K is indefinite here (compressed samples, the rotations' second-order terms,
           gravity, at a large dt): the step uses K's positive-definite part instead, which
           keeps the system positive definite at any dt */
        m->stats.definite_solves++;
    }
    if (cg != FRM__CG_OK) {
        frm__restore_state(m);
        return cg == FRM__CG_NOT_FINITE ? FRM_ERR_NOT_FINITE : FRM_ERR_NO_CONVERGENCE;
    }
    for (i = 0; i < m->frame_count; i++) {
        frm_real *v = m->vel + 6 * i, th[3];
        if (m->state[i] == FRM__FIXED) {
            for (k = 0; k < 6; k++) v[k] = 0;
            continue;
        }
        for (k = 0; k < 6; k++) v[k] += m->state[i] == FRM__DRIVEN ? drive[6 * i + k] : dv[6 * i + k];
        if (m->state[i] == FRM__DRIVEN) {
            for (k = 0; k < 3; k++) m->disp[3 * i + k] = m->target[7 * i + k] - m->rest_pos[3 * i + k];
            memcpy(m->quat + 4 * i, m->target + 7 * i + 3, 4 * sizeof(frm_real));
            continue;
        }
        for (k = 0; k < 6; k++)
            if ((m->axes[i] >> k) & 1) v[k] = 0;
        for (k = 0; k < 3; k++) {
            m->disp[3 * i + k] += (frm_real)dt * v[k];
            th[k] = (frm_real)dt * v[3 + k];
        }
        frm_quat_integrate(m->quat + 4 * i, th);
    }
    err = frm__accept(m);
    if (err) {
        frm__restore_state(m);
        return err;
    }
    memcpy(m->warm_dv, dv, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    frm__update_frames(m);
    m->lin_valid = 0;
    m->stats.newton_iterations = 1;
    return FRM_OK;
}

/* The step's displacement dq = q - q_t of every free frame from the step's start (kept in
   inc_state): translation, and the rotation vector from the start orientation. */
static void frm__step_displacement(const frm_model *m, frm_real *dq)
{
    int i, k;
    for (i = 0; i < m->frame_count; i++) {
        const frm_real *b = m->inc_state + 13 * (size_t)i;
        for (k = 0; k < 3; k++) dq[6 * i + k] = m->disp[3 * i + k] - b[k];
        frm__quat_delta(b + 3, m->quat + 4 * i, dq + 6 * i + 3);
    }
    frm__mask(m, dq);
}

/* What the implicit Newton minimises towards: implicit Euler's (dt, x_n, v_n) or BDF2's
   (2 dt / 3, xbar, vbar). The Newton variable is z = q - xbar (the step's displacement
   from x_n less the offset xbar - x_n, tangent coordinates at the step's start), and the
   new velocity is v = z / h. */
typedef struct frm__step_target {
    double h;                /* s: dt (implicit Euler) or 2 dt / 3 (BDF2) */
    const frm_real *offset;  /* 6 per frame: xbar - x_n; NULL: zero (implicit Euler) */
    const frm_real *vref;    /* the reference velocity v_n (in inc_state) or vbar */
    int vref_stride;         /* reals between frames in vref: 13 (inc_state + 7) or 6 */
    double warm_scale;       /* the first CG's start: warm_scale (v + last change) */
} frm__step_target;

/* z = q - xbar of every free frame (frm__step_displacement less the target's offset). */
static void frm__step_variable(const frm_model *m, const frm__step_target *t, frm_real *z)
{
    frm__step_displacement(m, z);
    if (t->offset) {
        int k;
        for (k = 0; k < 6 * m->frame_count; k++) z[k] -= t->offset[k];
        frm__mask(m, z);
    }
}

/* The implicit Newton's residual r = h f - M (v - v_ref) - h D v (momentum, N s), with
   dq = h v the step's variable z and kq = K z (zero without stiffness damping). */
static void frm__implicit_residual(const frm_model *m, const frm__step_target *t, const frm_real *f, const frm_real *dq,
                                   const frm_real *kq, frm_real *b)
{
    double alpha_d = (double)m->mass_damping, beta_d = (double)m->stiffness_damping, dt = t->h;
    int i, k;
    for (i = 0; i < m->frame_count; i++) {
        double mq[6], mv[6];
        frm__mass_apply(m, i, dq + 6 * i, mq);
        frm__mass_apply(m, i, t->vref + (size_t)t->vref_stride * (size_t)i, mv);
        for (k = 0; k < 6; k++)
            b[6 * i + k] = (frm_real)(dt * (double)f[6 * i + k] - (mq[k] / dt - mv[k]) - alpha_d * mq[k] -
                                      beta_d * (double)kq[6 * i + k]);
    }
    frm__mask(m, b);
}

/* After a converged implicit step: velocities are the step's variable over h, (q - xbar) / h
   (implicit Euler: the step's displacement over dt; driven frames: the same, fixed: zero);
   their change is the next step's CG warm start. */
static void frm__implicit_velocities(frm_model *m, const frm__step_target *t)
{
    double dt = t->h;
    int i, k;
    for (i = 0; i < m->frame_count; i++) {
        const frm_real *s = m->inc_state + 13 * (size_t)i;
        frm_real *v = m->vel + 6 * i, w[3];
        if (m->state[i] == FRM__FIXED) {
            for (k = 0; k < 6; k++) v[k] = 0;
            continue;
        }
        frm__quat_delta(s + 3, m->quat + 4 * i, w);
        if (t->offset) {
            const frm_real *e = t->offset + 6 * i;
            for (k = 0; k < 3; k++) {
                v[k] = (frm_real)(((double)m->disp[3 * i + k] - (double)s[k] - (double)e[k]) / dt);
                v[3 + k] = (frm_real)(((double)w[k] - (double)e[3 + k]) / dt);
            }
        } else
            for (k = 0; k < 3; k++) {
                v[k] = (frm_real)(((double)m->disp[3 * i + k] - (double)s[k]) / dt);
                v[3 + k] = (frm_real)((double)w[k] / dt);
            }
        for (k = 0; k < 6; k++) {
            if (m->state[i] == FRM__FREE && ((m->axes[i] >> k) & 1)) v[k] = 0;
            m->warm_dv[6 * i + k] = v[k] - s[7 + k]; /* the next step's warm start */
        }
    }
}

/* Implicit Euler as the minimisation of the step's incremental potential (our form of eq.
   3.64 taken to convergence). With dq the step's displacement, v = dq / dt, v_t the start
   velocity, M the mass at the start of the step and D = alpha M + beta K:
       Psi(dq) = 1/2 |dq - dt v_t|_M^2 + dt/2 dq^T D dq + dt^2 (W + V_g - f_ext . dq)
   whose stationarity is M (v - v_t) = dt (f - D v), implicit Euler. Newton iterations
       (M (1 + dt alpha) + (dt^2 + dt beta) K) delta_v = r,
       r = dt f - M (v - v_t) - dt D v            (momentum, N s)
   with a backtracking Armijo line search on Psi (the damping's K frozen per iteration),
   until |r| <= newton_tolerance * max(|r_0|, dt |load|, dt |reactions|), r_0 the residual
   at the step's start (the first iteration is the linearised step). Driven frames are at
   their targets from the first iteration. BDF2 runs the same iterations on its target
   (frm__step_target): h for dt, z = q - xbar for dq, vbar for v_t. */
static int frm__implicit_newton(frm_model *m, const frm__step_target *target)
{
    double dt = target->h;
    frm_real *f = m->total_force, *b = m->newton_rhs, *dv = m->newton_dx;
    /* kd and kq share CG's direction and residual: they are used between CG solves only
       and recomputed after each (the one place these roles alias) */
    frm_real *dq = m->drive_dv, *kd = m->cg_p;
    double alpha_d = (double)m->mass_damping, beta_d = (double)m->stiffness_damping;
    double a_mass = 1.0 + dt * alpha_d, a_stiff = dt * dt + dt * beta_d, ref = 0, norm = 0, previous = 0;
    int err, i, k, it, cg = FRM__CG_CAP, attempt, converged = 0, n6 = 6 * m->frame_count;
    frm_real *kq = m->cg_r; /* K dq; CG overwrites it, so it is recomputed after */
    frm__copy_state(m, m->inc_state);
    frm__mass_update(m);
    frm__apply_driven(m);
    for (it = 0;; it++) {
        double W0, slope, noise, eMd, qMd, dMd, qKd, dKd, eta;
        int h, accepted = 0, cheap = it > 0 && beta_d == 0;
        for (attempt = 0;; attempt++) {
            /* without stiffness damping the residual needs no K: a plain force pass tells
               whether the step has converged before paying for a linearisation */
            err = cheap ? frm__force_pass(m, 0, 0, &W0) : frm__linearize(m, &W0, attempt);
            if (err) return err;
            frm__total_force(m, f);
            frm__step_variable(m, target, dq);
            if (beta_d != 0) frm__stiffness_product(m, dq, kq, 0);
            else memset(kq, 0, sizeof(frm_real) * (size_t)n6);
            frm__implicit_residual(m, target, f, dq, kq, b);
            norm = sqrt(frm__dot(m, b, b));
            if (!frm__finite(norm)) return FRM_ERR_NOT_FINITE;
            if (it == 0 && attempt == 0) {
                double load;
                ref = dt * frm__static_scale(m, f, &load);
                if (norm > ref) ref = norm;
                if (!frm__finite(ref)) return FRM_ERR_NOT_FINITE;
            }
            if (attempt == 0 && (norm <= (double)m->newton_tolerance * ref || (it > 0 && norm <= dt * frm__round_off_floor(m) &&
                                                                             norm > 0.5 * previous))) {
                converged = 1;
                break;
            }
            if (attempt == 0 && it == m->newton_max_iterations) break;
            if (cheap) {
                cheap = 0;
                err = frm__linearize(m, &W0, 0);
                if (err) return err;
            }
            frm__build_precond(m, a_mass, a_stiff);
            eta = it == 0 ? (double)m->cg_tolerance : 1e-3 * (norm / previous) * (norm / previous);
            if (eta < 0.1 * (double)m->newton_tolerance * ref / norm) eta = 0.1 * (double)m->newton_tolerance * ref / norm;
            if (eta > 1e-3) eta = 1e-3;
            if (eta < (double)m->cg_tolerance) eta = (double)m->cg_tolerance;
            if (it == 0 && target->warm_scale == 1) /* warm start: the new velocity, about the start one plus the last step's change */
                for (k = 0; k < n6; k++) dv[k] = m->vel[k] + m->warm_dv[k];
            else if (it == 0)
                for (k = 0; k < n6; k++) dv[k] = (frm_real)(target->warm_scale * ((double)m->vel[k] + (double)m->warm_dv[k]));
            else
                memset(dv, 0, sizeof(frm_real) * (size_t)n6);
            cg = frm__linear_solve(m, a_mass, a_stiff, eta, b, dv);
            if (cg == FRM__CG_NOT_FINITE) return FRM_ERR_NOT_FINITE;
            if (cg == FRM__CG_CAP) return FRM_ERR_NO_CONVERGENCE;
            if (cg == FRM__CG_OK || attempt) break;
            /* M + dt^2 K indefinite (compressed samples, the rotations' second-order terms, gravity,
               a large dt): this iteration uses K's positive-definite part */
            m->stats.definite_solves++;
        }
        if (converged || (attempt == 0 && it == m->newton_max_iterations)) break;
        if (cg != FRM__CG_OK) return FRM_ERR_NO_CONVERGENCE;
        previous = norm;
        /* the Newton step delta = dt dv; Psi along it (the damping's K frozen at this iteration) */
        for (k = 0; k < n6; k++) dv[k] = (frm_real)(dt * (double)dv[k]);
        if (beta_d != 0) {
            frm__stiffness_product(m, dq, kq, 0);
            frm__stiffness_product(m, dv, kd, 0);
        } else {
            memset(kq, 0, sizeof(frm_real) * (size_t)n6);
            memset(kd, 0, sizeof(frm_real) * (size_t)n6);
        }
        eMd = qMd = dMd = 0;
        for (i = 0; i < m->frame_count; i++) {
            double md[6];
            const frm_real *vt = target->vref + (size_t)target->vref_stride * (size_t)i;
            frm__mass_apply(m, i, dv + 6 * i, md);
            for (k = 0; k < 6; k++) {
                double ek = (double)dq[6 * i + k] - dt * (double)vt[k];
                if (m->state[i] != FRM__FREE || ((m->axes[i] >> k) & 1)) continue;
                eMd += ek * md[k];
                qMd += (double)dq[6 * i + k] * md[k];
                dMd += (double)dv[6 * i + k] * md[k];
            }
        }
        qKd = frm__dot(m, kq, dv);
        dKd = frm__dot(m, kd, dv);
        slope = dt * frm__dot(m, b, dv); /* -dPsi/dalpha at 0: the gradient of Psi is -dt r */
        if (!(slope > 0)) return FRM_ERR_NO_CONVERGENCE;
        frm__save_state(m);
        noise = 64.0 * (FRM__IS_FLOAT ? FLT_EPSILON : DBL_EPSILON) * (dt * dt * fabs(W0) + slope);
        for (h = 0; h <= FRM__MAX_HALVINGS && !accepted; h++) {
            double a = ldexp(1.0, -h), W, dpsi;
            frm__set_trial(m, dv, a);
            err = frm__force_pass(m, 0, 0, &W);
            m->stats.line_search_cuts += h > 0;
            if (err) continue;
            dpsi = dt * dt * frm__potential_change(m, W, W0, dv, a) + a * eMd + 0.5 * a * a * dMd +
                   0.5 * dt * alpha_d * (2 * a * qMd + a * a * dMd) + 0.5 * dt * beta_d * (2 * a * qKd + a * a * dKd);
            if (dpsi <= -1e-4 * a * slope && dpsi < -noise) accepted = 1;
            else if (dpsi <= noise) { /* round-off: accept the step only if the residual falls, judged next iteration */
                accepted = 1;
            }
        }
        if (!accepted) {
            frm__restore_state(m);
            return err ? err : FRM_ERR_NO_CONVERGENCE;
        }
        m->stats.newton_iterations++;
    }
    m->stats.residual_force = (frm_real)norm;
    m->stats.residual = (frm_real)(ref > 0 ? norm / ref : 0);
    if (!converged) return FRM_ERR_NO_CONVERGENCE;
    frm__implicit_velocities(m, target);
    return FRM_OK;
}

/* Minimise towards target, accept or restore the step's start. */
static int frm__implicit_solve(frm_model *m, const frm__step_target *target)
{
    int err = frm__implicit_newton(m, target);
    if (!err) err = frm__accept(m);
    if (err) {
        frm__paste_state(m, m->inc_state);
        return err;
    }
    frm__update_frames(m);
    m->lin_valid = 0;
    return FRM_OK;
}

/* The Newton implicit Euler step (FRM_IMPLICIT_EULER). */
static int frm__implicit_euler(frm_model *m, double dt)
{
    frm__step_target t;
    t.h = dt;
    t.offset = NULL;
    t.vref = m->inc_state + 7; /* frm__implicit_newton copies the start state there first */
    t.vref_stride = 13;
    t.warm_scale = 1;
    return frm__implicit_solve(m, &t);
}

/* BDF2 (FRM_BDF2; see SOLVERS, BDF2). With beta = 2 dt / 3, xbar = (4 x_n - x_{n-1}) / 3 and
   vbar = (4 v_n - v_{n-1}) / 3 the step is implicit Euler's minimisation with (beta, xbar,
   vbar) for (dt, x_n, v_n), then v_{n+1} = (x_{n+1} - xbar) / beta. Orientations: in the
   step's tangent coordinates at q_n (world-axis rotation vectors, as implicit Euler's),
   x_{n-1} is phi = log(q_{n-1} q_n^*), so xbar - x_n = -phi / 3 and the world angular
   velocities serve as the coordinate velocities (they differ by phi x omega / 2 at q_{n-1},
   of second order in the rotation over a step: neglected, as implicit Euler neglects the
   gyroscopic terms). Without a history made with the same dt, one implicit Euler step.
   The history is the start state of the last successful step; after a failed step (state
   kept) the next step is implicit Euler. */
static int frm__bdf2(frm_model *m, double dt)
{
    frm__step_target t;
    int i, k, err;
    if (!m->history_valid || m->history_dt != dt) {
        err = frm__implicit_euler(m, dt);
    } else {
        for (i = 0; i < m->frame_count; i++) {
            const frm_real *p = m->history + 13 * (size_t)i;
            frm_real *e = m->step_offset + 6 * i, *vb = m->step_velocity + 6 * i, phi[3];
            frm__quat_delta(m->quat + 4 * i, p + 3, phi);
            for (k = 0; k < 3; k++) {
                e[k] = (frm_real)(((double)m->disp[3 * i + k] - (double)p[k]) / 3);
                e[3 + k] = (frm_real)(-(double)phi[k] / 3);
            }
            for (k = 0; k < 6; k++) vb[k] = (frm_real)((4 * (double)m->vel[6 * i + k] - (double)p[7 + k]) / 3);
        }
        t.h = 2 * dt / 3;
        t.offset = m->step_offset;
        t.vref = m->step_velocity;
        t.vref_stride = 6;
        t.warm_scale = 1.5;
        err = frm__implicit_solve(m, &t);
    }
    if (err) { /* the state and the history are kept; the next step restarts (as heml.h and
                  tensormass.h do after a failed step) */
        m->history_valid = 0;
        return err;
    }
    memcpy(m->history, m->inc_state, sizeof(frm_real) * 13 * (size_t)m->frame_count);
    m->history_valid = 1;
    m->history_dt = dt;
    return FRM_OK;
}

/* Every integrator is one row, indexed by frm_integrator. step(m, dt) advances the state
   by dt (s) from a state whose precision and inversions frm__implicit_step has checked,
   and leaves the state of the step's start on failure. */
typedef struct frm__integrator_ops {
    const char *name;
    int (*step)(frm_model *m, double dt);
    int is_explicit; /* 1: needs no linear solve (none yet) */
} frm__integrator_ops;

static const frm__integrator_ops frm__integrators[FRM_INTEGRATOR_COUNT] = {
    {"implicit Euler", frm__implicit_euler, 0},
    {"implicit Euler, linearised", frm__implicit_linearized, 0},
    {"BDF2", frm__bdf2, 0}};

/* One entry per integrator (negative array size otherwise). */
typedef char frm__integrators_cover_every_integrator[(sizeof frm__integrators / sizeof frm__integrators[0] ==
                                                      FRM_INTEGRATOR_COUNT) ? 1 : -1];

static int frm__implicit_step(frm_model *m, double dt)
{
    int err = frm__check_precision(m);
    if (err) return err;
    frm__inversions(m, 1);
    return frm__integrators[m->integrator].step(m, dt);
}

FRMDEF int frm_model_step(frm_model *m)
{
    if (!m) return FRM_ERR_ARG;
    return frm_model_step_ex(m, m->time_step);
}

FRMDEF int frm_model_step_ex(frm_model *m, frm_real dt)
{
    if (!m) return FRM_ERR_ARG;
    if (!(frm__finite((double)dt) && dt > 0)) return FRM_ERR_TIME_STEP;
    frm__reset_stats(m);
    return frm__implicit_step(m, (double)dt);
}

/* Linearises at the current state (force pass with the stiffness data: the symmetric part
   of K, or with definite its positive-definite part), chooses the mode and prepares it. */
static int frm__linearize(frm_model *m, double *energy, int definite)
{
    int err = frm__force_pass(m, definite ? 2 : 1, 0, energy);
    if (err) return err;
    frm__prepare_mode(m, frm__choose_mode(m));
    return FRM_OK;
}

/* >>boundary-conditions ---------------------------------------------------------------- */

static int frm__check_frame(const frm_model *m, int i)
{
    if (!m) return FRM_ERR_ARG;
    if (i < 0 || i >= m->frame_count) return FRM_ERR_FRAME_RANGE;
    return FRM_OK;
}

static int frm__vec3_finite(const frm_real *v)
{
    return frm__finite((double)v[0]) && frm__finite((double)v[1]) && frm__finite((double)v[2]);
}

FRMDEF int frm_model_fix_frame(frm_model *m, int i)
{
    int err = frm__check_frame(m, i);
    if (err) return err;
    m->state[i] = FRM__FIXED;
    m->axes[i] = 0;
    memset(m->vel + 6 * i, 0, 6 * sizeof(frm_real));
    m->history_valid = 0;
    return FRM_OK;
}

FRMDEF int frm_model_drive_frame(frm_model *m, int i, const frm_real position[3], const frm_real orientation[4])
{
    int err = frm__check_frame(m, i);
    if (err) return err;
    if (!position || !orientation || !frm__vec3_finite(position)) return FRM_ERR_ARG;
    if (!frm__quat_valid(orientation)) return FRM_ERR_QUATERNION;
    if (m->state[i] != FRM__DRIVEN) m->history_valid = 0; /* a new target of a driven frame keeps it */
    m->state[i] = FRM__DRIVEN;
    m->axes[i] = 0;
    memcpy(m->target + 7 * i, position, 3 * sizeof(frm_real));
    frm__quat_normalized(orientation, m->target + 7 * i + 3);
    return FRM_OK;
}

FRMDEF int frm_model_release_frame(frm_model *m, int i)
{
    int err = frm__check_frame(m, i);
    if (err) return err;
    m->state[i] = FRM__FREE;
    m->axes[i] = 0;
    m->history_valid = 0;
    return FRM_OK;
}

FRMDEF int frm_model_set_frame_axes(frm_model *m, int i, unsigned translation_axes, unsigned rotation_axes)
{
    int err = frm__check_frame(m, i), k;
    if (err) return err;
    if (translation_axes > 7 || rotation_axes > 7 || m->state[i] != FRM__FREE) return FRM_ERR_ARG;
    m->axes[i] = (unsigned char)(translation_axes | rotation_axes << 3);
    m->history_valid = 0;
    for (k = 0; k < 6; k++)
        if ((m->axes[i] >> k) & 1) m->vel[6 * i + k] = 0;
    return FRM_OK;
}

FRMDEF int frm_model_frame_axes(const frm_model *m, int i)
{
    int err = frm__check_frame(m, i);
    return err ? err : (int)m->axes[i];
}

FRMDEF int frm_model_frame_state(const frm_model *m, int i)
{
    int err = frm__check_frame(m, i);
    return err ? err : (int)m->state[i];
}

FRMDEF int frm_model_set_external(frm_model *m, int i, const frm_real force[3], const frm_real torque[3])
{
    int err = frm__check_frame(m, i), k;
    if (err) return err;
    if ((force && !frm__vec3_finite(force)) || (torque && !frm__vec3_finite(torque))) return FRM_ERR_ARG;
    for (k = 0; k < 3; k++) {
        m->ext[6 * i + k] = force ? force[k] : 0;
        m->ext[6 * i + 3 + k] = torque ? torque[k] : 0;
    }
    return FRM_OK;
}

FRMDEF void frm_model_clear_external(frm_model *m)
{
    if (m) memset(m->ext, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
}

FRMDEF int frm_model_set_gravity(frm_model *m, const frm_real g[3])
{
    if (!m || !g || !frm__vec3_finite(g)) return FRM_ERR_ARG;
    memcpy(m->gravity, g, 3 * sizeof(frm_real));
    m->lin_valid = 0;
    return FRM_OK;
}

FRMDEF int frm_model_set_solver(frm_model *m, frm_real cg_tolerance, int cg_max_iterations, frm_real newton_tolerance,
                                int newton_max_iterations)
{
    if (!m) return FRM_ERR_ARG;
    if (!(frm__finite((double)cg_tolerance) && cg_tolerance > 0) || cg_max_iterations < 1 ||
        !(frm__finite((double)newton_tolerance) && newton_tolerance > 0) || newton_max_iterations < 1)
        return FRM_ERR_SOLVER;
    m->cg_tolerance = cg_tolerance;
    m->cg_max_iterations = cg_max_iterations;
    m->newton_tolerance = newton_tolerance;
    m->newton_max_iterations = newton_max_iterations;
    return FRM_OK;
}

FRMDEF int frm_model_set_damping(frm_model *m, frm_real mass_damping, frm_real stiffness_damping)
{
    if (!m) return FRM_ERR_ARG;
    if (!(frm__finite((double)mass_damping) && mass_damping >= 0) ||
        !(frm__finite((double)stiffness_damping) && stiffness_damping >= 0))
        return FRM_ERR_DAMPING;
    m->mass_damping = mass_damping;
    m->stiffness_damping = stiffness_damping;
    return FRM_OK;
}

FRMDEF int frm_model_set_integrator(frm_model *m, frm_integrator integrator)
{
    if (!m) return FRM_ERR_ARG;
    if ((unsigned)integrator >= FRM_INTEGRATOR_COUNT) return FRM_ERR_SOLVER;
    m->integrator = (int)integrator;
    m->history_valid = 0;
    return FRM_OK;
}

FRMDEF int frm_model_set_stiffness_mode(frm_model *m, frm_stiffness_mode mode)
{
    if (!m) return FRM_ERR_ARG;
    if ((int)mode < 0 || (int)mode > 2 || (mode != FRM_STIFFNESS_PAIRS && !m->has_blocks)) return FRM_ERR_STIFFNESS_MODE;
    m->stiffness_mode = mode;
    m->lin_valid = 0;
    return FRM_OK;
}

/* >>state ------------------------------------------------------------------------------ */

FRMDEF int frm_model_frame_count(const frm_model *m) { return m ? m->frame_count : 0; }
FRMDEF int frm_model_sample_count(const frm_model *m) { return m ? m->sample_count : 0; }
FRMDEF int frm_model_pair_count(const frm_model *m) { return m ? m->pair_count : 0; }
FRMDEF const frm_real *frm_model_positions(const frm_model *m) { return m ? m->pos : NULL; }
FRMDEF const frm_real *frm_model_orientations(const frm_model *m) { return m ? m->quat : NULL; }
FRMDEF const frm_real *frm_model_velocities(const frm_model *m) { return m ? m->vel : NULL; }
FRMDEF const frm_real *frm_model_displacements(const frm_model *m) { return m ? m->disp : NULL; }
FRMDEF const frm_real *frm_model_rest_positions(const frm_model *m) { return m ? m->rest_pos : NULL; }
FRMDEF const frm_stats *frm_model_last_stats(const frm_model *m) { return m ? &m->stats : NULL; }

FRMDEF frm_linear_solver frm_model_linear_solver(const frm_model *m)
{
    return m ? (frm_linear_solver)m->linear_solver : FRM_LINEAR_SOLVER_COUNT;
}

FRMDEF int frm_model_set_poses(frm_model *m, const frm_real *positions, const frm_real *orientations)
{
    int i;
    if (!m || !positions || !orientations) return FRM_ERR_ARG;
    if (!frm__all_finite(positions, 3 * (size_t)m->frame_count)) return FRM_ERR_ARG;
    for (i = 0; i < m->frame_count; i++)
        if (!frm__quat_valid(orientations + 4 * i)) return FRM_ERR_QUATERNION;
    for (i = 0; i < 3 * m->frame_count; i++) m->disp[i] = positions[i] - m->rest_pos[i];
    for (i = 0; i < m->frame_count; i++) frm__quat_normalized(orientations + 4 * i, m->quat + 4 * i);
    frm__update_frames(m);
    m->lin_valid = 0;
    m->history_valid = 0;
    return FRM_OK;
}

FRMDEF int frm_model_set_velocities(frm_model *m, const frm_real *velocities)
{
    if (!m || !velocities || !frm__all_finite(velocities, 6 * (size_t)m->frame_count)) return FRM_ERR_ARG;
    memcpy(m->vel, velocities, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    m->history_valid = 0;
    return FRM_OK;
}

/* The per-sample outputs (positions, deformation gradients) without the force passes. */
static void frm__outputs_chunks(void *vctx, int begin, int end)
{
    frm_model *m = ((frm__force_ctx *)vctx)->m;
    int c;
    for (c = begin; c < end; c++) {
        int s0 = c * FRM__SAMPLE_CHUNK, s1 = s0 + FRM__SAMPLE_CHUNK, s;
        if (s1 > m->sample_count) s1 = m->sample_count;
        for (s = s0; s < s1; s++) {
            int b = m->s_start[s];
            frm_real *F = m->s_F + 9 * (size_t)s;
            frm_sample_deformation(m->s_start[s + 1] - b, m->p_frame + b, m->p_weight + b, m->p_grad + 3 * b,
                                   m->p_rlev + 3 * b, m->s_rest + 3 * (size_t)s, m->disp, m->relm, F, NULL, NULL,
                                   m->s_pos + 3 * (size_t)s);
            F[0] += 1;
            F[4] += 1;
            F[8] += 1;
        }
    }
}

static void frm__outputs(frm_model *m)
{
    frm__force_ctx ctx;
    ctx.m = m;
    ctx.linearize = 0;
    ctx.outputs = 1;
    frm__update_frames(m);
    frm__run(m, m->sample_chunks, frm__outputs_chunks, &ctx);
}

FRMDEF const frm_real *frm_model_sample_positions(frm_model *m)
{
    if (!m) return NULL;
    frm__outputs(m);
    return m->s_pos;
}

FRMDEF const frm_real *frm_model_deformation_gradients(frm_model *m)
{
    if (!m) return NULL;
    frm__outputs(m);
    return m->s_F;
}

FRMDEF int frm_model_forces(frm_model *m, const frm_real **out)
{
    int err;
    if (out) *out = NULL;
    if (!m || !out) return FRM_ERR_ARG;
    err = frm__force_pass(m, 0, 0, NULL);
    if (err) return err;
    *out = m->force;
    return FRM_OK;
}

FRMDEF int frm_model_total_forces(frm_model *m, const frm_real **out)
{
    int err;
    if (out) *out = NULL;
    if (!m || !out) return FRM_ERR_ARG;
    err = frm__force_pass(m, 0, 0, NULL);
    if (err) return err;
    frm__total_force(m, m->total_force);
    *out = m->total_force;
    return FRM_OK;
}

FRMDEF int frm_model_energy(frm_model *m, frm_energies *out)
{
    double W, kin = 0, grav = 0, ext = 0;
    int err, i, r;
    if (!m || !out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    err = frm__force_pass(m, 0, 0, &W);
    if (err) return err;
    frm__mass_update(m);
    for (i = 0; i < m->frame_count; i++) {
        double mv[6];
        const double *gl = m->grav_local + 4 * (size_t)i;
        const frm_real *Rb = m->rest_rot + 9 * i;
        frm_real cg[3];
        frm__mass_apply(m, i, m->vel + 6 * i, mv);
        frm__gravity_moment(m, i, cg);
        for (r = 0; r < 6; r++) kin += 0.5 * (double)m->vel[6 * i + r] * mv[r];
        for (r = 0; r < 3; r++) {
            double du = (double)m->disp[3 * i + r];
            double c0 = Rb[3 * r] * gl[1] + Rb[3 * r + 1] * gl[2] + Rb[3 * r + 2] * gl[3];
            grav -= (double)m->gravity[r] * (gl[0] * du + ((double)cg[r] - c0));
            ext -= (double)m->ext[6 * i + r] * du;
        }
    }
    out->elastic = W;
    out->kinetic = kin;
    out->gravitational = grav;
    out->external = ext;
    return FRM_OK;
}

FRMDEF int frm_model_mass_block(const frm_model *m, int i, frm_real out[36])
{
    double M[36];
    int err = frm__check_frame(m, i), k;
    if (err) return err;
    if (!out) return FRM_ERR_ARG;
    frm__mass_update((frm_model *)m);
    frm__mass_matrix(m, i, M);
    for (k = 0; k < 36; k++) out[k] = (frm_real)M[k];
    return FRM_OK;
}

FRMDEF size_t frm_model_memory_bytes(const frm_model *m) { return m ? m->block_bytes : 0; }
FRMDEF int frm_model_stabilized_frames(const frm_model *m) { return m ? m->stab_frames : 0; }
FRMDEF int frm_model_view(const frm_model *m, frm_view *out)
{
    int r;
    if (!m || !out) return FRM_ERR_ARG;
    *out = m->view;
    for (r = 0; r < 3; r++) out->gravity[r] = m->gravity[r]; /* the settings as they are now */
    out->time_step = m->time_step;
    out->mass_damping = m->mass_damping;
    out->stiffness_damping = m->stiffness_damping;
    out->cg_tolerance = m->cg_tolerance;
    out->cg_max_iterations = m->cg_max_iterations;
    return FRM_OK;
}

/* >>stiffness-api ---------------------------------------------------------------------- */

FRMDEF int frm_model_prepare_stiffness(frm_model *m)
{
    if (!m) return FRM_ERR_ARG;
    return frm__linearize(m, NULL, 0);
}

FRMDEF int frm_model_apply_stiffness(frm_model *m, const frm_real *v, frm_real *out, int symmetric)
{
    if (!m || !v || !out) return FRM_ERR_ARG;
    if (!m->lin_valid || m->lin_definite) {
        int err = frm__linearize(m, NULL, 0);
        if (err) return err;
    }
    frm__stiffness_product(m, v, out, !symmetric);
    return FRM_OK;
}

FRMDEF int frm_model_assemble_stiffness(frm_model *m)
{
    int err;
    if (!m) return FRM_ERR_ARG;
    if (!m->has_blocks) return FRM_ERR_STIFFNESS_MODE;
    err = frm__force_pass(m, 1, 0, NULL);
    if (err) return err;
    frm__prepare_mode(m, FRM_STIFFNESS_BLOCKS);
    return FRM_OK;
}

FRMDEF const frm_real *frm_model_stiffness_blocks(const frm_model *m, const int **row_start, const int **cols)
{
    if (row_start) *row_start = m && m->has_blocks ? m->blk_start : NULL;
    if (cols) *cols = m && m->has_blocks ? m->blk_col : NULL;
    return m && m->has_blocks ? m->blocks : NULL;
}

FRMDEF int frm_model_stiffness_block(const frm_model *m, int i, int j, frm_real out[36])
{
    int err = frm__check_frame(m, i), e;
    if (err) return err;
    err = frm__check_frame(m, j);
    if (err) return err;
    if (!out) return FRM_ERR_ARG;
    if (!m->has_blocks) return FRM_ERR_STIFFNESS_MODE;
    e = frm__find_block(m, i, j);
    if (e < 0) return FRM_ERR_NOT_NEIGHBORS;
    memcpy(out, m->blocks + 36 * (size_t)e, 36 * sizeof(frm_real));
    return FRM_OK;
}

/* >>shape-functions -------------------------------------------------------------------- */

static double frm__dot3d(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void frm__cross3d(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Tet barycentric functions in double: weights w[4] and constant gradients g[4][3].
   Returns 0 for a flat tetrahedron. */
static int frm__tet_functions(double X[4][3], const double p[3], double w[4], double g[4][3])
{
    double e[3][3], c[3][3], det, longest = 0, d[3];
    int k, r, a, b;
    for (k = 0; k < 3; k++)
        for (r = 0; r < 3; r++) e[k][r] = X[k + 1][r] - X[0][r];
    for (a = 0; a < 4; a++)
        for (b = a + 1; b < 4; b++) {
            double l2 = 0;
            for (r = 0; r < 3; r++) l2 += (X[a][r] - X[b][r]) * (X[a][r] - X[b][r]);
            if (l2 > longest) longest = l2;
        }
    frm__cross3d(e[1], e[2], c[0]);
    frm__cross3d(e[2], e[0], c[1]);
    frm__cross3d(e[0], e[1], c[2]);
    det = frm__dot3d(e[0], c[0]);
    /* a regular tetrahedron has |det| = l^3 / sqrt(2); refuse ones 1e10 times flatter */
    if (!(fabs(det) > 1e-10 * longest * sqrt(longest))) return 0;
    for (r = 0; r < 3; r++) d[r] = p[r] - X[0][r];
    w[0] = 1;
    for (r = 0; r < 3; r++) g[0][r] = 0;
    for (k = 0; k < 3; k++) {
        for (r = 0; r < 3; r++) {
            g[k + 1][r] = c[k][r] / det;
            g[0][r] -= g[k + 1][r];
        }
        w[k + 1] = frm__dot3d(g[k + 1], d);
        w[0] -= w[k + 1];
    }
    return 1;
}

FRMDEF int frm_shape_tet(const frm_real corners[12], const frm_real point[3], frm_real weights[4], frm_real gradients[12])
{
    double X[4][3], p[3], w[4], g[4][3];
    int k, r;
    if (!corners || !point || !weights || !gradients) return FRM_ERR_ARG;
    if (!frm__all_finite(corners, 12) || !frm__all_finite(point, 3)) return FRM_ERR_ARG;
    for (k = 0; k < 4; k++)
        for (r = 0; r < 3; r++) X[k][r] = (double)corners[3 * k + r];
    for (r = 0; r < 3; r++) p[r] = (double)point[r];
    if (!frm__tet_functions(X, p, w, g)) return FRM_ERR_SHAPE_DEGENERATE;
    for (k = 0; k < 4; k++) {
        weights[k] = (frm_real)w[k];
        for (r = 0; r < 3; r++) gradients[3 * k + r] = (frm_real)g[k][r];
    }
    return FRM_OK;
}

/* Trilinear functions of a hexahedron in double at xi in [0, 1]^3. Returns det(dx/dxi). */
static double frm__hex_functions(double X[8][3], const double xi[3], double p[3], double w[8], double g[8][3])
{
    double dn[8][3], J[9], inv[9], det;
    int a, r, k;
    for (a = 0; a < 8; a++) {
        double f[3], df[3];
        for (k = 0; k < 3; k++) {
            int bit = (a >> k) & 1;
            f[k] = bit ? xi[k] : 1 - xi[k];
            df[k] = bit ? 1 : -1;
        }
        w[a] = f[0] * f[1] * f[2];
        dn[a][0] = df[0] * f[1] * f[2];
        dn[a][1] = f[0] * df[1] * f[2];
        dn[a][2] = f[0] * f[1] * df[2];
    }
    for (r = 0; r < 9; r++) J[r] = 0;
    for (r = 0; r < 3; r++) p[r] = 0;
    for (a = 0; a < 8; a++)
        for (r = 0; r < 3; r++) {
            p[r] += w[a] * X[a][r];
            for (k = 0; k < 3; k++) J[3 * r + k] += X[a][r] * dn[a][k];
        }
    det = J[0] * (J[4] * J[8] - J[5] * J[7]) - J[1] * (J[3] * J[8] - J[5] * J[6]) + J[2] * (J[3] * J[7] - J[4] * J[6]);
    if (!(det > 0)) return det;
    inv[0] = (J[4] * J[8] - J[5] * J[7]) / det;
    inv[1] = (J[2] * J[7] - J[1] * J[8]) / det;
    inv[2] = (J[1] * J[5] - J[2] * J[4]) / det;
    inv[3] = (J[5] * J[6] - J[3] * J[8]) / det;
    inv[4] = (J[0] * J[8] - J[2] * J[6]) / det;
    inv[5] = (J[2] * J[3] - J[0] * J[5]) / det;
    inv[6] = (J[3] * J[7] - J[4] * J[6]) / det;
    inv[7] = (J[1] * J[6] - J[0] * J[7]) / det;
    inv[8] = (J[0] * J[4] - J[1] * J[3]) / det;
    /* grad_x N = J^-T grad_xi N: component c is sum_k inv[k][c] dN/dxi_k */
    for (a = 0; a < 8; a++)
        for (r = 0; r < 3; r++) g[a][r] = inv[r] * dn[a][0] + inv[3 + r] * dn[a][1] + inv[6 + r] * dn[a][2];
    return det;
}

FRMDEF int frm_shape_hex(const frm_real corners[24], const frm_real xi[3], frm_real point[3], frm_real weights[8],
                         frm_real gradients[24], frm_real *jacobian_det)
{
    double X[8][3], x[3], p[3], w[8], g[8][3], det;
    int a, r;
    if (!corners || !xi || !weights || !gradients) return FRM_ERR_ARG;
    if (!frm__all_finite(corners, 24) || !frm__all_finite(xi, 3)) return FRM_ERR_ARG;
    for (a = 0; a < 8; a++)
        for (r = 0; r < 3; r++) X[a][r] = (double)corners[3 * a + r];
    for (r = 0; r < 3; r++) x[r] = (double)xi[r];
    det = frm__hex_functions(X, x, p, w, g);
    if (jacobian_det) *jacobian_det = (frm_real)det;
    if (!(det > 0)) return FRM_ERR_SHAPE_DEGENERATE;
    for (a = 0; a < 8; a++) {
        weights[a] = (frm_real)w[a];
        for (r = 0; r < 3; r++) gradients[3 * a + r] = (frm_real)g[a][r];
    }
    if (point)
        for (r = 0; r < 3; r++) point[r] = (frm_real)p[r];
    return FRM_OK;
}

/* Shepard functions in double (see frm_shape_shepard). X: 3 * count. */
static int frm__shepard_functions(const double *X, int count, const double p[3], double power, double radius,
                                  double *w, double *g)
{
    double d[FRM_MAX_NEIGHBORS > 64 ? FRM_MAX_NEIGHBORS : 64], scale = 0, umax = 0, sum = 0, gsum[3] = {0, 0, 0};
    int i, j, r, hit = -1;
    if (count < 1 || count > 64 || !(power > 0)) return FRM_ERR_ARG;
    for (i = 0; i < count; i++) {
        double s = 0;
        for (r = 0; r < 3; r++) s += (p[r] - X[3 * i + r]) * (p[r] - X[3 * i + r]);
        d[i] = sqrt(s);
        if (d[i] > scale) scale = d[i];
    }
    for (i = 0; i < count; i++)
        for (j = i + 1; j < count; j++) {
            double s = 0;
            for (r = 0; r < 3; r++) s += (X[3 * i + r] - X[3 * j + r]) * (X[3 * i + r] - X[3 * j + r]);
            if (!(sqrt(s) > 1e-12 * scale)) return FRM_ERR_SHAPE_DEGENERATE; /* coincident frames */
        }
    for (i = 0; i < count; i++)
        if (!(d[i] > 1e-12 * scale)) hit = i;
    if (hit >= 0) { /* on a frame: the limit for p > 1 */
        if (!(power > 1)) return FRM_ERR_SHAPE_DEGENERATE;
        for (i = 0; i < count; i++) {
            w[i] = i == hit;
            for (r = 0; r < 3; r++) g[3 * i + r] = 0;
        }
        return FRM_OK;
    }
    /* phi_i = (u_i / u_max)^p with u = 1/d (or 1/d - 1/R), scaled to avoid overflow */
    for (i = 0; i < count; i++) {
        double u = 1.0 / d[i] - (radius > 0 ? 1.0 / radius : 0.0);
        if (u > umax) umax = u;
    }
    if (!(umax > 0)) return FRM_ERR_SHAPE_DEGENERATE; /* no frame inside the radius */
    for (i = 0; i < count; i++) {
        double u = 1.0 / d[i] - (radius > 0 ? 1.0 / radius : 0.0), phi = 0, dphi = 0;
        if (u > 0) {
            phi = pow(u / umax, power);
            /* d phi / dx = p (u/umax)^(p-1) / umax * du/dx, du/dx = -(x - X_i) / d^3 */
            dphi = -power * pow(u / umax, power - 1) / umax / (d[i] * d[i] * d[i]);
        }
        w[i] = phi;
        for (r = 0; r < 3; r++) {
            g[3 * i + r] = dphi * (p[r] - X[3 * i + r]);
            gsum[r] += g[3 * i + r];
        }
        sum += phi;
    }
    for (i = 0; i < count; i++) {
        w[i] /= sum;
        for (r = 0; r < 3; r++) g[3 * i + r] = (g[3 * i + r] - w[i] * gsum[r]) / sum;
    }
    return FRM_OK;
}

FRMDEF int frm_shape_shepard(const frm_real *frames, int count, const frm_real point[3], frm_real power, frm_real radius,
                             frm_real *weights, frm_real *gradients)
{
    double X[3 * 64], p[3], w[64], g[3 * 64];
    int i, err;
    if (!frames || !point || !weights || !gradients || count < 1 || count > 64) return FRM_ERR_ARG;
    if (!frm__all_finite(frames, 3 * (size_t)count) || !frm__all_finite(point, 3)) return FRM_ERR_ARG;
    if (!(frm__finite((double)power) && power > 1) || !frm__finite((double)radius)) return FRM_ERR_ARG;
    for (i = 0; i < 3 * count; i++) X[i] = (double)frames[i];
    for (i = 0; i < 3; i++) p[i] = (double)point[i];
    err = frm__shepard_functions(X, count, p, (double)power, (double)radius, w, g);
    if (err) return err;
    for (i = 0; i < count; i++) weights[i] = (frm_real)w[i];
    for (i = 0; i < 3 * count; i++) gradients[i] = (frm_real)g[i];
    return FRM_OK;
}

/* Cholesky inverse of a symmetric 4x4; 0 if a pivot falls below 1e-10 of the largest
   diagonal entry (a singular or nearly singular moment matrix). */
static int frm__invert4(const double A[16], double inv[16])
{
    double L[16], y[4], dmax = 0;
    int i, j, k, c;
    memset(L, 0, sizeof L);
    for (i = 0; i < 4; i++)
        if (A[5 * i] > dmax) dmax = A[5 * i];
    for (j = 0; j < 4; j++) {
        double d = A[5 * j];
        for (k = 0; k < j; k++) d -= L[4 * j + k] * L[4 * j + k];
        if (!(d > 1e-10 * dmax)) return 0;
        L[5 * j] = sqrt(d);
        for (i = j + 1; i < 4; i++) {
            double s = A[4 * i + j];
            for (k = 0; k < j; k++) s -= L[4 * i + k] * L[4 * j + k];
            L[4 * i + j] = s / L[5 * j];
        }
    }
    for (c = 0; c < 4; c++) {
        for (i = 0; i < 4; i++) {
            double s = (i == c);
            for (k = 0; k < i; k++) s -= L[4 * i + k] * y[k];
            y[i] = s / L[5 * i];
        }
        for (i = 3; i >= 0; i--) {
            double s = y[i];
            for (k = i + 1; k < 4; k++) s -= L[4 * k + i] * inv[4 * k + c];
            inv[4 * i + c] = s / L[5 * i];
        }
    }
    return 1;
}

/* Linear MLS functions in double (see frm_shape_mls). Basis p(y) = [1, (y - x)/R] centred
   at the evaluation point x, kernel phi(r) = (1 - r)^4 (4 r + 1) (Wendland C2), r = d/R:
       N_i = phi_i alpha . p_i,  M alpha = e_0,  M = sum phi_j p_j p_j^T
       dN_i/dx_k = phi_i (beta_k - gamma_k) . p_i + dphi_i/dx_k alpha . p_i,
       beta_k = M^-1 e_{k+1} / R,  gamma_k = M^-1 (dM/dx_k) alpha,
   the derivative taken with the centre fixed (then evaluated at x). */
static int frm__mls_functions(const double *X, int count, const double x[3], double radius, double *w, double *g)
{
    double P[64][4], phi[64], dphi[64][3], M[16], Mi[16], alpha[4], beta[3][4], gamma[3][4];
    int i, a, b, k, inside = 0;
    if (count < 1 || count > 64 || !(radius > 0)) return FRM_ERR_ARG;
    memset(M, 0, sizeof M);
    for (i = 0; i < count; i++) {
        double d2 = 0, d, r;
        for (k = 0; k < 3; k++) {
            P[i][1 + k] = (X[3 * i + k] - x[k]) / radius;
            d2 += P[i][1 + k] * P[i][1 + k];
        }
        P[i][0] = 1;
        r = sqrt(d2);
        d = r * radius;
        (void)d;
        if (r < 1) {
            double o = 1 - r;
            phi[i] = o * o * o * o * (4 * r + 1);
            /* dphi/dx = dphi/dr dr/dx = -20 r o^3 * (x - X_i) / (d R) = 20 o^3 P_i / R */
            for (k = 0; k < 3; k++) dphi[i][k] = 20 * o * o * o * P[i][1 + k] / radius;
            inside++;
        } else {
            phi[i] = 0;
            for (k = 0; k < 3; k++) dphi[i][k] = 0;
        }
        for (a = 0; a < 4; a++)
            for (b = 0; b < 4; b++) M[4 * a + b] += phi[i] * P[i][a] * P[i][b];
    }
    if (inside < 4 || !frm__invert4(M, Mi)) return FRM_ERR_SHAPE_DEGENERATE;
    for (a = 0; a < 4; a++) alpha[a] = Mi[4 * a];
    for (k = 0; k < 3; k++) {
        double Ma[4] = {0, 0, 0, 0};
        for (i = 0; i < count; i++) {
            double pa = 0;
            if (phi[i] == 0) continue;
            for (a = 0; a < 4; a++) pa += P[i][a] * alpha[a];
            for (a = 0; a < 4; a++) Ma[a] += dphi[i][k] * P[i][a] * pa;
        }
        for (a = 0; a < 4; a++) {
            beta[k][a] = Mi[4 * a + 1 + k] / radius;
            gamma[k][a] = 0;
            for (b = 0; b < 4; b++) gamma[k][a] += Mi[4 * a + b] * Ma[b];
        }
    }
    for (i = 0; i < count; i++) {
        double ap = 0;
        for (a = 0; a < 4; a++) ap += alpha[a] * P[i][a];
        w[i] = phi[i] * ap;
        for (k = 0; k < 3; k++) {
            double t = 0;
            for (a = 0; a < 4; a++) t += (beta[k][a] - gamma[k][a]) * P[i][a];
            g[3 * i + k] = phi[i] * t + dphi[i][k] * ap;
        }
    }
    return FRM_OK;
}

FRMDEF int frm_shape_mls(const frm_real *frames, int count, const frm_real point[3], frm_real radius, frm_real *weights,
                         frm_real *gradients)
{
    double X[3 * 64], p[3], w[64], g[3 * 64];
    int i, err;
    if (!frames || !point || !weights || !gradients || count < 1 || count > 64) return FRM_ERR_ARG;
    if (!frm__all_finite(frames, 3 * (size_t)count) || !frm__all_finite(point, 3) || !frm__finite((double)radius))
        return FRM_ERR_ARG;
    for (i = 0; i < 3 * count; i++) X[i] = (double)frames[i];
    for (i = 0; i < 3; i++) p[i] = (double)point[i];
    err = frm__mls_functions(X, count, p, (double)radius, w, g);
    if (err) return err;
    for (i = 0; i < count; i++) weights[i] = (frm_real)w[i];
    for (i = 0; i < 3 * count; i++) gradients[i] = (frm_real)g[i];
    return FRM_OK;
}

/* >>sampling --------------------------------------------------------------------------- */

FRMDEF frm_shape_desc frm_shape_default_desc(void)
{
    frm_shape_desc s;
    memset(&s, 0, sizeof s);
    s.shape = FRM_SHAPE_SHEPARD;
    s.support = FRM_SUPPORT_NEAREST;
    s.nearest = 8;
    s.radius = 0;
    s.power = 2;
    s.internal_cookie = FRM__SHAPE_COOKIE;
    return s;
}

FRMDEF frm_poisson_desc frm_poisson_default_desc(void)
{
    frm_poisson_desc p;
    memset(&p, 0, sizeof p);
    p.frame_spacing = (frm_real)0.2;
    p.sample_spacing = (frm_real)0.1;
    p.seed = 1;
    p.volume = 0;
    p.max_points = 1000000;
    p.internal_cookie = FRM__POISSON_COOKIE;
    return p;
}

static void frm__sampling_layout(frm_sampling *s, frm__carver *c)
{
    size_t F = (size_t)s->frame_count, S = (size_t)s->sample_count, P = (size_t)s->pair_count;
    FRM__CARVE(c, s->frame_positions, frm_real, 3 * F);
    FRM__CARVE(c, s->sample_positions, frm_real, 3 * S);
    FRM__CARVE(c, s->sample_volumes, frm_real, S);
    FRM__CARVE(c, s->neighbor_start, int, S + 1);
    FRM__CARVE(c, s->neighbor_frames, int, P);
    FRM__CARVE(c, s->neighbor_weights, frm_real, P);
    FRM__CARVE(c, s->neighbor_gradients, frm_real, 3 * P);
    if (s->cell_count > 0) FRM__CARVE(c, s->sample_cells, int, S);
}

static size_t frm__sampling_bytes(const frm_sampling *s)
{
    frm_sampling t = *s;
    frm__carver c;
    c.base = NULL;
    c.offset = 0;
    frm__sampling_layout(&t, &c);
    return c.offset;
}

/* One block for every array of the sampling (the first array is the block's start). */
static int frm__sampling_alloc(frm_sampling *s, int frames, int samples, int pairs, int cells, const frm_allocator *a)
{
    frm__carver c;
    void *block;
    memset(s, 0, sizeof *s);
    if (a) s->allocator = *a;
    s->frame_count = frames;
    s->sample_count = samples;
    s->pair_count = pairs;
    s->cell_count = cells;
    block = frm__alloc(&s->allocator, frm__sampling_bytes(s));
    if (!block) {
        memset(s, 0, sizeof *s);
        return FRM_ERR_ALLOC;
    }
    c.base = (char *)block;
    c.offset = 0;
    frm__sampling_layout(s, &c);
    return FRM_OK;
}

FRMDEF void frm_sampling_free(frm_sampling *s)
{
    if (!s) return;
    if (s->frame_positions) {
        frm_allocator a = s->allocator;
        frm__free(&a, s->frame_positions, frm__sampling_bytes(s));
    }
    memset(s, 0, sizeof *s);
}

FRMDEF void frm_sampling_apply(const frm_sampling *s, frm_desc *d)
{
    if (!s || !d) return;
    d->frame_positions = s->frame_positions;
    d->frame_orientations = NULL;
    d->frame_count = s->frame_count;
    d->sample_positions = s->sample_positions;
    d->sample_volumes = s->sample_volumes;
    d->sample_count = s->sample_count;
    d->neighbor_start = s->neighbor_start;
    d->neighbor_frames = s->neighbor_frames;
    d->neighbor_weights = s->neighbor_weights;
    d->neighbor_gradients = s->neighbor_gradients;
    d->sample_cells = s->sample_cells;
}

static int frm__check_mesh(const frm_real *nodes, int node_count, const int *cells, int cell_count, int per_cell)
{
    int i;
    if (!nodes || !cells || node_count < 1 || cell_count < 1 || node_count > 100000000 || cell_count > 100000000)
        return FRM_ERR_ARG;
    if (!frm__all_finite(nodes, 3 * (size_t)node_count)) return FRM_ERR_FRAME_NOT_FINITE;
    for (i = 0; i < per_cell * cell_count; i++)
        if (cells[i] < 0 || cells[i] >= node_count) return FRM_ERR_INDEX_RANGE;
    return FRM_OK;
}

/* Gauss-Legendre points and weights on [0, 1], n = 1..4. */
static void frm__gauss(int n, double *x, double *w)
{
    static const double p[4][4] = {{0.0, 0, 0, 0},
                                   {-0.57735026918962576, 0.57735026918962576, 0, 0},
                                   {-0.77459666924148338, 0.0, 0.77459666924148338, 0},
                                   {-0.86113631159405258, -0.33998104358485626, 0.33998104358485626, 0.86113631159405258}};
    static const double q[4][4] = {{2.0, 0, 0, 0},
                                   {1.0, 1.0, 0, 0},
                                   {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0, 0},
                                   {0.34785484513745386, 0.65214515486254614, 0.65214515486254614, 0.34785484513745386}};
    int i;
    for (i = 0; i < n; i++) {
        x[i] = 0.5 * (1.0 + p[n - 1][i]);
        w[i] = 0.5 * q[n - 1][i];
    }
}

FRMDEF int frm_sampling_hexes(frm_sampling *out, const frm_real *nodes, int node_count, const int *hexes, int hex_count,
                              int points, frm_quadrature rule, const frm_allocator *allocator)
{
    double gx[4], gw[4];
    int err, h, a, b, i, j, k, r, s = 0, g3;
    if (!out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    err = frm__check_mesh(nodes, node_count, hexes, hex_count, 8);
    if (err) return err;
    if (points < 1 || points > 4 || ((int)rule != FRM_QUADRATURE_SUBCELL && (int)rule != FRM_QUADRATURE_GAUSS))
        return FRM_ERR_SAMPLING;
    g3 = points * points * points;
    if ((long long)hex_count * g3 * 8 > 2000000000LL) return FRM_ERR_SAMPLING;
    for (h = 0; h < hex_count; h++)
        for (a = 0; a < 8; a++)
            for (b = 0; b < a; b++)
                if (hexes[8 * h + a] == hexes[8 * h + b]) return FRM_ERR_SHAPE_DEGENERATE;
    err = frm__sampling_alloc(out, node_count, hex_count * g3, hex_count * g3 * 8, hex_count, allocator);
    if (err) return err;
    memcpy(out->frame_positions, nodes, sizeof(frm_real) * 3 * (size_t)node_count);
    if (rule == FRM_QUADRATURE_GAUSS) frm__gauss(points, gx, gw);
    else
        for (i = 0; i < points; i++) {
            gx[i] = (i + 0.5) / points;
            gw[i] = 1.0 / points;
        }
    for (h = 0; h < hex_count; h++) {
        double X[8][3];
        for (a = 0; a < 8; a++)
            for (r = 0; r < 3; r++) X[a][r] = (double)nodes[3 * hexes[8 * h + a] + r];
        for (k = 0; k < points; k++)
            for (j = 0; j < points; j++)
                for (i = 0; i < points; i++, s++) {
                    double xi[3], p[3], w[8], g[8][3], det;
                    xi[0] = gx[i];
                    xi[1] = gx[j];
                    xi[2] = gx[k];
                    det = frm__hex_functions(X, xi, p, w, g);
                    if (!(det > 0)) {
                        frm_sampling_free(out);
                        return FRM_ERR_SHAPE_DEGENERATE;
                    }
                    out->neighbor_start[s] = 8 * s;
                    out->sample_cells[s] = h;
                    for (r = 0; r < 3; r++) out->sample_positions[3 * s + r] = (frm_real)p[r];
                    out->sample_volumes[s] = (frm_real)(det * gw[i] * gw[j] * gw[k]);
                    for (a = 0; a < 8; a++) {
                        out->neighbor_frames[8 * s + a] = hexes[8 * h + a];
                        out->neighbor_weights[8 * s + a] = (frm_real)w[a];
                        for (r = 0; r < 3; r++) out->neighbor_gradients[3 * (8 * s + a) + r] = (frm_real)g[a][r];
                    }
                }
    }
    out->neighbor_start[s] = 8 * s;
    return FRM_OK;
}

FRMDEF int frm_sampling_tets(frm_sampling *out, const frm_real *nodes, int node_count, const int *tets, int tet_count,
                             int points, const frm_real *barycentric, const frm_allocator *allocator)
{
    static const double gauss4a = 0.58541019662496845, gauss4b = 0.13819660112501052;
    double bary[4 * 64];
    int err, t, k, a, r, s = 0;
    if (!out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    err = frm__check_mesh(nodes, node_count, tets, tet_count, 4);
    if (err) return err;
    if (points < 1 || points > 64 || (long long)tet_count * points * 4 > 2000000000LL) return FRM_ERR_SAMPLING;
    if (!barycentric) {
        if (points == 1)
            for (k = 0; k < 4; k++) bary[k] = 0.25;
        else if (points == 4)
            for (k = 0; k < 4; k++)
                for (a = 0; a < 4; a++) bary[4 * k + a] = a == k ? gauss4a : gauss4b;
        else
            return FRM_ERR_SAMPLING;
    } else
        for (k = 0; k < points; k++) {
            double sum = 0;
            for (a = 0; a < 4; a++) {
                bary[4 * k + a] = (double)barycentric[4 * k + a];
                if (!frm__finite(bary[4 * k + a])) return FRM_ERR_SAMPLING;
                sum += bary[4 * k + a];
            }
            if (!(fabs(sum - 1.0) <= 1e-6)) return FRM_ERR_SAMPLING;
            for (a = 0; a < 4; a++) bary[4 * k + a] /= sum;
        }
    for (t = 0; t < tet_count; t++)
        for (a = 0; a < 4; a++)
            for (k = 0; k < a; k++)
                if (tets[4 * t + a] == tets[4 * t + k]) return FRM_ERR_SHAPE_DEGENERATE;
    err = frm__sampling_alloc(out, node_count, tet_count * points, tet_count * points * 4, tet_count, allocator);
    if (err) return err;
    memcpy(out->frame_positions, nodes, sizeof(frm_real) * 3 * (size_t)node_count);
    for (t = 0; t < tet_count; t++) {
        double X[4][3], w[4], g[4][3], vol, e[3][3], c[3];
        for (a = 0; a < 4; a++)
            for (r = 0; r < 3; r++) X[a][r] = (double)nodes[3 * tets[4 * t + a] + r];
        if (!frm__tet_functions(X, X[0], w, g)) {
            frm_sampling_free(out);
            return FRM_ERR_SHAPE_DEGENERATE;
        }
        for (a = 0; a < 3; a++)
            for (r = 0; r < 3; r++) e[a][r] = X[a + 1][r] - X[0][r];
        frm__cross3d(e[1], e[2], c);
        vol = fabs(frm__dot3d(e[0], c)) / 6.0;
        for (k = 0; k < points; k++, s++) {
            out->neighbor_start[s] = 4 * s;
            out->sample_cells[s] = t;
            for (r = 0; r < 3; r++) {
                double p = 0;
                for (a = 0; a < 4; a++) p += bary[4 * k + a] * X[a][r];
                out->sample_positions[3 * s + r] = (frm_real)p;
            }
            out->sample_volumes[s] = (frm_real)(vol / points);
            for (a = 0; a < 4; a++) {
                out->neighbor_frames[4 * s + a] = tets[4 * t + a];
                out->neighbor_weights[4 * s + a] = (frm_real)bary[4 * k + a];
                for (r = 0; r < 3; r++) out->neighbor_gradients[3 * (4 * s + a) + r] = (frm_real)g[a][r];
            }
        }
    }
    out->neighbor_start[s] = 4 * s;
    return FRM_OK;
}

FRMDEF int frm_sampling_curve(frm_sampling *out, const frm_real *nodes, int node_count, const frm_real section[2],
                              const frm_real up[3], const frm_allocator *allocator)
{
    double w, h, cy[4], cz[4];
    int err, e, k, r;
    if (!out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (!nodes || !section || node_count < 2 || node_count > 100000000) return FRM_ERR_ARG;
    if (!frm__all_finite(nodes, 3 * (size_t)node_count) || !frm__all_finite(section, 2) ||
        (up && !frm__all_finite(up, 3)))
        return FRM_ERR_ARG;
    w = (double)section[0];
    h = (double)section[1];
    if (!(w > 0) || h < 0) return FRM_ERR_SAMPLING;
    for (k = 0; k < 4; k++) { /* section points: rectangle 2 x 2 Gauss, or a disk at r / sqrt 2 */
        double sy = (k & 1) ? 1.0 : -1.0, sz = (k & 2) ? 1.0 : -1.0;
        if (h > 0) {
            cy[k] = sy * w / (2.0 * sqrt(3.0));
            cz[k] = sz * h / (2.0 * sqrt(3.0));
        } else {
            cy[k] = sy * w / 2.0;
            cz[k] = sz * w / 2.0;
        }
    }
    err = frm__sampling_alloc(out, node_count, 4 * (node_count - 1), 8 * (node_count - 1), node_count - 1, allocator);
    if (err) return err;
    memcpy(out->frame_positions, nodes, sizeof(frm_real) * 3 * (size_t)node_count);
    for (e = 0; e < node_count - 1; e++) {
        double t[3], n[3], b[3], u[3] = {0, 0, 1}, len = 0, un = 0, d, area = h > 0 ? w * h : 3.14159265358979324 * w * w;
        for (r = 0; r < 3; r++) {
            t[r] = (double)nodes[3 * (e + 1) + r] - (double)nodes[3 * e + r];
            len += t[r] * t[r];
        }
        len = sqrt(len);
        if (!(len > 0)) {
            frm_sampling_free(out);
            return FRM_ERR_SAMPLING;
        }
        for (r = 0; r < 3; r++) t[r] /= len;
        if (up)
            for (r = 0; r < 3; r++) u[r] = (double)up[r];
        else if (fabs(t[2]) > 0.70710678118654752) {
            u[1] = 1;
            u[2] = 0;
        }
        d = frm__dot3d(u, t);
        for (r = 0; r < 3; r++) {
            n[r] = u[r] - d * t[r];
            un += u[r] * u[r];
        }
        d = sqrt(frm__dot3d(n, n));
        if (!(d > 1e-3 * sqrt(un))) {
            frm_sampling_free(out);
            return FRM_ERR_SAMPLING;
        }
        for (r = 0; r < 3; r++) n[r] /= d;
        frm__cross3d(t, n, b);
        for (k = 0; k < 4; k++) {
            int s = 4 * e + k, q = 2 * s;
            out->neighbor_start[s] = q;
            out->sample_cells[s] = e;
            out->sample_volumes[s] = (frm_real)(len * area / 4.0);
            for (r = 0; r < 3; r++)
                out->sample_positions[3 * s + r] =
                    (frm_real)(0.5 * ((double)nodes[3 * e + r] + (double)nodes[3 * (e + 1) + r]) + cy[k] * b[r] + cz[k] * n[r]);
            out->neighbor_frames[q] = e;
            out->neighbor_frames[q + 1] = e + 1;
            out->neighbor_weights[q] = (frm_real)0.5;
            out->neighbor_weights[q + 1] = (frm_real)0.5;
            for (r = 0; r < 3; r++) {
                out->neighbor_gradients[3 * q + r] = (frm_real)(-t[r] / len);
                out->neighbor_gradients[3 * (q + 1) + r] = (frm_real)(t[r] / len);
            }
        }
    }
    out->neighbor_start[4 * (node_count - 1)] = 8 * (node_count - 1);
    return FRM_OK;
}

FRMDEF int frm_material_thin(frm_material *m, int dimensions)
{
    double E, nu, mu, lambda;
    if (!m || (dimensions != 1 && dimensions != 2) || (m->law != FRM_LAW_SVK && m->law != FRM_LAW_NEO_HOOKEAN))
        return FRM_ERR_ARG;
    E = (double)m->young_modulus;
    nu = (double)m->poisson_ratio;
    if (!(frm__finite(E) && E > 0 && nu > -1 && nu < 0.5)) return FRM_ERR_MATERIAL;
    mu = E / (2 * (1 + nu));
    lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    lambda = dimensions == 1 ? E - 2 * mu : 2 * mu * lambda / (lambda + 2 * mu);
    m->poisson_ratio = (frm_real)(lambda / (2 * (lambda + mu)));
    m->young_modulus = (frm_real)(mu * (3 * lambda + 2 * mu) / (lambda + mu));
    return FRM_OK;
}

/* A uniform grid over points (the frames), for neighbour queries. */
typedef struct frm__grid {
    double lo[3], h[3], hmin;
    int n[3];
    int *start, *items; /* cell -> point indices, in increasing index */
    size_t bytes;
} frm__grid;

static int frm__grid_cell(const frm__grid *g, const double *p, int axis)
{
    double t = (p[axis] - g->lo[axis]) / g->h[axis];
    int c = t < 0 ? 0 : (t >= g->n[axis] ? g->n[axis] - 1 : (int)t);
    return c;
}

/* Builds the grid with cells of about `cell` metres (cell <= 0: about one point per cell). */
static int frm__grid_build(frm__grid *g, const double *X, int count, double cell, const frm_allocator *a)
{
    double hi[3], ext[3], vol = 1;
    int i, k, dims = 0, cells;
    for (k = 0; k < 3; k++) {
        g->lo[k] = hi[k] = X[k];
        for (i = 1; i < count; i++) {
            if (X[3 * i + k] < g->lo[k]) g->lo[k] = X[3 * i + k];
            if (X[3 * i + k] > hi[k]) hi[k] = X[3 * i + k];
        }
        ext[k] = hi[k] - g->lo[k];
    }
    if (!(cell > 0)) {
        double emax = ext[0] > ext[1] ? (ext[0] > ext[2] ? ext[0] : ext[2]) : (ext[1] > ext[2] ? ext[1] : ext[2]);
        for (k = 0; k < 3; k++)
            if (ext[k] > 1e-9 * emax) {
                vol *= ext[k];
                dims++;
            }
        cell = dims ? pow(vol / count, 1.0 / dims) : 1.0;
        if (!(cell > 0)) cell = 1.0;
    }
    cells = 1;
    g->hmin = HUGE_VAL;
    for (k = 0; k < 3; k++) {
        double nk = ceil(ext[k] / cell);
        g->n[k] = nk < 1 ? 1 : (nk > 512 ? 512 : (int)nk);
        g->h[k] = ext[k] > 0 ? ext[k] / g->n[k] : cell;
        if (g->h[k] <= 0) g->h[k] = cell;
        if (g->n[k] > 1 && g->h[k] < g->hmin) g->hmin = g->h[k];
        cells *= g->n[k];
    }
    if (g->hmin == HUGE_VAL) g->hmin = cell;
    g->bytes = sizeof(int) * ((size_t)cells + 1 + (size_t)count);
    g->start = (int *)frm__alloc(a, g->bytes);
    if (!g->start) return FRM_ERR_ALLOC;
    g->items = g->start + cells + 1;
    memset(g->start, 0, sizeof(int) * ((size_t)cells + 1));
    for (i = 0; i < count; i++) {
        int c = frm__grid_cell(g, X + 3 * i, 0) + g->n[0] * (frm__grid_cell(g, X + 3 * i, 1) + g->n[1] * frm__grid_cell(g, X + 3 * i, 2));
        g->start[c + 1]++;
    }
    for (i = 0; i < cells; i++) g->start[i + 1] += g->start[i];
    for (i = 0; i < count; i++) { /* fill in index order, shifting start back after */
        int c = frm__grid_cell(g, X + 3 * i, 0) + g->n[0] * (frm__grid_cell(g, X + 3 * i, 1) + g->n[1] * frm__grid_cell(g, X + 3 * i, 2));
        g->items[g->start[c]++] = i;
    }
    for (i = cells; i > 0; i--) g->start[i] = g->start[i - 1];
    g->start[0] = 0;
    return FRM_OK;
}

/* Inserts (d, index) into the sorted list of the k best (smallest d, then index). */
static void frm__keep_nearest(double *bd, int *bi, int *count, int k, double d, int index)
{
    int j;
    if (*count == k && (d > bd[k - 1] || (d == bd[k - 1] && index > bi[k - 1]))) return;
    j = *count < k ? (*count)++ : k - 1;
    while (j > 0 && (bd[j - 1] > d || (bd[j - 1] == d && bi[j - 1] > index))) {
        bd[j] = bd[j - 1];
        bi[j] = bi[j - 1];
        j--;
    }
    bd[j] = d;
    bi[j] = index;
}

/* The neighbours of point p: the k nearest (radius <= 0) or all within radius (at most
   `cap`, else returns cap + 1), sorted by distance then index. */
static int frm__grid_query(const frm__grid *g, const double *X, const double *p, int k, double radius, int cap,
                           int *out, double *dist)
{
    int c[3], lo[3], hi[3], ring, count = 0, a;
    for (a = 0; a < 3; a++) c[a] = frm__grid_cell(g, p, a);
    for (ring = 0;; ring++) {
        int x, y, z, done = 1;
        if (radius > 0 && ring > 0) break;
        for (a = 0; a < 3; a++) {
            int span = radius > 0 ? (int)ceil(radius / g->h[a]) : ring;
            lo[a] = c[a] - span;
            hi[a] = c[a] + span;
            if (lo[a] > 0 || hi[a] < g->n[a] - 1) done = 0;
            if (lo[a] < 0) lo[a] = 0;
            if (hi[a] > g->n[a] - 1) hi[a] = g->n[a] - 1;
        }
        for (z = lo[2]; z <= hi[2]; z++)
            for (y = lo[1]; y <= hi[1]; y++)
                for (x = lo[0]; x <= hi[0]; x++) {
                    int cell = x + g->n[0] * (y + g->n[1] * z), e;
                    /* in nearest mode, only the shell of this ring is new */
                    if (radius <= 0 && ring > 0 && abs(x - c[0]) < ring && abs(y - c[1]) < ring && abs(z - c[2]) < ring)
                        continue;
                    for (e = g->start[cell]; e < g->start[cell + 1]; e++) {
                        int i = g->items[e];
                        double d = sqrt((p[0] - X[3 * i]) * (p[0] - X[3 * i]) + (p[1] - X[3 * i + 1]) * (p[1] - X[3 * i + 1]) +
                                        (p[2] - X[3 * i + 2]) * (p[2] - X[3 * i + 2]));
                        if (radius > 0) {
                            if (d < radius) {
                                if (count == cap) return cap + 1;
                                frm__keep_nearest(dist, out, &count, cap, d, i);
                            }
                        } else
                            frm__keep_nearest(dist, out, &count, k, d, i);
                    }
                }
        if (radius > 0) break;
        /* every point not yet seen lies at least ring * hmin away */
        if (done || (count == k && dist[k - 1] <= ring * g->hmin)) break;
    }
    return count;
}

static int frm__check_shape(const frm_shape_desc *sh)
{
    if (sh->internal_cookie != FRM__SHAPE_COOKIE) return FRM_ERR_DESC;
    if ((int)sh->shape != FRM_SHAPE_SHEPARD && (int)sh->shape != FRM_SHAPE_MLS) return FRM_ERR_SAMPLING;
    if (sh->support == FRM_SUPPORT_NEAREST) {
        if (sh->nearest < 1 || sh->nearest > FRM_MAX_NEIGHBORS) return FRM_ERR_SAMPLING;
        if (sh->shape == FRM_SHAPE_MLS && sh->nearest < 4) return FRM_ERR_SAMPLING;
    } else if (sh->support == FRM_SUPPORT_RADIUS) {
        if (!(frm__finite((double)sh->radius) && sh->radius > 0)) return FRM_ERR_SAMPLING;
    } else
        return FRM_ERR_SAMPLING;
    if (sh->shape == FRM_SHAPE_SHEPARD && !(frm__finite((double)sh->power) && sh->power > 1)) return FRM_ERR_SAMPLING;
    return FRM_OK;
}

FRMDEF int frm_sampling_meshless(frm_sampling *out, const frm_real *frames, int frame_count, const frm_real *samples,
                                 int sample_count, frm_real volume, const frm_shape_desc *shape,
                                 const frm_allocator *allocator)
{
    frm_shape_desc sh = shape ? *shape : frm_shape_default_desc();
    frm_allocator alloc;
    frm__grid grid;
    double *X = NULL, dist[FRM_MAX_NEIGHBORS + 1];
    int err, s, i, r, k, pass, pairs = 0, idx[FRM_MAX_NEIGHBORS + 1];
    size_t xbytes;
    if (!out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    memset(&alloc, 0, sizeof alloc);
    if (allocator) alloc = *allocator;
    if (!frames || !samples || frame_count < 1 || sample_count < 1 || frame_count > 100000000 || sample_count > 100000000)
        return FRM_ERR_ARG;
    if (!frm__all_finite(frames, 3 * (size_t)frame_count)) return FRM_ERR_FRAME_NOT_FINITE;
    if (!frm__all_finite(samples, 3 * (size_t)sample_count)) return FRM_ERR_SAMPLE_NOT_FINITE;
    if (!(frm__finite((double)volume) && volume > 0)) return FRM_ERR_SAMPLE_VOLUME;
    err = frm__check_shape(&sh);
    if (err) return err;
    k = sh.support == FRM_SUPPORT_NEAREST ? (sh.nearest < frame_count ? sh.nearest : frame_count) : 0;
    if (sh.shape == FRM_SHAPE_MLS && k > 0 && k < 4) return FRM_ERR_SHAPE_DEGENERATE;
    xbytes = sizeof(double) * 3 * (size_t)frame_count;
    X = (double *)frm__alloc(&alloc, xbytes);
    if (!X) return FRM_ERR_ALLOC;
    for (i = 0; i < 3 * frame_count; i++) X[i] = (double)frames[i];
    err = frm__grid_build(&grid, X, frame_count, sh.support == FRM_SUPPORT_RADIUS ? (double)sh.radius : 0.0, &alloc);
    if (err) {
        frm__free(&alloc, X, xbytes);
        return err;
    }
    /* pass 0 counts the neighbours, pass 1 fills the table */
    for (pass = 0; pass < 2 && !err; pass++) {
        if (pass == 1) {
            err = frm__sampling_alloc(out, frame_count, sample_count, pairs, 0, &alloc);
            if (err) break;
            memcpy(out->frame_positions, frames, sizeof(frm_real) * 3 * (size_t)frame_count);
            memcpy(out->sample_positions, samples, sizeof(frm_real) * 3 * (size_t)sample_count);
            pairs = 0;
        }
        for (s = 0; s < sample_count && !err; s++) {
            double p[3], Xn[3 * FRM_MAX_NEIGHBORS], w[FRM_MAX_NEIGHBORS], g[3 * FRM_MAX_NEIGHBORS], R;
            int n;
            for (r = 0; r < 3; r++) p[r] = (double)samples[3 * s + r];
            n = frm__grid_query(&grid, X, p, k, sh.support == FRM_SUPPORT_RADIUS ? (double)sh.radius : 0.0,
                                FRM_MAX_NEIGHBORS, idx, dist);
            if (n == 0) err = FRM_ERR_NO_NEIGHBOR;
            else if (n > FRM_MAX_NEIGHBORS) err = FRM_ERR_TOO_MANY_NEIGHBORS;
            if (err) break;
            if (pass == 0) {
                pairs += n;
                continue;
            }
            for (i = 0; i < n; i++)
                for (r = 0; r < 3; r++) Xn[3 * i + r] = X[3 * idx[i] + r];
            if (sh.shape == FRM_SHAPE_MLS) {
                /* nearest support: a kernel reaching 1.5 times the k-th distance */
                R = sh.support == FRM_SUPPORT_RADIUS ? (double)sh.radius : 1.5 * dist[n - 1];
                err = frm__mls_functions(Xn, n, p, R, w, g);
            } else
                err = frm__shepard_functions(Xn, n, p, (double)sh.power,
                                             sh.support == FRM_SUPPORT_RADIUS ? (double)sh.radius : 0.0, w, g);
            if (err) break;
            out->neighbor_start[s] = pairs;
            out->sample_volumes[s] = (frm_real)((double)volume / sample_count);
            for (i = 0; i < n; i++, pairs++) {
                out->neighbor_frames[pairs] = idx[i];
                out->neighbor_weights[pairs] = (frm_real)w[i];
                for (r = 0; r < 3; r++) out->neighbor_gradients[3 * pairs + r] = (frm_real)g[3 * i + r];
            }
        }
        if (pass == 1 && !err) out->neighbor_start[sample_count] = pairs;
    }
    frm__free(&alloc, grid.start, grid.bytes);
    frm__free(&alloc, X, xbytes);
    if (err) frm_sampling_free(out);
    return err;
}

/* >>poisson ---------------------------------------------------------------------------- */

/* splitmix64: the same stream on every platform for a seed. */
static double frm__random(unsigned long long *state)
{
    unsigned long long z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * (1.0 / 9007199254740992.0);
}

/* A closed triangle surface for inside tests: triangles binned by their xy bounding box. */
typedef struct frm__surface {
    const frm_real *v;
    const int *t;
    int tri_count, nb[2];
    double lo[3], hi[3], cell[2];
    int *start, *items;
    size_t bytes;
} frm__surface;

/* The 2D edge function of (a, b) at p, computed from the lexicographically smaller end so
   that the two triangles sharing an edge get exactly opposite values. */
static double frm__edge_function(const frm_real *a, const frm_real *b, double px, double py)
{
    int swap = (a[0] > b[0]) || (a[0] == b[0] && a[1] > b[1]);
    const frm_real *u = swap ? b : a, *w = swap ? a : b;
    double e = ((double)w[0] - u[0]) * (py - u[1]) - ((double)w[1] - u[1]) * (px - u[0]);
    return swap ? -e : e;
}

/* 1 if the +z ray from p crosses triangle t (xy projection containing (px, py) by the
   top-left rule, so a point on a shared edge belongs to exactly one side; above p). */
static int frm__ray_crosses(const frm__surface *S, int t, const double *p)
{
    const frm_real *a = S->v + 3 * S->t[3 * t], *b = S->v + 3 * S->t[3 * t + 1], *c = S->v + 3 * S->t[3 * t + 2];
    const frm_real *q[3];
    double area, e[3], z;
    int k;
    area = ((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)b[1] - a[1]) * ((double)c[0] - a[0]);
    if (area == 0) return 0;
    q[0] = a;
    q[1] = area > 0 ? b : c;
    q[2] = area > 0 ? c : b;
    for (k = 0; k < 3; k++) {
        const frm_real *u = q[k], *w = q[(k + 1) % 3];
        double dx = (double)w[0] - u[0], dy = (double)w[1] - u[1];
        e[k] = frm__edge_function(u, w, p[0], p[1]);
        if (e[k] < 0) return 0;
        if (e[k] == 0 && !(dy < 0 || (dy == 0 && dx < 0))) return 0;
    }
    /* e[k] is twice the area opposite vertex q[k + 2] */
    z = (e[0] * q[2][2] + e[1] * q[0][2] + e[2] * q[1][2]) / (e[0] + e[1] + e[2]);
    return z > p[2];
}

static int frm__inside(const frm__surface *S, const double *p)
{
    int bx, by, e, crossings = 0;
    if (p[0] < S->lo[0] || p[0] > S->hi[0] || p[1] < S->lo[1] || p[1] > S->hi[1] || p[2] < S->lo[2] || p[2] > S->hi[2])
        return 0;
    bx = (int)((p[0] - S->lo[0]) / S->cell[0]);
    by = (int)((p[1] - S->lo[1]) / S->cell[1]);
    if (bx >= S->nb[0]) bx = S->nb[0] - 1;
    if (by >= S->nb[1]) by = S->nb[1] - 1;
    for (e = S->start[bx + S->nb[0] * by]; e < S->start[bx + S->nb[0] * by + 1]; e++)
        crossings += frm__ray_crosses(S, S->items[e], p);
    return crossings & 1;
}

static int frm__edge_compare(const void *pa, const void *pb)
{
    const int *a = (const int *)pa, *b = (const int *)pb;
    if (a[0] != b[0]) return a[0] < b[0] ? -1 : 1;
    if (a[1] != b[1]) return a[1] < b[1] ? -1 : 1;
    return a[2] < b[2] ? -1 : (a[2] > b[2]);
}

/* Validates the surface (indices, every edge used once in each direction, positive
   volume), sets *volume and builds the bins. */
static int frm__surface_build(frm__surface *S, const frm_real *v, int vc, const int *t, int tc, double *volume,
                              const frm_allocator *a)
{
    int *edges, i, k, bx, by, pass;
    size_t ebytes = sizeof(int) * 3 * 3 * (size_t)tc;
    double vol = 0;
    memset(S, 0, sizeof *S);
    if (!v || !t || vc < 4 || tc < 4 || tc > 50000000) return FRM_ERR_SURFACE;
    if (!frm__all_finite(v, 3 * (size_t)vc)) return FRM_ERR_SAMPLE_NOT_FINITE;
    for (i = 0; i < 3 * tc; i++)
        if (t[i] < 0 || t[i] >= vc) return FRM_ERR_INDEX_RANGE;
    edges = (int *)frm__alloc(a, ebytes);
    if (!edges) return FRM_ERR_ALLOC;
    for (i = 0; i < tc; i++)
        for (k = 0; k < 3; k++) { /* directed edge (u, w) stored as (min, max, direction) */
            int u = t[3 * i + k], w = t[3 * i + (k + 1) % 3];
            int *e = edges + 3 * (3 * i + k);
            e[0] = u < w ? u : w;
            e[1] = u < w ? w : u;
            e[2] = u < w;
        }
    qsort(edges, 3 * (size_t)tc, 3 * sizeof(int), frm__edge_compare);
    for (i = 0; i < 3 * tc; i += 2) /* closed and consistently oriented: pairs (u,w,0)(u,w,1) */
        if (i + 1 >= 3 * tc || edges[3 * i] != edges[3 * i + 3] || edges[3 * i + 1] != edges[3 * i + 4] ||
            edges[3 * i + 2] != 0 || edges[3 * i + 5] != 1 || edges[3 * i] == edges[3 * i + 1] ||
            (i + 2 < 3 * tc && edges[3 * i + 6] == edges[3 * i] && edges[3 * i + 7] == edges[3 * i + 1])) {
            frm__free(a, edges, ebytes);
            return FRM_ERR_SURFACE;
        }
    frm__free(a, edges, ebytes);
    for (i = 0; i < tc; i++) { /* divergence theorem */
        const frm_real *p = v + 3 * t[3 * i], *q = v + 3 * t[3 * i + 1], *r = v + 3 * t[3 * i + 2];
        vol += ((double)p[0] * ((double)q[1] * r[2] - (double)q[2] * r[1]) - (double)p[1] * ((double)q[0] * r[2] - (double)q[2] * r[0]) +
                (double)p[2] * ((double)q[0] * r[1] - (double)q[1] * r[0])) / 6.0;
    }
    if (!(fabs(vol) > 0)) return FRM_ERR_SURFACE;
    *volume = fabs(vol);
    S->v = v;
    S->t = t;
    S->tri_count = tc;
    for (k = 0; k < 3; k++) {
        S->lo[k] = S->hi[k] = v[k];
        for (i = 1; i < vc; i++) {
            if (v[3 * i + k] < S->lo[k]) S->lo[k] = v[3 * i + k];
            if (v[3 * i + k] > S->hi[k]) S->hi[k] = v[3 * i + k];
        }
    }
    S->nb[0] = S->nb[1] = (int)sqrt((double)tc) + 1;
    if (S->nb[0] > 1024) S->nb[0] = S->nb[1] = 1024;
    for (k = 0; k < 2; k++) {
        S->cell[k] = (S->hi[k] - S->lo[k]) / S->nb[k];
        if (!(S->cell[k] > 0)) return FRM_ERR_SURFACE;
    }
    /* two passes over the triangles' xy boxes: count, then fill */
    for (pass = 0; pass < 2; pass++) {
        int cells = S->nb[0] * S->nb[1];
        if (pass == 0) {
            S->start = NULL;
            S->bytes = sizeof(int) * ((size_t)cells + 1);
            S->start = (int *)frm__alloc(a, S->bytes);
            if (!S->start) return FRM_ERR_ALLOC;
            memset(S->start, 0, S->bytes);
        }
        for (i = 0; i < tc; i++) {
            double lo[2], hi[2];
            int b0[2], b1[2];
            for (k = 0; k < 2; k++) {
                lo[k] = hi[k] = v[3 * t[3 * i] + k];
                if (v[3 * t[3 * i + 1] + k] < lo[k]) lo[k] = v[3 * t[3 * i + 1] + k];
                if (v[3 * t[3 * i + 1] + k] > hi[k]) hi[k] = v[3 * t[3 * i + 1] + k];
                if (v[3 * t[3 * i + 2] + k] < lo[k]) lo[k] = v[3 * t[3 * i + 2] + k];
                if (v[3 * t[3 * i + 2] + k] > hi[k]) hi[k] = v[3 * t[3 * i + 2] + k];
                b0[k] = (int)((lo[k] - S->lo[k]) / S->cell[k]);
                b1[k] = (int)((hi[k] - S->lo[k]) / S->cell[k]);
                if (b1[k] >= S->nb[k]) b1[k] = S->nb[k] - 1;
                if (b0[k] >= S->nb[k]) b0[k] = S->nb[k] - 1;
            }
            for (by = b0[1]; by <= b1[1]; by++)
                for (bx = b0[0]; bx <= b1[0]; bx++) {
                    if (pass == 0) S->start[bx + S->nb[0] * by + 1]++;
                    else S->items[S->start[bx + S->nb[0] * by]++] = i;
                }
        }
        if (pass == 0) { /* prefix sums, then the item array after them */
            size_t total, old = S->bytes;
            int *grown;
            for (i = 0; i < cells; i++) S->start[i + 1] += S->start[i];
            total = (size_t)S->start[cells];
            S->bytes = sizeof(int) * ((size_t)cells + 1 + total);
            grown = (int *)frm__alloc(a, S->bytes);
            if (!grown) {
                frm__free(a, S->start, old);
                S->start = NULL;
                return FRM_ERR_ALLOC;
            }
            memcpy(grown, S->start, sizeof(int) * ((size_t)cells + 1));
            frm__free(a, S->start, old);
            S->start = grown;
            S->items = grown + cells + 1;
        } else {
            for (i = cells; i > 0; i--) S->start[i] = S->start[i - 1];
            S->start[0] = 0;
        }
    }
    return FRM_OK;
}

/* Growable point list (3 doubles per point). */
typedef struct frm__points {
    double *p;
    int count, capacity, max;
    const frm_allocator *a;
} frm__points;

static int frm__points_push(frm__points *L, const double *x)
{
    if (L->count == L->max) return FRM_ERR_SAMPLING;
    if (L->count == L->capacity) {
        int cap = L->capacity ? 2 * L->capacity : 256;
        double *q = (double *)frm__alloc(L->a, sizeof(double) * 3 * (size_t)cap);
        if (!q) return FRM_ERR_ALLOC;
        if (L->p) {
            memcpy(q, L->p, sizeof(double) * 3 * (size_t)L->count);
            frm__free(L->a, L->p, sizeof(double) * 3 * (size_t)L->capacity);
        }
        L->p = q;
        L->capacity = cap;
    }
    memcpy(L->p + 3 * (size_t)L->count, x, 3 * sizeof(double));
    L->count++;
    return FRM_OK;
}

/* Poisson-disk points at least r apart in the box [lo, hi] (and inside S when given),
   Bridson's algorithm (30 candidates in the annulus [r, 2r] around each active point),
   then a fill pass that seeds every still-empty grid cell, so separate pieces and thin
   parts get points too. Axes with lo = hi stay flat. Deterministic for a seed. */
static int frm__poisson(const double lo[3], const double hi[3], const frm__surface *S, double r, unsigned int seed,
                        frm__points *L)
{
    unsigned long long state = 0x853C49E6748FEA9Bull ^ ((unsigned long long)seed * 0x9E3779B97F4A7C15ull);
    double cs, ext[3], emax = 0;
    int dims = 0, axis[3], n[3] = {1, 1, 1}, *grid, *active, active_count = 0, k, cell, err = FRM_OK, a;
    size_t cells, gbytes, abytes;
    for (k = 0; k < 3; k++) {
        ext[k] = hi[k] - lo[k];
        if (ext[k] > emax) emax = ext[k];
    }
    for (k = 0; k < 3; k++) axis[k] = ext[k] > 1e-12 * emax;
    for (k = 0; k < 3; k++) dims += axis[k];
    if (!dims || !(r > 0) || !(emax / r < 1e6)) return FRM_ERR_SAMPLING;
    cs = r / sqrt((double)dims);
    cells = 1;
    for (k = 0; k < 3; k++) {
        if (axis[k]) n[k] = (int)ceil(ext[k] / cs);
        if (n[k] < 1) n[k] = 1;
        cells *= (size_t)n[k];
    }
    if (cells > 100000000) return FRM_ERR_SAMPLING;
    gbytes = sizeof(int) * cells;
    grid = (int *)frm__alloc(L->a, gbytes);
    if (!grid) return FRM_ERR_ALLOC;
    for (cell = 0; cell < (int)cells; cell++) grid[cell] = -1;
    abytes = sizeof(int) * (size_t)(L->max + 1);
    active = (int *)frm__alloc(L->a, abytes);
    if (!active) {
        frm__free(L->a, grid, gbytes);
        return FRM_ERR_ALLOC;
    }
#define FRM__CELL_OF(x, c) \
    do { \
        for (a = 0; a < 3; a++) { \
            int t_ = axis[a] ? (int)(((x)[a] - lo[a]) / cs) : 0; \
            (c)[a] = t_ < 0 ? 0 : (t_ >= n[a] ? n[a] - 1 : t_); \
        } \
    } while (0)
    for (cell = 0; cell < (int)cells && !err; cell++) {
        int tries;
        if (grid[cell] >= 0) continue;
        /* seed this empty cell (the first one seeds the whole domain) */
        for (tries = 0; tries < 8 && grid[cell] < 0 && !err; tries++) {
            int ci[3], c3[3], ok = 1, x, y, z;
            double p[3];
            ci[0] = cell % n[0];
            ci[1] = (cell / n[0]) % n[1];
            ci[2] = cell / (n[0] * n[1]);
            for (a = 0; a < 3; a++) p[a] = axis[a] ? lo[a] + (ci[a] + frm__random(&state)) * cs : lo[a];
            for (a = 0; a < 3; a++)
                if (p[a] > hi[a]) ok = 0;
            if (!ok || (S && !frm__inside(S, p))) continue;
            FRM__CELL_OF(p, c3);
            for (z = c3[2] - 2; z <= c3[2] + 2 && ok; z++)
                for (y = c3[1] - 2; y <= c3[1] + 2 && ok; y++)
                    for (x = c3[0] - 2; x <= c3[0] + 2 && ok; x++) {
                        int q;
                        if (x < 0 || y < 0 || z < 0 || x >= n[0] || y >= n[1] || z >= n[2]) continue;
                        q = grid[x + n[0] * (y + n[1] * z)];
                        if (q >= 0) {
                            const double *o = L->p + 3 * (size_t)q;
                            if ((o[0] - p[0]) * (o[0] - p[0]) + (o[1] - p[1]) * (o[1] - p[1]) + (o[2] - p[2]) * (o[2] - p[2]) < r * r)
                                ok = 0;
                        }
                    }
            if (!ok) continue;
            err = frm__points_push(L, p);
            if (err) break;
            grid[c3[0] + n[0] * (c3[1] + n[1] * c3[2])] = L->count - 1;
            active[active_count++] = L->count - 1;
            while (active_count > 0 && !err) { /* Bridson growth */
                int pick = (int)(frm__random(&state) * active_count), j, found = 0;
                double base[3];
                if (pick >= active_count) pick = active_count - 1;
                memcpy(base, L->p + 3 * (size_t)active[pick], sizeof base);
                for (j = 0; j < 30 && !found; j++) {
                    double dir[3], len = 0, rad = r * (1.0 + frm__random(&state)), q[3];
                    int ok2 = 1;
                    do { /* a direction in the active axes */
                        len = 0;
                        for (a = 0; a < 3; a++) {
                            dir[a] = axis[a] ? 2.0 * frm__random(&state) - 1.0 : 0.0;
                            len += dir[a] * dir[a];
                        }
                    } while (len > 1.0 || len < 1e-6);
                    len = sqrt(len);
                    for (a = 0; a < 3; a++) {
                        q[a] = base[a] + rad * dir[a] / len;
                        if (axis[a] && (q[a] < lo[a] || q[a] > hi[a])) ok2 = 0;
                        if (!axis[a]) q[a] = lo[a];
                    }
                    if (!ok2 || (S && !frm__inside(S, q))) continue;
                    FRM__CELL_OF(q, c3);
                    for (z = c3[2] - 2; z <= c3[2] + 2 && ok2; z++)
                        for (y = c3[1] - 2; y <= c3[1] + 2 && ok2; y++)
                            for (x = c3[0] - 2; x <= c3[0] + 2 && ok2; x++) {
                                int o;
                                if (x < 0 || y < 0 || z < 0 || x >= n[0] || y >= n[1] || z >= n[2]) continue;
                                o = grid[x + n[0] * (y + n[1] * z)];
                                if (o >= 0) {
                                    const double *w = L->p + 3 * (size_t)o;
                                    if ((w[0] - q[0]) * (w[0] - q[0]) + (w[1] - q[1]) * (w[1] - q[1]) + (w[2] - q[2]) * (w[2] - q[2]) <
                                        r * r)
                                        ok2 = 0;
                                }
                            }
                    if (!ok2) continue;
                    err = frm__points_push(L, q);
                    if (err) break;
                    grid[c3[0] + n[0] * (c3[1] + n[1] * c3[2])] = L->count - 1;
                    active[active_count++] = L->count - 1;
                    found = 1;
                }
                if (!found) active[pick] = active[--active_count];
            }
        }
    }
#undef FRM__CELL_OF
    frm__free(L->a, active, abytes);
    frm__free(L->a, grid, gbytes);
    return err;
}

static int frm__check_poisson(const frm_poisson_desc *p, const frm_shape_desc *shape)
{
    if (!p) return FRM_ERR_ARG;
    if (p->internal_cookie != FRM__POISSON_COOKIE) return FRM_ERR_DESC;
    if (!(frm__finite((double)p->frame_spacing) && p->frame_spacing > 0) ||
        !(frm__finite((double)p->sample_spacing) && p->sample_spacing > 0) || !frm__finite((double)p->volume) ||
        p->max_points < 1 || p->frame_spacing < p->sample_spacing) /* frames coarser than samples */
        return FRM_ERR_SAMPLING;
    if (shape) return frm__check_shape(shape); /* before the points are made */
    return FRM_OK;
}

/* Poisson points for frames (seed) and samples (seed + 1), then the meshless tables. */
static int frm__sampling_poisson(frm_sampling *out, const double lo[3], const double hi[3], const frm__surface *S,
                                 double volume, const frm_poisson_desc *p, const frm_shape_desc *shape,
                                 const frm_allocator *alloc)
{
    frm__points F, P;
    frm_real *fr = NULL, *sr = NULL;
    size_t fbytes = 0, sbytes = 0;
    int err, i;
    memset(&F, 0, sizeof F);
    memset(&P, 0, sizeof P);
    F.a = P.a = alloc;
    F.max = P.max = p->max_points;
    err = frm__poisson(lo, hi, S, (double)p->frame_spacing, p->seed, &F);
    if (!err) err = frm__poisson(lo, hi, S, (double)p->sample_spacing, p->seed + 1u, &P);
    if (!err && (F.count < 1 || P.count < 1)) err = FRM_ERR_SAMPLING;
    if (!err) {
        fbytes = sizeof(frm_real) * 3 * (size_t)F.count;
        sbytes = sizeof(frm_real) * 3 * (size_t)P.count;
        fr = (frm_real *)frm__alloc(alloc, fbytes);
        sr = (frm_real *)frm__alloc(alloc, sbytes);
        if (!fr || !sr) err = FRM_ERR_ALLOC;
    }
    if (!err) {
        for (i = 0; i < 3 * F.count; i++) fr[i] = (frm_real)F.p[i];
        for (i = 0; i < 3 * P.count; i++) sr[i] = (frm_real)P.p[i];
        err = frm_sampling_meshless(out, fr, F.count, sr, P.count, (frm_real)volume, shape, alloc);
    }
    frm__free(alloc, fr, fbytes);
    frm__free(alloc, sr, sbytes);
    if (F.p) frm__free(alloc, F.p, sizeof(double) * 3 * (size_t)F.capacity);
    if (P.p) frm__free(alloc, P.p, sizeof(double) * 3 * (size_t)P.capacity);
    return err;
}

FRMDEF int frm_sampling_box(frm_sampling *out, const frm_real lo[3], const frm_real hi[3], const frm_poisson_desc *p,
                            const frm_shape_desc *shape, const frm_allocator *allocator)
{
    frm_allocator alloc;
    double l[3], h[3], vol = 1;
    int err, k;
    if (!out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (!lo || !hi || !frm__vec3_finite(lo) || !frm__vec3_finite(hi)) return FRM_ERR_ARG;
    err = frm__check_poisson(p, shape);
    if (err) return err;
    memset(&alloc, 0, sizeof alloc);
    if (allocator) alloc = *allocator;
    for (k = 0; k < 3; k++) {
        l[k] = (double)lo[k];
        h[k] = (double)hi[k];
        if (h[k] < l[k]) return FRM_ERR_ARG;
        vol *= h[k] - l[k];
    }
    if (p->volume > 0) vol = (double)p->volume;
    if (!(vol > 0)) return FRM_ERR_SAMPLING; /* a flat box needs its volume */
    return frm__sampling_poisson(out, l, h, NULL, vol, p, shape, &alloc);
}

FRMDEF int frm_sampling_surface(frm_sampling *out, const frm_real *vertices, int vertex_count, const int *triangles,
                                int triangle_count, const frm_poisson_desc *p, const frm_shape_desc *shape,
                                const frm_allocator *allocator)
{
    frm_allocator alloc;
    frm__surface S;
    double vol = 0;
    int err;
    if (!out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    err = frm__check_poisson(p, shape);
    if (err) return err;
    memset(&alloc, 0, sizeof alloc);
    if (allocator) alloc = *allocator;
    err = frm__surface_build(&S, vertices, vertex_count, triangles, triangle_count, &vol, &alloc);
    if (!err) err = frm__sampling_poisson(out, S.lo, S.hi, &S, p->volume > 0 ? (double)p->volume : vol, p, shape, &alloc);
    if (S.start) frm__free(&alloc, S.start, S.bytes);
    return err;
}

/* >>parts ------------------------------------------------------------------------------ */

FRMDEF frm_part frm_part_default(void)
{
    frm_part p;
    frm_desc d = frm_model_default_desc();
    memset(&p, 0, sizeof p);
    p.material = d.material;
    return p;
}

FRMDEF void frm_assembly_free(frm_assembly *a)
{
    if (!a) return;
    if (a->materials) frm__free(&a->allocator, a->materials, a->bytes);
    frm_sampling_free(&a->sampling);
    memset(a, 0, sizeof *a);
}

/* Part k's sample i mapped to the model's frames: its entries with frames on one rigid body
   merged (their weights and gradients add: the frames predict the same point, see RIGID
   BODIES). n entries into f, w, g; FRM_ERR_NEIGHBOR_TABLE for a malformed row. */
static int frm__part_row(const frm_part *pt, int i, const unsigned char *rigid, int *f, double *w, double *g, int *n)
{
    const frm_sampling *s = pt->sampling;
    int a = s->neighbor_start[i], b = s->neighbor_start[i + 1], e, q, r;
    *n = 0;
    if (a < 0 || b <= a || b - a > FRM_MAX_NEIGHBORS || b > s->pair_count) return FRM_ERR_NEIGHBOR_TABLE;
    for (e = a; e < b; e++) {
        int lf = s->neighbor_frames[e], gf;
        if (lf < 0 || lf >= s->frame_count) return FRM_ERR_NEIGHBOR_TABLE;
        gf = pt->frame_map ? pt->frame_map[lf] : lf;
        q = 0;
        while (q < *n && !(rigid[gf] && f[q] == gf)) q++;
        if (q == *n) {
            f[q] = gf, w[q] = 0;
            for (r = 0; r < 3; r++) g[3 * q + r] = 0;
            (*n)++;
        }
        w[q] += (double)s->neighbor_weights[e];
        for (r = 0; r < 3; r++) g[3 * q + r] += (double)s->neighbor_gradients[3 * e + r];
    }
    return FRM_OK;
}

FRMDEF frm_rigid_body frm_rigid_body_default(void)
{
    frm_rigid_body b;
    memset(&b, 0, sizeof b);
    b.frame = -1;
    return b;
}

FRMDEF int frm_parts_combine(frm_assembly *out, const frm_part *parts, int part_count, const frm_rigid_body *rigids,
                             int rigid_count, int frame_count, const frm_allocator *allocator)
{
    long long samples = 0, pairs = 0, cells = 0;
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, size = 0, tol;
    int k, i, j, r, s0 = 0, p0 = 0, c0 = 0, err = FRM_OK, first = 1, pass, all_cells = 1;
    int *given = NULL;
    unsigned char *rigid = NULL;
    frm_allocator al;
    frm__carver c;
    if (!out) return FRM_ERR_ARG;
    memset(out, 0, sizeof *out);
    if (!parts || part_count < 1 || frame_count < 1 || part_count > 100000000 || frame_count > 100000000 ||
        rigid_count < 0 || (rigid_count > 0 && !rigids))
        return FRM_ERR_ARG;
    memset(&al, 0, sizeof al);
    if (allocator) al = *allocator;
    for (k = 0; k < part_count; k++) {
        const frm_sampling *s = parts[k].sampling;
        if (!s || s->frame_count < 1 || s->sample_count < 1 || !s->frame_positions || !s->sample_positions ||
            !s->sample_volumes || !s->neighbor_start || !s->neighbor_frames || !s->neighbor_weights ||
            !s->neighbor_gradients)
            return FRM_ERR_ARG;
        if (!parts[k].frame_map && s->frame_count > frame_count) return FRM_ERR_PART_FRAME;
        for (j = 0; j < s->frame_count; j++) {
            int g = parts[k].frame_map ? parts[k].frame_map[j] : j;
            if (g < 0 || g >= frame_count) return FRM_ERR_PART_FRAME;
            for (r = 0; r < 3; r++) {
                double x = (double)s->frame_positions[3 * j + r];
                if (first || x < lo[r]) lo[r] = x;
                if (first || x > hi[r]) hi[r] = x;
            }
            first = 0;
        }
        samples += s->sample_count;
        /* cells (volumetric averaging): each part's own, numbered after the previous
           parts'; a combination keeps them only when every part has them */
        if (s->cell_count > 0 && s->sample_cells) cells += s->cell_count;
        else all_cells = 0;
    }
    if (!all_cells || cells > 100000000) cells = 0;
    for (k = 0; k < rigid_count; k++) {
        const frm_rigid_body *rb = rigids + k;
        if (rb->frame < 0 || rb->frame >= frame_count) return FRM_ERR_PART_FRAME;
        if (!frm__all_finite(rb->position, 3)) return FRM_ERR_ARG;
        if (!frm__rigid_valid((double)rb->mass, rb->inertia) || !(rb->mass > 0)) return FRM_ERR_RIGID;
    }
    if (samples > 100000000) return FRM_ERR_ARG;
    for (r = 0; r < 3; r++)
        if (hi[r] - lo[r] > size) size = hi[r] - lo[r];
    tol = (sizeof(frm_real) < sizeof(double) ? 1e-5 : 1e-9) * (size > 0 ? size : 1);
    /* the block of the assembly's own arrays and the scratch marks */
    c.base = NULL;
    for (pass = 0; pass < 2; pass++) {
        c.offset = 0;
        FRM__CARVE(&c, out->materials, frm_material, part_count);
        FRM__CARVE(&c, out->sample_materials, int, samples);
        FRM__CARVE(&c, out->part_samples, int, part_count + 1);
        FRM__CARVE(&c, out->frame_masses, frm_real, frame_count);
        FRM__CARVE(&c, out->frame_inertias, frm_real, 6 * (size_t)frame_count);
        FRM__CARVE(&c, out->sample_sizes, frm_real, samples);
        FRM__CARVE(&c, out->sample_linear, unsigned char, samples);
        FRM__CARVE(&c, given, int, frame_count); /* scratch: the last part (+ 1) that gave each model frame */
        FRM__CARVE(&c, rigid, unsigned char, frame_count); /* scratch: the frame is a rigid body's */
        if (pass == 0) {
            out->bytes = c.offset;
            c.base = (char *)frm__alloc(&al, out->bytes);
            if (!c.base) {
                memset(out, 0, sizeof *out);
                return FRM_ERR_ALLOC;
            }
        }
    }
    out->part_count = part_count;
    out->rigid_count = rigid_count;
    out->allocator = al;
    memset(given, 0, sizeof(int) * (size_t)frame_count);
    memset(rigid, 0, (size_t)frame_count);
    memset(out->frame_masses, 0, sizeof(frm_real) * (size_t)frame_count);
    memset(out->frame_inertias, 0, sizeof(frm_real) * 6 * (size_t)frame_count);
    for (k = 0; k < rigid_count; k++) {
        const frm_rigid_body *rb = rigids + k;
        if (rigid[rb->frame]) err = FRM_ERR_PART_FRAME; /* two bodies on one frame */
        rigid[rb->frame] = 1;
        out->frame_masses[rb->frame] = rb->mass;
        for (r = 0; r < 6; r++) out->frame_inertias[6 * (size_t)rb->frame + r] = rb->inertia[r];
    }
    /* the merged pairs (frames on one rigid body become one entry) */
    for (k = 0; k < part_count && !err; k++)
        for (i = 0; i < parts[k].sampling->sample_count && !err; i++) {
            int f[FRM_MAX_NEIGHBORS], n;
            double w[FRM_MAX_NEIGHBORS], g[3 * FRM_MAX_NEIGHBORS];
            err = frm__part_row(parts + k, i, rigid, f, w, g, &n);
            pairs += n;
        }
    if (!err && pairs > 1600000000) err = FRM_ERR_ARG;
    if (!err) err = frm__sampling_alloc(&out->sampling, frame_count, (int)samples, (int)pairs, (int)cells, &al);
    if (err) {
        frm_assembly_free(out);
        return err;
    }
    for (k = 0; k < rigid_count; k++) { /* a body gives its frame */
        for (r = 0; r < 3; r++) out->sampling.frame_positions[3 * rigids[k].frame + r] = rigids[k].position[r];
        given[rigids[k].frame] = -1;
    }
    out->sampling.neighbor_start[0] = 0;
    for (k = 0; k < part_count && !err; k++) {
        const frm_part *pt = parts + k;
        const frm_sampling *s = pt->sampling;
        out->materials[k] = pt->material;
        out->part_samples[k] = s0;
        for (j = 0; j < s->frame_count && !err; j++) { /* frames: the first giver sets, the others agree */
            int g = pt->frame_map ? pt->frame_map[j] : j;
            frm_real *x = out->sampling.frame_positions + 3 * g;
            if (rigid[g]) continue; /* attached to a body: moves with it rigidly */
            if (given[g] == k + 1) { /* repeated within this part */
                err = FRM_ERR_PART_FRAME;
                break;
            }
            if (!given[g])
                for (r = 0; r < 3; r++) x[r] = s->frame_positions[3 * j + r];
            else
                for (r = 0; r < 3; r++)
                    if (!(fabs((double)x[r] - (double)s->frame_positions[3 * j + r]) <= tol)) err = FRM_ERR_PART_FRAME;
            given[g] = k + 1;
        }
        for (i = 0; i < s->sample_count && !err; i++) {
            int f[FRM_MAX_NEIGHBORS], n, e;
            double w[FRM_MAX_NEIGHBORS], g[3 * FRM_MAX_NEIGHBORS];
            double h2 = 0, wsum = 0, A[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, lin = 0;
            err = frm__part_row(pt, i, rigid, f, w, g, &n);
            for (e = s->neighbor_start[i]; e < s->neighbor_start[i + 1] && !err; e++) { /* as frm__create_pairs */
                double l2 = 0, aw = fabs((double)s->neighbor_weights[e]), l[3];
                int q;
                for (r = 0; r < 3; r++) {
                    l[r] = (double)(frm_real)((double)s->sample_positions[3 * i + r] -
                                              (double)s->frame_positions[3 * s->neighbor_frames[e] + r]);
                    l2 += l[r] * l[r];
                }
                h2 += aw * l2;
                wsum += aw;
                for (r = 0; r < 3; r++)
                    for (q = 0; q < 3; q++) A[3 * r + q] += l[r] * (double)s->neighbor_gradients[3 * e + q];
            }
            for (r = 0; r < 9; r++) lin += fabs(A[r]);
            out->sample_sizes[s0 + i] = (frm_real)(wsum > 0 ? h2 / wsum : 0);
            out->sample_linear[s0 + i] = lin <= 1e-3;
            for (r = 0; r < 3; r++) out->sampling.sample_positions[3 * (s0 + i) + r] = s->sample_positions[3 * i + r];
            out->sampling.sample_volumes[s0 + i] = s->sample_volumes[i];
            if (cells) out->sampling.sample_cells[s0 + i] = c0 + s->sample_cells[i];
            out->sample_materials[s0 + i] = k;
            for (e = 0; e < n; e++) {
                out->sampling.neighbor_frames[p0 + e] = f[e];
                out->sampling.neighbor_weights[p0 + e] = (frm_real)w[e];
                for (r = 0; r < 3; r++) out->sampling.neighbor_gradients[3 * (p0 + e) + r] = (frm_real)g[3 * e + r];
            }
            p0 += n;
            out->sampling.neighbor_start[s0 + i + 1] = p0;
        }
        s0 += s->sample_count;
        if (cells) c0 += s->cell_count;
    }
    out->part_samples[part_count] = s0;
    for (j = 0; j < frame_count && !err; j++)
        if (!given[j]) err = FRM_ERR_PART_FRAME;
    if (err) {
        frm_assembly_free(out);
        return err;
    }
    return FRM_OK;
}

FRMDEF void frm_assembly_apply(const frm_assembly *a, frm_desc *d)
{
    if (!a || !d) return;
    frm_sampling_apply(&a->sampling, d);
    d->materials = a->materials;
    d->material_count = a->part_count;
    d->sample_materials = a->sample_materials;
    d->frame_masses = a->rigid_count > 0 ? a->frame_masses : NULL;
    d->frame_inertias = a->rigid_count > 0 ? a->frame_inertias : NULL;
    d->sample_sizes = a->rigid_count > 0 ? a->sample_sizes : NULL;
    d->sample_linear = a->rigid_count > 0 ? a->sample_linear : NULL;
}

/* >>probes ----------------------------------------------------------------------------- */

struct frm_probe {
    int count, pair_count, frame_count;
    int *start;       /* count + 1: point -> its pairs */
    int *frame;       /* per pair */
    double *weight;   /* per pair */
    double *lever;    /* 3 per pair: abar = pbar - xbar_i (rest, world axes) */
    double *rest;     /* 3 per point: pbar */
    frm_allocator allocator;
    size_t bytes;
};

FRMDEF frm_probe_desc frm_probe_default_desc(void)
{
    frm_probe_desc d;
    memset(&d, 0, sizeof d);
    d.kind = FRM_PROBE_MESHLESS;
    d.shape = frm_shape_default_desc();
    d.tolerance = (frm_real)1e-6;
    d.internal_cookie = FRM__PROBE_COOKIE;
    return d;
}

/* Trilinear functions of the parametric point xi (corner a + 2 b + 4 c at (a, b, c)) and
   their derivatives d/dxi (8 x 3). */
static void frm__trilinear(const double xi[3], double N[8], double dN[8][3])
{
    int a, k;
    for (a = 0; a < 8; a++) {
        double f[3], df[3];
        for (k = 0; k < 3; k++) {
            int bit = (a >> k) & 1;
            f[k] = bit ? xi[k] : 1 - xi[k];
            df[k] = bit ? 1 : -1;
        }
        N[a] = f[0] * f[1] * f[2];
        dN[a][0] = df[0] * f[1] * f[2];
        dN[a][1] = f[0] * df[1] * f[2];
        dN[a][2] = f[0] * f[1] * df[2];
    }
}

/* The parametric coordinates of p in the hexahedron X by Newton from its centre; 0 when
   it converged (|dxi| < 1e-13), else FRM_ERR_SHAPE_DEGENERATE. */
static int frm__hex_invert(double X[8][3], const double p[3], double xi[3])
{
    int it, a, r, c;
    xi[0] = xi[1] = xi[2] = 0.5;
    for (it = 0; it < 40; it++) {
        double N[8], dN[8][3], J[3][3], res[3], inv[3][3], det, step = 0;
        frm__trilinear(xi, N, dN);
        for (r = 0; r < 3; r++) {
            res[r] = -p[r];
            for (c = 0; c < 3; c++) J[r][c] = 0;
            for (a = 0; a < 8; a++) {
                res[r] += N[a] * X[a][r];
                for (c = 0; c < 3; c++) J[r][c] += X[a][r] * dN[a][c];
            }
        }
        det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
              J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
        if (!(fabs(det) > 0) || !frm__finite(det)) return FRM_ERR_SHAPE_DEGENERATE;
        inv[0][0] = (J[1][1] * J[2][2] - J[1][2] * J[2][1]) / det;
        inv[0][1] = (J[0][2] * J[2][1] - J[0][1] * J[2][2]) / det;
        inv[0][2] = (J[0][1] * J[1][2] - J[0][2] * J[1][1]) / det;
        inv[1][0] = (J[1][2] * J[2][0] - J[1][0] * J[2][2]) / det;
        inv[1][1] = (J[0][0] * J[2][2] - J[0][2] * J[2][0]) / det;
        inv[1][2] = (J[0][2] * J[1][0] - J[0][0] * J[1][2]) / det;
        inv[2][0] = (J[1][0] * J[2][1] - J[1][1] * J[2][0]) / det;
        inv[2][1] = (J[0][1] * J[2][0] - J[0][0] * J[2][1]) / det;
        inv[2][2] = (J[0][0] * J[1][1] - J[0][1] * J[1][0]) / det;
        for (r = 0; r < 3; r++) {
            double d = -(inv[r][0] * res[0] + inv[r][1] * res[1] + inv[r][2] * res[2]);
            xi[r] += d;
            if (fabs(d) > step) step = fabs(d);
        }
        if (!frm__finite(xi[0] + xi[1] + xi[2]) || fabs(xi[0]) + fabs(xi[1]) + fabs(xi[2]) > 1e3)
            return FRM_ERR_SHAPE_DEGENERATE;
        if (step < 1e-13) return FRM_OK;
    }
    return FRM_ERR_SHAPE_DEGENERATE;
}

/* Elements binned by their bounding boxes (widened by 1e-3 of their size, the room the
   containment test allows) in a uniform grid of about one cell per element: a point's
   candidates are its cell's elements. Temporary (frm_probe_create). */
typedef struct frm__bins {
    double lo[3], h[3];
    int n[3];
    int *start, *items; /* cell -> elements */
    size_t bytes;
} frm__bins;

static void frm__element_box(const frm_probe_desc *d, const double *X, int e, double lo[3], double hi[3])
{
    int nodes = d->kind == FRM_PROBE_TETS ? 4 : 8, a, r;
    const int *el = d->elements + (size_t)nodes * (size_t)e;
    double size = 0;
    for (r = 0; r < 3; r++) lo[r] = hi[r] = X[3 * el[0] + r]; /* set before the loop: gcc -O3 warned */
    for (a = 1; a < nodes; a++)
        for (r = 0; r < 3; r++) {
            double x = X[3 * el[a] + r];
            if (x < lo[r]) lo[r] = x;
            if (x > hi[r]) hi[r] = x;
        }
    for (r = 0; r < 3; r++)
        if (hi[r] - lo[r] > size) size = hi[r] - lo[r];
    for (r = 0; r < 3; r++) lo[r] -= 1e-3 * size, hi[r] += 1e-3 * size;
}

static int frm__bins_cell(const frm__bins *b, double x, int r)
{
    double t = (x - b->lo[r]) / b->h[r];
    return t < 0 ? 0 : (t >= b->n[r] ? b->n[r] - 1 : (int)t);
}

static int frm__bins_build(frm__bins *b, const frm_probe_desc *d, const double *X, int frame_count, const frm_allocator *a)
{
    double hi[3], ext[3], top = 0, cells1;
    int e, r, pass, cells, c;
    long long total = 0;
    memset(b, 0, sizeof *b);
    for (r = 0; r < 3; r++) b->lo[r] = hi[r] = X[r];
    for (e = 1; e < frame_count; e++)
        for (r = 0; r < 3; r++) {
            if (X[3 * e + r] < b->lo[r]) b->lo[r] = X[3 * e + r];
            if (X[3 * e + r] > hi[r]) hi[r] = X[3 * e + r];
        }
    for (r = 0; r < 3; r++) {
        ext[r] = hi[r] - b->lo[r];
        if (ext[r] > top) top = ext[r];
    }
    cells1 = pow((double)d->element_count, 1.0 / 3.0) + 1;
    for (r = 0; r < 3; r++) {
        b->n[r] = top > 0 ? (int)(cells1 * ext[r] / top) + 1 : 1;
        if (b->n[r] > 256) b->n[r] = 256;
        b->h[r] = ext[r] > 0 ? ext[r] / b->n[r] : 1;
    }
    cells = b->n[0] * b->n[1] * b->n[2];
    b->start = (int *)frm__alloc(a, sizeof(int) * ((size_t)cells + 1));
    if (!b->start) return FRM_ERR_ALLOC;
    memset(b->start, 0, sizeof(int) * ((size_t)cells + 1));
    /* pass 0 counts each cell's elements, pass 1 fills them (start[c] as the cursor) */
    for (pass = 0; pass < 2; pass++) {
        if (pass == 1) {
            for (c = 0; c < cells; c++) b->start[c + 1] += b->start[c];
            b->bytes = sizeof(int) * (size_t)(total > 0 ? total : 1);
            b->items = (int *)frm__alloc(a, b->bytes);
            if (!b->items) return FRM_ERR_ALLOC;
        }
        for (e = 0; e < d->element_count; e++) {
            double lo[3], up[3];
            int c0[3], c1[3], i, j, k;
            frm__element_box(d, X, e, lo, up);
            for (r = 0; r < 3; r++) c0[r] = frm__bins_cell(b, lo[r], r), c1[r] = frm__bins_cell(b, up[r], r);
            for (k = c0[2]; k <= c1[2]; k++)
                for (j = c0[1]; j <= c1[1]; j++)
                    for (i = c0[0]; i <= c1[0]; i++) {
                        int cell = i + b->n[0] * (j + b->n[1] * k);
                        if (pass == 0) {
                            b->start[cell + 1]++;
                            if (++total > 200000000) return FRM_ERR_ALLOC;
                        } else
                            b->items[b->start[cell]++] = e;
                    }
        }
    }
    for (c = cells; c > 0; c--) b->start[c] = b->start[c - 1]; /* the cursors ran to the next cell's start */
    b->start[0] = 0;
    return FRM_OK;
}

static void frm__bins_free(frm__bins *b, const frm_allocator *a)
{
    if (b->start) frm__free(a, b->start, sizeof(int) * ((size_t)b->n[0] * b->n[1] * b->n[2] + 1));
    if (b->items) frm__free(a, b->items, b->bytes);
    memset(b, 0, sizeof *b);
}

/* The frames and weights of one point p: n (<= FRM_MAX_NEIGHBORS) into idx, w. */
static int frm__probe_point(const frm_model *m, const frm_probe_desc *d, const frm__grid *grid, const frm__bins *bins,
                            const double *X, const double *reach, const double p[3], int *idx, double *w, int *n)
{
    double tol = (double)d->tolerance, best = -HUGE_VAL;
    int e, a, r, nodes = d->kind == FRM_PROBE_TETS ? 4 : 8, cell, q;
    *n = 0;
    if (d->kind == FRM_PROBE_MESHLESS) {
        const frm_shape_desc *sh = &d->shape;
        double dist[FRM_MAX_NEIGHBORS + 1], Xn[3 * FRM_MAX_NEIGHBORS], g[3 * FRM_MAX_NEIGHBORS], R;
        int k = sh->support == FRM_SUPPORT_NEAREST ? (sh->nearest < m->frame_count ? sh->nearest : m->frame_count) : 0, i,
            err;
        int c = frm__grid_query(grid, X, p, k, sh->support == FRM_SUPPORT_RADIUS ? (double)sh->radius : 0.0,
                                FRM_MAX_NEIGHBORS, idx, dist);
        if (c == 0) return FRM_ERR_POINT_OUTSIDE;
        if (c > FRM_MAX_NEIGHBORS) return FRM_ERR_TOO_MANY_NEIGHBORS;
        if (reach) { /* inside the support of at least one of its frames (issue 14) */
            int in = 0;
            for (i = 0; i < c && !in; i++) in = dist[i] <= reach[idx[i]] * (1 + 1e-3 + tol);
            if (!in) return FRM_ERR_POINT_OUTSIDE;
        }
        for (i = 0; i < c; i++)
            for (r = 0; r < 3; r++) Xn[3 * i + r] = X[3 * idx[i] + r];
        if (sh->shape == FRM_SHAPE_MLS) { /* as frm_sampling_meshless */
            R = sh->support == FRM_SUPPORT_RADIUS ? (double)sh->radius : 1.5 * dist[c - 1];
            err = frm__mls_functions(Xn, c, p, R, w, g);
        } else
            err = frm__shepard_functions(Xn, c, p, (double)sh->power, sh->support == FRM_SUPPORT_RADIUS ? (double)sh->radius : 0.0,
                                         w, g);
        if (err) return err;
        *n = c;
        return FRM_OK;
    }
    cell = frm__bins_cell(bins, p[0], 0) + bins->n[0] * (frm__bins_cell(bins, p[1], 1) + bins->n[1] * frm__bins_cell(bins, p[2], 2));
    for (q = bins->start[cell]; q < bins->start[cell + 1]; q++) { /* in element order: the same answer as a full scan */
        const int *el;
        double E[8][3], lo[3], hi[3], size = 0, ww[8], inside;
        e = bins->items[q];
        el = d->elements + (size_t)nodes * (size_t)e;
        int out = 0;
        for (a = 0; a < nodes; a++)
            for (r = 0; r < 3; r++) {
                E[a][r] = X[3 * el[a] + r];
                if (a == 0 || E[a][r] < lo[r]) lo[r] = E[a][r];
                if (a == 0 || E[a][r] > hi[r]) hi[r] = E[a][r];
            }
        for (r = 0; r < 3; r++)
            if (hi[r] - lo[r] > size) size = hi[r] - lo[r];
        for (r = 0; r < 3; r++) out |= p[r] < lo[r] - 1e-3 * size || p[r] > hi[r] + 1e-3 * size;
        if (out) continue; /* the bounding box, with room for the tolerance */
        if (nodes == 4) {
            double g4[4][3];
            if (!frm__tet_functions(E, p, ww, g4)) continue; /* a flat tetrahedron holds no point */
            inside = ww[0];
            for (a = 1; a < 4; a++)
                if (ww[a] < inside) inside = ww[a];
        } else {
            double xi[3], dN[8][3];
            if (frm__hex_invert(E, p, xi)) continue;
            frm__trilinear(xi, ww, dN);
            inside = HUGE_VAL;
            for (r = 0; r < 3; r++) {
                if (xi[r] < inside) inside = xi[r];
                if (1 - xi[r] < inside) inside = 1 - xi[r];
            }
        }
        if (inside >= -tol && inside > best) {
            best = inside;
            *n = nodes;
            for (a = 0; a < nodes; a++) idx[a] = el[a], w[a] = ww[a];
        }
    }
    return *n ? FRM_OK : FRM_ERR_POINT_OUTSIDE;
}

FRMDEF int frm_probe_create(const frm_model *m, const frm_probe_desc *d, const frm_real *rest_points, int count,
                            frm_probe **out)
{
    frm__carver c;
    frm__grid grid;
    frm__bins bins;
    frm_probe tmp, *p;
    double *X, *G;
    size_t xbytes;
    int err = FRM_OK, i, k, r, pass, pairs = 0, nodes, geo;
    if (out) *out = NULL;
    if (!m || !d || !out) return FRM_ERR_ARG;
    if (d->internal_cookie != FRM__PROBE_COOKIE) return FRM_ERR_DESC;
    if (!rest_points || count < 1 || count > 100000000 || !frm__all_finite(rest_points, 3 * (size_t)count) ||
        !(frm__finite((double)d->tolerance) && d->tolerance >= 0))
        return FRM_ERR_ARG;
    if ((int)d->kind < FRM_PROBE_TETS || (int)d->kind > FRM_PROBE_MESHLESS) return FRM_ERR_ARG;
    nodes = d->kind == FRM_PROBE_TETS ? 4 : 8;
    if (d->kind == FRM_PROBE_MESHLESS) {
        err = frm__check_shape(&d->shape);
        if (err) return err;
    } else {
        int range = d->nodes ? d->node_count : m->frame_count;
        if (!d->elements || d->element_count < 1) return FRM_ERR_ARG;
        if (d->nodes && (d->node_count < 1 || !d->node_frames || !frm__all_finite(d->nodes, 3 * (size_t)d->node_count)))
            return FRM_ERR_ARG;
        for (i = 0; i < nodes * d->element_count; i++)
            if (d->elements[i] < 0 || d->elements[i] >= range) return FRM_ERR_INDEX_RANGE;
        for (i = 0; d->nodes && i < d->node_count; i++)
            if (d->node_frames[i] < 0 || d->node_frames[i] >= m->frame_count) return FRM_ERR_INDEX_RANGE;
    }
    geo = d->kind != FRM_PROBE_MESHLESS && d->nodes ? d->node_count : 0;
    /* rest positions, each frame's reach, then the elements' own nodes */
    xbytes = sizeof(double) * (4 * (size_t)m->frame_count + 3 * (size_t)geo);
    X = (double *)frm__alloc(&m->allocator, xbytes);
    if (!X) return FRM_ERR_ALLOC;
    for (i = 0; i < 3 * m->frame_count; i++) X[i] = (double)m->rest_pos[i];
    G = geo ? X + 4 * (size_t)m->frame_count : X;
    for (i = 0; i < 3 * geo; i++) G[i] = (double)d->nodes[i];
    for (i = 0; i < m->frame_count; i++) X[3 * m->frame_count + i] = 0;
    for (k = 0; k < m->pair_count; k++) { /* reach: the frame's farthest sample (its rest lever) */
        const frm_real *a = m->p_rlev + 3 * (size_t)k;
        double len = sqrt((double)a[0] * a[0] + (double)a[1] * a[1] + (double)a[2] * a[2]);
        double *reach = X + 3 * m->frame_count + m->p_frame[k];
        if (len > *reach) *reach = len;
    }
    memset(&grid, 0, sizeof grid);
    memset(&bins, 0, sizeof bins);
    if (d->kind == FRM_PROBE_MESHLESS)
        err = frm__grid_build(&grid, X, m->frame_count, d->shape.support == FRM_SUPPORT_RADIUS ? (double)d->shape.radius : 0.0,
                              &m->allocator);
    else
        err = frm__bins_build(&bins, d, G, geo ? geo : m->frame_count, &m->allocator);
    memset(&tmp, 0, sizeof tmp);
    p = NULL;
    /* pass 0 counts the pairs, pass 1 fills the block */
    for (pass = 0; pass < 2 && !err; pass++) {
        if (pass == 1) {
            tmp.count = count;
            tmp.pair_count = pairs;
            tmp.frame_count = m->frame_count;
            c.base = NULL;
            c.offset = sizeof(frm_probe);
            FRM__CARVE(&c, tmp.start, int, count + 1);
            FRM__CARVE(&c, tmp.frame, int, pairs);
            FRM__CARVE(&c, tmp.weight, double, pairs);
            FRM__CARVE(&c, tmp.lever, double, 3 * (size_t)pairs);
            FRM__CARVE(&c, tmp.rest, double, 3 * (size_t)count);
            tmp.bytes = c.offset;
            tmp.allocator = m->allocator;
            p = (frm_probe *)frm__alloc(&m->allocator, tmp.bytes);
            if (!p) {
                err = FRM_ERR_ALLOC;
                break;
            }
            c.base = (char *)p;
            c.offset = sizeof(frm_probe);
            FRM__CARVE(&c, tmp.start, int, count + 1);
            FRM__CARVE(&c, tmp.frame, int, pairs);
            FRM__CARVE(&c, tmp.weight, double, pairs);
            FRM__CARVE(&c, tmp.lever, double, 3 * (size_t)pairs);
            FRM__CARVE(&c, tmp.rest, double, 3 * (size_t)count);
            *p = tmp;
            pairs = 0;
        }
        for (i = 0; i < count && !err; i++) {
            double pt[3], w[FRM_MAX_NEIGHBORS];
            int idx[FRM_MAX_NEIGHBORS + 1], n;
            for (r = 0; r < 3; r++) pt[r] = (double)rest_points[3 * i + r];
            err = frm__probe_point(m, d, &grid, &bins, G, X + 3 * m->frame_count, pt, idx, w, &n);
            for (k = 0; geo && k < n && !err; k++) idx[k] = d->node_frames[idx[k]]; /* nodes -> frames */
            if (err) break;
            if (pass == 1) {
                p->start[i] = pairs;
                for (r = 0; r < 3; r++) p->rest[3 * i + r] = pt[r];
                for (k = 0; k < n; k++) {
                    p->frame[pairs + k] = idx[k];
                    p->weight[pairs + k] = w[k];
                    for (r = 0; r < 3; r++) p->lever[3 * (pairs + k) + r] = pt[r] - X[3 * idx[k] + r];
                }
            }
            pairs += n;
        }
        if (pass == 1 && !err) p->start[count] = pairs;
    }
    if (grid.start) frm__free(&m->allocator, grid.start, grid.bytes);
    frm__bins_free(&bins, &m->allocator);
    frm__free(&m->allocator, X, xbytes);
    if (err) {
        if (p) frm__free(&m->allocator, p, p->bytes);
        return err;
    }
    *out = p;
    return FRM_OK;
}

/* what: 0 positions, 1 displacements, 2 velocities. */
static int frm__probe_eval(const frm_probe *p, const frm_model *m, frm_real *out, int what)
{
    int i, k, r;
    if (!p || !m || !out || p->frame_count != m->frame_count) return FRM_ERR_ARG;
    for (i = 0; i < p->count; i++) {
        double acc[3] = {0, 0, 0};
        for (k = p->start[i]; k < p->start[i + 1]; k++) {
            const double *a = p->lever + 3 * (size_t)k, w = p->weight[k];
            int f = p->frame[k];
            if (what < 2) { /* u_i + (Q_i - I) abar */
                const frm_real *Qm = m->relm + 9 * f;
                for (r = 0; r < 3; r++)
                    acc[r] += w * ((double)m->disp[3 * f + r] + (double)Qm[3 * r] * a[0] + (double)Qm[3 * r + 1] * a[1] +
                                   (double)Qm[3 * r + 2] * a[2]);
            } else { /* v_i + omega_i x Q_i abar */
                const frm_real *Q = m->rel + 9 * f, *v = m->vel + 6 * f;
                double l[3];
                for (r = 0; r < 3; r++) l[r] = (double)Q[3 * r] * a[0] + (double)Q[3 * r + 1] * a[1] + (double)Q[3 * r + 2] * a[2];
                acc[0] += w * ((double)v[0] + (double)v[4] * l[2] - (double)v[5] * l[1]);
                acc[1] += w * ((double)v[1] + (double)v[5] * l[0] - (double)v[3] * l[2]);
                acc[2] += w * ((double)v[2] + (double)v[3] * l[1] - (double)v[4] * l[0]);
            }
        }
        for (r = 0; r < 3; r++) out[3 * i + r] = (frm_real)(what == 0 ? p->rest[3 * i + r] + acc[r] : acc[r]);
    }
    return FRM_OK;
}

FRMDEF int frm_probe_positions(const frm_probe *p, const frm_model *m, frm_real *out) { return frm__probe_eval(p, m, out, 0); }
FRMDEF int frm_probe_displacements(const frm_probe *p, const frm_model *m, frm_real *out)
{
    return frm__probe_eval(p, m, out, 1);
}
FRMDEF int frm_probe_velocities(const frm_probe *p, const frm_model *m, frm_real *out) { return frm__probe_eval(p, m, out, 2); }
FRMDEF int frm_probe_count(const frm_probe *p) { return p ? p->count : 0; }

FRMDEF int frm_probe_jacobian(const frm_probe *p, const frm_model *m, const frm_real *dq, frm_real *out)
{
    int i, k, r;
    if (!p || !m || !dq || !out || p->frame_count != m->frame_count) return FRM_ERR_ARG;
    for (i = 0; i < p->count; i++) {
        double acc[3] = {0, 0, 0};
        for (k = p->start[i]; k < p->start[i + 1]; k++) { /* w (dx + dtheta x Q abar) */
            const double *a = p->lever + 3 * (size_t)k, w = p->weight[k];
            const frm_real *Q = m->rel + 9 * p->frame[k], *v = dq + 6 * p->frame[k];
            double l[3];
            for (r = 0; r < 3; r++) l[r] = (double)Q[3 * r] * a[0] + (double)Q[3 * r + 1] * a[1] + (double)Q[3 * r + 2] * a[2];
            acc[0] += w * ((double)v[0] + (double)v[4] * l[2] - (double)v[5] * l[1]);
            acc[1] += w * ((double)v[1] + (double)v[5] * l[0] - (double)v[3] * l[2]);
            acc[2] += w * ((double)v[2] + (double)v[3] * l[1] - (double)v[4] * l[0]);
        }
        for (r = 0; r < 3; r++) out[3 * i + r] = (frm_real)acc[r];
    }
    return FRM_OK;
}

/* Points in order, each adding to its frames: the sums' order is fixed (deterministic). */
FRMDEF int frm_probe_jacobian_transpose(const frm_probe *p, const frm_model *m, const frm_real *f, frm_real *out,
                                        int add)
{
    int i, k, r;
    if (!p || !m || !f || !out || p->frame_count != m->frame_count) return FRM_ERR_ARG;
    if (!add) memset(out, 0, sizeof(frm_real) * 6 * (size_t)m->frame_count);
    for (i = 0; i < p->count; i++) {
        const double fx = (double)f[3 * i], fy = (double)f[3 * i + 1], fz = (double)f[3 * i + 2];
        for (k = p->start[i]; k < p->start[i + 1]; k++) { /* w (f, Q abar x f) */
            const double *a = p->lever + 3 * (size_t)k, w = p->weight[k];
            const frm_real *Q = m->rel + 9 * p->frame[k];
            frm_real *o = out + 6 * p->frame[k];
            double l[3];
            for (r = 0; r < 3; r++) l[r] = (double)Q[3 * r] * a[0] + (double)Q[3 * r + 1] * a[1] + (double)Q[3 * r + 2] * a[2];
            o[0] = (frm_real)((double)o[0] + w * fx);
            o[1] = (frm_real)((double)o[1] + w * fy);
            o[2] = (frm_real)((double)o[2] + w * fz);
            o[3] = (frm_real)((double)o[3] + w * (l[1] * fz - l[2] * fy));
            o[4] = (frm_real)((double)o[4] + w * (l[2] * fx - l[0] * fz));
            o[5] = (frm_real)((double)o[5] + w * (l[0] * fy - l[1] * fx));
        }
    }
    return FRM_OK;
}

FRMDEF int frm_probe_add_external(const frm_probe *p, frm_model *m, const frm_real *f)
{
    if (!p || !m || !f || p->frame_count != m->frame_count || !frm__all_finite(f, 3 * (size_t)p->count)) return FRM_ERR_ARG;
    return frm_probe_jacobian_transpose(p, m, f, m->ext, 1);
}

FRMDEF int frm_model_set_anchors(frm_model *m, const frm_probe *p, const frm_real *stiffness, const frm_real *targets)
{
    int n;
    if (!m) return FRM_ERR_ARG;
    if (p) { /* the BTD solver factors the assembled blocks, which lack J^T k J: refused when
                chosen, CG while anchors are set when FRM_LINEAR_SOLVER_AUTO chose it */
        if (!stiffness || !targets || p->frame_count != m->frame_count ||
            (m->linear_solver == FRM_LINEAR_SOLVER_BTD && !m->auto_btd))
            return FRM_ERR_ARG;
        for (n = 0; n < p->count; n++)
            if (!(frm__finite((double)stiffness[n]) && stiffness[n] >= 0) || !frm__vec3_finite(targets + 3 * n))
                return FRM_ERR_ARG;
    }
    if (m->auto_btd) m->linear_solver = p ? FRM_LINEAR_SOLVER_CG : FRM_LINEAR_SOLVER_BTD;
    m->anchor_probe = p;
    m->anchor_k = p ? stiffness : NULL;
    m->anchor_target = p ? targets : NULL;
    m->lin_valid = 0;
    return FRM_OK;
}

/* The lever a = Q abar of a probe pair at the current pose. */
static void frm__anchor_lever(const frm_model *m, const frm_probe *p, int k, double l[3])
{
    const double *a = p->lever + 3 * (size_t)k;
    const frm_real *Q = m->rel + 9 * p->frame[k];
    int r;
    for (r = 0; r < 3; r++) l[r] = (double)Q[3 * r] * a[0] + (double)Q[3 * r + 1] * a[1] + (double)Q[3 * r + 2] * a[2];
}

/* The anchors' part of a force pass (frm_model_set_anchors), after the frames' update: per
   point d = p - t (p in the probes' displacement form, minus t), energy k |d|^2 / 2, and
   J^T (-k d) added to m->force (force -k w d, torque -k w a x d per pair). With
   `linearize`, the frame-own rotational term's symmetric part joins lin_hrot:
   K_own = k w (a d^T - (a . d) I) (the derivative of the torque through the lever's turn;
   its antisymmetric part is 1/2 [tau]x of the torque, which the exact product takes from
   lin_torque). Points in order: deterministic. Returns the energy. */
static double frm__anchor_force(frm_model *m, int linearize)
{
    const frm_probe *p = m->anchor_probe;
    double W = 0;
    int n, k, r;
    for (n = 0; n < p->count; n++) {
        double d[3], kn = (double)m->anchor_k[n];
        for (r = 0; r < 3; r++) d[r] = p->rest[3 * n + r] - (double)m->anchor_target[3 * n + r];
        for (k = p->start[n]; k < p->start[n + 1]; k++) {
            const double *a = p->lever + 3 * (size_t)k, w = p->weight[k];
            const frm_real *Qm = m->relm + 9 * p->frame[k], *u = m->disp + 3 * p->frame[k];
            for (r = 0; r < 3; r++)
                d[r] += w * ((double)u[r] + (double)Qm[3 * r] * a[0] + (double)Qm[3 * r + 1] * a[1] + (double)Qm[3 * r + 2] * a[2]);
        }
        W += 0.5 * kn * (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (k = p->start[n]; k < p->start[n + 1]; k++) {
            double l[3], w = p->weight[k], c = -kn * w;
            frm_real *o = m->force + 6 * p->frame[k];
            frm__anchor_lever(m, p, k, l);
            o[0] = (frm_real)((double)o[0] + c * d[0]);
            o[1] = (frm_real)((double)o[1] + c * d[1]);
            o[2] = (frm_real)((double)o[2] + c * d[2]);
            o[3] = (frm_real)((double)o[3] + c * (l[1] * d[2] - l[2] * d[1]));
            o[4] = (frm_real)((double)o[4] + c * (l[2] * d[0] - l[0] * d[2]));
            o[5] = (frm_real)((double)o[5] + c * (l[0] * d[1] - l[1] * d[0]));
            if (linearize) { /* k w (sym(a d^T) - (a . d) I): xx, yy, zz, yz, xz, xy */
                frm_real *h = m->lin_hrot + 6 * p->frame[k];
                double ad = l[0] * d[0] + l[1] * d[1] + l[2] * d[2], kw = kn * w;
                h[0] = (frm_real)((double)h[0] + kw * (l[0] * d[0] - ad));
                h[1] = (frm_real)((double)h[1] + kw * (l[1] * d[1] - ad));
                h[2] = (frm_real)((double)h[2] + kw * (l[2] * d[2] - ad));
                h[3] = (frm_real)((double)h[3] + kw * 0.5 * (l[1] * d[2] + l[2] * d[1]));
                h[4] = (frm_real)((double)h[4] + kw * 0.5 * (l[0] * d[2] + l[2] * d[0]));
                h[5] = (frm_real)((double)h[5] + kw * 0.5 * (l[0] * d[1] + l[1] * d[0]));
            }
        }
    }
    return W;
}

/* out += J^T k J v (the anchors' Gauss-Newton part; their frame-own term is in lin_hrot). */
static void frm__anchor_product(const frm_model *m, const frm_real *v, frm_real *out)
{
    const frm_probe *p = m->anchor_probe;
    int n, k;
    for (n = 0; n < p->count; n++) {
        double jv[3] = {0, 0, 0}, kn = (double)m->anchor_k[n];
        for (k = p->start[n]; k < p->start[n + 1]; k++) {
            const frm_real *x = v + 6 * p->frame[k];
            double l[3], w = p->weight[k];
            frm__anchor_lever(m, p, k, l);
            jv[0] += w * ((double)x[0] + (double)x[4] * l[2] - (double)x[5] * l[1]);
            jv[1] += w * ((double)x[1] + (double)x[5] * l[0] - (double)x[3] * l[2]);
            jv[2] += w * ((double)x[2] + (double)x[3] * l[1] - (double)x[4] * l[0]);
        }
        for (k = p->start[n]; k < p->start[n + 1]; k++) {
            double l[3], c = kn * p->weight[k];
            frm_real *o = out + 6 * p->frame[k];
            frm__anchor_lever(m, p, k, l);
            o[0] = (frm_real)((double)o[0] + c * jv[0]);
            o[1] = (frm_real)((double)o[1] + c * jv[1]);
            o[2] = (frm_real)((double)o[2] + c * jv[2]);
            o[3] = (frm_real)((double)o[3] + c * (l[1] * jv[2] - l[2] * jv[1]));
            o[4] = (frm_real)((double)o[4] + c * (l[2] * jv[0] - l[0] * jv[2]));
            o[5] = (frm_real)((double)o[5] + c * (l[0] * jv[1] - l[1] * jv[0]));
        }
    }
}

/* The diagonal blocks of J^T k J added to kdiag (the block-Jacobi preconditioner's K_ii):
   per pair k w^2 [I, -[a]x; [a]x, |a|^2 I - a a^T]. */
static void frm__anchor_diagonal(frm_model *m)
{
    const frm_probe *p = m->anchor_probe;
    int n, k, r, c;
    for (n = 0; n < p->count; n++)
        for (k = p->start[n]; k < p->start[n + 1]; k++) {
            double l[3], B[36], c2 = (double)m->anchor_k[n] * p->weight[k] * p->weight[k], aa;
            frm_real *K = m->kdiag + 36 * (size_t)p->frame[k];
            frm__anchor_lever(m, p, k, l);
            aa = l[0] * l[0] + l[1] * l[1] + l[2] * l[2];
            memset(B, 0, sizeof B);
            for (r = 0; r < 3; r++) {
                B[7 * r] = 1;
                for (c = 0; c < 3; c++) B[6 * (r + 3) + c + 3] = (r == c ? aa : 0) - l[r] * l[c];
            }
            /* [a]x in the lower-left block, -[a]x upper-right */
            B[6 * 3 + 1] = -l[2], B[6 * 3 + 2] = l[1];
            B[6 * 4 + 0] = l[2], B[6 * 4 + 2] = -l[0];
            B[6 * 5 + 0] = -l[1], B[6 * 5 + 1] = l[0];
            for (r = 0; r < 3; r++)
                for (c = 0; c < 3; c++) B[6 * c + r + 3] = B[6 * (r + 3) + c];
            for (r = 0; r < 36; r++) K[r] = (frm_real)((double)K[r] + c2 * B[r]);
        }
}

FRMDEF void frm_probe_destroy(frm_probe *p)
{
    frm_allocator a;
    if (!p) return;
    a = p->allocator;
    frm__free(&a, p, p->bytes);
}

/* >>modal ------------------------------------------------------------------------------ */

struct frm_modal {
    int count, block, frame_count, max_iterations, found;
    double tolerance, shift;
    frm_real *X, *Y, *Z; /* block vectors of 6 n: the basis, the solves, K Y */
    frm_real *b;         /* one right-hand side */
    double *Kr, *Mr, *V, *ev, *lambda, *work; /* block x block (ev, lambda: block) */
    double *previous;                         /* block: the last iteration's Ritz values */
    frm_allocator allocator;
    size_t bytes;
};

FRMDEF frm_modal_desc frm_modal_default_desc(void)
{
    frm_modal_desc d;
    memset(&d, 0, sizeof d);
    d.count = 6;
    d.max_iterations = 100;
    d.tolerance = (frm_real)(FRM__IS_FLOAT ? 1e-2 : 1e-8);
    d.shift = 0;
    d.internal_cookie = FRM__MODAL_COOKIE;
    return d;
}

static void frm__modal_layout(frm_modal *t, frm__carver *c, int n6)
{
    size_t B = (size_t)t->block;
    FRM__CARVE(c, t->X, frm_real, B * (size_t)n6);
    FRM__CARVE(c, t->Y, frm_real, B * (size_t)n6);
    FRM__CARVE(c, t->Z, frm_real, B * (size_t)n6);
    FRM__CARVE(c, t->b, frm_real, n6);
    FRM__CARVE(c, t->Kr, double, B * B);
    FRM__CARVE(c, t->Mr, double, B * B);
    FRM__CARVE(c, t->V, double, B * B);
    FRM__CARVE(c, t->work, double, B * B);
    FRM__CARVE(c, t->ev, double, B);
    FRM__CARVE(c, t->lambda, double, B);
    FRM__CARVE(c, t->previous, double, B);
}

FRMDEF int frm_modal_create(const frm_model *m, const frm_modal_desc *d, frm_modal **out)
{
    frm_modal tmp, *md;
    frm__carver c;
    int n6;
    if (out) *out = NULL;
    if (!m || !d || !out) return FRM_ERR_ARG;
    if (d->internal_cookie != FRM__MODAL_COOKIE) return FRM_ERR_DESC;
    if (d->count < 1 || d->count > 512 || d->max_iterations < 1 || !(frm__finite((double)d->tolerance) && d->tolerance > 0) ||
        !frm__finite((double)d->shift))
        return FRM_ERR_ARG;
    n6 = 6 * m->frame_count;
    memset(&tmp, 0, sizeof tmp);
    tmp.count = d->count < n6 ? d->count : n6;
    tmp.block = tmp.count + (tmp.count > 8 ? tmp.count : 8);
    if (tmp.block > n6) tmp.block = n6;
    tmp.frame_count = m->frame_count;
    tmp.max_iterations = d->max_iterations;
    tmp.tolerance = (double)d->tolerance;
    tmp.shift = (double)d->shift;
    tmp.allocator = m->allocator;
    c.base = NULL;
    c.offset = sizeof(frm_modal);
    frm__modal_layout(&tmp, &c, n6);
    tmp.bytes = c.offset;
    md = (frm_modal *)frm__alloc(&m->allocator, tmp.bytes);
    if (!md) return FRM_ERR_ALLOC;
    memset(md, 0, tmp.bytes);
    c.base = (char *)md;
    c.offset = sizeof(frm_modal);
    frm__modal_layout(&tmp, &c, n6);
    *md = tmp;
    *out = md;
    return FRM_OK;
}

/* Rayleigh-Ritz on the block Y (bs vectors, K Y in Z): the generalized eigenproblem of
   (Y^T K Y, Y^T M Y) by Cholesky and Jacobi, ascending; X = Y Q (M-orthonormal), Z = K X.
   0, or FRM_ERR_NO_CONVERGENCE when Y^T M Y is not positive definite (a dependent block). */
static int frm__modal_ritz(frm_modal *md, frm_model *m, int bs)
{
    int n6 = 6 * m->frame_count, i, j, k, a;
    double *L = md->Mr, *C = md->work;
    for (i = 0; i < bs; i++)
        for (j = 0; j <= i; j++) {
            const frm_real *yi = md->Y + (size_t)i * n6, *yj = md->Y + (size_t)j * n6, *zj = md->Z + (size_t)j * n6,
                           *zi = md->Z + (size_t)i * n6;
            double mm = 0;
            for (a = 0; a < m->frame_count; a++) {
                double mv[6];
                frm__mass_apply(m, a, yj + 6 * a, mv);
                for (k = 0; k < 6; k++) mm += (double)yi[6 * a + k] * mv[k];
            }
            md->Kr[bs * i + j] = md->Kr[bs * j + i] = 0.5 * (frm__dot(m, yi, zj) + frm__dot(m, yj, zi));
            L[bs * i + j] = L[bs * j + i] = mm;
        }
    /* Cholesky M_r = L L^T (lower, in place) */
    for (j = 0; j < bs; j++) {
        double dsum = L[bs * j + j];
        for (k = 0; k < j; k++) dsum -= L[bs * j + k] * L[bs * j + k];
        if (!(dsum > 0)) return FRM_ERR_NO_CONVERGENCE;
        L[bs * j + j] = sqrt(dsum);
        for (i = j + 1; i < bs; i++) {
            double t = L[bs * i + j];
            for (k = 0; k < j; k++) t -= L[bs * i + k] * L[bs * j + k];
            L[bs * i + j] = t / L[bs * j + j];
        }
        for (i = 0; i < j; i++) L[bs * i + j] = 0;
    }
    /* C = L^-1 K_r L^-T: solve L W = K_r (columns), then L C^T = W^T */
    for (j = 0; j < bs; j++)
        for (i = 0; i < bs; i++) {
            double t = md->Kr[bs * i + j];
            for (k = 0; k < i; k++) t -= L[bs * i + k] * C[bs * k + j];
            C[bs * i + j] = t / L[bs * i + i];
        }
    for (i = 0; i < bs; i++) /* W = C (rows i); C := L^-1 W^T, symmetric */
        for (j = 0; j < bs; j++) md->Kr[bs * i + j] = C[bs * j + i];
    for (j = 0; j < bs; j++)
        for (i = 0; i < bs; i++) {
            double t = md->Kr[bs * i + j];
            for (k = 0; k < i; k++) t -= L[bs * i + k] * C[bs * k + j];
            C[bs * i + j] = t / L[bs * i + i];
        }
    for (i = 0; i < bs; i++)
        for (j = 0; j < i; j++) C[bs * i + j] = C[bs * j + i] = 0.5 * (C[bs * i + j] + C[bs * j + i]);
    frm__jacobi(C, bs, md->V, md->ev);
    /* Q = L^-T V (back substitution per column) into Kr, columns sorted by eigenvalue */
    for (j = 0; j < bs; j++)
        for (i = bs - 1; i >= 0; i--) {
            double t = md->V[bs * i + j];
            for (k = i + 1; k < bs; k++) t -= L[bs * k + i] * md->Kr[bs * k + j];
            md->Kr[bs * i + j] = t / L[bs * i + i];
        }
    {
        int order[1024], tmpi; /* block <= 2 count <= 2000: sort indices by insertion */
        int *ord = bs <= 1024 ? order : NULL;
        if (!ord) return FRM_ERR_NO_CONVERGENCE;
        for (i = 0; i < bs; i++) ord[i] = i;
        for (i = 1; i < bs; i++)
            for (j = i; j > 0 && md->ev[ord[j]] < md->ev[ord[j - 1]]; j--) tmpi = ord[j], ord[j] = ord[j - 1], ord[j - 1] = tmpi;
        /* X = Y Q, Z = K Y Q (Z through the X storage as temporary: Z is rebuilt from it) */
        for (k = 0; k < n6; k++) {
            double y[1024], z[1024];
            for (i = 0; i < bs; i++) y[i] = (double)md->Y[(size_t)i * n6 + k], z[i] = (double)md->Z[(size_t)i * n6 + k];
            for (j = 0; j < bs; j++) {
                double tx = 0, tz = 0;
                for (i = 0; i < bs; i++) tx += y[i] * md->Kr[bs * i + ord[j]], tz += z[i] * md->Kr[bs * i + ord[j]];
                md->X[(size_t)j * n6 + k] = (frm_real)tx;
                md->Z[(size_t)j * n6 + k] = (frm_real)tz;
            }
        }
        for (j = 0; j < bs; j++) md->lambda[j] = md->ev[ord[j]];
    }
    return FRM_OK;
}

#define FRM__MODAL_INDEFINITE 1

static int frm__modal_iterate(frm_modal *md, frm_model *m, int bs, int want, double shift, double cg_tol);

FRMDEF int frm_modal_solve(frm_modal *md, frm_model *m)
{
    int i, k, free_dof = 0, bs, want, err, attempt;
    double shift, cg_tol;
    if (!md || !m || md->frame_count != m->frame_count) return FRM_ERR_ARG;
    if (md->block > 1024) return FRM_ERR_ARG;
    md->found = 0;
    frm__reset_stats(m);
    m->coarse_plain = -1; /* a modal solve does not depend on earlier solves (its own bits repeat) */
    m->lin_predict = -1;
    for (i = 0; i < m->frame_count; i++)
        if (m->state[i] == FRM__FREE)
            for (k = 0; k < 6; k++) free_dof += !((m->axes[i] >> k) & 1);
    if (free_dof == 0) return FRM_OK;
    bs = md->block < free_dof ? md->block : free_dof;
    want = md->count < bs ? md->count : bs;
    err = frm__linearize(m, NULL, 0);
    if (err) return err;
    frm__mass_update(m);
    shift = md->shift;
    if (!(shift > 0)) { /* 1e-4 of the mean translational K_ii / m_i */
        double sum = 0;
        int count = 0;
        for (i = 0; i < m->frame_count; i++)
            if (m->state[i] == FRM__FREE && m->mass_world[10 * (size_t)i] > 0) {
                const frm_real *K = m->kdiag + 36 * (size_t)i;
                sum += ((double)K[0] + (double)K[7] + (double)K[14]) / (3 * (double)m->mass_world[10 * (size_t)i]);
                count++;
            }
        shift = count && sum > 0 ? 1e-4 * sum / count : 1;
    }
    cg_tol = 1e-3 * md->tolerance;
    for (attempt = 0;; attempt++) {
        err = frm__modal_iterate(md, m, bs, want, shift, cg_tol);
        /* K + shift M indefinite (a state off equilibrium, gravity's torques, compression):
           an automatic shift grows a hundredfold, up to three times */
        if (err != FRM__MODAL_INDEFINITE || md->shift > 0 || attempt == 3) break;
        shift *= 100;
    }
    m->lin_valid = 0;
    if (err == FRM__MODAL_INDEFINITE) err = FRM_ERR_NO_CONVERGENCE;
    if (!err) md->found = want;
    return err;
}

/* The subspace iteration at a given shift (frm_modal_solve). */
static int frm__modal_iterate(frm_modal *md, frm_model *m, int bs, int want, double shift, double cg_tol)
{
    int n6 = 6 * m->frame_count, i, j, k, it, err, converged = 0;
    unsigned long long seed = 0x9E3779B97F4A7C15ull;
    frm__build_precond(m, shift, 1.0);
    if (cg_tol < (FRM__IS_FLOAT ? 1e-6 : 1e-13)) cg_tol = FRM__IS_FLOAT ? 1e-6 : 1e-13;
    /* deterministic start: pseudo-random vectors on the free components */
    for (j = 0; j < bs; j++) {
        frm_real *x = md->X + (size_t)j * n6;
        for (k = 0; k < n6; k++) x[k] = (frm_real)(frm__random(&seed) - 0.5);
        frm__mask(m, x);
    }
    for (it = 0; it < md->max_iterations && !converged; it++) {
        double worst = 0, change = 0;
        if (it) memcpy(md->previous, md->lambda, sizeof(double) * (size_t)bs);
        for (j = 0; j < bs; j++) { /* Y_j = (K + shift M)^-1 M X_j */
            const frm_real *x = md->X + (size_t)j * n6;
            frm_real *y = md->Y + (size_t)j * n6;
            int cg;
            for (i = 0; i < m->frame_count; i++) {
                double mv[6];
                frm__mass_apply(m, i, x + 6 * i, mv);
                for (k = 0; k < 6; k++) md->b[6 * i + k] = (frm_real)mv[k];
            }
            if (it == 0) memset(y, 0, sizeof(frm_real) * (size_t)n6);
            else /* the Ritz vector's own answer, x / (lambda + shift): exact once converged */
                for (k = 0; k < n6; k++) y[k] = (frm_real)((double)x[k] / (md->lambda[j] + shift));
            cg = frm__linear_solve(m, shift, 1.0, cg_tol, md->b, y);
            if (cg == FRM__CG_NOT_FINITE) return FRM_ERR_NOT_FINITE;
            if (cg == FRM__CG_NEGATIVE) return FRM__MODAL_INDEFINITE;
            if (cg != FRM__CG_OK) return FRM_ERR_NO_CONVERGENCE;
            frm__stiffness_product(m, y, md->Z + (size_t)j * n6, 0);
            frm__mask(m, md->Z + (size_t)j * n6);
        }
        err = frm__modal_ritz(md, m, bs);
        if (err) return err;
        for (j = 0; j < want; j++) { /* residual |K x - lambda M x| / ((|lambda| + shift) |M x|) */
            const frm_real *x = md->X + (size_t)j * n6, *z = md->Z + (size_t)j * n6;
            double rr = 0, mm = 0, r;
            for (i = 0; i < m->frame_count; i++) {
                double mv[6];
                if (m->state[i] != FRM__FREE) continue;
                frm__mass_apply(m, i, x + 6 * i, mv);
                for (k = 0; k < 6; k++) {
                    double d;
                    if ((m->axes[i] >> k) & 1) continue;
                    d = (double)z[6 * i + k] - md->lambda[j] * mv[k];
                    rr += d * d;
                    mm += mv[k] * mv[k];
                }
            }
            r = sqrt(rr) / ((fabs(md->lambda[j]) + shift) * sqrt(mm));
            if (!frm__finite(r)) return FRM_ERR_NOT_FINITE;
            if (r > worst) worst = r;
            if (it && fabs(md->lambda[j] - md->previous[j]) / (fabs(md->lambda[j]) + shift) > change)
                change = fabs(md->lambda[j] - md->previous[j]) / (fabs(md->lambda[j]) + shift);
        }
        /* the residual, or Ritz values that no longer move: the K products' rounding bounds
           the residual near eps |K| / (lambda + shift) (float: above 1e-4 on slender beams) */
        converged = worst <= md->tolerance || (it > 1 && change <= 1e-2 * md->tolerance);
    }
    return converged ? FRM_OK : FRM_ERR_NO_CONVERGENCE;
}

FRMDEF int frm_modal_count(const frm_modal *md) { return md ? md->found : 0; }

FRMDEF double frm_modal_frequency(const frm_modal *md, int i)
{
    if (!md || i < 0 || i >= md->found) return -1;
    return md->lambda[i] >= 0 ? sqrt(md->lambda[i]) / (2 * 3.14159265358979323846)
                              : -sqrt(-md->lambda[i]) / (2 * 3.14159265358979323846);
}

FRMDEF const frm_real *frm_modal_shape(const frm_modal *md, int i)
{
    if (!md || i < 0 || i >= md->found) return NULL;
    return md->X + (size_t)i * 6 * (size_t)md->frame_count;
}

FRMDEF void frm_modal_destroy(frm_modal *md)
{
    frm_allocator a;
    if (!md) return;
    a = md->allocator;
    frm__free(&a, md, md->bytes);
}

/* >>btd -------------------------------------------------------------------------------- */

/* Block LDL^T of a symmetric block-tridiagonal matrix, blocks of 6 (see the public
   declarations and BLOCK-TRIDIAGONAL SOLVER): A = L D L^T with L unit block lower
   bidiagonal, L(i + 1, i) = E_i = B_i D_i^-1 (B_i = A(i + 1, i)) and
   D_{i+1} = A(i + 1, i + 1) - E_i B_i^T. Per block i the factor holds
       D_i^-1 (symmetric, stored full) and E_i^T = D_i^-1 B_i^T (row-major).
   All three come from one symmetric sweep (Gauss-Jordan elimination without square roots)
   of the 12 x 12 window [D_i B_i^T; B_i A(i + 1, i + 1)] over its first six pivots: pivot k
   (p = a_kk, r = 1/p) subtracts a_jk a_km r from every other entry, scales row and column k
   by r and leaves -r on the diagonal; after six pivots the window holds
   [-D_i^-1, D_i^-1 B_i^T; B_i D_i^-1, D_{i+1}]. Each pivot's update of the next block's
   diagonal happens as soon as that pivot is known, so the sequential chain through the
   whole factorisation is one division and two multiply-adds a pivot; every other operation
   is a fixed-size row update off that chain. The pivots are those of an LDL^T (Cholesky's
   squared diagonal), judged as before. Solve: forward y_i = b_i - E_{i-1} y_{i-1},
   z_i = D_i^-1 y_i; backward x_i = z_i - E_i^T x_{i+1}: one 6x6 product a block on each
   sweep's chain (z off it). */

FRMDEF size_t frm_btd_factor_size(int n) { return n < 1 ? 0 : (size_t)72 * (size_t)n; }

/* A row of the window (6 doubles): with GCC or Clang vectors (AVX: one of 4 and one of 2,
   a ymm and an xmm register; otherwise three of 2), elsewhere an array and loops. The
   parts are named by FRM__BTD_PARTS; a lane is picked at compile time where the index is a
   constant. */
#if (defined(__GNUC__) || defined(__clang__)) && !defined(FRM_BTD_NO_VECTOR_EXTENSIONS)
#define FRM__BTD_VECTOR 1
typedef double frm__v2 __attribute__((vector_size(16)));
#ifdef __AVX__
typedef double frm__v4 __attribute__((vector_size(32)));
typedef struct frm__v8 {
    frm__v4 lo;
    frm__v2 hi;
} frm__v8;
#define FRM__BTD_PARTS(OP) OP(lo) OP(hi)
#define FRM__BTD_LANE(x, j) ((j) < 4 ? (x).lo[(j) & 3] : (x).hi[(j) & 1])
#define FRM__BTD_LOAD(x, p) (memcpy(&(x).lo, (p), 4 * sizeof(double)), memcpy(&(x).hi, (p) + 4, 2 * sizeof(double)))
#define FRM__BTD_STORE(p, x) (memcpy((p), &(x).lo, 4 * sizeof(double)), memcpy((p) + 4, &(x).hi, 2 * sizeof(double)))
#else
typedef struct frm__v8 {
    frm__v2 p0, p1, hi;
} frm__v8;
#define FRM__BTD_PARTS(OP) OP(p0) OP(p1) OP(hi)
#define FRM__BTD_LANE(x, j) ((j) < 2 ? (x).p0[(j) & 1] : (j) < 4 ? (x).p1[(j) & 1] : (x).hi[(j) & 1])
#define FRM__BTD_LOAD(x, p)                                                                            \
    (memcpy(&(x).p0, (p), 2 * sizeof(double)), memcpy(&(x).p1, (p) + 2, 2 * sizeof(double)),           \
     memcpy(&(x).hi, (p) + 4, 2 * sizeof(double)))
#define FRM__BTD_STORE(p, x)                                                                           \
    (memcpy((p), &(x).p0, 2 * sizeof(double)), memcpy((p) + 2, &(x).p1, 2 * sizeof(double)),           \
     memcpy((p) + 4, &(x).hi, 2 * sizeof(double)))
#endif
#define FRM__ALWAYS_INLINE static inline __attribute__((always_inline))
#else
typedef struct frm__v8 {
    double e[6];
} frm__v8;
#define FRM__BTD_LANE(x, j) ((x).e[j])
#define FRM__BTD_LOAD(x, p) memcpy((x).e, (p), 6 * sizeof(double))
#define FRM__BTD_STORE(p, x) memcpy((p), (x).e, 6 * sizeof(double))
#define FRM__ALWAYS_INLINE static inline
#endif

/* One pivot k (a constant where inlined; r = 1 / a_kk) of the sweep, with the pivots'
   column scaling deferred: T holds T~ = T diag(1 / sigma), sigma_b = r_b once column b has
   been pivoted (1 before; the block stores D^-1 = -T~ sigma). Every row a of T~ loses
   c_a w0 with c = T~_k sigma (the true row k) and w0 = T~_k r but 0 in lane k, then row k
   is replaced by w0 with -1 in lane k and sigma_k = r; U's rows lose c_a (v r), N loses
   v v^T r (v: row k of U). The unpivoted columns hold T's values exactly (the pivots, e
   and q); the scaled ones differ from scaling at each pivot (T_a s - c_a w0, the first
   form) by one rounding. 1,000 blocks with 4 + 2 rows at -O3 -march=x86-64-v3: 111 -> 99
   us; plain -O2: 179 -> 171 us. */
FRM__ALWAYS_INLINE void frm__btd_sweep(const int k, const double r, frm__v8 *T, frm__v8 *U, frm__v8 *N, frm__v8 *sg)
{
    frm__v8 c, v = U[k], w0, wk, wu;
    int a;
#ifdef FRM__BTD_VECTOR
    /* e_k and 1 - e_k as constant vectors: w0 = T~_k r (1 - e_k), wk = w0 - e_k,
       sigma = sigma (1 - e_k) + e_k r, each lane exact (a product by 1 or 0, a sum with 0) */
    static const double eye[6][6] = {{1, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0}, {0, 0, 1, 0, 0, 0},
                                     {0, 0, 0, 1, 0, 0}, {0, 0, 0, 0, 1, 0}, {0, 0, 0, 0, 0, 1}};
    static const double off[6][6] = {{0, 1, 1, 1, 1, 1}, {1, 0, 1, 1, 1, 1}, {1, 1, 0, 1, 1, 1},
                                     {1, 1, 1, 0, 1, 1}, {1, 1, 1, 1, 0, 1}, {1, 1, 1, 1, 1, 0}};
    frm__v8 m, m1;
    FRM__BTD_LOAD(m, eye[k]);
    FRM__BTD_LOAD(m1, off[k]);
#define FRM__BTD_SCALE(P)                                                                              \
    c.P = T[k].P * sg->P, wu.P = v.P * r, w0.P = T[k].P * r * m1.P, wk.P = w0.P - m.P,                 \
    sg->P = sg->P * m1.P + m.P * r;
    FRM__BTD_PARTS(FRM__BTD_SCALE)
#undef FRM__BTD_SCALE
    for (a = 0; a < 6; a++) {
        const double ca = FRM__BTD_LANE(c, a), va = FRM__BTD_LANE(v, a);
#define FRM__BTD_UPDATE(P) T[a].P = T[a].P - ca * w0.P, U[a].P = U[a].P - ca * wu.P, N[a].P = N[a].P - va * wu.P;
        FRM__BTD_PARTS(FRM__BTD_UPDATE)
#undef FRM__BTD_UPDATE
    }
#else
    int b;
    for (b = 0; b < 6; b++) {
        c.e[b] = T[k].e[b] * sg->e[b];
        wk.e[b] = b == k ? -1.0 : T[k].e[b] * r;
        w0.e[b] = b == k ? 0.0 : T[k].e[b] * r;
        wu.e[b] = v.e[b] * r;
    }
    sg->e[k] = r;
    for (a = 0; a < 6; a++)
        for (b = 0; b < 6; b++) {
            T[a].e[b] -= c.e[a] * w0.e[b];
            U[a].e[b] -= c.e[a] * wu.e[b];
            N[a].e[b] -= v.e[a] * wu.e[b];
        }
#endif
    T[k] = wk;
    U[k] = wu;
}

/* Block i's six pivots pv judged: each must be finite and above tol times the block's own
   diagonal entry A_kk (A: the block's 36 reals). Returns 0, or the first refused pivot's
   code (FRM_ERR_NOT_FINITE, FRM_ERR_BTD_INDEFINITE below -tol A_kk, FRM_ERR_BTD_SINGULAR
   within it) with *failed_block = i. The pass is branch-free; the code is found again only
   on refusal. */
static int frm__btd_judge(const double *pv, const frm_real *A, const double tol, int i, int *failed_block)
{
    int k, ok = 1, err = FRM_ERR_NOT_FINITE;
    for (k = 0; k < 6; k++) ok &= (pv[k] > tol * fabs((double)A[7 * k])) & (pv[k] <= DBL_MAX);
    if (ok) return FRM_OK;
    for (k = 0; k < 6; k++) {
        const double p = pv[k], scale = fabs((double)A[7 * k]);
        if (!frm__finite(p)) break;
        if (!(p > tol * scale)) {
            err = p < -tol * scale ? FRM_ERR_BTD_INDEFINITE : FRM_ERR_BTD_SINGULAR;
            break;
        }
    }
    if (failed_block) *failed_block = i;
    return err;
}

/* Pivot k of block i, swept; p becomes the next pivot, computed from r by one multiply-add
   (the next pivot's entry loses e^2 r; e its entry in row k), which is the factorisation's
   whole sequential chain. The pivot is recorded in pv and judged with the block's other
   five by frm__btd_judge after the sixth (a refused pivot's block is abandoned before its
   output is stored, so nothing changes but the branches: one a block instead of three a
   pivot). */
#define FRM__BTD_PIVOT(k)                                                                              \
    do {                                                                                               \
        double r_, q_, e_;                                                                             \
        pv[k] = p;                                                                                     \
        r_ = 1.0 / p;                                                                                  \
        e_ = (k) < 5 ? FRM__BTD_LANE(T[k], ((k) + 1) % 6) : FRM__BTD_LANE(U[k], 0);                   \
        q_ = (k) < 5 ? FRM__BTD_LANE(T[((k) + 1) % 6], ((k) + 1) % 6) : FRM__BTD_LANE(N[0], 0);        \
        frm__btd_sweep((k), r_, T, U, N, &sg);                                                         \
        p = q_ - (e_ * e_) * r_;                                                                       \
    } while (0)

#if defined(FRM__BTD_VECTOR) && defined(__AVX512F__) && !FRM__CAT(FRM__IS_, FRM_REAL) &&                     \
    !defined(FRM_BTD_NO_AVX512)
/* AVX-512, double builds: a row is one zmm register (lanes 6 and 7 zero), each row update
   one instruction (two with the 4 + 2 split), the 18 rows of the window in 18 of the 32
   registers as named variables (arrays of vectors stayed on the stack); lane masks replace
   the e_k / 1 - e_k constant vectors; the broadcasts of c_a and v_a read c and v back
   from a small array (loads, not shuffles); the pivots' column scaling deferred as in
   frm__btd_sweep (factor 50 -> 46 us for 1,000 blocks). The same operations and roundings
   as frm__btd_sweep where the compiler fuses its multiply-adds (-ffp-contract=fast). */
#include <immintrin.h>
#define FRM__BTD_ZMM 1
/* row a (a literal) in pivot k (a literal) */
#define FRM__BTD_ZROW(a, k)                                                                            \
    N##a = _mm512_fnmadd_pd(_mm512_set1_pd(vb_[a]), wu_, N##a);                                        \
    if ((a) != (k)) {                                                                                  \
        const __m512d ca_ = _mm512_set1_pd(cb_[a]);                                                    \
        T##a = _mm512_fnmadd_pd(ca_, w0_, T##a);                                                       \
        U##a = _mm512_fnmadd_pd(ca_, wu_, U##a);                                                       \
    }
/* Pivot k of block i (k1 = k + 1 mod 6), as FRM__BTD_PIVOT then frm__btd_sweep. Rows k of
   T and U go through cb_ / vb_ so that the broadcasts of their lanes are loads; the empty
   asm statement (no instruction) stops GCC from turning those loads back into shuffles of
   the registers (port 5, which the 512-bit multiply-adds share on Intel): factor 76 -> 48
   us for 1,000 blocks. The pivot is judged with the block's others (frm__btd_judge). */
#define FRM__BTD_ZPIVOT(k, k1)                                                                         \
    do {                                                                                               \
        const __mmask8 mk_ = (__mmask8)(1u << (k)), rest_ = (__mmask8)(0x3fu & ~(1u << (k)));          \
        double r_, q_, e_;                                                                             \
        __m512d rv_, wu_, w0_;                                                                         \
        pv_[k] = p;                                                                                    \
        r_ = 1.0 / p;                                                                                  \
        _mm512_store_pd(cb_, _mm512_mul_pd(T##k, sigma));                                              \
        _mm512_store_pd(vb_, U##k);                                                                    \
        __asm__("" : "+m"(cb_), "+m"(vb_));                                                            \
        e_ = (k) < 5 ? cb_[k1] : vb_[0];                                                               \
        q_ = (k) < 5 ? T##k1[k1] : N0[0];                                                              \
        rv_ = _mm512_set1_pd(r_);                                                                      \
        wu_ = _mm512_mul_pd(U##k, rv_);                                                                \
        w0_ = _mm512_maskz_mul_pd(rest_, T##k, rv_);                                                   \
        FRM__BTD_ZROW(0, k) FRM__BTD_ZROW(1, k) FRM__BTD_ZROW(2, k)                                    \
        FRM__BTD_ZROW(3, k) FRM__BTD_ZROW(4, k) FRM__BTD_ZROW(5, k)                                    \
        T##k = _mm512_mask_mov_pd(w0_, mk_, _mm512_set1_pd(-1.0));                                     \
        sigma = _mm512_mask_mov_pd(sigma, mk_, rv_);                                                   \
        U##k = wu_;                                                                                    \
        p = q_ - (e_ * e_) * r_;                                                                       \
    } while (0)
/* row a of a symmetric block from its lower triangle (a's entries up to the diagonal, then
   column a below it), by a gather of constant indices */
#define FRM__BTD_ZSYM(S, a, A)                                                                         \
    S = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), 0x3f,                                           \
                                 _mm256_setr_epi32(6 * a, a >= 1 ? 6 * a + 1 : 6 + a, a >= 2 ? 6 * a + 2 : 12 + a, \
                                                   a >= 3 ? 6 * a + 3 : 18 + a, a >= 4 ? 6 * a + 4 : 24 + a,      \
                                                   a >= 5 ? 6 * a + 5 : 30 + a, 0, 0),                          \
                                 (A), 8)
/* row a of B^T (column a of B) */
#define FRM__BTD_ZCOL(S, a, B)                                                                         \
    S = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), 0x3f, _mm256_setr_epi32(a, 6 + a, 12 + a, 18 + a, 24 + a, 30 + a, 0, 0), \
                                 (B), 8)
#define FRM__BTD_ZLOAD(a) FRM__BTD_ZSYM(N##a, a, A + 36), FRM__BTD_ZCOL(U##a, a, lower + 36 * (size_t)i);
#define FRM__BTD_ZZERO(a) N##a = U##a = _mm512_setzero_pd();
#define FRM__BTD_ZOUT(a)                                                                               \
    _mm512_mask_storeu_pd(Dout + 6 * a, 0x3f, _mm512_mul_pd(T##a, nsigma));                            \
    _mm512_mask_storeu_pd(Eout + 6 * a, 0x3f, U##a);
#define FRM__BTD_ZNEXT(a) T##a = N##a;
#define FRM__BTD_Z6(OP) OP(0) OP(1) OP(2) OP(3) OP(4) OP(5)
static int frm__btd_factor_zmm(int n, const double *diag, const double *lower, double *factor, int *failed_block,
                               const double tol)
{
    __m512d T0, T1, T2, T3, T4, T5, U0, U1, U2, U3, U4, U5, N0, N1, N2, N3, N4, N5, acc;
    const __m256i diagonal = _mm256_setr_epi32(0, 7, 14, 21, 28, 35, 0, 0);
    double cb_[8] __attribute__((aligned(64))), vb_[8] __attribute__((aligned(64))),
        pv_[8] __attribute__((aligned(64))) = {0, 0, 0, 0, 0, 0, 0, 0};
    double p = diag[0];
    int i;
    FRM__BTD_ZSYM(T0, 0, diag), FRM__BTD_ZSYM(T1, 1, diag), FRM__BTD_ZSYM(T2, 2, diag);
    FRM__BTD_ZSYM(T3, 3, diag), FRM__BTD_ZSYM(T4, 4, diag), FRM__BTD_ZSYM(T5, 5, diag);
    for (i = 0; i < n; i++) {
        const double *A = diag + 36 * (size_t)i;
        double *Dout = factor + 72 * (size_t)i, *Eout = Dout + 36;
        if (i + 1 < n) {
            FRM__BTD_Z6(FRM__BTD_ZLOAD)
        } else {
            FRM__BTD_Z6(FRM__BTD_ZZERO)
        }
        __m512d sigma = _mm512_set1_pd(1.0), nsigma;
        FRM__BTD_ZPIVOT(0, 1);
        FRM__BTD_ZPIVOT(1, 2);
        FRM__BTD_ZPIVOT(2, 3);
        FRM__BTD_ZPIVOT(3, 4);
        FRM__BTD_ZPIVOT(4, 5);
        FRM__BTD_ZPIVOT(5, 0);
        acc = _mm512_add_pd(_mm512_add_pd(_mm512_add_pd(U0, U1), _mm512_add_pd(U2, U3)), _mm512_add_pd(U4, U5));
        { /* the six pivots judged at once, as frm__btd_judge judges them (one branch a block
             instead of three a pivot: factor 69 -> 50 us for 1,000 blocks), and E_i^T's
             column sums finite */
            const __m512d P = _mm512_load_pd(pv_),
                          S = _mm512_mul_pd(_mm512_set1_pd(tol), _mm512_abs_pd(_mm512_mask_i32gather_pd(
                                                                     _mm512_setzero_pd(), 0x3f, diagonal, A, 8)));
            const __mmask8 ok = _mm512_mask_cmp_pd_mask(0x3f, P, S, _CMP_GT_OQ) &
                                _mm512_mask_cmp_pd_mask(0x3f, P, _mm512_set1_pd(DBL_MAX), _CMP_LE_OQ);
            if ((__mmask8)(ok & _mm512_mask_cmp_pd_mask(0x3f, _mm512_sub_pd(acc, acc), _mm512_setzero_pd(), _CMP_EQ_OQ)) != 0x3f) {
                if (ok != 0x3f) return frm__btd_judge(pv_, A, tol, i, failed_block);
                if (failed_block) *failed_block = i;
                return FRM_ERR_NOT_FINITE;
            }
        }
        nsigma = _mm512_sub_pd(_mm512_setzero_pd(), sigma);
        FRM__BTD_Z6(FRM__BTD_ZOUT)
        FRM__BTD_Z6(FRM__BTD_ZNEXT)
    }
    return FRM_OK;
}
#endif

/* the portable factorisation (arguments checked by frm_btd_factor): rows as frm__v8 */
static int frm__btd_factor_rows(int n, const frm_real *diag, const frm_real *lower, frm_real *factor, int *failed_block,
                                const double tol)
{
    int i, a, b;
    /* the window: T = rows / columns 0..5, U = rows 0..5 x columns 6..11, N = rows /
       columns 6..11 */
    static const double ones[6] = {1, 1, 1, 1, 1, 1};
    frm__v8 T[6], U[6], N[6], sg;
    double t[6][6], p, pv[6];
    memset(t, 0, sizeof t);
    for (a = 0; a < 6; a++)
        for (b = 0; b <= a; b++) t[a][b] = t[b][a] = (double)diag[6 * a + b];
    for (a = 0; a < 6; a++) FRM__BTD_LOAD(T[a], t[a]);
    p = t[0][0];
    for (i = 0; i < n; i++) {
        const frm_real *A = diag + 36 * (size_t)i;
        frm_real *Dout = factor + 72 * (size_t)i, *Eout = Dout + 36;
        double usum = 0, u[6][6];
        memset(t, 0, sizeof t);
        memset(u, 0, sizeof u);
        if (i + 1 < n) {
            const frm_real *B = lower + 36 * (size_t)i, *A1 = A + 36;
            for (a = 0; a < 6; a++)
                for (b = 0; b < 6; b++) u[b][a] = (double)B[6 * a + b]; /* B^T */
            for (a = 0; a < 6; a++)
                for (b = 0; b <= a; b++) t[a][b] = t[b][a] = (double)A1[6 * a + b];
        }
        for (a = 0; a < 6; a++) FRM__BTD_LOAD(U[a], u[a]), FRM__BTD_LOAD(N[a], t[a]);
        FRM__BTD_LOAD(sg, ones);
        FRM__BTD_PIVOT(0);
        FRM__BTD_PIVOT(1);
        FRM__BTD_PIVOT(2);
        FRM__BTD_PIVOT(3);
        FRM__BTD_PIVOT(4);
        FRM__BTD_PIVOT(5);
        a = frm__btd_judge(pv, A, tol, i, failed_block);
        if (a) return a;
#if defined(FRM__BTD_VECTOR) && !FRM__CAT(FRM__IS_, FRM_REAL)
        { /* double: rows stored straight from the registers (factor 109 -> 97 us for 1,000
             blocks against staging them through arrays, -O3 -march=native, best of 50) */
            frm__v8 acc = U[0], d;
            for (a = 0; a < 6; a++) {
#define FRM__BTD_OUT(P) d.P = -(T[a].P * sg.P), acc.P = a ? acc.P + U[a].P : acc.P;
                FRM__BTD_PARTS(FRM__BTD_OUT)
#undef FRM__BTD_OUT
                FRM__BTD_STORE(Dout + 6 * a, d);
                FRM__BTD_STORE(Eout + 6 * a, U[a]);
            }
            for (b = 0; b < 6; b++) usum += FRM__BTD_LANE(acc, b);
        }
#else
        FRM__BTD_STORE(pv, sg); /* (the pivots are judged) */
        for (a = 0; a < 6; a++) {
            FRM__BTD_STORE(t[a], T[a]);
            FRM__BTD_STORE(u[a], U[a]);
            for (b = 0; b < 6; b++) {
                Dout[6 * a + b] = (frm_real)(-(t[a][b] * pv[b]));
                Eout[6 * a + b] = (frm_real)u[a][b];
                usum += u[a][b];
            }
        }
#endif
        if (!frm__finite(usum)) {
            if (failed_block) *failed_block = i;
            return FRM_ERR_NOT_FINITE;
        }
        for (a = 0; a < 6; a++) T[a] = N[a];
    }
    return FRM_OK;
}
#undef FRM__BTD_PIVOT

FRMDEF int frm_btd_factor(int n, const frm_real *diag, const frm_real *lower, frm_real *factor, int *failed_block)
{
    const double tol = 4.0 * (double)(n + 16) * (FRM__IS_FLOAT ? (double)FLT_EPSILON : DBL_EPSILON);
    if (failed_block) *failed_block = -1;
    if (n < 1 || !diag || !factor || (n > 1 && !lower)) return FRM_ERR_ARG;
#ifdef FRM__BTD_ZMM
    (void)frm__btd_factor_rows; /* kept for the tests, which compare the two */
    return frm__btd_factor_zmm(n, diag, lower, factor, failed_block, tol);
#else
    return frm__btd_factor_rows(n, diag, lower, factor, failed_block, tol);
#endif
}

FRMDEF int frm_btd_solve(int n, const frm_real *factor, int nrhs, frm_real *b)
{
    int i, r, a, k, bad = 0;
    double chk[6] = {0, 0, 0, 0, 0, 0};
    size_t n6 = 6 * (size_t)n;
    if (n < 1 || !factor || !b || nrhs < 0) return FRM_ERR_ARG;
    for (r = 0; r < nrhs; r++) {
        frm_real *x = b + n6 * (size_t)r;
        double y[6] = {0, 0, 0, 0, 0, 0}, t[6];
        for (i = 0; i < n; i++) { /* forward: y_i = b_i - E_{i-1} y_{i-1}; x_i = z_i = D_i^-1 y_i */
            const frm_real *Di = factor + 72 * (size_t)i;
            if (i > 0) { /* two partial sums: the sweep's chain is 3 multiply-adds and an add a block */
                const frm_real *Et = Di - 36;
                double h[6];
                for (a = 0; a < 6; a++) t[a] = (double)x[6 * i + a], h[a] = 0;
                for (k = 0; k < 6; k += 2)
                    for (a = 0; a < 6; a++) {
                        t[a] -= (double)Et[6 * k + a] * y[k];
                        h[a] += (double)Et[6 * k + 6 + a] * y[k + 1];
                    }
                for (a = 0; a < 6; a++) t[a] -= h[a];
            } else
                for (a = 0; a < 6; a++) t[a] = (double)x[6 * i + a];
            for (a = 0; a < 6; a++) y[a] = t[a];
            for (a = 0; a < 6; a++) {
                double s = 0;
                for (k = 0; k < 6; k++) s += (double)Di[6 * a + k] * t[k];
                x[6 * i + a] = (frm_real)s;
            }
        }
        for (a = 0; a < 6; a++) y[a] = (double)x[n6 - 6 + a], chk[a] += y[a] - y[a];
        for (i = n - 2; i >= 0; i--) { /* backward: x_i = z_i - E_i^T x_{i+1} */
            const frm_real *Et = factor + 72 * (size_t)i + 36;
            for (a = 0; a < 6; a++) { /* two partial sums, as forward */
                double s = (double)x[6 * i + a], h = 0;
                for (k = 0; k < 6; k += 2) {
                    s -= (double)Et[6 * a + k] * y[k];
                    h += (double)Et[6 * a + k + 1] * y[k + 1];
                }
                t[a] = s - h;
            }
            for (a = 0; a < 6; a++) {
                y[a] = t[a];
                x[6 * i + a] = (frm_real)t[a];
                chk[a] += t[a] - t[a]; /* 0, or NaN from a non-finite answer */
            }
        }
    }
    for (a = 0; a < 6; a++) bad |= !(chk[a] == 0);
    if (bad) {
        memset(b, 0, sizeof(frm_real) * n6 * (size_t)nrhs);
        return FRM_ERR_NOT_FINITE;
    }
    return FRM_OK;
}

FRMDEF int frm_btd_compliance(int n, const frm_real *factor, int rows, const frm_real *J, frm_real *W, frm_real *work)
{
    int a, b, err;
    size_t k, n6 = 6 * (size_t)n;
    if (n < 1 || !factor || rows < 1 || !J || !W || !work) return FRM_ERR_ARG;
    memcpy(work, J, sizeof(frm_real) * n6 * (size_t)rows);
    err = frm_btd_solve(n, factor, rows, work);
    if (err) return err;
    for (a = 0; a < rows; a++)
        for (b = 0; b <= a; b++) {
            double s = 0, t = 0;
            for (k = 0; k < n6; k++) {
                s += (double)J[n6 * (size_t)a + k] * (double)work[n6 * (size_t)b + k];
                t += (double)J[n6 * (size_t)b + k] * (double)work[n6 * (size_t)a + k];
            }
            W[rows * a + b] = W[rows * b + a] = (frm_real)(0.5 * (s + t));
        }
    return FRM_OK;
}

/* FRM_LINEAR_SOLVER_BTD on a frames model (frm__linear_solve's case): the model's assembled
   blocks, whose pattern creation checked is a chain, as a block-tridiagonal a_mass M +
   a_stiff K (static_regularization on the rotational diagonal, as CG's product); held
   components (fixed and driven frames, held axes) become identity rows and columns. A
   failed factorisation is FRM__CG_NEGATIVE (the Newton loops then retry with K's definite
   part) or FRM__CG_NOT_FINITE; the answer is checked against the model's own product
   (|b - A x| <= tolerance |b|, with up to three steps of iterative refinement, which float
   needs; else FRM__CG_CAP). */
static int frm__btd_model_check(const frm_model *m, const frm_desc *d)
{
    int i, e;
    if (!m->has_blocks) return frm__fail(d, FRM_ERR_SOLVER, "linear_solver FRM_LINEAR_SOLVER_BTD needs block storage (stiffness_mode not PAIRS)");
    for (i = 0; i < m->frame_count; i++)
        for (e = m->blk_start[i]; e < m->blk_start[i + 1]; e++)
            if (m->blk_col[e] < i - 1 || m->blk_col[e] > i + 1)
                return frm__fail(d, FRM_ERR_SOLVER, "linear_solver FRM_LINEAR_SOLVER_BTD needs a chain: frame i coupled to i - 1 and i + 1 only");
    return FRM_OK;
}

static int frm__cg(frm_model *m, double a_mass, double a_stiff, double tolerance, frm_real *b, frm_real *x);
static int frm__btd_model_solve(frm_model *m, double a_mass, double a_stiff, double tolerance, frm_real *b, frm_real *x)
{
    int n = m->frame_count, i, e, a, c, err, k;
    size_t n6 = 6 * (size_t)n;
    frm_real *D = m->btd, *Lo = D + 36 * (size_t)n, *F = Lo + 36 * (size_t)n, *r = m->cg_r;
    double bb, rr;
    unsigned char held[6];
    m->stats.cg_iterations_last = 0;
    m->stats.cg_residual = 0;
    m->lin_iterations = 0;
    frm__mask(m, b);
    bb = frm__dot(m, b, b);
    if (!frm__finite(bb)) return FRM__CG_NOT_FINITE;
    memset(D, 0, sizeof(frm_real) * 72 * (size_t)n);
    for (i = 0; i < n; i++) {
        double mb[36];
        for (k = 0; k < 36; k++) mb[k] = 0;
        if (a_mass != 0)
            for (c = 0; c < 6; c++) { /* column c of the mass block */
                frm_real v[6] = {0, 0, 0, 0, 0, 0};
                double o[6];
                v[c] = 1;
                frm__mass_apply(m, i, v, o);
                for (a = 0; a < 6; a++) mb[6 * a + c] = o[a];
            }
        for (e = m->blk_start[i]; e < m->blk_start[i + 1]; e++) {
            const frm_real *K = m->blocks + 36 * (size_t)e;
            int j = m->blk_col[e];
            if (j == i)
                for (k = 0; k < 36; k++) D[36 * (size_t)i + k] = (frm_real)(a_stiff * (double)K[k] + a_mass * mb[k]);
            else if (j == i - 1)
                for (k = 0; k < 36; k++) Lo[36 * (size_t)j + k] = (frm_real)(a_stiff * (double)K[k]);
        }
        if (m->solve_regularization != 0)
            for (k = 3; k < 6; k++)
                D[36 * (size_t)i + 7 * k] += (frm_real)(a_stiff * m->solve_regularization * fabs((double)m->kdiag[36 * (size_t)i + 7 * k]));
    }
    for (i = 0; i < n; i++) { /* held components: identity rows and columns */
        for (k = 0; k < 6; k++) held[k] = (unsigned char)(m->state[i] != FRM__FREE || ((m->axes[i] >> k) & 1));
        for (k = 0; k < 6; k++) {
            if (!held[k]) continue;
            for (a = 0; a < 6; a++) {
                D[36 * (size_t)i + 6 * k + a] = D[36 * (size_t)i + 6 * a + k] = 0;
                if (i > 0) Lo[36 * (size_t)(i - 1) + 6 * k + a] = 0;        /* row k of A(i, i-1) */
                if (i + 1 < n) Lo[36 * (size_t)i + 6 * a + k] = 0;          /* column k of A(i+1, i) */
            }
            D[36 * (size_t)i + 7 * k] = 1;
        }
    }
    err = frm_btd_factor(n, D, Lo, F, NULL);
    if (err) {
        if (err == FRM_ERR_NOT_FINITE) return FRM__CG_NOT_FINITE;
        m->stats.negative_curvature++;
        memcpy(x, b, sizeof(frm_real) * n6); /* a descent direction for the retry's caller */
        return FRM__CG_NEGATIVE;
    }
    memcpy(x, b, sizeof(frm_real) * n6);
    if (frm_btd_solve(n, F, 1, x)) return FRM__CG_NOT_FINITE;
    frm__mask(m, x);
    if (bb == 0) return FRM__CG_OK;
    for (k = 0;; k++) { /* the residual by the model's product; iterative refinement (float) */
        int j;
        frm__system_product(m, a_mass, a_stiff, x, r);
        for (j = 0; j < (int)n6; j++) r[j] = b[j] - r[j];
        frm__mask(m, r);
        rr = frm__dot(m, r, r);
        m->stats.cg_residual = (frm_real)sqrt(rr / bb);
        m->lin_iterations = k;
        if (!frm__finite(rr)) return FRM__CG_NOT_FINITE;
        if (rr <= tolerance * tolerance * bb) return FRM__CG_OK;
        if (k == 3 || frm_btd_solve(n, F, 1, r)) /* refinement stalls (float, condition near
                                                     1 / eps): CG goes on from this answer */
            return frm__cg(m, a_mass, a_stiff, tolerance, b, x);
        frm__mask(m, r);
        for (j = 0; j < (int)n6; j++) x[j] += r[j];
    }
}

/* Primal active-set method for min 1/2 x^T H x + c^T x, lo <= x <= hi (the public comment).
   The working set holds variables at a bound; each iteration solves the equality-constrained
   problem on the free ones (Cholesky), steps to it or to the first bound in the way (which
   joins the set), and at a feasible stationary point releases the bound variable whose
   multiplier has the wrong sign most. */
#define FRM__QP_MAX 64
FRMDEF int frm_qp_box(int n, const double *H, const double *c, const double *lo, const double *hi, double *x,
                      int *iterations)
{
    int bound[FRM__QP_MAX], fr[FRM__QP_MAX];
    double L[FRM__QP_MAX * FRM__QP_MAX], y[FRM__QP_MAX], g[FRM__QP_MAX];
    double hmax = 0, shift, gscale = 0;
    int i, j, k, it = 0, cap, nf;
    if (iterations) *iterations = 0;
    if (n < 1 || n > FRM__QP_MAX || !H || !c || !lo || !hi || !x) return FRM_ERR_ARG;
    for (i = 0; i < n; i++) {
        if (!frm__finite(c[i]) || lo[i] != lo[i] || hi[i] != hi[i] || lo[i] > hi[i] || lo[i] == HUGE_VAL ||
            hi[i] == -HUGE_VAL)
            return FRM_ERR_ARG;
        for (j = 0; j < n; j++)
            if (!frm__finite(H[n * i + j])) return FRM_ERR_ARG;
        if (!frm__finite(x[i])) x[i] = 0;
        x[i] = x[i] < lo[i] ? lo[i] : x[i] > hi[i] ? hi[i] : x[i];
        if (!frm__finite(x[i])) x[i] = frm__finite(lo[i]) ? lo[i] : frm__finite(hi[i]) ? hi[i] : 0;
        bound[i] = x[i] == lo[i] ? -1 : x[i] == hi[i] ? 1 : 0;
        if (fabs(H[(n + 1) * i]) > hmax) hmax = fabs(H[(n + 1) * i]);
        if (H[(n + 1) * i] < 0) return FRM_ERR_QP_INDEFINITE;
        gscale += fabs(c[i]);
    }
    if (hmax == 0) hmax = 1;
    shift = 1e-12 * hmax;
    cap = 8 * n + 32;
    for (;;) {
        double alpha = 1.0;
        int block = -1;
        /* free set and its right-hand side -(c_F + H_FB x_B) */
        nf = 0;
        for (i = 0; i < n; i++)
            if (!bound[i]) fr[nf++] = i;
        for (j = 0; j < nf; j++) {
            double s = -c[fr[j]];
            for (k = 0; k < n; k++)
                if (bound[k]) s -= H[n * fr[j] + k] * x[k];
            y[j] = s;
        }
        /* Cholesky of H_FF + shift I */
        for (j = 0; j < nf; j++)
            for (k = 0; k <= j; k++) {
                double s = H[n * fr[j] + fr[k]] + (j == k ? shift : 0.0);
                int m2;
                for (m2 = 0; m2 < k; m2++) s -= L[nf * j + m2] * L[nf * k + m2];
                if (j == k) {
                    if (!(s > 1e-14 * hmax)) return FRM_ERR_QP_INDEFINITE;
                    L[nf * j + j] = sqrt(s);
                } else
                    L[nf * j + k] = s / L[nf * k + k];
            }
        for (j = 0; j < nf; j++) {
            for (k = 0; k < j; k++) y[j] -= L[nf * j + k] * y[k];
            y[j] /= L[nf * j + j];
        }
        for (j = nf - 1; j >= 0; j--) {
            for (k = j + 1; k < nf; k++) y[j] -= L[nf * k + j] * y[k];
            y[j] /= L[nf * j + j];
        }
        /* step towards y, stopping at the first bound */
        for (j = 0; j < nf; j++) {
            double xi = x[fr[j]], d = y[j] - xi, t;
            if (d < 0 && y[j] < lo[fr[j]]) {
                t = (lo[fr[j]] - xi) / d;
                if (t < alpha) alpha = t, block = j;
            } else if (d > 0 && y[j] > hi[fr[j]]) {
                t = (hi[fr[j]] - xi) / d;
                if (t < alpha) alpha = t, block = j;
            }
        }
        if (alpha < 0) alpha = 0;
        for (j = 0; j < nf; j++) {
            int v = fr[j];
            x[v] = j == block ? (y[j] < lo[v] ? lo[v] : hi[v]) : x[v] + alpha * (y[j] - x[v]);
            if (x[v] < lo[v]) x[v] = lo[v];
            if (x[v] > hi[v]) x[v] = hi[v];
        }
        if (block >= 0) {
            bound[fr[block]] = y[block] < lo[fr[block]] ? -1 : 1;
        } else {
            /* stationary on the free set: multipliers of the bound variables */
            double worst = 0, tol;
            int release = -1;
            double xs = 0;
            for (i = 0; i < n; i++) {
                double s = c[i];
                for (k = 0; k < n; k++) s += H[n * i + k] * x[k];
                g[i] = s;
                xs += fabs(x[i]);
            }
            tol = 1e-12 * (gscale + hmax * xs) + 1e-300;
            for (i = 0; i < n; i++)
                if (lo[i] < hi[i] && ((bound[i] < 0 && g[i] < -tol && -g[i] > worst) ||
                                      (bound[i] > 0 && g[i] > tol && g[i] > worst)))
                    worst = fabs(g[i]), release = i;
            if (release < 0) break;
            bound[release] = 0;
        }
        if (++it > cap) {
            if (iterations) *iterations = it;
            return FRM_ERR_NO_CONVERGENCE;
        }
    }
    if (iterations) *iterations = it;
    for (i = 0; i < n; i++)
        if (!frm__finite(x[i])) return FRM_ERR_NOT_FINITE;
    return FRM_OK;
}

/* >>chain ------------------------------------------------------------------------------ */

#define FRM__CHAIN_COOKIE 0x46524D43u /* "FRMC" */

struct frm_chain {
    int n, na, eff_frame, eff_orient, max_it;
    frm_allocator allocator;
    size_t bytes;
    double gravity[3], dt, alpha, tol, eps_inv, eff_off[3];
    double fsq;                              /* the last force pass's sum of squared link forces */
    frm_real *pos, *quat, *vel, *effort;     /* 3, 4, 6 per frame; 1 per actuator */
    double *mass, *inertia, *ext;            /* 1, 1, 6 per frame */
    double *kc, *dbar, *qbar;                /* per link: C^-1 (36), rest lever in frame i's axes (3),
                                                rest relative orientation conj(qbar_i) qbar_{i+1} (4) */
    double *eff_qrest;                       /* 4: the effector frame's rest orientation */
    int *a_kind, *a_pstart, *a_tstart;       /* per actuator; point and triangle ranges (na + 1) */
    int *p_frame, *tri;                      /* per point; 3 per triangle */
    double *p_local, *a_min, *a_max;         /* 3 per point (frame's rest axes); per actuator */
    /* scratch, carved at creation (nothing allocates later) */
    frm_real *diag, *lower, *factor;         /* BTD of the n - 1 free frames */
    frm_real *rhs;                           /* 6 n (na + 2): Newton's right-hand side, J_a^T columns */
    double *g, *dq, *delta, *delta0, *ja, *je; /* 6 n, 6 n, 6 n, 6 n, 6 n na, 6 n 6 */
    frm_real *save, *best, *trial;           /* 13 n + na each: poses, velocities, efforts */
    double *qp;                              /* na (na + 6) + 6 na */
};

static void frm__ch_qmul(const double a[4], const double b[4], double o[4])
{
    double t[4];
    t[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    t[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    t[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    t[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    memcpy(o, t, sizeof t);
}
static void frm__ch_qconj(const double a[4], double o[4]) { o[0] = -a[0], o[1] = -a[1], o[2] = -a[2], o[3] = a[3]; }
static void frm__ch_qload(const frm_real *q, double o[4])
{
    double s = 0;
    int k;
    for (k = 0; k < 4; k++) s += (double)q[k] * (double)q[k];
    s = 1.0 / sqrt(s);
    for (k = 0; k < 4; k++) o[k] = (double)q[k] * s;
}
static void frm__ch_rot(const double q[4], double R[9])
{
    double x = q[0], y = q[1], z = q[2], w = q[3];
    R[0] = 1 - 2 * (y * y + z * z), R[1] = 2 * (x * y - z * w), R[2] = 2 * (x * z + y * w);
    R[3] = 2 * (x * y + z * w), R[4] = 1 - 2 * (x * x + z * z), R[5] = 2 * (y * z - x * w);
    R[6] = 2 * (x * z - y * w), R[7] = 2 * (y * z + x * w), R[8] = 1 - 2 * (x * x + y * y);
}
static void frm__ch_qexp(const double t[3], double o[4])
{
    double a = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]), s = a > 1e-12 ? sin(0.5 * a) / a : 0.5 - a * a / 48;
    o[0] = s * t[0], o[1] = s * t[1], o[2] = s * t[2], o[3] = cos(0.5 * a);
}
static void frm__ch_cross(const double a[3], const double b[3], double o[3])
{
    double t[3];
    t[0] = a[1] * b[2] - a[2] * b[1], t[1] = a[2] * b[0] - a[0] * b[2], t[2] = a[0] * b[1] - a[1] * b[0];
    o[0] = t[0], o[1] = t[1], o[2] = t[2];
}
static void frm__ch_mv(const double R[9], const double v[3], double o[3])
{
    double t[3];
    int k;
    for (k = 0; k < 3; k++) t[k] = R[3 * k] * v[0] + R[3 * k + 1] * v[1] + R[3 * k + 2] * v[2];
    o[0] = t[0], o[1] = t[1], o[2] = t[2];
}
static void frm__ch_mtv(const double R[9], const double v[3], double o[3])
{
    double t[3];
    int k;
    for (k = 0; k < 3; k++) t[k] = R[k] * v[0] + R[3 + k] * v[1] + R[6 + k] * v[2];
    o[0] = t[0], o[1] = t[1], o[2] = t[2];
}
/* 2 vec(q) with w >= 0: the rotation vector to O(theta^3) (the link's rotation measure). */
static void frm__ch_qvec(double q[4])
{
    if (q[3] < 0) q[0] = -q[0], q[1] = -q[1], q[2] = -q[2], q[3] = -q[3];
}

/* A link's state: e = (d, phi), d = R0^T (x1 - x0) - dbar, phi = 2 vec(q_e) with
   q_e = conj(q0) q1 conj(qbar_rel) (w >= 0); g = C^-1 e; F = R0 g_t, mw = R0 (w g_r + v x g_r). */
typedef struct frm__ch_link {
    double R0[9], r[3], v[3], w, e[6], g[6], F[3], mw[3];
    const double *kc;
} frm__ch_link;

static void frm__ch_link_eval(const frm_chain *c, int i, frm__ch_link *L)
{
    double q0[4], q1[4], t[4], m[3];
    int a, b;
    frm__ch_qload(c->quat + 4 * i, q0);
    frm__ch_qload(c->quat + 4 * (i + 1), q1);
    frm__ch_rot(q0, L->R0);
    for (a = 0; a < 3; a++) L->r[a] = (double)c->pos[3 * (i + 1) + a] - (double)c->pos[3 * i + a];
    frm__ch_mtv(L->R0, L->r, L->e);
    for (a = 0; a < 3; a++) L->e[a] -= c->dbar[3 * i + a];
    frm__ch_qconj(q0, t);
    frm__ch_qmul(t, q1, t);
    frm__ch_qconj(c->qbar + 4 * i, q0);
    frm__ch_qmul(t, q0, t);
    frm__ch_qvec(t);
    for (a = 0; a < 3; a++) L->v[a] = t[a], L->e[3 + a] = 2 * t[a];
    L->w = t[3];
    L->kc = c->kc + 36 * (size_t)i;
    for (a = 0; a < 6; a++) {
        double s = 0;
        for (b = 0; b < 6; b++) s += L->kc[6 * a + b] * L->e[b];
        L->g[a] = s;
    }
    frm__ch_mv(L->R0, L->g, L->F);
    frm__ch_cross(L->v, L->g + 3, m);
    for (a = 0; a < 3; a++) m[a] += L->w * L->g[3 + a];
    frm__ch_mv(L->R0, m, L->mw);
}

/* The link's forces on its two frames (12: f0, tau0, f1, tau1; world, about each origin). */
static void frm__ch_link_force(const frm__ch_link *L, double f[12])
{
    double t[3];
    int a;
    frm__ch_cross(L->r, L->F, t);
    for (a = 0; a < 3; a++) {
        f[a] = L->F[a], f[3 + a] = L->mw[a] + t[a];
        f[6 + a] = -L->F[a], f[9 + a] = -L->mw[a];
    }
}

/* out = K d (12) for the link: gn = 0 the exact K = -df/dq, gn = 1 the Gauss-Newton part
   J^T C^-1 J (eqs. 5.16-5.17's Omega Gamma Omega^T with the current lever and the measure's
   Jacobian: positive semi-definite). */
static void frm__ch_link_apply(const frm__ch_link *L, const double d[12], double out[12], int gn)
{
    double dr[3], a3[3], dd[6], dg[6], om[3], t[3], u[3], dF[3], dmw[3], dv[3], dw;
    int a, b;
    for (a = 0; a < 3; a++) dr[a] = d[6 + a] - d[a], t[a] = d[9 + a] - d[3 + a];
    frm__ch_cross(L->r, d + 3, a3);
    for (a = 0; a < 3; a++) a3[a] += dr[a];
    frm__ch_mtv(L->R0, a3, dd);
    frm__ch_mtv(L->R0, t, om);
    frm__ch_cross(L->v, om, u);
    for (a = 0; a < 3; a++) dd[3 + a] = L->w * om[a] - u[a], dv[a] = 0.5 * dd[3 + a];
    dw = -0.5 * (L->v[0] * om[0] + L->v[1] * om[1] + L->v[2] * om[2]);
    for (a = 0; a < 6; a++) {
        double s = 0;
        for (b = 0; b < 6; b++) s += L->kc[6 * a + b] * dd[b];
        dg[a] = s;
    }
    if (gn) { /* J^T dg */
        double Y1[3], Y2[3], m[3];
        frm__ch_mv(L->R0, dg, Y1);
        frm__ch_cross(L->v, dg + 3, m);
        for (a = 0; a < 3; a++) m[a] += L->w * dg[3 + a];
        frm__ch_mv(L->R0, m, Y2);
        frm__ch_cross(Y1, L->r, t);
        for (a = 0; a < 3; a++) {
            out[a] = -Y1[a], out[3 + a] = t[a] - Y2[a];
            out[6 + a] = Y1[a], out[9 + a] = Y2[a];
        }
        return;
    }
    /* dF = dtheta0 x F + R0 dg_t; dm_loc = dw g_r + w dg_r + dv x g_r + v x dg_r;
       dmw = dtheta0 x mw + R0 dm_loc; df0 = (dF, dmw + dr x F + r x dF), df1 = -(dF, dmw) */
    frm__ch_cross(d + 3, L->F, dF);
    frm__ch_mv(L->R0, dg, t);
    for (a = 0; a < 3; a++) dF[a] += t[a];
    {
        double ml[3], p[3], q[3];
        frm__ch_cross(dv, L->g + 3, p);
        frm__ch_cross(L->v, dg + 3, q);
        for (a = 0; a < 3; a++) ml[a] = dw * L->g[3 + a] + L->w * dg[3 + a] + p[a] + q[a];
        frm__ch_mv(L->R0, ml, dmw);
        frm__ch_cross(d + 3, L->mw, p);
        for (a = 0; a < 3; a++) dmw[a] += p[a];
    }
    frm__ch_cross(dr, L->F, t);
    frm__ch_cross(L->r, dF, u);
    for (a = 0; a < 3; a++) {
        out[a] = -dF[a], out[3 + a] = -(dmw[a] + t[a] + u[a]);
        out[6 + a] = dF[a], out[9 + a] = dmw[a];
    }
}

/* The 12 x 12 link matrix (row-major) by 12 products with unit vectors. */
static void frm__ch_link_matrix(const frm__ch_link *L, double K[144], int gn)
{
    double d[12], o[12];
    int j, a;
    memset(d, 0, sizeof d);
    for (j = 0; j < 12; j++) {
        d[j] = 1;
        frm__ch_link_apply(L, d, o, gn);
        d[j] = 0;
        for (a = 0; a < 12; a++) K[12 * a + j] = o[a];
    }
}

/* Elastic forces (6 n, may be NULL) and energy of every link; *fsq (may be NULL) receives
   the sum of the links' squared force components (the round-off scale of the sums). */
static double frm__ch_elastic(const frm_chain *c, double *f, double *fsq)
{
    double E = 0, fl[12], s = 0;
    int i, k;
    if (f) memset(f, 0, sizeof(double) * 6 * (size_t)c->n);
    for (i = 0; i + 1 < c->n; i++) {
        frm__ch_link L;
        frm__ch_link_eval(c, i, &L);
        for (k = 0; k < 6; k++) E += 0.5 * L.e[k] * L.g[k];
        if (f) {
            double kmax = 0, xmax = 0;
            frm__ch_link_force(&L, fl);
            for (k = 0; k < 12; k++) f[6 * i + k] += fl[k], s += fl[k] * fl[k];
            /* and K times one unit of the positions' rounding */
            for (k = 0; k < 6; k++) kmax = L.kc[7 * k] > kmax ? L.kc[7 * k] : kmax;
            for (k = 0; k < 6; k++) xmax = fabs((double)c->pos[3 * i + k]) > xmax ? fabs((double)c->pos[3 * i + k]) : xmax;
            s += kmax * xmax * kmax * xmax;
        }
    }
    if (fsq) *fsq = s;
    return E;
}

/* A point fixed to frame f at local offset o: world position and lever R o. */
static void frm__ch_point(const frm_chain *c, int f, const double *o, double P[3], double lev[3])
{
    double q[4], R[9];
    int a;
    frm__ch_qload(c->quat + 4 * f, q);
    frm__ch_rot(q, R);
    frm__ch_mv(R, o, lev);
    for (a = 0; a < 3; a++) P[a] = (double)c->pos[3 * f + a] + lev[a];
}

/* Each actuator's measure (cable length, cavity volume) and, with rows != NULL, its row
   J_a (6 n): the generalized force per unit effort (-dL/dq for a cable, dV/dq for a cavity). */
static void frm__ch_actuators(const frm_chain *c, double *meas, double *rows)
{
    int a, k, j, n6 = 6 * c->n;
    for (a = 0; a < c->na; a++) {
        double *J = rows ? rows + (size_t)n6 * (size_t)a : NULL, s = 0;
        int p0 = c->a_pstart[a], np = c->a_pstart[a + 1] - p0;
        if (J) memset(J, 0, sizeof(double) * (size_t)n6);
        if (c->a_kind[a] == FRM_ACTUATOR_CABLE) {
            double P[3], lev[3], Pn[3], levn[3], u[3], uprev[3] = {0, 0, 0};
            frm__ch_point(c, c->p_frame[p0], c->p_local + 3 * p0, P, lev);
            for (k = 0; k < np; k++) {
                double t[3], tor[3];
                int f = c->p_frame[p0 + k];
                if (k + 1 < np) {
                    double len;
                    frm__ch_point(c, c->p_frame[p0 + k + 1], c->p_local + 3 * (p0 + k + 1), Pn, levn);
                    for (j = 0; j < 3; j++) u[j] = Pn[j] - P[j];
                    len = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
                    s += len;
                    for (j = 0; j < 3; j++) u[j] = len > 0 ? u[j] / len : 0;
                } else
                    u[0] = u[1] = u[2] = 0;
                if (J) { /* -dL/dP_k = u_k - u_{k-1} */
                    for (j = 0; j < 3; j++) t[j] = u[j] - uprev[j];
                    frm__ch_cross(lev, t, tor);
                    for (j = 0; j < 3; j++) J[6 * f + j] += t[j], J[6 * f + 3 + j] += tor[j];
                }
                memcpy(uprev, u, sizeof u);
                if (k + 1 < np) memcpy(P, Pn, sizeof P), memcpy(lev, levn, sizeof lev);
            }
        } else {
            int t0 = c->a_tstart[a], t1 = c->a_tstart[a + 1], t;
            for (t = t0; t < t1; t++) {
                double P[3][3], L3[3][3], x[3];
                int v;
                for (v = 0; v < 3; v++) {
                    int p = p0 + c->tri[3 * t + v];
                    frm__ch_point(c, c->p_frame[p], c->p_local + 3 * p, P[v], L3[v]);
                }
                frm__ch_cross(P[1], P[2], x);
                s += (P[0][0] * x[0] + P[0][1] * x[1] + P[0][2] * x[2]) / 6;
                if (J)
                    for (v = 0; v < 3; v++) { /* dV/dP_v = P_{v+1} x P_{v+2} / 6 */
                        double gv[3], tor[3];
                        int p = p0 + c->tri[3 * t + v], f = c->p_frame[p];
                        frm__ch_cross(P[(v + 1) % 3], P[(v + 2) % 3], gv);
                        for (j = 0; j < 3; j++) gv[j] /= 6;
                        frm__ch_cross(L3[v], gv, tor);
                        for (j = 0; j < 3; j++) J[6 * f + j] += gv[j], J[6 * f + 3 + j] += tor[j];
                    }
            }
        }
        if (meas) meas[a] = s;
    }
}

/* Total generalized force (6 n: elastic + gravity + external + actuators with `with_act`)
   and the potential (elastic - gravity's and external forces' work + actuators' lambda L,
   -p V; constant torques have none). The actuator rows are left in c->ja. */
static double frm__ch_total(frm_chain *c, double *g, int with_act)
{
    double pot = frm__ch_elastic(c, g, &c->fsq), meas[64];
    int i, k, a, n6 = 6 * c->n;
    for (i = 0; i < c->n; i++)
        for (k = 0; k < 3; k++) {
            double fk = c->mass[i] * c->gravity[k] + c->ext[6 * i + k];
            g[6 * i + k] += fk;
            g[6 * i + 3 + k] += c->ext[6 * i + 3 + k];
            pot -= fk * (double)c->pos[3 * i + k];
        }
    if (c->na > 0) {
        frm__ch_actuators(c, meas, c->ja);
        if (with_act)
            for (a = 0; a < c->na; a++) {
                double lam = (double)c->effort[a];
                if (lam == 0) continue;
                for (k = 0; k < n6; k++) g[k] += lam * c->ja[(size_t)n6 * a + k];
                pot += c->a_kind[a] == FRM_ACTUATOR_CABLE ? lam * meas[a] : -lam * meas[a];
            }
    }
    return pot;
}

/* The BTD blocks of the free frames 1 .. n-1: the links' symmetric K (gn = 0) or their
   Gauss-Newton part (gn = 1), plus diag_add (1/s^2) times each frame's mass. */
static void frm__ch_assemble(frm_chain *c, int gn, double diag_add)
{
    int i, a, b, nb = c->n - 1;
    double K[144];
    memset(c->diag, 0, sizeof(frm_real) * 36 * (size_t)nb);
    memset(c->lower, 0, sizeof(frm_real) * 36 * (size_t)nb);
    for (i = 0; i + 1 < c->n; i++) {
        frm__ch_link L;
        frm__ch_link_eval(c, i, &L);
        frm__ch_link_matrix(&L, K, gn);
        for (a = 0; a < 6; a++)
            for (b = 0; b < 6; b++) {
                /* frame i + 1 is block i; frame i is block i - 1 (the base, i = 0, is held) */
                c->diag[36 * i + 6 * a + b] += (frm_real)(0.5 * (K[12 * (6 + a) + 6 + b] + K[12 * (6 + b) + 6 + a]));
                if (i > 0) {
                    c->diag[36 * (i - 1) + 6 * a + b] += (frm_real)(0.5 * (K[12 * a + b] + K[12 * b + a]));
                    c->lower[36 * (i - 1) + 6 * a + b] += (frm_real)(0.5 * (K[12 * (6 + a) + b] + K[12 * b + 6 + a]));
                }
            }
    }
    if (diag_add > 0)
        for (i = 1; i < c->n; i++)
            for (a = 0; a < 6; a++)
                c->diag[36 * (i - 1) + 7 * a] += (frm_real)(diag_add * (a < 3 ? c->mass[i] : c->inertia[i]));
}

/* Factors the free frames' tangent: the exact symmetric part, or (indefinite: a stressed
   state past a bifurcation) the positive semi-definite Gauss-Newton part. */
static int frm__ch_factor(frm_chain *c, double diag_add)
{
    int err, failed;
    frm__ch_assemble(c, 0, diag_add);
    err = frm_btd_factor(c->n - 1, c->diag, c->lower, c->factor, &failed);
    if (err == FRM_ERR_BTD_INDEFINITE || err == FRM_ERR_BTD_SINGULAR) {
        frm__ch_assemble(c, 1, diag_add);
        err = frm_btd_factor(c->n - 1, c->diag, c->lower, c->factor, &failed);
    }
    return err;
}

static void frm__ch_store(const frm_chain *c, frm_real *s)
{
    size_t n = (size_t)c->n;
    memcpy(s, c->pos, sizeof(frm_real) * 3 * n);
    memcpy(s + 3 * n, c->quat, sizeof(frm_real) * 4 * n);
    memcpy(s + 7 * n, c->vel, sizeof(frm_real) * 6 * n);
    if (c->na) memcpy(s + 13 * n, c->effort, sizeof(frm_real) * (size_t)c->na);
}
static void frm__ch_restore(frm_chain *c, const frm_real *s)
{
    size_t n = (size_t)c->n;
    memcpy(c->pos, s, sizeof(frm_real) * 3 * n);
    memcpy(c->quat, s + 3 * n, sizeof(frm_real) * 4 * n);
    memcpy(c->vel, s + 7 * n, sizeof(frm_real) * 6 * n);
    if (c->na) memcpy(c->effort, s + 13 * n, sizeof(frm_real) * (size_t)c->na);
}

/* Frames 1 .. n-1 of the stored state s moved by alpha dq (world rotation vectors). */
static void frm__ch_move(frm_chain *c, const frm_real *s, const double *dq, double alpha)
{
    size_t n = (size_t)c->n;
    int i, k;
    for (i = 1; i < c->n; i++) {
        double q[4], e[4], t[3];
        for (k = 0; k < 3; k++) c->pos[3 * i + k] = (frm_real)((double)s[3 * i + k] + alpha * dq[6 * i + k]);
        for (k = 0; k < 3; k++) t[k] = alpha * dq[6 * i + 3 + k];
        frm__ch_qload(s + 3 * n + 4 * i, q);
        frm__ch_qexp(t, e);
        frm__ch_qmul(e, q, q);
        t[0] = 1.0 / sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        for (k = 0; k < 4; k++) c->quat[4 * i + k] = (frm_real)(q[k] * t[0]);
    }
}

/* |v| over the free frames (1 .. n-1). */
static double frm__ch_norm(const frm_chain *c, const double *v)
{
    double s = 0;
    int k;
    for (k = 6; k < 6 * c->n; k++) s += v[k] * v[k];
    return sqrt(s);
}

/* Newton iterations on the free frames (eq. 5.19), through the BTD solver, with a
   backtracking line search on the potential (or on |residual| where the potential's change
   is below its round-off). dyn = 1: implicit Euler of step h (residual g - M (delta / h -
   v_n) / h - alpha M delta / h over the step's increment delta, tangent K + M (1 + alpha h)
   / h^2). Converged when |r| <= tol * scale (the loads, the base's reaction, the inertia
   term). On failure the state is restored. *iterations receives the iterations. */
static int frm__ch_newton(frm_chain *c, int dyn, int *iterations)
{
    int it, i, k, err = FRM_ERR_NO_CONVERGENCE, n6 = 6 * c->n;
    double h = c->dt, a_m = dyn ? (1 + c->alpha * h) / (h * h) : 0, res = 0, pot = 0, previous = HUGE_VAL;
    double *g = c->g, *dq = c->dq, *dl = c->delta, *dl0 = c->delta0;
    frm__ch_store(c, c->save);
    if (iterations) *iterations = 0;
    memset(dl, 0, sizeof(double) * (size_t)n6);
    for (it = 0; it <= c->max_it; it++) {
        double scale = 0, rn, slope, alpha = 1, base_pot, floor;
        /* residual and its scale */
        pot = frm__ch_total(c, g, 1);
        for (k = 0; k < n6; k++) dq[k] = 0;
        for (i = 1; i < c->n; i++)
            for (k = 0; k < 3; k++) {
                double fk = c->mass[i] * c->gravity[k] + c->ext[6 * i + k];
                scale += fk * fk + c->ext[6 * i + 3 + k] * c->ext[6 * i + 3 + k];
            }
        for (k = 0; k < 6; k++) scale += g[k] * g[k]; /* the base's reaction */
        if (a_m > 0)
            for (i = 1; i < c->n; i++)
                for (k = 0; k < 6; k++) {
                double M = k < 3 ? c->mass[i] : c->inertia[i], v = (double)c->vel[6 * i + k];
                double r = M * ((dl[6 * i + k] / h - v) / h + c->alpha * dl[6 * i + k] / h);
                g[6 * i + k] -= r;
                scale += (M * v / h) * (M * v / h);
                pot += 0.5 * M / (h * h) * ((dl[6 * i + k] - h * v) * (dl[6 * i + k] - h * v) + c->alpha * h * dl[6 * i + k] * dl[6 * i + k]);
            }
        {
            int a;
            for (a = 0; a < c->na; a++) {
                double s = 0;
                for (k = 0; k < n6; k++) s += c->ja[(size_t)n6 * a + k] * c->ja[(size_t)n6 * a + k];
                scale += (double)c->effort[a] * (double)c->effort[a] * s;
            }
        }
        scale = sqrt(scale);
        rn = frm__ch_norm(c, g);
        res = rn;
        if (!frm__finite(rn) || !frm__finite(pot)) {
            err = FRM_ERR_NOT_FINITE;
            break;
        }
        /* converged, or at the round-off floor of the force sums once an iteration no longer
           halves the residual */
        floor = 16 * (FRM__IS_FLOAT ? (double)FLT_EPSILON : DBL_EPSILON) * sqrt(c->fsq);
        if (rn <= c->tol * scale || (it > 0 && rn > 0.5 * previous && rn <= floor)) {
            err = FRM_OK;
            break;
        }
        if (it == c->max_it) break;
        previous = rn;
        /* Newton direction */
        err = frm__ch_factor(c, a_m);
        if (err) break;
        for (k = 6; k < n6; k++) c->rhs[k - 6] = (frm_real)g[k];
        err = frm_btd_solve(c->n - 1, c->factor, 1, c->rhs);
        if (err) break;
        for (k = 6; k < n6; k++) dq[k] = (double)c->rhs[k - 6];
        slope = 0;
        for (k = 6; k < n6; k++) slope += g[k] * dq[k];
        /* line search from this iterate */
        frm__ch_store(c, c->trial);
        memcpy(dl0, dl, sizeof(double) * (size_t)n6);
        base_pot = pot;
        for (k = 0; k < 40; k++) {
            double tp, tr;
            int j;
            frm__ch_move(c, c->trial, dq, alpha);
            for (j = 6; j < n6; j++) dl[j] = dl0[j] + alpha * dq[j];
            tp = frm__ch_total(c, g, 1);
            for (i = 1; i < c->n; i++) /* constant torques: their work along the step */
                for (j = 3; j < 6; j++) tp -= alpha * c->ext[6 * i + j] * dq[6 * i + j];
            if (a_m > 0)
                for (i = 1; i < c->n; i++)
                    for (j = 0; j < 6; j++) {
                        double M = j < 3 ? c->mass[i] : c->inertia[i], v = (double)c->vel[6 * i + j];
                        g[6 * i + j] -= M * ((dl[6 * i + j] / h - v) / h + c->alpha * dl[6 * i + j] / h);
                        tp += 0.5 * M / (h * h) * ((dl[6 * i + j] - h * v) * (dl[6 * i + j] - h * v) + c->alpha * h * dl[6 * i + j] * dl[6 * i + j]);
                    }
            tr = frm__ch_norm(c, g);
            if (frm__finite(tp) && frm__finite(tr) &&
                (tp <= base_pot - 1e-4 * alpha * slope ||
                 (fabs(tp - base_pot) <= 1e-12 * (fabs(base_pot) + 1) && tr < rn)))
                break;
            alpha *= 0.5;
        }
        if (k == 40) { /* no decrease: converged only if already at the round-off floor */
            frm__ch_restore(c, c->trial);
            memcpy(dl, dl0, sizeof(double) * (size_t)n6);
            err = rn <= floor ? FRM_OK : FRM_ERR_NO_CONVERGENCE;
            break;
        }
        if (iterations) (*iterations)++;
    }
    (void)res;
    if (err) {
        frm__ch_restore(c, c->save);
        return err;
    }
    if (dyn)
        for (i = 1; i < c->n; i++)
            for (k = 0; k < 6; k++) c->vel[6 * i + k] = (frm_real)(dl[6 * i + k] / h);
    else
        memset(c->vel, 0, sizeof(frm_real) * (size_t)n6);
    return FRM_OK;
}

static int frm__ch_fail(const frm_chain_desc *d, int code, const char *detail)
{
    if (d && d->log) d->log(code, detail, d->log_user);
    return code;
}

FRMDEF frm_chain_desc frm_chain_default_desc(void)
{
    frm_chain_desc d;
    memset(&d, 0, sizeof d);
    d.gravity[2] = (frm_real)-9.81;
    d.time_step = (frm_real)0.01;
    d.newton_tolerance = (frm_real)(FRM__IS_FLOAT ? 1e-4 : 1e-9);
    d.newton_max_iterations = 50;
    d.effector_frame = -1;
    d.inverse_epsilon = (frm_real)1e-5;
    d.internal_cookie = FRM__CHAIN_COOKIE;
    return d;
}

static size_t frm__ch_carve(char *base, size_t *off, size_t bytes, void **out)
{
    *out = base ? (void *)(base + *off) : NULL;
    *off += (bytes + 63) / 64 * 64;
    return *off;
}

static size_t frm__ch_layout(frm_chain *c, char *base, int np, int nt)
{
    size_t off = (sizeof(frm_chain) + 63) / 64 * 64, n = (size_t)c->n, na = (size_t)c->na, nl = n - 1, R = sizeof(frm_real),
           D = sizeof(double);
    void *p;
#define FRM__CH_CARVE(field, bytes) (frm__ch_carve(base, &off, (bytes), &p), (base ? (void)(*(void **)&c->field = p) : (void)0))
    FRM__CH_CARVE(pos, R * 3 * n);
    FRM__CH_CARVE(quat, R * 4 * n);
    FRM__CH_CARVE(vel, R * 6 * n);
    FRM__CH_CARVE(effort, R * (na + 1));
    FRM__CH_CARVE(mass, D * n);
    FRM__CH_CARVE(inertia, D * n);
    FRM__CH_CARVE(ext, D * 6 * n);
    FRM__CH_CARVE(kc, D * 36 * nl);
    FRM__CH_CARVE(dbar, D * 3 * nl);
    FRM__CH_CARVE(qbar, D * 4 * nl);
    FRM__CH_CARVE(eff_qrest, D * 4);
    FRM__CH_CARVE(a_kind, sizeof(int) * (na + 1));
    FRM__CH_CARVE(a_pstart, sizeof(int) * (na + 1));
    FRM__CH_CARVE(a_tstart, sizeof(int) * (na + 1));
    FRM__CH_CARVE(p_frame, sizeof(int) * ((size_t)np + 1));
    FRM__CH_CARVE(tri, sizeof(int) * 3 * ((size_t)nt + 1));
    FRM__CH_CARVE(p_local, D * 3 * ((size_t)np + 1));
    FRM__CH_CARVE(a_min, D * (na + 1));
    FRM__CH_CARVE(a_max, D * (na + 1));
    FRM__CH_CARVE(diag, R * 36 * nl);
    FRM__CH_CARVE(lower, R * 36 * nl);
    FRM__CH_CARVE(factor, R * 72 * nl);
    FRM__CH_CARVE(rhs, R * 6 * n * (na + 2));
    FRM__CH_CARVE(g, D * 6 * n);
    FRM__CH_CARVE(dq, D * 6 * n);
    FRM__CH_CARVE(delta, D * 6 * n);
    FRM__CH_CARVE(delta0, D * 6 * n);
    FRM__CH_CARVE(ja, D * 6 * n * (na + 1));
    FRM__CH_CARVE(je, D * 6 * n * 6);
    FRM__CH_CARVE(save, R * (13 * n + na + 1));
    FRM__CH_CARVE(best, R * (13 * n + na + 1));
    FRM__CH_CARVE(trial, R * (13 * n + na + 1));
    FRM__CH_CARVE(qp, D * (na * (na + 6) + 6 * na + 8 * na + 8));
#undef FRM__CH_CARVE
    return off;
}

/* C^-1 of a symmetric positive definite 6x6 (Cholesky); 0 or FRM_ERR_COMPLIANCE. */
static int frm__ch_spd_inverse(const double *C, double *out)
{
    double L[36], cmax = 0;
    int a, b, k;
    for (a = 0; a < 36; a++) {
        if (!frm__finite(C[a])) return FRM_ERR_COMPLIANCE;
        if (fabs(C[a]) > cmax) cmax = fabs(C[a]);
    }
    for (a = 0; a < 6; a++)
        for (b = 0; b < a; b++)
            if (fabs(C[6 * a + b] - C[6 * b + a]) > 1e-6 * cmax) return FRM_ERR_COMPLIANCE;
    for (b = 0; b < 6; b++) {
        double d = C[7 * b];
        for (k = 0; k < b; k++) d -= L[6 * b + k] * L[6 * b + k];
        if (!(d > 1e-13 * fabs(C[7 * b])) || !(C[7 * b] > 0)) return FRM_ERR_COMPLIANCE;
        L[7 * b] = sqrt(d);
        for (a = b + 1; a < 6; a++) {
            double s = 0.5 * (C[6 * a + b] + C[6 * b + a]);
            for (k = 0; k < b; k++) s -= L[6 * a + k] * L[6 * b + k];
            L[6 * a + b] = s / L[7 * b];
        }
    }
    for (b = 0; b < 6; b++) { /* column b of the inverse */
        double z[6];
        for (a = 0; a < 6; a++) {
            double s = a == b ? 1.0 : 0.0;
            for (k = 0; k < a; k++) s -= L[6 * a + k] * z[k];
            z[a] = s / L[7 * a];
        }
        for (a = 5; a >= 0; a--) {
            double s = z[a];
            for (k = a + 1; k < 6; k++) s -= L[6 * k + a] * z[k];
            z[a] = s / L[7 * a];
        }
        for (a = 0; a < 6; a++) out[6 * a + b] = z[a];
    }
    for (a = 0; a < 36; a++)
        if (!frm__finite(out[a])) return FRM_ERR_COMPLIANCE;
    return FRM_OK;
}

FRMDEF int frm_chain_create(const frm_chain_desc *d, frm_chain **out)
{
    frm_chain tmp, *c;
    char msg[160];
    int i, k, a, np = 0, nt = 0, n;
    size_t bytes;
    if (out) *out = NULL;
    if (!d || !out) return FRM_ERR_ARG;
    if (d->internal_cookie != FRM__CHAIN_COOKIE) return FRM_ERR_DESC;
    n = d->frame_count;
    if (n < 2 || n > 1000000) return frm__ch_fail(d, FRM_ERR_FRAME_COUNT, "frame_count below 2 or too large");
    if (!d->positions || !d->compliances) return frm__ch_fail(d, FRM_ERR_ARG, "positions and compliances are required");
    for (i = 0; i < 3 * n; i++)
        if (!frm__finite((double)d->positions[i])) return frm__ch_fail(d, FRM_ERR_FRAME_NOT_FINITE, "position not finite");
    if (d->orientations)
        for (i = 0; i < n; i++)
            if (!frm__quat_valid(d->orientations + 4 * i)) return frm__ch_fail(d, FRM_ERR_QUATERNION, "orientation");
    for (i = 0; i < n; i++) {
        if (d->masses && !(d->masses[i] >= 0 && frm__finite((double)d->masses[i])))
            return frm__ch_fail(d, FRM_ERR_DENSITY, "mass not finite and >= 0");
        if (d->inertias && !(d->inertias[i] >= 0 && frm__finite((double)d->inertias[i])))
            return frm__ch_fail(d, FRM_ERR_DENSITY, "inertia not finite and >= 0");
    }
    for (i = 0; i < 3; i++)
        if (!frm__finite((double)d->gravity[i])) return frm__ch_fail(d, FRM_ERR_ARG, "gravity");
    if (!(d->time_step > 0) || !frm__finite((double)d->time_step)) return frm__ch_fail(d, FRM_ERR_TIME_STEP, "time_step");
    if (!(d->mass_damping >= 0) || !frm__finite((double)d->mass_damping)) return frm__ch_fail(d, FRM_ERR_DAMPING, "mass_damping");
    if (!(d->newton_tolerance > 0) || !frm__finite((double)d->newton_tolerance) || d->newton_max_iterations < 1 ||
        !(d->inverse_epsilon >= 0) || !frm__finite((double)d->inverse_epsilon))
        return frm__ch_fail(d, FRM_ERR_SOLVER, "newton_tolerance, newton_max_iterations or inverse_epsilon");
    if (d->effector_frame < -1 || d->effector_frame >= n || !frm__vec3_finite(d->effector_offset))
        return frm__ch_fail(d, FRM_ERR_ARG, "effector_frame out of range or effector_offset not finite");
    if (d->actuator_count < 0 || d->actuator_count > 64 || (d->actuator_count > 0 && !d->actuators))
        return frm__ch_fail(d, FRM_ERR_ACTUATOR, "actuator_count outside 0..64 or actuators NULL");
    for (a = 0; a < d->actuator_count; a++) {
        const frm_actuator *A = d->actuators + a;
        int cable = A->kind == FRM_ACTUATOR_CABLE;
        if (A->kind != FRM_ACTUATOR_CABLE && A->kind != FRM_ACTUATOR_CAVITY) {
            snprintf(msg, sizeof msg, "actuator %d: unknown kind", a);
            return frm__ch_fail(d, FRM_ERR_ACTUATOR, msg);
        }
        if (A->point_count < (cable ? 2 : 4) || !A->point_frames || !A->points ||
            (!cable && (A->triangle_count < 4 || !A->triangles))) {
            snprintf(msg, sizeof msg, "actuator %d: too few points or triangles, or NULL arrays", a);
            return frm__ch_fail(d, FRM_ERR_ACTUATOR, msg);
        }
        for (k = 0; k < A->point_count; k++) {
            if (A->point_frames[k] < 0 || A->point_frames[k] >= n) {
                snprintf(msg, sizeof msg, "actuator %d: point %d on frame %d, outside the chain", a, k, A->point_frames[k]);
                return frm__ch_fail(d, FRM_ERR_ACTUATOR, msg);
            }
            if (!frm__vec3_finite(A->points + 3 * k)) return frm__ch_fail(d, FRM_ERR_ACTUATOR, "actuator point not finite");
            if (cable && k > 0) {
                const frm_real *p = A->points + 3 * k, *q = p - 3;
                if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) {
                    snprintf(msg, sizeof msg, "actuator %d: cable points %d and %d coincide", a, k - 1, k);
                    return frm__ch_fail(d, FRM_ERR_ACTUATOR, msg);
                }
            }
        }
        if (!cable)
            for (k = 0; k < 3 * A->triangle_count; k++)
                if (A->triangles[k] < 0 || A->triangles[k] >= A->point_count) {
                    snprintf(msg, sizeof msg, "actuator %d: triangle vertex index out of range", a);
                    return frm__ch_fail(d, FRM_ERR_ACTUATOR, msg);
                }
        if (!(A->min_effort >= 0) || !(A->max_effort >= A->min_effort) || !frm__finite((double)A->min_effort)) {
            snprintf(msg, sizeof msg, "actuator %d: bounds need 0 <= min_effort <= max_effort", a);
            return frm__ch_fail(d, FRM_ERR_ACTUATOR_BOUNDS, msg);
        }
        np += A->point_count;
        nt += cable ? 0 : A->triangle_count;
    }
    memset(&tmp, 0, sizeof tmp);
    tmp.n = n;
    tmp.na = d->actuator_count;
    bytes = frm__ch_layout(&tmp, NULL, np, nt);
    c = (frm_chain *)frm__alloc(&d->allocator, bytes);
    if (!c) return frm__ch_fail(d, FRM_ERR_ALLOC, "out of memory");
    memset(c, 0, bytes);
    c->n = n;
    c->na = d->actuator_count;
    c->allocator = d->allocator;
    c->bytes = bytes;
    frm__ch_layout(c, (char *)c, np, nt);
    for (k = 0; k < 3; k++) c->gravity[k] = (double)d->gravity[k], c->eff_off[k] = (double)d->effector_offset[k];
    c->dt = (double)d->time_step;
    c->alpha = (double)d->mass_damping;
    c->tol = (double)d->newton_tolerance;
    c->max_it = d->newton_max_iterations;
    c->eps_inv = (double)d->inverse_epsilon;
    c->eff_frame = d->effector_frame < 0 ? n - 1 : d->effector_frame;
    c->eff_orient = d->effector_orientation != 0;
    for (i = 0; i < n; i++) {
        double q[4] = {0, 0, 0, 1};
        for (k = 0; k < 3; k++) c->pos[3 * i + k] = d->positions[3 * i + k];
        if (d->orientations) frm__ch_qload(d->orientations + 4 * i, q);
        for (k = 0; k < 4; k++) c->quat[4 * i + k] = (frm_real)q[k];
        c->mass[i] = d->masses ? (double)d->masses[i] : 0;
        c->inertia[i] = d->inertias ? (double)d->inertias[i] : 0;
    }
    for (i = 0; i + 1 < n; i++) {
        double C[36], q0[4], q1[4], R[9], r[3];
        int err;
        for (k = 0; k < 36; k++) C[k] = (double)d->compliances[36 * (size_t)i + k];
        err = frm__ch_spd_inverse(C, c->kc + 36 * (size_t)i);
        if (err) {
            snprintf(msg, sizeof msg, "link %d: compliance not finite, not symmetric or not positive definite", i);
            frm__free(&c->allocator, c, bytes);
            return frm__ch_fail(d, err, msg);
        }
        frm__ch_qload(c->quat + 4 * i, q0);
        frm__ch_qload(c->quat + 4 * (i + 1), q1);
        frm__ch_rot(q0, R);
        for (k = 0; k < 3; k++) r[k] = (double)c->pos[3 * (i + 1) + k] - (double)c->pos[3 * i + k];
        frm__ch_mtv(R, r, c->dbar + 3 * i);
        frm__ch_qconj(q0, q0);
        frm__ch_qmul(q0, q1, c->qbar + 4 * i);
    }
    frm__ch_qload(c->quat + 4 * c->eff_frame, c->eff_qrest);
    np = nt = 0;
    for (a = 0; a < c->na; a++) {
        const frm_actuator *A = d->actuators + a;
        c->a_kind[a] = (int)A->kind;
        c->a_pstart[a] = np;
        c->a_tstart[a] = nt;
        c->a_min[a] = (double)A->min_effort;
        c->a_max[a] = (double)A->max_effort;
        c->effort[a] = A->min_effort;
        for (k = 0; k < A->point_count; k++) {
            int f = A->point_frames[k], j;
            double q[4], R[9], r[3];
            frm__ch_qload(c->quat + 4 * f, q);
            frm__ch_rot(q, R);
            for (j = 0; j < 3; j++) r[j] = (double)A->points[3 * k + j] - (double)c->pos[3 * f + j];
            frm__ch_mtv(R, r, c->p_local + 3 * (np + k));
            c->p_frame[np + k] = f;
        }
        if (A->kind == FRM_ACTUATOR_CAVITY)
            for (k = 0; k < 3 * A->triangle_count; k++) c->tri[3 * nt + k] = A->triangles[k];
        np += A->point_count;
        nt += A->kind == FRM_ACTUATOR_CAVITY ? A->triangle_count : 0;
    }
    c->a_pstart[c->na] = np;
    c->a_tstart[c->na] = nt;
    if (c->na > 0) { /* cavities must enclose a positive volume (outward triangles) */
        double meas[64];
        frm__ch_actuators(c, meas, NULL);
        for (a = 0; a < c->na; a++)
            if (c->a_kind[a] == FRM_ACTUATOR_CAVITY && !(meas[a] > 0)) {
                snprintf(msg, sizeof msg, "actuator %d: the cavity's triangles enclose no positive volume", a);
                frm__free(&c->allocator, c, bytes);
                return frm__ch_fail(d, FRM_ERR_ACTUATOR, msg);
            }
    }
    *out = c;
    return FRM_OK;
}

FRMDEF void frm_chain_destroy(frm_chain *c)
{
    frm_allocator a;
    if (!c) return;
    a = c->allocator;
    frm__free(&a, c, c->bytes);
}

FRMDEF int frm_chain_frame_count(const frm_chain *c) { return c ? c->n : 0; }
FRMDEF int frm_chain_actuator_count(const frm_chain *c) { return c ? c->na : 0; }
FRMDEF const frm_real *frm_chain_positions(const frm_chain *c) { return c ? c->pos : NULL; }
FRMDEF const frm_real *frm_chain_orientations(const frm_chain *c) { return c ? c->quat : NULL; }
FRMDEF const frm_real *frm_chain_velocities(const frm_chain *c) { return c ? c->vel : NULL; }
FRMDEF const frm_real *frm_chain_efforts(const frm_chain *c) { return c ? c->effort : NULL; }

FRMDEF int frm_chain_set_poses(frm_chain *c, const frm_real *positions, const frm_real *orientations)
{
    int i, k;
    if (!c || !positions || !orientations) return FRM_ERR_ARG;
    for (i = 0; i < c->n; i++) {
        if (!frm__vec3_finite(positions + 3 * i)) return FRM_ERR_ARG;
        if (!frm__quat_valid(orientations + 4 * i)) return FRM_ERR_QUATERNION;
    }
    for (i = 0; i < c->n; i++) {
        double q[4];
        frm__ch_qload(orientations + 4 * i, q);
        for (k = 0; k < 3; k++) c->pos[3 * i + k] = positions[3 * i + k];
        for (k = 0; k < 4; k++) c->quat[4 * i + k] = (frm_real)q[k];
    }
    memset(c->vel, 0, sizeof(frm_real) * 6 * (size_t)c->n);
    return FRM_OK;
}

FRMDEF int frm_chain_set_base(frm_chain *c, const frm_real position[3], const frm_real orientation[4])
{
    double q[4];
    int k;
    if (!c || !position || !orientation || !frm__vec3_finite(position)) return FRM_ERR_ARG;
    if (!frm__quat_valid(orientation)) return FRM_ERR_QUATERNION;
    frm__ch_qload(orientation, q);
    for (k = 0; k < 3; k++) c->pos[k] = position[k];
    for (k = 0; k < 4; k++) c->quat[k] = (frm_real)q[k];
    return FRM_OK;
}

FRMDEF int frm_chain_set_external(frm_chain *c, int frame, const frm_real force[3], const frm_real torque[3])
{
    int k;
    if (!c) return FRM_ERR_ARG;
    if (frame < 0 || frame >= c->n) return FRM_ERR_FRAME_RANGE;
    if ((force && !frm__vec3_finite(force)) || (torque && !frm__vec3_finite(torque))) return FRM_ERR_ARG;
    for (k = 0; k < 3; k++) {
        c->ext[6 * frame + k] = force ? (double)force[k] : 0;
        c->ext[6 * frame + 3 + k] = torque ? (double)torque[k] : 0;
    }
    return FRM_OK;
}

FRMDEF int frm_chain_set_gravity(frm_chain *c, const frm_real g[3])
{
    int k;
    if (!c || !g || !frm__vec3_finite(g)) return FRM_ERR_ARG;
    for (k = 0; k < 3; k++) c->gravity[k] = (double)g[k];
    return FRM_OK;
}

FRMDEF int frm_chain_set_efforts(frm_chain *c, const frm_real *efforts)
{
    int a;
    if (!c || (c->na > 0 && !efforts)) return FRM_ERR_ARG;
    for (a = 0; a < c->na; a++)
        if (!((double)efforts[a] >= c->a_min[a] && (double)efforts[a] <= c->a_max[a])) return FRM_ERR_ACTUATOR_BOUNDS;
    for (a = 0; a < c->na; a++) c->effort[a] = efforts[a];
    return FRM_OK;
}

FRMDEF int frm_chain_forces(frm_chain *c, frm_real *out, double *energy)
{
    double E;
    int k;
    if (!c) return FRM_ERR_ARG;
    E = frm__ch_elastic(c, c->g, NULL);
    if (!frm__finite(E)) return FRM_ERR_NOT_FINITE;
    if (energy) *energy = E;
    if (out)
        for (k = 0; k < 6 * c->n; k++) out[k] = (frm_real)c->g[k];
    return FRM_OK;
}

FRMDEF double frm_chain_energy(const frm_chain *c) { return c ? frm__ch_elastic(c, NULL, NULL) : 0.0; }

FRMDEF int frm_chain_apply_stiffness(frm_chain *c, const frm_real *v, frm_real *out, int symmetric)
{
    int i, k;
    double K[144], o[12];
    if (!c || !v || !out) return FRM_ERR_ARG;
    memset(c->g, 0, sizeof(double) * 6 * (size_t)c->n);
    for (i = 0; i + 1 < c->n; i++) {
        frm__ch_link L;
        int a;
        frm__ch_link_eval(c, i, &L);
        frm__ch_link_matrix(&L, K, 0);
        for (a = 0; a < 12; a++) {
            double s = 0;
            for (k = 0; k < 12; k++)
                s += (symmetric ? 0.5 * (K[12 * a + k] + K[12 * k + a]) : K[12 * a + k]) * (double)v[6 * i + k];
            o[a] = s;
        }
        for (k = 0; k < 12; k++) c->g[6 * i + k] += o[k];
    }
    for (k = 0; k < 6 * c->n; k++) out[k] = (frm_real)c->g[k];
    return FRM_OK;
}

FRMDEF int frm_chain_actuator_measures(const frm_chain *c, double *out)
{
    if (!c || (c->na > 0 && !out)) return FRM_ERR_ARG;
    frm__ch_actuators(c, out, NULL);
    return FRM_OK;
}

FRMDEF int frm_chain_effector(const frm_chain *c, frm_real position[3], frm_real orientation[4])
{
    double P[3], lev[3];
    int k;
    if (!c || !position) return FRM_ERR_ARG;
    frm__ch_point(c, c->eff_frame, c->eff_off, P, lev);
    for (k = 0; k < 3; k++) position[k] = (frm_real)P[k];
    if (orientation) memcpy(orientation, c->quat + 4 * c->eff_frame, 4 * sizeof(frm_real));
    return FRM_OK;
}

FRMDEF int frm_chain_solve_static(frm_chain *c)
{
    if (!c) return FRM_ERR_ARG;
    return frm__ch_newton(c, 0, NULL);
}

FRMDEF int frm_chain_step(frm_chain *c)
{
    int i;
    if (!c) return FRM_ERR_ARG;
    for (i = 1; i < c->n; i++)
        if (!(c->mass[i] > 0) || !(c->inertia[i] > 0)) return FRM_ERR_DENSITY;
    return frm__ch_newton(c, 1, NULL);
}

/* >>actuation -------------------------------------------------------------------------- */

/* Effector rows J_e (ne x 6 n: position rows dP = dx - a x dtheta, orientation rows dtheta)
   and the current error e = effector - target (ne). */
static int frm__ch_effector_rows(frm_chain *c, const frm_real *target, double *err)
{
    int ne = c->eff_orient ? 6 : 3, n6 = 6 * c->n, f = c->eff_frame, j;
    double P[3], lev[3];
    memset(c->je, 0, sizeof(double) * (size_t)n6 * 6);
    frm__ch_point(c, f, c->eff_off, P, lev);
    for (j = 0; j < 3; j++) {
        double e[3] = {0, 0, 0}, t[3];
        double *row = c->je + (size_t)n6 * j;
        e[j] = 1;
        frm__ch_cross(lev, e, t);
        row[6 * f + j] = 1;
        row[6 * f + 3] = t[0], row[6 * f + 4] = t[1], row[6 * f + 5] = t[2];
        err[j] = P[j] - (double)target[j];
    }
    if (c->eff_orient) {
        double tq[4], e[4], q[4], th[3];
        for (j = 0; j < 3; j++) th[j] = (double)target[3 + j];
        frm__ch_qexp(th, e);
        frm__ch_qmul(e, c->eff_qrest, tq);
        frm__ch_qload(c->quat + 4 * f, q);
        frm__ch_qconj(tq, tq);
        frm__ch_qmul(q, tq, e);
        frm__ch_qvec(e);
        for (j = 0; j < 3; j++) {
            c->je[(size_t)n6 * (3 + j) + 6 * f + 3 + j] = 1;
            err[3 + j] = 2 * e[j];
        }
    }
    return ne;
}

static double frm__ch_effector_error(frm_chain *c, const frm_real *target)
{
    double e[6], s = 0;
    int ne = frm__ch_effector_rows(c, target, e), j;
    for (j = 0; j < ne; j++) s += e[j] * e[j];
    return sqrt(s);
}

/* One linearisation (eq. 5.23) and QP (eq. 5.29): efforts into lam, the predicted error. */
static int frm__ch_inverse_qp(frm_chain *c, const frm_real *target, double *lam, double *predicted, int *qp_it, int *active)
{
    int na = c->na, n6 = 6 * c->n, nb = c->n - 1, ne, a, b, j, k, err;
    size_t nb6 = 6 * (size_t)nb;
    double e[6], *Wea = c->qp, *Waa = Wea + 6 * na, *H = Waa + na * na, *cv = H + na * na, *lo = cv + na, *hi = lo + na;
    double trE = 0, trA = 0, eps, pred = 0;
    *qp_it = 0;
    *active = 0;
    /* free motion: the total force without the actuators at the current state */
    frm__ch_total(c, c->g, 0); /* also fills c->ja */
    err = frm__ch_factor(c, 0.0);
    if (err) return err;
    ne = frm__ch_effector_rows(c, target, e);
    for (k = 0; k < (int)nb6; k++) c->rhs[k] = (frm_real)c->g[6 + k];
    for (a = 0; a < na; a++)
        for (k = 0; k < (int)nb6; k++) c->rhs[nb6 * (size_t)(a + 1) + k] = (frm_real)c->ja[(size_t)n6 * a + 6 + k];
    err = frm_btd_solve(nb, c->factor, na + 1, c->rhs);
    if (err) return err;
    /* delta_e^free = e + J_e dq_free; W_ea = J_e K^-1 J_a^T; W_aa = J_a K^-1 J_a^T */
    for (j = 0; j < ne; j++) {
        const double *row = c->je + (size_t)n6 * j + 6;
        double s = e[j];
        for (k = 0; k < (int)nb6; k++) s += row[k] * (double)c->rhs[k];
        e[j] = s;
        for (a = 0; a < na; a++) {
            const frm_real *y = c->rhs + nb6 * (size_t)(a + 1);
            double t = 0;
            for (k = 0; k < (int)nb6; k++) t += row[k] * (double)y[k];
            Wea[na * j + a] = t;
        }
    }
    for (a = 0; a < na; a++)
        for (b = 0; b < na; b++) {
            const double *ra = c->ja + (size_t)n6 * a + 6;
            const frm_real *y = c->rhs + nb6 * (size_t)(b + 1);
            double t = 0;
            for (k = 0; k < (int)nb6; k++) t += ra[k] * (double)y[k];
            Waa[na * a + b] = t;
        }
    for (a = 0; a < na; a++) {
        for (b = 0; b < na; b++) {
            double t = 0;
            for (j = 0; j < ne; j++) t += Wea[na * j + a] * Wea[na * j + b];
            H[na * a + b] = t;
        }
        trE += H[na * a + a];
        trA += fabs(Waa[na * a + a]);
    }
    eps = trA > 0 ? c->eps_inv * trE / trA : 0;
    for (a = 0; a < na; a++) {
        double t = 0;
        for (b = 0; b < na; b++) H[na * a + b] += eps * 0.5 * (Waa[na * a + b] + Waa[na * b + a]);
        for (j = 0; j < ne; j++) t += Wea[na * j + a] * e[j];
        cv[a] = t;
        lo[a] = c->a_min[a];
        hi[a] = c->a_max[a];
        lam[a] = (double)c->effort[a];
    }
    err = frm_qp_box(na, H, cv, lo, hi, lam, qp_it);
    if (err) return err;
    for (j = 0; j < ne; j++) {
        double t = e[j];
        for (a = 0; a < na; a++) t += Wea[na * j + a] * lam[a];
        pred += t * t;
    }
    for (a = 0; a < na; a++) *active += lam[a] <= lo[a] || lam[a] >= hi[a];
    *predicted = sqrt(pred);
    return FRM_OK;
}

FRMDEF int frm_chain_inverse_step(frm_chain *c, const frm_real *target, double tolerance, frm_inverse_stats *stats)
{
    double lam[64], pred = 0;
    int a, err, qp_it = 0, active = 0, newton = 0;
    frm_inverse_stats st;
    memset(&st, 0, sizeof st);
    if (stats) *stats = st;
    if (!c || !target || !(tolerance > 0) || c->na < 1) return FRM_ERR_ARG;
    for (a = 0; a < (c->eff_orient ? 6 : 3); a++)
        if (!frm__finite((double)target[a])) return FRM_ERR_ARG;
    err = frm__ch_inverse_qp(c, target, lam, &pred, &qp_it, &active);
    st.linearizations = 1;
    st.qp_iterations = qp_it;
    st.active_bounds = active;
    st.predicted_error = pred;
    if (!err) {
        frm_real keep[64];
        for (a = 0; a < c->na; a++) keep[a] = c->effort[a], c->effort[a] = (frm_real)lam[a];
        err = frm__ch_newton(c, 0, &newton);
        if (err)
            for (a = 0; a < c->na; a++) c->effort[a] = keep[a];
    }
    st.newton_iterations = newton;
    st.error = frm__ch_effector_error(c, target);
    st.reached = st.error <= tolerance;
    if (stats) *stats = st;
    if (err) return err;
    return st.reached || pred <= tolerance ? FRM_OK : FRM_ERR_UNREACHABLE;
}

FRMDEF int frm_chain_inverse_solve(frm_chain *c, const frm_real *target, double tolerance, int max_linearizations,
                                   frm_inverse_stats *stats)
{
    frm_inverse_stats st, sum;
    double best = HUGE_VAL, previous = HUGE_VAL;
    int it, err = FRM_ERR_NO_CONVERGENCE, stalled = 0;
    memset(&sum, 0, sizeof sum);
    if (stats) *stats = sum;
    if (!c || !target || !(tolerance > 0) || max_linearizations < 1 || c->na < 1) return FRM_ERR_ARG;
    frm__ch_store(c, c->best);
    best = frm__ch_effector_error(c, target);
    for (it = 0; it < max_linearizations; it++) {
        err = frm_chain_inverse_step(c, target, tolerance, &st);
        sum.linearizations++;
        sum.qp_iterations += st.qp_iterations;
        sum.newton_iterations += st.newton_iterations;
        sum.active_bounds = st.active_bounds;
        sum.predicted_error = st.predicted_error;
        if (err && err != FRM_ERR_UNREACHABLE) break;
        if (st.error < best) {
            best = st.error;
            frm__ch_store(c, c->best);
        }
        if (st.reached) break;
        /* out of reach and no longer improving: the closest pose */
        if (err == FRM_ERR_UNREACHABLE && !(st.error < previous * (1 - 1e-3))) {
            if (++stalled >= 2) break;
        } else
            stalled = 0;
        previous = st.error;
    }
    if (st.reached)
        err = FRM_OK;
    else if (err == FRM_OK || err == FRM_ERR_UNREACHABLE) {
        /* the closest pose found (a valid equilibrium) */
        frm__ch_restore(c, c->best);
        err = st.predicted_error > tolerance ? FRM_ERR_UNREACHABLE : FRM_ERR_NO_CONVERGENCE;
    }
    sum.error = frm__ch_effector_error(c, target);
    sum.reached = sum.error <= tolerance;
    if (stats) *stats = sum;
    return err;
}

/* Eqs. 5.1-5.11 on a frames sub-model: end A held, end B rigid with a virtual frame at
   origin_b. For each unit rigid motion t_k of end B (translation, then rotation about
   origin_b): the interior's response u_I = -K_II^-1 K_IB t_k by the model's linear solver,
   the reaction r = K (t_k + u_I) on end B's frames, reduced to origin_b: column k of the
   condensed stiffness K_red = T^T (K_BB - K_BI K_II^-1 K_IB) T; C = K_red^-1 (eq. 5.10). */
FRMDEF int frm_chain_link_compliance(frm_model *m, const int *end_a, int na, const int *end_b, int nb,
                                     const frm_real origin_b[3], frm_real C[36])
{
    unsigned char *keep_state, *keep_axes;
    size_t n6, bytes;
    frm_real *v, *x, *kv;
    double Kr[36], Ci[36], reg;
    int i, k, j, err = FRM_OK, n, cg_cap;
    if (!m || !end_a || !end_b || na < 1 || nb < 1 || !origin_b || !C || !frm__vec3_finite(origin_b)) return FRM_ERR_ARG;
    n = m->frame_count;
    for (i = 0; i < na; i++)
        if (end_a[i] < 0 || end_a[i] >= n) return FRM_ERR_FRAME_RANGE;
    for (i = 0; i < nb; i++)
        if (end_b[i] < 0 || end_b[i] >= n) return FRM_ERR_FRAME_RANGE;
    n6 = 6 * (size_t)n;
    bytes = 2 * (size_t)n + 3 * n6 * sizeof(frm_real) + 64;
    keep_state = (unsigned char *)frm__alloc(&m->allocator, bytes);
    if (!keep_state) return FRM_ERR_ALLOC;
    keep_axes = keep_state + n;
    v = (frm_real *)(void *)(keep_state + ((2 * (size_t)n + 63) / 64) * 64);
    x = v + n6;
    kv = x + n6;
    memcpy(keep_state, m->state, (size_t)n);
    memcpy(keep_axes, m->axes, (size_t)n);
    reg = m->solve_regularization;
    cg_cap = m->cg_max_iterations;
    /* the ends' frames: translations held (end A) or imposed (end B), rotations free */
    for (i = 0; i < n; i++) m->state[i] = FRM__FREE, m->axes[i] = 0;
    for (i = 0; i < na; i++) m->axes[end_a[i]] = 7;
    for (i = 0; i < nb; i++) m->axes[end_b[i]] = 7;
    m->solve_regularization = 0;
    if (m->cg_max_iterations < 20 * n) m->cg_max_iterations = 20 * n;
    err = frm__linearize(m, NULL, 0);
    if (!err) frm__build_precond(m, 0.0, 1.0);
    for (k = 0; k < 6 && !err; k++) {
        double F[6] = {0, 0, 0, 0, 0, 0};
        int cg;
        memset(v, 0, sizeof(frm_real) * n6);
        for (i = 0; i < nb; i++) {
            int f = end_b[i];
            double lev[3], e[3] = {0, 0, 0}, t[3];
            for (j = 0; j < 3; j++) lev[j] = (double)m->pos[3 * f + j] - (double)origin_b[j];
            if (k < 3)
                v[6 * f + k] = 1;
            else {
                e[k - 3] = 1;
                frm__ch_cross(e, lev, t);
                for (j = 0; j < 3; j++) v[6 * f + j] = (frm_real)t[j];
            }
        }
        frm__stiffness_product(m, v, kv, 0);
        for (j = 0; j < (int)n6; j++) kv[j] = -kv[j];
        memset(x, 0, sizeof(frm_real) * n6);
        cg = frm__linear_solve(m, 0.0, 1.0, FRM__IS_FLOAT ? 1e-6 : 1e-11, kv, x);
        if (cg != FRM__CG_OK) {
            err = cg == FRM__CG_NOT_FINITE ? FRM_ERR_NOT_FINITE : FRM_ERR_NO_CONVERGENCE;
            break;
        }
        for (j = 0; j < (int)n6; j++) v[j] += x[j];
        frm__stiffness_product(m, v, kv, 0);
        for (i = 0; i < nb; i++) {
            int f = end_b[i];
            double lev[3], fo[3], t[3];
            for (j = 0; j < 3; j++) lev[j] = (double)m->pos[3 * f + j] - (double)origin_b[j], fo[j] = (double)kv[6 * f + j];
            frm__ch_cross(lev, fo, t);
            for (j = 0; j < 3; j++) F[j] += fo[j], F[3 + j] += (double)kv[6 * f + 3 + j] + t[j];
        }
        for (j = 0; j < 6; j++) Kr[6 * j + k] = F[j];
    }
    memcpy(m->state, keep_state, (size_t)n);
    memcpy(m->axes, keep_axes, (size_t)n);
    m->solve_regularization = reg;
    m->cg_max_iterations = cg_cap;
    m->lin_valid = 0;
    frm__free(&m->allocator, keep_state, bytes);
    if (err) return err;
    for (k = 0; k < 6; k++) /* symmetrise (round-off of the solves) */
        for (j = 0; j < k; j++) Kr[6 * k + j] = Kr[6 * j + k] = 0.5 * (Kr[6 * k + j] + Kr[6 * j + k]);
    err = frm__ch_spd_inverse(Kr, Ci);
    if (err) return err;
    for (k = 0; k < 36; k++) C[k] = (frm_real)Ci[k];
    return FRM_OK;
}

#if defined(FRM_STATIC) && defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
#endif /* FRAMES_IMPLEMENTATION */

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
