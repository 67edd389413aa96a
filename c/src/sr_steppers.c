/*
 * sr_steppers.c -- every time stepper of the spherical robot, on one vector field: Lie-Euler
 * (the paper's eq. (111), first order), the fourth-order Lie-group integrators RKMK4
 * (Runge-Kutta-Munthe-Kaas) and CF4 (commutator-free, Celledoni-Marthinsen-Owren), the
 * optional projection (SR_PROJECT), the public one-step entry points (sr_step and one per
 * method) and the internal ones of the simulation drivers (sr_drivers.c).
 * Hand-written C99; see spherical_robot.h for the public contract.
 *
 * Every function has its own section when built with -ffunction-sections (c/Makefile and
 * c/CMakeLists.txt do): a firmware that calls only sr_step_lie_euler and links with
 * --gc-sections keeps none of the fourth-order code (docs/embedding.md).
 *
 * The state lives on the product group  G = SO(3) x SO(2)_x x SO(2)_y x R^3 x R^5
 * (R_S, R_Y, R_P, q, nu), and the equations of motion have the form
 *
 *     R_S' = R_S [[w_S]],  R_Y' = R_Y w_Y Sigma_Y,  R_P' = R_P w_P Sigma_P,
 *     q'   = r R_S (w_S x gamma),  nu' = accel(x, u),
 *
 * i.e. x' = x . f(x) with f(x) in the Lie algebra g = so(3) x R x R x R^3 x R^5, acting by
 *
 *     x . exp(theta) = (R_S Exp([[th_S]]), R_Y Exp(th_Y Sigma_Y), R_P Exp(th_P Sigma_P),
 *                       q + th_q, nu + th_nu)                                   (act below).
 *
 * We store an element of g in 13 "tangent" numbers [th_S (3) | th_Y | th_P | th_q (3) | th_nu (5)]
 * (SR_T_S ... SR_NT in sr_action.h).  Lie-Euler is x_new = x . exp(h f(x)).
 * Only the so(3) factor is non-abelian; on every other factor both methods reduce to the
 * classical RK4, with q and nu treated as stage variables like the rotations (so the whole
 * method, q included, is of order 4).  R_Y and R_P are advanced by exact one-axis rotations:
 * their zeros and ones stay exact.  No projection is applied (unless SR_PROJECT asks for
 * it): R_S is multiplied by orthogonal matrices (Rodrigues), so R_S^T R_S - I only
 * accumulates rounding.
 *
 * Right trivialisation.  For R(t) = R0 Exp([[theta(t)]]) to solve R' = R [[w]] we need
 *     theta' = dexp^{-1}_{-theta}(w) = w + 1/2 theta x w + c(|theta|) theta x (theta x w),
 *     c(t) = (1 - (t/2) cot(t/2)) / t^2 = 1/12 + t^2/720 + t^4/30240 + t^6/1209600 + ...
 * (dexpinv_series in sr_so3.h)
 * (the inverse of the right Jacobian of SO(3)).  The left-action formulas of the literature
 * (y' = A(y) y, y1 = exp(...) y0) become ours for Z = R^T; in particular, in a product of
 * exponentials the factor applied first stands next to R0.
 */
#include "sr_checks.h"
#include "sr_kernels.h"
#include "sr_so3.h"
#include "sr_steppers.h"
#include "sr_argcheck.h"

#include <stddef.h>

/* f = the velocity of the state in the Lie algebra: (w_S, w_Y, w_P, q', nu').
 * q' = r R_S (w_S x gamma) with its z component set to 0: gamma . (w_S x gamma) = 0 exactly,
 * so the centre moves in its plane and q_z = r is kept to the last bit. */
void sr_internal_kinematics(const sr_model *model, const sr_real x[SR_NX], sr_real f[SR_NT])
{
    const sr_real *R = x + SR_X_R_S, *w = x + SR_X_w_S, *gam = x + SR_X_R_S + 6;
    const sr_real r = model->p[SR_P_r];
    sr_real v[3];
    int i;
    for (i = 0; i < 3; ++i) f[SR_T_S + i] = w[i];
    f[SR_T_Y] = x[SR_X_w_Y];
    f[SR_T_P] = x[SR_X_w_P];
    v[0] = w[1] * gam[2] - w[2] * gam[1];
    v[1] = w[2] * gam[0] - w[0] * gam[2];
    v[2] = w[0] * gam[1] - w[1] * gam[0];
    f[SR_T_Q + 0] = r * (R[0] * v[0] + R[1] * v[1] + R[2] * v[2]);
    f[SR_T_Q + 1] = r * (R[3] * v[0] + R[4] * v[1] + R[5] * v[2]);
    f[SR_T_Q + 2] = 0;
}

