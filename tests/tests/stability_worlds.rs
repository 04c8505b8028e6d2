//! Degenerate and long-lived worlds stay sane (issue #5): full, empty and
//! all-obstacle worlds, corridors and pockets, the smallest worlds with every
//! boundary, saturated emitters, and a million steps.

mod common;
mod stability;

use common::{cells, memory, scale};
use mpca::{Boundary, Description, Emitter, Error, ErrorKind, Quantization, Shape, World};
use stability::*;

// ------------------------------------------------------------- degenerate worlds

/// Every cell a particle, periodic, e = 1, speeds up to 0.3. Expected after
/// every step: `check_sane` with the full count, so every cell still holds
/// one particle (a particle per cell at most, M1); momentum within `Book`'s
/// band over the clamp-free steps.
#[test]
fn full_world_stays_full() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            let what = format!("{dim}D {q:?} full");
            let mut desc = cube(dim, if dim == 2 { 16 } else { 8 });
            desc.quantization = q;
            desc.seed = 13;
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            let mut rng = common::test_rng(13);
            for pos in cells(&desc) {
                world.add_particle(pos, rng.velocity(dim, 0.3)).unwrap();
            }
            let n = cells(&desc).count() as u64;
            let mut book = Book::new(world, 1.0);
            for t in 0..200 {
                world.step(1);
                check_sane(world, n, &format!("{what}, step {t}"));
                book.step(world);
            }
            assert!(book.collisions > 1000, "{what}");
            book.check(&what);
        }
    }
}

/// No particle at all, with obstacles, forces and an emitter of rate 0.
/// Expected: every step processes no block and skips them all, the state
/// hash and the counts stay those of the empty world.
#[test]
fn empty_world_steps_without_work() {
    for dim in [2u32, 3] {
        let mut desc = busy_desc(dim);
        desc.seed = 1;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        world.add_shape(Shape::Box { min: [2.0; 3], max: [4.0; 3] }, 1.0).unwrap();
        world.add_emitter(Emitter { min: [0; 3], max: [2, 2, 2], rate: 0.0, mass: 1.0, ..Emitter::default() }).unwrap();
        let hash = world.state_hash();
        for _ in 0..20 {
            world.step(1);
            let s = world.stats();
            assert_eq!((s.particles, s.blocks_processed, s.emitted, s.collisions), (0, 0, 0, 0));
            assert!(s.blocks_skipped > 0);
            assert_eq!(world.state_hash(), hash);
        }
    }
}

/// Every cell an obstacle (a mask of ones), under each boundary kind, in 2D
/// and 3D. Expected: the mask is accepted (no surface cell lacks a normal:
/// cells next to an open face face out of it, the others have no free
/// neighbour); particles are refused with CellObstacle; an emitter over
/// the whole world places nothing and falls short by its whole (integer)
/// rate every step; steps complete with no particle and no block processed.
#[test]
fn world_of_obstacles() {
    for dim in [2u32, 3] {
        for faces in [Boundary::Periodic, Boundary::Wall, Boundary::Open] {
            let what = format!("{dim}D {faces:?}");
            let mut desc = cube(dim, if dim == 2 { 8 } else { 4 }).with_boundary(faces);
            desc.obstacles = true;
            desc.surface_capacity = 512;
            desc.emitter_capacity = 1;
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            let n = cells(&desc).count();
            world.add_obstacle_mask(&vec![1u8; n], 1.0).unwrap_or_else(|e| panic!("{what}: {e:?}"));
            assert!(cells(&desc).all(|p| world.obstacle_at(p)), "{what}");
            assert_eq!(world.add_particle([1, 1, 0], [0.0; 3]).map_err(Error::kind), Err(ErrorKind::CellObstacle), "{what}");
            let max = [desc.size[0], desc.size[1], if dim == 3 { desc.size[2] } else { 1 }];
            world.add_emitter(Emitter { min: [0; 3], max, rate: 3.0, mass: 1.0, ..Emitter::default() }).unwrap();
            for t in 1..=10u64 {
                world.step(1);
                let s = world.stats();
                assert_eq!((s.particles, s.emitted, s.emit_shortfall, s.blocks_processed), (0, 0, 3 * t, 0), "{what}");
            }
        }
    }
}

