/*
 * test_ekf.c -- the error-state EKF (c/src/sr_ekf.c): updates whose answer is known by hand (a
 * position fix on a diagonal covariance is a scalar Kalman filter per axis), the block structure
 * of the prediction, gating and the recovery from a run of refusals, the bias states, the observability
 * constraint, and status codes with nothing written on error.
 */
#include "sr_test.h"
#include "sr_ekf.h"

#include <math.h>
#include <string.h>

static const sr_real chi2_2 = SR_C(13.815510557964274); /* 99.9 % quantile, 2 degrees of freedom */

static void start(sr_ekf *ekf, sr_model *m, double sigma_all)
{
    sr_real x[SR_NX], sigma[SR_NEB];
    int i;
    paper_simulation_model(m);
    make_state(x, 0.1, -0.2, (double)m->p[SR_P_r]);
    for (i = 0; i < SR_NEB; ++i) sigma[i] = (sr_real)sigma_all;
    CHECK_STATUS(sr_ekf_init_diagonal(ekf, m, x, NULL, sigma), SR_OK);
}

static void test_a_position_fix_on_a_diagonal_covariance_is_the_scalar_filter_per_axis(void)
{
    /* P = p I, R = s^2: K = p/(p + s^2), q <- q + K r, P_qq <- (1-K)^2 p + K^2 s^2 = p s^2/(p + s^2) */
    sr_ekf ekf;
    sr_model m;
    const double p = 0.04, s = 0.1, k = p / (p + s * s);
    const sr_real y[2] = {SR_C(0.3), SR_C(-0.1)};
    start(&ekf, &m, sqrt(p));
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, (sr_real)s, chi2_2), SR_OK);
    CHECK_NEAR(ekf.x[SR_X_q + 0], k * 0.3, 8 * TEST_EPS);
    CHECK_NEAR(ekf.x[SR_X_q + 1], k * -0.1, 8 * TEST_EPS);
    CHECK_NEAR(ekf.P[SR_NEB * SR_EB_q + SR_EB_q], p * s * s / (p + s * s), 8 * TEST_EPS);
    CHECK_NEAR(ekf.P[SR_NEB * (SR_EB_q + 1) + SR_EB_q], 0, 8 * TEST_EPS);
    CHECK_NEAR(ekf.P[SR_NEB * SR_EB_nu + SR_EB_nu], p, 8 * TEST_EPS);
    CHECK(ekf.accepted[SR_EKF_POSITION] == 1 && ekf.gated[SR_EKF_POSITION] == 0);
}

static void test_an_outlier_is_gated_counted_and_not_applied(void)
{
    sr_ekf ekf, before;
    sr_model m;
    const sr_real y[2] = {SR_C(1.0), SR_C(0.0)}; /* 10 sigma off */
    start(&ekf, &m, 0.01);
    before = ekf;
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, SR_C(0.1), chi2_2), SR_OK);
    CHECK(ekf.gated[SR_EKF_POSITION] == 1 && ekf.accepted[SR_EKF_POSITION] == 0);
    CHECK(memcmp(ekf.x, before.x, sizeof ekf.x) == 0 && memcmp(ekf.P, before.P, sizeof ekf.P) == 0);
    CHECK(ekf.nis[SR_EKF_POSITION] > chi2_2);
    /* with the gate open the same sample is applied */
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, SR_C(0.1), (sr_real)INFINITY), SR_OK);
    CHECK(ekf.accepted[SR_EKF_POSITION] == 1);
}

