/*
 * Animated GIFs through giflib: frames are collected as they are drawn,
 * then written with one palette of at most 255 colours chosen for all of
 * them (median cut), each frame after the first stored only where it
 * differs from the one before (the rest transparent), looping forever.
 * Browsers, image viewers and tools such as ffmpeg and ImageMagick read
 * the frames in order.
 */
#ifndef MPCA_EXAMPLES_GIF_H
#define MPCA_EXAMPLES_GIF_H

#include <stddef.h>
#include <stdint.h>

#include "image.h"

typedef struct gif_anim gif_anim;

/* An empty animation of width x height frames. */
gif_anim *gif_new(uint32_t width, uint32_t height);
void gif_free(gif_anim *a);

/* Appends a frame (the alpha byte is ignored); `frame` must be width x
 * height. Keeps 2 bytes a pixel until gif_write. */
void gif_add(gif_anim *a, const image *frame);

/* What gif_write wrote. */
typedef struct gif_written {
    uint32_t frames, colours;
    long bytes;
} gif_written;

/* Writes the frames to `path`, each shown `delay_cs` hundredths of a
 * second and the last `last_delay_cs`; exits with giflib's message on
 * failure. */
gif_written gif_write(const gif_anim *a, const char *path, int delay_cs, int last_delay_cs);

#endif /* MPCA_EXAMPLES_GIF_H */
