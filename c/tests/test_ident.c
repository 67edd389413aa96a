/*
 * test_ident.c -- the identification fit's chain, rows and whitening (sr_ident.h) against the
 * same quantities formed another way: the chain as products of the steps' Jacobians and a sum of
 * each step's sensitivity carried to the end; the rows with the products associated the other
 * way; the whitening as the block lower-triangular matrix the recursion applies.
 */
#include <math.h>
#include <string.h>

#include "sr_ident.h"
#include "sr_sensors.h"
#include "sr_test.h"

#define NE SR_NE
#define NV SR_NV
#define NB SR_NBIAS
#define NF 2
#define WG (NE + NF)

/* A fixed pseudo-random value in [-1, 1) (no state: a hash of i). */
static double pseudo(long i)
{
    unsigned long h = (unsigned long)i * 2654435761UL + 12345UL;
    h ^= h >> 13;
    h *= 1103515245UL;
    h ^= h >> 16;
    return (double)(h % 20001UL) / 10000.0 - 1.0;
}

static void fill(sr_real *v, long n, long seed, double scale)
{
    long i;
    for (i = 0; i < n; ++i) v[i] = (sr_real)(scale * pseudo(seed * 7919 + i));
}

/* c (n x p) = a (n x m) b (m x p), double accumulation */
static void matmul(const double *a, const double *b, double *c, int n, int m, int p)
{
    int i, j, l;
    for (i = 0; i < n; ++i)
        for (j = 0; j < p; ++j) {
            double s = 0;
            for (l = 0; l < m; ++l) s += a[i * m + l] * b[l * p + j];
            c[i * p + j] = s;
        }
}

#define STEPS0 3
#define STEPS1 2
#define NSTEP (STEPS0 + STEPS1)

static void test_ident_chain_is_the_product_of_the_steps_and_the_carried_sensitivities(void)
{
    const long steps[2] = {STEPS0, STEPS1};
    sr_real F[NSTEP * NE * NE], Jp[NSTEP * NE * NF], G[(NSTEP + 2) * NE * WG];
    long s, k, first = 0, g0 = 0;
    int i, j;
    fill(F, NSTEP * NE * NE, 1, 0.3);
    for (k = 0; k < NSTEP; ++k)
        for (i = 0; i < NE; ++i) F[k * NE * NE + i * NE + i] += 1;     /* near the identity, as a step's */
    fill(Jp, NSTEP * NE * NF, 2, 0.1);
    CHECK_STATUS(sr_ident_chain(2, steps, NF, F, Jp, G), SR_OK);
    for (s = 0; s < 2; ++s) {
        double Phi[NE * NE], tmp[NE * NE], S[NE * NF];
        for (i = 0; i < NE * NE; ++i) Phi[i] = (i % (NE + 1) == 0);
        memset(S, 0, sizeof S);
        for (k = 0; k < steps[s]; ++k) {
            double f[NE * NE], carried[NE * NE], c[NE * NF], jp[NE * NF];
            long m;
            for (i = 0; i < NE * NE; ++i) f[i] = (double)F[(first + k) * NE * NE + i];
            matmul(f, Phi, tmp, NE, NE, NE);
            memcpy(Phi, tmp, sizeof Phi);
            /* the step's sensitivity carried by the later steps to the segment's end */
            for (i = 0; i < NE * NE; ++i) carried[i] = (i % (NE + 1) == 0);
            for (m = k + 1; m < steps[s]; ++m) {
                for (i = 0; i < NE * NE; ++i) f[i] = (double)F[(first + m) * NE * NE + i];
                matmul(f, carried, tmp, NE, NE, NE);
                memcpy(carried, tmp, sizeof carried);
            }
            for (i = 0; i < NE * NF; ++i) jp[i] = (double)Jp[(first + k) * NE * NF + i];
            matmul(carried, jp, c, NE, NE, NF);
            for (i = 0; i < NE * NF; ++i) S[i] += c[i];
        }
        {
            const sr_real *gl = G + (g0 + steps[s]) * NE * WG, *gs = G + g0 * NE * WG;
            for (i = 0; i < NE; ++i) {
                for (j = 0; j < NE; ++j) {
                    CHECK_NEAR(gl[i * WG + j], Phi[i * NE + j], 200 * TEST_EPS);
                    CHECK_NEAR(gs[i * WG + j], i == j, 0);
                }
                for (j = 0; j < NF; ++j) {
                    CHECK_NEAR(gl[i * WG + NE + j], S[i * NF + j], 200 * TEST_EPS);
                    CHECK_NEAR(gs[i * WG + NE + j], 0, 0);
                }
            }
        }
        first += steps[s];
        g0 += steps[s] + 1;
    }
    /* without sensitivities the parameters' columns stay zero */
    CHECK_STATUS(sr_ident_chain(2, steps, NF, F, NULL, G), SR_OK);
    for (k = 0; k < NSTEP + 2; ++k)
        for (i = 0; i < NE; ++i)
            for (j = 0; j < NF; ++j) CHECK(G[k * NE * WG + i * WG + NE + j] == 0);
}

