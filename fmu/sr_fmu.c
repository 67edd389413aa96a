/*
 * sr_fmu.c -- one robot instance behind the FMI wrappers (sr_fmu.h).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sr_fmu.h"

static const sr_fmu_variable VARIABLES[SR_FMU_NVARS] = SR_FMU_VARIABLES;
static const char *const NAMES[SR_FMU_NVARS] = SR_FMU_NAMES;
static const sr_real PARAM_START[SR_NPARAM] = SR_FMU_PARAM_START;
static const sr_real INIT_START[SR_FMU_NINIT] = SR_FMU_INIT_START;

/* The name of the variable of a kind and index, for messages. */
static const char *name_of(int kind, int index)
{
    size_t vr;
    for (vr = 0; vr < SR_FMU_NVARS; ++vr)
        if (VARIABLES[vr].kind == kind && VARIABLES[vr].index == index)
            return NAMES[vr];
    return "?";
}

static int fail(sr_fmu *fmu, const char *format, const char *name, const char *what, double value)
{
    snprintf(fmu->message, sizeof fmu->message, format, name, what, value);
    return SR_FMU_ERROR;
}

void sr_fmu_reset(sr_fmu *fmu)
{
    memset(fmu, 0, sizeof *fmu);
    memcpy(fmu->params, PARAM_START, sizeof fmu->params);
    memcpy(fmu->init, INIT_START, sizeof fmu->init);
    fmu->method = SR_FMU_METHOD_START;
    fmu->step = SR_FMU_STEP_START;
}

const sr_fmu_variable *sr_fmu_variable_of(sr_fmu *fmu, unsigned int vr)
{
    if (vr >= SR_FMU_NVARS) {
        snprintf(fmu->message, sizeof fmu->message, "unknown value reference %u", vr);
        return NULL;
    }
    return &VARIABLES[vr];
}

static int known_method(long method)
{
    static const long methods[] = SR_FMU_METHODS;
    size_t i;
    for (i = 0; i < sizeof methods / sizeof methods[0]; ++i)
        if (method == methods[i])
            return 1;
    return 0;
}

int sr_fmu_prepare(sr_fmu *fmu, double start_time)
{
    sr_real c, s;
    sr_real *x = fmu->x;
    const sr_real *init = fmu->init;
    int i, status, bad = -1, rule = SR_PARAM_RULE_NONE;

    fmu->ready = 0;
    if (!known_method(fmu->method))
        return fail(fmu, "%s: %s, got %g", name_of(SR_FMU_METHOD, 0),
                    "not a stepper of this FMU (" SR_FMU_METHOD_NAMES ")", (double)fmu->method);
    if (!(fmu->step > 0) || !isfinite(fmu->step))
        return fail(fmu, "%s: %s, got %g", name_of(SR_FMU_STEP, 0), "must be > 0 and finite", fmu->step);
    if (!isfinite(start_time))
        return fail(fmu, "%s: %s, got %g", "start time", "must be finite", start_time);
    status = sr_check_params(fmu->params, &bad, &rule);
    if (status != SR_OK && bad >= 0) {
        /* A tensor or centre breaks its rule as a whole: C reports its first entry. */
        int last = rule == SR_PARAM_RULE_INERTIA ? bad + 5 : rule == SR_PARAM_RULE_INSIDE ? bad + 2 : bad;
        if (last != bad) {
            const char *name = name_of(SR_FMU_PARAM, bad);
            size_t suffix = rule == SR_PARAM_RULE_INERTIA ? 3 : 2;  /* _xx of a tensor, _x of a centre */
            snprintf(fmu->message, sizeof fmu->message, "%.*s (%s .. %s): %s", (int)(strlen(name) - suffix), name,
                     name, name_of(SR_FMU_PARAM, last), sr_param_rule_string(rule));
            return SR_FMU_ERROR;
        }
        return fail(fmu, "%s: %s, got %g", name_of(SR_FMU_PARAM, bad), sr_param_rule_string(rule),
                    fmu->params[bad]);
    }
    status = sr_model_init(&fmu->model, fmu->params);
    if (status != SR_OK) {
        snprintf(fmu->message, sizeof fmu->message, "the parameters give no model: %s",
                 sr_status_string(status));
        return SR_FMU_ERROR;
    }
    for (i = 0; i < SR_FMU_NINIT; ++i)
        if (!isfinite(init[i]))
            return fail(fmu, "%s: %s, got %g", name_of(SR_FMU_INIT, i), "must be finite", init[i]);

    memset(x, 0, sizeof fmu->x);
    c = cos(init[SR_FMU_INIT_yaw_S_0]);
    s = sin(init[SR_FMU_INIT_yaw_S_0]);
    x[SR_X_R_S + 0] = c;  x[SR_X_R_S + 1] = -s;
    x[SR_X_R_S + 3] = s;  x[SR_X_R_S + 4] = c;
    x[SR_X_R_S + 8] = 1;
    c = cos(init[SR_FMU_INIT_theta_Y_0]);
    s = sin(init[SR_FMU_INIT_theta_Y_0]);
    x[SR_X_R_Y + 0] = 1;
    x[SR_X_R_Y + 4] = c;  x[SR_X_R_Y + 5] = -s;
    x[SR_X_R_Y + 7] = s;  x[SR_X_R_Y + 8] = c;
    c = cos(init[SR_FMU_INIT_theta_P_0]);
    s = sin(init[SR_FMU_INIT_theta_P_0]);
    x[SR_X_R_P + 0] = c;  x[SR_X_R_P + 2] = s;
    x[SR_X_R_P + 4] = 1;
    x[SR_X_R_P + 6] = -s; x[SR_X_R_P + 8] = c;
    x[SR_X_q + 0] = init[SR_FMU_INIT_q_x_0];
    x[SR_X_q + 1] = init[SR_FMU_INIT_q_y_0];
    x[SR_X_q + 2] = fmu->params[SR_P_r];
    x[SR_X_w_S + 0] = init[SR_FMU_INIT_w_S_x_0];
    x[SR_X_w_S + 1] = init[SR_FMU_INIT_w_S_y_0];
    x[SR_X_w_S + 2] = init[SR_FMU_INIT_w_S_z_0];
    x[SR_X_w_Y] = init[SR_FMU_INIT_w_Y_0];
    x[SR_X_w_P] = init[SR_FMU_INIT_w_P_0];
    status = sr_check_state(&fmu->model, x);
    if (status != SR_OK) {
        snprintf(fmu->message, sizeof fmu->message, "the initial conditions give no valid state: %s",
                 sr_status_string(status));
        return SR_FMU_ERROR;
    }
    fmu->time = start_time;
    fmu->ready = 1;
    return SR_FMU_OK;
}

