/*
 * sr_jacobians.c -- derivatives of the dynamics in the error coordinates of sr_group.c.
 * The generated kernels give M, f, df, df/du and dM (derive/derivatives.py): for a
 * general robot in the shell frame, for the paper's in the yoke frame (a third of the operations);
 * one factorisation of M (joints first for the paper's geometry, Cholesky for a general robot)
 * serves the accelerations and every column: d(nu') = M^-1 (df - (dM) nu').
 */
#include "sr_checks.h"
#include "sr_jacobians.h"
#include "sr_kernels.h"
#include "sr_so3.h"
#include "sr_argcheck.h"

#include <string.h>

#define NCOL (SR_NE + SR_NU)

/* The paper's robot: M = [A B; B^T D], D = diag(M_33, M_44), since M_34 = 0 (the yoke and the
 * pendulum rates do not couple; derive/codegen/joint_first.py proves it, and the generated terms
 * kernel writes M_34 as a literal 0).  As in sr_gen_accel, the joints go first: with
 * beta = B D^-1 and the Schur complement S = A - beta B^T (3 x 3), M v = r is
 *     S v_S = r_S - beta r_J,   v_J = D^-1 r_J - beta^T v_S,
 * S inverted by its adjugate.  The pivots are tested as in sr_gen_accel (M_33, M_44 > 0, the
 * leading minors of S above SR_GEN_PIVOT_TOL times M's diagonal), else SR_ERR_SINGULAR. */
typedef struct {
    sr_real dinv[2], beta[3][2], Sinv[3][3];
} joint_first;

static int joint_first_factor(const sr_real Mu[15], joint_first *s)
{
    sr_real S[3][3], C[3][3], det;
    int i, j, k;
    if (!(Mu[SR_UPPER[3][3]] > 0 && Mu[SR_UPPER[4][4]] > 0)) return SR_ERR_SINGULAR;
    for (k = 0; k < 2; ++k) s->dinv[k] = 1 / Mu[SR_UPPER[3 + k][3 + k]];
    for (i = 0; i < 3; ++i)
        for (k = 0; k < 2; ++k) s->beta[i][k] = Mu[SR_UPPER[i][3 + k]] * s->dinv[k];
    for (i = 0; i < 3; ++i)
        for (j = i; j < 3; ++j)
            S[i][j] = S[j][i] = Mu[SR_UPPER[i][j]] - s->beta[i][0] * Mu[SR_UPPER[j][3]]
                                                   - s->beta[i][1] * Mu[SR_UPPER[j][4]];
    C[0][0] = S[1][1] * S[2][2] - S[1][2] * S[1][2];
    C[0][1] = S[1][2] * S[0][2] - S[0][1] * S[2][2];
    C[0][2] = S[0][1] * S[1][2] - S[1][1] * S[0][2];
    C[1][1] = S[0][0] * S[2][2] - S[0][2] * S[0][2];
    C[1][2] = S[0][1] * S[0][2] - S[1][2] * S[0][0];
    C[2][2] = S[1][1] * S[0][0] - S[0][1] * S[0][1];
    det = S[0][0] * C[0][0] + S[0][1] * C[0][1] + S[0][2] * C[0][2];
    if (!(S[0][0] > SR_GEN_PIVOT_TOL * Mu[SR_UPPER[0][0]])) return SR_ERR_SINGULAR;
    if (!(C[2][2] > SR_GEN_PIVOT_TOL * Mu[SR_UPPER[1][1]] * S[0][0])) return SR_ERR_SINGULAR;
    if (!(det > SR_GEN_PIVOT_TOL * Mu[SR_UPPER[2][2]] * C[2][2])) return SR_ERR_SINGULAR;
    for (i = 0; i < 3; ++i)
        for (j = i; j < 3; ++j) s->Sinv[i][j] = s->Sinv[j][i] = C[i][j] / det;
    return SR_OK;
}

/* B <- M^-1 B for the first n columns, M factored by joint_first_factor: each step a loop along
 * the columns (which the compiler vectorises), every entry the same expression as column by column. */
