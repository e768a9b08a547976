/* frames_cuda.cu - the CUDA companion of frames.h (see frames_cuda.h for the API and its
   STATUS: compiled, not yet run on a GPU). MIT or public domain.

   The device runs the passes of frames.h (>>passes) on a frm_view whose pointers are
   device copies of the model's arrays: pass 1 one thread a sample, pass 2 one thread a
   frame. Around them, per frame, the steps of the CPU's linearised implicit Euler
   (frm__implicit_linearized and the functions it calls: frm__force_pass's linearisation,
   frm__prepare_mode's pair mode, frm__mass_update, frm__total_force, frm__build_precond,
   frm__system_product, frm__cg), written here as small device functions that mirror them
   line by line. Dot products: double, a fixed grid, a per-thread sum in index order, a
   shared-memory tree, then one block reducing the partials the same way: repeatable bit
   for bit. Compile: nvcc -c frames_cuda.cu (-DFRM_REAL=float for float builds). */
#define FRAMES_KERNELS
extern "C" {
#include "frames.h"
}
#include "frames_cuda.h"
#include <cuda_runtime.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#define FCU_BLOCK 128   /* threads a block, both passes */
#define FCU_RED 256     /* threads a block of the reductions */
#define FCU_RED_MAX 256 /* most partial sums (blocks) of a reduction */
#define FCU_BATCH 16    /* CG iterations between two looks at convergence */
#define FCU_MAX_BUFFERS 64

/* device scalars (double) */
enum { FS_BB, FS_RR, FS_RZ, FS_PQ, FS_ALPHA, FS_BETA, FS_TOL2, FS_RZNEW, FS_COUNT };
/* device ints */
enum { FI_ERR, FI_DONE, FI_ACTIVE, FI_STATUS, FI_ITER, FI_MAXIT, FI_COUNT };
#define FCU_CG_OK 0
#define FCU_CG_NEGATIVE 1
#define FCU_CG_NOT_FINITE 2

struct frm_cuda {
    frm_view d; /* device pointers; counts and settings as on the host */
    cudaStream_t stream;
    void *buffers[FCU_MAX_BUFFERS];
    int buffer_count;
    frm_real *disp, *quat, *vel, *rot, *rel, *relm, *ext, *lin_hrot; /* writable frame state */
    unsigned char *state, *axes;
    frm_real *force, *total, *kdiag, *precond, *mass_world, *lin_gravity;
    frm_real *cg_r, *cg_z, *cg_p, *cg_q, *dv, *rhs, *work, *warm, *backup;
    double *partial, *scal, *h_scal; /* h_scal: pinned host copy */
    int *iflags, *h_iflags;
    int iterations;
};

static int fcu_ok(cudaError_t e) { return e == cudaSuccess; }

static void *fcu_alloc(frm_cuda *g, size_t bytes, const void *src)
{
    void *p = NULL;
    if (g->buffer_count == FCU_MAX_BUFFERS) return NULL;
    if (bytes == 0) bytes = 8;
    if (!fcu_ok(cudaMalloc(&p, bytes))) return NULL;
    g->buffers[g->buffer_count++] = p;
    if (src) {
        if (!fcu_ok(cudaMemcpy(p, src, bytes, cudaMemcpyHostToDevice))) return NULL;
    } else if (!fcu_ok(cudaMemset(p, 0, bytes)))
        return NULL;
    return p;
}

static int fcu_blocks(int n, int per) { return n > 0 ? (n + per - 1) / per : 1; }

/* ---- per frame (mirrors of the CPU's private per-frame code) ---------------------------- */

/* frm__update_frames without the output positions. */
__global__ static void fcu_update_frames(frm_view w, frm_real *rot, frm_real *rel, frm_real *relm)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= w.frame_count) return;
    frm_frame_rotations(w.quat + 4 * i, w.rest_quat + 4 * i, rot + 9 * i, rel + 9 * i, relm + 9 * i);
}

/* ---- pass 1 (one thread a sample) ------------------------------------------------------- */

/* The force pass (frm__force_chunks without volumetric averaging, with the kernels' laws):
   partial forces into p_out; with linearize, the linearisation's data. err: FRM_ERR_INVERTED
   (or another law error) by an integer atomic minimum (order-free). */
__global__ static void fcu_force_pass1(frm_view w, int linearize, int *err)
{
    int s = blockIdx.x * blockDim.x + threadIdx.x, b, n, e, r;
    frm_real F[9], H[9], S[6], P[9], cache[FRM_LAW_CACHE], psi = 0, D = 0;
    const frm_real *prm;
    double energy = 0;
    if (s >= w.sample_count) return;
    b = w.s_start[s];
    n = w.s_start[s + 1] - b;
    prm = w.s_law_params + FRM_LAW_PARAMS * (size_t)s;
    frm_pass1_deform(&w, s, H, F, NULL);
    e = frm_material_stress(w.s_law[s], prm[0], prm[1], H, S, &psi, cache);
    if (e) {
        atomicMin(err, e);
        for (r = 0; r < 6 * n; r++) w.p_out[6 * (size_t)b + r] = 0;
        return;
    }
    frm_first_piola(F, S, P);
    if (w.s_stab[s]) energy += frm_pass1_stab_force(&w, s, H, F, P, linearize, &D);
    frm_pass1_force_pairs(&w, s, H, F, P, D, linearize, &energy);
    if (linearize) {
        for (r = 0; r < 9; r++) w.lin_F[9 * (size_t)s + r] = F[r];
        for (r = 0; r < 6; r++) w.lin_S[6 * (size_t)s + r] = S[r];
        for (r = 0; r < w.law_cache && r < FRM_LAW_CACHE; r++) w.lin_cache[(size_t)w.law_cache * s + r] = cache[r];
    }
}

