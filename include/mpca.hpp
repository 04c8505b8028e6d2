/*
 * mpca.hpp: libmpca for C++11, header-only, over the C ABI of mpca.h.
 *
 *   mpca::world w(mpca::desc_2d(64, 64));      // mpca_world_create
 *   w.add_particle({10, 60, 0}, {0.3f, 0.0f, 0.0f});
 *   w.step(100);
 *   std::vector<float> xyz = w.positions();    // 3 floats a particle
 *                                              // ~world: mpca_world_destroy
 *
 * - mpca::world owns one world made by mpca_world_create (hosted builds of
 *   the library) and destroys it in its destructor. It moves and does not
 *   copy; a moved-from world is empty, and calls on it throw the status
 *   MPCA_STATUS_NULL_POINTER.
 * - Every refusal throws mpca::error, which carries the mpca_status, the
 *   detail that names the field or part at fault (mpca_last_error's text,
 *   as detail()), and both as what(): "a world size is odd; Margolus blocks
 *   need even sizes: desc.size[1]". The world is unchanged then, as the C
 *   ABI promises.
 * - Exports come back as std::vector, or go into the caller's buffer
 *   (export_positions and its twins, for a mapped vertex buffer).
 * - step_parallel takes any callable host, a lambda or a std::function,
 *   which runs one step's tasks on the caller's threads (M11).
 * - world::init and world::init_from_image build a world in the caller's
 *   memory instead (mpca_world_init, for builds without an allocator);
 *   the object then ends it with mpca_world_deinit and never frees it.
 *
 * Each method is one call of the C function of the same name, and every
 * function of mpca.h has one (tests/c/cpp_wrapper.cpp takes the address of
 * each); get() gives the mpca_world * all the same.
 */
#ifndef MPCA_HPP
#define MPCA_HPP

#include <array>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "mpca.h"

namespace mpca {

/** A call the library refused: its status, that status's message and the
 * detail naming where the problem is. */
class error : public std::runtime_error {
public:
    /** The refusal of the call this thread just made: `status`, and
     * mpca_last_error's detail. */
    explicit error(mpca_status status) : error(status, mpca_last_error()) {}

    /** A refusal with a detail of the caller's (static text). */
    error(mpca_status status, const char *detail)
        : std::runtime_error(text(status, detail)), status_(status), detail_(detail) {}

    /** The status the C function returned. */
    mpca_status status() const noexcept { return status_; }

    /** The field, argument or part at fault ("desc.size[1]"): static
     * text, never freed. */
    const char *detail() const noexcept { return detail_; }

private:
    /** what(): the status's message, then the detail where it says more
     * (a status without a detail of its own has its message as one). */
    static std::string text(mpca_status status, const char *detail) {
        std::string t = mpca_status_message(status);
        if (detail != nullptr && *detail != '\0' && t != detail) {
            t += ": ";
            t += detail;
        }
        return t;
    }