static void test_after_n_refusals_in_a_row_the_next_outlier_is_admitted_with_the_prior_inflated(void)
{
    /* P = p I, R = s^2, the fix 1 m off: NIS = 1/(p + s^2) above the gate.  Refused twice, then
     * admitted with P and R times lambda = NIS/gate: the ungated gain k = p/(p + s^2) and
     * P_qq = lambda p s^2/(p + s^2); the other states' variance grows by lambda too. */
    sr_ekf ekf;
    sr_model m;
    const double p = 1e-4, s = 0.1, k = p / (p + s * s), lambda = 1 / (p + s * s) / (double)chi2_2;
    const sr_real y[2] = {SR_C(1.0), SR_C(0.0)};
    start(&ekf, &m, sqrt(p));
    CHECK_STATUS(sr_ekf_set_recovery(&ekf, SR_EKF_POSITION, 2), SR_OK);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, (sr_real)s, chi2_2), SR_OK);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, (sr_real)s, chi2_2), SR_OK);
    CHECK(ekf.gated[SR_EKF_POSITION] == 2 && ekf.streak[SR_EKF_POSITION] == 2 && ekf.x[SR_X_q] == 0);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, (sr_real)s, chi2_2), SR_OK);
    CHECK(ekf.recovered[SR_EKF_POSITION] == 1 && ekf.accepted[SR_EKF_POSITION] == 0);
    CHECK(ekf.gated[SR_EKF_POSITION] == 2 && ekf.streak[SR_EKF_POSITION] == 0);
    CHECK_NEAR(ekf.x[SR_X_q + 0], k, 8 * TEST_EPS);
    CHECK_NEAR(ekf.P[SR_NEB * SR_EB_q + SR_EB_q] / (lambda * p * s * s / (p + s * s)), 1, 64 * TEST_EPS);
    CHECK_NEAR(ekf.P[SR_NEB * SR_EB_nu + SR_EB_nu] / (lambda * p), 1, 64 * TEST_EPS);
    /* off (the start's policy): the same fix is refused however often it comes */
    start(&ekf, &m, sqrt(p));
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, (sr_real)s, chi2_2), SR_OK);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, (sr_real)s, chi2_2), SR_OK);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, y, (sr_real)s, chi2_2), SR_OK);
    CHECK(ekf.gated[SR_EKF_POSITION] == 3 && ekf.recovered[SR_EKF_POSITION] == 0 && ekf.x[SR_X_q] == 0);
}

static void test_encoder_innovations_wrap_around_pi(void)
{
    /* The estimate at theta_Y = 0.1; a reading of 0.1 - 2 pi is the same angle: no correction. */
    sr_ekf ekf;
    sr_model m;
    const sr_real y[2] = {(sr_real)(0.1 - 2 * 3.14159265358979323846), SR_C(-0.2)};
    sr_real before;
    start(&ekf, &m, 0.01);
    before = ekf.x[SR_X_R_Y + 7];
    CHECK_STATUS(sr_ekf_update_encoders(&ekf, &m, y, SR_C(0.001), chi2_2), SR_OK);
    CHECK(ekf.accepted[SR_EKF_ENCODERS] == 1);
    CHECK_NEAR(ekf.x[SR_X_R_Y + 7], before, 64 * TEST_EPS);
}

static void test_predict_leaves_the_bias_block_alone_and_moves_the_cross_terms(void)
{
    sr_ekf ekf;
    sr_model m;
    sr_ekf_process q = {{SR_C(0.01), SR_C(0.01), SR_C(0.01)}, 0, 0};
    const sr_real u[2] = {SR_C(0.1), SR_C(0.0)};
    const sr_real y[SR_NIMU] = {0, 0, 0, 0, 0, SR_C(9.81)};
    sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    sr_real bias_block[36];
    int i, j, nonzero = 0;
    start(&ekf, &m, 0.01);
    /* an IMU update correlates the biases with the rest */
    CHECK_STATUS(sr_ekf_update_imu(&ekf, &m, y, u, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02), (sr_real)INFINITY),
                 SR_OK);
    for (i = 0; i < 6; ++i)
        for (j = 0; j < 6; ++j) bias_block[6 * i + j] = ekf.P[SR_NEB * (SR_EB_b_g + i) + SR_EB_b_g + j];
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, u, SR_C(0.005), &q), SR_OK);
    for (i = 0; i < 6; ++i)
        for (j = 0; j < 6; ++j) CHECK(ekf.P[SR_NEB * (SR_EB_b_g + i) + SR_EB_b_g + j] == bias_block[6 * i + j]);
    for (i = 0; i < SR_NE; ++i)
        for (j = SR_NE; j < SR_NEB; ++j) {
            CHECK(ekf.P[SR_NEB * i + j] == ekf.P[SR_NEB * j + i]);
            nonzero += ekf.P[SR_NEB * i + j] != 0;
        }
    CHECK(nonzero > 0);
}

