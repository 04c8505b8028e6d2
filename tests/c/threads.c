/*
 * Calls on one world from several threads, and worlds built, loaded or
 * ended over a world in use: the rule the header states at mpca_world
 * (calls that read run together; a call that changes the world waits for
 * them and runs alone; a call that ends or replaces a world is refused
 * with MPCA_STATUS_BUSY while any call is inside; a call the world is not
 * free for is refused at once).
 *
 * - Readers and steps: one thread reads statistics and hashes while
 *   another steps (in parallel, and serially) for many rounds. Reads are
 *   OK or BUSY, steps always OK (they wait for the reads); every reading
 *   taken between two equal step counts hashes as the stepping thread saw
 *   the world at that step, so no read saw a world half stepped.
 * - Memory in use, from a task and from another thread: inside a parallel
 *   step's run_tasks, and from a thread it starts, mpca_world_init and
 *   mpca_world_init_from_image over the stepped world's memory (all of it,
 *   and a part), mpca_world_load, mpca_world_deinit and mpca_world_destroy
 *   return BUSY and change nothing: the step ends as the serial step does
 *   and the refused calls wrote no handle.
 * - Ending a world another thread is using: a thread steps or reads a
 *   world until its handle dies while the main thread builds a world over
 *   its memory, or deinitialises or destroys it, until that is accepted.
 *   The user's calls are OK, BUSY or, once it ended, BAD_HANDLE; the new
 *   world was never stepped.
 * - Details per thread: two threads refuse descriptions for different
 *   fields at the same time, and each reads its own detail
 *   (mpca_last_error) back after every refusal; a thread that has refused
 *   nothing reads "".
 *
 * Worker threads record what they saw and the main thread checks it after
 * joining them (check.c's counters are not shared between threads).
 * Prints "threads: NAME ..." per group.
 */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"

/* A stop flag shared by two threads, under a mutex so that the test
 * itself is free of races under ThreadSanitizer. */
struct flag {
    pthread_mutex_t lock;
    int set;
};

static void flag_init(struct flag *f) {
    pthread_mutex_init(&f->lock, NULL);
    f->set = 0;
}

static void flag_raise(struct flag *f) {
    pthread_mutex_lock(&f->lock);
    f->set = 1;
    pthread_mutex_unlock(&f->lock);
}

static int flag_is_up(struct flag *f) {
    int set;
    pthread_mutex_lock(&f->lock);
    set = f->set;
    pthread_mutex_unlock(&f->lock);
    return set;
}

/* A 64 x 64 walled gas with an emitter, so a step writes particles and
 * the emitter's counters alike. */
static void gas_desc(mpca_desc *d) {
    unsigned k;
    CHECK_OK(mpca_desc_defaults(d, 2, 64, 64, 0));
    d->seed = 25;
    d->restitution = 0.7f;
    for (k = 0; k < 2; k++) {
        d->boundary[k][0] = d->boundary[k][1] = MPCA_BOUNDARY_WALL;
    }
    d->boundary[1][1] = MPCA_BOUNDARY_OPEN;
    d->emitter_capacity = 1;
}

static void fill(mpca_world *w) {
    uint64_t s = 7;
    uint32_t x, y;
    mpca_emitter e;
    uint32_t index = 0;
    for (y = 0; y < 64; y++) {
        for (x = 0; x < 64; x++) {
            if (check_unit(&s) < 0.3f) {
                uint32_t pos[3] = {x, y, 0};
                float v[3] = {0.6f * (check_unit(&s) - 0.5f), 0.6f * (check_unit(&s) - 0.5f), 0};
                CHECK_OK(mpca_world_add_particle(w, pos, v));
            }
        }
    }
    memset(&e, 0, sizeof e);
    e.struct_size = sizeof e;
    e.min[0] = 20;
    e.max[0] = 44;
    e.min[1] = 2;
    e.max[1] = 4;
    e.max[2] = 1;
    e.rate = 3.0f;
    e.velocity[1] = 0.4f;
    e.mass = 1.0f;
    CHECK_OK(mpca_world_add_emitter(w, &e, &index));
}

/* run_tasks that runs every task on the calling thread. */
static void run_here(mpca_world *world, uint64_t ticket, uint32_t count, void *user_data) {
    uint32_t i;
    (void)user_data;
    for (i = 0; i < count; i++) {
        (void)mpca_world_step_task(world, ticket, i);
    }
}

