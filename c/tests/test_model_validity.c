/*
 * test_model_validity.c -- every function that takes a model refuses one that sr_model_init did
 * not fill, or that changed since (SR_ERR_MODEL), before it looks at any other argument; and the
 * arguments of one kind get one check everywhere, before any early return (sr_argcheck.h).
 */
#include "sr_test.h"
#include "sr_sensors.h"

#include <math.h>
#include <string.h>

/* ---- every entry point that takes a model, on a valid state and valid other arguments --------
 * call(m, n): n is the row count of the batch forms (0 or 1), ignored by the others. */
typedef struct model_fn {
    const char *name;
    int (*call)(const sr_model *m, long n);
} model_fn;

static sr_real X[2 * SR_NX], U[2 * SR_NU], OUT[4 * SR_NE * SR_NE], OUT2[4 * SR_NE * SR_NU];
static sr_real MOUNT[SR_NMOUNT], NU_DOT[SR_NV];
static long ROW;
static sr_lqr LQR;

/* A valid state (x, twice), torques, a one-point schedule with zero gains, and a sensor mount
 * (lever arm, axes of the body) with accelerations. */
static void valid_arguments(double r)
{
    int i;
    make_state(X, 0.3, -0.4, r);
    for (i = 0; i < SR_NMOUNT; ++i) MOUNT[i] = 0;
    MOUNT[SR_MOUNT_lever + 2] = SR_C(-0.05);
    MOUNT[SR_MOUNT_R_m + 0] = MOUNT[SR_MOUNT_R_m + 4] = MOUNT[SR_MOUNT_R_m + 8] = 1;
    for (i = 0; i < SR_NV; ++i) NU_DOT[i] = SR_C(0.1) * (sr_real)(i + 1);
    X[SR_X_w_S] = SR_C(0.2);
    X[SR_X_w_Y] = SR_C(0.5);
    memcpy(X + SR_NX, X, sizeof(sr_real) * SR_NX);
    U[0] = U[2] = SR_C(0.1);
    U[1] = U[3] = SR_C(-0.05);
    memset(&LQR, 0, sizeof LQR);
    LQR.n_speeds = LQR.n_curvatures = 1;
    LQR.period = SR_C(0.02);
    LQR.u_max = SR_C(0.5);
    LQR.integral_zone = SR_C(0.2);
}

static const sr_lqr_target TARGET = {SR_C(0.3), SR_C(0.5), SR_C(0.2), SR_C(0.05), 1};

