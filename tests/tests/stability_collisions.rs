//! Numerical stability of collisions (issue #5): extreme mass ratios and
//! restitution at and beyond its ends.

mod common;
mod stability;

use common::{memory, scale, Z};
use mpca::{Boundary, Description, Error, ErrorKind, Quantization, Shape, Stats, World};
use stability::*;

// ------------------------------------------------------------- masses

/// One block's pair before and after one step.
struct Pair {
    masses: [f64; 2],
    before: [[i64; 3]; 2],
    after: [[i64; 3]; 2],
}

impl Pair {
    fn collided(&self) -> bool {
        let mut a = self.before;
        let mut b = self.after;
        a.sort();
        b.sort();
        a != b
    }

    fn momentum_change(&self) -> [f64; 3] {
        [0, 1, 2].map(|k| {
            (0..2).map(|i| self.masses[i] * (self.after[i][k] - self.before[i][k]) as f64).sum::<f64>()
        })
    }
}

/// Two particles in every block of the first step's partition (offset 0),
/// masses `masses[0]` and `masses[1]`, velocities uniform in the ball of
/// radius 0.3, restitution `e`; one step. Particles stay in their block for
/// a step, so the block identifies the pair, and the mass the particle (for
/// equal masses the order is arbitrary, which the symmetric checks allow).
fn pairs(dim: u32, q: Quantization, masses: [f32; 2], e: f32, seed: u64) -> (Vec<Pair>, Stats) {
    let n = if dim == 2 { 64 } else { 32 };
    let mut desc = cube(dim, n);
    desc.quantization = q;
    desc.restitution = e;
    desc.seed = seed;
    desc.mass = masses[0];
    desc.per_particle_mass = masses[0] != masses[1];
    desc.mass_classes = 2;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let mut rng = common::test_rng(seed);
    let cells_per_block = 1u32 << dim;
    let blocks = if dim == 2 { (n / 2) * (n / 2) } else { (n / 2) * (n / 2) * (n / 2) };
    for b in 0..blocks {
        let origin = [2 * (b % (n / 2)), 2 * (b / (n / 2) % (n / 2)), if dim == 3 { 2 * (b / (n / 2 * n / 2)) } else { 0 }];
        let first = rng.below(cells_per_block);
        let second = (first + 1 + rng.below(cells_per_block - 1)) % cells_per_block;
        for (i, c) in [first, second].into_iter().enumerate() {
            let pos = [origin[0] + (c & 1), origin[1] + (c >> 1 & 1), origin[2] + (c >> 2 & 1)];
            world.add_particle_with_mass(pos, rng.velocity(dim, 0.3), masses[i]).unwrap();
        }
    }
    let key = |p: &mpca::Particle| [p.pos[0] / 2, p.pos[1] / 2, p.pos[2] / 2];
    let collect = |w: &World| {
        let mut by_block = std::collections::BTreeMap::<[u32; 3], Vec<(f32, [i64; 3])>>::new();
        for p in w.particles() {
            by_block.entry(key(&p)).or_default().push((p.mass, stored(p.velocity, q)));
        }
        by_block
    };
    let before = collect(world);
    world.step(1);
    let after = collect(world);
    check_sane(world, 2 * u64::from(blocks), "pairs");
    let order = |mut v: Vec<(f32, [i64; 3])>| {
        assert_eq!(v.len(), 2, "a block lost or gained a particle in one step");
        if v[0].0 != v[1].0 && v[0].0 != masses[0] {
            v.swap(0, 1);
        }
        v
    };
    let out = before
        .into_iter()
        .map(|(k, b)| {
            let (b, a) = (order(b), order(after[&k].clone()));
            Pair { masses: [f64::from(b[0].0), f64::from(b[1].0)], before: [b[0].1, b[1].1], after: [a[0].1, a[1].1] }
        })
        .collect();
    (out, world.stats())
}

