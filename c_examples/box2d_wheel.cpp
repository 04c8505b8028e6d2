/*
 * A water wheel of a rigid-body engine turned by a waterfall of particles
 * (M13, issue 27): Box2D (2.4, its C++ API) owns the wheel, a hub and six
 * blades on a pin joint; the automaton owns the water. Each blade is a
 * body of the automaton's world, and the momentum the falling water hands
 * it pushes the wheel round. Box2D has no liquids; this is one way to give
 * it one.
 *
 * Units. A cell is 5 cm (20 cells a metre) and Box2D steps at 60 Hz, with
 * two automaton steps to each Box2D step: 120 steps a second. The world's
 * 128 x 128 cells are 6.4 m square, a speed of 1 cell per step (the
 * automaton's top speed) is 6 m/s, and gravity, 9.81 m/s^2 in Box2D, is
 * 9.81 / (0.05 x 120^2) = 0.0136 cells per step^2 for the water (the
 * figures of docs/model.md, "Units"). A water particle is 1 kg (mass 1 in
 * the world).
 *
 * Each Box2D step:
 *   1. for each of its two automaton steps, every blade's place and the
 *      velocity of its middle go from Box2D into its body
 *      (mpca::world::move_body; for the second step the wheel's angle is
 *      carried on by its angular velocity); the world steps, and what each
 *      body handed the particles in that step (body_stats().momentum, in
 *      mass times cells per step) is added up;
 *   2. each blade's sum, negated, is an impulse on the wheel at the middle
 *      of the blade, in kg m/s: the sum times 1 kg times 6 m/s. Applied
 *      there rather than at the centre, the impulses turn the wheel: the
 *      library reports a body's momentum, not where it took it, so a body
 *      that must turn is made of parts, each small enough for its middle
 *      to stand for it;
 *   3. Box2D steps 1/60 s (8 velocity and 3 position iterations).
 * A second Box2D world holds the same wheel without the water. Every
 * second the program prints both wheels' speeds in turns a minute and the
 * water's mean torque on the wet one over that second, and at the end the
 * mean torque over the last second (which a steady wheel balances against
 * the load) and the blade tips' speed beside the water's as it reaches the
 * wheel's middle.
 *
 * Why a waterfall and not a pool: under gravity the automaton's water packs
 * every cell of a pool, and its resting particles keep the downward speeds
 * gravity gives them. A body moving into a packed pool finds no free cell
 * within two of the ones it takes, so it removes ("crushes") those
 * particles, and the ones it can push already move away from it, which
 * hands it nothing: a ball dropped into a settled pool falls through it as
 * through air. Moving water is another matter: falling water runs into the
 * blades and bounces off them, and that is the momentum a rigid body needs.
 *
 * The scene: walls on both sides, open at the top and at the floor, so the
 * water drains out through the floor. The wheel (radius 1.2 m, blades 0.1 m
 * thick, 50 kg/m^2, e = 0.5 to the water) turns on a pin at (3.2 m, 2.4 m)
 * whose friction holds back up to 100 N m, the load the water drives. The
 * waterfall, 10 cells wide, leaves a spout 3.7 m up over the right half of
 * the wheel at 0.5 cells per step (3 m/s) down, 3 particles a step, and
 * meets the blades at up to 5.9 m/s, below the top speed; below the wheel
 * it reaches the top speed, where the clamp holds it (a terminal speed).
 * The wheel turns clockwise, so its speeds are negative.
 *
 * Drawn: the wheel in grey where the water last met it, the spout, the
 * walls, the water coloured by speed.
 */
#include <box2d/box2d.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "mpca.hpp"

extern "C" {
#include "scene.h"
}

