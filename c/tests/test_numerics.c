/*
 * test_numerics.c -- the numbers: the SO(3) exponential against its Taylor
 * series, the equilibria, the consistency of M, f and the accelerations,
 * energy conservation without friction, the rolling constraint, and
 * determinism (aliasing, re-entrancy: no hidden state between calls).
 */
#include "sr_test.h"
#include "../src/sr_so3.h" /* dexpinv_series: internal, tested directly */

#include <math.h>
#include <string.h>

/* ---- helpers ------------------------------------------------------------------ */

/* Exp([[w]]) by the Taylor series sum_k [[w]]^k / k!, in double, 60 terms. */
static void exp_taylor(const double w[3], double E[9])
{
    const double W[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
    double term[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1}, next[9];
    int i, j, k, n;
    memcpy(E, term, sizeof term);
    for (n = 1; n < 60; ++n) {
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) {
                double s = 0;
                for (k = 0; k < 3; ++k) s += term[3 * i + k] * W[3 * k + j];
                next[3 * i + j] = s / n;
            }
        memcpy(term, next, sizeof term);
        for (i = 0; i < 9; ++i) E[i] += term[i];
    }
}

static double max_abs(const sr_real *v, int n)
{
    double worst = 0;
    int i;
    for (i = 0; i < n; ++i)
        if (fabs((double)v[i]) > worst) worst = fabs((double)v[i]);
    return worst;
}

static sr_real energy_of(const sr_model *m, const sr_real x[SR_NX])
{
    sr_real E = 0;
    CHECK_STATUS(sr_energy(m, x, &E), SR_OK);
    return E;
}

/* ---- the SO(3) exponential ---------------------------------------------------- */

static void test_so3_exp_matches_taylor_series(void)
{
    /* Angles on both sides of the series branch (|w| < 1e-4) up to nearly pi. */
    const double angles[] = {1e-12, 1e-8, 1e-5, 9.99e-5, 1.001e-4, 1e-3, 0.1, 1.0, 2.0, 3.0, 3.14159};
    const double axes[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.48, -0.6, 0.64}, {-0.36, 0.48, 0.8}};
    int a, b, i;
    for (a = 0; a < (int)(sizeof angles / sizeof angles[0]); ++a)
        for (b = 0; b < (int)(sizeof axes / sizeof axes[0]); ++b) {
            sr_real w[3], R[9];
            double wd[3], E[9];
            for (i = 0; i < 3; ++i) {
                w[i] = (sr_real)(angles[a] * axes[b][i]);
                wd[i] = (double)w[i]; /* the exact input the C sees */
            }
            CHECK_STATUS(sr_so3_exp(w, R), SR_OK);
            exp_taylor(wd, E);
            for (i = 0; i < 9; ++i) CHECK_NEAR(R[i], E[i], 16 * TEST_EPS);
            CHECK(orthonormality_error(R) <= 16 * TEST_EPS);
        }
}

/* sin t and cos t - 1 from sr_so3_exp about one axis, where the series of sin(t)/t and
 * (1 - cos t)/t^2 serve (|t| < 1/4, src/sr_so3.h) and just above, against libm, to a few ulp
 * of each entry (not of 1: cos t - 1 is read as E - I).  The control: the same series without
 * its last two terms misses that bound near t = 1/4, so the check can see a wrong series. */
static void test_so3_exp_small_angle_series_match_libm_to_a_few_ulp(void)
{
    int n, worst_truncated_ok = 1;
    for (n = 1; n <= 300; ++n) {
        const sr_real t = (sr_real)(0.26 * n / 300.0);
        const double td = (double)t, s = sin(td), cm1 = -2 * sin(td / 2) * sin(td / 2);
        sr_real w[3] = {t, 0, 0}, R[9];
        CHECK_STATUS(sr_so3_exp(w, R), SR_OK);
        CHECK_NEAR(R[7], s, 4 * TEST_EPS * fabs(s));
        CHECK_NEAR(R[4] - (sr_real)1, cm1, 4 * TEST_EPS + 4 * TEST_EPS * fabs(cm1));
        if (td > 0.2) { /* truncated: sin t/t = 1 - t^2/6 (1 - t^2/20 (1 - t^2/42)) */
            const double t2 = td * td, truncated = td * (1 - t2 / 6 * (1 - t2 / 20 * (1 - t2 / 42)));
            if (fabs(truncated - s) > 4 * DBL_EPSILON * fabs(s)) worst_truncated_ok = 0;
        }
    }
    CHECK(!worst_truncated_ok); /* the truncated series fails the bound the C passes */
}

