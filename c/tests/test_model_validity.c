/*
 * test_model_validity.c -- every function that takes a model refuses one that sr_model_init did
 * not fill, or whose entries that function reads changed since (SR_ERR_MODEL), before it looks at
 * any other argument; an entry it does not read may change and changes nothing; and the arguments
 * of one kind get one check everywhere, before any early return (sr_argcheck.h).
 */
#include "sr_test.h"
#include "sr_sensors.h"

#include <math.h>
#include <string.h>

/* ---- what each entry point reads of a model -------------------------------------------------
 * The kernels it runs (their read sets are the generator's, SR_GEN_READS_<kernel>) and what the
 * hand-written code reads of p: r (the state check's contact, the rolling kinematics, the LQR's
 * rate), the energy guard's m_Y, c_Y, m_P, c_P and g. */
enum {
    R_STATE = 1 << 0,       /* p[r] */
    R_ACCEL = 1 << 1,       /* sr_gen_accel / sr_gen_general_system */
    R_INERTIA = 1 << 2,     /* sr_gen_inertia / sr_gen_general_inertia */
    R_RHS = 1 << 3,         /* sr_gen_rhs / sr_gen_general_rhs */
    R_ENERGY = 1 << 4,      /* sr_gen_energy / sr_gen_general_energy */
    R_EQUILIBRIUM = 1 << 5, /* sr_gen_equilibrium_residual / sr_gen_general_equilibrium_residual */
    R_JACOBIAN = 1 << 6,    /* sr_gen_accel_jacobian_yoke_terms / sr_gen_general_accel_jacobian_terms */
    R_SENSORS = 1 << 7,     /* sr_gen_sensor_constants */
    R_GUARD = 1 << 8,       /* the energy guard's scale */
    R_WHOLE = 1 << 9        /* all of p and the constants of the model's kind */
};

/* An entry's read marks: which of p, c and cg the entry point reads. */
typedef struct read_marks {
    char p[SR_NPARAM], c[SR_GEN_NCONST], cg[SR_GEN_GENERAL_NCONST];
} read_marks;

#define MARK(array, first, end) mark(marks->array, first, end);
static void mark(char *marks, int first, int end)
{
    int i;
    for (i = first; i < end; ++i) marks[i] = 1;
}

/* The entries of a model of kind `general` that an entry point with read sets `reads` reads. */
static void expected_reads(unsigned reads, int general, read_marks *marks)
{
    memset(marks, 0, sizeof *marks);
    if (reads & R_STATE) mark(marks->p, SR_P_r, SR_P_r + 1);
    if (reads & R_GUARD) {
        mark(marks->p, SR_P_m_Y, SR_P_c_Y_z + 1);
        mark(marks->p, SR_P_m_P, SR_P_c_P_z + 1);
        mark(marks->p, SR_P_g, SR_P_g + 1);
    }
    if (reads & R_SENSORS) { SR_GEN_READS_sensor_constants(MARK) }
    if (reads & R_WHOLE) {
        mark(marks->p, 0, SR_NPARAM);
        if (general) mark(marks->cg, 0, SR_GEN_GENERAL_NCONST); else mark(marks->c, 0, SR_GEN_NCONST);
    }
    if (general) {
        if (reads & R_ACCEL) { SR_GEN_READS_general_system(MARK) }
        if (reads & R_INERTIA) { SR_GEN_READS_general_inertia(MARK) }
        if (reads & R_RHS) { SR_GEN_READS_general_rhs(MARK) }
        if (reads & R_ENERGY) { SR_GEN_READS_general_energy(MARK) }
        if (reads & R_EQUILIBRIUM) { SR_GEN_READS_general_equilibrium_residual(MARK) }
        if (reads & R_JACOBIAN) { SR_GEN_READS_general_accel_jacobian_terms(MARK) }
    } else {
        if (reads & R_ACCEL) { SR_GEN_READS_accel(MARK) }
        if (reads & R_INERTIA) { SR_GEN_READS_inertia(MARK) }
        if (reads & R_RHS) { SR_GEN_READS_rhs(MARK) }
        if (reads & R_ENERGY) { SR_GEN_READS_energy(MARK) }
        if (reads & R_EQUILIBRIUM) { SR_GEN_READS_equilibrium_residual(MARK) }
        if (reads & R_JACOBIAN) { SR_GEN_READS_accel_jacobian_yoke_terms(MARK) }
    }
}

