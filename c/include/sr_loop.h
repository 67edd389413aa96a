/**
 * sr_loop.h -- a whole closed loop on sensors in C: a path reference (the nearest point, its
 * tangent, curvature and signed cross-track error, the curvature ahead), and the LQR (sr_lqr_control)
 * closed on the filter of a simulated run (sr_sim_advance), sample after sample.
 *
 * A path is a polyline sampled every few millimetres (runtime/control/reference.py builds it; its
 * samples' arc lengths, tangent headings and curvatures come with it).  The nearest sample to a
 * position is searched in the arc-length window [s_hint - search_back, s_hint + search_ahead]
 * around the last match (the hint), so that a figure eight's crossing does not make it jump to the
 * other lobe; the first of equally near samples wins.  The cross-track error is the position's
 * offset from that sample along the tangent's left normal (-sin psi, cos psi).  The curvature at a
 * distance d ahead is the path's curvature interpolated linearly in arc length at s_hint + d, held at
 * the ends.
 *
 * One controller sample k of sr_loop_lqr, at t = k period: the filter is predicted to t under the
 * torques held since the last sample (when t is past its time), the target is read at the estimate's
 * position, the operating curvature is the mean of the path's curvature at the preview distances
 * (or the nearest sample's when there are none), the slope estimate (when given) takes the estimate
 * and the torques held since the last sample (sr_slope_update), sr_lqr_control_offsets gives the
 * torques (with the estimate's offsets, or the fixed ones, or none: sr_lqr_control), and the run
 * advances the controller's period (sr_sim_advance) under them.  This is the order of
 * runtime/control/closed_loop.py's Python loop, which stays the reference.
 *
 * Self-contained C99: no dynamic allocation, no globals; the caller owns every buffer.
 * @file
 */
#ifndef SR_LOOP_H
#define SR_LOOP_H

#include "spherical_robot.h"
#include "sr_sim.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef SR_USE_FLOAT
#define sr_path sr_path_f
#define sr_path_check sr_path_check_f
#define sr_path_target sr_path_target_f
#define sr_path_curvature_ahead sr_path_curvature_ahead_f
#define sr_path_cross_track sr_path_cross_track_f
#define sr_loop_lqr sr_loop_lqr_f
#endif

/** @name Where sr_loop_lqr stopped on an error (its *failed_in) */
/** @{ */
#define SR_LOOP_OK 0           /**< no error */
#define SR_LOOP_FILTER 1       /**< the filter's prediction to the controller's sample */
#define SR_LOOP_CONTROL 2      /**< the path or the controller (sr_path_target, sr_lqr_control) */
#define SR_LOOP_SIM 3          /**< the plant, its sensors or the filter's updates (sr_sim_advance) */
/** @} */

/** A path reference: n samples of a polyline with their arc lengths, tangents and curvatures. */
typedef struct sr_path {
    long n;                    /**< samples, >= 2 */
    const sr_real *points;     /**< n x 2 positions [m] */
    const sr_real *s;          /**< n arc lengths [m], strictly increasing */
    const sr_real *tangent;    /**< n tangent headings [rad] */
    const sr_real *curvature;  /**< n curvatures [1/m], left positive */
    sr_real speed;             /**< the speed to hold along the path [m/s] */
    sr_real search_back;       /**< the arc length searched behind the hint [m], >= 0 */
    sr_real search_ahead;      /**< ... and ahead of it [m], >= 0 */
    long hint;                 /**< the last nearest sample (0 at the start), written by sr_path_target */
} sr_path;

/** Checks a path: SR_ERR_NULL (path or an array), SR_ERR_ARG (n < 2, hint out of 0..n-1, arc lengths
 * not strictly increasing, a negative search window), SR_ERR_NONFINITE (a non-finite entry). */
int sr_path_check(const sr_path *path);

/** The target at the sample nearest to position[2] (searched around path->hint, which it becomes):
 * target->speed, ->heading (the tangent), ->curvature, ->cross_track, ->path = 1.  Returns SR_OK,
 * SR_ERR_NULL, SR_ERR_NONFINITE (the position) or SR_ERR_ARG (a hint out of range); run
 * sr_path_check once on a path before using it. */
int sr_path_target(sr_path *path, const sr_real position[2], sr_lqr_target *target);

/** out[i] = the path's curvature at distances[i] [m] ahead of the hint's arc length, i < n
 * (n >= 0).  Returns SR_OK, SR_ERR_NULL (with n > 0), SR_ERR_ARG (n < 0, a hint out of range) or
 * SR_ERR_NONFINITE (a distance). */
int sr_path_curvature_ahead(const sr_path *path, const sr_real *distances, int n, sr_real *out);

/** The signed cross-track errors out[i] of n positions (rows of positions, stride >= 2 numbers apart,
 * x and y first), matched in order: each searched around the last match as sr_path_target does
 * (the first around path->hint), path->hint left at the last.  *first (may be NULL): the first
 * position's nearest sample.  Returns SR_OK, SR_ERR_NULL (with n > 0), SR_ERR_ARG (n < 0, stride < 2,
 * a hint out of range) or SR_ERR_NONFINITE (a position: out and the hint as far as it got). */
int sr_path_cross_track(sr_path *path, const sr_real *positions, long n, long stride, sr_real *out, long *first);

/** Controller samples first..first+count-1 of the LQR on the path, closed on the filter ekf of
 * the run sim (see the file's description); per plant steps per sample.  x[SR_NX]: the plant's
 * state, overwritten with the state after the last sample; u[SR_NU]: the torques held before sample
 * first (zeros at the start), overwritten with the last sample's.  preview: n_preview distances [m]
 * (NULL with 0).  Outputs (each NULL or count rows): traj (count times per) x SR_NX (the plant after
 * each step), torques count x SR_NU, estimates count x SR_NX (what the controller read), applied count
 * (the run's samples applied by the end of each controller sample).  saturated (may be NULL) is
 * increased by the samples at which a torque reached u_max within a relative 1e-9.  done: the
 * samples completed; failed_in: where an error stopped the run (SR_LOOP_*; the slope estimate's
 * errors are SR_LOOP_CONTROL's).  estimate (may be NULL): the slope estimate, updated at every
 * sample before the law, whose offsets the law feeds forward; without it, offsets (may be NULL: the
 * plain law) are fed forward at every sample (a known slope).  Returns SR_OK,
 * SR_ERR_NULL, SR_ERR_ARG (per < 1, count < 0, n_preview < 0, steps beyond the run, an invalid
 * schedule's sizes), sr_sim_check's or sr_path_check's status, or the first failing call's. */
int sr_loop_lqr(sr_sim *sim, const sr_model *plant, sr_ekf *ekf, const sr_model *model, const sr_lqr *lqr,
                sr_lqr_memory *memory, sr_slope_estimator *estimate, const sr_lqr_offsets *offsets,
                sr_path *path, const sr_real *preview, int n_preview, long per, long first,
                long count, sr_real x[SR_NX], sr_real u[SR_NU], sr_real *traj, sr_real *torques,
                sr_real *estimates, long *applied, long *saturated, long *done, int *failed_in);

#ifdef __cplusplus
}
#endif

#endif /* SR_LOOP_H */
