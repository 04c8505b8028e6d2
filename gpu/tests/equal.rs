//! The GPU's worlds against the CPU's (M8b): after every step the same
//! hash, the same counters and the same snapshot image, bit for bit. On a
//! machine without a GPU the tests run on Mesa's lavapipe; a test that finds
//! no adapter fails (it never skips).

use mpca::{Description, Drift, World, WorldBox};
use mpca_gpu::{Gpu, GpuWorld};

/// One device for every test of the binary: its pipelines are compiled
/// once (a software adapter takes a while for it).
fn gpu() -> Gpu {
    static GPU: std::sync::OnceLock<Gpu> = std::sync::OnceLock::new();
    GPU.get_or_init(|| Gpu::new().unwrap_or_else(|e| panic!("{e} (install mesa-vulkan-drivers for lavapipe)"))).clone()
}

/// A 2D gas of `nx x ny` cells at `density`, velocities uniform in the
/// square [-1, 1]^2 cut to the unit disc, from `seed`.
fn gas(nx: u32, ny: u32, density: f64, seed: u64, edit: impl Fn(&mut Description)) -> WorldBox {
    gas_around(nx, ny, density, seed, edit, |_| {})
}

/// [`gas`] in a world that `place` gives obstacles first: their cells get
/// no particle.
fn gas_around(nx: u32, ny: u32, density: f64, seed: u64, edit: impl Fn(&mut Description), place: impl Fn(&mut World)) -> WorldBox {
    let mut desc = Description::new_2d(nx, ny);
    desc.seed = seed;
    edit(&mut desc);
    filled(&desc, density, place)
}

/// A 3D gas of `size` cells at `density`, velocities uniform in the cube
/// [-1, 1]^3 cut to the unit ball, from `seed`, in a world that `place`
/// gives obstacles first.
fn gas_3d(size: [u32; 3], density: f64, seed: u64, edit: impl Fn(&mut Description), place: impl Fn(&mut World)) -> WorldBox {
    let mut desc = Description::new_3d(size[0], size[1], size[2]);
    desc.seed = seed;
    edit(&mut desc);
    filled(&desc, density, place)
}

/// A world of `desc` that `place` gives obstacles, then a particle in each
/// free cell with probability `density`, velocities uniform in the square
/// or cube cut to the unit disc or ball, from the description's seed.
fn filled(desc: &Description, density: f64, place: impl Fn(&mut World)) -> WorldBox {
    let mut w = WorldBox::new(desc).unwrap();
    place(&mut w);
    let mut rng = mpca::rng::block_stream(desc.seed, 99, 0);
    let dim = desc.dim as usize;
    let [nx, ny, nz] = desc.size;
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                if f64::from(rng.bits(24)) < density * 16_777_216.0 {
                    let mut v = [0f32; 3];
                    loop {
                        for c in &mut v[..dim] {
                            *c = rng.bits(16) as f32 / 32768.0 - 1.0;
                        }
                        if v.iter().map(|c| c * c).sum::<f32>() <= 0.98 {
                            break;
                        }
                    }
                    match w.add_particle([x, y, z], v) {
                        Ok(()) => {}
                        Err(e) if e.kind() == mpca::ErrorKind::CellObstacle => {}
                        Err(e) => panic!("{e:?}"),
                    }
                }
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
        let on_gpu = g.sync().unwrap();
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
    let mut d = Description::new_3d(8, 8, 8);
    d.method = mpca::Method::Exhaustive;
    let w = WorldBox::new(&d).unwrap();
    let refused = |w: &WorldBox| match GpuWorld::new(&gpu, w) {
        Err(mpca_gpu::Error::World(e)) => Some((e.kind(), e.detail())),
        _ => None,
    };
    assert_eq!(refused(&w), Some((mpca::ErrorKind::FeatureDisabled, "desc.method: exhaustive assignment in 3D")));
    assert_eq!(mpca_gpu::unsupported(w.description()), Some("exhaustive assignment in 3D"));
    let mut d = Description::new_2d(16, 16);
    (d.obstacles, d.body_capacity, d.body_surface_capacity) = (true, 1, 64);
    let w = WorldBox::new(&d).unwrap();
    assert_eq!(refused(&w), Some((mpca::ErrorKind::FeatureDisabled, "desc.body_capacity: bodies, obstacles the caller moves (M13)")));
    assert_eq!(mpca_gpu::unsupported(w.description()), Some("bodies, obstacles the caller moves (M13)"));
}

/// A box with walls of `size` cells (2D where the third is 1) under
/// gravity 0.02 down y, with restitution `e` for particles and walls,
/// contacts and resting contact (M5.7b), and `rows` full rows of still
/// particles from 12 cells up, as the pile of `tests/tests/rest.rs`.
fn pile(size: [u32; 3], e: f32, rows: u32, seed: u64) -> WorldBox {
    let mut d = if size[2] == 1 { Description::new_2d(size[0], size[1]) } else { Description::new_3d(size[0], size[1], size[2]) };
    d = d.with_boundary(mpca::Boundary::Wall);
    d.forces.uniform = true;
    d.gravity = [0.0, -0.02, 0.0];
    (d.restitution, d.wall_restitution) = (e, e);
    (d.contacts, d.rest) = (true, true);
    d.seed = seed;
    let mut w = WorldBox::new(&d).unwrap();
    for z in 0..size[2] {
        for y in 12..12 + rows {
            for x in 0..size[0] {
                w.add_particle([x, y, z], [0.0; 3]).unwrap();
            }
        }
    }
    w
}

