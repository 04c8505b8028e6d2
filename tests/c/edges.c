/*
 * Inputs at the edges of the model, judged by what the world then does
 * (errors.c judges the refusals):
 *
 * - a 2D half-space takes only the x and y of its normal, as
 *   mpca_world_add_obstacle does: a normal (1, 0, 5) is the wall x <= c
 *   with normal (1, 0, 0), off which a particle bounces;
 * - a Rankine vortex with a core too small to square in float exerts no
 *   force at its centre (no 0 * inf), so a particle there keeps its
 *   velocity, with or without circulation;
 * - a world is rebuilt from its own export: every particle read back with
 *   mpca_world_cell is added again to a world of the same description,
 *   and the two hash equal (2D and 3D, 8- and 16-bit velocities, right
 *   after adding velocities of length 1 and after steps);
 * - speed limits at 1 and one unit in the last place beyond, in each
 *   direction: a wind cell, a wind field, the description's wind and an
 *   emitter take |u| <= 1 exactly, so (0.6, 0.8) and (1, 2e-4), over 1 by
 *   about 2e-8, are refused with MPCA_STATUS_SPEED_RANGE and change
 *   nothing; a particle takes what a world can store (each component in
 *   [-1, 1], and the velocity rounded to its quanta within one quantum of
 *   |v| <= 1: docs/model.md M1), so those two are accepted and only a
 *   component beyond 1 is refused.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

/* The one particle of `w`, its velocity into `v`; 0 if not exactly one. */
static int only_particle(mpca_world *w, float pos[3], float v[3]) {
    size_t n = 0;
    CHECK_OK(mpca_world_particle_count(w, &n));
    if (n != 1) {
        return 0;
    }
    CHECK_OK(mpca_world_export_positions(w, pos, 1, &n));
    CHECK_OK(mpca_world_export_velocities(w, v, 1, &n));
    return 1;
}

/* --- Half-spaces in 2D --------------------------------------------------- */

static void half_space_in_2d(void) {
    check_context = "2D half-space normal";
    mpca_desc d;
    CHECK_OK(mpca_desc_defaults(&d, 2, 16, 16, 0));
    d.boundary[0][0] = d.boundary[0][1] = MPCA_BOUNDARY_WALL;
    d.obstacles = 1;
    d.surface_capacity = 64;
    d.seed = 5;
    mpca_world *w = NULL;
    CHECK_OK(mpca_world_create(&d, &w));
    /* The cells whose centres have x <= 4: columns 0 to 3. */
    float point[3] = {4, 0, 0}, normal[3] = {1, 0, 5};
    CHECK_OK(mpca_world_add_half_space(w, point, normal, 1.0f));
    for (uint32_t y = 0; y < 16; y++) {
        uint32_t wall[3] = {3, y, 0}, free_cell[3] = {4, y, 0};
        float n[3] = {0, 0, 0}, e = 0;
        mpca_cell c;
        CHECK_OK(mpca_world_surface(w, wall, n, &e));
        CHECK(n[0] == 1 && n[1] == 0 && n[2] == 0 && e == 1);
        CHECK_OK(mpca_world_cell(w, free_cell, &c));
        CHECK(c.kind == MPCA_CELL_KIND_EMPTY);
    }
    /* A particle flying at it bounces: its x velocity turns positive. */
    uint32_t pos[3] = {6, 8, 0};
    float v0[3] = {-0.5f, 0, 0}, at[3], v[3];
    CHECK_OK(mpca_world_add_particle(w, pos, v0));
    float most = -1;
    for (unsigned t = 0; t < 60; t++) {
        CHECK_OK(mpca_world_step(w, 1));
        CHECK(only_particle(w, at, v));
        CHECK(at[0] > 4); /* never inside the wall */
        most = v[0] > most ? v[0] : most;
    }
    CHECK(most > 0.4f);
    printf("half-space: x velocity after the bounce %.3f\n", (double)most);
    CHECK_OK(mpca_world_destroy(w));
}

/* --- A vortex with a tiny core ---------------------------------------- */

/* A particle at the vortex centre, moving along x: after one step (the
 * force acts before the move) its stored velocity is what it was. */
