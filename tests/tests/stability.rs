//! Numerical stability on stiff and extreme inputs (issue #5).
//!
//! Every case states what it expects. Two checks recur:
//! - `check_sane`: the particle count is exact; every stored velocity
//!   component lies in [-1, 1] and the stored speed is at most
//!   `1 + sqrt(dim)/SCALE` (the documented rounding excess, README "Speed
//!   limit"), checked exactly in quanta; masses are finite and positive;
//!   the statistics' momentum, kinetic energy and clamped energy are finite.
//! - `Book`: the momentum change over steps in which no clamp fired (a clamp
//!   scales a velocity and so changes momentum; M5.5), against the band that
//!   rounding allows (derived in tests/tests/conservation.rs): per collision
//!   and axis two roundings, each adding `m eps` with `Var[eps] <= 1/4`, and
//!   the f32 arithmetic of eqs. 7-8 and the 24-bit draw as a deterministic
//!   slack; the band is 5 standard deviations plus the slack.

mod common;

use common::{cells, mean_and_se, memory, quanta, scale, TestRng, Z};
use mpca::{Boundary, Cell, Description, Drift, Emitter, Error, Quantization, Shape, Stats, Vortex, World};

/// 2^-24, the unit roundoff of f32.
const U: f64 = 1.0 / 16_777_216.0;

const QUANTS: [Quantization; 2] = [Quantization::Bits8, Quantization::Bits16];

fn cube(dim: u32, n: u32) -> Description {
    if dim == 2 { Description::new_2d(n, n) } else { Description::new_3d(n, n, n) }
}

fn stored(v: [f32; 3], q: Quantization) -> [i64; 3] {
    v.map(|c| quanta(c, q))
}

/// The checks every world must pass after every step (module doc).
fn check_sane(world: &World, expected: u64, what: &str) {
    let d = world.description();
    let (dim, q) = (d.dim as usize, d.quantization);
    let s = scale(q);
    let limit = s + (dim as f64).sqrt();
    let mut n = 0u64;
    for p in world.particles() {
        n += 1;
        for (k, c) in p.velocity.iter().enumerate() {
            assert!(c.is_finite() && (-1.0..=1.0).contains(c), "{what}: component {k} = {c} at {:?}", p.pos);
        }
        if dim == 2 {
            assert_eq!(p.velocity[2], 0.0, "{what}: 2D velocity with a z component");
        }
        let x = stored(p.velocity, q);
        let speed = ((x[0] * x[0] + x[1] * x[1] + x[2] * x[2]) as f64).sqrt();
        assert!(speed <= limit, "{what}: stored speed {speed} quanta > {limit} at {:?}", p.pos);
        assert!(p.mass.is_finite() && p.mass > 0.0, "{what}: mass {}", p.mass);
    }
    assert_eq!(n, expected, "{what}: particles found");
    assert_eq!(world.particle_count(), expected, "{what}: particle count");
    let st = world.stats();
    assert_eq!(st.particles, expected, "{what}: stats particles");
    assert!(st.momentum.iter().all(|c| c.is_finite()), "{what}: momentum {:?}", st.momentum);
    assert!(st.kinetic_energy.is_finite(), "{what}: energy {}", st.kinetic_energy);
    assert!(st.clamp_energy.is_finite() && st.clamp_energy >= 0.0, "{what}: clamped energy {}", st.clamp_energy);
}

/// Places particles on about `density` of the free cells with velocities
/// uniform in the ball of radius `speed`, masses drawn from `masses` (the
/// world must accept them); returns how many.
fn scatter(world: &mut World, density: f32, speed: f32, masses: &[f32], rng: &mut TestRng) -> u64 {
    let desc = *world.description();
    let mut n = 0;
    for pos in cells(&desc) {
        if rng.unit() < density {
            let m = masses[rng.below(masses.len() as u32) as usize];
            if world.add_particle_with_mass(pos, rng.velocity(desc.dim, speed), m).is_ok() {
                n += 1;
            }
        }
    }
    n
}

// ------------------------------------------------------------- momentum book

/// Exact sums of one moment, in quanta.
struct Snap {
    momentum: [f64; 3],
}

fn snap(world: &World) -> Snap {
    let q = world.description().quantization;
    let mut momentum = [0.0; 3];
    for p in world.particles() {
        let x = stored(p.velocity, q);
        for k in 0..3 {
            momentum[k] += f64::from(p.mass) * x[k] as f64;
        }
    }
    Snap { momentum }
}

/// The momentum change over clamp-free steps and its band (module doc).
struct Book {
    m_max: f64,
    s: f64,
    prev: Snap,
    prev_stats: Stats,
    drift: [f64; 3],
    var: f64,
    slack: f64,
    collisions: u64,
}

