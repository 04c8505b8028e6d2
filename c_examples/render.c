/*
 * The shared part of the scene programs: see render.h.
 */
#define _POSIX_C_SOURCE 200809L
/* glPointParameter* (OpenGL 1.4) are declared only with this. */
#define GL_GLEXT_PROTOTYPES

#include "render.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include <GL/osmesa.h>
#include <png.h>

#define PI_F 3.14159265358979323846f

/* ---- errors, memory, time --------------------------------------------- */

void mpca_check(mpca_status status, const char *what) {
    if (status != MPCA_STATUS_OK) {
        fprintf(stderr, "mpca: %s: %s (status %u)\n", what, mpca_status_message(status), (unsigned)status);
        exit(1);
    }
}

mpca_world *world_create(const mpca_desc *desc) {
    mpca_world *w = NULL;
    mpca_check(mpca_world_create(desc, &w), "mpca_world_create");
    return w;
}

static void *xrealloc(void *p, size_t bytes) {
    void *q = realloc(p, bytes ? bytes : 1);
    if (!q) {
        fprintf(stderr, "out of memory (%zu bytes)\n", bytes);
        exit(1);
    }
    return q;
}

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

uint32_t scale_cells(uint32_t v, uint32_t size, uint32_t reference) {
    return (uint32_t)((uint64_t)v * size / reference);
}

/* ---- PCG32, as rand_pcg::Pcg32 ------------------------------------------ */

#define PCG_MULTIPLIER 6364136223846793005ULL

pcg32 pcg32_new(uint64_t state, uint64_t stream) {
    pcg32 rng;
    rng.increment = (stream << 1) | 1u;
    rng.state = state + rng.increment;
    rng.state = rng.state * PCG_MULTIPLIER + rng.increment;
    return rng;
}

uint32_t pcg32_next(pcg32 *rng) {
    uint64_t old = rng->state;
    rng->state = old * PCG_MULTIPLIER + rng->increment;
    uint32_t rot = (uint32_t)(old >> 59);
    uint32_t xsh = (uint32_t)(((old >> 18) ^ old) >> 27);
    return (xsh >> rot) | (xsh << ((32u - rot) & 31u));
}

float pcg32_unit(pcg32 *rng) {
    return (float)(pcg32_next(rng) >> 8) / 16777216.0f;
}

/* ---- colours ------------------------------------------------------------- */

/* Piecewise linear through `n` stops; every stop and every blend of two
 * neighbouring stops keeps max - min of its channels far above
 * RENDER_CHROMA_MIN, so a particle is never mistaken for a grey. */
static void ramp(const uint8_t (*stops)[3], int n, float t, uint8_t rgb[3]) {
    if (!(t > 0.0f)) t = 0.0f; /* also NaN */
    if (t > 1.0f) t = 1.0f;
    float x = t * (float)(n - 1);
    int i = (int)x;
    if (i >= n - 1) i = n - 2;
    float f = x - (float)i;
    for (int k = 0; k < 3; k++) {
        rgb[k] = (uint8_t)lrintf((1.0f - f) * (float)stops[i][k] + f * (float)stops[i + 1][k]);
    }
}

void speed_colour(float speed, uint8_t rgb[3]) {
    /* blue, cyan, green, yellow, red: slow to fast */
    static const uint8_t stops[5][3] = {
        {50, 100, 230}, {40, 200, 220}, {110, 220, 70}, {250, 200, 40}, {240, 60, 40},
    };
    ramp(stops, 5, speed, rgb);
}

void water_colour(float speed, uint8_t rgb[3]) {
    static const uint8_t stops[3][3] = {{25, 80, 215}, {40, 160, 240}, {150, 235, 255}};
    ramp(stops, 3, speed, rgb);
}

void grey(float level) {
    glColor3f(level, level, level);
}

