/*
 * The path a real-time engine takes to draw an mpca world, in OpenGL 2.1
 * and GLSL 1.20 (also what OpenGL ES 2 and WebGL offer, and what every
 * OSMesa and desktop driver runs):
 *
 *   - the particles' positions and velocities are exported by the library
 *     straight into a vertex buffer object (glMapBuffer, no copy of our
 *     own), and a shader turns each into a point: coloured by speed through
 *     a palette texture, square in 2D, a shaded sprite sized by its distance
 *     in 3D;
 *   - the density (mpca_world_density_u8) is uploaded into a texture and
 *     drawn on a quad with linear filtering, as a soft haze.
 *
 * Usage, once per frame with a current GL context:
 *
 *   gpu *g = gpu_create();                          once
 *   size_t n = gpu_upload_particles(g, world);
 *   gpu_draw_points_2d(g, mvp, point_px);           or gpu_draw_sprites_3d
 *   gpu_destroy(g);                                 at the end
 *
 * `mvp` is the model-view-projection matrix, column-major as OpenGL takes
 * it, mapping cell coordinates (x, y, z in cells) to clip space. The
 * objects belong to the context that was current at gpu_create(), which
 * must be current for every other call. GL errors and shader compile errors
 * end the program with a message.
 */
#ifndef MPCA_EXAMPLES_GPU_H
#define MPCA_EXAMPLES_GPU_H

#include <stddef.h>
#include <stdint.h>

#include <GL/gl.h>

#include "mpca.h"

typedef struct gpu gpu;

/* A shader program from GLSL sources, its attributes bound to the
 * locations every program here uses; ends the program with the compiler's
 * log when it does not compile or link. */
GLuint gpu_program(const char *vs, const char *fs, const char *name);
/* Ends the program with a message naming `what` on a GL error. */
void gpu_check(const char *what);

/* Compiles the shaders, creates the buffers and the palette textures. */
gpu *gpu_create(void);
void gpu_destroy(gpu *g);

/* Exports every particle's position and velocity into the vertex buffer;
 * returns the count. */
size_t gpu_upload_particles(gpu *g, const mpca_world *w);

/* 2D: the uploaded particles as unsmoothed squares of `point_px` pixels,
 * coloured by the square root of their speed (blue slow, through cyan,
 * green and yellow, to red at 1 cell per step). */
void gpu_draw_points_2d(gpu *g, const float mvp[16], float point_px);

/* 3D: how the sprites are sized and shaded. */
typedef struct gpu_sprites {
    float eye[3];         /* the camera, in cells */
    float focal_px;       /* a cell at distance d is focal_px / d pixels wide */
    float min_px, max_px; /* the sprite diameter is clamped to this range */
    float near_d, far_d;  /* full colour at near_d, half at far_d and beyond */
} gpu_sprites;

/* 3D: the uploaded particles as sprites one cell wide, lit from the upper
 * left, coloured by speed (dark blue slow to light cyan) and darkened with
 * distance. Depth-tested against what is drawn already. */
void gpu_draw_sprites_3d(gpu *g, const float mvp[16], const gpu_sprites *s);

/* 2D, once a step: `n` particles' cell centres before the step (`from`)
 * and after it (`to`), 2 floats each, and their ages after it, into the
 * motion buffer (c_examples/smoke-ids.c matches the two by id). */
void gpu_upload_motion_2d(gpu *g, const float *from, const float *to, const uint32_t *ages, size_t n);

/* 2D: how the uploaded motion is drawn, any number of times a step. */
typedef struct gpu_smoke {
    float blend;     /* where between the two steps: 0 before, 1 after */
    float lifetime;  /* steps; a puff fades out over them */
    float sprite_px; /* a puff's diameter in pixels */
    float peak;      /* a new puff's alpha at its centre */
} gpu_smoke;

/* 2D: the uploaded particles as soft round puffs at `blend` between
 * their two positions, alpha-blended over what is drawn already, fading
 * and cooling in colour (yellow, orange, red, violet) with age. */
void gpu_draw_smoke_2d(gpu *g, const float mvp[16], const gpu_smoke *s);

/* 2D: the world's density in bins of `bin` x `bin` cells into the density
 * texture (the world's size must be a multiple of `bin`). */
void gpu_upload_density_2d(gpu *g, const mpca_world *w, uint32_t bin);

/* 2D: the density texture over the world's nx x ny cells, as grey haze on
 * the background colour `bg` (RGB, 0..1): a bin of density `full` or more
 * is at its brightest, an empty bin is exactly the background. */
void gpu_draw_density_2d(gpu *g, const float mvp[16], uint32_t nx, uint32_t ny, const float bg[3], float full);

#endif /* MPCA_EXAMPLES_GPU_H */