impl Book {
    fn new(world: &World, m_max: f64) -> Book {
        let s = scale(world.description().quantization);
        Book { m_max, s, prev: snap(world), prev_stats: world.stats(), drift: [0.0; 3], var: 0.0, slack: 0.0, collisions: 0 }
    }

    /// Call after every step.
    fn step(&mut self, world: &World) {
        let now = snap(world);
        let st = world.stats();
        let c = st.collisions - self.prev_stats.collisions;
        if st.clamps == self.prev_stats.clamps {
            for k in 0..3 {
                self.drift[k] += now.momentum[k] - self.prev.momentum[k];
            }
            let c = c as f64;
            self.var += c * 2.0 * self.m_max * self.m_max / 4.0;
            // Unequal masses: ~16 f32 roundings of values up to 2 SCALE in
            // quanta, over (ma + mb) <= 2 m_max; the 24-bit draw biases
            // each of the two roundings by at most 2^-24.
            self.slack += c * (32.0 * U * self.s * self.m_max + 2.0 * U * self.m_max);
            self.collisions += st.collisions - self.prev_stats.collisions;
        }
        self.prev = now;
        self.prev_stats = st;
    }

    fn check(&self, what: &str) {
        let band = Z * self.var.sqrt() + self.slack;
        for k in 0..3 {
            assert!(
                self.drift[k].abs() <= band,
                "{what}: momentum moved {} quanta along axis {k} in clamp-free steps, band {band}",
                self.drift[k]
            );
        }
    }
}

// ------------------------------------------------------------- huge forces

/// Runs `steps` steps of a world of `desc` filled by `fill`, checking it
/// after every step; returns the world's clamps.
fn run_checked(desc: &Description, steps: u64, what: &str, fill: &dyn Fn(&mut World) -> u64) -> u64 {
    let mut mem = memory(desc);
    let world = World::init(desc, &mut mem).unwrap();
    let n = fill(world);
    check_sane(world, n, what);
    for t in 0..steps {
        world.step(1);
        check_sane(world, n, &format!("{what}, step {t}"));
    }
    world.stats().clamps
}

/// Every variant of a stiff world: 2D and 3D, 8 and 16 bits, periodic and
/// walled.
fn variants(make: impl Fn(u32) -> Description) -> Vec<(String, Description)> {
    let mut v = vec![];
    for dim in [2u32, 3] {
        for q in QUANTS {
            for faces in [Boundary::Periodic, Boundary::Wall] {
                let mut d = make(dim);
                d.boundary = [[faces; 2]; 3];
                d.quantization = q;
                d.seed = 500 + u64::from(dim);
                v.push((format!("{dim}D {q:?} {faces:?}"), d));
            }
        }
    }
    v
}

fn fill_half(world: &mut World, masses: &[f32]) -> u64 {
    let mut rng = common::test_rng(world.description().seed);
    scatter(world, 0.5, 1.0, masses, &mut rng)
}

