/*
 * test_nmpc.c -- the NMPC's box QP solver (c/src/sr_boxqp.c) against its optimality conditions,
 * the prediction node's sensitivities against central differences, and the sample's status codes
 * (c/src/sr_nmpc.c).  Equality with DAQP and the closed loop are tests/test_c_nmpc.py's.
 */
#include "sr_test.h"
#include "sr_nmpc.h"

#include <math.h>
#include <string.h>

#define QN 12

/* A random positive definite H = M M^T + n I / 10 and a gradient, bounds around zero. */
static void random_qp(test_rng *rng, int n, sr_real *H, sr_real *g, sr_real *lb, sr_real *ub)
{
    double M[QN * QN];
    int i, j, k;
    for (i = 0; i < n * n; ++i) M[i] = rng_uniform(rng, -1, 1);
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            double s = i == j ? 0.1 * n : 0;
            for (k = 0; k < n; ++k) s += M[i * n + k] * M[j * n + k];
            H[i * n + j] = (sr_real)s;
        }
    for (i = 0; i < n; ++i) {
        g[i] = (sr_real)rng_uniform(rng, -5, 5);
        lb[i] = (sr_real)rng_uniform(rng, -1, 0);
        ub[i] = (sr_real)rng_uniform(rng, 0, 1);
    }
}

/* The KKT conditions of the box QP at x: inside the box, the gradient zero on free entries and
 * pushing outwards on bound ones, to tol. */
static int kkt_holds(int n, const sr_real *H, const sr_real *g, const sr_real *lb, const sr_real *ub,
                     const sr_real *x, double tol)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        double grad = g[i];
        for (j = 0; j < n; ++j) grad += (double)H[i * n + j] * x[j];
        if (x[i] < lb[i] || x[i] > ub[i]) return 0;
        if (x[i] > lb[i] && x[i] < ub[i] && fabs(grad) > tol) return 0;
        if (x[i] == lb[i] && grad < -tol) return 0;
        if (x[i] == ub[i] && grad > tol) return 0;
    }
    return 1;
}

static void test_boxqp_meets_the_optimality_conditions_on_random_problems(void)
{
    test_rng rng = {7};
    sr_real H[QN * QN], g[QN], lb[QN], ub[QN], x[QN], work[SR_BOXQP_WORK_REALS(QN)];
    int iwork[SR_BOXQP_WORK_INTS(QN)], trial, n, iterations, bound = 0;
    for (trial = 0; trial < 200; ++trial) {
        n = 1 + trial % QN;
        random_qp(&rng, n, H, g, lb, ub);
        memset(x, 0, sizeof x);
        CHECK_STATUS(sr_boxqp_solve(n, H, g, lb, ub, 10 * n, x, work, iwork, &iterations), SR_OK);
        CHECK(kkt_holds(n, H, g, lb, ub, x, 1e3 * TEST_EPS * (1 + 5 * n)));
        CHECK(iterations >= 1 && iterations <= 10 * n);
        bound += x[0] == lb[0] || x[0] == ub[0];
    }
    CHECK(bound > 20 && bound < 180); /* the problems exercise both free and bound solutions */
}

static void test_boxqp_without_active_bounds_solves_the_linear_system(void)
{
    const sr_real H[4] = {4, 1, 1, 3}, g[2] = {1, 2}, lb[2] = {-10, -10}, ub[2] = {10, 10};
    sr_real x[2] = {5, -5}, work[SR_BOXQP_WORK_REALS(2)];
    int iwork[SR_BOXQP_WORK_INTS(2)];
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, work, iwork, NULL), SR_OK);
    /* [[4, 1], [1, 3]] x = -(1, 2): x = (-1/11, -7/11) */
    CHECK_NEAR(x[0], -1.0 / 11, 8 * TEST_EPS);
    CHECK_NEAR(x[1], -7.0 / 11, 8 * TEST_EPS);
}

static void test_boxqp_releases_a_bound_the_start_put_it_on(void)
{
    /* Starting at the lower bound of x0, whose multiplier has the wrong sign there. */
    const sr_real H[4] = {2, 0, 0, 2}, g[2] = {-1, 4}, lb[2] = {-1, -1}, ub[2] = {1, 1};
    sr_real x[2] = {-1, 0}, work[SR_BOXQP_WORK_REALS(2)];
    int iwork[SR_BOXQP_WORK_INTS(2)];
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, work, iwork, NULL), SR_OK);
    CHECK_NEAR(x[0], 0.5, 8 * TEST_EPS);
    CHECK(x[1] == -1);
}

