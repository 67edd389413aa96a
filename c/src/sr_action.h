/*
 * sr_action.h -- the Lie algebra of the state's group and its action
 * x . exp(th), given the SO(3) increment (the steppers and the step Jacobians' stages).
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_ACTION_H
#define SR_ACTION_H

#include "sr_compensated.h"
#include "sr_so3.h"

/* A Lie-algebra element ("tangent coordinates") of the state's group, 13 numbers:
 * [th_S (3) | th_Y | th_P | th_q (3) | th_nu (5)] (see the top of sr_steppers.c). */
enum { SR_T_S = 0, SR_T_Y = 3, SR_T_P = 4, SR_T_Q = 5, SR_T_V = 8, SR_NT = 13 };

/* Rounding and orthogonality.  Forming E = Exp(...) and then R E rounds the diagonal of E to
 * the grid of numbers near 1 (spacing 1.1e-16 or 2.2e-16); when the angular velocity changes
 * slowly, that rounding error is nearly the same at every step and |R^T R - I| grows
 * linearly (about 1e-11 after 10^6 steps).  We therefore form the increment D = E - I
 * directly (its entries are small and carry full relative precision) and update
 * R <- R + R D: the remaining rounding is that of one addition per entry, which does not
 * repeat from step to step. */

/* The one-axis rotation R = Exp(theta [[e_k]]) (k = 0: R_Y about x, entries c = R[4],
 * s = R[7]; k = 1: R_P about y, c = R[0], s = R[2]) times Exp(angle [[e_k]]): R (Exp - I)
 * changes only (c, s), by (c (cos - 1) - s sin, s (cos - 1) + c sin); the exact zeros and ones
 * are copied (an increment of exactly 0, whose compensation stays 0).  The state check has made
 * sure R has this form.  out may alias R. */
static inline void axis_increment(const sr_real R[9], int k, sr_real angle, sr_real *comp, sr_real out[9])
{
    const int ic = k == 0 ? 4 : 0, is = k == 0 ? 7 : 2;      /* where c and s stand */
    const int ims = k == 0 ? 5 : 6, ic2 = 8;                   /* -s and the second c */
    const sr_real c = R[ic], s = R[is];
    sr_real sn, cm1, dc, ds;
    int m;
    sin_and_cos_minus_one(angle, &sn, &cm1);
    dc = c * cm1 - s * sn;
    ds = s * cm1 + c * sn;
    for (m = 0; m < 9; ++m) out[m] = R[m];
    out[ic] = compensated_add(R[ic], dc, comp ? comp + ic : NULL);
    out[ic2] = compensated_add(R[ic2], dc, comp ? comp + ic2 : NULL);
    out[is] = compensated_add(R[is], ds, comp ? comp + is : NULL);
    out[ims] = compensated_add(R[ims], -ds, comp ? comp + ims : NULL);
}

/* out = x . exp(th) for D = Exp(th_S) - I already formed: R_S + R_S D, the one-axis rotations by
 * th_Y and th_P, q + th_q, nu + th_nu, every sum compensated with comp (SR_NX entries) unless it
 * is NULL.  out may alias x.  The one formula of the group action: the steppers (sr_steppers.c)
 * and the step Jacobians' stages (sr_step_jacobians.c, which have D at hand) both use it. */
static inline void act_increment(const sr_real x[SR_NX], const sr_real D[9], const sr_real th[SR_NT], sr_real *comp,
                                 sr_real out[SR_NX])
{
    sr_real dR[9];
    int i;
    matmul3(x + SR_X_R_S, D, dR);
    for (i = 0; i < 9; ++i) out[SR_X_R_S + i] = compensated_add(x[SR_X_R_S + i], dR[i], comp ? comp + SR_X_R_S + i : NULL);
    axis_increment(x + SR_X_R_Y, 0, th[SR_T_Y], comp ? comp + SR_X_R_Y : NULL, out + SR_X_R_Y);
    axis_increment(x + SR_X_R_P, 1, th[SR_T_P], comp ? comp + SR_X_R_P : NULL, out + SR_X_R_P);
    for (i = 0; i < 3; ++i) out[SR_X_q + i] = compensated_add(x[SR_X_q + i], th[SR_T_Q + i], comp ? comp + SR_X_q + i : NULL);
    for (i = 0; i < SR_NV; ++i)
        out[SR_X_w_S + i] = compensated_add(x[SR_X_w_S + i], th[SR_T_V + i], comp ? comp + SR_X_w_S + i : NULL);
}

#endif /* SR_ACTION_H */
