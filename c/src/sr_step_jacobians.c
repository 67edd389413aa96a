/*
 * sr_step_jacobians.c -- the Jacobians F, G of one RKMK4 or CF4 step in the error coordinates:
 * step(x (+) d, u + w) (-) step(x, u) = F d + G w + O(2), the exact derivatives of
 * the maps of sr_steppers.c as they are implemented (stage by stage, dexp^-1 differentiated).
 *
 * Every quantity of a step carries its derivative with respect to (d, w): a matrix of
 * NC columns (see below).  The rules, for the action y = x . exp(th) of c/src/sr_steppers.c:
 *   y (-) y0 = A(th) (x (-) x0) + B(th) dth,   A = diag(Exp(th_S)^T, 1, 1, I_2, I_5),
 *                                              B = diag(Jr(th_S), 1, 1, [I_2 0], I_5)
 * (the right Jacobian Jr of SO(3); q_z does not move); for the vector field f of
 * sr_internal_vector_field at a stage state y with error e: df = J_f(y) e + [0 | J_u] w, from
 * sr_internal_accel_jacobian(_along) (the accelerations) and the rolling kinematics (q' = r (R_S w) x e_z, as in
 * sr_step_jacobian_lie_euler); and for k = dexp^-1(th, f) = f + th x f / 2 + c(|th|^2) th x (th x f)
 * on the SO(3) block: dk = (I + [th]/2 + c [th]^2) df + (-[f]/2 + c ((th.f) I + th f^T - 2 f th^T)
 * + 2 c'(|th|^2) (th x (th x f)) th^T) dth.
 */
#include "sr_finite.h"
#include "sr_jacobians.h"
#include "sr_so3.h"
#include "sr_dexpinv.h"
#include "sr_steppers.h"
#include "sr_argcheck.h"
#include "sr_step_jacobians.h"

#include <string.h>

/* The columns carried: every direction of (d, w) but the two of dq.  Nothing in a step depends
 * on where the robot stands (q enters neither the accelerations nor q' itself), so every
 * derivative along dq is exactly 0 but that of q (+) itself, the identity; deliver_jacobians
 * writes those columns.  Carrying 12 columns instead of 14, and skipping the dq rows in the
 * products with the accelerations' Jacobian (whose dq columns are exact zeros), gives the same
 * numbers with a sixth less work.  Column a of the carried ones is column full_column(a) of
 * [F | G]. */
#define NC (SR_NE + SR_NU - 2)
#define full_column(a) ((a) < SR_E_q ? (a) : (a) + 2)
#define NU_COLUMN(i) (SR_E_nu - 2 + (i))   /* the carried column of d_nu_i */

typedef sr_real tangent[SR_NT][NC];   /* d(13-vector)/d(d, w), carried columns */
typedef sr_real error[SR_NE][NC];     /* d(state error)/d(d, w), carried columns */

/* out = scale M in (add 0) or out += scale M in (add 1) for nr rows of NC columns, M nr x 3 row-major
 * and in three contiguous rows of NC.  One product per statement, restrict-qualified rows: the form
 * GCC 12 vectorises across the columns (the same loops written in the callers, with a sum of two
 * products per statement or rows it could not tell apart, stayed scalar: RKMK4 -0.1 us). */
static inline void mul_rows(int nr, const sr_real *M, sr_real scale, const sr_real *restrict in, sr_real *restrict out,
                            int add)
{
    int i, j, c;
    for (i = 0; i < nr; ++i) {
        sr_real *restrict o = out + NC * i;
        if (!add) {
            const sr_real m0 = scale * M[3 * i];
            for (c = 0; c < NC; ++c) o[c] = m0 * in[c];
        }
        for (j = add ? 0 : 1; j < 3; ++j) {
            const sr_real mij = scale * M[3 * i + j];
            for (c = 0; c < NC; ++c) o[c] += mij * in[NC * j + c];
        }
    }
}

/* ---- the stages -----------------------------------------------------------------------------
 * A stage's rows that the dynamics reads, dy_read (xi_S, th_Y, th_P and nu: SR_J_READ rows of NC
 * columns; nothing depends on q), are formed once; the accelerations' rows are then Ja dy_read + [0 | Jb]
 * from sr_internal_accel_jacobian_along, which for the paper's robot applies the yoke frame's chain
 * rule to dy_read and never forms the shell-frame Ja: on an AMD EPYC (Zen 4) the RKMK4 step Jacobian
 * takes 1.74 us so, 1.81 us with the shell-frame Ja pulled through A(th) and B(th) row by row.  The
 * column loops hold one product per statement (mul_rows): GCC 12 vectorises those, and leaves a sum
 * of two products per statement scalar.  GCC's code for the flattened clones
 * moves by +-30 ns with unrelated edits in this file: time a change in interleaved runs. */