static int c_check_state(const sr_model *m, long n) { (void)n; return sr_check_state(m, X); }
static int c_check_state_batch(const sr_model *m, long n) { return sr_check_state_batch(m, n, X, &ROW); }
static int c_accel(const sr_model *m, long n) { (void)n; return sr_accel(m, X, U, OUT); }
static int c_accel_batch(const sr_model *m, long n) { return sr_accel_batch(m, n, X, U, OUT, &ROW); }
static int c_checked_accel_batch(const sr_model *m, long n) { return sr_checked_accel_batch(m, n, X, U, OUT, &ROW); }
static int c_inertia(const sr_model *m, long n) { (void)n; return sr_inertia(m, X, OUT); }
static int c_rhs(const sr_model *m, long n) { (void)n; return sr_rhs(m, X, U, OUT); }
static int c_energy(const sr_model *m, long n) { (void)n; return sr_energy(m, X, OUT); }
static int c_residual(const sr_model *m, long n) { (void)n; return sr_equilibrium_residual(m, X, OUT); }
static int c_contact_force(const sr_model *m, long n) { (void)n; return sr_contact_force(m, X, U, OUT); }
static int c_contact_force_batch(const sr_model *m, long n) { return sr_contact_force_batch(m, n, X, U, OUT, &ROW); }
static int c_step(const sr_model *m, long n) { (void)n; return sr_step(m, SR_RKMK4 | SR_PROJECT, X, U, SR_C(0.01), OUT); }
static int c_step_lie_euler(const sr_model *m, long n) { (void)n; return sr_step_lie_euler(m, X, U, SR_C(0.01), OUT); }
static int c_step_rkmk4(const sr_model *m, long n) { (void)n; return sr_step_rkmk4(m, X, U, SR_C(0.01), OUT); }
static int c_step_cf4(const sr_model *m, long n) { (void)n; return sr_step_cf4(m, X, U, SR_C(0.01), OUT); }
static int c_step_batch(const sr_model *m, long n) { return sr_step_batch(m, SR_CF4, n, X, U, SR_C(0.01), OUT, &ROW); }
static int c_simulate(const sr_model *m, long n) { return sr_simulate(m, SR_LIE_EULER, X, SR_C(0.01), n, U, OUT, &ROW); }
static int c_simulate_guarded(const sr_model *m, long n)
{
    sr_energy_guard guard = {SR_C(0.5), 0, 0, 0, 0};
    return sr_simulate_guarded(m, SR_CF4, X, SR_C(0.01), n, U, &guard, OUT, &ROW);
}
static int c_simulate_adaptive(const sr_model *m, long n)
{
    return sr_simulate_adaptive(m, SR_RKMK4, X, SR_C(0.01), n, U, SR_C(1e-6), SR_C(1e-9), 0, 1000, OUT, NULL);
}
static int c_retract(const sr_model *m, long n) { static const sr_real d[SR_NE]; (void)n; return sr_retract(m, X, d, OUT); }
static int c_local(const sr_model *m, long n) { (void)n; return sr_local(m, X, X + SR_NX, OUT); }
static int c_retract_batch(const sr_model *m, long n) { static const sr_real d[SR_NE]; return sr_retract_batch(m, n, X, d, OUT, &ROW); }
static int c_local_batch(const sr_model *m, long n) { return sr_local_batch(m, n, X, X + SR_NX, OUT, &ROW); }
static int c_accel_jacobian(const sr_model *m, long n) { (void)n; return sr_accel_jacobian(m, X, U, OUT, OUT2); }
static int c_accel_jacobian_batch(const sr_model *m, long n) { return sr_accel_jacobian_batch(m, n, X, U, OUT, OUT2, &ROW); }
static int c_step_jacobian_lie_euler(const sr_model *m, long n) { (void)n; return sr_step_jacobian_lie_euler(m, X, U, SR_C(0.01), OUT, OUT2); }
static int c_step_jacobian_lie_euler_batch(const sr_model *m, long n)
{
    return sr_step_jacobian_lie_euler_batch(m, n, X, U, SR_C(0.01), OUT, OUT2, &ROW);
}
static int c_step_jacobian_rkmk4(const sr_model *m, long n) { (void)n; return sr_step_jacobian_rkmk4(m, X, U, SR_C(0.01), OUT, OUT2); }
static int c_step_jacobian_cf4(const sr_model *m, long n) { (void)n; return sr_step_jacobian_cf4(m, X, U, SR_C(0.01), OUT, OUT2); }
static int c_step_jacobian(const sr_model *m, long n) { (void)n; return sr_step_jacobian(m, SR_CF4, X, U, SR_C(0.01), OUT, OUT2); }
static int c_step_jacobian_batch(const sr_model *m, long n)
{
    return sr_step_jacobian_batch(m, SR_RKMK4, n, X, U, SR_C(0.01), OUT, OUT2, &ROW);
}
static int c_lqr_error(const sr_model *m, long n) { (void)n; return sr_lqr_error(m, X, &TARGET, NULL, OUT); }
static int c_lqr_control(const sr_model *m, long n)
{
    sr_lqr_memory memory = {{0, 0}, 0, 0, 0};
    (void)n;
    return sr_lqr_control(&LQR, m, X, &TARGET, &memory, OUT, OUT2);
}
static int c_imu_measure(const sr_model *m, long n)
{
    (void)n;
    return sr_imu_measure(m, X, NU_DOT, SR_BODY_yoke, MOUNT, NULL, OUT);
}
static int c_imu_measure_u(const sr_model *m, long n)
{
    (void)n;
    return sr_imu_measure_u(m, X, U, SR_BODY_pendulum, MOUNT, NULL, OUT);
}
static int c_imu_partials(const sr_model *m, long n)
{
    (void)n;
    return sr_imu_partials(m, X, NU_DOT, SR_BODY_shell, MOUNT, NULL, OUT, OUT + SR_NIMU, OUT2);
}
static int c_imu_jacobian(const sr_model *m, long n)
{
    (void)n;
    return sr_imu_jacobian(m, X, U, SR_BODY_yoke, MOUNT, NULL, OUT, OUT + SR_NIMU);
}
static int c_encoders_measure(const sr_model *m, long n) { (void)n; return sr_encoders_measure(m, X, OUT); }
static int c_encoders_jacobian(const sr_model *m, long n) { (void)n; return sr_encoders_jacobian(m, X, OUT, OUT + 2); }
static int c_position_measure(const sr_model *m, long n) { (void)n; return sr_position_measure(m, X, OUT); }
static int c_position_jacobian(const sr_model *m, long n) { (void)n; return sr_position_jacobian(m, X, OUT, OUT + 2); }
static int c_heading_measure(const sr_model *m, long n) { (void)n; return sr_heading_measure(m, X, SR_BODY_yoke, MOUNT, OUT); }
static int c_heading_jacobian(const sr_model *m, long n)
{
    (void)n;
    return sr_heading_jacobian(m, X, SR_BODY_yoke, MOUNT, OUT, OUT + 1);
}

