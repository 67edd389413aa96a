/* sr_checks.c -- the full state check (the cheap per-call checks are inline in sr_internal.h).
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_internal.h" /* spherical_robot.h, math macros, shared helpers */

#include <stddef.h>

static int is_rotation(const sr_real *R)
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

int sr_check_state(const sr_model *model, const sr_real x[SR_NX])
{
    const sr_real r = model ? model->p[SR_P_r] : 0;
    if (!model || !x) return SR_ERR_NULL;
    if (!all_finite(x, SR_NX)) return SR_ERR_NONFINITE;
    if (!is_rotation(x + SR_X_R_S) || !is_axis_rotation(x + SR_X_R_Y, 0) || !is_axis_rotation(x + SR_X_R_P, 1))
        return SR_ERR_NOT_ROTATION;
    if (SR_FABS(x[SR_X_q + 2] - r) > SR_ROTATION_TOL * r) return SR_ERR_CONSTRAINT;
    return SR_OK;
}

int sr_check_state_batch(const sr_model *model, long n, const sr_real *x, long *failed_row)
{
    long i;
    if (failed_row) *failed_row = -1;
    if (!model || !x) return SR_ERR_NULL;
    if (n < 0) return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        const int status = sr_check_state(model, x + i * SR_NX);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
