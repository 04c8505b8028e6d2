/*
 * ARM semihosting: the firmware's only way out. A BKPT 0xab (the Thumb
 * semihosting trap of M-profile cores) asks the debugger, here QEMU with
 * -semihosting-config enable=on, to do the work: r0 names the request, r1
 * points at its argument.
 */
#ifndef FIRMWARE_SEMIHOSTING_H
#define FIRMWARE_SEMIHOSTING_H

#include <stddef.h>
#include <stdint.h>

/* Writes a NUL-terminated string to the debugger's console (SYS_WRITE0). */
void sh_write0(const char *text);

/* Ends the run (SYS_EXIT): QEMU exits with status 0 when `status` is 0,
 * else with 1 (32-bit semihosting passes a reason, not a number). */
_Noreturn void sh_exit(int status);

/* A line assembled without printf, then written with sh_write0. */
typedef struct sh_line {
    char text[96];
    size_t len;
} sh_line;

void sh_str(sh_line *line, const char *text);
void sh_dec(sh_line *line, uint32_t value);
void sh_hex64(sh_line *line, uint64_t value);
/* Appends a newline, writes the line and empties it. */
void sh_flush(sh_line *line);

#endif
