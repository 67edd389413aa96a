/*
 * sr_internal.h -- helpers shared by the hand-written C files.  Internal to the library: not
 * part of the public API of spherical_robot.h, and not seen by the cffi bindings.
 *
 * The files and who calls whom (no file calls a file above it, so there is no call cycle):
 *     sr_drivers.c   sr_simulate, sr_simulate_guarded, sr_simulate_adaptive
 *       -> sr_steppers.c  every stepper (Lie-Euler, RKMK4, CF4) on one vector field, projection
 *       -> sr_checks.c    sr_check_state (full state check)
 *     sr_kernels.c   the checked wrappers of the generated kernels, sr_so3_exp
 *     sr_model.c     sr_status_string, sr_check_params, sr_model_init
 * and all of them -> generated/sr_generated.c and the inline helpers below.
 *
 * Everything here is static inline (no code unless used) or a declaration of an internal
 * function of sr_steppers.c; no globals.
 */
#ifndef SR_INTERNAL_H
#define SR_INTERNAL_H

#include "spherical_robot.h"

#include <float.h>
#include <math.h>
#include <stddef.h> /* NULL */

#ifdef SR_USE_FLOAT
#define SR_SQRT sqrtf
#define SR_SIN SR_GEN_SIN      /* c/sr_trig.c, or libm's with -DSR_LIBM_TRIG (sr_real.h) */
#define SR_COS SR_GEN_COS
#define SR_FABS fabsf
#define SR_POW powf
#define SR_ATAN2 atan2f
#define SR_EPSILON FLT_EPSILON
#else
#define SR_SQRT sqrt
#define SR_SIN sin
#define SR_COS cos
#define SR_FABS fabs
#define SR_POW pow
#define SR_ATAN2 atan2
#define SR_EPSILON DBL_EPSILON
#endif

/* c/sr_trig.c's float sine and cosine: accurate to 2^-23 up to SR_TRIG_EXACT_RANGE, their
 * reduction's rounding growing as |x| 2^-24 beyond, NaN past SR_TRIG_MAX_ARG. */
#define SR_TRIG_EXACT_RANGE 8192.0f
#define SR_TRIG_MAX_ARG 16777216.0f

/* The generated kernels' status codes are the library's: their results pass through. */
#if SR_GEN_OK != SR_OK || SR_GEN_NONFINITE != SR_ERR_NONFINITE || SR_GEN_SINGULAR != SR_ERR_SINGULAR
#error "generated status codes differ from spherical_robot.h"
#endif

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
 * n/4 (the step Jacobians -10 ns, measured 2026-11-25); for the 35 entries of a state or the 70 of
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

static inline int near(sr_real a, sr_real b) { return SR_FABS(a - b) <= SR_ROTATION_TOL; }

/* Zero torque, for the callers that pass u = NULL. */
static const sr_real sr_zero_u[SR_NU] = {0, 0};

/* Checks before every kernel call: all of x (and u, if given) finite; gamma = third row of
 * R_S of unit length; the cos/sin entries of R_Y and R_P of unit length.  The full structure
 * check is sr_check_state. */
static inline int checks(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU])
{
    const sr_real *gam = x + SR_X_R_S + 6;
    sr_real sum, worst, defect;
    if (!model || !x) return SR_ERR_NULL;
    /* Fast path, one branch: the sum of all entries finite and the largest unit-length defect
     * within tolerance (a NaN fails both tests).  Anything else is sorted out below, in order. */
    sum = lane_sum(x, SR_NX) + (u ? u[0] + u[1] : 0);
    worst = SR_FABS(gam[0] * gam[0] + gam[1] * gam[1] + gam[2] * gam[2] - 1);
    defect = SR_FABS(x[SR_X_R_Y + 4] * x[SR_X_R_Y + 4] + x[SR_X_R_Y + 7] * x[SR_X_R_Y + 7] - 1);
    worst = defect > worst ? defect : worst;
    defect = SR_FABS(x[SR_X_R_P + 0] * x[SR_X_R_P + 0] + x[SR_X_R_P + 2] * x[SR_X_R_P + 2] - 1);
    worst = defect > worst ? defect : worst;
    if (isfinite(sum) && worst <= SR_ROTATION_TOL) return SR_OK;
    if (!all_finite(x, SR_NX) || (u && !all_finite(u, SR_NU))) return SR_ERR_NONFINITE;
    if (!near(gam[0] * gam[0] + gam[1] * gam[1] + gam[2] * gam[2], 1)) return SR_ERR_NOT_ROTATION;
    if (!near(x[SR_X_R_Y + 4] * x[SR_X_R_Y + 4] + x[SR_X_R_Y + 7] * x[SR_X_R_Y + 7], 1)) return SR_ERR_NOT_ROTATION;
    if (!near(x[SR_X_R_P + 0] * x[SR_X_R_P + 0] + x[SR_X_R_P + 2] * x[SR_X_R_P + 2], 1)) return SR_ERR_NOT_ROTATION;
    return SR_OK;
}

