/*
 * sr_param_jacobians.c -- derivatives in the parameters: of the accelerations, of one step of
 * Lie-Euler or RKMK4, and the regressor form of the equations of motion.
 *
 * With the state and the torques held, M nu' = f gives d(nu')/dp = -M^-1 d(M nu' - f)/dp, nu'
 * held in the bracket (derive/param_derivatives.py): one generated kernel for the bracket, the
 * general robot's M and f and its Cholesky factor for the solve.  A robot of the paper's geometry
 * is evaluated with the general kernels too (its general constants computed per call), so that
 * every parameter, the ones the paper's kernels fold into constants included, has its column.
 *
 * A step's sensitivity follows the stages of sr_steppers.c with the state held (x fixed, so its
 * error enters nowhere): for the action y = x . exp(th), y (-) y0 = B(th) dth with B of
 * sr_step_jacobians.c; for the vector field at a stage state y, df = J_f(y) dy + df/dp(y), where
 * df/dp has the accelerations' rows and, since q' = r (R_S w) x e_z, q'/r in the column of r;
 * and RKMK4's dexp^-1 on the SO(3) block, dk_S = P df_S + Q dth_S (sr_dexpinv.h).
 *
 * The columns are independent all the way: a sensitivity to a few parameters (the free ones of a
 * fit) runs the same stages on those columns only.
 */
#include "sr_checks.h"
#include "sr_dexpinv.h"
#include "sr_finite.h"
#include "sr_jacobians.h"
#include "sr_kernels.h"
#include "sr_steppers.h"
#include "sr_argcheck.h"

#include <string.h>

#define NP SR_NPARAM

typedef sr_real tangent_p[SR_NT][NP];   /* d(13-vector)/dp */
typedef sr_real error_p[SR_NE][NP];     /* d(state error)/dp */

/* The columns computed: n of them; cols[c] the SR_P_* of column c, or cols NULL for all in order
 * (the whole bracket by one kernel); r_col the column of r, or -1. */
typedef struct {
    int n, r_col;
    const int *cols;
} colset;

static const colset ALL_COLUMNS = {NP, SR_P_r, NULL};

/* The set of ncols columns cols (checked by the caller: 1 <= ncols <= NP, each an index of p). */
static colset columns_of(int ncols, const int *cols)
{
    colset s;
    int c;
    s.n = ncols;
    s.cols = cols;
    s.r_col = -1;
    for (c = ncols - 1; c >= 0; --c)
        if (cols[c] == SR_P_r) s.r_col = c;
    return s;
}

/* SR_OK if 1 <= ncols <= NP, cols not NULL and each of its entries an index of p. */
static int arg_columns(int ncols, const int *cols)
{
    int c;
    if (!cols) return SR_ERR_NULL;
    if (ncols < 1 || ncols > NP) return SR_ERR_ARG;
    for (c = 0; c < ncols; ++c)
        if (cols[c] < 0 || cols[c] >= NP) return SR_ERR_ARG;
    return SR_OK;
}

/* The general kernels' constants of any robot: the model's own for a general one; the paper's
 * kernels fold parameters into constants, so for its robot they are computed (once per call of an
 * entry point: a step's stages share them). */
static const sr_real *general_constants(const sr_model *model, sr_real cg[SR_GEN_GENERAL_NCONST])
{
    if (model->general) return model->cg;
    sr_gen_general_constants(model->p, cg);
    return cg;
}

/* d(M nu' - f)/dp on the columns cs (dR row-major SR_NV x NP, its first cs->n columns), nu' = a held:
 * the generated bracket, its chosen columns moved to the front. */
static int residual_columns(const sr_model *model, const colset *cs, const sr_real x[SR_NX], const sr_real a[SR_NV],
                            sr_real dR[SR_NV * NP])
{
    sr_real all[SR_NV * NP];
    int i, c, status;
    if (!cs->cols) return sr_gen_general_param_residual_jacobian(model->p, x, a, dR);
    status = sr_gen_general_param_residual_jacobian(model->p, x, a, all);
    for (i = 0; i < SR_NV && status == SR_OK; ++i)
        for (c = 0; c < cs->n; ++c) dR[NP * i + c] = all[NP * i + cs->cols[c]];
    return status;
}

