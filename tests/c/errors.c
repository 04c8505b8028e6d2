/*
 * Every error path of the C ABI, tried from C: NULL for every pointer
 * parameter, dead and forged handles, NaN and infinities in every float
 * parameter and field, out-of-range values, wrong struct sizes, small
 * buffers. Each case checks the status returned AND that no world changed:
 * a fingerprint of every watched world (hash, description, statistics, and
 * every cell and surface entry read back) is taken before and after the call.
 * Out-parameters of refused calls are checked to be untouched.
 *
 * Also: the structure layouts and every status message (panics: panic.c).
 * Prints "error cases: N"; tests/tests/c_abi.rs checks N against a minimum.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* The layout ffi/src/lib.rs asserts on the Rust side. */
STATIC_ASSERT(sizeof(mpca_desc) == 200 && ALIGNOF(mpca_desc) == 8, "mpca_desc layout");
STATIC_ASSERT(sizeof(mpca_stats) == 152 && ALIGNOF(mpca_stats) == 8, "mpca_stats layout");
STATIC_ASSERT(sizeof(mpca_body_stats) == 40 && ALIGNOF(mpca_body_stats) == 8, "mpca_body_stats layout");
STATIC_ASSERT(sizeof(mpca_particle) == 44 && ALIGNOF(mpca_particle) == 4, "mpca_particle layout");
STATIC_ASSERT(sizeof(mpca_particle_columns) == 8 + 5 * sizeof(void *) && ALIGNOF(mpca_particle_columns) == ALIGNOF(void *), "mpca_particle_columns layout");
STATIC_ASSERT(sizeof(mpca_cell) == 48 && ALIGNOF(mpca_cell) == 4, "mpca_cell layout");
STATIC_ASSERT(sizeof(mpca_emitter) == 56 && ALIGNOF(mpca_emitter) == 4, "mpca_emitter layout");
STATIC_ASSERT(sizeof(mpca_shape) == 36 && ALIGNOF(mpca_shape) == 4, "mpca_shape layout");
STATIC_ASSERT(sizeof(mpca_status) == 4 && sizeof(mpca_boundary) == 4, "enum sizes");

/* The three values no float input may hold. */
static const float BAD[3] = {NAN, INFINITY, -INFINITY};

/* Out-parameters are preset to these; a refused call must leave them. */
#define SENTINEL_U32 0xdeadbeefu
#define SENTINEL_SIZE ((size_t)0x5eed5eed)
#define SENTINEL_FLOAT 1234.5f
#define SENTINEL_BYTE 0xa5

static unsigned error_cases;

/* --- Fingerprints of the watched worlds -------------------------------- */

#define MAX_WATCHED 8
static mpca_world *watched[MAX_WATCHED];
static unsigned n_watched;

static void watch(mpca_world *w) {
    CHECK(n_watched < MAX_WATCHED);
    if (n_watched < MAX_WATCHED) {
        watched[n_watched++] = w;
    }
}

static uint64_t fnv(uint64_t h, const void *p, size_t n) {
    const unsigned char *b = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; i++) {
        h = (h ^ b[i]) * 0x100000001b3ull;
    }
    return h;
}

/* Everything the ABI can read back from a world. Not traced: these calls
 * are the instrument, not the subject. */
static uint64_t world_fingerprint(const mpca_world *w, uint64_t h) {
    mpca_desc d;
    mpca_stats s;
    uint64_t hash = 0;
    size_t count = 0;
    memset(&d, 0, sizeof d);
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    CHECK(mpca_world_desc(w, &d) == MPCA_STATUS_OK);
    CHECK(mpca_world_stats(w, &s) == MPCA_STATUS_OK);
    CHECK(mpca_world_hash(w, &hash) == MPCA_STATUS_OK);
    CHECK(mpca_world_particle_count(w, &count) == MPCA_STATUS_OK);
    h = fnv(h, &d, sizeof d);
    h = fnv(h, &s, sizeof s);
    h = fnv(h, &hash, sizeof hash);
    h = fnv(h, &count, sizeof count);
    /* The body table (M13), where the world has one: each slot's tally or
     * its status. */
    for (uint32_t id = 0; id < 4; id++) {
        mpca_body_stats b;
        memset(&b, 0, sizeof b);
        b.struct_size = sizeof b;
        mpca_status st = mpca_world_body_stats(w, id, &b);
        h = fnv(h, &st, sizeof st);
        h = fnv(h, &b, sizeof b);
    }
    uint32_t nz = d.dim == 3 ? d.size[2] : 1;
    for (uint32_t z = 0; z < nz; z++) {
        for (uint32_t y = 0; y < d.size[1]; y++) {
            for (uint32_t x = 0; x < d.size[0]; x++) {
                uint32_t pos[3] = {x, y, z};
                mpca_cell c;
                float normal[3] = {0, 0, 0}, e = 0;
                memset(&c, 0, sizeof c);
                CHECK(mpca_world_cell(w, pos, &c) == MPCA_STATUS_OK);
                mpca_status st = mpca_world_surface(w, pos, normal, &e);
                CHECK(st == MPCA_STATUS_OK || st == MPCA_STATUS_NOT_A_SURFACE);
                h = fnv(h, &c, sizeof c);
                h = fnv(h, &st, sizeof st);
                h = fnv(h, normal, sizeof normal);
                h = fnv(h, &e, sizeof e);
            }
        }
    }
    return h;
}

static uint64_t fingerprint(void) {
    uint64_t h = 0xcbf29ce484222325ull;
    for (unsigned i = 0; i < n_watched; i++) {
        h = world_fingerprint(watched[i], h);
    }
    return h;
}

/* The details the last REFUSED call left, read before the fingerprint's
 * own calls (which change them: a read of a world succeeds, and its
 * surface query of a cell that is no surface is refused). */
static const char *thread_detail, *world_detail;

/* An error case: `call` on world `w` (or NULL) must return `want`, leave
 * every watched world as it was, and leave a detail for this thread
 * (mpca_last_error) and, where `w` is given, the same for the world
 * (mpca_world_last_error). */
