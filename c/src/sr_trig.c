/*
 * sr_trig.c -- the library's own sine, cosine and arctangent, so that every platform computes the
 * same bits.
 *
 * Why: libm's results are not specified to the bit.  glibc and newlib round a few arguments of
 * sin, cos and atan2 differently, so a closed loop built for a Cortex-M7 drifted from the host's
 * by a last bit at its second sample; with these functions, which use only IEEE double additions,
 * multiplications and divisions (no fused multiply-add: the library is built with
 * -ffp-contract=off), the double build is the same on the host and on the target, bit for bit.
 * And newlib's sinf and cosf carry a Payne-Hanek argument reduction and its 2/pi table for
 * arguments up to FLT_MAX: 4.3 KB of flash, more than the paper-geometry kernels and a Lie-Euler
 * step together.  The library's angles are rotation angles of one step (|w| dt), their halves,
 * joint angles, slopes and headings: a few radians, so no Payne-Hanek reduction here either.
 *
 * Double (sr_internal_sin, sr_internal_cos, sr_internal_atan2): the classic fdlibm scheme
 * (K. C. Ng, Sun Microsystems, 1993).  sin and cos reduce x by Cody-Waite with pi/2 in three parts
 * of 33 bits and their tails, keeping the reduced argument as a head and a tail, then evaluate
 * fdlibm's minimax polynomials of degree 13 and 14 on [-pi/4, pi/4]; atan reduces |x| to one of
 * five intervals around 0, 0.5, 1, 1.5 and infinity and evaluates fdlibm's polynomial of degree
 * 22; atan2 divides and places the quadrant.  Accuracy (c/tests/test_trig.c, against libm on
 * dense grids, on the host and under QEMU):
 *   sin, cos: within 1 ulp up to SR_TRIG_DOUBLE_MAX_ARG (2^20 pi/2 rad, where the octant count
 *     times the first part of pi/2 stays exact); beyond, and for infinities and NaN: NaN, which
 *     every caller's finiteness check turns into SR_ERR_NONFINITE;
 *   atan2: within 2 ulp everywhere, with C99's values for zeros and infinities.
 *
 * Float (sr_internal_sinf, sr_internal_cosf; -DSR_LIBM_TRIG uses libm's sinf and cosf instead):
 * reduction by Cody-Waite with pi/4 in three parts (Cephes' sinf/cosf, S. L. Moshier) and the
 * minimax polynomials of Cephes on [-pi/4, pi/4]; about 300 bytes of Thumb-2 code.
 *   |x| <= SR_TRIG_EXACT_RANGE (8192 rad): absolute error <= 2^-23 (measured 7.7e-8, about 1 ulp
 *     of a result near 1);
 *   up to SR_TRIG_MAX_ARG (2^24 rad): the reduction's rounding grows as |x| 2^-24 (measured
 *     5.9e-8 |x|), the size of the argument's own rounding there (a float of 8192 rad or more is
 *     a multiple of 2^-10);
 *   beyond, and for infinities and NaN: NaN, as in double.
 * The float build's atan2 is libm's atan2f: the float build is held to a tolerance, not to bits.
 */
#include "sr_math.h"
#include "sr_finite.h"

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

#endif

#if !defined(SR_USE_FLOAT) && !defined(SR_LIBM_TRIG)

/* pi/2 = PIO2_1 + PIO2_2 + PIO2_3 + PIO2_3T, each of the first three with 33 significant bits, so
 * that n PIO2_k is exact for the quadrant counts n <= 2^20; PIO2_kT is pi/2 minus the parts up to k. */
#define TWO_OVER_PI 6.36619772367581382433e-01
#define PIO2_1 1.57079632673412561417e+00
#define PIO2_2 6.07710050630396597660e-11
#define PIO2_2T 2.02226624879595063154e-21
#define PIO2_3 2.02226624871116645580e-21
#define PIO2_3T 8.47842766036889956997e-32

/* sin and cos of x + y on [-pi/4, pi/4], |y| below half an ulp of x: fdlibm's kernels. */
static double sin_kernel(double x, double y)
{
    const double z = x * x, v = z * x;
    const double r = 8.33333333332248946124e-03
                     + z * (-1.98412698298579493134e-04
                            + z * (2.75573137070700676789e-06
                                   + z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)));
    return x - ((z * (0.5 * y - v * r) - y) - v * -1.66666666666666324348e-01);
}

static double cos_kernel(double x, double y)
{
    const double z = x * x, w = z * z;
    const double r = z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 + z * 2.48015872894767294178e-05))
                     + w * w * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11));
    const double hz = 0.5 * z, h = 1.0 - hz;
    return h + (((1.0 - h) - hz) + (z * r - x * y));
}

/* x = n pi/2 + y[0] + y[1], |y[0] + y[1]| <= pi/4 (to a rounding); returns 0 for |x| beyond
 * SR_TRIG_DOUBLE_MAX_ARG or NaN. */
static int reduce_pio2(double x, double y[2], long *n)
{
    double fn, r, t, w;
    if (!(fabs(x) <= SR_TRIG_DOUBLE_MAX_ARG)) return 0;
    *n = (long)(x * TWO_OVER_PI + (x < 0 ? -0.5 : 0.5)); /* the nearest multiple of pi/2 */
    fn = (double)*n;
    r = x - fn * PIO2_1;                   /* exact: fn PIO2_1 is, and r is far below x */
    t = r;                                 /* the next 33 bits, with the rounding of r - w kept */
    w = fn * PIO2_2;
    r = t - w;
    w = fn * PIO2_2T - ((t - r) - w);
    t = r;                                 /* and the next, for the cancellations near n pi/2 */
    w = fn * PIO2_3;
    r = t - w;
    w = fn * PIO2_3T - ((t - r) - w);
    y[0] = r - w;
    y[1] = (r - y[0]) - w;
    return 1;
}

