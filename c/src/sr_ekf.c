/* sr_ekf.c -- the error-state EKF on the group (contract and equations: c/include/sr_ekf.h).
 * Every call works on local copies and writes the filter only when it succeeds. */
#include "sr_ekf.h"
#include "sr_argcheck.h"
#include "sr_checks.h"
#include "sr_so3.h"
#include "sr_kernels.h"
#include "sr_jacobians.h"
#include "sr_steppers.h"
#include "sr_unchecked.h"

#include <string.h>

#define NB SR_NEB
#define NE SR_NE
#define MAXM SR_NIMU /* the largest sample */
/* The stride of the update's rows (gain, cross-covariance, Joseph terms, new covariance): NB
 * padded with zeros to a multiple of four, so that every row operation is whole vectors of two or
 * four numbers, without a remainder. */
#define NBP (NB + 3 - (NB + 3) % 4)

#ifdef SR_USE_FLOAT
#define SR_FMOD fmodf
#else
#define SR_FMOD fmod
#endif

/* The predict's pairs of rows need an even NE; its skip of the dq columns, that they are the two
 * before nu. */
typedef char layout_fits[(NE % 2 == 0 && SR_E_nu == SR_E_q + 2) ? 1 : -1];
/* The predict's sparse F_d P F_d^T: the attitude first, the two joint angles, q, then the five rates. */
typedef char nv_fits[SR_NV == 5 ? 1 : -1];   /* the held disturbance's rows of five, in registers */
typedef char order_fits[(SR_E_xi_S == 0 && SR_E_th_Y == 3 && SR_E_th_P == 4 && SR_E_q == 5 && NE == SR_E_nu + 5) ? 1 : -1];

static const sr_real pi_ = SR_C(3.14159265358979323846);

/* a - b wrapped into (-pi, pi]: the innovation of an angle. */
static sr_real angle_difference(sr_real a, sr_real b)
{
    const sr_real two_pi = 2 * pi_;
    sr_real w = SR_FMOD(a - b + pi_, two_pi);
    if (w < 0) w += two_pi;
    w -= pi_;
    return w == -pi_ ? pi_ : w;
}

/* y <- y - a x and y <- y + a x over a row of NB: restrict-qualified, so that the compiler
 * vectorises them without a run-time overlap test (rows of one array looked as if they might
 * overlap, and the loop ran scalar). */
static inline void row_minus(sr_real a, const sr_real *restrict x, sr_real *restrict y)
{
    int k;
    for (k = 0; k < NBP; ++k) y[k] -= a * x[k];
}

static inline void row_plus(sr_real a, const sr_real *restrict x, sr_real *restrict y)
{
    int k;
    for (k = 0; k < NB; ++k) y[k] += a * x[k];
}

/* The same with two rows a pass (half the loads and stores of y). */
static inline void rows_minus2(sr_real a, const sr_real *restrict x, sr_real b, const sr_real *restrict z,
                               sr_real *restrict y)
{
    int k;
    for (k = 0; k < NBP; ++k) y[k] -= a * x[k] + b * z[k];
}

static inline void rows_plus2(sr_real a, const sr_real *restrict x, sr_real b, const sr_real *restrict z,
                              sr_real *restrict y)
{
    int k;
    for (k = 0; k < NB; ++k) y[k] += a * x[k] + b * z[k];
}

/* A = L L^T for a symmetric n x n A (row-major; only its lower triangle is read).  SR_ERR_SINGULAR
 * when a pivot is not positive (A not positive definite, or NaN). */
static int cholesky(int n, const sr_real *A, sr_real *L)
{
    int i, j, k;
    for (j = 0; j < n; ++j) {
        sr_real s = A[n * j + j];
        for (k = 0; k < j; ++k) s -= L[n * j + k] * L[n * j + k];
        if (!(s > 0)) return SR_ERR_SINGULAR;
        L[n * j + j] = SR_SQRT(s);
        for (i = j + 1; i < n; ++i) {
            sr_real t = A[n * i + j];
            for (k = 0; k < j; ++k) t -= L[n * i + k] * L[n * j + k];
            L[n * i + j] = t / L[n * j + j];
        }
        for (i = 0; i < j; ++i) L[n * i + j] = 0;
    }
    return SR_OK;
}

/* b <- L^-1 b, then (solve_both) L^-T of that: b <- (L L^T)^-1 b. */
static void forward(int n, const sr_real *L, sr_real *b)
{
    int i, k;
    for (i = 0; i < n; ++i) {
        sr_real s = b[i];
        for (k = 0; k < i; ++k) s -= L[n * i + k] * b[k];
        b[i] = s / L[n * i + i];
    }
}

static void solve_both(int n, const sr_real *L, sr_real *b)
{
    int i, k;
    forward(n, L, b);
    for (i = n - 1; i >= 0; --i) {
        sr_real s = b[i];
        for (k = i + 1; k < n; ++k) s -= L[n * k + i] * b[k];
        b[i] = s / L[n * i + i];
    }
}

/* The filter's own data: x a valid state, biases and P finite. */
static SR_LANES_CLONES int check_filter(const sr_model *model, const sr_ekf *ekf)
{
    const int status = sr_internal_check_state(model, ekf->x);
    if (status != SR_OK) return status;
    return all_finite(ekf->bias, SR_NBIAS) && all_finite(ekf->P, NB * NB) ? SR_OK : SR_ERR_NONFINITE;
}

static int positive(sr_real v) { return v > 0 && isfinite(v); }

/* A gate: > 0, +infinity allowed (every sample accepted), NaN refused. */
static int valid_gate(sr_real gate) { return gate > 0; }

int sr_ekf_init(sr_ekf *ekf, const sr_model *model, const sr_real x0[SR_NX], const sr_real bias[SR_NBIAS],
                const sr_real P0[SR_NEB * SR_NEB])
{
    sr_real L[NB * NB], scale = 0;
    int status = arg_model(model, READS(WHOLE)), i, j;
    if (status != SR_OK) return status;
    if (!ekf || !x0 || !P0) return SR_ERR_NULL;
    if (!all_finite(P0, NB * NB)) return SR_ERR_ARG;
    for (i = 0; i < NB; ++i) scale = P0[NB * i + i] > scale ? P0[NB * i + i] : scale;
    for (i = 0; i < NB; ++i)
        for (j = 0; j < i; ++j)
            if (SR_FABS(P0[NB * i + j] - P0[NB * j + i]) > SR_C(1e-12) * scale) return SR_ERR_ARG;
    status = sr_internal_check_state(model, x0);
    if (status != SR_OK) return status;
    if (bias && !all_finite(bias, SR_NBIAS)) return SR_ERR_NONFINITE;
    status = cholesky(NB, P0, L);
    if (status != SR_OK) return status;
    memset(ekf, 0, sizeof *ekf);
    memcpy(ekf->x, x0, sizeof ekf->x);
    if (bias) memcpy(ekf->bias, bias, sizeof ekf->bias);
    /* Stored exactly symmetric: the updates read one triangle as the whole. */
    for (i = 0; i < NB; ++i)
        for (j = 0; j < NB; ++j) ekf->P[NB * i + j] = j >= i ? P0[NB * i + j] : P0[NB * j + i];
    return SR_OK;
}

int sr_ekf_init_diagonal(sr_ekf *ekf, const sr_model *model, const sr_real x0[SR_NX], const sr_real bias[SR_NBIAS],
                         const sr_real sigma[SR_NEB])
{
    sr_real P0[NB * NB];
    int status = arg_model(model, READS(WHOLE)), i;
    if (status != SR_OK) return status;
    if (!ekf || !x0 || !sigma) return SR_ERR_NULL;
    for (i = 0; i < NB; ++i)
        if (!positive(sigma[i])) return SR_ERR_ARG;
    memset(P0, 0, sizeof P0);
    for (i = 0; i < NB; ++i) P0[NB * i + i] = sigma[i] * sigma[i];
    return sr_ekf_init(ekf, model, x0, bias, P0);
}

static int valid_process(const sr_ekf_process *q)
{
    int i;
    for (i = 0; i < 3; ++i)
        if (!(q->torque_psd[i] >= 0 && isfinite(q->torque_psd[i]))) return 0;
    return q->gyro_bias_rw >= 0 && isfinite(q->gyro_bias_rw) && q->accel_bias_rw >= 0 && isfinite(q->accel_bias_rw);
}

/* Q_nu = dt M^-1 D^2 M^-1 (D = diag of the torque densities) from M^-1 (the factorisation of the
 * accelerations' Jacobian, sr_internal_accel_jacobian_minv): Z = M^-1 D, Q = dt Z Z^T, exactly
 * symmetric. */
