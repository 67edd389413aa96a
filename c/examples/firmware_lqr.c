/*
 * firmware_lqr.c -- a closed-loop firmware example: the LQR controller (sr_lqr_control) at a
 * fixed rate, driving the simulated robot; no Python, no heap.
 *
 * The scenario comes from generated/lqr_task.h, written by `make generate` (python -m runtime
 * firmware-table; by default: the heading-step task, a heading step of pi/2 while rolling at 0.3 m/s, with the LQR
 * at 100 Hz; its gain schedule designed for the task's model).  Every controller sample reads
 * the state, computes the torques, and holds them for LQR_TASK_STEPS_PER_SAMPLE plant steps of
 * LQR_TASK_DT (sr_simulate: on a robot, the plant is the robot and the state comes from the
 * estimator).
 *
 * Output (stdout): CSV, a header line then one row per plant step (t = 0 and after every step):
 * t, the 35 state entries in the order of spherical_robot.h, and the torques u_Y, u_P held from
 * that row's time on (the last row repeats the torques before it), %.17g.  In the double build
 * the rows equal, bit for bit, the Python closed loop of the same task
 * (runtime.control.closed_loop.simulate_closed_loop with the C controller,
 * tests/runtime/control/test_firmware.py).  Build: `make example` in c/.
 * With the slope's feedforward in the task's LQR (the header then defines LQR_TASK_SLOPE_ESTIMATE_S:
 * `slope_estimate_s` > 0, or a slope in the controller's model), every sample first updates the slope
 * estimate (sr_slope_update: the state and the torques held since the last sample) and the law feeds
 * its offsets forward (sr_lqr_control_offsets); without an estimate, the model's slope.  With
 * LQR_TASK_SLOPE_PRIOR > 0 (`slope_prior`), the estimate is the weighted fit (sr_slope_weigh).
 * The sample's calls are lqr_task_law.h's, which firmware_ekf_lqr.c shares.
 * Exit status 0 on success; on an error, a message on stderr and 1.
 */
#include <stdio.h>

/* -DLQR_TASK_FROM_INCLUDE_PATH -I<dir>: another task's header from <dir> (the tests do this, through
 * c/Makefile's CPPFLAGS, which come before the library's include directories). */
#ifdef LQR_TASK_FROM_INCLUDE_PATH
#include <lqr_task.h>
#else
#include "lqr_task.h"
#endif
#include "spherical_robot.h"
#include "lqr_task_law.h"
#include "systick.h"

#define PER LQR_TASK_STEPS_PER_SAMPLE

/* On a target this would block until the next controller tick; the host runs flat out. */
static void wait_for_tick(void) {}

static void print_header(void)
{
    static const char *const blocks[] = {"RS", "RY", "RP"};
    int b, i, j;
    printf("t");
    for (b = 0; b < 3; ++b)
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) printf(",%s_%d%d", blocks[b], i, j);
    printf(",q_x,q_y,q_z,w_Sx,w_Sy,w_Sz,w_Y,w_P,u_Y,u_P\n");
}

static void print_row(long n, const sr_real x[SR_NX], const sr_real u[SR_NU])
{
    int i;
    printf("%.17g", (double)n * LQR_TASK_DT_SECONDS); /* t = n dt, as numpy computes it */
    for (i = 0; i < SR_NX; ++i) printf(",%.17g", (double)x[i]);
    printf(",%.17g,%.17g\n", (double)u[0], (double)u[1]);
}

#if defined(LQR_TASK_SLOPE_ESTIMATE_S) && defined(HAVE_SYSTICK)
/* on a Cortex-M: the instructions of each sample's estimate and law (stderr) */
static uint32_t sample_ticks[LQR_TASK_SAMPLES];
#endif

int main(void)
{
    /* the law's memory and the slope estimate (the seven moved models in it: static storage, not the stack) */
    static lqr_task_law law;
    sr_model model, plant;
    const sr_lqr_target target = {LQR_TASK_SPEED, LQR_TASK_HEADING, 0, 0, 0};
    sr_real x[SR_NX], traj[PER + 1][SR_NX], u[SR_NU] = {0, 0}, u_hold[PER][SR_NU];   /* u: held before the first sample */
    long k, done;
    int i, status;

    status = sr_model_init(&model, LQR_TASK_PARAMS);
#ifdef LQR_TASK_HAS_PLANT   /* a robot unlike the controller's model */
    if (status == SR_OK) status = sr_model_init(&plant, LQR_TASK_PLANT_PARAMS);
#else
    plant = model;
#endif
    if (status == SR_OK) status = sr_check_state(&model, LQR_TASK_X0);
    if (status == SR_OK) status = lqr_task_law_init(&law);
    if (status != SR_OK) {
        fprintf(stderr, "firmware_lqr: setup failed: %s\n", sr_status_string(status));
        return 1;
    }
    for (i = 0; i < SR_NX; ++i) x[i] = LQR_TASK_X0[i];

    print_header();
#if defined(LQR_TASK_SLOPE_ESTIMATE_S) && defined(HAVE_SYSTICK)
    systick_start();
#endif
    for (k = 0; k < LQR_TASK_SAMPLES; ++k) {
        wait_for_tick();
        {
#if defined(LQR_TASK_SLOPE_ESTIMATE_S) && defined(HAVE_SYSTICK)
            const uint32_t start = SYST_CVR;
#endif
            status = lqr_task_law_sample(&law, &model, x, &target, u);
#if defined(LQR_TASK_SLOPE_ESTIMATE_S) && defined(HAVE_SYSTICK)
            sample_ticks[k] = ticks_since(start);
#endif
        }
        if (status != SR_OK) {
            fprintf(stderr, "firmware_lqr: controller sample %ld failed: %s\n", k, sr_status_string(status));
            return 1;
        }
        for (i = 0; i < PER; ++i) {
            u_hold[i][0] = u[0];
            u_hold[i][1] = u[1];
        }
        status = sr_simulate(&plant, LQR_TASK_METHOD, x, LQR_TASK_DT, PER, &u_hold[0][0], &traj[0][0], &done);
        if (status != SR_OK) {
            fprintf(stderr, "firmware_lqr: plant step %ld failed: %s\n", k * PER + done + 1, sr_status_string(status));
            return 1;
        }
        for (i = 0; i < PER; ++i) print_row(k * PER + i, traj[i], u);
        for (i = 0; i < SR_NX; ++i) x[i] = traj[PER][i];
    }
    print_row(LQR_TASK_SAMPLES * PER, x, u);
#if defined(LQR_TASK_SLOPE_ESTIMATE_S) && defined(HAVE_SYSTICK)
    report_first_and_rest("sample", "the slope estimate and the law", sample_ticks, LQR_TASK_SAMPLES,
                          instructions_per_tick());
#endif
    return 0;
}
