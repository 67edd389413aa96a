/*
 * sr_step_jacobians.h -- the step and its Jacobian F at once (c/src/sr_step_jacobians.c), for the
 * filter's predict.  Internal to the library: not part of the public API of spherical_robot.h, and
 * not seen by the cffi bindings.
 */
#ifndef SR_STEP_JACOBIANS_H
#define SR_STEP_JACOBIANS_H

#include "sr_math.h"

#ifdef SR_USE_FLOAT /* float symbols carry _f, as in spherical_robot.h */
#define sr_internal_step_and_jacobian sr_internal_step_and_jacobian_f
#endif

/* x_next = sr_step(method, x, u, dt) (to rounding) and F of sr_step_jacobian(method & ~SR_PROJECT),
 * without the argument checks (x valid, u finite or NULL, method and dt valid).  RKMK4 takes the
 * step from its Jacobian's own stages and carries no G; the other methods step and differentiate
 * apart.  Outputs written only on SR_OK; SR_ERR_NONFINITE if either is not finite. */
int sr_internal_step_and_jacobian(const sr_model *model, int method, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                  sr_real dt, sr_real x_next[SR_NX], sr_real F[SR_NE * SR_NE]);

#endif /* SR_STEP_JACOBIANS_H */
