//! Particle accounting (M6) and obstacle fidelity (M10) in busy scenes:
//! emitters with lifetimes, open faces, walls, obstacles and gravity.

mod common;

use common::memory;
use mpca::{Boundary, Description, Emitter, Shape, World};

/// Checks, after a step, the invariants of M6 and M10:
/// - the count is exactly initial + emitted - exited - expired;
/// - it is the number of particles the world holds;
/// - no particle sits on an obstacle cell;
/// - every lifetime is within the emitter's.
fn check_books(world: &World, initial: u64, lifetime: u16, step: u64) {
    let s = world.stats();
    assert_eq!(s.step, step);
    assert_eq!(s.particles, initial + s.emitted - s.exited - s.expired, "step {step}: {s:?}");
    assert_eq!(world.particles().count() as u64, s.particles, "step {step}");
    assert_eq!(world.particle_count(), s.particles);
    for p in world.particles() {
        assert!(!world.obstacle_at(p.pos), "step {step}: particle inside an obstacle at {:?}", p.pos);
        assert!(p.life <= lifetime, "step {step}: life {} > {lifetime}", p.life);
    }
}

/// Places about `density` of the free cells with random velocities of speed
/// at most 0.8, returning how many were placed.
fn scatter(world: &mut World, desc: &Description, density: f32, seed: u64) -> u64 {
    let mut rng = common::test_rng(seed);
    let mut placed = 0;
    for pos in common::cells(desc) {
        if rng.unit() < density && !world.obstacle_at(pos) {
            world.add_particle(pos, rng.velocity(desc.dim, 0.8)).unwrap();
            placed += 1;
        }
    }
    placed
}

/// M6 in 2D: open sides and top, a wall below, a disc and a box obstacle,
/// gravity, and an emitter with a lifetime under the top. Expected after
/// every one of 400 steps: the books balance, the count matches the
/// particles held, and none is on an obstacle; and by the end particles
/// were emitted, have exited and have expired (the scene exercises all).
#[test]
fn books_balance_2d() {
    let mut desc = Description::new_2d(64, 64).with_boundary(Boundary::Open);
    desc.boundary[1][0] = Boundary::Wall;
    desc.obstacles = true;
    desc.surface_capacity = 512;
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.01, 0.0];
    desc.restitution = 0.8;
    desc.wall_restitution = 0.9;
    desc.emitter_capacity = 2;
    desc.lifetimes = true;
    desc.seed = 61;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    world.add_shape(Shape::Disc { centre: [32.0, 20.0], radius: 6.0 }, 1.0).unwrap();
    world.add_shape(Shape::Box { min: [10.0, 30.0, 0.0], max: [20.0, 36.0, 1.0] }, 0.5).unwrap();
    let initial = scatter(world, &desc, 0.2, 61);
    let lifetime = 80;
    let e = Emitter {
        min: [24, 54, 0],
        max: [40, 60, 1],
        rate: 3.5,
        velocity: [0.0, -0.4, 0.0],
        spread: 0.4,
        mass: 1.0,
        lifetime: u32::from(lifetime),
    };
    world.add_emitter(e).unwrap();
    // A second emitter right over the disc keeps particles arriving there.
    world.add_emitter(Emitter { min: [28, 27, 0], max: [36, 29, 1], rate: 0.7, ..e }).unwrap();
    check_books(world, initial, lifetime, 0);
    for step in 1..=400 {
        world.step(1);
        check_books(world, initial, lifetime, step);
    }
    let s = world.stats();
    assert!(s.emitted > 0 && s.exited > 0 && s.expired > 0, "{s:?}");
}

