/*
 * sr_ident.c -- the sensor-log identification fit's arithmetic around the kernels (sr_ident.h):
 * the segments' sensitivity chains, their rows and their whitening.  Plain loops over rows of
 * contiguous columns, so that the compiler vectorises the inner ones; the sums run in a fixed
 * order, so the results do not depend on the batch.
 */
#include "sr_ident.h"

#include "sr_math.h"
#include "sr_sensors.h"

#define NE SR_NE
#define NV SR_NV
#define NB SR_NBIAS

/* Zero for finite entries, NaN otherwise: v - v summed (vectorisable; no branch per entry). */
static sr_real nonfinite_mark(const sr_real *v, long n)
{
    sr_real s = 0;
    long i;
    for (i = 0; i < n; ++i) s += v[i] - v[i];
    return s;
}

/* y[0 .. n) += a x[0 .. n) */
static inline void axpy(long n, sr_real a, const sr_real *restrict x, sr_real *restrict y)
{
    long j;
    for (j = 0; j < n; ++j) y[j] += a * x[j];
}

/* y[0 .. n) = sum over l < m, in order, of a[l] times B's row l (B[l ldb + 0 .. n)) */
static inline void vec_mat(int m, long n, const sr_real *restrict a, const sr_real *restrict B, long ldb,
                           sr_real *restrict y)
{
    long j;
    int l;
    for (j = 0; j < n; ++j) y[j] = 0;
    for (l = 0; l < m; ++l) axpy(n, a[l], B + l * ldb, y);
}

SR_LANES_CLONES int sr_ident_chain(long n_seg, const long *steps, long nf, const sr_real *F, const sr_real *Jp,
                                   sr_real *G)
{
    const long w = NE + nf;
    long s, k, total = 0;
    int i;
    if (n_seg < 0 || nf < 0) return SR_ERR_ARG;
    if (n_seg == 0) return SR_OK;
    if (!steps || !F || !G) return SR_ERR_NULL;
    for (s = 0; s < n_seg; ++s) {
        if (steps[s] < 0) return SR_ERR_ARG;
        total += steps[s] + 1;
    }
    for (s = 0; s < n_seg; ++s) {
        sr_real *g = G;
        long j;
        for (i = 0; i < NE; ++i)
            for (j = 0; j < w; ++j) g[i * w + j] = (j == i) ? SR_C(1.0) : SR_C(0.0);
        for (k = 0; k < steps[s]; ++k) {
            sr_real *next = g + NE * w;
            for (i = 0; i < NE; ++i) {
                vec_mat(NE, w, F + k * NE * NE + i * NE, g, w, next + i * w);
                if (Jp) axpy(nf, 1, Jp + (k * NE + i) * nf, next + i * w + NE);
            }
            g = next;
        }
        F += steps[s] * NE * NE;
        if (Jp) Jp += steps[s] * NE * nf;
        G += (steps[s] + 1) * NE * w;
    }
    return isfinite(nonfinite_mark(G - total * NE * w, total * NE * w)) ? SR_OK : SR_ERR_NONFINITE;
}