/// M5.1 with forces far beyond one cell per step, M5.5 clamps them.
/// Uniform gravity of 1e30 (and 3e38, whose dt * g * SCALE overflows f32),
/// a force field with dt |F| / m = 1e6, the same field on masses of 1e-30
/// (the acceleration overflows), a potential with a jump of 1e30 between
/// neighbouring cells (a near-vertical wall) and one jumping from f32::MAX to
/// -f32::MAX (its central difference overflows), and a vortex with a core of
/// 1e-30 cells and circulation 1e30 centred on an occupied cell.
/// Expected after every step: `check_sane` (so no NaN, no infinity,
/// |v| <= 1 + sqrt(dim)/SCALE, exact count), and clamps fired.
#[test]
fn huge_forces_keep_speeds_bounded() {
    type Describe = Box<dyn Fn(&mut Description)>;
    type Prepare = Box<dyn Fn(&mut World)>;
    let cases: Vec<(&str, Describe, Prepare)> = vec![
        (
            "gravity 1e30",
            Box::new(|d| {
                d.forces.uniform = true;
                d.gravity = [1e30, -1e30, 1e30];
            }),
            Box::new(|_| {}),
        ),
        (
            "gravity 3e38",
            Box::new(|d| {
                d.forces.uniform = true;
                d.gravity = [3e38, -3e38, 0.0];
            }),
            Box::new(|_| {}),
        ),
        (
            "field 1e6 per step",
            Box::new(|d| d.forces.field = true),
            Box::new(|w| {
                let dim = w.description().dim as usize;
                let n = w.description().size[..dim].iter().product::<u32>() as usize;
                let mut rng = common::test_rng(9);
                let f: Vec<f32> = (0..n * dim).map(|_| 2e6 * (rng.unit() - 0.5)).collect();
                w.set_force_field(&f).unwrap();
            }),
        ),
        (
            "field 1e30 on masses 1e-30",
            Box::new(|d| {
                d.forces.field = true;
                d.per_particle_mass = true;
                d.mass_classes = 2;
            }),
            Box::new(|w| {
                let dim = w.description().dim as usize;
                let n = w.description().size[..dim].iter().product::<u32>() as usize;
                let f: Vec<f32> = (0..n * dim).map(|i| if i % 3 == 0 { -1e30 } else { 1e30 }).collect();
                w.set_force_field(&f).unwrap();
            }),
        ),
        (
            "potential cliff 1e30",
            Box::new(|d| d.forces.potential = true),
            Box::new(|w| {
                let desc = *w.description();
                let u: Vec<f32> = cells(&desc).map(|p| if p[0] < desc.size[0] / 2 { 0.0 } else { 1e30 }).collect();
                w.set_potential(&u).unwrap();
            }),
        ),
        (
            "potential MAX to -MAX",
            Box::new(|d| d.forces.potential = true),
            Box::new(|w| {
                let desc = *w.description();
                let u: Vec<f32> =
                    cells(&desc).map(|p| if (p[0] + p[1]) < desc.size[0] / 2 { f32::MAX } else { -f32::MAX }).collect();
                w.set_potential(&u).unwrap();
            }),
        ),
        (
            "vortex core 1e-30",
            Box::new(|d| {
                d.forces.vortex = true;
                d.vortex = Vortex { centre: [4.5, 4.5], core_radius: 1e-30, circulation: 1e30 };
            }),
            Box::new(|_| {}),
        ),
    ];
    for (name, describe, prepare) in &cases {
        for (variant, desc) in variants(|dim| {
            let mut d = cube(dim, if dim == 2 { 16 } else { 8 });
            describe(&mut d);
            d
        }) {
            let what = format!("{name}, {variant}");
            let masses: &[f32] = if desc.per_particle_mass { &[1e-30, 1.0] } else { &[1.0] };
            let clamps = run_checked(&desc, 20, &what, &|w| {
                prepare(w);
                let n = fill_half(w, masses);
                // The vortex case puts a particle on the centre cell.
                let _ = w.add_particle_with_mass([4, 4, if desc.dim == 3 { 4 } else { 0 }], [0.0; 3], masses[0]);
                n + u64::from(w.particle_count() > n)
            });
            assert!(clamps > 0, "{what}: no clamp fired");
        }
    }
}

/// M5.5 keeps the direction of a clamped velocity: with a uniform
/// acceleration of 1e30 cells per step^2 along -y, or a force field with
/// dt |F| / m = 1e6 along a fixed unit direction `u` in every cell, every
/// particle of a periodic world leaves each step with velocity `u` (the
/// velocity it had adds less than 1e-6 of a quantum after the clamp, equal
/// velocities collide into themselves). Expected: every stored component
/// within one quantum (its stochastic rounding) of `u * SCALE`.
#[test]
fn clamped_velocities_point_along_the_force() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            let u: [f32; 3] = if dim == 2 { [0.6, 0.8, 0.0] } else { [0.48, 0.6, -0.64] };
            for use_field in [false, true] {
                let mut desc = cube(dim, if dim == 2 { 16 } else { 8 });
                desc.quantization = q;
                desc.seed = 31;
                let dir = if use_field {
                    desc.forces.field = true;
                    u
                } else {
                    desc.forces.uniform = true;
                    desc.gravity = [0.0, -1e30, 0.0];
                    [0.0, -1.0, 0.0]
                };
                let mut mem = memory(&desc);
                let world = World::init(&desc, &mut mem).unwrap();
                if use_field {
                    let n = cells(&desc).count();
                    let f: Vec<f32> = (0..n).flat_map(|_| u[..dim as usize].iter().map(|c| c * 1e6)).collect();
                    world.set_force_field(&f).unwrap();
                }
                let n = fill_half(world, &[1.0]);
                let s = scale(q);
                for t in 0..10 {
                    world.step(1);
                    check_sane(world, n, "direction");
                    for p in world.particles() {
                        let x = stored(p.velocity, q);
                        for k in 0..3 {
                            let want = f64::from(dir[k]) * s;
                            assert!(
                                (x[k] as f64 - want).abs() < 1.0 + 1e-5 * s + 1e-3,
                                "{dim}D {q:?} field {use_field} step {t}: {x:?} vs {dir:?} * SCALE"
                            );
                        }
                    }
                }
            }
        }
    }
}

