/* model_common.h - glue shared by the bench adapters (bench/model_*.c): the conversions
   each adapter makes between the bench_model interface (double) and its library's real
   type. Include after bench.h in an adapter; the adapter is compiled in double, and in
   float with -DBENCH_FLOAT, where it also sets its library's real type to float, so
   bench_real is that type (a mismatch is a pointer-type error at compile time).

   What each helper gives:
   - bench_to_reals(src, dst, n): n doubles to bench_real (rest positions for a desc,
     a pin's displacement, gravity).
   - bench_to_doubles(src, dst, n): n bench_real to doubles (forces out of the model).
   - bench_rest_position(rest, i, p): node i of an array of 3n rest positions in double.
   - bench_displaced_position(rest, x, x0, i, p): node i at its double rest position plus
     the model's displacement x - x0, so that a float model far from the origin reports
     its displacement, not the rounding of its coordinates.
   - bench_kernel_direction(v, n): a fixed vector of n components of about 1e-3, the
     direction the K * v kernels are timed with. */
#ifndef BENCH_MODEL_COMMON_H
#define BENCH_MODEL_COMMON_H

#ifdef BENCH_FLOAT
typedef float bench_real;
#else
typedef double bench_real;
#endif

static inline void bench_to_reals(const double *src, bench_real *dst, int n)
{
    int i;
    for (i = 0; i < n; i++) dst[i] = (bench_real)src[i];
}

static inline void bench_to_doubles(const bench_real *src, double *dst, int n)
{
    int i;
    for (i = 0; i < n; i++) dst[i] = (double)src[i];
}

static inline void bench_rest_position(const double *rest, int i, double p[3])
{
    int k;
    for (k = 0; k < 3; k++) p[k] = rest[3 * i + k];
}

static inline void bench_displaced_position(const double *rest, const bench_real *x, const bench_real *x0, int i,
                                            double p[3])
{
    int k;
    for (k = 0; k < 3; k++) p[k] = rest[3 * i + k] + ((double)x[3 * i + k] - (double)x0[3 * i + k]);
}

static inline void bench_kernel_direction(bench_real *v, int n)
{
    int i;
    for (i = 0; i < n; i++) v[i] = (bench_real)(1e-3 * ((i * 7919) % 13 - 6));
}

#endif
