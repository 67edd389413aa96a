/*
 * test_accel_batch.c -- sr_accel_batch and sr_checked_accel_batch (c/src/sr_kernels.c), which run
 * the vectorised lanes form of the checks and the kernel (sr_internal_check_lanes,
 * sr_gen_accel_lanes) and hand every row that form does not clear to the scalar functions: each
 * row's result is sr_accel's bit for bit, and every bad entry of every row is reported with the
 * scalar functions' status, at its row.
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

#define N 150 /* two full blocks of 64 and a short one */

static void random_rows(sr_real x[N][SR_NX], sr_real u[N][SR_NU], double r)
{
    test_rng rng = {11};
    int i;
    for (i = 0; i < N; ++i) {
        random_state(&rng, r, 5.0, x[i]);
        u[i][0] = (sr_real)rng_uniform(&rng, -0.5, 0.5);
        u[i][1] = (sr_real)rng_uniform(&rng, -0.5, 0.5);
    }
}

/* The rows of a equal sr_accel's of the same rows, bit for bit. */
static int equal_to_single_calls(const sr_model *m, sr_real x[N][SR_NX], sr_real u[N][SR_NU], int with_u,
                                 sr_real a[N][SR_NV])
{
    sr_real one[SR_NV];
    int i;
    for (i = 0; i < N; ++i) {
        if (sr_accel(m, x[i], with_u ? u[i] : NULL, one) != SR_OK) return 0;
        if (memcmp(one, a[i], sizeof one) != 0) return 0;
    }
    return 1;
}

static void test_batch_rows_equal_single_calls_bit_for_bit(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], a[N][SR_NV], b[N][SR_NV];
    sr_model m;
    long row = 99;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r]);
    CHECK_STATUS(sr_accel_batch(&m, N, x[0], u[0], a[0], &row), SR_OK);
    CHECK(row == -1 && equal_to_single_calls(&m, x, u, 1, a));
    CHECK_STATUS(sr_checked_accel_batch(&m, N, x[0], u[0], b[0], &row), SR_OK);
    CHECK(row == -1 && memcmp(a, b, sizeof a) == 0);
    CHECK_STATUS(sr_checked_accel_batch(&m, N, x[0], NULL, b[0], &row), SR_OK); /* u = NULL: zero torque */
    CHECK(row == -1 && equal_to_single_calls(&m, x, u, 0, b));
}

/* The comparison above sees a one-ulp change of one entry of one row (it can fail). */
static void test_bit_for_bit_comparison_sees_one_ulp(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], a[N][SR_NV];
    sr_model m;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r]);
    CHECK_STATUS(sr_accel_batch(&m, N, x[0], u[0], a[0], NULL), SR_OK);
    a[N - 1][SR_NV - 1] = next_up(a[N - 1][SR_NV - 1]);
    CHECK(!equal_to_single_calls(&m, x, u, 1, a));
}

static void test_general_robot_rows_equal_single_calls(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], a[N][SR_NV];
    sr_real p[SR_NPARAM];
    sr_model m;
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_rows(x, u, m.p[SR_P_r]);
    CHECK_STATUS(sr_checked_accel_batch(&m, N, x[0], u[0], a[0], NULL), SR_OK);
    CHECK(equal_to_single_calls(&m, x, u, 1, a));
}

/* A NaN or an infinity in any entry of x or u, in a row of the first, middle or last block, is
 * reported at that row with sr_accel's status, and the rows before it are written. */
static void test_every_non_finite_entry_is_reported_at_its_row(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], a[N][SR_NV], want[N][SR_NV];
    const int rows[] = {0, 70, N - 1};
    const double bad[] = {NAN, INFINITY, -INFINITY};
    sr_model m;
    int r, k, b, missed = 0;
    long row;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r]);
    CHECK_STATUS(sr_accel_batch(&m, N, x[0], u[0], want[0], NULL), SR_OK);
    for (r = 0; r < 3; ++r)
        for (b = 0; b < 3; ++b)
            for (k = 0; k < SR_NX + SR_NU; ++k) {
                sr_real *entry = k < SR_NX ? &x[rows[r]][k] : &u[rows[r]][k - SR_NX];
                const sr_real keep = *entry;
                *entry = (sr_real)bad[b];
                memset(a, 0, sizeof a);
                if (sr_accel_batch(&m, N, x[0], u[0], a[0], &row) != SR_ERR_NONFINITE || row != rows[r]
                    || sr_checked_accel_batch(&m, N, x[0], u[0], a[0], &row) != SR_ERR_NONFINITE || row != rows[r]
                    || memcmp(a, want, sizeof(sr_real) * SR_NV * rows[r]) != 0) {
                    ++missed;
                    printf("    entry %d of row %d = %g not reported\n", k, rows[r], bad[b]);
                }
                *entry = keep;
            }
    CHECK(missed == 0);
}