/* ---- every entry point that takes a model, on a valid state and valid other arguments --------
 * call(m, n): n is the row count of the batch forms (0 or 1), ignored by the others; reads: what
 * it reads of the model (R_*). */
typedef struct model_fn {
    const char *name;
    int (*call)(const sr_model *m, long n);
    unsigned reads;
} model_fn;

static sr_real X[2 * SR_NX], U[2 * SR_NU], NUDOT[2 * SR_NV], OUT[4 * SR_NE * SR_NPARAM], OUT2[4 * SR_NE * SR_NU];
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
    LQR.steady_rate = SR_C(0.005);
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
    sr_lqr_memory memory = {{0, 0}, 0, 0, 0, 0, {0, 0}, 0};
    (void)n;
    return sr_lqr_control(&LQR, m, X, &TARGET, &memory, OUT, OUT2);
}
static int c_lqr_control_offsets(const sr_model *m, long n)
{
    sr_lqr_memory memory = {{0, 0}, 0, 0, 0, 0, {0, 0}, 0};
    const sr_lqr_offsets offsets = {{SR_C(0.01), 0}, {SR_C(0.001), 0}, {0, 0, 0, 0}};
    (void)n;
    return sr_lqr_control_offsets(&LQR, m, X, &TARGET, &offsets, &memory, OUT, OUT2);
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
static int c_contact_force(const sr_model *m, long n) { (void)n; return sr_contact_force(m, X, U, OUT); }
static int c_contact_force_batch(const sr_model *m, long n) { return sr_contact_force_batch(m, n, X, U, OUT, &ROW); }
static int c_accel_param_jacobian(const sr_model *m, long n) { (void)n; return sr_accel_param_jacobian(m, X, U, OUT); }
static int c_accel_param_jacobian_batch(const sr_model *m, long n) { return sr_accel_param_jacobian_batch(m, n, X, U, OUT, &ROW); }
static int c_step_param_jacobian(const sr_model *m, long n) { (void)n; return sr_step_param_jacobian(m, SR_RKMK4, X, U, SR_C(0.01), OUT); }
static int c_step_param_jacobian_batch(const sr_model *m, long n)
{
    return sr_step_param_jacobian_batch(m, SR_LIE_EULER, n, X, U, SR_C(0.01), OUT, &ROW);
}
static int c_regressor(const sr_model *m, long n) { (void)n; return sr_regressor(m, X, NUDOT, OUT); }
static int c_regressor_batch(const sr_model *m, long n) { return sr_regressor_batch(m, n, X, NUDOT, OUT, &ROW); }
static int c_heading_jacobian(const sr_model *m, long n)
{
    (void)n;
    return sr_heading_jacobian(m, X, SR_BODY_yoke, MOUNT, OUT, OUT + 1);
}

static const model_fn TAKES_MODEL[] = {
    {"sr_check_state", c_check_state, R_STATE},
    {"sr_check_state_batch", c_check_state_batch, R_STATE},
    {"sr_accel", c_accel, R_ACCEL},
    {"sr_accel_batch", c_accel_batch, R_ACCEL | R_STATE},
    {"sr_checked_accel_batch", c_checked_accel_batch, R_ACCEL | R_STATE},
    {"sr_inertia", c_inertia, R_INERTIA},
    {"sr_rhs", c_rhs, R_RHS},
    {"sr_energy", c_energy, R_ENERGY},
    {"sr_equilibrium_residual", c_residual, R_EQUILIBRIUM},
    {"sr_contact_force", c_contact_force, R_WHOLE},
    {"sr_contact_force_batch", c_contact_force_batch, R_WHOLE},
    {"sr_accel_param_jacobian", c_accel_param_jacobian, R_WHOLE},
    {"sr_accel_param_jacobian_batch", c_accel_param_jacobian_batch, R_WHOLE},
    {"sr_step_param_jacobian", c_step_param_jacobian, R_WHOLE},
    {"sr_step_param_jacobian_batch", c_step_param_jacobian_batch, R_WHOLE},
    {"sr_regressor", c_regressor, R_WHOLE},
    {"sr_regressor_batch", c_regressor_batch, R_WHOLE},
    {"sr_step", c_step, R_ACCEL | R_STATE},
    {"sr_step_lie_euler", c_step_lie_euler, R_ACCEL | R_STATE},
    {"sr_step_rkmk4", c_step_rkmk4, R_ACCEL | R_STATE},
    {"sr_step_cf4", c_step_cf4, R_ACCEL | R_STATE},
    {"sr_step_batch", c_step_batch, R_ACCEL | R_STATE},
    {"sr_simulate", c_simulate, R_ACCEL | R_STATE},
    {"sr_simulate_guarded", c_simulate_guarded, R_ACCEL | R_STATE | R_ENERGY | R_GUARD},
    {"sr_simulate_adaptive", c_simulate_adaptive, R_ACCEL | R_STATE},
    {"sr_retract", c_retract, R_STATE},
    {"sr_local", c_local, R_STATE},
    {"sr_retract_batch", c_retract_batch, R_STATE},
    {"sr_local_batch", c_local_batch, R_STATE},
    {"sr_accel_jacobian", c_accel_jacobian, R_JACOBIAN},
    {"sr_accel_jacobian_batch", c_accel_jacobian_batch, R_JACOBIAN},
    {"sr_step_jacobian_lie_euler", c_step_jacobian_lie_euler, R_JACOBIAN | R_STATE},
    {"sr_step_jacobian_lie_euler_batch", c_step_jacobian_lie_euler_batch, R_JACOBIAN | R_STATE},
    {"sr_step_jacobian_rkmk4", c_step_jacobian_rkmk4, R_JACOBIAN | R_STATE},
    {"sr_step_jacobian_cf4", c_step_jacobian_cf4, R_JACOBIAN | R_STATE},
    {"sr_step_jacobian", c_step_jacobian, R_JACOBIAN | R_STATE},
    {"sr_step_jacobian_batch", c_step_jacobian_batch, R_JACOBIAN | R_STATE},
    {"sr_lqr_error", c_lqr_error, R_STATE},
    {"sr_lqr_control", c_lqr_control, R_STATE},
    {"sr_lqr_control_offsets", c_lqr_control_offsets, R_STATE},
    {"sr_imu_measure", c_imu_measure, R_STATE | R_SENSORS},
    {"sr_imu_measure_u", c_imu_measure_u, R_STATE | R_SENSORS | R_ACCEL},
    {"sr_imu_partials", c_imu_partials, R_STATE | R_SENSORS},
    {"sr_imu_jacobian", c_imu_jacobian, R_STATE | R_SENSORS | R_JACOBIAN},
    {"sr_encoders_measure", c_encoders_measure, R_STATE},
    {"sr_encoders_jacobian", c_encoders_jacobian, R_STATE},
    {"sr_position_measure", c_position_measure, R_STATE},
    {"sr_position_jacobian", c_position_jacobian, R_STATE},
    {"sr_heading_measure", c_heading_measure, R_STATE},
    {"sr_heading_jacobian", c_heading_jacobian, R_STATE},
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

/* ---- one entry of a model changed -------------------------------------------------------- */

/* A model's entry k of its p, c and cg, in that order. */
#define N_ENTRIES (SR_NPARAM + SR_GEN_NCONST + SR_GEN_GENERAL_NCONST)
static sr_real *entry(sr_model *m, int k, const char **array, int *index)
{
    if (k < SR_NPARAM) return *array = "p", *index = k, &m->p[k];
    k -= SR_NPARAM;
    if (k < SR_GEN_NCONST) return *array = "c", *index = k, &m->c[k];
    k -= SR_GEN_NCONST;
    return *array = "cg", *index = k, &m->cg[k];
}

static int marked(const read_marks *marks, int k)
{
    if (k < SR_NPARAM) return marks->p[k];
    k -= SR_NPARAM;
    return k < SR_GEN_NCONST ? marks->c[k] : marks->cg[k - SR_GEN_NCONST];
}

/* What a call leaves: its status, its outputs (over a fill pattern) and its failed row. */
typedef struct result {
    int status;
    long row;
    sr_real out[sizeof OUT / sizeof OUT[0]], out2[sizeof OUT2 / sizeof OUT2[0]];
} result;

static void run(const model_fn *fn, const sr_model *m, result *r)
{
    memset(OUT, 0x5A, sizeof OUT);
    memset(OUT2, 0x5A, sizeof OUT2);
    ROW = -7;
    r->status = fn->call(m, 1);
    r->row = ROW;
    memcpy(r->out, OUT, sizeof OUT);
    memcpy(r->out2, OUT2, sizeof OUT2);
}

/* Values other than v: NaN, a finite one, and the next one up (one ulp). */
#define N_CHANGES 3
static sr_real changed_value(sr_real v, int which)
{
    if (which == 0) return (sr_real)NAN;
    if (which == 2) return next_up(v);
    return v == 0 ? SR_C(0.75) : v * SR_C(1.5) + SR_C(0.25);
}

/* Every entry point, every entry of the model (both constants arrays, whichever kind it is)
 * changed to NaN, to another finite value and by one ulp: refused (SR_ERR_MODEL) where the entry point reads
 * it, and otherwise the very result of the valid model, status, outputs and failed row bit for bit
 * (so a read set that misses an entry that the code reads fails here). */
static void check_each_entry_against_the_read_sets(const sr_model *valid, const char *kind)
{
    static result want, got;
    read_marks marks;
    sr_model changed;
    int f, k, which, index;
    const char *array;
    for (f = 0; f < N_TAKES_MODEL; ++f) {
        const model_fn *fn = &TAKES_MODEL[f];
        expected_reads(fn->reads, valid->general, &marks);
        run(fn, valid, &want);
        CHECK_STATUS(want.status, SR_OK);
        for (k = 0; k < N_ENTRIES; ++k)
            for (which = 0; which < N_CHANGES; ++which) {
                sr_real *e;
                changed = *valid;
                e = entry(&changed, k, &array, &index);
                *e = changed_value(*e, which);
                run(fn, &changed, &got);
                if (marked(&marks, k)) {
                    if (got.status != SR_ERR_MODEL)
                        sr_test_fail(__FILE__, __LINE__, "%s (%s robot) with %s[%d] = %g, which it reads, returned %d (%s)",
                                     fn->name, kind, array, index, (double)*e, got.status, sr_status_string(got.status));
                } else if (got.status != want.status || got.row != want.row
                           || memcmp(got.out, want.out, sizeof got.out) != 0 || memcmp(got.out2, want.out2, sizeof got.out2) != 0) {
                    sr_test_fail(__FILE__, __LINE__,
                                 "%s (%s robot) with %s[%d] = %g, outside its read set, returned %d (%s) and other outputs"
                                 " than with the valid model: the read set misses an entry that the code reads",
                                 fn->name, kind, array, index, (double)*e, got.status, sr_status_string(got.status));
                }
            }
    }
}

static void test_each_entry_point_refuses_a_change_to_what_it_reads_and_only_that(void)
{
    sr_model m;
    sr_real p[SR_NPARAM];
    paper_simulation_model(&m);
    valid_arguments((double)m.p[SR_P_r]);
    check_each_entry_against_the_read_sets(&m, "paper");
    general_robot_params(p);
    CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    CHECK(m.general);
    valid_arguments((double)p[SR_P_r]);
    check_each_entry_against_the_read_sets(&m, "general");
}

/* The read sets are what the kernels read, not empty: sr_accel reads some of c and not all of it. */
static void test_the_read_sets_are_proper_subsets(void)
{
    read_marks marks;
    int i, read = 0;
    expected_reads(R_ACCEL, 0, &marks);
    for (i = 0; i < SR_GEN_NCONST; ++i) read += marks.c[i];
    CHECK(read > 0 && read < SR_GEN_NCONST);
    for (i = 0; i < SR_NPARAM; ++i) CHECK(!marks.p[i]);
}

/* The other kind's kernels, or a changed stamp, are refused everywhere. */
static void test_a_flipped_kind_or_a_changed_stamp_is_refused(void)
{
    sr_model m, changed;
    paper_simulation_model(&m);
    valid_arguments((double)m.p[SR_P_r]);
    changed = m;
    changed.general = 1;
    expect_every_entry(&changed, SR_ERR_MODEL, "general flipped");
    changed = m;
    changed.stamp ^= 1;
    expect_every_entry(&changed, SR_ERR_MODEL, "the stamp changed");
}

/* The full re-check: a changed entry of the constants of the model's kind, the kind or a checksum
 * is refused, and so is a changed parameter unless the model is, as it is, what sr_model_init
 * makes of the changed parameters (a rotor's gear ratio of a robot without rotors); the other
 * kind's constants are not the model's. */
static int same_model_of(const sr_model *m)
{
    sr_model fresh;
    if (sr_model_init(&fresh, m->p) != SR_OK || fresh.general != m->general) return 0;
    if (memcmp(fresh.sums, m->sums, sizeof fresh.sums) != 0) return 0;
    return m->general ? memcmp(fresh.cg, m->cg, sizeof fresh.cg) == 0 : memcmp(fresh.c, m->c, sizeof fresh.c) == 0;
}

static void test_sr_check_model_refuses_any_change(void)
{
    sr_model m, changed;
    sr_real p[SR_NPARAM];
    int kind, k, which, index;
    const char *array;
    for (kind = 0; kind < 2; ++kind) {
        if (kind) {
            general_robot_params(p);
            CHECK_STATUS(sr_model_init(&m, p), SR_OK);
        } else {
            paper_simulation_model(&m);
        }
        CHECK_STATUS(sr_check_model(&m), SR_OK);
        for (k = 0; k < N_ENTRIES; ++k)
            for (which = 0; which < N_CHANGES; ++which) {
                sr_real *e;
                changed = m;
                e = entry(&changed, k, &array, &index);
                *e = changed_value(*e, which);
                if (strcmp(array, m.general ? "c" : "cg") == 0 || (strcmp(array, "p") == 0 && same_model_of(&changed))) {
                    CHECK_STATUS(sr_check_model(&changed), SR_OK);
                } else if (sr_check_model(&changed) != SR_ERR_MODEL) {
                    sr_test_fail(__FILE__, __LINE__, "sr_check_model accepted %s[%d] = %g", array, index, (double)*e);
                }
            }
        for (k = 0; k < SR_MODEL_NSUMS; ++k) {
            changed = m;
            changed.sums[k] += 1;
            CHECK_STATUS(sr_check_model(&changed), SR_ERR_MODEL);
        }
        changed = m;
        changed.general = !m.general;
        CHECK_STATUS(sr_check_model(&changed), SR_ERR_MODEL);
    }
    CHECK_STATUS(sr_check_model(NULL), SR_ERR_NULL);
    memset(&m, 0, sizeof m);
    CHECK_STATUS(sr_check_model(&m), SR_ERR_MODEL);
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
    RUN_TEST(test_each_entry_point_refuses_a_change_to_what_it_reads_and_only_that);
    RUN_TEST(test_the_read_sets_are_proper_subsets);
    RUN_TEST(test_a_flipped_kind_or_a_changed_stamp_is_refused);
    RUN_TEST(test_sr_check_model_refuses_any_change);
    RUN_TEST(test_a_failed_sr_model_init_leaves_no_valid_model);
    RUN_TEST(test_sr_err_model_has_its_own_name);
    RUN_TEST(test_an_unknown_method_is_refused_even_without_rows);
    RUN_TEST(test_a_bad_dt_or_row_count_is_refused_before_any_row);
    RUN_TEST(test_arguments_are_checked_before_the_state);
    RUN_TEST(test_a_sensor_checks_model_pointers_body_and_mount_before_the_state);
}