static void test_boxqp_status_codes_leave_x_untouched(void)
{
    sr_real H[4] = {1, 0, 0, 1}, g[2] = {1, 1}, lb[2] = {-1, -1}, ub[2] = {1, 1};
    sr_real x[2] = {0.25, 0.25}, work[SR_BOXQP_WORK_REALS(2)];
    int iwork[SR_BOXQP_WORK_INTS(2)];
    CHECK_STATUS(sr_boxqp_solve(2, NULL, g, lb, ub, 10, x, work, iwork, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, NULL, iwork, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_boxqp_solve(0, H, g, lb, ub, 10, x, work, iwork, NULL), SR_ERR_ARG);
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 0, x, work, iwork, NULL), SR_ERR_ARG);
    lb[1] = 2;
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, work, iwork, NULL), SR_ERR_ARG);
    lb[1] = -1;
    g[1] = (sr_real)NAN;
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, work, iwork, NULL), SR_ERR_NONFINITE);
    g[1] = 1;
    lb[0] = (sr_real)NAN;
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, work, iwork, NULL), SR_ERR_NONFINITE);
    lb[0] = -1;
    H[3] = -1;
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, work, iwork, NULL), SR_ERR_SINGULAR);
    H[3] = 1;
    /* the minimum (-1, -1) is met by a step blocked at x[1]: one factorisation does not get there */
    g[1] = 3;
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 1, x, work, iwork, NULL), SR_ERR_MAX_STEPS);
    CHECK(x[0] == SR_C(0.25) && x[1] == SR_C(0.25));
    g[1] = 1;
    /* infinite bounds are allowed */
    lb[0] = lb[1] = -(sr_real)INFINITY;
    ub[0] = ub[1] = (sr_real)INFINITY;
    CHECK_STATUS(sr_boxqp_solve(2, H, g, lb, ub, 10, x, work, iwork, NULL), SR_OK);
    CHECK_NEAR(x[0], -1, 0);
}

/* A state near straight rolling at v: small errors in every coordinate. */
static void some_z(sr_real z[SR_NMPC_NZ])
{
    const double values[SR_NMPC_NZ] = {0.02, -0.03, 0.05, 0.1, 0.05, -0.02, 0.03, -0.1, 0.2, 0.01, 0.003};
    int i;
    for (i = 0; i < SR_NMPC_NZ; ++i) z[i] = (sr_real)values[i];
}

static void test_node_sensitivities_equal_central_differences(void)
{
    sr_model m;
    const double h = sizeof(sr_real) == sizeof(double) ? 1e-6 : 3e-3;
    const double tol = sizeof(sr_real) == sizeof(double) ? 1e-6 : 3e-2;
    const sr_real u[SR_NU] = {SR_C(0.1), SR_C(-0.05)}, kappas[2] = {0, SR_C(0.5)};
    sr_real z[SR_NMPC_NZ], zp[SR_NMPC_NZ], zm[SR_NMPC_NZ], zn[SR_NMPC_NZ], up[SR_NU];
    sr_real A[SR_NMPC_NZ * SR_NMPC_NZ], B[SR_NMPC_NZ * SR_NU];
    int i, j, c;
    paper_simulation_model(&m);
    for (c = 0; c < 2; ++c) {
        some_z(z);
        CHECK_STATUS(sr_nmpc_node(&m, z, u, SR_C(0.3), kappas[c], SR_C(0.1), zn, A, B), SR_OK);
        for (j = 0; j < SR_NMPC_NZ; ++j) {
            sr_real d[SR_NMPC_NZ];
            memcpy(d, z, sizeof d);
            d[j] = (sr_real)(z[j] + h);
            CHECK_STATUS(sr_nmpc_node(&m, d, u, SR_C(0.3), kappas[c], SR_C(0.1), zp, NULL, NULL), SR_OK);
            d[j] = (sr_real)(z[j] - h);
            CHECK_STATUS(sr_nmpc_node(&m, d, u, SR_C(0.3), kappas[c], SR_C(0.1), zm, NULL, NULL), SR_OK);
            for (i = 0; i < SR_NMPC_NZ; ++i)
                CHECK_NEAR(A[i * SR_NMPC_NZ + j], (zp[i] - zm[i]) / (2 * h), tol * (1 + fabs(A[i * SR_NMPC_NZ + j])));
        }
        for (j = 0; j < SR_NU; ++j) {
            memcpy(up, u, sizeof up);
            up[j] = (sr_real)(u[j] + h);
            CHECK_STATUS(sr_nmpc_node(&m, z, up, SR_C(0.3), kappas[c], SR_C(0.1), zp, NULL, NULL), SR_OK);
            up[j] = (sr_real)(u[j] - h);
            CHECK_STATUS(sr_nmpc_node(&m, z, up, SR_C(0.3), kappas[c], SR_C(0.1), zm, NULL, NULL), SR_OK);
            for (i = 0; i < SR_NMPC_NZ; ++i)
                CHECK_NEAR(B[i * SR_NU + j], (zp[i] - zm[i]) / (2 * h), tol * (1 + fabs(B[i * SR_NU + j])));
        }
    }
}