#define REFUSED_IN(w, want, call)                                                                 \
    do {                                                                                          \
        uint64_t before_ = fingerprint();                                                         \
        check_status(TRACE(call), (want), #call, __FILE__, __LINE__);                             \
        thread_detail = TRACE(mpca_last_error());                                                 \
        world_detail = (w) != NULL ? TRACE(mpca_world_last_error(w)) : thread_detail;             \
        check_true(fingerprint() == before_, "no world changed by " #call, __FILE__, __LINE__);    \
        check_true(*thread_detail != '\0', "a detail for " #call, __FILE__, __LINE__);            \
        check_true(strcmp(world_detail, thread_detail) == 0, "the world's detail of " #call " is the thread's", \
                   __FILE__, __LINE__);                                                           \
        error_cases++;                                                                            \
    } while (0)
#define REFUSED(want, call) REFUSED_IN(NULL, want, call)

/* Whether `got` is `want`, printing both where not. */
static int same_detail(const char *got, const char *want, const char *what) {
    if (strcmp(got, want) == 0) {
        return 1;
    }
    printf("detail of %s: \"%s\", expected \"%s\"\n", what, got, want);
    return 0;
}

/* REFUSED, and this thread's detail must be `detail`. */
#define REFUSED_AT(want, detail, call)                                                                   \
    do {                                                                                                 \
        REFUSED(want, call);                                                                             \
        check_true(same_detail(thread_detail, (detail), #call), "the detail of " #call " is " #detail,   \
                   __FILE__, __LINE__);                                                                  \
    } while (0)

/* REFUSED_AT of a call on world `w`, whose detail must be the same. */
#define REFUSED_ON(w, want, detail, call)                                                                \
    do {                                                                                                 \
        REFUSED_IN(w, want, call);                                                                       \
        check_true(same_detail(thread_detail, (detail), #call), "the detail of " #call " is " #detail,   \
                   __FILE__, __LINE__);                                                                  \
    } while (0)

/* Which case is running, for failure messages. */
static char context[256];

static void set_context(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(context, sizeof context, fmt, ap);
    va_end(ap);
    check_context = context;
}

/* The element a case changes, shown in failures. */
static unsigned at;

/* Sets the float lvalue `slot` to NaN, +inf and -inf in turn; `call` must
 * return `want` for each. `slot` is restored afterwards. */
#define EACH_BAD(slot, want, call)                                                 \
    do {                                                                           \
        float saved_ = (slot);                                                     \
        for (unsigned b_ = 0; b_ < 3; b_++) {                                      \
            (slot) = BAD[b_];                                                      \
            set_context("%s = %g (at = %u)", #slot, (double)BAD[b_], at);          \
            REFUSED((want), call);                                                 \
        }                                                                          \
        (slot) = saved_;                                                           \
    } while (0)

/* --- The worlds under test --------------------------------------------- */

/* Memory a pointer rounded up to 64 bytes can use: forged handles must pass
 * the library's alignment check, so that the tag check is what refuses them. */
static unsigned char *align64(unsigned char *p) {
    return p + ((64 - (uintptr_t)p % 64) % 64);
}

/* Every part enabled: walls, obstacles, all four forces, drag with the wind
 * plane and turbulence, per-particle masses (a table of two), lifetimes,
 * identity, room for two emitters. */
static mpca_desc full_desc(uint32_t dim, uint32_t n) {
    mpca_desc d;
    CHECK_OK(mpca_desc_defaults(&d, dim, n, n, n));
    for (unsigned k = 0; k < 3; k++) {
        d.boundary[k][0] = d.boundary[k][1] = MPCA_BOUNDARY_WALL;
    }
    d.seed = 11;
    d.obstacles = 1;
    d.surface_capacity = 256;
    d.forces = MPCA_FORCE_UNIFORM | MPCA_FORCE_FIELD | MPCA_FORCE_POTENTIAL | MPCA_FORCE_VORTEX;
    d.gravity[1] = -0.01f;
    d.vortex_centre[0] = d.vortex_centre[1] = (float)n / 2;
    d.vortex_core_radius = 2;
    d.vortex_circulation = 0.1f;
    d.per_particle_mass = 1;
    d.mass_classes = 2;
    d.lifetimes = 1;
    d.emitter_capacity = 2;
    d.drag_rate = 0.1f;
    d.drag_wind_field = 1;
    d.drag_turbulence_amplitude = 0.2f;
    d.drag_turbulence_scale = 4;
    d.drag_turbulence_rate = 0.05f;
    d.identity = MPCA_IDENTITY_IDS | MPCA_IDENTITY_AGES | MPCA_IDENTITY_TAGS;
    return d;
}

static mpca_emitter emitter_at(uint32_t x0, uint32_t y0, uint32_t z0, uint32_t side) {
    mpca_emitter e;
    memset(&e, 0, sizeof e);
    e.struct_size = sizeof e;
    e.min[0] = x0;
    e.min[1] = y0;
    e.min[2] = z0;
    e.max[0] = x0 + side;
    e.max[1] = y0 + side;
    e.max[2] = z0 + side;
    e.rate = 0.5f;
    e.velocity[0] = 0.1f;
    e.velocity[1] = -0.2f;
    e.velocity[2] = 0.1f;
    e.spread = 0.1f;
    e.mass = 1;
    e.lifetime = 30;
    return e;
}

#define N2 16 /* full2: 16 x 16 */
#define N3 8  /* full3: 8 x 8 x 8 */
#define CELLS2 (N2 * N2)
#define CELLS3 (N3 * N3 * N3)

static mpca_world *full2; /* in caller memory, misaligned by 5 bytes */
static mpca_world *full3; /* from mpca_world_create */
static mpca_world *bare2; /* defaults: nothing enabled, 8 x 8 */
static mpca_world *small2; /* obstacles with room for one surface cell, 8 x 8 */
static mpca_world *emit2;  /* as full2, from mpca_world_create, with room for 16 emitters */
static mpca_world *body2;  /* walls on x, room for two bodies (body_cases) */
static unsigned char *full2_memory, *small2_memory;
static size_t full2_bytes;

static float field2[CELLS2 * 2], potential2[CELLS2];
static float field3[CELLS3 * 3], potential3[CELLS3];

static void build_worlds(void) {
    set_context("building the worlds");
    mpca_desc d = full_desc(2, N2);
    CHECK_OK(mpca_world_bytes(&d, &full2_bytes));
    full2_memory = malloc(full2_bytes + 5);
    CHECK(full2_memory != NULL);
    CHECK_OK(mpca_world_init(&d, full2_memory + 5, full2_bytes, &full2));

    float floor_point[3] = {0, 2, 0}, up[3] = {0, 1, 0};
    CHECK_OK(mpca_world_add_half_space(full2, floor_point, up, 0.5f)); /* rows 0 and 1 */
    uint32_t post[3] = {12, 12, 0};
    CHECK_OK(mpca_world_add_obstacle(full2, post, up, 0.9f));
    /* The cell (10, 4), nearer the low x face than the high one: a box
     * whose centre is as near every face has no normal. */
    float box_min[3] = {10, 4, 0}, box_max[3] = {11.2f, 5, 1};
    CHECK_OK(mpca_world_add_box(full2, box_min, box_max, 1.0f));
    unsigned char mask[CELLS2] = {0};
    mask[6 * N2 + 12] = mask[6 * N2 + 13] = mask[7 * N2 + 12] = mask[7 * N2 + 13] = 1;
    CHECK_OK(mpca_world_add_obstacle_mask(full2, mask, sizeof mask, 0.8f));
    CHECK_OK(mpca_world_add_disc(full2, 3.0f, 13.0f, 1.0f, 0.7f));
    uint32_t p0[3] = {4, 8, 0}, p1[3] = {5, 8, 0}, p2[3] = {6, 9, 0}, p3[3] = {7, 9, 0};
    float v0[3] = {0.25f, -0.5f, 0}, v1[3] = {0, 0, 0}, v2[3] = {-0.3f, 0.1f, 0}, v3[3] = {0.1f, 0.2f, 0};
    CHECK_OK(mpca_world_add_particle(full2, p0, v0));
    CHECK_OK(mpca_world_add_particle(full2, p1, v1));
    CHECK_OK(mpca_world_add_particle(full2, p2, v2));
    CHECK_OK(mpca_world_add_particle_mass(full2, p3, v3, 2.0f)); /* the mass table {1, 2} is now full */
    mpca_emitter e = emitter_at(2, 10, 0, 3);
    uint32_t index = SENTINEL_U32;
    CHECK_OK(mpca_world_add_emitter(full2, &e, &index)); /* one of two slots used */
    CHECK(index == 0);
    CHECK_OK(mpca_world_set_emitter_rate(full2, 0, 0.75f));
    CHECK_OK(mpca_world_set_emitter_tag(full2, 0, 200));
    CHECK_OK(mpca_world_set_tag(full2, p2, 255));
    for (unsigned i = 0; i < CELLS2; i++) {
        field2[2 * i] = 0.001f * (float)(i % 7);
        field2[2 * i + 1] = -0.002f;
        potential2[i] = 0.01f * (float)(i % N2);
    }
    CHECK_OK(mpca_world_set_force_field(full2, field2, CELLS2 * 2));
    CHECK_OK(mpca_world_set_potential(full2, potential2, CELLS2));
    CHECK_OK(mpca_world_set_wind_field(full2, field2, CELLS2 * 2)); /* small: a wind too */
    float g[3] = {0, -0.02f, 0}, f[3] = {0.01f, 0, 0};
    CHECK_OK(mpca_world_set_gravity(full2, g));
    CHECK_OK(mpca_world_set_cell_force(full2, p0, f));
    CHECK_OK(mpca_world_set_cell_potential(full2, p0, 0.5f));
    CHECK_OK(mpca_world_set_vortex(full2, 8.0f, 8.0f, 3.0f, 0.2f));

    d = full_desc(3, N3);
    CHECK_OK(mpca_world_create(&d, &full3));
    float centre[3] = {4, 4, 4};
    CHECK_OK(mpca_world_add_sphere(full3, centre, 2.2f, 0.9f));
    uint32_t q0[3] = {1, 6, 1}, q1[3] = {6, 1, 6}, q2[3] = {1, 1, 6}, q3[3] = {6, 6, 6};
    float w0[3] = {0.2f, -0.1f, 0.3f}, w1[3] = {0, 0.5f, 0}, w2[3] = {-0.1f, 0, -0.1f};
    CHECK_OK(mpca_world_add_particle(full3, q0, w0));
    CHECK_OK(mpca_world_add_particle(full3, q1, w1));
    CHECK_OK(mpca_world_add_particle(full3, q2, w2));
    CHECK_OK(mpca_world_add_particle_mass(full3, q3, w0, 2.0f));
    e = emitter_at(0, 6, 0, 2);
    CHECK_OK(mpca_world_add_emitter(full3, &e, &index));
    CHECK(index == 0);
    for (unsigned i = 0; i < CELLS3; i++) {
        field3[3 * i] = field3[3 * i + 1] = field3[3 * i + 2] = 0.001f;
        potential3[i] = 0.0f;
    }
    CHECK_OK(mpca_world_set_force_field(full3, field3, CELLS3 * 3));
    CHECK_OK(mpca_world_set_potential(full3, potential3, CELLS3));
    CHECK_OK(mpca_world_set_wind_field(full3, field3, CELLS3 * 3));

    CHECK_OK(mpca_desc_defaults(&d, 2, 8, 8, 0));
    CHECK_OK(mpca_world_create(&d, &bare2));
    uint32_t b0[3] = {1, 1, 0}, b1[3] = {2, 2, 0};
    CHECK_OK(mpca_world_add_particle(bare2, b0, v0));
    CHECK_OK(mpca_world_add_particle(bare2, b1, v2));

    d.obstacles = 1;
    d.surface_capacity = 1;
    size_t bytes = 0;
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    small2_memory = malloc(bytes);
    CHECK(small2_memory != NULL);
    CHECK_OK(mpca_world_init(&d, small2_memory, bytes, &small2));

    d = full_desc(2, N2);
    d.emitter_capacity = 16;
    CHECK_OK(mpca_world_create(&d, &emit2));
    CHECK_OK(mpca_world_add_particle_mass(emit2, p3, v3, 2.0f)); /* the mass table {1, 2} is now full */

    watch(full2);
    watch(full3);
    watch(bare2);
    watch(small2);
    watch(emit2);
}

/* --- Descriptions ------------------------------------------------------- */

/* Big enough for any valid description tried here. */
#define POOL_BYTES (256 * 1024)
static unsigned char *pool;

/* A refused description: every function that takes one must return `want`
 * with `detail` (the field at fault) as this thread's detail, write no
 * output, and leave the caller's memory as it was. */
static void desc_refused(const mpca_desc *d, mpca_status want, const char *detail) {
    size_t bytes = SENTINEL_SIZE;
    mpca_world *const sentinel = (mpca_world *)(void *)&bytes;
    mpca_world *w = sentinel;
    REFUSED_AT(want, detail, mpca_desc_validate(d));
    REFUSED_AT(want, detail, mpca_world_bytes(d, &bytes));
    CHECK(bytes == SENTINEL_SIZE);
    memset(pool, SENTINEL_BYTE, POOL_BYTES);
    REFUSED_AT(want, detail, mpca_world_init(d, pool + 3, POOL_BYTES - 3, &w));
    CHECK(w == sentinel);
    size_t untouched = 0;
    while (untouched < POOL_BYTES && pool[untouched] == SENTINEL_BYTE) {
        untouched++;
    }
    CHECK(untouched == POOL_BYTES);
    REFUSED_AT(want, detail, mpca_world_create(d, &w));
    CHECK(w == sentinel);
}

/* Field `field` of a copy of `base` set to each value in turn; `detail`
 * names it. */
#define DESC_VALUES(base, field, want, detail, ...)                                         \
    do {                                                                                    \
        const uint32_t values_[] = {__VA_ARGS__};                                           \
        for (unsigned i_ = 0; i_ < sizeof values_ / sizeof values_[0]; i_++) {              \
            mpca_desc d_ = (base);                                                          \
            d_.field = values_[i_];                                                         \
            set_context("%uD desc.%s = %u (at = %u)", (base).dim, #field, values_[i_], at); \
            desc_refused(&d_, (want), (detail));                                            \
        }                                                                                   \
    } while (0)

#define DESC_FLOATS(base, field, want, detail, ...)                                                    \
    do {                                                                                               \
        const float values_[] = {__VA_ARGS__};                                                         \
        for (unsigned i_ = 0; i_ < sizeof values_ / sizeof values_[0]; i_++) {                         \
            mpca_desc d_ = (base);                                                                     \
            d_.field = values_[i_];                                                                    \
            set_context("%uD desc.%s = %g (at = %u)", (base).dim, #field, (double)values_[i_], at);    \
            desc_refused(&d_, (want), (detail));                                                       \
        }                                                                                              \
    } while (0)

/* "desc.NAME[k]": the detail naming entry `k` of an array field. */
static const char *indexed(const char *name, unsigned k) {
    static char text[64];
    snprintf(text, sizeof text, "desc.%s[%u]", name, k);
    return text;
}

static void description_cases(void) {
    const mpca_desc bases[2] = {full_desc(2, 16), full_desc(3, 8)};
    for (unsigned b = 0; b < 2; b++) {
        const mpca_desc base = bases[b];
        const uint32_t dim = base.dim;
        CHECK_OK(mpca_desc_validate(&base));

        DESC_VALUES(base, struct_size, MPCA_STATUS_BAD_STRUCT_SIZE, "desc.struct_size", 0, sizeof(mpca_desc) - 4,
                    sizeof(mpca_desc) + 4, UINT32_MAX);
        DESC_VALUES(base, dim, MPCA_STATUS_BAD_DIMENSION, "desc.dim", 0, 1, 4, UINT32_MAX);
        for (at = 0; at < dim; at++) {
            DESC_VALUES(base, size[at], MPCA_STATUS_SIZE_ZERO, indexed("size", at), 0);
            DESC_VALUES(base, size[at], MPCA_STATUS_SIZE_ODD, indexed("size", at), 1, 7, 15);
        }
        /* Every face, also the unused third axis of 2D: its value is still
         * an enumeration the library must know. */
        for (at = 0; at < 6; at++) {
            DESC_VALUES(base, boundary[at / 2][at % 2], MPCA_STATUS_BAD_ENUM, "desc.boundary", 3, UINT32_MAX);
        }
        for (at = 0; at < dim; at++) {
            DESC_VALUES(base, boundary[at][0], MPCA_STATUS_PERIODIC_MISMATCH, indexed("boundary", at), MPCA_BOUNDARY_PERIODIC);
            DESC_VALUES(base, boundary[at][1], MPCA_STATUS_PERIODIC_MISMATCH, indexed("boundary", at), MPCA_BOUNDARY_PERIODIC);
        }
        at = 0;
        DESC_VALUES(base, per_particle_mass, MPCA_STATUS_BAD_ENUM, "desc.per_particle_mass", 2, UINT32_MAX);
        DESC_VALUES(base, obstacles, MPCA_STATUS_BAD_ENUM, "desc.obstacles", 2, UINT32_MAX);
        DESC_VALUES(base, lifetimes, MPCA_STATUS_BAD_ENUM, "desc.lifetimes", 2, UINT32_MAX);
        DESC_VALUES(base, forces, MPCA_STATUS_BAD_ENUM, "desc.forces", 16, 0x80000000u, UINT32_MAX);
        DESC_VALUES(base, quantization, MPCA_STATUS_BAD_ENUM, "desc.quantization", 0, 1, 4, 32);
        DESC_VALUES(base, drift, MPCA_STATUS_BAD_ENUM, "desc.drift", 2, UINT32_MAX);
        DESC_VALUES(base, method, MPCA_STATUS_BAD_ENUM, "desc.method", 3, UINT32_MAX);
        DESC_VALUES(base, collisions, MPCA_STATUS_BAD_ENUM, "desc.collisions", 2, UINT32_MAX);
        DESC_VALUES(base, contacts, MPCA_STATUS_BAD_ENUM, "desc.contacts", 2, UINT32_MAX);
        DESC_VALUES(base, rest, MPCA_STATUS_BAD_ENUM, "desc.rest", 2, UINT32_MAX);
        DESC_VALUES(base, energy_neutral, MPCA_STATUS_BAD_ENUM, "desc.energy_neutral", 2, UINT32_MAX);
        DESC_VALUES(base, drag_vortex, MPCA_STATUS_BAD_ENUM, "desc.drag_vortex", 2, UINT32_MAX);
        DESC_VALUES(base, drag_wind_field, MPCA_STATUS_BAD_ENUM, "desc.drag_wind_field", 2, UINT32_MAX);
        DESC_VALUES(base, identity, MPCA_STATUS_BAD_ENUM, "desc.identity", 8, UINT32_MAX);
        DESC_VALUES(base, mass_classes, MPCA_STATUS_CAPACITY_RANGE, "desc.mass_classes", 0, 257, UINT32_MAX);

        /* Every float field, the third gravity component in 2D included. */
        DESC_FLOATS(base, mass, MPCA_STATUS_NOT_FINITE, "desc.mass", NAN, INFINITY, -INFINITY);
        for (at = 0; at < 3; at++) {
            DESC_FLOATS(base, gravity[at], MPCA_STATUS_NOT_FINITE, "desc.gravity", NAN, INFINITY, -INFINITY);
        }
        for (at = 0; at < 2; at++) {
            DESC_FLOATS(base, vortex_centre[at], MPCA_STATUS_NOT_FINITE, "desc.vortex", NAN, INFINITY, -INFINITY);
        }
        at = 0;
        DESC_FLOATS(base, vortex_core_radius, MPCA_STATUS_NOT_FINITE, "desc.vortex", NAN, INFINITY, -INFINITY);
        DESC_FLOATS(base, vortex_circulation, MPCA_STATUS_NOT_FINITE, "desc.vortex", NAN, INFINITY, -INFINITY);
        DESC_FLOATS(base, restitution, MPCA_STATUS_NOT_FINITE, "desc.restitution", NAN, INFINITY, -INFINITY);
        DESC_FLOATS(base, wall_restitution, MPCA_STATUS_NOT_FINITE, "desc.wall_restitution", NAN, INFINITY, -INFINITY);
        DESC_FLOATS(base, dt, MPCA_STATUS_NOT_FINITE, "desc.dt", NAN, INFINITY, -INFINITY);

        DESC_FLOATS(base, mass, MPCA_STATUS_MASS_RANGE, "desc.mass", 0.0f, -0.0f, -1.0f);
        DESC_FLOATS(base, restitution, MPCA_STATUS_RESTITUTION_RANGE, "desc.restitution", 1.5f, -0.1f, 1.0000001f);
        DESC_FLOATS(base, wall_restitution, MPCA_STATUS_RESTITUTION_RANGE, "desc.wall_restitution", 1.5f, -0.1f);
        DESC_FLOATS(base, dt, MPCA_STATUS_NEGATIVE_DT, "desc.dt", -1.0f, -1e-30f);
        DESC_FLOATS(base, vortex_core_radius, MPCA_STATUS_BAD_VORTEX, "desc.vortex.core_radius", 0.0f, -2.0f);
        DESC_FLOATS(base, drag_rate, MPCA_STATUS_NOT_FINITE, "desc.drag.rate", NAN, INFINITY, -INFINITY);
        DESC_FLOATS(base, drag_rate, MPCA_STATUS_BAD_DRAG, "desc.drag.rate", -1.0f, -1e-30f);
        DESC_FLOATS(base, drag_turbulence_amplitude, MPCA_STATUS_NOT_FINITE, "desc.drag.turbulence", NAN, INFINITY, -INFINITY);
        DESC_FLOATS(base, drag_turbulence_rate, MPCA_STATUS_NOT_FINITE, "desc.drag.turbulence", NAN, INFINITY);
        DESC_FLOATS(base, drag_turbulence_amplitude, MPCA_STATUS_BAD_DRAG, "desc.drag.turbulence.amplitude (0 to 1)", -0.5f, -1e-30f,
                    1.0001f, 2.0f);
        DESC_FLOATS(base, drag_turbulence_rate, MPCA_STATUS_BAD_DRAG, "desc.drag.turbulence.rate (0 to 1)", -0.1f, 1.5f);
        DESC_VALUES(base, drag_turbulence_scale, MPCA_STATUS_BAD_DRAG, "desc.drag.turbulence.scale (a power of two, 1 to 1024)", 0,
                    3, 12, 2048, UINT32_MAX);
        DESC_FLOATS(base, drag_rate, MPCA_STATUS_BAD_DRAG, "desc.drag.turbulence (needs desc.drag.rate above 0)", 0.0f);
        {
            /* A periodic first axis: the scale must divide its size. */
            mpca_desc periodic = base;
            periodic.boundary[0][0] = periodic.boundary[0][1] = MPCA_BOUNDARY_PERIODIC;
            CHECK_OK(mpca_desc_validate(&periodic));
            DESC_VALUES(periodic, drag_turbulence_scale, MPCA_STATUS_BAD_DRAG,
                        "desc.drag.turbulence.scale (must divide the size of every periodic axis)", 2 * base.size[0], 1024);
        }
        DESC_FLOATS(base, drag_wind[0], MPCA_STATUS_NOT_FINITE, "desc.drag.wind", NAN, INFINITY);
        DESC_FLOATS(base, drag_wind[1], MPCA_STATUS_SPEED_RANGE, "desc.drag.wind", 1.0001f, -2.0f);
    }

    /* 2^16 x 2^16 x 2 cells: more than a 32-bit cell index holds. */
    mpca_desc d = bases[1];
    d.size[0] = d.size[1] = 65536;
    d.size[2] = 2;
    set_context("3D desc of 2^33 cells");
    desc_refused(&d, MPCA_STATUS_TOO_LARGE, "desc.size");

    set_context("NULL descriptions and outputs");
    d = bases[0];
    size_t bytes = SENTINEL_SIZE;
    mpca_world *w = NULL;
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_defaults(NULL, 2, 8, 8, 0));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_preset(NULL, MPCA_PRESET_WATER, 2, 8, 8, 0));
    {
        /* An unknown preset leaves the description as it was. */
        mpca_desc kept = d;
        REFUSED(MPCA_STATUS_BAD_ENUM, mpca_desc_preset(&d, 3, 2, 8, 8, 0));
        REFUSED(MPCA_STATUS_BAD_ENUM, mpca_desc_preset(&d, UINT32_MAX, 3, 8, 8, 8));
        CHECK(memcmp(&kept, &d, sizeof d) == 0);
        /* A mass table beyond 16 bits is refused even with masses off:
         * the world could not report it back. */
        mpca_desc big = d;
        big.per_particle_mass = 0;
        big.mass_classes = 65536;
        set_context("desc.mass_classes = 65536, masses off");
        desc_refused(&big, MPCA_STATUS_CAPACITY_RANGE, "desc.mass_classes");
        for (uint32_t p = MPCA_PRESET_SMOKE; p <= MPCA_PRESET_SAND; p++) {
            mpca_desc preset;
            CHECK_OK(mpca_desc_preset(&preset, p, 3, 8, 8, 8));
            CHECK_OK(mpca_desc_validate(&preset));
        }
    }
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_validate(NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_bytes(NULL, &bytes));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_bytes(&d, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_init(NULL, pool, POOL_BYTES, &w));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_init(&d, NULL, POOL_BYTES, &w));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_init(&d, NULL, 0, &w));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_init(&d, pool, POOL_BYTES, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_create(NULL, &w));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_create(&d, NULL));
    CHECK(bytes == SENTINEL_SIZE && w == NULL);
}

/* --- Memory for mpca_world_init ------------------------------------------ */

/* mpca_world_bytes includes the slack for any alignment: `bytes` at every
 * start offset must work; too few bytes must be refused without a write
 * (each buffer is malloc'ed to its exact length, so ASan sees any write
 * past it). */
static void memory_cases(void) {
    mpca_desc d;
    size_t bytes = 0;
    CHECK_OK(mpca_desc_defaults(&d, 2, 8, 8, 0));
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    unsigned refused_short = 0;
    for (at = 0; at < 64; at++) {
        set_context("mpca_world_init at offset %u", at);
        unsigned char *raw = malloc(at + bytes);
        CHECK(raw != NULL);
        if (raw == NULL) {
            return;
        }
        mpca_world *w = NULL;
        /* Enough memory: accepted at every offset. */
        CHECK_OK(mpca_world_init(&d, raw + at, bytes, &w));
        uint32_t pos[3] = {1, 2, 0};
        float v[3] = {0.5f, 0, 0};
        CHECK_OK(mpca_world_add_particle(w, pos, v));
        CHECK_OK(mpca_world_step(w, 2));
        CHECK_OK(mpca_world_deinit(w));
        free(raw);

        /* One byte short: refused where the alignment slack is needed; where
         * it is not, the world must fit in what was given (ASan checks). */
        raw = malloc(at + bytes - 1);
        CHECK(raw != NULL);
        if (raw == NULL) {
            return;
        }
        memset(raw, SENTINEL_BYTE, at + bytes - 1);
        w = NULL;
        mpca_status st = TRACE(mpca_world_init(&d, raw + at, bytes - 1, &w));
        if (st == MPCA_STATUS_OK) {
            CHECK_OK(mpca_world_add_particle(w, pos, v));
            CHECK_OK(mpca_world_step(w, 2));
            CHECK_OK(mpca_world_deinit(w));
        } else {
            CHECK(st == MPCA_STATUS_BUFFER_TOO_SMALL);
            CHECK(w == NULL);
            size_t i = 0;
            while (i < at + bytes - 1 && raw[i] == SENTINEL_BYTE) {
                i++;
            }
            CHECK(i == at + bytes - 1);
            refused_short++;
            error_cases++;
        }
        free(raw);

        /* Far too little. */
        REFUSED(MPCA_STATUS_BUFFER_TOO_SMALL, mpca_world_init(&d, pool + at, 0, &w));
        REFUSED(MPCA_STATUS_BUFFER_TOO_SMALL, mpca_world_init(&d, pool + at, bytes / 2, &w));
    }
    /* Some offset in 64 needs the full slack. */
    CHECK(refused_short > 0);

    /* Lengths no buffer can have (more than PTRDIFF_MAX bytes). */
    set_context("mpca_world_init with a length beyond PTRDIFF_MAX");
    mpca_world *w = NULL;
    memset(pool, SENTINEL_BYTE, POOL_BYTES);
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_init(&d, pool, SIZE_MAX, &w));
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_init(&d, pool, (size_t)PTRDIFF_MAX + 1, &w));
    CHECK(w == NULL && pool[0] == SENTINEL_BYTE && pool[POOL_BYTES - 1] == SENTINEL_BYTE);
}

/* --- Handles ----------------------------------------------------------- */

/* Every function that takes a world, with valid other arguments, given the
 * handle `h`: each must return `want`. */
static void handle_sweep(mpca_world *h, mpca_status want, const char *kind) {
    set_context("handle: %s", kind);
    uint32_t pos[3] = {3, 3, 0}, res[3] = {2, 2, 1}, index = SENTINEL_U32;
    float v[3] = {0.1f, 0, 0}, n[3] = {0, 1, 0}, point[3] = {0, 1, 0}, lo[3] = {1, 1, 0}, hi[3] = {2, 2, 1};
    float out[CELLS2 * 3], normal[3] = {SENTINEL_FLOAT, SENTINEL_FLOAT, SENTINEL_FLOAT}, e = SENTINEL_FLOAT;
    unsigned char mask[CELLS2] = {0}, bytes[4];
    size_t count = SENTINEL_SIZE;
    mpca_emitter em = emitter_at(1, 1, 0, 2);
    mpca_particle p;
    mpca_cell c;
    mpca_desc d;
    mpca_stats s;
    uint64_t hash = SENTINEL_U32;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;

    REFUSED(want, mpca_world_add_emitter(h, &em, &index));
    REFUSED(want, mpca_world_set_emitter_rate(h, 0, 1.0f));
    REFUSED(want, mpca_world_set_gravity(h, v));
    REFUSED(want, mpca_world_set_force_field(h, field2, CELLS2 * 2));
    REFUSED(want, mpca_world_set_cell_force(h, pos, v));
    REFUSED(want, mpca_world_set_potential(h, potential2, CELLS2));
    REFUSED(want, mpca_world_set_cell_potential(h, pos, 1.0f));
    REFUSED(want, mpca_world_set_vortex(h, 1.0f, 1.0f, 1.0f, 1.0f));
    REFUSED(want, mpca_world_set_wind_field(h, field2, CELLS2 * 2));
    REFUSED(want, mpca_world_set_cell_wind(h, pos, v));
    REFUSED(want, mpca_world_add_obstacle(h, pos, n, 1.0f));
    REFUSED(want, mpca_world_add_half_space(h, point, n, 1.0f));
    REFUSED(want, mpca_world_add_box(h, lo, hi, 1.0f));
    REFUSED(want, mpca_world_add_disc(h, 4.0f, 4.0f, 1.0f, 1.0f));
    REFUSED(want, mpca_world_add_sphere(h, point, 1.0f, 1.0f));
    REFUSED(want, mpca_world_add_obstacle_mask(h, mask, CELLS2, 1.0f));
    REFUSED(want, mpca_world_surface(h, pos, normal, &e));
    REFUSED(want, mpca_world_add_particle(h, pos, v));
    REFUSED(want, mpca_world_add_particle_mass(h, pos, v, 1.0f));
    REFUSED(want, mpca_world_remove_particle(h, pos, &p));
    REFUSED(want, mpca_world_cell(h, pos, &c));
    REFUSED(want, mpca_world_particle_count(h, &count));
    REFUSED(want, mpca_world_export_positions(h, out, CELLS2, &count));
    REFUSED(want, mpca_world_export_velocities(h, out, CELLS2, &count));
    REFUSED(want, mpca_world_export_masses(h, out, CELLS2, &count));
    mpca_particle_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.struct_size = sizeof cols;
    cols.positions = out;
    REFUSED(want, mpca_world_export_particles(h, &cols, CELLS2, &count));
    REFUSED(want, mpca_world_set_tag(h, pos, 1));
    REFUSED(want, mpca_world_set_emitter_tag(h, 0, 1));
    REFUSED(want, mpca_world_density(h, res, out, 4));
    REFUSED(want, mpca_world_density_u8(h, res, bytes, 4));
    REFUSED(want, mpca_world_step(h, 1));
    REFUSED(want, mpca_world_desc(h, &d));
    REFUSED(want, mpca_world_stats(h, &s));
    REFUSED(want, mpca_world_hash(h, &hash));
    REFUSED(want, mpca_world_deinit(h));
    if (h == NULL) {
        CHECK_OK(mpca_world_destroy(NULL)); /* NULL is accepted by design */
    } else {
        REFUSED(want, mpca_world_destroy(h));
    }
    CHECK(index == SENTINEL_U32 && count == SENTINEL_SIZE && hash == SENTINEL_U32);
    CHECK(e == SENTINEL_FLOAT && normal[0] == SENTINEL_FLOAT);
    CHECK(s.step == 0 && s.particles == 0);
}

static void handle_cases(void) {
    handle_sweep(NULL, MPCA_STATUS_NULL_POINTER, "NULL");

    /* Forged: aligned memory that never held a world. */
    unsigned char *raw = malloc(8192 + 64), *forged = align64(raw);
    CHECK(raw != NULL);
    memset(forged, 0, 8192);
    handle_sweep((mpca_world *)(void *)forged, MPCA_STATUS_BAD_HANDLE, "forged, zeroed memory");
    memset(forged, SENTINEL_BYTE, 8192);
    handle_sweep((mpca_world *)(void *)forged, MPCA_STATUS_BAD_HANDLE, "forged, garbage memory");

    /* A byte-for-byte copy of a live world elsewhere is not a world, and
     * neither is the live world's own memory: a handle is what
     * mpca_world_init returned, not an address. Every 8-byte aligned
     * address where a world could start in either (it starts within the
     * first 5 + 64 bytes: 5 of misalignment, then the alignment slack). */
    unsigned char *copy_raw = malloc(full2_bytes + 5 + 64);
    CHECK(copy_raw != NULL);
    unsigned char *copy = align64(copy_raw);
    memcpy(copy, full2_memory, full2_bytes + 5);
    for (size_t offset = 0; offset < 5 + 64; offset++) {
        if ((uintptr_t)(copy + offset) % 8 == 0) {
            handle_sweep((mpca_world *)(void *)(copy + offset), MPCA_STATUS_BAD_HANDLE, "a copy of a live world");
        }
        if ((uintptr_t)(full2_memory + offset) % 8 == 0) {
            handle_sweep((mpca_world *)(void *)(full2_memory + offset), MPCA_STATUS_BAD_HANDLE,
                         "the memory of a live world");
        }
    }

    /* Near a live handle: misaligned, and aligned but not the handle. */
    handle_sweep((mpca_world *)(void *)((unsigned char *)full2 + 8), MPCA_STATUS_BAD_HANDLE, "live world + 8");
    handle_sweep((mpca_world *)(void *)((unsigned char *)full2 + 64), MPCA_STATUS_BAD_HANDLE, "live world + 64");

    /* Deinitialised, its memory still there. */
    mpca_desc d;
    size_t bytes = 0;
    mpca_world *w = NULL;
    CHECK_OK(mpca_desc_defaults(&d, 2, 8, 8, 0));
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    unsigned char *memory = malloc(bytes);
    CHECK(memory != NULL);
    CHECK_OK(mpca_world_init(&d, memory, bytes, &w));
    CHECK_OK(mpca_world_deinit(w));
    handle_sweep(w, MPCA_STATUS_BAD_HANDLE, "deinitialised");

    /* Deinitialised, its memory then freed: refused without a read of the
     * freed memory. 512 x 512 cells, so that free gives the block back to
     * the system and a read of it faults (ASan reports any size). */
    mpca_desc big;
    size_t big_bytes = 0;
    CHECK_OK(mpca_desc_defaults(&big, 2, 512, 512, 0));
    CHECK_OK(mpca_world_bytes(&big, &big_bytes));
    unsigned char *big_memory = malloc(big_bytes);
    CHECK(big_memory != NULL);
    mpca_world *gone = NULL;
    CHECK_OK(mpca_world_init(&big, big_memory, big_bytes, &gone));
    CHECK_OK(mpca_world_deinit(gone));
    free(big_memory);
    handle_sweep(gone, MPCA_STATUS_BAD_HANDLE, "deinitialised, memory freed");

    /* Destroyed, and destroyed twice (the sweep ends with a second
     * mpca_world_destroy). No world is created between the destroy and the
     * sweeps, so the address cannot hold a new world. */
    CHECK_OK(mpca_world_create(&d, &w));
    uint32_t pos[3] = {1, 1, 0};
    float v[3] = {0, 0.5f, 0};
    CHECK_OK(mpca_world_add_particle(w, pos, v));
    CHECK_OK(mpca_world_destroy(w));
    handle_sweep(w, MPCA_STATUS_BAD_HANDLE, "destroyed");
    handle_sweep(w, MPCA_STATUS_BAD_HANDLE, "destroyed twice");

    /* The wrong end of the life cycle: both refused, both worlds live on. */
    set_context("life cycle");
    REFUSED(MPCA_STATUS_BAD_HANDLE, mpca_world_deinit(full3));
    REFUSED(MPCA_STATUS_NOT_OWNED, mpca_world_destroy(full2));
    REFUSED(MPCA_STATUS_NOT_OWNED, mpca_world_destroy(small2));

    free(memory);
    free(copy_raw);
    free(raw);
}

/* --- NULL for every other pointer parameter ----------------------------- */

/* A shape of `kind`, every number 0 but the ones the caller sets. */
static mpca_shape shape_of(mpca_shape_kind kind) {
    mpca_shape s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    s.kind = kind;
    return s;
}

static void null_cases(void) {
    set_context("NULL arguments");
    mpca_world *w = full2;
    uint32_t free_cell[3] = {9, 9, 0}, particle[3] = {4, 8, 0}, surface[3] = {12, 12, 0}, res[3] = {2, 2, 1};
    uint32_t index = SENTINEL_U32;
    float v[3] = {0.1f, 0, 0}, up[3] = {0, 1, 0}, point[3] = {0, 2, 0}, lo[3] = {9, 9, 0}, hi[3] = {9.9f, 9.9f, 1};
    float out[CELLS2 * 3], normal[3], e;
    uint8_t bytes[4];
    size_t count = SENTINEL_SIZE;
    mpca_emitter em = emitter_at(4, 5, 0, 2);
    mpca_particle p;
    mpca_cell c;

    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_emitter(w, NULL, &index));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_emitter(w, &em, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_gravity(w, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_force_field(w, NULL, CELLS2 * 2));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_force_field(w, NULL, 0));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_cell_force(w, NULL, v));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_cell_force(w, free_cell, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_potential(w, NULL, CELLS2));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_cell_potential(w, NULL, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_wind_field(w, NULL, CELLS2 * 2));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_wind_field(w, NULL, 0));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_cell_wind(w, NULL, v));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_cell_wind(w, free_cell, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_obstacle(w, NULL, up, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_obstacle(w, free_cell, NULL, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_half_space(w, NULL, up, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_half_space(w, point, NULL, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_box(w, NULL, hi, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_box(w, lo, NULL, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_sphere(full3, NULL, 1.0f, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_obstacle_mask(w, NULL, CELLS2, 1.0f));
    mpca_shape shape = shape_of(MPCA_SHAPE_KIND_DISC);
    shape.a[0] = shape.a[1] = 9.5f;
    shape.radius = 0.5f;
    mpca_desc d = full_desc(2, N2);
    uint32_t entries = SENTINEL_U32;
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_shape(w, NULL, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_surface_entries(w, NULL, &entries));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_surface_entries(w, &shape, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_surface_entries(NULL, &shape, &entries));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_surface_entries(&d, NULL, &entries));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_surface_entries(&d, &shape, NULL));
    CHECK(entries == SENTINEL_U32);
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_surface(w, NULL, normal, &e));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_surface(w, surface, NULL, &e));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_surface(w, surface, normal, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_particle(w, NULL, v));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_particle(w, free_cell, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_particle_mass(w, NULL, v, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_particle_mass(w, free_cell, NULL, 1.0f));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_remove_particle(w, NULL, &p));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_remove_particle(w, particle, NULL)); /* must not remove it */
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_cell(w, NULL, &c));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_cell(w, particle, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_particle_count(w, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_positions(w, NULL, CELLS2, &count));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_positions(w, out, CELLS2, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_velocities(w, NULL, CELLS2, &count));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_velocities(w, out, CELLS2, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_masses(w, NULL, CELLS2, &count));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_masses(w, out, CELLS2, NULL));
    mpca_particle_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.struct_size = sizeof cols;
    cols.positions = out;
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_particles(w, NULL, CELLS2, &count));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_particles(w, &cols, CELLS2, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_set_tag(w, NULL, 1));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_density(w, NULL, out, 4));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_density(w, res, NULL, 4));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_density_u8(w, NULL, bytes, 4));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_density_u8(w, res, NULL, 4));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_desc(w, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_stats(w, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_hash(w, NULL));
    CHECK(index == SENTINEL_U32 && count == SENTINEL_SIZE);
}

