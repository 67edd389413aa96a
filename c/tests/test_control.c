/*
 * test_control.c -- the LQR controller (c/src/sr_control.c) on hand-made schedules: the error
 * coordinates at and near the reference, the law at a grid point and between points, clipping
 * with conditional integration at any offset, the curvature's rate limit, the recovery at a large
 * error, and status codes with untouched outputs.
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

/* A state rolling at speed v along the heading psi exactly as the reference wants: the yoke
 * upright (R_S = rot_z(psi - pi/2), theta_Y = 0), w_S = (-v/r, 0, 0), w_Y = v/r. */
static void reference_state(double v, double psi, double r, sr_real x[SR_NX])
{
    make_state(x, 0.0, 0.0, r);
    rot_z(psi - PI / 2, x + SR_X_R_S);
    x[SR_X_w_S] = (sr_real)(-v / r);
    x[SR_X_w_Y] = (sr_real)(v / r);
}

/* One grid point (or two speeds), zero operating point, zero gains. */
static void empty_schedule(sr_lqr *lqr, int n_speeds)
{
    memset(lqr, 0, sizeof *lqr);
    lqr->n_speeds = n_speeds;
    lqr->n_curvatures = 1;
    lqr->speeds[0] = SR_C(0.2);
    if (n_speeds > 1) lqr->speeds[1] = SR_C(0.4);
    lqr->period = SR_C(0.02);
    lqr->u_max = SR_C(0.5);
    lqr->kappa_rate = SR_C(0.3);
    lqr->steady_rate = SR_C(0.005);
}

static void test_error_coordinates_vanish_at_the_reference_and_read_each_deviation(void)
{
    sr_model m;
    sr_real x[SR_NX], z[SR_LQR_NZ], R[9];
    const sr_real integrals[2] = {SR_C(0.25), SR_C(-0.5)};
    sr_lqr_target t = {SR_C(0.3), SR_C(0.7), 0, 0, 0};
    int i;
    paper_simulation_model(&m);
    reference_state(0.3, 0.7, 0.3, x);
    CHECK_STATUS(sr_lqr_error(&m, x, &t, NULL, z), SR_OK);
    for (i = 0; i < SR_LQR_NZ; ++i) CHECK_NEAR(z[i], 0.0, 8 * TEST_EPS);
    /* Heading 0.1 rad to the left of the reference: E = 0.1 about the world's vertical, which
     * is the yoke's z axis; the pendulum at 0.2; a cross-track error; the integrals as given. */
    reference_state(0.3, 0.8, 0.3, x);
    rot_y(0.2, x + SR_X_R_P);
    x[SR_X_w_P] = SR_C(0.4);
    t.path = 1;
    t.cross_track = SR_C(-0.05);
    CHECK_STATUS(sr_lqr_error(&m, x, &t, integrals, z), SR_OK);
    CHECK_NEAR(z[0], 0.0, 8 * TEST_EPS);
    CHECK_NEAR(z[1], 0.0, 8 * TEST_EPS);
    CHECK_NEAR(z[2], 0.1, 8 * TEST_EPS);
    CHECK_NEAR(z[3], 0.2, 8 * TEST_EPS);
    CHECK_NEAR(z[8], SR_C(0.4), 0);
    CHECK_NEAR(z[9], SR_C(-0.05), 0);
    CHECK_NEAR(z[10], 0.25, 0);
    CHECK_NEAR(z[11], -0.5, 0);
    /* The shell turned about the hinge, the yoke joint turned back: the same z (the symmetry the
     * coordinates are built on), including the shell's rate seen in the yoke's frame. */
    reference_state(0.3, 0.7, 0.3, x);
    rot_x(0.9, x + SR_X_R_Y);
    memcpy(R, x + SR_X_R_S, sizeof R);
    {
        sr_real Rx[9];
        rot_x(-0.9, Rx);
        for (i = 0; i < 9; ++i) {
            const int r = i / 3, c = i % 3;
            x[SR_X_R_S + i] = R[3 * r] * Rx[c] + R[3 * r + 1] * Rx[3 + c] + R[3 * r + 2] * Rx[6 + c];
        }
    }
    t.path = 0;
    CHECK_STATUS(sr_lqr_error(&m, x, &t, NULL, z), SR_OK);
    for (i = 0; i < SR_LQR_NZ; ++i) CHECK_NEAR(z[i], 0.0, 16 * TEST_EPS);
}

