/*
 * sr_control.h -- what the LQR (sr_control.c) and the NMPC (sr_nmpc.c) share: the rate of the
 * cross-track error, which holds their integrals while the robot closes on the path.
 * Internal to the library: not part of the public API, and not seen by the cffi bindings.
 */
#ifndef SR_CONTROL_H
#define SR_CONTROL_H

#include "spherical_robot.h"

/* de_y/dt [m/s]: the contact point's velocity r (R_S w_S) x e_z along the left normal
 * (-sin psi, cos psi) of a path heading psi. */
static inline sr_real cross_track_rate(const sr_model *model, const sr_real x[SR_NX], sr_real heading)
{
    const sr_real *R_S = x + SR_X_R_S, *w_S = x + SR_X_w_S;
    sr_real w[2];
    int i;
    for (i = 0; i < 2; ++i) w[i] = R_S[3 * i] * w_S[0] + R_S[3 * i + 1] * w_S[1] + R_S[3 * i + 2] * w_S[2];
    return model->p[SR_P_r] * (-SR_SIN(heading) * w[1] - SR_COS(heading) * w[0]);
}

#endif /* SR_CONTROL_H */
