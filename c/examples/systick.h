/*
 * systick.h -- instruction counts on an Armv7-M (Cortex-M4F, M7) for the firmware examples: SysTick
 * read around a piece of code, calibrated against a loop of known length.  Under QEMU with
 * `-icount shift=0` one tick is a fixed number of instructions, so ticks x instructions_per_tick()
 * is the instructions executed.  Defines HAVE_SYSTICK on those parts only; elsewhere it is empty.
 */
#ifndef SR_EXAMPLES_SYSTICK_H
#define SR_EXAMPLES_SYSTICK_H

#if defined(__ARM_ARCH_7M__) || defined(__ARM_ARCH_7EM__)
#define HAVE_SYSTICK 1
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

/* SysTick (Armv7-M): a 24-bit down-counter of the processor clock, free-running, no interrupt. */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define SYSTICK_MASK 0xFFFFFFu

static inline void systick_start(void)
{
    SYST_RVR = SYSTICK_MASK;
    SYST_CVR = 0;
    SYST_CSR = 5u; /* enable, processor clock */
}

static inline uint32_t ticks_since(uint32_t start) { return (start - SYST_CVR) & SYSTICK_MASK; }

/* Instructions per SysTick tick: a loop of 2^20 iterations of two instructions (subs, bne). */
static inline double instructions_per_tick(void)
{
    uint32_t n = 1u << 20, start = SYST_CVR;
    __asm__ volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(n)::"cc");
    return 2.0 * (double)(1u << 20) / (double)ticks_since(start);
}

/* qsort's order of tick counts, ascending. */
static inline int by_ticks(const void *a, const void *b)
{
    const uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

/* One line on stderr, "instructions per <unit> (<what>): first F; the other N: p50 P, max M", for the
 * tick counts of n samples (the first, a cold start, apart; ticks[1..n-1] sorted in place). */
static inline void report_first_and_rest(const char *unit, const char *what, uint32_t *ticks, long n, double per_tick)
{
    if (n < 2) return;
    qsort(ticks + 1, (size_t)(n - 1), sizeof ticks[0], by_ticks);
    fprintf(stderr, "instructions per %s (%s): first %.0f; the other %ld: p50 %.0f, max %.0f\n", unit, what,
            per_tick * (double)ticks[0], n - 1, per_tick * (double)ticks[n / 2], per_tick * (double)ticks[n - 1]);
}
#endif

#endif
