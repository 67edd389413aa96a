/*
 * nmpc_loop.c -- the C NMPC (sr_nmpc_step) in a closed loop on a circle, timed: no Python, no heap.
 *
 * The design and the task come from nmpc_task.h, written by `python -m runtime nmpc-c --header`
 * (an `sr_nmpc` initializer designed for the task's robot, as runtime/control/nmpc.py's NmpcC
 * builds it, the initial state, the circle, dt and the rates).  Every controller sample finds the
 * nearest point of the circle (centre NMPC_TASK_CENTRE, counter-clockwise), computes the torques
 * and holds them for NMPC_TASK_STEPS_PER_SAMPLE plant steps (sr_step, RKMK4).
 *
 * Output (stdout): one line: the samples; the wall-clock time of sr_nmpc_step, p50, p99 and max [us];
 * the same in the thread's CPU time; the QP's factorisations per sample (the last iteration's), p50,
 * p99, max; the cross-track RMS over the second half of the run [m]; restarts and failures.  Build and run:
 * `python -m runtime nmpc-c --timing` (docs/control.md).  Exit status 0, or 1 with a message on stderr.
 */
#include "nmpc_task.h"
#include "sr_nmpc.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

static sr_nmpc_memory memory; /* the controller's whole workspace, static: no heap, not on the stack */
static double elapsed_us[NMPC_TASK_SAMPLES], cpu_us[NMPC_TASK_SAMPLES];
static int qp_iterations[NMPC_TASK_SAMPLES];

static int by_value(const void *a, const void *b)
{
    const double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int by_int(const void *a, const void *b)
{
    const int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Wall-clock time, or (cpu) the thread's CPU time: on a shared machine the latter leaves out the
 * time the process waited for a core. */
static double now_us(int cpu)
{
    struct timespec t;
    clock_gettime(cpu ? CLOCK_THREAD_CPUTIME_ID : CLOCK_MONOTONIC, &t);
    return 1e6 * (double)t.tv_sec + 1e-3 * (double)t.tv_nsec;
}

int main(void)
{
    const double pi = 3.14159265358979323846;
    sr_model model;
    sr_nmpc_target target = {0, 0, 0, 0, 1, NULL};
    sr_real x[SR_NX], u[SR_NU];
    double sum2 = 0;
    long k, counted = 0;
    int i, status = sr_model_init(&model, NMPC_TASK_PARAMS);
    if (status == SR_OK) status = sr_nmpc_check(&NMPC_DESIGN);
    if (status == SR_OK) status = sr_nmpc_reset(&memory);
    if (status != SR_OK) {
        fprintf(stderr, "nmpc_loop: %s\n", sr_status_string(status));
        return 1;
    }
    for (i = 0; i < SR_NX; ++i) x[i] = NMPC_TASK_X0[i];
    target.speed = NMPC_TASK_SPEED;
    target.curvature = 1 / NMPC_TASK_RADIUS;
    for (k = 0; k < NMPC_TASK_SAMPLES; ++k) {
        const double dx = (double)x[SR_X_q] - NMPC_TASK_CENTRE[0], dy = (double)x[SR_X_q + 1] - NMPC_TASK_CENTRE[1];
        double t0, c0;
        target.heading = (sr_real)(atan2(dy, dx) + pi / 2);
        target.cross_track = (sr_real)(NMPC_TASK_RADIUS - sqrt(dx * dx + dy * dy));
        if (2 * k >= NMPC_TASK_SAMPLES) {
            sum2 += (double)target.cross_track * target.cross_track;
            ++counted;
        }
        c0 = now_us(1);
        t0 = now_us(0);
        status = sr_nmpc_step(&NMPC_DESIGN, &memory, &model, x, &target, u);
        elapsed_us[k] = now_us(0) - t0;
        cpu_us[k] = now_us(1) - c0;
        qp_iterations[k] = memory.qp_iterations;
        for (i = 0; i < NMPC_TASK_STEPS_PER_SAMPLE && status == SR_OK; ++i)
            status = sr_step(&model, SR_RKMK4, x, u, NMPC_TASK_DT, x);
        if (status != SR_OK) {
            fprintf(stderr, "nmpc_loop: sample %ld: %s\n", k, sr_status_string(status));
            return 1;
        }
    }
    qsort(elapsed_us, NMPC_TASK_SAMPLES, sizeof elapsed_us[0], by_value);
    qsort(cpu_us, NMPC_TASK_SAMPLES, sizeof cpu_us[0], by_value);
    qsort(qp_iterations, NMPC_TASK_SAMPLES, sizeof qp_iterations[0], by_int);
    printf("samples %d p50_us %.1f p99_us %.1f max_us %.1f cpu_p50_us %.1f cpu_p99_us %.1f cpu_max_us %.1f "
           "qp_iterations_p50 %d p99 %d max %d cross_track_rms_m %.5f restarts %ld failures %ld\n",
           NMPC_TASK_SAMPLES, elapsed_us[NMPC_TASK_SAMPLES / 2], elapsed_us[(99 * NMPC_TASK_SAMPLES) / 100],
           elapsed_us[NMPC_TASK_SAMPLES - 1], cpu_us[NMPC_TASK_SAMPLES / 2], cpu_us[(99 * NMPC_TASK_SAMPLES) / 100],
           cpu_us[NMPC_TASK_SAMPLES - 1], qp_iterations[NMPC_TASK_SAMPLES / 2],
           qp_iterations[(99 * NMPC_TASK_SAMPLES) / 100], qp_iterations[NMPC_TASK_SAMPLES - 1],
           sqrt(sum2 / (double)(counted ? counted : 1)), memory.restarts, memory.failures);
    return 0;
}
