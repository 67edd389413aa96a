/* bench_kernels.c -- times the kernels in a C loop (no Python in the timed region).
 *
 * usage: bench_kernels INPUT.bin REPEATS
 * INPUT.bin: int32 n, then params[SR_NPARAM], states[n][35], inputs[n][2], a general robot's
 * params[SR_NPARAM] (float64), the LQR's schedule (the bytes of an sr_lqr); with -DWITH_KANE
 * also kane[n][12], each state in the Kane model's coordinates (runtime/bench/kane_compiled.py).
 * Prints one JSON object: ns per call of each kernel (best of 11 rounds, each kernel timed
 * once per round over REPEATS sweeps of the n states, after a 0.3 s warm-up) and the outputs for every one of the n states,
 * which the Python driver checks against the reference before reporting any time.
 * Built by runtime/bench/harness.py; with -DWITH_CASADI the CasADi-generated reference
 * (ref_accel.c, written by the driver) is timed too; with -DWITH_KANE the Kane model compiled
 * three ways (kane_baselines.h: CasADi's C with ca.solve, SymPy's C printer and PyDy's C, both
 * with a generic LU).
 */
#define _POSIX_C_SOURCE 199309L
#include "spherical_robot.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#ifdef WITH_CASADI
#include "ref_accel.h"
#endif
#ifdef WITH_KANE
#include "kane_baselines.h"
#endif

#define NMAX 4096

#define NOUT (SR_NE * (SR_NE + SR_NU)) /* the Jacobians' outputs: a step Jacobian's F and G */
/* The Jacobians write to JOUT, everything else to OUT: one buffer as wide as a step Jacobian
 * would spread the other kernels' outputs over five times the memory and slow them. */
static sr_real X[NMAX][SR_NX], U[NMAX][SR_NU], OUT[NMAX][SR_NX], JOUT[NMAX][NOUT], BATCH_OUT[NMAX][SR_NV];
static sr_real STEP_BATCH_OUT[NMAX][SR_NX];
static double sink;

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

typedef int (*kernel_fn)(const sr_model *, int, int);
static sr_model model;
/* A robot of none of the paper's special geometry: the general kernels, same states. */
static sr_model general_model;

static int k_accel(const sr_model *m, int i, int arg) { (void)arg; return sr_accel(m, X[i], U[i], OUT[i]); }
static int k_gen_accel(const sr_model *m, int i, int arg) { (void)arg; return sr_gen_accel(m->c, X[i], U[i], OUT[i]); }
static int k_inertia(const sr_model *m, int i, int arg) { (void)arg; return sr_inertia(m, X[i], OUT[i]); }
static int k_step(const sr_model *m, int i, int method) { return sr_step(m, method, X[i], U[i], 0.01, OUT[i]); }
/* The batch form Python's Model.accel calls: sr_check_state and sr_accel on every row, vectorised. */
static int k_checked_accel_batch(const sr_model *m, int n, int arg)
{
    (void)arg;
    return sr_checked_accel_batch(m, n, X[0], U[0], BATCH_OUT[0], NULL);
}
/* The batch step Python's Model.step calls for (B, 35) states, vectorised across them. */
static int k_step_batch(const sr_model *m, int n, int method)
{
    return sr_step_batch(m, method, n, X[0], U[0], 0.01, STEP_BATCH_OUT[0], NULL);
}
static int k_accel_general(const sr_model *m, int i, int arg) { (void)m; (void)arg; return sr_accel(&general_model, X[i], U[i], OUT[i]); }
static int k_step_general(const sr_model *m, int i, int method) { (void)m; return sr_step(&general_model, method, X[i], U[i], 0.01, OUT[i]); }
static int k_accel_jacobian(const sr_model *m, int i, int arg) { (void)arg; return sr_accel_jacobian(m, X[i], U[i], JOUT[i], JOUT[i] + SR_NV * SR_NE); }
static int k_step_jacobian_lie_euler(const sr_model *m, int i, int arg) { (void)arg; return sr_step_jacobian_lie_euler(m, X[i], U[i], 0.01, JOUT[i], JOUT[i] + SR_NE * SR_NE); }
static int k_step_jacobian_rkmk4(const sr_model *m, int i, int arg) { (void)arg; return sr_step_jacobian_rkmk4(m, X[i], U[i], 0.01, JOUT[i], JOUT[i] + SR_NE * SR_NE); }
/* The LQR controller: one sample from a fresh memory, a path target (runtime/bench/harness.py
 * LQR_TARGET holds the same numbers for the check). */