static const model_fn TAKES_MODEL[] = {
    {"sr_check_state", c_check_state},
    {"sr_check_state_batch", c_check_state_batch},
    {"sr_accel", c_accel},
    {"sr_accel_batch", c_accel_batch},
    {"sr_checked_accel_batch", c_checked_accel_batch},
    {"sr_inertia", c_inertia},
    {"sr_rhs", c_rhs},
    {"sr_energy", c_energy},
    {"sr_equilibrium_residual", c_residual},
    {"sr_contact_force", c_contact_force},
    {"sr_contact_force_batch", c_contact_force_batch},
    {"sr_step", c_step},
    {"sr_step_lie_euler", c_step_lie_euler},
    {"sr_step_rkmk4", c_step_rkmk4},
    {"sr_step_cf4", c_step_cf4},
    {"sr_step_batch", c_step_batch},
    {"sr_simulate", c_simulate},
    {"sr_simulate_guarded", c_simulate_guarded},
    {"sr_simulate_adaptive", c_simulate_adaptive},
    {"sr_retract", c_retract},
    {"sr_local", c_local},
    {"sr_retract_batch", c_retract_batch},
    {"sr_local_batch", c_local_batch},
    {"sr_accel_jacobian", c_accel_jacobian},
    {"sr_accel_jacobian_batch", c_accel_jacobian_batch},
    {"sr_step_jacobian_lie_euler", c_step_jacobian_lie_euler},
    {"sr_step_jacobian_lie_euler_batch", c_step_jacobian_lie_euler_batch},
    {"sr_step_jacobian_rkmk4", c_step_jacobian_rkmk4},
    {"sr_step_jacobian_cf4", c_step_jacobian_cf4},
    {"sr_step_jacobian", c_step_jacobian},
    {"sr_step_jacobian_batch", c_step_jacobian_batch},
    {"sr_lqr_error", c_lqr_error},
    {"sr_lqr_control", c_lqr_control},
    {"sr_imu_measure", c_imu_measure},
    {"sr_imu_measure_u", c_imu_measure_u},
    {"sr_imu_partials", c_imu_partials},
    {"sr_imu_jacobian", c_imu_jacobian},
    {"sr_encoders_measure", c_encoders_measure},
    {"sr_encoders_jacobian", c_encoders_jacobian},
    {"sr_position_measure", c_position_measure},
    {"sr_position_jacobian", c_position_jacobian},
    {"sr_heading_measure", c_heading_measure},
    {"sr_heading_jacobian", c_heading_jacobian},
};
#define N_TAKES_MODEL ((int)(sizeof TAKES_MODEL / sizeof TAKES_MODEL[0]))