/* K v pass 1 (frm__apply_chunks, pair mode, kernels' laws, not definite). */
__global__ static void fcu_apply_pass1(frm_view w, const frm_real *v)
{
    int s = blockIdx.x * blockDim.x + threadIdx.x;
    frm_real dF[9], dP[9];
    const frm_real *prm;
    if (s >= w.sample_count) return;
    prm = w.s_law_params + FRM_LAW_PARAMS * (size_t)s;
    frm_pass1_apply_dF(&w, s, v, dF);
    frm_sample_dP(w.s_law[s], prm[0], prm[1], w.lin_cache + (size_t)w.law_cache * s, w.lin_F + 9 * (size_t)s,
                  w.lin_S + 6 * (size_t)s, dF, dP);
    frm_pass1_apply_pairs(&w, s, v, dF, dP, 0);
}

/* det F > 0 for every sample (frm__inversions); err = FRM_ERR_INVERTED otherwise. */
__global__ static void fcu_inversions(frm_view w, int *err)
{
    int s = blockIdx.x * blockDim.x + threadIdx.x;
    frm_real H[9], F[9];
    if (s >= w.sample_count) return;
    frm_pass1_deform(&w, s, H, F, NULL);
    if (!(1 + frm_det_minus_one(H) > 0)) atomicMin(err, FRM_ERR_INVERTED);
}

/* ---- pass 2 and the per-frame solver steps (one thread a frame) -------------------------- */

/* Pass 2 of the linearising force pass and the per-frame rest of frm__force_pass,
   frm__prepare_mode (pair mode), frm__mass_update, frm__total_force and
   frm__build_precond. */
__global__ static void fcu_frames_linearize(frm_view w, const frm_real *rot, frm_real *force, frm_real *total,
                                            frm_real *kdiag, frm_real *precond, frm_real *mass_world,
                                            frm_real *lin_gravity, double a_mass, double a_stiff, int *err)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, r, k, l;
    const frm_real *R, *K;
    frm_real cg[3], tg[3], mg;
    double Kg[9], h[6], A[36], M[36], inv[36];
    if (i >= w.frame_count) return;
    frm_pass2_gather(&w, i, w.p_out, force, NULL);
    frm_pass2_gather(&w, i, w.p_H, w.lin_hrot, NULL);
    for (k = 0; k < 6; k++)
        if (!isfinite((double)force[6 * i + k])) atomicMin(err, FRM_ERR_NOT_FINITE);
    R = rot + 9 * i;
    { /* frm__gravity_moment, lin_gravity; frm__gravity_stiffness added to the frame-own term */
        frm_pass_gravity_moment(R, w.grav_local + 4 * (size_t)i, cg);
        frm_cross(cg, w.gravity, tg);
        for (r = 0; r < 3; r++) lin_gravity[3 * i + r] = cg[r];
        frm_pass_gravity_stiffness(cg, w.gravity, Kg);
        for (r = 0; r < 6; r++) h[r] = (double)w.lin_hrot[6 * i + r];
        h[0] += Kg[0], h[1] += Kg[4], h[2] += Kg[8], h[3] += Kg[5], h[4] += Kg[2], h[5] += Kg[1];
        for (r = 0; r < 6; r++) w.lin_hrot[6 * i + r] = (frm_real)h[r];
    }
    /* frm__prepare_mode, pair mode: T K_rest T^T + the frame-own rotational term */
    K = kdiag + 36 * (size_t)i;
    frm_pass_precond_block(w.rel + 9 * i, w.kdiag_rest + 36 * (size_t)i, w.lin_hrot + 6 * i, kdiag + 36 * (size_t)i);
    frm_pass_mass_world(w.mass_local + 10 * (size_t)i, rot + 9 * i, mass_world + 10 * (size_t)i);
    mg = (frm_real)w.grav_local[4 * (size_t)i];
    for (r = 0; r < 3; r++) { /* frm__total_force */
        total[6 * i + r] = force[6 * i + r] + mg * w.gravity[r] + w.ext[6 * i + r];
        total[6 * i + 3 + r] = force[6 * i + 3 + r] + tg[r] + w.ext[6 * i + 3 + r];
    }
    /* frm__build_precond (steps: no regularisation) */
    if (w.state[i] != 0) {
        for (k = 0; k < 36; k++) precond[36 * (size_t)i + k] = 0;
        return;
    }
    frm_pass_mass_matrix(mass_world + 10 * (size_t)i, M);
    for (k = 0; k < 36; k++) A[k] = a_mass * M[k] + a_stiff * (double)K[k];
    if (w.axes[i])
        for (k = 0; k < 6; k++)
            if ((w.axes[i] >> k) & 1) {
                for (l = 0; l < 6; l++) A[6 * k + l] = A[6 * l + k] = 0;
                A[7 * k] = 1;
            }
    if (!frm_pass_invert6(A, inv)) { /* the CPU takes |eigenvalues| (Jacobi); here the inverse diagonal */
        for (k = 0; k < 36; k++) inv[k] = 0;
        for (k = 0; k < 6; k++) inv[7 * k] = A[7 * k] != 0 && isfinite(A[7 * k]) ? 1 / fabs(A[7 * k]) : 0;
    }
    if (w.axes[i])
        for (k = 0; k < 36; k++)
            if (((w.axes[i] >> (k / 6)) & 1) || ((w.axes[i] >> (k % 6)) & 1)) inv[k] = 0;
    for (k = 0; k < 36; k++) precond[36 * (size_t)i + k] = (frm_real)inv[k];
}

