/*
 * 4.4 water (Ecchu, Takai, Sato 1993; docs/model.md "The paper's four scenes"): a 3D
 * box of 64^3 cells with walls, water poured in at the top, gravity, a
 * sphere obstacle in the middle, e = 1. The same scene as
 * tests/src/scenes.rs `water()`: y is up, the sphere of radius 10 is centred
 * at (32, 28, 32), an 8 x 2 x 8 emitter at y = 60 pours 16 particles a step
 * at v = (0, -0.3, 0). At another --size every length scales with it and
 * the rate with the emitter's area.
 *
 * Built a second time with -DWATER_POOL as `water-pool` (M5.7 contacts,
 * beyond the paper; tests/src/scenes.rs `water_pool()`): no emitter, but a
 * 24 x 16 x 24 block of water released at rest above the sphere (x and z
 * 20..44, y 44..60), gravity 0.002, e = 0.5 for the water, the walls and
 * the sphere, contacts on, the default (calibrated) drift. It splashes off
 * the sphere and forms a pool on the floor.
 *
 * Drawn in perspective from above and in front: the floor with a grid, the
 * box's edges and the sphere in greys, the water as point sprites coloured
 * by speed and darkened with distance.
 */
#include <math.h>

#include "scene.h"

#define PAPER_SIZE 64

typedef struct water_geometry {
    float centre[3], radius;
    uint32_t emit_min[3], emit_max[3];
    float rate;
} water_geometry;

static water_geometry geometry(uint32_t size) {
    const float s = (float)size / PAPER_SIZE;
    water_geometry g = {{32.0f * s, 28.0f * s, 32.0f * s}, 10.0f * s, {0, 0, 0}, {0, 0, 0}, 16.0f * s * s};
    const uint32_t lo[3] = {28, 60, 28}, hi[3] = {36, 62, 36};
    for (int k = 0; k < 3; k++) {
        g.emit_min[k] = scale_cells(lo[k], size, PAPER_SIZE);
        g.emit_max[k] = scale_cells(hi[k], size, PAPER_SIZE);
        if (g.emit_max[k] <= g.emit_min[k]) g.emit_max[k] = g.emit_min[k] + 1;
    }
    return g;
}

/* What both builds share: the box with walls, a uniform force, room for
 * the sphere's surface and the seed. */
static mpca_desc box_desc(const scene_opts *o) {
    mpca_desc d;
    mpca_check(mpca_desc_defaults(&d, 3, o->size, o->size, o->size), "mpca_desc_defaults");
    for (int axis = 0; axis < 3; axis++) {
        d.boundary[axis][0] = d.boundary[axis][1] = MPCA_BOUNDARY_WALL;
    }
    d.forces = MPCA_FORCE_UNIFORM;
    d.obstacles = 1;
    /* The sphere's surface grows with the square of the size. */
    float area = (float)o->size / PAPER_SIZE;
    area *= area;
    d.surface_capacity = area > 1.0f ? (uint32_t)ceilf(4096.0f * area) : 4096;
    d.seed = o->seed;
    return d;
}

