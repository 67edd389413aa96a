/*
 * test_jacobians.c -- sr_accel_jacobian (c/src/sr_jacobians.c): each column is the central difference
 * of sr_accel along sr_retract (or along u); status codes and untouched outputs on error; the
 * accelerations its internal form gives the step Jacobians are sr_accel's.
 */
#include "sr_test.h"
#include "../src/sr_jacobians.h" /* sr_internal_accel_jacobian: the step Jacobians' stage values, tested directly */

#include <math.h>
#include <string.h>

static void test_accel_jacobian_columns_are_central_differences_along_retract(void)
{
    /* Step h: truncation ~h^2, rounding ~eps/h: 1e-4 in double, 3e-2 in float. */
    const double h = TEST_EPS < 1e-10 ? 1e-4 : 3e-2, tol = TEST_EPS < 1e-10 ? 1e-6 : 3e-2;
    sr_real p[SR_NPARAM], x[SR_NX], y[SR_NX], u[SR_NU] = {SR_C(0.05), SR_C(-0.02)}, up[SR_NU], d[SR_NE];
    sr_real Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU], ap[SR_NV], am[SR_NV];
    test_rng rng = {23};
    sr_model m;
    double scale = 0;
    int k, i, s;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 2.0, x);
    CHECK_STATUS(sr_accel_jacobian(&m, x, u, Ja, Jb), SR_OK);
    for (i = 0; i < SR_NV * SR_NE; ++i) scale = fabs((double)Ja[i]) > scale ? fabs((double)Ja[i]) : scale;
    for (k = 0; k < SR_NE; ++k) {
        for (s = -1; s <= 1; s += 2) {
            memset(d, 0, sizeof d);
            d[k] = (sr_real)(s * h);
            CHECK_STATUS(sr_retract(&m, x, d, y), SR_OK);
            CHECK_STATUS(sr_accel(&m, y, u, s > 0 ? ap : am), SR_OK);
        }
        for (i = 0; i < SR_NV; ++i)
            CHECK_NEAR(Ja[SR_NE * i + k], ((double)ap[i] - (double)am[i]) / (2 * h), tol * scale);
    }
    for (k = 0; k < SR_NU; ++k) {
        for (s = -1; s <= 1; s += 2) {
            memcpy(up, u, sizeof up);
            up[k] += (sr_real)(s * h);
            CHECK_STATUS(sr_accel(&m, x, up, s > 0 ? ap : am), SR_OK);
        }
        for (i = 0; i < SR_NV; ++i)
            CHECK_NEAR(Jb[SR_NU * i + k], ((double)ap[i] - (double)am[i]) / (2 * h), tol * scale);
    }
}

/* The step Jacobians take each stage's accelerations from sr_internal_accel_jacobian (for the
 * paper's robot solved in the yoke frame and turned by R_Y; for a general one by Cholesky), not
 * from sr_accel: both robots, to rounding. */
static void test_internal_accel_jacobian_gives_the_accelerations_of_sr_accel(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], u[SR_NU] = {SR_C(0.05), SR_C(-0.02)}, a[SR_NV], b[SR_NV];
    sr_real Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU];
    test_rng rng = {31};
    sr_model m;
    int robot, n, i;
    for (robot = 0; robot < 2; ++robot) {
        if (robot) general_robot_params(p);
        else paper_simulation_params(p);
        CHECK_STATUS(sr_model_init(&m, p), SR_OK);
        CHECK(m.general == robot);
        for (n = 0; n < 20; ++n) {
            double scale = 1;
            random_state(&rng, p[SR_P_r], 3.0, x);
            CHECK_STATUS(sr_accel(&m, x, u, a), SR_OK);
            CHECK_STATUS(sr_internal_accel_jacobian(&m, x, u, b, Ja, Jb), SR_OK);
            for (i = 0; i < SR_NV; ++i) scale = fabs((double)a[i]) > scale ? fabs((double)a[i]) : scale;
            for (i = 0; i < SR_NV; ++i) CHECK_NEAR(b[i], a[i], 64 * TEST_EPS * scale);
        }
    }
}

