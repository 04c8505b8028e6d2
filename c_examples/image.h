/*
 * Images in memory and on disk: an RGBA image, copies out of an OpenGL
 * buffer, small grey labels, and PNG files through libpng.
 */
#ifndef MPCA_EXAMPLES_IMAGE_H
#define MPCA_EXAMPLES_IMAGE_H

#include <stdint.h>

/* The background (dark blue-grey) and the chroma that marks a particle:
 * a pixel is "coloured" when max(r,g,b) - min(r,g,b) >= RENDER_CHROMA_MIN.
 * Particles are drawn in saturated colours, everything else in greys. */
#define RENDER_BG_R 16
#define RENDER_BG_G 17
#define RENDER_BG_B 22
#define RENDER_CHROMA_MIN 24

/* An RGBA image, rows top to bottom. */
typedef struct image {
    uint32_t width, height;
    uint8_t *rgba;
} image;

/* A width x height image filled with the background. */
image image_new(uint32_t width, uint32_t height);
void image_free(image *im);
/* Fills `im` with the background. */
void image_clear(image *im);

/* Copies an OpenGL buffer of w x h (RGBA, rows bottom to top) into `dst`
 * with its top left corner at (x0, y0). */
void image_blit_gl(image *dst, const uint8_t *gl_rgba, uint32_t w, uint32_t h, uint32_t x0, uint32_t y0);

/* Labels: digits, 't', '=' and '.' in grey, LABEL_HEIGHT pixels tall. */
#define LABEL_SCALE 2
#define LABEL_HEIGHT (5 * LABEL_SCALE)
/* Draws `text` with its top left corner at (x0, y0). */
void image_label(image *im, uint32_t x0, uint32_t y0, const char *text);

/* Writes `im` as an 8-bit RGB PNG (alpha dropped) at zlib compression
 * `level` (0 to 9); exits on failure. */
void png_write(const char *path, const image *im, int level);

#endif /* MPCA_EXAMPLES_IMAGE_H */