/* K v pass 2 and frm__system_product (mass, mask); system = 0: the plain K v. */
__global__ static void fcu_apply_pass2(frm_view w, const frm_real *v, frm_real *out, const frm_real *mass_world,
                                       double a_mass, double a_stiff, int system, const int *iflags)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, k;
    double mv[6] = {0, 0, 0, 0, 0, 0};
    if (i >= w.frame_count) return;
    if (iflags && !iflags[FI_ACTIVE]) return;
    frm_pass2_gather(&w, i, w.p_out, out, NULL);
    frm_pass2_rotational(&w, i, v, out);
    if (!system) return;
    if (w.state[i] != 0) {
        for (k = 0; k < 6; k++) out[6 * i + k] = 0;
        return;
    }
    if (a_mass != 0) frm_pass_mass_apply(mass_world + 10 * (size_t)i, v + 6 * i, mv);
    for (k = 0; k < 6; k++) out[6 * i + k] = (frm_real)(a_stiff * (double)out[6 * i + k] + a_mass * mv[k]);
    for (k = 0; k < 6; k++)
        if ((w.axes[i] >> k) & 1) out[6 * i + k] = 0;
}

/* The step's right-hand side b = dt (f - (dt + beta) K v - alpha M v), masked. */
__global__ static void fcu_step_rhs(frm_view w, const frm_real *f, const frm_real *kv, const frm_real *mass_world,
                                    double dt, frm_real *b)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, k;
    double mv[6];
    if (i >= w.frame_count) return;
    frm_pass_mass_apply(mass_world + 10 * (size_t)i, w.vel + 6 * i, mv);
    for (k = 0; k < 6; k++)
        b[6 * i + k] = (frm_real)(dt * ((double)f[6 * i + k] - (dt + (double)w.stiffness_damping) * kv[6 * i + k] -
                                        (double)w.mass_damping * mv[k]));
    for (k = 0; k < 6; k++)
        if (w.state[i] != 0 || ((w.axes[i] >> k) & 1)) b[6 * i + k] = 0;
}

/* frm__mask on x (the warm start). */
__global__ static void fcu_mask(frm_view w, frm_real *x)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, k;
    if (i >= w.frame_count) return;
    for (k = 0; k < 6; k++)
        if (w.state[i] != 0 || ((w.axes[i] >> k) & 1)) x[6 * i + k] = 0;
}

/* z = P r (frm__precond_apply). */
__global__ static void fcu_precond(int frames, const frm_real *P, const frm_real *r, frm_real *z, const int *iflags)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, a, c;
    if (i >= frames || (iflags && !iflags[FI_ACTIVE])) return;
    for (a = 0; a < 6; a++) {
        frm_real t = 0;
        for (c = 0; c < 6; c++) t += P[36 * (size_t)i + 6 * a + c] * r[6 * i + c];
        z[6 * i + a] = t;
    }
}

/* ---- reductions: fixed grid, fixed order -------------------------------------------------- */

__device__ static void fcu_tree(double *sh)
{
    int t = threadIdx.x, half;
    for (half = FCU_RED / 2; half > 0; half /= 2) {
        __syncthreads();
        if (t < half) sh[t] += sh[t + half];
    }
    __syncthreads();
}

/* partial[block] = sum of a[k] b[k] over the block's fixed share. */
__global__ static void fcu_dot_partial(int n, const frm_real *a, const frm_real *b, double *partial, const int *iflags)
{
    __shared__ double sh[FCU_RED];
    int k, stride = gridDim.x * FCU_RED;
    double s = 0;
    if (iflags && !iflags[FI_ACTIVE]) return; /* uniform over the grid */
    for (k = blockIdx.x * FCU_RED + threadIdx.x; k < n; k += stride) s += (double)a[k] * (double)b[k];
    sh[threadIdx.x] = s;
    fcu_tree(sh);
    if (threadIdx.x == 0) partial[blockIdx.x] = sh[0];
}

__global__ static void fcu_dot_final(int count, const double *partial, double *out, const int *iflags)
{
    __shared__ double sh[FCU_RED];
    int k;
    double s = 0;
    if (iflags && !iflags[FI_ACTIVE]) return;
    for (k = threadIdx.x; k < count; k += FCU_RED) s += partial[k];
    sh[threadIdx.x] = s;
    fcu_tree(sh);
    if (threadIdx.x == 0) *out = sh[0];
}

static void fcu_dot(frm_cuda *g, int n, const frm_real *a, const frm_real *b, int slot, const int *iflags)
{
    int blocks = fcu_blocks(n, FCU_RED);
    if (blocks > FCU_RED_MAX) blocks = FCU_RED_MAX;
    fcu_dot_partial<<<blocks, FCU_RED, 0, g->stream>>>(n, a, b, g->partial, iflags);
    fcu_dot_final<<<1, FCU_RED, 0, g->stream>>>(blocks, g->partial, g->scal + slot, iflags);
}

/* ---- CG (frm__cg, the scalars on the device) ----------------------------------------------- */