/* c(s) = (1 - (t/2) cot(t/2)) / t^2 of dexp^-1 (s = t^2) from the Bernoulli numbers, an
 * independent form of its series: c = sum_{n>=1} (-1)^(n+1) B_2n s^(n-1) / (2n)!, ten terms. */
static double dexpinv_reference(double s, int derivative)
{
    static const double B[11] = {1, 1.0 / 6, -1.0 / 30, 1.0 / 42, -1.0 / 30, 5.0 / 66, -691.0 / 2730, 7.0 / 6,
                                 -3617.0 / 510, 43867.0 / 798, -174611.0 / 330};   /* B_0, B_2, ..., B_20 */
    double sum = 0, factorial = 2;   /* (2n)! */
    int n;
    for (n = 1; n <= 10; ++n) {
        const double coefficient = (n % 2 ? 1 : -1) * B[n] / factorial;
        if (derivative) sum += n >= 2 ? (n - 1) * coefficient * pow(s, n - 2) : 0;
        else sum += coefficient * pow(s, n - 1);
        factorial *= (2 * n + 1) * (2 * n + 2);
    }
    return sum;
}

/* The series of dexp^-1's coefficient and of its derivative (src/sr_so3.h; the fourth-order steps
 * and their Jacobians use them below s = 1/16) equal the Bernoulli form to a few ulp.  The control:
 * a four-term series (enough below s = 1e-2) misses the bound near 1/16. */
static void test_dexpinv_series_match_the_bernoulli_form_to_a_few_ulp(void)
{
    int n, truncated_ok = 1;
    for (n = 0; n < 400; ++n) {
        const sr_real s = (sr_real)(0.0625 * n / 400.0);
        const double sd = (double)s, c = dexpinv_reference(sd, 0), dc = dexpinv_reference(sd, 1);
        const double four_terms = 1.0 / 12 + sd * (1.0 / 720 + sd * (1.0 / 30240 + sd * (1.0 / 1209600)));
        CHECK_NEAR(dexpinv_series(s), c, 2 * TEST_EPS * c);
        CHECK_NEAR(dexpinv_series_derivative(s), dc, 4 * TEST_EPS * dc);
        if (fabs(four_terms - c) > 2 * DBL_EPSILON * c) truncated_ok = 0;
    }
    CHECK(!truncated_ok);
}

static void test_so3_exp_of_zero_is_identity(void)
{
    const sr_real w[3] = {0, 0, 0};
    sr_real R[9];
    int i;
    CHECK_STATUS(sr_so3_exp(w, R), SR_OK);
    for (i = 0; i < 9; ++i) CHECK(R[i] == (i % 4 == 0 ? 1 : 0));
}

static void test_so3_exp_inverse_is_exp_of_minus_w(void)
{
    const sr_real w[3] = {SR_C(0.7), SR_C(-1.1), SR_C(0.4)}, mw[3] = {SR_C(-0.7), SR_C(1.1), SR_C(-0.4)};
    sr_real R[9], Rm[9];
    int i, j, k;
    CHECK_STATUS(sr_so3_exp(w, R), SR_OK);
    CHECK_STATUS(sr_so3_exp(mw, Rm), SR_OK);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            double s = 0;
            for (k = 0; k < 3; ++k) s += (double)R[3 * i + k] * (double)Rm[3 * k + j];
            CHECK_NEAR(s, i == j, 8 * TEST_EPS);
        }
}

/* ---- equilibria ----------------------------------------------------------------- */

