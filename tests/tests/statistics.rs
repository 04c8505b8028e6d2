//! Statistical checks of the local map and the emitters, each against a
//! probability derived from docs/model.md, with fixed seeds and bands of five
//! standard deviations derived from the variance (binomial, or the sample
//! variance across independent particles).
//!
//! - M5.2: the collision frequency C(k,2)/6 (2D) and C(k,2)/28 (3D).
//! - M5.3: the drift of a free particle, p/(2-p) under the paper's rule and
//!   |v| under the calibrated one.
//! - M6: the emitter's mean rate, its uniform choice of cells, its spread.

mod common;

use common::{assert_binomial, mean_and_se, memory, particle, Z};
use mpca::{Boundary, Description, Drift, Emitter, World};

// ------------------------------------------------------------ M5.2 collisions

/// `C(k, 2)`.
fn pairs(k: u64) -> u64 {
    k * k.saturating_sub(1) / 2
}

/// Fills every block of the offset-0 partition of a periodic `n^dim` world
/// with exactly `k` resting particles in cells drawn at random, steps once and
/// returns (blocks, collisions).
fn collisions_with_k(dim: u32, n: u32, k: usize, seed: u64) -> (u64, u64) {
    let mut desc = if dim == 2 { Description::new_2d(n, n) } else { Description::new_3d(n, n, n) };
    desc.seed = seed;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let cells = 1usize << dim;
    let nz = if dim == 3 { n } else { 1 };
    let mut rng = common::test_rng(seed.wrapping_mul(31).wrapping_add(k as u64));
    let mut blocks = 0u64;
    for bz in (0..nz).step_by(2) {
        for by in (0..n).step_by(2) {
            for bx in (0..n).step_by(2) {
                // A partial Fisher-Yates shuffle picks k distinct local cells.
                let mut local: Vec<usize> = (0..cells).collect();
                for i in 0..k {
                    let j = i + rng.below((cells - i) as u32) as usize;
                    local.swap(i, j);
                    let c = local[i];
                    let pos = [bx + (c & 1) as u32, by + (c >> 1 & 1) as u32, bz + (c >> 2 & 1) as u32];
                    world.add_particle(pos, [0.0; 3]).unwrap();
                }
                blocks += 1;
            }
        }
    }
    world.step(1);
    let s = world.stats();
    // Every block holding a particle is processed (M3), the others skipped.
    let occupied = if k == 0 { 0 } else { blocks };
    assert_eq!((s.blocks_processed, s.blocks_skipped), (occupied, blocks - occupied));
    (blocks, s.collisions)
}

/// M5.2: one of the C(4,2) = 6 cell pairs of a 2D block is drawn uniformly,
/// and a collision happens when both cells hold a particle, so a block with k
/// particles collides with probability C(k,2)/6: 0, 0, 1/6, 1/2, 1. Blocks
/// draw from independent streams (M8), so the count over n blocks is
/// binomial(n, p); expected within 5 sd (exact for p = 0 and p = 1).
#[test]
fn collision_frequency_2d() {
    for k in 0..=4usize {
        let (blocks, collisions) = collisions_with_k(2, 256, k, 100 + k as u64);
        let p = pairs(k as u64) as f64 / 6.0;
        assert_binomial(collisions, blocks, p, &format!("2D collisions with k = {k}"));
    }
}

/// M5.2 in 3D: C(8,2) = 28 pairs, so a block of k particles collides with
/// probability C(k,2)/28. Four 32^3 worlds per k (16384 blocks) keep the
/// band narrow; the total is binomial(16384, p), expected within 5 sd.
#[test]
fn collision_frequency_3d() {
    for k in 0..=8usize {
        let (mut blocks, mut collisions) = (0, 0);
        for seed in 0..4u64 {
            let (b, c) = collisions_with_k(3, 32, k, 200 + 10 * k as u64 + seed);
            blocks += b;
            collisions += c;
        }
        let p = pairs(k as u64) as f64 / 28.0;
        assert_binomial(collisions, blocks, p, &format!("3D collisions with k = {k}"));
    }
}

// ------------------------------------------------------------ M5.3 drift

/// The move probability of M5.3 for a stored speed.
fn move_probability(drift: Drift, speed: f64) -> f64 {
    match drift {
        Drift::Paper => speed,
        Drift::Calibrated => 2.0 * speed / (1.0 + speed),
    }
}

