/*
 * Particles drawn as a game engine draws effects, in OpenGL 2.1 and GLSL
 * 1.20 plus a framebuffer object (also what OpenGL ES 2 and WebGL offer):
 *
 *   - smoke as soft sprites: a puff texture (a radial falloff broken up by
 *     noise) turned by a per-particle angle, growing and fading with age,
 *     laid over one another with premultiplied alpha;
 *   - a liquid as a surface: every particle splatted as a blurred disc
 *     into an offscreen density image (an 8-bit texture behind a
 *     framebuffer object), which a second pass thresholds and shades: an
 *     antialiased edge, a bright rim along it, a tint that darkens with
 *     the depth below the surface, a highlight from the image's gradient,
 *     foam where the liquid runs fast, and a lone particle as a faint drop;
 *   - grains as small opaque discs, lit as beads, coloured by material
 *     (the particle's tag) with a per-grain jitter.
 *
 * All three read one vertex a particle, a `moving` (follow.h fills them):
 * its cell centre before and after the last step, so every frame may be
 * drawn part of the way between the two, and the traits the looks need.
 *
 *   engine *e = engine_create();                     once, context current
 *   engine_upload(e, particles, n);                  once a step
 *   engine_draw_smoke(e, mvp, &smoke_look);          any number of times
 *   engine_destroy(e);
 *
 * `mvp` maps cell coordinates to clip space, as in gpu.h. GL errors and
 * shader errors end the program with a message.
 */
#ifndef MPCA_EXAMPLES_ENGINE_H
#define MPCA_EXAMPLES_ENGINE_H

#include <stddef.h>
#include <stdint.h>

/* One particle between two steps. */
typedef struct moving {
    float from[2], to[2]; /* cell centres before and after the step */
    float age;            /* steps lived, after the step (0 without ages) */
    float tag;            /* the caller's byte (M6b; 0 without tags) */
    float seed;           /* in [0, 1), the same all its life (from its id) */
    /* Cells a step it has travelled lately (its last steps' lengths,
     * averaged): not its stored speed, which a particle pressed against a
     * floor keeps while it goes nowhere (M5.7). */
    float travel;
} moving;

typedef struct engine engine;

engine *engine_create(void);
void engine_destroy(engine *e);

/* The particles of the last step, into the vertex buffer. */
void engine_upload(engine *e, const moving *particles, size_t n);

/* Smoke: how the uploaded particles are drawn as puffs. */
typedef struct smoke_look {
    float blend;       /* where between the two steps: 0 before, 1 after */
    float lifetime;    /* steps; a puff is gone when its particle dies */
    float fade_in;     /* steps over which a new puff grows opaque */
    float start_px;    /* a new puff's diameter in pixels */
    float end_px;      /* its diameter at the end of its life */
    float peak;        /* a young puff's opacity at its centre */
    float spin;        /* turns a puff makes over its life, either way */
    float young[3];    /* colour of new smoke, RGB 0..1 */
    float old[3];      /* colour it turns to as it ages */
} smoke_look;
void engine_draw_smoke(engine *e, const float mvp[16], const smoke_look *s);

/* A liquid: how the uploaded particles become a surface. */
typedef struct liquid_look {
    float blend;         /* between the two steps, as for smoke */
    float cell_px;       /* pixels a cell */
    float cells[2];      /* the world's size, in cells */
    /* Faces of the world that are walls (bit 2 axis + side: 1 low x, 2 high
     * x, 4 low y, 8 high y): the liquid is splatted mirrored across them,
     * as if it went on behind the wall, so its surface meets the wall
     * instead of curling away from it. */
    uint32_t walls;
    float radius_cells;  /* a splat's radius, in cells */
    float depth_cells;   /* the depth below the surface at which the tint is deepest */
    float foam_travel;   /* cells a step above which the liquid turns white with foam */
    float shallow[3];    /* colour at the surface, RGB 0..1 */
    float deep[3];       /* colour at depth_cells and below */
} liquid_look;
/* Draws into a `width` x `height` frame: the splats go to the engine's
 * own image of that size, the shaded surface over what the frame holds. */
void engine_draw_liquid(engine *e, const float mvp[16], uint32_t width, uint32_t height, const liquid_look *l);

/* Grains: how the uploaded particles are drawn as discs. */
typedef struct grain_look {
    float blend;              /* between the two steps, as for smoke */
    float grain_px;           /* a grain's mean diameter in pixels */
    float jitter;             /* how far a grain's brightness strays, 0..1 */
    float scatter;            /* how far off its cell's centre it is drawn, in cells */
    const float (*colours)[3]; /* a colour per tag, RGB 0..1 */
    uint32_t materials;       /* how many; larger tags take the last */
} grain_look;
void engine_draw_grains(engine *e, const float mvp[16], const grain_look *g);

#endif /* MPCA_EXAMPLES_ENGINE_H */
