/*
 * test_status.c -- every class of bad input gets its own status code, from
 * every public function that can see it: NULL pointers, non-finite values,
 * rotations of the wrong kind, the rolling constraint, invalid and singular
 * parameters, dt <= 0, a negative step count, an unknown method.
 */
#include "sr_test.h"

#include <limits.h>
#include <math.h>
#include <string.h>

/* ---- a uniform view of the state-taking functions ---------------------------------
 * call(model, x, u, out) runs one public function; out has room for OUT_MAX reals. */
#define OUT_MAX (2 * SR_NX)

typedef struct api_fn {
    const char *name;
    int (*call)(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out);
    int reads_u;    /* a NaN in u must be reported */
    int has_output; /* out may be NULL only if not */
} api_fn;

static int call_accel(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    return sr_accel(m, x, u, out);
}
static int call_accel_batch(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    return sr_accel_batch(m, 1, x, u, out, NULL);
}
static int call_rhs(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    return sr_rhs(m, x, u, out);
}
static int call_inertia(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    (void)u;
    return sr_inertia(m, x, out);
}
static int call_energy(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    (void)u;
    return sr_energy(m, x, out);
}
static int call_residual(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    (void)u;
    return sr_equilibrium_residual(m, x, out);
}
static int call_contact_force(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    return sr_contact_force(m, x, u, out);
}
static int call_contact_force_batch(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    return sr_contact_force_batch(m, 1, x, u, out, NULL);
}
static int call_step(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    return sr_step(m, SR_LIE_EULER, x, u, SR_C(0.01), out);
}
static int call_simulate(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    long done;
    return sr_simulate(m, SR_LIE_EULER, x, SR_C(0.01), 1, u, out, &done);
}
static int call_check_state(const sr_model *m, const sr_real *x, const sr_real *u, sr_real *out)
{
    (void)u;
    (void)out;
    return sr_check_state(m, x);
}

static const api_fn API[] = {
    {"sr_accel", call_accel, 1, 1},
    {"sr_accel_batch", call_accel_batch, 1, 1},
    {"sr_rhs", call_rhs, 1, 1},
    {"sr_inertia", call_inertia, 0, 1},
    {"sr_energy", call_energy, 0, 1},
    {"sr_equilibrium_residual", call_residual, 0, 1},
    {"sr_contact_force", call_contact_force, 1, 1},
    {"sr_contact_force_batch", call_contact_force_batch, 1, 1},
    {"sr_step", call_step, 1, 1},
    {"sr_simulate", call_simulate, 1, 1},
    {"sr_check_state", call_check_state, 0, 0},
};
#define N_API ((int)(sizeof API / sizeof API[0]))

/* Every function of API on (x, u) must return `want`; prints which one did not. */
static void expect_all(const sr_model *m, const sr_real *x, const sr_real *u, int want,
                       int only_u_readers, const char *what)
{
    sr_real out[OUT_MAX];
    int k;
    for (k = 0; k < N_API; ++k) {
        int got;
        if (only_u_readers && !API[k].reads_u) continue;
        got = API[k].call(m, x, u, out);
        if (got != want)
            sr_test_fail(__FILE__, __LINE__, "%s with %s returned %d (%s), expected %d (%s)",
                         API[k].name, what, got, sr_status_string(got), want, sr_status_string(want));
    }
}

/* A valid state with some motion, and a valid input. */
static void good_input(sr_real x[SR_NX], sr_real u[SR_NU])
{
    make_state(x, 0.3, -0.4, 0.3);
    x[SR_X_w_S] = SR_C(0.2);
    x[SR_X_w_S + 1] = SR_C(-0.1);
    x[SR_X_w_Y] = SR_C(0.5);
    u[0] = SR_C(0.1);
    u[1] = SR_C(-0.05);
}

/* ---- tests -------------------------------------------------------------------- */

