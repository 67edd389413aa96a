/* A robot on its sensors, simulated: c/include/sr_sim.h. */
#include "sr_sim.h"

#include <math.h>

#include "sr_kernels.h"

#ifdef SR_USE_FLOAT
#define SIM_NEARBYINT nearbyintf
#define SIM_REMAINDER remainderf
#else
#define SIM_NEARBYINT nearbyint
#define SIM_REMAINDER remainder
#endif

static const int WIDTH[SR_SIM_NKINDS] = {SR_NIMU, 2, 2, 1};
static const sr_real TWO_PI = SR_C(6.283185307179586476925286766559);

static int finite_nonnegative(sr_real v)
{
    return v - v == 0 && v >= 0;
}

static int check_stream(const sr_sim_stream *s, int kind)
{
    int j, status;
    if (s->n < 0 || s->read < 0 || s->applied < 0 || s->read > s->n || s->applied > s->read) return SR_ERR_ARG;
    if (s->n == 0) return SR_OK;
    if (!s->time || !s->arrival || !s->reading || (kind != SR_SIM_ENCODERS && !s->draw)) return SR_ERR_NULL;
    for (j = 0; j < WIDTH[kind]; ++j) {
        if (!finite_nonnegative(s->noise[j]) || !finite_nonnegative(s->sigma[j])) return SR_ERR_ARG;
    }
    if (!(s->gate >= 0)) return SR_ERR_ARG;     /* +infinity: no gate, as in sr_ekf */
    if (kind == SR_SIM_IMU) {
        for (j = 0; j < SR_NIMU; ++j) {
            if (!(finite_nonnegative(s->range[j]) && s->range[j] > 0)) return SR_ERR_ARG;
        }
    }
    if (kind == SR_SIM_ENCODERS && !(finite_nonnegative(s->range[0]) && s->range[0] > 0)) return SR_ERR_ARG;
    if (kind == SR_SIM_IMU || kind == SR_SIM_HEADING) {
        status = sr_check_mount(s->body, s->mount);
        if (status == SR_OK) status = sr_check_mount(s->filter_body, s->filter_mount);
        if (status != SR_OK) return status;
    }
    return SR_OK;
}

int sr_sim_check(const sr_sim *sim)
{
    int k, status;
    if (!sim) return SR_ERR_NULL;
    if (!(sim->dt - sim->dt == 0 && sim->dt > 0) || sim->steps < 0) return SR_ERR_ARG;
    if ((sim->method & ~SR_PROJECT) < SR_LIE_EULER || (sim->method & ~SR_PROJECT) > SR_CF4) return SR_ERR_ARG;
    if ((sim->filter_method & ~SR_PROJECT) < SR_LIE_EULER || (sim->filter_method & ~SR_PROJECT) > SR_CF4)
        return SR_ERR_ARG;
    if (sim->bias_stride != 0 && sim->bias_stride != SR_NBIAS) return SR_ERR_ARG;
    if (!(sim->filter_time - sim->filter_time == 0) || sim->applied < 0) return SR_ERR_ARG;
    if (!finite_nonnegative(sim->filter_hold)) return SR_ERR_ARG;
    if (sim->steps > 0 && !sim->process) return SR_ERR_NULL;
    if (sim->stream[SR_SIM_IMU].n > 0 && !sim->bias) return SR_ERR_NULL;
    for (k = 0; k < SR_NV; ++k) {
        if (!finite_nonnegative(sim->q_std[k])) return SR_ERR_ARG;
    }
    for (k = 0; k < SR_SIM_NKINDS; ++k) {
        status = check_stream(&sim->stream[k], k);
        if (status != SR_OK) return status;
    }
    return SR_OK;
}

/* nu_dot_w = M^-1 w by the library's Cholesky of the inertia. */
static int disturbance_accel(const sr_model *plant, const sr_real x[SR_NX], const sr_real w[SR_NV],
                             sr_real out[SR_NV])
{
    sr_real M[SR_NV * SR_NV], Mu[15], L[SR_NV * SR_NV], inv[SR_NV];
    int i, j, status = sr_inertia(plant, x, M);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) {
        for (j = i; j < SR_NV; ++j) Mu[SR_UPPER[i][j]] = M[i * SR_NV + j];
    }
    status = sr_internal_cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) out[i] = w[i];
    sr_internal_cholesky_solve(L, inv, 1, 1, out);
    return SR_OK;
}

static int read_sample(sr_sim *sim, const sr_model *plant, int kind, long i, const sr_real xs[SR_NX],
                       const sr_real u[SR_NU], const sr_real nu_dot_w[SR_NV])
{
    sr_sim_stream *s = &sim->stream[kind];
    sr_real *y = s->reading + i * WIDTH[kind];
    const sr_real *z = s->draw ? s->draw + i * WIDTH[kind] : 0;
    sr_real a[SR_NV];
    int j, status;
    switch (kind) {
    case SR_SIM_IMU:
        status = sr_check_state(plant, xs);
        if (status == SR_OK) status = sr_accel(plant, xs, u, a);
        if (status != SR_OK) return status;
        for (j = 0; j < SR_NV; ++j) a[j] += sim->disturbance_in_accel ? nu_dot_w[j] : SR_C(0.0);
        status = sr_imu_measure(plant, xs, a, s->body, s->mount, sim->bias + i * sim->bias_stride, y);
        if (status != SR_OK) return status;
        for (j = 0; j < SR_NIMU; ++j) {
            y[j] += z[j] * s->noise[j];
            if (y[j] < -s->range[j]) y[j] = -s->range[j];
            if (y[j] > s->range[j]) y[j] = s->range[j];
        }
        return SR_OK;
    case SR_SIM_ENCODERS:
        status = sr_encoders_measure(plant, xs, y);
        if (status != SR_OK) return status;
        for (j = 0; j < 2; ++j) y[j] = SIM_NEARBYINT(y[j] / s->range[0]) * s->range[0];
        return SR_OK;
    case SR_SIM_FIXES:
        status = sr_position_measure(plant, xs, y);
        if (status != SR_OK) return status;
        for (j = 0; j < 2; ++j) y[j] += SR_C(0.0) + s->noise[0] * z[j];
        return SR_OK;
    default:
        status = sr_heading_measure(plant, xs, s->body, s->mount, y);
        if (status != SR_OK) return status;
        y[0] = SIM_REMAINDER(y[0] + (SR_C(0.0) + s->noise[0] * z[0]), TWO_PI);
        return SR_OK;
    }
}