/* --- Values ------------------------------------------------------------- */

static void emitter_cases(void) {
    uint32_t index = SENTINEL_U32;
    /* Valid in full3 (one slot free) and emit2 (fifteen free): only the
     * value under test is wrong in each case. */
    mpca_emitter e = emitter_at(4, 5, 0, 2);
    mpca_world *const worlds[2] = {full3, emit2};

    for (unsigned i = 0; i < 2; i++) {
        mpca_world *w = worlds[i];
        unsigned dim = w == full3 ? 3 : 2;
        at = 0;
        EACH_BAD(e.rate, MPCA_STATUS_NOT_FINITE, mpca_world_add_emitter(w, &e, &index));
        EACH_BAD(e.spread, MPCA_STATUS_NOT_FINITE, mpca_world_add_emitter(w, &e, &index));
        EACH_BAD(e.mass, MPCA_STATUS_NOT_FINITE, mpca_world_add_emitter(w, &e, &index));
        /* All three components: the header promises NaN is refused, and
         * mpca_world_add_particle refuses it in the third even in 2D. */
        for (at = 0; at < 3; at++) {
            EACH_BAD(e.velocity[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_emitter(w, &e, &index));
        }
        set_context("%uD emitter values", dim);
        mpca_emitter x = e;
        x.struct_size = 0;
        REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_add_emitter(w, &x, &index));
        x.struct_size = sizeof x - 4;
        REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_add_emitter(w, &x, &index));
        x.struct_size = sizeof x + 4;
        REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_add_emitter(w, &x, &index));
        x = e;
        x.rate = -0.5f;
        REFUSED(MPCA_STATUS_BAD_EMITTER, mpca_world_add_emitter(w, &x, &index));
        x = e;
        x.spread = -0.1f;
        REFUSED(MPCA_STATUS_BAD_EMITTER, mpca_world_add_emitter(w, &x, &index));
        for (at = 0; at < dim; at++) {
            set_context("%uD emitter region, axis %u", dim, at);
            x = e;
            x.max[at] = x.min[at]; /* empty */
            REFUSED(MPCA_STATUS_BAD_EMITTER, mpca_world_add_emitter(w, &x, &index));
            x.max[at] = x.min[at] - 1; /* reversed */
            REFUSED(MPCA_STATUS_BAD_EMITTER, mpca_world_add_emitter(w, &x, &index));
            x = e;
            x.max[at] = dim == 3 ? N3 + 1 : N2 + 1; /* beyond the world */
            REFUSED(MPCA_STATUS_BAD_EMITTER, mpca_world_add_emitter(w, &x, &index));
        }
        set_context("%uD emitter ranges", dim);
        x = e;
        x.velocity[0] = 0.8f;
        x.velocity[1] = 0.7f;
        x.spread = 0;
        REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_emitter(w, &x, &index));
        x = e;
        x.velocity[0] = 0.5f;
        x.velocity[1] = x.velocity[2] = 0;
        x.spread = 0.6f; /* |v| + spread > 1 */
        REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_emitter(w, &x, &index));
        /* |v| + spread above 1 by less than a float's spacing at 1: a sum
         * in float rounds both to 1. */
        x.spread = nextafterf(0.5f, 1.0f);
        REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_emitter(w, &x, &index));
        x.velocity[0] = 0;
        x.velocity[1] = 0.75f;
        x.spread = nextafterf(0.25f, 1.0f);
        REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_emitter(w, &x, &index));
        x = e;
        x.lifetime = 65536;
        REFUSED(MPCA_STATUS_LIFETIME_RANGE, mpca_world_add_emitter(w, &x, &index));
        x = e;
        x.mass = 0;
        REFUSED(MPCA_STATUS_MASS_RANGE, mpca_world_add_emitter(w, &x, &index));
        x.mass = -1;
        REFUSED(MPCA_STATUS_MASS_RANGE, mpca_world_add_emitter(w, &x, &index));
        x.mass = 3; /* the table {1, 2} is full */
        REFUSED(MPCA_STATUS_MASS_TABLE_FULL, mpca_world_add_emitter(w, &x, &index));
        CHECK(index == SENTINEL_U32);
    }

    set_context("emitters in a world without lifetimes and emitters");
    mpca_emitter x = emitter_at(2, 2, 0, 2);
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_emitter(bare2, &x, &index)); /* lifetime 30 */
    x.lifetime = 0;
    /* No room for emitters at all (emitter_capacity 0): the part is off,
     * not a full table. */
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_emitter(bare2, &x, &index));
    x.mass = 2;
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_emitter(bare2, &x, &index));

    set_context("emitter table full");
    CHECK_OK(mpca_world_add_emitter(full2, &e, &index)); /* the second slot */
    CHECK(index == 1);
    index = SENTINEL_U32;
    REFUSED(MPCA_STATUS_EMITTER_TABLE_FULL, mpca_world_add_emitter(full2, &e, &index));
    CHECK(index == SENTINEL_U32);

    float rate = 1.0f;
    at = 0;
    EACH_BAD(rate, MPCA_STATUS_NOT_FINITE, mpca_world_set_emitter_rate(full2, 0, rate));
    set_context("emitter rate");
    REFUSED(MPCA_STATUS_BAD_EMITTER, mpca_world_set_emitter_rate(full2, 0, -1.0f));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_set_emitter_rate(full2, 2, 1.0f));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_set_emitter_rate(full2, UINT32_MAX, 1.0f));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_set_emitter_rate(bare2, 0, 1.0f));
    /* Per-emitter counts: full2 has two emitters by now, bare2 none. */
    uint64_t requested = SENTINEL_U32, delivered = SENTINEL_U32;
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_emitter_stats(full2, 2, &requested, &delivered));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_emitter_stats(full2, UINT32_MAX, &requested, &delivered));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_emitter_stats(bare2, 0, &requested, &delivered));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_emitter_stats(full2, 0, NULL, &delivered));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_emitter_stats(full2, 0, &requested, NULL));
    CHECK(requested == SENTINEL_U32 && delivered == SENTINEL_U32);
    CHECK_OK(mpca_world_emitter_stats(full2, 0, &requested, &delivered));
    CHECK(requested != SENTINEL_U32 && delivered <= requested);
}

