/**
 * sr_sensors.h -- what the robot's sensors read, and the derivatives an estimator needs: an IMU
 * (gyroscope and accelerometer) on the shell, the yoke or the pendulum, the joint encoders, a
 * position fix and a heading sensor (docs/estimation.md).  Derived in derive/sensors.py and
 * emitted as the sr_gen_imu_* / sr_gen_heading_* kernels; checked here.
 *
 * Frames and units (SI).  The inertial frame lies in the floor's plane, x up the slope, z along
 * its normal; gravity there is -g (sin(slope), 0, cos(slope)).  A sensor sits on a body B
 * (SR_BODY_shell, SR_BODY_yoke, SR_BODY_pendulum) with attitude R_B = R_S, R_S R_Y or
 * R_S R_Y R_P, at a lever arm rho from the shell centre in B's frame, with its axes R_m in B's
 * frame: mount[SR_MOUNT_lever + 0..2] = rho [m], mount[SR_MOUNT_R_m + 0..8] = R_m row-major.
 *
 *   gyroscope      y[SR_IMU_gyro + 0..2]  = R_m^T w_B + b_g                 [rad/s]
 *   accelerometer  y[SR_IMU_accel + 0..2] = R_m^T R_B^T (p'' - g) + b_a     [m/s^2]
 *                  the specific force at p = q + R_B rho, with the centre's rolling acceleration and
 *                  the tangential and centripetal terms; at rest it reads +g along the upward normal
 *   encoders       (theta_Y, theta_P): the angles of R_Y about x and of R_P about y, in (-pi, pi] [rad]
 *   position fix   (q_x, q_y): the shell centre on the floor [m]
 *   heading        atan2(h_y, h_x) of h = R_B R_m e_x, the sensor's x axis, on the floor's axes:
 *                  counter-clockwise from the up-slope x axis about the normal, in (-pi, pi] [rad]
 * bias[SR_BIAS_b_g + 0..2], bias[SR_BIAS_b_a + 0..2]: the IMU's biases in its axes (NULL: zero).
 *
 * Jacobians are taken in the estimator's error state [d | b_g | b_a] (SR_NEB = 18 columns,
 * offsets SR_EB_*): d the 12 error coordinates of sr_retract (spherical_robot.h), the biases
 * additively; H row-major (rows of the measurement x SR_NEB).  The accelerometer reads nu_dot:
 * sr_imu_partials gives dy/d(d, b) with nu_dot held and dy/d(nu_dot), for an estimator that has
 * the accel Jacobian Ja at hand (dy/dd = H + Hn Ja); sr_imu_jacobian forms nu_dot and Ja from the
 * torques itself.
 *
 * Every function that takes a model checks its arguments in the library's order
 * (docs/robustness.md): the model (SR_ERR_NULL, SR_ERR_MODEL: see sr_model), the other pointers
 * (SR_ERR_NULL; bias and u may be NULL), the body and the mount (SR_ERR_ARG: body not an
 * SR_BODY_*; SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION: the mount not finite, R_m not a rotation to
 * SR_ROTATION_TOL), then the state x as sr_check_state does, in full (the heading reads every row
 * of R_S: SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT) and the other data for
 * finiteness (nu_dot, u, bias: SR_ERR_NONFINITE).  Then SR_ERR_NONFINITE for a result that
 * overflows, SR_ERR_SINGULAR for sr_imu_measure_u and sr_imu_jacobian where M is not positive
 * definite and for the heading functions where the sensor's x axis is within
 * SR_HEADING_MIN_HORIZONTAL of the floor's normal (the heading is undefined there).  Outputs are
 * written only on SR_OK.
 * @file
 */
#ifndef SR_SENSORS_H
#define SR_SENSORS_H

#include "spherical_robot.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef SR_USE_FLOAT
#define sr_check_mount sr_check_mount_f
#define sr_imu_measure sr_imu_measure_f
#define sr_imu_measure_u sr_imu_measure_u_f
#define sr_imu_partials sr_imu_partials_f
#define sr_imu_jacobian sr_imu_jacobian_f
#define sr_encoders_measure sr_encoders_measure_f
#define sr_imu_partials_batch sr_imu_partials_batch_f
#define sr_encoders_jacobian_batch sr_encoders_jacobian_batch_f
#define sr_position_jacobian_batch sr_position_jacobian_batch_f
#define sr_encoders_jacobian sr_encoders_jacobian_f
#define sr_position_measure sr_position_measure_f
#define sr_position_jacobian sr_position_jacobian_f
#define sr_heading_measure sr_heading_measure_f
#define sr_heading_jacobian sr_heading_jacobian_f
#endif

#define SR_NMOUNT SR_GEN_NMOUNT  /**< entries of a mount: lever arm (SR_MOUNT_lever), then R_m (SR_MOUNT_R_m) */
#define SR_NBIAS SR_GEN_NBIAS    /**< IMU biases: gyroscope (SR_BIAS_b_g), then accelerometer (SR_BIAS_b_a) */
#define SR_NIMU SR_GEN_NIMU      /**< an IMU reading: gyroscope (SR_IMU_gyro), then accelerometer (SR_IMU_accel) */
#define SR_NEB SR_GEN_NEB        /**< the estimator's error state: d (SR_NE), b_g, b_a (offsets SR_EB_*) */
#define SR_NBODY 3               /**< the bodies a sensor sits on: SR_BODY_shell, SR_BODY_yoke, SR_BODY_pendulum */

