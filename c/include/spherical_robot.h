/**
 * spherical_robot.h -- public C API of the spherical-robot kernels.
 *
 * Model: S. Fiori (2024), "Lie-group modeling and simulation of a spherical
 * robot, actuated by a yoke-pendulum system, rolling over a flat surface
 * without slipping".  The equations are derived symbolically in derive/ and
 * emitted to generated/sr_generated.c; this header and the hand-written c/sr_*.c add
 * input checks, the SO(3) exponential and the time steppers (c/src/sr_model.c: status strings,
 * parameter rules, model; c/src/sr_checks.c: state checks; c/src/sr_kernels.c: the checked kernels;
 * c/src/sr_steppers.c: every stepper; c/src/sr_drivers.c: the simulation loops).
 *
 * Self-contained C99: no dynamic allocation, no mutable globals, every
 * function is re-entrant, every buffer is provided by the caller, every
 * function returns a status code (SR_OK = 0 on success).
 *
 * Scalar type: sr_real is double, or float when compiled with -DSR_USE_FLOAT.
 *
 * Units and frames (SI throughout):
 *   params  [SR_NPARAM] = the robot (index of each: SR_P_r ... SR_P_slope in
 *           sr_generated.h):
 *           r shell radius [m], m_S shell mass [kg], j_S its isotropic inertia [kg m^2],
 *           m_Y yoke mass, c_Y (c_Y_x, c_Y_y, c_Y_z) its centre of mass [m] in the yoke
 *           frame from the shell centre, J_Y (J_Y_xx, J_Y_yy, J_Y_zz, J_Y_xy, J_Y_xz, J_Y_yz)
 *           its inertia tensor about that centre [kg m^2]; m_P, c_P, J_P the same for the
 *           pendulum (pendulum frame, from its hinge at the shell centre); j_mY, j_mP the
 *           motor rotors' inertias about their axes [kg m^2], n_Y, n_P their gear ratios
 *           (rotor speed relative to its carrier = n * joint speed; the yoke motor's rotor
 *           sits on the shell, the pendulum motor's on the yoke); g gravity [m/s^2]; slope
 *           the floor's inclination [rad] (the inertial frame lies in the plane, x up the
 *           slope: gravity is -g (sin(slope), 0, cos(slope)));
 *           k_S, k_Y, k_P physical damping [N m s/rad]: torque -k*omega.
 *           The paper's robot: sr_paper_params from (r, m_S, k_S, b, h, m_b, m_h, k_Y, l,
 *           m_P, k_P, g) (SR_PAPER_r ... SR_PAPER_g).
 *   x       [SR_NX] = 35 state entries (offset of each block: SR_X_R_S ... SR_X_w_P in
 *           sr_generated.h):
 *           x[0..8]   R_S row-major, shell frame -> inertial frame
 *           x[9..17]  R_Y row-major, yoke relative to shell, rotation about x
 *           x[18..26] R_P row-major, pendulum relative to yoke, rotation about y
 *           x[27..29] q, shell centre in the inertial frame [m], q_z = r
 *           x[30..32] w_S, shell angular velocity in the shell frame [rad/s]
 *                     (R_S^T dR_S/dt = [[w_S]])
 *           x[33]     w_Y, yoke speed (R_Y^T dR_Y/dt = w_Y Sigma_Y) [rad/s]
 *           x[34]     w_P, pendulum speed (R_P^T dR_P/dt = w_P Sigma_P) [rad/s]
 *   u       [SR_NU] = (yoke motor torque, pendulum motor torque) [N m]
 *   nu      [SR_NV] = (w_S, w_Y, w_P); accelerations are d(nu)/dt [rad/s^2]
 * @file
 */
#ifndef SPHERICAL_ROBOT_H
#define SPHERICAL_ROBOT_H

#include "sr_generated.h"

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The float build has symbol names of its own (suffix _f): code compiled with SR_USE_FLOAT
 * against the double library, or the reverse, fails at link time instead of misreading every
 * buffer, and one program can link both builds. */
#ifdef SR_USE_FLOAT
#define sr_status_string sr_status_string_f
#define sr_param_rule_string sr_param_rule_string_f
#define sr_check_params sr_check_params_f
#define sr_check_paper_params sr_check_paper_params_f
#define sr_paper_params sr_paper_params_f
#define sr_paper_params_unchecked sr_paper_params_unchecked_f
#define sr_model_init sr_model_init_f
#define sr_check_model sr_check_model_f
#define sr_check_state sr_check_state_f
#define sr_check_state_batch sr_check_state_batch_f
#define sr_accel sr_accel_f
#define sr_accel_batch sr_accel_batch_f
#define sr_checked_accel_batch sr_checked_accel_batch_f
#define sr_inertia sr_inertia_f
#define sr_rhs sr_rhs_f
#define sr_energy sr_energy_f
#define sr_equilibrium_residual sr_equilibrium_residual_f
#define sr_contact_force sr_contact_force_f
#define sr_contact_force_batch sr_contact_force_batch_f
#define sr_so3_exp sr_so3_exp_f
#define sr_atan2 sr_atan2_f
#define sr_step sr_step_f
#define sr_step_lie_euler sr_step_lie_euler_f
#define sr_step_rkmk4 sr_step_rkmk4_f
#define sr_step_cf4 sr_step_cf4_f
#define sr_step_batch sr_step_batch_f
#define sr_simulate sr_simulate_f
#define sr_simulate_guarded sr_simulate_guarded_f
#define sr_simulate_adaptive sr_simulate_adaptive_f
#endif

#define SR_NPARAM SR_GEN_NPARAM /**< entries of a parameter vector (params) */
#define SR_NPAPER SR_GEN_NPAPER /**< the paper's parameters (paper) */
#define SR_NX SR_GEN_NX         /**< entries of a state (x) */
#define SR_NU SR_GEN_NU         /**< motor torques (u) */
#define SR_NV SR_GEN_NV         /**< generalized velocities (nu) and accelerations */
#define SR_NE SR_GEN_NE         /**< entries of an error state (d): the tangent coordinates */

/** @name Status codes */
/** @{ */
#define SR_OK 0                /**< success */
#define SR_ERR_NULL 1          /**< a required pointer is NULL */
#define SR_ERR_NONFINITE 2     /**< an input is NaN or infinite, or a result overflowed (outputs are
                                  finite whenever a function returns SR_OK) */
#define SR_ERR_NOT_ROTATION 3  /**< a rotation matrix is not orthonormal with det +1, R_Y is not about x or R_P not about y */
#define SR_ERR_SINGULAR 4      /**< the generalized inertia M is not positive definite */
#define SR_ERR_PARAM 5         /**< a parameter is out of its physical range */
#define SR_ERR_ARG 6           /**< another argument is invalid (dt <= 0, steps < 0, unknown method) */
#define SR_ERR_CONSTRAINT 7    /**< q_z differs from r by more than SR_ROTATION_TOL * r */
#define SR_ERR_STEP_SIZE 8     /**< adaptive stepping: the step size fell below the rounding level of t */
#define SR_ERR_MAX_STEPS 9     /**< adaptive stepping: more than max_steps step attempts */
#define SR_ERR_ENERGY 10       /**< sr_simulate_guarded: the energy rose without input power beyond the
                                  guard's tolerance (see sr_energy_guard) */
#define SR_ERR_MODEL 11        /**< the model is not one that sr_model_init filled: never initialised
                                  (zeroed or garbage memory), or an entry that the function reads
                                  changed since (see sr_model) */
/** @} */

/** Tolerance on |R^T R - I| (entry-wise) and |det R - 1| accepted by the checks. */
#ifdef SR_USE_FLOAT
#define SR_ROTATION_TOL SR_C(1e-3)
#else
#define SR_ROTATION_TOL SR_C(1e-6)
#endif

/** sr_simulate and sr_simulate_guarded check the whole state (sr_check_state) every
 * SR_GUARD_INTERVAL steps and after the last step; finiteness is checked after every step. */
#define SR_GUARD_INTERVAL 16

/** @name Time-stepping methods */
/** @{ */
#define SR_LIE_EULER 0         /**< the paper's equation (111), first order */
/** Fourth-order Lie-group methods (c/src/sr_steppers.c).  Both advance the state on
 * SO(3) x SO(2)_x x SO(2)_y x R^3 x R^5: R_S by right multiplication with Exp of an so(3)
 * element, R_Y and R_P by exact rotations about x and y, q and nu additively.  The torque u
 * is held constant over the step; q is a stage variable like every other (order 4 overall).
 * Rotations stay orthonormal to rounding (no projection). */
#define SR_RKMK4 1             /**< Runge-Kutta-Munthe-Kaas: classical RK4 tableau in the Lie
                                  algebra with the closed-form dexp^-1 of SO(3); 4 acceleration
                                  evaluations and 4 SO(3) exponentials per step */
#define SR_CF4 2               /**< commutator-free method of Celledoni-Marthinsen-Owren (2003):
                                  4 stages, no dexp^-1, the update a product of 2 exponentials;
                                  4 acceleration evaluations and 5 SO(3) exponentials per step */
