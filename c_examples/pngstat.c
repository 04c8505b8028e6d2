/*
 * pngstat FILE [R G B]: reads a PNG with libpng, or an animated GIF with
 * giflib, and prints
 *   width=W height=H nonbg=N coloured=C            (PNG)
 *   width=W height=H nonbg=N coloured=C frames=F   (GIF)
 * where N counts the pixels that differ from the background (R, G, B; by
 * default the scene programs' background) and C those whose channels differ
 * by at least RENDER_CHROMA_MIN (max - min): the particles, since the
 * programs draw everything else in greys. For a GIF the counts are those
 * of its last frame as shown: every frame drawn over the ones before, as
 * the scene programs write them (gif.c). The test of c_examples
 * (tests/tests/examples.rs) reads images through this, so it needs no
 * image crate.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gif_lib.h>
#include <png.h>

#include "image.h"

static void fail(png_structp png, png_const_charp message) {
    fprintf(stderr, "pngstat: %s: %s\n", (const char *)png_get_error_ptr(png), message);
    exit(1);
}

static int channel(const char *text, int *out) {
    char *end = NULL;
    long v = strtol(text, &end, 10);
    if (*text == '\0' || *end || v < 0 || v > 255) return 0;
    *out = (int)v;
    return 1;
}

/* Counts the pixels of a width x height RGB image and prints the counts
 * (without a newline). */
static void count(const uint8_t *rgb, unsigned long width, unsigned long height, const int bg[3]) {
    unsigned long long nonbg = 0, coloured = 0;
    for (unsigned long i = 0; i < width * height; i++) {
        const uint8_t *p = rgb + 3 * i;
        int hi = p[0], lo = p[0];
        for (int k = 1; k < 3; k++) {
            if (p[k] > hi) hi = p[k];
            if (p[k] < lo) lo = p[k];
        }
        nonbg += p[0] != bg[0] || p[1] != bg[1] || p[2] != bg[2];
        coloured += hi - lo >= RENDER_CHROMA_MIN;
    }
    printf("width=%lu height=%lu nonbg=%llu coloured=%llu", width, height, nonbg, coloured);
}

/* The last frame of an animated GIF as shown; exits on a malformed file. */
static int gif_stat(const char *path, const int bg[3]) {
    int err = 0;
    GifFileType *g = DGifOpenFileName(path, &err);
    if (!g) {
        fprintf(stderr, "pngstat: %s: %s\n", path, GifErrorString(err));
        return 1;
    }
    if (DGifSlurp(g) != GIF_OK || g->ImageCount < 1 || !g->SColorMap) {
        fprintf(stderr, "pngstat: %s: %s\n", path, g->ImageCount < 1 ? "no frame" : GifErrorString(g->Error));
        DGifCloseFile(g, &err);
        return 1;
    }
    unsigned long width = (unsigned long)g->SWidth, height = (unsigned long)g->SHeight;
    uint8_t *rgb = calloc(width * height, 3);
    if (!rgb) return 1;
    for (int f = 0; f < g->ImageCount; f++) {
        const SavedImage *im = &g->SavedImages[f];
        const GifImageDesc *d = &im->ImageDesc;
        GraphicsControlBlock gcb = {0, false, 0, NO_TRANSPARENT_COLOR};
        DGifSavedExtensionToGCB(g, f, &gcb);
        const ColorMapObject *map = d->ColorMap ? d->ColorMap : g->SColorMap;
        if (d->Left < 0 || d->Top < 0 || (unsigned long)(d->Left + d->Width) > width ||
            (unsigned long)(d->Top + d->Height) > height) {
            fprintf(stderr, "pngstat: %s: frame %d lies outside the screen\n", path, f);
            return 1;
        }
        for (int y = 0; y < d->Height; y++) {
            for (int x = 0; x < d->Width; x++) {
                int i = im->RasterBits[(size_t)y * (size_t)d->Width + (size_t)x];
                if (i == gcb.TransparentColor) continue;
                if (i >= map->ColorCount) {
                    fprintf(stderr, "pngstat: %s: frame %d: index %d outside the palette\n", path, f, i);
                    return 1;
                }
                uint8_t *p = rgb + 3 * ((size_t)(d->Top + y) * width + (size_t)(d->Left + x));
                p[0] = map->Colors[i].Red;
                p[1] = map->Colors[i].Green;
                p[2] = map->Colors[i].Blue;
            }
        }
    }
    count(rgb, width, height, bg);
    printf(" frames=%d\n", g->ImageCount);
    free(rgb);
    DGifCloseFile(g, &err);
    return 0;
}

int main(int argc, char **argv) {
    int bg[3] = {RENDER_BG_R, RENDER_BG_G, RENDER_BG_B};
    if (!(argc == 2 || (argc == 5 && channel(argv[2], &bg[0]) && channel(argv[3], &bg[1]) &&
                        channel(argv[4], &bg[2])))) {
        fprintf(stderr, "usage: pngstat FILE [R G B]\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "rb");
    if (!f) {
        fprintf(stderr, "pngstat: %s: %s\n", argv[1], strerror(errno));
        return 1;
    }
    char magic[3] = {0, 0, 0};
    if (fread(magic, 1, 3, f) == 3 && memcmp(magic, "GIF", 3) == 0) {
        fclose(f);
        return gif_stat(argv[1], bg);
    }
    rewind(f);
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, argv[1], fail, NULL);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        fprintf(stderr, "pngstat: libpng cannot start\n");
        return 1;
    }
    png_init_io(png, f);
    /* Whatever the file holds, read 8-bit RGB. */
    png_read_png(png, info,
                 PNG_TRANSFORM_STRIP_16 | PNG_TRANSFORM_PACKING | PNG_TRANSFORM_EXPAND | PNG_TRANSFORM_STRIP_ALPHA |
                     PNG_TRANSFORM_GRAY_TO_RGB,
                 NULL);
    png_uint_32 width = png_get_image_width(png, info), height = png_get_image_height(png, info);
    png_bytepp rows = png_get_rows(png, info);
    uint8_t *rgb = malloc((size_t)width * height * 3 + 1);
    if (!rgb) return 1;
    for (png_uint_32 y = 0; y < height; y++) memcpy(rgb + (size_t)y * width * 3, rows[y], (size_t)width * 3);
    count(rgb, (unsigned long)width, (unsigned long)height, bg);
    printf("\n");
    free(rgb);
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    return 0;
}