static void test_the_law_at_a_grid_point_is_u_star_minus_K_dz(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU], raw[SR_NU];
    const sr_lqr_target t = {SR_C(0.2), 0, 0, 0, 0};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    lqr.u_star[0][0] = SR_C(0.1);
    lqr.u_star[0][1] = SR_C(-0.05);
    lqr.z_star[0][3] = SR_C(0.1);               /* theta_P* = 0.1 */
    lqr.K_heading[0][3] = SR_C(2.0);            /* u_Y -= 2 (theta_P - 0.1) */
    lqr.K_heading[0][SR_LQR_NZ + 8] = SR_C(0.5); /* u_P -= 0.5 w_P */
    CHECK_STATUS(sr_lqr_check(&lqr), SR_OK);
    CHECK_STATUS(sr_lqr_reset(&mem), SR_OK);
    reference_state(0.2, 0.0, 0.3, x);
    rot_y(0.15, x + SR_X_R_P);
    x[SR_X_w_P] = SR_C(0.2);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, raw), SR_OK);
    CHECK_NEAR(u[0], 0.1 - 2.0 * 0.05, 16 * TEST_EPS);
    CHECK_NEAR(u[1], -0.05 - 0.5 * 0.2, 16 * TEST_EPS);
    CHECK(u[0] == raw[0] && u[1] == raw[1] && mem.saturated == 0);
    /* Not clipped: the integrals advanced by one period (no path: e_y's stays 0). */
    CHECK_NEAR(mem.integrals[0], 0.0, 0);
    CHECK_NEAR(mem.integrals[1], 0.0, 16 * TEST_EPS);
}

static void test_between_two_speeds_the_law_interpolates_linearly_and_clamps_outside(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU];
    sr_lqr_target t = {SR_C(0.25), 0, 0, 0, 0};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 2);
    lqr.u_star[0][0] = SR_C(0.1);
    lqr.u_star[1][0] = SR_C(0.3);
    reference_state(0.25, 0.0, 0.3, x);
    sr_lqr_reset(&mem);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_NEAR(u[0], 0.15, 8 * TEST_EPS);
    t.speed = SR_C(0.9);
    reference_state(0.9, 0.0, 0.3, x);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_NEAR(u[0], SR_C(0.3), 0);
}

static void test_the_cross_track_integral_acts_at_any_offset_and_holds_only_against_a_clipped_torque(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU], raw[SR_NU];
    const sr_lqr_target far = {SR_C(0.2), 0, 0, SR_C(0.3), 1};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    lqr.steady_rate = SR_C(0.01);
    lqr.K_path[0][9] = SR_C(-1.0);              /* u_Y = e_y + I = 0.3 N m: free */
    lqr.K_path[0][10] = SR_C(-1.0);
    sr_lqr_reset(&mem);
    reference_state(0.2, 0.0, 0.3, x);
    /* 0.3 m off the path, rolling along it, torques free: the integral advances. */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &far, &mem, u, raw), SR_OK);
    CHECK(mem.saturated == 0);
    CHECK_NEAR(mem.integrals[0], 0.02 * 0.3, 8 * TEST_EPS);
    /* u_Y = 10 e_y + I = 3 N m, clipped to 0.5: the integral's step (+) would push it further: held. */
    lqr.K_path[0][9] = SR_C(-10.0);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &far, &mem, u, raw), SR_OK);
    CHECK(u[0] == SR_C(0.5) && mem.saturated == 1);
    CHECK_NEAR(mem.integrals[0], 0.02 * 0.3, 8 * TEST_EPS);
    /* The same excess with the integral's gain reversed: its step pulls u_Y back, so it advances. */
    lqr.K_path[0][10] = SR_C(1.0);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &far, &mem, u, raw), SR_OK);
    CHECK(mem.saturated == 1);
    CHECK_NEAR(mem.integrals[0], 2 * 0.02 * 0.3, 8 * TEST_EPS);
}

