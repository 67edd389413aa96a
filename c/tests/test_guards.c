/*
 * test_guards.c -- the C API's guards: sr_model_init rejects parameters
 * that overflow or make M singular; kernel results are finite whenever SR_OK; the
 * batch state check names its failing row; sr_simulate / sr_simulate_guarded stop
 * when the state drifts off the constraints or gains energy without input power.
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

#ifdef SR_USE_FLOAT
#define HUGE_LENGTH SR_C(1e30)  /* its square overflows in float */
#define TINY_LENGTH SR_C(1e-30) /* its square underflows in float */
#else
#define HUGE_LENGTH SR_C(1e200)
#define TINY_LENGTH SR_C(1e-200)
#endif

/* The paper's robot with every length scaled by s (r, b, h, l), as the general parameters; the
 * conversion itself may overflow (SR_ERR_PARAM) or underflow (inertias 0: SR_ERR_PARAM later). */
static int scale_lengths(sr_real p[SR_NPARAM], sr_real s)
{
    sr_real pp[SR_NPAPER];
    paper_simulation_paper(pp);
    pp[SR_PAPER_r] *= s;
    pp[SR_PAPER_b] *= s;
    pp[SR_PAPER_h] *= s;
    pp[SR_PAPER_l] *= s;
    return sr_paper_params(pp, p);
}

static void test_model_init_rejects_lengths_whose_inertias_underflow(void)
{
    sr_model m;
    sr_real p[SR_NPARAM];
    CHECK_STATUS(scale_lengths(p, TINY_LENGTH), SR_OK);
    memset(&m, 0x5A, sizeof m);
    CHECK(p[SR_P_j_S] == 0); /* 2/3 m_S r^2 underflowed */
    CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
    CHECK(((unsigned char *)&m)[0] == 0x5A); /* untouched */
}

static void test_model_init_rejects_lengths_whose_inertias_overflow(void)
{
    sr_model m;
    sr_real p[SR_NPARAM];
    paper_simulation_params(p);
    CHECK_STATUS(scale_lengths(p, HUGE_LENGTH), SR_ERR_PARAM); /* the conversion's squares overflow */
    p[SR_P_r] = HUGE_LENGTH; /* and the general robot's own check: r^2 m_R overflows in M */
    p[SR_P_j_S] = HUGE_LENGTH;
    CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
}

static void test_kernel_results_that_overflow_are_reported_not_returned(void)
{
    sr_model m;
    sr_real x[SR_NX], a[SR_NV] = {7, 7, 7, 7, 7}, next[SR_NX], E = 7;
    int i;
    paper_simulation_model(&m);
    make_state(x, 0.3, 0.2, 0.3);
    for (i = SR_X_w_S; i < SR_NX; ++i) x[i] = (sr_real)(0.3 * FLT_MAX * (i % 2 ? 1 : -1)); /* finite speeds */
#ifndef SR_USE_FLOAT
    for (i = SR_X_w_S; i < SR_NX; ++i) x[i] = (sr_real)(1e200 * (i % 2 ? 1 : -1));
#endif
    CHECK_STATUS(sr_accel(&m, x, NULL, a), SR_ERR_NONFINITE);
    CHECK(a[0] == 7 && a[4] == 7);
    CHECK_STATUS(sr_energy(&m, x, &E), SR_ERR_NONFINITE);
    CHECK(E == 7);
    CHECK_STATUS(sr_step(&m, SR_RKMK4, x, NULL, SR_C(0.01), next), SR_ERR_NONFINITE);
}

static void test_check_state_batch_names_the_first_failing_row(void)
{
    sr_model m;
    sr_real x[3 * SR_NX];
    long row = 99;
    int i;
    paper_simulation_model(&m);
    for (i = 0; i < 3; ++i) make_state(x + i * SR_NX, 0.1 * i, -0.2 * i, 0.3);
    CHECK_STATUS(sr_check_state_batch(&m, 3, x, &row), SR_OK);
    CHECK(row == -1);
    x[2 * SR_NX + 29] = SR_C(0.31); /* q_z of row 2 */
    x[1 * SR_NX + 10] = SR_C(0.01); /* R_Y[0,1] of row 1: not a rotation about x */
    CHECK_STATUS(sr_check_state_batch(&m, 3, x, &row), SR_ERR_NOT_ROTATION);
    CHECK(row == 1);
    CHECK_STATUS(sr_check_state_batch(&m, -1, x, &row), SR_ERR_ARG);
    CHECK_STATUS(sr_check_state_batch(NULL, 3, x, &row), SR_ERR_NULL);
}

