/*
 * sr_nmpc.c -- the NMPC's real-time iteration (sr_nmpc.h; the formulation of
 * runtime/control/nmpc.py, docs/control.md).
 */
#include "sr_nmpc.h"
#include "sr_checks.h"
#include "sr_control.h"
#include "sr_so3.h"
#include "sr_argcheck.h"

#include <string.h>

#define NZ SR_NMPC_NZ
#define NE SR_NE
#define Z_EY 9
#define Z_IY 10
#define Z_SHELL 4 /* the shell's rates in the yoke's frame, z[4..6] */
/* The share of u_max below which a torque counts as free for the integral's anti-windup. */
#define FREE_SHARE SR_C(0.999)
#define PI_ SR_C(3.14159265358979323846)

long sr_nmpc_memory_bytes(void) { return (long)sizeof(sr_nmpc_memory); }

static int valid_sizes(const sr_nmpc *d)
{
    return d->horizon >= 1 && d->horizon <= SR_NMPC_MAX_HORIZON && d->node_periods >= 1 && d->cold_iterations >= 1
        && d->iterations >= 1 && d->qp_max_iterations >= 1 && d->n_speeds >= 1 && d->n_speeds <= SR_LQR_MAX_SPEEDS
        && d->n_curvatures >= 1 && d->n_curvatures <= SR_LQR_MAX_CURVATURES && d->period > 0 && d->u_max > 0
        && d->r > 0 && d->r_step >= 0 && d->steady_rate >= 0 && d->heading_jump > 0 && d->disturbance_gain >= 0
        && d->disturbance_gain <= 1;
}

int sr_nmpc_check(const sr_nmpc *d)
{
    int i, n;
    if (!d) return SR_ERR_NULL;
    if (!all_finite(&d->period, 1) || !all_finite(&d->u_max, 1) || !all_finite(&d->r, 1) || !all_finite(&d->r_step, 1)
        || !all_finite(&d->steady_rate, 1) || !all_finite(&d->heading_jump, 1) || !all_finite(&d->disturbance_gain, 1) || !all_finite(d->q_path, NZ)
        || !all_finite(d->q_heading, NZ))
        return SR_ERR_NONFINITE;
    if (!valid_sizes(d)) return SR_ERR_ARG;
    for (i = 0; i < NZ; ++i)
        if (d->q_path[i] < 0 || d->q_heading[i] < 0) return SR_ERR_ARG;
    if (!all_finite(d->speeds, d->n_speeds) || !all_finite(d->curvatures, d->n_curvatures)) return SR_ERR_NONFINITE;
    n = d->n_speeds * d->n_curvatures;
    for (i = 0; i < n; ++i)
        if (!all_finite(d->z_star[i], NZ) || !all_finite(d->u_star[i], SR_NU) || !all_finite(d->P_path[i], NZ * NZ)
            || !all_finite(d->P_heading[i], NZ * NZ))
            return SR_ERR_NONFINITE;
    for (i = 1; i < d->n_speeds; ++i)
        if (!(d->speeds[i] > d->speeds[i - 1])) return SR_ERR_ARG;
    for (i = 1; i < d->n_curvatures; ++i)
        if (!(d->curvatures[i] > d->curvatures[i - 1])) return SR_ERR_ARG;
    return SR_OK;
}

int sr_nmpc_reset(sr_nmpc_memory *memory)
{
    if (!memory) return SR_ERR_NULL;
    memory->have_guess = memory->have_u_last = 0;
    memory->heading = memory->integral = 0;
    memory->samples = memory->restarts = memory->recoveries = memory->failures = 0;
    memory->failing = memory->recovering = 0;
    memory->qp_iterations = memory->saturated = 0;
    memory->u_last[0] = memory->u_last[1] = 0;
    memory->disturbance[0] = memory->disturbance[1] = 0;
    memory->shell_accel[0] = memory->shell_accel[1] = memory->shell_accel[2] = 0;
    memory->have_last = 0;
    return SR_OK;
}

/* ---- The prediction model ---------------------------------------------------------------------- */

/* The full state whose error coordinates are z against a reference at heading 0 through the
 * origin (lqr_design.lift): theta_Y = 0, R_S = Q = Q_ref(0) Exp(E), q = (0, e_y, r). */
static void lift(const sr_model *model, const sr_real z[NZ], sr_real v, sr_real x[SR_NX])
{
    static const sr_real Q0[9] = {0, 1, 0, -1, 0, 0, 0, 0, 1}; /* Q_ref(0) = rot_z(-pi/2) */
    const sr_real r = model->p[SR_P_r], c = SR_COS(z[3]), s = SR_SIN(z[3]);
    sr_real D[9];
    int i;
    so3_exp_minus_identity(z, D);
    D[0] += 1;
    D[4] += 1;
    D[8] += 1;
    matmul3(Q0, D, x + SR_X_R_S);
    memset(x + SR_X_R_Y, 0, 9 * sizeof(sr_real));
    x[SR_X_R_Y] = x[SR_X_R_Y + 4] = x[SR_X_R_Y + 8] = 1;
    memset(x + SR_X_R_P, 0, 9 * sizeof(sr_real));
    x[SR_X_R_P] = c;
    x[SR_X_R_P + 2] = s;
    x[SR_X_R_P + 4] = 1;
    x[SR_X_R_P + 6] = -s;
    x[SR_X_R_P + 8] = c;
    x[SR_X_q] = 0;
    x[SR_X_q + 1] = z[Z_EY];
    x[SR_X_q + 2] = r;
    for (i = 0; i < 3; ++i) x[SR_X_w_S + i] = z[4 + i];
    x[SR_X_w_S] -= v / r;
    x[SR_X_w_Y] = z[7] + v / r;
    x[SR_X_w_P] = z[8];
}

