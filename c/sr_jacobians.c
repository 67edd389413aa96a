/*
 * sr_jacobians.c -- derivatives of the dynamics in the error coordinates of c/sr_group.c
 * (issue 19).  The generated sr_gen_accel_jacobian_terms gives M, f, df/dd, df/du and dM/dd
 * (derive/derivatives.py); here one Cholesky factorisation of M serves the accelerations and
 * every column:  d(nu') = M^-1 (df - (dM) nu').
 */
#include "sr_internal.h"

#include <string.h>

/* Index of M[i][j], i <= j, in the row-by-row upper triangle of a 5x5 matrix. */
static int upper(int i, int j)
{
    if (i > j) {
        const int t = i;
        i = j;
        j = t;
    }
    return i * SR_NV - i * (i - 1) / 2 + (j - i);
}

/* M = L L^T (L lower, row-major); each pivot must exceed SR_GEN_PIVOT_TOL times M's diagonal
 * entry, as in the accel kernel's test, else SR_ERR_SINGULAR. */
static int cholesky(const sr_real Mu[15], sr_real L[SR_NV * SR_NV])
{
    int i, j, k;
    memset(L, 0, sizeof(sr_real) * SR_NV * SR_NV);
    for (j = 0; j < SR_NV; ++j) {
        sr_real d = Mu[upper(j, j)];
        for (k = 0; k < j; ++k) d -= L[SR_NV * j + k] * L[SR_NV * j + k];
        if (!(d > SR_GEN_PIVOT_TOL * Mu[upper(j, j)])) return SR_ERR_SINGULAR;
        L[SR_NV * j + j] = SR_SQRT(d);
        for (i = j + 1; i < SR_NV; ++i) {
            sr_real s = Mu[upper(i, j)];
            for (k = 0; k < j; ++k) s -= L[SR_NV * i + k] * L[SR_NV * j + k];
            L[SR_NV * i + j] = s / L[SR_NV * j + j];
        }
    }
    return SR_OK;
}

/* b <- M^-1 b with M = L L^T. */
static void solve(const sr_real L[SR_NV * SR_NV], sr_real b[SR_NV])
{
    int i, k;
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < i; ++k) b[i] -= L[SR_NV * i + k] * b[k];
        b[i] /= L[SR_NV * i + i];
    }
    for (i = SR_NV - 1; i >= 0; --i) {
        for (k = i + 1; k < SR_NV; ++k) b[i] -= L[SR_NV * k + i] * b[k];
        b[i] /= L[SR_NV * i + i];
    }
}

int sr_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                      sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU])
{
    static const sr_real zero_u[SR_NU] = {0, 0};
    sr_real Mu[15], f[SR_NV], df[SR_NV * SR_NE], dfdu[SR_NV * SR_NU], dM[5 * 15], L[SR_NV * SR_NV];
    sr_real a[SR_NV], col[SR_NV], ja[SR_NV * SR_NE], jb[SR_NV * SR_NU];
    int status, i, j, k;
    if (!Ja || !Jb) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    status = sr_gen_accel_jacobian_terms(model->c, x, u ? u : zero_u, Mu, f, df, dfdu, dM);
    if (status != SR_OK) return status;
    status = cholesky(Mu, L);
    if (status != SR_OK) return status;
    memcpy(a, f, sizeof a);
    solve(L, a);
    for (k = 0; k < SR_NE; ++k) {
        for (i = 0; i < SR_NV; ++i) col[i] = df[SR_NE * i + k];
        if (k < 5) /* the configuration directions d_xi_S, d_th_Y, d_th_P move M */
            for (i = 0; i < SR_NV; ++i)
                for (j = 0; j < SR_NV; ++j) col[i] -= dM[15 * k + upper(i, j)] * a[j];
        solve(L, col);
        for (i = 0; i < SR_NV; ++i) ja[SR_NE * i + k] = col[i];
    }
    for (k = 0; k < SR_NU; ++k) {
        for (i = 0; i < SR_NV; ++i) col[i] = dfdu[SR_NU * i + k];
        solve(L, col);
        for (i = 0; i < SR_NV; ++i) jb[SR_NU * i + k] = col[i];
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