static int apply_sample(sr_sim *sim, sr_ekf *ekf, const sr_model *model, int kind, const sr_real u[SR_NU])
{
    sr_sim_stream *s = &sim->stream[kind];
    long i = s->applied;
    const sr_real *y = s->reading + i * WIDTH[kind];
    int status = SR_OK;
    if (s->arrival[i] > sim->filter_time) {
        status = sr_ekf_predict(ekf, model, sim->filter_method, u, s->arrival[i] - sim->filter_time,
                                &sim->filter_process);
        if (status != SR_OK) return status;
        sim->filter_time = s->arrival[i];
    }
    switch (kind) {
    case SR_SIM_IMU:
        status = sim->filter_hold > 0
            ? sr_ekf_update_imu_held(ekf, model, y, u, s->filter_body, s->filter_mount, s->sigma, &sim->filter_process,
                                     sim->filter_hold, s->gate)
            : sr_ekf_update_imu_axes(ekf, model, y, u, s->filter_body, s->filter_mount, s->sigma, s->gate);
        break;
    case SR_SIM_ENCODERS:
        status = sr_ekf_update_encoders(ekf, model, y, s->sigma[0], s->gate);
        break;
    case SR_SIM_FIXES:
        status = sr_ekf_update_position(ekf, model, y, s->sigma[0], s->gate);
        break;
    default:
        status = sr_ekf_update_heading(ekf, model, y[0], s->filter_body, s->filter_mount, s->sigma[0], s->gate);
        break;
    }
    if (status != SR_OK) return status;
    if (sim->order) {
        sim->order[2 * sim->applied] = kind;
        sim->order[2 * sim->applied + 1] = i;
    }
    ++sim->applied;
    ++s->applied;
    return SR_OK;
}

int sr_sim_advance(sr_sim *sim, const sr_model *plant, sr_ekf *ekf, const sr_model *model, long step, long count,
                   sr_real x[SR_NX], const sr_real u[SR_NU], sr_real *traj)
{
    long k, c;
    int kind, j, status;
    if (!sim || !plant || !ekf || !model || !x || !u) return SR_ERR_NULL;
    status = sr_sim_check(sim);
    if (status != SR_OK) return status;
    if (step < 0 || count < 0 || step > sim->steps - count) return SR_ERR_ARG;
    for (c = 0; c < count; ++c) {
        sr_real w[SR_NV], nu_dot_w[SR_NV], xs[SR_NX], next[SR_NX];
        sr_real t_k, end, arrived;
        k = step + c;
        t_k = (sr_real)k * sim->dt;
        end = t_k + sim->dt;                               /* the reading's bound, as the Python simulation's */
        arrived = (sr_real)(k + 1) * sim->dt - SR_C(1e-9) * sim->dt;   /* the closed loop's */
        for (j = 0; j < SR_NV; ++j) w[j] = sim->process[k * SR_NV + j] * sim->q_std[j];
        status = disturbance_accel(plant, x, w, nu_dot_w);
        if (status != SR_OK) return status;
        for (kind = 0; kind < SR_SIM_NKINDS; ++kind) {
            sr_sim_stream *s = &sim->stream[kind];
            while (s->read < s->n && s->time[s->read] < end - SR_C(1e-9) * sim->dt) {
                sr_real tau = s->time[s->read] - t_k;
                const sr_real *at = x;
                if (tau > SR_C(1e-9) * sim->dt) {
                    status = sr_step(plant, sim->method, x, u, tau, xs);
                    if (status != SR_OK) return status;
                    for (j = 0; j < SR_NV; ++j) xs[SR_X_w_S + j] += nu_dot_w[j] * tau;
                    at = xs;
                }
                status = read_sample(sim, plant, kind, s->read, at, u, nu_dot_w);
                if (status != SR_OK) return status;
                ++s->read;
            }
        }
        status = sr_step(plant, sim->method, x, u, sim->dt, next);
        if (status != SR_OK) return status;
        for (j = 0; j < SR_NV; ++j) next[SR_X_w_S + j] += nu_dot_w[j] * sim->dt;
        for (j = 0; j < SR_NX; ++j) x[j] = next[j];
        if (traj) {
            for (j = 0; j < SR_NX; ++j) traj[c * SR_NX + j] = x[j];
        }
        for (;;) {               /* the arrived samples, by (arrival, kind): a merge of the streams */
            int first = -1;
            for (kind = 0; kind < SR_SIM_NKINDS; ++kind) {
                const sr_sim_stream *s = &sim->stream[kind];
                if (s->applied < s->read && s->arrival[s->applied] < arrived
                    && (first < 0 || s->arrival[s->applied] < sim->stream[first].arrival[sim->stream[first].applied]))
                    first = kind;
            }
            if (first < 0) break;
            status = apply_sample(sim, ekf, model, first, u);
            if (status != SR_OK) return status;
        }
    }
    return SR_OK;
}