/* Positions outside world `w` of `dim` dimensions and side `n`: each axis
 * at the size and at UINT32_MAX, and z = 1 in 2D (whose only z is 0). */
#define EACH_OUTSIDE(pos, dim, n, call)                                                 \
    do {                                                                                \
        for (at = 0; at < 3; at++) {                                                    \
            const uint32_t outside_[2] = {(at < (dim)) ? (n) : 1, UINT32_MAX};           \
            for (unsigned o_ = 0; o_ < 2; o_++) {                                       \
                uint32_t saved_ = (pos)[at];                                            \
                (pos)[at] = outside_[o_];                                               \
                set_context("%s[%u] = %u", #pos, at, outside_[o_]);                     \
                REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, call);                               \
                (pos)[at] = saved_;                                                     \
            }                                                                           \
        }                                                                               \
    } while (0)

static void force_cases(void) {
    struct {
        mpca_world *w;
        unsigned dim, n, cells;
        float *field, *potential;
    } const worlds[2] = {{full2, 2, N2, CELLS2, field2, potential2}, {full3, 3, N3, CELLS3, field3, potential3}};

    for (unsigned i = 0; i < 2; i++) {
        mpca_world *w = worlds[i].w;
        const unsigned dim = worlds[i].dim, n = worlds[i].n, cells = worlds[i].cells;
        float *field = worlds[i].field, *potential = worlds[i].potential;
        float g[3] = {0, -0.01f, 0}, f[3] = {0.01f, 0.01f, 0.01f};
        uint32_t pos[3] = {1, 2, dim == 3 ? 3 : 0};

        for (at = 0; at < 3; at++) {
            EACH_BAD(g[at], MPCA_STATUS_NOT_FINITE, mpca_world_set_gravity(w, g));
            EACH_BAD(f[at], MPCA_STATUS_NOT_FINITE, mpca_world_set_cell_force(w, pos, f));
        }
        const unsigned elements[3] = {0, 1, cells * dim - 1};
        for (unsigned j = 0; j < 3; j++) {
            at = elements[j];
            EACH_BAD(field[at], MPCA_STATUS_NOT_FINITE, mpca_world_set_force_field(w, field, cells * dim));
        }
        const unsigned cells_at[2] = {0, cells - 1};
        for (unsigned j = 0; j < 2; j++) {
            at = cells_at[j];
            EACH_BAD(potential[at], MPCA_STATUS_NOT_FINITE, mpca_world_set_potential(w, potential, cells));
        }
        float u = 0.5f, cx = 2, cy = 2, core = 1, circulation = 0.1f;
        at = 0;
        EACH_BAD(u, MPCA_STATUS_NOT_FINITE, mpca_world_set_cell_potential(w, pos, u));
        EACH_BAD(cx, MPCA_STATUS_NOT_FINITE, mpca_world_set_vortex(w, cx, cy, core, circulation));
        EACH_BAD(cy, MPCA_STATUS_NOT_FINITE, mpca_world_set_vortex(w, cx, cy, core, circulation));
        EACH_BAD(core, MPCA_STATUS_NOT_FINITE, mpca_world_set_vortex(w, cx, cy, core, circulation));
        EACH_BAD(circulation, MPCA_STATUS_NOT_FINITE, mpca_world_set_vortex(w, cx, cy, core, circulation));

        set_context("%uD force ranges and lengths", dim);
        REFUSED(MPCA_STATUS_BAD_VORTEX, mpca_world_set_vortex(w, cx, cy, 0.0f, circulation));
        REFUSED(MPCA_STATUS_BAD_VORTEX, mpca_world_set_vortex(w, cx, cy, -1.0f, circulation));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_force_field(w, field, cells * dim - 1));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_force_field(w, field, cells));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_force_field(w, field, 0));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_potential(w, potential, cells - 1));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_potential(w, potential, 0));
        /* Lengths no array can have (more than PTRDIFF_MAX bytes). */
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_force_field(w, field, SIZE_MAX));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_force_field(w, field, (size_t)PTRDIFF_MAX / sizeof(float) + 1));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_potential(w, potential, SIZE_MAX));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_potential(w, potential, (size_t)PTRDIFF_MAX / sizeof(float) + 1));
        EACH_OUTSIDE(pos, dim, n, mpca_world_set_cell_force(w, pos, f));
        EACH_OUTSIDE(pos, dim, n, mpca_world_set_cell_potential(w, pos, u));

        /* M5.1b's wind plane: finite, no cell faster than 1, whole. The
         * world's plane holds `field` (every speed far below 1). */
        set_context("%uD wind plane", dim);
        float wind[3] = {0.1f, -0.2f, 0.05f};
        for (at = 0; at < 3; at++) {
            EACH_BAD(wind[at], MPCA_STATUS_NOT_FINITE, mpca_world_set_cell_wind(w, pos, wind));
        }
        for (unsigned j = 0; j < 3; j++) {
            at = elements[j];
            EACH_BAD(field[at], MPCA_STATUS_NOT_FINITE, mpca_world_set_wind_field(w, field, cells * dim));
        }
        float fast[3] = {0.8f, 0.7f, 0.0f}, faster[3] = {1.0001f, 0.0f, 0.0f};
        REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_set_cell_wind(w, pos, fast));
        REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_set_cell_wind(w, pos, faster));
        for (unsigned j = 0; j < 3; j++) {
            at = elements[j];
            float saved = field[at];
            field[at] = -1.5f;
            REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_set_wind_field(w, field, cells * dim));
            field[at] = saved;
        }
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_wind_field(w, field, cells * dim - 1));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_wind_field(w, field, cells));
        REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_set_wind_field(w, field, SIZE_MAX));
        EACH_OUTSIDE(pos, dim, n, mpca_world_set_cell_wind(w, pos, wind));
    }

    set_context("forces in a world without them");
    float g[3] = {0, -0.01f, 0};
    uint32_t pos[3] = {1, 1, 0};
    float small_field[64 * 2] = {0}, small_potential[64] = {0};
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_gravity(bare2, g));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_force_field(bare2, small_field, 64 * 2));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_cell_force(bare2, pos, g));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_potential(bare2, small_potential, 64));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_cell_potential(bare2, pos, 1.0f));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_vortex(bare2, 1.0f, 1.0f, 1.0f, 1.0f));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_wind_field(bare2, small_field, 64 * 2));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_cell_wind(bare2, pos, g));
}