/* The force of the floor on the shell at the contact point (plane frame): the library's
 * sr_contact_force, the balance of the total momentum (derive/contact.py). */
static int contact_force(sr_fmu *fmu, sr_real F[3])
{
    int status = sr_contact_force(&fmu->model, fmu->x, fmu->u, F);

    if (status != SR_OK) {
        snprintf(fmu->message, sizeof fmu->message, "contact force at t = %g: %s", fmu->time,
                 sr_status_string(status));
        return SR_FMU_ERROR;
    }
    return SR_FMU_OK;
}

static int need_ready(sr_fmu *fmu, unsigned int vr)
{
    if (!fmu->ready && sr_fmu_prepare(fmu, fmu->time) != SR_FMU_OK) {
        char why[SR_FMU_MESSAGE];
        memcpy(why, fmu->message, sizeof why);
        snprintf(fmu->message, sizeof fmu->message, "%.40s: cannot be computed: %.180s", NAMES[vr], why);
        return SR_FMU_ERROR;
    }
    return SR_FMU_OK;
}

int sr_fmu_get_real(sr_fmu *fmu, unsigned int vr, double *value)
{
    const sr_fmu_variable *v = sr_fmu_variable_of(fmu, vr);
    sr_real F[3], energy;
    int status;

    if (v == NULL)
        return SR_FMU_ERROR;
    switch (v->kind) {
    case SR_FMU_TIME: *value = fmu->time; return SR_FMU_OK;
    case SR_FMU_INPUT: *value = fmu->u[v->index]; return SR_FMU_OK;
    case SR_FMU_PARAM: *value = fmu->params[v->index]; return SR_FMU_OK;
    case SR_FMU_INIT: *value = fmu->init[v->index]; return SR_FMU_OK;
    case SR_FMU_STEP: *value = fmu->step; return SR_FMU_OK;
    case SR_FMU_METHOD: break;
    default:
        if (need_ready(fmu, vr) != SR_FMU_OK)
            return SR_FMU_ERROR;
        switch (v->kind) {
        case SR_FMU_STATE: *value = fmu->x[v->index]; return SR_FMU_OK;
        case SR_FMU_HEADING:
            /* The direction of forward rolling, from the plane's x axis: the rolling axis is
             * a = R_S e_x, forward is e_z x a (runtime.control.geometry.heading). */
            *value = atan2(fmu->x[SR_X_R_S + 0], -fmu->x[SR_X_R_S + 3]);
            return SR_FMU_OK;
        case SR_FMU_ENERGY:
            status = sr_energy(&fmu->model, fmu->x, &energy);
            if (status != SR_OK) {
                snprintf(fmu->message, sizeof fmu->message, "%s at t = %.17g: %s", NAMES[vr], fmu->time,
                         sr_status_string(status));
                return SR_FMU_ERROR;
            }
            *value = energy;
            return SR_FMU_OK;
        case SR_FMU_CONTACT:
            if (contact_force(fmu, F) != SR_FMU_OK)
                return SR_FMU_ERROR;
            *value = F[v->index];
            return SR_FMU_OK;
        default: break;
        }
    }
    snprintf(fmu->message, sizeof fmu->message, "%s (value reference %u) is not a real variable", NAMES[vr], vr);
    return SR_FMU_ERROR;
}

