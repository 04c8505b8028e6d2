/*
 * Smoke drawn the way a game draws it (M6b; issue 27): the automaton moves
 * a particle a whole cell at a time, which looks jerky once a cell is many
 * pixels wide, so the renderer follows each particle by its id and draws
 * it part of the way between its last two cells, several frames a step;
 * and it fades each puff by its age, so smoke thins out before its
 * lifetime ends and the library removes it.
 *
 * The world: buoyant smoke in a breeze, with the figures docs/model.md
 * ("Units") works out for smoke at cells of 2 cm and 60 steps a second:
 * buoyancy 0.0069 cells per step^2, a drag rate of 0.033 towards a wind of
 * 0.25 cells per step (0.3 m/s), a lifetime of 240 steps (4 s). Two
 * particles a step rise from a vent in the ground; the world is periodic
 * across, so the smoke the breeze carries out on the right comes back on
 * the left (a particle that wraps is not drawn sliding across the whole
 * world), and open at the top. Ids and ages are the world's planes
 * (mpca_desc.identity); mpca_world_export_particles writes positions, ids
 * and ages in one pass after every step.
 *
 * What the renderer does each step, as an engine would:
 *   1. export the particles (cell centres, ids, ages), in cell order;
 *   2. sort them by id and merge with the last step's, also by id: a
 *      particle found in both slides from its old cell to its new one; a
 *      new one (its id above every id seen before) appears where it is;
 *      one that is gone (left through the top, or its lifetime ended) is
 *      simply not drawn;
 *   3. upload both positions and the ages once, into a vertex buffer;
 *   4. draw SUBFRAMES frames, the shader blending the two positions.
 * Along the way it checks what M6b promises and exits 1 if one fails:
 * ids unique and never 0, new ids above every earlier one, a particle
 * seen twice one step older and at most a cell away per axis (or wrapped).
 *
 * Frames (--every), the contact sheet and the labels are at whole steps,
 * as in the other scenes; the animated GIF is the run's last --gif frames
 * one after the other, SUBFRAMES of them a step, so it shows the smooth
 * motion (t=41.25 is a quarter of the way from step 41 to step 42).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gif.h"
#include "image.h"
#include "scene.h"

/* The size the vent's place is given for; cells are in steps and cells
 * per step, so the smoke's motion is the same at any --size. */
#define REFERENCE_SIZE 48
#define LIFETIME 240
#define SUBFRAMES 4
/* A puff is this many cells wide, so the puffs of neighbouring particles
 * overlap into smoke. */
#define PUFF_CELLS 3.0f
#define PUFF_PEAK 0.45f

/* The GIF's timing: a frame is a quarter step, shown 4 hundredths of a
 * second: 6.25 steps a second. */
#define GIF_DELAY_CS 4
#define GIF_LAST_DELAY_CS 4

/* ---- the world -------------------------------------------------------------- */

static void vent(uint32_t size, uint32_t min[2], uint32_t max[2]) {
    min[0] = scale_cells(8, size, REFERENCE_SIZE);
    max[0] = scale_cells(16, size, REFERENCE_SIZE);
    min[1] = 0;
    max[1] = 1;
    if (max[0] <= min[0]) max[0] = min[0] + 1;
}

