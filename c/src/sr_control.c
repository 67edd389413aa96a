/*
 * sr_control.c -- the firmware controller: LQR gain-scheduled on speed and curvature.
 * The law, its coordinates and its design are described in spherical_robot.h and
 * docs/control.md; the schedule comes from runtime/control/lqr_design.py.
 */
#include "sr_checks.h"
#include "sr_control.h"
#include "sr_so3.h"
#include "sr_argcheck.h"

#include <string.h>

/* z[SR_LQR_Z_INTEGRALS..] are the integrators: their gains are K_path's at any tight weight. */
#define SR_LQR_Z_INTEGRALS 10

static int valid_sizes(const sr_lqr *lqr)
{
    return lqr->n_speeds >= 1 && lqr->n_speeds <= SR_LQR_MAX_SPEEDS && lqr->n_curvatures >= 1
        && lqr->n_curvatures <= SR_LQR_MAX_CURVATURES && lqr->period > 0 && lqr->u_max > 0
        && lqr->kappa_rate >= 0 && lqr->steady_rate >= 0 && lqr->tight_band >= 0
        && (lqr->tight_band == 0 || lqr->tight_rise > 0) && lqr->world_share >= 0 && lqr->world_share <= 1
        && lqr->tight_fall >= 0 && lqr->tight_wait >= 0 && lqr->tight_wait <= 1 && lqr->heading_band >= 0
        && (lqr->heading_band == 0 || lqr->heading_rise > 0) && lqr->recovery_cross_track >= 0
        && lqr->recovery_heading >= 0 && lqr->recovery_slow >= 0 && lqr->recovery_slow < 1
        && (lqr->recovery_slow == 0 || lqr->recovery_rise > 0) && lqr->pendulum_share >= 0 && lqr->pendulum_share <= 1;
}

int sr_lqr_check(const sr_lqr *lqr)
{
    int i, n;
    if (!lqr) return SR_ERR_NULL;
    if (!all_finite(&lqr->period, 1) || !all_finite(&lqr->u_max, 1) || !all_finite(&lqr->kappa_rate, 1)
        || !all_finite(&lqr->steady_rate, 1) || !all_finite(&lqr->tight_band, 1) || !all_finite(&lqr->tight_rise, 1)
        || !all_finite(&lqr->tight_fall, 1) || !all_finite(&lqr->tight_wait, 1)
        || !all_finite(&lqr->world_share, 1) || !all_finite(&lqr->heading_band, 1) || !all_finite(&lqr->heading_rise, 1)
        || !all_finite(&lqr->recovery_cross_track, 1) || !all_finite(&lqr->recovery_heading, 1)
        || !all_finite(&lqr->recovery_slow, 1) || !all_finite(&lqr->recovery_rise, 1)
        || !all_finite(&lqr->pendulum_share, 1))
        return SR_ERR_NONFINITE;
    if (!valid_sizes(lqr)) return SR_ERR_ARG;
    n = lqr->n_speeds * lqr->n_curvatures;
    if (!all_finite(lqr->speeds, lqr->n_speeds) || !all_finite(lqr->curvatures, lqr->n_curvatures))
        return SR_ERR_NONFINITE;
    for (i = 0; i < n; ++i)
        if (!all_finite(lqr->z_star[i], SR_LQR_NZ) || !all_finite(lqr->u_star[i], SR_NU)
            || !all_finite(lqr->K_path[i], SR_NU * SR_LQR_NZ) || !all_finite(lqr->K_heading[i], SR_NU * SR_LQR_NZ)
            || (lqr->tight_band > 0 && !all_finite(lqr->K_tight[i], SR_NU * SR_LQR_NZ))
            || (lqr->heading_band > 0 && !all_finite(lqr->K_heading_tight[i], SR_NU * SR_LQR_NZ))
            || (lqr->slope && (!all_finite(lqr->slope->dz_up[i], SR_LQR_NZ) || !all_finite(lqr->slope->du_up[i], SR_NU)
                               || !all_finite(lqr->slope->dz_right[i], SR_LQR_NZ)
                               || !all_finite(lqr->slope->du_right[i], SR_NU)))
            || (lqr->pendulum && (!all_finite(lqr->pendulum->dz[i][0], SR_LQR_NPENDULUM * SR_LQR_NZ)
                                  || !all_finite(lqr->pendulum->du[i][0], SR_LQR_NPENDULUM * SR_NU))))
            return SR_ERR_NONFINITE;
    for (i = 1; i < lqr->n_speeds; ++i)
        if (!(lqr->speeds[i] > lqr->speeds[i - 1])) return SR_ERR_ARG;
    for (i = 1; i < lqr->n_curvatures; ++i)
        if (!(lqr->curvatures[i] > lqr->curvatures[i - 1])) return SR_ERR_ARG;
    return SR_OK;
}

