/*
 * What every file of the scene programs needs: a library call checked,
 * memory that is there or an exit, and a monotonic clock.
 */
#ifndef MPCA_EXAMPLES_COMMON_H
#define MPCA_EXAMPLES_COMMON_H

#include <stddef.h>

#include "mpca.h"

/* Exits with the library's message when `status` is not MPCA_STATUS_OK. */
void mpca_check(mpca_status status, const char *what);

/* The library's world, created from `desc`, or exit with a message. */
mpca_world *world_create(const mpca_desc *desc);

/* realloc that exits when memory runs out; never returns NULL, even for
 * 0 bytes. */
void *xrealloc(void *p, size_t bytes);

/* Seconds on a monotonic clock. */
double now_s(void);

#endif /* MPCA_EXAMPLES_COMMON_H */
