/*
 * The command-line options every scene program takes (--help lists them).
 */
#ifndef MPCA_EXAMPLES_OPTIONS_H
#define MPCA_EXAMPLES_OPTIONS_H

#include <stdint.h>

#define DEFAULT_OUT "out/scenes"

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

struct scene;

/* Fills `o` from the scene's defaults and argv. Returns -1 to go on, or
 * the status to exit with (0 after --help or --version, 2 on a bad
 * option, with the usage on stderr). */
int options_parse(const struct scene *s, scene_opts *o, int argc, char **argv);

#endif /* MPCA_EXAMPLES_OPTIONS_H */
