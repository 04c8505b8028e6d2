/*
 * include/mpca.hpp, the C++11 wrapper, tried against the C ABI it wraps
 * (built with -std=c++11 -Wall -Wextra -Wpedantic -Werror and run by
 * tests/tests/c_abi.rs):
 *
 * - ownership: mpca::world moves and never copies; the world a moved-from,
 *   reassigned, reset or destroyed object held is gone (its handle is
 *   refused by the library);
 * - errors: every refusal throws mpca::error with the status, the detail
 *   mpca_last_error gives (for some, the field it must name) and the two
 *   as what(), and changes nothing;
 * - the wrapper gives what the C calls give: a scene built both ways
 *   hashes equal, and the exports are the same bytes;
 * - step_parallel with a lambda, a std::function on two std::threads, a
 *   host that throws (the step completes, the exception comes back, no
 *   later step runs) and misused tasks;
 * - the rest: worlds in caller memory, snapshots, region counters, force
 *   fields, potentials, the vortex, single obstacle cells and masks, each
 *   against the C call;
 * - every function: the address of the wrapper of each function of mpca.h,
 *   printed as "wraps: NAME" (c_abi.rs holds the names to the header's).
 *
 * Prints "sanitizer: address" or "none" first (as the C programs do),
 * "cpp: GROUP" for each group it finished and "cpp checks: N
 * failed: M" last; exits 1 if any check failed.
 */
/* First, so that the test fails if mpca.hpp does not include what it uses. */
#include "mpca.hpp"

#include <atomic>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

/* As tests/c/check.c: GCC says __SANITIZE_ADDRESS__, Clang __has_feature. */
#if defined(__SANITIZE_ADDRESS__)
#define CPP_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CPP_ASAN 1
#endif
#endif

static unsigned checks, failed;

static void check_true(bool ok, const char *what, int line) {
    checks++;
    if (!ok) {
        failed++;
        std::printf("FAILED line %d: %s\n", line, what);
    }
}
#define CHECK(cond) check_true((cond), #cond, __LINE__)

/* What mpca::error's what() must be: the status's message, then the
 * detail where it is not that message. */
static std::string what_of(mpca_status status, const char *detail) {
    std::string t = mpca_status_message(status);
    return t == detail ? t : t + ": " + detail;
}

/* `call` must throw mpca::error with status `want`, the detail this
 * thread's last refusal has (which `named`, unless NULL, must be), and
 * the two as what(). */
