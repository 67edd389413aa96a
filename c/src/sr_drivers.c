/* sr_drivers.c -- the simulation drivers: fixed step (sr_simulate), fixed step with the energy
 * guard (sr_simulate_guarded) and adaptive RKMK4 with output on a fixed grid
 * (sr_simulate_adaptive).  They call the steppers of sr_steppers.c and the state check of
 * sr_checks.c; nothing calls back into this file.
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_checks.h"
#include "sr_kernels.h"
#include "sr_steppers.h"
#include "sr_argcheck.h"

#include <stddef.h>

/* ---- fixed step ------------------------------------------------------------------------- */

/* Kinetic energy 1/2 nu^T M nu and total energy of x (both finite, else SR_ERR_NONFINITE). */
static int energies(const sr_model *model, const sr_real x[SR_NX], sr_real *kinetic, sr_real *total)
{
    sr_real rest[SR_NX], potential;
    int i, status;
    for (i = 0; i < SR_NX; ++i) rest[i] = i < SR_X_w_S ? x[i] : 0; /* nu = 0 */
    status = sr_internal_energy(model, x, total);
    if (status == SR_OK) status = sr_internal_energy(model, rest, &potential);
    if (status != SR_OK) return status;
    *kinetic = *total - potential;
    return isfinite(*total) && isfinite(*kinetic) ? SR_OK : SR_ERR_NONFINITE;
}