static void test_a_world_share_of_the_cross_track_integral_is_held_along_the_paths_normal(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU], raw[SR_NU];
    const sr_lqr_target along_x = {SR_C(0.2), 0, 0, SR_C(0.3), 1};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    lqr.steady_rate = SR_C(0.01);
    lqr.K_path[0][10] = SR_C(-1.0);             /* u_Y = I: free */
    lqr.world_share = SR_C(0.25);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_OK);
    sr_lqr_reset(&mem);
    reference_state(0.2, 0.0, 0.3, x);
    /* Heading +x: the left normal is +y; a quarter of the step goes to the world's y. */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &along_x, &mem, u, raw), SR_OK);
    CHECK_NEAR(mem.integrals[0], 0.75 * 0.02 * 0.3, 8 * TEST_EPS);
    CHECK_NEAR(mem.world[0], 0.0, 8 * TEST_EPS);
    CHECK_NEAR(mem.world[1], 0.25 * 0.02 * 0.3, 8 * TEST_EPS);
    /* ... and z[10] reads both: u_Y = I + n . W = 0.02 * 0.3 at the next sample. */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &along_x, &mem, u, raw), SR_OK);
    CHECK_NEAR(u[0], 0.02 * 0.3, 8 * TEST_EPS);
    lqr.world_share = SR_C(1.5);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &along_x, &mem, u, raw), SR_ERR_ARG);
    lqr.world_share = SR_C(-0.1);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
}

static void test_the_cross_track_integral_holds_while_the_error_moves(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU];
    /* The path heads 0.2 rad left of the robot, which rolls at 0.2 m/s: the error moves at
     * 0.2 sin 0.2 = 0.04 m/s (towards the path from its left; away from it from its right). */
    sr_lqr_target t = {SR_C(0.2), SR_C(0.2), 0, SR_C(0.3), 1};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    lqr.steady_rate = SR_C(0.01);
    sr_lqr_reset(&mem);
    reference_state(0.2, 0.0, 0.3, x);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK(mem.integrals[0] == 0);
    t.cross_track = SR_C(-0.3);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK(mem.integrals[0] == 0);
    /* Moving more slowly than steady_rate: integrated. */
    lqr.steady_rate = SR_C(0.05);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_NEAR(mem.integrals[0], -0.02 * 0.3, 8 * TEST_EPS);
}

static void test_the_operating_curvature_follows_a_jump_at_its_rate(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU];
    sr_lqr_target t = {SR_C(0.2), 0, SR_C(0.5), 0, 1};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    sr_lqr_reset(&mem);
    reference_state(0.2, 0.0, 0.3, x);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK(mem.kappa == SR_C(0.5));
    t.curvature = SR_C(-0.5);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_NEAR(mem.kappa, 0.5 - 0.3 * 0.02, 8 * TEST_EPS);
}

static void test_the_tight_gains_weigh_in_as_the_error_allows_and_are_checked(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU], raw[SR_NU];
    sr_lqr_target t = {SR_C(0.2), 0, 0, SR_C(0.005), 1};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    lqr.K_tight[0][9] = SR_C(10.0);                      /* yoke torque per metre of e_y */
    lqr.K_tight[0][10] = SR_C(1e6);                      /* an integral column: never read */
    lqr.tight_band = SR_C(0.02);
    lqr.tight_rise = SR_C(0.04);                         /* two samples from 0 to 1 */
    CHECK_STATUS(sr_lqr_check(&lqr), SR_OK);
    sr_lqr_reset(&mem);
    mem.integrals[0] = SR_C(1.0);
    reference_state(0.2, 0.0, 0.3, x);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, raw), SR_OK);
    CHECK_NEAR(mem.tight, 0.5, TEST_EPS);                /* the rise: one period / tight_rise */
    CHECK_NEAR(raw[0], -0.5 * 10.0 * 0.005, 8 * TEST_EPS);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, raw), SR_OK);
    CHECK_NEAR(mem.tight, 0.75, TEST_EPS);               /* the bound 1 - |e_y| / tight_band */
    lqr.tight_rise = 0;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    lqr.tight_rise = SR_C(0.04);
    lqr.K_tight[0][3] = (sr_real)NAN;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_NONFINITE);
    lqr.tight_band = 0;                                  /* off: K_tight is not read */
    CHECK_STATUS(sr_lqr_check(&lqr), SR_OK);
    lqr.tight_band = SR_C(-0.01);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
}

