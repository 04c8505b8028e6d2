/*
 * Smoke, water and sand drawn as a game engine draws them (issue 28), beside
 * the paper's scenes, which draw every particle as a square coloured by
 * speed. One source built three times: `looks-smoke`, `looks-water` and
 * `looks-sand` (-DLOOK='"smoke"', ...), each a 2D world stepped one step at
 * a time and followed by id (follow.h), so every frame may be drawn part of
 * the way between the last two steps (engine.h):
 *
 *   - smoke: a vent in the ground puffs buoyant smoke that rises through
 *     still air and dies after its lifetime; drawn as soft noisy sprites
 *     laid over one another with premultiplied alpha, each growing, turning
 *     and fading with its particle's age;
 *   - water: a tap pours into a pool with two stones on its floor, then
 *     closes; drawn as a surface: the particles splatted as blurred discs
 *     into an offscreen density image, thresholded, tinted by the depth
 *     below the surface, lit by its gradient, white with foam where it
 *     runs, and spray as faint drops;
 *   - sand: a wide spout pours grains onto the floor into a mound, in bands
 *     of four materials (the emitter's tag, changed every 250 steps, M6b);
 *     drawn as small opaque beads, coloured by tag with a per-grain jitter.
 *
 * Each effect's world description is set in one function (smoke_desc,
 * water_desc, sand_desc): what makes the effect, from docs/model.md (Units,
 * M5.1b, M5.7) and the paper's scenes. The scene around it (emitters,
 * obstacles) is set apart, in build_*.
 *
 * Frames (--every) and the contact sheet are at whole steps; the animated
 * GIF's frames are spread evenly over the span of the run it shows (the
 * whole run, or the smoke's last steps), at fractional steps where they
 * fall between two (t=412.50 is half way from step 412 to 413).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "follow.h"
#include "gif.h"
#include "image.h"
#include "scene.h"

/* The effect this build draws: "smoke", "water" or "sand". */
#ifndef LOOK
#error "build with -DLOOK='\"smoke\"' (or water, or sand)"
#endif

#define PI_F 3.14159265358979323846f

/* What one effect is: its program, its world, how it is drawn. */
typedef struct effect {
    scene s; /* name, title, defaults, about; build and draw are not used */
    /* The size its geometry is given for: positions scale with --size;
     * velocities and accelerations, in cells and steps, do not. */
    uint32_t reference;
    mpca_world *(*build)(const scene_opts *o);
    /* Called before step t (from t to t + 1): closes a tap, changes a tag. */
    void (*before_step)(mpca_world *w, const scene_opts *o, uint64_t t);
    /* Draws the uploaded particles `blend` of the way through the last
     * step, and the scene's fixed parts, into the current context. */
    void (*draw)(const scene_opts *o, float blend, const view *v);
    /* The steps the GIF spans, ending with the run; 0 for the whole run. */
    uint64_t gif_span;
    int gif_delay_cs, gif_last_delay_cs;
} effect;

/* Cells at --size from cells at the effect's reference size. */
static float at_size(float cells, const scene_opts *o, uint32_t reference) {
    return cells * (float)o->size / (float)reference;
}

static uint32_t cells_at_size(uint32_t cells, const scene_opts *o, uint32_t reference) {
    return scale_cells(cells, o->size, reference);
}

/* An emitter of the scene's reference geometry at --size: its box scaled,
 * at least a cell each way, its rate with its width. */
static mpca_emitter scaled_emitter(mpca_emitter e, const scene_opts *o, uint32_t reference) {
    uint32_t width = e.max[0] - e.min[0];
    for (int k = 0; k < 2; k++) {
        e.min[k] = cells_at_size(e.min[k], o, reference);
        e.max[k] = cells_at_size(e.max[k], o, reference);
        if (e.max[k] <= e.min[k]) e.max[k] = e.min[k] + 1;
    }
    e.min[2] = 0;
    e.max[2] = 1;
    e.rate *= (float)(e.max[0] - e.min[0]) / (float)width;
    return e;
}

static void add_emitter(mpca_world *w, const mpca_emitter *e) {
    uint32_t index = 0;
    mpca_check(mpca_world_add_emitter(w, e, &index), "mpca_world_add_emitter");
}