static uint64_t step_of(const mpca_world *w) {
    mpca_stats s;
    memset(&s, 0, sizeof s);
    s.struct_size = sizeof s;
    CHECK_OK(mpca_world_stats(w, &s));
    return s.step;
}

/* ---- Readers and steps -------------------------------------------------- */

#define ROUNDS 1200

/* Retries after which a call refused with BUSY every time counts as a
 * hang, not as bad luck: a reader's call lasts microseconds. */
#define PATIENCE 20000000u

struct reader {
    mpca_world *world;
    struct flag *done;
    /* Rounds of three reads the reader has finished, whatever they got. */
    pthread_mutex_t lock;
    unsigned rounds;
    /* A consistent reading: step count, hash, at that step. */
    uint64_t step[ROUNDS * 4], hash[ROUNDS * 4];
    unsigned readings, torn, busy, other;
};

static void *read_loop(void *arg) {
    struct reader *r = arg;
    while (!flag_is_up(r->done)) {
        mpca_stats a, b;
        uint64_t h = 0;
        mpca_status s1, s2, s3;
        memset(&a, 0, sizeof a);
        memset(&b, 0, sizeof b);
        a.struct_size = b.struct_size = sizeof a;
        s1 = mpca_world_stats(r->world, &a);
        s2 = mpca_world_hash(r->world, &h);
        s3 = mpca_world_stats(r->world, &b);
        if (s1 == MPCA_STATUS_OK && s2 == MPCA_STATUS_OK && s3 == MPCA_STATUS_OK) {
            /* A step between the two stats calls makes the pair useless,
             * not wrong: only equal counts pin the hash to a step. */
            if (a.step == b.step && r->readings < ROUNDS * 4) {
                r->step[r->readings] = a.step;
                r->hash[r->readings] = h;
                r->readings++;
            } else {
                r->torn++;
            }
        }
        pthread_mutex_lock(&r->lock);
        r->rounds++;
        pthread_mutex_unlock(&r->lock);
        r->busy += (s1 == MPCA_STATUS_BUSY) + (s2 == MPCA_STATUS_BUSY) + (s3 == MPCA_STATUS_BUSY);
        r->other += (s1 != MPCA_STATUS_OK && s1 != MPCA_STATUS_BUSY) + (s2 != MPCA_STATUS_OK && s2 != MPCA_STATUS_BUSY) +
                    (s3 != MPCA_STATUS_OK && s3 != MPCA_STATUS_BUSY);
    }
    return NULL;
}

static unsigned rounds_of(struct reader *r) {
    unsigned n;
    pthread_mutex_lock(&r->lock);
    n = r->rounds;
    pthread_mutex_unlock(&r->lock);
    return n;
}

static void readers_and_steps(void) {
    static struct reader r;
    static uint64_t seen[ROUNDS + 1];
    struct flag done;
    mpca_desc d;
    mpca_world *w = NULL;
    pthread_t thread;
    unsigned steps = 0, busy = 0, other = 0, i, matched = 0;
    check_context = "readers and steps";
    gas_desc(&d);
    CHECK_OK(mpca_world_create(&d, &w));
    if (w == NULL) {
        return;
    }
    fill(w);
    CHECK_OK(mpca_world_hash(w, &seen[0]));
    flag_init(&done);
    memset(&r, 0, sizeof r);
    pthread_mutex_init(&r.lock, NULL);
    r.world = w;
    r.done = &done;
    if (pthread_create(&thread, NULL, read_loop, &r) != 0) {
        CHECK(0);
        return;
    }
    /* Every third step serial, the rest parallel: both change the world. */
    while (steps < ROUNDS && busy < PATIENCE) {
        mpca_status s = steps % 3 == 2 ? mpca_world_step(w, 1) : mpca_world_step_parallel(w, 1, 4, run_here, NULL);
        if (s == MPCA_STATUS_OK) {
            steps++;
            /* Read beside the reader: a read never refuses a read. */
            s = mpca_world_hash(w, &seen[steps]);
            other += s != MPCA_STATUS_OK;
            /* A pause between steps, as a program's frame has, in which
             * the reader reads three times in a row: until it has finished
             * a round begun after this step (the one under way may have
             * begun before). Without it the reader's three calls outlast
             * the main thread's one on a loaded machine, and a step
             * refuses the third every time. */
            {
                unsigned start = rounds_of(&r), spins = 0;
                while (rounds_of(&r) < start + 2 && spins++ < PATIENCE) {
                    sched_yield();
                }
            }
        } else if (s == MPCA_STATUS_BUSY) {
            busy++;
        } else {
            other++;
        }
    }
    flag_raise(&done);
    pthread_join(thread, NULL);
    for (i = 0; i < r.readings; i++) {
        if (r.step[i] <= ROUNDS && r.hash[i] == seen[r.step[i]]) {
            matched++;
        }
    }
    CHECK(other == 0 && r.other == 0);
    /* Nothing else changes the world: a step waits for the reads. */
    CHECK(busy == 0);
    CHECK(step_of(w) == ROUNDS);
    CHECK(r.readings > 0);
    CHECK(matched == r.readings);
    CHECK_OK(mpca_world_destroy(w));
    printf("threads: readers and steps: %u steps (%u refused BUSY), %u readings all at a step's hash: %s, %u torn, %u "
           "reads refused BUSY\n",
           steps, busy, r.readings, matched == r.readings ? "yes" : "no", r.torn, r.busy);
}

