//! The page's scenes built natively: the hash each world has after N
//! steps, which the browser's must equal (scripts/wasm.sh).
//!
//!     web_hash SCENE SEED STEPS      SCENE: smoke or water

use mpca_web::scene::{self, Kind};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [name, seed, steps] = args.as_slice() else {
        eprintln!("usage: web_hash smoke|water SEED STEPS");
        std::process::exit(2);
    };
    let kind = Kind::from_name(name).expect("smoke or water");
    let seed: u64 = seed.parse().expect("a seed");
    let steps: u64 = steps.parse().expect("a step count");
    let mut memory = vec![0u8; mpca::world_bytes(&scene::description(kind, seed)).expect("the scene is valid")];
    let world = scene::build(kind, seed, &mut memory).expect("the scene builds");
    for _ in 0..steps {
        scene::step(kind, world);
    }
    println!("{name} seed {seed} steps {steps} particles {} hash {:016x}", world.particle_count(), world.state_hash());
}