/// Eqs. 7-8 with mass ratios from 1e-6 to 1e6 and extreme masses (1e-30
/// with 1e30, 1e-45 with itself, f32::MAX with itself, whose sum
/// overflows), e = 1, speeds up to 0.3 so that no result exceeds
/// |V0| + |v_a - v_b| <= 0.9 and no clamp fires (asserted). Expected:
/// `check_sane`; no more pairs changed than collisions were counted (a
/// collision can hand a pair back the velocities it had, a swap say); in
/// every pair, per axis, |m_a dX_a + m_b dX_b| <= (m_a + m_b) (one quantum
/// each, the stochastic rounding) plus the f32 slack of `Book`; summed over
/// the pairs, within 5 standard deviations of the rounding noise of the
/// counted collisions plus their slack.
#[test]
fn extreme_mass_ratios_conserve_momentum() {
    let ratios: [[f32; 2]; 9] = [
        [1e-6, 1.0],
        [1e-3, 1.0],
        [1.0, 1.0],
        [1e3, 1.0],
        [1e6, 1.0],
        [1e-6, 1e6],
        [1e-30, 1e30],
        [1e-45, 1e-45],
        [f32::MAX, f32::MAX],
    ];
    for dim in [2u32, 3] {
        for q in QUANTS {
            for (r, masses) in ratios.iter().enumerate() {
                let what = format!("{dim}D {q:?} masses {masses:?}");
                let (pairs, stats) = pairs(dim, q, *masses, 1.0, 40 + r as u64);
                assert_eq!(stats.clamps, 0, "{what}: a clamp fired");
                let changed = pairs.iter().filter(|p| p.collided()).count() as u64;
                assert!(changed <= stats.collisions, "{what}: {changed} pairs changed, {} collisions", stats.collisions);
                assert!(stats.collisions > 20, "{what}: only {} collisions", stats.collisions);
                let m_max = f64::from(masses[0].max(masses[1]));
                let s = scale(q);
                let slack = 32.0 * U * s * m_max + 2.0 * U * m_max;
                let mut total = [0.0; 3];
                for p in &pairs {
                    let dp = p.momentum_change();
                    for k in 0..3 {
                        let bound = p.masses[0] + p.masses[1] + slack;
                        assert!(dp[k].abs() <= bound, "{what}: pair momentum moved {} quanta on axis {k}, bound {bound}", dp[k]);
                        total[k] += dp[k];
                    }
                }
                let m = [f64::from(masses[0]), f64::from(masses[1])];
                let var = stats.collisions as f64 * (m[0] * m[0] + m[1] * m[1]) / 4.0;
                let collisions = stats.collisions as f64;
                let band = Z * var.sqrt() + slack * collisions;
                for (k, t) in total.iter().enumerate() {
                    assert!(t.abs() <= band, "{what}: summed momentum moved {t} quanta on axis {k}, band {band}");
                }
            }
        }
    }
}

/// Many steps of gases mixing every mass from 1e-6 to 1e6, and of 1e-30 with
/// 1e30, e = 1, speeds up to 1. Expected after every step: `check_sane`.
/// (Light particles kicked by heavy ones of different velocities reach
/// |v| > 1 and clamp in nearly every step, so momentum is checked on
/// isolated pairs, where no clamp can fire, in
/// `extreme_mass_ratios_conserve_momentum`.)
#[test]
fn mixed_extreme_masses_stay_finite() {
    let sets: [&[f32]; 2] = [&[1e-6, 1e-3, 1.0, 1e3, 1e6], &[1e-30, 1e30]];
    for dim in [2u32, 3] {
        for q in QUANTS {
            for masses in sets {
                let what = format!("{dim}D {q:?} masses {masses:?}");
                let mut desc = cube(dim, if dim == 2 { 32 } else { 12 });
                desc.quantization = q;
                desc.per_particle_mass = true;
                desc.mass_classes = masses.len() as u16;
                desc.mass = masses[0];
                desc.seed = 77;
                let mut mem = memory(&desc);
                let world = World::init(&desc, &mut mem).unwrap();
                let mut rng = common::test_rng(77);
                let n = scatter(world, 0.4, 1.0, masses, &mut rng);
                for t in 0..200 {
                    world.step(1);
                    check_sane(world, n, &format!("{what}, step {t}"));
                }
                assert!(world.stats().collisions > 1000, "{what}: too few collisions");
            }
        }
    }
}