/* Shapes as one value (mpca_shape): the surface entries one takes, asked
 * of a description and of a world, refused as adding it would be. */
static void shape_cases(void) {
    set_context("mpca_shape");
    mpca_shape disc = shape_of(MPCA_SHAPE_KIND_DISC);
    disc.a[0] = 9.5f;
    disc.a[1] = 9.5f;
    disc.radius = 1.5f;
    mpca_desc d = full_desc(2, N2);
    uint32_t entries = SENTINEL_U32, now = SENTINEL_U32;
    CHECK_OK(mpca_desc_surface_entries(&d, &disc, &entries));
    CHECK(entries > 0 && entries != SENTINEL_U32);
    /* full2's obstacles are away from the disc: the same count. */
    CHECK_OK(mpca_world_surface_entries(full2, &disc, &now));
    CHECK(now == entries);
    /* A world of exactly that capacity takes it; one entry fewer, not. */
    mpca_world *w = NULL;
    CHECK_OK(mpca_desc_defaults(&d, 2, N2, N2, 0));
    d.obstacles = 1;
    d.surface_capacity = entries - 1;
    CHECK_OK(mpca_world_create(&d, &w));
    REFUSED(MPCA_STATUS_SURFACE_TABLE_FULL, mpca_world_add_shape(w, &disc, 1.0f));
    CHECK_OK(mpca_world_destroy(w));
    d.surface_capacity = entries;
    CHECK_OK(mpca_world_create(&d, &w));
    CHECK_OK(mpca_world_add_shape(w, &disc, 1.0f));
    /* The same disc again covers only obstacle cells: nothing new. */
    CHECK_OK(mpca_world_surface_entries(w, &disc, &now));
    CHECK(now == 0);
    CHECK_OK(mpca_world_destroy(w));

    mpca_shape bad = disc;
    uint32_t out = SENTINEL_U32;
    bad.kind = 5;
    REFUSED(MPCA_STATUS_BAD_ENUM, mpca_desc_surface_entries(&d, &bad, &out));
    REFUSED(MPCA_STATUS_BAD_ENUM, mpca_world_surface_entries(full2, &bad, &out));
    REFUSED(MPCA_STATUS_BAD_ENUM, mpca_world_add_shape(full2, &bad, 1.0f));
    bad = disc;
    bad.struct_size = sizeof bad - 4;
    REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_desc_surface_entries(&d, &bad, &out));
    REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_add_shape(full2, &bad, 1.0f));
    bad = disc;
    bad.kind = MPCA_SHAPE_KIND_SPHERE;
    REFUSED(MPCA_STATUS_BAD_DIMENSION, mpca_world_surface_entries(full2, &bad, &out));
    REFUSED(MPCA_STATUS_BAD_DIMENSION, mpca_world_add_shape(full2, &bad, 1.0f));
    bad = disc;
    bad.radius = -1.0f;
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_desc_surface_entries(&d, &bad, &out));
    bad.radius = NAN;
    REFUSED(MPCA_STATUS_NOT_FINITE, mpca_world_add_shape(full2, &bad, 1.0f));
    bad = disc;
    bad.kind = MPCA_SHAPE_KIND_BOX;
    bad.a[0] = 4.0f; /* the box (4, 8)..(4.9, 8.9) holds the particle at (4, 8) */
    bad.a[1] = 8.0f;
    bad.b[0] = 4.9f;
    bad.b[1] = 8.9f;
    bad.b[2] = 1.0f;
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_surface_entries(full2, &bad, &out));
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_shape(full2, &bad, 1.0f));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_surface_entries(bare2, &disc, &out));
    mpca_desc plain;
    CHECK_OK(mpca_desc_defaults(&plain, 2, N2, N2, 0));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_desc_surface_entries(&plain, &disc, &out));
    plain.size[0] = 15;
    REFUSED(MPCA_STATUS_SIZE_ODD, mpca_desc_surface_entries(&plain, &disc, &out));
    CHECK(out == SENTINEL_U32);
    /* A half-space by mpca_world_add_shape is mpca_world_add_half_space. */
    mpca_shape floor = shape_of(MPCA_SHAPE_KIND_HALF_SPACE);
    floor.a[1] = 2.0f;
    floor.b[1] = 1.0f;
    CHECK_OK(mpca_world_surface_entries(full2, &floor, &now));
    CHECK(now == 0); /* full2 has this floor already */
}

/* --- Bodies (M13) ------------------------------------------------------ */

static void body_cases(void) {
    set_context("bodies: a world with room for two");
    mpca_desc d;
    CHECK_OK(mpca_desc_defaults(&d, 2, N2, N2, 0));
    d.boundary[0][0] = d.boundary[0][1] = MPCA_BOUNDARY_WALL;
    d.obstacles = 1;
    d.surface_capacity = 16;
    d.body_capacity = 2;
    d.body_surface_capacity = 24;
    CHECK_OK(mpca_world_create(&d, &body2));
    mpca_world *w = body2;
    watch(w);
    uint32_t pos[3] = {6, 6, 0};
    float v[3] = {0.25f, 0, 0}, u[3] = {0.5f, 0, 0}, still[3] = {0, 0, 0};
    CHECK_OK(mpca_world_add_particle(w, pos, v));
    mpca_shape disc = shape_of(MPCA_SHAPE_KIND_DISC);
    disc.a[0] = 6.0f;
    disc.a[1] = 6.5f;
    disc.radius = 0.9f;
    /* Its entries, known before: the description's count is what the
     * body takes (the table has room for it). */
    uint32_t entries = SENTINEL_U32;
    CHECK_OK(mpca_desc_body_surface_entries(&d, &disc, &entries));
    CHECK(entries > 0 && entries <= d.body_surface_capacity);
    uint32_t id = SENTINEL_U32;
    CHECK_OK(mpca_world_add_body(w, &disc, u, 0.5f, &id));
    CHECK(id == 0);
    /* The disc took the particle's cell: pushed, none lost. */
    mpca_cell c;
    CHECK_OK(mpca_world_cell(w, pos, &c));
    CHECK(c.kind == MPCA_CELL_KIND_OBSTACLE);
    size_t count = 0;
    CHECK_OK(mpca_world_particle_count(w, &count));
    CHECK(count == 1);
    CHECK_OK(mpca_world_step(w, 1));
    mpca_body_stats b;
    memset(&b, 0, sizeof b);
    b.struct_size = sizeof b;
    CHECK_OK(mpca_world_body_stats(w, id, &b));
    CHECK(b.pushed == 1 && b.crushed == 0);
    mpca_shape capsule = shape_of(MPCA_SHAPE_KIND_CAPSULE);
    capsule.a[0] = 10.0f;
    capsule.a[1] = 10.0f;
    capsule.b[0] = 12.0f;
    capsule.b[1] = 11.0f;
    capsule.radius = 0.8f;
    CHECK_OK(mpca_world_move_body(w, id, &capsule, still));

    set_context("bodies: refusals");
    uint32_t out = SENTINEL_U32;
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_body(NULL, &disc, u, 1.0f, &out));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_body(w, NULL, u, 1.0f, &out));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_body(w, &disc, NULL, 1.0f, &out));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_add_body(w, &disc, u, 1.0f, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_move_body(w, id, NULL, u));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_move_body(w, id, &disc, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_remove_body(NULL, id));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_body_stats(w, id, NULL));
    mpca_shape bad = disc;
    bad.kind = 5;
    REFUSED(MPCA_STATUS_BAD_ENUM, mpca_world_add_body(w, &bad, u, 1.0f, &out));
    bad = disc;
    bad.struct_size = sizeof bad + 4;
    REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_move_body(w, id, &bad, u));
    bad = disc;
    bad.radius = 0.0f;
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_body(w, &bad, u, 1.0f, &out));
    bad.radius = NAN;
    REFUSED(MPCA_STATUS_NOT_FINITE, mpca_world_move_body(w, id, &bad, u));
    float fast[3] = {0.8f, 0.8f, 0};
    REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_body(w, &disc, fast, 1.0f, &out));
    REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_move_body(w, id, &disc, fast));
    REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_body(w, &disc, u, 1.5f, &out));
    bad = disc;
    bad.radius = 6.0f;
    REFUSED(MPCA_STATUS_SURFACE_TABLE_FULL, mpca_world_add_body(w, &bad, u, 1.0f, &out));
    REFUSED(MPCA_STATUS_NO_BODY, mpca_world_move_body(w, 1, &disc, u));
    REFUSED(MPCA_STATUS_NO_BODY, mpca_world_remove_body(w, 7));
    REFUSED(MPCA_STATUS_NO_BODY, mpca_world_body_stats(w, 1, &b));
    b.struct_size = sizeof b - 8;
    REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_body_stats(w, id, &b));
    b.struct_size = sizeof b;
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_body(full2, &disc, u, 1.0f, &out));
    mpca_desc no_bodies = d;
    no_bodies.body_capacity = 0;
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_desc_body_surface_entries(&no_bodies, &disc, &out));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_body_surface_entries(NULL, &disc, &out));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_body_surface_entries(&d, NULL, &out));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_desc_body_surface_entries(&d, &disc, NULL));
    bad = disc;
    bad.kind = 5;
    REFUSED(MPCA_STATUS_BAD_ENUM, mpca_desc_body_surface_entries(&d, &bad, &out));
    bad = disc;
    bad.radius = -1.0f;
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_desc_body_surface_entries(&d, &bad, &out));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_body_stats(full2, 0, &b));
    CHECK(out == SENTINEL_U32);
    disc.a[0] = 20.0f;
    CHECK_OK(mpca_world_add_body(w, &disc, still, 1.0f, &out));
    disc.a[0] = 24.0f;
    REFUSED(MPCA_STATUS_BODY_TABLE_FULL, mpca_world_add_body(w, &disc, still, 1.0f, &id));
    CHECK_OK(mpca_world_remove_body(w, out));
}