static void vortex_centre(uint32_t dim, float core, float circulation, int through_set) {
    mpca_desc d;
    CHECK_OK(mpca_desc_defaults(&d, dim, 8, 8, 8));
    d.forces = MPCA_FORCE_VORTEX;
    d.vortex_centre[0] = 4.5f; /* the centre of cell (4, 4) */
    d.vortex_centre[1] = 4.5f;
    d.vortex_core_radius = through_set ? 1.0f : core;
    d.vortex_circulation = through_set ? 0.0f : circulation;
    mpca_world *w = NULL;
    CHECK_OK(mpca_world_create(&d, &w));
    if (through_set) {
        CHECK_OK(mpca_world_set_vortex(w, 4.5f, 4.5f, core, circulation));
    }
    uint32_t pos[3] = {4, 4, dim == 3 ? 4 : 0};
    float v0[3] = {0.5f, 0, 0}, at[3], before[3], after[3];
    mpca_cell c;
    CHECK_OK(mpca_world_add_particle(w, pos, v0));
    CHECK_OK(mpca_world_cell(w, pos, &c));
    memcpy(before, c.particle.velocity, sizeof before);
    CHECK_OK(mpca_world_step(w, 1));
    CHECK(only_particle(w, at, after));
    CHECK(after[0] == before[0] && after[1] == before[1] && after[2] == before[2]);
    mpca_stats s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    CHECK_OK(mpca_world_stats(w, &s));
    CHECK(s.clamps == 0);
    printf("vortex %uD core %g circulation %g: velocity (%g, %g) after a step at its centre\n", dim, (double)core,
           (double)circulation, (double)after[0], (double)after[1]);
    CHECK_OK(mpca_world_destroy(w));
}

static void vortex_cases(void) {
    check_context = "vortex with a tiny core";
    for (uint32_t dim = 2; dim <= 3; dim++) {
        for (int through_set = 0; through_set <= 1; through_set++) {
            vortex_centre(dim, 1e-30f, 0.0f, through_set);
            vortex_centre(dim, 1e-30f, 1.0f, through_set);
            vortex_centre(dim, 1e-30f, -3e38f, through_set);
        }
    }
}

/* --- Rebuilding a world from its export ----------------------------------- */

/* Directions spread over the circle (2D) or the sphere (3D). */
static void direction(uint32_t dim, unsigned i, unsigned n, float out[3]) {
    double phi = 2.399963229728653 * i; /* the golden angle */
    if (dim == 2) {
        out[0] = (float)cos(phi);
        out[1] = (float)sin(phi);
        out[2] = 0;
    } else {
        double z = 1 - 2 * (i + 0.5) / n, r = sqrt(1 - z * z);
        out[0] = (float)(r * cos(phi));
        out[1] = (float)(r * sin(phi));
        out[2] = (float)z;
    }
}

/* A copy of `w` built from what mpca_world_cell reports of each cell;
 * returns the number of adds refused, counting the velocities longer than 1
 * in `above`. */
static unsigned rebuild(mpca_world *w, unsigned *above, uint64_t *hash) {
    mpca_desc d;
    CHECK_OK(mpca_world_desc(w, &d));
    mpca_world *copy = NULL;
    CHECK_OK(mpca_world_create(&d, &copy));
    unsigned refused = 0;
    uint32_t nz = d.dim == 3 ? d.size[2] : 1;
    for (uint32_t z = 0; z < nz; z++) {
        for (uint32_t y = 0; y < d.size[1]; y++) {
            for (uint32_t x = 0; x < d.size[0]; x++) {
                uint32_t pos[3] = {x, y, z};
                mpca_cell c;
                CHECK_OK(mpca_world_cell(w, pos, &c));
                if (c.kind != MPCA_CELL_KIND_PARTICLE) {
                    continue;
                }
                const float *v = c.particle.velocity;
                double s2 = (double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2];
                *above += s2 > 1;
                mpca_status st = TRACE(mpca_world_add_particle_mass(copy, pos, v, c.particle.mass));
                if (st != MPCA_STATUS_OK) {
                    refused++;
                    printf("rebuild: (%u, %u, %u) velocity (%.9g, %.9g, %.9g), |v| = %.9g: %s\n", x, y, z, (double)v[0],
                           (double)v[1], (double)v[2], sqrt(s2), mpca_status_message(st));
                }
            }
        }
    }
    uint64_t mine = 0;
    CHECK_OK(mpca_world_hash(w, &mine));
    CHECK_OK(mpca_world_hash(copy, hash));
    CHECK(*hash == mine);
    CHECK_OK(mpca_world_destroy(copy));
    return refused;
}