static void torque_noise_of(const sr_real Minv[SR_NV * SR_NV], const sr_ekf_process *q, sr_real dt,
                            sr_real Q[SR_NV * SR_NV])
{
    sr_real Z[SR_NV * SR_NV];
    const sr_real d[SR_NV] = {q->torque_psd[0], q->torque_psd[0], q->torque_psd[0], q->torque_psd[1],
                              q->torque_psd[2]};
    int i, j, k;
    for (i = 0; i < SR_NV; ++i)
        for (k = 0; k < SR_NV; ++k) Z[SR_NV * i + k] = Minv[SR_NV * i + k] * d[k];
    for (i = 0; i < SR_NV; ++i)
        for (j = i; j < SR_NV; ++j) {
            sr_real s = 0;
            for (k = 0; k < SR_NV; ++k) s += Z[SR_NV * i + k] * Z[SR_NV * j + k];
            Q[SR_NV * i + j] = Q[SR_NV * j + i] = dt * s;
        }
}

/* How long of the predict's dt a held disturbance still drives: the rest of its period, at most dt
 * (0: none held). */
static sr_real held_for(const sr_ekf_held *h, sr_real dt)
{
    return !h->pending ? 0 : h->remaining < dt ? h->remaining : dt;
}

/* A held disturbance a (sr_ekf.h, "Held disturbance") over g of the predict, in place of the torque
 * noise there: e' = Phi e + Gm a with Gm = g on nu's rows, a' = a, so x_nu += g a_hat,
 * P' += Phi C Gm^T + Gm C^T Phi^T + Gm A Gm^T (Phi = diag(F, I)) and next->cross = Phi C + Gm A.
 * next is the held disturbance after the predict: spent when its period is. */
static SR_LANES_CLONES void step_held(const sr_ekf_held *h, const sr_real F[NE * NE], sr_real g, sr_real dt,
                                      sr_real xn[SR_NX], sr_real *Pn, sr_ekf_held *next)
{
    sr_real *Y = next->cross;
    int i, j, k;
    *next = *h;
    if (!h->pending) return;
    for (i = 0; i < SR_NV; ++i) xn[SR_X_w_S + i] += g * h->mean[i];
    /* Phi C: row i of F C sums the rows of C (SR_NV numbers each), in the order of the columns. */
    for (i = 0; i < NE; ++i) {   /* five sums in registers; F's zeros skipped (most of its rows are sparse) */
        const sr_real *f = F + NE * i;
        sr_real y0 = 0, y1 = 0, y2 = 0, y3 = 0, y4 = 0;
        for (k = 0; k < NE; ++k) {
            const sr_real fk = f[k], *c = h->cross + SR_NV * k;
            if (fk == 0) continue;
            y0 += fk * c[0];
            y1 += fk * c[1];
            y2 += fk * c[2];
            y3 += fk * c[3];
            y4 += fk * c[4];
        }
        Y[SR_NV * i] = y0;
        Y[SR_NV * i + 1] = y1;
        Y[SR_NV * i + 2] = y2;
        Y[SR_NV * i + 3] = y3;
        Y[SR_NV * i + 4] = y4;
    }
    for (i = 0; i < NB; ++i) {
        const sr_real *y = Y + SR_NV * i;
        sr_real *p = Pn + NB * i + SR_EB_nu;
        for (j = 0; j < SR_NV; ++j) {
            p[j] += g * y[j];
            Pn[NB * (SR_EB_nu + j) + i] += g * y[j];
        }
    }
    for (i = 0; i < SR_NV; ++i)
        for (j = 0; j < SR_NV; ++j) {
            Pn[NB * (SR_EB_nu + i) + SR_EB_nu + j] += g * g * h->cov[SR_NV * i + j];
            Y[SR_NV * (SR_EB_nu + i) + j] += g * h->cov[SR_NV * i + j];
        }
    next->remaining = h->remaining - g;
    if (!(next->remaining > SR_C(1e-9) * dt)) memset(next, 0, sizeof *next);
}

/* After the predict: the waiting fixes' C_j gain Gm Cov(a, z_j) (g of the held a), and the held
 * disturbance is what step_held left. */
static void release_held(sr_ekf *ekf, sr_real g, const sr_ekf_held *next)
{
    int i, b, k;
    for (k = 0; k < SR_EKF_NDELAYED && ekf->held.pending; ++k) {
        if (!ekf->delayed[k].marked) continue;
        for (i = 0; i < SR_NV; ++i)
            for (b = 0; b < 2; ++b)
                ekf->delayed[k].C[2 * (SR_EB_nu + i) + b] += g * ekf->held.fix[2 * SR_NV * k + 2 * i + b];
    }
    ekf->held = *next;
}

/* x_next = the step of `method` (sr_step's bits) and F the transition matrix: the Lie-Euler step's
 * Jacobian at x, whatever the method (sr_ekf.h, "Transition matrix"), one evaluation of the
 * accelerations' Jacobian instead of one per stage; Minv (not NULL) = M^-1 at x from its
 * factorisation, for the process noise.  x valid, u finite, method and dt valid. */
static int step_and_transition(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                               sr_real dt, sr_real x_next[SR_NX], sr_real F[NE * NE], sr_real Minv[SR_NV * SR_NV])
{
    int status = sr_internal_advance(model, method, x, u, dt, NULL, x_next);
    if (status == SR_OK && !all_finite(x_next, SR_NX)) status = SR_ERR_NONFINITE;
    if (status == SR_OK) status = sr_internal_step_jacobian_lie_euler_minv(model, x, u, dt, F, NULL, Minv);
    return status;
}

/* ---- The observability constraint (sr_ekf.h, "Observability constraint"): off, none of it runs. */

/* N(x) (NE x 3 row-major; the columns beyond the count returned are zero): the turn about the
 * floor's normal (on a level floor only), then the moves along the floor's x and y. */
static int unobservable(const sr_model *model, const sr_real x[SR_NX], sr_real N[NE * 3])
{
    int i, c = 0;
    memset(N, 0, NE * 3 * sizeof(sr_real));
    if (model->p[SR_P_slope] == 0) {
        for (i = 0; i < 3; ++i) N[3 * (SR_E_xi_S + i)] = x[SR_X_R_S + 6 + i];   /* R_S^T e_z: R_S's third row */
        N[3 * SR_E_q] = -x[SR_X_q + 1];
        N[3 * (SR_E_q + 1)] = x[SR_X_q];
        c = 1;
    }
    N[3 * SR_E_q + c] = 1;
    N[3 * (SR_E_q + 1) + c + 1] = 1;
    return c + 2;
}

/* d = (A N - B) (N^T N)^-1 (rows x 3, stride 3) for the first NE columns of `rows` rows of A (stride
 * `stride`), B rows x 3 (NULL: zero): A - d N^T is the nearest matrix to A with (A - d N^T) N = B.
 * N^T N is positive definite: its translations are unit vectors, its turn has a unit attitude part
 * (moved by resets, near unit). */
static void constraint_weights(int rows, int stride, const sr_real *A, const sr_real *N, int cols, const sr_real *B,
                               sr_real *d)
{
    sr_real G[9], L[9];
    int a, b, i, k;
    for (a = 0; a < cols; ++a)
        for (b = 0; b < cols; ++b) {
            sr_real s = 0;
            for (k = 0; k < NE; ++k) s += N[3 * k + a] * N[3 * k + b];
            G[cols * a + b] = s;
        }
    (void)cholesky(cols, G, L);
    for (i = 0; i < rows; ++i) {
        const sr_real *row = A + stride * i;
        sr_real *di = d + 3 * i;
        for (a = 0; a < cols; ++a) {
            sr_real s = B ? -B[3 * i + a] : 0;
            for (k = 0; k < NE; ++k) s += row[k] * N[3 * k + a];
            di[a] = s;
        }
        solve_both(cols, L, di);
    }
}

/* H <- H* = H - H N_k (N_k^T N_k)^-1 N_k^T for an IMU or encoder sample of m rows (stride NB). */
static void constrain_sample(const sr_ekf *ekf, int m, sr_real *H)
{
    sr_real d[MAXM * 3];
    int a, i, k;
    constraint_weights(m, NB, H, ekf->null_space, ekf->null_cols, NULL, d);
    for (i = 0; i < m; ++i)
        for (k = 0; k < NE; ++k)
            for (a = 0; a < ekf->null_cols; ++a) H[NB * i + k] -= d[3 * i + a] * ekf->null_space[3 * k + a];
}

