/*
 * test_step_batch.c -- sr_step_batch (c/src/sr_step_batch.c, c/src/sr_step_lanes.c): every method's step
 * vectorised across the states, every row not cleared by the lanes through sr_step.  Each row's
 * result is sr_step's bit for bit, whichever path it took (the lanes, or sr_step for a step angle
 * past the series' range), and every bad entry of every row is reported with sr_step's status, at
 * its row.
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

#define N 150 /* two full blocks of 64 and a short one */

static void random_rows(sr_real x[N][SR_NX], sr_real u[N][SR_NU], double r, double max_speed)
{
    test_rng rng = {23};
    int i;
    for (i = 0; i < N; ++i) {
        random_state(&rng, r, max_speed, x[i]);
        u[i][0] = (sr_real)rng_uniform(&rng, -0.5, 0.5);
        u[i][1] = (sr_real)rng_uniform(&rng, -0.5, 0.5);
    }
}

/* The rows of y equal sr_step's of the same rows, bit for bit. */
static int equal_to_single_steps(const sr_model *m, int method, sr_real x[N][SR_NX], sr_real u[N][SR_NU], int with_u,
                                 sr_real dt, sr_real y[N][SR_NX])
{
    sr_real one[SR_NX];
    int i;
    for (i = 0; i < N; ++i) {
        if (sr_step(m, method, x[i], with_u ? u[i] : NULL, dt, one) != SR_OK) return 0;
        if (memcmp(one, y[i], sizeof one) != 0) return 0;
    }
    return 1;
}

static void test_rows_equal_single_steps_bit_for_bit_for_every_method(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX];
    const int methods[] = {SR_LIE_EULER, SR_RKMK4, SR_CF4};
    sr_model m;
    long row = 99;
    int k;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    for (k = 0; k < 3; ++k) {
        CHECK_STATUS(sr_step_batch(&m, methods[k], N, x[0], u[0], (sr_real)0.01, y[0], &row), SR_OK);
        CHECK(row == -1 && equal_to_single_steps(&m, methods[k], x, u, 1, (sr_real)0.01, y));
        CHECK_STATUS(sr_step_batch(&m, methods[k], N, x[0], NULL, (sr_real)0.01, y[0], &row), SR_OK);
        CHECK(row == -1 && equal_to_single_steps(&m, methods[k], x, u, 0, (sr_real)0.01, y));
    }
}

/* Steps of up to 0.5 rad (speeds to 5 rad/s, dt = 0.1 s): the rows past the series' 1/4 rad go
 * through sr_step's closed forms, the others through the lanes; all equal sr_step's. */
static void test_rows_past_the_series_range_equal_single_steps(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX];
    sr_model m;
    int i, past = 0;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    for (i = 0; i < N; ++i) {
        const sr_real *w = x[i] + SR_X_w_S;
        const sr_real dt2 = (sr_real)0.01;   /* (0.1 s)^2 */
        past += dt2 * (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]) >= (sr_real)0.0625 || dt2 * w[3] * w[3] >= (sr_real)0.0625
             || dt2 * w[4] * w[4] >= (sr_real)0.0625;
    }
    CHECK(past > 0 && past < N);   /* both paths are taken */
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, N, x[0], u[0], (sr_real)0.1, y[0], NULL), SR_OK);
    CHECK(equal_to_single_steps(&m, SR_LIE_EULER, x, u, 1, (sr_real)0.1, y));
    /* the stages' dexp^-1 series ends at |th|^2 = 1e-2: dt = 0.04 s takes some rows past it */
    CHECK_STATUS(sr_step_batch(&m, SR_RKMK4, N, x[0], u[0], (sr_real)0.04, y[0], NULL), SR_OK);
    CHECK(equal_to_single_steps(&m, SR_RKMK4, x, u, 1, (sr_real)0.04, y));
    CHECK_STATUS(sr_step_batch(&m, SR_CF4, N, x[0], u[0], (sr_real)0.1, y[0], NULL), SR_OK);
    CHECK(equal_to_single_steps(&m, SR_CF4, x, u, 1, (sr_real)0.1, y));
}

/* The comparison above sees a one-ulp change of one entry of one row (it can fail). */
static void test_bit_for_bit_comparison_sees_one_ulp(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX];
    sr_model m;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, N, x[0], u[0], (sr_real)0.01, y[0], NULL), SR_OK);
    y[N - 1][SR_X_R_S + 4] = next_up(y[N - 1][SR_X_R_S + 4]);
    CHECK(!equal_to_single_steps(&m, SR_LIE_EULER, x, u, 1, (sr_real)0.01, y));
}

static void test_projected_methods_and_general_robots_equal_single_steps(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX];
    sr_real p[SR_NPARAM];
    sr_model m, g;
    paper_simulation_model(&m);
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&g, p), SR_OK);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    CHECK_STATUS(sr_step_batch(&m, SR_CF4 | SR_PROJECT, N, x[0], u[0], (sr_real)0.01, y[0], NULL), SR_OK);
    CHECK(equal_to_single_steps(&m, SR_CF4 | SR_PROJECT, x, u, 1, (sr_real)0.01, y));
    random_rows(x, u, g.p[SR_P_r], 5.0);
    CHECK_STATUS(sr_step_batch(&g, SR_LIE_EULER, N, x[0], u[0], (sr_real)0.01, y[0], NULL), SR_OK);
    CHECK(equal_to_single_steps(&g, SR_LIE_EULER, x, u, 1, (sr_real)0.01, y));
    CHECK_STATUS(sr_step_batch(&g, SR_RKMK4, N, x[0], u[0], (sr_real)0.01, y[0], NULL), SR_OK);
    CHECK(equal_to_single_steps(&g, SR_RKMK4, x, u, 1, (sr_real)0.01, y));
}

