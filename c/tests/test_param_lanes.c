/*
 * test_param_lanes.c -- the lanes forms of the parameter sensitivity's two generated kernels
 * (sr_gen_general_accel_jacobian_terms_lanes, sr_gen_regressor_lanes) and the RKMK4 sensitivity
 * that runs them on blocks of states in lockstep (sr_step_and_param_jacobian_cols_batch and
 * sr_step_jacobian_param_cols_batch, c/src/sr_param_jacobians.c, where every free column moves pi
 * alone): each lane is the scalar kernel's bit for bit, on random robots and states; the batched
 * sensitivity equals the one-state path's (sr_step_param_jacobian, all columns, its bracket
 * generated, not the regressor's), and the batched step Jacobian F the state-by-state path's bit for
 * bit (sr_step_jacobian_param_cols_batch with r among the columns, which the lanes never take).
 */
#include "sr_test.h"

#include "sr_generated.h"

#include <math.h>
#include <string.h>

#define N 21 /* two full blocks of 8 and a short one; an odd count for the vector loops' tails */
#define NROBOTS 3
#define NCOLS 6

/* A general robot near general_robot_params with its masses, dampings and rotors, and each body's
 * centre and tensor (as a whole: it stays physical), scaled by random factors in [0.8, 1.25], and
 * a random slope in [-0.2, 0.2]. */
static void random_robot(test_rng *rng, sr_model *m)
{
    static const int single[] = {SR_P_m_S, SR_P_j_S, SR_P_k_S, SR_P_m_Y, SR_P_k_Y, SR_P_m_P, SR_P_k_P, SR_P_j_mY, SR_P_j_mP};
    static const int groups[4][2] = {{SR_P_c_Y_x, 3}, {SR_P_J_Y_xx, 6}, {SR_P_c_P_x, 3}, {SR_P_J_P_xx, 6}};
    sr_real p[SR_NPARAM];
    size_t k;
    int g, e;
    general_robot_params(p);
    for (k = 0; k < sizeof single / sizeof single[0]; ++k) p[single[k]] *= (sr_real)rng_uniform(rng, 0.8, 1.25);
    for (g = 0; g < 4; ++g) {
        const sr_real factor = (sr_real)rng_uniform(rng, 0.8, 1.25);
        for (e = 0; e < groups[g][1]; ++e) p[groups[g][0] + e] *= factor;
    }
    p[SR_P_slope] = (sr_real)rng_uniform(rng, -0.2, 0.2);
    CHECK_STATUS(sr_model_init(m, p), SR_OK);
    CHECK(m->general);
}

static void random_rows(test_rng *rng, const sr_model *m, sr_real x[N][SR_NX], sr_real u[N][SR_NU],
                        sr_real a[N][SR_NV])
{
    int i, k;
    for (i = 0; i < N; ++i) {
        random_state(rng, m->p[SR_P_r], 5.0, x[i]);
        for (k = 0; k < SR_NU; ++k) u[i][k] = (sr_real)rng_uniform(rng, -0.5, 0.5);
        for (k = 0; k < SR_NV; ++k) a[i][k] = (sr_real)rng_uniform(rng, -20.0, 20.0);
    }
}

/* The outputs of the two kernels on N states, one row per state. */
typedef struct {
    sr_real M[N][15], f[N][SR_NV], df[N][SR_NV * SR_NE], dfdu[N][SR_NV * SR_NU], dM[N][75], Y[N][SR_NV * SR_NPI];
} kernel_rows;

/* One workspace for all the tests (they run one after the other): the Cortex-M targets' RAM. */
static struct {
    sr_real x[N][SR_NX], u[N][SR_NU], a[N][SR_NV], next[N][SR_NX], Jp[N][SR_NE * NCOLS], ref[N][SR_NE * NCOLS];
    sr_real F[N][SR_NE * SR_NE], Fref[N][SR_NE * SR_NE], all[SR_NE * SR_NPARAM], cols_r[SR_NE * (NCOLS + 1)];
    kernel_rows out;
} ws;

