/*
 * sr_step_lanes.c -- the steppers of sr_steppers.c in lanes form, for sr_step_batch
 * (c/sr_step_batch.c, issue 21): loops over the states of a block, one lane per state, without
 * branches or inner loops, that the compiler vectorises across the states from plain C99 (at -O3;
 * SR_LANES_CLONES adds AVX2).  Each computes the same expressions in the same order as the scalar
 * code, so a lane's result is the scalar step's bit for bit wherever the scalar code takes the
 * series branches; ok[i] is cleared where it does not (an angle of 1/4 rad or more, |th_S| >= 1/4 rad
 * for dexp^-1) or where a result's sum is not finite, and sr_step_batch hands that state to sr_step.
 *
 * Strides are arguments (GCC 12 vectorises strided loads with a variable stride, not with a
 * constant 35), and these functions live in a file of their own: in the file of their caller,
 * GCC propagated the caller's constant strides into them and did not vectorise them.
 * Hand-written C99.
 */
#include "sr_internal.h"

/* sin(t)/t and (1 - cos t)/t^2 by the series of sr_internal.h, whose range the caller tests. */
#define SINC(t2) sinc_series(t2)
#define COSC(t2) cosc_series(t2)

/* The Lie-Euler step x . exp(dt f(x)) of sr_steppers.c (sr_internal_vector_field, then
 * `advance` with one exponential and no compensation) on n states whose accelerations a are
 * given, one lane per state.  The same expressions in the same order as the scalar code, so a
 * lane's result is sr_step's bit for bit where the scalar code takes the series branches: ok[i]
 * is cleared where an angle is beyond them (|t| >= 1/4 rad, where sr_step uses sin and cos) or
 * the result's sum is not finite, and that state is left to sr_step.  Strides are arguments (GCC
 * 12 vectorises strided loads with a variable stride, not with a constant 35). */