static void obstacle_cases(void) {
    /* In full2: free cell (9, 9), particle (4, 8), surface cell (12, 12),
     * floor rows 0 and 1. In full3: free cell (1, 3, 1). */
    uint32_t cell2[3] = {9, 9, 0}, particle2[3] = {4, 8, 0}, cell3[3] = {1, 3, 1};
    float n[3] = {0, 1, 0.5f}, e = 0.5f;
    float point[3] = {0, 2, 0}, lo[3] = {9, 9, 0}, hi[3] = {9.9f, 9.9f, 1}, centre[3] = {4, 4, 4};
    float cx = 9.5f, cy = 9.5f, r = 0.5f, radius = 1.0f;
    unsigned char mask2[CELLS2] = {0}, mask3[CELLS3] = {0};
    mask2[9 * N2 + 9] = 1;
    mask3[1 * N3 * N3 + 3 * N3 + 1] = 1;

    for (at = 0; at < 3; at++) {
        EACH_BAD(n[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_obstacle(full2, cell2, n, e));
        EACH_BAD(n[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_obstacle(full3, cell3, n, e));
        EACH_BAD(point[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_half_space(full2, point, n, e));
        EACH_BAD(n[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_half_space(full2, point, n, e));
        EACH_BAD(n[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_half_space(full3, point, n, e));
        EACH_BAD(lo[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_box(full2, lo, hi, e));
        EACH_BAD(hi[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_box(full2, lo, hi, e));
        EACH_BAD(centre[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_sphere(full3, centre, radius, e));
    }
    at = 0;
    EACH_BAD(cx, MPCA_STATUS_NOT_FINITE, mpca_world_add_disc(full2, cx, cy, r, e));
    EACH_BAD(cy, MPCA_STATUS_NOT_FINITE, mpca_world_add_disc(full2, cx, cy, r, e));
    EACH_BAD(r, MPCA_STATUS_NOT_FINITE, mpca_world_add_disc(full2, cx, cy, r, e));
    EACH_BAD(radius, MPCA_STATUS_NOT_FINITE, mpca_world_add_sphere(full3, centre, radius, e));
    /* The restitution of every obstacle call: not finite, then out of [0, 1]. */
    const float outside[3] = {1.5f, -0.5f, 1.0000001f};
    EACH_BAD(e, MPCA_STATUS_NOT_FINITE, mpca_world_add_obstacle(full2, cell2, n, e));
    EACH_BAD(e, MPCA_STATUS_NOT_FINITE, mpca_world_add_half_space(full2, point, n, e));
    EACH_BAD(e, MPCA_STATUS_NOT_FINITE, mpca_world_add_box(full2, lo, hi, e));
    EACH_BAD(e, MPCA_STATUS_NOT_FINITE, mpca_world_add_disc(full2, cx, cy, r, e));
    EACH_BAD(e, MPCA_STATUS_NOT_FINITE, mpca_world_add_sphere(full3, centre, radius, e));
    EACH_BAD(e, MPCA_STATUS_NOT_FINITE, mpca_world_add_obstacle_mask(full2, mask2, CELLS2, e));
    for (at = 0; at < 3; at++) {
        set_context("restitution %g", (double)outside[at]);
        REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_obstacle(full2, cell2, n, outside[at]));
        REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_half_space(full2, point, n, outside[at]));
        REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_box(full2, lo, hi, outside[at]));
        REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_disc(full2, cx, cy, r, outside[at]));
        REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_sphere(full3, centre, radius, outside[at]));
        REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_obstacle_mask(full2, mask2, CELLS2, outside[at]));
        REFUSED(MPCA_STATUS_RESTITUTION_RANGE, mpca_world_add_obstacle_mask(full3, mask3, CELLS3, outside[at]));
    }

    set_context("degenerate shapes and normals");
    float zero[3] = {0, 0, 0}, z_only[3] = {0, 0, 1};
    REFUSED(MPCA_STATUS_UNDEFINED_NORMAL, mpca_world_add_obstacle(full2, cell2, zero, e));
    REFUSED(MPCA_STATUS_UNDEFINED_NORMAL, mpca_world_add_obstacle(full2, cell2, z_only, e)); /* no z in 2D */
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_half_space(full2, point, z_only, e));       /* nor here */
    REFUSED(MPCA_STATUS_UNDEFINED_NORMAL, mpca_world_add_obstacle(full3, cell3, zero, e));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_half_space(full2, point, zero, e));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_half_space(full3, point, zero, e));
    float rev_lo[3] = {9.9f, 9, 0}, rev_hi[3] = {9, 9.9f, 1};
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_box(full2, rev_lo, rev_hi, e));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_box(full2, rev_hi, rev_lo, e));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_disc(full2, cx, cy, 0.0f, e));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_disc(full2, cx, cy, -1.0f, e));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_sphere(full3, centre, 0.0f, e));
    REFUSED(MPCA_STATUS_BAD_SHAPE, mpca_world_add_sphere(full3, centre, -1.0f, e));
    REFUSED(MPCA_STATUS_BAD_DIMENSION, mpca_world_add_disc(full3, cx, cy, r, e));
    REFUSED(MPCA_STATUS_BAD_DIMENSION, mpca_world_add_sphere(full2, centre, radius, e));
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_add_obstacle_mask(full2, mask2, CELLS2 - 1, e));
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_add_obstacle_mask(full2, mask2, CELLS2 + 1, e));
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_add_obstacle_mask(full3, mask3, CELLS3 - 1, e));
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_add_obstacle_mask(full2, mask2, SIZE_MAX, e));
    REFUSED(MPCA_STATUS_BAD_LENGTH, mpca_world_add_obstacle_mask(full2, mask2, (size_t)PTRDIFF_MAX + 1, e));
    /* A wall one cell thick across the world: free on both sides, so the
     * normal of its inner cells vanishes (M7). */
    unsigned char wall[CELLS2] = {0};
    for (unsigned x = 0; x < N2; x++) {
        wall[12 * N2 + x] = 1;
    }
    REFUSED(MPCA_STATUS_UNDEFINED_NORMAL, mpca_world_add_obstacle_mask(full2, wall, CELLS2, e));

    set_context("obstacles over particles, outside, without room");
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_obstacle(full2, particle2, n, e));
    float above[3] = {0, 8.5f, 0}; /* every cell with y <= 8 */
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_half_space(full2, above, n, e));
    float p_lo[3] = {4, 8, 0}, p_hi[3] = {4.9f, 8.9f, 1};
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_box(full2, p_lo, p_hi, e));
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_disc(full2, 4.5f, 8.5f, 0.5f, e));
    unsigned char over[CELLS2] = {0};
    over[8 * N2 + 4] = 1;
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_obstacle_mask(full2, over, CELLS2, e));
    EACH_OUTSIDE(cell2, 2, N2, mpca_world_add_obstacle(full2, cell2, n, e));
    EACH_OUTSIDE(cell3, 3, N3, mpca_world_add_obstacle(full3, cell3, n, e));
    set_context("surface table full");
    float s_lo[3] = {2, 2, 0}, s_hi[3] = {3.9f, 3.9f, 1}; /* four cells, four surfaces */
    REFUSED(MPCA_STATUS_SURFACE_TABLE_FULL, mpca_world_add_box(small2, s_lo, s_hi, e));
    set_context("obstacles in a world without them");
    uint32_t bare_cell[3] = {3, 3, 0};
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_obstacle(bare2, bare_cell, n, e));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_half_space(bare2, point, n, e));
    float b_lo[3] = {3, 3, 0}, b_hi[3] = {3.9f, 3.9f, 1};
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_box(bare2, b_lo, b_hi, e));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_disc(bare2, 4.0f, 4.0f, 1.0f, e));
    unsigned char bare_mask[64] = {0};
    bare_mask[3 * 8 + 3] = 1;
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_obstacle_mask(bare2, bare_mask, 64, e));

    shape_cases();

    set_context("surface queries");
    uint32_t empty[3] = {9, 9, 0}, inner[3] = {5, 0, 0}, surface[3] = {12, 12, 0};
    float normal[3] = {SENTINEL_FLOAT, SENTINEL_FLOAT, SENTINEL_FLOAT}, restitution = SENTINEL_FLOAT;
    REFUSED(MPCA_STATUS_NOT_A_SURFACE, mpca_world_surface(full2, empty, normal, &restitution));
    REFUSED(MPCA_STATUS_NOT_A_SURFACE, mpca_world_surface(full2, particle2, normal, &restitution));
    REFUSED(MPCA_STATUS_NOT_A_SURFACE, mpca_world_surface(full2, inner, normal, &restitution)); /* floor, row 0 */
    REFUSED(MPCA_STATUS_NOT_A_SURFACE, mpca_world_surface(bare2, bare_cell, normal, &restitution));
    EACH_OUTSIDE(surface, 2, N2, mpca_world_surface(full2, surface, normal, &restitution));
    CHECK(normal[0] == SENTINEL_FLOAT && normal[1] == SENTINEL_FLOAT && normal[2] == SENTINEL_FLOAT);
    CHECK(restitution == SENTINEL_FLOAT);
    /* And a real one, to show the query works: the single obstacle's normal. */
    CHECK_OK(mpca_world_surface(full2, surface, normal, &restitution));
    CHECK(normal[0] == 0 && normal[1] == 1 && normal[2] == 0 && restitution == 0.9f);
}

static void particle_cases(void) {
    uint32_t free2[3] = {9, 9, 0}, free3[3] = {1, 3, 1}, particle2[3] = {4, 8, 0}, obstacle2[3] = {12, 12, 0};
    uint32_t free_bare[3] = {3, 3, 0};
    float v[3] = {0.1f, 0.2f, 0.1f}, m = 2.0f;

    for (at = 0; at < 3; at++) {
        EACH_BAD(v[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_particle(full2, free2, v));
        EACH_BAD(v[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_particle(full3, free3, v));
        EACH_BAD(v[at], MPCA_STATUS_NOT_FINITE, mpca_world_add_particle_mass(full3, free3, v, m));
    }
    at = 0;
    EACH_BAD(m, MPCA_STATUS_NOT_FINITE, mpca_world_add_particle_mass(full2, free2, v, m));
    EACH_BAD(m, MPCA_STATUS_NOT_FINITE, mpca_world_add_particle_mass(full3, free3, v, m));
    EACH_BAD(m, MPCA_STATUS_NOT_FINITE, mpca_world_add_particle_mass(bare2, free_bare, v, m));

    set_context("particle ranges");
    float fast2[3] = {0.8f, 0.7f, 0}, fast3[3] = {0.6f, 0.6f, 0.6f}, just_over[3] = {1.0001f, 0, 0};
    REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_particle(full2, free2, fast2));
    REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_particle(full2, free2, just_over));
    REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_particle(full3, free3, fast3));
    REFUSED(MPCA_STATUS_SPEED_RANGE, mpca_world_add_particle_mass(full3, free3, fast3, 1.0f));
    REFUSED(MPCA_STATUS_MASS_RANGE, mpca_world_add_particle_mass(full2, free2, v, 0.0f));
    REFUSED(MPCA_STATUS_MASS_RANGE, mpca_world_add_particle_mass(full2, free2, v, -0.0f));
    REFUSED(MPCA_STATUS_MASS_RANGE, mpca_world_add_particle_mass(full2, free2, v, -2.0f));
    REFUSED(MPCA_STATUS_MASS_TABLE_FULL, mpca_world_add_particle_mass(full2, free2, v, 3.0f));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_add_particle_mass(bare2, free_bare, v, 2.0f)); /* one mass only */
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_particle(full2, particle2, v));
    REFUSED(MPCA_STATUS_CELL_OCCUPIED, mpca_world_add_particle_mass(full2, particle2, v, 1.0f));
    REFUSED(MPCA_STATUS_CELL_OBSTACLE, mpca_world_add_particle(full2, obstacle2, v));
    REFUSED(MPCA_STATUS_CELL_OBSTACLE, mpca_world_add_particle_mass(full2, obstacle2, v, 1.0f));
    EACH_OUTSIDE(free2, 2, N2, mpca_world_add_particle(full2, free2, v));
    EACH_OUTSIDE(free3, 3, N3, mpca_world_add_particle(full3, free3, v));
    EACH_OUTSIDE(free2, 2, N2, mpca_world_add_particle_mass(full2, free2, v, 1.0f));

    mpca_particle p;
    mpca_cell c;
    memset(&p, SENTINEL_BYTE, sizeof p);
    memset(&c, SENTINEL_BYTE, sizeof c);
    set_context("removing and reading");
    REFUSED(MPCA_STATUS_NO_PARTICLE, mpca_world_remove_particle(full2, free2, &p));
    REFUSED(MPCA_STATUS_NO_PARTICLE, mpca_world_remove_particle(full2, obstacle2, &p));
    EACH_OUTSIDE(particle2, 2, N2, mpca_world_remove_particle(full2, particle2, &p));
    EACH_OUTSIDE(particle2, 2, N2, mpca_world_cell(full2, particle2, &c));
    EACH_OUTSIDE(free3, 3, N3, mpca_world_cell(full3, free3, &c));
    const unsigned char *pb = (const unsigned char *)&p, *cb = (const unsigned char *)&c;
    unsigned touched = 0;
    for (size_t i = 0; i < sizeof p; i++) {
        touched += pb[i] != SENTINEL_BYTE;
    }
    for (size_t i = 0; i < sizeof c; i++) {
        touched += cb[i] != SENTINEL_BYTE;
    }
    CHECK(touched == 0);
}