#[test]
fn resting_contact_steps_as_on_the_cpu() {
    // M5.7b: 8 rows dropped 12 cells onto the floor, at e = 0 and 0.5 (the
    // fall, the impacts, the pile coming to rest and resting), 2D for 600
    // steps compared every 20; 3D (4 rows, 16 x 24 x 6) for 300 steps.
    for e in [0.0, 0.5] {
        let mut w = pile([64, 48, 1], e, 8, 11);
        same_worlds(&mut w, 600, 20);
        let mut w = pile([16, 24, 6], e, 4, 12);
        same_worlds(&mut w, 300, 20);
    }
}

#[test]
fn a_pour_onto_a_resting_pool_steps_as_on_the_cpu() {
    // M5.7b with everything round it: the water preset, an emitter pouring
    // onto a pool at rest, obstacles (a disc), gravity, contacts.
    let mut d = Description::preset(mpca::Preset::Water, 2, [48, 48, 1]);
    d.obstacles = true;
    d.surface_capacity = 128;
    d.emitter_capacity = 1;
    d.seed = 21;
    let mut w = WorldBox::new(&d).unwrap();
    w.add_shape(mpca::Shape::Disc { centre: [30.0, 10.0], radius: 5.0 }, 0.95).unwrap();
    for y in 0..4 {
        for x in 0..48 {
            match w.add_particle([x, y, 0], [0.0; 3]) {
                Ok(()) => {}
                Err(e) if e.kind() == mpca::ErrorKind::CellObstacle => {}
                Err(e) => panic!("{e:?}"),
            }
        }
    }
    let pour = mpca::Emitter { min: [10, 40, 0], max: [16, 44, 1], rate: 1.0, velocity: [0.1, -0.3, 0.0], spread: 0.1, mass: 1.0, lifetime: 0 };
    w.add_emitter(pour).unwrap();
    same_worlds(&mut w, 400, 20);
}

#[test]
fn a_3d_gas_steps_as_on_the_cpu() {
    // Periodic 3D gases with exact-fast (M5.6: its direct cases, the
    // Hungarian method and the count of optima in dense blocks) and greedy
    // assignment, at both widths: blocks of four rows (y, z), the blocks
    // that straddle 32-cell words and wrap round x, y and z, densities up
    // to full blocks.
    use mpca::Method::{ExactFast, Greedy};
    for (size, density, method, quantization) in [
        ([16, 8, 8], 0.3, Greedy, mpca::Quantization::Bits8),
        ([16, 8, 8], 0.3, ExactFast, mpca::Quantization::Bits8),
        ([2, 2, 2], 0.6, ExactFast, mpca::Quantization::Bits8),
        ([66, 6, 4], 0.5, Greedy, mpca::Quantization::Bits16),
        ([34, 4, 6], 0.8, ExactFast, mpca::Quantization::Bits8),
        ([20, 6, 6], 0.6, ExactFast, mpca::Quantization::Bits16),
    ] {
        let mut w = gas_3d(size, density, u64::from(size[0]), |d| {
            d.method = method;
            d.quantization = quantization;
            d.restitution = 0.8;
        }, |_| {});
        same_worlds(&mut w, 12, 1);
    }
}

/// A scene of the paper as the paper ran it, compared every `every` steps.
fn same_scene(scene: mpca_tests::scenes::Scene, every: u64) {
    let mut memory = Vec::new();
    let w = mpca_tests::scenes::build(&scene, &mut memory).unwrap();
    same_worlds(w, scene.steps, every);
}

#[test]
fn the_papers_aggregation_scene_steps_as_on_the_cpu() {
    // 4.1: 800 steps, the paper's drift rule, periodic.
    same_scene(mpca_tests::scenes::aggregation(), 100);
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
    // 4.2: walls all round, e = 1, 130 steps.
    same_scene(mpca_tests::scenes::cluster(), 10);
}


