/*
 * Following particles from step to step by their ids (M6b), as an engine
 * does to draw them between steps: after every step, export the world's
 * particles, sort them by id and match them with the last step's, so each
 * has the cell it came from and the cell it is in (engine.h, `moving`).
 *
 *   follower f;
 *   follow_start(&f, world);        the particles as they are, not moving
 *   mpca_world_step(world, 1);
 *   follow_step(&f, world);         after every step
 *   ... f.particles, f.count ...
 *   follow_free(&f);
 *
 * The world needs ids (MPCA_IDENTITY_IDS); ages and tags are read when it
 * has them. A particle new in this step (its id unseen) has not moved; one
 * that moved more than a cell, round a periodic edge, jumps instead of
 * sliding across the world. Particles come out in id order, so the oldest
 * first.
 */
#ifndef MPCA_EXAMPLES_FOLLOW_H
#define MPCA_EXAMPLES_FOLLOW_H

#include <stddef.h>
#include <stdint.h>

#include "engine.h"
#include "mpca.h"

typedef struct follower {
    moving *particles;        /* this step's, in id order */
    size_t count;
    double mean_speed;        /* of the stored velocities, this step */
    uint64_t matched, appeared; /* totals over the run: seen the step before, new */
    struct follow_state *state;
} follower;

void follow_start(follower *f, const mpca_world *w);
void follow_step(follower *f, const mpca_world *w);
void follow_free(follower *f);

#endif /* MPCA_EXAMPLES_FOLLOW_H */