SR_LANES_CLONES int sr_ident_rows(long n_seg, long nf, const long *steps, const long *n_read, const int *has_next,
                                  const long *at, const long *node, long n_nodes, const sr_real *Hx,
                                  const sr_real *Hn, const sr_real *Hb, const sr_real *r, const sr_real *sig,
                                  const sr_real *G, const sr_real *Jpa, const sr_real *D, const sr_real *A,
                                  const sr_real *B, const sr_real *Dn, const sr_real *defect, sr_real *M)
{
    const long wg = NE + nf;
    long s, q, q0, any_next = 0, n_rows = 0, total = 0;
    sr_real *M0 = M;
    if (n_seg < 0 || nf < 0 || nf > SR_NPARAM || n_nodes < 0) return SR_ERR_ARG;
    if (n_seg == 0) return SR_OK;
    if (!steps || !n_read || !has_next || !G || !D || !M) return SR_ERR_NULL;
    for (s = 0; s < n_seg; ++s) {
        if (steps[s] < 0 || n_read[s] < 0 || (has_next[s] != 0 && has_next[s] != 1)) return SR_ERR_ARG;
        any_next |= has_next[s];
        n_rows += n_read[s];
    }
    if (n_rows > 0 && (!at || !Hx || !Hn || !Hb || !r || !sig || (Jpa && !node))) return SR_ERR_NULL;
    if (any_next && (!A || !B || !Dn || !defect)) return SR_ERR_NULL;
    for (s = 0, q = 0; s < n_seg; ++s)
        for (q0 = q + n_read[s]; q < q0; ++q)
            if (at[q] < 0 || at[q] > steps[s] || !(sig[q] > 0) || (Jpa && (node[q] < 0 || node[q] >= n_nodes)))
                return SR_ERR_ARG;
    for (s = 0, q = 0; s < n_seg; ++s) {
        const long w = nf + NB + NE + NE * has_next[s] + 1, cx = nf + NB;
        const sr_real *d = D + s * NE * NE;
        long j;
        int l;
        for (q0 = q + n_read[s]; q < q0; ++q, M += w) {
            const sr_real sq = sig[q];
            sr_real hg[NE + SR_NPARAM];
            vec_mat(NE, wg, Hx + q * NE, G + at[q] * NE * wg, wg, hg);      /* Hx [Phi_k | S_k] */
            if (Jpa)
                for (l = 0; l < NV; ++l) axpy(nf, Hn[q * NV + l], Jpa + (node[q] * NV + l) * nf, hg + NE);
            for (j = 0; j < nf; ++j) M[j] = -hg[NE + j] / sq;
            for (j = 0; j < NB; ++j) M[nf + j] = -Hb[q * NB + j] / sq;
            for (j = 0; j < NE; ++j) hg[j] = -hg[j] / sq;
            vec_mat(NE, NE, hg, d, NE, M + cx);
            for (j = cx + NE; j < w - 1; ++j) M[j] = 0;
            M[w - 1] = r[q] / sq;
        }
        if (has_next[s]) {
            const sr_real *gl = G + steps[s] * NE * wg;
            int i;
            for (i = 0; i < NE; ++i, M += w) {
                const sr_real *a = A + s * NE * NE + i * NE;
                sr_real ag[NE + SR_NPARAM];
                vec_mat(NE, wg, a, gl, wg, ag);                             /* A [Phi_L | S_L] */
                for (j = 0; j < nf; ++j) M[j] = ag[NE + j];
                for (j = 0; j < NB; ++j) M[nf + j] = 0;
                vec_mat(NE, NE, ag, d, NE, M + cx);                          /* (A Phi_L) D */
                vec_mat(NE, NE, B + s * NE * NE + i * NE, Dn + s * NE * NE, NE, M + cx + NE);
                M[w - 1] = defect[s * NE + i];
            }
        }
        total += (n_read[s] + NE * has_next[s]) * w;
        G += (steps[s] + 1) * NE * wg;
    }
    return isfinite(nonfinite_mark(M0, total)) ? SR_OK : SR_ERR_NONFINITE;
}

/* The columns [*z0, *z1) that a step's rows (k x w) and the mean so far (live[j] != 0 where the
 * mean's column j may be nonzero) leave zero: the longest such run (empty: *z0 == *z1 == w). */
static void zero_span(const sr_real *M, long k, long w, const sr_real *live, long *z0, long *z1)
{
    long i, j, run = 0, best = 0;
    *z0 = *z1 = w;
    for (j = 0; j < w; ++j) {
        int zero = live[j] == 0;
        for (i = 0; zero && i < k; ++i) zero = M[i * w + j] == 0;
        run = zero ? run + 1 : 0;
        if (run > best) {
            best = run;
            *z0 = j + 1 - run;
            *z1 = j + 1;
        }
    }
}

/* The whitening's three products on the nc columns from j of one step (whiten_columns), each entry a
 * sum in a fixed order, carried in registers across the sum (nc = CB: one vector of columns). */
#define CB 4

static inline void innovations(long k, long w, long j, int nc, sr_real u, const sr_real *restrict H,
                               const sr_real *restrict M, const sr_real *restrict mean, sr_real *restrict W)
{
    long i;
    int l, c;
    for (i = 0; i < k; ++i) {
        sr_real v[CB];
        for (c = 0; c < nc; ++c) v[c] = u == 1 ? M[i * w + j + c] : M[i * w + j + c] / u;
        for (l = 0; l < NE; ++l)
            for (c = 0; c < nc; ++c) v[c] -= H[i * NE + l] * mean[l * w + j + c];
        for (c = 0; c < nc; ++c) W[i * w + j + c] = v[c];
    }
}