static void lanes_rows(const sr_model *m, sr_real x[N][SR_NX], sr_real u[N][SR_NU], sr_real a[N][SR_NV],
                       kernel_rows *out)
{
    sr_real ok[N];
    int i;
    sr_gen_general_accel_jacobian_terms_lanes(m->cg, N, x[0], SR_NX, u[0], SR_NU, out->M[0], 15, out->f[0], SR_NV,
                                              out->df[0], SR_NV * SR_NE, out->dfdu[0], SR_NV * SR_NU, out->dM[0], 75, ok);
    for (i = 0; i < N; ++i) CHECK(ok[i] == 1);
    sr_gen_regressor_lanes(m->p, N, x[0], SR_NX, a[0], SR_NV, out->Y[0], SR_NV * SR_NPI, ok);
    for (i = 0; i < N; ++i) CHECK(ok[i] == 1);
}

/* Every row of `out` is the scalar kernels' at that state, bit for bit. */
static int equal_to_scalar_kernels(const sr_model *m, sr_real x[N][SR_NX], sr_real u[N][SR_NU],
                                   sr_real a[N][SR_NV], const kernel_rows *out)
{
    sr_real M[15], f[SR_NV], df[SR_NV * SR_NE], dfdu[SR_NV * SR_NU], dM[75], Y[SR_NV * SR_NPI];
    int i;
    for (i = 0; i < N; ++i) {
        if (sr_gen_general_accel_jacobian_terms(m->cg, x[i], u[i], M, f, df, dfdu, dM) != SR_GEN_OK
            || sr_gen_regressor(m->p, x[i], a[i], Y) != SR_GEN_OK)
            return 0;
        if (memcmp(M, out->M[i], sizeof M) || memcmp(f, out->f[i], sizeof f) || memcmp(df, out->df[i], sizeof df)
            || memcmp(dfdu, out->dfdu[i], sizeof dfdu) || memcmp(dM, out->dM[i], sizeof dM) || memcmp(Y, out->Y[i], sizeof Y))
            return 0;
    }
    return 1;
}

static void test_lanes_kernels_equal_the_scalar_kernels_bit_for_bit(void)
{
    test_rng rng = {29};
    sr_model m;
    int r;
    for (r = 0; r < NROBOTS; ++r) {
        random_robot(&rng, &m);
        random_rows(&rng, &m, ws.x, ws.u, ws.a);
        lanes_rows(&m, ws.x, ws.u, ws.a, &ws.out);
        CHECK(equal_to_scalar_kernels(&m, ws.x, ws.u, ws.a, &ws.out));
    }
}

/* The comparison above sees a one-ulp change of one output of one lane, in each kernel. */
static void test_kernel_comparison_sees_one_ulp_of_one_lane(void)
{
    test_rng rng = {31};
    sr_model m;
    random_robot(&rng, &m);
    random_rows(&rng, &m, ws.x, ws.u, ws.a);
    lanes_rows(&m, ws.x, ws.u, ws.a, &ws.out);
    CHECK(equal_to_scalar_kernels(&m, ws.x, ws.u, ws.a, &ws.out));
    ws.out.dM[N - 1][40] = next_up(ws.out.dM[N - 1][40]);
    CHECK(!equal_to_scalar_kernels(&m, ws.x, ws.u, ws.a, &ws.out));
    ws.out.dM[N - 1][40] = -next_up(-ws.out.dM[N - 1][40]);   /* back down one ulp */
    CHECK(equal_to_scalar_kernels(&m, ws.x, ws.u, ws.a, &ws.out));
    ws.out.Y[3][SR_NPI + 2] = next_up(ws.out.Y[3][SR_NPI + 2]);
    CHECK(!equal_to_scalar_kernels(&m, ws.x, ws.u, ws.a, &ws.out));
}

/* A fit's free entries, each moving pi alone (the lanes' case); COLS_R the same and r, whose column
 * (the rolling kinematics) keeps a batch on the state-by-state path. */
