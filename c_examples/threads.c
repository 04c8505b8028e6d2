/*
 * A 1024 x 1024 gas stepped on N POSIX threads with the parallel step
 * (M11), against the serial step.
 *
 *   threads [--threads N] [--steps S] [--version]
 *
 * libmpca starts no thread of its own. mpca_world_step_parallel calls
 * run_tasks() below once per step; run_tasks lends the step's tasks to a
 * pool of threads that this program owns (started once, reused for every
 * step), which run them with mpca_world_step_task, and returns when all are
 * done. The two worlds must end with the same hash: the program exits 1
 * otherwise.
 *
 * Prints: "serial ms_per_step=..", "threads=N ms_per_step=.. speedup=..",
 * "hash serial=.. parallel=.. equal=yes|no".
 */
#define _POSIX_C_SOURCE 200809L
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mpca.h"

#define SIZE 1024
#define MAX_THREADS 64

/* ---- A pool of worker threads that run one step's tasks at a time ---- */

struct pool {
    pthread_mutex_t lock;
    pthread_cond_t work; /* a batch of tasks is ready, or the pool ends */
    pthread_cond_t done; /* the batch's last task returned */
    pthread_t threads[MAX_THREADS];
    unsigned count;
    /* The batch: tasks [next, total) of `ticket` on `world` are not taken
     * yet; `running` were taken and have not returned. */
    mpca_world *world;
    uint64_t ticket;
    uint32_t next, total, running;
    unsigned long batch;
    int quit;
};

/* Takes and runs tasks of the current batch until none is left. Called
 * with the lock held; returns with it held. */
static void drain(struct pool *p) {
    while (p->next < p->total) {
        uint32_t task = p->next++;
        mpca_world *world = p->world;
        uint64_t ticket = p->ticket;
        p->running++;
        pthread_mutex_unlock(&p->lock);
        mpca_status s = mpca_world_step_task(world, ticket, task);
        if (s != MPCA_STATUS_OK) {
            fprintf(stderr, "threads: task %u: %s\n", task, mpca_status_message(s));
        }
        pthread_mutex_lock(&p->lock);
        if (--p->running == 0 && p->next >= p->total) {
            pthread_cond_broadcast(&p->done);
        }
    }
}

static void *worker(void *arg) {
    struct pool *p = arg;
    unsigned long seen = 0;
    pthread_mutex_lock(&p->lock);
    for (;;) {
        while (!p->quit && p->batch == seen) {
            pthread_cond_wait(&p->work, &p->lock);
        }
        if (p->quit) {
            break;
        }
        seen = p->batch;
        drain(p);
    }
    pthread_mutex_unlock(&p->lock);
    return NULL;
}

/* mpca_run_tasks: hand the step's tasks to the pool, take part in running
 * them, and return when every one has returned. */
static void run_tasks(mpca_world *world, uint64_t ticket, uint32_t count, void *user_data) {
    struct pool *p = user_data;
    pthread_mutex_lock(&p->lock);
    p->world = world;
    p->ticket = ticket;
    p->next = 0;
    p->total = count;
    p->batch++;
    pthread_cond_broadcast(&p->work);
    drain(p);
    while (p->running > 0 || p->next < p->total) {
        pthread_cond_wait(&p->done, &p->lock);
    }
    pthread_mutex_unlock(&p->lock);
}

/* Starts `n - 1` workers: the thread that steps the world is the n-th. */
static int pool_start(struct pool *p, unsigned n) {
    memset(p, 0, sizeof *p);
    pthread_mutex_init(&p->lock, NULL);
    pthread_cond_init(&p->work, NULL);
    pthread_cond_init(&p->done, NULL);
    for (p->count = 0; p->count + 1 < n; p->count++) {
        if (pthread_create(&p->threads[p->count], NULL, worker, p) != 0) {
            return -1;
        }
    }
    return 0;
}

