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

/* ---- the read sets of a model: one checksum each (sr_model.sums) ---------------------------
 * A read set is what one kernel reads of the model: a generated kernel's entries of p, c or cg
 * (SR_GEN_READS_<kernel>, emitted by the generator from the code of that kernel; for the kinds that
 * have two kernels, the paper-geometry one's or the general one's, by the model's kind), or the
 * hand-written code's own reads of p, listed here.  Every checksum includes general.  An entry
 * point checks the read sets of the kernels it calls (arg_model's `reads`), and a kernel that
 * reads more of the model than its set says would be found by c/tests/test_model_validity.c (an
 * entry changed outside the set must leave the result unchanged). */
enum {
    SR_READS_STATE,       /* p[r]: the state check's contact q_z = r, the rolling kinematics, the LQR's rate */
    SR_READS_ACCEL,       /* sr_gen_accel and its lanes form / sr_gen_general_system */
    SR_READS_INERTIA,     /* sr_gen_inertia / sr_gen_general_inertia */
    SR_READS_RHS,         /* sr_gen_rhs / sr_gen_general_rhs */
    SR_READS_ENERGY,      /* sr_gen_energy / sr_gen_general_energy */
    SR_READS_EQUILIBRIUM, /* sr_gen_equilibrium_residual / sr_gen_general_equilibrium_residual */
    SR_READS_JACOBIAN,    /* sr_gen_accel_jacobian_yoke_terms / sr_gen_general_accel_jacobian_terms */
    SR_READS_SENSORS,     /* sr_gen_sensor_constants (p) */
    SR_READS_GUARD,       /* the energy guard's scale (c/src/sr_drivers.c): m_Y, c_Y, m_P, c_P, g */
    SR_READS_WHOLE,       /* all of p and the constants of the model's kind: the entry points off the
                           * hot path (contact force, parameter Jacobians, estimator, NMPC) */
    SR_READS_COUNT
};
typedef char sr_reads_count_matches[SR_READS_COUNT == SR_MODEL_NSUMS ? 1 : -1];

/* The bit of read set k in arg_model's `reads`. */
#define READS(k) (1u << SR_READS_##k)

/* The hand-written code's reads of p, as R(array, first, end) like the generated read sets. */
#define SR_READS_state(R) R(p, SR_P_r, SR_P_r + 1)
#define SR_READS_guard(R) R(p, SR_P_m_Y, SR_P_c_Y_z + 1) R(p, SR_P_m_P, SR_P_c_P_z + 1) R(p, SR_P_g, SR_P_g + 1)

/* One term of a read set's sum: the words of model->array[first..end). */
#define SR_READS_TERM(array, first, end) + model_words_sum(model->array + (first), (end) - (first))
/* The sum of a read set that is one kernel's of either kind (its paper-geometry and general kernels). */
#define SR_READS_OF_KIND(paper, general_kernel) \
    (model->general ? 0 SR_GEN_READS_##general_kernel(SR_READS_TERM) : 0 SR_GEN_READS_##paper(SR_READS_TERM))

/* The checksum of read set k of a model (k constant where it is inlined: the switch folds away). */
static inline uint64_t model_reads_sum(const sr_model *model, int k)
{
    uint64_t sum = 0;
    switch (k) {
    case SR_READS_STATE: sum = 0 SR_READS_state(SR_READS_TERM); break;
    case SR_READS_ACCEL: sum = SR_READS_OF_KIND(accel, general_system); break;
    case SR_READS_INERTIA: sum = SR_READS_OF_KIND(inertia, general_inertia); break;
    case SR_READS_RHS: sum = SR_READS_OF_KIND(rhs, general_rhs); break;
    case SR_READS_ENERGY: sum = SR_READS_OF_KIND(energy, general_energy); break;
    case SR_READS_EQUILIBRIUM: sum = SR_READS_OF_KIND(equilibrium_residual, general_equilibrium_residual); break;
    case SR_READS_JACOBIAN: sum = SR_READS_OF_KIND(accel_jacobian_yoke_terms, general_accel_jacobian_terms); break;
    case SR_READS_SENSORS: sum = 0 SR_GEN_READS_sensor_constants(SR_READS_TERM); break;
    case SR_READS_GUARD: sum = 0 SR_READS_guard(SR_READS_TERM); break;
    default:
        sum = model_words_sum(model->p, SR_NPARAM)
              + (model->general ? model_words_sum(model->cg, SR_GEN_GENERAL_NCONST) : model_words_sum(model->c, SR_GEN_NCONST));
        break;
    }
    return sum + (uint64_t)(unsigned)model->general;
}

/* Whether read set k (an enum name without SR_READS_: ACCEL) is in `reads` and its checksum differs from the stored one. */
#define READS_SUM_DIFFERS(k) \
    ((reads & READS(k)) && model->sums[SR_READS_##k] != model_reads_sum(model, SR_READS_##k))

/* The model argument: not NULL (SR_ERR_NULL), and as sr_model_init left it (SR_ERR_MODEL) in what
 * the caller reads: its stamp, and the checksums of the read sets in `reads` (READS(...) | ...; a
 * constant, so that only those sums are compiled in). */
static inline int arg_model(const sr_model *model, unsigned reads)
{
    if (!model) return SR_ERR_NULL;
    if (model->stamp != SR_MODEL_STAMP) return SR_ERR_MODEL;
    if (READS_SUM_DIFFERS(STATE) || READS_SUM_DIFFERS(ACCEL) || READS_SUM_DIFFERS(INERTIA) || READS_SUM_DIFFERS(RHS)
        || READS_SUM_DIFFERS(ENERGY) || READS_SUM_DIFFERS(EQUILIBRIUM) || READS_SUM_DIFFERS(JACOBIAN)
        || READS_SUM_DIFFERS(SENSORS) || READS_SUM_DIFFERS(GUARD) || READS_SUM_DIFFERS(WHOLE))
        return SR_ERR_MODEL;
    return SR_OK;
}

/* Every read set. */
#define READS_ALL ((1u << SR_READS_COUNT) - 1)

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
