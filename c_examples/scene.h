/*
 * A scene program: its defaults, how it builds its world and how it draws
 * it. scene_main() does the rest: options, stepping (serially or on
 * threads), the frames, the contact sheet, timings. The parts it uses are
 * options.h (command line), draw.h (OpenGL through OSMesa) and image.h
 * (images and PNG files).
 */
#ifndef MPCA_EXAMPLES_SCENE_H
#define MPCA_EXAMPLES_SCENE_H

#include <stdint.h>

#include "common.h"
#include "draw.h"
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
} scene;

/* Parses the options, builds the world, steps it, writes the frames and the
 * contact sheet, prints progress and timings. Returns the exit status. */
int scene_main(const scene *s, int argc, char **argv);

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