/* R_S = I + S/2 with S = d (1 1^T - I): R^T R - I = S + S^2/4, largest entry ~d and det ~1, so
 * it passes the check for d < tol; rotating it (R_S Exp(...)) turns S into E^T S E, whose
 * entries reach 2d along the (1,1,1) direction: the defect that was in tolerance drifts out. */
static void nearly_orthonormal_spinning_state(sr_real x[SR_NX], double d)
{
    int i, j;
    make_state(x, 0.3, 0.2, 0.3);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) x[3 * i + j] = (sr_real)((i == j ? 1.0 : 0.5 * d));
    x[SR_X_w_S] = SR_C(3.0);
    x[SR_X_w_S + 1] = SR_C(-2.0);
    x[SR_X_w_S + 2] = SR_C(5.0);
}

static void test_simulate_stops_when_a_rotation_drifts_out_of_tolerance(void)
{
    enum { STEPS = 2000 };
    static sr_real traj[(STEPS + 1) * SR_NX];
    sr_model m;
    sr_real x[SR_NX];
    long done = -1;
    paper_simulation_model(&m);
    nearly_orthonormal_spinning_state(x, 0.9 * (double)SR_ROTATION_TOL);
    CHECK_STATUS(sr_check_state(&m, x), SR_OK);
    CHECK_STATUS(sr_simulate(&m, SR_RKMK4, x, SR_C(0.01), STEPS, NULL, traj, &done), SR_ERR_NOT_ROTATION);
    /* caught at a check row: the state after step done + 1, a multiple of SR_GUARD_INTERVAL */
    CHECK(done >= 0 && done < STEPS && (done + 1) % SR_GUARD_INTERVAL == 0);
    CHECK(sr_check_state(&m, traj + (done + 1) * SR_NX) == SR_ERR_NOT_ROTATION);
}

static void test_simulate_checks_x0_in_full(void)
{
    sr_model m;
    sr_real x[SR_NX], traj[2 * SR_NX];
    long done = -1;
    paper_simulation_model(&m);
    make_state(x, 0.3, 0.2, 0.3);
    x[11] = SR_C(1e-3); /* R_Y[0,2]: sr_accel does not read it, the simulation checks it */
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), 1, NULL, traj, &done), SR_ERR_NOT_ROTATION);
    CHECK(done == 0);
}

/* A frictionless robot under Lie-Euler with a large step: energy grows without input. */
static void frictionless_swing(sr_model *m, sr_real x[SR_NX])
{
    sr_real p[SR_NPARAM];
    paper_simulation_params(p);
    p[SR_P_k_S] = p[SR_P_k_Y] = p[SR_P_k_P] = 0; /* k_S, k_Y, k_P */
    CHECK_STATUS(sr_model_init(m, p), SR_OK);
    make_state(x, 0.0, 1.0, 0.3);
}

static void test_energy_guard_stops_a_run_that_gains_energy_without_input(void)
{
    enum { STEPS = 2000 };
    static sr_real traj[(STEPS + 1) * SR_NX];
    sr_model m;
    sr_real x[SR_NX];
    sr_energy_guard guard;
    long done = -1;
    frictionless_swing(&m, x);
    memset(&guard, 0, sizeof guard);
    guard.tol = SR_C(0.5);
    CHECK_STATUS(sr_simulate_guarded(&m, SR_LIE_EULER, x, SR_C(0.05), STEPS, NULL, &guard, traj, &done),
                 SR_ERR_ENERGY);
    CHECK(done > 0 && done < STEPS);
    CHECK(guard.energy > guard.e_start + SR_C(0.5) * guard.scale);
    /* disabled (tol < 0): the same run goes on */
    guard.tol = -1;
    guard.in_stretch = 0;
    CHECK_STATUS(sr_simulate_guarded(&m, SR_LIE_EULER, x, SR_C(0.05), done + 10, NULL, &guard, traj, &done),
                 SR_OK);
}