/* In place (x_next = x): every row is stepped from its own old state. */
static void test_in_place_equals_a_separate_output(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX];
    sr_model m;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    CHECK_STATUS(sr_step_batch(&m, SR_RKMK4, N, x[0], u[0], (sr_real)0.1, y[0], NULL), SR_OK);
    CHECK_STATUS(sr_step_batch(&m, SR_RKMK4, N, x[0], u[0], (sr_real)0.1, x[0], NULL), SR_OK);
    CHECK(memcmp(x, y, sizeof x) == 0);
}

/* A NaN or an infinity in any entry of x or u, in a row of the first, middle or last block, is
 * reported at that row with sr_step's status; the rows before it are written, the rows after not. */
static void test_every_non_finite_entry_is_reported_at_its_row(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX], want[N][SR_NX], one[SR_NX];
    const int rows[] = {0, 70, N - 1};
    const double bad[] = {NAN, INFINITY, -INFINITY};
    sr_model m;
    int r, k, b, missed = 0;
    long row;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, N, x[0], u[0], (sr_real)0.01, want[0], NULL), SR_OK);
    for (r = 0; r < 3; ++r)
        for (b = 0; b < 3; ++b)
            for (k = 0; k < SR_NX + SR_NU; ++k) {
                sr_real *entry = k < SR_NX ? &x[rows[r]][k] : &u[rows[r]][k - SR_NX];
                const sr_real keep = *entry;
                const int status = (*entry = (sr_real)bad[b],
                                    sr_step(&m, SR_LIE_EULER, x[rows[r]], u[rows[r]], (sr_real)0.01, one));
                memset(y, 0, sizeof y);
                if (status == SR_OK
                    || sr_step_batch(&m, SR_LIE_EULER, N, x[0], u[0], (sr_real)0.01, y[0], &row) != status
                    || row != rows[r] || memcmp(y, want, sizeof(sr_real) * SR_NX * rows[r]) != 0
                    || (rows[r] + 1 < N && y[rows[r] + 1][0] != 0)
                    || sr_step_batch(&m, SR_RKMK4, N, x[0], u[0], (sr_real)0.01, y[0], &row) != status
                    || row != rows[r]) {
                    ++missed;
                    printf("    entry %d of row %d = %g not reported\n", k, rows[r], bad[b]);
                }
                *entry = keep;
            }
    CHECK(missed == 0);
}

/* What the full state check refuses is refused at its row with sr_check_state's status. */
static void test_states_the_full_check_refuses_are_reported_at_their_row(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX];
    sr_model m;
    int c;
    long row;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    for (c = 0; c < 3; ++c) {
        sr_real *entry = c == 0 ? &x[100][SR_X_R_S + 0] : c == 1 ? &x[100][SR_X_R_Y + 1] : &x[100][SR_X_q + 2];
        const sr_real keep = *entry;
        *entry = c == 0 ? keep + 10 * SR_ROTATION_TOL : c == 1 ? next_up(keep) : keep * (1 + 10 * SR_ROTATION_TOL);
        CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, N, x[0], u[0], (sr_real)0.01, y[0], &row), sr_check_state(&m, x[100]));
        CHECK(row == 100);
        *entry = keep;
    }
}

/* The arguments are checked before any row, as in every batch call (sr_argcheck.h): a bad dt or
 * method is refused with failed_row -1, also when there are no rows. */
static void test_bad_arguments_are_refused_before_any_row(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], y[N][SR_NX];
    sr_model m;
    long row = 5;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r], 5.0);
    CHECK_STATUS(sr_step_batch(NULL, SR_LIE_EULER, 2, x[0], NULL, (sr_real)0.01, y[0], &row), SR_ERR_NULL);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, 2, NULL, NULL, (sr_real)0.01, y[0], &row), SR_ERR_NULL);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, 2, x[0], NULL, (sr_real)0.01, NULL, &row), SR_ERR_NULL);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, -1, x[0], NULL, (sr_real)0.01, y[0], &row), SR_ERR_ARG);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, 0, x[0], NULL, (sr_real)0.01, y[0], &row), SR_OK);
    CHECK(row == -1);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, 2, x[0], NULL, (sr_real)-0.01, y[0], &row), SR_ERR_ARG);
    CHECK(row == -1);
    CHECK_STATUS(sr_step_batch(&m, 99, 2, x[0], NULL, (sr_real)0.01, y[0], &row), SR_ERR_ARG);
    CHECK(row == -1);
    CHECK_STATUS(sr_step_batch(&m, 99, 0, NULL, NULL, (sr_real)0.01, NULL, &row), SR_ERR_ARG);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, 0, NULL, NULL, (sr_real)0.0, NULL, &row), SR_ERR_ARG);
}

void suite_step_batch(void)
{
    RUN_TEST(test_rows_equal_single_steps_bit_for_bit_for_every_method);
    RUN_TEST(test_rows_past_the_series_range_equal_single_steps);
    RUN_TEST(test_bit_for_bit_comparison_sees_one_ulp);
    RUN_TEST(test_projected_methods_and_general_robots_equal_single_steps);
    RUN_TEST(test_in_place_equals_a_separate_output);
    RUN_TEST(test_every_non_finite_entry_is_reported_at_its_row);
    RUN_TEST(test_states_the_full_check_refuses_are_reported_at_their_row);
    RUN_TEST(test_bad_arguments_are_refused_before_any_row);
}