/* J_r^-1(e) = I + [e]/2 + c [e]^2, c = (1 - (t/2) cot(t/2)) / t^2. */
static void inverse_right_jacobian(const sr_real e[3], sr_real J[9])
{
    const sr_real t2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
    sr_real c;
    if (t2 < SR_SERIES_T2) {
        c = dexpinv_series(t2);
    } else {
        const sr_real t = SR_SQRT(t2);
        c = 1 / t2 - (1 + SR_COS(t)) / (2 * t * SR_SIN(t));
    }
    J[0] = 1 - c * (e[1] * e[1] + e[2] * e[2]);
    J[4] = 1 - c * (e[0] * e[0] + e[2] * e[2]);
    J[8] = 1 - c * (e[0] * e[0] + e[1] * e[1]);
    J[1] = -SR_C(0.5) * e[2] + c * e[0] * e[1];
    J[3] = SR_C(0.5) * e[2] + c * e[0] * e[1];
    J[2] = SR_C(0.5) * e[1] + c * e[0] * e[2];
    J[6] = -SR_C(0.5) * e[1] + c * e[0] * e[2];
    J[5] = -SR_C(0.5) * e[0] + c * e[1] * e[2];
    J[7] = SR_C(0.5) * e[0] + c * e[1] * e[2];
}

/* z[0..9] of the state x against the path through the origin along +x with curvature kappa (a
 * circle, left positive; the foot point's heading psi = kappa s), and (J not NULL) their
 * derivatives J (10 x NE) in the library's error coordinates of x.  The formulas hold at kappa = 0
 * without a special case: psi = atan2(kappa q_x, 1 - kappa q_y), and e_y = (2 q_y - kappa |q|^2) /
 * (1 + |(kappa q_x, 1 - kappa q_y)|) (the distance to the circle, with the cancellation removed). */
static void project(const sr_model *model, const sr_real x[SR_NX], sr_real v, sr_real kappa, sr_real z[NZ - 1],
                    sr_real *J)
{
    const sr_real *R_S = x + SR_X_R_S, *R_Y = x + SR_X_R_Y, *R_P = x + SR_X_R_P, *w_S = x + SR_X_w_S;
    const sr_real qx = x[SR_X_q], qy = x[SR_X_q + 1], rate = v / model->p[SR_P_r];
    const sr_real a = kappa * qx, b = 1 - kappa * qy, n2 = a * a + b * b, n = SR_SQRT(n2);
    const sr_real psi = SR_ATAN2(a, b), s = SR_SIN(psi), c = SR_COS(psi);
    const sr_real e_y = (2 * qy - kappa * (qx * qx + qy * qy)) / (1 + n);
    sr_real Q[9], M[9], om[3];
    int i, j;
    matmul3(R_S, R_Y, Q);
    for (j = 0; j < 3; ++j) { /* M = Q_ref(psi)^T Q */
        M[j] = s * Q[j] - c * Q[3 + j];
        M[3 + j] = c * Q[j] + s * Q[3 + j];
        M[6 + j] = Q[6 + j];
    }
    so3_log(M, z);
    z[3] = SR_ATAN2(R_P[2], R_P[0]);
    for (j = 0; j < 3; ++j) om[j] = R_Y[j] * w_S[0] + R_Y[3 + j] * w_S[1] + R_Y[6 + j] * w_S[2];
    for (j = 0; j < 3; ++j) z[4 + j] = om[j];
    z[4] += rate;
    z[7] = x[SR_X_w_Y] - rate;
    z[8] = x[SR_X_w_P];
    z[Z_EY] = e_y;
    if (J) {
        const sr_real dpsi[2] = {b * kappa / n2, a * kappa / n2};
        const sr_real de[2] = {(-2 * kappa * qx - e_y * a * kappa / n) / (1 + n),
                               (2 * b + e_y * b * kappa / n) / (1 + n)};
        sr_real Ji[9], W[3][NE];
        memset(J, 0, (NZ - 1) * NE * sizeof(sr_real));
        /* omega = R_Y^T dxi + dth_Y e_x - dpsi Q^T e_z, dE = J_r^-1(E) omega */
        memset(W, 0, sizeof W);
        for (i = 0; i < 3; ++i) {
            for (j = 0; j < 3; ++j) W[i][SR_E_xi_S + j] = R_Y[3 * j + i];
            W[i][SR_E_q] = -Q[6 + i] * dpsi[0];
            W[i][SR_E_q + 1] = -Q[6 + i] * dpsi[1];
        }
        W[0][SR_E_th_Y] = 1;
        inverse_right_jacobian(z, Ji);
        for (i = 0; i < 3; ++i)
            for (j = 0; j < NE; ++j) J[i * NE + j] = Ji[3 * i] * W[0][j] + Ji[3 * i + 1] * W[1][j] + Ji[3 * i + 2] * W[2][j];
        J[3 * NE + SR_E_th_P] = 1;
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) J[(4 + i) * NE + SR_E_nu + j] = R_Y[3 * j + i];
        /* d(R_Y^T w_S) along dth_Y: -e_x x om */
        J[5 * NE + SR_E_th_Y] = om[2];
        J[6 * NE + SR_E_th_Y] = -om[1];
        J[7 * NE + SR_E_nu + 3] = 1;
        J[8 * NE + SR_E_nu + 4] = 1;
        J[Z_EY * NE + SR_E_q] = de[0];
        J[Z_EY * NE + SR_E_q + 1] = de[1];
    }
}

