/* param_jacobian_timing.c -- what one step's sensitivity to the parameters costs, next to the
 * step Jacobian and to the same sensitivity by finite differences, in one C loop over a file of
 * states (the input format of step_anatomy.c: int32 n, params[SR_NPARAM], states[n][35],
 * inputs[n][2]).  Prints one JSON object, ns per state, best of 11 rounds:
 *
 *   step_jacobian_<m>        sr_step_jacobian (F and G)
 *   step_param_jacobian_<m>  sr_step_param_jacobian (the analytic J_p)
 *   fd_batched_<m>           J_p by central differences, batched as a fit does it in C
 *                            (sr_step_param_jacobian_fd_batch): for each parameter, the model at
 *                            p +- h e_j and one sr_step_batch over all the states each, then
 *                            sr_local_batch against the nominal step and the difference quotient
 *   fd_worst_parameter_<m>   the column (SR_P_*) of that largest difference
 *   fd_skipped_columns       parameters with no valid robot on either side of p (the paper's flat
 *                            yoke lies on its tensor's triangle inequality: no product of inertia
 *                            can move); left out of fd_batched's work and error
 *   fd_max_error_<m>         the largest |J_p(fd) - J_p(analytic)| over the states, relative to the
 *                            largest entry of the analytic J_p: that both compute the same thing
 *
 * for <m> = rkmk4 and lie_euler (dt = 0.01).  bench/param_jacobian_timing.py writes the input and
 * runs it. */
#define _POSIX_C_SOURCE 199309L
#include "spherical_robot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

enum { MAX_STATES = 1024, ROUNDS = 11 };
static sr_real X[MAX_STATES][SR_NX], U[MAX_STATES][SR_NU], WORK[MAX_STATES][SR_PARAM_FD_WORK];
static sr_real JP[MAX_STATES][SR_NE * SR_NPARAM], JFD[MAX_STATES][SR_NE * SR_NPARAM];
static sr_real JFDC[MAX_STATES * SR_NE * SR_NPARAM];   /* n x SR_NE x ncols, as the library writes it */
static sr_real F[SR_NE * SR_NE], G[SR_NE * SR_NU];
static int SKIPPED[SR_NPARAM];

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

/* The finite-difference J_p of the library (sr_step_param_jacobian_fd_batch: per parameter, the
 * robot at p +- h and one sr_step_batch of all n states each side) in every column that has a valid
 * robot on some side of p, into JFD's full width. */
static int fd_batched(const sr_real p[SR_NPARAM], int method, int n)
{
    sr_model m0, m;
    sr_real q[SR_NPARAM];
    int cols[SR_NPARAM], ncols = 0, i, j, k, status = sr_model_init(&m0, p);
    for (j = 0; j < SR_NPARAM && status == SR_OK; ++j) {
        const sr_real h = SR_C(6e-6) * (p[j] != 0 ? fabs(p[j]) : 1);
        int side = 0;
        for (k = 0; k < SR_NPARAM; ++k) q[k] = p[k];
        q[j] = p[j] + h;
        side += sr_model_init(&m, q) == SR_OK;
        q[j] = p[j] - h;
        side += sr_model_init(&m, q) == SR_OK;
        SKIPPED[j] = !side;
        if (side) cols[ncols++] = j;
    }
    if (status == SR_OK)
        status = sr_step_param_jacobian_fd_batch(&m0, method, n, &X[0][0], &U[0][0], SR_C(0.01), ncols, cols,
                                                 JFDC, &WORK[0][0], NULL);
    for (i = 0; i < n && status == SR_OK; ++i)
        for (k = 0; k < SR_NE; ++k)
            for (j = 0; j < ncols; ++j) JFD[i][SR_NPARAM * k + cols[j]] = JFDC[(i * SR_NE + k) * ncols + j];
    return status;
}

int main(int argc, char **argv)
{
    static const char *names[] = {"step_jacobian", "step_param_jacobian", "fd_batched"};
    static const char *method_names[] = {"rkmk4", "lie_euler"};
    const int methods[] = {SR_RKMK4, SR_LIE_EULER};
    double best[2][3], sink = 0;
    sr_real p[SR_NPARAM];
    sr_model m;
    FILE *f;
    int n, repeats, round, c, r, i, k, mi;
    if (argc != 3) {
        fprintf(stderr, "usage: param_jacobian_timing INPUT REPEATS\n");
        return 2;
    }
    repeats = atoi(argv[2]);
    f = fopen(argv[1], "rb");
    if (!f || fread(&n, sizeof n, 1, f) != 1 || n < 1 || n > MAX_STATES || repeats < 1
        || fread(p, sizeof p[0], SR_NPARAM, f) != SR_NPARAM || fread(X, sizeof X[0], (size_t)n, f) != (size_t)n
        || fread(U, sizeof U[0], (size_t)n, f) != (size_t)n) {
        fprintf(stderr, "param_jacobian_timing: cannot read %s\n", argv[1]);
        return 2;
    }
    fclose(f);
    if (sr_model_init(&m, p) != SR_OK) return 3;
    printf("{");
    for (mi = 0; mi < 2; ++mi) {
        double err = 0, scale = 0;
        int worst = -1;
        for (c = 0; c < 3; ++c) best[mi][c] = 1e300;
        for (round = -3; round < ROUNDS; ++round)   /* three rounds of warm-up */
            for (c = 0; c < 3; ++c) {
                const double t0 = now_ns();
                double t;
                int status = SR_OK;
                for (r = 0; r < repeats; ++r) {
                    if (c == 2) {
                        status |= fd_batched(p, methods[mi], n);
                        sink += JFD[0][0];
                        continue;
                    }
                    for (i = 0; i < n; ++i) {
                        status |= c == 0 ? sr_step_jacobian(&m, methods[mi], X[i], U[i], SR_C(0.01), F, G)
                                         : sr_step_param_jacobian(&m, methods[mi], X[i], U[i], SR_C(0.01), JP[i]);
                        sink += c == 0 ? F[0] : JP[i][0];
                    }
                }
                if (status != SR_OK) {
                    fprintf(stderr, "param_jacobian_timing: %s failed (%d)\n", names[c], status);
                    return 4;
                }
                t = (now_ns() - t0) / ((double)repeats * n);
                if (round >= 0 && t < best[mi][c]) best[mi][c] = t;
            }
        for (i = 0; i < n; ++i)
            for (k = 0; k < SR_NE * SR_NPARAM; ++k) {
                if (fabs(JP[i][k]) > scale) scale = fabs(JP[i][k]);
                if (SKIPPED[k % SR_NPARAM]) continue;
                if (fabs(JFD[i][k] - JP[i][k]) > err) err = fabs(JFD[i][k] - JP[i][k]), worst = k % SR_NPARAM;
            }
        for (c = 0; c < 3; ++c) printf("\"%s_%s\": %.1f, ", names[c], method_names[mi], best[mi][c]);
        printf("\"fd_max_error_%s\": %.3g, \"fd_worst_parameter_%s\": %d, ", method_names[mi], err / scale,
               method_names[mi], worst);
    }
    for (k = 0, n = 0; k < SR_NPARAM; ++k) n += SKIPPED[k];
    printf("\"fd_skipped_columns\": %d, \"sink\": %.17g}\n", n, sink);
    return 0;
}
