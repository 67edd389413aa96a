/*
 * test_param_jacobians.c -- the derivatives in the parameters (c/src/sr_param_jacobians.c): the
 * columns of sr_accel_param_jacobian are central differences of sr_accel over perturbed models; a
 * Lie-Euler step's sensitivity is dt times it in the nu rows; the regressor times the robot's
 * inertial parameters is M nu' - f; an RKMK4 step's sensitivity on columns that move pi alone is
 * the batched central differences; the method and bad input are refused with outputs untouched.
 */
#include "sr_test.h"

#include <math.h>
#include <string.h>

static void test_accel_param_jacobian_columns_are_central_differences_over_perturbed_models(void)
{
    /* Step h |p_k|: truncation ~h^2, rounding ~eps/h (double only: float rounding swamps it). */
    const double h = 1e-4, tol = 1e-5;
    sr_real p[SR_NPARAM], q[SR_NPARAM], x[SR_NX], u[SR_NU] = {SR_C(0.05), SR_C(-0.02)};
    sr_real J[SR_NV * SR_NPARAM], ap[SR_NV], am[SR_NV];
    test_rng rng = {38};
    sr_model m, mq;
    double scale = 0;
    int k, i, s;
    if (TEST_EPS > 1e-10) return;
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 2.0, x);
    CHECK_STATUS(sr_accel_param_jacobian(&m, x, u, J), SR_OK);
    for (i = 0; i < SR_NV * SR_NPARAM; ++i) scale = fabs((double)J[i]) > scale ? fabs((double)J[i]) : scale;
    for (k = 0; k < SR_NPARAM; ++k) {
        const double step = p[k] != 0 ? h * fabs((double)p[k]) : 1e-6;
        for (s = -1; s <= 1; s += 2) {
            memcpy(q, p, sizeof q);
            q[k] += (sr_real)(s * step);
            CHECK_STATUS(sr_model_init(&mq, q), SR_OK);
            x[SR_X_q + 2] = q[SR_P_r];   /* the state's q_z follows the radius */
            CHECK_STATUS(sr_accel(&mq, x, u, s > 0 ? ap : am), SR_OK);
        }
        x[SR_X_q + 2] = p[SR_P_r];
        for (i = 0; i < SR_NV; ++i)
            CHECK_NEAR(J[SR_NPARAM * i + k], ((double)ap[i] - (double)am[i]) / (2 * step), tol * scale);
    }
}

static void test_a_lie_euler_steps_sensitivity_is_dt_times_the_accelerations_in_the_nu_rows(void)
{
    const sr_real dt = SR_C(0.02);
    sr_real p[SR_NPARAM], x[SR_NX], u[SR_NU] = {SR_C(0.1), SR_C(0.03)};
    sr_real J[SR_NV * SR_NPARAM], Jp[SR_NE * SR_NPARAM];
    test_rng rng = {39};
    sr_model m;
    int i, k;
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 2.0, x);
    CHECK_STATUS(sr_accel_param_jacobian(&m, x, u, J), SR_OK);
    CHECK_STATUS(sr_step_param_jacobian(&m, SR_LIE_EULER, x, u, dt, Jp), SR_OK);
    for (i = 0; i < SR_NV; ++i)
        for (k = 0; k < SR_NPARAM; ++k)
            CHECK_NEAR(Jp[SR_NPARAM * (SR_E_nu + i) + k], (double)dt * (double)J[SR_NPARAM * i + k],
                       8 * TEST_EPS * fabs((double)dt * (double)J[SR_NPARAM * i + k]) + 1e-300);
    for (i = 0; i < SR_E_q; ++i)   /* the attitude and the joint angles move with the speeds alone */
        for (k = 0; k < SR_NPARAM; ++k) CHECK(Jp[SR_NPARAM * i + k] == 0);
}