int sr_fmu_set_real(sr_fmu *fmu, unsigned int vr, double value, int initialising)
{
    const sr_fmu_variable *v = sr_fmu_variable_of(fmu, vr);

    if (v == NULL)
        return SR_FMU_ERROR;
    if (v->kind == SR_FMU_INPUT) {
        fmu->u[v->index] = value;
        return SR_FMU_OK;
    }
    if (v->kind != SR_FMU_PARAM && v->kind != SR_FMU_INIT && v->kind != SR_FMU_STEP) {
        snprintf(fmu->message, sizeof fmu->message, "%s (value reference %u) cannot be set as a real",
                 NAMES[vr], vr);
        return SR_FMU_ERROR;
    }
    if (!initialising) {
        snprintf(fmu->message, sizeof fmu->message,
                 "%s: a parameter is set only before the end of initialisation", NAMES[vr]);
        return SR_FMU_ERROR;
    }
    if (v->kind == SR_FMU_PARAM)
        fmu->params[v->index] = value;
    else if (v->kind == SR_FMU_INIT)
        fmu->init[v->index] = value;
    else
        fmu->step = value;
    fmu->ready = 0;
    return SR_FMU_OK;
}

int sr_fmu_get_integer(sr_fmu *fmu, unsigned int vr, long *value)
{
    const sr_fmu_variable *v = sr_fmu_variable_of(fmu, vr);

    if (v == NULL)
        return SR_FMU_ERROR;
    if (v->kind != SR_FMU_METHOD) {
        snprintf(fmu->message, sizeof fmu->message, "%s (value reference %u) is not an integer variable",
                 NAMES[vr], vr);
        return SR_FMU_ERROR;
    }
    *value = fmu->method;
    return SR_FMU_OK;
}

int sr_fmu_set_integer(sr_fmu *fmu, unsigned int vr, long value, int initialising)
{
    const sr_fmu_variable *v = sr_fmu_variable_of(fmu, vr);

    if (v == NULL)
        return SR_FMU_ERROR;
    if (v->kind != SR_FMU_METHOD) {
        snprintf(fmu->message, sizeof fmu->message, "%s (value reference %u) is not an integer variable",
                 NAMES[vr], vr);
        return SR_FMU_ERROR;
    }
    if (!initialising) {
        snprintf(fmu->message, sizeof fmu->message,
                 "%s: a parameter is set only before the end of initialisation", NAMES[vr]);
        return SR_FMU_ERROR;
    }
    if (!known_method(value))
        return fail(fmu, "%s: %s, got %g", NAMES[vr], "not a stepper of this FMU (" SR_FMU_METHOD_NAMES ")",
                    (double)value);
    fmu->method = (int)value;
    fmu->ready = 0;
    return SR_FMU_OK;
}

int sr_fmu_do_step(sr_fmu *fmu, double t, double h)
{
    sr_real x[SR_NX];
    double n_real, sub;
    long n, k;
    int i, status;

    if (!fmu->ready) {
        snprintf(fmu->message, sizeof fmu->message, "doStep before a successful initialisation");
        return SR_FMU_ERROR;
    }
    if (!(h > 0) || !isfinite(h))
        return fail(fmu, "%s: %s, got %g", "communication step size", "must be > 0 and finite", h);
    if (!(fabs(t - fmu->time) <= 1e-9 * (1 + fabs(fmu->time))))
        return fail(fmu, "%s: %s, got %.17g", "current communication point", "must be the FMU's time", t);
    for (i = 0; i < SR_NU; ++i)
        if (!isfinite(fmu->u[i]))
            return fail(fmu, "%s: %s, got %g", name_of(SR_FMU_INPUT, i), "must be finite", fmu->u[i]);
    /* Equal substeps no longer than step; a communication step that is a whole number of
     * internal steps (to rounding) takes exactly those steps. */
    n_real = ceil(h / fmu->step * (1 - 1e-12));
    if (!(n_real <= 1e9))
        return fail(fmu, "%s: %s, got %g", "communication step size", "needs more than 1e9 internal steps", h);
    n = n_real < 1 ? 1 : (long)n_real;
    sub = h / (double)n;
    memcpy(x, fmu->x, sizeof x);
    for (k = 0; k < n; ++k) {
        status = sr_step(&fmu->model, fmu->method, x, fmu->u, sub, x);
        if (status != SR_OK) {
            snprintf(fmu->message, sizeof fmu->message, "the step from t = %.17g failed at t = %.17g: %s",
                     t, t + (double)k * sub, sr_status_string(status));
            return SR_FMU_ERROR;
        }
    }
    memcpy(fmu->x, x, sizeof x);
    fmu->time = t + h;
    return SR_FMU_OK;
}
