/* sr_kernels.c -- the checked wrappers of the generated kernels, and the SO(3) exponential.
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_internal.h" /* spherical_robot.h, math macros, shared helpers */

#include <stddef.h>

int sr_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV])
{
    int status;
    if (!a) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    return sr_gen_accel(model->c, x, u ? u : sr_zero_u, a);
}

int sr_accel_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                   sr_real *a, long *failed_row)
{
    long i;
    if (failed_row) *failed_row = -1;
    if (!model || !x || !a) return SR_ERR_NULL;
    if (n < 0) return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        int status = sr_accel(model, x + i * SR_NX, u ? u + i * SR_NU : NULL, a + i * SR_NV);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}

int sr_inertia(const sr_model *model, const sr_real x[SR_NX], sr_real M[SR_NV * SR_NV])
{
    int status;
    if (!M) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_gen_inertia(model->c, x, M);
}

int sr_rhs(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real f[SR_NV])
{
    int status;
    if (!f) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    return sr_gen_rhs(model->c, x, u ? u : sr_zero_u, f);
}

int sr_energy(const sr_model *model, const sr_real x[SR_NX], sr_real *energy)
{
    int status;
    if (!energy) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_gen_energy(model->c, x, energy);
}

int sr_equilibrium_residual(const sr_model *model, const sr_real x[SR_NX], sr_real res[SR_NV])
{
    int status;
    if (!res) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_gen_equilibrium_residual(model->c, x, res);
}

int sr_so3_exp(const sr_real w[3], sr_real R[9])
{
    sr_real tmp[9];
    int i;
    if (!w || !R) return SR_ERR_NULL;
    if (!all_finite(w, 3)) return SR_ERR_NONFINITE;
    /* R = I + (Exp([[w]]) - I) */
    so3_exp_minus_identity(w, tmp);
    for (i = 0; i < 9; i += 4) tmp[i] += 1;
    return deliver(SR_OK, tmp, 9, R); /* |w|^2 may overflow */
}