    mpca_status status_;
    const char *detail_;
};

/** Throws mpca::error unless `status` is MPCA_STATUS_OK. */
inline void check(mpca_status status) {
    if (status != MPCA_STATUS_OK) {
        throw error(status);
    }
}

/** The library's version, "MAJOR.MINOR.PATCH". */
inline const char *version() noexcept { return mpca_version(); }

/** The detail of this thread's last refusal (mpca_last_error); "" while
 * none. mpca::error carries it already. */
inline const char *last_error() noexcept { return mpca_last_error(); }

/** Cell coordinates (the third 0 in 2D). */
typedef std::array<std::uint32_t, 3> cell_pos;
/** A vector: a velocity, a force, a point or a normal (the third 0 in 2D). */
typedef std::array<float, 3> vec3;

/** mpca_desc_defaults for a world of nx x ny cells. */
inline mpca_desc desc_2d(std::uint32_t nx, std::uint32_t ny) {
    mpca_desc d;
    check(mpca_desc_defaults(&d, 2, nx, ny, 0));
    return d;
}

/** mpca_desc_defaults for a world of nx x ny x nz cells. */
inline mpca_desc desc_3d(std::uint32_t nx, std::uint32_t ny, std::uint32_t nz) {
    mpca_desc d;
    check(mpca_desc_defaults(&d, 3, nx, ny, nz));
    return d;
}

/** mpca_desc_preset: a world of nx x ny cells (nz > 0: nx x ny x nz) set
 * up for an effect, MPCA_PRESET_SMOKE, _WATER or _SAND. */
inline mpca_desc preset(mpca_preset effect, std::uint32_t nx, std::uint32_t ny, std::uint32_t nz = 0) {
    mpca_desc d;
    check(mpca_desc_preset(&d, effect, nz > 0 ? 3 : 2, nx, ny, nz));
    return d;
}

/** Checks a description in full, as mpca_world_create will (mpca_desc_validate). */
inline void validate(const mpca_desc &desc) { check(mpca_desc_validate(&desc)); }

/** The bytes of caller memory a world of `desc` needs (mpca_world_bytes). */
inline std::size_t world_bytes(const mpca_desc &desc) {
    std::size_t bytes = 0;
    check(mpca_world_bytes(&desc, &bytes));
    return bytes;
}

/** The surface entries `shape` takes as the first obstacle of a world of
 * `desc` (mpca_desc_surface_entries); sets the shape's struct_size. */
inline std::uint32_t surface_entries(const mpca_desc &desc, mpca_shape shape) {
    shape.struct_size = sizeof shape;
    std::uint32_t entries = 0;
    check(mpca_desc_surface_entries(&desc, &shape, &entries));
    return entries;
}

/** The description of the world a snapshot image holds (mpca_desc_from_image). */
inline mpca_desc desc_from_image(const void *image, std::size_t len) {
    mpca_desc d = mpca_desc();
    check(mpca_desc_from_image(image, len, &d));
    return d;
}

/** The body surface entries a body of `shape` takes alone where it lies,
 * in a world of `desc` (mpca_desc_body_surface_entries); sets the shape's
 * struct_size. */
inline std::uint32_t body_surface_entries(const mpca_desc &desc, mpca_shape shape) {
    shape.struct_size = sizeof shape;
    std::uint32_t entries = 0;
    check(mpca_desc_body_surface_entries(&desc, &shape, &entries));
    return entries;
}

/** An obstacle surface cell: its outward normal and restitution. */
struct surface {
    vec3 normal;
    float restitution;
};

/** What an emitter asked for and placed (world::emitter_stats). */
struct emitter_counts {
    std::uint64_t requested;
    std::uint64_t delivered;
};

/**
 * The tasks of one step of world::step_parallel, as the host receives
 * them: run each index in [0, count()) once, in any order, on any thread;
 * distinct indices may run at the same time.
 */
class tasks {
public:
    tasks(mpca_world *world, std::uint64_t ticket, std::uint32_t count) noexcept
        : world_(world), ticket_(ticket), count_(count) {}

    /** How many tasks this step has. */
    std::uint32_t count() const noexcept { return count_; }

    /** Runs task `index` (mpca_world_step_task); throws mpca::error when
     * refused: run already, index not below count(), or the step is over. */
    void operator()(std::uint32_t index) const { check(run(index)); }

    /** Runs task `index`, returning the status instead of throwing. */
    mpca_status run(std::uint32_t index) const noexcept { return mpca_world_step_task(world_, ticket_, index); }

private:
    mpca_world *world_;
    std::uint64_t ticket_;
    std::uint32_t count_;
};

namespace detail {

/** What mpca_world_step_parallel hands back to run_tasks: the host, how to
 * call it, and an exception it threw, kept until the C call returns. */
struct host_call {
    void *host;
    void (*invoke)(void *host, const tasks &t);
    std::exception_ptr thrown;
};

template <class Host>
void invoke_host(void *host, const tasks &t) {
    (*static_cast<Host *>(host))(t);
}

/* The mpca_run_tasks of every step_parallel. An exception must not unwind
 * through the library, so it is caught here and thrown again once
 * mpca_world_step_parallel has returned. */
extern "C" inline void mpca_hpp_run_tasks(mpca_world *world, std::uint64_t ticket, std::uint32_t count,
                                          void *user_data) noexcept {
    host_call *call = static_cast<host_call *>(user_data);
    try {
        call->invoke(call->host, tasks(world, ticket, count));
    } catch (...) {
        call->thrown = std::current_exception();
    }
}

} // namespace detail

/** A world made by mpca_world_create, destroyed with the object. */
class world {
public:
    /** mpca_world_create; throws mpca::error if `desc` is refused. */
    explicit world(const mpca_desc &desc) : w_(nullptr), in_caller_memory_(false) {
        check(mpca_world_create(&desc, &w_));
    }