static mpca_world *build(const scene_opts *o) {
    mpca_desc d;
    mpca_check(mpca_desc_defaults(&d, 2, o->size, o->size, 0), "mpca_desc_defaults");
    d.boundary[0][0] = d.boundary[0][1] = MPCA_BOUNDARY_PERIODIC;
    d.boundary[1][0] = MPCA_BOUNDARY_WALL; /* the ground */
    d.boundary[1][1] = MPCA_BOUNDARY_OPEN;
    d.collisions = MPCA_COLLISIONS_SPEED_LIMITED;
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = 0.0069f; /* buoyancy: up */
    d.drag_rate = 0.033f;
    d.drag_wind[0] = 0.25f;
    d.lifetimes = 1;
    d.identity = MPCA_IDENTITY_IDS | MPCA_IDENTITY_AGES;
    d.emitter_capacity = 1;
    d.seed = o->seed;
    mpca_world *w = world_create(&d);
    uint32_t min[2], max[2];
    vent(o->size, min, max);
    const mpca_emitter e = {
        .struct_size = sizeof e,
        .min = {min[0], min[1], 0},
        .max = {max[0], max[1], 1},
        .rate = 2.0f,
        .velocity = {0.0f, 0.4f, 0.0f},
        .spread = 0.2f,
        .mass = 1.0f,
        .lifetime = LIFETIME,
    };
    uint32_t index = 0;
    mpca_check(mpca_world_add_emitter(w, &e, &index), "mpca_world_add_emitter");
    return w;
}

/* ---- following particles by id ------------------------------------------------ */

typedef struct particle {
    uint32_t id, age;
    float x, y;
} particle;

/* What the renderer keeps from step to step. */
typedef struct tracker {
    uint32_t size;   /* cells per axis */
    int wrap_x;      /* x is periodic */
    size_t capacity; /* of every array below */
    /* The export's columns, in cell order. */
    float *positions;
    uint32_t *ids, *ages;
    /* The particles after the last step and before it, sorted by id. */
    particle *now, *before;
    size_t count, before_count;
    /* Per particle of `now`: where it was and where it is, for the GPU. */
    float *from, *to;
    uint32_t *now_ages;
    uint32_t first_new;       /* every id below this was seen before */
    uint64_t moved, wrapped, appeared, gone; /* totals over the run */
} tracker;

static int by_id(const void *a, const void *b) {
    uint32_t x = ((const particle *)a)->id, y = ((const particle *)b)->id;
    return x < y ? -1 : x > y;
}

static void fail(const char *what, const particle *p) {
    fprintf(stderr, "smoke-ids: %s: id %u, age %u, at (%.1f, %.1f)\n", what, (unsigned)p->id, (unsigned)p->age,
            (double)p->x, (double)p->y);
    exit(1);
}

static void grow(tracker *k, size_t n) {
    if (n <= k->capacity) return;
    k->capacity = n + n / 2 + 64;
    k->positions = xrealloc(k->positions, 3 * k->capacity * sizeof *k->positions);
    k->ids = xrealloc(k->ids, k->capacity * sizeof *k->ids);
    k->ages = xrealloc(k->ages, k->capacity * sizeof *k->ages);
    k->now = xrealloc(k->now, k->capacity * sizeof *k->now);
    k->before = xrealloc(k->before, k->capacity * sizeof *k->before);
    k->from = xrealloc(k->from, 2 * k->capacity * sizeof *k->from);
    k->to = xrealloc(k->to, 2 * k->capacity * sizeof *k->to);
    k->now_ages = xrealloc(k->now_ages, k->capacity * sizeof *k->now_ages);
}

/* The step's motion: exports the world and matches it to the last step's
 * particles by id. */
