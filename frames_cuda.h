/* frames_cuda.h - the CUDA companion of frames.h: a created frm_model on one GPU - MIT or public domain

   STATUS: compiled (nvcc, sm_80 and sm_90, warnings as errors, by `make test`) but NOT YET
   RUN ON A GPU: no test of it has passed on a device. bench/gpu.sh builds and runs its
   tests (tests/test_frames_cuda.cu) and bench on the first machine that has one. Until
   then treat every result as unverified.

   USE (C or C++): compile frames_cuda.cu once with nvcc, with the FRM_REAL of the program
   (nvcc -c frames_cuda.cu [-DFRM_REAL=float]), link it with the C file that defines
   FRAMES_IMPLEMENTATION and with -lcudart:

       frm_cuda *g;
       frm_model_create(&d, &m);                      // host model, boundary conditions set
       if (frm_cuda_create(m, &g) == 0) {             // uploads structure, rest data, state
           for (i = 0; i < 100; i++) frm_cuda_step(g); // on the device; nothing comes back
           frm_cuda_download(g, m);                    // poses and velocities into the model
           frm_cuda_destroy(g);
       }

   WHAT RUNS ON THE DEVICE: the two passes of frames.h (>>passes: frm_pass1_*,
   frm_pass2_*, the very functions the CPU loops call) for the force, its linearisation
   and K v (pair mode, matrix-free): pass 1 one thread a sample, pass 2 one thread a frame;
   the linearised implicit Euler step (FRM_IMPLICIT_EULER_LINEARIZED's scheme, one linear
   solve a step, the thesis's GPU scheme) with block-Jacobi CG, its dot products in double
   reduced by a fixed-order tree (no floating-point atomics: repeatable bit for bit on one
   GPU; the CG runs 16 iterations between convergence checks, iterations past convergence
   change nothing, so there is no host synchronisation per iteration), all on one stream.
   The block-Jacobi blocks are the model's rest blocks turned with each frame plus its
   frame-own rotational term (the CPU pair mode's), inverted on the device.
   Errors as the CPU path: FRM_ERR_NO_CONVERGENCE (CG at its cap, or negative curvature),
   FRM_ERR_NOT_FINITE, FRM_ERR_INVERTED (a sample with det F <= 0 after the step);
   a failed step leaves the device state at the last valid step (a device copy restored).
   FRM_ERR_DEVICE: no device, a CUDA call failed, or a model it does not run.

   NOT ON THE DEVICE (use the CPU path): the static solve, Newton-based implicit Euler and
   BDF2, the definite fallback (the CPU retries an indefinite system with K's positive
   part; the device step fails with FRM_ERR_NO_CONVERGENCE), the precision check
   (FRM_ERR_PRECISION), assembled blocks, volumetric averaging, Mooney-Rivlin and user
   laws (no kernel fast path), driven frames. Held axes and fixed frames are supported.
   Results differ from the CPU's in the last bits (other summation order inside a thread's
   fused multiply-adds, the reductions' tree order): tests/test_frames_cuda.cu states the
   tolerances.

   Float builds: compile with -DFRM_REAL=float; every entry point is renamed ..._f32 as in
   frames.h. */
#ifndef FRAMES_CUDA_H
#define FRAMES_CUDA_H

#include "frames.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct frm_cuda frm_cuda;

/* float builds: the same renaming rule as frames.h */
#if FRM__CAT(FRM__IS_, FRM_REAL)
#define frm_cuda_create frm_cuda_create_f32
#define frm_cuda_destroy frm_cuda_destroy_f32
#define frm_cuda_upload_state frm_cuda_upload_state_f32
#define frm_cuda_download frm_cuda_download_f32
#define frm_cuda_forces frm_cuda_forces_f32
#define frm_cuda_linearize frm_cuda_linearize_f32
#define frm_cuda_apply_stiffness frm_cuda_apply_stiffness_f32
#define frm_cuda_step frm_cuda_step_f32
#define frm_cuda_last_iterations frm_cuda_last_iterations_f32
#define frm_cuda_synchronize frm_cuda_synchronize_f32
#endif

/* Uploads the model (structure, rest data, state, loads, settings as they are now) to the
   current device; *out NULL on failure. FRM_ERR_DEVICE (see above), FRM_ERR_ARG on NULL. */
int frm_cuda_create(const frm_model *m, frm_cuda **out);
/* Frees the device memory. NULL is allowed. */
void frm_cuda_destroy(frm_cuda *g);
/* Uploads the model's state (poses, velocities), loads, frame states and settings again
   (after host-side changes). */
int frm_cuda_upload_state(frm_cuda *g, const frm_model *m);
/* Copies the device state (displacements, orientations, velocities) into the model
   (frm_model_set_poses and frm_model_set_velocities). */
int frm_cuda_download(frm_cuda *g, frm_model *m);
/* Internal forces of the device state (both passes); out (6 per frame, host; NULL: keep
   on the device) receives them. */
int frm_cuda_forces(frm_cuda *g, frm_real *out);
/* Linearises at the device state (the force pass that stores G, Hs, F, S). */
int frm_cuda_linearize(frm_cuda *g);
/* out = K v (symmetric part, pair mode) at the last linearisation; v and out host arrays
   of 6 per frame. */
int frm_cuda_apply_stiffness(frm_cuda *g, const frm_real *v, frm_real *out);
/* One linearised implicit Euler step of desc.time_step on the device (see above). */
int frm_cuda_step(frm_cuda *g);
/* CG iterations of the last step. */
int frm_cuda_last_iterations(const frm_cuda *g);
/* Waits for the device (for timing). */
int frm_cuda_synchronize(frm_cuda *g);

#ifdef __cplusplus
}
#endif

#endif /* FRAMES_CUDA_H */