int sr_internal_vector_field(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                             sr_real f[SR_NT], long *evaluations)
{
    int status;
    sr_internal_kinematics(model, x, f);
    if (evaluations) ++*evaluations;
    status = sr_internal_accel(model, x, u, f + SR_T_V);
    /* A stage state that overflowed fails the pivot test (NaN): report what happened. */
    if (status == SR_ERR_SINGULAR && !all_finite(x, SR_NX)) return SR_ERR_NONFINITE;
    return status;
}

/* out = x . exp(th1) . exp(th2), formed as x + increment (th2 may be NULL: one exponential);
 * comp as in act_increment (sr_action.h).  On SO(3): R E1 E2 = R + R (D1 + D2 + D1 D2) with
 * D = E - I; the one-axis rotations and the vector parts add their arguments.  out may alias x. */
static void advance(const sr_real x[SR_NX], const sr_real th1[SR_NT], const sr_real *th2, sr_real *comp,
                    sr_real out[SR_NX])
{
    sr_real D[9], th[SR_NT];
    int i;
    so3_exp_minus_identity(th1 + SR_T_S, D);
    if (th2) {
        sr_real D2[9], D12[9];
        so3_exp_minus_identity(th2 + SR_T_S, D2);
        matmul3(D, D2, D12);
        for (i = 0; i < 9; ++i) D[i] = D[i] + D2[i] + D12[i];
    }
    for (i = SR_T_Y; i < SR_NT; ++i) th[i] = th1[i] + (th2 ? th2[i] : 0);
    act_increment(x, D, th, comp, out);
}

/* out = x . exp(th) (see the top of the file); out may alias x. */
static void act(const sr_real x[SR_NX], const sr_real th[SR_NT], sr_real out[SR_NX])
{
    advance(x, th, NULL, NULL, out);
}

/* k = dexp^{-1}_{-th}(f): the so(3) block gets the closed form above (its series below
 * |th| = 1/4 rad, dexpinv_series of sr_so3.h); the abelian blocks are copied.  k may alias f. */
void sr_internal_dexpinv(const sr_real th[SR_NT], const sr_real f[SR_NT], sr_real k[SR_NT])
{
    const sr_real *t = th + SR_T_S, *w = f + SR_T_S;
    const sr_real t2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
    sr_real c, a[3], b[3];
    int i;
    if (t2 < SR_SERIES_T2) {
        c = dexpinv_series(t2);
    } else {
        const sr_real half = SR_C(0.5) * SR_SQRT(t2);
        c = (1 - half * SR_COS(half) / SR_SIN(half)) / t2;
    }
    /* a = t x w, b = t x a */
    a[0] = t[1] * w[2] - t[2] * w[1];
    a[1] = t[2] * w[0] - t[0] * w[2];
    a[2] = t[0] * w[1] - t[1] * w[0];
    b[0] = t[1] * a[2] - t[2] * a[1];
    b[1] = t[2] * a[0] - t[0] * a[2];
    b[2] = t[0] * a[1] - t[1] * a[0];
    for (i = 0; i < 3; ++i) k[SR_T_S + i] = w[i] + SR_C(0.5) * a[i] + c * b[i];
    for (i = SR_T_Y; i < SR_NT; ++i) k[i] = f[i];
}

/* th = sum_j coef[j] * K[j] (n terms). */
static void combine(int n, const sr_real *coef, const sr_real (*K)[SR_NT], sr_real th[SR_NT])
{
    int i, j;
    for (i = 0; i < SR_NT; ++i) {
        sr_real s = 0;
        for (j = 0; j < n; ++j) s += coef[j] * K[j][i];
        th[i] = s;
    }
}

/* RKMK4: the classical RK4 tableau (c = 0, 1/2, 1/2, 1; b = 1/6, 1/3, 1/3, 1/6) on theta:
 *     K1 = f(x),                       Theta_2 = h/2 K1,   K2 = dexpinv(Theta_2, f(x . exp Theta_2)),
 *     Theta_3 = h/2 K2,                K3 = dexpinv(Theta_3, f(x . exp Theta_3)),
 *     Theta_4 = h K3,                  K4 = dexpinv(Theta_4, f(x . exp Theta_4)),
 *     Theta = h (K1 + 2 K2 + 2 K3 + K4)/6,   x_new = x . exp(Theta).
 * K[0] = f(x) must be filled by the caller (the adaptive driver reuses it); K[1..3] and theta
 * (the final Theta) are outputs.  out and comp are written last, only on success; out may alias x. */