#[test]
fn planes_that_are_not_a_world_are_refused_and_change_nothing() {
    // mpca::World::port_finish_steps, which the sync goes through: each
    // damaged plane is refused with the world's hash and statistics as
    // they were; the planes as they are pass.
    use mpca::port::{PortPlanes, StepCounts};
    let mut w = gas(66, 6, 0.4, 3, |_| {});
    let (occupancy, velocity, row_words) = {
        let p = w.port_planes();
        (p.occupancy.to_vec(), p.velocity.to_vec(), p.row_words)
    };
    let (hash, stats) = (w.state_hash(), w.stats());
    let one = StepCounts { steps: 1, ..StepCounts::default() };
    let first = occupancy.iter().position(|&o| o != 0).unwrap();
    let cell = 64 * first + occupancy[first].trailing_zeros() as usize;
    // Occupancy, velocities, lifetimes, and the refusal they get: its kind
    // and the detail naming the plane.
    use mpca::ErrorKind::{BadLength, ImageInvalid};
    type Case = (Vec<u64>, Vec<u8>, &'static [u8], (mpca::ErrorKind, &'static str));
    let mut cases: Vec<Case> = Vec::new();
    cases.push((occupancy[1..].to_vec(), velocity.clone(), &[], (BadLength, "planes.occupancy is not the world's length")));
    cases.push((occupancy.clone(), velocity[1..].to_vec(), &[], (BadLength, "planes.velocity is not the world's length")));
    // A lifetime plane in a world without lifetimes.
    cases.push((occupancy.clone(), velocity.clone(), &[0, 0], (BadLength, "planes.life is not the world's length")));
    let mut beyond = occupancy.clone();
    beyond[1] |= 1 << 63; // cell 127 of a 66-cell row
    beyond[first] &= beyond[first] - 1;
    cases.push((beyond, velocity.clone(), &[], (ImageInvalid, "planes.occupancy has a bit past a row's end")));
    let mut fast = velocity.clone();
    fast[2 * (cell % 64 + 66 * (first / 2))] = 0x80; // -128: beyond -127
    cases.push((occupancy.clone(), fast, &[], (ImageInvalid, "planes.velocity holds a component out of range")));
    let mut lost = occupancy.clone();
    lost[first] &= lost[first] - 1;
    cases.push((lost.clone(), velocity.clone(), &[], (ImageInvalid, "planes.occupancy does not hold the particles counts says")));
    for (o, v, life, want) in cases {
        let planes = PortPlanes { occupancy: &o, row_words, velocity: &v, life, mass_index: &[], id: &[], age: &[], tag: &[] };
        assert_eq!(w.port_finish_steps(&planes, &one, &[]).map_err(|e| (e.kind(), e.detail())), Err(want));
        assert_eq!((w.state_hash(), w.stats()), (hash, stats));
    }
    // One particle fewer is what one exit (or one expiry) leaves.
    let planes = PortPlanes { occupancy: &lost, row_words, velocity: &velocity, life: &[], mass_index: &[], id: &[], age: &[], tag: &[] };
    w.port_finish_steps(&planes, &StepCounts { steps: 1, exited: 1, ..StepCounts::default() }, &[]).unwrap();
    assert_eq!(w.stats().particles, stats.particles - 1);
    // A mass index the world has no class for.
    let mut heavy = gas(8, 8, 0.4, 3, |d| d.per_particle_mass = true);
    let (o, v, mut m) = {
        let p = heavy.port_planes();
        (p.occupancy.to_vec(), p.velocity.to_vec(), p.mass_index.to_vec())
    };
    let cell = o[0].trailing_zeros() as usize;
    m[cell] = 1;
    let planes = PortPlanes { occupancy: &o, row_words: 1, velocity: &v, life: &[], mass_index: &m, id: &[], age: &[], tag: &[] };
    let seen = |e: mpca::Error| (e.kind(), e.detail());
    assert_eq!(heavy.port_finish_steps(&planes, &one, &[]).map_err(seen), Err((ImageInvalid, "planes.mass_index names a class the world has not")));
    // Ids: one never given, and fewer ids given than before.
    let mut named = gas(8, 8, 0.4, 3, |d| d.identity = mpca::Identity::ALL);
    let (o, v, mut id, age, tag) = {
        let p = named.port_planes();
        (p.occupancy.to_vec(), p.velocity.to_vec(), p.id.to_vec(), p.age.to_vec(), p.tag.to_vec())
    };
    let given = named.port_ids_given();
    let counts = StepCounts { steps: 1, ids_given: given, ..StepCounts::default() };
    let fewer = StepCounts { ids_given: given - 1, ..counts };
    let planes = PortPlanes { occupancy: &o, row_words: 1, velocity: &v, life: &[], mass_index: &[], id: &id, age: &age, tag: &tag };
    assert_eq!(named.port_finish_steps(&planes, &fewer, &[]).map_err(seen), Err((ImageInvalid, "counts.ids_given is below the world's")));
    let cell = o[0].trailing_zeros() as usize;
    id[4 * cell..4 * cell + 4].copy_from_slice(&(given + 1).to_ne_bytes());
    let planes = PortPlanes { occupancy: &o, row_words: 1, velocity: &v, life: &[], mass_index: &[], id: &id, age: &age, tag: &tag };
    assert_eq!(named.port_finish_steps(&planes, &counts, &[]).map_err(seen), Err((ImageInvalid, "planes.id holds an id never given")));
}

#[test]
fn steps_recorded_into_the_callers_encoder_step_as_on_the_cpu() {
    // An engine's frame: its own encoder, two recordings in one
    // submission; a sync before the submission says so, and one after it
    // finds the CPU's world.
    let gpu = gpu();
    let mut w = gas(64, 32, 0.4, 9, |d| d.boundary[1] = [mpca::Boundary::Wall; 2]);
    let mut g = GpuWorld::new(&gpu, &w).unwrap();
    for frame in 0..3 {
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        g.record(&mut encoder, 2);
        g.record(&mut encoder, 3);
        assert!(matches!(g.sync(), Err(mpca_gpu::Error::Unsubmitted)), "frame {frame}");
        gpu.queue.submit([encoder.finish()]);
        w.step(5);
        let on_gpu = g.sync().unwrap();
        assert_eq!((on_gpu.stats(), on_gpu.state_hash()), (w.stats(), w.state_hash()), "frame {frame}");
    }
}

