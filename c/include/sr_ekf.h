/**
 * sr_ekf.h -- an error-state extended Kalman filter on the robot's group: the state x of
 * spherical_robot.h and the IMU's biases estimated from the sensors of sr_sensors.h
 * (docs/estimation.md, "The filter").
 *
 * Error state.  The filter keeps a point x of SO(3) x SO(2) x SO(2) x R^2 x R^5 and the biases
 * b = (b_g, b_a), and the covariance P (SR_NEB x SR_NEB, row-major) of the error
 * e = (d, db): the truth is x (+) d (sr_retract's right-trivialised coordinates) and b + db.
 *
 * Predict (one sample of dt, torques u held):
 *   x <- step(x, u, dt)                     sr_step with the given method
 *   P_dd <- F P_dd F^T + Q_d,  P_db <- F P_db,  P_bb <- P_bb + Q_b
 * Transition matrix: F is the Lie-Euler step's Jacobian at the prior x (sr_step_jacobian_lie_euler),
 * whatever the method the mean steps with: one evaluation of the accelerations' Jacobian instead
 * of one per stage, and within O(dt^2) of the method's own step Jacobian, far below the process
 * noise at the sample rates of a filter (docs/estimation.md, "Transition matrix").  The biases
 * do not enter the step, so only the 12 x 12 block and the cross terms move, and F's structural
 * zeros (the attitude's, joint angles' and q's rows read few columns) are skipped.  Q_d is white generalized torque noise w on nu
 * (M nu' = f + w; spectral densities: the shell's three axes, the yoke joint, the pendulum joint,
 * process->torque_psd [N m/sqrt(Hz)]), Q_d = dt M^-1 diag(psd^2) M^-1 in the nu block, M the
 * inertia at the prior x; Q_b = dt diag(rw^2) for the biases' random walks.
 *
 * Update (one sample y of m entries, H its Jacobian in (d, db), R = diag(sigma^2)):
 *   r = y - h(x, b)  (angles wrapped into (-pi, pi]),  S = H P H^T + R = L L^T (Cholesky),
 *   NIS = r^T S^-1 r: if NIS > gate the sample is counted in gated[kind] and nothing else changes;
 *   else K = P H^T S^-1, e = K r, P <- (I - K H) P (I - K H)^T + K R K^T (Joseph form; evaluated
 *   expanded, P - K C^T - (C - K S) K^T with C = P H^T: the same polynomial in K, in O(18^2 m)),
 *   x <- x (+) e_d (sr_retract), b <- b + e_b, and the reset P <- G P G^T, G = I but for the
 *   shell block, the right Jacobian Jr(e_xi_S) of SO(3) (the error after the injection is
 *   Exp(e_xi) Exp(d') = Exp(d): d' = Jr(e_xi)(d - e_xi) to first order).
 * gate: the caller's threshold on the NIS, e.g. the 99.9 % quantile of chi-square with m degrees
 * of freedom (10.83, 13.82, 22.46 for m = 1, 2, 6); +INFINITY accepts every sample.
 *
 * Recovery from a lost estimate (off unless sr_ekf_set_recovery turns it on for a kind): a filter
 * whose covariance has shrunk below its true error refuses every sample that would correct it.
 * Once n samples of a kind have been refused in a row, the next one that fails the gate is applied
 * as if both the prior and the sample's noise were lambda = NIS / gate times larger (P -> lambda P,
 * R -> lambda R, the waiting fixes' covariances alike): S becomes lambda S, so its NIS is the
 * gate's; the gain, and so the correction, is the ungated one, and the covariance after it is lambda
 * times the ungated one, wide enough for the samples that follow to pass the gate and finish the
 * correction.  Counted in recovered[kind] (not in accepted or gated); the run of refusals restarts.
 *
 * Delayed fixes (a position fix that arrives some time after the instant it measures; Larsen's
 * method with the cross-covariance carried already projected onto the fix):
 *   at the instant s the fix is measured, sr_ekf_mark_position keeps in a slot the prediction
 *   yh = h(x_s) and C = P_s H^T = Cov(e, z), z = H e_s (H of a fix is constant: it reads q);
 *   every later predict and update moves C as it moves the error: C <- Phi C (Phi = diag(F, I)),
 *   C <- C - K Cov(r, z) for an applied sample (Cov(r, z) = H C), then the reset's G;
 *   on arrival, sr_ekf_update_position_delayed applies r = y - yh with S = H P_s H^T + R and the
 *   cross-covariance C in place of P H^T: K = C S^-1, P <- P - K C^T - (C - K S) K^T, the
 *   injection and the reset as above.
 * In a linear filter C is exactly the covariance of the current error with z, so the update is
 * the best one of the form x + K r and P stays the covariance of its error (not the smoother's
 * optimum: the samples applied meanwhile do not revise z).  Several fixes may wait at once: each
 * slot also keeps Cov(z_i, z_j) with every other waiting slot (taken when the later is marked),
 * because applying one moves the others' C by -K Cov(z_i, z_j).  A fix that arrives when it is
 * measured (no latency) is simply sr_ekf_update_position.
 * Cost: SR_EKF_NDELAYED slots of 2 + 2 SR_NEB + 4 SR_EKF_NDELAYED numbers and an int in the
 * sr_ekf (the default 4: 216 numbers, 1.7 kB in double, 0.9 kB in float), instead of a history of
 * states and covariances to re-run; per waiting slot and predict one
 * 12 x 12 by 12 x 2 product, per update an m x 2 and an SR_NEB x 2 product.
 *
 * Held disturbance (sr_ekf_update_imu_held).  A truth stepped under a white torque w drawn once per
 * period T and held over it (Q_a = M^-1 diag(psd^2) M^-1 / T for a = M^-1 w, so that T^2 Q_a is the
 * predict's Q_d over T) moves nu by a t over the time t it acts, and its accelerometer reads nu' + a
 * within the period.  The first such sample of a period appends a to the filter's error, prior
 * (mean 0, Cov Q_a at the prior x, independent of e), and every sample of the period applies
 * with the joint Jacobian (H, Hn), Hn = dy/d(nu') of sr_imu_partials (zero on the gyroscope's
 * rows): r = y - h - Hn a_hat, Cov(e, r) = P H^T + C Hn^T, B = Cov(a, r)^T = H C + Hn A,
 * S = H Cov(e, r) + Hn B^T + R (C = Cov(e, a), A = Cov(a)).  The error moves by the update above
 * with these C^T and S; a by a_hat += B^T S^-1 r, A -= B^T S^-1 B, Cov(a, z_j) -= B^T S^-1 Cov(r, z_j),
 * and C <- G (C - K B), all times lambda in a recovery.  Other updates move C as they move a slot's
 * cross-covariance (C <- G (C - K Cov(r, a)), Cov(r, a) = H C, or Cov(z_j, a) for a delayed fix)
 * and leave a_hat and A (a is not revised by them: as the delayed fixes' z); a fix marked meanwhile
 * takes Cov(a, z) = (H C)^T.  A predict of dt steps g = min(dt, the period left) with the held a
 * in place of its torque noise, the rest of dt with the torque noise (times (dt - g)/dt):
 * x_nu += g a_hat, P <- Phi P Phi^T + Phi C Gm^T + Gm C^T Phi^T + Gm A Gm^T (Gm = g on nu's rows)
 * plus the biases' walks, C <- Phi C + Gm A, C_j <- Phi C_j + Gm Cov(a, z_j); a is dropped when its
 * period ends.  A gated sample leaves everything as it was.  In a linear filter this is the exact
 * filter of the augmented state (e, a), with a revised by the IMU samples only.
 *
 * Observability constraint (off unless sr_ekf_set_observability_constraint turns it on; the OC-EKF
 * of Huang, Mourikis and Roumeliotis).  Without position fixes or a heading sensor, the IMU and the
 * encoders cannot tell where the robot stands nor, on a level floor, which way it faces: every
 * reading and the step are the same after the whole robot is turned about the floor's normal or
 * moved along the floor.  In the error coordinates at x those motions are the columns of
 *   N(x) = [n_yaw, n_x, n_y],  n_yaw = (R_S^T e_z, 0, 0, -q_y, q_x, 0...),  n_x = e_{q_x},  n_y = e_{q_y}
 * (R_S Exp(a R_S^T e_z) = Rz(a) R_S; the joint angles, the body rates and the biases do not move;
 * on a slope, gravity fixes the heading and N is (n_x, n_y)).  At any x, H(x) N(x) = 0 for the IMU
 * and the encoders and F(x) N(x) = N(step(x)), but the filter takes F at the updated estimate and
 * H at the predicted one, so the directions it cannot see change between the two and the updates
 * feed it heading information the sensors do not hold (its sigma shrinks while its error does
 * not).  With the constraint, the filter carries N_k, the directions at the last predicted state
 * moved by every reset since (N <- G N), and
 *   F* = F - (F N_k - N_k+1) (N_k^T N_k)^-1 N_k^T,  N_k+1 = N(the predicted state),
 *   H* = H - H N_k (N_k^T N_k)^-1 N_k^T  for the IMU's and the encoders' samples,
 * the nearest matrices (Frobenius) with F* N_k = N_k+1 and H* N_k = 0: the information along N
 * (N^T P^-1 N) is then left as it is by those updates and only lowered by the process noise.
 * Position fixes and the heading sensor keep their H.  The predict adds F* P F*^T - F P F^T to the
 * sparse product (F* - F has rank 3: about 2700 products more), and the held disturbance and the
 * waiting fixes step with F*.  Turned off, none of it runs: the filter's arithmetic is unchanged.
 *
 * Checks, in the library's order (docs/robustness.md): the model (SR_ERR_NULL, SR_ERR_MODEL), the
 * other pointers (SR_ERR_NULL), the arguments (SR_ERR_ARG: method, dt, a standard deviation or a
 * noise density not finite and > 0 (>= 0 for the process noise), gate not > 0 or NaN, body; the
 * mount as sr_check_mount), then the data: the sample and u finite (SR_ERR_NONFINITE), the
 * filter's x (sr_check_state) and its biases and P finite.  A failing call writes nothing, the
 * counters included; SR_ERR_SINGULAR where S (or M) is not positive definite, SR_ERR_NONFINITE
 * where a result overflows.  No dynamic allocation, no globals: the caller owns the sr_ekf.
 * @file
 */