static float speed_of(const float *v) {
    return sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

/* ---- particles out of the library ----------------------------------------- */

typedef struct particle_buffers {
    size_t capacity;
    float *pos, *vel;
    uint8_t *rgb;
} particle_buffers;

static particle_buffers scratch;

/* Exports every particle's position and velocity; returns the count. */
static size_t export_particles(mpca_world *w) {
    size_t n = 0;
    mpca_check(mpca_world_particle_count(w, &n), "mpca_world_particle_count");
    /* Never a NULL buffer, even for no particles: the library refuses NULL
     * whatever the capacity. */
    if (n > scratch.capacity || !scratch.pos) {
        scratch.capacity = n + n / 2 + 16;
        scratch.pos = xrealloc(scratch.pos, 3 * scratch.capacity * sizeof(float));
        scratch.vel = xrealloc(scratch.vel, 3 * scratch.capacity * sizeof(float));
        scratch.rgb = xrealloc(scratch.rgb, 3 * scratch.capacity);
    }
    size_t got = 0;
    mpca_check(mpca_world_export_positions(w, scratch.pos, scratch.capacity, &got), "mpca_world_export_positions");
    mpca_check(mpca_world_export_velocities(w, scratch.vel, scratch.capacity, &got), "mpca_world_export_velocities");
    return got;
}

/* ---- 2D ---------------------------------------------------------------------- */

void view2d_begin(uint32_t nx, uint32_t ny) {
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glOrtho(0.0, (double)nx, 0.0, (double)ny, -1.0, 1.0);
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glDisable(GL_DEPTH_TEST);
}

/* Draws the first n points of the scratch arrays (positions and colours). */
static void draw_scratch_points(size_t n) {
    glEnableClientState(GL_VERTEX_ARRAY);
    glEnableClientState(GL_COLOR_ARRAY);
    glVertexPointer(3, GL_FLOAT, 0, scratch.pos);
    glColorPointer(3, GL_UNSIGNED_BYTE, 0, scratch.rgb);
    glDrawArrays(GL_POINTS, 0, (GLsizei)n);
    glDisableClientState(GL_COLOR_ARRAY);
    glDisableClientState(GL_VERTEX_ARRAY);
}

size_t draw_particles_2d(mpca_world *w, const view *v) {
    size_t n = export_particles(w);
    for (size_t i = 0; i < n; i++) {
        /* sqrt spreads the slow speeds, where a cooling gas spends its time. */
        speed_colour(sqrtf(speed_of(&scratch.vel[3 * i])), &scratch.rgb[3 * i]);
    }
    /* Square, unsmoothed points: each covers point_px x point_px pixels
     * inside its own cell, and no two particles share a cell (M1). */
    glDisable(GL_POINT_SMOOTH);
    glPointSize((float)v->point_px);
    draw_scratch_points(n);
    return n;
}

void draw_walls_2d(const mpca_desc *desc, const view *v) {
    /* In pixels, so the line is two pixels wide at any cell size. */
    float wpx = (float)v->width, hpx = (float)v->height;
    glMatrixMode(GL_PROJECTION);
    glPushMatrix();
    glLoadIdentity();
    glOrtho(0.0, (double)wpx, 0.0, (double)hpx, -1.0, 1.0);
    grey(0.55f);
    for (int axis = 0; axis < 2; axis++) {
        for (int side = 0; side < 2; side++) {
            if (desc->boundary[axis][side] != MPCA_BOUNDARY_WALL) continue;
            if (axis == 0) {
                float x0 = side ? wpx - 2.0f : 0.0f;
                glRectf(x0, 0.0f, x0 + 2.0f, hpx);
            } else {
                float y0 = side ? hpx - 2.0f : 0.0f;
                glRectf(0.0f, y0, wpx, y0 + 2.0f);
            }
        }
    }
    glPopMatrix();
    glMatrixMode(GL_MODELVIEW);
}

/* ---- 3D ---------------------------------------------------------------------- */

static void normalise(float v[3]) {
    float l = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (l > 0.0f) {
        v[0] /= l;
        v[1] /= l;
        v[2] /= l;
    }
}

static void cross(const float a[3], const float b[3], float out[3]) {
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Focal length in pixels: a thing of size s at distance d is s * f / d
 * pixels tall. */
static float focal_px(const view *v, const camera *c) {
    return 0.5f * (float)v->height / tanf(0.5f * c->fov_deg * PI_F / 180.0f);
}

void view3d_begin(const view *v, const camera *c) {
    double aspect = (double)v->width / (double)v->height;
    double top = c->near_clip * tan(0.5 * c->fov_deg * 3.14159265358979323846 / 180.0);
    glMatrixMode(GL_PROJECTION);
    glLoadIdentity();
    glFrustum(-top * aspect, top * aspect, -top, top, c->near_clip, c->far_clip);
    /* The look-at matrix, column-major. */
    float f[3] = {c->target[0] - c->eye[0], c->target[1] - c->eye[1], c->target[2] - c->eye[2]};
    normalise(f);
    const float up[3] = {0.0f, 1.0f, 0.0f};
    float s[3], u[3];
    cross(f, up, s);
    normalise(s);
    cross(s, f, u);
    GLfloat m[16] = {
        s[0], u[0], -f[0], 0.0f, s[1], u[1], -f[1], 0.0f, s[2], u[2], -f[2], 0.0f, 0.0f, 0.0f, 0.0f, 1.0f,
    };
    glMatrixMode(GL_MODELVIEW);
    glLoadMatrixf(m);
    glTranslatef(-c->eye[0], -c->eye[1], -c->eye[2]);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
}

void draw_sphere(const float centre[3], float radius) {
    enum { SLICES = 48, STACKS = 24 };
    /* White light on a grey material: every lit pixel stays grey. */
    const GLfloat light_dir[4] = {-0.4f, 0.8f, 0.6f, 0.0f};
    const GLfloat ambient[4] = {0.22f, 0.22f, 0.22f, 1.0f};
    const GLfloat diffuse[4] = {0.75f, 0.75f, 0.75f, 1.0f};
    const GLfloat material[4] = {0.8f, 0.8f, 0.8f, 1.0f};
    const GLfloat none[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, none);
    glLightfv(GL_LIGHT0, GL_POSITION, light_dir);
    glLightfv(GL_LIGHT0, GL_AMBIENT, ambient);
    glLightfv(GL_LIGHT0, GL_DIFFUSE, diffuse);
    glLightfv(GL_LIGHT0, GL_SPECULAR, none);
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, material);
    glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, none);
    glShadeModel(GL_SMOOTH);
    for (int i = 0; i < STACKS; i++) {
        float a0 = PI_F * (float)i / STACKS - 0.5f * PI_F;
        float a1 = PI_F * (float)(i + 1) / STACKS - 0.5f * PI_F;
        glBegin(GL_TRIANGLE_STRIP);
        for (int j = 0; j <= SLICES; j++) {
            float b = 2.0f * PI_F * (float)j / SLICES;
            for (int k = 0; k < 2; k++) {
                float a = k ? a0 : a1;
                float n[3] = {cosf(a) * cosf(b), sinf(a), cosf(a) * sinf(b)};
                glNormal3fv(n);
                glVertex3f(centre[0] + radius * n[0], centre[1] + radius * n[1], centre[2] + radius * n[2]);
            }
        }
        glEnd();
    }
    glDisable(GL_LIGHTING);
}

