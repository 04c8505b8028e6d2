//! Prints the state hash of the paper's four scenes after their step counts,
//! and of one scene that uses every optional part, one `name hash` line
//! each. `scripts/cross-target.sh` runs it natively and on 32-bit Arm under
//! QEMU and compares: M8 says the same seed and inputs give bit-identical
//! worlds on every target.

use mpca::{Boundary, Description, Drift, Emitter, Method, Quantization, Shape, World};
use mpca_tests::scenes::{build, paper_scenes};

fn main() {
    let mut memory = Vec::new();
    for scene in paper_scenes() {
        let world = build(&scene, &mut memory).expect("scene builds");
        world.step(scene.steps);
        println!("{} {:016x}", scene.name, world.state_hash());
    }
    for method in [Method::Exhaustive, Method::ExactFast, Method::Greedy] {
        let world = every_part(&mut memory, method);
        world.step(60);
        println!("every-part-{method:?} {:016x}", world.state_hash());
    }
}

/// A 3D world with per-particle masses, 16-bit velocities, all four force
/// terms, a mask obstacle and a sphere, lifetimes, an emitter, the
/// calibrated drift rule and every boundary kind.
fn every_part(memory: &mut Vec<u8>, method: Method) -> &mut World {
    let mut d = Description::new_3d(16, 16, 16);
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
