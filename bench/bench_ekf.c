/* bench_ekf.c -- times one sample of the error-state EKF (c/include/sr_ekf.h) at 200 Hz in a C loop:
 * one prediction (RKMK4, its step Jacobian, the process noise), one IMU update on the yoke and one
 * encoder update, over a recorded run; and the prediction alone, and each update alone.
 *
 * The same sample is timed on the filter's default path too: the IMU read through
 * sr_ekf_update_imu_held with the torque disturbance held over one IMU period (as estimate_log, the
 * closed loop sr_sim.c and the firmware example read it), its prior drawn at every IMU sample.
 *
 * usage: bench_ekf [SAMPLES [PARTS]]   (default 2000: 10 s at 200 Hz)
 * With PARTS (a sum of 1 predict, 2 IMU update, 4 encoder update, 8 held IMU update; 0 none) only
 * those parts run,
 * once over the samples: the program an instruction counter runs (bench/ekf_timing.py --callgrind
 * subtracts the run of PARTS 0, the setup).
 * Build (portable -O2, as the bench's C loop), from the repository's root:
 *   make -C c lib && cc -O2 -std=c99 -ffp-contract=off -Ic/include -Igenerated bench/bench_ekf.c \
 *       c/build/libsphericalrobot.a -lm -o bench_ekf
 * The run is simulated first (sr_step, readings by sr_imu_measure_u and sr_encoders_measure); the
 * timed loops read it.  Prints one JSON object: ns per sample, best of 11 rounds, and in the same
 * run one RKMK4 step Jacobian (sr_step_jacobian), the bench's step_jacobian_rkmk4: on a loaded
 * machine the ratio of the two is the number that carries over.
 */
#define _POSIX_C_SOURCE 199309L
#include "sr_ekf.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define NMAX 20000
#define DT 0.005

static sr_real U[NMAX][SR_NU], IMU[NMAX][SR_NIMU], ENC[NMAX][2];
static const sr_real MOUNT[SR_NMOUNT] = {0, 0, -0.05, 1, 0, 0, 0, 1, 0, 0, 0, 1};
static const sr_ekf_process PROCESS = {{0.01, 0.01, 0.01}, 0, 0};
static const sr_real SIGMA[SR_NIMU] = {0.003, 0.003, 0.003, 0.02, 0.02, 0.02};

static double now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return 1e9 * (double)t.tv_sec + (double)t.tv_nsec;
}

static void start_state(const sr_model *m, sr_real x[SR_NX])
{
    memset(x, 0, sizeof(sr_real) * SR_NX);
    x[SR_X_R_S + 0] = x[SR_X_R_S + 4] = x[SR_X_R_S + 8] = 1;
    x[SR_X_R_Y + 0] = x[SR_X_R_Y + 4] = x[SR_X_R_Y + 8] = 1;
    x[SR_X_R_P + 0] = x[SR_X_R_P + 4] = x[SR_X_R_P + 8] = 1;
    x[SR_X_q + 2] = m->p[SR_P_r];
}

/* parts: 1 predict, 2 IMU update, 4 encoder update, 8 held IMU update (the disturbance held over DT). */
static int run(const sr_model *m, int n, int parts, double *ns)
{
    sr_ekf ekf;
    sr_real x[SR_NX], sigma[SR_NEB];
    const sr_real gate = INFINITY;
    double t0;
    int i, status = SR_OK;
    start_state(m, x);
    for (i = 0; i < SR_NEB; ++i) sigma[i] = 0.01;
    if ((status = sr_ekf_init_diagonal(&ekf, m, x, NULL, sigma)) != SR_OK) return status;
    t0 = now_ns();
    for (i = 0; i < n && status == SR_OK; ++i) {
        if (parts & 1) status = sr_ekf_predict(&ekf, m, SR_RKMK4, U[i], DT, &PROCESS);
        if (status == SR_OK && (parts & 2))
            status = sr_ekf_update_imu(&ekf, m, IMU[i], U[i], SR_BODY_yoke, MOUNT, 0.003, 0.02, gate);
        if (status == SR_OK && (parts & 8))
            status = sr_ekf_update_imu_held(&ekf, m, IMU[i], U[i], SR_BODY_yoke, MOUNT, SIGMA, &PROCESS, DT, gate);
        if (status == SR_OK && (parts & 4)) status = sr_ekf_update_encoders(&ekf, m, ENC[i], 0.0005, gate);
    }
    *ns = (now_ns() - t0) / n;
    return status;
}

