/*
 * sr_jacobians.h -- the accelerations' derivatives without the checks
 * (sr_jacobians.c), for the step Jacobians.
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_JACOBIANS_H
#define SR_JACOBIANS_H

#include "sr_math.h"

#ifdef SR_USE_FLOAT /* float symbols carry _f, as in spherical_robot.h */
#define sr_internal_accel_jacobian sr_internal_accel_jacobian_f
#define sr_internal_accel_jacobian_minv sr_internal_accel_jacobian_minv_f
#define sr_internal_accel_jacobian_along sr_internal_accel_jacobian_along_f
#define sr_internal_step_jacobian_lie_euler sr_internal_step_jacobian_lie_euler_f
#define sr_internal_step_jacobian_lie_euler_minv sr_internal_step_jacobian_lie_euler_minv_f
#define sr_internal_check_step_arguments sr_internal_check_step_arguments_f
#endif

/* sr_accel_jacobian without the checks (x valid, u not NULL): Ja, Jb and the accelerations a
 * (to rounding those of sr_accel) at once, for the step Jacobians; outputs not tested for
 * finiteness.  c/src/sr_jacobians.c. */
int sr_internal_accel_jacobian(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                               sr_real a[SR_NV], sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU]);

/* The same, and (Minv not NULL) M^-1, the inverse of the inertia at x (5 x 5 row-major, to
 * rounding symmetric), from the factorisation the accelerations use: for the paper's robot
 * T^T M'^-1 T, M' the yoke frame's inertia (T below).  The filter's process noise. */
int sr_internal_accel_jacobian_minv(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                    sr_real a[SR_NV], sr_real Ja[SR_NV * SR_NE], sr_real Jb[SR_NV * SR_NU],
                                    sr_real *Minv);

/* The accelerations' derivative along given directions, for the step Jacobians' stages: out = Ja V
 * (5 x SR_J_NC) for V the derivatives of the error's rows that the dynamics reads (SR_J_READ rows:
 * xi_S, th_Y, th_P, nu; nothing depends on q) along SR_J_NC directions; also Jb and the
 * accelerations a, as sr_internal_accel_jacobian.  For the paper's robot Ja is never formed: the
 * yoke frame's chain rule acts on V (c/src/sr_jacobians.c). */
enum { SR_J_XI = 0, SR_J_TH_Y = 3, SR_J_TH_P = 4, SR_J_NU = 5, SR_J_READ = 10, SR_J_NC = 12 };
int sr_internal_accel_jacobian_along(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                     const sr_real V[SR_J_READ][SR_J_NC], sr_real a[SR_NV],
                                     sr_real out[SR_NV][SR_J_NC], sr_real Jb[SR_NV * SR_NU]);

/* F and G of sr_step_jacobian_lie_euler without the checks (x valid, u not NULL; G may be NULL):
 * one evaluation of the accelerations' Jacobian.  Outputs written only on SR_OK; SR_ERR_NONFINITE
 * if either is not finite.  The filter's transition matrix (sr_ekf.h). */
int sr_internal_step_jacobian_lie_euler(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                        sr_real dt, sr_real F[SR_NE * SR_NE], sr_real *G);

/* The same, and (Minv not NULL) M^-1 at x as sr_internal_accel_jacobian_minv, not tested for
 * finiteness: the filter's process noise. */
int sr_internal_step_jacobian_lie_euler_minv(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                             sr_real dt, sr_real F[SR_NE * SR_NE], sr_real *G, sr_real *Minv);

/* The step Jacobians' argument checks, in the order of sr_argcheck.h: the model, the pointers
 * (x, F, G), dt, then the state and the torques (u may be NULL).  c/src/sr_step_jacobians.c. */
int sr_internal_check_step_arguments(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                     sr_real dt, const sr_real *F, const sr_real *G);

#endif /* SR_JACOBIANS_H */