static void test_the_mean_steps_by_the_method_and_the_covariance_by_the_lie_euler_jacobian(void)
{
    /* Without process noise, from P = p I: x <- sr_step(RKMK4) bit for bit, P_dd <- p F F^T with F
     * the Lie-Euler step's Jacobian at the prior x (sr_ekf.h, "Transition matrix"); RKMK4's own
     * Jacobian differs from it by far more than the tolerance. */
    sr_ekf ekf;
    sr_model m;
    const sr_ekf_process q = {{0, 0, 0}, 0, 0};
    const sr_real u[2] = {SR_C(0.3), SR_C(-0.1)};
    const double dt = 0.005, p = 1e-4;
    sr_real x0[SR_NX], x1[SR_NX], F[SR_NE * SR_NE], Fk[SR_NE * SR_NE], G[SR_NE * SR_NU];
    double worst = 0, apart = 0;
    int i, j, k;
    start(&ekf, &m, sqrt(p));
    for (i = 0; i < SR_NV; ++i) ekf.x[SR_X_w_S + i] = (sr_real)(0.4 - 0.3 * i);
    memcpy(x0, ekf.x, sizeof x0);
    CHECK_STATUS(sr_step(&m, SR_RKMK4, x0, u, (sr_real)dt, x1), SR_OK);
    CHECK_STATUS(sr_step_jacobian_lie_euler(&m, x0, u, (sr_real)dt, F, G), SR_OK);
    CHECK_STATUS(sr_step_jacobian(&m, SR_RKMK4, x0, u, (sr_real)dt, Fk, G), SR_OK);
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, u, (sr_real)dt, &q), SR_OK);
    CHECK(memcmp(ekf.x, x1, sizeof x1) == 0);
    for (i = 0; i < SR_NE; ++i)
        for (j = 0; j < SR_NE; ++j) {
            double want = 0, other = 0;
            for (k = 0; k < SR_NE; ++k) {
                want += p * F[SR_NE * i + k] * F[SR_NE * j + k];
                other += p * Fk[SR_NE * i + k] * Fk[SR_NE * j + k];
            }
            worst = fmax(worst, fabs(ekf.P[SR_NEB * i + j] - want));
            apart = fmax(apart, fabs(other - want));
        }
    CHECK(worst <= 64 * TEST_EPS * p);
    CHECK(apart > 100 * 64 * TEST_EPS * p);   /* 1 % of p here */
}

static void test_the_bias_variances_grow_by_their_random_walk_over_dt(void)
{
    /* P_bb <- P_bb + dt diag(rw^2): the biases do not enter the step, only their random walk. */
    sr_ekf ekf;
    sr_model m;
    const sr_ekf_process q = {{SR_C(0.01), SR_C(0.01), SR_C(0.01)}, SR_C(0.02), SR_C(0.3)};
    const double dt = 0.005, p = 1e-4;
    int i;
    start(&ekf, &m, sqrt(p));
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, NULL, (sr_real)dt, &q), SR_OK);
    for (i = 0; i < 3; ++i) {
        CHECK_NEAR(ekf.P[SR_NEB * (SR_EB_b_g + i) + SR_EB_b_g + i], p + dt * 0.02 * 0.02, 8 * TEST_EPS);
        CHECK_NEAR(ekf.P[SR_NEB * (SR_EB_b_a + i) + SR_EB_b_a + i], p + dt * 0.3 * 0.3, 8 * TEST_EPS);
    }
}

static void test_a_constant_gyro_offset_at_rest_is_learnt_as_the_gyro_bias(void)
{
    sr_ekf ekf;
    sr_model m;
    sr_ekf_process q = {{SR_C(0.01), SR_C(0.01), SR_C(0.01)}, 0, 0};
    sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    sr_real x[SR_NX], sigma[SR_NEB], y[SR_NIMU];
    int i, k;
    paper_simulation_model(&m);
    make_state(x, 0, 0, (double)m.p[SR_P_r]);
    for (i = 0; i < SR_NEB; ++i) sigma[i] = SR_C(0.01);
    for (i = 0; i < 3; ++i) sigma[SR_EB_b_g + i] = SR_C(0.05);
    CHECK_STATUS(sr_ekf_init_diagonal(&ekf, &m, x, NULL, sigma), SR_OK);
    CHECK_STATUS(sr_imu_measure_u(&m, x, NULL, SR_BODY_yoke, mount, NULL, y), SR_OK);
    y[SR_IMU_gyro + 2] += SR_C(0.02);
    for (k = 0; k < 400; ++k) {
        CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, NULL, SR_C(0.005), &q), SR_OK);
        CHECK_STATUS(sr_ekf_update_imu(&ekf, &m, y, NULL, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02), (sr_real)INFINITY),
                     SR_OK);
    }
    CHECK_NEAR(ekf.bias[SR_BIAS_b_g + 2], 0.02, 0.002);
    CHECK(sqrt((double)ekf.P[SR_NEB * (SR_EB_b_g + 2) + SR_EB_b_g + 2]) < 0.01);
}