/* B <- M^-1 B on the first nc columns, M = L L^T (sr_internal_cholesky). */
static void solve_columns(const sr_real L[SR_NV * SR_NV], const sr_real inv[SR_NV], int nc, sr_real B[SR_NV][NP])
{
    int i, k, c;
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < i; ++k)
            for (c = 0; c < nc; ++c) B[i][c] -= L[SR_NV * i + k] * B[k][c];
        for (c = 0; c < nc; ++c) B[i][c] *= inv[i];
    }
    for (i = SR_NV - 1; i >= 0; --i) {
        for (k = i + 1; k < SR_NV; ++k)
            for (c = 0; c < nc; ++c) B[i][c] -= L[SR_NV * k + i] * B[k][c];
        for (c = 0; c < nc; ++c) B[i][c] *= inv[i];
    }
}

/* A general robot's stage: nu' = a and its whole derivative along the stage's dy on the columns
 * cs, D = Ja dy + d(nu')/dp = M^-1 ((df - (dM) a) dy - d(M nu' - f)/dp), from one kernel for M, f
 * and their state derivatives and one factorisation: Ja itself is never formed, and the solve runs
 * on the few columns only. */
static int general_stage_rows(const sr_model *model, const colset *cs, const sr_real y[SR_NX],
                              const sr_real u[SR_NU], const error_p dy, sr_real a[SR_NV], sr_real D[SR_NV][NP])
{
    sr_real Mu[15], f[SR_NV], df[SR_NV * SR_NE], dfdu[SR_NV * SR_NU], dM[5 * 15], L[SR_NV * SR_NV], inv[SR_NV];
    sr_real g[SR_NV][SR_NE], dR[SR_NV * NP];
    const int nc = cs->n;
    int i, j, k, c, status = sr_internal_general_accel_jacobian_terms(model, y, u, Mu, f, df, dfdu, dM);
    if (status == SR_OK) status = sr_internal_cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) {   /* a = M^-1 f */
        sr_real t = f[i];
        for (k = 0; k < i; ++k) t -= L[SR_NV * i + k] * a[k];
        a[i] = t * inv[i];
    }
    for (i = SR_NV - 1; i >= 0; --i) {
        sr_real t = a[i];
        for (k = i + 1; k < SR_NV; ++k) t -= L[SR_NV * k + i] * a[k];
        a[i] = t * inv[i];
    }
    status = residual_columns(model, cs, y, a, dR);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) {
        for (k = 0; k < SR_NE; ++k) g[i][k] = df[SR_NE * i + k];
        for (k = 0; k < 5; ++k)   /* the configuration directions d_xi_S, d_th_Y, d_th_P move M */
            for (j = 0; j < SR_NV; ++j) g[i][k] -= dM[15 * k + SR_UPPER[i][j]] * a[j];
        for (c = 0; c < nc; ++c) D[i][c] = -dR[NP * i + c];
        for (k = 0; k < SR_NE; ++k) {
            const sr_real m = g[i][k];
            if (k == SR_E_q || k == SR_E_q + 1) continue;   /* nothing depends on q */
            for (c = 0; c < nc; ++c) D[i][c] += m * dy[k][c];
        }
    }
    solve_columns(L, inv, nc, D);
    return SR_OK;
}

/* nu' and d(nu')/dp on the columns cs at a state the caller checked (u not NULL), the general
 * kernels' constants given; J row-major SR_NV x NP, its first cs->n columns written. */
