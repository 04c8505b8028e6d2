#include "semihosting.h"

enum {
    SYS_WRITE0 = 0x04,
    SYS_EXIT = 0x18,
    /* Reasons for SYS_EXIT; on 32-bit Arm r1 holds the reason itself. */
    ADP_STOPPED_RUN_TIME_ERROR = 0x20023,
    ADP_STOPPED_APPLICATION_EXIT = 0x20026,
};

static uintptr_t semihost(uintptr_t request, const void *argument) {
    register uintptr_t r0 __asm__("r0") = request;
    register const void *r1 __asm__("r1") = argument;
    /* "memory": the debugger reads what r1 points at. */
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void sh_write0(const char *text) {
    semihost(SYS_WRITE0, text);
}

_Noreturn void sh_exit(int status) {
    semihost(SYS_EXIT, (const void *)(uintptr_t)(status == 0 ? ADP_STOPPED_APPLICATION_EXIT : ADP_STOPPED_RUN_TIME_ERROR));
    for (;;) {
        /* Only reached without a debugger: nothing left to do. */
    }
}

/* The line being assembled. */
static struct {
    char text[96];
    size_t len;
} line;

static void put(char c) {
    /* One byte stays free for the NUL; a longer line is cut, not overrun. */
    if (line.len + 1 < sizeof line.text) line.text[line.len++] = c;
}

void sh_str(const char *text) {
    while (*text) put(*text++);
}

void sh_dec(uint32_t value) {
    /* Digit by digit from the highest power of ten, each by subtraction:
     * no division, which the Cortex-M0 has no instruction for (it would
     * link a division routine for this alone). */
    static const uint32_t powers[] = {1000000000u, 100000000u, 10000000u, 1000000u, 100000u, 10000u, 1000u, 100u, 10u, 1u};
    int started = 0;
    for (size_t i = 0; i < sizeof powers / sizeof powers[0]; i++) {
        char digit = '0';
        while (value >= powers[i]) {
            value -= powers[i];
            digit++;
        }
        /* Leading zeros left out; 0 itself is one digit. */
        started |= digit != '0' || powers[i] == 1;
        if (started) put(digit);
    }
}

void sh_hex64(uint64_t value) {
    for (int shift = 60; shift >= 0; shift -= 4) put("0123456789abcdef"[(value >> shift) & 0xf]);
}

void sh_flush(void) {
    put('\n');
    line.text[line.len] = '\0';
    sh_write0(line.text);
    line.len = 0;
}