static void test_each_imu_reading_has_its_own_standard_deviation(void)
{
    /* A reading with a huge sigma is all but ignored, the others not; equal sigmas per sensor are
     * sr_ekf_update_imu's two numbers. */
    sr_ekf a, b, c, d;
    sr_model m;
    sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    sr_real y[SR_NIMU], off_x[SR_NIMU], off_z[SR_NIMU];
    const sr_real loose_z[SR_NIMU] = {SR_C(0.003), SR_C(0.003), SR_C(0.003), SR_C(0.02), SR_C(0.02), SR_C(1e4)};
    const sr_real same[SR_NIMU] = {SR_C(0.003), SR_C(0.003), SR_C(0.003), SR_C(0.02), SR_C(0.02), SR_C(0.02)};
    int i;
    start(&a, &m, 0.01);
    CHECK_STATUS(sr_imu_measure_u(&m, a.x, NULL, SR_BODY_yoke, mount, a.bias, y), SR_OK);
    memcpy(off_x, y, sizeof y);
    memcpy(off_z, y, sizeof y);
    off_x[SR_IMU_accel] += SR_C(0.05);
    off_z[SR_IMU_accel + 2] += SR_C(0.05);
    b = c = d = a;
    CHECK_STATUS(sr_ekf_update_imu_axes(&a, &m, off_z, NULL, SR_BODY_yoke, mount, loose_z, (sr_real)INFINITY), SR_OK);
    CHECK_STATUS(sr_ekf_update_imu_axes(&b, &m, y, NULL, SR_BODY_yoke, mount, loose_z, (sr_real)INFINITY), SR_OK);
    CHECK_STATUS(sr_ekf_update_imu_axes(&c, &m, off_x, NULL, SR_BODY_yoke, mount, loose_z, (sr_real)INFINITY), SR_OK);
    for (i = 0; i < SR_NBIAS; ++i) CHECK_NEAR(a.bias[i], b.bias[i], 1e-6);
    CHECK_NEAR(a.nis[SR_EKF_IMU], b.nis[SR_EKF_IMU], 1e-4);
    CHECK(c.nis[SR_EKF_IMU] > b.nis[SR_EKF_IMU] + 0.1);
    b = d;
    CHECK_STATUS(sr_ekf_update_imu_axes(&b, &m, off_x, NULL, SR_BODY_yoke, mount, same, (sr_real)INFINITY), SR_OK);
    CHECK_STATUS(sr_ekf_update_imu(&d, &m, off_x, NULL, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02),
                                   (sr_real)INFINITY), SR_OK);
    CHECK(memcmp(&b, &d, sizeof b) == 0);
}

static void test_a_fix_marked_and_applied_at_once_is_the_plain_fix(void)
{
    /* No time between the measuring instant and the arrival: the delayed update is the plain one. */
    sr_ekf plain, late;
    sr_model m;
    const sr_real y[2] = {SR_C(0.03), SR_C(-0.01)};
    int i;
    start(&plain, &m, 0.02);
    late = plain;
    CHECK_STATUS(sr_ekf_update_position(&plain, &m, y, SR_C(0.01), chi2_2), SR_OK);
    CHECK_STATUS(sr_ekf_mark_position(&late, &m, 2), SR_OK);
    CHECK(late.delayed[2].marked == 1);
    CHECK_STATUS(sr_ekf_update_position_delayed(&late, &m, 2, y, SR_C(0.01), chi2_2), SR_OK);
    CHECK(late.delayed[2].marked == 0 && late.accepted[SR_EKF_POSITION] == 1);
    for (i = 0; i < SR_NX; ++i) CHECK_NEAR(late.x[i], plain.x[i], 8 * TEST_EPS);
    for (i = 0; i < SR_NEB * SR_NEB; ++i) CHECK_NEAR(late.P[i], plain.P[i], 8 * TEST_EPS);
}