enum { NREAD = SR_J_READ };
typedef char nc_matches[(NC == SR_J_NC && SR_E_th_Y == 3 && SR_E_th_P == 4 && SR_E_q == 5) ? 1 : -1];

/* The rows of J_f(y) that are not the accelerations' (the rolling q' = p . w, d(q') = p . dw +
 * (w x p) . dxi, as in sr_step_jacobian_lie_euler): wxp[i] and p[i] for q'_x, q'_y. */
static void rolling_rows(const sr_model *model, const sr_real y[SR_NX], sr_real p[2][3], sr_real wxp[2][3])
{
    const sr_real *R = y + SR_X_R_S, *w = y + SR_X_w_S, r = model->p[SR_P_r];
    int i, l;
    for (l = 0; l < 3; ++l) {
        p[0][l] = r * R[3 + l];    /* q_x' = r (R_S w)_y */
        p[1][l] = -r * R[l];       /* q_y' = -r (R_S w)_x */
    }
    for (i = 0; i < 2; ++i) {
        wxp[i][0] = w[1] * p[i][2] - w[2] * p[i][1];
        wxp[i][1] = w[2] * p[i][0] - w[0] * p[i][2];
        wxp[i][2] = w[0] * p[i][1] - w[1] * p[i][0];
    }
}

/* The kinematic rows of a stage, for dy_read the derivatives of the read rows of y's error: f's
 * entries before SR_T_V (f_S, f_Y, f_P, q') and df_q; nothing here waits for the dynamics. */
static void kinematic_rows(const sr_model *model, const sr_real y[SR_NX], const sr_real dy[NREAD][NC],
                           sr_real f[SR_NT], tangent df)
{
    sr_real p[2][3], wxp[2][3];
    int c;
    sr_internal_kinematics(model, y, f);
    rolling_rows(model, y, p, wxp);
    mul_rows(2, &p[0][0], 1, dy[SR_J_NU], df[SR_T_Q], 0);   /* d(q') = p . dw + (w x p) . dxi */
    mul_rows(2, &wxp[0][0], 1, dy[SR_J_XI], df[SR_T_Q], 1);
    for (c = 0; c < NC; ++c) df[SR_T_Q + 2][c] = 0;
}

/* The dynamic rows: f's accelerations and df_nu = Ja dy_read + [0 | Jb]. */
static int accel_rows(const sr_model *model, const sr_real y[SR_NX], const sr_real u[SR_NU],
                      const sr_real dy[NREAD][NC], sr_real f[SR_NT], tangent df)
{
    sr_real Jb[SR_NV * SR_NU];
    int i, c, status = sr_internal_accel_jacobian_along(model, y, u, dy, f + SR_T_V, &df[SR_T_V], Jb);
    /* A stage state that overflowed fails the pivot test (NaN): report what happened. */
    if (status != SR_OK) return status == SR_ERR_SINGULAR && !all_finite(y, SR_NX) ? SR_ERR_NONFINITE : status;
    for (i = 0; i < SR_NV; ++i)
        for (c = 0; c < SR_NU; ++c) df[SR_T_V + i][NC - SR_NU + c] += Jb[SR_NU * i + c];
    return SR_OK;
}

/* The stage k = dexp^-1(th, f(x . exp(th))) of RKMK4 (dexpinv set), or k = f(x . exp(th)) of CF4's
 * second and third stages, th = h Kp, and dk.  Also returns the stage state y = x . exp(th) and the
 * derivatives of its read rows, dy_read = A(th) [I | 0] + B(th) h dKp (see the top of the file; CF4
 * goes on from its Y2).  The rows of dk that need no dynamics come first (dk_S = P dy_nu_S +
 * Q h dKp_S, or dy_nu_S; dk_q, dk_Y, dk_P), the accelerations' rows last. */