/// M6 in 3D: a sphere and a half-space floor, open x faces, periodic z, a
/// wall below and open above, gravity, an emitter with a lifetime. Expected
/// after every one of 150 steps: the same invariants as in 2D; by the end
/// particles were emitted, have exited and have expired.
#[test]
fn books_balance_3d() {
    let mut desc = Description::new_3d(32, 32, 32);
    desc.boundary[0] = [Boundary::Open; 2];
    desc.boundary[1] = [Boundary::Wall, Boundary::Open];
    desc.obstacles = true;
    desc.surface_capacity = 4096;
    desc.forces.uniform = true;
    desc.gravity = [0.0, -0.02, 0.0];
    desc.emitter_capacity = 1;
    desc.lifetimes = true;
    desc.seed = 62;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    world.add_shape(Shape::Sphere { centre: [16.0, 14.0, 16.0], radius: 6.0 }, 1.0).unwrap();
    world.add_shape(Shape::HalfSpace { point: [0.0, 4.0, 0.0], normal: [0.0, 1.0, 0.0] }, 0.7).unwrap();
    let initial = scatter(world, &desc, 0.1, 62);
    let lifetime = 60;
    world
        .add_emitter(Emitter {
            min: [12, 26, 12],
            max: [20, 30, 20],
            rate: 6.0,
            velocity: [0.1, -0.3, 0.0],
            spread: 0.3,
            mass: 1.0,
            lifetime: u32::from(lifetime),
        })
        .unwrap();
    check_books(world, initial, lifetime, 0);
    for step in 1..=150 {
        world.step(1);
        check_books(world, initial, lifetime, step);
    }
    let s = world.stats();
    assert!(s.emitted > 0 && s.exited > 0 && s.expired > 0, "{s:?}");
}

/// M6: an emitter whose region is full emits fewer and counts the rest.
/// A 2 x 2 region with one obstacle cell, rate 10 (an integer, so exactly
/// 10 wanted every step), resting particles (zero velocity, no force: they
/// never move). Expected: step 1 places 3 and falls 7 short; every later
/// step places none and falls 10 short; the obstacle cell is never used.
#[test]
fn full_region_counts_shortfall() {
    let mut desc = Description::new_2d(16, 16).with_boundary(Boundary::Wall);
    desc.emitter_capacity = 1;
    desc.obstacles = true;
    desc.surface_capacity = 16;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    world.add_obstacle([4, 4, 0], [0.0, 1.0, 0.0], 1.0).unwrap();
    let e = Emitter { min: [3, 3, 0], max: [5, 5, 1], rate: 10.0, mass: 1.0, ..Emitter::default() };
    world.add_emitter(e).unwrap();
    world.step(1);
    let s = world.stats();
    assert_eq!((s.emitted, s.emit_shortfall, s.particles), (3, 7, 3));
    assert!(!matches!(world.cell([4, 4, 0]), Ok(mpca::Cell::Particle(_))));
    for step in 2..=20u64 {
        world.step(1);
        let s = world.stats();
        assert_eq!((s.emitted, s.emit_shortfall, s.particles), (3, 7 + 10 * (step - 1), 3));
    }
}

/// M6, per emitter (issue 27 item 3): what each emitter asked for and
/// placed. Two emitters with rate 4 in a walled 16 x 16 box under no
/// force: one in open space (a 6 x 6 region whose particles drift away at
/// up to 0.5), one in a 2 x 2 corner region whose particles rest (zero
/// velocity, no spread). Expected after 25 steps: the corner emitter asked
/// for 100 and placed 4 (its cells filled on the first step and never
/// emptied); the open one asked for 100 and placed every one its region
/// had room for; the two differences add up to the world's shortfall and
/// the placed ones to its emitted count; an index past the two is
/// `OutOfBounds`.
#[test]
fn each_emitter_counts_what_it_asked_for_and_placed() {
    let mut desc = Description::new_2d(16, 16).with_boundary(Boundary::Wall);
    desc.emitter_capacity = 3;
    desc.seed = 27;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let open = Emitter { min: [5, 5, 0], max: [11, 11, 1], rate: 4.0, velocity: [0.0, 0.3, 0.0], spread: 0.2, mass: 1.0, ..Emitter::default() };
    let corner = Emitter { min: [0, 0, 0], max: [2, 2, 1], rate: 4.0, mass: 1.0, ..Emitter::default() };
    assert_eq!((world.add_emitter(open), world.add_emitter(corner)), (Ok(0), Ok(1)));
    world.step(25);
    let (a, b) = (world.emitter_stats(0).unwrap(), world.emitter_stats(1).unwrap());
    assert_eq!((b.requested, b.delivered), (100, 4), "{b:?}");
    assert_eq!(a.requested, 100);
    assert!(a.delivered > 4 && a.delivered <= 100, "{a:?}");
    let s = world.stats();
    assert_eq!(s.emit_shortfall, (a.requested - a.delivered) + (b.requested - b.delivered));
    assert_eq!(s.emitted, a.delivered + b.delivered);
    assert_eq!(world.emitter_stats(2).map_err(mpca::Error::kind), Err(mpca::ErrorKind::OutOfBounds));
}