static void test_a_late_fix_corrects_the_estimate_by_what_it_said_when_it_measured(void)
{
    /* The robot rolling (q_x moves about 1 cm in the 8 samples between the measuring instant and
     * the arrival), P diagonal: the late fix corrects q by the scalar filter's gain times the fix
     * minus q then, whatever q became; taken as fresh it would pull q back by the distance rolled. */
    sr_ekf ekf, fresh;
    sr_model m;
    sr_ekf_process q = {{0, 0, 0}, 0, 0};
    const double p = 0.04, s = 0.1, k = p / (p + s * s);
    sr_real x[SR_NX], sigma[SR_NEB], y[2], before;
    int i;
    paper_simulation_model(&m);
    make_state(x, 0, 0, (double)m.p[SR_P_r]);
    x[SR_X_w_S + 1] = 1;
    for (i = 0; i < SR_NEB; ++i) sigma[i] = (sr_real)sqrt(p);
    CHECK_STATUS(sr_ekf_init_diagonal(&ekf, &m, x, NULL, sigma), SR_OK);
    CHECK_STATUS(sr_ekf_mark_position(&ekf, &m, 1), SR_OK);
    y[0] = ekf.x[SR_X_q] + SR_C(0.3);
    y[1] = ekf.x[SR_X_q + 1];
    for (i = 0; i < 8; ++i) CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, NULL, SR_C(0.005), &q), SR_OK);
    CHECK(fabs((double)(ekf.x[SR_X_q] - x[SR_X_q])) > 0.01);
    fresh = ekf;
    before = ekf.x[SR_X_q];
    CHECK_STATUS(sr_ekf_update_position_delayed(&ekf, &m, 1, y, (sr_real)s, chi2_2), SR_OK);
    CHECK_NEAR(ekf.x[SR_X_q] - before, k * 0.3, 64 * TEST_EPS);
    CHECK_STATUS(sr_ekf_update_position(&fresh, &m, y, (sr_real)s, (sr_real)INFINITY), SR_OK);
    CHECK(fabs((double)(fresh.x[SR_X_q] - ekf.x[SR_X_q])) > 0.005);
}

static void test_a_held_disturbance_is_read_by_the_imu_sample_and_spent_by_the_next_predict(void)
{
    /* An accelerometer reading off along x: the held update estimates a (pending), the predict moves
     * nu by dt a_hat on top of the step and drops a; a refused or bad sample leaves all as it was. */
    sr_ekf ekf, plain, before;
    sr_model m;
    sr_ekf_process q = {{SR_C(0.01), SR_C(0.01), SR_C(0.01)}, 0, 0};
    sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    sr_real y[SR_NIMU], a_hat[SR_NV], moved = 0;
    const sr_real sigma[SR_NIMU] = {SR_C(0.003), SR_C(0.003), SR_C(0.003), SR_C(0.02), SR_C(0.02), SR_C(0.02)};
    const sr_real dt = SR_C(0.005);
    int i;
    start(&ekf, &m, 0.01);
    CHECK_STATUS(sr_imu_measure_u(&m, ekf.x, NULL, SR_BODY_yoke, mount, ekf.bias, y), SR_OK);
    y[SR_IMU_accel] += SR_C(0.2);
    before = ekf;
    CHECK_STATUS(sr_ekf_update_imu_held(&ekf, &m, y, NULL, SR_BODY_yoke, mount, sigma, NULL, dt, chi2_2), SR_ERR_NULL);
    CHECK_STATUS(sr_ekf_update_imu_held(&ekf, &m, y, NULL, SR_BODY_yoke, mount, sigma, &q, 0, chi2_2), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_update_imu_held(&ekf, &m, y, NULL, SR_BODY_yoke, mount, sigma, &q, (sr_real)NAN, chi2_2),
                 SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_update_imu_held(&ekf, &m, y, NULL, SR_BODY_yoke, mount, sigma, &q, dt, SR_C(1e-6)), SR_OK);
    CHECK(ekf.gated[SR_EKF_IMU] == 1 && !ekf.held.pending);
    CHECK(memcmp(ekf.x, before.x, sizeof ekf.x) == 0 && memcmp(ekf.P, before.P, sizeof ekf.P) == 0);
    ekf = before;
    CHECK_STATUS(sr_ekf_update_imu_held(&ekf, &m, y, NULL, SR_BODY_yoke, mount, sigma, &q, dt, (sr_real)INFINITY),
                 SR_OK);
    CHECK(ekf.held.pending == 1);
    for (i = 0; i < SR_NV; ++i) moved += ekf.held.mean[i] * ekf.held.mean[i];
    CHECK(moved > 0);
    memcpy(a_hat, ekf.held.mean, sizeof a_hat);
    plain = ekf;
    plain.held.pending = 0;   /* the same filter without the held a */
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, NULL, dt, &q), SR_OK);
    CHECK_STATUS(sr_ekf_predict(&plain, &m, SR_RKMK4, NULL, dt, &q), SR_OK);
    CHECK(!ekf.held.pending);
    for (i = 0; i < SR_NV; ++i) CHECK_NEAR(ekf.x[SR_X_w_S + i] - plain.x[SR_X_w_S + i], dt * a_hat[i], 8 * TEST_EPS);
}

