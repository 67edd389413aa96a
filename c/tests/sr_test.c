/* sr_test.c -- the test runner (main), the framework's counters and the shared helpers. */
#include "sr_test.h"

#include <math.h>
#include <stdarg.h>

int sr_test_current_failures = 0;
static int tests_passed = 0, tests_failed = 0;

void sr_test_fail(const char *file, int line, const char *fmt, ...)
{
    va_list args;
    ++sr_test_current_failures;
    fprintf(stderr, "%s:%d: ", file, line);
    va_start(args, fmt);
    vfprintf(stderr, fmt, args);
    va_end(args);
    fputc('\n', stderr);
}

void sr_test_run(const char *name, void (*test)(void))
{
    sr_test_current_failures = 0;
    test();
    if (sr_test_current_failures == 0) {
        ++tests_passed;
    } else {
        ++tests_failed;
        fprintf(stderr, "FAILED %s (%d failed checks)\n", name, sr_test_current_failures);
    }
}

int sr_test_summary(void)
{
    printf("%d passed, %d failed\n", tests_passed, tests_failed);
    return tests_failed == 0 ? 0 : 1;
}

int main(void)
{
    printf("spherical-robot C tests, sr_real = %s\n", TEST_SCALAR_NAME);
    suite_status();
    suite_numerics();
    suite_buffers();
    suite_precision();
    suite_guards();
    suite_batch();
    suite_group();
    suite_general();
    suite_jacobians();
    suite_control();
    suite_slope();
    suite_trig();
    suite_accel_batch();
    suite_param_lanes();
    suite_step_batch();
    suite_model_validity();
    suite_sensors();
    suite_ekf();
    suite_param_jacobians();
    suite_nmpc();
    suite_sim();
    suite_ident();
    return sr_test_summary();
}

/* ---- helpers -------------------------------------------------------------------- */