int sr_lqr_reset(sr_lqr_memory *memory)
{
    if (!memory) return SR_ERR_NULL;
    memset(memory, 0, sizeof *memory);
    return SR_OK;
}

static int valid_target(const sr_lqr_target *target)
{
    return all_finite(&target->speed, 1) && all_finite(&target->heading, 1)
        && (!target->path || (all_finite(&target->curvature, 1) && all_finite(&target->cross_track, 1)));
}

/* z without checks (see sr_lqr_error). */
static void error_coordinates(const sr_model *model, const sr_real x[SR_NX], const sr_lqr_target *target,
                              const sr_real integrals[2], sr_real z[SR_LQR_NZ])
{
    const sr_real *R_Y = x + SR_X_R_Y, *R_P = x + SR_X_R_P, *w_S = x + SR_X_w_S;
    const sr_real rate = target->speed / model->p[SR_P_r];
    /* Q_ref = rot_z(psi - pi/2) = [[sin psi, cos psi, 0], [-cos psi, sin psi, 0], [0, 0, 1]]. */
    const sr_real s = SR_SIN(target->heading), c = SR_COS(target->heading);
    sr_real Q[9], M[9];
    int j;
    matmul3(x + SR_X_R_S, R_Y, Q);
    for (j = 0; j < 3; ++j) { /* M = Q_ref^T Q */
        M[j] = s * Q[j] - c * Q[3 + j];
        M[3 + j] = c * Q[j] + s * Q[3 + j];
        M[6 + j] = Q[6 + j];
    }
    so3_log(M, z);
    z[3] = SR_ATAN2(R_P[2], R_P[0]); /* R_P = rot_y(theta_P): R_P[0][2] = sin, R_P[0][0] = cos */
    for (j = 0; j < 3; ++j) /* R_Y^T w_S */
        z[4 + j] = R_Y[j] * w_S[0] + R_Y[3 + j] * w_S[1] + R_Y[6 + j] * w_S[2];
    z[4] += rate;
    z[7] = x[SR_X_w_Y] - rate;
    z[8] = x[SR_X_w_P];
    z[9] = target->path ? target->cross_track : 0;
    z[10] = integrals ? integrals[0] : 0;
    z[11] = integrals ? integrals[1] : 0;
}

int sr_lqr_error(const sr_model *model, const sr_real x[SR_NX], const sr_lqr_target *target,
                 const sr_real integrals[2], sr_real z[SR_LQR_NZ])
{
    sr_real tmp[SR_LQR_NZ];
    int status = arg_model(model, READS(STATE));
    if (status != SR_OK) return status;
    if (!x || !target || !z) return SR_ERR_NULL;
    status = sr_internal_check_state(model, x);
    if (status != SR_OK) return status;
    if (!valid_target(target) || (integrals && !all_finite(integrals, 2))) return SR_ERR_NONFINITE;
    error_coordinates(model, x, target, integrals, tmp);
    return deliver(SR_OK, tmp, SR_LQR_NZ, z);
}

/* The grid interval [*lo, *hi] around value and its weight in it, clamped to the grid. */
static void bracket(const sr_real *grid, int n, sr_real value, int *lo, int *hi, sr_real *w)
{
    int i = 0;
    if (n == 1) {
        *lo = *hi = 0;
        *w = 0;
        return;
    }
    while (i < n - 2 && value > grid[i + 1]) ++i;
    *lo = i;
    *hi = i + 1;
    *w = (value - grid[i]) / (grid[i + 1] - grid[i]);
    *w = *w < 0 ? 0 : (*w > 1 ? 1 : *w);
}

