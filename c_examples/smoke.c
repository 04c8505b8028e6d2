/*
 * 4.3 smoke (Ecchu, Takai, Sato 1993; docs/model.md "The paper's four scenes"):
 * about one particle per step emitted at the bottom with a rising velocity,
 * swirled by a static Rankine vortex force, e = 1, one mass. The same scene
 * as tests/src/scenes.rs `smoke()`: 128 x 128 (the paper gives no size), a
 * wall below, open on the other faces. At another --size the emitter and
 * the vortex scale with it (circulation too, so the force at corresponding
 * points is the same); the rate stays one particle per step.
 *
 * The vortex is drawn as grey circles at one, two and three core radii
 * with arrowheads in its sense of rotation; the emitter as a grey bar.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "scene.h"

/* Built a second time with -DSMOKE_FLOW as `smoke-flow` (M5.1b, beyond the
 * paper; tests/src/scenes.rs `smoke_flow()`): the same emitter and vortex
 * geometry, but the smoke is buoyancy (an upward acceleration of 0.004)
 * plus drag at rate 0.05 towards the air's flow, with the calibrated drift
 * rule and speed-limited collisions, instead of the paper's vortex force.
 * The air's flow is a vortex fed through its core: the vortex read as a
 * velocity field (circulation 12 at the paper's size) plus an inflow of
 * the same profile in the wind plane (sink strength 8), so the plume winds
 * into the vortex along spiral streamlines. */
#ifdef SMOKE_FLOW
#define CIRCULATION 12.0f
#define INFLOW 8.0f
#else
#define CIRCULATION 2.0f
#endif

#define PAPER_SIZE 128
#define PI_F 3.14159265358979323846f

typedef struct smoke_geometry {
    float centre[2], core, circulation;
    uint32_t emit_min[2], emit_max[2];
} smoke_geometry;

static smoke_geometry geometry(uint32_t size) {
    const float s = (float)size / PAPER_SIZE;
    smoke_geometry g = {{64.0f * s, 72.0f * s}, 10.0f * s, CIRCULATION * s, {0, 0}, {0, 0}};
    g.emit_min[0] = scale_cells(60, size, PAPER_SIZE);
    g.emit_max[0] = scale_cells(68, size, PAPER_SIZE);
    g.emit_max[1] = scale_cells(2, size, PAPER_SIZE);
    for (int k = 0; k < 2; k++) {
        if (g.emit_max[k] <= g.emit_min[k]) g.emit_max[k] = g.emit_min[k] + 1;
    }
    return g;
}

#ifdef SMOKE_FLOW
/* The inflow into the core, in the wind plane: radial, Q r / (2 pi R^2)
 * inside the core and Q / (2 pi r) outside, that is
 * -Q (dx, dy) / (2 pi max(r^2, R^2)); Q scales with the size, as the
 * circulation does. Only + - * / on floats, in the order of
 * tests/src/scenes.rs `smoke_flow_wind()`, so both hold the same bits. */
static void set_inflow(mpca_world *w, const smoke_geometry *g, uint32_t size) {
    const float inflow = INFLOW * ((float)size / PAPER_SIZE);
    const size_t cells = (size_t)size * size;
    float *plane = malloc(2 * cells * sizeof *plane);
    if (plane == NULL) {
        fprintf(stderr, "smoke-flow: out of memory for the wind plane\n");
        exit(1);
    }
    for (uint32_t y = 0; y < size; y++) {
        for (uint32_t x = 0; x < size; x++) {
            const float dx = ((float)x + 0.5f) - g->centre[0], dy = ((float)y + 0.5f) - g->centre[1];
            float r2 = dx * dx + dy * dy;
            const float core2 = g->core * g->core;
            r2 = r2 > core2 ? r2 : core2;
            const float s = -inflow / (2.0f * PI_F * r2);
            plane[2 * ((size_t)y * size + x)] = dx * s;
            plane[2 * ((size_t)y * size + x) + 1] = dy * s;
        }
    }
    mpca_check(mpca_world_set_wind_field(w, plane, 2 * cells), "mpca_world_set_wind_field");
    free(plane);
}
#endif

