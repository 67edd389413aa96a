/*
 * firmware_ekf_lqr.c -- a closed-loop firmware example on the robot's own sensors: sensor samples
 * in, the error-state EKF (sr_ekf_*), the LQR (sr_lqr_control) on its estimate, torques out; no
 * Python, no heap.
 *
 * The task comes from two headers on the include path, written by runtime/control/firmware.py
 * (`write_ekf_headers`): lqr_task.h (the LQR's schedule, the initial state, the constant target,
 * the controller's rate) and ekf_task.h (the filter's start, noise, IMU mount and gates).  On a
 * robot the samples come from the sensor drivers; here they come from stdin, one event a line,
 * in the order they reach the filter (times in s, numbers as %.17g prints them):
 *
 *   0 t                    a controller tick at t
 *   1 t g_x g_y g_z a_x a_y a_z   an IMU sample (gyroscope [rad/s], accelerometer [m/s^2])
 *   2 t theta_Y theta_P    an encoder sample [rad]
 *   3 t q_x q_y            a position fix [m], at its arrival
 *   4 t psi                a heading [rad]
 *
 * Every event first predicts the filter from its last time to t under the torques held since the
 * last tick; a tick then runs the LQR on the estimate and holds its torques until the next tick.
 * With the slope's feedforward in the task's LQR (lqr_task.h defines LQR_TASK_SLOPE_ESTIMATE_S), a
 * tick first updates the slope estimate on the filter's estimate and the torques held since the last
 * tick (sr_slope_update; weighted, sr_slope_weigh, when LQR_TASK_SLOPE_PRIOR > 0), then runs the law
 * with its offsets (sr_lqr_control_offsets), as the Python closed loop on sensors does
 * (lqr_task_law.h).
 * Output (stdout): CSV, a header line (as firmware_lqr.c's) then one row per tick: t, the 35 estimated state entries (spherical_robot.h's
 * order) and the torques u_Y, u_P, %.17g.  In the double build the rows equal, bit for bit, the
 * Python closed loop on the estimator of the same task fed the same samples
 * (runtime.control.closed_loop.simulate_on_sensors, tests/runtime/control/test_firmware_ekf.py).
 * Exit status 0 on success; on an error, a message on stderr and 1.
 * On an Armv7-M part (SysTick) also one line on stderr: the instructions of the filter's 200 Hz
 * samples (the prediction to the sample's time, the IMU and the encoder update; not the LQR, nor
 * fixes and headings), as SysTick counts them converted to instructions by a calibration loop of
 * known length; under QEMU with -icount shift=0 (one instruction per nanosecond of virtual time)
 * that is the exact count.
 */
#include <stdio.h>
#include <stdlib.h>

#include <ekf_task.h>
#include <lqr_task.h>
#include "sr_ekf.h"
#include "spherical_robot.h"
#include "lqr_task_law.h"

#define MAX_LINE 1024

#include "systick.h"

#ifdef HAVE_SYSTICK
#define MAX_SAMPLES 256   /* the samples counted (the recorded input has 200); a longer input's first ones */

/* The parts of a sample counted so far (1 prediction, 2 IMU, 4 encoders) and their ticks; a
 * sample with all three is kept. */
typedef struct sample_count {
    uint32_t ticks[MAX_SAMPLES], current;
    int parts, n;
} sample_count;

static void close_sample(sample_count *c)
{
    if (c->parts == 7 && c->n < MAX_SAMPLES) c->ticks[c->n++] = c->current;
    c->parts = 0;
    c->current = 0;
}

static void report(sample_count *c, double per_tick)
{
    double sum = 0;
    int k;
    close_sample(c);
    if (c->n == 0) {
        fprintf(stderr, "instructions per filter sample: no sample with a prediction, an IMU and an encoder update\n");
        return;
    }
    for (k = 0; k < c->n; ++k) sum += per_tick * (double)c->ticks[k];
    qsort(c->ticks, (size_t)c->n, sizeof c->ticks[0], by_ticks);
    fprintf(stderr,
            "instructions per filter sample (prediction, IMU and encoder updates), %d samples: mean %.0f, "
            "p50 %.0f, max %.0f (%.3g instructions per SysTick tick)\n",
            c->n, sum / c->n, per_tick * (double)c->ticks[c->n / 2], per_tick * (double)c->ticks[c->n - 1], per_tick);
}

static sample_count counts; /* 1 kB, not on the stack */

#ifdef LQR_TASK_SLOPE_ESTIMATE_S
/* The ticks of each controller tick's slope estimate and law (the first MAX_SAMPLES). */
typedef struct tick_count {
    uint32_t ticks[MAX_SAMPLES];
    int n;
} tick_count;

static tick_count law_counts;
#endif
#endif

/* The numbers after the kind and the time on a line of each kind. */
static const int WIDTH[5] = {0, SR_NIMU, 2, 2, 1};

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

static void print_row(double t, const sr_real x[SR_NX], const sr_real u[SR_NU])
{
    int i;
    printf("%.17g", t);
    for (i = 0; i < SR_NX; ++i) printf(",%.17g", (double)x[i]);
    printf(",%.17g,%.17g\n", (double)u[0], (double)u[1]);
}

/* One event line: its kind, time and numbers; 0 when it is not a whole event. */
static int parse(const char *line, int *kind, double *t, sr_real v[SR_NIMU])
{
    char *end;
    int i;
    long k = strtol(line, &end, 10);
    if (end == line || k < 0 || k > 4) return 0;
    *kind = (int)k;
    line = end;
    *t = strtod(line, &end);
    if (end == line) return 0;
    for (i = 0; i < WIDTH[*kind]; ++i) {
        line = end;
        v[i] = (sr_real)strtod(line, &end);
        if (end == line) return 0;
    }
    return 1;
}