__global__ static void fcu_cg_start(double *sc, int *fl, double tolerance, int max_iterations)
{
    sc[FS_TOL2] = tolerance * tolerance * sc[FS_BB];
    fl[FI_STATUS] = FCU_CG_OK;
    fl[FI_ITER] = 0;
    fl[FI_MAXIT] = max_iterations;
    fl[FI_DONE] = !(max_iterations > 0 && sc[FS_RR] > sc[FS_TOL2]);
    fl[FI_ACTIVE] = !fl[FI_DONE];
}

/* Before an iteration's updates: alpha, or stop (negative curvature, non-finite). */
__global__ static void fcu_cg_alpha(double *sc, int *fl)
{
    double pq = sc[FS_PQ], rz = sc[FS_RZ];
    if (fl[FI_DONE]) {
        fl[FI_ACTIVE] = 0;
        return;
    }
    if (!(pq > 0) || !(rz > 0)) {
        fl[FI_STATUS] = isfinite(pq) && isfinite(rz) ? FCU_CG_NEGATIVE : FCU_CG_NOT_FINITE;
        fl[FI_DONE] = 1;
        fl[FI_ACTIVE] = 0;
        return;
    }
    sc[FS_ALPHA] = rz / pq;
}

/* After them: beta, the iteration count, the loop's condition. */
__global__ static void fcu_cg_beta(double *sc, int *fl)
{
    if (!fl[FI_ACTIVE]) return;
    sc[FS_BETA] = sc[FS_RZNEW] / sc[FS_RZ];
    sc[FS_RZ] = sc[FS_RZNEW];
    fl[FI_ITER]++;
    if (!(fl[FI_ITER] < fl[FI_MAXIT] && sc[FS_RR] > sc[FS_TOL2])) fl[FI_DONE] = 1;
}

__global__ static void fcu_cg_pq_gate(int *fl)
{
    fl[FI_ACTIVE] = !fl[FI_DONE]; /* the product and p . q of the coming iteration run only while active */
}

__global__ static void fcu_cg_update(int n, const double *sc, const int *fl, frm_real *x, frm_real *r, const frm_real *p,
                                     const frm_real *q)
{
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    frm_real alpha;
    if (k >= n || !fl[FI_ACTIVE]) return;
    alpha = (frm_real)sc[FS_ALPHA];
    x[k] += alpha * p[k];
    r[k] -= alpha * q[k];
}

__global__ static void fcu_cg_direction(int n, const double *sc, const int *fl, frm_real *p, const frm_real *z)
{
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k >= n || !fl[FI_ACTIVE]) return;
    p[k] = z[k] + (frm_real)sc[FS_BETA] * p[k];
}

__global__ static void fcu_sub(int n, const frm_real *b, const frm_real *q, frm_real *r)
{
    int k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < n) r[k] = b[k] - q[k];
}

/* the system product out = (a_mass M + a_stiff K) v, masked; gated by iflags when given */
static void fcu_system(frm_cuda *g, const frm_real *v, frm_real *out, double a_mass, double a_stiff, int system,
                       const int *iflags)
{
    fcu_apply_pass1<<<fcu_blocks(g->d.sample_count, FCU_BLOCK), FCU_BLOCK, 0, g->stream>>>(g->d, v);
    fcu_apply_pass2<<<fcu_blocks(g->d.frame_count, FCU_BLOCK), FCU_BLOCK, 0, g->stream>>>(
        g->d, v, out, g->mass_world, a_mass, a_stiff, system, iflags);
}

static int fcu_sync_read(frm_cuda *g)
{
    if (!fcu_ok(cudaMemcpyAsync(g->h_scal, g->scal, sizeof(double) * FS_COUNT, cudaMemcpyDeviceToHost, g->stream)))
        return 0;
    if (!fcu_ok(cudaMemcpyAsync(g->h_iflags, g->iflags, sizeof(int) * FI_COUNT, cudaMemcpyDeviceToHost, g->stream)))
        return 0;
    return fcu_ok(cudaStreamSynchronize(g->stream));
}

/* The CG of the step: FRM_OK, FRM_ERR_NO_CONVERGENCE, FRM_ERR_NOT_FINITE, FRM_ERR_DEVICE or
   the linearisation's error (read at the first synchronisation). */