SR_LANES_CLONES void sr_internal_lie_euler_lanes(sr_real r, long n, const sr_real *restrict x, long x_stride,
                                                 const sr_real *restrict a, long a_stride, sr_real dt,
                                                 sr_real *restrict out, long out_stride, sr_real *restrict ok)
{
    long i;
/* Lane i's entries, indexed as in the generated lanes kernels (what GCC vectorises). */
#define R(k) x[x_stride * i + SR_X_R_S + (k)]
#define Y(k) x[x_stride * i + SR_X_R_Y + (k)]
#define P(k) x[x_stride * i + SR_X_R_P + (k)]
#define q(k) x[x_stride * i + SR_X_q + (k)]
#define w(k) x[x_stride * i + SR_X_w_S + (k)]
#define gam(k) x[x_stride * i + SR_X_R_S + 6 + (k)]
#define acc(k) a[a_stride * i + (k)]
#define o(k) out[out_stride * i + (k)]
    for (i = 0; i < n; ++i) {
        sr_real v0, v1, v2, t0, t1, t2, x2, y2, z2, th2, A, B, D0, D1, D2, D3, D4, D5, D6, D7, D8;
        sr_real angle, a2, sn, cm1, dc, ds, sum;
        sr_real good = 1;
        /* No inner loops and no branches below: GCC 12 vectorises the lane loop only then. */
        /* the vector field's q' (sr_internal_vector_field), times dt */
        v0 = w(1) * gam(2) - w(2) * gam(1);
        v1 = w(2) * gam(0) - w(0) * gam(2);
        v2 = w(0) * gam(1) - w(1) * gam(0);
        /* R_S Exp(dt w_S) = R_S + R_S D, D = Exp - I (so3_exp_minus_identity, series branch;
         * matmul3, then the additions of `advance`) */
        t0 = dt * w(0);
        t1 = dt * w(1);
        t2 = dt * w(2);
        x2 = t0 * t0;
        y2 = t1 * t1;
        z2 = t2 * t2;
        th2 = x2 + y2 + z2;
        good = th2 < SR_SERIES_T2 ? good : 0;
        A = SINC(th2);
        B = COSC(th2);
        D0 = -B * (y2 + z2);
        D4 = -B * (x2 + z2);
        D8 = -B * (x2 + y2);
        D1 = B * t0 * t1 - A * t2;
        D3 = B * t0 * t1 + A * t2;
        D2 = B * t0 * t2 + A * t1;
        D6 = B * t0 * t2 - A * t1;
        D5 = B * t1 * t2 - A * t0;
        D7 = B * t1 * t2 + A * t0;
#define ROW(j)                                                                                      \
        o(SR_X_R_S + 3 * (j) + 0) = R(3 * (j)) + (R(3 * (j)) * D0 + R(3 * (j) + 1) * D3 + R(3 * (j) + 2) * D6); \
        o(SR_X_R_S + 3 * (j) + 1) = R(3 * (j) + 1) + (R(3 * (j)) * D1 + R(3 * (j) + 1) * D4 + R(3 * (j) + 2) * D7); \
        o(SR_X_R_S + 3 * (j) + 2) = R(3 * (j) + 2) + (R(3 * (j)) * D2 + R(3 * (j) + 1) * D5 + R(3 * (j) + 2) * D8);
        ROW(0)
        ROW(1)
        ROW(2)
#undef ROW
        /* R_Y Exp(dt w_Y Sigma_Y): only (c, s) = (R_Y[4], R_Y[7]) change (advance_axis); the
         * exact zeros and ones are copied */
        angle = dt * w(3) + (sr_real)0;
        a2 = angle * angle;
        good = a2 < SR_SERIES_T2 ? good : 0;
        sn = angle * SINC(a2);
        cm1 = -a2 * COSC(a2);
        dc = Y(4) * cm1 - Y(7) * sn;
        ds = Y(7) * cm1 + Y(4) * sn;
        o(SR_X_R_Y + 0) = Y(0);
        o(SR_X_R_Y + 1) = Y(1);
        o(SR_X_R_Y + 2) = Y(2);
        o(SR_X_R_Y + 3) = Y(3);
        o(SR_X_R_Y + 4) = Y(4) + dc;
        o(SR_X_R_Y + 5) = Y(5) + -ds;
        o(SR_X_R_Y + 6) = Y(6);
        o(SR_X_R_Y + 7) = Y(7) + ds;
        o(SR_X_R_Y + 8) = Y(8) + dc;
        /* R_P Exp(dt w_P Sigma_P): (c, s) = (R_P[0], R_P[2]) */
        angle = dt * w(4) + (sr_real)0;
        a2 = angle * angle;
        good = a2 < SR_SERIES_T2 ? good : 0;
        sn = angle * SINC(a2);
        cm1 = -a2 * COSC(a2);
        dc = P(0) * cm1 - P(2) * sn;
        ds = P(2) * cm1 + P(0) * sn;
        o(SR_X_R_P + 0) = P(0) + dc;
        o(SR_X_R_P + 1) = P(1);
        o(SR_X_R_P + 2) = P(2) + ds;
        o(SR_X_R_P + 3) = P(3);
        o(SR_X_R_P + 4) = P(4);
        o(SR_X_R_P + 5) = P(5);
        o(SR_X_R_P + 6) = P(6) + -ds;
        o(SR_X_R_P + 7) = P(7);
        o(SR_X_R_P + 8) = P(8) + dc;
        /* q + dt q' (q'_z = 0), nu + dt nu' */
        o(SR_X_q + 0) = q(0) + (dt * (r * (R(0) * v0 + R(1) * v1 + R(2) * v2)) + (sr_real)0);
        o(SR_X_q + 1) = q(1) + (dt * (r * (R(3) * v0 + R(4) * v1 + R(5) * v2)) + (sr_real)0);
        o(SR_X_q + 2) = q(2) + (dt * (sr_real)0 + (sr_real)0);
        o(SR_X_w_S + 0) = w(0) + (dt * acc(0) + (sr_real)0);
        o(SR_X_w_S + 1) = w(1) + (dt * acc(1) + (sr_real)0);
        o(SR_X_w_S + 2) = w(2) + (dt * acc(2) + (sr_real)0);
        o(SR_X_w_Y) = w(3) + (dt * acc(3) + (sr_real)0);
        o(SR_X_w_P) = w(4) + (dt * acc(4) + (sr_real)0);
        /* deliver's test: every output finite (the unchanged entries were checked by the lanes of
         * the state check, and a non-finite one would have made the accelerations so) */
        sum = (o(0) + o(1) + o(2)) + (o(3) + o(4) + o(5)) + (o(6) + o(7) + o(8)) + (o(SR_X_R_Y + 4) + o(SR_X_R_Y + 7))
            + (o(SR_X_R_P + 0) + o(SR_X_R_P + 2)) + (o(SR_X_q + 0) + o(SR_X_q + 1) + o(SR_X_q + 2))
            + (o(SR_X_w_S + 0) + o(SR_X_w_S + 1) + o(SR_X_w_S + 2) + o(SR_X_w_Y) + o(SR_X_w_P));
        ok[i] = SR_GEN_LANE_FINITE(sum) ? good : 0;
    }
#undef R
#undef Y
#undef P
#undef q
#undef w
#undef gam
#undef acc
#undef o
}