#ifndef SR_EKF_H
#define SR_EKF_H

#include "sr_sensors.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef SR_USE_FLOAT
#define sr_ekf_init sr_ekf_init_f
#define sr_ekf_init_diagonal sr_ekf_init_diagonal_f
#define sr_ekf_predict sr_ekf_predict_f
#define sr_ekf_update_imu sr_ekf_update_imu_f
#define sr_ekf_update_imu_axes sr_ekf_update_imu_axes_f
#define sr_ekf_update_encoders sr_ekf_update_encoders_f
#define sr_ekf_update_position sr_ekf_update_position_f
#define sr_ekf_update_heading sr_ekf_update_heading_f
#define sr_ekf_mark_position sr_ekf_mark_position_f
#define sr_ekf_update_position_delayed sr_ekf_update_position_delayed_f
#define sr_ekf_set_recovery sr_ekf_set_recovery_f
#define sr_ekf_update_imu_held sr_ekf_update_imu_held_f
#define sr_ekf_set_observability_constraint sr_ekf_set_observability_constraint_f
#endif

#ifndef SR_EKF_NDELAYED
/** How many delayed position fixes may wait at once (slots of sr_ekf_mark_position); a build may
 * set its own (>= 1) with -DSR_EKF_NDELAYED=n, the library and its callers alike. */
