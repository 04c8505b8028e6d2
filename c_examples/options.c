/*
 * The command-line options every scene program takes. See options.h.
 */
#include "options.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mpca.h"
#include "scene.h"

static void usage(const scene *s, FILE *f) {
    const scene_opts *d = &s->defaults;
    fprintf(f,
            "usage: %s [options]\n"
            "%s: %s\n"
            "Renders off-screen (OSMesa) and writes PNG frames (NAME-frame-0000.png,\n"
            "NAME-frame-0001.png, ...), a contact sheet (NAME-sheet.png) and an animated\n"
            "GIF (NAME.gif).\n"
            "  --size N    cells per axis, even, at least 8 (default %u)\n"
            "  --steps N   steps to run (default %llu)\n"
            "  --seed N    seed of the world and of the initial placement (default %llu)\n"
            "  --every N   write a frame every N steps, 0 for none (default %llu)\n"
            "  --tiles N   frames in the contact sheet, 1 to 12 (default %u)\n"
            "  --gif N     frames in the animated GIF, at the sheet's size, 0 for none,\n"
            "              at most %d (default %d)\n"
            "  --px N      frame width in pixels (default %u; the sheet's tiles are half)\n"
            "  --out DIR   output folder, created if missing (default " DEFAULT_OUT ")\n"
            "  --name S    file name prefix (default %s)\n"
            "  --threads N step in tasks on N threads, 1 to 16 (M11; default: mpca_world_step)\n"
            "  --density N 2D: the density in bins of N x N cells, uploaded as a texture and\n"
            "              drawn as grey haze under the particles; 0 for none (default %u)\n"
            "  --png-level N  PNG compression, 0 (none) to 9 (smallest, slowest; default %d)\n"
            "  --progress  report progress on stderr every 10 %% of the steps\n"
            "  --quiet     no progress report (the default reports it when stderr is a\n"
            "              terminal, once the run has taken a second)\n"
            "  --version   print the program's and libmpca's versions and exit\n"
            "  --help      print this and exit\n",
            s->name, s->title, s->about, (unsigned)d->size, (unsigned long long)d->steps,
            (unsigned long long)d->seed, (unsigned long long)d->every, (unsigned)d->tiles, MAX_GIF_FRAMES,
            DEFAULT_GIF_FRAMES, (unsigned)d->px, s->name, (unsigned)d->density, DEFAULT_PNG_LEVEL);
}

static int parse_u64(const char *text, uint64_t max, uint64_t *out) {
    if (!text || *text < '0' || *text > '9') return 0;
    char *end = NULL;
    errno = 0;
    unsigned long long v = strtoull(text, &end, 10);
    if (errno || *end || v > max) return 0;
    *out = v;
    return 1;
}

int options_parse(const scene *s, scene_opts *o, int argc, char **argv) {
    *o = s->defaults;
    o->out = DEFAULT_OUT;
    o->name = s->name;
    o->png_level = DEFAULT_PNG_LEVEL;
    o->gif = DEFAULT_GIF_FRAMES;
    o->progress = PROGRESS_AUTO;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(s, stdout);
            return 0;
        }
        if (strcmp(a, "--version") == 0) {
            printf("%s (libmpca %s)\n", s->name, mpca_version());
            return 0;
        }
        if (strcmp(a, "--progress") == 0 || strcmp(a, "--quiet") == 0) {
            o->progress = a[2] == 'p' ? PROGRESS_ALWAYS : PROGRESS_NEVER;
            continue;
        }
        const char *value = i + 1 < argc ? argv[i + 1] : NULL;
        uint64_t v = 0;
        int ok = 1;
        if (strcmp(a, "--size") == 0) {
            ok = parse_u64(value, 4096, &v) && v >= 8 && v % 2 == 0;
            o->size = (uint32_t)v;
        } else if (strcmp(a, "--steps") == 0) {
            ok = parse_u64(value, 100000000, &v);
            o->steps = v;
        } else if (strcmp(a, "--seed") == 0) {
            ok = parse_u64(value, UINT64_MAX, &v);
            o->seed = v;
        } else if (strcmp(a, "--every") == 0) {
            ok = parse_u64(value, 100000000, &v);
            o->every = v;
        } else if (strcmp(a, "--tiles") == 0) {
            ok = parse_u64(value, 12, &v) && v >= 1;
            o->tiles = (uint32_t)v;
        } else if (strcmp(a, "--px") == 0) {
            ok = parse_u64(value, 4096, &v) && v >= 16;
            o->px = (uint32_t)v;
        } else if (strcmp(a, "--out") == 0) {
            ok = value && *value;
            o->out = value;
        } else if (strcmp(a, "--threads") == 0) {
            ok = parse_u64(value, 16, &v) && v >= 1;
            o->threads = (uint32_t)v;
        } else if (strcmp(a, "--gif") == 0) {
            ok = parse_u64(value, MAX_GIF_FRAMES, &v);
            o->gif = (uint32_t)v;
        } else if (strcmp(a, "--density") == 0) {
            ok = parse_u64(value, 4096, &v) && (s->dim == 2 || v == 0);
            o->density = (uint32_t)v;
        } else if (strcmp(a, "--png-level") == 0) {
            ok = parse_u64(value, 9, &v);
            o->png_level = (uint32_t)v;
        } else if (strcmp(a, "--name") == 0) {
            ok = value && *value && !strchr(value, '/');
            o->name = value;
        } else {
            fprintf(stderr, "%s: unknown option '%s'\n", s->name, a);
            usage(s, stderr);
            return 2;
        }
        if (!ok) {
            fprintf(stderr, "%s: bad or missing value for %s: '%s'\n", s->name, a, value ? value : "");
            usage(s, stderr);
            return 2;
        }
        i++;
    }
    return -1;
}