/* The predict's transition with the constraint: Nn = N(xn), F <- F* = F + dF with F* N_k = Nn, and
 * Pn += Phi* P Phi*^T - Phi P Phi^T = dPhi P Phi*^T + Phi P dPhi^T (Phi = diag(F, I), dPhi = diag(dF, 0),
 * P the prior), added to the sparse product's Pn.  dF = -d N^T has rank <= 3, so with W = N^T P
 * (3 x NB): dF P = -d W, dF P_dd F*^T = -d X (X = W_dd F*^T), F P_dd dF^T = -Y d^T (Y = F W_dd^T),
 * about 2700 products. */
static void constrain_predict(const sr_model *model, const sr_ekf *ekf, const sr_real xn[SR_NX], sr_real F[NE * NE],
                              sr_real Pn[NB * NB], sr_real Nn[NE * 3])
{
    sr_real d[NE * 3] = {0}, W[3 * NB], X[3 * NE], Y[NE * 3];
    const sr_real *N = ekf->null_space;
    int a, i, j, k;
    (void)unobservable(model, xn, Nn);
    /* three columns throughout (a third left zero on a slope, in N and in d): loops of a fixed length */
    constraint_weights(NE, NE, F, N, ekf->null_cols, Nn, d);
    for (a = 0; a < 3; ++a)
        for (j = 0; j < NB; ++j) {
            sr_real s = 0;
            for (k = 0; k < NE; ++k) s += N[3 * k + a] * ekf->P[NB * k + j];
            W[NB * a + j] = s;
        }
    for (i = 0; i < NE; ++i)   /* Y = F W_dd^T with the F of the sparse product */
        for (a = 0; a < 3; ++a) {
            sr_real s = 0;
            for (k = 0; k < NE; ++k) s += F[NE * i + k] * W[NB * a + k];
            Y[3 * i + a] = s;
        }
    for (i = 0; i < NE; ++i)   /* F <- F* */
        for (k = 0; k < NE; ++k)
            for (a = 0; a < 3; ++a) F[NE * i + k] -= d[3 * i + a] * N[3 * k + a];
    for (a = 0; a < 3; ++a)
        for (j = 0; j < NE; ++j) {
            sr_real s = 0;
            for (k = 0; k < NE; ++k) s += W[NB * a + k] * F[NE * j + k];
            X[NE * a + j] = s;
        }
    for (i = 0; i < NE; ++i) {
        for (j = 0; j <= i; ++j) {
            sr_real s = 0;
            for (a = 0; a < 3; ++a) s += d[3 * i + a] * X[NE * a + j] + Y[3 * i + a] * d[3 * j + a];
            Pn[NB * i + j] -= s;
            if (j < i) Pn[NB * j + i] = Pn[NB * i + j];
        }
        for (j = NE; j < NB; ++j) {
            sr_real s = 0;
            for (a = 0; a < 3; ++a) s += d[3 * i + a] * W[NB * a + j];
            Pn[NB * i + j] -= s;
            Pn[NB * j + i] = Pn[NB * i + j];
        }
    }
}

/* N <- G N after an applied sample's reset (G = Jr on the attitude's rows). */
static void carry_null_space(sr_ekf *ekf, const sr_real Jr[9])
{
    sr_real t[9];
    int i, c;
    for (i = 0; i < 3; ++i)
        for (c = 0; c < 3; ++c)
            t[3 * i + c] = Jr[3 * i] * ekf->null_space[3 * SR_E_xi_S + c] + Jr[3 * i + 1] * ekf->null_space[3 * (SR_E_xi_S + 1) + c]
                         + Jr[3 * i + 2] * ekf->null_space[3 * (SR_E_xi_S + 2) + c];
    memcpy(ekf->null_space + 3 * SR_E_xi_S, t, sizeof t);
}

int sr_ekf_set_observability_constraint(sr_ekf *ekf, const sr_model *model, int on)
{
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!ekf) return SR_ERR_NULL;
    if (on != 0 && on != 1) return SR_ERR_ARG;
    status = check_filter(model, ekf);
    if (status != SR_OK) return status;
    memset(ekf->null_space, 0, sizeof ekf->null_space);
    ekf->null_cols = on ? unobservable(model, ekf->x, ekf->null_space) : 0;
    ekf->constrained = on;
    return SR_OK;
}

