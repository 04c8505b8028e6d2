/*
 * A scene program: its defaults, how it builds its world and how it draws
 * it. scene_main() does the rest: options, stepping (serially or on
 * threads), the frames, the contact sheet, timings. The parts it uses are
 * options.h (command line), draw.h (OpenGL through OSMesa) and image.h
 * (images and PNG files).
 */
#ifndef MPCA_EXAMPLES_SCENE_H
#define MPCA_EXAMPLES_SCENE_H

#include <stddef.h>
#include <stdint.h>

#include "common.h"
#include "draw.h"
#include "gif.h"
#include "image.h"
#include "mpca.h"
#include "options.h"

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
    /* Takes step t (from t to t + 1) with what the scene moves around it,
     * its bodies (M13) say, which the caller moves before every step; it
     * steps the world with scene_step. NULL: scene_main steps on to the
     * next frame in one call. */
    void (*step)(const scene_opts *o, mpca_world *w, uint64_t t);
} scene;

/* Parses the options, builds the world, steps it, writes the frames and the
 * contact sheet, prints progress and timings. Returns the exit status. */
int scene_main(const scene *s, int argc, char **argv);

/* Parts of that loop, for a program that runs its own (smoke-ids.c, which
 * steps one step at a time and draws between steps). */
/* Steps `w` on `n` steps as the options say: mpca_world_step, or the
 * parallel step on o->threads POSIX threads. */
void scene_step(mpca_world *w, uint64_t n, const scene_opts *o);
/* mkdir -p; exits with a message on failure. */
void scene_make_dirs(const char *path);
/* Step i of n spread evenly over 0..steps, both ends included:
 * round(i * steps / (n - 1)); the end alone when n is 1. */
uint64_t scene_spread(uint64_t i, uint64_t n, uint64_t steps);

/* Gap between the contact sheet's tiles, and margin of a GIF frame's
 * label, in pixels: a sheet is SHEET_GAP + tiles * (width + SHEET_GAP)
 * wide, a GIF frame LABEL_HEIGHT + 2 * GIF_GAP taller than a tile. */
#define SHEET_GAP 6
#define GIF_GAP 4

/* Writes the drawing `gl` (RGBA rows as OpenGL reads them, fv's size),
 * through `frame`, as the PNG of frame `n` into o->out, its number
 * `digits` wide; its path goes to `path` (`path_len` bytes). */
void scene_frame_png(image *frame, const uint8_t *gl, const view *fv, const scene_opts *o, int digits, uint64_t n,
                     char *path, size_t path_len);

/* Draws the tile `gl` (RGBA rows as OpenGL reads them, tv's size) into
 * place `i` of the contact sheet, with its label. */
void scene_tile(image *sheet, const uint8_t *gl, const view *tv, uint64_t i, const char *label);
/* Adds the tile `gl` with its label to the GIF, as `frame` (the GIF's
 * size) drawn anew. */
void scene_gif_frame(gif_anim *gif, image *frame, const uint8_t *gl, const view *tv, const char *label);

/* The end of a scene's run: writes the contact sheet and, where `gif`
 * holds frames, the animated GIF (frames of `delay_cs`, the last of
 * `last_delay_cs`, hundredths of a second) into o->out, and frees `gif`;
 * prints where they went, then the world's statistics (into `stats`) and
 * hash on one `end:` line. Returns the seconds the sheet's PNG took. */
double scene_finish(const scene_opts *o, const image *sheet, unsigned tiles, gif_anim *gif, const image *gif_frame,
                    int delay_cs, int last_delay_cs, mpca_world *w, mpca_stats *stats);

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

#endif /* MPCA_EXAMPLES_SCENE_H */
