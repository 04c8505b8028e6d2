//! A 1024 x 1024 gas stepped on N threads (M11), against the serial step.
//!
//!     cargo run --release -p mpca --features std --example parallel -- [threads] [steps]
//!
//! The library starts no thread: `World::step_parallel` hands the step's
//! tasks to a parallel-for of the caller's, here scoped threads of the
//! standard library that split the tasks between them round-robin. The
//! worlds must end with the same hash.

use std::time::Instant;

use mpca::{Description, World};

fn main() -> Result<(), mpca::Error> {
    let mut args = std::env::args().skip(1).map(|a| a.parse::<usize>().expect("a number"));
    let threads = args.next().unwrap_or(2).max(1);
    let steps = args.next().unwrap_or(50);

    let mut desc = Description::new_2d(1024, 1024);
    desc.restitution = 0.5;
    desc.seed = 7;
    let mut serial_memory = vec![0u8; mpca::world_bytes(&desc)?];
    let mut split_memory = serial_memory.clone();
    let serial = World::init(&desc, &mut serial_memory)?;
    let split = World::init(&desc, &mut split_memory)?;
    fill(serial)?;
    fill(split)?;
    println!("{} particles, {steps} steps", serial.particle_count());

    let start = Instant::now();
    serial.step(steps as u64);
    let serial_time = start.elapsed();

    // The host's parallel-for: thread t of `threads` runs tasks t,
    // t + threads, t + 2 threads, ... and the call returns when all are
    // done. (World::step_threads instead lets threads take the next task
    // as they finish one.)
    let mut host = |count: usize, task: &(dyn Fn(usize) + Sync)| {
        std::thread::scope(|s| {
            for t in 1..threads.min(count) {
                s.spawn(move || (t..count).step_by(threads).for_each(task));
            }
            (0..count).step_by(threads).for_each(task);
        });
    };
    let start = Instant::now();
    for _ in 0..steps {
        split.step_parallel(4 * threads, &mut host);
    }
    let split_time = start.elapsed();

    let per_step = |t: std::time::Duration| t.as_secs_f64() * 1e3 / steps as f64;
    println!("serial step:      {:8.3} ms/step", per_step(serial_time));
    println!("{threads} thread(s):      {:8.3} ms/step ({:.2}x)", per_step(split_time), serial_time.as_secs_f64() / split_time.as_secs_f64());
    let same = serial.state_hash() == split.state_hash();
    println!("hashes {:016x} {:016x}: {}", serial.state_hash(), split.state_hash(), if same { "equal" } else { "DIFFERENT" });
    assert!(same, "the parallel step must equal the serial one");
    Ok(())
}

/// One particle in ten cells, random speed below 0.5 in a random direction,
/// from the library's own generator (an emitter stream: 2^32 outputs).
fn fill(w: &mut World) -> Result<(), mpca::Error> {
    let mut rng = mpca::rng::emitter_stream(1, 0, 0);
    for y in 0..1024 {
        for x in 0..1024 {
            if rng.chance(0.1) {
                let (vx, vy) = (rng.unit() - 0.5, rng.unit() - 0.5);
                w.add_particle([x, y, 0], [vx * 0.7, vy * 0.7, 0.0])?;
            }
        }
    }
    Ok(())
}