static void test_ident_chain_refuses_bad_arguments(void)
{
    const long steps[2] = {STEPS0, STEPS1}, bad[2] = {STEPS0, -1};
    sr_real F[NSTEP * NE * NE], G[(NSTEP + 2) * NE * WG];
    fill(F, NSTEP * NE * NE, 3, 0.3);
    CHECK_STATUS(sr_ident_chain(2, NULL, NF, F, NULL, G), SR_ERR_NULL);
    CHECK_STATUS(sr_ident_chain(2, steps, NF, NULL, NULL, G), SR_ERR_NULL);
    CHECK_STATUS(sr_ident_chain(2, steps, NF, F, NULL, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_ident_chain(-1, steps, NF, F, NULL, G), SR_ERR_ARG);
    CHECK_STATUS(sr_ident_chain(2, steps, -1, F, NULL, G), SR_ERR_ARG);
    CHECK_STATUS(sr_ident_chain(2, bad, NF, F, NULL, G), SR_ERR_ARG);
    CHECK_STATUS(sr_ident_chain(0, NULL, NF, NULL, NULL, NULL), SR_OK);
    F[5] = (sr_real)NAN;
    CHECK_STATUS(sr_ident_chain(2, steps, NF, F, NULL, G), SR_ERR_NONFINITE);
}

/* Two segments: the first of 2 steps with 3 reading rows and a next start, the second of 1 step
 * with 2 rows.  Widths: first NF + NB + 2 NE + 1, second NF + NB + NE + 1. */
#define R0 3
#define R1 2
#define W0 (NF + NB + 2 * NE + 1)
#define W1 (NF + NB + NE + 1)

static void test_ident_rows_are_the_readings_through_the_chain_and_the_end_state_difference(void)
{
    const long steps[2] = {2, 1}, n_read[2] = {R0, R1}, at[R0 + R1] = {0, 2, 1, 1, 0},
               node[R0 + R1] = {0, 2, 1, 4, 3};
    const int has[2] = {1, 0};
    sr_real G[5 * NE * WG], Jpa[5 * NV * NF], Hx[(R0 + R1) * NE], Hn[(R0 + R1) * NV], Hb[(R0 + R1) * NB];
    sr_real r[R0 + R1], sig[R0 + R1] = {0.5, 2.0, 1.0, 0.25, 3.0};
    sr_real D[2 * NE * NE], A[2 * NE * NE], B[2 * NE * NE], Dn[2 * NE * NE], defect[2 * NE];
    sr_real M[(R0 + NE) * W0 + R1 * W1];
    long q, s;
    int i, j;
    fill(G, 5 * NE * WG, 4, 1.0);
    fill(Jpa, 5 * NV * NF, 5, 1.0);
    fill(Hx, (R0 + R1) * NE, 6, 1.0);
    fill(Hn, (R0 + R1) * NV, 7, 1.0);
    fill(Hb, (R0 + R1) * NB, 8, 1.0);
    fill(r, R0 + R1, 9, 1.0);
    fill(D, 2 * NE * NE, 10, 1.0);
    fill(A, 2 * NE * NE, 11, 1.0);
    fill(B, 2 * NE * NE, 12, 1.0);
    fill(Dn, 2 * NE * NE, 13, 1.0);
    fill(defect, 2 * NE, 14, 1.0);
    CHECK_STATUS(sr_ident_rows(2, NF, steps, n_read, has, at, node, 5, Hx, Hn, Hb, r, sig, G, Jpa, D, A, B, Dn,
                               defect, M), SR_OK);
    for (s = 0, q = 0; s < 2; ++s) {
        const long w = s == 0 ? W0 : W1, g0 = s == 0 ? 0 : 3;
        const sr_real *Ms = M + (s == 0 ? 0 : (R0 + NE) * W0);
        double PhiD[NE * NE], phi[NE * NE], d[NE * NE];
        for (i = 0; i < NE * NE; ++i) d[i] = (double)D[s * NE * NE + i];
        for (; q < (s == 0 ? R0 : R0 + R1); ++q) {
            const sr_real *row = Ms + (q - (s == 0 ? 0 : R0)) * w, *g = G + (g0 + at[q]) * NE * WG;
            double hpd[NE];
            for (i = 0; i < NE; ++i)
                for (j = 0; j < NE; ++j) phi[i * NE + j] = (double)g[i * WG + j];
            matmul(phi, d, PhiD, NE, NE, NE);                       /* (Phi D), then Hx (Phi D) */
            for (j = 0; j < NE; ++j) {
                hpd[j] = 0;
                for (i = 0; i < NE; ++i) hpd[j] += (double)Hx[q * NE + i] * PhiD[i * NE + j];
                CHECK_NEAR(row[NF + NB + j], -hpd[j] / sig[q], 1e3 * TEST_EPS);
            }
            for (j = 0; j < NF; ++j) {
                double th = 0;
                for (i = 0; i < NE; ++i) th += (double)Hx[q * NE + i] * g[i * WG + NE + j];
                for (i = 0; i < NV; ++i) th += (double)Hn[q * NV + i] * Jpa[node[q] * NV * NF + i * NF + j];
                CHECK_NEAR(row[j], -th / sig[q], 1e3 * TEST_EPS);
            }
            for (j = 0; j < NB; ++j) CHECK_NEAR(row[NF + j], -Hb[q * NB + j] / sig[q], 8 * TEST_EPS);
            for (j = NF + NB + NE; j < w - 1; ++j) CHECK(row[j] == 0);
            CHECK_NEAR(row[w - 1], r[q] / sig[q], 8 * TEST_EPS);
        }
        if (has[s]) {
            const sr_real *gl = G + (g0 + steps[s]) * NE * WG;
            double a[NE * NE], ex[NE * NE], b[NE * NE], dn[NE * NE], bdn[NE * NE];
            for (i = 0; i < NE * NE; ++i) {
                a[i] = (double)A[s * NE * NE + i];
                b[i] = (double)B[s * NE * NE + i];
                dn[i] = (double)Dn[s * NE * NE + i];
            }
            for (i = 0; i < NE; ++i)
                for (j = 0; j < NE; ++j) phi[i * NE + j] = (double)gl[i * WG + j];
            matmul(phi, d, PhiD, NE, NE, NE);
            matmul(a, PhiD, ex, NE, NE, NE);                        /* A (Phi D) */
            matmul(b, dn, bdn, NE, NE, NE);
            for (i = 0; i < NE; ++i) {
                const sr_real *row = Ms + (R0 + i) * w;
                for (j = 0; j < NF; ++j) {
                    double th = 0;
                    int l;
                    for (l = 0; l < NE; ++l) th += a[i * NE + l] * gl[l * WG + NE + j];
                    CHECK_NEAR(row[j], th, 1e3 * TEST_EPS);
                }
                for (j = 0; j < NB; ++j) CHECK(row[NF + j] == 0);
                for (j = 0; j < NE; ++j) {
                    CHECK_NEAR(row[NF + NB + j], ex[i * NE + j], 1e3 * TEST_EPS);
                    CHECK_NEAR(row[NF + NB + NE + j], bdn[i * NE + j], 1e3 * TEST_EPS);
                }
                CHECK_NEAR(row[w - 1], defect[s * NE + i], 0);
            }
        }
    }
}

/* sr_ident_rows on one segment of one step and one reading row, no next start, with the
 * arguments a refusal case varies. */
static int one_row(long n_seg, const int *has, const long *at, const long *node, const sr_real *r,
                   const sr_real *sig, const sr_real *D)
{
    const long steps[1] = {1}, n_read[1] = {1};
    sr_real G[2 * NE * WG], Jpa[NV * NF], Hx[NE], Hn[NV], Hb[NB], M[W1];
    fill(G, 2 * NE * WG, 15, 1.0);
    fill(Jpa, NV * NF, 16, 1.0);
    fill(Hx, NE, 17, 1.0);
    fill(Hn, NV, 18, 1.0);
    fill(Hb, NB, 19, 1.0);
    return sr_ident_rows(n_seg, NF, steps, n_read, has, at, node, 1, Hx, Hn, Hb, r, sig, G, Jpa, D, NULL, NULL,
                         NULL, NULL, M);
}

static void test_ident_rows_refuse_bad_arguments(void)
{
    const long at[1] = {0}, far[1] = {2}, node[1] = {0}, off[1] = {1};
    const int has[1] = {0}, two[1] = {2};
    sr_real r[1] = {1}, sig[1] = {1}, zero[1] = {0}, D[NE * NE];
    fill(D, NE * NE, 20, 1.0);
    CHECK_STATUS(one_row(1, has, at, node, r, sig, D), SR_OK);
    CHECK_STATUS(one_row(1, has, at, node, r, sig, NULL), SR_ERR_NULL);
    CHECK_STATUS(one_row(1, two, at, node, r, sig, D), SR_ERR_ARG);        /* has_next not 0 or 1 */
    CHECK_STATUS(one_row(1, has, far, node, r, sig, D), SR_ERR_ARG);       /* a node past the chain */
    CHECK_STATUS(one_row(1, has, at, off, r, sig, D), SR_ERR_ARG);         /* a node past Jpa */
    CHECK_STATUS(one_row(1, has, at, node, r, zero, D), SR_ERR_ARG);       /* sigma not > 0 */
    CHECK_STATUS(one_row(-1, has, at, node, r, sig, D), SR_ERR_ARG);
    r[0] = (sr_real)INFINITY;
    CHECK_STATUS(one_row(1, has, at, node, r, sig, D), SR_ERR_NONFINITE);
}

/* One segment of three steps (2, 3 and 1 rows, the last divided by 0.5 first), width 4: column 1
 * zero in the first step's rows (the mean's too, so skipped there) and nonzero later; column 2
 * nonzero in the first step's rows only (the mean carries it on). */
#define WR 6
#define WW 4

static void test_ident_whitening_is_the_recursions_block_triangular_matrix(void)
{
    const long rows[1] = {WR}, width[1] = {WW}, n_steps[1] = {3}, step_rows[3] = {2, 3, 1};
    const sr_real unit[3] = {1, 1, 0.5};
    sr_real H[WR * NE], L[4 + 9 + 1], K[NE * WR], M[WR * WW], W[WR * WW], work[(NE + 1) * WW];
    double T[WR * WR], Md[WR * WW], expect[WR * WW];
    long o[3] = {0, 2, 5}, lo[3] = {0, 4, 13}, k[3] = {2, 3, 1};
    int t, u, i, j;
    fill(H, WR * NE, 21, 1.0);
    fill(L, 14, 22, 1.0);
    fill(K, NE * WR, 23, 0.5);
    fill(M, WR * WW, 24, 1.0);
    M[0 * WW + 1] = M[1 * WW + 1] = 0;          /* column 1: zero in the first step */
    for (i = 2; i < WR; ++i) M[i * WW + 2] = 0; /* column 2: only in the first step */
    /* T: the rows of step t are L_t (M_t / unit_t - H_t mean_t), mean_{t+1} = mean_t + K_t (...),
     * so T's block (t, u) for u < t is -L_t H_t sum over the paths of the gains; built row of
     * steps by row of steps from the maps mean_t = P_t M (P_t: NE x WR). */
    {
        double P[NE * WR], I[WR * WR], LI[WR * WR];
        memset(P, 0, sizeof P);
        memset(T, 0, sizeof T);
        for (t = 0; t < 3; ++t) {
            /* the innovations' map I_t (k_t x WR) = E_t / unit_t - H_t P */
            for (i = 0; i < k[t]; ++i)
                for (u = 0; u < WR; ++u) {
                    double v = (u == o[t] + i) / (double)unit[t];
                    int l;
                    for (l = 0; l < NE; ++l) v -= (double)H[(o[t] + i) * NE + l] * P[l * WR + u];
                    I[i * WR + u] = v;
                }
            for (i = 0; i < k[t]; ++i)
                for (u = 0; u < WR; ++u) {
                    double v = 0;
                    for (j = 0; j <= i; ++j) v += (double)L[lo[t] + i * k[t] + j] * I[j * WR + u];
                    LI[i * WR + u] = v;
                }
            for (i = 0; i < k[t]; ++i)
                for (u = 0; u < WR; ++u) T[(o[t] + i) * WR + u] = LI[i * WR + u];
            for (i = 0; i < NE; ++i)
                for (u = 0; u < WR; ++u)
                    for (j = 0; j < k[t]; ++j) P[i * WR + u] += (double)K[NE * o[t] + i * k[t] + j] * I[j * WR + u];
        }
    }
    for (i = 0; i < WR * WW; ++i) Md[i] = (double)M[i];
    matmul(T, Md, expect, WR, WR, WW);
    CHECK_STATUS(sr_ident_whiten(1, rows, width, n_steps, step_rows, unit, H, L, K, M, W, work), SR_OK);
    for (i = 0; i < WR * WW; ++i) CHECK_NEAR(W[i], expect[i], 1e3 * TEST_EPS);
    for (i = 0; i < 2; ++i) CHECK(W[i * WW + 1] == 0);     /* nothing reached column 1 in the first step */
    CHECK(fabs((double)W[4 * WW + 2]) > 1e-3);             /* the mean carried column 2 on */
}

static void test_ident_whitening_refuses_bad_arguments(void)
{
    const long rows[1] = {3}, width[1] = {2}, n_steps[1] = {2}, step_rows[2] = {2, 1}, short_steps[2] = {1, 1};
    const sr_real unit[2] = {1, 1}, zero_unit[2] = {1, 0};
    sr_real H[3 * NE], L[5], K[NE * 3], M[6], W[6], work[(NE + 1) * 2];
    fill(H, 3 * NE, 25, 1.0);
    fill(L, 5, 26, 1.0);
    fill(K, NE * 3, 27, 1.0);
    fill(M, 6, 28, 1.0);
    CHECK_STATUS(sr_ident_whiten(1, rows, width, n_steps, step_rows, unit, H, L, K, M, W, work), SR_OK);
    CHECK_STATUS(sr_ident_whiten(1, rows, width, n_steps, short_steps, unit, H, L, K, M, W, work), SR_ERR_ARG);
    CHECK_STATUS(sr_ident_whiten(1, rows, width, n_steps, step_rows, zero_unit, H, L, K, M, W, work), SR_ERR_ARG);
    CHECK_STATUS(sr_ident_whiten(1, rows, width, n_steps, step_rows, unit, H, L, K, M, W, NULL), SR_ERR_NULL);
    CHECK_STATUS(sr_ident_whiten(-1, rows, width, n_steps, step_rows, unit, H, L, K, M, W, work), SR_ERR_ARG);
    M[3] = (sr_real)NAN;
    CHECK_STATUS(sr_ident_whiten(1, rows, width, n_steps, step_rows, unit, H, L, K, M, W, work), SR_ERR_NONFINITE);
}

void suite_ident(void)
{
    RUN_TEST(test_ident_chain_is_the_product_of_the_steps_and_the_carried_sensitivities);
    RUN_TEST(test_ident_chain_refuses_bad_arguments);
    RUN_TEST(test_ident_rows_are_the_readings_through_the_chain_and_the_end_state_difference);
    RUN_TEST(test_ident_rows_refuse_bad_arguments);
    RUN_TEST(test_ident_whitening_is_the_recursions_block_triangular_matrix);
    RUN_TEST(test_ident_whitening_refuses_bad_arguments);
}