/* The columns of project()'s J that can be nonzero, by row: their count, then their indices. */
static const unsigned char PROJECT_COLUMNS[NZ - 1][8] = {
    {6, SR_E_xi_S, SR_E_xi_S + 1, SR_E_xi_S + 2, SR_E_th_Y, SR_E_q, SR_E_q + 1},
    {6, SR_E_xi_S, SR_E_xi_S + 1, SR_E_xi_S + 2, SR_E_th_Y, SR_E_q, SR_E_q + 1},
    {6, SR_E_xi_S, SR_E_xi_S + 1, SR_E_xi_S + 2, SR_E_th_Y, SR_E_q, SR_E_q + 1},
    {1, SR_E_th_P},
    {4, SR_E_th_Y, SR_E_nu, SR_E_nu + 1, SR_E_nu + 2},
    {4, SR_E_th_Y, SR_E_nu, SR_E_nu + 1, SR_E_nu + 2},
    {4, SR_E_th_Y, SR_E_nu, SR_E_nu + 1, SR_E_nu + 2},
    {1, SR_E_nu + 3},
    {1, SR_E_nu + 4},
    {2, SR_E_q, SR_E_q + 1}};

/* sr_nmpc_node without its argument checks (sr_step checks the lifted state). */
static int node(const sr_model *model, const sr_real z[NZ], const sr_real u[SR_NU], sr_real v, sr_real kappa,
                sr_real dt, sr_real z_next[NZ], sr_real *A, sr_real *B)
{
    sr_real x[SR_NX], x_next[SR_NX], F[NE * NE], G[NE * SR_NU], J[(NZ - 1) * NE], T[(NZ - 1) * NE], Jr[9];
    const sr_real h2 = SR_C(0.5) * dt;
    int i, j, k, status;
    lift(model, z, v, x);
    status = sr_step(model, SR_RKMK4, x, u, dt, x_next);
    if (status == SR_OK && A) status = sr_step_jacobian(model, SR_RKMK4, x, u, dt, F, G);
    if (status != SR_OK) return status;
    project(model, x_next, v, kappa, z_next, A ? J : NULL);
    z_next[Z_IY] = z[Z_IY] + h2 * (z[Z_EY] + z_next[Z_EY]); /* the trapezoid of e_y over the node */
    if (!all_finite(z_next, NZ)) return SR_ERR_NONFINITE;
    if (!A) return SR_OK;
    /* T = J F, B = J G over the columns project() can fill (J is sparse: a third of the products). */
    for (i = 0; i < NZ - 1; ++i) {
        const unsigned char *col = PROJECT_COLUMNS[i];
        for (j = 0; j < NE; ++j) T[i * NE + j] = 0;
        B[i * SR_NU] = B[i * SR_NU + 1] = 0;
        for (k = 1; k <= col[0]; ++k) {
            const sr_real Jik = J[i * NE + col[k]];
            const sr_real *Fk = F + col[k] * NE;
            for (j = 0; j < NE; ++j) T[i * NE + j] += Jik * Fk[j];
            B[i * SR_NU] += Jik * G[col[k] * SR_NU];
            B[i * SR_NU + 1] += Jik * G[col[k] * SR_NU + 1];
        }
    }
    /* The lift's derivative: dxi = J_r(E) dE, dth_P, dq_y = de_y, dnu = (dOm, dw_Y, dw_P). */
    so3_right_jacobian(z, Jr);
    for (i = 0; i < NZ - 1; ++i) {
        const sr_real *t = T + i * NE;
        sr_real *a = A + i * NZ;
        for (j = 0; j < 3; ++j) a[j] = t[SR_E_xi_S] * Jr[j] + t[SR_E_xi_S + 1] * Jr[3 + j] + t[SR_E_xi_S + 2] * Jr[6 + j];
        a[3] = t[SR_E_th_P];
        for (j = 0; j < 5; ++j) a[4 + j] = t[SR_E_nu + j];
        a[Z_EY] = t[SR_E_q + 1];
        a[Z_IY] = 0;
    }
    for (j = 0; j < NZ; ++j) A[Z_IY * NZ + j] = h2 * A[Z_EY * NZ + j];
    A[Z_IY * NZ + Z_EY] += h2;
    A[Z_IY * NZ + Z_IY] = 1;
    for (j = 0; j < SR_NU; ++j) B[Z_IY * SR_NU + j] = h2 * B[Z_EY * SR_NU + j];
    if (!all_finite(A, NZ * NZ) || !all_finite(B, NZ * SR_NU)) return SR_ERR_NONFINITE;
    return SR_OK;
}

int sr_nmpc_node(const sr_model *model, const sr_real z[SR_NMPC_NZ], const sr_real u[SR_NU], sr_real v,
                 sr_real kappa, sr_real dt, sr_real z_next[SR_NMPC_NZ], sr_real *A, sr_real *B)
{
    sr_real zn[NZ], An[NZ * NZ], Bn[NZ * SR_NU];
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!z || !u || !z_next || (A && !B) || (B && !A)) return SR_ERR_NULL;
    if (!all_finite(z, NZ) || !all_finite(u, SR_NU) || !all_finite(&v, 1) || !all_finite(&kappa, 1))
        return SR_ERR_NONFINITE;
    if (arg_dt(dt) != SR_OK) return SR_ERR_ARG;
    status = node(model, z, u, v, kappa, dt, zn, A ? An : NULL, Bn);
    if (status != SR_OK) return status;
    memcpy(z_next, zn, sizeof zn);
    if (A) {
        memcpy(A, An, sizeof An);
        memcpy(B, Bn, sizeof Bn);
    }
    return SR_OK;
}