/* ---- the pieces of the fourth-order steps ---------------------------------------------------- */

/* D = Exp([[t]]) - I by the series (so3_exp_minus_identity), in the variables D0..D8; clears
 * good when |t|^2 is past the series' range. */
#define EXP_MINUS_I(t0, t1, t2, D0, D1, D2, D3, D4, D5, D6, D7, D8, good)  \
    do {                                                                   \
        const sr_real x2_ = (t0) * (t0), y2_ = (t1) * (t1), z2_ = (t2) * (t2); \
        const sr_real th2_ = x2_ + y2_ + z2_;                              \
        const sr_real A_ = SINC(th2_), B_ = COSC(th2_);                    \
        good = th2_ < SR_SERIES_T2 ? good : 0;                             \
        D0 = -B_ * (y2_ + z2_);                                            \
        D4 = -B_ * (x2_ + z2_);                                            \
        D8 = -B_ * (x2_ + y2_);                                            \
        D1 = B_ * (t0) * (t1) - A_ * (t2);                                 \
        D3 = B_ * (t0) * (t1) + A_ * (t2);                                 \
        D2 = B_ * (t0) * (t2) + A_ * (t1);                                 \
        D6 = B_ * (t0) * (t2) - A_ * (t1);                                 \
        D5 = B_ * (t1) * (t2) - A_ * (t0);                                 \
        D7 = B_ * (t1) * (t2) + A_ * (t0);                                 \
    } while (0)

/* out = x . exp(th) (`act` of sr_steppers.c: `advance` with one exponential, no compensation) on
 * n states; ok[i] is cleared where an angle is past the series (|t| >= 1/4 rad) or the result's
 * sum is not finite, and kept otherwise. */