int sr_internal_rkmk4_core(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                           sr_real K[4][SR_NT], sr_real theta[SR_NT], sr_real *comp, sr_real out[SR_NX],
                           long *evaluations)
{
    static const sr_real a_diag[3] = {SR_C(0.5), SR_C(0.5), SR_C(1.0)}; /* a_{i+1,i} */
    const sr_real b[4] = {h / 6, h / 3, h / 3, h / 6};
    sr_real th[SR_NT], y[SR_NX];
    int i, s, status;
    for (s = 1; s < 4; ++s) {
        for (i = 0; i < SR_NT; ++i) th[i] = a_diag[s - 1] * h * K[s - 1][i];
        act(x, th, y);
        status = sr_internal_vector_field(model, y, u, K[s], evaluations);
        if (status != SR_OK) return status;
        sr_internal_dexpinv(th, K[s], K[s]);
    }
    combine(4, b, (const sr_real(*)[SR_NT])K, theta);
    advance(x, theta, NULL, comp, out);
    return SR_OK;
}

/* CF4 of Celledoni, Marthinsen & Owren (FGCS 19, 2003), written for x' = x . f(x):
 *     F1 = f(x),  Y2 = x . exp(h/2 F1),  F2 = f(Y2),  Y3 = x . exp(h/2 F2),  F3 = f(Y3),
 *     Y4 = Y2 . exp(h (F3 - F1/2)),  F4 = f(Y4),
 *     x_new = x . exp(h/12 (3F1 + 2F2 + 2F3 - F4)) . exp(h/12 (-F1 + 2F2 + 2F3 + 3F4)).
 * No dexp^-1; on the abelian factors this is the classical RK4.  out and comp are written last,
 * only on success; out may alias x. */
static int cf4_core(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                    sr_real *comp, sr_real out[SR_NX], long *evaluations)
{
    const sr_real beta1[4] = {h / 4, h / 6, h / 6, -h / 12};
    const sr_real beta2[4] = {-h / 12, h / 6, h / 6, h / 4};
    sr_real F[4][SR_NT], th[SR_NT], th2[SR_NT], Y2[SR_NX], Y[SR_NX];
    int i, status;
    status = sr_internal_vector_field(model, x, u, F[0], evaluations);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NT; ++i) th[i] = SR_C(0.5) * h * F[0][i];
    act(x, th, Y2);
    status = sr_internal_vector_field(model, Y2, u, F[1], evaluations);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NT; ++i) th[i] = SR_C(0.5) * h * F[1][i];
    act(x, th, Y);
    status = sr_internal_vector_field(model, Y, u, F[2], evaluations);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NT; ++i) th[i] = h * (F[2][i] - SR_C(0.5) * F[0][i]);
    act(Y2, th, Y);
    status = sr_internal_vector_field(model, Y, u, F[3], evaluations);
    if (status != SR_OK) return status;
    combine(4, beta1, (const sr_real(*)[SR_NT])F, th);
    combine(4, beta2, (const sr_real(*)[SR_NT])F, th2);
    advance(x, th, th2, comp, out);  /* both exponentials as one increment of x */
    return SR_OK;
}

/* The cores write out and comp only at their end, once every stage has succeeded, and their
 * final update may alias x: no copies here. */
static int rkmk4_step(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                      sr_real *comp, sr_real out[SR_NX])
{
    sr_real K[4][SR_NT], theta[SR_NT];
    const int status = sr_internal_vector_field(model, x, u, K[0], NULL);
    if (status != SR_OK) return status;
    return sr_internal_rkmk4_core(model, x, u, dt, K, theta, comp, out, NULL);
}

static int cf4_step(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                    sr_real *comp, sr_real out[SR_NX])
{
    return cf4_core(model, x, u, dt, comp, out, NULL);
}

void sr_internal_project(sr_real x[SR_NX])
{
    sr_real *R = x + SR_X_R_S, S[9], P[9];
    int i, j, k;
    /* S = (3I - R^T R)/2, then R <- R S: exact on SO(3), and it squares the defect. */
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            sr_real dot = 0;
            for (k = 0; k < 3; ++k) dot += R[3 * k + i] * R[3 * k + j];
            S[3 * i + j] = SR_C(0.5) * ((i == j ? 3 : 0) - dot);
        }
    matmul3(R, S, P);
    for (i = 0; i < 9; ++i) R[i] = P[i];
    /* One-axis rotations: (c, s) <- (c, s) (3 - c^2 - s^2)/2, the zeros and ones untouched. */
    {
        sr_real *c = x + SR_X_R_Y + 4, *sn = x + SR_X_R_Y + 7, *ms = x + SR_X_R_Y + 5; /* R_Y = [1 0 0; 0 c -s; 0 s c] */
        const sr_real f = SR_C(0.5) * (3 - (*c * *c + *sn * *sn));
        *c *= f;
        *sn *= f;
        *ms = -*sn;
        x[SR_X_R_Y + 8] = *c;
    }
    {
        sr_real *c = x + SR_X_R_P + 0, *sn = x + SR_X_R_P + 2; /* R_P = [c 0 s; 0 1 0; -s 0 c] */
        const sr_real f = SR_C(0.5) * (3 - (*c * *c + *sn * *sn));
        *c *= f;
        *sn *= f;
        x[SR_X_R_P + 6] = -*sn;
        x[SR_X_R_P + 8] = *c;
    }
}