#define SR_PROJECT 16          /**< flag, OR-ed into any method (as in SR_RKMK4 | SR_PROJECT): after
                                  every step, one Newton-Schulz step R <- R (3I - R^T R)/2 pulls
                                  R_S (and the cos/sin pairs of R_Y, R_P) back to the rotations.
                                  Off by default: the methods need it only where rounding is
                                  biased, e.g. a robot at rest for ~10^5+ steps, whose tiny
                                  constant increments round the same way every step */
/** @} */

/** The number of read sets of a model, one checksum each (sr_model). */
#define SR_MODEL_NSUMS 10

/** Model: the parameters and the constants derived from them. Fill with sr_model_init.
 * A robot of the paper's geometry (c_Y = 0, J_Y_zz = J_Y_xx + J_Y_yy, J_Y diagonal, c_P on
 * the pendulum's z axis, J_P = diag(a, a, 0), no rotors, level floor) is evaluated by the
 * paper-geometry kernels (constants c, general = 0), any other by the general kernels
 * (constants cg, general = 1); sr_model_init chooses.  A library compiled with -DSR_PAPER_ONLY
 * has no general kernels (smaller firmware): sr_model_init refuses other robots (SR_ERR_PARAM).  Both give the same numbers for the
 * paper's robot, to rounding (tests/runtime/test_general_robot.py).
 * A model is a value: copy it whole (assignment, memcpy), never change a field.  Every function
 * that takes a model first checks that it is valid, and returns SR_ERR_MODEL for one that is not:
 * its stamp missing (memory that sr_model_init never filled: zeroed, uninitialised, or left
 * untouched by a failed sr_model_init), or a checksum of what that function reads of the model
 * differing from the one sr_model_init stored.  sr_model_init stores one checksum per read set
 * (SR_MODEL_NSUMS of them): the entries of p, c or cg that one generated kernel reads (listed by
 * the generator, SR_GEN_READS_<kernel> in sr_generated.h) or that the hand-written code reads
 * (r by the state check, the energy guard's masses, centres and g), each with general.  A function
 * checks the read sets of the kernels it calls: any entry it reads, changed since to NaN or to any
 * other value, is refused; an entry it does not read may change without that function refusing
 * (nor its result changing).  sr_check_model re-checks the whole model. */
typedef struct sr_model {
    sr_real p[SR_NPARAM];                /**< the parameters, as given to sr_model_init */
    int general;                         /**< 1: the general kernels (cg), 0: the paper-geometry ones (c) */
    sr_real c[SR_GEN_NCONST];            /**< derived constants of the paper-geometry kernels */
    sr_real cg[SR_GEN_GENERAL_NCONST];   /**< derived constants of the general kernels */
    uint64_t stamp;                      /**< set by sr_model_init: a model never initialised lacks it */
    uint64_t sums[SR_MODEL_NSUMS];       /**< one checksum per read set, set by sr_model_init */
} sr_model;

/** Human-readable name of a status code (static string, never NULL). */
const char *sr_status_string(int status);

/** @name Parameter rules
 * The rules a parameter vector must obey, in the order sr_check_params tests them. */
/** @{ */
#define SR_PARAM_RULE_NONE 0         /**< no rule broken */
#define SR_PARAM_RULE_FINITE 1       /**< every parameter finite */
#define SR_PARAM_RULE_POSITIVE 2     /**< general: r, m_S, j_S, m_Y, m_P > 0; paper: r, m_S, b, h, m_b, m_h, l, m_P > 0 */
#define SR_PARAM_RULE_NONNEGATIVE 3  /**< k_S, k_Y, k_P, g >= 0; general also j_mY, j_mP >= 0 */
#define SR_PARAM_RULE_YOKE_FITS 4    /**< paper: yoke half-diagonal sqrt(b^2 + h^2)/2 <= r */
#define SR_PARAM_RULE_PENDULUM_FITS 5 /**< paper: l <= r */
#define SR_PARAM_RULE_NONZERO 6      /**< general: gear ratios n_Y, n_P != 0 */
#define SR_PARAM_RULE_INERTIA 7      /**< general: J_Y, J_P physical: tr(J)/2 I - J (the second
                                        moment of the mass) positive semidefinite, that is J positive
                                        semidefinite with the triangle inequalities */
#define SR_PARAM_RULE_INSIDE 8       /**< general: centres of mass inside the shell, |c_Y|, |c_P| < r */
#define SR_PARAM_RULE_SLOPE 9        /**< general: |slope| < pi/2 */
/** @} */

/** The one place that decides whether params are in their physical range (sr_model_init and
 * the Python runtime's Params call it).  Tests the rules above in order and, for the first
 * one broken, writes its SR_PARAM_RULE_* code to *rule and the index (SR_P_*) of the first
 * parameter that breaks it to *bad_index (for a tensor, its J_*_xx; for a centre, its c_*_x);
 * with every rule kept, SR_PARAM_RULE_NONE and -1.  bad_index and rule may be NULL.
 * Returns SR_OK, SR_ERR_NULL (params), SR_ERR_NONFINITE (rule FINITE) or SR_ERR_PARAM. */
int sr_check_params(const sr_real params[SR_NPARAM], int *bad_index, int *rule);

/** The same for the paper's twelve parameters (index SR_PAPER_*; the yoke rule reports
 * SR_PAPER_b, the pendulum rule SR_PAPER_l). */
int sr_check_paper_params(const sr_real paper[SR_NPAPER], int *bad_index, int *rule);

/** The paper's robot (Section 2.3: a yoke of four uniform rods, a slender pendulum rod, a thin
 * shell, massless motors, level floor) as params: checks paper (sr_check_paper_params) and
 * writes params.  Returns SR_OK, SR_ERR_NULL, SR_ERR_NONFINITE or SR_ERR_PARAM. */
int sr_paper_params(const sr_real paper[SR_NPAPER], sr_real params[SR_NPARAM]);

/** The conversion of sr_paper_params without the paper's rules: for batch tools that hand each
 * sample to sr_simulate_batch, whose sr_model_init then judges it (a negative rod mass gives a
 * negative m_Y, SR_ERR_PARAM for that sample alone).  Returns SR_OK, SR_ERR_NULL or
 * SR_ERR_NONFINITE (a result not finite; params untouched). */
int sr_paper_params_unchecked(const sr_real paper[SR_NPAPER], sr_real params[SR_NPARAM]);

/** The text of a rule of sr_check_params ("must be > 0", ...; static string, never NULL). */
const char *sr_param_rule_string(int rule);

/** Validate params (sr_check_params) and fill *model, choosing the kernels (see sr_model).  The derived
 * constants, M and the energy at the reference state (R_S = R_Y = R_P = I, q = (0, 0, r), at
 * rest) must be finite (else SR_ERR_PARAM: a value so large that it overflows), and M there
 * positive definite (else SR_ERR_SINGULAR: values so small that the inertias underflow).
 * Returns SR_OK, SR_ERR_NULL, SR_ERR_NONFINITE, SR_ERR_PARAM or SR_ERR_SINGULAR; *model is
 * untouched on error. */
int sr_model_init(sr_model *model, const sr_real params[SR_NPARAM]);

/** The full re-check of a model: its stamp, and its constants, kind and checksums exactly those
 * that sr_model_init makes of its parameters p (the other entry points check the checksums of
 * what they read only).  Costs about one sr_model_init.  SR_OK, SR_ERR_NULL or SR_ERR_MODEL. */
int sr_check_model(const sr_model *model);

/** Full state check: finite entries, R_S orthonormal with det +1, R_Y a rotation
 * about x, R_P a rotation about y (to SR_ROTATION_TOL), |q_z - r| <= SR_ROTATION_TOL*r.
 * Returns SR_OK, SR_ERR_NULL, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION or SR_ERR_CONSTRAINT. */
int sr_check_state(const sr_model *model, const sr_real x[SR_NX]);

/** sr_check_state over n states (x is n x SR_NX, row-major).  Stops at the first failing row,
 * whose index goes to *failed_row (if not NULL; -1 when all rows pass). */
int sr_check_state_batch(const sr_model *model, long n, const sr_real *x, long *failed_row);

/** Accelerations a = d(nu)/dt at state x under torques u (u may be NULL: zero torque).
 * Cheap checks only: finiteness of x and u, |gamma| = 1 and the unit columns of R_Y, R_P
 * that the model reads (call sr_check_state once for the full check).  Returns SR_OK or an
 * error code (SR_ERR_NONFINITE also when the result overflows); a is untouched on error.
 * The same holds for sr_inertia, sr_rhs, sr_energy and sr_equilibrium_residual: every output
 * is either fully written and finite (SR_OK) or untouched. */
int sr_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV]);

/** sr_accel over n states: x is n x SR_NX, u is n x SR_NU (or NULL), a is n x SR_NV,
 * all row-major.  Stops at the first failing row, whose index goes to *failed_row
 * (if not NULL; -1 when all rows succeed); only the rows before it are written.
 * Each row's result and status are sr_accel's, bit for bit: the rows go through a vectorised
 * form of the checks and the kernel 64 at a time (sr_gen_accel_lanes; GCC vectorises it at -O3,
 * docs/sweeps.md "The batch accel"), and any row that form does not clear through sr_accel itself. */
int sr_accel_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                   sr_real *a, long *failed_row);

/** sr_check_state, then sr_accel, on each of n states, as sr_accel_batch (what the Python
 * Model.accel does for a batch): the full state check at little cost over sr_accel_batch. */