static int accel_param_jacobian(const sr_model *model, const sr_real *constants, const colset *cs,
                                const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV],
                                sr_real J[SR_NV][NP])
{
    sr_real Mu[15], f[SR_NV], L[SR_NV * SR_NV], inv[SR_NV], dR[SR_NV * NP];
    const int nc = cs->n;
    int i, k, c, status;
    status = sr_gen_general_system(constants, x, u, Mu, f);
    if (status == SR_OK) status = sr_internal_cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) {   /* a = M^-1 f */
        sr_real s = f[i];
        for (k = 0; k < i; ++k) s -= L[SR_NV * i + k] * a[k];
        a[i] = s * inv[i];
    }
    for (i = SR_NV - 1; i >= 0; --i) {
        sr_real s = a[i];
        for (k = i + 1; k < SR_NV; ++k) s -= L[SR_NV * k + i] * a[k];
        a[i] = s * inv[i];
    }
    status = residual_columns(model, cs, x, a, dR);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i)
        for (c = 0; c < nc; ++c) J[i][c] = -dR[NP * i + c];
    solve_columns(L, inv, nc, J);   /* J = -M^-1 dR */
    return SR_OK;
}

int sr_accel_param_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                            sr_real J[SR_NV * SR_NPARAM])
{
    sr_real a[SR_NV], j[SR_NV][NP], cg[SR_GEN_GENERAL_NCONST];
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!x || !J) return SR_ERR_NULL;
    status = sr_internal_check_state(model, x);
    if (status == SR_OK && u && !all_finite(u, SR_NU)) status = SR_ERR_NONFINITE;
    if (status == SR_OK)
        status = accel_param_jacobian(model, general_constants(model, cg), &ALL_COLUMNS, x, u ? u : sr_zero_u, a, j);
    if (status != SR_OK) return status;
    if (!all_finite_long(&j[0][0], SR_NV * NP)) return SR_ERR_NONFINITE;
    memcpy(J, j, sizeof j);
    return SR_OK;
}

int sr_accel_param_jacobian_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real *J,
                                  long *failed_row)
{
    long i;
    int status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && J);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_accel_param_jacobian(model, x + i * SR_NX, u ? u + i * SR_NU : NULL, J + i * SR_NV * NP);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* ---- one step ------------------------------------------------------------------------------- */

/* dy = B(th) dth on the first nc columns: the error of y = x . exp(th) along p with x held (q_z
 * does not move). */
static void action_rows(int nc, const sr_real th[SR_NT], const tangent_p dth, error_p dy)
{
    const size_t row = (size_t)nc * sizeof(sr_real);
    sr_real Jr[9];
    int i, c;
    so3_right_jacobian(th + SR_T_S, Jr);
    for (i = 0; i < 3; ++i)
        for (c = 0; c < nc; ++c)
            dy[SR_E_xi_S + i][c] = Jr[3 * i] * dth[SR_T_S][c] + Jr[3 * i + 1] * dth[SR_T_S + 1][c]
                                   + Jr[3 * i + 2] * dth[SR_T_S + 2][c];
    memcpy(dy[SR_E_th_Y], dth[SR_T_Y], row);
    memcpy(dy[SR_E_th_P], dth[SR_T_P], row);
    for (i = 0; i < 2; ++i) memcpy(dy[SR_E_q + i], dth[SR_T_Q + i], row);
    for (i = 0; i < SR_NV; ++i) memcpy(dy[SR_E_nu + i], dth[SR_T_V + i], row);
}

/* The vector field f at y and df = J_f(y) dy + df/dp(y) on the columns cs (dy NULL: y is the
 * step's start, dy = 0). */
