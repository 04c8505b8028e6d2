//! The GPU's worlds against the CPU's (M8b): after every step the same
//! hash, the same counters and the same snapshot image, bit for bit. On a
//! machine without a GPU the tests run on Mesa's lavapipe; a test that finds
//! no adapter fails (it never skips).

use mpca::{Description, Drift, World, WorldBox};
use mpca_gpu::{Gpu, GpuWorld};

fn gpu() -> Gpu {
    Gpu::new().unwrap_or_else(|e| panic!("{e} (install mesa-vulkan-drivers for lavapipe)"))
}

/// A 2D gas of `nx x ny` cells at `density`, velocities uniform in the
/// square [-1, 1]^2 cut to the unit disc, from `seed`.
fn gas(nx: u32, ny: u32, density: f64, seed: u64, edit: impl Fn(&mut Description)) -> WorldBox {
    let mut desc = Description::new_2d(nx, ny);
    desc.seed = seed;
    edit(&mut desc);
    let mut w = WorldBox::new(&desc).unwrap();
    let mut rng = mpca::rng::block_stream(seed, 99, 0);
    for y in 0..ny {
        for x in 0..nx {
            if f64::from(rng.bits(24)) < density * 16_777_216.0 {
                let mut v = [0f32; 3];
                loop {
                    v[0] = rng.bits(16) as f32 / 32768.0 - 1.0;
                    v[1] = rng.bits(16) as f32 / 32768.0 - 1.0;
                    if v[0] * v[0] + v[1] * v[1] <= 0.98 {
                        break;
                    }
                }
                w.add_particle([x, y, 0], v).unwrap();
            }
        }
    }
    w
}

fn image(w: &World) -> Vec<u8> {
    let mut out = vec![0u8; w.snapshot_bytes()];
    let n = w.save(&mut out).unwrap();
    out.truncate(n);
    out
}

/// Steps `cpu` and a GPU copy of it `steps` times, syncing every `every`
/// steps, and asks for the same world at each sync.
fn same_worlds(cpu: &mut World, steps: u64, every: u64) {
    let gpu = gpu();
    let mut g = GpuWorld::new(&gpu, cpu).unwrap();
    let mut done = 0;
    while done < steps {
        cpu.step(every);
        g.step(every);
        done += every;
        let on_gpu = g.sync();
        assert_eq!(on_gpu.stats(), cpu.stats(), "step {done}: statistics");
        assert_eq!(on_gpu.state_hash(), cpu.state_hash(), "step {done}: hash");
        assert!(image(on_gpu) == image(cpu), "step {done}: image");
    }
}

#[test]
fn a_2d_gas_steps_as_on_the_cpu() {
    let mut w = gas(64, 64, 0.3, 1, |_| {});
    same_worlds(&mut w, 40, 1);
}

#[test]
fn sizes_that_are_not_whole_words_step_as_on_the_cpu() {
    // 2 to 70 cells across: blocks straddle 32-cell words at odd steps and
    // the block that wraps round x is shared by the first and last word.
    for (nx, ny) in [(2, 2), (6, 4), (30, 8), (34, 6), (66, 10), (70, 4)] {
        let mut w = gas(nx, ny, 0.45, u64::from(nx), |_| {});
        same_worlds(&mut w, 12, 1);
    }
}

#[test]
fn inelastic_paper_drift_dense_gas_steps_as_on_the_cpu() {
    let mut w = gas(96, 64, 0.8, 7, |d| {
        d.restitution = 0.4;
        d.drift = Drift::Paper;
    });
    same_worlds(&mut w, 30, 3);
}

#[test]
fn many_steps_between_syncs_step_as_on_the_cpu() {
    let mut w = gas(128, 128, 0.3, 5, |d| d.mass = 2.5);
    same_worlds(&mut w, 200, 50);
}

#[test]
fn a_part_the_backend_does_not_run_is_refused() {
    let gpu = gpu();
    let w = gas(8, 8, 0.2, 1, |d| d.contacts = true);
    assert!(matches!(GpuWorld::new(&gpu, &w), Err(mpca_gpu::Error::World(mpca::Error::FeatureDisabled))));
    assert_eq!(mpca_gpu::unsupported(w.description()), Some("contacts"));
}

#[test]
fn the_papers_aggregation_scene_steps_as_on_the_cpu() {
    // 4.1 as the paper ran it (800 steps, the paper's drift rule), compared
    // every 100 steps.
    let scene = mpca_tests::scenes::aggregation();
    let mut memory = Vec::new();
    let w = mpca_tests::scenes::build(&scene, &mut memory).unwrap();
    same_worlds(w, scene.steps, 100);
}

#[test]
fn walls_open_faces_and_gravity_step_as_on_the_cpu() {
    // Every mix of wall, open and periodic axes, with and without a uniform
    // force (large enough to clamp), at sizes whose half blocks cross words.
    use mpca::Boundary::{Open, Periodic, Wall};
    let faces = [[[Wall, Wall], [Wall, Wall]], [[Open, Open], [Wall, Wall]], [[Wall, Open], [Open, Wall]], [[Periodic, Periodic], [Wall, Open]], [[Open, Wall], [Periodic, Periodic]]];
    for (i, f) in faces.into_iter().enumerate() {
        for (nx, ny) in [(8, 6), (66, 34)] {
            for gravity in [None, Some([0.02, -0.3, 0.5])] {
                let mut w = gas(nx, ny, 0.5, 100 + i as u64, |d| {
                    d.boundary[0] = f[0];
                    d.boundary[1] = f[1];
                    d.wall_restitution = 0.7;
                    if let Some(g) = gravity {
                        d.forces.uniform = true;
                        d.gravity = g;
                    }
                });
                same_worlds(&mut w, 16, 1);
            }
        }
    }
}

#[test]
fn the_papers_cluster_scene_steps_as_on_the_cpu() {
    // 4.2 as the paper ran it: walls all round, e = 1, 130 steps.
    let scene = mpca_tests::scenes::cluster();
    let mut memory = Vec::new();
    let w = mpca_tests::scenes::build(&scene, &mut memory).unwrap();
    same_worlds(w, scene.steps, 10);
}