static int fcu_cg(frm_cuda *g, double a_mass, double a_stiff, const frm_real *b, frm_real *x)
{
    int n6 = 6 * g->d.frame_count, fb = fcu_blocks(g->d.frame_count, FCU_BLOCK), vb = fcu_blocks(n6, FCU_BLOCK), it;
    int *fl = g->iflags;
    double bb, rr, tol2;
    fcu_mask<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d, x);
    fcu_dot(g, n6, b, b, FS_BB, NULL);
    fcu_system(g, x, g->cg_q, a_mass, a_stiff, 1, NULL);
    fcu_sub<<<vb, FCU_BLOCK, 0, g->stream>>>(n6, b, g->cg_q, g->cg_r);
    fcu_precond<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d.frame_count, g->precond, g->cg_r, g->cg_z, NULL);
    if (!fcu_ok(cudaMemcpyAsync(g->cg_p, g->cg_z, sizeof(frm_real) * n6, cudaMemcpyDeviceToDevice, g->stream)))
        return FRM_ERR_DEVICE;
    fcu_dot(g, n6, g->cg_r, g->cg_r, FS_RR, NULL);
    fcu_dot(g, n6, g->cg_r, g->cg_z, FS_RZ, NULL);
    fcu_cg_start<<<1, 1, 0, g->stream>>>(g->scal, fl, (double)g->d.cg_tolerance, g->d.cg_max_iterations);
    if (!fcu_sync_read(g)) return FRM_ERR_DEVICE;
    if (g->h_iflags[FI_ERR]) return g->h_iflags[FI_ERR];
    bb = g->h_scal[FS_BB];
    g->iterations = 0;
    if (!isfinite(bb)) return FRM_ERR_NOT_FINITE;
    if (bb == 0) {
        cudaMemsetAsync(x, 0, sizeof(frm_real) * n6, g->stream);
        return FRM_OK;
    }
    while (!g->h_iflags[FI_DONE]) {
        for (it = 0; it < FCU_BATCH; it++) {
            fcu_cg_pq_gate<<<1, 1, 0, g->stream>>>(fl);
            fcu_system(g, g->cg_p, g->cg_q, a_mass, a_stiff, 1, fl);
            fcu_dot(g, n6, g->cg_p, g->cg_q, FS_PQ, fl);
            fcu_cg_alpha<<<1, 1, 0, g->stream>>>(g->scal, fl);
            fcu_cg_update<<<vb, FCU_BLOCK, 0, g->stream>>>(n6, g->scal, fl, x, g->cg_r, g->cg_p, g->cg_q);
            fcu_precond<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d.frame_count, g->precond, g->cg_r, g->cg_z, fl);
            fcu_dot(g, n6, g->cg_r, g->cg_r, FS_RR, fl);
            fcu_dot(g, n6, g->cg_r, g->cg_z, FS_RZNEW, fl);
            fcu_cg_beta<<<1, 1, 0, g->stream>>>(g->scal, fl);
            fcu_cg_direction<<<vb, FCU_BLOCK, 0, g->stream>>>(n6, g->scal, fl, g->cg_p, g->cg_z);
        }
        if (!fcu_sync_read(g)) return FRM_ERR_DEVICE;
    }
    g->iterations = g->h_iflags[FI_ITER];
    rr = g->h_scal[FS_RR];
    tol2 = g->h_scal[FS_TOL2];
    if (g->h_iflags[FI_STATUS] == FCU_CG_NOT_FINITE) return FRM_ERR_NOT_FINITE;
    if (g->h_iflags[FI_STATUS] == FCU_CG_NEGATIVE) return FRM_ERR_NO_CONVERGENCE; /* no definite retry here */
    if (!isfinite(rr)) return FRM_ERR_NOT_FINITE;
    if (!(rr <= tol2)) return FRM_ERR_NO_CONVERGENCE;
    return FRM_OK;
}

/* ---- the step's state update (frm__implicit_linearized's loop, no driven frames) ----------- */

__global__ static void fcu_step_update(frm_view w, frm_real *vel, frm_real *disp, frm_real *quat, const frm_real *dv,
                                       double dt)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, k;
    frm_real *v, th[3];
    if (i >= w.frame_count) return;
    v = vel + 6 * i;
    if (w.state[i] == 1) {
        for (k = 0; k < 6; k++) v[k] = 0;
        return;
    }
    for (k = 0; k < 6; k++) v[k] += dv[6 * i + k];
    for (k = 0; k < 6; k++)
        if ((w.axes[i] >> k) & 1) v[k] = 0;
    for (k = 0; k < 3; k++) {
        disp[3 * i + k] += (frm_real)dt * v[k];
        th[k] = (frm_real)dt * v[3 + k];
    }
    frm_quat_integrate(quat + 4 * i, th);
}

/* non-finite state: err = FRM_ERR_NOT_FINITE (frm__accept's first test) */
__global__ static void fcu_finite(frm_view w, int *err)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, k, ok = 1;
    if (i >= w.frame_count) return;
    for (k = 0; k < 3; k++) ok &= isfinite((double)w.disp[3 * i + k]);
    for (k = 0; k < 4; k++) ok &= isfinite((double)w.quat[4 * i + k]);
    for (k = 0; k < 6; k++) ok &= isfinite((double)w.vel[6 * i + k]);
    if (!ok) atomicMin(err, FRM_ERR_NOT_FINITE);
}

/* backup (13 per frame: displacement, orientation, velocity) <-> state */
__global__ static void fcu_backup(int frames, frm_real *disp, frm_real *quat, frm_real *vel, frm_real *backup, int restore)
{
    int i = blockIdx.x * blockDim.x + threadIdx.x, k;
    frm_real *b;
    if (i >= frames) return;
    b = backup + 13 * (size_t)i;
    if (restore) {
        for (k = 0; k < 3; k++) disp[3 * i + k] = b[k];
        for (k = 0; k < 4; k++) quat[4 * i + k] = b[3 + k];
        for (k = 0; k < 6; k++) vel[6 * i + k] = b[7 + k];
    } else {
        for (k = 0; k < 3; k++) b[k] = disp[3 * i + k];
        for (k = 0; k < 4; k++) b[3 + k] = quat[4 * i + k];
        for (k = 0; k < 6; k++) b[7 + k] = vel[6 * i + k];
    }
}

/* ---- host side ------------------------------------------------------------------------------ */

static int fcu_check_model(const frm_view *h)
{
    int s, i;
    if (h->volumetric) return FRM_ERR_DEVICE;
    for (s = 0; s < h->sample_count; s++)
        if (h->s_law[s] != FRM_LAW_SVK && h->s_law[s] != FRM_LAW_NEO_HOOKEAN) return FRM_ERR_DEVICE;
    for (i = 0; i < h->frame_count; i++)
        if (h->state[i] == 2) return FRM_ERR_DEVICE;
    return FRM_OK;
}