static int stage_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                          const sr_real Kp[SR_NT], const tangent dKp, int dexpinv, sr_real k[SR_NT], tangent dk,
                          sr_real y[SR_NX], sr_real dy[NREAD][NC])
{
    sr_real th[SR_NT], D[9], Jr[9];
    int i, j, c;
    for (i = 0; i < SR_NT; ++i) th[i] = h * Kp[i];
    so3_exp_minus_identity(th + SR_T_S, D);
    act_increment(x, D, th, NULL, y);   /* y = x . exp(th), the stepper's stage state bit for bit */
    so3_right_jacobian(th + SR_T_S, Jr);
    mul_rows(3, Jr, h, dKp[SR_T_S], dy[SR_J_XI], 0);   /* dy_xi = Exp(th_S)^T [I | 0] + Jr h dKp_S */
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j) dy[SR_J_XI + i][j] += D[3 * j + i];
        dy[SR_J_XI + i][i] += 1;
    }
    for (c = 0; c < NC; ++c) {  /* the abelian rows: the identity + h dKp */
        dy[SR_J_TH_Y][c] = h * dKp[SR_T_Y][c];
        dy[SR_J_TH_P][c] = h * dKp[SR_T_P][c];
    }
    {   /* the nu rows are contiguous in both: one loop of 60, which GCC vectorises as a loop (the nest
         * of 5 x 12 it unrolled completely into scalar products) */
        const sr_real *src = dKp[SR_T_V];
        sr_real *dst = dy[SR_J_NU];
        for (c = 0; c < SR_NV * NC; ++c) dst[c] = h * src[c];
    }
    dy[SR_J_TH_Y][SR_E_th_Y] += 1;   /* carried column a is error row a here */
    dy[SR_J_TH_P][SR_E_th_P] += 1;
    for (i = 0; i < SR_NV; ++i) dy[SR_J_NU + i][NU_COLUMN(i)] += 1;
    kinematic_rows(model, y, (const sr_real(*)[NC])dy, k, dk);
    if (dexpinv) {   /* on the SO(3) block only: k_S = dexp^-1(th, f_S) from the kinematics alone */
        sr_real P[9], Q[9], kS[3];
        dexpinv_and_derivatives(th, k, kS, P, Q);
        mul_rows(3, P, 1, dy[SR_J_NU], dk[SR_T_S], 0);
        mul_rows(3, Q, h, dKp[SR_T_S], dk[SR_T_S], 1);
        for (i = 0; i < 3; ++i) k[SR_T_S + i] = kS[i];
    } else {
        for (i = 0; i < 3; ++i) memcpy(dk[SR_T_S + i], dy[SR_J_NU + i], sizeof dk[0]);
    }
    memcpy(dk[SR_T_Y], dy[SR_J_NU + 3], sizeof dk[0]);
    memcpy(dk[SR_T_P], dy[SR_J_NU + 4], sizeof dk[0]);
    return accel_rows(model, y, u, (const sr_real(*)[NC])dy, k, dk);
}

/* The read rows of the identity [I | 0]: carried column a is read row a (xi_S, th_Y, th_P, then nu
 * at NU_COLUMN). */
typedef char read_rows_lead[(SR_J_NU == NU_COLUMN(0) && SR_J_TH_P == SR_E_th_P && NREAD < NC) ? 1 : -1];
static const sr_real identity_read[NREAD][NC] = {
    {1}, {0, 1}, {0, 0, 1}, {0, 0, 0, 1}, {0, 0, 0, 0, 1}, {0, 0, 0, 0, 0, 1}, {0, 0, 0, 0, 0, 0, 1},
    {0, 0, 0, 0, 0, 0, 0, 1}, {0, 0, 0, 0, 0, 0, 0, 0, 1}, {0, 0, 0, 0, 0, 0, 0, 0, 0, 1}};

/* K = f(x) and dK = J_f(x) [I | 0] + [0 | J_u]: RKMK4's and CF4's first stage, as a stage whose
 * read rows are the identity's.  The accelerations' rows come from the same chain rule as the
 * other stages' (sr_internal_accel_jacobian_along) rather than from the shell-frame Ja: a third
 * fewer instructions for the first stage, the same numbers to rounding. */
static int first_stage_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                sr_real K[SR_NT], tangent dK)
{
    int i;
    kinematic_rows(model, x, identity_read, K, dK);
    for (i = 0; i < 3; ++i) memcpy(dK[SR_T_S + i], identity_read[SR_J_NU + i], sizeof dK[0]);   /* th_S' = w_S */
    memcpy(dK[SR_T_Y], identity_read[SR_J_NU + 3], sizeof dK[0]);
    memcpy(dK[SR_T_P], identity_read[SR_J_NU + 4], sizeof dK[0]);
    return accel_rows(model, x, u, identity_read, K, dK);
}

