/*
 * Particles in a vertex buffer drawn by shaders, density in a texture: see
 * gpu.h. OpenGL 2.1 and GLSL 1.20 only.
 */
/* The GL 1.5-2.1 entry points (buffers, shaders) are declared only with
 * this. OSMesa exports them; an engine gets them from its loader (glad,
 * GLEW, SDL_GL_GetProcAddress) instead. */
#define GL_GLEXT_PROTOTYPES

#include "gpu.h"

#include <stdio.h>
#include <stdlib.h>

#include <GL/gl.h>
#include <GL/glext.h>

#include "common.h"

/* ---- shaders ------------------------------------------------------------- */

/* One vertex per particle: its position in cells and its velocity in cells
 * per step, from two halves of the same buffer. */
static const char *const POINTS_2D_VS =
    "#version 120\n"
    "uniform mat4 mvp;\n"
    "uniform float point_px;\n"
    "attribute vec3 position;\n"
    "attribute vec3 velocity;\n"
    "varying float speed;\n"
    "void main() {\n"
    "    gl_Position = mvp * vec4(position, 1.0);\n"
    "    gl_PointSize = point_px;\n"
    "    speed = length(velocity);\n"
    "}\n";

/* The palette is a row of colour stops; u puts 0 on the first stop's texel
 * centre and 1 on the last's, so linear filtering blends neighbouring
 * stops. sqrt spreads the slow speeds, where a cooling gas spends its
 * time. */
static const char *const POINTS_2D_FS =
    "#version 120\n"
    "uniform sampler2D palette;\n"
    "uniform float stops;\n"
    "varying float speed;\n"
    "void main() {\n"
    "    float t = clamp(sqrt(speed), 0.0, 1.0);\n"
    "    float u = (0.5 + t * (stops - 1.0)) / stops;\n"
    "    gl_FragColor = vec4(texture2D(palette, vec2(u, 0.5)).rgb, 1.0);\n"
    "}\n";

/* Perspective size: a cell at distance d is focal_px / d pixels wide. */
static const char *const SPRITES_3D_VS =
    "#version 120\n"
    "uniform mat4 mvp;\n"
    "uniform vec3 eye;\n"
    "uniform float focal_px, min_px, max_px, near_d, far_d;\n"
    "attribute vec3 position;\n"
    "attribute vec3 velocity;\n"
    "varying float speed, shade;\n"
    "void main() {\n"
    "    gl_Position = mvp * vec4(position, 1.0);\n"
    "    float d = distance(position, eye);\n"
    "    gl_PointSize = clamp(focal_px / d, min_px, max_px);\n"
    "    shade = 1.0 - 0.5 * clamp((d - near_d) / (far_d - near_d), 0.0, 1.0);\n"
    "    speed = length(velocity);\n"
    "}\n";

/* A disc lit from the upper left; outside the disc nothing is written, so
 * a pixel is the particle's or untouched (no blending, no sorting). The
 * light never takes the colour below 0.6 of itself, so it stays saturated
 * (image.h, RENDER_CHROMA_MIN). */
static const char *const SPRITES_3D_FS =
    "#version 120\n"
    "uniform sampler2D palette;\n"
    "uniform float stops;\n"
    "varying float speed, shade;\n"
    "void main() {\n"
    "    vec2 p = 2.0 * gl_PointCoord - 1.0;\n"
    "    float r2 = dot(p, p);\n"
    "    if (r2 > 1.0) discard;\n"
    "    float lit = max(0.0, -0.4 * p.x - 0.4 * p.y + 0.82 * sqrt(1.0 - r2));\n"
    "    float u = (0.5 + clamp(speed, 0.0, 1.0) * (stops - 1.0)) / stops;\n"
    "    vec3 c = texture2D(palette, vec2(u, 0.5)).rgb;\n"
    "    gl_FragColor = vec4(c * shade * (0.6 + 0.4 * lit), 1.0);\n"
    "}\n";

/* A quad over the world; the texture spans it exactly. */
static const char *const DENSITY_VS =
    "#version 120\n"
    "uniform mat4 mvp;\n"
    "uniform vec2 cells;\n"
    "attribute vec2 corner;\n"
    "varying vec2 uv;\n"
    "void main() {\n"
    "    uv = corner;\n"
    "    gl_Position = mvp * vec4(corner * cells, 0.0, 1.0);\n"
    "}\n";

/* Haze: the background where the density is 0, a light grey where it is
 * `full` or more. Greys only, so it never passes for a particle. */
