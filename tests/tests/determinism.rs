//! Determinism (M8): every draw of a block comes from a stream of (seed,
//! step, block index), so the same seed and inputs give bit-identical worlds
//! whatever the block order or the memory the world lives in, and another
//! seed gives another world.

mod common;

use mpca::{Boundary, Collisions, Description, Drag, Drift, Emitter, Method, Quantization, Shape, Stats, Vortex, World};

/// The boundary kinds a configuration can have.
#[derive(Clone, Copy, Debug)]
enum Faces {
    Periodic,
    Wall,
    Open,
    /// x periodic, y wall below and open above, z open below and wall above.
    Mixed,
}

/// One scene with every part a world can have: obstacles, an emitter with
/// lifetimes, per-particle masses, every force term, and the given faces.
fn description(dim: u32, faces: Faces, variant: usize) -> Description {
    let mut desc = if dim == 2 { Description::new_2d(32, 32) } else { Description::new_3d(16, 16, 16) };
    desc = match faces {
        Faces::Periodic => desc.with_boundary(Boundary::Periodic),
        Faces::Wall => desc.with_boundary(Boundary::Wall),
        Faces::Open => desc.with_boundary(Boundary::Open),
        Faces::Mixed => {
            let mut d = desc;
            d.boundary = [[Boundary::Periodic; 2], [Boundary::Wall, Boundary::Open], [Boundary::Open, Boundary::Wall]];
            d
        }
    };
    desc.obstacles = true;
    desc.surface_capacity = 1024;
    desc.per_particle_mass = true;
    desc.mass_classes = 4;
    desc.forces.uniform = true;
    desc.gravity = [0.003, -0.01, 0.002];
    desc.forces.field = true;
    desc.forces.potential = true;
    desc.forces.vortex = dim == 2;
    desc.vortex = Vortex { centre: [16.0, 16.0], core_radius: 4.0, circulation: 0.5 };
    desc.restitution = 0.9;
    desc.wall_restitution = 0.8;
    desc.dt = 0.5;
    desc.emitter_capacity = 1;
    desc.lifetimes = true;
    desc.quantization = [Quantization::Bits8, Quantization::Bits16][variant % 2];
    desc.drift = [Drift::Paper, Drift::Calibrated][variant / 3 % 2];
    desc.method = [Method::ExactFast, Method::Greedy, Method::Exhaustive][variant % 3];
    desc.collisions = [Collisions::Paper, Collisions::SpeedLimited][variant / 2 % 2];
    desc.contacts = variant % 4 < 2;
    desc.energy_neutral = variant % 3 == 1;
    if variant % 2 == 0 {
        // Turbulence (M5.1c) in every other world with drag.
        let turbulence = if variant % 4 == 2 { mpca::Turbulence { amplitude: 0.25, scale: 8, rate: 0.05 } } else { mpca::Turbulence::OFF };
        desc.drag = Drag { rate: 0.2, wind: [0.05, 0.1, -0.05], field: variant % 4 == 0, vortex: dim == 2, turbulence };
    }
    desc.seed = 0x5eed_0000 + variant as u64;
    desc
}

/// Everything a world is filled with, drawn once so two worlds can be
/// filled with exactly the same inputs, in either order.
struct Inputs {
    particles: Vec<([u32; 3], [f32; 3], f32)>,
    field: Vec<f32>,
    potential: Vec<f32>,
    wind: Vec<f32>,
}

fn inputs(desc: &Description, seed: u64) -> Inputs {
    let mut rng = common::test_rng(seed);
    let cells: Vec<[u32; 3]> = common::cells(desc).collect();
    let masses = [1.0f32, 2.0, 0.5];
    let mut particles = vec![];
    for &pos in &cells {
        if rng.unit() < 0.3 {
            particles.push((pos, rng.velocity(desc.dim, 0.9), masses[rng.below(3) as usize]));
        }
    }
    let d = desc.dim as usize;
    let field = (0..cells.len() * d).map(|_| 0.02 * (rng.unit() - 0.5)).collect();
    let potential = cells.iter().map(|c| 0.05 * ((c[0] as f32 * 0.4).sin() + (c[1] as f32 * 0.3).cos())).collect();
    let wind = (0..cells.len() * d).map(|_| 0.4 * (rng.unit() - 0.5)).collect();
    Inputs { particles, field, potential, wind }
}

