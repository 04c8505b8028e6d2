/*
 * A world that mpca_world_init builds in caller memory is a live world, even
 * when the allocator hands the caller the block a world from
 * mpca_world_create lived in before mpca_world_destroy freed it. Freed
 * blocks are reused all the time, so a C program meets this by chance.
 *
 * Prints "reuse: reached" when the allocator gave the freed block back (the
 * Rust side requires it, so the check cannot pass by not running), then
 * checks that the new world works.
 */
#include <stdio.h>
#include <stdlib.h>

#include "check.h"

#define TRIES 64

int main(void) {
    check_begin();
    check_context = "caller memory at a destroyed world's address";
    mpca_desc d;
    size_t bytes = 0;
    CHECK_OK(mpca_desc_defaults(&d, 2, 8, 8, 0));
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    mpca_world *gone = NULL;
    CHECK_OK(mpca_world_create(&d, &gone));
    CHECK_OK(mpca_world_destroy(gone));

    /* Blocks of the same size until the freed one comes back; glibc gives
     * it at once, ASan when run with quarantine_size_mb=0 and
     * thread_local_quarantine_size_kb=0 (c_abi.rs does). */
    void *held[TRIES];
    unsigned char *memory = NULL;
    unsigned n = 0;
    while (n < TRIES) {
        void *p = malloc(bytes);
        if (p == NULL) {
            break;
        }
        if (p == (void *)gone) {
            memory = p;
            break;
        }
        held[n++] = p;
    }
    while (n > 0) {
        free(held[--n]);
    }
    if (memory == NULL) {
        printf("reuse: not reached\n");
        return check_end();
    }
    printf("reuse: reached\n");

    mpca_world *w = NULL;
    CHECK_OK(mpca_world_init(&d, memory, bytes, &w));
    CHECK(w == gone); /* the same address: malloc's block is aligned enough */
    uint32_t pos[3] = {1, 1, 0};
    float v[3] = {0.5f, 0, 0};
    size_t count = 0;
    CHECK_OK(mpca_world_add_particle(w, pos, v));
    CHECK_OK(mpca_world_step(w, 3));
    CHECK_OK(mpca_world_particle_count(w, &count));
    CHECK(count == 1);
    CHECK_OK(mpca_world_deinit(w));
    free(memory);
    return check_end();
}
