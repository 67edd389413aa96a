/*
 * test_sensors.c -- the sensor models (c/src/sr_sensors.c): the readings in states whose answer is known
 * by hand (at rest, on a slope, spinning), the Jacobians against central differences of the readings
 * through sr_retract, status codes and untouched outputs on error.
 */
#include "sr_test.h"
#include "sr_sensors.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

/* A mount on the body: lever arm (a, b, c), axes rotated by R (NULL: the body's). */
static void make_mount(sr_real mount[SR_NMOUNT], double a, double b, double c, const sr_real *R)
{
    int i;
    mount[SR_MOUNT_lever + 0] = (sr_real)a;
    mount[SR_MOUNT_lever + 1] = (sr_real)b;
    mount[SR_MOUNT_lever + 2] = (sr_real)c;
    for (i = 0; i < 9; ++i) mount[SR_MOUNT_R_m + i] = R ? R[i] : (sr_real)(i % 4 == 0);
}

static void test_accelerometer_at_rest_reads_g_upwards_gyroscope_zero(void)
{
    sr_real x[SR_NX], a[SR_NV] = {0}, mount[SR_NMOUNT], y[SR_NIMU];
    sr_model m;
    int body, i;
    paper_simulation_model(&m);
    make_state(x, 0.0, 0.0, (double)m.p[SR_P_r]);
    make_mount(mount, 0.02, -0.03, -0.05, NULL);
    for (body = 0; body < SR_NBODY; ++body) {
        CHECK_STATUS(sr_imu_measure(&m, x, a, body, mount, NULL, y), SR_OK);
        for (i = 0; i < 3; ++i) CHECK_NEAR(y[SR_IMU_gyro + i], 0, 0);
        CHECK_NEAR(y[SR_IMU_accel + 0], 0, 0);
        CHECK_NEAR(y[SR_IMU_accel + 1], 0, 0);
        CHECK_NEAR(y[SR_IMU_accel + 2], m.p[SR_P_g], 4 * TEST_EPS * m.p[SR_P_g]);
    }
}

static void test_accelerometer_on_a_slope_reads_g_along_the_vertical_in_the_floor_frame(void)
{
    /* The floor's frame is tilted by the slope (x up the slope): at rest the specific force is
     * g (sin(slope), 0, cos(slope)) in it; turned into a sensor rotated by pi/2 about z, (0, -g sin, g cos). */
    sr_real p[SR_NPARAM], x[SR_NX], a[SR_NV] = {0}, mount[SR_NMOUNT], Rz[9], y[SR_NIMU];
    sr_model m;
    double g, s;
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    g = (double)p[SR_P_g], s = (double)p[SR_P_slope];
    make_state(x, 0.0, 0.0, (double)p[SR_P_r]);
    rot_z(PI / 2, Rz);
    make_mount(mount, 0, 0, 0, Rz);
    CHECK_STATUS(sr_imu_measure(&m, x, a, SR_BODY_shell, mount, NULL, y), SR_OK);
    CHECK_NEAR(y[SR_IMU_accel + 0], 0, 8 * TEST_EPS * g);
    CHECK_NEAR(y[SR_IMU_accel + 1], -g * sin(s), 8 * TEST_EPS * g);
    CHECK_NEAR(y[SR_IMU_accel + 2], g * cos(s), 8 * TEST_EPS * g);
}

static void test_spinning_about_the_vertical_gives_the_centripetal_term_and_the_rate(void)
{
    /* Spinning about the floor's normal moves no contact point: the centre stays, a point at rho
     * e_x accelerates by -w^2 rho e_x; the gyroscope reads w e_z; biases add. */
    const double w = 3.0, rho = 0.1;
    sr_real x[SR_NX], a[SR_NV] = {0}, mount[SR_NMOUNT], y[SR_NIMU], bias[SR_NBIAS] = {SR_C(0.1), 0, 0, 0, 0, SR_C(0.5)};
    sr_model m;
    paper_simulation_model(&m);
    make_state(x, 0.0, 0.0, (double)m.p[SR_P_r]);
    x[SR_X_w_S + 2] = (sr_real)w;
    make_mount(mount, rho, 0, 0, NULL);
    CHECK_STATUS(sr_imu_measure(&m, x, a, SR_BODY_shell, mount, bias, y), SR_OK);
    CHECK_NEAR(y[SR_IMU_gyro + 0], 0.1, 4 * TEST_EPS);
    CHECK_NEAR(y[SR_IMU_gyro + 2], w, 4 * TEST_EPS * w);
    CHECK_NEAR(y[SR_IMU_accel + 0], -w * w * rho, 16 * TEST_EPS * w * w);
    CHECK_NEAR(y[SR_IMU_accel + 2], (double)m.p[SR_P_g] + 0.5, 16 * TEST_EPS * 10);
}