/* The nozzle an emitter pours from, a grey bar over its box. */
static void draw_nozzle(const mpca_emitter *e, int below) {
    grey(0.4f);
    float y = below ? (float)e->min[1] - 1.0f : (float)e->max[1];
    glRectf((float)e->min[0] - 1.0f, y, (float)e->max[0] + 1.0f, y + 1.0f);
}

/* ---- smoke ---------------------------------------------------------------------- */

#define SMOKE_REFERENCE 64
#define SMOKE_LIFETIME 240

/* The library's smoke preset, with a faint breeze. Its figures are those
 * of docs/model.md (Units):
 * cells of 2 cm, 60 steps a second, so a buoyancy of 0.5 m/s^2 is 0.0069
 * cells per step^2 up, and a drag of 0.033 a step towards the air (M5.1b)
 * brings it to its terminal rise of 0.0069 / 0.033 = 0.21 cells a step
 * (0.25 m/s) in about half a second, so it never runs at the speed cap as
 * the paper's smoke does; the preset's turbulence (M5.1c: eddies of 16
 * cells, up to 0.5 cells a step, a new flow every 50 steps) makes the
 * column waver and break up; the air drifts right at 0.04 cells a step (5
 * cm/s), which leans the plume as a draught in a room does. Speed-limited collisions (M5.2b) spread the
 * plume without speeding it up. It lives 4 s (lifetimes on); ids and
 * ages let the renderer follow each puff and fade it. Open at the top and
 * the sides, with the ground a wall. */
static void smoke_desc(mpca_desc *d, uint32_t size) {
    mpca_check(mpca_desc_preset(d, MPCA_PRESET_SMOKE, 2, size, size, 0), "mpca_desc_preset");
    /* A light breeze: the scene's, not the preset's. */
    d->drag_wind[0] = 0.04f;
}

/* The vent: 8 cells wide in the ground, puffing upwards. */
static mpca_emitter smoke_vent(const scene_opts *o) {
    const mpca_emitter e = {
        .struct_size = sizeof e,
        .min = {28, 0, 0},
        .max = {36, 2, 1},
        .rate = 3.0f,
        .velocity = {0.0f, 0.6f, 0.0f},
        .spread = 0.25f,
        .mass = 1.0f,
        .lifetime = SMOKE_LIFETIME,
    };
    return scaled_emitter(e, o, SMOKE_REFERENCE);
}

static mpca_world *build_smoke(const scene_opts *o) {
    mpca_desc d;
    smoke_desc(&d, o->size);
    d.emitter_capacity = 1;
    d.seed = o->seed;
    mpca_world *w = world_create(&d);
    const mpca_emitter e = smoke_vent(o);
    add_emitter(w, &e);
    return w;
}

static void draw_smoke(const scene_opts *o, float blend, const view *v) {
    view2d_begin(o->size, o->size);
    const float cell = (float)v->cell_px;
    const smoke_look look = {
        .blend = blend,
        .lifetime = (float)SMOKE_LIFETIME,
        .fade_in = 6.0f,
        .start_px = 2.5f * cell,
        .end_px = 10.0f * cell,
        .peak = 0.5f,
        .spin = 0.5f,
        .young = {0.86f, 0.84f, 0.80f},
        .old = {0.50f, 0.52f, 0.56f},
    };
    draw_puffs_2d(&look);
    const mpca_emitter e = smoke_vent(o);
    draw_nozzle(&e, 0);
}

/* ---- water ---------------------------------------------------------------------- */

#define WATER_REFERENCE 96
#define WATER_OBSTACLES 2

/* The library's water preset (docs/model.md, Presets): a gentler gravity
 * than docs/model.md's 0.0136, contacts (M5.7) and resting contact
 * (M5.7b), and a high restitution for the water and every surface: a
 * particle moves sideways only after a collision gives it sideways speed,
 * so water with a low one heaps where it lands, while at 0.95 it keeps
 * jostling, spreads into a level pool and then rests. */
static void water_desc(mpca_desc *d, uint32_t size) {
    mpca_check(mpca_desc_preset(d, MPCA_PRESET_WATER, 2, size, size, 0), "mpca_desc_preset");
}

/* The tap, over the middle of the pool, pouring straight down: water
 * thrown to one side stands there as a wall (see water_desc), water that
 * lands in the middle splashes both ways and levels. */
