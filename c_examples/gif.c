/*
 * Animated GIFs through giflib: see gif.h.
 *
 * giflib writes the file; the palette is ours. giflib's own quantizer
 * (GifQuantizeBuffer) is deprecated and left out of some builds of the
 * library, so a median cut of our own picks the colours: pixels are
 * counted in a histogram of 5 bits per channel, the histogram's cells are
 * split into boxes until there are 255, and each box's colour is the mean
 * of the pixels in it. The index after the last colour means "unchanged"
 * (transparent), and the palette is the smallest power of two that holds
 * them all, since LZW codes start one bit wider than its indices.
 */
#define _POSIX_C_SOURCE 200809L

#include "gif.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <gif_lib.h>

#include "common.h"

#define CELLS (1u << 15) /* 5 bits per channel */
#define MAX_COLOURS 255

struct gif_anim {
    uint32_t width, height, frames, capacity;
    uint16_t *cells; /* per frame, per pixel: its histogram cell */
    /* Per histogram cell: pixels and their channel sums, over all frames. */
    uint64_t count[CELLS];
    uint64_t sum[CELLS][3];
};

static uint16_t cell_of(const uint8_t *rgb) {
    return (uint16_t)(((unsigned)(rgb[0] >> 3) << 10) | ((unsigned)(rgb[1] >> 3) << 5) | (unsigned)(rgb[2] >> 3));
}

/* Channel k (0 red, 1 green, 2 blue) of a cell, 0..31. */
static unsigned cell_channel(uint16_t cell, int k) {
    return (cell >> (10 - 5 * k)) & 31u;
}

gif_anim *gif_new(uint32_t width, uint32_t height) {
    gif_anim *a = xrealloc(NULL, sizeof *a);
    memset(a, 0, sizeof *a);
    a->width = width;
    a->height = height;
    return a;
}

void gif_free(gif_anim *a) {
    if (!a) return;
    free(a->cells);
    free(a);
}

void gif_add(gif_anim *a, const image *frame) {
    if (frame->width != a->width || frame->height != a->height) {
        fprintf(stderr, "gif_add: a %ux%u frame in a %ux%u animation\n", (unsigned)frame->width,
                (unsigned)frame->height, (unsigned)a->width, (unsigned)a->height);
        exit(1);
    }
    size_t pixels = (size_t)a->width * a->height;
    if (a->frames == a->capacity) {
        a->capacity = a->capacity ? 2 * a->capacity : 16;
        a->cells = xrealloc(a->cells, (size_t)a->capacity * pixels * sizeof *a->cells);
    }
    uint16_t *out = a->cells + (size_t)a->frames * pixels;
    for (size_t i = 0; i < pixels; i++) {
        const uint8_t *p = frame->rgba + 4 * i;
        uint16_t c = cell_of(p);
        out[i] = c;
        a->count[c]++;
        for (int k = 0; k < 3; k++) a->sum[c][k] += p[k];
    }
    a->frames++;
}

/* ---- the palette: median cut over the histogram's occupied cells ---------- */

typedef struct box {
    uint32_t start, end; /* a range of the occupied-cell list */
    uint64_t pixels;
    int axis;            /* the channel with the widest range */
    unsigned range;      /* that range, in cells */
} box;

static int sort_axis; /* qsort has no context argument in C99 */
static int by_channel(const void *x, const void *y) {
    unsigned a = cell_channel(*(const uint16_t *)x, sort_axis), b = cell_channel(*(const uint16_t *)y, sort_axis);
    return (a > b) - (a < b);
}

static void measure(box *b, const uint16_t *cells, const uint64_t *count) {
    unsigned lo[3] = {31, 31, 31}, hi[3] = {0, 0, 0};
    b->pixels = 0;
    for (uint32_t i = b->start; i < b->end; i++) {
        b->pixels += count[cells[i]];
        for (int k = 0; k < 3; k++) {
            unsigned v = cell_channel(cells[i], k);
            if (v < lo[k]) lo[k] = v;
            if (v > hi[k]) hi[k] = v;
        }
    }
    b->axis = 0;
    b->range = 0;
    for (int k = 0; k < 3; k++) {
        if (hi[k] - lo[k] > b->range) {
            b->range = hi[k] - lo[k];
            b->axis = k;
        }
    }
}

