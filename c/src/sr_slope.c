/*
 * sr_slope.c -- the slope estimate of the LQR (spherical_robot.h, sr_slope_*): a slope vector, a
 * torque offset and the pendulum's departure from the model, by least squares with exponential
 * forgetting on the measured rates against the model's one-period predictions.  The same
 * arithmetic as runtime/control/slope.py's SlopeEstimator, which is its reference.
 */
#include "sr_finite.h"
#include "sr_math.h"

#include <string.h>

#define NT SR_SLOPE_NTHETA
#define NM SR_SLOPE_NMOVED
/* The probes and scales of runtime/control/slope.py (PROBE_SLOPE, PREDICT_DT, TORQUE_PROBE, MASS_PROBE,
 * CENTRE_PROBE_M, MASS_SCALE, CENTRE_SCALE_M, DAMPING_PROBE, DAMPING_SCALE). */
#define PROBE_SLOPE SR_C(1e-3)
#define PREDICT_DT SR_C(0.005)
#define TORQUE_PROBE SR_C(1e-3)
#define MASS_PROBE SR_C(1e-3)
#define CENTRE_PROBE SR_C(1e-4)
#define MASS_SCALE SR_C(0.1)
#define CENTRE_SCALE SR_C(0.01)
#define DAMPING_PROBE SR_C(1e-4)
#define DAMPING_SCALE SR_C(0.01)
/* cos and sin of -pi/2 as libm gives them for the double nearest -pi/2 (Python's math.cos, math.sin) */
#define COS_MINUS_PI_HALF SR_C(6.123233995736766e-17)
#define SIN_MINUS_PI_HALF SR_C(-1.0)
#ifdef SR_USE_FLOAT
#define SLOPE_CEIL ceilf
#define SLOPE_EXP expf
#else
#define SLOPE_CEIL ceil
#define SLOPE_EXP exp
#endif

/* The model's parameters p (slope 0) with the estimate's model k moved: -1 the probe slope, 0 m_P
 * (relative step), 1..3 c_P x, y, z (metres), 4 k_P (absolute); *step and *scale of its column. */
static void moved_params(const sr_real p[SR_NPARAM], int k, sr_real moved[SR_NPARAM], sr_real *step, sr_real *scale)
{
    memcpy(moved, p, SR_NPARAM * sizeof *p);
    *step = *scale = 1;
    if (k < 0) {
        moved[SR_P_slope] = PROBE_SLOPE;
    } else if (k == 0) {
        moved[SR_P_m_P] = p[SR_P_m_P] * (1 + MASS_PROBE);
        *step = MASS_PROBE * p[SR_P_m_P];
        *scale = MASS_SCALE * p[SR_P_m_P];
    } else if (k < 4) {
        moved[SR_P_c_P_x + k - 1] = p[SR_P_c_P_x + k - 1] + CENTRE_PROBE;
        *step = CENTRE_PROBE;
        *scale = CENTRE_SCALE;
    } else {
        moved[SR_P_k_P] = p[SR_P_k_P] + DAMPING_PROBE;
        *step = DAMPING_PROBE;
        *scale = DAMPING_SCALE;
    }
}

int sr_slope_init(sr_slope_estimator *est, const sr_real params[SR_NPARAM], sr_real period, sr_real time_constant)
{
    sr_real p[SR_NPARAM], moved[SR_NPARAM], steps, step, scale;
    sr_model probe;     /* each model tried here first: *est is written only when all of them are valid */
    int k, status;
    if (!est || !params) return SR_ERR_NULL;
    if (!all_finite(params, SR_NPARAM) || !all_finite(&period, 1) || !all_finite(&time_constant, 1))
        return SR_ERR_NONFINITE;
    if (!(period > 0) || !(time_constant > 0)) return SR_ERR_ARG;
    steps = SLOPE_CEIL(period / PREDICT_DT - SR_C(1e-9));
    if (steps > SR_SLOPE_MAX_STEPS) return SR_ERR_ARG;
    memcpy(p, params, sizeof p);
    p[SR_P_slope] = 0;
    status = sr_model_init(&probe, p);
    for (k = -1; k < NM && status == SR_OK; ++k) {
        moved_params(p, k, moved, &step, &scale);
        status = sr_model_init(&probe, moved);
    }
    if (status != SR_OK) return status;
    memset(est, 0, sizeof *est);
    est->steps = steps < 1 ? 1 : (int)steps;
    est->period = period;
    est->forget = SLOPE_EXP(-period / time_constant);
    sr_model_init(&est->flat, p);
    moved_params(p, -1, moved, &step, &scale);
    sr_model_init(&est->sloped, moved);
    for (k = 0; k < NM; ++k) {
        moved_params(p, k, moved, &step, &scale);
        est->factor[k] = scale / step;
        est->scale[k] = scale;
        sr_model_init(&est->moved[k], moved);
    }
    return SR_OK;
}

