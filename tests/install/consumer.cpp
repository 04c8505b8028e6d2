/* consumer.c's world through the C++ wrapper, mpca.hpp: the same line. */
#include <cstdio>

#include "mpca.hpp"

int main() {
    try {
        mpca_desc d = mpca::desc_2d(32, 32);
        d.seed = 5;
        d.forces = MPCA_FORCE_UNIFORM;
        d.gravity[1] = -0.02f;
        d.boundary[1][0] = d.boundary[1][1] = MPCA_BOUNDARY_WALL;
        mpca::world w(d);
        for (std::uint32_t x = 0; x < 32; x += 2) {
            w.add_particle({x, 20, 0}, {0.25f, 0.0f, 0.0f});
        }
        w.step(50);
        std::printf("mpca %s: %zu particles, hash %016llx\n", mpca::version(), w.particle_count(),
                    static_cast<unsigned long long>(w.hash()));
    } catch (const mpca::error &e) {
        std::fprintf(stderr, "mpca: %s\n", e.what());
        return 1;
    }
    return 0;
}