static void rebuild_cases(void) {
    check_context = "a world rebuilt from its own export";
    unsigned above_total = 0;
    for (uint32_t dim = 2; dim <= 3; dim++) {
        for (uint32_t bits = 8; bits <= 16; bits += 8) {
            uint32_t n = dim == 2 ? 16 : 8;
            mpca_desc d;
            CHECK_OK(mpca_desc_defaults(&d, dim, n, n, n));
            for (unsigned k = 0; k < 3; k++) {
                d.boundary[k][0] = d.boundary[k][1] = MPCA_BOUNDARY_WALL;
            }
            d.quantization = bits;
            d.per_particle_mass = 1;
            d.mass_classes = 2;
            d.seed = 77 + dim * 100 + bits;
            mpca_world *w = NULL;
            CHECK_OK(mpca_world_create(&d, &w));
            /* Every third cell, at speed 1 (as near as the library
             * accepts) in directions all round, masses 1 and 2. */
            unsigned added = 0, total = 0;
            uint32_t nz = dim == 3 ? n : 1;
            for (uint32_t z = 0; z < nz; z++) {
                for (uint32_t y = 0; y < n; y++) {
                    for (uint32_t x = 0; x < n; x++) {
                        if ((x + y + z) % 3 != 0) {
                            continue;
                        }
                        uint32_t pos[3] = {x, y, z};
                        float v[3];
                        direction(dim, total++, n * n * nz / 3 + 1, v);
                        float mass = total % 2 ? 1.0f : 2.0f;
                        mpca_status st;
                        while ((st = TRACE(mpca_world_add_particle_mass(w, pos, v, mass))) == MPCA_STATUS_SPEED_RANGE) {
                            for (unsigned k = 0; k < 3; k++) {
                                v[k] = nextafterf(v[k], 0.0f);
                            }
                        }
                        CHECK(st == MPCA_STATUS_OK);
                        added += st == MPCA_STATUS_OK;
                    }
                }
            }
            const uint64_t steps[2] = {0, 40};
            for (unsigned i = 0; i < 2; i++) {
                CHECK_OK(mpca_world_step(w, steps[i]));
                unsigned above = 0;
                uint64_t hash = 0;
                unsigned refused = rebuild(w, &above, &hash);
                CHECK(refused == 0);
                above_total += above;
                printf("rebuild %uD %u-bit after %u steps: %u particles, %u with |v| > 1, %u refused, hash %016llx\n",
                       dim, bits, (unsigned)steps[i], added, above, refused, (unsigned long long)hash);
            }
            CHECK_OK(mpca_world_destroy(w));
        }
    }
    /* Else the case never met a velocity that rounding took above 1. */
    CHECK(above_total > 0);
}

/* --- Speed limits ----------------------------------------------------------- */

/* One velocity against every speed check. `wind_ok`: the wind cell, wind
 * field, description wind and emitter accept it; `particle_ok`: a particle
 * may have it. Refusals must be SPEED_RANGE and change nothing. */
static unsigned speed_cases;

