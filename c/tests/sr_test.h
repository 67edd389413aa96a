/*
 * sr_test.h -- a tiny test framework and shared helpers for the C tests of the
 * spherical-robot library.  Plain C99, no dependencies.
 *
 * A test is a `void f(void)` that uses the CHECK macros; RUN_TEST(f) runs it
 * and counts it as passed when none of its checks failed.  Every failed check
 * prints file:line and the expression.  sr_test_summary() prints the final line
 * "N passed, M failed" (parsed by tests/test_c_library.py) and returns the exit
 * status.  The same sources are compiled for the double and the float build;
 * tolerances are expressed in units of TEST_EPS, the machine epsilon of sr_real.
 */
#ifndef SR_TEST_H
#define SR_TEST_H

#include <float.h>
#include <stdio.h>

#include "spherical_robot.h"

#ifdef SR_USE_FLOAT
#define TEST_EPS ((double)FLT_EPSILON)
#define TEST_SCALAR_NAME "float"
#else
#define TEST_EPS DBL_EPSILON
#define TEST_SCALAR_NAME "double"
#endif

/* ---- framework --------------------------------------------------------------- */

/* Checks failed so far in the running test (reset by sr_test_run). */
extern int sr_test_current_failures;

void sr_test_fail(const char *file, int line, const char *fmt, ...);
void sr_test_run(const char *name, void (*test)(void));
int sr_test_summary(void);

#define RUN_TEST(fn) sr_test_run(#fn, fn)

#define CHECK(cond)                                                          \
    do {                                                                     \
        if (!(cond)) sr_test_fail(__FILE__, __LINE__, "CHECK(%s)", #cond);   \
    } while (0)

/* expr must return the status code want (both ints). */
#define CHECK_STATUS(expr, want)                                                       \
    do {                                                                               \
        const int got_ = (expr), want_ = (want);                                       \
        if (got_ != want_)                                                             \
            sr_test_fail(__FILE__, __LINE__, "%s returned %d (%s), expected %d (%s)",  \
                         #expr, got_, sr_status_string(got_), want_,                   \
                         sr_status_string(want_));                                     \
    } while (0)

/* |got - want| <= tol, all converted to double. */
#define CHECK_NEAR(got, want, tol)                                                    \
    do {                                                                              \
        const double g_ = (double)(got), w_ = (double)(want), t_ = (double)(tol);     \
        if (!(g_ - w_ <= t_ && w_ - g_ <= t_))                                        \
            sr_test_fail(__FILE__, __LINE__, "%s = %.17g, expected %.17g +- %.3g",    \
                         #got, g_, w_, t_);                                           \
    } while (0)

/* ---- suites (one per test file) -------------------------------------------------- */
void suite_status(void);
void suite_numerics(void);
void suite_buffers(void);
void suite_precision(void);
void suite_guards(void);
void suite_batch(void);
void suite_group(void);
void suite_general(void);
void suite_jacobians(void);
void suite_control(void);
void suite_slope(void);
void suite_trig(void);
void suite_accel_batch(void);
void suite_param_lanes(void);
void suite_step_batch(void);
void suite_model_validity(void);
void suite_sensors(void);
void suite_ekf(void);
void suite_ident(void);
void suite_param_jacobians(void);
void suite_nmpc(void);
void suite_sim(void);

/* ---- shared helpers (sr_test.c) ---------------------------------------------------- */

/* Deterministic random numbers (splitmix64): the tests never depend on libc's rand. */
typedef struct test_rng {
    unsigned long long s;
} test_rng;
double rng_uniform(test_rng *rng, double lo, double hi);

/* Runtime's Params.paper_simulation(): Section 5.2 with the damping doubled, the paper's twelve
 * parameters (SR_PAPER_*) and the general robot they describe (SR_P_*). */
void paper_simulation_paper(sr_real pp[SR_NPAPER]);
void paper_simulation_params(sr_real p[SR_NPARAM]);
/* A robot of none of the paper's special geometry (off-centre masses, full tensors, geared
 * rotors, a 0.1 rad slope), near the paper's: sr_model_init chooses the general kernels. */
void general_robot_params(sr_real p[SR_NPARAM]);
/* Fills *model from paper_simulation_params (checks SR_OK). */
void paper_simulation_model(sr_model *model);
/* R = rotation by theta about x / y / z, row-major. */
void rot_x(double theta, sr_real R[9]);
void rot_y(double theta, sr_real R[9]);
void rot_z(double theta, sr_real R[9]);
/* R_S = I, R_Y = rot_x(theta_Y), R_P = rot_y(theta_P), q = (0, 0, r), at rest. */
void make_state(sr_real x[SR_NX], double theta_Y, double theta_P, double r);
/* A random valid state: uniform-ish R_S, any yoke and pendulum angle, q_z = r,
 * speeds up to max_speed rad/s. */
void random_state(test_rng *rng, double r, double max_speed, sr_real x[SR_NX]);
/* The next representable sr_real above v (a one-ulp change, for checks that must see it). */
sr_real next_up(sr_real v);
/* Largest |A^T A - I| entry and |det A - 1| of a row-major 3x3 matrix. */
double orthonormality_error(const sr_real R[9]);

#endif /* SR_TEST_H */
