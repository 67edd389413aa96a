/* sr_model.c -- status strings, the parameter rules and the model's initialisation.
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_checks.h"
#include "sr_kernels.h"
#include "sr_argcheck.h"

#include <stddef.h>
#include <string.h>

const char *sr_status_string(int status)
{
    switch (status) {
    case SR_OK: return "ok";
    case SR_ERR_NULL: return "null pointer";
    case SR_ERR_NONFINITE: return "non-finite value";
    case SR_ERR_NOT_ROTATION: return "not a rotation matrix of the required kind";
    case SR_ERR_SINGULAR: return "singular generalized inertia";
    case SR_ERR_PARAM: return "parameter out of range";
    case SR_ERR_ARG: return "invalid argument";
    case SR_ERR_CONSTRAINT: return "constraint violated (q_z != r)";
    case SR_ERR_STEP_SIZE: return "adaptive step size below the rounding level of t";
    case SR_ERR_MAX_STEPS: return "adaptive stepping exceeded max_steps";
    case SR_ERR_ENERGY: return "energy rose without input power beyond the guard's tolerance";
    case SR_ERR_MODEL: return "model not valid (not filled by sr_model_init, or changed since)";
    default: return "unknown status";
    }
}

const char *sr_param_rule_string(int rule)
{
    switch (rule) {
    case SR_PARAM_RULE_NONE: return "within range";
    case SR_PARAM_RULE_FINITE: return "must be finite";
    case SR_PARAM_RULE_POSITIVE: return "must be > 0";
    case SR_PARAM_RULE_NONNEGATIVE: return "must be >= 0";
    case SR_PARAM_RULE_YOKE_FITS:
        return "the yoke does not fit inside the shell (its half-diagonal sqrt(b^2 + h^2)/2 must be <= r)";
    case SR_PARAM_RULE_PENDULUM_FITS: return "the pendulum does not fit inside the shell (l must be <= r)";
    case SR_PARAM_RULE_NONZERO: return "must be nonzero";
    case SR_PARAM_RULE_INERTIA:
        return "not a physical inertia tensor (tr(J)/2 I - J, the second moment of the mass, must be positive semidefinite: J positive semidefinite with each principal moment <= the sum of the other two)";
    case SR_PARAM_RULE_INSIDE: return "the centre of mass must lie inside the shell (|c| < r)";
    case SR_PARAM_RULE_SLOPE: return "the slope must lie strictly between -pi/2 and pi/2";
    default: return "unknown rule";
    }
}

/* The first index of list (n entries) whose parameter fails test, or -1. */
static int first_failing(const sr_real *p, const int *list, int n, int (*test)(sr_real))
{
    int i;
    for (i = 0; i < n; ++i)
        if (!test(p[list[i]])) return list[i];
    return -1;
}

static int is_positive(sr_real v) { return v > 0; }
static int is_nonnegative(sr_real v) { return v >= 0; }
static int is_nonzero(sr_real v) { return v != 0; }

#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

/* Report the verdict of a check function (the first broken rule at index bad, or none). */
static int verdict(int bad, int broken, int *bad_index, int *rule)
{
    if (bad < 0) return SR_OK;
    if (bad_index) *bad_index = bad;
    if (rule) *rule = broken;
    return broken == SR_PARAM_RULE_FINITE ? SR_ERR_NONFINITE : SR_ERR_PARAM;
}

