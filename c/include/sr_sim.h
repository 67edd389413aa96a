/**
 * sr_sim.h -- a robot on its sensors, simulated in C: the plant stepped under a white torque
 * disturbance, its IMU, encoders, position fixes and heading read along the steps, and every sample
 * applied to the filter (sr_ekf) when it arrives.  This is the work of runtime/sensor_sim.py's
 * SensorSimulation and of the sample loop of runtime/control/closed_loop.py between two controller
 * samples, done in one call, so that a closed loop on sensors crosses into C once per controller
 * period.  The Python simulation stays the reference this one is tested against, reading for reading.
 *
 * Every random number comes from the caller, drawn beforehand (standard normal draws per step for
 * the process noise, per sample for each sensor's noise), and so do the IMU's biases (a row per
 * IMU sample, or one row for the run): the seeding and the biases' model stay with the caller.
 *
 * Over a step k (from t_k = k dt) the disturbance w = process[k] * q_std (elementwise) is a constant
 * generalized force; its velocity change M^-1 w tau after tau into the step is added to the state
 * the stepper reaches at tau, and the accelerometer reads M^-1 w on top of the applied torques'
 * acceleration.  A sample whose time falls in [t_k, t_k + dt) is read from the state at its time:
 *   IMU      sr_imu_measure + bias + noise * draw, clipped at +-range      (noise, range per axis)
 *   encoders sr_encoders_measure rounded to the nearest multiple of the step (ties to even)
 *   fixes    sr_position_measure + noise * draw
 *   heading  sr_heading_measure + noise * draw, wrapped into [-pi, pi] by remainder()
 * After the step every sample that has arrived before t_k + dt reaches the filter, in the order of
 * its arrival time, then its kind (IMU, encoders, fixes, heading), then its index: the filter is
 * predicted to the arrival time under the held torques, then updated: an IMU sample through
 * sr_ekf_update_imu_held with the hold filter_hold > 0 (dt: the disturbance as this simulation
 * holds it, the Python closed loop's default), else through sr_ekf_update_imu_axes.  Tolerances of
 * the sample times: 1e-9 dt, as in the Python simulation.
 *
 * Self-contained C99: no dynamic allocation, no globals; the caller owns every buffer.
 * @file
 */
#ifndef SR_SIM_H
#define SR_SIM_H

#include "spherical_robot.h"
#include "sr_sensors.h"
#include "sr_ekf.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef SR_USE_FLOAT
#define sr_sim_stream sr_sim_stream_f
#define sr_sim sr_sim_f
#define sr_sim_check sr_sim_check_f
#define sr_sim_advance sr_sim_advance_f
#endif

/** @name Sensor kinds, in the order samples of one arrival time reach the filter */
/** @{ */
#define SR_SIM_IMU 0           /**< SR_NIMU numbers: gyroscope [rad/s], accelerometer [m/s^2] */
#define SR_SIM_ENCODERS 1      /**< theta_Y, theta_P [rad] */
#define SR_SIM_FIXES 2         /**< q_x, q_y [m] */
#define SR_SIM_HEADING 3       /**< one angle [rad] */
#define SR_SIM_NKINDS 4        /**< the number of kinds */
/** @} */

/** One sensor's samples over a run (n = 0: the robot does not carry it). */
typedef struct sr_sim_stream {
    long n;                  /**< samples in the run */
    const sr_real *time;     /**< n measurement times [s], increasing */
    const sr_real *arrival;  /**< n arrival times [s] (time + latency), increasing */
    const sr_real *draw;     /**< n x width standard normal draws of the noise (unused for encoders) */
    sr_real *reading;        /**< n x width readings, written as they are read */
    long read;               /**< samples read so far (start at 0) */
    long applied;            /**< samples applied to the filter so far (start at 0) */
    int body;                /**< IMU and heading: the body carrying the sensor (SR_BODY_*) */
    sr_real mount[SR_NMOUNT];/**< IMU and heading: its mount on that body */
    sr_real noise[SR_NIMU];  /**< the readings' standard deviations (the IMU's per axis; others: [0]) */
    sr_real range[SR_NIMU];  /**< IMU: the full scale per axis; encoders: [0] is the quantisation step */
    sr_real sigma[SR_NIMU];  /**< what the filter assumes: the IMU's per axis, the others' [0] */
    sr_real gate;            /**< the filter's gate for this kind */
    int filter_body;         /**< IMU and heading: the body of the filter's mount */
    sr_real filter_mount[SR_NMOUNT]; /**< IMU and heading: the mount the filter assumes */
} sr_sim_stream;

/** A simulated run on sensors: the caller fills every field, then calls sr_sim_advance with the
 * steps in order. */
typedef struct sr_sim {
    sr_sim_stream stream[SR_SIM_NKINDS]; /**< by kind (SR_SIM_*) */
    long steps;                  /**< plant steps in the run */
    sr_real dt;                  /**< the plant's step [s] */
    int method;                  /**< the plant's stepping method (SR_RKMK4, ...) */
    const sr_real *process;      /**< steps x SR_NV standard normal draws of the disturbance */
    sr_real q_std[SR_NV];        /**< the disturbance's standard deviation per generalized force [N m] */
    int disturbance_in_accel;    /**< 1: the accelerometer reads the disturbance's acceleration too */
    const sr_real *bias;         /**< the IMU's biases (SR_NBIAS: gyroscope, accelerometer) at its sample i: bias + i * bias_stride */
    long bias_stride;            /**< 0: constant biases; SR_NBIAS: a row per IMU sample */
    int filter_method;           /**< the filter's prediction method */
    sr_ekf_process filter_process; /**< the filter's process noise */
    sr_real filter_hold;         /**< > 0: the filter reads the IMU through sr_ekf_update_imu_held, the torque
                                      disturbance held that long [s] (dt: as this simulation holds it);
                                      0: through sr_ekf_update_imu_axes (the disturbance's share in sigma) */
    sr_real filter_time;         /**< the time [s] the filter is predicted to (the caller's predictions included) */
    long *order;                 /**< NULL, or 2 x (all samples): (kind, index) of every sample in the order applied */
    long applied;                /**< samples applied so far (entries of order written) */
} sr_sim;

/** Checks a run's description: SR_ERR_NULL (sim, or a buffer of a stream with n > 0, or process
 * or bias), SR_ERR_ARG (dt not > 0 or not finite, steps < 0, a negative n or cursor, a stride
 * that is neither 0 nor SR_NBIAS, an unknown method, a negative or non-finite noise, range,
 * sigma or filter_hold, a negative or NaN gate), or a mount's sr_check_mount status. */
int sr_sim_check(const sr_sim *sim);

/** Advances the run by steps step..step+count-1 from the plant's state x (SR_NX, overwritten with
 * the state after them) under the held torques u[SR_NU]: reads every sample of those steps and
 * applies to the filter *ekf (on the controller's model) every sample that has arrived by their
 * end (see the file's description).  plant is the true robot.  traj: NULL, or count x SR_NX rows,
 * the state after each step.  Returns SR_OK, sr_sim_check's status, SR_ERR_ARG (steps out of the
 * run's range), or the first failing kernel's status (a plant step, a sensor model or a filter
 * update: the run stops there, x and the cursors as far as it got). */
int sr_sim_advance(sr_sim *sim, const sr_model *plant, sr_ekf *ekf, const sr_model *model, long step, long count,
                   sr_real x[SR_NX], const sr_real u[SR_NU], sr_real *traj);

#ifdef __cplusplus
}
#endif

#endif /* SR_SIM_H */