/* one pass of the force (linearize 0 or 1) and pass 2 */
static int fcu_force_pass(frm_cuda *g, int linearize, double a_mass, double a_stiff)
{
    int sb = fcu_blocks(g->d.sample_count, FCU_BLOCK), fb = fcu_blocks(g->d.frame_count, FCU_BLOCK);
    fcu_update_frames<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d, g->rot, g->rel, g->relm);
    fcu_force_pass1<<<sb, FCU_BLOCK, 0, g->stream>>>(g->d, linearize, g->iflags + FI_ERR);
    fcu_frames_linearize<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d, g->rot, g->force, g->total, g->kdiag, g->precond,
                                                          g->mass_world, g->lin_gravity, a_mass, a_stiff,
                                                          g->iflags + FI_ERR);
    return fcu_ok(cudaGetLastError()) ? FRM_OK : FRM_ERR_DEVICE;
}

extern "C" int frm_cuda_upload_state(frm_cuda *g, const frm_model *m)
{
    frm_view h;
    int F, err;
    if (!g || !m) return FRM_ERR_ARG;
    if (frm_model_view(m, &h)) return FRM_ERR_ARG;
    if (h.frame_count != g->d.frame_count || h.sample_count != g->d.sample_count) return FRM_ERR_ARG;
    err = fcu_check_model(&h);
    if (err) return err;
    F = h.frame_count;
    if (!fcu_ok(cudaMemcpy(g->disp, h.disp, sizeof(frm_real) * 3 * F, cudaMemcpyHostToDevice)) ||
        !fcu_ok(cudaMemcpy(g->quat, h.quat, sizeof(frm_real) * 4 * F, cudaMemcpyHostToDevice)) ||
        !fcu_ok(cudaMemcpy(g->vel, h.vel, sizeof(frm_real) * 6 * F, cudaMemcpyHostToDevice)) ||
        !fcu_ok(cudaMemcpy(g->ext, h.ext, sizeof(frm_real) * 6 * F, cudaMemcpyHostToDevice)) ||
        !fcu_ok(cudaMemcpy(g->state, h.state, F, cudaMemcpyHostToDevice)) ||
        !fcu_ok(cudaMemcpy(g->axes, h.axes, F, cudaMemcpyHostToDevice)))
        return FRM_ERR_DEVICE;
    memcpy(g->d.gravity, h.gravity, sizeof h.gravity);
    g->d.time_step = h.time_step;
    g->d.mass_damping = h.mass_damping;
    g->d.stiffness_damping = h.stiffness_damping;
    g->d.cg_tolerance = h.cg_tolerance;
    g->d.cg_max_iterations = h.cg_max_iterations;
    return FRM_OK;
}