static void track(tracker *k, const mpca_world *w) {
    mpca_particle_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.struct_size = sizeof cols;
    cols.reserved = 0;
    size_t n = 0;
    /* Every column NULL and no room: the count alone. */
    mpca_check(mpca_world_export_particles(w, &cols, 0, &n), "mpca_world_export_particles (count)");
    grow(k, n);
    cols.positions = k->positions;
    cols.ids = k->ids;
    cols.ages = k->ages;
    size_t got = 0;
    mpca_check(mpca_world_export_particles(w, &cols, k->capacity, &got), "mpca_world_export_particles");

    /* The last step's `now` becomes `before`. */
    particle *swap = k->before;
    k->before = k->now;
    k->now = swap;
    k->before_count = k->count;
    k->count = got;
    for (size_t i = 0; i < got; i++) {
        particle p = {k->ids[i], k->ages[i], k->positions[3 * i], k->positions[3 * i + 1]};
        k->now[i] = p;
    }
    /* The export is in cell order, which says nothing of the ids; sorted,
     * both steps can be matched in one merge. */
    qsort(k->now, got, sizeof *k->now, by_id);

    size_t j = 0, matched = 0;
    uint32_t first_new = k->first_new;
    for (size_t i = 0; i < got; i++) {
        const particle *p = &k->now[i];
        if (p->id == 0) fail("id 0 in a world with ids", p);
        if (i > 0 && p->id == k->now[i - 1].id) fail("two particles with one id", p);
        while (j < k->before_count && k->before[j].id < p->id) j++;
        float *from = k->from + 2 * i, *to = k->to + 2 * i;
        to[0] = from[0] = p->x;
        to[1] = from[1] = p->y;
        k->now_ages[i] = p->age;
        if (j < k->before_count && k->before[j].id == p->id) {
            const particle *q = &k->before[j];
            matched++;
            if (p->age != q->age + 1) fail("seen again, but not one step older", p);
            float dx = p->x - q->x, dy = p->y - q->y;
            if (dx < 0.0f) dx = -dx;
            if (dy < 0.0f) dy = -dy;
            if (dy > 1.0f) fail("moved more than a cell up or down in a step", p);
            if (dx <= 1.0f) {
                from[0] = q->x;
                from[1] = q->y;
                k->moved++;
            } else if (k->wrap_x && dx == (float)(k->size - 1)) {
                /* Across the periodic edge: sliding from the old cell to
                 * the new one would sweep the puff through the whole
                 * world, so it jumps instead. */
                k->wrapped++;
            } else {
                fail("moved more than a cell across in a step", p);
            }
        } else {
            /* Ids are given in increasing order and never again. */
            if (p->id < k->first_new) fail("an unknown particle with an old id", p);
            /* Emitted in this step, which it took part in. */
            if (p->age != 1) fail("a new particle whose age is not 1", p);
            k->appeared++;
        }
        if (p->age > LIFETIME) fail("older than its lifetime", p);
        if (p->id >= first_new) first_new = p->id + 1;
    }
    k->first_new = first_new;
    k->gone += k->before_count - matched;
}

static void tracker_free(tracker *k) {
    free(k->positions);
    free(k->ids);
    free(k->ages);
    free(k->now);
    free(k->before);
    free(k->from);
    free(k->to);
    free(k->now_ages);
}

/* ---- drawing ----------------------------------------------------------------- */

/* 2D views in whole cells, as scene.c makes them. */
static view make_view(uint32_t size, uint32_t px) {
    view v = {0, 0, px / size ? px / size : 1, 0};
    v.point_px = v.cell_px;
    v.width = v.height = v.cell_px * size;
    return v;
}

typedef struct renderer {
    canvas *c;
    const mpca_desc *desc;
    uint32_t size;
    uint64_t uploaded; /* the step whose motion is in the vertex buffer, +1; 0: none */
} renderer;

/* Draws the world `blend` of the way from step `step - 1` to `step` into
 * `rgba`; the motion is uploaded the first time a step is drawn. */
static void render(renderer *r, const tracker *k, uint64_t step, float blend, uint8_t *rgba, const view *v) {
    canvas_begin(r->c, rgba, v);
    view2d_begin(r->size, r->size);
    if (r->uploaded != step + 1) {
        upload_motion_2d(k->from, k->to, k->now_ages, k->count);
        r->uploaded = step + 1;
    }
    draw_motion_2d(blend, (float)LIFETIME, PUFF_CELLS * (float)v->cell_px, PUFF_PEAK);
    /* The vent, over the smoke it makes. */
    uint32_t min[2], max[2];
    vent(r->size, min, max);
    grey(0.4f);
    glRectf((float)min[0], (float)min[1], (float)max[0], (float)max[1]);
    draw_walls_2d(r->desc, v);
    canvas_end(r->c, "smoke-ids");
}