    /**
     * An empty world built in `memory` (`len` bytes, at least
     * world_bytes(desc), any alignment) by mpca_world_init. The memory
     * stays the caller's: keep it, unmoved, while the object holds the
     * world, which ends it with mpca_world_deinit.
     */
    static world init(const mpca_desc &desc, void *memory, std::size_t len) {
        mpca_world *w = nullptr;
        check(mpca_world_init(&desc, memory, len, &w));
        return world(w);
    }

    /** The world a snapshot image holds, built in `memory` as init() builds
     * one (mpca_world_init_from_image; size it with
     * world_bytes(desc_from_image(image, image_len))). */
    static world init_from_image(const void *image, std::size_t image_len, void *memory, std::size_t len) {
        mpca_world *w = nullptr;
        check(mpca_world_init_from_image(image, image_len, memory, len, &w));
        return world(w);
    }

    ~world() { reset(); }

    world(world &&other) noexcept : w_(other.w_), in_caller_memory_(other.in_caller_memory_) { other.w_ = nullptr; }

    world &operator=(world &&other) noexcept {
        if (this != &other) {
            reset();
            w_ = other.w_;
            in_caller_memory_ = other.in_caller_memory_;
            other.w_ = nullptr;
        }
        return *this;
    }

    world(const world &) = delete;
    world &operator=(const world &) = delete;

    /** The handle, for the functions of mpca.h this class does not wrap;
     * still owned by this object. NULL when empty. */
    mpca_world *get() const noexcept { return w_; }

    /** The detail of this world's last call if it was refused, "" if it
     * succeeded (mpca_world_last_error). */
    const char *last_error() const noexcept { return mpca_world_last_error(w_); }

    /** Whether this object holds a world (it does until moved from or reset). */
    explicit operator bool() const noexcept { return w_ != nullptr; }

    /** Ends the world now (mpca_world_destroy, or mpca_world_deinit for
     * one in caller memory); the object is empty afterwards. */
    void reset() noexcept {
        if (w_ != nullptr) {
            if (in_caller_memory_) {
                mpca_world_deinit(w_);
            } else {
                mpca_world_destroy(w_);
            }
            w_ = nullptr;
        }
    }

    // --- particles --------------------------------------------------------

    /** A particle of the world's mass (mpca_world_add_particle). */
    void add_particle(const cell_pos &pos, const vec3 &velocity) {
        check(mpca_world_add_particle(w_, pos.data(), velocity.data()));
    }

    /** A particle of mass `mass` (mpca_world_add_particle_mass). */
    void add_particle(const cell_pos &pos, const vec3 &velocity, float mass) {
        check(mpca_world_add_particle_mass(w_, pos.data(), velocity.data(), mass));
    }

    /** Removes the particle at `pos` and returns it. */
    mpca_particle remove_particle(const cell_pos &pos) {
        mpca_particle p = mpca_particle();
        check(mpca_world_remove_particle(w_, pos.data(), &p));
        return p;
    }

    /** What the cell at `pos` holds. */
    mpca_cell cell(const cell_pos &pos) const {
        mpca_cell c = mpca_cell();
        check(mpca_world_cell(w_, pos.data(), &c));
        return c;
    }

    /** The number of particles now. */
    std::size_t particle_count() const {
        std::size_t n = 0;
        check(mpca_world_particle_count(w_, &n));
        return n;
    }

    // --- stepping ----------------------------------------------------------

    /** Advances `steps` steps (mpca_world_step). */
    void step(std::uint64_t steps = 1) { check(mpca_world_step(w_, steps)); }

    /**
     * Advances `steps` steps, each split into at most `max_tasks` tasks
     * (mpca_world_step_parallel): `host(const mpca::tasks &t)` is called
     * once a step and must run t(i) for each i below t.count(), on any of
     * its threads, returning once all have returned. The world is the one
     * step() gives, bit for bit.
     *
     * If the host throws, the step it was in is still completed (the
     * library runs the tasks the host did not), no later step is taken,
     * and the exception is thrown again from here.
     */
    template <class Host>
    void step_parallel(std::uint64_t steps, std::uint32_t max_tasks, Host &&host) {
        typedef typename std::remove_reference<Host>::type host_type;
        detail::host_call call;
        call.host = const_cast<void *>(static_cast<const void *>(std::addressof(host)));
        call.invoke = &detail::invoke_host<host_type>;
        // One C call a step, so that a throw ends the loop after its step.
        for (std::uint64_t s = 0; s < steps; s++) {
            check(mpca_world_step_parallel(w_, 1, max_tasks, &detail::mpca_hpp_run_tasks, &call));
            if (call.thrown) {
                std::rethrow_exception(call.thrown);
            }
        }
    }