int sr_slope_reset(sr_slope_estimator *est)
{
    if (!est) return SR_ERR_NULL;
    memset(est->normal, 0, sizeof est->normal);
    memset(est->rhs, 0, sizeof est->rhs);
    memset(&est->offsets, 0, sizeof est->offsets);
    est->pendulum_damping = 0;
    est->started = 0;
    memset(est->variance_sum, 0, sizeof est->variance_sum);
    est->variance_count = 0;
    memset(est->theta, 0, sizeof est->theta);
    return SR_OK;
}

int sr_slope_weigh(sr_slope_estimator *est, sr_real prior_scale)
{
    /* the prior's standard deviations in theta's units (runtime/control/slope.py's PRIOR_SD): 5 mrad,
     * 0.05 N m, 20 % of m_P (2 tenths), 1 cm (CENTRE_SCALE), 0.01 N m s (DAMPING_SCALE) */
    const sr_real sd[NT] = {SR_C(5e-3), SR_C(5e-3), SR_C(0.05), SR_C(0.05), 2, 1, 1, 1, 1};
    int k;
    if (!est) return SR_ERR_NULL;
    if (!all_finite(&prior_scale, 1)) return SR_ERR_NONFINITE;
    if (!(prior_scale >= 0)) return SR_ERR_ARG;
    for (k = 0; k < NT; ++k) {
        const sr_real s = prior_scale * sd[k];
        est->prior_precision[k] = prior_scale > 0 ? 1 / (s * s) : 0;
    }
    return SR_OK;
}

/* The rates nu (SR_NV) one period after x under the torques u held, by the model's RKMK4 in
 * est->steps steps (sr_simulate: what the Python estimator's Model.simulate runs). */
static int rates(sr_slope_estimator *est, const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                 sr_real nu[SR_NV])
{
    sr_real held[SR_SLOPE_MAX_STEPS * SR_NU];
    int n, status;
    for (n = 0; n < est->steps; ++n) memcpy(held + n * SR_NU, u, SR_NU * sizeof *u);
    status = sr_simulate(model, SR_RKMK4, x, est->period / est->steps, est->steps, held, est->work, NULL);
    if (status != SR_OK) return status;
    memcpy(nu, est->work + est->steps * SR_NX + SR_X_w_S, SR_NV * sizeof *nu);
    return SR_OK;
}

/* The 2-norm condition number of the symmetric n x n matrix a (row stride NT): the ratio of its
 * largest to its smallest eigenvalue in magnitude (np.linalg.cond's singular values), the eigenvalues by
 * cyclic Jacobi rotations with the relative threshold of Demmel and Veselic (a rotation only where
 * |a_pq| > eps sqrt(|a_pp a_qq|)), which leaves the small eigenvalues of a scaled positive definite
 * matrix accurate to their own size.  Infinite when the smallest is 0 or a sweep limit is reached
 * first (not seen: 9 x 9 converges in under 10 sweeps). */
static sr_real condition(const sr_real *a, int n)
{
    sr_real m[NT * NT], lo, hi;
    int sweep, p, q, k, rotated = 1;
    for (p = 0; p < n; ++p)
        for (q = 0; q < n; ++q) m[p * NT + q] = a[p * NT + q];
    for (sweep = 0; sweep < 60 && rotated; ++sweep) {
        rotated = 0;
        for (p = 0; p < n - 1; ++p)
            for (q = p + 1; q < n; ++q) {
                const sr_real apq = m[p * NT + q], app = m[p * NT + p], aqq = m[q * NT + q];
                sr_real theta, t, c, s;
                if (!(SR_FABS(apq) > SR_EPSILON * SR_SQRT(SR_FABS(app * aqq)))) continue;
                rotated = 1;
                theta = (aqq - app) / (2 * apq);
                t = SR_FABS(theta) * SR_EPSILON > 1 ? 1 / (2 * theta)
                  : (theta >= 0 ? 1 : -1) / (SR_FABS(theta) + SR_SQRT(1 + theta * theta));
                c = 1 / SR_SQRT(1 + t * t);
                s = t * c;
                for (k = 0; k < n; ++k) {       /* columns p, q */
                    const sr_real kp = m[k * NT + p], kq = m[k * NT + q];
                    m[k * NT + p] = c * kp - s * kq;
                    m[k * NT + q] = s * kp + c * kq;
                }
                for (k = 0; k < n; ++k) {       /* rows p, q */
                    const sr_real pk = m[p * NT + k], qk = m[q * NT + k];
                    m[p * NT + k] = c * pk - s * qk;
                    m[q * NT + k] = s * pk + c * qk;
                }
                m[p * NT + q] = m[q * NT + p] = 0;
            }
    }
    if (rotated) return (sr_real)HUGE_VAL;
    lo = hi = SR_FABS(m[0]);
    for (p = 1; p < n; ++p) {
        const sr_real v = SR_FABS(m[p * NT + p]);
        lo = v < lo ? v : lo;
        hi = v > hi ? v : hi;
    }
    return lo > 0 ? hi / lo : (sr_real)HUGE_VAL;
}

