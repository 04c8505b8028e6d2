/*
 * What every file of the scene programs needs: the library's status
 * checked, memory that is there or an exit, and a clock.
 */
#define _POSIX_C_SOURCE 200809L

#include "common.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

/* ---- errors, memory, time --------------------------------------------- */

void mpca_check(mpca_status status, const char *what) {
    if (status != MPCA_STATUS_OK) {
        fprintf(stderr, "mpca: %s: %s (status %u)\n", what, mpca_status_message(status), (unsigned)status);
        exit(1);
    }
}

mpca_world *world_create(const mpca_desc *desc) {
    mpca_world *w = NULL;
    mpca_check(mpca_world_create(desc, &w), "mpca_world_create");
    return w;
}

void *xrealloc(void *p, size_t bytes) {
    void *q = realloc(p, bytes ? bytes : 1);
    if (!q) {
        fprintf(stderr, "out of memory (%zu bytes)\n", bytes);
        exit(1);
    }
    return q;
}

double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