/* ---- The real-time iteration ------------------------------------------------------------------- */

/* The grid interval around value and its weight in it, clamped to the grid (as sr_lqr's). */
static void bracket(const sr_real *grid, int n, sr_real value, int *lo, int *hi, sr_real *w)
{
    int i = 0;
    if (n == 1) {
        *lo = *hi = 0;
        *w = 0;
        return;
    }
    while (i < n - 2 && value > grid[i + 1]) ++i;
    *lo = i;
    *hi = i + 1;
    *w = (value - grid[i]) / (grid[i + 1] - grid[i]);
    *w = *w < 0 ? 0 : (*w > 1 ? 1 : *w);
}

/* The first index of the grid entry nearest to value. */
static int nearest(const sr_real *grid, int n, sr_real value)
{
    int i, best = 0;
    for (i = 1; i < n; ++i)
        if (SR_FABS(grid[i] - value) < SR_FABS(grid[best] - value)) best = i;
    return best;
}

/* The reference nodes zs (N + 1) and torques us (N) at speed v and the nodes' curvatures. */
static void references(const sr_nmpc *d, sr_nmpc_memory *m, sr_real v)
{
    int i0, i1, j0, j1, k, j, nc = d->n_curvatures;
    sr_real wv, wk;
    bracket(d->speeds, d->n_speeds, v, &i0, &i1, &wv);
    for (k = 0; k <= d->horizon; ++k) {
        bracket(d->curvatures, nc, m->kappa[k], &j0, &j1, &wk);
        for (j = 0; j < NZ; ++j)
            m->zs[k * NZ + j] = (1 - wv) * ((1 - wk) * d->z_star[i0 * nc + j0][j] + wk * d->z_star[i0 * nc + j1][j])
                              + wv * ((1 - wk) * d->z_star[i1 * nc + j0][j] + wk * d->z_star[i1 * nc + j1][j]);
        if (k < d->horizon)
            for (j = 0; j < SR_NU; ++j)
                m->us[k * SR_NU + j] = (1 - wv) * ((1 - wk) * d->u_star[i0 * nc + j0][j] + wk * d->u_star[i0 * nc + j1][j])
                                     + wv * ((1 - wk) * d->u_star[i1 * nc + j0][j] + wk * d->u_star[i1 * nc + j1][j]);
    }
}

/* out = v A: a row of NZ times an NZ x NZ matrix, as rows of A scaled and added (vectorisable). */
static void row_times(const sr_real *restrict v, const sr_real *restrict A, sr_real *restrict out)
{
    int l, b;
    for (b = 0; b < NZ; ++b) out[b] = 0;
    for (l = 0; l < NZ; ++l) {
        const sr_real vl = v[l];
        for (b = 0; b < NZ; ++b) out[b] += vl * A[l * NZ + b];
    }
}

/* One Gauss-Newton QP around the nodes (m->Z, m->U) into (m->Zn, m->Un); nonzero when the
 * prediction or the QP gives no finite answer. */
