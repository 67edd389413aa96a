/*
 * test_precision.c -- the scalar type of this build, and a sanity check of the
 * whole chain (parameters, kernels, stepper) against a recorded double-precision
 * trajectory.  Compiled into both test programs: the double build must reproduce
 * the recording to 1e-10 (differences only from the platform's libm), the float
 * build to 1e-4 (about 20 times the float error measured in docs/embedding.md).
 *
 * The recording is the t-shape scenario of examples/firmware_tshape.c after
 * 2000 steps (t = 20 s, after the first yoke window and the first pendulum
 * window).  If the model changes on purpose, regenerate it with
 *     make -C c example && c/build/firmware_tshape | sed -n 2002p
 * (the row's first entry is t; the 35 state entries follow).
 */
#include "sr_test.h"

#include <math.h>

static const double TSHAPE_STATE_AT_20S[SR_NX] = {
    0.957371015254879, 0.062144883114095384, -0.28209706246712707,
    -0.01265505683926278, -0.96662267442574279, -0.2558914903282527,
    -0.28858376372596078, 0.24855305025035349, -0.92463008415528136,
    1, 0, 0, 0, -0.96977621491435739, 0.24399609215391055, 0, -0.24399609215391055, -0.96977621491435739,
    0.96030429809522266, 0, -0.27895457526243356, 0, 1, 0, 0.27895457526243356, 0, 0.96030429809522266,
    0.088107359902164728, 1.0199579422606517, 0.29999999999999999,
    -0.074665732773757876, -0.10667203542410611, -0.014676572639108055,
    -0.010773545899652945, -0.080132573952602468,
};

#ifdef SR_USE_FLOAT
#define TRAJECTORY_TOL 1e-4
#else
#define TRAJECTORY_TOL 1e-10
#endif

static void test_scalar_type_matches_the_build(void)
{
#ifdef SR_USE_FLOAT
    CHECK(sizeof(sr_real) == sizeof(float));
#else
    CHECK(sizeof(sr_real) == sizeof(double));
#endif
    CHECK(sizeof(SR_C(0.1)) == sizeof(sr_real));
    CHECK(sizeof(sr_model) >= (SR_NPARAM + SR_GEN_NCONST + SR_GEN_GENERAL_NCONST) * sizeof(sr_real));
    /* The rotation tolerance must sit well above rounding and well below real errors. */
    CHECK((double)SR_ROTATION_TOL >= 1000 * TEST_EPS && (double)SR_ROTATION_TOL <= 1e-2);
}

/* The t-shape torque program over its first 2000 steps: yoke +0.1 N m on steps
 * 1-800, pendulum -0.1 N m on steps 1600-1900 (the full table is in the example). */
static void test_tshape_first_20_seconds_match_the_double_recording(void)
{
    sr_model m;
    sr_real x[SR_NX];
    long n;
    int i;
    paper_simulation_model(&m);
    make_state(x, 0, 0, 0.3);
    for (n = 1; n <= 2000; ++n) {
        sr_real u[SR_NU] = {0, 0};
        if (n <= 800) u[0] = SR_C(0.1);
        if (n >= 1600 && n <= 1900) u[1] = SR_C(-0.1);
        CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u, SR_C(0.01), x), SR_OK);
    }
    CHECK_STATUS(sr_check_state(&m, x), SR_OK);
    for (i = 0; i < SR_NX; ++i) CHECK_NEAR(x[i], TSHAPE_STATE_AT_20S[i], TRAJECTORY_TOL);
}

void suite_precision(void)
{
    RUN_TEST(test_scalar_type_matches_the_build);
    RUN_TEST(test_tshape_first_20_seconds_match_the_double_recording);
}