/// Steps `w` and a GPU copy of it 9 steps, with the exports recorded in
/// the same encoder after the steps, and checks every particle's cell and
/// velocity in the CPU's order, the draw's count, and the density of each
/// 4 x 4 tile (the texture's rows read through a buffer, padded as a copy
/// needs); and the world itself.
fn exports_match(mut w: WorldBox) {
    let gpu = gpu();
    let [nx, ny, _] = w.description().size;
    let mut g = GpuWorld::new(&gpu, &w).unwrap();
    let exports = mpca_gpu::Exports::new(&g, 4).unwrap();
    let mut encoder = gpu.device.create_command_encoder(&Default::default());
    g.record(&mut encoder, 9);
    exports.record(&g, &mut encoder);
    let (tw, th) = (nx.div_ceil(4), ny.div_ceil(4));
    // Eight bytes a texel (four half floats), rows padded as a copy needs.
    let row = (8 * tw).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let texels = gpu.device.create_buffer(&wgpu::BufferDescriptor { label: None, size: u64::from(row * th), usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC, mapped_at_creation: false });
    encoder.copy_texture_to_buffer(
        exports.density.as_image_copy(),
        wgpu::TexelCopyBufferInfo { buffer: &texels, layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None } },
        exports.density.size(),
    );
    gpu.queue.submit([encoder.finish()]);
    w.step(9);
    assert!(w.stats().exited > 0, "the test wants particles gone through the open faces");
    let particles: Vec<[f32; 4]> = bytemuck::cast_slice::<u8, [f32; 4]>(&gpu.read(&exports.particles)).to_vec();
    let draw: Vec<u32> = bytemuck::cast_slice(&gpu.read(&exports.draw)).to_vec();
    let cpu: Vec<_> = w.particles().collect();
    assert_eq!(draw, [6, cpu.len() as u32, 0, 0]);
    for (i, p) in cpu.iter().enumerate() {
        let q = particles[i];
        assert_eq!([q[0], q[1]], [p.pos[0] as f32 + 0.5, p.pos[1] as f32 + 0.5], "particle {i}");
        for k in 0..2 {
            assert!((q[2 + k] - p.velocity[k]).abs() <= 1e-6, "particle {i}: {q:?} {p:?}");
        }
    }
    let texels = gpu.read(&texels);
    for ty in 0..th {
        for tx in 0..tw {
            let at = (row * ty + 8 * tx) as usize;
            let share = half::f16::from_le_bytes([texels[at], texels[at + 1]]).to_f32();
            let n = cpu.iter().filter(|p| p.pos[0] / 4 == tx && p.pos[1] / 4 == ty).count();
            assert_eq!(share, n as f32 / 16.0, "tile {tx} {ty}");
        }
    }
    assert_eq!(g.sync().unwrap().state_hash(), w.state_hash());
}

#[test]
fn the_exports_hold_the_cpus_particles_in_its_order() {
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        exports_match(gas(70, 36, 0.35, 21, |d| {
            d.boundary[0] = [mpca::Boundary::Open; 2];
            d.quantization = quantization;
        }));
    }
}

#[test]
fn a_world_moves_between_the_cpu_and_the_gpu_through_its_image_mid_run() {
    // A GPU world runs a world of its own, then takes the CPU's image at
    // step 10 (another seed and restitution: its settings come with it),
    // runs on, and its image comes back to a fresh CPU world that runs on:
    // all equal to the CPU's own run. Images of another size, or of a 3D
    // world, are refused and change nothing.
    let gpu = gpu();
    let walls = |d: &mut Description| d.boundary[1] = [mpca::Boundary::Wall; 2];
    let mut cpu = gas(48, 40, 0.4, 31, walls);
    let mut g = GpuWorld::new(&gpu, &gas(48, 40, 0.2, 32, |d| {
        walls(d);
        d.restitution = 0.3;
    }))
    .unwrap();
    g.step(7);
    cpu.step(10);
    g.load(&image(&cpu)).unwrap();
    let before = g.sync().unwrap().state_hash();
    assert_eq!(before, cpu.state_hash());
    let solid = WorldBox::new(&Description::new_3d(48, 40, 2)).unwrap();
    let why = (mpca::ErrorKind::ImageMismatch, "desc.size");
    for other in [&*gas(50, 40, 0.4, 31, walls), &*solid] {
        assert!(matches!(g.load(&image(other)), Err(mpca_gpu::Error::World(e)) if (e.kind(), e.detail()) == why));
        assert_eq!(g.sync().unwrap().state_hash(), before);
    }
    g.step(15);
    cpu.step(15);
    let back = image(g.sync().unwrap());
    assert!(back == image(&cpu));
    let mut again = WorldBox::new(&mpca::image_description(&back).unwrap()).unwrap();
    again.load(&back).unwrap();
    again.step(5);
    cpu.step(5);
    assert_eq!((again.stats(), again.state_hash()), (cpu.stats(), cpu.state_hash()));
}

#[test]
fn sixteen_bit_velocities_step_as_on_the_cpu() {
    // 16-bit storage (M1c: F = 12, the move limits computed, a word a
    // cell) under both drift rules, with walls, an open face and gravity.
    for drift in [Drift::Calibrated, Drift::Paper] {
        let mut w = gas(66, 20, 0.5, 41, |d| {
            d.quantization = mpca::Quantization::Bits16;
            d.drift = drift;
            d.boundary[0] = [mpca::Boundary::Wall, mpca::Boundary::Open];
            d.forces.uniform = true;
            d.gravity = [0.0, 0.01, 0.0];
        });
        same_worlds(&mut w, 24, 1);
    }
}

