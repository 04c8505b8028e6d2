//! The GPU step against the CPU's (issue 29 item 5): `cargo bench -p
//! mpca-gpu`. For each world it prints the adapter, cell updates and
//! particle-steps a second on the GPU, and the CPU step of the same world on
//! one thread and on every core, with their ratios, from the median of
//! `MPCA_BENCH_RUNS` runs (default 3). Timing is of the steps alone: the
//! GPU's runs end with a read-back of the world, which waits for the last
//! step (and is counted in), the CPU's with the last step.
//!
//! Worlds: the 2D gas at density 0.3 (`mpca_tests::scenes::full_gas`) at
//! 4096^2; `MPCA_GPU_BENCH_LARGE=1` adds 16384^2 (off by default: that
//! world is held on the CPU and on the GPU at once, and its steps take long
//! on a software adapter). 3D water is not run: this version of the backend
//! has no 3D rule.

use std::time::Instant;

use mpca::World;
use mpca_gpu::{Gpu, GpuWorld};
use mpca_tests::scenes::{build, full_gas, Scene};

fn median(mut t: Vec<f64>) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

/// Seconds for `scene.steps` steps of the scene's world, by `step`, the
/// median of `runs` runs from a fresh world.
fn time(scene: &Scene, runs: usize, memory: &mut Vec<u8>, step: &mut dyn FnMut(&mut World, u64)) -> f64 {
    median((0..runs).map(|_| {
        let world = build(scene, memory).expect("the scene builds");
        let start = Instant::now();
        step(world, scene.steps);
        start.elapsed().as_secs_f64()
    }).collect())
}

fn main() {
    let runs: usize = std::env::var("MPCA_BENCH_RUNS").ok().and_then(|s| s.parse().ok()).unwrap_or(3).max(1);
    let gpu = Gpu::new().unwrap_or_else(|e| panic!("{e}"));
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    println!("adapter: {}", gpu.adapter);
    println!("CPU: {threads} threads; median of {runs} runs");
    let mut scenes = vec![full_gas("gas-4096", 4096, 20)];
    if std::env::var("MPCA_GPU_BENCH_LARGE").is_ok_and(|v| v == "1") {
        scenes.push(full_gas("gas-16384", 16384, 10));
    }
    println!("| world | cells | particles | steps | GPU cell updates/s | GPU particle-steps/s | CPU 1 thread cells/s | CPU {threads} threads cells/s | GPU / 1 thread | GPU / {threads} threads |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let mut memory = Vec::new();
    for scene in &scenes {
        let cells = f64::from(scene.desc.size[0]) * f64::from(scene.desc.size[1]);
        let particles = build(scene, &mut memory).expect("the scene builds").particle_count();
        let gpu_s = median((0..runs).map(|_| {
            let w = build(scene, &mut memory).expect("the scene builds");
            let mut g = GpuWorld::new(&gpu, w).expect("the backend runs the gas");
            // The shader compiled and the buffers filled before the clock
            // starts: one step and a read-back first.
            g.step(1);
            g.sync().expect("the GPU world syncs");
            let start = Instant::now();
            g.step(scene.steps);
            g.sync().expect("the GPU world syncs");
            start.elapsed().as_secs_f64()
        }).collect());
        let one = time(scene, runs, &mut memory, &mut |w, n| w.step(n));
        let all = time(scene, runs, &mut memory, &mut |w, n| w.step_threads(n, threads));
        let steps = scene.steps as f64;
        let rate = |s: f64| cells * steps / s;
        println!(
            "| {} | {} | {} | {} | {:.3e} | {:.3e} | {:.3e} | {:.3e} | {:.2} | {:.2} |",
            scene.name,
            cells,
            particles,
            scene.steps,
            rate(gpu_s),
            particles as f64 * steps / gpu_s,
            rate(one),
            rate(all),
            one / gpu_s,
            all / gpu_s
        );
    }
}
