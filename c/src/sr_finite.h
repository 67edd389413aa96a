/*
 * sr_finite.h -- finiteness tests of arrays, and the all-or-nothing copy of
 * results (written only when they are all finite).
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_FINITE_H
#define SR_FINITE_H

#include "sr_math.h"

/* Sum in four lanes (a short chain of additions per lane).  A NaN or an infinity anywhere makes
 * the sum non-finite; so can finite entries that overflow.  The lanes are an array indexed in an
 * inner loop, the form compilers turn into plain vertical vector additions: with four named
 * accumulators, GCC 12 -O2 -march=native on an AVX-512 machine fully unrolled the loop into
 * 512-bit loads and shuffles around scalar additions, and sr_accel took 71 ns instead of 44. */
static inline sr_real lane_sum(const sr_real *v, int n)
{
    sr_real s[4] = {0, 0, 0, 0};
    int i, k;
    for (i = 0; i + 4 <= n; i += 4)
        for (k = 0; k < 4; ++k) s[k] += v[i + k];
    /* The tail counted from 0: written as `for (; i < n; ++i)`, GCC 12 for 32-bit Arm at -O2
     * reports a false "iteration 1073741823 invokes undefined behavior" (-Werror). */
    for (k = 0; k < n - i; ++k) s[0] += v[i + k];
    return (s[0] + s[1]) + (s[2] + s[3]);
}

/* One test of the sum clears the common case; otherwise entry by entry. */
static inline int all_finite(const sr_real *v, int n)
{
    int i;
    if (isfinite(lane_sum(v, n))) return 1;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* all_finite for long arrays (n a multiple of 16, the step Jacobians' 144 carried entries): the sum
 * in sixteen lanes, four AVX2 vectors, so that its chain of dependent additions is n/16 long, not
 * n/4 (the step Jacobians 10 ns faster); for the 35 entries of a state or the 70 of
 * an accel Jacobian the four lanes of lane_sum are as fast or faster. */
static inline int all_finite_long(const sr_real *v, int n)
{
    sr_real s[16] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    int i, k;
    for (i = 0; i + 16 <= n; i += 16)
        for (k = 0; k < 16; ++k) s[k] += v[i + k];
    for (k = 0; k < 8; ++k) s[k] += s[k + 8];
    for (k = 0; k < 4; ++k) s[k] += s[k + 4];
    if (i == n && isfinite((s[0] + s[1]) + (s[2] + s[3]))) return 1;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* Copy n results from tmp to out when the computation succeeded and they are all finite:
 * outputs are either fully written and finite or untouched.  (The generated kernels do the
 * same themselves: they write only on SR_GEN_OK, and return SR_GEN_NONFINITE, equal to
 * SR_ERR_NONFINITE, when a result is not finite.) */
static inline int deliver(int status, const sr_real *tmp, int n, sr_real *out)
{
    int i;
    if (status != SR_OK) return status;
    if (!all_finite(tmp, n)) return SR_ERR_NONFINITE;
    for (i = 0; i < n; ++i) out[i] = tmp[i];
    return SR_OK;
}

#endif /* SR_FINITE_H */
