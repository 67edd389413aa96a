/*
 * sr_steppers.h -- the steppers' pieces of sr_steppers.c, for the drivers
 * (sr_drivers.c), the batch step's lanes (sr_step_lanes.c) and the step Jacobians.
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_STEPPERS_H
#define SR_STEPPERS_H

#include "sr_action.h"

#ifdef SR_USE_FLOAT /* float symbols carry _f, as in spherical_robot.h */
#define sr_internal_valid_method sr_internal_valid_method_f
#define sr_internal_advance sr_internal_advance_f
#define sr_internal_vector_field sr_internal_vector_field_f
#define sr_internal_kinematics sr_internal_kinematics_f
#define sr_internal_rkmk4_core sr_internal_rkmk4_core_f
#define sr_internal_dexpinv sr_internal_dexpinv_f
#define sr_internal_project sr_internal_project_f
#endif

/* Nonzero if method is SR_LIE_EULER, SR_RKMK4 or SR_CF4, optionally | SR_PROJECT. */
int sr_internal_valid_method(int method);

/* One step of any valid method without argument checks (sr_step/sr_simulate check first);
 * u must not be NULL; out may alias x.  comp: NULL for a single step, or the running Kahan
 * compensation of a simulation (SR_NX entries, zero at its start) for the fourth-order
 * methods, updated only when the step succeeds (Lie-Euler stays the paper's plain eq. (111)). */
int sr_internal_advance(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                        sr_real dt, sr_real *comp, sr_real out[SR_NX]);

/* f = the velocity of the state in the Lie algebra (SR_NT entries); counts the acceleration
 * evaluations in *evaluations (if not NULL). */
int sr_internal_vector_field(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                             sr_real f[SR_NT], long *evaluations);

/* The first SR_T_V entries of the vector field: the velocities and the rolling q' (the rest,
 * the accelerations, from the dynamics). */
void sr_internal_kinematics(const sr_model *model, const sr_real x[SR_NX], sr_real f[SR_NT]);

/* The stages of RKMK4 from K[0] = f(x) (filled by the caller): K[1..3] and the final Theta;
 * out = x . exp(Theta) (out must not alias x). */
int sr_internal_rkmk4_core(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real h,
                           sr_real K[4][SR_NT], sr_real theta[SR_NT], sr_real *comp, sr_real out[SR_NX],
                           long *evaluations);

/* k = dexp^{-1}_{-th}(f) (k may alias f). */
void sr_internal_dexpinv(const sr_real th[SR_NT], const sr_real f[SR_NT], sr_real k[SR_NT]);

/* The optional correction of SR_PROJECT: one Newton-Schulz step R <- R (3I - R^T R)/2 towards
 * the nearest rotation for R_S, the same on the (cos, sin) pair of R_Y and R_P. */
void sr_internal_project(sr_real x[SR_NX]);

#endif /* SR_STEPPERS_H */