// ------------------------------------------------------------- restitution

/// Eqs. 7-8 at e = 0 and e = 1 on isolated pairs (one per block, one step).
/// Expected in every pair that collided: e = 0, both particles leave with
/// V0 (the same f32 value, rounded independently), so each component of
/// X_a - X_b is at most 1 quantum; e = 1, the relative speed is kept:
/// | |X_a' - X_b'| - |X_a - X_b| | < 2 sqrt(dim) quanta (each component off
/// by less than a quantum) plus 1e-3 for f32. A pair whose stored
/// velocities changed collided; no more pairs change than collisions were
/// counted.
#[test]
fn particle_restitution_zero_and_one() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            for e in [0.0f32, 1.0] {
                let what = format!("{dim}D {q:?} e {e}");
                let (pairs, stats) = pairs(dim, q, [1.0, 1.0], e, 60);
                let mut collided = 0;
                for p in &pairs {
                    if !p.collided() {
                        continue;
                    }
                    collided += 1;
                    let rel = |v: [[i64; 3]; 2]| [0, 1, 2].map(|k| (v[0][k] - v[1][k]) as f64);
                    let (r0, r1) = (rel(p.before), rel(p.after));
                    if e == 0.0 {
                        assert!(r1.iter().all(|c| c.abs() <= 1.0), "{what}: e = 0 left {r1:?} apart");
                    } else {
                        let n = |r: [f64; 3]| (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]).sqrt();
                        let d = (n(r1) - n(r0)).abs();
                        assert!(d < 2.0 * f64::from(dim).sqrt() + 1e-3, "{what}: relative speed {} -> {}", n(r0), n(r1));
                    }
                }
                assert!(collided <= stats.collisions, "{what}: {collided} changed, {} collisions", stats.collisions);
                assert!(collided > 20, "{what}: {collided} collisions");
            }
        }
    }
}

/// Eq. 9 at e = 0 and e = 1 off a domain wall (M4) and off a half-space
/// obstacle, both with normal +y (exact, so eq. 9 is exact in quanta).
/// Particles fall at 45 degrees with |v| = 0.6. Expected at the first
/// velocity change, next to the floor: e = 1, v_y flips sign exactly and
/// v_x is kept; e = 0, v_y becomes exactly 0 and v_x is kept; afterwards,
/// with e = 0, the particle slides along the floor: its row and its
/// velocity never change again (nothing pushes it off).
#[test]
fn wall_restitution_zero_and_one() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            for obstacle in [false, true] {
                for e in [0.0f32, 1.0] {
                    let what = format!("{dim}D {q:?} obstacle {obstacle} e {e}");
                    let mut desc = cube(dim, 16);
                    desc.boundary[1] = [Boundary::Wall; 2];
                    desc.quantization = q;
                    desc.wall_restitution = e;
                    desc.obstacles = obstacle;
                    desc.surface_capacity = 2048;
                    desc.seed = 71;
                    let mut mem = memory(&desc);
                    let world = World::init(&desc, &mut mem).unwrap();
                    let floor = if obstacle {
                        world.add_shape(Shape::HalfSpace { point: [0.0, 3.0, 0.0], normal: [0.0, 1.0, 0.0] }, e).unwrap();
                        3
                    } else {
                        0
                    };
                    // One particle per z-plane in 3D (planes 4 apart); in 2D
                    // one only.
                    let planes = if dim == 3 { 4 } else { 1 };
                    for j in 0..planes {
                        world.add_particle([3 * j, 12, 4 * j], [0.42, -0.42, 0.0]).unwrap();
                    }
                    let v0 = stored(world.particles().next().unwrap().velocity, q);
                    let mut bounced = vec![false; planes as usize];
                    for _ in 0..400 {
                        world.step(1);
                        for p in world.particles() {
                            let x = stored(p.velocity, q);
                            let j = (p.pos[2] / 4) as usize;
                            if !bounced[j] && x != v0 {
                                bounced[j] = true;
                                assert_eq!(p.pos[1], floor, "{what}: bounce away from the floor");
                                let want = if e == 1.0 { [v0[0], -v0[1], 0] } else { [v0[0], 0, 0] };
                                assert_eq!(x, want, "{what}: eq. 9");
                            } else if bounced[j] && e == 0.0 {
                                assert_eq!((x, p.pos[1]), ([v0[0], 0, 0], floor), "{what}: sliding");
                            }
                        }
                    }
                    assert!(bounced.iter().all(|&b| b), "{what}: a particle never reached the floor");
                    check_sane(world, u64::from(planes), &what);
                }
            }
        }
    }
}

