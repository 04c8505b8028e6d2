/*
 * Smoke, a liquid and grains drawn as a game engine draws them: see
 * engine.h. OpenGL 2.1 and GLSL 1.20, and a framebuffer object for the
 * liquid's density image.
 */
/* Buffers, shaders and framebuffer objects are declared only with this
 * (see gpu.c). */
#define GL_GLEXT_PROTOTYPES

#include "engine.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <GL/gl.h>
#include <GL/glext.h>

#include "common.h"
#include "gpu.h"

/* ---- shaders ------------------------------------------------------------------ */

/* Every look reads one vertex a particle: `motion` its cell before and
 * after the step, `traits` its age, tag, seed and travel (a `moving`). */

/* A puff's age runs from age - 1 to age as `blend` runs from 0 to 1, so it
 * grows and fades smoothly between steps too. It fades in over `fade_in`
 * steps, so new smoke does not pop up at the vent, and out as the life left
 * to the power 1.5, so it thins out while it spreads. Its texture turns by
 * an angle of its own, and slowly with age, so no two puffs look alike. */
static const char *const SMOKE_VS =
    "#version 120\n"
    "uniform mat4 mvp;\n"
    "uniform float blend, lifetime, fade_in, start_px, end_px, peak, spin;\n"
    "attribute vec4 motion;\n"
    "attribute vec4 traits;\n"
    "varying float alpha, lived;\n"
    "varying vec2 turn;\n"
    "void main() {\n"
    "    gl_Position = mvp * vec4(mix(motion.xy, motion.zw, blend), 0.0, 1.0);\n"
    "    float age = max(traits.x - 1.0 + blend, 0.0);\n"
    "    lived = clamp(age / lifetime, 0.0, 1.0);\n"
    "    gl_PointSize = mix(start_px, end_px, sqrt(lived));\n"
    "    float left = 1.0 - lived;\n"
    "    alpha = peak * clamp(age / fade_in, 0.0, 1.0) * left * sqrt(left);\n"
    "    float sense = traits.z < 0.5 ? -1.0 : 1.0;\n"
    "    float angle = 6.2831853 * (7.0 * traits.z + sense * spin * lived);\n"
    "    turn = vec2(cos(angle), sin(angle));\n"
    "}\n";

/* Premultiplied alpha: the colour leaves the shader already scaled by its
 * coverage, so overlapping puffs add up without dark fringes. */
static const char *const SMOKE_FS =
    "#version 120\n"
    "uniform sampler2D puff;\n"
    "uniform vec3 young, old;\n"
    "varying float alpha, lived;\n"
    "varying vec2 turn;\n"
    "void main() {\n"
    "    vec2 p = gl_PointCoord - 0.5;\n"
    "    p = vec2(turn.x * p.x - turn.y * p.y, turn.y * p.x + turn.x * p.y) + 0.5;\n"
    "    float a = alpha * texture2D(puff, p).r;\n"
    "    gl_FragColor = vec4(mix(young, old, lived) * a, a);\n"
    "}\n";

/* A splat: the density kernel (1 - r^2)^3, a smooth bump with a flat top,
 * in red, and the same weighted by how fast the particle travels in
 * green, so the shading pass can tell running water (foam) from still.
 * Alone, a particle's splat stays under the surface's level, so a drop in
 * the air would vanish: alpha, blended by taking the largest, holds a
 * disc `drop` of the splat's radius round every particle, which the
 * shading pass counts as liquid. `mirror`
 * (scale, offset) reflects the particles across a wall. */
static const char *const SPLAT_VS =
    "#version 120\n"
    "uniform mat4 mvp;\n"
    "uniform vec4 mirror;\n"
    "uniform float blend, splat_px, foam_travel;\n"
    "attribute vec4 motion;\n"
    "attribute vec4 traits;\n"
    "varying float fast;\n"
    "void main() {\n"
    "    vec2 at = mirror.xy * mix(motion.xy, motion.zw, blend) + mirror.zw;\n"
    "    gl_Position = mvp * vec4(at, 0.0, 1.0);\n"
    "    gl_PointSize = splat_px;\n"
    "    fast = smoothstep(foam_travel, 1.0, traits.w);\n"
    "}\n";