/* Every entry point, with 0 and with 1 row, must return `want` for model m. */
static void expect_every_entry(const sr_model *m, int want, const char *what)
{
    long n;
    int k;
    for (n = 0; n <= 1; ++n)
        for (k = 0; k < N_TAKES_MODEL; ++k) {
            const int got = TAKES_MODEL[k].call(m, n);
            if (got != want)
                sr_test_fail(__FILE__, __LINE__, "%s (n = %ld) with %s returned %d (%s), expected %d (%s)",
                             TAKES_MODEL[k].name, n, what, got, sr_status_string(got), want, sr_status_string(want));
        }
}

/* ---- tests -------------------------------------------------------------------------------- */

/* The baseline of the tests below: with a model from sr_model_init, every call succeeds, so an
 * SR_ERR_MODEL below is the model's doing alone. */
static void test_a_model_from_sr_model_init_is_valid_everywhere(void)
{
    sr_model m, general, copy;
    sr_real p[SR_NPARAM];
    paper_simulation_model(&m);
    valid_arguments((double)m.p[SR_P_r]);
    expect_every_entry(&m, SR_OK, "a model from sr_model_init");
    memcpy(&copy, &m, sizeof m); /* a model is a value: a copy is as valid */
    expect_every_entry(&copy, SR_OK, "a copy of a valid model");
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&general, p), SR_OK);
    CHECK(general.general);
    valid_arguments((double)p[SR_P_r]);
    expect_every_entry(&general, SR_OK, "a general robot's model");
}

static void test_a_zeroed_model_is_refused_by_every_entry_point(void)
{
    sr_model m;
    memset(&m, 0, sizeof m);
    valid_arguments(0.3);
    expect_every_entry(&m, SR_ERR_MODEL, "a zeroed model");
    memset(&m, 0xA5, sizeof m); /* uninitialised memory */
    expect_every_entry(&m, SR_ERR_MODEL, "a model of garbage bytes");
}

/* A zeroed model is named before what it makes of the state (r = 0: q_z != r). */
static void test_a_zeroed_model_is_named_before_the_state(void)
{
    sr_model m;
    memset(&m, 0, sizeof m);
    valid_arguments(0.3);
    CHECK_STATUS(sr_step(&m, SR_LIE_EULER, X, U, SR_C(0.01), OUT), SR_ERR_MODEL);
    CHECK_STATUS(sr_energy(&m, X, OUT), SR_ERR_MODEL);
    /* before the other arguments too: NULL outputs, a bad dt, an unknown method */
    CHECK_STATUS(sr_accel(&m, X, U, NULL), SR_ERR_MODEL);
    CHECK_STATUS(sr_step(&m, 99, X, U, SR_C(-1.0), NULL), SR_ERR_MODEL);
    CHECK_STATUS(sr_step_batch(&m, 99, -1, NULL, NULL, SR_C(0.01), NULL, &ROW), SR_ERR_MODEL);
    CHECK(ROW == -1);
}

/* Any one parameter or constant that the kernels read, overwritten after sr_model_init with NaN
 * or with a finite value, makes the model invalid everywhere. */
static void test_a_changed_parameter_or_constant_is_refused_by_every_entry_point(void)
{
    const double values[] = {NAN, INFINITY, 1.5, 0.0};
    sr_model m, changed;
    int i, v;
    char what[96];
    paper_simulation_model(&m);
    valid_arguments((double)m.p[SR_P_r]);
    for (v = 0; v < 4; ++v) {
        for (i = 0; i < SR_NPARAM; ++i) {
            changed = m;
            if (changed.p[i] == (sr_real)values[v]) continue;
            changed.p[i] = (sr_real)values[v];
            snprintf(what, sizeof what, "p[%d] = %g", i, values[v]);
            expect_every_entry(&changed, SR_ERR_MODEL, what);
        }
        for (i = 0; i < SR_GEN_NCONST; ++i) {
            changed = m;
            if (changed.c[i] == (sr_real)values[v]) continue;
            changed.c[i] = (sr_real)values[v];
            snprintf(what, sizeof what, "c[%d] = %g", i, values[v]);
            expect_every_entry(&changed, SR_ERR_MODEL, what);
        }
    }
    changed = m; /* the kernels of the other kind */
    changed.general = 1;
    expect_every_entry(&changed, SR_ERR_MODEL, "general flipped");
    changed = m;
    changed.p[SR_P_m_P] = next_up(changed.p[SR_P_m_P]); /* one ulp */
    expect_every_entry(&changed, SR_ERR_MODEL, "m_P one ulp up");
}