static void speed_case(uint32_t dim, float x, float y, float z, int wind_ok, int particle_ok) {
    const float v[3] = {x, y, dim == 3 ? z : 0.0f};
    const mpca_status want = wind_ok ? MPCA_STATUS_OK : MPCA_STATUS_SPEED_RANGE;
    const uint32_t origin[3] = {0, 0, 0};
    mpca_desc d;
    mpca_world *w = NULL;
    float field[3 * 8];
    uint64_t before = 0, after = 0;
    uint32_t index = 0;
    mpca_emitter e;
    unsigned k;
    char what[160];
    snprintf(what, sizeof what, "%uD (%.9g, %.9g, %.9g)", dim, (double)v[0], (double)v[1], (double)v[2]);

    CHECK_OK(mpca_desc_defaults(&d, dim, 2, 2, 2));
    d.forces = MPCA_FORCE_UNIFORM;
    d.drag_rate = 0.1f;
    d.drag_wind_field = 1;
    d.emitter_capacity = 1;
    for (k = 0; k < 3; k++) {
        d.drag_wind[k] = v[k];
    }
    check_status(mpca_desc_validate(&d), want, what, __FILE__, __LINE__);
    for (k = 0; k < 3; k++) {
        d.drag_wind[k] = 0.0f;
    }
    if (mpca_world_create(&d, &w) != MPCA_STATUS_OK) {
        CHECK(0);
        return;
    }
    CHECK_OK(mpca_world_hash(w, &before));
    check_status(mpca_world_set_cell_wind(w, origin, v), want, what, __FILE__, __LINE__);
    memset(field, 0, sizeof field);
    for (k = 0; k < dim; k++) {
        field[dim * 3 + k] = v[k]; /* the fourth cell */
    }
    check_status(mpca_world_set_wind_field(w, field, dim == 3 ? 24 : 8), want, what, __FILE__, __LINE__);
    memset(&e, 0, sizeof e);
    e.struct_size = sizeof e;
    e.max[0] = e.max[1] = e.max[2] = 1;
    e.rate = 1.0f;
    for (k = 0; k < 3; k++) {
        e.velocity[k] = v[k];
    }
    e.mass = 1.0f;
    check_status(mpca_world_add_emitter(w, &e, &index), want, what, __FILE__, __LINE__);
    check_status(mpca_world_add_particle(w, origin, v), particle_ok ? MPCA_STATUS_OK : MPCA_STATUS_SPEED_RANGE, what,
                 __FILE__, __LINE__);
    if (!wind_ok && !particle_ok) {
        CHECK_OK(mpca_world_hash(w, &after));
        CHECK(after == before);
    }
    CHECK_OK(mpca_world_destroy(w));
    speed_cases++;
}

static void speed_limits(void) {
    const float one_up = nextafterf(1.0f, 2.0f), one_down = nextafterf(1.0f, 0.0f);
    const float tiny = nextafterf(0.0f, 1.0f);
    uint32_t dim;
    check_context = "speed limits";
    for (dim = 2; dim <= 3; dim++) {
        float z = dim == 3 ? 1.0f : 0.0f;
        /* Along each axis: 1 passes, one unit more fails, one less passes. */
        speed_case(dim, 1.0f, 0.0f, 0.0f, 1, 1);
        speed_case(dim, 0.0f, -1.0f, 0.0f, 1, 1);
        speed_case(dim, one_up, 0.0f, 0.0f, 0, 0);
        speed_case(dim, 0.0f, -one_up, 0.0f, 0, 0);
        speed_case(dim, one_down, 0.0f, 0.0f, 1, 1);
        /* The least excess: a unit component and a subnormal one. */
        speed_case(dim, 1.0f, tiny, 0.0f, 0, 1);
        speed_case(dim, one_down, tiny, 0.0f, 1, 1);
        /* The cases, and one unit less of either component. */
        speed_case(dim, 0.6f, 0.8f, 0.0f, 0, 1);
        speed_case(dim, -0.8f, 0.6f, 0.0f, 0, 1);
        speed_case(dim, 1.0f, 2e-4f, 0.0f, 0, 1);
        speed_case(dim, 0.6f, nextafterf(0.8f, 0.0f), 0.0f, 1, 1);
        speed_case(dim, nextafterf(0.6f, 0.0f), 0.8f, 0.0f, 1, 1);
        if (dim == 3) {
            speed_case(dim, 0.0f, 0.0f, z, 1, 1);
            speed_case(dim, 0.0f, 0.0f, -one_up, 0, 0);
            speed_case(dim, 0.6f, 0.0f, -0.8f, 0, 1);
            speed_case(dim, tiny, 0.0f, one_down, 1, 1);
            speed_case(dim, tiny, 0.0f, 1.0f, 0, 1);
        }
    }
    printf("speed limits: %u velocities, each against 5 checks\n", speed_cases);
}

int main(void) {
    check_begin();
    half_space_in_2d();
    vortex_cases();
    rebuild_cases();
    speed_limits();
    return check_end();
}