static const char *const SPLAT_FS =
    "#version 120\n"
    "uniform float gain, drop;\n"
    "varying float fast;\n"
    "void main() {\n"
    "    vec2 p = 2.0 * gl_PointCoord - 1.0;\n"
    "    float r2 = dot(p, p);\n"
    "    float k = 1.0 - r2;\n"
    "    if (k <= 0.0) discard;\n"
    "    float w = gain * k * k * k;\n"
    "    gl_FragColor = vec4(w, w * fast, 0.0, 1.0 - smoothstep(0.6 * drop, drop, sqrt(r2)));\n"
    "}\n";

/* A quad over the whole frame, in clip space; the density image has a
 * margin round the frame, which `inset` (scale, offset) steps over. */
static const char *const SURFACE_VS =
    "#version 120\n"
    "uniform vec4 inset;\n"
    "attribute vec2 corner;\n"
    "varying vec2 uv;\n"
    "void main() {\n"
    "    uv = inset.xy * corner + inset.zw;\n"
    "    gl_Position = vec4(2.0 * corner - 1.0, 0.0, 1.0);\n"
    "}\n";

/* The surface is where the density crosses `level`, half a packed body's:
 * there it passes the outer particles' centres by about half a cell. The
 * edge is smoothed over a band of the density, so it is antialiased at any
 * scale. The tint is by the liquid above a pixel (sampled upwards, up to
 * depth_cells): a column's top is light and its bottom dark, as light is
 * absorbed through water, and a thin sheet or a drop stays light. The
 * gradient of the density is the surface's slope, for a highlight from
 * the upper left, taken a cell either side, where the ripple a lattice of
 * particles leaves in the density cancels out; a rim just inside the edge
 * catches the light as a meniscus does. Foam is the travel the splats carried, whitening the
 * liquid where it runs fast. */
static const char *const SURFACE_FS =
    "#version 120\n"
    "uniform sampler2D density;\n"
    "uniform vec2 cell;\n"
    "uniform float level, full, depth_uv;\n"
    "uniform vec3 shallow, deep;\n"
    "varying vec2 uv;\n"
    "float at(vec2 o) { return texture2D(density, uv + o).r; }\n"
    "void main() {\n"
    "    vec4 s = texture2D(density, uv);\n"
    "    float band = 0.12 * full;\n"
    "    float d = max(s.r, s.a * level);\n"
    "    float edge = smoothstep(level - band, level + band, d);\n"
    "    if (edge <= 0.0) discard;\n"
    "    float above = 0.0;\n"
    "    for (int k = 1; k <= 16; k++) {\n"
    "        above += clamp((at(vec2(0.0, depth_uv * float(k) / 16.0)) - level) / (full - level), 0.0, 1.0);\n"
    "    }\n"
    "    vec3 c = mix(shallow, deep, pow(above / 16.0, 0.8));\n"
    "    vec2 g = vec2(at(vec2(cell.x, 0.0)) - at(vec2(-cell.x, 0.0)),\n"
    "                  at(vec2(0.0, cell.y)) - at(vec2(0.0, -cell.y)));\n"
    "    vec3 n = normalize(vec3(-g / full, 0.6));\n"
    "    vec3 h = normalize(vec3(-0.45, 0.65, 0.6) + vec3(0.0, 0.0, 1.0));\n"
    "    float spec = pow(max(dot(n, h), 0.0), 30.0);\n"
    "    float rim = 1.0 - smoothstep(level, level + 0.35 * full, d);\n"
    "    c = mix(c, min(shallow * 1.35 + 0.12, 1.0), 0.7 * rim);\n"
    "    float foam = clamp(s.g / max(d, 0.004), 0.0, 1.0);\n"
    "    c = mix(c, vec3(0.88, 0.94, 1.0), 0.8 * foam);\n"
    "    c += 0.55 * spec;\n"
    "    gl_FragColor = vec4(min(c, 1.0), edge);\n"
    "}\n";

/* A grain's size and brightness stray from the mean by its seed, its hue a
 * little towards red or blue, and its place off its cell's centre by up to
 * `scatter` cells, so a pile of one material still reads as many grains
 * and not as the automaton's lattice. */
