/*
 * sr_checks.h -- the checks of the state and torques before every kernel call
 * (inline), and the lanes form of the state checks (sr_checks.c).
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_CHECKS_H
#define SR_CHECKS_H

#include "sr_finite.h"

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

#ifdef SR_USE_FLOAT /* float symbols carry _f, as in spherical_robot.h */
#define sr_internal_check_lanes sr_internal_check_lanes_f
#define sr_internal_is_rotation sr_internal_is_rotation_f
#endif

/* The lanes form of the state checks but finiteness (c/src/sr_checks.c): ok[i] = 1 or 0. */
/* R (row-major) orthonormal with det +1, to SR_ROTATION_TOL: 1, else 0 (sr_checks.c). */
int sr_internal_is_rotation(const sr_real *R);

void sr_internal_check_lanes(const sr_model *model, long n, const sr_real *restrict x, long x_stride,
                             sr_real *restrict ok);

#endif /* SR_CHECKS_H */