/* NaN for an argument the reduction does not take (x - x is 0 for a finite x, NaN otherwise). */
static double out_of_range_d(double x)
{
    const double zero = x - x;
    return zero / zero;
}

double sr_internal_sin(double x)
{
    double y[2];
    long n;
    if (fabs(x) <= 0.785398163397448279) return fabs(x) < 7.450580596923828125e-9 ? x : sin_kernel(x, 0.0);
    if (!reduce_pio2(x, y, &n)) return out_of_range_d(x);
    switch (n & 3) {
    case 0: return sin_kernel(y[0], y[1]);
    case 1: return cos_kernel(y[0], y[1]);
    case 2: return -sin_kernel(y[0], y[1]);
    default: return -cos_kernel(y[0], y[1]);
    }
}

double sr_internal_cos(double x)
{
    double y[2];
    long n;
    if (fabs(x) <= 0.785398163397448279) return fabs(x) < 7.450580596923828125e-9 ? 1.0 : cos_kernel(x, 0.0);
    if (!reduce_pio2(x, y, &n)) return out_of_range_d(x);
    switch (n & 3) {
    case 0: return cos_kernel(y[0], y[1]);
    case 1: return -sin_kernel(y[0], y[1]);
    case 2: return -cos_kernel(y[0], y[1]);
    default: return sin_kernel(y[0], y[1]);
    }
}

#define PI_HI 3.14159265358979311600e+00
#define PI_LO 1.22464679914735317723e-16
#define PIO2_HI 1.57079632679489655800e+00
#define PIO2_LO 6.12323399573676603587e-17

/* atan(x) for x >= 0 (finite or not): x reduced to t around 0 with atan(x) = atan(c) + atan(t),
 * c in {0, 0.5, 1, 1.5, infinity}, then fdlibm's odd polynomial of t. */
static double atan_nonnegative(double x)
{
    static const double hi[4] = {4.63647609000806093515e-01, 7.85398163397448278999e-01,
                                 9.82793723247329054082e-01, 1.57079632679489655800e+00};
    static const double lo[4] = {2.26987774529616870924e-17, 3.06161699786838301793e-17,
                                 1.39033110312309984516e-17, 6.12323399573676603587e-17};
    double z, w, s1, s2;
    int id;
    if (!(x < 6.80564733841876926927e+38)) return x != x ? x : PIO2_HI + PIO2_LO; /* 2^129 */
    if (x < 0.4375) {
        if (x < 1.862645149230957031e-09) return x; /* 2^-29: atan(x) = x to a rounding */
        id = -1;
    } else if (x < 1.1875) {
        if (x < 0.6875) {
            id = 0;
            x = (2.0 * x - 1.0) / (2.0 + x);
        } else {
            id = 1;
            x = (x - 1.0) / (x + 1.0);
        }
    } else if (x < 2.4375) {
        id = 2;
        x = (x - 1.5) / (1.0 + 1.5 * x);
    } else {
        id = 3;
        x = -1.0 / x;
    }
    z = x * x;
    w = z * z;
    s1 = z * (3.33333333333329318027e-01
              + w * (1.42857142725034663711e-01
                     + w * (9.09088713343650656196e-02
                            + w * (6.66107313738753120669e-02 + w * (4.97687799461593236017e-02 + w * 1.62858201153657823623e-02)))));
    s2 = w * (-1.99999999998764832476e-01
              + w * (-1.11111104054623557880e-01
                     + w * (-7.69187620504482999495e-02 + w * (-5.83357013379057348645e-02 + w * -3.65315727442169155270e-02))));
    if (id < 0) return x - x * (s1 + s2);
    return hi[id] - ((x * (s1 + s2) - lo[id]) - x);
}

double sr_internal_atan2(double y, double x)
{
    const double ax = fabs(x), ay = fabs(y);
    const int y_negative = signbit(y) != 0;
    double z;
    if (x != x || y != y) return x + y;
    if (signbit(x)) {                 /* the left half-plane, -0 included */
        if (ay == 0) z = PI_HI;                           /* atan2(+-0, x <= -0) = +-pi */
        else if (ax == 0) z = PIO2_HI;
        else if (ax > 1.79769313486231570815e+308) z = ay > 1.79769313486231570815e+308 ? 2.35619449019234483700e+00 : PI_HI;
        else if (ay > 1.79769313486231570815e+308) z = PIO2_HI;
        else if (ay < ax * 8.67361737988403547206e-19) z = PI_HI; /* 2^-60: pi - atan(tiny) */
        else z = PI_HI - (atan_nonnegative(ay / ax) - PI_LO);
    } else {
        if (ay == 0) z = 0;                               /* atan2(+-0, x >= +0) = +-0 */
        else if (ax == 0) z = PIO2_HI;
        else if (ax > 1.79769313486231570815e+308) z = ay > 1.79769313486231570815e+308 ? 0.78539816339744827900 : 0;
        else if (ay > ax * 1.15292150460684697600e+18) z = PIO2_HI + PIO2_LO; /* 2^60 */
        else z = atan_nonnegative(ay / ax);
    }
    return y_negative ? -z : z;
}

#endif

int sr_atan2(sr_real y, sr_real x, sr_real *angle)
{
    const sr_real yx[2] = {y, x};
    if (!angle) return SR_ERR_NULL;
    if (!all_finite(yx, 2)) return SR_ERR_NONFINITE;
    *angle = SR_ATAN2(y, x);
    return SR_OK;
}