#[test]
fn speed_limited_collisions_step_as_on_the_cpu() {
    // M5.2b: a dense elastic gas of particles up to nearly the unit
    // speed, where tries are refused and drawn again, at both widths, with
    // and without energy-neutral rounding (M1b: the elastic box of M10).
    for (quantization, neutral) in [(mpca::Quantization::Bits8, false), (mpca::Quantization::Bits16, false), (mpca::Quantization::Bits8, true), (mpca::Quantization::Bits16, true)] {
        let mut w = gas(64, 32, 0.7, 51, |d| {
            d.collisions = mpca::Collisions::SpeedLimited;
            d.quantization = quantization;
            d.energy_neutral = neutral;
        });
        same_worlds(&mut w, 20, 1);
    }
}

#[test]
fn contacts_step_as_on_the_cpu() {
    // M5.7: a dense inelastic pile under gravity in a box, where refused
    // moves meet the particles placed in their cells, at both widths; and
    // with energy-neutral rounding (M1b) after every collision and contact.
    for (quantization, neutral) in [(mpca::Quantization::Bits8, false), (mpca::Quantization::Bits16, false), (mpca::Quantization::Bits8, true), (mpca::Quantization::Bits16, true)] {
        let pile = |contacts| {
            gas(40, 40, 0.6, 61, |d| {
                d.contacts = contacts;
                d.energy_neutral = neutral;
                d.restitution = 0.5;
                d.quantization = quantization;
                d.boundary[0] = [mpca::Boundary::Wall; 2];
                d.boundary[1] = [mpca::Boundary::Wall; 2];
                d.forces.uniform = true;
                d.gravity = [0.0, 0.02, 0.0];
            })
        };
        let mut w = pile(true);
        same_worlds(&mut w, 40, 1);
        // The contacts did something: without them the pile differs.
        let mut without = pile(false);
        without.step(40);
        assert_ne!(without.state_hash(), w.state_hash());
    }
}

#[test]
fn the_papers_smoke_scene_steps_as_on_the_cpu() {
    // 4.3: an emitter, the Rankine vortex force, open faces and a wall
    // floor, 120 steps, compared every 10.
    same_scene(mpca_tests::scenes::smoke(), 10);
}

#[test]
fn emitters_and_the_vortex_step_as_on_the_cpu() {
    // Two emitters (one with a spread and a lifetime, one asking for more
    // than its region holds, so it falls short), a vortex whose centre lies
    // on a cell's corner and one off the grid, with gravity, at both
    // widths.
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        for centre in [[20.0, 12.0], [20.3, 300.0]] {
            let mut w = gas(40, 24, 0.1, 71, |d| {
                d.quantization = quantization;
                d.boundary[1] = [mpca::Boundary::Wall, mpca::Boundary::Open];
                d.forces.vortex = true;
                d.vortex = mpca::Vortex { centre, core_radius: 3.0, circulation: -5.0 };
                d.forces.uniform = true;
                d.gravity = [0.0, 0.003, 0.0];
                d.emitter_capacity = 3;
                d.lifetimes = true;
            });
            let emitter = |min: [u32; 3], max: [u32; 3], rate: f32, spread: f32, lifetime: u32| mpca::Emitter { min, max, rate, velocity: [0.2, 0.3, 0.0], spread, mass: 1.0, lifetime };
            w.add_emitter(emitter([2, 2, 0], [8, 5, 0], 1.7, 0.4, 7)).unwrap();
            w.add_emitter(emitter([30, 0, 0], [32, 2, 0], 6.5, 0.0, 0)).unwrap();
            same_worlds(&mut w, 30, 1);
            assert!(w.stats().emit_shortfall > 0, "the second emitter falls short");
            assert!(w.stats().expired > 0, "the first emitter's particles expire");
        }
    }
}

#[test]
fn the_smoke_scene_with_flow_drag_steps_as_on_the_cpu() {
    // 4.3b: buoyancy, drag towards a vortex fed through its core (the wind
    // plane and the vortex read as a flow), speed-limited collisions, an
    // emitter; 1,200 steps, compared every 100.
    same_scene(mpca_tests::scenes::smoke_flow(), 100);
}

#[test]
fn the_turbulent_plume_steps_as_on_the_cpu() {
    // M5.1c: the smoke preset's plume with its turbulence (eddies of 16
    // cells, open faces and a floor); 600 steps, compared every 50.
    let mut scene = mpca_tests::scenes::plume(true, 4);
    scene.steps = 600;
    same_scene(scene, 50);
}

#[test]
fn turbulence_steps_as_on_the_cpu_in_3d() {
    // M5.1c in 3D: the three components of the potential, periodic x and z
    // (the lattice and the corners wrap), walls on y, at both widths.
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        let mut w = gas_3d(
            [16, 8, 8],
            0.3,
            171,
            |d| {
                d.quantization = quantization;
                d.boundary[1] = [mpca::Boundary::Wall; 2];
                let turbulence = mpca::Turbulence { amplitude: 0.6, scale: 4, rate: 0.1 };
                d.drag = mpca::Drag { rate: 0.3, turbulence, ..mpca::Drag::OFF };
            },
            |_| {},
        );
        same_worlds(&mut w, 30, 1);
    }
}