static inline void gain(long k, long w, long j, int nc, const sr_real *restrict K, const sr_real *restrict W,
                        sr_real *restrict mean)
{
    long i;
    int l, c;
    for (l = 0; l < NE; ++l) {
        sr_real v[CB];
        for (c = 0; c < nc; ++c) v[c] = mean[l * w + j + c];
        for (i = 0; i < k; ++i)
            for (c = 0; c < nc; ++c) v[c] += K[l * k + i] * W[i * w + j + c];
        for (c = 0; c < nc; ++c) mean[l * w + j + c] = v[c];
    }
}

/* W = L I in place from the last row up (row i needs the innovations of rows <= i) */
static inline void lower_times(long k, long w, long j, int nc, const sr_real *restrict L, sr_real *W)
{
    long i, m;
    int c;
    for (i = k - 1; i >= 0; --i) {
        sr_real v[CB];
        for (c = 0; c < nc; ++c) v[c] = 0;
        for (m = 0; m <= i; ++m)
            for (c = 0; c < nc; ++c) v[c] += L[i * k + m] * W[m * w + j + c];
        for (c = 0; c < nc; ++c) W[i * w + j + c] = v[c];
    }
}

/* One step of the whitening on the columns [c0, c1) of rows of width w (sr_ident_whiten): the
 * innovations I = M / u - H mean in W's rows, mean += K I, W = L I. */
static SR_LANES_CLONES void whiten_columns(long k, long w, long c0, long c1, sr_real u, const sr_real *H,
                                           const sr_real *L, const sr_real *K, const sr_real *M, sr_real *W,
                                           sr_real *mean)
{
    long j;
    for (j = c0; j + CB <= c1; j += CB) innovations(k, w, j, CB, u, H, M, mean, W);
    if (j < c1) innovations(k, w, j, (int)(c1 - j), u, H, M, mean, W);
    for (j = c0; j + CB <= c1; j += CB) gain(k, w, j, CB, K, W, mean);
    if (j < c1) gain(k, w, j, (int)(c1 - j), K, W, mean);
    for (j = c0; j + CB <= c1; j += CB) lower_times(k, w, j, CB, L, W);
    if (j < c1) lower_times(k, w, j, (int)(c1 - j), L, W);
}

int sr_ident_whiten(long n_seg, const long *rows, const long *width, const long *n_steps, const long *step_rows,
                    const sr_real *unit, const sr_real *H, const sr_real *L, const sr_real *K, const sr_real *M,
                    sr_real *W, sr_real *work)
{
    long s, t, t0, total = 0;
    sr_real *W0 = W;
    if (n_seg < 0) return SR_ERR_ARG;
    if (n_seg == 0) return SR_OK;
    if (!rows || !width || !n_steps || !step_rows || !unit || !H || !L || !K || !M || !W || !work)
        return SR_ERR_NULL;
    for (s = 0, t = 0; s < n_seg; ++s) {
        long covered = 0;
        if (rows[s] < 0 || width[s] < 1 || n_steps[s] < 0) return SR_ERR_ARG;
        for (t0 = t + n_steps[s]; t < t0; ++t) {
            if (step_rows[t] < 1 || !(unit[t] > 0)) return SR_ERR_ARG;
            covered += step_rows[t];
        }
        if (covered != rows[s]) return SR_ERR_ARG;
    }
    for (s = 0, t = 0; s < n_seg; ++s) {
        const long w = width[s];
        sr_real *mean = work, *live = work + NE * w;
        long i, j;
        for (j = 0; j < (NE + 1) * w; ++j) work[j] = 0;
        for (t0 = t + n_steps[s]; t < t0; ++t) {
            const long k = step_rows[t];
            long z0, z1;
            /* columns zero in the step's rows and in the mean stay zero: skipped */
            zero_span(M, k, w, live, &z0, &z1);
            whiten_columns(k, w, 0, z0, unit[t], H, L, K, M, W, mean);
            whiten_columns(k, w, z1, w, unit[t], H, L, K, M, W, mean);
            for (i = 0; i < k; ++i)
                for (j = z0; j < z1; ++j) W[i * w + j] = 0;
            for (j = 0; j < w; ++j)
                if (j < z0 || j >= z1) live[j] = 1;
            M += k * w;
            W += k * w;
            H += k * NE;
            L += k * k;
            K += NE * k;
        }
        total += rows[s] * w;
    }
    return isfinite(nonfinite_mark(W0, total)) ? SR_OK : SR_ERR_NONFINITE;
}
