//! The paper's four scenes (section 4; docs/model.md, "The paper's four
//! scenes"), as descriptions plus a function that fills a fresh world.
//! Where the paper gives no figure (the smoke domain, the water emitter), the
//! choice is written next to it.

use mpca::{Boundary, Description, Drift, Emitter, Error, Method, Quantization, Shape, Vortex, World};
use rand_core::Rng;
use rand_pcg::Pcg32;

use crate::setup::{cells, SetupRng};

/// One of the paper's scenes.
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    /// Short name, also used for file names.
    pub name: &'static str,
    /// Section of the paper.
    pub section: &'static str,
    /// The world's description.
    pub desc: Description,
    /// Steps the paper ran.
    pub steps: u64,
    /// The paper's wall time for those steps on a Sun SPARCstation 2GS, s.
    pub paper_seconds: f64,
    /// Places the scene's particles and obstacles in a fresh world.
    pub setup: fn(&mut World) -> Result<(), Error>,
}

/// A stream for placing the initial particles; the world's own streams are
/// separate (M8).
fn setup_rng(world: &World) -> Pcg32 {
    Pcg32::new(world.description().seed ^ 0x5ce7_e500, 0x0dd)
}

/// 4.1 aggregation: 2D 128 x 128, density 0.3, random velocities, no force,
/// e = 0.5, 800 steps. Periodic. Speeds uniform in [0, 1), directions
/// uniform.
pub fn aggregation() -> Scene {
    let mut desc = Description::new_2d(128, 128);
    desc.drift = Drift::Paper; // the paper's rule, as printed
    desc.restitution = 0.5;
    desc.seed = 41;
    Scene { name: "aggregation", section: "4.1", desc, steps: 800, paper_seconds: 800.0, setup: fill_aggregation }
}

/// The aggregation's gas over the whole world, whatever its size.
fn fill_aggregation(w: &mut World) -> Result<(), Error> {
    let [nx, ny, _] = w.description().size;
    fill_gas(w, nx, ny)
}

/// The aggregation scene's gas in cells `[0, nx) x [0, ny)`.
fn fill_gas(w: &mut World, nx: u32, ny: u32) -> Result<(), Error> {
    let mut rng = setup_rng(w);
    for y in 0..ny {
        for x in 0..nx {
            if unit(&mut rng) < 0.3 {
                let speed = unit(&mut rng);
                let a = core::f32::consts::TAU * unit(&mut rng);
                w.add_particle([x, y, 0], [speed * a.cos(), speed * a.sin(), 0.0])?;
            }
        }
    }
    Ok(())
}

/// 4.2 cluster collision: 2D 128 x 128, two discs of radius 10 cells
/// (about 300 particles each), velocities (+-0.8, 0), e = 1, m = 1, 130 steps.
/// Walls all round, so nothing leaves.
pub fn cluster() -> Scene {
    let mut desc = Description::new_2d(128, 128).with_boundary(Boundary::Wall);
    desc.drift = Drift::Paper; // the paper's rule, as printed
    desc.restitution = 1.0;
    desc.mass = 1.0;
    desc.seed = 42;
    Scene { name: "cluster", section: "4.2", desc, steps: 130, paper_seconds: 70.0, setup: fill_cluster }
}

fn fill_cluster(w: &mut World) -> Result<(), Error> {
    for (cx, vx) in [(40.0f32, 0.8f32), (88.0, -0.8)] {
        for y in 0..128u32 {
            for x in 0..128u32 {
                let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - 64.0);
                if dx * dx + dy * dy <= 100.0 {
                    w.add_particle([x, y, 0], [vx, 0.0, 0.0])?;
                }
            }
        }
    }
    Ok(())
}

/// 4.3 smoke: 2D 128 x 128 (the paper gives no size), about one particle per
/// step emitted at the bottom with a rising velocity, a static Rankine vortex
/// force, e = 1, one mass, 120 steps. A wall below, open on the other faces.
pub fn smoke() -> Scene {
    let mut desc = Description::new_2d(128, 128).with_boundary(Boundary::Open);
    desc.drift = Drift::Paper; // the paper's rule, as printed
    desc.boundary[1][0] = Boundary::Wall;
    desc.restitution = 1.0;
    desc.forces.vortex = true;
    desc.vortex = Vortex { centre: [64.0, 72.0], core_radius: 10.0, circulation: 2.0 };
    desc.emitter_capacity = 1;
    desc.seed = 43;
    Scene { name: "smoke", section: "4.3", desc, steps: 120, paper_seconds: 8.0, setup: fill_smoke }
}

