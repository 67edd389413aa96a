/*
 * startup.c -- the smallest bare-metal start for a Cortex-M4F/M7 under QEMU (mps2-an386,
 * mps2-an500) or on a board with the same memory layout: vector table, reset handler, fault
 * handler.  Output goes through newlib's semihosting (librdimon: link with
 * --specs=rdimon.specs -nostartfiles), so QEMU prints it on its stdout.
 *
 * Reset: enable the FPU first (CPACR, before any floating-point instruction can run), copy
 * .data from its load address, zero .bss, open the semihosting handles, run main and pass its
 * status to exit() (newlib hands it to QEMU, whose exit status it becomes).
 * The symbols _sidata, _sdata, _edata, _sbss, _ebss and _estack come from the linker script
 * (mps2-common.ld).
 */
#include <stdint.h>
#include <stdlib.h>
#include <unistd.h>

extern uint32_t _sidata[], _sdata[], _edata[], _sbss[], _ebss[], _estack[];
extern void initialise_monitor_handles(void); /* librdimon */
int main(void);

void reset_handler(void);
void fault_handler(void);
void _init(void);
void _fini(void);

/* -nostartfiles leaves out crti.o, whose _init/_fini newlib's exit() calls; nothing to do here. */
void _init(void) {}
void _fini(void) {}

/* CPACR (Coprocessor Access Control Register): bits 20-23 give full access to CP10 and CP11,
 * the FPU.  Until they are set every FPU instruction raises a UsageFault. */
#define CPACR (*(volatile uint32_t *)0xE000ED88u)

__attribute__((noreturn)) void reset_handler(void)
{
    uint32_t *src, *dst;
    CPACR |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory"); /* the new access rights apply from here */
    for (src = _sidata, dst = _sdata; dst < _edata;) *dst++ = *src++;
    for (dst = _sbss; dst < _ebss;) *dst++ = 0;
    initialise_monitor_handles();
    exit(main());
}

/* Any fault (hard, memory, bus, usage) or unexpected interrupt: say so and stop with status 70,
 * so that a crash under QEMU is a failed run rather than a hang. */
__attribute__((noreturn)) void fault_handler(void)
{
    static const char message[] = "startup: fault or unexpected interrupt\n";
    (void)write(2, message, sizeof message - 1);
    _exit(70);
}

/* The 16 system entries of the Armv7-M vector table; no peripheral interrupt is used. */
__attribute__((section(".isr_vector"), used)) static void (*const vector_table[16])(void) = {
    (void (*)(void))(uintptr_t)_estack, /* initial main stack pointer */
    reset_handler,
    fault_handler, /* NMI */
    fault_handler, /* HardFault */
    fault_handler, /* MemManage */
    fault_handler, /* BusFault */
    fault_handler, /* UsageFault */
    0, 0, 0, 0,    /* reserved */
    fault_handler, /* SVCall */
    fault_handler, /* DebugMonitor */
    0,             /* reserved */
    fault_handler, /* PendSV */
    fault_handler, /* SysTick */
};
