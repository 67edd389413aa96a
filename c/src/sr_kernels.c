/* sr_kernels.c -- the checked wrappers of the generated kernels, and the SO(3) exponential.
 * Hand-written; see spherical_robot.h for the contract of every function. */
#include "sr_checks.h"
#include "sr_kernels.h"
#include "sr_so3.h"
#include "sr_argcheck.h"

#include <stddef.h>
#include <string.h>

/* ---- the kernels of the model's kind (sr_model: paper geometry or general) ----------------
 * Compiled with -DSR_PAPER_ONLY, the library leaves the general robot's kernels out (a firmware
 * for a robot of the paper's geometry links about 6 KB less on a Cortex-M4): sr_model_init then
 * refuses any other robot with SR_ERR_PARAM, and model->general is never set. */
#ifdef SR_PAPER_ONLY
#define GENERAL(call) SR_ERR_PARAM
#else
#define GENERAL(call) (call)
#endif

int sr_internal_cholesky(const sr_real Mu[15], sr_real L[SR_NV * SR_NV], sr_real inv[SR_NV])
{
    /* Column by column (j), as the loops L_jj = sqrt(M_jj - sum_(k<j) L_jk^2) and
     * L_ij = (M_ij - sum_(k<j) L_ik L_jk) / L_jj, k ascending, written out for the five rows: the
     * entries stay in locals (Mu's index of M_ij is SR_UPPER[i][j]). */
    typedef char five_rows[SR_NV == 5 ? 1 : -1];
    sr_real d, l00, l10, l20, l30, l40, l11, l21, l31, l41, l22, l32, l42, l33, l43, l44, i0, i1, i2, i3, i4;
    (void)sizeof(five_rows);
    d = Mu[0];
    if (!(d > SR_GEN_PIVOT_TOL * Mu[0])) return SR_ERR_SINGULAR;
    l00 = SR_SQRT(d);
    i0 = 1 / l00;
    l10 = Mu[1] * i0;
    l20 = Mu[2] * i0;
    l30 = Mu[3] * i0;
    l40 = Mu[4] * i0;
    d = Mu[5] - l10 * l10;
    if (!(d > SR_GEN_PIVOT_TOL * Mu[5])) return SR_ERR_SINGULAR;
    l11 = SR_SQRT(d);
    i1 = 1 / l11;
    l21 = (Mu[6] - l20 * l10) * i1;
    l31 = (Mu[7] - l30 * l10) * i1;
    l41 = (Mu[8] - l40 * l10) * i1;
    d = Mu[9] - l20 * l20 - l21 * l21;
    if (!(d > SR_GEN_PIVOT_TOL * Mu[9])) return SR_ERR_SINGULAR;
    l22 = SR_SQRT(d);
    i2 = 1 / l22;
    l32 = (Mu[10] - l30 * l20 - l31 * l21) * i2;
    l42 = (Mu[11] - l40 * l20 - l41 * l21) * i2;
    d = Mu[12] - l30 * l30 - l31 * l31 - l32 * l32;
    if (!(d > SR_GEN_PIVOT_TOL * Mu[12])) return SR_ERR_SINGULAR;
    l33 = SR_SQRT(d);
    i3 = 1 / l33;
    l43 = (Mu[13] - l40 * l30 - l41 * l31 - l42 * l32) * i3;
    d = Mu[14] - l40 * l40 - l41 * l41 - l42 * l42 - l43 * l43;
    if (!(d > SR_GEN_PIVOT_TOL * Mu[14])) return SR_ERR_SINGULAR;
    l44 = SR_SQRT(d);
    i4 = 1 / l44;
    {
        const sr_real lower[SR_NV * SR_NV] = {l00, 0, 0, 0, 0, l10, l11, 0, 0, 0, l20, l21, l22, 0, 0,
                                              l30, l31, l32, l33, 0, l40, l41, l42, l43, l44};
        const sr_real r[SR_NV] = {i0, i1, i2, i3, i4};
        memcpy(L, lower, sizeof lower);
        memcpy(inv, r, sizeof r);
    }
    return SR_OK;
}

/* The general robot: M and f from the generated kernel, M a = f by Cholesky (with rotors and
 * general tensors every entry of M may be nonzero, so the paper's joint-first solve does not apply). */
#ifndef SR_PAPER_ONLY
static int general_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV])
{
    sr_real Mu[15], L[SR_NV * SR_NV], inv[SR_NV], y[SR_NV];
    int i, status = sr_gen_general_system(model->cg, x, u, Mu, y);
    if (status != SR_OK) return status;
    status = sr_internal_cholesky(Mu, L, inv);
    if (status != SR_OK) return status;
    sr_internal_cholesky_solve(L, inv, 1, 1, y);
    if (!all_finite(y, SR_NV)) return SR_ERR_NONFINITE;
    for (i = 0; i < SR_NV; ++i) a[i] = y[i];
    return SR_OK;
}
#endif

int sr_internal_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV])
{
    return model->general ? GENERAL(general_accel(model, x, u, a)) : sr_gen_accel(model->c, x, u, a);
}

int sr_internal_inertia(const sr_model *model, const sr_real x[SR_NX], sr_real M[SR_NV * SR_NV])
{
    return model->general ? GENERAL(sr_gen_general_inertia(model->cg, x, M)) : sr_gen_inertia(model->c, x, M);
}

