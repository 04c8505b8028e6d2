/*
 * 4.1 aggregation (Ecchu, Takai, Sato 1993; docs/model.md "The paper's four scenes"):
 * a periodic 2D box, 30 % of the cells holding a particle with a random
 * velocity, no force, particle-particle restitution e = 0.5. Inelastic
 * collisions cool the gas and the particles gather into clusters.
 * The same scene as tests/src/scenes.rs `aggregation()`, placement included.
 */
#include <math.h>

#include "scene.h"

#define PAPER_SIZE 128
#define DENSITY 0.3f
#define RESTITUTION 0.5f

static mpca_world *build(const scene_opts *o) {
    mpca_desc d;
    mpca_check(mpca_desc_defaults(&d, 2, o->size, o->size, 0), "mpca_desc_defaults");
    d.drift = MPCA_DRIFT_PAPER; /* the paper's rule, as printed */
    d.restitution = RESTITUTION; /* periodic on every face: the defaults */
    d.seed = o->seed;
    mpca_world *w = world_create(&d);
    /* The placement stream of tests/src/scenes.rs: Pcg32::new(seed ^
     * 0x5ce7e500, 0x0dd); per cell, row by row, one draw for "occupied?",
     * then the speed and the angle. */
    pcg32 rng = pcg32_new(o->seed ^ 0x5ce7e500u, 0x0ddu);
    for (uint32_t y = 0; y < o->size; y++) {
        for (uint32_t x = 0; x < o->size; x++) {
            if (pcg32_unit(&rng) < DENSITY) {
                float speed = pcg32_unit(&rng);
                float a = 6.28318530717958647692f * pcg32_unit(&rng);
                const uint32_t pos[3] = {x, y, 0};
                const float v[3] = {speed * cosf(a), speed * sinf(a), 0.0f};
                mpca_check(mpca_world_add_particle(w, pos, v), "mpca_world_add_particle");
            }
        }
    }
    return w;
}

static drawn draw(const scene_opts *o, mpca_world *w, const view *v) {
    view2d_begin(o->size, o->size);
    drawn d = {draw_particles_2d(w, v), 0.0f, 0.0f};
    return d;
}

int main(int argc, char **argv) {
    const scene s = {
        .name = "aggregation",
        .title = "4.1 aggregation",
        .dim = 2,
        .defaults = {.size = PAPER_SIZE, .steps = 800, .seed = 41, .every = 40, .tiles = 6, .px = 512},
        .about = "periodic 2D box, density 0.3, random velocities, e = 0.5, no force",
        .build = build,
        .draw = draw,
    };
    return scene_main(&s, argc, argv);
}