/* y = x . exp(th) and dy_read = A(th) dx_read + B(th) dth_read on the read rows, where x's read rows
 * dx are any (CF4's Y4 = Y2 . exp(th)); dth in the read rows' order too. */
static void move_read_rows(const sr_real x[SR_NX], const sr_real dx[NREAD][NC], const sr_real th[SR_NT],
                           const sr_real dth[NREAD][NC], sr_real y[SR_NX], sr_real dy[NREAD][NC])
{
    sr_real D[9], Dt[9], Jr[9];
    int i, j;
    so3_exp_minus_identity(th + SR_T_S, D);
    act_increment(x, D, th, NULL, y);
    so3_right_jacobian(th + SR_T_S, Jr);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) Dt[3 * i + j] = D[3 * j + i];
    mul_rows(3, Jr, 1, dth[SR_J_XI], dy[SR_J_XI], 0);   /* Exp(th_S)^T dx_xi + Jr dth_S */
    mul_rows(3, Dt, 1, dx[SR_J_XI], dy[SR_J_XI], 1);
    for (i = 0; i < NC * SR_J_TH_Y; ++i) (&dy[0][0])[i] += (&dx[0][0])[i];
    for (i = NC * SR_J_TH_Y; i < NREAD * NC; ++i) (&dy[0][0])[i] = (&dx[0][0])[i] + (&dth[0][0])[i];
}

/* RKMK4's update x_new = x . exp(th), th = sum_k b_k K_k, and its error dy = A(th) [I | 0] + B(th) dth:
 * the xi rows Jr(th_S) dth_S plus Exp(th_S)^T on the xi columns, the others dth plus the identity's
 * entries, dth's rows summed straight into dy.  With x_next (not NULL) also the update itself, as
 * the stepper's advance does it. */
static void rkmk4_final_jacobian(const sr_real x[SR_NX], sr_real h, const sr_real (*K)[SR_NT], tangent *dK, error dy,
                                 sr_real *x_next)
{
    const sr_real b[4] = {h / 6, h / 3, h / 3, h / 6};
    sr_real th[SR_NT], D[9], Jr[9], dth_S[3][NC], *o = &dy[0][0];
    int i, j, k, c;
    for (i = 0; i < (x_next ? SR_NT : 3); ++i) {   /* as the stepper's combine */
        th[i] = 0;
        for (k = 0; k < 4; ++k) th[i] += b[k] * K[k][SR_T_S + i];
    }
    so3_exp_minus_identity(th, D);
    if (x_next) act_increment(x, D, th, NULL, x_next);
    so3_right_jacobian(th, Jr);
    for (k = 0; k < 4; ++k) {   /* dth_S, then the rows th_Y .. q_y and nu of dy (tangent rows alike) */
        const sr_real *s = &dK[k][SR_T_S][0], *a = &dK[k][SR_T_Y][0], *v = &dK[k][SR_T_V][0];
        sr_real *ds = &dth_S[0][0], *oq = o + NC * SR_E_th_Y, *on = o + NC * SR_E_nu;
        if (k == 0) {
            for (c = 0; c < 3 * NC; ++c) ds[c] = b[k] * s[c];
            for (c = 0; c < 4 * NC; ++c) oq[c] = b[k] * a[c];
            for (c = 0; c < SR_NV * NC; ++c) on[c] = b[k] * v[c];
        } else {
            for (c = 0; c < 3 * NC; ++c) ds[c] += b[k] * s[c];
            for (c = 0; c < 4 * NC; ++c) oq[c] += b[k] * a[c];
            for (c = 0; c < SR_NV * NC; ++c) on[c] += b[k] * v[c];
        }
    }
    mul_rows(3, Jr, 1, dth_S[0], dy[SR_E_xi_S], 0);
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j) dy[SR_E_xi_S + i][j] += D[3 * j + i];
        dy[SR_E_xi_S + i][i] += 1;
    }
    dy[SR_E_th_Y][SR_E_th_Y] += 1;   /* carried column a is error row a before q, NU_COLUMN after */
    dy[SR_E_th_P][SR_E_th_P] += 1;
    for (i = 0; i < SR_NV; ++i) dy[SR_E_nu + i][NU_COLUMN(i)] += 1;
}