static int iteration(const sr_nmpc *d, sr_nmpc_memory *m, const sr_model *model, const sr_real z0[NZ], sr_real v,
                     const sr_real q[NZ], const sr_real *P)
{
    const int N = d->horizon, nq = SR_NU * N;
    const sr_real T = d->period * (sr_real)d->node_periods;
    sr_real zp[NZ], tmp[NZ * NZ], w[NZ], w2[NZ], M[SR_NU][NZ], M2[SR_NU][NZ];
    sr_real ud[SR_NU];
    int i, j, k, a, b, status;
    for (k = 0; k < N; ++k) {
        ud[0] = m->U[k * SR_NU] + m->disturbance[0];
        ud[1] = m->U[k * SR_NU + 1] + m->disturbance[1];
        if (node(model, m->Z + k * NZ, ud, v, m->kappa[k], T, zp, m->A[k], m->B[k]) != SR_OK) return 1;
        for (j = 0; j < 3; ++j) zp[Z_SHELL + j] += T * m->shell_accel[j];
        for (j = 0; j < NZ; ++j) m->gap[k * NZ + j] = zp[j] - m->Z[(k + 1) * NZ + j];
    }
    /* The free response c (delta U = 0): c_0 = z0 - Z_0, c_{k+1} = A_k c_k + gap_k. */
    for (j = 0; j < NZ; ++j) m->c[j] = z0[j] - m->Z[j];
    for (k = 0; k < N; ++k)
        for (i = 0; i < NZ; ++i) {
            sr_real acc = m->gap[k * NZ + i];
            for (j = 0; j < NZ; ++j) acc += m->A[k][i * NZ + j] * m->c[k * NZ + j];
            m->c[(k + 1) * NZ + i] = acc;
        }
    /* The gradient by the adjoint: lambda_N = P e_N, lambda_k = q e_k + A_k^T lambda_{k+1} (into gap),
     * e_k = Z_k + c_k - zs_k the error at delta U = 0; g_j = B_j^T lambda_{j+1} + r (U_j - us_j). */
    for (j = 0; j < NZ; ++j) w[j] = m->Z[N * NZ + j] + m->c[N * NZ + j] - m->zs[N * NZ + j];
    for (i = 0; i < NZ; ++i) {
        sr_real acc = 0;
        for (j = 0; j < NZ; ++j) acc += P[i * NZ + j] * w[j];
        m->gap[N * NZ + i] = acc;
    }
    for (k = N - 1; k >= 1; --k)
        for (i = 0; i < NZ; ++i) {
            sr_real acc = q[i] * (m->Z[k * NZ + i] + m->c[k * NZ + i] - m->zs[k * NZ + i]);
            for (j = 0; j < NZ; ++j) acc += m->A[k][j * NZ + i] * m->gap[(k + 1) * NZ + j];
            m->gap[k * NZ + i] = acc;
        }
    for (k = 0; k < N; ++k)
        for (a = 0; a < SR_NU; ++a) {
            sr_real acc = d->r * (m->U[k * SR_NU + a] - m->us[k * SR_NU + a]);
            for (j = 0; j < NZ; ++j) acc += m->B[k][j * SR_NU + a] * m->gap[(k + 1) * NZ + j];
            m->g[k * SR_NU + a] = acc;
        }
    /* The Hessian: S_N = P, S_k = diag(q) + A_k^T S_{k+1} A_k; H_ij = (S_{i+1} B_i)^T A_i ... A_{j+1} B_j
     * for i >= j, a row of blocks from each S_{i+1} B_i by products with the A's backwards. */
    memcpy(m->S, P, NZ * NZ * sizeof(sr_real));
    for (k = N - 1; k >= 0; --k) {
        for (i = 0; i < NZ; ++i)
            for (a = 0; a < SR_NU; ++a) {
                sr_real acc = 0;
                for (j = 0; j < NZ; ++j) acc += m->S[i * NZ + j] * m->B[k][j * SR_NU + a];
                m->SB[k][i * SR_NU + a] = acc;
            }
        if (k == 0) break;
        for (i = 0; i < NZ; ++i) row_times(m->S + i * NZ, m->A[k], tmp + i * NZ); /* tmp = S A_k */
        for (i = 0; i < NZ; ++i) { /* S = A_k^T tmp + diag(q): row i of A_k^T tmp = sum_a A[a][i] tmp[a][:] */
            sr_real *Si = m->S + i * NZ;
            for (j = 0; j < NZ; ++j) Si[j] = 0;
            for (a = 0; a < NZ; ++a) {
                const sr_real Aai = m->A[k][a * NZ + i];
                const sr_real *t = tmp + a * NZ;
                for (j = 0; j < NZ; ++j) Si[j] += Aai * t[j];
            }
            Si[i] += q[i];
        }
    }
    for (i = 0; i < N; ++i) {
        for (a = 0; a < SR_NU; ++a)
            for (j = 0; j < NZ; ++j) M[a][j] = m->SB[i][j * SR_NU + a];
        for (j = i; j >= 0; --j) {
            for (a = 0; a < SR_NU; ++a)
                for (b = 0; b < SR_NU; ++b) {
                    sr_real acc = 0;
                    int l;
                    for (l = 0; l < NZ; ++l) acc += M[a][l] * m->B[j][l * SR_NU + b];
                    m->H[(SR_NU * i + a) * nq + SR_NU * j + b] = acc;
                    m->H[(SR_NU * j + b) * nq + SR_NU * i + a] = acc;
                }
            if (j == 0) break;
            row_times(M[0], m->A[j], M2[0]);
            row_times(M[1], m->A[j], M2[1]);
            memcpy(M, M2, sizeof M);
        }
    }
    for (i = 0; i < nq; ++i) m->H[i * nq + i] += d->r;
    /* The torques' changes: sum_k |U_k - U_{k-1}|^2 r_step, U_{-1} the last applied. */
    if (m->have_u_last && d->r_step > 0) {
        for (k = 0; k < N; ++k)
            for (a = 0; a < SR_NU; ++a) {
                const int i0 = k * SR_NU + a;
                const sr_real prev = k == 0 ? m->u_last[a] : m->U[i0 - SR_NU];
                const sr_real step = m->U[i0] - prev;
                const sr_real next = k + 1 < N ? m->U[i0 + SR_NU] - m->U[i0] : 0;
                m->g[i0] += d->r_step * (step - next);
                m->H[i0 * nq + i0] += d->r_step * (k + 1 < N ? 2 : 1);
                if (k + 1 < N) {
                    m->H[i0 * nq + i0 + SR_NU] -= d->r_step;
                    m->H[(i0 + SR_NU) * nq + i0] -= d->r_step;
                }
            }
    }
    if (!all_finite(m->g, nq)) return 1;
    for (i = 0; i < nq; ++i) {
        m->lb[i] = -d->u_max - m->U[i];
        m->ub[i] = d->u_max - m->U[i];
        m->dU[i] = 0;
    }
    status = sr_boxqp_solve(nq, m->H, m->g, m->lb, m->ub, d->qp_max_iterations, m->dU, m->qp_work, m->qp_iwork,
                            &m->qp_iterations);
    if (status != SR_OK) return 1;
    /* The new nodes: Z + c + the linear response to delta U. */
    memset(w, 0, sizeof w);
    for (j = 0; j < NZ; ++j) m->Zn[j] = m->Z[j] + m->c[j];
    for (k = 0; k < N; ++k) {
        for (i = 0; i < NZ; ++i) {
            sr_real acc = m->B[k][i * SR_NU] * m->dU[k * SR_NU] + m->B[k][i * SR_NU + 1] * m->dU[k * SR_NU + 1];
            for (j = 0; j < NZ; ++j) acc += m->A[k][i * NZ + j] * w[j];
            w2[i] = acc;
        }
        memcpy(w, w2, sizeof w);
        for (i = 0; i < NZ; ++i) m->Zn[(k + 1) * NZ + i] = m->Z[(k + 1) * NZ + i] + m->c[(k + 1) * NZ + i] + w[i];
    }
    for (i = 0; i < nq; ++i) m->Un[i] = m->U[i] + m->dU[i];
    return !all_finite(m->Zn, (N + 1) * NZ) || !all_finite(m->Un, nq);
}