/* x (n) solving the n x n system a x = b (row stride NT) by Gaussian elimination with partial
 * pivoting (LAPACK's dgesv, which np.linalg.solve calls, pivots so). */
static void solve(const sr_real *a, const sr_real *b, int n, sr_real *x)
{
    sr_real m[NT * NT], r[NT];
    int i, j, k;
    for (i = 0; i < n; ++i) {
        for (j = 0; j < n; ++j) m[i * NT + j] = a[i * NT + j];
        r[i] = b[i];
    }
    for (k = 0; k < n; ++k) {
        int pivot = k;
        for (i = k + 1; i < n; ++i)
            if (SR_FABS(m[i * NT + k]) > SR_FABS(m[pivot * NT + k])) pivot = i;
        if (pivot != k) {
            sr_real t;
            for (j = 0; j < n; ++j) {
                t = m[k * NT + j];
                m[k * NT + j] = m[pivot * NT + j];
                m[pivot * NT + j] = t;
            }
            t = r[k];
            r[k] = r[pivot];
            r[pivot] = t;
        }
        for (i = k + 1; i < n; ++i) {
            const sr_real f = m[i * NT + k] / m[k * NT + k];
            for (j = k + 1; j < n; ++j) m[i * NT + j] -= f * m[k * NT + j];
            r[i] -= f * r[k];
        }
    }
    for (i = n - 1; i >= 0; --i) {
        sr_real s = r[i];
        for (j = i + 1; j < n; ++j) s -= m[i * NT + j] * x[j];
        x[i] = s / m[i * NT + i];
    }
}

/* The outputs from theta (scaled units). */
static void set_estimate(sr_slope_estimator *est, const sr_real theta[NT])
{
    int k;
    for (k = 0; k < 2; ++k) {
        est->offsets.slope[k] = theta[k];
        est->offsets.torque_offset[k] = theta[2 + k];
    }
    for (k = 0; k < SR_LQR_NPENDULUM; ++k) est->offsets.pendulum[k] = theta[4 + k] * est->scale[k];
    est->pendulum_damping = theta[8] * est->scale[4];
}