/// Obstacles everywhere but a corridor one cell wide: along x in 2D (row
/// y = 4), and a tube along x in 3D (y = z = 4), periodic, e = 1 and 0.5,
/// particles on half the corridor's cells with velocities in every
/// direction. Expected after every step: `check_sane`, every particle still
/// in the corridor (the walls reflect every move across it, M5.4).
#[test]
fn one_cell_corridors() {
    for dim in [2u32, 3] {
        for e in [1.0f32, 0.5] {
            for q in QUANTS {
                let what = format!("{dim}D {q:?} e {e}");
                let mut desc = if dim == 2 { Description::new_2d(32, 8) } else { Description::new_3d(32, 8, 8) };
                desc.quantization = q;
                desc.obstacles = true;
                desc.surface_capacity = 32 * 8 * 8;
                desc.restitution = e;
                desc.seed = 14;
                let mut mem = memory(&desc);
                let world = World::init(&desc, &mut mem).unwrap();
                let in_corridor = |p: [u32; 3]| p[1] == 4 && (dim == 2 || p[2] == 4);
                let mask: Vec<u8> = cells(&desc).map(|p| u8::from(!in_corridor(p))).collect();
                world.add_obstacle_mask(&mask, e).unwrap();
                let mut rng = common::test_rng(14);
                let mut n = 0;
                for x in (0..32).step_by(2) {
                    world.add_particle([x, 4, if dim == 3 { 4 } else { 0 }], rng.velocity(dim, 1.0)).unwrap();
                    n += 1;
                }
                for t in 0..300 {
                    world.step(1);
                    check_sane(world, n, &format!("{what}, step {t}"));
                    for p in world.particles() {
                        assert!(in_corridor(p.pos), "{what}, step {t}: left the corridor at {:?}", p.pos);
                    }
                }
                assert!(world.stats().collisions > 0, "{what}: the corridor saw no collision");
            }
        }
    }
}

/// Particles sealed in pockets of an obstacle mask that covers everything
/// else: a single cell holding one particle, and a block-straddling
/// 2 x 2 (x 2) pocket holding 3 (2D) or 5 (3D) fast particles, e = 1.
/// Expected after every step: `check_sane`; every particle in its pocket;
/// the single-cell particle never leaves its cell (it can move nowhere).
#[test]
fn sealed_particles_stay_in_their_pocket() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            let what = format!("{dim}D {q:?}");
            let mut desc = cube(dim, 12);
            desc.quantization = q;
            desc.obstacles = true;
            desc.surface_capacity = 512;
            desc.seed = 15;
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            let z = |c: u32| if dim == 3 { c } else { 0 };
            let single = [2, 2, z(2)];
            let in_pocket = |p: [u32; 3]| (5..7).contains(&p[0]) && (5..7).contains(&p[1]) && (dim == 2 || (5..7).contains(&p[2]));
            let mask: Vec<u8> = cells(&desc).map(|p| u8::from(p != single && !in_pocket(p))).collect();
            world.add_obstacle_mask(&mask, 1.0).unwrap();
            let mut rng = common::test_rng(15);
            world.add_particle(single, rng.velocity(dim, 1.0)).unwrap();
            let pocket: Vec<[u32; 3]> = cells(&desc).filter(|&p| in_pocket(p)).collect();
            let k = if dim == 2 { 3 } else { 5 };
            for &p in &pocket[..k] {
                world.add_particle(p, rng.velocity(dim, 1.0)).unwrap();
            }
            let n = 1 + k as u64;
            for t in 0..500 {
                world.step(1);
                check_sane(world, n, &format!("{what}, step {t}"));
                let mut found_single = false;
                for p in world.particles() {
                    found_single |= p.pos == single;
                    assert!(p.pos == single || in_pocket(p.pos), "{what}, step {t}: escaped to {:?}", p.pos);
                }
                assert!(found_single, "{what}, step {t}: the single-cell particle moved");
            }
        }
    }
}

/// A packed gas among obstacles: 2 x 2 (x 2) boxes scattered over a
/// periodic world (aligned to odd cells, so every Margolus block at either
/// offset can hold obstacle and free cells together), the free cells filled
/// at 90 %, speeds up to 1, e = 1. Blocks with more particles than their
/// free cells can place as desired displace some, and an obstacle cell is
/// sometimes the nearest alternative (M5.6 cost), which M1 forbids.
/// Expected after every step: `check_sane`, no particle on an obstacle
/// cell.
#[test]
fn packed_gas_never_enters_obstacles() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            let what = format!("{dim}D {q:?}");
            let mut desc = cube(dim, if dim == 2 { 32 } else { 12 });
            desc.quantization = q;
            desc.obstacles = true;
            desc.surface_capacity = 4096;
            desc.seed = 18;
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            let mut rng = common::test_rng(18);
            let n = desc.size[0];
            let boxes = if dim == 2 { 40 } else { 30 };
            for _ in 0..boxes {
                let c = [0, 1, 2].map(|_| (2 * rng.below(n / 2 - 1) + 1) as f32);
                let _ = world.add_shape(Shape::Box { min: c, max: c.map(|v| v + 2.0) }, 1.0);
            }
            assert!(cells(&desc).filter(|&p| world.obstacle_at(p)).count() >= 40, "{what}: too few obstacles");
            let count = scatter(world, 0.9, 1.0, &[1.0], &mut rng);
            for t in 0..200 {
                world.step(1);
                check_sane(world, count, &format!("{what}, step {t}"));
                for p in world.particles() {
                    assert!(!world.obstacle_at(p.pos), "{what}, step {t}: a particle on obstacle cell {:?}", p.pos);
                }
            }
            assert!(world.stats().displaced > 1000, "{what}: too few displaced particles to test");
        }
    }
}

