/*
 * Two small scenes stepped from C. tests/tests/c_abi.rs builds the same two
 * scenes through the Rust API (the same constants, the same calls in the
 * same order) and compares the hashes and statistics printed here:
 *
 *   hash2d: <16 hex digits>    stats2d: key=value ...
 *   hash3d: <16 hex digits>    stats3d: key=value ...
 *
 * The 2D world lives in caller memory, deliberately misaligned; the 3D one
 * comes from mpca_world_create. After stepping, the exported positions,
 * velocities and masses are checked against mpca_world_cell, and the
 * density against the cells.
 */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* --- The 2D scene (scene_2d in c_abi.rs) -------------------------------- */
#define S2_SIZE 32u
#define S2_SEED 2024u
#define S2_GRAVITY_Y (-0.02f)
#define S2_RESTITUTION 0.9f
#define S2_WALL_RESTITUTION 0.7f
#define S2_DISC_X 16.0f
#define S2_DISC_Y 12.0f
#define S2_DISC_RADIUS 5.0f
#define S2_DISC_E 0.8f
#define S2_EMIT_MIN_X 4u
#define S2_EMIT_MIN_Y 26u
#define S2_EMIT_MAX_X 28u
#define S2_EMIT_MAX_Y 30u
#define S2_EMIT_RATE 1.5f
#define S2_EMIT_VX 0.1f
#define S2_EMIT_VY (-0.3f)
#define S2_EMIT_SPREAD 0.2f
#define S2_EMIT_LIFETIME 20u
#define S2_PARTICLES 10u /* at (2 + 3 i, 20) */
#define S2_PARTICLE_Y 20u
#define S2_SPEED_X 0.6f  /* to +x for odd i, to -x for even i */
#define S2_MISALIGN 3u   /* bytes past malloc's alignment */
#define S2_STEPS 50u

/* --- The 3D scene (scene_3d in c_abi.rs) -------------------------------- */
#define S3_SIZE 16u
#define S3_SEED 99u
#define S3_GRAVITY_Y (-0.03f)
#define S3_RESTITUTION 0.8f
#define S3_SURFACES 512u
#define S3_SPHERE_X 8.0f
#define S3_SPHERE_Y 6.0f
#define S3_SPHERE_Z 8.0f
#define S3_SPHERE_RADIUS 3.5f
#define S3_SPHERE_E 0.9f
#define S3_BLOCK_Y 11u   /* a block of 4 x 3 x 4 particles, y from 11 */
#define S3_BLOCK_XZ 6u   /* x and z from 6 */
#define S3_HEAVY 2.0f    /* the mass of those with even x */
#define S3_STEPS 30u

static void print_stats(const char *name, const mpca_stats *s) {
    printf("%s: step=%" PRIu64 " particles=%" PRIu64 " emitted=%" PRIu64 " exited=%" PRIu64 " expired=%" PRIu64
           " shortfall=%" PRIu64 " collisions=%" PRIu64 " clamps=%" PRIu64 " displaced=%" PRIu64 "\n",
           name, s->step, s->particles, s->emitted, s->exited, s->expired, s->emit_shortfall, s->collisions,
           s->clamps, s->displaced);
}

