/*
 * test_slope.c -- the slope estimate (c/src/sr_slope.c) on its own: a robot of the model's own
 * parameters rolling freely on a slope is read as that slope and nothing else; the status codes;
 * the estimator untouched on an error.  (tests/runtime/control/test_slope_c.py holds it equal to
 * runtime/control/slope.py's NumPy estimate over whole closed-loop runs.)
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

#define SLOPE 0.005  /* [rad], uphill towards the world's +x */

/* The robot of the paper's simulation, rolling at 0.3 m/s along the world's y axis (across the
 * slope), on the slope `slope` along x: the estimator (flat model, 20 ms, 5 s) after `samples`
 * periods of zero torque. */
static void run_on_slope(double slope, int samples, sr_slope_estimator *est, double prior_scale)
{
    sr_model plant;
    sr_real p[SR_NPARAM], x[SR_NX], traj[5 * SR_NX];
    const sr_real zero[4 * SR_NU] = {0};
    long done;
    int k;
    paper_simulation_params(p);
    CHECK_STATUS(sr_slope_init(est, p, SR_C(0.02), SR_C(5.0)), SR_OK);
    CHECK_STATUS(sr_slope_weigh(est, (sr_real)prior_scale), SR_OK);
    p[SR_P_slope] = (sr_real)slope;
    CHECK_STATUS(sr_model_init(&plant, p), SR_OK);
    make_state(x, 0.0, 0.0, (double)p[SR_P_r]);
    x[SR_X_w_S] = (sr_real)(-0.3 / (double)p[SR_P_r]);     /* rolling about the shell's x axis: along the world's y */
    x[SR_X_w_Y] = (sr_real)(0.3 / (double)p[SR_P_r]);
    for (k = 0; k < samples; ++k) {
        CHECK_STATUS(sr_slope_update(est, x, zero), SR_OK);
        CHECK_STATUS(sr_simulate(&plant, SR_RKMK4, x, SR_C(0.005), 4, zero, traj, &done), SR_OK);
        memcpy(x, traj + 4 * SR_NX, sizeof x);
    }
}

/* The estimate reads SLOPE along x and none along y: within `relative` of SLOPE in double; in float
 * within a tenth (the one-period differences of 1e-3 probes keep about three digits). */
static void check_reads_the_slope(const sr_slope_estimator *est, double relative)
{
#ifdef SR_USE_FLOAT
    relative = 0.1;
#endif
    CHECK_NEAR(est->offsets.slope[0], SLOPE, relative * SLOPE);
    CHECK_NEAR(est->offsets.slope[1], 0.0, relative * SLOPE);
}

/* 16 KB each: static, not on the stack, and shared by the tests (the Cortex-M7 test image holds
 * every suite's statics and its stack in 4 MB of RAM). */
static sr_slope_estimator slope_est, slope_kept;

static void test_a_robot_rolling_on_a_slope_reads_as_that_slope_and_no_other_offset(void)
{
    int k;
    run_on_slope(SLOPE, 100, &slope_est, 0.0);
    check_reads_the_slope(&slope_est, 1e-3);
#ifndef SR_USE_FLOAT
    for (k = 0; k < 2; ++k) CHECK_NEAR(slope_est.offsets.torque_offset[k], 0.0, 1e-5);
    for (k = 0; k < SR_LQR_NPENDULUM; ++k) CHECK_NEAR(slope_est.offsets.pendulum[k], 0.0, 1e-4);   /* 0.1 g, 0.1 mm */
#endif
    (void)k;
}

static void test_on_level_ground_the_estimate_is_zero_and_the_slope_is_not_invented(void)
{
    run_on_slope(0.0, 50, &slope_est, 0.0);
    CHECK_NEAR(slope_est.offsets.slope[0], 0.0, 1e-9);
    CHECK_NEAR(slope_est.offsets.slope[1], 0.0, 1e-9);
}

static void test_weighted_a_robot_rolling_on_a_slope_still_reads_as_that_slope(void)
{
    /* no process noise: after the first samples (whose errors, the slope not yet read, stay in the
     * forgotten variances) the residuals are small, their weights large, and the prior (5 mrad) light:
     * 4.993 mrad after 2 s */
    run_on_slope(SLOPE, 100, &slope_est, 1.0);
    CHECK(slope_est.prior_precision[0] > 0);
    check_reads_the_slope(&slope_est, 1e-2);
}