/* "t=41" at a whole step, "t=41.25" a quarter of the way to step 42. */
static void time_label(char *out, size_t len, uint64_t step, uint32_t sub) {
    if (sub == 0) {
        snprintf(out, len, "t=%llu", (unsigned long long)step);
    } else {
        snprintf(out, len, "t=%llu.%02u", (unsigned long long)step, (unsigned)(100 * sub / SUBFRAMES));
    }
}

/* ---- the run ------------------------------------------------------------------ */

int main(int argc, char **argv) {
    const scene s = {
        .name = "smoke-ids",
        .title = "smoke tracked by id (M6b)",
        .dim = 2,
        .defaults = {.size = REFERENCE_SIZE, .steps = 360, .seed = 27, .every = 60, .tiles = 6, .px = 480},
        .about = "buoyant smoke in a breeze, drawn between steps by following each particle's id and faded by its age",
        .build = build,
        .draw = NULL,
    };
    scene_opts o;
    int status = options_parse(&s, &o, argc, argv);
    if (status >= 0) return status;
    if (o.density) {
        /* The haze is the density at a whole step; the puffs are between
         * steps, and they are the smoke's density already. */
        fprintf(stderr, "smoke-ids: --density is not drawn here: the puffs are the smoke\n");
        return 2;
    }
    scene_make_dirs(o.out);

    mpca_world *w = build(&o);
    mpca_desc desc;
    desc.struct_size = sizeof desc;
    mpca_check(mpca_world_desc(w, &desc), "mpca_world_desc");
    mpca_stats stats = {.struct_size = sizeof stats};
    mpca_check(mpca_world_stats(w, &stats), "mpca_world_stats");
    printf("%s (%s): %ux%u cells, %llu particles, %llu steps, seed %llu, %.2f bytes/cell\n", o.name, s.title,
           (unsigned)o.size, (unsigned)o.size, (unsigned long long)stats.particles, (unsigned long long)o.steps,
           (unsigned long long)o.seed, stats.bytes_per_cell);

    view fv = make_view(o.size, o.px);
    view tv = make_view(o.size, (fv.cell_px + 1) / 2 * o.size);
    renderer r = {canvas_create(), &desc, o.size, 0};
    uint8_t *frame_gl = xrealloc(NULL, (size_t)fv.width * fv.height * 4);
    uint8_t *tile_gl = xrealloc(NULL, (size_t)tv.width * tv.height * 4);
    uint32_t tiles = o.tiles;
    if ((uint64_t)tiles > o.steps + 1) tiles = (uint32_t)(o.steps + 1);
    /* The GIF: the last frames of the run, SUBFRAMES a step. */
    uint64_t subframes = o.steps * SUBFRAMES;
    uint64_t gif_frames = o.gif < subframes ? o.gif : subframes;
    image sheet = image_new(tiles * tv.width + (tiles + 1) * SHEET_GAP, tv.height + 3 * SHEET_GAP + LABEL_HEIGHT);
    image frame = image_new(fv.width, fv.height);
    image gif_frame = image_new(tv.width, tv.height + 2 * GIF_GAP + LABEL_HEIGHT);
    gif_anim *gif = gif_frames ? gif_new(gif_frame.width, gif_frame.height) : NULL;
    size_t path_len = strlen(o.out) + strlen(o.name) + 48;
    char *path = xrealloc(NULL, path_len);

    tracker k;
    memset(&k, 0, sizeof k);
    k.size = o.size;
    k.wrap_x = desc.boundary[0][0] == MPCA_BOUNDARY_PERIODIC;
    k.first_new = 1;
    track(&k, w); /* step 0: nothing emitted yet */

    double sim_s = 0.0, track_s = 0.0, draw_s = 0.0, png_s = 0.0;
    uint64_t images = 0, pngs = 1, frames = 0, next_tile = 0;
    for (uint64_t t = 0;; t++) {
        char label[32];
        /* Between step t - 1 and t: the sub-frames the GIF shows. */
        for (uint32_t sub = 1; t > 0 && sub < SUBFRAMES; sub++) {
            if ((t - 1) * SUBFRAMES + sub + gif_frames <= subframes) continue;
            double t0 = now_s();
            render(&r, &k, t, (float)sub / SUBFRAMES, tile_gl, &tv);
            draw_s += now_s() - t0;
            images++;
            time_label(label, sizeof label, t - 1, sub);
            image_clear(&gif_frame);
            image_blit_gl(&gif_frame, tile_gl, tv.width, tv.height, 0, 0);
            image_label(&gif_frame, GIF_GAP, tv.height + GIF_GAP, label);
            gif_add(gif, &gif_frame);
        }
        /* At step t itself: a frame, a tile, a GIF frame. */
        time_label(label, sizeof label, t, 0);
        if (o.every && (t % o.every == 0 || t == o.steps)) {
            double t0 = now_s();
            render(&r, &k, t, 1.0f, frame_gl, &fv);
            double t1 = now_s();
            scene_frame_png(&frame, frame_gl, &fv, &o, 4, frames, path, path_len);
            draw_s += t1 - t0;
            png_s += now_s() - t1;
            images++;
            pngs++;
            frames++;
            printf("frame: %s step=%llu particles=%zu size=%ux%u puff_px=%.1f\n", path, (unsigned long long)t,
                   k.count, (unsigned)fv.width, (unsigned)fv.height, (double)(PUFF_CELLS * (float)fv.cell_px));
        }
        int tile_now = next_tile < tiles && scene_spread(next_tile, tiles, o.steps) == t;
        int gif_now = t * SUBFRAMES + gif_frames > subframes;
        if (tile_now || gif_now) {
            double t0 = now_s();
            render(&r, &k, t, 1.0f, tile_gl, &tv);
            draw_s += now_s() - t0;
            images++;
            if (tile_now) {
                scene_tile(&sheet, tile_gl, &tv, next_tile, label);
                printf("tile: step=%llu particles=%zu size=%ux%u\n", (unsigned long long)t, k.count,
                       (unsigned)tv.width, (unsigned)tv.height);
                next_tile++;
            }
            if (gif_now) {
                scene_gif_frame(gif, &gif_frame, tile_gl, &tv, label);
            }
        }
        fflush(stdout);
        if (t >= o.steps) break;
        /* One step at a time: the renderer needs every step's motion. */
        double t0 = now_s();
        scene_step(w, 1, &o);
        double t1 = now_s();
        track(&k, w);
        sim_s += t1 - t0;
        track_s += now_s() - t1;
    }
    png_s += scene_finish(&o, &sheet, (unsigned)tiles, gif, &gif_frame, GIF_DELAY_CS, GIF_LAST_DELAY_CS, w, &stats);
    printf("ids: moved=%llu wrapped=%llu appeared=%llu gone=%llu last_id=%u\n", (unsigned long long)k.moved,
           (unsigned long long)k.wrapped, (unsigned long long)k.appeared, (unsigned long long)k.gone,
           (unsigned)(k.first_new - 1));
    double per_step = o.steps ? 1e3 * sim_s / (double)o.steps : 0.0;
    printf("sim: %.3f ms/step (%llu steps in %.1f ms), track: %.3f ms/step (export, sort, match), "
           "render: %.2f ms/frame (%llu frames, tiles and sub-frames), png: %.2f ms/file (%llu files)\n",
           per_step, (unsigned long long)o.steps, 1e3 * sim_s, o.steps ? 1e3 * track_s / (double)o.steps : 0.0,
           images ? 1e3 * draw_s / (double)images : 0.0, (unsigned long long)images, 1e3 * png_s / (double)pngs,
           (unsigned long long)pngs);

    free(path);
    image_free(&frame);
    image_free(&sheet);
    image_free(&gif_frame);
    free(frame_gl);
    free(tile_gl);
    tracker_free(&k);
    canvas_destroy(r.c);
    mpca_check(mpca_world_destroy(w), "mpca_world_destroy");
    return 0;
}
