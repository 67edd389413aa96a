/**
 * sr_ident.h -- the arithmetic of one evaluation of the sensor-log identification fit around the
 * kernels (runtime/identification/fit.py, docs/identification.md "Identifying a robot from a
 * log"): a multiple-shooting fit whose segments are simulated from their start states, whose IMU,
 * encoder and fix readings are compared with a log, and whose residuals are whitened by their
 * covariance.  The kernels (the steps' Jacobians F and parameter sensitivities, the sensors'
 * Jacobians, dnu/dtheta) are the library's; these three functions chain and combine their outputs:
 *
 *   sr_ident_chain   each segment's sensitivity chain G_k = [Phi_k | S_k] from its steps' F and Jp
 *   sr_ident_rows    each segment's rows [theta | b | x | next | r]: the readings' Jacobians
 *                    through the chain, and the end-state difference to the next segment
 *   sr_ident_whiten  each segment's rows whitened by the innovations form of their covariance
 *                    (a Kalman recursion over the segment's steps of rows)
 *
 * Sizes: NE = SR_NE (12) error coordinates, NV = SR_NV (5) accelerations, NB = SR_NBIAS (6) IMU
 * biases, nf the free parameters (>= 0).  Every matrix is row-major; the segments' arrays are
 * stacked one after the other in segment order.  No allocation: every buffer is the caller's.
 * Each function checks its arguments (SR_ERR_NULL for a required pointer that is NULL,
 * SR_ERR_ARG for a count or index out of its range) before it writes anything, then computes and
 * returns SR_ERR_NONFINITE if a result is not finite (its output buffer then holds partial
 * results); SR_OK otherwise.  Host-side helpers of the identification fit (the Python package
 * calls them once per evaluation); firmware does not need them.
 * @file
 */
#ifndef SR_IDENT_H
#define SR_IDENT_H

#include "spherical_robot.h"

#ifdef __cplusplus
extern "C" {
#endif

#ifdef SR_USE_FLOAT
#define sr_ident_chain sr_ident_chain_f
#define sr_ident_rows sr_ident_rows_f
#define sr_ident_whiten sr_ident_whiten_f
#endif

/**
 * The sensitivity chains of n_seg segments: for segment s of steps[s] steps, G_0 = [I | 0] and
 * G_{k+1} = F_k G_k + [0 | Jp_k], each G_k of NE x (NE + nf): the state transition Phi_k from the
 * segment's start and the sensitivity S_k of the state to the nf parameters.
 * F: sum(steps) x NE x NE, the steps' state Jacobians, segment after segment.
 * Jp: sum(steps) x NE x nf, the steps' parameter sensitivities, or NULL for zero (S_k = 0).
 * G: sum(steps + 1) x NE x (NE + nf), written.
 * Returns SR_OK, SR_ERR_NULL (steps, F or G; n_seg > 0), SR_ERR_ARG (n_seg, nf or a steps[s] < 0)
 * or SR_ERR_NONFINITE.
 */
int sr_ident_chain(long n_seg, const long *steps, long nf, const sr_real *F, const sr_real *Jp, sr_real *G);

/**
 * The unwhitened rows of n_seg segments, M_s = [theta | b | x | next | r] of width
 * nf + NB + NE + NE has_next[s] + 1 and n_read[s] + NE has_next[s] rows, stacked in M segment
 * after segment.  A reading row q (the segment's readings first, in the stacked order of the
 * per-row arrays) at node at[q] of its segment's chain G_k = [Phi_k | S_k] (sr_ident_chain's G,
 * the segment's blocks from sum over earlier segments of (steps + 1)) reads the state through
 * Hx[q] (NE) and the accelerations through Hn[q] (NV), the biases through Hb[q] (NB), with raw
 * residual r[q] and noise sigma sig[q] > 0:
 *
 *   theta = -(Hx S_k + Hn Jpa[node[q]]) / sig     (Jpa: NV x nf per node; NULL for zero)
 *   b     = -Hb / sig
 *   x     = (-Hx Phi_k / sig) D_s                 (D: NE x NE per segment, the start's offset map)
 *   next  = 0,   r = r / sig.
 *
 * With has_next[s] the NE end-state rows follow, with L = steps[s], A = A_s, B = B_s (NE x NE per
 * segment: the derivatives of the end-state difference local(end, next start) in the end and in
 * the next start) and Dn_s the next start's offset map:
 *
 *   theta = A S_L,   b = 0,   x = (A Phi_L) D_s,   next = B Dn_s,   r = defect_s (NE).
 *
 * at: per reading row, 0 <= at[q] <= steps[s]; node: per reading row, 0 <= node[q] < n_nodes
 * (read only with Jpa); nf <= SR_NPARAM.  A, B, Dn and defect may be NULL when no segment has a next.
 * Returns SR_OK, SR_ERR_NULL, SR_ERR_ARG (a count < 0, an index out of range, a has_next not 0
 * or 1, sig not > 0) or SR_ERR_NONFINITE.
 */
int sr_ident_rows(long n_seg, long nf, const long *steps, const long *n_read, const int *has_next,
                  const long *at, const long *node, long n_nodes, const sr_real *Hx, const sr_real *Hn,
                  const sr_real *Hb, const sr_real *r, const sr_real *sig, const sr_real *G, const sr_real *Jpa,
                  const sr_real *D, const sr_real *A, const sr_real *B, const sr_real *Dn, const sr_real *defect,
                  sr_real *M);

/**
 * W_s = the whitening of M_s for n_seg segments (M_s: rows[s] x width[s], stacked; W the same
 * layout, written; W must not overlap M).  Segment s has n_steps[s] steps of consecutive rows
 * that together cover its rows in order, step t of k_t = step_rows[t] >= 1 rows (the steps
 * of all segments stacked), with H_t (k_t x NE), the lower triangle of L_t (k_t x k_t), K_t
 * (NE x k_t) and unit_t > 0 (H, L and K stacked step after step).  With mean = 0 (NE x width[s])
 * at each segment's start, per step:
 *
 *   Y = M[step's rows] / unit_t,   I = Y - H_t mean,   W[step's rows] = L_t I,   mean += K_t I.
 *
 * Columns that are zero in a step's rows and in the mean so far stay zero and are skipped.
 * work: (NE + 1) x (the largest width) scratch.  Returns SR_OK, SR_ERR_NULL, SR_ERR_ARG (a count < 1
 * where one is needed, steps not covering a segment's rows, unit not > 0) or SR_ERR_NONFINITE.
 */
int sr_ident_whiten(long n_seg, const long *rows, const long *width, const long *n_steps, const long *step_rows,
                    const sr_real *unit, const sr_real *H, const sr_real *L, const sr_real *K, const sr_real *M,
                    sr_real *W, sr_real *work);

#ifdef __cplusplus
}
#endif

#endif /* SR_IDENT_H */
