/*
 * Handles after their worlds end, while the allocator and the caller reuse
 * the memory those worlds lived in. Freed blocks are reused all the time,
 * so a C program meets each of these by chance:
 *
 * - caller memory at the address of a destroyed world holds a live world,
 *   and the destroyed world's handle stays refused;
 * - a destroyed handle stays refused when mpca_world_create gets the same
 *   block back (create, destroy, create, 200 times), and no handle value
 *   is ever handed out twice;
 * - a deinitialised handle stays refused when mpca_world_init builds a new
 *   world in the same memory, and a world's handle is refused once its
 *   memory is reused by mpca_world_init without mpca_world_deinit.
 *
 * Prints "reuse: reached" when the allocator gave the freed block back (the
 * Rust side requires it, so the first check cannot pass by not running).
 * c_abi.rs runs this program with ASan's quarantine off, so that ASan
 * hands freed blocks back as glibc does, and without its fill of new
 * blocks, so that the block is known by what it held.
 */
#include <stdio.h>
#include <stdlib.h>

#include "check.h"

#define TRIES 64
#define CYCLES 200

/* Calls that must refuse the dead handle `h`; none may reach a world. */
static void refused(mpca_world *h) {
    uint64_t hash = 0x5eed;
    size_t count = 0x5eed;
    uint32_t pos[3] = {1, 1, 0};
    float v[3] = {0.25f, 0, 0};
    check_status(TRACE(mpca_world_hash(h, &hash)), MPCA_STATUS_BAD_HANDLE, "mpca_world_hash(dead)", __FILE__, __LINE__);
    check_status(TRACE(mpca_world_particle_count(h, &count)), MPCA_STATUS_BAD_HANDLE, "mpca_world_particle_count(dead)",
                 __FILE__, __LINE__);
    check_status(TRACE(mpca_world_add_particle(h, pos, v)), MPCA_STATUS_BAD_HANDLE, "mpca_world_add_particle(dead)",
                 __FILE__, __LINE__);
    check_status(TRACE(mpca_world_step(h, 1)), MPCA_STATUS_BAD_HANDLE, "mpca_world_step(dead)", __FILE__, __LINE__);
    check_status(TRACE(mpca_world_deinit(h)), MPCA_STATUS_BAD_HANDLE, "mpca_world_deinit(dead)", __FILE__, __LINE__);
    check_status(TRACE(mpca_world_destroy(h)), MPCA_STATUS_BAD_HANDLE, "mpca_world_destroy(dead)", __FILE__, __LINE__);
    CHECK(hash == 0x5eed && count == 0x5eed);
}

/* The particle count of the live world `w`, or SIZE_MAX if refused. */
static size_t count_of(mpca_world *w) {
    size_t count = SIZE_MAX;
    if (TRACE(mpca_world_particle_count(w, &count)) != MPCA_STATUS_OK) {
        return SIZE_MAX;
    }
    return count;
}

/* The seed of the world whose block the first case looks for: its
 * header keeps the description, which freeing the block leaves in place. */
#define MARK_SEED 0x6d70636172657573ull /* "mpcareus" */

/* Whether `p` (`bytes` long, as malloc gave it: its bytes are whatever the
 * block held before) holds the description of the world seeded MARK_SEED. */
static int held_the_marked_world(const unsigned char *p, size_t bytes) {
    const uint64_t mark = MARK_SEED;
    const unsigned char *m = (const unsigned char *)&mark;
    for (size_t i = 0; i + sizeof mark <= bytes; i++) {
        size_t k = 0;
        while (k < sizeof mark && p[i + k] == m[k]) {
            k++;
        }
        if (k == sizeof mark) {
            return 1;
        }
    }
    return 0;
}