static void output_cases(void) {
    size_t n = 0;
    CHECK_OK(mpca_world_particle_count(full2, &n));
    CHECK(n >= 2);
    float out[CELLS2 * 3];
    uint8_t bytes[CELLS2 * 2];
    const size_t capacities[2] = {0, n - 1};
    for (at = 0; at < 2; at++) {
        set_context("export with capacity %u of %u", (unsigned)capacities[at], (unsigned)n);
        for (size_t i = 0; i < CELLS2 * 3; i++) {
            out[i] = SENTINEL_FLOAT;
        }
        size_t count = SENTINEL_SIZE;
        REFUSED(MPCA_STATUS_OUTPUT_TOO_SMALL, mpca_world_export_positions(full2, out, capacities[at], &count));
        CHECK(count == n); /* the count needed is written */
        count = SENTINEL_SIZE;
        REFUSED(MPCA_STATUS_OUTPUT_TOO_SMALL, mpca_world_export_velocities(full2, out, capacities[at], &count));
        CHECK(count == n);
        count = SENTINEL_SIZE;
        REFUSED(MPCA_STATUS_OUTPUT_TOO_SMALL, mpca_world_export_masses(full2, out, capacities[at], &count));
        CHECK(count == n);
        size_t written = 0;
        for (size_t i = 0; i < CELLS2 * 3; i++) {
            written += out[i] != SENTINEL_FLOAT;
        }
        CHECK(written == 0);
    }

    /* NULL with capacity 0 is not an error but the size query: the count,
     * MPCA_STATUS_OK, and no world changed. With room claimed (capacity
     * 1, below the count, or the whole count) NULL is refused. */
    set_context("size query: NULL with capacity 0");
    uint64_t before = fingerprint();
    size_t count = SENTINEL_SIZE;
    CHECK_OK(mpca_world_export_positions(full2, NULL, 0, &count));
    CHECK(count == n);
    count = SENTINEL_SIZE;
    CHECK_OK(mpca_world_export_velocities(full2, NULL, 0, &count));
    CHECK(count == n);
    count = SENTINEL_SIZE;
    CHECK_OK(mpca_world_export_masses(full2, NULL, 0, &count));
    CHECK(count == n);
    CHECK(fingerprint() == before);
    const size_t claimed[2] = {1, n};
    for (at = 0; at < 2; at++) {
        set_context("NULL with capacity %u of %u", (unsigned)claimed[at], (unsigned)n);
        count = SENTINEL_SIZE;
        REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_positions(full2, NULL, claimed[at], &count));
        REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_velocities(full2, NULL, claimed[at], &count));
        REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_masses(full2, NULL, claimed[at], &count));
        CHECK(count == SENTINEL_SIZE);
    }
    set_context("size query without a count");
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_positions(full2, NULL, 0, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_velocities(full2, NULL, 0, NULL));
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_masses(full2, NULL, 0, NULL));

    /* Resolutions: zero, more bins than cells, a z bin count other than 1
     * in 2D; and lengths that are not the product of the resolution. */
    const uint32_t bad2[][3] = {{0, 16, 1}, {16, 0, 1}, {16, 16, 0}, {17, 16, 1}, {16, 17, 1}, {16, 16, 2}, {1, 1, 2}};
    for (at = 0; at < sizeof bad2 / sizeof bad2[0]; at++) {
        set_context("2D density resolution %u x %u x %u", bad2[at][0], bad2[at][1], bad2[at][2]);
        size_t len = (size_t)bad2[at][0] * bad2[at][1] * bad2[at][2];
        REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density(full2, bad2[at], out, len));
        REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density_u8(full2, bad2[at], bytes, len));
    }
    const uint32_t bad3[][3] = {{8, 8, 0}, {8, 8, 9}, {0, 8, 8}, {9, 1, 1}};
    for (at = 0; at < sizeof bad3 / sizeof bad3[0]; at++) {
        set_context("3D density resolution %u x %u x %u", bad3[at][0], bad3[at][1], bad3[at][2]);
        size_t len = (size_t)bad3[at][0] * bad3[at][1] * bad3[at][2];
        REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density(full3, bad3[at], out, len));
        REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density_u8(full3, bad3[at], bytes, len));
    }
    const uint32_t res[3] = {4, 4, 1};
    const size_t lens[3] = {0, 15, 17};
    for (at = 0; at < 3; at++) {
        set_context("density length %u for 4 x 4", (unsigned)lens[at]);
        REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density(full2, res, out, lens[at]));
        REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density_u8(full2, res, bytes, lens[at]));
    }
    set_context("density buffers longer than PTRDIFF_MAX bytes");
    REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density(full2, res, out, SIZE_MAX));
    REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density(full2, res, out, (size_t)PTRDIFF_MAX / sizeof(float) + 1));
    REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density_u8(full2, res, bytes, SIZE_MAX));
    REFUSED(MPCA_STATUS_BAD_RESOLUTION, mpca_world_density_u8(full2, res, bytes, (size_t)PTRDIFF_MAX + 1));

    set_context("statistics struct_size");
    const uint32_t sizes[4] = {0, sizeof(mpca_stats) - 8, sizeof(mpca_stats) + 8, UINT32_MAX};
    for (at = 0; at < 4; at++) {
        mpca_stats s;
        memset(&s, 0, sizeof s);
        s.struct_size = sizes[at];
        REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_stats(full2, &s));
        REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_stats(full3, &s));
        CHECK(s.struct_size == sizes[at] && s.step == 0 && s.particles == 0 && s.bytes_per_cell == 0);
    }
}

/* --- Messages, version ------------------------------------------------ */

#define STATUS(name) {#name, name}
static const struct {
    const char *name;
    uint32_t value;
} STATUSES[] = {
    STATUS(MPCA_STATUS_OK),
    STATUS(MPCA_STATUS_NULL_POINTER),
    STATUS(MPCA_STATUS_BAD_HANDLE),
    STATUS(MPCA_STATUS_PANIC),
    STATUS(MPCA_STATUS_BAD_STRUCT_SIZE),
    STATUS(MPCA_STATUS_BAD_ENUM),
    STATUS(MPCA_STATUS_OUTPUT_TOO_SMALL),
    STATUS(MPCA_STATUS_NOT_A_SURFACE),
    STATUS(MPCA_STATUS_BUSY),
    STATUS(MPCA_STATUS_STALE_TASK),
    STATUS(MPCA_STATUS_TASK_INDEX),
    STATUS(MPCA_STATUS_TASK_DONE),
    STATUS(MPCA_STATUS_OVERLAP),
    STATUS(MPCA_STATUS_TAG_RANGE),
    STATUS(MPCA_STATUS_BAD_DIMENSION),
    STATUS(MPCA_STATUS_DIM3_DISABLED),
    STATUS(MPCA_STATUS_SIZE_ZERO),
    STATUS(MPCA_STATUS_SIZE_ODD),
    STATUS(MPCA_STATUS_TOO_LARGE),
    STATUS(MPCA_STATUS_PERIODIC_MISMATCH),
    STATUS(MPCA_STATUS_NOT_FINITE),
    STATUS(MPCA_STATUS_NEGATIVE_DT),
    STATUS(MPCA_STATUS_BAD_VORTEX),
    STATUS(MPCA_STATUS_BAD_DRAG),
    STATUS(MPCA_STATUS_RESTITUTION_RANGE),
    STATUS(MPCA_STATUS_MASS_RANGE),
    STATUS(MPCA_STATUS_SPEED_RANGE),
    STATUS(MPCA_STATUS_Q16_DISABLED),
    STATUS(MPCA_STATUS_FEATURE_DISABLED),
    STATUS(MPCA_STATUS_NOT_ENABLED),
    STATUS(MPCA_STATUS_CAPACITY_RANGE),
    STATUS(MPCA_STATUS_BUFFER_TOO_SMALL),
    STATUS(MPCA_STATUS_OUT_OF_BOUNDS),
    STATUS(MPCA_STATUS_CELL_OCCUPIED),
    STATUS(MPCA_STATUS_CELL_OBSTACLE),
    STATUS(MPCA_STATUS_NO_PARTICLE),
    STATUS(MPCA_STATUS_MASS_TABLE_FULL),
    STATUS(MPCA_STATUS_SURFACE_TABLE_FULL),
    STATUS(MPCA_STATUS_UNDEFINED_NORMAL),
    STATUS(MPCA_STATUS_EMITTER_TABLE_FULL),
    STATUS(MPCA_STATUS_BAD_EMITTER),
    STATUS(MPCA_STATUS_LIFETIME_RANGE),
    STATUS(MPCA_STATUS_BAD_SHAPE),
    STATUS(MPCA_STATUS_BAD_RESOLUTION),
    STATUS(MPCA_STATUS_BAD_LENGTH),
    STATUS(MPCA_STATUS_NOT_OWNED),
    STATUS(MPCA_STATUS_OUT_OF_MEMORY),
    STATUS(MPCA_STATUS_NOT_AN_IMAGE),
    STATUS(MPCA_STATUS_IMAGE_VERSION),
    STATUS(MPCA_STATUS_IMAGE_LENGTH),
    STATUS(MPCA_STATUS_IMAGE_CHECKSUM),
    STATUS(MPCA_STATUS_IMAGE_INVALID),
    STATUS(MPCA_STATUS_IMAGE_MISMATCH),
    STATUS(MPCA_STATUS_IDS_EXHAUSTED),
    STATUS(MPCA_STATUS_BODY_TABLE_FULL),
    STATUS(MPCA_STATUS_NO_BODY),
    STATUS(MPCA_STATUS_UNKNOWN),
};
#define STATUS_COUNT (sizeof STATUSES / sizeof STATUSES[0])

/* Every status has its own non-empty message; numbers that are no status
 * share one message, different from all of those. Prints "status: NAME N"
 * so the Rust side can compare the table with the header. */
/* --- Identity (M6b): tags and the one-pass export ---------------------- */

static void identity_cases(void) {
    uint32_t particle[3] = {4, 8, 0}, empty[3] = {1, 12, 0}, outside[3] = {N2, 0, 0};
    set_context("the description reports the planes");
    mpca_desc d;
    CHECK_OK(mpca_world_desc(full2, &d));
    CHECK(d.identity == (MPCA_IDENTITY_IDS | MPCA_IDENTITY_AGES | MPCA_IDENTITY_TAGS));
    set_context("mpca_world_set_tag");
    REFUSED(MPCA_STATUS_TAG_RANGE, mpca_world_set_tag(full2, particle, 256));
    REFUSED(MPCA_STATUS_TAG_RANGE, mpca_world_set_tag(full2, particle, UINT32_MAX));
    REFUSED(MPCA_STATUS_NO_PARTICLE, mpca_world_set_tag(full2, empty, 1));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_set_tag(full2, outside, 1));
    uint32_t bare_particle[3] = {1, 1, 0};
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_tag(bare2, bare_particle, 1));
    set_context("mpca_world_set_emitter_tag");
    REFUSED(MPCA_STATUS_TAG_RANGE, mpca_world_set_emitter_tag(full2, 0, 256));
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_set_emitter_tag(full2, 2, 1)); /* room for two */
    REFUSED(MPCA_STATUS_OUT_OF_BOUNDS, mpca_world_set_emitter_tag(full2, UINT32_MAX, 1));
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_set_emitter_tag(bare2, 0, 1));

    set_context("mpca_world_export_particles");
    size_t n = 0;
    CHECK_OK(mpca_world_particle_count(full2, &n));
    static float positions[CELLS2 * 3], velocities[CELLS2 * 3];
    static uint32_t ids[CELLS2], ages[CELLS2];
    static uint8_t tags[CELLS2];
    for (size_t i = 0; i < CELLS2 * 3; i++) {
        positions[i] = velocities[i] = SENTINEL_FLOAT;
    }
    memset(ids, SENTINEL_BYTE, sizeof ids);
    mpca_particle_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.struct_size = sizeof cols;
    cols.positions = positions;
    cols.velocities = velocities;
    cols.ids = ids;
    cols.ages = ages;
    cols.tags = tags;
    size_t count = SENTINEL_SIZE;
    cols.struct_size = sizeof cols - 1;
    REFUSED(MPCA_STATUS_BAD_STRUCT_SIZE, mpca_world_export_particles(full2, &cols, CELLS2, &count));
    cols.struct_size = sizeof cols;
    cols.reserved = 1;
    REFUSED(MPCA_STATUS_BAD_ENUM, mpca_world_export_particles(full2, &cols, CELLS2, &count));
    cols.reserved = 0;
    CHECK(count == SENTINEL_SIZE);
    /* A column of a plane the world does not keep. */
    REFUSED(MPCA_STATUS_NOT_ENABLED, mpca_world_export_particles(bare2, &cols, CELLS2, &count));
    CHECK(count == SENTINEL_SIZE);
    /* Too small: the count, nothing written. */
    REFUSED(MPCA_STATUS_OUTPUT_TOO_SMALL, mpca_world_export_particles(full2, &cols, n - 1, &count));
    CHECK(count == n);
    /* Columns that share memory. */
    count = SENTINEL_SIZE;
    cols.velocities = positions + 3;
    REFUSED(MPCA_STATUS_OVERLAP, mpca_world_export_particles(full2, &cols, CELLS2, &count));
    cols.velocities = velocities;
    cols.ages = ids;
    REFUSED(MPCA_STATUS_OVERLAP, mpca_world_export_particles(full2, &cols, CELLS2, &count));
    cols.ages = ages;
    cols.tags = (uint8_t *)(void *)(ids + n - 1);
    REFUSED(MPCA_STATUS_OVERLAP, mpca_world_export_particles(full2, &cols, CELLS2, &count));
    cols.tags = tags;
    size_t written = 0;
    for (size_t i = 0; i < CELLS2 * 3; i++) {
        written += positions[i] != SENTINEL_FLOAT || velocities[i] != SENTINEL_FLOAT;
    }
    CHECK(written == 0);
    CHECK(ids[0] == 0xa5a5a5a5u);
    /* No column: the size query with capacity 0, else a NULL column. */
    mpca_particle_columns none;
    memset(&none, 0, sizeof none);
    none.struct_size = sizeof none;
    count = SENTINEL_SIZE;
    CHECK_OK(mpca_world_export_particles(full2, &none, 0, &count));
    CHECK(count == n);
    count = SENTINEL_SIZE;
    REFUSED(MPCA_STATUS_NULL_POINTER, mpca_world_export_particles(full2, &none, n, &count));
    CHECK(count == SENTINEL_SIZE); /* as the other exports: refused before the count */

    /* The export itself: the twins' positions and velocities, the cells'
     * ids, ages and tags, in one order; ids positive and distinct. */
    CHECK_OK(mpca_world_export_particles(full2, &cols, CELLS2, &count));
    CHECK(count == n);
    static float twin[CELLS2 * 3];
    CHECK_OK(mpca_world_export_positions(full2, twin, CELLS2, &count));
    CHECK(memcmp(twin, positions, n * 3 * sizeof(float)) == 0);
    CHECK_OK(mpca_world_export_velocities(full2, twin, CELLS2, &count));
    CHECK(memcmp(twin, velocities, n * 3 * sizeof(float)) == 0);
    unsigned tagged = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t pos[3] = {(uint32_t)positions[3 * i], (uint32_t)positions[3 * i + 1], 0};
        mpca_cell c;
        CHECK_OK(mpca_world_cell(full2, pos, &c));
        CHECK(c.kind == MPCA_CELL_KIND_PARTICLE && c.particle.id == ids[i] && c.particle.age == ages[i] && c.particle.tag == tags[i]);
        CHECK(ids[i] > 0);
        for (size_t j = 0; j < i; j++) {
            CHECK(ids[j] != ids[i]);
        }
        tagged += tags[i] == 255;
    }
    CHECK(tagged == 1); /* set_tag in build_worlds */
}

