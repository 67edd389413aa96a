/* sr_contact.c -- the checked contact force around the generated sr_gen_contact_force and
 * sr_gen_general_contact_force kernels (derive/contact.py).  Hand-written; see spherical_robot.h
 * for the contract of every function. */
#include "sr_argcheck.h"
#include "sr_checks.h"
#include "sr_kernels.h"

/* The accelerations, then the momentum balance of the model's kind, unchecked (u not NULL). */
static int contact_force(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real F[3])
{
    sr_real a[SR_NV];
    int status = sr_internal_accel(model, x, u, a);
    if (status != SR_OK) return status;
#ifdef SR_PAPER_ONLY
    return sr_gen_contact_force(model->c, x, a, F);   /* sr_model_init accepts only the paper's robot */
#else
    return model->general ? sr_gen_general_contact_force(model->cg, x, a, F) : sr_gen_contact_force(model->c, x, a, F);
#endif
}

int sr_contact_force(const sr_model *model, const sr_real x[SR_NX], const sr_real u[SR_NU], sr_real F[3])
{
    int status = arg_model(model, READS(WHOLE));
    if (status != SR_OK) return status;
    if (!F) return SR_ERR_NULL;
    status = checks(model, x, u);
    if (status != SR_OK) return status;
    return contact_force(model, x, u ? u : sr_zero_u, F);
}

int sr_contact_force_batch(const sr_model *model, long n, const sr_real *x, const sr_real *u, sr_real *F,
                           long *failed_row)
{
    long i;
    int status = arg_model(model, READS(WHOLE));
    if (failed_row) *failed_row = -1;
    if (status == SR_OK) status = arg_rows(n, x && F);
    if (status != SR_OK) return status;
    for (i = 0; i < n; ++i) {
        const sr_real *xi = x + i * SR_NX, *ui = u ? u + i * SR_NU : sr_zero_u;
        status = sr_internal_check_state(model, xi);
        if (status == SR_OK) status = checks(model, xi, ui);
        if (status == SR_OK) status = contact_force(model, xi, ui, F + i * 3);
        if (status != SR_OK) {
            if (failed_row) *failed_row = i;
            return status;
        }
    }
    return SR_OK;
}