static void test_accel_at_identity_equilibrium_is_zero(void)
{
    sr_model m;
    sr_real x[SR_NX], a[SR_NV], res[SR_NV];
    int i;
    paper_simulation_model(&m);
    make_state(x, 0, 0, 0.3);
    CHECK_STATUS(sr_accel(&m, x, NULL, a), SR_OK);
    CHECK_STATUS(sr_equilibrium_residual(&m, x, res), SR_OK);
    for (i = 0; i < SR_NV; ++i) {
        CHECK(a[i] == 0);
        CHECK(res[i] == 0);
    }
    /* Any heading of the shell (R_S about the vertical) is the same equilibrium. */
    rot_z(1.234, x);
    x[SR_X_q] = SR_C(0.5);
    x[SR_X_q + 1] = SR_C(-2.0);
    CHECK_STATUS(sr_accel(&m, x, NULL, a), SR_OK);
    for (i = 0; i < SR_NV; ++i) CHECK(a[i] == 0);
}

/* Eq. (108): at rest, f = 0 whenever R_S R_Y R_P e_z = e_z, e.g. a tilted shell
 * with the yoke tilted back (R_S = rot_x(-t), R_Y = rot_x(t)). */
static void test_tilted_equilibrium_has_zero_residual(void)
{
    sr_model m;
    sr_real x[SR_NX], res[SR_NV], a[SR_NV];
    paper_simulation_model(&m);
    make_state(x, 0.6, 0, 0.3);
    rot_x(-0.6, x);
    CHECK_STATUS(sr_equilibrium_residual(&m, x, res), SR_OK);
    CHECK(max_abs(res, SR_NV) <= 64 * TEST_EPS); /* scale: m_P g l = 2 N m */
    CHECK_STATUS(sr_accel(&m, x, NULL, a), SR_OK);
    CHECK(max_abs(a, SR_NV) <= 256 * TEST_EPS);
    /* ... and not when the pendulum swings out of the vertical. */
    rot_y(0.3, x + SR_X_R_P);
    CHECK_STATUS(sr_equilibrium_residual(&m, x, res), SR_OK);
    CHECK(max_abs(res, SR_NV) > 0.1);
}

/* ---- M, f and the accelerations ------------------------------------------------- */

static void test_inertia_is_symmetric_positive_definite_and_solves_for_accel(void)
{
    test_rng rng = {20241122ULL};
    sr_model m;
    sr_real x[SR_NX], u[SR_NU], M[SR_NV * SR_NV], f[SR_NV], a[SR_NV];
    int trial, i, j, k;
    paper_simulation_model(&m);
    for (trial = 0; trial < 50; ++trial) {
        double L[SR_NV * SR_NV] = {0}, scale = 0;
        random_state(&rng, 0.3, 3.0, x);
        u[0] = (sr_real)rng_uniform(&rng, -0.5, 0.5);
        u[1] = (sr_real)rng_uniform(&rng, -0.5, 0.5);
        CHECK_STATUS(sr_inertia(&m, x, M), SR_OK);
        CHECK_STATUS(sr_rhs(&m, x, u, f), SR_OK);
        CHECK_STATUS(sr_accel(&m, x, u, a), SR_OK);
        for (i = 0; i < SR_NV; ++i)
            for (j = 0; j < SR_NV; ++j) CHECK(M[SR_NV * i + j] == M[SR_NV * j + i]);
        /* Cholesky in double: every pivot positive. */
        for (j = 0; j < SR_NV; ++j) {
            double d = (double)M[SR_NV * j + j];
            for (k = 0; k < j; ++k) d -= L[SR_NV * j + k] * L[SR_NV * j + k];
            CHECK(d > 0);
            if (!(d > 0)) break;
            L[SR_NV * j + j] = sqrt(d);
            for (i = j + 1; i < SR_NV; ++i) {
                double s = (double)M[SR_NV * i + j];
                for (k = 0; k < j; ++k) s -= L[SR_NV * i + k] * L[SR_NV * j + k];
                L[SR_NV * i + j] = s / L[SR_NV * j + j];
            }
        }
        /* M a = f to working precision. */
        for (i = 0; i < SR_NV; ++i) {
            double s = 0;
            for (j = 0; j < SR_NV; ++j) s += fabs((double)M[SR_NV * i + j] * (double)a[j]);
            if (s + fabs((double)f[i]) > scale) scale = s + fabs((double)f[i]);
        }
        for (i = 0; i < SR_NV; ++i) {
            double s = -(double)f[i];
            for (j = 0; j < SR_NV; ++j) s += (double)M[SR_NV * i + j] * (double)a[j];
            CHECK(fabs(s) <= 256 * TEST_EPS * scale);
        }
    }
}