/* Below this t^2 (|t| < 1/4 rad) sin(t)/t and (1 - cos t)/t^2 come from their Taylor series:
 * the first omitted terms, t^12/13! and t^12/14!, are below 1e-17 of the sums, so the series
 * are as accurate as libm's sin and need neither sqrt nor sin.  The steppers' increments
 * (|w| dt for dt = 0.01 s up to 25 rad/s) fall here, which makes the fourth-order steps about
 * twice as fast (README, "Benchmarks"). */
#define SR_SERIES_T2 SR_C(0.0625)

/* sin(t)/t and (1 - cos t)/t^2 from t2 = t^2 < SR_SERIES_T2, through the t2^5 terms, in
 * Estrin's form: pairs of terms, then t2^2 and t2^4 times them, so that the chain of dependent
 * operations is 5 long instead of Horner's 15 (the steppers' stages wait for these
 * coefficients: the RKMK4 step is about a tenth faster).  Within 0.75 ulp of sin(t)/t and
 * 2 sin^2(t/2)/t^2 for |t| < 1/4 (measured against long double at 2e5 points). */
static inline sr_real sinc_series(sr_real t2)
{
    const sr_real t4 = t2 * t2, t8 = t4 * t4;
    return (1 - t2 * (SR_C(1.0) / 6)) + t4 * (SR_C(1.0) / 120 - t2 * (SR_C(1.0) / 5040))
         + t8 * (SR_C(1.0) / 362880 - t2 * (SR_C(1.0) / 39916800));
}
static inline sr_real cosc_series(sr_real t2)
{
    const sr_real t4 = t2 * t2, t8 = t4 * t4;
    return (SR_C(0.5) - t2 * (SR_C(1.0) / 24)) + t4 * (SR_C(1.0) / 720 - t2 * (SR_C(1.0) / 40320))
         + t8 * (SR_C(1.0) / 3628800 - t2 * (SR_C(1.0) / 479001600));
}

/* c(t) = (1 - (t/2) cot(t/2)) / t^2 of dexp^-1 (sr_steppers.c) and its derivative dc/ds, s = t^2,
 * by their Taylor series for s < SR_SERIES_T2 (|t| < 1/4 rad), in Estrin's form: through s^5, the
 * first omitted term of c, s^6/74724249600, is below 1e-17 of c there; dc through s^5 and one term
 * more (its first omitted, 7 c_7 s^6, below 1e-16 of dc).  Up to 2026-11-25 the series ended at
 * s = 1e-2 (four terms) and sin, cos and a division served beyond: RKMK4 stages at 10-25 rad/s
 * with dt = 0.01 s took that branch, which the vectorised batch step (sr_step_lanes.c) cannot. */
#define SR_DEXPINV_C0 (SR_C(1.0) / 12)
#define SR_DEXPINV_C1 (SR_C(1.0) / 720)
#define SR_DEXPINV_C2 (SR_C(1.0) / 30240)
#define SR_DEXPINV_C3 (SR_C(1.0) / 1209600)
#define SR_DEXPINV_C4 (SR_C(1.0) / 47900160)
#define SR_DEXPINV_C5 (SR_C(691.0) / SR_C(1307674368000.0))
#define SR_DEXPINV_C6 (SR_C(1.0) / SR_C(74724249600.0))
static inline sr_real dexpinv_series(sr_real s)
{
    const sr_real s2 = s * s, s4 = s2 * s2;
    return (SR_DEXPINV_C0 + s * SR_DEXPINV_C1) + s2 * (SR_DEXPINV_C2 + s * SR_DEXPINV_C3)
         + s4 * (SR_DEXPINV_C4 + s * SR_DEXPINV_C5);
}
static inline sr_real dexpinv_series_derivative(sr_real s)
{
    const sr_real s2 = s * s, s4 = s2 * s2;
    return (SR_DEXPINV_C1 + s * (2 * SR_DEXPINV_C2)) + s2 * (3 * SR_DEXPINV_C3 + s * (4 * SR_DEXPINV_C4))
         + s4 * (5 * SR_DEXPINV_C5 + s * (6 * SR_DEXPINV_C6));
}