static void test_status_codes_are_distinct_and_named(void)
{
    const int codes[] = {SR_OK, SR_ERR_NULL, SR_ERR_NONFINITE, SR_ERR_NOT_ROTATION, SR_ERR_SINGULAR,
                         SR_ERR_PARAM, SR_ERR_ARG, SR_ERR_CONSTRAINT
#ifdef SR_ERR_STEP_SIZE /* the adaptive stepper's codes, where present */
                         , SR_ERR_STEP_SIZE, SR_ERR_MAX_STEPS
#endif
                         , SR_ERR_ENERGY, SR_ERR_MODEL
    };
    const int n = (int)(sizeof codes / sizeof codes[0]);
    int i, j;
    CHECK(SR_OK == 0);
    for (i = 0; i < n; ++i) {
        const char *name = sr_status_string(codes[i]);
        CHECK(name != NULL);
        if (name && strcmp(name, "unknown status") == 0)
            sr_test_fail(__FILE__, __LINE__, "sr_status_string(%d) has no name", codes[i]);
        for (j = 0; j < i; ++j) {
            CHECK(codes[i] != codes[j]);
            if (name && strcmp(name, sr_status_string(codes[j])) == 0)
                sr_test_fail(__FILE__, __LINE__, "codes %d and %d share the name \"%s\"", codes[i], codes[j], name);
        }
    }
    CHECK(strcmp(sr_status_string(-1), "unknown status") == 0);
    CHECK(strcmp(sr_status_string(INT_MAX), "unknown status") == 0);
}

static void test_valid_input_is_accepted_everywhere(void)
{
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    paper_simulation_model(&m);
    good_input(x, u);
    expect_all(&m, x, u, SR_OK, 0, "a valid state");
    expect_all(&m, x, NULL, SR_OK, 0, "u = NULL (zero torque)");
}

static void test_null_pointers(void)
{
    sr_model m;
    sr_real x[SR_NX], u[SR_NU], out[OUT_MAX], p[SR_NPARAM];
    long done, row;
    int k;
    paper_simulation_model(&m);
    paper_simulation_params(p);
    good_input(x, u);
    for (k = 0; k < N_API; ++k) {
        CHECK_STATUS(API[k].call(NULL, x, u, out), SR_ERR_NULL);
        CHECK_STATUS(API[k].call(&m, NULL, u, out), SR_ERR_NULL);
        if (API[k].has_output) CHECK_STATUS(API[k].call(&m, x, u, NULL), SR_ERR_NULL);
    }
    CHECK_STATUS(sr_model_init(NULL, p), SR_ERR_NULL);
    CHECK_STATUS(sr_model_init(&m, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_so3_exp(NULL, out), SR_ERR_NULL);
    CHECK_STATUS(sr_so3_exp(x + SR_X_w_S, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_accel_batch(&m, 1, x, u, out, &row), SR_OK);
    CHECK(row == -1);
    /* The optional out-parameters may be NULL. */
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), 1, NULL, out, NULL), SR_OK);
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), 1, NULL, NULL, &done), SR_ERR_NULL);
    CHECK(done == 0);
}

static void test_nonfinite_state_entries(void)
{
    const double bad[] = {NAN, INFINITY, -INFINITY};
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    int i, b;
    char what[64];
    paper_simulation_model(&m);
    for (i = 0; i < SR_NX; ++i)
        for (b = 0; b < 3; ++b) {
            good_input(x, u);
            x[i] = (sr_real)bad[b];
            snprintf(what, sizeof what, "x[%d] = %g", i, bad[b]);
            expect_all(&m, x, u, SR_ERR_NONFINITE, 0, what);
        }
}

static void test_nonfinite_torques(void)
{
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    int i;
    paper_simulation_model(&m);
    for (i = 0; i < SR_NU; ++i) {
        good_input(x, u);
        u[i] = (sr_real)NAN;
        expect_all(&m, x, u, SR_ERR_NONFINITE, 1, "u = NaN");
        u[i] = (sr_real)INFINITY;
        expect_all(&m, x, u, SR_ERR_NONFINITE, 1, "u = inf");
    }
}

/* Rotations the cheap checks of every function see: gamma (third row of R_S) not a
 * unit vector, R_Y and R_P not rotations in their planes. */