int sr_checked_accel_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                           sr_real *a, long *failed_row);

/** Generalized inertia M (row-major 5x5): kinetic energy = 1/2 nu^T M nu [kg m^2]. */
int sr_inertia(const sr_model *model, const sr_real x[SR_NX], sr_real M[SR_NV * SR_NV]);

/** Right-hand side f of M d(nu)/dt = f [N m]. */
int sr_rhs(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real f[SR_NV]);

/** Total energy [J]: 1/2 nu^T M nu + m_P g e_z^T (q + R_S R_Y R_P cbar_P). */
int sr_energy(const sr_model *model, const sr_real x[SR_NX], sr_real *energy);

/** Generalized gravity torques at rest (f at nu = 0, u = 0) [N m]; zero exactly at the
 * equilibria R_S R_Y R_P e_z = +-e_z of equation (108). */
int sr_equilibrium_residual(const sr_model *model, const sr_real x[SR_NX], sr_real res[SR_NV]);

/** Contact force F = (F_x, F_y, F_z) [N] of the floor on the shell at the contact point, in the
 * plane frame (x up the slope, z the floor's normal: F_z is the normal force, (F_x, F_y) the
 * friction that rolling without slipping needs), at state x under torques u (u may be NULL: zero
 * torque).  From the balance of the total momentum, F = sum_B m_B p''_B - m_R g_vec (derive/contact.py),
 * with the accelerations of sr_accel.  The checks and status codes are sr_accel's (SR_ERR_MODEL
 * first, then SR_ERR_NULL, then the state's cheap checks); F is written only on SR_OK. */
int sr_contact_force(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real F[3]);

/** sr_check_state, then sr_contact_force, on each of n states: x is n x SR_NX, u is n x SR_NU (or
 * NULL), F is n x 3, all row-major.  Stops at the first failing row, whose index goes to
 * *failed_row (if not NULL; -1 when all rows succeed); only the rows before it are written. */
int sr_contact_force_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real *F,
                           long *failed_row);

/** atan2(y, x) as the library computes it (its controllers' headings and pendulum angles): in
 * double the library's own, the same bits on every platform (within 2 ulp of the exact value, with
 * C99's values at zeros and infinities), so that a firmware computing its targets with it matches
 * its host build bit for bit; in float libm's atan2f (or libm's atan2 with -DSR_LIBM_TRIG).  Writes
 * *angle in [-pi, pi].  Returns SR_OK, SR_ERR_NULL (angle) or SR_ERR_NONFINITE (y or x NaN or
 * infinite; *angle untouched). */
int sr_atan2(sr_real y, sr_real x, sr_real *angle);

/** R = Exp([[w]]) by Rodrigues' formula, with a series branch for |w| < 1e-4 rad.
 * SR_ERR_NONFINITE (R untouched) if w is not finite or |w|^2 overflows. */
int sr_so3_exp(const sr_real w[3], sr_real R[9]);

/** One step of size dt > 0 with constant torques u (NULL: zero) from x to x_next
 * (x_next may alias x).  method: SR_LIE_EULER, SR_RKMK4 or SR_CF4.  x gets the full check
 * (sr_check_state: SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT), so a loop of
 * single steps stops at a corrupt state instead of carrying it on; the check costs about a
 * fifth of a Lie-Euler step.  x_next is written only on SR_OK (a non-finite new state gives
 * SR_ERR_NONFINITE). */
int sr_step(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
            sr_real dt, sr_real x_next[SR_NX]);

/** @{ */
/** sr_step with the method fixed (no projection): the same bits and status codes as
 * sr_step(model, SR_LIE_EULER / SR_RKMK4 / SR_CF4, ...), to which sr_step dispatches.  Each one
 * reaches only its own method's code: a firmware that calls sr_step_lie_euler alone (and
 * neither sr_step nor the drivers), compiled with -ffunction-sections and linked with
 * --gc-sections, links no fourth-order code (docs/embedding.md). */
int sr_step_lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                      sr_real x_next[SR_NX]);
int sr_step_rkmk4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                  sr_real x_next[SR_NX]);
int sr_step_cf4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                sr_real x_next[SR_NX]);
/** @} */

/** sr_step on n states of one robot (x n x SR_NX, u n x SR_NU or NULL, x_next n x SR_NX; x_next may
 * equal x, and must not overlap it otherwise), for particle filters, sampling-based controllers
 * and Monte Carlo over initial states (c/src/sr_step_batch.c).  Every row gets exactly the
 * bits and the status code sr_step gives it; the call stops at the first failing row (its index
 * in *failed_row, -1 when all succeed) and writes no row after it.  For SR_LIE_EULER, SR_RKMK4 and
 * SR_CF4 and a robot of the paper's geometry it is vectorised across the states (16 at a time, in
 * loops without branches: build with -O3; a row with a step angle of 1/4 rad or more, or anything
 * else the lanes do not clear, goes through sr_step); the projected methods and general robots go
 * row by row.  Stack: about 18 KB in double (five blocks of stage data). */
int sr_step_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u, sr_real dt,
                  sr_real *x_next, long *failed_row);

/** steps steps of size dt from x0: traj[(steps+1) x SR_NX] receives x0 and every state after;
 * u is steps x SR_NU (torque held over each step) or NULL.  x0 gets the full check
 * (sr_check_state).  Guards: the state is checked for finiteness after every step
 * (SR_ERR_NONFINITE), and fully (SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT: the rotations or
 * q_z drifted beyond SR_ROTATION_TOL) every SR_GUARD_INTERVAL steps and after the last.
 * On an error at step k (1-based: a bad torque of step k, a failing kernel, or a guard failing
 * on the state after step k), *steps_done = k-1 and traj rows 0..k-1 are valid; row k may have
 * been written (with the offending state, for a guard), rows after k are untouched.
 * Rounding: for SR_RKMK4 and SR_CF4 the update x + increment is Kahan-compensated across the
 * steps of one call (a resting robot's constant sub-ulp increments would otherwise round the
 * same way every step and grow |R^T R - I| linearly), so sr_simulate may differ from repeated
 * sr_step calls in the last bits; SR_LIE_EULER is the paper's plain eq. (111) in both.  The
 * compensation needs IEEE arithmetic: do not compile with -ffast-math. */
int sr_simulate(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt, long steps,
                const sr_real *u, sr_real *traj, long *steps_done);

/** Energy guard of sr_simulate_guarded.  Over a torque-free stretch (steps whose torques are
 * both exactly 0: no input power) the exact energy cannot rise, since the damping is >= 0.
 * The guard fails the run with SR_ERR_ENERGY when, at a check (the same steps as the state
 * checks), the energy E exceeds
 *     E_start + tol * scale + 64 eps (|E_start| + scale),
 * E_start being the energy at the start of the stretch and scale its kinetic energy plus
 * m_P g l (the swing of the pendulum's potential energy); the last term absorbs rounding.
 * A non-zero torque ends the stretch; the next torque-free step starts a new one.
 * Set tol (< 0 disables the guard) and in_stretch = 0 before a run; to continue a run in
 * chunks, pass the same struct again: it carries the stretch across calls. */
typedef struct sr_energy_guard {
    sr_real tol;      /**< in: allowed rise as a fraction of scale; < 0: no energy guard */
    int in_stretch;   /**< in/out: nonzero inside a torque-free stretch */
    sr_real e_start;  /**< in/out: energy at the start of the stretch [J] */
    sr_real scale;    /**< in/out: kinetic energy at the start of the stretch + m_P g l [J] */
    sr_real energy;   /**< out: energy at the last check [J] (at the failing one on SR_ERR_ENERGY) */
} sr_energy_guard;

/** sr_simulate with the energy guard (guard may be NULL: same as sr_simulate). */
int sr_simulate_guarded(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt,
                        long steps, const sr_real *u, sr_energy_guard *guard, sr_real *traj,
                        long *steps_done);

/** Counters of sr_simulate_adaptive. */
typedef struct sr_adaptive_stats {
    long accepted;    /**< accepted steps */
    long rejected;    /**< rejected step attempts (error estimate above tolerance) */
    long evaluations; /**< calls of the acceleration kernel */
    long rows_done;   /**< output rows written, x0 included: traj rows 0..rows_done-1 are valid */
    sr_real h_next;   /**< step-size proposal at exit: pass it as h_init to continue a run */
} sr_adaptive_stats;