// ------------------------------------------------------------- sizes

/// The smallest worlds, 2 x 2 and 2 x 2 x 2, with every boundary kind per
/// axis (periodic, wall, open, and wall on one face with open on the
/// other, both ways): full at the start, speeds up to 1, gravity along
/// (1, -1, 1) x 0.05, e = 1. Expected after every step: `check_sane` with
/// the count `initial - exited` (M6), nothing exits without an open face,
/// and a world with no open face keeps everything.
#[test]
fn smallest_worlds_with_every_boundary() {
    use Boundary::{Open, Periodic, Wall};
    let kinds = [[Periodic; 2], [Wall; 2], [Open; 2], [Wall, Open], [Open, Wall]];
    for dim in [2u32, 3] {
        let combos = if dim == 2 { 25 } else { 125 };
        for c in 0..combos {
            let mut desc = cube(dim, 2);
            let mut any_open = false;
            for k in 0..dim as usize {
                let kind = kinds[c / 5usize.pow(k as u32) % 5];
                desc.boundary[k] = kind;
                any_open |= kind.contains(&Open);
            }
            desc.forces.uniform = true;
            desc.gravity = [0.05, -0.05, 0.05];
            desc.seed = c as u64;
            let what = format!("{dim}D {:?}", &desc.boundary[..dim as usize]);
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            let mut rng = common::test_rng(c as u64);
            for pos in cells(&desc) {
                world.add_particle(pos, rng.velocity(dim, 1.0)).unwrap();
            }
            let initial = 1u64 << dim;
            for t in 0..60 {
                world.step(1);
                let s = world.stats();
                check_sane(world, initial - s.exited, &format!("{what}, step {t}"));
                if !any_open {
                    assert_eq!(s.exited, 0, "{what}");
                }
            }
        }
    }
}

// ------------------------------------------------------------- emitters

/// M6: an emitter into a region that is already full places nothing and
/// counts the shortfall: a 4 x 4 region of resting particles (no force, so
/// they never move), integer rates 5 and 16 (exactly that many wanted each
/// step). Expected: per step the shortfall grows by the rate, nothing is
/// emitted, the count stays 16.
#[test]
fn emitter_into_a_full_region_counts_shortfall() {
    for dim in [2u32, 3] {
        let mut desc = cube(dim, 8).with_boundary(Boundary::Wall);
        desc.emitter_capacity = 2;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        for x in 2..6 {
            for y in 2..6 {
                world.add_particle([x, y, 0], [0.0; 3]).unwrap();
            }
        }
        let region = Emitter { min: [2, 2, 0], max: [6, 6, 1], mass: 1.0, ..Emitter::default() };
        world.add_emitter(Emitter { rate: 5.0, ..region }).unwrap();
        world.add_emitter(Emitter { rate: 16.0, ..region }).unwrap();
        for t in 1..=50u64 {
            world.step(1);
            let s = world.stats();
            assert_eq!((s.emitted, s.emit_shortfall), (0, 21 * t), "{dim}D step {t}");
            check_sane(world, 16, &format!("{dim}D full region, step {t}"));
        }
    }
}

