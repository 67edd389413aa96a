/*
 * test_trig.c -- the float build's own sine and cosine (c/src/sr_trig.c) against double libm: within
 * 2^-23 on a dense grid of |x| <= 8192 rad, within |x| 2^-23 up to 2^24 rad, NaN beyond.  In
 * the double build (and with -DSR_LIBM_TRIG) the library uses libm and there is nothing to test.
 */
#include "sr_test.h"

#include <math.h>

#if defined(SR_USE_FLOAT) && !defined(SR_LIBM_TRIG)

/* Under emulation (cross/cross_test.sh builds the tests with -DSR_TEST_EMULATED) every 20th point of
 * each grid: on the Cortex-M4F the double reference is software arithmetic, and the whole grids take
 * minutes under QEMU; the host build checks every point.  A point is computed from i and n alone, so
 * the emulated grid is a subset of the host's. */
#ifdef SR_TEST_EMULATED
#define GRID_STRIDE 20
#else
#define GRID_STRIDE 1
#endif

/* Largest |f(x) - ref(x)| over n points evenly spread on [lo, hi] (x rounded to float first; n a
 * multiple of GRID_STRIDE). */
static double worst_error(float (*f)(float), double (*ref)(double), double lo, double hi, long n, double scale_by_x)
{
    double worst = 0;
    long i;
    for (i = 0; i <= n; i += GRID_STRIDE) {
        const float x = (float)(lo + (hi - lo) * (double)i / (double)n);
        double e = fabs((double)f(x) - ref((double)x));
        if (scale_by_x) e /= fabs((double)x);
        if (e > worst) worst = e;
    }
    return worst;
}

static void test_own_sin_and_cos_are_within_2_to_the_minus_23_up_to_8192_rad(void)
{
    const double bound = 8e-8; /* measured 7.7e-8; 2^-23 = 1.2e-7 is the documented bound */
    /* Fine near the library's usual angles (a few radians), then the whole exact range. */
    CHECK(worst_error(sr_internal_sinf, sin, -8.0, 8.0, 400000, 0) <= bound);
    CHECK(worst_error(sr_internal_cosf, cos, -8.0, 8.0, 400000, 0) <= bound);
    CHECK(worst_error(sr_internal_sinf, sin, -8192.0, 8192.0, 2000000, 0) <= bound);
    CHECK(worst_error(sr_internal_cosf, cos, -8192.0, 8192.0, 2000000, 0) <= bound);
}

static void test_own_sin_and_cos_are_exact_at_the_octant_boundaries_to_a_rounding(void)
{
    int k;
    for (k = -16; k <= 16; ++k) {
        const float x = (float)(k * 0.78539816339744830962);
        CHECK_NEAR(sr_internal_sinf(x), sin((double)x), ldexp(1.0, -23));
        CHECK_NEAR(sr_internal_cosf(x), cos((double)x), ldexp(1.0, -23));
    }
    CHECK(sr_internal_sinf(0.0f) == 0.0f && sr_internal_cosf(0.0f) == 1.0f);
    CHECK(sr_internal_sinf(-1e-20f) == -1e-20f);
}

static void test_beyond_8192_rad_the_error_grows_as_the_arguments_own_rounding(void)
{
    CHECK(worst_error(sr_internal_sinf, sin, 8192.0, 16777216.0, 1000000, 1) <= ldexp(1.0, -23));
    CHECK(worst_error(sr_internal_cosf, cos, 8192.0, 16777216.0, 1000000, 1) <= ldexp(1.0, -23));
}

static void test_arguments_beyond_2_to_the_24_infinities_and_nan_give_nan(void)
{
    CHECK(isnan(sr_internal_sinf(3e7f)) && isnan(sr_internal_cosf(-3e7f)));
    CHECK(isnan(sr_internal_sinf((float)INFINITY)) && isnan(sr_internal_cosf((float)-INFINITY)));
    CHECK(isnan(sr_internal_sinf((float)NAN)) && isnan(sr_internal_cosf((float)NAN)));
}

void suite_trig(void)
{
    RUN_TEST(test_own_sin_and_cos_are_within_2_to_the_minus_23_up_to_8192_rad);
    RUN_TEST(test_own_sin_and_cos_are_exact_at_the_octant_boundaries_to_a_rounding);
    RUN_TEST(test_beyond_8192_rad_the_error_grows_as_the_arguments_own_rounding);
    RUN_TEST(test_arguments_beyond_2_to_the_24_infinities_and_nan_give_nan);
}

#else

void suite_trig(void) {}

#endif
