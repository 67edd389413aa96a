/*
 * test_trig.c -- the library's own trigonometry (c/src/sr_trig.c) against libm.  Double: sine and
 * cosine within 1 ulp of libm's on dense grids up to SR_TRIG_DOUBLE_MAX_ARG, NaN beyond; atan2
 * within 2 ulp, with C99's values at zeros and infinities.  Float: sine and cosine within 2^-23 of
 * double libm on a dense grid of |x| <= 8192 rad, within |x| 2^-23 up to 2^24 rad, NaN beyond.
 * With -DSR_LIBM_TRIG the library uses libm and there is nothing to test.  On the emulated parts
 * the reference is newlib's libm, on the host glibc's.
 */
#include "sr_test.h"

#include <math.h>

/* Under emulation (cross/cross_test.sh builds the tests with -DSR_TEST_EMULATED) every 20th point of
 * each grid: on the Cortex-M4F the double reference is software arithmetic, and the whole grids take
 * minutes under QEMU; the host build checks every point.  A point is computed from i and n alone, so
 * the emulated grid is a subset of the host's. */
#ifdef SR_TEST_EMULATED
#define GRID_STRIDE 20
#else
#define GRID_STRIDE 1
#endif

#if !defined(SR_USE_FLOAT) && !defined(SR_LIBM_TRIG)

#include "../src/sr_math.h" /* SR_TRIG_DOUBLE_MAX_ARG */

/* |a - ref| in units in the last place of ref (of the smallest normal for a subnormal ref). */
static double ulps(double a, double ref)
{
    int e;
    if (a == ref) return 0;
    if (ref != ref || a != a) return HUGE_VAL;
    (void)frexp(ref == 0 ? DBL_MIN : ref, &e);
    return fabs(a - ref) / ldexp(1.0, (e < DBL_MIN_EXP ? DBL_MIN_EXP : e) - DBL_MANT_DIG);
}

/* Largest error in ulp of f against ref over n + 1 points evenly spread on [lo, hi], or, with
 * log_spaced, over [2^lo, 2^hi] with exponents evenly spread (n a multiple of GRID_STRIDE). */
static double worst_ulps(double (*f)(double), double (*ref)(double), double lo, double hi, long n, int log_spaced)
{
    double worst = 0;
    long i;
    for (i = 0; i <= n; i += GRID_STRIDE) {
        const double t = lo + (hi - lo) * (double)i / (double)n, x = log_spaced ? pow(2.0, t) : t;
        const double e = ulps(f(x), ref(x));
        if (!(e <= worst)) worst = e;
    }
    return worst;
}

static void test_own_double_sin_and_cos_are_within_one_ulp_of_libm_up_to_their_range(void)
{
    /* Fine near the library's usual angles, then the whole range, then small arguments. */
    CHECK(worst_ulps(sr_internal_sin, sin, -8.0, 8.0, 400000, 0) <= 1.0);
    CHECK(worst_ulps(sr_internal_cos, cos, -8.0, 8.0, 400000, 0) <= 1.0);
    CHECK(worst_ulps(sr_internal_sin, sin, -SR_TRIG_DOUBLE_MAX_ARG, SR_TRIG_DOUBLE_MAX_ARG, 200000, 0) <= 1.0);
    CHECK(worst_ulps(sr_internal_cos, cos, -SR_TRIG_DOUBLE_MAX_ARG, SR_TRIG_DOUBLE_MAX_ARG, 200000, 0) <= 1.0);
    CHECK(worst_ulps(sr_internal_sin, sin, -40.0, 0.0, 100000, 1) <= 1.0);
    CHECK(worst_ulps(sr_internal_cos, cos, -40.0, 0.0, 100000, 1) <= 1.0);
}

static void test_own_double_sin_and_cos_are_within_one_ulp_at_the_quadrant_boundaries(void)
{
    /* Where the reduction cancels most: the doubles nearest multiples of pi/2, far out too. */
    long k;
    for (k = -64; k <= 64; ++k) {
        const double x = (double)k * 1.57079632679489661923, far = (double)(k * 16381) * 1.57079632679489661923;
        CHECK(ulps(sr_internal_sin(x), sin(x)) <= 1.0 && ulps(sr_internal_cos(x), cos(x)) <= 1.0);
        CHECK(ulps(sr_internal_sin(far), sin(far)) <= 1.0 && ulps(sr_internal_cos(far), cos(far)) <= 1.0);
    }
    CHECK(sr_internal_sin(0.0) == 0.0 && !signbit(sr_internal_sin(0.0)) && signbit(sr_internal_sin(-0.0)));
    CHECK(sr_internal_cos(0.0) == 1.0 && sr_internal_cos(-0.0) == 1.0 && sr_internal_sin(-1e-300) == -1e-300);
}