/// Builds and fills a world in `memory`; `reverse` adds the particles in the
/// opposite order (so the mass table is filled in another order too).
fn build<'a>(desc: &Description, inputs: &Inputs, memory: &'a mut [u8], reverse: bool) -> &'a mut World {
    let world = World::init(desc, memory).unwrap();
    let (shape, box_) = if desc.dim == 2 {
        (
            Shape::Disc { centre: [10.0, 22.0], radius: 4.0 },
            Shape::Box { min: [20.0, 6.0, 0.0], max: [26.0, 10.0, 1.0] },
        )
    } else {
        (
            Shape::Sphere { centre: [5.0, 11.0, 8.0], radius: 3.0 },
            Shape::Box { min: [10.0, 3.0, 3.0], max: [13.0, 6.0, 7.0] },
        )
    };
    world.add_shape(shape, 0.9).unwrap();
    world.add_shape(box_, 0.6).unwrap();
    world.set_force_field(&inputs.field).unwrap();
    world.set_potential(&inputs.potential).unwrap();
    if desc.drag.field {
        world.set_wind_field(&inputs.wind).unwrap();
    }
    let add = |world: &mut World, &(pos, v, m): &([u32; 3], [f32; 3], f32)| {
        if !world.obstacle_at(pos) {
            world.add_particle_with_mass(pos, v, m).unwrap();
        }
    };
    if reverse {
        inputs.particles.iter().rev().for_each(|p| add(world, p));
    } else {
        inputs.particles.iter().for_each(|p| add(world, p));
    }
    let top = desc.size[1] - 3;
    world
        .add_emitter(Emitter {
            min: [2, top, 0],
            max: [12, top + 2, if desc.dim == 3 { 6 } else { 1 }],
            rate: 1.7,
            velocity: [0.1, -0.4, 0.0],
            spread: 0.3,
            mass: 2.0,
            lifetime: 25,
        })
        .unwrap();
    world
}

/// Every configuration of the determinism tests: 2D and 3D, every kind of
/// faces, all three methods, both quantizations and drift rules.
fn configurations() -> Vec<Description> {
    let mut v = vec![];
    for dim in [2u32, 3] {
        for (i, faces) in [Faces::Periodic, Faces::Wall, Faces::Open, Faces::Mixed].into_iter().enumerate() {
            v.push(description(dim, faces, i + 4 * dim as usize));
        }
    }
    v
}

fn same(a: &World, b: &World, what: &str) {
    assert_eq!(a.state_hash(), b.state_hash(), "{what}: state hashes differ");
    let (sa, sb): (Stats, Stats) = (a.stats(), b.stats());
    assert_eq!(sa, sb, "{what}: stats differ");
}

/// M8: blocks are independent, so visiting them in reverse order gives the
/// same world. Expected, at every one of 100 steps of every configuration:
/// the same state hash and the same statistics (counters, momentum, energy)
/// with Order::Forward and Order::Reverse.
#[test]
fn block_order_does_not_matter() {
    for desc in configurations() {
        let inp = inputs(&desc, desc.seed);
        let mut ma = common::memory(&desc);
        let mut mb = common::memory(&desc);
        let a = build(&desc, &inp, &mut ma, false);
        let b = build(&desc, &inp, &mut mb, false);
        same(a, b, "before stepping");
        for step in 1..=100 {
            a.step_in_order(mpca::Order::Forward);
            b.step_in_order(mpca::Order::Reverse);
            same(a, b, &format!("{}D {:?} step {step}", desc.dim, desc.boundary));
        }
        assert!(a.stats().collisions > 0 && a.stats().emitted > 0);
    }
}

