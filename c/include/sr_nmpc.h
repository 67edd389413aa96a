/**
 * sr_nmpc.h -- the NMPC in C: real-time iterations on the library's step and step Jacobians, and
 * the box-constrained QP solver they use (c/src/sr_boxqp.c, c/src/sr_nmpc.c).
 *
 * The formulation is runtime/control/nmpc.py's (docs/control.md, "NMPC"): multiple shooting over
 * N nodes of node_periods controller periods each, in the reduced error coordinates of the LQR
 * (z[SR_NMPC_NZ]: the yoke's attitude error, the pendulum, the rates in the yoke's frame, the
 * cross-track error and its integral); one Gauss-Newton QP in the torques per sample, condensed,
 * with the torque limits as bounds; the LQR's Bryson weights on z and u, a cost on the torques'
 * changes from node to node, the discrete Riccati cost-to-go at the end.  A node's prediction is
 * one RKMK4 step of the full model (sr_step) over the node period from the lift of z_k, taken back
 * to the error coordinates against the path (a circle of the node's curvature through the foot
 * point); its sensitivities are sr_step_jacobian's, chained through the lift and that projection.
 *
 * Offset-free: the plant is modelled as the model driven by u + d, d a constant offset of the two
 * torques, whose shell rates (z[4..6]) gain a constant acceleration a besides: what a slope's pull,
 * a heavier body or a moved centre of mass add that the motors' torques cannot explain.  Both are
 * estimated online from the model's one-period prediction error (the last sample's z and torques,
 * with d and a, predicted by one node of one period against the measured z, on the pendulum and
 * the rates: (d, a) += disturbance_gain * the least-squares step that explains the difference,
 * d clipped to +-u_max).  Every node adds d to its torques and a times its period to its shell
 * rates, and the reference torques are u* - d.  The cross-track integral acts at any offset; it holds while a torque is at its
 * bound (anti-windup) and while the error moves faster than steady_rate (a transient).
 *
 * Self-contained C99: no dynamic allocation, no mutable globals.  Every buffer is sized by the
 * compile-time maximums below (SR_NMPC_MAX_HORIZON), so that sizeof(sr_nmpc_memory) is the
 * controller's whole workspace; every function returns a status code of spherical_robot.h.
 * @file
 */
#ifndef SR_NMPC_H
#define SR_NMPC_H

#include "spherical_robot.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef SR_USE_FLOAT
#define sr_boxqp_solve sr_boxqp_solve_f
#define sr_nmpc sr_nmpc_f
#define sr_nmpc_target sr_nmpc_target_f
#define sr_nmpc_memory sr_nmpc_memory_f
#define sr_nmpc_check sr_nmpc_check_f
#define sr_nmpc_reset sr_nmpc_reset_f
#define sr_nmpc_step sr_nmpc_step_f
#define sr_nmpc_node sr_nmpc_node_f
#define sr_nmpc_memory_bytes sr_nmpc_memory_bytes_f
#endif

/** @name The box-constrained QP
 * min 1/2 x^T H x + g^T x subject to lb <= x <= ub, H symmetric positive definite (row-major n x n,
 * only its lower triangle read).  A primal active-set method: from the start point clamped to the
 * box, each iteration minimises over the free variables (a Cholesky factorisation of H on them),
 * steps until a bound blocks and fixes that variable, or, at a face's minimum, frees the bound
 * variable whose multiplier has the wrong sign by the most; it stops when every multiplier has
 * its sign (to a relative SR_BOXQP_TOL).  The active set of a warm start (a start point on its
 * bounds) is kept, so that an RTI sample that activates the bounds of the last one needs one
 * factorisation.  Finite termination for positive definite H (the objective falls strictly at
 * every step that is not blocked at once). */
/** @{ */
/** Reals of the caller's workspace of sr_boxqp_solve for n unknowns. */
#define SR_BOXQP_WORK_REALS(n) ((n) * (n) + 3 * (n))
/** Ints of its integer workspace for n unknowns. */
#define SR_BOXQP_WORK_INTS(n) (2 * (n))
/** Relative tolerance on the multipliers' signs (of the gradient's scale). */
#ifdef SR_USE_FLOAT
#define SR_BOXQP_TOL SR_C(1e-6)
#else
#define SR_BOXQP_TOL SR_C(1e-13)
#endif