static void test_bad_rotations_seen_by_every_function(void)
{
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    int i;
    paper_simulation_model(&m);

    good_input(x, u);
    for (i = 0; i < 9; ++i) x[i] *= SR_C(1.01); /* R_S scaled: |gamma| = 1.01 */
    expect_all(&m, x, u, SR_ERR_NOT_ROTATION, 0, "R_S = 1.01 I");

    good_input(x, u);
    rot_z(0.3, x + SR_X_R_Y); /* R_Y about z */
    expect_all(&m, x, u, SR_ERR_NOT_ROTATION, 0, "R_Y about z");

    good_input(x, u);
    rot_z(0.3, x + SR_X_R_P); /* R_P about z */
    expect_all(&m, x, u, SR_ERR_NOT_ROTATION, 0, "R_P about z");

    good_input(x, u);
    x[SR_X_R_P + 2] *= SR_C(1.5); /* R_P's first column no longer unit */
    expect_all(&m, x, u, SR_ERR_NOT_ROTATION, 0, "R_P stretched");
}

/* sr_check_state is the full check: everything the cheap checks cannot see. */
static void test_check_state_rejects_every_non_rotation(void)
{
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    const double tol = (double)SR_ROTATION_TOL;
    paper_simulation_model(&m);

    good_input(x, u); /* R_S a reflection (det -1) with an intact gamma row */
    x[0] = -x[0]; x[1] = -x[1]; x[2] = -x[2];
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_NOT_ROTATION);

    good_input(x, u); /* R_S sheared, gamma intact */
    x[1] = SR_C(0.01);
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_NOT_ROTATION);

    good_input(x, u); /* first row of R_S stretched */
    x[0] = SR_C(1.01);
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_NOT_ROTATION);

    good_input(x, u); /* R_Y a rotation, but about y: not about x */
    rot_y(0.3, x + SR_X_R_Y);
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_NOT_ROTATION);

    good_input(x, u); /* R_Y = [[1,0,0],[0,c,s],[0,s,-c]]: orthonormal columns, det -1 */
    x[SR_X_R_Y + 5] = -x[SR_X_R_Y + 5];
    x[SR_X_R_Y + 8] = -x[SR_X_R_Y + 8];
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_NOT_ROTATION);

    good_input(x, u); /* R_P about x: not about y */
    rot_x(0.3, x + SR_X_R_P);
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_NOT_ROTATION);

    good_input(x, u); /* R_Y with a stray entry outside its plane */
    x[SR_X_R_Y + 1] = SR_C(1e-3);
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_NOT_ROTATION);

    /* Within tolerance: accepted. */
    good_input(x, u);
    x[0] += (sr_real)(0.1 * tol);
    CHECK_STATUS(sr_check_state(&m, x), SR_OK);
}

/* sr_step gives the full check too: a loop of single steps (firmware) must not carry a
 * corrupt state on.  Each corruption below passes the kernels' cheap checks. */
static void test_step_checks_the_state_in_full(void)
{
    sr_model m;
    sr_real x[SR_NX], u[SR_NU], next[SR_NX];
    int i, k;
    paper_simulation_model(&m);
    for (k = 0; k < 5; ++k) {
        int expected = SR_ERR_NOT_ROTATION;
        good_input(x, u);
        switch (k) {
        case 0: x[0] = SR_C(2.0); break;                          /* a row of R_S of length 2 */
        case 1: x[0] = -x[0]; x[1] = -x[1]; x[2] = -x[2]; break;  /* R_S a reflection */
        case 2: x[1] = SR_C(0.01); break;                         /* R_S sheared */
        case 3: x[10] = SR_C(1e-3); break;                        /* R_Y not about x */
        default: x[29] = SR_C(0.31); expected = SR_ERR_CONSTRAINT; /* q_z != r */
        }
        for (i = 0; i < SR_NX; ++i) next[i] = SR_C(-7.0);
        CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u, SR_C(0.01), next), expected);
        CHECK_STATUS(sr_step(&m, SR_RKMK4, x, u, SR_C(0.01), next), expected);
        for (i = 0; i < SR_NX; ++i) CHECK(next[i] == SR_C(-7.0));
    }
}