/// M5.5 on a velocity some of whose components the force left undefined.
/// collision.rs documents the rule: a component left undefined (inf - inf)
/// counts as zero, infinite components become unit ones and finite ones
/// vanish beside them; and the clamp only ever scales a velocity back to
/// |v| = 1 (M5.5). Here, in 3D, at cell (4, 4, z) a potential cliff gives
/// F_x = +inf and a vortex centred at (4.5, 4.25) with circulation 3e38
/// gives F_x = -inf (so F_x = inf - inf) and F_y = 0 * inf; nothing is
/// infinite along z, where gravity adds 0.001 per step. A particle there at
/// rest, alone in its block. Expected after one step: x and y count as
/// zero, so the stored velocity is (0, 0, 0.001) within one quantum per
/// axis (its rounding), and in particular |v| stays far below 1.
#[test]
fn undefined_force_components_count_as_zero() {
    for q in QUANTS {
        let mut desc = cube(3, 8);
        desc.quantization = q;
        desc.forces.uniform = true;
        desc.forces.potential = true;
        desc.forces.vortex = true;
        desc.gravity = [0.0, 0.0, 0.001];
        desc.vortex = Vortex { centre: [4.5, 4.25], core_radius: 1e-3, circulation: 3e38 };
        desc.seed = 20;
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        let u: Vec<f32> = cells(&desc).map(|p| if p[0] < 5 { f32::MAX } else { -f32::MAX }).collect();
        world.set_potential(&u).unwrap();
        world.add_particle([4, 4, 4], [0.0; 3]).unwrap();
        world.step(1);
        check_sane(world, 1, &format!("{q:?}"));
        let p = world.particles().next().unwrap();
        let x = stored(p.velocity, q);
        let s = scale(q);
        let want = [0.0, 0.0, 0.001 * s];
        for k in 0..3 {
            assert!((x[k] as f64 - want[k]).abs() < 1.0 + 1e-3, "{q:?}: stored {x:?} quanta, expected {want:?} within a quantum");
        }
    }
}

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
                desc.mass_classes = masses.len() as u32;
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

// ------------------------------------------------------------- time steps

/// A world with all four force terms at ordinary strengths (gravity 0.01, a
/// field up to 0.02, a potential with gradient up to 0.01, a vortex of
/// circulation 2) and `dt`.
fn forced(dim: u32, q: Quantization, dt: f32, scale_forces: f32) -> Description {
    let mut d = cube(dim, if dim == 2 { 16 } else { 8 }).with_boundary(Boundary::Wall);
    d.quantization = q;
    d.dt = dt;
    d.forces.uniform = true;
    d.forces.field = true;
    d.forces.potential = true;
    d.forces.vortex = true;
    d.gravity = [0.0, -0.01 * scale_forces, 0.0];
    d.vortex = Vortex { centre: [4.0, 4.0], core_radius: 2.0, circulation: 2.0 * scale_forces };
    d.seed = 3;
    d
}

fn set_fields(w: &mut World, scale_forces: f32) {
    let desc = *w.description();
    let dim = desc.dim as usize;
    let n = cells(&desc).count();
    let mut rng = common::test_rng(4);
    let f: Vec<f32> = (0..n * dim).map(|_| 0.04 * scale_forces * (rng.unit() - 0.5)).collect();
    w.set_force_field(&f).unwrap();
    let u: Vec<f32> = cells(&desc).map(|p| 0.01 * scale_forces * (p[0] as f32 + 0.5 * p[1] as f32)).collect();
    w.set_potential(&u).unwrap();
}

/// M5.1 with dt = 0, 1e-30 and 1e30 and every force term on. Expected:
/// `check_sane` after every step for each; with dt = 0 the forces vanish
/// (dt a = 0 for finite a), so the world matches, bit for bit, one with
/// every force term on but zero (same seed, particles and step path).
#[test]
fn extreme_time_steps_stay_finite() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            for dt in [0.0f32, 1e-30, 1e30] {
                let desc = forced(dim, q, dt, 1.0);
                let what = format!("{dim}D {q:?} dt {dt}");
                let mut mem = memory(&desc);
                let world = World::init(&desc, &mut mem).unwrap();
                set_fields(world, 1.0);
                let n = fill_half(world, &[1.0]);
                let mut twin_desc = forced(dim, q, 1.0, 0.0);
                twin_desc.vortex.circulation = 0.0;
                let mut twin_mem = memory(&twin_desc);
                let twin = World::init(&twin_desc, &mut twin_mem).unwrap();
                set_fields(twin, 0.0);
                assert_eq!(fill_half(twin, &[1.0]), n);
                for t in 0..50 {
                    world.step(1);
                    twin.step(1);
                    check_sane(world, n, &format!("{what}, step {t}"));
                    if dt == 0.0 {
                        assert_eq!(world.state_hash(), twin.state_hash(), "{what}: dt = 0 differs from zero forces at step {t}");
                    }
                }
                if dt == 1e30 {
                    assert!(world.stats().clamps > 0, "{what}: no clamp");
                }
            }
        }
    }
}