int sr_check_paper_params(const sr_real paper[SR_NPAPER], int *bad_index, int *rule)
{
    static const int positive[] = {SR_PAPER_r, SR_PAPER_m_S, SR_PAPER_b, SR_PAPER_h, SR_PAPER_m_b,
                                   SR_PAPER_m_h, SR_PAPER_l, SR_PAPER_m_P};
    static const int nonnegative[] = {SR_PAPER_k_S, SR_PAPER_k_Y, SR_PAPER_k_P, SR_PAPER_g};
    const sr_real *p = paper;
    int i, bad = -1, broken = SR_PARAM_RULE_NONE;
    if (bad_index) *bad_index = -1;
    if (rule) *rule = SR_PARAM_RULE_NONE;
    if (!paper) return SR_ERR_NULL;
    for (i = 0; i < SR_NPAPER && bad < 0; ++i)
        if (!isfinite(p[i])) bad = i, broken = SR_PARAM_RULE_FINITE;
    if (bad < 0 && (bad = first_failing(p, positive, COUNT(positive), is_positive)) >= 0) broken = SR_PARAM_RULE_POSITIVE;
    if (bad < 0 && (bad = first_failing(p, nonnegative, COUNT(nonnegative), is_nonnegative)) >= 0) broken = SR_PARAM_RULE_NONNEGATIVE;
    /* The yoke's corners and the pendulum's tip must fit inside the shell. */
    if (bad < 0 && p[SR_PAPER_b] * p[SR_PAPER_b] + p[SR_PAPER_h] * p[SR_PAPER_h] > SR_C(4.0) * p[SR_PAPER_r] * p[SR_PAPER_r])
        bad = SR_PAPER_b, broken = SR_PARAM_RULE_YOKE_FITS;
    if (bad < 0 && p[SR_PAPER_l] > p[SR_PAPER_r]) bad = SR_PAPER_l, broken = SR_PARAM_RULE_PENDULUM_FITS;
    return verdict(bad, broken, bad_index, rule);
}

int sr_paper_params(const sr_real paper[SR_NPAPER], sr_real params[SR_NPARAM])
{
    sr_real p[SR_NPARAM];
    int status;
    if (!params) return SR_ERR_NULL;
    status = sr_check_paper_params(paper, NULL, NULL);
    if (status != SR_OK) return status;
    status = sr_gen_paper_params(paper, p);
    if (status != SR_OK) return SR_ERR_PARAM; /* finite values whose squares overflow */
    return deliver(SR_OK, p, SR_NPARAM, params);
}

int sr_paper_params_unchecked(const sr_real paper[SR_NPAPER], sr_real params[SR_NPARAM])
{
    sr_real p[SR_NPARAM];
    if (!paper || !params) return SR_ERR_NULL;
    if (sr_gen_paper_params(paper, p) != SR_OK) return SR_ERR_NONFINITE;
    return deliver(SR_OK, p, SR_NPARAM, params);
}

/* A physical inertia tensor: S = tr(J)/2 I - J (= the integral of rho rho^T dm) positive
 * semidefinite, tested on its principal minors with a tolerance of rounding relative to tr(J)
 * (a slender rod's zero moment, or a planar body's J_zz = J_xx + J_yy, sits on the boundary). */
static int physical_inertia(const sr_real *J6)
{
    const sr_real xx = J6[0], yy = J6[1], zz = J6[2], xy = J6[3], xz = J6[4], yz = J6[5];
    const sr_real h = (xx + yy + zz) / 2, a = h - xx, b = h - yy, c = h - zz;
    const sr_real t = xx + yy + zz, tol = 64 * SR_EPSILON * t;
    if (!(t > 0)) return 0;
    if (a < -tol || b < -tol || c < -tol) return 0;
    if (a * b - xy * xy < -tol * t || a * c - xz * xz < -tol * t || b * c - yz * yz < -tol * t) return 0;
    /* det of [[a, -xy, -xz], [-xy, b, -yz], [-xz, -yz, c]] */
    return a * (b * c - yz * yz) - c * xy * xy - b * xz * xz - 2 * xy * yz * xz >= -tol * t * t;
}

static int inside_shell(const sr_real *c3, sr_real r)
{
    return c3[0] * c3[0] + c3[1] * c3[1] + c3[2] * c3[2] < r * r;
}