static mpca_emitter water_tap(const scene_opts *o) {
    const mpca_emitter e = {
        .struct_size = sizeof e,
        .min = {40, 84, 0},
        .max = {48, 88, 1},
        .rate = 2.0f,
        .velocity = {0.0f, -0.5f, 0.0f},
        .spread = 0.05f,
        .mass = 1.0f,
        .lifetime = 0,
    };
    return scaled_emitter(e, o, WATER_REFERENCE);
}

/* The tap closes after this share of the run, so the pool settles. */
#define WATER_POUR_SHARE 0.45

/* Two stones on the pool's floor, which the water covers. */
static void water_obstacles(const scene_opts *o, mpca_shape out[WATER_OBSTACLES]) {
    const float stones[WATER_OBSTACLES][3] = {{22.0f, 0.0f, 8.0f}, {70.0f, 0.0f, 11.0f}};
    memset(out, 0, WATER_OBSTACLES * sizeof *out);
    for (int i = 0; i < WATER_OBSTACLES; i++) {
        out[i].struct_size = sizeof *out;
        out[i].kind = MPCA_SHAPE_KIND_DISC;
        out[i].a[0] = at_size(stones[i][0], o, WATER_REFERENCE);
        out[i].a[1] = at_size(stones[i][1], o, WATER_REFERENCE);
        out[i].radius = at_size(stones[i][2], o, WATER_REFERENCE);
    }
}

static mpca_world *build_water(const scene_opts *o) {
    mpca_desc d;
    water_desc(&d, o->size);
    mpca_shape shapes[WATER_OBSTACLES];
    water_obstacles(o, shapes);
    d.obstacles = 1;
    d.surface_capacity = 0;
    for (int i = 0; i < WATER_OBSTACLES; i++) {
        uint32_t entries = 0;
        mpca_check(mpca_desc_surface_entries(&d, &shapes[i], &entries), "mpca_desc_surface_entries");
        d.surface_capacity += entries;
    }
    d.emitter_capacity = 1;
    d.seed = o->seed;
    mpca_world *w = world_create(&d);
    for (int i = 0; i < WATER_OBSTACLES; i++) {
        mpca_check(mpca_world_add_shape(w, &shapes[i], d.wall_restitution), "mpca_world_add_shape");
    }
    const mpca_emitter e = water_tap(o);
    add_emitter(w, &e);
    return w;
}

static void water_before_step(mpca_world *w, const scene_opts *o, uint64_t t) {
    if (t == (uint64_t)(WATER_POUR_SHARE * (double)o->steps)) {
        mpca_check(mpca_world_set_emitter_rate(w, 0, 0.0f), "mpca_world_set_emitter_rate");
        printf("tap: closed step=%llu\n", (unsigned long long)t);
    }
}

static void draw_water(const scene_opts *o, float blend, const view *v) {
    view2d_begin(o->size, o->size);
    const liquid_look look = {
        .blend = blend,
        .walls = 15,
        .radius_cells = 2.5f,
        .depth_cells = 24.0f,
        .foam_travel = 0.2f,
        .shallow = {0.30f, 0.72f, 0.95f},
        .deep = {0.03f, 0.16f, 0.45f},
    };
    draw_liquid_2d(&look, v);
    /* Over the liquid: its splats reach a little into the stones. */
    mpca_shape shapes[WATER_OBSTACLES];
    water_obstacles(o, shapes);
    for (int i = 0; i < WATER_OBSTACLES; i++) draw_shape_2d(&shapes[i], 0.35f);
    const mpca_emitter e = water_tap(o);
    draw_nozzle(&e, 0);
}

/* ---- sand ----------------------------------------------------------------------- */

#define SAND_REFERENCE 96
#define SAND_MATERIALS 4
/* Steps between changes of the spout's material. */
#define SAND_BAND_STEPS 250

/* The library's sand preset (docs/model.md, Presets): docs/model.md's
 * scale (cells of 5 cm, 120 steps a second), gravity 0.0136, contacts
 * (M5.7), resting contact (M5.7b) and a low restitution, so grains that
 * land stay where they land and the pile rests; walls as dull as the
 * grains. Tags carry each grain's material (M6b). */
static void sand_desc(mpca_desc *d, uint32_t size) {
    mpca_check(mpca_desc_preset(d, MPCA_PRESET_SAND, 2, size, size, 0), "mpca_desc_preset");
}