static inline void joint_first_solve(const joint_first *s, sr_real B[SR_NV][NCOL], int n)
{
    sr_real g[3][NCOL], v[3][NCOL];
    int i, c;
    for (i = 0; i < 3; ++i)
        for (c = 0; c < n; ++c) g[i][c] = B[i][c] - s->beta[i][0] * B[3][c] - s->beta[i][1] * B[4][c];
    for (i = 0; i < 3; ++i)
        for (c = 0; c < n; ++c) v[i][c] = s->Sinv[i][0] * g[0][c] + s->Sinv[i][1] * g[1][c] + s->Sinv[i][2] * g[2][c];
    for (c = 0; c < n; ++c)
        B[3][c] = s->dinv[0] * B[3][c] - (s->beta[0][0] * v[0][c] + s->beta[1][0] * v[1][c] + s->beta[2][0] * v[2][c]);
    for (c = 0; c < n; ++c)
        B[4][c] = s->dinv[1] * B[4][c] - (s->beta[0][1] * v[0][c] + s->beta[1][1] * v[1][c] + s->beta[2][1] * v[2][c]);
    for (i = 0; i < 3; ++i)
        for (c = 0; c < n; ++c) B[i][c] = v[i][c];
}

/* B[i][k] -= (dM'_k g)_i for the four directions that move M' (d_xi', d_th_P), M' packed upper: one
 * index lookup per (i, j) for all four, the four sums in locals (the order of each sum kept). */
static inline void subtract_dM_g(const sr_real dM[4 * 15], const sr_real g[SR_NV][NCOL], sr_real B[SR_NV][NCOL])
{
    int i, j;
    for (i = 0; i < SR_NV; ++i) {
        sr_real b0 = B[i][0], b1 = B[i][1], b2 = B[i][2], b3 = B[i][3];
        for (j = 0; j < SR_NV; ++j) {
            const int e = SR_UPPER[i][j];
            const sr_real gj = g[j][0];
            b0 -= dM[e] * gj;
            b1 -= dM[15 + e] * gj;
            b2 -= dM[30 + e] * gj;
            b3 -= dM[45 + e] * gj;
        }
        B[i][0] = b0;
        B[i][1] = b1;
        B[i][2] = b2;
        B[i][3] = b3;
    }
}

/* The general robot, in the shell frame: M, f, df/dd, df/du, dM/dd from the generated kernel,
 * M = L L^T; ja, jb its 5 x 12 and 5 x 2 Jacobians. */
static int general_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                  sr_real acc[SR_NV], sr_real ja[SR_NV * SR_NE], sr_real jb[SR_NV * SR_NU],
                                  sr_real *minv)
{
    sr_real Mu[15], f[SR_NV], df[SR_NV * SR_NE], dfdu[SR_NV * SR_NU], dM[5 * 15], L[SR_NV * SR_NV], inv[SR_NV];
    sr_real a[SR_NV][NCOL], B[SR_NV][NCOL];
    int status, i, j, k;
    status = sr_internal_general_accel_jacobian_terms(model, x, u, Mu, f, df, dfdu, dM);
    if (status != SR_OK) return status;
    status = sr_internal_cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) a[i][0] = f[i];
    sr_internal_cholesky_solve(L, inv, NCOL, 1, &a[0][0]);                                    /* a = nu' */
    for (i = 0; i < SR_NV; ++i) acc[i] = a[i][0];
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < SR_NE; ++k) B[i][k] = df[SR_NE * i + k];
        for (k = 0; k < SR_NU; ++k) B[i][SR_NE + k] = dfdu[SR_NU * i + k];
        for (k = 0; k < 5; ++k) /* the configuration directions d_xi_S, d_th_Y, d_th_P move M */
            for (j = 0; j < SR_NV; ++j) B[i][k] -= dM[15 * k + SR_UPPER[i][j]] * a[j][0];
    }
    sr_internal_cholesky_solve(L, inv, NCOL, NCOL, &B[0][0]);
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < SR_NE; ++k) ja[SR_NE * i + k] = B[i][k];
        for (k = 0; k < SR_NU; ++k) jb[SR_NU * i + k] = B[i][SR_NE + k];
    }
    if (minv) {   /* M^-1 = M^-1 I */
        for (i = 0; i < SR_NV; ++i)
            for (k = 0; k < SR_NV; ++k) a[i][k] = i == k ? 1 : 0;
        sr_internal_cholesky_solve(L, inv, NCOL, SR_NV, &a[0][0]);
        for (i = 0; i < SR_NV; ++i)
            for (k = 0; k < SR_NV; ++k) minv[SR_NV * i + k] = a[i][k];
    }
    return SR_OK;
}