static void test_weigh_refuses_a_bad_prior_scale_and_leaves_the_estimator_untouched(void)
{
    sr_real p[SR_NPARAM];
    paper_simulation_params(p);
    CHECK_STATUS(sr_slope_init(&slope_est, p, SR_C(0.02), SR_C(5.0)), SR_OK);
    slope_kept = slope_est;
    CHECK_STATUS(sr_slope_weigh(NULL, 1), SR_ERR_NULL);
    CHECK_STATUS(sr_slope_weigh(&slope_est, -1), SR_ERR_ARG);
    CHECK_STATUS(sr_slope_weigh(&slope_est, (sr_real)NAN), SR_ERR_NONFINITE);
    CHECK_STATUS(sr_slope_weigh(&slope_est, (sr_real)INFINITY), SR_ERR_NONFINITE);
    CHECK(memcmp(&slope_est, &slope_kept, sizeof slope_est) == 0);
    CHECK_STATUS(sr_slope_weigh(&slope_est, 2), SR_OK);
    CHECK_NEAR(slope_est.prior_precision[0], 1 / (0.01 * 0.01), 1e-3);      /* 1 / (2 x 5 mrad)^2 */
    CHECK_STATUS(sr_slope_weigh(&slope_est, 0), SR_OK);
    CHECK(memcmp(&slope_est, &slope_kept, sizeof slope_est) == 0);                      /* 0: unweighted, as init left it */
}

static void test_bad_input_gives_status_and_leaves_the_estimator_untouched(void)
{
    sr_real p[SR_NPARAM], x[SR_NX];
    sr_real u[SR_NU] = {0, 0};
    paper_simulation_params(p);
    CHECK_STATUS(sr_slope_init(NULL, p, SR_C(0.02), SR_C(5.0)), SR_ERR_NULL);
    CHECK_STATUS(sr_slope_init(&slope_est, NULL, SR_C(0.02), SR_C(5.0)), SR_ERR_NULL);
    CHECK_STATUS(sr_slope_init(&slope_est, p, 0, SR_C(5.0)), SR_ERR_ARG);
    CHECK_STATUS(sr_slope_init(&slope_est, p, SR_C(0.02), 0), SR_ERR_ARG);
    CHECK_STATUS(sr_slope_init(&slope_est, p, SR_C(0.1), SR_C(5.0)), SR_ERR_ARG);   /* 20 steps of 5 ms > 16 */
    CHECK_STATUS(sr_slope_init(&slope_est, p, (sr_real)NAN, SR_C(5.0)), SR_ERR_NONFINITE);
    p[SR_P_m_P] = -1;
    CHECK_STATUS(sr_slope_init(&slope_est, p, SR_C(0.02), SR_C(5.0)), SR_ERR_PARAM);
    paper_simulation_params(p);
    CHECK_STATUS(sr_slope_init(&slope_est, p, SR_C(0.02), SR_C(5.0)), SR_OK);
    CHECK_STATUS(sr_slope_reset(NULL), SR_ERR_NULL);
    make_state(x, 0.0, 0.0, (double)p[SR_P_r]);
    CHECK_STATUS(sr_slope_update(&slope_est, x, u), SR_OK);
    slope_kept = slope_est;
    CHECK_STATUS(sr_slope_update(NULL, x, u), SR_ERR_NULL);
    CHECK_STATUS(sr_slope_update(&slope_est, NULL, u), SR_ERR_NULL);
    u[1] = (sr_real)INFINITY;
    CHECK_STATUS(sr_slope_update(&slope_est, x, u), SR_ERR_NONFINITE);
    u[1] = 0;
    x[SR_X_R_S] += SR_C(0.1);
    CHECK_STATUS(sr_slope_update(&slope_est, x, u), SR_ERR_NOT_ROTATION);
    CHECK(memcmp(&slope_est, &slope_kept, sizeof slope_est) == 0);
}

void suite_slope(void)
{
    RUN_TEST(test_a_robot_rolling_on_a_slope_reads_as_that_slope_and_no_other_offset);
    RUN_TEST(test_on_level_ground_the_estimate_is_zero_and_the_slope_is_not_invented);
    RUN_TEST(test_bad_input_gives_status_and_leaves_the_estimator_untouched);
    RUN_TEST(test_weighted_a_robot_rolling_on_a_slope_still_reads_as_that_slope);
    RUN_TEST(test_weigh_refuses_a_bad_prior_scale_and_leaves_the_estimator_untouched);
}
