/*
 * test_buffers.c -- every output buffer is written exactly within its
 * documented size.  Each output lives in the middle of a larger array whose
 * guard zones before and after it hold a canary byte pattern: on success the
 * guards must be intact and every output entry written; on error (where the
 * header promises it) the output must be untouched.  The sanitizer build
 * (make sanitize) checks the same from the other side: no read or write
 * outside the caller's arrays.
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

#define GUARD 8                      /* sr_reals of canary before and after an output */
#define CANARY_BYTE 0xA5
#define MAX_OUT (5 * SR_NX)          /* the largest output tested (a 4-step trajectory) */

/* An output region of n reals with guard zones, all filled with the canary. */
typedef struct guarded {
    sr_real buf[GUARD + MAX_OUT + GUARD];
    int n;
} guarded;

static sr_real *guarded_init(guarded *g, int n)
{
    memset(g->buf, CANARY_BYTE, sizeof g->buf);
    g->n = n;
    return g->buf + GUARD;
}

static int is_canary(const sr_real *v)
{
    const unsigned char *b = (const unsigned char *)v;
    size_t i;
    for (i = 0; i < sizeof *v; ++i)
        if (b[i] != CANARY_BYTE) return 0;
    return 1;
}

/* Guards intact; the first `written` outputs overwritten and the rest untouched. */
static int guarded_ok(const guarded *g, int written)
{
    int i;
    for (i = 0; i < GUARD; ++i)
        if (!is_canary(g->buf + i) || !is_canary(g->buf + GUARD + g->n + i)) return 0;
    for (i = 0; i < g->n; ++i)
        if (is_canary(g->buf + GUARD + i) != (i >= written)) return 0;
    return 1;
}

static void moving_state(sr_real x[SR_NX])
{
    make_state(x, 0.4, -0.7, 0.3);
    x[SR_X_w_S] = SR_C(0.3);
    x[SR_X_w_S + 2] = SR_C(-0.2);
    x[SR_X_w_P] = SR_C(1.0);
}

static void test_kernels_write_exactly_their_outputs(void)
{
    sr_model m;
    sr_real x[SR_NX];
    const sr_real u[SR_NU] = {SR_C(0.1), SR_C(0.2)};
    guarded g;
    paper_simulation_model(&m);
    moving_state(x);

    CHECK_STATUS(sr_accel(&m, x, u, guarded_init(&g, SR_NV)), SR_OK);
    CHECK(guarded_ok(&g, SR_NV));
    CHECK_STATUS(sr_rhs(&m, x, u, guarded_init(&g, SR_NV)), SR_OK);
    CHECK(guarded_ok(&g, SR_NV));
    CHECK_STATUS(sr_inertia(&m, x, guarded_init(&g, SR_NV * SR_NV)), SR_OK);
    CHECK(guarded_ok(&g, SR_NV * SR_NV));
    CHECK_STATUS(sr_energy(&m, x, guarded_init(&g, 1)), SR_OK);
    CHECK(guarded_ok(&g, 1));
    CHECK_STATUS(sr_equilibrium_residual(&m, x, guarded_init(&g, SR_NV)), SR_OK);
    CHECK(guarded_ok(&g, SR_NV));
    CHECK_STATUS(sr_so3_exp(x + SR_X_w_S, guarded_init(&g, 9)), SR_OK);
    CHECK(guarded_ok(&g, 9));
    CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u, SR_C(0.01), guarded_init(&g, SR_NX)), SR_OK);
    CHECK(guarded_ok(&g, SR_NX));
}