/* The paper's robot, in the yoke frame (derive/derivatives.py, "the paper's robot in the yoke
 * frame"): nu' = T^T g, T = diag(R_Y^T, 1, 1), g = M'^-1 f'(gamma', R_P, nu').  The generated kernel
 * gives M', f', df' along (d_xi', d_th_P, d_nu'), df'/du and dM' along (d_xi', d_th_P); with one
 * joint-first factorisation of M', G = M'^-1 (df' - (dM') g), 11 columns (Y_* below).  The chain
 * rule to the error coordinates, c and s the entries of R_Y:
 *   d_xi_S:            d_xi' = R_Y^T d_xi_S                   -> T^T G_xi' R_Y^T
 *   d_th_Y:            gamma' and w' turn by -d_th_Y about e_x,
 *                      and nu'_S = R_Y g_S turns with R_Y      -> T^T (G_xi'x + G_w' (w' x e_x)) + (R_Y (e_x x g_S), 0, 0)
 *   d_th_P, d_w_Y, d_w_P, u:                                   -> T^T G
 *   d_w_S:             d_w' = R_Y^T d_w_S                      -> T^T G_w' R_Y^T
 * where T^T on the left turns rows 1 and 2 (the shell's y and z) by R_Y. */
/* Y_SOLVED: the columns solved, Y_NCOL and one of zeros, an even count, so that the vectorised
 * column loops of joint_first_solve need no scalar remainder (which GCC's -O2 does not vectorise). */
enum { Y_XI = 0, Y_TH_P = 3, Y_W = 4, Y_U = 9, Y_NCOL = 11, Y_SOLVED = 12 };
typedef char solved_fit[(Y_SOLVED <= NCOL && Y_SOLVED % 4 == 0) ? 1 : -1];
/* SR_LANES_CLONES: with -DSR_CLONES also compiled for AVX2 (the same bits: no FMA, no contraction),
 * so that joint_first_solve's column loops run four numbers a vector (the filter's predict and IMU
 * update call it). */

