/* The general robot in C: sr_model_init chooses the kernels, the general kernels agree
 * with the paper-geometry ones where both apply, and a general robot conserves energy on its slope.
 * (Against the independent references: tests/runtime/verification, make verify.) */
#include "sr_test.h"

#include <math.h>

static void test_model_init_chooses_the_kernels_by_the_geometry(void)
{
    sr_model m;
    sr_real p[SR_NPARAM];
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    CHECK(m.general == 0);
    p[SR_P_slope] = SR_C(1e-3); /* any departure from the paper's geometry */
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    CHECK(m.general == 1);
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    CHECK(m.general == 1);
}

/* The paper's robot through the general kernels (forced by a rotor of negligible inertia) gives
 * the paper-geometry kernels' accelerations and energies, to rounding. */
static void test_general_kernels_agree_with_the_paper_kernels_on_the_papers_robot(void)
{
    sr_model paper, general;
    sr_real p[SR_NPARAM], x[SR_NX], u[SR_NU], a[SR_NV], b[SR_NV], Ea, Eb;
    test_rng rng = {42};
    int i, k;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&paper, p), SR_OK);
    p[SR_P_j_mY] = SR_C(1e-30);
    CHECK_STATUS(sr_model_init(&general, p), SR_OK);
    CHECK(general.general == 1);
    for (i = 0; i < 200; ++i) {
        double scale = 0;
        random_state(&rng, p[SR_P_r], 3.0, x);
        u[0] = (sr_real)rng_uniform(&rng, -1, 1);
        u[1] = (sr_real)rng_uniform(&rng, -1, 1);
        CHECK_STATUS(sr_accel(&paper, x, u, a), SR_OK);
        CHECK_STATUS(sr_accel(&general, x, u, b), SR_OK);
        for (k = 0; k < SR_NV; ++k) scale = fmax(scale, fabs((double)a[k]));
        for (k = 0; k < SR_NV; ++k) CHECK_NEAR(b[k], a[k], 1e4 * TEST_EPS * scale);
        CHECK_STATUS(sr_energy(&paper, x, &Ea), SR_OK);
        CHECK_STATUS(sr_energy(&general, x, &Eb), SR_OK);
        CHECK_NEAR(Eb, Ea, 1e4 * TEST_EPS * fabs((double)Ea) + 1e3 * TEST_EPS);
    }
}

/* The contact force of the paper's robot through the general kernel equals the paper-geometry
 * kernel's, and one state of a batch is the single call's, bit for bit. */
static void test_general_contact_force_agrees_with_the_papers_and_the_batch_with_single_calls(void)
{
    sr_model paper, general;
    sr_real p[SR_NPARAM], x[2 * SR_NX], u[2 * SR_NU], F[3], G[3], B[6];
    test_rng rng = {43};
    long row;
    int i, k;
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(&paper, p), SR_OK);
    p[SR_P_j_mY] = SR_C(1e-30);
    CHECK_STATUS(sr_model_init(&general, p), SR_OK);
    for (i = 0; i < 100; ++i) {
        double scale = 0;
        random_state(&rng, p[SR_P_r], 3.0, x);
        random_state(&rng, p[SR_P_r], 3.0, x + SR_NX);
        for (k = 0; k < 2 * SR_NU; ++k) u[k] = (sr_real)rng_uniform(&rng, -1, 1);
        CHECK_STATUS(sr_contact_force(&paper, x, u, F), SR_OK);
        CHECK_STATUS(sr_contact_force(&general, x, u, G), SR_OK);
        for (k = 0; k < 3; ++k) scale = fmax(scale, fabs((double)F[k]));
        for (k = 0; k < 3; ++k) CHECK_NEAR(G[k], F[k], 1e4 * TEST_EPS * scale);
        CHECK_STATUS(sr_contact_force_batch(&general, 2, x, u, B, &row), SR_OK);
        CHECK(row == -1);
        CHECK_STATUS(sr_contact_force(&general, x + SR_NX, u + SR_NU, F), SR_OK);
        for (k = 0; k < 3; ++k) CHECK(B[k] == G[k] && B[3 + k] == F[k]);
    }
}

/* At rest on a flat floor the floor carries the weight m_R g and no more. */
static void test_at_rest_the_contact_force_is_the_weight(void)
{
    sr_model m;
    sr_real p[SR_NPARAM], x[SR_NX], F[3];
    double weight;
    paper_simulation_model(&m);
    paper_simulation_params(p);
    weight = (double)((p[SR_P_m_S] + p[SR_P_m_Y] + p[SR_P_m_P]) * p[SR_P_g]);
    make_state(x, 0.0, 0.0, p[SR_P_r]);
    CHECK_STATUS(sr_contact_force(&m, x, NULL, F), SR_OK);
    CHECK_NEAR(F[0], 0.0, 10 * TEST_EPS * weight);
    CHECK_NEAR(F[1], 0.0, 10 * TEST_EPS * weight);
    CHECK_NEAR(F[2], weight, 10 * TEST_EPS * weight);
}

/* Without damping and torque a general robot on its slope keeps its energy (RKMK4 error only). */
static void test_a_general_robot_keeps_its_energy_on_its_slope(void)
{
    sr_model m;
    sr_real p[SR_NPARAM], x[SR_NX], E0, E1;
    test_rng rng = {7};
    int n;
    general_robot_params(p);
    p[SR_P_k_S] = p[SR_P_k_Y] = p[SR_P_k_P] = 0;
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    random_state(&rng, p[SR_P_r], 1.0, x);
    CHECK_STATUS(sr_energy(&m, x, &E0), SR_OK);
    for (n = 0; n < 200; ++n) CHECK_STATUS(sr_step(&m, SR_RKMK4, x, NULL, SR_C(0.005), x), SR_OK);
    CHECK_STATUS(sr_energy(&m, x, &E1), SR_OK);
    CHECK_NEAR(E1, E0, (TEST_EPS > 1e-10 ? 1e-3 : 1e-7) * fabs((double)E0));
}

void suite_general(void)
{
    RUN_TEST(test_model_init_chooses_the_kernels_by_the_geometry);
    RUN_TEST(test_general_kernels_agree_with_the_paper_kernels_on_the_papers_robot);
    RUN_TEST(test_a_general_robot_keeps_its_energy_on_its_slope);
    RUN_TEST(test_general_contact_force_agrees_with_the_papers_and_the_batch_with_single_calls);
    RUN_TEST(test_at_rest_the_contact_force_is_the_weight);
}