int sr_slope_update(sr_slope_estimator *est, const sr_real x[SR_NX], const sr_real u[SR_NU])
{
    sr_real G[SR_NV][NT], flat[SR_NV], nu[SR_NV], turned[SR_NX], normal[NT * NT], rhs[NT], theta[NT], probe[SR_NU];
    sr_real residual[SR_NV], variance_sum[SR_NV], variance_count = 0;
    int i, j, k, status, weighted = 0;
    if (!est || !x || !u) return SR_ERR_NULL;
    if (!all_finite(u, SR_NU)) return SR_ERR_NONFINITE;
    status = sr_check_state(&est->flat, x);
    if (status != SR_OK) return status;
    if (!est->started) {
        memcpy(est->last, x, sizeof est->last);
        est->started = 1;
        return SR_OK;
    }
    status = rates(est, &est->flat, est->last, u, flat);
    /* column 0: a slope along the world's x (the model's); 1: along y, the model's with the world turned by -pi/2 */
    if (status == SR_OK) status = rates(est, &est->sloped, est->last, u, nu);
    for (i = 0; i < SR_NV && status == SR_OK; ++i) G[i][0] = (nu[i] - flat[i]) / PROBE_SLOPE;
    if (status == SR_OK) {
        const sr_real c = COS_MINUS_PI_HALF, s = SIN_MINUS_PI_HALF;
        const sr_real turn[9] = {c, -s, 0, s, c, 0, 0, 0, 1};
        memcpy(turned, est->last, sizeof turned);
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j)
                turned[SR_X_R_S + 3 * i + j] = turn[3 * i] * est->last[SR_X_R_S + j]
                    + turn[3 * i + 1] * est->last[SR_X_R_S + 3 + j] + turn[3 * i + 2] * est->last[SR_X_R_S + 6 + j];
        turned[SR_X_q] = c * est->last[SR_X_q] - s * est->last[SR_X_q + 1];
        turned[SR_X_q + 1] = s * est->last[SR_X_q] + c * est->last[SR_X_q + 1];
        status = rates(est, &est->sloped, turned, u, nu);
    }
    for (i = 0; i < SR_NV && status == SR_OK; ++i) G[i][1] = (nu[i] - flat[i]) / PROBE_SLOPE;
    /* columns 2, 3: the torques; 4..: the pendulum's parameters, scaled */
    for (k = 0; k < SR_NU && status == SR_OK; ++k) {
        probe[0] = u[0] + (k == 0 ? TORQUE_PROBE : 0);
        probe[1] = u[1] + (k == 1 ? TORQUE_PROBE : 0);
        status = rates(est, &est->flat, est->last, probe, nu);
        for (i = 0; i < SR_NV && status == SR_OK; ++i) G[i][2 + k] = (nu[i] - flat[i]) / TORQUE_PROBE;
    }
    for (k = 0; k < NM && status == SR_OK; ++k) {
        status = rates(est, &est->moved[k], est->last, u, nu);
        for (i = 0; i < SR_NV && status == SR_OK; ++i) G[i][4 + k] = (nu[i] - flat[i]) * est->factor[k];
    }
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NV; ++i) residual[i] = x[SR_X_w_S + i] - flat[i];
    for (k = 0; k < NT; ++k) weighted |= est->prior_precision[k] > 0;
    if (weighted) {
        /* each rate's row over the root of its prediction error's forgotten variance */
        variance_count = est->forget * est->variance_count + 1;
        for (i = 0; i < SR_NV; ++i) {
            sr_real e = residual[i], w;
            for (k = 0; k < NT; ++k) e -= G[i][k] * est->theta[k];
            variance_sum[i] = est->forget * est->variance_sum[i] + e * e;
            w = variance_sum[i] / variance_count;
            w = 1 / SR_SQRT(w > (sr_real)SR_SLOPE_VARIANCE_FLOOR ? w : (sr_real)SR_SLOPE_VARIANCE_FLOOR);
            for (k = 0; k < NT; ++k) G[i][k] *= w;
            residual[i] *= w;
        }
    }
    /* the normal equations, forgetting the old samples */
    for (j = 0; j < NT; ++j) {
        sr_real acc = 0;
        for (k = 0; k < NT; ++k) {
            sr_real gg = 0;
            for (i = 0; i < SR_NV; ++i) gg += G[i][j] * G[i][k];
            normal[j * NT + k] = est->forget * est->normal[j * NT + k] + gg;
        }
        for (i = 0; i < SR_NV; ++i) acc += G[i][j] * residual[i];
        rhs[j] = est->forget * est->rhs[j] + acc;
    }
    if (!all_finite(normal, NT * NT) || !all_finite(rhs, NT)) return SR_ERR_NONFINITE;
    memcpy(est->normal, normal, sizeof normal);
    memcpy(est->rhs, rhs, sizeof rhs);
    memcpy(est->last, x, sizeof est->last);
    if (weighted) {
        /* the prior makes N + P positive definite: solved at every sample */
        sr_real posterior[NT * NT];
        memcpy(est->variance_sum, variance_sum, sizeof variance_sum);
        est->variance_count = variance_count;
        memcpy(posterior, normal, sizeof posterior);
        for (k = 0; k < NT; ++k) posterior[k * NT + k] += est->prior_precision[k];
        solve(posterior, rhs, NT, theta);
        if (!all_finite(theta, NT)) return SR_OK;
        memcpy(est->theta, theta, sizeof theta);
        set_estimate(est, theta);
    } else if (condition(normal, NT) < (sr_real)SR_SLOPE_COND_LIMIT) {
        solve(normal, rhs, NT, theta);
        if (!all_finite(theta, NT)) return SR_OK;
        set_estimate(est, theta);
    } else if (condition(normal, 4) < (sr_real)SR_SLOPE_COND_LIMIT) {
        /* Until the samples tell the pendulum from the slope and d: those alone, the pendulum held. */
        sr_real held[4];
        for (j = 0; j < 4; ++j) {
            sr_real acc = 0;
            for (k = 0; k < NM; ++k)
                acc += normal[j * NT + 4 + k] * ((k < 4 ? est->offsets.pendulum[k] : est->pendulum_damping) / est->scale[k]);
            held[j] = rhs[j] - acc;
        }
        solve(normal, held, 4, theta);
        if (!all_finite(theta, 4)) return SR_OK;
        for (k = 0; k < 2; ++k) {
            est->offsets.slope[k] = theta[k];
            est->offsets.torque_offset[k] = theta[2 + k];
        }
    }
    return SR_OK;
}
