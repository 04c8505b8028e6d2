/*
 * The command-line options every scene program takes (--help lists them).
 */
#ifndef MPCA_EXAMPLES_OPTIONS_H
#define MPCA_EXAMPLES_OPTIONS_H

#include <stdint.h>

#define DEFAULT_OUT "out/scenes"
/* zlib's own default. On the scenes' images level 9 takes about three
 * times as long for files 5 % smaller (scripts/png-level.sh measures it). */
#define DEFAULT_PNG_LEVEL 6

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
    uint32_t png_level; /* zlib compression level of the PNGs, 0 to 9 */
    uint32_t density; /* 2D: the density as haze in bins of this many cells; 0: none */
    uint32_t gif;     /* frames in the animated GIF; 0: no GIF */
    int progress;     /* PROGRESS_* */
} scene_opts;

/* Progress on stderr: never (--quiet), always (--progress), or when stderr
 * is a terminal and the run has taken a second (the default). */
enum { PROGRESS_NEVER, PROGRESS_AUTO, PROGRESS_ALWAYS };

#define DEFAULT_GIF_FRAMES 40
#define MAX_GIF_FRAMES 1000

struct scene;

/* Fills `o` from the scene's defaults and argv. Returns -1 to go on, or
 * the status to exit with (0 after --help or --version, 2 on a bad
 * option, with the usage on stderr). */
int options_parse(const struct scene *s, scene_opts *o, int argc, char **argv);

#endif /* MPCA_EXAMPLES_OPTIONS_H */