static void test_encoders_position_and_heading_read_the_angles_and_the_centre(void)
{
    sr_real x[SR_NX], y[2], mount[SR_NMOUNT], Rz[9], heading;
    sr_model m;
    paper_simulation_model(&m);
    make_state(x, 0.7, -2.5, (double)m.p[SR_P_r]);
    x[SR_X_q + 0] = SR_C(1.5), x[SR_X_q + 1] = SR_C(-0.25);
    rot_z(-2.0, x + SR_X_R_S);
    CHECK_STATUS(sr_encoders_measure(&m, x, y), SR_OK);
    CHECK_NEAR(y[0], 0.7, 8 * TEST_EPS);
    CHECK_NEAR(y[1], -2.5, 8 * TEST_EPS);
    CHECK_STATUS(sr_position_measure(&m, x, y), SR_OK);
    CHECK(y[0] == SR_C(1.5) && y[1] == SR_C(-0.25));
    /* The yoke turns about the shell's x axis: its x axis keeps the shell's heading, -2.0; a
     * sensor turned by 0.5 about the yoke's z axis reads -1.5 while the yoke is upright. */
    make_state(x, 0.0, 0.3, (double)m.p[SR_P_r]);
    rot_z(-2.0, x + SR_X_R_S);
    rot_z(0.5, Rz);
    make_mount(mount, 0, 0, 0, NULL);
    CHECK_STATUS(sr_heading_measure(&m, x, SR_BODY_yoke, mount, &heading), SR_OK);
    CHECK_NEAR(heading, -2.0, 8 * TEST_EPS);
    make_mount(mount, 0, 0, 0, Rz);
    CHECK_STATUS(sr_heading_measure(&m, x, SR_BODY_yoke, mount, &heading), SR_OK);
    CHECK_NEAR(heading, -1.5, 8 * TEST_EPS);
}

/* Largest |entry| of a matrix, for relative tolerances. */
static double largest(const sr_real *v, int n)
{
    double s = 0;
    int i;
    for (i = 0; i < n; ++i) s = fabs((double)v[i]) > s ? fabs((double)v[i]) : s;
    return s;
}

/* Every column of sr_imu_jacobian (nu_dot moving with the state under u) and of sr_heading_jacobian
 * against central differences of the readings through sr_retract and in the biases. */
static void check_jacobians_by_differences(const sr_real p[SR_NPARAM], unsigned long long seed)
{
    /* Step h: truncation ~h^2, rounding ~eps/h: 1e-4 in double, 3e-2 in float. */
    const double h = TEST_EPS < 1e-10 ? 1e-4 : 3e-2, tol = TEST_EPS < 1e-10 ? 1e-6 : 5e-2;
    sr_real x[SR_NX], xd[SR_NX], d[SR_NE], u[SR_NU] = {SR_C(0.3), SR_C(-0.2)}, mount[SR_NMOUNT], R[9];
    sr_real bias[SR_NBIAS] = {SR_C(0.01), SR_C(-0.02), SR_C(0.03), SR_C(0.1), SR_C(-0.2), SR_C(0.3)}, bd[SR_NBIAS];
    sr_real y[SR_NIMU], H[SR_NIMU * SR_NEB], yp[SR_NIMU], ym[SR_NIMU], psi, Hpsi[SR_NEB], pp, pm;
    test_rng rng = {seed};
    sr_model m;
    int body, k, i, s;
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    for (body = 0; body < SR_NBODY; ++body) {
        random_state(&rng, (double)p[SR_P_r], 2.0, x);
        random_state(&rng, 1.0, 1.0, xd); /* its R_S: a random mounting rotation */
        memcpy(R, xd + SR_X_R_S, sizeof R);
        make_mount(mount, rng_uniform(&rng, -0.1, 0.1), rng_uniform(&rng, -0.1, 0.1), rng_uniform(&rng, -0.1, 0.1), R);
        CHECK_STATUS(sr_imu_jacobian(&m, x, u, body, mount, bias, y, H), SR_OK);
        CHECK_STATUS(sr_heading_jacobian(&m, x, body, mount, &psi, Hpsi), SR_OK);
        for (k = 0; k < SR_NEB; ++k) {
            for (s = -1; s <= 1; s += 2) {
                memset(d, 0, sizeof d);
                memcpy(bd, bias, sizeof bd);
                if (k < SR_NE) d[k] = (sr_real)(s * h);
                else bd[k - SR_NE] += (sr_real)(s * h);
                CHECK_STATUS(sr_retract(&m, x, d, xd), SR_OK);
                CHECK_STATUS(sr_imu_measure_u(&m, xd, u, body, mount, bd, s > 0 ? yp : ym), SR_OK);
                CHECK_STATUS(sr_heading_measure(&m, xd, body, mount, s > 0 ? &pp : &pm), SR_OK);
            }
            for (i = 0; i < SR_NIMU; ++i)
                CHECK_NEAR(H[SR_NEB * i + k], ((double)yp[i] - (double)ym[i]) / (2 * h), tol * largest(H, SR_NIMU * SR_NEB));
            CHECK_NEAR(Hpsi[k], ((double)pp - (double)pm) / (2 * h), tol * largest(Hpsi, SR_NEB));
        }
    }
}