    // --- reading the world ---------------------------------------------------

    /** Statistics (mpca_world_stats). */
    mpca_stats stats() const {
        mpca_stats s = mpca_stats();
        s.struct_size = sizeof s;
        check(mpca_world_stats(w_, &s));
        return s;
    }

    /** The hash of every particle (mpca_world_hash). */
    std::uint64_t hash() const {
        std::uint64_t h = 0;
        check(mpca_world_hash(w_, &h));
        return h;
    }

    /** The description the world was built from, with later changes. */
    mpca_desc desc() const {
        mpca_desc d = mpca_desc();
        check(mpca_world_desc(w_, &d));
        return d;
    }

    /** Positions, 3 floats a particle (cell centres), in cell order. */
    std::vector<float> positions() const { return gather(&mpca_world_export_positions, 3); }

    /** Velocities, 3 floats a particle, in the order of positions(). */
    std::vector<float> velocities() const { return gather(&mpca_world_export_velocities, 3); }

    /** Masses, one float a particle, in the order of positions(). */
    std::vector<float> masses() const { return gather(&mpca_world_export_masses, 1); }

    /**
     * Positions into the caller's buffer of `capacity` particles (3 *
     * capacity floats). Returns the particle count; the buffer was filled
     * only if that is not above `capacity`. nullptr with capacity 0 asks
     * for the count alone.
     */
    std::size_t export_positions(float *out, std::size_t capacity) const {
        return fill(&mpca_world_export_positions, out, capacity);
    }

    /** Velocities into the caller's buffer; as export_positions. */
    std::size_t export_velocities(float *out, std::size_t capacity) const {
        return fill(&mpca_world_export_velocities, out, capacity);
    }

    /** Masses into the caller's buffer (one float a particle); as export_positions. */
    std::size_t export_masses(float *out, std::size_t capacity) const {
        return fill(&mpca_world_export_masses, out, capacity);
    }

    /**
     * Every particle, in cell order, into the non-null columns of
     * `columns` (mpca_world_export_particles: positions, velocities, ids,
     * ages, tags, each with room for `capacity` particles); sets its
     * struct_size. Returns the particle count; the columns were filled
     * only if that is not above `capacity`. All columns null with capacity
     * 0 asks for the count alone.
     */
    std::size_t export_particles(mpca_particle_columns columns, std::size_t capacity) const {
        columns.struct_size = sizeof columns;
        std::size_t count = 0;
        mpca_status s = mpca_world_export_particles(w_, &columns, capacity, &count);
        if (s != MPCA_STATUS_OUTPUT_TOO_SMALL) {
            check(s);
        }
        return count;
    }

    /** Gives the particle at `pos` the tag `tag` (mpca_world_set_tag). */
    void set_tag(const cell_pos &pos, std::uint32_t tag) { check(mpca_world_set_tag(w_, pos.data(), tag)); }

    /** The share of occupied cells in each of res[0] x res[1] x res[2]
     * bins (res[2] is 1 in 2D), x fastest (mpca_world_density). */
    std::vector<float> density(const cell_pos &res) const {
        std::vector<float> out(bins(res));
        float none = 0;
        check(mpca_world_density(w_, res.data(), out.empty() ? &none : out.data(), out.size()));
        return out;
    }

    /** As density(), scaled to bytes 0..255 (mpca_world_density_u8). */
    std::vector<std::uint8_t> density_u8(const cell_pos &res) const {
        std::vector<std::uint8_t> out(bins(res));
        std::uint8_t none = 0;
        check(mpca_world_density_u8(w_, res.data(), out.empty() ? &none : out.data(), out.size()));
        return out;
    }

    /** The particles, momentum and kinetic energy in the box of cells
     * min <= c < max (mpca_world_region_stats). */
    mpca_region_stats region_stats(const cell_pos &min, const cell_pos &max) const {
        mpca_region_stats r = mpca_region_stats();
        r.struct_size = sizeof r;
        check(mpca_world_region_stats(w_, min.data(), max.data(), &r));
        return r;
    }

    // --- snapshots (M12) --------------------------------------------------------

    /** The length of the image save() would write now (mpca_world_snapshot_bytes). */
    std::size_t snapshot_bytes() const {
        std::size_t n = 0;
        check(mpca_world_snapshot_bytes(w_, &n));
        return n;
    }

