/*
 * accel_dump.c -- accelerations at reproducible random states, for measuring
 * the float build against the double build (tools/float_accuracy.sh).
 *
 *     accel_dump [N]      N states (default 1000); one CSV line per state:
 *                         a_Sx,a_Sy,a_Sz,a_Y,a_P  (%.17g)
 *
 * Built twice (make float-accuracy): build/accel_dump (double) and
 * build/accel_dump_f (float).  Both builds see exactly the same inputs: every
 * state and torque is drawn and built in double (own PRNG, own Rodrigues
 * formula), then rounded to float, so the double build's answer is the
 * reference for the float build's arithmetic on the same numbers.
 *
 * Ranges: R_S uniform-ish (rotation vector in a cube of half-width 1.8 rad),
 * yoke and pendulum angles in (-pi, pi), shell rates up to 3 rad/s, joint
 * rates up to 3 rad/s, torques up to 0.2 N m; parameters as the t-shape example.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "spherical_robot.h"

static double uniform(unsigned long long *s, double lo, double hi)
{
    unsigned long long z = (*s += 0x9E3779B97F4A7C15ULL); /* splitmix64 */
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return lo + (hi - lo) * ((double)(z >> 11) * (1.0 / 9007199254740992.0));
}

/* A double rounded to float, stored as sr_real: the same number in both builds. */
static sr_real f32(double v) { return (sr_real)(float)v; }

/* R = Exp([[w]]) in double (Rodrigues), rounded to float. */
static void rotation(const double w[3], sr_real R[9])
{
    const double t = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    const double A = sin(t) / t, B = (1 - cos(t)) / (t * t);
    const double W[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
    int i, j, k;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            double W2 = 0;
            for (k = 0; k < 3; ++k) W2 += W[3 * i + k] * W[3 * k + j];
            R[3 * i + j] = f32((i == j) + A * W[3 * i + j] + B * W2);
        }
}

int main(int argc, char **argv)
{
    static const sr_real paper[SR_NPAPER] = { /* the paper's twelve, in SR_PAPER_* order */
        SR_C(0.3), SR_C(2.0), SR_C(0.16), SR_C(0.2), SR_C(0.5), SR_C(2.0),
        SR_C(5.0), SR_C(0.04), SR_C(0.2), SR_C(1.0), SR_C(0.10), SR_C(9.81),
    };
    sr_real params[SR_NPARAM];
    unsigned long long seed = 20241122ULL;
    long n = argc > 1 ? strtol(argv[1], NULL, 10) : 1000, k;
    sr_model model;
    int status = sr_paper_params(paper, params);
    if (status == SR_OK) status = sr_model_init(&model, params);
    if (status != SR_OK || n < 0) {
        fprintf(stderr, "usage: accel_dump [N >= 0] (%s)\n", sr_status_string(status));
        return 2;
    }
    for (k = 0; k < n; ++k) {
        sr_real x[SR_NX] = {0}, u[SR_NU], a[SR_NV];
        double w[3], tY, tP;
        int i;
        for (i = 0; i < 3; ++i) w[i] = uniform(&seed, -1.8, 1.8);
        rotation(w, x);
        tY = uniform(&seed, -3.14159, 3.14159);
        tP = uniform(&seed, -3.14159, 3.14159);
        x[9] = 1;                                   /* R_Y = rot_x(tY) */
        x[13] = f32(cos(tY)), x[14] = f32(-sin(tY));
        x[16] = f32(sin(tY)), x[17] = f32(cos(tY));
        x[22] = 1;                                  /* R_P = rot_y(tP) */
        x[18] = f32(cos(tP)), x[20] = f32(sin(tP));
        x[24] = f32(-sin(tP)), x[26] = f32(cos(tP));
        x[27] = f32(uniform(&seed, -1, 1));
        x[28] = f32(uniform(&seed, -1, 1));
        x[29] = f32(0.3);
        for (i = 30; i < SR_NX; ++i) x[i] = f32(uniform(&seed, -3, 3));
        u[0] = f32(uniform(&seed, -0.2, 0.2));
        u[1] = f32(uniform(&seed, -0.2, 0.2));
        status = sr_accel(&model, x, u, a);
        if (status != SR_OK) {
            fprintf(stderr, "accel_dump: state %ld: %s\n", k, sr_status_string(status));
            return 1;
        }
        printf("%.17g,%.17g,%.17g,%.17g,%.17g\n", (double)a[0], (double)a[1], (double)a[2], (double)a[3],
               (double)a[4]);
    }
    return 0;
}
