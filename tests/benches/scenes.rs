//! The paper's four scenes, timed: `cargo bench -p mpca-tests`.
//!
//! For each scene it builds the world, runs the paper's step count several
//! times (set `MPCA_BENCH_RUNS`, default 5) and prints the median wall time
//! with the spread, nanoseconds per processed block, the share of blocks
//! skipped as empty, bytes per cell and the paper's time. Timing is of the
//! steps alone, not of building the world. `MPCA_BENCH_SCENE=water` (say)
//! runs one scene only, e.g. under `valgrind --tool=callgrind`; the last
//! column, the blocks processed over the run, is what
//! `scripts/instructions.sh` divides the step's instructions by.

use std::time::Instant;

use mpca_tests::scenes::{build, paper_scenes};

fn main() {
    let runs: usize = std::env::var("MPCA_BENCH_RUNS").ok().and_then(|s| s.parse().ok()).unwrap_or(5).max(1);
    println!("mpca {} — paper scenes, median of {runs} runs", env!("CARGO_PKG_VERSION"));
    println!(
        "{:<12} {:>4} {:>9} {:>9} {:>6} {:>11} {:>15} {:>10} {:>9} {:>7} {:>12} {:>10}",
        "scene", "sec", "cells", "particles", "steps", "median_ms", "min..max_ms", "ns/block", "skipped", "B/cell", "paper_s", "blocks"
    );
    let only = std::env::var("MPCA_BENCH_SCENE").ok();
    let mut memory = Vec::new();
    for scene in paper_scenes().into_iter().filter(|s| only.as_deref().is_none_or(|n| n == s.name)) {
        let mut times = Vec::with_capacity(runs);
        let (mut processed, mut total) = (0u64, 0u64);
        let mut particles = 0;
        let mut bytes_per_cell = 0.0;
        for _ in 0..runs {
            let world = build(&scene, &mut memory).expect("scene builds");
            let (mut p, mut t) = (0u64, 0u64);
            let start = Instant::now();
            for _ in 0..scene.steps {
                world.step(1);
                let (done, skipped) = world.last_step_blocks();
                p += done;
                t += done + skipped;
            }
            times.push(start.elapsed().as_secs_f64());
            (processed, total) = (p, t);
            particles = world.particle_count();
            bytes_per_cell = world.bytes_per_cell();
        }
        times.sort_by(f64::total_cmp);
        let median = times[runs / 2];
        let cells: u64 = scene.desc.size[..scene.desc.dim as usize].iter().map(|&s| u64::from(s)).product();
        println!(
            "{:<12} {:>4} {:>9} {:>9} {:>6} {:>11.2} {:>7.2}..{:<7.2} {:>10.1} {:>8.1}% {:>7.3} {:>12.0} {:>10}",
            scene.name,
            scene.section,
            cells,
            particles,
            scene.steps,
            median * 1e3,
            times[0] * 1e3,
            times[runs - 1] * 1e3,
            median * 1e9 / processed.max(1) as f64,
            100.0 * (total - processed) as f64 / total.max(1) as f64,
            bytes_per_cell,
            scene.paper_seconds,
            processed,
        );
    }
}
