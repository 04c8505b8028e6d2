//! A row of particles falling in a walled 64 x 64 box: the crate's README
//! example, printing what it computes.
//!
//!     cargo run --release -p mpca --example falling

use mpca::{Boundary, Description, World};

fn main() -> Result<(), mpca::Error> {
    let mut desc = Description::new_2d(64, 64).with_boundary(Boundary::Wall);
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.01, 0.0];
    desc.seed = 42;

    let mut memory = vec![0u8; mpca::world_bytes(&desc)?];
    let world = World::init(&desc, &mut memory)?;
    for x in 0..64 {
        world.add_particle([x, 60, 0], [0.3, 0.0, 0.0])?;
    }
    for _ in 0..4 {
        world.step(25);
        let stats = world.stats();
        let lowest = world.particles().map(|p| p.pos[1]).min().unwrap_or(0);
        println!("step {:3}: {} particles, lowest row {lowest:2}, momentum y {:.2}", stats.step, stats.particles, stats.momentum[1]);
    }
    println!("hash {:016x}", world.state_hash());
    Ok(())
}