/// 4.3 with flow drag (M5.1b) in place of the paper's vortex force: smoke
/// is buoyancy (a uniform upward acceleration of 0.004) plus drag at rate
/// 0.05 towards the air's flow, so it rises at the terminal speed
/// 0.004 / 0.05 = 0.08 relative to the air instead of being flung out at
/// the speed cap. The air's flow is a columnar vortex fed through its core
/// (the Rankine vortex-sink of a bathtub vortex or a fire whirl, seen in a
/// section across its axis): the Rankine vortex read as a velocity
/// (centre (64, 72), core 10, circulation 12: 0.19 cells a step at the
/// core's edge) plus, in the wind plane, an inflow of the same profile
/// ([`smoke_flow_wind`]), `Q / (2 pi r)` outside the core, so the
/// streamlines are spirals that wind in at atan(Q / G) = 34 degrees to the
/// circles. The air converging on the axis leaves along it, out of the
/// plane; the smoke cannot, so the plume is wound into the vortex and
/// gathers in its core, where the inflow balances the buoyant drift. A
/// purely tangential flow only carries a plume round the vortex's side
/// (the streamlines of a steady flow without a sink are closed or pass
/// by). Calibrated drift, speed-limited collisions; the same emitter.
pub fn smoke_flow() -> Scene {
    let mut desc = Description::new_2d(128, 128).with_boundary(Boundary::Open);
    desc.boundary[1][0] = Boundary::Wall;
    desc.restitution = 1.0;
    desc.collisions = mpca::Collisions::SpeedLimited;
    desc.forces.uniform = true;
    desc.gravity = [0.0, 0.004, 0.0];
    desc.vortex = Vortex { centre: [64.0, 72.0], core_radius: 10.0, circulation: 12.0 };
    desc.drag = mpca::Drag { rate: 0.05, wind: [0.0; 3], field: true, vortex: true, ..mpca::Drag::OFF };
    desc.emitter_capacity = 1;
    desc.seed = 43;
    Scene { name: "smoke-flow", section: "4.3b", desc, steps: 1200, paper_seconds: f64::NAN, setup: fill_smoke_flow }
}

/// The sink strength `Q` of [`smoke_flow`]'s inflow, cells^2 a step: the
/// air the core takes in a step.
pub const SMOKE_FLOW_INFLOW: f32 = 8.0;

/// The inflow of [`smoke_flow`] at point `p` towards `centre`: radial, of
/// magnitude `Q r / (2 pi R^2)` inside the core `R` (a sink spread evenly
/// over it) and `Q / (2 pi r)` outside: the vortex's own profile, turned
/// by a right angle, so `-Q (dx, dy) / (2 pi max(r^2, R^2))`. Computed
/// with `+ - * /` only, as `c_examples/smoke.c` computes it, so the C and
/// the Rust scene hold the same bits.
pub fn smoke_flow_wind(centre: [f32; 2], core_radius: f32, inflow: f32, p: [f32; 2]) -> [f32; 2] {
    let (dx, dy) = (p[0] - centre[0], p[1] - centre[1]);
    let r2 = (dx * dx + dy * dy).max(core_radius * core_radius);
    let s = -inflow / (core::f32::consts::TAU * r2);
    [dx * s, dy * s]
}

/// The smoke's emitter and, where the world has the plane, the inflow of
/// [`smoke_flow`] in the wind plane.
fn fill_smoke_flow(w: &mut World) -> Result<(), Error> {
    fill_smoke(w)?;
    let d = *w.description();
    if d.drag.field {
        let [nx, ny, _] = d.size;
        let mut plane = Vec::with_capacity(2 * nx as usize * ny as usize);
        for y in 0..ny {
            for x in 0..nx {
                let p = [x as f32 + 0.5, y as f32 + 0.5];
                plane.extend(smoke_flow_wind(d.vortex.centre, d.vortex.core_radius, SMOKE_FLOW_INFLOW, p));
            }
        }
        w.set_wind_field(&plane)?;
    }
    Ok(())
}

fn fill_smoke(w: &mut World) -> Result<(), Error> {
    smoke_emitter(w, [60, 0, 0], [68, 2, 1])
}

