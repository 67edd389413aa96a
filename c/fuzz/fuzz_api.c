/*
 * fuzz_api.c -- fuzz target for every public entry point of the spherical-robot library.
 *
 * LLVMFuzzerTestOneInput turns the input bytes into parameters, a state, torques, a time
 * step, a method and small step counts, calls every function of spherical_robot.h (the
 * controller's sr_lqr_* with a fuzzed gain schedule, target and memory) and of sr_sensors.h
 * (a fuzzed body, mount, nu_dot and biases) and of sr_ekf.h (a fuzzed start, process noise,
 * samples, noise levels, one per reading for sr_ekf_update_imu_axes and sr_ekf_update_imu_held, holds,
 * gates and delayed-fix slots)
 * and of sr_nmpc.h (a fuzzed box QP; a fuzzed NMPC design of a short horizon, target and
 * curvatures ahead), the slope estimate (sr_slope_*: fuzzed period, time constant, prior scale,
 * samples) and the law with offsets (sr_lqr_control_offsets: fuzzed feedforward tables and
 * offsets), and checks their
 * contract (abort() on a violation, so libFuzzer and the plain driver both report it with the
 * input that caused it):
 *
 *   - the status is one of the codes the header documents for that function;
 *   - whenever the status is SR_OK, every output is finite;
 *   - outputs are fully written on SR_OK and untouched on error (single-state kernels,
 *     sr_step, sr_model_init), or written exactly up to the documented row (simulations);
 *   - nothing is written outside the output buffers: every buffer is surrounded by canary
 *     zones that are checked after each call (and ASan sees any access beyond them).
 *
 * The bytes are read as a sequence of choices, each falling back to a valid value when
 * the input runs out: most fields stay valid and a few are perturbed (slightly, wildly,
 * or replaced by raw bits: NaN, infinities, subnormals, huge values), so the fuzzer gets
 * past the first check and exercises the steppers.  Built two ways (c/Makefile):
 *   make fuzz            plain C driver (fuzz/driver.c), gcc or clang, ASan + UBSan
 *   make fuzz-libfuzzer  clang -fsanitize=fuzzer,address,undefined
 */
#include "spherical_robot.h"
#include "sr_sensors.h"
#include "sr_ekf.h"
#include "sr_nmpc.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define GUARD 8             /* canary reals on each side of an output */
#define CANARY 0xA5      /* byte pattern of the model before sr_model_init */
#define MAX_STEPS 6         /* largest step count of a fuzzed simulation */
#define MAX_OUT (2 * SR_NE * SR_NPARAM)  /* two step sensitivities to the parameters; more than two step
                                         * Jacobians and (MAX_STEPS + 1) rows of a simulation */

typedef struct reader {
    const uint8_t *p;
    size_t n;
} reader;

static unsigned read_u8(reader *r)
{
    if (r->n == 0) return 0;
    --r->n;
    return *r->p++;
}

static double read_raw(reader *r)
{
    uint64_t bits = 0;
    double v;
    int i;
    for (i = 0; i < 8; ++i) bits = (bits << 8) | read_u8(r);
    memcpy(&v, &bits, sizeof v);
    return v;
}

/* A value for a field whose valid value is `valid`: usually valid, sometimes perturbed. */
static sr_real pick(reader *r, double valid)
{
    static const double special[] = {0.0, -0.0, 1e-300, 1e300, 1e-30, 1e30, 4.9e-324, -1.0,
                                     1.0 + 1e-7, 1.0 - 1e-7, 1e-7, 2.0};
    const unsigned c = read_u8(r);
    switch (c % 16) {
    case 12: return (sr_real)(valid * (1.0 + ((double)read_u8(r) - 128.0) * 1e-9)); /* slightly off */
    case 13: return (sr_real)(valid + ((double)read_u8(r) - 128.0) / 16.0);        /* off */
    case 14: return (sr_real)read_raw(r);                                            /* any bits */
    case 15: {
        const unsigned k = read_u8(r);
        if (k % 16 == 12) return (sr_real)NAN;
        if (k % 16 == 13) return (sr_real)INFINITY;
        if (k % 16 == 14) return (sr_real)-INFINITY;
        if (k % 16 == 15) return (sr_real)-valid;
        return (sr_real)special[k % 12];
    }
    default: return (sr_real)valid;
    }
}

static double unit(reader *r) { return ((double)read_u8(r) - 128.0) / 128.0; } /* [-1, 1) */

/* ---- canary-guarded output buffers -----------------------------------------------------
 * The canary is a signalling NaN with a fixed payload: never a valid output (outputs are finite
 * on SR_OK), and not what arithmetic produces (quiet NaNs), so "untouched" is unambiguous even
 * when the fuzzer feeds the canary's bytes as input. */
#ifdef SR_USE_FLOAT
typedef uint32_t canary_bits;
static const canary_bits CANARY_BITS = 0x7FA5A5A5u;
#else
typedef uint64_t canary_bits;
static const canary_bits CANARY_BITS = 0x7FF4A5A5A5A5A5A5ull;
#endif

typedef struct guarded {
    sr_real buf[GUARD + MAX_OUT + GUARD];
    int n;
} guarded;

static sr_real *arm(guarded *g, int n)
{
    size_t i;
    for (i = 0; i < sizeof g->buf / sizeof g->buf[0]; ++i) memcpy(&g->buf[i], &CANARY_BITS, sizeof(sr_real));
    g->n = n;
    return g->buf + GUARD;
}

static int is_canary(const sr_real *v) { return memcmp(v, &CANARY_BITS, sizeof *v) == 0; }

static void fail(const char *fn, int status, const char *what)
{
    fprintf(stderr, "fuzz: contract violated by %s (status %d, %s): %s\n", fn, status, sr_status_string(status),
            what);
    abort();
}

/* Guards intact; outputs [0, written) written (finite if `finite`), [written, n) untouched. */
static void expect(const char *fn, int status, const guarded *g, int written, int finite)
{
    int i;
    for (i = 0; i < GUARD; ++i)
        if (!is_canary(g->buf + i) || !is_canary(g->buf + GUARD + g->n + i)) fail(fn, status, "wrote outside its buffer");
    for (i = 0; i < g->n; ++i) {
        const sr_real v = g->buf[GUARD + i];
        if (i < written && is_canary(&g->buf[GUARD + i])) fail(fn, status, "left an output unwritten");
        if (i < written && finite && !isfinite(v)) fail(fn, status, "returned a non-finite output");
        if (i >= written && !is_canary(&g->buf[GUARD + i])) fail(fn, status, "wrote an output it documents as untouched");
    }
}

/* status must be one of the `n` codes in `allowed`. */
static void expect_status(const char *fn, int status, const int *allowed, int n)
{
    int i;
    for (i = 0; i < n; ++i)
        if (status == allowed[i]) return;
    fail(fn, status, "undocumented status code");
}
#define EXPECT_STATUS(fn, status, ...)                                                   \
    do {                                                                                 \
        const int allowed_[] = {__VA_ARGS__};                                            \
        expect_status(fn, status, allowed_, (int)(sizeof allowed_ / sizeof allowed_[0])); \
    } while (0)

/* ---- the fuzzed inputs --------------------------------------------------------------------- */
static void read_params(reader *r, sr_real p[SR_NPARAM])
{
    /* A general robot near Section 5.2's (doubled damping), every field nonzero somewhere. */
    static const double base[SR_NPARAM] = {
        [SR_P_r] = 0.3, [SR_P_m_S] = 2.0, [SR_P_j_S] = 0.12, [SR_P_k_S] = 0.16, [SR_P_m_Y] = 14.0,
        [SR_P_c_Y_x] = 0.01, [SR_P_c_Y_y] = -0.02, [SR_P_c_Y_z] = 0.03, [SR_P_J_Y_xx] = 0.2,
        [SR_P_J_Y_yy] = 0.5, [SR_P_J_Y_zz] = 0.6, [SR_P_J_Y_xy] = 0.01, [SR_P_J_Y_xz] = 0.02,
        [SR_P_J_Y_yz] = -0.03, [SR_P_k_Y] = 0.04, [SR_P_m_P] = 1.0, [SR_P_c_P_x] = 0.02, [SR_P_c_P_y] = 0.01,
        [SR_P_c_P_z] = -0.1, [SR_P_J_P_xx] = 0.004, [SR_P_J_P_yy] = 0.0035, [SR_P_J_P_zz] = 0.0015,
        [SR_P_J_P_xy] = 0.0005, [SR_P_J_P_xz] = 0.0002, [SR_P_J_P_yz] = 0.0001, [SR_P_k_P] = 0.1,
        [SR_P_j_mY] = 0.01, [SR_P_n_Y] = 20.0, [SR_P_j_mP] = 0.005, [SR_P_n_P] = -15.0, [SR_P_g] = 9.81,
        [SR_P_slope] = 0.1};
    int i;
    for (i = 0; i < SR_NPARAM; ++i) p[i] = pick(r, base[i]);
}

static void rot_axis(int k, double t, sr_real R[9])
{
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    int m;
    for (m = 0; m < 9; ++m) R[m] = 0;
    R[4 * k] = 1;
    R[4 * i] = R[4 * j] = (sr_real)cos(t);
    R[3 * i + j] = (sr_real)-sin(t);
    R[3 * j + i] = (sr_real)sin(t);
}

/* A valid state built from the bytes (any attitude, joint angles, speeds up to ~20 rad/s),
 * then each entry possibly perturbed. */
static void read_state(reader *r, sr_real radius, sr_real x[SR_NX])
{
    sr_real w[3];
    const double speed = 20.0 * fabs(unit(r));
    int i;
    for (i = 0; i < 3; ++i) w[i] = (sr_real)(3.2 * unit(r));
    if (sr_so3_exp(w, x) != SR_OK) abort();
    rot_axis(0, 3.2 * unit(r), x + SR_X_R_Y);
    rot_axis(1, 3.2 * unit(r), x + SR_X_R_P);
    x[SR_X_q] = (sr_real)unit(r);
    x[SR_X_q + 1] = (sr_real)unit(r);
    x[SR_X_q + 2] = isfinite(radius) ? radius : SR_C(0.3);
    for (i = 30; i < SR_NX; ++i) x[i] = (sr_real)(speed * unit(r));
    for (i = 0; i < SR_NX; ++i) x[i] = pick(r, (double)x[i]);
}

/* ---- the controller: sr_lqr_check, sr_lqr_reset, sr_lqr_error, sr_lqr_control ---------------
 * A schedule of fuzzed sizes, grids strictly increasing unless a pick perturbs them, gains and
 * operating points mostly small and finite; a target and a memory likewise.  Contract: documented
 * status; z, u and u_raw finite on SR_OK (|u| <= u_max) and untouched otherwise; the memory
 * untouched on error. */