/* The exports against mpca_world_cell, the cell scan and the density. */
static void check_exports(mpca_world *w, const char *name) {
    mpca_desc d;
    mpca_stats s;
    size_t n = 0, count = 0;
    CHECK_OK(mpca_world_desc(w, &d));
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    CHECK_OK(mpca_world_stats(w, &s));
    CHECK_OK(mpca_world_particle_count(w, &n));
    CHECK(n > 0 && n == s.particles);
    const uint32_t dim = d.dim, nx = d.size[0], ny = d.size[1], nz = dim == 3 ? d.size[2] : 1;
    /* Room for two more than needed: only n are written. */
    float *pos = malloc((n + 2) * 3 * sizeof(float)), *vel = malloc((n + 2) * 3 * sizeof(float));
    float *mass = malloc((n + 2) * sizeof(float));
    float *density = malloc((size_t)nx * ny * nz * sizeof(float));
    uint8_t *density_u8 = malloc((size_t)nx * ny * nz);
    CHECK(pos != NULL && vel != NULL && mass != NULL && density != NULL && density_u8 != NULL);
    if (pos == NULL || vel == NULL || mass == NULL || density == NULL || density_u8 == NULL) {
        return;
    }
    CHECK_OK(mpca_world_export_positions(w, pos, n + 2, &count));
    CHECK(count == n);
    count = 0;
    CHECK_OK(mpca_world_export_velocities(w, vel, n + 2, &count));
    CHECK(count == n);
    count = 0;
    CHECK_OK(mpca_world_export_masses(w, mass, n, &count)); /* exactly enough */
    CHECK(count == n);
    const uint32_t res[3] = {nx, ny, nz};
    CHECK_OK(mpca_world_density(w, res, density, (size_t)nx * ny * nz));
    CHECK_OK(mpca_world_density_u8(w, res, density_u8, (size_t)nx * ny * nz));

    double momentum[3] = {0, 0, 0};
    long previous = -1;
    unsigned bad = 0;
    for (size_t i = 0; i < n; i++) {
        uint32_t c[3];
        for (unsigned k = 0; k < 3; k++) {
            c[k] = (uint32_t)floorf(pos[3 * i + k]);
            bad += pos[3 * i + k] != (float)c[k] + 0.5f; /* a cell centre */
        }
        bad += dim == 2 && c[2] != 0;
        long dense = (long)c[0] + (long)nx * ((long)c[1] + (long)ny * (long)c[2]);
        bad += dense <= previous; /* cell order, x fastest */
        previous = dense;
        mpca_cell cell;
        memset(&cell, 0, sizeof cell);
        CHECK_OK(mpca_world_cell(w, c, &cell));
        bad += cell.kind != MPCA_CELL_KIND_PARTICLE;
        for (unsigned k = 0; k < 3; k++) {
            bad += cell.particle.pos[k] != c[k];
            bad += memcmp(&cell.particle.velocity[k], &vel[3 * i + k], sizeof(float)) != 0;
            momentum[k] += (double)mass[i] * (double)vel[3 * i + k];
        }
        bad += memcmp(&cell.particle.mass, &mass[i], sizeof(float)) != 0;
        bad += density[dense] != 1.0f || density_u8[dense] != 255;
    }
    CHECK(bad == 0);
    for (unsigned k = 0; k < 3; k++) {
        CHECK(fabs(momentum[k] - s.momentum[k]) <= 1e-9 * (1.0 + fabs(s.momentum[k])));
    }

    /* Every cell: as many particles as exported, and the density is the
     * occupancy. */
    size_t particles = 0;
    unsigned mismatches = 0;
    for (uint32_t z = 0; z < nz; z++) {
        for (uint32_t y = 0; y < ny; y++) {
            for (uint32_t x = 0; x < nx; x++) {
                uint32_t c[3] = {x, y, z};
                mpca_cell cell;
                CHECK_OK(mpca_world_cell(w, c, &cell));
                size_t dense = x + (size_t)nx * (y + (size_t)ny * z);
                int occupied = cell.kind == MPCA_CELL_KIND_PARTICLE;
                particles += (size_t)occupied;
                mismatches += cell.kind > MPCA_CELL_KIND_OBSTACLE;
                mismatches += density[dense] != (occupied ? 1.0f : 0.0f);
                mismatches += density_u8[dense] != (occupied ? 255 : 0);
                mismatches += !occupied && (cell.particle.mass != 0 || cell.particle.life != 0);
            }
        }
    }
    CHECK(particles == n);
    CHECK(mismatches == 0);

    /* Coarse bins of 4 cells per used axis: the shares add up to n. */
    const uint32_t coarse[3] = {nx / 4, ny / 4, dim == 3 ? nz / 4 : 1};
    const size_t bins = (size_t)coarse[0] * coarse[1] * coarse[2];
    CHECK_OK(mpca_world_density(w, coarse, density, bins));
    double sum = 0;
    for (size_t b = 0; b < bins; b++) {
        sum += density[b] * (dim == 3 ? 64.0 : 16.0);
    }
    CHECK(fabs(sum - (double)n) < 1e-3);
    printf("exports%s: %zu particles, consistent with mpca_world_cell and the density\n", name, n);
    free(pos);
    free(vel);
    free(mass);
    free(density);
    free(density_u8);
}

/* The accounting every scene must satisfy (M10). */
static void check_accounting(const mpca_stats *s, uint64_t added, uint64_t steps) {
    CHECK(s->step == steps);
    CHECK(s->particles == added + s->emitted - s->exited - s->expired);
    CHECK(s->bytes_per_cell > 0);
}

/* Prints the world's hash and statistics as "hash<name>: ..." and
 * "stats<name>: ..." lines for the Rust side, filling in the statistics. */
static void report_world(const mpca_world *w, const char *name, mpca_stats *s) {
    uint64_t hash = 0;
    char label[16];
    memset(s, 0, sizeof *s);
    s->struct_size = sizeof *s;
    CHECK_OK(mpca_world_hash(w, &hash));
    CHECK_OK(mpca_world_stats(w, s));
    printf("hash%s: %016" PRIx64 "\n", name, hash);
    snprintf(label, sizeof label, "stats%s", name);
    print_stats(label, s);
}