static sr_lqr LQR;
static const sr_lqr_target LQR_TARGET = {SR_C(0.3), SR_C(0.5), SR_C(0.2), SR_C(0.05), 1};
static int k_lqr_control(const sr_model *m, int i, int arg)
{
    sr_lqr_memory memory;
    (void)arg;
    if (sr_lqr_reset(&memory) != SR_OK) return SR_ERR_NULL;
    return sr_lqr_control(&LQR, m, X[i], &LQR_TARGET, &memory, OUT[i], NULL);
}
static int k_step_jacobian_cf4(const sr_model *m, int i, int arg) { (void)arg; return sr_step_jacobian_cf4(m, X[i], U[i], 0.01, JOUT[i], JOUT[i] + SR_NE * SR_NE); }

#ifdef WITH_KANE
static double KANE[NMAX][12], KANE_P[12]; /* the Kane model: its coordinates, the paper's twelve parameters */
static int k_kane_casadi(const sr_model *m, int i, int arg) { (void)m; (void)arg; return kane_casadi_c(KANE[i], U[i], KANE_P, OUT[i]); }
static int k_kane_sympy(const sr_model *m, int i, int arg) { (void)m; (void)arg; return kane_sympy_c(KANE[i], U[i], KANE_P, OUT[i]); }
static int k_kane_pydy(const sr_model *m, int i, int arg) { (void)m; (void)arg; return kane_pydy_c(KANE[i], U[i], KANE_P, OUT[i]); }
static int k_kane_casadi_jac(const sr_model *m, int i, int arg) { (void)m; (void)arg; return kane_casadi_jac_c(KANE[i], U[i], KANE_P, JOUT[i]); }
#endif

#ifdef WITH_CASADI
static casadi_int iw[4096];
static casadi_real w[65536];
static int k_casadi(const sr_model *m, int i, int arg)
{
    const casadi_real *in[64];
    casadi_real *out[64];
    (void)m; (void)arg;
    in[0] = X[i]; in[1] = U[i]; out[0] = OUT[i];
    return ref_accel(in, out, iw, w, 0);
}
#endif

typedef struct {
    kernel_fn fn;
    int arg, nout, repeat_divisor;
    const char *name;
    double best;
    int batch; /* fn does all n states in one call (fn(model, n, arg)), its outputs in BATCH_OUT
                * (1) or, for a step batch, STEP_BATCH_OUT (2) */
} bench_case;

/* One timed sweep: `repeats` passes over the n states, ns per call. */
static double sweep(const bench_case *c, int n, int repeats)
{
    double t0 = now_ns();
    int r, i, reps = repeats / c->repeat_divisor > 0 ? repeats / c->repeat_divisor : 1;
    for (r = 0; r < reps && c->batch; ++r) {
        if (c->fn(&model, n, c->arg) != 0) { fprintf(stderr, "%s failed\n", c->name); exit(2); }
        sink += c->batch == 2 ? STEP_BATCH_OUT[n - 1][0] : BATCH_OUT[n - 1][0];
    }
    for (r = 0; r < reps && !c->batch; ++r)
        for (i = 0; i < n; ++i) {
            if (c->fn(&model, i, c->arg) != 0) { fprintf(stderr, "%s failed at state %d\n", c->name, i); exit(2); }
            sink += c->nout > SR_NX ? JOUT[i][0] : OUT[i][0];
        }
    return (now_ns() - t0) / ((double)reps * n);
}

static void print_case(const bench_case *c, int n)
{
    int i, k;
    printf("  \"%s\": {\"ns\": %.3f, \"check\": [", c->name, c->best);
    if (c->batch) c->fn(&model, n, c->arg);
    for (i = 0; i < n; ++i) {
        if (!c->batch) c->fn(&model, i, c->arg);
        printf("%s[", i ? ", " : "");
        for (k = 0; k < c->nout; ++k)
            printf("%s%.17g", k ? ", " : "",
                   (double)(c->batch == 2 ? STEP_BATCH_OUT[i][k] : c->batch ? BATCH_OUT[i][k]
                            : c->nout > SR_NX ? JOUT[i][k] : OUT[i][k]));
        printf("]");
    }
    printf("]},\n");
}

/* Warm up (clock and caches) for at least 0.3 s, then 11 rounds that time every kernel once
 * each, round robin, so that a change of clock speed during the run affects all of them alike;
 * the best round of each kernel is reported. */
static void time_all(bench_case *cases, int ncases, int n, int repeats)
{
    double start = now_ns();
    int round, k;
    while (now_ns() - start < 3e8)
        for (k = 0; k < ncases; ++k) sweep(&cases[k], n, 1);
    for (k = 0; k < ncases; ++k) cases[k].best = 1e300;
    for (round = 0; round < 11; ++round)
        for (k = 0; k < ncases; ++k) {
            double dt = sweep(&cases[k], n, repeats);
            if (dt < cases[k].best) cases[k].best = dt;
        }
}

