/*
 * test_group.c -- sr_retract and sr_local (c/src/sr_group.c): inverse of each other for every angle,
 * the shell's Log accurate near pi, status codes and untouched outputs on error.
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

#define PI 3.14159265358979323846

static void random_error(test_rng *rng, double max_angle, sr_real d[SR_NE])
{
    double axis[3], norm = 0, angle;
    int i;
    for (i = 0; i < SR_NE; ++i) d[i] = (sr_real)rng_uniform(rng, -1, 1);
    for (i = 0; i < 3; ++i) {
        axis[i] = rng_uniform(rng, -1, 1);
        norm += axis[i] * axis[i];
    }
    norm = sqrt(norm);
    angle = rng_uniform(rng, 0, max_angle);
    for (i = 0; i < 3; ++i) d[SR_E_xi_S + i] = (sr_real)(angle * axis[i] / norm);
    d[SR_E_th_Y] = (sr_real)rng_uniform(rng, -max_angle, max_angle);
    d[SR_E_th_P] = (sr_real)rng_uniform(rng, -max_angle, max_angle);
}

static void test_local_inverts_retract_for_angles_up_to_pi(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], y[SR_NX], d[SR_NE], back[SR_NE];
    test_rng rng = {19};
    sr_model m;
    int k, i;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    for (k = 0; k < 100; ++k) {
        random_state(&rng, p[SR_P_r], 5.0, x);
        random_error(&rng, 0.999 * PI, d);
        CHECK_STATUS(sr_retract(&m, x, d, y), SR_OK);
        CHECK_STATUS(sr_check_state(&m, y), SR_OK);
        CHECK_STATUS(sr_local(&m, x, y, back), SR_OK);
        /* Near pi the angle's rounding is amplified by 1/sin: 1e4 eps covers 0.999 pi. */
        for (i = 0; i < SR_NE; ++i) CHECK_NEAR(back[i], d[i], 1e4 * TEST_EPS * (1 + fabs((double)d[i])));
    }
}

static void test_local_is_accurate_at_pi_minus_a_rounding_gap(void)
{
    /* R_S rotated by pi - gap about a diagonal axis: the Log's axis from the symmetric part.  The
     * gap is above the rounding of pi (else the axis's sign is undetermined): 1e-9 in double, 1e-3 in float. */
    sr_real p[SR_NPARAM], x[SR_NX], y[SR_NX], d[SR_NE] = {0}, back[SR_NE];
    test_rng rng = {3};
    sr_model m;
    const double angle = PI - (TEST_EPS < 1e-10 ? 1e-9 : 1e-3), n[3] = {0.48, 0.6, 0.64};
    int i;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 1.0, x);
    for (i = 0; i < 3; ++i) d[SR_E_xi_S + i] = (sr_real)(angle * n[i]);
    CHECK_STATUS(sr_retract(&m, x, d, y), SR_OK);
    CHECK_STATUS(sr_local(&m, x, y, back), SR_OK);
    for (i = 0; i < 3; ++i) CHECK_NEAR(back[SR_E_xi_S + i], d[SR_E_xi_S + i], 64 * TEST_EPS);
}

static void test_retract_may_write_over_its_input(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], y[SR_NX], d[SR_NE];
    test_rng rng = {5};
    sr_model m;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 1.0, x);
    random_error(&rng, 3.0, d);
    CHECK_STATUS(sr_retract(&m, x, d, y), SR_OK);
    CHECK_STATUS(sr_retract(&m, x, d, x), SR_OK);
    CHECK(memcmp(x, y, sizeof x) == 0);
}

static void test_bad_input_gives_status_and_leaves_output_untouched(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], bad[SR_NX], y[SR_NX], d[SR_NE] = {0}, out[SR_NE], keep[SR_NE];
    test_rng rng = {11};
    sr_model m;
    long failed = 7;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 1.0, x);
    memcpy(bad, x, sizeof x);
    bad[SR_X_R_S] += (sr_real)0.1;
    memset(out, 0x5a, sizeof out);
    memcpy(keep, out, sizeof out);
    CHECK_STATUS(sr_local(&m, x, bad, out), SR_ERR_NOT_ROTATION);
    CHECK_STATUS(sr_local(&m, bad, x, out), SR_ERR_NOT_ROTATION);
    CHECK(memcmp(out, keep, sizeof out) == 0);
    CHECK_STATUS(sr_local(&m, x, NULL, out), SR_ERR_NULL);
    d[SR_E_q] = (sr_real)NAN;
    CHECK_STATUS(sr_retract(&m, x, d, y), SR_ERR_NONFINITE);
    CHECK_STATUS(sr_retract(NULL, x, d, y), SR_ERR_NULL);
    CHECK_STATUS(sr_retract_batch(&m, 1, x, d, y, &failed), SR_ERR_NONFINITE);
    CHECK(failed == 0);
    CHECK_STATUS(sr_local_batch(&m, -1, x, x, out, &failed), SR_ERR_ARG);
}

void suite_group(void)
{
    RUN_TEST(test_local_inverts_retract_for_angles_up_to_pi);
    RUN_TEST(test_local_is_accurate_at_pi_minus_a_rounding_gap);
    RUN_TEST(test_retract_may_write_over_its_input);
    RUN_TEST(test_bad_input_gives_status_and_leaves_output_untouched);
}
