/*
 * lie_euler_firmware.c -- the smallest useful firmware: set the model up once, then per control
 * tick one acceleration (sr_accel, e.g. for a controller or an observer) and one Lie-Euler step.
 * Linked with -ffunction-sections -fdata-sections -Wl,--gc-sections it is what a Lie-Euler-only
 * product carries; its `size` is the figure in docs/embedding.md.
 *
 * It also measures, under QEMU, the stack each entry point really uses (libm included, which
 * the static call-graph bound of size_report.py leaves out): paint the free stack below main's
 * frame with a pattern, make one call, find the deepest word that changed.  Output: one line
 * per entry point, "stack <name> <bytes>", then "ticks <n> q <x> <y> <z>" (a sanity check that
 * the steps ran).  Output goes through write() with a small integer formatter, not printf
 * (whose newlib version links its double conversions even for integer formats), so that the image
 * holds the library, libm and the start-up code only: cross_test.sh checks that it links no
 * software double routine (__aeabi_d*).  Exit status 0, or 1 on a kernel error.
 */
#include <stdint.h>
#include <string.h>
#include <unistd.h>

#include "spherical_robot.h"

#define PAINT_BYTES 8192u       /* painted below main's frame: far more than any entry point uses */
#define PAINT_WORD 0xA5C3E10Fu

/* runtime.Params.paper_simulation() (SI): the paper's twelve parameters, each value at its index
 * SR_PAPER_<name>; sr_paper_params turns them into the robot's parameters (SR_P_*). */
static const sr_real PAPER[SR_NPAPER] = {
    [SR_PAPER_r] = SR_C(0.3), [SR_PAPER_m_S] = SR_C(2.0), [SR_PAPER_k_S] = SR_C(0.16), [SR_PAPER_b] = SR_C(0.2),
    [SR_PAPER_h] = SR_C(0.5), [SR_PAPER_m_b] = SR_C(2.0), [SR_PAPER_m_h] = SR_C(5.0), [SR_PAPER_k_Y] = SR_C(0.04),
    [SR_PAPER_l] = SR_C(0.2), [SR_PAPER_m_P] = SR_C(1.0), [SR_PAPER_k_P] = SR_C(0.10), [SR_PAPER_g] = SR_C(9.81),
};

static uintptr_t stack_pointer(void)
{
    uintptr_t sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    return sp;
}

/* Fill [top - PAINT_BYTES, top) with the pattern; top is main's stack pointer, so everything
 * painted is free stack below main's frame.  noinline: this frame lies inside the painted range
 * only while painting. */
static __attribute__((noinline)) void paint_stack(uintptr_t top)
{
    volatile uint32_t *p = (volatile uint32_t *)(top - PAINT_BYTES);
    while ((uintptr_t)p < top - 64u) *p++ = PAINT_WORD; /* keep clear of our own frame */
}

/* Bytes below top that a call wrote: from the bottom of the painted range up to the first
 * word that no longer holds the pattern. */
static __attribute__((noinline)) unsigned long stack_used(uintptr_t top)
{
    const volatile uint32_t *p = (const volatile uint32_t *)(top - PAINT_BYTES);
    while ((uintptr_t)p < top && *p == PAINT_WORD) ++p;
    return (unsigned long)(top - (uintptr_t)p);
}

static void put(const char *text)
{
    (void)write(1, text, strlen(text));
}

static void put_long(long value)
{
    char digits[24], *p = digits + sizeof digits;
    unsigned long magnitude = value < 0 ? 0ul - (unsigned long)value : (unsigned long)value;
    *--p = '\0';
    do *--p = (char)('0' + magnitude % 10u); while ((magnitude /= 10u) != 0);
    if (value < 0) *--p = '-';
    put(p);
}

static void report(const char *name, unsigned long bytes)
{
    put("stack ");
    put(name);
    put(" ");
    put_long((long)bytes);
    put("\n");
}

int main(void)
{
    static sr_model model; /* static: keep main's frame small and the measured calls honest */
    static sr_real x[SR_NX], a[SR_NV], params[SR_NPARAM];
    sr_real u[SR_NU] = {SR_C(0.1), SR_C(0.0)};
    const uintptr_t top = stack_pointer();
    int status, n, i;

    for (i = 0; i < 3; ++i) /* R_S = R_Y = R_P = I (row-major 3x3 blocks) */
        x[SR_X_R_S + 4 * i] = x[SR_X_R_Y + 4 * i] = x[SR_X_R_P + 4 * i] = 1;
    x[SR_X_q + 2] = PAPER[SR_PAPER_r]; /* q = (0, 0, r) */

    paint_stack(top);
    status = sr_paper_params(PAPER, params);
    if (status == SR_OK) status = sr_model_init(&model, params);
    report("sr_model_init", stack_used(top));

    paint_stack(top);
    if (status == SR_OK) status = sr_check_state(&model, x);
    report("sr_check_state", stack_used(top));

    paint_stack(top);
    if (status == SR_OK) status = sr_accel(&model, x, u, a);
    report("sr_accel", stack_used(top));

    paint_stack(top);
    if (status == SR_OK) status = sr_step_lie_euler(&model, x, u, SR_C(0.01), x);
    report("sr_step_lie_euler", stack_used(top));

    /* The control loop proper: one second at 100 Hz. */
    for (n = 1; n < 100 && status == SR_OK; ++n) {
        status = sr_accel(&model, x, u, a);
        if (status == SR_OK) status = sr_step_lie_euler(&model, x, u, SR_C(0.01), x);
    }
    if (status != SR_OK) {
        put("lie_euler_firmware: ");
        put(sr_status_string(status));
        put("\n");
        return 1;
    }
    /* q in micrometres, as integers. */
    put("ticks ");
    put_long(n);
    put(" q_um");
    for (i = 0; i < 3; ++i) {
        put(" ");
        put_long((long)(x[SR_X_q + i] * SR_C(1e6)));
    }
    put("\n");
    return 0;
}
