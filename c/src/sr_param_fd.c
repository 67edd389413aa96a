/*
 * sr_param_fd.c -- a step's sensitivity to chosen parameters by central differences, batched:
 * the reference that the analytic sensitivity (sr_param_jacobians.c) is timed against, and the
 * Jacobian of an identification that does without it.
 *
 * Per column: the robot at p + a e_j and at p + b e_j (sr_model_init), one sr_step_batch over all
 * the states each side, sr_local_batch against the model's own step, and the difference quotient
 * (wa D(a) + wb D(b)) / 2h.  Central (a = h, b = -h) where both sides are valid robots; a parameter
 * at a bound of its rule (a zero rotor inertia, a tensor entry on its triangle inequality) takes the
 * one-sided second-order difference from the valid side.  h = FD_REL |p_j| (FD_REL for a zero p_j),
 * about the cube root of the rounding unit.  A state's q_z is the radius r, so the column of r steps
 * copies of the states whose q_z moves with r (q_z is no error coordinate).
 */
#include "sr_argcheck.h"
#include "sr_math.h"

#ifdef SR_USE_FLOAT
#define FD_REL SR_C(5e-3)
#else
#define FD_REL SR_C(6e-6)
#endif

/* One batch step of the n states x by the robot q; for the column of r, of copies (in xr) with q_z = r. */
static int step_side(const sr_model *m, int method, long n, const sr_real *x, const sr_real *u, sr_real dt, int j,
                     const sr_real q[SR_NPARAM], sr_real *xr, sr_real *out, long *failed_row)
{
    long i;
    int k;
    if (j != SR_P_r) return sr_step_batch(m, method, n, x, u, dt, out, failed_row);
    for (i = 0; i < n; ++i) {
        for (k = 0; k < SR_NX; ++k) xr[i * SR_NX + k] = x[i * SR_NX + k];
        xr[i * SR_NX + SR_X_q + 2] = q[SR_P_r];
    }
    return sr_step_batch(m, method, n, xr, u, dt, out, failed_row);
}

int sr_step_param_jacobian_fd_batch(const sr_model *model, int method, long n, const sr_real *x, const sr_real *u,
                                    sr_real dt, int ncols, const int *cols, sr_real *Jp, sr_real *work,
                                    long *failed_row)
{
    sr_model m;
    sr_real q[SR_NPARAM];
    sr_real *nominal, *plus, *minus, *xr, *dplus, *dminus;
    long i;
    int c, k, status = arg_model(model, READS_ALL);
    if (failed_row) *failed_row = -1;
    if (status == SR_OK && !cols) status = SR_ERR_NULL;
    if (status == SR_OK) status = arg_rows(n, x && Jp && work);
    if (status == SR_OK && ((method != SR_LIE_EULER && method != SR_RKMK4) || arg_dt(dt) != SR_OK || ncols < 1))
        status = SR_ERR_ARG;
    for (c = 0; c < ncols && status == SR_OK; ++c)
        if (cols[c] < 0 || cols[c] >= SR_NPARAM) status = SR_ERR_ARG;
    if (status != SR_OK || n == 0) return status;
    nominal = work;
    plus = nominal + n * SR_NX;
    minus = plus + n * SR_NX;
    xr = minus + n * SR_NX;
    dplus = xr + n * SR_NX;
    dminus = dplus + n * SR_NE;
    status = sr_step_batch(model, method, n, x, u, dt, nominal, failed_row);
    for (c = 0; c < ncols && status == SR_OK; ++c) {
        const int j = cols[c];
        const sr_real p = model->p[j];
        const sr_real h = FD_REL * (p != 0 ? SR_FABS(p) : SR_C(1.0));
        sr_real a = h, b = -h, wa = 1, wb = -1;
        for (k = 0; k < SR_NPARAM; ++k) q[k] = model->p[k];
        q[j] = p + h;
        if (sr_model_init(&m, q) != SR_OK) {
            q[j] = p - h;
            if (sr_model_init(&m, q) != SR_OK) return SR_ERR_PARAM;   /* no valid robot on either side */
            a = -h, b = -2 * h, wa = -4, wb = 1;
        } else {
            q[j] = p - h;
            if (sr_model_init(&m, q) != SR_OK) b = 2 * h, wa = 4, wb = -1;
        }
        q[j] = p + a;
        status = sr_model_init(&m, q);
        if (status == SR_OK) status = step_side(&m, method, n, x, u, dt, j, q, xr, plus, failed_row);
        q[j] = p + b;
        if (status == SR_OK) status = sr_model_init(&m, q);
        if (status == SR_OK) status = step_side(&m, method, n, x, u, dt, j, q, xr, minus, failed_row);
        for (i = 0; i < n && j == SR_P_r; ++i) plus[i * SR_NX + SR_X_q + 2] = minus[i * SR_NX + SR_X_q + 2] = p;
        if (status == SR_OK) status = sr_local_batch(model, n, nominal, plus, dplus, failed_row);
        if (status == SR_OK) status = sr_local_batch(model, n, nominal, minus, dminus, failed_row);
        for (i = 0; i < n && status == SR_OK; ++i)
            for (k = 0; k < SR_NE; ++k)
                Jp[(i * SR_NE + k) * ncols + c] = (wa * dplus[i * SR_NE + k] + wb * dminus[i * SR_NE + k]) / (2 * h);
    }
    return status;
}