/* The step Jacobians' stages take Ja dy from sr_internal_accel_jacobian_along, which for the paper's
 * robot applies the yoke frame's chain rule to the directions and never forms Ja: it must equal Ja's
 * read columns times the directions, Jb and the accelerations alike, for both robots (tolerance
 * 256 eps of the largest term: a product off by 1e-9 relative is far outside it). */
static void test_accel_jacobian_along_directions_is_ja_times_the_directions(void)
{
    static const int column[SR_J_READ] = {SR_E_xi_S + 0, SR_E_xi_S + 1, SR_E_xi_S + 2, SR_E_th_Y, SR_E_th_P,
                                          SR_E_nu + 0, SR_E_nu + 1, SR_E_nu + 2, SR_E_nu + 3, SR_E_nu + 4};
    sr_real p[SR_NPARAM], x[SR_NX], u[SR_NU] = {SR_C(0.05), SR_C(-0.02)}, a[SR_NV], b[SR_NV];
    sr_real Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU], Jb2[SR_NV * SR_NU], V[SR_J_READ][SR_J_NC], out[SR_NV][SR_J_NC];
    test_rng rng = {37};
    sr_model m;
    int robot, n, i, k, l;
    for (robot = 0; robot < 2; ++robot) {
        if (robot) general_robot_params(p);
        else paper_simulation_params(p);
        CHECK_STATUS(sr_model_init(&m, p), SR_OK);
        for (n = 0; n < 20; ++n) {
            random_state(&rng, p[SR_P_r], 3.0, x);
            for (k = 0; k < SR_J_READ; ++k)
                for (l = 0; l < SR_J_NC; ++l) V[k][l] = (sr_real)rng_uniform(&rng, -1, 1);
            CHECK_STATUS(sr_internal_accel_jacobian(&m, x, u, a, Ja, Jb), SR_OK);
            CHECK_STATUS(sr_internal_accel_jacobian_along(&m, x, u, (const sr_real(*)[SR_J_NC])V, b, out, Jb2), SR_OK);
            for (i = 0; i < SR_NV; ++i) {
                double scale = 1;
                for (k = 0; k < SR_J_READ; ++k)
                    scale = fabs((double)Ja[SR_NE * i + column[k]]) > scale ? fabs((double)Ja[SR_NE * i + column[k]]) : scale;
                for (l = 0; l < SR_J_NC; ++l) {
                    double want = 0;
                    for (k = 0; k < SR_J_READ; ++k) want += (double)Ja[SR_NE * i + column[k]] * (double)V[k][l];
                    CHECK_NEAR(out[i][l], want, 256 * TEST_EPS * scale);
                }
                for (k = 0; k < SR_NU; ++k) CHECK_NEAR(Jb2[SR_NU * i + k], Jb[SR_NU * i + k], 64 * TEST_EPS * (1 + fabs((double)Jb[SR_NU * i + k])));
                CHECK_NEAR(b[i], a[i], 64 * TEST_EPS * (1 + fabs((double)a[i])));
            }
        }
    }
}

static void test_accel_jacobian_bad_input_leaves_outputs_untouched(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], Ja[SR_NV * SR_NE], Jb[SR_NV * SR_NU], keep[SR_NV * SR_NE];
    test_rng rng = {29};
    sr_model m;
    long failed = 5;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 1.0, x);
    memset(Ja, 0x5a, sizeof Ja);
    memcpy(keep, Ja, sizeof Ja);
    x[SR_X_w_P] = (sr_real)INFINITY;
    CHECK_STATUS(sr_accel_jacobian(&m, x, NULL, Ja, Jb), SR_ERR_NONFINITE);
    CHECK(memcmp(Ja, keep, sizeof Ja) == 0);
    CHECK_STATUS(sr_accel_jacobian(&m, x, NULL, NULL, Jb), SR_ERR_NULL);
    CHECK_STATUS(sr_accel_jacobian_batch(&m, 1, x, NULL, Ja, Jb, &failed), SR_ERR_NONFINITE);
    CHECK(failed == 0);
    CHECK_STATUS(sr_accel_jacobian_batch(&m, -1, x, NULL, Ja, Jb, &failed), SR_ERR_ARG);
}

