//! The step has two block routines: a lean one for blocks of plain worlds
//! (one mass, no lifetimes, at most a uniform force) away from the faces and
//! without an obstacle, and one that handles every part; and it skips rows and
//! words of the occupancy that its summaries say are empty. Both routines
//! draw the same numbers in the same order (M8), so a world stepped with
//! every block through the general routine and every row and word swept
//! (`World::step_reference`) must be the same world, bit for bit, as one
//! stepped normally: these tests hold the lean routine to the general one
//! and the skipping to a full sweep, step by step.

mod common;

use mpca::{Boundary, Collisions, Description, Drift, Emitter, Method, Quantization, Shape, World};

/// A plain world: a gas at density `density` with speeds up to `speed`.
fn gas<'a>(desc: &Description, density: f32, speed: f32, seed: u64, memory: &'a mut Vec<u8>) -> &'a mut World {
    memory.clear();
    memory.resize(mpca::world_bytes(desc).unwrap(), 0);
    let world = World::init(desc, memory).unwrap();
    if desc.obstacles {
        // A round obstacle in the middle: blocks touching it take the general
        // routine, the others the lean one.
        let c = desc.size.map(|s| s as f32 / 2.0);
        let shape = if desc.dim == 2 { Shape::Disc { centre: [c[0], c[1]], radius: 3.5 } } else { Shape::Sphere { centre: c, radius: 2.5 } };
        world.add_shape(shape, 0.8).unwrap();
    }
    let mut rng = common::test_rng(seed);
    for pos in common::cells(desc).collect::<Vec<_>>() {
        if rng.unit() < density && !world.obstacle_at(pos) {
            world.add_particle(pos, rng.velocity(desc.dim, speed)).unwrap();
        }
    }
    world
}

/// Every plain setting: 2D and 3D; periodic, walled and open faces (whose
/// half blocks take the general routine in both runs); no force and
/// gravity; with and without an obstacle; both widths, both drift rules,
/// all three methods, both collision rules, with and without contacts and
/// energy-neutral rounding. 2D worlds 48 wide (one occupancy word a row)
/// and 130 wide (blocks across two words).
fn settings() -> Vec<Description> {
    let mut out = vec![];
    for (dim, wide) in [(2u32, false), (2, true), (3, false)] {
        for (i, faces) in [Boundary::Periodic, Boundary::Wall, Boundary::Open].into_iter().enumerate() {
            for variant in 0..4usize {
                let mut d = match (dim, wide) {
                    (2, false) => Description::new_2d(48, 40),
                    (2, true) => Description::new_2d(130, 16),
                    _ => Description::new_3d(12, 10, 14),
                };
                d = d.with_boundary(faces);
                d.quantization = [Quantization::Bits8, Quantization::Bits16][variant % 2];
                d.drift = [Drift::Paper, Drift::Calibrated][variant / 2];
                d.method = [Method::ExactFast, Method::Greedy, Method::Exhaustive][(variant + i) % 3];
                d.restitution = [1.0, 0.6, 0.0][i];
                d.collisions = [Collisions::Paper, Collisions::SpeedLimited][(variant + i) % 2];
                d.contacts = (variant + i / 2) % 2 == 1;
                d.energy_neutral = (variant + i) % 3 == 0;
                if variant % 2 == 1 {
                    d.forces.uniform = true;
                    d.gravity = [0.004, -0.03, 0.01];
                }
                if variant >= 2 {
                    d.obstacles = true;
                    d.surface_capacity = 512;
                }
                d.seed = 900 + 10 * u64::from(dim) + 100 * u64::from(wide) + (4 * i + variant) as u64;
                out.push(d);
            }
        }
    }
    out
}

#[test]
fn lean_routine_equals_the_general_one_bit_for_bit() {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for (n, desc) in settings().iter().enumerate() {
        let what = format!(
            "setting {n}: {}D {:?} {:?} {:?} {:?} {:?} contacts {}",
            desc.dim, desc.boundary[0][0], desc.quantization, desc.drift, desc.method, desc.collisions, desc.contacts
        );
        let lean = gas(desc, 0.35, 0.9, n as u64, &mut a);
        let general = gas(desc, 0.35, 0.9, n as u64, &mut b);
        same_as_reference(lean, general, 40, &what);
        assert!(lean.stats().collisions > 100, "{what}: too few collisions to compare");
    }
}

/// Checks `step` against `step_reference` for `steps` steps.
fn same_as_reference(lean: &mut World, general: &mut World, steps: u64, what: &str) {
    assert_eq!(lean.state_hash(), general.state_hash(), "{what}: different worlds to start with");
    for step in 0..steps {
        lean.step(1);
        general.step_reference();
        assert_eq!(lean.state_hash(), general.state_hash(), "{what}: worlds differ after step {step}");
        assert_eq!(lean.stats(), general.stats(), "{what}: stats differ after step {step}");
    }
}

/// Worlds wider than one summary word (4160 cells: 65 occupancy words a
/// row, two summary words) and narrow ones, 2D and 3D, every kind of face
/// along x, sparse gases with an emitter feeding them, some with every
/// part (obstacles, per-particle masses, lifetimes, a force field): the
/// skipped rows and words never hold a particle the full sweep would move.
#[test]
fn skipping_never_hides_a_particle() {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    let mut n = 0;
    for dim in [2u32, 3] {
        for faces in [Boundary::Periodic, Boundary::Wall, Boundary::Open] {
            for every_part in [false, true] {
                n += 1;
                let mut d = if dim == 2 { Description::new_2d(4160, 6) } else { Description::new_3d(130, 6, 4) };
                d.boundary[0] = [faces; 2];
                d.seed = 700 + n;
                d.emitter_capacity = 1;
                if every_part {
                    d.obstacles = true;
                    d.surface_capacity = 4096;
                    d.per_particle_mass = true;
                    d.mass_classes = 4;
                    d.lifetimes = true;
                    d.forces.field = true;
                }
                let what = format!("{dim}D {faces:?} every part {every_part}");
                let size = d.size;
                let prepare = |w: &mut World| {
                    if every_part {
                        let shape = if dim == 2 {
                            Shape::Disc { centre: [100.0, 3.0], radius: 2.0 }
                        } else {
                            Shape::Sphere { centre: [60.0, 3.0, 2.0], radius: 1.6 }
                        };
                        w.add_shape(shape, 0.7).unwrap();
                        let cells = common::cells(&d).count() * dim as usize;
                        w.set_force_field(&(0..cells).map(|i| ((i % 5) as f32 - 2.0) * 0.002).collect::<Vec<_>>()).unwrap();
                    }
                    let max = [size[0], size[1], if dim == 3 { size[2] } else { 1 }];
                    let e = Emitter { min: [size[0] - 8, 0, 0], max, rate: 0.7, velocity: [-0.5, 0.1, 0.0], spread: 0.4, mass: 1.0, lifetime: if every_part { 90 } else { 0 } };
                    w.add_emitter(e).unwrap();
                };
                let lean = gas(&d, 0.01, 0.9, n, &mut a);
                prepare(lean);
                let general = gas(&d, 0.01, 0.9, n, &mut b);
                prepare(general);
                same_as_reference(lean, general, 60, &what);
            }
        }
    }
}