SR_LANES_CLONES int sr_ekf_predict(sr_ekf *ekf, const sr_model *model, int method, const sr_real u[SR_NU], sr_real dt,
                   const sr_ekf_process *process)
{
    sr_real xn[SR_NX], F[NE * NE], Minv[SR_NV * SR_NV], Qnu[SR_NV * SR_NV], T[NE * NBP], Pp[NE * NBP], Pn[NB * NB], g, white;
    sr_real Nn[NE * 3];   /* the constraint's N at the predicted state */
    sr_ekf_held next;
    int status = arg_model(model, READS(WHOLE)), i, j, k, dq_identity = 1, cols[NE], ncols = 0;
    if (status != SR_OK) return status;
    if (!ekf || !process) return SR_ERR_NULL;
    if (arg_method(method) != SR_OK || arg_dt(dt) != SR_OK || !valid_process(process)) return SR_ERR_ARG;
    if (u && !all_finite(u, SR_NU)) return SR_ERR_NONFINITE;
    status = check_filter(model, ekf);
    /* A held disturbance drives g of dt; the torque noise the rest (white, a share of Q_nu). */
    g = held_for(&ekf->held, dt);
    white = (dt - g) / dt;
    /* The state and u are checked: the step of `method`, and F (sr_ekf.h, "Transition matrix");
     * M^-1 only for a share of white noise. */
    if (status == SR_OK)
        status = step_and_transition(model, method, ekf->x, u ? u : sr_zero_u, dt, xn, F, white > 0 ? Minv : NULL);
    if (status != SR_OK) return status;
    if (white > 0) torque_noise_of(Minv, process, dt, Qnu);

    /* F P F^T with F = [[F_d, 0], [0, I]] blockwise: T = F_d [P_dd P_db] (the cross terms F_d P_db come
     * with it), then F_d P_dd F_d^T = T_dd F_d^T on the upper triangle.  The steps' F_d has the
     * identity's dq columns (nothing in a step depends on where the robot stands,
     * sr_step_jacobian): when it does, the first product skips those two columns and takes the
     * dq rows of P as they are (the second, a twelfth of the work, multiplies by their 0 and 1). */
    for (k = 0; k < NE; ++k) {
        const int dq = k == SR_E_q || k == SR_E_q + 1;
        for (i = 0; i < NE && dq; ++i) dq_identity &= F[NE * i + k] == (i == k ? 1 : 0);
    }
    for (k = 0; k < NE; ++k)   /* the columns summed */
        if (!dq_identity || (k != SR_E_q && k != SR_E_q + 1)) cols[ncols++] = k;
    /* P's first NE rows padded to NBP (whole vectors, no remainder). */
    for (i = 0; i < NE; ++i) {
        memcpy(Pp + NBP * i, ekf->P + NB * i, NB * sizeof(sr_real));
        for (j = NB; j < NBP; ++j) Pp[NBP * i + j] = 0;
    }
    for (i = 0; i < NE; ++i) {
        if (dq_identity && (i == SR_E_q || i == SR_E_q + 1))
            memcpy(T + NBP * i, Pp + NBP * i, NBP * sizeof(sr_real));
        else
            memset(T + NBP * i, 0, NBP * sizeof(sr_real));
    }
    /* Two rows of T and two rows of P a pass: each load serves two products. */
    for (i = 0; i < NE; i += 2) {
        sr_real *T0 = T + NBP * i, *T1 = T0 + NBP;
        const sr_real *F0 = F + NE * i, *F1 = F0 + NE;
        for (k = 0; k + 1 < ncols; k += 2) {
            const sr_real a0 = F0[cols[k]], a1 = F0[cols[k + 1]], b0 = F1[cols[k]], b1 = F1[cols[k + 1]];
            const sr_real *P0 = Pp + NBP * cols[k], *P1 = Pp + NBP * cols[k + 1];
            for (j = 0; j < NBP; ++j) {
                T0[j] += a0 * P0[j] + a1 * P1[j];
                T1[j] += b0 * P0[j] + b1 * P1[j];
            }
        }
        for (; k < ncols; ++k) {
            const sr_real a0 = F0[cols[k]], b0 = F1[cols[k]], *Pk = Pp + NBP * cols[k];
            for (j = 0; j < NBP; ++j) {
                T0[j] += a0 * Pk[j];
                T1[j] += b0 * Pk[j];
            }
        }
    }
    /* Pn_dd[i][j] = T_dd[i] . F_d[j] on the lower triangle (i >= j), over the entries the Lie-Euler
     * Jacobian can make nonzero (its construction, sr_internal_step_jacobian_lie_euler): the
     * attitude's rows read the attitude and w_S, the joint angles' their own angle and rate, q's
     * the attitude, their own q and w_S, the rates' every column but q's (dq_identity; else those
     * too).  473 products instead of the dense upper triangle's 936: the sparse rows of F_d meet
     * most of the lower triangle's entries. */
#define SR_DOT3(t, f, c) ((t[c] * f[c] + t[(c) + 1] * f[(c) + 1]) + t[(c) + 2] * f[(c) + 2])
    for (j = 0; j < SR_E_th_Y; ++j) {
        const sr_real *f = F + NE * j;
        for (i = j; i < NE; ++i) {
            const sr_real *t = T + NBP * i;
            Pn[NB * i + j] = Pn[NB * j + i] = SR_DOT3(t, f, 0) + SR_DOT3(t, f, SR_E_nu);
        }
    }
    for (j = SR_E_th_Y; j < SR_E_q; ++j) {
        const sr_real *f = F + NE * j;
        const int rate = SR_E_nu + 3 + j - SR_E_th_Y;
        for (i = j; i < NE; ++i)
            Pn[NB * i + j] = Pn[NB * j + i] = T[NBP * i + j] * f[j] + T[NBP * i + rate] * f[rate];
    }
    for (j = SR_E_q; j < SR_E_nu; ++j) {
        const sr_real *f = F + NE * j;
        for (i = j; i < NE; ++i) {
            const sr_real *t = T + NBP * i;
            Pn[NB * i + j] = Pn[NB * j + i] = (SR_DOT3(t, f, 0) + t[j] * f[j]) + SR_DOT3(t, f, SR_E_nu);
        }
    }
    for (j = SR_E_nu; j < NE; ++j) {
        const sr_real *f = F + NE * j;
        for (i = j; i < NE; ++i) {
            const sr_real *t = T + NBP * i;
            sr_real s = (SR_DOT3(t, f, 0) + (t[3] * f[3] + t[4] * f[4]))
                      + (SR_DOT3(t, f, SR_E_nu) + (t[SR_E_nu + 3] * f[SR_E_nu + 3] + t[SR_E_nu + 4] * f[SR_E_nu + 4]));
            if (!dq_identity) s += t[SR_E_q] * f[SR_E_q] + t[SR_E_q + 1] * f[SR_E_q + 1];
            Pn[NB * i + j] = Pn[NB * j + i] = s;
        }
    }
#undef SR_DOT3
    for (i = 0; i < SR_NV && white > 0; ++i)
        for (j = 0; j < SR_NV; ++j) Pn[NB * (SR_EB_nu + i) + SR_EB_nu + j] += white * Qnu[SR_NV * i + j];
    /* The cross terms F P_db (in T already); the bias block only gains its random walk. */
    for (i = 0; i < NE; ++i)
        for (j = NE; j < NB; ++j) Pn[NB * i + j] = Pn[NB * j + i] = T[NBP * i + j];
    for (i = NE; i < NB; ++i)
        for (j = NE; j < NB; ++j) Pn[NB * i + j] = ekf->P[NB * i + j];
    for (i = 0; i < 3; ++i) {
        Pn[NB * (SR_EB_b_g + i) + SR_EB_b_g + i] += dt * process->gyro_bias_rw * process->gyro_bias_rw;
        Pn[NB * (SR_EB_b_a + i) + SR_EB_b_a + i] += dt * process->accel_bias_rw * process->accel_bias_rw;
    }
    if (ekf->constrained) constrain_predict(model, ekf, xn, F, Pn, Nn);   /* F <- F* from here on */
    step_held(&ekf->held, F, g, dt, xn, Pn, &next);
    if (!all_finite(Pn, NB * NB)) return SR_ERR_NONFINITE;
    memcpy(ekf->x, xn, sizeof xn);
    memcpy(ekf->P, Pn, sizeof Pn);
    if (ekf->constrained) memcpy(ekf->null_space, Nn, sizeof Nn);
    /* The waiting fixes' cross-covariances: C <- diag(F, I) C (the process noise is independent). */
    for (k = 0; k < SR_EKF_NDELAYED; ++k) {
        sr_real *Ck = ekf->delayed[k].C, t[NE * 2];
        if (!ekf->delayed[k].marked) continue;
        for (i = 0; i < NE; ++i) {
            sr_real s0 = 0, s1 = 0;
            for (j = 0; j < NE; ++j) {
                s0 += F[NE * i + j] * Ck[2 * j];
                s1 += F[NE * i + j] * Ck[2 * j + 1];
            }
            t[2 * i] = s0;
            t[2 * i + 1] = s1;
        }
        memcpy(Ck, t, sizeof t);
    }
    release_held(ekf, g, &next);
    return SR_OK;
}

/* A held disturbance a (sr_ekf.h, "Held disturbance") through an applied sample, e <- G (e - K r): its
 * cross-covariance moves as a waiting fix's, C <- G (C - K Wa) with Wa = Cov(r, a) (m x SR_NV); a
 * itself is not revised; a recovery's lambda scales all of its covariances.  KT as in apply (m rows of NBP). */
static SR_LANES_CLONES void carry_held(sr_ekf_held *h, int m, const sr_real *KT, const sr_real *Wa,
                                       const sr_real Jr[9], sr_real inflate)
{
    sr_real t[3 * SR_NV];
    int a, b, i;
    if (!h->pending) return;
    for (a = 0; a < NB; ++a) {   /* row a of C, its SR_NV numbers in registers, less the sample's m terms in turn */
        sr_real *c = h->cross + SR_NV * a, c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3], c4 = c[4];
        for (i = 0; i < m; ++i) {
            const sr_real k = KT[NBP * i + a], *w = Wa + SR_NV * i;
            c0 -= k * w[0];
            c1 -= k * w[1];
            c2 -= k * w[2];
            c3 -= k * w[3];
            c4 -= k * w[4];
        }
        c[0] = inflate * c0;
        c[1] = inflate * c1;
        c[2] = inflate * c2;
        c[3] = inflate * c3;
        c[4] = inflate * c4;
    }
    for (i = 0; i < SR_NV * SR_NV && inflate != 1; ++i) h->cov[i] *= inflate;
    for (i = 0; i < SR_EKF_NDELAYED * SR_NV * 2 && inflate != 1; ++i) h->fix[i] *= inflate;
    for (i = 0; i < 3; ++i)
        for (b = 0; b < SR_NV; ++b)
            t[SR_NV * i + b] = Jr[3 * i] * h->cross[SR_NV * SR_EB_xi_S + b]
                             + Jr[3 * i + 1] * h->cross[SR_NV * (SR_EB_xi_S + 1) + b]
                             + Jr[3 * i + 2] * h->cross[SR_NV * (SR_EB_xi_S + 2) + b];
    memcpy(h->cross + SR_NV * SR_EB_xi_S, t, sizeof t);
}

/* Cov(r, a) = H C (m x SR_NV) of a sample that does not read a, from its sparse rows. */
static void held_of_sample(const sr_ekf_held *h, int m, const int *nnz, const int *col, const sr_real *val,
                           sr_real *Wa)
{
    int i, b, k;
    for (i = 0; i < m && h->pending; ++i)
        for (b = 0; b < SR_NV; ++b) {
            sr_real s = 0;
            for (k = 0; k < nnz[i]; ++k) s += val[NB * i + k] * h->cross[SR_NV * col[NB * i + k] + b];
            Wa[SR_NV * i + b] = s;
        }
}

/* Applies an m-entry sample with innovation r, the transposed cross-covariance CT = Cov(e, r)^T
 * (m rows of NBP, zero padded) and innovation covariance S (m x m, stride m): gate, gain, the covariance
 * update, injection, reset; W[j] (m x 2, stride 2, at MAXM * 2 j) is Cov(r, z_j) for every waiting
 * slot j (not `released`, the slot this sample comes from, freed whether applied or gated).  The
 * gain and the Joseph terms are kept transposed (m rows of NBP), so that every inner loop runs along
 * a row of NBP contiguous numbers.  The filter is written only on SR_OK.  SR_LANES_CLONES: with
 * -DSR_CLONES also compiled for AVX2 (four numbers a vector, the same bits: no FMA, no contraction),
 * as are update and the predict. */