static void test_imu_and_heading_jacobians_are_central_differences_through_retract(void)
{
    sr_real p[SR_NPARAM];
    paper_simulation_params(p);
    check_jacobians_by_differences(p, 41);
}

static void test_imu_jacobians_of_a_general_robot_on_a_slope_are_central_differences(void)
{
    sr_real p[SR_NPARAM];
    general_robot_params(p);
    check_jacobians_by_differences(p, 43);
}

static void test_imu_jacobian_is_the_partials_composed_with_the_accel_jacobian(void)
{
    sr_real x[SR_NX], u[SR_NU] = {SR_C(0.2), SR_C(0.1)}, a[SR_NV], Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU];
    sr_real mount[SR_NMOUNT], y[SR_NIMU], y2[SR_NIMU], H[SR_NIMU * SR_NEB], H2[SR_NIMU * SR_NEB], Hn[SR_NIMU * SR_NV];
    test_rng rng = {47};
    sr_model m;
    int i, j, k;
    paper_simulation_model(&m);
    random_state(&rng, (double)m.p[SR_P_r], 3.0, x);
    make_mount(mount, 0.01, 0.02, -0.05, NULL);
    CHECK_STATUS(sr_accel(&m, x, u, a), SR_OK);
    CHECK_STATUS(sr_accel_jacobian(&m, x, u, Ja, Jb), SR_OK);
    CHECK_STATUS(sr_imu_partials(&m, x, a, SR_BODY_pendulum, mount, NULL, y, H, Hn), SR_OK);
    CHECK_STATUS(sr_imu_jacobian(&m, x, u, SR_BODY_pendulum, mount, NULL, y2, H2), SR_OK);
    for (i = 0; i < 3; ++i)
        for (k = 0; k < SR_NV; ++k) CHECK(Hn[SR_NV * (SR_IMU_gyro + i) + k] == 0);
    for (i = 0; i < SR_NIMU; ++i) {
        CHECK_NEAR(y2[i], y[i], 64 * TEST_EPS * (1 + fabs((double)y[i])));
        for (j = 0; j < SR_NEB; ++j) {
            double want = (double)H[SR_NEB * i + j];
            for (k = 0; j < SR_NE && k < SR_NV; ++k) want += (double)Hn[SR_NV * i + k] * (double)Ja[SR_NE * k + j];
            CHECK_NEAR(H2[SR_NEB * i + j], want, 256 * TEST_EPS * (1 + fabs(want)));
        }
    }
}

static void test_encoder_and_position_jacobians_pick_their_coordinates(void)
{
    sr_real x[SR_NX], y[2], H[2 * SR_NEB];
    sr_model m;
    int j;
    paper_simulation_model(&m);
    make_state(x, 0.4, 0.2, (double)m.p[SR_P_r]);
    CHECK_STATUS(sr_encoders_jacobian(&m, x, y, H), SR_OK);
    for (j = 0; j < SR_NEB; ++j) {
        CHECK(H[j] == (j == SR_EB_th_Y));
        CHECK(H[SR_NEB + j] == (j == SR_EB_th_P));
    }
    CHECK_STATUS(sr_position_jacobian(&m, x, y, H), SR_OK);
    for (j = 0; j < SR_NEB; ++j) {
        CHECK(H[j] == (j == SR_EB_q));
        CHECK(H[SR_NEB + j] == (j == SR_EB_q + 1));
    }
}