static mpca_world *build(const scene_opts *o) {
    const smoke_geometry g = geometry(o->size);
    mpca_desc d;
    mpca_check(mpca_desc_defaults(&d, 2, o->size, o->size, 0), "mpca_desc_defaults");
    for (int axis = 0; axis < 2; axis++) {
        d.boundary[axis][0] = d.boundary[axis][1] = MPCA_BOUNDARY_OPEN;
    }
    d.boundary[1][0] = MPCA_BOUNDARY_WALL; /* the ground */
    d.restitution = 1.0f;
#ifdef SMOKE_FLOW
    d.collisions = MPCA_COLLISIONS_SPEED_LIMITED;
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = 0.004f;
    d.drag_rate = 0.05f;
    d.drag_vortex = 1;
    d.drag_wind_field = 1;
#else
    d.drift = MPCA_DRIFT_PAPER; /* the paper's rule, as printed */
    d.forces = MPCA_FORCE_VORTEX;
#endif
    d.vortex_centre[0] = g.centre[0];
    d.vortex_centre[1] = g.centre[1];
    d.vortex_core_radius = g.core;
    d.vortex_circulation = g.circulation;
    d.emitter_capacity = 1;
    d.seed = o->seed;
    mpca_world *w = world_create(&d);
    const mpca_emitter e = {
        .struct_size = sizeof e,
        .min = {g.emit_min[0], g.emit_min[1], 0},
        .max = {g.emit_max[0], g.emit_max[1], 1},
        .rate = 1.0f,
        .velocity = {0.0f, 0.6f, 0.0f},
        .spread = 0.2f,
        .mass = 1.0f,
        .lifetime = 0,
    };
    uint32_t index = 0;
    mpca_check(mpca_world_add_emitter(w, &e, &index), "mpca_world_add_emitter");
#ifdef SMOKE_FLOW
    set_inflow(w, &g, o->size);
#endif
    return w;
}

/* A circle of radius r round the vortex centre with three arrowheads
 * pointing along the rotation (counter-clockwise for circulation > 0). */
static void vortex_ring(const smoke_geometry *g, float r) {
    enum { SEGMENTS = 96 };
    glBegin(GL_LINE_LOOP);
    for (int i = 0; i < SEGMENTS; i++) {
        float a = 2.0f * PI_F * (float)i / SEGMENTS;
        glVertex2f(g->centre[0] + r * cosf(a), g->centre[1] + r * sinf(a));
    }
    glEnd();
    float sense = g->circulation >= 0.0f ? 1.0f : -1.0f;
    float head = 0.15f * r < 3.0f ? 0.15f * r : 3.0f;
    glBegin(GL_LINES);
    for (int i = 0; i < 3; i++) {
        float a = 2.0f * PI_F * ((float)i / 3.0f + 0.1f * r / g->core);
        float px = g->centre[0] + r * cosf(a), py = g->centre[1] + r * sinf(a);
        float tx = -sinf(a) * sense, ty = cosf(a) * sense; /* along the flow */
        float nx = cosf(a), ny = sinf(a);                  /* outwards */
        for (int side = -1; side <= 1; side += 2) {
            glVertex2f(px, py);
            glVertex2f(px - head * (tx + 0.6f * (float)side * nx), py - head * (ty + 0.6f * (float)side * ny));
        }
    }
    glEnd();
}

static drawn draw(const scene_opts *o, mpca_world *w, const view *v) {
    const smoke_geometry g = geometry(o->size);
    mpca_desc d;
    d.struct_size = sizeof d;
    mpca_check(mpca_world_desc(w, &d), "mpca_world_desc");
    view2d_begin(o->size, o->size);
    grey(0.38f);
    for (int i = 1; i <= 3; i++) vortex_ring(&g, g.core * (float)i);
    grey(0.4f);
    glRectf((float)g.emit_min[0], (float)g.emit_min[1], (float)g.emit_max[0], (float)g.emit_max[1]);
    draw_walls_2d(&d, v);
    drawn out = {draw_particles_2d(w, v), 0.0f, 0.0f};
    return out;
}

int main(int argc, char **argv) {
#ifdef SMOKE_FLOW
    const scene s = {
        .name = "smoke-flow",
        .title = "4.3 smoke with flow drag (M5.1b)",
        .dim = 2,
        /* The density drawn as haze: smoke as a renderer would show it. */
        .defaults = {.size = PAPER_SIZE, .steps = 1200, .seed = 43, .every = 100, .tiles = 6, .px = 512, .density = 8},
        .about = "buoyant smoke dragged towards the flow of a vortex fed through its core: it rises at its terminal speed and winds into the vortex",
        .build = build,
        .draw = draw,
    };
#else
    const scene s = {
        .name = "smoke",
        .title = "4.3 smoke",
        .dim = 2,
        .defaults = {.size = PAPER_SIZE, .steps = 120, .seed = 43, .every = 10, .tiles = 6, .px = 512},
        .about = "one particle per step rising from the ground into a static Rankine vortex, e = 1",
        .build = build,
        .draw = draw,
    };
#endif
    return scene_main(&s, argc, argv);
}
