/*
 * sr_step_lanes.c -- the steppers of sr_steppers.c in lanes form, for sr_step_batch
 * (sr_step_batch.c): loops over the states of a block, one lane per state, without
 * branches or inner loops, that the compiler vectorises across the states from plain C99 (at -O3;
 * SR_LANES_CLONES adds AVX2).  Each computes the same expressions in the same order as the scalar
 * code, so a lane's result is the scalar step's bit for bit wherever the scalar code takes the
 * series branches; ok[i] = 0 where it does not (an angle of 1/4 rad or more, for dexp^-1 too) or
 * where a result's sum is not finite, else 1, and sr_step_batch hands a state with a 0 to sr_step.
 *
 * Strides are arguments (GCC 12 vectorises strided loads with a variable stride, not with a
 * constant 35), and these functions live in a file of their own: in the file of their caller,
 * GCC propagated the caller's constant strides into them and did not vectorise them.
 * Hand-written C99.
 */
#include "sr_finite.h"
#include "sr_lanes.h"
#include "sr_so3.h"
#include "sr_steppers.h"

/* sin(t)/t and (1 - cos t)/t^2 by the series of sr_so3.h, whose range the caller tests. */
#define SINC(t2) sinc_series(t2)
#define COSC(t2) cosc_series(t2)

/* The pieces of `advance` (sr_steppers.c) that every stepper ends with, for lane i of x (the state,
 * X(k)) into out (O(k)); each function below defines X and O.  No inner loops and no branches:
 * GCC 12 vectorises a lane loop only then. */

/* D = Exp([[t]]) - I by the series (so3_exp_minus_identity), into D0..D8; clears good when |t|^2
 * is past the series' range. */
#define EXP_MINUS_I(t0, t1, t2, D0, D1, D2, D3, D4, D5, D6, D7, D8, good)    \
    do {                                                                     \
        const sr_real u0_ = (t0), u1_ = (t1), u2_ = (t2);                    \
        const sr_real x2_ = u0_ * u0_, y2_ = u1_ * u1_, z2_ = u2_ * u2_;     \
        const sr_real th2_ = x2_ + y2_ + z2_;                                \
        const sr_real A_ = SINC(th2_), B_ = COSC(th2_);                      \
        good = th2_ < SR_SERIES_T2 ? good : 0;                               \
        D0 = -B_ * (y2_ + z2_);                                              \
        D4 = -B_ * (x2_ + z2_);                                              \
        D8 = -B_ * (x2_ + y2_);                                              \
        D1 = B_ * u0_ * u1_ - A_ * u2_;                                      \
        D3 = B_ * u0_ * u1_ + A_ * u2_;                                      \
        D2 = B_ * u0_ * u2_ + A_ * u1_;                                      \
        D6 = B_ * u0_ * u2_ - A_ * u1_;                                      \
        D5 = B_ * u1_ * u2_ - A_ * u0_;                                      \
        D7 = B_ * u1_ * u2_ + A_ * u0_;                                      \
    } while (0)

/* R_S + R_S D (matmul3, then the additions of `advance`), row j */
#define R_S_ROW(j, D0, D1, D2, D3, D4, D5, D6, D7, D8)                                                              \
    O(SR_X_R_S + 3 * (j) + 0) = X(3 * (j)) + (X(3 * (j)) * D0 + X(3 * (j) + 1) * D3 + X(3 * (j) + 2) * D6);     \
    O(SR_X_R_S + 3 * (j) + 1) = X(3 * (j) + 1) + (X(3 * (j)) * D1 + X(3 * (j) + 1) * D4 + X(3 * (j) + 2) * D7); \
    O(SR_X_R_S + 3 * (j) + 2) = X(3 * (j) + 2) + (X(3 * (j)) * D2 + X(3 * (j) + 1) * D5 + X(3 * (j) + 2) * D8)
#define R_S_TIMES_EXP(D0, D1, D2, D3, D4, D5, D6, D7, D8)   \
    do {                                                    \
        R_S_ROW(0, D0, D1, D2, D3, D4, D5, D6, D7, D8);     \
        R_S_ROW(1, D0, D1, D2, D3, D4, D5, D6, D7, D8);     \
        R_S_ROW(2, D0, D1, D2, D3, D4, D5, D6, D7, D8);     \
    } while (0)

/* The one-axis rotations times Exp(angle [[e_k]]) (advance_axis): only (c, s) change, in two
 * places each, and the exact zeros and ones are copied; clears good past the series.  R_Y is
 * [1 0 0; 0 c -s; 0 s c], R_P is [c 0 s; 0 1 0; -s 0 c]. */
#define AXIS_INCREMENT(c, s, angle, dc, ds, good)                      \
    do {                                                               \
        const sr_real t_ = (angle), t2_ = t_ * t_;                     \
        const sr_real sn_ = t_ * SINC(t2_), cm1_ = -t2_ * COSC(t2_);   \
        good = t2_ < SR_SERIES_T2 ? good : 0;                          \
        dc = (c) * cm1_ - (s) * sn_;                                   \
        ds = (s) * cm1_ + (c) * sn_;                                   \
    } while (0)