    /** The world's image (mpca_world_save). */
    std::vector<std::uint8_t> save() const {
        std::vector<std::uint8_t> image(snapshot_bytes());
        image.resize(save(image.data(), image.size()));
        return image;
    }

    /** The world's image into the caller's buffer of `len` bytes; returns
     * its length (mpca_world_save; too small a buffer throws
     * MPCA_STATUS_OUTPUT_TOO_SMALL). */
    std::size_t save(void *buf, std::size_t len) const {
        std::size_t written = 0;
        check(mpca_world_save(w_, buf, len, &written));
        return written;
    }

    /** Replaces this world's state with an image of a world of the same
     * plan (mpca_world_load); a refused image changes nothing. */
    void load(const void *image, std::size_t len) { check(mpca_world_load(w_, image, len)); }

    /** As load(image, len), from a vector save() returned. */
    void load(const std::vector<std::uint8_t> &image) { load(image.data(), image.size()); }

    // --- forces, obstacles, emitters ------------------------------------------

    /** The uniform acceleration (mpca_world_set_gravity). */
    void set_gravity(const vec3 &g) { check(mpca_world_set_gravity(w_, g.data())); }

    /** Replaces the wind plane of the flow drag (M5.1b): dim flow velocity
     * components per cell, x fastest, each cell's speed at most 1
     * (mpca_world_set_wind_field). */
    void set_wind_field(const std::vector<float> &wind) {
        check(mpca_world_set_wind_field(w_, wind.data(), wind.size()));
    }

    /** The flow velocity of one cell in the wind plane (mpca_world_set_cell_wind). */
    void set_cell_wind(const cell_pos &pos, const vec3 &u) { check(mpca_world_set_cell_wind(w_, pos.data(), u.data())); }

    /** Replaces the force field: dim components per cell, x fastest
     * (mpca_world_set_force_field). */
    void set_force_field(const std::vector<float> &forces) {
        check(mpca_world_set_force_field(w_, forces.data(), forces.size()));
    }

    /** The force of one cell (mpca_world_set_cell_force). */
    void set_cell_force(const cell_pos &pos, const vec3 &force) {
        check(mpca_world_set_cell_force(w_, pos.data(), force.data()));
    }

    /** Replaces the potential, one value per cell, x fastest (mpca_world_set_potential). */
    void set_potential(const std::vector<float> &u) { check(mpca_world_set_potential(w_, u.data(), u.size())); }

    /** The potential of one cell (mpca_world_set_cell_potential). */
    void set_cell_potential(const cell_pos &pos, float u) { check(mpca_world_set_cell_potential(w_, pos.data(), u)); }

    /** Moves or changes the Rankine vortex (mpca_world_set_vortex). */
    void set_vortex(float cx, float cy, float core_radius, float circulation) {
        check(mpca_world_set_vortex(w_, cx, cy, core_radius, circulation));
    }

    /** One obstacle cell with the given outward normal (mpca_world_add_obstacle). */
    void add_obstacle(const cell_pos &pos, const vec3 &normal, float e) {
        check(mpca_world_add_obstacle(w_, pos.data(), normal.data(), e));
    }

    /** Obstacle cells where `mask`, one byte a cell, x fastest, is not 0
     * (mpca_world_add_obstacle_mask). */
    void add_obstacle_mask(const std::vector<std::uint8_t> &mask, float e) {
        check(mpca_world_add_obstacle_mask(w_, mask.data(), mask.size(), e));
    }

    /** The normal and restitution of the obstacle surface cell at `pos`
     * (mpca_world_surface; MPCA_STATUS_NOT_A_SURFACE if it is none). */
    mpca::surface surface(const cell_pos &pos) const {
        mpca::surface s = mpca::surface();
        check(mpca_world_surface(w_, pos.data(), s.normal.data(), &s.restitution));
        return s;
    }

    /** Obstacle cells with centres in the box min <= c <= max. */
    void add_box(const vec3 &min, const vec3 &max, float e) {
        check(mpca_world_add_box(w_, min.data(), max.data(), e));
    }

    /** An obstacle disc (2D). */
    void add_disc(float cx, float cy, float radius, float e) { check(mpca_world_add_disc(w_, cx, cy, radius, e)); }

    /** An obstacle sphere (3D). */
    void add_sphere(const vec3 &centre, float radius, float e) {
        check(mpca_world_add_sphere(w_, centre.data(), radius, e));
    }