/* ---- one step of each method ------------------------------------------------------------- */

/* Lie-Euler, the paper's eq. (111): x_new = x . exp(h f(x)), first order, on the same vector
 * field and group action as the fourth-order methods (so q_z = r is kept exactly here too).
 * Never compensated: the plain eq. (111) in sr_step and sr_simulate alike.  out may alias x. */
static int lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                     sr_real dt, sr_real out[SR_NX])
{
    sr_real f[SR_NT], th[SR_NT];
    int i, status = sr_internal_vector_field(model, x, u, f, NULL);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NT; ++i) th[i] = dt * f[i];
    act(x, th, out);
    return SR_OK;
}

int sr_internal_valid_method(int method)
{
    return arg_method(method) == SR_OK;
}

int sr_internal_advance(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                        sr_real dt, sr_real *comp, sr_real out[SR_NX])
{
    int i, status;
    switch (method & ~SR_PROJECT) {
    case SR_LIE_EULER: status = lie_euler(model, x, u, dt, out); break;
    case SR_RKMK4: status = rkmk4_step(model, x, u, dt, comp, out); break;
    case SR_CF4: status = cf4_step(model, x, u, dt, comp, out); break;
    default: return SR_ERR_ARG;
    }
    if (status == SR_OK && (method & SR_PROJECT)) {
        sr_internal_project(out);
        if (comp) for (i = 0; i < SR_X_q; ++i) comp[i] = 0; /* the projection moved the rotations */
    }
    return status;
}

/* ---- the public one-step entry points ---------------------------------------------------- */

/* The argument checks of every one-step entry point, in the order of sr_argcheck.h: the model,
 * the pointers, the method and dt, then the state and the torques. */
static int step_arguments(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                          sr_real dt, const sr_real *x_next)
{
    int status = arg_model(model, READS(ACCEL) | READS(STATE));
    if (status != SR_OK) return status;
    if (!x || !x_next) return SR_ERR_NULL;
    if (arg_method(method) != SR_OK || arg_dt(dt) != SR_OK) return SR_ERR_ARG;
    /* The full state check, not only the kernels' cheap one: a firmware loop of single steps
     * would otherwise carry a corrupt attitude (a row of R_S of length 2) on silently.  It costs
     * about a fifth of a Lie-Euler step, a twentieth of an RKMK4 one (measured, docs/robustness.md). */
    status = sr_internal_check_state(model, x);
    if (status == SR_OK && u && !all_finite(u, SR_NU)) status = SR_ERR_NONFINITE;
    return status;
}

/* Each method's entry point calls its own stepper only, so that a program calling one of them
 * links none of the others' code (with --gc-sections). */
int sr_step_lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                      sr_real x_next[SR_NX])
{
    sr_real tmp[SR_NX];
    const int status = step_arguments(model, SR_LIE_EULER, x, u, dt, x_next);
    if (status != SR_OK) return status;
    return deliver(lie_euler(model, x, u ? u : sr_zero_u, dt, tmp), tmp, SR_NX, x_next);
}

int sr_step_rkmk4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                  sr_real x_next[SR_NX])
{
    sr_real tmp[SR_NX];
    const int status = step_arguments(model, SR_RKMK4, x, u, dt, x_next);
    if (status != SR_OK) return status;
    return deliver(rkmk4_step(model, x, u ? u : sr_zero_u, dt, NULL, tmp), tmp, SR_NX, x_next);
}

int sr_step_cf4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                sr_real x_next[SR_NX])
{
    sr_real tmp[SR_NX];
    const int status = step_arguments(model, SR_CF4, x, u, dt, x_next);
    if (status != SR_OK) return status;
    return deliver(cf4_step(model, x, u ? u : sr_zero_u, dt, NULL, tmp), tmp, SR_NX, x_next);
}

int sr_step(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
            sr_real dt, sr_real x_next[SR_NX])
{
    sr_real tmp[SR_NX];
    int status;
    switch (method) {
    case SR_LIE_EULER: return sr_step_lie_euler(model, x, u, dt, x_next);
    case SR_RKMK4: return sr_step_rkmk4(model, x, u, dt, x_next);
    case SR_CF4: return sr_step_cf4(model, x, u, dt, x_next);
    default: /* a projected method, or an unknown one */
        status = step_arguments(model, method, x, u, dt, x_next);
        if (status != SR_OK) return status;
        return deliver(sr_internal_advance(model, method, x, u ? u : sr_zero_u, dt, NULL, tmp), tmp,
                       SR_NX, x_next);
    }
}