#ifndef SR_USE_FLOAT
/* n^T P^-1 n for the turn n (the first column of the constraint's N, or N at the estimate): P n' = n
 * by Gaussian elimination on a copy. */
static double information_along(const sr_ekf *ekf, const sr_real N[SR_NE * 3])
{
    double A[SR_NEB][SR_NEB + 1], s = 0;
    int i, j, k;
    for (i = 0; i < SR_NEB; ++i) {
        for (j = 0; j < SR_NEB; ++j) A[i][j] = ekf->P[SR_NEB * i + j];
        A[i][SR_NEB] = i < SR_NE ? N[3 * i] : 0;
    }
    for (k = 0; k < SR_NEB; ++k)
        for (i = k + 1; i < SR_NEB; ++i) {
            const double f = A[i][k] / A[k][k];
            for (j = k; j <= SR_NEB; ++j) A[i][j] -= f * A[k][j];
        }
    for (i = SR_NEB - 1; i >= 0; --i) {
        for (j = i + 1; j < SR_NEB; ++j) A[i][SR_NEB] -= A[i][j] * A[j][SR_NEB];
        A[i][SR_NEB] /= A[i][i];
        s += (i < SR_NE ? N[3 * i] : 0) * A[i][SR_NEB];
    }
    return s;
}

/* Without process noise: a predict, two IMU samples (the second away from where N was taken) and
 * an encoder sample, n^T P^-1 n before and after; N the filter's (constrained) or the turn at the
 * estimate (not). */
static void information_before_after(int constrained, double *before, double *after)
{
    sr_ekf ekf;
    sr_model m;
    sr_real N[SR_NE * 3] = {0};
    const sr_ekf_process quiet = {{0, 0, 0}, 0, 0};
    const sr_real u[2] = {SR_C(0.2), SR_C(0.05)}, enc[2] = {SR_C(0.001), SR_C(-0.002)};
    const sr_real y[SR_NIMU] = {SR_C(0.01), SR_C(-0.02), SR_C(0.03), SR_C(0.1), SR_C(-0.05), SR_C(9.7)};
    const sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    int i, k;
    start(&ekf, &m, 0.05);
    ekf.x[SR_X_q] = SR_C(0.7);
    ekf.x[SR_X_q + 1] = SR_C(-0.4);
    CHECK_STATUS(sr_ekf_set_observability_constraint(&ekf, &m, constrained), SR_OK);
    for (k = 0; k < 2; ++k) {
        CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, u, SR_C(0.005), &quiet), SR_OK);
        if (k == 1) break;
        CHECK_STATUS(sr_ekf_update_imu(&ekf, &m, y, u, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02), (sr_real)INFINITY), SR_OK);
    }
    for (i = 0; i < 3; ++i) N[3 * i] = ekf.x[SR_X_R_S + 6 + i];
    N[3 * SR_E_q] = -ekf.x[SR_X_q + 1];
    N[3 * (SR_E_q + 1)] = ekf.x[SR_X_q];
    if (constrained) {   /* right after a predict, the filter's N is the turn at its estimate */
        for (i = 0; i < SR_NE; ++i) CHECK(fabs(ekf.null_space[3 * i] - N[3 * i]) <= 1e-15);
    }
    *before = information_along(&ekf, N);
    for (k = 0; k < 2; ++k)
        CHECK_STATUS(sr_ekf_update_imu(&ekf, &m, y, u, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02), (sr_real)INFINITY), SR_OK);
    CHECK_STATUS(sr_ekf_update_encoders(&ekf, &m, enc, SR_C(0.0005), (sr_real)INFINITY), SR_OK);
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, u, SR_C(0.005), &quiet), SR_OK);
    if (constrained) memcpy(N, ekf.null_space, sizeof N);
    else {
        for (i = 0; i < 3; ++i) N[3 * i] = ekf.x[SR_X_R_S + 6 + i];
        N[3 * SR_E_q] = -ekf.x[SR_X_q + 1];
        N[3 * (SR_E_q + 1)] = ekf.x[SR_X_q];
    }
    *after = information_along(&ekf, N);
}
#endif