void draw_floor_and_box(uint32_t nx, uint32_t ny, uint32_t nz, uint32_t grid) {
    float x = (float)nx, y = (float)ny, z = (float)nz;
    /* The floor, pushed back in depth so its grid lines win. */
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 1.0f);
    grey(0.2f);
    glBegin(GL_QUADS);
    glVertex3f(0.0f, 0.0f, 0.0f);
    glVertex3f(0.0f, 0.0f, z);
    glVertex3f(x, 0.0f, z);
    glVertex3f(x, 0.0f, 0.0f);
    glEnd();
    glDisable(GL_POLYGON_OFFSET_FILL);
    grey(0.3f);
    glBegin(GL_LINES);
    for (uint32_t i = grid; grid > 0 && i < nx; i += grid) {
        glVertex3f((float)i, 0.0f, 0.0f);
        glVertex3f((float)i, 0.0f, z);
    }
    for (uint32_t i = grid; grid > 0 && i < nz; i += grid) {
        glVertex3f(0.0f, 0.0f, (float)i);
        glVertex3f(x, 0.0f, (float)i);
    }
    glEnd();
    /* The twelve edges of the box. */
    grey(0.5f);
    const float c[8][3] = {{0, 0, 0}, {x, 0, 0}, {x, 0, z}, {0, 0, z}, {0, y, 0}, {x, y, 0}, {x, y, z}, {0, y, z}};
    const int e[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    glBegin(GL_LINES);
    for (int i = 0; i < 12; i++) {
        glVertex3fv(c[e[i][0]]);
        glVertex3fv(c[e[i][1]]);
    }
    glEnd();
}

