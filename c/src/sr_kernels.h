/*
 * sr_kernels.h -- the model's kernels of sr_kernels.c, of the paper's geometry or
 * general (sr_model), unchecked, and the Cholesky factorisation of the general robot's M.
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_KERNELS_H
#define SR_KERNELS_H

#include "sr_math.h"

#ifdef SR_USE_FLOAT
#define sr_internal_accel sr_internal_accel_f
#define sr_internal_inertia sr_internal_inertia_f
#define sr_internal_rhs sr_internal_rhs_f
#define sr_internal_energy sr_internal_energy_f
#define sr_internal_equilibrium_residual sr_internal_equilibrium_residual_f
#define sr_internal_general_accel_jacobian_terms sr_internal_general_accel_jacobian_terms_f
#define sr_internal_cholesky sr_internal_cholesky_f
#endif

/* The generated kernel of model's kind, unchecked (the SR_GEN_ status codes); u not NULL. */
int sr_internal_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV]);
int sr_internal_inertia(const sr_model *model, const sr_real x[SR_NX], sr_real M[SR_NV * SR_NV]);
int sr_internal_rhs(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real f[SR_NV]);
int sr_internal_energy(const sr_model *model, const sr_real x[SR_NX], sr_real *energy);
int sr_internal_equilibrium_residual(const sr_model *model, const sr_real x[SR_NX], sr_real res[SR_NV]);
/* The general robot's M, f, df/dd, df/du and dM/dd (shell frame) for sr_accel_jacobian; the
 * paper's robot has its own kernel in the yoke frame (c/src/sr_jacobians.c). */
int sr_internal_general_accel_jacobian_terms(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                             sr_real Mu[15], sr_real f[SR_NV], sr_real df[SR_NV * SR_NE],
                                             sr_real dfdu[SR_NV * SR_NU], sr_real dM[5 * 15]);

/* Index of M[i][j] (either order) in the row-by-row upper triangle Mu[15] of a 5x5 matrix. */
static const unsigned char SR_UPPER[SR_NV][SR_NV] = {
    {0, 1, 2, 3, 4}, {1, 5, 6, 7, 8}, {2, 6, 9, 10, 11}, {3, 7, 10, 12, 13}, {4, 8, 11, 13, 14}};

/* M = L L^T (L lower, row-major) from its upper triangle Mu, and the reciprocals of L's diagonal;
 * each pivot must exceed SR_GEN_PIVOT_TOL times M's diagonal entry, as in the paper-geometry
 * accel kernel's test, else SR_ERR_SINGULAR. */
int sr_internal_cholesky(const sr_real Mu[15], sr_real L[SR_NV * SR_NV], sr_real inv[SR_NV]);

/* B <- M^-1 B on the first n columns of B (SR_NV rows, row-major, ld entries per row), M = L L^T
 * from sr_internal_cholesky: forward then back substitution, column by column, each column's five
 * entries held in locals through both sweeps (B may alias L for all the compiler can prove, so
 * updated in place it would store and reload an entry per term).  Each entry's terms are taken in
 * the order of the substitution loops, y_i = (b_i - sum_(k<i) L_ik y_k) / L_ii, then
 * x_i = (y_i - sum_(k>i) L_ki x_k) / L_ii, k ascending. */
static inline void sr_internal_cholesky_solve(const sr_real L[SR_NV * SR_NV], const sr_real inv[SR_NV], int ld, int n,
                                              sr_real *B)
{
    typedef char five_rows[SR_NV == 5 ? 1 : -1];
    int c;
    (void)sizeof(five_rows);
    for (c = 0; c < n; ++c) {
        sr_real *b = B + c;
        const sr_real y0 = b[0] * inv[0];
        const sr_real y1 = (b[ld] - L[5] * y0) * inv[1];
        const sr_real y2 = (b[2 * ld] - L[10] * y0 - L[11] * y1) * inv[2];
        const sr_real y3 = (b[3 * ld] - L[15] * y0 - L[16] * y1 - L[17] * y2) * inv[3];
        const sr_real x4 = (b[4 * ld] - L[20] * y0 - L[21] * y1 - L[22] * y2 - L[23] * y3) * inv[4] * inv[4];
        const sr_real x3 = (y3 - L[23] * x4) * inv[3];
        const sr_real x2 = (y2 - L[17] * x3 - L[22] * x4) * inv[2];
        const sr_real x1 = (y1 - L[11] * x2 - L[16] * x3 - L[21] * x4) * inv[1];
        b[0] = (y0 - L[5] * x1 - L[10] * x2 - L[15] * x3 - L[20] * x4) * inv[0];
        b[ld] = x1;
        b[2 * ld] = x2;
        b[3 * ld] = x3;
        b[4 * ld] = x4;
    }
}

#endif /* SR_KERNELS_H */