/* The spout: a slot a quarter of the floor wide, spraying a little. A
 * grain that lands on another stays on it (no rule makes it roll off), so a narrow stream builds a spire as tall as the spout;
 * from a wide slot the grains land side by side and the pile rises as a
 * mound, its flanks fed by the grains that land with sideways speed. */
static mpca_emitter sand_spout(const scene_opts *o) {
    const mpca_emitter e = {
        .struct_size = sizeof e,
        .min = {36, 56, 0},
        .max = {60, 58, 1},
        .rate = 1.0f,
        .velocity = {0.0f, -0.1f, 0.0f},
        .spread = 0.3f,
        .mass = 1.0f,
        .lifetime = 0,
    };
    return scaled_emitter(e, o, SAND_REFERENCE);
}

static mpca_world *build_sand(const scene_opts *o) {
    mpca_desc d;
    sand_desc(&d, o->size);
    d.emitter_capacity = 1;
    d.seed = o->seed;
    mpca_world *w = world_create(&d);
    const mpca_emitter e = sand_spout(o);
    add_emitter(w, &e);
    return w;
}

static void sand_before_step(mpca_world *w, const scene_opts *o, uint64_t t) {
    (void)o;
    if (t % SAND_BAND_STEPS == 0) {
        uint32_t tag = (uint32_t)(t / SAND_BAND_STEPS % SAND_MATERIALS);
        mpca_check(mpca_world_set_emitter_tag(w, 0, tag), "mpca_world_set_emitter_tag");
    }
}

/* Pale sand, ochre, rust and a grey-green basalt: tags 0 to 3. */
static const float SAND_COLOURS[SAND_MATERIALS][3] = {
    {0.90f, 0.78f, 0.52f},
    {0.78f, 0.56f, 0.28f},
    {0.66f, 0.34f, 0.22f},
    {0.45f, 0.48f, 0.40f},
};

static void draw_sand(const scene_opts *o, float blend, const view *v) {
    view2d_begin(o->size, o->size);
    const grain_look look = {
        .blend = blend,
        .grain_px = (float)v->cell_px,
        .jitter = 0.18f,
        .scatter = 0.12f,
        .colours = SAND_COLOURS,
        .materials = SAND_MATERIALS,
    };
    draw_grains_2d(&look);
    const mpca_emitter e = sand_spout(o);
    draw_nozzle(&e, 0);
}

/* ---- the effects ------------------------------------------------------------------- */

static const effect EFFECTS[] = {
    {
        .s = {
            .name = "looks-smoke",
            .title = "smoke drawn as a game would",
            .dim = 2,
            .defaults = {.size = SMOKE_REFERENCE, .steps = 480, .seed = 28, .every = 60, .tiles = 6, .px = 512},
            .about = "buoyant smoke from a vent, drawn as soft sprites that grow and fade with age, between steps",
        },
        .reference = SMOKE_REFERENCE,
        .build = build_smoke,
        .before_step = NULL,
        .draw = draw_smoke,
        .gif_span = 60,
        .gif_delay_cs = 4,
        .gif_last_delay_cs = 4,
    },
    {
        .s = {
            .name = "looks-water",
            .title = "water drawn as a game would",
            .dim = 2,
            .defaults = {.size = WATER_REFERENCE, .steps = 1500, .seed = 28, .every = 100, .tiles = 6, .px = 480},
            .about = "water poured into a pool with stones, drawn as a shaded surface from splatted particles",
        },
        .reference = WATER_REFERENCE,
        .build = build_water,
        .before_step = water_before_step,
        .draw = draw_water,
        .gif_span = 0,
        .gif_delay_cs = 8,
        .gif_last_delay_cs = 100,
    },
    {
        .s = {
            .name = "looks-sand",
            .title = "sand drawn as a game would",
            .dim = 2,
            .defaults = {.size = SAND_REFERENCE, .steps = 1200, .seed = 28, .every = 100, .tiles = 6, .px = 480},
            .about = "sand poured in bands of four materials into a mound, drawn as grains coloured by tag",
        },
        .reference = SAND_REFERENCE,
        .build = build_sand,
        .before_step = sand_before_step,
        .draw = draw_sand,
        .gif_span = 0,
        .gif_delay_cs = 8,
        .gif_last_delay_cs = 100,
    },
};

