/*
 * sr_math.h -- the libm functions of sr_real's precision, the float sine and
 * cosine's ranges, and the generated kernels' status codes, which are the library's.
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_MATH_H
#define SR_MATH_H

#include "spherical_robot.h"

#include <float.h>
#include <math.h>
#include <stddef.h> /* NULL */

#ifdef SR_USE_FLOAT
#define SR_SQRT sqrtf
#define SR_SIN SR_GEN_SIN      /* c/src/sr_trig.c, or libm's with -DSR_LIBM_TRIG (sr_real.h) */
#define SR_COS SR_GEN_COS
#define SR_FABS fabsf
#define SR_POW powf
#define SR_ATAN2 atan2f
#define SR_EPSILON FLT_EPSILON
#else
#define SR_SQRT sqrt
#define SR_SIN SR_GEN_SIN      /* c/src/sr_trig.c, or libm's with -DSR_LIBM_TRIG (sr_real.h) */
#define SR_COS SR_GEN_COS
#define SR_FABS fabs
#define SR_POW pow
#ifdef SR_LIBM_TRIG
#define SR_ATAN2 atan2
#else
#define SR_ATAN2 sr_internal_atan2
#endif
#define SR_EPSILON DBL_EPSILON
#endif

/* c/src/sr_trig.c's float sine and cosine: accurate to 2^-23 up to SR_TRIG_EXACT_RANGE, their
 * reduction's rounding growing as |x| 2^-24 beyond, NaN past SR_TRIG_MAX_ARG. */
#define SR_TRIG_EXACT_RANGE 8192.0f
#define SR_TRIG_MAX_ARG 16777216.0f
/* c/src/sr_trig.c's double sine and cosine: within 1 ulp up to here (just below 2^20 pi/2, where
 * the quadrant count times the first 33 bits of pi/2 stays exact), NaN beyond. */
#define SR_TRIG_DOUBLE_MAX_ARG 1647099.0

/* The generated kernels' status codes are the library's: their results pass through. */
#if SR_GEN_OK != SR_OK || SR_GEN_NONFINITE != SR_ERR_NONFINITE || SR_GEN_SINGULAR != SR_ERR_SINGULAR
#error "generated status codes differ from spherical_robot.h"
#endif

#endif /* SR_MATH_H */
