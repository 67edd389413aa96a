/*
 * sr_step_batch.c -- one step of many states of one robot: sr_step_batch.  Every method
 * is vectorised across the states, like the batch accel (sr_kernels.c, docs/sweeps.md): a block of
 * states at a time goes through the lanes of the state check, the accelerations
 * (sr_gen_accel_lanes) and the steppers (c/src/sr_step_lanes.c), and any state those do not clear goes
 * through sr_step itself.  So every row gets exactly the bits and the status code that sr_step
 * gives it alone, and the rows after a failing one are not written.  A general robot, and the
 * projected methods, go row by row.
 * Hand-written C99; see spherical_robot.h for the contract.
 */
#include "sr_checks.h"
#include "sr_lanes.h"
#include "sr_argcheck.h"

#include <stddef.h>

/* States per block: 16 run as fast as 64 (AMD EPYC, AVX2) with a quarter of the stack (the
 * fourth-order methods keep five blocks of stage data: about 18 KB in double). */
enum { BLOCK = 16 };

/* One step of `method` (SR_LIE_EULER, SR_RKMK4 or SR_CF4, as in sr_steppers.c) of the m <= BLOCK
 * states xb, into out; ok[i] = 1 where lane i's result is sr_step's, else 0 (that row is then left
 * to sr_step). */