/** Solves the box QP above.  x[n]: in, the start (clamped to the box; its entries on a bound
 * start the active set); out, the solution.  lb[i] may be -infinity and ub[i] +infinity, not NaN,
 * and lb[i] <= ub[i].  work: SR_BOXQP_WORK_REALS(n) reals, iwork: SR_BOXQP_WORK_INTS(n) ints.
 * max_iterations bounds the factorisations (at least n + 1 are sometimes needed from a cold start);
 * *iterations (if not NULL) receives the number used.  Returns SR_OK; SR_ERR_NULL; SR_ERR_ARG
 * (n < 1, max_iterations < 1, lb[i] > ub[i]); SR_ERR_NONFINITE (H, g or x not finite, a bound NaN);
 * SR_ERR_SINGULAR (H not positive definite on the free variables); SR_ERR_MAX_STEPS (no solution
 * in max_iterations).  x is written only on SR_OK. */
int sr_boxqp_solve(int n, const sr_real *H, const sr_real *g, const sr_real *lb, const sr_real *ub,
                   int max_iterations, sr_real *x, sr_real *work, int *iwork, int *iterations);
/** @} */

/** @name The NMPC */
/** @{ */
#define SR_NMPC_NZ 11              /**< entries of the NMPC's error coordinates: sr_lqr's z[0..10] */
#ifndef SR_NMPC_MAX_HORIZON
#define SR_NMPC_MAX_HORIZON 40     /**< capacity of the horizon, in nodes (may be set at build time) */
#endif
/** Unknowns of the condensed QP at the largest horizon. */
#define SR_NMPC_MAX_QP (SR_NU * SR_NMPC_MAX_HORIZON)
/** Halvings of a recovery's Gauss-Newton step before it is dropped (sr_nmpc_step). */
#define SR_NMPC_HALVINGS 6
#ifndef SR_NMPC_RECOVERY_SAMPLES
/** Samples after a failed restart from the reference that start with the recovery too (may be set at build time). */
#define SR_NMPC_RECOVERY_SAMPLES 20
#endif

/** The controller's design (read-only during control; runtime/control/nmpc.py's NmpcC fills it
 * from the same design as the Python NMPC).  Grid point (i, j), speed i and curvature j, is entry
 * i * n_curvatures + j of z_star, u_star, P_path and P_heading (P row-major). */
typedef struct sr_nmpc {
    int horizon;                    /**< N nodes, 1 .. SR_NMPC_MAX_HORIZON */
    int node_periods;               /**< controller periods per node, >= 1 */
    int cold_iterations;            /**< Gauss-Newton iterations of a start without a guess, >= 1 */
    int iterations;                 /**< iterations of every other sample, >= 1 */
    int qp_max_iterations;          /**< bound on each QP's factorisations, >= 1 */
    sr_real period;                 /**< the controller's sampling period [s], > 0 */
    sr_real u_max;                  /**< torque limit on both motors [N m], > 0 */
    sr_real r;                      /**< weight of the torques' distance from u* [1/(N m)^2], > 0 */
    sr_real r_step;                 /**< weight of a torque's change from node to node, >= 0 */
    sr_real steady_rate;           /**< the cross-track integral advances only while |de_y/dt| <= this [m/s], >= 0 */
    sr_real disturbance_gain;       /**< the share of the torque offset's one-sample update taken, 0 .. 1 (0: no estimate) */
    sr_real heading_jump;           /**< a jump of the reference's heading beyond this [rad] drops the guess, > 0 */
    sr_real q_path[SR_NMPC_NZ];     /**< weights of z on path references, >= 0 */
    sr_real q_heading[SR_NMPC_NZ];  /**< weights of z on speed and heading references, >= 0 */
    int n_speeds;                   /**< 1 .. SR_LQR_MAX_SPEEDS */
    int n_curvatures;               /**< 1 .. SR_LQR_MAX_CURVATURES */
    sr_real speeds[SR_LQR_MAX_SPEEDS];              /**< strictly increasing [m/s] */
    sr_real curvatures[SR_LQR_MAX_CURVATURES];      /**< strictly increasing [1/m] */
    sr_real z_star[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NMPC_NZ]; /**< operating points' z* */
    sr_real u_star[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NU];      /**< their torques u* [N m] */
    sr_real P_path[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NMPC_NZ * SR_NMPC_NZ];    /**< cost-to-go, paths */
    sr_real P_heading[SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES][SR_NMPC_NZ * SR_NMPC_NZ]; /**< cost-to-go, speed and heading */
} sr_nmpc;