/** Adaptive RKMK4 with output on the fixed grid t_k = k*dt_out, k = 0..n_out:
 * traj[(n_out+1) x SR_NX] receives x0 and the state at every t_k.  Steps land exactly on the
 * grid points (no interpolation), so the torque may jump there: u is n_out x SR_NU, row k held
 * over [t_k, t_k+1) (NULL: zero torque).
 *   method: SR_RKMK4, optionally | SR_PROJECT.  The error estimate comes from the RK4(3) pair
 *   with the "first same as last" stage: the 3rd-order weights (1/6, 1/3, 1/3, 0, 1/6) use the
 *   stage at the new point, so the estimate is dt/6 (K4 - K5) in the Lie algebra and an
 *   accepted step costs 4 acceleration evaluations (5 after a torque change).  The 4th-order
 *   solution is propagated (local extrapolation); the global error is typically ~3 rtol.
 * Error test (max norm): every component e_i of the estimate satisfies |e_i| <= atol + rtol*s_i,
 * with s_i = 1 for the 5 rotation angles and s_i = max(|old_i|, |new_i|) for q and nu.
 * Step-size control: h *= clamp(0.9 err^(-1/4), 0.2, 5) (no growth right after a rejection).
 *   rtol, atol >= 0 with rtol + atol > 0; h_init > 0 the first trial step, or <= 0 for
 *   min(dt_out, 0.1*tol^(1/4)) with tol = max(rtol, atol); max_steps > 0 bounds the step
 *   attempts (accepted + rejected).  stats may be NULL.
 * x0 gets the full check (sr_check_state).
 * Returns SR_OK, SR_ERR_NULL, SR_ERR_ARG, SR_ERR_NONFINITE (x0 or u or the state),
 * SR_ERR_NOT_ROTATION or SR_ERR_CONSTRAINT (x0), SR_ERR_SINGULAR, SR_ERR_STEP_SIZE or
 * SR_ERR_MAX_STEPS; on error the valid rows are reported in stats->rows_done (the rows after
 * them are untouched). */
int sr_simulate_adaptive(const sr_model *model, int method, const sr_real x0[SR_NX], sr_real dt_out,
                         long n_out, const sr_real *u, sr_real rtol, sr_real atol, sr_real h_init,
                         long max_steps, sr_real *traj, sr_adaptive_stats *stats);

/* ---- Many robots in one call (c/src/sr_batch.c) ---------------------------------------------- */
#ifdef SR_USE_FLOAT
#define sr_simulate_batch sr_simulate_batch_f
#endif

/** Summary metrics of one simulated sample, SR_BATCH_NMETRICS numbers in this order. */
#define SR_BATCH_NMETRICS 4
#define SR_BATCH_PATH_LENGTH 0    /**< length of the path of the shell centre q, sum of |q_k+1 - q_k| [m] */
#define SR_BATCH_MAX_DISTANCE 1   /**< largest distance |q_k - q_0| from the start [m] */
#define SR_BATCH_MAX_SHELL_RATE 2 /**< largest shell angular speed |w_S| over the rows [rad/s] */
#define SR_BATCH_FINAL_ENERGY 3   /**< total energy of the final state (sr_energy) [J] */

/** n independent runs of sr_simulate_guarded, one per sample i, each with its own parameters,
 * initial state and torque program:
 *   params + i*params_stride  [SR_NPARAM]       (stride 0: every sample has the same parameters)
 *   x0 + i*x0_stride          [SR_NX]           (stride 0: the same initial state)
 *   u + i*u_stride            [steps x SR_NU]   (stride 0: the same program; u NULL: zero torque)
 * with the same method, dt, steps and energy guard tolerance energy_tol (< 0: no energy guard;
 * see sr_energy_guard).  Sample i is exactly the run "sr_model_init, then sr_simulate_guarded in
 * consecutive calls of chunk_steps steps (the last one shorter), one sr_energy_guard carried
 * across them": the same bits as a caller making those calls (the Kahan compensation of the
 * fourth-order methods restarts with every call, so chunk_steps is part of the result).
 * Outputs (any of traj, x_final, metrics may be NULL; traj and work not both):
 *   traj     n x (steps+1) x SR_NX: every sample's trajectory, x0 included (rows past a
 *            failure as in sr_simulate); when NULL, work holds one chunk instead:
 *   work     (chunk_steps+1) x SR_NX scratch rows, reused by every sample (unused with traj)
 *   x_final  n x SR_NX: the state after the last step
 *   metrics  n x SR_BATCH_NMETRICS: the summary metrics above, over rows 0..steps
 *   status   n: the status of each sample: SR_OK, or the error of sr_model_init (its
 *            parameters), sr_check_state (its x0), sr_simulate_guarded (its run) or
 *            sr_energy (SR_ERR_NONFINITE with steps_done = steps: every step ran, but the final
 *            energy, or the path length or a distance of far-out positions, overflowed, so the
 *            sample has no finite metrics)
 *   steps_done n: the steps completed before the sample stopped (steps on SR_OK)
 * One failing sample never touches another's outputs; its own x_final and metrics rows are
 * left untouched.  status[i] and steps_done[i] are written when sample i is finished, in
 * order of i.  Returns SR_ERR_NULL or SR_ERR_ARG (n, steps or a stride < 0, chunk_steps < 1,
 * dt not positive and finite, an unknown method, energy_tol infinite) before running any
 * sample, else SR_OK: the outcome of each sample is in status. */
int sr_simulate_batch(int method, long n, const sr_real *params, long params_stride, const sr_real *x0,
                      long x0_stride, sr_real dt, long steps, const sr_real *u, long u_stride,
                      sr_real energy_tol, long chunk_steps, sr_real *work, sr_real *traj,
                      sr_real *x_final, sr_real *metrics, int *status, long *steps_done);

/* ---- The state on its group: error coordinates (c/src/sr_group.c) ------------------------------ */
#ifdef SR_USE_FLOAT
#define sr_retract sr_retract_f
#define sr_local sr_local_f
#define sr_retract_batch sr_retract_batch_f
#define sr_local_batch sr_local_batch_f
#endif

/** @{ */
/** The error state d[SR_NE] = 12 entries (offsets SR_E_* of sr_generated.h), the
 * right-trivialised tangent coordinates in which every Jacobian of this library is expressed:
 *   d[SR_E_xi_S + 0..2]  shell rotation vector, R_S <- R_S Exp([[d]])          [rad]
 *   d[SR_E_th_Y]         yoke angle, R_Y <- R_Y Exp(d Sigma_Y)                  [rad]
 *   d[SR_E_th_P]         pendulum angle, R_P <- R_P Exp(d Sigma_P)              [rad]
 *   d[SR_E_q + 0..1]     shell centre along the plane's x and y axes, q_z kept  [m]
 *   d[SR_E_nu + 0..4]    nu <- nu + d (w_S, w_Y, w_P)                           [rad/s]
 * sr_retract gives y = x (+) d for every finite d (the exponentials are exact for every angle).
 * sr_local gives d = y (-) x, its inverse: Log(R_S^T R_S') with |xi| <= pi (accurate near pi,
 * where the axis is taken from the symmetric part), the joint angle differences in (-pi, pi],
 * the in-plane difference of q, the difference of nu.  So local(x, retract(x, d)) = d whenever
 * |d_xi_S| < pi and |d_th_Y|, |d_th_P| < pi, and retract(x, local(x, y)) = y for all valid x, y.
 * Both check their states in full (sr_check_state) and d for finiteness; they return SR_OK,
 * SR_ERR_NULL, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION or SR_ERR_CONSTRAINT and write their
 * output only on SR_OK (y may alias x in sr_retract). */
int sr_retract(const sr_model *model, const sr_real x[SR_NX], const sr_real d[SR_NE], sr_real y[SR_NX]);
int sr_local(const sr_model *model, const sr_real x[SR_NX], const sr_real y[SR_NX], sr_real d[SR_NE]);
/** @} */

/** @{ */
/** The same over n rows (x, y n x SR_NX, d n x SR_NE, row-major); stops at the first failing row,
 * whose index goes to *failed_row (if not NULL; -1 when all rows succeed).  n < 0: SR_ERR_ARG. */
int sr_retract_batch(const sr_model *model, long n, const sr_real *x, const sr_real *d, sr_real *y,
                     long *failed_row);
int sr_local_batch(const sr_model *model, long n, const sr_real *x, const sr_real *y, sr_real *d,
                   long *failed_row);
/** @} */

/* ---- Derivatives of the dynamics (c/src/sr_jacobians.c) ------------------------------------------ */
#ifdef SR_USE_FLOAT
#define sr_accel_jacobian sr_accel_jacobian_f
#define sr_accel_jacobian_batch sr_accel_jacobian_batch_f
#define sr_step_jacobian_lie_euler sr_step_jacobian_lie_euler_f
#define sr_step_jacobian_lie_euler_batch sr_step_jacobian_lie_euler_batch_f
#define sr_step_jacobian_rkmk4 sr_step_jacobian_rkmk4_f
#define sr_step_jacobian_cf4 sr_step_jacobian_cf4_f
#define sr_step_jacobian sr_step_jacobian_f
#define sr_step_jacobian_batch sr_step_jacobian_batch_f
#define sr_accel_param_jacobian sr_accel_param_jacobian_f
#define sr_accel_param_jacobian_batch sr_accel_param_jacobian_batch_f
#define sr_step_param_jacobian sr_step_param_jacobian_f
#define sr_step_param_jacobian_batch sr_step_param_jacobian_batch_f
#define sr_step_param_jacobian_fd_batch sr_step_param_jacobian_fd_batch_f
#define sr_step_param_jacobian_cols_batch sr_step_param_jacobian_cols_batch_f
#define sr_step_and_param_jacobian_cols_batch sr_step_and_param_jacobian_cols_batch_f
#define sr_accel_param_jacobian_cols_batch sr_accel_param_jacobian_cols_batch_f
#define sr_step_jacobian_param_cols_batch sr_step_jacobian_param_cols_batch_f
#define sr_regressor sr_regressor_f
#define sr_regressor_batch sr_regressor_batch_f
#endif