#[test]
fn force_fields_potentials_and_drag_step_as_on_the_cpu() {
    // Every per-cell term at once, from random planes (some values large
    // enough to saturate M1c's conv, some tiny): a force field, a
    // potential (one-sided at the walls, wrapped on the periodic axis),
    // drag towards a uniform wind plus the wind plane plus the vortex as a
    // flow, and the vortex force; at both widths, periodic x and walled y.
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        let mut w = gas(34, 20, 0.4, 81, |d| {
            d.quantization = quantization;
            d.boundary[1] = [mpca::Boundary::Wall; 2];
            d.forces.field = true;
            d.forces.potential = true;
            d.forces.vortex = true;
            d.vortex = mpca::Vortex { centre: [17.0, 10.5], core_radius: 4.0, circulation: 3.0 };
            // Turbulence of eddies of 2 cells: 2 divides the periodic 34.
            let turbulence = mpca::Turbulence { amplitude: 0.3, scale: 2, rate: 0.3 };
            d.drag = mpca::Drag { rate: 0.2, wind: [0.1, -0.05, 0.0], field: true, vortex: true, turbulence };
            d.mass = 1.7;
        });
        let mut rng = mpca::rng::block_stream(82, 0, 0);
        let cells = 34 * 20;
        let mut value = |scale: f32| (rng.bits(16) as f32 / 32768.0 - 1.0) * scale;
        let force: Vec<f32> = (0..2 * cells).map(|i| value(if i % 97 == 0 { 1e30 } else if i % 89 == 0 { 1e-20 } else { 0.02 })).collect();
        let potential: Vec<f32> = (0..cells).map(|_| value(0.05)).collect();
        let wind: Vec<f32> = (0..cells).flat_map(|_| [value(0.3), value(0.3)]).collect();
        w.set_force_field(&force).unwrap();
        w.set_potential(&potential).unwrap();
        w.set_wind_field(&wind).unwrap();
        same_worlds(&mut w, 25, 1);
    }
}

#[test]
fn obstacles_step_as_on_the_cpu() {
    // M5.4 off obstacles (M7): a disc, a box, a floor tilted by 30 degrees
    // (a staircase, where particles leave the surface and keep their
    // velocity, or turn back off the face they came through), a mask blob
    // and a cell with a normal of its own; walls below and above, periodic
    // x (the half-space seen across the seam), gravity, an emitter whose
    // region holds obstacle cells; at both widths.
    use mpca::Shape;
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        let mut w = gas_around(
            64,
            48,
            0.35,
            91,
            |d| {
                d.quantization = quantization;
                d.boundary[1] = [mpca::Boundary::Wall; 2];
                d.obstacles = true;
                d.surface_capacity = 2000;
                d.forces.uniform = true;
                d.gravity = [0.0, 0.01, 0.0];
                d.wall_restitution = 0.6;
                d.emitter_capacity = 1;
            },
            |w| {
                w.add_shape(Shape::Disc { centre: [20.0, 16.0], radius: 6.5 }, 0.9).unwrap();
                w.add_shape(Shape::Box { min: [40.0, 8.0, 0.0], max: [47.0, 20.0, 1.0] }, 0.3).unwrap();
                w.add_shape(Shape::HalfSpace { point: [0.0, 38.0, 0.0], normal: [-0.5, -0.866_025_4, 0.0] }, 0.7).unwrap();
                let mut mask = vec![0u8; 64 * 48];
                for (i, m) in mask.iter_mut().enumerate() {
                    let (x, y) = ((i % 64) as i32 - 54, (i / 64) as i32 - 26);
                    *m = u8::from(x * x + 2 * y * y <= 12);
                }
                w.add_obstacle_mask(&mask, 1.0).unwrap();
                w.add_obstacle([30, 30, 0], [0.6, -0.8, 0.0], 0.5).unwrap();
                w.add_emitter(mpca::Emitter { min: [16, 2, 0], max: [26, 12, 0], rate: 2.5, velocity: [0.0, 0.4, 0.0], spread: 0.2, mass: 1.0, lifetime: 0 }).unwrap();
            },
        );
        same_worlds(&mut w, 40, 1);
    }
}

#[test]
fn masses_step_as_on_the_cpu() {
    // M9's mass classes: particles of five masses (1e-3 to 40, so shares
    // far from halves and the heavier balanced against the lighter), with
    // gravity, a force field and a potential (divided by each mass), the
    // vortex force, contacts and energy-neutral rounding, an emitter of
    // its own mass; walls and an open face; at both widths.
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        let masses = [1.0f32, 40.0, 0.001, 2.5, 7.0];
        let mut w = gas_around(
            40,
            30,
            0.0,
            101,
            |d| {
                d.quantization = quantization;
                d.per_particle_mass = true;
                d.mass_classes = 8;
                d.boundary[1] = [mpca::Boundary::Wall, mpca::Boundary::Open];
                d.forces = mpca::Forces { uniform: true, field: true, potential: true, vortex: true };
                d.gravity = [0.0, 0.005, 0.0];
                d.vortex = mpca::Vortex { centre: [20.0, 15.0], core_radius: 5.0, circulation: 2.0 };
                d.contacts = true;
                d.energy_neutral = true;
                d.emitter_capacity = 1;
                d.restitution = 0.8;
            },
            |_| {},
        );
        let mut rng = mpca::rng::block_stream(102, 0, 0);
        for y in 0..30 {
            for x in 0..40 {
                if rng.bits(8) < 110 {
                    let v = [rng.bits(16) as f32 / 65536.0 - 0.5, rng.bits(16) as f32 / 65536.0 - 0.5, 0.0];
                    w.add_particle_with_mass([x, y, 0], v, masses[rng.below(5) as usize]).unwrap();
                }
            }
        }
        let cells = 40 * 30;
        let force: Vec<f32> = (0..2 * cells).map(|i| ((i * 37 % 101) as f32 - 50.0) * 2e-4).collect();
        let potential: Vec<f32> = (0..cells).map(|i| ((i * 53 % 97) as f32) * 1e-3).collect();
        w.set_force_field(&force).unwrap();
        w.set_potential(&potential).unwrap();
        w.add_emitter(mpca::Emitter { min: [5, 20, 0], max: [12, 26, 0], rate: 1.3, velocity: [0.1, -0.2, 0.0], spread: 0.1, mass: 2.5, lifetime: 0 }).unwrap();
        same_worlds(&mut w, 30, 1);
    }
}