static void test_node_on_a_straight_path_reads_the_step_of_the_full_model(void)
{
    /* kappa = 0: the cross-track error is q_y of sr_step's new state, the heading error its yaw. */
    sr_model m;
    const sr_real u[SR_NU] = {SR_C(0.1), SR_C(-0.05)};
    sr_real z[SR_NMPC_NZ], zn[SR_NMPC_NZ], x[SR_NX], xn[SR_NX];
    sr_lqr_target t = {SR_C(0.3), 0, 0, 0, 1};
    sr_real zl[SR_LQR_NZ];
    int i;
    paper_simulation_model(&m);
    some_z(z);
    CHECK_STATUS(sr_nmpc_node(&m, z, u, SR_C(0.3), 0, SR_C(0.1), zn, NULL, NULL), SR_OK);
    /* the lift by hand: R_S = rot_z(-pi/2) Exp(E), R_Y = I, R_P = rot_y(theta_P), q = (0, e_y, r) */
    make_state(x, 0.0, (double)z[3], 0.3);
    {
        sr_real E[9], Rz[9];
        int r, c;
        CHECK_STATUS(sr_so3_exp(z, E), SR_OK);
        rot_z(-3.14159265358979323846 / 2, Rz);
        for (r = 0; r < 3; ++r)
            for (c = 0; c < 3; ++c)
                x[SR_X_R_S + 3 * r + c] = Rz[3 * r] * E[c] + Rz[3 * r + 1] * E[3 + c] + Rz[3 * r + 2] * E[6 + c];
    }
    x[SR_X_q + 1] = z[9];
    x[SR_X_w_S] = z[4] - SR_C(0.3) / SR_C(0.3);
    x[SR_X_w_S + 1] = z[5];
    x[SR_X_w_S + 2] = z[6];
    x[SR_X_w_Y] = z[7] + 1;
    x[SR_X_w_P] = z[8];
    CHECK_STATUS(sr_step(&m, SR_RKMK4, x, u, SR_C(0.1), xn), SR_OK);
    t.cross_track = xn[SR_X_q + 1];
    CHECK_STATUS(sr_lqr_error(&m, xn, &t, NULL, zl), SR_OK);
    for (i = 0; i < 10; ++i) CHECK_NEAR(zn[i], zl[i], 64 * TEST_EPS);
    CHECK_NEAR(zn[10], z[10] + 0.05 * (z[9] + zn[9]), 16 * TEST_EPS);
}

/* A design of one grid point: rolling at 0.3 m/s on the paper's robot needs (u*, z*) which the
 * test does not know, so u* = 0 and z* = 0 with weights that only ask for a small error. */



static void small_design(sr_nmpc *d)
{
    int i;
    memset(d, 0, sizeof *d);
    d->horizon = 10;
    d->node_periods = 2;
    d->cold_iterations = 3;
    d->iterations = 1;
    d->qp_max_iterations = 100;
    d->period = SR_C(0.05);
    d->u_max = SR_C(0.5);
    d->r = 4;
    d->r_step = 100;
    d->steady_rate = SR_C(0.005);
    d->disturbance_gain = SR_C(0.2);
    d->heading_jump = SR_C(0.3);
    for (i = 0; i < SR_NMPC_NZ; ++i) d->q_path[i] = d->q_heading[i] = 1;
    d->n_speeds = d->n_curvatures = 1;
    d->speeds[0] = SR_C(0.3);
    for (i = 0; i < SR_NMPC_NZ; ++i) d->P_path[0][i * (SR_NMPC_NZ + 1)] = d->P_heading[0][i * (SR_NMPC_NZ + 1)] = 10;
}