static void test_with_the_observability_constraint_the_imu_and_encoders_tell_nothing_of_the_heading(void)
{
#ifndef SR_USE_FLOAT
    double before, after;
    information_before_after(1, &before, &after);
    CHECK(fabs(after - before) <= 1e-9 * before);
    information_before_after(0, &before, &after);   /* the same without the constraint: it learns */
    CHECK(fabs(after - before) > 1e-6 * before);
#endif
}

static void test_the_observability_constraint_turned_off_is_the_filter_as_it_was(void)
{
    sr_ekf plain, toggled;
    sr_model m;
    const sr_ekf_process q = {{SR_C(0.01), SR_C(0.01), SR_C(0.01)}, 0, 0};
    const sr_real u[2] = {SR_C(0.1), 0}, y[SR_NIMU] = {0, 0, 0, 0, 0, SR_C(9.81)};
    const sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    start(&plain, &m, 0.01);
    toggled = plain;
    CHECK_STATUS(sr_ekf_set_observability_constraint(&toggled, &m, 1), SR_OK);
    CHECK(toggled.constrained == 1 && toggled.null_cols == 3);
    CHECK_STATUS(sr_ekf_set_observability_constraint(&toggled, &m, 0), SR_OK);
    CHECK(memcmp(&toggled, &plain, sizeof plain) == 0);
    CHECK_STATUS(sr_ekf_predict(&plain, &m, SR_RKMK4, u, SR_C(0.005), &q), SR_OK);
    CHECK_STATUS(sr_ekf_update_imu(&plain, &m, y, u, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02), (sr_real)INFINITY), SR_OK);
    CHECK_STATUS(sr_ekf_predict(&toggled, &m, SR_RKMK4, u, SR_C(0.005), &q), SR_OK);
    CHECK_STATUS(sr_ekf_update_imu(&toggled, &m, y, u, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02), (sr_real)INFINITY), SR_OK);
    CHECK(memcmp(&toggled, &plain, sizeof plain) == 0);
}