/* The one statement of the parameter rules (the Python Params calls this function too). */
int sr_check_params(const sr_real params[SR_NPARAM], int *bad_index, int *rule)
{
    static const int positive[] = {SR_P_r, SR_P_m_S, SR_P_j_S, SR_P_m_Y, SR_P_m_P};
    static const int nonnegative[] = {SR_P_k_S, SR_P_k_Y, SR_P_k_P, SR_P_j_mY, SR_P_j_mP, SR_P_g};
    static const int nonzero[] = {SR_P_n_Y, SR_P_n_P};
    const sr_real *p = params;
    int i, bad = -1, broken = SR_PARAM_RULE_NONE;
    if (bad_index) *bad_index = -1;
    if (rule) *rule = SR_PARAM_RULE_NONE;
    if (!params) return SR_ERR_NULL;
    for (i = 0; i < SR_NPARAM && bad < 0; ++i)
        if (!isfinite(p[i])) bad = i, broken = SR_PARAM_RULE_FINITE;
    if (bad < 0 && (bad = first_failing(p, positive, COUNT(positive), is_positive)) >= 0) broken = SR_PARAM_RULE_POSITIVE;
    if (bad < 0 && (bad = first_failing(p, nonnegative, COUNT(nonnegative), is_nonnegative)) >= 0) broken = SR_PARAM_RULE_NONNEGATIVE;
    if (bad < 0 && (bad = first_failing(p, nonzero, COUNT(nonzero), is_nonzero)) >= 0) broken = SR_PARAM_RULE_NONZERO;
    if (bad < 0 && !physical_inertia(p + SR_P_J_Y_xx)) bad = SR_P_J_Y_xx, broken = SR_PARAM_RULE_INERTIA;
    if (bad < 0 && !physical_inertia(p + SR_P_J_P_xx)) bad = SR_P_J_P_xx, broken = SR_PARAM_RULE_INERTIA;
    if (bad < 0 && !inside_shell(p + SR_P_c_Y_x, p[SR_P_r])) bad = SR_P_c_Y_x, broken = SR_PARAM_RULE_INSIDE;
    if (bad < 0 && !inside_shell(p + SR_P_c_P_x, p[SR_P_r])) bad = SR_P_c_P_x, broken = SR_PARAM_RULE_INSIDE;
    if (bad < 0 && !(SR_FABS(p[SR_P_slope]) < SR_C(1.5707963267948966))) bad = SR_P_slope, broken = SR_PARAM_RULE_SLOPE;
    return verdict(bad, broken, bad_index, rule);
}

/* The paper's geometry, exactly (see sr_model): then the paper-geometry kernels apply. */
static int paper_geometry(const sr_real *p)
{
    return p[SR_P_c_Y_x] == 0 && p[SR_P_c_Y_y] == 0 && p[SR_P_c_Y_z] == 0
        && p[SR_P_J_Y_xy] == 0 && p[SR_P_J_Y_xz] == 0 && p[SR_P_J_Y_yz] == 0
        && p[SR_P_J_Y_zz] == p[SR_P_J_Y_xx] + p[SR_P_J_Y_yy]
        && p[SR_P_c_P_x] == 0 && p[SR_P_c_P_y] == 0
        && p[SR_P_J_P_xy] == 0 && p[SR_P_J_P_xz] == 0 && p[SR_P_J_P_yz] == 0
        && p[SR_P_J_P_xx] == p[SR_P_J_P_yy] && p[SR_P_J_P_zz] == 0
        && p[SR_P_j_mY] == 0 && p[SR_P_j_mP] == 0 && p[SR_P_slope] == 0;
}

/* The reference state of sr_model_init's checks: R_S = R_Y = R_P = I, q = (0, 0, r), at rest. */
static void reference_state(sr_real r, sr_real x[SR_NX])
{
    int i;
    for (i = 0; i < SR_NX; ++i) x[i] = 0;
    for (i = 0; i < 3; ++i) x[SR_X_R_S + 4 * i] = x[SR_X_R_Y + 4 * i] = x[SR_X_R_P + 4 * i] = 1;
    x[SR_X_q + 2] = r;
}

