/*
 * sr_lie_integrators.c -- fourth-order Lie-group integrators for the spherical robot:
 * RKMK4 (Runge-Kutta-Munthe-Kaas) and CF4 (commutator-free, Celledoni-Marthinsen-Owren),
 * plus adaptive stepping with fixed-grid output (sr_simulate_adaptive).
 * Hand-written C99; see spherical_robot.h for the public contract.
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
 * We store an element of g in 13 "tangent" numbers [th_S (3) | th_Y | th_P | th_q (3) | th_nu (5)].
 * Only the so(3) factor is non-abelian; on every other factor both methods reduce to the
 * classical RK4, with q and nu treated as stage variables like the rotations (so the whole
 * method, q included, is of order 4).  R_Y and R_P are advanced by exact one-axis rotations:
 * their zeros and ones stay exact.  No projection is ever applied: R_S is multiplied by
 * orthogonal matrices (Rodrigues), so R_S^T R_S - I only accumulates rounding.
 *
 * Right trivialisation.  For R(t) = R0 Exp([[theta(t)]]) to solve R' = R [[w]] we need
 *     theta' = dexp^{-1}_{-theta}(w) = w + 1/2 theta x w + c(|theta|) theta x (theta x w),
 *     c(t) = (1 - (t/2) cot(t/2)) / t^2 = 1/12 + t^2/720 + t^4/30240 + t^6/1209600 + ...
 * (the inverse of the right Jacobian of SO(3)).  The left-action formulas of the literature
 * (y' = A(y) y, y1 = exp(...) y0) become ours for Z = R^T; in particular, in a product of
 * exponentials the factor applied first stands next to R0.
 */
#include "sr_internal.h"

#include <stddef.h>

/* Layout of a Lie-algebra element ("tangent coordinates"). */
enum { T_S = 0, T_Y = 3, T_P = 4, T_Q = 5, T_V = 8, NT = 13 };

static const sr_real zero_u[SR_NU] = {0, 0};

/* f = the velocity of the state in the Lie algebra: (w_S, w_Y, w_P, q', nu').
 * q' = r R_S (w_S x gamma) with its z component set to 0: gamma . (w_S x gamma) = 0 exactly,
 * so the centre moves in its plane and q_z = r is kept to the last bit. */
static int vector_field(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                        sr_real f[NT], long *evaluations)
{
    const sr_real *R = x + RS, *w = x + W, *gam = x + RS + 6;
    const sr_real r = model->c[0];
    sr_real v[3];
    int i;
    for (i = 0; i < 3; ++i) f[T_S + i] = w[i];
    f[T_Y] = w[3];
    f[T_P] = w[4];
    v[0] = w[1] * gam[2] - w[2] * gam[1];
    v[1] = w[2] * gam[0] - w[0] * gam[2];
    v[2] = w[0] * gam[1] - w[1] * gam[0];
    f[T_Q + 0] = r * (R[0] * v[0] + R[1] * v[1] + R[2] * v[2]);
    f[T_Q + 1] = r * (R[3] * v[0] + R[4] * v[1] + R[5] * v[2]);
    f[T_Q + 2] = 0;
    if (evaluations) ++*evaluations;
    i = sr_gen_accel(model->c, x, u, f + T_V);
    /* A stage state that overflowed fails the pivot test (NaN): report what happened. */
    if (i == SR_ERR_SINGULAR && !all_finite(x, SR_NX)) return SR_ERR_NONFINITE;
    return i;
}

/* Rounding and orthogonality.  Forming E = Exp(...) and then R E rounds the diagonal of E to
 * the grid of numbers near 1 (spacing 1.1e-16 or 2.2e-16); when the angular velocity changes
 * slowly, that rounding error is nearly the same at every step and |R^T R - I| grows
 * linearly (about 1e-11 after 10^6 steps).  We therefore form the increment D = E - I
 * directly (its entries are small and carry full relative precision) and update
 * R <- R + R D: the remaining rounding is that of one addition per entry, which does not
 * repeat from step to step. */

/* delta = R Exp(angle [[e_k]]) - R for R a rotation about axis k (0 = x, 1 = y): only the
 * (i, j) plane changes, by R (Exp - I) with cos(angle) - 1 = -2 sin^2(angle/2); the other
 * entries (exact zeros and ones) get a zero increment. */