static const char *const GRAINS_VS =
    "#version 120\n"
    "uniform mat4 mvp;\n"
    "uniform float blend, grain_px, jitter, scatter, materials;\n"
    "attribute vec4 motion;\n"
    "attribute vec4 traits;\n"
    "varying float material;\n"
    "varying vec3 tint;\n"
    "void main() {\n"
    "    float a = fract(traits.z * 97.31), b = fract(traits.z * 13.73 + 0.37);\n"
    "    vec2 off = scatter * (2.0 * vec2(fract(traits.z * 53.17), fract(traits.z * 71.71)) - 1.0);\n"
    "    gl_Position = mvp * vec4(mix(motion.xy, motion.zw, blend) + off, 0.0, 1.0);\n"
    "    gl_PointSize = grain_px * (0.85 + 0.3 * a);\n"
    "    material = (min(traits.y, materials - 1.0) + 0.5) / materials;\n"
    "    float bright = 1.0 + jitter * (2.0 * traits.z - 1.0);\n"
    "    float warm = 0.5 * jitter * (2.0 * b - 1.0);\n"
    "    tint = bright * vec3(1.0 + warm, 1.0, 1.0 - warm);\n"
    "}\n";

/* An opaque disc shaded as a bead lit from the upper left: a pile of them
 * shows every grain's outline without drawing one. */
static const char *const GRAINS_FS =
    "#version 120\n"
    "uniform sampler2D palette;\n"
    "varying float material;\n"
    "varying vec3 tint;\n"
    "void main() {\n"
    "    vec2 p = 2.0 * gl_PointCoord - 1.0;\n"
    "    p.y = -p.y;\n"
    "    float r2 = dot(p, p);\n"
    "    if (r2 > 1.0) discard;\n"
    "    float lit = max(0.0, dot(vec3(p, sqrt(1.0 - r2)), normalize(vec3(-0.45, 0.55, 0.7))));\n"
    "    vec3 c = texture2D(palette, vec2(material, 0.5)).rgb * tint;\n"
    "    gl_FragColor = vec4(min(c * (0.45 + 0.7 * lit), 1.0), 1.0);\n"
    "}\n";

/* ---- the object ------------------------------------------------------------------ */

/* The puff texture's side: a puff is drawn a few dozen pixels wide, and
 * mipmaps cover the smaller ones. */
#define PUFF_TEXELS 64
#define MAX_MATERIALS 256
/* The radius of a lone drop of liquid, in cells. */
#define DROP_CELLS 0.6f

struct engine {
    GLuint smoke, splat, surface, grains;
    GLuint particles; /* the `moving` vertices */
    size_t capacity, count;
    GLuint puff;      /* LUMINANCE, PUFF_TEXELS square, mipmapped */
    GLuint palette;   /* the grains' colours, one texel a material */
    GLuint quad;      /* the corners (0,0) to (1,1) */
    GLuint density;   /* the liquid's density image, RGBA8 */
    GLuint framebuffer;
    uint32_t density_size[2];
};

/* A lattice hash to [0, 1): the puff's noise is fixed, the same on every
 * machine. */
static float lattice(int x, int y) {
    uint32_t h = (uint32_t)x * 0x8da6b343u ^ (uint32_t)y * 0xd8163841u;
    h ^= h >> 15;
    h *= 0x2c1b3c6du;
    h ^= h >> 12;
    h *= 0x297a2d39u;
    h ^= h >> 15;
    return (float)(h >> 8) / 16777216.0f;
}

/* Value noise, smoothly interpolated between lattice points `period`
 * apart, and wrapping at `period` cells so the texture has no seam where
 * the puff's edge is zero anyway. */
static float value_noise(float x, float y, int period) {
    int x0 = (int)floorf(x), y0 = (int)floorf(y);
    float fx = x - (float)x0, fy = y - (float)y0;
    fx = fx * fx * (3.0f - 2.0f * fx);
    fy = fy * fy * (3.0f - 2.0f * fy);
    int x1 = (x0 + 1) % period, y1 = (y0 + 1) % period;
    x0 %= period;
    y0 %= period;
    float a = lattice(x0, y0) + fx * (lattice(x1, y0) - lattice(x0, y0));
    float b = lattice(x0, y1) + fx * (lattice(x1, y1) - lattice(x0, y1));
    return a + fy * (b - a);
}