static int field_rows(const sr_model *model, const sr_real *constants, const colset *cs, const sr_real y[SR_NX],
                      const sr_real u[SR_NU], const error_p dy, sr_real f[SR_NT], tangent_p df)
{
    const sr_real *R = y + SR_X_R_S, *w = y + SR_X_w_S, r = model->p[SR_P_r];
    const int nc = cs->n;
    const size_t row = (size_t)nc * sizeof(sr_real);
    sr_real a[SR_NV], Jp[SR_NV][NP], Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU], p[2][3], wxp[2][3];
    int i, j, c, status;
    const int general_stage = dy && model->general;
    sr_internal_kinematics(model, y, f);
    if (general_stage) status = general_stage_rows(model, cs, y, u, dy, f + SR_T_V, Jp);
    else status = accel_param_jacobian(model, constants, cs, y, u, f + SR_T_V, Jp);
    if (status == SR_OK && dy && !general_stage) status = sr_internal_accel_jacobian(model, y, u, a, Ja, Jb);
    /* A stage state that overflowed fails the pivot test (NaN): report what happened. */
    if (status != SR_OK) return status == SR_ERR_SINGULAR && !all_finite(y, SR_NX) ? SR_ERR_NONFINITE : status;
    for (i = 0; i < SR_T_V; ++i) memset(df[i], 0, row);
    for (i = 0; i < SR_NV; ++i) memcpy(df[SR_T_V + i], Jp[i], row);
    if (cs->r_col >= 0)   /* q' is linear in r */
        for (i = 0; i < 2; ++i) df[SR_T_Q + i][cs->r_col] = f[SR_T_Q + i] / r;
    if (!dy) return SR_OK;
    for (i = 0; i < 3; ++i) memcpy(df[SR_T_S + i], dy[SR_E_nu + i], row);   /* th_S' = w_S */
    memcpy(df[SR_T_Y], dy[SR_E_nu + 3], row);
    memcpy(df[SR_T_P], dy[SR_E_nu + 4], row);
    for (j = 0; j < 3; ++j) {   /* d(q') = p . dw + (w x p) . dxi, as in sr_step_jacobian_lie_euler */
        p[0][j] = r * R[3 + j];
        p[1][j] = -r * R[j];
    }
    for (i = 0; i < 2; ++i) {
        wxp[i][0] = w[1] * p[i][2] - w[2] * p[i][1];
        wxp[i][1] = w[2] * p[i][0] - w[0] * p[i][2];
        wxp[i][2] = w[0] * p[i][1] - w[1] * p[i][0];
        for (j = 0; j < 3; ++j)
            for (c = 0; c < nc; ++c)
                df[SR_T_Q + i][c] += p[i][j] * dy[SR_E_nu + j][c] + wxp[i][j] * dy[SR_E_xi_S + j][c];
    }
    for (i = 0; i < SR_NV && !general_stage; ++i)   /* the accelerations: Ja dy (q's columns of Ja are zero) */
        for (j = 0; j < SR_NE; ++j) {
            const sr_real m = Ja[SR_NE * i + j];
            if (j == SR_E_q || j == SR_E_q + 1) continue;
            for (c = 0; c < nc; ++c) df[SR_T_V + i][c] += m * dy[j][c];
        }
    return SR_OK;
}

/* RKMK4 with the state held: K1 = f(x), K_s = dexp^-1(th_s, f(x . exp(th_s))), th_s = a_s h K_(s-1),
 * x_new = x . exp(sum_k b_k K_k); dy the error of x_new along p.  Only the last stage's dK is kept
 * and the combination sum_k b_k dK_k is summed as the stages go (in the combine's order): a
 * quarter of the stack, which keeps the working set in L1. */
