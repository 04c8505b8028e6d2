/*
 * An hourglass through include/mpca.hpp, the C++11 wrapper; no graphics.
 * Grains poured in at the top of a walled 128 x 128 box fall through the
 * gap between two slanted walls and pile up on the floor. Every few steps
 * the box is printed as text from its density (density_u8); at the end,
 * the statistics and the world's hash.
 *
 *   cpp_example [--steps N] [--threads N] [--every N] [--version] [--help]
 *
 * Each step runs in tasks on std::threads (step_parallel): the library
 * starts no thread, this program's host does. The hash is the same for
 * every --threads (and equals that of mpca_world_step), so the printout
 * ends the same way on any machine.
 */
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "mpca.hpp"

namespace {

const std::uint32_t SIZE = 128;
const std::uint32_t COLUMNS = 64, ROWS = 32; // the text picture

/* The host: `threads` std::threads take the step's tasks from a shared
 * counter. Started anew each step for brevity; threads.c keeps a pool. */
struct thread_host {
    unsigned threads;

    void operator()(const mpca::tasks &t) const {
        std::atomic<std::uint32_t> next(0);
        std::atomic<bool> refused(false);
        auto work = [&t, &next, &refused]() {
            for (std::uint32_t i = next++; i < t.count(); i = next++) {
                if (t.run(i) != MPCA_STATUS_OK) {
                    refused = true; // not thrown: an exception may not leave a thread
                }
            }
        };
        std::vector<std::thread> helpers;
        for (unsigned k = 1; k < threads; k++) {
            helpers.push_back(std::thread(work));
        }
        work();
        for (std::thread &h : helpers) {
            h.join();
        }
        if (refused) {
            throw std::runtime_error("a task was refused");
        }
    }
};

mpca::world build() {
    mpca_desc d = mpca::desc_2d(SIZE, SIZE);
    d.seed = 2026;
    for (int k = 0; k < 2; k++) {
        d.boundary[k][0] = d.boundary[k][1] = MPCA_BOUNDARY_WALL;
    }
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = -0.02f;
    d.restitution = 0.5f;
    d.wall_restitution = 0.3f;
    d.collisions = MPCA_COLLISIONS_SPEED_LIMITED;
    d.contacts = 1;
    d.obstacles = 1;
    d.surface_capacity = 1024;
    d.emitter_capacity = 1;
    mpca::world w(d);

    // Two walls slanting down to a gap of 8 cells in the middle.
    const float e = 0.3f;
    for (std::uint32_t x = 0; x < SIZE / 2 - 4; x++) {
        const float y = 64.0f + 0.5f * static_cast<float>(SIZE / 2 - 4 - x);
        w.add_box({static_cast<float>(x), y, 0.0f}, {static_cast<float>(x) + 0.9f, y + 1.9f, 0.0f}, e);
        const float xr = static_cast<float>(SIZE - 1 - x);
        w.add_box({xr, y, 0.0f}, {xr + 0.9f, y + 1.9f, 0.0f}, e);
    }

    // Grains poured in across the top, three a step on average.
    mpca_emitter pour = mpca_emitter();
    pour.min[0] = 16;
    pour.min[1] = SIZE - 8;
    pour.max[0] = SIZE - 16;
    pour.max[1] = SIZE - 2;
    pour.rate = 3.0f;
    pour.velocity[1] = -0.2f;
    pour.spread = 0.1f;
    pour.mass = 1.0f;
    w.add_emitter(pour);
    return w;
}

void print_picture(const mpca::world &w) {
    const char shades[] = " .:-=+*#%@";
    const std::vector<std::uint8_t> bins = w.density_u8({COLUMNS, ROWS, 1});
    std::string line;
    for (std::uint32_t row = ROWS; row-- > 0;) { // top row first
        line.assign(1, '|');
        for (std::uint32_t col = 0; col < COLUMNS; col++) {
            const std::uint8_t v = bins[row * COLUMNS + col];
            line += shades[v == 0 ? 0 : 1 + v * 8 / 255];
        }
        line += '|';
        std::puts(line.c_str());
    }
}

bool parse(const char *text, unsigned long long max, unsigned long long *out) {
    if (text == nullptr || *text < '0' || *text > '9') {
        return false;
    }
    char *end = nullptr;
    const unsigned long long v = std::strtoull(text, &end, 10);
    if (*end != '\0' || v > max) {
        return false;
    }
    *out = v;
    return true;
}

void usage(const char *name, std::FILE *f) {
    std::fprintf(f,
                 "usage: %s [--steps N] [--threads N] [--every N] [--version] [--help]\n"
                 "An hourglass of grains through mpca.hpp, printed as text.\n"
                 "  --steps N    steps to run (default 600)\n"
                 "  --threads N  threads that run each step's tasks, 1 to 16 (default 2)\n"
                 "  --every N    print the box every N steps, 0 for only the end (default 200)\n"
                 "  --version    print the program's and libmpca's versions and exit\n"
                 "  --help       print this and exit\n",
                 name);
}

} // namespace

int main(int argc, char **argv) {
    unsigned long long steps = 600, threads = 2, every = 200;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *value = i + 1 < argc ? argv[i + 1] : nullptr;
        bool ok = true;
        if (std::strcmp(a, "--version") == 0) {
            std::printf("cpp_example (libmpca %s)\n", mpca::version());
            return 0;
        } else if (std::strcmp(a, "--help") == 0 || std::strcmp(a, "-h") == 0) {
            usage(argv[0], stdout);
            return 0;
        } else if (std::strcmp(a, "--steps") == 0) {
            ok = parse(value, 1000000, &steps);
        } else if (std::strcmp(a, "--threads") == 0) {
            ok = parse(value, 16, &threads) && threads >= 1;
        } else if (std::strcmp(a, "--every") == 0) {
            ok = parse(value, 1000000, &every);
        } else {
            std::fprintf(stderr, "cpp_example: unknown option '%s'\n", a);
            usage(argv[0], stderr);
            return 2;
        }
        if (!ok) {
            std::fprintf(stderr, "cpp_example: bad or missing value for %s\n", a);
            usage(argv[0], stderr);
            return 2;
        }
        i++;
    }

    try {
        mpca::world w = build();
        const thread_host host = {static_cast<unsigned>(threads)};
        for (unsigned long long done = 0; done < steps;) {
            const unsigned long long n = every > 0 && steps - done > every ? every : steps - done;
            w.step_parallel(n, 4 * static_cast<std::uint32_t>(threads), host);
            done += n;
            if (every > 0 || done == steps) {
                std::printf("step %llu: %zu grains\n", done, w.particle_count());
                print_picture(w);
            }
        }
        const mpca_stats s = w.stats();
        std::printf("steps=%llu particles=%llu emitted=%llu collisions=%llu threads=%llu hash=%016llx\n",
                    static_cast<unsigned long long>(s.step), static_cast<unsigned long long>(s.particles),
                    static_cast<unsigned long long>(s.emitted), static_cast<unsigned long long>(s.collisions), threads,
                    static_cast<unsigned long long>(w.hash()));
    } catch (const mpca::error &e) {
        std::fprintf(stderr, "cpp_example: mpca: %s (status %u)\n", e.what(), static_cast<unsigned>(e.status()));
        return 1;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "cpp_example: %s\n", e.what());
        return 1;
    }
    return 0;
}