/* Fills `colours` and `index_of` (histogram cell to palette index);
 * returns the number of colours. */
static uint32_t median_cut(const gif_anim *a, GifColorType colours[256], uint8_t *index_of) {
    uint16_t *cells = xrealloc(NULL, CELLS * sizeof *cells);
    uint32_t occupied = 0;
    for (uint32_t c = 0; c < CELLS; c++) {
        if (a->count[c]) cells[occupied++] = (uint16_t)c;
    }
    box boxes[MAX_COLOURS];
    uint32_t n = 0;
    if (occupied) {
        boxes[n++] = (box){0, occupied, 0, 0, 0};
        measure(&boxes[0], cells, a->count);
    }
    while (n < MAX_COLOURS) {
        /* Split the box where it matters most: many pixels over a wide
         * range. A box of one cell cannot split. */
        uint32_t pick = n;
        uint64_t best = 0;
        for (uint32_t i = 0; i < n; i++) {
            uint64_t weight = boxes[i].pixels * boxes[i].range;
            if (boxes[i].end - boxes[i].start > 1 && weight > best) {
                best = weight;
                pick = i;
            }
        }
        if (pick == n) break;
        box *b = &boxes[pick];
        sort_axis = b->axis;
        qsort(cells + b->start, b->end - b->start, sizeof *cells, by_channel);
        /* At the median pixel, keeping a cell on each side. */
        uint64_t seen = 0;
        uint32_t cut = b->start + 1;
        for (uint32_t i = b->start; i + 1 < b->end; i++) {
            seen += a->count[cells[i]];
            cut = i + 1;
            if (2 * seen >= b->pixels) break;
        }
        boxes[n] = (box){cut, b->end, 0, 0, 0};
        b->end = cut;
        measure(b, cells, a->count);
        measure(&boxes[n], cells, a->count);
        n++;
    }
    memset(colours, 0, 256 * sizeof *colours);
    for (uint32_t i = 0; i < n; i++) {
        uint64_t sum[3] = {0, 0, 0};
        for (uint32_t j = boxes[i].start; j < boxes[i].end; j++) {
            for (int k = 0; k < 3; k++) sum[k] += a->sum[cells[j]][k];
            index_of[cells[j]] = (uint8_t)i;
        }
        uint64_t p = boxes[i].pixels;
        colours[i].Red = (GifByteType)((sum[0] + p / 2) / p);
        colours[i].Green = (GifByteType)((sum[1] + p / 2) / p);
        colours[i].Blue = (GifByteType)((sum[2] + p / 2) / p);
    }
    free(cells);
    return n;
}

/* ---- writing ------------------------------------------------------------------ */

static void gif_fail(GifFileType *gf, const char *path, const char *what) {
    fprintf(stderr, "giflib: %s: %s: %s\n", path, what, GifErrorString(gf->Error));
    int ignored = 0;
    EGifCloseFile(gf, &ignored);
    exit(1);
}

/* One frame: the rectangle (x0, y0, w, h) of `pixels` (a whole frame of
 * palette indices), shown for `delay_cs`. */
static void put_frame(GifFileType *gf, const char *path, const uint8_t *pixels, uint32_t stride, uint32_t x0,
                      uint32_t y0, uint32_t w, uint32_t h, int delay_cs, int transparent) {
    /* transparent: the index that leaves a pixel as it was, or -1. */
    GraphicsControlBlock gcb = {
        .DisposalMode = DISPOSE_DO_NOT, /* later frames draw over this one */
        .UserInputFlag = false,
        .DelayTime = delay_cs,
        .TransparentColor = transparent >= 0 ? transparent : NO_TRANSPARENT_COLOR,
    };
    GifByteType extension[4];
    size_t len = EGifGCBToExtension(&gcb, extension);
    if (EGifPutExtension(gf, GRAPHICS_EXT_FUNC_CODE, (int)len, extension) != GIF_OK) {
        gif_fail(gf, path, "frame timing");
    }
    if (EGifPutImageDesc(gf, (int)x0, (int)y0, (int)w, (int)h, false, NULL) != GIF_OK) {
        gif_fail(gf, path, "frame header");
    }
    for (uint32_t y = y0; y < y0 + h; y++) {
        if (EGifPutLine(gf, (GifPixelType *)(pixels + (size_t)y * stride + x0), (int)w) != GIF_OK) {
            gif_fail(gf, path, "frame pixels");
        }
    }
}