/* The same for a general robot, whose kernels read the other constants. */
static void test_a_changed_general_constant_is_refused(void)
{
    sr_model m, changed;
    sr_real p[SR_NPARAM];
    int i;
    char what[64];
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    valid_arguments((double)p[SR_P_r]);
    for (i = 0; i < SR_GEN_GENERAL_NCONST; ++i) {
        changed = m;
        changed.cg[i] = (sr_real)NAN;
        snprintf(what, sizeof what, "cg[%d] = NaN", i);
        expect_every_entry(&changed, SR_ERR_MODEL, what);
    }
}

/* A failed sr_model_init leaves the model untouched: memory it never filled stays invalid. */
static void test_a_failed_sr_model_init_leaves_no_valid_model(void)
{
    sr_model m;
    sr_real p[SR_NPARAM];
    memset(&m, 0, sizeof m);
    paper_simulation_params(p);
    p[SR_P_m_S] = -1;
    CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
    valid_arguments(0.3);
    CHECK_STATUS(sr_check_state(&m, X), SR_ERR_MODEL);
}

static void test_sr_err_model_has_its_own_name(void)
{
    CHECK(strstr(sr_status_string(SR_ERR_MODEL), "model") != NULL);
    CHECK(strcmp(sr_status_string(SR_ERR_MODEL), "unknown status") != 0);
}

/* One check per kind of argument: an unknown method is refused by every call that takes one,
 * with rows or without (n = 0, steps = 0), and a batch refuses it before any row. */
static void test_an_unknown_method_is_refused_even_without_rows(void)
{
    const int bad[] = {-1, 3, 99, SR_PROJECT | 3};
    sr_model m;
    sr_real p[SR_NPARAM];
    int status[1];
    long done[1];
    int i;
    paper_simulation_model(&m);
    paper_simulation_params(p);
    valid_arguments((double)m.p[SR_P_r]);
    for (i = 0; i < (int)(sizeof bad / sizeof bad[0]); ++i) {
        const int b = bad[i];
        ROW = 7;
        CHECK_STATUS(sr_step_batch(&m, b, 0, X, U, SR_C(0.01), OUT, &ROW), SR_ERR_ARG);
        CHECK(ROW == -1);
        ROW = 7;
        CHECK_STATUS(sr_step_batch(&m, b, 2, X, U, SR_C(0.01), OUT, &ROW), SR_ERR_ARG);
        CHECK(ROW == -1);
        ROW = 7;
        CHECK_STATUS(sr_step_jacobian_batch(&m, b, 0, X, U, SR_C(0.01), OUT, OUT2, &ROW), SR_ERR_ARG);
        CHECK(ROW == -1);
        CHECK_STATUS(sr_step(&m, b, X, U, SR_C(0.01), OUT), SR_ERR_ARG);
        CHECK_STATUS(sr_step_jacobian(&m, b, X, U, SR_C(0.01), OUT, OUT2), SR_ERR_ARG);
        CHECK_STATUS(sr_simulate(&m, b, X, SR_C(0.01), 0, NULL, OUT, NULL), SR_ERR_ARG);
        CHECK_STATUS(sr_simulate_adaptive(&m, b, X, SR_C(0.01), 0, NULL, SR_C(1e-6), 0, 0, 10, OUT, NULL), SR_ERR_ARG);
        CHECK_STATUS(sr_simulate_batch(b, 0, p, 0, X, 0, SR_C(0.01), 1, NULL, 0, -1, 1, OUT, NULL, NULL, NULL,
                                       status, done), SR_ERR_ARG);
    }
    /* a projected method is a stepping method, not a step Jacobian's */
    CHECK_STATUS(sr_step_batch(&m, SR_CF4 | SR_PROJECT, 0, X, U, SR_C(0.01), OUT, &ROW), SR_OK);
    CHECK_STATUS(sr_step_jacobian_batch(&m, SR_CF4 | SR_PROJECT, 0, X, U, SR_C(0.01), OUT, OUT2, &ROW), SR_ERR_ARG);
}