/// The smoke's emitter over cells `min..max`: one particle a step at
/// (0, 0.6) with a spread of 0.2.
fn smoke_emitter(w: &mut World, min: [u32; 3], max: [u32; 3]) -> Result<(), Error> {
    w.add_emitter(Emitter { min, max, rate: 1.0, velocity: [0.0, 0.6, 0.0], spread: 0.2, mass: 1.0, lifetime: 0 })?;
    Ok(())
}

/// A rising plume for M5.1c: the smoke preset (docs/model.md, Presets) in
/// a 128 x 128 world with no wind, a vent 8 cells wide in the middle of
/// the floor puffing one particle a step upwards, with the preset's
/// turbulence or without it (drag alone: a column rising at the terminal
/// speed). 1,200 steps; the smoke reaches the top after about 600.
pub fn plume(turbulent: bool, seed: u64) -> Scene {
    let mut desc = Description::preset(mpca::Preset::Smoke, 2, [128, 128, 1]);
    if !turbulent {
        desc.drag.turbulence = mpca::Turbulence::OFF;
    }
    desc.emitter_capacity = 1;
    desc.seed = seed;
    let name = if turbulent { "plume, turbulent" } else { "plume, drag alone" };
    Scene { name, section: "M5.1c", desc, steps: 1200, paper_seconds: f64::NAN, setup: fill_plume }
}

fn fill_plume(w: &mut World) -> Result<(), Error> {
    w.add_emitter(Emitter { min: [60, 0, 0], max: [68, 2, 1], rate: 1.0, velocity: [0.0, 0.2, 0.0], spread: 0.1, mass: 1.0, lifetime: 0 })?;
    Ok(())
}

/// The firmware example's scene (`c_examples/firmware/smoke64.c`, issue 12):
/// 4.3 smoke at 64 x 64, scaled as `c_examples/smoke.c --size 64` scales it
/// (the vortex's centre, core and circulation by half, the emitter to
/// cells 30..34 of the bottom row); the same seed, rate and velocity.
pub fn smoke_64() -> Scene {
    let mut scene = smoke();
    scene.name = "smoke-64";
    scene.desc.size = [64, 64, 1];
    scene.desc.vortex = Vortex { centre: [32.0, 36.0], core_radius: 5.0, circulation: 1.0 };
    scene.setup = fill_smoke_64;
    scene
}

fn fill_smoke_64(w: &mut World) -> Result<(), Error> {
    smoke_emitter(w, [30, 0, 0], [34, 1, 1])
}

/// 4.4 water: 3D 64^3, emitted at the top, gravity, a sphere obstacle in the
/// middle, e = 1, 130 steps. y is up; walls all round. The emitter (the paper
/// gives no rate) pours 16 particles a step from an 8 x 8 patch.
pub fn water() -> Scene {
    let mut desc = Description::new_3d(64, 64, 64).with_boundary(Boundary::Wall);
    desc.drift = Drift::Paper; // the paper's rule, as printed
    desc.restitution = 1.0;
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.02, 0.0];
    desc.obstacles = true;
    desc.surface_capacity = 4096;
    desc.emitter_capacity = 1;
    desc.seed = 44;
    Scene { name: "water", section: "4.4", desc, steps: 130, paper_seconds: 270.0, setup: fill_water }
}

fn fill_water(w: &mut World) -> Result<(), Error> {
    w.add_shape(Shape::Sphere { centre: [32.0, 28.0, 32.0], radius: 10.0 }, 1.0)?;
    w.add_emitter(Emitter {
        min: [28, 60, 28],
        max: [36, 62, 36],
        rate: 16.0,
        velocity: [0.0, -0.3, 0.0],
        spread: 0.05,
        mass: 1.0,
        lifetime: 0,
    })?;
    Ok(())
}

/// 4.4 with contacts (M5.7), beyond the paper: the water released at rest
/// above the sphere as one 24 x 16 x 24 block (9,216 particles, x and z
/// 20..44, y 44..60), gravity 0.002, e = 0.5 for particles, walls and the
/// sphere, calibrated drift (the default). It falls on the sphere, splashes
/// off it and forms a pool on the floor: every particle lies below y = 10
/// by step 1,000, at a mean speed near 0.07, and no clamp fires (measured;
/// tests/tests/effects.rs holds it). A pool's speed does not fall much
/// further: a resting particle hands on gravity's push only when it tries
/// a move, so a pile of depth h keeps speeds near sqrt(h g)
/// (docs/model.md, M5.7).
pub fn water_pool() -> Scene {
    let mut desc = Description::new_3d(64, 64, 64).with_boundary(Boundary::Wall);
    desc.restitution = 0.5;
    desc.wall_restitution = 0.5;
    desc.contacts = true;
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.002, 0.0];
    desc.obstacles = true;
    desc.surface_capacity = 4096;
    desc.seed = 45;
    Scene { name: "water-pool", section: "4.4b", desc, steps: 1200, paper_seconds: f64::NAN, setup: fill_water_pool }
}