/** Jacobians of the accelerations in the error coordinates:
 *   nu'(x (+) d, u + w) = nu'(x, u) + Ja d + Jb w + O(|d|^2 + |w|^2),
 * Ja row-major SR_NV x SR_NE, Jb row-major SR_NV x SR_NU.  Derived symbolically from the same
 * derivation as sr_accel (derive/derivatives.py): d(nu') = M^-1 (df - (dM) nu'), one
 * factorisation of M for nu' and every column.  For a robot of the paper's geometry in the yoke
 * frame, as sr_accel (SR_GEN_ACCEL_JACOBIAN_YOKE_TERMS_FLOPS, then the joint-first solve of 11
 * columns and the chain rule through R_Y); for a general robot in the shell frame
 * (SR_GEN_GENERAL_ACCEL_JACOBIAN_TERMS_FLOPS, then a Cholesky solve).  Checks and status codes as
 * sr_accel (u may be NULL: zero torque); the outputs are written only on SR_OK. */
int sr_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                      sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU]);

/** The same over n rows (x n x SR_NX, u n x SR_NU or NULL, Ja n x SR_NV x SR_NE, Jb n x SR_NV x
 * SR_NU); stops at the first failing row, its index in *failed_row (-1 when all succeed). */
int sr_accel_jacobian_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                            sr_real *Ja, sr_real *Jb, long *failed_row);

/** Jacobians of one Lie-Euler step (sr_step_lie_euler) in the error coordinates:
 *   step(x (+) d, u + w) (-) step(x, u) = F d + G w + O(|d|^2 + |w|^2),
 * F row-major SR_NE x SR_NE, G row-major SR_NE x SR_NU: the exact derivative of the map as
 * implemented (R_S Exp(h w_S) through the right Jacobian of SO(3), the joint angles, q by the
 * rolling kinematics, nu by sr_accel_jacobian).  Checks and status codes as sr_step_lie_euler
 * (the full state check; dt > 0 and finite, else SR_ERR_ARG; u may be NULL); outputs written
 * only on SR_OK. */
int sr_step_jacobian_lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                               sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU]);

/** The same over n rows (x n x SR_NX, u n x SR_NU or NULL, F n x SR_NE x SR_NE, G n x SR_NE x SR_NU),
 * one dt; stops at the first failing row, its index in *failed_row (-1 when all succeed). */
int sr_step_jacobian_lie_euler_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real dt,
                                     sr_real *F, sr_real *G, long *failed_row);

/** @{ */
/** The same for one RKMK4 and one CF4 step (c/src/sr_step_jacobians.c): the exact derivatives of the
 * steps of c/src/sr_steppers.c, stage by stage (an accel Jacobian at each of the four stage states,
 * dexp^-1 differentiated for RKMK4); checks, status codes and outputs as
 * sr_step_jacobian_lie_euler.  Built with -DSR_CLONES on x86-64 (GCC, glibc), each is compiled
 * for AVX2 too and the loader picks (SR_JACOBIAN_CLONES, sr_real.h). */
int sr_step_jacobian_rkmk4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                           sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU]);
int sr_step_jacobian_cf4(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                         sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU]);
/** @} */

/** @{ */
/** The step Jacobian of any method (SR_LIE_EULER, SR_RKMK4, SR_CF4; no SR_PROJECT): SR_ERR_ARG for
 * another; and over n rows (x n x SR_NX, u n x SR_NU or NULL, F n x SR_NE^2, G n x SR_NE*SR_NU),
 * stopping at the first failing row (its index in *failed_row, -1 when all succeed). */
int sr_step_jacobian(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real dt,
                     sr_real F[SR_NE * SR_NE], sr_real G[SR_NE * SR_NU]);
int sr_step_jacobian_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u, sr_real dt,
                           sr_real *F, sr_real *G, long *failed_row);
/** @} */

/** @name Derivatives in the parameters and the regressor (c/src/sr_param_jacobians.c) */
/** @{ */
/** Entries of pi, the parameters the equations of motion are linear in (the regressor's columns,
 * SR_PI_* of sr_generated.h): m_S, j_S, k_S; for the yoke and then the pendulum its mass, first
 * moment m c (3, body frame), standard inertia tensor about the shell centre O,
 * J + m (|c|^2 I - c c^T) (xx, yy, zz, xy, xz, yz), damping; then j_mY, j_mP. */
#define SR_NPI SR_GEN_NPI

/** Jacobian of the accelerations in the parameters, the state and the torques held:
 *   nu'(x, u; p + dp) = nu'(x, u; p) + J dp + O(|dp|^2),
 * J row-major SR_NV x SR_NPARAM, columns SR_P_*.  From M nu' = f: J = -M^-1 d(M nu' - f)/dp with
 * nu' held in the bracket (derive/param_derivatives.py, SR_GEN_GENERAL_PARAM_RESIDUAL_JACOBIAN_FLOPS),
 * M by its Cholesky factor; a robot of the paper's geometry is evaluated with the general kernels,
 * so that every parameter has its column.  Checks in the order of every entry point: the model
 * (SR_ERR_NULL, SR_ERR_MODEL), the pointers (SR_ERR_NULL; u may be NULL: zero torque), then the
 * full state check (sr_check_state) and u finite; SR_ERR_SINGULAR, SR_ERR_NONFINITE as sr_accel.
 * J is written only on SR_OK. */
int sr_accel_param_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                            sr_real J[SR_NV * SR_NPARAM]);

/** The same over n rows (x n x SR_NX, u n x SR_NU or NULL, J n x SR_NV x SR_NPARAM); stops at the
 * first failing row, its index in *failed_row (-1 when all succeed). */
int sr_accel_param_jacobian_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real *J,
                                  long *failed_row);

/** Sensitivity of one step to the parameters, in the error coordinates, the state and the torque held:
 *   step(x, u; p + dp) (-) step(x, u; p) = Jp dp + O(|dp|^2),
 * Jp row-major SR_NE x SR_NPARAM: the exact derivative of the step of sr_steppers.c as implemented,
 * by the chain rule through its stages (sr_accel_param_jacobian and sr_accel_jacobian at each stage
 * state, the rolling kinematics' r, RKMK4's dexp^-1 differentiated).  method: SR_LIE_EULER or
 * SR_RKMK4, else SR_ERR_ARG; checks and status codes as sr_step_jacobian; Jp written only on SR_OK. */
int sr_step_param_jacobian(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                           sr_real dt, sr_real Jp[SR_NE * SR_NPARAM]);

/** The same over n rows (x n x SR_NX, u n x SR_NU or NULL, Jp n x SR_NE x SR_NPARAM), one method
 * and dt; stops at the first failing row, its index in *failed_row (-1 when all succeed). */
int sr_step_param_jacobian_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                 sr_real dt, sr_real *Jp, long *failed_row);

/** sr_step_param_jacobian_batch on the columns cols[0..ncols) (SR_P_*) only, in their order:
 * Jp n x SR_NE x ncols row-major, equal to those columns of sr_step_param_jacobian.  The stages run
 * on those columns alone, so a sensitivity to a few parameters costs a fraction of all of them.  Checks: the model, the pointers (SR_ERR_NULL), 1 <= ncols <= SR_NPARAM
 * and every column an index of p, method SR_LIE_EULER or SR_RKMK4, dt (SR_ERR_ARG); then per row
 * as sr_step_param_jacobian, stopping at the first failing row, its index in *failed_row (-1 when
 * all succeed); the rows before it are written. */
int sr_step_param_jacobian_cols_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                      sr_real dt, int ncols, const int *cols, sr_real *Jp, long *failed_row);

/** sr_step_param_jacobian_cols_batch that also writes each row's step, x_next n x SR_NX: the end
 * state of the same stages (x . exp(Theta), Theta summed from the stages' K as the stepper sums
 * them), so a fit that needs the step and its sensitivity pays for the stages once.  x_next equals
 * sr_step's to rounding (the stages solve M nu' = f by the parameter path's Cholesky factor, not by
 * sr_accel's solve).  Checks and status codes as sr_step_param_jacobian_cols_batch (x_next too not
 * NULL; SR_ERR_NONFINITE also for a non-finite end state); the rows before a failing one are written. */
int sr_step_and_param_jacobian_cols_batch(const sr_model *model, int method, long n, const sr_real *x,
                                          const sr_real *u, sr_real dt, int ncols, const int *cols, sr_real *x_next,
                                          sr_real *Jp, long *failed_row);

/** The step's state Jacobian F (sr_step_jacobian's, n x SR_NE x SR_NE row-major) and its parameter
 * sensitivity on the columns cols[0..ncols) (sr_step_param_jacobian_cols_batch's Jp, n x SR_NE x
 * ncols) at the same states, at once: F's columns run through the parameter columns' stages, so
 * each stage's derivative kernel and factorisation serve both (what a fit that asks for both costs
 * less than the two calls).  F equals sr_step_jacobian's to rounding, Jp those columns of
 * sr_step_param_jacobian.  Checks and status codes as sr_step_param_jacobian_cols_batch (F too
 * not NULL); the rows before a failing one are written. */
int sr_step_jacobian_param_cols_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                      sr_real dt, int ncols, const int *cols, sr_real *F, sr_real *Jp,
                                      long *failed_row);