static SR_LANES_CLONES int apply(sr_ekf *ekf, int kind, int m, const sr_real *r, const sr_real *CT,
                 const sr_real *S, sr_real gate, const sr_real *W, int released, const sr_real *Wa)
{
    sr_real L[MAXM * MAXM], KT[MAXM * NBP], DT[MAXM * NBP], Pn[NB * NBP];
    sr_real z[MAXM], e[NBP], xn[SR_NX], Jr[9], T[3 * NB], nis = 0, inflate = 1;
    int a, b, i, j, k, status, recovering = 0;

    status = cholesky(m, S, L);
    if (status != SR_OK) return status;
    for (i = 0; i < m; ++i) z[i] = r[i];
    forward(m, L, z);
    for (i = 0; i < m; ++i) nis += z[i] * z[i];
    if (!isfinite(nis)) return SR_ERR_NONFINITE;
    if (!(nis <= gate)) {
        if (!(ekf->recover_after[kind] > 0 && ekf->streak[kind] >= ekf->recover_after[kind])) {
            ekf->gated[kind] += 1;
            ekf->streak[kind] += 1;
            ekf->nis[kind] = nis;
            if (released >= 0) ekf->delayed[released].marked = 0;
            return SR_OK;
        }
        /* Recovery: the prior and R times lambda leave K as it is and scale what follows by lambda
         * (the Joseph form is homogeneous in (P, R), the reset and the slots' updates linear). */
        inflate = nis / gate;
        recovering = 1;
    }

    /* K^T = S^-1 C^T = L^-T L^-1 C^T, both substitutions on all NB columns at once, by the pivots'
     * reciprocals (a division per pivot, not per entry); e = K r. */
    for (i = 0; i < m; ++i) {
        sr_real *Ki = KT + NBP * i;
        const sr_real d = 1 / L[m * i + i];
        for (a = 0; a < NBP; ++a) Ki[a] = CT[NBP * i + a];
        for (k = 0; k + 1 < i; k += 2)
            rows_minus2(L[m * i + k], KT + NBP * k, L[m * i + k + 1], KT + NBP * (k + 1), Ki);
        if (k < i) row_minus(L[m * i + k], KT + NBP * k, Ki);
        for (a = 0; a < NBP; ++a) Ki[a] *= d;
    }
    for (i = m - 1; i >= 0; --i) {
        sr_real *Ki = KT + NBP * i;
        const sr_real d = 1 / L[m * i + i];
        for (k = i + 1; k + 1 < m; k += 2)
            rows_minus2(L[m * k + i], KT + NBP * k, L[m * (k + 1) + i], KT + NBP * (k + 1), Ki);
        if (k < m) row_minus(L[m * k + i], KT + NBP * k, Ki);
        for (a = 0; a < NBP; ++a) Ki[a] *= d;
    }
    for (a = 0; a < NBP; ++a) e[a] = 0;
    for (i = 0; i < m; ++i)
        for (a = 0; a < NBP; ++a) e[a] += KT[NBP * i + a] * r[i];
    /* The Joseph form (I - K H) P (I - K H)^T + K R K^T, expanded with C = P H^T and S = H P H^T + R:
     * P - K C^T - C K^T + K S K^T = P - K C^T - (C - K S) K^T.  The same polynomial in K (exact
     * for any gain, so an error in K enters only to second order), in O(NB^2 m) on the upper
     * triangle instead of the products of 18 x 18 matrices.  For a delayed fix the same
     * expression is the covariance of e - K r with C its cross-covariance.  D^T = C^T - S K^T. */
    for (i = 0; i < m; ++i) {
        sr_real *Di = DT + NBP * i;
        for (a = 0; a < NBP; ++a) Di[a] = CT[NBP * i + a];
        for (j = 0; j + 1 < m; j += 2)
            rows_minus2(S[m * j + i], KT + NBP * j, S[m * (j + 1) + i], KT + NBP * (j + 1), Di);
        if (j < m) row_minus(S[m * j + i], KT + NBP * j, Di);
    }
    /* Row a from the group of four columns that holds the diagonal: four columns a statement
     * group, which compilers turn into vector operations (the entries left of the diagonal are
     * computed and then overwritten by the copy of the upper triangle; the padding is zero). */
    for (a = 0; a < NB; ++a) {
        sr_real *row = Pn + NBP * a;
        const int b0 = a - a % 4;
        for (b = 0; b < NB; ++b) row[b] = ekf->P[NB * a + b];   /* whole: the finiteness test reads it */
        for (b = NB; b < NBP; ++b) row[b] = 0;
        for (i = 0; i + 1 < m; i += 2) {   /* two entries of the sample a pass: half the row's loads and stores */
            const sr_real ka = KT[NBP * i + a], da = DT[NBP * i + a], *Ci = CT + NBP * i, *Ki = KT + NBP * i;
            const sr_real kb = KT[NBP * (i + 1) + a], db = DT[NBP * (i + 1) + a], *Cj = Ci + NBP, *Kj = Ki + NBP;
            for (b = b0; b < NBP; b += 4) {
                row[b] -= (ka * Ci[b] + da * Ki[b]) + (kb * Cj[b] + db * Kj[b]);
                row[b + 1] -= (ka * Ci[b + 1] + da * Ki[b + 1]) + (kb * Cj[b + 1] + db * Kj[b + 1]);
                row[b + 2] -= (ka * Ci[b + 2] + da * Ki[b + 2]) + (kb * Cj[b + 2] + db * Kj[b + 2]);
                row[b + 3] -= (ka * Ci[b + 3] + da * Ki[b + 3]) + (kb * Cj[b + 3] + db * Kj[b + 3]);
            }
        }
        for (; i < m; ++i) {
            const sr_real ka = KT[NBP * i + a], da = DT[NBP * i + a], *Ci = CT + NBP * i, *Ki = KT + NBP * i;
            for (b = b0; b < NBP; b += 4) {
                row[b] -= ka * Ci[b] + da * Ki[b];
                row[b + 1] -= ka * Ci[b + 1] + da * Ki[b + 1];
                row[b + 2] -= ka * Ci[b + 2] + da * Ki[b + 2];
                row[b + 3] -= ka * Ci[b + 3] + da * Ki[b + 3];
            }
        }
    }
    /* Only the upper triangle is read from here on (the reset's three entries below the diagonal
     * excepted, mirrored here); the filter's P gets both halves from it in one pass at the end. */
    for (a = 0; a < NB * NBP && recovering; ++a) Pn[a] *= inflate;
    Pn[NBP * 1] = Pn[1];
    Pn[NBP * 2] = Pn[2];
    Pn[NBP * 2 + 1] = Pn[NBP + 2];

    /* Injection, then the reset of the shell's block by Jr(e_xi). */
    /* The state was checked by the call: the retraction without its checks. */
    if (!all_finite(e, NB)) return SR_ERR_NONFINITE;
    sr_internal_retract(ekf->x, e, xn);
    so3_right_jacobian(e + SR_EB_xi_S, Jr);
    for (i = 0; i < 3; ++i)
        for (b = 0; b < NB; ++b)
            T[NB * i + b] = Jr[3 * i] * Pn[NBP * (SR_EB_xi_S) + b] + Jr[3 * i + 1] * Pn[NBP * (SR_EB_xi_S + 1) + b]
                          + Jr[3 * i + 2] * Pn[NBP * (SR_EB_xi_S + 2) + b];
    for (i = 0; i < 3; ++i) {
        for (b = 3; b < NB; ++b) Pn[NBP * (SR_EB_xi_S + i) + b] = T[NB * i + b];
        for (j = i; j < 3; ++j) {
            const sr_real s = T[NB * i] * Jr[3 * j] + T[NB * i + 1] * Jr[3 * j + 1] + T[NB * i + 2] * Jr[3 * j + 2];
            Pn[NBP * i + j] = Pn[NBP * j + i] = s;
        }
    }
    if (!all_finite(Pn, NB * NBP) || !all_finite(xn, SR_NX)) return SR_ERR_NONFINITE;
    memcpy(ekf->x, xn, sizeof xn);
    for (i = 0; i < SR_NBIAS; ++i) ekf->bias[i] += e[SR_EB_b_g + i];
    if (ekf->constrained) carry_null_space(ekf, Jr);
    /* Pn's rows whole (a copy of fixed length, in vectors), then the lower triangle from the upper,
     * two rows of Pn a pass (one entry of each a step: half the overhead of a column at a time). */
    for (a = 0; a < NB; ++a)
        for (b = 0; b < NB; ++b) ekf->P[NB * a + b] = Pn[NBP * a + b];
    for (b = 0; b + 1 < NB; b += 2) {
        const sr_real *u0 = Pn + NBP * b, *u1 = u0 + NBP;
        ekf->P[NB * (b + 1) + b] = u0[b + 1];
        for (a = b + 2; a < NB; ++a) {
            ekf->P[NB * a + b] = u0[a];
            ekf->P[NB * a + b + 1] = u1[a];
        }
    }
    for (; b < NB; ++b)
        for (a = b + 1; a < NB; ++a) ekf->P[NB * a + b] = Pn[NBP * b + a];
    if (recovering)
        ekf->recovered[kind] += 1;
    else
        ekf->accepted[kind] += 1;
    ekf->streak[kind] = 0;
    ekf->nis[kind] = nis;
    if (released >= 0) ekf->delayed[released].marked = 0;

    /* The waiting fixes' cross-covariances move with the error: e <- G (e - K r). */
    for (j = 0; j < SR_EKF_NDELAYED; ++j) {
        sr_real *Cj = ekf->delayed[j].C, t[6];
        const sr_real *Wj = W + MAXM * 2 * j;
        if (!ekf->delayed[j].marked) continue;
        for (a = 0; a < NB; ++a)
            for (b = 0; b < 2; ++b) {
                sr_real s = Cj[2 * a + b];
                for (i = 0; i < m; ++i) s -= KT[NBP * i + a] * Wj[2 * i + b];
                Cj[2 * a + b] = inflate * s;
            }
        for (i = 0; i < SR_EKF_NDELAYED * 4 && recovering; ++i) ekf->delayed[j].Z[i] *= inflate;
        for (i = 0; i < 3; ++i)
            for (b = 0; b < 2; ++b)
                t[2 * i + b] = Jr[3 * i] * Cj[2 * SR_EB_xi_S + b] + Jr[3 * i + 1] * Cj[2 * (SR_EB_xi_S + 1) + b]
                             + Jr[3 * i + 2] * Cj[2 * (SR_EB_xi_S + 2) + b];
        memcpy(Cj + 2 * SR_EB_xi_S, t, sizeof t);
    }
    carry_held(&ekf->held, m, KT, Wa, Jr, inflate);
    return SR_OK;
}