static void test_energy_guard_ignores_stretches_with_input_power(void)
{
    enum { STEPS = 400 };
    static sr_real traj[(STEPS + 1) * SR_NX], u[STEPS * SR_NU];
    sr_model m;
    sr_real x[SR_NX];
    sr_energy_guard guard;
    long done = -1;
    int i;
    frictionless_swing(&m, x);
    for (i = 0; i < STEPS * SR_NU; ++i) u[i] = SR_C(0.2); /* the motors push all the time */
    memset(&guard, 0, sizeof guard);
    guard.tol = 0;
    CHECK_STATUS(sr_simulate_guarded(&m, SR_RKMK4, x, SR_C(0.01), STEPS, u, &guard, traj, &done), SR_OK);
    CHECK(done == STEPS);
}

static void test_energy_guard_passes_an_accurate_damped_run(void)
{
    enum { STEPS = 1000 };
    static sr_real traj[(STEPS + 1) * SR_NX];
    sr_model m;
    sr_real x[SR_NX];
    sr_energy_guard guard;
    long done = -1;
    paper_simulation_model(&m);
    make_state(x, 0.5, 0.8, 0.3);
    x[SR_X_w_S] = SR_C(1.0);
    memset(&guard, 0, sizeof guard);
    guard.tol = SR_C(1e-3);
    CHECK_STATUS(sr_simulate_guarded(&m, SR_RKMK4, x, SR_C(0.01), STEPS, NULL, &guard, traj, &done), SR_OK);
    CHECK(guard.in_stretch && guard.energy < guard.e_start);
}

static void test_energy_guard_carries_its_stretch_across_chunks(void)
{
    enum { STEPS = 2000, CHUNK = 160 };
    static sr_real traj[(STEPS + 1) * SR_NX];
    sr_model m;
    sr_real x[SR_NX];
    sr_energy_guard whole, chunked;
    long done = -1, total = 0;
    int status = SR_OK;
    frictionless_swing(&m, x);
    memset(&whole, 0, sizeof whole);
    whole.tol = SR_C(0.5);
    CHECK_STATUS(sr_simulate_guarded(&m, SR_LIE_EULER, x, SR_C(0.05), STEPS, NULL, &whole, traj, &done),
                 SR_ERR_ENERGY);
    chunked = whole;
    chunked.in_stretch = 0;
    memcpy(traj, x, sizeof x);
    while (status == SR_OK && total < STEPS) {
        long part = 0;
        status = sr_simulate_guarded(&m, SR_LIE_EULER, traj + total * SR_NX, SR_C(0.05), CHUNK, NULL,
                                     &chunked, traj + total * SR_NX, &part);
        total += part;
    }
    CHECK_STATUS(status, SR_ERR_ENERGY);
    CHECK(total == done);
    CHECK(chunked.e_start == whole.e_start);
}

static void test_energy_guard_rejects_an_infinite_tolerance(void)
{
    sr_model m;
    sr_real x[SR_NX], traj[2 * SR_NX];
    sr_energy_guard guard;
    long done;
    paper_simulation_model(&m);
    make_state(x, 0.0, 0.0, 0.3);
    memset(&guard, 0, sizeof guard);
    guard.tol = (sr_real)INFINITY;
    CHECK_STATUS(sr_simulate_guarded(&m, SR_LIE_EULER, x, SR_C(0.01), 1, NULL, &guard, traj, &done), SR_ERR_ARG);
}

void suite_guards(void)
{
    RUN_TEST(test_model_init_rejects_lengths_whose_inertias_underflow);
    RUN_TEST(test_model_init_rejects_lengths_whose_inertias_overflow);
    RUN_TEST(test_kernel_results_that_overflow_are_reported_not_returned);
    RUN_TEST(test_check_state_batch_names_the_first_failing_row);
    RUN_TEST(test_simulate_stops_when_a_rotation_drifts_out_of_tolerance);
    RUN_TEST(test_simulate_checks_x0_in_full);
    RUN_TEST(test_energy_guard_stops_a_run_that_gains_energy_without_input);
    RUN_TEST(test_energy_guard_ignores_stretches_with_input_power);
    RUN_TEST(test_energy_guard_passes_an_accurate_damped_run);
    RUN_TEST(test_energy_guard_carries_its_stretch_across_chunks);
    RUN_TEST(test_energy_guard_rejects_an_infinite_tolerance);
}
