/*
 * A ball moving through smoke, leaving a wake (M13, issue 27): a disc body
 * crosses a world of smoke at a constant speed, pushing the smoke aside,
 * and the channel it clears behind it is carried off with the smoke.
 *
 * The smoke is drag towards still air rising at 0.15 cells per step (the
 * drag rate 0.05, as smoke-flow's), with speed-limited collisions: the
 * world is filled with it at a density of 0.3 at step 0, moving with the
 * air, and a vent along the whole ground keeps it coming at the rate that
 * holds that density, 0.3 x 0.15 particles per step per cell of ground. The
 * world is periodic across and open at the top, where the smoke leaves.
 *
 * The disc (radius 6 cells at 128 x 128, e = 0.5) moves to the right at
 * 0.4 cells per step along y = 56, from x = 16 to x = 112 (240 steps, the
 * run), and stops there.
 * A body never moves by itself: before every step the program moves it by
 * its velocity (mpca_world_move_body), and after the step reads what it
 * handed the particles (mpca_world_body_stats). The smoke it takes is
 * pushed out ahead of it, the smoke it meets bounces off it in its own
 * frame, and behind it the smoke has to come back in from the sides and
 * from below; since the air has no motion of its own to lend (the smoke
 * relaxes towards a fixed flow), the channel stays clear and rises, so the
 * wake lies along a line tilted by the ratio of the two speeds.
 *
 * Printed at the end (the `wake:` line): the density of the smoke in the
 * strip just behind the disc and in the same rows well ahead of it, means
 * over the crossing, and what the disc handed the smoke (momentum per
 * step, particles reflected, pushed and crushed).
 *
 * Drawn: the density in bins of 8 x 8 cells as grey haze, the particles
 * coloured by speed over it, the disc in grey.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "scene.h"

/* Lengths are given for this size and scale with --size; speeds,
 * densities and rates do not. */
#define REFERENCE_SIZE 128
#define PI_F 3.14159265358979323846f

#define AIR_RISE 0.15f
#define DRAG_RATE 0.05f
#define DENSITY 0.3f
#define BALL_SPEED 0.4f
#define BALL_E 0.5f
/* The strip behind the disc whose density says how clear the wake is:
 * this many cells wide. */
#define WAKE_CELLS 8

typedef struct wake_geometry {
    float radius, start, end, height;
} wake_geometry;

static wake_geometry geometry(uint32_t size) {
    const float s = (float)size / REFERENCE_SIZE;
    wake_geometry g = {6.0f * s, 16.0f * s, 112.0f * s, 56.0f * s};
    /* Some cells across at the smallest sizes, so it is a disc. */
    if (g.radius < 2.0f) g.radius = 2.0f;
    return g;
}

/* Where the disc's centre is before step t, and its velocity through that
 * step: BALL_SPEED to the right until it reaches the end, then at rest. */
static float ball_x(const wake_geometry *g, uint64_t t, float *u) {
    float x = g->start + BALL_SPEED * (float)t;
    *u = BALL_SPEED;
    if (x >= g->end) {
        x = g->end;
        *u = 0.0f;
    }
    return x;
}

static mpca_shape disc(const wake_geometry *g, float x) {
    mpca_shape s = {.struct_size = sizeof s, .kind = MPCA_SHAPE_KIND_DISC, .a = {x, g->height, 0.0f}, .radius = g->radius};
    return s;
}

/* What the run measures, for the wake: line. */
static struct {
    uint64_t samples;
    double behind, ahead;      /* sums of the strips' densities */
    double momentum[2];        /* sums of what the disc handed the smoke */
    uint64_t reflected, pushed, crushed;
    uint64_t moving_steps;
    float *occupancy;          /* size x size */
} run;

static mpca_world *build(const scene_opts *o) {
    const wake_geometry g = geometry(o->size);
    mpca_desc d;
    mpca_check(mpca_desc_defaults(&d, 2, o->size, o->size, 0), "mpca_desc_defaults");
    d.boundary[0][0] = d.boundary[0][1] = MPCA_BOUNDARY_PERIODIC;
    d.boundary[1][0] = MPCA_BOUNDARY_WALL; /* the ground */
    d.boundary[1][1] = MPCA_BOUNDARY_OPEN;
    d.collisions = MPCA_COLLISIONS_SPEED_LIMITED;
    d.drag_rate = DRAG_RATE;
    d.drag_wind[1] = AIR_RISE;
    d.emitter_capacity = 1;
    d.obstacles = 1;
    d.body_capacity = 1;
    /* What the disc takes as the first obstacle bounds what it takes
     * anywhere. */
    const mpca_shape first = disc(&g, g.start);
    mpca_check(mpca_desc_surface_entries(&d, &first, &d.body_surface_capacity), "mpca_desc_surface_entries");
    d.seed = o->seed;
    mpca_world *w = world_create(&d);

    /* The smoke already there, at the density the vent keeps, moving with
     * the air; the same seed places it and seeds the world. */
    pcg32 rng = pcg32_new(o->seed, 0);
    const float rising[3] = {0.0f, AIR_RISE, 0.0f};
    for (uint32_t y = 1; y < o->size; y++) {
        for (uint32_t x = 0; x < o->size; x++) {
            if (pcg32_unit(&rng) >= DENSITY) continue;
            const uint32_t pos[3] = {x, y, 0};
            mpca_check(mpca_world_add_particle(w, pos, rising), "mpca_world_add_particle");
        }
    }
    const mpca_emitter vent = {
        .struct_size = sizeof vent,
        .min = {0, 0, 0},
        .max = {o->size, 1, 1},
        .rate = DENSITY * AIR_RISE * (float)o->size,
        .velocity = {0.0f, AIR_RISE, 0.0f},
        .spread = 0.05f,
        .mass = 1.0f,
        .lifetime = 0,
    };
    uint32_t index = 0;
    mpca_check(mpca_world_add_emitter(w, &vent, &index), "mpca_world_add_emitter");
    /* The particles in the disc's cells are pushed out: the disc's place
     * at step 0. */
    const float still[3] = {BALL_SPEED, 0.0f, 0.0f};
    uint32_t id = 0;
    mpca_check(mpca_world_add_body(w, &first, still, BALL_E, &id), "mpca_world_add_body");
    run.occupancy = xrealloc(NULL, (size_t)o->size * o->size * sizeof *run.occupancy);
    return w;
}

