/*
 * sr_dexpinv.h -- the derivatives of RKMK4's dexp^-1 on the SO(3) block, for the step Jacobians
 * in the state (sr_step_jacobians.c) and in the parameters (sr_param_jacobians.c).
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.  Everything here is static inline; no globals.
 */
#ifndef SR_DEXPINV_H
#define SR_DEXPINV_H

#include "sr_action.h"
#include "sr_so3.h"

/* c(s) of dexp^-1 (s = |th|^2) and its derivative dc/ds: the closed form of sr_internal_dexpinv,
 * with the same series below s = SR_SERIES_T2 (sr_so3.h). */
static inline void dexpinv_coefficient(sr_real s, sr_real *c, sr_real *dc)
{
    if (s < SR_SERIES_T2) {
        *c = dexpinv_series(s);
        *dc = dexpinv_series_derivative(s);
    } else {
        const sr_real half = SR_C(0.5) * SR_SQRT(s), sn = SR_SIN(half), cs = SR_COS(half);
        const sr_real phi = 1 - half * cs / sn;                 /* c = phi / s */
        const sr_real dphi_dhalf = -cs / sn + half / (sn * sn);  /* d(1 - h cot h)/dh */
        *c = phi / s;
        *dc = dphi_dhalf / (SR_C(8.0) * half) / s - phi / (s * s);   /* h = sqrt(s)/2: dh/ds = 1/(8h) */
    }
}

/* k = dexp^-1(th, f) on the SO(3) block, k_S = v + t x v / 2 + c t x (t x v) with t = th_S, v = f_S
 * (sr_internal_dexpinv's formula, in its order), and its derivatives P = dk_S/dv, Q = dk_S/dt (see the
 * top of the file); the coefficient c and its derivative computed once for all three. */
static inline void dexpinv_and_derivatives(const sr_real th[SR_NT], const sr_real f[SR_NT], sr_real k[3], sr_real P[9],
                                    sr_real Q[9])
{
    const sr_real *t = th + SR_T_S, *v = f + SR_T_S;
    const sr_real t00 = t[0] * t[0], t11 = t[1] * t[1], t22 = t[2] * t[2];
    const sr_real s = t00 + t11 + t22, tv = t[0] * v[0] + t[1] * v[1] + t[2] * v[2];
    sr_real c, dc, dc2, a[3], b[3], T2[9];
    int i, j;
    dexpinv_coefficient(s, &c, &dc);
    dc2 = 2 * dc;
    a[0] = t[1] * v[2] - t[2] * v[1];   /* a = t x v, b = t x a */
    a[1] = t[2] * v[0] - t[0] * v[2];
    a[2] = t[0] * v[1] - t[1] * v[0];
    b[0] = t[1] * a[2] - t[2] * a[1];
    b[1] = t[2] * a[0] - t[0] * a[2];
    b[2] = t[0] * a[1] - t[1] * a[0];
    for (i = 0; i < 3; ++i) k[i] = v[i] + SR_C(0.5) * a[i] + c * b[i];
    /* [t]^2 = t t^T - |t|^2 I, its diagonal without cancellation */
    T2[0] = -(t11 + t22);   T2[1] = t[0] * t[1];    T2[2] = t[0] * t[2];
    T2[3] = T2[1];          T2[4] = -(t00 + t22);   T2[5] = t[1] * t[2];
    T2[6] = T2[2];          T2[7] = T2[5];          T2[8] = -(t00 + t11);
    /* P = I + [t]/2 + c [t]^2 */
    P[0] = 1 + c * T2[0];                  P[1] = -SR_C(0.5) * t[2] + c * T2[1]; P[2] = SR_C(0.5) * t[1] + c * T2[2];
    P[3] = SR_C(0.5) * t[2] + c * T2[3];   P[4] = 1 + c * T2[4];                 P[5] = -SR_C(0.5) * t[0] + c * T2[5];
    P[6] = -SR_C(0.5) * t[1] + c * T2[6];  P[7] = SR_C(0.5) * t[0] + c * T2[7];  P[8] = 1 + c * T2[8];
    /* Q = -[v]/2 + c ((t.v) I + t v^T - 2 v t^T) + 2 c' b t^T */
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) Q[3 * i + j] = c * (t[i] * v[j] - 2 * v[i] * t[j]) + dc2 * b[i] * t[j];
    Q[0] += c * tv;
    Q[4] += c * tv;
    Q[8] += c * tv;
    Q[1] += SR_C(0.5) * v[2];
    Q[2] -= SR_C(0.5) * v[1];
    Q[3] -= SR_C(0.5) * v[2];
    Q[5] += SR_C(0.5) * v[0];
    Q[6] += SR_C(0.5) * v[1];
    Q[7] -= SR_C(0.5) * v[0];
}

#endif /* SR_DEXPINV_H */
