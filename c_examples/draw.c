/*
 * OpenGL drawing through OSMesa: the off-screen canvas, the 2D and 3D
 * views, the fixed parts of the scenes (walls, floor, sphere) and the
 * particles. See draw.h.
 */
#define _POSIX_C_SOURCE 200809L
/* glPointParameter* (OpenGL 1.4) are declared only with this. */
#define GL_GLEXT_PROTOTYPES

#include "draw.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <GL/osmesa.h>

#include "common.h"
#include "image.h"

#define PI_F 3.14159265358979323846f

/* ---- the canvas ------------------------------------------------------------ */

struct canvas {
    OSMesaContext ctx;
};

canvas *canvas_create(void) {
    canvas *c = xrealloc(NULL, sizeof *c);
    /* RGBA, a 24-bit depth buffer (3D), no stencil or accumulation. */
    c->ctx = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, NULL);
    if (!c->ctx) {
        fprintf(stderr, "OSMesaCreateContextExt failed\n");
        exit(1);
    }
    return c;
}

void canvas_begin(canvas *c, uint8_t *rgba, const view *v) {
    if (!OSMesaMakeCurrent(c->ctx, rgba, GL_UNSIGNED_BYTE, (GLsizei)v->width, (GLsizei)v->height)) {
        fprintf(stderr, "OSMesaMakeCurrent failed (%ux%u)\n", (unsigned)v->width, (unsigned)v->height);
        exit(1);
    }
    glViewport(0, 0, (GLsizei)v->width, (GLsizei)v->height);
    glDisable(GL_DITHER);
    glClearColor(RENDER_BG_R / 255.0f, RENDER_BG_G / 255.0f, RENDER_BG_B / 255.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
}

void canvas_end(canvas *c, const char *what) {
    (void)c;
    glFinish();
    GLenum err = glGetError();
    if (err != GL_NO_ERROR) {
        fprintf(stderr, "OpenGL error 0x%x while drawing %s\n", (unsigned)err, what);
        exit(1);
    }
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

void canvas_destroy(canvas *c) {
    if (!c) return;
    OSMesaDestroyContext(c->ctx);
    free(c);
    free(scratch.pos);
    free(scratch.vel);
    free(scratch.rgb);
    scratch = (particle_buffers){0, NULL, NULL, NULL};
}
