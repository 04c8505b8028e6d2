/*
 * What a panic inside the library does to a C program. mpca_debug_panic
 * (built with the feature panic-test) panics on purpose. c_abi.rs builds
 * this program twice:
 *
 * - against the library built with catch-panics: the call returns
 *   MPCA_STATUS_PANIC, twice, no world changed, and the library goes on
 *   stepping worlds; the program ends normally;
 * - against the shipped library (libmpca.so, without catch-panics): the
 *   call does not return. The library writes one line on stderr and
 *   aborts; the Rust side checks the line, SIGABRT, and that nothing after
 *   the call was printed.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* A 2D world with a few particles, stepped. */
static mpca_world *make_world(void) {
    mpca_desc d;
    mpca_world *w = NULL;
    CHECK_OK(mpca_desc_defaults(&d, 2, 16, 16, 0));
    d.seed = 5;
    CHECK_OK(mpca_world_create(&d, &w));
    for (uint32_t i = 0; i < 8; i++) {
        uint32_t pos[3] = {i * 2, i, 0};
        float v[3] = {0.3f, -0.2f, 0.0f};
        CHECK_OK(mpca_world_add_particle(w, pos, v));
    }
    CHECK_OK(mpca_world_step(w, 3));
    return w;
}

static uint64_t world_hash(const mpca_world *w) {
    uint64_t h = 0;
    CHECK_OK(mpca_world_hash(w, &h));
    return h;
}

int main(void) {
    check_begin();
    check_context = "panic";
    mpca_world *w = make_world();
    uint64_t before = world_hash(w);
    printf("before panic: world hash %016llx\n", (unsigned long long)before);
    /* The shipped library aborts inside the call: what is buffered must be
     * out first. */
    fflush(stdout);

    mpca_status st = TRACE(mpca_debug_panic());
    CHECK(st == MPCA_STATUS_PANIC);
    printf("panic: mpca_debug_panic returned %u and the program goes on\n", (unsigned)st);
    CHECK(world_hash(w) == before);
    st = TRACE(mpca_debug_panic());
    CHECK(st == MPCA_STATUS_PANIC);
    CHECK(world_hash(w) == before);
    CHECK_OK(mpca_world_step(w, 1));
    CHECK(world_hash(w) != before);
    printf("after panic: the library still steps worlds\n");
    CHECK_OK(mpca_world_destroy(w));
    return check_end();
}