/// Issue 27 item 3: a world described without room for emitters says the
/// part is off, not that a table is full. Expected: `NotEnabled` with
/// `emitter_capacity` 0, the detail naming it; with 1, the first emitter
/// is index 0 and the second `EmitterTableFull`.
#[test]
fn no_room_for_emitters_is_not_a_full_table() {
    let e = Emitter { min: [0, 0, 0], max: [2, 2, 1], rate: 1.0, mass: 1.0, ..Emitter::default() };
    let none = (mpca::ErrorKind::NotEnabled, "desc.emitter_capacity is 0");
    let full = (mpca::ErrorKind::EmitterTableFull, "desc.emitter_capacity");
    for (capacity, second) in [(0, none), (1, full)] {
        let mut desc = Description::new_2d(8, 8);
        desc.emitter_capacity = capacity;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        if capacity == 1 {
            assert_eq!(world.add_emitter(e), Ok(0));
        }
        assert_eq!(world.add_emitter(e).map_err(|e| (e.kind(), e.detail())), Err(second), "capacity {capacity}");
    }
}

/// M6 lifetimes: a particle emitted with lifetime L is processed L times:
/// it is seen after steps 1 .. L-1 with life L-1 .. 1 (steps left) and
/// expires during step L. A particle added by hand has life 0 (no limit).
#[test]
fn lifetime_counts_steps() {
    const L: u16 = 5;
    let mut desc = Description::new_2d(8, 8).with_boundary(Boundary::Wall);
    desc.emitter_capacity = 1;
    desc.lifetimes = true;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    world.add_particle([0, 0, 0], [0.0; 3]).unwrap();
    let e =
        Emitter { min: [4, 4, 0], max: [5, 5, 1], rate: 1.0, mass: 1.0, lifetime: u32::from(L), ..Emitter::default() };
    world.add_emitter(e).unwrap();
    // Emit exactly once: rate 1 for one step, then 0.
    world.step(1);
    world.set_emitter_rate(0, 0.0).unwrap();
    for step in 1..L {
        if step > 1 {
            world.step(1);
        }
        let life = common::particle(world, [4, 4, 0]).life;
        assert_eq!(life, L - step, "after step {step}");
        assert_eq!(world.stats().expired, 0);
    }
    world.step(1);
    let s = world.stats();
    assert_eq!((s.emitted, s.expired, s.particles), (1, 1, 1));
    assert_eq!(common::particle(world, [0, 0, 0]).life, 0);
    world.step(100);
    assert_eq!(world.stats().particles, 1, "a hand-added particle lives on");
}

/// Removing a particle by hand is counted too: the count is always
/// added + emitted - exited - expired - removed (Stats::particles).
#[test]
fn removal_is_counted() {
    let desc = Description::new_2d(8, 8);
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    world.add_particle([1, 1, 0], [0.3, 0.0, 0.0]).unwrap();
    world.add_particle([5, 5, 0], [0.0, 0.3, 0.0]).unwrap();
    world.step(3);
    let p = world.particles().next().unwrap();
    let removed = world.remove_particle(p.pos).unwrap();
    assert_eq!(removed, p);
    assert_eq!(world.stats().particles, 1);
    assert_eq!(world.particles().count(), 1);
    assert_eq!(world.remove_particle(p.pos).map_err(mpca::Error::kind), Err(mpca::ErrorKind::NoParticle));
}