static const char *const DENSITY_FS =
    "#version 120\n"
    "uniform sampler2D density;\n"
    "uniform vec3 bg;\n"
    "uniform float full;\n"
    "varying vec2 uv;\n"
    "void main() {\n"
    "    float a = clamp(texture2D(density, uv).r / full, 0.0, 1.0);\n"
    "    gl_FragColor = vec4(mix(bg, vec3(0.45), a), 1.0);\n"
    "}\n";

/* Motion between two steps, one vertex per particle: its cell centre
 * before the step (motion.xy) and after it (motion.zw), and its age after
 * the step. `blend` runs from 0 (before) to 1 (after), so the points slide
 * between cells instead of jumping a whole cell a step; the age slides with
 * them, from age - 1 to age. */
static const char *const SMOKE_2D_VS =
    "#version 120\n"
    "uniform mat4 mvp;\n"
    "uniform float blend, lifetime, sprite_px;\n"
    "attribute vec4 motion;\n"
    "attribute float age;\n"
    "varying float lived;\n"
    "void main() {\n"
    "    gl_Position = mvp * vec4(mix(motion.xy, motion.zw, blend), 0.0, 1.0);\n"
    "    gl_PointSize = sprite_px;\n"
    "    lived = clamp((age - 1.0 + blend) / lifetime, 0.0, 1.0);\n"
    "}\n";

/* A soft puff: alpha falls from the centre to 0 at the rim as 1 - r^2,
 * and with the share of its lifetime lived, so old smoke thins out and is
 * gone by the time the library removes it. Its colour cools with age
 * along the palette. */
static const char *const SMOKE_2D_FS =
    "#version 120\n"
    "uniform sampler2D palette;\n"
    "uniform float stops, peak;\n"
    "varying float lived;\n"
    "void main() {\n"
    "    vec2 p = 2.0 * gl_PointCoord - 1.0;\n"
    "    float r2 = dot(p, p);\n"
    "    if (r2 > 1.0) discard;\n"
    "    float u = (0.5 + lived * (stops - 1.0)) / stops;\n"
    "    float a = peak * (1.0 - r2) * (1.0 - lived);\n"
    "    gl_FragColor = vec4(texture2D(palette, vec2(u, 0.5)).rgb, a);\n"
    "}\n";

/* ---- GL helpers --------------------------------------------------------- */

void gpu_check(const char *what) {
    GLenum err = glGetError();
    if (err != GL_NO_ERROR) {
        fprintf(stderr, "OpenGL error 0x%x in %s\n", (unsigned)err, what);
        exit(1);
    }
}

static GLuint compile(GLenum kind, const char *source, const char *name) {
    GLuint shader = glCreateShader(kind);
    glShaderSource(shader, 1, &source, NULL);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetShaderInfoLog(shader, sizeof log, NULL, log);
        fprintf(stderr, "shader %s does not compile:\n%s\n", name, log);
        exit(1);
    }
    return shader;
}

/* Attribute 0 is `position` (or `corner`, or `motion`), 1 is `velocity`
 * (or `age`, or `traits`), bound before linking so every program agrees
 * (engine.c's too). */
GLuint gpu_program(const char *vs, const char *fs, const char *name) {
    GLuint program = glCreateProgram();
    GLuint v = compile(GL_VERTEX_SHADER, vs, name), f = compile(GL_FRAGMENT_SHADER, fs, name);
    glAttachShader(program, v);
    glAttachShader(program, f);
    glBindAttribLocation(program, 0, "position");
    glBindAttribLocation(program, 0, "corner");
    glBindAttribLocation(program, 0, "motion");
    glBindAttribLocation(program, 1, "velocity");
    glBindAttribLocation(program, 1, "age");
    glBindAttribLocation(program, 1, "traits");
    glLinkProgram(program);
    glDeleteShader(v); /* freed with the program */
    glDeleteShader(f);
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[2048];
        glGetProgramInfoLog(program, sizeof log, NULL, log);
        fprintf(stderr, "shader program %s does not link:\n%s\n", name, log);
        exit(1);
    }
    return program;
}

/* A texture of `n` x 1 RGB texels, linearly filtered, clamped. */
static GLuint palette_texture(const uint8_t (*stops)[3], int n) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, n, 1, 0, GL_RGB, GL_UNSIGNED_BYTE, stops);
    return t;
}

/* ---- the object ----------------------------------------------------------- */