#[test]
fn ids_ages_and_tags_step_as_on_the_cpu() {
    // M6b: particles added with ids (and tags set on some), two emitters
    // with tags of their own, lifetimes and an open face, so that ids are
    // given, carried, aged and removed; each plane alone and all three, at
    // both widths.
    for (identity, quantization) in [(mpca::Identity::ALL, mpca::Quantization::Bits8), (mpca::Identity::IDS, mpca::Quantization::Bits16), (mpca::Identity::AGES, mpca::Quantization::Bits8), (mpca::Identity::TAGS, mpca::Quantization::Bits16)] {
        let mut w = gas(34, 24, 0.3, 111, |d| {
            d.identity = identity;
            d.quantization = quantization;
            d.boundary[0] = [mpca::Boundary::Open, mpca::Boundary::Wall];
            d.lifetimes = true;
            d.emitter_capacity = 2;
            d.per_particle_mass = identity == mpca::Identity::ALL;
        });
        if identity.contains(mpca::Identity::TAGS) {
            for (i, p) in w.particles().collect::<Vec<_>>().into_iter().enumerate().step_by(3) {
                w.set_tag(p.pos, (i % 250) as u8 + 1).unwrap();
            }
        }
        let emitter = |min: [u32; 3], max: [u32; 3], lifetime: u32| mpca::Emitter { min, max, rate: 2.2, velocity: [0.3, 0.1, 0.0], spread: 0.3, mass: 1.0, lifetime };
        let a = w.add_emitter(emitter([2, 2, 0], [10, 8, 0], 9)).unwrap();
        let b = w.add_emitter(emitter([20, 14, 0], [30, 20, 0], 0)).unwrap();
        if identity.contains(mpca::Identity::TAGS) {
            w.set_emitter_tag(a, 7).unwrap();
            w.set_emitter_tag(b, 200).unwrap();
        }
        same_worlds(&mut w, 30, 1);
    }
}

#[test]
fn exhaustive_and_greedy_assignments_step_as_on_the_cpu() {
    // M5.6 by the paper's exhaustive search and by greedy, in a dense gas
    // with walls and obstacles (blocked cells in the blocks) and gravity.
    for method in [mpca::Method::Exhaustive, mpca::Method::Greedy] {
        let mut w = gas_around(
            34,
            26,
            0.6,
            121,
            |d| {
                d.method = method;
                d.boundary[1] = [mpca::Boundary::Wall; 2];
                d.obstacles = true;
                d.surface_capacity = 200;
                d.forces.uniform = true;
                d.gravity = [0.0, 0.01, 0.0];
            },
            |w| w.add_shape(mpca::Shape::Disc { centre: [17.0, 13.0], radius: 4.5 }, 0.5).unwrap(),
        );
        same_worlds(&mut w, 30, 1);
    }
}

#[test]
fn walls_open_faces_and_gravity_step_as_on_the_cpu_in_3d() {
    // Mixes of wall, open and periodic axes in 3D (edges and corners
    // beyond two and three walls, with their diagonal normals, and walls
    // beside open faces), with a uniform force strong enough to clamp, at
    // both widths and at sizes whose half blocks cross words.
    use mpca::Boundary::{Open, Periodic, Wall};
    let faces = [[[Wall, Wall], [Wall, Wall], [Wall, Wall]], [[Open, Wall], [Wall, Open], [Periodic, Periodic]], [[Periodic, Periodic], [Wall, Wall], [Open, Wall]]];
    for (i, f) in faces.into_iter().enumerate() {
        for (size, quantization) in [([8, 6, 4], mpca::Quantization::Bits8), ([34, 4, 6], mpca::Quantization::Bits16)] {
            let mut w = gas_3d(size, 0.4, 130 + i as u64, |d| {
                d.boundary = f;
                d.wall_restitution = 0.7;
                d.method = mpca::Method::Greedy;
                d.quantization = quantization;
                d.forces.uniform = true;
                d.gravity = [0.02, -0.3, 0.4];
            }, |_| {});
            same_worlds(&mut w, 12, 1);
        }
    }
}