#ifdef WATER_POOL
static mpca_world *build(const scene_opts *o) {
    const water_geometry g = geometry(o->size);
    const float e = 0.5f;
    mpca_desc d = box_desc(o);
    d.restitution = e;
    d.wall_restitution = e;
    d.contacts = 1;
    d.gravity[1] = -0.002f;
    mpca_world *w = world_create(&d);
    mpca_check(mpca_world_add_sphere(w, g.centre, g.radius, e), "mpca_world_add_sphere");
    const uint32_t lo[3] = {20, 44, 20}, hi[3] = {44, 60, 44};
    uint32_t min[3], max[3];
    for (int k = 0; k < 3; k++) {
        min[k] = scale_cells(lo[k], o->size, PAPER_SIZE);
        max[k] = scale_cells(hi[k], o->size, PAPER_SIZE);
    }
    const float rest[3] = {0.0f, 0.0f, 0.0f};
    for (uint32_t y = min[1]; y < max[1]; y++) {
        for (uint32_t z = min[2]; z < max[2]; z++) {
            for (uint32_t x = min[0]; x < max[0]; x++) {
                const uint32_t pos[3] = {x, y, z};
                mpca_check(mpca_world_add_particle(w, pos, rest), "mpca_world_add_particle");
            }
        }
    }
    return w;
}
#else
static mpca_world *build(const scene_opts *o) {
    const water_geometry g = geometry(o->size);
    mpca_desc d = box_desc(o);
    d.drift = MPCA_DRIFT_PAPER; /* the paper's rule, as printed */
    d.restitution = 1.0f;
    d.gravity[1] = -0.02f;
    d.emitter_capacity = 1;
    mpca_world *w = world_create(&d);
    mpca_check(mpca_world_add_sphere(w, g.centre, g.radius, 1.0f), "mpca_world_add_sphere");
    const mpca_emitter e = {
        .struct_size = sizeof e,
        .min = {g.emit_min[0], g.emit_min[1], g.emit_min[2]},
        .max = {g.emit_max[0], g.emit_max[1], g.emit_max[2]},
        .rate = g.rate,
        .velocity = {0.0f, -0.3f, 0.0f},
        .spread = 0.05f,
        .mass = 1.0f,
        .lifetime = 0,
    };
    uint32_t index = 0;
    mpca_check(mpca_world_add_emitter(w, &e, &index), "mpca_world_add_emitter");
    return w;
}
#endif

/* From the front, to one side and above, aimed a little below the sphere's
 * centre so the falling column, the sphere and the splash on the floor all
 * fit. Distances in cells, scaled with the box. */
static camera view_camera(uint32_t size) {
    const float s = (float)size / PAPER_SIZE;
    const float azimuth = 0.55f, elevation = 0.38f, distance = 150.0f * s;
    camera c;
    c.target[0] = 32.0f * s;
    c.target[1] = 25.0f * s;
    c.target[2] = 32.0f * s;
    c.eye[0] = c.target[0] + distance * sinf(azimuth) * cosf(elevation);
    c.eye[1] = c.target[1] + distance * sinf(elevation);
    c.eye[2] = c.target[2] + distance * cosf(azimuth) * cosf(elevation);
    c.fov_deg = 42.0f;
    c.near_clip = 1.0f * s;
    c.far_clip = 400.0f * s;
    return c;
}

static drawn draw(const scene_opts *o, mpca_world *w, const view *v) {
    const water_geometry g = geometry(o->size);
    const camera c = view_camera(o->size);
    const uint32_t size[3] = {o->size, o->size, o->size};
    view3d_begin(v, &c);
    draw_floor_and_box(o->size, o->size, o->size, o->size / 8);
    draw_sphere(g.centre, g.radius);
    return draw_particles_3d(w, v, &c, size);
}

int main(int argc, char **argv) {
#ifdef WATER_POOL
    const scene s = {
        .name = "water-pool",
        .title = "4.4 water poured into a pool (M5.7)",
        .dim = 3,
        .defaults = {.size = PAPER_SIZE, .steps = 1200, .seed = 45, .every = 100, .tiles = 6, .px = 512},
        .about = "3D box, a block of water released above a sphere under gravity, e = 0.5, contacts: it splashes and pools on the floor",
        .build = build,
        .draw = draw,
    };
#else
    const scene s = {
        .name = "water",
        .title = "4.4 water",
        .dim = 3,
        .defaults = {.size = PAPER_SIZE, .steps = 130, .seed = 44, .every = 10, .tiles = 6, .px = 512},
        .about = "3D box, water poured from the top onto a sphere under gravity, e = 1",
        .build = build,
        .draw = draw,
    };
#endif
    return scene_main(&s, argc, argv);
}
