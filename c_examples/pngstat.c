/*
 * pngstat FILE [R G B]: reads a PNG with libpng and prints
 *   width=W height=H nonbg=N coloured=C
 * where N counts the pixels that differ from the background (R, G, B; by
 * default the scene programs' background) and C those whose channels differ
 * by at least RENDER_CHROMA_MIN (max - min): the particles, since the
 * programs draw everything else in greys. The test of c_examples
 * (tests/tests/examples.rs) reads PNGs through this, so it needs no image
 * crate.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    unsigned long long nonbg = 0, coloured = 0;
    for (png_uint_32 y = 0; y < height; y++) {
        for (png_uint_32 x = 0; x < width; x++) {
            const png_byte *p = rows[y] + 3 * x;
            int hi = p[0], lo = p[0];
            for (int k = 1; k < 3; k++) {
                if (p[k] > hi) hi = p[k];
                if (p[k] < lo) lo = p[k];
            }
            nonbg += p[0] != bg[0] || p[1] != bg[1] || p[2] != bg[2];
            coloured += hi - lo >= RENDER_CHROMA_MIN;
        }
    }
    png_destroy_read_struct(&png, &info, NULL);
    fclose(f);
    printf("width=%lu height=%lu nonbg=%llu coloured=%llu\n", (unsigned long)width, (unsigned long)height, nonbg,
           coloured);
    return 0;
}
