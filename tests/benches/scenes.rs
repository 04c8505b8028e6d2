//! The paper's four scenes and the size cases, timed: `cargo bench -p
//! mpca-tests`.
//!
//! For each scene it builds the world, runs the paper's step count several
//! times (set `MPCA_BENCH_RUNS`, default 5) and prints the median wall time
//! with the spread, nanoseconds per processed block, the share of blocks
//! skipped as empty, bytes per cell and the paper's time. Timing is of the
//! steps alone, not of building the world. `MPCA_BENCH_SCENE=water` (say)
//! runs one scene only, e.g. under `valgrind --tool=callgrind`; the last
//! column, the blocks processed over the run, is what
//! `scripts/instructions.sh` divides the step's instructions by.
//!
//! The parallel case (M11, `MPCA_BENCH_SCENE=parallel`) steps the 1024^2
//! gas serially, as tasks on one thread, and on two threads.

use std::time::Instant;

use mpca::World;
use mpca_tests::scenes::{build, paper_scenes, size_scenes, wide_gas, Scene};

/// One scene's timing: the median and spread of `runs` runs, and what the
/// last run did.
struct Timing {
    times: Vec<f64>,
    processed: u64,
    total: u64,
    particles: u64,
    bytes_per_cell: f64,
}

fn time(scene: &Scene, runs: usize, memory: &mut Vec<u8>) -> Timing {
    time_with(scene, runs, memory, &mut |w| w.step(1))
}

/// Takes one step of a world.
type Stepper<'a> = &'a mut dyn FnMut(&mut World);

/// [`time`] with each step taken by `step`.
fn time_with(scene: &Scene, runs: usize, memory: &mut Vec<u8>, step: Stepper<'_>) -> Timing {
    let mut t = Timing { times: Vec::with_capacity(runs), processed: 0, total: 0, particles: 0, bytes_per_cell: 0.0 };
    for _ in 0..runs {
        let world = build(scene, memory).expect("scene builds");
        let (mut p, mut all) = (0u64, 0u64);
        let start = Instant::now();
        for _ in 0..scene.steps {
            step(world);
            let (done, skipped) = world.last_step_blocks();
            p += done;
            all += done + skipped;
        }
        t.times.push(start.elapsed().as_secs_f64());
        (t.processed, t.total) = (p, all);
        t.particles = world.particle_count();
        t.bytes_per_cell = world.bytes_per_cell();
    }
    t.times.sort_by(f64::total_cmp);
    t
}

fn main() {
    let runs: usize = std::env::var("MPCA_BENCH_RUNS").ok().and_then(|s| s.parse().ok()).unwrap_or(5).max(1);
    println!("mpca {} — paper scenes and size cases, median of {runs} runs", env!("CARGO_PKG_VERSION"));
    println!(
        "{:<12} {:>4} {:>9} {:>9} {:>6} {:>11} {:>15} {:>10} {:>9} {:>7} {:>12} {:>10}",
        "scene", "sec", "cells", "particles", "steps", "median_ms", "min..max_ms", "ns/block", "skipped", "B/cell", "paper_s", "blocks"
    );
    let only = std::env::var("MPCA_BENCH_SCENE").ok();
    let mut memory = Vec::new();
    let mut per_step = Vec::new();
    let scenes = paper_scenes().into_iter().chain(size_scenes());
    for scene in scenes.filter(|s| only.as_deref().is_none_or(|n| n == s.name)) {
        let t = time(&scene, runs, &mut memory);
        let median = t.times[runs / 2];
        let cells: u64 = scene.desc.size[..scene.desc.dim as usize].iter().map(|&s| u64::from(s)).product();
        println!(
            "{:<12} {:>4} {:>9} {:>9} {:>6} {:>11.2} {:>7.2}..{:<7.2} {:>10.1} {:>8.1}% {:>7.3} {:>12.0} {:>10}",
            scene.name,
            scene.section,
            cells,
            t.particles,
            scene.steps,
            median * 1e3,
            t.times[0] * 1e3,
            t.times[runs - 1] * 1e3,
            median * 1e9 / t.processed.max(1) as f64,
            100.0 * (t.total - t.processed) as f64 / t.total.max(1) as f64,
            t.bytes_per_cell,
            scene.paper_seconds,
            t.processed,
        );
        per_step.push((scene.name, median / scene.steps as f64));
    }
    // The size cases against the 128^2 gas, from the same run.
    if let Some(&(_, base)) = per_step.iter().find(|(n, _)| *n == "gas-128") {
        println!("\nper step, against gas-128 ({:.1} us):", base * 1e6);
        for (name, t) in per_step.iter().filter(|(n, _)| n.starts_with("gas-") || n.starts_with("empty-")) {
            println!("{name:<12} {:>10.1} us {:>8.3}x", t * 1e6, t / base);
        }
    }
    if only.as_deref().is_none_or(|n| n == "parallel") {
        parallel(runs, &mut memory);
    }
}

/// The parallel step against the serial one on the 1024^2 gas, from one
/// run: the plain step, the split step on the calling thread (its overhead)
/// and on two threads (its speed-up).
fn parallel(runs: usize, memory: &mut Vec<u8>) {
    let scene = wide_gas();
    let one_thread = |w: &mut World| w.step_parallel(8, &mut |count, task| (0..count).for_each(task));
    let cases: [(&str, Stepper<'_>); 3] =
        [("step", &mut |w| w.step(1)), ("tasks, 1 thread", &mut { one_thread }), ("tasks, 2 threads", &mut |w| w.step_threads(1, 2))];
    println!("\nparallel step, {} ({} steps), median of {runs} runs:", scene.name, scene.steps);
    let mut base = 0.0;
    for (name, step) in cases {
        let t = time_with(&scene, runs, memory, step);
        let median = t.times[runs / 2];
        if base == 0.0 {
            base = median;
        }
        println!(
            "{name:<18} {:>9} particles {:>9.2} ms/step ({:.2}..{:.2}) {:>7.3}x the step",
            t.particles,
            median * 1e3 / scene.steps as f64,
            t.times[0] * 1e3 / scene.steps as f64,
            t.times[runs - 1] * 1e3 / scene.steps as f64,
            base / median
        );
    }
}
