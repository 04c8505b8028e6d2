/*
 * 4.3 smoke at 64 x 64 on a microcontroller (issue 12): the world in a
 * static array (mpca_world_init, no allocator), 120 steps, then its hash,
 * the world's size and the stack's high-water mark over semihosting.
 * scripts/firmware.sh runs it under QEMU on a Cortex-M0 and a Cortex-M4F
 * and checks the hash against the host's (tests/src/bin/firmware_hash.rs,
 * the same scene as tests/src/scenes.rs `smoke_64`).
 *
 * The scene is c_examples/smoke.c at --size 64: a wall below, open above
 * and at the sides; one particle a step rising from cells 30..34 of the
 * bottom row; a static Rankine vortex at (32, 36), core 5, circulation 1.
 */
#include <stdalign.h>
#include <stdint.h>

#include "mpca.h"
#include "semihosting.h"
#include "startup.h"

#define SIZE 64
#define STEPS 120

/* What mpca_world_bytes asks for this scene on 32-bit Arm (alignment slack
 * included), with a little room; main checks it, and names the size it
 * needs should a change of the library make it short. */
#define WORLD_BYTES 9984

static alignas(8) uint8_t world_memory[WORLD_BYTES];

/* Appends `text`, then `value` in decimal: the pair every number printed
 * comes in, one call each (not inlined: that is the point). */
__attribute__((noinline)) static void text_dec(const char *text, uint32_t value) {
    sh_str(text);
    sh_dec(value);
}

/* Prints which call failed and its status number (names in mpca.h;
 * mpca_status_message would bring every message into flash). */
static int failed(const char *call, mpca_status status) {
    sh_str("firmware: ");
    sh_str(call);
    text_dec(" returned status ", (uint32_t)status);
    sh_flush();
    return 1;
}

#define CHECK(call)                                \
    do {                                           \
        mpca_status status_ = (call);              \
        if (status_ != MPCA_STATUS_OK) return failed(#call, status_); \
    } while (0)

int main(void) {
    mpca_desc d;
    CHECK(mpca_desc_defaults(&d, 2, SIZE, SIZE, 0));
    d.drift = MPCA_DRIFT_PAPER; /* the paper's rule, as printed */
    d.boundary[0][0] = d.boundary[0][1] = MPCA_BOUNDARY_OPEN;
    d.boundary[1][0] = MPCA_BOUNDARY_WALL; /* the ground */
    d.boundary[1][1] = MPCA_BOUNDARY_OPEN;
    d.restitution = 1.0f;
    d.forces = MPCA_FORCE_VORTEX;
    d.vortex_centre[0] = 32.0f;
    d.vortex_centre[1] = 36.0f;
    d.vortex_core_radius = 5.0f;
    d.vortex_circulation = 1.0f;
    d.emitter_capacity = 1;
    d.seed = 43;

    size_t need = 0;
    CHECK(mpca_world_bytes(&d, &need));
    if (need > sizeof world_memory) {
        text_dec("firmware: the world needs ", (uint32_t)need);
        sh_str(" bytes; raise WORLD_BYTES");
        sh_flush();
        return 1;
    }
    mpca_world *w = NULL;
    CHECK(mpca_world_init(&d, world_memory, sizeof world_memory, &w));
    /* Static: read where it lies in flash, not copied to the stack first
     * (a copy is a memcpy call). */
    static const mpca_emitter e = {
        .struct_size = sizeof e,
        .min = {30, 0, 0},
        .max = {34, 1, 1},
        .rate = 1.0f,
        .velocity = {0.0f, 0.6f, 0.0f},
        .spread = 0.2f,
        .mass = 1.0f,
        .lifetime = 0,
    };
    uint32_t index = 0;
    CHECK(mpca_world_add_emitter(w, &e, &index));

    mark_begin();
    mpca_status stepped = mpca_world_step(w, STEPS);
    mark_end();
    CHECK(stepped);

    uint64_t hash = 0;
    CHECK(mpca_world_hash(w, &hash));
    sh_str("smoke-64 hash ");
    sh_hex64(hash);
    sh_flush();

    const stack_use stack = stack_measure();
    text_dec("smoke-64 world ", (uint32_t)need);
    text_dec(" of ", (uint32_t)sizeof world_memory);
    text_dec(" bytes, stack ", (uint32_t)stack.used);
    text_dec(" of ", (uint32_t)stack.size);
    sh_str(stack.overflowed ? " bytes, OVERFLOWED" : " bytes");
    sh_flush();
    CHECK(mpca_world_deinit(w));
    return stack.overflowed;
}