static SR_LANES_CLONES int paper_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                sr_real acc[SR_NV], sr_real ja[SR_NV * SR_NE], sr_real jb[SR_NV * SR_NU],
                                sr_real *minv)
{
    const sr_real c = x[SR_X_R_Y + 4], s = x[SR_X_R_Y + 7];
    const sr_real *w = x + SR_X_w_S;
    sr_real Mu[15], f[SR_NV], df[SR_NV * 9], dfdu[SR_NV * SR_NU], dM[4 * 15];
    sr_real g[SR_NV][NCOL], B[SR_NV][NCOL], Y[SR_NV][SR_NE + SR_NU];
    sr_real wy, wz;
    joint_first jf;
    int status, i, k;
    status = sr_gen_accel_jacobian_yoke_terms(model->c, x, u, Mu, f, df, dfdu, dM);
    if (status != SR_OK) return status;
    status = joint_first_factor(Mu, &jf);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) g[i][0] = f[i];
    joint_first_solve(&jf, g, 1);                            /* g = M'^-1 f' */
    acc[0] = g[0][0];                                        /* nu' = T^T g */
    acc[1] = c * g[1][0] - s * g[2][0];
    acc[2] = s * g[1][0] + c * g[2][0];
    acc[3] = g[3][0];
    acc[4] = g[4][0];
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < 9; ++k) B[i][k] = df[9 * i + k];
        for (k = 0; k < SR_NU; ++k) B[i][Y_U + k] = dfdu[SR_NU * i + k];
        B[i][Y_NCOL] = 0;
    }
    subtract_dM_g(dM, (const sr_real(*)[NCOL])g, B);   /* d_xi', d_th_P move M' */
    joint_first_solve(&jf, B, Y_SOLVED);
    wy = c * w[1] + s * w[2];                                /* w' = R_Y^T w_S */
    wz = c * w[2] - s * w[1];
    for (i = 0; i < SR_NV; ++i) {                            /* the columns, rows still in the yoke frame */
        const sr_real *b = B[i];
        sr_real *y = Y[i];
        y[SR_E_xi_S + 0] = b[Y_XI + 0];
        y[SR_E_xi_S + 1] = c * b[Y_XI + 1] - s * b[Y_XI + 2];
        y[SR_E_xi_S + 2] = s * b[Y_XI + 1] + c * b[Y_XI + 2];
        y[SR_E_th_Y] = b[Y_XI + 0] + wz * b[Y_W + 1] - wy * b[Y_W + 2];
        y[SR_E_th_P] = b[Y_TH_P];
        y[SR_E_q + 0] = 0;                                   /* the dynamics does not depend on q */
        y[SR_E_q + 1] = 0;
        y[SR_E_nu + 0] = b[Y_W + 0];
        y[SR_E_nu + 1] = c * b[Y_W + 1] - s * b[Y_W + 2];
        y[SR_E_nu + 2] = s * b[Y_W + 1] + c * b[Y_W + 2];
        y[SR_E_nu + 3] = b[Y_W + 3];
        y[SR_E_nu + 4] = b[Y_W + 4];
        y[SR_NE + 0] = b[Y_U + 0];
        y[SR_NE + 1] = b[Y_U + 1];
    }
    Y[1][SR_E_th_Y] -= g[2][0];                              /* + e_x x g_S, turned by R_Y below */
    Y[2][SR_E_th_Y] += g[1][0];
    for (k = 0; k < SR_NE + SR_NU; ++k) {                    /* T^T: the shell rows turn by R_Y */
        const sr_real y1 = Y[1][k], y2 = Y[2][k];
        Y[1][k] = c * y1 - s * y2;
        Y[2][k] = s * y1 + c * y2;
    }
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < SR_NE; ++k) ja[SR_NE * i + k] = Y[i][k];
        for (k = 0; k < SR_NU; ++k) jb[SR_NU * i + k] = Y[i][SR_NE + k];
    }
    if (minv) {   /* M^-1 = T^T M'^-1 T: M'^-1 on eight columns (the identity's five, zeros), then
                   * R_Y on rows 1 and 2 (T^T) and on columns 1 and 2 (T) */
        for (i = 0; i < SR_NV; ++i)
            for (k = 0; k < 8; ++k) g[i][k] = i == k ? 1 : 0;
        joint_first_solve(&jf, g, 8);
        for (i = 0; i < SR_NV; ++i) {
            const sr_real y1 = g[i][1], y2 = g[i][2];
            g[i][1] = c * y1 - s * y2;
            g[i][2] = s * y1 + c * y2;
        }
        for (k = 0; k < SR_NV; ++k) {
            minv[k] = g[0][k];
            minv[SR_NV + k] = c * g[1][k] - s * g[2][k];
            minv[2 * SR_NV + k] = s * g[1][k] + c * g[2][k];
            minv[3 * SR_NV + k] = g[3][k];
            minv[4 * SR_NV + k] = g[4][k];
        }
    }
    return SR_OK;
}

int sr_internal_accel_jacobian_minv(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                    sr_real a[SR_NV], sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU],
                                    sr_real *Minv)
{
    return model->general ? general_accel_jacobian(model, x, u, a, Ja, Jb, Minv)
                          : paper_accel_jacobian(model, x, u, a, Ja, Jb, Minv);
}

int sr_internal_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                               sr_real a[SR_NV], sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU])
{
    return sr_internal_accel_jacobian_minv(model, x, u, a, Ja, Jb, NULL);
}

/* out = Ja V on the read rows (see sr_jacobians.h), the paper's robot: the chain rule of
 * paper_accel_jacobian applied to the directions V instead of to the unit ones, so that the
 * shell-frame Ja is never formed.  With z the yoke frame's directions (d_xi', d_th_P, d_nu'),
 *   z_xi' = R_Y^T V_xi + e_x V_th_Y,   z_th_P = V_th_P,
 *   z_w'  = R_Y^T V_w + (w' x e_x) V_th_Y,   z_w_Y, z_w_P = V_w_Y, V_w_P,
 * and out = T^T (G z) + R_Y (e_x x g_S) V_th_Y, G = M'^-1 (df' - (dM') g) as there.  Its first lines,
 * up to G, repeat paper_accel_jacobian's on purpose: the same lines as one helper of both, inlined,
 * makes the RKMK4 and CF4 step Jacobians 0.1 us slower with GCC 12 (AMD EPYC Zen 4). */
