/* step_anatomy.c -- where the time of a fourth-order step goes, in a C loop
 * over the benchmark's states (the input file of bench_kernels.c; only n, the parameters, the
 * states and the torques are read).  Prints one JSON object, ns per call, best of 11 rounds:
 *
 *   accel                       sr_accel, each call independent (as bench_kernels.c times it)
 *   accels_chained_through_nu   four sr_accel calls, each one's velocities nu depending on the
 *                               previous one's output (per four calls): the dependency a step's
 *                               stages have through their velocities
 *   accels_chained_through_state  the same through every entry the dynamics reads (gamma, the
 *                               yoke and pendulum angles, nu): the full latency of four calls
 *   step_rkmk4, step_cf4        sr_step
 *
 * Built a second time with -DANATOMY_GLUE_ONLY (runtime/bench/harness.py): the library's steppers
 * (c/src/sr_steppers.c, included below) then call a stub in place of the dynamics, two flops per
 * acceleration that keep the stages' dependence on the stage state, so step_rkmk4 and step_cf4
 * time everything a step does but the four accelerations: the state check, the group action
 * x . exp(th) (Rodrigues' and the one-axis exponentials), the kinematics, dexp^-1 and the tableau.
 * accel and the chained calls are the real kernel in both builds. */
#define _POSIX_C_SOURCE 199309L
#include "spherical_robot.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#ifdef ANATOMY_GLUE_ONLY
#define sr_internal_accel anatomy_stub_accel
#include "sr_steppers.c"
#undef sr_internal_accel
int anatomy_stub_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV])
{
    int i;
    (void)model;
    for (i = 0; i < SR_NV; ++i) a[i] = SR_C(1e-3) * x[SR_X_w_S + i] + x[SR_X_R_S + 6] * u[0];
    return SR_OK;
}
#endif

enum { MAX_STATES = 4096, ROUNDS = 11 };
static sr_real X[MAX_STATES][SR_NX], U[MAX_STATES][SR_NU], OUT[MAX_STATES][SR_NX];
/* The entries of x the paper robot's dynamics reads (generated/sr_generated.c, sr_gen_accel). */
static const int READ[] = {SR_X_R_S + 6, SR_X_R_S + 7, SR_X_R_S + 8, SR_X_R_Y + 4, SR_X_R_Y + 7, SR_X_R_P + 0,
                           SR_X_R_P + 2, SR_X_w_S, SR_X_w_S + 1, SR_X_w_S + 2, SR_X_w_Y, SR_X_w_P};
enum { NREAD = sizeof READ / sizeof READ[0] };

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

/* Four calls, each one's inputs (the first `depth` entries of READ) moved by 1e-300 times the
 * previous output: a real data dependency that leaves every input's value unchanged. */
static int chained(const sr_model *m, int i, int depth)
{
    sr_real x[SR_NX];
    int k, c, status = SR_OK;
    for (k = 0; k < SR_NX; ++k) x[k] = X[i][k];
    for (c = 0; c < 4; ++c) {
        status |= sr_accel(m, x, U[i], OUT[i]);
        for (k = 0; k < depth; ++k) x[READ[NREAD - 1 - k]] += SR_C(1e-300) * OUT[i][0];
    }
    return status;
}

static int run(const sr_model *m, int which, int i)
{
    switch (which) {
    case 0: return sr_accel(m, X[i], U[i], OUT[i]);
    case 1: return chained(m, i, SR_NV);
    case 2: return chained(m, i, NREAD);
    case 3: return sr_step(m, SR_RKMK4, X[i], U[i], SR_C(0.01), OUT[i]);
    default: return sr_step(m, SR_CF4, X[i], U[i], SR_C(0.01), OUT[i]);
    }
}

int main(int argc, char **argv)
{
    static const char *names[] = {"accel", "accels_chained_through_nu", "accels_chained_through_state",
                                  "step_rkmk4", "step_cf4"};
    enum { NCASES = sizeof names / sizeof names[0] };
    double best[NCASES], sink[NCASES];
    sr_real p[SR_NPARAM];
    sr_model m;
    FILE *f;
    int n, repeats, round, c, r, i;
    if (argc != 3) {
        fprintf(stderr, "usage: step_anatomy INPUT REPEATS\n");
        return 2;
    }
    repeats = atoi(argv[2]);
    f = fopen(argv[1], "rb");
    if (!f || fread(&n, sizeof n, 1, f) != 1 || n < 1 || n > MAX_STATES || repeats < 1
        || fread(p, sizeof p[0], SR_NPARAM, f) != SR_NPARAM || fread(X, sizeof X[0], (size_t)n, f) != (size_t)n
        || fread(U, sizeof U[0], (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "step_anatomy: cannot read %s\n", argv[1]);
        return 2;
    }
    fclose(f);
    if (sr_model_init(&m, p) != SR_OK) return 3;
    for (c = 0; c < NCASES; ++c) best[c] = 1e300, sink[c] = 0;
    for (round = -3; round < ROUNDS; ++round) /* three rounds of warm-up */
        for (c = 0; c < NCASES; ++c) {
            const double t0 = now_ns();
            double t;
            for (r = 0; r < repeats; ++r)
                for (i = 0; i < n; ++i) {
                    if (run(&m, c, i) != SR_OK) {
                        fprintf(stderr, "step_anatomy: %s failed on state %d\n", names[c], i);
                        return 4;
                    }
                    sink[c] += OUT[i][0];
                }
            t = (now_ns() - t0) / ((double)repeats * n);
            if (round >= 0 && t < best[c]) best[c] = t;
        }
    /* The sums of each case's first outputs, for the test that the stub is in place: the accels'
     * are the same in both builds, the steps' differ. */
    printf("{");
    for (c = 0; c < NCASES; ++c) printf("\"%s\": %.3f, ", names[c], best[c]);
    for (c = 0; c < NCASES; ++c) printf("\"%s_sink\": %.17g%s", names[c], sink[c], c + 1 < NCASES ? ", " : "}\n");
    return 0;
}