/* ---- the run ---------------------------------------------------------------------- */

/* 2D views in whole cells, as scene.c makes them. */
static view make_view(uint32_t size, uint32_t px) {
    view v = {0, 0, px / size ? px / size : 1, 0};
    v.point_px = v.cell_px;
    v.width = v.height = v.cell_px * size;
    return v;
}

/* The step whose particles are in the vertex buffer, plus 1; 0: none. */
static uint64_t uploaded;

/* Draws the world `blend` of the way from step t - 1 to step t into `rgba`;
 * step t's particles are uploaded the first time it is drawn. */
static void render(const effect *e, const scene_opts *o, canvas *c, const follower *f, uint64_t t, float blend,
                   uint8_t *rgba, const view *v) {
    canvas_begin(c, rgba, v);
    if (uploaded != t + 1) {
        upload_moving_2d(f->particles, f->count);
        uploaded = t + 1;
    }
    e->draw(o, blend, v);
    canvas_end(c, e->s.name);
}

/* "t=41" at a whole step, "t=41.50" half way to step 42. */
static void time_label(char *out, size_t len, double t) {
    double whole = floor(t);
    if (t - whole < 0.005) {
        snprintf(out, len, "t=%.0f", whole);
    } else {
        snprintf(out, len, "t=%.2f", t);
    }
}

/* The share of the particles that changed cell in the last step: a pool
 * or a pile at rest changes few. */
static double changed_share(const follower *f) {
    size_t changed = 0;
    for (size_t i = 0; i < f->count; i++) {
        const moving *p = &f->particles[i];
        changed += p->from[0] != p->to[0] || p->from[1] != p->to[1];
    }
    return f->count ? (double)changed / (double)f->count : 0.0;
}