static void test_kernels_leave_outputs_untouched_on_error(void)
{
    sr_model m;
    sr_real x[SR_NX];
    guarded g;
    paper_simulation_model(&m);
    moving_state(x);
    x[SR_X_w_S + 1] = (sr_real)NAN;

    CHECK_STATUS(sr_accel(&m, x, NULL, guarded_init(&g, SR_NV)), SR_ERR_NONFINITE);
    CHECK(guarded_ok(&g, 0));
    CHECK_STATUS(sr_rhs(&m, x, NULL, guarded_init(&g, SR_NV)), SR_ERR_NONFINITE);
    CHECK(guarded_ok(&g, 0));
    CHECK_STATUS(sr_inertia(&m, x, guarded_init(&g, SR_NV * SR_NV)), SR_ERR_NONFINITE);
    CHECK(guarded_ok(&g, 0));
    CHECK_STATUS(sr_energy(&m, x, guarded_init(&g, 1)), SR_ERR_NONFINITE);
    CHECK(guarded_ok(&g, 0));
    CHECK_STATUS(sr_equilibrium_residual(&m, x, guarded_init(&g, SR_NV)), SR_ERR_NONFINITE);
    CHECK(guarded_ok(&g, 0));
    CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, NULL, SR_C(0.01), guarded_init(&g, SR_NX)), SR_ERR_NONFINITE);
    CHECK(guarded_ok(&g, 0));
}

static void test_model_init_writes_only_the_model(void)
{
    struct {
        sr_real before[GUARD];
        sr_model model;
        sr_real after[GUARD];
    } s;
    sr_real p[SR_NPARAM];
    int i;
    paper_simulation_params(p);
    memset(&s, CANARY_BYTE, sizeof s);
    p[SR_P_m_S] = -1; /* invalid: the model must stay untouched */
    CHECK_STATUS(sr_model_init(&s.model, p), SR_ERR_PARAM);
    for (i = 0; i < SR_NPARAM; ++i) CHECK(is_canary(s.model.p + i));
    for (i = 0; i < SR_GEN_NCONST; ++i) CHECK(is_canary(s.model.c + i));
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&s.model, p), SR_OK);
    for (i = 0; i < GUARD; ++i) CHECK(is_canary(s.before + i) && is_canary(s.after + i));
    for (i = 0; i < SR_NPARAM; ++i) CHECK(s.model.p[i] == p[i]);
}

static void test_simulate_writes_steps_plus_one_rows(void)
{
    enum { STEPS = 4 };
    sr_model m;
    sr_real x[SR_NX], u[STEPS * SR_NU];
    guarded g;
    long done = -1;
    int i;
    paper_simulation_model(&m);
    moving_state(x);
    for (i = 0; i < STEPS * SR_NU; ++i) u[i] = SR_C(0.1);
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), STEPS, u, guarded_init(&g, (STEPS + 1) * SR_NX), &done),
                 SR_OK);
    CHECK(done == STEPS && guarded_ok(&g, (STEPS + 1) * SR_NX));

    /* A bad torque at step 3: rows 0..2 written, the rest untouched. */
    u[2 * SR_NU] = (sr_real)INFINITY;
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), STEPS, u, guarded_init(&g, (STEPS + 1) * SR_NX), &done),
                 SR_ERR_NONFINITE);
    CHECK(done == 2 && guarded_ok(&g, 3 * SR_NX));
}

static void test_accel_batch_writes_only_the_rows_it_computed(void)
{
    enum { N = 4 };
    sr_model m;
    sr_real x[N * SR_NX];
    guarded g;
    long row = 99;
    int i;
    paper_simulation_model(&m);
    for (i = 0; i < N; ++i) moving_state(x + i * SR_NX);
    CHECK_STATUS(sr_accel_batch(&m, N, x, NULL, guarded_init(&g, N * SR_NV), &row), SR_OK);
    CHECK(row == -1 && guarded_ok(&g, N * SR_NV));
    x[2 * SR_NX] = (sr_real)NAN; /* row 2 fails: rows 0 and 1 written */
    CHECK_STATUS(sr_accel_batch(&m, N, x, NULL, guarded_init(&g, N * SR_NV), &row), SR_ERR_NONFINITE);
    CHECK(row == 2 && guarded_ok(&g, 2 * SR_NV));
}

void suite_buffers(void)
{
    RUN_TEST(test_kernels_write_exactly_their_outputs);
    RUN_TEST(test_kernels_leave_outputs_untouched_on_error);
    RUN_TEST(test_model_init_writes_only_the_model);
    RUN_TEST(test_simulate_writes_steps_plus_one_rows);
    RUN_TEST(test_accel_batch_writes_only_the_rows_it_computed);
}