#define SR_EKF_NDELAYED 4
#endif

/** @name Sensor kinds: the index of each update's counters and last NIS */
/** @{ */
#define SR_EKF_IMU 0           /**< sr_ekf_update_imu (6 entries: gyroscope, accelerometer) */
#define SR_EKF_ENCODERS 1      /**< sr_ekf_update_encoders (theta_Y, theta_P) */
#define SR_EKF_POSITION 2      /**< sr_ekf_update_position (q_x, q_y) */
#define SR_EKF_HEADING 3       /**< sr_ekf_update_heading (one angle) */
#define SR_EKF_NKINDS 4        /**< the number of sensor kinds */
/** @} */

/** A position fix measured and not yet arrived (sr_ekf_mark_position; see the file's description). */
typedef struct sr_ekf_delayed {
    sr_real yh[2];                        /**< the fix predicted at the instant it measures, h(x_s) [m] */
    sr_real C[SR_NEB * 2];                /**< Cov(e, z) of the current error with z = H e_s, SR_NEB x 2 row-major */
    sr_real Z[SR_EKF_NDELAYED * 4];       /**< Cov(z, z_j) per slot j (2 x 2 row-major at 4 j); its own: H P_s H^T */
    int marked;                           /**< 1 while the slot waits for its fix */
} sr_ekf_delayed;