extern "C" int frm_cuda_create(const frm_model *m, frm_cuda **out)
{
    frm_view h, *d;
    frm_cuda *g;
    int F, S, P, L, err, count = 0;
    if (!out) return FRM_ERR_ARG;
    *out = NULL;
    if (!m || frm_model_view(m, &h)) return FRM_ERR_ARG;
    err = fcu_check_model(&h);
    if (err) return err;
    if (!fcu_ok(cudaGetDeviceCount(&count)) || count < 1) return FRM_ERR_DEVICE;
    g = (frm_cuda *)calloc(1, sizeof *g);
    if (!g) return FRM_ERR_DEVICE;
    F = h.frame_count;
    S = h.sample_count;
    P = h.pair_count;
    L = h.law_cache;
    d = &g->d;
    *d = h;
#define FCU_UP(field, type, count_)                                                                          \
    do {                                                                                                     \
        d->field = (type *)fcu_alloc(g, sizeof(type) * (size_t)(count_), h.field);                           \
        if (!d->field) goto fail;                                                                            \
    } while (0)
#define FCU_NEW(ptr, type, count_)                                                                           \
    do {                                                                                                     \
        ptr = (type *)fcu_alloc(g, sizeof(type) * (size_t)(count_), NULL);                                   \
        if (!ptr) goto fail;                                                                                 \
    } while (0)
    if (!fcu_ok(cudaStreamCreateWithFlags(&g->stream, cudaStreamNonBlocking))) goto fail;
    FCU_NEW(g->disp, frm_real, 3 * F);
    FCU_NEW(g->quat, frm_real, 4 * F);
    FCU_NEW(g->vel, frm_real, 6 * F);
    FCU_NEW(g->ext, frm_real, 6 * F);
    FCU_NEW(g->state, unsigned char, F);
    FCU_NEW(g->axes, unsigned char, F);
    d->disp = g->disp;
    d->quat = g->quat;
    d->vel = g->vel;
    d->ext = g->ext;
    d->state = g->state;
    d->axes = g->axes;
    FCU_UP(rest_quat, const frm_real, 4 * F);
    FCU_UP(f_stab, const frm_real, 6 * F);
    FCU_UP(f_stab_on, const unsigned char, F);
    FCU_UP(rev_start, const int, F + 1);
    FCU_UP(rev_pair, const int, P);
    FCU_UP(mass_local, const double, 10 * F);
    FCU_UP(grav_local, const double, 4 * F);
    FCU_UP(kdiag_rest, const frm_real, 36 * F);
    FCU_UP(s_start, const int, S + 1);
    FCU_UP(s_rest, const frm_real, 3 * S);
    FCU_UP(s_volume, const frm_real, S);
    FCU_UP(s_couple, const frm_real, S);
    FCU_UP(s_mu, const frm_real, S);
    FCU_UP(s_hstab, const frm_real, S);
    FCU_UP(s_law, const unsigned char, S);
    FCU_UP(s_stab, const unsigned char, S);
    FCU_UP(s_law_params, const frm_real, FRM_LAW_PARAMS * (size_t)S);
    FCU_UP(p_frame, const int, P);
    FCU_UP(p_weight, const frm_real, P);
    FCU_UP(p_grad, const frm_real, 3 * P);
    FCU_UP(p_rlev, const frm_real, 3 * P);
    FCU_NEW(g->lin_hrot, frm_real, 6 * F);
    d->lin_hrot = g->lin_hrot;
    FCU_NEW(d->s_stabY, frm_real, 9 * S);
    FCU_NEW(d->s_stabD, frm_real, S);
    FCU_NEW(d->lin_F, frm_real, 9 * S);
    FCU_NEW(d->lin_S, frm_real, 6 * S);
    FCU_NEW(d->lin_cache, frm_real, (size_t)L * S);
    d->s_pos = NULL;
    FCU_NEW(d->p_G, frm_real, 9 * P);
    FCU_NEW(d->p_H, frm_real, 6 * P);
    FCU_NEW(d->p_A, frm_real, 3 * P);
    FCU_NEW(d->p_C, frm_real, 3 * P);
    FCU_NEW(d->p_stab, frm_real, 3 * P);
    FCU_NEW(d->p_out, frm_real, 6 * P);
    FCU_NEW(g->rot, frm_real, 9 * F);
    FCU_NEW(g->rel, frm_real, 9 * F);
    FCU_NEW(g->relm, frm_real, 9 * F);
    d->rel = g->rel;
    d->relm = g->relm;
    FCU_NEW(g->force, frm_real, 6 * F);
    FCU_NEW(g->total, frm_real, 6 * F);
    FCU_NEW(g->kdiag, frm_real, 36 * F);
    FCU_NEW(g->precond, frm_real, 36 * F);
    FCU_NEW(g->mass_world, frm_real, 10 * F);
    FCU_NEW(g->lin_gravity, frm_real, 3 * F);
    FCU_NEW(g->cg_r, frm_real, 6 * F);
    FCU_NEW(g->cg_z, frm_real, 6 * F);
    FCU_NEW(g->cg_p, frm_real, 6 * F);
    FCU_NEW(g->cg_q, frm_real, 6 * F);
    FCU_NEW(g->dv, frm_real, 6 * F);
    FCU_NEW(g->rhs, frm_real, 6 * F);
    FCU_NEW(g->work, frm_real, 6 * F);
    FCU_NEW(g->warm, frm_real, 6 * F);
    FCU_NEW(g->backup, frm_real, 13 * F);
    FCU_NEW(g->partial, double, FCU_RED_MAX);
    FCU_NEW(g->scal, double, FS_COUNT);
    FCU_NEW(g->iflags, int, FI_COUNT);
#undef FCU_UP
#undef FCU_NEW
    if (!fcu_ok(cudaMallocHost((void **)&g->h_scal, sizeof(double) * FS_COUNT))) goto fail;
    if (!fcu_ok(cudaMallocHost((void **)&g->h_iflags, sizeof(int) * FI_COUNT))) goto fail;
    err = frm_cuda_upload_state(g, m);
    if (err) {
        frm_cuda_destroy(g);
        return err;
    }
    *out = g;
    return FRM_OK;
fail:
    frm_cuda_destroy(g);
    return FRM_ERR_DEVICE;
}

extern "C" void frm_cuda_destroy(frm_cuda *g)
{
    int k;
    if (!g) return;
    if (g->stream) cudaStreamSynchronize(g->stream);
    for (k = 0; k < g->buffer_count; k++) cudaFree(g->buffers[k]);
    if (g->h_scal) cudaFreeHost(g->h_scal);
    if (g->h_iflags) cudaFreeHost(g->h_iflags);
    if (g->stream) cudaStreamDestroy(g->stream);
    free(g);
}

extern "C" int frm_cuda_download(frm_cuda *g, frm_model *m)
{
    int F, k, err;
    frm_real *buf;
    if (!g || !m || frm_model_frame_count(m) != g->d.frame_count) return FRM_ERR_ARG;
    F = g->d.frame_count;
    buf = (frm_real *)malloc(sizeof(frm_real) * 13 * (size_t)F);
    if (!buf) return FRM_ERR_DEVICE;
    if (!fcu_ok(cudaMemcpyAsync(buf, g->disp, sizeof(frm_real) * 3 * F, cudaMemcpyDeviceToHost, g->stream)) ||
        !fcu_ok(cudaMemcpyAsync(buf + 3 * F, g->quat, sizeof(frm_real) * 4 * F, cudaMemcpyDeviceToHost, g->stream)) ||
        !fcu_ok(cudaMemcpyAsync(buf + 7 * F, g->vel, sizeof(frm_real) * 6 * F, cudaMemcpyDeviceToHost, g->stream)) ||
        !fcu_ok(cudaStreamSynchronize(g->stream))) {
        free(buf);
        return FRM_ERR_DEVICE;
    }
    { /* positions = rest + displacement (frm_model_set_poses takes positions) */
        const frm_real *rest = frm_model_rest_positions(m);
        for (k = 0; k < 3 * F; k++) buf[k] = rest[k] + buf[k];
    }
    err = frm_model_set_poses(m, buf, buf + 3 * F);
    if (!err) err = frm_model_set_velocities(m, buf + 7 * F);
    free(buf);
    return err;
}