/** sr_accel_param_jacobian_batch on the columns cols[0..ncols) (SR_P_*) only, in their order: J n x
 * SR_NV x ncols row-major, equal to those columns of sr_accel_param_jacobian.  Checks as
 * sr_step_param_jacobian_cols_batch (no method, no dt). */
int sr_accel_param_jacobian_cols_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, int ncols,
                                       const int *cols, sr_real *J, long *failed_row);

/** Entries of work per state that sr_step_param_jacobian_fd_batch needs. */
#define SR_PARAM_FD_WORK (4 * SR_NX + 2 * SR_NE)

/** The sensitivity of a step to the parameters cols[0..ncols) (SR_P_*) by finite differences,
 * batched (c/src/sr_param_fd.c): per column, the robot at p +- h (h about the cube root of the
 * rounding unit relative to p_j, absolute for a zero p_j), one sr_step_batch of all n states each
 * side, sr_local_batch against the model's own step and the central difference; a parameter at a
 * bound of its rule (a side that sr_check_params refuses) takes the one-sided second-order
 * difference from the valid side.  What sr_step_param_jacobian computes exactly, to O(h^2); the
 * reference it is timed against and a fit's Jacobian without it.  Jp n x SR_NE x ncols row-major;
 * work n * SR_PARAM_FD_WORK entries, the caller's.  Checks: the model, the pointers (SR_ERR_NULL),
 * method SR_LIE_EULER or SR_RKMK4, dt, ncols >= 1 and every column an index of p (SR_ERR_ARG);
 * SR_ERR_PARAM for a column with no valid robot on either side; otherwise the status of the first
 * failing step or local map, its row in *failed_row (-1 when all succeed). */
int sr_step_param_jacobian_fd_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                    sr_real dt, int ncols, const int *cols, sr_real *Jp, sr_real *work,
                                    long *failed_row);

/** The regressor Y (row-major SR_NV x SR_NPI, columns SR_PI_*) of the model's robot at state x and
 * accelerations nudot: M nu' - f(u = 0) = Y pi for the robot's pi, so that along any motion
 * Y pi = (0, 0, 0, u_Y, u_P).  Y depends on the parameters only through r, n_Y, n_P, g and slope.
 * Checks: the model, the pointers (SR_ERR_NULL), sr_check_state, nudot finite (SR_ERR_NONFINITE);
 * Y written only on SR_OK. */
int sr_regressor(const sr_model *model, const sr_real x[SR_NX], const sr_real nudot[SR_NV],
                 sr_real Y[SR_NV * SR_NPI]);

/** The same over n rows (x n x SR_NX, nudot n x SR_NV, Y n x SR_NV x SR_NPI); stops at the first
 * failing row, its index in *failed_row (-1 when all succeed). */
int sr_regressor_batch(const sr_model *model, long n, const sr_real *x, const sr_real *nudot, sr_real *Y,
                       long *failed_row);
/** @} */

/** @name The firmware controller: LQR gain-scheduled on speed and curvature (c/src/sr_control.c)
 *
 * The controller acts through the two motor torques only.  It measures the state
 * against a reference that rolls at speed v_ref along the heading psi_ref (the heading to hold,
 * or a path's tangent at the point nearest to the robot, with the path's curvature kappa and the
 * signed cross-track error e_y, left positive), in the error coordinates z[SR_LQR_NZ]:
 *   z[0..2]  E = Log(Q_ref^T Q): the yoke's attitude in the world, Q = R_S R_Y, against
 *            Q_ref = rot_z(psi_ref - pi/2) (the yoke upright, rolling along psi_ref)       [rad]
 *   z[3]     the pendulum's angle theta_P                                                 [rad]
 *   z[4..6]  R_Y^T w_S - (-v_ref / r, 0, 0): the shell's rate in the yoke's frame       [rad/s]
 *   z[7]     w_Y - v_ref / r;   z[8]  w_P                                               [rad/s]
 *   z[9]     e_y (path references; 0 otherwise)                                           [m]
 *   z[10]    the integral of e_y;  z[11]  the integral of z[4] - z*[4]          [m s], [rad]
 * In these coordinates steady rolling on a path of constant curvature is an equilibrium (the
 * shell is a uniform sphere: its phase about the yoke's hinge does not enter the dynamics), so
 * the law is time-invariant: u = u* - K (z - z*), with the operating point (z*, u*) and the gain
 * K interpolated bilinearly in (v_ref, kappa) over a grid designed offline
 * (runtime/control/lqr_design.py: Newton on the reduced dynamics, their linearisation, a
 * discrete Riccati equation at the controller's period; docs/control.md).  K_path is used for
 * path references, K_heading (whose e_y columns are zero) for speed and heading references.
 * The torques are clipped to +-u_max.  The integrators (z[10], z[11]) act at any error: each
 * advances by one period's step unless that step would push a clipped torque further past its
 * limit (conditional integration against the torque limits: with the interpolated gain K, the
 * step s_i of integrator i changes torque k by -K[k][10 + i] s_i; it is skipped when that change
 * has the sign of the torque's excess over u_max).  The cross-track integral also holds while the
 * error moves faster than steady_rate (|de_y/dt| > steady_rate, de_y/dt the contact point's
 * velocity along the path's normal): such an error, a line's initial offset or the first lean
 * into a circle, is a transient the loop is already removing, and integrating it would force an
 * overshoot of the same area.  So a steady offset of any size is integrated away, and nothing winds up
 * while a torque is held at its limit.  The curvature of the operating point follows the
 * reference's at most kappa_rate per second (a figure eight's switch of turn direction).
 * Near the path the law moves toward tighter gains, which hold the path closer under the
 * process noise but would saturate the torques on a transient (a start from rest, a large
 * offset): on path references with tight_band > 0 the gain's columns 0..9 are
 * (1 - w) K_path + w K_tight, with the weight w <= 1 - |e_y - e_y*| / tight_band, rising by at
 * most period / tight_rise per sample and not at all after a sample that clipped a torque;
 * after such a sample it falls by period / tight_fall instead (tight_fall > 0; 0: it holds), and
 * at once when the bound falls, w >= -tight_wait: below 0 the gain is K_path's (a wait before
 * the tight gains return).  Held at the limits, the tight gains on a robot off the model
 * switch the steering torque between them for seconds and the robot leaves the path.  The integral columns stay K_path's, so moving w moves no torque through the
 * integrals (the integrators carry over unchanged between the gains).
 * Heading references have the same mechanism on the heading: with heading_band > 0 the gain's
 * columns 0..9 are (1 - w) K_heading + w K_heading_tight, w <= 1 - |z[2] - z*[2]| / heading_band
 * (z[2], the yaw of the attitude error: the heading error), rising by at most
 * period / heading_rise per sample, after a clipped sample as above (tight_fall, tight_wait);
 * the integral columns stay K_heading's.  Stiffer heading gains hold the heading closer under
 * the process noise but, as a linear law on the saturating steering, lose a large step.
 * Recovery at a large error (recovery_cross_track, recovery_heading > 0; 0: off, the law above):
 * the law acts on the cross-track error e_y - e_y* clipped to +-recovery_cross_track and on the
 * heading error z[2] - z*[2] clipped to +-recovery_heading, so that far from the path the
 * steering asks for a bounded lean (a linear law asks for a lean that grows with the error, which
 * on a robot off the model swings the pendulum past the horizontal, where the lean no longer
 * steers).  While either error is beyond its bound the robot is recovering: the tight gains' weight
 * is held at 0 or below (K_path's or K_heading's gain), neither integral advances, and with
 * recovery_slow > 0 the speed reference is lowered by recovery_slow * r, the weight r rising by
 * period / recovery_rise per sample while recovering and falling by as much otherwise (the
 * operating point and the rolling-rate error taken at the lowered speed). */
/** @{ */
#define SR_LQR_NZ 12               /**< entries of the error coordinates z */
#ifndef SR_LQR_MAX_SPEEDS
#define SR_LQR_MAX_SPEEDS 6        /**< capacity of a schedule's speed grid (may be set at build time) */
#endif
#ifndef SR_LQR_MAX_CURVATURES
#define SR_LQR_MAX_CURVATURES 5    /**< capacity of its curvature grid (may be set at build time) */
#endif

#ifdef SR_USE_FLOAT
#define sr_lqr sr_lqr_f
#define sr_lqr_target sr_lqr_target_f
#define sr_lqr_memory sr_lqr_memory_f
#define sr_lqr_check sr_lqr_check_f
#define sr_lqr_reset sr_lqr_reset_f
#define sr_lqr_error sr_lqr_error_f
#define sr_lqr_control sr_lqr_control_f
#define sr_lqr_control_offsets sr_lqr_control_offsets_f
#define sr_lqr_slope_table sr_lqr_slope_table_f
#define sr_lqr_pendulum_table sr_lqr_pendulum_table_f
#define sr_lqr_offsets sr_lqr_offsets_f
#endif

#define SR_LQR_NPOINTS (SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES) /**< capacity of a schedule's grid points */
#define SR_LQR_NPENDULUM 4         /**< the pendulum's departure fed forward: (dm_P [kg], dc_P x, y, z [m]) */