#define THROWS_AT(want, named, call)                                                                   \
    do {                                                                                                \
        bool thrown_ = false;                                                                           \
        const char *named_ = (named);                                                                 \
        try {                                                                                           \
            call;                                                                                       \
        } catch (const mpca::error &e_) {                                                               \
            thrown_ = true;                                                                             \
            check_true(e_.status() == (want), #call ": the status", __LINE__);                          \
            check_true(std::strcmp(e_.detail(), mpca_last_error()) == 0, #call ": the detail", __LINE__); \
            check_true(named_ == nullptr || std::strcmp(e_.detail(), named_) == 0, #call ": names " #named, \
                       __LINE__);                                                                       \
            check_true(e_.what() == what_of((want), e_.detail()), #call ": what()", __LINE__);          \
        }                                                                                               \
        check_true(thrown_, #call " throws mpca::error", __LINE__);                                     \
    } while (0)
#define THROWS(want, call) THROWS_AT(want, nullptr, call)

static_assert(!std::is_copy_constructible<mpca::world>::value, "a world is not copied");
static_assert(!std::is_copy_assignable<mpca::world>::value, "a world is not copied");
static_assert(std::is_nothrow_move_constructible<mpca::world>::value, "a world moves");
static_assert(std::is_nothrow_move_assignable<mpca::world>::value, "a world moves");
static_assert(std::is_base_of<std::runtime_error, mpca::error>::value, "mpca::error is a std::runtime_error");

/* Whether the library still knows the handle. */
static bool alive(mpca_world *w) {
    std::uint64_t h = 0;
    return mpca_world_hash(w, &h) == MPCA_STATUS_OK;
}

/* A walled 2D box under gravity with a row of particles: the scene built
 * through the wrapper and through the C functions alike. */
static mpca_desc box_desc() {
    mpca_desc d = mpca::desc_2d(32, 32);
    d.seed = 11;
    for (int k = 0; k < 2; k++) {
        d.boundary[k][0] = d.boundary[k][1] = MPCA_BOUNDARY_WALL;
    }
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = -0.02f;
    d.restitution = 0.7f;
    d.per_particle_mass = 1;
    d.mass_classes = 2;
    return d;
}

static float speed(std::uint32_t x) { return 0.1f * static_cast<float>(x % 7) - 0.3f; }

static void fill_box(mpca::world &w) {
    for (std::uint32_t x = 2; x < 30; x++) {
        for (std::uint32_t y = 20; y < 24; y++) {
            if (x % 3 == 0) {
                w.add_particle({x, y, 0}, {speed(x), 0.1f, 0.0f}, 2.0f);
            } else {
                w.add_particle({x, y, 0}, {speed(x), -0.1f, 0.0f});
            }
        }
    }
}

static void ownership() {
    const mpca_desc d = box_desc();
    mpca_world *held = nullptr;
    {
        mpca::world a(d);
        held = a.get();
        CHECK(a && held != nullptr && alive(held));
    }
    CHECK(!alive(held)); /* the destructor destroyed it */

    mpca::world a(d);
    mpca_world *raw_a = a.get();
    mpca::world b(std::move(a));
    CHECK(!a && a.get() == nullptr && b.get() == raw_a && alive(raw_a));
    THROWS(MPCA_STATUS_NULL_POINTER, a.step(1));
    THROWS(MPCA_STATUS_NULL_POINTER, a.hash());

    mpca::world c(d);
    mpca_world *raw_c = c.get();
    c = std::move(b); /* c's own world is destroyed, a's moves in */
    CHECK(!alive(raw_c) && c.get() == raw_a && !b && alive(raw_a));
    mpca::world &same = c;
    c = std::move(same); /* self-move keeps the world */
    CHECK(c.get() == raw_a && alive(raw_a));
    c.reset();
    CHECK(!c && !alive(raw_a));
    c.reset(); /* empty: nothing to do */
    std::printf("cpp: ownership\n");
}

static void errors() {
    mpca_desc odd = mpca::desc_2d(32, 32);
    odd.size[0] = 31;
    THROWS_AT(MPCA_STATUS_SIZE_ODD, "desc.size[0]", mpca::world w(odd));
    /* mpca_desc_defaults takes any size; the world refuses it. */
    const mpca_desc zero = mpca::desc_3d(0, 0, 0);
    THROWS_AT(MPCA_STATUS_SIZE_ZERO, "desc.size[0]", mpca::world w(zero));

    mpca::world w(box_desc());
    fill_box(w);
    const std::uint64_t before = w.hash();
    THROWS_AT(MPCA_STATUS_OUT_OF_BOUNDS, "pos", w.add_particle({32, 0, 0}, {0.0f, 0.0f, 0.0f}));
    THROWS(MPCA_STATUS_CELL_OCCUPIED, w.add_particle({2, 20, 0}, {0.0f, 0.0f, 0.0f}));
    THROWS_AT(MPCA_STATUS_SPEED_RANGE, "velocity", w.add_particle({1, 1, 0}, {1.5f, 0.0f, 0.0f}));
    THROWS_AT(MPCA_STATUS_MASS_RANGE, "mass", w.add_particle({1, 1, 0}, {0.0f, 0.0f, 0.0f}, -1.0f));
    CHECK(std::strcmp(w.last_error(), "mass") == 0 && std::strcmp(mpca::last_error(), "mass") == 0);
    THROWS(MPCA_STATUS_NO_PARTICLE, w.remove_particle({1, 1, 0}));
    THROWS(MPCA_STATUS_NOT_FINITE, w.set_gravity({0.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f}));
    THROWS(MPCA_STATUS_BAD_RESOLUTION, w.density({0, 4, 1}));
    THROWS(MPCA_STATUS_BAD_RESOLUTION, w.density_u8({4, 4, 2}));
    THROWS_AT(MPCA_STATUS_NOT_ENABLED, "desc.obstacles", w.add_disc(16.0f, 16.0f, 4.0f, 1.0f)); /* no obstacles in this world */
    THROWS(MPCA_STATUS_OUT_OF_BOUNDS, w.set_emitter_rate(0, 1.0f)); /* no emitter 0 */
    THROWS(MPCA_STATUS_BAD_EMITTER, w.set_emitter_rate(0, -1.0f));
    THROWS_AT(MPCA_STATUS_NOT_ENABLED, "desc.drag.field", w.set_cell_wind({1, 1, 0}, {0.1f, 0.0f, 0.0f})); /* no wind plane */
    CHECK(w.hash() == before);
    /* hash() succeeded: the world's detail is cleared, the thread's kept. */
    CHECK(*w.last_error() == '\0' && std::strcmp(mpca::last_error(), "desc.drag.field") == 0);

    /* Caught as what it derives from, too. */
    bool caught = false;
    try {
        w.add_particle({0, 32, 0}, {0.0f, 0.0f, 0.0f});
    } catch (const std::exception &e) {
        caught = std::string(e.what()) == what_of(MPCA_STATUS_OUT_OF_BOUNDS, "pos");
    }
    CHECK(caught && w.hash() == before);
    std::printf("cpp: errors\n");
}

/* The same scene through mpca.h alone. */
static mpca_world *box_in_c() {
    mpca_desc d = box_desc();
    mpca_world *w = nullptr;
    CHECK(mpca_world_create(&d, &w) == MPCA_STATUS_OK);
    for (std::uint32_t x = 2; x < 30; x++) {
        for (std::uint32_t y = 20; y < 24; y++) {
            std::uint32_t pos[3] = {x, y, 0};
            float v[3] = {speed(x), x % 3 == 0 ? 0.1f : -0.1f, 0.0f};
            mpca_status s = x % 3 == 0 ? mpca_world_add_particle_mass(w, pos, v, 2.0f) : mpca_world_add_particle(w, pos, v);
            CHECK(s == MPCA_STATUS_OK);
        }
    }
    return w;
}

static void same_as_c() {
    mpca::world w(box_desc());
    fill_box(w);
    mpca_world *c = box_in_c();
    w.step(40);
    CHECK(mpca_world_step(c, 40) == MPCA_STATUS_OK);

    std::uint64_t hash_c = 0;
    CHECK(mpca_world_hash(c, &hash_c) == MPCA_STATUS_OK);
    CHECK(w.hash() == hash_c);
    mpca_stats sc;
    std::memset(&sc, 0, sizeof sc);
    sc.struct_size = sizeof sc;
    CHECK(mpca_world_stats(c, &sc) == MPCA_STATUS_OK);
    const mpca_stats sw = w.stats();
    CHECK(sw.step == 40 && sw.particles == sc.particles && sw.collisions == sc.collisions && sc.collisions > 0);
    CHECK(sw.particles == 4 * 28 && w.particle_count() == sw.particles);
    CHECK(w.desc().seed == 11);

    const std::size_t n = w.particle_count();
    std::vector<float> pos_c(3 * n), vel_c(3 * n), mass_c(n);
    std::size_t count = 0;
    CHECK(mpca_world_export_positions(c, pos_c.data(), n, &count) == MPCA_STATUS_OK && count == n);
    CHECK(mpca_world_export_velocities(c, vel_c.data(), n, &count) == MPCA_STATUS_OK && count == n);
    CHECK(mpca_world_export_masses(c, mass_c.data(), n, &count) == MPCA_STATUS_OK && count == n);
    CHECK(w.positions() == pos_c);
    CHECK(w.velocities() == vel_c);
    CHECK(w.masses() == mass_c);

    /* The caller's buffer: the size query, too small (untouched), enough. */
    CHECK(w.export_positions(nullptr, 0) == n);
    CHECK(w.export_masses(nullptr, 0) == n);
    std::vector<float> buffer(3 * n, -7.0f);
    CHECK(w.export_velocities(buffer.data(), n - 1) == n);
    CHECK(buffer == std::vector<float>(3 * n, -7.0f));
    CHECK(w.export_velocities(buffer.data(), n) == n && buffer == vel_c);
    {
        /* One pass, the same order: the columns are the twins' exports. */
        std::vector<float> pos_all(3 * n), vel_all(3 * n);
        mpca_particle_columns columns = mpca_particle_columns();
        CHECK(w.export_particles(columns, 0) == n); /* the size query */
        columns.positions = pos_all.data();
        columns.velocities = vel_all.data();
        CHECK(w.export_particles(columns, n - 1) == n);
        CHECK(w.export_particles(columns, n) == n && pos_all == pos_c && vel_all == vel_c);
        std::vector<std::uint32_t> ids(n);
        columns.ids = ids.data();
        THROWS(MPCA_STATUS_NOT_ENABLED, w.export_particles(columns, n)); /* a world without ids */
        THROWS(MPCA_STATUS_NOT_ENABLED, w.set_tag(mpca::cell_pos{{0, 0, 0}}, 1u));
        THROWS(MPCA_STATUS_NOT_ENABLED, w.set_emitter_tag(0, 1));
    }

    /* Density at the world's resolution is the occupancy. */
    std::vector<float> occupancy = w.density({32, 32, 1});
    double sum = 0;
    for (std::size_t i = 0; i < occupancy.size(); i++) {
        sum += occupancy[i];
    }
    CHECK(occupancy.size() == 32 * 32 && sum == static_cast<double>(n));
    std::vector<std::uint8_t> bytes = w.density_u8({4, 4, 1});
    CHECK(bytes.size() == 16);

    /* A particle removed from both: the worlds stay equal. */
    const std::uint32_t at[3] = {static_cast<std::uint32_t>(pos_c[0]), static_cast<std::uint32_t>(pos_c[1]), 0};
    mpca_particle pc;
    CHECK(mpca_world_remove_particle(c, at, &pc) == MPCA_STATUS_OK);
    const mpca_cell before = w.cell({at[0], at[1], 0});
    const mpca_particle pw = w.remove_particle({at[0], at[1], 0});
    CHECK(before.kind == MPCA_CELL_KIND_PARTICLE && std::memcmp(&pw, &pc, sizeof pw) == 0);
    CHECK(w.cell({at[0], at[1], 0}).kind == MPCA_CELL_KIND_EMPTY);
    CHECK(mpca_world_hash(c, &hash_c) == MPCA_STATUS_OK && w.hash() == hash_c);
    CHECK(mpca_world_destroy(c) == MPCA_STATUS_OK);

    /* Obstacles, emitters and gravity through the wrapper. */
    mpca_desc d = mpca::desc_2d(32, 32);
    d.obstacles = 1;
    d.surface_capacity = 256;
    d.emitter_capacity = 1;
    d.forces = MPCA_FORCE_UNIFORM;
    mpca::world o(d);
    o.add_disc(16.0f, 12.0f, 4.0f, 0.8f);
    o.add_box({0.0f, 0.0f, 0.0f}, {31.9f, 1.9f, 0.0f}, 0.5f);
    o.add_half_space({0.0f, 30.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, 0.5f);
    o.set_gravity({0.0f, -0.01f, 0.0f});
    mpca_emitter e = mpca_emitter();
    e.min[0] = 4;
    e.min[1] = 20;
    e.max[0] = 28;
    e.max[1] = 24;
    e.rate = 2.0f;
    e.mass = 1.0f;
    CHECK(o.add_emitter(e) == 0);
    o.step(10);
    o.set_emitter_rate(0, 0.0f);
    o.step(5);
    CHECK(o.stats().emitted == 20 && o.cell({16, 12, 0}).kind == MPCA_CELL_KIND_OBSTACLE);
    /* Rate 2 for 10 steps, then 0: 20 asked for, all placed. */
    CHECK(o.emitter_stats(0).requested == 20 && o.emitter_stats(0).delivered == 20);
    THROWS(MPCA_STATUS_OUT_OF_BOUNDS, o.emitter_stats(1));
    mpca_desc d3 = mpca::desc_3d(16, 16, 16);
    d3.obstacles = 1;
    d3.surface_capacity = 512;
    /* A sphere sized before its world is made: the description's count
     * is the world's, and the shape's wrapper adds what add_sphere adds. */
    mpca_shape ball = mpca_shape();
    ball.kind = MPCA_SHAPE_KIND_SPHERE;
    ball.a[0] = ball.a[1] = ball.a[2] = 8.0f;
    ball.radius = 3.0f;
    const std::uint32_t entries = mpca::surface_entries(d3, ball);
    CHECK(entries > 0 && entries <= 512);
    mpca::world s(d3);
    CHECK(s.surface_entries(ball) == entries);
    s.add_sphere({8.0f, 8.0f, 8.0f}, 3.0f, 1.0f);
    CHECK(s.surface_entries(ball) == 0);
    ball.a[0] = 12.0f; /* overlapping: only the cells not yet covered */
    CHECK(s.surface_entries(ball) < entries);
    s.add_shape(ball, 1.0f);
    ball.kind = 9;
    THROWS(MPCA_STATUS_BAD_ENUM, s.add_shape(ball, 1.0f));
    CHECK(s.cell({8, 8, 8}).kind == MPCA_CELL_KIND_OBSTACLE && std::strcmp(mpca::version(), mpca_version()) == 0);

    /* Bodies (M13): a capsule added over a particle pushes it out; moved,
     * its tally is read; an id that names no body throws. */
    mpca_desc db = mpca::desc_2d(16, 16);
    db.obstacles = 1;
    db.body_capacity = 1;
    db.body_surface_capacity = 64;
    mpca::world b(db);
    b.add_particle({5, 5, 0}, {0.0f, 0.0f, 0.0f});
    mpca_shape paddle = mpca_shape();
    paddle.kind = MPCA_SHAPE_KIND_CAPSULE;
    paddle.a[0] = 5.5f;
    paddle.a[1] = 3.0f;
    paddle.b[0] = 5.5f;
    paddle.b[1] = 8.0f;
    paddle.radius = 0.6f;
    CHECK(mpca::body_surface_entries(db, paddle) > 0);
    const std::uint32_t id = b.add_body(paddle, {0.5f, 0.0f, 0.0f}, 1.0f);
    CHECK(b.cell({5, 5, 0}).kind == MPCA_CELL_KIND_OBSTACLE && b.particle_count() == 1);
    b.step(1);
    CHECK(b.body_stats(id).pushed == 1);
    paddle.a[0] = paddle.b[0] = 6.5f;
    b.move_body(id, paddle, {0.5f, 0.0f, 0.0f});
    THROWS(MPCA_STATUS_NO_BODY, b.move_body(id + 1, paddle, {0.0f, 0.0f, 0.0f}));
    b.remove_body(id);
    THROWS(MPCA_STATUS_NO_BODY, b.body_stats(id));

    /* The wind plane (M5.1b): a particle at rest in a wind of (0.5, 0)
     * with drag k = 1 moves off along +x; a wind too fast is refused. */
    mpca_desc dw = mpca::desc_2d(16, 16);
    dw.drag_rate = 1.0f;
    dw.drag_wind_field = 1;
    mpca::world wind(dw);
    std::vector<float> plane(16 * 16 * 2, 0.0f);
    for (std::size_t i = 0; i < plane.size(); i += 2) plane[i] = 0.5f;
    wind.set_wind_field(plane);
    wind.add_particle({8, 8, 0}, {0.0f, 0.0f, 0.0f});
    wind.set_cell_wind({8, 8, 0}, {0.5f, 0.0f, 0.0f});
    const std::uint64_t calm = wind.hash();
    plane[7] = 1.5f;
    THROWS(MPCA_STATUS_SPEED_RANGE, wind.set_wind_field(plane));
    THROWS(MPCA_STATUS_SPEED_RANGE, wind.set_cell_wind({8, 8, 0}, {0.0f, -1.01f, 0.0f}));
    CHECK(wind.hash() == calm);
    wind.step(1);
    CHECK(wind.velocities()[0] > 0.2f);
    std::printf("cpp: same as C\n");
}

static void parallel() {
    mpca::world serial(box_desc()), forward(box_desc()), threaded(box_desc());
    fill_box(serial);
    fill_box(forward);
    fill_box(threaded);
    serial.step(30);

    /* A lambda host: a loop on this thread. */
    unsigned calls = 0;
    forward.step_parallel(30, 8, [&calls](const mpca::tasks &t) {
        calls++;
        for (std::uint32_t i = 0; i < t.count(); i++) {
            t(i);
        }
    });
    CHECK(calls == 30 && forward.hash() == serial.hash());

    /* A std::function host on two std::threads, odd and even tasks. */
    std::atomic<unsigned> refused(0);
    std::function<void(const mpca::tasks &)> two_threads = [&refused](const mpca::tasks &t) {
        auto half = [&refused, &t](std::uint32_t first) {
            for (std::uint32_t i = first; i < t.count(); i += 2) {
                if (t.run(i) != MPCA_STATUS_OK) {
                    refused++;
                }
            }
        };
        std::thread other(half, 1);
        half(0);
        other.join();
    };
    threaded.step_parallel(30, 7, two_threads);
    CHECK(refused == 0 && threaded.hash() == serial.hash());

    /* Misuse inside a host: a task twice, an index past the count, another
     * call on the world; a task kept past its step. */
    mpca::world misused(box_desc());
    fill_box(misused);
    std::vector<mpca::tasks> kept;
    misused.step_parallel(1, 4, [&misused, &kept](const mpca::tasks &t) {
        kept.push_back(t);
        t(0);
        THROWS(MPCA_STATUS_TASK_DONE, t(0));
        THROWS(MPCA_STATUS_TASK_INDEX, t(t.count()));
        THROWS(MPCA_STATUS_BUSY, misused.step(1));
        THROWS(MPCA_STATUS_BUSY, misused.hash());
    });
    CHECK(kept.size() == 1 && kept[0].run(0) == MPCA_STATUS_STALE_TASK);
    mpca::world one(box_desc());
    fill_box(one);
    one.step(1);
    CHECK(misused.hash() == one.hash()); /* tasks the host skipped were run */

    /* A host that throws in its third step: that step completes, the
     * exception comes back, and the other seven steps are not taken. */
    mpca::world thrower(box_desc());
    fill_box(thrower);
    unsigned hosted = 0;
    std::string message;
    try {
        thrower.step_parallel(10, 4, [&hosted](const mpca::tasks &t) {
            if (++hosted == 3) {
                t(1);
                throw std::runtime_error("the host gave up");
            }
            for (std::uint32_t i = 0; i < t.count(); i++) {
                t(i);
            }
        });
    } catch (const std::runtime_error &e) {
        message = e.what();
    }
    mpca::world three(box_desc());
    fill_box(three);
    three.step(3);
    CHECK(message == "the host gave up" && hosted == 3);
    CHECK(thrower.stats().step == 3 && thrower.hash() == three.hash());
    thrower.step(1); /* and the world goes on */
    three.step(1);
    CHECK(thrower.hash() == three.hash());
    std::printf("cpp: parallel\n");
}

/* A walled 2D world with every force and obstacles, filled the same way
 * through the wrapper and through mpca.h. */
static mpca_desc forces_desc() {
    mpca_desc d = box_desc();
    d.forces = MPCA_FORCE_UNIFORM | MPCA_FORCE_FIELD | MPCA_FORCE_POTENTIAL | MPCA_FORCE_VORTEX;
    d.vortex_centre[0] = d.vortex_centre[1] = 16.0f;
    d.vortex_core_radius = 3.0f;
    d.vortex_circulation = 0.5f;
    d.obstacles = 1;
    d.surface_capacity = 64;
    return d;
}

static void the_rest() {
    /* Caller memory: mpca_world_bytes, init, deinit on reset. */
    const mpca_desc d = box_desc();
    mpca::validate(d);
    mpca_desc odd = d;
    odd.size[0] = 31;
    THROWS(MPCA_STATUS_SIZE_ODD, mpca::validate(odd));
    THROWS(MPCA_STATUS_SIZE_ODD, mpca::world_bytes(odd));
    const std::size_t bytes = mpca::world_bytes(d);
    std::size_t c_bytes = 0;
    CHECK(mpca_world_bytes(&d, &c_bytes) == MPCA_STATUS_OK && bytes == c_bytes);
    std::vector<unsigned char> memory(bytes + 1);
    THROWS(MPCA_STATUS_BUFFER_TOO_SMALL, mpca::world::init(d, memory.data(), bytes / 2));
    mpca_world *raw = nullptr;
    std::vector<std::uint8_t> image;
    std::uint64_t hash = 0;
    {
        /* At an odd address: any alignment is accepted. */
        mpca::world w = mpca::world::init(d, memory.data() + 1, bytes);
        raw = w.get();
        fill_box(w);
        w.step(10);
        hash = w.hash();
        image = w.save();
        CHECK(image.size() == w.snapshot_bytes());
        THROWS(MPCA_STATUS_OUTPUT_TOO_SMALL, w.save(image.data(), image.size() - 1));
        const mpca_region_stats all = w.region_stats({0, 0, 0}, {32, 32, 1});
        CHECK(all.particles == w.particle_count());
        THROWS(MPCA_STATUS_BAD_SHAPE, w.region_stats({4, 4, 0}, {2, 8, 1}));
    }
    CHECK(!alive(raw)); /* deinitialised by the destructor */

    /* The image back: a world in fresh memory, and one loaded into. */
    const mpca_desc from_image = mpca::desc_from_image(image.data(), image.size());
    CHECK(std::memcmp(&from_image.size, &d.size, sizeof d.size) == 0);
    THROWS(MPCA_STATUS_IMAGE_LENGTH, mpca::desc_from_image(image.data(), image.size() - 1));
    std::vector<unsigned char> other(mpca::world_bytes(from_image));
    mpca::world copy = mpca::world::init_from_image(image.data(), image.size(), other.data(), other.size());
    CHECK(copy.hash() == hash);
    mpca::world loaded(d);
    loaded.load(image);
    CHECK(loaded.hash() == hash);
    copy.step(5);
    loaded.step(5);
    CHECK(copy.hash() == loaded.hash());
    image[image.size() / 2] ^= 1;
    const std::uint64_t before = loaded.hash();
    THROWS(MPCA_STATUS_IMAGE_CHECKSUM, loaded.load(image));
    CHECK(loaded.hash() == before);

    /* Forces and obstacles: the same calls through mpca.h give the same world. */
    const mpca_desc f = forces_desc();
    mpca::world w(f);
    mpca_world *c = nullptr;
    CHECK(mpca_world_create(&f, &c) == MPCA_STATUS_OK);
    std::vector<float> field(2 * 32 * 32), potential(32 * 32);
    std::vector<std::uint8_t> mask(32 * 32);
    for (std::size_t i = 0; i < potential.size(); i++) {
        field[2 * i] = 0.001f * static_cast<float>(i % 5);
        potential[i] = 0.01f * static_cast<float>(i % 32);
        mask[i] = (i / 32 >= 4 && i / 32 < 6 && i % 32 >= 20 && i % 32 < 26) ? 1 : 0;
    }
    const std::uint32_t cell[3] = {3, 3, 0}, wall[3] = {10, 8, 0};
    const float force[3] = {0.0f, 0.01f, 0.0f}, normal[3] = {0.0f, 1.0f, 0.0f};
    w.set_force_field(field);
    CHECK(mpca_world_set_force_field(c, field.data(), field.size()) == MPCA_STATUS_OK);
    w.set_cell_force({3, 3, 0}, {0.0f, 0.01f, 0.0f});
    CHECK(mpca_world_set_cell_force(c, cell, force) == MPCA_STATUS_OK);
    w.set_potential(potential);
    CHECK(mpca_world_set_potential(c, potential.data(), potential.size()) == MPCA_STATUS_OK);
    w.set_cell_potential({3, 3, 0}, 0.5f);
    CHECK(mpca_world_set_cell_potential(c, cell, 0.5f) == MPCA_STATUS_OK);
    w.set_vortex(12.0f, 14.0f, 2.0f, -0.3f);
    CHECK(mpca_world_set_vortex(c, 12.0f, 14.0f, 2.0f, -0.3f) == MPCA_STATUS_OK);
    w.add_obstacle({10, 8, 0}, {0.0f, 1.0f, 0.0f}, 0.9f);
    CHECK(mpca_world_add_obstacle(c, wall, normal, 0.9f) == MPCA_STATUS_OK);
    w.add_obstacle_mask(mask, 0.8f);
    CHECK(mpca_world_add_obstacle_mask(c, mask.data(), mask.size(), 0.8f) == MPCA_STATUS_OK);
    const mpca::surface s = w.surface({10, 8, 0});
    CHECK(s.normal[1] == 1.0f && s.restitution == 0.9f);
    THROWS(MPCA_STATUS_NOT_A_SURFACE, w.surface({1, 1, 0}));
    THROWS(MPCA_STATUS_NOT_FINITE, w.set_cell_potential({3, 3, 0}, std::numeric_limits<float>::infinity()));
    fill_box(w);
    for (std::uint32_t x = 2; x < 30; x++) {
        for (std::uint32_t y = 20; y < 24; y++) {
            std::uint32_t pos[3] = {x, y, 0};
            float v[3] = {speed(x), x % 3 == 0 ? 0.1f : -0.1f, 0.0f};
            CHECK((x % 3 == 0 ? mpca_world_add_particle_mass(c, pos, v, 2.0f) : mpca_world_add_particle(c, pos, v)) ==
                  MPCA_STATUS_OK);
        }
    }
    w.step(30);
    CHECK(mpca_world_step(c, 30) == MPCA_STATUS_OK);
    std::uint64_t c_hash = 0;
    CHECK(mpca_world_hash(c, &c_hash) == MPCA_STATUS_OK && w.hash() == c_hash);
    mpca_world_destroy(c);
    std::printf("cpp: the rest\n");
}

/* `wrapper` is the wrapper of `c_function`: its address is taken and the
 * name printed. A constructor has no address: WRAPS_CONSTRUCTOR checks it
 * exists for the arguments. */
#define WRAPS(c_function, wrapper)                          \
    do {                                                    \
        (void)&c_function;                                  \
        CHECK((wrapper) != nullptr);                        \
        std::printf("wraps: %s\n", #c_function);            \
    } while (0)
#define WRAPS_CONSTRUCTOR(c_function, type, ...)            \
    do {                                                    \
        (void)&c_function;                                  \
        CHECK((std::is_constructible<type, __VA_ARGS__>::value)); \
        std::printf("wraps: %s\n", #c_function);            \
    } while (0)

static void every_function() {
    typedef mpca::world W;
    typedef std::function<void(const mpca::tasks &)> host;
    WRAPS(mpca_version, &mpca::version);
    WRAPS(mpca_last_error, &mpca::last_error);
    WRAPS(mpca_world_last_error, &W::last_error);
    WRAPS(mpca_desc_defaults, &mpca::desc_2d);
    WRAPS(mpca_desc_defaults, &mpca::desc_3d);
    WRAPS(mpca_desc_preset, &mpca::preset);
    WRAPS(mpca_desc_validate, &mpca::validate);
    WRAPS(mpca_desc_from_image, &mpca::desc_from_image);
    WRAPS_CONSTRUCTOR(mpca_status_message, mpca::error, mpca_status);
    WRAPS(mpca_world_bytes, &mpca::world_bytes);
    WRAPS_CONSTRUCTOR(mpca_world_create, W, const mpca_desc &);
    WRAPS(mpca_world_destroy, &W::reset);
    WRAPS(mpca_world_init, &W::init);
    WRAPS(mpca_world_init_from_image, &W::init_from_image);
    WRAPS(mpca_world_deinit, &W::reset);
    WRAPS(mpca_world_add_particle, static_cast<void (W::*)(const mpca::cell_pos &, const mpca::vec3 &)>(&W::add_particle));
    WRAPS(mpca_world_add_particle_mass,
          static_cast<void (W::*)(const mpca::cell_pos &, const mpca::vec3 &, float)>(&W::add_particle));
    WRAPS(mpca_world_remove_particle, &W::remove_particle);
    WRAPS(mpca_world_cell, &W::cell);
    WRAPS(mpca_world_particle_count, &W::particle_count);
    WRAPS(mpca_world_step, &W::step);
    WRAPS(mpca_world_step_parallel, &W::step_parallel<host &>);
    WRAPS(mpca_world_step_task, &mpca::tasks::run);
    WRAPS(mpca_world_stats, &W::stats);
    WRAPS(mpca_world_hash, &W::hash);
    WRAPS(mpca_world_desc, &W::desc);
    WRAPS(mpca_world_export_positions, &W::export_positions);
    WRAPS(mpca_world_export_velocities, &W::export_velocities);
    WRAPS(mpca_world_export_masses, &W::export_masses);
    WRAPS(mpca_world_export_particles, &W::export_particles);
    WRAPS(mpca_world_set_tag, &W::set_tag);
    WRAPS(mpca_world_set_emitter_tag, &W::set_emitter_tag);
    WRAPS(mpca_world_density, &W::density);
    WRAPS(mpca_world_density_u8, &W::density_u8);
    WRAPS(mpca_world_region_stats, &W::region_stats);
    WRAPS(mpca_world_snapshot_bytes, &W::snapshot_bytes);
    WRAPS(mpca_world_save, static_cast<std::size_t (W::*)(void *, std::size_t) const>(&W::save));
    WRAPS(mpca_world_load, static_cast<void (W::*)(const void *, std::size_t)>(&W::load));
    WRAPS(mpca_world_set_gravity, &W::set_gravity);
    WRAPS(mpca_world_set_wind_field, &W::set_wind_field);
    WRAPS(mpca_world_set_cell_wind, &W::set_cell_wind);
    WRAPS(mpca_world_set_force_field, &W::set_force_field);
    WRAPS(mpca_world_set_cell_force, &W::set_cell_force);
    WRAPS(mpca_world_set_potential, &W::set_potential);
    WRAPS(mpca_world_set_cell_potential, &W::set_cell_potential);
    WRAPS(mpca_world_set_vortex, &W::set_vortex);
    WRAPS(mpca_world_add_box, &W::add_box);
    WRAPS(mpca_world_add_disc, &W::add_disc);
    WRAPS(mpca_world_add_sphere, &W::add_sphere);
    WRAPS(mpca_world_add_half_space, &W::add_half_space);
    WRAPS(mpca_world_add_obstacle, &W::add_obstacle);
    WRAPS(mpca_world_add_obstacle_mask, &W::add_obstacle_mask);
    WRAPS(mpca_world_surface, &W::surface);
    WRAPS(mpca_world_surface_entries, &W::surface_entries);
    WRAPS(mpca_world_add_shape, &W::add_shape);
    WRAPS(mpca_desc_surface_entries, &mpca::surface_entries);
    WRAPS(mpca_world_add_emitter, &W::add_emitter);
    WRAPS(mpca_world_set_emitter_rate, &W::set_emitter_rate);
    WRAPS(mpca_world_emitter_stats, &W::emitter_stats);
    WRAPS(mpca_world_add_body, &W::add_body);
    WRAPS(mpca_desc_body_surface_entries, &mpca::body_surface_entries);
    WRAPS(mpca_world_move_body, &W::move_body);
    WRAPS(mpca_world_remove_body, &W::remove_body);
    WRAPS(mpca_world_body_stats, &W::body_stats);
    std::printf("cpp: every function\n");
}

int main() {
#if defined(CPP_ASAN)
    std::printf("sanitizer: address\n");
#else
    std::printf("sanitizer: none\n");
#endif
    ownership();
    errors();
    same_as_c();
    parallel();
    the_rest();
    every_function();
    std::printf("cpp checks: %u failed: %u\n", checks, failed);
    return failed == 0 ? 0 : 1;
}