static int paper_accel_jacobian_along(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                      const sr_real V[SR_J_READ][SR_J_NC], sr_real acc[SR_NV],
                                      sr_real out[SR_NV][SR_J_NC], sr_real jb[SR_NV * SR_NU])
{
    enum { NZ = 9 };   /* the yoke frame's directions: Y_XI (3), Y_TH_P, Y_W (5) */
    const sr_real c = x[SR_X_R_Y + 4], s = x[SR_X_R_Y + 7];
    const sr_real *w = x + SR_X_w_S;
    const sr_real wy = c * w[1] + s * w[2], wz = c * w[2] - s * w[1];   /* w' = R_Y^T w_S */
    sr_real Mu[15], f[SR_NV], df[SR_NV * 9], dfdu[SR_NV * SR_NU], dM[4 * 15];
    sr_real g[SR_NV][NCOL], B[SR_NV][NCOL], Z[NZ][SR_J_NC], o[SR_NV][SR_J_NC];
    joint_first jf;
    int status, i, k, l;
    status = sr_gen_accel_jacobian_yoke_terms(model->c, x, u, Mu, f, df, dfdu, dM);
    if (status != SR_OK) return status;
    status = joint_first_factor(Mu, &jf);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) g[i][0] = f[i];
    joint_first_solve(&jf, g, 1);
    acc[0] = g[0][0];
    acc[1] = c * g[1][0] - s * g[2][0];
    acc[2] = s * g[1][0] + c * g[2][0];
    acc[3] = g[3][0];
    acc[4] = g[4][0];
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < 9; ++k) B[i][k] = df[9 * i + k];
        for (k = 0; k < SR_NU; ++k) B[i][Y_U + k] = dfdu[SR_NU * i + k];
        B[i][Y_NCOL] = 0;
    }
    subtract_dM_g(dM, (const sr_real(*)[NCOL])g, B);
    joint_first_solve(&jf, B, Y_SOLVED);
    for (l = 0; l < SR_J_NC; ++l) {
        const sr_real vY = V[SR_J_TH_Y][l];
        Z[Y_XI + 0][l] = V[SR_J_XI + 0][l] + vY;
        Z[Y_XI + 1][l] = c * V[SR_J_XI + 1][l] + s * V[SR_J_XI + 2][l];
        Z[Y_XI + 2][l] = c * V[SR_J_XI + 2][l] - s * V[SR_J_XI + 1][l];
        Z[Y_TH_P][l] = V[SR_J_TH_P][l];
        Z[Y_W + 0][l] = V[SR_J_NU + 0][l];
        Z[Y_W + 1][l] = (c * V[SR_J_NU + 1][l] + s * V[SR_J_NU + 2][l]) + wz * vY;
        Z[Y_W + 2][l] = (c * V[SR_J_NU + 2][l] - s * V[SR_J_NU + 1][l]) - wy * vY;
        Z[Y_W + 3][l] = V[SR_J_NU + 3][l];
        Z[Y_W + 4][l] = V[SR_J_NU + 4][l];
    }
    for (i = 0; i < SR_NV; ++i) {   /* o = G z, row by row over the contiguous columns */
        for (l = 0; l < SR_J_NC; ++l) o[i][l] = B[i][0] * Z[0][l];
        for (k = 1; k < NZ; ++k)
            for (l = 0; l < SR_J_NC; ++l) o[i][l] += B[i][k] * Z[k][l];
    }
    {
        const sr_real e1 = -(c * g[2][0] + s * g[1][0]), e2 = c * g[1][0] - s * g[2][0];   /* R_Y (e_x x g_S) */
        for (l = 0; l < SR_J_NC; ++l) {
            const sr_real vY = V[SR_J_TH_Y][l];
            out[0][l] = o[0][l];
            out[1][l] = (c * o[1][l] - s * o[2][l]) + e1 * vY;
            out[2][l] = (s * o[1][l] + c * o[2][l]) + e2 * vY;
            out[3][l] = o[3][l];
            out[4][l] = o[4][l];
        }
    }
    for (k = 0; k < SR_NU; ++k) {
        jb[SR_NU * 0 + k] = B[0][Y_U + k];
        jb[SR_NU * 1 + k] = c * B[1][Y_U + k] - s * B[2][Y_U + k];
        jb[SR_NU * 2 + k] = s * B[1][Y_U + k] + c * B[2][Y_U + k];
        jb[SR_NU * 3 + k] = B[3][Y_U + k];
        jb[SR_NU * 4 + k] = B[4][Y_U + k];
    }
    return SR_OK;
}