/* Rodrigues' coefficients A = sin(t)/t and B = (1 - cos t)/t^2 from t^2 = |w|^2, so that
 * Exp([[w]]) = I + A [[w]] + B [[w]]^2 (sr_so3_exp; the Lie-group steppers use the same
 * coefficients to form Exp - I directly). */
static inline void so3_exp_coefficients(sr_real theta2, sr_real *A, sr_real *B)
{
    if (theta2 < SR_SERIES_T2) {
        *A = sinc_series(theta2);
        *B = cosc_series(theta2);
    } else {
        const sr_real theta = SR_SQRT(theta2);
        const sr_real s_half = SR_SIN(SR_C(0.5) * theta);
        *A = SR_SIN(theta) / theta;
        *B = SR_C(2.0) * s_half * s_half / theta2; /* (1 - cos t)/t^2 without cancellation */
    }
}

/* sin(t) and cos(t) - 1 (the latter without cancellation): the one-axis rotations' increments. */
static inline void sin_and_cos_minus_one(sr_real t, sr_real *s, sr_real *cm1)
{
    const sr_real t2 = t * t;
    if (t2 < SR_SERIES_T2) {
        *s = t * sinc_series(t2);
        *cm1 = -t2 * cosc_series(t2);
    } else {
        const sr_real sh = SR_SIN(SR_C(0.5) * t);
        *s = SR_SIN(t);
        *cm1 = SR_C(-2.0) * sh * sh;
    }
}

/* D = Exp([[w]]) - I = A [[w]] + B [[w]]^2, the one formula behind
 * sr_so3_exp and the steppers (small entries keep full relative precision). */
static inline void so3_exp_minus_identity(const sr_real w[3], sr_real D[9])
{
    const sr_real x2 = w[0] * w[0], y2 = w[1] * w[1], z2 = w[2] * w[2];
    sr_real A, B;
    so3_exp_coefficients(x2 + y2 + z2, &A, &B);
    /* [[w]]^2 = w w^T - |w|^2 I, its diagonal written without cancellation. */
    D[0] = -B * (y2 + z2);
    D[4] = -B * (x2 + z2);
    D[8] = -B * (x2 + y2);
    D[1] = B * w[0] * w[1] - A * w[2];
    D[3] = B * w[0] * w[1] + A * w[2];
    D[2] = B * w[0] * w[2] + A * w[1];
    D[6] = B * w[0] * w[2] - A * w[1];
    D[5] = B * w[1] * w[2] - A * w[0];
    D[7] = B * w[1] * w[2] + A * w[0];
}

/* C = A B for row-major 3x3 matrices (C must not alias A or B). */
static inline void matmul3(const sr_real *A, const sr_real *B, sr_real *C)
{
    int i, j;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j)
            C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
}

/* out = R Exp(angle * [[e_k]]) for a rotation about axis k, keeping the exact zeros and ones
 * (out must not alias R). */