/// The exact expected displacement along one axis of a free particle after
/// `steps` steps, from the two-state chain below.
///
/// Derivation of the mean speed p/(2-p) (M5.3). Along an axis where the
/// particle moves towards +, call it "front" (F) when the next cell in that
/// direction lies in its own block this step, and "back" (B) when it lies
/// in the next block. The partition's offset alternates every step, so a
/// particle that stays swaps sides: F -> B -> F. A particle that moves from F
/// lands in the far cell, which at the next offset is again the front of a
/// new block: F -> F. From B it cannot want the move at all (M5.3). So
///   F -> F with probability p (one cell gained), F -> B with 1 - p, B -> F.
/// Each failure costs the failed step and the step spent at the back, so
/// the steps per cell are 1 + 2 (1 - p)/p = (2 - p)/p, the mean speed is
/// p/(2 - p): the stationary P(F) = 1/(2 - p) times p.
/// Under the calibrated rule p = 2v/(1 + v), and p/(2 - p) = v exactly.
///
/// Starting from a given side, the chain's expected displacement after T
/// steps is p * sum_{t<T} P(F at t), with P(F at t+1) = 1 - (1 - p) P(F at t);
/// it differs from T p/(2-p) by less than one cell (a geometric series of
/// ratio -(1-p) starting below 1), which the test also checks.
fn expected_displacement(p: f64, front_at_start: bool, steps: u64) -> f64 {
    let mut front = if front_at_start { 1.0 } else { 0.0 };
    let mut sum = 0.0;
    for _ in 0..steps {
        sum += p * front;
        front = 1.0 - (1.0 - p) * front;
    }
    sum
}

/// Whether a particle at coordinate `x` moving along `sign` can move at step
/// 0: the offset-0 block of x starts at the even cell, so the front is the
/// even cell for + and the odd cell for -.
fn front_at_start(x: u32, positive: bool) -> bool {
    (x & 1 == 0) == positive
}

/// Checks one group of free particles: `moved[i]` against `expect[i]`
/// cells after `steps` steps, with the rule's speed `formula`.
fn check_drift(what: &str, moved: &[f64], expect: &[f64], formula: f64, steps: u64) {
    let t = steps as f64;
    // The chain's finite-T expectation is within a cell of the formula.
    for e in expect {
        assert!((e / t - formula.abs()).abs() <= 1.0 / t, "{what}: chain {e} vs formula {formula}");
    }
    // Particles are independent (different blocks and streams), so the
    // mean deviation from the expectation has the sample standard error.
    let dev: Vec<f64> = moved.iter().zip(expect).map(|(m, e)| (m - e) / t).collect();
    let (mean, se) = mean_and_se(&dev);
    let speed = moved.iter().sum::<f64>() / moved.len() as f64 / t;
    assert!(
        mean.abs() <= Z * se,
        "{what}: mean speed {speed:.5}, expected {:.5} (formula {formula:.5}), band {:.5}",
        speed - mean,
        Z * se
    );
}

/// M5.3 in 2D: free particles (one per row, rows 4 apart, so no two ever
/// share a block at either offset) moving along +x or -x in a periodic world.
/// Expected: the measured mean speed per particle group is the chain's
/// expectation (limit p/(2-p) under Drift::Paper, |v| under
/// Drift::Calibrated) within 5 standard errors from the sample variance.
#[test]
fn free_particle_drift_2d() {
    const NX: u32 = 64;
    const PER_SPEED: usize = 400;
    const STEPS: u64 = 4000;
    let speeds = [0.2f32, 0.5, 0.8, -0.5];
    for (r, drift) in [Drift::Paper, Drift::Calibrated].into_iter().enumerate() {
        let n = speeds.len() * PER_SPEED;
        let mut desc = Description::new_2d(NX, 4 * n as u32);
        desc.drift = drift;
        desc.seed = 7 + r as u64;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        let mut x = vec![0u32; n];
        let mut stored = vec![0.0f64; n];
        for i in 0..n {
            x[i] = (7 * i as u32) % NX; // both parities
            let pos = [x[i], 4 * i as u32, 0];
            world.add_particle(pos, [speeds[i / PER_SPEED], 0.0, 0.0]).unwrap();
            stored[i] = f64::from(particle(world, pos).velocity[0]);
        }
        let start = x.clone();
        let mut moved = vec![0i64; n];
        // A particle moves at most one cell per step, so reading positions
        // every 16 steps (< NX/2) unwraps the periodic axis unambiguously.
        for _ in 0..STEPS / 16 {
            world.step(16);
            for p in world.particles() {
                let i = p.pos[1] as usize / 4;
                let mut d = (i64::from(p.pos[0]) - i64::from(x[i])).rem_euclid(i64::from(NX));
                if d > i64::from(NX / 2) {
                    d -= i64::from(NX);
                }
                moved[i] += d;
                x[i] = p.pos[0];
            }
            // Free particles never meet, so nothing collides.
            assert_eq!(world.stats().collisions, 0);
        }
        for (g, &v) in speeds.iter().enumerate() {
            let idx = g * PER_SPEED..(g + 1) * PER_SPEED;
            let speed = stored[idx.start].abs();
            let p = move_probability(drift, speed);
            let sign = stored[idx.start].signum();
            // Displacements along the velocity (positive when on time).
            let along: Vec<f64> = idx.clone().map(|i| sign * moved[i] as f64).collect();
            let expect: Vec<f64> =
                idx.clone().map(|i| expected_displacement(p, front_at_start(start[i], sign > 0.0), STEPS)).collect();
            let formula = p / (2.0 - p);
            if drift == Drift::Calibrated {
                assert!((formula - speed).abs() < 1e-12);
            }
            check_drift(&format!("2D {drift:?} v = {v}"), &along, &expect, formula, STEPS);
        }
    }
}