/* A puff: a soft radial falloff, zero at the rim, times three octaves of
 * noise, so overlapping puffs make billows instead of a smooth blur. */
static GLuint puff_texture(void) {
    static uint8_t texels[PUFF_TEXELS * PUFF_TEXELS];
    for (int y = 0; y < PUFF_TEXELS; y++) {
        for (int x = 0; x < PUFF_TEXELS; x++) {
            float u = ((float)x + 0.5f) / PUFF_TEXELS * 2.0f - 1.0f;
            float v = ((float)y + 0.5f) / PUFF_TEXELS * 2.0f - 1.0f;
            float r2 = u * u + v * v;
            float fall = r2 < 1.0f ? (1.0f - r2) * (1.0f - r2) : 0.0f;
            float n = 0.0f, amp = 0.5f;
            for (int octave = 0, period = 4; octave < 3; octave++, period *= 2) {
                float s = (float)period / PUFF_TEXELS;
                n += amp * value_noise((float)x * s, (float)y * s, period);
                amp *= 0.5f;
            }
            /* Noise pushed towards 0 and 1, so a puff is clumps of
             * smoke with thin gaps, not a soft disc. */
            float clump = n < 0.3f ? 0.0f : n > 0.75f ? 1.0f : (n - 0.3f) / 0.45f;
            clump = clump * clump * (3.0f - 2.0f * clump);
            float a = fall * (0.15f + 1.1f * clump);
            texels[y * PUFF_TEXELS + x] = (uint8_t)lrintf(255.0f * (a < 1.0f ? a : 1.0f));
        }
    }
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_LUMINANCE, PUFF_TEXELS, PUFF_TEXELS, 0, GL_LUMINANCE, GL_UNSIGNED_BYTE,
                 texels);
    glGenerateMipmap(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, 0);
    return t;
}

static GLuint plain_texture(GLint filter) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    return t;
}

engine *engine_create(void) {
    engine *e = xrealloc(NULL, sizeof *e);
    e->smoke = gpu_program(SMOKE_VS, SMOKE_FS, "smoke");
    e->splat = gpu_program(SPLAT_VS, SPLAT_FS, "splat");
    e->surface = gpu_program(SURFACE_VS, SURFACE_FS, "surface");
    e->grains = gpu_program(GRAINS_VS, GRAINS_FS, "grains");
    glGenBuffers(1, &e->particles);
    e->capacity = e->count = 0;
    e->puff = puff_texture();
    /* Materials are whole tags: no blending between neighbours. */
    e->palette = plain_texture(GL_NEAREST);
    static const GLfloat corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    glGenBuffers(1, &e->quad);
    glBindBuffer(GL_ARRAY_BUFFER, e->quad);
    glBufferData(GL_ARRAY_BUFFER, sizeof corners, corners, GL_STATIC_DRAW);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    /* Linear, so the surface pass reads a smooth density between texels. */
    e->density = plain_texture(GL_LINEAR);
    glGenFramebuffers(1, &e->framebuffer);
    e->density_size[0] = e->density_size[1] = 0;
    gpu_check("engine_create");
    return e;
}

void engine_destroy(engine *e) {
    if (!e) return;
    glDeleteProgram(e->smoke);
    glDeleteProgram(e->splat);
    glDeleteProgram(e->surface);
    glDeleteProgram(e->grains);
    GLuint buffers[2] = {e->particles, e->quad};
    glDeleteBuffers(2, buffers);
    GLuint textures[3] = {e->puff, e->palette, e->density};
    glDeleteTextures(3, textures);
    glDeleteFramebuffers(1, &e->framebuffer);
    free(e);
}

void engine_upload(engine *e, const moving *particles, size_t n) {
    glBindBuffer(GL_ARRAY_BUFFER, e->particles);
    if (n > e->capacity || e->capacity == 0) {
        e->capacity = n + n / 2 + 64;
        glBufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(e->capacity * sizeof *particles), NULL, GL_STREAM_DRAW);
    }
    if (n) glBufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(n * sizeof *particles), particles);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    e->count = n;
    gpu_check("engine_upload");
}