static void test_bad_input_gives_a_status_and_writes_nothing(void)
{
    sr_ekf ekf, before;
    sr_model m, broken;
    sr_ekf_process q = {{SR_C(0.01), SR_C(0.01), SR_C(0.01)}, 0, 0};
    sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    sr_real y[SR_NIMU] = {0, 0, 0, 0, 0, SR_C(9.81)}, P0[SR_NEB * SR_NEB];
    sr_real imu_sigma[SR_NIMU] = {SR_C(0.003), SR_C(0.003), SR_C(0.003), SR_C(0.02), SR_C(0.02), SR_C(0.02)};
    const sr_real fix[2] = {0, 0};
    int i;
    start(&ekf, &m, 0.01);
    before = ekf;
    broken = m;
    broken.p[SR_P_r] = SR_C(0.5);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &broken, fix, SR_C(0.1), chi2_2), SR_ERR_MODEL);
    CHECK_STATUS(sr_ekf_predict(&ekf, &broken, SR_RKMK4, NULL, SR_C(0.005), &q), SR_ERR_MODEL);
    CHECK_STATUS(sr_ekf_update_position(NULL, &m, fix, SR_C(0.1), chi2_2), SR_ERR_NULL);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, fix, SR_C(0.0), chi2_2), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_update_position(&ekf, &m, fix, SR_C(0.1), (sr_real)NAN), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, 7, NULL, SR_C(0.005), &q), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, NULL, SR_C(-0.005), &q), SR_ERR_ARG);
    q.torque_psd[1] = (sr_real)NAN;
    CHECK_STATUS(sr_ekf_predict(&ekf, &m, SR_RKMK4, NULL, SR_C(0.005), &q), SR_ERR_ARG);
    y[SR_IMU_accel + 1] = (sr_real)NAN;
    CHECK_STATUS(sr_ekf_update_imu(&ekf, &m, y, NULL, SR_BODY_yoke, mount, SR_C(0.003), SR_C(0.02), chi2_2),
                 SR_ERR_NONFINITE);
    CHECK_STATUS(sr_ekf_update_imu(&ekf, &m, y, NULL, 5, mount, SR_C(0.003), SR_C(0.02), chi2_2), SR_ERR_ARG);
    imu_sigma[SR_IMU_accel + 2] = 0;
    CHECK_STATUS(sr_ekf_update_imu_axes(&ekf, &m, y, NULL, SR_BODY_yoke, mount, imu_sigma, chi2_2), SR_ERR_ARG);
    imu_sigma[SR_IMU_accel + 2] = (sr_real)NAN;
    CHECK_STATUS(sr_ekf_update_imu_axes(&ekf, &m, y, NULL, SR_BODY_yoke, mount, imu_sigma, chi2_2), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_update_imu_axes(&ekf, &m, y, NULL, SR_BODY_yoke, mount, NULL, chi2_2), SR_ERR_NULL);
    CHECK_STATUS(sr_ekf_update_heading(&ekf, &m, (sr_real)NAN, SR_BODY_yoke, mount, SR_C(0.05), chi2_2),
                 SR_ERR_NONFINITE);
    CHECK_STATUS(sr_ekf_mark_position(&ekf, &m, SR_EKF_NDELAYED), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_mark_position(&ekf, &m, -1), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_mark_position(NULL, &m, 0), SR_ERR_NULL);
    CHECK_STATUS(sr_ekf_update_position_delayed(&ekf, &m, 0, fix, SR_C(0.1), chi2_2), SR_ERR_ARG); /* not marked */
    CHECK_STATUS(sr_ekf_update_position_delayed(&ekf, &broken, 0, fix, SR_C(0.1), chi2_2), SR_ERR_MODEL);
    CHECK_STATUS(sr_ekf_set_recovery(&ekf, SR_EKF_NKINDS, 1), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_set_recovery(&ekf, -1, 1), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_set_recovery(&ekf, SR_EKF_IMU, -1), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_set_recovery(NULL, SR_EKF_IMU, 1), SR_ERR_NULL);
    CHECK_STATUS(sr_ekf_set_observability_constraint(&ekf, &m, 2), SR_ERR_ARG);
    CHECK_STATUS(sr_ekf_set_observability_constraint(NULL, &m, 1), SR_ERR_NULL);
    CHECK_STATUS(sr_ekf_set_observability_constraint(&ekf, &broken, 1), SR_ERR_MODEL);
    CHECK(memcmp(&ekf, &before, sizeof ekf) == 0);
    /* a covariance that is not symmetric, or not positive definite */
    memcpy(P0, ekf.P, sizeof P0);
    P0[1] = SR_C(1e-5);
    CHECK_STATUS(sr_ekf_init(&ekf, &m, before.x, NULL, P0), SR_ERR_ARG);
    P0[1] = 0;
    for (i = 0; i < SR_NEB; ++i) P0[SR_NEB * i + i] = i == 4 ? -1 : 1;
    CHECK_STATUS(sr_ekf_init(&ekf, &m, before.x, NULL, P0), SR_ERR_SINGULAR);
    CHECK(memcmp(&ekf, &before, sizeof ekf) == 0);
}

void suite_ekf(void)
{
    RUN_TEST(test_a_position_fix_on_a_diagonal_covariance_is_the_scalar_filter_per_axis);
    RUN_TEST(test_an_outlier_is_gated_counted_and_not_applied);
    RUN_TEST(test_after_n_refusals_in_a_row_the_next_outlier_is_admitted_with_the_prior_inflated);
    RUN_TEST(test_encoder_innovations_wrap_around_pi);
    RUN_TEST(test_predict_leaves_the_bias_block_alone_and_moves_the_cross_terms);
    RUN_TEST(test_the_mean_steps_by_the_method_and_the_covariance_by_the_lie_euler_jacobian);
    RUN_TEST(test_the_bias_variances_grow_by_their_random_walk_over_dt);
    RUN_TEST(test_a_constant_gyro_offset_at_rest_is_learnt_as_the_gyro_bias);
    RUN_TEST(test_each_imu_reading_has_its_own_standard_deviation);
    RUN_TEST(test_a_fix_marked_and_applied_at_once_is_the_plain_fix);
    RUN_TEST(test_a_late_fix_corrects_the_estimate_by_what_it_said_when_it_measured);
    RUN_TEST(test_a_held_disturbance_is_read_by_the_imu_sample_and_spent_by_the_next_predict);
    RUN_TEST(test_with_the_observability_constraint_the_imu_and_encoders_tell_nothing_of_the_heading);
    RUN_TEST(test_the_observability_constraint_turned_off_is_the_filter_as_it_was);
    RUN_TEST(test_bad_input_gives_a_status_and_writes_nothing);
}
