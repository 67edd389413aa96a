/*
 * sr_jacobians.c -- derivatives of the dynamics in the error coordinates of c/sr_group.c
 * (issue 19).  The generated sr_gen_accel_jacobian_terms gives M, f, df/dd, df/du and dM/dd
 * (derive/derivatives.py); here one Cholesky factorisation of M serves the accelerations and
 * every column:  d(nu') = M^-1 (df - (dM) nu').
 */
#include "sr_internal.h"

#include <string.h>

/* Index of M[i][j] (either order) in the row-by-row upper triangle of a 5x5 matrix. */
static const unsigned char UPPER[SR_NV][SR_NV] = {
    {0, 1, 2, 3, 4}, {1, 5, 6, 7, 8}, {2, 6, 9, 10, 11}, {3, 7, 10, 12, 13}, {4, 8, 11, 13, 14}};

/* M = L L^T (L lower, row-major) and the reciprocals of L's diagonal; each pivot must exceed
 * SR_GEN_PIVOT_TOL times M's diagonal entry, as in the accel kernel's test, else SR_ERR_SINGULAR. */
static int cholesky(const sr_real Mu[15], sr_real L[SR_NV * SR_NV], sr_real inv[SR_NV])
{
    int i, j, k;
    memset(L, 0, sizeof(sr_real) * SR_NV * SR_NV);
    for (j = 0; j < SR_NV; ++j) {
        sr_real d = Mu[UPPER[j][j]];
        for (k = 0; k < j; ++k) d -= L[SR_NV * j + k] * L[SR_NV * j + k];
        if (!(d > SR_GEN_PIVOT_TOL * Mu[UPPER[j][j]])) return SR_ERR_SINGULAR;
        L[SR_NV * j + j] = SR_SQRT(d);
        inv[j] = 1 / L[SR_NV * j + j];
        for (i = j + 1; i < SR_NV; ++i) {
            sr_real s = Mu[UPPER[i][j]];
            for (k = 0; k < j; ++k) s -= L[SR_NV * i + k] * L[SR_NV * j + k];
            L[SR_NV * i + j] = s * inv[j];
        }
    }
    return SR_OK;
}

#define NCOL (SR_NE + SR_NU)

/* B <- M^-1 B for the first n columns of B (SR_NV rows of NCOL), M = L L^T: all columns at once,
 * with the diagonal's reciprocals (five divisions instead of ten per column).  Inline, so that
 * the compiler sees n as a constant at each call (and vectorizes the 14 columns). */
static inline void solve(const sr_real L[SR_NV * SR_NV], const sr_real inv[SR_NV], sr_real B[SR_NV][NCOL], int n)
{
    int i, k, c;
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < i; ++k)
            for (c = 0; c < n; ++c) B[i][c] -= L[SR_NV * i + k] * B[k][c];
        for (c = 0; c < n; ++c) B[i][c] *= inv[i];
    }
    for (i = SR_NV - 1; i >= 0; --i) {
        for (k = i + 1; k < SR_NV; ++k)
            for (c = 0; c < n; ++c) B[i][c] -= L[SR_NV * k + i] * B[k][c];
        for (c = 0; c < n; ++c) B[i][c] *= inv[i];
    }
}

int sr_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                      sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU])
{
    static const sr_real zero_u[SR_NU] = {0, 0};
    sr_real Mu[15], f[SR_NV], df[SR_NV * SR_NE], dfdu[SR_NV * SR_NU], dM[5 * 15], L[SR_NV * SR_NV], inv[SR_NV];
    sr_real a[SR_NV][NCOL], B[SR_NV][NCOL], ja[SR_NV * SR_NE], jb[SR_NV * SR_NU];
    int status, i, j, k;
    if (!Ja || !Jb) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    status = sr_gen_accel_jacobian_terms(model->c, x, u ? u : zero_u, Mu, f, df, dfdu, dM);
    if (status != SR_OK) return status;
    status = cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) a[i][0] = f[i];
    solve(L, inv, a, 1);                                  /* a = nu' */
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < SR_NE; ++k) B[i][k] = df[SR_NE * i + k];
        for (k = 0; k < SR_NU; ++k) B[i][SR_NE + k] = dfdu[SR_NU * i + k];
        for (k = 0; k < 5; ++k) /* the configuration directions d_xi_S, d_th_Y, d_th_P move M */
            for (j = 0; j < SR_NV; ++j) B[i][k] -= dM[15 * k + UPPER[i][j]] * a[j][0];
    }
    solve(L, inv, B, NCOL);
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < SR_NE; ++k) ja[SR_NE * i + k] = B[i][k];
        for (k = 0; k < SR_NU; ++k) jb[SR_NU * i + k] = B[i][SR_NE + k];
    }
    if (!all_finite(ja, SR_NV * SR_NE) || !all_finite(jb, SR_NV * SR_NU)) return SR_ERR_NONFINITE;
    memcpy(Ja, ja, sizeof ja);
    memcpy(Jb, jb, sizeof jb);
    return SR_OK;
}

int sr_accel_jacobian_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                            sr_real *Ja, sr_real *Jb, long *failed_row)
{
    long i;
    if (failed_row) *failed_row = -1;
    if (!model || (n > 0 && (!x || !Ja || !Jb))) return SR_ERR_NULL;
    if (n < 0) return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        const int status = sr_accel_jacobian(model, x + i * SR_NX, u ? u + i * SR_NU : NULL,
                                             Ja + i * SR_NV * SR_NE, Jb + i * SR_NV * SR_NU);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
