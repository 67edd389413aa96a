/*
 * sr_lanes.h -- the batch step's lanes (sr_step_lanes.c): one state per lane,
 * for sr_step_batch (sr_step_batch.c).
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_LANES_H
#define SR_LANES_H

#include "sr_action.h" /* SR_NT: the tangent coordinates of the lanes th */

#ifdef SR_USE_FLOAT /* float symbols carry _f, as in spherical_robot.h */
#define sr_internal_lie_euler_lanes sr_internal_lie_euler_lanes_f
#define sr_internal_act_lanes sr_internal_act_lanes_f
#define sr_internal_act2_lanes sr_internal_act2_lanes_f
#define sr_internal_field_lanes sr_internal_field_lanes_f
#endif

/* The Lie-Euler step of n states whose accelerations a are given, one lane per state, for
 * sr_step_batch (c/src/sr_step_batch.c): ok[i] = 1 where the lane's result is sr_step's, else 0. */
void sr_internal_lie_euler_lanes(sr_real r, long n, const sr_real *restrict x, long x_stride,
                                 const sr_real *restrict a, long a_stride, sr_real dt,
                                 sr_real *restrict out, long out_stride, sr_real *restrict ok);

/* The pieces of the fourth-order steps in the same form (c/src/sr_step_batch.c): x . exp(th) and
 * x . exp(th1) . exp(th2) (ok cleared past the series or for a non-finite result, else kept); the
 * vector field from given accelerations, then dexp^-1 if th is not NULL (ok likewise). */
void sr_internal_act_lanes(long n, const sr_real *restrict x, long x_stride, const sr_real *restrict th,
                           long th_stride, sr_real *restrict out, long out_stride, sr_real *restrict ok);
void sr_internal_act2_lanes(long n, const sr_real *restrict x, long x_stride, const sr_real *restrict th1,
                            const sr_real *restrict th2, long th_stride, sr_real *restrict out, long out_stride,
                            sr_real *restrict ok);
void sr_internal_field_lanes(sr_real r, long n, const sr_real *restrict y, long y_stride, const sr_real *restrict a,
                             long a_stride, const sr_real *restrict th, long th_stride, sr_real *restrict f,
                             long f_stride, sr_real *restrict ok);

#endif /* SR_LANES_H */
