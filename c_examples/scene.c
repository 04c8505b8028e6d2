/*
 * The loop every scene program runs: see scene.h.
 */
#define _POSIX_C_SOURCE 200809L

#include "scene.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "common.h"
#include "gif.h"
#include "image.h"

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

void scene_step(mpca_world *w, uint64_t n, const scene_opts *o) {
    if (o->threads == 0) {
        mpca_check(mpca_world_step(w, n), "mpca_world_step");
    } else {
        mpca_check(mpca_world_step_parallel(w, n, 4 * o->threads, run_tasks, (void *)&o->threads),
                   "mpca_world_step_parallel");
    }
}

void scene_make_dirs(const char *path) {
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

/* 12.5 frames a second, and a second on the last before it loops. */
#define GIF_DELAY_CS 8
#define GIF_LAST_DELAY_CS 100

/* The haze is at its brightest where a quarter of a bin's cells hold a
 * particle: smoke is sparse, and a bin that full already reads as thick. */
#define DENSITY_FULL 0.25f

/* Draws the scene into `rgba` (v->width x v->height, rows bottom to top). */
static drawn render(const scene *s, const scene_opts *o, mpca_world *w, canvas *c, uint8_t *rgba, const view *v) {
    canvas_begin(c, rgba, v);
    if (o->density && s->dim == 2) {
        /* Under everything else: it covers the whole view. */
        view2d_begin(o->size, o->size);
        draw_density_2d(w, o->density, DENSITY_FULL);
    }
    drawn d = s->draw(o, w, v);
    canvas_end(c, s->name);
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

uint64_t scene_spread(uint64_t i, uint64_t n, uint64_t steps) {
    return n <= 1 ? steps : (steps * i + (n - 1) / 2) / (n - 1);
}

/* ---- progress on stderr ------------------------------------------------------- */

typedef struct progress {
    int mode;          /* PROGRESS_*, PROGRESS_NEVER when nothing will be said */
    double start;
    uint32_t next;     /* the next tenth to report, 1 to 10; 11: done */
} progress;

static progress progress_start(int mode) {
    if (mode == PROGRESS_AUTO && !isatty(STDERR_FILENO)) mode = PROGRESS_NEVER;
    progress p = {mode, now_s(), 1};
    return p;
}

/* The step at which tenth `k` is reached: ceil(k * steps / 10). */
static uint64_t tenth_step(uint32_t k, uint64_t steps) {
    return (steps * k + 9) / 10;
}

/* Reports the highest tenth reached at step t, once; in the automatic
 * mode only once the run has taken a second, so short runs say nothing. */
static void progress_report(progress *p, const char *name, uint64_t t, uint64_t steps) {
    if (p->mode == PROGRESS_NEVER || p->next > 10 || t < tenth_step(p->next, steps)) return;
    while (p->next <= 10 && t >= tenth_step(p->next, steps)) p->next++;
    double elapsed = now_s() - p->start;
    if (p->mode == PROGRESS_AUTO && elapsed < 1.0) return;
    fprintf(stderr, "%s: %u %% (step %llu of %llu, %.1f s)\n", name, 10 * (p->next - 1), (unsigned long long)t,
            (unsigned long long)steps, elapsed);
}

/* The next step after t where a tenth is reached, or UINT64_MAX. */
static uint64_t progress_next(const progress *p, uint64_t steps) {
    return p->mode == PROGRESS_NEVER || p->next > 10 ? UINT64_MAX : tenth_step(p->next, steps);
}

/* ---- the run -------------------------------------------------------------------- */

void scene_frame_png(image *frame, const uint8_t *gl, const view *fv, const scene_opts *o, int digits, uint64_t n,
                     char *path, size_t path_len) {
    image_blit_gl(frame, gl, fv->width, fv->height, 0, 0);
    snprintf(path, path_len, "%s/%s-frame-%0*llu.png", o->out, o->name, digits, (unsigned long long)n);
    png_write(path, frame, (int)o->png_level);
}

void scene_tile(image *sheet, const uint8_t *gl, const view *tv, uint64_t i, const char *label) {
    uint32_t x0 = SHEET_GAP + (uint32_t)i * (tv->width + SHEET_GAP);
    image_blit_gl(sheet, gl, tv->width, tv->height, x0, SHEET_GAP);
    image_label(sheet, x0, tv->height + 2 * SHEET_GAP, label);
}

void scene_gif_frame(gif_anim *gif, image *frame, const uint8_t *gl, const view *tv, const char *label) {
    image_clear(frame);
    image_blit_gl(frame, gl, tv->width, tv->height, 0, 0);
    image_label(frame, GIF_GAP, tv->height + GIF_GAP, label);
    gif_add(gif, frame);
}

double scene_finish(const scene_opts *o, const image *sheet, unsigned tiles, gif_anim *gif, const image *gif_frame,
                    int delay_cs, int last_delay_cs, mpca_world *w, mpca_stats *stats) {
    size_t path_len = strlen(o->out) + strlen(o->name) + 48;
    char *path = xrealloc(NULL, path_len);
    double t0 = now_s();
    snprintf(path, path_len, "%s/%s-sheet.png", o->out, o->name);
    png_write(path, sheet, (int)o->png_level);
    double png_s = now_s() - t0;
    printf("sheet: %s size=%ux%u tiles=%u\n", path, (unsigned)sheet->width, (unsigned)sheet->height, tiles);
    if (gif) {
        t0 = now_s();
        snprintf(path, path_len, "%s/%s.gif", o->out, o->name);
        gif_written g = gif_write(gif, path, delay_cs, last_delay_cs);
        printf("gif: %s size=%ux%u frames=%u colours=%u bytes=%ld in %.1f ms\n", path, (unsigned)gif_frame->width,
               (unsigned)gif_frame->height, (unsigned)g.frames, (unsigned)g.colours, g.bytes, 1e3 * (now_s() - t0));
        gif_free(gif);
    }
    free(path);

    mpca_check(mpca_world_stats(w, stats), "mpca_world_stats");
    uint64_t hash = 0;
    mpca_check(mpca_world_hash(w, &hash), "mpca_world_hash");
    printf("end: step=%llu particles=%llu emitted=%llu shortfall=%llu exited=%llu collisions=%llu clamps=%llu "
           "hash=%016llx\n",
           (unsigned long long)stats->step, (unsigned long long)stats->particles, (unsigned long long)stats->emitted,
           (unsigned long long)stats->emit_shortfall, (unsigned long long)stats->exited,
           (unsigned long long)stats->collisions, (unsigned long long)stats->clamps, (unsigned long long)hash);
    return png_s;
}

int scene_main(const scene *s, int argc, char **argv) {
    scene_opts o;
    int status = options_parse(s, &o, argc, argv);
    if (status >= 0) return status;
    scene_make_dirs(o.out);

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
    /* Sheet tiles and GIF frames at half the frame's resolution (whole
     * cells in 2D). */
    view tv = make_view(s, o.size, s->dim == 2 ? (fv.cell_px + 1) / 2 * o.size : o.px / 2);
    canvas *c = canvas_create();
    /* What OpenGL draws into, rows bottom to top. */
    uint8_t *frame_gl = xrealloc(NULL, (size_t)fv.width * fv.height * 4);
    uint8_t *tile_gl = xrealloc(NULL, (size_t)tv.width * tv.height * 4);

    /* Sheet tiles and GIF frames spread evenly over the run, 0 and the end
     * included, never two at one step. */
    uint32_t tiles = o.tiles;
    if ((uint64_t)tiles > o.steps + 1) tiles = (uint32_t)(o.steps + 1);
    uint32_t gif_frames = o.gif;
    if ((uint64_t)gif_frames > o.steps + 1) gif_frames = (uint32_t)(o.steps + 1);
    image sheet = image_new(tiles * tv.width + (tiles + 1) * SHEET_GAP,
                            tv.height + 3 * SHEET_GAP + LABEL_HEIGHT);
    image frame = image_new(fv.width, fv.height);
    /* A GIF frame: the tile with its label in a strip below. */
    image gif_frame = image_new(tv.width, tv.height + 2 * GIF_GAP + LABEL_HEIGHT);
    gif_anim *gif = gif_frames ? gif_new(gif_frame.width, gif_frame.height) : NULL;
    /* Frames are numbered 0, 1, 2, ... (not by step), so that tools that
     * read numbered sequences (ffmpeg -i NAME-frame-%04d.png) find them
     * all; the step of each is printed. */
    uint64_t frame_count = o.every ? o.steps / o.every + 1 + (o.steps % o.every != 0) : 0;
    int digits = snprintf(NULL, 0, "%llu", (unsigned long long)(frame_count ? frame_count - 1 : 0));
    if (digits < 4) digits = 4;
    size_t path_len = strlen(o.out) + strlen(o.name) + 48;
    char *path = xrealloc(NULL, path_len);

    double sim_s = 0.0, draw_s = 0.0, png_s = 0.0;
    /* pngs: the frames and the sheet */
    uint64_t images = 0, pngs = 1, frames = 0, next_tile = 0, next_gif = 0;
    progress prog = progress_start(o.progress);
    for (uint64_t t = 0;;) {
        char label[32];
        snprintf(label, sizeof label, "t=%llu", (unsigned long long)t);
        if (o.every && (t % o.every == 0 || t == o.steps)) {
            double t0 = now_s();
            drawn d = render(s, &o, w, c, frame_gl, &fv);
            double t1 = now_s();
            scene_frame_png(&frame, frame_gl, &fv, &o, digits, frames, path, path_len);
            draw_s += t1 - t0;
            png_s += now_s() - t1;
            images++;
            pngs++;
            frames++;
            printf("frame: %s step=%llu", path, (unsigned long long)t);
            print_drawn(&d, &fv);
        }
        int tile_now = next_tile < tiles && scene_spread(next_tile, tiles, o.steps) == t;
        int gif_now = next_gif < gif_frames && scene_spread(next_gif, gif_frames, o.steps) == t;
        if (tile_now || gif_now) {
            /* One drawing serves both. */
            double t0 = now_s();
            drawn d = render(s, &o, w, c, tile_gl, &tv);
            draw_s += now_s() - t0;
            images++;
            if (tile_now) {
                scene_tile(&sheet, tile_gl, &tv, next_tile, label);
                printf("tile: step=%llu", (unsigned long long)t);
                print_drawn(&d, &tv);
                next_tile++;
            }
            if (gif_now) {
                scene_gif_frame(gif, &gif_frame, tile_gl, &tv, label);
                next_gif++;
            }
        }
        fflush(stdout);
        progress_report(&prog, o.name, t, o.steps);
        if (t >= o.steps) break;
        /* Step on to the next frame, tile, GIF frame, tenth or the end,
         * timing only the steps. */
        uint64_t next = o.steps;
        if (o.every && (t / o.every + 1) * o.every < next) next = (t / o.every + 1) * o.every;
        if (next_tile < tiles && scene_spread(next_tile, tiles, o.steps) < next) {
            next = scene_spread(next_tile, tiles, o.steps);
        }
        if (next_gif < gif_frames && scene_spread(next_gif, gif_frames, o.steps) < next) {
            next = scene_spread(next_gif, gif_frames, o.steps);
        }
        if (progress_next(&prog, o.steps) < next) next = progress_next(&prog, o.steps);
        double t0 = now_s();
        if (s->step) {
            for (uint64_t k = t; k < next; k++) s->step(&o, w, k);
        } else {
            scene_step(w, next - t, &o);
        }
        sim_s += now_s() - t0;
        t = next;
    }
    png_s += scene_finish(&o, &sheet, (unsigned)tiles, gif, &gif_frame, GIF_DELAY_CS, GIF_LAST_DELAY_CS, w, &stats);
    double per_step = o.steps ? 1e3 * sim_s / (double)o.steps : 0.0;
    printf("sim: %.3f ms/step (%llu steps in %.1f ms), render: %.2f ms/frame (%llu frames and tiles), "
           "png: %.2f ms/file (%llu files)\n",
           per_step, (unsigned long long)o.steps, 1e3 * sim_s, 1e3 * draw_s / (double)images,
           (unsigned long long)images, 1e3 * png_s / (double)pngs, (unsigned long long)pngs);

    free(path);
    image_free(&frame);
    image_free(&sheet);
    image_free(&gif_frame);
    free(frame_gl);
    free(tile_gl);
    canvas_destroy(c);
    mpca_check(mpca_world_destroy(w), "mpca_world_destroy");
    return 0;
}
