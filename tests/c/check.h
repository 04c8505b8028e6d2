/*
 * Shared by the C programs of the C ABI tests (built and run by
 * tests/tests/c_abi.rs): non-fatal checks, the table of every function the
 * header declares, and a record of which of them a program called.
 *
 * A program calls check_begin() first and returns check_end() from main;
 * its stdout is parsed by the Rust side, line by line.
 */
#ifndef MPCA_TEST_CHECK_H
#define MPCA_TEST_CHECK_H

#include <stdint.h>

#include "mpca.h"

/* _Static_assert and _Alignof are C11; __extension__ lets GCC and Clang
 * accept them in these -std=c99 -Wpedantic -Werror builds. */
#define STATIC_ASSERT(cond, msg) __extension__ _Static_assert(cond, msg)
#define ALIGNOF(type) (__extension__ _Alignof(type))

/* Every library call of the tests goes through TRACE, which marks the
 * function as called (by the name that starts `call`) and yields the call's
 * value. */
#define TRACE(call) (check_called(#call), (call))

/* A check that does not stop the program: a failure is printed with its line
 * and makes check_end() return 1, and the program goes on, so one run shows
 * every failure. */
#define CHECK(cond) check_true((cond) != 0, #cond, __FILE__, __LINE__)

/* `call` must succeed. */
#define CHECK_OK(call) check_status(TRACE(call), MPCA_STATUS_OK, #call, __FILE__, __LINE__)

/* Prints "sanitizer: address" or "sanitizer: none", and every entry of the
 * symbol table as "symbol: NAME" (after checking that its address is not
 * NULL and differs from every other). */
void check_begin(void);

/* Prints "called: NAME" for every function this program called and the
 * number of checks; returns the exit status: 0, or 1 if any check failed. */
int check_end(void);

/* Marks the function whose name starts `call_text` as called. */
void check_called(const char *call_text);

/* Shown with every failure until changed: which case group is running. */
extern const char *check_context;

void check_true(int ok, const char *what, const char *file, int line);
void check_status(mpca_status got, mpca_status want, const char *what, const char *file, int line);

/* The number of failed checks so far. */
unsigned check_failures(void);

/* A small deterministic generator (a 64-bit LCG, its high bits) for placing
 * particles: the next 31-bit value, and a float uniform in [0, 1). */
uint32_t check_random(uint64_t *state);
float check_unit(uint64_t *state);

#endif /* MPCA_TEST_CHECK_H */