gif_written gif_write(const gif_anim *a, const char *path, int delay_cs, int last_delay_cs) {
    gif_written out = {a->frames, 0, 0};
    GifColorType colours[256];
    uint8_t *index_of = xrealloc(NULL, CELLS);
    out.colours = median_cut(a, colours, index_of);
    const uint8_t transparent = (uint8_t)out.colours;
    int map_size = 1 << GifBitSize((int)out.colours + 1);

    /* Opened here rather than by EGifOpenFileName, which makes the file
     * readable by its owner only. */
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (fd < 0) {
        fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
        exit(1);
    }
    int err = 0;
    GifFileType *gf = EGifOpenFileHandle(fd, &err); /* closed by EGifCloseFile */
    if (!gf) {
        fprintf(stderr, "giflib: cannot write %s: %s\n", path, GifErrorString(err));
        exit(1);
    }
    EGifSetGifVersion(gf, true); /* GIF89a: frame timing and transparency */
    ColorMapObject *map = GifMakeMapObject(map_size, colours);
    if (!map) gif_fail(gf, path, "palette");
    int fail = EGifPutScreenDesc(gf, (int)a->width, (int)a->height, 8, 0, map) != GIF_OK;
    GifFreeMapObject(map); /* giflib keeps its own copy */
    if (fail) gif_fail(gf, path, "screen");
    /* The NETSCAPE2.0 application block: loop forever (count 0). */
    static const GifByteType app[11] = {'N', 'E', 'T', 'S', 'C', 'A', 'P', 'E', '2', '.', '0'};
    static const GifByteType loop[3] = {1, 0, 0};
    if (EGifPutExtensionLeader(gf, APPLICATION_EXT_FUNC_CODE) != GIF_OK ||
        EGifPutExtensionBlock(gf, sizeof app, app) != GIF_OK || EGifPutExtensionBlock(gf, sizeof loop, loop) != GIF_OK ||
        EGifPutExtensionTrailer(gf) != GIF_OK) {
        gif_fail(gf, path, "loop block");
    }

    size_t pixels = (size_t)a->width * a->height;
    uint8_t *now = xrealloc(NULL, pixels), *before = xrealloc(NULL, pixels), *put = xrealloc(NULL, pixels);
    for (uint32_t f = 0; f < a->frames; f++) {
        const uint16_t *cells = a->cells + (size_t)f * pixels;
        for (size_t i = 0; i < pixels; i++) now[i] = index_of[cells[i]];
        int delay = f + 1 == a->frames ? last_delay_cs : delay_cs;
        if (f == 0) {
            put_frame(gf, path, now, a->width, 0, 0, a->width, a->height, delay, -1);
        } else {
            /* The rectangle round what changed; inside it, an unchanged
             * pixel is transparent, which also compresses better. */
            uint32_t x0 = a->width, y0 = a->height, x1 = 0, y1 = 0;
            for (uint32_t y = 0; y < a->height; y++) {
                for (uint32_t x = 0; x < a->width; x++) {
                    size_t i = (size_t)y * a->width + x;
                    if (now[i] == before[i]) {
                        put[i] = transparent;
                        continue;
                    }
                    put[i] = now[i];
                    if (x < x0) x0 = x;
                    if (y < y0) y0 = y;
                    if (x + 1 > x1) x1 = x + 1;
                    if (y + 1 > y1) y1 = y + 1;
                }
            }
            if (x1 == 0) { /* nothing changed: one transparent pixel */
                x0 = y0 = 0;
                x1 = y1 = 1;
            }
            put_frame(gf, path, put, a->width, x0, y0, x1 - x0, y1 - y0, delay, transparent);
        }
        uint8_t *swap = before;
        before = now;
        now = swap;
    }
    free(now);
    free(before);
    free(put);
    free(index_of);
    if (EGifCloseFile(gf, &err) != GIF_OK) {
        fprintf(stderr, "giflib: %s: %s\n", path, GifErrorString(err));
        exit(1);
    }
    struct stat st;
    out.bytes = stat(path, &st) == 0 ? (long)st.st_size : -1;
    return out;
}