static void axis_increment(const sr_real R[9], int k, sr_real angle, sr_real delta[9])
{
    const sr_real sh = SR_SIN(SR_C(0.5) * angle);
    const sr_real cm1 = SR_C(-2.0) * sh * sh, s = SR_SIN(angle);
    const int i = (k + 1) % 3, j = (k + 2) % 3; /* Exp(t[[e_k]]) rotates the (i, j) plane */
    int m;
    for (m = 0; m < 9; ++m) delta[m] = 0;
    for (m = 0; m < 3; ++m) { /* row m: (R_mi, R_mj) <- (R_mi, R_mj) [[c, -s], [s, c]] */
        const sr_real a = R[3 * m + i], b = R[3 * m + j];
        delta[3 * m + i] = a * cm1 + b * s;
        delta[3 * m + j] = b * cm1 - a * s;
    }
}

/* delta = x . exp(th1) . exp(th2) - x, written as increments (th2 may be NULL: one exponential).
 * On SO(3): R (E1 E2 - I) = R (D1 + D2 + D1 D2) with D = E - I; the one-axis rotations and the
 * vector parts add their arguments. */
static void increment(const sr_real x[SR_NX], const sr_real th1[NT], const sr_real *th2, sr_real delta[SR_NX])
{
    sr_real D[9];
    int i;
    so3_exp_minus_identity(th1 + T_S, D);
    if (th2) {
        sr_real D2[9], D12[9];
        so3_exp_minus_identity(th2 + T_S, D2);
        matmul3(D, D2, D12);
        for (i = 0; i < 9; ++i) D[i] = D[i] + D2[i] + D12[i];
    }
    matmul3(x + RS, D, delta + RS);
    axis_increment(x + RY, 0, th1[T_Y] + (th2 ? th2[T_Y] : 0), delta + RY);
    axis_increment(x + RP, 1, th1[T_P] + (th2 ? th2[T_P] : 0), delta + RP);
    for (i = 0; i < 3; ++i) delta[Q + i] = th1[T_Q + i] + (th2 ? th2[T_Q + i] : 0);
    for (i = 0; i < SR_NV; ++i) delta[W + i] = th1[T_V + i] + (th2 ? th2[T_V + i] : 0);
}

/* out = x + delta.  With comp (a running compensation, zero at the start of a simulation)
 * the sum is Kahan-compensated: the low-order bits that one addition loses are carried to
 * the next step instead of being rounded the same way at every step, which keeps |R^T R - I|
 * at the rounding level even when a resting robot's increments stay constant and below one
 * ulp of the entries near 1 (the stagnation that otherwise grows |R^T R - I| linearly). */
static void apply(const sr_real x[SR_NX], const sr_real delta[SR_NX], sr_real *comp, sr_real out[SR_NX])
{
    int i;
    if (!comp) {
        for (i = 0; i < SR_NX; ++i) out[i] = x[i] + delta[i];
        return;
    }
    for (i = 0; i < SR_NX; ++i) {
        const sr_real y = delta[i] - comp[i];
        const sr_real t = x[i] + y;
        comp[i] = (t - x[i]) - y;
        out[i] = t;
    }
}

/* out = x . exp(th) (see the top of the file); out must not alias x. */
static void act(const sr_real x[SR_NX], const sr_real th[NT], sr_real out[SR_NX])
{
    sr_real delta[SR_NX];
    increment(x, th, NULL, delta);
    apply(x, delta, NULL, out);
}

/* k = dexp^{-1}_{-th}(f): the so(3) block gets the closed form above (series below
 * |th| = 0.1 rad, where the omitted t^8/47900160 term is below 1e-16 relative); the abelian
 * blocks are copied.  k may alias f. */