/** The operating point's derivatives per radian of slope at each grid point (entry i * n_curvatures
 * + j, as sr_lqr's tables): the slope along the path (uphill ahead) and across it (uphill on the
 * robot's right), each the change of z* and u* that Newton's operating point of the flat design
 * makes on that slope, to first order (runtime/control/slope.py, SlopeSchedule). */
typedef struct sr_lqr_slope_table {
    sr_real dz_up[SR_LQR_NPOINTS][SR_LQR_NZ];    /**< dz* / d(slope along the path) [per rad] */
    sr_real du_up[SR_LQR_NPOINTS][SR_NU];        /**< du* / d(slope along the path) [N m per rad] */
    sr_real dz_right[SR_LQR_NPOINTS][SR_LQR_NZ]; /**< dz* / d(slope across, uphill on the right) */
    sr_real du_right[SR_LQR_NPOINTS][SR_NU];     /**< du* / d(slope across) */
} sr_lqr_slope_table;

/** The operating point's derivatives with respect to the pendulum's parameters at each grid point
 * (runtime/control/slope.py, PendulumSchedule): row k of dz[i] and du[i] per unit of entry k of
 * sr_lqr_offsets.pendulum (dm_P [kg], dc_P x, y, z [m]). */
typedef struct sr_lqr_pendulum_table {
    sr_real dz[SR_LQR_NPOINTS][SR_LQR_NPENDULUM][SR_LQR_NZ]; /**< dz* per unit of each pendulum entry */
    sr_real du[SR_LQR_NPOINTS][SR_LQR_NPENDULUM][SR_NU];     /**< du* [N m] per unit of each pendulum entry */
} sr_lqr_pendulum_table;

/** A gain schedule (read-only during control; fill it from the design, such as the header that
 * `python -m runtime.control.lqr --emit-c` writes).  Point (i, j) of the grid, speed i and
 * curvature j, is entry i * n_curvatures + j of z_star, u_star, K_path and K_heading
 * (K row-major 2 x SR_LQR_NZ). */
typedef struct sr_lqr {
    int n_speeds;                                   /**< 1 .. SR_LQR_MAX_SPEEDS */
    int n_curvatures;                               /**< 1 .. SR_LQR_MAX_CURVATURES */
    sr_real speeds[SR_LQR_MAX_SPEEDS];              /**< strictly increasing [m/s] */
    sr_real curvatures[SR_LQR_MAX_CURVATURES];      /**< strictly increasing [1/m] */
    sr_real z_star[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_LQR_NZ]; /**< the operating point's z* at each grid point */
    sr_real u_star[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NU]; /**< the operating point's torques u* [N m] */
    sr_real K_path[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NU * SR_LQR_NZ]; /**< gains for path references */
    sr_real K_heading[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NU * SR_LQR_NZ]; /**< gains for speed and heading references */
    sr_real period;                                 /**< the controller's sampling period [s], > 0 */
    sr_real u_max;                                  /**< torque limit on both motors [N m], > 0 */
    sr_real kappa_rate;                             /**< [1/(m s)], >= 0 */
    sr_real steady_rate;                           /**< [m/s], >= 0: the integral of e_y advances only while |de_y/dt| <= this */
    sr_real K_tight[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NU * SR_LQR_NZ]; /**< tighter gains for path references, scheduled in near the path (their integral columns are not read) */
    sr_real tight_band;                            /**< [m], >= 0: K_tight's weight is at most 1 - |e_y| / tight_band; 0: K_tight unused */
    sr_real tight_rise;                            /**< [s], > 0 when tight_band > 0: K_tight's weight rises from 0 to 1 in no less than this */
    sr_real world_share;                           /**< in [0, 1]: the share of the integral of e_y held as a world vector along the path's left normal (it cancels a pull that turns with the heading, such as a slope's on a turning path); 0: all of it along the path */
    sr_real tight_fall;                            /**< [s], >= 0: after a sample that clipped a torque K_tight's weight falls by period / tight_fall; 0: it holds */
    sr_real tight_wait;                           /**< in [0, 1]: the weight falls to -tight_wait at the lowest; below 0 the gain is K_path, so the tight gains return up to tight_wait * tight_rise after a clip ends */
    sr_real K_heading_tight[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NU * SR_LQR_NZ]; /**< stiffer heading gains for heading references, scheduled in near the heading (their integral columns are not read) */
    sr_real heading_band;                          /**< [rad], >= 0: K_heading_tight's weight is at most 1 - |heading error| / heading_band; 0: K_heading_tight unused */
    sr_real heading_rise;                          /**< [s], > 0 when heading_band > 0: K_heading_tight's weight rises from 0 to 1 in no less than this */
    sr_real recovery_cross_track;                  /**< [m], >= 0: path references: the law acts on e_y - e_y* clipped to +-this, and beyond it recovers (see above); 0: neither */
    sr_real recovery_heading;                      /**< [rad], >= 0: the law acts on the heading error z[2] - z*[2] clipped to +-this, and beyond it recovers; 0: neither */
    sr_real recovery_slow;                         /**< in [0, 1): at full recovery the speed reference is lowered by this share; 0: not at all */
    sr_real recovery_rise;                         /**< [s], > 0 when recovery_slow > 0: the recovery's weight moves from 0 to 1 (or back) in no less than this */
    const sr_lqr_slope_table *slope;               /**< the slope's feedforward table (read by sr_lqr_control_offsets); NULL: none */
    const sr_lqr_pendulum_table *pendulum;         /**< the pendulum's feedforward table (read by sr_lqr_control_offsets); NULL: none */
    sr_real pendulum_share;                        /**< in [0, 1]: the share of the pendulum's feedforward applied */
} sr_lqr;

/** What sr_lqr_control_offsets feeds forward at one sample: a slope, a torque offset and the
 * pendulum's departure from the model (from an estimate, sr_slope_update, or known). */
typedef struct sr_lqr_offsets {
    sr_real slope[2];                      /**< the world's slope vector alpha (cos beta, sin beta) [rad]: inclination alpha, uphill towards beta */
    sr_real torque_offset[2];              /**< d [N m]: the plant moves as the model under u + d; the law subtracts it */
    sr_real pendulum[SR_LQR_NPENDULUM];    /**< the pendulum's departure from the model: dm_P [kg], dc_P (x, y, z) [m] */
} sr_lqr_offsets;

/** What to track at this sample (from the reference). */
typedef struct sr_lqr_target {
    sr_real speed;        /**< v_ref [m/s] */
    sr_real heading;      /**< psi_ref [rad]: the heading to hold or the path's tangent */
    sr_real curvature;    /**< kappa [1/m], left positive (path references) */
    sr_real cross_track;  /**< e_y [m], positive when the robot is left of the path */
    int path;             /**< nonzero: a path reference (curvature and cross_track are read) */
} sr_lqr_target;

/** The controller's memory between samples (sr_lqr_reset before the first). */
typedef struct sr_lqr_memory {
    sr_real integrals[2];  /**< z[10], z[11] */
    sr_real kappa;         /**< the operating point's curvature [1/m] */
    int started;           /**< 0 until the first sample */
    int saturated;         /**< out: the last sample clipped a torque */
    sr_real tight;         /**< the tight gains' weight (K_tight's on a path, K_heading_tight's on a heading) at the last sample */
    sr_real world[2];      /**< the world part of the integral of e_y (x, y) [m s]: z[10] is integrals[0] plus its component along the path's left normal */
    sr_real recovery;      /**< the recovery's weight in [0, 1] at the last sample (the share of recovery_slow applied) */
} sr_lqr_memory;

/** Checks a schedule: sizes in range, grids strictly increasing, every entry finite, period
 * and u_max > 0, kappa_rate, steady_rate, tight_band and tight_fall >= 0, tight_wait in [0, 1], tight_rise > 0 when tight_band > 0
 * (K_tight is read only then), heading_band >= 0, heading_rise > 0 when heading_band > 0 (K_heading_tight is read only then),
 * recovery_cross_track and recovery_heading >= 0, recovery_slow in [0, 1), recovery_rise > 0 when recovery_slow > 0,
 * pendulum_share in [0, 1], the feedforward tables (when not NULL) finite at every grid point.  Returns SR_OK, SR_ERR_NULL, SR_ERR_NONFINITE or SR_ERR_ARG. */
int sr_lqr_check(const sr_lqr *lqr);

/** Zeroes the memory.  Returns SR_OK or SR_ERR_NULL. */
int sr_lqr_reset(sr_lqr_memory *memory);

/** The error coordinates z of x against the target (integrals: z[10], z[11]; NULL: zeros).
 * Checks x in full (sr_check_state) and the target for finiteness.  Returns SR_OK,
 * SR_ERR_NULL, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION or SR_ERR_CONSTRAINT; z is written only
 * on SR_OK. */
int sr_lqr_error(const sr_model *model, const sr_real x[SR_NX], const sr_lqr_target *target,
                 const sr_real integrals[2], sr_real z[SR_LQR_NZ]);

/** One sample of the controller: the torques u (clipped to +-u_max) for the next period, and
 * (if u_raw is not NULL) the torques before clipping; advances the memory.  Checks x and the
 * target as sr_lqr_error does, the schedule's sizes, period and u_max (SR_ERR_ARG), and that
 * the torques are finite (SR_ERR_NONFINITE: a non-finite entry of the schedule that was used);
 * run sr_lqr_check once on a schedule before using it.  u, u_raw and the memory are written
 * only on SR_OK. */
