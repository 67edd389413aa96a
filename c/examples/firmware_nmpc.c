/*
 * firmware_nmpc.c -- a closed-loop firmware example with the NMPC (sr_nmpc_step) at 20 Hz on a
 * circle, driving the simulated robot; no Python, no heap.  Run on the host and, in
 * `make -C c cross-test`, on the emulated Cortex-M7 (double) and Cortex-M4F (float).
 *
 * The design and the task come from generated/nmpc_task.h, written by `make generate`
 * (python -m runtime nmpc-c --header --horizon 20 --node-periods 3): an `sr_nmpc` initializer
 * designed for the circle task's robot as the controller kind nmpc-c builds it, on 20 nodes of 3
 * periods (the tasks' 3 s horizon in nodes that keep every warm-started sample within 5 million
 * instructions on the Cortex-M; the tasks' 30 nodes of 2 periods take up to 8.4 million), the
 * initial state, the circle (centre, radius), dt and the rates.  Every controller sample finds the nearest point of the circle, computes the
 * torques and holds them for NMPC_TASK_STEPS_PER_SAMPLE plant steps (sr_step, RKMK4).  The run is
 * NMPC_FIRMWARE_SAMPLES samples (default 60: 3 s, a cold start and the warm-started samples after it).
 *
 * Output (stdout): CSV as c/examples/firmware_lqr.c's: a header line, then one row per plant step,
 * t, the 35 state entries and the torques held from that row on (%.17g).  On a Cortex-M (an
 * Armv7-M with SysTick), also one line on stderr: the instructions each sr_nmpc_step took, as
 * SysTick counts them converted to instructions by a calibration loop of known length; under QEMU
 * with -icount shift=0 (one instruction per nanosecond of virtual time) that is the exact count.
 * Exit status 0 on success; on an error, a message on stderr and 1.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* -DNMPC_TASK_FROM_INCLUDE_PATH -I<dir>: another task's header from <dir> (through c/Makefile's
 * CPPFLAGS, which come before the library's include directories). */
#ifdef NMPC_TASK_FROM_INCLUDE_PATH
#include <nmpc_task.h>
#else
#include "nmpc_task.h"
#endif
#include "sr_nmpc.h"

#ifndef NMPC_FIRMWARE_SAMPLES
#define NMPC_FIRMWARE_SAMPLES 60
#endif
#define PER NMPC_TASK_STEPS_PER_SAMPLE
#ifdef SR_USE_FLOAT
#define SQRT sqrtf
#else
#define SQRT sqrt
#endif

static sr_nmpc_memory memory; /* the controller's whole workspace, static: no heap, not on the stack */

#include "systick.h"

#ifdef HAVE_SYSTICK
static uint32_t sample_ticks[NMPC_FIRMWARE_SAMPLES];
#endif

static void print_header(void)
{
    static const char *const blocks[] = {"RS", "RY", "RP"};
    int b, i, j;
    printf("t");
    for (b = 0; b < 3; ++b)
        for (i = 0; i < 3; ++i)
            for (j = 0; j < 3; ++j) printf(",%s_%d%d", blocks[b], i, j);
    printf(",q_x,q_y,q_z,w_Sx,w_Sy,w_Sz,w_Y,w_P,u_Y,u_P\n");
}

static void print_row(long n, const sr_real x[SR_NX], const sr_real u[SR_NU])
{
    int i;
    printf("%.17g", (double)n * NMPC_TASK_DT_SECONDS); /* the same times in both builds */
    for (i = 0; i < SR_NX; ++i) printf(",%.17g", (double)x[i]);
    printf(",%.17g,%.17g\n", (double)u[0], (double)u[1]);
}

int main(void)
{
    sr_model model;
    sr_nmpc_target target = {0, 0, 0, 0, 1, NULL};
    sr_real x[SR_NX], u[SR_NU];
    const sr_real cx = (sr_real)NMPC_TASK_CENTRE[0], cy = (sr_real)NMPC_TASK_CENTRE[1];
    const sr_real half_pi = SR_C(1.5707963267948966);
    long k;
    int i, status = sr_model_init(&model, NMPC_TASK_PARAMS);
#ifdef HAVE_SYSTICK
    double per_tick;
    systick_start();
    per_tick = instructions_per_tick();
#endif
    if (status == SR_OK) status = sr_nmpc_check(&NMPC_DESIGN);
    if (status == SR_OK) status = sr_nmpc_reset(&memory);
    if (status != SR_OK) {
        fprintf(stderr, "firmware_nmpc: %s\n", sr_status_string(status));
        return 1;
    }
    for (i = 0; i < SR_NX; ++i) x[i] = NMPC_TASK_X0[i];
    target.speed = NMPC_TASK_SPEED;
    target.curvature = (sr_real)(1 / NMPC_TASK_RADIUS);
    print_header();
    for (k = 0; k < NMPC_FIRMWARE_SAMPLES; ++k) {
        /* The circle is counter-clockwise: its tangent is the radius turned by +90 degrees. */
        const sr_real dx = x[SR_X_q] - cx, dy = x[SR_X_q + 1] - cy;
#ifdef HAVE_SYSTICK
        uint32_t start;
#endif
        /* The library's atan2, not libm's: the double build then matches its host build bit for bit. */
        sr_real bearing;
        if (sr_atan2(dy, dx, &bearing) != SR_OK) return 1;
        target.heading = bearing + half_pi;
        target.cross_track = (sr_real)NMPC_TASK_RADIUS - SQRT(dx * dx + dy * dy);
#ifdef HAVE_SYSTICK
        start = SYST_CVR;
#endif
        status = sr_nmpc_step(&NMPC_DESIGN, &memory, &model, x, &target, u);
#ifdef HAVE_SYSTICK
        sample_ticks[k] = ticks_since(start);
#endif
        if (status != SR_OK) {
            fprintf(stderr, "firmware_nmpc: sample %ld: %s\n", k, sr_status_string(status));
            return 1;
        }
        print_row(k * PER, x, u);
        for (i = 0; i < PER; ++i) {
            status = sr_step(&model, SR_RKMK4, x, u, NMPC_TASK_DT, x);
            if (status != SR_OK) {
                fprintf(stderr, "firmware_nmpc: step %ld: %s\n", k * PER + i, sr_status_string(status));
                return 1;
            }
            if (i + 1 < PER) print_row(k * PER + i + 1, x, u);
        }
    }
    print_row((long)NMPC_FIRMWARE_SAMPLES * PER, x, u);
#ifdef HAVE_SYSTICK
    {
        double first = per_tick * (double)sample_ticks[0], sum = 0;
        for (k = 1; k < NMPC_FIRMWARE_SAMPLES; ++k) sum += per_tick * (double)sample_ticks[k];
        qsort(sample_ticks + 1, NMPC_FIRMWARE_SAMPLES - 1, sizeof sample_ticks[0], by_ticks);
        fprintf(stderr,
                "instructions per sample: first (cold start) %.0f; the other %d: mean %.0f, p50 %.0f, max %.0f "
                "(%.3g instructions per SysTick tick; restarts %ld, failures %ld)\n",
                first, NMPC_FIRMWARE_SAMPLES - 1, sum / (NMPC_FIRMWARE_SAMPLES - 1),
                per_tick * (double)sample_ticks[NMPC_FIRMWARE_SAMPLES / 2],
                per_tick * (double)sample_ticks[NMPC_FIRMWARE_SAMPLES - 1], per_tick, memory.restarts,
                memory.failures);
    }
#endif
    return 0;
}