static inline void rotate_about_axis(const sr_real *R, int k, sr_real angle, sr_real *out)
{
    sr_real E[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
    const sr_real c = SR_COS(angle), s = SR_SIN(angle);
    const int i = (k + 1) % 3, j = (k + 2) % 3; /* Exp(t[[e_k]]) rotates the (i, j) plane */
    E[4 * k] = 1;
    E[3 * i + i] = c;
    E[3 * j + j] = c;
    E[3 * i + j] = -s;
    E[3 * j + i] = s;
    matmul3(R, E, out);
}

/* w = Log(R), |w| <= pi, for a rotation R (row-major), accurate for every angle: the axis comes
 * from the skew part while the angle is at most pi/2 and from the symmetric part beyond, where
 * sin(theta) loses the accuracy that (R + R^T)/2 - cos(theta) I = (1 - cos theta) n n^T keeps. */
static inline void so3_log(const sr_real R[9], sr_real w[3])
{
    const sr_real s[3] = {SR_C(0.5) * (R[7] - R[5]), SR_C(0.5) * (R[2] - R[6]), SR_C(0.5) * (R[3] - R[1])};
    const sr_real sin_t = SR_SQRT(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    sr_real cos_t = SR_C(0.5) * (R[0] + R[4] + R[8] - 1);
    sr_real theta, scale;
    int i;
    cos_t = cos_t > 1 ? 1 : (cos_t < -1 ? -1 : cos_t);
    theta = SR_ATAN2(sin_t, cos_t);
    if (cos_t >= 0) {
        /* theta / sin(theta); its series below 1e-4 rad (the next term, 7 t^4/360, is < 2e-18). */
        scale = theta < SR_C(1e-4) ? 1 + theta * theta / 6 : theta / sin_t;
        for (i = 0; i < 3; ++i) w[i] = scale * s[i];
    } else {
        /* The column of S = (R + R^T)/2 - cos(theta) I with the largest diagonal entry: that
         * entry is (1 - cos theta) n_k^2 >= 1/3, so its direction is n to rounding. */
        sr_real n[3], norm;
        int k = 0;
        for (i = 1; i < 3; ++i)
            if (R[4 * i] > R[4 * k]) k = i;
        for (i = 0; i < 3; ++i) n[i] = SR_C(0.5) * (R[3 * i + k] + R[3 * k + i]);
        n[k] -= cos_t;
        /* The sign of the axis from the skew part sin(theta) n (immaterial at theta = pi). */
        if (n[0] * s[0] + n[1] * s[1] + n[2] * s[2] < 0)
            for (i = 0; i < 3; ++i) n[i] = -n[i];
        norm = SR_SQRT(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (i = 0; i < 3; ++i) w[i] = theta * n[i] / norm;
    }
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

/* The right Jacobian of SO(3), Exp(phi + e) = Exp(phi) Exp(Jr(phi) e) + O(|e|^2):
 * Jr = I - a [[phi]] + b [[phi]]^2, a = (1 - cos t)/t^2, b = (t - sin t)/t^3 (series below t = 1/4). */
static inline void so3_right_jacobian(const sr_real phi[3], sr_real Jr[9])
{
    const sr_real x2 = phi[0] * phi[0], y2 = phi[1] * phi[1], z2 = phi[2] * phi[2];
    const sr_real t2 = x2 + y2 + z2;
    sr_real a, b;
    if (t2 < SR_SERIES_T2) {
        /* b = sum_k (-t2)^k / (2k + 3)! through k = 5, in Estrin's form (as the series above) */
        const sr_real t4 = t2 * t2;
        a = cosc_series(t2);
        b = (SR_C(1.0) / 6 - t2 * (SR_C(1.0) / 120)) + t4 * (SR_C(1.0) / 5040 - t2 * (SR_C(1.0) / 362880))
          + t4 * t4 * (SR_C(1.0) / 39916800 - t2 * (SR_C(1.0) / SR_C(6227020800.0)));
    } else {
        const sr_real t = SR_SQRT(t2), s_half = SR_SIN(SR_C(0.5) * t);
        a = SR_C(2.0) * s_half * s_half / t2;
        b = (t - SR_SIN(t)) / (t2 * t);
    }
    /* Jr = I - a [phi] + b [phi]^2, [phi]^2 = phi phi^T - |phi|^2 I with its diagonal written
     * without cancellation */
    Jr[0] = 1 - b * (y2 + z2);
    Jr[4] = 1 - b * (x2 + z2);
    Jr[8] = 1 - b * (x2 + y2);
    Jr[1] = a * phi[2] + b * phi[0] * phi[1];
    Jr[3] = -a * phi[2] + b * phi[0] * phi[1];
    Jr[2] = -a * phi[1] + b * phi[0] * phi[2];
    Jr[6] = a * phi[1] + b * phi[0] * phi[2];
    Jr[5] = a * phi[0] + b * phi[1] * phi[2];
    Jr[7] = -a * phi[0] + b * phi[1] * phi[2];
}

/* ---- sr_kernels.c: the model's kernels, of the paper's geometry or general (sr_model) ------ */
#ifdef SR_USE_FLOAT
#define sr_internal_accel sr_internal_accel_f
#define sr_internal_inertia sr_internal_inertia_f
#define sr_internal_rhs sr_internal_rhs_f
#define sr_internal_energy sr_internal_energy_f
#define sr_internal_equilibrium_residual sr_internal_equilibrium_residual_f
#define sr_internal_general_accel_jacobian_terms sr_internal_general_accel_jacobian_terms_f
#define sr_internal_cholesky sr_internal_cholesky_f
#endif

/* The generated kernel of model's kind, unchecked (the SR_GEN_ status codes); u not NULL. */
int sr_internal_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV]);
int sr_internal_inertia(const sr_model *model, const sr_real x[SR_NX], sr_real M[SR_NV * SR_NV]);
int sr_internal_rhs(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real f[SR_NV]);
int sr_internal_energy(const sr_model *model, const sr_real x[SR_NX], sr_real *energy);
int sr_internal_equilibrium_residual(const sr_model *model, const sr_real x[SR_NX], sr_real res[SR_NV]);
/* The general robot's M, f, df/dd, df/du and dM/dd (shell frame) for sr_accel_jacobian; the
 * paper's robot has its own kernel in the yoke frame (c/sr_jacobians.c). */
int sr_internal_general_accel_jacobian_terms(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                             sr_real Mu[15], sr_real f[SR_NV], sr_real df[SR_NV * SR_NE],
                                             sr_real dfdu[SR_NV * SR_NU], sr_real dM[5 * 15]);

/* Index of M[i][j] (either order) in the row-by-row upper triangle Mu[15] of a 5x5 matrix. */
static const unsigned char SR_UPPER[SR_NV][SR_NV] = {
    {0, 1, 2, 3, 4}, {1, 5, 6, 7, 8}, {2, 6, 9, 10, 11}, {3, 7, 10, 12, 13}, {4, 8, 11, 13, 14}};

/* M = L L^T (L lower, row-major) from its upper triangle Mu, and the reciprocals of L's diagonal;
 * each pivot must exceed SR_GEN_PIVOT_TOL times M's diagonal entry, as in the paper-geometry
 * accel kernel's test, else SR_ERR_SINGULAR. */
int sr_internal_cholesky(const sr_real Mu[15], sr_real L[SR_NV * SR_NV], sr_real inv[SR_NV]);

/* ---- sr_steppers.c, for the drivers of sr_drivers.c ---------------------------------------- */
#ifdef SR_USE_FLOAT /* float symbols carry _f, as in spherical_robot.h */
#define sr_internal_valid_method sr_internal_valid_method_f
#define sr_internal_advance sr_internal_advance_f
#define sr_internal_check_lanes sr_internal_check_lanes_f
#define sr_internal_lie_euler_lanes sr_internal_lie_euler_lanes_f
#define sr_internal_act_lanes sr_internal_act_lanes_f
#define sr_internal_act2_lanes sr_internal_act2_lanes_f
#define sr_internal_field_lanes sr_internal_field_lanes_f
#define sr_internal_vector_field sr_internal_vector_field_f
#define sr_internal_kinematics sr_internal_kinematics_f
#define sr_internal_accel_jacobian sr_internal_accel_jacobian_f
#define sr_internal_accel_jacobian_along sr_internal_accel_jacobian_along_f
#define sr_internal_rkmk4_core sr_internal_rkmk4_core_f
#define sr_internal_dexpinv sr_internal_dexpinv_f
#define sr_internal_project sr_internal_project_f
#endif

/* A Lie-algebra element ("tangent coordinates") of the state's group, 13 numbers:
 * [th_S (3) | th_Y | th_P | th_q (3) | th_nu (5)] (see the top of sr_steppers.c). */
enum { SR_T_S = 0, SR_T_Y = 3, SR_T_P = 4, SR_T_Q = 5, SR_T_V = 8, SR_NT = 13 };

/* ---- the group action, given the SO(3) increment (the steppers and the step Jacobians' stages) --
 * Rounding and orthogonality.  Forming E = Exp(...) and then R E rounds the diagonal of E to
 * the grid of numbers near 1 (spacing 1.1e-16 or 2.2e-16); when the angular velocity changes
 * slowly, that rounding error is nearly the same at every step and |R^T R - I| grows
 * linearly (about 1e-11 after 10^6 steps).  We therefore form the increment D = E - I
 * directly (its entries are small and carry full relative precision) and update
 * R <- R + R D: the remaining rounding is that of one addition per entry, which does not
 * repeat from step to step. */

/* x + d, Kahan-compensated when comp is not NULL: the low-order bits that one addition loses are
 * carried to the next step instead of being rounded the same way at every step, which keeps
 * |R^T R - I| at the rounding level even when a resting robot's increments stay constant and
 * below one ulp of the entries near 1 (the stagnation that otherwise grows |R^T R - I| linearly). */
static inline sr_real compensated_add(sr_real x, sr_real d, sr_real *comp)
{
    sr_real y, t;
    if (!comp) return x + d;
    y = d - *comp;
    t = x + y;
    *comp = (t - x) - y;
    return t;
}

/* The one-axis rotation R = Exp(theta [[e_k]]) (k = 0: R_Y about x, entries c = R[4],
 * s = R[7]; k = 1: R_P about y, c = R[0], s = R[2]) times Exp(angle [[e_k]]): R (Exp - I)
 * changes only (c, s), by (c (cos - 1) - s sin, s (cos - 1) + c sin); the exact zeros and ones
 * are copied (an increment of exactly 0, whose compensation stays 0).  The state check has made
 * sure R has this form.  out may alias R. */
static inline void axis_increment(const sr_real R[9], int k, sr_real angle, sr_real *comp, sr_real out[9])
{
    const int ic = k == 0 ? 4 : 0, is = k == 0 ? 7 : 2;      /* where c and s stand */
    const int ims = k == 0 ? 5 : 6, ic2 = 8;                   /* -s and the second c */
    const sr_real c = R[ic], s = R[is];
    sr_real sn, cm1, dc, ds;
    int m;
    sin_and_cos_minus_one(angle, &sn, &cm1);
    dc = c * cm1 - s * sn;
    ds = s * cm1 + c * sn;
    for (m = 0; m < 9; ++m) out[m] = R[m];
    out[ic] = compensated_add(R[ic], dc, comp ? comp + ic : NULL);
    out[ic2] = compensated_add(R[ic2], dc, comp ? comp + ic2 : NULL);
    out[is] = compensated_add(R[is], ds, comp ? comp + is : NULL);
    out[ims] = compensated_add(R[ims], -ds, comp ? comp + ims : NULL);
}

/* out = x . exp(th) for D = Exp(th_S) - I already formed: R_S + R_S D, the one-axis rotations by
 * th_Y and th_P, q + th_q, nu + th_nu, every sum compensated with comp (SR_NX entries) unless it
 * is NULL.  out may alias x.  The one formula of the group action: the steppers (sr_steppers.c)
 * and the step Jacobians' stages (sr_step_jacobians.c, which have D at hand) both use it. */
static inline void act_increment(const sr_real x[SR_NX], const sr_real D[9], const sr_real th[SR_NT], sr_real *comp,
                                 sr_real out[SR_NX])
{
    sr_real dR[9];
    int i;
    matmul3(x + SR_X_R_S, D, dR);
    for (i = 0; i < 9; ++i) out[SR_X_R_S + i] = compensated_add(x[SR_X_R_S + i], dR[i], comp ? comp + SR_X_R_S + i : NULL);
    axis_increment(x + SR_X_R_Y, 0, th[SR_T_Y], comp ? comp + SR_X_R_Y : NULL, out + SR_X_R_Y);
    axis_increment(x + SR_X_R_P, 1, th[SR_T_P], comp ? comp + SR_X_R_P : NULL, out + SR_X_R_P);
    for (i = 0; i < 3; ++i) out[SR_X_q + i] = compensated_add(x[SR_X_q + i], th[SR_T_Q + i], comp ? comp + SR_X_q + i : NULL);
    for (i = 0; i < SR_NV; ++i)
        out[SR_X_w_S + i] = compensated_add(x[SR_X_w_S + i], th[SR_T_V + i], comp ? comp + SR_X_w_S + i : NULL);
}

/* The lanes form of the state checks but finiteness (c/sr_checks.c): ok[i] = 1 or 0. */
void sr_internal_check_lanes(const sr_model *model, long n, const sr_real *restrict x, long x_stride,
                             sr_real *restrict ok);

/* The Lie-Euler step of n states whose accelerations a are given, one lane per state, for
 * sr_step_batch (c/sr_step_batch.c): ok[i] = 1 where the lane's result is sr_step's, else 0. */
void sr_internal_lie_euler_lanes(sr_real r, long n, const sr_real *restrict x, long x_stride,
                                 const sr_real *restrict a, long a_stride, sr_real dt,
                                 sr_real *restrict out, long out_stride, sr_real *restrict ok);

/* The pieces of the fourth-order steps in the same form (c/sr_step_batch.c): x . exp(th) and
 * x . exp(th1) . exp(th2) (ok cleared past the series or for a non-finite result, else kept); the
 * vector field from given accelerations, then dexp^-1 if th is not NULL (ok likewise). */
void sr_internal_act_lanes(long n, const sr_real *restrict x, long x_stride, const sr_real *restrict th,
                           long th_stride, sr_real *restrict out, long out_stride, sr_real *restrict ok);
void sr_internal_act2_lanes(long n, const sr_real *restrict x, long x_stride, const sr_real *restrict th1,
                            const sr_real *restrict th2, long th_stride, sr_real *restrict out, long out_stride,
                            sr_real *restrict ok);
void sr_internal_field_lanes(sr_real r, long n, const sr_real *restrict y, long y_stride, const sr_real *restrict a,
                             long a_stride, const sr_real *restrict th, long th_stride, sr_real *restrict f,
                             long f_stride, sr_real *restrict ok);

/* Nonzero if method is SR_LIE_EULER, SR_RKMK4 or SR_CF4, optionally | SR_PROJECT. */
int sr_internal_valid_method(int method);

/* One step of any valid method without argument checks (sr_step/sr_simulate check first);
 * u must not be NULL; out may alias x.  comp: NULL for a single step, or the running Kahan
 * compensation of a simulation (SR_NX entries, zero at its start) for the fourth-order
 * methods, updated only when the step succeeds (Lie-Euler stays the paper's plain eq. (111)). */
int sr_internal_advance(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                        sr_real dt, sr_real *comp, sr_real out[SR_NX]);

/* f = the velocity of the state in the Lie algebra (SR_NT entries); counts the acceleration
 * evaluations in *evaluations (if not NULL). */
int sr_internal_vector_field(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                             sr_real f[SR_NT], long *evaluations);

/* The first SR_T_V entries of the vector field: the velocities and the rolling q' (the rest,
 * the accelerations, from the dynamics). */
void sr_internal_kinematics(const sr_model *model, const sr_real x[SR_NX], sr_real f[SR_NT]);

/* sr_accel_jacobian without the checks (x valid, u not NULL): Ja, Jb and the accelerations a
 * (to rounding those of sr_accel) at once, for the step Jacobians; outputs not tested for
 * finiteness.  c/sr_jacobians.c. */
int sr_internal_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                               sr_real a[SR_NV], sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU]);