struct gpu {
    GLuint points_2d, sprites_3d, density_program, smoke_2d;
    /* Positions in the first half (3 * capacity floats), velocities in the
     * second. */
    GLuint particles;
    size_t capacity, count;
    GLuint palette_2d, palette_3d, palette_smoke;
    /* 5 floats a particle: before and after a step, and the age. */
    GLuint motion;
    size_t motion_capacity, motion_count;
    GLuint quad;                 /* the corners (0,0) to (1,1) */
    GLuint density;              /* a LUMINANCE texture of res[0] x res[1] */
    GLsizei res[2];
    uint8_t *density_bytes;
};

/* Blue, cyan, green, yellow, red: slow to fast. Every stop and every blend
 * of two neighbours keeps its channels' max - min far above
 * RENDER_CHROMA_MIN, so a particle never passes for a grey. */
static const uint8_t PALETTE_2D[5][3] = {
    {50, 100, 230}, {40, 200, 220}, {110, 220, 70}, {250, 200, 40}, {240, 60, 40},
};
/* Water: dark blue to light cyan. */
static const uint8_t PALETTE_3D[3][3] = {{25, 80, 215}, {40, 160, 240}, {150, 235, 255}};
/* Smoke by age: hot yellow, orange, red, cooling to violet. Saturated, as
 * every particle colour is, though a faded puff over the background is
 * not. */
static const uint8_t PALETTE_SMOKE[4][3] = {{255, 214, 110}, {245, 135, 55}, {200, 65, 100}, {110, 85, 200}};

gpu *gpu_create(void) {
    gpu *g = xrealloc(NULL, sizeof *g);
    g->points_2d = gpu_program(POINTS_2D_VS, POINTS_2D_FS, "points_2d");
    g->sprites_3d = gpu_program(SPRITES_3D_VS, SPRITES_3D_FS, "sprites_3d");
    g->density_program = gpu_program(DENSITY_VS, DENSITY_FS, "density");
    g->smoke_2d = gpu_program(SMOKE_2D_VS, SMOKE_2D_FS, "smoke_2d");
    glGenBuffers(1, &g->particles);
    glGenBuffers(1, &g->motion);
    g->motion_capacity = 0;
    g->motion_count = 0;
    g->capacity = 0;
    g->count = 0;
    g->palette_2d = palette_texture(PALETTE_2D, 5);
    g->palette_3d = palette_texture(PALETTE_3D, 3);
    g->palette_smoke = palette_texture(PALETTE_SMOKE, 4);
    static const GLfloat corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    glGenBuffers(1, &g->quad);
    glBindBuffer(GL_ARRAY_BUFFER, g->quad);
    glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glGenTextures(1, &g->density);
    g->res[0] = g->res[1] = 0;
    g->density_bytes = NULL;
    gpu_check("gpu_create");
    return g;
}

void gpu_destroy(gpu *g) {
    if (!g) return;
    glDeleteProgram(g->points_2d);
    glDeleteProgram(g->sprites_3d);
    glDeleteProgram(g->density_program);
    glDeleteProgram(g->smoke_2d);
    GLuint buffers[3] = {g->particles, g->quad, g->motion};
    glDeleteBuffers(3, buffers);
    GLuint textures[4] = {g->palette_2d, g->palette_3d, g->palette_smoke, g->density};
    glDeleteTextures(4, textures);
    free(g->density_bytes);
    free(g);
}

/* ---- particles ------------------------------------------------------------- */

size_t gpu_upload_particles(gpu *g, const mpca_world *w) {
    size_t n = 0;
    mpca_check(mpca_world_export_positions(w, NULL, 0, &n), "mpca_world_export_positions (size query)");
    /* Room to grow, so a world that gains particles does not reallocate the
     * buffer every frame. */
    if (n > g->capacity || g->capacity == 0) g->capacity = n + n / 2 + 64;
    glBindBuffer(GL_ARRAY_BUFFER, g->particles);
    /* New storage every frame ("orphaning"): the driver may still be drawing
     * from the old one, and mapping it would wait for that. */
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(6 * g->capacity * sizeof(float)), NULL, GL_STREAM_DRAW);
    float *mapped = glMapBuffer(GL_ARRAY_BUFFER, GL_WRITE_ONLY);
    if (!mapped) {
        fprintf(stderr, "glMapBuffer failed (0x%x)\n", (unsigned)glGetError());
        exit(1);
    }
    size_t got = 0;
    mpca_status s = mpca_world_export_positions(w, mapped, g->capacity, &got);
    if (s == MPCA_STATUS_OK) s = mpca_world_export_velocities(w, mapped + 3 * g->capacity, g->capacity, &got);
    /* Unmapped before a failed status ends the program, as it must be. */
    GLboolean intact = glUnmapBuffer(GL_ARRAY_BUFFER);
    mpca_check(s, "mpca_world_export_positions/velocities into the vertex buffer");
    if (!intact) {
        /* The storage was lost while mapped (a mode switch): upload again. */
        glBindBuffer(GL_ARRAY_BUFFER, 0);
        return gpu_upload_particles(g, w);
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    g->count = got;
    gpu_check("gpu_upload_particles");
    return got;
}