/// M5.3 in 3D along a direction on no axis, v = (0.5, -0.3, 0.4): each axis
/// follows its own chain, independently of the others (a lone particle
/// always gets its desired cell). One particle per 8^3 periodic world, a
/// different seed each, so particles are independent. Expected per axis:
/// the chain's expectation (limit p_k/(2-p_k) or |v_k|) within 5 standard
/// errors.
#[test]
fn free_particle_drift_3d() {
    const N: u32 = 8;
    const WORLDS: u64 = 300;
    const STEPS: u64 = 2000;
    let v = [0.5f32, -0.3, 0.4];
    for drift in [Drift::Paper, Drift::Calibrated] {
        let mut desc = Description::new_3d(N, N, N);
        desc.drift = drift;
        let mut mem = memory(&desc);
        let mut moved = [vec![], vec![], vec![]];
        let mut expect = [vec![], vec![], vec![]];
        let mut stored = [0.0f64; 3];
        for w in 0..WORLDS {
            desc.seed = 1000 + w;
            let world = World::init(&desc, &mut mem).unwrap();
            let start = [(w % N as u64) as u32, (w / 2 % N as u64) as u32, (w / 4 % N as u64) as u32];
            world.add_particle(start, v).unwrap();
            let vs = particle(world, start).velocity;
            let mut at = start;
            let mut d = [0i64; 3];
            for _ in 0..STEPS {
                world.step(1);
                let p = world.particles().next().unwrap();
                for k in 0..3 {
                    // Unwrap: a step moves at most one cell per axis.
                    let mut s = (i64::from(p.pos[k]) - i64::from(at[k])).rem_euclid(i64::from(N));
                    if s > 1 {
                        s -= i64::from(N);
                    }
                    d[k] += s;
                }
                at = p.pos;
            }
            for k in 0..3 {
                stored[k] = f64::from(vs[k]);
                let sign = stored[k].signum();
                let p = move_probability(drift, stored[k].abs());
                moved[k].push(sign * d[k] as f64);
                expect[k].push(expected_displacement(p, front_at_start(start[k], sign > 0.0), STEPS));
            }
        }
        for k in 0..3 {
            let p = move_probability(drift, stored[k].abs());
            check_drift(&format!("3D {drift:?} axis {k}"), &moved[k], &expect[k], p / (2.0 - p), STEPS);
        }
    }
}

// ------------------------------------------------------------ M6 emitters

/// M6: an emitter of rate 2.3 places floor(rate) = 2 particles plus one
/// with probability 0.3 each step (a Bernoulli sum, documented in
/// emitter.rs), into a region with room to spare. Lifetime 1 makes every
/// particle expire in the step that emitted it. Expected: emitted over T
/// steps = 2T + binomial(T, 0.3), within 5 sd; expired = emitted, no
/// shortfall, and no particle left after any step.
#[test]
fn emitter_mean_rate() {
    const STEPS: u64 = 20_000;
    let mut desc = Description::new_2d(32, 32).with_boundary(Boundary::Wall);
    desc.emitter_capacity = 1;
    desc.lifetimes = true;
    desc.seed = 5;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let e = Emitter { min: [0, 0, 0], max: [32, 32, 1], rate: 2.3, mass: 1.0, lifetime: 1, ..Emitter::default() };
    world.add_emitter(e).unwrap();
    for _ in 0..STEPS {
        world.step(1);
        assert_eq!(world.particle_count(), 0);
    }
    let s = world.stats();
    assert_eq!((s.expired, s.emit_shortfall, s.particles), (s.emitted, 0, 0));
    assert_binomial(s.emitted - 2 * STEPS, STEPS, 0.3, "emissions beyond 2 per step");
}

