/* fixtures.h - helpers shared by the test programs (tests/test_*.c).

   Include after test.h (and after examples/tetmesh.h for the mesh helpers). Everything
   here is static inline, in the common subset of C99 and C++, and works in double
   whatever the library's real type (helpers tied to one header's types stay in that
   header's test programs). The names are the ones the test programs used when each kept
   its own copy, so a test reads the same with the shared helper.

   What each helper gives:
   - rnd(&state): deterministic pseudo-random numbers in [-1, 1] (a linear congruential
     generator: the same sequence on every platform and compiler), for perturbed states,
     random directions and the seeds of the finite-difference checks.
   - counting_allocator, count_alloc, count_free: an allocator for a desc's allocator
     field (user = &a counting_allocator) that counts allocations, frees and live bytes,
     honours the requested alignment, and returns NULL on every call while .fail is set
     (out-of-memory tests). The "nothing allocates after creation" and "everything is
     freed" tests read its counters.
   - log_capture, capture_log: a logger callback for a desc's log field (user = &a
     log_capture) that counts the calls and keeps the last error code.
   Only when examples/tetmesh.h was included before this file:
   - box_mesh(mesh, nx, ny, nz, sx, sy, sz, split): the box [0, sx] x [0, sy] x [0, sz]
     of nx x ny x nz cells, split into tetrahedra (TETMESH_SPLIT5 or TETMESH_SPLIT6).
   - fem_gradients(p, grad): the gradients of the barycentric coordinates of the
     tetrahedron p[0..3] (the P1 shape functions of an independent linear FEM, to compare
     the models with), returning its signed volume. */
#ifndef FIXTURES_H
#define FIXTURES_H

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

/* Deterministic pseudo-random numbers in [-1, 1]. */
static inline double rnd(unsigned *state)
{
    *state = *state * 1664525u + 1013904223u;
    return ((*state >> 8) & 0xFFFFFF) / (double)0x7FFFFF - 1.0;
}

/* Allocation counters: start from {0, 0, 0, 0}; {0, 0, 1, 0} (fail set) is an allocator
   with nothing to give. */
typedef struct counting_allocator {
    int allocs, frees, fail;
    long long live; /* bytes allocated and not yet freed */
} counting_allocator;

static inline void *count_alloc(size_t size, size_t align, void *user)
{
    counting_allocator *c = (counting_allocator *)user;
    char *raw, *p;
    if (c->fail) return NULL;
    raw = (char *)malloc(size + align + sizeof(void *));
    if (!raw) return NULL;
    p = raw + sizeof(void *);
    p += (align - (size_t)p % align) % align;
    ((void **)p)[-1] = raw;
    c->allocs++;
    c->live += (long long)size;
    return p;
}

static inline void count_free(void *ptr, size_t size, void *user)
{
    counting_allocator *c = (counting_allocator *)user;
    c->frees++;
    c->live -= (long long)size;
    free(((void **)ptr)[-1]);
}

/* What a logger callback received. */
typedef struct log_capture {
    int calls, last_code;
} log_capture;

static inline void capture_log(int code, const char *message, void *user)
{
    log_capture *c = (log_capture *)user;
    c->calls++;
    c->last_code = code;
    (void)message;
}

#ifdef TETMESH_H
/* The box [0, sx] x [0, sy] x [0, sz], nx x ny x nz cells, split into tetrahedra. */
static inline void box_mesh(tetmesh *mesh, int nx, int ny, int nz, double sx, double sy, double sz,
                                    int split)
{
    double lo[3] = {0, 0, 0}, hi[3];
    hi[0] = sx;
    hi[1] = sy;
    hi[2] = sz;
    tetmesh_box(mesh, lo, hi, nx, ny, nz, split);
}

/* Gradients of the barycentric coordinates from the inverse of [1 x y z] rows; returns
   the signed volume. */
static inline double fem_gradients(const double *p[4], double grad[4][3])
{
    double a[4][8];
    int i, j, k;
    for (i = 0; i < 4; i++) {
        a[i][0] = 1.0;
        for (k = 0; k < 3; k++) a[i][1 + k] = p[i][k];
        for (j = 0; j < 4; j++) a[i][4 + j] = (i == j);
    }
    for (i = 0; i < 4; i++) { /* Gauss-Jordan with partial pivoting */
        int piv = i;
        double s;
        for (j = i + 1; j < 4; j++)
            if (fabs(a[j][i]) > fabs(a[piv][i])) piv = j;
        for (k = 0; k < 8; k++) {
            s = a[i][k];
            a[i][k] = a[piv][k];
            a[piv][k] = s;
        }
        s = a[i][i];
        for (k = 0; k < 8; k++) a[i][k] /= s;
        for (j = 0; j < 4; j++)
            if (j != i) {
                s = a[j][i];
                for (k = 0; k < 8; k++) a[j][k] -= s * a[i][k];
            }
    }
    /* inverse C = a[.][4..7]; N_j = C[0][j] + C[1][j] x + C[2][j] y + C[3][j] z */
    for (j = 0; j < 4; j++)
        for (k = 0; k < 3; k++) grad[j][k] = a[1 + k][4 + j];
    return tetmesh_tet_volume(p[0], p[1], p[2], p[3]);
}
#endif /* TETMESH_H */

#endif /* FIXTURES_H */