static void scene_2d(void) {
    check_context = "2D scene";
    mpca_desc d;
    CHECK_OK(mpca_desc_defaults(&d, 2, S2_SIZE, S2_SIZE, 0));
    d.seed = S2_SEED;
    d.boundary[0][0] = d.boundary[0][1] = MPCA_BOUNDARY_OPEN;
    d.boundary[1][0] = d.boundary[1][1] = MPCA_BOUNDARY_WALL;
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = S2_GRAVITY_Y;
    d.restitution = S2_RESTITUTION;
    d.wall_restitution = S2_WALL_RESTITUTION;
    d.obstacles = 1;
    d.surface_capacity = 256;
    d.lifetimes = 1;
    d.emitter_capacity = 1;
    CHECK_OK(mpca_desc_validate(&d));

    size_t bytes = 0;
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    unsigned char *memory = malloc(bytes + S2_MISALIGN);
    CHECK(memory != NULL);
    if (memory == NULL) {
        return;
    }
    mpca_world *w = NULL;
    CHECK_OK(mpca_world_init(&d, memory + S2_MISALIGN, bytes, &w));

    CHECK_OK(mpca_world_add_disc(w, S2_DISC_X, S2_DISC_Y, S2_DISC_RADIUS, S2_DISC_E));
    mpca_emitter e;
    memset(&e, 0, sizeof e);
    e.struct_size = sizeof e;
    e.min[0] = S2_EMIT_MIN_X;
    e.min[1] = S2_EMIT_MIN_Y;
    e.max[0] = S2_EMIT_MAX_X;
    e.max[1] = S2_EMIT_MAX_Y;
    e.rate = S2_EMIT_RATE;
    e.velocity[0] = S2_EMIT_VX;
    e.velocity[1] = S2_EMIT_VY;
    e.spread = S2_EMIT_SPREAD;
    e.mass = 1.0f;
    e.lifetime = S2_EMIT_LIFETIME;
    uint32_t index = 99;
    CHECK_OK(mpca_world_add_emitter(w, &e, &index));
    CHECK(index == 0);
    for (uint32_t i = 0; i < S2_PARTICLES; i++) {
        uint32_t pos[3] = {2 + 3 * i, S2_PARTICLE_Y, 0};
        float v[3] = {i % 2 ? S2_SPEED_X : -S2_SPEED_X, 0.1f * (float)(i % 3) - 0.1f, 0};
        CHECK_OK(mpca_world_add_particle(w, pos, v));
    }
    CHECK_OK(mpca_world_step(w, S2_STEPS));

    mpca_stats s;
    report_world(w, "2d", &s);
    check_accounting(&s, S2_PARTICLES, S2_STEPS);
    /* Each path of the accounting was taken. */
    CHECK(s.emitted > 0 && s.exited > 0 && s.expired > 0);
    /* The world fits in the memory handed in. */
    CHECK(s.bytes_per_cell * S2_SIZE * S2_SIZE <= (double)bytes);
    check_exports(w, "2d");
    CHECK_OK(mpca_world_deinit(w));
    free(memory);
}

static void scene_3d(void) {
    check_context = "3D scene";
    mpca_desc d;
    CHECK_OK(mpca_desc_defaults(&d, 3, S3_SIZE, S3_SIZE, S3_SIZE));
    d.seed = S3_SEED;
    for (unsigned k = 0; k < 3; k++) {
        d.boundary[k][0] = d.boundary[k][1] = MPCA_BOUNDARY_WALL;
    }
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = S3_GRAVITY_Y;
    d.restitution = S3_RESTITUTION;
    d.obstacles = 1;
    d.surface_capacity = S3_SURFACES;
    d.per_particle_mass = 1;
    d.mass_classes = 2;
    d.quantization = 16;
    d.drift = MPCA_DRIFT_CALIBRATED;
    d.method = MPCA_METHOD_GREEDY;
    d.collisions = MPCA_COLLISIONS_SPEED_LIMITED;
    d.contacts = 1;
    mpca_world *w = NULL;
    CHECK_OK(mpca_world_create(&d, &w));
    if (w == NULL) {
        return;
    }

    const float centre[3] = {S3_SPHERE_X, S3_SPHERE_Y, S3_SPHERE_Z};
    CHECK_OK(mpca_world_add_sphere(w, centre, S3_SPHERE_RADIUS, S3_SPHERE_E));
    uint64_t added = 0;
    for (uint32_t y = S3_BLOCK_Y; y < S3_BLOCK_Y + 3; y++) {
        for (uint32_t z = S3_BLOCK_XZ; z < S3_BLOCK_XZ + 4; z++) {
            for (uint32_t x = S3_BLOCK_XZ; x < S3_BLOCK_XZ + 4; x++) {
                uint32_t pos[3] = {x, y, z};
                float a[3] = {0.2f, 0, -0.1f}, b[3] = {-0.1f, 0.1f, 0.2f};
                const float *v = (x + y + z) % 2 == 0 ? a : b;
                if (x % 2 == 0) {
                    CHECK_OK(mpca_world_add_particle_mass(w, pos, v, S3_HEAVY));
                } else {
                    CHECK_OK(mpca_world_add_particle(w, pos, v));
                }
                added++;
            }
        }
    }
    CHECK_OK(mpca_world_step(w, S3_STEPS));

    mpca_stats s;
    report_world(w, "3d", &s);
    check_accounting(&s, added, S3_STEPS);
    CHECK(s.particles == added); /* walls all round, no emitter, no lifetimes */
    CHECK(s.collisions > 0);
    check_exports(w, "3d");
    CHECK_OK(mpca_world_destroy(w));
}

int main(void) {
    check_begin();
    scene_2d();
    scene_3d();
    return check_end();
}