#define AXIS_Y(angle, good)                                                        \
    do {                                                                           \
        sr_real dc_, ds_;                                                          \
        AXIS_INCREMENT(X(SR_X_R_Y + 4), X(SR_X_R_Y + 7), angle, dc_, ds_, good);   \
        O(SR_X_R_Y + 0) = X(SR_X_R_Y + 0);                                         \
        O(SR_X_R_Y + 1) = X(SR_X_R_Y + 1);                                         \
        O(SR_X_R_Y + 2) = X(SR_X_R_Y + 2);                                         \
        O(SR_X_R_Y + 3) = X(SR_X_R_Y + 3);                                         \
        O(SR_X_R_Y + 4) = X(SR_X_R_Y + 4) + dc_;                                   \
        O(SR_X_R_Y + 5) = X(SR_X_R_Y + 5) + -ds_;                                  \
        O(SR_X_R_Y + 6) = X(SR_X_R_Y + 6);                                         \
        O(SR_X_R_Y + 7) = X(SR_X_R_Y + 7) + ds_;                                   \
        O(SR_X_R_Y + 8) = X(SR_X_R_Y + 8) + dc_;                                   \
    } while (0)
#define AXIS_P(angle, good)                                                        \
    do {                                                                           \
        sr_real dc_, ds_;                                                          \
        AXIS_INCREMENT(X(SR_X_R_P + 0), X(SR_X_R_P + 2), angle, dc_, ds_, good);   \
        O(SR_X_R_P + 0) = X(SR_X_R_P + 0) + dc_;                                   \
        O(SR_X_R_P + 1) = X(SR_X_R_P + 1);                                         \
        O(SR_X_R_P + 2) = X(SR_X_R_P + 2) + ds_;                                   \
        O(SR_X_R_P + 3) = X(SR_X_R_P + 3);                                         \
        O(SR_X_R_P + 4) = X(SR_X_R_P + 4);                                         \
        O(SR_X_R_P + 5) = X(SR_X_R_P + 5);                                         \
        O(SR_X_R_P + 6) = X(SR_X_R_P + 6) + -ds_;                                  \
        O(SR_X_R_P + 7) = X(SR_X_R_P + 7);                                         \
        O(SR_X_R_P + 8) = X(SR_X_R_P + 8) + dc_;                                   \
    } while (0)

/* q + dq and nu + dnu, the vector parts of `advance` (d = th1 + th2, or th + 0) */
#define VECTORS(d)                                                  \
    do {                                                            \
        O(SR_X_q + 0) = X(SR_X_q + 0) + (d(SR_T_Q + 0));            \
        O(SR_X_q + 1) = X(SR_X_q + 1) + (d(SR_T_Q + 1));            \
        O(SR_X_q + 2) = X(SR_X_q + 2) + (d(SR_T_Q + 2));            \
        O(SR_X_w_S + 0) = X(SR_X_w_S + 0) + (d(SR_T_V + 0));        \
        O(SR_X_w_S + 1) = X(SR_X_w_S + 1) + (d(SR_T_V + 1));        \
        O(SR_X_w_S + 2) = X(SR_X_w_S + 2) + (d(SR_T_V + 2));        \
        O(SR_X_w_Y) = X(SR_X_w_Y) + (d(SR_T_V + 3));                \
        O(SR_X_w_P) = X(SR_X_w_P) + (d(SR_T_V + 4));                \
    } while (0)

/* deliver's test: ok[i] = 1 where every entry that changed is finite (the others were checked by
 * the lanes of the state check) and good holds, else 0.  Written, never read: with ok[i] read as
 * well, GCC 12 did not vectorise the loop. */
#define KEEP_IF_FINITE(good)                                                                                  \
    ok[i] = SR_GEN_LANE_FINITE((O(0) + O(1) + O(2)) + (O(3) + O(4) + O(5)) + (O(6) + O(7) + O(8))                \
                               + (O(SR_X_R_Y + 4) + O(SR_X_R_Y + 7)) + (O(SR_X_R_P + 0) + O(SR_X_R_P + 2))      \
                               + (O(SR_X_q + 0) + O(SR_X_q + 1) + O(SR_X_q + 2))                                \
                               + (O(SR_X_w_S + 0) + O(SR_X_w_S + 1) + O(SR_X_w_S + 2) + O(SR_X_w_Y) + O(SR_X_w_P))) \
                ? (good) : 0

/* The Lie-Euler step x . exp(dt f(x)) of sr_steppers.c (sr_internal_vector_field, then `advance`
 * with one exponential and no compensation) on n states whose accelerations a are given. */