SR_LANES_CLONES void sr_internal_act_lanes(long n, const sr_real *restrict x, long x_stride, const sr_real *restrict th,
                                           long th_stride, sr_real *restrict out, long out_stride, sr_real *restrict ok)
{
    long i;
#define X(k) x[x_stride * i + (k)]
#define T(k) th[th_stride * i + (k)]
#define O(k) out[out_stride * i + (k)]
    for (i = 0; i < n; ++i) {
        const sr_real t0 = T(SR_T_S), t1 = T(SR_T_S + 1), t2 = T(SR_T_S + 2);
        sr_real D0, D1, D2, D3, D4, D5, D6, D7, D8, angle, a2, sn, cm1, dc, ds, sum;
        sr_real good = 1;
        /* Every entry is read once, into a name (repeated reads of one entry kept GCC 12 from
         * vectorising the loop). */
        EXP_MINUS_I(t0, t1, t2, D0, D1, D2, D3, D4, D5, D6, D7, D8, good);
#define ROW(j)                                                                                                  \
        O(SR_X_R_S + 3 * (j) + 0) = X(3 * (j)) + (X(3 * (j)) * D0 + X(3 * (j) + 1) * D3 + X(3 * (j) + 2) * D6);     \
        O(SR_X_R_S + 3 * (j) + 1) = X(3 * (j) + 1) + (X(3 * (j)) * D1 + X(3 * (j) + 1) * D4 + X(3 * (j) + 2) * D7); \
        O(SR_X_R_S + 3 * (j) + 2) = X(3 * (j) + 2) + (X(3 * (j)) * D2 + X(3 * (j) + 1) * D5 + X(3 * (j) + 2) * D8);
        ROW(0)
        ROW(1)
        ROW(2)
#undef ROW
        angle = T(SR_T_Y) + (sr_real)0;
        a2 = angle * angle;
        good = a2 < SR_SERIES_T2 ? good : 0;
        sn = angle * SINC(a2);
        cm1 = -a2 * COSC(a2);
        dc = X(SR_X_R_Y + 4) * cm1 - X(SR_X_R_Y + 7) * sn;
        ds = X(SR_X_R_Y + 7) * cm1 + X(SR_X_R_Y + 4) * sn;
        O(SR_X_R_Y + 0) = X(SR_X_R_Y + 0);
        O(SR_X_R_Y + 1) = X(SR_X_R_Y + 1);
        O(SR_X_R_Y + 2) = X(SR_X_R_Y + 2);
        O(SR_X_R_Y + 3) = X(SR_X_R_Y + 3);
        O(SR_X_R_Y + 4) = X(SR_X_R_Y + 4) + dc;
        O(SR_X_R_Y + 5) = X(SR_X_R_Y + 5) + -ds;
        O(SR_X_R_Y + 6) = X(SR_X_R_Y + 6);
        O(SR_X_R_Y + 7) = X(SR_X_R_Y + 7) + ds;
        O(SR_X_R_Y + 8) = X(SR_X_R_Y + 8) + dc;
        angle = T(SR_T_P) + (sr_real)0;
        a2 = angle * angle;
        good = a2 < SR_SERIES_T2 ? good : 0;
        sn = angle * SINC(a2);
        cm1 = -a2 * COSC(a2);
        dc = X(SR_X_R_P + 0) * cm1 - X(SR_X_R_P + 2) * sn;
        ds = X(SR_X_R_P + 2) * cm1 + X(SR_X_R_P + 0) * sn;
        O(SR_X_R_P + 0) = X(SR_X_R_P + 0) + dc;
        O(SR_X_R_P + 1) = X(SR_X_R_P + 1);
        O(SR_X_R_P + 2) = X(SR_X_R_P + 2) + ds;
        O(SR_X_R_P + 3) = X(SR_X_R_P + 3);
        O(SR_X_R_P + 4) = X(SR_X_R_P + 4);
        O(SR_X_R_P + 5) = X(SR_X_R_P + 5);
        O(SR_X_R_P + 6) = X(SR_X_R_P + 6) + -ds;
        O(SR_X_R_P + 7) = X(SR_X_R_P + 7);
        O(SR_X_R_P + 8) = X(SR_X_R_P + 8) + dc;
        O(SR_X_q + 0) = X(SR_X_q + 0) + (T(SR_T_Q + 0) + (sr_real)0);
        O(SR_X_q + 1) = X(SR_X_q + 1) + (T(SR_T_Q + 1) + (sr_real)0);
        O(SR_X_q + 2) = X(SR_X_q + 2) + (T(SR_T_Q + 2) + (sr_real)0);
        O(SR_X_w_S + 0) = X(SR_X_w_S + 0) + (T(SR_T_V + 0) + (sr_real)0);
        O(SR_X_w_S + 1) = X(SR_X_w_S + 1) + (T(SR_T_V + 1) + (sr_real)0);
        O(SR_X_w_S + 2) = X(SR_X_w_S + 2) + (T(SR_T_V + 2) + (sr_real)0);
        O(SR_X_w_Y) = X(SR_X_w_Y) + (T(SR_T_V + 3) + (sr_real)0);
        O(SR_X_w_P) = X(SR_X_w_P) + (T(SR_T_V + 4) + (sr_real)0);
        sum = (O(0) + O(1) + O(2)) + (O(3) + O(4) + O(5)) + (O(6) + O(7) + O(8)) + (O(SR_X_R_Y + 4) + O(SR_X_R_Y + 7))
            + (O(SR_X_R_P + 0) + O(SR_X_R_P + 2)) + (O(SR_X_q + 0) + O(SR_X_q + 1) + O(SR_X_q + 2))
            + (O(SR_X_w_S + 0) + O(SR_X_w_S + 1) + O(SR_X_w_S + 2) + O(SR_X_w_Y) + O(SR_X_w_P));
        ok[i] = SR_GEN_LANE_FINITE(sum) ? (good != 0 ? ok[i] : 0) : 0;
    }
#undef X
#undef T
#undef O
}