static void step_block(const sr_model *model, int method, long m, const sr_real *xb, const sr_real *ub,
                       sr_real dt, sr_real *out, sr_real *ok)
{
    sr_real K[4][BLOCK * SR_NT], th[BLOCK * SR_NT], Y2[BLOCK * SR_NX], Y[BLOCK * SR_NX], acc[BLOCK * SR_NV];
    sr_real ok_stage[BLOCK];
    const sr_real r = model->p[SR_P_r], *u = ub ? ub : sr_zero_u;
    const long us = ub ? SR_NU : 0;
    long i, k;
    int s;
    sr_internal_check_lanes(model, m, xb, SR_NX, ok);
    /* Every lanes function writes its own verdict, 1 or 0, into ok_stage; a lane stays clean only
     * while every verdict is 1. */
#define AND_STAGE() for (i = 0; i < m; ++i) ok[i] = ok_stage[i] != 0 ? ok[i] : 0
#define ACCEL(y)                                                                        \
    do {                                                                                \
        sr_gen_accel_lanes(model->c, m, y, SR_NX, u, us, acc, SR_NV, ok_stage);         \
        AND_STAGE();                                                                    \
    } while (0)
    ACCEL(xb);
    if (method == SR_LIE_EULER) {
        sr_internal_lie_euler_lanes(r, m, xb, SR_NX, acc, SR_NV, dt, out, SR_NX, ok_stage);
        AND_STAGE();
        return;
    }
    sr_internal_field_lanes(r, m, xb, SR_NX, acc, SR_NV, NULL, 0, K[0], SR_NT, ok_stage);
    if (method == SR_RKMK4) {
        static const sr_real a_diag[3] = {SR_C(0.5), SR_C(0.5), SR_C(1.0)};
        const sr_real b[4] = {dt / 6, dt / 3, dt / 3, dt / 6};
        for (s = 1; s < 4; ++s) {
            for (k = 0; k < m * SR_NT; ++k) th[k] = a_diag[s - 1] * dt * K[s - 1][k];
            sr_internal_act_lanes(m, xb, SR_NX, th, SR_NT, Y, SR_NX, ok_stage);
            AND_STAGE();
            ACCEL(Y);
            sr_internal_field_lanes(r, m, Y, SR_NX, acc, SR_NV, th, SR_NT, K[s], SR_NT, ok_stage);
            AND_STAGE();
        }
        for (k = 0; k < m * SR_NT; ++k) {   /* combine: th = sum_j b_j K_j */
            sr_real sum = 0;
            sum += b[0] * K[0][k];
            sum += b[1] * K[1][k];
            sum += b[2] * K[2][k];
            sum += b[3] * K[3][k];
            th[k] = sum;
        }
        sr_internal_act_lanes(m, xb, SR_NX, th, SR_NT, out, SR_NX, ok_stage);
        AND_STAGE();
    } else {
        const sr_real beta1[4] = {dt / 4, dt / 6, dt / 6, -dt / 12};
        const sr_real beta2[4] = {-dt / 12, dt / 6, dt / 6, dt / 4};
        for (k = 0; k < m * SR_NT; ++k) th[k] = SR_C(0.5) * dt * K[0][k];
        sr_internal_act_lanes(m, xb, SR_NX, th, SR_NT, Y2, SR_NX, ok_stage);           /* Y2 */
        AND_STAGE();
        ACCEL(Y2);
        sr_internal_field_lanes(r, m, Y2, SR_NX, acc, SR_NV, NULL, 0, K[1], SR_NT, ok_stage);
        for (k = 0; k < m * SR_NT; ++k) th[k] = SR_C(0.5) * dt * K[1][k];
        sr_internal_act_lanes(m, xb, SR_NX, th, SR_NT, Y, SR_NX, ok_stage);            /* Y3 */
        AND_STAGE();
        ACCEL(Y);
        sr_internal_field_lanes(r, m, Y, SR_NX, acc, SR_NV, NULL, 0, K[2], SR_NT, ok_stage);
        for (k = 0; k < m * SR_NT; ++k) th[k] = dt * (K[2][k] - SR_C(0.5) * K[0][k]);
        sr_internal_act_lanes(m, Y2, SR_NX, th, SR_NT, Y, SR_NX, ok_stage);            /* Y4 */
        AND_STAGE();
        ACCEL(Y);
        sr_internal_field_lanes(r, m, Y, SR_NX, acc, SR_NV, NULL, 0, K[3], SR_NT, ok_stage);
        for (k = 0; k < m * SR_NT; ++k) {   /* the two combinations of the last update */
            sr_real s1 = 0, s2 = 0;
            s1 += beta1[0] * K[0][k];
            s1 += beta1[1] * K[1][k];
            s1 += beta1[2] * K[2][k];
            s1 += beta1[3] * K[3][k];
            s2 += beta2[0] * K[0][k];
            s2 += beta2[1] * K[1][k];
            s2 += beta2[2] * K[2][k];
            s2 += beta2[3] * K[3][k];
            th[k] = s1;
            Y2[k] = s2;     /* Y2 is free by now: it holds th2 */
        }
        sr_internal_act2_lanes(m, xb, SR_NX, th, Y2, SR_NT, out, SR_NX, ok_stage);
        AND_STAGE();
    }
#undef ACCEL
#undef AND_STAGE
}

int sr_step_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u, sr_real dt,
                  sr_real *x_next, long *failed_row)
{
    sr_real ok[BLOCK], block[BLOCK * SR_NX];
    long start, i;
    int k, lanes, status = arg_model(model, READS(ACCEL) | READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && x_next);
    if (status == SR_OK && (arg_method(method) != SR_OK || arg_dt(dt) != SR_OK)) status = SR_ERR_ARG;
    if (status != SR_OK) return status;
    lanes = !model->general && (method == SR_LIE_EULER || method == SR_RKMK4 || method == SR_CF4);
    for (start = 0; start < n; start += BLOCK) {
        const long m = n - start < BLOCK ? n - start : BLOCK;
        const sr_real *xb = x + start * SR_NX, *ub = u ? u + start * SR_NU : NULL;
        sr_real *ob = x_next + start * SR_NX;
        if (lanes) {
            step_block(model, method, m, xb, ub, dt, block, ok);
        } else {
            for (i = 0; i < m; ++i) ok[i] = 0;
        }
        for (i = 0; i < m; ++i) {
            if (ok[i] != 0) {
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