/* The general robot: Ja itself, then its read columns times V. */
static int general_accel_jacobian_along(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                        const sr_real V[SR_J_READ][SR_J_NC], sr_real acc[SR_NV],
                                        sr_real out[SR_NV][SR_J_NC], sr_real jb[SR_NV * SR_NU])
{
    static const unsigned char column[SR_J_READ] = {SR_E_xi_S + 0, SR_E_xi_S + 1, SR_E_xi_S + 2, SR_E_th_Y,
                                                   SR_E_th_P, SR_E_nu + 0, SR_E_nu + 1, SR_E_nu + 2,
                                                   SR_E_nu + 3, SR_E_nu + 4};
    sr_real ja[SR_NV * SR_NE];
    int i, k, l, status = general_accel_jacobian(model, x, u, acc, ja, jb, NULL);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) {
        sr_real o[SR_J_NC];
        for (l = 0; l < SR_J_NC; ++l) o[l] = 0;
        for (k = 0; k < SR_J_READ; ++k) {
            const sr_real jik = ja[SR_NE * i + column[k]];
            for (l = 0; l < SR_J_NC; ++l) o[l] += jik * V[k][l];
        }
        memcpy(out[i], o, sizeof o);
    }
    return SR_OK;
}

SR_JACOBIAN_CLONES int sr_internal_accel_jacobian_along(const sr_model *model, const sr_real x[SR_NX],
                                                        const sr_real u[SR_NU], const sr_real V[SR_J_READ][SR_J_NC],
                                                        sr_real a[SR_NV], sr_real out[SR_NV][SR_J_NC],
                                                        sr_real Jb[SR_NV * SR_NU])
{
    return model->general ? general_accel_jacobian_along(model, x, u, V, a, out, Jb)
                          : paper_accel_jacobian_along(model, x, u, V, a, out, Jb);
}

int sr_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                      sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU])
{
    sr_real a[SR_NV], ja[SR_NV * SR_NE], jb[SR_NV * SR_NU];
    int status = arg_model(model, READS(JACOBIAN));
    if (status != SR_OK) return status;
    if (!Ja || !Jb) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    status = sr_internal_accel_jacobian(model, x, u ? u : sr_zero_u, a, ja, jb);
    if (status != SR_OK) return status;
    if (!all_finite(ja, SR_NV * SR_NE) || !all_finite(jb, SR_NV * SR_NU)) return SR_ERR_NONFINITE;
    memcpy(Ja, ja, sizeof ja);
    memcpy(Jb, jb, sizeof jb);
    return SR_OK;
}