/* ---- Memory in use, from a task and from another thread ----------------- */

/* What the probe tries on the stepped world, and what came back. */
struct probe {
    mpca_world *world;   /* the stepped world, in `memory` */
    mpca_world *owned;   /* a world from mpca_world_create, stepped too */
    unsigned char *memory;
    size_t len;
    const mpca_desc *desc;
    const void *image;
    size_t image_len;
    mpca_status seen[8];
    mpca_world *made[4]; /* handles the refused calls must not write */
};

enum { PROBES = 8 };
static const char *const PROBE_NAMES[PROBES] = {
    "init over its memory",  "init over a part of it",   "init_from_image over it", "init_from_image at an offset",
    "load into it",          "deinit it",                "destroy it (owned)",       "step_parallel it again",
};

static void try_all(struct probe *p) {
    size_t half = p->len / 2;
    unsigned k;
    for (k = 0; k < 4; k++) {
        p->made[k] = NULL;
    }
    p->seen[0] = mpca_world_init(p->desc, p->memory, p->len, &p->made[0]);
    p->seen[1] = mpca_world_init(p->desc, p->memory + 64, p->len, &p->made[1]);
    p->seen[2] = mpca_world_init_from_image(p->image, p->image_len, p->memory, p->len, &p->made[2]);
    p->seen[3] = mpca_world_init_from_image(p->image, p->image_len, p->memory + half, p->len, &p->made[3]);
    p->seen[4] = mpca_world_load(p->world, p->image, p->image_len);
    p->seen[5] = mpca_world_deinit(p->world);
    p->seen[6] = mpca_world_destroy(p->owned);
    p->seen[7] = mpca_world_step_parallel(p->world, 1, 2, run_here, NULL);
}

static void *try_all_thread(void *arg) {
    try_all(arg);
    return NULL;
}

/* run_tasks that first tries everything, on this thread or another, then
 * runs the tasks. The owned world's run_tasks only runs its tasks, but
 * while `p` is in one, it destroys from here. */
struct host {
    struct probe *probe;
    int other_thread;
    int tried;
};

static void probing_host(mpca_world *world, uint64_t ticket, uint32_t count, void *user_data) {
    struct host *h = user_data;
    if (!h->tried) {
        h->tried = 1;
        if (h->other_thread) {
            pthread_t t;
            if (pthread_create(&t, NULL, try_all_thread, h->probe) == 0) {
                pthread_join(t, NULL);
            }
        } else {
            try_all(h->probe);
        }
    }
    run_here(world, ticket, count, NULL);
}

/* The owned world is held busy by a step of its own whose host steps the
 * caller-memory world: so both are inside a call when try_all runs. */
struct nested {
    struct probe *probe;
    struct host *inner;
    mpca_status inner_step;
    int stepped;
};

static void nesting_host(mpca_world *world, uint64_t ticket, uint32_t count, void *user_data) {
    struct nested *n = user_data;
    if (!n->stepped) {
        n->stepped = 1;
        n->inner_step = mpca_world_step_parallel(n->probe->world, 1, 3, probing_host, n->inner);
    }
    run_here(world, ticket, count, NULL);
}

