/* A program that uses an installed libmpca (scripts/check-install.sh copies
 * it out of the source tree and builds it with pkg-config, CMake and plain
 * cc). Prints one line, which every build must print alike. */
#include <stdio.h>

#include "mpca.h"

int main(void) {
    mpca_desc d;
    mpca_world *w = NULL;
    size_t n = 0;
    uint64_t hash = 0;
    mpca_status s = mpca_desc_defaults(&d, 2, 32, 32, 0);
    d.seed = 5;
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = -0.02f;
    d.boundary[1][0] = d.boundary[1][1] = MPCA_BOUNDARY_WALL;
    if (s == MPCA_STATUS_OK) s = mpca_world_create(&d, &w);
    for (uint32_t x = 0; x < 32 && s == MPCA_STATUS_OK; x += 2) {
        uint32_t pos[3] = {x, 20, 0};
        float v[3] = {0.25f, 0.0f, 0.0f};
        s = mpca_world_add_particle(w, pos, v);
    }
    if (s == MPCA_STATUS_OK) s = mpca_world_step(w, 50);
    if (s == MPCA_STATUS_OK) s = mpca_world_particle_count(w, &n);
    if (s == MPCA_STATUS_OK) s = mpca_world_hash(w, &hash);
    mpca_world_destroy(w);
    if (s != MPCA_STATUS_OK) {
        fprintf(stderr, "mpca: %s\n", mpca_status_message(s));
        return 1;
    }
    printf("mpca %s: %zu particles, hash %016llx\n", mpca_version(), n, (unsigned long long)hash);
    return 0;
}