/* out = x . exp(th1) . exp(th2) as one increment (`advance` of sr_steppers.c with two
 * exponentials: D = D1 + D2 + D1 D2, the angles and vectors added), the last update of CF4; ok as
 * in sr_internal_act_lanes. */
SR_LANES_CLONES void sr_internal_act2_lanes(long n, const sr_real *restrict x, long x_stride, const sr_real *restrict th1,
                                            const sr_real *restrict th2, long th_stride, sr_real *restrict out,
                                            long out_stride, sr_real *restrict ok)
{
    long i;
#define X(k) x[x_stride * i + (k)]
#define T(k) th1[th_stride * i + (k)]
#define U(k) th2[th_stride * i + (k)]
#define O(k) out[out_stride * i + (k)]
    for (i = 0; i < n; ++i) {
        sr_real a0, a1, a2, a3, a4, a5, a6, a7, a8, b0, b1, b2, b3, b4, b5, b6, b7, b8;
        sr_real D0, D1, D2, D3, D4, D5, D6, D7, D8, angle, t2, sn, cm1, dc, ds, sum;
        sr_real good = 1;
        EXP_MINUS_I(T(SR_T_S), T(SR_T_S + 1), T(SR_T_S + 2), a0, a1, a2, a3, a4, a5, a6, a7, a8, good);
        EXP_MINUS_I(U(SR_T_S), U(SR_T_S + 1), U(SR_T_S + 2), b0, b1, b2, b3, b4, b5, b6, b7, b8, good);
        /* D = D1 + D2 + D1 D2 (matmul3, then the sum in `advance`'s order) */
        D0 = a0 + b0 + (a0 * b0 + a1 * b3 + a2 * b6);
        D1 = a1 + b1 + (a0 * b1 + a1 * b4 + a2 * b7);
        D2 = a2 + b2 + (a0 * b2 + a1 * b5 + a2 * b8);
        D3 = a3 + b3 + (a3 * b0 + a4 * b3 + a5 * b6);
        D4 = a4 + b4 + (a3 * b1 + a4 * b4 + a5 * b7);
        D5 = a5 + b5 + (a3 * b2 + a4 * b5 + a5 * b8);
        D6 = a6 + b6 + (a6 * b0 + a7 * b3 + a8 * b6);
        D7 = a7 + b7 + (a6 * b1 + a7 * b4 + a8 * b7);
        D8 = a8 + b8 + (a6 * b2 + a7 * b5 + a8 * b8);
#define ROW(j)                                                                                                  \
        O(SR_X_R_S + 3 * (j) + 0) = X(3 * (j)) + (X(3 * (j)) * D0 + X(3 * (j) + 1) * D3 + X(3 * (j) + 2) * D6);     \
        O(SR_X_R_S + 3 * (j) + 1) = X(3 * (j) + 1) + (X(3 * (j)) * D1 + X(3 * (j) + 1) * D4 + X(3 * (j) + 2) * D7); \
        O(SR_X_R_S + 3 * (j) + 2) = X(3 * (j) + 2) + (X(3 * (j)) * D2 + X(3 * (j) + 1) * D5 + X(3 * (j) + 2) * D8);
        ROW(0)
        ROW(1)
        ROW(2)
#undef ROW
        angle = T(SR_T_Y) + U(SR_T_Y);
        t2 = angle * angle;
        good = t2 < SR_SERIES_T2 ? good : 0;
        sn = angle * SINC(t2);
        cm1 = -t2 * COSC(t2);
        dc = X(SR_X_R_Y + 4) * cm1 - X(SR_X_R_Y + 7) * sn;
        ds = X(SR_X_R_Y + 7) * cm1 + X(SR_X_R_Y + 4) * sn;
        O(SR_X_R_Y + 0) = X(SR_X_R_Y + 0);
        O(SR_X_R_Y + 1) = X(SR_X_R_Y + 1);
        O(SR_X_R_Y + 2) = X(SR_X_R_Y + 2);
        O(SR_X_R_Y + 3) = X(SR_X_R_Y + 3);
        O(SR_X_R_Y + 4) = X(SR_X_R_Y + 4) + dc;
        O(SR_X_R_Y + 5) = X(SR_X_R_Y + 5) + -ds;
        O(SR_X_R_Y + 6) = X(SR_X_R_Y + 6);
        O(SR_X_R_Y + 7) = X(SR_X_R_Y + 7) + ds;
        O(SR_X_R_Y + 8) = X(SR_X_R_Y + 8) + dc;
        angle = T(SR_T_P) + U(SR_T_P);
        t2 = angle * angle;
        good = t2 < SR_SERIES_T2 ? good : 0;
        sn = angle * SINC(t2);
        cm1 = -t2 * COSC(t2);
        dc = X(SR_X_R_P + 0) * cm1 - X(SR_X_R_P + 2) * sn;
        ds = X(SR_X_R_P + 2) * cm1 + X(SR_X_R_P + 0) * sn;
        O(SR_X_R_P + 0) = X(SR_X_R_P + 0) + dc;
        O(SR_X_R_P + 1) = X(SR_X_R_P + 1);
        O(SR_X_R_P + 2) = X(SR_X_R_P + 2) + ds;
        O(SR_X_R_P + 3) = X(SR_X_R_P + 3);
        O(SR_X_R_P + 4) = X(SR_X_R_P + 4);
        O(SR_X_R_P + 5) = X(SR_X_R_P + 5);
        O(SR_X_R_P + 6) = X(SR_X_R_P + 6) + -ds;
        O(SR_X_R_P + 7) = X(SR_X_R_P + 7);
        O(SR_X_R_P + 8) = X(SR_X_R_P + 8) + dc;
        O(SR_X_q + 0) = X(SR_X_q + 0) + (T(SR_T_Q + 0) + U(SR_T_Q + 0));
        O(SR_X_q + 1) = X(SR_X_q + 1) + (T(SR_T_Q + 1) + U(SR_T_Q + 1));
        O(SR_X_q + 2) = X(SR_X_q + 2) + (T(SR_T_Q + 2) + U(SR_T_Q + 2));
        O(SR_X_w_S + 0) = X(SR_X_w_S + 0) + (T(SR_T_V + 0) + U(SR_T_V + 0));
        O(SR_X_w_S + 1) = X(SR_X_w_S + 1) + (T(SR_T_V + 1) + U(SR_T_V + 1));
        O(SR_X_w_S + 2) = X(SR_X_w_S + 2) + (T(SR_T_V + 2) + U(SR_T_V + 2));
        O(SR_X_w_Y) = X(SR_X_w_Y) + (T(SR_T_V + 3) + U(SR_T_V + 3));
        O(SR_X_w_P) = X(SR_X_w_P) + (T(SR_T_V + 4) + U(SR_T_V + 4));
        sum = (O(0) + O(1) + O(2)) + (O(3) + O(4) + O(5)) + (O(6) + O(7) + O(8)) + (O(SR_X_R_Y + 4) + O(SR_X_R_Y + 7))
            + (O(SR_X_R_P + 0) + O(SR_X_R_P + 2)) + (O(SR_X_q + 0) + O(SR_X_q + 1) + O(SR_X_q + 2))
            + (O(SR_X_w_S + 0) + O(SR_X_w_S + 1) + O(SR_X_w_S + 2) + O(SR_X_w_Y) + O(SR_X_w_P));
        ok[i] = SR_GEN_LANE_FINITE(sum) ? (good != 0 ? ok[i] : 0) : 0;
    }
#undef X
#undef T
#undef U
#undef O
}