/* CF4's update x_new = x . exp(th) . exp(th2), th = sum_k beta1_k F_k, th2 = sum_k beta2_k F_k, and
 * its error dy: by the rules at the top of the file, dy = A(th2) (A(th) [I | 0] + B(th) dth) + B(th2) dth2,
 *   xi rows:   (E E2)^T [I | 0] + sum_k (beta1_k E2^T Jr(th_S) + beta2_k Jr(th2_S)) dF_k,S,
 *   the rest:  [I | 0] + sum_k (beta1_k + beta2_k) dF_k          (E = Exp(th_S), E2 = Exp(th2_S)):
 * one pass over the stages' rows, not two sums and two actions (CF4's step Jacobian -35 ns). */
static void cf4_final_jacobian(sr_real h, const sr_real (*F)[SR_NT], tangent *dF, error dy)
{
    const sr_real beta1[4] = {h / 4, h / 6, h / 6, -h / 12};
    const sr_real beta2[4] = {-h / 12, h / 6, h / 6, h / 4};
    sr_real th[3], th2[3], D1[9], D2[9], Jr1[9], Jr2[9], E2tJr1[9], M[9], *o = &dy[0][0];
    int i, j, k, c;
    for (i = 0; i < 3; ++i) {   /* as the stepper's combine */
        th[i] = 0;
        th2[i] = 0;
        for (k = 0; k < 4; ++k) th[i] += beta1[k] * F[k][SR_T_S + i];
        for (k = 0; k < 4; ++k) th2[i] += beta2[k] * F[k][SR_T_S + i];
    }
    so3_exp_minus_identity(th, D1);
    so3_exp_minus_identity(th2, D2);
    so3_right_jacobian(th, Jr1);
    so3_right_jacobian(th2, Jr2);
    for (i = 0; i < 3; ++i)   /* E2^T Jr1 = Jr1 + D2^T Jr1 */
        for (j = 0; j < 3; ++j)
            E2tJr1[3 * i + j] = Jr1[3 * i + j] + (D2[i] * Jr1[j] + D2[3 + i] * Jr1[3 + j] + D2[6 + i] * Jr1[6 + j]);
    for (k = 0; k < 4; ++k) {
        for (i = 0; i < 9; ++i) M[i] = beta1[k] * E2tJr1[i] + beta2[k] * Jr2[i];
        mul_rows(3, M, 1, dF[k][SR_T_S], dy[SR_E_xi_S], k > 0);
    }
    for (i = 0; i < 3; ++i) {   /* (E E2)^T = I + (D1 + D2 + D1 D2)^T on the xi columns */
        for (j = 0; j < 3; ++j)
            dy[SR_E_xi_S + i][j] += (D1[3 * j + i] + D2[3 * j + i])
                                    + (D1[3 * j] * D2[i] + D1[3 * j + 1] * D2[3 + i] + D1[3 * j + 2] * D2[6 + i]);
        dy[SR_E_xi_S + i][i] += 1;
    }
    for (k = 0; k < 4; ++k) {   /* error rows th_Y .. q_y are the tangent's th_Y .. q_y, then nu */
        const sr_real g = beta1[k] + beta2[k], *a = &dF[k][SR_T_Y][0], *b = &dF[k][SR_T_V][0];
        sr_real *oq = o + NC * SR_E_th_Y, *on = o + NC * SR_E_nu;
        if (k == 0) {
            for (c = 0; c < 4 * NC; ++c) oq[c] = g * a[c];
            for (c = 0; c < SR_NV * NC; ++c) on[c] = g * b[c];
        } else {
            for (c = 0; c < 4 * NC; ++c) oq[c] += g * a[c];
            for (c = 0; c < SR_NV * NC; ++c) on[c] += g * b[c];
        }
    }
    dy[SR_E_th_Y][SR_E_th_Y] += 1;
    dy[SR_E_th_P][SR_E_th_P] += 1;
    for (i = 0; i < SR_NV; ++i) dy[SR_E_nu + i][NU_COLUMN(i)] += 1;
}

/* F, G from the carried columns of the step's error (checked finite first: F and G are written
 * only on success; G may be NULL); the dq columns are the identity's (see NC). */