/* A state the full check refuses (R_S not orthogonal by 10 SR_ROTATION_TOL, R_Y's axis entry off
 * by one ulp, q_z off by 10 SR_ROTATION_TOL r) passes sr_accel_batch's cheap checks where sr_accel does, and is reported by
 * sr_checked_accel_batch with sr_check_state's status. */
static void test_checked_batch_reports_what_sr_check_state_refuses(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], a[N][SR_NV], one[SR_NV];
    sr_model m;
    int c;
    long row;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r]);
    for (c = 0; c < 3; ++c) {
        sr_real *entry = c == 0 ? &x[100][SR_X_R_S + 0] : c == 1 ? &x[100][SR_X_R_Y + 1] : &x[100][SR_X_q + 2];
        const sr_real keep = *entry;
        *entry = c == 0 ? keep + 10 * SR_ROTATION_TOL : c == 1 ? next_up(keep) : keep * (1 + 10 * SR_ROTATION_TOL);
        CHECK_STATUS(sr_checked_accel_batch(&m, N, x[0], u[0], a[0], &row), sr_check_state(&m, x[100]));
        CHECK(row == 100);
        CHECK_STATUS(sr_accel_batch(&m, N, x[0], u[0], a[0], &row), sr_accel(&m, x[100], u[100], one));
        *entry = keep;
    }
}

/* A row whose accelerations overflow (a finite torque of 1e308 N m, 3e38 in float) is reported at its row. */
static void test_batch_reports_a_failing_kernel_at_its_row(void)
{
    static sr_real x[N][SR_NX], u[N][SR_NU], a[N][SR_NV];
    sr_model m;
    long row;
    paper_simulation_model(&m);
    random_rows(x, u, m.p[SR_P_r]);
    u[90][0] = (sr_real)(TEST_EPS > 1e-10 ? 3e38 : 1e308);
    CHECK_STATUS(sr_checked_accel_batch(&m, N, x[0], u[0], a[0], &row), SR_ERR_NONFINITE);
    CHECK(row == 90);
}

static void test_batch_refuses_null_and_negative_sizes(void)
{
    static sr_real x[2][SR_NX], a[2][SR_NV];
    sr_model m;
    long row = 5;
    paper_simulation_model(&m);
    CHECK_STATUS(sr_checked_accel_batch(NULL, 2, x[0], NULL, a[0], &row), SR_ERR_NULL);
    CHECK_STATUS(sr_checked_accel_batch(&m, 2, NULL, NULL, a[0], &row), SR_ERR_NULL);
    CHECK_STATUS(sr_checked_accel_batch(&m, 2, x[0], NULL, NULL, &row), SR_ERR_NULL);
    CHECK_STATUS(sr_checked_accel_batch(&m, -1, x[0], NULL, a[0], &row), SR_ERR_ARG);
    CHECK_STATUS(sr_checked_accel_batch(&m, 0, x[0], NULL, a[0], &row), SR_OK);
    CHECK(row == -1);
}

void suite_accel_batch(void)
{
    RUN_TEST(test_batch_rows_equal_single_calls_bit_for_bit);
    RUN_TEST(test_bit_for_bit_comparison_sees_one_ulp);
    RUN_TEST(test_general_robot_rows_equal_single_calls);
    RUN_TEST(test_every_non_finite_entry_is_reported_at_its_row);
    RUN_TEST(test_checked_batch_reports_what_sr_check_state_refuses);
    RUN_TEST(test_batch_reports_a_failing_kernel_at_its_row);
    RUN_TEST(test_batch_refuses_null_and_negative_sizes);
}