static void test_kinetic_energy_is_half_nu_M_nu(void)
{
    test_rng rng = {7ULL};
    sr_model m;
    sr_real x[SR_NX], rest[SR_NX], M[SR_NV * SR_NV];
    int trial, i, j;
    paper_simulation_model(&m);
    for (trial = 0; trial < 20; ++trial) {
        double T = 0;
        random_state(&rng, 0.3, 3.0, x);
        memcpy(rest, x, sizeof x);
        for (i = 30; i < SR_NX; ++i) rest[i] = 0;
        CHECK_STATUS(sr_inertia(&m, x, M), SR_OK);
        for (i = 0; i < SR_NV; ++i)
            for (j = 0; j < SR_NV; ++j) T += 0.5 * (double)x[SR_X_w_S + i] * (double)M[SR_NV * i + j] * (double)x[SR_X_w_S + j];
        CHECK(T > 0);
        CHECK_NEAR(energy_of(&m, x) - energy_of(&m, rest), T, 64 * TEST_EPS * (T + 5));
    }
}

static void test_motor_torques_enter_f_with_unit_coefficients(void)
{
    test_rng rng = {11ULL};
    sr_model m;
    sr_real x[SR_NX], u[SR_NU] = {SR_C(0.3), SR_C(-0.2)}, f0[SR_NV], fu[SR_NV];
    int i;
    paper_simulation_model(&m);
    random_state(&rng, 0.3, 2.0, x);
    CHECK_STATUS(sr_rhs(&m, x, NULL, f0), SR_OK);
    CHECK_STATUS(sr_rhs(&m, x, u, fu), SR_OK);
    for (i = 0; i < 3; ++i) CHECK_NEAR(fu[i], f0[i], 16 * TEST_EPS * (1 + fabs((double)f0[i])));
    CHECK_NEAR(fu[3] - f0[3], u[0], 16 * TEST_EPS * (1 + fabs((double)f0[3])));
    CHECK_NEAR(fu[4] - f0[4], u[1], 16 * TEST_EPS * (1 + fabs((double)f0[4])));
}

/* ---- time stepping -------------------------------------------------------------- */

/* Energy drift of a frictionless, unforced Lie-Euler run of 1 s with step dt. */
static double frictionless_drift(double dt, double *E0)
{
    sr_model m;
    sr_real p[SR_NPARAM], x[SR_NX];
    const long steps = (long)(1.0 / dt + 0.5);
    long n;
    paper_simulation_params(p);
    p[SR_P_k_S] = p[SR_P_k_Y] = p[SR_P_k_P] = 0; /* k_S = k_Y = k_P = 0 */
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    make_state(x, 0.3, 0.5, 0.3);
    x[SR_X_w_S] = SR_C(0.4);
    x[SR_X_w_S + 1] = SR_C(-0.3);
    x[SR_X_w_S + 2] = SR_C(0.2);
    x[SR_X_w_Y] = SR_C(0.8);
    x[SR_X_w_P] = SR_C(-0.5);
    *E0 = (double)energy_of(&m, x);
    for (n = 0; n < steps; ++n) CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, NULL, (sr_real)dt, x), SR_OK);
    return (double)energy_of(&m, x) - *E0;
}

static void test_energy_is_conserved_without_friction_to_first_order(void)
{
    double E0, d1 = frictionless_drift(1e-3, &E0), d2 = frictionless_drift(5e-4, &E0);
    /* Lie-Euler is first order: the drift is O(dt) (about 0.4 % of E here) and halves with dt. */
    CHECK(fabs(d1) <= 5e-3 * fabs(E0));
    CHECK(d1 / d2 > 1.8 && d1 / d2 < 2.2);
}

static void test_friction_dissipates_energy(void)
{
    sr_model m;
    sr_real x[SR_NX];
    double E0;
    int n;
    paper_simulation_model(&m);
    make_state(x, 0.0, 0.8, 0.3);
    x[SR_X_w_S] = SR_C(1.0);
    x[SR_X_w_Y] = SR_C(2.0);
    E0 = (double)energy_of(&m, x);
    for (n = 0; n < 500; ++n) CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, NULL, SR_C(0.01), x), SR_OK);
    CHECK((double)energy_of(&m, x) < E0 - 0.01);
}

