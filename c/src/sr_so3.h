/*
 * sr_so3.h -- SO(3): the Taylor series of Rodrigues' and dexp^-1's
 * coefficients, Exp - I, the one-axis rotations, Log and the right Jacobian.
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_SO3_H
#define SR_SO3_H

#include "sr_math.h"

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
 * more (its first omitted, 7 c_7 s^6, below 1e-16 of dc).  The series reach that far so that RKMK4
 * stages at 10-25 rad/s with dt = 0.01 s need no sin, cos and division, a branch the vectorised
 * batch step (sr_step_lanes.c) cannot take. */
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

#endif /* SR_SO3_H */