static int deliver_jacobians(const error dy, sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU])
{
    int i;
    if (!all_finite_long(&dy[0][0], SR_NE * NC)) return SR_ERR_NONFINITE;
    for (i = 0; i < SR_NE; ++i) {
        sr_real *row = F + SR_NE * i;
        int c;
        for (c = 0; c < SR_E_q; ++c) row[c] = dy[i][c];
        row[SR_E_q] = (sr_real)(i == SR_E_q);
        row[SR_E_q + 1] = (sr_real)(i == SR_E_q + 1);
        for (c = 0; c < SR_NV; ++c) row[SR_E_nu + c] = dy[i][SR_E_q + c];
        for (c = 0; c < SR_NU && G; ++c) G[SR_NU * i + c] = dy[i][NC - SR_NU + c];
    }
    return SR_OK;
}

int sr_internal_check_step_arguments(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                     sr_real dt, const sr_real *F, const sr_real *G)
{
    int status = arg_model(model, READS(JACOBIAN) | READS(STATE));
    if (status != SR_OK) return status;
    if (!x || !F || !G) return SR_ERR_NULL;
    if (arg_dt(dt) != SR_OK) return SR_ERR_ARG;
    status = sr_internal_check_state(model, x);
    if (status == SR_OK && u && !all_finite(u, SR_NU)) status = SR_ERR_NONFINITE;
    return status;
}

/* RKMK4's F and G (G may be NULL), and with x_next (not NULL) the step: the stepper's stages are
 * the Jacobian's own (the same stage states; the accelerations and dexp^-1 to rounding). */
static int rkmk4_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                          sr_real F[SR_NE * SR_NE], sr_real *G, sr_real *x_next)
{
    static const sr_real a_diag[3] = {SR_C(0.5), SR_C(0.5), SR_C(1.0)};
    sr_real K[4][SR_NT], y[SR_NX], dy_read[NREAD][NC], xn[SR_NX];
    tangent dK[4];
    error dy;
    int s, status = first_stage_jacobian(model, x, u, K[0], dK[0]);
    for (s = 1; s < 4 && status == SR_OK; ++s)
        status = stage_jacobian(model, x, u, a_diag[s - 1] * dt, K[s - 1], (const sr_real(*)[NC])dK[s - 1], 1,
                                K[s], dK[s], y, dy_read);
    if (status != SR_OK) return status;
    rkmk4_final_jacobian(x, dt, (const sr_real(*)[SR_NT])K, dK, dy, x_next ? xn : NULL);
    if (x_next && !all_finite(xn, SR_NX)) return SR_ERR_NONFINITE;
    status = deliver_jacobians((const sr_real(*)[NC])dy, F, G);
    if (status == SR_OK && x_next) memcpy(x_next, xn, sizeof xn);
    return status;
}

SR_JACOBIAN_CLONES int sr_step_jacobian_rkmk4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                           sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU])
{
    static const sr_real zero_u[SR_NU] = {0, 0};
    const int status = sr_internal_check_step_arguments(model, x, u, dt, F, G);
    if (status != SR_OK) return status;
    return rkmk4_jacobian(model, x, u ? u : zero_u, dt, F, G, NULL);
}