/* The columns of F and G of one step of `method` against central differences of the C step through
 * sr_retract and sr_local (robot: the paper's, or the general one of sr_test.c). */
static void check_step_jacobian_against_differences(int method, int general, unsigned long long seed)
{
    const double h = TEST_EPS < 1e-10 ? 1e-4 : 3e-2, tol = TEST_EPS < 1e-10 ? 1e-6 : 3e-2;
    const sr_real dt = SR_C(0.05);
    sr_real p[SR_NPARAM], x[SR_NX], y[SR_NX], y0[SR_NX], ys[SR_NX], u[SR_NU] = {SR_C(0.05), SR_C(-0.02)}, up[SR_NU];
    sr_real d[SR_NE], F[SR_NE * SR_NE], G[SR_NE * SR_NU], ep[SR_NE], em[SR_NE];
    test_rng rng;
    sr_model m;
    double scale = 0;
    int k, i, s;
    rng.s = seed;
    if (general) general_robot_params(p); else paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 2.0, x);
    CHECK_STATUS(sr_step_jacobian(&m, method, x, u, dt, F, G), SR_OK);
    CHECK_STATUS(sr_step(&m, method, x, u, dt, y0), SR_OK);
    for (i = 0; i < SR_NE * SR_NE; ++i) scale = fabs((double)F[i]) > scale ? fabs((double)F[i]) : scale;
    for (k = 0; k < SR_NE + SR_NU; ++k) {
        for (s = -1; s <= 1; s += 2) {
            memset(d, 0, sizeof d);
            memcpy(up, u, sizeof up);
            if (k < SR_NE) d[k] = (sr_real)(s * h); else up[k - SR_NE] += (sr_real)(s * h);
            CHECK_STATUS(sr_retract(&m, x, d, y), SR_OK);
            CHECK_STATUS(sr_step(&m, method, y, up, dt, ys), SR_OK);
            CHECK_STATUS(sr_local(&m, y0, ys, s > 0 ? ep : em), SR_OK);
        }
        for (i = 0; i < SR_NE; ++i)
            CHECK_NEAR(k < SR_NE ? F[SR_NE * i + k] : G[SR_NU * i + k - SR_NE],
                       ((double)ep[i] - (double)em[i]) / (2 * h), tol * scale);
    }
}

static void test_lie_euler_step_jacobian_columns_are_central_differences_through_retract_and_local(void)
{
    check_step_jacobian_against_differences(SR_LIE_EULER, 0, 31);
}

static void test_rkmk4_and_cf4_step_jacobians_are_central_differences_through_retract_and_local(void)
{
    check_step_jacobian_against_differences(SR_RKMK4, 0, 33);
    check_step_jacobian_against_differences(SR_CF4, 0, 35);
}

static void test_step_jacobians_of_a_general_robot_are_central_differences(void)
{
    check_step_jacobian_against_differences(SR_LIE_EULER, 1, 43);
    check_step_jacobian_against_differences(SR_RKMK4, 1, 45);
    check_step_jacobian_against_differences(SR_CF4, 1, 47);
}

static void test_step_jacobian_refuses_an_unknown_method_and_batches_name_the_failing_row(void)
{
    sr_real p[SR_NPARAM], x[3][SR_NX], F[3][SR_NE * SR_NE], G[3][SR_NE * SR_NU], Fs[SR_NE * SR_NE], Gs[SR_NE * SR_NU];
    test_rng rng = {53};
    sr_model m;
    long failed = 7;
    int i;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    for (i = 0; i < 3; ++i) random_state(&rng, p[SR_P_r], 1.0, x[i]);
    CHECK_STATUS(sr_step_jacobian(&m, SR_RKMK4 | SR_PROJECT, x[0], NULL, SR_C(0.01), Fs, Gs), SR_ERR_ARG);
    CHECK_STATUS(sr_step_jacobian_batch(&m, 7, 3, x[0], NULL, SR_C(0.01), F[0], G[0], &failed), SR_ERR_ARG);
    CHECK_STATUS(sr_step_jacobian_batch(&m, SR_CF4, 3, x[0], NULL, SR_C(0.01), F[0], G[0], &failed), SR_OK);
    CHECK(failed == -1);
    for (i = 0; i < 3; ++i) {
        CHECK_STATUS(sr_step_jacobian_cf4(&m, x[i], NULL, SR_C(0.01), Fs, Gs), SR_OK);
        CHECK(memcmp(Fs, F[i], sizeof Fs) == 0 && memcmp(Gs, G[i], sizeof Gs) == 0);
    }
    x[2][SR_X_w_S] = (sr_real)NAN;
    CHECK_STATUS(sr_step_jacobian_batch(&m, SR_RKMK4, 3, x[0], NULL, SR_C(0.01), F[0], G[0], &failed), SR_ERR_NONFINITE);
    CHECK(failed == 2);
}