static void test_own_double_sin_and_cos_give_nan_beyond_their_range_and_for_infinities_and_nan(void)
{
    CHECK(isnan(sr_internal_sin(1.7e6)) && isnan(sr_internal_cos(-1.7e6)));
    CHECK(isnan(sr_internal_sin(HUGE_VAL)) && isnan(sr_internal_cos(-HUGE_VAL)));
    CHECK(isnan(sr_internal_sin(NAN)) && isnan(sr_internal_cos(NAN)));
}

static void test_own_atan2_is_within_two_ulp_of_libm_in_every_quadrant(void)
{
    /* Directions on circles of radii from 1e-8 to 1e8 (the quotient y/x spans every size). */
    double worst = 0;
    long i, j;
    for (j = -8; j <= 8; ++j) {
        const double r = pow(10.0, (double)j);
        for (i = 0; i < 40000; i += GRID_STRIDE) {
            const double a = 6.28318530717958647692 * ((double)i + 0.37) / 40000.0, y = r * sin(a), x = r * cos(a);
            const double e = ulps(sr_internal_atan2(y, x), atan2(y, x));
            if (!(e <= worst)) worst = e;
        }
    }
    CHECK(worst <= 2.0);
    CHECK(ulps(sr_internal_atan2(1e300, 1e-300), atan2(1e300, 1e-300)) <= 2.0);
    CHECK(ulps(sr_internal_atan2(-1e-300, -1e300), atan2(-1e-300, -1e300)) <= 2.0);
}

static void test_own_atan2_gives_c99s_values_at_zeros_infinities_and_nan(void)
{
    const double pi = 3.14159265358979311600, inf = HUGE_VAL;
    CHECK(sr_internal_atan2(0.0, 1.0) == 0.0 && !signbit(sr_internal_atan2(0.0, 1.0)));
    CHECK(sr_internal_atan2(-0.0, 0.0) == 0.0 && signbit(sr_internal_atan2(-0.0, 0.0)));
    CHECK(sr_internal_atan2(0.0, -0.0) == pi && sr_internal_atan2(-0.0, -1.0) == -pi);
    CHECK(sr_internal_atan2(1.0, 0.0) == pi / 2 && sr_internal_atan2(-1.0, -0.0) == -pi / 2);
    CHECK(sr_internal_atan2(inf, inf) == atan2(inf, inf) && sr_internal_atan2(-inf, -inf) == atan2(-inf, -inf));
    CHECK(sr_internal_atan2(1.0, -inf) == pi && sr_internal_atan2(-1.0, inf) == 0.0 && signbit(sr_internal_atan2(-1.0, inf)));
    CHECK(sr_internal_atan2(inf, 1.0) == pi / 2 && sr_internal_atan2(-inf, -1.0) == -pi / 2);
    CHECK(isnan(sr_internal_atan2(NAN, 1.0)) && isnan(sr_internal_atan2(1.0, NAN)));
}

static void test_the_public_atan2_is_the_librarys_own(void)
{
    const double y = 0.7315, x = -0.2201;
    double angle = 0.0;
    CHECK(sr_atan2(y, x, &angle) == SR_OK && angle == sr_internal_atan2(y, x));
}

static void test_the_public_atan2_refuses_nan_infinities_and_a_null_output(void)
{
    double angle = 5.0;
    CHECK(sr_atan2(NAN, 1.0, &angle) == SR_ERR_NONFINITE && angle == 5.0);
    CHECK(sr_atan2(1.0, HUGE_VAL, &angle) == SR_ERR_NONFINITE && angle == 5.0);
    CHECK(sr_atan2(1.0, 1.0, NULL) == SR_ERR_NULL);
}

void suite_trig(void)
{
    RUN_TEST(test_own_double_sin_and_cos_are_within_one_ulp_of_libm_up_to_their_range);
    RUN_TEST(test_own_double_sin_and_cos_are_within_one_ulp_at_the_quadrant_boundaries);
    RUN_TEST(test_own_double_sin_and_cos_give_nan_beyond_their_range_and_for_infinities_and_nan);
    RUN_TEST(test_own_atan2_is_within_two_ulp_of_libm_in_every_quadrant);
    RUN_TEST(test_own_atan2_gives_c99s_values_at_zeros_infinities_and_nan);
    RUN_TEST(test_the_public_atan2_is_the_librarys_own);
    RUN_TEST(test_the_public_atan2_refuses_nan_infinities_and_a_null_output);
}

#elif !defined(SR_LIBM_TRIG)

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
