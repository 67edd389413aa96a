/*
 * sr_trig.c -- single-precision sine and cosine of the float build (for flash).
 *
 * Why: newlib's sinf and cosf carry a Payne-Hanek argument reduction and its 2/pi table for
 * arguments up to FLT_MAX: 4.3 KB of flash, more than the paper-geometry kernels and a Lie-Euler
 * step together.  The library's angles are rotation angles of one step (|w| dt), their halves,
 * joint angles and headings: a few radians.  These two functions reduce by Cody-Waite with pi/4
 * in three parts (Cephes' sinf/cosf, S. L. Moshier) and evaluate the minimax polynomials of Cephes on
 * [-pi/4, pi/4]; about 300 bytes of Thumb-2 code.
 *
 * Accuracy (c/tests/test_numerics.c checks it against double sin and cos on a dense grid):
 *   |x| <= SR_TRIG_EXACT_RANGE (8192 rad): absolute error <= 2^-23 (measured 7.7e-8, about 1 ulp
 *     of a result near 1);
 *   up to SR_TRIG_MAX_ARG (2^24 rad): the reduction's rounding grows as |x| 2^-24 (measured
 *     5.9e-8 |x|), the size of the argument's own rounding there (a float of 8192 rad or more is
 *     a multiple of 2^-10);
 *   beyond, and for infinities and NaN: NaN, which every caller's finiteness check turns into
 *     SR_ERR_NONFINITE (an angle of 2^24 rad in one step is no motion a valid state makes).
 * -DSR_LIBM_TRIG uses libm's sinf and cosf instead.  The double build always uses libm.
 */
#include "sr_math.h"

#if defined(SR_USE_FLOAT) && !defined(SR_LIBM_TRIG)

#define FOUR_OVER_PI 1.27323954473516f
/* pi/4 = DP1 + DP2 + DP3, DP1 and DP2 with few significant bits, so that j * DP1 and j * DP2 are
 * exact for the octant counts j of |x| <= 8192. */
#define DP1 0.78515625f
#define DP2 2.4187564849853515625e-4f
#define DP3 3.77489497744594108e-8f

/* sin and cos of r in [-pi/4, pi/4] (z = r^2): Cephes' polynomials, relative error < 1e-7. */
static float sin_poly(float r, float z)
{
    return ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * r + r;
}

static float cos_poly(float z)
{
    return ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z
           - 0.5f * z + 1.0f;
}

/* |x| reduced to r in [-pi/4, pi/4] and its octant (0..7) of x = octant pi/4 + r + 2 pi k;
 * returns 0 for an argument beyond SR_TRIG_MAX_ARG (or NaN). */
static int reduce(float x, float *r, int *octant)
{
    float y;
    long j;
    if (!(x <= SR_TRIG_MAX_ARG)) return 0;
    j = (long)(FOUR_OVER_PI * x);
    if (j & 1) ++j;              /* the nearest even octant boundary: r in [-pi/4, pi/4] */
    y = (float)j;
    *r = ((x - y * DP1) - y * DP2) - y * DP3;
    *octant = (int)(j & 7);
    return 1;
}

/* NaN for an argument the reduction does not take (x - x is 0 for a finite x, NaN otherwise). */
static float out_of_range(float x)
{
    const float zero = x - x;
    return zero / zero;
}

float sr_internal_sinf(float x)
{
    float r, z, s;
    int octant, negative = x < 0;
    if (!reduce(negative ? -x : x, &r, &octant)) return out_of_range(x);
    if (octant > 3) {
        negative = !negative;
        octant -= 4;
    }
    z = r * r;
    s = (octant == 2) ? cos_poly(z) : sin_poly(r, z);
    return negative ? -s : s;
}

float sr_internal_cosf(float x)
{
    float r, z, c;
    int octant, negative = 0;
    if (!reduce(x < 0 ? -x : x, &r, &octant)) return out_of_range(x);
    if (octant > 3) {
        negative = 1;
        octant -= 4;
    }
    if (octant == 2) negative = !negative;
    z = r * r;
    c = (octant == 2) ? sin_poly(r, z) : cos_poly(z);
    return negative ? -c : c;
}

#else
typedef int sr_trig_unused; /* ISO C wants a declaration in every translation unit */
#endif