/* Iterations from the nodes in m->Z, m->U; the result in them.  Nonzero on failure. */
static int iterate(const sr_nmpc *d, sr_nmpc_memory *m, const sr_model *model, const sr_real z0[NZ], sr_real v,
                   const sr_real q[NZ], const sr_real *P, int count)
{
    const int N = d->horizon;
    int it;
    for (it = 0; it < count; ++it) {
        if (iteration(d, m, model, z0, v, q, P)) return 1;
        memcpy(m->Z, m->Zn, (size_t)(N + 1) * NZ * sizeof(sr_real));
        memcpy(m->U, m->Un, (size_t)N * SR_NU * sizeof(sr_real));
    }
    return 0;
}

/* ---- Recovery: damped single shooting ---------------------------------------------------------- */

/* The nodes Z of the torques U from z0 (Z_0 = z0, Z_{k+1} the prediction of Z_k under U_k + d, as
 * iteration()'s nodes); nonzero when a prediction is not finite. */
static int rollout(const sr_nmpc *d, sr_nmpc_memory *m, const sr_model *model, const sr_real z0[NZ], sr_real v,
                   const sr_real *U, sr_real *Z)
{
    const sr_real T = d->period * (sr_real)d->node_periods;
    sr_real ud[SR_NU];
    int j, k;
    memcpy(Z, z0, NZ * sizeof(sr_real));
    for (k = 0; k < d->horizon; ++k) {
        ud[0] = U[k * SR_NU] + m->disturbance[0];
        ud[1] = U[k * SR_NU + 1] + m->disturbance[1];
        if (node(model, Z + k * NZ, ud, v, m->kappa[k], T, Z + (k + 1) * NZ, NULL, NULL) != SR_OK) return 1;
        for (j = 0; j < 3; ++j) Z[(k + 1) * NZ + Z_SHELL + j] += T * m->shell_accel[j];
    }
    return 0;
}

/* Twice the QP's objective at gap-free nodes Z and torques U: the weighted errors of nodes 1 .. N - 1,
 * the cost-to-go of node N, the torques' distance from the reference and their changes. */
static sr_real objective(const sr_nmpc *d, const sr_nmpc_memory *m, const sr_real q[NZ], const sr_real *P,
                         const sr_real *Z, const sr_real *U)
{
    const int N = d->horizon;
    sr_real J = 0, e[NZ];
    int i, j, k;
    for (k = 1; k < N; ++k)
        for (i = 0; i < NZ; ++i) {
            const sr_real ek = Z[k * NZ + i] - m->zs[k * NZ + i];
            J += q[i] * ek * ek;
        }
    for (i = 0; i < NZ; ++i) e[i] = Z[N * NZ + i] - m->zs[N * NZ + i];
    for (i = 0; i < NZ; ++i)
        for (j = 0; j < NZ; ++j) J += e[i] * P[i * NZ + j] * e[j];
    for (k = 0; k < N * SR_NU; ++k) {
        const sr_real du = U[k] - m->us[k];
        J += d->r * du * du;
        if (m->have_u_last && d->r_step > 0) {
            const sr_real step = U[k] - (k < SR_NU ? m->u_last[k] : U[k - SR_NU]);
            J += d->r_step * step * step;
        }
    }
    return J;
}

/* U clipped to the torque limits and rolled out from z0 into Z, *J its objective; nonzero when the
 * rollout or the objective is not finite. */
static int start(const sr_nmpc *d, sr_nmpc_memory *m, const sr_model *model, const sr_real z0[NZ], sr_real v,
                 const sr_real q[NZ], const sr_real *P, sr_real *U, sr_real *Z, sr_real *J)
{
    int i;
    for (i = 0; i < SR_NU * d->horizon; ++i) U[i] = U[i] > d->u_max ? d->u_max : (U[i] < -d->u_max ? -d->u_max : U[i]);
    if (rollout(d, m, model, z0, v, U, Z)) return 1;
    *J = objective(d, m, q, P, Z, U);
    return !all_finite(J, 1);
}

/* A start that cannot diverge: the torques of the guess in m->U (if guess) or the reference's,
 * whichever's rollout from the measured z0 costs less, then up to cold_iterations Gauss-Newton
 * steps on these gap-free nodes, each QP's step halved (up to SR_NMPC_HALVINGS times) until the
 * rolled-out nodes are finite and the objective falls; a step that does not is dropped and the
 * iterations end.  The result in m->Z, m->U; nonzero only when neither start rolls out. */