fn fill_water_pool(w: &mut World) -> Result<(), Error> {
    w.add_shape(Shape::Sphere { centre: [32.0, 28.0, 32.0], radius: 10.0 }, 0.5)?;
    for y in 44..60 {
        for z in 20..44 {
            for x in 20..44 {
                w.add_particle([x, y, z], [0.0; 3])?;
            }
        }
    }
    Ok(())
}

/// The benchmark's size cases (issue 8): the aggregation gas in the
/// 128 x 128 corner of a periodic world of 128^2, 1024^2 and 4096^2 cells,
/// and an empty 4096^2 world, 200 steps each: what a step costs should
/// follow the particles, not the world's size.
pub fn size_scenes() -> [Scene; 4] {
    let gas = |name, n| {
        let mut desc = Description::new_2d(n, n);
        desc.restitution = 0.5;
        desc.seed = 41;
        Scene { name, section: "-", desc, steps: 200, paper_seconds: f64::NAN, setup: |w| fill_gas(w, 128, 128) }
    };
    let mut empty = gas("empty-4096", 4096);
    empty.setup = |_| Ok(());
    [gas("gas-128", 128), gas("gas-1024", 1024), gas("gas-4096", 4096), empty]
}

/// The parallel step's benchmark and test world (issue 9): the aggregation
/// gas over the whole of a periodic 1024 x 1024 world, about 315,000
/// particles.
pub fn wide_gas() -> Scene {
    full_gas("gas-1024-full", 1024, 50)
}

/// The aggregation gas over the whole of a periodic `n x n` world (density
/// 0.3, e = 0.5), `steps` steps: [`wide_gas`] at 1024, and the GPU
/// backend's benchmark and tests at other sizes (issue 29).
pub fn full_gas(name: &'static str, n: u32, steps: u64) -> Scene {
    let mut desc = Description::new_2d(n, n);
    desc.restitution = 0.5;
    desc.seed = 43;
    Scene { name, section: "-", desc, steps, paper_seconds: f64::NAN, setup: fill_aggregation }
}

/// The elastic 8-bit box of M1b's test and report row: 128 x 128 cells with
/// `boundary` on every face (walls reflect along the axes exactly),
/// speed-limited collisions (M5.2b, so no clamp changes momentum), e = 1,
/// unbiased or energy-neutral rounding. [`fill_elastic`] fills it.
pub fn elastic_box(energy_neutral: bool, boundary: Boundary) -> Description {
    let mut desc = Description::new_2d(128, 128).with_boundary(boundary);
    desc.collisions = mpca::Collisions::SpeedLimited;
    desc.energy_neutral = energy_neutral;
    desc.seed = 12;
    desc
}

/// The elastic box's gas: a particle in each cell with probability 0.3
/// (4,898 of them), speeds up to 0.6.
pub fn fill_elastic(w: &mut World) {
    let desc = *w.description();
    let mut rng = SetupRng::new(4);
    for pos in cells(&desc) {
        if rng.unit() < 0.3 {
            let v = rng.velocity(2, 0.6);
            w.add_particle(pos, v).expect("a free cell, |v| <= 0.6");
        }
    }
}

/// All four, in the paper's order.
pub fn paper_scenes() -> [Scene; 4] {
    [aggregation(), cluster(), smoke(), water()]
}

/// Builds a scene's world in `memory` (resized to fit) and fills it.
pub fn build<'a>(scene: &Scene, memory: &'a mut Vec<u8>) -> Result<&'a mut World, Error> {
    memory.clear();
    memory.resize(mpca::world_bytes(&scene.desc)?, 0);
    let world = World::init(&scene.desc, memory)?;
    (scene.setup)(world)?;
    Ok(world)
}

fn unit(rng: &mut Pcg32) -> f32 {
    (rng.next_u32() >> 8) as f32 / 16_777_216.0
}