/* The same for dt and for the rows: one rule for every batch, checked before any row. */
static void test_a_bad_dt_or_row_count_is_refused_before_any_row(void)
{
    sr_model m;
    paper_simulation_model(&m);
    valid_arguments((double)m.p[SR_P_r]);
    ROW = 7;
    CHECK_STATUS(sr_step_batch(&m, SR_RKMK4, 0, X, U, SR_C(0.0), OUT, &ROW), SR_ERR_ARG);
    CHECK(ROW == -1);
    ROW = 7;
    CHECK_STATUS(sr_step_jacobian_batch(&m, SR_RKMK4, 2, X, U, (sr_real)NAN, OUT, OUT2, &ROW), SR_ERR_ARG);
    CHECK(ROW == -1);
    ROW = 7;
    CHECK_STATUS(sr_step_jacobian_lie_euler_batch(&m, 0, X, U, SR_C(-0.01), OUT, OUT2, &ROW), SR_ERR_ARG);
    CHECK(ROW == -1);
    /* no rows: the buffers may be NULL, in every batch call */
    CHECK_STATUS(sr_check_state_batch(&m, 0, NULL, &ROW), SR_OK);
    CHECK_STATUS(sr_accel_batch(&m, 0, NULL, NULL, NULL, &ROW), SR_OK);
    CHECK_STATUS(sr_checked_accel_batch(&m, 0, NULL, NULL, NULL, &ROW), SR_OK);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, 0, NULL, NULL, SR_C(0.01), NULL, &ROW), SR_OK);
    CHECK_STATUS(sr_retract_batch(&m, 0, NULL, NULL, NULL, &ROW), SR_OK);
    CHECK_STATUS(sr_local_batch(&m, 0, NULL, NULL, NULL, &ROW), SR_OK);
    CHECK_STATUS(sr_accel_jacobian_batch(&m, 0, NULL, NULL, NULL, NULL, &ROW), SR_OK);
    CHECK_STATUS(sr_step_jacobian_batch(&m, SR_CF4, 0, NULL, NULL, SR_C(0.01), NULL, NULL, &ROW), SR_OK);
    /* ... and a negative count is refused by every one */
    CHECK_STATUS(sr_check_state_batch(&m, -1, X, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_accel_batch(&m, -1, X, U, OUT, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_checked_accel_batch(&m, -1, X, U, OUT, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_step_batch(&m, SR_LIE_EULER, -1, X, U, SR_C(0.01), OUT, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_retract_batch(&m, -1, X, X, OUT, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_local_batch(&m, -1, X, X, OUT, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_accel_jacobian_batch(&m, -1, X, U, OUT, OUT2, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_step_jacobian_batch(&m, SR_CF4, -1, X, U, SR_C(0.01), OUT, OUT2, &ROW), SR_ERR_ARG);
    CHECK_STATUS(sr_step_jacobian_lie_euler_batch(&m, -1, X, U, SR_C(0.01), OUT, OUT2, &ROW), SR_ERR_ARG);
}

/* The arguments come before the state: a bad dt with a corrupt state is a bad dt, as with a good one. */
static void test_arguments_are_checked_before_the_state(void)
{
    sr_model m;
    sr_real traj[3 * SR_NX];
    paper_simulation_model(&m);
    valid_arguments((double)m.p[SR_P_r]);
    X[SR_X_q + 2] = SR_C(7.0); /* q_z != r */
    CHECK_STATUS(sr_step(&m, SR_LIE_EULER, X, U, SR_C(0.01), OUT), SR_ERR_CONSTRAINT);
    CHECK_STATUS(sr_step(&m, SR_LIE_EULER, X, U, SR_C(-0.01), OUT), SR_ERR_ARG);
    CHECK_STATUS(sr_step_jacobian_rkmk4(&m, X, U, SR_C(-0.01), OUT, OUT2), SR_ERR_ARG);
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, X, SR_C(-0.01), 2, NULL, traj, NULL), SR_ERR_ARG);
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, X, SR_C(0.01), -1, NULL, traj, NULL), SR_ERR_ARG);
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, X, SR_C(0.01), 2, NULL, traj, NULL), SR_ERR_CONSTRAINT);
}