/* Draws the uploaded particles as point sprites with the program in use. */
static void draw_points(engine *e) {
    glBindBuffer(GL_ARRAY_BUFFER, e->particles);
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    const GLsizei stride = sizeof(moving);
    glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, stride, (const void *)offsetof(moving, from));
    glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, stride, (const void *)offsetof(moving, age));
    glEnable(GL_VERTEX_PROGRAM_POINT_SIZE);
    glEnable(GL_POINT_SPRITE);
    glDrawArrays(GL_POINTS, 0, (GLsizei)e->count);
    glDisable(GL_POINT_SPRITE);
    glDisable(GL_VERTEX_PROGRAM_POINT_SIZE);
    glDisableVertexAttribArray(1);
    glDisableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
}

static void uniform1(GLuint p, const char *name, float v) {
    glUniform1f(glGetUniformLocation(p, name), v);
}

/* ---- smoke --------------------------------------------------------------------- */

void engine_draw_smoke(engine *e, const float mvp[16], const smoke_look *s) {
    if (e->count == 0) return;
    GLuint p = e->smoke;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "mvp"), 1, GL_FALSE, mvp);
    uniform1(p, "blend", s->blend);
    uniform1(p, "lifetime", s->lifetime > 0.0f ? s->lifetime : 1.0f);
    uniform1(p, "fade_in", s->fade_in > 0.0f ? s->fade_in : 1e-3f);
    uniform1(p, "start_px", s->start_px);
    uniform1(p, "end_px", s->end_px);
    uniform1(p, "peak", s->peak);
    uniform1(p, "spin", s->spin);
    glUniform3fv(glGetUniformLocation(p, "young"), 1, s->young);
    glUniform3fv(glGetUniformLocation(p, "old"), 1, s->old);
    glUniform1i(glGetUniformLocation(p, "puff"), 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, e->puff);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    draw_points(e);
    glDisable(GL_BLEND);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    gpu_check("engine_draw_smoke");
}

/* ---- a liquid ---------------------------------------------------------------------- */

/* The density image, `width` x `height`, bound as the framebuffer. */
static void bind_density(engine *e, uint32_t width, uint32_t height) {
    glBindTexture(GL_TEXTURE_2D, e->density);
    if (e->density_size[0] != width || e->density_size[1] != height) {
        /* 8 bits a channel are enough, and every OpenGL ES 2 renders into
         * them: in 2D a cell holds one particle at most, so the density is
         * bounded and the splats' gain keeps a packed body at half scale. */
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, (GLsizei)width, (GLsizei)height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                     NULL);
        e->density_size[0] = width;
        e->density_size[1] = height;
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, e->framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, e->density, 0);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "the liquid's density framebuffer is incomplete (0x%x)\n", (unsigned)status);
        exit(1);
    }
}

