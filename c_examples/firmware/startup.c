/*
 * Reset for Cortex-M0 and M4F: the vector table, and a reset handler that
 * fills the stack with a pattern (to measure its high-water mark), enables
 * the FPU where there is one, copies .data from flash, zeroes .bss, runs
 * main and reports its result to QEMU over semihosting. The symbols come
 * from sections.ld.
 */
#include <stdint.h>

#include "semihosting.h"
#include "startup.h"

extern uint32_t __data_load[], __data_start[], __data_end[];
extern uint32_t __bss_start[], __bss_end[];
extern uint32_t __stack_limit[], __stack_top[];

int main(void);
_Noreturn void reset_handler(void);
_Noreturn void fault_handler(void);

/* A word the program is unlikely to leave on the stack. */
#define STACK_PATTERN 0xdeadc0deu

/* The core's exceptions only; this firmware takes no interrupts. Entry 0
 * is the initial stack pointer, the rest handlers (M0 and M4: 16 words). */
typedef struct vector_table {
    const uint32_t *initial_sp;
    void (*handler[15])(void);
} vector_table;

__attribute__((section(".vectors"), used)) static const vector_table vectors = {
    .initial_sp = __stack_top,
    .handler = {
        reset_handler,
        fault_handler, /* NMI */
        fault_handler, /* HardFault: everything else escalates to it */
        fault_handler, /* MemManage (M4) */
        fault_handler, /* BusFault (M4) */
        fault_handler, /* UsageFault (M4): e.g. an FPU instruction with the FPU off */
    },
};

_Noreturn void fault_handler(void) {
    sh_write0("firmware: fault\n");
    sh_exit(1);
}

_Noreturn void reset_handler(void) {
#if defined(__ARM_FP)
    /* CPACR: full access to coprocessors 10 and 11 (the FPU), before any
     * floating-point instruction runs (hard-float code uses it freely). */
    volatile uint32_t *const cpacr = (volatile uint32_t *)0xe000ed88u;
    *cpacr |= 0xfu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
    /* Nothing below the stack pointer is live (AAPCS has no red zone), so
     * every word from the stack's limit up to it can take the pattern. */
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (uint32_t *p = __stack_limit; p < sp; p++) *p = STACK_PATTERN;

    for (uint32_t *src = __data_load, *dst = __data_start; dst < __data_end;) *dst++ = *src++;
    for (uint32_t *p = __bss_start; p < __bss_end; p++) *p = 0;

    sh_exit(main());
}

stack_use stack_measure(void) {
    const uint32_t *p = __stack_limit;
    while (p < __stack_top && *p == STACK_PATTERN) p++;
    stack_use use = {
        .size = (size_t)((const char *)__stack_top - (const char *)__stack_limit),
        .used = (size_t)((const char *)__stack_top - (const char *)p),
        .overflowed = __stack_limit[0] != STACK_PATTERN,
    };
    return use;
}

/* Not inlined, and not removable (the asm has an effect as far as the
 * compiler knows), so each call reaches its own address. */
__attribute__((noinline)) void mark_begin(void) {
    __asm__ volatile("" ::: "memory");
}

__attribute__((noinline)) void mark_end(void) {
    __asm__ volatile("" ::: "memory");
}