/* The grid's four points around (v, kappa) and their weights, in the order of the law. */
static void grid_points(const sr_lqr *lqr, sr_real v, sr_real kappa, int point[4], sr_real weight[4])
{
    int i0, i1, j0, j1, n = lqr->n_curvatures;
    sr_real wv, wk;
    bracket(lqr->speeds, lqr->n_speeds, v, &i0, &i1, &wv);
    bracket(lqr->curvatures, lqr->n_curvatures, kappa, &j0, &j1, &wk);
    point[0] = i0 * n + j0; weight[0] = (1 - wv) * (1 - wk);
    point[1] = i0 * n + j1; weight[1] = (1 - wv) * wk;
    point[2] = i1 * n + j0; weight[2] = wv * (1 - wk);
    point[3] = i1 * n + j1; weight[3] = wv * wk;
}

/* The feedforward of the offsets (see sr_lqr_control_offsets) at speed v and operating curvature
 * kappa: du + K dz of the slope's and the pendulum's moves of the operating point, less d. */
static void feedforward(const sr_lqr *lqr, const sr_lqr_offsets *offsets, const sr_lqr_target *target, sr_real v,
                        sr_real kappa, sr_real ff[SR_NU])
{
    sr_real weight[4], dz[SR_LQR_NZ], du[SR_NU], K[SR_NU][SR_LQR_NZ];
    const sr_real s = SR_SIN(target->heading), c = SR_COS(target->heading);
    const sr_real up = offsets->slope[0] * c + offsets->slope[1] * s, right = offsets->slope[0] * s - offsets->slope[1] * c;
    int point[4], i, j, k, part;
    grid_points(lqr, v, kappa, point, weight);
    for (k = 0; k < SR_NU; ++k)
        for (j = 0; j < SR_LQR_NZ; ++j) {
            K[k][j] = 0;
            for (i = 0; i < 4; ++i) K[k][j] += weight[i] * (target->path ? lqr->K_path : lqr->K_heading)[point[i]][k * SR_LQR_NZ + j];
        }
    for (k = 0; k < SR_NU; ++k) ff[k] = -offsets->torque_offset[k];
    for (part = 0; part < 2; ++part) {
        sr_real share = part == 0 ? 1 : lqr->pendulum_share;
        if (part == 0 ? !lqr->slope : !lqr->pendulum) continue;
        memset(dz, 0, sizeof dz);
        memset(du, 0, sizeof du);
        for (i = 0; i < 4; ++i) {
            const int p = point[i];
            if (part == 0) {
                for (j = 0; j < SR_LQR_NZ; ++j)
                    dz[j] += weight[i] * (up * lqr->slope->dz_up[p][j] + right * lqr->slope->dz_right[p][j]);
                for (k = 0; k < SR_NU; ++k)
                    du[k] += weight[i] * (up * lqr->slope->du_up[p][k] + right * lqr->slope->du_right[p][k]);
            } else {
                int e;
                for (e = 0; e < SR_LQR_NPENDULUM; ++e) {
                    for (j = 0; j < SR_LQR_NZ; ++j) dz[j] += weight[i] * offsets->pendulum[e] * lqr->pendulum->dz[p][e][j];
                    for (k = 0; k < SR_NU; ++k) du[k] += weight[i] * offsets->pendulum[e] * lqr->pendulum->du[p][e][k];
                }
            }
        }
        for (k = 0; k < SR_NU; ++k) {
            sr_real kdz = 0;
            for (j = 0; j < SR_LQR_NZ; ++j) kdz += K[k][j] * dz[j];
            ff[k] += share * (du[k] + kdz);
        }
    }
}

int sr_lqr_control(const sr_lqr *lqr, const sr_model *model, const sr_real x[SR_NX],
                   const sr_lqr_target *target, sr_lqr_memory *memory, sr_real u[SR_NU],
                   sr_real u_raw[SR_NU])
{
    return sr_lqr_control_offsets(lqr, model, x, target, NULL, memory, u, u_raw);
}

