/* sr_batch.c -- many robots in one call: sr_simulate_batch (see spherical_robot.h).
 * Built on the public API only (sr_model_init, sr_simulate_guarded, sr_energy), so that each
 * sample is exactly the run a caller would make alone, chunk for chunk. */
#include "sr_math.h"
#include "sr_argcheck.h"

#include <stddef.h>

/* Running summary metrics of one sample, updated row by row. */
typedef struct metrics_acc {
    sr_real q0[3];
    sr_real path, max_distance, max_rate;
} metrics_acc;

/* |(a, b, c)|, finite whenever it is representable: where the squares overflow (components past
 * ~1e154, a state far out but finite), scaled by the largest magnitude. */
static sr_real norm3(sr_real a, sr_real b, sr_real c)
{
    const sr_real s = a * a + b * b + c * c;
    sr_real m;
    if (isfinite(s)) return SR_SQRT(s);
    m = SR_FABS(a) > SR_FABS(b) ? SR_FABS(a) : SR_FABS(b);
    m = m > SR_FABS(c) ? m : SR_FABS(c);
    if (!isfinite(m)) return m;
    a /= m;
    b /= m;
    c /= m;
    return m * SR_SQRT(a * a + b * b + c * c);
}

static void metrics_start(metrics_acc *m, const sr_real x0[SR_NX])
{
    int i;
    for (i = 0; i < 3; ++i) m->q0[i] = x0[SR_X_q + i];
    m->path = 0;
    m->max_distance = 0;
    m->max_rate = norm3(x0[SR_X_w_S], x0[SR_X_w_S + 1], x0[SR_X_w_S + 2]);
}

/* Rows 1..n of rows (row 0 is the state the rows continue from). */
static void metrics_add(metrics_acc *m, const sr_real *rows, long n)
{
    long k;
    for (k = 1; k <= n; ++k) {
        const sr_real *prev = rows + (k - 1) * SR_NX + SR_X_q, *x = rows + k * SR_NX;
        const sr_real *q = x + SR_X_q, *w = x + SR_X_w_S;
        const sr_real distance = norm3(q[0] - m->q0[0], q[1] - m->q0[1], q[2] - m->q0[2]);
        const sr_real rate = norm3(w[0], w[1], w[2]);
        m->path += norm3(q[0] - prev[0], q[1] - prev[1], q[2] - prev[2]);
        if (distance > m->max_distance) m->max_distance = distance;
        if (rate > m->max_rate) m->max_rate = rate;
    }
}

/* One sample: the chunked, guarded run of steps steps; writes *x_final and metrics on SR_OK. */
static int run_sample(int method, const sr_real params[SR_NPARAM], const sr_real x0[SR_NX], sr_real dt,
                      long steps, const sr_real *u, sr_real energy_tol, long chunk_steps, sr_real *work,
                      sr_real *traj, sr_real x_final[SR_NX], sr_real metrics[SR_BATCH_NMETRICS],
                      long *steps_done)
{
    sr_model model;
    sr_energy_guard guard;
    metrics_acc acc;
    sr_real energy;
    const sr_real *last = x0;
    long done = 0;
    int i, status = sr_model_init(&model, params);
    if (status != SR_OK) return status;
    status = sr_check_state(&model, x0);
    if (status != SR_OK) return status;
    guard.tol = energy_tol;
    guard.in_stretch = 0;
    guard.e_start = guard.scale = guard.energy = 0;
    metrics_start(&acc, x0);
    if (traj) for (i = 0; i < SR_NX; ++i) traj[i] = x0[i];
    while (done < steps) { /* chunks of chunk_steps, the energy guard carried across them */
        const long n = steps - done < chunk_steps ? steps - done : chunk_steps;
        sr_real *rows = traj ? traj + done * SR_NX : work;
        long chunk_done = 0;
        status = sr_simulate_guarded(&model, method, last, dt, n, u ? u + done * SR_NU : NULL, &guard,
                                     rows, &chunk_done);
        *steps_done = done + chunk_done;
        if (status != SR_OK) return status;
        metrics_add(&acc, rows, n);
        done += n;
        last = rows + n * SR_NX;
        if (!traj && done < steps) { /* the next chunk starts from row 0 of the work buffer */
            for (i = 0; i < SR_NX; ++i) work[i] = last[i];
            last = work;
        }
    }
    status = sr_energy(&model, last, &energy);
    if (status != SR_OK) return status;
    /* Every row finite, but a sum or a difference of positions may still overflow (a path longer
     * than the largest number): no finite metrics, as for an energy that overflows. */
    if (!isfinite(acc.path) || !isfinite(acc.max_distance) || !isfinite(acc.max_rate)) return SR_ERR_NONFINITE;
    if (x_final) for (i = 0; i < SR_NX; ++i) x_final[i] = last[i];
    if (metrics) {
        metrics[SR_BATCH_PATH_LENGTH] = acc.path;
        metrics[SR_BATCH_MAX_DISTANCE] = acc.max_distance;
        metrics[SR_BATCH_MAX_SHELL_RATE] = acc.max_rate;
        metrics[SR_BATCH_FINAL_ENERGY] = energy;
    }
    return SR_OK;
}

int sr_simulate_batch(int method, long n, const sr_real *params, long params_stride, const sr_real *x0,
                      long x0_stride, sr_real dt, long steps, const sr_real *u, long u_stride,
                      sr_real energy_tol, long chunk_steps, sr_real *work, sr_real *traj,
                      sr_real *x_final, sr_real *metrics, int *status, long *steps_done)
{
    long i;
    if (!params || !x0 || !status || !steps_done || (!traj && !work)) return SR_ERR_NULL;
    if (n < 0 || steps < 0 || chunk_steps < 1 || params_stride < 0 || x0_stride < 0 || u_stride < 0
        || arg_dt(dt) != SR_OK || arg_method(method) != SR_OK
        || (energy_tol == energy_tol && !isfinite(energy_tol)))
        return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        steps_done[i] = 0;
        status[i] = run_sample(method, params + i * params_stride, x0 + i * x0_stride, dt, steps,
                               u ? u + i * u_stride : NULL, energy_tol, chunk_steps, work,
                               traj ? traj + i * (steps + 1) * SR_NX : NULL,
                               x_final ? x_final + i * SR_NX : NULL,
                               metrics ? metrics + i * SR_BATCH_NMETRICS : NULL, steps_done + i);
    }
    return SR_OK;
}