void engine_draw_liquid(engine *e, const float mvp[16], uint32_t width, uint32_t height, const liquid_look *l) {
    if (e->count == 0) return;
    const float splat_px = 2.0f * l->radius_cells * l->cell_px;
    /* A packed body (a particle every cell) sums the kernel over the
     * lattice: gain * pi R^2 / 4 with R in cells. Half scale leaves room
     * above it for the 8-bit image. */
    const float full = 0.5f, r = l->radius_cells;
    const float gain = full * 4.0f / (3.14159265f * r * r);
    /* The density image reaches a splat beyond the frame on every side:
     * a point is clipped whole when its centre leaves the viewport, and
     * the particles mirrored behind a wall have theirs outside. */
    const uint32_t margin = (uint32_t)ceilf(0.5f * splat_px) + 1;
    const uint32_t w = width + 2 * margin, h = height + 2 * margin;
    const float sx = (float)width / (float)w, sy = (float)height / (float)h;
    float wide[16];
    for (int col = 0; col < 4; col++) {
        wide[4 * col + 0] = sx * mvp[4 * col + 0];
        wide[4 * col + 1] = sy * mvp[4 * col + 1];
        wide[4 * col + 2] = mvp[4 * col + 2];
        wide[4 * col + 3] = mvp[4 * col + 3];
    }

    /* Pass 1: the splats, added up in the density image. */
    bind_density(e, w, h);
    glViewport(0, 0, (GLsizei)w, (GLsizei)h);
    GLfloat clear[4];
    glGetFloatv(GL_COLOR_CLEAR_VALUE, clear);
    glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    glClearColor(clear[0], clear[1], clear[2], clear[3]);
    GLuint p = e->splat;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "mvp"), 1, GL_FALSE, wide);
    uniform1(p, "blend", l->blend);
    uniform1(p, "splat_px", splat_px);
    uniform1(p, "foam_travel", l->foam_travel < 1.0f ? l->foam_travel : 0.999f);
    uniform1(p, "gain", gain);
    uniform1(p, "drop", DROP_CELLS / r);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquationSeparate(GL_FUNC_ADD, GL_MAX);
    GLint mirror = glGetUniformLocation(p, "mirror");
    glUniform4f(mirror, 1.0f, 1.0f, 0.0f, 0.0f);
    draw_points(e);
    for (int axis = 0; axis < 2; axis++) {
        for (int side = 0; side < 2; side++) {
            if (!(l->walls >> (2 * axis + side) & 1u)) continue;
            /* x -> 2 face - x along the axis; particles far from the
             * face land outside the image. */
            float face = side ? l->cells[axis] : 0.0f;
            if (axis == 0) {
                glUniform4f(mirror, -1.0f, 1.0f, 2.0f * face, 0.0f);
            } else {
                glUniform4f(mirror, 1.0f, -1.0f, 0.0f, 2.0f * face);
            }
            draw_points(e);
        }
    }
    glBlendEquation(GL_FUNC_ADD);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    /* Pass 2: the surface, shaded over the frame. */
    glViewport(0, 0, (GLsizei)width, (GLsizei)height);
    p = e->surface;
    glUseProgram(p);
    glUniform4f(glGetUniformLocation(p, "inset"), sx, sy, (float)margin / (float)w, (float)margin / (float)h);
    glUniform2f(glGetUniformLocation(p, "cell"), l->cell_px / (float)w, l->cell_px / (float)h);
    uniform1(p, "level", 0.5f * full);
    uniform1(p, "full", full);
    uniform1(p, "depth_uv", l->depth_cells * l->cell_px / (float)h);
    glUniform3fv(glGetUniformLocation(p, "shallow"), 1, l->shallow);
    glUniform3fv(glGetUniformLocation(p, "deep"), 1, l->deep);
    glUniform1i(glGetUniformLocation(p, "density"), 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, e->density);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glBindBuffer(GL_ARRAY_BUFFER, e->quad);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, (const void *)0);
    glDrawArrays(GL_TRIANGLE_FAN, 0, 4);
    glDisableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    glDisable(GL_BLEND);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    gpu_check("engine_draw_liquid");
}

/* ---- grains ---------------------------------------------------------------------- */

void engine_draw_grains(engine *e, const float mvp[16], const grain_look *g) {
    if (e->count == 0 || g->materials == 0) return;
    uint32_t materials = g->materials < MAX_MATERIALS ? g->materials : MAX_MATERIALS;
    uint8_t texels[MAX_MATERIALS][3];
    for (uint32_t i = 0; i < materials; i++) {
        for (int k = 0; k < 3; k++) {
            float c = g->colours[i][k];
            texels[i][k] = (uint8_t)lrintf(255.0f * (c < 0.0f ? 0.0f : c > 1.0f ? 1.0f : c));
        }
    }
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, e->palette);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB, (GLsizei)materials, 1, 0, GL_RGB, GL_UNSIGNED_BYTE, texels);
    GLuint p = e->grains;
    glUseProgram(p);
    glUniformMatrix4fv(glGetUniformLocation(p, "mvp"), 1, GL_FALSE, mvp);
    uniform1(p, "blend", g->blend);
    uniform1(p, "grain_px", g->grain_px);
    uniform1(p, "jitter", g->jitter);
    uniform1(p, "scatter", g->scatter);
    uniform1(p, "materials", (float)materials);
    glUniform1i(glGetUniformLocation(p, "palette"), 0);
    /* Opaque: a grain is drawn over whatever is there. */
    glDisable(GL_BLEND);
    draw_points(e);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    gpu_check("engine_draw_grains");
}