namespace {

const float CELL_M = 0.05f;    // metres a cell
const int SUBSTEPS = 2;        // automaton steps a Box2D step
const float BOX2D_HZ = 60.0f;  // Box2D steps a second
const float STEPS_PER_S = SUBSTEPS * BOX2D_HZ;
const float TOP_SPEED = CELL_M * STEPS_PER_S; // m/s: one cell per step
const float GRAVITY = 9.81f;   // m/s^2
const float PARTICLE_KG = 1.0f;

// Lengths for REFERENCE_SIZE; at another --size a cell is still 5 cm, so
// the world is smaller, and they shrink with it.
const uint32_t REFERENCE_SIZE = 128;
const float HUB_M[2] = {3.2f, 2.4f};
const float HUB_RADIUS_M = 0.2f;
const float WHEEL_RADIUS_M = 1.2f;
const float BLADE_THICK_M = 0.1f;
const int BLADES = 6;
const float WHEEL_DENSITY = 50.0f; // kg/m^2
const float WHEEL_E = 0.5f;
const float LOAD_N_M = 100.0f;     // the torque the pin's friction holds back, at REFERENCE_SIZE
const float WATER_E = 0.5f;
const float SPOUT_X_M = 3.8f;      // the waterfall's middle: over the right half
const float SPOUT_Y_M = 3.7f;      // so the water meets the wheel below the top speed
const uint32_t SPOUT_CELLS = 10;
const uint32_t SPOUT_ROWS = 2;
const float SPOUT_SPEED = 0.5f;    // cells per step (3 m/s), down
const float SPOUT_RATE = 3.0f;     // particles per step
const float PI_F = 3.14159265358979323846f;

/* The wheel in one Box2D world, and its blades' bodies in the water. */
struct wheel {
    b2Body *body = nullptr;
    std::uint32_t hub_id = 0, blade_ids[BLADES] = {};
    mpca_shape hub = mpca_shape(), blades[BLADES] = {}; // as the water last met them
    double momentum[BLADES][2] = {};                    // handed to the water since the last Box2D step
};

mpca_shape disc(float x, float y, float radius) {
    mpca_shape s = mpca_shape();
    s.struct_size = sizeof s;
    s.kind = MPCA_SHAPE_KIND_DISC;
    s.a[0] = x;
    s.a[1] = y;
    s.radius = radius;
    return s;
}

mpca_shape capsule(float ax, float ay, float bx, float by, float radius) {
    mpca_shape s = mpca_shape();
    s.struct_size = sizeof s;
    s.kind = MPCA_SHAPE_KIND_CAPSULE;
    s.a[0] = ax;
    s.a[1] = ay;
    s.b[0] = bx;
    s.b[1] = by;
    s.radius = radius;
    return s;
}

/* The wheel's sizes at this --size, in metres. */
struct geometry {
    float scale, hub[2], hub_radius, radius, thick;
};

geometry make_geometry(uint32_t size) {
    const float s = static_cast<float>(size) / REFERENCE_SIZE;
    geometry g = {s, {HUB_M[0] * s, HUB_M[1] * s}, HUB_RADIUS_M * s, WHEEL_RADIUS_M * s, BLADE_THICK_M * s};
    // A blade at least two cells thick, so the water cannot pass through it.
    if (g.thick < 2.0f * CELL_M) g.thick = 2.0f * CELL_M;
    return g;
}

/* A hub and BLADES blades on a pin at the hub's centre. */
b2Body *add_wheel(b2World &world, const geometry &g) {
    b2BodyDef ground_def;
    b2Body *ground = world.CreateBody(&ground_def);
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position.Set(g.hub[0], g.hub[1]);
    def.allowSleep = false;
    b2Body *body = world.CreateBody(&def);
    b2CircleShape hub;
    hub.m_radius = g.hub_radius;
    body->CreateFixture(&hub, WHEEL_DENSITY);
    const float half = 0.5f * (g.radius - g.hub_radius), middle = 0.5f * (g.radius + g.hub_radius);
    for (int k = 0; k < BLADES; k++) {
        const float a = 2.0f * PI_F * static_cast<float>(k) / BLADES;
        b2PolygonShape blade;
        blade.SetAsBox(half, 0.5f * g.thick, b2Vec2(middle * std::cos(a), middle * std::sin(a)), a);
        body->CreateFixture(&blade, WHEEL_DENSITY);
    }
    // The pin's friction, a load for the water to drive: a motor that wants
    // the wheel still, with no more than LOAD_N_M to hold it.
    b2RevoluteJointDef pin;
    pin.Initialize(ground, body, body->GetPosition());
    pin.enableMotor = true;
    pin.motorSpeed = 0.0f;
    // The water's torque on a smaller wheel (another --size) shrinks with
    // the square of its size, as its lever and the water's rate do.
    pin.maxMotorTorque = LOAD_N_M * g.scale * g.scale;
    world.CreateJoint(&pin);
    return body;
}

/* A velocity in m/s as cells per step. The library refuses a body faster
 * than 1 cell per step and checks the length in floats, so a velocity
 * scaled to exactly 1 can come out a rounding above it: cut to 0.999. */
mpca::vec3 cells_per_step(const b2Vec2 &v) {
    float x = v.x / TOP_SPEED, y = v.y / TOP_SPEED;
    const float speed = std::sqrt(x * x + y * y);
    if (speed > 0.999f) {
        x *= 0.999f / speed;
        y *= 0.999f / speed;
    }
    mpca::vec3 u = {{x, y, 0.0f}};
    return u;
}

/* Blade k's shape in cells with the wheel at `angle`, and the world point
 * (metres) of its middle. */
mpca_shape blade_shape(const geometry &g, float angle, int k, b2Vec2 *middle) {
    const float a = angle + 2.0f * PI_F * static_cast<float>(k) / BLADES;
    const float c = std::cos(a), s = std::sin(a);
    // The capsule's segment stops short of the blade's ends by its radius,
    // so its rounded ends end where the box does.
    const float r = 0.5f * g.thick, from = g.hub_radius + r, to = g.radius - r;
    const float mid = 0.5f * (g.radius + g.hub_radius);
    *middle = b2Vec2(g.hub[0] + mid * c, g.hub[1] + mid * s);
    return capsule((g.hub[0] + from * c) / CELL_M, (g.hub[1] + from * s) / CELL_M, (g.hub[0] + to * c) / CELL_M,
                   (g.hub[1] + to * s) / CELL_M, r / CELL_M);
}

/* Turns a minute, to a tenth (so a wheel at rest, turning a hair's breadth
 * either way, prints 0.0 and not -0.0). */
double rpm(const b2Body *b) {
    const double r = std::round(static_cast<double>(b->GetAngularVelocity()) * 600.0 / (2.0 * PI_F)) / 10.0;
    return r == 0.0 ? 0.0 : r;
}

/* What render() draws beside the world. */
struct drawing {
    const mpca_desc *desc;
    const wheel *wet;
    uint32_t size;
    uint32_t spout_min[2], spout_max[2];
};

void draw_capsule(const mpca_shape &s) {
    const int segments = 16;
    const float dx = s.b[0] - s.a[0], dy = s.b[1] - s.a[1];
    const float along = std::atan2(dy, dx);
    // Round the end at b from -90 to +90 degrees of the segment's
    // direction, then round the end at a, as one convex polygon.
    glBegin(GL_POLYGON);
    for (int i = 0; i <= segments; i++) {
        const float a = along - 0.5f * PI_F + PI_F * static_cast<float>(i) / segments;
        glVertex2f(s.b[0] + s.radius * std::cos(a), s.b[1] + s.radius * std::sin(a));
    }
    for (int i = 0; i <= segments; i++) {
        const float a = along + 0.5f * PI_F + PI_F * static_cast<float>(i) / segments;
        glVertex2f(s.a[0] + s.radius * std::cos(a), s.a[1] + s.radius * std::sin(a));
    }
    glEnd();
}

drawn render(const drawing &d, canvas *c, mpca_world *w, uint8_t *rgba, const view *v) {
    canvas_begin(c, rgba, v);
    view2d_begin(d.size, d.size);
    grey(0.4f);
    glRectf(static_cast<float>(d.spout_min[0]), static_cast<float>(d.spout_max[1]), static_cast<float>(d.spout_max[0]),
            static_cast<float>(d.spout_max[1] + 1));
    grey(0.55f);
    const int segments = 32;
    const mpca_shape &hub = d.wet->hub;
    glBegin(GL_TRIANGLE_FAN);
    glVertex2f(hub.a[0], hub.a[1]);
    for (int i = 0; i <= segments; i++) {
        const float a = 2.0f * PI_F * static_cast<float>(i) / segments;
        glVertex2f(hub.a[0] + hub.radius * std::cos(a), hub.a[1] + hub.radius * std::sin(a));
    }
    glEnd();
    for (int k = 0; k < BLADES; k++) draw_capsule(d.wet->blades[k]);
    draw_walls_2d(d.desc, v);
    // Last, so no grey covers a particle's square.
    drawn out = {draw_particles_2d(w, v), 0.0f, 0.0f};
    canvas_end(c, "box2d-wheel");
    return out;
}

/* 2D views in whole cells, as scene.c makes them. */
view make_view(uint32_t size, uint32_t px) {
    view v = {0, 0, px / size ? px / size : 1, 0};
    v.point_px = v.cell_px >= 3 ? v.cell_px - 1 : v.cell_px;
    v.width = v.height = v.cell_px * size;
    return v;
}

} // namespace

