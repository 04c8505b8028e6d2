/*
 * The parallel step (M11) from C: mpca_world_step_parallel hands each step's
 * tasks to a run_tasks callback of the program's, which runs them with
 * mpca_world_step_task on its own threads (POSIX threads here).
 *
 * - Worlds stepped in tasks hash equal to their twins stepped by
 *   mpca_world_step, for 1, 2, 3, 4, 7 and 64 tasks, run forward, in
 *   reverse and shuffled, on the calling thread and on two threads; for a
 *   2D gas, a walled 2D box under gravity, a 3D box with a sphere, an
 *   emitter world with lifetimes and a 1024 x 1024 gas.
 * - Misuse is refused with a status and changes nothing: a task run twice,
 *   an index beyond the count, a task of another step or of no step, any
 *   other call on the world while a step is in flight (from inside a task
 *   and from another thread), a NULL callback. A callback that runs no
 *   task still gets the whole step.
 *
 * Prints "parallel: NAME equal N" per world (N runs compared) and
 * "misuse: NAME" per misuse case.
 */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

/* ---- The worlds -------------------------------------------------------- */

enum kind { GAS_2D, BOX_2D, SPHERE_3D, EMITTER_2D, GAS_1024, KINDS };
static const char *const KIND_NAMES[KINDS] = {"gas-2d", "box-2d", "sphere-3d", "emitter-2d", "gas-1024"};
static const uint64_t KIND_STEPS[KINDS] = {24, 24, 16, 30, 3};

/* Builds world `kind`; NULL if any call failed (the checks say which). */
static mpca_world *build(enum kind kind) {
    mpca_desc d;
    uint32_t n = kind == GAS_1024 ? 1024 : kind == SPHERE_3D ? 24 : 96;
    uint32_t dim = kind == SPHERE_3D ? 3 : 2;
    CHECK_OK(mpca_desc_defaults(&d, dim, n, n, n));
    d.seed = 17 + (uint64_t)kind;
    d.restitution = 0.6f;
    if (kind == BOX_2D || kind == SPHERE_3D) {
        unsigned k;
        for (k = 0; k < 3; k++) {
            d.boundary[k][0] = d.boundary[k][1] = MPCA_BOUNDARY_WALL;
        }
        d.forces = MPCA_FORCE_UNIFORM;
        d.gravity[1] = -0.02f;
        d.contacts = 1;
        d.collisions = MPCA_COLLISIONS_SPEED_LIMITED;
    }
    if (kind == SPHERE_3D) {
        d.obstacles = 1;
        d.surface_capacity = 4096;
    }
    if (kind == EMITTER_2D) {
        d.boundary[1][0] = d.boundary[1][1] = MPCA_BOUNDARY_OPEN;
        d.forces = MPCA_FORCE_UNIFORM | MPCA_FORCE_VORTEX;
        d.gravity[1] = 0.01f;
        d.vortex_centre[0] = 48.0f;
        d.vortex_centre[1] = 48.0f;
        d.vortex_core_radius = 6.0f;
        d.vortex_circulation = 0.8f;
        d.emitter_capacity = 1;
        d.lifetimes = 1;
    }
    mpca_world *w = NULL;
    if (mpca_world_create(&d, &w) != MPCA_STATUS_OK) {
        CHECK(0);
        return NULL;
    }
    if (kind == SPHERE_3D) {
        const float centre[3] = {12.0f, 8.0f, 12.0f};
        CHECK_OK(mpca_world_add_sphere(w, centre, 5.0f, 0.7f));
    }
    if (kind == EMITTER_2D) {
        mpca_emitter e;
        uint32_t index = 0;
        memset(&e, 0, sizeof e);
        e.struct_size = sizeof e;
        e.min[0] = 40;
        e.max[0] = 56;
        e.min[1] = 2;
        e.max[1] = 6;
        e.max[2] = 1;
        e.rate = 6.5f;
        e.velocity[1] = 0.3f;
        e.spread = 0.2f;
        e.mass = 1.0f;
        e.lifetime = 25;
        CHECK_OK(mpca_world_add_emitter(w, &e, &index));
    }
    {
        uint64_t s = 99 + (uint64_t)kind;
        float density = kind == GAS_1024 ? 0.1f : kind == SPHERE_3D ? 0.08f : 0.3f;
        uint32_t nz = dim == 3 ? n : 1, x, y, z;
        for (z = 0; z < nz; z++) {
            for (y = 0; y < n; y++) {
                for (x = 0; x < n; x++) {
                    if (check_unit(&s) < density) {
                        uint32_t pos[3] = {x, y, z};
                        float v[3] = {0.6f * (check_unit(&s) - 0.5f), 0.6f * (check_unit(&s) - 0.5f), 0};
                        if (dim == 3) {
                            v[2] = 0.6f * (check_unit(&s) - 0.5f);
                        }
                        /* Obstacle cells refuse; that is fine. */
                        (void)mpca_world_add_particle(w, pos, v);
                    }
                }
            }
        }
    }
    return w;
}