/** The torque disturbance an IMU sample has read and the predicts of its period will step with
 * (sr_ekf_update_imu_held; see the file's description): a = M^-1 w, its estimate and covariances. */
typedef struct sr_ekf_held {
    sr_real mean[SR_NV];                        /**< the estimate of a [rad/s^2] */
    sr_real cov[SR_NV * SR_NV];                 /**< Cov(a), row-major */
    sr_real cross[SR_NEB * SR_NV];              /**< Cov(e, a) with the error e, SR_NEB x SR_NV row-major */
    sr_real fix[SR_EKF_NDELAYED * SR_NV * 2];   /**< Cov(a, z_j) per delayed slot j (SR_NV x 2 row-major at 2 SR_NV j) */
    sr_real remaining;                          /**< how much of its period is left [s] */
    int pending;                                /**< 1 from the sample that read a to the end of its period */
} sr_ekf_held;

/** The filter's state, owned by the caller; fill it with sr_ekf_init or sr_ekf_init_diagonal. */
typedef struct sr_ekf {
    sr_real x[SR_NX];                 /**< the state estimate (layout of spherical_robot.h) */
    sr_real bias[SR_NBIAS];           /**< the IMU's bias estimate: b_g (SR_BIAS_b_g), b_a (SR_BIAS_b_a) */
    sr_real P[SR_NEB * SR_NEB];       /**< covariance of (d, db), row-major, offsets SR_EB_* */
    long accepted[SR_EKF_NKINDS];     /**< samples applied, per kind (SR_EKF_*) */
    long gated[SR_EKF_NKINDS];        /**< samples refused by the gate, per kind */
    sr_real nis[SR_EKF_NKINDS];       /**< the last sample's r^T S^-1 r, per kind (applied or gated) */
    long recovered[SR_EKF_NKINDS];    /**< samples admitted by the recovery policy (sr_ekf_set_recovery), per kind */
    long streak[SR_EKF_NKINDS];       /**< samples refused in a row, per kind (0 once one is applied) */
    long recover_after[SR_EKF_NKINDS]; /**< the recovery policy per kind: 0 off (the start), else n of sr_ekf_set_recovery */
    sr_ekf_delayed delayed[SR_EKF_NDELAYED]; /**< the delayed fixes waiting, by slot */
    sr_ekf_held held;                 /**< the disturbance read by sr_ekf_update_imu_held, until its period ends */
    int constrained;                  /**< 1: observability-constrained (sr_ekf_set_observability_constraint), 0: off (the start) */
    int null_cols;                    /**< the columns of null_space: 3 on a level floor, 2 on a slope */
    sr_real null_space[SR_NE * 3];    /**< N, the unobservable directions in the current error coordinates (SR_NE x 3 row-major) */
} sr_ekf;