static void test_rolling_constraint(void)
{
    sr_model m;
    sr_real x[SR_NX], u[SR_NU];
    paper_simulation_model(&m);
    good_input(x, u);
    x[SR_X_q + 2] = SR_C(0.31); /* q_z != r */
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_CONSTRAINT);
    x[SR_X_q + 2] = SR_C(0.0);
    CHECK_STATUS(sr_check_state(&m, x), SR_ERR_CONSTRAINT);
}

static void test_invalid_parameters(void)
{
    const int positive[] = {SR_P_r, SR_P_m_S, SR_P_j_S, SR_P_m_Y, SR_P_m_P};
    const int nonnegative[] = {SR_P_k_S, SR_P_k_Y, SR_P_k_P, SR_P_j_mY, SR_P_j_mP, SR_P_g};
    sr_model m;
    sr_real p[SR_NPARAM], pp[SR_NPAPER];
    int i;
    for (i = 0; i < SR_NPARAM; ++i) {
        general_robot_params(p);
        p[i] = (sr_real)NAN;
        CHECK_STATUS(sr_model_init(&m, p), SR_ERR_NONFINITE);
        p[i] = (sr_real)INFINITY;
        CHECK_STATUS(sr_model_init(&m, p), SR_ERR_NONFINITE);
    }
    for (i = 0; i < (int)(sizeof positive / sizeof positive[0]); ++i) {
        general_robot_params(p);
        p[positive[i]] = 0;
        CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
        p[positive[i]] = SR_C(-1.0);
        CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
    }
    for (i = 0; i < (int)(sizeof nonnegative / sizeof nonnegative[0]); ++i) {
        general_robot_params(p);
        p[nonnegative[i]] = SR_C(-0.01);
        CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
        p[nonnegative[i]] = 0; /* no damping, no rotor, no gravity: allowed */
        CHECK_STATUS(sr_model_init(&m, p), SR_OK);
    }
    general_robot_params(p); /* a principal moment above the sum of the other two */
    p[SR_P_J_Y_zz] = SR_C(0.7);
    CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
    general_robot_params(p); /* the pendulum's centre of mass outside the shell */
    p[SR_P_c_P_z] = SR_C(-0.31);
    CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
    general_robot_params(p);
    p[SR_P_slope] = SR_C(1.6);
    CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
    paper_simulation_paper(pp); /* the paper's robot: the yoke's corners stick out of the shell */
    pp[SR_PAPER_h] = SR_C(0.6);
    CHECK_STATUS(sr_paper_params(pp, p), SR_ERR_PARAM);
    paper_simulation_paper(pp); /* the pendulum is longer than the radius */
    pp[SR_PAPER_l] = SR_C(0.31);
    CHECK_STATUS(sr_paper_params(pp, p), SR_ERR_PARAM);
    pp[SR_PAPER_l] = (sr_real)NAN;
    CHECK_STATUS(sr_paper_params(pp, p), SR_ERR_NONFINITE);
    CHECK_STATUS(sr_paper_params(NULL, p), SR_ERR_NULL);
    CHECK_STATUS(sr_paper_params(pp, NULL), SR_ERR_NULL);
}

/* sr_check_params(p) must give (status, bad_index, rule); prints the case when it does not. */
static void expect_param_verdict(const sr_real p[SR_NPARAM], int status, int bad_index, int rule, const char *what)
{
    int got_index = -7, got_rule = -7;
    const int got = sr_check_params(p, &got_index, &got_rule);
    if (got != status || got_index != bad_index || got_rule != rule)
        sr_test_fail(__FILE__, __LINE__, "%s: got status %d, index %d, rule %d; want %d, %d, %d", what, got,
                     got_index, got_rule, status, bad_index, rule);
}

/* The same for sr_check_paper_params. */
static void expect_paper_verdict(const sr_real pp[SR_NPAPER], int status, int bad_index, int rule, const char *what)
{
    int got_index = -7, got_rule = -7;
    const int got = sr_check_paper_params(pp, &got_index, &got_rule);
    if (got != status || got_index != bad_index || got_rule != rule)
        sr_test_fail(__FILE__, __LINE__, "%s: got status %d, index %d, rule %d; want %d, %d, %d", what, got,
                     got_index, got_rule, status, bad_index, rule);
}