static int recover(const sr_nmpc *d, sr_nmpc_memory *m, const sr_model *model, const sr_real z0[NZ], sr_real v,
                   const sr_real q[NZ], const sr_real *P, int guess)
{
    const int N = d->horizon, nq = SR_NU * N;
    sr_real J = 0, Jn = 0, alpha;
    int it, h, i, from_guess;
    from_guess = guess && !start(d, m, model, z0, v, q, P, m->U, m->Z, &J);
    memcpy(m->Un, m->us, (size_t)nq * sizeof(sr_real));
    if (start(d, m, model, z0, v, q, P, m->Un, m->Zn, &Jn)) {
        if (!from_guess) return 1;
    } else if (!from_guess || Jn < J) {
        J = Jn;
        memcpy(m->Z, m->Zn, (size_t)(N + 1) * NZ * sizeof(sr_real));
        memcpy(m->U, m->Un, (size_t)nq * sizeof(sr_real));
    }
    for (it = 0; it < d->cold_iterations; ++it) {
        if (iteration(d, m, model, z0, v, q, P)) break;
        for (h = 0, alpha = 1; h <= SR_NMPC_HALVINGS; ++h, alpha *= SR_C(0.5)) {
            for (i = 0; i < nq; ++i) m->Un[i] = m->U[i] + alpha * m->dU[i];
            if (rollout(d, m, model, z0, v, m->Un, m->Zn)) continue;
            Jn = objective(d, m, q, P, m->Zn, m->Un);
            if (all_finite(&Jn, 1) && Jn < J) break;
        }
        if (h > SR_NMPC_HALVINGS) break;
        J = Jn;
        memcpy(m->Z, m->Zn, (size_t)(N + 1) * NZ * sizeof(sr_real));
        memcpy(m->U, m->Un, (size_t)nq * sizeof(sr_real));
    }
    return 0;
}

/* The rows of z the offsets are estimated from: the pendulum and the rates (3 .. 8), which do not
 * depend on where the reference's nearest point falls. */
#define D_FIRST 3
#define D_LAST 8

/* (d, a) += gain * argmin |B1 delta + period (0, alpha, 0) - r|, r = z - Phi_1(z_last, u_last + d)
 * - period (0, a, 0), over rows D_FIRST .. D_LAST: the last sample predicted over one period against
 * the measured z, B1 the prediction's torque Jacobian, alpha the shell rates' acceleration (rows
 * Z_SHELL ..).  alpha is free on the shell's rows, so they are fitted exactly: delta is the
 * least-squares fit of the other rows (the pendulum, the joints' rates), alpha what is left on the
 * shell's.  d is clipped to +-u_max.  Leaves d and a as they are when the prediction fails. */
static void estimate_disturbance(const sr_nmpc *d, sr_nmpc_memory *m, const sr_model *model, const sr_real z[NZ])
{
    sr_real ud[SR_NU], zp[NZ], res[NZ], BtB[3] = {0, 0, 0}, Btr[2] = {0, 0}, det, step[2], alpha[3];
    const sr_real *B = m->B[0];
    int i, j;
    ud[0] = m->u_last[0] + m->disturbance[0];
    ud[1] = m->u_last[1] + m->disturbance[1];
    /* A[0], B[0] are scratch here: the iteration overwrites them. */
    if (node(model, m->z_last, ud, m->v_last, m->kappa_last, d->period, zp, m->A[0], m->B[0]) != SR_OK) return;
    for (j = 0; j < 3; ++j) zp[Z_SHELL + j] += d->period * m->shell_accel[j];
    for (i = D_FIRST; i <= D_LAST; ++i) res[i] = z[i] - zp[i];
    for (i = D_FIRST; i <= D_LAST; ++i) {
        const sr_real b0 = B[i * SR_NU], b1 = B[i * SR_NU + 1];
        if (i >= Z_SHELL && i < Z_SHELL + 3) continue;
        BtB[0] += b0 * b0;
        BtB[1] += b0 * b1;
        BtB[2] += b1 * b1;
        Btr[0] += b0 * res[i];
        Btr[1] += b1 * res[i];
    }
    det = BtB[0] * BtB[2] - BtB[1] * BtB[1];
    if (!(det > 0) || !all_finite(&det, 1)) return;
    step[0] = (BtB[2] * Btr[0] - BtB[1] * Btr[1]) / det;
    step[1] = (BtB[0] * Btr[1] - BtB[1] * Btr[0]) / det;
    for (j = 0; j < 3; ++j)
        alpha[j] = (res[Z_SHELL + j] - B[(Z_SHELL + j) * SR_NU] * step[0] - B[(Z_SHELL + j) * SR_NU + 1] * step[1])
                 / d->period;
    if (!all_finite(step, SR_NU) || !all_finite(alpha, 3)) return;
    for (j = 0; j < SR_NU; ++j) {
        const sr_real dj = m->disturbance[j] + d->disturbance_gain * step[j];
        m->disturbance[j] = dj > d->u_max ? d->u_max : (dj < -d->u_max ? -d->u_max : dj);
    }
    for (j = 0; j < 3; ++j) m->shell_accel[j] += d->disturbance_gain * alpha[j];
}

static sr_real wrap(sr_real angle)
{
    /* into [-pi, pi): the heading jump test needs only the magnitude */
    while (angle >= PI_) angle -= 2 * PI_;
    while (angle < -PI_) angle += 2 * PI_;
    return angle;
}