int sr_lqr_control_offsets(const sr_lqr *lqr, const sr_model *model, const sr_real x[SR_NX],
                           const sr_lqr_target *target, const sr_lqr_offsets *offsets, sr_lqr_memory *memory,
                           sr_real u[SR_NU], sr_real u_raw[SR_NU])
{
    const sr_lqr_target *reference = target;
    sr_real z[SR_LQR_NZ], dz[SR_LQR_NZ], out[SR_NU], raw[SR_NU], ff[SR_NU], ff_out[SR_NU], kappa, step;
    sr_real weight[4], k_int[SR_NU][2], step_int[2], tight = 0, normal[2], integrals[2], band, recovery;
    sr_lqr_target slowed;
    int status = arg_model(model, READS(STATE)), i0, k, j, point[4], clipped = 0, recovering = 0;
    if (status != SR_OK) return status;
    if (!lqr || !x || !target || !memory || !u) return SR_ERR_NULL;
    if (!valid_sizes(lqr)) return SR_ERR_ARG;
    status = sr_internal_check_state(model, x);
    if (status != SR_OK) return status;
    if (!valid_target(target) || !all_finite(memory->integrals, 2) || !all_finite(&memory->kappa, 1)
        || !all_finite(&memory->tight, 1) || !all_finite(memory->world, 2) || !all_finite(&memory->recovery, 1)
        || (offsets && (!all_finite(offsets->slope, 2) || !all_finite(offsets->torque_offset, 2)
                        || !all_finite(offsets->pendulum, SR_LQR_NPENDULUM))))
        return SR_ERR_NONFINITE;

    /* Recovery: the speed reference lowered by the weight of the samples before (0 unless recovery_slow > 0). */
    slowed = *target;
    slowed.speed = target->speed * (1 - lqr->recovery_slow * memory->recovery);
    target = &slowed;

    /* The operating point's curvature follows the reference's at a bounded rate. */
    kappa = target->path ? target->curvature : 0;
    if (memory->started) {
        step = lqr->kappa_rate * lqr->period;
        kappa = kappa - memory->kappa > step ? memory->kappa + step
              : (kappa - memory->kappa < -step ? memory->kappa - step : kappa);
    }
    grid_points(lqr, target->speed, kappa, point, weight);

    /* z[10] reads the world part along the path's left normal (-sin psi, cos psi): a pull fixed in
     * the world (a slope) turns against a turning path, and only a world vector can hold it. */
    normal[0] = -SR_SIN(target->heading);
    normal[1] = SR_COS(target->heading);
    integrals[0] = memory->integrals[0] + (target->path ? normal[0] * memory->world[0] + normal[1] * memory->world[1] : 0);
    integrals[1] = memory->integrals[1];
    error_coordinates(model, x, target, integrals, z);
    for (j = 0; j < SR_LQR_NZ; ++j)
        dz[j] = z[j] - (weight[0] * lqr->z_star[point[0]][j] + weight[1] * lqr->z_star[point[1]][j]
                        + weight[2] * lqr->z_star[point[2]][j] + weight[3] * lqr->z_star[point[3]][j]);
    /* Recovery: the cross-track and heading errors the law acts on clipped to their bounds; beyond
     * either the robot is recovering (below: no tight gains, no integration, the speed lowered). */
    if (target->path && lqr->recovery_cross_track > 0 && SR_FABS(dz[9]) > lqr->recovery_cross_track) {
        dz[9] = dz[9] > 0 ? lqr->recovery_cross_track : -lqr->recovery_cross_track;
        recovering = 1;
    }
    if (lqr->recovery_heading > 0 && SR_FABS(dz[2]) > lqr->recovery_heading) {
        dz[2] = dz[2] > 0 ? lqr->recovery_heading : -lqr->recovery_heading;
        recovering = 1;
    }
    /* The tight gains' weight: bounded by how near the path the robot is, rising slowly (a transient
     * must have died down) and falling after a clipped torque, below 0 (K_path's gain, a wait before
     * the tight gains return): held at the limits, they switch the steering torque between them. */
    /* On a heading reference the same with the heading error z[2] against heading_band. */
    band = target->path ? lqr->tight_band : lqr->heading_band;
    if (band > 0) {
        sr_real bound = 1 - SR_FABS(dz[target->path ? 9 : 2]) / band, prev = memory->tight;
        sr_real rise = !memory->saturated ? prev + lqr->period / (target->path ? lqr->tight_rise : lqr->heading_rise)
                     : (lqr->tight_fall > 0 ? prev - lqr->period / lqr->tight_fall : prev);
        bound = bound < 0 || recovering ? 0 : bound;
        tight = rise < bound ? rise : bound;
        tight = tight > 1 ? 1 : (tight < -lqr->tight_wait ? -lqr->tight_wait : tight);
    }
    for (k = 0; k < SR_NU; ++k) {
        sr_real acc = 0;
        k_int[k][0] = k_int[k][1] = 0;
        for (i0 = 0; i0 < 4; ++i0) {
            const sr_real *K = (target->path ? lqr->K_path : lqr->K_heading)[point[i0]] + k * SR_LQR_NZ;
            const sr_real *T = (target->path ? lqr->K_tight : lqr->K_heading_tight)[point[i0]] + k * SR_LQR_NZ;
            sr_real kdz = 0;
            for (j = 0; j < SR_LQR_NZ; ++j) kdz += K[j] * dz[j];
            if (tight > 0)
                for (j = 0; j < SR_LQR_Z_INTEGRALS; ++j) kdz += tight * (T[j] - K[j]) * dz[j];
            acc += weight[i0] * (lqr->u_star[point[i0]][k] - kdz);
            k_int[k][0] += weight[i0] * K[10];
            k_int[k][1] += weight[i0] * K[11];
        }
        raw[k] = acc;
        out[k] = acc > lqr->u_max ? lqr->u_max : (acc < -lqr->u_max ? -lqr->u_max : acc);
        clipped |= out[k] != acc;
    }
    if (offsets) {      /* the feedforward, after the law's limits (see spherical_robot.h) */
        feedforward(lqr, offsets, reference, reference->speed, target->path ? kappa : 0, ff);
        for (k = 0; k < SR_NU; ++k) {
            ff[k] += raw[k];
            ff_out[k] = ff[k] > lqr->u_max ? lqr->u_max : (ff[k] < -lqr->u_max ? -lqr->u_max : ff[k]);
        }
        if (!all_finite(ff, SR_NU)) return SR_ERR_NONFINITE;
    }
    if (!all_finite(raw, SR_NU)) return SR_ERR_NONFINITE;

    /* Conditional integration: an integrator advances at any error unless its step would push a
     * clipped torque further past its limit (the step s_i changes u[k] by -K[k][10 + i] s_i), and
     * the cross-track integral only while the error is steady, |de_y/dt| <= steady_rate: an error
     * that moves is a transient (a start off the path, the first lean into a turn) that the loop
     * is already removing, and integrating it would force an overshoot of equal area later. */
    step_int[0] = target->path ? lqr->period * dz[9] : 0;
    step_int[1] = lqr->period * dz[4];
    for (j = 0; j < 2; ++j) {
        int advance = !recovering && (j == 1 || SR_FABS(cross_track_rate(model, x, target->heading)) <= lqr->steady_rate);
        for (k = 0; k < SR_NU; ++k)
            if (out[k] != raw[k] && -k_int[k][j] * step_int[j] * (raw[k] - out[k]) > 0) advance = 0;
        if (!advance) continue;
        if (j == 0) {       /* split between the path's and the world's part: together they move z[10] by the step */
            memory->integrals[0] += (1 - lqr->world_share) * step_int[0];
            memory->world[0] += lqr->world_share * step_int[0] * normal[0];
            memory->world[1] += lqr->world_share * step_int[0] * normal[1];
        } else {
            memory->integrals[1] += step_int[1];
        }
    }
    recovery = memory->recovery;
    if (lqr->recovery_slow > 0) {
        recovery += (recovering ? 1 : -1) * lqr->period / lqr->recovery_rise;
        recovery = recovery > 1 ? 1 : (recovery < 0 ? 0 : recovery);
    }
    memory->recovery = recovery;
    memory->kappa = kappa;
    memory->started = 1;
    memory->saturated = clipped;
    memory->tight = tight;
    memcpy(u, offsets ? ff_out : out, sizeof out);
    if (u_raw) memcpy(u_raw, offsets ? ff : raw, sizeof raw);
    return SR_OK;
}