static void test_the_tight_gains_weight_falls_after_a_clipped_torque_to_minus_its_wait(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU];
    int k;
    sr_lqr_target t = {SR_C(0.2), 0, 0, 0, 1};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    lqr.tight_band = SR_C(0.02);
    lqr.tight_rise = SR_C(0.04);                         /* two samples from 0 to 1 */
    lqr.tight_fall = SR_C(0.1);                          /* five samples from 1 to 0 */
    CHECK_STATUS(sr_lqr_check(&lqr), SR_OK);
    sr_lqr_reset(&mem);
    reference_state(0.2, 0.0, 0.3, x);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_NEAR(mem.tight, 1.0, TEST_EPS);
    mem.saturated = 1;                                   /* as after a clipped torque */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_NEAR(mem.tight, 1.0 - 0.02 / 0.1, TEST_EPS);   /* the fall: one period / tight_fall */
    lqr.tight_fall = 0;                                  /* no fall time: the weight holds */
    mem.saturated = 1;
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    CHECK_NEAR(mem.tight, 1.0 - 0.02 / 0.1, TEST_EPS);
    lqr.tight_fall = SR_C(0.1);
    lqr.tight_wait = SR_C(0.3);                         /* below 0 to -0.3 (K_path's gain) */
    for (k = 0; k < 6; ++k) {
        mem.saturated = 1;
        CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_OK);
    }
    CHECK_NEAR(mem.tight, -0.3, TEST_EPS);               /* 0.8 - 6 * 0.2 = -0.4, held at -0.3 */
    lqr.tight_wait = SR_C(1.5);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    lqr.tight_wait = 0;
    lqr.tight_fall = SR_C(-0.1);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    lqr.tight_fall = (sr_real)NAN;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_NONFINITE);
}

static void test_the_recovery_clips_the_errors_holds_the_integrals_and_lowers_the_speed(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem;
    sr_real x[SR_NX], u[SR_NU], raw[SR_NU];
    const sr_lqr_target far = {SR_C(0.2), 0, 0, SR_C(0.3), 1}, near = {SR_C(0.2), 0, 0, SR_C(0.05), 1};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    lqr.steady_rate = SR_C(0.01);
    lqr.K_path[0][9] = SR_C(-1.0);               /* u_Y = e_y (clipped) + I */
    lqr.K_path[0][10] = SR_C(-1.0);
    lqr.K_path[0][SR_LQR_NZ + 4] = SR_C(1.0);    /* u_P = -(z[4] - z*[4]): the rolling-rate error */
    lqr.recovery_cross_track = SR_C(0.1);
    lqr.recovery_slow = SR_C(0.5);
    lqr.recovery_rise = SR_C(0.04);              /* two samples from 0 to 1 */
    CHECK_STATUS(sr_lqr_check(&lqr), SR_OK);
    sr_lqr_reset(&mem);
    reference_state(0.2, 0.0, 0.3, x);
    /* 0.3 m off: the law acts on 0.1 m, neither integral advances, the weight rises by one half. */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &far, &mem, u, raw), SR_OK);
    CHECK_NEAR(raw[0], 0.1, 8 * TEST_EPS);
    CHECK_NEAR(raw[1], 0.0, 8 * TEST_EPS);
    CHECK(mem.integrals[0] == 0 && mem.integrals[1] == 0);
    CHECK_NEAR(mem.recovery, 0.5, TEST_EPS);
    /* The next sample tracks 0.2 (1 - 0.5 * 0.5) = 0.15 m/s: the robot at 0.2 m/s rolls 0.05 m/s too fast,
     * z[4] - z*[4] = -0.05 / r, so u_P = 0.05 / r. */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &far, &mem, u, raw), SR_OK);
    CHECK_NEAR(raw[1], 0.05 / 0.3, 8 * TEST_EPS);
    CHECK_NEAR(mem.recovery, 1.0, TEST_EPS);
    /* Back within the bound: the law acts on the error itself, the integral advances, the weight falls. */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &near, &mem, u, raw), SR_OK);
    CHECK_NEAR(raw[0], 0.05, 8 * TEST_EPS);
    CHECK_NEAR(mem.integrals[0], 0.02 * 0.05, 8 * TEST_EPS);
    CHECK_NEAR(mem.recovery, 0.5, TEST_EPS);
    /* The heading error too: a robot turned 0.3 rad off acts as if 0.2 rad off. */
    lqr.K_path[0][2] = SR_C(-1.0);
    lqr.K_path[0][9] = 0;
    lqr.recovery_heading = SR_C(0.2);
    sr_lqr_reset(&mem);
    reference_state(0.2, 0.3, 0.3, x);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &near, &mem, u, raw), SR_OK);
    CHECK_NEAR(raw[0], 0.2, 8 * TEST_EPS);
    CHECK(mem.integrals[0] == 0);
    /* Refused: negative bounds, a slow-down of the whole speed or more, one with no rise time, NaN. */
    lqr.recovery_cross_track = SR_C(-0.1);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &near, &mem, u, raw), SR_ERR_ARG);
    lqr.recovery_cross_track = SR_C(0.1);
    lqr.recovery_heading = SR_C(-0.2);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    lqr.recovery_heading = SR_C(0.2);
    lqr.recovery_slow = SR_C(1.0);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    lqr.recovery_slow = SR_C(0.5);
    lqr.recovery_rise = 0;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    lqr.recovery_rise = (sr_real)NAN;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_NONFINITE);
    lqr.recovery_rise = SR_C(0.04);
    CHECK_STATUS(sr_lqr_check(&lqr), SR_OK);
}

