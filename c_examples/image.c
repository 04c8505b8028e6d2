/*
 * Images in memory and on disk: RGBA images, copies out of the OpenGL
 * buffer, the sheet's labels and PNG files through libpng. See image.h.
 */
#include "image.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <png.h>

#include "common.h"

image image_new(uint32_t width, uint32_t height) {
    image im = {width, height, NULL};
    im.rgba = xrealloc(NULL, (size_t)width * height * 4);
    image_clear(&im);
    return im;
}

void image_clear(image *im) {
    for (size_t i = 0; i < (size_t)im->width * im->height; i++) {
        im->rgba[4 * i + 0] = RENDER_BG_R;
        im->rgba[4 * i + 1] = RENDER_BG_G;
        im->rgba[4 * i + 2] = RENDER_BG_B;
        im->rgba[4 * i + 3] = 255;
    }
}

void image_free(image *im) {
    free(im->rgba);
    im->rgba = NULL;
}

static void png_fail(png_structp png, png_const_charp message) {
    fprintf(stderr, "libpng: %s: %s\n", (const char *)png_get_error_ptr(png), message);
    exit(1);
}

static void png_warn(png_structp png, png_const_charp message) {
    fprintf(stderr, "libpng: %s: warning: %s\n", (const char *)png_get_error_ptr(png), message);
}

/* libpng's errors end the program, so no setjmp is needed. */
void png_write(const char *path, const image *im, int level) {
    FILE *f = fopen(path, "wb");
    if (!f) {
        fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
        exit(1);
    }
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, (png_voidp)path, png_fail, png_warn);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        fprintf(stderr, "libpng: cannot start %s\n", path);
        exit(1);
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, im->width, im->height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, level);
    png_write_info(png, info);
    png_set_filler(png, 0, PNG_FILLER_AFTER); /* rows are RGBA: skip A */
    for (uint32_t y = 0; y < im->height; y++) {
        png_write_row(png, im->rgba + (size_t)y * im->width * 4);
    }
    png_write_end(png, NULL);
    png_destroy_write_struct(&png, &info);
    if (fclose(f) != 0) {
        fprintf(stderr, "cannot write %s: %s\n", path, strerror(errno));
        exit(1);
    }
}

void image_blit_gl(image *dst, const uint8_t *gl_rgba, uint32_t w, uint32_t h, uint32_t x0, uint32_t y0) {
    for (uint32_t y = 0; y < h; y++) {
        memcpy(dst->rgba + ((size_t)(y0 + y) * dst->width + x0) * 4, gl_rgba + (size_t)(h - 1 - y) * w * 4,
               (size_t)w * 4);
    }
}

/* 3 x 5 glyphs for the labels, one row per byte (bit 2 leftmost). */
static const uint8_t *glyph(char ch) {
    static const uint8_t digits[10][5] = {
        {7, 5, 5, 5, 7}, {2, 6, 2, 2, 7}, {7, 1, 7, 4, 7}, {7, 1, 7, 1, 7}, {5, 5, 7, 1, 1},
        {7, 4, 7, 1, 7}, {7, 4, 7, 5, 7}, {7, 1, 1, 1, 1}, {7, 5, 7, 5, 7}, {7, 5, 7, 1, 7},
    };
    static const uint8_t t[5] = {2, 7, 2, 2, 3}, eq[5] = {0, 7, 0, 7, 0}, dot[5] = {0, 0, 0, 0, 2}, blank[5] = {0};
    if (ch >= '0' && ch <= '9') return digits[ch - '0'];
    if (ch == 't') return t;
    if (ch == '=') return eq;
    if (ch == '.') return dot;
    return blank;
}

/* LABEL_SCALE pixels per glyph pixel. */
void image_label(image *im, uint32_t x0, uint32_t y0, const char *text) {
    for (const char *c = text; *c; c++, x0 += 4 * LABEL_SCALE) {
        const uint8_t *g = glyph(*c);
        for (uint32_t row = 0; row < 5 * LABEL_SCALE; row++) {
            for (uint32_t col = 0; col < 3 * LABEL_SCALE; col++) {
                if (!(g[row / LABEL_SCALE] & (4u >> (col / LABEL_SCALE)))) continue;
                uint32_t x = x0 + col, y = y0 + row;
                if (x >= im->width || y >= im->height) continue;
                uint8_t *p = im->rgba + ((size_t)y * im->width + x) * 4;
                p[0] = p[1] = p[2] = 200;
            }
        }
    }
}