static uint64_t hash_of(mpca_world *w) {
    uint64_t h = 0;
    CHECK_OK(mpca_world_hash(w, &h));
    return h;
}

/* ---- Hosts ------------------------------------------------------------- */

enum order { FORWARD, REVERSE, SHUFFLED };
static const char *const ORDER_NAMES[3] = {"forward", "reverse", "shuffled"};

/* What run_tasks does with the tasks it is given. */
struct host {
    unsigned threads; /* 1: the calling thread; 2: it and one pthread */
    enum order order;
    uint64_t shuffle;
    unsigned repeat; /* run every task this many times (misuse: > 1) */
    uint32_t max_count; /* the largest count seen */
    unsigned failures;  /* mpca_world_step_task calls not OK (first runs) */
    unsigned refused_again; /* repeats refused with TASK_DONE */
};

struct worker {
    mpca_world *world;
    uint64_t ticket;
    const uint32_t *order;
    uint32_t count, first, stride;
    unsigned repeat, failures, refused_again;
};

static void *work(void *arg) {
    struct worker *k = arg;
    uint32_t i;
    unsigned r;
    for (r = 0; r < k->repeat; r++) {
        for (i = k->first; i < k->count; i += k->stride) {
            mpca_status s = mpca_world_step_task(k->world, k->ticket, k->order[i]);
            if (r == 0 && s != MPCA_STATUS_OK) {
                k->failures++;
            }
            if (r > 0 && s == MPCA_STATUS_TASK_DONE) {
                k->refused_again++;
            }
        }
    }
    return NULL;
}

static void run_tasks(mpca_world *world, uint64_t ticket, uint32_t count, void *user_data) {
    struct host *h = user_data;
    uint32_t order[MPCA_MAX_TASKS], i;
    struct worker k[2];
    pthread_t thread;
    unsigned t;
    if (count > h->max_count) {
        h->max_count = count;
    }
    if (count > MPCA_MAX_TASKS) {
        h->failures++;
        return;
    }
    for (i = 0; i < count; i++) {
        order[i] = h->order == REVERSE ? count - 1 - i : i;
    }
    if (h->order == SHUFFLED) {
        for (i = count; i > 1; i--) {
            uint32_t j = check_random(&h->shuffle) % i, tmp = order[i - 1];
            order[i - 1] = order[j];
            order[j] = tmp;
        }
    }
    for (t = 0; t < 2; t++) {
        k[t].world = world;
        k[t].ticket = ticket;
        k[t].order = order;
        k[t].count = count;
        k[t].first = t;
        k[t].stride = h->threads;
        k[t].repeat = h->repeat;
        k[t].failures = k[t].refused_again = 0;
    }
    if (h->threads == 2 && pthread_create(&thread, NULL, work, &k[1]) == 0) {
        work(&k[0]);
        pthread_join(thread, NULL);
    } else {
        k[0].stride = 1;
        work(&k[0]);
        k[1].failures = k[1].refused_again = 0;
    }
    h->failures += k[0].failures + k[1].failures;
    h->refused_again += k[0].refused_again + k[1].refused_again;
}

/* ---- Equal to the serial step ------------------------------------------ */

static void equal_to_serial(enum kind kind) {
    static const uint32_t TASKS[6] = {1, 2, 3, 4, 7, 64};
    unsigned ti, o, threads, runs = 0;
    uint64_t want;
    mpca_world *serial = build(kind);
    check_context = KIND_NAMES[kind];
    if (serial == NULL) {
        return;
    }
    CHECK_OK(mpca_world_step(serial, KIND_STEPS[kind]));
    want = hash_of(serial);
    CHECK_OK(mpca_world_destroy(serial));
    for (ti = 0; ti < 6; ti++) {
        for (o = 0; o < 3; o++) {
            for (threads = 1; threads <= 2; threads++) {
                struct host h;
                mpca_world *w;
                /* Every order on two threads only for the smaller worlds. */
                if (kind == GAS_1024 && threads == 2 && o != SHUFFLED) {
                    continue;
                }
                w = build(kind);
                if (w == NULL) {
                    return;
                }
                memset(&h, 0, sizeof h);
                h.threads = threads;
                h.order = (enum order)o;
                h.shuffle = 1000 + ti;
                h.repeat = 1;
                CHECK_OK(mpca_world_step_parallel(w, KIND_STEPS[kind], TASKS[ti], run_tasks, &h));
                CHECK(h.failures == 0);
                CHECK(h.max_count >= 1 && h.max_count <= TASKS[ti]);
                if (hash_of(w) != want) {
                    printf("FAILED [%s] %u tasks, %s, %u threads: hash differs from the serial step\n", KIND_NAMES[kind],
                           TASKS[ti], ORDER_NAMES[o], threads);
                    check_true(0, "hash equal to the serial step", __FILE__, __LINE__);
                }
                CHECK_OK(mpca_world_destroy(w));
                runs++;
            }
        }
    }
    printf("parallel: %s equal %u\n", KIND_NAMES[kind], runs);
}