extern "C" int frm_cuda_forces(frm_cuda *g, frm_real *out)
{
    int err;
    if (!g) return FRM_ERR_ARG;
    cudaMemsetAsync(g->iflags, 0, sizeof(int) * FI_COUNT, g->stream);
    err = fcu_force_pass(g, 0, 1, 0);
    if (err) return err;
    if (!fcu_sync_read(g)) return FRM_ERR_DEVICE;
    if (g->h_iflags[FI_ERR]) return g->h_iflags[FI_ERR];
    if (out && !fcu_ok(cudaMemcpy(out, g->force, sizeof(frm_real) * 6 * g->d.frame_count, cudaMemcpyDeviceToHost)))
        return FRM_ERR_DEVICE;
    return FRM_OK;
}

extern "C" int frm_cuda_linearize(frm_cuda *g)
{
    int err;
    if (!g) return FRM_ERR_ARG;
    cudaMemsetAsync(g->iflags, 0, sizeof(int) * FI_COUNT, g->stream);
    err = fcu_force_pass(g, 1, 1, 0);
    if (err) return err;
    if (!fcu_sync_read(g)) return FRM_ERR_DEVICE;
    return g->h_iflags[FI_ERR];
}

extern "C" int frm_cuda_apply_stiffness(frm_cuda *g, const frm_real *v, frm_real *out)
{
    size_t bytes;
    if (!g || !v || !out) return FRM_ERR_ARG;
    bytes = sizeof(frm_real) * 6 * (size_t)g->d.frame_count;
    if (!fcu_ok(cudaMemcpyAsync(g->work, v, bytes, cudaMemcpyHostToDevice, g->stream))) return FRM_ERR_DEVICE;
    fcu_system(g, g->work, g->cg_q, 0, 1, 0, NULL);
    if (!fcu_ok(cudaMemcpyAsync(out, g->cg_q, bytes, cudaMemcpyDeviceToHost, g->stream)) ||
        !fcu_ok(cudaStreamSynchronize(g->stream)))
        return FRM_ERR_DEVICE;
    return FRM_OK;
}

extern "C" int frm_cuda_step(frm_cuda *g)
{
    double dt, a_mass, a_stiff;
    int fb, sb, err;
    if (!g) return FRM_ERR_ARG;
    dt = (double)g->d.time_step;
    a_mass = 1.0 + dt * (double)g->d.mass_damping;
    a_stiff = dt * dt + dt * (double)g->d.stiffness_damping;
    fb = fcu_blocks(g->d.frame_count, FCU_BLOCK);
    sb = fcu_blocks(g->d.sample_count, FCU_BLOCK);
    cudaMemsetAsync(g->iflags, 0, sizeof(int) * FI_COUNT, g->stream);
    fcu_backup<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d.frame_count, g->disp, g->quat, g->vel, g->backup, 0);
    err = fcu_force_pass(g, 1, a_mass, a_stiff);
    if (err) return err;
    fcu_system(g, g->vel, g->work, 0, 1, 0, NULL); /* K v of the velocities */
    fcu_step_rhs<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d, g->total, g->work, g->mass_world, dt, g->rhs);
    if (!fcu_ok(cudaMemcpyAsync(g->dv, g->warm, sizeof(frm_real) * 6 * g->d.frame_count, cudaMemcpyDeviceToDevice,
                                g->stream)))
        return FRM_ERR_DEVICE;
    err = fcu_cg(g, a_mass, a_stiff, g->rhs, g->dv);
    if (!err) {
        fcu_step_update<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d, g->vel, g->disp, g->quat, g->dv, dt);
        fcu_finite<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d, g->iflags + FI_ERR);
        fcu_update_frames<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d, g->rot, g->rel, g->relm);
        fcu_inversions<<<sb, FCU_BLOCK, 0, g->stream>>>(g->d, g->iflags + FI_ERR);
        if (!fcu_sync_read(g)) return FRM_ERR_DEVICE;
        err = g->h_iflags[FI_ERR];
    }
    if (err) { /* the last valid state back */
        fcu_backup<<<fb, FCU_BLOCK, 0, g->stream>>>(g->d.frame_count, g->disp, g->quat, g->vel, g->backup, 1);
        if (!fcu_ok(cudaStreamSynchronize(g->stream))) return FRM_ERR_DEVICE;
        return err;
    }
    if (!fcu_ok(cudaMemcpyAsync(g->warm, g->dv, sizeof(frm_real) * 6 * g->d.frame_count, cudaMemcpyDeviceToDevice,
                                g->stream)))
        return FRM_ERR_DEVICE;
    return fcu_ok(cudaGetLastError()) ? FRM_OK : FRM_ERR_DEVICE;
}

extern "C" int frm_cuda_last_iterations(const frm_cuda *g) { return g ? g->iterations : 0; }

extern "C" int frm_cuda_synchronize(frm_cuda *g)
{
    if (!g) return FRM_ERR_ARG;
    return fcu_ok(cudaStreamSynchronize(g->stream)) ? FRM_OK : FRM_ERR_DEVICE;
}