static void memory_in_use(void) {
    mpca_desc d;
    size_t bytes = 0, image_len = 0;
    unsigned char *memory;
    void *image;
    mpca_world *w = NULL, *owned = NULL, *twin = NULL;
    uint64_t want = 0, want_owned = 0, h = 0;
    int other;
    check_context = "memory in use";
    gas_desc(&d);
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    /* Room for the offset inits to fit past the world's end. */
    memory = malloc(bytes * 2);
    CHECK_OK(mpca_world_init(&d, memory, bytes, &w));
    CHECK_OK(mpca_world_create(&d, &owned));
    CHECK_OK(mpca_world_create(&d, &twin));
    if (memory == NULL || w == NULL || owned == NULL || twin == NULL) {
        CHECK(0);
        return;
    }
    fill(w);
    fill(owned);
    fill(twin);
    CHECK_OK(mpca_world_save(w, NULL, 0, &image_len));
    image = malloc(image_len);
    CHECK_OK(mpca_world_save(w, image, image_len, &image_len));
    for (other = 0; other < 2; other++) {
        struct probe p;
        struct host inner;
        struct nested outer;
        unsigned k;
        memset(&p, 0, sizeof p);
        p.world = w;
        p.owned = owned;
        p.memory = memory;
        p.len = bytes;
        p.desc = &d;
        p.image = image;
        p.image_len = image_len;
        memset(&inner, 0, sizeof inner);
        inner.probe = &p;
        inner.other_thread = other;
        memset(&outer, 0, sizeof outer);
        outer.probe = &p;
        outer.inner = &inner;
        /* The owned world steps; its host steps w; w's host tries. */
        CHECK_OK(mpca_world_step_parallel(owned, 1, 2, nesting_host, &outer));
        check_status(outer.inner_step, MPCA_STATUS_OK, "the stepped world's step, from the owned world's host", __FILE__,
                     __LINE__);
        CHECK(inner.tried == 1);
        for (k = 0; k < PROBES; k++) {
            if (p.seen[k] != MPCA_STATUS_BUSY) {
                printf("FAILED [memory in use] %s, from %s: status %d, not BUSY\n", PROBE_NAMES[k],
                       other ? "another thread" : "the task's host", (int)p.seen[k]);
                check_true(0, "BUSY", __FILE__, __LINE__);
            }
        }
        for (k = 0; k < 4; k++) {
            CHECK(p.made[k] == NULL);
        }
        /* Both worlds stepped once more, exactly as a serial step does. */
        CHECK_OK(mpca_world_step(twin, 1));
        CHECK_OK(mpca_world_hash(twin, &want));
        CHECK_OK(mpca_world_hash(w, &h));
        CHECK(h == want);
        CHECK_OK(mpca_world_hash(owned, &want_owned));
        CHECK(want_owned == want);
        printf("threads: memory in use, from %s: %u calls refused BUSY\n", other ? "another thread" : "the task's host",
               PROBES);
    }
    /* Once idle, the same calls work: the memory is free to reuse. */
    CHECK(step_of(w) == 2);
    {
        mpca_world *again = NULL;
        CHECK_OK(mpca_world_init_from_image(image, image_len, memory, bytes, &again));
        CHECK(mpca_world_hash(w, &h) == MPCA_STATUS_BAD_HANDLE);
        CHECK(again != NULL && step_of(again) == 0);
        CHECK_OK(mpca_world_deinit(again));
    }
    CHECK_OK(mpca_world_destroy(owned));
    CHECK_OK(mpca_world_destroy(twin));
    free(image);
    free(memory);
}

/* ---- Ending a world another thread is using ----------------------------- */

enum end_by { BY_INIT, BY_DEINIT, BY_DESTROY, ENDS };
static const char *const END_NAMES[ENDS] = {"init over it", "deinit", "destroy"};

struct user {
    mpca_world *world;
    struct flag *stop; /* raised only if the world never ends */
    int reading; /* hash instead of step */
    unsigned ok, busy, other;
    mpca_status last;
};

static void *use_until_dead(void *arg) {
    struct user *u = arg;
    while (!flag_is_up(u->stop)) {
        uint64_t h = 0;
        mpca_status s = u->reading ? mpca_world_hash(u->world, &h) : mpca_world_step(u->world, 1);
        /* A pause between calls, as a program has: a call that ends the
         * world is refused while any call is inside, so it needs one. */
        sched_yield();
        if (s == MPCA_STATUS_OK) {
            u->ok++;
        } else if (s == MPCA_STATUS_BUSY) {
            u->busy++;
        } else {
            u->last = s;
            if (s != MPCA_STATUS_BAD_HANDLE) {
                u->other++;
            }
            return NULL;
        }
    }
    return NULL;
}