int sr_accel_jacobian_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                            sr_real *Ja, sr_real *Jb, long *failed_row)
{
    long i;
    int status = arg_model(model, READS(JACOBIAN));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && Ja && Jb);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_accel_jacobian(model, x + i * SR_NX, u ? u + i * SR_NU : NULL,
                                             Ja + i * SR_NV * SR_NE, Jb + i * SR_NV * SR_NU);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_internal_step_jacobian_lie_euler_minv(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                             sr_real dt, sr_real F[SR_NE * SR_NE], sr_real *G, sr_real *Minv)
{
    const sr_real *w, *R;
    sr_real a[SR_NV], Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU], phi[3], D[9], Jr[9], f[SR_NE * SR_NE], g[SR_NE * SR_NU];
    sr_real v[2][3], r;
    int status = sr_internal_accel_jacobian_minv(model, x, u, a, Ja, Jb, Minv), i, j;
    if (status != SR_OK) return status;
    w = x + SR_X_w_S;
    R = x + SR_X_R_S;
    r = model->p[SR_P_r];
    memset(f, 0, sizeof f);
    memset(g, 0, sizeof g);
    for (i = 0; i < 3; ++i) phi[i] = dt * w[i];
    so3_exp_minus_identity(phi, D);
    so3_right_jacobian(phi, Jr);
    /* R_S Exp(d_xi) Exp(h(w + d_w)) = R_S Exp(h w) Exp(Exp(h w)^T d_xi + h Jr(h w) d_w): */
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            f[SR_NE * (SR_E_xi_S + i) + SR_E_xi_S + j] = (i == j ? 1 : 0) + D[3 * j + i];
            f[SR_NE * (SR_E_xi_S + i) + SR_E_nu + j] = dt * Jr[3 * i + j];
        }
    /* the joint angles advance by h w_Y, h w_P */
    f[SR_NE * SR_E_th_Y + SR_E_th_Y] = 1;
    f[SR_NE * SR_E_th_Y + SR_E_nu + 3] = dt;
    f[SR_NE * SR_E_th_P + SR_E_th_P] = 1;
    f[SR_NE * SR_E_th_P + SR_E_nu + 4] = dt;
    /* q advances by h r ((R_S w) x e_z) in the plane: d(R_S w) = R_S (d_w - w x d_xi); the rows
     * (v_y, -v_x) of that, v[k] = row k of r R_S (k = 0, 1). */
    for (j = 0; j < 3; ++j) {
        v[0][j] = r * R[3 + j];       /* q_x' = r (R_S w)_y */
        v[1][j] = -r * R[j];          /* q_y' = -r (R_S w)_x */
    }
    for (i = 0; i < 2; ++i) {
        const sr_real *p = v[i];
        f[SR_NE * (SR_E_q + i) + SR_E_q + i] = 1;
        for (j = 0; j < 3; ++j) f[SR_NE * (SR_E_q + i) + SR_E_nu + j] = dt * p[j];
        /* -p . (w x d_xi) = (w x p) . d_xi */
        f[SR_NE * (SR_E_q + i) + SR_E_xi_S + 0] = dt * (w[1] * p[2] - w[2] * p[1]);
        f[SR_NE * (SR_E_q + i) + SR_E_xi_S + 1] = dt * (w[2] * p[0] - w[0] * p[2]);
        f[SR_NE * (SR_E_q + i) + SR_E_xi_S + 2] = dt * (w[0] * p[1] - w[1] * p[0]);
    }
    /* nu advances by h nu'(x, u) */
    for (i = 0; i < SR_NV; ++i) {
        for (j = 0; j < SR_NE; ++j) f[SR_NE * (SR_E_nu + i) + j] = dt * Ja[SR_NE * i + j];
        f[SR_NE * (SR_E_nu + i) + SR_E_nu + i] += 1;
        for (j = 0; j < SR_NU; ++j) g[SR_NU * (SR_E_nu + i) + j] = dt * Jb[SR_NU * i + j];
    }
    if (!all_finite(f, SR_NE * SR_NE) || !all_finite(g, SR_NE * SR_NU)) return SR_ERR_NONFINITE;
    memcpy(F, f, sizeof f);
    if (G) memcpy(G, g, sizeof g);
    return SR_OK;
}

int sr_internal_step_jacobian_lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                        sr_real dt, sr_real F[SR_NE * SR_NE], sr_real *G)
{
    return sr_internal_step_jacobian_lie_euler_minv(model, x, u, dt, F, G, NULL);
}

int sr_step_jacobian_lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                               sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU])
{
    const int status = sr_internal_check_step_arguments(model, x, u, dt, F, G);
    if (status != SR_OK) return status;
    return sr_internal_step_jacobian_lie_euler(model, x, u ? u : sr_zero_u, dt, F, G);   /* checked above */
}

int sr_step_jacobian_lie_euler_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real dt,
                                     sr_real *F, sr_real *G, long *failed_row)
{
    long i;
    int status = arg_model(model, READS(JACOBIAN) | READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && F && G);
    if (status == SR_OK) status = arg_dt(dt);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_step_jacobian_lie_euler(model, x + i * SR_NX, u ? u + i * SR_NU : NULL, dt,
                                                      F + i * SR_NE * SR_NE, G + i * SR_NE * SR_NU);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
