/* A whole closed loop on sensors: c/include/sr_loop.h. */
#include "sr_loop.h"

#include <string.h>

#include "sr_finite.h"

int sr_path_check(const sr_path *path)
{
    long i;
    if (!path) return SR_ERR_NULL;
    if (path->n < 2 || path->hint < 0 || path->hint >= path->n) return SR_ERR_ARG;
    if (!path->points || !path->s || !path->tangent || !path->curvature) return SR_ERR_NULL;
    if (!all_finite(&path->speed, 1) || !all_finite(&path->search_back, 1) || !all_finite(&path->search_ahead, 1))
        return SR_ERR_NONFINITE;
    if (path->search_back < 0 || path->search_ahead < 0) return SR_ERR_ARG;
    for (i = 0; i < path->n; ++i) {
        if (!all_finite(path->points + 2 * i, 2) || !all_finite(path->s + i, 1) || !all_finite(path->tangent + i, 1)
            || !all_finite(path->curvature + i, 1))
            return SR_ERR_NONFINITE;
        if (i > 0 && !(path->s[i] > path->s[i - 1])) return SR_ERR_ARG;
    }
    return SR_OK;
}

/* The first index whose arc length is >= value (n when none): NumPy's searchsorted, side "left". */
static long first_at_least(const sr_real *s, long n, sr_real value)
{
    long lo = 0, hi = n;
    while (lo < hi) {
        long mid = lo + (hi - lo) / 2;
        if (s[mid] < value) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

int sr_path_target(sr_path *path, const sr_real position[2], sr_lqr_target *target)
{
    long lo, hi, i, best;
    sr_real best_d2 = 0, s_hint, rel[2];
    if (!path || !position || !target) return SR_ERR_NULL;
    if (path->hint < 0 || path->hint >= path->n) return SR_ERR_ARG;
    if (!all_finite(position, 2)) return SR_ERR_NONFINITE;
    s_hint = path->s[path->hint];
    lo = first_at_least(path->s, path->n, s_hint - path->search_back);
    hi = first_at_least(path->s, path->n, s_hint + path->search_ahead) + 1;
    if (hi > path->n) hi = path->n;
    best = lo;
    for (i = lo; i < hi; ++i) {
        sr_real dx = path->points[2 * i] - position[0], dy = path->points[2 * i + 1] - position[1];
        sr_real d2 = dx * dx + dy * dy;
        if (i == lo || d2 < best_d2) {
            best_d2 = d2;
            best = i;
        }
    }
    rel[0] = position[0] - path->points[2 * best];
    rel[1] = position[1] - path->points[2 * best + 1];
    path->hint = best;
    target->speed = path->speed;
    target->heading = path->tangent[best];
    target->curvature = path->curvature[best];
    target->cross_track = -SR_SIN(target->heading) * rel[0] + SR_COS(target->heading) * rel[1];
    target->path = 1;
    return SR_OK;
}

int sr_path_cross_track(sr_path *path, const sr_real *positions, long n, long stride, sr_real *out, long *first)
{
    sr_lqr_target target;
    long i;
    if (!path || (n > 0 && (!positions || !out))) return SR_ERR_NULL;
    if (n < 0 || stride < 2) return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        int status = sr_path_target(path, positions + i * stride, &target);
        if (status != SR_OK) return status;
        out[i] = target.cross_track;
        if (i == 0 && first) *first = path->hint;
    }
    return SR_OK;
}

/* The curvature at arc length value: linear between samples, held beyond the ends (NumPy's interp). */
static sr_real curvature_at(const sr_path *path, sr_real value)
{
    const sr_real *s = path->s, *k = path->curvature;
    long j;
    if (value <= s[0]) return k[0];
    if (value >= s[path->n - 1]) return k[path->n - 1];
    j = first_at_least(s, path->n, value);      /* s[j - 1] < value <= s[j] */
    if (s[j] == value) return k[j];
    --j;
    if (k[j] == k[j + 1]) return k[j];
    return (k[j + 1] - k[j]) / (s[j + 1] - s[j]) * (value - s[j]) + k[j];
}

int sr_path_curvature_ahead(const sr_path *path, const sr_real *distances, int n, sr_real *out)
{
    int i;
    if (!path || (n > 0 && (!distances || !out))) return SR_ERR_NULL;
    if (n < 0 || path->hint < 0 || path->hint >= path->n) return SR_ERR_ARG;
    if (n > 0 && !all_finite(distances, n)) return SR_ERR_NONFINITE;
    for (i = 0; i < n; ++i) out[i] = curvature_at(path, path->s[path->hint] + distances[i]);
    return SR_OK;
}

/* The target of one sample: the path's at the estimate's position, its curvature the preview's mean. */
static int sample_target(sr_path *path, const sr_real *preview, int n_preview, const sr_real x[SR_NX],
                         sr_lqr_target *target)
{
    int i, status = sr_path_target(path, x + SR_X_q, target);
    if (status != SR_OK || n_preview == 0) return status;
    {
        sr_real sum = 0;
        const sr_real s_hint = path->s[path->hint];
        for (i = 0; i < n_preview; ++i) sum += curvature_at(path, s_hint + preview[i]);
        target->curvature = sum / n_preview;
    }
    return SR_OK;
}

int sr_loop_lqr(sr_sim *sim, const sr_model *plant, sr_ekf *ekf, const sr_model *model, const sr_lqr *lqr,
                sr_lqr_memory *memory, sr_slope_estimator *estimate, const sr_lqr_offsets *offsets,
                sr_path *path, const sr_real *preview, int n_preview, long per, long first,
                long count, sr_real x[SR_NX], sr_real u[SR_NU], sr_real *traj, sr_real *torques,
                sr_real *estimates, long *applied, long *saturated, long *done, int *failed_in)
{
    long k;
    int status;
    if (!done || !failed_in) return SR_ERR_NULL;
    *done = 0;
    *failed_in = SR_LOOP_CONTROL;
    if (!sim || !plant || !ekf || !model || !lqr || !memory || !path || !x || !u || (n_preview > 0 && !preview))
        return SR_ERR_NULL;
    if (per < 1 || count < 0 || first < 0 || n_preview < 0) return SR_ERR_ARG;
    status = sr_path_check(path);
    if (status != SR_OK) return status;
    if (n_preview > 0 && !all_finite(preview, n_preview)) return SR_ERR_NONFINITE;
    *failed_in = SR_LOOP_SIM;
    status = sr_sim_check(sim);
    if (status != SR_OK) return status;
    if (count > 0 && (first + count) * per > sim->steps) return SR_ERR_ARG;
    *failed_in = SR_LOOP_OK;
    for (k = 0; k < count; ++k) {
        const sr_real t = (sr_real)(first + k) * lqr->period;
        sr_lqr_target target;
        sr_real out[SR_NU];
        if (t > sim->filter_time) {
            status = sr_ekf_predict(ekf, model, sim->filter_method, u, t - sim->filter_time, &sim->filter_process);
            if (status != SR_OK) {
                *failed_in = SR_LOOP_FILTER;
                return status;
            }
            sim->filter_time = t;
        }
        if (estimates) memcpy(estimates + k * SR_NX, ekf->x, sizeof ekf->x);
        status = sample_target(path, preview, n_preview, ekf->x, &target);
        if (status == SR_OK && estimate) status = sr_slope_update(estimate, ekf->x, u);
        if (status == SR_OK)
            status = sr_lqr_control_offsets(lqr, model, ekf->x, &target, estimate ? &estimate->offsets : offsets, memory,
                                            out, NULL);
        if (status != SR_OK) {
            *failed_in = SR_LOOP_CONTROL;
            return status;
        }
        memcpy(u, out, sizeof out);
        if (saturated && (SR_FABS(u[0]) >= lqr->u_max * (1 - SR_C(1e-9)) || SR_FABS(u[1]) >= lqr->u_max * (1 - SR_C(1e-9))))
            ++*saturated;
        if (torques) memcpy(torques + k * SR_NU, u, sizeof out);
        status = sr_sim_advance(sim, plant, ekf, model, (first + k) * per, per, x, u,
                                traj ? traj + k * per * SR_NX : NULL);
        if (status != SR_OK) {
            *failed_in = SR_LOOP_SIM;
            return status;
        }
        if (applied) applied[k] = sim->applied;
        *done = k + 1;
    }
    return SR_OK;
}