static void message_cases(void) {
    set_context("status messages");
    const char *messages[STATUS_COUNT];
    for (unsigned i = 0; i < STATUS_COUNT; i++) {
        printf("status: %s %u\n", STATUSES[i].name, STATUSES[i].value);
        messages[i] = TRACE(mpca_status_message(STATUSES[i].value));
        CHECK(messages[i] != NULL && messages[i][0] != '\0');
        for (unsigned j = 0; j < i && messages[i] != NULL; j++) {
            CHECK(messages[j] == NULL || strcmp(messages[i], messages[j]) != 0);
        }
    }
    const uint32_t unknown[] = {14, 99, 130, 139, 144, 198, 200, 1000, 0x7fffffffu, UINT32_MAX};
    const char *first = TRACE(mpca_status_message(unknown[0]));
    CHECK(first != NULL && first[0] != '\0');
    for (unsigned i = 0; i < sizeof unknown / sizeof unknown[0] && first != NULL; i++) {
        const char *m = TRACE(mpca_status_message(unknown[i]));
        CHECK(m != NULL && strcmp(m, first) == 0);
        for (unsigned j = 0; j < STATUS_COUNT; j++) {
            CHECK(messages[j] == NULL || strcmp(first, messages[j]) != 0);
        }
    }
    if (first != NULL) {
        printf("unknown status message: %s\n", first);
    }

    const char *version = TRACE(mpca_version());
    char expected[64];
    snprintf(expected, sizeof expected, "%d.%d.%d", MPCA_VERSION_MAJOR, MPCA_VERSION_MINOR, MPCA_VERSION_PATCH);
    CHECK(version != NULL && strcmp(version, expected) == 0);
    printf("version: %s\n", version != NULL ? version : "(null)");
}

/* --- Details (issue 27 item 3) ----------------------------------------- */

/* A free cell of `w` (2D), into `pos`. */
static void free_cell(const mpca_world *w, uint32_t pos[3]) {
    mpca_desc d;
    CHECK_OK(mpca_world_desc(w, &d));
    for (pos[2] = 0, pos[1] = 0; pos[1] < d.size[1]; pos[1]++) {
        for (pos[0] = 0; pos[0] < d.size[0]; pos[0]++) {
            mpca_cell c;
            CHECK_OK(mpca_world_cell(w, pos, &c));
            if (c.kind == MPCA_CELL_KIND_EMPTY) {
                return;
            }
        }
    }
    CHECK(!"a free cell");
}

/* Each refusal's detail names the field, argument or part at fault, the
 * same for the thread (mpca_last_error) and the world called
 * (mpca_world_last_error); refusals of one kind for different fields name
 * different ones; a call on the world that succeeds clears its detail and
 * leaves the thread's, and a refusal on another world leaves it too. */
static void detail_cases(void) {
    set_context("details");
    uint32_t pos[3] = {1, 1, 0}, outside[3] = {N2, 0, 0}, bare_free[3], full_free[3];
    float nan3[3] = {NAN, 0, 0}, zero[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    uint64_t requested = SENTINEL_SIZE, delivered = SENTINEL_SIZE;
    uint32_t index = SENTINEL_U32;
    free_cell(bare2, bare_free);
    free_cell(full2, full_free);

    /* Not enabled: each call names the part its world was made without. */
    mpca_emitter e = emitter_at(2, 2, 0, 2);
    e.lifetime = 0;
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.obstacles", mpca_world_add_obstacle(bare2, pos, up, 1.0f));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.forces.uniform", mpca_world_set_gravity(bare2, up));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.forces.field", mpca_world_set_cell_force(bare2, pos, zero));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.forces.potential", mpca_world_set_cell_potential(bare2, pos, 0.0f));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.forces.vortex", mpca_world_set_vortex(bare2, 1.0f, 1.0f, 1.0f, 1.0f));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.drag.field", mpca_world_set_cell_wind(bare2, pos, zero));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.emitter_capacity is 0", mpca_world_add_emitter(bare2, &e, &index));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "desc.identity (no tags)", mpca_world_set_tag(bare2, pos, 1));
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "mass is not desc.mass (desc.per_particle_mass is off)",
               mpca_world_add_particle_mass(bare2, bare_free, zero, 2.0f));
    mpca_shape disc;
    memset(&disc, 0, sizeof disc);
    disc.struct_size = sizeof disc;
    disc.kind = MPCA_SHAPE_KIND_DISC;
    disc.a[0] = disc.a[1] = 4.0f;
    disc.radius = 1.0f;
    uint32_t id = SENTINEL_U32;
    REFUSED_ON(full2, MPCA_STATUS_NOT_ENABLED, "desc.obstacles or desc.body_capacity",
               mpca_world_add_body(full2, &disc, zero, 1.0f, &id));
    e.lifetime = 30;
    REFUSED_ON(bare2, MPCA_STATUS_NOT_ENABLED, "emitter.lifetime (desc.lifetimes is off)", mpca_world_add_emitter(bare2, &e, &index));
    CHECK(index == SENTINEL_U32 && id == SENTINEL_U32);

    /* Not finite: each names its argument or field. */
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "gravity", mpca_world_set_gravity(full2, nan3));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "vortex", mpca_world_set_vortex(full2, NAN, 8.0f, 3.0f, 0.2f));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "force", mpca_world_set_cell_force(full2, pos, nan3));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "potential", mpca_world_set_cell_potential(full2, pos, NAN));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "wind", mpca_world_set_cell_wind(full2, pos, nan3));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "velocity", mpca_world_add_particle(full2, full_free, nan3));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "rate", mpca_world_set_emitter_rate(full2, 0, NAN));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "normal", mpca_world_add_obstacle(full2, full_free, nan3, 1.0f));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "e", mpca_world_add_obstacle(full2, full_free, up, NAN));
    REFUSED_ON(full2, MPCA_STATUS_NOT_FINITE, "shape", mpca_world_add_disc(full2, NAN, 5.0f, 1.0f, 1.0f));
    e.mass = NAN;
    REFUSED_ON(emit2, MPCA_STATUS_NOT_FINITE, "emitter.mass", mpca_world_add_emitter(emit2, &e, &index));
    e.mass = 1;

    /* Out of bounds, bad shapes, bad emitters: one kind, several fields. */
    mpca_region_stats region;
    memset(&region, 0, sizeof region);
    region.struct_size = sizeof region;
    uint32_t lo[3] = {4, 4, 0}, hi[3] = {2, 8, 1}, far[3] = {N2 + 1, 8, 1};
    REFUSED_ON(full2, MPCA_STATUS_OUT_OF_BOUNDS, "pos", mpca_world_add_particle(full2, outside, zero));
    REFUSED_ON(full2, MPCA_STATUS_OUT_OF_BOUNDS, "index (past the emitters)",
               mpca_world_emitter_stats(full2, 2, &requested, &delivered)); /* both slots used */
    REFUSED_ON(full2, MPCA_STATUS_OUT_OF_BOUNDS, "max", mpca_world_region_stats(full2, lo, far, &region));
    REFUSED_ON(full2, MPCA_STATUS_BAD_SHAPE, "min is not below max", mpca_world_region_stats(full2, lo, hi, &region));
    REFUSED_ON(full2, MPCA_STATUS_BAD_SHAPE, "shape: radius", mpca_world_add_disc(full2, 5.0f, 5.0f, 0.0f, 1.0f));
    float box_lo[3] = {5, 5, 0}, box_hi[3] = {4, 6, 1};
    REFUSED_ON(full2, MPCA_STATUS_BAD_SHAPE, "shape: box min above max", mpca_world_add_box(full2, box_lo, box_hi, 1.0f));
    e.rate = -1.0f;
    REFUSED_ON(emit2, MPCA_STATUS_BAD_EMITTER, "emitter.rate is negative", mpca_world_add_emitter(emit2, &e, &index));
    e.rate = 0.5f;
    e.max[0] = N2 + 1;
    REFUSED_ON(emit2, MPCA_STATUS_BAD_EMITTER, "emitter.max is past the world", mpca_world_add_emitter(emit2, &e, &index));
    e.max[0] = e.min[0];
    REFUSED_ON(emit2, MPCA_STATUS_BAD_EMITTER, "emitter.min is not below max", mpca_world_add_emitter(emit2, &e, &index));
    REFUSED_ON(full2, MPCA_STATUS_BAD_EMITTER, "rate", mpca_world_set_emitter_rate(full2, 0, -1.0f));
    CHECK(requested == SENTINEL_SIZE && delivered == SENTINEL_SIZE && index == SENTINEL_U32);

    /* The C boundary's own: the structure or field named. */
    e = emitter_at(2, 2, 0, 2);
    e.struct_size = 8;
    REFUSED_ON(emit2, MPCA_STATUS_BAD_STRUCT_SIZE, "emitter.struct_size", mpca_world_add_emitter(emit2, &e, &index));
    disc.kind = 9;
    REFUSED_ON(full2, MPCA_STATUS_BAD_ENUM, "shape.kind", mpca_world_add_shape(full2, &disc, 1.0f));

    /* Snapshots: which part of the image is wrong. */
    size_t need = 0, need3 = 0;
    CHECK_OK(mpca_world_save(full2, NULL, 0, &need));
    CHECK_OK(mpca_world_save(full3, NULL, 0, &need3));
    unsigned char *image = malloc(need), *image3 = malloc(need3);
    CHECK(image != NULL && image3 != NULL);
    if (image != NULL && image3 != NULL) {
        CHECK_OK(mpca_world_save(full2, image, need, &need));
        CHECK_OK(mpca_world_save(full3, image3, need3, &need3));
        REFUSED_ON(full2, MPCA_STATUS_IMAGE_LENGTH, "header", mpca_world_load(full2, image, 12));
        REFUSED_ON(full2, MPCA_STATUS_IMAGE_LENGTH, "header: length", mpca_world_load(full2, image, need - 1));
        image[need / 2] ^= 0x10;
        REFUSED_ON(full2, MPCA_STATUS_IMAGE_CHECKSUM, "checksum", mpca_world_load(full2, image, need));
        image[need / 2] ^= 0x10;
        image[8] ^= 0x40; /* the version */
        REFUSED_ON(full2, MPCA_STATUS_IMAGE_VERSION, "header: version", mpca_world_load(full2, image, need));
        image[8] ^= 0x40;
        image[0] ^= 1;
        REFUSED_ON(full2, MPCA_STATUS_NOT_AN_IMAGE, "header: magic", mpca_world_load(full2, image, need));
        image[0] ^= 1;
        REFUSED_ON(full2, MPCA_STATUS_IMAGE_MISMATCH, "desc.size", mpca_world_load(full2, image3, need3));
        /* Of the size, with another capacity: that capacity named. */
        mpca_desc d = full_desc(2, N2);
        d.emitter_capacity = 3;
        mpca_world *other = NULL;
        CHECK_OK(mpca_world_create(&d, &other));
        REFUSED_ON(other, MPCA_STATUS_IMAGE_MISMATCH, "desc.emitter_capacity", mpca_world_load(other, image, need));
        CHECK_OK(mpca_world_destroy(other));
    }
    free(image);
    free(image3);

    /* A step task of no step: the thread's detail is the status's message
     * (a status that says it all); no world records it. */
    REFUSED_AT(MPCA_STATUS_STALE_TASK, mpca_status_message(MPCA_STATUS_STALE_TASK), mpca_world_step_task(full2, 12345, 0));

    /* A success clears the world's detail, not the thread's; a refusal on
     * another world leaves it (calls of their own: REFUSED reads every
     * watched world, which clears them). */
    CHECK(TRACE(mpca_world_set_gravity(full2, nan3)) == MPCA_STATUS_NOT_FINITE);
    CHECK(TRACE(mpca_world_set_gravity(bare2, up)) == MPCA_STATUS_NOT_ENABLED);
    CHECK(strcmp(mpca_world_last_error(full2), "gravity") == 0);
    CHECK(strcmp(mpca_world_last_error(bare2), "desc.forces.uniform") == 0);
    CHECK(strcmp(mpca_last_error(), "desc.forces.uniform") == 0);
    uint64_t hash = 0;
    CHECK_OK(mpca_world_hash(full2, &hash));
    CHECK(*mpca_world_last_error(full2) == '\0');
    CHECK(strcmp(mpca_world_last_error(bare2), "desc.forces.uniform") == 0);
    CHECK(strcmp(mpca_last_error(), "desc.forces.uniform") == 0);
    CHECK(strcmp(mpca_world_last_error(NULL), "world (not a live handle)") == 0);
}

/* The success paths that the error cases above do not reach. */
static void success_cases(void) {
    set_context("success paths");
    mpca_desc d;
    CHECK_OK(mpca_world_desc(full2, &d));
    /* The set functions changed the world's description. */
    CHECK(d.struct_size == sizeof d && d.dim == 2 && d.size[0] == N2 && d.size[1] == N2 && d.size[2] == 1);
    CHECK(d.gravity[0] == 0 && d.gravity[1] == -0.02f && d.gravity[2] == 0);
    CHECK(d.vortex_centre[0] == 8 && d.vortex_core_radius == 3 && d.vortex_circulation == 0.2f);
    uint32_t pos[3] = {9, 9, 0};
    float v[3] = {0.25f, -0.25f, 0};
    mpca_particle p;
    CHECK_OK(mpca_world_add_particle_mass(full2, pos, v, 2.0f));
    CHECK_OK(mpca_world_remove_particle(full2, pos, &p));
    CHECK(p.pos[0] == 9 && p.pos[1] == 9 && p.pos[2] == 0 && p.mass == 2.0f && p.life == 0);
    CHECK(fabsf(p.velocity[0] - 0.25f) < 0.5f / 127 && fabsf(p.velocity[1] + 0.25f) < 0.5f / 127);
    for (unsigned i = 0; i < n_watched; i++) {
        mpca_stats s;
        memset(&s, 0, sizeof s);
        s.struct_size = sizeof s;
        CHECK_OK(mpca_world_step(watched[i], 3));
        CHECK_OK(mpca_world_stats(watched[i], &s));
        CHECK(s.step >= 3);
    }
}

int main(void) {
    check_begin();
    pool = malloc(POOL_BYTES);
    CHECK(pool != NULL);
    if (pool == NULL) {
        return check_end();
    }
    build_worlds();
    description_cases();
    memory_cases();
    null_cases();
    emitter_cases();
    force_cases();
    obstacle_cases();
    particle_cases();
    output_cases();
    identity_cases();
    body_cases();
    handle_cases();
    message_cases();
    detail_cases();
    success_cases();

    set_context("teardown");
    CHECK_OK(mpca_world_deinit(full2));
    CHECK_OK(mpca_world_deinit(small2));
    CHECK_OK(mpca_world_destroy(full3));
    CHECK_OK(mpca_world_destroy(bare2));
    CHECK_OK(mpca_world_destroy(emit2));
    CHECK_OK(mpca_world_destroy(body2));
    free(full2_memory);
    free(small2_memory);
    free(pool);
    printf("error cases: %u\n", error_cases);
    return check_end();
}