int sr_lqr_control(const sr_lqr *lqr, const sr_model *model, const sr_real x[SR_NX],
                   const sr_lqr_target *target, sr_lqr_memory *memory, sr_real u[SR_NU],
                   sr_real u_raw[SR_NU]);

/** sr_lqr_control with the offsets fed forward (offsets NULL: exactly sr_lqr_control).  At the
 * reference's speed v_ref (before any recovery slowing) and the operating curvature kappa of this
 * sample (0 on a heading reference), with the gain K (K_path on a path, K_heading otherwise, without
 * the tight gains) and the tables interpolated bilinearly as the schedule is:
 *     u_raw = (the law's torques) + du_s + K dz_s - d + pendulum_share (du_p + K dz_p),
 * (dz_s, du_s) = up (dz_up, du_up) + right (dz_right, du_right), up = s_x cos psi + s_y sin psi and
 * right = s_x sin psi - s_y cos psi the slope vector's components along the reference's heading psi
 * and to its right, (dz_p, du_p) = sum_k pendulum[k] (dz[k], du[k]), d the torque offset; a table
 * that is NULL adds nothing.  u is u_raw clipped to +-u_max.  The feedforward is added after the
 * law's own limits: the conditional integration and the tight weight's clip (memory->saturated) see
 * the law's torques without it, as runtime/control/lqr.py's controller has it.  Checks as
 * sr_lqr_control, and the offsets for finiteness (SR_ERR_NONFINITE); u, u_raw and the memory are
 * written only on SR_OK. */
int sr_lqr_control_offsets(const sr_lqr *lqr, const sr_model *model, const sr_real x[SR_NX],
                           const sr_lqr_target *target, const sr_lqr_offsets *offsets, sr_lqr_memory *memory,
                           sr_real u[SR_NU], sr_real u_raw[SR_NU]);
/** @} */

/** @name Slope estimate (c/src/sr_slope.c)
 * The world's slope vector s, a torque offset d and the pendulum's departure from the model (dm_P,
 * dc_P, and its joint damping dk_P) from the measured states and the torques held between them,
 * for the LQR's feedforward (sr_lqr_control_offsets); runtime/control/slope.py's SlopeEstimator
 * (its reference: the same arithmetic) and docs/control.md describe it.  At each sample after the
 * first, the rates nu one period after the last state x0 under the torques u held are predicted by
 * the flat model (slope 0) in RKMK4 steps of at most 5 ms (sr_simulate), and the measured rates'
 * departure from that prediction is fitted as G theta, theta = (s_x, s_y, d_1, d_2, the pendulum's
 * m_P, c_P x, y, z and k_P scaled to a tenth of m_P, 1 cm, 1 cm, 1 cm and 0.01 N m s): G's columns
 * the predictions of the model on a slope of 1e-3 rad (along x; along y with x0 turned by -pi/2
 * about the vertical), under u + 1e-3 N m on each motor and with each pendulum parameter moved
 * (m_P by 0.1 %, c_P by 0.1 mm, k_P by 1e-4 N m s), less the flat one, per unit of each entry.
 * Normal equations with exponential forgetting, N = f N + G^T G, b = f b + G^T (nu - nu_flat),
 * f = exp(-period / time_constant); theta = N^-1 b (Gaussian elimination with partial pivoting)
 * when N's 2-norm condition number (for the symmetric N: the ratio of its eigenvalues' magnitudes,
 * by Jacobi rotations) is below SR_SLOPE_COND_LIMIT; else, while the leading 4 x 4 block (slope and
 * d) is below it, those four alone with the pendulum's entries held at their last estimate (rolling
 * straight at the start the samples do not yet tell them apart); else the estimate is held.
 * Weighted (opt-in, sr_slope_weigh with a prior scale a > 0): each rate's row of G and of the
 * residual is divided by the root of that rate's one-period prediction error's variance, estimated
 * with the same forgetting (v = (f v_num + e^2) / (f v_den + 1), e = nu - nu_flat - G theta_last, at
 * least SR_SLOPE_VARIANCE_FLOOR), so a rate the process noise moves much (the pendulum's) does not
 * decide the fit; and theta = (N + P)^-1 b always, P = diag(1 / (a sigma)^2) a Gaussian prior of
 * standard deviations sigma = (5 mrad, 5 mrad, 0.05 N m, 0.05 N m, 20 % of m_P, 1 cm, 1 cm, 1 cm,
 * 0.01 N m s) in theta's units.  The estimator's state, its moved models included, lives in the
 * caller's struct: no allocation. */
/** @{ */
#define SR_SLOPE_NTHETA 9          /**< the fitted entries: slope (2), torque offset (2), pendulum (4), its damping */
#define SR_SLOPE_NMOVED 5          /**< the pendulum's parameters moved: m_P, c_P x, y, z, k_P */
#define SR_SLOPE_MAX_STEPS 16      /**< the prediction's RKMK4 steps per period at most (period <= 80 ms) */
#define SR_SLOPE_COND_LIMIT 1e10   /**< the condition number below which the normal equations are solved */
#define SR_SLOPE_VARIANCE_FLOOR 1e-10 /**< the weighted fit's least variance of a rate's prediction error [(rad/s)^2] */

#ifdef SR_USE_FLOAT
#define sr_slope_estimator sr_slope_estimator_f
#define sr_slope_init sr_slope_init_f
#define sr_slope_reset sr_slope_reset_f
#define sr_slope_update sr_slope_update_f
#define sr_slope_weigh sr_slope_weigh_f
#endif

/** The estimator's state (fill with sr_slope_init).  Read offsets and pendulum_damping; the rest is
 * its working state. */
typedef struct sr_slope_estimator {
    sr_model flat;                          /**< the robot with slope 0 */
    sr_model sloped;                        /**< ... on the probe slope */
    sr_model moved[SR_SLOPE_NMOVED];        /**< ... with one pendulum parameter moved each */
    sr_real factor[SR_SLOPE_NMOVED];        /**< each pendulum column's scale over its probe's step */
    sr_real scale[SR_SLOPE_NMOVED];         /**< each pendulum column's scale (theta's unit) */
    sr_real period;                         /**< the sampling period [s] */
    sr_real forget;                         /**< exp(-period / time_constant) */
    int steps;                              /**< RKMK4 steps per period */
    int started;                            /**< nonzero once a state is held */
    sr_real normal[SR_SLOPE_NTHETA * SR_SLOPE_NTHETA]; /**< the normal equations' matrix N (row-major) */
    sr_real rhs[SR_SLOPE_NTHETA];           /**< ... and right-hand side b */
    sr_real last[SR_NX];                    /**< the last state */
    sr_lqr_offsets offsets;                 /**< out: the slope vector [rad], torque offset [N m] and pendulum (dm_P [kg], dc_P [m]) */
    sr_real pendulum_damping;               /**< out: dk_P [N m s/rad] */
    sr_real work[(SR_SLOPE_MAX_STEPS + 1) * SR_NX]; /**< the predictions' trajectory (scratch) */
    sr_real prior_precision[SR_SLOPE_NTHETA]; /**< the weighted fit's prior P's diagonal (all 0: unweighted; sr_slope_weigh) */
    sr_real variance_sum[SR_NV];            /**< the weighted fit's forgotten sums of each rate's squared error ... */
    sr_real variance_count;                 /**< ... and of the samples */
    sr_real theta[SR_SLOPE_NTHETA];         /**< the weighted fit's last theta (scaled units) */
} sr_slope_estimator;

/** Fills the estimator for the robot params (its slope ignored: the model is the flat one) at the
 * sampling period [s] with the forgetting time constant [s], and resets it.  Returns SR_OK,
 * SR_ERR_NULL, SR_ERR_NONFINITE, SR_ERR_ARG (period or time_constant not > 0, period above
 * SR_SLOPE_MAX_STEPS * 5 ms), or sr_model_init's status for params or a moved copy; *est is written
 * only on SR_OK. */
int sr_slope_init(sr_slope_estimator *est, const sr_real params[SR_NPARAM], sr_real period, sr_real time_constant);

/** Forgets the samples and the estimate (zeros).  Returns SR_OK or SR_ERR_NULL. */
int sr_slope_reset(sr_slope_estimator *est);

/** One sample: the measured (or estimated) state x and the torques u held since the last sample
 * (ignored at the first).  Updates est->offsets and est->pendulum_damping as described above.
 * Checks x in full (sr_check_state) and u for finiteness; returns SR_OK, SR_ERR_NULL,
 * SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT or a prediction's sr_simulate status (the
 * estimator then unchanged). */
int sr_slope_update(sr_slope_estimator *est, const sr_real x[SR_NX], const sr_real u[SR_NU]);

/** Makes the fit weighted with a prior of prior_scale times the standard deviations above (0: the
 * unweighted fit, as sr_slope_init leaves it); call after sr_slope_init, before the first sample.
 * Returns SR_OK, SR_ERR_NULL, SR_ERR_NONFINITE or SR_ERR_ARG (prior_scale < 0); *est unchanged
 * unless SR_OK. */
int sr_slope_weigh(sr_slope_estimator *est, sr_real prior_scale);
/** @} */

#ifdef __cplusplus
}
#endif

#endif /* SPHERICAL_ROBOT_H */