/* The mean occupancy of columns x0 .. x0 + width - 1 (wrapped, since the
 * world is periodic across) and rows y0 .. y1 - 1. */
static double strip(const float *occ, uint32_t size, int x0, int width, int y0, int y1) {
    double sum = 0.0;
    int n = 0;
    for (int y = y0 < 0 ? 0 : y0; y < y1 && y < (int)size; y++) {
        for (int i = 0; i < width; i++) {
            int x = ((x0 + i) % (int)size + (int)size) % (int)size;
            sum += occ[(size_t)y * size + (size_t)x];
            n++;
        }
    }
    return n ? sum / n : 0.0;
}

static void step(const scene_opts *o, mpca_world *w, uint64_t t) {
    const wake_geometry g = geometry(o->size);
    float u = 0.0f;
    const float x = ball_x(&g, t, &u);
    const uint32_t id = 0;
    if (t > 0) {
        const mpca_shape s = disc(&g, x);
        const float velocity[3] = {u, 0.0f, 0.0f};
        mpca_check(mpca_world_move_body(w, id, &s, velocity), "mpca_world_move_body");
    }
    scene_step(w, 1, o);
    mpca_body_stats b = {.struct_size = sizeof b};
    mpca_check(mpca_world_body_stats(w, id, &b), "mpca_world_body_stats");
    run.reflected += b.reflected;
    run.pushed += b.pushed;
    run.crushed += b.crushed;
    if (u == 0.0f) return;
    run.moving_steps++;
    run.momentum[0] += b.momentum[0];
    run.momentum[1] += b.momentum[1];
    /* The wake, once the disc has gone a few radii and while it is well
     * short of the end: the strip just behind it against the same rows
     * half the world ahead, which it has not reached yet (or has crossed
     * long enough ago, across the periodic edge, for the smoke to have
     * risen past). */
    if (x < g.start + 3.0f * g.radius || x > g.end - 3.0f * g.radius) return;
    const uint32_t res[3] = {o->size, o->size, 1};
    mpca_check(mpca_world_density(w, res, run.occupancy, (size_t)o->size * o->size), "mpca_world_density");
    const int back = (int)floorf(x - g.radius) - WAKE_CELLS, ahead = back + (int)o->size / 2;
    const int y0 = (int)floorf(g.height - g.radius), y1 = (int)ceilf(g.height + g.radius);
    run.behind += strip(run.occupancy, o->size, back, WAKE_CELLS, y0, y1);
    run.ahead += strip(run.occupancy, o->size, ahead, WAKE_CELLS, y0, y1);
    run.samples++;
}

/* The disc in grey, with the smoke it pushes round it. */
static drawn draw(const scene_opts *o, mpca_world *w, const view *v) {
    const wake_geometry g = geometry(o->size);
    mpca_desc d;
    d.struct_size = sizeof d;
    mpca_check(mpca_world_desc(w, &d), "mpca_world_desc");
    mpca_stats st = {.struct_size = sizeof st};
    mpca_check(mpca_world_stats(w, &st), "mpca_world_stats");
    float u = 0.0f;
    const float x = ball_x(&g, st.step, &u);
    view2d_begin(o->size, o->size);
    enum { SEGMENTS = 64 };
    grey(0.55f);
    glBegin(GL_TRIANGLE_FAN);
    glVertex2f(x, g.height);
    for (int i = 0; i <= SEGMENTS; i++) {
        float a = 2.0f * PI_F * (float)i / SEGMENTS;
        glVertex2f(x + g.radius * cosf(a), g.height + g.radius * sinf(a));
    }
    glEnd();
    draw_walls_2d(&d, v);
    /* Last, so no grey covers a particle's square. */
    drawn out = {draw_particles_2d(w, v), 0.0f, 0.0f};
    return out;
}

int main(int argc, char **argv) {
    const scene s = {
        .name = "wake",
        .title = "a ball through smoke (M13)",
        .dim = 2,
        .defaults = {.size = REFERENCE_SIZE, .steps = 240, .seed = 13, .every = 40, .tiles = 6, .px = 512, .density = 8},
        .about = "a disc body moved at 0.4 cells per step through rising smoke pushes it aside and leaves a clear wake",
        .build = build,
        .draw = draw,
        .step = step,
    };
    int status = scene_main(&s, argc, argv);
    if (status != 0 || run.occupancy == NULL) return status;
    const double n = run.samples ? (double)run.samples : 1.0, m = run.moving_steps ? (double)run.moving_steps : 1.0;
    printf("wake: behind=%.3f ahead=%.3f (density in the %d cells behind the disc and half the world ahead, "
           "mean of %llu steps) momentum_per_step=(%.3f,%.3f) reflected=%llu pushed=%llu crushed=%llu\n",
           run.behind / n, run.ahead / n, WAKE_CELLS, (unsigned long long)run.samples, run.momentum[0] / m,
           run.momentum[1] / m, (unsigned long long)run.reflected, (unsigned long long)run.pushed,
           (unsigned long long)run.crushed);
    free(run.occupancy);
    return 0;
}