/** Below this length of the sensor's x axis projected on the floor (a unit vector's), the heading
 * is refused (SR_ERR_SINGULAR): its derivative grows as one over that length. */
#define SR_HEADING_MIN_HORIZONTAL SR_C(1e-6)

/** @name Sensor models */
/** @{ */

/** SR_OK if body is an SR_BODY_* and mount finite with R_m a rotation; else SR_ERR_NULL (mount),
 * SR_ERR_ARG (body), SR_ERR_NONFINITE or SR_ERR_NOT_ROTATION (mount). */
int sr_check_mount(int body, const sr_real mount[SR_NMOUNT]);

/** The IMU's reading y[SR_NIMU] given the accelerations nu_dot[SR_NV] (as sr_accel returns them);
 * bias NULL: zero. */
int sr_imu_measure(const sr_model *model, const sr_real x[SR_NX], const sr_real nu_dot[SR_NV], int body,
                   const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU]);

/** The IMU's reading y[SR_NIMU] under the torques u (NULL: zero), nu_dot that of sr_accel;
 * bias NULL: zero. */
int sr_imu_measure_u(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], int body,
                     const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU]);

/** y, H = dy/d(d, b) with nu_dot held (SR_NIMU x SR_NEB) and Hn = dy/d(nu_dot) (SR_NIMU x SR_NV;
 * the gyroscope's rows are zero): y(x (+) d, b + db, nu_dot + e) = y + H (d, db) + Hn e + O(2). */
int sr_imu_partials(const sr_model *model, const sr_real x[SR_NX], const sr_real nu_dot[SR_NV], int body,
                    const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                    sr_real H[SR_NIMU * SR_NEB], sr_real Hn[SR_NIMU * SR_NV]);

/** y and H = dy/d(d, b) (SR_NIMU x SR_NEB) under the torques u (NULL: zero), nu_dot moving with
 * the state: H = H|nu_dot + Hn Ja with Ja of sr_accel_jacobian.  nu_dot is the one
 * sr_accel_jacobian forms, so y equals sr_imu_measure_u's to rounding. */
int sr_imu_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], int body,
                    const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real y[SR_NIMU],
                    sr_real H[SR_NIMU * SR_NEB]);

/** The joint encoders: y = (theta_Y, theta_P) in (-pi, pi] [rad]. */
int sr_encoders_measure(const sr_model *model, const sr_real x[SR_NX], sr_real y[2]);

/** The joint encoders' y = (theta_Y, theta_P) and H (2 x SR_NEB). */
int sr_encoders_jacobian(const sr_model *model, const sr_real x[SR_NX], sr_real y[2], sr_real H[2 * SR_NEB]);

/** The position fix: y = (q_x, q_y), the shell centre on the floor [m]. */
int sr_position_measure(const sr_model *model, const sr_real x[SR_NX], sr_real y[2]);

/** The position fix's y = (q_x, q_y) and H (2 x SR_NEB). */
int sr_position_jacobian(const sr_model *model, const sr_real x[SR_NX], sr_real y[2], sr_real H[2 * SR_NEB]);

/** The heading of the sensor's x axis on the floor, in (-pi, pi] [rad] (see the file's description). */
int sr_heading_measure(const sr_model *model, const sr_real x[SR_NX], int body, const sr_real mount[SR_NMOUNT],
                       sr_real *heading);

/** The heading of the sensor's x axis and its H (1 x SR_NEB). */
int sr_heading_jacobian(const sr_model *model, const sr_real x[SR_NX], int body, const sr_real mount[SR_NMOUNT],
                        sr_real *heading, sr_real H[SR_NEB]);
/** @} */

/** @name Sensor models over many states */
/** @{ */

/** sr_imu_partials on n rows (x n x SR_NX, nu_dot n x SR_NV; y n x SR_NIMU, H n x SR_NIMU x SR_NEB,
 * Hn n x SR_NIMU x SR_NV, row-major), one body, mount and bias for all: what a fit to a whole log
 * needs in one call.  Stops at the first failing row, its index in *failed_row (if not NULL; -1 when
 * all rows succeed); n < 0: SR_ERR_ARG.  Rows before the failing one are written. */
int sr_imu_partials_batch(const sr_model *model, long n, const sr_real *x, const sr_real *nu_dot, int body,
                          const sr_real mount[SR_NMOUNT], const sr_real bias[SR_NBIAS], sr_real *y, sr_real *H,
                          sr_real *Hn, long *failed_row);

/** sr_encoders_jacobian on n rows (y n x 2, H n x 2 x SR_NEB), as sr_imu_partials_batch. */
int sr_encoders_jacobian_batch(const sr_model *model, long n, const sr_real *x, sr_real *y, sr_real *H,
                               long *failed_row);

/** sr_position_jacobian on n rows (y n x 2, H n x 2 x SR_NEB), as sr_imu_partials_batch. */
int sr_position_jacobian_batch(const sr_model *model, long n, const sr_real *x, sr_real *y, sr_real *H,
                               long *failed_row);
/** @} */

#ifdef __cplusplus
}
#endif

#endif /* SR_SENSORS_H */
