/*
 * Following particles by id between steps: see follow.h.
 */
#include "follow.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "common.h"

/* The steps a particle's travel is averaged over. */
#define TRAVEL_STEPS 8.0f

/* A particle's id and where the export put it. */
typedef struct keyed {
    uint32_t id, index;
} keyed;

struct follow_state {
    uint32_t identity; /* the world's mpca_identity bits */
    size_t capacity;   /* of every array below */
    /* The export's columns, in cell order. */
    float *positions, *velocities;
    uint32_t *ids, *ages;
    uint8_t *tags;
    keyed *order;
    /* The last step's ids, cells and travel, in id order. */
    uint32_t *last_ids;
    float *last_cells, *last_travel;
    size_t last_count;
};

static int by_id(const void *a, const void *b) {
    uint32_t x = ((const keyed *)a)->id, y = ((const keyed *)b)->id;
    return x < y ? -1 : x > y;
}

/* A particle's seed: its id hashed (an integer finaliser), so neighbours
 * in id, emitted one after the other, look nothing alike. */
static float seed_of(uint32_t id) {
    uint32_t h = id;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return (float)(h >> 8) / 16777216.0f;
}

static void grow(follower *f, size_t n) {
    struct follow_state *s = f->state;
    if (n <= s->capacity) return;
    s->capacity = n + n / 2 + 64;
    size_t c = s->capacity;
    s->positions = xrealloc(s->positions, 3 * c * sizeof *s->positions);
    s->velocities = xrealloc(s->velocities, 3 * c * sizeof *s->velocities);
    s->ids = xrealloc(s->ids, c * sizeof *s->ids);
    s->ages = xrealloc(s->ages, c * sizeof *s->ages);
    s->tags = xrealloc(s->tags, c * sizeof *s->tags);
    s->order = xrealloc(s->order, c * sizeof *s->order);
    s->last_ids = xrealloc(s->last_ids, c * sizeof *s->last_ids);
    s->last_cells = xrealloc(s->last_cells, 2 * c * sizeof *s->last_cells);
    s->last_travel = xrealloc(s->last_travel, c * sizeof *s->last_travel);
    f->particles = xrealloc(f->particles, c * sizeof *f->particles);
}

/* Exports the world, sorts it by id and matches it with the last step's
 * cells; `first` says there is no last step. */
static void follow(follower *f, const mpca_world *w, int first) {
    struct follow_state *s = f->state;
    mpca_particle_columns cols;
    memset(&cols, 0, sizeof cols);
    cols.struct_size = sizeof cols;
    size_t n = 0;
    /* Every column NULL and no room: the count alone. */
    mpca_check(mpca_world_export_particles(w, &cols, 0, &n), "mpca_world_export_particles (count)");
    grow(f, n);
    cols.positions = s->positions;
    cols.velocities = s->velocities;
    cols.ids = s->ids;
    cols.ages = s->identity & MPCA_IDENTITY_AGES ? s->ages : NULL;
    cols.tags = s->identity & MPCA_IDENTITY_TAGS ? s->tags : NULL;
    mpca_check(mpca_world_export_particles(w, &cols, s->capacity, &n), "mpca_world_export_particles");

    /* The export is in cell order, which says nothing of the ids; sorted,
     * both steps are matched in one merge. */
    for (size_t i = 0; i < n; i++) {
        s->order[i].id = s->ids[i];
        s->order[i].index = (uint32_t)i;
    }
    qsort(s->order, n, sizeof *s->order, by_id);
    size_t j = 0;
    double speed = 0.0;
    for (size_t i = 0; i < n; i++) {
        const uint32_t id = s->order[i].id, k = s->order[i].index;
        const float *at = s->positions + 3 * k, *v = s->velocities + 3 * k;
        moving *p = &f->particles[i];
        p->to[0] = p->from[0] = at[0];
        p->to[1] = p->from[1] = at[1];
        p->age = cols.ages ? (float)s->ages[k] : 0.0f;
        p->tag = cols.tags ? (float)s->tags[k] : 0.0f;
        p->seed = seed_of(id);
        p->travel = 0.0f;
        speed += sqrtf(v[0] * v[0] + v[1] * v[1]);
        while (!first && j < s->last_count && s->last_ids[j] < id) j++;
        if (!first && j < s->last_count && s->last_ids[j] == id) {
            const float *was = s->last_cells + 2 * j;
            /* At most a cell a step per axis (M1); farther is round a
             * periodic edge, where sliding would sweep the particle
             * across the whole world. */
            float dx = at[0] - was[0], dy = at[1] - was[1];
            if (fabsf(dx) <= 1.0f && fabsf(dy) <= 1.0f) {
                p->from[0] = was[0];
                p->from[1] = was[1];
                /* A step is 0 or 1 cell (or a diagonal); averaged over
                 * about TRAVEL_STEPS steps it is how fast it travels. */
                p->travel = s->last_travel[j] + (sqrtf(dx * dx + dy * dy) - s->last_travel[j]) / TRAVEL_STEPS;
            } else {
                p->travel = s->last_travel[j];
            }
            f->matched++;
        } else if (!first) {
            f->appeared++;
        }
    }
    for (size_t i = 0; i < n; i++) {
        s->last_ids[i] = s->order[i].id;
        s->last_cells[2 * i] = f->particles[i].to[0];
        s->last_cells[2 * i + 1] = f->particles[i].to[1];
        s->last_travel[i] = f->particles[i].travel;
    }
    f->mean_speed = n ? speed / (double)n : 0.0;
    s->last_count = n;
    f->count = n;
}

void follow_start(follower *f, const mpca_world *w) {
    memset(f, 0, sizeof *f);
    f->state = xrealloc(NULL, sizeof *f->state);
    memset(f->state, 0, sizeof *f->state);
    mpca_desc d;
    d.struct_size = sizeof d;
    mpca_check(mpca_world_desc(w, &d), "mpca_world_desc");
    if (!(d.identity & MPCA_IDENTITY_IDS)) {
        fprintf(stderr, "follow: the world has no ids (mpca_desc.identity)\n");
        exit(1);
    }
    f->state->identity = d.identity;
    follow(f, w, 1);
}

void follow_step(follower *f, const mpca_world *w) {
    follow(f, w, 0);
}

void follow_free(follower *f) {
    struct follow_state *s = f->state;
    if (s) {
        free(s->positions);
        free(s->velocities);
        free(s->ids);
        free(s->ages);
        free(s->tags);
        free(s->order);
        free(s->last_ids);
        free(s->last_cells);
        free(s->last_travel);
        free(s);
    }
    free(f->particles);
    memset(f, 0, sizeof *f);
}
