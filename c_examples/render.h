/*
 * The part the four scene programs share: options, the stepping and timing
 * loop, off-screen OpenGL through OSMesa, PNG output through libpng and the
 * contact sheet. A scene program supplies a `scene` (defaults, how to build
 * its world, how to draw it) and calls scene_main().
 *
 * Pixels: frames are square. In 2D a cell is `cell_px` pixels wide and a
 * particle is a square point of `point_px` pixels (one pixel less than the
 * cell when the cell is at least 3 pixels wide, so neighbours stay apart).
 * Particles are drawn in saturated colours and everything else (walls,
 * obstacles, guides, labels) in greys, so `pngstat` can tell them apart:
 * a pixel is "coloured" when max(r,g,b) - min(r,g,b) >= RENDER_CHROMA_MIN.
 */
#ifndef MPCA_RENDER_H
#define MPCA_RENDER_H

#include <stddef.h>
#include <stdint.h>

#include <GL/gl.h>

#include "mpca.h"

/* The background (dark blue-grey) and the chroma that marks a particle. */
#define RENDER_BG_R 16
#define RENDER_BG_G 17
#define RENDER_BG_B 22
#define RENDER_CHROMA_MIN 24

/* Command-line options; every program takes the same ones. */
typedef struct scene_opts {
    uint32_t size;   /* cells per axis */
    uint64_t steps;  /* steps to run */
    uint64_t seed;   /* world seed (and the seed of the initial placement) */
    uint64_t every;  /* a frame every this many steps; 0: none */
    uint32_t tiles;  /* frames in the contact sheet */
    uint32_t px;     /* frame size in pixels (2D: rounded down to whole cells) */
    const char *out; /* output folder */
    const char *name; /* file name prefix */
    uint32_t threads; /* 0: mpca_world_step; else the parallel step on this many threads */
} scene_opts;

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

/* A scene program: its defaults and its two functions. */
typedef struct scene {
    const char *name;    /* "aggregation": the default file prefix */
    const char *title;   /* "4.1 aggregation" */
    uint32_t dim;        /* 2 or 3 */
    scene_opts defaults; /* out and name are set by scene_main */
    const char *about;   /* one line for --help */
    /* Creates and fills the world; exits with a message on failure. */
    mpca_world *(*build)(const scene_opts *o);
    /* Draws the world into the current context (cleared already). */
    drawn (*draw)(const scene_opts *o, mpca_world *w, const view *v);
} scene;

/* Parses the options, builds the world, steps it, writes the frames and the
 * contact sheet, prints progress and timings. Returns the exit status. */
int scene_main(const scene *s, int argc, char **argv);

/* Exits with the library's message when `status` is not MPCA_STATUS_OK. */
void mpca_check(mpca_status status, const char *what);

/* The library's world, created from `desc`, or exit with a message. */
mpca_world *world_create(const mpca_desc *desc);

/* `v * size / reference`, rounded down: scene coordinates given for the
 * paper's size, at another size. */
uint32_t scale_cells(uint32_t v, uint32_t size, uint32_t reference);

/* A 32-bit PCG (XSH RR on a 64-bit LCG), the same generator and seeding as
 * Rust's rand_pcg::Pcg32::new(state, stream), so the C scenes place their
 * initial particles exactly as tests/src/scenes.rs does. */
typedef struct pcg32 {
    uint64_t state, increment;
} pcg32;
pcg32 pcg32_new(uint64_t state, uint64_t stream);
uint32_t pcg32_next(pcg32 *rng);
/* Uniform in [0, 1) with 24 random bits. */
float pcg32_unit(pcg32 *rng);

/* Speed (0..1) to a saturated colour, 2D and 3D palettes. */
void speed_colour(float speed, uint8_t rgb[3]);
void water_colour(float speed, uint8_t rgb[3]);

/* 2D: an orthographic view of nx x ny cells, y up. */
void view2d_begin(uint32_t nx, uint32_t ny);
/* 2D: every particle as a square point coloured by its speed; returns the
 * count. */
size_t draw_particles_2d(mpca_world *w, const view *v);
/* 2D: the faces of the domain that are walls, as grey lines two pixels
 * wide along the image border. */
void draw_walls_2d(const mpca_desc *desc, const view *v);
/* A grey (0..1). */
void grey(float level);

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
 * coloured by speed and darkened with distance. Sprite sizes are clamped to
 * the range a particle inside the nx x ny x nz box can have, which is
 * reported with the count. */
drawn draw_particles_3d(mpca_world *w, const view *v, const camera *c, const uint32_t size[3]);

#endif /* MPCA_RENDER_H */