/* The update of sr_ekf.h for an m-entry sample with innovation r, Jacobian H (m x NB) and noise
 * variances Rd. */
static SR_LANES_CLONES int update(sr_ekf *ekf, int kind, int m, const sr_real *r, const sr_real *H,
                  const sr_real *Rd, sr_real gate)
{
    sr_real CT[MAXM * NBP], S[MAXM * MAXM] = {0}, val[MAXM * NB], W[SR_EKF_NDELAYED * MAXM * 2], Wa[MAXM * SR_NV];
    int col[MAXM * NB], nnz[MAXM], a, i, j, k;

    /* H is sparse: an IMU row reads at most 13 of the 18 columns (never q, and one bias block),
     * an encoder or a fix row one or two.  Row by row, its nonzero entries (val, col) are gathered
     * and only they enter C^T = H P (P symmetric: row i of C^T sums rows of P) and S = H C + R. */
    for (i = 0; i < m; ++i) {
        nnz[i] = 0;
        for (k = 0; k < NB; ++k)
            if (H[NB * i + k] != 0) {
                val[NB * i + nnz[i]] = H[NB * i + k];
                col[NB * i + nnz[i]++] = k;
            }
    }
    for (i = 0; i < m; ++i) {
        sr_real *Ci = CT + NBP * i;
        for (a = 0; a < NBP; ++a) Ci[a] = 0;
        for (k = 0; k + 1 < nnz[i]; k += 2)
            rows_plus2(val[NB * i + k], ekf->P + NB * col[NB * i + k], val[NB * i + k + 1],
                       ekf->P + NB * col[NB * i + k + 1], Ci);
        if (k < nnz[i]) row_plus(val[NB * i + k], ekf->P + NB * col[NB * i + k], Ci);
    }
    for (i = 0; i < m; ++i)
        for (j = i; j < m; ++j) {
            sr_real s = i == j ? Rd[i] : 0;
            for (k = 0; k < nnz[i]; ++k) s += val[NB * i + k] * CT[NBP * j + col[NB * i + k]];
            S[m * i + j] = S[m * j + i] = s;
        }
    /* Cov(r, z_j) = H C_j for every waiting fix. */
    for (j = 0; j < SR_EKF_NDELAYED; ++j) {
        const sr_real *Cj = ekf->delayed[j].C;
        if (!ekf->delayed[j].marked) continue;
        for (i = 0; i < m; ++i)
            for (a = 0; a < 2; ++a) {
                sr_real s = 0;
                for (k = 0; k < nnz[i]; ++k) s += val[NB * i + k] * Cj[2 * col[NB * i + k] + a];
                W[MAXM * 2 * j + 2 * i + a] = s;
            }
    }
    held_of_sample(&ekf->held, m, nnz, col, val, Wa);
    return apply(ekf, kind, m, r, CT, S, gate, W, -1, Wa);
}

int sr_ekf_update_imu_axes(sr_ekf *ekf, const sr_model *model, const sr_real y[SR_NIMU], const sr_real u[SR_NU],
                           int body, const sr_real mount[SR_NMOUNT], const sr_real sigma[SR_NIMU], sr_real gate)
{
    sr_real yh[SR_NIMU], H[SR_NIMU * NB], r[SR_NIMU], Rd[SR_NIMU];
    int status = arg_model(model, READS(WHOLE)), i;
    if (status != SR_OK) return status;
    if (!ekf || !y || !mount || !sigma) return SR_ERR_NULL;
    status = sr_check_mount(body, mount);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NIMU; ++i)
        if (!positive(sigma[i])) return SR_ERR_ARG;
    if (!valid_gate(gate)) return SR_ERR_ARG;
    if (!all_finite(y, SR_NIMU) || (u && !all_finite(u, SR_NU))) return SR_ERR_NONFINITE;
    status = check_filter(model, ekf);
    /* The state, biases, mount and u are checked: the Jacobian without its checks. */
    if (status == SR_OK) status = sr_internal_imu_jacobian(model, ekf->x, u, body, mount, ekf->bias, yh, H);
    if (status != SR_OK) return status;
    if (ekf->constrained) constrain_sample(ekf, SR_NIMU, H);
    for (i = 0; i < SR_NIMU; ++i) {
        r[i] = y[i] - yh[i];
        Rd[i] = sigma[i] * sigma[i];
    }
    return update(ekf, SR_EKF_IMU, SR_NIMU, r, H, Rd, gate);
}

/* The held sample's products (sr_ekf.h, "Held disturbance") from the nonzero entries of H and Hn
 * (an IMU row of H reads at most 13 of the 18 columns; Hn's gyroscope rows are zero): r's
 * prediction's share Hn a_hat in pred, Cov(e, r)^T = H P + Hn C^T (CT, rows of NBP, zero padded),
 * B = H C + Hn A, S = H Cov(e, r) + Hn B^T + R on the upper triangle (mirrored), and
 * Cov(r, z_j) = H C_j + Hn Cov(a, z_j) for every waiting fix (W). */