int main(int argc, char **argv)
{
    FILE *f;
    int n, repeats;
    sr_real p[SR_NPARAM], gp[SR_NPARAM];
    if (argc != 3) { fprintf(stderr, "usage: %s INPUT.bin REPEATS\n", argv[0]); return 2; }
    f = fopen(argv[1], "rb");
    if (!f || fread(&n, sizeof n, 1, f) != 1 || n < 1 || n > NMAX) { fprintf(stderr, "bad input\n"); return 2; }
    if (fread(p, sizeof(sr_real), SR_NPARAM, f) != SR_NPARAM
        || fread(X, sizeof(sr_real) * SR_NX, (size_t)n, f) != (size_t)n
        || fread(U, sizeof(sr_real) * SR_NU, (size_t)n, f) != (size_t)n
        || fread(gp, sizeof(sr_real), SR_NPARAM, f) != SR_NPARAM
        || fread(&LQR, sizeof LQR, 1, f) != 1) { fprintf(stderr, "short input\n"); return 2; }
#ifdef WITH_KANE
    if (fread(KANE, sizeof(double) * 12, (size_t)n, f) != (size_t)n
        || fread(KANE_P, sizeof(double), 12, f) != 12) { fprintf(stderr, "short input\n"); return 2; }
#endif
    fclose(f);
    repeats = atoi(argv[2]);
    if (sr_model_init(&model, p) != SR_OK || sr_model_init(&general_model, gp) != SR_OK || !general_model.general
        || sr_lqr_check(&LQR) != SR_OK) {
        fprintf(stderr, "bad params\n");
        return 2;
    }
#ifdef WITH_CASADI
    {
        casadi_int sz_arg, sz_res, sz_iw, sz_w;
        ref_accel_work(&sz_arg, &sz_res, &sz_iw, &sz_w);
        if (sz_arg > 64 || sz_res > 64 || sz_iw > (casadi_int)(sizeof iw / sizeof iw[0])
            || sz_w > (casadi_int)(sizeof w / sizeof w[0])) { fprintf(stderr, "CasADi work arrays too small\n"); return 2; }
    }
#endif
    {
        bench_case cases[] = {
            {k_accel, 0, SR_NV, 1, "accel", 0, 0},
            {k_gen_accel, 0, SR_NV, 1, "accel_unchecked", 0, 0},
            {k_inertia, 0, SR_NV * SR_NV, 1, "inertia", 0, 0},
            {k_step, SR_LIE_EULER, SR_NX, 1, "step_lie_euler", 0, 0},
            {k_step, SR_RKMK4, SR_NX, 1, "step_rkmk4", 0, 0},
            {k_step, SR_CF4, SR_NX, 1, "step_cf4", 0, 0},
            {k_checked_accel_batch, 0, SR_NV, 1, "checked_accel_batch", 0, 1},
            {k_step_batch, SR_LIE_EULER, SR_NX, 1, "step_batch_lie_euler", 0, 2},
            {k_step_batch, SR_RKMK4, SR_NX, 1, "step_batch_rkmk4", 0, 2},
            {k_step_batch, SR_CF4, SR_NX, 1, "step_batch_cf4", 0, 2},
            {k_accel_general, 0, SR_NV, 1, "accel_general_robot", 0, 0},
            {k_step_general, SR_RKMK4, SR_NX, 1, "step_rkmk4_general_robot", 0, 0},
            {k_accel_jacobian, 0, SR_NV * (SR_NE + SR_NU), 1, "accel_jacobian", 0, 0},
            {k_step_jacobian_lie_euler, 0, NOUT, 1, "step_jacobian_lie_euler", 0, 0},
            {k_step_jacobian_rkmk4, 0, NOUT, 4, "step_jacobian_rkmk4", 0, 0},
            {k_step_jacobian_cf4, 0, NOUT, 4, "step_jacobian_cf4", 0, 0},
            {k_lqr_control, 0, SR_NU, 1, "lqr_control", 0, 0},
#ifdef WITH_CASADI
            {k_casadi, 0, SR_NV, 10, "casadi_generated_reference_accel", 0, 0},
#endif
#ifdef WITH_KANE
            {k_kane_casadi, 0, SR_NV, 4, "kane_casadi_c_accel", 0, 0},
            {k_kane_sympy, 0, SR_NV, 4, "kane_sympy_c_accel", 0, 0},
            {k_kane_pydy, 0, SR_NV, 4, "kane_pydy_c_accel", 0, 0},
            {k_kane_casadi_jac, 0, SR_NV * (SR_NE + SR_NU), 4, "kane_casadi_c_accel_jacobian", 0, 0},
#endif
        };
        const int ncases = (int)(sizeof cases / sizeof cases[0]);
        int k;
        time_all(cases, ncases, n, repeats);
        printf("{\n");
        for (k = 0; k < ncases; ++k) print_case(&cases[k], n);
    }
    printf("  \"accel_flops\": %d,\n  \"general_system_flops\": %d,\n  \"sink\": %g\n}\n", SR_GEN_ACCEL_FLOPS,
           SR_GEN_GENERAL_SYSTEM_FLOPS, sink);
    return 0;
}