/** The process noise of sr_ekf_predict (all >= 0 and finite). */
typedef struct sr_ekf_process {
    sr_real torque_psd[3];    /**< white generalized torques on the shell (each axis), the yoke joint and the pendulum joint [N m/sqrt(Hz)] */
    sr_real gyro_bias_rw;     /**< the gyroscope biases' random walk [rad/s/sqrt(s)] (0: constant) */
    sr_real accel_bias_rw;    /**< the accelerometer biases' random walk [m/s^2/sqrt(s)] (0: constant) */
} sr_ekf_process;

/** Starts the filter at x0 (checked as sr_check_state), biases bias (NULL: zero), covariance
 * P0 (SR_NEB x SR_NEB row-major: finite, symmetric to 1e-12 relative of its largest diagonal
 * entry, else SR_ERR_ARG; positive definite, else SR_ERR_SINGULAR); counters and NIS zeroed.
 * Returns SR_OK or an error code; *ekf is written only on SR_OK. */
int sr_ekf_init(sr_ekf *ekf, const sr_model *model, const sr_real x0[SR_NX], const sr_real bias[SR_NBIAS],
                const sr_real P0[SR_NEB * SR_NEB]);

/** sr_ekf_init with P0 = diag(sigma^2), sigma[SR_NEB] the standard deviations of (d, db), each
 * finite and > 0 (else SR_ERR_ARG). */
int sr_ekf_init_diagonal(sr_ekf *ekf, const sr_model *model, const sr_real x0[SR_NX], const sr_real bias[SR_NBIAS],
                         const sr_real sigma[SR_NEB]);

/** One prediction over dt > 0 under the torques u (NULL: zero): the mean by the stepping method
 * (SR_LIE_EULER, SR_RKMK4 or SR_CF4, optionally | SR_PROJECT), the covariance by the Lie-Euler
 * step's Jacobian (the file's "Transition matrix"), process noise *process (see the file's
 * description). */
int sr_ekf_predict(sr_ekf *ekf, const sr_model *model, int method, const sr_real u[SR_NU], sr_real dt,
                   const sr_ekf_process *process);

/** One IMU sample y[SR_NIMU] (gyroscope [rad/s], accelerometer [m/s^2], in the sensor's axes)
 * from the IMU on body at mount, while the torques u (NULL: zero) act: the reading and H of
 * sr_imu_jacobian at the estimate (nu' moving with the state), R = diag(sigma_gyro^2 x 3,
 * sigma_accel^2 x 3) (per-sample standard deviations), gated at gate. */
int sr_ekf_update_imu(sr_ekf *ekf, const sr_model *model, const sr_real y[SR_NIMU], const sr_real u[SR_NU],
                      int body, const sr_real mount[SR_NMOUNT], sr_real sigma_gyro, sr_real sigma_accel, sr_real gate);

/** sr_ekf_update_imu with a standard deviation per reading: R = diag(sigma[i]^2), sigma[SR_NIMU] in
 * the sample's order (gyroscope x, y, z [rad/s], accelerometer x, y, z [m/s^2]), each finite and
 * > 0 (else SR_ERR_ARG; NULL: SR_ERR_NULL).  What the unmodelled accelerations add to the
 * accelerometer's reading differs between its axes (at rest the process noise reaches the
 * horizontal ones only): one number for the three would be too wide on some or too narrow on others. */
int sr_ekf_update_imu_axes(sr_ekf *ekf, const sr_model *model, const sr_real y[SR_NIMU], const sr_real u[SR_NU],
                           int body, const sr_real mount[SR_NMOUNT], const sr_real sigma[SR_NIMU], sr_real gate);