int main(int argc, char **argv) {
    const effect *e = NULL;
    for (size_t i = 0; i < sizeof EFFECTS / sizeof EFFECTS[0]; i++) {
        if (strcmp(EFFECTS[i].s.name, "looks-" LOOK) == 0) e = &EFFECTS[i];
    }
    if (!e) {
        fprintf(stderr, "looks: no effect named %s\n", LOOK);
        return 1;
    }
    scene_opts o;
    int status = options_parse(&e->s, &o, argc, argv);
    if (status >= 0) return status;
    if (o.density) {
        fprintf(stderr, "%s: --density is not drawn here: the effect is drawn from the particles\n", e->s.name);
        return 2;
    }
    scene_make_dirs(o.out);

    mpca_world *w = e->build(&o);
    mpca_stats stats = {.struct_size = sizeof stats};
    mpca_check(mpca_world_stats(w, &stats), "mpca_world_stats");
    printf("%s (%s): %ux%u cells, %llu particles, %llu steps, seed %llu, %.2f bytes/cell\n", o.name, e->s.title,
           (unsigned)o.size, (unsigned)o.size, (unsigned long long)stats.particles, (unsigned long long)o.steps,
           (unsigned long long)o.seed, stats.bytes_per_cell);

    view fv = make_view(o.size, o.px);
    view tv = make_view(o.size, (fv.cell_px + 1) / 2 * o.size);
    canvas *c = canvas_create();
    uint8_t *frame_gl = xrealloc(NULL, (size_t)fv.width * fv.height * 4);
    uint8_t *tile_gl = xrealloc(NULL, (size_t)tv.width * tv.height * 4);
    uint32_t tiles = o.tiles;
    if ((uint64_t)tiles > o.steps + 1) tiles = (uint32_t)(o.steps + 1);
    /* The GIF: `gif_frames` frames spread evenly from `gif_start` to the
     * end, both included. */
    uint64_t gif_start = e->gif_span && e->gif_span < o.steps ? o.steps - e->gif_span : 0;
    uint64_t gif_frames = o.gif;
    if (o.steps == gif_start && gif_frames > 1) gif_frames = 1;
    image sheet = image_new(tiles * tv.width + (tiles + 1) * SHEET_GAP, tv.height + 3 * SHEET_GAP + LABEL_HEIGHT);
    image frame = image_new(fv.width, fv.height);
    image gif_frame = image_new(tv.width, tv.height + 2 * GIF_GAP + LABEL_HEIGHT);
    gif_anim *gif = gif_frames ? gif_new(gif_frame.width, gif_frame.height) : NULL;
    size_t path_len = strlen(o.out) + strlen(o.name) + 48;
    char *path = xrealloc(NULL, path_len);

    follower f;
    follow_start(&f, w);

    double sim_s = 0.0, follow_s = 0.0, draw_s = 0.0, png_s = 0.0;
    uint64_t images = 0, pngs = 1, frames = 0, next_tile = 0, next_gif = 0;
    for (uint64_t t = 0;; t++) {
        char label[32];
        /* The GIF's frames that fall in (t - 1, t]: step t's motion. */
        while (next_gif < gif_frames) {
            double at = gif_frames == 1 ? (double)o.steps
                                        : (double)gif_start + (double)next_gif * (double)(o.steps - gif_start) /
                                                                  (double)(gif_frames - 1);
            if (at > (double)t + 1e-9) break;
            double t0 = now_s();
            render(e, &o, c, &f, t, t == 0 ? 1.0f : (float)(at - (double)(t - 1)), tile_gl, &tv);
            draw_s += now_s() - t0;
            images++;
            time_label(label, sizeof label, at);
            scene_gif_frame(gif, &gif_frame, tile_gl, &tv, label);
            next_gif++;
        }
        time_label(label, sizeof label, (double)t);
        if (o.every && (t % o.every == 0 || t == o.steps)) {
            double t0 = now_s();
            render(e, &o, c, &f, t, 1.0f, frame_gl, &fv);
            double t1 = now_s();
            scene_frame_png(&frame, frame_gl, &fv, &o, 4, frames, path, path_len);
            draw_s += t1 - t0;
            png_s += now_s() - t1;
            images++;
            pngs++;
            frames++;
            printf("frame: %s step=%llu particles=%zu size=%ux%u\n", path, (unsigned long long)t, f.count,
                   (unsigned)fv.width, (unsigned)fv.height);
        }
        if (next_tile < tiles && scene_spread(next_tile, tiles, o.steps) == t) {
            double t0 = now_s();
            render(e, &o, c, &f, t, 1.0f, tile_gl, &tv);
            draw_s += now_s() - t0;
            images++;
            scene_tile(&sheet, tile_gl, &tv, next_tile, label);
            printf("tile: step=%llu particles=%zu size=%ux%u\n", (unsigned long long)t, f.count, (unsigned)tv.width,
                   (unsigned)tv.height);
            next_tile++;
        }
        fflush(stdout);
        if (t >= o.steps) break;
        /* One step at a time: the renderer needs every step's motion. */
        double t0 = now_s();
        if (e->before_step) e->before_step(w, &o, t);
        scene_step(w, 1, &o);
        double t1 = now_s();
        follow_step(&f, w);
        sim_s += t1 - t0;
        follow_s += now_s() - t1;
    }
    png_s += scene_finish(&o, &sheet, (unsigned)tiles, gif, &gif_frame, e->gif_delay_cs, e->gif_last_delay_cs, w,
                          &stats);
    printf("look: particles=%zu mean_speed=%.3f changed_cell=%.4f followed=%llu appeared=%llu\n", f.count,
           f.mean_speed, changed_share(&f), (unsigned long long)f.matched, (unsigned long long)f.appeared);
    double per_step = o.steps ? 1e3 * sim_s / (double)o.steps : 0.0;
    printf("sim: %.3f ms/step (%llu steps in %.1f ms), follow: %.3f ms/step (export, sort, match), "
           "render: %.2f ms/frame (%llu frames, tiles and GIF frames), png: %.2f ms/file (%llu files)\n",
           per_step, (unsigned long long)o.steps, 1e3 * sim_s, o.steps ? 1e3 * follow_s / (double)o.steps : 0.0,
           images ? 1e3 * draw_s / (double)images : 0.0, (unsigned long long)images, 1e3 * png_s / (double)pngs,
           (unsigned long long)pngs);

    free(path);
    image_free(&frame);
    image_free(&sheet);
    image_free(&gif_frame);
    free(frame_gl);
    free(tile_gl);
    follow_free(&f);
    canvas_destroy(c);
    mpca_check(mpca_world_destroy(w), "mpca_world_destroy");
    return 0;
}
