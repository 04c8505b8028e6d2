/*
 * 4.2 cluster collision (Ecchu, Takai, Sato 1993; docs/model.md "The paper's
 * four scenes"): two discs of particles, radius 10 cells, flying at each other
 * with v = (+-0.8, 0), e = 1, m = 1, in a 2D box with walls all round.
 * The same scene as tests/src/scenes.rs `cluster()`; at another --size the
 * discs' centres and radius scale with it.
 */
#include "scene.h"

#define PAPER_SIZE 128
#define SPEED 0.8f

static mpca_world *build(const scene_opts *o) {
    mpca_desc d;
    mpca_check(mpca_desc_defaults(&d, 2, o->size, o->size, 0), "mpca_desc_defaults");
    d.drift = MPCA_DRIFT_PAPER; /* the paper's rule, as printed */
    for (int axis = 0; axis < 2; axis++) {
        d.boundary[axis][0] = d.boundary[axis][1] = MPCA_BOUNDARY_WALL;
    }
    d.restitution = 1.0f;
    d.mass = 1.0f;
    d.seed = o->seed;
    mpca_world *w = world_create(&d);
    const float s = (float)o->size / PAPER_SIZE;
    const float r = 10.0f * s, cy = 64.0f * s;
    const float cx[2] = {40.0f * s, 88.0f * s}, vx[2] = {SPEED, -SPEED};
    for (int disc = 0; disc < 2; disc++) {
        for (uint32_t y = 0; y < o->size; y++) {
            for (uint32_t x = 0; x < o->size; x++) {
                float dx = (float)x + 0.5f - cx[disc], dy = (float)y + 0.5f - cy;
                if (dx * dx + dy * dy <= r * r) {
                    const uint32_t pos[3] = {x, y, 0};
                    const float v[3] = {vx[disc], 0.0f, 0.0f};
                    mpca_check(mpca_world_add_particle(w, pos, v), "mpca_world_add_particle");
                }
            }
        }
    }
    return w;
}

static drawn draw(const scene_opts *o, mpca_world *w, const view *v) {
    mpca_desc d;
    d.struct_size = sizeof d;
    mpca_check(mpca_world_desc(w, &d), "mpca_world_desc");
    view2d_begin(o->size, o->size);
    draw_walls_2d(&d, v);
    drawn out = {draw_particles_2d(w, v), 0.0f, 0.0f};
    return out;
}

int main(int argc, char **argv) {
    const scene s = {
        .name = "cluster",
        .title = "4.2 cluster collision",
        .dim = 2,
        .defaults = {.size = PAPER_SIZE, .steps = 130, .seed = 42, .every = 10, .tiles = 6, .px = 512},
        .about = "two discs of radius 10 at v = (+-0.8, 0), e = 1, m = 1, walls all round",
        .build = build,
        .draw = draw,
    };
    return scene_main(&s, argc, argv);
}