int sr_internal_rhs(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real f[SR_NV])
{
    return model->general ? GENERAL(sr_gen_general_rhs(model->cg, x, u, f)) : sr_gen_rhs(model->c, x, u, f);
}

int sr_internal_energy(const sr_model *model, const sr_real x[SR_NX], sr_real *energy)
{
    return model->general ? GENERAL(sr_gen_general_energy(model->cg, x, energy)) : sr_gen_energy(model->c, x, energy);
}

int sr_internal_equilibrium_residual(const sr_model *model, const sr_real x[SR_NX], sr_real res[SR_NV])
{
    return model->general ? GENERAL(sr_gen_general_equilibrium_residual(model->cg, x, res))
                          : sr_gen_equilibrium_residual(model->c, x, res);
}

int sr_internal_general_accel_jacobian_terms(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU],
                                             sr_real Mu[15], sr_real f[SR_NV], sr_real df[SR_NV * SR_NE],
                                             sr_real dfdu[SR_NV * SR_NU], sr_real dM[5 * 15])
{
#ifdef SR_PAPER_ONLY
    (void)model; (void)x; (void)u; (void)Mu; (void)f; (void)df; (void)dfdu; (void)dM;
    return SR_ERR_PARAM;
#else
    return sr_gen_general_accel_jacobian_terms(model->cg, x, u, Mu, f, df, dfdu, dM);
#endif
}

/* ---- the checked API ------------------------------------------------------------------------ */

int sr_accel(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real a[SR_NV])
{
    int status = arg_model(model, READS(ACCEL));
    if (status != SR_OK) return status;
    if (!a) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    return sr_internal_accel(model, x, u ? u : sr_zero_u, a);
}

/* sr_accel (and, if `full`, sr_check_state first) on n rows, a block at a time: the vectorised
 * lanes form of the checks and the kernel over the block, into a local block, then row by row:
 * a clean lane's result is copied out, any other row goes through the scalar functions (which
 * return the same status codes and write the same bits as they would alone).  So the rows after
 * a failing one are not written, as with a loop of sr_accel.  The general robot goes row by row. */
static int accel_rows(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real *a,
                      long *failed_row, int full)
{
    enum { BLOCK = 64 };
    sr_real ok_state[BLOCK], ok_accel[BLOCK], block[BLOCK * SR_NV];
    long start, i;
    /* the lanes' state check reads r, whether or not the full check decides */
    int k, status = arg_model(model, READS(ACCEL) | READS(STATE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && a);
    if (status != SR_OK) return status;
    for (start = 0; start < n; start += BLOCK) {
        const long m = n - start < BLOCK ? n - start : BLOCK;
        const sr_real *xb = x + start * SR_NX, *ub = u ? u + start * SR_NU : NULL;
        sr_real *ab = a + start * SR_NV;
        if (model->general) {
            for (i = 0; i < m; ++i) ok_state[i] = ok_accel[i] = 0;
        } else {
            sr_internal_check_lanes(model, m, xb, SR_NX, ok_state);
            sr_gen_accel_lanes(model->c, m, xb, SR_NX, ub ? ub : sr_zero_u, ub ? SR_NU : 0, block, SR_NV, ok_accel);
        }
        for (i = 0; i < m; ++i) {
            const sr_real *xi = xb + i * SR_NX, *ui = ub ? ub + i * SR_NU : NULL;
            if (ok_state[i] != 0 && ok_accel[i] != 0) {
                for (k = 0; k < SR_NV; ++k) ab[i * SR_NV + k] = block[i * SR_NV + k];
                continue;
            }
            /* sr_check_state and sr_accel on the row, the model checked above */
            status = full ? sr_internal_check_state(model, xi) : SR_OK;
            if (status == SR_OK) status = checks(model, xi, ui);
            if (status == SR_OK) status = sr_internal_accel(model, xi, ui ? ui : sr_zero_u, ab + i * SR_NV);
            if (status != SR_OK) {
                if (failed_row) *failed_row = start + i;
                return status;
            }
        }
    }
    return SR_OK;
}

int sr_accel_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                   sr_real *a, long *failed_row)
{
    return accel_rows(model, n, x, u, a, failed_row, 0);
}

int sr_checked_accel_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u,
                           sr_real *a, long *failed_row)
{
    return accel_rows(model, n, x, u, a, failed_row, 1);
}

int sr_inertia(const sr_model *model, const sr_real x[SR_NX], sr_real M[SR_NV * SR_NV])
{
    int status = arg_model(model, READS(INERTIA));
    if (status != SR_OK) return status;
    if (!M) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_internal_inertia(model, x, M);
}

int sr_rhs(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real f[SR_NV])
{
    int status = arg_model(model, READS(RHS));
    if (status != SR_OK) return status;
    if (!f) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    return sr_internal_rhs(model, x, u ? u : sr_zero_u, f);
}

int sr_energy(const sr_model *model, const sr_real x[SR_NX], sr_real *energy)
{
    int status = arg_model(model, READS(ENERGY));
    if (status != SR_OK) return status;
    if (!energy) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_internal_energy(model, x, energy);
}

int sr_equilibrium_residual(const sr_model *model, const sr_real x[SR_NX], sr_real res[SR_NV])
{
    int status = arg_model(model, READS(EQUILIBRIUM));
    if (status != SR_OK) return status;
    if (!res) return SR_ERR_NULL;
    status = checks(model, x, NULL);
    if (status != SR_OK) return status;
    return sr_internal_equilibrium_residual(model, x, res);
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