/// M6: cells are chosen uniformly among the empty cells of the region. One
/// resting particle per step into a 4 x 4 region; after each step it is
/// found and removed, so every draw sees the whole region empty. Expected:
/// each cell's count is binomial(T, 1/16), within 5 sd.
#[test]
fn emitter_places_uniformly() {
    const STEPS: u64 = 16_000;
    let mut desc = Description::new_2d(16, 16).with_boundary(Boundary::Wall);
    desc.emitter_capacity = 1;
    desc.seed = 6;
    let mut mem = memory(&desc);
    let world = World::init(&desc, &mut mem).unwrap();
    let e = Emitter { min: [4, 4, 0], max: [8, 8, 1], rate: 1.0, mass: 1.0, ..Emitter::default() };
    world.add_emitter(e).unwrap();
    let mut hits = [0u64; 16];
    for _ in 0..STEPS {
        world.step(1);
        let p = world.particles().next().expect("one particle per step");
        assert_eq!(world.particle_count(), 1);
        let (x, y) = (p.pos[0], p.pos[1]);
        assert!((4..8).contains(&x) && (4..8).contains(&y), "emitted outside the region: {:?}", p.pos);
        hits[((y - 4) * 4 + (x - 4)) as usize] += 1;
        world.remove_particle(p.pos).unwrap();
    }
    for (cell, &h) in hits.iter().enumerate() {
        assert_binomial(h, STEPS, 1.0 / 16.0, &format!("emissions into region cell {cell}"));
    }
}

/// M6: the emitted velocity is the emitter's velocity plus a point uniform
/// in the disc (2D) or ball (3D) of radius `spread`, stored with unbiased
/// rounding (M1). Expected, over independent emissions:
/// - every stored velocity lies within spread + one quantum per axis of the
///   emitter's velocity;
/// - the mean offset is 0 on each axis, within 5 standard errors;
/// - the mean squared offset is spread^2 * D/(D+2) (the second moment of a
///   uniform disc, 1/2, or ball, 3/5) plus the rounding's E[eps^2], which is
///   in [0, D/4] quanta^2, within 5 standard errors.
#[test]
fn emitter_spread() {
    const STEPS: u64 = 8000;
    for dim in [2u32, 3] {
        let mut desc = if dim == 2 { Description::new_2d(16, 16) } else { Description::new_3d(16, 16, 16) }
            .with_boundary(Boundary::Wall);
        desc.emitter_capacity = 1;
        desc.seed = 8 + u64::from(dim);
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        let velocity = [0.3f32, 0.1, if dim == 3 { -0.2 } else { 0.0 }];
        let spread = 0.4f32;
        let e = Emitter { min: [6, 6, 6], max: [10, 10, 10], rate: 1.0, velocity, spread, mass: 1.0, lifetime: 0 };
        world.add_emitter(e).unwrap();
        let d = dim as usize;
        let mut offsets = vec![vec![]; d];
        let mut squares = vec![];
        for _ in 0..STEPS {
            world.step(1);
            // Alone in its block with no force, the particle's velocity is
            // the stored one, unchanged by the step.
            let p = world.particles().next().unwrap();
            let mut r2 = 0.0;
            for k in 0..d {
                let off = f64::from(p.velocity[k]) - f64::from(velocity[k]);
                assert!(off.abs() <= f64::from(spread) + 1.0 / 127.0 + 1e-6, "offset {off} on axis {k}");
                offsets[k].push(off);
                r2 += off * off;
            }
            squares.push(r2);
            world.remove_particle(p.pos).unwrap();
        }
        for (k, o) in offsets.iter().enumerate() {
            let (mean, se) = mean_and_se(o);
            assert!(mean.abs() <= Z * se, "{dim}D axis {k}: mean offset {mean}, band {}", Z * se);
        }
        let (mean, se) = mean_and_se(&squares);
        let moment = f64::from(spread * spread) * f64::from(dim) / f64::from(dim + 2);
        let rounding = f64::from(dim) / 4.0 / (127.0 * 127.0);
        assert!(
            mean >= moment - Z * se && mean <= moment + rounding + Z * se,
            "{dim}D: mean squared offset {mean}, expected {moment} (+ up to {rounding}) +- {}",
            Z * se
        );
    }
}
