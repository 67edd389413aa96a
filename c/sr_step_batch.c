/*
 * sr_step_batch.c -- one step of many states of one robot (issue 21): sr_step_batch.  The
 * paper's Lie-Euler step is vectorised across the states, like the batch accel (sr_kernels.c,
 * docs/sweeps.md): a block of 64 states at a time goes through loops without branches, one lane
 * per state, that the compiler vectorises from plain C99 (at -O3; SR_LANES_CLONES adds AVX2), and
 * any state those loops do not clear goes through sr_step itself.  So every row gets exactly the
 * bits and the status code that sr_step gives it alone, and the rows after a failing one are not
 * written.  The fourth-order methods, and a general robot, go row by row.
 * Hand-written C99; see spherical_robot.h for the contract.
 */
#include "sr_internal.h"

#include <stddef.h>

enum { BLOCK = 64 };

/* sin(t)/t and (1 - cos t)/t^2 by the series of sr_internal.h, whose range the caller tests. */
#define SINC(t2) sinc_series(t2)
#define COSC(t2) cosc_series(t2)

/* The Lie-Euler step x . exp(dt f(x)) of sr_steppers.c (sr_internal_vector_field, then
 * `advance` with one exponential and no compensation) on n states whose accelerations a are
 * given, one lane per state.  The same expressions in the same order as the scalar code, so a
 * lane's result is sr_step's bit for bit where the scalar code takes the series branches: ok[i]
 * is cleared where an angle is beyond them (|t| >= 1/4 rad, where sr_step uses sin and cos) or
 * the result's sum is not finite, and that state is left to sr_step.  Strides are arguments (GCC
 * 12 vectorises strided loads with a variable stride, not with a constant 35), and the function
 * has external linkage (sr_internal.h): static, GCC propagated the constant strides of its one
 * caller into it and did not vectorise it. */
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

int sr_step_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u, sr_real dt,
                  sr_real *x_next, long *failed_row)
{
    sr_real ok_state[BLOCK], ok_accel[BLOCK], ok_step[BLOCK], acc[BLOCK * SR_NV], block[BLOCK * SR_NX];
    long start, i;
    int k;
    const int lanes = method == SR_LIE_EULER && model && !model->general && dt > 0 && isfinite(dt);
    if (failed_row) *failed_row = -1;
    if (!model || (n > 0 && (!x || !x_next))) return SR_ERR_NULL;
    if (n < 0) return SR_ERR_ARG;
    for (start = 0; start < n; start += BLOCK) {
        const long m = n - start < BLOCK ? n - start : BLOCK;
        const sr_real *xb = x + start * SR_NX, *ub = u ? u + start * SR_NU : NULL;
        sr_real *ob = x_next + start * SR_NX;
        if (lanes) {
            sr_internal_check_lanes(model, m, xb, SR_NX, ok_state);
            sr_gen_accel_lanes(model->c, m, xb, SR_NX, ub ? ub : sr_zero_u, ub ? SR_NU : 0, acc, SR_NV, ok_accel);
            sr_internal_lie_euler_lanes(model->p[SR_P_r], m, xb, SR_NX, acc, SR_NV, dt, block, SR_NX, ok_step);
        } else {
            for (i = 0; i < m; ++i) ok_state[i] = 0;
        }
        for (i = 0; i < m; ++i) {
            int status;
            if (lanes && ok_state[i] != 0 && ok_accel[i] != 0 && ok_step[i] != 0) {
                for (k = 0; k < SR_NX; ++k) ob[i * SR_NX + k] = block[i * SR_NX + k];
                continue;
            }
            status = sr_step(model, method, xb + i * SR_NX, ub ? ub + i * SR_NU : NULL, dt, ob + i * SR_NX);
            if (status != SR_OK) {
                if (failed_row) *failed_row = start + i;
                return status;
            }
        }
    }
    return SR_OK;
}
