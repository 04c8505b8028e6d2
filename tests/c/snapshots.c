/*
 * Snapshots (M12) and region counters from C, run by tests/tests/c_abi.rs.
 *
 * - Round trips: a 2D world in caller memory and a 3D world from
 *   mpca_world_create are saved, rebuilt with mpca_world_init_from_image
 *   (memory sized by mpca_desc_from_image and mpca_world_bytes) and loaded
 *   into a live world; the copies hash equal, report equal statistics, save
 *   to the same bytes, and still hash equal after stepping on. Prints
 *   "round trip: NAME ..." per world.
 * - Refusals, each checked to change no watched world (hash, statistics,
 *   description and image): every truncation and every single-bit flip of
 *   the 2D image, a foreign version and a foreign reserved word re-sealed
 *   with a CRC-32 computed here, a foreign magic, worlds of another plan,
 *   short buffers, overlapping memory, NULL pointers, a dead handle, too
 *   little memory. Prints "snapshot cases: N".
 * - The 2D image as hex ("image: ...") with its world's hash ("imagehash:
 *   ..."), which the Rust side loads through the Rust API.
 * - Region counters of known particles; their refusals.
 */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

STATIC_ASSERT(sizeof(mpca_region_stats) == 48 && ALIGNOF(mpca_region_stats) == 8, "mpca_region_stats layout");

/* Offsets of the image format (docs/model.md, M12). */
#define VERSION_AT 8u
#define RESERVED_AT 12u
#define LENGTH_AT 16u
#define HEAD_BYTES 24u

static unsigned cases;

/* CRC-32 as the format states it (zlib's), a bit at a time. */
static uint32_t crc32(const unsigned char *p, size_t n) {
    uint32_t r = 0xffffffffu;
    for (size_t i = 0; i < n; i++) {
        r ^= p[i];
        for (unsigned k = 0; k < 8; k++) {
            r = (r >> 1) ^ (0xedb88320u & (0u - (r & 1u)));
        }
    }
    return ~r;
}

static void put_u32(unsigned char *p, uint32_t v) {
    for (unsigned k = 0; k < 4; k++) {
        p[k] = (unsigned char)(v >> (8 * k));
    }
}

static uint32_t get_u32(const unsigned char *p) {
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Writes a fresh checksum over an edited image. */
static void reseal(unsigned char *image, size_t n) {
    put_u32(image + n - 4, crc32(image, n - 4));
}

/* --- What a refusal must leave as it was --------------------------------- */

static uint64_t fnv(uint64_t h, const void *p, size_t n) {
    const unsigned char *b = (const unsigned char *)p;
    for (size_t i = 0; i < n; i++) {
        h = (h ^ b[i]) * 0x100000001b3ull;
    }
    return h;
}

#define MAX_WATCHED 4
static const mpca_world *watched[MAX_WATCHED];
static unsigned n_watched;

/* Hash, statistics, description and image of every watched world. Not
 * traced: these calls are the instrument, not the subject. */
static uint64_t fingerprint(void) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (unsigned i = 0; i < n_watched; i++) {
        mpca_desc d;
        mpca_stats s;
        uint64_t hash = 0;
        size_t n = 0, written = 0;
        memset(&d, 0, sizeof d);
        memset(&s, 0, sizeof s);
        s.struct_size = sizeof s;
        CHECK(mpca_world_desc(watched[i], &d) == MPCA_STATUS_OK);
        CHECK(mpca_world_stats(watched[i], &s) == MPCA_STATUS_OK);
        CHECK(mpca_world_hash(watched[i], &hash) == MPCA_STATUS_OK);
        CHECK(mpca_world_snapshot_bytes(watched[i], &n) == MPCA_STATUS_OK);
        unsigned char *image = malloc(n);
        CHECK(image != NULL);
        if (image != NULL) {
            CHECK(mpca_world_save(watched[i], image, n, &written) == MPCA_STATUS_OK && written == n);
            h = fnv(h, image, n);
            free(image);
        }
        h = fnv(h, &d, sizeof d);
        h = fnv(h, &s, sizeof s);
        h = fnv(h, &hash, sizeof hash);
    }
    return h;
}