static SR_LANES_CLONES void held_products(const sr_ekf *ekf, const sr_real *H, const sr_real *Hn,
                                          const sr_real *sigma, sr_real *pred, sr_real *CT, sr_real *S,
                                          sr_real *B, sr_real *W)
{
    const sr_ekf_held *h = &ekf->held;
    sr_real val[SR_NIMU * NB], hv[SR_NIMU * SR_NV];
    int col[SR_NIMU * NB], nnz[SR_NIMU], hc[SR_NIMU * SR_NV], nh[SR_NIMU], a, i, j, k;
    for (i = 0; i < SR_NIMU; ++i) {
        nnz[i] = nh[i] = 0;
        for (k = 0; k < NB; ++k)
            if (H[NB * i + k] != 0) {
                val[NB * i + nnz[i]] = H[NB * i + k];
                col[NB * i + nnz[i]++] = k;
            }
        for (k = 0; k < SR_NV; ++k)
            if (Hn[SR_NV * i + k] != 0) {
                hv[SR_NV * i + nh[i]] = Hn[SR_NV * i + k];
                hc[SR_NV * i + nh[i]++] = k;
            }
    }
    for (i = 0; i < SR_NIMU; ++i) {
        sr_real *Ci = CT + NBP * i, *Bi = B + SR_NV * i;
        const sr_real *v = val + NB * i, *w = hv + SR_NV * i;
        const int *c = col + NB * i, *d = hc + SR_NV * i;
        for (a = 0; a < NBP; ++a) Ci[a] = 0;
        for (k = 0; k + 1 < nnz[i]; k += 2) rows_plus2(v[k], ekf->P + NB * c[k], v[k + 1], ekf->P + NB * c[k + 1], Ci);
        if (k < nnz[i]) row_plus(v[k], ekf->P + NB * c[k], Ci);
        {   /* B's row: five sums in registers */
            sr_real b0 = 0, b1 = 0, b2 = 0, b3 = 0, b4 = 0;
            for (k = 0; k < nnz[i]; ++k) {
                const sr_real *Ck = h->cross + SR_NV * c[k];
                b0 += v[k] * Ck[0];
                b1 += v[k] * Ck[1];
                b2 += v[k] * Ck[2];
                b3 += v[k] * Ck[3];
                b4 += v[k] * Ck[4];
            }
            for (k = 0; k < nh[i]; ++k) {
                const sr_real *Ak = h->cov + SR_NV * d[k];
                b0 += w[k] * Ak[0];
                b1 += w[k] * Ak[1];
                b2 += w[k] * Ak[2];
                b3 += w[k] * Ak[3];
                b4 += w[k] * Ak[4];
                pred[i] += w[k] * h->mean[d[k]];
            }
            Bi[0] = b0;
            Bi[1] = b1;
            Bi[2] = b2;
            Bi[3] = b3;
            Bi[4] = b4;
        }
    }
    for (a = 0; a < NB; ++a) {   /* Hn C^T: row a of C in registers, for the rows Hn reads (the accelerometer's) */
        const sr_real *Ca = h->cross + SR_NV * a, c0 = Ca[0], c1 = Ca[1], c2 = Ca[2], c3 = Ca[3], c4 = Ca[4];
        for (i = 0; i < SR_NIMU; ++i) {
            const sr_real *w = Hn + SR_NV * i;
            if (nh[i]) CT[NBP * i + a] += (((w[0] * c0 + w[1] * c1) + w[2] * c2) + w[3] * c3) + w[4] * c4;
        }
    }
    for (i = 0; i < SR_NIMU; ++i)
        for (j = i; j < SR_NIMU; ++j) {
            sr_real s = i == j ? sigma[i] * sigma[i] : 0;
            for (k = 0; k < nnz[i]; ++k) s += val[NB * i + k] * CT[NBP * j + col[NB * i + k]];
            for (k = 0; k < nh[i]; ++k) s += hv[SR_NV * i + k] * B[SR_NV * j + hc[SR_NV * i + k]];
            S[SR_NIMU * i + j] = S[SR_NIMU * j + i] = s;
        }
    for (j = 0; j < SR_EKF_NDELAYED; ++j) {
        const sr_real *Cj = ekf->delayed[j].C, *Aj = h->fix + 2 * SR_NV * j;
        if (!ekf->delayed[j].marked) continue;
        for (i = 0; i < SR_NIMU; ++i)
            for (a = 0; a < 2; ++a) {
                sr_real s = 0;
                for (k = 0; k < nnz[i]; ++k) s += val[NB * i + k] * Cj[2 * col[NB * i + k] + a];
                for (k = 0; k < nh[i]; ++k) s += hv[SR_NV * i + k] * Aj[2 * hc[SR_NV * i + k] + a];
                W[MAXM * 2 * j + 2 * i + a] = s;
            }
    }
}

int sr_ekf_update_imu_held(sr_ekf *ekf, const sr_model *model, const sr_real y[SR_NIMU], const sr_real u[SR_NU],
                           int body, const sr_real mount[SR_NMOUNT], const sr_real sigma[SR_NIMU],
                           const sr_ekf_process *process, sr_real hold, sr_real gate)
{
    sr_real yh[SR_NIMU], H[SR_NIMU * NB], Hn[SR_NIMU * SR_NV], r[SR_NIMU], Minv[SR_NV * SR_NV];
    sr_real CT[SR_NIMU * NBP], S[SR_NIMU * SR_NIMU], L[SR_NIMU * SR_NIMU], B[SR_NIMU * SR_NV];
    sr_real X[SR_NIMU * SR_NV], Sr[SR_NIMU], col[SR_NIMU], W[SR_EKF_NDELAYED * MAXM * 2];
    sr_ekf_held before, *h;
    long applied, recovered;
    sr_real inflate;
    int status = arg_model(model, READS(WHOLE)), a, b, i, j;
    if (status != SR_OK) return status;
    if (!ekf || !y || !mount || !sigma || !process) return SR_ERR_NULL;
    before = ekf->held;
    status = sr_check_mount(body, mount);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NIMU; ++i)
        if (!positive(sigma[i])) return SR_ERR_ARG;
    if (!valid_gate(gate) || !valid_process(process) || arg_dt(hold) != SR_OK) return SR_ERR_ARG;
    if (!all_finite(y, SR_NIMU) || (u && !all_finite(u, SR_NU))) return SR_ERR_NONFINITE;
    status = check_filter(model, ekf);
    /* The state, biases, mount and u are checked: the Jacobian without its checks, with Hn (the
     * reading is linear in nu': the same at any nu') and, when a period starts, M^-1 at x from the
     * same evaluation of the accelerations' Jacobian. */
    if (status == SR_OK)
        status = sr_internal_imu_jacobian_minv(model, ekf->x, u, body, mount, ekf->bias, yh, H, Hn,
                                               ekf->held.pending ? NULL : Minv);
    if (status != SR_OK) return status;
    if (ekf->constrained) constrain_sample(ekf, SR_NIMU, H);

    h = &ekf->held;
    if (!h->pending) {   /* a's prior: mean 0, Q_a = M^-1 D^2 M^-1 / hold, independent of e */
        memset(h, 0, sizeof *h);
        torque_noise_of(Minv, process, 1 / hold, h->cov);
        h->pending = 1;
        h->remaining = hold;
    }
    /* r = y - h - Hn a_hat; Cov(e, r)^T = H P + Hn C^T, B = H C + Hn A, S = H Cov(e, r) + Hn B^T + R,
     * Cov(r, z_j) for the waiting fixes. */
    memcpy(r, yh, sizeof r);
    held_products(ekf, H, Hn, sigma, r, CT, S, B, W);
    for (i = 0; i < SR_NIMU; ++i) r[i] = y[i] - r[i];
    /* S^-1 r and X = S^-1 B for a's own revision after the error's. */
    status = cholesky(SR_NIMU, S, L);
    if (status != SR_OK) {
        *h = before;
        return status;
    }
    memcpy(Sr, r, sizeof Sr);
    solve_both(SR_NIMU, L, Sr);
    for (b = 0; b < SR_NV; ++b) {
        for (i = 0; i < SR_NIMU; ++i) col[i] = B[SR_NV * i + b];
        solve_both(SR_NIMU, L, col);
        for (i = 0; i < SR_NIMU; ++i) X[SR_NV * i + b] = col[i];
    }
    recovered = ekf->recovered[SR_EKF_IMU];
    applied = ekf->accepted[SR_EKF_IMU] + recovered;
    status = apply(ekf, SR_EKF_IMU, SR_NIMU, r, CT, S, gate, W, -1, B);
    if (status != SR_OK || ekf->accepted[SR_EKF_IMU] + ekf->recovered[SR_EKF_IMU] == applied) {
        ekf->held = before;   /* refused (or failed): a as before the sample */
        return status;
    }
    /* apply moved C and scaled A and Cov(a, z_j) by lambda; a's own revision, times lambda. */
    inflate = ekf->recovered[SR_EKF_IMU] > recovered ? ekf->nis[SR_EKF_IMU] / gate : 1;
    for (a = 0; a < SR_NV; ++a) {
        for (i = 0; i < SR_NIMU; ++i) h->mean[a] += B[SR_NV * i + a] * Sr[i];
        for (b = 0; b < SR_NV; ++b) {
            sr_real s = 0;
            for (i = 0; i < SR_NIMU; ++i) s += B[SR_NV * i + a] * X[SR_NV * i + b];
            h->cov[SR_NV * a + b] -= inflate * s;
        }
        for (j = 0; j < SR_EKF_NDELAYED; ++j) {
            if (!ekf->delayed[j].marked) continue;
            for (b = 0; b < 2; ++b) {
                sr_real s = 0;
                for (i = 0; i < SR_NIMU; ++i) s += X[SR_NV * i + a] * W[MAXM * 2 * j + 2 * i + b];
                h->fix[2 * SR_NV * j + 2 * a + b] -= inflate * s;
            }
        }
    }
    return SR_OK;
}

