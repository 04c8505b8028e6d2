/*
 * OpenGL drawing, off-screen through OSMesa: the canvas a frame is drawn
 * into, the 2D and 3D views, the fixed parts of the scenes, and the
 * particles and the density (drawn by gpu.c, the path a real-time engine
 * would take).
 *
 * Pixels: frames are square. In 2D a cell is `cell_px` pixels wide and a
 * particle is a square point of `point_px` pixels (one pixel less than the
 * cell when the cell is at least 3 pixels wide, so neighbours stay apart).
 * Particles are drawn in saturated colours and everything else (walls,
 * obstacles, guides, labels) in greys, so `pngstat` can tell them apart
 * (image.h, RENDER_CHROMA_MIN).
 */
#ifndef MPCA_EXAMPLES_DRAW_H
#define MPCA_EXAMPLES_DRAW_H

#include <stddef.h>
#include <stdint.h>

#include <GL/gl.h>

#include "engine.h"
#include "mpca.h"

/* What one drawing call renders into: the pixel size of the image and, in
 * 2D, the size of a cell and of a particle in pixels. */
typedef struct view {
    uint32_t width, height;
    uint32_t cell_px;  /* 2D */
    uint32_t point_px; /* 2D */
} view;

/* What a drawing call drew: the particle count and, in 3D, the range of
 * sprite diameters in pixels (0 in 2D). */
typedef struct drawn {
    size_t particles;
    float sprite_min_px, sprite_max_px;
} drawn;

/* An OSMesa context that draws into memory the caller owns. */
typedef struct canvas canvas;
canvas *canvas_create(void);
/* Makes `rgba` (v->width x v->height, rows bottom to top) the target,
 * clears it to the background and sets the viewport. */
void canvas_begin(canvas *c, uint8_t *rgba, const view *v);
/* Waits for the drawing to land in the buffer; exits on an OpenGL error,
 * naming `what`. */
void canvas_end(canvas *c, const char *what);
/* Frees the context and the drawing code's buffers. */
void canvas_destroy(canvas *c);

/* A grey (0..1). */
void grey(float level);

/* 2D: an orthographic view of nx x ny cells, y up. */
void view2d_begin(uint32_t nx, uint32_t ny);
/* 2D: every particle as a square point coloured by its speed, through a
 * vertex buffer and a shader (gpu.h); returns the count. */
size_t draw_particles_2d(mpca_world *w, const view *v);
/* 2D: the density in bins of `bin` x `bin` cells, uploaded into a texture
 * and drawn over the whole view as grey haze (gpu.h), brightest where a
 * bin's share of occupied cells is `full` or more. */
void draw_density_2d(mpca_world *w, uint32_t bin, float full);
/* 2D, once a step: the particles' cell centres before the step and after
 * it (2 floats each) and their ages, into a vertex buffer (gpu.h,
 * gpu_upload_motion_2d). */
void upload_motion_2d(const float *from, const float *to, const uint32_t *ages, size_t n);
/* 2D: the uploaded particles as soft puffs of `sprite_px` pixels at
 * `blend` (0 to 1) between their two cells, fading out over `lifetime`
 * steps of age (gpu.h, gpu_draw_smoke_2d). */
void draw_motion_2d(float blend, float lifetime, float sprite_px, float peak);
/* 2D: the faces of the domain that are walls, as grey lines two pixels
 * wide along the image border. */
void draw_walls_2d(const mpca_desc *desc, const view *v);
/* 2D: an obstacle shape (a box or a disc; a half-space up to the view's
 * edge) as a solid grey of `level`, over what is drawn. */
void draw_shape_2d(const mpca_shape *shape, float level);

/* 2D, drawn as a game engine draws effects (engine.h): once a step, the
 * particles followed between the last two steps (follow.h), into a vertex
 * buffer; then, any number of times, */
void upload_moving_2d(const moving *particles, size_t n);
/* as soft puffs that grow and fade with age (smoke), */
void draw_puffs_2d(const smoke_look *s);
/* as a shaded liquid surface over the frame `v`, splatted from them
 * (`l->cell_px` and `l->cells` are taken from `v`), */
void draw_liquid_2d(const liquid_look *l, const view *v);
/* or as opaque grains coloured by tag. */
void draw_grains_2d(const grain_look *g);

/* 3D: a camera looking at `target` from `eye`, y up. */
typedef struct camera {
    float eye[3], target[3];
    float fov_deg;
    float near_clip, far_clip;
} camera;
void view3d_begin(const view *v, const camera *c);
/* 3D: a lit grey sphere. */
void draw_sphere(const float centre[3], float radius);
/* 3D: a floor of nx x nz cells at y = 0 with a grid every `grid` cells,
 * and the edges of the box up to height ny. */
void draw_floor_and_box(uint32_t nx, uint32_t ny, uint32_t nz, uint32_t grid);
/* 3D: every particle as a perspective point sprite one cell wide,
 * coloured by speed and darkened with distance, through a vertex buffer
 * and a shader (gpu.h). Sprite sizes are clamped to
 * the range a particle inside the nx x ny x nz box can have, which is
 * reported with the count. */
drawn draw_particles_3d(mpca_world *w, const view *v, const camera *c, const uint32_t size[3]);

#endif /* MPCA_EXAMPLES_DRAW_H */