static void dexpinv(const sr_real th[NT], const sr_real f[NT], sr_real k[NT])
{
    const sr_real *t = th + T_S, *w = f + T_S;
    const sr_real t2 = t[0] * t[0] + t[1] * t[1] + t[2] * t[2];
    sr_real c, a[3], b[3];
    int i;
    if (t2 < SR_C(1e-2)) {
        c = SR_C(1.0) / 12 + t2 * (SR_C(1.0) / 720 + t2 * (SR_C(1.0) / 30240 + t2 * (SR_C(1.0) / 1209600)));
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
    for (i = 0; i < 3; ++i) k[T_S + i] = w[i] + SR_C(0.5) * a[i] + c * b[i];
    for (i = T_Y; i < NT; ++i) k[i] = f[i];
}

/* th = sum_j coef[j] * K[j] (n terms). */
static void combine(int n, const sr_real *coef, const sr_real (*K)[NT], sr_real th[NT])
{
    int i, j;
    for (i = 0; i < NT; ++i) {
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
 * (the final Theta) are outputs.  out must not alias x. */
static int rkmk4_core(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                      sr_real K[4][NT], sr_real theta[NT], sr_real *comp, sr_real out[SR_NX], long *evaluations)
{
    static const sr_real a_diag[3] = {SR_C(0.5), SR_C(0.5), SR_C(1.0)}; /* a_{i+1,i} */
    const sr_real b[4] = {h / 6, h / 3, h / 3, h / 6};
    sr_real th[NT], y[SR_NX];
    int i, s, status;
    for (s = 1; s < 4; ++s) {
        for (i = 0; i < NT; ++i) th[i] = a_diag[s - 1] * h * K[s - 1][i];
        act(x, th, y);
        status = vector_field(model, y, u, K[s], evaluations);
        if (status != SR_OK) return status;
        dexpinv(th, K[s], K[s]);
    }
    combine(4, b, (const sr_real(*)[NT])K, theta);
    increment(x, theta, NULL, y);
    apply(x, y, comp, out);
    return SR_OK;
}

/* CF4 of Celledoni, Marthinsen & Owren (FGCS 19, 2003), written for x' = x . f(x):
 *     F1 = f(x),  Y2 = x . exp(h/2 F1),  F2 = f(Y2),  Y3 = x . exp(h/2 F2),  F3 = f(Y3),
 *     Y4 = Y2 . exp(h (F3 - F1/2)),  F4 = f(Y4),
 *     x_new = x . exp(h/12 (3F1 + 2F2 + 2F3 - F4)) . exp(h/12 (-F1 + 2F2 + 2F3 + 3F4)).
 * No dexp^-1; on the abelian factors this is the classical RK4.  out must not alias x. */
static int cf4_core(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                    sr_real *comp, sr_real out[SR_NX], long *evaluations)
{
    const sr_real beta1[4] = {h / 4, h / 6, h / 6, -h / 12};
    const sr_real beta2[4] = {-h / 12, h / 6, h / 6, h / 4};
    sr_real F[4][NT], th[NT], th2[NT], Y2[SR_NX], Y[SR_NX];
    int i, status;
    status = vector_field(model, x, u, F[0], evaluations);
    if (status != SR_OK) return status;
    for (i = 0; i < NT; ++i) th[i] = SR_C(0.5) * h * F[0][i];
    act(x, th, Y2);
    status = vector_field(model, Y2, u, F[1], evaluations);
    if (status != SR_OK) return status;
    for (i = 0; i < NT; ++i) th[i] = SR_C(0.5) * h * F[1][i];
    act(x, th, Y);
    status = vector_field(model, Y, u, F[2], evaluations);
    if (status != SR_OK) return status;
    for (i = 0; i < NT; ++i) th[i] = h * (F[2][i] - SR_C(0.5) * F[0][i]);
    act(Y2, th, Y);
    status = vector_field(model, Y, u, F[3], evaluations);
    if (status != SR_OK) return status;
    combine(4, beta1, (const sr_real(*)[NT])F, th);
    combine(4, beta2, (const sr_real(*)[NT])F, th2);
    increment(x, th, th2, Y);  /* both exponentials as one increment of x */
    apply(x, Y, comp, out);
    return SR_OK;
}

int sr_internal_rkmk4_step(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                           sr_real dt, sr_real *comp, sr_real out[SR_NX])
{
    sr_real K[4][NT], theta[NT], y[SR_NX], c[SR_NX];
    int i, status = vector_field(model, x, u, K[0], NULL);
    if (status != SR_OK) return status;
    if (comp) for (i = 0; i < SR_NX; ++i) c[i] = comp[i];
    status = rkmk4_core(model, x, u, dt, K, theta, comp ? c : NULL, y, NULL);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NX; ++i) out[i] = y[i];
    if (comp) for (i = 0; i < SR_NX; ++i) comp[i] = c[i];
    return SR_OK;
}

int sr_internal_cf4_step(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                         sr_real dt, sr_real *comp, sr_real out[SR_NX])
{
    sr_real y[SR_NX], c[SR_NX];
    int i, status;
    if (comp) for (i = 0; i < SR_NX; ++i) c[i] = comp[i];
    status = cf4_core(model, x, u, dt, comp ? c : NULL, y, NULL);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NX; ++i) out[i] = y[i];
    if (comp) for (i = 0; i < SR_NX; ++i) comp[i] = c[i];
    return SR_OK;
}

void sr_internal_project(sr_real x[SR_NX])
{
    sr_real *R = x + RS, S[9], P[9];
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
        sr_real *c = x + RY + 4, *sn = x + RY + 7, *ms = x + RY + 5; /* R_Y = [1 0 0; 0 c -s; 0 s c] */
        const sr_real f = SR_C(0.5) * (3 - (*c * *c + *sn * *sn));
        *c *= f;
        *sn *= f;
        *ms = -*sn;
        x[RY + 8] = *c;
    }
    {
        sr_real *c = x + RP + 0, *sn = x + RP + 2; /* R_P = [c 0 s; 0 1 0; -s 0 c] */
        const sr_real f = SR_C(0.5) * (3 - (*c * *c + *sn * *sn));
        *c *= f;
        *sn *= f;
        x[RP + 6] = -*sn;
        x[RP + 8] = *c;
    }
}