static void caller_memory_at_a_destroyed_worlds_address(const mpca_desc *desc, size_t bytes) {
    check_context = "caller memory at a destroyed world's address";
    mpca_desc d = *desc;
    d.seed = MARK_SEED;
    mpca_world *gone = NULL;
    CHECK_OK(mpca_world_create(&d, &gone));
    CHECK_OK(mpca_world_destroy(gone));

    /* Blocks of the same size until the freed one comes back (glibc gives
     * it at once), known by the description the dead world left in it. */
    void *held[TRIES];
    unsigned char *memory = NULL;
    unsigned n = 0;
    while (n < TRIES) {
        unsigned char *p = malloc(bytes);
        if (p == NULL) {
            break;
        }
        if (held_the_marked_world(p, bytes)) {
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
        return;
    }
    printf("reuse: reached\n");

    mpca_world *w = NULL;
    CHECK_OK(mpca_world_init(&d, memory, bytes, &w));
    CHECK(w != gone); /* a new world never gets a dead world's handle */
    refused(gone);    /* and the dead handle reaches nothing, not the new world */
    uint32_t pos[3] = {1, 1, 0};
    float v[3] = {0.5f, 0, 0};
    CHECK_OK(mpca_world_add_particle(w, pos, v));
    CHECK_OK(mpca_world_step(w, 3));
    CHECK(count_of(w) == 1);
    CHECK_OK(mpca_world_deinit(w));
    free(memory);
}

/* create(&a); destroy(a); create(&b): the allocator gives b a's block, and
 * a must not reach b. Every handle value seen is different. */
static void created_worlds_in_reused_blocks(const mpca_desc *d) {
    check_context = "destroyed handles while the allocator reuses blocks";
    static mpca_world *seen[2 * CYCLES];
    unsigned n_seen = 0, reached = 0;
    uint32_t pos[3] = {3, 3, 0};
    float v[3] = {0, 0.25f, 0};
    for (unsigned i = 0; i < CYCLES; i++) {
        mpca_world *a = NULL, *b = NULL;
        CHECK_OK(mpca_world_create(d, &a));
        CHECK_OK(mpca_world_destroy(a));
        CHECK_OK(mpca_world_create(d, &b));
        CHECK_OK(mpca_world_add_particle(b, pos, v));
        uint64_t hash = 0;
        mpca_status st = TRACE(mpca_world_hash(a, &hash));
        reached += st == MPCA_STATUS_OK;
        CHECK(st == MPCA_STATUS_BAD_HANDLE);
        CHECK(b != a);
        refused(a);
        CHECK(count_of(b) == 1); /* b untouched by the calls on a */
        seen[n_seen++] = a;
        seen[n_seen++] = b;
        CHECK_OK(mpca_world_destroy(b));
        refused(b);
    }
    printf("destroyed handles that reached a world: %u of %u\n", reached, CYCLES);

    check_context = "handle values are never reused";
    unsigned repeats = 0;
    for (unsigned i = 0; i < n_seen; i++) {
        for (unsigned j = 0; j < i; j++) {
            repeats += seen[i] == seen[j];
        }
    }
    CHECK(repeats == 0);
    printf("handle values repeated: %u of %u\n", repeats, n_seen);
}

/* init(m); deinit; init(m) again: the first handle stays dead. init(m)
 * twice without deinit: the first world ended when its memory was reused. */
static void caller_worlds_in_reused_memory(const mpca_desc *d, size_t bytes) {
    check_context = "deinitialised handles while the caller reuses memory";
    unsigned char *memory = malloc(bytes);
    CHECK(memory != NULL);
    if (memory == NULL) {
        return;
    }
    uint32_t pos[3] = {2, 2, 0};
    float v[3] = {0.25f, 0.25f, 0};
    mpca_world *first = NULL, *second = NULL, *third = NULL;
    CHECK_OK(mpca_world_init(d, memory, bytes, &first));
    CHECK_OK(mpca_world_deinit(first));
    CHECK_OK(mpca_world_init(d, memory, bytes, &second));
    CHECK(second != first);
    refused(first);
    CHECK_OK(mpca_world_add_particle(second, pos, v));
    CHECK(count_of(second) == 1);

    check_context = "a world whose memory mpca_world_init reused";
    CHECK_OK(mpca_world_init(d, memory, bytes, &third)); /* no deinit of second */
    CHECK(third != second && third != first);
    refused(second);
    CHECK(count_of(third) == 0);
    CHECK_OK(mpca_world_deinit(third));
    refused(third);
    free(memory);
}

int main(void) {
    check_begin();
    mpca_desc d;
    size_t bytes = 0;
    CHECK_OK(mpca_desc_defaults(&d, 2, 8, 8, 0));
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    caller_memory_at_a_destroyed_worlds_address(&d, bytes);
    created_worlds_in_reused_blocks(&d);
    caller_worlds_in_reused_memory(&d, bytes);
    return check_end();
}
