/* sr_runtime.c -- checks, SO(3) exponential and time steppers around the generated kernels.
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_internal.h" /* spherical_robot.h, math macros, shared helpers */

#include <stddef.h>

const char *sr_status_string(int status)
{
    switch (status) {
    case SR_OK: return "ok";
    case SR_ERR_NULL: return "null pointer";
    case SR_ERR_NONFINITE: return "non-finite value";
    case SR_ERR_NOT_ROTATION: return "not a rotation matrix of the required kind";
    case SR_ERR_SINGULAR: return "singular generalized inertia";
    case SR_ERR_PARAM: return "parameter out of range";
    case SR_ERR_ARG: return "invalid argument";
    case SR_ERR_CONSTRAINT: return "constraint violated (q_z != r)";
    case SR_ERR_STEP_SIZE: return "adaptive step size below the rounding level of t";
    case SR_ERR_MAX_STEPS: return "adaptive stepping exceeded max_steps";
    case SR_ERR_ENERGY: return "energy rose without input power beyond the guard's tolerance";
    default: return "unknown status";
    }
}

/* The reference state of sr_model_init's checks: R_S = R_Y = R_P = I, q = (0, 0, r), at rest. */
static void reference_state(sr_real r, sr_real x[SR_NX])
{
    int i;
    for (i = 0; i < SR_NX; ++i) x[i] = 0;
    for (i = 0; i < 3; ++i) x[RS + 4 * i] = x[RY + 4 * i] = x[RP + 4 * i] = 1;
    x[Q + 2] = r;
}

static const sr_real zero_u[SR_NU] = {0, 0};

int sr_model_init(sr_model *model, const sr_real params[SR_NPARAM])
{
    enum { r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g };
    static const int positive[] = {r, m_S, b, h, m_b, m_h, l, m_P};
    static const int nonnegative[] = {k_S, k_Y, k_P, g};
    sr_model m;
    sr_real x[SR_NX], M[SR_NV * SR_NV], a[SR_NV], energy;
    size_t i;
    int status;
    if (!model || !params) return SR_ERR_NULL;
    if (!all_finite(params, SR_NPARAM)) return SR_ERR_NONFINITE;
    for (i = 0; i < sizeof positive / sizeof positive[0]; ++i)
        if (!(params[positive[i]] > 0)) return SR_ERR_PARAM;
    for (i = 0; i < sizeof nonnegative / sizeof nonnegative[0]; ++i)
        if (!(params[nonnegative[i]] >= 0)) return SR_ERR_PARAM;
    /* The yoke's corners and the pendulum's tip must fit inside the shell. */
    if (params[b] * params[b] + params[h] * params[h] > SR_C(4.0) * params[r] * params[r]) return SR_ERR_PARAM;
    if (params[l] > params[r]) return SR_ERR_PARAM;
    for (i = 0; i < SR_NPARAM; ++i) m.p[i] = params[i];
    status = sr_gen_constants(m.p, m.c);
    if (status != SR_OK) return status;
    /* Values in range one by one can still overflow or underflow together (r = 1e200, or every
     * length 1e-200): evaluate the model once at the reference state.  M is positive definite
     * for any positive masses and lengths in exact arithmetic, so a failing pivot means that
     * the inertias underflowed. */
    if (!all_finite(m.c, SR_GEN_NCONST_NAMED)) return SR_ERR_PARAM;
    reference_state(params[r], x);
    if (sr_gen_inertia(m.c, x, M) != SR_OK) return SR_ERR_PARAM;
    status = sr_gen_accel(m.c, x, zero_u, a);
    if (status == SR_GEN_SINGULAR) return SR_ERR_SINGULAR;
    /* After the pivots, so that inertias that underflow to zero (and whose reciprocals among the
     * pooled constants are infinite) are reported as singular. */
    if (status != SR_OK || !all_finite(m.c, SR_GEN_NCONST)) return SR_ERR_PARAM;
    if (sr_gen_energy(m.c, x, &energy) != SR_OK) return SR_ERR_PARAM;
    *model = m;
    return SR_OK;
}