static const int COLS[NCOLS] = {SR_P_k_S, SR_P_m_P, SR_P_c_Y_x, SR_P_J_P_yy, SR_P_j_mY, SR_P_c_P_z};
static const int COLS_R[NCOLS + 1] = {SR_P_k_S, SR_P_m_P, SR_P_c_Y_x, SR_P_J_P_yy, SR_P_j_mY, SR_P_c_P_z, SR_P_r};

/* Largest |v| of an n-vector. */
static double largest(const sr_real *v, long n)
{
    double s = 0;
    long i;
    for (i = 0; i < n; ++i) s = fmax(s, fabs((double)v[i]));
    return s;
}

/* Largest |a - b| over the largest |b| of an n-vector pair. */
static double relative_difference(const sr_real *a, const sr_real *b, long n)
{
    double d = 0;
    long i;
    for (i = 0; i < n; ++i) d = fmax(d, fabs((double)a[i] - (double)b[i]));
    return d / largest(b, n);
}

/* The one-state paths at the N states: the sensitivity on COLS, COLS' columns of
 * sr_step_param_jacobian (every column, the bracket generated), into Jp; the step Jacobian F of
 * sr_step_jacobian_param_cols_batch on COLS_R, one state at a time (r's column: no lanes), into F. */
static void state_by_state(const sr_model *m, sr_real x[N][SR_NX], sr_real u[N][SR_NU], sr_real Jp[N][SR_NE * NCOLS],
                           sr_real F[N][SR_NE * SR_NE])
{
    int i, k, c;
    for (i = 0; i < N; ++i) {
        CHECK_STATUS(sr_step_param_jacobian(m, SR_RKMK4, x[i], u[i], SR_C(0.01), ws.all), SR_OK);
        for (k = 0; k < SR_NE; ++k)
            for (c = 0; c < NCOLS; ++c) Jp[i][k * NCOLS + c] = ws.all[k * SR_NPARAM + COLS[c]];
        CHECK_STATUS(sr_step_jacobian_param_cols_batch(m, SR_RKMK4, 1, x[i], u[i], SR_C(0.01), NCOLS + 1, COLS_R, F[i],
                                                       ws.cols_r, NULL),
                     SR_OK);
    }
}

/* The sensitivity on COLS of the workspace's N states in one batch call, into ws.next and ws.Jp. */
static int batch(const sr_model *m, long *row)
{
    return sr_step_and_param_jacobian_cols_batch(m, SR_RKMK4, N, ws.x[0], ws.u[0], SR_C(0.01), NCOLS, COLS, ws.next[0],
                                                 ws.Jp[0], row);
}

/* How far the first rows of the batch's sensitivity are from the state-by-state path's. */
static double batch_error(long rows)
{
    return relative_difference(ws.Jp[0], ws.ref[0], rows * SR_NE * NCOLS);
}

/* A random robot, N random states and the state-by-state path's sensitivity at them (ws.ref). */
static void new_case(test_rng *rng, sr_model *m)
{
    random_robot(rng, m);
    random_rows(rng, m, ws.x, ws.u, ws.a);
    state_by_state(m, ws.x, ws.u, ws.ref, ws.Fref);
}

/* F and the sensitivity on COLS of the workspace's N states in one sr_step_jacobian_param_cols_batch
 * call, into ws.F and ws.Jp. */
static int step_jacobian_batch(const sr_model *m, long *row)
{
    return sr_step_jacobian_param_cols_batch(m, SR_RKMK4, N, ws.x[0], ws.u[0], SR_C(0.01), NCOLS, COLS, ws.F[0],
                                             ws.Jp[0], row);
}

#define SENSITIVITY_TOL (TEST_EPS > 1e-10 ? 1e-5 : 1e-13)