static void ending_a_world_in_use(void) {
    mpca_desc d;
    size_t bytes = 0;
    unsigned char *memory;
    unsigned by, round, rounds = 40;
    check_context = "ending a world in use";
    gas_desc(&d);
    CHECK_OK(mpca_world_bytes(&d, &bytes));
    memory = malloc(bytes);
    if (memory == NULL) {
        CHECK(0);
        return;
    }
    for (by = 0; by < ENDS; by++) {
        unsigned refused = 0, stepped_new = 0, used = 0;
        for (round = 0; round < rounds; round++) {
            struct user u;
            pthread_t thread;
            struct flag stop;
            mpca_world *w = NULL, *fresh = NULL;
            mpca_status s;
            if (by == BY_DESTROY) {
                CHECK_OK(mpca_world_create(&d, &w));
            } else {
                CHECK_OK(mpca_world_init(&d, memory, bytes, &w));
            }
            if (w == NULL) {
                return;
            }
            fill(w);
            memset(&u, 0, sizeof u);
            flag_init(&stop);
            u.world = w;
            u.stop = &stop;
            u.reading = round % 2;
            if (pthread_create(&thread, NULL, use_until_dead, &u) != 0) {
                CHECK(0);
                return;
            }
            do {
                s = by == BY_INIT ? mpca_world_init(&d, memory, bytes, &fresh)
                    : by == BY_DEINIT ? mpca_world_deinit(w)
                                      : mpca_world_destroy(w);
                refused += s == MPCA_STATUS_BUSY;
            } while (s == MPCA_STATUS_BUSY && refused < PATIENCE);
            CHECK(s == MPCA_STATUS_OK);
            if (s != MPCA_STATUS_OK) {
                flag_raise(&stop);
            }
            pthread_join(thread, NULL);
            used += u.ok;
            CHECK(u.other == 0 && u.last == MPCA_STATUS_BAD_HANDLE);
            if (fresh != NULL) {
                /* Built while no call was inside the old world, and never
                 * stepped since: the old handle reaches nothing. */
                size_t n = 1;
                stepped_new += step_of(fresh) != 0;
                CHECK_OK(mpca_world_particle_count(fresh, &n));
                CHECK(n == 0);
                CHECK_OK(mpca_world_deinit(fresh));
            }
        }
        CHECK(stepped_new == 0);
        printf("threads: ending a world in use by %s: %u rounds, %u calls made first, %u refused BUSY, new worlds "
               "stepped: %u\n",
               END_NAMES[by], rounds, used, refused, stepped_new);
    }
    free(memory);
}

/* --- Details per thread ------------------------------------------------ */

#define DETAIL_ROUNDS 20000

/* A thread's refusals: a description refused for `field`, whose detail
 * mpca_last_error must give back each time. */
struct refuser {
    mpca_desc desc;
    const char *field;
    const char *before; /* the detail before its first refusal */
    unsigned wrong;     /* refusals whose status or detail was another */
};

/* Runs on two threads at once: no check.c calls (its counters are not
 * shared), what it saw goes into `r`. */
static void *refuse_loop(void *arg) {
    struct refuser *r = arg;
    r->before = mpca_last_error();
    for (unsigned i = 0; i < DETAIL_ROUNDS; i++) {
        mpca_status s = mpca_desc_validate(&r->desc);
        const char *d = mpca_last_error();
        r->wrong += s == MPCA_STATUS_OK || strcmp(d, r->field) != 0;
    }
    return NULL;
}

static void details_per_thread(void) {
    check_context = "details per thread";
    struct refuser odd, flat;
    memset(&odd, 0, sizeof odd);
    memset(&flat, 0, sizeof flat);
    gas_desc(&odd.desc);
    odd.desc.size[1] = 7;
    odd.field = "desc.size[1]";
    gas_desc(&flat.desc);
    flat.desc.dim = 4;
    flat.field = "desc.dim";
    pthread_t other;
    CHECK(pthread_create(&other, NULL, refuse_loop, &flat) == 0);
    refuse_loop(&odd);
    CHECK(pthread_join(other, NULL) == 0);
    /* The main thread refused before (memory in use); the other had not. */
    CHECK(strcmp(flat.before, "") == 0);
    CHECK(odd.wrong == 0 && flat.wrong == 0);
    /* The other thread's refusals left this thread's as it was. */
    CHECK(strcmp(mpca_last_error(), "desc.size[1]") == 0);
    printf("threads: details per thread: %u refusals each, %u read back wrong\n", DETAIL_ROUNDS, odd.wrong + flat.wrong);
}

int main(void) {
    check_begin();
    readers_and_steps();
    memory_in_use();
    ending_a_world_in_use();
    details_per_thread();
    return check_end();
}