static void pool_stop(struct pool *p) {
    unsigned i;
    pthread_mutex_lock(&p->lock);
    p->quit = 1;
    pthread_cond_broadcast(&p->work);
    pthread_mutex_unlock(&p->lock);
    for (i = 0; i < p->count; i++) {
        pthread_join(p->threads[i], NULL);
    }
    pthread_cond_destroy(&p->done);
    pthread_cond_destroy(&p->work);
    pthread_mutex_destroy(&p->lock);
}

/* ---- The world ----------------------------------------------------------- */

static uint32_t next_random(uint64_t *s) {
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*s >> 33);
}

static float unit(uint64_t *s) {
    return (float)(next_random(s) >> 8) / 16777216.0f;
}

/* A periodic 1024 x 1024 gas, one particle in ten cells, e = 0.5. */
static mpca_world *gas(void) {
    mpca_desc d;
    mpca_world *w = NULL;
    uint64_t s = 7;
    uint32_t x, y;
    if (mpca_desc_defaults(&d, 2, SIZE, SIZE, 0) != MPCA_STATUS_OK) {
        return NULL;
    }
    d.restitution = 0.5f;
    d.seed = 11;
    if (mpca_world_create(&d, &w) != MPCA_STATUS_OK) {
        return NULL;
    }
    for (y = 0; y < SIZE; y++) {
        for (x = 0; x < SIZE; x++) {
            if (unit(&s) < 0.1f) {
                uint32_t pos[3] = {x, y, 0};
                float v[3] = {0.7f * (unit(&s) - 0.5f), 0.7f * (unit(&s) - 0.5f), 0};
                mpca_world_add_particle(w, pos, v);
            }
        }
    }
    return w;
}

static double seconds(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int main(int argc, char **argv) {
    unsigned threads = 2;
    uint64_t steps = 50, hs = 0, hp = 0;
    size_t particles = 0;
    struct pool pool;
    int i;
    for (i = 1; i < argc; i++) {
        if (strcmp(argv[i], "--version") == 0) {
            printf("threads (libmpca %s)\n", mpca_version());
            return 0;
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            threads = (unsigned)strtoul(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
            steps = strtoull(argv[++i], NULL, 10);
        } else {
            fprintf(stderr, "usage: %s [--threads N] [--steps S] [--version]\n", argv[0]);
            return 2;
        }
    }
    if (threads < 1 || threads > MAX_THREADS) {
        fprintf(stderr, "threads: --threads must be 1 to %d\n", MAX_THREADS);
        return 2;
    }

    mpca_world *serial = gas(), *parallel = gas();
    if (serial == NULL || parallel == NULL) {
        fprintf(stderr, "threads: could not build the worlds\n");
        return 1;
    }
    mpca_world_particle_count(serial, &particles);
    printf("world %ux%u particles=%zu steps=%llu\n", SIZE, SIZE, particles, (unsigned long long)steps);

    double t0 = seconds();
    mpca_world_step(serial, steps);
    double serial_s = seconds() - t0;

    if (pool_start(&pool, threads) != 0) {
        fprintf(stderr, "threads: could not start the threads\n");
        return 1;
    }
    t0 = seconds();
    /* Four tasks a thread, so that a thread that finishes early takes more. */
    mpca_status s = mpca_world_step_parallel(parallel, steps, 4 * threads, run_tasks, &pool);
    double parallel_s = seconds() - t0;
    pool_stop(&pool);
    if (s != MPCA_STATUS_OK) {
        fprintf(stderr, "threads: mpca_world_step_parallel: %s\n", mpca_status_message(s));
        return 1;
    }

    mpca_world_hash(serial, &hs);
    mpca_world_hash(parallel, &hp);
    printf("serial ms_per_step=%.3f\n", 1e3 * serial_s / (double)steps);
    printf("threads=%u ms_per_step=%.3f speedup=%.2f\n", threads, 1e3 * parallel_s / (double)steps, serial_s / parallel_s);
    printf("hash serial=%016llx parallel=%016llx equal=%s\n", (unsigned long long)hs, (unsigned long long)hp,
           hs == hp ? "yes" : "no");
    mpca_world_destroy(serial);
    mpca_world_destroy(parallel);
    return hs == hp ? 0 : 1;
}
