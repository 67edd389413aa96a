/*
 * test_sim.c -- a robot on its sensors simulated into the EKF (c/src/sr_sim.c): at rest without
 * noise every sample is read once, the encoders on their quantisation grid, and reaches the filter
 * in order; the description's checks and the steps' range as status codes.
 */
#include "sr_test.h"
#include "sr_sim.h"

#include <math.h>
#include <string.h>

#define STEPS 4

typedef struct rig {
    sr_model m;
    sr_ekf ekf;
    sr_sim sim;
    sr_real x[SR_NX];
    sr_real times[STEPS], zeros[STEPS * SR_NIMU], imu[STEPS * SR_NIMU], enc[STEPS * 2];
    sr_real process[STEPS * SR_NV], bias[SR_NBIAS];
    long order[2 * 2 * STEPS];
} rig;

/* The robot at rest, an IMU and encoders sampled at every step start, no noise, no disturbance. */
static void make_rig(rig *r)
{
    sr_real sigma[SR_NEB];
    int i, k;
    memset(r, 0, sizeof *r);
    paper_simulation_model(&r->m);
    make_state(r->x, 0.3, 0.0, (double)r->m.p[SR_P_r]);
    for (i = 0; i < SR_NEB; ++i) sigma[i] = SR_C(0.01);
    CHECK_STATUS(sr_ekf_init_diagonal(&r->ekf, &r->m, r->x, NULL, sigma), SR_OK);
    r->sim.steps = STEPS;
    r->sim.dt = SR_C(0.005);
    r->sim.method = r->sim.filter_method = SR_RKMK4;
    r->sim.process = r->process;
    r->sim.bias = r->bias;
    r->sim.order = r->order;
    for (k = 0; k < STEPS; ++k) r->times[k] = (sr_real)k * r->sim.dt;
    for (k = 0; k < 2; ++k) {
        sr_sim_stream *s = &r->sim.stream[k];
        s->n = STEPS;
        s->time = s->arrival = r->times;
        s->draw = r->zeros;
        s->reading = k == SR_SIM_IMU ? r->imu : r->enc;
        s->body = s->filter_body = SR_BODY_yoke;
        for (i = 0; i < 3; ++i) s->mount[SR_MOUNT_R_m + 4 * i] = s->filter_mount[SR_MOUNT_R_m + 4 * i] = SR_C(1.0);
        for (i = 0; i < SR_NIMU; ++i) {
            s->range[i] = SR_C(100.0);
            s->sigma[i] = SR_C(0.01);
        }
        s->gate = (sr_real)INFINITY;
    }
    r->sim.stream[SR_SIM_ENCODERS].range[0] = SR_C(0.25);
}

static void test_at_rest_every_sample_is_read_once_and_reaches_the_filter_in_order(void)
{
    static rig r;
    long k;
    make_rig(&r);
    CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 0, STEPS, r.x, (sr_real[SR_NU]){0, 0}, NULL), SR_OK);
    CHECK(r.sim.applied == 2 * STEPS && r.ekf.accepted[SR_EKF_IMU] == STEPS
          && r.ekf.accepted[SR_EKF_ENCODERS] == STEPS);
    for (k = 0; k < 2 * STEPS; ++k) CHECK(r.order[2 * k] == k % 2 && r.order[2 * k + 1] == k / 2);
    CHECK_NEAR(r.enc[0], 0.25, 0);             /* theta_Y = 0.3 on a grid of 0.25 */
    for (k = 0; k < 3; ++k) CHECK_NEAR(r.imu[SR_IMU_gyro + k], 0, 0);   /* released at rest */
    CHECK_NEAR(r.sim.filter_time, (STEPS - 1) * 0.005, 1e-6);   /* the float build too */
}

/* filter_hold > 0: every IMU sample goes through sr_ekf_update_imu_held (the last one's disturbance
 * still held when the run ends); 0: through sr_ekf_update_imu_axes (nothing held). */
static void test_a_hold_sends_the_imu_through_the_held_update(void)
{
    static rig r;
    int hold;
    for (hold = 0; hold < 2; ++hold) {
        make_rig(&r);
        r.sim.filter_process.torque_psd[0] = r.sim.filter_process.torque_psd[1] = r.sim.filter_process.torque_psd[2]
            = SR_C(0.01);
        r.sim.filter_hold = hold ? r.sim.dt : 0;
        CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 0, STEPS, r.x, (sr_real[SR_NU]){0, 0}, NULL), SR_OK);
        CHECK(r.ekf.accepted[SR_EKF_IMU] == STEPS && r.ekf.held.pending == hold);
    }
}

static void test_a_bad_description_or_step_range_is_a_status_and_nothing_moves(void)
{
    static rig r;
    sr_real u[SR_NU] = {0, 0}, before[SR_NX];
    make_rig(&r);
    memcpy(before, r.x, sizeof before);
    CHECK_STATUS(sr_sim_check(NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 1, STEPS, r.x, u, NULL), SR_ERR_ARG);
    r.sim.bias_stride = 3;
    CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 0, 1, r.x, u, NULL), SR_ERR_ARG);
    r.sim.bias_stride = 0;
    r.sim.bias = NULL;
    CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 0, 1, r.x, u, NULL), SR_ERR_NULL);
    r.sim.bias = r.bias;
    r.sim.filter_hold = SR_C(-0.005);
    CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 0, 1, r.x, u, NULL), SR_ERR_ARG);
    r.sim.filter_hold = (sr_real)NAN;
    CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 0, 1, r.x, u, NULL), SR_ERR_ARG);
    r.sim.filter_hold = 0;
    r.sim.dt = 0;
    CHECK_STATUS(sr_sim_advance(&r.sim, &r.m, &r.ekf, &r.m, 0, 1, r.x, u, NULL), SR_ERR_ARG);
    CHECK(memcmp(before, r.x, sizeof before) == 0 && r.sim.stream[0].read == 0 && r.sim.applied == 0);
}

void suite_sim(void)
{
    RUN_TEST(test_at_rest_every_sample_is_read_once_and_reaches_the_filter_in_order);
    RUN_TEST(test_a_hold_sends_the_imu_through_the_held_update);
    RUN_TEST(test_a_bad_description_or_step_range_is_a_status_and_nothing_moves);
}
