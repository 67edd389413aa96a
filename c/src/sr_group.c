/*
 * sr_group.c -- the state as a point of the group SO(3) x SO(2)_x x SO(2)_y x R^2 x R^5 and its
 * tangent (error) coordinates: x (+) d (sr_retract) and y (-) x (sr_local), right-trivialised
 * (as in manif and SymForce).  The Jacobians of the dynamics and of the steps are
 * expressed in these coordinates, so they are the contract between them and their users.
 */
#include "sr_checks.h"
#include "sr_so3.h"
#include "sr_argcheck.h"
#include "sr_unchecked.h"

#include <string.h>

/* y = x (+) d without checks (y may alias x). */
static void retract(const sr_real x[SR_NX], const sr_real d[SR_NE], sr_real y[SR_NX])
{
    sr_real D[9], RD[9], RY[9], RP[9];
    int i;
    /* R_S Exp(d_S) = R_S + R_S (Exp(d_S) - I): small steps keep full relative precision. */
    so3_exp_minus_identity(d + SR_E_xi_S, D);
    matmul3(x + SR_X_R_S, D, RD);
    rotate_about_axis(x + SR_X_R_Y, 0, d[SR_E_th_Y], RY);
    rotate_about_axis(x + SR_X_R_P, 1, d[SR_E_th_P], RP);
    if (y != x) memcpy(y, x, sizeof(sr_real) * SR_NX);
    for (i = 0; i < 9; ++i) {
        y[SR_X_R_S + i] += RD[i];
        y[SR_X_R_Y + i] = RY[i];
        y[SR_X_R_P + i] = RP[i];
    }
    y[SR_X_q + 0] += d[SR_E_q + 0];
    y[SR_X_q + 1] += d[SR_E_q + 1];
    for (i = 0; i < SR_NV; ++i) y[SR_X_w_S + i] += d[SR_E_nu + i];
}

/* d = y (-) x without checks. */
static void local(const sr_real x[SR_NX], const sr_real y[SR_NX], sr_real d[SR_NE])
{
    sr_real E[9], Rt[9];
    int i, j;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) Rt[3 * i + j] = x[SR_X_R_S + 3 * j + i];
    matmul3(Rt, y + SR_X_R_S, E);
    so3_log(E, d + SR_E_xi_S);
    /* R_Y^T R_Y' is the rotation by the angle difference about x: its (cos, sin) in the (y, z)
     * block; the same for R_P about y in the (z, x) block.  Both sums use the two copies. */
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) Rt[3 * i + j] = x[SR_X_R_Y + 3 * j + i];
    matmul3(Rt, y + SR_X_R_Y, E);
    d[SR_E_th_Y] = SR_ATAN2(E[7] - E[5], E[4] + E[8]);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) Rt[3 * i + j] = x[SR_X_R_P + 3 * j + i];
    matmul3(Rt, y + SR_X_R_P, E);
    d[SR_E_th_P] = SR_ATAN2(E[2] - E[6], E[0] + E[8]);
    d[SR_E_q + 0] = y[SR_X_q + 0] - x[SR_X_q + 0];
    d[SR_E_q + 1] = y[SR_X_q + 1] - x[SR_X_q + 1];
    for (i = 0; i < SR_NV; ++i) d[SR_E_nu + i] = y[SR_X_w_S + i] - x[SR_X_w_S + i];
}

void sr_internal_retract(const sr_real x[SR_NX], const sr_real d[SR_NE], sr_real y[SR_NX]) { retract(x, d, y); }

int sr_retract(const sr_model *model, const sr_real x[SR_NX], const sr_real d[SR_NE], sr_real y[SR_NX])
{
    sr_real out[SR_NX];
    int status = arg_model(model, READS(STATE));
    if (status != SR_OK) return status;
    if (!x || !d || !y) return SR_ERR_NULL;
    status = sr_internal_check_state(model, x);
    if (status != SR_OK) return status;
    if (!all_finite(d, SR_NE)) return SR_ERR_NONFINITE;
    retract(x, d, out);
    if (!all_finite(out, SR_NX)) return SR_ERR_NONFINITE;
    memcpy(y, out, sizeof out);
    return SR_OK;
}

int sr_local(const sr_model *model, const sr_real x[SR_NX], const sr_real y[SR_NX], sr_real d[SR_NE])
{
    sr_real out[SR_NE];
    int status = arg_model(model, READS(STATE));
    if (status != SR_OK) return status;
    if (!x || !y || !d) return SR_ERR_NULL;
    status = sr_internal_check_state(model, x);
    if (status == SR_OK) status = sr_internal_check_state(model, y);
    if (status != SR_OK) return status;
    local(x, y, out);
    if (!all_finite(out, SR_NE)) return SR_ERR_NONFINITE;
    memcpy(d, out, sizeof out);
    return SR_OK;
}

int sr_retract_batch(const sr_model *model, long n, const sr_real *x, const sr_real *d, sr_real *y,
                     long *failed_row)
{
    long i;
    int status = arg_model(model, READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && d && y);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_retract(model, x + i * SR_NX, d + i * SR_NE, y + i * SR_NX);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_local_batch(const sr_model *model, long n, const sr_real *x, const sr_real *y, sr_real *d,
                   long *failed_row)
{
    long i;
    int status = arg_model(model, READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && y && d);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_local(model, x + i * SR_NX, y + i * SR_NX, d + i * SR_NE);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