/* `call` must return `want` and change no watched world. */
#define REFUSED(want, call)                                                                  \
    do {                                                                                     \
        uint64_t before_ = fingerprint();                                                    \
        check_status(TRACE(call), (want), #call, __FILE__, __LINE__);                        \
        check_true(fingerprint() == before_, "no world changed by " #call, __FILE__, __LINE__); \
        cases++;                                                                             \
    } while (0)

/* --- The worlds ------------------------------------------------------------ */

/* 2D, 24 x 24: 16-bit velocities, per-particle masses, lifetimes, a disc,
 * an emitter, gravity and the vortex, open and wall faces. */
static void desc_2d(mpca_desc *d) {
    CHECK_OK(mpca_desc_defaults(d, 2, 24, 24, 0));
    d->seed = 4242;
    d->boundary[0][0] = d->boundary[0][1] = MPCA_BOUNDARY_OPEN;
    d->boundary[1][0] = d->boundary[1][1] = MPCA_BOUNDARY_WALL;
    d->quantization = 16;
    d->per_particle_mass = 1;
    d->mass_classes = 4;
    d->lifetimes = 1;
    d->obstacles = 1;
    d->surface_capacity = 64;
    d->emitter_capacity = 1;
    d->forces = MPCA_FORCE_UNIFORM | MPCA_FORCE_VORTEX;
    d->gravity[1] = -0.01f;
    d->vortex_centre[0] = 12.0f;
    d->vortex_centre[1] = 12.0f;
    d->vortex_core_radius = 4.0f;
    d->vortex_circulation = 0.5f;
    d->restitution = 0.8f;
    d->contacts = 1;
}

static void fill_2d(mpca_world *w) {
    CHECK_OK(mpca_world_add_disc(w, 7.0f, 8.0f, 2.5f, 0.9f));
    mpca_emitter e;
    memset(&e, 0, sizeof e);
    e.struct_size = sizeof e;
    e.min[0] = 14;
    e.min[1] = 18;
    e.max[0] = 20;
    e.max[1] = 20;
    e.max[2] = 1;
    e.rate = 0.8f;
    e.velocity[1] = -0.4f;
    e.spread = 0.2f;
    e.mass = 2.0f;
    e.lifetime = 25;
    uint32_t index = 99;
    CHECK_OK(mpca_world_add_emitter(w, &e, &index));
    uint64_t s = 11;
    for (uint32_t y = 0; y < 24; y++) {
        for (uint32_t x = 0; x < 24; x++) {
            uint32_t r = check_random(&s);
            mpca_cell c;
            uint32_t pos[3] = {x, y, 0};
            CHECK_OK(mpca_world_cell(w, pos, &c));
            if (r % 5 == 0 && c.kind == MPCA_CELL_KIND_EMPTY) {
                float v[3] = {(float)((r >> 8) % 9) * 0.1f - 0.4f, (float)((r >> 12) % 9) * 0.1f - 0.4f, 0};
                CHECK_OK(mpca_world_add_particle_mass(w, pos, v, (r >> 16) % 2 ? 1.0f : 0.5f));
            }
        }
    }
}

/* 3D, 12 x 12 x 12 in 8-bit velocities: a sphere, gravity, walls. */
static void desc_3d(mpca_desc *d) {
    CHECK_OK(mpca_desc_defaults(d, 3, 12, 12, 12));
    d->seed = 77;
    for (unsigned k = 0; k < 3; k++) {
        d->boundary[k][0] = d->boundary[k][1] = MPCA_BOUNDARY_WALL;
    }
    d->obstacles = 1;
    d->surface_capacity = 256;
    d->forces = MPCA_FORCE_UNIFORM;
    d->gravity[1] = -0.02f;
    d->method = MPCA_METHOD_GREEDY;
}

static void fill_3d(mpca_world *w) {
    const float centre[3] = {6.0f, 4.0f, 6.0f};
    CHECK_OK(mpca_world_add_sphere(w, centre, 2.5f, 1.0f));
    uint64_t s = 5;
    for (uint32_t z = 0; z < 12; z++) {
        for (uint32_t y = 7; y < 11; y++) {
            for (uint32_t x = 0; x < 12; x++) {
                uint32_t r = check_random(&s);
                uint32_t pos[3] = {x, y, z};
                if (r % 3 == 0) {
                    float v[3] = {(float)(r % 7) * 0.05f - 0.15f, -0.1f, (float)((r >> 4) % 7) * 0.05f - 0.15f};
                    CHECK_OK(mpca_world_add_particle(w, pos, v));
                }
            }
        }
    }
}

static uint64_t hash_of(const mpca_world *w) {
    uint64_t h = 0;
    CHECK_OK(mpca_world_hash(w, &h));
    return h;
}

static mpca_stats stats_of(const mpca_world *w) {
    mpca_stats s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    CHECK_OK(mpca_world_stats(w, &s));
    return s;
}

/* The world's image in a new block (`*n` bytes); NULL on failure. */
static unsigned char *save(const mpca_world *w, size_t *n) {
    size_t need = 0, bytes = 0, written = 0;
    CHECK_OK(mpca_world_save(w, NULL, 0, &need)); /* the size query */
    CHECK_OK(mpca_world_snapshot_bytes(w, &bytes));
    CHECK(need == bytes && need > HEAD_BYTES);
    unsigned char *image = malloc(need);
    CHECK(image != NULL);
    if (image == NULL) {
        return NULL;
    }
    CHECK_OK(mpca_world_save(w, image, need, &written));
    CHECK(written == need);
    *n = need;
    return image;
}

/* Saves `w`, rebuilds it into fresh caller memory and into a created world,
 * compares, steps all three `more` steps and compares again. */
static void round_trip(mpca_world *w, const char *name, uint64_t more) {
    check_context = name;
    size_t n = 0;
    unsigned char *image = save(w, &n);
    if (image == NULL) {
        return;
    }
    mpca_desc d, own;
    size_t bytes = 0;
    CHECK_OK(mpca_desc_from_image(image, n, &d));
    CHECK_OK(mpca_world_desc(w, &own));
    CHECK(memcmp(&d, &own, sizeof d) == 0);
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    unsigned char *memory = malloc(bytes + 5);
    CHECK(memory != NULL);
    if (memory == NULL) {
        free(image);
        return;
    }
    mpca_world *a = NULL, *b = NULL;
    CHECK_OK(mpca_world_init_from_image(image, n, memory + 5, bytes, &a)); /* misaligned on purpose */
    CHECK_OK(mpca_world_create(&d, &b));
    CHECK_OK(mpca_world_load(b, image, n));
    unsigned equal = 0;
    const mpca_world *copies[2] = {a, b};
    mpca_stats s = stats_of(w);
    for (unsigned i = 0; i < 2; i++) {
        size_t m = 0;
        mpca_stats t = stats_of(copies[i]);
        unsigned char *again = save(copies[i], &m);
        CHECK(hash_of(copies[i]) == hash_of(w));
        CHECK(memcmp(&s, &t, sizeof s) == 0);
        CHECK(again != NULL && m == n && memcmp(again, image, n) == 0);
        equal += again != NULL && m == n && memcmp(again, image, n) == 0 && hash_of(copies[i]) == hash_of(w);
        free(again);
    }
    CHECK_OK(mpca_world_step(w, more));
    CHECK_OK(mpca_world_step(a, more));
    CHECK_OK(mpca_world_step(b, more));
    s = stats_of(w);
    for (unsigned i = 0; i < 2; i++) {
        mpca_stats t = stats_of(copies[i]);
        CHECK(hash_of(copies[i]) == hash_of(w));
        CHECK(memcmp(&s, &t, sizeof s) == 0);
        equal += hash_of(copies[i]) == hash_of(w) && memcmp(&s, &t, sizeof s) == 0;
    }
    printf("round trip: %s image %zu bytes, %u of 4 equal, %" PRIu64 " particles\n", name, n, equal, s.particles);
    CHECK_OK(mpca_world_deinit(a));
    CHECK_OK(mpca_world_destroy(b));
    free(memory);
    free(image);
}

/* --- Refusals -------------------------------------------------------------- */

/* The status a flip of a bit of byte `at` must give: the framing fields
 * are checked before the checksum, everything else by it. */
static mpca_status flip_status(const unsigned char *image, size_t at, unsigned bit) {
    if (at < VERSION_AT) {
        return MPCA_STATUS_NOT_AN_IMAGE;
    }
    if (at < RESERVED_AT) {
        /* A version this library reads (1, 2 or 3) goes on to the
         * checksum, which the flip breaks. */
        uint32_t version = get_u32(image + VERSION_AT) ^ (1u << (8 * (at - VERSION_AT) + bit));
        return version >= 1 && version <= 3 ? MPCA_STATUS_IMAGE_CHECKSUM : MPCA_STATUS_IMAGE_VERSION;
    }
    if (at >= LENGTH_AT && at < HEAD_BYTES) {
        return MPCA_STATUS_IMAGE_LENGTH;
    }
    return MPCA_STATUS_IMAGE_CHECKSUM;
}

static void refusals(mpca_world *w2, unsigned char *w2_memory, size_t w2_bytes, mpca_world *w3) {
    check_context = "refusals";
    size_t n = 0, n3 = 0;
    unsigned char *image = save(w2, &n);
    unsigned char *image3 = save(w3, &n3);
    /* The target: a world of the 2D plan in another state. */
    mpca_desc d;
    desc_2d(&d);
    mpca_world *target = NULL;
    CHECK_OK(mpca_world_create(&d, &target));
    if (image == NULL || image3 == NULL || target == NULL) {
        return;
    }
    n_watched = 0;
    watched[n_watched++] = target;
    watched[n_watched++] = w2;
    watched[n_watched++] = w3;

    check_context = "every truncation";
    for (size_t len = 0; len < n; len++) {
        REFUSED(MPCA_STATUS_IMAGE_LENGTH, mpca_world_load(target, image, len));
    }
    REFUSED(MPCA_STATUS_IMAGE_LENGTH, mpca_desc_from_image(image, n - 1, &d));

    check_context = "every single-bit flip";
    unsigned char *damaged = malloc(n);
    CHECK(damaged != NULL);
    if (damaged != NULL) {
        memcpy(damaged, image, n);
        unsigned wrong = 0;
        uint64_t before = fingerprint();
        for (size_t at = 0; at < n; at++) {
            for (unsigned bit = 0; bit < 8; bit++) {
                damaged[at] ^= (unsigned char)(1u << bit);
                wrong += TRACE(mpca_world_load(target, damaged, n)) != flip_status(image, at, bit);
                damaged[at] ^= (unsigned char)(1u << bit);
                cases++;
            }
            if (at % 97 == 0) {
                CHECK(fingerprint() == before);
            }
        }
        CHECK(wrong == 0);
        CHECK(fingerprint() == before);
        printf("bit flips: %zu refused\n", n * 8);

        check_context = "foreign images re-sealed";
        memcpy(damaged, image, n);
        put_u32(damaged + VERSION_AT, 4);
        reseal(damaged, n);
        REFUSED(MPCA_STATUS_IMAGE_VERSION, mpca_world_load(target, damaged, n));
        memcpy(damaged, image, n);
        put_u32(damaged + RESERVED_AT, 1);
        reseal(damaged, n);
        REFUSED(MPCA_STATUS_IMAGE_INVALID, mpca_world_load(target, damaged, n));
        REFUSED(MPCA_STATUS_IMAGE_INVALID, mpca_desc_from_image(damaged, n, &d));
        memcpy(damaged, image, n);
        damaged[0] = 'm';
        REFUSED(MPCA_STATUS_NOT_AN_IMAGE, mpca_world_load(target, damaged, n));
        /* The CRC computed here is the image's own. */
        CHECK(crc32(image, n - 4) == get_u32(image + n - 4));
        free(damaged);
    }

    check_context = "worlds of another plan";
    REFUSED(MPCA_STATUS_IMAGE_MISMATCH, mpca_world_load(w3, image, n));
    REFUSED(MPCA_STATUS_IMAGE_MISMATCH, mpca_world_load(target, image3, n3));
    mpca_desc other;
    desc_2d(&other);
    other.size[1] = 26;
    mpca_world *taller = NULL;
    CHECK_OK(mpca_world_create(&other, &taller));
    watched[n_watched++] = taller;
    REFUSED(MPCA_STATUS_IMAGE_MISMATCH, mpca_world_load(taller, image, n));

    check_context = "save into short or missing buffers";
    unsigned char *out = malloc(n);
    size_t written = SIZE_MAX;
    CHECK(out != NULL);
    if (out != NULL) {
        memset(out, 0xa5, n);
        REFUSED(MPCA_STATUS_OUTPUT_TOO_SMALL, mpca_world_save(w2, out, n - 1, &written));
        CHECK(written == n);
        written = SIZE_MAX;
        REFUSED(MPCA_STATUS_OUTPUT_TOO_SMALL, mpca_world_save(w2, out, 1, &written));
        CHECK(written == n);
        size_t untouched = 0;
        for (size_t i = 0; i < n; i++) {
            untouched += out[i] == 0xa5;
        }
        CHECK(untouched == n);
        written = SIZE_MAX;
        REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_save(w2, NULL, n, &written));
        CHECK(written == SIZE_MAX);
        REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_save(w2, out, n, NULL));
        REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_save(NULL, out, n, &written));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_save(w2, out, SIZE_MAX, &written));
        free(out);
    }

    check_context = "overlapping memory";
    /* w2 lives at w2_memory + 3, w2_bytes - 3 bytes: an image into or out of it. */
    REFUSED(MPCA_STATUS_OVERLAP, mpca_world_save(w2, w2_memory + 100, n, &written));
    REFUSED(MPCA_STATUS_OVERLAP, mpca_world_load(w2, w2_memory + 3, n));
    REFUSED(MPCA_STATUS_OVERLAP, mpca_world_load(w2, w2_memory + 40, 16));
    mpca_world *x = NULL;
    REFUSED(MPCA_STATUS_OVERLAP, mpca_world_init_from_image(w2_memory + 3, n, w2_memory + 3, w2_bytes - 3, &x));
    CHECK(x == NULL);

    check_context = "NULL and dead handles";
    size_t bytes = SIZE_MAX;
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_snapshot_bytes(NULL, &bytes));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_snapshot_bytes(w2, NULL));
    CHECK(bytes == SIZE_MAX);
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_load(NULL, image, n));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_load(target, NULL, n));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_load(target, NULL, 0));
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_load(target, image, SIZE_MAX));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_from_image(NULL, n, &d));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_from_image(image, n, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_init_from_image(NULL, n, w2_memory, w2_bytes, &x));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_init_from_image(image, n, NULL, w2_bytes, &x));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_init_from_image(image, n, w2_memory, w2_bytes, NULL));
    CHECK(x == NULL);
    mpca_world *gone = NULL;
    CHECK_OK(mpca_world_create(&d, &gone));
    CHECK_OK(mpca_world_destroy(gone));
    REFUSED(MPCA_STATUS_BAD_HANDLE, mpca_world_load(gone, image, n));
    REFUSED(MPCA_STATUS_BAD_HANDLE, mpca_world_save(gone, NULL, 0, &written));
    REFUSED(MPCA_STATUS_BAD_HANDLE, mpca_world_snapshot_bytes(gone, &bytes));

    check_context = "init_from_image without room, or over a live world";
    size_t need = 0;
    CHECK_OK(mpca_world_bytes(&d, &need));
    unsigned char *small = malloc(need);
    CHECK(small != NULL);
    if (small != NULL) {
        memset(small, 0x3c, need);
        REFUSED(MPCA_STATUS_BUFFER_TOO_SMALL, mpca_world_init_from_image(image, n, small, need / 2, &x));
        size_t untouched = 0;
        for (size_t i = 0; i < need; i++) {
            untouched += small[i] == 0x3c;
        }
        CHECK(untouched == need);
        free(small);
    }
    /* A damaged image over the memory of the live w2 leaves w2 alive. */
    unsigned char last = image[n - 1];
    image[n - 1] ^= 0x10;
    REFUSED(MPCA_STATUS_IMAGE_CHECKSUM, mpca_world_init_from_image(image, n, w2_memory, w2_bytes, &x));
    image[n - 1] = last;
    CHECK(x == NULL);
    CHECK_OK(mpca_world_step(w2, 1)); /* still reachable */

    n_watched = 0;
    CHECK_OK(mpca_world_destroy(target));
    CHECK_OK(mpca_world_destroy(taller));
    free(image);
    free(image3);
}