static void test_bad_input_gives_status_and_leaves_outputs_untouched(void)
{
    sr_real x[SR_NX], a[SR_NV] = {0}, mount[SR_NMOUNT], y[SR_NIMU], keep[SR_NIMU], heading = SR_C(7.0);
    sr_real bias[SR_NBIAS] = {0}, H[SR_NIMU * SR_NEB];
    sr_model m;
    int i;
    paper_simulation_model(&m);
    make_state(x, 0.0, 0.0, (double)m.p[SR_P_r]);
    make_mount(mount, 0, 0, 0, NULL);
    for (i = 0; i < SR_NIMU; ++i) y[i] = keep[i] = (sr_real)(i + 1);
    CHECK_STATUS(sr_imu_measure(&m, x, a, 3, mount, NULL, y), SR_ERR_ARG);
    CHECK_STATUS(sr_imu_measure(&m, x, a, -1, mount, NULL, y), SR_ERR_ARG);
    CHECK_STATUS(sr_imu_measure(&m, x, NULL, SR_BODY_yoke, mount, NULL, y), SR_ERR_NULL);
    CHECK_STATUS(sr_imu_measure(&m, x, a, SR_BODY_yoke, NULL, NULL, y), SR_ERR_NULL);
    bias[4] = (sr_real)NAN;
    CHECK_STATUS(sr_imu_measure(&m, x, a, SR_BODY_yoke, mount, bias, y), SR_ERR_NONFINITE);
    a[2] = (sr_real)INFINITY;
    CHECK_STATUS(sr_imu_measure(&m, x, a, SR_BODY_yoke, mount, NULL, y), SR_ERR_NONFINITE);
    a[2] = 0;
    mount[SR_MOUNT_R_m + 0] = SR_C(1.1);
    CHECK_STATUS(sr_imu_measure(&m, x, a, SR_BODY_yoke, mount, NULL, y), SR_ERR_NOT_ROTATION);
    CHECK_STATUS(sr_check_mount(SR_BODY_yoke, mount), SR_ERR_NOT_ROTATION);
    make_mount(mount, 0, 0, 0, NULL);
    mount[SR_MOUNT_lever + 1] = (sr_real)NAN;
    CHECK_STATUS(sr_imu_jacobian(&m, x, NULL, SR_BODY_yoke, mount, NULL, y, H), SR_ERR_NONFINITE);
    make_mount(mount, 0, 0, 0, NULL);
    x[SR_X_R_S + 1] = SR_C(0.5);
    CHECK_STATUS(sr_imu_measure(&m, x, a, SR_BODY_yoke, mount, NULL, y), SR_ERR_NOT_ROTATION);
    CHECK_STATUS(sr_position_measure(&m, x, y), SR_ERR_NOT_ROTATION);
    CHECK(memcmp(y, keep, sizeof keep) == 0);
    /* A sensor whose x axis is the floor's normal has no heading. */
    make_state(x, 0.0, 0.0, (double)m.p[SR_P_r]);
    rot_y(-PI / 2, mount + SR_MOUNT_R_m);
    CHECK_STATUS(sr_heading_measure(&m, x, SR_BODY_shell, mount, &heading), SR_ERR_SINGULAR);
    CHECK(heading == SR_C(7.0));
    CHECK_STATUS(sr_heading_measure(NULL, x, SR_BODY_shell, mount, &heading), SR_ERR_NULL);
}

void suite_sensors(void)
{
    RUN_TEST(test_accelerometer_at_rest_reads_g_upwards_gyroscope_zero);
    RUN_TEST(test_accelerometer_on_a_slope_reads_g_along_the_vertical_in_the_floor_frame);
    RUN_TEST(test_spinning_about_the_vertical_gives_the_centripetal_term_and_the_rate);
    RUN_TEST(test_encoders_position_and_heading_read_the_angles_and_the_centre);
    RUN_TEST(test_imu_and_heading_jacobians_are_central_differences_through_retract);
    RUN_TEST(test_imu_jacobians_of_a_general_robot_on_a_slope_are_central_differences);
    RUN_TEST(test_imu_jacobian_is_the_partials_composed_with_the_accel_jacobian);
    RUN_TEST(test_encoder_and_position_jacobians_pick_their_coordinates);
    RUN_TEST(test_bad_input_gives_status_and_leaves_outputs_untouched);
}