SR_LANES_CLONES void sr_internal_lie_euler_lanes(sr_real r, long n, const sr_real *restrict x, long x_stride,
                                                 const sr_real *restrict a, long a_stride, sr_real dt,
                                                 sr_real *restrict out, long out_stride, sr_real *restrict ok)
{
    long i;
#define X(k) x[x_stride * i + (k)]
#define O(k) out[out_stride * i + (k)]
#define ACC(k) a[a_stride * i + (k)]
    for (i = 0; i < n; ++i) {
        /* the vector field's q' (sr_internal_vector_field), with gamma the third row of R_S */
        const sr_real v0 = X(SR_X_w_S + 1) * X(8) - X(SR_X_w_S + 2) * X(7);
        const sr_real v1 = X(SR_X_w_S + 2) * X(6) - X(SR_X_w_S + 0) * X(8);
        const sr_real v2 = X(SR_X_w_S + 0) * X(7) - X(SR_X_w_S + 1) * X(6);
        sr_real D0, D1, D2, D3, D4, D5, D6, D7, D8, good = 1;
        EXP_MINUS_I(dt * X(SR_X_w_S), dt * X(SR_X_w_S + 1), dt * X(SR_X_w_S + 2), D0, D1, D2, D3, D4, D5, D6, D7, D8,
                    good);
        R_S_TIMES_EXP(D0, D1, D2, D3, D4, D5, D6, D7, D8);
        AXIS_Y(dt * X(SR_X_w_Y) + (sr_real)0, good);
        AXIS_P(dt * X(SR_X_w_P) + (sr_real)0, good);
        O(SR_X_q + 0) = X(SR_X_q + 0) + (dt * (r * (X(0) * v0 + X(1) * v1 + X(2) * v2)) + (sr_real)0);
        O(SR_X_q + 1) = X(SR_X_q + 1) + (dt * (r * (X(3) * v0 + X(4) * v1 + X(5) * v2)) + (sr_real)0);
        O(SR_X_q + 2) = X(SR_X_q + 2) + (dt * (sr_real)0 + (sr_real)0);
        O(SR_X_w_S + 0) = X(SR_X_w_S + 0) + (dt * ACC(0) + (sr_real)0);
        O(SR_X_w_S + 1) = X(SR_X_w_S + 1) + (dt * ACC(1) + (sr_real)0);
        O(SR_X_w_S + 2) = X(SR_X_w_S + 2) + (dt * ACC(2) + (sr_real)0);
        O(SR_X_w_Y) = X(SR_X_w_Y) + (dt * ACC(3) + (sr_real)0);
        O(SR_X_w_P) = X(SR_X_w_P) + (dt * ACC(4) + (sr_real)0);
        KEEP_IF_FINITE(good);
    }
#undef X
#undef O
#undef ACC
}

/* ---- the pieces of the fourth-order steps ---------------------------------------------------- */

/* out = x . exp(th) (`act` of sr_steppers.c: `advance` with one exponential, no compensation) on
 * n states; ok as in the Lie-Euler step (1 where the lane is sr_step's, else 0). */
SR_LANES_CLONES void sr_internal_act_lanes(long n, const sr_real *restrict x, long x_stride, const sr_real *restrict th,
                                           long th_stride, sr_real *restrict out, long out_stride, sr_real *restrict ok)
{
    long i;
#define X(k) x[x_stride * i + (k)]
#define T(k) th[th_stride * i + (k)]
#define O(k) out[out_stride * i + (k)]
    for (i = 0; i < n; ++i) {
        sr_real D0, D1, D2, D3, D4, D5, D6, D7, D8, good = 1;
        EXP_MINUS_I(T(SR_T_S), T(SR_T_S + 1), T(SR_T_S + 2), D0, D1, D2, D3, D4, D5, D6, D7, D8, good);
        R_S_TIMES_EXP(D0, D1, D2, D3, D4, D5, D6, D7, D8);
        AXIS_Y(T(SR_T_Y) + (sr_real)0, good);
        AXIS_P(T(SR_T_P) + (sr_real)0, good);
#define D(k) T(k) + (sr_real)0
        VECTORS(D);
#undef D
        KEEP_IF_FINITE(good);
    }
#undef X
#undef T
#undef O
}

/* out = x . exp(th1) . exp(th2) as one increment (`advance` of sr_steppers.c with two
 * exponentials: D = D1 + D2 + D1 D2, the angles and vectors added), the last update of CF4; ok as
 * in the Lie-Euler step. */
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
        sr_real a0, a1, a2, a3, a4, a5, a6, a7, a8, b0, b1, b2, b3, b4, b5, b6, b7, b8, good = 1;
        sr_real D0, D1, D2, D3, D4, D5, D6, D7, D8;
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
        R_S_TIMES_EXP(D0, D1, D2, D3, D4, D5, D6, D7, D8);
        AXIS_Y(T(SR_T_Y) + U(SR_T_Y), good);
        AXIS_P(T(SR_T_P) + U(SR_T_P), good);
#define D(k) T(k) + U(k)
        VECTORS(D);
#undef D
        KEEP_IF_FINITE(good);
    }
#undef X
#undef T
#undef U
#undef O
}

/* f = the vector field at the states y (sr_internal_vector_field) whose accelerations a are
 * given; then, if th is not NULL, k = dexp^-1_{-th}(f) in place (sr_internal_dexpinv, its series
 * branch: ok[i] = 0 where |th_S| >= 1/4 rad, else 1; ok is not written without th). */
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
        ok[i] = s2 < SR_SERIES_T2 ? 1 : 0;
    }
#undef Y
#undef A
#undef T
#undef F
}