static void test_bad_input_gives_status_and_leaves_outputs_untouched(void)
{
    sr_model m;
    sr_lqr lqr;
    sr_lqr_memory mem, kept;
    sr_real x[SR_NX], u[SR_NU] = {7, 7}, z[SR_LQR_NZ];
    sr_lqr_target t = {SR_C(0.2), 0, 0, 0, 0};
    paper_simulation_model(&m);
    empty_schedule(&lqr, 1);
    sr_lqr_reset(&mem);
    mem.integrals[0] = SR_C(0.125);
    kept = mem;
    reference_state(0.2, 0.0, 0.3, x);
    CHECK_STATUS(sr_lqr_check(NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_lqr_reset(NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_lqr_control(NULL, &m, x, &t, &mem, u, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, NULL, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_lqr_error(&m, x, NULL, NULL, z), SR_ERR_NULL);
    lqr.n_speeds = 0;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_ERR_ARG);
    lqr.n_speeds = SR_LQR_MAX_SPEEDS + 1;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    empty_schedule(&lqr, 2);
    lqr.speeds[1] = lqr.speeds[0];                       /* not increasing */
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    empty_schedule(&lqr, 1);
    lqr.K_path[0][5] = (sr_real)NAN;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_NONFINITE);
    t.path = 1;                                          /* the NaN gain is used: caught in the result */
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_ERR_NONFINITE);
    empty_schedule(&lqr, 1);
    lqr.u_max = 0;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_ARG);
    lqr.u_max = (sr_real)INFINITY;
    CHECK_STATUS(sr_lqr_check(&lqr), SR_ERR_NONFINITE);
    empty_schedule(&lqr, 1);
    t.cross_track = (sr_real)NAN;
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_ERR_NONFINITE);
    CHECK_STATUS(sr_lqr_error(&m, x, &t, NULL, z), SR_ERR_NONFINITE);
    t.cross_track = 0;
    x[SR_X_R_S] += SR_C(0.1);
    CHECK_STATUS(sr_lqr_control(&lqr, &m, x, &t, &mem, u, NULL), SR_ERR_NOT_ROTATION);
    CHECK(u[0] == 7 && u[1] == 7);
    CHECK(memcmp(&mem, &kept, sizeof mem) == 0);
}

void suite_control(void)
{
    RUN_TEST(test_error_coordinates_vanish_at_the_reference_and_read_each_deviation);
    RUN_TEST(test_the_law_at_a_grid_point_is_u_star_minus_K_dz);
    RUN_TEST(test_between_two_speeds_the_law_interpolates_linearly_and_clamps_outside);
    RUN_TEST(test_the_cross_track_integral_acts_at_any_offset_and_holds_only_against_a_clipped_torque);
    RUN_TEST(test_a_world_share_of_the_cross_track_integral_is_held_along_the_paths_normal);
    RUN_TEST(test_the_cross_track_integral_holds_while_the_error_moves);
    RUN_TEST(test_the_operating_curvature_follows_a_jump_at_its_rate);
    RUN_TEST(test_the_tight_gains_weigh_in_as_the_error_allows_and_are_checked);
    RUN_TEST(test_the_tight_gains_weight_falls_after_a_clipped_torque_to_minus_its_wait);
    RUN_TEST(test_the_recovery_clips_the_errors_holds_the_integrals_and_lowers_the_speed);
    RUN_TEST(test_bad_input_gives_status_and_leaves_outputs_untouched);
}