/// M6 with absurd rates: 1e19 (beyond u64 after two steps), 2^64, 1e30 and
/// f32::MAX into an empty 4 x 4 region, and f32::MAX set later on an
/// emitter whose region is full. Expected: no panic (overflow checks are on
/// in the test profile), the region fills (16 emitted, 16 particles), the
/// shortfall is huge (at least 1e18) after the first step and never
/// decreases (it may saturate at u64::MAX), the count stays exact.
#[test]
fn absurd_emitter_rates_saturate() {
    for rate in [1e19f32, 18_446_744_073_709_551_616.0, 1e30, f32::MAX] {
        let mut desc = Description::new_2d(8, 8).with_boundary(Boundary::Wall);
        desc.emitter_capacity = 2;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        let region = Emitter { min: [2, 2, 0], max: [6, 6, 1], mass: 1.0, ..Emitter::default() };
        world.add_emitter(Emitter { rate, ..region }).unwrap();
        let mut last = 0u64;
        for t in 1..=5u64 {
            world.step(1);
            let s = world.stats();
            assert_eq!(s.emitted, 16, "rate {rate}, step {t}");
            assert!(s.emit_shortfall >= 1_000_000_000_000_000_000 && s.emit_shortfall >= last, "rate {rate}: {}", s.emit_shortfall);
            last = s.emit_shortfall;
            check_sane(world, 16, &format!("rate {rate}, step {t}"));
        }
        let second = world.add_emitter(Emitter { rate: 1.0, ..region }).unwrap();
        world.set_emitter_rate(second, f32::MAX).unwrap();
        world.step(3);
        assert!(world.stats().emit_shortfall >= last);
        check_sane(world, 16, &format!("rate {rate}, then f32::MAX"));
    }
}

// ------------------------------------------------------------- long run

/// A million steps of a small closed box: 8 x 8 periodic 2D, 20 particles,
/// speeds up to 1, e = 0.9, no force; 8 bits (`q`). Expected at every step:
/// the count is exactly 20 (counter and occupancy); the statistics are
/// finite; the energy sum m |X|^2 (quanta) does not grow by more than
/// rounding allows: eqs. 7-8 with e < 1 and the clamp never add energy in
/// real arithmetic, a stored component X rounded from x changes X^2 by
/// (X - x)(X + x) < 2|X| + 1, a step rounds 2 dim components per collision,
/// so the growth is at most the sum of the 2 dim c largest 2|X| + 1 over the
/// components after the step, plus the f32 slack of the collisions (16
/// 2^-24 of twice the largest particle energy each) and of the clamps (32
/// 2^-24 SCALE^2 each). At the end: the momentum moved over clamp-free steps
/// within `Book`'s band.
fn long_run(q: Quantization, steps: u64) {
    let mut desc = Description::new_2d(8, 8);
    desc.quantization = q;
    desc.restitution = 0.9;
    desc.seed = 1_000_000;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let mut rng = common::test_rng(16);
    let mut n = 0;
    while n < 20 {
        if world.add_particle([rng.below(8), rng.below(8), 0], rng.velocity(2, 1.0)).is_ok() {
            n += 1;
        }
    }
    let s2 = scale(q) * scale(q);
    let energy = |w: &World, comps: &mut Vec<i64>| {
        comps.clear();
        let (mut e, mut max) = (0i64, 0i64);
        for p in w.particles() {
            let x = stored(p.velocity, q);
            let pe = x[0] * x[0] + x[1] * x[1];
            e += pe;
            max = max.max(pe);
            comps.extend([2 * x[0].abs() + 1, 2 * x[1].abs() + 1]);
        }
        (e, max, comps.len())
    };
    let mut comps = vec![];
    let (mut e_prev, mut max_prev, _) = energy(world, &mut comps);
    let mut book = Book::new(world, 1.0);
    let mut prev = world.stats();
    for t in 0..steps {
        world.step(1);
        assert_eq!(world.particle_count(), 20, "step {t}");
        let st = world.stats();
        assert!(st.kinetic_energy.is_finite() && st.momentum.iter().all(|c| c.is_finite()), "step {t}");
        let (e, max, count) = energy(world, &mut comps);
        assert_eq!(count, 40, "step {t}: occupancy count");
        let c = st.collisions - prev.collisions;
        let k = st.clamps - prev.clamps;
        let roundings = (4 * c as usize).min(comps.len());
        comps.sort_unstable_by(|a, b| b.cmp(a));
        let allowance = comps[..roundings].iter().sum::<i64>() as f64
            + c as f64 * 16.0 * U * 2.0 * (max.max(max_prev) as f64)
            + k as f64 * 32.0 * U * s2;
        assert!(
            (e - e_prev) as f64 <= allowance,
            "step {t}: energy grew by {} quanta^2, rounding allows {allowance}",
            e - e_prev
        );
        book.step(world);
        (e_prev, max_prev, prev) = (e, max, st);
    }
    assert!(world.stats().collisions > steps, "too few collisions");
    book.check(&format!("{q:?} long run"));
}

/// `long_run` with 8-bit velocities, 10^6 steps.
#[test]
fn a_million_steps_of_a_small_box_8_bit() {
    long_run(Quantization::Bits8, 1_000_000);
}

/// `long_run` with 16-bit velocities, 10^6 steps.
#[test]
fn a_million_steps_of_a_small_box_16_bit() {
    long_run(Quantization::Bits16, 1_000_000);
}