static void fuzz_controller(reader *r, const sr_model *model, const sr_real x[SR_NX])
{
    static sr_lqr lqr;   /* 9 KB: not on the stack of the fuzz target */
    static guarded gz, gu, gr;
    sr_lqr_target target;
    sr_lqr_memory memory, before, ran;
    sr_real integrals[2];
    int i, j, status, no_integrals, has_run, raw[2];
    memset(&lqr, 0, sizeof lqr);
    /* the small choices first, the long tables last: an input that runs out leaves valid gains */
    lqr.n_speeds = 1 + (int)(read_u8(r) % SR_LQR_MAX_SPEEDS);
    lqr.n_curvatures = 1 + (int)(read_u8(r) % SR_LQR_MAX_CURVATURES);
    if (read_u8(r) % 16 == 15) lqr.n_speeds = (int)read_u8(r) - 128;         /* out of range, sometimes */
    if (read_u8(r) % 16 == 15) lqr.n_curvatures = (int)read_u8(r) - 128;
    lqr.period = pick(r, 0.01);
    lqr.u_max = pick(r, 2.0);
    lqr.kappa_rate = pick(r, 1.0);
    lqr.steady_rate = pick(r, 0.005);
    target.speed = pick(r, 0.5 * unit(r));
    target.heading = pick(r, 3.2 * unit(r));
    target.curvature = pick(r, unit(r));
    target.cross_track = pick(r, 0.2 * unit(r));
    target.path = (int)(read_u8(r) % 2);
    integrals[0] = pick(r, 0.1 * unit(r));
    integrals[1] = pick(r, 0.1 * unit(r));
    no_integrals = read_u8(r) % 4 == 3;
    has_run = read_u8(r) % 4 == 3;   /* a memory that has run before, possibly corrupt */
    memset(&ran, 0, sizeof ran);
    ran.started = 1;
    ran.integrals[0] = pick(r, 0.05 * unit(r));
    ran.integrals[1] = pick(r, 0.05 * unit(r));
    ran.kappa = pick(r, 0.5 * unit(r));
    raw[0] = read_u8(r) % 4 != 3;    /* u_raw asked for */
    raw[1] = read_u8(r) % 4 != 3;
    for (i = 0; i < SR_LQR_MAX_SPEEDS; ++i) lqr.speeds[i] = pick(r, 0.25 * (i + 1));
    for (i = 0; i < SR_LQR_MAX_CURVATURES; ++i) lqr.curvatures[i] = pick(r, -1.0 + 0.5 * i);
    for (i = 0; i < SR_LQR_MAX_SPEEDS * SR_LQR_MAX_CURVATURES; ++i) {
        for (j = 0; j < SR_LQR_NZ; ++j) lqr.z_star[i][j] = pick(r, 0.1 * unit(r));
        for (j = 0; j < SR_NU; ++j) lqr.u_star[i][j] = pick(r, 0.1 * unit(r));
        for (j = 0; j < SR_NU * SR_LQR_NZ; ++j) {
            lqr.K_path[i][j] = pick(r, 2.0 * unit(r));
            lqr.K_heading[i][j] = pick(r, 2.0 * unit(r));
        }
    }

    status = sr_lqr_check(&lqr);
    EXPECT_STATUS("sr_lqr_check", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_ARG);
    EXPECT_STATUS("sr_lqr_check(NULL)", sr_lqr_check(NULL), SR_ERR_NULL);

    status = sr_lqr_error(model, x, &target, no_integrals ? NULL : integrals, arm(&gz, SR_LQR_NZ));
    EXPECT_STATUS("sr_lqr_error", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
    expect("sr_lqr_error", status, &gz, status == SR_OK ? SR_LQR_NZ : 0, 1);

    EXPECT_STATUS("sr_lqr_reset", sr_lqr_reset(&memory), SR_OK);
    if (memory.started != 0 || memory.integrals[0] != 0 || memory.integrals[1] != 0 || memory.kappa != 0)
        fail("sr_lqr_reset", SR_OK, "left the memory unzeroed");
    if (has_run) memory = ran;
    for (i = 0; i < 2; ++i) {   /* two samples: the second from the memory the first left */
        before = memory;
        status = sr_lqr_control(&lqr, model, x, &target, &memory, arm(&gu, SR_NU), raw[i] ? arm(&gr, SR_NU) : NULL);
        EXPECT_STATUS("sr_lqr_control", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                      SR_ERR_ARG);
        expect("sr_lqr_control", status, &gu, status == SR_OK ? SR_NU : 0, 1);
        if (raw[i]) expect("sr_lqr_control", status, &gr, status == SR_OK ? SR_NU : 0, 1);
        if (status == SR_OK) {
            for (j = 0; j < SR_NU; ++j)
                if (!(fabs((double)gu.buf[GUARD + j]) <= (double)lqr.u_max)) fail("sr_lqr_control", status, "torque beyond u_max");
            if (lqr.n_speeds < 1 || lqr.n_speeds > SR_LQR_MAX_SPEEDS || lqr.n_curvatures < 1 ||
                lqr.n_curvatures > SR_LQR_MAX_CURVATURES || !(lqr.period > 0) || !(lqr.u_max > 0))
                fail("sr_lqr_control", status, "accepted a schedule of bad sizes, period or u_max");
        } else if (memcmp(&before, &memory, sizeof memory) != 0) {
            fail("sr_lqr_control", status, "changed the memory on error");
        }
    }
    EXPECT_STATUS("sr_lqr_control(NULL)", sr_lqr_control(&lqr, model, x, &target, NULL, arm(&gu, SR_NU), NULL),
                  SR_ERR_NULL);
}

#define QP_N 6   /* unknowns of a fuzzed box QP */

/* sr_boxqp_solve on a fuzzed QP (H = M M^T + d I, perturbed), and sr_nmpc_* on a fuzzed design. */
static void fuzz_nmpc(reader *r, const sr_model *model, const sr_real x[SR_NX])
{
    static sr_nmpc design;           /* 60 kB: not on the stack of the fuzz target */
    static sr_nmpc_memory memory, before;
    static guarded gx, gu, gz, gA, gB;
    sr_real H[QP_N * QP_N], g[QP_N], lb[QP_N], ub[QP_N], work[SR_BOXQP_WORK_REALS(QP_N)], M[QP_N * QP_N];
    sr_real z[SR_NMPC_NZ], ahead[SR_NMPC_MAX_HORIZON + 1], u0[SR_NU];
    sr_nmpc_target target;
    int iwork[SR_BOXQP_WORK_INTS(QP_N)], i, j, k, status, iterations = -1, n, max_it, use_ahead;
    sr_real *xq;
    n = 1 + (int)(read_u8(r) % QP_N);
    max_it = read_u8(r) % 8 == 7 ? (int)(read_u8(r) % 3) : 4 * n;
    for (i = 0; i < n * n; ++i) M[i] = (sr_real)unit(r);
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            sr_real acc = i == j ? SR_C(0.1) : 0;
            for (k = 0; k < n; ++k) acc += M[i * n + k] * M[j * n + k];
            H[i * n + j] = pick(r, (double)acc);
        }
    xq = arm(&gx, n);
    for (i = 0; i < n; ++i) {
        g[i] = pick(r, 3 * unit(r));
        lb[i] = pick(r, -1 + 0.5 * unit(r));
        ub[i] = pick(r, 1 + 0.5 * unit(r));
        xq[i] = pick(r, unit(r));
    }
    memcpy(M, xq, (size_t)n * sizeof *xq);
    status = sr_boxqp_solve(n, H, g, lb, ub, max_it, xq, work, iwork, &iterations);
    EXPECT_STATUS("sr_boxqp_solve", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_SINGULAR, SR_ERR_MAX_STEPS);
    if (status == SR_OK) {
        expect("sr_boxqp_solve", status, &gx, n, 1);
        for (i = 0; i < n; ++i)
            if (!(xq[i] >= lb[i] && xq[i] <= ub[i])) fail("sr_boxqp_solve", status, "solution outside the box");
        if (iterations < 1 || iterations > max_it) fail("sr_boxqp_solve", status, "iterations out of range");
    } else if (memcmp(M, xq, (size_t)n * sizeof *xq) != 0) {
        fail("sr_boxqp_solve", status, "changed x on error");
    }

    /* the prediction node */
    for (i = 0; i < SR_NMPC_NZ; ++i) z[i] = pick(r, 0.1 * unit(r));
    u0[0] = pick(r, 0.2 * unit(r));
    u0[1] = pick(r, 0.2 * unit(r));
    {
        const sr_real v = pick(r, 0.5 * unit(r)), kappa = pick(r, unit(r)), dt = pick(r, 0.1);
        status = sr_nmpc_node(model, z, u0, v, kappa, dt, arm(&gz, SR_NMPC_NZ), arm(&gA, SR_NMPC_NZ * SR_NMPC_NZ),
                              arm(&gB, SR_NMPC_NZ * SR_NU));
        EXPECT_STATUS("sr_nmpc_node", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_ARG, SR_ERR_SINGULAR,
                      SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
        expect("sr_nmpc_node", status, &gz, status == SR_OK ? SR_NMPC_NZ : 0, 1);
        expect("sr_nmpc_node", status, &gA, status == SR_OK ? SR_NMPC_NZ * SR_NMPC_NZ : 0, 1);
        expect("sr_nmpc_node", status, &gB, status == SR_OK ? SR_NMPC_NZ * SR_NU : 0, 1);
    }

    /* a short design: identity-like weights and cost-to-go, fuzzed sizes and entries */
    memset(&design, 0, sizeof design);
    design.horizon = 1 + (int)(read_u8(r) % 4);
    if (read_u8(r) % 16 == 15) design.horizon = (int)read_u8(r) - 128;
    design.node_periods = 1 + (int)(read_u8(r) % 3);
    design.cold_iterations = 1 + (int)(read_u8(r) % 3);
    design.iterations = 1;
    design.qp_max_iterations = 1 + (int)(read_u8(r) % 40);
    design.period = pick(r, 0.05);
    design.u_max = pick(r, 0.5);
    design.r = pick(r, 4.0);
    design.r_step = pick(r, 100.0);
    design.steady_rate = pick(r, 0.02);
    design.heading_jump = pick(r, 0.3);
    design.disturbance_gain = pick(r, 0.2);
    design.n_speeds = design.n_curvatures = 1;
    design.speeds[0] = pick(r, 0.3);
    for (i = 0; i < SR_NMPC_NZ; ++i) {
        design.q_path[i] = pick(r, 1.0);
        design.q_heading[i] = pick(r, 1.0);
        design.z_star[0][i] = pick(r, 0.0);
        design.P_path[0][i * (SR_NMPC_NZ + 1)] = pick(r, 10.0);
        design.P_heading[0][i * (SR_NMPC_NZ + 1)] = pick(r, 10.0);
    }
    design.u_star[0][0] = pick(r, 0.1);
    design.u_star[0][1] = pick(r, 0.0);
    target.speed = pick(r, 0.3);
    target.heading = pick(r, 3.2 * unit(r));
    target.curvature = pick(r, 0.5 * unit(r));
    target.cross_track = pick(r, 0.05 * unit(r));
    target.path = (int)(read_u8(r) % 2);
    use_ahead = read_u8(r) % 2;
    for (i = 0; i <= SR_NMPC_MAX_HORIZON; ++i) ahead[i] = pick(r, 0.5);
    target.curvature_ahead = use_ahead ? ahead : NULL;

    status = sr_nmpc_check(&design);
    EXPECT_STATUS("sr_nmpc_check", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_ARG);
    EXPECT_STATUS("sr_nmpc_check(NULL)", sr_nmpc_check(NULL), SR_ERR_NULL);
    EXPECT_STATUS("sr_nmpc_reset", sr_nmpc_reset(&memory), SR_OK);
    for (i = 0; i < 2; ++i) {   /* two samples: the second warm-started from the first */
        before = memory;
        status = sr_nmpc_step(&design, &memory, model, x, &target, arm(&gu, SR_NU));
        EXPECT_STATUS("sr_nmpc_step", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                      SR_ERR_ARG);
        expect("sr_nmpc_step", status, &gu, status == SR_OK ? SR_NU : 0, 1);
        if (status == SR_OK) {
            for (j = 0; j < SR_NU; ++j)
                if (!(fabs((double)gu.buf[GUARD + j]) <= (double)design.u_max)) fail("sr_nmpc_step", status, "torque beyond u_max");
        } else if (memory.samples != before.samples || memory.have_guess != before.have_guess
                   || memcmp(memory.Z, before.Z, sizeof memory.Z) != 0 || memory.integral != before.integral) {
            fail("sr_nmpc_step", status, "changed the memory on error");
        }
    }
    if (sr_nmpc_memory_bytes() != (long)sizeof(sr_nmpc_memory)) fail("sr_nmpc_memory_bytes", SR_OK, "not the memory's size");
    EXPECT_STATUS("sr_nmpc_step(NULL)", sr_nmpc_step(&design, NULL, model, x, &target, arm(&gu, SR_NU)), SR_ERR_NULL);
}

/* ---- the validity stamp: every entry point on a model whose bytes the input changed ------------
 * The model is zeroed, filled with input bytes, has one parameter or constant replaced by a picked
 * value, has one byte flipped, or stays as it is.  Every function that takes the model runs on it
 * and on the valid model.  Contract: a function either refuses the changed model (SR_ERR_MODEL,
 * outputs untouched) or returns what it returns on the valid model, status and outputs bit for
 * bit: a change to what it reads is refused, a change to what it does not read makes no
 * difference.  A model without the stamp is refused by every one, and one whose fields (stamp,
 * sums, p, general, c, cg) all equal the valid model's by none (a flipped byte of padding);
 * sr_check_model refuses any change to general, the sums or the constants of the model's kind.  SR_OK always comes with finite outputs. */
static int model_changed(const sr_model *a, const sr_model *b)
{
    if (a->stamp != b->stamp || memcmp(a->sums, b->sums, sizeof a->sums) != 0 || a->general != b->general) return 1;
    if (memcmp(a->p, b->p, sizeof a->p) != 0) return 1;
    return memcmp(a->cg, b->cg, sizeof a->cg) != 0 || memcmp(a->c, b->c, sizeof a->c) != 0;
}

/* The verdict on the changed model m (status, outputs in g) against the valid one's (ref_status, ref). */
static void expect_model_verdict(const char *fn, int status, int ref_status, const sr_model *m, const sr_model *valid,
                                 const guarded *g, const guarded *ref, int n_out)
{
    if (m->stamp != valid->stamp && status != SR_ERR_MODEL) fail(fn, status, "accepted a model without the stamp");
    if (status == SR_ERR_MODEL) {
        if (!model_changed(m, valid)) fail(fn, status, "refused a valid model");
        expect(fn, status, g, 0, 1);
        return;
    }
    if (status != ref_status) fail(fn, status, "accepted a changed model, and returned another status than on the valid one");
    if (memcmp(g->buf, ref->buf, sizeof g->buf) != 0)
        fail(fn, status, "accepted a changed model, and wrote other outputs than on the valid one");
    if (status == SR_OK) expect(fn, status, g, n_out, 1);
}

/* Run `call` (an expression of the model M and the outputs it arms in g, g2, g3) on the valid
 * model, then on m, and hold m's result to the contract above. */
#define ON_BOTH_MODELS(fn, n_out, call)                                                       \
    do {                                                                                      \
        const sr_model *M = valid;                                                            \
        int ref_status;                                                                       \
        memory = fresh;                                                                       \
        ref_status = (call);                                                                  \
        ref = g;                                                                              \
        M = &m;                                                                               \
        memory = fresh;                                                                       \
        status = (call);                                                                      \
        expect_model_verdict(fn, status, ref_status, &m, valid, &g, &ref, n_out);            \
    } while (0)

static void fuzz_model_validity(reader *r, const sr_model *valid, const sr_real x[SR_NX], const sr_real *u,
                                sr_real dt, int method)
{
    static sr_model m;
    static guarded g, g2, g3, ref;
    static sr_lqr lqr;
    static const sr_real mount[SR_NMOUNT] = {0, 0, SR_C(-0.05), 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const sr_real mount_nu_dot[SR_NV] = {SR_C(0.1), SR_C(-0.2), SR_C(0.3), SR_C(0.4), SR_C(-0.5)};
    static const sr_lqr_target target = {SR_C(0.3), SR_C(0.5), SR_C(0.2), SR_C(0.05), 1};
    static const sr_real d[SR_NE];
    static const sr_real nmpc_z[SR_NMPC_NZ] = {SR_C(0.02), SR_C(-0.03), SR_C(0.05), SR_C(0.1), SR_C(0.05), SR_C(-0.02),
                                               SR_C(0.03), SR_C(-0.1), SR_C(0.2), SR_C(0.01), SR_C(0.003)};
    static const sr_real nmpc_u[SR_NU] = {SR_C(0.1), SR_C(-0.05)};
    sr_real x2[2 * SR_NX];
    const sr_lqr_memory fresh = {{0, 0}, 0, 0, 0, 0, {0, 0}, 0};
    sr_lqr_memory memory = fresh;
    sr_energy_guard guard = {SR_C(0.5), 0, 0, 0, 0};
    sr_adaptive_stats st;
    const unsigned mode = read_u8(r) % 5;
    long row, done;
    int status;
    size_t i;
    m = *valid;
    if (mode == 0) {
        memset(&m, 0, sizeof m);
    } else if (mode == 1) {
        unsigned char *b = (unsigned char *)&m;
        for (i = 0; i < sizeof m; ++i) b[i] = (unsigned char)read_u8(r);
    } else if (mode == 2) {
        const unsigned k = read_u8(r) % (SR_NPARAM + SR_GEN_NCONST + SR_GEN_GENERAL_NCONST);
        sr_real *field = k < SR_NPARAM ? &m.p[k] : k < SR_NPARAM + SR_GEN_NCONST ? &m.c[k - SR_NPARAM]
                                                                                : &m.cg[k - SR_NPARAM - SR_GEN_NCONST];
        *field = pick(r, (double)*field);
    } else if (mode == 3) {
        const size_t at = ((size_t)read_u8(r) << 8 | read_u8(r)) % sizeof m;
        ((unsigned char *)&m)[at] ^= (unsigned char)(1u << (read_u8(r) % 8));
    }
    memcpy(x2, x, sizeof(sr_real) * SR_NX);
    memcpy(x2 + SR_NX, x, sizeof(sr_real) * SR_NX);
    memset(&lqr, 0, sizeof lqr);
    lqr.n_speeds = lqr.n_curvatures = 1;
    lqr.period = SR_C(0.02);
    lqr.u_max = SR_C(0.5);
    lqr.steady_rate = SR_C(0.005);

    ON_BOTH_MODELS("sr_check_state (model)", 0, (arm(&g, 0), sr_check_state(M, x)));
    ON_BOTH_MODELS("sr_check_state_batch (model)", 0, (arm(&g, 0), sr_check_state_batch(M, 2, x2, &row)));
    ON_BOTH_MODELS("sr_check_model (model)", 0, (arm(&g, 0), sr_check_model(M)));
    if (m.general != valid->general || memcmp(m.sums, valid->sums, sizeof m.sums) != 0
        || (m.general ? memcmp(m.cg, valid->cg, sizeof m.cg) : memcmp(m.c, valid->c, sizeof m.c)) != 0)
        if (sr_check_model(&m) != SR_ERR_MODEL) fail("sr_check_model", sr_check_model(&m), "accepted changed constants or sums");
    ON_BOTH_MODELS("sr_accel (model)", SR_NV, sr_accel(M, x, u, arm(&g, SR_NV)));
    ON_BOTH_MODELS("sr_accel_batch (model)", 2 * SR_NV, sr_accel_batch(M, 2, x2, NULL, arm(&g, 2 * SR_NV), &row));
    ON_BOTH_MODELS("sr_checked_accel_batch (model)", 2 * SR_NV, sr_checked_accel_batch(M, 2, x2, NULL, arm(&g, 2 * SR_NV), &row));
    ON_BOTH_MODELS("sr_inertia (model)", SR_NV * SR_NV, sr_inertia(M, x, arm(&g, SR_NV * SR_NV)));
    ON_BOTH_MODELS("sr_rhs (model)", SR_NV, sr_rhs(M, x, u, arm(&g, SR_NV)));
    ON_BOTH_MODELS("sr_energy (model)", 1, sr_energy(M, x, arm(&g, 1)));
    ON_BOTH_MODELS("sr_equilibrium_residual (model)", SR_NV, sr_equilibrium_residual(M, x, arm(&g, SR_NV)));
    ON_BOTH_MODELS("sr_contact_force (model)", 3, sr_contact_force(M, x, u, arm(&g, 3)));
    ON_BOTH_MODELS("sr_contact_force_batch (model)", 2 * 3, sr_contact_force_batch(M, 2, x2, NULL, arm(&g, 2 * 3), &row));
    ON_BOTH_MODELS("sr_step (model)", SR_NX, sr_step(M, method, x, u, dt, arm(&g, SR_NX)));
    ON_BOTH_MODELS("sr_step_lie_euler (model)", SR_NX, sr_step_lie_euler(M, x, u, dt, arm(&g, SR_NX)));
    ON_BOTH_MODELS("sr_step_rkmk4 (model)", SR_NX, sr_step_rkmk4(M, x, u, dt, arm(&g, SR_NX)));
    ON_BOTH_MODELS("sr_step_cf4 (model)", SR_NX, sr_step_cf4(M, x, u, dt, arm(&g, SR_NX)));
    ON_BOTH_MODELS("sr_step_batch (model)", 2 * SR_NX, sr_step_batch(M, method, 2, x2, NULL, dt, arm(&g, 2 * SR_NX), &row));
    ON_BOTH_MODELS("sr_simulate (model)", 2 * SR_NX, sr_simulate(M, method, x, dt, 1, u, arm(&g, 2 * SR_NX), &done));
    ON_BOTH_MODELS("sr_simulate_guarded (model)", 2 * SR_NX, sr_simulate_guarded(M, method, x, dt, 1, u, &guard, arm(&g, 2 * SR_NX), &done));
    ON_BOTH_MODELS("sr_simulate_adaptive (model)", 2 * SR_NX, sr_simulate_adaptive(M, SR_RKMK4, x, dt, 1, u, SR_C(1e-6), SR_C(1e-9), 0, 40, arm(&g, 2 * SR_NX), &st));
    ON_BOTH_MODELS("sr_retract (model)", SR_NX, sr_retract(M, x, d, arm(&g, SR_NX)));
    ON_BOTH_MODELS("sr_local (model)", SR_NE, sr_local(M, x, x, arm(&g, SR_NE)));
    ON_BOTH_MODELS("sr_retract_batch (model)", SR_NX, sr_retract_batch(M, 1, x, d, arm(&g, SR_NX), &row));
    ON_BOTH_MODELS("sr_local_batch (model)", SR_NE, sr_local_batch(M, 1, x, x, arm(&g, SR_NE), &row));
    ON_BOTH_MODELS("sr_accel_jacobian (model)", SR_NV * SR_NE, sr_accel_jacobian(M, x, u, arm(&g, SR_NV * SR_NE), arm(&g2, SR_NV * SR_NU)));
    ON_BOTH_MODELS("sr_accel_jacobian_batch (model)", SR_NV * SR_NE, sr_accel_jacobian_batch(M, 1, x, u, arm(&g, SR_NV * SR_NE), arm(&g2, SR_NV * SR_NU), &row));
    ON_BOTH_MODELS("sr_step_jacobian_lie_euler (model)", SR_NE * SR_NE, sr_step_jacobian_lie_euler(M, x, u, dt, arm(&g, SR_NE * SR_NE), arm(&g2, SR_NE * SR_NU)));
    ON_BOTH_MODELS("sr_step_jacobian_lie_euler_batch (model)", SR_NE * SR_NE, sr_step_jacobian_lie_euler_batch(M, 1, x, u, dt, arm(&g, SR_NE * SR_NE), arm(&g2, SR_NE * SR_NU), &row));
    ON_BOTH_MODELS("sr_step_jacobian_rkmk4 (model)", SR_NE * SR_NE, sr_step_jacobian_rkmk4(M, x, u, dt, arm(&g, SR_NE * SR_NE), arm(&g2, SR_NE * SR_NU)));
    ON_BOTH_MODELS("sr_step_jacobian_cf4 (model)", SR_NE * SR_NE, sr_step_jacobian_cf4(M, x, u, dt, arm(&g, SR_NE * SR_NE), arm(&g2, SR_NE * SR_NU)));
    ON_BOTH_MODELS("sr_step_jacobian (model)", SR_NE * SR_NE, sr_step_jacobian(M, method, x, u, dt, arm(&g, SR_NE * SR_NE), arm(&g2, SR_NE * SR_NU)));
    ON_BOTH_MODELS("sr_step_jacobian_batch (model)", SR_NE * SR_NE, sr_step_jacobian_batch(M, method, 1, x, u, dt, arm(&g, SR_NE * SR_NE), arm(&g2, SR_NE * SR_NU), &row));
    ON_BOTH_MODELS("sr_lqr_error (model)", SR_LQR_NZ, sr_lqr_error(M, x, &target, NULL, arm(&g, SR_LQR_NZ)));
    ON_BOTH_MODELS("sr_lqr_control (model)", SR_NU, sr_lqr_control(&lqr, M, x, &target, &memory, arm(&g, SR_NU), NULL));
    ON_BOTH_MODELS("sr_accel_param_jacobian (model)", SR_NV * SR_NPARAM, sr_accel_param_jacobian(M, x, u, arm(&g, SR_NV * SR_NPARAM)));
    ON_BOTH_MODELS("sr_accel_param_jacobian_batch (model)", SR_NV * SR_NPARAM, sr_accel_param_jacobian_batch(M, 1, x, u, arm(&g, SR_NV * SR_NPARAM), &row));
    ON_BOTH_MODELS("sr_step_param_jacobian (model)", SR_NE * SR_NPARAM, sr_step_param_jacobian(M, SR_RKMK4, x, u, dt, arm(&g, SR_NE * SR_NPARAM)));
    ON_BOTH_MODELS("sr_step_param_jacobian_batch (model)", SR_NE * SR_NPARAM, sr_step_param_jacobian_batch(M, SR_LIE_EULER, 1, x, u, dt, arm(&g, SR_NE * SR_NPARAM), &row));
    ON_BOTH_MODELS("sr_regressor (model)", SR_NV * SR_NPI, sr_regressor(M, x, mount_nu_dot, arm(&g, SR_NV * SR_NPI)));
    ON_BOTH_MODELS("sr_regressor_batch (model)", SR_NV * SR_NPI, sr_regressor_batch(M, 1, x, mount_nu_dot, arm(&g, SR_NV * SR_NPI), &row));
    ON_BOTH_MODELS("sr_nmpc_node (model)", SR_NMPC_NZ, sr_nmpc_node(M, nmpc_z, nmpc_u, SR_C(0.3), SR_C(0.5), dt, arm(&g, SR_NMPC_NZ), arm(&g2, SR_NMPC_NZ * SR_NMPC_NZ), arm(&g3, SR_NMPC_NZ * SR_NU)));

    /* the sensors (sr_sensors.h), on a valid mount: a lever arm along the body's -z, its axes */
    ON_BOTH_MODELS("sr_imu_measure (model)", SR_NIMU, sr_imu_measure(M, x, mount_nu_dot, SR_BODY_yoke, mount, NULL, arm(&g, SR_NIMU)));
    ON_BOTH_MODELS("sr_imu_measure_u (model)", SR_NIMU, sr_imu_measure_u(M, x, u, SR_BODY_pendulum, mount, NULL, arm(&g, SR_NIMU)));
    ON_BOTH_MODELS("sr_imu_partials (model)", SR_NIMU * SR_NEB, sr_imu_partials(M, x, mount_nu_dot, SR_BODY_shell, mount, NULL, arm(&g3, SR_NIMU), arm(&g, SR_NIMU * SR_NEB), arm(&g2, SR_NIMU * SR_NV)));
    ON_BOTH_MODELS("sr_imu_jacobian (model)", SR_NIMU * SR_NEB, sr_imu_jacobian(M, x, u, SR_BODY_yoke, mount, NULL, arm(&g3, SR_NIMU), arm(&g, SR_NIMU * SR_NEB)));
    ON_BOTH_MODELS("sr_encoders_measure (model)", 2, sr_encoders_measure(M, x, arm(&g, 2)));
    ON_BOTH_MODELS("sr_encoders_jacobian (model)", 2 * SR_NEB, sr_encoders_jacobian(M, x, arm(&g3, 2), arm(&g, 2 * SR_NEB)));
    ON_BOTH_MODELS("sr_position_measure (model)", 2, sr_position_measure(M, x, arm(&g, 2)));
    ON_BOTH_MODELS("sr_position_jacobian (model)", 2 * SR_NEB, sr_position_jacobian(M, x, arm(&g3, 2), arm(&g, 2 * SR_NEB)));
    ON_BOTH_MODELS("sr_heading_measure (model)", 1, sr_heading_measure(M, x, SR_BODY_yoke, mount, arm(&g, 1)));
    ON_BOTH_MODELS("sr_heading_jacobian (model)", SR_NEB, sr_heading_jacobian(M, x, SR_BODY_yoke, mount, arm(&g3, 1), arm(&g, SR_NEB)));
}

/* ---- the target ------------------------------------------------------------------------------ */
/* ---- the sensors (sr_sensors.h): a body code (sometimes out of range), a mount whose rotation is
 * a valid one unless a pick perturbs it, nu_dot and biases (or NULL biases).  Contract: documented
 * status; outputs finite on SR_OK and untouched otherwise. */
static void fuzz_sensors(reader *r, const sr_model *model, const sr_real x[SR_NX], const sr_real *u)
{
    static guarded g, g2, g3;
    sr_real mount[SR_NMOUNT], nu_dot[SR_NV], bias[SR_NBIAS], R[9], S[9];
    const sr_real *bias_or_null;
    int i, status;
    const unsigned b = read_u8(r);
    const int body = b % 16 == 15 ? (int)(b / 16) - 8 : (int)(b % SR_NBODY);
    for (i = 0; i < 3; ++i) mount[SR_MOUNT_lever + i] = pick(r, 0.1 * unit(r));
    rot_axis(0, 3.2 * unit(r), R);
    rot_axis(2, 3.2 * unit(r), S);
    for (i = 0; i < 9; ++i) {
        const int row = i / 3, col = i % 3;
        const double v = (double)(R[3 * row] * S[col] + R[3 * row + 1] * S[3 + col] + R[3 * row + 2] * S[6 + col]);
        mount[SR_MOUNT_R_m + i] = pick(r, v);
    }
    for (i = 0; i < SR_NV; ++i) nu_dot[i] = pick(r, 20.0 * unit(r));
    for (i = 0; i < SR_NBIAS; ++i) bias[i] = pick(r, 0.1 * unit(r));
    bias_or_null = read_u8(r) % 4 == 3 ? NULL : bias;

    status = sr_check_mount(body, mount);
    EXPECT_STATUS("sr_check_mount", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION);
    status = sr_imu_measure(model, x, nu_dot, body, mount, bias_or_null, arm(&g, SR_NIMU));
    EXPECT_STATUS("sr_imu_measure", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT, SR_ERR_ARG);
    expect("sr_imu_measure", status, &g, status == SR_OK ? SR_NIMU : 0, 1);
    status = sr_imu_measure_u(model, x, u, body, mount, bias_or_null, arm(&g, SR_NIMU));
    EXPECT_STATUS("sr_imu_measure_u", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                  SR_ERR_ARG, SR_ERR_SINGULAR);
    expect("sr_imu_measure_u", status, &g, status == SR_OK ? SR_NIMU : 0, 1);
    status = sr_imu_partials(model, x, nu_dot, body, mount, bias_or_null, arm(&g, SR_NIMU), arm(&g2, SR_NIMU * SR_NEB),
                             arm(&g3, SR_NIMU * SR_NV));
    EXPECT_STATUS("sr_imu_partials", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT, SR_ERR_ARG);
    expect("sr_imu_partials", status, &g, status == SR_OK ? SR_NIMU : 0, 1);
    expect("sr_imu_partials", status, &g2, status == SR_OK ? SR_NIMU * SR_NEB : 0, 1);
    expect("sr_imu_partials", status, &g3, status == SR_OK ? SR_NIMU * SR_NV : 0, 1);
    status = sr_imu_jacobian(model, x, u, body, mount, bias_or_null, arm(&g, SR_NIMU), arm(&g2, SR_NIMU * SR_NEB));
    EXPECT_STATUS("sr_imu_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                  SR_ERR_ARG, SR_ERR_SINGULAR);
    expect("sr_imu_jacobian", status, &g, status == SR_OK ? SR_NIMU : 0, 1);
    expect("sr_imu_jacobian", status, &g2, status == SR_OK ? SR_NIMU * SR_NEB : 0, 1);
    status = sr_heading_measure(model, x, body, mount, arm(&g, 1));
    EXPECT_STATUS("sr_heading_measure", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                  SR_ERR_ARG, SR_ERR_SINGULAR);
    expect("sr_heading_measure", status, &g, status == SR_OK ? 1 : 0, 1);
    status = sr_heading_jacobian(model, x, body, mount, arm(&g, 1), arm(&g2, SR_NEB));
    EXPECT_STATUS("sr_heading_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                  SR_ERR_ARG, SR_ERR_SINGULAR);
    expect("sr_heading_jacobian", status, &g, status == SR_OK ? 1 : 0, 1);
    expect("sr_heading_jacobian", status, &g2, status == SR_OK ? SR_NEB : 0, 1);
    status = sr_encoders_jacobian(model, x, arm(&g, 2), arm(&g2, 2 * SR_NEB));
    EXPECT_STATUS("sr_encoders_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
    expect("sr_encoders_jacobian", status, &g, status == SR_OK ? 2 : 0, 1);
    expect("sr_encoders_jacobian", status, &g2, status == SR_OK ? 2 * SR_NEB : 0, 1);
    status = sr_encoders_measure(model, x, arm(&g, 2));
    EXPECT_STATUS("sr_encoders_measure", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
    expect("sr_encoders_measure", status, &g, status == SR_OK ? 2 : 0, 1);
    status = sr_position_jacobian(model, x, arm(&g, 2), arm(&g2, 2 * SR_NEB));
    EXPECT_STATUS("sr_position_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
    expect("sr_position_jacobian", status, &g, status == SR_OK ? 2 : 0, 1);
    expect("sr_position_jacobian", status, &g2, status == SR_OK ? 2 * SR_NEB : 0, 1);
    status = sr_position_measure(model, x, arm(&g, 2));
    EXPECT_STATUS("sr_position_measure", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
    expect("sr_position_measure", status, &g, status == SR_OK ? 2 : 0, 1);
}

/* The filter: every sr_ekf_* entry point gives a documented status; on error the filter is byte for
 * byte what it was, on SR_OK its x, biases and P are finite. */
static void check_ekf(const char *fn, int status, const sr_ekf *ekf, const sr_ekf *before)
{
    int i;
    if (status != SR_OK) {
        if (memcmp(ekf, before, sizeof *ekf) != 0) fail(fn, status, "changed the filter on error");
        return;
    }
    for (i = 0; i < SR_NX; ++i)
        if (!isfinite(ekf->x[i])) fail(fn, status, "non-finite state with SR_OK");
    for (i = 0; i < SR_NBIAS; ++i)
        if (!isfinite(ekf->bias[i])) fail(fn, status, "non-finite bias with SR_OK");
    for (i = 0; i < SR_NEB * SR_NEB; ++i)
        if (!isfinite(ekf->P[i])) fail(fn, status, "non-finite covariance with SR_OK");
}

static void fuzz_ekf(reader *r, const sr_model *model, const sr_real x[SR_NX], const sr_real *u)
{
    static sr_ekf ekf, before;
    static sr_real P0[SR_NEB * SR_NEB];
    sr_real sigma[SR_NEB], bias[SR_NBIAS], mount[SR_NMOUNT], y[SR_NIMU], sigma_axes[SR_NIMU], dt, noise, gate;
    sr_ekf_process q;
    const sr_real gates[4] = {SR_C(13.8), SR_C(1.0), (sr_real)INFINITY, SR_C(-1.0)};
    int i, k, status, slot;
    const unsigned b = read_u8(r);
    const int body = b % 16 == 15 ? (int)(b / 16) - 8 : (int)(b % SR_NBODY);

    for (i = 0; i < SR_NEB; ++i) sigma[i] = pick(r, 0.001 + 0.1 * fabs(unit(r)));
    for (i = 0; i < SR_NBIAS; ++i) bias[i] = pick(r, 0.05 * unit(r));
    memset(&ekf, CANARY, sizeof ekf);
    memcpy(&before, &ekf, sizeof ekf);
    status = sr_ekf_init_diagonal(&ekf, model, x, read_u8(r) % 4 == 3 ? NULL : bias, sigma);
    EXPECT_STATUS("sr_ekf_init_diagonal", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                  SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
    check_ekf("sr_ekf_init_diagonal", status, &ekf, &before);
    /* sr_ekf_init with a covariance perturbed in one entry (asymmetric, indefinite or not finite) */
    memset(P0, 0, sizeof P0);
    for (i = 0; i < SR_NEB; ++i) P0[SR_NEB * i + i] = SR_C(1e-4);
    i = (int)(read_u8(r) % (SR_NEB * SR_NEB));
    P0[i] = pick(r, (double)P0[i]);
    memcpy(&before, &ekf, sizeof ekf);
    status = sr_ekf_init(&ekf, model, x, bias, P0);
    EXPECT_STATUS("sr_ekf_init", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                  SR_ERR_SINGULAR);
    check_ekf("sr_ekf_init", status, &ekf, &before);
    EXPECT_STATUS("sr_ekf_init(NULL)", sr_ekf_init(NULL, model, x, bias, P0), SR_ERR_NULL);
    if (status != SR_OK) return;
    /* the observability constraint on half the time, an invalid switch (2) now and then */
    k = (int)(read_u8(r) % 4);
    memcpy(&before, &ekf, sizeof ekf);
    status = sr_ekf_set_observability_constraint(&ekf, model, k == 3 ? 2 : k % 2);
    EXPECT_STATUS("sr_ekf_set_observability_constraint", status, SR_OK, SR_ERR_ARG);
    check_ekf("sr_ekf_set_observability_constraint", status, &ekf, &before);

    for (k = 0; k < 3; ++k) {
        const unsigned what = read_u8(r);
        int method = (int)(read_u8(r) % 3);
        if (what % 32 == 31) method = 9; /* an unknown method */
        dt = pick(r, 0.002 + 0.02 * fabs(unit(r)));
        for (i = 0; i < 3; ++i) q.torque_psd[i] = pick(r, 0.01);
        q.gyro_bias_rw = pick(r, 1e-4);
        q.accel_bias_rw = pick(r, 1e-3);
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_predict(&ekf, model, method, u, dt, &q);
        EXPECT_STATUS("sr_ekf_predict", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_predict", status, &ekf, &before);

        slot = (int)(read_u8(r) % (SR_EKF_NDELAYED + 2)) - 1; /* -1 .. SR_EKF_NDELAYED */
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_mark_position(&ekf, model, slot);
        EXPECT_STATUS("sr_ekf_mark_position", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT);
        check_ekf("sr_ekf_mark_position", status, &ekf, &before);

        for (i = 0; i < 3; ++i) mount[SR_MOUNT_lever + i] = pick(r, 0.05 * unit(r));
        for (i = 0; i < 9; ++i) mount[SR_MOUNT_R_m + i] = pick(r, i % 4 == 0 ? 1.0 : 0.0);
        for (i = 0; i < SR_NIMU; ++i) y[i] = pick(r, (i == SR_NIMU - 1 ? 9.81 : 0.0) + 0.5 * unit(r));
        noise = pick(r, 0.01 + 0.1 * fabs(unit(r)));
        gate = gates[read_u8(r) % 4];
        if (read_u8(r) % 8 == 7) gate = (sr_real)NAN;
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_update_imu(&ekf, model, y, u, body, mount, noise, noise, gate);
        EXPECT_STATUS("sr_ekf_update_imu", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_update_imu", status, &ekf, &before);
        /* a σ per reading, any of them perturbed (zero, negative, NaN, huge): the axes' own check */
        for (i = 0; i < SR_NIMU; ++i) sigma_axes[i] = pick(r, 0.01 + 0.1 * fabs(unit(r)));
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_update_imu_axes(&ekf, model, y, u, body, mount, sigma_axes, gate);
        EXPECT_STATUS("sr_ekf_update_imu_axes", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_update_imu_axes", status, &ekf, &before);
        /* the held disturbance: a fuzzed hold (zero, negative, NaN, huge) and process noise; a
         * disturbance held on from an earlier sample then rides through the next predicts */
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_update_imu_held(&ekf, model, y, u, body, mount, sigma_axes, &q,
                                        pick(r, 0.005 + 0.02 * fabs(unit(r))), gate);
        EXPECT_STATUS("sr_ekf_update_imu_held", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_update_imu_held", status, &ekf, &before);
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_update_encoders(&ekf, model, y, noise, gate);
        EXPECT_STATUS("sr_ekf_update_encoders", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_update_encoders", status, &ekf, &before);
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_update_position(&ekf, model, y + 2, noise, gate);
        EXPECT_STATUS("sr_ekf_update_position", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_update_position", status, &ekf, &before);
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_update_heading(&ekf, model, y[0], body, mount, noise, gate);
        EXPECT_STATUS("sr_ekf_update_heading", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_update_heading", status, &ekf, &before);
        slot = (int)(read_u8(r) % (SR_EKF_NDELAYED + 2)) - 1;
        memcpy(&before, &ekf, sizeof ekf);
        status = sr_ekf_update_position_delayed(&ekf, model, slot, y + 3, noise, gate);
        EXPECT_STATUS("sr_ekf_update_position_delayed", status, SR_OK, SR_ERR_ARG, SR_ERR_NONFINITE,
                      SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        check_ekf("sr_ekf_update_position_delayed", status, &ekf, &before);
    }
    EXPECT_STATUS("sr_ekf_predict(NULL)", sr_ekf_predict(&ekf, model, SR_RKMK4, u, SR_C(0.005), NULL), SR_ERR_NULL);
    EXPECT_STATUS("sr_ekf_mark_position(NULL)", sr_ekf_mark_position(NULL, model, 0), SR_ERR_NULL);
    memcpy(&before, &ekf, sizeof ekf);
    status = sr_ekf_update_imu_axes(&ekf, model, y, u, SR_BODY_yoke, mount, NULL, SR_C(13.8));
    EXPECT_STATUS("sr_ekf_update_imu_axes(NULL)", status, SR_ERR_NULL);
    check_ekf("sr_ekf_update_imu_axes(NULL)", status, &ekf, &before);
    EXPECT_STATUS("sr_ekf_update_position_delayed(NULL)",
                  sr_ekf_update_position_delayed(&ekf, model, 0, NULL, SR_C(0.01), SR_C(1.0)), SR_ERR_NULL);
    memcpy(&before, &ekf, sizeof ekf);
    status = sr_ekf_update_imu_held(&ekf, model, y, u, SR_BODY_yoke, mount, sigma_axes, NULL, SR_C(0.005), SR_C(13.8));
    EXPECT_STATUS("sr_ekf_update_imu_held(NULL)", status, SR_ERR_NULL);
    check_ekf("sr_ekf_update_imu_held(NULL)", status, &ekf, &before);
}

/* ---- the slope estimate and the law with offsets: sr_slope_init, sr_slope_weigh, sr_slope_reset,
 * sr_slope_update, sr_lqr_control_offsets ------------------------------------------------------
 * The estimator for the model's parameters with one of them picked, a fuzzed period (mostly one
 * 5 ms prediction step, for speed) and time constant, a fuzzed prior scale, sometimes a reset, then
 * two samples (x, then x with one entry picked, under fuzzed torques).  Contract: documented status;
 * the estimator byte for byte as it was on every error (its scratch trajectory aside) and never
 * written by a failed sr_slope_init; on SR_OK its offsets and pendulum damping finite.  Then
 * sr_lqr_control_offsets on a 1 x 1 schedule of fuzzed gains, operating point and feedforward
 * tables (the pendulum's sometimes NULL, its share picked), with the estimate's offsets, fuzzed
 * ones or NULL: documented status, u and u_raw finite with |u| <= u_max on SR_OK and untouched
 * otherwise, the memory untouched on error. */
static void check_slope(const char *fn, int status, const sr_slope_estimator *est, const sr_slope_estimator *before)
{
    int k;
    if (status != SR_OK) {
        static sr_slope_estimator same;   /* 16 KB: not on the stack */
        same = *est;
        memcpy(same.work, before->work, sizeof same.work);
        if (memcmp(&same, before, sizeof same) != 0) fail(fn, status, "changed the estimator on error");
        return;
    }
    for (k = 0; k < 2; ++k)
        if (!isfinite(est->offsets.slope[k]) || !isfinite(est->offsets.torque_offset[k]))
            fail(fn, status, "a non-finite slope or torque offset with SR_OK");
    for (k = 0; k < SR_LQR_NPENDULUM; ++k)
        if (!isfinite(est->offsets.pendulum[k])) fail(fn, status, "a non-finite pendulum offset with SR_OK");
    if (!isfinite(est->pendulum_damping)) fail(fn, status, "a non-finite pendulum damping with SR_OK");
}

static void fuzz_slope(reader *r, const sr_model *model, const sr_real x[SR_NX], const sr_real *u)
{
    static sr_slope_estimator est, before;
    static sr_lqr lqr;
    static sr_lqr_slope_table slope;
    static sr_lqr_pendulum_table pendulum;
    static guarded gu, gr;
    const sr_lqr_target target = {SR_C(0.3), SR_C(0.5), SR_C(0.2), SR_C(0.05), 1};
    sr_real p[SR_NPARAM], x1[SR_NX], u1[SR_NU], period, time_constant, prior;
    sr_lqr_offsets fuzzed;
    const sr_lqr_offsets *offsets;
    sr_lqr_memory memory, kept;
    int i, j, k, status, sample;

    memcpy(p, model->p, sizeof p);
    i = (int)(read_u8(r) % SR_NPARAM);
    p[i] = pick(r, (double)p[i]);
    period = pick(r, read_u8(r) % 8 == 7 ? 0.02 : 0.005);
    time_constant = pick(r, 5.0);
    prior = pick(r, read_u8(r) % 2 ? 1.0 : 0.0);
    memset(&est, CANARY, sizeof est);
    before = est;
    status = sr_slope_init(&est, p, period, time_constant);
    EXPECT_STATUS("sr_slope_init", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_ARG, SR_ERR_PARAM, SR_ERR_SINGULAR);
    if (status != SR_OK && memcmp(&est, &before, sizeof est) != 0) fail("sr_slope_init", status, "wrote the estimator on error");
    if (status != SR_OK && sr_slope_init(&est, model->p, SR_C(0.005), SR_C(5.0)) != SR_OK) return; /* a model at a rule's edge */
    EXPECT_STATUS("sr_slope_init(NULL)", sr_slope_init(NULL, p, period, time_constant), SR_ERR_NULL);
    before = est;
    status = sr_slope_init(&est, NULL, period, time_constant);
    EXPECT_STATUS("sr_slope_init(NULL params)", status, SR_ERR_NULL);
    if (memcmp(&est, &before, sizeof est) != 0) fail("sr_slope_init(NULL params)", status, "wrote the estimator on error");

    status = sr_slope_weigh(&est, prior);
    EXPECT_STATUS("sr_slope_weigh", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_ARG);
    check_slope("sr_slope_weigh", status, &est, &before);
    EXPECT_STATUS("sr_slope_weigh(NULL)", sr_slope_weigh(NULL, SR_C(1.0)), SR_ERR_NULL);
    if (read_u8(r) % 4 == 3) {
        EXPECT_STATUS("sr_slope_reset", sr_slope_reset(&est), SR_OK);
        if (est.started || est.offsets.slope[0] != 0 || est.offsets.torque_offset[1] != 0 || est.pendulum_damping != 0)
            fail("sr_slope_reset", SR_OK, "left the estimate unzeroed");
    }
    EXPECT_STATUS("sr_slope_reset(NULL)", sr_slope_reset(NULL), SR_ERR_NULL);

    memcpy(x1, x, sizeof x1);
    i = (int)(read_u8(r) % SR_NX);
    x1[i] = pick(r, (double)x1[i]);
    for (sample = 0; sample < 2; ++sample) {   /* the first stores the state, the second predicts from it */
        for (k = 0; k < SR_NU; ++k) u1[k] = u ? pick(r, (double)u[k]) : 0;
        before = est;
        status = sr_slope_update(&est, sample ? x1 : x, u1);
        EXPECT_STATUS("sr_slope_update", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                      SR_ERR_SINGULAR, SR_ERR_ARG);
        check_slope("sr_slope_update", status, &est, &before);
    }
    before = est;
    EXPECT_STATUS("sr_slope_update(NULL)", sr_slope_update(NULL, x, u1), SR_ERR_NULL);
    EXPECT_STATUS("sr_slope_update(NULL x)", sr_slope_update(&est, NULL, u1), SR_ERR_NULL);
    EXPECT_STATUS("sr_slope_update(NULL u)", sr_slope_update(&est, x, NULL), SR_ERR_NULL);
    check_slope("sr_slope_update(NULL)", SR_ERR_NULL, &est, &before);

    /* the law with offsets on a 1 x 1 schedule */
    memset(&lqr, 0, sizeof lqr);
    lqr.n_speeds = lqr.n_curvatures = 1;
    lqr.period = SR_C(0.01);
    lqr.u_max = pick(r, 0.5);
    lqr.steady_rate = SR_C(0.005);
    lqr.slope = &slope;
    lqr.pendulum = read_u8(r) % 4 == 3 ? NULL : &pendulum;
    lqr.pendulum_share = pick(r, 1.0);
    for (j = 0; j < SR_LQR_NZ; ++j) lqr.z_star[0][j] = pick(r, 0.1 * unit(r));
    for (j = 0; j < SR_NU; ++j) lqr.u_star[0][j] = pick(r, 0.1 * unit(r));
    for (j = 0; j < SR_NU * SR_LQR_NZ; ++j) lqr.K_path[0][j] = pick(r, 2.0 * unit(r));
    for (j = 0; j < SR_NU * SR_LQR_NZ; ++j) lqr.K_heading[0][j] = pick(r, 2.0 * unit(r));
    for (j = 0; j < SR_LQR_NZ; ++j) {
        slope.dz_up[0][j] = pick(r, unit(r));
        slope.dz_right[0][j] = pick(r, unit(r));
        for (k = 0; k < SR_LQR_NPENDULUM; ++k) pendulum.dz[0][k][j] = pick(r, unit(r));
    }
    for (j = 0; j < SR_NU; ++j) {
        slope.du_up[0][j] = pick(r, unit(r));
        slope.du_right[0][j] = pick(r, unit(r));
        for (k = 0; k < SR_LQR_NPENDULUM; ++k) pendulum.du[0][k][j] = pick(r, unit(r));
    }
    fuzzed = est.offsets;
    for (k = 0; k < 2; ++k) {
        fuzzed.slope[k] = pick(r, (double)fuzzed.slope[k]);
        fuzzed.torque_offset[k] = pick(r, (double)fuzzed.torque_offset[k]);
    }
    for (k = 0; k < SR_LQR_NPENDULUM; ++k) fuzzed.pendulum[k] = pick(r, (double)fuzzed.pendulum[k]);
    k = (int)(read_u8(r) % 4);
    offsets = k == 3 ? NULL : k == 2 ? &fuzzed : &est.offsets;
    EXPECT_STATUS("sr_lqr_reset", sr_lqr_reset(&memory), SR_OK);
    for (sample = 0; sample < 2; ++sample) {
        kept = memory;
        status = sr_lqr_control_offsets(&lqr, model, sample ? x1 : x, &target, offsets, &memory, arm(&gu, SR_NU),
                                        arm(&gr, SR_NU));
        EXPECT_STATUS("sr_lqr_control_offsets", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_ARG);
        expect("sr_lqr_control_offsets", status, &gu, status == SR_OK ? SR_NU : 0, 1);
        expect("sr_lqr_control_offsets", status, &gr, status == SR_OK ? SR_NU : 0, 1);
        if (status == SR_OK) {
            for (j = 0; j < SR_NU; ++j)
                if (!(fabs((double)gu.buf[GUARD + j]) <= (double)lqr.u_max))
                    fail("sr_lqr_control_offsets", status, "torque beyond u_max");
        } else if (memcmp(&kept, &memory, sizeof memory) != 0) {
            fail("sr_lqr_control_offsets", status, "changed the memory on error");
        }
    }
    EXPECT_STATUS("sr_lqr_control_offsets(NULL)",
                  sr_lqr_control_offsets(&lqr, model, x, &target, offsets, NULL, arm(&gu, SR_NU), NULL), SR_ERR_NULL);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader rd = {data, size};
    sr_model model, fallback;
    sr_real p[SR_NPARAM], raw_p[SR_NPARAM], x[SR_NX], x2[2 * SR_NX], u[MAX_STEPS * SR_NU], dt;
    const sr_real *u_or_null;
    static guarded g; /* static: too large for some stacks, and the harness is single-threaded */
    long done, row;
    int status, method, steps, i;

    /* sr_model_init: untouched on error */
    read_params(&rd, p);
    memcpy(raw_p, p, sizeof p); /* the batch below gets them even when they are invalid */
    memset(&model, CANARY, sizeof model);
    status = sr_model_init(&model, p);
    EXPECT_STATUS("sr_model_init", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_PARAM, SR_ERR_SINGULAR);
    { /* sr_check_params is sr_model_init's range verdict */
        int bad = -7, rule = -7;
        const int verdict = sr_check_params(p, &bad, &rule);
        if (verdict != SR_OK ? verdict != status : status == SR_ERR_NONFINITE)
            fail("sr_check_params", verdict, "disagrees with sr_model_init");
        if ((verdict == SR_OK) != (bad == -1 && rule == SR_PARAM_RULE_NONE) || bad < -1 || bad >= SR_NPARAM)
            fail("sr_check_params", verdict, "bad index or rule");
    }
    if (status != SR_OK) {
        const unsigned char *b = (const unsigned char *)&model;
        for (i = 0; i < (int)sizeof model; ++i)
            if (b[i] != CANARY) fail("sr_model_init", status, "wrote the model on error");
        static const double paper[SR_NPAPER] = {
            [SR_PAPER_r] = 0.3, [SR_PAPER_m_S] = 2, [SR_PAPER_k_S] = 0.16, [SR_PAPER_b] = 0.2,
            [SR_PAPER_h] = 0.5, [SR_PAPER_m_b] = 2, [SR_PAPER_m_h] = 5, [SR_PAPER_k_Y] = 0.04,
            [SR_PAPER_l] = 0.2, [SR_PAPER_m_P] = 1, [SR_PAPER_k_P] = 0.1, [SR_PAPER_g] = 9.81};
        sr_real pp[SR_NPAPER];
        for (i = 0; i < SR_NPAPER; ++i) pp[i] = (sr_real)paper[i];
        if (sr_paper_params(pp, p) != SR_OK || sr_model_init(&fallback, p) != SR_OK) abort();
        model = fallback; /* keep fuzzing the state paths */
    } else {
        for (i = 0; i < SR_GEN_NCONST && !model.general; ++i)
            if (!isfinite(model.c[i])) fail("sr_model_init", status, "non-finite constant with SR_OK");
        for (i = 0; i < SR_GEN_GENERAL_NCONST && model.general; ++i)
            if (!isfinite(model.cg[i])) fail("sr_model_init", status, "non-finite constant with SR_OK");
    }

    read_state(&rd, model.p[SR_P_r], x);
    for (i = 0; i < MAX_STEPS * SR_NU; ++i) u[i] = pick(&rd, 0.3 * unit(&rd));
    u_or_null = read_u8(&rd) % 4 == 3 ? NULL : u;
    dt = pick(&rd, 0.002 + 0.05 * fabs(unit(&rd)));
    method = (int)(read_u8(&rd) % 3);
    {
        const unsigned c = read_u8(&rd);
        if (c % 2) method |= SR_PROJECT;
        if (c % 32 == 31) method = (int)(c * 12345u); /* an unknown method */
    }
    steps = (int)(read_u8(&rd) % (MAX_STEPS + 2)) - 1; /* -1 .. MAX_STEPS */

    status = sr_check_state(&model, x);
    EXPECT_STATUS("sr_check_state", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);

    /* single-state kernels: all or nothing, finite on SR_OK */
    status = sr_accel(&model, x, u_or_null, arm(&g, SR_NV));
    EXPECT_STATUS("sr_accel", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_SINGULAR);
    expect("sr_accel", status, &g, status == SR_OK ? SR_NV : 0, 1);
    status = sr_rhs(&model, x, u_or_null, arm(&g, SR_NV));
    EXPECT_STATUS("sr_rhs", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION);
    expect("sr_rhs", status, &g, status == SR_OK ? SR_NV : 0, 1);
    status = sr_inertia(&model, x, arm(&g, SR_NV * SR_NV));
    EXPECT_STATUS("sr_inertia", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION);
    expect("sr_inertia", status, &g, status == SR_OK ? SR_NV * SR_NV : 0, 1);
    status = sr_energy(&model, x, arm(&g, 1));
    EXPECT_STATUS("sr_energy", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION);
    expect("sr_energy", status, &g, status == SR_OK ? 1 : 0, 1);
    status = sr_equilibrium_residual(&model, x, arm(&g, SR_NV));
    EXPECT_STATUS("sr_equilibrium_residual", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION);
    expect("sr_equilibrium_residual", status, &g, status == SR_OK ? SR_NV : 0, 1);
    status = sr_so3_exp(x + SR_X_w_S, arm(&g, 9));
    EXPECT_STATUS("sr_so3_exp", status, SR_OK, SR_ERR_NONFINITE);
    expect("sr_so3_exp", status, &g, status == SR_OK ? 9 : 0, 1);
    {
        /* the library's atan2: an angle in [-pi, pi] for two finite arguments, SR_ERR_NONFINITE otherwise */
        const sr_real ay = pick(&rd, 0.3), ax = pick(&rd, -0.7);
        sr_real angle = SR_C(9.0);
        const int finite_in = ay - ay == 0 && ax - ax == 0;
        status = sr_atan2(ay, ax, &angle);
        if (status != (finite_in ? SR_OK : SR_ERR_NONFINITE))
            fail("sr_atan2", status, finite_in ? "refused two finite arguments" : "accepted a NaN or an infinity");
        else if (finite_in ? !(angle >= -SR_C(3.1415927) && angle <= SR_C(3.1415927)) : angle != SR_C(9.0))
            fail("sr_atan2", status, finite_in ? "an angle outside [-pi, pi]" : "wrote its output on an error");
    }

    /* batches: two rows, the second a copy of x with one more perturbation */
    memcpy(x2, x, sizeof x);
    memcpy(x2 + SR_NX, x, sizeof x);
    i = (int)(read_u8(&rd) % SR_NX);
    x2[SR_NX + i] = pick(&rd, (double)x2[SR_NX + i]);
    status = sr_accel_batch(&model, 2, x2, u_or_null, arm(&g, 2 * SR_NV), &row);
    EXPECT_STATUS("sr_accel_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_SINGULAR);
    if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_accel_batch", status, "bad failed_row");
    expect("sr_accel_batch", status, &g, status == SR_OK ? 2 * SR_NV : (int)row * SR_NV, 1);
    status = sr_check_state_batch(&model, 2, x2, &row);
    EXPECT_STATUS("sr_check_state_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
    if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_check_state_batch", status, "bad failed_row");

    /* one step: all or nothing */
    status = sr_step(&model, method, x, u_or_null, dt, arm(&g, SR_NX));
    EXPECT_STATUS("sr_step", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                  SR_ERR_SINGULAR, SR_ERR_ARG);
    expect("sr_step", status, &g, status == SR_OK ? SR_NX : 0, 1);
    if (method == SR_LIE_EULER || method == SR_RKMK4 || method == SR_CF4) { /* = the per-method entry */
        sr_real via_step[SR_NX], fixed[SR_NX];
        const int want = sr_step(&model, method, x, u_or_null, dt, via_step);
        const int got = method == SR_LIE_EULER ? sr_step_lie_euler(&model, x, u_or_null, dt, fixed)
                      : method == SR_RKMK4     ? sr_step_rkmk4(&model, x, u_or_null, dt, fixed)
                                               : sr_step_cf4(&model, x, u_or_null, dt, fixed);
        if (got != want || (got == SR_OK && memcmp(via_step, fixed, sizeof fixed) != 0))
            fail("sr_step_<method>", got, "differs from sr_step");
    }

    /* simulations: rows 0..steps_done valid; nothing past row steps_done + 1 */
    {
        sr_energy_guard guard;
        const int rows = steps >= 0 ? steps + 1 : 1;
        int pass;
        for (pass = 0; pass < 2; ++pass) {
            const char *fn = pass ? "sr_simulate_guarded" : "sr_simulate";
            memset(&guard, 0, sizeof guard);
            guard.tol = pick(&rd, 0.5);
            done = -7;
            status = pass ? sr_simulate_guarded(&model, method, x, dt, steps, u_or_null, &guard, arm(&g, rows * SR_NX), &done)
                          : sr_simulate(&model, method, x, dt, steps, u_or_null, arm(&g, rows * SR_NX), &done);
            EXPECT_STATUS(fn, status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_SINGULAR, SR_ERR_ARG,
                          SR_ERR_CONSTRAINT, SR_ERR_ENERGY);
            if (status == SR_ERR_ENERGY && !pass) fail(fn, status, "energy guard without a guard");
            if (status == SR_OK) {
                if (done != steps) fail(fn, status, "steps_done != steps on success");
                expect(fn, status, &g, rows * SR_NX, 1);
            } else {
                if (done < 0 || done > (steps > 0 ? steps - 1 : 0))
                    fail(fn, status, "steps_done out of range on error");
                /* rows 0..done valid (finite), row done + 1 may be written, the rest untouched */
                for (i = 0; i < GUARD; ++i)
                    if (!is_canary(g.buf + i) || !is_canary(g.buf + GUARD + g.n + i)) fail(fn, status, "wrote outside its buffer");
                if (done > 0) /* x0 and every state that passed the finiteness check */
                    for (i = 0; i < (int)(done + 1) * SR_NX; ++i)
                        if (!isfinite(g.buf[GUARD + i])) fail(fn, status, "a valid row is not finite");
                for (i = (int)(done + 2) * SR_NX; i < rows * SR_NX; ++i)
                    if (!is_canary(g.buf + GUARD + i)) fail(fn, status, "wrote past the failing row");
            }
        }
    }

    /* adaptive: small limits */
    {
        sr_adaptive_stats st;
        const long n_out = (long)(read_u8(&rd) % (MAX_STEPS + 1));
        const sr_real rtol = pick(&rd, 1e-6), atol = pick(&rd, 1e-9), h0 = pick(&rd, 0.0);
        const long max_steps = (long)(read_u8(&rd) % 64);
        const int amethod = read_u8(&rd) % 4 == 0 ? method : SR_RKMK4 | (method & SR_PROJECT);
        status = sr_simulate_adaptive(&model, amethod, x, dt, n_out, u_or_null, rtol, atol, h0, max_steps,
                                      arm(&g, (int)(n_out + 1) * SR_NX), &st);
        EXPECT_STATUS("sr_simulate_adaptive", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_SINGULAR,
                      SR_ERR_ARG, SR_ERR_CONSTRAINT, SR_ERR_STEP_SIZE, SR_ERR_MAX_STEPS);
        if (st.rows_done < 0 || st.rows_done > n_out + 1) fail("sr_simulate_adaptive", status, "rows_done out of range");
        if (status == SR_OK && st.rows_done != n_out + 1) fail("sr_simulate_adaptive", status, "rows_done short on success");
        expect("sr_simulate_adaptive", status, &g, (int)st.rows_done * SR_NX, 1);
    }

    /* sr_simulate_batch: sample 0 the model's parameters and x, sample 1 the raw fuzzed parameters
     * and the perturbed second row of x2; every sample gets its own status, a failed sample's
     * final row stays untouched, arguments are refused before any sample runs */
    {
        sr_real bp[2 * SR_NPARAM], work[5 * SR_NX], metrics[2 * SR_BATCH_NMETRICS];
        int bstatus[2] = {-7, -7}, s;
        long bdone[2] = {-7, -7};
        const long chunk = (long)(read_u8(&rd) % 4) + 1; /* 1..4 steps per sr_simulate_guarded call */
        const sr_real tol = pick(&rd, 0.5);
        memcpy(bp, model.p, sizeof model.p);
        memcpy(bp + SR_NPARAM, raw_p, sizeof raw_p);
        status = sr_simulate_batch(method, 2, bp, SR_NPARAM, x2, SR_NX, dt, steps, u_or_null, 0, tol, chunk, work,
                                   NULL, arm(&g, 2 * SR_NX), metrics, bstatus, bdone);
        EXPECT_STATUS("sr_simulate_batch", status, SR_OK, SR_ERR_ARG);
        for (i = 0; i < GUARD; ++i)
            if (!is_canary(g.buf + i) || !is_canary(g.buf + GUARD + g.n + i))
                fail("sr_simulate_batch", status, "wrote outside its buffer");
        for (s = 0; s < 2; ++s) {
            const sr_real *row_out = g.buf + GUARD + s * SR_NX;
            if (status != SR_OK) {
                if (bstatus[s] != -7 || !is_canary(row_out)) fail("sr_simulate_batch", status, "ran a sample after refusing");
                continue;
            }
            EXPECT_STATUS("sr_simulate_batch sample", bstatus[s], SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                          SR_ERR_SINGULAR, SR_ERR_CONSTRAINT, SR_ERR_ENERGY, SR_ERR_PARAM);
            if (bstatus[s] == SR_OK) {
                if (bdone[s] != steps) fail("sr_simulate_batch", bstatus[s], "steps_done != steps on success");
                for (i = 0; i < SR_NX; ++i)
                    if (is_canary(row_out + i) || !isfinite(row_out[i])) fail("sr_simulate_batch", bstatus[s], "final row unwritten or not finite");
                for (i = 0; i < SR_BATCH_NMETRICS; ++i)
                    if (!isfinite(metrics[s * SR_BATCH_NMETRICS + i])) fail("sr_simulate_batch", bstatus[s], "non-finite metric");
            } else {
                /* steps_done = steps only when every step ran and the final energy overflowed */
                const long most = bstatus[s] == SR_ERR_NONFINITE ? steps : (steps > 0 ? steps - 1 : 0);
                if (bdone[s] < 0 || bdone[s] > most) fail("sr_simulate_batch", bstatus[s], "steps_done out of range");
                for (i = 0; i < SR_NX; ++i)
                    if (!is_canary(row_out + i)) fail("sr_simulate_batch", bstatus[s], "wrote a failed sample's final row");
            }
        }
    }

    /* The group, the derivatives and the batch steps; read last, so that the
     * inputs kept in fuzz/regressions/ still mean what they meant. */
    {
        static guarded g2;   /* a second output (G of a step Jacobian, Jb) */
        sr_real d[SR_NE], y[SR_NX];
        const int jmethod = read_u8(&rd) % 8 == 7 ? method : (int)(read_u8(&rd) % 3);
        for (i = 0; i < SR_NE; ++i) d[i] = pick(&rd, 0.5 * unit(&rd));

        status = sr_retract(&model, x, d, arm(&g, SR_NX));
        EXPECT_STATUS("sr_retract", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
        expect("sr_retract", status, &g, status == SR_OK ? SR_NX : 0, 1);
        memcpy(y, status == SR_OK ? g.buf + GUARD : x2 + SR_NX, sizeof y);
        status = sr_local(&model, x, y, arm(&g, SR_NE));
        EXPECT_STATUS("sr_local", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
        expect("sr_local", status, &g, status == SR_OK ? SR_NE : 0, 1);

        status = sr_accel_jacobian(&model, x, u_or_null, arm(&g, SR_NV * SR_NE), arm(&g2, SR_NV * SR_NU));
        EXPECT_STATUS("sr_accel_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_SINGULAR);
        expect("sr_accel_jacobian", status, &g, status == SR_OK ? SR_NV * SR_NE : 0, 1);
        expect("sr_accel_jacobian", status, &g2, status == SR_OK ? SR_NV * SR_NU : 0, 1);

        status = sr_step_jacobian(&model, jmethod, x, u_or_null, dt, arm(&g, SR_NE * SR_NE), arm(&g2, SR_NE * SR_NU));
        EXPECT_STATUS("sr_step_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                      SR_ERR_SINGULAR, SR_ERR_ARG);
        expect("sr_step_jacobian", status, &g, status == SR_OK ? SR_NE * SR_NE : 0, 1);
        expect("sr_step_jacobian", status, &g2, status == SR_OK ? SR_NE * SR_NU : 0, 1);

        /* two rows: all rows before the failing one written (finite), none after it */
        status = sr_step_batch(&model, method, 2, x2, u_or_null, dt, arm(&g, 2 * SR_NX), &row);
        EXPECT_STATUS("sr_step_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                      SR_ERR_SINGULAR, SR_ERR_ARG);
        /* SR_ERR_ARG (a bad method or dt) is refused before any row: failed_row -1 */
        if (status == SR_ERR_ARG ? row != -1 : ((status == SR_OK) != (row == -1) || row < -1 || row > 1))
            fail("sr_step_batch", status, "bad failed_row");
        expect("sr_step_batch", status, &g, status == SR_OK ? 2 * SR_NX : (row > 0 ? (int)row * SR_NX : 0), 1);
        if (status == SR_OK || row == 1) { /* each written row is sr_step's, bit for bit */
            sr_real one[SR_NX];
            if (sr_step(&model, method, x2, u_or_null, dt, one) != SR_OK || memcmp(one, g.buf + GUARD, sizeof one) != 0)
                fail("sr_step_batch", status, "row 0 differs from sr_step");
        }
        /* the batch forms of the Jacobians and of the group: rows before the failing one written */
        status = sr_accel_jacobian_batch(&model, 2, x2, u_or_null, arm(&g, 2 * SR_NV * SR_NE), arm(&g2, 2 * SR_NV * SR_NU), &row);
        EXPECT_STATUS("sr_accel_jacobian_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_SINGULAR);
        if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_accel_jacobian_batch", status, "bad failed_row");
        expect("sr_accel_jacobian_batch", status, &g, status == SR_OK ? 2 * SR_NV * SR_NE : (row > 0 ? (int)row * SR_NV * SR_NE : 0), 1);
        expect("sr_accel_jacobian_batch", status, &g2, status == SR_OK ? 2 * SR_NV * SR_NU : (row > 0 ? (int)row * SR_NV * SR_NU : 0), 1);
        status = sr_step_jacobian_batch(&model, jmethod, 2, x2, u_or_null, dt, arm(&g, 2 * SR_NE * SR_NE),
                                        arm(&g2, 2 * SR_NE * SR_NU), &row);
        EXPECT_STATUS("sr_step_jacobian_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT,
                      SR_ERR_SINGULAR, SR_ERR_ARG);
        /* SR_ERR_ARG: an unknown method or a bad dt is refused before any row (-1) */
        if (status == SR_ERR_ARG ? row != -1 : ((status == SR_OK) != (row == -1) || row < -1 || row > 1))
            fail("sr_step_jacobian_batch", status, "bad failed_row");
        expect("sr_step_jacobian_batch", status, &g, status == SR_OK ? 2 * SR_NE * SR_NE : (row > 0 ? (int)row * SR_NE * SR_NE : 0), 1);
        expect("sr_step_jacobian_batch", status, &g2, status == SR_OK ? 2 * SR_NE * SR_NU : (row > 0 ? (int)row * SR_NE * SR_NU : 0), 1);
        /* the parameter sensitivities and the regressor (nu_dot: the state's speeds, fuzzed with it) */
        status = sr_accel_param_jacobian(&model, x, u_or_null, arm(&g, SR_NV * SR_NPARAM));
        EXPECT_STATUS("sr_accel_param_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        expect("sr_accel_param_jacobian", status, &g, status == SR_OK ? SR_NV * SR_NPARAM : 0, 1);
        status = sr_step_param_jacobian(&model, jmethod, x, u_or_null, dt, arm(&g, SR_NE * SR_NPARAM));
        EXPECT_STATUS("sr_step_param_jacobian", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR, SR_ERR_ARG);
        expect("sr_step_param_jacobian", status, &g, status == SR_OK ? SR_NE * SR_NPARAM : 0, 1);
        status = sr_step_param_jacobian_batch(&model, jmethod, 2, x2, u_or_null, dt, arm(&g, 2 * SR_NE * SR_NPARAM), &row);
        EXPECT_STATUS("sr_step_param_jacobian_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR, SR_ERR_ARG);
        if (status == SR_ERR_ARG ? row != -1 : ((status == SR_OK) != (row == -1) || row < -1 || row > 1))
            fail("sr_step_param_jacobian_batch", status, "bad failed_row");
        expect("sr_step_param_jacobian_batch", status, &g, status == SR_OK ? 2 * SR_NE * SR_NPARAM
               : (row > 0 ? (int)row * SR_NE * SR_NPARAM : 0), 1);
        status = sr_accel_param_jacobian_batch(&model, 2, x2, u_or_null, arm(&g, 2 * SR_NV * SR_NPARAM), &row);
        EXPECT_STATUS("sr_accel_param_jacobian_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_accel_param_jacobian_batch", status, "bad failed_row");
        expect("sr_accel_param_jacobian_batch", status, &g, status == SR_OK ? 2 * SR_NV * SR_NPARAM
               : (row > 0 ? (int)row * SR_NV * SR_NPARAM : 0), 1);
        status = sr_regressor(&model, x, x + SR_X_w_S, arm(&g, SR_NV * SR_NPI));
        EXPECT_STATUS("sr_regressor", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
        expect("sr_regressor", status, &g, status == SR_OK ? SR_NV * SR_NPI : 0, 1);
        {
            sr_real a2[2 * SR_NV];
            memcpy(a2, x + SR_X_w_S, sizeof(sr_real) * SR_NV);
            memcpy(a2 + SR_NV, x + SR_X_w_S, sizeof(sr_real) * SR_NV);
            status = sr_regressor_batch(&model, 2, x2, a2, arm(&g, 2 * SR_NV * SR_NPI), &row);
            EXPECT_STATUS("sr_regressor_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
            if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_regressor_batch", status, "bad failed_row");
            expect("sr_regressor_batch", status, &g, status == SR_OK ? 2 * SR_NV * SR_NPI : (row > 0 ? (int)row * SR_NV * SR_NPI : 0), 1);
        }
        {
            sr_real d2[2 * SR_NE];
            memcpy(d2, d, sizeof d);
            memcpy(d2 + SR_NE, d, sizeof d);
            status = sr_retract_batch(&model, 2, x2, d2, arm(&g, 2 * SR_NX), &row);
            EXPECT_STATUS("sr_retract_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
            if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_retract_batch", status, "bad failed_row");
            expect("sr_retract_batch", status, &g, status == SR_OK ? 2 * SR_NX : (row > 0 ? (int)row * SR_NX : 0), 1);
            status = sr_local_batch(&model, 2, x2, x2, arm(&g, 2 * SR_NE), &row);
            EXPECT_STATUS("sr_local_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_CONSTRAINT);
            if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_local_batch", status, "bad failed_row");
            expect("sr_local_batch", status, &g, status == SR_OK ? 2 * SR_NE : (row > 0 ? (int)row * SR_NE : 0), 1);
        }
        status = sr_checked_accel_batch(&model, 2, x2, u_or_null, arm(&g, 2 * SR_NV), &row);
        EXPECT_STATUS("sr_checked_accel_batch", status, SR_OK, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION,
                      SR_ERR_CONSTRAINT, SR_ERR_SINGULAR);
        if ((status == SR_OK) != (row == -1) || row < -1 || row > 1) fail("sr_checked_accel_batch", status, "bad failed_row");
        expect("sr_checked_accel_batch", status, &g, status == SR_OK ? 2 * SR_NV : (row > 0 ? (int)row * SR_NV : 0), 1);
    }

    /* The controller; read last, for the same reason. */
    fuzz_controller(&rd, &model, x);

    /* The NMPC; read last, for the same reason. */
    fuzz_nmpc(&rd, &model, x);

    /* The sensors; read last, for the same reason. */
    fuzz_sensors(&rd, &model, x, u_or_null);
    fuzz_ekf(&rd, &model, x, u_or_null);

    /* NULL pointers */
    EXPECT_STATUS("sr_accel(NULL)", sr_accel(&model, x, u, NULL), SR_ERR_NULL);
    EXPECT_STATUS("sr_check_state(NULL)", sr_check_state(NULL, x), SR_ERR_NULL);

    /* The validity stamp (read last, for the same reason). */
    fuzz_model_validity(&rd, &model, x, u_or_null, dt, method);

    /* The slope estimate and the law with offsets: their own reader over the input from its start
     * (the parts above exhaust most inputs), after everything else (the kept inputs decode as before). */
    {
        reader again = {data, size};
        fuzz_slope(&again, &model, x, u_or_null);
    }
    return 0;
}