/* f = the vector field at the states y (sr_internal_vector_field) whose accelerations a are
 * given; then, if th is not NULL, k = dexp^-1_{-th}(f) in place (sr_internal_dexpinv, its series
 * branch: ok[i] cleared where |th_S| >= 1/4 rad, kept otherwise). */
SR_LANES_CLONES void sr_internal_field_lanes(sr_real r, long n, const sr_real *restrict y, long y_stride,
                                             const sr_real *restrict a, long a_stride, const sr_real *restrict th,
                                             long th_stride, sr_real *restrict f, long f_stride, sr_real *restrict ok)
{
    long i;
#define Y(k) y[y_stride * i + (k)]
#define A(k) a[a_stride * i + (k)]
#define T(k) th[th_stride * i + (k)]
#define F(k) f[f_stride * i + (k)]
    for (i = 0; i < n; ++i) {
        const sr_real w0 = Y(SR_X_w_S), w1 = Y(SR_X_w_S + 1), w2 = Y(SR_X_w_S + 2);
        const sr_real v0 = w1 * Y(8) - w2 * Y(7), v1 = w2 * Y(6) - w0 * Y(8), v2 = w0 * Y(7) - w1 * Y(6);
        F(SR_T_S + 0) = w0;
        F(SR_T_S + 1) = w1;
        F(SR_T_S + 2) = w2;
        F(SR_T_Y) = Y(SR_X_w_Y);
        F(SR_T_P) = Y(SR_X_w_P);
        F(SR_T_Q + 0) = r * (Y(0) * v0 + Y(1) * v1 + Y(2) * v2);
        F(SR_T_Q + 1) = r * (Y(3) * v0 + Y(4) * v1 + Y(5) * v2);
        F(SR_T_Q + 2) = 0;
        F(SR_T_V + 0) = A(0);
        F(SR_T_V + 1) = A(1);
        F(SR_T_V + 2) = A(2);
        F(SR_T_V + 3) = A(3);
        F(SR_T_V + 4) = A(4);
    }
    if (th)
    for (i = 0; i < n; ++i) {
        const sr_real t0 = T(SR_T_S), t1 = T(SR_T_S + 1), t2 = T(SR_T_S + 2);
        const sr_real s2 = t0 * t0 + t1 * t1 + t2 * t2;
        const sr_real c = dexpinv_series(s2);
        const sr_real u0 = F(SR_T_S), u1 = F(SR_T_S + 1), u2 = F(SR_T_S + 2);
        const sr_real a0 = t1 * u2 - t2 * u1, a1 = t2 * u0 - t0 * u2, a2 = t0 * u1 - t1 * u0;
        const sr_real b0 = t1 * a2 - t2 * a1, b1 = t2 * a0 - t0 * a2, b2 = t0 * a1 - t1 * a0;
        F(SR_T_S + 0) = u0 + SR_C(0.5) * a0 + c * b0;
        F(SR_T_S + 1) = u1 + SR_C(0.5) * a1 + c * b1;
        F(SR_T_S + 2) = u2 + SR_C(0.5) * a2 + c * b2;
        ok[i] = s2 < SR_SERIES_T2 ? ok[i] : 0;
    }
#undef Y
#undef A
#undef T
#undef F
}