/** What to track at this sample (as sr_lqr_target, with the path's curvature ahead). */
typedef struct sr_nmpc_target {
    sr_real speed;                  /**< v_ref [m/s] */
    sr_real heading;                /**< psi_ref [rad]: the heading to hold or the path's tangent */
    sr_real curvature;              /**< kappa [1/m] at the foot point (path references) */
    sr_real cross_track;            /**< e_y [m], positive left of the path (path references) */
    int path;                       /**< nonzero: a path reference */
    const sr_real *curvature_ahead; /**< NULL, or horizon + 1 curvatures at the nodes (path references) */
} sr_nmpc_target;

/** The controller's memory between samples and its whole workspace (sr_nmpc_reset before the first
 * sample).  The fields after `saturated` are scratch; the last QP (H, g, lb, ub, its solution dU) is
 * left in them for inspection. */
typedef struct sr_nmpc_memory {
    sr_real Z[(SR_NMPC_MAX_HORIZON + 1) * SR_NMPC_NZ]; /**< the nodes' states of the last solution */
    sr_real U[SR_NMPC_MAX_QP];      /**< the nodes' torques of the last solution */
    sr_real u_last[SR_NU];          /**< the first torques of the last solution */
    sr_real heading;                /**< the last sample's reference heading [rad] */
    sr_real integral;               /**< the cross-track integral [m s] */
    sr_real disturbance[SR_NU];     /**< the estimated torque offset d [N m] */
    sr_real shell_accel[3];         /**< the estimated acceleration a of the shell's rates z[4..6] [rad/s^2] */
    sr_real z_last[SR_NMPC_NZ];     /**< the last sample's error coordinates (what d is estimated from) */
    sr_real v_last;                 /**< the last sample's reference speed [m/s] */
    sr_real kappa_last;             /**< the last sample's curvature at the foot point [1/m] */
    int have_last;                  /**< z_last, v_last, kappa_last and u_last are those of a solved sample */
    long samples;                   /**< samples since the reset */
    long restarts;                  /**< samples whose start failed (restarted from the reference, then recovered or failed) */
    long recoveries;                /**< samples that ran the recovery (sr_nmpc_step) */
    long failures;                  /**< samples with no solution at all (the torques u* held) */
    int failing;                    /**< consecutive failed samples up to the last (0: the last was solved) */
    int recovering;                 /**< samples still to start with the recovery (SR_NMPC_RECOVERY_SAMPLES after a failed restart) */
    int have_guess;                 /**< Z, U hold a solution to warm-start from */
    int have_u_last;                /**< u_last is set */
    int qp_iterations;              /**< factorisations of the last QP */
    int saturated;                  /**< out: the last torques are at a limit */
    sr_real zs[(SR_NMPC_MAX_HORIZON + 1) * SR_NMPC_NZ]; /**< scratch: the reference nodes */
    sr_real us[SR_NMPC_MAX_QP];     /**< scratch: the reference torques */
    sr_real kappa[SR_NMPC_MAX_HORIZON + 1];            /**< scratch: the nodes' curvatures */
    sr_real Zn[(SR_NMPC_MAX_HORIZON + 1) * SR_NMPC_NZ]; /**< scratch: the iterate's nodes */
    sr_real Un[SR_NMPC_MAX_QP];     /**< scratch: the iterate's torques */
    sr_real A[SR_NMPC_MAX_HORIZON][SR_NMPC_NZ * SR_NMPC_NZ]; /**< scratch: node sensitivities dz+/dz */
    sr_real B[SR_NMPC_MAX_HORIZON][SR_NMPC_NZ * SR_NU];      /**< scratch: node sensitivities dz+/du */
    sr_real S[SR_NMPC_NZ * SR_NMPC_NZ];                     /**< scratch: the condensing's cost-to-go */
    sr_real SB[SR_NMPC_MAX_HORIZON][SR_NMPC_NZ * SR_NU];     /**< scratch: S_{k+1} B_k */
    sr_real gap[(SR_NMPC_MAX_HORIZON + 1) * SR_NMPC_NZ];    /**< scratch: the gaps, then the lambdas */
    sr_real c[(SR_NMPC_MAX_HORIZON + 1) * SR_NMPC_NZ];      /**< scratch: the free response */
    sr_real H[SR_NMPC_MAX_QP * SR_NMPC_MAX_QP];             /**< scratch: the last QP's Hessian */
    sr_real g[SR_NMPC_MAX_QP];      /**< scratch: the last QP's gradient */
    sr_real lb[SR_NMPC_MAX_QP];     /**< scratch: its lower bounds */
    sr_real ub[SR_NMPC_MAX_QP];     /**< scratch: its upper bounds */
    sr_real dU[SR_NMPC_MAX_QP];     /**< scratch: its solution */
    sr_real qp_work[SR_BOXQP_WORK_REALS(SR_NMPC_MAX_QP)];   /**< scratch: the QP solver's */
    int qp_iwork[SR_BOXQP_WORK_INTS(SR_NMPC_MAX_QP)];       /**< scratch: the QP solver's */
} sr_nmpc_memory;