static int is_rotation(const sr_real *R)
{
    int i, j;
    sr_real det;
    for (i = 0; i < 3; ++i) /* RᵀR is symmetric: its upper triangle decides */
        for (j = i; j < 3; ++j) {
            const sr_real dot = R[i] * R[j] + R[3 + i] * R[3 + j] + R[6 + i] * R[6 + j];
            if (!near(dot, i == j ? 1 : 0)) return 0;
        }
    det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6])
        + R[2] * (R[3] * R[7] - R[4] * R[6]);
    return near(det, 1);
}

/* Rotation about axis k (0 = x, 1 = y): the entries outside the k-plane are exact, so the
 * columns in the plane, (c, s) and (-s', c') on rows p, q, decide: unit length, orthogonal,
 * determinant c c' + s s' = 1. */
static int is_axis_rotation(const sr_real *R, int k)
{
    const int p = k == 0 ? 1 : 0, q = k == 2 ? 1 : 2;
    int i;
    for (i = 0; i < 3; ++i)
        if (R[3 * k + i] != (i == k ? 1 : 0) || R[3 * i + k] != (i == k ? 1 : 0)) return 0;
    return near(R[3 * p + p] * R[3 * p + p] + R[3 * q + p] * R[3 * q + p], 1)
        && near(R[3 * p + q] * R[3 * p + q] + R[3 * q + q] * R[3 * q + q], 1)
        && near(R[3 * p + p] * R[3 * p + q] + R[3 * q + p] * R[3 * q + q], 0)
        && near(R[3 * p + p] * R[3 * q + q] - R[3 * p + q] * R[3 * q + p], 1);
}

int sr_check_state(const sr_model *model, const sr_real x[SR_NX])
{
    if (!model || !x) return SR_ERR_NULL;
    if (!all_finite(x, SR_NX)) return SR_ERR_NONFINITE;
    if (!is_rotation(x + RS) || !is_axis_rotation(x + RY, 0) || !is_axis_rotation(x + RP, 1))
        return SR_ERR_NOT_ROTATION;
    if (SR_FABS(x[Q + 2] - model->p[0]) > SR_ROTATION_TOL * model->p[0]) return SR_ERR_CONSTRAINT;
    return SR_OK;
}

int sr_check_state_batch(const sr_model *model, long n, const sr_real *x, long *failed_row)
{
    long i;
    if (failed_row) *failed_row = -1;
    if (!model || !x) return SR_ERR_NULL;
    if (n < 0) return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        const int status = sr_check_state(model, x + i * SR_NX);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

/* Copy n results from tmp to out when the computation succeeded and they are all finite:
 * outputs are either fully written and finite or untouched.  (The generated kernels do the
 * same themselves: they write only on SR_GEN_OK, and return SR_GEN_NONFINITE, equal to
 * SR_ERR_NONFINITE, when a result is not finite.) */
static int deliver(int status, const sr_real *tmp, int n, sr_real *out)
{
    int i;
    if (status != SR_OK) return status;
    if (!all_finite(tmp, n)) return SR_ERR_NONFINITE;
    for (i = 0; i < n; ++i) out[i] = tmp[i];
    return SR_OK;
}

int sr_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV])
{
    int status;
    if (!a) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    return sr_gen_accel(model->c, x, u ? u : zero_u, a);
}

