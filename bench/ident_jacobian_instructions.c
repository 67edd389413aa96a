/*
 * ident_jacobian_instructions.c -- one call of a fit's step-Jacobian kernels on the states of a file,
 * for callgrind (bench/ident_jacobian_instructions.py counts the instructions inside run()):
 *   F     sr_step_jacobian_batch (RKMK4; the state Jacobians both arms of a fit use)
 *   cols  sr_step_param_jacobian_cols_batch (the analytic parameter columns alone)
 *   both  sr_step_jacobian_param_cols_batch (F and those columns at once; not with -DSR_NO_BOTH)
 *   fd    sr_step_param_jacobian_fd_batch (the same columns by central differences, batched)
 *   fdF   F by central differences of sr_step_batch in the 12 error directions (sr_retract_batch,
 *         sr_local_batch), batched as fd: the all-differences arm's state Jacobian
 * Usage: ident_jacobian_instructions FILE MODE [COLUMN ...]; FILE: int n, the parameters, x (n x
 * SR_NX), u (n x SR_NU).
 */
#include "spherical_robot.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#define MAXN 64
static double XP[MAXN][SR_NX], XM[MAXN][SR_NX], Y0[MAXN][SR_NX], YP[MAXN][SR_NX], YM[MAXN][SR_NX];
static double D[MAXN][SR_NE], DP[MAXN][SR_NE], DM[MAXN][SR_NE];
static double X[MAXN][SR_NX], U[MAXN][SR_NU], F[MAXN][144], G[MAXN][24], JP[MAXN * 12 * 32], WORK[MAXN * SR_PARAM_FD_WORK];
/* F by central differences, every state at once per direction (what runtime.identification's
 * "fd-all" source does through the batched calls). */
static int fd_state_jacobian(const sr_model *m, int n)
{
    const double e = 6e-6;
    long failed;
    int i, j, k, status = sr_step_batch(m, SR_RKMK4, n, &X[0][0], &U[0][0], 0.01, &Y0[0][0], &failed);
    for (j = 0; j < SR_NE && status == SR_OK; ++j) {
        for (i = 0; i < n; ++i)
            for (k = 0; k < SR_NE; ++k) D[i][k] = k == j ? e : 0;
        status |= sr_retract_batch(m, n, &X[0][0], &D[0][0], &XP[0][0], &failed);
        for (i = 0; i < n; ++i) D[i][j] = -e;
        status |= sr_retract_batch(m, n, &X[0][0], &D[0][0], &XM[0][0], &failed);
        status |= sr_step_batch(m, SR_RKMK4, n, &XP[0][0], &U[0][0], 0.01, &YP[0][0], &failed);
        status |= sr_step_batch(m, SR_RKMK4, n, &XM[0][0], &U[0][0], 0.01, &YM[0][0], &failed);
        status |= sr_local_batch(m, n, &Y0[0][0], &YP[0][0], &DP[0][0], &failed);
        status |= sr_local_batch(m, n, &Y0[0][0], &YM[0][0], &DM[0][0], &failed);
        for (i = 0; i < n; ++i)
            for (k = 0; k < SR_NE; ++k) F[i][SR_NE * k + j] = (DP[i][k] - DM[i][k]) / (2 * e);
    }
    return status;
}

__attribute__((noinline)) int run(const sr_model *m, const char *mode, int n, int ncols, const int *cols)
{
    long failed;
    if (!strcmp(mode, "F")) return sr_step_jacobian_batch(m, SR_RKMK4, n, &X[0][0], &U[0][0], 0.01, &F[0][0], &G[0][0], &failed);
    if (!strcmp(mode, "cols")) return sr_step_param_jacobian_cols_batch(m, SR_RKMK4, n, &X[0][0], &U[0][0], 0.01, ncols, cols, JP, &failed);
    if (!strcmp(mode, "fdF")) return fd_state_jacobian(m, n);
#ifndef SR_NO_BOTH
    if (!strcmp(mode, "both")) return sr_step_jacobian_param_cols_batch(m, SR_RKMK4, n, &X[0][0], &U[0][0], 0.01, ncols, cols, &F[0][0], JP, &failed);
#endif
    if (!strcmp(mode, "fd")) return sr_step_param_jacobian_fd_batch(m, SR_RKMK4, n, &X[0][0], &U[0][0], 0.01, ncols, cols, JP, WORK, &failed);
    return -99;
}
int main(int argc, char **argv)
{
    sr_model m; double p[SR_NPARAM]; int n, ncols = 0, cols[32], i; FILE *f = fopen(argv[1], "rb");
    if (fread(&n, sizeof n, 1, f) != 1 || fread(p, sizeof p, 1, f) != 1) return 2;
    if (fread(X, sizeof X[0], n, f) != (size_t)n || fread(U, sizeof U[0], n, f) != (size_t)n) return 2;
    fclose(f);
    for (i = 3; i < argc; ++i) cols[ncols++] = atoi(argv[i]);
    if (sr_model_init(&m, p) != SR_OK) return 3;
    i = run(&m, argv[2], n, ncols, cols);
    printf("%s status %d\n", argv[2], i);
    return i != 0;
}
