/*
 * firmware_tshape.c -- a firmware-style simulator of the spherical robot: no
 * Python, no heap, a fixed-rate 100 Hz loop driven by a torque table.
 *
 * Scenario: the "t-shape" torque program of the paper's Section 5.3.3 as the
 * project runs it (see README, "Conventions"): physical torques in N m,
 * windows counted in steps of dt = 0.01 s, where step n advances the state
 * from t = (n-1) dt to t = n dt:
 *
 *     steps    1 -  800   yoke      +0.1 N m
 *     steps 1600 - 1900   pendulum  -0.1 N m
 *     steps 2500 - 3000   yoke      -0.1 N m
 *     steps 3400 - 4500   pendulum  +0.1 N m
 *
 * 10,000 steps (100 s) from rest with R_S = R_Y = R_P = I and q = (0, 0, r),
 * parameters runtime.Params.paper_simulation(), Lie-Euler (sr_step_lie_euler: linked with
 * --gc-sections, as `make example` does, the program contains no fourth-order stepper).
 *
 * Output (stdout): CSV, a header line then one row per sample (t = 0 and after
 * every step): t and the 35 state entries in the order of spherical_robot.h,
 * printed with %.17g so that a double build round-trips exactly.  In the double
 * build the rows equal, bit for bit,
 *     runtime.Model(runtime.Params.paper_simulation()).simulate(x0, 0.01, 10000, u)
 * (checked by tests/test_c_library.py).  Build: `make example` in c/.
 * Exit status 0 on success; on a kernel error, a message on stderr and 1.
 */
#include <stdio.h>

#include "spherical_robot.h"

#define DT SR_C(0.01)      /* control period [s]: 100 Hz (a float in the float build) */
#define DT_SECONDS 0.01    /* the same period as a double, for the time column */
#define N_STEPS 10000L     /* 100 s */

enum { JOINT_YOKE = SR_U_u_Y, JOINT_PENDULUM = SR_U_u_P }; /* index into u[SR_NU] */

/* One window of the torque program: `torque` on `joint` during steps first..last (inclusive). */
typedef struct torque_window {
    long first, last;
    int joint;
    sr_real torque; /* [N m] */
} torque_window;

static const torque_window TSHAPE_PROGRAM[] = {
    {1, 800, JOINT_YOKE, SR_C(0.1)},
    {1600, 1900, JOINT_PENDULUM, SR_C(-0.1)},
    {2500, 3000, JOINT_YOKE, SR_C(-0.1)},
    {3400, 4500, JOINT_PENDULUM, SR_C(0.1)},
};
#define N_WINDOWS (sizeof TSHAPE_PROGRAM / sizeof TSHAPE_PROGRAM[0])

/* runtime.Params.paper_simulation() (SI): the paper's twelve parameters, each value at its index
 * SR_PAPER_<name>; sr_paper_params turns them into the robot's parameters (SR_P_*). */
static const sr_real PAPER[SR_NPAPER] = {
    [SR_PAPER_r] = SR_C(0.3), [SR_PAPER_m_S] = SR_C(2.0), [SR_PAPER_k_S] = SR_C(0.16), [SR_PAPER_b] = SR_C(0.2),
    [SR_PAPER_h] = SR_C(0.5), [SR_PAPER_m_b] = SR_C(2.0), [SR_PAPER_m_h] = SR_C(5.0), [SR_PAPER_k_Y] = SR_C(0.04),
    [SR_PAPER_l] = SR_C(0.2), [SR_PAPER_m_P] = SR_C(1.0), [SR_PAPER_k_P] = SR_C(0.10), [SR_PAPER_g] = SR_C(9.81),
};

/* The motor torques held during step n (1-based). */
static void torque_program(long n, sr_real u[SR_NU])
{
    size_t k;
    u[JOINT_YOKE] = 0;
    u[JOINT_PENDULUM] = 0;
    for (k = 0; k < N_WINDOWS; ++k)
        if (n >= TSHAPE_PROGRAM[k].first && n <= TSHAPE_PROGRAM[k].last)
            u[TSHAPE_PROGRAM[k].joint] += TSHAPE_PROGRAM[k].torque;
}

/* On a target this would block until the next 100 Hz timer tick; the host runs flat out. */
static void wait_for_tick(void) {}

static void print_header(void)
{
    static const char *const blocks[] = {"RS", "RY", "RP"};
    int b, i, j;
    printf("t");
    for (b = 0; b < 3; ++b)
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) printf(",%s_%d%d", blocks[b], i, j);
    printf(",q_x,q_y,q_z,w_Sx,w_Sy,w_Sz,w_Y,w_P\n");
}

static void print_row(double t, const sr_real x[SR_NX])
{
    int i;
    printf("%.17g", t);
    for (i = 0; i < SR_NX; ++i) printf(",%.17g", (double)x[i]);
    putchar('\n');
}

int main(void)
{
    sr_model model;
    sr_real x[SR_NX] = {0}, u[SR_NU], params[SR_NPARAM];
    long n;
    int status;

    /* Initial state: at rest, all rotations identity, centre at q = (0, 0, r). */
    for (n = 0; n < 3; ++n) x[SR_X_R_S + 4 * n] = x[SR_X_R_Y + 4 * n] = x[SR_X_R_P + 4 * n] = 1;
    x[SR_X_q + 2] = PAPER[SR_PAPER_r];

    status = sr_paper_params(PAPER, params);
    if (status == SR_OK) status = sr_model_init(&model, params);
    if (status == SR_OK) status = sr_check_state(&model, x);
    if (status != SR_OK) {
        fprintf(stderr, "firmware_tshape: setup failed: %s\n", sr_status_string(status));
        return 1;
    }

    print_header();
    print_row(0.0, x);
    for (n = 1; n <= N_STEPS; ++n) {
        wait_for_tick();
        torque_program(n, u);
        status = sr_step_lie_euler(&model, x, u, DT, x); /* in place: x_next may alias x */
        if (status != SR_OK) {
            fprintf(stderr, "firmware_tshape: step %ld failed: %s\n", n, sr_status_string(status));
            return 1;
        }
        print_row((double)n * DT_SECONDS, x); /* t = n dt, as numpy computes it */
    }
    return 0;
}