/// M1: e in [0, 1]. Expected: values outside (below 0 by any amount, above 1
/// by one ulp, the extremes of f32) are RestitutionRange wherever a
/// restitution is given: the description's two, add_obstacle, add_shape and
/// add_obstacle_mask; the world is unchanged; 0 and 1 are accepted (by the
/// world's calls here; by the description in descriptions.rs,
/// ranges_are_checked).
#[test]
fn restitution_outside_zero_one_is_refused() {
    let bad = [-f32::MIN_POSITIVE, -1e-30, -0.5, 1.0 + f32::EPSILON, 2.0, f32::MAX, -f32::MAX];
    for e in bad {
        let mut d = Description::new_2d(8, 8);
        d.restitution = e;
        assert_eq!(d.validate().map_err(Error::kind), Err(ErrorKind::RestitutionRange), "restitution {e}");
        let mut d = Description::new_2d(8, 8);
        d.wall_restitution = e;
        assert_eq!(d.validate().map_err(Error::kind), Err(ErrorKind::RestitutionRange), "wall restitution {e}");
    }
    let mut desc = Description::new_2d(16, 16);
    desc.obstacles = true;
    desc.surface_capacity = 256;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    world.add_particle([1, 1, 0], [0.3, 0.2, 0.0]).unwrap();
    world.add_shape(Shape::Disc { centre: [8.0, 8.0], radius: 2.0 }, 0.5).unwrap();
    world.step(2);
    let before = (world.state_hash(), world.stats(), *world.description());
    let mut mask = vec![0u8; 256];
    mask[3 * 16 + 12] = 1;
    for e in bad {
        assert_eq!(world.add_obstacle([12, 12, 0], [0.0, 1.0, 0.0], e).map_err(Error::kind), Err(ErrorKind::RestitutionRange), "add_obstacle {e}");
        let disc = Shape::Disc { centre: [3.0, 12.0], radius: 1.5 };
        assert_eq!(world.add_shape(disc, e).map_err(Error::kind), Err(ErrorKind::RestitutionRange), "add_shape {e}");
        assert_eq!(world.add_obstacle_mask(&mask, e).map_err(Error::kind), Err(ErrorKind::RestitutionRange), "add_obstacle_mask {e}");
        assert_eq!((world.state_hash(), world.stats(), *world.description()), before, "e = {e} changed the world");
        assert!(!world.obstacle_at([12, 12, 0]) && !world.obstacle_at([12, 3, 0]));
    }
    world.add_obstacle([12, 12, 0], [0.0, 1.0, 0.0], 0.0).unwrap();
    world.add_obstacle([12, 3, 0], [0.0, 1.0, 0.0], 1.0).unwrap();
}