/* pi of a general robot (SR_PI_*): masses, m c, J + m (|c|^2 I - c c^T), dampings, rotors. */
static void inertial_parameters(const sr_real p[SR_NPARAM], sr_real pi[SR_NPI])
{
    static const int c_Y = SR_P_c_Y_x, c_P = SR_P_c_P_x, J_Y = SR_P_J_Y_xx, J_P = SR_P_J_P_xx;
    const int bodies[2][6] = {{SR_P_m_Y, c_Y, J_Y, SR_P_k_Y, SR_PI_m_Y, SR_PI_k_Y},
                              {SR_P_m_P, c_P, J_P, SR_P_k_P, SR_PI_m_P, SR_PI_k_P}};
    int b, i;
    pi[SR_PI_m_S] = p[SR_P_m_S];
    pi[SR_PI_j_S] = p[SR_P_j_S];
    pi[SR_PI_k_S] = p[SR_P_k_S];
    pi[SR_PI_j_mY] = p[SR_P_j_mY];
    pi[SR_PI_j_mP] = p[SR_P_j_mP];
    for (b = 0; b < 2; ++b) {
        const sr_real m = p[bodies[b][0]], *c = p + bodies[b][1], *J = p + bodies[b][2];
        const sr_real cc = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
        sr_real *out = pi + bodies[b][4];   /* m, m c (3), J_O xx yy zz xy xz yz, then k */
        out[0] = m;
        for (i = 0; i < 3; ++i) out[1 + i] = m * c[i];
        for (i = 0; i < 3; ++i) out[4 + i] = J[i] + m * (cc - c[i] * c[i]);
        out[7] = J[3] - m * c[0] * c[1];
        out[8] = J[4] - m * c[0] * c[2];
        out[9] = J[5] - m * c[1] * c[2];
        pi[bodies[b][5]] = p[bodies[b][3]];
    }
}

static void test_the_regressor_times_pi_is_m_nudot_minus_f(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], a[SR_NV] = {SR_C(0.3), SR_C(-1.2), SR_C(0.7), SR_C(2.0), SR_C(-0.4)};
    sr_real pi[SR_NPI], Y[SR_NV * SR_NPI], M[SR_NV * SR_NV], f[SR_NV];
    test_rng rng = {40};
    sr_model m;
    int i, k;
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 2.0, x);
    inertial_parameters(p, pi);
    CHECK_STATUS(sr_regressor(&m, x, a, Y), SR_OK);
    CHECK_STATUS(sr_inertia(&m, x, M), SR_OK);
    CHECK_STATUS(sr_rhs(&m, x, NULL, f), SR_OK);
    for (i = 0; i < SR_NV; ++i) {
        double y = 0, r = -(double)f[i], scale = fabs((double)f[i]);
        for (k = 0; k < SR_NPI; ++k) y += (double)Y[SR_NPI * i + k] * (double)pi[k];
        for (k = 0; k < SR_NV; ++k) {
            r += (double)M[SR_NV * i + k] * (double)a[k];
            scale += fabs((double)M[SR_NV * i + k] * (double)a[k]);
        }
        CHECK_NEAR(y, r, 1e3 * TEST_EPS * scale);
    }
}

/* An RKMK4 step's sensitivity on columns that move pi alone (a fit's free entries: the lockstep
 * blocks and the regressor's bracket) is the batched central differences of the step over
 * perturbed models (sr_step_param_jacobian_fd_batch, its own path through sr_step_batch), from both
 * entry points that take it: with the end states (a full-state fit's) and with F (a sensor fit's). */
