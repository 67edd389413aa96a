/*
 * sr_compensated.h -- Kahan-compensated sums, for the group action's updates.
 * Internal to the library: not part of the public API of spherical_robot.h, and not seen by the
 * cffi bindings.
 */
#ifndef SR_COMPENSATED_H
#define SR_COMPENSATED_H

#include "sr_math.h"

/* x + d, Kahan-compensated when comp is not NULL: the low-order bits that one addition loses are
 * carried to the next step instead of being rounded the same way at every step, which keeps
 * |R^T R - I| at the rounding level even when a resting robot's increments stay constant and
 * below one ulp of the entries near 1 (the stagnation that otherwise grows |R^T R - I| linearly). */
static inline sr_real compensated_add(sr_real x, sr_real d, sr_real *comp)
{
    sr_real y, t;
    if (!comp) return x + d;
    y = d - *comp;
    t = x + y;
    *comp = (t - x) - y;
    return t;
}

#endif /* SR_COMPENSATED_H */
