/*
 * lqr_task_law.h -- the LQR of an lqr_task.h (runtime/control/firmware.py) as the firmware examples
 * run it, one call per controller sample: with the slope's feedforward in the task's LQR (the header
 * defines LQR_TASK_SLOPE_ESTIMATE_S), the slope estimate first (sr_slope_update on the state read and
 * the torques held since the last sample; the weighted fit, sr_slope_weigh, when LQR_TASK_SLOPE_PRIOR
 * > 0) and the law with its offsets (sr_lqr_control_offsets; without an estimate, the model's slope);
 * otherwise the plain law (sr_lqr_control).  What the Python closed loop's controller does at each
 * sample (runtime/control/lqr.py, Lqr.compute).  Include after lqr_task.h; the state lives in the
 * caller's lqr_task_law (with the estimate: 16 KB in double, so static storage, not the stack).
 */
#ifndef SR_EXAMPLES_LQR_TASK_LAW_H
#define SR_EXAMPLES_LQR_TASK_LAW_H

#include "spherical_robot.h"

typedef struct lqr_task_law {
    sr_lqr_memory memory;             /* the law's integrals and operating curvature */
#ifdef LQR_TASK_SLOPE_ESTIMATE_S
    sr_slope_estimator estimate;      /* the slope estimate (LQR_TASK_SLOPE_ESTIMATE_S > 0) */
    sr_lqr_offsets known;             /* ... or the model's slope, fed forward without an estimate */
#endif
} lqr_task_law;

/* Checks the schedule and starts a run: the law's memory reset, the estimate filled for the
 * controller's model.  Returns SR_OK or the first failing call's status. */
static int lqr_task_law_init(lqr_task_law *law)
{
    int status = sr_lqr_check(&LQR_TASK_SCHEDULE);
    if (status == SR_OK) status = sr_lqr_reset(&law->memory);
#ifdef LQR_TASK_SLOPE_ESTIMATE_S
    static const sr_lqr_offsets none = {{0, 0}, {0, 0}, {0, 0, 0, 0}};
    law->known = none;
    law->known.slope[0] = LQR_TASK_MODEL_SLOPE[0];
    law->known.slope[1] = LQR_TASK_MODEL_SLOPE[1];
    if (LQR_TASK_SLOPE_ESTIMATE_S > 0) {
        if (status == SR_OK)
            status = sr_slope_init(&law->estimate, LQR_TASK_PARAMS, LQR_TASK_SCHEDULE.period, LQR_TASK_SLOPE_ESTIMATE_S);
        if (status == SR_OK && LQR_TASK_SLOPE_PRIOR > 0) status = sr_slope_weigh(&law->estimate, LQR_TASK_SLOPE_PRIOR);
    }
#endif
    return status;
}

/* One controller sample on the state x (measured or estimated) for the target: u holds the torques
 * held since the last sample on entry (zeros before the first) and the new ones on SR_OK. */
static int lqr_task_law_sample(lqr_task_law *law, const sr_model *model, const sr_real x[SR_NX],
                               const sr_lqr_target *target, sr_real u[SR_NU])
{
#ifdef LQR_TASK_SLOPE_ESTIMATE_S
    int status = SR_OK;
    if (LQR_TASK_SLOPE_ESTIMATE_S > 0) status = sr_slope_update(&law->estimate, x, u);
    if (status != SR_OK) return status;
    return sr_lqr_control_offsets(&LQR_TASK_SCHEDULE, model, x, target,
                                  LQR_TASK_SLOPE_ESTIMATE_S > 0 ? &law->estimate.offsets : &law->known,
                                  &law->memory, u, NULL);
#else
    return sr_lqr_control(&LQR_TASK_SCHEDULE, model, x, target, &law->memory, u, NULL);
#endif
}

#endif