/* sr_check_params names the first rule broken and the parameter that breaks it, in the order
 * of spherical_robot.h, and keeps its outputs at "none" for valid parameters. */
static void test_check_params_names_the_rule_and_the_parameter(void)
{
    const int positive[] = {SR_P_r, SR_P_m_S, SR_P_j_S, SR_P_m_Y, SR_P_m_P};
    const int nonnegative[] = {SR_P_k_S, SR_P_k_Y, SR_P_k_P, SR_P_j_mY, SR_P_j_mP, SR_P_g};
    const int nonzero[] = {SR_P_n_Y, SR_P_n_P};
    sr_real p[SR_NPARAM];
    int i, rule;
    general_robot_params(p);
    expect_param_verdict(p, SR_OK, -1, SR_PARAM_RULE_NONE, "valid");
    CHECK_STATUS(sr_check_params(p, NULL, NULL), SR_OK);
    CHECK_STATUS(sr_check_params(NULL, NULL, NULL), SR_ERR_NULL);
    for (i = 0; i < SR_NPARAM; ++i) {
        general_robot_params(p);
        p[i] = (sr_real)NAN;
        expect_param_verdict(p, SR_ERR_NONFINITE, i, SR_PARAM_RULE_FINITE, "NaN");
        p[SR_P_m_S] = -1; /* a later rule broken too: the first one is reported */
        if (i != SR_P_m_S) expect_param_verdict(p, SR_ERR_NONFINITE, i, SR_PARAM_RULE_FINITE, "NaN first");
    }
    for (i = 0; i < (int)(sizeof positive / sizeof positive[0]); ++i) {
        general_robot_params(p);
        p[positive[i]] = 0;
        expect_param_verdict(p, SR_ERR_PARAM, positive[i], SR_PARAM_RULE_POSITIVE, "zero");
    }
    for (i = 0; i < (int)(sizeof nonnegative / sizeof nonnegative[0]); ++i) {
        general_robot_params(p);
        p[nonnegative[i]] = SR_C(-0.01);
        expect_param_verdict(p, SR_ERR_PARAM, nonnegative[i], SR_PARAM_RULE_NONNEGATIVE, "negative");
    }
    for (i = 0; i < (int)(sizeof nonzero / sizeof nonzero[0]); ++i) {
        general_robot_params(p);
        p[nonzero[i]] = 0;
        expect_param_verdict(p, SR_ERR_PARAM, nonzero[i], SR_PARAM_RULE_NONZERO, "gear ratio zero");
    }
    general_robot_params(p);
    p[SR_P_J_P_zz] = SR_C(0.008); /* 0.008 > 0.004 + 0.0035 */
    expect_param_verdict(p, SR_ERR_PARAM, SR_P_J_P_xx, SR_PARAM_RULE_INERTIA, "triangle inequality");
    p[SR_P_J_P_zz] = SR_C(0.0074); /* 0.0074 < 0.0075 */
    expect_param_verdict(p, SR_OK, -1, SR_PARAM_RULE_NONE, "triangle inequality kept");
    general_robot_params(p);
    p[SR_P_J_Y_xy] = SR_C(0.3); /* diagonal fine, not positive semidefinite */
    expect_param_verdict(p, SR_ERR_PARAM, SR_P_J_Y_xx, SR_PARAM_RULE_INERTIA, "indefinite tensor");
    general_robot_params(p);
    p[SR_P_c_Y_x] = SR_C(0.3);
    expect_param_verdict(p, SR_ERR_PARAM, SR_P_c_Y_x, SR_PARAM_RULE_INSIDE, "yoke's centre on the shell");
    general_robot_params(p);
    p[SR_P_slope] = SR_C(-1.5708);
    expect_param_verdict(p, SR_ERR_PARAM, SR_P_slope, SR_PARAM_RULE_SLOPE, "slope");
    p[SR_P_slope] = SR_C(-1.5707);
    expect_param_verdict(p, SR_OK, -1, SR_PARAM_RULE_NONE, "steep slope");
    /* The paper's twelve: their own rules. */
    {
        const int paper_positive[] = {SR_PAPER_r, SR_PAPER_m_S, SR_PAPER_b, SR_PAPER_h, SR_PAPER_m_b,
                                      SR_PAPER_m_h, SR_PAPER_l, SR_PAPER_m_P};
        sr_real pp[SR_NPAPER];
        for (i = 0; i < (int)(sizeof paper_positive / sizeof paper_positive[0]); ++i) {
            paper_simulation_paper(pp);
            pp[paper_positive[i]] = 0;
            expect_paper_verdict(pp, SR_ERR_PARAM, paper_positive[i], SR_PARAM_RULE_POSITIVE, "paper zero");
        }
        paper_simulation_paper(pp);
        pp[SR_PAPER_b] = SR_C(0.4); /* half-diagonal sqrt(0.16 + 0.25)/2 = 0.32 > r = 0.3 */
        expect_paper_verdict(pp, SR_ERR_PARAM, SR_PAPER_b, SR_PARAM_RULE_YOKE_FITS, "yoke");
        pp[SR_PAPER_b] = SR_C(0.33); /* 0.2996 <= 0.3: fits */
        expect_paper_verdict(pp, SR_OK, -1, SR_PARAM_RULE_NONE, "yoke just fits");
        paper_simulation_paper(pp);
        pp[SR_PAPER_l] = SR_C(0.31);
        expect_paper_verdict(pp, SR_ERR_PARAM, SR_PAPER_l, SR_PARAM_RULE_PENDULUM_FITS, "pendulum");
        pp[SR_PAPER_l] = pp[SR_PAPER_r]; /* touching the shell: allowed */
        expect_paper_verdict(pp, SR_OK, -1, SR_PARAM_RULE_NONE, "pendulum just fits");
    }
    /* Every rule has its own text. */
    for (rule = SR_PARAM_RULE_NONE; rule <= SR_PARAM_RULE_SLOPE; ++rule) {
        int other;
        CHECK(strcmp(sr_param_rule_string(rule), "unknown rule") != 0);
        for (other = SR_PARAM_RULE_NONE; other < rule; ++other)
            CHECK(strcmp(sr_param_rule_string(rule), sr_param_rule_string(other)) != 0);
    }
    CHECK(strcmp(sr_param_rule_string(SR_PARAM_RULE_SLOPE + 1), "unknown rule") == 0);
}