static void test_rolling_keeps_the_centre_at_height_r_and_rotations_orthonormal(void)
{
    test_rng rng = {3ULL};
    sr_model m;
    sr_real x[SR_NX], u[SR_NU] = {SR_C(0.1), SR_C(-0.1)};
    int n;
    paper_simulation_model(&m);
    random_state(&rng, 0.3, 2.0, x);
    for (n = 0; n < 2000; ++n) CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u, SR_C(0.01), x), SR_OK);
    CHECK_NEAR(x[SR_X_q + 2], 0.3, 1e3 * TEST_EPS);
    CHECK(orthonormality_error(x) <= 1e3 * TEST_EPS);
    CHECK(orthonormality_error(x + SR_X_R_Y) <= 1e3 * TEST_EPS);
    CHECK(orthonormality_error(x + SR_X_R_P) <= 1e3 * TEST_EPS);
    CHECK_STATUS(sr_check_state(&m, x), SR_OK);
}

static void test_step_in_place_equals_step_out_of_place(void)
{
    test_rng rng = {5ULL};
    sr_model m;
    sr_real x[SR_NX], y[SR_NX], u[SR_NU] = {SR_C(0.1), SR_C(0.05)};
    paper_simulation_model(&m);
    random_state(&rng, 0.3, 2.0, x);
    CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u, SR_C(0.01), y), SR_OK);
    CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u, SR_C(0.01), x), SR_OK);
    CHECK(memcmp(x, y, sizeof x) == 0);
}

typedef int (*fixed_method_step)(const sr_model *, const sr_real *, const sr_real *, sr_real, sr_real *);

/* sr_step_lie_euler, sr_step_rkmk4 and sr_step_cf4 are sr_step with the method fixed: the same
 * bits on valid input, the same status on invalid input; and the three methods differ. */
static void test_per_method_steps_equal_sr_step(void)
{
    const int methods[3] = {SR_LIE_EULER, SR_RKMK4, SR_CF4};
    const fixed_method_step steps[3] = {sr_step_lie_euler, sr_step_rkmk4, sr_step_cf4};
    test_rng rng = {17ULL};
    sr_model m;
    sr_real x[SR_NX], bad[SR_NX], want[3][SR_NX], got[SR_NX], u[SR_NU] = {SR_C(0.1), SR_C(-0.05)};
    int k;
    paper_simulation_model(&m);
    random_state(&rng, 0.3, 2.0, x);
    for (k = 0; k < 3; ++k) {
        CHECK_STATUS(sr_step(&m, methods[k], x, u, SR_C(0.01), want[k]), SR_OK);
        CHECK_STATUS(steps[k](&m, x, u, SR_C(0.01), got), SR_OK);
        CHECK(memcmp(got, want[k], sizeof got) == 0);
        CHECK_STATUS(steps[k](&m, x, NULL, SR_C(0.01), got), SR_OK); /* NULL: zero torque */
        CHECK_STATUS(sr_step(&m, methods[k], x, NULL, SR_C(0.01), want[k]), SR_OK);
        CHECK(memcmp(got, want[k], sizeof got) == 0);
        memcpy(got, x, sizeof got); /* in place */
        CHECK_STATUS(steps[k](&m, got, NULL, SR_C(0.01), got), SR_OK);
        CHECK(memcmp(got, want[k], sizeof got) == 0);
        memcpy(bad, x, sizeof bad);
        bad[SR_X_w_S] = (sr_real)NAN;
        CHECK_STATUS(steps[k](&m, bad, u, SR_C(0.01), got), SR_ERR_NONFINITE);
        CHECK_STATUS(steps[k](&m, x, u, SR_C(0.0), got), SR_ERR_ARG);
        CHECK_STATUS(steps[k](&m, x, u, SR_C(0.01), NULL), SR_ERR_NULL);
        CHECK_STATUS(steps[k](NULL, x, u, SR_C(0.01), got), SR_ERR_NULL);
    }
    /* The three entry points are three methods: at dt = 0.25 s their results differ even in float
     * (at 0.01 s RKMK4 and CF4 differ by O(dt^5), which float rounding can hide). */
    for (k = 0; k < 3; ++k) CHECK_STATUS(steps[k](&m, x, u, SR_C(0.25), want[k]), SR_OK);
    CHECK(memcmp(want[0], want[1], sizeof want[0]) != 0);
    CHECK(memcmp(want[1], want[2], sizeof want[1]) != 0);
}