/// M3: step t partitions the grid with offset t mod 2; along an axis of n
/// cells there are n/2 blocks at offset 0, n/2 at offset 1 when periodic and
/// n/2 + 1 (two halves at the faces) when not. Expected: processed + skipped
/// equals the product over the axes, at both offsets, for periodic, wall,
/// open and mixed faces, in 2D and 3D; processed is the number of blocks
/// holding a particle (one particle here: 1).
#[test]
fn blocks_follow_the_partition() {
    let n = 16u32;
    for dim in [2u32, 3] {
        for faces in ["periodic", "wall", "open", "mixed"] {
            let mut desc = if dim == 2 { Description::new_2d(n, n) } else { Description::new_3d(n, n, n) };
            desc = match faces {
                "periodic" => desc.with_boundary(Boundary::Periodic),
                "wall" => desc.with_boundary(Boundary::Wall),
                "open" => desc.with_boundary(Boundary::Open),
                _ => {
                    let mut d = desc.with_boundary(Boundary::Periodic);
                    d.boundary[1] = [Boundary::Open, Boundary::Wall];
                    d
                }
            };
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            world.add_particle([5, 6, if dim == 3 { 7 } else { 0 }], [0.0; 3]).unwrap();
            for step in 0..4u64 {
                world.step(1);
                let (processed, skipped) = world.last_step_blocks();
                let mut total = 1u64;
                for k in 0..dim as usize {
                    let periodic = desc.boundary[k][0] == Boundary::Periodic;
                    total *= u64::from(n / 2) + u64::from(step % 2 == 1 && !periodic);
                }
                assert_eq!((processed, processed + skipped), (1, total), "{dim}D {faces} step {step}");
                let s = world.stats();
                assert_eq!((s.blocks_processed, s.blocks_skipped), (processed, skipped));
            }
        }
    }
}

/// `density` bins: bin i of r along an axis of n cells covers cells
/// i n / r .. (i + 1) n / r, and holds the share of its cells holding a
/// particle. Expected: at full resolution, 1 exactly on occupied cells and 0
/// elsewhere; at resolution 1, particles / cells; at an uneven resolution
/// (3 bins of 16 cells: 5, 5, 6), each bin's count over its own cells; the
/// u8 version is that share times 255, rounded; bad resolutions or lengths
/// are BadResolution.
#[test]
fn density_bins_count_particles() {
    let desc = Description::new_3d(16, 8, 4);
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let mut rng = common::test_rng(71);
    let cells: Vec<[u32; 3]> = common::cells(&desc).collect();
    for &pos in &cells {
        if rng.unit() < 0.35 {
            world.add_particle(pos, [0.0; 3]).unwrap();
        }
    }
    let occupied = |p: [u32; 3]| matches!(world.cell(p), Ok(mpca::Cell::Particle(_)));
    let mut full = vec![0.0f32; 16 * 8 * 4];
    world.density([16, 8, 4], &mut full).unwrap();
    for (i, &pos) in cells.iter().enumerate() {
        assert_eq!(full[i], if occupied(pos) { 1.0 } else { 0.0 }, "{pos:?}");
    }
    let mut one = [0.0f32; 1];
    world.density([1, 1, 1], &mut one).unwrap();
    assert_eq!(one[0], world.particle_count() as f32 / 512.0);
    let edges = |n: u32, r: u32, i: u32| (i * n / r)..((i + 1) * n / r);
    let mut uneven = vec![0.0f32; 3 * 3 * 2];
    let mut bytes = vec![0u8; 3 * 3 * 2];
    world.density([3, 3, 2], &mut uneven).unwrap();
    world.density_u8([3, 3, 2], &mut bytes).unwrap();
    let mut i = 0;
    for bz in 0..2 {
        for by in 0..3 {
            for bx in 0..3 {
                let (xs, ys, zs) = (edges(16, 3, bx), edges(8, 3, by), edges(4, 2, bz));
                let total = xs.len() * ys.len() * zs.len();
                let hit = cells
                    .iter()
                    .filter(|p| xs.contains(&p[0]) && ys.contains(&p[1]) && zs.contains(&p[2]) && occupied(**p))
                    .count();
                assert_eq!(uneven[i], hit as f32 / total as f32, "bin {bx} {by} {bz}");
                assert_eq!(usize::from(bytes[i]), (hit * 255 + total / 2) / total, "u8 bin {bx} {by} {bz}");
                i += 1;
            }
        }
    }
    assert_eq!(world.density([0, 1, 1], &mut one).map_err(mpca::Error::kind), Err(mpca::ErrorKind::BadResolution));
    assert_eq!(world.density([17, 1, 1], &mut [0.0; 17]).map_err(mpca::Error::kind), Err(mpca::ErrorKind::BadResolution));
    assert_eq!(world.density([2, 1, 1], &mut one).map_err(mpca::Error::kind), Err(mpca::ErrorKind::BadResolution));
}