int sr_accel_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                   sr_real *a, long *failed_row)
{
    long i;
    if (failed_row) *failed_row = -1;
    if (!model || !x || !a) return SR_ERR_NULL;
    if (n < 0) return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        int status = sr_accel(model, x + i * SR_NX, u ? u + i * SR_NU : NULL, a + i * SR_NV);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_inertia(const sr_model *model, const sr_real x[SR_NX], sr_real M[SR_NV * SR_NV])
{
    int status;
    if (!M) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_gen_inertia(model->c, x, M);
}

int sr_rhs(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real f[SR_NV])
{
    int status;
    if (!f) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    return sr_gen_rhs(model->c, x, u ? u : zero_u, f);
}

int sr_energy(const sr_model *model, const sr_real x[SR_NX], sr_real *energy)
{
    int status;
    if (!energy) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_gen_energy(model->c, x, energy);
}

int sr_equilibrium_residual(const sr_model *model, const sr_real x[SR_NX], sr_real res[SR_NV])
{
    int status;
    if (!res) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_gen_equilibrium_residual(model->c, x, res);
}

/* R = Exp([[w]]) = I + (Exp([[w]]) - I) (no checks). */
static void so3_exp(const sr_real w[3], sr_real R[9])
{
    int i;
    so3_exp_minus_identity(w, R);
    for (i = 0; i < 9; i += 4) R[i] += 1;
}

int sr_so3_exp(const sr_real w[3], sr_real R[9])
{
    sr_real tmp[9];
    if (!w || !R) return SR_ERR_NULL;
    if (!all_finite(w, 3)) return SR_ERR_NONFINITE;
    so3_exp(w, tmp);
    return deliver(SR_OK, tmp, 9, R); /* |w|^2 may overflow */
}

static int lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                     sr_real dt, sr_real out[SR_NX])
{
    sr_real a[SR_NV], E[9], w_dt[3], v[3], x_new[SR_NX];
    const sr_real *R = x + RS, *w = x + W, *gam = x + RS + 6;
    const sr_real r = model->c[0];
    int i, status = sr_gen_accel(model->c, x, u, a);
    if (status != SR_OK) return status;
    for (i = 0; i < 3; ++i) w_dt[i] = dt * w[i];
    so3_exp(w_dt, E);
    matmul3(R, E, x_new + RS);
    rotate_about_axis(x + RY, 0, dt * x[W + 3], x_new + RY);
    rotate_about_axis(x + RP, 1, dt * x[W + 4], x_new + RP);
    /* q' = q + dt r R_S (w_S x gamma): the rolling constraint (eq. 37). */
    v[0] = w[1] * gam[2] - w[2] * gam[1];
    v[1] = w[2] * gam[0] - w[0] * gam[2];
    v[2] = w[0] * gam[1] - w[1] * gam[0];
    for (i = 0; i < 3; ++i)
        x_new[Q + i] = x[Q + i] + dt * r * (R[3 * i] * v[0] + R[3 * i + 1] * v[1] + R[3 * i + 2] * v[2]);
    for (i = 0; i < SR_NV; ++i) x_new[W + i] = x[W + i] + dt * a[i];
    for (i = 0; i < SR_NX; ++i) out[i] = x_new[i];
    return SR_OK;
}

/* One step of any method; x and out may alias.  comp: NULL, or a simulation's running
 * compensation for the fourth-order methods (Lie-Euler stays the paper's plain eq. (111)). */
static int advance(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                   sr_real dt, sr_real *comp, sr_real out[SR_NX])
{
    int i, status;
    switch (method & ~SR_PROJECT) {
    case SR_LIE_EULER: status = lie_euler(model, x, u, dt, out); break;
    case SR_RKMK4: status = sr_internal_rkmk4_step(model, x, u, dt, comp, out); break;
    case SR_CF4: status = sr_internal_cf4_step(model, x, u, dt, comp, out); break;
    default: return SR_ERR_ARG;
    }
    if (status == SR_OK && (method & SR_PROJECT)) {
        sr_internal_project(out);
        if (comp) for (i = 0; i < Q; ++i) comp[i] = 0; /* the projection moved the rotations */
    }
    return status;
}

static int valid_method(int method)
{
    const int base = method & ~SR_PROJECT;
    return base == SR_LIE_EULER || base == SR_RKMK4 || base == SR_CF4;
}

int sr_step(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
            sr_real dt, sr_real x_next[SR_NX])
{
    int status;
    sr_real tmp[SR_NX];
    if (!x_next) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    if (!(dt > 0) || !isfinite(dt) || !valid_method(method)) return SR_ERR_ARG;
    return deliver(advance(model, method, x, u ? u : zero_u, dt, NULL, tmp), tmp, SR_NX, x_next);
}

/* Kinetic energy 1/2 nu^T M nu and total energy of x (both finite, else SR_ERR_NONFINITE). */
static int energies(const sr_model *model, const sr_real x[SR_NX], sr_real *kinetic, sr_real *total)
{
    sr_real rest[SR_NX], potential;
    int i, status;
    for (i = 0; i < SR_NX; ++i) rest[i] = i < W ? x[i] : 0;
    status = sr_gen_energy(model->c, x, total);
    if (status == SR_OK) status = sr_gen_energy(model->c, rest, &potential);
    if (status != SR_OK) return status;
    *kinetic = *total - potential;
    return isfinite(*total) && isfinite(*kinetic) ? SR_OK : SR_ERR_NONFINITE;
}