/* The accelerations' derivative along given directions, for the step Jacobians' stages: out = Ja V
 * (5 x SR_J_NC) for V the derivatives of the error's rows that the dynamics reads (SR_J_READ rows:
 * xi_S, th_Y, th_P, nu; nothing depends on q) along SR_J_NC directions; also Jb and the
 * accelerations a, as sr_internal_accel_jacobian.  For the paper's robot Ja is never formed: the
 * yoke frame's chain rule acts on V (c/sr_jacobians.c). */
enum { SR_J_XI = 0, SR_J_TH_Y = 3, SR_J_TH_P = 4, SR_J_NU = 5, SR_J_READ = 10, SR_J_NC = 12 };
int sr_internal_accel_jacobian_along(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                     const sr_real V[SR_J_READ][SR_J_NC], sr_real a[SR_NV],
                                     sr_real out[SR_NV][SR_J_NC], sr_real Jb[SR_NV * SR_NU]);

/* The stages of RKMK4 from K[0] = f(x) (filled by the caller): K[1..3] and the final Theta;
 * out = x . exp(Theta) (out must not alias x). */
int sr_internal_rkmk4_core(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                           sr_real K[4][SR_NT], sr_real theta[SR_NT], sr_real *comp, sr_real out[SR_NX],
                           long *evaluations);

/* k = dexp^{-1}_{-th}(f) (k may alias f). */
void sr_internal_dexpinv(const sr_real th[SR_NT], const sr_real f[SR_NT], sr_real k[SR_NT]);

/* The optional correction of SR_PROJECT: one Newton-Schulz step R <- R (3I - R^T R)/2 towards
 * the nearest rotation for R_S, the same on the (cos, sin) pair of R_Y and R_P. */
void sr_internal_project(sr_real x[SR_NX]);

#endif /* SR_INTERNAL_H */