/// Where a particle with |v_k| = 1 (p = 1 under the paper's drift) on
/// coordinate `x` of an axis of `n` cells is after `steps` steps, by M3-M5
/// directly: at step t (offset o = t mod 2) it moves one cell along `dir`
/// exactly when the next cell lies in its block, i.e. when it is on the
/// block's low side (x - o even) for +1 or the high side for -1. Beyond a
/// face it wraps (periodic), leaves (open: None) or is reflected with e = 1
/// and stays (wall: dir flips).
fn unit_speed_reference(mut x: i64, mut dir: i64, n: i64, face: Boundary, steps: u64) -> Option<(i64, i64)> {
    for t in 0..steps as i64 {
        let low_side = (x - t % 2).rem_euclid(2) == 0;
        if low_side != (dir > 0) {
            continue;
        }
        let to = x + dir;
        if (0..n).contains(&to) {
            x = to;
            continue;
        }
        match face {
            Boundary::Periodic => x = to.rem_euclid(n),
            Boundary::Open => return None,
            Boundary::Wall => dir = -dir,
        }
    }
    Some((x, dir))
}

/// M3: every block holding a particle is visited, at both offsets, wherever
/// it lies: across the 64-cell words of the occupancy rows (axes of 2, 4,
/// 64, 66 and 130 cells: one to three words, and word edges inside and
/// between blocks), at the wrapping block of a periodic axis and at the
/// half blocks of the faces. One particle per line (lines 4 apart on the
/// other axes, so none share a block), with unit speed along the axis, so
/// its path is deterministic. Expected after 3 steps: every particle where
/// `unit_speed_reference` puts it, with its velocity, or gone through an
/// open face, for every start cell, both directions, every axis, 2D and 3D.
#[test]
fn every_occupied_block_is_visited() {
    for n in [2u32, 4, 64, 66, 130] {
        visit_every_block(n);
    }
}

fn visit_every_block(n: u32) {
    for dim in [2u32, 3] {
        for axis in 0..dim as usize {
            for face in [Boundary::Periodic, Boundary::Open, Boundary::Wall] {
                for dir in [1i64, -1] {
                    // The moving axis has n cells; the others hold the lines.
                    let other = if dim == 2 { 4 * n } else { 48 };
                    let mut size = [other, other, if dim == 3 { other } else { 1 }];
                    size[axis] = n;
                    let mut desc = if dim == 2 {
                        Description::new_2d(size[0], size[1])
                    } else {
                        Description::new_3d(size[0], size[1], size[2])
                    };
                    desc.boundary[axis] = [face; 2];
                    let mut mem = memory(&desc);
                    let world = World::init(&desc, &mut mem).unwrap();
                    let others: Vec<usize> = (0..dim as usize).filter(|&k| k != axis).collect();
                    let line = |s: u32| {
                        let mut pos = [0u32; 3];
                        pos[axis] = s;
                        if dim == 2 {
                            pos[others[0]] = 4 * s;
                        } else {
                            pos[others[0]] = 4 * (s % 12);
                            pos[others[1]] = 4 * (s / 12);
                        }
                        pos
                    };
                    let mut v = [0.0f32; 3];
                    v[axis] = dir as f32;
                    for s in 0..n {
                        world.add_particle(line(s), v).unwrap();
                    }
                    world.step(3);
                    let what = format!("{dim}D n {n} axis {axis} {face:?} dir {dir}");
                    let mut left = 0;
                    for s in 0..n {
                        match unit_speed_reference(i64::from(s), dir, i64::from(n), face, 3) {
                            None => left += 1,
                            Some((x, d)) => {
                                let mut pos = line(s);
                                pos[axis] = x as u32;
                                let p = common::particle(world, pos);
                                assert_eq!(p.velocity[axis], d as f32, "{what}: start {s}");
                            }
                        }
                    }
                    let st = world.stats();
                    assert_eq!((st.exited, st.particles), (left, u64::from(n) - left), "{what}");
                }
            }
        }
    }
}