/** sr_ekf_update_imu_axes for a robot driven by the white torque disturbance of *process held
 * constant over periods of hold > 0 [s], the first starting at this sample (a simulation's step,
 * or the IMU's period): the accelerometer reads the acceleration a = M^-1 w that the same w gives
 * nu over the predicts of that period, so the sample's noise and their process noise are correlated (see the
 * file's description, "Held disturbance").  sigma[SR_NIMU] is the readings' own noise (white, per
 * sample) without any share of the disturbance.  process and hold: SR_ERR_NULL, SR_ERR_ARG as
 * sr_ekf_predict's; SR_ERR_SINGULAR where M is not positive definite.  A sample while a is held
 * (within its period) reads the same a. */
int sr_ekf_update_imu_held(sr_ekf *ekf, const sr_model *model, const sr_real y[SR_NIMU], const sr_real u[SR_NU],
                           int body, const sr_real mount[SR_NMOUNT], const sr_real sigma[SR_NIMU],
                           const sr_ekf_process *process, sr_real hold, sr_real gate);

/** One encoder sample y = (theta_Y, theta_P) [rad], standard deviation sigma each (e.g. a count's
 * quantisation, 2 pi / (counts sqrt(12))), gated at gate; the innovations are wrapped into (-pi, pi]. */
int sr_ekf_update_encoders(sr_ekf *ekf, const sr_model *model, const sr_real y[2], sr_real sigma, sr_real gate);

/** One position fix y = (q_x, q_y) [m], standard deviation sigma each, gated at gate. */
int sr_ekf_update_position(sr_ekf *ekf, const sr_model *model, const sr_real y[2], sr_real sigma, sr_real gate);

/** The instant a position fix is measured that will arrive later: keeps in slot (0 <=
 * slot < SR_EKF_NDELAYED, else SR_ERR_ARG) what its update will need (see the file's
 * description); a slot still waiting is overwritten (its fix is forgotten).  Call it after the
 * predict to that instant; the samples of the same instant may be applied before or after. */
int sr_ekf_mark_position(sr_ekf *ekf, const sr_model *model, int slot);

/** The fix y = (q_x, q_y) [m] measured at the instant slot was marked (SR_ERR_ARG if slot is out
 * of range or waits for no fix), standard deviation sigma each, gated at gate; counted as a
 * position fix.  Applied or gated, the slot is free afterwards. */
int sr_ekf_update_position_delayed(sr_ekf *ekf, const sr_model *model, int slot, const sr_real y[2], sr_real sigma,
                                   sr_real gate);

/** One heading sample [rad] of the sensor on body at mount (sr_heading_measure), standard deviation
 * sigma, gated at gate; the innovation is wrapped into (-pi, pi].  SR_ERR_SINGULAR where the
 * estimate's sensor x axis is along the floor's normal (the heading is undefined there). */
int sr_ekf_update_heading(sr_ekf *ekf, const sr_model *model, sr_real y, int body, const sr_real mount[SR_NMOUNT],
                          sr_real sigma, sr_real gate);

/** The recovery policy of sensor kind (SR_EKF_IMU ... SR_EKF_HEADING, else SR_ERR_ARG): after n
 * samples of that kind refused by the gate in a row, the next refused one is admitted with the
 * prior and its noise inflated (see the file's description); n = 0 turns it off (the default after
 * sr_ekf_init), n < 0 is SR_ERR_ARG.  The counters stay as they are. */
int sr_ekf_set_recovery(sr_ekf *ekf, int kind, long n);

/** The observability constraint (see the file's description): on = 1 turns it on, with N = N(x) at
 * the filter's estimate (its third column only on a level floor, model's slope 0), on = 0 turns
 * it off (the default after sr_ekf_init); any other on is SR_ERR_ARG.  Checks the model, the
 * pointers and the filter's data as the updates do; the counters stay as they are. */
int sr_ekf_set_observability_constraint(sr_ekf *ekf, const sr_model *model, int on);

#ifdef __cplusplus
}
#endif

#endif /* SR_EKF_H */