/* A shaded disc for the sprites: luminance from a light at the upper left,
 * alpha 1 inside the disc and 0 outside (cut by the alpha test, so a pixel
 * is either the particle's or untouched: no blending). */
static void sprite_texture(void) {
    static GLuint texture;
    if (texture) {
        glBindTexture(GL_TEXTURE_2D, texture);
        return;
    }
    enum { N = 32 };
    static GLubyte texels[N][N][2];
    for (int j = 0; j < N; j++) {
        for (int i = 0; i < N; i++) {
            float x = ((float)i + 0.5f) / (N / 2) - 1.0f, y = ((float)j + 0.5f) / (N / 2) - 1.0f;
            float r2 = x * x + y * y;
            float z = sqrtf(r2 < 1.0f ? 1.0f - r2 : 0.0f);
            float lit = (-0.4f * x - 0.4f * y + 0.82f * z);
            if (lit < 0.0f) lit = 0.0f;
            /* Luminance at least 0.6, so the colour keeps its chroma. */
            texels[j][i][0] = (GLubyte)lrintf(255.0f * (0.6f + 0.4f * lit));
            texels[j][i][1] = r2 <= 1.0f ? 255 : 0;
        }
    }
    glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_LUMINANCE_ALPHA, N, N, 0, GL_LUMINANCE_ALPHA, GL_UNSIGNED_BYTE, texels);
}

/* Distance from `p` to the nearest and the farthest point of the box. */
static void box_distances(const float p[3], const uint32_t size[3], float *near_d, float *far_d) {
    float n2 = 0.0f, f2 = 0.0f;
    for (int k = 0; k < 3; k++) {
        float hi = (float)size[k];
        float d_in = p[k] < 0.0f ? -p[k] : (p[k] > hi ? p[k] - hi : 0.0f);
        float d_out = fmaxf(fabsf(p[k]), fabsf(p[k] - hi));
        n2 += d_in * d_in;
        f2 += d_out * d_out;
    }
    *near_d = sqrtf(n2);
    *far_d = sqrtf(f2);
}

drawn draw_particles_3d(mpca_world *w, const view *v, const camera *c, const uint32_t size[3]) {
    drawn d = {0, 0.0f, 0.0f};
    size_t n = export_particles(w);
    float dmin, dmax;
    box_distances(c->eye, size, &dmin, &dmax);
    if (dmin < c->near_clip) dmin = c->near_clip;
    /* Depth shading: full colour at the nearest point of the box, half at
     * the farthest. */
    for (size_t i = 0; i < n; i++) {
        const float *p = &scratch.pos[3 * i];
        float dx = p[0] - c->eye[0], dy = p[1] - c->eye[1], dz = p[2] - c->eye[2];
        float t = (sqrtf(dx * dx + dy * dy + dz * dz) - dmin) / (dmax - dmin);
        float shade = 1.0f - 0.5f * (t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t));
        uint8_t rgb[3];
        water_colour(speed_of(&scratch.vel[3 * i]), rgb);
        for (int k = 0; k < 3; k++) scratch.rgb[3 * i + k] = (uint8_t)lrintf(shade * (float)rgb[k]);
    }
    /* Perspective size: one cell at distance d is f/d pixels (the
     * attenuation's 1/sqrt(c d^2)); clamped to what the box allows. */
    float f = focal_px(v, c);
    d.sprite_min_px = f / dmax;
    d.sprite_max_px = f / dmin;
    const GLfloat attenuation[3] = {0.0f, 0.0f, 1.0f};
    glPointParameterfv(GL_POINT_DISTANCE_ATTENUATION, attenuation);
    glPointParameterf(GL_POINT_SIZE_MIN, d.sprite_min_px);
    glPointParameterf(GL_POINT_SIZE_MAX, d.sprite_max_px);
    glPointSize(f);
    glEnable(GL_POINT_SPRITE);
    glTexEnvi(GL_POINT_SPRITE, GL_COORD_REPLACE, GL_TRUE);
    glEnable(GL_TEXTURE_2D);
    sprite_texture();
    glTexEnvi(GL_TEXTURE_ENV, GL_TEXTURE_ENV_MODE, GL_MODULATE);
    glEnable(GL_ALPHA_TEST);
    glAlphaFunc(GL_GREATER, 0.5f);
    draw_scratch_points(n);
    glDisable(GL_ALPHA_TEST);
    glDisable(GL_TEXTURE_2D);
    glDisable(GL_POINT_SPRITE);
    const GLfloat constant[3] = {1.0f, 0.0f, 0.0f};
    glPointParameterfv(GL_POINT_DISTANCE_ATTENUATION, constant);
    d.particles = n;
    return d;
}