/* How far the shape potential can range: 2 g (m_Y |c_Y| + m_P |c_P|) (m_P g l for the paper's robot). */
static sr_real potential_range(const sr_real *p)
{
    const sr_real *cY = p + SR_P_c_Y_x, *cP = p + SR_P_c_P_x;
    return 2 * p[SR_P_g] * (p[SR_P_m_Y] * SR_SQRT(cY[0] * cY[0] + cY[1] * cY[1] + cY[2] * cY[2])
                            + p[SR_P_m_P] * SR_SQRT(cP[0] * cP[0] + cP[1] * cP[1] + cP[2] * cP[2]));
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
        status = sr_internal_energy(model, x, &total);
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
        guard->scale = kinetic + potential_range(p);
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
    /* the guard's energies read the energy kernel's constants and the masses, centres and g */
    status = guard ? arg_model(model, READS(ACCEL) | READS(STATE) | READS(ENERGY) | READS(GUARD))
                   : arg_model(model, READS(ACCEL) | READS(STATE));
    if (status != SR_OK) return status;
    if (!x0 || !traj) return SR_ERR_NULL;
    if (steps < 0 || arg_dt(dt) != SR_OK || arg_method(method) != SR_OK) return SR_ERR_ARG;
    if (guard && guard->tol == guard->tol && !isfinite(guard->tol)) return SR_ERR_ARG; /* +-inf */
    status = sr_internal_check_state(model, x0);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NX; ++i) traj[i] = x0[i];
    for (n = 0; n < steps; ++n) {
        const sr_real *x = traj + n * SR_NX;
        sr_real *next = traj + (n + 1) * SR_NX;
        const sr_real *un = u ? u + n * SR_NU : sr_zero_u;
        const int check_row = (n + 1) % SR_GUARD_INTERVAL == 0 || n + 1 == steps;
        if (!all_finite(un, SR_NU)) return SR_ERR_NONFINITE;
        if (n == 0) { /* open a stretch at x0 (or continue the caller's) */
            status = energy_guard(model, guard, x, NULL, un, 0);
            if (status != SR_OK) return status;
        }
        status = sr_internal_advance(model, method, x, un, dt, comp, next);
        if (status == SR_OK && !all_finite(next, SR_NX)) status = SR_ERR_NONFINITE;
        if (status == SR_OK && check_row) status = sr_internal_check_state(model, next);
        if (status == SR_OK) {
            const sr_real *u_next = n + 1 < steps ? (u ? u + (n + 1) * SR_NU : sr_zero_u) : NULL;
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

/* ---- adaptive stepping ------------------------------------------------------------------ */

static sr_real max_r(sr_real a, sr_real b) { return a > b ? a : b; }
static sr_real min_r(sr_real a, sr_real b) { return a < b ? a : b; }

/* Weighted max norm of the RKMK4(3) error estimate e = h/6 (K4 - K5) (tangent coordinates). */
static sr_real rkmk4_error(const sr_real K4[SR_NT], const sr_real K5[SR_NT], sr_real h, const sr_real x[SR_NX],
                           const sr_real y[SR_NX], sr_real rtol, sr_real atol)
{
    sr_real err = 0;
    int i;
    for (i = 0; i < SR_NT; ++i) {
        const sr_real e = SR_FABS(h / 6 * (K4[i] - K5[i]));
        sr_real scale = 1; /* rotation angles: the entries of a rotation are of size 1 */
        if (i >= SR_T_Q) {
            const int j = i < SR_T_V ? SR_X_q + (i - SR_T_Q) : SR_X_w_S + (i - SR_T_V);
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
    sr_real f_cur[SR_NT];
    sr_adaptive_stats *st;
} adaptive_ctx;

/* One trial step of RKMK4 with its embedded estimate, size h from x: y = the propagated
 * (4th-order) state, *err = the weighted norm of the estimate (<= 1: accept), f_next = f(y). */
static int trial_step(adaptive_ctx *cx, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                      sr_real y[SR_NX], sr_real f_next[SR_NT], sr_real *err)
{
    sr_real K[4][SR_NT], theta[SR_NT], K5[SR_NT];
    int i, status;
    if (!cx->have_f) {
        status = sr_internal_vector_field(cx->model, x, u, cx->f_cur, &cx->st->evaluations);
        if (status != SR_OK) return status;
        cx->have_f = 1;
    }
    for (i = 0; i < SR_NT; ++i) K[0][i] = cx->f_cur[i];
    status = sr_internal_rkmk4_core(cx->model, x, u, h, K, theta, NULL, y, &cx->st->evaluations);
    if (status != SR_OK) return status;
    /* Fifth stage at the new point ("first same as last"): K5 = sr_internal_dexpinv(Theta, f(y)). */
    status = sr_internal_vector_field(cx->model, y, u, f_next, &cx->st->evaluations);
    if (status != SR_OK) return status;
    sr_internal_dexpinv(theta, f_next, K5);
    *err = rkmk4_error(K[3], K5, h, x, y, cx->rtol, cx->atol);
    return SR_OK;
}

int sr_simulate_adaptive(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt_out,
                         long n_out, const sr_real *u, sr_real rtol, sr_real atol, sr_real h_init,
                         long max_steps, sr_real *traj, sr_adaptive_stats *stats)
{
    sr_adaptive_stats local = {0, 0, 0, 0, 0};
    adaptive_ctx cx;
    sr_real x[SR_NX], y[SR_NX], f_next[SR_NT], h, tol, expo;
    long k;
    int i, base, status;
    if (!stats) stats = &local;
    *stats = local;
    status = arg_model(model, READS(ACCEL) | READS(STATE));
    if (status != SR_OK) return status;
    if (!x0 || !traj) return SR_ERR_NULL;
    base = method & ~SR_PROJECT;
    if (arg_method(method) != SR_OK || base != SR_RKMK4 || arg_dt(dt_out) != SR_OK || n_out < 0
        || !(rtol >= 0) || !(atol >= 0) || !(rtol + atol > 0) || !isfinite(rtol) || !isfinite(atol)
        || !(max_steps > 0) || h_init != h_init || !isfinite(h_init))
        return SR_ERR_ARG;
    status = sr_internal_check_state(model, x0); /* in full, like sr_simulate */
    if (status != SR_OK) return status;

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
        const sr_real *uk = u ? u + k * SR_NU : sr_zero_u;
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
            for (i = 0; i < SR_NT; ++i) cx.f_cur[i] = f_next[i]; /* first same as last */
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
