/*
 * What startup.c offers the program: the stack's size and high-water mark,
 * and the two markers the instruction count (insn_count.c) is taken
 * between.
 */
#ifndef FIRMWARE_STARTUP_H
#define FIRMWARE_STARTUP_H

#include <stddef.h>

typedef struct stack_use {
    size_t size;    /* bytes between the end of .bss and the top of RAM */
    size_t used;    /* the deepest the stack has reached since reset */
    int overflowed; /* the pattern is gone from the lowest word: it may have run past */
} stack_use;

/* Reads the high-water mark the reset handler's fill pattern left. */
stack_use stack_measure(void);

/* Empty calls bracketing the counted code. */
void mark_begin(void);
void mark_end(void);

#endif
