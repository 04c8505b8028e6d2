//! The host side of the firmware check (`scripts/firmware.sh`, issue 12):
//! builds the firmware's scene (`scenes::smoke_64`), steps it as the
//! firmware does, and prints
//!
//! ```text
//! smoke-64 hash 0123456789abcdef
//! smoke-64 steps 120 particles 88 blocks 1234
//! ```
//!
//! The hash line must equal the one the firmware prints over semihosting
//! (M8: the same world on every target). `blocks` counts the blocks the
//! steps processed, so that instructions counted on the firmware can be
//! divided per processed block, as `scripts/instructions.sh` does on the
//! host.

use mpca_tests::scenes;

fn main() {
    let scene = scenes::smoke_64();
    let mut memory = Vec::new();
    let world = scenes::build(&scene, &mut memory).expect("the firmware's scene builds");
    let mut blocks = 0;
    for _ in 0..scene.steps {
        world.step(1);
        blocks += world.last_step_blocks().0;
    }
    println!("{} hash {:016x}", scene.name, world.state_hash());
    println!("{} steps {} particles {} blocks {}", scene.name, scene.steps, world.stats().particles, blocks);
}