/* The 2D world's image as hex, with its hash, for the Rust side. */
static void print_image(const mpca_world *w) {
    size_t n = 0;
    unsigned char *image = save(w, &n);
    if (image == NULL) {
        return;
    }
    printf("imagehash: %016" PRIx64 "\n", hash_of(w));
    printf("image: ");
    for (size_t i = 0; i < n; i++) {
        printf("%02x", image[i]);
    }
    printf("\n");
    free(image);
}

/* --- Region counters ---------------------------------------------------- */

static void regions(void) {
    check_context = "region counters";
    mpca_desc d;
    CHECK_OK(mpca_desc_defaults(&d, 2, 130, 6, 0));
    d.per_particle_mass = 1;
    d.mass_classes = 2;
    mpca_world *w = NULL;
    CHECK_OK(mpca_world_create(&d, &w));
    if (w == NULL) {
        return;
    }
    /* Velocities in whole quanta (k / 127) at the edges of the 64-cell words. */
    const uint32_t at[4][3] = {{0, 0, 0}, {63, 2, 0}, {64, 2, 0}, {129, 5, 0}};
    const float v[4][3] = {{64 / 127.0f, 0, 0}, {0, -32 / 127.0f, 0}, {-16 / 127.0f, 16 / 127.0f, 0}, {127 / 127.0f, 0, 0}};
    const float m[4] = {1.0f, 2.0f, 1.0f, 2.0f};
    for (unsigned i = 0; i < 4; i++) {
        CHECK_OK(mpca_world_add_particle_mass(w, at[i], v[i], m[i]));
    }
    mpca_region_stats r;
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    const uint32_t lo[3] = {60, 0, 0}, hi[3] = {66, 6, 1};
    CHECK_OK(mpca_world_region_stats(w, lo, hi, &r));
    CHECK(r.struct_size == sizeof r && r.particles == 2);
    CHECK(fabs(r.momentum[0] - (-16.0 / 127.0)) < 1e-6 && fabs(r.momentum[1] - (-64.0 + 16.0) / 127.0) < 1e-6);
    CHECK(fabs(r.kinetic_energy - 0.5 * (2.0 * 32 * 32 + 16 * 16 + 16 * 16) / (127.0 * 127.0)) < 1e-6);
    const uint32_t all_lo[3] = {0, 0, 0}, all_hi[3] = {130, 6, 1};
    CHECK_OK(mpca_world_region_stats(w, all_lo, all_hi, &r));
    mpca_stats s = stats_of(w);
    CHECK(r.particles == 4 && r.particles == s.particles);
    CHECK(memcmp(r.momentum, s.momentum, sizeof r.momentum) == 0 && r.kinetic_energy == s.kinetic_energy);
    printf("region: %" PRIu64 " of %" PRIu64 " particles in [60, 66) x [0, 6)\n", (uint64_t)2, s.particles);

    n_watched = 0;
    watched[n_watched++] = w;
    mpca_region_stats kept;
    memset(&kept, 0x5a, sizeof kept);
    kept.struct_size = sizeof kept;
    r = kept;
    const uint32_t reversed[3] = {66, 0, 0}, empty_hi[3] = {60, 6, 1}, beyond[3] = {131, 6, 1};
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_region_stats(w, reversed, hi, &r));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_region_stats(w, lo, empty_hi, &r));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_region_stats(w, lo, beyond, &r));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_region_stats(NULL, lo, hi, &r));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_region_stats(w, NULL, hi, &r));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_region_stats(w, lo, NULL, &r));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_region_stats(w, lo, hi, NULL));
    CHECK(memcmp(&r, &kept, sizeof r) == 0);
    r.struct_size = sizeof r - 8;
    kept = r;
    REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_region_stats(w, lo, hi, &r));
    CHECK(memcmp(&r, &kept, sizeof r) == 0);
    n_watched = 0;
    CHECK_OK(mpca_world_destroy(w));
}

int main(void) {
    check_begin();

    check_context = "building";
    mpca_desc d2, d3;
    desc_2d(&d2);
    desc_3d(&d3);
    size_t bytes = 0;
    CHECK_OK(mpca_world_bytes(&d2, &bytes));
    unsigned char *memory = malloc(bytes + 3);
    mpca_world *w2 = NULL, *w3 = NULL;
    CHECK(memory != NULL);
    if (memory == NULL) {
        return check_end();
    }
    CHECK_OK(mpca_world_init(&d2, memory + 3, bytes, &w2));
    CHECK_OK(mpca_world_create(&d3, &w3));
    if (w2 == NULL || w3 == NULL) {
        return check_end();
    }
    fill_2d(w2);
    fill_3d(w3);
    CHECK_OK(mpca_world_step(w2, 30));
    CHECK_OK(mpca_world_step(w3, 12));

    round_trip(w2, "2d", 40);
    round_trip(w3, "3d", 20);
    print_image(w2);
    refusals(w2, memory, bytes + 3, w3);
    regions();

    check_context = "teardown";
    CHECK_OK(mpca_world_deinit(w2));
    CHECK_OK(mpca_world_destroy(w3));
    free(memory);
    printf("snapshot cases: %u\n", cases);
    return check_end();
}