static void test_an_rkmk4_steps_pi_columns_are_the_batched_central_differences(void)
{
    enum { N = 11, NC = 7 };
    static const int cols[NC] = {SR_P_k_S, SR_P_k_Y, SR_P_k_P, SR_P_m_P, SR_P_J_P_yy, SR_P_c_P_x, SR_P_j_mY};
    static sr_real x[N][SR_NX], u[N][SR_NU], next[N][SR_NX], F[N][SR_NE * SR_NE], Jp[N][SR_NE * NC],
        Jf[N][SR_NE * NC], Jw[N][SR_NE * NC], work[N * SR_PARAM_FD_WORK];
    const sr_real dt = SR_C(0.01);
    sr_real p[SR_NPARAM];
    test_rng rng = {42};
    sr_model m;
    long row = 5;
    int i, k, c;
    if (TEST_EPS > 1e-10) return;   /* double only: float rounding swamps the differences */
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    for (i = 0; i < N; ++i) {
        random_state(&rng, p[SR_P_r], 2.0, x[i]);
        u[i][0] = (sr_real)rng_uniform(&rng, -0.15, 0.15);
        u[i][1] = (sr_real)rng_uniform(&rng, -0.15, 0.15);
    }
    CHECK_STATUS(sr_step_param_jacobian_fd_batch(&m, SR_RKMK4, N, x[0], u[0], dt, NC, cols, Jf[0], work, &row), SR_OK);
    CHECK_STATUS(sr_step_and_param_jacobian_cols_batch(&m, SR_RKMK4, N, x[0], u[0], dt, NC, cols, next[0], Jp[0], &row),
                 SR_OK);
    CHECK_STATUS(sr_step_jacobian_param_cols_batch(&m, SR_RKMK4, N, x[0], u[0], dt, NC, cols, F[0], Jw[0], &row), SR_OK);
    CHECK(row == -1);
    for (c = 0; c < NC; ++c) {   /* each column against its own size: the differences' error is ~1e-10 of it */
        double scale = 0;
        for (i = 0; i < N; ++i)
            for (k = 0; k < SR_NE; ++k) scale = fmax(scale, fabs((double)Jf[i][NC * k + c]));
        for (i = 0; i < N; ++i)
            for (k = 0; k < SR_NE; ++k) {
                CHECK_NEAR(Jp[i][NC * k + c], Jf[i][NC * k + c], 1e-7 * scale);
                CHECK_NEAR(Jw[i][NC * k + c], Jf[i][NC * k + c], 1e-7 * scale);
            }
    }
}

static void test_parameter_jacobians_refuse_a_method_and_bad_input_leaving_outputs_untouched(void)
{
    sr_real p[SR_NPARAM], x[SR_NX], a[SR_NV] = {0}, Jp[SR_NE * SR_NPARAM], Y[SR_NV * SR_NPI];
    test_rng rng = {41};
    sr_model m;
    long row = 7;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 2.0, x);
    Jp[0] = SR_C(42.0);
    CHECK_STATUS(sr_step_param_jacobian(&m, SR_CF4, x, NULL, SR_C(0.01), Jp), SR_ERR_ARG);
    CHECK_STATUS(sr_step_param_jacobian_batch(&m, SR_CF4, 1, x, NULL, SR_C(0.01), Jp, &row), SR_ERR_ARG);
    CHECK(row == -1);
    CHECK_STATUS(sr_step_param_jacobian(&m, SR_RKMK4, x, NULL, SR_C(0.0), Jp), SR_ERR_ARG);
    a[2] = (sr_real)NAN;
    Y[0] = SR_C(42.0);
    CHECK_STATUS(sr_regressor(&m, x, a, Y), SR_ERR_NONFINITE);
    CHECK(Jp[0] == SR_C(42.0) && Y[0] == SR_C(42.0));
    CHECK_STATUS(sr_accel_param_jacobian(NULL, x, NULL, Jp), SR_ERR_NULL);
}

void suite_param_jacobians(void)
{
    RUN_TEST(test_accel_param_jacobian_columns_are_central_differences_over_perturbed_models);
    RUN_TEST(test_a_lie_euler_steps_sensitivity_is_dt_times_the_accelerations_in_the_nu_rows);
    RUN_TEST(test_the_regressor_times_pi_is_m_nudot_minus_f);
    RUN_TEST(test_an_rkmk4_steps_pi_columns_are_the_batched_central_differences);
    RUN_TEST(test_parameter_jacobians_refuse_a_method_and_bad_input_leaving_outputs_untouched);
}