int main(void)
{
    static const sr_real zero_bias[SR_NBIAS] = {0};
    const sr_lqr_target target = {LQR_TASK_SPEED, LQR_TASK_HEADING, 0, 0, 0};
    const sr_ekf_process process = {{EKF_TASK_TORQUE_PSD, EKF_TASK_TORQUE_PSD, EKF_TASK_TORQUE_PSD},
                                    EKF_TASK_GYRO_BIAS_RW, EKF_TASK_ACCEL_BIAS_RW};
    /* the law's memory and, with the slope's feedforward, its estimate (16 KB in double: static storage) */
    static lqr_task_law law;
    sr_model model;
    sr_ekf ekf;
    sr_real u[SR_NU] = {0, 0}, v[SR_NIMU];
    double t_now = 0.0, t;
    char line[MAX_LINE];
    long n = 0;
    int kind, status;
#ifdef HAVE_SYSTICK
    uint32_t start = 0;
    double per_tick;
    systick_start();
    per_tick = instructions_per_tick();
#define COUNT_FROM() (start = SYST_CVR)
#define COUNT_PART(part) (counts.current += ticks_since(start), counts.parts |= (part))
#else
#define COUNT_FROM() ((void)0)
#define COUNT_PART(part) ((void)0)
#endif

    status = sr_model_init(&model, LQR_TASK_PARAMS);
    if (status == SR_OK) status = lqr_task_law_init(&law);
    if (status == SR_OK) status = sr_ekf_init_diagonal(&ekf, &model, LQR_TASK_X0, zero_bias, EKF_TASK_SIGMA);
    for (kind = 0; kind < SR_EKF_NKINDS && status == SR_OK; ++kind)
        status = sr_ekf_set_recovery(&ekf, kind, EKF_TASK_RECOVER_AFTER[kind]);
    if (status != SR_OK) {
        fprintf(stderr, "firmware_ekf_lqr: setup failed: %s\n", sr_status_string(status));
        return 1;
    }
    print_header();
    while (fgets(line, sizeof line, stdin) != NULL) {
        ++n;
        if (!parse(line, &kind, &t, v)) {
            fprintf(stderr, "firmware_ekf_lqr: line %ld: not an event\n", n);
            return 1;
        }
        status = SR_OK;
        if (t > t_now) { /* the filter's time, as the Python loop's: predicted only forward */
#ifdef HAVE_SYSTICK
            close_sample(&counts);
#endif
            COUNT_FROM();
            status = sr_ekf_predict(&ekf, &model, EKF_TASK_METHOD, u, (sr_real)(t - t_now), &process);
            COUNT_PART(1);
            t_now = t;
        }
        if (status == SR_OK) switch (kind) {
        case 0: {
#if defined(HAVE_SYSTICK) && defined(LQR_TASK_SLOPE_ESTIMATE_S)
            const uint32_t law_start = SYST_CVR;
#endif
            status = lqr_task_law_sample(&law, &model, ekf.x, &target, u);
#if defined(HAVE_SYSTICK) && defined(LQR_TASK_SLOPE_ESTIMATE_S)
            if (law_counts.n < MAX_SAMPLES) law_counts.ticks[law_counts.n++] = ticks_since(law_start);
#endif
            if (status == SR_OK) print_row(t, ekf.x, u);
            break;
        }
        case 1:
            COUNT_FROM();
            /* The torque disturbance held over EKF_TASK_TORQUE_HOLD (> 0) read by the accelerometer, as the
             * closed loop's filter reads it; 0: its share in the accelerometer's sigma. */
            status = EKF_TASK_TORQUE_HOLD > 0
                ? sr_ekf_update_imu_held(&ekf, &model, v, u, EKF_TASK_BODY, EKF_TASK_MOUNT, EKF_TASK_IMU_SIGMA,
                                         &process, EKF_TASK_TORQUE_HOLD, EKF_TASK_GATE_IMU)
                : sr_ekf_update_imu_axes(&ekf, &model, v, u, EKF_TASK_BODY, EKF_TASK_MOUNT, EKF_TASK_IMU_SIGMA,
                                         EKF_TASK_GATE_IMU);
            COUNT_PART(2);
            break;
        case 2:
            COUNT_FROM();
            status = sr_ekf_update_encoders(&ekf, &model, v, EKF_TASK_ENCODER, EKF_TASK_GATE_ENCODERS);
            COUNT_PART(4);
            break;
        case 3:
            status = sr_ekf_update_position(&ekf, &model, v, EKF_TASK_POSITION, EKF_TASK_GATE_POSITION);
            break;
        default:
            status = sr_ekf_update_heading(&ekf, &model, v[0], EKF_TASK_BODY, EKF_TASK_MOUNT, EKF_TASK_HEADING,
                                           EKF_TASK_GATE_HEADING);
            break;
        }
        if (status != SR_OK) {
            fprintf(stderr, "firmware_ekf_lqr: line %ld failed: %s\n", n, sr_status_string(status));
            return 1;
        }
    }
#ifdef HAVE_SYSTICK
    report(&counts, per_tick);
#ifdef LQR_TASK_SLOPE_ESTIMATE_S
    report_first_and_rest("tick", "the slope estimate and the law", law_counts.ticks, law_counts.n, per_tick);
#endif
#endif
    return 0;
}
