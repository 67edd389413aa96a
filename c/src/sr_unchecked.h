/*
 * sr_unchecked.h -- the sensors' Jacobians and the retraction without their argument checks, for
 * callers that have checked the same arguments already (the filter checks its state, biases,
 * mount and inputs once per call; the public functions would check them again).  Internal to the
 * library: not part of the public API of spherical_robot.h, and not seen by the cffi bindings.
 */
#ifndef SR_UNCHECKED_H
#define SR_UNCHECKED_H

#include "sr_math.h"
#include "sr_sensors.h"

#ifdef SR_USE_FLOAT /* float symbols carry _f, as in spherical_robot.h */
#define sr_internal_imu_jacobian sr_internal_imu_jacobian_f
#define sr_internal_imu_jacobian_minv sr_internal_imu_jacobian_minv_f
#define sr_internal_encoders_jacobian sr_internal_encoders_jacobian_f
#define sr_internal_retract sr_internal_retract_f
#endif

/* sr_imu_jacobian for a valid x, body and mount, finite u (or NULL) and bias (or NULL: zero).
 * Outputs written only on SR_OK; SR_ERR_NONFINITE if any is not finite. */
int sr_internal_imu_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], int body,
                             const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                             sr_real H[SR_NIMU * SR_NEB]);

/* The same, and (each if not NULL) Hn = dy/d(nu_dot) (SR_NIMU x SR_NV, as sr_imu_partials: the
 * reading is linear in nu_dot, so Hn is the same at any nu_dot) and M^-1 at x (5 x 5, from the
 * factorisation of the accelerations' Jacobian, sr_internal_accel_jacobian_minv; not tested for
 * finiteness): the held disturbance's update and prior (sr_ekf_update_imu_held) from one
 * evaluation. */
int sr_internal_imu_jacobian_minv(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], int body,
                                  const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                                  sr_real H[SR_NIMU * SR_NEB], sr_real *Hn, sr_real *Minv);

/* sr_encoders_jacobian for a valid x. */
void sr_internal_encoders_jacobian(const sr_real x[SR_NX], sr_real y[2], sr_real H[2 * SR_NEB]);

/* y = x (+) d of sr_retract for a valid x and a finite d (y may alias x); y is not checked. */
void sr_internal_retract(const sr_real x[SR_NX], const sr_real d[SR_NE], sr_real y[SR_NX]);

#endif /* SR_UNCHECKED_H */