/* ---- images --------------------------------------------------------------- */

/* An RGBA image, rows top to bottom. */
typedef struct image {
    uint32_t width, height;
    uint8_t *rgba;
} image;

static image image_new(uint32_t width, uint32_t height) {
    image im = {width, height, NULL};
    im.rgba = xrealloc(NULL, (size_t)width * height * 4);
    for (size_t i = 0; i < (size_t)width * height; i++) {
        im.rgba[4 * i + 0] = RENDER_BG_R;
        im.rgba[4 * i + 1] = RENDER_BG_G;
        im.rgba[4 * i + 2] = RENDER_BG_B;
        im.rgba[4 * i + 3] = 255;
    }
    return im;
}

static void png_fail(png_structp png, png_const_charp message) {
    fprintf(stderr, "libpng: %s: %s\n", (const char *)png_get_error_ptr(png), message);
    exit(1);
}

static void png_warn(png_structp png, png_const_charp message) {
    fprintf(stderr, "libpng: %s: warning: %s\n", (const char *)png_get_error_ptr(png), message);
}

/* Writes `im` as an 8-bit RGB PNG (the alpha byte is dropped). libpng's
 * errors end the program, so no setjmp is needed. */
static void png_write(const char *path, const image *im) {
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
    png_set_compression_level(png, 9);
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

/* Copies the OSMesa buffer (rows bottom to top) into `dst` at (x0, y0). */
static void blit(image *dst, const uint8_t *gl_rgba, uint32_t w, uint32_t h, uint32_t x0, uint32_t y0) {
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
    static const uint8_t t[5] = {2, 7, 2, 2, 3}, eq[5] = {0, 7, 0, 7, 0}, blank[5] = {0};
    if (ch >= '0' && ch <= '9') return digits[ch - '0'];
    if (ch == 't') return t;
    if (ch == '=') return eq;
    return blank;
}

#define LABEL_SCALE 2
#define LABEL_HEIGHT (5 * LABEL_SCALE)
#define SHEET_GAP 6

/* Grey text at (x0, y0), top left, LABEL_SCALE pixels per glyph pixel. */
static void draw_label(image *im, uint32_t x0, uint32_t y0, const char *text) {
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

#define DEFAULT_OUT "out/scenes"

/* ---- stepping: serially, or the parallel step (M11) on POSIX threads ---- */

/* What the threads of one step share: the step's tasks, taken in turn. */
typedef struct task_batch {
    pthread_mutex_t lock;
    mpca_world *world;
    uint64_t ticket;
    uint32_t next, count;
} task_batch;

static void *take_tasks(void *arg) {
    task_batch *b = arg;
    for (;;) {
        pthread_mutex_lock(&b->lock);
        uint32_t task = b->next < b->count ? b->next++ : b->count;
        pthread_mutex_unlock(&b->lock);
        if (task == b->count) return NULL;
        mpca_check(mpca_world_step_task(b->world, b->ticket, task), "mpca_world_step_task");
    }
}

/* mpca_run_tasks: `threads - 1` new threads and this one take the step's
 * tasks until none is left. (c_examples/threads.c keeps its threads from
 * step to step instead.) */
static void run_tasks(mpca_world *world, uint64_t ticket, uint32_t count, void *user_data) {
    uint32_t threads = *(const uint32_t *)user_data, started = 0;
    pthread_t helpers[15];
    task_batch b = {.world = world, .ticket = ticket, .next = 0, .count = count};
    pthread_mutex_init(&b.lock, NULL);
    while (started + 1 < threads && started < 15 && pthread_create(&helpers[started], NULL, take_tasks, &b) == 0) {
        started++;
    }
    take_tasks(&b);
    for (uint32_t i = 0; i < started; i++) pthread_join(helpers[i], NULL);
    pthread_mutex_destroy(&b.lock);
}

/* Steps `w` on `n` steps as the options say. */
static void step_world(mpca_world *w, uint64_t n, const scene_opts *o) {
    if (o->threads == 0) {
        mpca_check(mpca_world_step(w, n), "mpca_world_step");
    } else {
        mpca_check(mpca_world_step_parallel(w, n, 4 * o->threads, run_tasks, (void *)&o->threads),
                   "mpca_world_step_parallel");
    }
}

/* ---- options ------------------------------------------------------------------- */

static void usage(const scene *s, FILE *f) {
    const scene_opts *d = &s->defaults;
    fprintf(f,
            "usage: %s [options]\n"
            "%s: %s\n"
            "Renders off-screen (OSMesa) and writes PNG frames and a contact sheet.\n"
            "  --size N    cells per axis, even, at least 8 (default %u)\n"
            "  --steps N   steps to run (default %llu)\n"
            "  --seed N    seed of the world and of the initial placement (default %llu)\n"
            "  --every N   write a frame every N steps, 0 for none (default %llu)\n"
            "  --tiles N   frames in the contact sheet, 1 to 12 (default %u)\n"
            "  --px N      frame width in pixels (default %u; the sheet's tiles are half)\n"
            "  --out DIR   output folder, created if missing (default " DEFAULT_OUT ")\n"
            "  --name S    file name prefix (default %s)\n"
            "  --threads N step in tasks on N threads, 1 to 16 (M11; default: mpca_world_step)\n"
            "  --version   print the program's and libmpca's versions and exit\n"
            "  --help      print this and exit\n",
            s->name, s->title, s->about, (unsigned)d->size, (unsigned long long)d->steps,
            (unsigned long long)d->seed, (unsigned long long)d->every, (unsigned)d->tiles, (unsigned)d->px,
            s->name);
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

/* Parses argv into `o`; returns -1 to go on, else an exit status. */
static int parse_options(const scene *s, scene_opts *o, int argc, char **argv) {
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

/* mkdir -p */
static void make_dirs(const char *path) {
    char *p = xrealloc(NULL, strlen(path) + 1);
    strcpy(p, path);
    for (char *c = p + 1;; c++) {
        if (*c == '/' || *c == '\0') {
            char end = *c;
            *c = '\0';
            if (mkdir(p, 0777) != 0 && errno != EEXIST) {
                fprintf(stderr, "cannot create %s: %s\n", p, strerror(errno));
                exit(1);
            }
            *c = end;
            if (!end) break;
        }
    }
    free(p);
}

/* ---- the loop ------------------------------------------------------------------- */

typedef struct canvas {
    OSMesaContext ctx;
    uint8_t *frame, *tile; /* OSMesa colour buffers, rows bottom to top */
} canvas;

/* Renders into `buffer` (v->width x v->height, RGBA). */
static drawn render(const scene *s, const scene_opts *o, mpca_world *w, canvas *c, uint8_t *buffer,
                    const view *v) {
    if (!OSMesaMakeCurrent(c->ctx, buffer, GL_UNSIGNED_BYTE, (GLsizei)v->width, (GLsizei)v->height)) {
        fprintf(stderr, "OSMesaMakeCurrent failed (%ux%u)\n", (unsigned)v->width, (unsigned)v->height);
        exit(1);
    }
    glViewport(0, 0, (GLsizei)v->width, (GLsizei)v->height);
    glDisable(GL_DITHER);
    glClearColor(RENDER_BG_R / 255.0f, RENDER_BG_G / 255.0f, RENDER_BG_B / 255.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    drawn d = s->draw(o, w, v);
    glFinish();
    GLenum err = glGetError();
    if (err != GL_NO_ERROR) {
        fprintf(stderr, "OpenGL error 0x%x while drawing %s\n", (unsigned)err, s->name);
        exit(1);
    }
    return d;
}

static view make_view(const scene *s, uint32_t size, uint32_t px) {
    view v = {px, px, 0, 0};
    if (s->dim == 2) {
        v.cell_px = px / size ? px / size : 1;
        v.point_px = v.cell_px >= 3 ? v.cell_px - 1 : v.cell_px;
        v.width = v.height = v.cell_px * size;
    }
    return v;
}

static void print_drawn(const drawn *d, const view *v) {
    printf(" particles=%zu size=%ux%u", d->particles, (unsigned)v->width, (unsigned)v->height);
    if (v->point_px) {
        printf(" point_px=%u\n", (unsigned)v->point_px);
    } else {
        printf(" sprite_px=%.2f..%.2f\n", d->sprite_min_px, d->sprite_max_px);
    }
}

int scene_main(const scene *s, int argc, char **argv) {
    scene_opts o = s->defaults;
    o.out = DEFAULT_OUT;
    o.name = s->name;
    int status = parse_options(s, &o, argc, argv);
    if (status >= 0) return status;
    make_dirs(o.out);

    mpca_world *w = s->build(&o);
    mpca_stats stats = {.struct_size = sizeof stats};
    mpca_check(mpca_world_stats(w, &stats), "mpca_world_stats");
    char cells[48];
    if (s->dim == 3) {
        snprintf(cells, sizeof cells, "%ux%ux%u", (unsigned)o.size, (unsigned)o.size, (unsigned)o.size);
    } else {
        snprintf(cells, sizeof cells, "%ux%u", (unsigned)o.size, (unsigned)o.size);
    }
    printf("%s (%s): %s cells, %llu particles, %llu steps, seed %llu, %.2f bytes/cell\n", o.name, s->title, cells,
           (unsigned long long)stats.particles, (unsigned long long)o.steps, (unsigned long long)o.seed,
           stats.bytes_per_cell);

    view fv = make_view(s, o.size, o.px);
    /* Sheet tiles at half the frame's resolution (whole cells in 2D). */
    view tv = make_view(s, o.size, s->dim == 2 ? (fv.cell_px + 1) / 2 * o.size : o.px / 2);
    canvas c;
    c.ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
    if (!c.ctx) {
        fprintf(stderr, "OSMesaCreateContextExt failed\n");
        return 1;
    }
    c.frame = xrealloc(NULL, (size_t)fv.width * fv.height * 4);
    c.tile = xrealloc(NULL, (size_t)tv.width * tv.height * 4);

    /* Sheet tiles at round(i * steps / (n - 1)), 0 and the end included. */
    uint32_t tiles = o.tiles;
    if ((uint64_t)tiles > o.steps + 1) tiles = (uint32_t)(o.steps + 1);
    uint64_t tile_step[12];
    for (uint32_t i = 0; i < tiles; i++) {
        tile_step[i] = tiles == 1 ? o.steps : (o.steps * i + (tiles - 1) / 2) / (tiles - 1);
    }
    image sheet = image_new(tiles * tv.width + (tiles + 1) * SHEET_GAP,
                            tv.height + 3 * SHEET_GAP + LABEL_HEIGHT);
    image frame = image_new(fv.width, fv.height);
    int digits = snprintf(NULL, 0, "%llu", (unsigned long long)o.steps);
    if (digits < 4) digits = 4;
    size_t path_len = strlen(o.out) + strlen(o.name) + 48;
    char *path = xrealloc(NULL, path_len);

    double sim_s = 0.0, draw_s = 0.0, png_s = 0.0;
    uint64_t images = 0, pngs = 1, next_tile = 0; /* pngs: the frames and the sheet */
    for (uint64_t t = 0;; ) {
        if (o.every && (t % o.every == 0 || t == o.steps)) {
            double t0 = now_s();
            drawn d = render(s, &o, w, &c, c.frame, &fv);
            double t1 = now_s();
            blit(&frame, c.frame, fv.width, fv.height, 0, 0);
            snprintf(path, path_len, "%s/%s-%0*llu.png", o.out, o.name, digits, (unsigned long long)t);
            png_write(path, &frame);
            draw_s += t1 - t0;
            png_s += now_s() - t1;
            images++;
            pngs++;
            printf("frame: %s step=%llu", path, (unsigned long long)t);
            print_drawn(&d, &fv);
        }
        while (next_tile < tiles && tile_step[next_tile] == t) {
            double t0 = now_s();
            drawn d = render(s, &o, w, &c, c.tile, &tv);
            draw_s += now_s() - t0;
            images++;
            uint32_t x0 = SHEET_GAP + next_tile * (tv.width + SHEET_GAP);
            blit(&sheet, c.tile, tv.width, tv.height, x0, SHEET_GAP);
            char label[32];
            snprintf(label, sizeof label, "t=%llu", (unsigned long long)t);
            draw_label(&sheet, x0, tv.height + 2 * SHEET_GAP, label);
            printf("tile: step=%llu", (unsigned long long)t);
            print_drawn(&d, &tv);
            next_tile++;
        }
        fflush(stdout);
        if (t >= o.steps) break;
        /* Step on to the next frame, tile or the end, timing only the steps. */
        uint64_t next = o.steps;
        if (o.every && (t / o.every + 1) * o.every < next) next = (t / o.every + 1) * o.every;
        if (next_tile < tiles && tile_step[next_tile] < next) next = tile_step[next_tile];
        double t0 = now_s();
        step_world(w, next - t, &o);
        sim_s += now_s() - t0;
        t = next;
    }
    double t0 = now_s();
    snprintf(path, path_len, "%s/%s-sheet.png", o.out, o.name);
    png_write(path, &sheet);
    png_s += now_s() - t0;
    printf("sheet: %s size=%ux%u tiles=%u\n", path, (unsigned)sheet.width, (unsigned)sheet.height, (unsigned)tiles);

    mpca_check(mpca_world_stats(w, &stats), "mpca_world_stats");
    uint64_t hash = 0;
    mpca_check(mpca_world_hash(w, &hash), "mpca_world_hash");
    printf("end: step=%llu particles=%llu emitted=%llu shortfall=%llu exited=%llu collisions=%llu clamps=%llu "
           "hash=%016llx\n",
           (unsigned long long)stats.step, (unsigned long long)stats.particles, (unsigned long long)stats.emitted,
           (unsigned long long)stats.emit_shortfall, (unsigned long long)stats.exited,
           (unsigned long long)stats.collisions, (unsigned long long)stats.clamps, (unsigned long long)hash);
    double per_step = o.steps ? 1e3 * sim_s / (double)o.steps : 0.0;
    printf("sim: %.3f ms/step (%llu steps in %.1f ms), render: %.2f ms/frame (%llu frames and tiles), "
           "png: %.2f ms/file (%llu files)\n",
           per_step, (unsigned long long)o.steps, 1e3 * sim_s, 1e3 * draw_s / (double)images,
           (unsigned long long)images, 1e3 * png_s / (double)pngs, (unsigned long long)pngs);

    free(path);
    free(frame.rgba);
    free(sheet.rgba);
    free(c.frame);
    free(c.tile);
    OSMesaDestroyContext(c.ctx);
    mpca_check(mpca_world_destroy(w), "mpca_world_destroy");
    free(scratch.pos);
    free(scratch.vel);
    free(scratch.rgb);
    return 0;
}