/* ---- Misuse ------------------------------------------------------------ */

/* What the misbehaving callbacks do and saw. */
struct probe {
    int mode;
    uint64_t old_ticket;
    mpca_world *world; /* for the other thread */
    mpca_status seen[8];
    uint32_t count;
};

enum { RUN_NOTHING, CALL_WORLD, BAD_INDEX, OLD_TICKET, OTHER_THREAD };

static void *count_particles(void *arg) {
    struct probe *p = arg;
    size_t n = 0;
    p->seen[6] = mpca_world_particle_count(p->world, &n);
    return NULL;
}

static void misbehave(mpca_world *world, uint64_t ticket, uint32_t count, void *user_data) {
    struct probe *p = user_data;
    uint32_t i;
    uint64_t h = 0;
    p->count = count;
    switch (p->mode) {
    case RUN_NOTHING:
        return;
    case CALL_WORLD:
        p->seen[0] = mpca_world_step(world, 1);
        p->seen[1] = mpca_world_hash(world, &h);
        p->seen[2] = mpca_world_step_parallel(world, 1, 2, misbehave, p);
        p->seen[3] = mpca_world_destroy(world);
        p->seen[4] = mpca_world_deinit(world);
        break;
    case BAD_INDEX:
        p->seen[0] = mpca_world_step_task(world, ticket, count);
        p->seen[1] = mpca_world_step_task(world, ticket, UINT32_MAX);
        p->seen[2] = mpca_world_step_task(world, ticket + 1, 0);
        break;
    case OLD_TICKET:
        if (p->old_ticket != 0) {
            p->seen[0] = mpca_world_step_task(world, p->old_ticket, 0);
        }
        p->old_ticket = ticket;
        break;
    case OTHER_THREAD: {
        pthread_t t;
        p->world = world;
        if (pthread_create(&t, NULL, count_particles, p) == 0) {
            pthread_join(t, NULL);
        }
        break;
    }
    }
    for (i = 0; i < count; i++) {
        (void)mpca_world_step_task(world, ticket, i);
    }
}

/* A fresh GAS_2D world and its hash after `steps` serial steps. */
static mpca_world *twin(uint64_t steps, uint64_t *want) {
    mpca_world *s = build(GAS_2D);
    if (s != NULL) {
        CHECK_OK(mpca_world_step(s, steps));
        *want = hash_of(s);
        CHECK_OK(mpca_world_destroy(s));
    }
    return build(GAS_2D);
}