int main(int argc, char **argv)
{
    /* Params.paper_simulation(): the paper's Section 5.2 robot with the damping doubled. */
    const sr_real paper[SR_NPAPER] = {
        [SR_PAPER_r] = 0.3, [SR_PAPER_m_S] = 2.0, [SR_PAPER_k_S] = 0.16, [SR_PAPER_b] = 0.2, [SR_PAPER_h] = 0.5,
        [SR_PAPER_m_b] = 2.0, [SR_PAPER_m_h] = 5.0, [SR_PAPER_k_Y] = 0.04, [SR_PAPER_l] = 0.2, [SR_PAPER_m_P] = 1.0,
        [SR_PAPER_k_P] = 0.10, [SR_PAPER_g] = 9.81};
    const char *names[] = {"predict_imu_encoders", "predict", "update_imu", "update_encoders",
                           "held_predict_imu_encoders", "held_predict_imu"};
    const int parts[] = {7, 1, 2, 4, 13, 9};
    sr_real params[SR_NPARAM], x[SR_NX];
    sr_model m;
    int n = argc > 1 ? atoi(argv[1]) : 2000, only, i, k, r;
    if (n < 1 || n > NMAX) n = 2000;
    if (sr_paper_params(paper, params) != SR_OK || sr_model_init(&m, params) != SR_OK) return 1;
    only = argc > 2 ? atoi(argv[2]) : -1;
    start_state(&m, x);
    for (i = 0; i < n; ++i) {
        U[i][0] = (sr_real)(0.2 + 0.1 * sin(0.7 * i * DT));
        U[i][1] = (sr_real)(0.05 * cos(1.3 * i * DT));
        if (sr_imu_measure_u(&m, x, U[i], SR_BODY_yoke, MOUNT, NULL, IMU[i]) != SR_OK
            || sr_encoders_measure(&m, x, ENC[i]) != SR_OK || sr_step(&m, SR_RKMK4, x, U[i], DT, x) != SR_OK)
            return 1;
    }
    if (only >= 0) {
        double ns = 0;
        if (only > 15 || run(&m, n, only, &ns) != SR_OK) return 1;
        printf("{\"samples\": %d, \"parts\": %d, \"ns\": %.1f}\n", n, only, ns);
        return 0;
    }
    printf("{\"samples\": %d, \"dt\": %g", n, DT);
    for (k = 0; k < 6; ++k) {
        double best = 1e300, ns = 0;
        for (r = 0; r < 11; ++r) {
            if (run(&m, n, parts[k], &ns) != SR_OK) return 1;
            best = ns < best ? ns : best;
        }
        printf(", \"%s_ns\": %.1f", names[k], best);
    }
    {
        sr_real F[SR_NE * SR_NE], G[SR_NE * SR_NU];
        double best = 1e300;
        for (r = 0; r < 11; ++r) {
            const double t0 = now_ns();
            for (i = 0; i < n; ++i)
                if (sr_step_jacobian(&m, SR_RKMK4, x, U[i], DT, F, G) != SR_OK) return 1;
            best = (now_ns() - t0) / n < best ? (now_ns() - t0) / n : best;
        }
        printf(", \"step_jacobian_rkmk4_ns\": %.1f", best);
    }
    printf("}\n");
    return 0;
}