    /** Obstacle cells beyond the plane through `point` with outward `normal`. */
    void add_half_space(const vec3 &point, const vec3 &normal, float e) {
        check(mpca_world_add_half_space(w_, point.data(), normal.data(), e));
    }

    /** The surface entries adding `shape` now takes
     * (mpca_world_surface_entries); sets the shape's struct_size. */
    std::uint32_t surface_entries(mpca_shape shape) const {
        shape.struct_size = sizeof shape;
        std::uint32_t entries = 0;
        check(mpca_world_surface_entries(w_, &shape, &entries));
        return entries;
    }

    /** Adds `shape`'s cells as obstacles (mpca_world_add_shape); sets its
     * struct_size. */
    void add_shape(mpca_shape shape, float e) {
        shape.struct_size = sizeof shape;
        check(mpca_world_add_shape(w_, &shape, e));
    }

    /** Adds an emitter and returns its index; sets its struct_size. */
    std::uint32_t add_emitter(mpca_emitter emitter) {
        emitter.struct_size = sizeof emitter;
        std::uint32_t index = 0;
        check(mpca_world_add_emitter(w_, &emitter, &index));
        return index;
    }

    /** What emitter `index` asked for and placed since it was added
     * (mpca_world_emitter_stats). */
    emitter_counts emitter_stats(std::uint32_t index) const {
        emitter_counts c = emitter_counts();
        check(mpca_world_emitter_stats(w_, index, &c.requested, &c.delivered));
        return c;
    }

    /** Changes the rate of emitter `index`. */
    void set_emitter_rate(std::uint32_t index, float rate) { check(mpca_world_set_emitter_rate(w_, index, rate)); }

    /** Gives the particles emitter `index` places the tag `tag`. */
    void set_emitter_tag(std::uint32_t index, std::uint32_t tag) { check(mpca_world_set_emitter_tag(w_, index, tag)); }

    /** Adds a body, an obstacle the caller moves (mpca_world_add_body), and
     * returns its id; sets the shape's struct_size. */
    std::uint32_t add_body(mpca_shape shape, const vec3 &velocity, float e) {
        shape.struct_size = sizeof shape;
        std::uint32_t id = 0;
        check(mpca_world_add_body(w_, &shape, velocity.data(), e, &id));
        return id;
    }

    /** Gives body `id` a new shape and velocity (mpca_world_move_body);
     * sets the shape's struct_size. */
    void move_body(std::uint32_t id, mpca_shape shape, const vec3 &velocity) {
        shape.struct_size = sizeof shape;
        check(mpca_world_move_body(w_, id, &shape, velocity.data()));
    }

    /** Removes body `id` (mpca_world_remove_body). */
    void remove_body(std::uint32_t id) { check(mpca_world_remove_body(w_, id)); }

    /** What body `id` gave the particles in the last step
     * (mpca_world_body_stats). */
    mpca_body_stats body_stats(std::uint32_t id) const {
        mpca_body_stats s = mpca_body_stats();
        s.struct_size = sizeof s;
        check(mpca_world_body_stats(w_, id, &s));
        return s;
    }

private:
    typedef mpca_status (*export_fn)(const mpca_world *, float *, std::size_t, std::size_t *);

    std::size_t fill(export_fn fn, float *out, std::size_t capacity) const {
        std::size_t count = 0;
        mpca_status s = fn(w_, out, capacity, &count);
        if (s != MPCA_STATUS_OUTPUT_TOO_SMALL) {
            check(s);
        }
        return count;
    }

    std::vector<float> gather(export_fn fn, std::size_t per) const {
        std::size_t count = fill(fn, nullptr, 0); // the size query
        std::vector<float> out(count * per);
        if (count > 0) {
            std::size_t written = 0;
            check(fn(w_, out.data(), count, &written));
        }
        return out;
    }

    static std::size_t bins(const cell_pos &res) {
        std::size_t n = 1;
        for (std::size_t i = 0; i < 3; i++) {
            if (res[i] != 0 && n > std::numeric_limits<std::size_t>::max() / res[i]) {
                throw error(MPCA_STATUS_BAD_RESOLUTION, "res: more bins than a size_t counts");
            }
            n *= res[i];
        }
        return n;
    }

    /** A world mpca_world_init built: deinitialised, never destroyed. */
    explicit world(mpca_world *w) noexcept : w_(w), in_caller_memory_(true) {}

    mpca_world *w_;
    bool in_caller_memory_;
};

} // namespace mpca

#endif /* MPCA_HPP */
