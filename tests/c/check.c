/*
 * The check machinery of check.h, and the table holding the address of every
 * function include/mpca.h declares. Linking a program with this file links
 * every export, so a symbol missing from libmpca.a or libmpca.so fails the
 * link. The Rust side compares the names printed from the table with the
 * declarations in the header, so a function added to the header and not
 * here fails the test.
 */
#include "check.h"

#include <stdio.h>
#include <string.h>

/* GCC says __SANITIZE_ADDRESS__; Clang says __has_feature(address_sanitizer). */
#if defined(__SANITIZE_ADDRESS__)
#define CHECK_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CHECK_ASAN 1
#endif
#endif

/* void (*)(void) is the generic function pointer type: GCC's
 * -Wcast-function-type accepts casts to it from any function type. */
typedef void (*any_fn)(void);

#define SYMBOL(f) {#f, (any_fn)f}

static const struct symbol {
    const char *name;
    any_fn address;
} SYMBOLS[] = {
    SYMBOL(mpca_version),
#if defined(MPCA_PANIC_TEST)
    SYMBOL(mpca_debug_panic),
#endif
    SYMBOL(mpca_desc_defaults),
    SYMBOL(mpca_desc_preset),
    SYMBOL(mpca_desc_validate),
    SYMBOL(mpca_world_bytes),
    SYMBOL(mpca_world_add_emitter),
    SYMBOL(mpca_world_add_body),
    SYMBOL(mpca_desc_body_surface_entries),
    SYMBOL(mpca_world_move_body),
    SYMBOL(mpca_world_remove_body),
    SYMBOL(mpca_world_body_stats),
    SYMBOL(mpca_world_set_emitter_rate),
    SYMBOL(mpca_world_set_emitter_tag),
    SYMBOL(mpca_world_emitter_stats),
    SYMBOL(mpca_world_set_tag),
    SYMBOL(mpca_world_set_gravity),
    SYMBOL(mpca_world_set_force_field),
    SYMBOL(mpca_world_set_cell_force),
    SYMBOL(mpca_world_set_potential),
    SYMBOL(mpca_world_set_cell_potential),
    SYMBOL(mpca_world_set_vortex),
    SYMBOL(mpca_world_set_wind_field),
    SYMBOL(mpca_world_set_cell_wind),
    SYMBOL(mpca_world_add_obstacle),
    SYMBOL(mpca_world_add_half_space),
    SYMBOL(mpca_world_add_box),
    SYMBOL(mpca_world_add_disc),
    SYMBOL(mpca_world_add_sphere),
    SYMBOL(mpca_world_add_obstacle_mask),
    SYMBOL(mpca_world_surface),
    SYMBOL(mpca_desc_surface_entries),
    SYMBOL(mpca_world_surface_entries),
    SYMBOL(mpca_world_add_shape),
    SYMBOL(mpca_world_add_particle),
    SYMBOL(mpca_world_add_particle_mass),
    SYMBOL(mpca_world_remove_particle),
    SYMBOL(mpca_world_cell),
    SYMBOL(mpca_world_particle_count),
    SYMBOL(mpca_world_export_positions),
    SYMBOL(mpca_world_export_velocities),
    SYMBOL(mpca_world_export_masses),
    SYMBOL(mpca_world_export_particles),
    SYMBOL(mpca_world_density),
    SYMBOL(mpca_world_density_u8),
    SYMBOL(mpca_status_message),
    SYMBOL(mpca_last_error),
    SYMBOL(mpca_world_last_error),
    SYMBOL(mpca_world_init),
    SYMBOL(mpca_world_deinit),
    SYMBOL(mpca_world_create),
    SYMBOL(mpca_world_destroy),
    SYMBOL(mpca_world_step),
    SYMBOL(mpca_world_step_parallel),
    SYMBOL(mpca_world_step_task),
    SYMBOL(mpca_world_desc),
    SYMBOL(mpca_world_stats),
    SYMBOL(mpca_world_hash),
    SYMBOL(mpca_world_region_stats),
    SYMBOL(mpca_world_snapshot_bytes),
    SYMBOL(mpca_world_save),
    SYMBOL(mpca_world_load),
    SYMBOL(mpca_desc_from_image),
    SYMBOL(mpca_world_init_from_image),
};

#define SYMBOL_COUNT (sizeof SYMBOLS / sizeof SYMBOLS[0])

static unsigned char called[SYMBOL_COUNT];
static unsigned checks;
static unsigned failures;

const char *check_context = "";

void check_begin(void) {
    size_t i, j;
#if defined(CHECK_ASAN)
    printf("sanitizer: address\n");
#else
    printf("sanitizer: none\n");
#endif
    for (i = 0; i < SYMBOL_COUNT; i++) {
        printf("symbol: %s\n", SYMBOLS[i].name);
        CHECK(SYMBOLS[i].address != NULL);
        for (j = 0; j < i; j++) {
            CHECK(SYMBOLS[i].address != SYMBOLS[j].address);
        }
    }
}

int check_end(void) {
    size_t i;
    for (i = 0; i < SYMBOL_COUNT; i++) {
        if (called[i]) {
            printf("called: %s\n", SYMBOLS[i].name);
        }
    }
    printf("checks: %u, failed: %u\n", checks, failures);
    fflush(stdout);
    return failures == 0 ? 0 : 1;
}

void check_called(const char *call_text) {
    size_t i, len = strspn(call_text, "abcdefghijklmnopqrstuvwxyz0123456789_");
    for (i = 0; i < SYMBOL_COUNT; i++) {
        if (strlen(SYMBOLS[i].name) == len && strncmp(SYMBOLS[i].name, call_text, len) == 0) {
            called[i] = 1;
            return;
        }
    }
    check_true(0, "TRACE of a function missing from the symbol table", call_text, 0);
}

void check_true(int ok, const char *what, const char *file, int line) {
    checks++;
    if (!ok) {
        failures++;
        printf("FAILED %s:%d [%s]: %s\n", file, line, check_context, what);
    }
}

void check_status(mpca_status got, mpca_status want, const char *what, const char *file, int line) {
    checks++;
    if (got != want) {
        failures++;
        printf("FAILED %s:%d [%s]: %s returned %u (%s), expected %u (%s)\n", file, line, check_context, what,
               (unsigned)got, mpca_status_message(got), (unsigned)want, mpca_status_message(want));
    }
}

unsigned check_failures(void) {
    return failures;
}

uint32_t check_random(uint64_t *state) {
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*state >> 33);
}

float check_unit(uint64_t *state) {
    return (float)(check_random(state) >> 8) / 16777216.0f;
}