#[test]
fn obstacles_emitters_and_identity_step_as_on_the_cpu_in_3d() {
    // M5.4 off 3D obstacles (a sphere, a box, a tilted half-space, a mask
    // blob, a cell with its own normal) in a walled box under gravity, an
    // emitter over obstacle cells with a spread and a lifetime (M6), ids,
    // ages and tags (M6b), contacts (M5.7); at both widths.
    use mpca::Shape;
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        let mut w = gas_3d(
            [36, 16, 12],
            0.25,
            141,
            |d| {
                d.quantization = quantization;
                d.method = mpca::Method::Greedy;
                d.boundary = [[mpca::Boundary::Periodic; 2], [mpca::Boundary::Wall; 2], [mpca::Boundary::Wall, mpca::Boundary::Open]];
                d.obstacles = true;
                d.surface_capacity = 3000;
                d.forces.uniform = true;
                d.gravity = [0.0, -0.01, 0.003];
                d.wall_restitution = 0.6;
                d.restitution = 0.7;
                d.contacts = true;
                d.emitter_capacity = 1;
                d.lifetimes = true;
                d.identity = mpca::Identity::ALL;
            },
            |w| {
                w.add_shape(Shape::Sphere { centre: [9.0, 8.0, 6.0], radius: 3.5 }, 0.9).unwrap();
                w.add_shape(Shape::Box { min: [20.0, 2.0, 3.0], max: [25.0, 7.0, 8.0] }, 0.3).unwrap();
                w.add_shape(Shape::HalfSpace { point: [0.0, 3.0, 0.0], normal: [0.2, 0.95, -0.2] }, 0.7).unwrap();
                let mut mask = vec![0u8; 36 * 16 * 12];
                for (i, m) in mask.iter_mut().enumerate() {
                    let (x, y, z) = ((i % 36) as i32 - 30, (i / 36 % 16) as i32 - 11, (i / 576) as i32 - 6);
                    *m = u8::from(x * x + 2 * y * y + z * z <= 6);
                }
                w.add_obstacle_mask(&mask, 1.0).unwrap();
                w.add_obstacle([15, 12, 2], [0.6, -0.8, 0.0], 0.5).unwrap();
                w.add_emitter(mpca::Emitter { min: [6, 10, 3], max: [14, 14, 9], rate: 3.5, velocity: [0.1, -0.3, 0.2], spread: 0.25, mass: 1.0, lifetime: 9 }).unwrap();
            },
        );
        same_worlds(&mut w, 24, 1);
        assert!(w.stats().expired > 0 && w.stats().exited > 0, "particles expire and leave: {:?}", w.stats());
    }
}

#[test]
fn forces_masses_and_collision_rules_step_as_on_the_cpu_in_3d() {
    // Every force term in 3D (a force field and a potential from random
    // planes, the vortex about z, drag towards a uniform wind, the wind
    // plane and the vortex as a flow), five masses, speed-limited
    // collisions and energy-neutral rounding; walls on y, at both widths.
    for quantization in [mpca::Quantization::Bits8, mpca::Quantization::Bits16] {
        let size = [18u32, 10, 8];
        let masses = [1.0f32, 40.0, 0.001, 2.5, 7.0];
        let mut w = gas_3d(
            size,
            0.0,
            151,
            |d| {
                d.quantization = quantization;
                d.method = mpca::Method::Greedy;
                d.boundary[1] = [mpca::Boundary::Wall; 2];
                d.forces = mpca::Forces { uniform: true, field: true, potential: true, vortex: true };
                d.gravity = [0.0, 0.004, -0.002];
                d.vortex = mpca::Vortex { centre: [9.0, 5.5], core_radius: 3.0, circulation: 2.5 };
                let turbulence = mpca::Turbulence { amplitude: 0.4, scale: 2, rate: 0.3 };
                d.drag = mpca::Drag { rate: 0.2, wind: [0.1, -0.05, 0.07], field: true, vortex: true, turbulence };
                d.per_particle_mass = true;
                d.mass_classes = 8;
                d.collisions = mpca::Collisions::SpeedLimited;
                d.energy_neutral = true;
            },
            |_| {},
        );
        let mut rng = mpca::rng::block_stream(152, 0, 0);
        let cells = (size[0] * size[1] * size[2]) as usize;
        for i in 0..cells as u32 {
            if rng.bits(8) < 100 {
                let v = [0, 1, 2].map(|_| rng.bits(16) as f32 / 65536.0 - 0.5);
                w.add_particle_with_mass([i % size[0], i / size[0] % size[1], i / (size[0] * size[1])], v, masses[rng.below(5) as usize]).unwrap();
            }
        }
        let mut value = |scale: f32| (rng.bits(16) as f32 / 32768.0 - 1.0) * scale;
        let force: Vec<f32> = (0..3 * cells).map(|i| value(if i % 97 == 0 { 1e30 } else { 0.02 })).collect();
        let potential: Vec<f32> = (0..cells).map(|_| value(0.05)).collect();
        let wind: Vec<f32> = (0..cells).flat_map(|_| [value(0.3), value(0.3), value(0.3)]).collect();
        w.set_force_field(&force).unwrap();
        w.set_potential(&potential).unwrap();
        w.set_wind_field(&wind).unwrap();
        same_worlds(&mut w, 16, 1);
    }
}

#[test]
fn the_papers_water_scene_steps_as_on_the_cpu() {
    // 4.4: 3D 64^3, walls all round, gravity, a sphere obstacle, an
    // emitter with a spread, exact-fast assignment and 8-bit velocities;
    // 130 steps, compared every 10.
    same_scene(mpca_tests::scenes::water(), 10);
}