/* The energy guard at row n of a run (the state x after n steps of this call); step_u is the
 * torque of the step that starts at x (NULL after the last step), prev_u that of the step that
 * ended there (NULL at row 0).  Opens a stretch at the start of a torque-free step, closes it
 * at a powered one, and compares the energy with the stretch's start at the check rows. */
static int energy_guard(const sr_model *model, sr_energy_guard *guard, const sr_real x[SR_NX],
                        const sr_real *prev_u, const sr_real *step_u, int check_row)
{
    const sr_real *p = model->p;
    sr_real kinetic, total;
    int status;
    if (!guard || !(guard->tol >= 0)) return SR_OK;
    if (prev_u && (prev_u[0] != 0 || prev_u[1] != 0)) guard->in_stretch = 0;
    if (guard->in_stretch && check_row) {
        sr_real limit;
        status = sr_gen_energy(model->c, x, &total);
        if (status != SR_OK) return status;
        if (!isfinite(total)) return SR_ERR_NONFINITE;
        guard->energy = total;
        limit = guard->e_start + guard->tol * guard->scale
              + 64 * SR_EPSILON * (SR_FABS(guard->e_start) + guard->scale);
        if (total > limit) return SR_ERR_ENERGY;
    }
    if (!guard->in_stretch && step_u && step_u[0] == 0 && step_u[1] == 0) {
        status = energies(model, x, &kinetic, &total);
        if (status != SR_OK) return status;
        guard->in_stretch = 1;
        guard->e_start = guard->energy = total;
        guard->scale = kinetic + p[9] * p[11] * p[8]; /* + m_P g l */
    }
    return SR_OK;
}

int sr_simulate_guarded(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt,
                        long steps, const sr_real *u, sr_energy_guard *guard, sr_real *traj,
                        long *steps_done)
{
    long n;
    int i, status;
    sr_real comp[SR_NX] = {0}; /* Kahan compensation carried across the steps of this call */
    if (steps_done) *steps_done = 0;
    status = sr_check_state(model, x0);
    if (status != SR_OK) return status;
    if (!traj) return SR_ERR_NULL;
    if (steps < 0 || !(dt > 0) || !isfinite(dt) || !valid_method(method)) return SR_ERR_ARG;
    if (guard && guard->tol == guard->tol && !isfinite(guard->tol)) return SR_ERR_ARG; /* +-inf */
    for (i = 0; i < SR_NX; ++i) traj[i] = x0[i];
    for (n = 0; n < steps; ++n) {
        const sr_real *x = traj + n * SR_NX;
        sr_real *next = traj + (n + 1) * SR_NX;
        const sr_real *un = u ? u + n * SR_NU : zero_u;
        const int check_row = (n + 1) % SR_GUARD_INTERVAL == 0 || n + 1 == steps;
        if (!all_finite(un, SR_NU)) return SR_ERR_NONFINITE;
        if (n == 0) { /* open a stretch at x0 (or continue the caller's) */
            status = energy_guard(model, guard, x, NULL, un, 0);
            if (status != SR_OK) return status;
        }
        status = advance(model, method, x, un, dt, comp, next);
        if (status == SR_OK && !all_finite(next, SR_NX)) status = SR_ERR_NONFINITE;
        if (status == SR_OK && check_row) status = sr_check_state(model, next);
        if (status == SR_OK) {
            const sr_real *u_next = n + 1 < steps ? (u ? u + (n + 1) * SR_NU : zero_u) : NULL;
            if (u_next && !all_finite(u_next, SR_NU)) u_next = NULL; /* reported at step n + 2 */
            status = energy_guard(model, guard, next, un, u_next, check_row);
        }
        if (status != SR_OK) return status;
        if (steps_done) *steps_done = n + 1;
    }
    return SR_OK;
}

int sr_simulate(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt, long steps,
                const sr_real *u, sr_real *traj, long *steps_done)
{
    return sr_simulate_guarded(model, method, x0, dt, steps, u, NULL, traj, steps_done);
}