/* Parameters that pass the range checks but whose evaluation underflows: a robot so small that
 * the paper's conversion gives j_S = 0 (rejected by the positivity rule, SR_ERR_PARAM).  The
 * kernels keep their own pivot check (SR_ERR_SINGULAR). */
static void test_singular_inertia(void)
{
#ifdef SR_USE_FLOAT
    const sr_real tiny = SR_C(1e-30); /* tiny^2 underflows in float */
#else
    const sr_real tiny = SR_C(1e-200); /* tiny^2 underflows in double */
#endif
    sr_model m;
    sr_real p[SR_NPARAM], pp[SR_NPAPER];
    paper_simulation_paper(pp);
    pp[SR_PAPER_r] = pp[SR_PAPER_b] = pp[SR_PAPER_h] = pp[SR_PAPER_l] = tiny; /* r, b, h, l */
    CHECK_STATUS(sr_paper_params(pp, p), SR_OK);
    CHECK_STATUS(sr_model_init(&m, p), SR_ERR_PARAM);
}

static void test_bad_time_step(void)
{
    const double bad_dt[] = {0.0, -0.0, -0.01, NAN, INFINITY, -INFINITY};
    sr_model m;
    sr_real x[SR_NX], u[SR_NU], traj[3 * SR_NX];
    long done = -7;
    int i;
    paper_simulation_model(&m);
    good_input(x, u);
    for (i = 0; i < (int)(sizeof bad_dt / sizeof bad_dt[0]); ++i) {
        CHECK_STATUS(sr_step(&m, SR_LIE_EULER, x, u, (sr_real)bad_dt[i], traj), SR_ERR_ARG);
        CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, (sr_real)bad_dt[i], 2, NULL, traj, &done), SR_ERR_ARG);
        CHECK(done == 0);
    }
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), -1, NULL, traj, &done), SR_ERR_ARG);
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), 0, NULL, traj, &done), SR_OK);
    CHECK(done == 0 && memcmp(traj, x, sizeof x) == 0);
}