/// M5.1 with dt = 0: `v <- v + dt F / m` leaves every velocity as it is,
/// whatever the force, even one that overflows f32 (a potential jumping
/// from f32::MAX to -f32::MAX, whose central difference is infinite, and a
/// force of 1e30 on a mass of 1e-30). Particles alone in their blocks (4
/// cells apart), speeds up to 0.5, periodic, no obstacle: nothing else can
/// change a velocity in one step. Expected: every stored velocity after the
/// step equals the one before, exactly.
#[test]
fn zero_time_step_ignores_even_infinite_forces() {
    for dim in [2u32, 3] {
        for q in QUANTS {
            let what = format!("{dim}D {q:?}");
            let mut desc = cube(dim, 16);
            desc.quantization = q;
            desc.dt = 0.0;
            desc.forces.potential = true;
            desc.forces.field = true;
            desc.per_particle_mass = true;
            desc.mass_classes = 2;
            desc.seed = 19;
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            // The cliff runs through x = 8.5: cells 8 and 9 see an infinite
            // central difference.
            let u: Vec<f32> = cells(&desc).map(|p| if p[0] < 9 { f32::MAX } else { -f32::MAX }).collect();
            world.set_potential(&u).unwrap();
            let f: Vec<f32> = cells(&desc).flat_map(|_| [1e30f32, -1e30, 1e30].into_iter().take(dim as usize)).collect();
            world.set_force_field(&f).unwrap();
            let mut rng = common::test_rng(19);
            let mut before = std::collections::BTreeMap::new();
            for pos in cells(&desc).filter(|p| p.iter().take(dim as usize).all(|&c| c % 4 == 1)) {
                let m = if (pos[0] / 4) % 2 == 0 { 1.0 } else { 1e-30 };
                world.add_particle_with_mass(pos, rng.velocity(dim, 0.5), m).unwrap();
                before.insert(pos.map(|c| c / 4), stored(common::particle(world, pos).velocity, q));
            }
            world.step(1);
            check_sane(world, before.len() as u64, &what);
            let mut changed = vec![];
            for p in world.particles() {
                let x = stored(p.velocity, q);
                if before[&p.pos.map(|c| c / 4)] != x {
                    changed.push(format!("{:?}: {:?} -> {x:?}", p.pos, before[&p.pos.map(|c| c / 4)]));
                }
            }
            assert!(changed.is_empty(), "{what}: dt = 0 changed {} velocities:\n  {}", changed.len(), changed.join("\n  "));
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
/// add_obstacle_mask; the world is unchanged; 0 and 1 are accepted.
#[test]
fn restitution_outside_zero_one_is_refused() {
    let bad = [-f32::MIN_POSITIVE, -1e-30, -0.5, 1.0 + f32::EPSILON, 2.0, f32::MAX, -f32::MAX];
    for e in bad {
        let mut d = Description::new_2d(8, 8);
        d.restitution = e;
        assert_eq!(d.validate(), Err(Error::RestitutionRange), "restitution {e}");
        let mut d = Description::new_2d(8, 8);
        d.wall_restitution = e;
        assert_eq!(d.validate(), Err(Error::RestitutionRange), "wall restitution {e}");
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
        assert_eq!(world.add_obstacle([12, 12, 0], [0.0, 1.0, 0.0], e), Err(Error::RestitutionRange), "add_obstacle {e}");
        let disc = Shape::Disc { centre: [3.0, 12.0], radius: 1.5 };
        assert_eq!(world.add_shape(disc, e), Err(Error::RestitutionRange), "add_shape {e}");
        assert_eq!(world.add_obstacle_mask(&mask, e), Err(Error::RestitutionRange), "add_obstacle_mask {e}");
        assert_eq!((world.state_hash(), world.stats(), *world.description()), before, "e = {e} changed the world");
        assert!(!world.obstacle_at([12, 12, 0]) && !world.obstacle_at([12, 3, 0]));
    }
    for e in [0.0, 1.0] {
        let mut d = Description::new_2d(8, 8);
        d.restitution = e;
        d.wall_restitution = e;
        assert_eq!(d.validate(), Ok(()));
    }
    world.add_obstacle([12, 12, 0], [0.0, 1.0, 0.0], 0.0).unwrap();
    world.add_obstacle([12, 3, 0], [0.0, 1.0, 0.0], 1.0).unwrap();
}

// ------------------------------------------------------------- non-finite

const NON_FINITE: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

/// A description with every part on.
fn busy_desc(dim: u32) -> Description {
    let mut desc = cube(dim, 8).with_boundary(Boundary::Wall);
    desc.per_particle_mass = true;
    desc.mass_classes = 4;
    desc.obstacles = true;
    desc.surface_capacity = 512;
    desc.forces = mpca::Forces { uniform: true, field: true, potential: true, vortex: true };
    desc.gravity = [0.0, -0.01, 0.0];
    desc.vortex = Vortex { centre: [4.0, 4.0], core_radius: 1.0, circulation: 0.5 };
    desc.lifetimes = true;
    desc.emitter_capacity = 8;
    desc.seed = 12;
    desc
}

/// Fills a `busy_desc` world: particles of two masses, an obstacle, an
/// emitter; a few steps taken.
fn make_busy(w: &mut World) {
    w.add_particle([1, 1, 0], [0.3, 0.1, 0.0]).unwrap();
    w.add_particle_with_mass([2, 5, 0], [-0.2, 0.1, 0.0], 2.0).unwrap();
    w.add_obstacle([6, 1, 0], [0.0, 1.0, 0.0], 1.0).unwrap();
    let e = Emitter { min: [0, 6, 0], max: [2, 8, 1], rate: 0.5, velocity: [0.1, 0.0, 0.0], mass: 1.0, lifetime: 30, ..Emitter::default() };
    w.add_emitter(e).unwrap();
    w.step(5);
}

/// M1, STYLE practice 3: NaN, +inf and -inf are refused with NotFinite in
/// every float input, and a refused call changes nothing. Expected for the
/// description's floats: validate, world_bytes and init say NotFinite and
/// init leaves the memory untouched; for every call taking a float
/// (add_particle velocity, add_particle_with_mass velocity and mass,
/// add_obstacle normal and restitution, every field of every Shape and its
/// restitution, add_obstacle_mask's restitution, set_gravity, set_force_field,
/// set_cell_force, set_potential, set_cell_potential, set_vortex, every float
/// of add_emitter, set_emitter_rate), in 2D and 3D, every component
/// including the third of a 2D world: NotFinite, with state_hash, stats and
/// description as before.
#[test]
fn non_finite_inputs_are_refused_and_change_nothing() {
        let fields = common::description_floats();
    for dim in [2u32, 3] {
        for bad in NON_FINITE {
            for (name, set) in fields {
                let mut d = busy_desc(dim);
                set(&mut d, bad);
                assert_eq!(d.validate(), Err(Error::NotFinite), "{dim}D description {name} = {bad}");
                assert_eq!(mpca::world_bytes(&d), Err(Error::NotFinite), "{dim}D world_bytes {name} = {bad}");
                let mut poison = vec![0xa5u8; 1 << 16];
                assert_eq!(World::init(&d, &mut poison).err(), Some(Error::NotFinite), "{dim}D init {name}");
                assert!(poison.iter().all(|&b| b == 0xa5), "{dim}D init {name} wrote memory");
            }
        }
    }

    for dim in [2u32, 3] {
        let desc = busy_desc(dim);
        let mut mem = memory(&desc);
        let world = World::init(&desc, &mut mem).unwrap();
        make_busy(world);
        let before = (world.state_hash(), world.stats(), *world.description());
        let free = cells(&desc).find(|&p| world.cell(p) == Ok(Cell::Empty)).expect("an empty cell");
        let n = cells(&desc).count();
        let d = dim as usize;
        for bad in NON_FINITE {
            let mut calls: Vec<(String, Result<(), Error>)> = vec![];
            for k in 0..3 {
                let mut v = [0.1f32, 0.1, 0.0];
                v[k] = bad;
                calls.push((format!("add_particle v[{k}]"), world.add_particle(free, v)));
                calls.push((format!("add_particle_with_mass v[{k}]"), world.add_particle_with_mass(free, v, 1.0)));
                let mut nrm = [0.0f32, 1.0, 0.0];
                nrm[k] = bad;
                calls.push((format!("add_obstacle normal[{k}]"), world.add_obstacle(free, nrm, 1.0)));
                let mut g = [0.0f32, -0.01, 0.0];
                g[k] = bad;
                calls.push((format!("set_gravity[{k}]"), world.set_gravity(g)));
                calls.push((format!("set_cell_force[{k}]"), world.set_cell_force(free, g)));
                let mut p3 = [4.0f32, 4.0, 4.0];
                p3[k] = bad;
                let shapes = [
                    ("half-space point", Shape::HalfSpace { point: p3, normal: [0.0, 1.0, 0.0] }),
                    ("half-space normal", Shape::HalfSpace { point: [0.0, 1.0, 0.0], normal: g }),
                    ("box min", Shape::Box { min: p3, max: [5.0, 5.0, 5.0] }),
                    ("box max", Shape::Box { min: [3.0, 3.0, 3.0], max: p3.map(|c| if c.is_finite() { c + 1.0 } else { c }) }),
                ];
                for (sname, shape) in shapes {
                    calls.push((format!("add_shape {sname}[{k}]"), world.add_shape(shape, 1.0)));
                }
                if dim == 3 {
                    calls.push((format!("add_shape sphere centre[{k}]"), world.add_shape(Shape::Sphere { centre: p3, radius: 1.0 }, 1.0)));
                } else if k < 2 {
                    let c = [p3[0], p3[1]];
                    calls.push((format!("add_shape disc centre[{k}]"), world.add_shape(Shape::Disc { centre: c, radius: 1.0 }, 1.0)));
                }
                let e = Emitter { min: [0, 0, 0], max: [2, 2, 2], rate: 1.0, velocity: v, mass: 1.0, ..Emitter::default() };
                calls.push((format!("add_emitter velocity[{k}]"), world.add_emitter(e).map(|_| ())));
            }
            let radius_shape = if dim == 3 { Shape::Sphere { centre: [4.0; 3], radius: bad } } else { Shape::Disc { centre: [4.0; 2], radius: bad } };
            calls.push(("add_shape radius".into(), world.add_shape(radius_shape, 1.0)));
            calls.push(("add_particle_with_mass mass".into(), world.add_particle_with_mass(free, [0.0; 3], bad)));
            calls.push(("add_obstacle restitution".into(), world.add_obstacle(free, [0.0, 1.0, 0.0], bad)));
            calls.push(("add_shape restitution".into(), world.add_shape(Shape::Box { min: [3.0; 3], max: [4.0; 3] }, bad)));
            calls.push(("add_obstacle_mask restitution".into(), world.add_obstacle_mask(&vec![0u8; n], bad)));
            for at in [0, n * d / 2, n * d - 1] {
                let mut f = vec![0.0f32; n * d];
                f[at] = bad;
                calls.push((format!("set_force_field[{at}]"), world.set_force_field(&f)));
            }
            for at in [0, n / 2, n - 1] {
                let mut u = vec![0.0f32; n];
                u[at] = bad;
                calls.push((format!("set_potential[{at}]"), world.set_potential(&u)));
            }
            calls.push(("set_cell_potential".into(), world.set_cell_potential(free, bad)));
            let v = Vortex { centre: [4.0, 4.0], core_radius: 1.0, circulation: 0.5 };
            calls.push(("set_vortex centre x".into(), world.set_vortex(Vortex { centre: [bad, 4.0], ..v })));
            calls.push(("set_vortex centre y".into(), world.set_vortex(Vortex { centre: [4.0, bad], ..v })));
            calls.push(("set_vortex core".into(), world.set_vortex(Vortex { core_radius: bad, ..v })));
            calls.push(("set_vortex circulation".into(), world.set_vortex(Vortex { circulation: bad, ..v })));
            let e = Emitter { min: [0, 0, 0], max: [2, 2, 2], rate: 1.0, mass: 1.0, ..Emitter::default() };
            calls.push(("add_emitter rate".into(), world.add_emitter(Emitter { rate: bad, ..e }).map(|_| ())));
            calls.push(("add_emitter spread".into(), world.add_emitter(Emitter { spread: bad, ..e }).map(|_| ())));
            calls.push(("add_emitter mass".into(), world.add_emitter(Emitter { mass: bad, ..e }).map(|_| ())));
            calls.push(("set_emitter_rate".into(), world.set_emitter_rate(0, bad)));
            let mut failures = vec![];
            for (call, result) in calls {
                if result != Err(Error::NotFinite) {
                    failures.push(format!("{call} = {bad}: {result:?}"));
                }
            }
            assert!(failures.is_empty(), "{dim}D: not refused as NotFinite:\n  {}", failures.join("\n  "));
            assert_eq!((world.state_hash(), world.stats(), *world.description()), before, "{dim}D {bad}: a refused call changed the world");
            assert_eq!(world.cell(free), Ok(Cell::Empty), "{dim}D {bad}");
        }
    }
}

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
            assert_eq!(world.add_particle([1, 1, 0], [0.0; 3]), Err(Error::CellObstacle), "{what}");
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

/// M1/M9: a world whose cell count does not fit the u32 cell index, or
/// whose byte count overflows the target, is refused with TooLarge by
/// validate and world_bytes, and nothing is allocated (only the
/// descriptions are checked here). Expected: TooLarge for 2^32 cells and
/// beyond, in 2D and 3D, with and without every part; the largest world
/// with fewer cells and every part is either refused with TooLarge (when
/// its payload, computed here in u128, exceeds usize) or gets a byte count
/// at least that payload.
#[test]
fn oversized_worlds_are_refused_without_allocating() {
    let every_part = |mut d: Description| {
        d.per_particle_mass = true;
        d.mass_classes = 256;
        d.obstacles = true;
        d.surface_capacity = u32::MAX;
        d.forces = mpca::Forces { uniform: true, field: true, potential: true, vortex: true };
        d.lifetimes = true;
        d.emitter_capacity = u32::MAX;
        d.quantization = Quantization::Bits16;
        d
    };
    let big = u32::MAX - 1; // the largest even size
    let too_many = [
        Description::new_2d(1 << 16, 1 << 16),
        Description::new_2d(1 << 31, 2),
        Description::new_2d(2, 1 << 31),
        Description::new_2d(big, big),
        Description::new_3d(1 << 11, 1 << 11, 1 << 10),
        Description::new_3d(2, 2, 1 << 30),
        Description::new_3d(1 << 22, 1 << 22, 1 << 22),
        Description::new_3d(big, big, big),
    ];
    for d in too_many {
        for desc in [d, every_part(d)] {
            assert_eq!(desc.validate(), Err(Error::TooLarge), "{:?}", desc.size);
            assert_eq!(mpca::world_bytes(&desc), Err(Error::TooLarge), "{:?}", desc.size);
        }
    }
    for d in [Description::new_2d(1 << 16, 1 << 15), Description::new_3d(1 << 11, 1 << 11, 1 << 9)] {
        let desc = every_part(d);
        let cells: u128 = desc.size[..desc.dim as usize].iter().map(|&s| u128::from(s)).product();
        let dim = u128::from(desc.dim);
        // Velocity 2 dim, mass index 1, lifetime 2, field 4 dim, potential
        // 4 bytes per cell, two bit planes; the tables on top.
        let payload = cells * (2 * dim + 1 + 2 + 4 * dim + 4) + 2 * cells / 8
            + u128::from(u32::MAX) * std::mem::size_of::<mpca::Surface>() as u128
            + u128::from(u32::MAX) * std::mem::size_of::<Emitter>() as u128;
        match mpca::world_bytes(&desc) {
            Ok(bytes) => assert!(bytes as u128 >= payload && payload <= usize::MAX as u128, "{bytes} < {payload}"),
            Err(e) => assert!(e == Error::TooLarge && payload > usize::MAX as u128 / 2, "{e:?} for a payload of {payload}"),
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

// ------------------------------------------------------------- sub-quantum

/// Extends forces.rs's `sub_quantum_accelerations_act_on_average` (2D,
/// from rest, 0.127 quantum per step on the uniform path at 8 bits, 0.33 on
/// the field path at 16 bits) to 3D, to the potential path (eq. 6's central
/// differences of a linear potential), to the paths forces.rs left out at
/// each width (field at 8 bits, uniform at 16), to a hundredth of a quantum
/// per step, and to a deceleration through zero: particles start at +10
/// quanta along x, alone in their (y, z) row, and feel -0.01 quantum per
/// step for 2000 steps. Expected: mean stored v_x = 10 - 20 = -10 quanta
/// within 5 standard errors (sample variance across the independent
/// particles); the band excludes +10, where rounding to nearest would
/// leave them.
#[test]
fn hundredth_of_a_quantum_per_step_acts_on_average() {
    const STEPS: u64 = 2000;
    const ROWS: u32 = 16;
    for q in QUANTS {
        for path in ["uniform", "field", "potential"] {
            let what = format!("{q:?} {path}");
            let s = scale(q) as f32;
            let a = -0.01 / s; // cells per step^2
            let mut desc = Description::new_3d(512, 4 * ROWS, 4 * ROWS);
            desc.boundary[0] = [Boundary::Wall; 2];
            desc.quantization = q;
            desc.seed = 17;
            desc.drift = Drift::Calibrated;
            match path {
                "uniform" => {
                    desc.forces.uniform = true;
                    desc.gravity = [a, 0.0, 0.0];
                }
                "field" => desc.forces.field = true,
                _ => desc.forces.potential = true,
            }
            let mut mem = memory(&desc);
            let world = World::init(&desc, &mut mem).unwrap();
            match path {
                "field" => {
                    let f: Vec<f32> = cells(&desc).flat_map(|_| [a, 0.0, 0.0]).collect();
                    world.set_force_field(&f).unwrap();
                }
                "potential" => {
                    // F = -dU/dx = a (mass 1): U = -a x, exact differences.
                    let u: Vec<f32> = cells(&desc).map(|p| -a * p[0] as f32).collect();
                    world.set_potential(&u).unwrap();
                }
                _ => {}
            }
            let v0 = 10.0 / s;
            for j in 0..ROWS * ROWS {
                world.add_particle([252 + j % 8, 4 * (j % ROWS), 4 * (j / ROWS)], [v0, 0.0, 0.0]).unwrap();
            }
            world.step(STEPS);
            assert_eq!(world.stats().collisions, 0, "{what}");
            let v: Vec<f64> = world.particles().map(|p| quanta(p.velocity[0], q) as f64).collect();
            assert_eq!(v.len(), (ROWS * ROWS) as usize);
            // The walls at x = 0 and 511 stay out of reach (a wall would
            // flip a velocity): the mean path goes out 39 cells at 8 bits
            // and back, and rounding (variance 0.01 quantum^2 per step)
            // spreads it by about 40 cells.
            assert!(world.particles().all(|p| (1..511).contains(&p.pos[0])), "{what}");
            let (mean, se) = mean_and_se(&v);
            let want = 10.0 - 0.01 * STEPS as f64;
            assert!((mean - want).abs() <= Z * se, "{what}: mean {mean} quanta, expected {want} +- {}", Z * se);
            assert!((10.0 - want) > Z * se, "{what}: the band reaches +10");
        }
    }
}
