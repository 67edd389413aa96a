/*
 * sr_argcheck.h -- the argument checks that every public entry point shares, one per kind of
 * argument: the model, the method, the time step, the row count with its buffers.  Internal to
 * the library (not part of spherical_robot.h, not seen by the cffi bindings).
 *
 * Every entry point runs the checks of its arguments in one order, all of them before it looks
 * at any state or returns early (n = 0, steps = 0):
 *     the model (SR_ERR_NULL, SR_ERR_MODEL), the other pointers (SR_ERR_NULL), the method, dt and
 *     the counts (SR_ERR_ARG), then the data (states, torques: SR_ERR_NONFINITE, ...).
 * So a call that is wrong in its arguments is refused the same way whatever else it is given,
 * and a batch refuses it before any row (failed_row -1).
 *
 * Everything here is static inline; no globals.
 */
#ifndef SR_ARGCHECK_H
#define SR_ARGCHECK_H

#include "spherical_robot.h"

#include <math.h>
#include <stdint.h>
#include <string.h>

/* The stamp of a model that sr_model_init filled: a constant that zeroed or uninitialised memory
 * is unlikely to hold, different in the float and the double build (a model of one build handed
 * to the other, by a cast, is refused). */
#ifdef SR_USE_FLOAT
#define SR_MODEL_STAMP UINT64_C(0x5352F10A7D0DE15F)
typedef uint32_t sr_model_word;
#else
#define SR_MODEL_STAMP UINT64_C(0x5352D0B1E0DE1564)
typedef uint64_t sr_model_word;
#endif

/* The wrapping sum of the bit patterns of v[0..n), in 8 lanes (short chains of integer
 * additions that vectorise).  Bit patterns, not values: exact, the same in every build and order
 * of summation, and any one changed entry changes the sum (a NaN, a -0 for a +0 included). */
static inline uint64_t model_words_sum(const sr_real *v, int n)
{
    uint64_t s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    int i, k;
    for (i = 0; i + 8 <= n; i += 8)
        for (k = 0; k < 8; ++k) {
            sr_model_word w;
            memcpy(&w, v + i + k, sizeof w);
            s[k] += w;
        }
    for (k = 0; k < n - i; ++k) {
        sr_model_word w;
        memcpy(&w, v + i + k, sizeof w);
        s[k] += w;
    }
    return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

/* The checksum of what the kernels and checks read from a model: the parameters, the kind
 * (general) and the constants of that kind.  The constants of the other kind are never read. */
static inline uint64_t model_checksum(const sr_model *model)
{
    const uint64_t constants = model->general ? model_words_sum(model->cg, SR_GEN_GENERAL_NCONST)
                                              : model_words_sum(model->c, SR_GEN_NCONST);
    return model_words_sum(model->p, SR_NPARAM) + constants + (uint64_t)(unsigned)model->general;
}

/* The model argument: not NULL (SR_ERR_NULL), and as sr_model_init left it (SR_ERR_MODEL): its
 * stamp, and the checksum of what the kernels read (a parameter or constant overwritten since,
 * with NaN or any other value, is caught). */
static inline int arg_model(const sr_model *model)
{
    if (!model) return SR_ERR_NULL;
    if (model->stamp != SR_MODEL_STAMP || model->checksum != model_checksum(model)) return SR_ERR_MODEL;
    return SR_OK;
}

/* A stepping method: SR_LIE_EULER, SR_RKMK4 or SR_CF4, optionally | SR_PROJECT. */
static inline int arg_method(int method)
{
    const int base = method & ~SR_PROJECT;
    return base == SR_LIE_EULER || base == SR_RKMK4 || base == SR_CF4 ? SR_OK : SR_ERR_ARG;
}

/* A method of the step Jacobians: SR_LIE_EULER, SR_RKMK4 or SR_CF4, no projection. */
static inline int arg_jacobian_method(int method)
{
    return method == SR_LIE_EULER || method == SR_RKMK4 || method == SR_CF4 ? SR_OK : SR_ERR_ARG;
}

/* A time step: positive and finite. */
static inline int arg_dt(sr_real dt)
{
    return dt > 0 && isfinite(dt) ? SR_OK : SR_ERR_ARG;
}

/* A row count n and its buffers (buffers: nonzero when every required buffer is given): n < 0 is
 * SR_ERR_ARG; the buffers may be NULL only when there are no rows. */
static inline int arg_rows(long n, int buffers)
{
    if (n < 0) return SR_ERR_ARG;
    return n > 0 && !buffers ? SR_ERR_NULL : SR_OK;
}

#ifdef SR_USE_FLOAT
#define sr_internal_check_state sr_internal_check_state_f
#endif

/* The rules of sr_check_state on a state x (not NULL) of a model that arg_model accepted: for the
 * entry points that have checked their model already (c/sr_checks.c). */
int sr_internal_check_state(const sr_model *model, const sr_real x[SR_NX]);

#endif /* SR_ARGCHECK_H */