static void test_lie_euler_step_jacobian_bad_input_gives_status_and_leaves_outputs_untouched(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], F[SR_NE * SR_NE], G[SR_NE * SR_NU], keep[SR_NE * SR_NE];
    test_rng rng = {37};
    sr_model m;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 1.0, x);
    memset(F, 0x5a, sizeof F);
    memcpy(keep, F, sizeof F);
    CHECK_STATUS(sr_step_jacobian_lie_euler(&m, x, NULL, 0, F, G), SR_ERR_ARG);
    CHECK_STATUS(sr_step_jacobian_lie_euler(&m, x, NULL, SR_C(0.01), NULL, G), SR_ERR_NULL);
    x[SR_X_R_S] = 2;
    CHECK_STATUS(sr_step_jacobian_lie_euler(&m, x, NULL, SR_C(0.01), F, G), SR_ERR_NOT_ROTATION);
    CHECK(memcmp(F, keep, sizeof F) == 0);
}

static void test_lie_euler_step_jacobian_batch_equals_single_calls_and_names_the_failing_row(void)
{
    sr_real p[SR_NPARAM], x[3][SR_NX], F[3][SR_NE * SR_NE], G[3][SR_NE * SR_NU], Fs[SR_NE * SR_NE], Gs[SR_NE * SR_NU];
    test_rng rng = {41};
    sr_model m;
    long failed = 7;
    int i;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    for (i = 0; i < 3; ++i) random_state(&rng, p[SR_P_r], 1.0, x[i]);
    CHECK_STATUS(sr_step_jacobian_lie_euler_batch(&m, 3, x[0], NULL, SR_C(0.01), F[0], G[0], &failed), SR_OK);
    CHECK(failed == -1);
    for (i = 0; i < 3; ++i) {
        CHECK_STATUS(sr_step_jacobian_lie_euler(&m, x[i], NULL, SR_C(0.01), Fs, Gs), SR_OK);
        CHECK(memcmp(Fs, F[i], sizeof Fs) == 0 && memcmp(Gs, G[i], sizeof Gs) == 0);
    }
    x[1][SR_X_w_Y] = (sr_real)NAN;
    CHECK_STATUS(sr_step_jacobian_lie_euler_batch(&m, 3, x[0], NULL, SR_C(0.01), F[0], G[0], &failed), SR_ERR_NONFINITE);
    CHECK(failed == 1);
}

void suite_jacobians(void)
{
    RUN_TEST(test_accel_jacobian_columns_are_central_differences_along_retract);
    RUN_TEST(test_accel_jacobian_bad_input_leaves_outputs_untouched);
    RUN_TEST(test_internal_accel_jacobian_gives_the_accelerations_of_sr_accel);
    RUN_TEST(test_accel_jacobian_along_directions_is_ja_times_the_directions);
    RUN_TEST(test_lie_euler_step_jacobian_columns_are_central_differences_through_retract_and_local);
    RUN_TEST(test_rkmk4_and_cf4_step_jacobians_are_central_differences_through_retract_and_local);
    RUN_TEST(test_step_jacobians_of_a_general_robot_are_central_differences);
    RUN_TEST(test_step_jacobian_refuses_an_unknown_method_and_batches_name_the_failing_row);
    RUN_TEST(test_lie_euler_step_jacobian_bad_input_gives_status_and_leaves_outputs_untouched);
    RUN_TEST(test_lie_euler_step_jacobian_batch_equals_single_calls_and_names_the_failing_row);
}