/* Binds the particle buffer's two halves to attributes 0 and 1 and the
 * palette to texture unit 0, and draws the points with `program`. */
static void draw_particles(gpu *g, GLuint program, GLuint palette, int stops) {
    glUniform1i(glGetUniformLocation(program, "palette"), 0);
    glUniform1f(glGetUniformLocation(program, "stops"), (float)stops);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, palette);
    glBindBuffer(GL_ARRAY_BUFFER, g->particles);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, (const void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, (const void *)(3 * g->capacity * sizeof(float)));
    /* The shaders set the point size. */
    glEnable(GL_VERTEX_PROGRAM_POINT_SIZE);
    glDrawArrays(GL_POINTS, 0, (GLsizei)g->count);
    glDisable(GL_VERTEX_PROGRAM_POINT_SIZE);
    glDisableVertexAttribArray(1);
    glDisableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
}

void gpu_draw_points_2d(gpu *g, const float mvp[16], float point_px) {
    if (g->count == 0) return;
    GLuint p = g->points_2d;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "mvp"), 1, GL_FALSE, mvp);
    glUniform1f(glGetUniformLocation(p, "point_px"), point_px);
    /* Square, unsmoothed points: each covers point_px x point_px pixels
     * inside its own cell, and no two particles share a cell (M1). */
    glDisable(GL_POINT_SMOOTH);
    glDisable(GL_BLEND);
    draw_particles(g, p, g->palette_2d, 5);
    gpu_check("gpu_draw_points_2d");
}

void gpu_draw_sprites_3d(gpu *g, const float mvp[16], const gpu_sprites *s) {
    if (g->count == 0) return;
    GLuint p = g->sprites_3d;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "mvp"), 1, GL_FALSE, mvp);
    glUniform3fv(glGetUniformLocation(p, "eye"), 1, s->eye);
    glUniform1f(glGetUniformLocation(p, "focal_px"), s->focal_px);
    glUniform1f(glGetUniformLocation(p, "min_px"), s->min_px);
    glUniform1f(glGetUniformLocation(p, "max_px"), s->max_px);
    glUniform1f(glGetUniformLocation(p, "near_d"), s->near_d);
    glUniform1f(glGetUniformLocation(p, "far_d"), s->far_d);
    glDisable(GL_BLEND);
    /* gl_PointCoord needs point sprites on in a compatibility context. */
    glEnable(GL_POINT_SPRITE);
    draw_particles(g, p, g->palette_3d, 3);
    glDisable(GL_POINT_SPRITE);
    gpu_check("gpu_draw_sprites_3d");
}

/* ---- motion between steps ---------------------------------------------------- */

void gpu_upload_motion_2d(gpu *g, const float *from, const float *to, const uint32_t *ages, size_t n) {
    if (n > g->motion_capacity || g->motion_capacity == 0) g->motion_capacity = n + n / 2 + 64;
    glBindBuffer(GL_ARRAY_BUFFER, g->motion);
    /* Orphaned, as the particle buffer is (gpu_upload_particles). */
    glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(5 * g->motion_capacity * sizeof(float)), NULL, GL_STREAM_DRAW);
    float *mapped = glMapBuffer(GL_ARRAY_BUFFER, GL_WRITE_ONLY);
    if (!mapped) {
        fprintf(stderr, "glMapBuffer failed (0x%x)\n", (unsigned)glGetError());
        exit(1);
    }
    for (size_t i = 0; i < n; i++) {
        float *v = mapped + 5 * i;
        v[0] = from[2 * i];
        v[1] = from[2 * i + 1];
        v[2] = to[2 * i];
        v[3] = to[2 * i + 1];
        v[4] = (float)ages[i];
    }
    GLboolean intact = glUnmapBuffer(GL_ARRAY_BUFFER);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    if (!intact) {
        /* The storage was lost while mapped: upload again. */
        gpu_upload_motion_2d(g, from, to, ages, n);
        return;
    }
    g->motion_count = n;
    gpu_check("gpu_upload_motion_2d");
}