/* The sensors keep the same order: the model, then the pointers, then the body and the mount,
 * then the state and the data beside it. */
static void test_a_sensor_checks_model_pointers_body_and_mount_before_the_state(void)
{
    sr_model m, zeroed;
    paper_simulation_model(&m);
    memset(&zeroed, 0, sizeof zeroed);
    valid_arguments((double)m.p[SR_P_r]);
    CHECK_STATUS(sr_imu_measure(&zeroed, NULL, NULL, 7, NULL, NULL, NULL), SR_ERR_MODEL);
    CHECK_STATUS(sr_heading_jacobian(&zeroed, X, -1, MOUNT, NULL, NULL), SR_ERR_MODEL);
    CHECK_STATUS(sr_encoders_measure(&zeroed, X, NULL), SR_ERR_MODEL);
    X[SR_X_q + 2] = SR_C(7.0); /* q_z != r */
    CHECK_STATUS(sr_imu_measure(&m, X, NU_DOT, SR_BODY_yoke, MOUNT, NULL, OUT), SR_ERR_CONSTRAINT);
    CHECK_STATUS(sr_imu_measure(&m, X, NU_DOT, SR_BODY_yoke, MOUNT, NULL, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_imu_measure(&m, X, NU_DOT, SR_NBODY, MOUNT, NULL, OUT), SR_ERR_ARG);
    CHECK_STATUS(sr_imu_jacobian(&m, X, U, -1, MOUNT, NULL, OUT, OUT + SR_NIMU), SR_ERR_ARG);
    CHECK_STATUS(sr_heading_measure(&m, X, SR_NBODY, MOUNT, OUT), SR_ERR_ARG);
    MOUNT[SR_MOUNT_R_m + 0] = SR_C(2.0); /* R_m not a rotation */
    CHECK_STATUS(sr_imu_partials(&m, X, NU_DOT, SR_BODY_shell, MOUNT, NULL, OUT, OUT + SR_NIMU, OUT2),
                 SR_ERR_NOT_ROTATION);
    CHECK_STATUS(sr_heading_jacobian(&m, X, SR_BODY_yoke, MOUNT, OUT, OUT + 1), SR_ERR_NOT_ROTATION);
    CHECK_STATUS(sr_encoders_measure(&m, X, OUT), SR_ERR_CONSTRAINT);
    CHECK_STATUS(sr_position_jacobian(&m, X, OUT, NULL), SR_ERR_NULL);
}

void suite_model_validity(void)
{
    RUN_TEST(test_a_model_from_sr_model_init_is_valid_everywhere);
    RUN_TEST(test_a_zeroed_model_is_refused_by_every_entry_point);
    RUN_TEST(test_a_zeroed_model_is_named_before_the_state);
    RUN_TEST(test_a_changed_parameter_or_constant_is_refused_by_every_entry_point);
    RUN_TEST(test_a_changed_general_constant_is_refused);
    RUN_TEST(test_a_failed_sr_model_init_leaves_no_valid_model);
    RUN_TEST(test_sr_err_model_has_its_own_name);
    RUN_TEST(test_an_unknown_method_is_refused_even_without_rows);
    RUN_TEST(test_a_bad_dt_or_row_count_is_refused_before_any_row);
    RUN_TEST(test_arguments_are_checked_before_the_state);
    RUN_TEST(test_a_sensor_checks_model_pointers_body_and_mount_before_the_state);
}
