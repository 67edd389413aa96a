/*
 * sr_real.h -- the hand-written part of the generated kernels' interface.
 *
 * generated/sr_generated.h includes this header and adds only what derive/
 * derives (sizes, layout macros, flop counts, prototypes).  What is chosen
 * rather than derived lives here, in C, not in the generator's strings:
 *
 *   sr_real           the scalar type: double, or float with -DSR_USE_FLOAT.
 *   SR_C(v)           a numeric literal in sr_real (1.5 -> 1.5f in the float
 *                     build), so that both builds are clean under
 *                     -Wall -Wextra -Wpedantic -Werror (no double promotion).
 *   SR_GEN_SIN, SR_GEN_COS
 *                     the sine and cosine of sr_real (sr_gen_general_constants
 *                     takes those of the slope, once per model): the library's
 *                     own (c/src/sr_trig.c: in double the same bits on every
 *                     platform, which libm's are not; in float no 4 KB libm
 *                     reduction in a firmware); -DSR_LIBM_TRIG for libm's.
 *   SR_GEN_PIVOT_TOL  relative pivot tolerance of the joint-first solve in
 *                     sr_gen_accel: each pivot of M (M_33, M_44, the leading
 *                     minors of the Schur complement) must exceed it times
 *                     M's diagonal entry, as in an LDL^T, or the kernel
 *                     returns SR_GEN_SINGULAR (1e-13 for double, 1e-6 for
 *                     float).
 *   SR_GEN_LANE_FINITE(v)
 *                     1 if v is finite, else 0, without a branch or a call
 *                     (v - v is 0 for a finite v, NaN otherwise), so that the
 *                     lanes kernels (sr_gen_*_lanes) stay vectorisable; exact
 *                     without -ffast-math, which the library is never built with.
 *   SR_LANES_CLONES   before the definition of a lanes loop (sr_gen_*_lanes,
 *                     sr_internal_check_lanes).  Built with -DSR_CLONES by GCC
 *                     on x86-64 Linux and glibc (the Python extension is), it
 *                     is GCC's target_clones: the loop compiled twice, for AVX2
 *                     and for the baseline, and the loader picks the one the
 *                     CPU runs (ifunc): 1.5x faster batches on any AVX2 machine
 *                     without -march=native.  No FMA is enabled and the library
 *                     is built with -ffp-contract=off, so both clones give the
 *                     same bits (tests/runtime/test_model.py compares batches
 *                     with single calls).  Off by default: the clones need
 *                     libgcc's CPU detection (__cpu_model) and the loader's
 *                     ifunc, outside the self-contained C99 of the library.
 *   SR_JACOBIAN_CLONES
 *                     the same before the definition of a fourth-order step
 *                     Jacobian (c/src/sr_step_jacobians.c), with GCC's flatten, so
 *                     that the file's helpers (rows of 12 columns: three AVX2
 *                     vectors) are inlined into, and compiled for, each clone.
 *   SR_GEN_OK, SR_GEN_NONFINITE, SR_GEN_SINGULAR
 *                     the kernels' status codes; c/src/sr_math.h asserts
 *                     that they equal SR_OK, SR_ERR_NONFINITE and
 *                     SR_ERR_SINGULAR of the public API.
 *
 * Internal to the library: use the checked API of c/include/spherical_robot.h.
 */
#ifndef SR_REAL_H
#define SR_REAL_H

#ifdef SR_USE_FLOAT
typedef float sr_real;
#define SR_C(v) ((sr_real)(v##f))
#define SR_GEN_PIVOT_TOL SR_C(1e-6)
#ifdef SR_LIBM_TRIG
#define SR_GEN_SIN sinf
#define SR_GEN_COS cosf
#else
#define SR_GEN_SIN sr_internal_sinf
#define SR_GEN_COS sr_internal_cosf
/* c/src/sr_trig.c (internal to the library). */
float sr_internal_sinf(float x);
float sr_internal_cosf(float x);
#endif
#else
typedef double sr_real;
#define SR_C(v) ((sr_real)(v))
#define SR_GEN_PIVOT_TOL SR_C(1e-13)
#ifdef SR_LIBM_TRIG
#define SR_GEN_SIN sin
#define SR_GEN_COS cos
#else
#define SR_GEN_SIN sr_internal_sin
#define SR_GEN_COS sr_internal_cos
/* c/src/sr_trig.c (internal to the library); also its arctangent, sr_internal_atan2. */
double sr_internal_sin(double x);
double sr_internal_cos(double x);
double sr_internal_atan2(double y, double x);
#endif
#endif

#define SR_GEN_LANE_FINITE(v) ((v) - (v) == 0)

#include <limits.h> /* with glibc, defines __GLIBC__ (needed by the test below) */
#if defined(SR_CLONES) && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) \
    && defined(__linux__) && defined(__GLIBC__)
#define SR_LANES_CLONES __attribute__((target_clones("avx2", "default")))
#define SR_JACOBIAN_CLONES __attribute__((target_clones("avx2", "default"), flatten))
#else
#define SR_LANES_CLONES
#define SR_JACOBIAN_CLONES
#endif

#define SR_GEN_OK 0
#define SR_GEN_NONFINITE 2
#define SR_GEN_SINGULAR 4

#endif /* SR_REAL_H */
