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

/* One line, assembled without printf in a buffer of semihosting.c, then
 * written with sh_write0. One buffer for the whole program: no pointer to
 * it to pass with every call. */
void sh_str(const char *text);
void sh_dec(uint32_t value);
void sh_hex64(uint64_t value);
/* Appends a newline, writes the line and empties it. */
void sh_flush(void);

#endif