/* ---- adaptive stepping ------------------------------------------------------------------ */

static sr_real max_r(sr_real a, sr_real b) { return a > b ? a : b; }
static sr_real min_r(sr_real a, sr_real b) { return a < b ? a : b; }

/* Weighted max norm of the RKMK4(3) error estimate e = h/6 (K4 - K5) (tangent coordinates). */
static sr_real rkmk4_error(const sr_real K4[NT], const sr_real K5[NT], sr_real h, const sr_real x[SR_NX],
                           const sr_real y[SR_NX], sr_real rtol, sr_real atol)
{
    sr_real err = 0;
    int i;
    for (i = 0; i < NT; ++i) {
        const sr_real e = SR_FABS(h / 6 * (K4[i] - K5[i]));
        sr_real scale = 1; /* rotation angles: the entries of a rotation are of size 1 */
        if (i >= T_Q) {
            const int j = i < T_V ? Q + (i - T_Q) : W + (i - T_V);
            scale = max_r(SR_FABS(x[j]), SR_FABS(y[j]));
        }
        err = max_r(err, e / (atol + rtol * scale));
        if (e != e) return e; /* NaN: reject */
    }
    return err;
}

/* Driver state of one adaptive run (lives on the caller's stack). */
typedef struct adaptive_ctx {
    const sr_model *model;
    sr_real rtol, atol;
    int have_f;          /* f_cur holds f(x) under the current torque (RKMK4: FSAL) */
    sr_real f_cur[NT];
    sr_adaptive_stats *st;
} adaptive_ctx;

/* One trial step of RKMK4 with its embedded estimate, size h from x: y = the propagated
 * (4th-order) state, *err = the weighted norm of the estimate (<= 1: accept), f_next = f(y). */
static int trial_step(adaptive_ctx *cx, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                      sr_real y[SR_NX], sr_real f_next[NT], sr_real *err)
{
    sr_real K[4][NT], theta[NT], K5[NT];
    int i, status;
    if (!cx->have_f) {
        status = vector_field(cx->model, x, u, cx->f_cur, &cx->st->evaluations);
        if (status != SR_OK) return status;
        cx->have_f = 1;
    }
    for (i = 0; i < NT; ++i) K[0][i] = cx->f_cur[i];
    status = rkmk4_core(cx->model, x, u, h, K, theta, NULL, y, &cx->st->evaluations);
    if (status != SR_OK) return status;
    /* Fifth stage at the new point ("first same as last"): K5 = dexpinv(Theta, f(y)). */
    status = vector_field(cx->model, y, u, f_next, &cx->st->evaluations);
    if (status != SR_OK) return status;
    dexpinv(theta, f_next, K5);
    *err = rkmk4_error(K[3], K5, h, x, y, cx->rtol, cx->atol);
    return SR_OK;
}