/** sizeof(sr_nmpc_memory): the controller's workspace in bytes (metadata for a firmware's RAM
 * budget and for bindings). */
long sr_nmpc_memory_bytes(void);

/** Checks a design: sizes in range, grids strictly increasing, every entry finite, the signs
 * above.  Returns SR_OK, SR_ERR_NULL, SR_ERR_NONFINITE or SR_ERR_ARG. */
int sr_nmpc_check(const sr_nmpc *design);

/** Forgets the warm start, the heading, the integral, the torque offset and the counters.  Returns SR_OK or SR_ERR_NULL. */
int sr_nmpc_reset(sr_nmpc_memory *memory);

/** One node of the prediction model: from the error coordinates z (reference speed v, the path's
 * curvature kappa) under torques u held for dt, z_next; and (if A, B are not NULL) its
 * sensitivities A = dz_next/dz (row-major SR_NMPC_NZ^2) and B = dz_next/du (SR_NMPC_NZ x SR_NU).
 * Returns SR_OK or the status of sr_step / sr_step_jacobian (SR_ERR_NULL for model, z, u, z_next;
 * SR_ERR_NONFINITE for non-finite inputs or results); outputs written only on SR_OK. */
int sr_nmpc_node(const sr_model *model, const sr_real z[SR_NMPC_NZ], const sr_real u[SR_NU], sr_real v,
                 sr_real kappa, sr_real dt, sr_real z_next[SR_NMPC_NZ], sr_real *A, sr_real *B);

/** One sample: the torques u for the next period from the measured state x and the target (the
 * real-time iteration: update the torque offset, shift the last solution when a node has passed,
 * linearise the nodes, condense, solve the torque-limited QP, advance the integral).
 *
 * Recovery.  A sample whose iterations fail from its start (a prediction or a QP not finite;
 * memory->restarts) starts once more from the reference (cold_iterations; a cold start was from
 * there already).  When that fails too, the sample is solved by the recovery, and so are the
 * SR_NMPC_RECOVERY_SAMPLES samples after it and every sample after one with no solution
 * (memory->recoveries counts them).
 * The recovery cannot diverge: it starts from the guess's torques or the reference's u* - d (clipped
 * to +-u_max), whichever costs less when rolled out by the prediction model from the measured state,
 * and takes up to cold_iterations Gauss-Newton steps on these gap-free nodes, each QP's step halved
 * up to SR_NMPC_HALVINGS times until the rolled-out nodes are finite and the objective falls (a step
 * that does not is dropped and the iterations end).  Only when no rollout is finite does a sample
 * fail: it returns the reference's torques u*_0 - d clipped (memory->failures, memory->failing the
 * consecutive failures, cleared by the next solved sample) and SR_OK.
 *
 * Checks the
 * design (sr_nmpc_check: SR_ERR_ARG, SR_ERR_NONFINITE), x in full (sr_check_state), the target's
 * and the memory's integral and heading for finiteness.  Returns SR_OK, SR_ERR_NULL, SR_ERR_MODEL, SR_ERR_ARG, SR_ERR_NONFINITE,
 * SR_ERR_NOT_ROTATION or SR_ERR_CONSTRAINT; u and the memory are written only on SR_OK, u within
 * +-u_max. */
int sr_nmpc_step(const sr_nmpc *design, sr_nmpc_memory *memory, const sr_model *model, const sr_real x[SR_NX],
                 const sr_nmpc_target *target, sr_real u[SR_NU]);
/** @} */

#ifdef __cplusplus
}
#endif

#endif /* SR_NMPC_H */