int sr_model_init(sr_model *model, const sr_real params[SR_NPARAM])
{
    sr_model m;
    sr_real x[SR_NX], M[SR_NV * SR_NV], a[SR_NV], energy;
    int i, status;
    if (!model || !params) return SR_ERR_NULL;
    status = sr_check_params(params, NULL, NULL);
    if (status != SR_OK) return status;
    for (i = 0; i < SR_NPARAM; ++i) m.p[i] = params[i];
    m.general = !paper_geometry(params);
    /* Both constants arrays are filled, whichever kernels are chosen: a model is one value. */
    for (i = 0; i < SR_GEN_NCONST; ++i) m.c[i] = 0;
    for (i = 0; i < SR_GEN_GENERAL_NCONST; ++i) m.cg[i] = 0;
    if (!m.general) sr_gen_constants(m.p, m.c);
#ifdef SR_PAPER_ONLY
    if (m.general) return SR_ERR_PARAM; /* built without the general kernels (see sr_kernels.c) */
#else
    sr_gen_general_constants(m.p, m.cg);
#endif
    /* Values in range one by one can still overflow or underflow together (r = 1e200, or every
     * length 1e-200): evaluate the model once at the reference state.  M is positive definite
     * for any positive masses and lengths in exact arithmetic, so a failing pivot means that
     * the inertias underflowed. */
    if (m.general ? !all_finite(m.cg, SR_GEN_GENERAL_NCONST_NAMED) : !all_finite(m.c, SR_GEN_NCONST_NAMED))
        return SR_ERR_PARAM;
    reference_state(params[SR_P_r], x);
    if (sr_internal_inertia(&m, x, M) != SR_OK) return SR_ERR_PARAM;
    status = sr_internal_accel(&m, x, sr_zero_u, a);
    if (status == SR_GEN_SINGULAR) return SR_ERR_SINGULAR;
    /* After the pivots, so that inertias that underflow to zero (and whose reciprocals among the
     * pooled constants are infinite) are reported as singular. */
    if (status != SR_OK || !(m.general ? all_finite(m.cg, SR_GEN_GENERAL_NCONST) : all_finite(m.c, SR_GEN_NCONST)))
        return SR_ERR_PARAM;
    if (sr_internal_energy(&m, x, &energy) != SR_OK) return SR_ERR_PARAM;
    m.stamp = SR_MODEL_STAMP;
    for (i = 0; i < SR_READS_COUNT; ++i) m.sums[i] = model_reads_sum(&m, i);
    *model = m;
    return SR_OK;
}

/* Whether a[0..n) and b[0..n) hold the same bit patterns (a NaN equals itself, -0 differs from +0,
 * as in the checksums); word by word: the library links no more than libm and the mem* it copies with. */
static int same_bits(const sr_real *a, const sr_real *b, int n)
{
    int i;
    for (i = 0; i < n; ++i) {
        sr_model_word wa, wb;
        memcpy(&wa, a + i, sizeof wa);
        memcpy(&wb, b + i, sizeof wb);
        if (wa != wb) return 0;
    }
    return 1;
}

int sr_check_model(const sr_model *model)
{
    sr_model fresh;
    int status = arg_model(model, READS_ALL), i;
    if (status != SR_OK) return status;
    if (sr_model_init(&fresh, model->p) != SR_OK || fresh.general != model->general) return SR_ERR_MODEL;
    for (i = 0; i < SR_READS_COUNT; ++i)
        if (fresh.sums[i] != model->sums[i]) return SR_ERR_MODEL;
    if (!(model->general ? same_bits(fresh.cg, model->cg, SR_GEN_GENERAL_NCONST) : same_bits(fresh.c, model->c, SR_GEN_NCONST)))
        return SR_ERR_MODEL;
    return SR_OK;
}