int sr_simulate_adaptive(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt_out,
                         long n_out, const sr_real *u, sr_real rtol, sr_real atol, sr_real h_init,
                         long max_steps, sr_real *traj, sr_adaptive_stats *stats)
{
    sr_adaptive_stats local = {0, 0, 0, 0, 0};
    adaptive_ctx cx;
    sr_real x[SR_NX], y[SR_NX], f_next[NT], h, tol, expo;
    long k;
    int i, base, status;
    if (!stats) stats = &local;
    *stats = local;
    status = sr_check_state(model, x0); /* in full, like sr_simulate */
    if (status != SR_OK) return status;
    if (!traj) return SR_ERR_NULL;
    base = method & ~SR_PROJECT;
    if (base != SR_RKMK4 || !(dt_out > 0) || !isfinite(dt_out) || n_out < 0
        || !(rtol >= 0) || !(atol >= 0) || !(rtol + atol > 0) || !isfinite(rtol) || !isfinite(atol)
        || !(max_steps > 0) || h_init != h_init || !isfinite(h_init))
        return SR_ERR_ARG;

    cx.model = model;
    cx.rtol = rtol;
    cx.atol = atol;
    cx.have_f = 0;
    cx.st = stats;
    /* Controller exponent -1/(p+1), p = 3: the order of the embedded solution. */
    expo = SR_C(-0.25);
    tol = max_r(rtol, atol);
    h = h_init > 0 ? h_init : min_r(dt_out, SR_C(0.1) * SR_POW(tol, SR_C(0.25)));

    for (i = 0; i < SR_NX; ++i) traj[i] = x[i] = x0[i];
    stats->rows_done = 1;
    stats->h_next = h;
    for (k = 0; k < n_out; ++k) {
        const sr_real *uk = u ? u + k * SR_NU : zero_u;
        const sr_real t_end = (sr_real)(k + 1) * dt_out;
        /* Below this the step no longer changes t in floating point (in any useful way). */
        const sr_real h_min = 64 * SR_EPSILON * t_end;
        sr_real s = 0; /* time elapsed in [t_k, t_k+1) */
        int rejected = 0, done = 0;
        if (!all_finite(uk, SR_NU)) return SR_ERR_NONFINITE;
        if (k > 0 && u && (uk[0] != uk[-SR_NU] || uk[1] != uk[1 - SR_NU])) cx.have_f = 0;
        while (!done) {
            const sr_real remaining = dt_out - s;
            sr_real hs = h, err, fac;
            int last = 0;
            /* Land exactly on the grid point; stretch by up to 10% rather than leave a sliver. */
            if (SR_C(1.1) * hs >= remaining) {
                hs = remaining;
                last = 1;
            } else if (hs < h_min) {
                stats->h_next = h;
                return SR_ERR_STEP_SIZE;
            }
            if (stats->accepted + stats->rejected >= max_steps) {
                stats->h_next = h;
                return SR_ERR_MAX_STEPS;
            }
            status = trial_step(&cx, x, uk, hs, y, f_next, &err);
            if (status != SR_OK) {
                stats->h_next = h;
                return status;
            }
            if (!(err <= 1)) { /* reject (NaN included) and retry with a smaller step */
                ++stats->rejected;
                fac = err == err ? max_r(SR_C(0.2), SR_C(0.9) * SR_POW(err, expo)) : SR_C(0.2);
                h = hs * min_r(fac, SR_C(0.9));
                rejected = 1;
                continue;
            }
            if (method & SR_PROJECT) {
                sr_internal_project(y); /* f(x) of the unprojected point differs by rounding only */
            }
            if (!all_finite(y, SR_NX)) {
                stats->h_next = h;
                return SR_ERR_NONFINITE;
            }
            ++stats->accepted;
            for (i = 0; i < SR_NX; ++i) x[i] = y[i];
            for (i = 0; i < NT; ++i) cx.f_cur[i] = f_next[i]; /* first same as last */
            cx.have_f = 1;
            fac = err > 0 ? SR_C(0.9) * SR_POW(err, expo) : SR_C(5.0);
            fac = max_r(SR_C(0.2), min_r(fac, rejected ? SR_C(1.0) : SR_C(5.0)));
            /* A step shortened to hit the grid says little about the step the solution allows. */
            h = last ? max_r(h, hs * fac) : hs * fac;
            rejected = 0;
            if (last) done = 1;
            else s += hs;
        }
        for (i = 0; i < SR_NX; ++i) traj[(k + 1) * SR_NX + i] = x[i];
        stats->rows_done = k + 2;
        stats->h_next = h;
    }
    return SR_OK;
}