static void misuse(void) {
    uint64_t want = 0, before;
    struct probe p;
    struct host h;
    unsigned i;
    mpca_world *w;
    check_context = "misuse";

    /* A task run twice: the repeat is refused, the world is the serial one. */
    w = twin(6, &want);
    memset(&h, 0, sizeof h);
    h.threads = 2;
    h.order = SHUFFLED;
    h.shuffle = 5;
    h.repeat = 2;
    CHECK_OK(mpca_world_step_parallel(w, 6, 8, run_tasks, &h));
    CHECK(h.failures == 0 && h.refused_again == 6 * 8);
    CHECK(hash_of(w) == want);
    CHECK_OK(mpca_world_destroy(w));
    printf("misuse: task run twice\n");

    /* A callback that runs nothing: the step still completes. */
    w = twin(3, &want);
    memset(&p, 0, sizeof p);
    p.mode = RUN_NOTHING;
    CHECK_OK(mpca_world_step_parallel(w, 3, 4, misbehave, &p));
    CHECK(p.count == 4 && hash_of(w) == want);
    CHECK_OK(mpca_world_destroy(w));
    printf("misuse: no task run\n");

    /* Other calls on the world from inside a task: BUSY, and the nested
     * destroy and deinit did nothing. */
    w = twin(2, &want);
    memset(&p, 0, sizeof p);
    p.mode = CALL_WORLD;
    CHECK_OK(mpca_world_step_parallel(w, 2, 3, misbehave, &p));
    for (i = 0; i < 5; i++) {
        check_status(p.seen[i], MPCA_STATUS_BUSY, "a call on the world during its parallel step", __FILE__, __LINE__);
    }
    CHECK(hash_of(w) == want);
    printf("misuse: calls during the step\n");

    /* From another thread while the step is in flight: BUSY too. */
    memset(&p, 0, sizeof p);
    p.mode = OTHER_THREAD;
    CHECK_OK(mpca_world_step_parallel(w, 1, 3, misbehave, &p));
    check_status(p.seen[6], MPCA_STATUS_BUSY, "a call from another thread during the step", __FILE__, __LINE__);
    CHECK_OK(mpca_world_destroy(w));
    printf("misuse: another thread\n");

    /* Indices beyond the count, a ticket that is not the step's. */
    w = twin(1, &want);
    memset(&p, 0, sizeof p);
    p.mode = BAD_INDEX;
    CHECK_OK(mpca_world_step_parallel(w, 1, 5, misbehave, &p));
    check_status(p.seen[0], MPCA_STATUS_TASK_INDEX, "index == count", __FILE__, __LINE__);
    check_status(p.seen[1], MPCA_STATUS_TASK_INDEX, "index UINT32_MAX", __FILE__, __LINE__);
    check_status(p.seen[2], MPCA_STATUS_STALE_TASK, "a ticket no step has", __FILE__, __LINE__);
    CHECK(hash_of(w) == want);
    CHECK_OK(mpca_world_destroy(w));
    printf("misuse: bad index\n");

    /* A task of an earlier step, during the next and after the last; a task
     * when no step is in flight. */
    w = twin(2, &want);
    memset(&p, 0, sizeof p);
    p.mode = OLD_TICKET;
    CHECK_OK(mpca_world_step_parallel(w, 2, 4, misbehave, &p));
    check_status(p.seen[0], MPCA_STATUS_STALE_TASK, "a task of the previous step", __FILE__, __LINE__);
    check_status(TRACE(mpca_world_step_task(w, p.old_ticket, 0)), MPCA_STATUS_STALE_TASK, "a task after the step",
                 __FILE__, __LINE__);
    check_status(mpca_world_step_task(w, 0, 0), MPCA_STATUS_STALE_TASK, "no step in flight", __FILE__, __LINE__);
    CHECK(hash_of(w) == want);
    printf("misuse: stale tickets\n");

    /* NULL callback, NULL world, dead world: refused, nothing stepped. */
    before = hash_of(w);
    check_status(TRACE(mpca_world_step_parallel(w, 1, 2, NULL, NULL)), MPCA_STATUS_NULL_POINTER, "NULL run_tasks",
                 __FILE__, __LINE__);
    check_status(mpca_world_step_parallel(NULL, 1, 2, run_tasks, &h), MPCA_STATUS_NULL_POINTER, "NULL world",
                 __FILE__, __LINE__);
    check_status(mpca_world_step_task(NULL, 1, 0), MPCA_STATUS_NULL_POINTER, "NULL world (task)", __FILE__, __LINE__);
    CHECK(hash_of(w) == before);
    {
        mpca_stats s;
        memset(&s, 0, sizeof s);
        s.struct_size = sizeof s;
        CHECK_OK(mpca_world_stats(w, &s));
        CHECK(s.step == 2);
    }
    CHECK_OK(mpca_world_destroy(w));
    check_status(mpca_world_step_parallel(w, 1, 2, run_tasks, &h), MPCA_STATUS_BAD_HANDLE, "destroyed world", __FILE__,
                 __LINE__);
    printf("misuse: NULL and dead\n");

    /* Task counts: 0 is one task, more than MPCA_MAX_TASKS is that many. */
    w = twin(2, &want);
    memset(&h, 0, sizeof h);
    h.threads = 1;
    h.repeat = 1;
    CHECK_OK(mpca_world_step_parallel(w, 1, 0, run_tasks, &h));
    CHECK(h.max_count == 1);
    CHECK_OK(mpca_world_step_parallel(w, 1, 1000, run_tasks, &h));
    CHECK(h.max_count >= 1 && h.max_count <= MPCA_MAX_TASKS && h.failures == 0);
    CHECK(hash_of(w) == want);
    CHECK_OK(mpca_world_destroy(w));
    printf("misuse: task counts\n");
}

int main(void) {
    unsigned kind;
    check_begin();
    for (kind = 0; kind < KINDS; kind++) {
        equal_to_serial((enum kind)kind);
    }
    misuse();
    return check_end();
}