static void test_step_keeps_the_torques_within_the_limits_and_counts_samples(void)
{
    static sr_nmpc_memory mem; /* about 160 kB: not on the stack */
    sr_nmpc d;
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    sr_nmpc_target t = {SR_C(0.3), SR_C(0.5), 0, SR_C(0.01), 1, NULL};
    int k;
    paper_simulation_model(&m);
    small_design(&d);
    CHECK_STATUS(sr_nmpc_check(&d), SR_OK);
    CHECK_STATUS(sr_nmpc_reset(&mem), SR_OK);
    make_state(x, 0.0, 0.0, 0.3);
    for (k = 0; k < 3; ++k) {
        CHECK_STATUS(sr_nmpc_step(&d, &mem, &m, x, &t, u), SR_OK);
        CHECK(fabs(u[0]) <= 0.5 && fabs(u[1]) <= 0.5);
    }
    CHECK(mem.samples == 3 && mem.failures == 0 && mem.have_guess);
    CHECK(sr_nmpc_memory_bytes() == (long)sizeof(sr_nmpc_memory));
}

static void test_step_status_codes_leave_u_and_memory_untouched(void)
{
    static sr_nmpc_memory mem;
    sr_nmpc d;
    sr_model m;
    sr_real x[SR_NX], u[SR_NU] = {7, 7};
    sr_nmpc_target t = {SR_C(0.3), 0, 0, 0, 1, NULL};
    paper_simulation_model(&m);
    small_design(&d);
    sr_nmpc_reset(&mem);
    make_state(x, 0.0, 0.0, 0.3);
    CHECK_STATUS(sr_nmpc_step(NULL, &mem, &m, x, &t, u), SR_ERR_NULL);
    CHECK_STATUS(sr_nmpc_step(&d, &mem, &m, x, NULL, u), SR_ERR_NULL);
    d.horizon = SR_NMPC_MAX_HORIZON + 1;
    CHECK_STATUS(sr_nmpc_step(&d, &mem, &m, x, &t, u), SR_ERR_ARG);
    CHECK_STATUS(sr_nmpc_check(&d), SR_ERR_ARG);
    d.horizon = 10;
    d.P_path[0][3] = (sr_real)NAN;
    CHECK_STATUS(sr_nmpc_check(&d), SR_ERR_NONFINITE);
    d.P_path[0][3] = 0;
    t.cross_track = (sr_real)INFINITY;
    CHECK_STATUS(sr_nmpc_step(&d, &mem, &m, x, &t, u), SR_ERR_NONFINITE);
    t.cross_track = 0;
    x[SR_X_q + 2] = SR_C(0.5);
    CHECK_STATUS(sr_nmpc_step(&d, &mem, &m, x, &t, u), SR_ERR_CONSTRAINT);
    CHECK(u[0] == 7 && u[1] == 7 && mem.samples == 0 && !mem.have_guess);
    CHECK_STATUS(sr_nmpc_reset(NULL), SR_ERR_NULL);
}

/* The recovery tests' case: the paper's robot rolling at 0.3 m/s on a straight path, small_design,
 * a reset memory (static: the memory is about 160 kB). */
typedef struct recovery_case {
    sr_nmpc_memory mem;
    sr_nmpc *d; /* the caller's (on its stack: static, the M7 test image's RAM overflows) */
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    sr_nmpc_target t;
} recovery_case;

static recovery_case *recovery_start(sr_nmpc *d)
{
    static recovery_case c;
    const sr_nmpc_target t = {SR_C(0.3), 0, 0, SR_C(0.01), 1, NULL};
    paper_simulation_model(&c.m);
    c.d = d;
    small_design(d);
    sr_nmpc_reset(&c.mem);
    make_state(c.x, 0.0, 0.0, 0.3);
    c.t = t;
    return &c;
}