/// A 3D world with per-particle masses, 16-bit velocities, all four force
/// terms, a mask obstacle and a sphere, lifetimes, an emitter, the
/// calibrated drift rule, every boundary kind and the given method: every
/// optional part at once, for the hash checks across targets and commits.
pub fn every_part(memory: &mut Vec<u8>, method: Method) -> &mut World {
    every_part_with(memory, method, mpca::Identity::NONE)
}

/// [`every_part`] with the identity planes `identity` (M6b), which change
/// nothing else of the world.
pub fn every_part_with(memory: &mut Vec<u8>, method: Method, identity: mpca::Identity) -> &mut World {
    let mut d = Description::new_3d(16, 16, 16);
    d.identity = identity;
    d.boundary = [[Boundary::Periodic; 2], [Boundary::Wall, Boundary::Open], [Boundary::Open, Boundary::Wall]];
    d.per_particle_mass = true;
    d.mass_classes = 4;
    d.obstacles = true;
    d.surface_capacity = 1024;
    d.forces.uniform = true;
    d.forces.field = true;
    d.forces.potential = true;
    d.forces.vortex = true;
    d.gravity = [0.0, -0.01, 0.0];
    d.vortex.centre = [8.0, 8.0];
    d.vortex.core_radius = 3.0;
    d.vortex.circulation = 0.4;
    d.restitution = 0.8;
    d.wall_restitution = 0.6;
    d.dt = 0.5;
    d.seed = 77;
    d.quantization = Quantization::Bits16;
    d.drift = Drift::Calibrated;
    d.method = method;
    d.emitter_capacity = 1;
    d.lifetimes = true;
    memory.clear();
    memory.resize(mpca::world_bytes(&d).expect("valid"), 0);
    let w = World::init(&d, memory).expect("fits");
    let cells = 16 * 16 * 16;
    let field: Vec<f32> = (0..cells * 3).map(|i| ((i % 7) as f32 - 3.0) * 0.001).collect();
    w.set_force_field(&field).unwrap();
    let potential: Vec<f32> = (0..cells).map(|i| ((i % 16) as f32 - 8.0).powi(2) * 0.0005).collect();
    w.set_potential(&potential).unwrap();
    let mut mask = vec![0u8; cells];
    for x in 2..5 {
        for y in 2..5 {
            for z in 10..13 {
                mask[x + 16 * (y + 16 * z)] = 1;
            }
        }
    }
    w.add_obstacle_mask(&mask, 0.9).unwrap();
    w.add_shape(Shape::Sphere { centre: [10.0, 6.0, 6.0], radius: 2.5 }, 1.0).unwrap();
    w.add_emitter(Emitter { min: [6, 12, 6], max: [10, 14, 10], rate: 2.5, velocity: [0.1, -0.2, 0.0], spread: 0.3, mass: 2.0, lifetime: 40 })
        .unwrap();
    let mut i = 0u32;
    for z in 0..16u32 {
        for y in 0..16u32 {
            for x in 0..16u32 {
                i = i.wrapping_mul(1_103_515_245).wrapping_add(12345);
                let p = [x, y, z];
                if (i >> 16) % 5 == 0 && matches!(w.cell(p), Ok(mpca::Cell::Empty)) {
                    let v = [((i >> 8) % 9) as f32 * 0.05 - 0.2, ((i >> 12) % 9) as f32 * 0.05 - 0.2, 0.1];
                    let m = [0.5, 1.0, 3.0][(i % 3) as usize];
                    w.add_particle_with_mass(p, v, m).unwrap();
                }
            }
        }
    }
    w
}

/// The state hash of each paper scene after its step count, and of the
/// every-part world after 60 steps with each method, as `(name, hash)`.
/// `scene_hashes` prints them (compared across targets by
/// `scripts/cross-target.sh`) and `tests/pinned.rs` pins them.
pub fn scene_hashes() -> Vec<(String, u64)> {
    let mut memory = Vec::new();
    let mut out = Vec::new();
    for scene in paper_scenes() {
        let world = build(&scene, &mut memory).expect("scene builds");
        world.step(scene.steps);
        out.push((scene.name.to_string(), world.state_hash()));
    }
    for method in [Method::Exhaustive, Method::ExactFast, Method::Greedy] {
        let world = every_part(&mut memory, method);
        world.step(60);
        out.push((format!("every-part-{method:?}"), world.state_hash()));
    }
    out
}