int sr_ekf_update_imu(sr_ekf *ekf, const sr_model *model, const sr_real y[SR_NIMU], const sr_real u[SR_NU],
                      int body, const sr_real mount[SR_NMOUNT], sr_real sigma_gyro, sr_real sigma_accel, sr_real gate)
{
    sr_real sigma[SR_NIMU];
    int i;
    for (i = 0; i < 3; ++i) {
        sigma[SR_IMU_gyro + i] = sigma_gyro;
        sigma[SR_IMU_accel + i] = sigma_accel;
    }
    return sr_ekf_update_imu_axes(ekf, model, y, u, body, mount, sigma, gate);
}

/* The checks of the two-entry samples and the one-angle sample: model, pointers, sigma and gate, data. */
static int check_simple(const sr_ekf *ekf, const sr_model *model, const sr_real *y, int n, sr_real sigma, sr_real gate)
{
    const int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!ekf || !y) return SR_ERR_NULL;
    if (!positive(sigma) || !valid_gate(gate)) return SR_ERR_ARG;
    if (!all_finite(y, n)) return SR_ERR_NONFINITE;
    return check_filter(model, ekf);
}

int sr_ekf_update_encoders(sr_ekf *ekf, const sr_model *model, const sr_real y[2], sr_real sigma, sr_real gate)
{
    sr_real yh[2], H[2 * NB], r[2], Rd[2];
    const int status = check_simple(ekf, model, y, 2, sigma, gate);
    if (status != SR_OK) return status;
    sr_internal_encoders_jacobian(ekf->x, yh, H);
    if (ekf->constrained) constrain_sample(ekf, 2, H);
    r[0] = angle_difference(y[0], yh[0]);
    r[1] = angle_difference(y[1], yh[1]);
    Rd[0] = Rd[1] = sigma * sigma;
    return update(ekf, SR_EKF_ENCODERS, 2, r, H, Rd, gate);
}

int sr_ekf_update_position(sr_ekf *ekf, const sr_model *model, const sr_real y[2], sr_real sigma, sr_real gate)
{
    sr_real yh[2], H[2 * NB], r[2], Rd[2];
    int status = check_simple(ekf, model, y, 2, sigma, gate);
    if (status == SR_OK) status = sr_position_jacobian(model, ekf->x, yh, H);
    if (status != SR_OK) return status;
    r[0] = y[0] - yh[0];
    r[1] = y[1] - yh[1];
    Rd[0] = Rd[1] = sigma * sigma;
    return update(ekf, SR_EKF_POSITION, 2, r, H, Rd, gate);
}

int sr_ekf_update_heading(sr_ekf *ekf, const sr_model *model, sr_real y, int body, const sr_real mount[SR_NMOUNT],
                          sr_real sigma, sr_real gate)
{
    sr_real yh, H[NB], r, Rd;
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!ekf || !mount) return SR_ERR_NULL;
    status = sr_check_mount(body, mount);
    if (status != SR_OK) return status;
    status = check_simple(ekf, model, &y, 1, sigma, gate);
    if (status == SR_OK) status = sr_heading_jacobian(model, ekf->x, body, mount, &yh, H);
    if (status != SR_OK) return status;
    r = angle_difference(y, yh);
    Rd = sigma * sigma;
    return update(ekf, SR_EKF_HEADING, 1, &r, H, &Rd, gate);
}

int sr_ekf_mark_position(sr_ekf *ekf, const sr_model *model, int slot)
{
    sr_real yh[2], H[2 * NB], C[NB * 2], Z[SR_EKF_NDELAYED * 4];
    int status = arg_model(model, READS(WHOLE)), a, i, j, k;
    sr_ekf_delayed *d;
    if (status != SR_OK) return status;
    if (!ekf) return SR_ERR_NULL;
    if (slot < 0 || slot >= SR_EKF_NDELAYED) return SR_ERR_ARG;
    status = check_filter(model, ekf);
    if (status == SR_OK) status = sr_position_jacobian(model, ekf->x, yh, H);
    if (status != SR_OK) return status;
    for (a = 0; a < NB; ++a)
        for (i = 0; i < 2; ++i) {
            sr_real s = 0;
            for (k = 0; k < NB; ++k) s += ekf->P[NB * a + k] * H[NB * i + k];
            C[2 * a + i] = s;
        }
    /* Cov(z, z_j) = H C_j for every other waiting fix, H P H^T for its own. */
    for (j = 0; j < SR_EKF_NDELAYED; ++j) {
        const sr_real *Cj = j == slot ? C : ekf->delayed[j].C;
        if (j != slot && !ekf->delayed[j].marked) continue;
        for (i = 0; i < 2; ++i)
            for (a = 0; a < 2; ++a) {
                sr_real s = 0;
                for (k = 0; k < NB; ++k) s += H[NB * i + k] * Cj[2 * k + a];
                Z[4 * j + 2 * i + a] = s;
            }
    }
    if (!all_finite(C, NB * 2) || !all_finite(Z + 4 * slot, 4)) return SR_ERR_NONFINITE;
    d = &ekf->delayed[slot];
    for (j = 0; j < SR_EKF_NDELAYED; ++j) {
        if (j == slot || !ekf->delayed[j].marked) continue;
        for (i = 0; i < 2; ++i)
            for (a = 0; a < 2; ++a) {
                d->Z[4 * j + 2 * i + a] = Z[4 * j + 2 * i + a];
                ekf->delayed[j].Z[4 * slot + 2 * a + i] = Z[4 * j + 2 * i + a];
            }
    }
    memcpy(d->Z + 4 * slot, Z + 4 * slot, 4 * sizeof(sr_real));
    /* Cov(a, z) = (H C)^T with a held disturbance: a moves the error over the next predict. */
    for (a = 0; a < SR_NV; ++a)
        for (i = 0; i < 2; ++i) {
            sr_real s = 0;
            for (k = 0; k < NB && ekf->held.pending; ++k) s += H[NB * i + k] * ekf->held.cross[SR_NV * k + a];
            ekf->held.fix[2 * SR_NV * slot + 2 * a + i] = s;
        }
    memcpy(d->yh, yh, sizeof yh);
    memcpy(d->C, C, sizeof C);
    d->marked = 1;
    return SR_OK;
}

int sr_ekf_update_position_delayed(sr_ekf *ekf, const sr_model *model, int slot, const sr_real y[2], sr_real sigma,
                                   sr_real gate)
{
    sr_real r[2], CT[2 * NBP] = {0}, S[4], W[SR_EKF_NDELAYED * MAXM * 2], Wa[2 * SR_NV];
    const sr_ekf_delayed *d;
    int status = arg_model(model, READS(WHOLE)), a, j;
    if (status != SR_OK) return status;
    if (!ekf || !y) return SR_ERR_NULL;
    if (slot < 0 || slot >= SR_EKF_NDELAYED || !ekf->delayed[slot].marked) return SR_ERR_ARG;
    status = check_simple(ekf, model, y, 2, sigma, gate);
    if (status != SR_OK) return status;
    d = &ekf->delayed[slot];
    r[0] = y[0] - d->yh[0];
    r[1] = y[1] - d->yh[1];
    for (a = 0; a < NB; ++a) {
        CT[a] = d->C[2 * a];
        CT[NBP + a] = d->C[2 * a + 1];
    }
    memcpy(S, d->Z + 4 * slot, sizeof S);
    S[0] += sigma * sigma;
    S[3] += sigma * sigma;
    /* Cov(r, z_j) = Cov(z, z_j): the fix's noise is independent of the others. */
    for (j = 0; j < SR_EKF_NDELAYED; ++j)
        if (j != slot && ekf->delayed[j].marked) memcpy(W + MAXM * 2 * j, d->Z + 4 * j, 4 * sizeof(sr_real));
    /* Cov(r, a) = Cov(z, a): the fix's noise is independent of the held disturbance. */
    for (j = 0; j < 2; ++j)
        for (a = 0; a < SR_NV; ++a) Wa[SR_NV * j + a] = ekf->held.fix[2 * SR_NV * slot + 2 * a + j];
    return apply(ekf, SR_EKF_POSITION, 2, r, CT, S, gate, W, slot, Wa);
}

int sr_ekf_set_recovery(sr_ekf *ekf, int kind, long n)
{
    if (!ekf) return SR_ERR_NULL;
    if (kind < 0 || kind >= SR_EKF_NKINDS || n < 0) return SR_ERR_ARG;
    ekf->recover_after[kind] = n;
    return SR_OK;
}
