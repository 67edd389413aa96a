/* sr_model.c -- status strings, the parameter rules and the model's initialisation.
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_internal.h" /* spherical_robot.h, math macros, shared helpers */

#include <stddef.h>

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
    default: return "unknown rule";
    }
}

/* The one statement of the parameter rules (the Python Params calls this function too). */
int sr_check_params(const sr_real params[SR_NPARAM], int *bad_index, int *rule)
{
    static const int positive[] = {SR_P_r, SR_P_m_S, SR_P_b, SR_P_h, SR_P_m_b, SR_P_m_h, SR_P_l, SR_P_m_P};
    static const int nonnegative[] = {SR_P_k_S, SR_P_k_Y, SR_P_k_P, SR_P_g};
    const sr_real *p = params;
    int i, bad = -1, broken = SR_PARAM_RULE_NONE;
    if (bad_index) *bad_index = -1;
    if (rule) *rule = SR_PARAM_RULE_NONE;
    if (!params) return SR_ERR_NULL;
    for (i = 0; i < SR_NPARAM && bad < 0; ++i)
        if (!isfinite(p[i])) bad = i, broken = SR_PARAM_RULE_FINITE;
    for (i = 0; i < (int)(sizeof positive / sizeof positive[0]) && bad < 0; ++i)
        if (!(p[positive[i]] > 0)) bad = positive[i], broken = SR_PARAM_RULE_POSITIVE;
    for (i = 0; i < (int)(sizeof nonnegative / sizeof nonnegative[0]) && bad < 0; ++i)
        if (!(p[nonnegative[i]] >= 0)) bad = nonnegative[i], broken = SR_PARAM_RULE_NONNEGATIVE;
    /* The yoke's corners and the pendulum's tip must fit inside the shell. */
    if (bad < 0 && p[SR_P_b] * p[SR_P_b] + p[SR_P_h] * p[SR_P_h] > SR_C(4.0) * p[SR_P_r] * p[SR_P_r])
        bad = SR_P_b, broken = SR_PARAM_RULE_YOKE_FITS;
    if (bad < 0 && p[SR_P_l] > p[SR_P_r]) bad = SR_P_l, broken = SR_PARAM_RULE_PENDULUM_FITS;
    if (bad < 0) return SR_OK;
    if (bad_index) *bad_index = bad;
    if (rule) *rule = broken;
    return broken == SR_PARAM_RULE_FINITE ? SR_ERR_NONFINITE : SR_ERR_PARAM;
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
    status = sr_gen_constants(m.p, m.c);
    if (status != SR_OK) return status;
    /* Values in range one by one can still overflow or underflow together (r = 1e200, or every
     * length 1e-200): evaluate the model once at the reference state.  M is positive definite
     * for any positive masses and lengths in exact arithmetic, so a failing pivot means that
     * the inertias underflowed. */
    if (!all_finite(m.c, SR_GEN_NCONST_NAMED)) return SR_ERR_PARAM;
    reference_state(params[SR_P_r], x);
    if (sr_gen_inertia(m.c, x, M) != SR_OK) return SR_ERR_PARAM;
    status = sr_gen_accel(m.c, x, sr_zero_u, a);
    if (status == SR_GEN_SINGULAR) return SR_ERR_SINGULAR;
    /* After the pivots, so that inertias that underflow to zero (and whose reciprocals among the
     * pooled constants are infinite) are reported as singular. */
    if (status != SR_OK || !all_finite(m.c, SR_GEN_NCONST)) return SR_ERR_PARAM;
    if (sr_gen_energy(m.c, x, &energy) != SR_OK) return SR_ERR_PARAM;
    *model = m;
    return SR_OK;
}
