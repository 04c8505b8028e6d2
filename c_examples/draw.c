/*
 * OpenGL drawing through OSMesa: the off-screen canvas, the 2D and 3D
 * views and the fixed parts of the scenes (walls, floor, sphere) with GL's
 * fixed-function pipeline; the particles and the density through the
 * shader path of gpu.c. See draw.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "draw.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <GL/osmesa.h>

#include "common.h"
#include "engine.h"
#include "gpu.h"
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

/* ---- colours and the particles' GPU objects ------------------------------------ */

void grey(float level) {
    glColor3f(level, level, level);
}

/* The shader path (gpu.h), created at the first particle drawn, with the
 * canvas's context current. */
static gpu *shaders;

static gpu *gpu_of_canvas(void) {
    if (!shaders) shaders = gpu_create();
    return shaders;
}

/* The effects' drawing (engine.h), created at its first use as the shader
 * path is. */
static engine *effects;

static engine *engine_of_canvas(void) {
    if (!effects) effects = engine_create();
    return effects;
}

/* The product of GL's projection and model-view matrices, as the shaders
 * take it: the scene's fixed parts are drawn with GL's matrix stack, and
 * the particles must land on the same pixels. */
static void current_mvp(float mvp[16]) {
    float p[16], m[16];
    glGetFloatv(GL_PROJECTION_MATRIX, p);
    glGetFloatv(GL_MODELVIEW_MATRIX, m);
    for (int col = 0; col < 4; col++) {
        for (int row = 0; row < 4; row++) {
            float sum = 0.0f;
            for (int k = 0; k < 4; k++) sum += p[k * 4 + row] * m[col * 4 + k];
            mvp[col * 4 + row] = sum;
        }
    }
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

size_t draw_particles_2d(mpca_world *w, const view *v) {
    gpu *g = gpu_of_canvas();
    size_t n = gpu_upload_particles(g, w);
    float mvp[16];
    current_mvp(mvp);
    gpu_draw_points_2d(g, mvp, (float)v->point_px);
    return n;
}

void draw_density_2d(mpca_world *w, uint32_t bin, float full) {
    gpu *g = gpu_of_canvas();
    gpu_upload_density_2d(g, w, bin);
    mpca_desc d;
    d.struct_size = sizeof d;
    mpca_check(mpca_world_desc(w, &d), "mpca_world_desc");
    float mvp[16];
    current_mvp(mvp);
    const float bg[3] = {RENDER_BG_R / 255.0f, RENDER_BG_G / 255.0f, RENDER_BG_B / 255.0f};
    gpu_draw_density_2d(g, mvp, d.size[0], d.size[1], bg, full);
}

void upload_motion_2d(const float *from, const float *to, const uint32_t *ages, size_t n) {
    gpu_upload_motion_2d(gpu_of_canvas(), from, to, ages, n);
}

void draw_motion_2d(float blend, float lifetime, float sprite_px, float peak) {
    const gpu_smoke s = {blend, lifetime, sprite_px, peak};
    float mvp[16];
    current_mvp(mvp);
    gpu_draw_smoke_2d(gpu_of_canvas(), mvp, &s);
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

void draw_shape_2d(const mpca_shape *shape, float level) {
    enum { SEGMENTS = 72 };
    grey(level);
    if (shape->kind == MPCA_SHAPE_KIND_BOX) {
        glRectf(shape->a[0], shape->a[1], shape->b[0], shape->b[1]);
    } else if (shape->kind == MPCA_SHAPE_KIND_DISC) {
        glBegin(GL_TRIANGLE_FAN);
        glVertex2f(shape->a[0], shape->a[1]);
        for (int i = 0; i <= SEGMENTS; i++) {
            float t = 2.0f * PI_F * (float)i / SEGMENTS;
            glVertex2f(shape->a[0] + shape->radius * cosf(t), shape->a[1] + shape->radius * sinf(t));
        }
        glEnd();
    } else if (shape->kind == MPCA_SHAPE_KIND_HALF_SPACE) {
        /* The far side of the line through a with normal b, cut to a
         * square far larger than any view. */
        float nx = shape->b[0], ny = shape->b[1], len = sqrtf(nx * nx + ny * ny);
        if (len == 0.0f) return;
        nx /= len;
        ny /= len;
        const float far = 1e5f, x = shape->a[0], y = shape->a[1];
        glBegin(GL_QUADS);
        glVertex2f(x - far * ny, y + far * nx);
        glVertex2f(x + far * ny, y - far * nx);
        glVertex2f(x + far * ny - far * nx, y - far * nx - far * ny);
        glVertex2f(x - far * ny - far * nx, y + far * nx - far * ny);
        glEnd();
    }
}

void upload_moving_2d(const moving *particles, size_t n) {
    engine_upload(engine_of_canvas(), particles, n);
}

void draw_puffs_2d(const smoke_look *s) {
    float mvp[16];
    current_mvp(mvp);
    engine_draw_smoke(engine_of_canvas(), mvp, s);
}

void draw_liquid_2d(const liquid_look *l, const view *v) {
    liquid_look at = *l;
    at.cell_px = (float)v->cell_px;
    at.cells[0] = (float)v->width / (float)v->cell_px;
    at.cells[1] = (float)v->height / (float)v->cell_px;
    float mvp[16];
    current_mvp(mvp);
    engine_draw_liquid(engine_of_canvas(), mvp, v->width, v->height, &at);
}

void draw_grains_2d(const grain_look *g) {
    float mvp[16];
    current_mvp(mvp);
    engine_draw_grains(engine_of_canvas(), mvp, g);
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
    gpu *g = gpu_of_canvas();
    drawn d = {gpu_upload_particles(g, w), 0.0f, 0.0f};
    gpu_sprites sprites;
    for (int k = 0; k < 3; k++) sprites.eye[k] = c->eye[k];
    box_distances(c->eye, size, &sprites.near_d, &sprites.far_d);
    if (sprites.near_d < c->near_clip) sprites.near_d = c->near_clip;
    sprites.focal_px = focal_px(v, c);
    /* No particle is nearer than the box's nearest point or farther than its
     * farthest. */
    sprites.min_px = sprites.focal_px / sprites.far_d;
    sprites.max_px = sprites.focal_px / sprites.near_d;
    float mvp[16];
    current_mvp(mvp);
    gpu_draw_sprites_3d(g, mvp, &sprites);
    d.sprite_min_px = sprites.min_px;
    d.sprite_max_px = sprites.max_px;
    return d;
}

void canvas_destroy(canvas *c) {
    if (!c) return;
    /* The GPU objects go with the context, which is still current. */
    gpu_destroy(shaders);
    shaders = NULL;
    engine_destroy(effects);
    effects = NULL;
    OSMesaDestroyContext(c->ctx);
    free(c);
}