/// M8: the world depends only on its seed and inputs, not on where it lives
/// or the order the inputs were given in. Expected: a world in an aligned
/// buffer and one in a buffer misaligned by 1 to 7 bytes, its particles
/// added in the opposite order, hash and count the same after 60 steps; a
/// third world whose seed differs by one hashes differently.
#[test]
fn same_seed_same_world_anywhere() {
    for (i, desc) in configurations().into_iter().enumerate() {
        let inp = inputs(&desc, desc.seed);
        let bytes = mpca::world_bytes(&desc).unwrap();
        let mut ma = common::memory(&desc);
        let a = build(&desc, &inp, &mut ma, false);
        let shift = 1 + i % 7;
        let mut mb = vec![0u8; bytes + shift];
        let slice = &mut mb[shift..];
        assert_ne!(slice.as_ptr() as usize % mpca::WORLD_ALIGN, 0, "the buffer should be misaligned");
        let b = build(&desc, &inp, slice, true);
        a.step(60);
        b.step(60);
        same(a, b, &format!("{}D {:?} shifted by {shift}", desc.dim, desc.boundary));

        let mut other = desc;
        other.seed += 1;
        let mut mc = common::memory(&other);
        let c = build(&other, &inp, &mut mc, false);
        c.step(60);
        assert_ne!(
            a.state_hash(),
            c.state_hash(),
            "{}D {:?}: seeds {} and {} agree",
            desc.dim,
            desc.boundary,
            desc.seed,
            other.seed
        );
    }
}

/// M8: nothing but the description and the inputs feeds a world: two
/// worlds built the same way, one stepped 30 times in one call and one a
/// step at a time, stay identical; and stepping is not affected by reading
/// the world (queries draw nothing).
#[test]
fn queries_and_step_batching_change_nothing() {
    let desc = description(2, Faces::Mixed, 1);
    let inp = inputs(&desc, 3);
    let mut ma = common::memory(&desc);
    let mut mb = common::memory(&desc);
    let a = build(&desc, &inp, &mut ma, false);
    let b = build(&desc, &inp, &mut mb, false);
    a.step(30);
    for _ in 0..30 {
        b.step(1);
        let _ = b.stats();
        let _ = b.particles().count();
        let mut density = vec![0.0f32; 64];
        b.density([8, 8, 1], &mut density).unwrap();
        let _ = b.cell([3, 3, 0]);
        let _ = b.state_hash();
    }
    same(a, b, "batched vs single steps");
}

/// M9: planes for parts a scene does not use change nothing but memory. The
/// paper's scenes run in a world that also enables per-particle masses,
/// obstacles (none placed), lifetimes (none given), emitter room, and every
/// force term at zero strength (zero gravity, an all-zero field and
/// potential, a vortex of zero circulation) and an all-zero wind plane
/// (M5.1b, drag off). Expected: the same hash after
/// every step as the same scene in its own lean world, and more bytes per
/// cell.
#[test]
fn unused_parts_change_nothing_but_memory() {
    for scene in mpca_tests::scenes::paper_scenes() {
        let mut lean_mem = Vec::new();
        let lean = mpca_tests::scenes::build(&scene, &mut lean_mem).unwrap();
        let mut d = scene.desc;
        d.per_particle_mass = true;
        d.mass_classes = 8;
        if !d.obstacles {
            d.obstacles = true;
            d.surface_capacity = 16;
        }
        d.lifetimes = true;
        d.emitter_capacity += 2;
        if !d.forces.uniform {
            d.forces.uniform = true;
            d.gravity = [0.0; 3];
        }
        d.forces.field = true;
        d.forces.potential = true;
        d.drag.field = true;
        if !d.forces.vortex {
            d.forces.vortex = true;
            d.vortex = Vortex { centre: [3.0, 5.0], core_radius: 2.0, circulation: 0.0 };
        }
        let full_scene = mpca_tests::scenes::Scene { desc: d, ..scene };
        let mut full_mem = Vec::new();
        let full = mpca_tests::scenes::build(&full_scene, &mut full_mem).unwrap();
        let cells: usize = d.size[..d.dim as usize].iter().map(|&s| s as usize).product();
        full.set_force_field(&vec![0.0; cells * d.dim as usize]).unwrap();
        full.set_potential(&vec![0.0; cells]).unwrap();
        full.set_wind_field(&vec![0.0; cells * d.dim as usize]).unwrap();
        assert!(full.bytes_per_cell() > lean.bytes_per_cell());
        for step in 0..scene.steps.min(200) {
            assert_eq!(full.state_hash(), lean.state_hash(), "{}: worlds differ after {step} steps", scene.name);
            full.step(1);
            lean.step(1);
        }
        assert_eq!(full.stats().clamps, lean.stats().clamps, "{}", scene.name);
    }
}