static void test_simulate_equals_repeated_steps(void)
{
    enum { STEPS = 50 };
    test_rng rng = {9ULL};
    sr_model m;
    sr_real x[SR_NX], u[STEPS * SR_NU], traj[(STEPS + 1) * SR_NX];
    long done = -1;
    int n;
    paper_simulation_model(&m);
    random_state(&rng, 0.3, 2.0, x);
    for (n = 0; n < STEPS * SR_NU; ++n) u[n] = (sr_real)rng_uniform(&rng, -0.2, 0.2);
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), STEPS, u, traj, &done), SR_OK);
    CHECK(done == STEPS);
    CHECK(memcmp(traj, x, sizeof x) == 0);
    for (n = 0; n < STEPS; ++n) {
        CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u + n * SR_NU, SR_C(0.01), x), SR_OK);
        CHECK(memcmp(traj + (n + 1) * SR_NX, x, sizeof x) == 0);
    }
}

/* Two models interleaved give the same bits as each run alone: no state survives a call. */
static void test_interleaved_models_do_not_interfere(void)
{
    sr_model m1, m2;
    sr_real p[SR_NPARAM], x1[SR_NX], x2[SR_NX], y1[SR_NX], y2[SR_NX];
    const sr_real u[SR_NU] = {SR_C(0.1), SR_C(-0.1)};
    int n;
    paper_simulation_model(&m1);
    paper_simulation_params(p);
    p[SR_P_m_P] = SR_C(3.0); /* a heavier pendulum */
    p[SR_P_k_S] = 0;
    CHECK_STATUS(sr_model_init(&m2, p), SR_OK);
    make_state(x1, 0.1, 0.2, 0.3);
    memcpy(x2, x1, sizeof x1);
    memcpy(y1, x1, sizeof x1);
    memcpy(y2, x1, sizeof x1);
    for (n = 0; n < 100; ++n) CHECK_STATUS(sr_step(&m1, SR_LIE_EULER, y1, u, SR_C(0.01), y1), SR_OK);
    for (n = 0; n < 100; ++n) CHECK_STATUS(sr_step(&m2, SR_LIE_EULER, y2, u, SR_C(0.01), y2), SR_OK);
    for (n = 0; n < 100; ++n) {
        CHECK_STATUS(sr_step(&m1, SR_LIE_EULER, x1, u, SR_C(0.01), x1), SR_OK);
        CHECK_STATUS(sr_step(&m2, SR_LIE_EULER, x2, u, SR_C(0.01), x2), SR_OK);
    }
    CHECK(memcmp(x1, y1, sizeof x1) == 0);
    CHECK(memcmp(x2, y2, sizeof x2) == 0);
    CHECK(memcmp(x1, x2, sizeof x1) != 0);
}

void suite_numerics(void)
{
    RUN_TEST(test_so3_exp_matches_taylor_series);
    RUN_TEST(test_so3_exp_small_angle_series_match_libm_to_a_few_ulp);
    RUN_TEST(test_dexpinv_series_match_the_bernoulli_form_to_a_few_ulp);
    RUN_TEST(test_so3_exp_of_zero_is_identity);
    RUN_TEST(test_so3_exp_inverse_is_exp_of_minus_w);
    RUN_TEST(test_accel_at_identity_equilibrium_is_zero);
    RUN_TEST(test_tilted_equilibrium_has_zero_residual);
    RUN_TEST(test_inertia_is_symmetric_positive_definite_and_solves_for_accel);
    RUN_TEST(test_kinetic_energy_is_half_nu_M_nu);
    RUN_TEST(test_motor_torques_enter_f_with_unit_coefficients);
    RUN_TEST(test_energy_is_conserved_without_friction_to_first_order);
    RUN_TEST(test_friction_dissipates_energy);
    RUN_TEST(test_rolling_keeps_the_centre_at_height_r_and_rotations_orthonormal);
    RUN_TEST(test_step_in_place_equals_step_out_of_place);
    RUN_TEST(test_per_method_steps_equal_sr_step);
    RUN_TEST(test_simulate_equals_repeated_steps);
    RUN_TEST(test_interleaved_models_do_not_interfere);
}