static int rkmk4_param(const sr_model *model, const colset *cs, const sr_real x[SR_NX], const sr_real u[SR_NU],
                       sr_real h, error_p dy)
{
    static const sr_real a_diag[3] = {SR_C(0.5), SR_C(0.5), SR_C(1.0)};
    const sr_real b[4] = {h / 6, h / 3, h / 3, h / 6};
    const int nc = cs->n;
    sr_real K[4][SR_NT], th[SR_NT], D[9], y[SR_NX], cg[SR_GEN_GENERAL_NCONST];
    const sr_real *constants = general_constants(model, cg);
    tangent_p dK, dth, dsum;
    error_p dstage;
    int s, i, c, status = field_rows(model, constants, cs, x, u, NULL, K[0], dK);
    for (i = 0; i < SR_NT; ++i)
        for (c = 0; c < nc; ++c) dsum[i][c] = b[0] * dK[i][c];
    for (s = 1; s < 4 && status == SR_OK; ++s) {
        const sr_real hs = a_diag[s - 1] * h;
        for (i = 0; i < SR_NT; ++i) th[i] = hs * K[s - 1][i];
        for (i = 0; i < SR_NT; ++i)
            for (c = 0; c < nc; ++c) dth[i][c] = hs * dK[i][c];
        so3_exp_minus_identity(th + SR_T_S, D);
        act_increment(x, D, th, NULL, y);   /* the stepper's stage state */
        action_rows(nc, th, (const sr_real(*)[NP])dth, dstage);
        status = field_rows(model, constants, cs, y, u, (const sr_real(*)[NP])dstage, K[s], dK);
        if (status == SR_OK) {   /* k_S = dexp^-1(th, f_S): dk_S = P df_S + Q dth_S */
            sr_real P[9], Q[9], kS[3], dS[3][NP];
            int j;
            dexpinv_and_derivatives(th, K[s], kS, P, Q);
            for (i = 0; i < 3; ++i)
                for (c = 0; c < nc; ++c) {
                    dS[i][c] = 0;
                    for (j = 0; j < 3; ++j) dS[i][c] += P[3 * i + j] * dK[SR_T_S + j][c] + Q[3 * i + j] * dth[SR_T_S + j][c];
                }
            for (i = 0; i < 3; ++i) {
                K[s][SR_T_S + i] = kS[i];
                memcpy(dK[SR_T_S + i], dS[i], (size_t)nc * sizeof(sr_real));
            }
            for (i = 0; i < SR_NT; ++i)
                for (c = 0; c < nc; ++c) dsum[i][c] += b[s] * dK[i][c];
        }
    }
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NT; ++i) {   /* as the stepper's combine */
        th[i] = 0;
        for (s = 0; s < 4; ++s) th[i] += b[s] * K[s][i];
    }
    action_rows(nc, th, (const sr_real(*)[NP])dsum, dy);
    return SR_OK;
}

/* Lie-Euler: x_new = x . exp(h f(x)). */
static int lie_euler_param(const sr_model *model, const colset *cs, const sr_real x[SR_NX], const sr_real u[SR_NU],
                           sr_real h, error_p dy)
{
    sr_real f[SR_NT], th[SR_NT], cg[SR_GEN_GENERAL_NCONST];
    tangent_p df;
    int i, c, status = field_rows(model, general_constants(model, cg), cs, x, u, NULL, f, df);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NT; ++i) {
        th[i] = h * f[i];
        for (c = 0; c < cs->n; ++c) df[i][c] *= h;
    }
    action_rows(cs->n, th, (const sr_real(*)[NP])df, dy);
    return SR_OK;
}

/* The step's sensitivity on the columns cs at a state not yet checked (u may be NULL); dy's first
 * cs->n columns written. */
static int step_param(const sr_model *model, const colset *cs, int method, const sr_real x[SR_NX],
                      const sr_real u[SR_NU], sr_real dt, error_p dy)
{
    int status = sr_internal_check_state(model, x);
    if (status == SR_OK && u && !all_finite(u, SR_NU)) status = SR_ERR_NONFINITE;
    if (status != SR_OK) return status;
    if (!u) u = sr_zero_u;
    return method == SR_LIE_EULER ? lie_euler_param(model, cs, x, u, dt, dy) : rkmk4_param(model, cs, x, u, dt, dy);
}

int sr_step_param_jacobian(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                           sr_real dt, sr_real Jp[SR_NE * SR_NPARAM])
{
    error_p dy;
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!x || !Jp) return SR_ERR_NULL;
    if ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK) return SR_ERR_ARG;
    status = step_param(model, &ALL_COLUMNS, method, x, u, dt, dy);
    if (status != SR_OK) return status;
    if (!all_finite_long(&dy[0][0], SR_NE * NP)) return SR_ERR_NONFINITE;
    memcpy(Jp, dy, sizeof dy);
    return SR_OK;
}