double rng_uniform(test_rng *rng, double lo, double hi)
{
    unsigned long long z = (rng->s += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return lo + (hi - lo) * ((double)(z >> 11) * (1.0 / 9007199254740992.0));
}

void paper_simulation_paper(sr_real pp[SR_NPAPER])
{
    const sr_real values[SR_NPAPER] = {
        [SR_PAPER_r] = SR_C(0.3), [SR_PAPER_m_S] = SR_C(2.0), [SR_PAPER_k_S] = SR_C(0.16), [SR_PAPER_b] = SR_C(0.2),
        [SR_PAPER_h] = SR_C(0.5), [SR_PAPER_m_b] = SR_C(2.0), [SR_PAPER_m_h] = SR_C(5.0), [SR_PAPER_k_Y] = SR_C(0.04),
        [SR_PAPER_l] = SR_C(0.2), [SR_PAPER_m_P] = SR_C(1.0), [SR_PAPER_k_P] = SR_C(0.10), [SR_PAPER_g] = SR_C(9.81)};
    int i;
    for (i = 0; i < SR_NPAPER; ++i) pp[i] = values[i];
}

void paper_simulation_params(sr_real p[SR_NPARAM])
{
    sr_real pp[SR_NPAPER];
    paper_simulation_paper(pp);
    CHECK_STATUS(sr_paper_params(pp, p), SR_OK);
}

void general_robot_params(sr_real p[SR_NPARAM])
{
    paper_simulation_params(p);
    p[SR_P_c_Y_x] = SR_C(0.01), p[SR_P_c_Y_y] = SR_C(-0.02), p[SR_P_c_Y_z] = SR_C(0.03);
    p[SR_P_J_Y_xx] = SR_C(0.2), p[SR_P_J_Y_yy] = SR_C(0.5), p[SR_P_J_Y_zz] = SR_C(0.6);
    p[SR_P_J_Y_xy] = SR_C(0.01), p[SR_P_J_Y_xz] = SR_C(0.02), p[SR_P_J_Y_yz] = SR_C(-0.03);
    p[SR_P_c_P_x] = SR_C(0.02), p[SR_P_c_P_y] = SR_C(0.01);
    p[SR_P_J_P_xx] = SR_C(0.004), p[SR_P_J_P_yy] = SR_C(0.0035), p[SR_P_J_P_zz] = SR_C(0.0015);
    p[SR_P_J_P_xy] = SR_C(0.0005), p[SR_P_J_P_xz] = SR_C(0.0002), p[SR_P_J_P_yz] = SR_C(0.0001);
    p[SR_P_j_mY] = SR_C(0.01), p[SR_P_n_Y] = SR_C(20.0), p[SR_P_j_mP] = SR_C(0.005), p[SR_P_n_P] = SR_C(-15.0);
    p[SR_P_slope] = SR_C(0.1);
}

void paper_simulation_model(sr_model *model)
{
    sr_real p[SR_NPARAM];
    paper_simulation_params(p);
    CHECK_STATUS(sr_model_init(model, p), SR_OK);
}

static void set3(sr_real R[9], double a, double b, double c, double d, double e, double f,
                 double g, double h, double i)
{
    R[0] = (sr_real)a; R[1] = (sr_real)b; R[2] = (sr_real)c;
    R[3] = (sr_real)d; R[4] = (sr_real)e; R[5] = (sr_real)f;
    R[6] = (sr_real)g; R[7] = (sr_real)h; R[8] = (sr_real)i;
}

void rot_x(double t, sr_real R[9]) { set3(R, 1, 0, 0, 0, cos(t), -sin(t), 0, sin(t), cos(t)); }
void rot_y(double t, sr_real R[9]) { set3(R, cos(t), 0, sin(t), 0, 1, 0, -sin(t), 0, cos(t)); }
void rot_z(double t, sr_real R[9]) { set3(R, cos(t), -sin(t), 0, sin(t), cos(t), 0, 0, 0, 1); }

void make_state(sr_real x[SR_NX], double theta_Y, double theta_P, double r)
{
    int i;
    for (i = 0; i < SR_NX; ++i) x[i] = 0;
    rot_z(0.0, x + SR_X_R_S);
    rot_x(theta_Y, x + SR_X_R_Y);
    rot_y(theta_P, x + SR_X_R_P);
    x[SR_X_q + 2] = (sr_real)r;
}

void random_state(test_rng *rng, double r, double max_speed, sr_real x[SR_NX])
{
    sr_real w[3];
    int i;
    make_state(x, rng_uniform(rng, -3.14159, 3.14159), rng_uniform(rng, -3.14159, 3.14159), r);
    for (i = 0; i < 3; ++i) w[i] = (sr_real)rng_uniform(rng, -1.8, 1.8); /* |w| up to ~pi */
    CHECK_STATUS(sr_so3_exp(w, x), SR_OK);
    x[SR_X_q] = (sr_real)rng_uniform(rng, -1, 1);
    x[SR_X_q + 1] = (sr_real)rng_uniform(rng, -1, 1);
    for (i = SR_X_w_S; i < SR_NX; ++i) x[i] = (sr_real)rng_uniform(rng, -max_speed, max_speed);
}

sr_real next_up(sr_real v)
{
#ifdef SR_USE_FLOAT
    return nextafterf(v, INFINITY);
#else
    return nextafter(v, INFINITY);
#endif
}

double orthonormality_error(const sr_real R[9])
{
    double worst = 0, det;
    int i, j, k;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            double dot = 0;
            for (k = 0; k < 3; ++k) dot += (double)R[3 * k + i] * (double)R[3 * k + j];
            dot -= (i == j);
            if (fabs(dot) > worst) worst = fabs(dot);
        }
    det = (double)R[0] * ((double)R[4] * R[8] - (double)R[5] * R[7])
        - (double)R[1] * ((double)R[3] * R[8] - (double)R[5] * R[6])
        + (double)R[2] * ((double)R[3] * R[7] - (double)R[4] * R[6]);
    return fabs(det - 1) > worst ? fabs(det - 1) : worst;
}
