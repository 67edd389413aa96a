/* sr_checks.c -- the full state check (the cheap per-call checks are inline in sr_checks.h).
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_checks.h"
#include "sr_argcheck.h"

#include <stddef.h>

int sr_internal_is_rotation(const sr_real *R)
{
    int i, j;
    sr_real det;
    for (i = 0; i < 3; ++i) /* RᵀR is symmetric: its upper triangle decides */
        for (j = i; j < 3; ++j) {
            const sr_real dot = R[i] * R[j] + R[3 + i] * R[3 + j] + R[6 + i] * R[6 + j];
            if (!near(dot, i == j ? 1 : 0)) return 0;
        }
    det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6])
        + R[2] * (R[3] * R[7] - R[4] * R[6]);
    return near(det, 1);
}

/* Rotation about axis k (0 = x, 1 = y): the entries outside the k-plane are exact, so the
 * columns in the plane, (c, s) and (-s', c') on rows p, q, decide: unit length, orthogonal,
 * determinant c c' + s s' = 1. */
static int is_axis_rotation(const sr_real *R, int k)
{
    const int p = k == 0 ? 1 : 0, q = k == 2 ? 1 : 2;
    int i;
    for (i = 0; i < 3; ++i)
        if (R[3 * k + i] != (i == k ? 1 : 0) || R[3 * i + k] != (i == k ? 1 : 0)) return 0;
    return near(R[3 * p + p] * R[3 * p + p] + R[3 * q + p] * R[3 * q + p], 1)
        && near(R[3 * p + q] * R[3 * p + q] + R[3 * q + q] * R[3 * q + q], 1)
        && near(R[3 * p + p] * R[3 * p + q] + R[3 * q + p] * R[3 * q + q], 0)
        && near(R[3 * p + p] * R[3 * q + q] - R[3 * p + q] * R[3 * q + p], 1);
}

int sr_internal_check_state(const sr_model *model, const sr_real x[SR_NX])
{
    const sr_real r = model->p[SR_P_r];
    if (!all_finite(x, SR_NX)) return SR_ERR_NONFINITE;
    if (!sr_internal_is_rotation(x + SR_X_R_S) || !is_axis_rotation(x + SR_X_R_Y, 0) || !is_axis_rotation(x + SR_X_R_P, 1))
        return SR_ERR_NOT_ROTATION;
    if (SR_FABS(x[SR_X_q + 2] - r) > SR_ROTATION_TOL * r) return SR_ERR_CONSTRAINT;
    return SR_OK;
}

int sr_check_state(const sr_model *model, const sr_real x[SR_NX])
{
    const int status = arg_model(model, READS(STATE));
    if (status != SR_OK) return status;
    if (!x) return SR_ERR_NULL;
    return sr_internal_check_state(model, x);
}

int sr_check_state_batch(const sr_model *model, long n, const sr_real *x, long *failed_row)
{
    long i;
    int status = arg_model(model, READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x != NULL);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_internal_check_state(model, x + i * SR_NX);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* ---- the lanes form, for the batch calls --------------------------------------------------- */

/* The tests of sr_check_state and of the kernels' cheap checks (checks() in sr_checks.h), one
 * lane per state of a block, without branches, so that the loop vectorises as sr_gen_accel_lanes
 * does.  ok[i] = 1 where the lane is clean, else 0: the scalar functions then decide, and name
 * what is wrong.  The form is stricter than the scalar tests, never looser: the defects of the
 * unit lengths, orthogonality and determinants are summed (their sum within SR_ROTATION_TOL
 * implies each one is), the entries that must be exact 0 or 1 likewise (a sum of absolute values
 * is 0 only if each term is), and a NaN or infinity makes a sum fail.  Finiteness: q_x, q_y here;
 * every other entry of x and u enters these sums or the kernel's outputs, whose sum the lanes
 * kernel tests (tests/c: a NaN or infinity in any entry of any row is reported). */
SR_LANES_CLONES void sr_internal_check_lanes(const sr_model *model, long n, const sr_real *restrict x,
                                             long x_stride, sr_real *restrict ok)
{
    const sr_real r = model->p[SR_P_r];
    long i;
    for (i = 0; i < n; ++i) {
        const sr_real *S = x + x_stride * i + SR_X_R_S, *Y = x + x_stride * i + SR_X_R_Y;
        const sr_real *P = x + x_stride * i + SR_X_R_P, *q = x + x_stride * i + SR_X_q;
        /* R_S: orthonormal columns (the upper triangle of R^T R), determinant 1, unit third row. */
        const sr_real rotation
            = SR_FABS(S[0] * S[0] + S[3] * S[3] + S[6] * S[6] - 1) + SR_FABS(S[0] * S[1] + S[3] * S[4] + S[6] * S[7])
            + SR_FABS(S[0] * S[2] + S[3] * S[5] + S[6] * S[8]) + SR_FABS(S[1] * S[1] + S[4] * S[4] + S[7] * S[7] - 1)
            + SR_FABS(S[1] * S[2] + S[4] * S[5] + S[7] * S[8]) + SR_FABS(S[2] * S[2] + S[5] * S[5] + S[8] * S[8] - 1)
            + SR_FABS(S[0] * (S[4] * S[8] - S[5] * S[7]) - S[1] * (S[3] * S[8] - S[5] * S[6])
                      + S[2] * (S[3] * S[7] - S[4] * S[6]) - 1)
            + SR_FABS(S[6] * S[6] + S[7] * S[7] + S[8] * S[8] - 1)
            /* R_Y about x, R_P about y: the (cos, sin) blocks rotations. */
            + SR_FABS(Y[4] * Y[4] + Y[7] * Y[7] - 1) + SR_FABS(Y[5] * Y[5] + Y[8] * Y[8] - 1)
            + SR_FABS(Y[4] * Y[5] + Y[7] * Y[8]) + SR_FABS(Y[4] * Y[8] - Y[5] * Y[7] - 1)
            + SR_FABS(P[0] * P[0] + P[6] * P[6] - 1) + SR_FABS(P[2] * P[2] + P[8] * P[8] - 1)
            + SR_FABS(P[0] * P[2] + P[6] * P[8]) + SR_FABS(P[0] * P[8] - P[2] * P[6] - 1)
            + SR_FABS(P[0] * P[0] + P[2] * P[2] - 1);
        /* ... and their axis rows and columns exact. */
        const sr_real exact = SR_FABS(Y[0] - 1) + SR_FABS(Y[1]) + SR_FABS(Y[2]) + SR_FABS(Y[3]) + SR_FABS(Y[6])
                            + SR_FABS(P[4] - 1) + SR_FABS(P[1]) + SR_FABS(P[3]) + SR_FABS(P[5]) + SR_FABS(P[7]);
        /* The contact q_z = r; q_x, q_y finite. */
        const sr_real contact = SR_FABS(q[2] - r);
        sr_real good = rotation <= SR_ROTATION_TOL ? 1 : 0;   /* selects, not &&: no branches */
        good = exact == 0 ? good : 0;
        good = contact <= SR_ROTATION_TOL * r ? good : 0;
        ok[i] = SR_GEN_LANE_FINITE(q[0] + q[1]) ? good : 0;
    }
}