void gpu_draw_smoke_2d(gpu *g, const float mvp[16], const gpu_smoke *s) {
    if (g->motion_count == 0) return;
    GLuint p = g->smoke_2d;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "mvp"), 1, GL_FALSE, mvp);
    glUniform1f(glGetUniformLocation(p, "blend"), s->blend);
    glUniform1f(glGetUniformLocation(p, "lifetime"), s->lifetime > 0.0f ? s->lifetime : 1.0f);
    glUniform1f(glGetUniformLocation(p, "sprite_px"), s->sprite_px);
    glUniform1f(glGetUniformLocation(p, "peak"), s->peak);
    glUniform1i(glGetUniformLocation(p, "palette"), 0);
    glUniform1f(glGetUniformLocation(p, "stops"), 4.0f);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->palette_smoke);
    glBindBuffer(GL_ARRAY_BUFFER, g->motion);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    const GLsizei stride = 5 * sizeof(float);
    glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, stride, (const void *)0);
    glVertexAttribPointer(1, 1, GL_FLOAT, GL_FALSE, stride, (const void *)(4 * sizeof(float)));
    /* Puffs overlap: each is laid over what is there by its alpha, so
     * where many meet the smoke is thick. */
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glEnable(GL_VERTEX_PROGRAM_POINT_SIZE);
    glEnable(GL_POINT_SPRITE);
    glDrawArrays(GL_POINTS, 0, (GLsizei)g->motion_count);
    glDisable(GL_POINT_SPRITE);
    glDisable(GL_VERTEX_PROGRAM_POINT_SIZE);
    glDisable(GL_BLEND);
    glDisableVertexAttribArray(1);
    glDisableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    gpu_check("gpu_draw_smoke_2d");
}

/* ---- density --------------------------------------------------------------- */

void gpu_upload_density_2d(gpu *g, const mpca_world *w, uint32_t bin) {
    mpca_desc d;
    d.struct_size = sizeof d;
    mpca_check(mpca_world_desc(w, &d), "mpca_world_desc");
    if (bin == 0) bin = 1;
    const uint32_t res[3] = {d.size[0] / bin ? d.size[0] / bin : 1, d.size[1] / bin ? d.size[1] / bin : 1, 1};
    size_t len = (size_t)res[0] * res[1];
    int fresh = (GLsizei)res[0] != g->res[0] || (GLsizei)res[1] != g->res[1];
    if (fresh) g->density_bytes = xrealloc(g->density_bytes, len);
    mpca_check(mpca_world_density_u8(w, res, g->density_bytes, len), "mpca_world_density_u8");
    glBindTexture(GL_TEXTURE_2D, g->density);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (fresh) {
        /* Storage once; later frames only replace the texels. */
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_LUMINANCE, (GLsizei)res[0], (GLsizei)res[1], 0, GL_LUMINANCE,
                     GL_UNSIGNED_BYTE, g->density_bytes);
        g->res[0] = (GLsizei)res[0];
        g->res[1] = (GLsizei)res[1];
    } else {
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, g->res[0], g->res[1], GL_LUMINANCE, GL_UNSIGNED_BYTE,
                        g->density_bytes);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    gpu_check("gpu_upload_density_2d");
}

void gpu_draw_density_2d(gpu *g, const float mvp[16], uint32_t nx, uint32_t ny, const float bg[3], float full) {
    if (g->res[0] == 0) return;
    GLuint p = g->density_program;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "mvp"), 1, GL_FALSE, mvp);
    glUniform2f(glGetUniformLocation(p, "cells"), (float)nx, (float)ny);
    glUniform3fv(glGetUniformLocation(p, "bg"), 1, bg);
    glUniform1f(glGetUniformLocation(p, "full"), full > 0.0f ? full : 1.0f);
    glUniform1i(glGetUniformLocation(p, "density"), 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->density);
    glBindBuffer(GL_ARRAY_BUFFER, g->quad);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, (const void *)0);
    glDisable(GL_BLEND);
    glDrawArrays(GL_TRIANGLE_FAN, 0, 4);
    glDisableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    gpu_check("gpu_draw_density_2d");
}
