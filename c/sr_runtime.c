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
    default: return "unknown status";
    }
}

int sr_model_init(sr_model *model, const sr_real params[SR_NPARAM])
{
    enum { r, m_S, k_S, b, h, m_b, m_h, k_Y, l, m_P, k_P, g };
    static const int positive[] = {r, m_S, b, h, m_b, m_h, l, m_P};
    static const int nonnegative[] = {k_S, k_Y, k_P, g};
    size_t i;
    if (!model || !params) return SR_ERR_NULL;
    if (!all_finite(params, SR_NPARAM)) return SR_ERR_NONFINITE;
    for (i = 0; i < sizeof positive / sizeof positive[0]; ++i)
        if (!(params[positive[i]] > 0)) return SR_ERR_PARAM;
    for (i = 0; i < sizeof nonnegative / sizeof nonnegative[0]; ++i)
        if (!(params[nonnegative[i]] >= 0)) return SR_ERR_PARAM;
    /* The yoke's corners and the pendulum's tip must fit inside the shell. */
    if (params[b] * params[b] + params[h] * params[h] > SR_C(4.0) * params[r] * params[r]) return SR_ERR_PARAM;
    if (params[l] > params[r]) return SR_ERR_PARAM;
    for (i = 0; i < SR_NPARAM; ++i) model->p[i] = params[i];
    return sr_gen_constants(model->p, model->c);
}

static int is_rotation(const sr_real *R)
{
    int i, j, k;
    sr_real det;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            sr_real dot = 0;
            for (k = 0; k < 3; ++k) dot += R[3 * k + i] * R[3 * k + j];
            if (!near(dot, i == j ? 1 : 0)) return 0;
        }
    det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6])
        + R[2] * (R[3] * R[7] - R[4] * R[6]);
    return near(det, 1);
}

/* Rotation about axis k (0 = x, 1 = y): the entries outside the k-plane are exact. */
static int is_axis_rotation(const sr_real *R, int k)
{
    int i;
    for (i = 0; i < 3; ++i)
        if (R[3 * k + i] != (i == k ? 1 : 0) || R[3 * i + k] != (i == k ? 1 : 0)) return 0;
    return is_rotation(R);
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

static const sr_real zero_u[SR_NU] = {0, 0};

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

int sr_so3_exp(const sr_real w[3], sr_real R[9])
{
    sr_real theta2, A, B;
    if (!w || !R) return SR_ERR_NULL;
    theta2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
    so3_exp_coefficients(theta2, &A, &B);
    /* R = I + A [[w]] + B [[w]]^2, with [[w]]^2 = w w^T - |w|^2 I. */
    R[0] = 1 + B * (w[0] * w[0] - theta2);
    R[4] = 1 + B * (w[1] * w[1] - theta2);
    R[8] = 1 + B * (w[2] * w[2] - theta2);
    R[1] = B * w[0] * w[1] - A * w[2];
    R[3] = B * w[0] * w[1] + A * w[2];
    R[2] = B * w[0] * w[2] + A * w[1];
    R[6] = B * w[0] * w[2] - A * w[1];
    R[5] = B * w[1] * w[2] - A * w[0];
    R[7] = B * w[1] * w[2] + A * w[0];
    return SR_OK;
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
    sr_so3_exp(w_dt, E);
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

/* One step of any method; x and out may alias. */
static int advance(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                   sr_real dt, sr_real out[SR_NX])
{
    int status;
    switch (method & ~SR_PROJECT) {
    case SR_LIE_EULER: status = lie_euler(model, x, u, dt, out); break;
    case SR_RKMK4: status = sr_internal_rkmk4_step(model, x, u, dt, out); break;
    case SR_CF4: status = sr_internal_cf4_step(model, x, u, dt, out); break;
    default: return SR_ERR_ARG;
    }
    if (status == SR_OK && (method & SR_PROJECT)) sr_internal_project(out);
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
    if (!x_next) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    if (!(dt > 0) || !isfinite(dt) || !valid_method(method)) return SR_ERR_ARG;
    return advance(model, method, x, u ? u : zero_u, dt, x_next);
}

int sr_simulate(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt, long steps,
                const sr_real *u, sr_real *traj, long *steps_done)
{
    long n;
    int i, status;
    if (steps_done) *steps_done = 0;
    status = checks(model, x0, NULL);
    if (status != SR_OK) return status;
    if (!traj) return SR_ERR_NULL;
    if (steps < 0 || !(dt > 0) || !isfinite(dt) || !valid_method(method)) return SR_ERR_ARG;
    for (i = 0; i < SR_NX; ++i) traj[i] = x0[i];
    for (n = 0; n < steps; ++n) {
        const sr_real *x = traj + n * SR_NX;
        const sr_real *un = u ? u + n * SR_NU : zero_u;
        if (!all_finite(un, SR_NU)) return SR_ERR_NONFINITE;
        status = advance(model, method, x, un, dt, traj + (n + 1) * SR_NX);
        if (status == SR_OK && !all_finite(traj + (n + 1) * SR_NX, SR_NX)) status = SR_ERR_NONFINITE;
        if (status != SR_OK) return status;
        if (steps_done) *steps_done = n + 1;
    }
    return SR_OK;
}