int sr_step_param_jacobian_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                 sr_real dt, sr_real *Jp, long *failed_row)
{
    long i;
    int status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && Jp);
    if (status == SR_OK && ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK)) status = SR_ERR_ARG;
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_step_param_jacobian(model, method, x + i * SR_NX, u ? u + i * SR_NU : NULL, dt,
                                        Jp + i * SR_NE * NP);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_step_param_jacobian_cols_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                      sr_real dt, int ncols, const int *cols, sr_real *Jp, long *failed_row)
{
    colset cs;
    error_p dy;
    long i;
    int k, c, status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_columns(ncols, cols);
    if (status == SR_OK) status = arg_rows(n, x && Jp);
    if (status == SR_OK && ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK)) status = SR_ERR_ARG;
    if (status != SR_OK) return status;
    cs = columns_of(ncols, cols);
    for (i = 0; i < n; ++i) {
        sr_real *out = Jp + i * SR_NE * ncols;
        status = step_param(model, &cs, method, x + i * SR_NX, u ? u + i * SR_NU : NULL, dt, dy);
        for (k = 0; k < SR_NE && status == SR_OK; ++k) {
            if (!all_finite(dy[k], ncols)) status = SR_ERR_NONFINITE;
            for (c = 0; c < ncols; ++c) out[k * ncols + c] = dy[k][c];
        }
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_accel_param_jacobian_cols_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, int ncols,
                                       const int *cols, sr_real *J, long *failed_row)
{
    colset cs;
    sr_real a[SR_NV], j[SR_NV][NP], cg[SR_GEN_GENERAL_NCONST];
    const sr_real *constants;
    long i;
    int k, c, status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_columns(ncols, cols);
    if (status == SR_OK) status = arg_rows(n, x && J);
    if (status != SR_OK) return status;
    cs = columns_of(ncols, cols);
    constants = general_constants(model, cg);
    for (i = 0; i < n; ++i) {
        const sr_real *ui = u ? u + i * SR_NU : NULL;
        sr_real *out = J + i * SR_NV * ncols;
        status = sr_internal_check_state(model, x + i * SR_NX);
        if (status == SR_OK && ui && !all_finite(ui, SR_NU)) status = SR_ERR_NONFINITE;
        if (status == SR_OK) status = accel_param_jacobian(model, constants, &cs, x + i * SR_NX, ui ? ui : sr_zero_u, a, j);
        for (k = 0; k < SR_NV && status == SR_OK; ++k) {
            if (!all_finite(j[k], ncols)) status = SR_ERR_NONFINITE;
            for (c = 0; c < ncols; ++c) out[k * ncols + c] = j[k][c];
        }
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* ---- the regressor -------------------------------------------------------------------------- */

int sr_regressor(const sr_model *model, const sr_real x[SR_NX], const sr_real nudot[SR_NV],
                 sr_real Y[SR_NV * SR_NPI])
{
    sr_real y[SR_NV * SR_NPI];
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!x || !nudot || !Y) return SR_ERR_NULL;
    status = sr_internal_check_state(model, x);
    if (status == SR_OK && !all_finite(nudot, SR_NV)) status = SR_ERR_NONFINITE;
    if (status == SR_OK) status = sr_gen_regressor(model->p, x, nudot, y);
    if (status != SR_OK) return status;
    memcpy(Y, y, sizeof y);
    return SR_OK;
}

int sr_regressor_batch(const sr_model *model, long n, const sr_real *x, const sr_real *nudot, sr_real *Y,
                       long *failed_row)
{
    long i;
    int status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && nudot && Y);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_regressor(model, x + i * SR_NX, nudot + i * SR_NV, Y + i * SR_NV * SR_NPI);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