static void test_lockstep_sensitivity_equals_the_state_by_state_path(void)
{
    sr_real one_next[SR_NX];
    test_rng rng = {37};
    sr_model m;
    long row = 5;
    int r;
    for (r = 0; r < NROBOTS; ++r) {
        new_case(&rng, &m);
        CHECK_STATUS(batch(&m, &row), SR_OK);
        CHECK(row == -1 && batch_error(N) <= SENSITIVITY_TOL);
        CHECK_STATUS(sr_step(&m, SR_RKMK4, ws.x[N - 1], ws.u[N - 1], SR_C(0.01), one_next), SR_OK);
        CHECK(relative_difference(ws.next[N - 1], one_next, SR_NX) <= (TEST_EPS > 1e-10 ? 1e-5 : 1e-12));
    }
}

static void test_lockstep_step_jacobian_and_sensitivity_equal_the_state_by_state_paths(void)
{
    test_rng rng = {47};
    sr_model m;
    long row = 5;
    int r;
    for (r = 0; r < NROBOTS; ++r) {
        new_case(&rng, &m);
        CHECK_STATUS(step_jacobian_batch(&m, &row), SR_OK);
        CHECK(row == -1 && memcmp(ws.F, ws.Fref, sizeof ws.F) == 0 && batch_error(N) <= SENSITIVITY_TOL);
    }
}

/* The F comparison sees one ulp of one entry of one state's F. */
static void test_step_jacobian_comparison_sees_one_ulp(void)
{
    test_rng rng = {53};
    sr_model m;
    sr_real *e = &ws.F[N / 2][SR_NE * 3 + 4];
    new_case(&rng, &m);
    CHECK_STATUS(step_jacobian_batch(&m, NULL), SR_OK);
    CHECK(memcmp(ws.F, ws.Fref, sizeof ws.F) == 0);
    *e = sizeof(sr_real) == sizeof(float) ? (sr_real)nextafterf((float)*e, 2 * (float)*e + 1)
                                          : (sr_real)nextafter((double)*e, 2 * (double)*e + 1);
    CHECK(memcmp(ws.F, ws.Fref, sizeof ws.F) != 0);
}

/* The comparison above sees a change of 1e-12 of one entry of one state's sensitivity. */
static void test_sensitivity_comparison_sees_a_perturbed_state(void)
{
    test_rng rng = {41};
    sr_model m;
    new_case(&rng, &m);
    CHECK_STATUS(batch(&m, NULL), SR_OK);
    CHECK(batch_error(N) <= SENSITIVITY_TOL);
    ws.Jp[N / 2][SR_NE * NCOLS / 2] += (sr_real)((TEST_EPS > 1e-10 ? 1e-4 : 1e-12) * largest(ws.ref[0], (long)N * SR_NE * NCOLS));
    CHECK(batch_error(N) > SENSITIVITY_TOL);
}

/* A state the lanes cannot take (a non-finite torque in the middle of a block) is reported at its
 * row with its status, and the rows before it, in its block too, are written as the others. */
static void test_a_bad_row_in_a_block_is_reported_at_its_row(void)
{
    test_rng rng = {43};
    sr_model m;
    long row = 0;
    new_case(&rng, &m);
    ws.u[19][1] = (sr_real)NAN;
    CHECK_STATUS(batch(&m, &row), SR_ERR_NONFINITE);
    CHECK(row == 19 && batch_error(19) <= SENSITIVITY_TOL);
}

void suite_param_lanes(void)
{
    RUN_TEST(test_lanes_kernels_equal_the_scalar_kernels_bit_for_bit);
    RUN_TEST(test_kernel_comparison_sees_one_ulp_of_one_lane);
    RUN_TEST(test_lockstep_sensitivity_equals_the_state_by_state_path);
    RUN_TEST(test_sensitivity_comparison_sees_a_perturbed_state);
    RUN_TEST(test_lockstep_step_jacobian_and_sensitivity_equal_the_state_by_state_paths);
    RUN_TEST(test_step_jacobian_comparison_sees_one_ulp);
    RUN_TEST(test_a_bad_row_in_a_block_is_reported_at_its_row);
}