int main(int argc, char **argv) {
    scene s = scene();
    s.name = "box2d-wheel";
    s.title = "a Box2D water wheel (M13)";
    s.dim = 2;
    s.defaults = scene_opts();
    s.defaults.size = REFERENCE_SIZE;
    s.defaults.steps = 600; // 5 s
    s.defaults.seed = 27;
    s.defaults.every = 60;
    s.defaults.tiles = 6;
    s.defaults.px = 512;
    s.about = "a Box2D wheel on a pin turned by a waterfall of particles, through the momentum the water takes from its blades";
    scene_opts o;
    int status = options_parse(&s, &o, argc, argv);
    if (status >= 0) return status;
    if (o.density) {
        std::fprintf(stderr, "box2d-wheel: --density is not drawn here\n");
        return 2;
    }
    scene_make_dirs(o.out);
    const geometry g = make_geometry(o.size);

    // ---- the water ----
    mpca_desc d;
    mpca::check(mpca_desc_defaults(&d, 2, o.size, o.size, 0));
    d.boundary[0][0] = d.boundary[0][1] = MPCA_BOUNDARY_WALL;
    d.boundary[1][0] = d.boundary[1][1] = MPCA_BOUNDARY_OPEN;
    d.forces = MPCA_FORCE_UNIFORM;
    d.gravity[1] = -GRAVITY / (CELL_M * STEPS_PER_S * STEPS_PER_S);
    d.restitution = WATER_E;
    d.emitter_capacity = 1;
    d.obstacles = 1;
    d.body_capacity = 1 + BLADES;
    // What each shape takes as the first obstacle bounds what it takes
    // anywhere; a blade takes more cells at some angles than at others, so
    // the most over a quarter turn, in small steps. (A static shape with a
    // cell centre on a capsule's segment has no normal there and is
    // refused; a body is not, but the count is asked of static shapes, so
    // such angles are passed over.)
    b2Vec2 middle;
    uint32_t blade_entries = 0;
    for (int i = 0; i < 90; i++) {
        try {
            const uint32_t n = mpca::surface_entries(d, blade_shape(g, 0.5f * PI_F * static_cast<float>(i) / 90, 0, &middle));
            if (n > blade_entries) blade_entries = n;
        } catch (const mpca::error &) {
        }
    }
    d.body_surface_capacity =
        mpca::surface_entries(d, disc(g.hub[0] / CELL_M, g.hub[1] / CELL_M, g.hub_radius / CELL_M)) + BLADES * blade_entries;
    d.seed = o.seed;
    mpca::world w(d);
    drawing dr = {nullptr, nullptr, o.size, {0, 0}, {0, 0}};
    {
        const uint32_t centre = static_cast<uint32_t>(SPOUT_X_M * g.scale / CELL_M);
        uint32_t width = scale_cells(SPOUT_CELLS, o.size, REFERENCE_SIZE);
        if (width < 2) width = 2;
        dr.spout_min[0] = centre - width / 2;
        dr.spout_max[0] = dr.spout_min[0] + width;
        dr.spout_min[1] = static_cast<uint32_t>(SPOUT_Y_M * g.scale / CELL_M);
        dr.spout_max[1] = dr.spout_min[1] + SPOUT_ROWS;
        mpca_emitter e = mpca_emitter();
        e.min[0] = dr.spout_min[0];
        e.max[0] = dr.spout_max[0];
        e.min[1] = dr.spout_min[1];
        e.max[1] = dr.spout_max[1];
        e.max[2] = 1;
        e.rate = SPOUT_RATE * g.scale;
        e.velocity[1] = -SPOUT_SPEED;
        e.spread = 0.05f;
        e.mass = 1.0f;
        w.add_emitter(e);
    }

    // ---- the wheel, in both Box2D worlds, and its bodies in the water ----
    b2World wet_world(b2Vec2(0.0f, -GRAVITY)), dry_world(b2Vec2(0.0f, -GRAVITY));
    wheel wet;
    wet.body = add_wheel(wet_world, g);
    b2Body *dry = add_wheel(dry_world, g);
    const mpca::vec3 still = {{0.0f, 0.0f, 0.0f}};
    wet.hub = disc(g.hub[0] / CELL_M, g.hub[1] / CELL_M, g.hub_radius / CELL_M);
    wet.hub_id = w.add_body(wet.hub, still, WHEEL_E);
    for (int k = 0; k < BLADES; k++) {
        wet.blades[k] = blade_shape(g, 0.0f, k, &middle);
        wet.blade_ids[k] = w.add_body(wet.blades[k], still, WHEEL_E);
    }
    const mpca_desc desc = w.desc();
    dr.desc = &desc;
    dr.wet = &wet;
    std::printf("%s (%s): %ux%u cells, %zu particles, %llu steps, seed %llu, %.0f steps a second, "
                "%.1f kg a particle, wheel %.1f kg, %.2f kg m^2\n",
                o.name, s.title, o.size, o.size, w.particle_count(), static_cast<unsigned long long>(o.steps),
                static_cast<unsigned long long>(o.seed), static_cast<double>(STEPS_PER_S),
                static_cast<double>(PARTICLE_KG), static_cast<double>(wet.body->GetMass()),
                static_cast<double>(wet.body->GetInertia()));

    // ---- frames, sheet, GIF: as scene_main, one step at a time ----
    const view fv = make_view(o.size, o.px);
    const view tv = make_view(o.size, (fv.cell_px + 1) / 2 * o.size);
    canvas *c = canvas_create();
    std::vector<uint8_t> frame_gl(static_cast<std::size_t>(fv.width) * fv.height * 4);
    std::vector<uint8_t> tile_gl(static_cast<std::size_t>(tv.width) * tv.height * 4);
    uint32_t tiles = o.tiles;
    if (static_cast<uint64_t>(tiles) > o.steps + 1) tiles = static_cast<uint32_t>(o.steps + 1);
    uint32_t gif_frames = o.gif;
    if (static_cast<uint64_t>(gif_frames) > o.steps + 1) gif_frames = static_cast<uint32_t>(o.steps + 1);
    image sheet = image_new(tiles * tv.width + (tiles + 1) * SHEET_GAP, tv.height + 3 * SHEET_GAP + LABEL_HEIGHT);
    image frame = image_new(fv.width, fv.height);
    image gif_frame = image_new(tv.width, tv.height + 2 * GIF_GAP + LABEL_HEIGHT);
    gif_anim *gif = gif_frames ? gif_new(gif_frame.width, gif_frame.height) : nullptr;
    std::vector<char> path(std::strlen(o.out) + std::strlen(o.name) + 48);

    const float kg_m_per_s = PARTICLE_KG * TOP_SPEED; // a particle's momentum at a cell per step
    const uint64_t box2d_steps = o.steps / SUBSTEPS;
    const uint64_t last_second = box2d_steps > static_cast<uint64_t>(BOX2D_HZ) ? box2d_steps - static_cast<uint64_t>(BOX2D_HZ) : 0;
    double sim_s = 0.0, box2d_s = 0.0, draw_s = 0.0, torque_sum = 0.0, second_torque = 0.0;
    uint64_t images = 0, frames = 0, next_tile = 0, next_gif = 0, torque_steps = 0;
    uint64_t reflected = 0, pushed = 0, crushed = 0;
    for (uint64_t t = 0;; t++) {
        char label[32];
        std::snprintf(label, sizeof label, "t=%.2fs", static_cast<double>(t) / STEPS_PER_S);
        if (o.every && (t % o.every == 0 || t == o.steps)) {
            const double t0 = now_s();
            const drawn dn = render(dr, c, w.get(), frame_gl.data(), &fv);
            draw_s += now_s() - t0;
            images++;
            scene_frame_png(&frame, frame_gl.data(), &fv, &o, 4, frames, path.data(), path.size());
            frames++;
            std::printf("frame: %s step=%llu particles=%zu size=%ux%u point_px=%u\n", path.data(),
                        static_cast<unsigned long long>(t), dn.particles, fv.width, fv.height, fv.point_px);
        }
        const bool tile_now = next_tile < tiles && scene_spread(next_tile, tiles, o.steps) == t;
        const bool gif_now = next_gif < gif_frames && scene_spread(next_gif, gif_frames, o.steps) == t;
        if (tile_now || gif_now) {
            const double t0 = now_s();
            const drawn dn = render(dr, c, w.get(), tile_gl.data(), &tv);
            draw_s += now_s() - t0;
            images++;
            if (tile_now) {
                scene_tile(&sheet, tile_gl.data(), &tv, next_tile, label);
                std::printf("tile: step=%llu particles=%zu size=%ux%u point_px=%u\n",
                            static_cast<unsigned long long>(t), dn.particles, tv.width, tv.height, tv.point_px);
                next_tile++;
            }
            if (gif_now) {
                scene_gif_frame(gif, &gif_frame, tile_gl.data(), &tv, label);
                next_gif++;
            }
        }
        std::fflush(stdout);
        if (t >= o.steps) break;

        // One automaton step, the blades where Box2D has them (the angle
        // carried on by the angular velocity in a Box2D step's later
        // automaton steps), each moving at the velocity of its middle.
        const int sub = static_cast<int>(t % SUBSTEPS);
        double t0 = now_s();
        const float angle = wet.body->GetAngle() + wet.body->GetAngularVelocity() * static_cast<float>(sub) / STEPS_PER_S;
        for (int k = 0; k < BLADES; k++) {
            wet.blades[k] = blade_shape(g, angle, k, &middle);
            w.move_body(wet.blade_ids[k], wet.blades[k], cells_per_step(wet.body->GetLinearVelocityFromWorldPoint(middle)));
        }
        scene_step(w.get(), 1, &o);
        for (int k = 0; k < BLADES; k++) {
            const mpca_body_stats bs = w.body_stats(wet.blade_ids[k]);
            wet.momentum[k][0] += bs.momentum[0];
            wet.momentum[k][1] += bs.momentum[1];
            reflected += bs.reflected;
            pushed += bs.pushed;
            crushed += bs.crushed;
        }
        const mpca_body_stats hs = w.body_stats(wet.hub_id);
        reflected += hs.reflected;
        sim_s += now_s() - t0;
        if (sub != SUBSTEPS - 1) continue;

        // The water's push on each blade, at its middle, then Box2D's step.
        // (The hub is on the pin: what the water hands it does not turn it.)
        t0 = now_s();
        const uint64_t n = t / SUBSTEPS; // this Box2D step
        double torque = 0.0;
        for (int k = 0; k < BLADES; k++) {
            blade_shape(g, wet.body->GetAngle(), k, &middle);
            const b2Vec2 impulse(static_cast<float>(-wet.momentum[k][0]) * kg_m_per_s,
                                 static_cast<float>(-wet.momentum[k][1]) * kg_m_per_s);
            wet.body->ApplyLinearImpulse(impulse, middle, true);
            const b2Vec2 arm = middle - wet.body->GetPosition();
            torque += static_cast<double>(b2Cross(arm, impulse)) * BOX2D_HZ;
            wet.momentum[k][0] = wet.momentum[k][1] = 0.0;
        }
        second_torque += torque;
        if (n >= last_second) {
            torque_sum += torque;
            torque_steps++;
        }
        wet_world.Step(1.0f / BOX2D_HZ, 8, 3);
        dry_world.Step(1.0f / BOX2D_HZ, 8, 3);
        box2d_s += now_s() - t0;
        if ((n + 1) % static_cast<uint64_t>(BOX2D_HZ) == 0) {
            std::printf("wheel: t=%.0fs rpm=%.1f dry_rpm=%.1f torque=%.1f\n", static_cast<double>(n + 1) / BOX2D_HZ,
                        rpm(wet.body), rpm(dry), second_torque / BOX2D_HZ);
            second_torque = 0.0;
        }
    }
    mpca_stats stats = mpca_stats();
    stats.struct_size = sizeof stats;
    scene_finish(&o, &sheet, tiles, gif, &gif_frame, 8, 100, w.get(), &stats);
    // The water's speed at the height of the wheel's middle, from its speed
    // at the spout and the fall, in free fall.
    const double fall_m = SPOUT_Y_M * g.scale - g.hub[1];
    const double spout_ms = static_cast<double>(SPOUT_SPEED * TOP_SPEED);
    const double water_ms = std::sqrt(spout_ms * spout_ms + 2.0 * GRAVITY * fall_m);
    const double tip_ms = std::fabs(static_cast<double>(wet.body->GetAngularVelocity())) * g.radius;
    std::printf("water: torque=%.1f N m (mean over the last second) blade_tips=%.2f m/s falling_water=%.2f m/s "
                "reflected=%llu pushed=%llu crushed=%llu\n",
                torque_steps ? torque_sum / static_cast<double>(torque_steps) : 0.0, tip_ms, water_ms,
                static_cast<unsigned long long>(reflected), static_cast<unsigned long long>(pushed),
                static_cast<unsigned long long>(crushed));
    const double per_step = o.steps ? 1e3 * sim_s / static_cast<double>(o.steps) : 0.0;
    std::printf("sim: %.3f ms/step (%llu steps in %.1f ms, moving the bodies included), box2d: %.3f ms/step, "
                "render: %.2f ms/frame (%llu frames and tiles)\n",
                per_step, static_cast<unsigned long long>(o.steps), 1e3 * sim_s,
                o.steps ? 1e3 * box2d_s / static_cast<double>(o.steps) : 0.0,
                images ? 1e3 * draw_s / static_cast<double>(images) : 0.0, static_cast<unsigned long long>(images));
    image_free(&frame);
    image_free(&sheet);
    image_free(&gif_frame);
    canvas_destroy(c);
    return 0;
}