int sr_nmpc_step(const sr_nmpc *d, sr_nmpc_memory *m, const sr_model *model, const sr_real x[SR_NX],
                 const sr_nmpc_target *target, sr_real u[SR_NU])
{
    sr_lqr_target lt;
    sr_real z[SR_LQR_NZ], integrals[2], v, heading_change;
    const sr_real *q, *P;
    int status = arg_model(model, READS(WHOLE)), N, k, j, cold, path, failed, jumped;
    if (status != SR_OK) return status;
    if (!d || !m || !x || !target || !u) return SR_ERR_NULL;
    /* The whole design, every sample (a few microseconds): a corrupt entry never reaches the torques. */
    status = sr_nmpc_check(d);
    if (status != SR_OK) return status;
    N = d->horizon;
    path = target->path != 0;
    if (!all_finite(&target->speed, 1) || !all_finite(&target->heading, 1)
        || (path && (!all_finite(&target->curvature, 1) || !all_finite(&target->cross_track, 1)))
        || (path && target->curvature_ahead && !all_finite(target->curvature_ahead, N + 1))
        || !all_finite(&m->integral, 1) || !all_finite(&m->heading, 1))
        return SR_ERR_NONFINITE;
    /* z0: the measured error coordinates (the checks of sr_lqr_error: x in full). */
    lt.speed = target->speed;
    lt.heading = target->heading;
    lt.curvature = path ? target->curvature : 0;
    lt.cross_track = path ? target->cross_track : 0;
    lt.path = path;
    integrals[0] = path ? m->integral : 0;
    integrals[1] = 0;
    status = sr_lqr_error(model, x, &lt, integrals, z);
    if (status != SR_OK) return status;
    v = target->speed;
    heading_change = wrap(target->heading - m->heading);
    jumped = SR_FABS(heading_change) > d->heading_jump;
    if (m->have_last && !jumped && d->disturbance_gain > 0) estimate_disturbance(d, m, model, z);
    for (k = 0; k <= N; ++k)
        m->kappa[k] = !path ? 0 : (target->curvature_ahead ? target->curvature_ahead[k] : target->curvature);
    references(d, m, v);
    /* The torques that hold the reference on a plant driven by u + d. */
    for (k = 0; k < N * SR_NU; ++k) m->us[k] -= m->disturbance[k % SR_NU];

    if (m->have_guess && jumped) m->have_guess = 0;
    m->heading = target->heading;
    cold = !m->have_guess;
    if (cold) {
        memcpy(m->Z, m->zs, (size_t)(N + 1) * NZ * sizeof(sr_real));
        memcpy(m->U, m->us, (size_t)N * SR_NU * sizeof(sr_real));
    } else if (m->samples % d->node_periods == 0) { /* a node has passed: the guess one node on */
        memmove(m->Z, m->Z + NZ, (size_t)N * NZ * sizeof(sr_real));
        memmove(m->U, m->U + SR_NU, (size_t)(N - 1) * SR_NU * sizeof(sr_real));
    }
    {
        const int i = nearest(d->speeds, d->n_speeds, v), jj = nearest(d->curvatures, d->n_curvatures, m->kappa[N]);
        P = (path ? d->P_path : d->P_heading)[i * d->n_curvatures + jj];
        q = path ? d->q_path : d->q_heading;
    }
    /* After a failed sample, and for SR_NMPC_RECOVERY_SAMPLES samples after a failed restart, the
     * start is the recovery's.  Else the guess's; when its iterations fail, the reference's; when
     * those fail too, the recovery's. */
    if (m->failing > 0 || m->recovering > 0) {
        if (m->recovering > 0) m->recovering--;
        m->recoveries++;
        failed = recover(d, m, model, z, v, q, P, m->failing == 0);
    } else if (iterate(d, m, model, z, v, q, P, cold ? d->cold_iterations : d->iterations)) {
        m->restarts++;
        failed = 1;
        if (!cold) { /* a cold start was from the reference already */
            memcpy(m->Z, m->zs, (size_t)(N + 1) * NZ * sizeof(sr_real));
            memcpy(m->U, m->us, (size_t)N * SR_NU * sizeof(sr_real));
            failed = iterate(d, m, model, z, v, q, P, d->cold_iterations);
        }
        if (failed) {
            m->recoveries++;
            m->recovering = SR_NMPC_RECOVERY_SAMPLES;
            failed = recover(d, m, model, z, v, q, P, 1);
        }
    } else {
        failed = 0;
    }
    m->samples++;
    if (failed) { /* no prediction at all: hold the reference's torques */
        m->failures++;
        m->failing++;
        m->recovering = SR_NMPC_RECOVERY_SAMPLES;
        m->have_guess = m->have_last = 0;
        for (j = 0; j < SR_NU; ++j) u[j] = m->us[j] > d->u_max ? d->u_max : (m->us[j] < -d->u_max ? -d->u_max : m->us[j]);
        m->saturated = SR_FABS(u[0]) >= d->u_max || SR_FABS(u[1]) >= d->u_max;
        return SR_OK;
    }
    m->failing = 0;
    m->have_guess = 1;
    m->have_u_last = 1;
    m->u_last[0] = m->U[0];
    m->u_last[1] = m->U[1];
    memcpy(m->z_last, z, sizeof m->z_last);
    m->v_last = v;
    m->kappa_last = m->kappa[0];
    m->have_last = 1;
    /* The integral advances at any offset unless a torque is at its bound (anti-windup) or the
     * error moves faster than steady_rate (a transient the loop is removing). */
    if (path && SR_FABS(m->U[0]) < d->u_max * FREE_SHARE && SR_FABS(m->U[1]) < d->u_max * FREE_SHARE
        && SR_FABS(cross_track_rate(model, x, target->heading)) <= d->steady_rate)
        m->integral += d->period * target->cross_track;
    for (j = 0; j < SR_NU; ++j) u[j] = m->U[j] > d->u_max ? d->u_max : (m->U[j] < -d->u_max ? -d->u_max : m->U[j]);
    m->saturated = SR_FABS(u[0]) >= d->u_max || SR_FABS(u[1]) >= d->u_max;
    return SR_OK;
}