static void test_unknown_method(void)
{
    /* Values no method will ever take (new methods get small non-negative codes). */
    const int bad[] = {-1, 12345, INT_MAX, INT_MIN};
    sr_model m;
    sr_real x[SR_NX], u[SR_NU], traj[3 * SR_NX];
    long done = -7;
    int i;
    paper_simulation_model(&m);
    good_input(x, u);
    for (i = 0; i < (int)(sizeof bad / sizeof bad[0]); ++i) {
        CHECK_STATUS(sr_step(&m, bad[i], x, u, SR_C(0.01), traj), SR_ERR_ARG);
        CHECK_STATUS(sr_simulate(&m, bad[i], x, SR_C(0.01), 2, NULL, traj, &done), SR_ERR_ARG);
        CHECK(done == 0);
    }
}

static void test_simulate_reports_the_failing_step(void)
{
    sr_model m;
    sr_real x[SR_NX], u[4 * SR_NU], traj[5 * SR_NX];
    long done = -7;
    int i;
    paper_simulation_model(&m);
    good_input(x, u);
    for (i = 0; i < 4 * SR_NU; ++i) u[i] = SR_C(0.05);
    u[2 * SR_NU + 1] = (sr_real)NAN; /* the torque of step 3 */
    CHECK_STATUS(sr_simulate(&m, SR_LIE_EULER, x, SR_C(0.01), 4, u, traj, &done), SR_ERR_NONFINITE);
    CHECK(done == 2);
}

static void test_accel_batch_arguments(void)
{
    sr_model m;
    sr_real x[3 * SR_NX], u[3 * SR_NU], a[3 * SR_NV];
    long row = 99;
    int i;
    paper_simulation_model(&m);
    for (i = 0; i < 3; ++i) good_input(x + i * SR_NX, u + i * SR_NU);
    CHECK_STATUS(sr_accel_batch(&m, -1, x, u, a, &row), SR_ERR_ARG);
    CHECK_STATUS(sr_accel_batch(&m, 0, x, u, a, &row), SR_OK);
    CHECK(row == -1);
    CHECK_STATUS(sr_accel_batch(&m, 3, x, NULL, a, &row), SR_OK);
    CHECK(row == -1);
    x[2 * SR_NX + 7] = (sr_real)NAN;
    CHECK_STATUS(sr_accel_batch(&m, 3, x, u, a, &row), SR_ERR_NONFINITE);
    CHECK(row == 2);
    x[2 * SR_NX + 7] = 0;
    rot_z(0.2, x + SR_NX + 9);
    CHECK_STATUS(sr_accel_batch(&m, 3, x, u, a, &row), SR_ERR_NOT_ROTATION);
    CHECK(row == 1);
}

void suite_status(void)
{
    RUN_TEST(test_status_codes_are_distinct_and_named);
    RUN_TEST(test_valid_input_is_accepted_everywhere);
    RUN_TEST(test_null_pointers);
    RUN_TEST(test_nonfinite_state_entries);
    RUN_TEST(test_nonfinite_torques);
    RUN_TEST(test_bad_rotations_seen_by_every_function);
    RUN_TEST(test_check_state_rejects_every_non_rotation);
    RUN_TEST(test_step_checks_the_state_in_full);
    RUN_TEST(test_rolling_constraint);
    RUN_TEST(test_invalid_parameters);
    RUN_TEST(test_check_params_names_the_rule_and_the_parameter);
    RUN_TEST(test_singular_inertia);
    RUN_TEST(test_bad_time_step);
    RUN_TEST(test_unknown_method);
    RUN_TEST(test_simulate_reports_the_failing_step);
    RUN_TEST(test_accel_batch_arguments);
}
