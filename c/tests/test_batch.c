/*
 * test_batch.c -- sr_simulate_batch (c/src/sr_batch.c): each sample is the chunked guarded run a
 * caller would make alone, bit for bit; a failing sample fails alone and leaves its rows
 * untouched; malformed arguments are refused before any sample runs.
 */
#include "sr_test.h"

#include <string.h>

#define NS 3
#define STEPS 50
#define CHUNK 16 /* STEPS is not a multiple: the last chunk is shorter */

static void three_samples(sr_real p[NS][SR_NPARAM], sr_real x0[NS][SR_NX], sr_real u[NS][STEPS][SR_NU])
{
    test_rng rng = {7};
    int i, k;
    for (i = 0; i < NS; ++i) {
        paper_simulation_params(p[i]);
        p[i][SR_P_m_P] *= (sr_real)rng_uniform(&rng, 0.8, 1.2);
        random_state(&rng, p[i][SR_P_r], 1.0, x0[i]);
        for (k = 0; k < STEPS; ++k) {
            u[i][k][0] = (sr_real)rng_uniform(&rng, -0.1, 0.1);
            u[i][k][1] = (sr_real)rng_uniform(&rng, -0.1, 0.1);
        }
    }
}

/* The run sample i stands for: sr_simulate_guarded in chunks of CHUNK steps, one guard. */
static int alone(int method, const sr_real p[SR_NPARAM], const sr_real x0[SR_NX],
                 sr_real u[STEPS][SR_NU], sr_real traj[STEPS + 1][SR_NX])
{
    sr_model m;
    sr_energy_guard guard = {SR_C(0.5), 0, 0, 0, 0};
    long done = 0, n, k;
    int status = sr_model_init(&m, p);
    if (status != SR_OK) return status;
    memcpy(traj[0], x0, sizeof traj[0]);
    for (k = 0; k < STEPS; k += n) {
        n = STEPS - k < CHUNK ? STEPS - k : CHUNK;
        status = sr_simulate_guarded(&m, method, traj[k], SR_C(0.01), n, u[k], &guard, traj[k], &done);
        if (status != SR_OK) return status;
    }
    return SR_OK;
}

static void test_batch_samples_equal_their_chunked_runs_alone(void)
{
    static sr_real p[NS][SR_NPARAM], x0[NS][SR_NX], u[NS][STEPS][SR_NU];
    static sr_real traj[NS][STEPS + 1][SR_NX], one[STEPS + 1][SR_NX], work[CHUNK + 1][SR_NX];
    static sr_real final[NS][SR_NX], metrics[NS][SR_BATCH_NMETRICS];
    const int methods[] = {SR_LIE_EULER, SR_RKMK4, SR_CF4 | SR_PROJECT};
    int status[NS], i, j;
    long done[NS];
    three_samples(p, x0, u);
    for (j = 0; j < 3; ++j) {
        CHECK_STATUS(sr_simulate_batch(methods[j], NS, p[0], SR_NPARAM, x0[0], SR_NX, SR_C(0.01), STEPS,
                                       u[0][0], STEPS * SR_NU, SR_C(0.5), CHUNK, NULL, traj[0][0],
                                       NULL, NULL, status, done), SR_OK);
        CHECK_STATUS(sr_simulate_batch(methods[j], NS, p[0], SR_NPARAM, x0[0], SR_NX, SR_C(0.01), STEPS,
                                       u[0][0], STEPS * SR_NU, SR_C(0.5), CHUNK, work[0], NULL,
                                       final[0], metrics[0], status, done), SR_OK);
        for (i = 0; i < NS; ++i) {
            CHECK_STATUS(status[i], SR_OK);
            CHECK(done[i] == STEPS);
            CHECK_STATUS(alone(methods[j], p[i], x0[i], u[i], one), SR_OK);
            CHECK(memcmp(traj[i], one, sizeof one) == 0);
            CHECK(memcmp(final[i], one[STEPS], sizeof final[i]) == 0);
            CHECK(metrics[i][SR_BATCH_PATH_LENGTH] >= metrics[i][SR_BATCH_MAX_DISTANCE]);
        }
    }
}

static void test_batch_failing_sample_fails_alone_and_leaves_its_rows_untouched(void)
{
    static sr_real p[NS][SR_NPARAM], x0[NS][SR_NX], u[NS][STEPS][SR_NU], work[CHUNK + 1][SR_NX];
    static sr_real final[NS][SR_NX], metrics[NS][SR_BATCH_NMETRICS], one[STEPS + 1][SR_NX];
    int status[NS];
    long done[NS];
    three_samples(p, x0, u);
    p[1][SR_P_m_P] = -1;
    memset(final, 0x5A, sizeof final);
    memset(metrics, 0x5A, sizeof metrics);
    CHECK_STATUS(sr_simulate_batch(SR_RKMK4, NS, p[0], SR_NPARAM, x0[0], SR_NX, SR_C(0.01), STEPS, u[0][0],
                                   STEPS * SR_NU, SR_C(0.5), CHUNK, work[0], NULL, final[0], metrics[0],
                                   status, done), SR_OK);
    CHECK_STATUS(status[0], SR_OK);
    CHECK_STATUS(status[1], SR_ERR_PARAM);
    CHECK_STATUS(status[2], SR_OK);
    CHECK(done[1] == 0);
    CHECK(((unsigned char *)final[1])[0] == 0x5A && ((unsigned char *)metrics[1])[0] == 0x5A);
    CHECK_STATUS(alone(SR_RKMK4, p[2], x0[2], u[2], one), SR_OK);
    CHECK(memcmp(final[2], one[STEPS], sizeof final[2]) == 0);
}

static void test_batch_refuses_malformed_arguments_before_any_sample(void)
{
    static sr_real p[NS][SR_NPARAM], x0[NS][SR_NX], u[NS][STEPS][SR_NU], work[CHUNK + 1][SR_NX];
    int status[NS] = {-1, -1, -1};
    long done[NS];
    three_samples(p, x0, u);
    CHECK_STATUS(sr_simulate_batch(SR_LIE_EULER, NS, p[0], 0, x0[0], 0, SR_C(0.01), STEPS, NULL, 0, SR_C(0.5),
                                   0, work[0], NULL, NULL, NULL, status, done), SR_ERR_ARG);
    CHECK_STATUS(sr_simulate_batch(7, NS, p[0], 0, x0[0], 0, SR_C(0.01), STEPS, NULL, 0, SR_C(0.5), CHUNK,
                                   work[0], NULL, NULL, NULL, status, done), SR_ERR_ARG);
    CHECK_STATUS(sr_simulate_batch(SR_LIE_EULER, NS, p[0], 0, x0[0], 0, SR_C(-0.01), STEPS, NULL, 0, SR_C(0.5),
                                   CHUNK, work[0], NULL, NULL, NULL, status, done), SR_ERR_ARG);
    CHECK_STATUS(sr_simulate_batch(SR_LIE_EULER, NS, p[0], 0, x0[0], 0, SR_C(0.01), STEPS, NULL, 0, SR_C(0.5),
                                   CHUNK, NULL, NULL, NULL, NULL, status, done), SR_ERR_NULL);
    CHECK(status[0] == -1 && status[1] == -1 && status[2] == -1);
}

void suite_batch(void)
{
    RUN_TEST(test_batch_samples_equal_their_chunked_runs_alone);
    RUN_TEST(test_batch_failing_sample_fails_alone_and_leaves_its_rows_untouched);
    RUN_TEST(test_batch_refuses_malformed_arguments_before_any_sample);
}