static int recovery_step(recovery_case *c)
{
    return sr_nmpc_step(c->d, &c->mem, &c->m, c->x, &c->t, c->u);
}

/* A guess whose nodes cannot be predicted (the warm start fails): the sample starts once more from
 * the reference, which solves it, and the recovery is not needed. */
static void test_a_failed_warm_start_is_solved_from_the_reference(void)
{
    sr_nmpc d;
    recovery_case *c = recovery_start(&d);
    int k;
    CHECK_STATUS(recovery_step(c), SR_OK);
    CHECK(c->mem.restarts == 0 && c->mem.recoveries == 0 && c->mem.recovering == 0);
    for (k = 0; k < (SR_NMPC_MAX_HORIZON + 1) * SR_NMPC_NZ; ++k) c->mem.Z[k] = SR_C(1e30);
    CHECK_STATUS(recovery_step(c), SR_OK);
    CHECK(c->mem.restarts == 1 && c->mem.recoveries == 0 && c->mem.failures == 0 && c->mem.recovering == 0);
    CHECK(c->mem.have_guess && fabs(c->u[0]) <= 0.5 && fabs(c->u[1]) <= 0.5 && fabs(c->mem.Z[0]) < 1);
}

/* A reference whose nodes cannot be predicted (an operating point's shell rate far beyond the
 * model's range): every start from it fails, and the recovery's rollout from the measured state
 * solves the sample and the next SR_NMPC_RECOVERY_SAMPLES samples (the restart from the reference
 * alone failed every sample and held the reference's torques). */
static void test_a_reference_that_cannot_be_predicted_is_solved_by_the_recovery(void)
{
    sr_nmpc d;
    recovery_case *c = recovery_start(&d);
    int k;
    d.z_star[0][4] = 1000; /* rad/s */
    for (k = 0; k < 3; ++k) {
        CHECK_STATUS(recovery_step(c), SR_OK);
        CHECK(fabs(c->u[0]) <= 0.5 && fabs(c->u[1]) <= 0.5);
    }
    CHECK(c->mem.failures == 0 && c->mem.failing == 0 && c->mem.restarts == 1 && c->mem.recoveries == 3);
    CHECK(c->mem.recovering == SR_NMPC_RECOVERY_SAMPLES - 2 && c->mem.have_guess);
}

/* A sample that nothing can predict (a shell acceleration beyond any rollout) holds the reference's
 * torques and counts a failure; once the prediction is possible again the next sample is solved by
 * the recovery and the count of consecutive failures is cleared. */
static void test_a_failed_sample_is_recovered_from(void)
{
    sr_nmpc d;
    recovery_case *c = recovery_start(&d);
    d.disturbance_gain = 0;
    c->mem.shell_accel[0] = SR_C(1e30);
    CHECK_STATUS(recovery_step(c), SR_OK);
    CHECK(c->mem.failures == 1 && c->mem.failing == 1 && !c->mem.have_guess && c->u[0] == 0 && c->u[1] == 0);
    CHECK(c->mem.recovering == SR_NMPC_RECOVERY_SAMPLES);
    c->mem.shell_accel[0] = 0;
    CHECK_STATUS(recovery_step(c), SR_OK);
    CHECK(c->mem.failures == 1 && c->mem.failing == 0 && c->mem.have_guess && c->mem.recoveries == 2);
}

void suite_nmpc(void)
{
    RUN_TEST(test_boxqp_meets_the_optimality_conditions_on_random_problems);
    RUN_TEST(test_boxqp_without_active_bounds_solves_the_linear_system);
    RUN_TEST(test_boxqp_releases_a_bound_the_start_put_it_on);
    RUN_TEST(test_boxqp_status_codes_leave_x_untouched);
    RUN_TEST(test_node_sensitivities_equal_central_differences);
    RUN_TEST(test_node_on_a_straight_path_reads_the_step_of_the_full_model);
    RUN_TEST(test_step_keeps_the_torques_within_the_limits_and_counts_samples);
    RUN_TEST(test_step_status_codes_leave_u_and_memory_untouched);
    RUN_TEST(test_a_failed_warm_start_is_solved_from_the_reference);
    RUN_TEST(test_a_reference_that_cannot_be_predicted_is_solved_by_the_recovery);
    RUN_TEST(test_a_failed_sample_is_recovered_from);
}
