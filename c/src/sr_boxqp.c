/*
 * sr_boxqp.c -- the box-constrained QP of the NMPC: a primal active-set method with one Cholesky
 * factorisation of the free variables' Hessian per iteration (sr_nmpc.h).
 */
#include "sr_nmpc.h"
#include "sr_math.h"

/* Not finite: NaN or +-inf (x - x is 0 only for finite x). */
static int finite1(sr_real v) { return v - v == 0; }

/* U^T U = H[free, free] in U (nf x nf, row-major, upper triangle), right-looking: every update is a
 * scaled row added to a row (contiguous, vectorisable without reordering a sum); 0 when H is not
 * positive definite there. */
static int factor(int n, const sr_real *H, const int *free, int nf, sr_real *U)
{
    int i, j, k;
    for (i = 0; i < nf; ++i)
        for (k = i; k < nf; ++k)
            U[i * nf + k] = H[free[k] * n + free[i]]; /* free[] increases: (free[k], free[i]) is in the lower triangle */
    for (j = 0; j < nf; ++j) {
        sr_real *Uj = U + j * nf, d = Uj[j];
        if (!(d > 0)) return 0;
        d = SR_SQRT(d);
        Uj[j] = d;
        for (k = j + 1; k < nf; ++k) Uj[k] /= d;
        for (i = j + 1; i < nf; ++i) {
            sr_real *Ui = U + i * nf;
            const sr_real a = Uj[i];
            for (k = i; k < nf; ++k) Ui[k] -= a * Uj[k];
        }
    }
    return 1;
}

/* b <- (U^T U)^-1 b */
static void solve(int nf, const sr_real *U, sr_real *b)
{
    int i, k;
    for (i = 0; i < nf; ++i) { /* U^T y = b, y in b */
        const sr_real *Ui = U + i * nf;
        const sr_real y = b[i] / Ui[i];
        b[i] = y;
        for (k = i + 1; k < nf; ++k) b[k] -= Ui[k] * y;
    }
    for (i = nf - 1; i >= 0; --i) {
        const sr_real *Ui = U + i * nf;
        sr_real s = b[i];
        for (k = i + 1; k < nf; ++k) s -= Ui[k] * b[k];
        b[i] = s / Ui[i];
    }
}

/* grad = H x + g from H's lower triangle. */
static void gradient(int n, const sr_real *H, const sr_real *g, const sr_real *x, sr_real *grad)
{
    int i, j;
    for (i = 0; i < n; ++i) {
        sr_real s = g[i];
        for (j = 0; j <= i; ++j) s += H[i * n + j] * x[j];
        for (j = i + 1; j < n; ++j) s += H[j * n + i] * x[j];
        grad[i] = s;
    }
}

int sr_boxqp_solve(int n, const sr_real *H, const sr_real *g, const sr_real *lb, const sr_real *ub,
                   int max_iterations, sr_real *x, sr_real *work, int *iwork, int *iterations)
{
    sr_real *L, *p, *grad, *y, scale = 1, tol;
    int *state, *free, i, j, nf, used = 0, need_solve = 1;
    if (!H || !g || !lb || !ub || !x || !work || !iwork) return SR_ERR_NULL;
    if (n < 1 || max_iterations < 1) return SR_ERR_ARG;
    for (i = 0; i < n; ++i) {
        if (lb[i] != lb[i] || ub[i] != ub[i]) return SR_ERR_NONFINITE;
        if (!finite1(g[i]) || !finite1(x[i])) return SR_ERR_NONFINITE;
        for (j = 0; j <= i; ++j)
            if (!finite1(H[i * n + j])) return SR_ERR_NONFINITE;
    }
    for (i = 0; i < n; ++i)
        if (lb[i] > ub[i]) return SR_ERR_ARG;
    L = work;
    y = work + n * n;            /* the iterate (x is written only on success) */
    p = y + n;
    grad = p + n;
    state = iwork;               /* -1 at lb, +1 at ub, 0 free */
    free = iwork + n;
    for (i = 0; i < n; ++i) {
        y[i] = x[i] < lb[i] ? lb[i] : (x[i] > ub[i] ? ub[i] : x[i]);
        state[i] = y[i] == ub[i] ? 1 : (y[i] == lb[i] ? -1 : 0);
        scale = SR_FABS(g[i]) > scale ? SR_FABS(g[i]) : scale;
        for (j = 0; j <= i; ++j) scale = SR_FABS(H[i * n + j]) > scale ? SR_FABS(H[i * n + j]) : scale;
    }
    tol = SR_BOXQP_TOL * scale;
    for (;;) {
        if (need_solve) {
            sr_real alpha = 1;
            int block = -1, side = 0;
            if (used == max_iterations) return SR_ERR_MAX_STEPS;
            ++used;
            for (nf = 0, i = 0; i < n; ++i)
                if (state[i] == 0) free[nf++] = i;
            if (nf > 0) {
                if (!factor(n, H, free, nf, L)) return SR_ERR_SINGULAR;
                gradient(n, H, g, y, grad);
                for (i = 0; i < nf; ++i) p[i] = -grad[free[i]];
                solve(nf, L, p);
                /* The longest step along p within the box; the first bound met blocks. */
                for (i = 0; i < nf; ++i) {
                    const int k = free[i];
                    if (p[i] < 0 && lb[k] - y[k] > alpha * p[i]) {
                        alpha = (lb[k] - y[k]) / p[i];
                        block = i;
                        side = -1;
                    } else if (p[i] > 0 && ub[k] - y[k] < alpha * p[i]) {
                        alpha = (ub[k] - y[k]) / p[i];
                        block = i;
                        side = 1;
                    }
                }
                alpha = alpha < 0 ? 0 : alpha;
                for (i = 0; i < nf; ++i) y[free[i]] += alpha * p[i];
                if (block >= 0) {
                    const int k = free[block];
                    y[k] = side < 0 ? lb[k] : ub[k];
                    state[k] = side;
                    continue;
                }
            }
            need_solve = 0;
        }
        /* At the minimum on the face: free the bound variable whose multiplier is most wrong. */
        {
            sr_real worst = tol;
            int release = -1;
            gradient(n, H, g, y, grad);
            for (i = 0; i < n; ++i) {
                const sr_real wrong = state[i] < 0 ? -grad[i] : (state[i] > 0 ? grad[i] : 0);
                if (wrong > worst && lb[i] < ub[i]) {
                    worst = wrong;
                    release = i;
                }
            }
            if (release < 0) break;
            state[release] = 0;
            need_solve = 1;
        }
    }
    for (i = 0; i < n; ++i)
        if (!finite1(y[i])) return SR_ERR_NONFINITE;
    for (i = 0; i < n; ++i) x[i] = y[i];
    if (iterations) *iterations = used;
    return SR_OK;
}