SR_JACOBIAN_CLONES int sr_step_jacobian_cf4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                         sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU])
{
    static const sr_real zero_u[SR_NU] = {0, 0};
    sr_real Fk[4][SR_NT], th[SR_NT], Y2[SR_NX], Y[SR_NX];
    sr_real dY2[NREAD][NC], dY4[NREAD][NC], dth4[NREAD][NC];
    tangent dF[4];
    error dY;
    int i, c, status = sr_internal_check_step_arguments(model, x, u, dt, F, G);
    if (status != SR_OK) return status;
    if (!u) u = zero_u;
    status = first_stage_jacobian(model, x, u, Fk[0], dF[0]);                            /* F1 = f(x) */
    if (status == SR_OK)                                              /* F2 = f(Y2), Y2 = x . exp(h/2 F1) */
        status = stage_jacobian(model, x, u, SR_C(0.5) * dt, Fk[0], (const sr_real(*)[NC])dF[0], 0, Fk[1], dF[1],
                                Y2, dY2);
    if (status == SR_OK)                                                  /* F3 = f(x . exp(h/2 F2)) */
        status = stage_jacobian(model, x, u, SR_C(0.5) * dt, Fk[1], (const sr_real(*)[NC])dF[1], 0, Fk[2], dF[2],
                                Y, dY4);
    if (status == SR_OK) {                                      /* F4 = f(Y4), Y4 = Y2 . exp(h (F3 - F1/2)) */
        static const unsigned char tangent_row[NREAD] = {SR_T_S, SR_T_S + 1, SR_T_S + 2, SR_T_Y, SR_T_P,
                                                          SR_T_V, SR_T_V + 1, SR_T_V + 2, SR_T_V + 3, SR_T_V + 4};
        for (i = 0; i < SR_NT; ++i) th[i] = dt * (Fk[2][i] - SR_C(0.5) * Fk[0][i]);
        for (i = 0; i < NREAD; ++i) {
            const sr_real *a = dF[2][tangent_row[i]], *b = dF[0][tangent_row[i]];
            for (c = 0; c < NC; ++c) dth4[i][c] = dt * a[c];
            for (c = 0; c < NC; ++c) dth4[i][c] -= SR_C(0.5) * dt * b[c];
        }
        move_read_rows(Y2, (const sr_real(*)[NC])dY2, th, (const sr_real(*)[NC])dth4, Y, dY4);
        kinematic_rows(model, Y, (const sr_real(*)[NC])dY4, Fk[3], dF[3]);
        for (i = 0; i < 3; ++i) memcpy(dF[3][SR_T_S + i], dY4[SR_J_NU + i], sizeof dF[3][0]);   /* f_S = w_S */
        memcpy(dF[3][SR_T_Y], dY4[SR_J_NU + 3], sizeof dF[3][0]);
        memcpy(dF[3][SR_T_P], dY4[SR_J_NU + 4], sizeof dF[3][0]);
        status = accel_rows(model, Y, u, (const sr_real(*)[NC])dY4, Fk[3], dF[3]);
    }
    if (status != SR_OK) return status;
    cf4_final_jacobian(dt, (const sr_real(*)[SR_NT])Fk, dF, dY);   /* x_new = x . exp(th) . exp(th2) */
    return deliver_jacobians((const sr_real(*)[NC])dY, F, G);
}

int sr_step_jacobian(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                     sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU])
{
    int status;
    switch (method) {
    case SR_LIE_EULER: return sr_step_jacobian_lie_euler(model, x, u, dt, F, G);
    case SR_RKMK4: return sr_step_jacobian_rkmk4(model, x, u, dt, F, G);
    case SR_CF4: return sr_step_jacobian_cf4(model, x, u, dt, F, G);
    default: /* the model and the pointers before the method, as for every other argument */
        status = arg_model(model, READS(JACOBIAN) | READS(STATE));
        if (status != SR_OK) return status;
        return !x || !F || !G ? SR_ERR_NULL : SR_ERR_ARG;
    }
}

SR_JACOBIAN_CLONES int sr_internal_step_and_jacobian(const sr_model *model, int method, const sr_real x[SR_NX],
                                                     const sr_real u[SR_NU], sr_real dt, sr_real x_next[SR_NX],
                                                     sr_real F[SR_NE * SR_NE])
{
    static const sr_real zero_u[SR_NU] = {0, 0};
    sr_real xn[SR_NX], Fn[SR_NE * SR_NE], G[SR_NE * SR_NU];
    int status;
    if (!u) u = zero_u;
    if ((method & ~SR_PROJECT) == SR_RKMK4) {
        status = rkmk4_jacobian(model, x, u, dt, Fn, NULL, xn);
        if (status == SR_OK && (method & SR_PROJECT)) sr_internal_project(xn);
    } else {
        status = sr_internal_advance(model, method, x, u, dt, NULL, xn);
        if (status == SR_OK) status = sr_step_jacobian(model, method & ~SR_PROJECT, x, u, dt, Fn, G);
    }
    if (status == SR_OK && !all_finite(xn, SR_NX)) status = SR_ERR_NONFINITE;
    if (status != SR_OK) return status;
    memcpy(x_next, xn, sizeof xn);
    memcpy(F, Fn, sizeof Fn);
    return SR_OK;
}

int sr_step_jacobian_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u, sr_real dt,
                           sr_real *F, sr_real *G, long *failed_row)
{
    long i;
    int status = arg_model(model, READS(JACOBIAN) | READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && F && G);
    if (status == SR_OK && (arg_jacobian_method(method) != SR_OK || arg_dt(dt) != SR_OK)) status = SR_ERR_ARG;
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        status = sr_step_jacobian(model, method, x + i * SR_NX, u ? u + i * SR_NU : NULL, dt,
                                            F + i * SR_NE * SR_NE, G + i * SR_NE * SR_NU);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
